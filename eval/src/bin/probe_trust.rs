//! Probe trust (issue #13): which rule picks the probe's family member, and how wide its error
//! bar must be, measured on real maps with an independent f64 Gaussian-process engine.
//!
//! ```text
//! cargo eval probe_trust                     # report to stdout
//! cargo eval probe_trust -- --out docs       # also writes docs/probe_trust.md
//! cargo eval probe_trust -- --csv rows.csv a.hdr b.hdr
//! ```
//!
//! # What it measures
//! Luminance probes of the crate's sphere SF set (seeded random rotations, nearest-pixel
//! samples) on the `clamp` and `smooth` tiers of each map (`eval/src/bin/accuracy.rs` defines them),
//! queried for irradiance and the normalised Phong lobe (`e` = 5, 20, 100) about seeded random
//! axes; truth summed over every pixel. The engine is f64 and independent of the crate: every
//! kernel `k(t) = Σ a_l (2l + 1)/(4π)·P_l(t)` (256 degrees, normalised to `k(1) = 1`),
//! `Q = K + σ′²I`, the GLS constant mean, `zᵢ = Σ a_l Λ_l (2l + 1)/(4π)·P_l(xᵢ·n)` with the
//! query's Funk–Hecke gains `Λ_l`, and the exact posterior variance.
//!
//! 1. **Member choice** (N = 16, 32, 64): rules that pick (or weigh) a kernel per probe,
//!    against the cheap peers that see the same samples (cosine- or lobe-weighted average, SH
//!    L2). Per map, the ratio of the rule's relative RMSE to the smaller of the two peers'; the
//!    tables give the mean of the per-map ratios, the ratio of the mean errors and the worst
//!    map, over the held-out maps.
//! 2. **Calibration** (N = 16 … 256, the baked family of `tables/probe.txt` with the crate's
//!    rule): the REML error bar `σ̂_f²·v(n)` is too narrow on real maps (aliasing is not in
//!    the model). Per size, member and query the factor `c` that makes 95 % of the training
//!    maps' errors fall within `2√(c·σ̂_f²·v)` (both tiers pooled); the held-out maps check it.
//!    `cargo writer probe_calibration` fits the same factors and stores them as
//!    `calibration = …` lines in `tables/probe.txt`, which the build script bakes into the probe
//!    (`Probe::irradiance` and the glossy queries multiply their variance by them).
//!
//! Training maps are those whose file stem is apartment, bridge, forest or lab (`--train`);
//! the others are held out. Without training maps the calibration in `tables/probe.txt` is
//! checked instead of fitted.

use std::error::Error;
use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use sphere_quadrature_eval::cli;
use sphere_quadrature_eval::probe_trust::{csv_rows, render, run, Setup};

/// probe trust (issue #13): member choice and error-bar calibration
#[derive(Clone, Parser)]
#[command(bin_name = "cargo eval probe_trust --")]
struct Args {
    #[command(flatten)]
    maps: cli::AllMaps,
    /// Rows
    /// probe_trust,<part>,<tier>,<query>,<n>,<method>,<map>,<rel_rmse>,<coverage2s>
    #[arg(long, value_name = "FILE", verbatim_doc_comment)]
    csv: Option<PathBuf>,
    /// Also write DIR/probe_trust.md (`--out docs` updates the docs)
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    #[command(flatten)]
    train: cli::Train,
    /// Random probe rotations per map
    #[arg(long, value_name = "R", default_value_t = 16, value_parser = cli::positive)]
    rotations: usize,
    /// Query axes per map
    #[arg(long, value_name = "Q", default_value_t = 64, value_parser = cli::positive)]
    normals: usize,
    /// Two maps, N = 16 and 32, four rotations, 16 axes (CI)
    #[arg(long)]
    quick: bool,
    #[command(flatten)]
    threads: cli::Threads,
}

/// The arguments, defaults filled in.
fn parse_args() -> Result<Args, Box<dyn Error>> {
    let mut a = Args::parse();
    if a.maps.maps.is_empty() {
        a.maps.maps = cli::all_bundled_maps_or(a.quick, ["apartment", "lobby"])?;
    }
    if a.quick {
        a.rotations = a.rotations.min(4);
        a.normals = a.normals.min(16);
    }
    Ok(a)
}

fn main() {
    cli::run_main("probe_trust", parse_args, report);
}

fn report(args: &Args) -> Result<(), Box<dyn Error>> {
    let start = Instant::now();
    let setup = Setup {
        maps: args.maps.maps.clone(),
        train: args.train.train.clone(),
        rotations: args.rotations,
        normals: args.normals,
        quick: args.quick,
        threads: args.threads.count(),
    };
    let result = run(&setup)?;
    let report = render(&setup, &result, start.elapsed().as_secs_f64());
    print!("{report}");
    if let Some(csv) = &args.csv {
        if let Some(dir) = csv.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(csv, csv_rows(&result))?;
        eprintln!("wrote {}", csv.display());
    }
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)?;
        let path = dir.join("probe_trust.md");
        std::fs::write(&path, &report)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
