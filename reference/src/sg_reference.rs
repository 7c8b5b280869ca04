//! Ground truth for the hemispherical integrals of a spherical Gaussian (SG), by adaptive
//! quadrature of the defining integral.
//!
//! For a unit SG G(v) = exp(λ(μ·v − 1)) and a normal n with t = μ·n = cos θa, integrating the
//! azimuth about n first (∫₀^{2π} e^{κ cos φ} dφ = 2π I₀(κ)) leaves, in the polar angle θ
//! from n, with λ(cos θa cos θ + sin θa sin θ − 1) = −2λ sin²((θ − θa)/2):
//!
//! - H(λ, t) = 2π ∫₀^{π/2} sin θ · e^{−2λ sin²((θ−θa)/2)} · I0e(λ sin θa sin θ) dθ,
//! - C(λ, t) = 2π ∫₀^{π/2} cos θ sin θ · e^{−2λ sin²((θ−θa)/2)} · I0e(λ sin θa sin θ) dθ,
//!
//! evaluated by globally adaptive Gauss–Kronrod (7, 15) split at θa and θa ± {1, 3, 6, 10}/√λ
//! (≈1e-13 absolute on the normalised values). The library's generator uses a different
//! reduction (elementary azimuthal measures, no Bessel function), so the two are independent.

use crate::quad::integrate_with_breaks;
use crate::special::bessel_i0e;
use std::f64::consts::PI;

/// F(λ) = ∫_{S²} exp(λ(μ·v − 1)) dv = 2π(1 − e^{−2λ})/λ (4π at λ = 0).
pub fn full_integral(lambda: f64) -> f64 {
    if lambda == 0.0 {
        4.0 * PI
    } else {
        -2.0 * PI * (-2.0 * lambda).exp_m1() / lambda
    }
}

/// Langevin function L(λ) = coth λ − 1/λ: the mean of μ·v under the normalised SG.
pub fn langevin(lambda: f64) -> f64 {
    if lambda < 1e-2 {
        let l2 = lambda * lambda;
        lambda * (1.0 / 3.0 - l2 * (1.0 / 45.0 - l2 * 2.0 / 945.0))
    } else {
        1.0 / lambda.tanh() - 1.0 / lambda
    }
}

fn hemi_integral(lambda: f64, t: f64, weight: impl Fn(f64) -> f64) -> f64 {
    let t = t.clamp(-1.0, 1.0);
    let ta = t.acos();
    let sa = ta.sin();
    let mut breaks = vec![ta];
    if lambda > 0.0 {
        let w = 1.0 / lambda.sqrt();
        for k in [1.0, 3.0, 6.0, 10.0] {
            breaks.push(ta - k * w);
            breaks.push(ta + k * w);
        }
    }
    // Normalised by F(λ) inside, so that the tolerances are on the O(1) ratio.
    let scale = 2.0 * PI / full_integral(lambda);
    integrate_with_breaks(
        |th| {
            let (st, _) = th.sin_cos();
            let h = (0.5 * (th - ta)).sin();
            weight(th) * st * (-2.0 * lambda * h * h).exp() * bessel_i0e(lambda * sa * st) * scale
        },
        0.0,
        0.5 * PI,
        &breaks,
        1e-14,
        1e-13,
    )
    .value
}

/// H(λ, t)/F(λ): the fraction of a unit SG's integral over the hemisphere of a normal at
/// cosine t from its axis.
pub fn hemi_fraction(lambda: f64, t: f64) -> f64 {
    hemi_integral(lambda, t, |_| 1.0)
}

/// C(λ, t)/F(λ): the clamped-cosine integral ∫ G·max(0, n·v) of a unit SG over F(λ).
pub fn clamped_fraction(lambda: f64, t: f64) -> f64 {
    hemi_integral(lambda, t, f64::cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_cases() {
        for l in [0.0f64, 1e-3, 0.5, 3.0, 40.0, 1e4] {
            let e = (-l).exp();
            // Axis at the pole and at the nadir: H = 2π(1 − e^{−λ})/λ and e^{−λ} times that.
            assert!((hemi_fraction(l, 1.0) - 1.0 / (1.0 + e)).abs() < 1e-13, "{l}");
            assert!((hemi_fraction(l, -1.0) - e / (1.0 + e)).abs() < 1e-13, "{l}");
            // On the horizon, by symmetry, half.
            assert!((hemi_fraction(l, 0.0) - 0.5).abs() < 1e-13, "{l}");
            // C(t) − C(−t) = t·F·L(λ).
            for &t in &[0.2, 0.7, 0.99] {
                let d = clamped_fraction(l, t) - clamped_fraction(l, -t);
                assert!((d - t * langevin(l)).abs() < 1e-12, "{l} {t}");
            }
        }
        assert!((clamped_fraction(0.0, 0.3) - 0.25).abs() < 1e-14);
    }

    #[test]
    fn matches_the_sg_light_irradiance() {
        use crate::analytic::SgLight;
        for &l in &[0.1, 2.0, 30.0, 700.0] {
            for &t in &[-0.6, -0.01, 0.0, 0.3, 0.95] {
                let w = (1.0f64 - t * t).sqrt();
                let light = SgLight { axis: [w, 0.0, t], sharpness: l, amplitude: 1.0 };
                let want = light.irradiance([0.0, 0.0, 1.0]) / light.integral();
                assert!((clamped_fraction(l, t) - want).abs() < 1e-12, "{l} {t}");
            }
        }
    }
}
