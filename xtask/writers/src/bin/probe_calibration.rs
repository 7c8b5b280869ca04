//! The error-bar calibration of the point probe: per size, family member and query kind, the
//! factor `c` that makes 95 % of the training maps' errors fall within `2√(c·σ̂_f²·v)`, fitted
//! by the probe-trust benchmark's engine (`cargo eval probe_trust`, whose docs describe the
//! measurement and report it; `sphere_quadrature_eval::probe_trust`) on the training maps, and
//! written as the `calibration = N lambda c_irradiance c_7 c_22 c_102` lines that end
//! `tables/probe.txt` (the build script bakes them into the probe).
//!
//! ```text
//! cargo writer probe_calibration             # fail unless tables/probe.txt holds this fit
//! cargo writer probe_calibration -- --write  # rewrite its calibration lines
//! cargo xtask regen calibration              # the write, after the families it calibrates
//! ```
//!
//! The fit needs the families of `tables/probe.txt` (`cargo xtask regen hyperparameters`)
//! first. It reads the training maps only (default apartment, bridge, forest, lab); the
//! held-out maps check the factors in the benchmark's report.

use std::error::Error;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use sphere_quadrature_eval::cli;
use sphere_quadrature_eval::probe_trust::{run, Family, MapJob, Setup};

/// probe_calibration: fits the point probe's error-bar calibration on the training maps and
/// checks (or, with --write, rewrites) the calibration lines of tables/probe.txt
#[derive(Parser)]
#[command(bin_name = "cargo writer probe_calibration --", verbatim_doc_comment)]
struct Args {
    /// Equirectangular .hdr maps (default: the training maps in examples/envmaps/);
    /// only those named by --train are fitted on
    #[arg(value_name = "MAPS", value_parser = cli::map_file, verbatim_doc_comment)]
    maps: Vec<PathBuf>,
    #[command(flatten)]
    train: cli::Train,
    /// Random probe rotations per map
    #[arg(long, value_name = "R", default_value_t = 16, value_parser = cli::positive)]
    rotations: usize,
    /// Query axes per map
    #[arg(long, value_name = "Q", default_value_t = 64, value_parser = cli::positive)]
    normals: usize,
    /// Rewrite the calibration lines of tables/probe.txt instead of checking them
    #[arg(long)]
    write: bool,
    #[command(flatten)]
    threads: cli::Threads,
}

const TABLE: &str = "tables/probe.txt";

fn calibrate(args: &Args) -> Result<bool, Box<dyn Error>> {
    let maps = if args.maps.is_empty() {
        let names: Vec<&str> = args.train.train.iter().map(String::as_str).collect();
        cli::bundled_maps(&names)
    } else {
        args.maps.clone()
    };
    let setup = Setup {
        maps,
        train: args.train.train.clone(),
        rotations: args.rotations,
        normals: args.normals,
        quick: false,
        threads: args.threads.count(),
    };
    let result = run(&setup)?;
    if !result.any_training {
        return Err("no training maps among the inputs (see --train)".into());
    }
    let text =
        calibration_block(&result.table_text, &result.factors, &result.families, &result.jobs);
    let path = cli::repo_root().join(TABLE);
    if args.write {
        std::fs::write(&path, text)?;
        eprintln!("wrote {TABLE}");
        Ok(true)
    } else if text == result.table_text {
        println!("{TABLE}: the calibration lines are current");
        Ok(true)
    } else {
        eprintln!("{TABLE}: the calibration lines are not what the training maps give; rerun with --write");
        Ok(false)
    }
}

fn main() -> ExitCode {
    match calibrate(&Args::parse()) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("probe_calibration: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `tables/probe.txt` with its calibration block replaced.
fn calibration_block(
    old: &str,
    factors: &[(usize, Vec<[f64; 4]>)],
    families: &[Family],
    jobs: &[MapJob],
) -> String {
    const MARK: &str = "\n#\n# Error-bar calibration";
    let mut text = match old.find(MARK) {
        Some(at) => old[..at + 1].to_string(),
        None => format!("{}\n", old.trim_end()),
    };
    let train: Vec<&str> = jobs.iter().filter(|j| j.training).map(|j| j.name.as_str()).collect();
    let _ = writeln!(text, "#\n# Error-bar calibration (issue #13), written by");
    let _ = writeln!(
        text,
        "# `cargo xtask regen calibration`, which runs it after the families above."
    );
    let _ = writeln!(text, "# `calibration = N lambda c_irradiance c_7 c_22 c_102`: the point probe's variances of member λ are");
    let _ = writeln!(text, "# multiplied by c (irradiance; glossy at lobe sharpness μ = 7, 22, 102, log-linear in μ between and");
    let _ = writeln!(text, "# constant outside). c makes 95 % of the errors fall within 2σ on the training maps {} (clamp", train.join(", "));
    let _ = writeln!(
        text,
        "# and smooth tiers pooled, docs/probe_trust.md). A member without a line keeps c = 1."
    );
    for (n, f) in factors {
        let Some(fam) = families.iter().find(|x| x.n == *n) else { continue };
        for (l, c) in fam.lambdas.iter().zip(f) {
            let _ = writeln!(
                text,
                "calibration = {n} {l} {:.4} {:.4} {:.4} {:.4}",
                c[0], c[1], c[2], c[3]
            );
        }
    }
    text
}
