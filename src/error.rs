//! The crate's error type.

use core::fmt;

/// Why a computation refused its input.
///
/// Every public function that can be handed bad data returns this instead of panicking.
///
/// # Examples
/// ```
/// use sphere_quadrature::{warp::Frame, Error, Vec3};
///
/// // A zero normal has no direction: the call returns an error instead of panicking.
/// assert_eq!(Frame::from_normal(Vec3::ZERO), Err(Error::InvalidDirection));
/// assert!(Frame::from_normal(Vec3::Z).is_ok());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error {
    /// A direction (normal, reflection or query vector) is zero or has a NaN or infinite
    /// component. Any other vector is valid, however long or short (crate docs,
    /// "Directions").
    InvalidDirection,
    /// A Phong exponent is negative, NaN or infinite.
    InvalidExponent,
    /// A slice has the wrong length (for example directions and samples differ in length, or
    /// an empty point set was asked for).
    LengthMismatch,
    /// A point-set size is zero, too large, or not allowed for that set (for example not a
    /// Fibonacci number for the Fibonacci lattice).
    InvalidSize,
    /// A numeric parameter is outside its documented range (for example a Sobolev
    /// smoothness `s` outside `(1, 2)`, a negative or NaN tolerance, a non-finite
    /// interval length, a NaN or negative spectrum entry), or a matrix is not a valid rotation
    /// (`Mat3::validate_rotation`: finite, orthonormal within 10⁻³, determinant `+1`).
    InvalidParameter,
    /// A spherical-Gaussian sharpness is negative, NaN or infinite.
    InvalidSharpness,
    /// A radiance sample has a NaN or infinite channel (where a computation keeps state, such
    /// as a probe update, instead of propagating NaN).
    InvalidRadiance,
    /// A masked probe update (`Probe::update_masked`) has more missing samples than the
    /// probe's capacity `M`, or fewer than two valid samples (or, never seen with the baked
    /// families, a missing block the f32 arithmetic finds singular for every member).
    TooManyMissing,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Error::InvalidDirection => "direction is zero or not finite",
            Error::InvalidExponent => "Phong exponent must be finite and non-negative",
            Error::LengthMismatch => "slice lengths do not match or a slice is empty",
            Error::InvalidSize => "point-set size is zero, too large, or not valid for this set",
            Error::InvalidSharpness => "SG sharpness must be finite and non-negative",
            Error::InvalidParameter => {
                "parameter is outside its documented range (or a matrix is not a valid rotation)"
            }
            Error::InvalidRadiance => "radiance sample is NaN or infinite",
            Error::TooManyMissing => {
                "more samples missing than the probe's capacity M, or fewer than two valid"
            }
        })
    }
}

impl core::error::Error for Error {}
