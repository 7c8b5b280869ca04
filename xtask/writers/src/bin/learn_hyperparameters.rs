//! Learns the Gaussian-process hyperparameters of Bayesian Monte Carlo offline (issue #6,
//! item 2; seed "Learn the hyperparameters").
//!
//! ```text
//! cargo writer learn_hyperparameters                 # print the report
//! cargo writer learn_hyperparameters -- --write      # and write the tables
//! cargo writer learn_hyperparameters -- a.hdr b.hdr   # other maps (`--maps a.hdr b.hdr` too)
//! cargo xtask regen hyperparameters                   # the write, in the pipeline's order
//! ```
//!
//! Model: k(x, x′) = σ_f²·exp(−|x − x′|²/l²) + σ_n²δ on unit vectors, |x − x′|² = 2 − 2x·x′,
//! sharpness λ = 2/l², σ′ = σ_n/σ_f, Q = K + σ′²I with Kᵢⱼ = exp(λ(xᵢ·xⱼ − 1)), constant prior
//! mean by generalised least squares.
//!
//! Training data for the probe form: the N-point spherical Fibonacci sphere set, rotated as a
//! whole by 32 seeded uniform rotations per map, reading Yⱼ = luminance of the nearest pixel of
//! each of the two lighting tiers that `eval/src/bin/accuracy.rs` builds from a map: `clamp` (each
//! pixel's luminance clamped at 30 × the map's solid-angle mean) and `smooth` (the clamped map
//! box-downsampled to 128×64 and convolved with the normalised spherical Gaussian of sharpness
//! 10, `common/tiers.rs`), the same rotations in both tiers. The training maps are apartment,
//! bridge, forest and lab; city, dawn, hall, lobby, night and park are held out for evaluation
//! elsewhere and never read here.
//!
//! 1. Seed's method (`clamp` tier only): standardise each probe (subtract the mean, divide by the standard
//!    deviation), bin the products YᵢYⱼ by d² = |xᵢ − xⱼ|² (40 bins over [0, 4], i = j apart),
//!    fit c(d²) = a·exp(−d²/l²) for d > 0 by count-weighted least squares (a in closed form,
//!    l by a log-grid and golden-section search) and read the nugget from the gap at d = 0:
//!    σ′² = (c(0) − a)/a.
//! 2. Maximum marginal likelihood: the REML profile log-likelihood with σ_f profiled out,
//!    ℓ = −½·log det Q − ½·log(1ᵀQ⁻¹1) − ((N−1)/2)·log(rᵀQ⁻¹r), r = Y − β1,
//!    β = 1ᵀQ⁻¹Y / 1ᵀQ⁻¹1 (Cholesky in f64), summed over the probes on a (λ, σ′) grid (per tier
//!    and over both); and for the ladder λ ∈ {1, 4, 16, 64} with per-probe selection (each
//!    probe takes its member of highest ℓ) the σ′ that maximises the summed best-member ℓ over
//!    the training probes of BOTH tiers (the written σ′). A probe does not know which tier it
//!    is in, so its σ′ must serve both; trained on `clamp` alone, ML chose σ′ = 1 for N ≥ 32,
//!    which over-smooths low-noise (`smooth`) lighting. The per-tier optima are printed too.
//! 3. Renderer form (irradiance from the N-point uniform hemisphere SF set about the normal):
//!    (l, σ′) by maximum marginal likelihood on synthetic radiance fields (1–4 spherical
//!    Gaussians plus a constant), with the relative RMS error of the BMC estimate
//!    E ≈ π·Σ wᵢYᵢ and of the crate's cosine-morphed QMC-SF estimate against exact irradiance.
//!
//! Also printed: a recovery check (both methods on draws from the GP prior itself, where the
//! truth is known) and, for the ladder, ℓ beyond the σ′ grid (diagnostic only).
//!
//! With `--write` it writes `tables/probe.txt` (`probe = N sigma lambda1 …`),
//! `tables/bmc_smooth.txt` (`set = N l sigma`: the renderer's smooth-light preset, which a user
//! selects with `SPHERE_QUADRATURE_BMC_TABLE`; the shipped `tables/bmc.txt` is learned on real
//! maps by `cargo xtask regen renderer-hyperparameters`) and the report `docs/hyperparameters.md`; without it,
//! it only prints the report. Q depends only on the point set's dot products, so one Cholesky
//! factor per (N, λ, σ′) serves every rotation.

use sphere_quadrature_eval::{cli, compare, tiers};

use tiers::Mixture;

use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use cli::TRAINING_MAPS;
use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use reference::sf::{hemisphere_point, sphere_point};
use reference::vec::mat_mul_vec;
use sphere_quadrature::{qmc, Vec3};

/// Sample counts learned for (the sizes `tables/` bakes).
const NS: [usize; 5] = [16, 32, 64, 128, 256];
/// Held out for evaluation by another tool; never read here.
const HELD_OUT_MAPS: [&str; 6] = ["city", "dawn", "hall", "lobby", "night", "park"];
/// Random rotations of the probe set per map.
const ROTATIONS: usize = 32;
/// Seed of map m's rotations is `ROTATION_SEED + m` (the same rotations for every N).
const ROTATION_SEED: u64 = 0x5EED_0000;
/// Bins of d² = |x − x′|² over [0, 4] for the empirical covariance.
const BINS: usize = 40;
/// N whose covariance table and likelihood grid are printed in full.
const SHOWN_N: usize = 64;
/// Sharpness grid of the probe-form likelihood.
const LAMBDAS: [f64; 10] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0];
/// σ′ grid of the probe-form likelihood (and of the ladder's objective).
const SIGMAS: [f64; 7] = [0.03, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0];
/// The lighting tiers the probe form trains on (index 0 and 1 of the per-tier arrays).
const TIERS: [&str; 2] = ["clamp", "smooth"];
/// The probe family: per-probe selection among these sharpnesses.
const LADDER: [f64; 4] = [1.0, 4.0, 16.0, 64.0];
/// σ′ beyond the grid, for the ladder only: a diagnostic, never written.
const BEYOND_SIGMAS: [f64; 3] = [1.5, 2.0, 3.0];
/// Length-scale grid of the renderer form.
const LENGTHS: [f64; 9] = [0.25, 0.3, 0.35, 0.4, 0.5, 0.6, 0.7, 0.85, 1.0];
/// σ′ grid of the renderer form.
const RENDER_SIGMAS: [f64; 4] = [1e-4, 1e-3, 1e-2, 1e-1];
/// Seed of the synthetic training fields (the evaluation tool uses another).
const SYNTH_SEED: u64 = 0x5EED_0001;
/// Synthetic training fields (the same fields for every N).
const DRAWS: usize = 200;

/// Prints a line and appends it to the report.
macro_rules! emit {
    ($rep:expr) => {{
        println!();
        $rep.push('\n');
    }};
    ($rep:expr, $($arg:tt)*) => {{
        let line = format!($($arg)*);
        println!("{line}");
        $rep.push_str(&line);
        $rep.push('\n');
    }};
}

/// Lower Cholesky factor of the row-major `n × n` matrix `a`, in place (upper part left
/// as is); `None` if `a` is not numerically positive definite.
fn cholesky(a: &mut [f64], n: usize) -> Option<()> {
    for j in 0..n {
        let (head, tail) = a.split_at_mut((j + 1) * n);
        let row_j = &mut head[j * n..];
        let d = row_j[j] - row_j[..j].iter().map(|v| v * v).sum::<f64>();
        if d.is_nan() || d <= 0.0 {
            return None;
        }
        row_j[j] = d.sqrt();
        let row_j = &*row_j;
        for row_i in tail.chunks_exact_mut(n) {
            let s: f64 = row_i[..j].iter().zip(&row_j[..j]).map(|(p, q)| p * q).sum();
            row_i[j] = (row_i[j] - s) / row_j[j];
        }
    }
    Some(())
}

/// `L⁻¹b` for a lower-triangular row-major factor `l`.
fn forward(l: &[f64], n: usize, b: &[f64]) -> Vec<f64> {
    let mut x = b.to_vec();
    for i in 0..n {
        let row = &l[i * n..i * n + i];
        let s: f64 = row.iter().zip(&x[..i]).map(|(p, q)| p * q).sum();
        x[i] = (x[i] - s) / l[i * n + i];
    }
    x
}

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum()
}

/// One Gaussian process on a fixed point set: the Cholesky factor of Q and what the REML
/// likelihood needs from it.
struct Gp {
    n: usize,
    chol: Vec<f64>,
    /// ½·log det Q.
    half_logdet: f64,
    /// u = L⁻¹1.
    u: Vec<f64>,
    /// 1ᵀQ⁻¹1 = u·u.
    uu: f64,
}

impl Gp {
    fn new(points: &[[f64; 3]], lambda: f64, sigma: f64) -> Option<Gp> {
        let n = points.len();
        let mut q = vec![0.0; n * n];
        for (i, &a) in points.iter().enumerate() {
            for (j, &b) in points.iter().enumerate() {
                q[i * n + j] =
                    (-0.5 * lambda * dist2(a, b)).exp() + if i == j { sigma * sigma } else { 0.0 };
            }
        }
        cholesky(&mut q, n)?;
        let half_logdet = (0..n).map(|i| q[i * n + i].ln()).sum();
        let u = forward(&q, n, &vec![1.0; n]);
        let uu = u.iter().map(|v| v * v).sum();
        Some(Gp { n, chol: q, half_logdet, u, uu })
    }

    /// REML profile log-likelihood of the samples `y` (σ_f profiled out, constants dropped);
    /// −∞ for a constant probe.
    fn reml(&self, y: &[f64]) -> f64 {
        let v = forward(&self.chol, self.n, y);
        let beta = self.u.iter().zip(&v).map(|(a, b)| a * b).sum::<f64>() / self.uu;
        let rr: f64 = v.iter().zip(&self.u).map(|(v, u)| (v - beta * u).powi(2)).sum();
        if rr <= 0.0 || rr.is_nan() {
            return f64::NEG_INFINITY;
        }
        -self.half_logdet - 0.5 * self.uu.ln() - 0.5 * (self.n as f64 - 1.0) * rr.ln()
    }
}

/// Empirical covariance of standardised probes, binned by d².
#[derive(Clone)]
struct Covariance {
    sum: [f64; BINS],
    sum_d2: [f64; BINS],
    pairs: [u64; BINS],
    diag_sum: f64,
    diag_count: u64,
}

impl Covariance {
    fn new() -> Self {
        Covariance {
            sum: [0.0; BINS],
            sum_d2: [0.0; BINS],
            pairs: [0; BINS],
            diag_sum: 0.0,
            diag_count: 0,
        }
    }

    /// Adds one probe (already standardised); `d2` is the n × n table of |xᵢ − xⱼ|².
    fn add(&mut self, y: &[f64], d2: &[f64]) {
        let n = y.len();
        for i in 0..n {
            self.diag_sum += y[i] * y[i];
            self.diag_count += 1;
            for j in 0..n {
                if i != j {
                    let d = d2[i * n + j];
                    let b = ((d / 4.0 * BINS as f64) as usize).min(BINS - 1);
                    self.sum[b] += y[i] * y[j];
                    self.sum_d2[b] += d;
                    self.pairs[b] += 1;
                }
            }
        }
    }

    /// (mean d², mean product, pairs) of the non-empty off-diagonal bins.
    fn points(&self) -> Vec<(f64, f64, u64)> {
        (0..BINS)
            .filter(|&b| self.pairs[b] > 0)
            .map(|b| {
                let c = self.pairs[b] as f64;
                (self.sum_d2[b] / c, self.sum[b] / c, self.pairs[b])
            })
            .collect()
    }

    fn c0(&self) -> f64 {
        self.diag_sum / self.diag_count as f64
    }
}

/// The seed's fit: (a, b, l) of c(d²) = a·exp(−d²/l²) + b by pair-count weighted least
/// squares with a ≥ 0; b = 0 unless `offset` (then b absorbs the constant that standardising
/// by the probe's own mean subtracts, −1/(N−1) on average, and real anticorrelation).
fn fit_covariance(points: &[(f64, f64, u64)], offset: bool) -> (f64, f64, f64) {
    // For a fixed l the best (a, b) is closed-form; returns (residual, a, b).
    let eval = |l: f64| {
        let (mut sw, mut se, mut see, mut sc, mut sce) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for &(d2, c, w) in points {
            let (w, e) = (w as f64, (-d2 / (l * l)).exp());
            sw += w;
            se += w * e;
            see += w * e * e;
            sc += w * c;
            sce += w * c * e;
        }
        let (mut a, mut b) = if offset {
            let det = see * sw - se * se;
            if det > 0.0 {
                ((sce * sw - se * sc) / det, (see * sc - se * sce) / det)
            } else {
                (0.0, sc / sw)
            }
        } else {
            (if see > 0.0 { sce / see } else { 0.0 }, 0.0)
        };
        if a < 0.0 {
            a = 0.0;
            b = if offset { sc / sw } else { 0.0 };
        }
        let res: f64 = points
            .iter()
            .map(|&(d2, c, w)| w as f64 * (c - a * (-d2 / (l * l)).exp() - b).powi(2))
            .sum();
        (res, a, b)
    };
    // Log grid over l ∈ [0.02, 8], then golden section in log l around the best node.
    let (lo, hi, steps) = (0.02f64.ln(), 8.0f64.ln(), 400);
    let node = |k: usize| lo + (hi - lo) * k as f64 / steps as f64;
    let best = (0..=steps).min_by(|&a, &b| eval(node(a).exp()).0.total_cmp(&eval(node(b).exp()).0));
    let k = best.unwrap_or(0);
    let (mut a, mut b) = (node(k.saturating_sub(1)), node((k + 1).min(steps)));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..80 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if eval(c.exp()).0 < eval(d.exp()).0 {
            b = d;
        } else {
            a = c;
        }
    }
    let l = (0.5 * (a + b)).exp();
    let (_, a, b) = eval(l);
    (a, b, l)
}

/// A standard normal deviate (Box–Muller).
fn normal(rng: &mut Rng) -> f64 {
    let (u1, u2) = (1.0 - rng.next_f64(), rng.next_f64());
    (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
}

/// Recovery check of both methods: `count` probes drawn from the GP prior itself (σ_f = 1,
/// mean 0.5) at the sphere set of `n` points; returns the seed method's (l, σ′²) and the
/// REML arg-max (λ, σ′) over the probe grid.
fn recovery_check(n: usize, lambda: f64, sigma: f64, count: usize) -> ((f64, f64), (f64, f64)) {
    let points: Vec<[f64; 3]> = (0..n as u64).map(|j| sphere_point(j, n as u64)).collect();
    let gp = Gp::new(&points, lambda, sigma).expect("positive definite");
    let mut rng = Rng::new(0xC4EC_0000);
    let samples: Vec<Vec<f64>> = (0..count)
        .map(|_| {
            let xi: Vec<f64> = (0..n).map(|_| normal(&mut rng)).collect();
            (0..n).map(|i| 0.5 + (0..=i).map(|k| gp.chol[i * n + k] * xi[k]).sum::<f64>()).collect()
        })
        .collect();
    let d2: Vec<f64> =
        points.iter().flat_map(|&a| points.iter().map(move |&b| dist2(a, b))).collect();
    let mut cov = Covariance::new();
    for y in &samples {
        if let Some(s) = standardise(y) {
            cov.add(&s, &d2);
        }
    }
    let (a, _, l) = fit_covariance(&cov.points(), false);
    let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
    for &lam in &LAMBDAS {
        for &sig in &SIGMAS {
            if let Some(g) = Gp::new(&points, lam, sig) {
                let ll: f64 = samples.iter().map(|y| g.reml(y)).sum();
                if ll > best.0 {
                    best = (ll, lam, sig);
                }
            }
        }
    }
    ((l, (cov.c0() - a) / a), (best.1, best.2))
}

/// Subtracts the mean and divides by the (population) standard deviation; `None` for a
/// constant probe.
fn standardise(y: &[f64]) -> Option<Vec<f64>> {
    let n = y.len() as f64;
    let mean = y.iter().sum::<f64>() / n;
    let sd = (y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    (sd > 0.0).then(|| y.iter().map(|v| (v - mean) / sd).collect())
}

/// The luminance samples of every training probe for one N: map-major, rotation-minor.
fn probe_samples(maps: &[EnvMap], rotations: &[Vec<[[f64; 3]; 3]>], n: usize) -> Vec<Vec<f64>> {
    let points: Vec<[f64; 3]> = (0..n as u64).map(|j| sphere_point(j, n as u64)).collect();
    let mut out = Vec::new();
    for (map, rots) in maps.iter().zip(rotations) {
        for &r in rots {
            out.push(points.iter().map(|&p| luminance(map.radiance(mat_mul_vec(r, p)))).collect());
        }
    }
    out
}

/// QMC-SF irradiance about +z from the crate (cosine-morphed hemisphere SF, phase 0).
fn qmc_sf_n<const N: usize>(fields: &[Mixture]) -> Vec<f64> {
    fields
        .iter()
        .map(|f| {
            qmc::irradiance::<N, f32, _>(Vec3::Z, 0, |d| {
                f.value([f64::from(d.x), f64::from(d.y), f64::from(d.z)]) as f32
            })
            .map_or(f64::NAN, f64::from)
        })
        .collect()
}

fn qmc_sf(n: usize, fields: &[Mixture]) -> Vec<f64> {
    match n {
        16 => qmc_sf_n::<16>(fields),
        32 => qmc_sf_n::<32>(fields),
        64 => qmc_sf_n::<64>(fields),
        128 => qmc_sf_n::<128>(fields),
        256 => qmc_sf_n::<256>(fields),
        _ => unreachable!("NS lists only these sizes"),
    }
}

/// RMSE / mean |truth|.
fn rel_rms(est: &[f64], truth: &[f64]) -> f64 {
    let se: f64 = est.iter().zip(truth).map(|(e, t)| (e - t).powi(2)).sum();
    let mean_abs = truth.iter().map(|t| t.abs()).sum::<f64>() / truth.len() as f64;
    (se / truth.len() as f64).sqrt() / mean_abs
}

/// Index of the largest value (NaN-safe: −∞ and NaN lose).
fn argmax(v: &[f64]) -> usize {
    let key = |x: f64| if x.is_nan() { f64::NEG_INFINITY } else { x };
    (0..v.len()).max_by(|&a, &b| key(v[a]).total_cmp(&key(v[b]))).unwrap_or(0)
}

/// Learned figures of the probe form at one N.
struct ProbeResult {
    n: usize,
    seed_a: f64,
    seed_l: f64,
    seed_sigma2: f64,
    /// The same fit with a constant offset: (a, b, l).
    offset_fit: (f64, f64, f64),
    /// Full-grid arg-max (λ*, σ′*): `clamp`, `smooth`, both tiers.
    ml: [(f64, f64); 3],
    /// Summed best-member ℓ of the ladder per σ′: `clamp`, `smooth`, both tiers.
    ladder_ll: [[f64; SIGMAS.len()]; 3],
    /// The ladder's ML σ′ of the combined objective (the written value).
    ladder_sigma: f64,
    /// Wins of each ladder member at `ladder_sigma`, per tier.
    ladder_counts: [[usize; LADDER.len()]; 2],
    /// Summed best-member ℓ of the ladder (both tiers) at `BEYOND_SIGMAS`.
    beyond_ll: [f64; BEYOND_SIGMAS.len()],
    /// Usable (non-constant) probes per tier.
    probes: [usize; 2],
}

/// Learned figures of the renderer form at one N.
struct RenderResult {
    n: usize,
    /// Summed ℓ, [length][sigma].
    ll: Vec<[f64; RENDER_SIGMAS.len()]>,
    /// BMC relative RMS, [length][sigma].
    rms: Vec<[f64; RENDER_SIGMAS.len()]>,
    ml: (usize, usize),
    qmc_rms: f64,
}

/// learn_hyperparameters: learns the Gaussian-process hyperparameters of Bayesian Monte Carlo
/// offline (issue #6): prints the report; --write also rewrites tables/ and the docs
#[derive(Parser)]
#[command(bin_name = "cargo writer learn_hyperparameters --", verbatim_doc_comment)]
struct Args {
    /// Equirectangular .hdr training maps (default: apartment, bridge, forest and lab in
    /// examples/envmaps/)
    #[arg(value_name = "MAPS", value_parser = cli::map_file, verbatim_doc_comment)]
    maps: Vec<PathBuf>,
    /// The maps, as the earlier `--maps a.hdr b.hdr …` (same as positional MAPS)
    #[arg(long = "maps", value_name = "MAPS", num_args = 1.., hide = true)]
    #[arg(value_parser = cli::map_file)]
    maps_option: Vec<PathBuf>,
    /// Also write the report to DIR/hyperparameters.md
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Write tables/probe.txt, tables/bmc_smooth.txt and docs/hyperparameters.md
    #[arg(long)]
    write: bool,
}

fn main() {
    let start = Instant::now();
    let args = Args::parse();
    let write = args.write;
    let mut custom = args.maps;
    custom.extend(args.maps_option);
    let root = cli::repo_root();
    let paths: Vec<PathBuf> =
        if custom.is_empty() { cli::bundled_maps(&TRAINING_MAPS) } else { custom };
    let names: Vec<String> = paths.iter().map(|p| cli::map_name(p)).collect();
    let maps: Vec<EnvMap> = paths
        .iter()
        .map(|p| {
            let map = EnvMap::load(p).unwrap_or_else(|e| {
                eprintln!("cannot load {}: {e}", p.display());
                std::process::exit(1);
            });
            compare::clamped(&map)
        })
        .collect();
    let t = Instant::now();
    let smooth_maps: Vec<EnvMap> = maps.iter().map(tiers::smooth).collect();
    println!("(smooth tier built: {:.2} s)", t.elapsed().as_secs_f64());
    let tier_maps: [&[EnvMap]; 2] = [&maps, &smooth_maps];
    let rotations: Vec<Vec<[[f64; 3]; 3]>> = (0..maps.len())
        .map(|m| {
            let mut rng = Rng::new(ROTATION_SEED + m as u64);
            (0..ROTATIONS).map(|_| rng.uniform_rotation()).collect()
        })
        .collect();

    let mut rep = String::new();
    emit!(rep, "# Learned Gaussian-process hyperparameters (issue #6)");
    emit!(rep);
    emit!(
        rep,
        "Written by `cargo xtask regen hyperparameters` \
         (`xtask/writers/src/bin/learn_hyperparameters.rs`; its module docs explain the method)."
    );
    emit!(rep);
    emit!(
        rep,
        "Kernel k(x, x′) = σ_f²·exp(−|x − x′|²/l²) + σ_n²δ, λ = 2/l², σ′ = σ_n/σ_f, \
         Q = K + σ′²I, constant prior mean by GLS."
    );
    emit!(rep);
    emit!(
        rep,
        "- Training maps ({}): {}. Two lighting tiers of each, as `eval/src/bin/accuracy.rs` builds \
         them: `clamp` (luminance clamped at {}× the map's solid-angle mean) and `smooth` (the \
         clamped map box-downsampled to {}×{} and convolved with the normalised spherical \
         Gaussian of sharpness {}).",
        maps.len(),
        names.join(", "),
        compare::CLAMP,
        tiers::SMOOTH_WIDTH,
        tiers::SMOOTH_HEIGHT,
        tiers::SMOOTH_SHARPNESS
    );
    if paths.iter().all(|p| p.starts_with(root.join("examples/envmaps"))) && names.len() == 4 {
        emit!(
            rep,
            "- Held out (never read by this tool; for evaluation elsewhere): {}.",
            HELD_OUT_MAPS.join(", ")
        );
    }
    emit!(
        rep,
        "- Probe set: N-point spherical Fibonacci sphere set, {ROTATIONS} uniform rotations per \
         map (map m's from `Rng::new({ROTATION_SEED:#x} + m)`, the same in both tiers), \
         nearest-pixel luminance."
    );
    emit!(
        rep,
        "- **The probe family's σ′ (written to `tables/probe.txt`) maximises the ladder's summed \
         best-member ℓ over the training probes of BOTH tiers.** A probe does not know which \
         tier it is in, so one σ′ must serve both; trained on `clamp` alone, ML chose σ′ = 1 \
         for N ≥ 32, which over-smooths low-noise lighting (the benchmark's `smooth` tier got \
         5–8× worse than with σ′ = 0.3). The seed's method below uses the `clamp` tier only."
    );
    emit!(
        rep,
        "- Renderer set: N-point uniform hemisphere SF set about the normal; {DRAWS} synthetic \
         fields from `Rng::new({SYNTH_SEED:#x})`, the same fields for every N."
    );

    // ---- Probe form: seed's method and maximum likelihood ----
    let mut probe_results = Vec::new();
    let mut shown_cov = None;
    let mut shown_ll = None;
    for &n in &NS {
        let t = Instant::now();
        let points: Vec<[f64; 3]> = (0..n as u64).map(|j| sphere_point(j, n as u64)).collect();
        let d2: Vec<f64> =
            points.iter().flat_map(|&a| points.iter().map(move |&b| dist2(a, b))).collect();
        let tier_samples: Vec<Vec<Vec<f64>>> =
            tier_maps.iter().map(|m| probe_samples(m, &rotations, n)).collect();
        let samples = &tier_samples[0];
        let mut cov = Covariance::new();
        for y in samples {
            if let Some(s) = standardise(y) {
                cov.add(&s, &d2);
            }
        }
        let (seed_a, _, seed_l) = fit_covariance(&cov.points(), false);
        let seed_sigma2 = (cov.c0() - seed_a) / seed_a;
        let offset_fit = fit_covariance(&cov.points(), true);

        // ℓ[tier][probe][λ][σ′].
        let usable: Vec<Vec<&Vec<f64>>> = tier_samples
            .iter()
            .map(|ys| ys.iter().filter(|y| standardise(y).is_some()).collect())
            .collect();
        let mut ll: Vec<Vec<[[f64; SIGMAS.len()]; LAMBDAS.len()]>> = usable
            .iter()
            .map(|u| vec![[[f64::NEG_INFINITY; SIGMAS.len()]; LAMBDAS.len()]; u.len()])
            .collect();
        for (li, &lambda) in LAMBDAS.iter().enumerate() {
            for (si, &sigma) in SIGMAS.iter().enumerate() {
                if let Some(gp) = Gp::new(&points, lambda, sigma) {
                    for (tier_ll, tier_usable) in ll.iter_mut().zip(&usable) {
                        for (p, y) in tier_usable.iter().enumerate() {
                            tier_ll[p][li][si] = gp.reml(y);
                        }
                    }
                }
            }
        }
        // Summed ℓ per (λ, σ′): `clamp`, `smooth`, both tiers.
        let mut total = [[[0.0; SIGMAS.len()]; LAMBDAS.len()]; 3];
        for (t, tier_ll) in ll.iter().enumerate() {
            for probe in tier_ll {
                for li in 0..LAMBDAS.len() {
                    for si in 0..SIGMAS.len() {
                        total[t][li][si] += probe[li][si];
                        total[2][li][si] += probe[li][si];
                    }
                }
            }
        }
        let ml = total.map(|tot| {
            let flat: Vec<f64> = tot.iter().flatten().copied().collect();
            let best = argmax(&flat);
            (LAMBDAS[best / SIGMAS.len()], SIGMAS[best % SIGMAS.len()])
        });

        let ladder_idx: Vec<usize> = LADDER
            .iter()
            .map(|&l| LAMBDAS.iter().position(|&x| x == l).expect("ladder ⊂ grid"))
            .collect();
        let mut ladder_ll = [[0.0; SIGMAS.len()]; 3];
        for (t, tier_ll) in ll.iter().enumerate() {
            for probe in tier_ll {
                for si in 0..SIGMAS.len() {
                    let best = ladder_idx
                        .iter()
                        .map(|&li| probe[li][si])
                        .fold(f64::NEG_INFINITY, f64::max);
                    ladder_ll[t][si] += best;
                    ladder_ll[2][si] += best;
                }
            }
        }
        let ls = argmax(&ladder_ll[2]);
        let mut beyond_ll = [0.0; BEYOND_SIGMAS.len()];
        for (acc, &sigma) in beyond_ll.iter_mut().zip(&BEYOND_SIGMAS) {
            let gps: Vec<Option<Gp>> = LADDER.iter().map(|&l| Gp::new(&points, l, sigma)).collect();
            for y in usable.iter().flatten() {
                *acc += gps
                    .iter()
                    .map(|g| g.as_ref().map_or(f64::NEG_INFINITY, |g| g.reml(y)))
                    .fold(f64::NEG_INFINITY, f64::max);
            }
        }
        let mut ladder_counts = [[0; LADDER.len()]; 2];
        for (counts, tier_ll) in ladder_counts.iter_mut().zip(&ll) {
            for probe in tier_ll {
                let vals: Vec<f64> = ladder_idx.iter().map(|&li| probe[li][ls]).collect();
                counts[argmax(&vals)] += 1;
            }
        }
        if n == SHOWN_N {
            shown_cov = Some((cov.clone(), seed_a, seed_l));
            shown_ll = Some(total);
        }
        println!("(probe form, N = {n}: {:.2} s)", t.elapsed().as_secs_f64());
        probe_results.push(ProbeResult {
            n,
            seed_a,
            seed_l,
            seed_sigma2,
            offset_fit,
            ml,
            ladder_ll,
            ladder_sigma: SIGMAS[ls],
            ladder_counts,
            beyond_ll,
            probes: [usable[0].len(), usable[1].len()],
        });
    }

    emit!(rep);
    emit!(rep, "## Probe form, seed's method (empirical covariance, fitted kernel)");
    emit!(rep);
    emit!(
        rep,
        "`clamp` tier only (diagnostic; nothing written comes from it). Each probe standardised (mean 0, population standard deviation 1, so c(0) = 1); \
         products YᵢYⱼ binned by d² = |xᵢ − xⱼ|² into {BINS} bins over [0, 4], pooled over all \
         maps and rotations; c(d²) = a·exp(−d²/l²) fitted to the d > 0 bins by pair-count \
         weighted least squares; nugget σ′² = (c(0) − a)/a."
    );
    emit!(rep);
    emit!(
        rep,
        "| N | probes | a | l | λ = 2/l² | σ′ | with offset: a | b | l | λ | σ′ = √((c(0) − a − b)/a) |"
    );
    emit!(rep, "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    let nugget = |s2: f64| {
        if s2 >= 0.0 && s2.is_finite() {
            format!("{:.3}", s2.sqrt())
        } else {
            format!("— (σ′² = {s2:.3})")
        }
    };
    for r in &probe_results {
        let (oa, ob, ol) = r.offset_fit;
        emit!(
            rep,
            "| {} | {} | {:.3} | {:.3} | {:.2} | {} | {oa:.3} | {ob:+.3} | {ol:.3} | {:.2} | {} |",
            r.n,
            r.probes[0],
            r.seed_a,
            r.seed_l,
            2.0 / (r.seed_l * r.seed_l),
            nugget(r.seed_sigma2),
            2.0 / (ol * ol),
            nugget((1.0 - oa - ob) / oa)
        );
    }
    emit!(rep);
    emit!(
        rep,
        "The fit is constrained to a ≥ 0. Standardising by the probe's own mean makes the \
         off-diagonal products average −1/(N − 1) (the sum of all products is 0), and real maps \
         are anticorrelated at large d (sky against ground); the plain fit has no term for \
         either, which is why the offset b is shown beside it."
    );
    {
        let ((l, s2), (lam, sig)) = recovery_check(SHOWN_N, 16.0, 0.1, 128);
        emit!(rep);
        emit!(
            rep,
            "Recovery check: 128 draws from the GP prior itself at N = {SHOWN_N} with λ = 16 \
             (l = {:.3}), σ′ = 0.1: the seed's method gives l = {l:.3} (λ = {:.2}), σ′ = {}; \
             the REML arg-max on the grid below is λ = {lam}, σ′ = {sig}.",
            (2.0f64 / 16.0).sqrt(),
            2.0 / (l * l),
            nugget(s2)
        );
    }
    if let Some((cov, a, l)) = &shown_cov {
        emit!(rep);
        emit!(rep, "Binned empirical covariance at N = {SHOWN_N} (c(0) = {:.4}, fit a = {a:.4}, l = {l:.4}):", cov.c0());
        emit!(rep);
        emit!(rep, "| bin of d² | pairs | mean d² | c(d²) | fit a·exp(−d²/l²) |");
        emit!(rep, "| --- | ---: | ---: | ---: | ---: |");
        for b in 0..BINS {
            let lo = 4.0 * b as f64 / BINS as f64;
            let hi = 4.0 * (b + 1) as f64 / BINS as f64;
            if cov.pairs[b] == 0 {
                emit!(rep, "| [{lo:.1}, {hi:.1}) | 0 | | | |");
                continue;
            }
            let c = cov.pairs[b] as f64;
            let md = cov.sum_d2[b] / c;
            emit!(
                rep,
                "| [{lo:.1}, {hi:.1}) | {} | {md:.3} | {:+.4} | {:+.4} |",
                cov.pairs[b],
                cov.sum[b] / c,
                a * (-md / (l * l)).exp()
            );
        }
    }

    emit!(rep);
    emit!(rep, "## Probe form, maximum marginal likelihood (REML, σ_f profiled out)");
    emit!(rep);
    emit!(
        rep,
        "ℓ = −½·log det Q − ½·log(1ᵀQ⁻¹1) − ((N−1)/2)·log(rᵀQ⁻¹r), r = Y − β1, \
         β = 1ᵀQ⁻¹Y / 1ᵀQ⁻¹1, summed over the training probes (constants dropped)."
    );
    emit!(rep);
    emit!(
        rep,
        "Full (λ, σ′) grid arg-max per tier and over both tiers' probes (diagnostic; probes \
         per tier: {}):",
        probe_results
            .iter()
            .map(|r| format!("N = {}: {}/{}", r.n, r.probes[0], r.probes[1]))
            .collect::<Vec<_>>()
            .join(", ")
    );
    emit!(rep);
    emit!(rep, "| N | clamp λ* | clamp σ′* | smooth λ* | smooth σ′* | both λ* | both l* = √(2/λ*) | both σ′* |");
    emit!(rep, "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for r in &probe_results {
        let [(cl, cs), (sl, ss), (bl, bs)] = r.ml;
        emit!(
            rep,
            "| {} | {cl} | {cs} | {sl} | {ss} | {bl} | {:.3} | {bs} |",
            r.n,
            (2.0 / bl).sqrt()
        );
    }
    if let Some(total) = &shown_ll {
        emit!(rep);
        emit!(rep, "Summed ℓ at N = {SHOWN_N}, both tiers (rows λ, columns σ′):");
        emit!(rep);
        let head: Vec<String> = SIGMAS.iter().map(|s| format!("σ′ = {s}")).collect();
        emit!(rep, "| λ | {} |", head.join(" | "));
        emit!(rep, "| ---: |{}", " ---: |".repeat(SIGMAS.len()));
        for (li, row) in total[2].iter().enumerate() {
            let cells: Vec<String> = row.iter().map(|v| format!("{v:.1}")).collect();
            emit!(rep, "| {} | {} |", LAMBDAS[li], cells.join(" | "));
        }
    }
    let ladder = LADDER.map(|l| l.to_string()).join(", ");
    let head: Vec<String> = SIGMAS.iter().map(|s| format!("σ′ = {s}")).collect();
    for (t, tier) in TIERS.iter().enumerate() {
        emit!(rep);
        emit!(
            rep,
            "Ladder λ ∈ {{{ladder}}} with per-probe selection, `{tier}` tier only: summed \
             best-member ℓ per σ′, the tier's own ML σ′, and how often each member wins at the \
             written (combined) σ′:"
        );
        emit!(rep);
        emit!(
            rep,
            "| N | {} | {tier} ML σ′ | wins λ = {} at written σ′ |",
            head.join(" | "),
            LADDER.map(|l| l.to_string()).join("/")
        );
        emit!(rep, "| ---: |{} ---: | ---: |", " ---: |".repeat(SIGMAS.len()));
        for r in &probe_results {
            let cells: Vec<String> = r.ladder_ll[t].iter().map(|v| format!("{v:.1}")).collect();
            let wins: Vec<String> = r.ladder_counts[t].iter().map(|c| c.to_string()).collect();
            emit!(
                rep,
                "| {} | {} | {} | {} |",
                r.n,
                cells.join(" | "),
                SIGMAS[argmax(&r.ladder_ll[t])],
                wins.join("/")
            );
        }
    }
    emit!(rep);
    emit!(
        rep,
        "**Combined objective (written to `tables/probe.txt`)**: the ladder's summed \
         best-member ℓ over the probes of both tiers (the sum of the two tables above) and its \
         ML σ′, beside each tier's own optimum:"
    );
    emit!(rep);
    emit!(rep, "| N | {} | clamp ML σ′ | smooth ML σ′ | **combined ML σ′** |", head.join(" | "));
    emit!(rep, "| ---: |{} ---: | ---: | ---: |", " ---: |".repeat(SIGMAS.len()));
    for r in &probe_results {
        let cells: Vec<String> = r.ladder_ll[2].iter().map(|v| format!("{v:.1}")).collect();
        emit!(
            rep,
            "| {} | {} | {} | {} | **{}** |",
            r.n,
            cells.join(" | "),
            SIGMAS[argmax(&r.ladder_ll[0])],
            SIGMAS[argmax(&r.ladder_ll[1])],
            r.ladder_sigma
        );
    }
    for r in &probe_results {
        if r.ladder_sigma == 1.0 {
            let falls = r.beyond_ll[0] < r.ladder_ll[2][SIGMAS.len() - 1];
            emit!(
                rep,
                "\nWARNING: at N = {} the combined ML σ′ of the ladder is 1.0, the largest grid \
                 value (a nugget as large as the signal); {}.",
                r.n,
                if falls {
                    "ℓ falls again beyond it (σ′ = 1.5 below), so 1.0 is the optimum, not a \
                     grid-edge artefact"
                } else {
                    "ℓ still rises beyond it (σ′ = 1.5 below): the optimum lies outside the grid"
                }
            );
        }
    }

    emit!(rep);
    emit!(
        rep,
        "Diagnostic only (not written): the ladder's summed best-member ℓ beyond the grid, to \
         show where its σ′ optimum lies (combined objective, both tiers):"
    );
    emit!(rep);
    let head: Vec<String> = BEYOND_SIGMAS.iter().map(|s| format!("σ′ = {s}")).collect();
    emit!(rep, "| N | σ′ = 1 | {} |", head.join(" | "));
    emit!(rep, "| ---: | ---: |{}", " ---: |".repeat(BEYOND_SIGMAS.len()));
    for r in &probe_results {
        let cells: Vec<String> = r.beyond_ll.iter().map(|v| format!("{v:.1}")).collect();
        emit!(rep, "| {} | {:.1} | {} |", r.n, r.ladder_ll[2][SIGMAS.len() - 1], cells.join(" | "));
    }

    // ---- Renderer form on synthetic fields ----
    let t = Instant::now();
    // The benchmark's `synthetic` tier generator, with this tool's own seed.
    let fields: Vec<Mixture> = tiers::mixtures(DRAWS, SYNTH_SEED);
    let truth: Vec<f64> = fields.iter().map(|f| f.irradiance([0.0, 0.0, 1.0])).collect();
    let mut render_results = Vec::new();
    for &n in &NS {
        let points: Vec<[f64; 3]> = (0..n as u64).map(|j| hemisphere_point(j, n as u64)).collect();
        let ys: Vec<Vec<f64>> =
            fields.iter().map(|f| points.iter().map(|&p| f.value(p)).collect()).collect();
        let mut ll = vec![[f64::NEG_INFINITY; RENDER_SIGMAS.len()]; LENGTHS.len()];
        let mut rms = vec![[f64::NAN; RENDER_SIGMAS.len()]; LENGTHS.len()];
        for (li, &l) in LENGTHS.iter().enumerate() {
            for (si, &sigma) in RENDER_SIGMAS.iter().enumerate() {
                if let Some(gp) = Gp::new(&points, 2.0 / (l * l), sigma) {
                    ll[li][si] = ys.iter().map(|y| gp.reml(y)).sum();
                }
                let w = reference::bmc::weights(n, l, sigma).w;
                let est: Vec<f64> = ys
                    .iter()
                    .map(|y| PI * w.iter().zip(y).map(|(w, y)| w * y).sum::<f64>())
                    .collect();
                rms[li][si] = rel_rms(&est, &truth);
            }
        }
        let flat: Vec<f64> = ll.iter().flatten().copied().collect();
        let best = argmax(&flat);
        let ml = (best / RENDER_SIGMAS.len(), best % RENDER_SIGMAS.len());
        let qmc_rms = rel_rms(&qmc_sf(n, &fields), &truth);
        println!("(renderer form, N = {n}: {:.2} s so far)", t.elapsed().as_secs_f64());
        render_results.push(RenderResult { n, ll, rms, ml, qmc_rms });
    }

    emit!(rep);
    emit!(rep, "## Renderer form (irradiance, hemisphere SF set), ML on synthetic fields");
    emit!(rep);
    emit!(
        rep,
        "Fields: a constant uniform in [0, 0.5] plus 1–4 spherical Gaussians a·exp(λ_g(μ·x − 1)), \
         μ uniform on the sphere, λ_g uniform in [2, 20], a uniform in [0.2, 1]. Grid \
         l ∈ {{{}}} × σ′ ∈ {{{}}}. Errors are RMSE / mean |E| over the {DRAWS} training fields, \
         against exact irradiance (I₀ₑ quadrature of each lobe, π·c for the constant); BMC is \
         E ≈ π·Σ wᵢYᵢ with `reference::bmc::weights`, QMC-SF is \
         `sphere_quadrature::qmc::irradiance` (cosine-morphed hemisphere SF, phase 0).",
        LENGTHS.map(|l| l.to_string()).join(", "),
        RENDER_SIGMAS.map(|s| s.to_string()).join(", ")
    );
    emit!(rep);
    emit!(rep, "| N | ML l | ML σ′ | BMC rel RMS (ML) | QMC-SF rel RMS | BMC/QMC | best-RMS grid (l, σ′) | its BMC rel RMS |");
    emit!(rep, "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for r in &render_results {
        let (li, si) = r.ml;
        let flat: Vec<f64> = r.rms.iter().flatten().map(|v| -v).collect();
        let b = argmax(&flat);
        let (bl, bs) = (b / RENDER_SIGMAS.len(), b % RENDER_SIGMAS.len());
        emit!(
            rep,
            "| {} | {} | {} | {:.3e} | {:.3e} | {:.3} | ({}, {}) | {:.3e} |",
            r.n,
            LENGTHS[li],
            RENDER_SIGMAS[si],
            r.rms[li][si],
            r.qmc_rms,
            r.rms[li][si] / r.qmc_rms,
            LENGTHS[bl],
            RENDER_SIGMAS[bs],
            r.rms[bl][bs]
        );
    }
    if let Some(r) = render_results.iter().find(|r| r.n == SHOWN_N) {
        let (li, si) = r.ml;
        let ratio = r.rms[li][si] / r.qmc_rms;
        emit!(rep);
        emit!(
            rep,
            "Target checked elsewhere: BMC ≤ 0.1 × QMC-SF at N = {SHOWN_N}. On the training fields \
             the ML optimum gives BMC/QMC = {ratio:.3} ({}).",
            if ratio <= 0.1 { "met" } else { "NOT met" }
        );
    }
    for r in &render_results {
        emit!(rep);
        emit!(
            rep,
            "N = {}: summed ℓ / BMC rel RMS (rows l, columns σ′; ML optimum marked *):",
            r.n
        );
        emit!(rep);
        let head: Vec<String> = RENDER_SIGMAS.iter().map(|s| format!("σ′ = {s}")).collect();
        emit!(rep, "| l | {} |", head.join(" | "));
        emit!(rep, "| ---: |{}", " ---: |".repeat(RENDER_SIGMAS.len()));
        for (li, &l) in LENGTHS.iter().enumerate() {
            let cells: Vec<String> = (0..RENDER_SIGMAS.len())
                .map(|si| {
                    let mark = if (li, si) == r.ml { "*" } else { "" };
                    format!("{mark}{:.1} / {:.2e}", r.ll[li][si], r.rms[li][si])
                })
                .collect();
            emit!(rep, "| {l} | {} |", cells.join(" | "));
        }
    }

    emit!(rep);
    emit!(rep, "## What the tables get (with `--write`)");
    emit!(rep);
    emit!(
        rep,
        "| N | `tables/probe.txt`: σ′ of the ladder {{{}}} (both tiers) | `tables/bmc_smooth.txt`: l | σ′ |",
        LADDER.map(|l| l.to_string()).join(", ")
    );
    emit!(rep, "| ---: | ---: | ---: | ---: |");
    for (p, r) in probe_results.iter().zip(&render_results) {
        emit!(
            rep,
            "| {} | {} | {} | {} |",
            p.n,
            p.ladder_sigma,
            LENGTHS[r.ml.0],
            RENDER_SIGMAS[r.ml.1]
        );
    }
    let secs = start.elapsed().as_secs_f64();
    emit!(rep);
    emit!(rep, "## Rerun");
    emit!(rep);
    emit!(rep, "```text");
    emit!(rep, "cargo writer learn_hyperparameters             # report only");
    emit!(rep, "cargo writer learn_hyperparameters -- --write  # and write tables/probe.txt, tables/bmc_smooth.txt, this file");
    emit!(rep, "```");
    emit!(rep);
    emit!(rep, "The default run took {secs:.0} s (release, one thread).");

    if let Some(dir) = &args.out {
        let path = dir.join("hyperparameters.md");
        if let Err(e) = std::fs::create_dir_all(dir).and_then(|()| std::fs::write(&path, &rep)) {
            eprintln!("cannot write {}: {e}", path.display());
            std::process::exit(1);
        }
        println!("wrote {}", path.display());
    }
    if write {
        let mut probe_txt = probe_table(&probe_results, &names);
        // The footprint probes of issue #11 (learned by eval/src/bin/footprint.rs) share the file:
        // keep their block as it is.
        if let Ok(old) = std::fs::read_to_string(root.join("tables/probe.txt")) {
            if let Some(at) = old.find("\n#\n# Footprint probes") {
                probe_txt.push_str(&old[at + 1..]);
            }
        }
        let bmc_txt = bmc_table(&render_results);
        for (rel, text) in [
            ("tables/probe.txt", probe_txt),
            ("tables/bmc_smooth.txt", bmc_txt),
            ("docs/hyperparameters.md", rep.clone()),
        ] {
            let path = root.join(rel);
            if let Err(e) = std::fs::write(&path, text) {
                eprintln!("cannot write {}: {e}", path.display());
                std::process::exit(1);
            }
            println!("wrote {}", path.display());
        }
    }
}

/// `tables/probe.txt`: the ladder with its ML σ′ per N.
fn probe_table(results: &[ProbeResult], names: &[String]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Probe-form Gaussian-process hyperparameters (issue #6), written by");
    let _ = writeln!(s, "# `cargo xtask regen hyperparameters`; do not edit by hand.");
    let _ = writeln!(s, "# `probe = N sigma lambda1 lambda2 ...`, one line per N, N strictly increasing; `#` starts");
    let _ = writeln!(s, "# a comment. N: spherical Fibonacci sphere samples. sigma: σ′ = σ_n/σ_f shared by the family.");
    let _ = writeln!(
        s,
        "# lambda…: the family of kernel sharpnesses λ = 2/l² (ascending), chosen per probe by"
    );
    let _ = writeln!(s, "# maximum likelihood.");
    let _ = writeln!(s, "#");
    let _ = writeln!(
        s,
        "# Learned by REML maximum likelihood on the `{}` tiers of {} × {ROTATIONS} rotated probes",
        TIERS.join("` and `"),
        names.join(", ")
    );
    let _ = writeln!(
        s,
        "# (the same rotations in both tiers); σ′ maximises the summed per-probe best-member ℓ over"
    );
    let _ = writeln!(
        s,
        "# the probes of BOTH tiers, σ′ ∈ {{{}}}: a probe does not know which tier it is in,",
        SIGMAS.map(|v| v.to_string()).join(", ")
    );
    let _ =
        writeln!(s, "# and clamp-only training (σ′ = 1 for N ≥ 32) over-smoothed smooth lighting.");
    let _ = writeln!(s, "# Learned figures (see docs/hyperparameters.md):");
    let _ = writeln!(
        s,
        "#   seed l, λ: seed's method on clamp; ML λ*, σ′*: full grid, both tiers; ladder σ′: per tier and combined."
    );
    let _ =
        writeln!(s, "#   N    seed l  seed λ   ML λ*  ML σ′*  ladder σ′ clamp  smooth  combined");
    for r in results {
        let _ = writeln!(
            s,
            "#   {:<4} {:<7.3} {:<8.2} {:<6} {:<7} {:<15} {:<7} {}",
            r.n,
            r.seed_l,
            2.0 / (r.seed_l * r.seed_l),
            r.ml[2].0,
            r.ml[2].1,
            SIGMAS[argmax(&r.ladder_ll[0])],
            SIGMAS[argmax(&r.ladder_ll[1])],
            r.ladder_sigma
        );
    }
    for r in results {
        let _ = writeln!(
            s,
            "probe = {} {} {}",
            r.n,
            r.ladder_sigma,
            LADDER.map(|l| l.to_string()).join(" ")
        );
    }
    s
}

/// `tables/bmc_smooth.txt`: the renderer-form ML (l, σ′) per N on synthetic fields.
fn bmc_table(results: &[RenderResult]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Bayesian Monte Carlo weights for SMOOTH light (issue #6): the diffuse renderer's preset for"
    );
    let _ = writeln!(
        s,
        "# lighting as smooth as its training fields. Not read by default: build.rs bakes tables/bmc.txt"
    );
    let _ = writeln!(
        s,
        "# (learned on real maps); point SPHERE_QUADRATURE_BMC_TABLE at this file to bake these instead."
    );
    let _ = writeln!(
        s,
        "# `set = N l sigma`, one per line, N strictly increasing; `#` starts a comment."
    );
    let _ = writeln!(s, "#");
    let _ = writeln!(s, "# N: hemisphere spherical Fibonacci samples about the normal. l: length scale of the kernel");
    let _ = writeln!(
        s,
        "# exp(−|x − x′|²/l²) (sharpness λ = 2/l²). sigma: σ′ = σ_n/σ_f, the noise (nugget) ratio."
    );
    let _ = writeln!(s, "#");
    let _ = writeln!(s, "# LEARNED by `cargo xtask regen hyperparameters`: REML maximum");
    let _ = writeln!(
        s,
        "# likelihood over l ∈ {{{}}} × σ′ ∈ {{{}}} on {DRAWS} synthetic",
        LENGTHS.map(|v| v.to_string()).join(", "),
        RENDER_SIGMAS.map(|v| v.to_string()).join(", ")
    );
    let _ = writeln!(s, "# fields (constant + 1–4 spherical Gaussians, λ_g ∈ [2, 20]; seed {SYNTH_SEED:#x}). Training");
    let _ = writeln!(s, "# relative RMS of irradiance (see docs/hyperparameters.md):");
    let _ = writeln!(s, "#   N    BMC (ML)   QMC-SF");
    for r in results {
        let (li, si) = r.ml;
        let _ = writeln!(s, "#   {:<4} {:<10.3e} {:.3e}", r.n, r.rms[li][si], r.qmc_rms);
    }
    for r in results {
        let (li, si) = r.ml;
        let _ = writeln!(s, "set = {} {} {}", r.n, LENGTHS[li], RENDER_SIGMAS[si]);
    }
    s
}
