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

/// `2^e` as two normal factors for `|e| ≤ 252`.
fn split(e: i32) -> [f32; 2] {
    let half = e / 2;
    [math::pow2(half), math::pow2(e - half)]
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
    // The length hidden from the optimiser: this cold path stays one short loop in flash
    // instead of being unrolled for the caller's constant N.
    let lookups = lookups.get(..core::hint::black_box(lookups.len())).unwrap_or(&[]);
    if !lookups.iter().all(|y| (0..T::CHANNELS).all(|c| y.channel(c).is_finite())) {
        return Err(Error::InvalidRadiance);
    }
    Ok(from_channels(|c| {
        // `2^−k` and `2^k` each as two normal factors (|k| ≤ 149): every scaled lookup is
        // exact, and the sum is rounded once on the way back.
        let k = channel_binade(lookups, c);
        let (down, up) = (split(-k), split(k));
        let sum: f32 = lookups
            .iter()
            .enumerate()
            .map(|(j, y)| weight(j) * (y.channel(c) * down[0] * down[1]))
            .sum();
        sum * up[0] * up[1]
    }))
}
