//! Build script: bakes the spherical-Gaussian integral tables (issue #4) into
//! `$OUT_DIR/sg_tables.rs`, in f64, from the generator in `gen/` and the sizes in `tables/`.
//! Plain std Rust with no build-dependencies; the output is deterministic (exact f32 bits, no
//! timestamps or paths). `tests/sg_tables.rs` runs the same generator and checks the baked
//! tables bit for bit. The Bayesian Monte Carlo weights (issue #6) will be baked here too.

// The host tests use more of the generator than the build does.
#[allow(dead_code)]
#[path = "gen/mod.rs"]
mod gen;

use std::path::{Path, PathBuf};

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    // Every generator source and every file in tables/ (a directory alone only reruns on
    // entries added or removed).
    for dir in ["gen", "tables"] {
        println!("cargo::rerun-if-changed={dir}");
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("reading {dir}/: {e}"))
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_file())
            .collect();
        files.sort();
        for f in files {
            println!("cargo::rerun-if-changed={}", f.display());
        }
    }

    let text = std::fs::read_to_string(gen::sg::CONFIG_FILE)
        .unwrap_or_else(|e| panic!("reading {}: {e}", gen::sg::CONFIG_FILE));
    let cfg = gen::sg::parse(&text).unwrap_or_else(|e| panic!("{}: {e}", gen::sg::CONFIG_FILE));
    let tables = gen::sg::tables(&cfg);
    let out = Path::new(&std::env::var_os("OUT_DIR").expect("OUT_DIR is set by cargo"))
        .join("sg_tables.rs");
    let src = gen::sg::render(&cfg, &tables);
    // Rewrite only on change, so that dependants are not rebuilt needlessly.
    if std::fs::read_to_string(&out).ok().as_deref() != Some(src.as_str()) {
        std::fs::write(&out, src).unwrap_or_else(|e| panic!("writing {}: {e}", out.display()));
    }
}
