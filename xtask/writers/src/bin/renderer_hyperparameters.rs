//! The renderer's Gaussian-process hyperparameters `(l, σ′)` per (BRDF key, N), learned on the
//! training maps (apartment, bridge, forest, lab) for the sample sets and the f64 engine of the
//! renderer benchmark (`cargo eval renderer`, `eval/src/bin/renderer.rs`), which reads them.
//!
//! ```text
//! cargo writer renderer_hyperparameters             # target/eval/renderer_hyperparameters/
//! cargo writer renderer_hyperparameters -- --write  # tables/renderer_hyperparameters.txt
//! cargo xtask regen renderer-hyperparameters        # the write, in the pipeline's order
//! ```
//!
//! Three fits per key and N, on the luminance at the benchmark's BMC-SF samples of its seeded
//! queries (`src/renderer_hyperparameters.rs`): `ml`, maximum restricted (REML) marginal
//! likelihood with σ_f profiled out, over the clamp tier; `cov`, the seed's covariance fit;
//! `err` (keys `diffuse-cos` and `phongE`), the grid point whose estimates have the smallest
//! geometric mean, over the clamp and smooth tiers, of RMSE(BMC)/RMSE(QMC on the same
//! samples): the rows the crate bakes (`tables/bmc.txt`, `tables/glossy.txt`). Several
//! CPU-minutes. The file's header gives the grids and the training data; the REML surfaces go
//! to `--out DIR/renderer_reml_surfaces.txt`.

use std::error::Error;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use reference::envmap::EnvMap;
use sphere_quadrature_eval::renderer::scenes::Scene;
use sphere_quadrature_eval::renderer::{l_grid, CLAMP, HYPER_FILE, KEYS, NS, SEED_QUERIES, SMOOTH};
use sphere_quadrature_eval::{cli, compare, renderer_engine as engine, tiers};
use xtask_writers::renderer_hyperparameters::{hyper_file_text, learn, learn_err};

use cli::TRAINING_MAPS;

/// renderer_hyperparameters: learns the renderer benchmark's (l, σ′) per (BRDF, N) on the
/// training maps' clamp tier (REML, the seed's covariance fit, and the error-minimising fit)
#[derive(Parser)]
#[command(bin_name = "cargo writer renderer_hyperparameters --", verbatim_doc_comment)]
struct Cli {
    /// Equirectangular .hdr maps (default: the training maps apartment, bridge,
    /// forest and lab in examples/envmaps/; only training maps are read)
    #[arg(value_name = "MAPS", value_parser = cli::map_file, verbatim_doc_comment)]
    maps: Vec<PathBuf>,
    /// Output directory of the hyperparameter file without --write, and of the
    /// REML surfaces (default target/eval/renderer_hyperparameters)
    #[arg(long, value_name = "DIR", verbatim_doc_comment)]
    out: Option<PathBuf>,
    /// Write the learned rows to --hyper-file
    #[arg(long)]
    write: bool,
    /// The hyperparameter file --write writes (default tables/renderer_hyperparameters.txt)
    #[arg(long, value_name = "FILE")]
    hyper_file: Option<PathBuf>,
    /// Queries per map
    #[arg(long, value_name = "Q", default_value_t = 256, value_parser = cli::positive)]
    queries: usize,
    #[command(flatten)]
    threads: cli::Threads,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let c = Cli::parse();
    let start = Instant::now();
    let root = cli::repo_root();
    let threads = c.threads.count();
    let out = c.out.unwrap_or_else(|| cli::default_out("renderer_hyperparameters"));
    let hyper_file = c.hyper_file.unwrap_or_else(|| root.join(HYPER_FILE));
    let paths = if c.maps.is_empty() { cli::bundled_maps(&TRAINING_MAPS) } else { c.maps };
    let names: Vec<String> = paths.iter().map(|p| cli::map_name(p)).collect();
    let clamped: Vec<EnvMap> = paths
        .iter()
        .map(EnvMap::load)
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| format!("cannot load a map: {e}"))?
        .iter()
        .map(compare::clamped)
        .collect();
    let queries = engine::queries(c.queries, SEED_QUERIES);

    let mut learned = learn(threads, &names, &clamped, &queries);
    if learned.is_empty() {
        return Err("no training maps among the inputs".into());
    }
    // The error-minimising fit on the training maps' clamp and smooth tiers, for the sets
    // the crate bakes (cosine-morphed for diffuse, lobe-morphed for Phong).
    let mut training: Vec<Scene> = Vec::new();
    for (n, m) in names.iter().zip(&clamped) {
        if TRAINING_MAPS.contains(&n.as_str()) {
            training.push(Scene::map(CLAMP, n, m.clone()));
            training.push(Scene::map(SMOOTH, n, tiers::smooth(m)));
        }
    }
    for &(key, _, _) in KEYS.iter().filter(|k| k.0 != "diffuse") {
        for ((_, fit), lr) in NS
            .iter()
            .zip(learn_err(threads, key, &training, &queries))
            .zip(learned.iter_mut().filter(|lr| lr.key == key))
        {
            lr.err = Some(fit);
        }
    }
    let command = format!("cargo writer renderer_hyperparameters -- {}", args.join(" "));
    let text = hyper_file_text(&learned, &command, &names, queries.len());
    let path = if c.write { hyper_file } else { out.join("renderer_hyperparameters.txt") };
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(&path, &text)?;
    print!("{text}");
    // The REML surfaces, for the record.
    let mut md = String::new();
    for lr in &learned {
        let _ = writeln!(md, "{} N = {}: ℓ − ℓ_max over l (rows) × σ′ (columns)", lr.key, lr.n);
        let best = lr.surface.iter().flatten().copied().fold(f64::NEG_INFINITY, f64::max);
        for (a, row) in lr.surface.iter().enumerate() {
            let cells: Vec<String> = row.iter().map(|v| format!("{:9.1}", v - best)).collect();
            let _ = writeln!(md, "  l = {:.4}: {}", l_grid()[a], cells.join(" "));
        }
    }
    std::fs::create_dir_all(&out)?;
    std::fs::write(out.join("renderer_reml_surfaces.txt"), md)?;
    eprintln!("wrote {} ({:.1} s)", path.display(), start.elapsed().as_secs_f64());
    Ok(())
}
