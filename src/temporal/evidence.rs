//! The change test's arithmetic: prior odds, the posterior probability of a change, and the
//! Bayes factor of Gaussian innovations (shared with the layout probe's accumulation).

use crate::math;

/// `ln(h/(1 − h))`.
pub(crate) fn log_odds(h: f32) -> f32 {
    math::ln(h) - math::ln_1p(-h)
}

/// `1/(1 + e^(−x))`, 0 or 1 at the extremes (and for NaN evidence, 1: treated as a change).
pub(crate) fn logistic(x: f32) -> f32 {
    if x.is_nan() || x > 40.0 {
        1.0
    } else if x < -40.0 {
        0.0
    } else {
        1.0 / (1.0 + math::exp(-x))
    }
}

/// The log Bayes factor of `q` independent zero-mean Gaussian values with sum of squares `ss`:
/// variance `s0 + psi` (changed) against `s0` (unchanged).
pub(crate) fn gaussian_log_bf(ss: f32, q: f32, s0: f32, psi: f32) -> f32 {
    if s0 <= 0.0 {
        // No noise: any change is certain, an exact repeat rules one out.
        return if ss > 0.0 {
            f32::INFINITY
        } else if psi > 0.0 {
            f32::NEG_INFINITY
        } else {
            0.0
        };
    }
    let ratio = psi / s0;
    -0.5 * q * math::ln_1p(ratio) + 0.5 * ss / s0 * ratio / (1.0 + ratio)
}
