//! Irradiance and glossy radiance from real environment maps with three estimators at
//! N = 16…256, against ground truth integrated over every pixel.
//!
//! ```text
//! cargo run --release --example probe                   # two bundled maps
//! cargo run --release --example probe -- --all          # all ten bundled maps
//! cargo run --release --example probe -- a.hdr b.hdr    # your own maps
//! ```
//!
//! For each map: 64 seeded random normals (and as many random reflection directions for a
//! normalised Phong lobe of exponent 20), each estimated 16 times with independent
//! randomisation (the RMSE is over all 1024 estimates). Estimators, all on the nearest-pixel
//! radiance:
//! - `MC`: independent random lobe-distributed directions;
//! - `Sobol`: Owen-scrambled Sobol (0,2) points (`sobol_burley`), a new scramble per
//!   estimate, mapped through the same lobe morph;
//! - `QMC-SF`: this crate's hemisphere spherical Fibonacci set with the lobe morph and a new
//!   random rotation about the axis per estimate.
//!
//! Printed: relative RMSE of luminance = RMSE / mean |truth|, per map and averaged over the
//! maps, in two lighting tiers: `raw` (as loaded) and `clamp` (luminance clamped at 30× the
//! map's solid-angle mean: suns and lamps are direct light that renderers sample separately,
//! and no point-sampling estimator integrates a source 900× brighter than the mean with 256
//! samples). The default maps are `apartment` (nothing above 30× its mean) and `lobby`
//! (lamps holding 16 % of its energy above 30× its mean).

#[path = "common/compare.rs"]
mod compare;

use std::path::{Path, PathBuf};
use std::time::Instant;

use compare::{clamped, evaluate, truths, weights, Errors, Kind};
use reference::envmap::EnvMap;
use reference::rng::Rng;

const NS: [usize; 5] = [16, 32, 64, 128, 256];
const QUERIES: usize = 64;
const DRAWS: usize = 16;
const PHONG_EXPONENT: f64 = 20.0;
const KINDS: [Kind; 2] = [Kind::Diffuse, Kind::Glossy(PHONG_EXPONENT)];
const LABELS: [&str; 2] = ["irradiance", "Phong e=20"];
const TIERS: [&str; 2] = ["raw", "clamp"];
const DEFAULT_MAPS: [&str; 2] = ["apartment", "lobby"];
const ALL_MAPS: [&str; 10] =
    ["apartment", "bridge", "city", "dawn", "forest", "hall", "lab", "lobby", "night", "park"];

/// Per kind, per query axis, per pixel.
type WeightsPerKind = Vec<Vec<Vec<f64>>>;

fn print_table(title: &str, rows: &[Errors]) {
    println!("\n{title}");
    println!("{:>5} {:>10} {:>10} {:>10}", "N", "MC", "Sobol", "QMC-SF");
    for (n, r) in NS.iter().zip(rows) {
        println!("{n:>5} {:>9.3}% {:>9.3}% {:>9.3}%", 100.0 * r.mc, 100.0 * r.sobol, 100.0 * r.sf);
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/envmaps");
    let paths: Vec<PathBuf> = if args.is_empty() || args == ["--all"] {
        let names: &[&str] = if args.is_empty() { &DEFAULT_MAPS } else { &ALL_MAPS };
        names.iter().map(|n| dir.join(format!("{n}.hdr"))).collect()
    } else {
        args.iter().map(PathBuf::from).collect()
    };

    let start = Instant::now();
    let mut rng = Rng::new(2024);
    let normals: Vec<[f64; 3]> = (0..QUERIES).map(|_| rng.uniform_sphere()).collect();
    let reflections: Vec<[f64; 3]> = (0..QUERIES).map(|_| rng.uniform_sphere()).collect();
    let axes = [&normals, &reflections];

    // Pixel weights depend only on the grid size: compute them once per size.
    let mut cache: Option<((usize, usize), WeightsPerKind)> = None;
    // sums[tier][kind][n]: relative RMSE summed over the maps.
    let mut sums = [[[Errors::default(); NS.len()]; 2]; 2];
    for path in &paths {
        let raw = EnvMap::load(path).unwrap_or_else(|e| {
            eprintln!("cannot load {}: {e}", path.display());
            std::process::exit(1);
        });
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let size = (raw.width, raw.height);
        if cache.as_ref().is_none_or(|(s, _)| *s != size) {
            let w = KINDS.iter().zip(axes).map(|(&k, a)| weights(k, a, size.0, size.1)).collect();
            cache = Some((size, w));
        }
        let Some((_, pixel_weights)) = &cache else { unreachable!("just filled") };
        for (tier, map) in [raw.clone(), clamped(&raw)].iter().enumerate() {
            for (k, &kind) in KINDS.iter().enumerate() {
                let truth = truths(map, &pixel_weights[k]);
                let rows: Vec<Errors> = NS
                    .iter()
                    .map(|&n| evaluate(map, kind, axes[k], &truth, n, DRAWS, 7 + k as u64))
                    .collect();
                let title = format!(
                    "{name} [{}] {}: relative RMSE over {QUERIES} queries × {DRAWS} draws",
                    TIERS[tier], LABELS[k]
                );
                print_table(&title, &rows);
                for (sum, r) in sums[tier][k].iter_mut().zip(&rows) {
                    sum.mc += r.mc / paths.len() as f64;
                    sum.sobol += r.sobol / paths.len() as f64;
                    sum.sf += r.sf / paths.len() as f64;
                }
            }
        }
    }
    if paths.len() > 1 {
        for (tier, per_kind) in sums.iter().enumerate() {
            for (k, rows) in per_kind.iter().enumerate() {
                let title = format!(
                    "mean over {} maps [{}] {}: relative RMSE",
                    paths.len(),
                    TIERS[tier],
                    LABELS[k]
                );
                print_table(&title, rows);
            }
        }
    }
    eprintln!("\n({:.1} s)", start.elapsed().as_secs_f64());
}
