//! Weighted sums of lookups at any scale: the renderers' hot loops sum in plain f32, and a
//! result that is not finite or is too small to have kept its precision is recomputed here,
//! each channel scaled by a power of two first (exact), so that no intermediate overflows or
//! underflows when the result itself is in range.

use crate::error::Error;
use crate::math;
use crate::radiance::{from_channels, Radiance};

/// Bits of `2⁻⁹⁶`: below it a sum may have lost precision to subnormal products.
const SMALL: u32 = 0x0F80_0000;
/// Bits of `+∞`.
const INFINITY: u32 = 0x7F80_0000;

/// Whether every channel of a plain f32 sum is finite and at least `2⁻⁹⁶` in magnitude (then
/// it is the answer; otherwise [`rescaled_sum`] is). Integer comparisons only.
#[inline(always)]
pub(crate) fn in_range<T: Radiance>(sum: T) -> bool {
    (0..T::CHANNELS).all(|c| {
        let bits = sum.channel(c).to_bits() & 0x7FFF_FFFF;
        bits.wrapping_sub(SMALL) < INFINITY - SMALL
    })
}

/// The binade `k` of the largest `|Yⱼ|` of channel `c` (`2^k ≤ max < 2^(k+1)`; 0 for an
/// all-zero channel).
pub(crate) fn channel_binade<T: Radiance>(lookups: &[T], c: usize) -> i32 {
    math::binade(lookups.iter().fold(0.0f32, |m, y| m.max(math::abs(y.channel(c)))))
}

/// `Σ wⱼYⱼ` per channel, each channel divided by `2^k` at its largest `|Yⱼ|` before the sum and
/// multiplied back after: `±∞` only where the sum exceeds `f32::MAX`, full precision for
/// subnormal lookups. [`Error::InvalidRadiance`] if a lookup is NaN or infinite.
#[cold]
#[inline(never)]
pub(crate) fn rescaled_sum<T: Radiance>(
    lookups: &[T],
    weight: impl Fn(usize) -> f32,
) -> Result<T, Error> {
    if !lookups.iter().all(|y| (0..T::CHANNELS).all(|c| y.channel(c).is_finite())) {
        return Err(Error::InvalidRadiance);
    }
    Ok(from_channels(|c| {
        let k = channel_binade(lookups, c);
        let sum: f32 = lookups
            .iter()
            .enumerate()
            .map(|(j, y)| weight(j) * math::ldexp(y.channel(c), -k))
            .sum();
        math::ldexp(sum, k)
    }))
}
