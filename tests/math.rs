//! The crate's own math kernels against f64.

use reference::rng::Rng;
use sphere_quadrature::math::sin_cos_turns;

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
