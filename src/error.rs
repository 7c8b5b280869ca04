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
    /// A spherical-Gaussian sharpness is negative, NaN or infinite.
    InvalidSharpness,
    /// A radiance sample has a NaN or infinite channel (where a computation keeps state, such
    /// as a probe update, instead of propagating NaN).
    InvalidRadiance,
    /// A masked probe update (`Probe::update_masked`) has more missing samples than the
    /// probe's capacity `M`, or fewer than two valid samples (or, never seen with the baked
    /// families, a missing block the f32 arithmetic finds singular for every member).
    TooManyMissing,
    /// A matrix is not a rotation: a NaN or infinite entry, not orthonormal within
    /// [`ROTATION_TOLERANCE`](crate::rotation::ROTATION_TOLERANCE), or a reflection
    /// ([`Mat3::validate_rotation`](crate::Mat3::validate_rotation)).
    InvalidRotation,
    /// A probe family member index past the end of the baked family
    /// ([`Selection::Member`](crate::probe::Selection::Member)).
    InvalidMember,
    /// A channel index past the radiance type's last channel, or a radiance type with more
    /// channels than a probe supports.
    InvalidChannel,
    /// The weights of a linear combination (of channels, or a glossy lobe's amplitude) have a
    /// NaN or infinite entry, or are all zero where a combination must be non-trivial.
    InvalidWeights,
    /// A footprint or sensor response outside its range: a footprint parameter of zero or
    /// above [`footprint::MAX_PARAMETER`](crate::footprint::MAX_PARAMETER), a cosine power
    /// outside `[0, 4096]`, a response table that is not finite or never positive, more
    /// distinct responses than a layout holds, or a Legendre degree above 1024.
    InvalidResponse,
    /// A noise level is negative or not finite, or a sensor's noise scale is not positive.
    InvalidNoise,
    /// A layout prior is not a valid covariance: a negative or non-finite spectrum entry, no
    /// positive one, a non-positive variance scale, zonal covariances that do not form a
    /// positive semi-definite matrix, a mean with no non-zero finite coefficient, or a
    /// squared-exponential `λ` outside `(0, 64]`.
    InvalidPrior,
    /// A Sobolev smoothness `s` outside `(1, 2)`.
    InvalidSmoothness,
    /// A tolerance that is negative or NaN.
    InvalidTolerance,
    /// A change hazard (prior probability of a change per update) outside `(0, 1)`.
    InvalidHazard,
    /// A mip-pyramid resolution factor outside `[0.5, 64]`.
    InvalidResolution,
    /// A spectrum entry (a point set's energy per degree) that is negative, NaN or infinite.
    InvalidSpectrum,
    /// A numeric argument that must be finite is NaN or infinite (a circle pattern's offset).
    NonFinite,
    /// An internal consistency check of the baked tables failed. Never seen with the tables
    /// this crate ships or bakes; report it as a bug.
    Internal,
}

impl Error {
    /// Whether the error is an argument outside its documented range (a rotation, member,
    /// channel, weight, response, noise level, prior, smoothness, tolerance, spectrum, hazard,
    /// resolution or a non-finite number), rather than a bad direction, exponent, sharpness,
    /// radiance, size or length, too many missing samples, or an internal failure. For callers
    /// that map the errors onto fewer categories (a JavaScript binding's error names, a status
    /// code).
    ///
    /// ```
    /// use sphere_quadrature::Error;
    ///
    /// assert!(Error::InvalidHazard.is_out_of_range());
    /// assert!(!Error::InvalidDirection.is_out_of_range());
    /// ```
    #[must_use]
    pub const fn is_out_of_range(self) -> bool {
        matches!(
            self,
            Error::InvalidRotation
                | Error::InvalidMember
                | Error::InvalidChannel
                | Error::InvalidWeights
                | Error::InvalidResponse
                | Error::InvalidNoise
                | Error::InvalidPrior
                | Error::InvalidSmoothness
                | Error::InvalidTolerance
                | Error::InvalidSpectrum
                | Error::InvalidHazard
                | Error::InvalidResolution
                | Error::NonFinite
        )
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Error::InvalidDirection => "direction is zero or not finite",
            Error::InvalidExponent => "Phong exponent must be finite and non-negative",
            Error::LengthMismatch => "slice lengths do not match or a slice is empty",
            Error::InvalidSize => "point-set size is zero, too large, or not valid for this set",
            Error::InvalidSharpness => "SG sharpness must be finite and non-negative",
            Error::InvalidRadiance => "radiance sample is NaN or infinite",
            Error::TooManyMissing => {
                "more samples missing than the probe's capacity M, or fewer than two valid"
            }
            Error::InvalidRotation => "matrix is not a rotation",
            Error::InvalidMember => "family member index is past the baked family",
            Error::InvalidChannel => "channel index is past the last channel, or too many channels",
            Error::InvalidWeights => "combination weights are not finite, or all zero",
            Error::InvalidResponse => "footprint or sensor response is outside its range",
            Error::InvalidNoise => {
                "noise level is negative or not finite, or a noise scale is not positive"
            }
            Error::InvalidPrior => "layout prior is not a valid covariance",
            Error::InvalidSmoothness => "Sobolev smoothness must lie in (1, 2)",
            Error::InvalidTolerance => "tolerance must be non-negative",
            Error::InvalidHazard => "hazard must lie in (0, 1)",
            Error::InvalidResolution => "mip-pyramid resolution must lie in [0.5, 64]",
            Error::InvalidSpectrum => "spectrum entry is negative or not finite",
            Error::NonFinite => "numeric argument is NaN or infinite",
            Error::Internal => "internal table check failed (a bug: please report it)",
        })
    }
}

impl core::error::Error for Error {}
