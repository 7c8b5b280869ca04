//! Spherical Fibonacci point sets against the independent f64 reference.

use reference::rng::Rng;
use reference::vec::angle_between;
use sphere_quadrature::sf::{self, FibonacciPoints, GOLDEN_PHASE, MAX_POINTS};
use sphere_quadrature::{
    Error, FibonacciLattice, HemisphericalFibonacci, Mat3, RotationSequence, SphericalFibonacci,
    Vec3,
};

fn f64v(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// Largest angle between a point of the f32 set and the f64 reference point, in radians
/// (the bound; measured 1.4e-7 under both math backends, which share the point code).
const ANGLE_TOL: f64 = 2e-6;

/// Indices to check: all of them for small n, else the first and last 1000 and 20 000
/// seeded random ones.
fn sample_indices(n: usize, seed: u64) -> Vec<usize> {
    if n <= 70_000 {
        return (0..n).collect();
    }
    let mut rng = Rng::new(seed);
    let mut v: Vec<usize> = (0..1000).chain(n - 1000..n).collect();
    v.extend((0..20_000).map(|_| (rng.next_u64() % n as u64) as usize));
    v
}

fn max_error(set: &FibonacciPoints, reference: impl Fn(u64, u64) -> [f64; 3]) -> f64 {
    let n = set.len();
    let mut worst = 0.0f64;
    for j in sample_indices(n, n as u64) {
        let p = set.point(j).unwrap();
        let e = angle_between(f64v(p), reference(j as u64, n as u64));
        worst = worst.max(e);
    }
    worst
}

#[test]
fn sphere_points_match_reference() {
    for n in [1usize, 2, 3, 16, 1000, 1 << 16, 1 << 22, MAX_POINTS] {
        let worst = max_error(&FibonacciPoints::sphere(n).unwrap(), reference::sf::sphere_point);
        println!("sphere N = {n:>8}: max angle error {worst:.3e} rad");
        assert!(worst < ANGLE_TOL, "N = {n}: {worst:e} rad");
    }
}

#[test]
fn hemisphere_points_match_reference_and_spacing() {
    for n in [1usize, 2, 3, 16, 1000, 1 << 16, 1 << 22] {
        let set = FibonacciPoints::hemisphere(n).unwrap();
        let worst = max_error(&set, reference::sf::hemisphere_point);
        println!("hemisphere N = {n:>8}: max angle error {worst:.3e} rad");
        assert!(worst < ANGLE_TOL, "N = {n}: {worst:e} rad");
        for j in sample_indices(n, 7) {
            let zp = set.z_phi(j).unwrap();
            // The seed's heights: z_j = 1 − (2j+1)/(2N), all strictly positive.
            let exact = 1.0 - (2 * j + 1) as f64 / (2 * n) as f64;
            assert!(zp.z > 0.0, "N = {n}, j = {j}: z = {}", zp.z);
            // Two roundings (the quotient, then 1 − a): at most 2 ulp of 1.
            assert!((zp.z as f64 - exact).abs() <= 1.2e-7, "N = {n}, j = {j}");
            assert!(set.point(j).unwrap().z > 0.0);
        }
        // Consecutive heights are 1/N apart.
        if n >= 2 {
            let z0 = set.z_phi(0).unwrap().z as f64;
            let z1 = set.z_phi(1).unwrap().z as f64;
            assert!(((z0 - z1) - 1.0 / n as f64).abs() < 1e-7);
        }
    }
}

#[test]
fn lattice_matches_reference() {
    for n in [1usize, 2, 3, 89, 987, 6765, 317_811, 5_702_887] {
        let set = FibonacciPoints::lattice(n).unwrap();
        let worst = max_error(&set, reference::sf::lattice_point);
        println!("lattice N = {n:>8}: max angle error {worst:.3e} rad");
        assert!(worst < ANGLE_TOL, "N = {n}: {worst:e} rad");
    }
    assert_eq!(FibonacciPoints::lattice(90), Err(Error::InvalidSize));
}

#[test]
fn const_generic_sets_equal_runtime_sets() {
    let a = SphericalFibonacci::<1000>::new().points();
    let b = FibonacciPoints::sphere(1000).unwrap();
    assert!(a.iter().zip(b.iter()).all(|(p, q)| *p == q));
    let h = HemisphericalFibonacci::<77>::new();
    let hd = FibonacciPoints::hemisphere(77).unwrap();
    assert!(h.iter().zip(hd.iter()).all(|(p, q)| p == q));
    let l = FibonacciLattice::<233>::new();
    assert_eq!(l.points().len(), 233);
    assert!(l.iter().zip(FibonacciPoints::lattice(233).unwrap().iter()).all(|(p, q)| p == q));
}

#[test]
fn iteration_and_bounds() {
    let sf = SphericalFibonacci::<5>::new();
    assert_eq!(sf.iter().len(), 5);
    assert_eq!(sf.iter().count(), 5);
    let fwd: Vec<Vec3> = sf.iter().collect();
    let mut back: Vec<Vec3> = sf.iter().rev().collect();
    back.reverse();
    assert_eq!(fwd, back);
    assert_eq!(sf.point(4), Some(fwd[4]));
    assert_eq!(sf.point(5), None);
    assert_eq!(sf.z_phi(5), None);
    assert_eq!(FibonacciPoints::sphere(0), Err(Error::InvalidSize));
    assert_eq!(FibonacciPoints::hemisphere(MAX_POINTS + 1), Err(Error::InvalidSize));
    let mut out = [Vec3::ZERO; 8];
    assert_eq!(sf.dynamic().fill(&mut out), Err(Error::LengthMismatch));
    assert_eq!(out, [Vec3::ZERO; 8]);
    sf.dynamic().fill(&mut out[..5]).unwrap();
    assert_eq!(&out[..5], &fwd[..]);
    // N = 1: the single point sits on the equator (sphere) or at z = 1/2 (hemisphere).
    assert_eq!(SphericalFibonacci::<1>::new().points()[0], Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(HemisphericalFibonacci::<1>::new().z_phi(0).unwrap().z, 0.5);
}

#[test]
fn z_phi_form_matches_reference() {
    let set = FibonacciPoints::sphere(1 << 20).unwrap();
    let mut rng = Rng::new(3);
    for _ in 0..10_000 {
        let j = (rng.next_u64() % (1 << 20)) as usize;
        let zp = set.z_phi(j).unwrap();
        let (z, phi) = reference::sf::sphere_z_phi(j as u64, 1 << 20);
        assert!((0.0..core::f32::consts::TAU).contains(&zp.phi));
        assert!((zp.z as f64 - z).abs() < 1e-7);
        // Azimuth difference modulo 2π.
        let d = (zp.phi as f64 - phi).rem_euclid(std::f64::consts::TAU);
        assert!(d.min(std::f64::consts::TAU - d) < 8e-7, "j = {j}: {d:e}");
    }
}

#[test]
fn golden_phase_is_round_of_two_pow_64_over_phi() {
    // F₉₂/F₉₃ differs from 1/Φ by 1/(Φ·F₉₃²)·… ≈ 4·10⁻³⁹, i.e. 7·10⁻²⁰ units of 2⁻⁶⁴, while
    // 2⁶⁴/Φ = …485.9516 is 0.45 units from a rounding boundary: so round(2⁶⁴·F₉₂/F₉₃),
    // computed exactly in u128, is round(2⁶⁴/Φ).
    let (mut a, mut b) = (1u128, 1u128); // F₁, F₂
    for _ in 2..93 {
        (a, b) = (b, a + b);
    }
    assert_eq!(b, 12_200_160_415_121_876_738); // F₉₃
    let rounded = ((a << 64) + b / 2) / b;
    assert_eq!(GOLDEN_PHASE as u128, rounded);
    // And its top bits agree with the f64 value of 1/Φ.
    let inv_phi = 2.0 / (1.0 + 5f64.sqrt());
    assert!((GOLDEN_PHASE as f64 / 2f64.powi(64) - inv_phi).abs() < 1e-15);
}

#[test]
fn pole_rotation_is_exact_phase_shift() {
    let mut seq = RotationSequence::new(11);
    for n in [7usize, 64, 1 << 16] {
        let base = FibonacciPoints::sphere(n).unwrap();
        let bits = seq.next_phase();
        let rot = base.with_phase_bits(bits);
        let angle = bits as f64 / 2f64.powi(64) * std::f64::consts::TAU;
        for j in sample_indices(n, 5).into_iter().take(5000) {
            let p = reference::sf::sphere_point(j as u64, n as u64);
            let (s, c) = angle.sin_cos();
            let expected = [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]];
            let e = angle_between(f64v(rot.point(j).unwrap()), expected);
            assert!(e < ANGLE_TOL, "N = {n}, j = {j}: {e:e}");
        }
    }
    // Angle form agrees with bits form.
    let a = FibonacciPoints::sphere(100).unwrap().with_angle(1.0);
    let b = FibonacciPoints::sphere(100).unwrap().with_angle(1.0 + std::f32::consts::TAU);
    let e = angle_between(f64v(a.point(3).unwrap()), f64v(b.point(3).unwrap()));
    assert!(e < 1e-6);
    // Non-finite angles rotate nothing.
    let none = FibonacciPoints::sphere(100).unwrap();
    assert_eq!(none.with_angle(f32::NAN), none);
    assert_eq!(none.with_angle(f32::INFINITY), none);
}

#[test]
fn arbitrary_rotation_applies_matrix() {
    let mut rng = Rng::new(5);
    for _ in 0..20 {
        let m = rng.uniform_rotation();
        let mat = Mat3::from_rows(
            Vec3::new(m[0][0] as f32, m[0][1] as f32, m[0][2] as f32),
            Vec3::new(m[1][0] as f32, m[1][1] as f32, m[1][2] as f32),
            Vec3::new(m[2][0] as f32, m[2][1] as f32, m[2][2] as f32),
        );
        let set = SphericalFibonacci::<300>::new().with_rotation(mat).unwrap();
        for j in 0..300 {
            let expected = reference::vec::mat_mul_vec(m, reference::sf::sphere_point(j, 300));
            let e = angle_between(f64v(set.point(j as usize).unwrap()), expected);
            assert!(e < 4.0 * ANGLE_TOL, "{e:e}");
        }
    }
}

#[test]
fn rotation_sequence_is_deterministic_orthonormal_and_uniform() {
    let mut a = RotationSequence::new(42);
    let mut b = RotationSequence::new(42);
    let mut mean = [0.0f64; 3];
    let draws = 20_000;
    for _ in 0..draws {
        let r = a.next_rotation();
        assert_eq!(r, b.next_rotation());
        // Orthonormal rows, determinant +1.
        let [r0, r1, r2] = r.rows;
        for (u, v, d) in [(r0, r0, 1.0), (r1, r1, 1.0), (r2, r2, 1.0), (r0, r1, 0.0), (r1, r2, 0.0)]
        {
            assert!((u.dot(v) - d).abs() < 1e-5);
        }
        assert!((r0.cross(r1).dot(r2) - 1.0).abs() < 1e-5);
        let z = r * Vec3::Z;
        mean[0] += z.x as f64;
        mean[1] += z.y as f64;
        mean[2] += z.z as f64;
    }
    // A uniform rotation sends z to a uniform direction: each coordinate has mean 0 and
    // variance 1/3; allow 5 standard errors.
    let bound = 5.0 * (1.0f64 / 3.0 / draws as f64).sqrt();
    for m in mean {
        assert!((m / draws as f64).abs() < bound, "{mean:?}");
    }
    assert_ne!(RotationSequence::new(1).next_u64(), RotationSequence::new(2).next_u64());
}

#[test]
fn fibonacci_predecessor_rule() {
    assert_eq!(sf::fibonacci_predecessor(1), Some(1));
    assert_eq!(sf::fibonacci_predecessor(2), Some(1));
    assert_eq!(sf::fibonacci_predecessor(89), Some(55));
    assert_eq!(sf::fibonacci_predecessor(90), None);
    for n in [89u64, 5_702_887] {
        assert_eq!(
            sf::fibonacci_predecessor(n as usize).map(|p| p as u64),
            reference::sf::fibonacci_predecessor(n)
        );
    }
}
