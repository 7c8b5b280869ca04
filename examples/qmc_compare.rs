//! Irradiance and glossy radiance from real environment maps with three estimators at
//! N = 16…256, against ground truth integrated over every pixel.
//!
//! ```text
//! cargo run --release --example qmc_compare                   # two bundled maps
//! cargo run --release --example qmc_compare -- --all          # all ten bundled maps
//! cargo run --release --example qmc_compare -- a.hdr b.hdr    # your own maps
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
//! Then the **probe form** on the `clamp` tier: one `sphere_quadrature::probe::Probe` of N
//! samples (16 seeded random rotations of the set per map) answers every query — irradiance
//! about the normals and Phong glossy (`SphericalGaussian::phong_moments`) about the
//! reflection directions — next to the weighted averages of the same N samples (the cheap
//! probe peer: weights `max(0, n·x)` and `max(0, r·x)ᵉ`), with the fraction of queries whose
//! error is within two posterior standard deviations (`irradiance_variance`,
//! `glossy_variance`).
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
use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::probe::{Probe, ProbeSize};
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::{Mat3, Vec3};

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

/// Probe-form sample counts and rotations per map.
const PROBE_NS: [usize; 3] = [16, 64, 256];
const ROTATIONS: usize = 16;

/// Squared errors (BMC, weighted average), Σ|truth|, count and 2σ hits, per kind.
#[derive(Clone, Copy, Default)]
struct ProbeSums {
    sq: [[f64; 2]; 2],
    truth: [f64; 2],
    count: [usize; 2],
    within: [usize; 2],
}

impl ProbeSums {
    /// `[BMC, average]` relative RMSE and the 2σ fraction of `kind`.
    fn report(&self, kind: usize) -> (f64, f64, f64) {
        let c = self.count[kind] as f64;
        let mean = self.truth[kind] / c;
        let rel = |sq: f64| (sq / c).sqrt() / mean;
        (rel(self.sq[kind][0]), rel(self.sq[kind][1]), self.within[kind] as f64 / c)
    }
}

fn v32(d: [f64; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

/// One probe per rotation: irradiance about `axes[0]`, Phong glossy about `axes[1]`.
fn probe_form<const N: usize>(
    map: &EnvMap,
    axes: [&[[f64; 3]]; 2],
    truth: [&[f64]; 2],
    rotations: &[Mat3],
) -> ProbeSums
where
    Size<N>: ProbeSize,
{
    let mut s = ProbeSums::default();
    for &rot in rotations {
        let mut probe = Probe::<N>::new();
        probe.set_rotation(rot).expect("a random rotation is orthonormal");
        let xs: Vec<[f64; 3]> =
            probe.directions().iter().map(|d| [d.x as f64, d.y as f64, d.z as f64]).collect();
        let ys: [f32; N] = std::array::from_fn(|j| luminance(map.radiance(xs[j])) as f32);
        probe.update(&ys).expect("finite samples");
        for kind in 0..2 {
            for (a, &t) in axes[kind].iter().zip(truth[kind]) {
                let (bmc, var, power) = if kind == 0 {
                    let n = v32(*a);
                    let e = probe.irradiance(n).expect("unit normal");
                    let var = probe.irradiance_variance(n).expect("unit normal");
                    (e.value as f64, var as f64, 1.0)
                } else {
                    let lobe = SphericalGaussian::phong_moments(v32(*a), PHONG_EXPONENT as f32)
                        .expect("valid lobe");
                    let g = probe.glossy(&lobe).expect("valid lobe").value;
                    (
                        g as f64,
                        probe.glossy_variance(&lobe).expect("valid lobe") as f64,
                        PHONG_EXPONENT,
                    )
                };
                let (mut num, mut den) = (0.0, 0.0);
                for (x, &y) in xs.iter().zip(&ys) {
                    let w = (a[0] * x[0] + a[1] * x[1] + a[2] * x[2]).max(0.0).powf(power);
                    num += w * y as f64;
                    den += w;
                }
                let scale = if kind == 0 { std::f64::consts::PI } else { 1.0 };
                let avg = if den > 0.0 { scale * num / den } else { 0.0 };
                s.sq[kind][0] += (bmc - t).powi(2);
                s.sq[kind][1] += (avg - t).powi(2);
                s.truth[kind] += t.abs();
                s.count[kind] += 1;
                s.within[kind] += usize::from((bmc - t).abs() <= 2.0 * var.sqrt());
            }
        }
    }
    s
}

fn print_probe_table(title: &str, rows: &[ProbeSums]) {
    println!(
        "
{title}"
    );
    println!(
        "{:>5} {:>11} {:>11} {:>8} {:>11} {:>11} {:>8}",
        "N", "BMC irr", "cos-avg", "2σ", "BMC glossy", "lobe-avg", "2σ"
    );
    for (n, r) in PROBE_NS.iter().zip(rows) {
        let (bd, ad, cd) = r.report(0);
        let (bg, ag, cg) = r.report(1);
        println!(
            "{n:>5} {:>10.3}% {:>10.3}% {:>7.0}% {:>10.3}% {:>10.3}% {:>7.0}%",
            100.0 * bd,
            100.0 * ad,
            100.0 * cd,
            100.0 * bg,
            100.0 * ag,
            100.0 * cg
        );
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
    let rotations: Vec<Mat3> = (0..ROTATIONS)
        .map(|_| {
            let m = rng.uniform_rotation();
            Mat3::from_rows(v32(m[0]), v32(m[1]), v32(m[2]))
        })
        .collect();
    // Probe form, pooled over the maps: squared errors summed, so the mean is per query.
    let mut probe_sums = [ProbeSums::default(); PROBE_NS.len()];
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
            let truth_by_kind: Vec<Vec<f64>> =
                (0..KINDS.len()).map(|k| truths(map, &pixel_weights[k])).collect();
            if TIERS[tier] == "clamp" {
                let t = [truth_by_kind[0].as_slice(), truth_by_kind[1].as_slice()];
                let a = [normals.as_slice(), reflections.as_slice()];
                let rows = [
                    probe_form::<16>(map, a, t, &rotations),
                    probe_form::<64>(map, a, t, &rotations),
                    probe_form::<256>(map, a, t, &rotations),
                ];
                print_probe_table(
                    &format!(
                        "{name} [clamp] probe form, one probe of N samples for all queries \
                         ({ROTATIONS} rotations): relative RMSE, and |error| ≤ 2σ"
                    ),
                    &rows,
                );
                for (sum, r) in probe_sums.iter_mut().zip(&rows) {
                    for kind in 0..2 {
                        for e in 0..2 {
                            sum.sq[kind][e] += r.sq[kind][e];
                        }
                        sum.truth[kind] += r.truth[kind];
                        sum.count[kind] += r.count[kind];
                        sum.within[kind] += r.within[kind];
                    }
                }
            }
            for (k, &kind) in KINDS.iter().enumerate() {
                let truth = &truth_by_kind[k];
                let rows: Vec<Errors> = NS
                    .iter()
                    .map(|&n| evaluate(map, kind, axes[k], truth, n, DRAWS, 7 + k as u64))
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
        print_probe_table(
            &format!(
                "all {} maps pooled [clamp] probe form: relative RMSE, and |error| ≤ 2σ",
                paths.len()
            ),
            &probe_sums,
        );
    }
    eprintln!("\n({:.1} s)", start.elapsed().as_secs_f64());
}
