//! Real spherical harmonics from the textbook definitions, and the explicit projection of a
//! point set onto them.
//!
//! `Y_{l,0} = N_{l,0} P_l(cos θ)`, `Y_{l,m} = √2 N_{l,m} P_l^m(cos θ) cos mφ` and
//! `Y_{l,−m} = √2 N_{l,m} P_l^m(cos θ) sin mφ` for `m > 0`, with
//! `N_{l,m} = ((2l+1)/(4π) · (l−m)!/(l+m)!)^½`, orthonormal over the solid angle dΩ. The
//! associated Legendre functions carry no Condon–Shortley phase:
//! `P_l^m(x) = (1−x²)^{m/2} dᵐ/dxᵐ P_l(x)`, evaluated unnormalised by the classical
//! recurrences `P_m^m = (2m−1)!! (1−x²)^{m/2}`, `P_{m+1}^m = (2m+1) x P_m^m`,
//! `(l−m) P_l^m = (2l−1) x P_{l−1}^m − (l+m−1) P_{l−2}^m`, and normalised afterwards with the
//! factorial ratio (so degrees are limited to `l ≤ 80`, where `(l+m)!` still fits in f64).
//! The azimuth enters through `cos mφ`, `sin mφ` of `φ = atan2(y, x)`.

use std::f64::consts::PI;

/// Largest degree the unnormalised evaluation supports.
pub const MAX_DEGREE: usize = 80;

/// Legendre polynomial `P_l(x)` by Bonnet's recurrence.
pub fn legendre(l: usize, x: f64) -> f64 {
    let (mut p0, mut p1) = (1.0, x);
    if l == 0 {
        return 1.0;
    }
    for k in 1..l {
        let k = k as f64;
        let p2 = ((2.0 * k + 1.0) * x * p1 - k * p0) / (k + 1.0);
        p0 = p1;
        p1 = p2;
    }
    p1
}

/// Associated Legendre function `P_l^m(x)`, `0 ≤ m ≤ l ≤ 80`, without the Condon–Shortley
/// phase, with `(1 − x²)^{m/2}` passed in as `sin_theta^m` (so that it is accurate near the
/// poles).
pub fn assoc_legendre(l: usize, m: usize, x: f64, sin_theta: f64) -> f64 {
    assert!(m <= l && l <= MAX_DEGREE, "degree {l}, order {m} out of range");
    let mut pmm = 1.0;
    for i in 1..=m {
        pmm *= (2 * i - 1) as f64 * sin_theta;
    }
    if l == m {
        return pmm;
    }
    let mut p_prev = pmm;
    let mut p = (2 * m + 1) as f64 * x * pmm;
    for ll in m + 2..=l {
        let next = ((2 * ll - 1) as f64 * x * p - (ll + m - 1) as f64 * p_prev) / (ll - m) as f64;
        p_prev = p;
        p = next;
    }
    p
}

/// `N_{l,m} = ((2l+1)/(4π) · (l−m)!/(l+m)!)^½`.
fn normalisation(l: usize, m: usize) -> f64 {
    let mut ratio = 1.0; // (l−m)!/(l+m)!
    for j in (l - m + 1)..=(l + m) {
        ratio /= j as f64;
    }
    ((2 * l + 1) as f64 / (4.0 * PI) * ratio).sqrt()
}

/// Real spherical harmonic `Y_{l,m}(dir)` (`dir` unit, `|m| ≤ l ≤ 80`).
pub fn real_sh(l: usize, m: i64, dir: [f64; 3]) -> f64 {
    let [x, y, z] = dir;
    let sin_theta = x.hypot(y);
    let am = m.unsigned_abs() as usize;
    let p = normalisation(l, am) * assoc_legendre(l, am, z, sin_theta);
    if m == 0 {
        return p;
    }
    let phi = y.atan2(x);
    let mf = am as f64;
    if m > 0 {
        std::f64::consts::SQRT_2 * p * (mf * phi).cos()
    } else {
        std::f64::consts::SQRT_2 * p * (mf * phi).sin()
    }
}

/// `c_{l,m} = (1/N) Σₖ Y_{l,m}(ωₖ)` for `l ≤ l_max`, at index `l(l+1) + m`.
pub fn coefficients(points: &[[f64; 3]], l_max: usize) -> Vec<f64> {
    let mut c = vec![0.0; (l_max + 1) * (l_max + 1)];
    for &p in points {
        for l in 0..=l_max {
            for m in -(l as i64)..=(l as i64) {
                c[((l * (l + 1)) as i64 + m) as usize] += real_sh(l, m, p);
            }
        }
    }
    let n = points.len() as f64;
    c.iter_mut().for_each(|v| *v /= n);
    c
}

/// `C_l = (1/(2l+1)) Σₘ c_{l,m}²` by explicit projection onto the harmonics.
pub fn spectrum_by_projection(points: &[[f64; 3]], l_max: usize) -> Vec<f64> {
    let c = coefficients(points, l_max);
    (0..=l_max)
        .map(|l| {
            let row = &c[l * l..(l + 1) * (l + 1)];
            row.iter().map(|v| v * v).sum::<f64>() / (2 * l + 1) as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quad::gauss_legendre;
    use crate::rng::Rng;
    use crate::vec::dot;

    fn from_z_phi(z: f64, phi: f64) -> [f64; 3] {
        let s = ((1.0 - z) * (1.0 + z)).sqrt();
        [s * phi.cos(), s * phi.sin(), z]
    }

    #[test]
    fn low_degrees_match_closed_forms() {
        let mut r = Rng::new(5);
        for _ in 0..100 {
            let [x, y, z] = r.uniform_sphere();
            let d = [x, y, z];
            let c1 = (3.0 / (4.0 * PI)).sqrt();
            let want = [
                (0, 0, 0.5 / PI.sqrt()),
                (1, -1, c1 * y),
                (1, 0, c1 * z),
                (1, 1, c1 * x),
                (2, -2, (15.0 / (4.0 * PI)).sqrt() * x * y),
                (2, -1, (15.0 / (4.0 * PI)).sqrt() * y * z),
                (2, 0, (5.0 / (16.0 * PI)).sqrt() * (3.0 * z * z - 1.0)),
                (2, 1, (15.0 / (4.0 * PI)).sqrt() * x * z),
                (2, 2, (15.0 / (16.0 * PI)).sqrt() * (x * x - y * y)),
                (3, 0, (7.0 / (16.0 * PI)).sqrt() * z * (5.0 * z * z - 3.0)),
            ];
            for (l, m, v) in want {
                assert!((real_sh(l, m, d) - v).abs() < 1e-14, "Y_{l},{m}");
            }
        }
    }

    #[test]
    fn harmonics_are_orthonormal_under_exact_quadrature() {
        // Gauss–Legendre in z (exact to degree 2·26 − 1) times the trapezoid rule in φ
        // (exact for |frequency| < 60): exact for products of degree ≤ 2·12.
        let l_max = 12;
        let (zs, wz) = gauss_legendre(26);
        let n_phi = 60;
        let k = (l_max + 1) * (l_max + 1);
        let mut gram = vec![0.0; k * k];
        let mut y = vec![0.0; k];
        for (&z, &w) in zs.iter().zip(&wz) {
            for j in 0..n_phi {
                let phi = 2.0 * PI * j as f64 / n_phi as f64;
                let d = from_z_phi(z, phi);
                for l in 0..=l_max {
                    for m in -(l as i64)..=(l as i64) {
                        y[((l * (l + 1)) as i64 + m) as usize] = real_sh(l, m, d);
                    }
                }
                let wt = w * 2.0 * PI / n_phi as f64;
                for a in 0..k {
                    for b in 0..k {
                        gram[a * k + b] += wt * y[a] * y[b];
                    }
                }
            }
        }
        for a in 0..k {
            for b in 0..k {
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((gram[a * k + b] - want).abs() < 1e-13, "({a}, {b}): {}", gram[a * k + b]);
            }
        }
    }

    #[test]
    fn addition_theorem_holds_and_projection_spectrum_is_consistent() {
        let mut r = Rng::new(9);
        for _ in 0..50 {
            let (a, b) = (r.uniform_sphere(), r.uniform_sphere());
            for l in [0usize, 1, 2, 7, 20, 40, 80] {
                let s: f64 =
                    (-(l as i64)..=(l as i64)).map(|m| real_sh(l, m, a) * real_sh(l, m, b)).sum();
                let want = (2 * l + 1) as f64 / (4.0 * PI) * legendre(l, dot(a, b));
                assert!((s - want).abs() < 1e-12 * (2 * l + 1) as f64, "l = {l}: {s} vs {want}");
            }
        }
        // One point: C_l = (1/(2l+1)) Σ_m Y² = 1/(4π) for every l.
        let c = spectrum_by_projection(&[[0.6, 0.0, 0.8]], 10);
        assert!(c.iter().all(|v| (v - 1.0 / (4.0 * PI)).abs() < 1e-15));
    }

    #[test]
    fn legendre_matches_explicit_polynomials() {
        for i in 0..=20 {
            let x = -1.0 + 0.1 * i as f64;
            assert!((legendre(2, x) - 0.5 * (3.0 * x * x - 1.0)).abs() < 1e-15);
            let p5 = (63.0 * x.powi(5) - 70.0 * x.powi(3) + 15.0 * x) / 8.0;
            assert!((legendre(5, x) - p5).abs() < 1e-14);
        }
        assert_eq!(legendre(30, 1.0), 1.0);
        assert!((legendre(31, -1.0) + 1.0).abs() < 1e-14);
    }
}
