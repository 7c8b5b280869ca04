//! Fixed-point BMC weighted sums (feature `fixed`): baked Q1.31 weights against the
//! generator, accuracy against the f64 sum with the f64 weights, saturation, constants.
//!
//! ```text
//! cargo test --features fixed --test bmc fixed_point:: -- --nocapture
//! ```
#![cfg(feature = "fixed")]

use crate::gen::bmc;
use sphere_quadrature::bmc::Renderer;
use sphere_quadrature::fixed_point::{
    i16f16_from_f32, u16f16_from_f32, u16f16_from_f64, weighted_sum, weighted_sum_signed, BmcFixed,
    I16F16, U16F16,
};

/// The generator's sets (f64 weights), in the order of `tables/bmc.txt`.
fn sets() -> Vec<bmc::Baked> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tables/bmc.txt");
    let specs = bmc::parse(&std::fs::read_to_string(path).unwrap()).unwrap();
    bmc::bake_all(&specs).unwrap()
}

fn f64_weights(sets: &[bmc::Baked], n: usize) -> Vec<f64> {
    sets.iter().find(|b| b.spec.n == n).unwrap().weights_f64.clone()
}

/// xorshift64*: deterministic, no dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn baked_weights_equal_the_generator_and_sum_to_exactly_one() {
    let sets = sets();
    for_each_size!(N => {
        let w = f64_weights(&sets, N);
        let q = BmcFixed::<N>::weights_q31();
        assert_eq!(&q[..], &bmc::q31(&w).unwrap()[..], "N = {N}");
        assert_eq!(q.iter().map(|&x| u64::from(x)).sum::<u64>(), 1 << 31, "N = {N}");
        let worst = q
            .iter()
            .zip(&w)
            .map(|(&q, &w)| (f64::from(q) - w * 2f64.powi(31)).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1.0, "N = {N}: a weight is {worst} units from w·2³¹");
        // Same weights as the f32 renderer, to f32 and Q1.31 rounding.
        for (&q, &wf) in q.iter().zip(Renderer::<N>::weights()) {
            let d = (f64::from(q) / 2f64.powi(31) - f64::from(wf)).abs();
            assert!(d <= f64::from(wf) * 2f64.powi(-24) + 2f64.powi(-31), "N = {N}: {d}");
        }
    });
}

#[test]
fn relative_error_against_f64_is_below_1e_3() {
    let sets = sets();
    let mut rng = Rng(0x5eed_f1ced);
    for_each_size!(N => {
        let w = f64_weights(&sets, N);
        let bmc = BmcFixed::<N>::new();
        // Bound: |Σ δqᵢYᵢ| ≤ max(|δqᵢ|/qᵢ)·Σ qᵢYᵢ with |δq| < 1, plus ½ LSB of final rounding.
        let q_min = BmcFixed::<N>::weights_q31().iter().copied().min().unwrap();
        // (max relative error, max error in LSB) per distribution.
        let mut worst = [(0.0f64, 0.0f64); 3];
        for trial in 0..2000 {
            let ys: [U16F16; N] = core::array::from_fn(|_| match trial % 3 {
                // Uniform raw bits: the whole range [0, 65536).
                0 => U16F16::from_bits(rng.next() as u32),
                // Log-uniform over [2⁻⁷, 2¹⁶): HDR radiance, 23 octaves.
                1 => u16f16_from_f64(2f64.powf(-7.0 + 23.0 * rng.unit())),
                // A smooth sky: 1 + 0.5·z-like values with a small range.
                _ => u16f16_from_f64(1.0 + 0.5 * rng.unit()),
            });
            let fixed = bmc.mean_radiance(&ys).to_num::<f64>();
            let exact: f64 = ys.iter().zip(&w).map(|(y, w)| y.to_num::<f64>() * w).sum();
            let rel = (fixed - exact).abs() / exact;
            let lsb = (fixed - exact).abs() * 65536.0;
            let bound = 1.0 / f64::from(q_min) + 0.5 / (exact * 65536.0);
            assert!(rel <= bound * (1.0 + 1e-9), "N = {N}: {rel:e} > {bound:e}");
            let k = trial % 3;
            worst[k] = (worst[k].0.max(rel), worst[k].1.max(lsb));
        }
        println!(
            "N = {N}: min q = {q_min} (1/q = {:.1e}); max relative error (uniform, log-uniform, \
             smooth) = {:.2e}, {:.2e}, {:.2e}; max abs error {:.3}, {:.3}, {:.3} LSB",
            1.0 / f64::from(q_min), worst[0].0, worst[1].0, worst[2].0, worst[0].1, worst[1].1,
            worst[2].1
        );
        for (rel, _) in worst {
            assert!(rel <= 1e-3, "N = {N}: relative error {rel:e}");
        }
    });
}

#[test]
fn fixed_agrees_with_the_f32_renderer() {
    let mut rng = Rng(42);
    let r = Renderer::<64>::new();
    let bmc = BmcFixed::<64>::new();
    let mut worst = 0.0f64;
    for _ in 0..1000 {
        let yf: [f32; 64] = core::array::from_fn(|_| (1000.0 * rng.unit()) as f32);
        let yq = yf.map(u16f16_from_f32);
        let f = f64::from(r.estimate(&yf).unwrap()) / core::f64::consts::PI;
        let q = bmc.mean_radiance(&yq).to_num::<f64>();
        worst = worst.max((f - q).abs() / f);
    }
    println!("N = 64: fixed vs f32 renderer / π: max relative difference {worst:.2e}");
    assert!(worst < 1e-5, "{worst:e}");
}

#[test]
fn constants_are_exact() {
    for_each_size!(N => {
        let bmc = BmcFixed::<N>::new();
        for bits in [0, 1, 0x8000, 0x1_0000, 0x1234_5678, 0xFFFF_FFFE, u32::MAX] {
            let c = U16F16::from_bits(bits);
            assert_eq!(bmc.mean_radiance(&[c; N]), c, "N = {N}, bits = {bits:#x}");
        }
    });
}

#[test]
fn saturates_and_never_wraps() {
    // Baked weights: the top of the range stays at the top, and one huge sample among zeros
    // gives its weight's share.
    let bmc = BmcFixed::<256>::new();
    assert_eq!(bmc.mean_radiance(&[U16F16::MAX; 256]), U16F16::MAX);
    let mut ys = [U16F16::ZERO; 256];
    ys[0] = U16F16::MAX;
    let q0 = BmcFixed::<256>::weights_q31()[0];
    let expect = ((u64::from(q0) * u64::from(u32::MAX) + (1 << 30)) >> 31) as u32;
    assert_eq!(bmc.mean_radiance(&ys).to_bits(), expect);
    // Arbitrary weights summing to ~2 (Q1.31 twice one): the result saturates.
    assert_eq!(weighted_sum(&[1 << 31, 1 << 31], &[U16F16::MAX; 2]), U16F16::MAX);
    // Weights far above 2 (the accumulator itself saturates): still MAX, not a wrapped value.
    assert_eq!(weighted_sum(&[u32::MAX; 8], &[U16F16::MAX; 8]), U16F16::MAX);
    // Empty sum.
    assert_eq!(weighted_sum::<0>(&[], &[]), U16F16::ZERO);
    // Conversions saturate: no NaN in fixed point.
    assert_eq!(u16f16_from_f32(f32::NAN), U16F16::ZERO);
    assert_eq!(u16f16_from_f32(-1.0), U16F16::ZERO);
    assert_eq!(u16f16_from_f32(f32::NEG_INFINITY), U16F16::ZERO);
    assert_eq!(u16f16_from_f32(65536.0), U16F16::MAX);
    assert_eq!(u16f16_from_f32(f32::INFINITY), U16F16::MAX);
    assert_eq!(u16f16_from_f32(1.5).to_bits(), 0x1_8000);
    assert_eq!(u16f16_from_f32(1.5).to_num::<f32>(), 1.5);
}

/// The signed sum against an independent exact computation in `i128` (`Σ qᵢ·bitsᵢ`, rounded
/// half up), for uniform random bits (both signs, the whole range), baked and random weights.
#[test]
fn signed_sum_is_exact_and_rounded_once() {
    let mut rng = Rng(7);
    let exact = |q: &[u32], y: &[I16F16]| -> i32 {
        let s: i128 = q.iter().zip(y).map(|(&q, y)| i128::from(q) * i128::from(y.to_bits())).sum();
        let r = (s + (1 << 30)).div_euclid(1 << 31);
        r.clamp(i128::from(i32::MIN), i128::from(i32::MAX)) as i32
    };
    for_each_size!(N => {
        let bmc = BmcFixed::<N>::new();
        let q = BmcFixed::<N>::weights_q31();
        for trial in 0..500 {
            let ys: [I16F16; N] = core::array::from_fn(|_| match trial % 2 {
                0 => I16F16::from_bits(rng.next() as u32 as i32),
                _ => i16f16_from_f32((200.0 * rng.unit() - 100.0) as f32),
            });
            assert_eq!(bmc.mean_signed(&ys).to_bits(), exact(q, &ys), "N = {N}, trial {trial}");
        }
        // Constants, including the extremes, are exact.
        for c in [I16F16::MIN, I16F16::from_bits(-1), I16F16::ZERO, I16F16::DELTA, I16F16::MAX] {
            assert_eq!(bmc.mean_signed(&[c; N]), c, "N = {N}, {c}");
        }
    });
    // Weights summing to more than one saturate at both ends, never wrap.
    let q = [u32::MAX; 8];
    assert_eq!(weighted_sum_signed(&q, &[I16F16::MAX; 8]), I16F16::MAX);
    assert_eq!(weighted_sum_signed(&q, &[I16F16::MIN; 8]), I16F16::MIN);
    let ys: [I16F16; 8] =
        core::array::from_fn(|i| I16F16::from_bits((rng.next() as i32) >> (i % 4)));
    assert_eq!(weighted_sum_signed(&q, &ys).to_bits(), exact(&q, &ys));
    // Conversions: nearest, saturating, NaN to zero.
    assert_eq!(i16f16_from_f32(-1.5).to_bits(), -0x1_8000);
    assert_eq!(i16f16_from_f32(f32::NAN), I16F16::ZERO);
    assert_eq!(i16f16_from_f32(f32::NEG_INFINITY), I16F16::MIN);
    assert_eq!(i16f16_from_f32(f32::INFINITY), I16F16::MAX);
    assert_eq!(i16f16_from_f32(32768.0), I16F16::MAX);
    assert_eq!(i16f16_from_f32(-32768.0), I16F16::MIN);
}

/// The re-exported types are the `fixed` crate's: values pass to and from it unchanged.
#[test]
fn types_are_the_fixed_crates() {
    let y: fixed::types::U16F16 = u16f16_from_f32(2.25);
    assert_eq!(y, fixed::types::U16F16::from_num(2.25));
    let s: fixed::types::I16F16 =
        BmcFixed::<64>::new().mean_signed(&[fixed::types::I16F16::from_num(-0.75); 64]);
    assert_eq!(s, fixed::types::I16F16::from_num(-0.75));
}
