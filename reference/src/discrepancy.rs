//! The spherical cap L₂ discrepancy by direct numerical integration over caps, with no use of
//! Stolarsky's invariance principle:
//!
//! `L₂² = ∫_{S²} ∫₋₁¹ (F(ω, t) − (1 − t)/2)² dt dσ(ω)`,
//! `F(ω, t) = #{j : ωⱼ·ω ≥ t}/N`, σ the normalised surface measure, `(1 − t)/2` the
//! normalised area of the cap `{x : x·ω ≥ t}`.
//!
//! For a fixed centre ω the count is a step function of t that changes only at the sorted
//! heights `hⱼ = ωⱼ·ω`; between two heights the integrand is the square of a linear function
//! `g(t) = c − 1/2 + t/2`, integrated exactly as `(2/3)(g(b)³ − g(a)³)`. The outer integral
//! over centres uses a product rule (Gauss–Legendre in `z = cos θ`, equal steps in φ). The
//! profile is continuous but has kinks where two heights cross, so that rule converges
//! algebraically, not spectrally; callers check convergence by refining it.

use std::f64::consts::PI;

use crate::quad::gauss_legendre;
use crate::vec::dot;

/// `∫₋₁¹ (F(ω, t) − (1 − t)/2)² dt` for the cap centre `centre` (unit), exactly.
pub fn cap_profile(points: &[[f64; 3]], centre: [f64; 3]) -> f64 {
    let mut h: Vec<f64> = points.iter().map(|&p| dot(p, centre).clamp(-1.0, 1.0)).collect();
    h.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let n = h.len() as f64;
    let piece = |count: usize, a: f64, b: f64| {
        let c = count as f64 / n - 0.5;
        let (ga, gb) = (c + 0.5 * a, c + 0.5 * b);
        (2.0 / 3.0) * (gb * gb * gb - ga * ga * ga)
    };
    // On [−1, h₀) every point has height ≥ t; on [h_i, h_{i+1}) the N − 1 − i highest do.
    let mut total = piece(h.len(), -1.0, h[0]);
    for i in 0..h.len() {
        let b = if i + 1 < h.len() { h[i + 1] } else { 1.0 };
        total += piece(h.len() - 1 - i, h[i], b);
    }
    total
}

/// Centres and σ-weights (summing to 1) of the product rule with `n_z` Gauss–Legendre heights
/// and `n_phi` equally spaced azimuths (offset by half a step).
pub fn product_rule(n_z: usize, n_phi: usize) -> (Vec<[f64; 3]>, Vec<f64>) {
    let (zs, wz) = gauss_legendre(n_z);
    let mut centres = Vec::with_capacity(n_z * n_phi);
    let mut weights = Vec::with_capacity(n_z * n_phi);
    for (&z, &w) in zs.iter().zip(&wz) {
        let s = ((1.0 - z) * (1.0 + z)).sqrt();
        for j in 0..n_phi {
            let phi = 2.0 * PI * (j as f64 + 0.5) / n_phi as f64;
            centres.push([s * phi.cos(), s * phi.sin(), z]);
            weights.push(0.5 * w / n_phi as f64);
        }
    }
    (centres, weights)
}

/// The cap L₂ discrepancy `(Σᵢ wᵢ · cap_profile(points, centreᵢ))^½` over a rule of centres.
pub fn cap_l2_discrepancy(points: &[[f64; 3]], centres: &[[f64; 3]], weights: &[f64]) -> f64 {
    assert_eq!(centres.len(), weights.len());
    let sum: f64 = centres.iter().zip(weights).map(|(&c, &w)| w * cap_profile(points, c)).sum();
    sum.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_point_profile_is_the_closed_form() {
        // N = 1 at height h: ∫_{−1}^{h} ((1+t)/2)² dt + ∫_h^1 ((1−t)/2)² dt = (1 + 3h²)/6.
        let p = [0.0, 0.0, 1.0];
        for i in 0..=40 {
            let h = -1.0 + 0.05 * i as f64;
            let s = ((1.0 - h) * (1.0 + h)).sqrt();
            let got = cap_profile(&[p], [s, 0.0, h]);
            assert!((got - (1.0 + 3.0 * h * h) / 6.0).abs() < 1e-15, "h = {h}");
        }
        // Its mean over the sphere (h uniform on [−1, 1]) is 1/3; the rule integrates the
        // quadratic exactly.
        let (c, w) = product_rule(4, 3);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        let d = cap_l2_discrepancy(&[p], &c, &w);
        assert!((d * d - 1.0 / 3.0).abs() < 1e-15);
    }

    #[test]
    fn antipodal_pair_profile() {
        // Points ±e_z, centre at height h ≥ 0: F = 1 on [−1, −h), 1/2 on [−h, h), 0 after.
        let pts = [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
        let h: f64 = 0.3;
        let s = (1.0 - h * h).sqrt();
        let got = cap_profile(&pts, [s, 0.0, h]);
        // ∫_{−1}^{−h} ((1+t)/2)² + ∫_{−h}^{h} (t/2)² + ∫_h^1 ((1−t)/2)².
        let want = (1.0 - h).powi(3) / 12.0 + h.powi(3) / 6.0 + (1.0 - h).powi(3) / 12.0;
        assert!((got - want).abs() < 1e-15, "{got} vs {want}");
    }
}
