//! Powers of two for the probe's scale invariance: [`normalise`] maps the centred samples of
//! each channel to O(1) numbers at update, and the queries apply the scale at the end in an
//! order that cannot overflow or underflow in between ([`rescaled`], [`scaled_variance`]).
//!
//! Every scaling is by an exact power of two, so for data whose intermediates stay in the
//! normal f32 range the results are bit for bit those of the unscaled arithmetic.

use crate::math;
use crate::radiance::{from_channels, Radiance};

/// The lowest and highest exponents `k` of a channel's scale `s = 2^k`: both `s` and `1/s`
/// are normal f32 numbers.
const MIN_EXPONENT: i32 = -126;
const MAX_EXPONENT: i32 = 127;

pub(super) use crate::math::{exponent, pow2};

/// The centred samples `(Yᵢ − Y₀)/s` and the per-channel scale `s = 2^k`, `k = ⌊log₂ max |Yᵢ −
/// Y₀|⌋` clamped to [−126, 127] (`s = 1` for a constant channel): the largest normalised
/// sample of a channel lies in [1, 2) (in [½, 4) at the clamps; smaller for spreads below
/// 2⁻¹²⁶).
///
/// `Yᵢ − Y₀` can exceed `f32::MAX` though both are finite: such a channel is centred at half
/// scale, `Yᵢ/2 − Y₀/2`, and its `s` doubled.
pub(super) fn normalise<T: Radiance, const N: usize>(samples: &[T; N]) -> ([T; N], T) {
    let y0 = samples.first().copied().unwrap_or(T::ZERO);
    let largest = |centred: &[T; N]| -> T {
        from_channels(|c| centred.iter().fold(0.0f32, |m, y| m.max(math::abs(y.channel(c)))))
    };
    let mut centred = samples.map(|y| y.add(y0.scale(-1.0)));
    let mut top = largest(&centred);
    let half: T = top.map(|t| if t.is_finite() { 1.0 } else { 0.5 });
    let halved = (0..T::CHANNELS).any(|c| half.channel(c) < 1.0);
    if halved {
        let y0 = y0.mul(half);
        centred = samples.map(|y| y.mul(half).add(y0.scale(-1.0)));
        top = largest(&centred);
    }
    let k = |c: usize| -> i32 {
        let t = top.channel(c);
        if t > 0.0 {
            let doubled = i32::from(half.channel(c) < 1.0);
            (exponent(t) + doubled).clamp(MIN_EXPONENT, MAX_EXPONENT)
        } else {
            0
        }
    };
    let scale: T = from_channels(|c| pow2(k(c)));
    // (Yᵢ − Y₀)/s = centred·(1/half)/s = centred·2^(doubled − k): in [2⁻¹²⁷, 2¹²⁶].
    let factor: T = from_channels(|c| pow2(i32::from(half.channel(c) < 1.0) - k(c)));
    (centred.map(|y| y.mul(factor)), scale)
}

/// `a·(g·p + s·σ)` for the absolute part `p` (the probe's `β`, possibly ±∞), a gain
/// `g ∈ (0, 4π]`, the scale `s = 2^k` and the normalised sum `σ`, an amplitude `a` (finite):
/// mantissas and exponents apart, so that no intermediate overflows or underflows when the
/// result is in range; `±∞` when it exceeds `f32::MAX` (or when `p` is infinite).
pub(super) fn rescaled(p: f32, g: f32, s: f32, sum: f32, a: f32) -> f32 {
    if a == 0.0 {
        return 0.0;
    }
    if !p.is_finite() {
        return p * a;
    }
    // p = mp·2^ep, a = ma·2^ea with |mp|, |ma| ∈ [½, 1) (or 0), s = 2^ks.
    let (ma, ea) = libm::frexpf(a);
    let (mp, ep) = libm::frexpf(p);
    let ks = exponent(s);
    let t1 = ma * g * mp;
    let t2 = ma * sum;
    // The common exponent of the two terms: the larger, or the only non-zero one.
    let e = if t1 == 0.0 {
        ks
    } else if t2 == 0.0 {
        ep
    } else {
        ep.max(ks)
    };
    let total = libm::scalbnf(t1, ep - e) + libm::scalbnf(t2, ks - e);
    libm::scalbnf(total, e + ea)
}

/// `a²·s²·x` for `x ≥ 0`, the scale `s = 2^k` and an amplitude `a` (finite), without
/// intermediate overflow or underflow: `+∞` when it exceeds `f32::MAX`, subnormal below the
/// normal range (rounded up to the least positive f32 rather than to 0 when `x > 0`).
pub(super) fn scaled_variance(x: f32, s: f32, a: f32) -> f32 {
    if x == 0.0 || a == 0.0 {
        return 0.0;
    }
    let (ma, ea) = libm::frexpf(a);
    crate::math::ldexp_variance(ma * (ma * x), 2 * (ea + exponent(s)))
}

/// `v`, with each channel that is 0 where its unscaled `x` is positive raised to the least
/// positive f32: an error bar is never rounded to 0 unless it is 0.
#[inline]
pub(super) fn at_least_tiny<T: Radiance>(v: T, x: T) -> T {
    if (0..T::CHANNELS).all(|c| v.channel(c) != 0.0 || x.channel(c) <= 0.0) {
        return v;
    }
    from_channels(|c| {
        if v.channel(c) == 0.0 && x.channel(c) > 0.0 {
            f32::from_bits(1)
        } else {
            v.channel(c)
        }
    })
}
