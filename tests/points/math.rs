//! The crate's own math kernels against f64.

use reference::rng::Rng;
use sphere_quadrature::math::{sin_cos_turns, sqrt_const};
use sphere_quadrature::probe::Probe;
use sphere_quadrature::sf::SphericalFibonacci;

#[test]
fn sin_cos_of_a_turn_fraction_is_accurate() {
    let mut rng = Rng::new(17);
    let quarter = 1u64 << 62;
    // Random phases, and phases at and beside every quarter-turn boundary (where the
    // reduction switches quadrant) and the eighth turns (the largest reduced argument).
    let mut phases: Vec<u64> = (0..1_000_000).map(|_| rng.next_u64()).collect();
    for k in 0..8u64 {
        let b = k.wrapping_mul(quarter / 2);
        phases.extend([b, b.wrapping_sub(1), b.wrapping_add(1)]);
    }
    let mut worst = 0.0f64;
    for p in phases {
        let (s, c) = sin_cos_turns(p);
        let theta = p as f64 / 2f64.powi(64) * std::f64::consts::TAU;
        worst = worst.max((s as f64 - theta.sin()).abs()).max((c as f64 - theta.cos()).abs());
    }
    println!("sin_cos_turns: max abs error {worst:.3e}");
    // Two f32 ulps at 1 are 1.19e-7.
    assert!(worst <= 1.2e-7, "{worst:e}");
    assert_eq!(sin_cos_turns(0), (0.0, 1.0));
    assert_eq!(sin_cos_turns(quarter), (1.0, -0.0));
}

/// `inv_sqrt` over its domain `[2⁻¹²⁵, f32::MAX]`: random bit patterns (every exponent),
/// powers of two, the ends of the range and the neighbourhood of 1, against `1/√x` in f64, in ulps of
/// the correctly rounded result.
#[test]
fn inv_sqrt_is_within_one_and_a_half_ulp() {
    let mut rng = Rng::new(23);
    let mut xs: Vec<f32> = (0..2_000_000)
        .map(|_| {
            f32::from_bits(
                (rng.next_u64() >> 33) as u32 % (0x7F80_0000 - 0x0080_0000) + 0x0080_0000,
            )
        })
        .collect();
    xs.extend((-125..=127).map(|e| 2f32.powi(e)));
    xs.retain(|&x| x >= 2.0 * f32::MIN_POSITIVE);
    xs.extend([
        2.0 * f32::MIN_POSITIVE,
        f32::MAX,
        1.0,
        1.0 - f32::EPSILON / 2.0,
        1.0 + f32::EPSILON,
        4.0,
    ]);
    let (mut worst, mut at) = (0.0f64, 0.0f32);
    for x in xs {
        let got = f64::from(sphere_quadrature::math::inv_sqrt(x));
        let exact = 1.0 / f64::from(x).sqrt();
        // The f32 spacing above the (positive, finite) result; `next_up` needs Rust 1.86.
        let y = exact as f32;
        let ulp = f64::from(f32::from_bits(y.to_bits() + 1) - y);
        let e = (got - exact).abs() / ulp;
        if e > worst {
            (worst, at) = (e, x);
        }
    }
    println!("inv_sqrt: max error {worst:.2} ulp (x = {at:e})");
    assert!(worst <= 1.5, "{worst}");
}

/// The constant-evaluation square root is correctly rounded: equal to the f64 root rounded to
/// f32 (53 ≥ 2·24 + 2 bits, so that double rounding cannot move a square root), over random
/// positive normal numbers and every eighth number of [¼, 1), where the spherical Fibonacci
/// heights put it.
#[test]
fn the_constant_square_root_is_correctly_rounded() {
    let mut rng = Rng::new(29);
    let random = (0..2_000_000).map(|_| {
        let bits = (rng.next_u64() as u32) & 0x7fff_ffff;
        f32::from_bits(bits.clamp(0x0080_0000, 0x7f7f_ffff))
    });
    let quarter = (0.25f32.to_bits()..1.0f32.to_bits()).step_by(8).map(f32::from_bits);
    let mut checked = 0;
    for x in random.chain(quarter).chain([f32::MIN_POSITIVE, 1.0, 4.0, f32::MAX]) {
        let want = f64::from(x).sqrt() as f32;
        assert_eq!(sqrt_const(x).to_bits(), want.to_bits(), "sqrt({x:e})");
        checked += 1;
    }
    assert!(checked > 3_000_000);
}

/// `Probe::new` (a `const fn`) puts its directions where the run-time set does, bit for bit.
#[test]
fn a_constant_probe_has_the_run_time_directions() {
    const P16: Probe<16> = Probe::new();
    const P64: Probe<64, [f32; 3]> = Probe::new();
    static P256: Probe<256> = Probe::new();
    fn bits(d: &[sphere_quadrature::Vec3]) -> Vec<[u32; 3]> {
        d.iter().map(|v| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]).collect()
    }
    assert_eq!(bits(P16.directions()), bits(&SphericalFibonacci::<16>::new().points()));
    assert_eq!(bits(P64.directions()), bits(&SphericalFibonacci::<64>::new().points()));
    assert_eq!(bits(P256.directions()), bits(&SphericalFibonacci::<256>::new().points()));
    let p128 = Probe::<128>::new();
    assert_eq!(bits(p128.directions()), bits(&SphericalFibonacci::<128>::new().points()));
}
