//! Quasi-Monte Carlo estimators of illumination integrals with spherical Fibonacci points.
//!
//! Seed tutorial, "The QMC Estimator for Illumination Integrals": a hemisphere SF set is
//! morphed onto the lobe `cosᵉ θ` about an axis (the normal `n` for diffuse, the reflection
//! direction `r` for glossy), then
//!
//! `∫ L(ω)·cosᵉ θ dω ≈ 2π/(N(e+1)) · Σⱼ L(ωⱼ′)`.
//!
//! The estimators return:
//! - [`irradiance`]: `E(n) = ∫ L(ω)·max(0, n·ω) dω ≈ π/N · Σ L(ωⱼ′)`;
//! - [`phong`]: the normalised Phong lobe, `∫ L(ω)·(e+1)/(2π)·max(0, r·ω)ᵉ dω ≈ 1/N · Σ L(ωⱼ′)`
//!   (the lobe integrates to 1, so a constant radiance `c` gives `c`). For the seed's BRDF
//!   `ρ = k_s·cosᵉ/cos` multiply by `2π·k_s/(e+1)`. Samples are not clipped at a surface
//!   horizon; clip in the callback if the lobe crosses one.
//!
//! Each comes in a callback form (a closure evaluates radiance in a direction) and a slice
//! form (write directions with [`LobeSampler::fill`], trace them, sum with
//! [`LobeSampler::estimate`]). The pole phase (`phase_bits`, a 64-bit fraction of a turn, e.g.
//! from [`crate::rotation::RotationSequence::next_phase`]) randomly rotates the set about the
//! axis per estimate, which removes the structured error of a fixed orientation.
//!
//! A NaN or infinite sample is [`Error::InvalidRadiance`], as in every estimator of the crate.
//!
//! # Radiance scale
//! The estimators work at any radiance scale: a sum of samples that overflows f32 is taken
//! again with every sample scaled by `2^−⌈log₂ N⌉` first (exact), and the weight applied to
//! that sum, so an estimate is `±∞` only when it exceeds `f32::MAX` itself (a constant
//! `10³⁷` gives `π·10³⁷` irradiance). Whenever the plain sum fits, the estimate is the plain
//! sum times the weight, bit for bit.
//!
//! # Example
//! ```
//! use sphere_quadrature::{qmc, Vec3};
//!
//! // Irradiance of the sky L(ω) = 1 + z about +z: π + 2π/3.
//! let e = qmc::irradiance::<64, f32, _>(Vec3::Z, 0, |d| 1.0 + d.z)?;
//! let exact = core::f32::consts::PI * (1.0 + 2.0 / 3.0);
//! assert!((e - exact).abs() < 1e-3 * exact);
//! // Normalised Phong radiance of a constant is the constant.
//! let g = qmc::phong::<64, f32, _>(Vec3::X, 20.0, 0, |_| 0.7)?;
//! assert!((g - 0.7).abs() < 1e-5);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Cost
//! Instructions per call and flash on a Cortex-M4F: [`costs`](crate::costs#qmc-estimators).

use crate::error::Error;
use crate::radiance::Radiance;
use crate::sf::FibonacciPoints;
use crate::vec3::Vec3;
use crate::warp::{Frame, Lobe};

/// A hemisphere SF set morphed onto a lobe about an axis: the sample directions of one QMC
/// estimate, and its weight.
///
/// # Examples
/// ```
/// use sphere_quadrature::{qmc::LobeSampler, Lobe, Vec3};
///
/// // 32 cosine-distributed directions about a normal: all in its hemisphere.
/// let n = Vec3::new(0.0, 0.6, 0.8);
/// let s = LobeSampler::new(n, Lobe::Cosine, 32, 0)?;
/// assert!(s.iter().all(|d| d.dot(n) > 0.0 && (d.length() - 1.0).abs() < 1e-5));
/// // Callback or slice form: a constant radiance of 1 has irradiance π.
/// let e = s.integrate(|_| 1.0f32)?;
/// assert!((e - core::f32::consts::PI).abs() < 1e-5);
/// let mut dirs = [Vec3::ZERO; 32];
/// s.fill(&mut dirs)?;
/// let samples = dirs.map(|_| 1.0f32);
/// assert_eq!(s.estimate(&samples)?, e);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LobeSampler {
    set: FibonacciPoints,
    lobe: Lobe,
    frame: Frame,
}

impl LobeSampler {
    /// `n` directions distributed on `lobe` about `axis` (normalised first), rotated about the
    /// axis by `phase_bits / 2⁶⁴` turn.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite axis, [`Error::InvalidExponent`]
    /// for a bad Phong exponent, [`Error::InvalidSize`] for `n = 0` or `n > 2²⁴`.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{qmc::LobeSampler, Error, Lobe, Vec3};
    ///
    /// let s = LobeSampler::new(Vec3::new(0.0, 0.0, 3.0), Lobe::Phong(10.0), 16, 0)?;
    /// assert_eq!(s.len(), 16);
    /// assert_eq!(LobeSampler::new(Vec3::ZERO, Lobe::Cosine, 16, 0), Err(Error::InvalidDirection));
    /// assert_eq!(LobeSampler::new(Vec3::Z, Lobe::Cosine, 0, 0), Err(Error::InvalidSize));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn new(axis: Vec3, lobe: Lobe, n: usize, phase_bits: u64) -> Result<Self, Error> {
        let frame = Frame::from_normal(axis)?;
        let lobe = lobe.validate()?;
        let set = FibonacciPoints::hemisphere(n)?.with_phase_bits(phase_bits);
        Ok(Self { set, lobe, frame })
    }

    /// Number of directions.
    #[must_use]
    pub const fn len(&self) -> usize {
        self.set.len()
    }

    /// Always `false`.
    #[must_use]
    pub const fn is_empty(&self) -> bool {
        false
    }

    /// The frame about the axis.
    #[must_use]
    pub const fn frame(&self) -> &Frame {
        &self.frame
    }

    /// The lobe.
    #[must_use]
    pub const fn lobe(&self) -> Lobe {
        self.lobe
    }

    /// Direction `j` in world space, or `None` when `j ≥ len()`.
    #[must_use]
    pub fn direction(&self, j: usize) -> Option<Vec3> {
        if j >= self.set.len() {
            return None;
        }
        Some(self.direction_unchecked(j))
    }

    #[inline]
    fn direction_unchecked(&self, j: usize) -> Vec3 {
        self.set.morphed(j, self.lobe, &self.frame)
    }

    /// An iterator over the directions.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = Vec3> + '_ {
        (0..self.set.len()).map(|j| self.direction_unchecked(j))
    }

    /// Writes the directions into `out`.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `out.len() != len()`.
    pub fn fill(&self, out: &mut [Vec3]) -> Result<(), Error> {
        if out.len() != self.set.len() {
            return Err(Error::LengthMismatch);
        }
        for (j, slot) in out.iter_mut().enumerate() {
            *slot = self.direction_unchecked(j);
        }
        Ok(())
    }

    /// The weight of every sample in `∫ L·cosᵉ θ dω`: `2π/((e+1)·N)`.
    #[must_use]
    pub fn weight(&self) -> f32 {
        self.lobe.integral() / self.set.len() as f32
    }

    /// `∫ L(ω)·cosᵉ θ dω` from the radiance in each direction, in order.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `samples.len() != len()`, [`Error::InvalidRadiance`] for
    /// a NaN or infinite sample.
    pub fn estimate<T: Radiance>(&self, samples: &[T]) -> Result<T, Error> {
        let () = crate::radiance::Channels::<T>::VALID;
        if samples.len() != self.set.len() {
            return Err(Error::LengthMismatch);
        }
        let plain = samples.iter().fold(T::ZERO, |acc, &y| acc.add(y));
        if is_finite(plain) {
            return Ok(plain.scale(self.weight()));
        }
        // The sum overflowed (or a sample is not finite): again, every sample scaled down
        // first, which cannot overflow for finite samples.
        let p = prescale(samples.len());
        let scaled = samples.iter().fold(T::ZERO, |acc, &y| acc.mul_add(y, p));
        if !is_finite(scaled) {
            return Err(Error::InvalidRadiance);
        }
        Ok(scaled.scale(self.weight() / p))
    }

    /// `∫ L(ω)·cosᵉ θ dω` with radiance from a callback.
    ///
    /// # Errors
    /// [`Error::InvalidRadiance`] for a NaN or infinite value.
    pub fn integrate<T: Radiance, F: FnMut(Vec3) -> T>(&self, mut radiance: F) -> Result<T, Error> {
        weighted_sum(self.iter().map(&mut radiance), self.set.len(), self.weight())
    }
}

/// `w·Σ yⱼ` for `n` values `yⱼ`: the plain sum times `w` when that sum is finite (bit for bit
/// the unscaled arithmetic), else the sum of `yⱼ·2^−⌈log₂ n⌉` (which cannot overflow for
/// finite values) times `w·2^⌈log₂ n⌉`. Both sums are kept as the values go by, so each is
/// read once; [`Error::InvalidRadiance`] when a value is NaN or infinite.
fn weighted_sum<T: Radiance>(
    values: impl Iterator<Item = T>,
    n: usize,
    w: f32,
) -> Result<T, Error> {
    let () = crate::radiance::Channels::<T>::VALID;
    let p = prescale(n);
    let (plain, scaled) =
        values.fold((T::ZERO, T::ZERO), |(plain, scaled), y| (plain.add(y), scaled.mul_add(y, p)));
    if is_finite(plain) {
        Ok(plain.scale(w))
    } else if is_finite(scaled) {
        Ok(scaled.scale(w / p))
    } else {
        Err(Error::InvalidRadiance)
    }
}

/// `2^−⌈log₂ n⌉` (1 for `n ≤ 1`; `n ≤ 2²⁴`): `n` samples of at most `f32::MAX` scaled by it
/// sum to at most `f32::MAX`.
fn prescale(n: usize) -> f32 {
    let bits = usize::BITS - n.saturating_sub(1).leading_zeros();
    f32::from_bits((127u32.saturating_sub(bits)) << 23)
}

fn is_finite<T: Radiance>(x: T) -> bool {
    (0..T::CHANNELS).all(|c| x.channel(c).is_finite())
}

/// Irradiance `E(n) = ∫ L(ω)·max(0, n·ω) dω` from `N` cosine-morphed hemisphere SF
/// directions about `normal`, rotated about it by `phase_bits / 2⁶⁴` turn.
///
/// # Errors
/// [`Error::InvalidDirection`] for a zero or non-finite normal, [`Error::InvalidRadiance`] for
/// a NaN or infinite radiance value.
///
/// ```
/// use sphere_quadrature::{qmc, Vec3};
/// let e = qmc::irradiance::<64, f32, _>(Vec3::Z, 0, |_| 1.0).unwrap();
/// assert!((e - core::f32::consts::PI).abs() < 1e-5);
/// ```
///
/// `N = 0` does not compile:
/// ```compile_fail
/// # use sphere_quadrature::{qmc, Vec3};
/// let _ = qmc::irradiance::<0, f32, _>(Vec3::Z, 0, |_| 1.0);
/// ```
pub fn irradiance<const N: usize, T: Radiance, F: FnMut(Vec3) -> T>(
    normal: Vec3,
    phase_bits: u64,
    radiance: F,
) -> Result<T, Error> {
    const { assert!(N > 0 && N <= crate::sf::MAX_POINTS, "N must be in 1..=2^24") };
    LobeSampler::new(normal, Lobe::Cosine, N, phase_bits)?.integrate(radiance)
}

/// Normalised Phong glossy radiance `∫ L(ω)·(e+1)/(2π)·max(0, r·ω)ᵉ dω` from `N` morphed
/// hemisphere SF directions about `reflection`, rotated about it by `phase_bits / 2⁶⁴` turn.
///
/// # Errors
/// [`Error::InvalidDirection`] for a zero or non-finite `reflection`,
/// [`Error::InvalidExponent`] for a negative, NaN or infinite exponent,
/// [`Error::InvalidRadiance`] for a NaN or infinite radiance value.
///
/// # Examples
/// ```
/// use sphere_quadrature::{qmc, Error, Vec3};
///
/// // The normalised lobe integrates to 1: a constant radiance comes back unchanged.
/// let g = qmc::phong::<32, [f32; 3], _>(Vec3::new(1.0, 1.0, 0.0), 50.0, 0, |_| [0.2, 0.4, 0.8])?;
/// assert!(g.iter().zip([0.2, 0.4, 0.8]).all(|(a, b)| (a - b).abs() < 1e-5));
/// assert_eq!(qmc::phong::<32, f32, _>(Vec3::Z, -1.0, 0, |_| 1.0), Err(Error::InvalidExponent));
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
pub fn phong<const N: usize, T: Radiance, F: FnMut(Vec3) -> T>(
    reflection: Vec3,
    exponent: f32,
    phase_bits: u64,
    radiance: F,
) -> Result<T, Error> {
    const { assert!(N > 0 && N <= crate::sf::MAX_POINTS, "N must be in 1..=2^24") };
    let lobe = Lobe::phong(exponent)?;
    let s = LobeSampler::new(reflection, lobe, N, phase_bits)?;
    // The normalised lobe's weight is 1/N: the 2π/(e+1) of `integrate` cancels.
    weighted_sum(s.iter().map(radiance), N, 1.0 / N as f32)
}
