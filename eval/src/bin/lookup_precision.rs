//! Lookups at GPU precision: the crate's estimators fed the lookups a GPU reads back, fp16
//! or 8-bit sRGB, quantised here from the exact (f32) ones, against the ground truth of the
//! map; the relative irradiance error per tier, and the 2σ coverage with and without the
//! declared lookup noise.
//!
//! ```text
//! cargo eval lookup_precision                  # held-out maps, writes target/eval/lookup_precision/
//! cargo eval lookup_precision -- --out docs     # regenerates docs/lookup_precision.md
//! cargo eval lookup_precision -- --quick        # one held-out map, fewer queries (CI)
//! cargo eval lookup_precision -- a.hdr b.hdr --csv rows.csv
//! ```
//!
//! Estimators (irradiance of the `clamp` tier's luminance, N = 16, 32, 64, 128):
//! - `renderer`: `bmc::FootprintRenderer<N, Diffuse>` on `MipPyramid::footprint_sample`
//!   lookups, one call per normal; with the noise term, `set_lookup_noise`.
//! - `probe`: `Probe<N>` on point samples of the map, seeded rotations, queried at every normal.
//! - `probe-footprint`: `Probe<N, f32, Gaussian<N/8>>` on pyramid lookups of its footprint.
//! - `layout`: `LayoutProbe<K>` of cosine sensors on the rotated spherical Fibonacci set
//!   (K = 16, 32, 64), readings the pyramid's `CosinePower { exponent: 1 }` lookups, the
//!   recommended prior (`Prior::for_layout`); with the noise term, the tier's noise as the
//!   layout's `Noise` (a nugget in its model).
//!
//! Tiers: `f32` (the exact lookups), `fp16` (round to nearest even, 10-bit mantissa, exponents
//! −14…15, subnormals down to 2⁻²⁴, overflow above 65 504 to ∞), `srgb8` (exposure
//! `k = 1/max Yⱼ` over the probe's own lookups, or the renderer call's, so the brightest maps to
//! 1; the standard piecewise sRGB curve; 8 bits, round to nearest; decoded and divided by `k`).

use sphere_quadrature_eval::{cli, compare, parallel::parallel_map};

use std::error::Error;
use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Parser;
use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use sphere_quadrature::bmc::footprint::{Diffuse, FootprintRenderer};
use sphere_quadrature::bmc::{FootprintSize, Size};
use sphere_quadrature::envmap::{EquirectMap, MipPyramid};
use sphere_quadrature::footprint::{Footprint, Gaussian, Kind, Point};
use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
use sphere_quadrature::probe::{Probe, ProbeTables};
use sphere_quadrature::{Mat3, Vec3};

// ---------------------------------------------------------------------------------------------
// Quantisers.

/// `x` rounded to the nearest IEEE binary16 number (ties to even), returned in f64: 11
/// significant bits, exponents −14…15, subnormals in steps of 2⁻²⁴, `±∞` from 65 520 up.
fn fp16(x: f64) -> f64 {
    if !x.is_finite() || x == 0.0 {
        return x;
    }
    let a = x.abs();
    if a >= 65_520.0 {
        return f64::INFINITY.copysign(x);
    }
    // The binade of a (f64 is normal here: a ≥ 2⁻¹⁰⁷⁴ only matters below 2⁻²⁵, which rounds to
    // 0 or 2⁻²⁴ by the subnormal step).
    let e = ((a.to_bits() >> 52) as i64 - 1023).max(-14);
    let ulp = 2f64.powi((e - 10) as i32);
    (a / ulp).round_ties_even().copysign(x) * ulp
}

/// The sRGB encoding of linear `v ∈ [0, 1]`.
fn srgb_encode(v: f64) -> f64 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The sRGB decoding of `c ∈ [0, 1]`.
fn srgb_decode(c: f64) -> f64 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// `y` through an 8-bit sRGB target at exposure `k`: `decode(round(255·encode(k·y))/255)/k`,
/// clamped to the target's [0, 1].
fn srgb8(y: f64, k: f64) -> f64 {
    let code = (255.0 * srgb_encode((k * y).clamp(0.0, 1.0))).round_ties_even();
    srgb_decode(code / 255.0) / k
}

/// The linear step of an 8-bit sRGB code at linear value `v` (exposure units): `1/(255·c′(v))`.
fn srgb_step(v: f64) -> f64 {
    let slope = if v <= 0.003_130_8 { 12.92 } else { 1.055 / 2.4 * v.powf(1.0 / 2.4 - 1.0) };
    1.0 / (255.0 * slope)
}

/// The `(σ, η)` in exposure units whose `σ² + η²v²` bounds the rounding variance `Δ(v)²/12` of
/// an 8-bit sRGB code at every `v ∈ [0, 1]` with `η` the relative step at `v = 1`:
/// `η = Δ(1)/√12`, `σ² = max_v (Δ(v)² − Δ(1)²v²)/12` (on a grid of 2·10⁵ values).
fn srgb_envelope() -> (f64, f64) {
    let top = srgb_step(1.0);
    let mut worst = 0.0f64;
    for i in 0..=200_000 {
        let v = f64::from(i) / 200_000.0;
        worst = worst.max(srgb_step(v).powi(2) - top.powi(2) * v * v);
    }
    ((worst / 12.0).sqrt(), top / 12f64.sqrt())
}

/// The lookup tiers.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Tier {
    F32,
    Fp16,
    Srgb8,
}

const TIERS: [Tier; 3] = [Tier::F32, Tier::Fp16, Tier::Srgb8];

impl Tier {
    fn name(self) -> &'static str {
        match self {
            Tier::F32 => "f32",
            Tier::Fp16 => "fp16",
            Tier::Srgb8 => "srgb8",
        }
    }

    /// The lookups `ys` as this tier reads them back, and the noise that declares the
    /// rounding: none for f32; `η = 2⁻¹¹/√3` and the subnormal step's `σ = 2⁻²⁴/√12` for
    /// fp16; for sRGB [`srgb_envelope`] divided by the exposure `k = 1/max Yⱼ` (σ) and as
    /// it is (η).
    fn quantise(self, ys: &[f64], envelope: (f64, f64)) -> (Vec<f32>, Noise) {
        match self {
            Tier::F32 => (ys.iter().map(|&y| y as f32).collect(), Noise::NONE),
            Tier::Fp16 => (
                ys.iter().map(|&y| fp16(y) as f32).collect(),
                Noise {
                    absolute: (2f64.powi(-24) / 12f64.sqrt()) as f32,
                    relative: (2f64.powi(-11) / 3f64.sqrt()) as f32,
                },
            ),
            Tier::Srgb8 => {
                let top = ys.iter().fold(0.0f64, |m, &y| m.max(y));
                if top <= 0.0 {
                    return (vec![0.0; ys.len()], Noise::NONE);
                }
                let k = 1.0 / top;
                let noise =
                    Noise { absolute: (envelope.0 / k) as f32, relative: envelope.1 as f32 };
                (ys.iter().map(|&y| srgb8(y, k) as f32).collect(), noise)
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Tallies.

const ESTIMATORS: [&str; 4] = ["renderer", "probe", "probe-footprint", "layout"];
/// Whether an estimator has a noise term (the others' "with noise" is their plain answer).
const HAS_NOISE: [bool; 4] = [true, false, false, true];
const SIZES: [usize; 4] = [16, 32, 64, 128];

/// One (estimator, tier, N) on one map: squared errors, truths, queries, covered without and
/// with the noise term.
#[derive(Clone, Copy, Default)]
struct Tally {
    sq: f64,
    /// The squared errors of the estimate made with the tier's noise term.
    sq_noise: f64,
    truth: f64,
    count: usize,
    covered: usize,
    covered_noise: usize,
    failed: usize,
}

impl Tally {
    fn add(&mut self, truth: f64, plain: (f64, f64), noisy: (f64, f64)) {
        if !plain.0.is_finite() || !noisy.0.is_finite() {
            self.failed += 1;
            return;
        }
        let err = plain.0 - truth;
        self.sq += err * err;
        self.sq_noise += (noisy.0 - truth).powi(2);
        self.truth += truth;
        self.count += 1;
        self.covered += usize::from(err.abs() <= 2.0 * plain.1.max(0.0).sqrt());
        self.covered_noise += usize::from((noisy.0 - truth).abs() <= 2.0 * noisy.1.max(0.0).sqrt());
    }

    fn rel_err(&self) -> f64 {
        (self.sq / self.count as f64).sqrt() / (self.truth / self.count as f64)
    }

    fn rel_err_noise(&self) -> f64 {
        (self.sq_noise / self.count as f64).sqrt() / (self.truth / self.count as f64)
    }

    fn coverage(&self) -> f64 {
        self.covered as f64 / self.count as f64
    }

    fn coverage_noise(&self) -> f64 {
        self.covered_noise as f64 / self.count as f64
    }
}

/// `[estimator][tier][size]` for one map.
type MapTallies = [[[Tally; 4]; 3]; 4];

// ---------------------------------------------------------------------------------------------
// One map.

struct Scene<'a> {
    clamp: &'a EnvMap,
    pyramid: &'a MipPyramid<'a>,
    normals: &'a [Vec3],
    truths: &'a [f64],
    rotations: &'a [Mat3],
    envelope: (f64, f64),
}

impl Scene<'_> {
    fn point(&self, d: Vec3) -> f64 {
        luminance(self.clamp.radiance([f64::from(d.x), f64::from(d.y), f64::from(d.z)]))
    }

    fn footprint(&self, d: Vec3, kind: Kind) -> f64 {
        self.pyramid.footprint_sample(d, kind).map_or(f64::NAN, |c| luminance(c.map(f64::from)))
    }
}

fn pair(e: Result<sphere_quadrature::Estimate<f32>, sphere_quadrature::Error>) -> (f64, f64) {
    e.map_or((f64::NAN, f64::NAN), |e| (f64::from(e.value), f64::from(e.variance)))
}

fn renderer<const N: usize>(s: &Scene, out: &mut [Tally; 3])
where
    Size<N>: FootprintSize<Diffuse>,
{
    let plain = FootprintRenderer::<N, Diffuse>::new();
    let kinds = plain.footprints();
    for (&n, &truth) in s.normals.iter().zip(s.truths) {
        let mut dirs = [Vec3::ZERO; N];
        if plain.fill_directions(n, &mut dirs).is_err() {
            continue;
        }
        let exact: Vec<f64> = dirs.iter().zip(&kinds).map(|(&d, &k)| s.footprint(d, k)).collect();
        for (tier, tally) in TIERS.iter().zip(out.iter_mut()) {
            let (y, noise) = tier.quantise(&exact, s.envelope);
            let y: [f32; N] = std::array::from_fn(|j| y[j]);
            let mut noisy = plain;
            let with = match noisy.set_lookup_noise(noise) {
                Ok(()) => pair(noisy.estimate_with_variance(&y)),
                Err(_) => (f64::NAN, f64::NAN),
            };
            tally.add(truth, pair(plain.estimate_with_variance(&y)), with);
        }
    }
}

fn probe<const N: usize, F: Footprint>(s: &Scene, read: impl Fn(Vec3) -> f64, out: &mut [Tally; 3])
where
    Size<N>: ProbeTables<F>,
{
    for &rot in s.rotations {
        let mut p = Probe::<N, f32, F>::new();
        if p.set_rotation(rot).is_err() {
            continue;
        }
        let exact: Vec<f64> = p.directions().iter().map(|&d| read(d)).collect();
        for (tier, tally) in TIERS.iter().zip(out.iter_mut()) {
            let (y, _) = tier.quantise(&exact, s.envelope);
            let y: [f32; N] = std::array::from_fn(|j| y[j]);
            let ok = p.update(&y).is_ok();
            for (&n, &truth) in s.normals.iter().zip(s.truths) {
                let e = if ok { pair(p.irradiance(n)) } else { (f64::NAN, f64::NAN) };
                tally.add(truth, e, e);
            }
        }
    }
}

fn layout<const K: usize>(s: &Scene, out: &mut [Tally; 3]) {
    let diode = Kind::CosinePower { exponent: 1 };
    for &rot in s.rotations {
        let Ok(set) = sphere_quadrature::SphericalFibonacci::<K>::new().with_rotation(rot) else {
            continue;
        };
        let dirs = set.points();
        let sensors = dirs.map(Sensor::cosine);
        let prior = Prior::for_layout(&sensors);
        let exact: Vec<f64> = dirs.iter().map(|&d| s.footprint(d, diode)).collect();
        for (tier, tally) in TIERS.iter().zip(out.iter_mut()) {
            let (y, noise) = tier.quantise(&exact, s.envelope);
            let y: [f32; K] = std::array::from_fn(|j| y[j]);
            let run = |noise: Noise| -> Option<LayoutProbe<K>> {
                let mut p = LayoutProbe::<K>::new(&sensors, prior, noise).ok()?;
                p.update(&y).ok()?;
                Some(p)
            };
            let (plain, noisy) = (run(Noise::NONE), run(noise));
            for (&n, &truth) in s.normals.iter().zip(s.truths) {
                let nan = (f64::NAN, f64::NAN);
                let a = plain.as_ref().map_or(nan, |p| pair(p.irradiance(n)));
                let b = noisy.as_ref().map_or(nan, |p| pair(p.irradiance(n)));
                tally.add(truth, a, b);
            }
        }
    }
}

/// Every estimator, tier and size on one map.
fn run_map(s: &Scene) -> MapTallies {
    let mut t = MapTallies::default();
    let col = |t: &mut MapTallies, e: usize, i: usize| -> [Tally; 3] {
        [t[e][0][i], t[e][1][i], t[e][2][i]]
    };
    let put = |t: &mut MapTallies, e: usize, i: usize, v: [Tally; 3]| {
        for (k, x) in v.into_iter().enumerate() {
            t[e][k][i] = x;
        }
    };
    let point = |d: Vec3| s.point(d);
    macro_rules! size {
        ($i:expr, $n:literal, $s:literal) => {{
            let mut v = col(&mut t, 0, $i);
            renderer::<$n>(s, &mut v);
            put(&mut t, 0, $i, v);
            let mut v = col(&mut t, 1, $i);
            probe::<$n, Point>(s, point, &mut v);
            put(&mut t, 1, $i, v);
            let mut v = col(&mut t, 2, $i);
            let kind = Kind::Gaussian { sharpness: $s };
            probe::<$n, Gaussian<$s>>(s, |d| s.footprint(d, kind), &mut v);
            put(&mut t, 2, $i, v);
        }};
    }
    size!(0, 16, 2);
    size!(1, 32, 4);
    size!(2, 64, 8);
    size!(3, 128, 16);
    for (i, k) in [(0, 16), (1, 32), (2, 64)] {
        let mut v = col(&mut t, 3, i);
        match k {
            16 => layout::<16>(s, &mut v),
            32 => layout::<32>(s, &mut v),
            _ => layout::<64>(s, &mut v),
        }
        put(&mut t, 3, i, v);
    }
    t
}

// ---------------------------------------------------------------------------------------------
// Report.

/// lookup_precision: the estimators on fp16 and 8-bit sRGB lookups against f32 ones
#[derive(Parser)]
#[command(bin_name = "cargo eval lookup_precision --")]
struct Args {
    /// Equirectangular .hdr maps (default: the six held-out bundled maps); maps named
    /// apartment, bridge, forest or lab count as training maps, the rest as held out
    #[arg(value_name = "MAPS", value_parser = cli::map_file, verbatim_doc_comment)]
    maps: Vec<PathBuf>,
    /// Write DIR/lookup_precision.md (default target/eval/lookup_precision; `--out docs`
    /// regenerates the repository's docs)
    #[arg(long, value_name = "DIR", verbatim_doc_comment)]
    out: Option<PathBuf>,
    /// Also write rows precision,<estimator>,<tier>,<n>,<map>,<rel_err>,<coverage2s>
    /// (estimator `NAME+noise`: with the declared lookup noise)
    #[arg(long, value_name = "FILE", verbatim_doc_comment)]
    csv: Option<PathBuf>,
    /// One held-out map (lobby), 32 normals, 2 rotations (CI)
    #[arg(long)]
    quick: bool,
    #[command(flatten)]
    threads: cli::Threads,
}

/// `x` as a percentage with 2 decimals.
fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:.2} %", 100.0 * x)
    } else {
        "—".into()
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let raw_args: Vec<String> = std::env::args().skip(1).collect();
    let args = Args::parse();
    let quick = args.quick;
    let out = args.out.unwrap_or_else(|| cli::default_out("lookup_precision"));
    let paths = if !args.maps.is_empty() {
        args.maps
    } else if quick {
        cli::bundled_maps(&["lobby"])
    } else {
        let held: Vec<&str> =
            cli::ALL_MAPS.iter().copied().filter(|m| !cli::TRAINING_MAPS.contains(m)).collect();
        cli::bundled_maps(&held)
    };
    let names: Vec<String> = paths.iter().map(|p| cli::map_name(p)).collect();
    let held_out: Vec<bool> =
        names.iter().map(|n| !cli::TRAINING_MAPS.contains(&n.as_str())).collect();
    let (n_normals, n_rot) = if quick { (32, 2) } else { (96, 6) };
    let start = std::time::Instant::now();
    let envelope = srgb_envelope();
    let mut rng = Rng::new(0x6E0F_0001);
    let v = |d: [f64; 3]| Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
    let rotations: Vec<Mat3> = (0..n_rot)
        .map(|_| {
            let r = rng.uniform_rotation();
            Mat3::from_rows(v(r[0]), v(r[1]), v(r[2]))
        })
        .collect();
    let normals: Vec<Vec3> = (0..n_normals).map(|_| v(rng.uniform_sphere())).collect();
    let maps: Vec<EnvMap> = paths
        .iter()
        .map(|p| EnvMap::load(p).map(|m| compare::clamped(&m)))
        .collect::<Result<_, _>>()
        .map_err(|e| format!("cannot load a map: {e}"))?;
    let results: Vec<MapTallies> = parallel_map(&maps, args.threads.count(), |_, clamp| {
        let lum: Vec<f64> = clamp
            .pixels
            .iter()
            .map(|p| luminance([f64::from(p[0]), f64::from(p[1]), f64::from(p[2])]))
            .collect();
        let truths: Vec<f64> = normals
            .iter()
            .map(|n| {
                let w = reference::truth::cosine_weights(
                    clamp.width,
                    clamp.height,
                    [f64::from(n.x), f64::from(n.y), f64::from(n.z)],
                );
                w.iter().zip(&lum).map(|(a, b)| a * b).sum()
            })
            .collect();
        let eq = EquirectMap::new(clamp.width, clamp.height, &clamp.pixels).expect("a valid map");
        let mut buffer = vec![[0.0f32; 3]; MipPyramid::buffer_len(clamp.width, clamp.height)];
        let pyramid = MipPyramid::new(&eq, &mut buffer).expect("a pyramid of a valid map");
        let scene = Scene {
            clamp,
            pyramid: &pyramid,
            normals: &normals,
            truths: &truths,
            rotations: &rotations,
            envelope,
        };
        run_map(&scene)
    });

    // CSV rows.
    let mut csv = String::from("benchmark,estimator,tier,n,map,rel_err,coverage2s\n");
    for (map, t) in names.iter().zip(&results) {
        for (e, name) in ESTIMATORS.iter().enumerate() {
            for (k, tier) in TIERS.iter().enumerate() {
                for (i, n) in SIZES.iter().enumerate() {
                    let x = &t[e][k][i];
                    if x.count == 0 {
                        continue;
                    }
                    let tn = tier.name();
                    let (r, c, cn) = (x.rel_err(), x.coverage(), x.coverage_noise());
                    let _ = writeln!(csv, "precision,{name},{tn},{n},{map},{r:.6e},{c:.4}");
                    if HAS_NOISE[e] {
                        let rn = x.rel_err_noise();
                        let _ =
                            writeln!(csv, "precision,{name}+noise,{tn},{n},{map},{rn:.6e},{cn:.4}");
                    }
                }
            }
        }
    }

    // The report: held-out maps only.
    let held: Vec<usize> = (0..names.len()).filter(|&m| held_out[m]).collect();
    let held_names: Vec<&str> = held.iter().map(|&m| names[m].as_str()).collect();
    let mut md = String::new();
    writeln!(md, "# Lookups at GPU precision\n")?;
    writeln!(
        md,
        "`{}` ({:.0} s). Irradiance of the `clamp` tier's luminance (the map clamped at 30× its \
         mean) on the held-out maps {}; {n_normals} seeded normals per map, the probes at \
         {n_rot} seeded rotations each. Lookups: `f32` as the crate's samplers return them, \
         `fp16` rounded to the nearest binary16 (ties to even, subnormals, ∞ above 65 504), \
         `srgb8` through an 8-bit sRGB target after the exposure `k = 1/max Yⱼ` of the probe's \
         (or the renderer call's) own lookups, so the brightest lookup is code 255.\n",
        command(&raw_args),
        start.elapsed().as_secs_f64(),
        held_names.join(", ")
    )?;
    writeln!(
        md,
        "Noise term (`FootprintRenderer::set_lookup_noise`; for `layout`, the layout's `Noise`): \
         `fp16` η = 2⁻¹¹/√3 = {:.3e} and σ = 2⁻²⁴/√12; `srgb8` η = Δ(1)/√12 = {:.3e} and \
         σ = {:.3e}/k, the least σ with which σ² + η²v² bounds the rounding variance Δ(v)²/12 \
         of an 8-bit code at every linear value v ∈ [0, 1] of the exposed lookup (Δ(v) the \
         curve's step at v). `probe` and `probe-footprint` have no noise term. With it, the \
         renderer's weights are the same (only its variance grows); the layout's fit takes the \
         noise into its model, so its estimate changes too.\n",
        2f64.powi(-11) / 3f64.sqrt(),
        envelope.1,
        envelope.0
    )?;
    writeln!(
        md,
        "Relative error: RMS(E − E_true)/mean E_true per map. Ratio: a tier's error over the \
         `f32` tier's, as the mean of per-map ratios, the ratio of the mean errors, and the \
         worst map. Coverage: the share of queries with |E − E_true| ≤ 2σ, all held-out maps \
         pooled.\n"
    )?;
    // Per estimator: rows of (N, tier).
    let pooled = |e: usize, k: usize, i: usize| -> Tally {
        let mut p = Tally::default();
        for &m in &held {
            let x = results[m][e][k][i];
            p.count += x.count;
            p.covered += x.covered;
            p.covered_noise += x.covered_noise;
            p.failed += x.failed;
        }
        p
    };
    let mean_err = |e: usize, k: usize, i: usize| -> f64 {
        held.iter().map(|&m| results[m][e][k][i].rel_err()).sum::<f64>() / held.len() as f64
    };
    // With the noise term: the mean error, and the mean and the largest of the per-map ratios
    // to `f32`.
    let with_noise = |e: usize, k: usize, i: usize| -> (f64, f64, f64) {
        let n = held.len() as f64;
        let err = held.iter().map(|&m| results[m][e][k][i].rel_err_noise()).sum::<f64>() / n;
        let per = held
            .iter()
            .map(|&m| results[m][e][k][i].rel_err_noise() / results[m][e][0][i].rel_err_noise());
        let (sum, worst) = per.fold((0.0, f64::NEG_INFINITY), |(s, w), r| (s + r, w.max(r)));
        (err, sum / n, worst)
    };
    let ratios = |e: usize, k: usize, i: usize| -> (f64, f64, f64, String) {
        let per: Vec<f64> = held
            .iter()
            .map(|&m| results[m][e][k][i].rel_err() / results[m][e][0][i].rel_err())
            .collect();
        let mean = per.iter().sum::<f64>() / per.len() as f64;
        let (w, wm) =
            per.iter()
                .zip(&held)
                .fold((f64::NEG_INFINITY, 0), |b, (&r, &m)| if r > b.0 { (r, m) } else { b });
        (mean, mean_err(e, k, i) / mean_err(e, 0, i), w, names[wm].clone())
    };
    for (e, name) in ESTIMATORS.iter().enumerate() {
        writeln!(md, "## `{name}`\n")?;
        writeln!(
            md,
            "| N | tier | error | ratio (mean of maps) | ratio of means | worst map | 2σ | with the noise term: error | ratio (mean of maps) | 2σ |"
        )?;
        writeln!(md, "| ---: | --- | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: |")?;
        for (i, n) in SIZES.iter().enumerate() {
            if pooled(e, 0, i).count == 0 {
                continue;
            }
            for (k, tier) in TIERS.iter().enumerate() {
                let p = pooled(e, k, i);
                let (mean, of_means, worst, wmap) = ratios(e, k, i);
                let noise = if HAS_NOISE[e] {
                    let (err, ratio, _) = with_noise(e, k, i);
                    let ratio = if k == 0 { "—".to_string() } else { format!("{ratio:.3}") };
                    format!("{} | {ratio} | {}", pct(err), pct(p.coverage_noise()))
                } else {
                    "— | — | —".to_string()
                };
                let failed =
                    if p.failed > 0 { format!(" ({} failed)", p.failed) } else { String::new() };
                let rs = if k == 0 {
                    ("—".to_string(), "—".to_string(), "—".to_string())
                } else {
                    (format!("{mean:.3}"), format!("{of_means:.3}"), format!("{worst:.3} ({wmap})"))
                };
                writeln!(
                    md,
                    "| {n} | {} | {}{failed} | {} | {} | {} | {} | {noise} |",
                    tier.name(),
                    pct(mean_err(e, k, i)),
                    rs.0,
                    rs.1,
                    rs.2,
                    pct(p.coverage()),
                )?;
            }
        }
        writeln!(md)?;
    }
    // Targets.
    writeln!(md, "## Targets\n")?;
    writeln!(
        md,
        "Held-out maps, N = 16–128: the error ratio to `f32` (mean of per-map ratios; worst \
         map) at most 1.05 for `fp16` and 1.5 for `srgb8`, and 2σ coverage in [85 %, 99.5 %], \
         both with the noise term (without, for the estimators that have none; the ratio \
         without it beside); the renderer's error not higher at N = 64 than at N = 32 on any \
         tier.\n"
    )?;
    writeln!(
        md,
        "| estimator | tier | worst mean ratio (N) | worst map ratio | without the noise term: worst mean ratio (N) | coverage range | met |"
    )?;
    writeln!(md, "| --- | --- | ---: | ---: | ---: | ---: | --- |")?;
    for (e, name) in ESTIMATORS.iter().enumerate() {
        for (k, tier) in TIERS.iter().enumerate() {
            let sizes: Vec<usize> =
                (0..SIZES.len()).filter(|&i| pooled(e, 0, i).count > 0).collect();
            let (mut worst_mean, mut at, mut worst_map) = (0.0f64, 0, 0.0f64);
            let (mut worst_plain, mut at_plain) = (0.0f64, 0);
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for &i in &sizes {
                let (plain, _, plain_map, _) = ratios(e, k, i);
                let (mean, w) = if HAS_NOISE[e] {
                    let (_, mean, worst) = with_noise(e, k, i);
                    (mean, worst)
                } else {
                    (plain, plain_map)
                };
                if mean > worst_mean {
                    (worst_mean, at) = (mean, SIZES[i]);
                }
                if plain > worst_plain {
                    (worst_plain, at_plain) = (plain, SIZES[i]);
                }
                worst_map = worst_map.max(w);
                let p = pooled(e, k, i);
                let c = if HAS_NOISE[e] { p.coverage_noise() } else { p.coverage() };
                lo = lo.min(c);
                hi = hi.max(c);
            }
            let bound = match tier {
                Tier::F32 => f64::INFINITY,
                Tier::Fp16 => 1.05,
                Tier::Srgb8 => 1.5,
            };
            let met = worst_mean <= bound && lo >= 0.85 && hi <= 0.995;
            let ratio = if k == 0 { "—".to_string() } else { format!("{worst_mean:.3} ({at})") };
            let wm = if k == 0 { "—".to_string() } else { format!("{worst_map:.3}") };
            let plain = if k == 0 || !HAS_NOISE[e] {
                "—".to_string()
            } else {
                format!("{worst_plain:.3} ({at_plain})")
            };
            writeln!(
                md,
                "| `{name}` | {} | {ratio} | {wm} | {plain} | {}–{} | {} |",
                tier.name(),
                pct(lo),
                pct(hi),
                if met { "yes" } else { "no" }
            )?;
        }
    }
    writeln!(md)?;
    writeln!(md, "The renderer from N = 32 to N = 64 (mean error over the held-out maps):\n")?;
    writeln!(md, "| tier | N = 32 | N = 64 | rises |")?;
    writeln!(md, "| --- | ---: | ---: | --- |")?;
    for (k, tier) in TIERS.iter().enumerate() {
        let (a, b) = (mean_err(0, k, 1), mean_err(0, k, 2));
        writeln!(
            md,
            "| {} | {} | {} | {} |",
            tier.name(),
            pct(a),
            pct(b),
            if b > a { "yes" } else { "no" }
        )?;
    }

    if let Some(path) = &args.csv {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(path, &csv)?;
        eprintln!("wrote {}", path.display());
    }
    std::fs::create_dir_all(&out)?;
    let path = out.join("lookup_precision.md");
    std::fs::write(&path, &md)?;
    print!("{md}");
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// The command line as the report records it.
fn command(raw_args: &[String]) -> String {
    if raw_args.is_empty() {
        "cargo eval lookup_precision".to_string()
    } else {
        format!("cargo eval lookup_precision -- {}", raw_args.join(" "))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// binary16 against its definition: exact values stay, halfway cases go to even, the
    /// subnormal step is 2⁻²⁴, 65 504 is the largest finite value.
    #[test]
    fn fp16_rounds_to_nearest_even() {
        assert_eq!(fp16(1.0), 1.0);
        assert_eq!(fp16(1.0 + 2f64.powi(-11)), 1.0); // halfway: to even
        assert_eq!(fp16(1.0 + 3.0 * 2f64.powi(-11)), 1.0 + 2.0 * 2f64.powi(-10));
        assert_eq!(fp16(1.0 + 1.1 * 2f64.powi(-11)), 1.0 + 2f64.powi(-10));
        assert_eq!(fp16(65_504.0), 65_504.0);
        assert_eq!(fp16(65_519.9), 65_504.0);
        assert_eq!(fp16(65_520.0), f64::INFINITY);
        assert_eq!(fp16(2f64.powi(-24)), 2f64.powi(-24));
        assert_eq!(fp16(0.4 * 2f64.powi(-24)), 0.0);
        assert_eq!(fp16(0.6 * 2f64.powi(-24)), 2f64.powi(-24));
        assert_eq!(fp16(3.0 * 2f64.powi(-25)), 2f64.powi(-23)); // 1.5 steps: to even (2)
        assert_eq!(fp16(0.1), 0.0999755859375); // binary16's 0x2E66
                                                // Relative error at most half an ulp: 2⁻¹¹ of the value in the normal range.
        let mut rng = Rng::new(1);
        for _ in 0..10_000 {
            let x = 2f64.powf(30.0 * rng.next_f64() - 14.0);
            assert!(((fp16(x) - x) / x).abs() <= 2f64.powi(-11) * (1.0 + 1e-12), "{x}");
        }
    }

    /// The sRGB curve: continuous at the joint, inverse pairs, codes 0 and 255 exact, and the
    /// round trip within half a step of the code.
    #[test]
    fn srgb_round_trips() {
        assert!((srgb_encode(0.003_130_8) - 0.040_45).abs() < 1e-5);
        for i in 0..=255 {
            let c = f64::from(i) / 255.0;
            assert!((srgb_encode(srgb_decode(c)) - c).abs() < 1e-12, "{i}");
        }
        assert_eq!(srgb8(2.0, 0.5), 2.0);
        assert_eq!(srgb8(0.0, 0.5), 0.0);
        for i in 0..1000 {
            let v = f64::from(i) / 999.0;
            let q = srgb8(v, 1.0);
            assert!((srgb_encode(q) - srgb_encode(v)).abs() <= 0.5 / 255.0 + 1e-12, "{v}");
        }
        let (sigma, eta) = srgb_envelope();
        // Δ(1) = 2.4/(1.055·255) = 8.92·10⁻³.
        assert!((eta * 12f64.sqrt() - 2.4 / (1.055 * 255.0)).abs() < 1e-9);
        assert!(sigma > 0.0 && sigma < eta);
    }
}
