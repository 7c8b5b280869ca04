//! Build script: bakes the spherical-Gaussian integral tables (issue #4) into
//! `$OUT_DIR/sg_tables.rs` and the Bayesian Monte Carlo weights (issue #6) into
//! `$OUT_DIR/bmc_tables.rs` (and as Q1.31 integers into `$OUT_DIR/bmc_fixed_tables.rs`, for
//! the `fixed` feature), the glossy weights and the probe families, in f64, from the
//! generators in `gen/` and the files in `tables/`. Plain std Rust with no build-dependencies;
//! the output is deterministic (exact f32 bits, no timestamps or paths). `tests/bmc/sg_tables.rs`
//! and `tests/bmc/bmc.rs` run the same generators and check the baked tables bit for bit.
//!
//! The bake of the crate's own tables is also stored in `baked/` (`gen/cache.rs`), keyed by a
//! hash of `gen/`, `tables/` and this file: when the key matches, a family without a user
//! table or feature sweep is expanded from there instead of baked (a dependant runs this
//! script unoptimised); `tests/bmc/baked.rs` checks that the store equals a fresh bake.

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

    // The crate's own tables come prebaked from `baked/` when it is current (`gen/cache.rs`):
    // a family bakes here only for a user table, a feature sweep, or a stale cache.
    println!("cargo::rerun-if-changed={}", gen::cache::DIR);
    let root = PathBuf::from(".");
    let key = gen::cache::key(&root).unwrap_or_else(|e| fail("build.rs", &e));
    let cached = gen::cache::load(&root, &key).unwrap_or_else(|e| fail(gen::cache::DIR, &e));
    if cached.is_none() {
        println!(
            "cargo::warning={}/ does not hold this bake of gen/ and tables/: baking every table \
             (refresh it: SPHERE_QUADRATURE_WRITE_BAKED=1 cargo test --release --test bmc baked::)",
            gen::cache::DIR
        );
    }
    let read_crate = |file: &str| -> Result<String, gen::Failure> {
        std::fs::read_to_string(file).map_err(|e| gen::Failure {
            file: file.to_string(),
            message: format!("cannot read it: {e}"),
        })
    };
    let sweep = |feature: &str| std::env::var_os(feature).is_some();
    // Each family: its files from the cache, or baked from the config (user's or default).
    let bake = |names: &[&str], env: Option<&str>, custom: bool, files: Bake| {
        let user = env.is_some_and(|env| {
            println!("cargo::rerun-if-env-changed={env}");
            std::env::var_os(env).is_some()
        });
        let from_cache = cached.as_ref().filter(|_| !user && !custom).map(|c| {
            c.iter().filter(|(n, _)| names.contains(&n.as_str())).cloned().collect::<Vec<_>>()
        });
        let files: Vec<(String, String)> = match from_cache {
            Some(c) if c.len() == names.len() => c,
            _ => files()
                .unwrap_or_else(|e| fail(&e.file, &e.message))
                .into_iter()
                .map(|(n, t)| (n.to_string(), t))
                .collect(),
        };
        for (name, text) in files {
            write_if_changed(&out_dir.join(name), &text);
        }
    };
    bake(&["sg_tables.rs"], None, false, &|| {
        gen::sg_files(gen::sg::CONFIG_FILE, &read(gen::sg::CONFIG_FILE))
    });
    bake(
        &["bmc_tables.rs", "bmc_fixed_tables.rs", "bmc_size_diagnostics.rs"],
        Some(BMC_ENV),
        false,
        &|| {
            let (file, text) = config(gen::bmc::CONFIG_FILE, BMC_ENV);
            gen::bmc_files(&file, &text)
        },
    );
    // The feature `renderer-sweep` adds the renderer benchmark's other sets.
    let renderer_sweep = sweep("CARGO_FEATURE_RENDERER_SWEEP");
    bake(&["glossy_tables.rs"], Some(GLOSSY_ENV), renderer_sweep, &|| {
        let (file, text) = config(gen::glossy::CONFIG_FILE, GLOSSY_ENV);
        gen::glossy_files(&file, &text, renderer_sweep, &read_crate)
    });
    // The footprint renderer's sets.
    bake(&["footprint_tables.rs"], None, false, &|| {
        let file = gen::fp::CONFIG_FILE;
        gen::fp_files(file, &read_crate(file)?)
    });
    // The feature `footprint-sweep` adds the footprint benchmark's extra footprints.
    let footprint_sweep = sweep("CARGO_FEATURE_FOOTPRINT_SWEEP");
    bake(&["probe_tables.rs", "probe_size.rs"], Some(PROBE_ENV), footprint_sweep, &|| {
        let (file, text) = config(gen::probe::CONFIG_FILE, PROBE_ENV);
        gen::probe_files(&file, &text, footprint_sweep, &read_crate)
    });
}

/// Bakes one family's files.
type Bake<'a> = &'a dyn Fn() -> Result<gen::Files, gen::Failure>;

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
