//! Rotations of point sets: 3×3 matrices, uniform random rotations, and a seeded,
//! deterministic rotation sequence for per-update randomisation of a probe's rays.
//!
//! Randomly rotating a fixed point set before each use removes the structured error pattern
//! of a fixed orientation (seed tutorial, "Applying SF to Illumination Integrals") and keeps
//! the estimator unbiased in expectation. With an isotropic covariance kernel, Bayesian
//! quadrature weights do not change under a rotation of the whole set, so a probe may
//! re-rotate its rays every update.
//!
//! # Example
//! ```
//! use sphere_quadrature::{RotationSequence, SphericalFibonacci};
//!
//! // Re-randomise a point set at every update: rotated points stay on the sphere, and the
//! // rotations are reproducible from the seed.
//! let mut seq = RotationSequence::new(42);
//! let r = seq.next_rotation();
//! let points = SphericalFibonacci::<64>::new().points().map(|p| r * p);
//! assert!(points.iter().all(|p| (p.length() - 1.0).abs() < 1e-5));
//! assert_eq!(RotationSequence::new(42).next_rotation(), r);
//! ```

use core::ops::Mul;

use crate::math;
use crate::vec3::Vec3;

/// How far from orthonormal a rotation may be: each entry of `MᵀM − I` within 10⁻³
/// ([`Mat3::validate_rotation`]). Generous against f32 rounding (10⁻⁷ per product), tight
/// enough that a point set rotated by such a matrix stays within 10⁻³ of the unit sphere and
/// its nearest-point search stays exact (`tests/hardening/hardening.rs`).
pub const ROTATION_TOLERANCE: f32 = 1e-3;

/// A 3×3 matrix stored as rows; used for rotations.
///
/// # Examples
/// ```
/// use sphere_quadrature::{Mat3, Vec3};
///
/// // A quarter turn about z takes x to y; rotations keep lengths, and the transpose undoes them.
/// let m = Mat3::about_z(core::f32::consts::FRAC_PI_2);
/// assert!((m * Vec3::X - Vec3::Y).length() < 1e-6);
/// let r = Mat3::from_axis_angle(Vec3::new(1.0, 2.0, 3.0), 0.7);
/// let v = Vec3::new(0.3, -0.4, 0.5);
/// assert!(((r * v).length() - v.length()).abs() < 1e-6);
/// assert!((r.transpose() * (r * v) - v).length() < 1e-6);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Mat3 {
    /// Rows of the matrix: `(M·v).x = rows[0] · v`.
    pub rows: [Vec3; 3],
}

impl Default for Mat3 {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Mat3 {
    /// The identity.
    pub const IDENTITY: Self = Self { rows: [Vec3::X, Vec3::Y, Vec3::Z] };

    /// A matrix from its rows.
    #[must_use]
    pub const fn from_rows(r0: Vec3, r1: Vec3, r2: Vec3) -> Self {
        Self { rows: [r0, r1, r2] }
    }

    /// A matrix from its columns.
    #[must_use]
    pub const fn from_cols(c0: Vec3, c1: Vec3, c2: Vec3) -> Self {
        Self {
            rows: [
                Vec3::new(c0.x, c1.x, c2.x),
                Vec3::new(c0.y, c1.y, c2.y),
                Vec3::new(c0.z, c1.z, c2.z),
            ],
        }
    }

    /// Rotation by `angle` radians about the z (pole) axis.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{Mat3, Vec3};
    ///
    /// let m = Mat3::about_z(0.3);
    /// assert_eq!(m * Vec3::Z, Vec3::Z); // the pole is fixed
    /// // cos 0.3 to the accuracy of either math backend (micromath: 1.1·10⁻³).
    /// assert!(((m * Vec3::X).dot(Vec3::X) - 0.3f32.cos()).abs() < 2e-3);
    /// ```
    #[must_use]
    pub fn about_z(angle: f32) -> Self {
        let (s, c) = (math::sin(angle), math::cos(angle));
        Self::from_rows(Vec3::new(c, -s, 0.0), Vec3::new(s, c, 0.0), Vec3::Z)
    }

    /// Rotation from a quaternion `(x, y, z, w)` of any finite nonzero length; it is
    /// normalised first (divided by its largest component magnitude where its squared length
    /// would overflow or underflow, so `[0, 10²⁰, 0, 0]` and `[0, 10⁻¹⁶, 0, 0]` are both the
    /// half turn about y). A zero quaternion, or one with a NaN or infinite component, gives
    /// the identity.
    #[must_use]
    pub fn from_quaternion(q: [f32; 4]) -> Self {
        let mut q = q;
        let mut n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
        if !(n2 >= 1e-30 && n2.is_finite()) {
            let m = q.iter().fold(0.0f32, |m, &c| m.max(math::abs(c)));
            let usable = m > 0.0 && m.is_finite() && q.iter().all(|c| c.is_finite());
            if !usable {
                return Self::IDENTITY;
            }
            q = q.map(|c| c / m);
            n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
        }
        let s = 2.0 / n2;
        let [x, y, z, w] = q;
        let (xx, yy, zz) = (x * x * s, y * y * s, z * z * s);
        let (xy, xz, yz) = (x * y * s, x * z * s, y * z * s);
        let (wx, wy, wz) = (w * x * s, w * y * s, w * z * s);
        Self::from_rows(
            Vec3::new(1.0 - yy - zz, xy - wz, xz + wy),
            Vec3::new(xy + wz, 1.0 - xx - zz, yz - wx),
            Vec3::new(xz - wy, yz + wx, 1.0 - xx - yy),
        )
    }

    /// Rotation by `angle` radians about `axis` (normalised first); the identity when the
    /// axis is zero or not finite.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{Mat3, Vec3};
    ///
    /// // The axis is fixed by the rotation about it.
    /// let axis = Vec3::new(0.0, 0.6, 0.8);
    /// let m = Mat3::from_axis_angle(axis, 1.2);
    /// assert!((m * axis - axis).length() < 1e-6);
    /// ```
    #[must_use]
    pub fn from_axis_angle(axis: Vec3, angle: f32) -> Self {
        match axis.try_normalize() {
            Some(a) => {
                let (s, c) = (math::sin(0.5 * angle), math::cos(0.5 * angle));
                Self::from_quaternion([a.x * s, a.y * s, a.z * s, c])
            }
            None => Self::IDENTITY,
        }
    }

    /// A rotation distributed uniformly on SO(3) when `u` is uniform on `[0, 1)³`
    /// (Shoemake's subgroup algorithm: a uniform unit quaternion from three uniforms).
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{Mat3, Vec3};
    ///
    /// let m = Mat3::uniform([0.1, 0.5, 0.9]);
    /// // Orthonormal: the rows are unit vectors, pairwise orthogonal.
    /// for i in 0..3 {
    ///     assert!((m.rows[i].length() - 1.0).abs() < 1e-5);
    ///     assert!(m.rows[i].dot(m.rows[(i + 1) % 3]).abs() < 1e-5);
    /// }
    /// ```
    #[must_use]
    pub fn uniform(u: [f32; 3]) -> Self {
        let tau = core::f32::consts::TAU;
        let (a, b) = (tau * u[1], tau * u[2]);
        Self::shoemake(u[0], (math::sin(a), math::cos(a)), (math::sin(b), math::cos(b)))
    }

    /// Shoemake's rotation from `u₀` and the sines and cosines `(sin, cos)` of the two
    /// angles.
    fn shoemake(u0: f32, a: (f32, f32), b: (f32, f32)) -> Self {
        let r1 = math::sqrt(1.0 - u0);
        let r2 = math::sqrt(u0);
        Self::from_quaternion([r1 * a.0, r1 * a.1, r2 * b.0, r2 * b.1])
    }

    /// `Ok` when the matrix is a valid rotation: every entry finite, `MᵀM = I` entry by entry
    /// within [`ROTATION_TOLERANCE`], and determinant `+1` (not a reflection).
    ///
    /// This is the crate's one definition of a valid rotation: where a rotation enters a
    /// point set or a probe ([`crate::FibonacciPoints::with_rotation`],
    /// [`crate::SphericalFibonacci::with_rotation`],
    /// [`Probe::set_rotation`](crate::probe::Probe::set_rotation)) it is checked with this.
    /// The matrices of [`Mat3::from_quaternion`], [`Mat3::from_axis_angle`], [`Mat3::uniform`],
    /// [`RotationSequence::next_rotation`] and products of a few of them are orthonormal to
    /// f32 rounding (about 10⁻⁷), far inside the tolerance.
    ///
    /// # Errors
    /// [`crate::error::Error::InvalidRotation`] otherwise (a NaN or infinite entry, a scaled, sheared
    /// or reflecting matrix).
    pub fn validate_rotation(&self) -> Result<(), crate::error::Error> {
        let r = self.rows;
        let finite = r.iter().all(|v| v.is_finite());
        let orthonormal = (0..3).all(|i| {
            (0..3).all(|j| {
                let want = if i == j { 1.0 } else { 0.0 };
                let got = r.get(i).zip(r.get(j)).map_or(f32::NAN, |(a, b)| a.dot(*b));
                math::abs(got - want) <= ROTATION_TOLERANCE
            })
        });
        // Orthonormal rows have determinant ±1; +1 is a rotation.
        let det = r[0].cross(r[1]).dot(r[2]);
        if finite && orthonormal && det > 0.0 {
            Ok(())
        } else {
            Err(crate::error::Error::InvalidRotation)
        }
    }

    /// The transpose, which is the inverse of a rotation.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{Mat3, Vec3};
    ///
    /// // The inverse of a rotation is its transpose.
    /// let m = Mat3::from_axis_angle(Vec3::new(0.0, 1.0, 0.0), 0.8);
    /// let v = Vec3::new(0.2, 0.3, -0.9);
    /// assert!((m.transpose() * (m * v) - v).length() < 1e-6);
    /// ```
    #[must_use]
    pub fn transpose(&self) -> Self {
        let [a, b, c] = self.rows;
        Self::from_cols(a, b, c)
    }
}

impl Mul<Vec3> for Mat3 {
    type Output = Vec3;
    #[inline]
    fn mul(self, v: Vec3) -> Vec3 {
        Vec3::new(self.rows[0].dot(v), self.rows[1].dot(v), self.rows[2].dot(v))
    }
}

impl Mul<Vec3> for &Mat3 {
    type Output = Vec3;
    #[inline]
    fn mul(self, v: Vec3) -> Vec3 {
        *self * v
    }
}

impl Mul for Mat3 {
    type Output = Mat3;
    fn mul(self, o: Mat3) -> Mat3 {
        let t = o.transpose();
        let row = |r: Vec3| Vec3::new(r.dot(t.rows[0]), r.dot(t.rows[1]), r.dot(t.rows[2]));
        Mat3::from_rows(row(self.rows[0]), row(self.rows[1]), row(self.rows[2]))
    }
}

/// A seeded, deterministic stream of random rotations (and pole-phase offsets) for
/// re-randomising a point set at every probe update.
///
/// The generator is SplitMix64 (Steele, Lea and Flood 2014): 8 bytes of state, one 64-bit
/// multiply-xorshift per draw, no allocation, identical output on every target. It is not
/// cryptographic. The same seed always yields the same sequence.
///
/// # Examples
/// ```
/// use sphere_quadrature::{RotationSequence, Vec3};
///
/// // The same seed gives the same rotations, on every target.
/// let mut a = RotationSequence::new(7);
/// let mut b = RotationSequence::new(7);
/// let (ra, rb) = (a.next_rotation(), b.next_rotation());
/// assert_eq!(ra, rb);
/// // A rotation maps the pole to another unit vector.
/// assert!(((ra * Vec3::Z).length() - 1.0).abs() < 1e-5);
/// let u = a.next_f32();
/// assert!((0.0..1.0).contains(&u));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RotationSequence {
    state: u64,
}

impl RotationSequence {
    /// A sequence from a seed.
    #[must_use]
    pub const fn new(seed: u64) -> Self {
        Self { state: seed }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A uniform f32 in `[0, 1)` (24 random bits).
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / 16_777_216.0)
    }

    /// A uniformly random rotation about the pole, as an exact phase offset in turns × 2⁶⁴
    /// (pass to `with_phase_bits` of a point set).
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{RotationSequence, SphericalFibonacci};
    ///
    /// // A random turn about the pole keeps every height.
    /// let mut seq = RotationSequence::new(9);
    /// let set = SphericalFibonacci::<16>::new();
    /// let turned = set.with_phase_bits(seq.next_phase());
    /// assert!(set.iter().zip(turned.iter()).all(|(a, b)| a.z == b.z));
    /// ```
    pub fn next_phase(&mut self) -> u64 {
        self.next_u64()
    }

    /// A rotation uniformly distributed on SO(3).
    pub fn next_rotation(&mut self) -> Mat3 {
        let u = [self.next_f32(), self.next_f32(), self.next_f32()];
        Mat3::uniform(u)
    }

    /// [`Self::next_rotation`] from the same draws, with the angles' sines and cosines by
    /// [`math::sin_cos_turns`] of the exact turns: within 10⁻⁶ of the exact rotation of those
    /// draws on either math backend (as `next_rotation` is with `libm`), and many times
    /// cheaper where `libm`'s `sin` runs in software f64 (Cortex-M4F).
    pub(crate) fn next_rotation_turns(&mut self) -> Mat3 {
        let u0 = self.next_f32();
        // The 24 bits `next_f32` keeps, as a phase in turns × 2⁶⁴.
        let mut turn = || (self.next_u64() >> 40) << 40;
        let (a, b) = (turn(), turn());
        Mat3::shoemake(u0, math::sin_cos_turns(a), math::sin_cos_turns(b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_by_turns_are_the_exact_rotations_of_the_sequence_s_draws() {
        let (mut draws, mut turns) = (RotationSequence::new(11), RotationSequence::new(11));
        for _ in 0..2000 {
            let u = [draws.next_f32(), draws.next_f32(), draws.next_f32()].map(f64::from);
            let y = turns.next_rotation_turns();
            assert_eq!(y.validate_rotation(), Ok(()));
            // Shoemake's rotation of the same draws in f64.
            let tau = 2.0 * core::f64::consts::PI;
            let (r1, r2) = ((1.0 - u[0]).sqrt(), u[0].sqrt());
            let [x, yq, z, w] = [
                r1 * (tau * u[1]).sin(),
                r1 * (tau * u[1]).cos(),
                r2 * (tau * u[2]).sin(),
                r2 * (tau * u[2]).cos(),
            ];
            let exact = [
                [1.0 - 2.0 * (yq * yq + z * z), 2.0 * (x * yq - w * z), 2.0 * (x * z + w * yq)],
                [2.0 * (x * yq + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (yq * z - w * x)],
                [2.0 * (x * z - w * yq), 2.0 * (yq * z + w * x), 1.0 - 2.0 * (x * x + yq * yq)],
            ];
            for (row, want) in y.rows.iter().zip(&exact) {
                let got = [row.x, row.y, row.z].map(f64::from);
                for (g, e) in got.iter().zip(want) {
                    assert!((g - e).abs() < 1e-6, "{y:?} {exact:?}");
                }
            }
        }
    }
}
