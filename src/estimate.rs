//! The answer of every estimator: a value and its variance, per channel.

use crate::error::Error;
use crate::radiance::Radiance;

/// The largest lobe sharpness a glossy query accepts ([`Probe::glossy`](crate::Probe::glossy),
/// the Phong exponent of every `phong` query): an angular width of 10⁻⁴ rad, a mirror, for any
/// sample count.
pub const MAX_GLOSSY_SHARPNESS: f32 = 1e8;

/// An estimate and its error bar, per channel: what every query of every probe and renderer
/// returns.
///
/// # Examples
/// ```
/// use sphere_quadrature::{Probe, Vec3};
///
/// let mut probe = Probe::<64, [f32; 3]>::new();
/// let samples = probe.directions().map(|d| [1.0 + d.x * d.y, 0.5, 2.0 + d.z]);
/// probe.update(&samples)?;
/// let e = probe.irradiance(Vec3::new(0.0, 0.6, 0.8))?;
/// // The probe's channels share one model: each variance is the unit variance times that
/// // channel's signal variance.
/// let unit = e.unit_variance.expect("a Probe's channels share one model");
/// for c in 0..3 {
///     let product = unit * probe.signal_covariance(c, c)?;
///     assert!((e.variance[c] - product).abs() <= 1e-5 * e.variance[c].max(1e-30));
/// }
/// // The constant green channel is exact: π·0.5, no variance.
/// assert!((e.value[1] - 0.5 * core::f32::consts::PI).abs() < 1e-5 && e.variance[1] == 0.0);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Estimate<T> {
    /// The estimate (a posterior mean for the Bayesian estimators).
    pub value: T,
    /// Its variance. Zero only where the answer is exact (for example a constant light); a
    /// positive variance below the least positive `f32` is reported as that number, never 0.
    pub variance: T,
    /// The variance this query would have for a light of signal variance 1, where the
    /// estimator's channels share one model: then `variance` of channel `c` is
    /// `unit_variance` times that channel's signal variance (`Probe::signal_covariance(c, c)`,
    /// [`LayoutProbe::signal_variance`](crate::LayoutProbe::signal_variance)), and the variance
    /// of any combination of the channels follows from it (`combine`). It carries the query's
    /// weight (a glossy lobe's amplitude `a` as `a²`), the signal variance the radiance units.
    ///
    /// `None` where the channels are estimated apart and share no such factor:
    /// [`TemporalProbe`](crate::TemporalProbe) (each channel shrunk on its own) and a
    /// [`LayoutProbe`](crate::LayoutProbe) of more than one channel (each channel's noise
    /// ratio fitted on its own).
    pub unit_variance: Option<f32>,
}

/// `Σ_c w_c·value_c` with the largest variance any correlation between the channels' errors
/// allows, `(Σ_c |w_c|·σ_c)²` (reached when the errors are perfectly correlated, as for a grey
/// light); exact for one channel. `unit_variance` passes through for one channel, else `None`.
///
/// # Errors
/// [`Error::InvalidWeights`] for a NaN or infinite weight.
pub(crate) fn combine_bound<T: Radiance>(
    estimate: &Estimate<T>,
    weights: T,
) -> Result<Estimate<f32>, Error> {
    if !(0..T::CHANNELS).all(|c| weights.channel(c).is_finite()) {
        return Err(Error::InvalidWeights);
    }
    let (mut value, mut sigma) = (0.0f64, 0.0f64);
    for c in 0..T::CHANNELS {
        let w = f64::from(weights.channel(c));
        value += w * f64::from(estimate.value.channel(c));
        // σ ≤ 2^64 and |w| ≤ 2^128: no product or square here leaves f64's range.
        sigma += libm::fabs(w) * libm::sqrt(f64::from(estimate.variance.channel(c)));
    }
    let variance = sigma * sigma;
    let mut rounded = variance as f32;
    if rounded == 0.0 && variance > 0.0 {
        rounded = f32::from_bits(1);
    }
    let unit_variance = if T::CHANNELS == 1 { estimate.unit_variance } else { None };
    Ok(Estimate { value: value as f32, variance: rounded, unit_variance })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bound_is_exact_for_one_channel_and_covers_every_correlation() {
        let one = Estimate { value: 2.0f32, variance: 9.0, unit_variance: Some(0.5) };
        let c = combine_bound(&one, -3.0).unwrap();
        assert_eq!((c.value, c.variance, c.unit_variance), (-6.0, 81.0, Some(0.5)));
        let rgb =
            Estimate { value: [1.0f32, 2.0, 3.0], variance: [4.0, 1.0, 0.0], unit_variance: None };
        let c = combine_bound(&rgb, [0.5, -1.0, 2.0]).unwrap();
        assert_eq!(c.value, 0.5 - 2.0 + 6.0);
        // (0.5·2 + 1·1 + 0)² = 4: perfectly correlated errors of opposite weight signs.
        assert_eq!(c.variance, 4.0);
        assert_eq!(c.unit_variance, None);
        assert_eq!(combine_bound(&rgb, [f32::NAN, 0.0, 0.0]), Err(Error::InvalidWeights));
    }

    #[test]
    fn the_bound_neither_overflows_early_nor_rounds_to_zero() {
        let big = Estimate { value: 1e38f32, variance: f32::MAX, unit_variance: None };
        let c = combine_bound(&big, 1e-10).unwrap();
        assert!((c.variance / (f32::MAX * 1e-20) - 1.0).abs() < 1e-6);
        let tiny = Estimate { value: 1e-30f32, variance: f32::from_bits(1), unit_variance: None };
        let c = combine_bound(&tiny, 0.5).unwrap();
        assert_eq!(c.variance, f32::from_bits(1));
        let c = combine_bound(&big, f32::MAX).unwrap();
        assert_eq!((c.value, c.variance), (f32::INFINITY, f32::INFINITY));
    }
}
