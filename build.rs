//! Build script: bakes the spherical-Gaussian integral tables (issue #4) into
//! `$OUT_DIR/sg_tables.rs` and the Bayesian Monte Carlo weights (issue #6) into
//! `$OUT_DIR/bmc_tables.rs` (and as Q1.31 integers into `$OUT_DIR/bmc_fixed_tables.rs`, for
//! the `fixed` feature), in f64, from the generators in `gen/` and the files in `tables/`.
//! Plain std Rust with no build-dependencies; the output is deterministic (exact f32 bits, no
//! timestamps or paths). `tests/sg_tables.rs` and `tests/bmc.rs` run the same generators and
//! check the baked tables bit for bit.

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

    let out_dir = PathBuf::from(std::env::var_os("OUT_DIR").expect("OUT_DIR is set by cargo"));

    let text = std::fs::read_to_string(gen::sg::CONFIG_FILE)
        .unwrap_or_else(|e| panic!("reading {}: {e}", gen::sg::CONFIG_FILE));
    let cfg = gen::sg::parse(&text).unwrap_or_else(|e| panic!("{}: {e}", gen::sg::CONFIG_FILE));
    let tables = gen::sg::tables(&cfg);
    write_if_changed(&out_dir.join("sg_tables.rs"), &gen::sg::render(&cfg, &tables));

    let text = std::fs::read_to_string(gen::bmc::CONFIG_FILE)
        .unwrap_or_else(|e| panic!("reading {}: {e}", gen::bmc::CONFIG_FILE));
    let specs = gen::bmc::parse(&text).unwrap_or_else(|e| panic!("{}: {e}", gen::bmc::CONFIG_FILE));
    let sets =
        gen::bmc::bake_all(&specs).unwrap_or_else(|e| panic!("{}: {e}", gen::bmc::CONFIG_FILE));
    write_if_changed(&out_dir.join("bmc_tables.rs"), &gen::bmc::render(&sets));
    // The same weights as Q1.31 integers for the `fixed` feature (`src/fixed_point.rs`).
    let fixed = gen::bmc::render_fixed(&sets)
        .unwrap_or_else(|e| panic!("{}: fixed-point weights: {e}", gen::bmc::CONFIG_FILE));
    write_if_changed(&out_dir.join("bmc_fixed_tables.rs"), &fixed);
}

/// Rewrites `out` only on change, so that dependants are not rebuilt needlessly.
fn write_if_changed(out: &Path, src: &str) {
    if std::fs::read_to_string(out).ok().as_deref() != Some(src) {
        std::fs::write(out, src).unwrap_or_else(|e| panic!("writing {}: {e}", out.display()));
    }
}
