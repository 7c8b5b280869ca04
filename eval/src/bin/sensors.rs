//! Probes over sensor layouts: the hardware's own directions, angular responses and noise.
//!
//! ```text
//! cargo eval sensors -- [MAPS…] [--csv FILE] [--out DIR] [--quick] [--explore]
//! ```
//!
//! Prototype stage: f64 Gaussian-process estimators (variants of the prior mean and the
//! hyperparameter policy) against the standard estimators on the same readings.

#![allow(clippy::needless_range_loop)]

use sphere_quadrature_eval::sensors::{
    cosine_factors, crate_fit, gains, layouts, spectrum, spectrum_f32, Geometry, Layout, L, NOISES,
    SEED, TIERS, UP,
};
use sphere_quadrature_eval::{cli, compare, parallel, renderer_engine, tiers};

use std::error::Error;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Parser;
use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use reference::sh::{legendre, real_sh};
use reference::vec::{dot, mat_mul_vec};
use renderer_engine::Cholesky;
use sphere_quadrature::layout::{Mean as CrateMean, Prior, Sensor};
use sphere_quadrature::Vec3;

/// Legendre coefficients of `exp(λ(t − 1))`: `K_l = 4π e^{−λ} i_l(λ)`.
fn kernel_coefficients(lambda: f64) -> Vec<f64> {
    let top = L + 80;
    let mut r = vec![0.0; top + 2];
    for l in (1..=top).rev() {
        r[l] = 1.0 / ((2 * l + 1) as f64 / lambda + r[l + 1]);
    }
    let mut k = vec![0.0; L + 1];
    let mut v = 4.0 * PI * (1.0 - (-2.0 * lambda).exp()) / (2.0 * lambda);
    for l in 0..=L {
        if l > 0 {
            v *= r[l];
        }
        k[l] = v;
    }
    k
}

fn series(coef: &[f64], t: f64) -> f64 {
    // Σ coef_l (2l+1)/(4π) P_l(t) by the three-term recurrence.
    let t = t.clamp(-1.0, 1.0);
    let (mut p0, mut p1) = (1.0, t);
    let mut s = coef[0] / (4.0 * PI);
    if coef.len() > 1 {
        s += coef[1] * 3.0 / (4.0 * PI) * t;
    }
    for l in 2..coef.len() {
        let p2 = ((2 * l - 1) as f64 * t * p1 - (l - 1) as f64 * p0) / l as f64;
        s += coef[l] * (2 * l + 1) as f64 / (4.0 * PI) * p2;
        p0 = p1;
        p1 = p2;
    }
    s
}

/// Solves a small dense system by Gaussian elimination with partial pivoting.
fn dense_solve(mut a: Vec<f64>, n: usize, mut b: Vec<f64>) -> Option<Vec<f64>> {
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))?;
        if a[p * n + c].abs() < 1e-300 {
            return None;
        }
        if p != c {
            for k in 0..n {
                a.swap(p * n + k, c * n + k);
            }
            b.swap(p, c);
        }
        for i in c + 1..n {
            let f = a[i * n + c] / a[c * n + c];
            for k in c..n {
                a[i * n + k] -= f * a[c * n + k];
            }
            b[i] -= f * b[c];
        }
    }
    for i in (0..n).rev() {
        for k in i + 1..n {
            b[i] -= a[i * n + k] * b[k];
        }
        b[i] /= a[i * n + i];
    }
    Some(b)
}

/// The prior mean's basis.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mean {
    Zero,
    Constant,
    /// Constant and the vertical trend `z`.
    Trend,
    /// A multiple of the training maps' zonal profile.
    Profile,
    /// Constant and the profile.
    ConstantProfile,
}

const MEANS: [Mean; 5] =
    [Mean::Zero, Mean::Constant, Mean::Trend, Mean::Profile, Mean::ConstantProfile];
const CRATE_VARIANTS: [&str; 3] =
    ["crate-Zero-spec", "crate-Constant-4", "crate-Profile-spec-resid"];
const FAMILY: [f64; 6] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0];
const KERNEL_NAMES: [&str; 9] =
    ["0.5", "1", "2", "4", "8", "16", "spec", "spec-nolevel", "spec-resid"];

/// Mean basis functions: at sensor `i` (filtered) and at a query normal (irradiance).
fn basis_sensor(mean: Mean, geo: &Geometry, i: usize, profile: &[f64]) -> Vec<f64> {
    let d = geo.dirs[i];
    let g = &geo.g[i];
    let prof = || (0..profile.len()).map(|l| profile[l] * g[l] * legendre(l, d[2])).sum::<f64>();
    match mean {
        Mean::Zero => vec![],
        Mean::Constant => vec![1.0],
        Mean::Trend => vec![1.0, g[1] * d[2]],
        Mean::Profile => vec![prof()],
        Mean::ConstantProfile => vec![1.0, prof()],
    }
}

fn basis_query(mean: Mean, geo: &Geometry, n: [f64; 3], profile: &[f64]) -> Vec<f64> {
    let c = &geo.c;
    let prof = || (0..profile.len()).map(|l| profile[l] * c[l] * legendre(l, n[2])).sum::<f64>();
    match mean {
        Mean::Zero => vec![],
        Mean::Constant => vec![c[0]],
        Mean::Trend => vec![c[0], c[1] * n[2]],
        Mean::Profile => vec![prof()],
        Mean::ConstantProfile => vec![c[0], prof()],
    }
}

/// GP fit of one update: returns estimates and variances at the normals.
struct Fit {
    value: Vec<f64>,
    variance: Vec<f64>,
    log_lik: f64,
}

#[allow(clippy::too_many_arguments)]
fn gp_fit(
    geo: &Geometry,
    c: &[f64],
    zs: &[Vec<f64>],
    vbar: f64,
    mean: Mean,
    profile: &[f64],
    y: &[f64],
    noise_rel: f64,
    normals: &[[f64; 3]],
) -> Option<Fit> {
    let k = y.len();
    let h: Vec<Vec<f64>> = (0..k).map(|i| basis_sensor(mean, geo, i, profile)).collect();
    let p = h[0].len();
    // Noise variance relative: (η y_i)², plus a tiny jitter.
    let jitter = 1e-9 * c[0].max(1e-300);
    let nz: Vec<f64> = y.iter().map(|v| (noise_rel * v).powi(2)).collect();
    // REML over σ_f² on a log grid then golden refinement.
    let reml = |s2: f64| -> Option<(f64, Cholesky, Vec<f64>)> {
        let mut a = c.iter().map(|v| v * s2).collect::<Vec<_>>();
        for i in 0..k {
            a[i * k + i] += nz[i] + jitter * s2;
        }
        let ch = Cholesky::new(a.clone(), k)?;
        let (beta, r, ldh) = gls(&ch, &h, y, p)?;
        let alpha = ch.solve(&r);
        let quad: f64 = r.iter().zip(&alpha).map(|(a, b)| a * b).sum();
        let ll = -0.5 * ch.log_det() - 0.5 * ldh - 0.5 * quad;
        let _ = beta;
        Some((ll, ch, alpha))
    };
    let s2 = if noise_rel == 0.0 {
        // Closed form: σ_f² = rᵀC⁻¹r/(K − p).
        let mut a = c.to_vec();
        for i in 0..k {
            a[i * k + i] += jitter;
        }
        let ch = Cholesky::new(a.clone(), k)?;
        let (_, r, _) = gls(&ch, &h, y, p)?;
        let alpha = ch.solve(&r);
        let quad: f64 = r.iter().zip(&alpha).map(|(a, b)| a * b).sum();
        (quad / (k - p) as f64).max(1e-300)
    } else {
        let scale = y.iter().map(|v| v * v).sum::<f64>() / k as f64;
        let (mut lo, mut hi) = ((scale * 1e-8).ln(), (scale * 1e4).ln());
        let f = |x: f64| reml(x.exp()).map_or(f64::NEG_INFINITY, |r| r.0);
        let gr = 0.618_033_988_749_895;
        let (mut a, mut b) = (hi - gr * (hi - lo), lo + gr * (hi - lo));
        let (mut fa, mut fb) = (f(a), f(b));
        for _ in 0..60 {
            if fa > fb {
                hi = b;
                b = a;
                fb = fa;
                a = hi - gr * (hi - lo);
                fa = f(a);
            } else {
                lo = a;
                a = b;
                fa = fb;
                b = lo + gr * (hi - lo);
                fb = f(b);
            }
        }
        (0.5 * (lo + hi)).exp()
    };
    let (ll, ch, alpha) = reml(s2)?;
    let (beta, _, _) = gls(&ch, &h, y, p)?;
    // HᵀΣ⁻¹H for the variance.
    let sih: Vec<Vec<f64>> =
        (0..p).map(|a| ch.solve(&(0..k).map(|i| h[i][a]).collect::<Vec<_>>())).collect();
    let mut hsh = vec![0.0; p * p];
    for a in 0..p {
        for b in 0..p {
            hsh[a * p + b] = (0..k).map(|i| h[i][a] * sih[b][i]).sum();
        }
    }
    let mut value = Vec::with_capacity(normals.len());
    let mut variance = Vec::with_capacity(normals.len());
    for (q, &n) in normals.iter().enumerate() {
        let z: Vec<f64> = zs[q].iter().map(|v| s2 * v).collect();
        let hq = basis_query(mean, geo, n, profile);
        let m: f64 = (0..p).map(|a| hq[a] * beta[a]).sum();
        let e = m + z.iter().zip(&alpha).map(|(a, b)| a * b).sum::<f64>();
        let siz = ch.solve(&z);
        let mut v = s2 * vbar - z.iter().zip(&siz).map(|(a, b)| a * b).sum::<f64>();
        if p > 0 {
            let rr: Vec<f64> =
                (0..p).map(|a| hq[a] - (0..k).map(|i| h[i][a] * siz[i]).sum::<f64>()).collect();
            if let Some(w) = dense_solve(hsh.clone(), p, rr.clone()) {
                v += rr.iter().zip(&w).map(|(a, b)| a * b).sum::<f64>();
            }
        }
        value.push(e);
        variance.push(v.max(0.0));
    }
    Some(Fit { value, variance, log_lik: ll })
}

/// GLS: β, residual r = y − Hβ, log det HᵀΣ⁻¹H.
fn gls(ch: &Cholesky, h: &[Vec<f64>], y: &[f64], p: usize) -> Option<(Vec<f64>, Vec<f64>, f64)> {
    let k = y.len();
    if p == 0 {
        return Some((vec![], y.to_vec(), 0.0));
    }
    let sih: Vec<Vec<f64>> =
        (0..p).map(|a| ch.solve(&(0..k).map(|i| h[i][a]).collect::<Vec<_>>())).collect();
    let mut m = vec![0.0; p * p];
    let mut rhs = vec![0.0; p];
    for a in 0..p {
        for b in 0..p {
            m[a * p + b] = (0..k).map(|i| h[i][b] * sih[a][i]).sum();
        }
        rhs[a] = (0..k).map(|i| y[i] * sih[a][i]).sum();
    }
    let ldh = Cholesky::new(m.clone(), p).map_or(0.0, |c| c.log_det());
    let beta = dense_solve(m, p, rhs)?;
    let r: Vec<f64> =
        (0..k).map(|i| y[i] - (0..p).map(|a| h[i][a] * beta[a]).sum::<f64>()).collect();
    Some((beta, r, ldh))
}

/// Standard estimators.
fn sh_fit(
    geo: &Geometry,
    y: &[f64],
    degree: usize,
    min_norm: bool,
    normals: &[[f64; 3]],
) -> Vec<f64> {
    let k = y.len();
    let lm: Vec<(usize, i64)> =
        (0..=degree).flat_map(|l| (-(l as i64)..=l as i64).map(move |m| (l, m))).collect();
    let q = lm.len();
    let a: Vec<Vec<f64>> = (0..k)
        .map(|i| lm.iter().map(|&(l, m)| geo.g[i][l] * real_sh(l, m, geo.dirs[i])).collect())
        .collect();
    let coef: Vec<f64> = if min_norm {
        // c = Aᵀ(AAᵀ + εI)⁻¹y.
        let mut aat = vec![0.0; k * k];
        for i in 0..k {
            for j in 0..k {
                aat[i * k + j] = (0..q).map(|c| a[i][c] * a[j][c]).sum();
            }
        }
        let tr: f64 = (0..k).map(|i| aat[i * k + i]).sum::<f64>() / k as f64;
        for i in 0..k {
            aat[i * k + i] += 1e-10 * tr;
        }
        let w = dense_solve(aat, k, y.to_vec()).unwrap_or_else(|| vec![0.0; k]);
        (0..q).map(|c| (0..k).map(|i| a[i][c] * w[i]).sum()).collect()
    } else {
        let mut ata = vec![0.0; q * q];
        let mut aty = vec![0.0; q];
        for c1 in 0..q {
            for c2 in 0..q {
                ata[c1 * q + c2] = (0..k).map(|i| a[i][c1] * a[i][c2]).sum();
            }
            aty[c1] = (0..k).map(|i| a[i][c1] * y[i]).sum();
        }
        dense_solve(ata, q, aty).unwrap_or_else(|| vec![0.0; q])
    };
    normals
        .iter()
        .map(|&n| lm.iter().zip(&coef).map(|(&(l, m), c)| c * geo.c[l] * real_sh(l, m, n)).sum())
        .collect()
}

/// The prior the crate recommends for this layout and tier (from its directions).
fn recommended(tier: usize, lay: &Layout) -> Prior {
    let sensors: Vec<Sensor> = lay
        .dirs
        .iter()
        .map(|d| Sensor::cosine(Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)))
        .collect();
    if tier == 0 {
        Prior::for_layout(&sensors)
    } else {
        Prior::smooth_for_layout(&sensors)
    }
}

/// The alternatives to the recommended prior (of the tier's kind of light): name and prior.
const ALTERNATIVES: [&str; 4] = ["ENVIRONMENT", "constant mean", "SKY_ABOVE", "ONE_SIDED"];

fn alternatives(tier: usize) -> [Prior; 4] {
    if tier == 0 {
        [
            Prior::ENVIRONMENT,
            Prior::ENVIRONMENT.with_mean(CrateMean::Constant),
            Prior::SKY_ABOVE,
            Prior::ONE_SIDED,
        ]
    } else {
        [
            Prior::SMOOTH_ENVIRONMENT,
            Prior::SMOOTH_ENVIRONMENT.with_mean(CrateMean::Constant),
            Prior::SMOOTH_SKY_ABOVE,
            Prior::SMOOTH_ONE_SIDED,
        ]
    }
}

fn nearest(geo: &Geometry, y: &[f64], normals: &[[f64; 3]]) -> Vec<f64> {
    normals
        .iter()
        .map(|&n| {
            let i = (0..y.len())
                .max_by(|&a, &b| dot(geo.dirs[a], n).total_cmp(&dot(geo.dirs[b], n)))
                .unwrap_or(0);
            PI * y[i]
        })
        .collect()
}

fn cos_avg(geo: &Geometry, y: &[f64], normals: &[[f64; 3]]) -> Vec<f64> {
    normals
        .iter()
        .map(|&n| {
            let (mut s, mut w) = (0.0, 0.0);
            for i in 0..y.len() {
                let c = dot(geo.dirs[i], n).max(0.0);
                s += c * y[i];
                w += c;
            }
            if w > 0.0 {
                PI * s / w
            } else {
                nearest(geo, y, &[n])[0]
            }
        })
        .collect()
}

#[derive(Parser)]
#[command(
    bin_name = "cargo eval sensors --",
    about = "Probes over sensor layouts against the standard estimators"
)]
struct Args {
    #[command(flatten)]
    maps: cli::TrainingMaps,
    /// Also write rows sensors,<layout>,<noise>,<tier>,<estimator>,<map>,<rel_rmse>,<coverage2s>
    /// (coverage: the share of queries within 2σ, σ² the variance that `irradiance` returns)
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Write DIR/sensors.md (`--out docs` regenerates the repository's docs)
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    #[arg(long)]
    quick: bool,
    /// Rotations per map
    #[arg(long, default_value_t = 16)]
    rotations: usize,
    /// Query normals per layout (twice as many over the sphere for `wall6`, each scored where
    /// the wall faces)
    #[arg(long, default_value_t = 48)]
    normals: usize,
    #[command(flatten)]
    threads: cli::Threads,
    /// Only these layouts (comma-separated)
    #[arg(long, value_delimiter = ',')]
    layouts: Vec<String>,
    /// Also the f64 design variants (prior means, kernels, hyperparameter policies)
    #[arg(long)]
    explore: bool,
    /// Degree of the learned zonal profile
    #[arg(long, default_value_t = 8)]
    profile_degree: usize,
}

/// Zonal Legendre coefficients `a_l` (l ≤ 8) of a map's luminance over its mean.
fn zonal_profile(map: &EnvMap) -> Vec<f64> {
    let mut a = [0.0; 9];
    let mut mean = 0.0;
    for v in 0..map.height {
        let omega = map.pixel_solid_angle(v);
        for u in 0..map.width {
            let lum = luminance(map.pixel(u, v));
            let z = map.pixel_direction(u, v)[2];
            mean += lum * omega / (4.0 * PI);
            for l in 0..9 {
                a[l] += lum * omega * legendre(l, z) * (2 * l + 1) as f64 / (4.0 * PI);
            }
        }
    }
    a.iter().map(|x| x / mean).collect()
}

struct Scene {
    name: String,
    training: bool,
    tiers: Vec<EnvMap>,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let threads = args.threads.count();
    let paths = if args.maps.maps.is_empty() {
        cli::named_maps(args.quick)
    } else {
        args.maps.maps.clone()
    };
    let scenes: Vec<Scene> = parallel::parallel_map(&paths, threads, |_, p| {
        let m = EnvMap::load(p).expect("map");
        let clamp = compare::clamped(&m);
        let smooth = tiers::smooth(&clamp);
        let name = cli::map_name(p);
        Scene {
            training: cli::TRAINING_MAPS.contains(&name.as_str()),
            name,
            tiers: vec![clamp, smooth],
        }
    });
    let mut layouts = layouts();
    if !args.layouts.is_empty() {
        layouts.retain(|l| args.layouts.iter().any(|n| n == l.name));
    }
    let c = cosine_factors();
    // Per tier: the training maps' mean zonal profile.
    let explore_tiers = if args.explore { TIERS.len() } else { 0 };
    let profiles: Vec<Vec<f64>> = (0..explore_tiers)
        .map(|t| {
            let tr: Vec<Vec<f64>> =
                scenes.iter().filter(|s| s.training).map(|s| zonal_profile(&s.tiers[t])).collect();
            (0..=args.profile_degree.min(8))
                .map(|l| tr.iter().map(|p| p[l]).sum::<f64>() / tr.len().max(1) as f64)
                .collect()
        })
        .collect();
    for (t, p) in profiles.iter().enumerate() {
        eprintln!(
            "profile {}: {:?}",
            TIERS[t],
            p.iter().map(|x| format!("{x:.3}")).collect::<Vec<_>>()
        );
    }
    // Per tier: kernels (the SE family, then the training spectra).
    let kernels: Vec<Vec<Vec<f64>>> = (0..explore_tiers)
        .map(|t| {
            let mut ks: Vec<Vec<f64>> = FAMILY.iter().map(|&l| kernel_coefficients(l)).collect();
            let avg = |prof: &[f64]| -> Vec<f64> {
                let sp: Vec<Vec<f64>> = scenes
                    .iter()
                    .filter(|s| s.training)
                    .map(|s| spectrum(&s.tiers[t], prof))
                    .collect();
                (0..=L).map(|l| sp.iter().map(|p| p[l]).sum::<f64>() / sp.len() as f64).collect()
            };
            let full = avg(&[]);
            let mut nolevel = full.clone();
            nolevel[0] = full[1];
            let resid = avg(&profiles[t]);
            eprintln!(
                "spectrum {}: {:?}",
                TIERS[t],
                full.iter().take(9).map(|x| format!("{x:.3}")).collect::<Vec<_>>()
            );
            ks.push(full);
            ks.push(nolevel);
            ks.push(resid);
            ks
        })
        .collect();
    // Per layout: rotations and normals; truth weights per grid.
    let mut rng = Rng::new(SEED);
    struct Setup {
        rotations: Vec<[[f64; 3]; 3]>,
        normals: Vec<[f64; 3]>,
    }
    let setups: Vec<Setup> = layouts
        .iter()
        .map(|lay| {
            let rotations = (0..args.rotations)
                .map(|_| {
                    if lay.look.is_some() {
                        let a = 2.0 * PI * rng.next_f64();
                        let (s, c) = a.sin_cos();
                        [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
                    } else {
                        rng.uniform_rotation()
                    }
                })
                .collect();
            // Looking up: normals above. Another look direction: twice as many normals over
            // the sphere, each scored for the rotations that turn the look towards it.
            let normals = match lay.look {
                UP => (0..args.normals).map(|_| rng.uniform_hemisphere()).collect(),
                Some(_) => (0..2 * args.normals).map(|_| rng.uniform_sphere()).collect(),
                None => (0..args.normals).map(|_| rng.uniform_sphere()).collect(),
            };
            Setup { rotations, normals }
        })
        .collect();
    // Weight jobs: (layout, grid, axis kind).
    let grids: Vec<(usize, usize)> = vec![
        (scenes[0].tiers[0].width, scenes[0].tiers[0].height),
        (scenes[0].tiers[1].width, scenes[0].tiers[1].height),
    ];
    // For each layout and grid: sensor weights per rotation (K each) and normal weights.
    struct W {
        sensors: Vec<Vec<Vec<f64>>>,
        normals: Vec<Vec<f64>>,
    }
    let jobs: Vec<(usize, usize)> =
        (0..layouts.len()).flat_map(|l| (0..2).map(move |g| (l, g))).collect();
    let weights: Vec<W> = parallel::parallel_map(&jobs, threads, |_, &(li, gi)| {
        let lay = &layouts[li];
        let (w, h) = grids[gi];
        let sensors = setups[li]
            .rotations
            .iter()
            .map(|r| {
                lay.dirs
                    .iter()
                    .zip(&lay.power)
                    .map(|(&d, &p)| {
                        let d = mat_mul_vec(*r, d);
                        if p == 1 {
                            reference::truth::cosine_weights(w, h, d)
                                .iter()
                                .map(|x| x / PI)
                                .collect()
                        } else {
                            reference::truth::phong_weights(w, h, d, p as f64)
                        }
                    })
                    .collect()
            })
            .collect();
        let normals =
            setups[li].normals.iter().map(|&n| reference::truth::cosine_weights(w, h, n)).collect();
        W { sensors, normals }
    });
    eprintln!("weights done");
    // Variants.
    let mut variants: Vec<String> = Vec::new();
    for mean in if args.explore { &MEANS[..] } else { &[] } {
        let mean = *mean;
        variants.push(format!("{mean:?}-reml"));
        for name in KERNEL_NAMES {
            variants.push(format!("{mean:?}-{name}"));
        }
    }
    for name in if args.explore { &CRATE_VARIANTS[..] } else { &[] } {
        variants.push(name.to_string());
    }
    // The issue's estimators, then (report only) the per-probe choice among
    // squared-exponential kernels by REML likelihood, with the learned prior's mean.
    let mut peers: Vec<String> = ["nearest", "cos-avg", "sh1-ls", "sh2", "bmc", "bmc-se-reml"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let csv_estimators = 5;
    let first_alternative = peers.len();
    peers.extend(ALTERNATIVES.iter().map(|s| s.to_string()));
    // Evaluate: (layout, noise, tier, map) → per estimator (sum sq err, sum truth, covered, count).
    let count = scenes.len();
    let eval_jobs: Vec<(usize, usize, usize, usize)> = (0..layouts.len())
        .flat_map(|l| {
            (0..NOISES.len())
                .flat_map(move |n| (0..2).flat_map(move |t| (0..count).map(move |m| (l, n, t, m))))
        })
        .collect();
    let results: Vec<Vec<[f64; 5]>> =
        parallel::parallel_map(&eval_jobs, threads, |_, &(li, ni, ti, mi)| {
            let lay = &layouts[li];
            let map = &scenes[mi].tiers[ti];
            let wt = &weights[li * 2 + ti];
            let lum: Vec<f64> = map
                .pixels
                .iter()
                .map(|p| luminance([p[0] as f64, p[1] as f64, p[2] as f64]))
                .collect();
            let truth: Vec<f64> =
                wt.normals.iter().map(|w| w.iter().zip(&lum).map(|(a, b)| a * b).sum()).collect();
            let mut acc = vec![[0.0f64; 5]; peers.len() + variants.len()];
            let mut rng = Rng::new(
                SEED ^ (li as u64) << 40 ^ (ni as u64) << 32 ^ (ti as u64) << 24 ^ mi as u64,
            );
            for (ri, r) in setups[li].rotations.iter().enumerate() {
                let y: Vec<f64> = wt.sensors[ri]
                    .iter()
                    .map(|w| {
                        let v: f64 = w.iter().zip(&lum).map(|(a, b)| a * b).sum();
                        // Box–Muller.
                        let (u1, u2) = (rng.next_f64().max(1e-300), rng.next_f64());
                        let e = (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos();
                        v * (1.0 + NOISES[ni] * e)
                    })
                    .collect();
                let geo = Geometry {
                    g: lay.power.iter().map(|&p| gains(p)).collect(),
                    dirs: lay.dirs.iter().map(|&d| mat_mul_vec(*r, d)).collect(),
                    c: c.clone(),
                };
                let normals = &setups[li].normals;
                // The normals this rotation looks towards.
                let seen: Vec<bool> = match lay.look {
                    Some(l) => normals.iter().map(|&n| dot(n, mat_mul_vec(*r, l)) > 0.0).collect(),
                    None => vec![true; normals.len()],
                };
                // Per estimator: squared errors, |truth|, covered by 2σ of the exact variance,
                // count, covered by 2σ of the averaged variance.
                let mut record = |slot: usize, est: &[f64], var: Option<(&[f64], &[f64])>| {
                    for q in (0..normals.len()).filter(|&q| seen[q]) {
                        let e = est[q] - truth[q];
                        acc[slot][0] += e * e;
                        acc[slot][1] += truth[q].abs();
                        if let Some((exact, averaged)) = var {
                            if e.abs() <= 2.0 * exact[q].sqrt() {
                                acc[slot][2] += 1.0;
                            }
                            if e.abs() <= 2.0 * averaged[q].sqrt() {
                                acc[slot][4] += 1.0;
                            }
                        }
                        acc[slot][3] += 1.0;
                    }
                };
                record(0, &nearest(&geo, &y, normals), None);
                record(1, &cos_avg(&geo, &y, normals), None);
                record(2, &sh_fit(&geo, &y, 1, false, normals), None);
                let k = y.len();
                record(3, &sh_fit(&geo, &y, 2, k < 9, normals), None);
                // The crate's probe with its learned priors: for the tier's kind of light, and
                // for layouts that look up, the sky-above form.
                let chosen = recommended(ti, lay);
                let family: Vec<Prior> = [1.0f32, 2.0, 4.0, 8.0, 16.0, 32.0]
                    .iter()
                    .filter_map(|&l| Prior::squared_exponential(l).ok())
                    .map(|p| p.with_mean(chosen.mean))
                    .collect();
                if let Some(f) = crate_fit(&geo, &lay.power, &family, NOISES[ni], &y, normals) {
                    record(5, &f.values, Some((&f.exact, &f.averaged)));
                }
                if let Some(f) = crate_fit(&geo, &lay.power, &[chosen], NOISES[ni], &y, normals) {
                    record(4, &f.values, Some((&f.exact, &f.averaged)));
                }
                for (j, prior) in alternatives(ti).into_iter().enumerate() {
                    if let Some(f) = crate_fit(&geo, &lay.power, &[prior], NOISES[ni], &y, normals)
                    {
                        record(first_alternative + j, &f.values, Some((&f.exact, &f.averaged)));
                    }
                }
                if !args.explore {
                    continue;
                }
                let prof = &profiles[ti];
                let zonal: [f32; 9] =
                    std::array::from_fn(|l| prof.get(l).copied().unwrap_or(0.0) as f32);
                // Per λ: the rotation-invariant sensor covariance, the query covariances.
                let per_lambda: Vec<(Vec<f64>, Vec<Vec<f64>>, f64)> = kernels[ti]
                    .iter()
                    .map(|kl| {
                        let mut cm = vec![0.0; k * k];
                        for i in 0..k {
                            for j in 0..k {
                                let coef: Vec<f64> =
                                    (0..=L).map(|l| kl[l] * geo.g[i][l] * geo.g[j][l]).collect();
                                cm[i * k + j] = series(&coef, dot(geo.dirs[i], geo.dirs[j]));
                            }
                        }
                        let zs = normals
                            .iter()
                            .map(|&n| {
                                (0..k)
                                    .map(|i| {
                                        let coef: Vec<f64> = (0..=L)
                                            .map(|l| kl[l] * geo.g[i][l] * geo.c[l])
                                            .collect();
                                        series(&coef, dot(geo.dirs[i], n))
                                    })
                                    .collect()
                            })
                            .collect();
                        let vbar = (0..=L)
                            .map(|l| kl[l] * geo.c[l] * geo.c[l] * (2 * l + 1) as f64 / (4.0 * PI))
                            .sum();
                        (cm, zs, vbar)
                    })
                    .collect();
                for (mi_, mean) in MEANS.iter().enumerate() {
                    let fits: Vec<Option<Fit>> = per_lambda
                        .iter()
                        .map(|(cm, zs, vbar)| {
                            gp_fit(&geo, cm, zs, *vbar, *mean, prof, &y, NOISES[ni], normals)
                        })
                        .collect();
                    let base = peers.len() + mi_ * (KERNEL_NAMES.len() + 1);
                    let best = fits[..FAMILY.len()]
                        .iter()
                        .flatten()
                        .max_by(|a, b| a.log_lik.total_cmp(&b.log_lik));
                    if let Some(f) = best {
                        record(base, &f.value, Some((&f.variance, &f.variance)));
                    }
                    for (j, f) in fits.iter().enumerate() {
                        if let Some(f) = f {
                            record(base + 1 + j, &f.value, Some((&f.variance, &f.variance)));
                        }
                    }
                }
                let base = peers.len() + MEANS.len() * (KERNEL_NAMES.len() + 1);
                let priors = [
                    Prior {
                        spectrum: spectrum_f32(&kernels[ti][FAMILY.len()]),
                        zonal: [0.0; 3],
                        mean: CrateMean::Zero,
                        variance_scale: 1.0,
                    },
                    Prior {
                        spectrum: spectrum_f32(&kernels[ti][3]),
                        zonal: [0.0; 3],
                        mean: CrateMean::Constant,
                        variance_scale: 1.0,
                    },
                    Prior {
                        spectrum: spectrum_f32(&kernels[ti][FAMILY.len() + 2]),
                        zonal: [0.0; 3],
                        mean: CrateMean::Zonal(zonal),
                        variance_scale: 1.0,
                    },
                ];
                for (j, prior) in priors.into_iter().enumerate() {
                    if let Some(f) = crate_fit(&geo, &lay.power, &[prior], NOISES[ni], &y, normals)
                    {
                        record(base + j, &f.values, Some((&f.exact, &f.averaged)));
                    }
                }
            }
            acc
        });
    let names: Vec<String> =
        peers.iter().map(|s| s.to_string()).chain(variants.iter().cloned()).collect();
    let rel = |a: &[f64; 5]| (a[0] / a[3]).sqrt() / (a[1] / a[3]);
    // The best of the four standard estimators' errors on one map.
    let best_standard = |r: &[[f64; 5]]| (0..4).map(|s| rel(&r[s])).fold(f64::INFINITY, f64::min);
    // One layout, noise and tier: (map, accumulators) of every map.
    let rows_of = |li: usize, ni: usize, ti: usize| -> Vec<(usize, &Vec<[f64; 5]>)> {
        eval_jobs
            .iter()
            .zip(&results)
            .filter(|((l, n, t, _), _)| *l == li && *n == ni && *t == ti)
            .map(|((_, _, _, m), r)| (*m, r))
            .collect()
    };
    let noise_name = |n: f64| if n == 0.0 { "0".to_string() } else { format!("{n}") };
    let estimator_name = |li: usize, e: usize| -> String {
        if e == 3 {
            if layouts[li].dirs.len() >= 9 {
                "sh2-ls".into()
            } else {
                "sh2-mn".into()
            }
        } else {
            names[e].clone()
        }
    };
    if let Some(csv) = &args.csv {
        let mut text = String::new();
        for (&(li, ni, ti, mi), r) in eval_jobs.iter().zip(&results) {
            for e in 0..csv_estimators {
                let cov = if e == 4 { format!("{:.4}", r[e][4] / r[e][3]) } else { String::new() };
                let _ = writeln!(
                    text,
                    "sensors,{},{},{},{},{},{:.6},{}",
                    layouts[li].name,
                    noise_name(NOISES[ni]),
                    TIERS[ti],
                    estimator_name(li, e),
                    scenes[mi].name,
                    rel(&r[e]),
                    cov
                );
            }
        }
        if let Some(dir) = csv.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(csv, text)?;
    }
    let mut out = String::new();
    // Held-out maps: estimator `e` against `reference(r)` of each map: the mean of per-map
    // ratios, the ratio of mean errors, the worst map, the 2σ coverage of the variance that
    // `irradiance` returns and of the exact one.
    let versus = |held: &[&Vec<[f64; 5]>], e: usize, reference: &dyn Fn(&[[f64; 5]]) -> f64| {
        let n = held.len() as f64;
        let (mut sum_ratio, mut worst, mut sum_e, mut sum_ref, mut averaged, mut exact) =
            (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for r in held {
            let ratio = rel(&r[e]) / reference(r);
            sum_ratio += ratio;
            worst = worst.max(ratio);
            sum_e += rel(&r[e]);
            sum_ref += reference(r);
            averaged += r[e][4] / r[e][3];
            exact += r[e][2] / r[e][3];
        }
        (sum_ratio / n, sum_e / sum_ref, worst, 100.0 * averaged / n, 100.0 * exact / n)
    };
    let held_out = |li: usize, ni: usize, ti: usize| -> Vec<&Vec<[f64; 5]>> {
        rows_of(li, ni, ti)
            .into_iter()
            .filter(|(m, _)| !scenes[*m].training)
            .map(|(_, r)| r)
            .collect()
    };
    let _ = writeln!(out, "| layout | noise | tier | best standard | bmc / best (mean of per-map ratios) | ratio of mean errors | worst map | bmc 2σ coverage | exact variance's 2σ coverage |");
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|");
    for li in 0..layouts.len() {
        for ni in 0..NOISES.len() {
            for ti in 0..2 {
                let rows = rows_of(li, ni, ti);
                let held: Vec<&(usize, &Vec<[f64; 5]>)> =
                    rows.iter().filter(|(m, _)| !scenes[*m].training).collect();
                if held.is_empty() {
                    continue;
                }
                // The best standard estimator per map; the one best most often is named.
                let mut wins = [0usize; 4];
                let (mut sum_ratio, mut worst, mut sum_bmc, mut sum_best, mut cov, mut exact) =
                    (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
                for (_, r) in &held {
                    let (bi, best) = (0..4)
                        .map(|s| (s, rel(&r[s])))
                        .min_by(|a, b| a.1.total_cmp(&b.1))
                        .expect("four estimators");
                    wins[bi] += 1;
                    let ratio = rel(&r[4]) / best;
                    sum_ratio += ratio;
                    worst = worst.max(ratio);
                    sum_bmc += rel(&r[4]);
                    sum_best += best;
                    cov += r[4][4] / r[4][3];
                    exact += r[4][2] / r[4][3];
                }
                let n = held.len() as f64;
                let top = (0..4).max_by_key(|&s| wins[s]).unwrap_or(0);
                let _ = writeln!(
                    out,
                    "| {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.1} % | {:.1} % |",
                    layouts[li].name,
                    noise_name(NOISES[ni]),
                    TIERS[ti],
                    estimator_name(li, top),
                    sum_ratio / n,
                    sum_bmc / sum_best,
                    worst,
                    100.0 * cov / n,
                    100.0 * exact / n
                );
            }
        }
    }
    // Against the degree-2 SH fit alone (minimum norm below 9 sensors).
    let _ = writeln!(
        out,
        "\n## Against the degree-2 SH fit\n\n\
         `bmc` over `sh2` (the degree-2 SH fit: minimum norm below 9 sensors, least squares \
         from 9), held-out maps: the mean of per-map ratios of the errors, the ratio of mean \
         errors, the worst map, and the share of queries within 2σ, σ² the variance that \
         `irradiance` returns (the direction average) and the exact one at each normal \
         (`irradiance_variance`).\n\n\
         | layout | noise | tier | sh2 | bmc / sh2 (mean of per-map ratios) | ratio of mean errors | worst map | 2σ coverage | exact variance's 2σ coverage |\n\
         |---|---|---|---|---|---|---|---|---|"
    );
    let sh2 = |r: &[[f64; 5]]| rel(&r[3]);
    for li in 0..layouts.len() {
        for ni in 0..NOISES.len() {
            for ti in 0..2 {
                let held = held_out(li, ni, ti);
                if held.is_empty() {
                    continue;
                }
                let (mean, of_means, worst, averaged, exact) = versus(&held, 4, &sh2);
                let _ = writeln!(
                    out,
                    "| {} | {} | {} | {} | {mean:.3} | {of_means:.3} | {worst:.3} | {averaged:.1} % | {exact:.1} % |",
                    layouts[li].name,
                    noise_name(NOISES[ni]),
                    TIERS[ti],
                    estimator_name(li, 3),
                );
            }
        }
    }
    // The alternatives, to show why the recommendation is what it is.
    let _ = writeln!(
        out,
        "\n## The recommended prior against the alternatives\n\n\
         Error over the degree-2 SH fit's, mean of per-map ratios (worst map), held-out maps: \
         `bmc` the recommended prior (`Prior::for_layout`, `Prior::smooth_for_layout`), and \
         the crate's other priors for the tier's kind of light: `ENVIRONMENT` \
         (`SMOOTH_ENVIRONMENT`), the same with a constant mean, `SKY_ABOVE` \
         (`SMOOTH_SKY_ABOVE`) and `ONE_SIDED` (`SMOOTH_ONE_SIDED`).\n\n\
         | layout | noise | tier | bmc | {} |\n|---|---|---|---|---|---|---|---|",
        ALTERNATIVES.map(|a| format!("`{a}`")).join(" | ")
    );
    for li in 0..layouts.len() {
        for ni in 0..NOISES.len() {
            for ti in 0..2 {
                let held = held_out(li, ni, ti);
                if held.is_empty() {
                    continue;
                }
                let _ = write!(
                    out,
                    "| {} | {} | {} |",
                    layouts[li].name,
                    noise_name(NOISES[ni]),
                    TIERS[ti]
                );
                for e in std::iter::once(4).chain(first_alternative..first_alternative + 4) {
                    let (mean, _, worst, _, _) = versus(&held, e, &sh2);
                    let _ = write!(out, " {mean:.3} ({worst:.2}) |");
                }
                let _ = writeln!(out);
            }
        }
    }
    // The learned prior against the per-probe choice among squared-exponential kernels.
    let _ = writeln!(
        out,
        "\n## The learned prior against a choice per update\n\n\
         `bmc` (the learned prior, fixed) and `bmc-se-reml` (per update, the squared-exponential \
         kernel of sharpness 1, 2, 4, 8, 16 or 32 with the highest REML likelihood, the same \
         mean): error over the best standard estimator, mean of per-map ratios, held-out maps.\n\n\
         | layout | noise | tier | bmc | bmc-se-reml | bmc coverage | bmc-se-reml coverage |\n\
         |---|---|---|---|---|---|---|"
    );
    for li in 0..layouts.len() {
        for ni in 0..NOISES.len() {
            for ti in 0..2 {
                let held: Vec<&Vec<[f64; 5]>> = rows_of(li, ni, ti)
                    .into_iter()
                    .filter(|(m, _)| !scenes[*m].training)
                    .map(|(_, r)| r)
                    .collect();
                if held.is_empty() {
                    continue;
                }
                let n = held.len() as f64;
                let ratio =
                    |e: usize| held.iter().map(|r| rel(&r[e]) / best_standard(r)).sum::<f64>() / n;
                let coverage = |e: usize| held.iter().map(|r| r[e][4] / r[e][3]).sum::<f64>() / n;
                let _ = writeln!(
                    out,
                    "| {} | {} | {} | {:.3} | {:.3} | {:.1} % | {:.1} % |",
                    layouts[li].name,
                    noise_name(NOISES[ni]),
                    TIERS[ti],
                    ratio(4),
                    ratio(5),
                    100.0 * coverage(4),
                    100.0 * coverage(5)
                );
            }
        }
    }
    if args.explore {
        // Report: per layout × noise × tier, held-out: mean of per-map ratio to best standard.
        for li in 0..layouts.len() {
            for ni in 0..NOISES.len() {
                for ti in 0..2 {
                    let rows = rows_of(li, ni, ti);
                    let mut line =
                        format!("{:10} η={:.2} {:6}", layouts[li].name, NOISES[ni], TIERS[ti]);
                    let _ = &mut line;
                    // Per estimator: held-out mean of ratio to best standard, worst map, train mean, coverage.
                    let mut stats: Vec<(f64, f64, f64, f64, f64)> = Vec::new();
                    for e in 0..names.len() {
                        let (mut held, mut worst, mut train, mut cov, mut nh, mut nt) =
                            (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
                        let mut abs = 0.0f64;
                        for (m, r) in &rows {
                            let best = best_standard(r);
                            let ratio = rel(&r[e]) / best;
                            if scenes[*m].training {
                                train += ratio;
                                nt += 1.0;
                            } else {
                                held += ratio;
                                worst = worst.max(ratio);
                                cov += r[e][2] / r[e][3];
                                abs += rel(&r[e]);
                                nh += 1.0;
                            }
                        }
                        stats.push((held / nh, worst, train / nt.max(1.0), cov / nh, abs / nh));
                    }
                    let _ = writeln!(out, "{line}");
                    for (e, s) in stats.iter().enumerate() {
                        let _ = writeln!(
                            out,
                            "    {:24} held {:.3} worst {:.3} train {:.3} cov {:.3} abs {:.4}",
                            names[e], s.0, s.1, s.2, s.3, s.4
                        );
                    }
                }
            }
        }
    }
    print!("{out}");
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)?;
        let header =
            "# Probes over sensor layouts\n\nGenerated by `cargo eval sensors -- --out docs` \
            (held-out maps: every given map except apartment, bridge, forest and lab, from which \
            the crate's priors are learned).\n\n\
            - Layouts (cosine sensors unless noted): `cube6` the faces of a cube; `dome5` the \
            zenith and 4 at 45° elevation; `hemi7` the zenith and 6 at 30°; `ico12` the 12 \
            vertices of an icosahedron; `sf16` a spherical Fibonacci set of 16; `cube6-cos2` a \
            cube whose side faces have a cos² response; `tetra4` the vertices of a regular \
            tetrahedron; `cube5` a cube without its −z face (a device on a table); `ring8` 8 at \
            20° elevation, 45° apart, no zenith sensor; `corners8` the 8 corners of a cube; \
            `rand10` 10 uniform random directions (seeded); `wall6` on a wall facing +x, one \
            along +x and 5 at 60° from it, 72° apart, the first above it.\n\
            - Rotations: the layouts that see all round (`cube6`, `ico12`, `sf16`, `cube6-cos2`, \
            `tetra4`, `corners8`, `rand10`) at uniform random rotations, queried at uniform \
            normals on the sphere; the others about `z` only (up stays up), queried where they \
            look: `dome5`, `hemi7`, `cube5` and `ring8` at uniform normals above the horizon, \
            `wall6` at uniform normals over the sphere, each scored for the rotations that turn \
            +x towards it (the hemisphere in front of the wall).\n\
            - Noise: each reading times `1 + η·ε`, `ε` standard normal; the probe is told `η`.\n\
            - Truth: the exact integral over every pixel of the map.\n\
            - `bmc`: `LayoutProbe` with the prior the crate recommends for the layout, \
            `Prior::for_layout` (`clamp`) or `Prior::smooth_for_layout` (`smooth`): \
            `ENVIRONMENT` (`SMOOTH_ENVIRONMENT`) for the layouts that see all round, \
            `ONE_SIDED` (`SMOOTH_ONE_SIDED`) for the others. Its error over the best of the \
            nearest sensor, the cosine-weighted average of the readings and the SH fits of \
            degree 1 and 2 (least squares, or minimum norm below 9 sensors), deconvolved by the \
            responses, on the same readings, per map. Coverage: the share of queries within 2σ, \
            σ² the variance that `irradiance` returns (its direction average over the sphere) \
            and the exact variance at the normal (`irradiance_variance`).\n\n";
        std::fs::write(dir.join("sensors.md"), format!("{header}{out}"))?;
    }
    Ok(())
}
