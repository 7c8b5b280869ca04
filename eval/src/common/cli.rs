//! Shared command-line pieces of the evaluation programs: each program parses its arguments
//! with its own `#[derive(clap::Parser)]` struct, flattens into it the argument groups that
//! several programs share (`--threads`, the positional maps, `--train`), and takes from here
//! the repository root, the bundled maps, map names, the default output folder, the
//! `--threads` default and the `main` wrapper.

use std::error::Error;
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

/// The ten bundled maps, by name.
pub const ALL_MAPS: [&str; 10] =
    ["apartment", "bridge", "city", "dawn", "forest", "hall", "lab", "lobby", "night", "park"];
/// The training maps (tables/ are learned on them); the other bundled maps are held out.
pub const TRAINING_MAPS: [&str; 4] = ["apartment", "bridge", "forest", "lab"];
/// The bundled maps that are not [`TRAINING_MAPS`]: what the benchmarks report on.
pub const HELD_OUT_MAPS: [&str; 6] = ["city", "dawn", "hall", "lobby", "night", "park"];
/// `--quick`: one training and one held-out map.
pub const QUICK_MAPS: [&str; 2] = ["apartment", "lobby"];
/// `--quick` of the programs that run on held-out maps only: two of them.
pub const QUICK_HELD_OUT_MAPS: [&str; 2] = ["city", "lobby"];

// Every bundled map is either a training map or held out, never both.
const _: () = {
    let mut i = 0;
    while i < ALL_MAPS.len() {
        let name = ALL_MAPS[i].as_bytes();
        let (mut training, mut held) = (0, 0);
        let mut j = 0;
        while j < TRAINING_MAPS.len() {
            training += same(name, TRAINING_MAPS[j].as_bytes()) as usize;
            j += 1;
        }
        j = 0;
        while j < HELD_OUT_MAPS.len() {
            held += same(name, HELD_OUT_MAPS[j].as_bytes()) as usize;
            j += 1;
        }
        assert!(training + held == 1, "a bundled map is neither training nor held out, or both");
        i += 1;
    }
    assert!(TRAINING_MAPS.len() + HELD_OUT_MAPS.len() == ALL_MAPS.len());
};

/// Byte equality of two names (const).
const fn same(a: &[u8], b: &[u8]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// The default maps of the programs that name theirs: [`QUICK_MAPS`] with `--quick`, else
/// [`ALL_MAPS`].
pub fn named_maps(quick: bool) -> Vec<PathBuf> {
    bundled_maps(if quick { &QUICK_MAPS } else { &ALL_MAPS })
}

/// The default maps of the programs that report on held-out maps only: [`HELD_OUT_MAPS`], or
/// [`QUICK_HELD_OUT_MAPS`] with `--quick`.
pub fn held_out_maps(quick: bool) -> Vec<PathBuf> {
    bundled_maps(if quick { &QUICK_HELD_OUT_MAPS } else { &HELD_OUT_MAPS })
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

/// The default maps of the programs that take every bundled map: [`all_bundled_maps`], with
/// `--quick` only the two named.
pub fn all_bundled_maps_or(quick: bool, quick_maps: [&str; 2]) -> std::io::Result<Vec<PathBuf>> {
    let mut maps = all_bundled_maps()?;
    if quick {
        maps.retain(|p| p.file_stem().is_some_and(|s| s == quick_maps[0] || s == quick_maps[1]));
    }
    Ok(maps)
}

/// A map's name in reports and CSV rows: its file stem (`examples/envmaps/lab.hdr` → `lab`).
pub fn map_name(path: &Path) -> String {
    path.file_stem().map_or("map".into(), |s| s.to_string_lossy().into_owned())
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

/// `main` of a program whose argument check goes on after clap's: `program: error` on stderr,
/// exit code 2 when `parse` fails (a usage error, as clap's own) and 1 when `run` does.
pub fn run_main<A>(
    program: &str,
    parse: impl FnOnce() -> Result<A, Box<dyn Error>>,
    run: impl FnOnce(&A) -> Result<(), Box<dyn Error>>,
) {
    match parse() {
        Ok(args) => {
            if let Err(e) = run(&args) {
                eprintln!("{program}: {e}");
                std::process::exit(1);
            }
        }
        Err(e) => {
            eprintln!("{program}: {e}");
            std::process::exit(2);
        }
    }
}

// The argument groups below are flattened (`#[command(flatten)]`) into the programs that take
// them with the same meaning and help text.

// `--threads T`.
#[derive(Clone, clap::Args)]
pub struct Threads {
    /// Worker threads (default: all cores)
    #[arg(long, value_name = "T")]
    pub threads: Option<usize>,
}

impl Threads {
    /// The worker count: [`threads`] of the option.
    pub fn count(&self) -> usize {
        threads(self.threads)
    }
}

// The positional maps of the programs that name their default maps (`named_maps`) and count
// the `TRAINING_MAPS` as training maps, the rest as held out.
#[derive(Clone, clap::Args)]
pub struct TrainingMaps {
    /// Equirectangular .hdr maps (default: the ten in examples/envmaps/); maps named
    /// apartment, bridge, forest or lab count as training maps, the rest as held out
    #[arg(value_name = "MAPS", value_parser = map_file, verbatim_doc_comment)]
    pub maps: Vec<PathBuf>,
}

// The positional maps of the programs that take every bundled map by default
// (`all_bundled_maps_or`).
#[derive(Clone, clap::Args)]
pub struct AllMaps {
    /// Equirectangular .hdr maps (default: examples/envmaps/*.hdr)
    #[arg(value_name = "MAPS", value_parser = map_file)]
    pub maps: Vec<PathBuf>,
}

// `--train A,B,…`: the training maps by stem.
#[derive(Clone, clap::Args)]
pub struct Train {
    /// Training map stems (default apartment,bridge,forest,lab)
    #[arg(long, value_name = "A,B,…", value_delimiter = ',', hide_default_value = true)]
    #[arg(default_values = ["apartment", "bridge", "forest", "lab"])]
    pub train: Vec<String>,
}
