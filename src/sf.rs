//! Spherical Fibonacci (SF) point sets on the sphere and the hemisphere.
//!
//! Seed tutorial, "Spherical Fibonacci Point Sets" (Hannay and Nye 2004, with the offset of
//! Swinbank and Purser 2006), for `0 ≤ j < N`:
//!
//! - sphere: `zⱼ = 1 − (2j+1)/N`, `φⱼ = 2π·frac(j·Φ⁻¹)`, `Φ = (1+√5)/2`;
//! - hemisphere (`z > 0`): `zⱼ = 1 − (2j+1)/(2N)`, same `φⱼ`; the heights are the midpoints of
//!   `N` equal strata of `[0, 1]`, which is what the lobe warps in [`crate::warp`] expect;
//! - Fibonacci-number lattice: `N = Fₘ` and `φⱼ = 2π·frac(j·Fₘ₋₁/Fₘ)`, with the same offset
//!   heights as the sphere set.
//!
//! # Exact phase
//! `frac(j·Φ⁻¹)` evaluated in `f32` is off by a whole point spacing near `N = 2¹⁶`. Here the
//! phase is a 64-bit fixed-point fraction of a turn, `j × round(2⁶⁴/Φ)` with wrapping
//! arithmetic, which is exact up to `j·2⁻⁶⁵` turn; the Fibonacci-number lattice reduces
//! `j·Fₘ₋₁ mod Fₘ` in integers. Its sine and cosine come from [`math::sin_cos_turns`]: exact
//! integer range reduction to a quarter turn, then short f32 polynomials (no f64, the same
//! code under both math backends).
//! Heights are formed from `1 − z = (2j+1)/N` and `1 + z = (2N−2j−1)/N` in integers so that
//! points near both poles keep their accuracy. Every point is within 2·10⁻⁶ rad of the exact point for all `N ≤`
//! [`MAX_POINTS`] = 2²⁴ with the `libm` backend (tested against an f64 reference at
//! N ∈ {1, 2, 3, 16, 1000, 2¹⁶, 2²²}).
//!
//! # Inverse mapping
//! [`FibonacciPoints::nearest_index`] (and the same method on the const-generic sets) returns
//! the index of the point nearest to a direction, after Keinert, Innmann, Sänger and
//! Stamminger 2015, "Spherical Fibonacci Mapping", but exact by construction: lattice
//! coordinates in 64-bit integers, never a phase in floating point. Tested against an exact
//! f64 search on 10⁵ random queries per N for every N up to 2²⁴ (differences only at
//! near-ties below 1.1·10⁻⁷ chord); typically 1.5–1.7 candidate points evaluated per query.
//!
//! # Rotations
//! A rotation about the pole is an exact 64-bit phase offset ([`SphericalFibonacci::with_phase_bits`]);
//! an arbitrary rotation is a [`Mat3`] applied to every point ([`SphericalFibonacci::with_rotation`]).
//! [`crate::rotation::RotationSequence`] yields seeded random ones.
//!
//! # Example
//! ```
//! use sphere_quadrature::SphericalFibonacci;
//!
//! // 64 unit directions with heights symmetric about the equator: the plain average of z
//! // over the points is the sphere's mean of z, 0.
//! let points = SphericalFibonacci::<64>::new().points();
//! assert!(points.iter().all(|p| (p.length() - 1.0).abs() < 1e-6));
//! let mean_z = points.iter().map(|p| p.z).sum::<f32>() / 64.0;
//! assert!(mean_z.abs() < 1e-6);
//! // The inverse mapping finds a point from its own direction.
//! let sf = SphericalFibonacci::<64>::new();
//! assert_eq!(sf.nearest_index(points[17]), Ok(17));
//! ```
//!
//! # Cost
//! Instructions per call and flash on a Cortex-M4F: [`costs`](crate::costs#point-sets).

use core::marker::PhantomData;

mod inverse;

use crate::error::Error;
use crate::math;
use crate::rotation::Mat3;
use crate::vec3::Vec3;
use crate::warp::{Frame, Lobe};

/// `round(2⁶⁴/Φ)`: one step of the golden phase as a 64-bit fraction of a turn.
///
/// 2⁶⁴/Φ = 11 400 714 819 323 198 485.9516…, so the rounding error is 0.048 units of 2⁻⁶⁴
/// turn per step.
pub const GOLDEN_PHASE: u64 = 0x9E37_79B9_7F4A_7C16;

/// The largest `N` for which the accuracy stated in the module docs is guaranteed.
pub const MAX_POINTS: usize = 1 << 24;

/// Where a point set lives.
///
/// # Examples
/// ```
/// use sphere_quadrature::sf::{Domain, FibonacciPoints};
///
/// assert_eq!(FibonacciPoints::sphere(10)?.domain(), Domain::Sphere);
/// let hemi = FibonacciPoints::hemisphere(10)?;
/// assert_eq!(hemi.domain(), Domain::Hemisphere);
/// assert!(hemi.iter().all(|p| p.z > 0.0));
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Domain {
    /// The whole unit sphere.
    Sphere,
    /// The upper hemisphere `z > 0`.
    Hemisphere,
}

/// How the azimuth advances from one point to the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Step {
    /// `φⱼ = 2π·frac(j·Φ⁻¹)`.
    Golden,
    /// `φⱼ = 2π·frac(j·prev/N)` with `N = Fₘ`, `prev = Fₘ₋₁`.
    Fibonacci { prev: u64 },
}

/// A point in height/azimuth form.
///
/// # Examples
/// ```
/// use sphere_quadrature::SphericalFibonacci;
///
/// let sf = SphericalFibonacci::<16>::new();
/// let zp = sf.z_phi(3).unwrap();
/// let p = sf.point(3).unwrap();
/// // Height and azimuth are the point's cylindrical coordinates.
/// assert!((zp.z - p.z).abs() < 1e-6);
/// assert!((0.0..core::f32::consts::TAU).contains(&zp.phi));
/// assert!((zp.phi.cos() * (1.0 - zp.z * zp.z).sqrt() - p.x).abs() < 1e-5);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ZPhi {
    /// Height `z = cos θ`.
    pub z: f32,
    /// Azimuth `φ` in `[0, 2π)`, before any arbitrary rotation.
    pub phi: f32,
}

/// A Fibonacci point set whose size is known at run time: the engine behind the
/// const-generic [`SphericalFibonacci`], [`HemisphericalFibonacci`] and [`FibonacciLattice`],
/// and the form to use when `N` is not a compile-time constant.
///
/// # Examples
/// ```
/// use sphere_quadrature::{sf::FibonacciPoints, Error};
///
/// // A size chosen at run time.
/// let n = 100;
/// let set = FibonacciPoints::sphere(n)?;
/// assert_eq!(set.len(), n);
/// assert!(set.iter().all(|p| (p.length() - 1.0).abs() < 1e-6));
/// // Sizes are validated: 0 points, or a lattice size that is not a Fibonacci number.
/// assert_eq!(FibonacciPoints::sphere(0), Err(Error::InvalidSize));
/// assert_eq!(FibonacciPoints::lattice(100), Err(Error::InvalidSize));
/// assert!(FibonacciPoints::lattice(89).is_ok());
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FibonacciPoints {
    n: usize,
    domain: Domain,
    step: Step,
    phase: u64,
    rotation: Option<Mat3>,
}

/// Largest Fibonacci number below `n` when `n` is itself a Fibonacci number (`n ≥ 2`), else
/// `None`. `F₁ = F₂ = 1` is treated as `1` with predecessor `1`.
///
/// # Examples
/// ```
/// use sphere_quadrature::sf::fibonacci_predecessor;
///
/// assert_eq!(fibonacci_predecessor(89), Some(55));
/// assert_eq!(fibonacci_predecessor(90), None);
/// ```
#[must_use]
pub const fn fibonacci_predecessor(n: usize) -> Option<usize> {
    let (mut a, mut b) = (1usize, 1usize);
    while b < n {
        let c = match a.checked_add(b) {
            Some(c) => c,
            None => return None,
        };
        a = b;
        b = c;
    }
    if b == n {
        Some(a)
    } else {
        None
    }
}

impl FibonacciPoints {
    /// `n` points on the whole sphere (`n ≥ 1`).
    ///
    /// # Errors
    /// [`Error::InvalidSize`] when `n` is 0 or exceeds [`MAX_POINTS`].
    pub fn sphere(n: usize) -> Result<Self, Error> {
        Self::build(n, Domain::Sphere, Step::Golden)
    }

    /// `n` points on the upper hemisphere (`n ≥ 1`).
    ///
    /// # Errors
    /// [`Error::InvalidSize`] when `n` is 0 or exceeds [`MAX_POINTS`].
    pub fn hemisphere(n: usize) -> Result<Self, Error> {
        Self::build(n, Domain::Hemisphere, Step::Golden)
    }

    /// The Fibonacci-number lattice on the sphere, `n = Fₘ` points.
    ///
    /// # Errors
    /// [`Error::InvalidSize`] when `n` is not a Fibonacci number or exceeds [`MAX_POINTS`].
    pub fn lattice(n: usize) -> Result<Self, Error> {
        match fibonacci_predecessor(n) {
            Some(prev) => Self::build(n, Domain::Sphere, Step::Fibonacci { prev: prev as u64 }),
            None => Err(Error::InvalidSize),
        }
    }

    fn build(n: usize, domain: Domain, step: Step) -> Result<Self, Error> {
        if n == 0 || n > MAX_POINTS {
            return Err(Error::InvalidSize);
        }
        Ok(raw(n, domain, step))
    }

    /// Number of points.
    #[must_use]
    pub const fn len(&self) -> usize {
        self.n
    }

    /// Always `false`: a set has at least one point.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        false
    }

    /// The domain of the set.
    #[must_use]
    pub const fn domain(&self) -> Domain {
        self.domain
    }

    /// The same set rotated about the pole by `bits / 2⁶⁴` of a turn (exact).
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::sf::FibonacciPoints;
    ///
    /// // Half a turn about the pole: same heights, x and y negated.
    /// let set = FibonacciPoints::sphere(20)?;
    /// let turned = set.with_phase_bits(1 << 63);
    /// let (p, q) = (set.point(5).unwrap(), turned.point(5).unwrap());
    /// assert_eq!(p.z, q.z);
    /// assert!((p.x + q.x).abs() < 1e-6 && (p.y + q.y).abs() < 1e-6);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub const fn with_phase_bits(mut self, bits: u64) -> Self {
        self.phase = bits;
        self
    }

    /// The same set rotated about the pole by `angle` radians (any finite value; NaN or
    /// infinity gives no rotation).
    #[must_use]
    pub fn with_angle(self, angle: f32) -> Self {
        self.with_phase_bits(angle_to_phase(angle))
    }

    /// The pole-rotation phase in units of 2⁻⁶⁴ turn.
    #[must_use]
    pub const fn phase_bits(&self) -> u64 {
        self.phase
    }

    /// The same set followed by an arbitrary rotation `r` (applied after the pole phase).
    ///
    /// # Errors
    /// [`Error::InvalidRotation`] unless `r` is a valid rotation: finite, orthonormal within
    /// [`crate::rotation::ROTATION_TOLERANCE`] and of determinant `+1`
    /// ([`Mat3::validate_rotation`]). A NaN or scaled matrix would otherwise leave the
    /// nearest-point search ([`Self::nearest_index`]) without an answer.
    pub fn with_rotation(mut self, r: Mat3) -> Result<Self, Error> {
        r.validate_rotation()?;
        self.rotation = Some(r);
        Ok(self)
    }

    /// The arbitrary rotation, if any.
    #[must_use]
    pub const fn rotation(&self) -> Option<Mat3> {
        self.rotation
    }

    /// Phase of point `j` as a 64-bit fraction of a turn, including the pole rotation.
    #[inline]
    #[must_use]
    pub(crate) const fn phase_of(&self, j: usize) -> u64 {
        let base = match self.step {
            Step::Golden => (j as u64).wrapping_mul(GOLDEN_PHASE),
            Step::Fibonacci { prev } => {
                // `n ≥ 1` for every set that can be built; the (no-op) guard lets the
                // optimiser drop the division-by-zero panic paths of `%` and `/`.
                let n = if self.n == 0 { 1 } else { self.n as u64 };
                let r = ((j as u64) % n) * prev % n;
                (((r as u128) << 64) / (n as u128)) as u64
            }
        };
        base.wrapping_add(self.phase)
    }

    /// Denominator of the heights: `1 − zⱼ = (2j+1)/d`.
    #[inline]
    const fn height_denominator(&self) -> u64 {
        match self.domain {
            Domain::Sphere => self.n as u64,
            Domain::Hemisphere => 2 * self.n as u64,
        }
    }

    /// `1 − zⱼ` of point `j`, formed without cancellation.
    #[inline]
    pub(crate) fn one_minus_z(&self, j: usize) -> f32 {
        (2 * j as u64 + 1) as f32 / self.height_denominator() as f32
    }

    /// Point `j` of this hemisphere set morphed onto `lobe` about `frame`'s axis: the one
    /// morph every lobe sampler and renderer uses for its directions.
    #[inline]
    pub(crate) fn morphed(&self, j: usize, lobe: Lobe, frame: &Frame) -> Vec3 {
        let (c, s) = lobe.morph(self.one_minus_z(j));
        let (sin_phi, cos_phi) = math::sin_cos_turns(self.phase_of(j));
        frame.to_world(Vec3::new(s * cos_phi, s * sin_phi, c))
    }

    /// `(zⱼ, sin θⱼ)`, with `1 − z` and `1 + z` each formed from exact integers so that both
    /// poles keep full relative accuracy.
    #[inline]
    fn z_sin(&self, j: usize) -> (f32, f32) {
        let (z, sin_squared) = self.z_sin_squared(j);
        (z, math::sqrt(sin_squared))
    }

    /// `(zⱼ, (1 − zⱼ)(1 + zⱼ))`, the latter a positive normal number.
    #[inline]
    const fn z_sin_squared(&self, j: usize) -> (f32, f32) {
        let d = self.height_denominator();
        let k = 2 * j as u64 + 1;
        let a = k as f32 / d as f32;
        let b = (2 * d - k) as f32 / d as f32;
        let z = if k <= d { 1.0 - a } else { b - 1.0 };
        (z, a * b)
    }

    /// The `N` points of this set without its arbitrary rotation, in constant evaluation:
    /// bit for bit those of [`Self::iter`] for an unrotated set (the square root is
    /// [`math::sqrt_const`], correctly rounded as `math::sqrt` is). For `N > len()`, the
    /// points past the end are zero.
    pub(crate) const fn unrotated_points<const N: usize>(&self) -> [Vec3; N] {
        let mut out = [Vec3::ZERO; N];
        let mut j = 0;
        while j < N && j < self.n {
            let (z, sin_squared) = self.z_sin_squared(j);
            let sin_theta = math::sqrt_const(sin_squared);
            let (sin_phi, cos_phi) = math::sin_cos_turns(self.phase_of(j));
            out[j] = Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, z);
            j += 1;
        }
        out
    }

    /// Point `j` in height/azimuth form (before any arbitrary rotation), or `None` when
    /// `j ≥ len()`.
    #[must_use]
    pub fn z_phi(&self, j: usize) -> Option<ZPhi> {
        if j >= self.n {
            return None;
        }
        Some(ZPhi { z: self.z_sin(j).0, phi: phase_to_angle(self.phase_of(j)) })
    }

    /// Point `j` as a unit vector, or `None` when `j ≥ len()`.
    #[must_use]
    pub fn point(&self, j: usize) -> Option<Vec3> {
        if j >= self.n {
            return None;
        }
        Some(self.point_unchecked(j))
    }

    /// Point `j` for `j < len()` (not checked; callers guarantee the range).
    #[inline]
    pub(crate) fn point_unchecked(&self, j: usize) -> Vec3 {
        let (z, sin_theta) = self.z_sin(j);
        let (sin_phi, cos_phi) = math::sin_cos_turns(self.phase_of(j));
        let p = Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, z);
        match &self.rotation {
            Some(r) => r * p,
            None => p,
        }
    }

    /// An iterator over the points in index order.
    #[must_use]
    pub fn iter(&self) -> Points<'_> {
        Points { set: self, next: 0, end: self.n }
    }

    /// Writes the points into `out`, in index order (as every `fill` of the crate: a buffer
    /// of exactly the set's length).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `out.len() != len()`; `out` is then unchanged.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{sf::FibonacciPoints, Error, Vec3};
    ///
    /// let set = FibonacciPoints::sphere(5)?;
    /// let mut out = [Vec3::ZERO; 5];
    /// set.fill(&mut out)?;
    /// assert_eq!(out[4], set.point(4).unwrap());
    /// assert_eq!(set.fill(&mut [Vec3::ZERO; 8]), Err(Error::LengthMismatch));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn fill(&self, out: &mut [Vec3]) -> Result<(), Error> {
        if out.len() != self.n {
            return Err(Error::LengthMismatch);
        }
        for (slot, p) in out.iter_mut().zip(self.iter()) {
            *slot = p;
        }
        Ok(())
    }
}

impl<'a> IntoIterator for &'a FibonacciPoints {
    type Item = Vec3;
    type IntoIter = Points<'a>;
    fn into_iter(self) -> Points<'a> {
        self.iter()
    }
}

/// Iterator over the points of a set, in index order.
///
/// # Examples
/// ```
/// use sphere_quadrature::SphericalFibonacci;
///
/// let sf = SphericalFibonacci::<32>::new();
/// let it = sf.iter();
/// assert_eq!(it.len(), 32);
/// // Same points as the array form, in index order.
/// assert!(sf.iter().zip(sf.points()).all(|(a, b)| a == b));
/// // A slice of the set: points 8..16, from the set's own iterator.
/// assert_eq!(sf.iter().skip(8).take(8).count(), 8);
/// ```
#[derive(Clone, Debug)]
pub struct Points<'a> {
    set: &'a FibonacciPoints,
    next: usize,
    end: usize,
}

impl Iterator for Points<'_> {
    type Item = Vec3;
    #[inline]
    fn next(&mut self) -> Option<Vec3> {
        if self.next >= self.end {
            return None;
        }
        let p = self.set.point_unchecked(self.next);
        self.next += 1;
        Some(p)
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        let k = self.end - self.next;
        (k, Some(k))
    }
}

impl DoubleEndedIterator for Points<'_> {
    fn next_back(&mut self) -> Option<Vec3> {
        if self.next >= self.end {
            return None;
        }
        self.end -= 1;
        Some(self.set.point_unchecked(self.end))
    }
}

impl ExactSizeIterator for Points<'_> {}

/// Converts a 64-bit fraction of a turn to radians in `[0, 2π)`, rounding to 2⁻²⁴ turn.
#[inline]
#[must_use]
fn phase_to_angle(phase: u64) -> f32 {
    let k = (((phase >> 39) + 1) >> 1) & 0x00FF_FFFF;
    k as f32 * (core::f32::consts::TAU / 16_777_216.0)
}

/// Converts radians to a 64-bit fraction of a turn (wrapping); non-finite angles give 0.
#[must_use]
pub(crate) fn angle_to_phase(angle: f32) -> u64 {
    if !angle.is_finite() {
        return 0;
    }
    let turns = angle as f64 * (1.0 / core::f64::consts::TAU);
    let frac = turns - math::floor64(turns);
    // frac in [0, 1]; scale to 2^64 in two halves to stay exact in f64.
    let hi = (frac * 4_294_967_296.0) as u64;
    let lo = ((frac * 4_294_967_296.0 - hi as f64) * 4_294_967_296.0) as u64;
    (hi << 32).wrapping_add(lo)
}

macro_rules! const_set {
    ($(#[$doc:meta])* $name:ident, $raw:ident, $check:expr, $rule:literal) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        #[cfg_attr(feature = "defmt", derive(defmt::Format))]
        pub struct $name<const N: usize> {
            set: FibonacciPoints,
            _n: PhantomData<[(); N]>,
        }

        impl<const N: usize> Default for $name<N> {
            fn default() -> Self {
                Self::new()
            }
        }

        impl<const N: usize> $name<N> {
            #[doc = concat!("The set of `N` points; ", $rule, " (checked at compile time).")]
            #[must_use]
            pub const fn new() -> Self {
                const { assert!($check(N), concat!(stringify!($name), ": ", $rule)) };
                Self { set: $raw(N), _n: PhantomData }
            }

            /// The run-time form of this set.
            #[must_use]
            pub const fn dynamic(&self) -> &FibonacciPoints {
                &self.set
            }

            /// The same set rotated about the pole by `bits / 2⁶⁴` of a turn (exact).
            #[must_use]
            pub const fn with_phase_bits(self, bits: u64) -> Self {
                Self { set: self.set.with_phase_bits(bits), _n: PhantomData }
            }

            /// The same set rotated about the pole by `angle` radians (non-finite: none).
            #[must_use]
            pub fn with_angle(self, angle: f32) -> Self {
                Self { set: self.set.with_angle(angle), _n: PhantomData }
            }

            /// The same set followed by an arbitrary rotation (after the pole phase).
            ///
            /// # Errors
            /// [`Error::InvalidRotation`] unless `r` is a valid rotation
            /// ([`Mat3::validate_rotation`]).
            pub fn with_rotation(self, r: Mat3) -> Result<Self, Error> {
                Ok(Self { set: self.set.with_rotation(r)?, _n: PhantomData })
            }

            /// Point `j` as a unit vector, or `None` when `j ≥ N`.
            #[must_use]
            pub fn point(&self, j: usize) -> Option<Vec3> {
                self.set.point(j)
            }

            /// Point `j` in height/azimuth form (before any arbitrary rotation), or `None`
            /// when `j ≥ N`.
            #[must_use]
            pub fn z_phi(&self, j: usize) -> Option<ZPhi> {
                self.set.z_phi(j)
            }

            /// All `N` points.
            #[must_use]
            pub fn points(&self) -> [Vec3; N] {
                core::array::from_fn(|j| self.set.point_unchecked(j))
            }

            /// An iterator over the points in index order.
            #[must_use]
            pub fn iter(&self) -> Points<'_> {
                self.set.iter()
            }
        }

        impl<'a, const N: usize> IntoIterator for &'a $name<N> {
            type Item = Vec3;
            type IntoIter = Points<'a>;
            fn into_iter(self) -> Points<'a> {
                self.iter()
            }
        }
    };
}

const fn raw(n: usize, domain: Domain, step: Step) -> FibonacciPoints {
    FibonacciPoints { n, domain, step, phase: 0, rotation: None }
}

const fn sphere_raw(n: usize) -> FibonacciPoints {
    raw(n, Domain::Sphere, Step::Golden)
}

const fn hemisphere_raw(n: usize) -> FibonacciPoints {
    raw(n, Domain::Hemisphere, Step::Golden)
}

const fn lattice_raw(n: usize) -> FibonacciPoints {
    // `valid_lattice` has admitted `n`, so the predecessor exists.
    let prev = match fibonacci_predecessor(n) {
        Some(p) => p as u64,
        None => 0,
    };
    raw(n, Domain::Sphere, Step::Fibonacci { prev })
}

const fn valid_size(n: usize) -> bool {
    n > 0 && n <= MAX_POINTS
}

const fn valid_lattice(n: usize) -> bool {
    valid_size(n) && fibonacci_predecessor(n).is_some()
}

const_set!(
    /// `N` spherical Fibonacci points on the whole sphere (Swinbank–Purser offset).
    ///
    /// `N` must satisfy `1 ≤ N ≤ 2²⁴`; anything else is a compile-time error.
    ///
    /// ```
    /// use sphere_quadrature::sf::SphericalFibonacci;
    /// let sf = SphericalFibonacci::<64>::new();
    /// let p = sf.points();
    /// assert!((p[0].z - (1.0 - 1.0 / 64.0)).abs() < 1e-7);
    /// ```
    ///
    /// `N = 0` does not compile:
    /// ```compile_fail
    /// let _ = sphere_quadrature::sf::SphericalFibonacci::<0>::new();
    /// ```
    SphericalFibonacci, sphere_raw, valid_size, "N must be in 1..=2^24"
);

const_set!(
    /// `N` spherical Fibonacci points on the upper hemisphere `z > 0`, with heights
    /// `zⱼ = 1 − (2j+1)/(2N)`.
    ///
    /// `N` must satisfy `1 ≤ N ≤ 2²⁴`; anything else is a compile-time error.
    ///
    /// ```
    /// use sphere_quadrature::HemisphericalFibonacci;
    /// let points = HemisphericalFibonacci::<64>::new().points();
    /// // All above the horizon; the plain average of cos θ is ∫cos θ dω / 2π = 1/2.
    /// assert!(points.iter().all(|p| p.z > 0.0 && (p.length() - 1.0).abs() < 1e-6));
    /// let mean_z = points.iter().map(|p| p.z).sum::<f32>() / 64.0;
    /// assert!((mean_z - 0.5).abs() < 1e-6);
    /// ```
    ///
    /// ```compile_fail
    /// let _ = sphere_quadrature::sf::HemisphericalFibonacci::<0>::new();
    /// ```
    HemisphericalFibonacci, hemisphere_raw, valid_size, "N must be in 1..=2^24"
);

const_set!(
    /// The Fibonacci-number lattice on the sphere: `N = Fₘ` points with
    /// `φⱼ = 2π·frac(j·Fₘ₋₁/Fₘ)` (exact in integers) and offset heights.
    ///
    /// `N` must be a Fibonacci number in `1..=2²⁴`; anything else is a compile-time error.
    ///
    /// ```
    /// let l = sphere_quadrature::sf::FibonacciLattice::<89>::new();
    /// assert_eq!(l.points().len(), 89);
    /// ```
    /// ```compile_fail
    /// let _ = sphere_quadrature::sf::FibonacciLattice::<90>::new();
    /// ```
    FibonacciLattice, lattice_raw, valid_lattice, "N must be a Fibonacci number in 1..=2^24"
);
