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
            .unwrap_or_else(|e| fail(dir, &format!("cannot read the directory: {e}")))
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_file())
            .collect();
        files.sort();
        for f in files {
            println!("cargo::rerun-if-changed={}", f.display());
        }
    }

    let Some(out_dir) = std::env::var_os("OUT_DIR").map(PathBuf::from) else {
        fail("build.rs", "OUT_DIR is not set (run the build through cargo)")
    };

    let text = read(gen::sg::CONFIG_FILE);
    let cfg = gen::sg::parse(&text).unwrap_or_else(|e| fail(gen::sg::CONFIG_FILE, &e));
    let tables = gen::sg::tables(&cfg);
    write_if_changed(&out_dir.join("sg_tables.rs"), &gen::sg::render(&cfg, &tables));

    let (bmc_file, text) = config(gen::bmc::CONFIG_FILE, BMC_ENV);
    let specs = gen::bmc::parse(&text).unwrap_or_else(|e| fail(&bmc_file, &e));
    let sets = gen::bmc::bake_all(&specs).unwrap_or_else(|e| fail(&bmc_file, &e));
    write_if_changed(&out_dir.join("bmc_tables.rs"), &gen::bmc::render(&sets));
    // The same weights as Q1.31 integers for the `fixed` feature (`src/fixed_point.rs`).
    let fixed = gen::bmc::render_fixed(&sets);
    write_if_changed(&out_dir.join("bmc_fixed_tables.rs"), &fixed);
    // The compile error of an unbaked renderer or fixed-point size lists the sizes baked here.
    write_if_changed(
        &out_dir.join("bmc_size_diagnostics.rs"),
        &gen::bmc::render_size_diagnostics(&sets),
    );

    let (glossy_file, text) = config(gen::glossy::CONFIG_FILE, GLOSSY_ENV);
    // (Every file in tables/ is already a rerun trigger.)
    let learned_file = gen::glossy::LEARNED_FILE;
    let learned =
        gen::glossy::parse_learned(&read(learned_file)).unwrap_or_else(|e| fail(learned_file, &e));
    let optimal_file = gen::glossy::OPTIMAL_FILE;
    let optimal =
        gen::glossy::parse_optimal(&read(optimal_file)).unwrap_or_else(|e| fail(optimal_file, &e));
    let mut specs =
        gen::glossy::parse(&text, &learned, &optimal).unwrap_or_else(|e| fail(&glossy_file, &e));
    // The feature `renderer-sweep` adds the renderer benchmark's other sets.
    if std::env::var_os("CARGO_FEATURE_RENDERER_SWEEP").is_some() {
        let file = gen::glossy::SWEEP_FILE;
        let extra =
            gen::glossy::parse(&read(file), &learned, &optimal).unwrap_or_else(|e| fail(file, &e));
        for spec in extra {
            if !specs.iter().any(|s| s.n == spec.n && s.e == spec.e && s.optimal == spec.optimal) {
                specs.push(spec);
            }
        }
    }
    let sets = gen::glossy::bake_all(&specs, &optimal).unwrap_or_else(|e| fail(&glossy_file, &e));
    write_if_changed(&out_dir.join("glossy_tables.rs"), &gen::glossy::render(&sets));

    let (probe_file, text) = config(gen::probe::CONFIG_FILE, PROBE_ENV);
    let mut specs = gen::probe::parse(&text).unwrap_or_else(|e| fail(&probe_file, &e));
    // The feature `footprint-sweep` adds the footprint benchmark's extra footprints.
    if std::env::var_os("CARGO_FEATURE_FOOTPRINT_SWEEP").is_some() {
        let file = gen::probe::SWEEP_FILE;
        let extra = gen::probe::parse_extra(&read(file)).unwrap_or_else(|e| fail(file, &e));
        for spec in extra {
            if !specs.iter().any(|s| s.n == spec.n && s.footprint == spec.footprint) {
                specs.push(spec);
            }
        }
    }
    // (A footprint-sweep spec's error names its line in the sweep file.)
    let families = gen::probe::bake_all(&specs).unwrap_or_else(|e| fail(&probe_file, &e));
    write_if_changed(&out_dir.join("probe_tables.rs"), &gen::probe::render(&specs, &families));
    write_if_changed(&out_dir.join("probe_size.rs"), &gen::probe::render_size_trait(&specs));
}

/// Environment variable naming a file that replaces `tables/bmc.txt` (renderer weights).
const BMC_ENV: &str = "SPHERE_QUADRATURE_BMC_TABLE";
/// Environment variable naming a file that replaces `tables/glossy.txt` (glossy renderer).
const GLOSSY_ENV: &str = "SPHERE_QUADRATURE_GLOSSY_TABLE";
/// Environment variable naming a file that replaces `tables/probe.txt` (probe families).
const PROBE_ENV: &str = "SPHERE_QUADRATURE_PROBE_TABLE";

/// The config text: from the file named by `env` when it is set (so a user can bake other
/// sizes or hyperparameters without forking the crate), else the crate's own `default`.
fn config(default: &str, env: &str) -> (String, String) {
    println!("cargo::rerun-if-env-changed={env}");
    let path = match std::env::var_os(env) {
        Some(p) => {
            let p = PathBuf::from(p);
            println!("cargo::rerun-if-changed={}", p.display());
            p
        }
        None => PathBuf::from(default),
    };
    let file = path.display().to_string();
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        fail(&file, &format!("cannot read it (named by {env} or the default): {e}"))
    });
    (file, text)
}

/// The text of a file of the crate, or the build fails with one line.
fn read(file: &str) -> String {
    std::fs::read_to_string(file).unwrap_or_else(|e| fail(file, &format!("cannot read it: {e}")))
}

/// Fails the build with one clear line naming the file (and the line, when the parser gave
/// one) and the problem: `error: tables/probe.txt:12: …`, through the `cargo::error`
/// directive (Cargo ≥ 1.84, the MSRV), instead of a panic with its backtrace note.
fn fail(file: &str, message: &str) -> ! {
    let line = gen::error_line(file, message);
    let directive = line.strip_prefix("error: ").unwrap_or(&line);
    // Cargo fails the build on the directive and prints just `error: …`; a non-zero exit
    // would add the script's whole stdout (every rerun-if line) to the report.
    println!("cargo::error={directive}");
    std::process::exit(0)
}

/// Rewrites `out` only on change, so that dependants are not rebuilt needlessly.
fn write_if_changed(out: &Path, src: &str) {
    if std::fs::read_to_string(out).ok().as_deref() != Some(src) {
        std::fs::write(out, src)
            .unwrap_or_else(|e| fail(&out.display().to_string(), &format!("cannot write it: {e}")));
    }
}
