//! Fixed-point weighted sums for cores without an FPU (feature `fixed`).
//!
//! On a Cortex-M0 every f32 operation is a soft-float library call. This module computes the
//! Bayesian Monte Carlo weighted sum `Σ wᵢYᵢ` ([`crate::bmc`]) with integers only.
//!
//! # Formats
//! - Radiance: [`U16F16`], the `fixed` crate's unsigned Q16.16 (re-exported, so values come
//!   and go as `fixed::types::U16F16` with all of that crate's arithmetic and formatting).
//!   Range `[0, 65536)` in steps of 2⁻¹⁶. Radiance is non-negative; there is no NaN or
//!   infinity in fixed point: [`u16f16_from_f32`] maps NaN and negatives to 0 and values
//!   ≥ 65536 to [`U16F16::MAX`]. Signed data (SH coefficients, differences) use [`I16F16`]
//!   ([`i16f16_from_f32`], [`weighted_sum_signed`], [`BmcFixed::mean_signed`]).
//! - Weights: unsigned Q1.31 in a `u32` (`q = w·2³¹`). [`BmcFixed`] uses weights baked by
//!   `build.rs` from the f64 solve (`gen/bmc.rs`, `q31`): each within 2⁻³¹ of the f64 weight,
//!   rounded so that `Σq = 2³¹` **exactly**. All baked BMC weights are positive.
//! - Accumulation: exact. Each product `qᵢ·Yᵢ` is formed from 16-bit halves (ARMv6-M has no
//!   32 × 32 → 64 multiply) into three `u64` partial sums, which cannot overflow for any
//!   inputs and N < 2³²; they are combined once, and the result is rounded to nearest once
//!   (`(Σ qᵢYᵢ + 2³⁰) >> 31`).
//!
//! # Overflow and saturation
//! The accumulation is exact for every input, so overflow can only happen in the final
//! Q16.16 result, and there [`weighted_sum`] saturates at [`U16F16::MAX`]; it never wraps.
//! With the baked weights (`Σq = 2³¹`) the result is a convex combination of the inputs, so
//! it is at most the largest input and never saturates.
//!
//! # π
//! [`BmcFixed::mean_radiance`] returns the cosine-weighted mean radiance `Σ wᵢYᵢ` in
//! [`U16F16`]; the irradiance is `E = π·Σ wᵢYᵢ` (as [`crate::bmc::Renderer::estimate`]), which
//! can exceed the Q16.16 range, so the caller multiplies by π in the format it needs.
//!
//! # Accuracy
//! Against the f64 sum with the f64 weights over the same (quantised) inputs, the relative
//! error is at most `max(1/qᵢ)` (weight rounding, `|δqᵢ| < 1`) plus the final rounding, ½ LSB
//! (2⁻¹⁷) over the result: `1/q_min` is 4·10⁻⁸, 2·10⁻⁷, 6·10⁻⁷, 3·10⁻⁶ and 8·10⁻⁶ for
//! N = 16…256, so the relative error is ≤ 10⁻³ whenever the result is ≥ 2⁻⁷ (512 LSB).
//! Measured by `tests/bmc/fixed_point.rs` (2 000 seeded vectors per size: uniform bits,
//! log-uniform over [2⁻⁷, 2¹⁶), and values in [1, 1.5]): at most 6.4·10⁻⁶ relative (the ½ LSB
//! rounding at a result near 1), at most 8.7 LSB absolute at N = 256 for results near the
//! top of the range. Constants are exact (`Σq = 2³¹`).
//!
//! ```
//! use sphere_quadrature::fixed_point::{u16f16_from_f32, BmcFixed, U16F16};
//!
//! let bmc = BmcFixed::<64>::new();
//! // A constant is exact: the baked weights sum to exactly 2³¹.
//! let c = u16f16_from_f32(2.5);
//! assert_eq!(bmc.mean_radiance(&[c; 64]), c);
//! // The top of the range does not overflow.
//! assert_eq!(bmc.mean_radiance(&[U16F16::MAX; 64]), U16F16::MAX);
//! ```

use crate::bmc::{BakedSize, Size};

pub use fixed::types::{I16F16, U16F16};

/// `x` as [`U16F16`], rounded to nearest, saturating: NaN and negatives give 0, values
/// ≥ 65536 (and +∞) give [`U16F16::MAX`]. (`fixed`'s own `saturating_from_num` panics on NaN;
/// radiance from a sensor or a renderer can be NaN.)
///
/// ```
/// use sphere_quadrature::fixed_point::{u16f16_from_f32, U16F16};
///
/// assert_eq!(u16f16_from_f32(1.5), U16F16::from_bits(0x1_8000));
/// assert_eq!(u16f16_from_f32(f32::NAN), U16F16::ZERO);
/// assert_eq!(u16f16_from_f32(1e9), U16F16::MAX);
/// ```
#[must_use]
pub fn u16f16_from_f32(x: f32) -> U16F16 {
    u16f16_from_f64(f64::from(x))
}

/// `x` as [`U16F16`], rounded to nearest, saturating as [`u16f16_from_f32`].
#[must_use]
pub fn u16f16_from_f64(x: f64) -> U16F16 {
    let s = x * 65536.0 + 0.5;
    // `as` saturates: NaN → 0, negative → 0, too large → u32::MAX.
    U16F16::from_bits(if s >= 0.0 { s as u32 } else { 0 })
}

/// `x` as [`I16F16`], rounded to nearest (ties up), saturating: NaN gives 0, values below
/// −32768 (and −∞) give [`I16F16::MIN`], values ≥ 32768 (and +∞) give [`I16F16::MAX`].
///
/// ```
/// use sphere_quadrature::fixed_point::{i16f16_from_f32, I16F16};
///
/// assert_eq!(i16f16_from_f32(-1.5), I16F16::from_bits(-0x1_8000));
/// assert_eq!(i16f16_from_f32(f32::NAN), I16F16::ZERO);
/// assert_eq!(i16f16_from_f32(-1e9), I16F16::MIN);
/// ```
#[must_use]
pub fn i16f16_from_f32(x: f32) -> I16F16 {
    i16f16_from_f64(f64::from(x))
}

/// `x` as [`I16F16`], rounded to nearest (ties up), saturating as [`i16f16_from_f32`].
#[must_use]
pub fn i16f16_from_f64(x: f64) -> I16F16 {
    // `as` saturates and maps NaN to 0; `floor` keeps the rounding the same on both sides.
    I16F16::from_bits(libm::floor(x * 65536.0 + 0.5) as i32)
}

/// The exact `Σ qᵢuᵢ` of Q1.31 weights and 32-bit samples, in `u128`.
#[inline]
fn exact_sum<const N: usize>(weights_q31: &[u32; N], samples: impl Iterator<Item = u32>) -> u128 {
    // ARMv6-M has only a 32 × 32 → 32 multiply, and a `u64` product is a library call
    // (`__aeabi_lmul`), so split both operands into 16-bit halves: `q·y = 2³²·qₕyₕ +
    // 2¹⁶·(qₕyₗ + qₗyₕ) + qₗyₗ`, each partial product < 2³², summed in its own `u64` (no
    // overflow for N < 2³²), combined once at the end in `u128`.
    let (mut hh, mut mid, mut ll) = (0u64, 0u64, 0u64);
    for (&q, y) in weights_q31.iter().zip(samples) {
        let (qh, ql, yh, yl) = (q >> 16, q & 0xFFFF, y >> 16, y & 0xFFFF);
        hh += u64::from(qh * yh);
        mid += u64::from(qh * yl) + u64::from(ql * yh);
        ll += u64::from(ql * yl);
    }
    (u128::from(hh) << 32) + (u128::from(mid) << 16) + u128::from(ll)
}

/// `Σ qᵢYᵢ / 2³¹` for Q1.31 weights `qᵢ` (`u32`, `q = w·2³¹`) and [`U16F16`] samples, rounded
/// to nearest once, saturating at [`U16F16::MAX`] (never wrapping).
///
/// The sum is exact for every input (no intermediate overflow); the result cannot exceed the
/// largest sample when `Σq ≤ 2³¹` (weights summing to at most 1).
#[must_use]
#[inline]
pub fn weighted_sum<const N: usize>(weights_q31: &[u32; N], samples: &[U16F16; N]) -> U16F16 {
    let acc = exact_sum(weights_q31, samples.iter().map(|y| y.to_bits()));
    U16F16::from_bits(u32::try_from((acc + (1 << 30)) >> 31).unwrap_or(u32::MAX))
}

/// `Σ qᵢYᵢ / 2³¹` for Q1.31 weights and signed [`I16F16`] samples (spherical-harmonic
/// coefficients, differences, signed sensor readings), rounded to nearest (ties up) once,
/// saturating at [`I16F16::MIN`] / [`I16F16::MAX`] (never wrapping).
///
/// Exact for every input, with the same unsigned arithmetic as [`weighted_sum`]: each sample
/// is offset by 2³¹ (`Yᵢ + 2³¹ = bits ⊕ 2³¹` as `u32`), and `2³¹·Σqᵢ` is taken off the exact sum.
/// With weights summing to at most 1 the result lies between the smallest and the largest
/// sample.
///
/// ```
/// use sphere_quadrature::fixed_point::{weighted_sum_signed, I16F16};
///
/// let half = 1u32 << 30; // 0.5 in Q1.31
/// let y = [I16F16::from_num(-3), I16F16::from_num(1)];
/// assert_eq!(weighted_sum_signed(&[half, half], &y), I16F16::from_num(-1));
/// ```
#[must_use]
#[inline]
pub fn weighted_sum_signed<const N: usize>(
    weights_q31: &[u32; N],
    samples: &[I16F16; N],
) -> I16F16 {
    let offset_sum =
        exact_sum(weights_q31, samples.iter().map(|y| y.to_bits() as u32 ^ 0x8000_0000));
    let weight_sum: u64 = weights_q31.iter().map(|&q| u64::from(q)).sum();
    // Σqᵢ(Yᵢ + 2³¹) − 2³¹Σqᵢ, both exact (< 2¹²⁸ and < 2⁹⁵ for N < 2³²).
    let exact = offset_sum as i128 - (i128::from(weight_sum) << 31);
    let rounded = (exact + (1 << 30)) >> 31;
    I16F16::from_bits(i32::try_from(rounded).unwrap_or(if rounded < 0 {
        i32::MIN
    } else {
        i32::MAX
    }))
}

unbaked_size_diagnostic! { fixed,
    /// Implemented for exactly the sizes with baked fixed-point BMC weights; sealed.
    ///
    /// These are the sizes of [`crate::bmc::BAKED_SIZES`] whose weights all lie in [0, 1), which
    /// is every shipped size. It is a trait of its own, not part of `bmc::BakedSize`, because a
    /// table of your own (`SPHERE_QUADRATURE_BMC_TABLE`) may give a size a negative weight: that
    /// size keeps its float renderer and gets no fixed-point form, instead of failing the build.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::bmc::{BakedSize, Size};
    /// use sphere_quadrature::fixed_point::{BmcFixed, FixedSize};
    ///
    /// // The Q1.31 weights of every baked size sum to exactly 2³¹.
    /// fn weight_sum<const N: usize>() -> u64
    /// where
    ///     Size<N>: BakedSize + FixedSize,
    /// {
    ///     BmcFixed::<N>::weights_q31().iter().map(|&w| u64::from(w)).sum()
    /// }
    /// assert_eq!(weight_sum::<16>(), 1 << 31);
    /// assert_eq!(weight_sum::<64>(), 1 << 31);
    /// ```
    pub trait FixedSize: sealed::FixedSet {}
}

pub(crate) mod sealed {
    /// What `build.rs` baked for one size.
    pub trait FixedSet {
        /// Q1.31 weights, `Σ = 2³¹`.
        const WEIGHTS_Q31: &'static [u32];
    }
}

// `impl sealed::FixedSet` and `impl FixedSize` for each baked size (generator `gen/bmc.rs`,
// `render_fixed`).
include!(concat!(env!("OUT_DIR"), "/bmc_fixed_tables.rs"));

/// The fixed-point form of [`crate::bmc::Renderer`]: the same directions and weights, with
/// the weights baked as Q1.31 integers. Zero-sized.
///
/// # Examples
/// ```
/// use sphere_quadrature::fixed_point::{u16f16_from_f32, BmcFixed};
///
/// let r = BmcFixed::<64>::new();
/// // The weights form a convex combination summing to exactly 1: a constant comes back exact.
/// let c = u16f16_from_f32(2.25);
/// assert_eq!(r.mean_radiance(&[c; 64]), c);
/// // No weight is negative: the mean lies between the smallest and the largest sample.
/// let samples = core::array::from_fn(|i| u16f16_from_f32(1.0 + (i % 4) as f32));
/// let mean = r.mean_radiance(&samples).to_num::<f32>();
/// assert!((1.0..=4.0).contains(&mean));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BmcFixed<const N: usize>
where
    Size<N>: BakedSize + FixedSize;

impl<const N: usize> BmcFixed<N>
where
    Size<N>: BakedSize + FixedSize,
{
    const WEIGHTS: &'static [u32; N] =
        match <Size<N> as sealed::FixedSet>::WEIGHTS_Q31.first_chunk::<N>() {
            Some(w) => w,
            None => panic!("baked fixed-point weight count differs from N"),
        };

    /// The fixed-point renderer.
    #[must_use]
    pub const fn new() -> Self {
        Self
    }

    /// The Q1.31 weights (`Σ = 2³¹` exactly), in the order of
    /// [`crate::bmc::Renderer::fill_directions`].
    #[must_use]
    pub const fn weights_q31() -> &'static [u32; N] {
        Self::WEIGHTS
    }

    /// The cosine-weighted mean radiance `Σ wᵢYᵢ` (irradiance / π) from the radiance in each
    /// direction, in order; never above the largest sample, so it never saturates.
    #[must_use]
    pub fn mean_radiance(&self, samples: &[U16F16; N]) -> U16F16 {
        weighted_sum(Self::WEIGHTS, samples)
    }

    /// The same weighted mean `Σ wᵢYᵢ` of signed samples (for example one spherical-harmonic
    /// coefficient's or one colour difference's values in each direction); between the
    /// smallest and the largest sample, so it never saturates.
    #[must_use]
    pub fn mean_signed(&self, samples: &[I16F16; N]) -> I16F16 {
        weighted_sum_signed(Self::WEIGHTS, samples)
    }
}
