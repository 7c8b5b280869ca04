//! Spherical Fibonacci point sets in f64, evaluated from their definitions.
//!
//! * sphere, n points, j = 0..n: z_j = 1 − (2j + 1)/n, φ_j = 2π·frac(j/Φ);
//! * hemisphere, n points: z_j = 1 − (2j + 1)/(2n), same φ_j;
//! * Fibonacci lattice, n = F_m: sphere z_j, φ_j = 2π·((j·F_{m−1}) mod F_m)/F_m.
//!
//! Φ = (1 + √5)/2, so 1/Φ = Φ − 1 = (√5 − 1)/2. frac(j/Φ) is evaluated in double-double
//! arithmetic (1/Φ = hi + lo, j·hi split exactly by a fused multiply-add), so the phase
//! is accurate to about 1e-16 turn for j < 2^53 (and ≈ j·1e-33 turn beyond).
//! z_j is a ratio of exactly represented integers (one rounding) and sinθ_j is
//! √((1 − z)(1 + z)) with both factors formed from integers, which keeps full relative
//! precision at both poles.

use core::f64::consts::PI;

/// f64 nearest to 1/Φ = (√5 − 1)/2 = 0.61803398874989484820458683436563811772…
const INV_PHI_HI: f64 = 0.618_033_988_749_894_9;
/// 1/Φ − INV_PHI_HI (from the 45-digit decimal expansion above).
const INV_PHI_LO: f64 = -5.432_115_203_682_506e-17;

/// frac(m·(hi + lo)) in [0, 1) for an integer-valued `m` < 2^53.
fn frac_dd(m: f64, hi: f64, lo: f64) -> f64 {
    let p = m * hi;
    let err = m.mul_add(hi, -p); // m·hi = p + err exactly
                                 // Fractional parts extracted exactly: |err| ≤ ulp(p)/2 is itself an integer plus an
                                 // exact fraction once it is ≥ 1; below 1 it is kept as it is.
    let fe = if err.abs() >= 1.0 { err - err.trunc() } else { err };
    let f = (p - p.floor()) + fe + m * lo;
    wrap_unit(f)
}

fn wrap_unit(mut f: f64) -> f64 {
    f -= f.floor();
    if f >= 1.0 {
        f -= 1.0;
    }
    if f < 0.0 {
        f += 1.0;
    }
    if f >= 1.0 {
        0.0
    } else {
        f
    }
}

/// frac(j/Φ) = frac(j·0.6180339887…) in [0, 1) (turns).
pub fn golden_phase(j: u64) -> f64 {
    const TWO53: u64 = 1 << 53;
    if j < TWO53 {
        frac_dd(j as f64, INV_PHI_HI, INV_PHI_LO)
    } else {
        // j = jh·2^26 + jl; 2^26·(hi + lo) is exact in double-double.
        let jh = (j >> 26) as f64;
        let jl = (j & ((1 << 26) - 1)) as f64;
        let s = (1u64 << 26) as f64;
        wrap_unit(frac_dd(jh, INV_PHI_HI * s, INV_PHI_LO * s) + frac_dd(jl, INV_PHI_HI, INV_PHI_LO))
    }
}

fn turns_to_phi(t: f64) -> f64 {
    let phi = 2.0 * PI * t;
    if phi >= 2.0 * PI {
        0.0
    } else {
        phi
    }
}

fn from_parts(z: f64, sin_theta: f64, phi: f64) -> [f64; 3] {
    let (s, c) = phi.sin_cos();
    [sin_theta * c, sin_theta * s, z]
}

/// (z_j, sinθ_j) of the sphere set.
fn sphere_z_sin(j: u64, n: u64) -> (f64, f64) {
    assert!(j < n, "index {j} out of range for {n} points");
    let nf = n as f64;
    let z = (n as i128 - 2 * j as i128 - 1) as f64 / nf;
    let a = (2 * j as u128 + 1) as f64 / nf; // 1 − z
    let b = (2 * (n - j) as u128 - 1) as f64 / nf; // 1 + z
    (z, (a * b).sqrt())
}

/// (z_j, sinθ_j) of the hemisphere set.
fn hemisphere_z_sin(j: u64, n: u64) -> (f64, f64) {
    assert!(j < n, "index {j} out of range for {n} points");
    let d = 2.0 * n as f64;
    let z = (2 * (n - j) as u128 - 1) as f64 / d;
    let a = (2 * j as u128 + 1) as f64 / d; // 1 − z
    let b = (4 * n as u128 - 2 * j as u128 - 1) as f64 / d; // 1 + z
    (z, (a * b).sqrt())
}

/// z_j = 1 − (2j + 1)/n of the sphere set.
pub fn sphere_z(j: u64, n: u64) -> f64 {
    sphere_z_sin(j, n).0
}

/// z_j = 1 − (2j + 1)/(2n) of the hemisphere set.
pub fn hemisphere_z(j: u64, n: u64) -> f64 {
    hemisphere_z_sin(j, n).0
}

/// (z_j, φ_j) of the sphere set, φ_j = 2π·frac(j/Φ) in [0, 2π).
pub fn sphere_z_phi(j: u64, n: u64) -> (f64, f64) {
    (sphere_z(j, n), turns_to_phi(golden_phase(j)))
}

/// (z_j, φ_j) of the hemisphere set, φ_j in [0, 2π).
pub fn hemisphere_z_phi(j: u64, n: u64) -> (f64, f64) {
    (hemisphere_z(j, n), turns_to_phi(golden_phase(j)))
}

/// Point j (0 ≤ j < n) of the n-point spherical Fibonacci set on the sphere.
pub fn sphere_point(j: u64, n: u64) -> [f64; 3] {
    let (z, s) = sphere_z_sin(j, n);
    from_parts(z, s, turns_to_phi(golden_phase(j)))
}

/// Point j (0 ≤ j < n) of the n-point spherical Fibonacci set on the upper hemisphere
/// (z > 0).
pub fn hemisphere_point(j: u64, n: u64) -> [f64; 3] {
    let (z, s) = hemisphere_z_sin(j, n);
    from_parts(z, s, turns_to_phi(golden_phase(j)))
}

/// If `n` is a Fibonacci number F_m (1, 2, 3, 5, 8, …), its predecessor F_{m−1}
/// (for n = 1 this returns 1, F_1 = F_2 = 1); otherwise `None`.
pub fn fibonacci_predecessor(n: u64) -> Option<u64> {
    let (mut a, mut b) = (1u64, 1u64);
    while b < n {
        let c = a.checked_add(b)?;
        a = b;
        b = c;
    }
    (b == n).then_some(a)
}

/// (z_j, φ_j) of the Fibonacci lattice with n = F_m points:
/// φ_j = 2π·((j·F_{m−1}) mod F_m)/F_m, z_j as for the sphere set.
///
/// # Panics
/// If `n` is not a Fibonacci number or `j >= n`.
pub fn lattice_z_phi(j: u64, n: u64) -> (f64, f64) {
    let p = fibonacci_predecessor(n).unwrap_or_else(|| panic!("{n} is not a Fibonacci number"));
    let r = (j as u128 * p as u128) % n as u128;
    (sphere_z(j, n), turns_to_phi(r as f64 / n as f64))
}

/// Point j of the spherical Fibonacci lattice with n = F_m points (see
/// [`lattice_z_phi`]).
///
/// # Panics
/// If `n` is not a Fibonacci number or `j >= n`.
pub fn lattice_point(j: u64, n: u64) -> [f64; 3] {
    let (_, phi) = lattice_z_phi(j, n);
    let (z, s) = sphere_z_sin(j, n);
    from_parts(z, s, phi)
}

/// Result of an exact nearest-point search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nearest {
    /// Index of the nearest point (the smallest such index would not be guaranteed on an
    /// exact tie; compare `dist` and `second_dist` to detect ties).
    pub index: u64,
    /// Chord (Euclidean) distance from the normalised query to that point.
    pub dist: f64,
    /// Chord distance to the second nearest point (`f64::INFINITY` when n = 1).
    pub second_dist: f64,
}

fn chord(p: [f64; 3], q: [f64; 3]) -> f64 {
    let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// Exact nearest/second-nearest search for a set whose z is strictly decreasing in j.
///
/// Any point within chord distance d of q has |z_j − q_z| ≤ d. Indices are visited in
/// order of increasing |z_j − q_z| (two pointers moving away from the index whose z is
/// nearest q_z); the scan stops once that gap exceeds the current second-best distance,
/// so it is exact and costs O(d·n) point evaluations plus the start-up.
fn nearest_monotone(
    q: [f64; 3],
    n: u64,
    j0: u64,
    z_of: impl Fn(u64) -> f64,
    point: impl Fn(u64) -> [f64; 3],
) -> Nearest {
    assert!(n >= 1, "empty point set");
    let len = crate::vec::norm(q);
    assert!(len > 0.0 && len.is_finite(), "query must be a non-zero finite vector");
    let q = crate::vec::normalize(q);
    let mut best = (u64::MAX, f64::INFINITY);
    let mut second = f64::INFINITY;
    let mut consider = |j: u64| {
        let d = chord(point(j), q);
        if d < best.1 {
            second = best.1;
            best = (j, d);
        } else if d < second {
            second = d;
        }
        second
    };
    // `down` is the next index to visit going towards 0 (if any), `up` going towards n.
    let j0 = j0.min(n - 1);
    let mut down: Option<u64> = Some(j0);
    let mut up: Option<u64> = if j0 + 1 < n { Some(j0 + 1) } else { None };
    let mut bound = f64::INFINITY;
    loop {
        let gd = down.map(|j| (z_of(j) - q[2]).abs());
        let gu = up.map(|j| (z_of(j) - q[2]).abs());
        let take_down = match (gd, gu) {
            (None, None) => break,
            (Some(_), None) => true,
            (None, Some(_)) => false,
            (Some(a), Some(b)) => a <= b,
        };
        let gap = if take_down { gd.unwrap() } else { gu.unwrap() };
        // Margin for rounding in the chord (it can come out an ulp below |Δz|).
        if gap > bound * (1.0 + 1e-12) {
            break;
        }
        if take_down {
            let j = down.unwrap();
            bound = consider(j);
            down = j.checked_sub(1);
        } else {
            let j = up.unwrap();
            bound = consider(j);
            up = if j + 1 < n { Some(j + 1) } else { None };
        }
    }
    Nearest { index: best.0, dist: best.1, second_dist: second }
}

/// Exact nearest (and second nearest) point of the n-point spherical Fibonacci sphere set
/// to the direction of `q` (normalised first), by chord distance, with z-band pruning.
pub fn nearest_brute_force(q: [f64; 3], n: u64) -> Nearest {
    let qz = crate::vec::normalize(q)[2];
    // z_j = 1 − (2j + 1)/n = qz  ⇔  j = (n(1 − qz) − 1)/2
    let j0 = ((n as f64 * (1.0 - qz) - 1.0) * 0.5).round().clamp(0.0, (n - 1) as f64) as u64;
    nearest_monotone(q, n, j0, |j| sphere_z(j, n), |j| sphere_point(j, n))
}

/// Exact nearest (and second nearest) point of the n-point spherical Fibonacci hemisphere
/// set to the direction of `q` (normalised first; it may point below the horizon).
pub fn nearest_brute_force_hemisphere(q: [f64; 3], n: u64) -> Nearest {
    let qz = crate::vec::normalize(q)[2];
    // z_j = 1 − (2j + 1)/(2n) = qz  ⇔  j = (2n(1 − qz) − 1)/2
    let j0 = ((2.0 * n as f64 * (1.0 - qz) - 1.0) * 0.5).round().clamp(0.0, (n - 1) as f64) as u64;
    nearest_monotone(q, n, j0, |j| hemisphere_z(j, n), |j| hemisphere_point(j, n))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::vec::norm;

    #[test]
    fn inverse_golden_ratio_constant() {
        // hi is the nearest double and |lo| < ulp(hi)/2.
        let c = (5f64.sqrt() - 1.0) / 2.0;
        assert_eq!(INV_PHI_HI, c);
        assert!(INV_PHI_LO.abs() < 0.5 * f64::EPSILON * 0.5);
        // Φ⁻² = 1 − Φ⁻¹: hi² + 2·hi·lo + hi − 1 ≈ 0 in double-double.
        let sq = INV_PHI_HI * INV_PHI_HI;
        let sq_err = INV_PHI_HI.mul_add(INV_PHI_HI, -sq);
        let r = ((sq - 1.0) + INV_PHI_HI) + (sq_err + 2.0 * INV_PHI_HI * INV_PHI_LO + INV_PHI_LO);
        assert!(r.abs() < 1e-31, "{r:e}");
    }

    #[test]
    fn golden_phase_matches_exact_rational_arithmetic() {
        // frac(j/Φ) vs (j·p mod q)/q with the convergent p/q = F_90/F_91 of 1/Φ,
        // |1/Φ − p/q| < 1/q² ≈ 1e-38, so j·(1/Φ − p/q) < 1e-30 for every j tested.
        let (mut a, mut b) = (1u128, 1u128);
        for _ in 0..89 {
            let c = a + b;
            a = b;
            b = c;
        }
        let (p, q) = (a, b); // consecutive Fibonacci numbers
        let mut r = Rng::new(5);
        let mut js: Vec<u64> = (0..2000).map(|_| r.next_u64() >> 40).collect();
        js.extend([0, 1, 2, 3, (1 << 24) - 1, 1 << 24, 12_345_678, (1 << 40) + 17]);
        for j in js {
            let num = (j as u128 * p) % q;
            // num/q to ~1e-17 via long division in integers.
            let t = ((num << 20) / q) as f64 / (1u64 << 20) as f64;
            let rem = ((num << 20) % q) as f64 / q as f64 / (1u64 << 20) as f64;
            let want = t + rem;
            let got = golden_phase(j);
            let d = (got - want).abs().min(1.0 - (got - want).abs());
            assert!(d < 2e-16 + j as f64 * 1e-30, "j={j}: {got} vs {want}");
        }
    }

    #[test]
    fn points_are_unit_and_hemisphere_is_upper() {
        for n in [1u64, 2, 3, 10, 1000, 1 << 20] {
            let step = (n / 1000).max(1);
            let mut j = 0;
            while j < n {
                let p = sphere_point(j, n);
                assert!((norm(p) - 1.0).abs() < 4e-16, "n={n} j={j}");
                let h = hemisphere_point(j, n);
                assert!(h[2] > 0.0 && (norm(h) - 1.0).abs() < 4e-16);
                let (z, phi) = sphere_z_phi(j, n);
                assert!((0.0..2.0 * PI).contains(&phi) && z == p[2]);
                j += step;
            }
            // Last points next to the poles keep their tiny sinθ to full precision.
            let p = sphere_point(n - 1, n);
            let s = (p[0] * p[0] + p[1] * p[1]).sqrt();
            let want = ((2.0 * n as f64 - 1.0) / (n as f64 * n as f64)).sqrt();
            assert!((s / want - 1.0).abs() < 1e-15);
        }
        assert_eq!(sphere_point(0, 1), [1.0, 0.0, 0.0]);
    }

    #[test]
    fn lattice_matches_rational_evaluation() {
        assert_eq!(fibonacci_predecessor(89), Some(55));
        assert_eq!(fibonacci_predecessor(1), Some(1));
        assert_eq!(fibonacci_predecessor(2), Some(1));
        assert_eq!(fibonacci_predecessor(90), None);
        assert_eq!(fibonacci_predecessor(0), None);
        assert_eq!(
            fibonacci_predecessor(12_200_160_415_121_876_738),
            Some(7_540_113_804_746_346_429)
        );
        assert_eq!(fibonacci_predecessor(u64::MAX), None);
        let n = 89;
        for j in 0..n {
            let phi = 2.0 * PI * ((j * 55) % 89) as f64 / 89.0;
            let z = 1.0 - (2 * j + 1) as f64 / 89.0;
            let s = (1.0 - z * z).sqrt();
            let want = [s * phi.cos(), s * phi.sin(), z];
            let got = lattice_point(j, n);
            for k in 0..3 {
                assert!((got[k] - want[k]).abs() < 1e-15, "j={j}");
            }
        }
    }

    fn naive(q: [f64; 3], n: u64, point: impl Fn(u64) -> [f64; 3]) -> Nearest {
        let q = crate::vec::normalize(q);
        let mut best = (u64::MAX, f64::INFINITY);
        let mut second = f64::INFINITY;
        for j in 0..n {
            let d = chord(point(j), q);
            if d < best.1 {
                second = best.1;
                best = (j, d);
            } else if d < second {
                second = d;
            }
        }
        Nearest { index: best.0, dist: best.1, second_dist: second }
    }

    #[test]
    fn nearest_agrees_with_naive_scan() {
        let mut r = Rng::new(99);
        for n in [1u64, 2, 7, 100, 5000] {
            for i in 0..2000 {
                let mut q = r.uniform_sphere();
                if i % 3 == 0 {
                    q = crate::vec::scale(q, 3.7); // non-unit queries are normalised
                }
                if i == 0 {
                    q = [0.0, 0.0, 1.0];
                }
                if i == 1 {
                    q = [0.0, 0.0, -1.0];
                }
                let a = nearest_brute_force(q, n);
                let b = naive(q, n, |j| sphere_point(j, n));
                assert_eq!(a.dist, b.dist, "n={n} q={q:?}");
                assert_eq!(a.second_dist, b.second_dist, "n={n} q={q:?}");
                assert!(a.index == b.index || a.dist == a.second_dist);
                let a = nearest_brute_force_hemisphere(q, n);
                let b = naive(q, n, |j| hemisphere_point(j, n));
                assert_eq!(a.dist, b.dist, "hemi n={n} q={q:?}");
                assert_eq!(a.second_dist, b.second_dist, "hemi n={n} q={q:?}");
                assert!(a.index == b.index || a.dist == a.second_dist);
            }
        }
    }

    #[test]
    fn nearest_is_cheap_for_large_n() {
        // O(d·n) ≈ O(√n) work: a million-point set answers quickly even in debug builds.
        let mut r = Rng::new(1);
        let n = 1u64 << 24;
        for _ in 0..50 {
            let q = r.uniform_sphere();
            let a = nearest_brute_force(q, n);
            assert!(a.dist < 4.0 / (n as f64).sqrt());
            assert!(a.dist <= a.second_dist);
        }
    }
}
