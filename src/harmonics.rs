//! Real spherical harmonics `Y_lm`, orthonormal over the sphere, without the Condon–Shortley
//! phase, at index `l(l + 1) + m` (the basis of [`crate::sh`]): the degree-2 closed form and
//! the recurrence to any degree.
//!
//! `Y_l0 = Q_l^0(z)`, `Y_lm = Q_l^m(z)·Re (x + iy)ᵐ` and `Y_{l,−m} = Q_l^m(z)·Im (x + iy)ᵐ`
//! (`m > 0`): the factor `sinᵐθ·e^{imφ}` is carried by `(x + iy)ᵐ`, so no trigonometric
//! function is called and the poles need no special case. `Q_m^m` is a constant
//! ([`Factors::sectorals`]) and `Q_l^m = a·(z·Q_{l−1}^m − b·Q_{l−2}^m)` ([`Factors::pairs`],
//! [`step`]). The temporal probe runs the recurrence in f32 from [`Tables`] (degree ≤ 8), the
//! metrics in f64 from [`Computed`] (any degree).

use crate::legendre::Real;
use crate::vec3::Vec3;

/// `Y₀₀ = ½·√(1/π)`.
const Y00: f64 = 0.282_094_791_773_878_14;
/// `½·√(3/π)`, the degree-1 constant.
const Y1: f64 = 0.488_602_511_902_919_9;
/// `½·√(15/π)`, the constant of `xy`, `yz`, `xz`.
const Y2: f64 = 1.092_548_430_592_079_2;
/// `¼·√(5/π)`, the constant of `3z² − 1`.
const Y20: f64 = 0.315_391_565_252_520_05;
/// `¼·√(15/π)`, the constant of `x² − y²`.
const Y22: f64 = 0.546_274_215_296_039_6;

/// The constants of the degree-2 harmonics per index, in f64: `Y_lm = CONSTANTS64[k]·p_k`
/// with the [`polynomials64`] `p`.
pub(crate) const CONSTANTS64: [f64; 9] = [Y00, Y1, Y1, Y1, Y2, Y2, Y20, Y2, Y22];

/// [`CONSTANTS64`] rounded once to f32.
pub(crate) const CONSTANTS: [f32; 9] = {
    let mut c = [0.0f32; 9];
    let mut k = 0;
    while k < 9 {
        c[k] = CONSTANTS64[k] as f32;
        k += 1;
    }
    c
};

/// The degree of each index below 9.
pub(crate) const DEGREE: [usize; 9] = [0, 1, 1, 1, 2, 2, 2, 2, 2];

/// The polynomials `(1, y, z, x, xy, yz, 3z² − 1, xz, x² − y²)` of the degree-2 harmonics
/// (without their [`CONSTANTS`]) at a unit direction.
pub(crate) const fn polynomials(u: Vec3) -> [f32; 9] {
    let Vec3 { x, y, z } = u;
    [1.0, y, z, x, x * y, y * z, 3.0 * (z * z) - 1.0, x * z, x * x - y * y]
}

/// [`polynomials`] in f64.
pub(crate) fn polynomials64(u: [f64; 3]) -> [f64; 9] {
    let [x, y, z] = u;
    [1.0, y, z, x, x * y, y * z, 3.0 * (z * z) - 1.0, x * z, x * x - y * y]
}

/// The 9 harmonics of degree ≤ 2 at a unit direction.
pub(crate) const fn degree2(u: Vec3) -> [f32; 9] {
    let p = polynomials(u);
    let mut y = [0.0f32; 9];
    let mut k = 0;
    while k < 9 {
        y[k] = CONSTANTS[k] * p[k];
        k += 1;
    }
    y
}

/// The zonal harmonics `Y_l0`, `l ≤ 2`, at `z` (the 0th, 2nd and 6th of [`degree2`]).
pub(crate) const fn zonal(z: f32) -> [f32; 3] {
    [CONSTANTS[0], CONSTANTS[2] * z, CONSTANTS[6] * (3.0 * (z * z) - 1.0)]
}

/// The factors of the recurrence, in the precision `R` of their source.
pub(crate) trait Factors {
    /// The float type of the recurrence.
    type R: Real;
    /// `Q_m^m = √((2m + 1)/(4π)·Π_{i ≤ m} (2i − 1)/(2i))`, times `√2` for `m > 0`, for the
    /// orders `m ≤ degree`, in order.
    fn sectorals(&self, degree: usize) -> impl Iterator<Item = Self::R>;
    /// `(a, b)` of [`step`] for the degrees `m < l ≤ degree`, in order:
    /// `a = √((4l² − 1)/(l² − m²))`, `b = √(((l − 1)² − m²)/(4(l − 1)² − 1))`, `0` for
    /// `l = m + 1`.
    fn pairs(&self, m: usize, degree: usize) -> impl Iterator<Item = (Self::R, Self::R)>;
}

/// `Q_l^m = a·(z·Q_{l−1}^m − b·Q_{l−2}^m)`.
#[inline]
pub(crate) fn step<R: Real>((a, b): (R, R), z: R, q1: R, q2: R) -> R {
    a * (z * q1 - b * q2)
}

/// The factors computed in f64, any degree.
pub(crate) struct Computed;

impl Factors for Computed {
    type R = f64;

    fn sectorals(&self, degree: usize) -> impl Iterator<Item = f64> {
        (0..=degree).map(Computed::sectoral)
    }

    fn pairs(&self, m: usize, degree: usize) -> impl Iterator<Item = (f64, f64)> {
        (m + 1..=degree).map(move |l| Computed::pair(l, m))
    }
}

impl Computed {
    /// `Q_m^m` ([`Factors::sectorals`]).
    fn sectoral(m: usize) -> f64 {
        let mut product = (2 * m + 1) as f64 / (4.0 * core::f64::consts::PI);
        for i in 1..=m {
            product *= (2 * i - 1) as f64 / (2 * i) as f64;
        }
        let q = crate::math::sqrt64(product);
        if m > 0 {
            q * core::f64::consts::SQRT_2
        } else {
            q
        }
    }

    /// The pair of degree `l` and order `m < l` ([`Factors::pairs`]).
    fn pair(l: usize, m: usize) -> (f64, f64) {
        let (lf, mf) = (l as f64, m as f64);
        let a = crate::math::sqrt64((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf));
        if l == m + 1 {
            return (a, 0.0);
        }
        let k = lf - 1.0;
        (a, crate::math::sqrt64((k * k - mf * mf) / (4.0 * k * k - 1.0)))
    }
}

/// The highest degree of [`Tables`].
pub(crate) const TABLE_DEGREE: usize = 8;

/// The factors of [`Computed`] rounded once to f32, degree ≤ [`TABLE_DEGREE`] (the unit tests
/// below recompute them).
pub(crate) struct Tables;

/// [`Factors::sectorals`] of [`Tables`].
const SECTORAL: [f32; TABLE_DEGREE + 1] = [
    0.2820948, 0.48860252, 0.54627424, 0.5900436, 0.6258357, 0.6563821, 0.6831841, 0.70716274,
    0.72892666,
];

/// [`Factors::pairs`] of [`Tables`] for `m < l ≤ 8`, by `m` then `l`.
#[rustfmt::skip]
const PAIRS: [(f32, f32); 36] = [
    (1.7320508, 0.0), (1.9364917, 0.57735026),
    (1.9720266, 0.5163978), (1.9843135, 0.50709254),
    (1.9899749, 0.5039526), (1.9930434, 0.5025189),
    (1.9948914, 0.5017452), (1.9960899, 0.5012804),
    (2.236068, 0.0), (2.09165, 0.4472136),
    (2.04939, 0.47809145), (2.0310097, 0.48795003),
    (2.021315, 0.49236596), (2.0155644, 0.49472743),
    (2.0118694, 0.49613893), (2.6457512, 0.0),
    (2.291288, 0.37796447), (2.1712406, 0.4364358),
    (2.113942, 0.4605662), (2.081666, 0.4730499),
    (2.0615528, 0.48038447), (3.0, 0.0),
    (2.4874685, 0.33333334), (2.3013682, 0.40201512),
    (2.20794, 0.4345241), (2.1532216, 0.4529108),
    (3.3166249, 0.0), (2.6739483, 0.30151135),
    (2.4308622, 0.3739788), (2.304886, 0.41137668),
    (3.6055512, 0.0), (2.8504386, 0.2773501),
    (2.5570416, 0.3508232), (3.8729835, 0.0),
    (3.0178044, 0.2581989), (4.1231055, 0.0),
];

impl Tables {
    /// The pairs of order `m` for the degrees `m < l ≤ degree` (`degree ≤ 8`), in order.
    pub(crate) fn slice(m: usize, degree: usize) -> &'static [(f32, f32)] {
        // Order m starts after the orders below it, each with TABLE_DEGREE − k pairs.
        let start = m * TABLE_DEGREE - m * m.saturating_sub(1) / 2;
        PAIRS.get(start..start + degree.saturating_sub(m)).unwrap_or(&[])
    }
}

impl Factors for Tables {
    type R = f32;

    fn sectorals(&self, degree: usize) -> impl Iterator<Item = f32> {
        SECTORAL.iter().copied().take(degree + 1)
    }

    fn pairs(&self, m: usize, degree: usize) -> impl Iterator<Item = (f32, f32)> {
        Tables::slice(m, degree).iter().copied()
    }
}

/// Calls `emit(l(l + 1) + m, Y_lm(u))` for every `l ≤ degree`, `|m| ≤ l`, at a unit `u`, by the
/// recurrence with the factors of `factors` (whose degree must reach `degree`).
pub(crate) fn for_each<F: Factors>(
    factors: &F,
    u: [F::R; 3],
    degree: usize,
    mut emit: impl FnMut(usize, F::R),
) {
    let [x, y, z] = u;
    let (mut c, mut s) = (F::R::ONE, F::R::ZERO);
    for (m, sectoral) in factors.sectorals(degree).enumerate() {
        if m > 0 {
            (c, s) = (c * x - s * y, s * x + c * y);
        }
        let mut put = |i: usize, q: F::R| {
            if m == 0 {
                emit(i, q);
            } else {
                emit(i + m, q * c);
                emit(i - m, q * s);
            }
        };
        let (mut q2, mut q1) = (F::R::ZERO, sectoral);
        let mut i = m * (m + 1);
        put(i, q1);
        for (l, pair) in (m + 1..).zip(factors.pairs(m, degree)) {
            let q = step(pair, z, q1, q2);
            (q2, q1) = (q1, q);
            i += 2 * l;
            put(i, q);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::vec::Vec;

    #[test]
    fn the_tables_are_the_computed_factors_rounded_once() {
        for m in 0..=TABLE_DEGREE {
            let sectoral = Tables.sectorals(TABLE_DEGREE).nth(m);
            assert_eq!(sectoral, Some(Computed::sectoral(m) as f32), "m = {m}");
            let computed: Vec<_> = Computed.pairs(m, TABLE_DEGREE).collect();
            let tables: Vec<_> = Tables.pairs(m, TABLE_DEGREE).collect();
            assert_eq!(computed.len(), TABLE_DEGREE - m);
            for (k, (&(a, b), &t)) in computed.iter().zip(&tables).enumerate() {
                assert_eq!(t, (a as f32, b as f32), "l = {}, m = {m}", m + 1 + k);
            }
            assert_eq!(tables.len(), TABLE_DEGREE - m);
        }
        assert_eq!(Tables::slice(3, 5).len(), 2);
    }

    #[test]
    fn the_closed_form_is_the_recurrence_to_degree_2() {
        for d in [Vec3::new(0.3, -0.5, 0.812), Vec3::Z, -Vec3::Z, Vec3::new(-0.7, 0.1, -0.2)] {
            let u = d.try_normalize().unwrap();
            let mut y = [0.0f64; 9];
            for_each(&Computed, [u.x, u.y, u.z].map(f64::from), 2, |i, v| y[i] = v);
            let closed = degree2(u);
            let p = polynomials64([u.x, u.y, u.z].map(f64::from));
            for k in 0..9 {
                assert!((f64::from(closed[k]) - y[k]).abs() < 1e-6, "{k}: {d:?}");
                assert!((CONSTANTS64[k] * p[k] - y[k]).abs() < 1e-15, "{k}: {d:?}");
            }
            assert_eq!(zonal(u.z), [closed[0], closed[2], closed[6]]);
            let mut y32 = [0.0f32; 9];
            for_each(&Tables, [u.x, u.y, u.z], 2, |i, v| y32[i] = v);
            for k in 0..9 {
                assert!((f64::from(y32[k]) - y[k]).abs() < 1e-6, "{k}: {d:?}");
            }
        }
    }
}
