//! Probes over sensor layouts: the hardware's own directions, angular responses and noise.
//!
//! ```text
//! cargo eval sensors -- [MAPS…] [--csv FILE] [--out DIR] [--quick] [--explore]
//! ```
//!
//! Prototype stage: f64 Gaussian-process estimators (variants of the prior mean and the
//! hyperparameter policy) against the standard estimators on the same readings.

#![allow(clippy::needless_range_loop)]

use sphere_quadrature_eval::{cli, compare, parallel, renderer_engine, tiers};

use std::error::Error;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Parser;
use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use reference::sh::{legendre, real_sh};
use reference::vec::{dot, mat_mul_vec, normalize};
use renderer_engine::Cholesky;
use sphere_quadrature::footprint::Kind;
use sphere_quadrature::layout::{
    LayoutProbe, Mean as CrateMean, Noise, Prior, Response, Sensor, DEGREES,
};
use sphere_quadrature::Vec3;

/// Legendre degrees summed in the f64 series.
const L: usize = 48;
const TIERS: [&str; 2] = ["clamp", "smooth"];
const NOISES: [f64; 3] = [0.0, 0.01, 0.05];
const SEED: u64 = 0x5e45_0a11;

#[derive(Clone)]
struct Layout {
    name: &'static str,
    dirs: Vec<[f64; 3]>,
    /// Cosine power of each sensor's response.
    power: Vec<u32>,
    /// Where a layout that does not cover the sphere looks (before its rotation about `z`):
    /// it is queried at the normals of that hemisphere only.
    look: Option<[f64; 3]>,
}

const UP: Option<[f64; 3]> = Some([0.0, 0.0, 1.0]);

fn elevated(elevation_deg: f64, azimuth_deg: f64) -> [f64; 3] {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()]
}

fn layouts() -> Vec<Layout> {
    let cube: Vec<[f64; 3]> = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let mut dome = vec![[0.0, 0.0, 1.0]];
    dome.extend((0..4).map(|k| elevated(45.0, 90.0 * k as f64)));
    let mut hemi = vec![[0.0, 0.0, 1.0]];
    hemi.extend((0..6).map(|k| elevated(30.0, 60.0 * k as f64)));
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut ico = Vec::new();
    for s1 in [-1.0, 1.0] {
        for s2 in [-1.0, 1.0] {
            ico.push(normalize([0.0, s1, s2 * phi]));
            ico.push(normalize([s1, s2 * phi, 0.0]));
            ico.push(normalize([s2 * phi, 0.0, s1]));
        }
    }
    let sf: Vec<[f64; 3]> = {
        let p = sphere_quadrature::probe::Probe::<16>::new();
        p.directions().iter().map(|d| [d.x as f64, d.y as f64, d.z as f64]).collect()
    };
    let tetra: Vec<[f64; 3]> =
        [[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]]
            .into_iter()
            .map(normalize)
            .collect();
    let corners: Vec<[f64; 3]> = (0..8)
        .map(|k| {
            let s = |b: usize| if k >> b & 1 == 1 { -1.0 } else { 1.0 };
            normalize([s(0), s(1), s(2)])
        })
        .collect();
    let ring: Vec<[f64; 3]> = (0..8).map(|k| elevated(20.0, 45.0 * k as f64)).collect();
    let mut random = Rng::new(SEED ^ 0x0a4d_0010);
    let rand10: Vec<[f64; 3]> = (0..10).map(|_| random.uniform_sphere()).collect();
    // On a wall facing +x: one sensor along +x and five at 60° from it, 72° apart (the first
    // straight above it).
    let mut wall = vec![[1.0, 0.0, 0.0]];
    wall.extend((0..5).map(|k| {
        let (s, c) = (90.0 + 72.0 * k as f64).to_radians().sin_cos();
        let (st, ct) = 60f64.to_radians().sin_cos();
        [ct, st * c, st * s]
    }));
    vec![
        Layout { name: "cube6", dirs: cube.clone(), power: vec![1; 6], look: None },
        Layout { name: "dome5", dirs: dome, power: vec![1; 5], look: UP },
        Layout { name: "hemi7", dirs: hemi, power: vec![1; 7], look: UP },
        Layout { name: "ico12", dirs: ico, power: vec![1; 12], look: None },
        Layout { name: "sf16", dirs: sf, power: vec![1; 16], look: None },
        Layout {
            name: "cube6-cos2",
            dirs: cube.clone(),
            power: vec![2, 2, 2, 2, 1, 1],
            look: None,
        },
        Layout { name: "tetra4", dirs: tetra, power: vec![1; 4], look: None },
        Layout { name: "cube5", dirs: cube[..5].to_vec(), power: vec![1; 5], look: UP },
        Layout { name: "ring8", dirs: ring, power: vec![1; 8], look: UP },
        Layout { name: "corners8", dirs: corners, power: vec![1; 8], look: None },
        Layout { name: "rand10", dirs: rand10, power: vec![1; 10], look: None },
        Layout { name: "wall6", dirs: wall, power: vec![1; 6], look: Some([1.0, 0.0, 0.0]) },
    ]
}

/// `g_l` of the normalised cosine power `P`.
fn gains(p: u32) -> Vec<f64> {
    (0..=L).map(|l| Kind::CosinePower { exponent: p }.gain(l).expect("gain")).collect()
}

/// The clamped cosine's zonal factors `c_l` (`c₀ = π`).
fn cosine_factors() -> Vec<f64> {
    gains(1).iter().map(|g| g * PI).collect()
}

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

/// One layout's fixed geometry for the GP.
struct Geometry {
    g: Vec<Vec<f64>>,
    dirs: Vec<[f64; 3]>,
    c: Vec<f64>,
}

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

/// The crate's layout probe at this layout's size.
fn crate_fit_k<const K: usize>(
    geo: &Geometry,
    powers: &[u32],
    priors: &[Prior],
    relative: f64,
    y: &[f64],
    normals: &[[f64; 3]],
) -> Option<CrateFit> {
    let sensors: [Sensor; K] = std::array::from_fn(|i| {
        let d = geo.dirs[i];
        Sensor::new(
            Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32),
            Response::CosinePower(powers[i] as f32),
        )
    });
    let noise = Noise { absolute: 0.0, relative: relative as f32 };
    let readings: [f32; K] = std::array::from_fn(|i| y[i] as f32);
    // With several priors, the one of the highest REML likelihood for these readings.
    let mut probe: Option<LayoutProbe<K>> = None;
    for prior in priors {
        let mut candidate = LayoutProbe::<K>::new(&sensors, *prior, noise).ok()?;
        candidate.update(&readings).ok()?;
        if probe.as_ref().is_none_or(|p| candidate.log_likelihood() > p.log_likelihood()) {
            probe = Some(candidate);
        }
    }
    let probe = probe?;
    let mut fit = CrateFit { values: Vec::new(), exact: Vec::new(), averaged: Vec::new() };
    for n in normals {
        let v = Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32);
        let e = probe.irradiance(v).ok()?;
        fit.values.push(e.value as f64);
        fit.averaged.push(e.variance as f64);
        fit.exact.push(probe.irradiance_variance(v).ok()? as f64);
    }
    Some(fit)
}

/// The crate probe's values at the normals, with the exact variance at each
/// (`irradiance_variance`) and the direction-averaged one that `irradiance` returns.
struct CrateFit {
    values: Vec<f64>,
    exact: Vec<f64>,
    averaged: Vec<f64>,
}

fn crate_fit(
    geo: &Geometry,
    powers: &[u32],
    prior: &[Prior],
    relative: f64,
    y: &[f64],
    normals: &[[f64; 3]],
) -> Option<CrateFit> {
    match y.len() {
        4 => crate_fit_k::<4>(geo, powers, prior, relative, y, normals),
        5 => crate_fit_k::<5>(geo, powers, prior, relative, y, normals),
        6 => crate_fit_k::<6>(geo, powers, prior, relative, y, normals),
        7 => crate_fit_k::<7>(geo, powers, prior, relative, y, normals),
        8 => crate_fit_k::<8>(geo, powers, prior, relative, y, normals),
        10 => crate_fit_k::<10>(geo, powers, prior, relative, y, normals),
        12 => crate_fit_k::<12>(geo, powers, prior, relative, y, normals),
        16 => crate_fit_k::<16>(geo, powers, prior, relative, y, normals),
        _ => None,
    }
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

fn spectrum_f32(k: &[f64]) -> [f32; DEGREES] {
    std::array::from_fn(|l| k.get(l).copied().unwrap_or(0.0) as f32)
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
    /// Write src/layout/learned.rs (the crate's learned priors) from the training maps
    #[arg(long)]
    write_priors: bool,
    /// Fail unless src/layout/learned.rs is what the training maps give
    #[arg(long)]
    check_priors: bool,
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

/// Rotationally averaged SH power `C_l` (l ≤ 24) of `lum/mean − profile(z)` on a 128×64
/// downsample of `map` (`profile` empty: of `lum/mean`).
fn spectrum(map: &EnvMap, profile: &[f64]) -> Vec<f64> {
    const LS: usize = DEGREES - 1;
    let m = tiers::downsample(map, 128, 64);
    let mean = luminance(m.mean_radiance());
    let mut c = vec![0.0; (LS + 1) * (LS + 1)];
    for v in 0..m.height {
        let omega = m.pixel_solid_angle(v);
        for u in 0..m.width {
            let d = m.pixel_direction(u, v);
            let prof: f64 = (0..profile.len()).map(|l| profile[l] * legendre(l, d[2])).sum();
            let f = luminance(m.pixel(u, v)) / mean - prof;
            let mut k = 0;
            for l in 0..=LS {
                for mm in -(l as i64)..=l as i64 {
                    c[k] += f * omega * real_sh(l, mm, d);
                    k += 1;
                }
            }
        }
    }
    let mut out = vec![0.0; L + 1];
    let mut k = 0;
    for l in 0..=LS {
        let mut p = 0.0;
        for _ in 0..(2 * l + 1) {
            p += c[k] * c[k];
            k += 1;
        }
        out[l] = p / (2 * l + 1) as f64;
    }
    out
}

/// The second moments `c_a·c_b` (row-major 3×3) of a map's zonal coefficients `c₀₀, c₁₀, c₂₀`
/// of luminance over its mean (orthonormal harmonics about `+z`).
fn zonal_moments(map: &EnvMap) -> Vec<f64> {
    let mut c = [0.0f64; 3];
    let mean = luminance(map.mean_radiance());
    for v in 0..map.height {
        let omega = map.pixel_solid_angle(v);
        for u in 0..map.width {
            let d = map.pixel_direction(u, v);
            let f = luminance(map.pixel(u, v)) / mean;
            for (l, cl) in c.iter_mut().enumerate() {
                *cl += f * omega * real_sh(l, 0, d);
            }
        }
    }
    (0..9).map(|k| c[k / 3] * c[k % 3]).collect()
}

/// The prior of light from above from the maps `use_maps`: degrees ≤ 2 flat with the zonal
/// correlations of ½M + ½·diag(C₀, C₁, C₂), above them the spectrum over
/// τ = (C₀ + 3C₁ + 5C₂)/9.
fn sky_prior(
    spectra: &[Vec<f64>],
    moments: &[Vec<f64>],
    use_maps: &[usize],
) -> (Vec<f64>, [f64; 3]) {
    let n = use_maps.len() as f64;
    let spec: Vec<f64> = (0..spectra[0].len())
        .map(|l| use_maps.iter().map(|&m| spectra[m][l]).sum::<f64>() / n)
        .collect();
    let mom: Vec<f64> =
        (0..9).map(|k| use_maps.iter().map(|&m| moments[m][k]).sum::<f64>() / n).collect();
    let s_ab = |a: usize, b: usize| 0.5 * mom[3 * a + b] + if a == b { 0.5 * spec[a] } else { 0.0 };
    let rho = |a: usize, b: usize| s_ab(a, b) / (s_ab(a, a) * s_ab(b, b)).sqrt();
    let tau = (spec[0] + 3.0 * spec[1] + 5.0 * spec[2]) / 9.0;
    let mut sky: Vec<f64> = spec.iter().map(|c| c / tau).collect();
    sky[0] = 1.0;
    sky[1] = 1.0;
    sky[2] = 1.0;
    (sky, [rho(0, 1), rho(1, 2), rho(0, 2)])
}

/// |error|/σ (exact variance) of the crate's probe with `prior` on the upward layouts of the
/// benchmark over `map`: 8 turns about z, 32 normals above, noise 0, 1 and 5 %.
fn upward_errors(map: &EnvMap, prior: Prior, seed: u64) -> Vec<f64> {
    let mut rng = Rng::new(SEED ^ 0xca11 ^ seed);
    let normals: Vec<[f64; 3]> = (0..32).map(|_| rng.uniform_hemisphere()).collect();
    let lum: Vec<f64> =
        map.pixels.iter().map(|p| luminance([p[0] as f64, p[1] as f64, p[2] as f64])).collect();
    let integrate = |w: &[f64]| w.iter().zip(&lum).map(|(a, b)| a * b).sum::<f64>();
    let truth: Vec<f64> = normals
        .iter()
        .map(|&n| integrate(&reference::truth::cosine_weights(map.width, map.height, n)))
        .collect();
    let c = cosine_factors();
    let mut out = Vec::new();
    // The two upward layouts the sky priors were learned on (the later ones are held out).
    for lay in layouts().into_iter().filter(|l| matches!(l.name, "dome5" | "hemi7")) {
        for r in 0..8 {
            let (sn, cs) = (2.0 * PI * (r as f64 + 0.3) / 8.0).sin_cos();
            let rot = [[cs, -sn, 0.0], [sn, cs, 0.0], [0.0, 0.0, 1.0]];
            let geo = Geometry {
                g: lay.power.iter().map(|&p| gains(p)).collect(),
                dirs: lay.dirs.iter().map(|&d| mat_mul_vec(rot, d)).collect(),
                c: c.clone(),
            };
            let exact: Vec<f64> = geo
                .dirs
                .iter()
                .map(|&d| {
                    integrate(&reference::truth::cosine_weights(map.width, map.height, d)) / PI
                })
                .collect();
            for eta in NOISES {
                let y: Vec<f64> = exact
                    .iter()
                    .map(|v| {
                        let (u1, u2) = (rng.next_f64().max(1e-300), rng.next_f64());
                        v * (1.0 + eta * (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos())
                    })
                    .collect();
                if let Some(f) = crate_fit(&geo, &lay.power, &[prior], eta, &y, &normals) {
                    for q in 0..normals.len() {
                        out.push((f.values[q] - truth[q]).abs() / f.exact[q].max(1e-300).sqrt());
                    }
                }
            }
        }
    }
    out
}

/// The file of the crate's learned priors.
const LEARNED: &str = "src/layout/learned.rs";

/// The crate's learned priors from the training maps (examples/envmaps/), as the Rust
/// source of `src/layout/learned.rs`: per tier (`clamp` as the default, `smooth`), the mean
/// SH power spectrum of luminance over its mean (degrees < DEGREES, on a 128×64 downsample),
/// and the prior of light from above (below); in f64, rounded once to f32.
fn learned_priors(threads: usize) -> Result<String, String> {
    let paths = cli::bundled_maps(&cli::TRAINING_MAPS);
    let maps: Vec<[EnvMap; 2]> = parallel::parallel_map(&paths, threads, |_, p| {
        let m = EnvMap::load(p).map_err(|e| format!("{}: {e}", p.display()))?;
        let clamp = compare::clamped(&m);
        let smooth = tiers::smooth(&clamp);
        Ok::<_, String>([clamp, smooth])
    })
    .into_iter()
    .collect::<Result<_, _>>()?;
    let average = |f: &dyn Fn(&EnvMap) -> Vec<f64>, t: usize| -> Vec<f64> {
        let all: Vec<Vec<f64>> = maps.iter().map(|m| f(&m[t])).collect();
        (0..all[0].len())
            .map(|l| all.iter().map(|p| p[l]).sum::<f64>() / all.len() as f64)
            .collect()
    };
    let list = |v: &[f64], n: usize| -> String {
        v.iter().take(n).map(|x| format!("{:?}", *x as f32)).collect::<Vec<_>>().join(", ")
    };
    let mut out = String::from(
        "//! The learned priors of [`super::Prior`]: generated by `cargo eval sensors -- \
         --write-priors` from the\n//! bundled training maps (apartment, bridge, forest, lab) in f64, \
         rounded once to f32. Do not edit;\n//! CI regenerates and compares it \
         (`cargo eval sensors -- --check-priors`).\n\n",
    );
    for (t, tier) in ["ENVIRONMENT", "SMOOTH"].iter().enumerate() {
        let spec = average(&|m: &EnvMap| spectrum(m, &[]), t);
        let _ = writeln!(out, "/// Spectrum `K_l` of the {} tier.", TIERS[t]);
        let _ = writeln!(
            out,
            "pub(super) const {tier}_SPECTRUM: [f32; super::DEGREES] = [{}];",
            list(&spec, DEGREES)
        );
        // Light from above: a flat prior on degrees ≤ 2 (K₀ = K₁ = K₂ = 1) with the zonal
        // correlations of S = ½M + ½·diag(C₀, C₁, C₂), M the maps' second moments of their
        // zonal coefficients (c₀₀, c₁₀, c₂₀) of luminance over its mean, and above degree 2
        // the spectrum over τ = (C₀ + 3C₁ + 5C₂)/9, the mean power per coefficient of
        // degrees ≤ 2.
        let spectra: Vec<Vec<f64>> = maps.iter().map(|m| spectrum(&m[t], &[])).collect();
        let moments: Vec<Vec<f64>> = maps.iter().map(|m| zonal_moments(&m[t])).collect();
        let all: Vec<usize> = (0..maps.len()).collect();
        let (sky, zonal) = sky_prior(&spectra, &moments, &all);
        let _ = writeln!(
            out,
            "/// Spectrum of light from above (flat to degree 2), {} tier.",
            TIERS[t]
        );
        let _ = writeln!(
            out,
            "pub(super) const {tier}_SKY_SPECTRUM: [f32; super::DEGREES] = [{}];",
            list(&sky, DEGREES)
        );
        let _ = writeln!(out, "/// Zonal correlations of light from above, {} tier.", TIERS[t]);
        let _ =
            writeln!(out, "pub(super) const {tier}_SKY_ZONAL: [f32; 3] = [{}];", list(&zonal, 3));
        // Its variance factor, leave one map out: the prior of the other three on the upward
        // layouts (rotations about z, normals above) at noise 0, 1 and 5 %, the smallest
        // power of 2^¼ for which 2σ holds for 95 % of the errors.
        let calibrate = |name: &str, isotropic: bool| -> f64 {
            let mut ratios: Vec<f64> = Vec::new();
            for m in 0..maps.len() {
                let others: Vec<usize> = all.iter().copied().filter(|&o| o != m).collect();
                let (sky, zonal) = sky_prior(&spectra, &moments, &others);
                let zonal = if isotropic { [0.0; 3] } else { zonal };
                let prior = Prior {
                    spectrum: spectrum_f32(&sky),
                    zonal: [zonal[0] as f32, zonal[1] as f32, zonal[2] as f32],
                    mean: CrateMean::Zero,
                    variance_scale: 1.0,
                };
                ratios.extend(upward_errors(&maps[m][t], prior, m as u64));
            }
            ratios.sort_by(f64::total_cmp);
            let q95 = ratios[(0.95 * ratios.len() as f64) as usize];
            let mut k = -24i32;
            while 2f64.powf(k as f64 / 4.0) < (q95 / 2.0).powi(2) {
                k += 1;
            }
            let calibration = 2f64.powf(k as f64 / 4.0);
            eprintln!(
                "{} tier, {name}: 95 % of |error|/σ ≤ {q95:.3} over {} errors: variance \
                 factor 2^({k}/4) = {calibration:.4}",
                TIERS[t],
                ratios.len()
            );
            calibration
        };
        let calibration = calibrate("light from above", false);
        let _ = writeln!(
            out,
            "/// Variance factor of light from above (leave one map out), {} tier.",
            TIERS[t]
        );
        let _ = writeln!(
            out,
            "pub(super) const {tier}_SKY_CALIBRATION: f32 = {:?};",
            calibration as f32
        );
        // The one-sided prior: the same spectrum, isotropic; its variance factor likewise.
        let calibration = calibrate("one-sided", true);
        let _ = writeln!(
            out,
            "/// Variance factor of the one-sided prior (leave one map out), {} tier.",
            TIERS[t]
        );
        let _ = writeln!(
            out,
            "pub(super) const {tier}_ONE_SIDED_CALIBRATION: f32 = {:?};",
            calibration as f32
        );
    }
    rustfmt(&out)
}

/// The text as `rustfmt` (of the toolchain, the workspace's `rustfmt.toml`) lays it out, so
/// that the committed file passes `cargo fmt --check`.
fn rustfmt(text: &str) -> Result<String, String> {
    use std::io::Write as _;
    let mut child = std::process::Command::new("rustfmt")
        .args(["--edition", "2021", "--emit", "stdout"])
        .current_dir(cli::repo_root())
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| format!("rustfmt: {e}"))?;
    child
        .stdin
        .take()
        .ok_or("rustfmt: no stdin")?
        .write_all(text.as_bytes())
        .map_err(|e| format!("rustfmt: {e}"))?;
    let output = child.wait_with_output().map_err(|e| format!("rustfmt: {e}"))?;
    if !output.status.success() {
        return Err("rustfmt failed on the generated priors".into());
    }
    String::from_utf8(output.stdout).map_err(|e| format!("rustfmt: {e}"))
}

struct Scene {
    name: String,
    training: bool,
    tiers: Vec<EnvMap>,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let threads = args.threads.count();
    if args.write_priors || args.check_priors {
        let text = learned_priors(threads)?;
        let path = cli::repo_root().join(LEARNED);
        if args.write_priors {
            std::fs::write(&path, &text)?;
            println!("wrote {LEARNED}");
        } else if std::fs::read_to_string(&path).ok().as_deref() != Some(text.as_str()) {
            return Err(format!("{LEARNED} is not what the training maps give: run cargo eval sensors -- --write-priors").into());
        } else {
            println!("{LEARNED} is current");
        }
        return Ok(());
    }
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
