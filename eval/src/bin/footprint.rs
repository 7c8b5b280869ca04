//! The footprint benchmark (issue #11): probes whose samples integrate a lobe (a mip level, a
//! cone, a photodiode) against point samples, on real environment maps.
//!
//! ```text
//! cargo eval footprint -- [MAPS…] \
//!     [--tier clamp|raw] [--csv FILE] [--out DIR] [--train a,b,c,d] [--rotations R] [--quick]
//! ```
//!
//! For every map (default: the ten in `examples/envmaps/`), `R` random rotations of the probe
//! (default 4), every `N ∈ {16, 32, 64, 128, 256}` and every baked footprint of that `N` (the
//! Gaussian of sharpness `S ∈ {N/16, N/8, N/4, N/2}`, and the photodiode `cos1` for
//! N ≤ 64), the samples are taken from the map exactly (`EquirectMap::footprint_samples`, the
//! integral over all pixels), and these estimators answer 64 irradiance queries and 64 glossy
//! queries (normalised Phong, `e ∈ {5, 20, 100}`, about mirror directions):
//!
//! - `bmc-footprint`: `Probe<N, f32, F>`, the model that knows the footprint;
//! - `bmc-point-model`: `Probe<N, f32>` (point model) on the same footprint samples;
//! - `cos-avg`: their cosine-weighted (irradiance) or lobe-weighted (glossy) average;
//! - `sh2-deconv`: SH L2 least squares of the same samples, each band divided by the
//!   footprint's gain `g_l`, then the clamped-cosine or Phong zonal factors;
//! - `point-cos-avg`, `point-bmc`: point samples (nearest pixel) in the same directions,
//!   their weighted average and the point probe (footprint column `point`).
//!
//! Truth is always the *unfiltered* map, integrated exactly over every pixel. Errors are the
//! relative RMSE of luminance (RMSE / mean |truth|) per map; the error bar's 2σ coverage is
//! reported for the BMC estimators (`Probe::phong`, the exact Phong-lobe query, with its O(1)
//! variance). The probes run on the luminance of the samples.
//!
//! `--csv FILE` writes one row per (estimator, N, footprint, query, map):
//! `footprint,<estimator>,<n>,<footprint>,<query>,<map>,<rel_rmse>,<coverage2s>` (coverage
//! `nan` where there is no error bar), for the tier given by `--tier` (default `clamp`: each
//! pixel's luminance capped at 30× the map mean). The report (`footprint.md` and
//! `footprint.png`, or `footprint_raw.*` for the raw tier) goes to `target/footprint/` unless
//! `--out DIR` names a folder. The recommended footprint
//! per N is the one with the lowest mean per-map ratio to `point-cos-avg` on the **training**
//! maps (`--train`, default apartment, bridge, forest, lab); targets are judged on the others.
//! About 2 minutes for all ten maps on two cores; `--quick` (two maps, N ∈ {16, 64}, two
//! rotations) takes seconds.

use sphere_quadrature_eval::{cli, compare};

use clap::{Parser, ValueEnum};
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use reference::vec::dot;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::envmap::EquirectMap;
use sphere_quadrature::footprint::{CosinePower, Footprint, Gaussian, Kind};
use sphere_quadrature::probe::{cosine_weighted_average, Probe, ProbeSize, ProbeTables};
use sphere_quadrature::{Mat3, Vec3};
use std::collections::BTreeMap;
use std::error::Error;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::PathBuf;

/// Phong exponents of the glossy queries.
const EXPONENTS: [f64; 3] = [5.0, 20.0, 100.0];
/// Query directions (normals and mirror directions) per rotation.
const QUERIES: usize = 64;
const ESTIMATORS: [&str; 6] =
    ["bmc-footprint", "bmc-point-model", "cos-avg", "sh2-deconv", "point-cos-avg", "point-bmc"];

/// Squared errors, |truth| and 2σ hits of one (estimator, N, footprint, query, map).
#[derive(Clone, Default)]
struct Sums {
    sq: f64,
    truth: f64,
    count: usize,
    within: usize,
    has_bar: bool,
}

impl Sums {
    fn add(&mut self, est: f64, truth: f64, variance: Option<f64>) {
        self.sq += (est - truth).powi(2);
        self.truth += truth.abs();
        self.count += 1;
        if let Some(v) = variance {
            self.has_bar = true;
            self.within += usize::from((est - truth).abs() <= 2.0 * v.max(0.0).sqrt());
        }
    }

    fn rel_rmse(&self) -> f64 {
        (self.sq / self.count as f64).sqrt() / (self.truth / self.count as f64)
    }

    fn coverage(&self) -> f64 {
        if self.has_bar {
            self.within as f64 / self.count as f64
        } else {
            f64::NAN
        }
    }
}

/// (estimator, N, footprint, query, map) → sums.
type Table = BTreeMap<(&'static str, usize, String, String, String), Sums>;

fn vec32(d: [f64; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

fn footprint_name(kind: Kind) -> String {
    match kind {
        Kind::Point => "point".into(),
        Kind::Gaussian { sharpness } => sharpness.to_string(),
        Kind::CosinePower { exponent } => format!("cos{exponent}"),
    }
}

fn query_names() -> Vec<String> {
    let mut q = vec!["irradiance".to_string()];
    q.extend(EXPONENTS.iter().map(|e| format!("glossy-e{e}")));
    q
}

/// Real SH `Y_{l,m}(d)`, l ≤ 2, at index `l(l+1) + m`, with the band of each index.
fn sh9(d: [f64; 3]) -> [(usize, f64); 9] {
    let [x, y, z] = d;
    let c0 = 0.5 * (1.0 / PI).sqrt();
    let c1 = (3.0 / (4.0 * PI)).sqrt();
    let c2 = 0.5 * (15.0 / PI).sqrt();
    let c20 = 0.25 * (5.0 / PI).sqrt();
    let c22 = 0.25 * (15.0 / PI).sqrt();
    [
        (0, c0),
        (1, c1 * y),
        (1, c1 * z),
        (1, c1 * x),
        (2, c2 * x * y),
        (2, c2 * y * z),
        (2, c20 * (3.0 * z * z - 1.0)),
        (2, c2 * x * z),
        (2, c22 * (x * x - y * y)),
    ]
}

/// SH L2 least-squares coefficients of samples `ys` at `xs`, each band divided by `gains[l]`.
fn sh2_deconvolved(xs: &[[f64; 3]], ys: &[f64], gains: [f64; 3]) -> [f64; 9] {
    let mut a = [[0.0f64; 9]; 9];
    let mut b = [0.0f64; 9];
    for (x, &y) in xs.iter().zip(ys) {
        let s = sh9(*x);
        for i in 0..9 {
            b[i] += s[i].1 * y;
            for j in 0..9 {
                a[i][j] += s[i].1 * s[j].1;
            }
        }
    }
    let flat: Vec<f64> = a.iter().flatten().copied().collect();
    let c = reference::bmc::lu_solve(&flat, 9, &b);
    std::array::from_fn(|i| c[i] / gains[sh9([0.0, 0.0, 1.0])[i].0])
}

/// One map and tier: the shared per-map inputs.
struct Scene<'a> {
    map: &'a EnvMap,
    view: EquirectMap<'a>,
    normals: &'a [[f64; 3]],
    truths: &'a [Vec<f64>],
    rotations: &'a [Mat3],
}

/// The estimators of one footprint `F` at one `N` (and the point-sample ones, once, when
/// `with_point` is set), accumulated into `table` for map `stem`.
fn evaluate<const N: usize, F: Footprint>(
    scene: &Scene,
    stem: &str,
    with_point: bool,
    table: &mut Table,
) where
    Size<N>: ProbeTables<F> + ProbeSize,
{
    let fname = footprint_name(F::KIND);
    let queries = query_names();
    let gains = [0, 1, 2].map(|l| F::KIND.gain(l).expect("a baked footprint"));
    for &rot in scene.rotations {
        let mut probe = Probe::<N, f32, F>::new();
        probe.set_rotation(rot).expect("orthonormal");
        let dirs = *probe.directions();
        let xs: Vec<[f64; 3]> =
            dirs.iter().map(|d| [f64::from(d.x), f64::from(d.y), f64::from(d.z)]).collect();
        let mut rgb = [[0.0f32; 3]; N];
        scene.view.footprint_samples(&dirs, F::KIND, &mut rgb).expect("valid samples");
        let y: [f32; N] = rgb.map(|c| luminance(c.map(f64::from)) as f32);
        let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
        probe.update(&y).expect("finite");
        let mut point_model = Probe::<N>::new();
        point_model.set_rotation(rot).expect("orthonormal");
        point_model.update(&y).expect("finite");
        let sh = sh2_deconvolved(&xs, &y64, gains);
        let yp: [f32; N] = std::array::from_fn(|i| luminance(scene.map.radiance(xs[i])) as f32);
        let mut point = Probe::<N>::new();
        if with_point {
            point.set_rotation(rot).expect("orthonormal");
            point.update(&yp).expect("finite");
        }
        for (q, name) in queries.iter().enumerate() {
            let mut put = |est: &'static str, fp: &str, value: f64, truth: f64, v: Option<f64>| {
                table
                    .entry((est, N, fp.to_string(), name.clone(), stem.to_string()))
                    .or_default()
                    .add(value, truth, v);
            };
            for (k, &n) in scene.normals.iter().enumerate() {
                let truth = scene.truths[q][k];
                let nv = vec32(n);
                let (bmc, model, avg, shv, pavg, pbmc);
                if q == 0 {
                    bmc = probe.irradiance(nv).expect("unit normal");
                    model = point_model.irradiance(nv).expect("unit normal");
                    avg = f64::from(cosine_weighted_average(&dirs, &y, nv).expect("normal"));
                    let zonal = [PI, 2.0 * PI / 3.0, PI / 4.0];
                    shv = sh.iter().zip(sh9(n)).map(|(c, (l, v))| zonal[l] * c * v).sum::<f64>();
                    pavg = f64::from(cosine_weighted_average(&dirs, &yp, nv).expect("normal"));
                    pbmc = point.irradiance(nv).expect("unit normal");
                } else {
                    let e = EXPONENTS[q - 1];
                    bmc = probe.phong(nv, e as f32).expect("valid lobe");
                    model = point_model.phong(nv, e as f32).expect("valid lobe");
                    let weighted = |ys: &[f32]| {
                        let (mut num, mut den) = (0.0, 0.0);
                        for (x, &v) in xs.iter().zip(ys) {
                            let w = dot(n, *x).max(0.0).powf(e);
                            num += w * f64::from(v);
                            den += w;
                        }
                        if den > 0.0 {
                            num / den
                        } else {
                            0.0
                        }
                    };
                    avg = weighted(&y);
                    let zonal = [1.0, (e + 1.0) / (e + 2.0), e / (e + 3.0)];
                    shv = sh.iter().zip(sh9(n)).map(|(c, (l, v))| zonal[l] * c * v).sum::<f64>();
                    pavg = weighted(&yp);
                    pbmc = point.phong(nv, e as f32).expect("valid lobe");
                }
                let bar = |e: sphere_quadrature::probe::Estimate<f32>| {
                    (f64::from(e.value), Some(f64::from(e.variance)))
                };
                let (v, var) = bar(bmc);
                put(ESTIMATORS[0], &fname, v, truth, var);
                let (v, var) = bar(model);
                put(ESTIMATORS[1], &fname, v, truth, var);
                put(ESTIMATORS[2], &fname, avg, truth, None);
                put(ESTIMATORS[3], &fname, shv, truth, None);
                if with_point {
                    put(ESTIMATORS[4], "point", pavg, truth, None);
                    let (v, var) = bar(pbmc);
                    put(ESTIMATORS[5], "point", v, truth, var);
                }
            }
        }
    }
}

/// Every baked (N, footprint) of the sweep for one map.
fn evaluate_all(scene: &Scene, stem: &str, sizes: &[usize]) -> Table {
    let mut t = Table::new();
    macro_rules! run {
        ($n:literal: $first:ty $(, $rest:ty)*) => {
            if sizes.contains(&$n) {
                evaluate::<$n, $first>(scene, stem, true, &mut t);
                $(evaluate::<$n, $rest>(scene, stem, false, &mut t);)*
            }
        };
    }
    run!(16: Gaussian<1>, Gaussian<2>, Gaussian<4>, Gaussian<8>, CosinePower<1>);
    run!(32: Gaussian<2>, Gaussian<4>, Gaussian<8>, Gaussian<16>, CosinePower<1>);
    run!(64: Gaussian<4>, Gaussian<8>, Gaussian<16>, Gaussian<32>, CosinePower<1>);
    run!(128: Gaussian<8>, Gaussian<16>, Gaussian<32>, Gaussian<64>);
    run!(256: Gaussian<16>, Gaussian<32>, Gaussian<64>, Gaussian<128>);
    t
}

/// footprint benchmark (issue #11)
#[derive(Parser)]
#[command(bin_name = "cargo eval footprint --")]
struct Args {
    #[command(flatten)]
    maps: cli::AllMaps,
    /// clamp (default: luminance capped at 30× the map mean) or raw
    #[arg(long = "tier", value_name = "T", value_enum, default_value_t = Tier::Clamp)]
    #[arg(hide_possible_values = true, hide_default_value = true)]
    tier: Tier,
    /// Rows footprint,<estimator>,<n>,<footprint>,<query>,<map>,<rel_rmse>,<coverage2s>
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Report folder (default target/footprint; `--out docs` to update the docs)
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    #[command(flatten)]
    train: cli::Train,
    /// Random probe rotations per map
    #[arg(long, value_name = "R", default_value_t = 4)]
    rotations: usize,
    /// Two maps, N = 16 and 64, two rotations (CI)
    #[arg(long)]
    quick: bool,
    /// Worker threads (default: all cores, at most one per map)
    #[arg(long, value_name = "T")]
    threads: Option<usize>,
}

/// The lighting tier of `--tier`.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Tier {
    /// Luminance capped at 30× the map mean.
    Clamp,
    /// The map as it is.
    Raw,
}

/// The arguments, defaults filled in.
fn parse_args() -> Result<Args, Box<dyn Error>> {
    let mut a = Args::parse();
    if a.maps.maps.is_empty() {
        a.maps.maps = cli::all_bundled_maps_or(a.quick, ["apartment", "park"])?;
    }
    if a.quick {
        a.rotations = a.rotations.min(2);
    }
    Ok(a)
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = parse_args()?;
    let clamp = args.tier == Tier::Clamp;
    let out = args.out.clone().unwrap_or_else(|| cli::repo_root().join("target/footprint"));
    let sizes: Vec<usize> = if args.quick { vec![16, 64] } else { vec![16, 32, 64, 128, 256] };
    let tier = if clamp { "clamp" } else { "raw" };
    let start = std::time::Instant::now();
    let mut rng = Rng::new(0x00F0_07F0);
    let rotations: Vec<Mat3> = (0..args.rotations)
        .map(|_| {
            let r = rng.uniform_rotation();
            Mat3::from_rows(vec32(r[0]), vec32(r[1]), vec32(r[2]))
        })
        .collect();
    // Query directions: the 64-point SF set under a fixed rotation unrelated to the probes'.
    let turn = rng.uniform_rotation();
    let normals: Vec<[f64; 3]> = (0..QUERIES as u64)
        .map(|j| reference::vec::mat_mul_vec(turn, reference::sf::sphere_point(j, QUERIES as u64)))
        .collect();
    let mut scenes: Vec<(String, EnvMap)> = Vec::new();
    for p in &args.maps.maps {
        let map = EnvMap::load(p)?;
        let map = if clamp { compare::clamped(&map) } else { map };
        scenes.push((cli::map_name(p), map));
    }
    // Truth weights per grid size (one set serves every map of that size).
    let mut weights: BTreeMap<(usize, usize), Vec<Vec<Vec<f64>>>> = BTreeMap::new();
    for (_, m) in &scenes {
        weights.entry((m.width, m.height)).or_insert_with(|| {
            let mut w = vec![compare::weights(compare::Kind::Diffuse, &normals, m.width, m.height)];
            for &e in &EXPONENTS {
                w.push(compare::weights(compare::Kind::Glossy(e), &normals, m.width, m.height));
            }
            w
        });
    }
    let threads = cli::threads(args.threads).min(scenes.len());
    let next = std::sync::atomic::AtomicUsize::new(0);
    let table: Table = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut t = Table::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some((name, map)) = scenes.get(i) else { break };
                        let truths: Vec<Vec<f64>> = weights[&(map.width, map.height)]
                            .iter()
                            .map(|w| compare::truths(map, w))
                            .collect();
                        let view = EquirectMap::new(map.width, map.height, &map.pixels)
                            .expect("a valid map");
                        let scene = Scene {
                            map,
                            view,
                            normals: &normals,
                            truths: &truths,
                            rotations: &rotations,
                        };
                        t.extend(evaluate_all(&scene, name, &sizes));
                        eprintln!("{name}: done ({:.0} s)", start.elapsed().as_secs_f64());
                    }
                    t
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("worker")).collect()
    });
    if let Some(csv) = &args.csv {
        let mut s = String::new();
        for ((est, n, fp, q, map), sums) in &table {
            let _ = writeln!(
                s,
                "footprint,{est},{n},{fp},{q},{map},{:.6},{:.4}",
                sums.rel_rmse(),
                sums.coverage()
            );
        }
        if let Some(dir) = csv.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(csv, s)?;
    }
    let report = report(&table, &args, tier, &sizes);
    std::fs::create_dir_all(&out)?;
    // `footprint.md`/`.png` for the clamp tier, `footprint_raw.*` for the raw one.
    let name = if clamp { "footprint" } else { "footprint_raw" };
    std::fs::write(out.join(format!("{name}.md")), &report.0)?;
    plot(&report.1, &out.join(format!("{name}.png")))?;
    println!("{}", report.0);
    eprintln!("wrote {}/{name}.md ({:.0} s)", out.display(), start.elapsed().as_secs_f64());
    Ok(())
}

/// Per-map relative RMSE of one (estimator, N, footprint, query).
fn per_map(t: &Table, est: &'static str, n: usize, fp: &str, q: &str) -> BTreeMap<String, Sums> {
    t.iter()
        .filter(|((e, nn, f, qq, _), _)| *e == est && *nn == n && f == fp && qq == q)
        .map(|((_, _, _, _, m), s)| (m.clone(), s.clone()))
        .collect()
}

/// Mean of per-map ratios, ratio of means and the worst map (name, ratio) of `a / b` over
/// the maps in `maps`.
fn ratios(
    a: &BTreeMap<String, Sums>,
    b: &BTreeMap<String, Sums>,
    maps: &[String],
) -> (f64, f64, String, f64) {
    let (mut sum, mut ea, mut eb, mut worst, mut count) =
        (0.0, 0.0, 0.0, (String::new(), 0.0f64), 0);
    for m in maps {
        let (Some(x), Some(y)) = (a.get(m), b.get(m)) else { continue };
        let r = x.rel_rmse() / y.rel_rmse();
        sum += r;
        ea += x.rel_rmse();
        eb += y.rel_rmse();
        count += 1;
        if r > worst.1 {
            worst = (m.clone(), r);
        }
    }
    (sum / count.max(1) as f64, ea / eb, worst.0, worst.1)
}

fn mean_of(a: &BTreeMap<String, Sums>, maps: &[String], f: impl Fn(&Sums) -> f64) -> f64 {
    let v: Vec<f64> = maps.iter().filter_map(|m| a.get(m).map(&f)).collect();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The curve data: per N, (footprint sharpness, mean training ratio) pairs.
type Curves = Vec<(usize, Vec<(f64, f64)>)>;

fn report(t: &Table, args: &Args, tier: &str, sizes: &[usize]) -> (String, Curves) {
    let maps: Vec<String> = args.maps.maps.iter().map(|p| cli::map_name(p)).collect();
    let train: Vec<String> =
        maps.iter().filter(|m| args.train.train.contains(m)).cloned().collect();
    let held: Vec<String> =
        maps.iter().filter(|m| !args.train.train.contains(m)).cloned().collect();
    let held = if held.is_empty() { maps.clone() } else { held };
    let train = if train.is_empty() { maps.clone() } else { train };
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Footprint samples: Bayesian Monte Carlo that knows each sample integrates a lobe\n"
    );
    let _ = writeln!(
        s,
        "Generated by `cargo eval footprint{}` \
         (tier `{tier}`, {} rotations × {QUERIES} queries per map). Relative RMSE of luminance \
         against the unfiltered map. Training maps: {}; held-out maps: {}.\n",
        if args.quick { " -- --quick" } else { "" },
        args.rotations,
        train.join(", "),
        held.join(", ")
    );
    // Footprints per N (their column names), from the table.
    let footprints = |n: usize| -> Vec<String> {
        let mut v: Vec<String> = t
            .keys()
            .filter(|(e, nn, f, _, _)| *e == "bmc-footprint" && *nn == n && f != "point")
            .map(|(_, _, f, _, _)| f.clone())
            .collect();
        v.dedup();
        v.sort_by_key(|f| f.parse::<u32>().unwrap_or(u32::MAX));
        v
    };
    let mut curves: Curves = Vec::new();
    let mut recommended: BTreeMap<usize, String> = BTreeMap::new();
    let _ = writeln!(s, "## Error against the footprint sharpness (irradiance, training maps)\n");
    let _ = writeln!(s, "Mean over the training maps of the per-map ratio `bmc-footprint / point-cos-avg`; the lowest Gaussian is the recommended footprint (★).\n");
    let _ = writeln!(
        s,
        "| N | footprint | bmc-footprint | ratio (mean per map) | cos-avg | sh2-deconv |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for &n in sizes {
        let base = per_map(t, "point-cos-avg", n, "point", "irradiance");
        let mut best: Option<(String, f64)> = None;
        let mut curve = Vec::new();
        let rows: Vec<(String, f64, f64, f64, f64)> = footprints(n)
            .into_iter()
            .map(|fp| {
                let b = per_map(t, "bmc-footprint", n, &fp, "irradiance");
                let r = ratios(&b, &base, &train).0;
                if let Ok(sharp) = fp.parse::<f64>() {
                    curve.push((sharp, r));
                    if best.as_ref().is_none_or(|(_, x)| r < *x) {
                        best = Some((fp.clone(), r));
                    }
                }
                let m = |e: &'static str| {
                    mean_of(&per_map(t, e, n, &fp, "irradiance"), &train, Sums::rel_rmse)
                };
                (fp.clone(), m("bmc-footprint"), r, m("cos-avg"), m("sh2-deconv"))
            })
            .collect();
        if let Some((fp, _)) = &best {
            recommended.insert(n, fp.clone());
        }
        for (fp, e, r, c, sh) in rows {
            let star = if recommended.get(&n) == Some(&fp) { " ★" } else { "" };
            let _ = writeln!(
                s,
                "| {n} | {fp}{star} | {:.2} % | {r:.3} | {:.2} % | {:.2} % |",
                100.0 * e,
                100.0 * c,
                100.0 * sh
            );
        }
        curves.push((n, curve));
    }
    let _ = writeln!(s, "\n## Held-out maps at the recommended footprint\n");
    for q in query_names() {
        let _ = writeln!(s, "### {q}\n");
        let _ = writeln!(s, "| N | S | bmc-footprint | bmc-point-model | cos-avg | sh2-deconv | point-cos-avg | point-bmc | footprint / point-cos-avg: mean of ratios | ratio of means | worst map | footprint / sh2-deconv (mean of ratios) | footprint / cos-avg (mean of ratios) | 2σ coverage footprint | 2σ point-bmc |");
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
        for &n in sizes {
            let Some(fp) = recommended.get(&n) else { continue };
            let get = |e: &'static str, f: &str| per_map(t, e, n, f, &q);
            let fpb = get("bmc-footprint", fp);
            let base = get("point-cos-avg", "point");
            let (mr, rm, wm, wr) = ratios(&fpb, &base, &held);
            let sh = ratios(&fpb, &get("sh2-deconv", fp), &held).0;
            let ca = ratios(&fpb, &get("cos-avg", fp), &held).0;
            let e = |m: &BTreeMap<String, Sums>| 100.0 * mean_of(m, &held, Sums::rel_rmse);
            let cov = |m: &BTreeMap<String, Sums>| 100.0 * mean_of(m, &held, Sums::coverage);
            let _ = writeln!(
                s,
                "| {n} | {fp} | {:.2} % | {:.2} % | {:.2} % | {:.2} % | {:.2} % | {:.2} % | {mr:.3} | {rm:.3} | {wm} {wr:.3} | {sh:.3} | {ca:.3} | {:.1} % | {:.1} % |",
                e(&fpb),
                e(&get("bmc-point-model", fp)),
                e(&get("cos-avg", fp)),
                e(&get("sh2-deconv", fp)),
                e(&base),
                e(&get("point-bmc", "point")),
                cov(&fpb),
                cov(&get("point-bmc", "point")),
            );
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(s, "## Every footprint, held-out maps (mean of per-map relative RMSE, and 2σ coverage of bmc-footprint)\n");
    let _ = writeln!(s, "| N | footprint | query | bmc-footprint | coverage | bmc-point-model | cos-avg | sh2-deconv |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for &n in sizes {
        for fp in footprints(n) {
            for q in query_names() {
                let g = |e: &'static str| per_map(t, e, n, &fp, &q);
                let e = |m: &BTreeMap<String, Sums>| 100.0 * mean_of(m, &held, Sums::rel_rmse);
                let _ = writeln!(
                    s,
                    "| {n} | {fp} | {q} | {:.2} % | {:.1} % | {:.2} % | {:.2} % | {:.2} % |",
                    e(&g("bmc-footprint")),
                    100.0 * mean_of(&g("bmc-footprint"), &held, Sums::coverage),
                    e(&g("bmc-point-model")),
                    e(&g("cos-avg")),
                    e(&g("sh2-deconv"))
                );
            }
        }
    }
    (s, curves)
}

fn plot(curves: &Curves, path: &std::path::Path) -> Result<(), Box<dyn Error>> {
    register_font("sans-serif", FontStyle::Normal, ttf_noto_sans::REGULAR)
        .map_err(|_| "cannot register the embedded font")?;
    let root = BitMapBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let (mut lo, mut hi) = (f64::MAX, f64::MIN);
    for (_, c) in curves {
        for &(_, r) in c {
            lo = lo.min(r);
            hi = hi.max(r);
        }
    }
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0) {
        return Ok(());
    }
    let font = ("sans-serif", 18);
    let mut chart = ChartBuilder::on(&root)
        .caption("footprint BMC / point cosine average (irradiance, training maps)", font)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((0.7f64..180.0).log_scale(), (lo * 0.8..hi * 1.25).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("footprint sharpness S")
        .y_desc("mean per-map ratio")
        .label_style(("sans-serif", 14))
        .draw()?;
    for (i, (n, c)) in curves.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(c.iter().copied(), color.stroke_width(2)))?
            .label(format!("N = {n}"))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
            });
        chart.draw_series(c.iter().map(|&p| Circle::new(p, 4, color.filled())))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerLeft)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()?;
    root.present()?;
    Ok(())
}
