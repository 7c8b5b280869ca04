//! Luminance from an RGB probe: the value and the error bar of one query, the single place
//! where the accuracy and glossy benchmarks turn an `Estimate<[f32; 3]>` into luminance.
//!
//! Luminance is `wᵀc` with the Rec. 709 weights `w` of `reference::envmap::luminance`. The
//! value is linear, so it is `wᵀ` times the RGB estimate. Its variance is `wᵀΣw`, with `Σ` the
//! 3×3 posterior covariance of the channels.
//!
//! INTERIM: the crate has no channel covariance yet (issue #13 item 2), only per-channel
//! variances `σ_c²`. Until then the variance here is `(Σ_c w_c·σ_c)²`, the largest `wᵀΣw`
//! allowed by those variances (perfectly correlated channels; Cauchy–Schwarz). It is not the
//! probe's luminance bar; [`METHOD`] says so in every report.

use sphere_quadrature::bmc::Size;
use sphere_quadrature::probe::{Estimate, Probe, ProbeSize};

/// Rec. 709 luminance weights, as `reference::envmap::luminance`.
pub const LUMINANCE: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// How the luminance variance is obtained, for the reports.
pub const METHOD: &str = "INTERIM, not the probe's luminance bar: the crate does not expose \
     the channel covariance yet, so σ² of luminance is (Σ_c w_c·σ_c)² from the per-channel \
     variances σ_c² (w: Rec. 709 weights), the bound for perfectly correlated channels";

/// The luminance view of one update of an RGB probe.
pub struct LuminanceBar;

impl LuminanceBar {
    /// Once per update of `probe`.
    pub fn new<const N: usize>(_probe: &Probe<N, [f32; 3]>) -> Self
    where
        Size<N>: ProbeSize,
    {
        Self
    }

    /// Luminance value and variance of `estimate` (its own error bar).
    pub fn estimate(&self, estimate: &Estimate<[f32; 3]>) -> (f64, f64) {
        (weighted(estimate.value), self.variance(estimate.variance))
    }

    /// Luminance variance from the per-channel variances of the same query by another path
    /// (the exact `posterior_variance` or `glossy_variance`).
    pub fn variance(&self, per_channel: [f32; 3]) -> f64 {
        weighted(per_channel.map(|v| v.max(0.0).sqrt())).powi(2)
    }
}

/// `wᵀc` in f64.
fn weighted(c: [f32; 3]) -> f64 {
    LUMINANCE.iter().zip(c).map(|(&w, c)| f64::from(w) * f64::from(c)).sum()
}
