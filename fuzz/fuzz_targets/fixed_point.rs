//! Fixed point (feature `fixed`, `fixed_point` module docs) on arbitrary bits:
//! `u16f16_from_f32` rounds to nearest and saturates (NaN and negatives to 0, ≥ 65536 to MAX);
//! `weighted_sum` with any Q1.31 weights is the exact sum rounded once and saturated (checked
//! against u128 arithmetic); `BmcFixed::mean_radiance` lies between the smallest and largest
//! sample and agrees with the f32 renderer's weights (f64 sum) within the documented bound:
//! relative error ≤ 10⁻³ whenever the result is ≥ 2⁻⁷, and within `max(1/qᵢ)` relative plus
//! ½ LSB always.
#![no_main]

use fuzz_support::Bytes;
use libfuzzer_sys::fuzz_target;
use sphere_quadrature::bmc::{BakedSize, Renderer, Size};
use sphere_quadrature::fixed_point::{
    i16f16_from_f32, u16f16_from_f32, u16f16_from_f64, weighted_sum, weighted_sum_signed, BmcFixed,
    FixedSize, I16F16, U16F16,
};

fn sample(b: &mut Bytes) -> U16F16 {
    match b.u8() % 4 {
        0 => U16F16::from_bits(b.u32()),
        1 => U16F16::from_bits(u32::from(b.u16())),
        2 => u16f16_from_f32(b.f32()),
        _ => U16F16::from_bits(0xFFFF_0000 | u32::from(b.u8())),
    }
}

fn check_from_f32(x: f32) {
    let q = u16f16_from_f32(x);
    if x.is_nan() || x <= 0.0 {
        assert_eq!(q, U16F16::ZERO, "from_f32({x})");
    } else if f64::from(x) >= 65536.0 - 0.5 / 65536.0 {
        assert_eq!(q, U16F16::MAX, "from_f32({x})");
    } else {
        let err = (q.to_num::<f64>() - f64::from(x)).abs();
        assert!(err <= 0.5 / 65536.0, "from_f32({x}) = {} off by {err}", q.to_num::<f64>());
    }
    assert_eq!(u16f16_from_f64(f64::from(x)), q);
    assert_eq!(U16F16::from_bits(q.to_bits()), q);
}

/// `round(Σ qᵢyᵢ / 2³¹)`, saturated, exactly.
fn exact<const N: usize>(w: &[u32; N], s: &[U16F16; N]) -> U16F16 {
    let acc: u128 = w.iter().zip(s).map(|(&q, y)| u128::from(q) * u128::from(y.to_bits())).sum();
    U16F16::from_bits(u32::try_from((acc + (1 << 30)) >> 31).unwrap_or(u32::MAX))
}

fn run<const N: usize>(b: &mut Bytes)
where
    Size<N>: BakedSize + FixedSize,
{
    let samples: [U16F16; N] = core::array::from_fn(|_| sample(b));
    let fixed = BmcFixed::<N>::new().mean_radiance(&samples);
    let q = BmcFixed::<N>::weights_q31();
    assert_eq!(q.iter().map(|&x| u64::from(x)).sum::<u64>(), 1 << 31, "Σq ≠ 2³¹");
    assert_eq!(fixed, exact(q, &samples), "mean_radiance is not the exact rounded sum");
    let lo = samples.iter().min().unwrap();
    let hi = samples.iter().max().unwrap();
    assert!(fixed >= *lo && fixed <= *hi, "mean_radiance {fixed:?} outside [{lo:?}, {hi:?}]");
    // Against the float renderer's weights, in f64.
    let w = Renderer::<N>::weights();
    let reference: f64 =
        w.iter().zip(&samples).map(|(&w, y)| f64::from(w) * y.to_num::<f64>()).sum();
    let got = fixed.to_num::<f64>();
    let q_min = q.iter().copied().filter(|&x| x > 0).min().unwrap_or(1);
    // max(1/qᵢ) for the weight rounding, 2⁻²³ for the f32 weights' own rounding (relative),
    // ½ LSB for the final rounding.
    let bound = (1.0 / f64::from(q_min) + 2f64.powi(-23)) * reference + 0.5 / 65536.0 + 1e-12;
    assert!(
        (got - reference).abs() <= bound,
        "N = {N}: fixed {got} vs f64 {reference}, bound {bound}"
    );
    if reference >= 2f64.powi(-7) {
        assert!((got - reference).abs() <= 1e-3 * reference, "N = {N}: relative error above 10⁻³");
    }
    // Arbitrary weights: exact and saturating, never wrapping.
    let weights: [u32; N] = core::array::from_fn(|_| if b.bool() { b.u32() } else { u32::MAX });
    assert_eq!(weighted_sum(&weights, &samples), exact(&weights, &samples));
    // Signed samples (I16F16): the exact i128 sum rounded half up once, saturated; the baked
    // weights keep the result between the smallest and the largest sample.
    let signed: [I16F16; N] = core::array::from_fn(|_| match b.u8() % 3 {
        0 => I16F16::from_bits(b.u32() as i32),
        1 => i16f16_from_f32(b.f32()),
        _ => I16F16::from_bits(i32::from(b.u16() as i16)),
    });
    let exact_signed = |w: &[u32; N]| -> I16F16 {
        let s: i128 =
            w.iter().zip(&signed).map(|(&q, y)| i128::from(q) * i128::from(y.to_bits())).sum();
        let r = (s + (1 << 30)).div_euclid(1 << 31);
        I16F16::from_bits(r.clamp(i128::from(i32::MIN), i128::from(i32::MAX)) as i32)
    };
    let mean = BmcFixed::<N>::new().mean_signed(&signed);
    assert_eq!(mean, exact_signed(q), "mean_signed is not the exact rounded sum");
    let (lo, hi) = (signed.iter().min().unwrap(), signed.iter().max().unwrap());
    assert!(mean >= *lo && mean <= *hi, "mean_signed {mean:?} outside [{lo:?}, {hi:?}]");
    assert_eq!(weighted_sum_signed(&weights, &signed), exact_signed(&weights));
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes::new(data);
    for _ in 0..4 {
        check_from_f32(b.f32());
    }
    match b.u8() % 6 {
        0 => run::<16>(&mut b),
        1 => run::<32>(&mut b),
        2 => run::<64>(&mut b),
        3 => run::<80>(&mut b),
        4 => run::<128>(&mut b),
        _ => run::<256>(&mut b),
    }
});
