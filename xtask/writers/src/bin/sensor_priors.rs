//! The learned priors of the crate's sensor layouts (`tables/sensor_priors.rs`, included by `src/layout/learned.rs`).
//!
//! ```text
//! cargo writer sensor_priors             # check the committed file
//! cargo writer sensor_priors -- --write  # regenerate it
//! cargo xtask regen sensor-priors        # regenerate it, in the pipeline's order
//! ```
//!
//! From the bundled training maps (apartment, bridge, forest, lab), per lighting tier (`clamp`
//! for the defaults, `smooth`): the mean SH power spectrum of luminance over its mean, the
//! prior of light from above (flat to degree 2 with the maps' zonal correlations, the spectrum
//! above it) and the variance factors of that prior and of the one-sided one (leave one map
//! out, on the upward layouts of the `sensors` benchmark); in f64, rounded once to f32
//! (`sphere_quadrature_eval::sensors::learned_priors`, which the benchmark shares). Without
//! `--write` it regenerates the file in memory and fails if the committed one differs (CI
//! runs it that way).

use std::process::ExitCode;

use clap::Parser;
use sphere_quadrature_eval::cli;
use sphere_quadrature_eval::sensors::{learned_priors, LEARNED};

/// sensor_priors: the learned priors of the sensor layouts, checked against (or, with
/// --write, written to) tables/sensor_priors.rs
#[derive(Parser)]
#[command(bin_name = "cargo writer sensor_priors --", verbatim_doc_comment)]
struct Args {
    /// Regenerate tables/sensor_priors.rs instead of checking that it is current
    #[arg(long)]
    write: bool,
    #[command(flatten)]
    threads: cli::Threads,
}

fn main() -> ExitCode {
    let args = Args::parse();
    let text = match learned_priors(args.threads.count()) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("sensor_priors: {e}");
            return ExitCode::FAILURE;
        }
    };
    let path = cli::repo_root().join(LEARNED);
    if args.write {
        if let Err(e) = std::fs::write(&path, &text) {
            eprintln!("sensor_priors: {}: {e}", path.display());
            return ExitCode::FAILURE;
        }
        println!("wrote {LEARNED}");
    } else if std::fs::read_to_string(&path).ok().as_deref() != Some(text.as_str()) {
        eprintln!(
            "sensor_priors: {LEARNED} is not what the training maps give: run \
             cargo writer sensor_priors -- --write"
        );
        return ExitCode::FAILURE;
    } else {
        println!("{LEARNED} is current");
    }
    ExitCode::SUCCESS
}
