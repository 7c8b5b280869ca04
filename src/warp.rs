//! Local frames and the warps that morph hemisphere points onto BRDF lobes.
//!
//! # Frame
//! [`Frame::from_normal`] builds an orthonormal basis around a unit vector without branches on
//! the data (Duff, Burgess, Christensen, Hery, Kensler, Liani and Villemin 2017, "Building an
//! Orthonormal Basis, Revisited"): with `s = sign(n_z)`, `a = −1/(s + n_z)`, `b = n_x·n_y·a`,
//! `t = (1 + s·n_x²·a, s·b, −s·n_x)` and `b′ = (b, s + n_y²·a, −n_y)`.
//!
//! # Morphing (seed tutorial, "Morphing the Samples Set")
//! A point uniformly distributed on the hemisphere has a height `u = cos θ` uniform on
//! `[0, 1]`. For a Phong lobe `cosᵉ θ′` the substitution `cos θ′ = u^(1/(e+1))` (same `φ`)
//! makes the points distributed with density `(e+1)/(2π)·cosᵉ θ′`; the cosine lobe is `e = 1`,
//! `cos θ′ = √u`. Then `∫ L(ω)·cosᵉ θ dω = 2π/(e+1) · E[L(ω′)]`.
//!
//! `1 − cos θ′` is formed as `−expm1(ln(1 − a)/(e+1))` from `a = 1 − u`, so large exponents
//! keep their accuracy near the axis where `1 − cos θ′` is far below the f32 ulp of 1.
//!
//! # Example
//! ```
//! use sphere_quadrature::{warp::Frame, Lobe, Vec3};
//!
//! // A uniform hemisphere height, morphed onto the cosine lobe and placed around a normal.
//! let frame = Frame::from_normal(Vec3::new(0.0, 1.0, 1.0))?;
//! let (cos_t, sin_t) = Lobe::Cosine.morph(0.25); // a = 1 − u
//! let phi = 1.0f32;
//! let local = Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
//! let world = frame.to_world(local);
//! assert!((world.length() - 1.0).abs() < 1e-5);
//! assert!((world.dot(frame.n) - cos_t).abs() < 1e-5); // the height is measured along the normal
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```

use crate::error::Error;
use crate::math;
use crate::vec3::Vec3;

/// An orthonormal frame `(t, b, n)` with `n` the axis (normal or reflection direction).
///
/// # Examples
/// ```
/// use sphere_quadrature::{warp::Frame, Vec3};
///
/// let f = Frame::from_normal(Vec3::new(1.0, 2.0, 2.0))?;
/// // Orthonormal, with the axis as local z.
/// assert!(f.t.dot(f.b).abs() < 1e-6 && f.t.dot(f.n).abs() < 1e-6);
/// assert!((f.t.length() - 1.0).abs() < 1e-6);
/// assert!((f.to_world(Vec3::Z) - f.n).length() < 1e-6);
/// let v = Vec3::new(0.3, -0.2, 0.9);
/// assert!((f.to_local(f.to_world(v)) - v).length() < 1e-6);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frame {
    /// First tangent.
    pub t: Vec3,
    /// Second tangent, `n × t`.
    pub b: Vec3,
    /// The axis.
    pub n: Vec3,
}

impl Frame {
    /// The frame around `n`, which is normalised first.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] when `n` is zero or not finite (crate docs, "Directions").
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{warp::Frame, Error, Vec3};
    ///
    /// assert!((Frame::from_normal(Vec3::new(0.0, 0.0, 5.0))?.n - Vec3::Z).length() < 1e-6);
    /// assert_eq!(Frame::from_normal(Vec3::ZERO), Err(Error::InvalidDirection));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn from_normal(n: Vec3) -> Result<Self, Error> {
        let n = n.try_normalize().ok_or(Error::InvalidDirection)?;
        Ok(Self::from_unit(n))
    }

    /// The frame around a unit vector `n` (not checked).
    #[must_use]
    pub fn from_unit(n: Vec3) -> Self {
        let s = math::copysign(1.0, n.z);
        let a = -1.0 / (s + n.z);
        let b = n.x * n.y * a;
        Self {
            t: Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
            b: Vec3::new(b, s + n.y * n.y * a, -n.y),
            n,
        }
    }

    /// Local coordinates (`z` along the axis) to world.
    #[inline]
    #[must_use]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }

    /// World to local coordinates.
    #[inline]
    #[must_use]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(self.t.dot(v), self.b.dot(v), self.n.dot(v))
    }
}

/// A lobe over the hemisphere of an axis: the known part `p` of an illumination integral.
///
/// # Examples
/// ```
/// use sphere_quadrature::{Error, Lobe};
///
/// // ∫ cosᵉ θ dω over the hemisphere is 2π/(e + 1): π for the cosine lobe.
/// assert!((Lobe::Cosine.integral() - core::f32::consts::PI).abs() < 1e-6);
/// assert_eq!(Lobe::phong(1.0)?.integral(), Lobe::Cosine.integral());
/// assert_eq!(Lobe::phong(-1.0), Err(Error::InvalidExponent));
/// // Morphing keeps (cos θ′, sin θ′) on the unit circle.
/// let (c, s) = Lobe::Phong(20.0).morph(0.5);
/// assert!((c * c + s * s - 1.0).abs() < 1e-5);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Lobe {
    /// Constant over the hemisphere (`e = 0`).
    Uniform,
    /// Clamped cosine (`e = 1`): irradiance.
    Cosine,
    /// Phong lobe `cosᵉ θ` with exponent `e ≥ 0`.
    Phong(f32),
}

impl Lobe {
    /// A Phong lobe, validated.
    ///
    /// # Errors
    /// [`Error::InvalidExponent`] when `e` is negative, NaN or infinite.
    pub fn phong(e: f32) -> Result<Self, Error> {
        if e.is_finite() && e >= 0.0 {
            Ok(Lobe::Phong(e))
        } else {
            Err(Error::InvalidExponent)
        }
    }

    /// The exponent `e` of `cosᵉ θ`.
    #[must_use]
    pub fn exponent(&self) -> f32 {
        match *self {
            Lobe::Uniform => 0.0,
            Lobe::Cosine => 1.0,
            Lobe::Phong(e) => e,
        }
    }

    /// `∫ cosᵉ θ dω` over the hemisphere: `2π/(e+1)` (π for the cosine).
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::Lobe;
    ///
    /// // 2π for the uniform lobe (the hemisphere's solid angle), π for the cosine.
    /// assert!((Lobe::Uniform.integral() - 2.0 * core::f32::consts::PI).abs() < 1e-6);
    /// assert!((Lobe::Phong(3.0).integral() - core::f32::consts::PI / 2.0).abs() < 1e-6);
    /// ```
    #[must_use]
    pub fn integral(&self) -> f32 {
        core::f32::consts::TAU / (self.exponent() + 1.0)
    }

    /// Checks the lobe's parameters (a `Lobe::Phong` built directly may hold a bad exponent).
    ///
    /// # Errors
    /// [`Error::InvalidExponent`] for a negative, NaN or infinite Phong exponent.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{Error, Lobe};
    ///
    /// assert_eq!(Lobe::Phong(f32::INFINITY).validate(), Err(Error::InvalidExponent));
    /// assert_eq!(Lobe::Cosine.validate(), Ok(Lobe::Cosine));
    /// ```
    pub fn validate(&self) -> Result<Self, Error> {
        match *self {
            Lobe::Phong(e) => Lobe::phong(e),
            other => Ok(other),
        }
    }

    /// Morphs a uniform hemisphere height into the lobe: given `a = 1 − u` returns
    /// `(cos θ′, sin θ′)` with `cos θ′ = u^(1/(e+1))`.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::Lobe;
    ///
    /// // a = 1 − u: u = 1/4 on the cosine lobe gives cos θ′ = √u = 1/2.
    /// let (c, s) = Lobe::Cosine.morph(0.75);
    /// assert!((c - 0.5).abs() < 1e-6 && (s - 0.75f32.sqrt()).abs() < 1e-6);
    /// // Sharper lobes pull the same height closer to the axis.
    /// assert!(Lobe::Phong(100.0).morph(0.75).0 > Lobe::Phong(10.0).morph(0.75).0);
    /// ```
    #[inline]
    #[must_use]
    pub fn morph(&self, a: f32) -> (f32, f32) {
        let (c, one_minus_c) = match *self {
            Lobe::Uniform => (1.0 - a, a),
            Lobe::Cosine => {
                let c = math::sqrt(1.0 - a);
                (c, a / (1.0 + c))
            }
            Lobe::Phong(e) => {
                let l = math::ln_1p(-a) / (e + 1.0);
                let omc = -math::expm1(l);
                (1.0 - omc, omc)
            }
        };
        (c, math::sqrt(one_minus_c * (1.0 + c)))
    }
}
