//! Glossy accuracy of the lighting probe on real environment maps: the normalised Phong
//! radiance `∫ L(ω)·(e+1)/(2π)·max(0, r·ω)ᵉ dω` about random mirror directions `r`, from the N
//! samples of one probe, against ground truth summed over every pixel.
//!
//! ```text
//! cargo run --release --example glossy                  # ten bundled maps, report to stdout
//! cargo run --release --example glossy -- --out docs    # regenerates docs/glossy.md
//! cargo run --release --example glossy -- --quick --out target/glossy   # CI smoke run
//! cargo run --release --example glossy -- --l2-fit --out target/glossy  # phong_lobe instead
//! ```
//!
//! Estimators, all from the same N probe samples (the crate's sphere SF set under a random
//! rotation, 16 seeded rotations per map, RMSE pooled over rotations × 128 seeded random
//! directions; luminance):
//! - `BMC`: `Probe::glossy` with `SphericalGaussian::phong_moments(r, e)` (the SG with the
//!   Phong lobe's integral and first Legendre moment, `λ = e + 2`: the lobe mismatch is part of
//!   the measured error; `--l2-fit` uses `phong_lobe`, `λ = e + 1`, instead), after
//!   `Probe::update` (per-probe selection);
//! - `lobe-avg`: `Σ max(0, r·xⱼ)ᵉ·Yⱼ / Σ max(0, r·xⱼ)ᵉ`, the glossy twin of the
//!   cosine-weighted average;
//! - `SH L2`: projection on real SH up to l = 2 with weights 4π/N, convolved with the Phong
//!   lobe's zonal coefficients `1, (e+1)/(e+2), e/(e+3)`.
//!
//! Tiers `clamp` and `smooth` as in `examples/accuracy.rs` (`raw` suns and lamps are direct
//! light; a probe holds the rest). The probe's hyperparameters were trained on apartment,
//! bridge, forest and lab (irradiance only); the headline figures are means over the other six
//! maps. Error bars: fraction of queries with |error| ≤ 2σ, σ² from `Probe::glossy_variance`
//! (exact) and from `Probe::glossy` (the O(N) direction average).

#[allow(dead_code)]
#[path = "common/compare.rs"]
mod compare;
#[allow(dead_code)]
#[path = "common/tiers.rs"]
mod tiers;

use std::error::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use reference::sh::real_sh;
use reference::vec::dot;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::probe::{Probe, ProbeSize};
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::{Mat3, SphericalFibonacci, Vec3};

const ALL_MAPS: [&str; 10] =
    ["apartment", "bridge", "city", "dawn", "forest", "hall", "lab", "lobby", "night", "park"];
const TRAINING_MAPS: [&str; 4] = ["apartment", "bridge", "forest", "lab"];
const QUICK_MAPS: [&str; 2] = ["apartment", "lobby"];
const NS: [usize; 3] = [16, 64, 256];
const EXPONENTS: [f64; 3] = [5.0, 20.0, 100.0];
const TIERS: [&str; 2] = ["clamp", "smooth"];
const ESTIMATORS: [&str; 3] = ["BMC", "lobe-avg", "SH L2"];
const SEED_DIRECTIONS: u64 = 0x6105_0001;
const SEED_ROTATIONS: u64 = 0x6105_0002;

/// Per exponent, per direction, per pixel: the Phong truth weights of one grid size.
type WeightSets = Vec<Vec<Vec<f64>>>;

/// Squared errors, |truth| and 2σ hits of one (tier, map, N, e), per estimator.
#[derive(Clone, Default)]
struct Sums {
    sq: [f64; 3],
    truth: f64,
    count: usize,
    within: usize,
    within_fast: usize,
}

fn vec32(d: [f64; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

/// Real SH `Y_{l,m}(d)`, l ≤ 2, at index `l(l+1) + m`, with the band of each index.
fn sh9(d: [f64; 3]) -> [(usize, f64); 9] {
    std::array::from_fn(|i| {
        let l = match i {
            0 => 0,
            1..=3 => 1,
            _ => 2,
        };
        (l, real_sh(l, i as i64 - (l * (l + 1)) as i64, d))
    })
}

/// One map and tier at one N: `sums[e]` over all rotations and directions.
fn evaluate<const N: usize>(
    map: &EnvMap,
    truths: &[Vec<f64>],
    dirs: &[[f64; 3]],
    rotations: &[Mat3],
    l2_fit: bool,
) -> Vec<Sums>
where
    Size<N>: ProbeSize,
{
    let mut sums = vec![Sums::default(); EXPONENTS.len()];
    for &rot in rotations {
        let mut probe = Probe::<N>::new();
        probe.set_rotation(rot).expect("a random rotation is orthonormal");
        let xs: Vec<[f64; 3]> = SphericalFibonacci::<N>::new()
            .with_rotation(rot)
            .points()
            .iter()
            .map(|d| [d.x as f64, d.y as f64, d.z as f64])
            .collect();
        let ys: [f32; N] = std::array::from_fn(|j| luminance(map.radiance(xs[j])) as f32);
        probe.update(&ys).expect("finite samples");
        let mut sh = [0.0f64; 9];
        for (x, &y) in xs.iter().zip(&ys) {
            for (c, (_, v)) in sh.iter_mut().zip(sh9(*x)) {
                *c += 4.0 * std::f64::consts::PI / N as f64 * y as f64 * v;
            }
        }
        for ((&e, s), truth) in EXPONENTS.iter().zip(&mut sums).zip(truths) {
            let zonal = [1.0, (e + 1.0) / (e + 2.0), e / (e + 3.0)];
            for (r, &t) in dirs.iter().zip(truth) {
                let lobe = if l2_fit {
                    SphericalGaussian::phong_lobe(vec32(*r), e as f32)
                } else {
                    SphericalGaussian::phong_moments(vec32(*r), e as f32)
                }
                .expect("valid lobe");
                let g = probe.glossy(&lobe).expect("valid lobe");
                let (bmc, fast) = (g.value as f64, g.variance as f64);
                let var = probe.glossy_variance(&lobe).expect("valid lobe") as f64;
                let (mut num, mut den) = (0.0, 0.0);
                for (x, &y) in xs.iter().zip(&ys) {
                    let w = dot(*r, *x).max(0.0).powf(e);
                    num += w * y as f64;
                    den += w;
                }
                let avg = if den > 0.0 { num / den } else { 0.0 };
                let shl2: f64 = sh.iter().zip(sh9(*r)).map(|(c, (l, v))| zonal[l] * c * v).sum();
                for (k, est) in [bmc, avg, shl2].into_iter().enumerate() {
                    s.sq[k] += (est - t).powi(2);
                }
                s.truth += t.abs();
                s.count += 1;
                s.within += usize::from((bmc - t).abs() <= 2.0 * var.sqrt());
                s.within_fast += usize::from((bmc - t).abs() <= 2.0 * fast.sqrt());
            }
        }
    }
    sums
}

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    let l2_fit = args.iter().any(|a| a == "--l2-fit");
    let out =
        args.iter().position(|a| a == "--out").and_then(|i| args.get(i + 1)).map(PathBuf::from);
    let names: &[&str] = if quick { &QUICK_MAPS } else { &ALL_MAPS };
    let (n_dirs, n_rot) = if quick { (32, 4) } else { (128, 16) };
    let start = std::time::Instant::now();

    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/envmaps");
    let mut rng = Rng::new(SEED_DIRECTIONS);
    let dirs: Vec<[f64; 3]> = (0..n_dirs).map(|_| rng.uniform_sphere()).collect();
    let mut rng = Rng::new(SEED_ROTATIONS);
    let rotations: Vec<Mat3> = (0..n_rot)
        .map(|_| {
            let r = rng.uniform_rotation();
            let row = |v: [f64; 3]| vec32(v);
            Mat3::from_rows(row(r[0]), row(r[1]), row(r[2]))
        })
        .collect();

    // (tier, map) scenes.
    let mut scenes: Vec<(usize, usize, EnvMap)> = Vec::new();
    for (m, name) in names.iter().enumerate() {
        let raw = EnvMap::load(dir.join(format!("{name}.hdr")))?;
        let clamp = compare::clamped(&raw);
        let smooth = tiers::smooth(&clamp);
        scenes.push((0, m, clamp));
        scenes.push((1, m, smooth));
    }
    // Phong truth weights per grid size and exponent (one set serves every map of that size).
    let mut truths: Vec<Vec<Vec<f64>>> = Vec::new();
    let mut weight_cache: Vec<((usize, usize), WeightSets)> = Vec::new();
    for (_, _, map) in &scenes {
        let size = (map.width, map.height);
        if !weight_cache.iter().any(|(s, _)| *s == size) {
            let w = EXPONENTS
                .iter()
                .map(|&e| compare::weights(compare::Kind::Glossy(e), &dirs, size.0, size.1))
                .collect();
            weight_cache.push((size, w));
        }
        let w = &weight_cache.iter().find(|(s, _)| *s == size).expect("cached").1;
        truths.push(w.iter().map(|we| compare::truths(map, we)).collect());
    }
    drop(weight_cache);

    // sums[scene][n][e], the scenes split over the cores.
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let jobs: Vec<usize> = (0..scenes.len()).collect();
    let chunk = jobs.len().div_ceil(threads).max(1);
    let results: Vec<(usize, Vec<Vec<Sums>>)> = std::thread::scope(|scope| {
        let handles: Vec<_> = jobs
            .chunks(chunk)
            .map(|part| {
                let (scenes, truths, dirs, rotations) = (&scenes, &truths, &dirs, &rotations);
                scope.spawn(move || {
                    part.iter()
                        .map(|&i| {
                            let (map, t) = (&scenes[i].2, &truths[i]);
                            let per_n = vec![
                                evaluate::<16>(map, t, dirs, rotations, l2_fit),
                                evaluate::<64>(map, t, dirs, rotations, l2_fit),
                                evaluate::<256>(map, t, dirs, rotations, l2_fit),
                            ];
                            (i, per_n)
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("worker")).collect()
    });

    let mut md = String::new();
    writeln!(md, "# Glossy accuracy of the probe on environment maps\n")?;
    writeln!(
        md,
        "`cargo run --release --example glossy{}{}` ({:.0} s). Normalised Phong radiance about {n_dirs} \
         seeded random mirror directions per map, {n_rot} probe rotations per map, relative RMSE \
         of luminance (RMSE / mean |truth|) against every-pixel ground truth; estimators and \
         tiers in the example's header. Held-out maps (not used to train the probe's \
         hyperparameters): {}.\n",
        if quick { " -- --quick" } else { "" },
        if l2_fit { " -- --l2-fit" } else { "" },
        start.elapsed().as_secs_f64(),
        names.iter().filter(|n| !TRAINING_MAPS.contains(n)).copied().collect::<Vec<_>>().join(", ")
    )?;
    for (ti, tier) in TIERS.iter().enumerate() {
        writeln!(md, "## {tier}\n")?;
        writeln!(
            md,
            "| N | e | {} | BMC / best peer | worst map ratio | within 2σ (exact, O(N)) |",
            ESTIMATORS.join(" | ")
        )?;
        writeln!(md, "| ---: | ---: | ---: | ---: | ---: | ---: | --- | ---: |")?;
        for (ni, n) in NS.iter().enumerate() {
            for (ei, e) in EXPONENTS.iter().enumerate() {
                let mut mean = [0.0f64; 3];
                let mut held = 0usize;
                let mut worst = (0.0f64, "");
                let (mut within, mut within_fast, mut count) = (0usize, 0usize, 0usize);
                for (i, per_n) in &results {
                    let (t, m, _) = &scenes[*i];
                    if *t != ti {
                        continue;
                    }
                    let s = &per_n[ni][ei];
                    let rel: Vec<f64> =
                        s.sq.iter()
                            .map(|sq| (sq / s.count as f64).sqrt() / (s.truth / s.count as f64))
                            .collect();
                    let ratio = rel[0] / rel[1].min(rel[2]);
                    if ratio > worst.0 {
                        worst = (ratio, names[*m]);
                    }
                    within += s.within;
                    within_fast += s.within_fast;
                    count += s.count;
                    if quick || !TRAINING_MAPS.contains(&names[*m]) {
                        for (a, r) in mean.iter_mut().zip(&rel) {
                            *a += r;
                        }
                        held += 1;
                    }
                }
                let mean = mean.map(|x| x / held.max(1) as f64);
                writeln!(
                    md,
                    "| {n} | {e} | {:.1}% | {:.1}% | {:.1}% | **{:.3}** | {:.3} ({}) | {:.0}%, {:.0}% |",
                    100.0 * mean[0],
                    100.0 * mean[1],
                    100.0 * mean[2],
                    mean[0] / mean[1].min(mean[2]),
                    worst.0,
                    worst.1,
                    100.0 * within as f64 / count.max(1) as f64,
                    100.0 * within_fast as f64 / count.max(1) as f64
                )?;
            }
        }
        writeln!(md)?;
    }
    writeln!(
        md,
        "Columns: means over the held-out maps; `BMC / best peer` is the ratio of those means to \
         the better of lobe-avg and SH L2; `worst map ratio` is the largest per-map ratio over \
         all maps; the 2σ column pools all maps."
    )?;
    print!("{md}");
    if let Some(out) = out {
        std::fs::create_dir_all(&out)?;
        let path = out.join(if l2_fit { "glossy_l2_fit.md" } else { "glossy.md" });
        std::fs::write(&path, &md)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
