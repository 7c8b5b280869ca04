//! Sample values the estimators can sum: scalar radiance (`f32`) or RGB (`[f32; 3]`).
//!
//! # Example
//! ```
//! use sphere_quadrature::{qmc, Vec3};
//!
//! // Every estimator is generic over the sample type: the same call integrates f32 and RGB.
//! let one: f32 = qmc::irradiance::<64, f32, _>(Vec3::Z, 0, |_| 1.0)?;
//! let rgb: [f32; 3] = qmc::irradiance::<64, [f32; 3], _>(Vec3::Z, 0, |_| [1.0; 3])?;
//! // A constant unit radiance has irradiance π.
//! assert!((one - core::f32::consts::PI).abs() < 1e-4);
//! assert!(rgb.iter().all(|&c| (c - one).abs() < 1e-6));
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```

/// The most channels a radiance type may have, in every estimator of the crate: 1 (`f32`) to
/// 4 (`[f32; 4]`). A type with more (or none) is a compile error where an estimator takes it.
///
/// ```compile_fail,E0080
/// use sphere_quadrature::probe::Probe;
///
/// let _ = Probe::<16, [f32; 5]>::new();
/// ```
pub const MAX_CHANNELS: usize = 4;

/// The compile-time check of [`MAX_CHANNELS`]: evaluating `Channels::<T>::VALID` fails the
/// build for a type of no channels or more than [`MAX_CHANNELS`].
pub(crate) struct Channels<T>(core::marker::PhantomData<T>);

impl<T: Radiance> Channels<T> {
    pub(crate) const VALID: () = assert!(
        T::CHANNELS >= 1 && T::CHANNELS <= MAX_CHANNELS,
        "a radiance type has 1 to 4 channels (radiance::MAX_CHANNELS)"
    );
}

/// A radiance value: anything that can be summed and scaled.
///
/// Implemented for `f32` (one channel) and `[f32; N]` (`N` channels, e.g. RGB); the estimators
/// take 1 to [`MAX_CHANNELS`] channels. The trait's own arithmetic follows IEEE rules; the
/// estimators refuse a NaN or infinite sample ([`crate::Error::InvalidRadiance`]).
///
/// # Examples
/// ```
/// use sphere_quadrature::Radiance;
///
/// // The same weighted-sum code serves one channel and RGB.
/// fn weighted_sum<T: Radiance>(samples: &[T], weights: &[f32]) -> T {
///     samples.iter().zip(weights).fold(T::ZERO, |acc, (&y, &w)| acc.mul_add(y, w))
/// }
/// assert_eq!(weighted_sum(&[1.0f32, 3.0], &[0.5, 0.5]), 2.0);
/// let rgb = weighted_sum(&[[1.0f32, 2.0, 4.0], [3.0, 2.0, 0.0]], &[0.5, 0.5]);
/// assert_eq!(rgb, [2.0, 2.0, 2.0]);
/// assert_eq!(<[f32; 3]>::CHANNELS, 3);
/// ```
pub trait Radiance: Copy {
    /// The zero value.
    const ZERO: Self;
    /// One in every channel.
    const ONE: Self;
    /// Number of channels (1 for `f32`, `C` for `[f32; C]`).
    const CHANNELS: usize;
    /// Channel `k` (0 past the last channel).
    #[must_use]
    fn channel(self, k: usize) -> f32;
    /// Component-wise product.
    #[must_use]
    fn mul(self, other: Self) -> Self;
    /// `f` applied to each channel, in order of the channels (channel 0 first; the probe
    /// builds per-channel values through this order).
    #[must_use]
    fn map<F: Fn(f32) -> f32>(self, f: F) -> Self;
    /// Component-wise sum.
    #[must_use]
    fn add(self, other: Self) -> Self;
    /// Component-wise product with a scalar.
    #[must_use]
    fn scale(self, s: f32) -> Self;
    /// `self + other·s`, the weighted-sum step.
    #[inline]
    #[must_use]
    fn mul_add(self, other: Self, s: f32) -> Self {
        self.add(other.scale(s))
    }
}

impl Radiance for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const CHANNELS: usize = 1;
    #[inline]
    fn channel(self, k: usize) -> f32 {
        if k == 0 {
            self
        } else {
            0.0
        }
    }
    #[inline]
    fn mul(self, other: Self) -> Self {
        self * other
    }
    #[inline]
    fn map<F: Fn(f32) -> f32>(self, f: F) -> Self {
        f(self)
    }
    #[inline]
    fn add(self, other: Self) -> Self {
        self + other
    }
    #[inline]
    fn scale(self, s: f32) -> Self {
        self * s
    }
}

impl<const C: usize> Radiance for [f32; C] {
    const ZERO: Self = [0.0; C];
    const ONE: Self = [1.0; C];
    const CHANNELS: usize = C;
    #[inline]
    fn channel(self, k: usize) -> f32 {
        self.get(k).copied().unwrap_or(0.0)
    }
    #[inline]
    fn mul(self, other: Self) -> Self {
        core::array::from_fn(|k| self[k] * other[k])
    }
    #[inline]
    fn map<F: Fn(f32) -> f32>(self, f: F) -> Self {
        self.map(f)
    }
    #[inline]
    fn add(self, other: Self) -> Self {
        core::array::from_fn(|k| self[k] + other[k])
    }
    #[inline]
    fn scale(self, s: f32) -> Self {
        core::array::from_fn(|k| self[k] * s)
    }
}

/// The value whose channel `k` is `f(k)`, built through [`Radiance::map`] (which visits the
/// channels in order).
pub(crate) fn from_channels<T: Radiance>(f: impl Fn(usize) -> f32) -> T {
    let next = core::cell::Cell::new(0usize);
    T::ZERO.map(|_| {
        let k = next.get();
        next.set(k + 1);
        f(k)
    })
}
