//! The footprint renderer's model in f64, in spherical-harmonic form (the generator's prototype;
//! plain std Rust so that it can move into `gen/`).
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

use crate::gen::probe::{bessel_ratios, sg_coefficients};
use crate::gen::sg::gauss_legendre;

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
        let mut q = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..=i {
                let t = dot(design.xs[i], design.xs[j]).clamp(-1.0, 1.0);
                let (ri, rj) = (
                    &design.rho[i * (lmax + 1)..][..lmax + 1],
                    &design.rho[j * (lmax + 1)..][..lmax + 1],
                );
                let (mut p0, mut p1) = (1.0, t);
                let mut sum = 0.0;
                for l in 0..=lmax {
                    let p = match l {
                        0 => 1.0,
                        1 => t,
                        _ => {
                            let p2 = ((2 * l - 1) as f64 * t * p1 - (l - 1) as f64 * p0) / l as f64;
                            p0 = p1;
                            p1 = p2;
                            p2
                        }
                    };
                    sum += kappa[l] * ri[l] * rj[l] * (2 * l + 1) as f64 / (4.0 * PI) * p;
                }
                q[i * n + j] = sum;
                q[j * n + i] = sum;
            }
            q[i * n + i] += sigma * sigma;
        }
        let factor = cholesky(&q, n)?;
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
        let factor = cholesky(&m, k)?;
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

/// Lower Cholesky factor of the symmetric `n×n` matrix `a` (row-major).
fn cholesky(a: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum();
            if i == j {
                let d = a[i * n + i] - s;
                if d <= 0.0 || !d.is_finite() {
                    return None;
                }
                l[i * n + i] = d.sqrt();
            } else {
                l[i * n + j] = (a[i * n + j] - s) / l[j * n + j];
            }
        }
    }
    Some(l)
}

/// The lobe-morphed hemisphere spherical Fibonacci set in the lobe frame at phase 0:
/// `cos θⱼ = uⱼ^{1/(e+1)}`, `uⱼ = 1 − (2j + 1)/(2N)`, golden azimuth (as
/// `renderer_engine::sf_set` with the identity frame).
pub fn lobe_set(n: usize, morph_exponent: f64) -> Vec<[f64; 3]> {
    (0..n as u64)
        .map(|j| {
            let (z, phi) = reference::sf::hemisphere_z_phi(j, n as u64);
            let (c, s) = crate::renderer_engine::morph(z, morph_exponent);
            [s * phi.cos(), s * phi.sin(), c]
        })
        .collect()
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::renderer_engine::{Brdf, LobeFrame, Query, Rule};

    /// The real harmonics are orthonormal (a fine product rule).
    #[test]
    fn harmonics_are_orthonormal() {
        let lmax = 12;
        let width = (lmax + 1) * (lmax + 1);
        let mut gram = vec![0.0; width * width];
        let (x, w) = gauss_legendre(40);
        let m = 80;
        for (xk, wk) in x.iter().zip(&w) {
            let s = (1.0 - xk * xk).sqrt();
            for j in 0..m {
                let phi = 2.0 * PI * j as f64 / m as f64;
                let y = sh(lmax, [s * phi.cos(), s * phi.sin(), *xk]);
                let weight = wk * 2.0 * PI / m as f64;
                for a in 0..width {
                    for b in 0..width {
                        gram[a * width + b] += weight * y[a] * y[b];
                    }
                }
            }
        }
        for a in 0..width {
            for b in 0..width {
                let want = if a == b { 1.0 } else { 0.0 };
                assert!(
                    (gram[a * width + b] - want).abs() < 1e-12,
                    "{a} {b} {}",
                    gram[a * width + b]
                );
            }
        }
    }

    /// `p_lm` against the engine's product rule, and `z` and `V̄` of point samples against
    /// its kernel means.
    #[test]
    fn coefficients_match_the_engine_rule() {
        let l = 0.6;
        let lambda = 2.0 / (l * l);
        let lmax = degree_cut(lambda);
        for (e, alpha) in [(0.0, 0.0), (10.0, 1.2), (50.0, 1.45)] {
            let p = if e == 0.0 { Integrand::irradiance() } else { Integrand::phong(e, alpha) };
            let coef = p.coefficients(lmax, 160);
            // The engine's frame: n in the (t₁, a) plane at angle α.
            let (brdf, q) = if e == 0.0 {
                (Brdf::Diffuse, Query { n: [0.0, 0.0, 1.0], r: [0.0, 0.0, 1.0] })
            } else {
                (Brdf::Phong(e), Query { n: [alpha.sin(), 0.0, alpha.cos()], r: [0.0, 0.0, 1.0] })
            };
            let frame = LobeFrame::new(brdf, &q);
            let rule = Rule::new(brdf, &frame, lambda.max(100.0), 1.0);
            let mass = (4.0 * PI).sqrt() * coef[0];
            assert!(
                (mass - rule.mass()).abs() < 1e-10 * rule.mass(),
                "{e} {alpha}: {mass} {}",
                rule.mass()
            );
            // Point samples: z.
            let xs = lobe_set(16, if e == 0.0 { 1.0 } else { e });
            let world: Vec<[f64; 3]> = xs
                .iter()
                .map(|x| {
                    frame.direction(x[2], (x[0] * x[0] + x[1] * x[1]).sqrt(), x[1].atan2(x[0]))
                })
                .collect();
            let design = Design::new(xs, vec![0.0; 16], lmax);
            let model = Model::new(&design, l, 1e-2).unwrap();
            let z = model.z(&design, &coef);
            let z_rule = rule.kernel_means(&world, lambda);
            let top = z_rule.iter().cloned().fold(0.0, f64::max);
            for (a, b) in z.iter().zip(&z_rule) {
                assert!((a - b).abs() < 1e-9 * top, "{e} {alpha}: z {a} {b}");
            }
            let vbar: f64 = (0..=lmax)
                .map(|l| {
                    model.kappa[l]
                        * (l * l..(l + 1) * (l + 1)).map(|k| coef[k] * coef[k]).sum::<f64>()
                })
                .sum();
            let vbar_rule = rule.kernel_mean_mean(lambda);
            assert!(
                (vbar - vbar_rule).abs() < 1e-8 * vbar_rule,
                "{e} {alpha}: V̄ {vbar} {vbar_rule}"
            );
        }
    }

    /// `u(w)` equals `V̄ − 2wᵀz + wᵀQw` where that does not cancel.
    #[test]
    fn unit_variance_is_the_quadratic_form() {
        let lmax = degree_cut(2.0 / 0.36);
        let p = Integrand::phong(10.0, 0.7).coefficients(lmax, 120);
        let xs = lobe_set(24, 10.0);
        let sharp = footprints(&xs, 10.0, 16.0);
        let design = Design::new(xs, sharp, lmax);
        let model = Model::new(&design, 0.6, 0.05).unwrap();
        let w: Vec<f64> = (0..24).map(|j| 0.03 + 0.001 * j as f64).collect();
        let u = model.unit_variance(&design.residual_power(&p, &w), &w);
        let z = model.z(&design, &p);
        let vbar: f64 = (0..=lmax)
            .map(|l| model.kappa[l] * (l * l..(l + 1) * (l + 1)).map(|k| p[k] * p[k]).sum::<f64>())
            .sum();
        // wᵀQw by Q = L Lᵀ.
        let n = 24;
        let lw: Vec<f64> =
            (0..n).map(|i| (i..n).map(|k| model.factor[k * n + i] * w[k]).sum()).collect();
        let wqw: f64 = lw.iter().map(|x| x * x).sum();
        let direct = vbar - 2.0 * w.iter().zip(&z).map(|(a, b)| a * b).sum::<f64>() + wqw;
        assert!((u - direct).abs() < 1e-9 * vbar, "{u} {direct}");
    }

    /// With all `N − 1` contrasts the reduced fit is REML: the same `σ̂²`, and likelihoods
    /// that differ between models by the same constant.
    #[test]
    fn all_contrasts_give_reml() {
        let lmax = degree_cut(2.0 / 0.36);
        let xs = lobe_set(12, 10.0);
        let sharp = footprints(&xs, 10.0, 16.0);
        let design = Design::new(xs, sharp, lmax);
        let a = Model::new(&design, 0.6, 1e-3).unwrap();
        let b = Model::new(&design, 1.0, 1e-2).unwrap();
        let c = Contrasts::new(&a, 11);
        let y: Vec<f64> = (0..12).map(|j| 1.0 + (j as f64 * 0.7).sin()).collect();
        let t = c.apply(&y);
        let (fa, fb) = (a.reduced(&c).unwrap().fit(&t), b.reduced(&c).unwrap().fit(&t));
        let (ra, rb) = (a.reml(&y), b.reml(&y));
        assert!((fa.0 - ra.0).abs() < 1e-9 * ra.0 && (fb.0 - rb.0).abs() < 1e-9 * rb.0);
        assert!(((fa.1 - fb.1) - (ra.1 - rb.1)).abs() < 1e-7, "{fa:?} {fb:?} {ra:?} {rb:?}");
    }
}
