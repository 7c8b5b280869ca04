//! Irradiance and glossy radiance from a real environment map with three estimators at
//! N = 16…256, against ground truth summed over every pixel.
//!
//! ```text
//! cargo run --release --example probe                   # two bundled maps
//! cargo run --release --example probe -- --all          # all ten bundled maps
//! cargo run --release --example probe -- a.hdr b.hdr    # your own maps
//! ```
//!
//! Two lighting tiers per map: `raw` (as loaded) and `clamp` (luminance clamped at 30× the
//! map's solid-angle mean: suns and lamps are direct light that renderers sample separately;
//! no point-sampling estimator integrates a source 900× brighter than the mean with 256
//! samples). The default maps are `apartment` (nothing above 30× the mean) and `lobby`
//! (lamps holding 16 % of its energy above 30× the mean).
//!
//! For each map: 64 seeded random normals (and as many random reflection directions for a
//! normalised Phong lobe of exponent 20), each estimated 16 times with independent
//! randomisation (the RMSE is over all 1024 estimates). Estimators, all on the nearest-pixel radiance:
//! - `MC`: independent random cosine- (or lobe-) distributed directions per query;
//! - `Sobol`: Owen-scrambled Sobol (0,2) points (`sobol_burley`, a new scramble seed per
//!   query), mapped through the same lobe morph;
//! - `QMC-SF`: this crate's hemisphere spherical Fibonacci set with the lobe morph and a random
//!   rotation about the axis per query.
//!
//! Printed: relative RMSE of luminance = RMSE over the queries / mean |truth|, per map and
//! averaged over the maps.

use std::path::{Path, PathBuf};
use std::time::Instant;

use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use sphere_quadrature::qmc::LobeSampler;
use sphere_quadrature::{Lobe, RotationSequence, Vec3};

const NS: [usize; 5] = [16, 32, 64, 128, 256];
const QUERIES: usize = 64;
/// Independent draws per query (random rotation for SF, scramble for Sobol, sample for MC).
const DRAWS: usize = 16;
const PHONG_EXPONENT: f64 = 20.0;
const DEFAULT_MAPS: [&str; 2] = ["apartment", "lobby"];
const CLAMP: f64 = 30.0;
const ALL_MAPS: [&str; 10] =
    ["apartment", "bridge", "city", "dawn", "forest", "hall", "lab", "lobby", "night", "park"];

#[derive(Clone, Copy)]
enum Kind {
    Diffuse,
    Glossy,
}

impl Kind {
    fn lobe(self) -> Lobe {
        match self {
            Kind::Diffuse => Lobe::Cosine,
            Kind::Glossy => Lobe::Phong(PHONG_EXPONENT as f32),
        }
    }
    /// The estimate is `scale · mean(L)`: π for irradiance, 1 for the normalised Phong lobe.
    fn scale(self) -> f64 {
        match self {
            Kind::Diffuse => std::f64::consts::PI,
            Kind::Glossy => 1.0,
        }
    }
    fn exponent(self) -> f64 {
        match self {
            Kind::Diffuse => 1.0,
            Kind::Glossy => PHONG_EXPONENT,
        }
    }
}

fn luminance_at(map: &EnvMap, d: [f64; 3]) -> f64 {
    luminance(map.radiance(d))
}

/// A lobe direction from a point of the unit square: cos θ′ = u₁^(1/(e+1)), φ = 2π·u₂.
fn lobe_dir(axis: [f64; 3], e: f64, u1: f64, u2: f64) -> [f64; 3] {
    let c = u1.powf(1.0 / (e + 1.0));
    let s = (1.0 - c * c).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * u2;
    let (t, b) = reference::vec::frame(axis);
    let l = [s * phi.cos(), s * phi.sin(), c];
    std::array::from_fn(|k| l[0] * t[k] + l[1] * b[k] + l[2] * axis[k])
}

/// The map with each pixel's luminance clamped at `CLAMP` × the solid-angle mean (hue kept).
fn clamped(map: &EnvMap) -> EnvMap {
    let limit = CLAMP * luminance(map.mean_radiance());
    let pixels = map
        .pixels
        .iter()
        .map(|p| {
            let l = luminance([p[0] as f64, p[1] as f64, p[2] as f64]);
            if l > limit {
                let s = (limit / l) as f32;
                [p[0] * s, p[1] * s, p[2] * s]
            } else {
                *p
            }
        })
        .collect();
    EnvMap { width: map.width, height: map.height, pixels }
}

/// Per-pixel integration weights of every query axis (computed once, on all cores, and
/// shared by every map and tier: the ground truth of a map is then Σ weight × luminance).
fn weights(kind: Kind, axes: &[[f64; 3]], width: usize, height: usize) -> Vec<Vec<f64>> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let chunk = axes.len().div_ceil(threads);
    std::thread::scope(|scope| {
        let handles: Vec<_> = axes
            .chunks(chunk)
            .map(|part| {
                scope.spawn(move || {
                    part.iter()
                        .map(|&a| match kind {
                            Kind::Diffuse => reference::truth::cosine_weights(width, height, a),
                            Kind::Glossy => {
                                reference::truth::phong_weights(width, height, a, PHONG_EXPONENT)
                            }
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("weights thread")).collect()
    })
}

/// Ground-truth luminance integral of `map` for every axis.
fn truths(map: &EnvMap, weights: &[Vec<f64>]) -> Vec<f64> {
    let lum: Vec<f64> =
        map.pixels.iter().map(|p| luminance([p[0] as f64, p[1] as f64, p[2] as f64])).collect();
    weights.iter().map(|w| w.iter().zip(&lum).map(|(a, b)| a * b).sum()).collect()
}

struct Row {
    mc: f64,
    sobol: f64,
    sf: f64,
}

fn evaluate(map: &EnvMap, kind: Kind, axes: &[[f64; 3]], truth: &[f64], seed: u64) -> Vec<Row> {
    let mean_abs = truth.iter().map(|t| t.abs()).sum::<f64>() / truth.len() as f64;
    let rel_rmse = |se: f64| (se / (truth.len() * DRAWS) as f64).sqrt() / mean_abs;
    let e = kind.exponent();
    NS.iter()
        .map(|&n| {
            let mut rng = Rng::new(seed ^ n as u64);
            let mut seq = RotationSequence::new(seed.wrapping_add(n as u64));
            let (mut se_mc, mut se_sobol, mut se_sf) = (0.0, 0.0, 0.0);
            for (q, (&axis, &t)) in axes.iter().zip(truth).enumerate() {
                let axis32 = Vec3::new(axis[0] as f32, axis[1] as f32, axis[2] as f32);
                for draw in 0..DRAWS {
                    let mc: f64 = (0..n)
                        .map(|_| {
                            luminance_at(map, lobe_dir(axis, e, rng.next_f64(), rng.next_f64()))
                        })
                        .sum::<f64>()
                        * kind.scale()
                        / n as f64;
                    let scramble = (seed as u32)
                        ^ ((q * DRAWS + draw) as u32).wrapping_mul(0x9E37_79B9)
                        ^ n as u32;
                    let sobol: f64 = (0..n as u32)
                        .map(|i| {
                            let u1 = sobol_burley::sample(i, 0, scramble) as f64;
                            let u2 = sobol_burley::sample(i, 1, scramble) as f64;
                            luminance_at(map, lobe_dir(axis, e, u1, u2))
                        })
                        .sum::<f64>()
                        * kind.scale()
                        / n as f64;
                    let sampler = LobeSampler::new(axis32, kind.lobe(), n, seq.next_phase())
                        .expect("unit axis and valid lobe");
                    let sf: f64 = sampler.integrate(|d| {
                        luminance_at(map, [d.x as f64, d.y as f64, d.z as f64]) as f32
                    }) as f64
                        * kind.scale()
                        / kind.lobe().integral() as f64;
                    se_mc += (mc - t).powi(2);
                    se_sobol += (sobol - t).powi(2);
                    se_sf += (sf - t).powi(2);
                }
            }
            Row { mc: rel_rmse(se_mc), sobol: rel_rmse(se_sobol), sf: rel_rmse(se_sf) }
        })
        .collect()
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

    // Every bundled map is 512×256; other sizes get their own weights.
    let mut cache: Option<((usize, usize), [Vec<Vec<f64>>; 2])> = None;
    // sums[tier][kind][n] = [MC, Sobol, SF] relative RMSE summed over maps.
    let mut sums = [[[[0.0f64; 3]; NS.len()]; 2]; 2];
    for path in &paths {
        let raw = match EnvMap::load(path) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("cannot load {}: {e}", path.display());
                std::process::exit(1);
            }
        };
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let size = (raw.width, raw.height);
        if cache.as_ref().is_none_or(|(s, _)| *s != size) {
            let w = [
                weights(Kind::Diffuse, &normals, size.0, size.1),
                weights(Kind::Glossy, &reflections, size.0, size.1),
            ];
            cache = Some((size, w));
        }
        let Some((_, pixel_weights)) = &cache else { unreachable!() };
        for (tier, map) in [raw.clone(), clamped(&raw)].iter().enumerate() {
            for (k, kind) in [Kind::Diffuse, Kind::Glossy].into_iter().enumerate() {
                let axes: &[[f64; 3]] = match kind {
                    Kind::Diffuse => &normals,
                    Kind::Glossy => &reflections,
                };
                let truth = truths(map, &pixel_weights[k]);
                let rows = evaluate(map, kind, axes, &truth, 7 + k as u64);
                println!(
                    "\n{name} [{}] {}: relative RMSE over {QUERIES} queries × {DRAWS} draws",
                    TIERS[tier], LABELS[k]
                );
                print_header();
                for ((n, r), s) in NS.iter().zip(&rows).zip(sums[tier][k].iter_mut()) {
                    print_row(*n, [r.mc, r.sobol, r.sf]);
                    s[0] += r.mc;
                    s[1] += r.sobol;
                    s[2] += r.sf;
                }
            }
        }
    }
    if paths.len() > 1 {
        let m = paths.len() as f64;
        for (tier, per_kind) in sums.iter().enumerate() {
            for (k, per_n) in per_kind.iter().enumerate() {
                println!(
                    "\nmean over {} maps [{}] {}: relative RMSE",
                    paths.len(),
                    TIERS[tier],
                    LABELS[k]
                );
                print_header();
                for (n, s) in NS.iter().zip(per_n) {
                    print_row(*n, [s[0] / m, s[1] / m, s[2] / m]);
                }
            }
        }
    }
    eprintln!("\n({:.1} s)", start.elapsed().as_secs_f64());
}

const TIERS: [&str; 2] = ["raw", "clamp"];
const LABELS: [&str; 2] = ["irradiance", "Phong e=20"];

fn print_header() {
    println!("{:>5} {:>10} {:>10} {:>10}", "N", "MC", "Sobol", "QMC-SF");
}

fn print_row(n: usize, r: [f64; 3]) {
    println!("{n:>5} {:>9.3}% {:>9.3}% {:>9.3}%", 100.0 * r[0], 100.0 * r[1], 100.0 * r[2]);
}
