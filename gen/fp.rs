//! Generator of the *footprint renderer* tables (`bmc::FootprintRenderer`), in f64: Bayesian
//! Monte Carlo of the renderer integrals from lookups whose footprints follow the sample
//! density, with an error bar from the most likely of a family of models.
//!
//! # The integral and the samples
//! In the lobe frame `(t₁, t₂, a)` (`a` the lobe axis, `t₁` towards the normal `n`, which lies
//! at angle `α` from `a`), `p(y) = A·max(0, cos θ)ᵉ·max(0, n·y)`: irradiance is `A = 1, e = 0,
//! α = 0` (`p = max(0, n·y)`); Phong is `A = (e + 1)/(2π)` with `α = θₙ`. Sample `j` sits at
//! `xⱼ` (the lobe-morphed hemisphere spherical Fibonacci set) and reads the radiance through
//! the normalised spherical Gaussian footprint of sharpness `sⱼ`:
//! `Yⱼ = ∫ L(y)·sⱼ/(2π(1 − e^{−2sⱼ}))·exp(sⱼ(xⱼ·y − 1)) dy`.
//!
//! # The model
//! `L` is a Gaussian process with a constant mean and the kernel `σ²·exp(λ(x·y − 1))`
//! (`λ = 2/l²`), plus a nugget `σ²σ′²` on each lookup. In real spherical harmonics `Y_lm`
//! the kernel is `Σ_l κ_l Σ_m Y_lm(x)Y_lm(y)` (`κ_l = 2π∫exp(λ(t − 1))P_l(t)dt`) and the
//! footprint multiplies degree `l` by `ρ_l(s) = i_l(s)/i₀(s)` (Funk–Hecke). With the
//! features `ψⱼ,lm = ρ_l(sⱼ)·Y_lm(xⱼ)` and `p_lm = ∫p·Y_lm`, every quantity of Bayesian Monte
//! Carlo is a finite sum over degrees `l ≤ L` (the series is cut where `κ_l < 10⁻¹⁷κ₀`):
//! - `Qᵢⱼ = Σ κ_l ψᵢ,lm ψⱼ,lm + σ′²δᵢⱼ = Σ_l κ_l ρ_l(sᵢ)ρ_l(sⱼ)(2l + 1)/(4π)·P_l(xᵢ·xⱼ) + σ′²δᵢⱼ`;
//! - `zⱼ = Σ κ_l ψⱼ,lm p_lm`, `∫p = √(4π)·p₀₀`;
//! - for any weights `w`, the error variance of `Σwⱼ Yⱼ` (in units of `σ²`) is
//!   `u(w) = Σ_l κ_l Σ_m (p_lm − Σⱼ wⱼ ψⱼ,lm)² + σ′²|w|²`: a sum of squares, so it cannot
//!   cancel below zero (the quadrature `V̄ − 2wᵀz + wᵀQw` of the same quantity can).
//!
//! `p_lm` is exact up to rounding: `p` is even in the azimuth `φ`, so only the `cos mφ`
//! harmonics are nonzero, and on the ring at `θ` the azimuthal integral of
//! `(sin α sin θ cos φ + cos α cos θ)·cos mφ` over the visible arc `|φ| ≤ β(θ)` is closed form.
//! The integral over `θ` is Gauss–Legendre on two pieces: rings above the horizon
//! (`θ ≤ π/2 − α`), and rings the horizon cuts, in `v` with `θ = θ_b + (θ₁ − θ_b)v²`
//! (`β` has a square-root branch at `θ_b`, smooth in `v`).

use std::f64::consts::PI;

use std::fmt::Write as _;

use super::probe::{bessel_ratios, legendre_series, sg_coefficients};
use super::sg::gauss_legendre;

/// Index of the real spherical harmonic `(l, m)`, `−l ≤ m ≤ l`.
#[inline]
pub fn sh_index(l: usize, m: isize) -> usize {
    ((l * l + l) as isize + m) as usize
}

/// `Λ_l^m(cos θ)` for `0 ≤ m ≤ l ≤ lmax` (normalised so that `√2·Λ_l^m(cos θ)·cos mφ`,
/// `√2·Λ_l^m·sin mφ` and `Λ_l^0` are orthonormal on the sphere), indexed `l(l + 1)/2 + m`.
pub fn legendre_normalised(lmax: usize, c: f64, s: f64) -> Vec<f64> {
    let idx = |l: usize, m: usize| l * (l + 1) / 2 + m;
    let mut out = vec![0.0; (lmax + 1) * (lmax + 2) / 2];
    let mut diag = 1.0 / (4.0 * PI).sqrt();
    for m in 0..=lmax {
        if m > 0 {
            diag *= ((2 * m + 1) as f64 / (2 * m) as f64).sqrt() * s;
        }
        out[idx(m, m)] = diag;
        if m < lmax {
            out[idx(m + 1, m)] = ((2 * m + 3) as f64).sqrt() * c * diag;
        }
        for l in m + 2..=lmax {
            let (lf, mf) = (l as f64, m as f64);
            let a = ((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf)).sqrt();
            let b = (((lf - 1.0).powi(2) - mf * mf) / (4.0 * (lf - 1.0).powi(2) - 1.0)).sqrt();
            out[idx(l, m)] = a * (c * out[idx(l - 1, m)] - b * out[idx(l - 2, m)]);
        }
    }
    out
}

/// The `(lmax + 1)²` real spherical harmonics at the unit vector `x` (local frame, `z` the
/// lobe axis), indexed by [`sh_index`].
pub fn sh(lmax: usize, x: [f64; 3]) -> Vec<f64> {
    let c = x[2].clamp(-1.0, 1.0);
    let s = (x[0] * x[0] + x[1] * x[1]).sqrt();
    let phi = x[1].atan2(x[0]);
    let lam = legendre_normalised(lmax, c, s);
    let mut out = vec![0.0; (lmax + 1) * (lmax + 1)];
    for l in 0..=lmax {
        out[sh_index(l, 0)] = lam[l * (l + 1) / 2];
        for m in 1..=l {
            let v = 2f64.sqrt() * lam[l * (l + 1) / 2 + m];
            let (sm, cm) = (m as f64 * phi).sin_cos();
            out[sh_index(l, m as isize)] = v * cm;
            out[sh_index(l, -(m as isize))] = v * sm;
        }
    }
    out
}

/// The known factor of the integrand in its lobe frame: `A·max(0, cos θ)ᵉ·max(0, n·y)` with
/// `n = (sin α, 0, cos α)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integrand {
    /// `A`.
    pub scale: f64,
    /// `e`.
    pub exponent: f64,
    /// `α`, the angle from the lobe axis to the normal.
    pub alpha: f64,
}

impl Integrand {
    /// Irradiance: `p = max(0, n·y)` about `n`.
    pub fn irradiance() -> Self {
        Self { scale: 1.0, exponent: 0.0, alpha: 0.0 }
    }

    /// Normalised Phong of exponent `e` about the mirror direction, with the cosine factor
    /// and the horizon of a normal at angle `alpha` from it.
    pub fn phong(e: f64, alpha: f64) -> Self {
        Self { scale: (e + 1.0) / (2.0 * PI), exponent: e, alpha }
    }

    /// `p(y)` at a unit `y` of the lobe frame.
    pub fn value(&self, y: [f64; 3]) -> f64 {
        let (sa, ca) = self.alpha.sin_cos();
        let h = (sa * y[0] + ca * y[2]).max(0.0);
        if y[2] <= 0.0 {
            return 0.0;
        }
        self.scale * y[2].powf(self.exponent) * h
    }

    /// `p_lm = ∫ p·Y_lm` for `l ≤ lmax` (the `sin mφ` ones are zero), indexed by
    /// [`sh_index`]; `nodes` Gauss–Legendre nodes per piece.
    pub fn coefficients(&self, lmax: usize, nodes: usize) -> Vec<f64> {
        let mut out = vec![0.0; (lmax + 1) * (lmax + 1)];
        let (sa, ca) = self.alpha.sin_cos();
        let e = self.exponent;
        // Rings where cos^e θ is below e⁻⁴⁵ of its peak are left out.
        let theta_end = if e > 0.0 { (-45.0 / e).exp().acos().min(PI / 2.0) } else { PI / 2.0 };
        let theta_b = (PI / 2.0 - self.alpha).max(0.0);
        let (x, w) = gauss_legendre(nodes);
        let mut ring = |theta: f64, weight: f64| {
            let (s, c) = theta.sin_cos();
            // Visible arc |φ| ≤ β: sin α sin θ cos φ + cos α cos θ ≥ 0.
            let beta =
                if sa * s <= ca * c { PI } else { (-(ca * c) / (sa * s)).clamp(-1.0, 1.0).acos() };
            // J0_k = ∫_{−β}^{β} cos kφ dφ, k ≤ lmax + 1.
            let j0 = |k: usize| {
                if k == 0 {
                    2.0 * beta
                } else {
                    2.0 * (k as f64 * beta).sin() / k as f64
                }
            };
            let lam = legendre_normalised(lmax, c, s);
            let common = weight * self.scale * s * c.max(0.0).powf(e);
            for m in 0..=lmax {
                let j1 = 0.5 * (j0(m.abs_diff(1)) + j0(m + 1));
                let cm = sa * s * j1 + ca * c * j0(m);
                let norm = if m == 0 { 1.0 } else { 2f64.sqrt() };
                for l in m..=lmax {
                    out[sh_index(l, m as isize)] += common * cm * norm * lam[l * (l + 1) / 2 + m];
                }
            }
        };
        let full_end = theta_b.min(theta_end);
        for (xk, wk) in x.iter().zip(&w) {
            let theta = 0.5 * full_end * (xk + 1.0);
            ring(theta, 0.5 * full_end * wk);
        }
        if theta_b < theta_end {
            // θ = θ_b + (θ_end − θ_b)·v², v ∈ [0, 1].
            let span = theta_end - theta_b;
            for (xk, wk) in x.iter().zip(&w) {
                let v = 0.5 * (xk + 1.0);
                ring(theta_b + span * v * v, 0.5 * wk * 2.0 * span * v);
            }
        }
        out
    }
}

/// The highest degree the kernel of sharpness `lambda` needs: the first `l ≥ λ` with
/// `κ_l < 10⁻¹⁷·κ₀` (at most 400).
pub fn degree_cut(lambda: f64) -> usize {
    let k = sg_coefficients(lambda, 401);
    (1..401).find(|&l| l as f64 >= lambda && k[l] < 1e-17 * k[0]).unwrap_or(400)
}

/// The samples of one renderer set: directions in the lobe frame and footprint sharpnesses,
/// with their spherical-harmonic features up to `lmax`.
#[derive(Clone, Debug)]
pub struct Design {
    /// Directions (lobe frame).
    pub xs: Vec<[f64; 3]>,
    /// Footprint sharpness per sample (0: a point sample).
    pub sharpness: Vec<f64>,
    /// Highest degree.
    pub lmax: usize,
    /// `ψⱼ,lm = ρ_l(sⱼ)·Y_lm(xⱼ)`, sample-major (`(lmax + 1)²` per sample).
    pub psi: Vec<f64>,
    /// `ρ_l(sⱼ)`, sample-major (`lmax + 1` per sample).
    pub rho: Vec<f64>,
}

impl Design {
    /// The design of `xs` with footprints `sharpness`.
    pub fn new(xs: Vec<[f64; 3]>, sharpness: Vec<f64>, lmax: usize) -> Self {
        let width = (lmax + 1) * (lmax + 1);
        let mut psi = Vec::with_capacity(xs.len() * width);
        let mut rho = Vec::with_capacity(xs.len() * (lmax + 1));
        for (&x, &s) in xs.iter().zip(&sharpness) {
            let r = if s > 0.0 { bessel_ratios(s, lmax + 1) } else { vec![1.0; lmax + 1] };
            let y = sh(lmax, x);
            for (l, &rl) in r.iter().enumerate() {
                psi.extend(y[l * l..(l + 1) * (l + 1)].iter().map(|y| rl * y));
            }
            rho.extend_from_slice(&r);
        }
        Self { xs, sharpness, lmax, psi, rho }
    }

    /// Samples.
    pub fn len(&self) -> usize {
        self.xs.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.xs.is_empty()
    }

    fn width(&self) -> usize {
        (self.lmax + 1) * (self.lmax + 1)
    }

    /// `Σⱼ wⱼ ψⱼ,lm` per `(l, m)`.
    pub fn combine(&self, w: &[f64]) -> Vec<f64> {
        let width = self.width();
        let mut out = vec![0.0; width];
        for (j, &wj) in w.iter().enumerate() {
            for (o, p) in out.iter_mut().zip(&self.psi[j * width..(j + 1) * width]) {
                *o += wj * p;
            }
        }
        out
    }

    /// Per degree `l`, `R_l = Σ_m (p_lm − Σⱼ wⱼ ψⱼ,lm)²`: the weights' residual power.
    pub fn residual_power(&self, p: &[f64], w: &[f64]) -> Vec<f64> {
        let c = self.combine(w);
        (0..=self.lmax)
            .map(|l| {
                (l * l..(l + 1) * (l + 1))
                    .map(|k| (p.get(k).copied().unwrap_or(0.0) - c[k]).powi(2))
                    .sum()
            })
            .collect()
    }
}

/// The Gaussian process on one [`Design`]: `Q`, its Cholesky factor and the GLS pieces.
#[derive(Clone, Debug)]
pub struct Model {
    /// `λ = 2/l²`.
    pub lambda: f64,
    /// `σ′`.
    pub sigma: f64,
    /// `κ_l`, `l ≤ lmax`.
    pub kappa: Vec<f64>,
    n: usize,
    /// Lower Cholesky factor of `Q`, row-major `n×n`.
    factor: Vec<f64>,
    q1: Vec<f64>,
    s1: f64,
    log_det: f64,
}

impl Model {
    /// The model of `design` with kernel length `l` and nugget `sigma`; `None` if `Q` is not
    /// positive definite in f64.
    pub fn new(design: &Design, l: f64, sigma: f64) -> Option<Self> {
        let lambda = 2.0 / (l * l);
        let lmax = design.lmax;
        let kappa = sg_coefficients(lambda, lmax + 1);
        let n = design.len();
        let mut q = design.kernel_matrix(l);
        for i in 0..n {
            q[i * n + i] += sigma * sigma;
        }
        let factor = super::bmc::cholesky(&q, n).ok()?;
        let log_det = 2.0 * (0..n).map(|i| factor[i * n + i].ln()).sum::<f64>();
        let mut m = Self { lambda, sigma, kappa, n, factor, q1: Vec::new(), s1: 0.0, log_det };
        m.q1 = m.solve(&vec![1.0; n]);
        m.s1 = m.q1.iter().sum();
        Some(m)
    }

    /// `Q⁻¹b`.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.n;
        let l = &self.factor;
        let mut y = b.to_vec();
        for i in 0..n {
            let s: f64 = (0..i).map(|k| l[i * n + k] * y[k]).sum();
            y[i] = (y[i] - s) / l[i * n + i];
        }
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|k| l[k * n + i] * y[k]).sum();
            y[i] = (y[i] - s) / l[i * n + i];
        }
        y
    }

    /// `z` of the integrand with coefficients `p`.
    pub fn z(&self, design: &Design, p: &[f64]) -> Vec<f64> {
        let width = design.width();
        (0..design.len())
            .map(|j| {
                let psi = &design.psi[j * width..(j + 1) * width];
                (0..=design.lmax)
                    .map(|l| {
                        self.kappa[l]
                            * (l * l..(l + 1) * (l + 1)).map(|k| psi[k] * p[k]).sum::<f64>()
                    })
                    .sum()
            })
            .collect()
    }

    /// GLS weights `w = Q⁻¹z + (∫p − 1ᵀQ⁻¹z)·Q⁻¹1/(1ᵀQ⁻¹1)` for the integrand with
    /// coefficients `p`.
    pub fn weights(&self, design: &Design, p: &[f64]) -> Vec<f64> {
        let mass = (4.0 * PI).sqrt() * p[0];
        let a = self.solve(&self.z(design, p));
        let gap = mass - a.iter().sum::<f64>();
        a.iter().zip(&self.q1).map(|(a, q)| a + gap * q / self.s1).collect()
    }

    /// The unit error variance of weights `w` from the residual power of [`Design::residual_power`].
    pub fn unit_variance(&self, residual: &[f64], w: &[f64]) -> f64 {
        let s: f64 = residual.iter().zip(&self.kappa).map(|(r, k)| r * k).sum();
        s + self.sigma * self.sigma * w.iter().map(|w| w * w).sum::<f64>()
    }

    /// REML for samples `y`: `(σ̂², ℓ)` with `σ̂² = rᵀQ⁻¹r/(N − 1)` (`r = y − β̂1`, `β̂` the GLS
    /// mean) and `ℓ = −(N − 1)/2·ln σ̂² − ½ln|Q| − ½ln(1ᵀQ⁻¹1)`.
    pub fn reml(&self, y: &[f64]) -> (f64, f64) {
        let qy = self.solve(y);
        let beta = qy.iter().sum::<f64>() / self.s1;
        let quad: f64 = y.iter().zip(&qy).map(|(y, q)| y * q).sum::<f64>() - beta * beta * self.s1;
        let dof = (self.n - 1) as f64;
        let s2 = (quad / dof).max(f64::MIN_POSITIVE);
        (s2, -0.5 * dof * s2.ln() - 0.5 * self.log_det - 0.5 * self.s1.ln())
    }
}

impl Model {
    /// `Q` (row-major `n×n`) from its factor.
    pub fn matrix(&self) -> Vec<f64> {
        let n = self.n;
        let l = &self.factor;
        let mut q = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..=i {
                let s: f64 = (0..=j).map(|k| l[i * n + k] * l[j * n + k]).sum();
                q[i * n + j] = s;
                q[j * n + i] = s;
            }
        }
        q
    }

    /// The covariance `AᵀQA` of the contrasts `A` under this model, factored.
    pub fn reduced(&self, c: &Contrasts) -> Option<Reduced> {
        let (n, k) = (self.n, c.k);
        // B = LᵀA (n×k), AᵀQA = BᵀB.
        let mut b = vec![0.0; n * k];
        for i in 0..n {
            for j in 0..k {
                b[i * k + j] = (i..n).map(|r| self.factor[r * n + i] * c.a[r * k + j]).sum();
            }
        }
        let mut m = vec![0.0; k * k];
        for i in 0..k {
            for j in 0..k {
                m[i * k + j] = (0..n).map(|r| b[r * k + i] * b[r * k + j]).sum();
            }
        }
        let factor = super::bmc::cholesky(&m, k).ok()?;
        let log_det = 2.0 * (0..k).map(|i| factor[i * k + i].ln()).sum::<f64>();
        Some(Reduced { k, factor, log_det })
    }
}

/// `k` contrasts of the samples (orthogonal to constants): eigenvectors of `PQP`
/// (`P = I − 11ᵀ/N`) of a base model, spread evenly over its `N − 1` nonzero eigenvalues
/// from the largest down.
#[derive(Clone, Debug)]
pub struct Contrasts {
    /// Contrasts.
    pub k: usize,
    /// `A`, row-major `N×k`.
    pub a: Vec<f64>,
}

impl Contrasts {
    /// `k ≤ N − 1` contrasts from the base model.
    pub fn new(base: &Model, k: usize) -> Self {
        let n = base.n;
        let q = base.matrix();
        // PQP.
        let row: Vec<f64> =
            (0..n).map(|i| (0..n).map(|j| q[i * n + j]).sum::<f64>() / n as f64).collect();
        let all = row.iter().sum::<f64>() / n as f64;
        let mut pqp = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                pqp[i * n + j] = q[i * n + j] - row[i] - row[j] + all;
            }
        }
        let (values, vectors) = symmetric_eigen(&pqp, n);
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| values[b].total_cmp(&values[a]));
        // The constant vector has eigenvalue 0: drop the eigenvector closest to it.
        let constant = (0..n)
            .max_by(|&a, &b| {
                let s = |c: usize| (0..n).map(|r| vectors[r * n + c]).sum::<f64>().abs();
                s(a).total_cmp(&s(b))
            })
            .unwrap_or(n - 1);
        order.retain(|&c| c != constant);
        let k = k.clamp(1, n - 1);
        let picks: Vec<usize> = (0..k).map(|j| order[j * (n - 1) / k]).collect();
        let mut a = vec![0.0; n * k];
        for (j, &c) in picks.iter().enumerate() {
            for r in 0..n {
                a[r * k + j] = vectors[r * n + c];
            }
        }
        Self { k, a }
    }
}

/// A model's covariance of [`Contrasts`], factored.
#[derive(Clone, Debug)]
pub struct Reduced {
    k: usize,
    factor: Vec<f64>,
    log_det: f64,
}

impl Reduced {
    /// `(σ̂², ℓ)` of the contrasts `t = Aᵀy`: `σ̂² = tᵀC⁻¹t/k`, `ℓ = −k/2·ln σ̂² − ½ln|C|`.
    pub fn fit(&self, t: &[f64]) -> (f64, f64) {
        let k = self.k;
        let l = &self.factor;
        let mut y = t.to_vec();
        for i in 0..k {
            let s: f64 = (0..i).map(|r| l[i * k + r] * y[r]).sum();
            y[i] = (y[i] - s) / l[i * k + i];
        }
        let s2 = (y.iter().map(|v| v * v).sum::<f64>() / k as f64).max(f64::MIN_POSITIVE);
        (s2, -0.5 * k as f64 * s2.ln() - 0.5 * self.log_det)
    }
}

impl Contrasts {
    /// `t = Aᵀy`.
    pub fn apply(&self, y: &[f64]) -> Vec<f64> {
        let k = self.k;
        (0..k).map(|j| y.iter().enumerate().map(|(r, v)| self.a[r * k + j] * v).sum()).collect()
    }
}

/// Eigenvalues and eigenvectors (the columns of a row-major `n×n` matrix) of the symmetric
/// `a`, by cyclic Jacobi rotations to convergence.
pub fn symmetric_eigen(a: &[f64], n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut m = a.to_vec();
    let mut v = vec![0.0; n * n];
    for i in 0..n {
        v[i * n + i] = 1.0;
    }
    for _sweep in 0..100 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| m[i * n + j].powi(2))
            .sum();
        let diag: f64 = (0..n).map(|i| m[i * n + i].powi(2)).sum();
        if off <= 1e-30 * diag {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = m[p * n + q];
                if apq == 0.0 {
                    continue;
                }
                let theta = (m[q * n + q] - m[p * n + p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (mkp, mkq) = (m[k * n + p], m[k * n + q]);
                    m[k * n + p] = c * mkp - s * mkq;
                    m[k * n + q] = s * mkp + c * mkq;
                }
                for k in 0..n {
                    let (mpk, mqk) = (m[p * n + k], m[q * n + k]);
                    m[p * n + k] = c * mpk - s * mqk;
                    m[q * n + k] = s * mpk + c * mqk;
                }
                for k in 0..n {
                    let (vkp, vkq) = (v[k * n + p], v[k * n + q]);
                    v[k * n + p] = c * vkp - s * vkq;
                    v[k * n + q] = s * vkp + c * vkq;
                }
            }
        }
    }
    ((0..n).map(|i| m[i * n + i]).collect(), v)
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The lobe-morphed hemisphere spherical Fibonacci set in the lobe frame at phase 0 (the
/// glossy renderer's set, [`super::glossy::local_direction`]): `cos θⱼ = uⱼ^{1/(e+1)}`,
/// `uⱼ = 1 − (2j + 1)/(2N)`, golden azimuth; `e = 1` (the cosine) for irradiance.
pub fn lobe_set(n: usize, morph_exponent: u32) -> Vec<[f64; 3]> {
    (0..n).map(|j| super::glossy::local_direction(j, n, morph_exponent)).collect()
}

/// Footprint sharpness of each sample of `xs` (lobe frame): the normalised SG whose solid
/// angle `2π/s` is `c` times the sample's share `1/(N·pdf)` of the morph's lobe
/// `(e + 1)/(2π)·cosᵉθ`, rounded to an integer in `[1, 4096]`.
pub fn footprints(xs: &[[f64; 3]], morph_exponent: f64, c: f64) -> Vec<f64> {
    let n = xs.len() as f64;
    let e = morph_exponent;
    xs.iter()
        .map(|x| {
            let pdf = (e + 1.0) / (2.0 * PI) * x[2].max(0.0).powf(e);
            (2.0 * PI * n * pdf / c).round().clamp(1.0, 4096.0)
        })
        .collect()
}

impl Design {
    /// The kernel matrix `Kᵢⱼ = Σ_l κ_l ρ_l(sᵢ)ρ_l(sⱼ)(2l + 1)/(4π)·P_l(xᵢ·xⱼ)` for length `l`
    /// (no nugget), row-major.
    pub fn kernel_matrix(&self, l: f64) -> Vec<f64> {
        let lmax = self.lmax;
        let kappa = sg_coefficients(2.0 / (l * l), lmax + 1);
        let n = self.len();
        let mut q = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..=i {
                let t = dot(self.xs[i], self.xs[j]);
                let ri = &self.rho[i * (lmax + 1)..][..lmax + 1];
                let rj = &self.rho[j * (lmax + 1)..][..lmax + 1];
                let a: Vec<f64> = (0..=lmax).map(|l| kappa[l] * ri[l] * rj[l]).collect();
                let sum = legendre_series(&a, t);
                q[i * n + j] = sum;
                q[j * n + i] = sum;
            }
        }
        q
    }
}

/// The file in `tables/` that says what to bake.
pub const CONFIG_FILE: &str = "tables/footprint_renderer.txt";

/// The most models a family may have (the library's bound).
pub const MAX_MODELS: usize = 64;

/// Gauss–Legendre nodes per piece of [`Integrand::coefficients`] in the bake.
pub const P_NODES: usize = 160;

/// The error bar's family of models and contrasts, shared by every set of a config.
#[derive(Clone, Debug, PartialEq)]
pub struct Family {
    /// Kernel lengths `l`.
    pub lengths: Vec<f64>,
    /// Nuggets `σ′`.
    pub nuggets: Vec<f64>,
    /// Contrasts `k` (at most `N − 1`).
    pub contrasts: usize,
}

/// One set to bake: `set = BRDF N c l sigma calibration [feature=NAME]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Spec {
    /// Samples.
    pub n: usize,
    /// Phong exponent, or 0 for irradiance.
    pub e: u32,
    /// Footprint solid angle in samples' shares.
    pub c: f64,
    /// The weights' kernel length.
    pub l: f64,
    /// The weights' nugget.
    pub sigma: f64,
    /// The factor on the error bar's standard deviation.
    pub calibration: f64,
    /// The cargo feature the set is compiled under (`None`: always).
    pub feature: Option<String>,
}

impl Spec {
    /// The `#[cfg(…)]` line (with `indent` and a newline) of a set behind a feature, else "".
    fn cfg(&self, indent: &str) -> String {
        match &self.feature {
            Some(f) => format!("{indent}#[cfg(feature = \"{f}\")]\n"),
            None => String::new(),
        }
    }

    /// The exponent the set is morphed with (1, the cosine, for irradiance).
    pub fn morph(&self) -> u32 {
        if self.e == 0 {
            1
        } else {
            self.e
        }
    }

    /// `diffuse` or `phongE`.
    pub fn brdf_name(&self) -> String {
        if self.e == 0 {
            "diffuse".into()
        } else {
            format!("phong{}", self.e)
        }
    }
}

/// Parses the config: `family_l = l…`, `family_sigma = σ′…`, `contrasts = k` and one
/// `set = BRDF N c l sigma calibration [feature=NAME]` per set (`BRDF`: `diffuse` or
/// `phongE`; `NAME`: a cargo feature of the crate the set is compiled under).
pub fn parse(text: &str) -> Result<(Family, Vec<Spec>), String> {
    let mut family = Family { lengths: Vec::new(), nuggets: Vec::new(), contrasts: 0 };
    let mut specs: Vec<Spec> = Vec::new();
    for (no, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let at = |m: String| format!("line {}: {m}", no + 1);
        let (key, value) =
            line.split_once('=').ok_or_else(|| at("expected `key = values`".into()))?;
        let f: Vec<&str> = value.split_whitespace().collect();
        let positive = |s: &str, what: &str| -> Result<f64, String> {
            let x: f64 = s.parse().map_err(|e| at(format!("{what}: {e}")))?;
            if x.is_finite() && x > 0.0 {
                Ok(x)
            } else {
                Err(at(format!("{what} = {x} must be finite and positive")))
            }
        };
        match key.trim() {
            "family_l" => {
                family.lengths = f.iter().map(|s| positive(s, "l")).collect::<Result<_, _>>()?;
            }
            "family_sigma" => {
                family.nuggets =
                    f.iter().map(|s| positive(s, "sigma")).collect::<Result<_, _>>()?;
            }
            "contrasts" => {
                let k: usize = value.trim().parse().map_err(|e| at(format!("contrasts: {e}")))?;
                if k == 0 {
                    return Err(at("contrasts must be at least 1".into()));
                }
                family.contrasts = k;
            }
            "set" => {
                if f.len() != 6 && f.len() != 7 {
                    return Err(at(
                        "expected `set = BRDF N c l sigma calibration [feature=NAME]`".into()
                    ));
                }
                let feature = match f.get(6) {
                    None => None,
                    Some(x) => {
                        let name = x
                            .strip_prefix("feature=")
                            .filter(|n| {
                                !n.is_empty()
                                    && n.chars()
                                        .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
                            })
                            .ok_or_else(|| at(format!("`{x}`: expected feature=NAME")))?;
                        Some(name.to_string())
                    }
                };
                let e = match f[0] {
                    "diffuse" => 0,
                    b => b
                        .strip_prefix("phong")
                        .and_then(|e| e.parse::<u32>().ok())
                        .filter(|&e| (1..=4096).contains(&e))
                        .ok_or_else(|| {
                            at(format!("BRDF `{b}`: expected diffuse or phongE (E in 1..=4096)"))
                        })?,
                };
                let n: usize = f[1].parse().map_err(|x| at(format!("N: {x}")))?;
                if !(2..=super::glossy::MAX_N).contains(&n) {
                    return Err(at(format!("N = {n} must be in 2..={}", super::glossy::MAX_N)));
                }
                if specs.iter().any(|s| s.n == n && s.e == e) {
                    return Err(at(format!("{} N = {n} is baked twice", f[0])));
                }
                specs.push(Spec {
                    n,
                    e,
                    c: positive(f[2], "c")?,
                    l: positive(f[3], "l")?,
                    sigma: positive(f[4], "sigma")?,
                    calibration: positive(f[5], "calibration")?,
                    feature,
                });
            }
            other => return Err(at(format!("unknown key `{other}`"))),
        }
    }
    if family.lengths.is_empty() || family.nuggets.is_empty() || family.contrasts == 0 {
        return Err("the config needs `family_l`, `family_sigma` and `contrasts` lines".into());
    }
    if family.lengths.len() * family.nuggets.len() > MAX_MODELS {
        return Err(format!("at most {MAX_MODELS} models (family_l × family_sigma)"));
    }
    Ok((family, specs))
}

/// The baked tables of one set.
#[derive(Clone, Debug)]
pub struct Baked {
    /// What was baked.
    pub spec: Spec,
    /// θₙ nodes: 1 for irradiance, [`super::glossy::GRID`] for Phong.
    pub nodes: usize,
    /// Footprint sharpness per sample.
    pub sharpness: Vec<u32>,
    /// Weights, node-major.
    pub weights: Vec<f64>,
    /// Per node, `a_l = Σ κ_l·R_l` per family length (node-major): the unit error variance
    /// of the weights without the nugget.
    pub residual: Vec<f64>,
    /// Per node, `|w|²`.
    pub weight_norm: Vec<f64>,
    /// Contrasts, row-major `N×k`.
    pub contrasts: Vec<f64>,
    /// Per family length, the eigenvectors of `AᵀK_lA` (row-major `k×k`, columns) …
    pub eigenvectors: Vec<f64>,
    /// … and its eigenvalues (`k` per length, clamped at 0).
    pub eigenvalues: Vec<f64>,
    /// Per (length, nugget), `Σᵢ ln(λᵢ + σ′²)`.
    pub log_det: Vec<f64>,
    /// Per interval of θₙ (Phong), the interpolated weights' error at its midpoint: the mass
    /// error `|Σ δw|` and the norm `|δw|₂` (interval-major); empty for irradiance.
    pub interpolation: Vec<f64>,
    /// The contrasts' count `k`.
    pub k: usize,
}

/// Bakes one set.
pub fn bake(spec: &Spec, family: &Family) -> Result<Baked, String> {
    let what = || format!("{} N = {}", spec.brdf_name(), spec.n);
    let n = spec.n;
    let morph = spec.morph();
    let xs = lobe_set(n, morph);
    let sharp = footprints(&xs, f64::from(morph), spec.c);
    let lmax = family
        .lengths
        .iter()
        .chain([&spec.l])
        .map(|&l| degree_cut(2.0 / (l * l)))
        .max()
        .unwrap_or(40);
    let design = Design::new(xs, sharp.clone(), lmax);
    let own = Model::new(&design, spec.l, spec.sigma)
        .ok_or_else(|| format!("{}: Q is not positive definite", what()))?;
    let kappas: Vec<Vec<f64>> =
        family.lengths.iter().map(|&l| sg_coefficients(2.0 / (l * l), lmax + 1)).collect();
    let nodes = if spec.e == 0 { 1 } else { super::glossy::GRID };
    let mut weights = Vec::with_capacity(nodes * n);
    let mut residual = Vec::with_capacity(nodes * family.lengths.len());
    let mut weight_norm = Vec::with_capacity(nodes);
    for k in 0..nodes {
        let p = if spec.e == 0 {
            Integrand::irradiance()
        } else {
            Integrand::phong(f64::from(spec.e), super::glossy::grid_angle(k))
        };
        let coef = p.coefficients(lmax, P_NODES);
        let w = own.weights(&design, &coef);
        let r = design.residual_power(&coef, &w);
        for kappa in &kappas {
            residual.push(r.iter().zip(kappa).map(|(r, k)| r * k).sum());
        }
        weight_norm.push(w.iter().map(|w| w * w).sum());
        weights.extend(w);
    }
    // The interpolation's error at each interval's midpoint (Phong): the mass error
    // |Σ(wᵢₙₜ − w)| and the norm |wᵢₙₜ − w|₂ of the weights the library interpolates with
    // sin(θₖ₊₁ − θ) and sin(θ − θₖ).
    let mut interpolation = Vec::new();
    if nodes > 1 {
        for k in 0..nodes - 1 {
            let (t0, t1) = (super::glossy::grid_angle(k), super::glossy::grid_angle(k + 1));
            let t = 0.5 * (t0 + t1);
            let coef = Integrand::phong(f64::from(spec.e), t).coefficients(lmax, P_NODES);
            let exact = own.weights(&design, &coef);
            let d = (t1 - t0).sin();
            let (alpha, beta) = ((t1 - t).sin() / d, (t - t0).sin() / d);
            let (mut mass, mut l1) = (0.0, 0.0);
            for j in 0..n {
                let w = alpha * weights[k * n + j] + beta * weights[(k + 1) * n + j];
                mass += w - exact[j];
                l1 += (w - exact[j]).powi(2);
            }
            interpolation.push(mass.abs());
            interpolation.push(l1.sqrt());
        }
    }
    let c = Contrasts::new(&own, family.contrasts.min(n - 1));
    let k = c.k;
    let mut eigenvectors = Vec::new();
    let mut eigenvalues = Vec::new();
    let mut log_det = Vec::new();
    for &l in &family.lengths {
        let kl = design.kernel_matrix(l);
        // M = AᵀKA.
        let mut ka = vec![0.0; n * k];
        for i in 0..n {
            for j in 0..k {
                ka[i * k + j] = (0..n).map(|r| kl[i * n + r] * c.a[r * k + j]).sum();
            }
        }
        let mut m = vec![0.0; k * k];
        for i in 0..k {
            for j in 0..k {
                m[i * k + j] = (0..n).map(|r| c.a[r * k + i] * ka[r * k + j]).sum();
            }
        }
        let (values, vectors) = symmetric_eigen(&m, k);
        let values: Vec<f64> = values.iter().map(|v| v.max(0.0)).collect();
        for &s in &family.nuggets {
            log_det.push(values.iter().map(|v| (v + s * s).ln()).sum());
        }
        eigenvectors.extend(vectors);
        eigenvalues.extend(values);
    }
    let sharpness = sharp.iter().map(|&s| s as u32).collect();
    let baked = Baked {
        spec: spec.clone(),
        nodes,
        sharpness,
        weights,
        residual,
        weight_norm,
        contrasts: c.a,
        eigenvectors,
        eigenvalues,
        log_det,
        interpolation,
        k,
    };
    let finite = |x: &f64| (*x as f32).is_finite();
    let all = [
        &baked.weights,
        &baked.residual,
        &baked.weight_norm,
        &baked.contrasts,
        &baked.eigenvectors,
        &baked.eigenvalues,
        &baked.log_det,
        &baked.interpolation,
    ];
    if all.iter().all(|v| v.iter().all(finite)) {
        Ok(baked)
    } else {
        Err(format!("{}: a baked table is not finite", what()))
    }
}

/// Bakes every set of a config.
pub fn bake_all(family: &Family, specs: &[Spec]) -> Result<Vec<Baked>, String> {
    specs.iter().map(|s| bake(s, family)).collect()
}

fn words(s: &mut String, name: &str, values: &[f64]) {
    let _ = writeln!(s, "static {name}: [u32; {}] = [", values.len());
    for row in values.chunks(8) {
        let items: Vec<String> =
            row.iter().map(|&x| format!("0x{:08x}", (x as f32).to_bits())).collect();
        let _ = writeln!(s, "    {},", items.join(", "));
    }
    s.push_str("];\n");
}

/// The Rust source that `build.rs` writes to `$OUT_DIR/footprint_tables.rs`.
pub fn render(family: &Family, sets: &[Baked]) -> String {
    let mut out = String::new();
    out.push_str("// @generated by build.rs; do not edit\n");
    let _ = writeln!(out, "// From gen/fp.rs and {CONFIG_FILE}.");
    let pairs: Vec<String> = sets
        .iter()
        .map(|b| format!("{}    ({}, {}),\n", b.spec.cfg("    "), b.spec.n, b.spec.e))
        .collect();
    let _ = writeln!(
        out,
        "\n/// The baked (N, e) pairs of the footprint renderer (e = 0: irradiance), those behind a \
         feature when it is on."
    );
    let _ = writeln!(
        out,
        "pub(crate) const FOOTPRINT_SETS: &[(usize, u32)] = &[\n{}];",
        pairs.concat()
    );
    // The compile error of an unbaked pair: every set, those behind a feature saying so.
    let mut brdfs: Vec<u32> = sets.iter().map(|b| b.spec.e).collect();
    brdfs.sort_unstable();
    brdfs.dedup();
    let per_brdf: Vec<String> = brdfs
        .iter()
        .map(|&e| {
            let name = if e == 0 { "Diffuse".to_string() } else { format!("Phong<{e}>") };
            let sizes: Vec<String> = sets
                .iter()
                .filter(|b| b.spec.e == e)
                .map(|b| match &b.spec.feature {
                    Some(f) => format!("{} (feature `{f}`)", b.spec.n),
                    None => b.spec.n.to_string(),
                })
                .collect();
            format!("{name} at N = {}", sizes.join(", "))
        })
        .collect();
    let list = if per_brdf.is_empty() { "none".to_string() } else { per_brdf.join("; ") };
    let _ = writeln!(
        out,
        "\n/// The compile error of an unbaked (N, BRDF), listing the baked sets.\n\
         macro_rules! footprint_size_diagnostic {{\n    ($item:item) => {{\n        \
         #[diagnostic::on_unimplemented(\n            \
         message = \"no footprint renderer tables are baked for `{{Self}}` and `{{B}}`\",\n            \
         label = \"this sample count and BRDF have no baked tables\",\n            \
         note = \"the baked sets are {list} (the `set` lines of {CONFIG_FILE})\"\n        \
         )]\n        $item\n    }};\n}}"
    );
    let _ = writeln!(out, "\n/// The error bar family's nuggets σ′².");
    let nuggets: Vec<f64> = family.nuggets.iter().map(|s| s * s).collect();
    let mut nugget_words = String::new();
    words(&mut nugget_words, "FOOTPRINT_NUGGETS", &nuggets);
    out.push_str(
        &nugget_words.replace("static FOOTPRINT_NUGGETS", "pub(crate) static FOOTPRINT_NUGGETS"),
    );
    for b in sets {
        let mut s = String::new();
        let (n, e) = (b.spec.n, b.spec.e);
        let tag = format!("FOOTPRINT_{n}_{e}");
        let _ = writeln!(
            s,
            "\n/// {} N = {n}: c = {:?}, l = {:?}, σ′ = {:?}, calibration {:?}, {} θₙ nodes, k = {}.",
            b.spec.brdf_name(),
            b.spec.c,
            b.spec.l,
            b.spec.sigma,
            b.spec.calibration,
            b.nodes,
            b.k
        );
        words(&mut s, &format!("{tag}_W"), &b.weights);
        words(&mut s, &format!("{tag}_A"), &b.residual);
        words(&mut s, &format!("{tag}_B"), &b.weight_norm);
        words(&mut s, &format!("{tag}_C"), &b.contrasts);
        words(&mut s, &format!("{tag}_V"), &b.eigenvectors);
        words(&mut s, &format!("{tag}_L"), &b.eigenvalues);
        words(&mut s, &format!("{tag}_D"), &b.log_det);
        words(&mut s, &format!("{tag}_I"), &b.interpolation);
        let sharp: Vec<String> = b.sharpness.iter().map(|x| x.to_string()).collect();
        let _ = writeln!(s, "static {tag}_S: [u16; {n}] = [{}];", sharp.join(", "));
        let marker = if e == 0 { "Diffuse".to_string() } else { format!("Phong<{e}>") };
        let _ = writeln!(
            s,
            "impl crate::bmc::footprint::sealed::Sealed<crate::bmc::footprint::{marker}> for crate::bmc::Size<{n}> {{\n    \
             const SET: crate::bmc::footprint::sealed::Set = crate::bmc::footprint::sealed::Set {{\n        \
             nodes: {},\n        k: {},\n        lengths: {},\n        weights: &{tag}_W,\n        residual: &{tag}_A,\n        \
             weight_norm: &{tag}_B,\n        contrasts: &{tag}_C,\n        eigenvectors: &{tag}_V,\n        eigenvalues: &{tag}_L,\n        \
             log_det: &{tag}_D,\n        interpolation: &{tag}_I,\n        sharpness: &{tag}_S,\n        calibration: f32::from_bits(0x{:08x}),\n    }};\n}}",
            b.nodes,
            b.k,
            family.lengths.len(),
            (b.spec.calibration as f32).to_bits()
        );
        let _ = writeln!(
            s,
            "impl crate::bmc::FootprintSize<crate::bmc::footprint::{marker}> for crate::bmc::Size<{n}> {{}}"
        );
        // Every item of a set behind a feature under its `#[cfg]`.
        let cfg = b.spec.cfg("");
        for line in s.lines() {
            if line.starts_with("static ") || line.starts_with("impl ") {
                out.push_str(&cfg);
            }
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}
