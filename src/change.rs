//! Change detection shared by the streaming probes ([`crate::temporal::TemporalProbe`] and
//! [`crate::layout::LayoutProbe::pool`]): prior odds, the posterior probability of a change,
//! the Bayes factor of Gaussian innovations, and the weight old evidence keeps.

use crate::math;

/// The default prior probability that the light changes at an update (see
/// [`TemporalProbe::with_hazard`](crate::temporal::TemporalProbe::with_hazard) and
/// [`LayoutProbe::with_hazard`](crate::layout::LayoutProbe::with_hazard)).
pub const DEFAULT_HAZARD: f32 = 1.0 / 64.0;

/// What [`TemporalProbe::pool`](crate::temporal::TemporalProbe::pool) or
/// [`LayoutProbe::pool`](crate::layout::LayoutProbe::pool) did with the old evidence.
///
/// # Examples
/// ```
/// use sphere_quadrature::temporal::{Change, TemporalProbe};
///
/// let mut probe = TemporalProbe::<64>::new(3);
/// let frame = |p: &TemporalProbe<64>, level: f32| p.directions().map(|d| level + 0.25 * d.z);
/// assert_eq!(probe.pool(&frame(&probe, 1.0), &[])?, Change::First);
/// assert_eq!(probe.pool(&frame(&probe, 1.0), &[])?, Change::Blended);
/// // The lighting changes by far more than the noise: the state restarts.
/// assert_eq!(probe.pool(&frame(&probe, 20.0), &[])?, Change::Reset);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Change {
    /// The first update: the state is this update.
    First,
    /// The posterior probability of a change was below one half: the update is pooled with
    /// the old evidence (which may have lost some of its weight).
    Blended,
    /// The posterior probability of a change was at least one half, or the light changed in
    /// part of the sphere
    /// ([`TemporalProbe::last_changed_regions`](crate::temporal::TemporalProbe::last_changed_regions)):
    /// the state restarted.
    Reset,
}

/// The weight `w′` old evidence of weight `w` keeps after an update whose posterior
/// probability of a change is `π`: the mixture of "changed" (the new update alone) and
/// "unchanged" (pooled with the old evidence) collapsed to one pooled state with the same
/// mean, `w′/(w′ + 1) = (1 − π)·w/(w + 1)`, that is `w′ = (1 − π)·w/(1 + π·w)`.
pub(crate) fn soft_reset(probability: f32, w: f32) -> f32 {
    (1.0 - probability) * w / (1.0 + probability * w)
}

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
