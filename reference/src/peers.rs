//! The estimators a user would pick instead of this crate's QMC-SF, in plain f64: Monte Carlo
//! with independent random directions, and Owen-scrambled Sobol (0,2) points
//! (`sobol_burley`), both mapped onto the lobe `cosᵉ θ` about an axis by the same morph
//! `cos θ′ = u₁^(1/(e+1))`, `φ = 2π·u₂`.
//!
//! Both return the lobe-weighted mean `E[f(ω)]` under the density `(e+1)/(2π)·cosᵉ θ`:
//! multiply by π (with `e = 1`) for irradiance; it is the normalised Phong integral as is.

use std::f64::consts::TAU;

use crate::rng::Rng;
use crate::vec::frame;

/// The direction of lobe `cosᵉ θ` about unit `axis` for the point `(u₁, u₂)` of the unit
/// square.
#[must_use]
pub fn lobe_direction(axis: [f64; 3], e: f64, u1: f64, u2: f64) -> [f64; 3] {
    let c = u1.powf(1.0 / (e + 1.0));
    let s = (1.0 - c * c).max(0.0).sqrt();
    let (sp, cp) = (TAU * u2).sin_cos();
    let (t, b) = frame(axis);
    std::array::from_fn(|k| s * cp * t[k] + s * sp * b[k] + c * axis[k])
}

/// Mean of `f` over `n` independent random directions of the lobe.
pub fn monte_carlo(
    f: impl Fn([f64; 3]) -> f64,
    axis: [f64; 3],
    e: f64,
    n: usize,
    rng: &mut Rng,
) -> f64 {
    let sum: f64 = (0..n).map(|_| f(lobe_direction(axis, e, rng.next_f64(), rng.next_f64()))).sum();
    sum / n as f64
}

/// Mean of `f` over the first `n` points of the 2-D Owen-scrambled Sobol sequence with
/// scramble seed `seed`, mapped onto the lobe.
pub fn sobol(f: impl Fn([f64; 3]) -> f64, axis: [f64; 3], e: f64, n: u32, seed: u32) -> f64 {
    let sum: f64 = (0..n)
        .map(|i| {
            let u1 = sobol_burley::sample(i, 0, seed) as f64;
            let u2 = sobol_burley::sample(i, 1, seed) as f64;
            f(lobe_direction(axis, e, u1, u2))
        })
        .sum();
    sum / n as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peers_integrate_a_linear_function() {
        // E[ω·axis] under (e+1)/(2π)·cosᵉ θ is (e+1)/(e+2).
        let axis = crate::vec::normalize([0.3, -0.4, 0.5]);
        let f = |d: [f64; 3]| crate::vec::dot(d, axis);
        for e in [0.0, 1.0, 20.0] {
            let exact = (e + 1.0) / (e + 2.0);
            let s = sobol(f, axis, e, 4096, 7);
            assert!((s - exact).abs() < 1e-3, "Sobol e = {e}: {s} vs {exact}");
            let m = monte_carlo(f, axis, e, 100_000, &mut Rng::new(3));
            // Standard deviation of cos θ is below 0.3: 5σ at 10⁵ samples is 5e-3.
            assert!((m - exact).abs() < 5e-3, "MC e = {e}: {m} vs {exact}");
        }
    }
}
