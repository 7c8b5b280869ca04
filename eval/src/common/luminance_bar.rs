//! Luminance from an RGB probe: the value and the error bar of one query, the single place
//! where the accuracy and glossy benchmarks turn an `Estimate<[f32; 3]>` into luminance.
//!
//! Luminance is `wᵀc` with the Rec. 709 weights `w` of `reference::envmap::luminance`. One
//! kernel serves all channels, so the posterior covariance of an estimate's channels is its
//! `unit_variance` times the REML channel covariance `S` of the probe's samples, and the
//! variance of luminance is `unit_variance × wᵀSw`:
//! - [`LuminanceBar::estimate`] takes `wᵀSw` from `Probe::signal_variance_of`, once per
//!   update, and multiplies it by each query's `unit_variance` (O(1) per query);
//! - [`LuminanceBar::combine`] calls `Probe::combine` (O(N²) per query), the API's own form;
//! - [`LuminanceBar::exact`] gives an estimate the unit variance of an exact per-channel
//!   variance (`irradiance_variance`, `glossy_variance`: `S_cc` times the exact unit variance),
//!   for either of the two.

use sphere_quadrature::bmc::Size;
use sphere_quadrature::footprint::Point;
use sphere_quadrature::probe::{Estimate, Probe, ProbeSize};

/// Rec. 709 luminance weights, as `reference::envmap::luminance`.
pub const LUMINANCE: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// Luminance `wᵀc` of an RGB value, in f64.
pub fn luminance(rgb: [f32; 3]) -> f64 {
    LUMINANCE.iter().zip(rgb).map(|(&w, c)| f64::from(w) * f64::from(c)).sum()
}

/// How the luminance variance is obtained, for the reports.
pub const METHOD: &str = "σ² = unit_variance × wᵀSw with w the Rec. 709 weights and S the \
     probe's REML channel covariance (`Probe::signal_variance_of`, `Probe::combine`); the exact \
     bar's unit variance is the exact per-channel variance over S_cc";

/// The luminance view of one update of an RGB probe.
pub struct LuminanceBar {
    /// `wᵀSw`.
    signal: f32,
    /// `S_cc`, the per-channel signal variances.
    diagonal: [f32; 3],
}

impl LuminanceBar {
    /// Once per update of `probe` (of any capacity `M` for missing samples): `wᵀSw` (O(N²))
    /// and the diagonal of `S`.
    pub fn new<const N: usize, const M: usize>(probe: &Probe<N, [f32; 3], Point, M>) -> Self
    where
        Size<N>: ProbeSize,
    {
        Self {
            signal: probe.signal_variance_of(LUMINANCE).expect("finite weights"),
            diagonal: probe.signal_variance(),
        }
    }

    /// Luminance value and variance of `estimate`, `unit_variance × wᵀSw`.
    pub fn estimate(&self, estimate: &Estimate<[f32; 3]>) -> (f64, f64) {
        (
            luminance(estimate.value),
            f64::from(estimate.unit_variance.unwrap_or(f32::NAN)) * f64::from(self.signal),
        )
    }

    /// The same through `Probe::combine`.
    pub fn combine<const N: usize>(
        probe: &Probe<N, [f32; 3]>,
        estimate: &Estimate<[f32; 3]>,
    ) -> (f64, f64)
    where
        Size<N>: ProbeSize,
    {
        let y = probe.combine(estimate, LUMINANCE).expect("finite weights");
        (f64::from(y.value), f64::from(y.variance))
    }

    /// `estimate` with the variance `per_channel` of an exact query for the same estimate:
    /// its unit variance is `per_channel[c] / S_cc` on the channel of largest `S_cc` (0 if
    /// the samples have no spread).
    pub fn exact(
        &self,
        estimate: &Estimate<[f32; 3]>,
        per_channel: [f32; 3],
    ) -> Estimate<[f32; 3]> {
        let (c, s) = self.diagonal.iter().copied().enumerate().fold((0, 0.0f32), |best, (c, s)| {
            if s > best.1 {
                (c, s)
            } else {
                best
            }
        });
        let unit = if s > 0.0 { per_channel[c] / s } else { 0.0 };
        Estimate { value: estimate.value, variance: per_channel, unit_variance: Some(unit) }
    }
}
