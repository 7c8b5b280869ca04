//! A minimal 3-vector of `f32`, enough for directions on the unit sphere.

use core::ops::{Add, AddAssign, Mul, Neg, Sub};

use crate::math;

/// A 3-vector of `f32`. Directions in this crate are unit vectors with `z` as the pole
/// (zenith) axis of the point sets.
///
/// # Examples
/// ```
/// use sphere_quadrature::Vec3;
///
/// let v = Vec3::new(3.0, 0.0, 4.0);
/// assert_eq!(v.length(), 5.0);
/// let n = v.try_normalize().expect("a non-zero, finite vector");
/// assert!((n.length() - 1.0).abs() < 1e-6);
/// // The cross product of two axes is the third; the dot product of orthogonal vectors is 0.
/// assert_eq!(Vec3::X.cross(Vec3::Y), Vec3::Z);
/// assert_eq!(Vec3::X.dot(Vec3::Z), 0.0);
/// assert_eq!(Vec3::ZERO.try_normalize(), None);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Vec3 {
    /// x component.
    pub x: f32,
    /// y component.
    pub y: f32,
    /// z component (the pole axis of the point sets).
    pub z: f32,
}

impl Vec3 {
    /// The zero vector.
    pub const ZERO: Self = Self::new(0.0, 0.0, 0.0);
    /// Unit x.
    pub const X: Self = Self::new(1.0, 0.0, 0.0);
    /// Unit y.
    pub const Y: Self = Self::new(0.0, 1.0, 0.0);
    /// Unit z, the pole.
    pub const Z: Self = Self::new(0.0, 0.0, 1.0);

    /// A vector from its components.
    #[inline]
    #[must_use]
    pub const fn new(x: f32, y: f32, z: f32) -> Self {
        Self { x, y, z }
    }

    /// Dot product.
    #[inline]
    #[must_use]
    pub fn dot(self, o: Self) -> f32 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Cross product.
    #[inline]
    #[must_use]
    pub fn cross(self, o: Self) -> Self {
        Self::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }

    /// Squared Euclidean length.
    #[inline]
    #[must_use]
    pub fn length_squared(self) -> f32 {
        self.dot(self)
    }

    /// Euclidean length.
    #[inline]
    #[must_use]
    pub fn length(self) -> f32 {
        math::sqrt(self.length_squared())
    }

    /// `true` when every component is finite.
    #[inline]
    #[must_use]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }

    /// The unit vector in this direction, or `None` when the vector is zero or has a NaN or
    /// infinite component: the crate's one definition of a valid direction (crate docs,
    /// "Directions").
    ///
    /// Any finite nonzero vector normalises, however long or short (`10³⁸` or subnormal
    /// components): where the squared length would overflow or lose precision (outside
    /// `[10⁻³⁰, f32::MAX]`) the vector is first divided by its largest component magnitude.
    /// Elsewhere the result is `v·(1/|v|)`, as before.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::Vec3;
    ///
    /// let n = Vec3::new(1.0, 2.0, 2.0).try_normalize().unwrap();
    /// assert!((n.length() - 1.0).abs() < 1e-6);
    /// assert_eq!(Vec3::ZERO.try_normalize(), None);
    /// assert_eq!(Vec3::new(f32::NAN, 0.0, 1.0).try_normalize(), None);
    /// ```
    #[inline]
    #[must_use]
    pub fn try_normalize(self) -> Option<Self> {
        let l2 = self.length_squared();
        if l2 >= 1e-30 && l2.is_finite() {
            return Some(self * (1.0 / math::sqrt(l2)));
        }
        self.normalize_scaled()
    }

    /// The slow path of [`Self::try_normalize`]: divided by the largest component magnitude
    /// first, so the squared length is in `[1, 3]`.
    #[cold]
    #[inline(never)]
    fn normalize_scaled(self) -> Option<Self> {
        let (m, s) = self.scaled();
        if !(m > 0.0 && m.is_finite() && self.is_finite()) {
            return None;
        }
        Some(s * (1.0 / math::sqrt(s.length_squared())))
    }

    /// `|v|` without the precision a subnormal `|v|²` loses: below `10⁻³⁰` (or NaN) it is
    /// taken after dividing by the largest component magnitude, as [`Self::try_normalize`]
    /// does. 0 for a zero vector; NaN propagates.
    #[inline]
    #[must_use]
    pub(crate) fn length_precise(self) -> f32 {
        let l2 = self.length_squared();
        if l2 >= 1e-30 {
            math::sqrt(l2)
        } else {
            self.length_scaled()
        }
    }

    /// The slow path of [`Self::length_precise`].
    #[cold]
    #[inline(never)]
    fn length_scaled(self) -> f32 {
        let (m, s) = self.scaled();
        if m == 0.0 {
            return 0.0;
        }
        m * math::sqrt(s.length_squared())
    }

    /// The largest component magnitude `m` and `self / m`, whose squared length is in
    /// `[1, 3]` for a finite nonzero `self`.
    #[inline]
    fn scaled(self) -> (f32, Self) {
        let m = math::abs(self.x).max(math::abs(self.y)).max(math::abs(self.z));
        (m, Self::new(self.x / m, self.y / m, self.z / m))
    }

    /// The components as an array.
    #[inline]
    #[must_use]
    pub const fn to_array(self) -> [f32; 3] {
        [self.x, self.y, self.z]
    }
}

impl From<[f32; 3]> for Vec3 {
    #[inline]
    fn from(a: [f32; 3]) -> Self {
        Self::new(a[0], a[1], a[2])
    }
}

impl From<Vec3> for [f32; 3] {
    #[inline]
    fn from(v: Vec3) -> Self {
        v.to_array()
    }
}

impl Add for Vec3 {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl AddAssign for Vec3 {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

impl Sub for Vec3 {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl Mul<f32> for Vec3 {
    type Output = Self;
    #[inline]
    fn mul(self, s: f32) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }
}

impl Mul<Vec3> for f32 {
    type Output = Vec3;
    #[inline]
    fn mul(self, v: Vec3) -> Vec3 {
        v * self
    }
}

impl Neg for Vec3 {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}
