//! The noise of measured values: a sensor's readings ([`crate::layout`]), a renderer's
//! lookups read back at reduced precision ([`crate::bmc::FootprintRenderer::set_lookup_noise`]).

/// Measurement noise: a value `Y` (per channel) has variance `w²·σ² + η²·Y²`, `w` the
/// measurement's noise scale (1 unless a layout's sensor sets one,
/// [`Sensor::with_noise_scale`](crate::layout::Sensor::with_noise_scale)).
///
/// `σ` may be any finite non-negative number (in the values' units: a noise far above the
/// values leaves them little weight); `η` at most [`MAX_RELATIVE_NOISE`]. In a layout the
/// noise scales matter only beside an absolute noise: with `σ > 0` they may differ by at most
/// [`MAX_NOISE_SCALE_RATIO`](crate::layout::MAX_NOISE_SCALE_RATIO) (a sensor 2²⁰ times
/// noisier than another says nothing f32 can hold); with `σ = 0` any positive scales give the
/// same probe.
///
/// ```
/// use sphere_quadrature::layout::Noise;
///
/// let n = Noise { absolute: 0.01, relative: 0.05 };
/// assert_eq!(Noise::NONE.absolute, 0.0);
/// assert!(n.relative > 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Noise {
    /// `σ`, in the values' units.
    pub absolute: f32,
    /// `η`, a fraction of the value.
    pub relative: f32,
}

impl Noise {
    /// Exact values.
    pub const NONE: Noise = Noise { absolute: 0.0, relative: 0.0 };
}

/// The largest relative noise `η` a layout or a renderer accepts.
pub const MAX_RELATIVE_NOISE: f32 = 1e6;
