//! The point sets the spherical Fibonacci sets are compared with: points of the unit square
//! mapped to the sphere by the equal-area Lambert cylindrical map.
//!
//! `lambert(u, v)`: `z = 1 − 2u`, `φ = 2πv` (Archimedes' hat-box theorem: equal areas of the
//! square go to equal areas of the sphere), as used by the seed's "current approach in CG"
//! (a unit-square set followed by a spherical projection).
//!
//! * [`uniform_random`]: independent uniform points of the square (SplitMix64);
//! * [`sobol`]: the 2-D Owen-scrambled Sobol (0,2)-sequence of `sobol_burley`;
//! * [`halton`]: the Halton sequence in bases 2 and 3, indices `1 … N` (index 0 is the corner
//!   `(0, 0)`, the pole);
//! * [`jittered_grid`]: one uniform random point in each cell of a `rows × cols` grid of the
//!   square, `rows · cols = N`, with the shape closest to square cells at the equator.

use std::f64::consts::PI;

use crate::rng::Rng;

/// The equal-area map of the unit square to the sphere: `z = 1 − 2u`, `φ = 2πv`.
pub fn lambert(u: f64, v: f64) -> [f64; 3] {
    let z = 1.0 - 2.0 * u;
    // 1 − z² = 4u(1 − u), exact near both poles.
    let s = (4.0 * u * (1.0 - u)).max(0.0).sqrt();
    let phi = 2.0 * PI * v;
    [s * phi.cos(), s * phi.sin(), z]
}

/// `n` independent uniform points (uniform on the sphere by the equal-area map).
pub fn uniform_random(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut r = Rng::new(seed);
    (0..n)
        .map(|_| {
            let u = r.next_f64();
            let v = r.next_f64();
            lambert(u, v)
        })
        .collect()
}

/// The first `n` points of the Owen-scrambled 2-D Sobol sequence with scramble `seed`.
pub fn sobol(n: usize, seed: u32) -> Vec<[f64; 3]> {
    (0..n as u32)
        .map(|i| {
            lambert(
                sobol_burley::sample(i, 0, seed) as f64,
                sobol_burley::sample(i, 1, seed) as f64,
            )
        })
        .collect()
}

/// The van der Corput radical inverse of `i` in `base`.
pub fn radical_inverse(mut i: u64, base: u64) -> f64 {
    let inv = 1.0 / base as f64;
    let mut f = inv;
    let mut x = 0.0;
    while i > 0 {
        x += (i % base) as f64 * f;
        i /= base;
        f *= inv;
    }
    x
}

/// Halton points `1 … n` in bases 2 (height) and 3 (azimuth).
pub fn halton(n: usize) -> Vec<[f64; 3]> {
    (1..=n as u64).map(|i| lambert(radical_inverse(i, 2), radical_inverse(i, 3))).collect()
}

/// The grid shape `(rows, cols)` for [`jittered_grid`]: the divisor `rows` of `n` closest (in
/// ratio) to `(n/π)^½`, so that cells near the equator are about square (`cols ≈ π·rows`).
pub fn grid_shape(n: usize) -> (usize, usize) {
    let target = (n as f64 / PI).sqrt();
    let rows = (1..=n)
        .filter(|&r| n % r == 0)
        .min_by(|&a, &b| {
            let da = (a as f64 / target).ln().abs();
            let db = (b as f64 / target).ln().abs();
            da.partial_cmp(&db).unwrap()
        })
        .unwrap_or(1);
    (rows, n / rows)
}

/// One uniform random point in each cell of the [`grid_shape`] grid of the square (rows
/// stratify the height, columns the azimuth), mapped by [`lambert`].
pub fn jittered_grid(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let (rows, cols) = grid_shape(n);
    let mut r = Rng::new(seed);
    let mut out = Vec::with_capacity(n);
    for i in 0..rows {
        for j in 0..cols {
            let u = (i as f64 + r.next_f64()) / rows as f64;
            let v = (j as f64 + r.next_f64()) / cols as f64;
            out.push(lambert(u, v));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vec::norm;

    #[test]
    fn lambert_is_equal_area_and_unit() {
        // Equal area: z = 1 − 2u is uniform when u is; check the band fractions of a grid.
        assert_eq!(lambert(0.0, 0.3), [0.0, 0.0, 1.0]);
        assert_eq!(lambert(1.0, 0.0)[2], -1.0);
        let p = lambert(0.25, 0.125);
        assert!((p[2] - 0.5).abs() < 1e-16 && (norm(p) - 1.0).abs() < 1e-15);
        assert!((p[0] - p[1]).abs() < 1e-15); // φ = π/4
    }

    #[test]
    fn radical_inverse_values() {
        let b2: Vec<f64> = (1..=4).map(|i| radical_inverse(i, 2)).collect();
        assert_eq!(b2, [0.5, 0.25, 0.75, 0.125]);
        let b3: Vec<f64> = (1..=4).map(|i| radical_inverse(i, 3)).collect();
        let want = [1.0 / 3.0, 2.0 / 3.0, 1.0 / 9.0, 4.0 / 9.0];
        assert!(b3.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-16));
    }

    #[test]
    fn sets_have_the_right_size_and_strata() {
        for n in [16usize, 64, 100, 1000, 4096] {
            assert_eq!(uniform_random(n, 1).len(), n);
            assert_eq!(sobol(n, 1).len(), n);
            assert_eq!(halton(n).len(), n);
            let (rows, cols) = grid_shape(n);
            assert_eq!(rows * cols, n);
            let g = jittered_grid(n, 2);
            // One point per cell: cell (i, j) from u = (1 − z)/2 and v = φ/(2π).
            let mut seen = vec![false; n];
            for p in &g {
                assert!((norm(*p) - 1.0).abs() < 1e-15);
                let u = (1.0 - p[2]) / 2.0;
                let v = p[1].atan2(p[0]).rem_euclid(2.0 * PI) / (2.0 * PI);
                let i = ((u * rows as f64) as usize).min(rows - 1);
                let j = ((v * cols as f64) as usize).min(cols - 1);
                assert!(!seen[i * cols + j], "n = {n}: cell ({i}, {j}) twice");
                seen[i * cols + j] = true;
            }
        }
        assert_eq!(grid_shape(4096), (32, 128));
        assert_eq!(grid_shape(64), (4, 16));
    }

    #[test]
    fn sobol_points_stratify_the_square() {
        // A (0, 2)-sequence: the first 2^k points put one point in each of 2^k elementary
        // intervals, e.g. 16 points fill a 4 × 4 grid of the square.
        let pts = sobol(16, 3);
        let mut seen = [false; 16];
        for p in pts {
            let u = (1.0 - p[2]) / 2.0;
            let v = p[1].atan2(p[0]).rem_euclid(2.0 * PI) / (2.0 * PI);
            let c = ((u * 4.0) as usize).min(3) * 4 + ((v * 4.0) as usize).min(3);
            assert!(!seen[c]);
            seen[c] = true;
        }
    }
}
