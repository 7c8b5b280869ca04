//! A small, seeded, reproducible random number generator (SplitMix64) and the
//! sphere / rotation samplers that the tests need.
//!
//! SplitMix64 (Steele, Lea and Flood, 2014): the state advances by the odd constant
//! `0x9E37_79B9_7F4A_7C15` (2^64 / golden ratio) and each output is the state passed
//! through a 64-bit finaliser. It passes BigCrush and is ample for Monte Carlo checks.

use core::f64::consts::PI;

/// Seeded SplitMix64 generator.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// A generator whose sequence is fixed by `seed`.
    pub fn new(seed: u64) -> Self {
        Rng { state: seed }
    }

    /// Next 64 uniformly distributed bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)` with 53 random bits (a multiple of 2^-53).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform direction on the unit sphere (Archimedes: z uniform in [-1, 1]).
    pub fn uniform_sphere(&mut self) -> [f64; 3] {
        let z = 1.0 - 2.0 * self.next_f64(); // (-1, 1]
        let phi = 2.0 * PI * self.next_f64();
        let s = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
        [s * phi.cos(), s * phi.sin(), z]
    }

    /// Uniform direction on the upper hemisphere, `z > 0` (density 1/(2π)).
    pub fn uniform_hemisphere(&mut self) -> [f64; 3] {
        let z = 1.0 - self.next_f64(); // (0, 1]
        let phi = 2.0 * PI * self.next_f64();
        let s = ((1.0 - z) * (1.0 + z)).max(0.0).sqrt();
        [s * phi.cos(), s * phi.sin(), z]
    }

    /// Cosine-weighted direction on the upper hemisphere, `z > 0`, density cosθ/π.
    ///
    /// cos²θ is uniform on (0, 1] under that density (the cdf of cos²θ is
    /// ∫ 2 cosθ sinθ dθ = 1 − cos²θ), so z = √(1 − ξ), sinθ = √ξ.
    pub fn cosine_hemisphere(&mut self) -> [f64; 3] {
        let xi = self.next_f64(); // [0, 1)
        let z = (1.0 - xi).sqrt(); // (0, 1]
        let s = xi.sqrt();
        let phi = 2.0 * PI * self.next_f64();
        [s * phi.cos(), s * phi.sin(), z]
    }

    /// Uniformly distributed rotation matrix (Haar measure on SO(3)), as rows.
    ///
    /// Built from a uniform unit quaternion (Shoemake 1992: two independent uniform
    /// angles and a uniform split of the squared norm between the two complex halves).
    pub fn uniform_rotation(&mut self) -> [[f64; 3]; 3] {
        let u1 = self.next_f64();
        let a = 2.0 * PI * self.next_f64();
        let b = 2.0 * PI * self.next_f64();
        let s1 = (1.0 - u1).sqrt();
        let s2 = u1.sqrt();
        let (w, x, y, z) = (s1 * a.sin(), s1 * a.cos(), s2 * b.sin(), s2 * b.cos());
        [
            [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
            [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
            [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vec::{cross, dot, norm};

    #[test]
    fn splitmix_reference_values() {
        // First outputs of SplitMix64 seeded with 0 (as in Vigna's reference C code).
        let mut r = Rng::new(0);
        assert_eq!(r.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(r.next_u64(), 0x6E78_9E6A_A1B9_65F4);
    }

    #[test]
    fn samplers_are_on_the_right_domains_and_have_the_right_moments() {
        let mut r = Rng::new(7);
        let n = 200_000;
        let (mut mz_s, mut mz_h, mut mz_c, mut mzz_c) = (0.0, 0.0, 0.0, 0.0);
        for _ in 0..n {
            let f = r.next_f64();
            assert!((0.0..1.0).contains(&f));
            let s = r.uniform_sphere();
            assert!((norm(s) - 1.0).abs() < 1e-15);
            mz_s += s[2];
            let h = r.uniform_hemisphere();
            assert!(h[2] > 0.0 && (norm(h) - 1.0).abs() < 1e-15);
            mz_h += h[2];
            let c = r.cosine_hemisphere();
            assert!(c[2] > 0.0 && (norm(c) - 1.0).abs() < 1e-15);
            mz_c += c[2];
            mzz_c += c[2] * c[2];
        }
        let n = n as f64;
        // E[z]: sphere 0 (sd 1/√3), hemisphere 1/2 (sd 1/√12), cosine 2/3, E[z²] cosine 1/2.
        assert!((mz_s / n).abs() < 5.0 * (1.0f64 / 3.0).sqrt() / n.sqrt());
        assert!((mz_h / n - 0.5).abs() < 5.0 * (1.0f64 / 12.0).sqrt() / n.sqrt());
        assert!((mz_c / n - 2.0 / 3.0).abs() < 5.0 * (0.5f64 - 4.0 / 9.0).sqrt() / n.sqrt());
        assert!((mzz_c / n - 0.5).abs() < 5.0 * (1.0f64 / 12.0).sqrt() / n.sqrt());
    }

    #[test]
    fn rotations_are_proper_and_uniform() {
        let mut r = Rng::new(3);
        let n = 100_000;
        let mut mean = [[0.0; 3]; 3];
        for _ in 0..n {
            let m = r.uniform_rotation();
            for i in 0..3 {
                for j in 0..3 {
                    let d = dot(m[i], m[j]);
                    let want = if i == j { 1.0 } else { 0.0 };
                    assert!((d - want).abs() < 1e-14);
                    mean[i][j] += m[i][j];
                }
            }
            let det = dot(cross(m[0], m[1]), m[2]);
            assert!((det - 1.0).abs() < 1e-14);
        }
        // Every entry of a Haar rotation has mean 0 and variance 1/3.
        for row in mean {
            for v in row {
                assert!((v / n as f64).abs() < 5.0 * (1.0f64 / 3.0 / n as f64).sqrt());
            }
        }
    }
}
