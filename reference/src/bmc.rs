//! Bayesian Monte Carlo irradiance weights, independently of the crate's generator.
//!
//! The same model as `sphere_quadrature::bmc` (kernel `exp(−|x − x′|²/l²) + σ′²δ`, uniform
//! hemisphere spherical Fibonacci samples about `n = +z`, `p = cos θ/π`, GLS constant mean),
//! computed by different means:
//!
//! * points from [`crate::sf::hemisphere_point`] (double-double golden phase);
//! * `zᵢ = E(n)/π` of an SG light of axis `xᵢ`, sharpness `λ = 2/l²` and amplitude 1, by
//!   [`crate::analytic::SgLight::irradiance`] (I₀ₑ and adaptive Gauss–Kronrod);
//! * `V̄ = ∫ p(x)·zₓ dx = 2∫₀¹ t·z(t) dt` by 12 × 20-point Gauss–Legendre of the same;
//! * solves by Gaussian elimination with partial pivoting (LU), no refinement.

use crate::analytic::SgLight;
use crate::quad::gauss_legendre_on;
use crate::sf::hemisphere_point;
use std::f64::consts::PI;

/// The reference weights and posterior variance of one set.
#[derive(Clone, Debug)]
pub struct Weights {
    /// `w` with `E ≈ π·Σ wᵢ L(xᵢ)`.
    pub w: Vec<f64>,
    /// Posterior variance of `E` for σ_f = 1.
    pub variance: f64,
    /// `zᵢ = ∫ k(xᵢ, x)·cos θ/π dx`.
    pub z: Vec<f64>,
}

/// `∫ exp(λ(μ·x − 1))·cos θ/π dx` over the hemisphere of `+z` for `μ·z = t`.
pub fn kernel_mean(lambda: f64, t: f64) -> f64 {
    let s = (1.0 - t * t).max(0.0).sqrt();
    SgLight { axis: [s, 0.0, t], sharpness: lambda, amplitude: 1.0 }.irradiance([0.0, 0.0, 1.0])
        / PI
}

/// `V̄ = ∫∫ k p p` (without the nugget).
pub fn kernel_mean_mean(lambda: f64) -> f64 {
    let mut sum = 0.0;
    for p in 0..12 {
        let (ts, ws) = gauss_legendre_on(20, p as f64 / 12.0, (p + 1) as f64 / 12.0);
        for (t, w) in ts.iter().zip(&ws) {
            sum += w * t * kernel_mean(lambda, *t);
        }
    }
    2.0 * sum
}

/// Solves `a·x = b` (row-major `n × n`) by LU with partial pivoting.
pub fn lu_solve(a: &[f64], n: usize, b: &[f64]) -> Vec<f64> {
    Lu::new(a, n).solve(b)
}

/// The LU factorisation with partial pivoting of a row-major `n × n` matrix, `P·a = L·U`: one
/// factorisation for many right-hand sides and the determinant.
#[derive(Clone, Debug)]
pub struct Lu {
    n: usize,
    /// `U` on and above the diagonal, `L`'s multipliers below (its unit diagonal implied).
    m: Vec<f64>,
    /// Row `i` of `P·a` is row `perm[i]` of `a`.
    perm: Vec<usize>,
}

impl Lu {
    /// Factors `a` (Gaussian elimination, the largest remaining pivot of each column).
    pub fn new(a: &[f64], n: usize) -> Lu {
        assert_eq!(a.len(), n * n, "a is not n × n");
        let mut m = a.to_vec();
        let mut perm: Vec<usize> = (0..n).collect();
        for c in 0..n {
            let p =
                (c..n).max_by(|&i, &j| m[i * n + c].abs().total_cmp(&m[j * n + c].abs())).unwrap();
            if p != c {
                for k in 0..n {
                    m.swap(c * n + k, p * n + k);
                }
                perm.swap(c, p);
            }
            let piv = m[c * n + c];
            for r in c + 1..n {
                let f = m[r * n + c] / piv;
                m[r * n + c] = f;
                if f != 0.0 {
                    for k in c + 1..n {
                        m[r * n + k] -= f * m[c * n + k];
                    }
                }
            }
        }
        Lu { n, m, perm }
    }

    /// `x` with `a·x = b`.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.n;
        assert_eq!(b.len(), n, "b has not n entries");
        let mut x: Vec<f64> = self.perm.iter().map(|&i| b[i]).collect();
        for r in 0..n {
            let s: f64 = (0..r).map(|k| self.m[r * n + k] * x[k]).sum();
            x[r] -= s;
        }
        for r in (0..n).rev() {
            let s: f64 = (r + 1..n).map(|k| self.m[r * n + k] * x[k]).sum();
            x[r] = (x[r] - s) / self.m[r * n + r];
        }
        x
    }

    /// `log |det a|`: the sum of the logarithms of the pivots' magnitudes.
    pub fn log_abs_det(&self) -> f64 {
        (0..self.n).map(|i| self.m[i * self.n + i].abs().ln()).sum()
    }
}

/// BMC irradiance weights for `n` samples of the uniform hemisphere set, length scale `l` and
/// noise ratio `sigma`.
pub fn weights(n: usize, l: f64, sigma: f64) -> Weights {
    weights_on(n, l, sigma, false)
}

/// [`weights`] on the uniform set, or on the cosine-morphed one (`cosine`): the reference
/// point of height `u` moved to height `√u` along its meridian.
pub fn weights_on(n: usize, l: f64, sigma: f64, cosine: bool) -> Weights {
    let lambda = 2.0 / (l * l);
    let xs: Vec<[f64; 3]> = (0..n as u64)
        .map(|j| {
            let p = hemisphere_point(j, n as u64);
            if !cosine {
                return p;
            }
            let (u, h) = (p[2], (p[0] * p[0] + p[1] * p[1]).sqrt());
            let s = (1.0 - u).sqrt();
            [p[0] / h * s, p[1] / h * s, u.sqrt()]
        })
        .collect();
    let mut q = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            let c = crate::vec::dot(xs[i], xs[j]);
            q[i * n + j] = (lambda * (c - 1.0)).exp() + if i == j { sigma * sigma } else { 0.0 };
        }
    }
    let z: Vec<f64> = xs.iter().map(|x| kernel_mean(lambda, x[2])).collect();
    let a = lu_solve(&q, n, &z);
    let b = lu_solve(&q, n, &vec![1.0; n]);
    let (sa, sb): (f64, f64) = (a.iter().sum(), b.iter().sum());
    let w: Vec<f64> = a.iter().zip(&b).map(|(a, b)| a + (1.0 - sa) / sb * b).collect();
    let za: f64 = z.iter().zip(&a).map(|(z, a)| z * a).sum();
    let v = kernel_mean_mean(lambda) - za + (1.0 - sa).powi(2) / sb;
    Weights { w, variance: PI * PI * v, z }
}
