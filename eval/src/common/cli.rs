//! Shared command-line pieces of the evaluation programs: each program parses its arguments
//! with its own `#[derive(clap::Parser)]` struct and takes from here the repository root, the
//! bundled maps, the default output folder and the `--threads` default.

use std::path::{Path, PathBuf};

/// The repository root (the `eval/` crate's parent): bundled maps, `tables/` and the default
/// output folders are found from here whatever the working directory.
pub fn repo_root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

/// The bundled maps `examples/envmaps/<name>.hdr`, in the order given.
pub fn bundled_maps(names: &[&str]) -> Vec<PathBuf> {
    let dir = repo_root().join("examples/envmaps");
    names.iter().map(|n| dir.join(format!("{n}.hdr"))).collect()
}

/// Every `examples/envmaps/*.hdr`, sorted by path.
pub fn all_bundled_maps() -> std::io::Result<Vec<PathBuf>> {
    let mut maps: Vec<PathBuf> = std::fs::read_dir(repo_root().join("examples/envmaps"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "hdr"))
        .collect();
    maps.sort();
    Ok(maps)
}

/// Where a program writes its files without `--out`: `target/eval/<program>/` of the
/// repository (never the tracked `docs/` or `tables/`).
pub fn default_out(program: &str) -> PathBuf {
    repo_root().join("target/eval").join(program)
}

/// `--threads`: the given count (at least 1), by default every core.
pub fn threads(requested: Option<usize>) -> usize {
    requested.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())).max(1)
}

/// clap value parser of a map path: the file must exist, so that a mistyped map is a one-line
/// usage error (exit code 2) rather than a failure after minutes of work.
pub fn map_file(s: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(s);
    if path.is_file() {
        Ok(path)
    } else if path.exists() {
        Err("not a file".into())
    } else {
        Err("no such map file".into())
    }
}

/// clap value parser of a count that must be at least 1.
pub fn positive(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(0) => Err("must be positive".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(e.to_string()),
    }
}
