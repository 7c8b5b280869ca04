//! Published closed-form approximations of the hemispherical integrals of a spherical
//! Gaussian, in f64, to compare the library's tables with.
//!
//! All return values normalised by the full-sphere integral F(λ) = 2π(1 − e^{−2λ})/λ, for a
//! unit SG of sharpness λ whose axis makes cosine t with the normal. Each is written here
//! from the mathematics of its source:
//!
//! - [`tokuyoshi2022_hemi_fraction`]: Tokuyoshi 2022, "Accurate diffuse lighting from
//!   spherical Gaussian lights" (HPG 2022 poster). H interpolates between the upper and lower
//!   hemispherical integrals 2π(1 − e^{−λ})/λ and e^{−λ} times that with the factor
//!   v = 1/2 + erf(σ(λ)·t)/(2 erf σ(λ)), σ(λ) = λ·√((λ/2 + A)/((λ + B)λ + C)), with the fitted
//!   A = 0.6517328826907056, B = 1.3418280033141288, C = 7.2216687798956709.
//! - [`meder2018_hemi_fraction`]: Meder & Brüderlin 2018, "Hemispherical Gaussians for
//!   accurate light integration" (ICCVG 2018): the same interpolation with a logistic factor
//!   v = expm1(τ + τt)/(expm1(τ)(1 + e^{τt})), τ(λ) = √λ·λ(−1.6988λ − 10.8438)/
//!   ((λ + 6.2201)λ + 10.2415). The paper itself was not accessible here: the formula and its
//!   fitted coefficients are taken from their transcription in Tokuyoshi's public reference
//!   shader code (which cites the paper and rewrites it with negative exponents).
//! - [`tokuyoshi2024_clamped_fraction`]: Tokuyoshi, Ikeda, Harada and Sakai 2024,
//!   "Hierarchical light sampling with accurate spherical Gaussian lighting" (SIGGRAPH Asia
//!   2024, supplementary listings 5–7): C interpolates between the upper and lower clamped-
//!   cosine integrals 2π(1 − (1 − e^{−λ})/λ)/λ and 2π e^{−λ}((1 − e^{−λ})/λ − e^{−λ})/λ with
//!   v = (t·erfc(−τt) + erfc τ)/2 − e^{−τ²t²}·expm1(τ²(t² − 1))/(2√π τ), with
//!   τ(λ) = λ·√(((λ + A)λ + B)/(2((λ + C)λ + D)λ + 2E)) and the fitted A…E below.
//! - [`tokuyoshi2022_clamped_fraction`]: Tokuyoshi 2022's clamped cosine, max(0, n·v) ≈
//!   α(e^{λ₀ n·v} − 1) on the upper hemisphere with λ₀ = 8.4560872241480124e-4 and
//!   α = 1182.2467339678153, so C ≈ α(H(product SG) − H(G)) with the 2022 H above.
//! - [`meder2018_clamped_fraction`]: the same construction with Meder & Brüderlin's H,
//!   λ₀ = 0.0315 and the weights 32.7080 and 31.7003 (again from Tokuyoshi's transcription).

// The fitted constants are quoted with the digits their sources publish.
#![allow(clippy::excessive_precision)]

use std::f64::consts::PI;

/// erf(x) (series for |x| < 2, continued fraction above; ≈1e-15).
pub fn erf(x: f64) -> f64 {
    if x < 0.0 {
        -erf(-x)
    } else {
        1.0 - erfc_pos(x)
    }
}

/// erfc(x) for all real x.
pub fn erfc(x: f64) -> f64 {
    if x < 0.0 {
        2.0 - erfc_pos(-x)
    } else {
        erfc_pos(x)
    }
}

fn erfc_pos(x: f64) -> f64 {
    if x < 2.0 {
        // erf x = (2/√π) e^{−x²} Σ_n 2ⁿ x^{2n+1}/(2n+1)!!
        let (mut term, mut sum, mut n) = (x, x, 0.0);
        while term > 1e-17 * sum {
            n += 1.0;
            term *= 2.0 * x * x / (2.0 * n + 1.0);
            sum += term;
        }
        1.0 - 2.0 / PI.sqrt() * (-x * x).exp() * sum
    } else {
        // erfc x = e^{−x²}/√π / (x + (1/2)/(x + 1/(x + (3/2)/(x + …))))
        let mut f = x;
        for k in (1..=80).rev() {
            f = x + 0.5 * f64::from(k) / f;
        }
        (-x * x).exp() / (PI.sqrt() * f)
    }
}

/// (1 − e^{−λ})/λ, accurate at small λ.
fn expm1_over(lambda: f64) -> f64 {
    if lambda == 0.0 {
        1.0
    } else {
        -(-lambda).exp_m1() / lambda
    }
}

/// Full-sphere integral over 2π: (1 − e^{−2λ})/λ.
fn full_over_2pi(lambda: f64) -> f64 {
    2.0 * expm1_over(2.0 * lambda)
}

/// Tokuyoshi 2022: H/(2π).
fn t22_over_2pi(lambda: f64, t: f64) -> f64 {
    const A: f64 = 0.6517328826907056;
    const B: f64 = 1.3418280033141288;
    const C: f64 = 7.2216687798956709;
    let s = lambda * ((0.5 * lambda + A) / ((lambda + B) * lambda + C)).sqrt();
    let v = if s == 0.0 { 0.5 + 0.5 * t } else { 0.5 + 0.5 * erf(s * t.clamp(-1.0, 1.0)) / erf(s) };
    let e = (-lambda).exp();
    (e + v * (1.0 - e)) * expm1_over(lambda)
}

/// Meder & Brüderlin 2018: H/(2π).
fn mb18_over_2pi(lambda: f64, t: f64) -> f64 {
    let tau = lambda.sqrt() * lambda * (-1.6988 * lambda - 10.8438)
        / ((lambda + 6.2201) * lambda + 10.2415);
    let u = tau * t.clamp(-1.0, 1.0);
    let v = if tau == 0.0 {
        0.5 + 0.5 * t
    } else {
        ((tau + u).exp_m1() / (tau.exp_m1() * (1.0 + u.exp()))).clamp(0.0, 1.0)
    };
    let e = (-lambda).exp();
    (e + v * (1.0 - e)) * expm1_over(lambda)
}

/// Tokuyoshi 2022, hemispherical integral, as H/F.
pub fn tokuyoshi2022_hemi_fraction(lambda: f64, t: f64) -> f64 {
    t22_over_2pi(lambda, t) / full_over_2pi(lambda)
}

/// Meder & Brüderlin 2018, hemispherical integral, as H/F.
pub fn meder2018_hemi_fraction(lambda: f64, t: f64) -> f64 {
    mb18_over_2pi(lambda, t) / full_over_2pi(lambda)
}

/// Tokuyoshi et al. 2024, SG × clamped cosine, as C/F.
pub fn tokuyoshi2024_clamped_fraction(lambda: f64, t: f64) -> f64 {
    const A: f64 = 2.7360831611272558;
    const B: f64 = 17.021297781741875;
    const C: f64 = 4.0100826728510421;
    const D: f64 = 15.219156263147211;
    const E: f64 = 76.087896272360737;
    let t = t.clamp(-1.0, 1.0);
    let l = lambda;
    // Upper and lower clamped-cosine integrals over 2π (Taylor series near 0 as in the source).
    if l == 0.0 {
        return 0.25;
    }
    // Upper and lower clamped-cosine integrals over 2π (Taylor series near 0 as in the source).
    let (upper, lower) = if l <= 0.5 {
        let horner = |c: &[f64]| c.iter().fold(0.0, |acc, &c| acc * l + c);
        let up = horner(&[
            -1.0 / 362880.0,
            1.0 / 40320.0,
            -1.0 / 5040.0,
            1.0 / 720.0,
            -1.0 / 120.0,
            1.0 / 24.0,
            -1.0 / 6.0,
            0.5,
        ]);
        let lo = (-l).exp()
            * horner(&[
                1.0 / 403200.0,
                -1.0 / 45360.0,
                1.0 / 5760.0,
                -1.0 / 840.0,
                1.0 / 144.0,
                -1.0 / 30.0,
                1.0 / 8.0,
                -1.0 / 3.0,
                0.5,
            ]);
        (up, lo)
    } else {
        let e = (-l).exp();
        ((1.0 - expm1_over(l)) / l, e * (expm1_over(l) - e) / l)
    };
    let tau = l * (0.5 * ((l + A) * l + B) / (((l + C) * l + D) * l + E)).sqrt();
    let tz = tau * t;
    let v = 0.5 * (t * erfc(-tz) + erfc(tau))
        - 0.5 / PI.sqrt() * (-tz * tz).exp() * (tau * tau * (t * t - 1.0)).exp_m1() / tau;
    (lower + v * (upper - lower)) / full_over_2pi(l)
}

/// The product of a unit SG (λ, axis at cosine t from n) with the SG (λ₀, n):
/// (sharpness, cosine of its axis with n, log amplitude).
fn product_with_normal_lobe(lambda: f64, t: f64, l0: f64) -> (f64, f64, f64) {
    let lm = (lambda * lambda + l0 * l0 + 2.0 * lambda * l0 * t).max(0.0).sqrt();
    let tm = if lm > 0.0 { (lambda * t + l0) / lm } else { 1.0 };
    let log_a = -lambda * l0 * 2.0 * (1.0 - t) / (lm + lambda + l0);
    (lm, tm.clamp(-1.0, 1.0), log_a)
}

/// Tokuyoshi 2022, SG × clamped cosine, as C/F.
pub fn tokuyoshi2022_clamped_fraction(lambda: f64, t: f64) -> f64 {
    const L0: f64 = 0.00084560872241480124;
    const ALPHA: f64 = 1182.2467339678153;
    let (lm, tm, log_a) = product_with_normal_lobe(lambda, t, L0);
    let i0 = t22_over_2pi(lm, tm) * (log_a + L0).exp();
    let i1 = t22_over_2pi(lambda, t);
    // C/π = 2α(i0 − i1), clamped at 0.
    PI * (2.0 * ALPHA * (i0 - i1)).max(0.0) / (2.0 * PI * full_over_2pi(lambda))
}

/// Meder & Brüderlin 2018 (as transcribed by Tokuyoshi), SG × clamped cosine, as C/F.
pub fn meder2018_clamped_fraction(lambda: f64, t: f64) -> f64 {
    const L0: f64 = 0.0315;
    let (lm, tm, log_a) = product_with_normal_lobe(lambda, t, L0);
    let i0 = 32.7080 * 2.0 * mb18_over_2pi(lm, tm) * log_a.exp();
    let i1 = 31.7003 * 2.0 * mb18_over_2pi(lambda, t);
    PI * (i0 - i1).max(0.0) / (2.0 * PI * full_over_2pi(lambda))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erf_matches_tabulated_values() {
        // erf from 30-digit tables.
        for (x, want) in [
            (0.1, 0.112_462_916_018_284_9),
            (0.5, 0.520_499_877_813_046_5),
            (1.0, 0.842_700_792_949_714_9),
            (1.9, 0.992_790_429_235_257_5),
            (2.1, 0.997_020_533_343_667_0),
            (3.0, 0.999_977_909_503_001_4),
        ] {
            assert!((erf(x) - want).abs() < 2e-15, "{x}");
            assert!((erf(-x) + want).abs() < 2e-15, "{x}");
        }
        assert!((erfc(5.0) / 1.537_459_794_428_034_8e-12 - 1.0).abs() < 1e-12);
        assert!((erfc(-1.0) - 1.842_700_792_949_714_9).abs() < 2e-15);
    }

    #[test]
    fn closed_forms_are_exact_at_the_poles_and_horizon() {
        for l in [0.7f64, 5.0, 100.0] {
            let e = (-l).exp();
            for f in [tokuyoshi2022_hemi_fraction, meder2018_hemi_fraction] {
                assert!((f(l, 1.0) - 1.0 / (1.0 + e)).abs() < 1e-12);
                assert!((f(l, -1.0) - e / (1.0 + e)).abs() < 1e-12);
                assert!((f(l, 0.0) - 0.5).abs() < 1e-12);
            }
        }
    }
}
