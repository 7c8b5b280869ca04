//! The state's running scale: the largest sample's bits, and saturating rescaling by `2^k`
//! (the powers of two themselves are [`crate::math`]'s).

use crate::math;

/// The largest `|x|` of `values`, as the bits of `|x|` (f32 magnitudes order as their bits);
/// `None` if one is not finite.
pub(super) fn peak_bits(values: impl Iterator<Item = f32>) -> Option<u32> {
    let mut peak = 0u32;
    for v in values {
        let bits = v.to_bits() & 0x7fff_ffff;
        if bits >= 0x7f80_0000 {
            return None;
        }
        peak = peak.max(bits);
    }
    Some(peak)
}

/// [`math::ldexp`], finite: `±f32::MAX` where `x·2^k` would overflow.
pub(super) fn ldexp_saturating(x: f32, k: i32) -> f32 {
    let y = math::ldexp(x, k);
    if y.is_infinite() {
        f32::MAX.copysign(y)
    } else {
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{binade, ldexp};

    fn exponent(bits: u32) -> i32 {
        binade(f32::from_bits(bits))
    }

    #[test]
    fn exponents_and_powers_of_two_are_exact() {
        for (x, e) in [(1.0f32, 0), (1.5, 0), (2.0, 1), (0.75, -1), (f32::MAX, 127)] {
            assert_eq!(exponent(x.to_bits()), e, "{x}");
        }
        assert_eq!(exponent(f32::MIN_POSITIVE.to_bits()), -126);
        assert_eq!(exponent(1), -149);
        assert_eq!(exponent(3), -148);
        assert_eq!(peak_bits([1.0, -3.0, 2.0].into_iter()), Some(3f32.to_bits()));
        assert_eq!(peak_bits([1.0, f32::NAN].into_iter()), None);
        assert_eq!(peak_bits([f32::NEG_INFINITY].into_iter()), None);
        assert_eq!(ldexp(3.0, 200), f32::INFINITY);
        assert_eq!(ldexp(f32::from_bits(1), 149), 1.0);
        assert_eq!(ldexp(f32::from_bits(1), 149 + 127), 2f32.powi(127));
        assert_eq!(ldexp(1.0, -149), f32::from_bits(1));
        assert_eq!(ldexp(f32::MAX, -127 - 149), f32::from_bits(2));
        assert_eq!(ldexp(f32::MAX, -300), 0.0);
        assert_eq!(ldexp(1.5, -130), 1.5 * 2f32.powi(-130));
        assert_eq!(ldexp(1.5, 100), 1.5 * 2f32.powi(100));
        assert_eq!(ldexp_saturating(-1.0, 300), -f32::MAX);
        for k in -300..300 {
            let want = 1.25f64 * 2f64.powi(k);
            assert_eq!(f64::from(ldexp(1.25, k)), (want as f32) as f64, "k = {k}");
        }
    }
}
