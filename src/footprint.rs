//! Sample footprints: what one probe sample measures.
//!
//! A *point* sample is the radiance `L(xᵢ)` in its direction. A *footprint* sample integrates
//! the radiance against a normalised lobe about its direction,
//! `Yᵢ = ∫ L(x)·f(xᵢ·x) dx` with `∫ f = 1`: a mip level or a prefiltered cube map, a cone in
//! voxel cone tracing, or a physical light sensor whose angular response makes each reading an
//! integral over a lobe. Two lobes are modelled:
//!
//! - [`Gaussian<S>`]: the normalised spherical Gaussian `f(t) = exp(S(t − 1))/F(S)`,
//!   `F(S) = 2π(1 − e^(−2S))/S`, of integer sharpness `S` (what prefiltered maps approximate:
//!   [`crate::envmap`] takes such samples from an equirectangular map);
//! - [`CosinePower<P>`]: the normalised cosine-power response `f(t) = (P + 1)/(2π)·max(0, t)ᴾ`
//!   (`P = 1`: a bare photodiode; larger `P`: a sensor behind a lens or a diffuser).
//!
//! By the Funk–Hecke theorem a footprint acts on the spherical harmonics of degree `l` as a
//! gain `g_l = 2π ∫ f(t)·P_l(t) dt` (`g₀ = 1`): for the Gaussian `g_l = i_l(S)/i₀(S)` (modified
//! spherical Bessel functions), for the cosine power `g_l = (P + 1)∫₀¹ tᴾ P_l(t) dt` (zero for
//! `l > P` with `l − P` even). [`Kind::gain`] evaluates them; `gen/probe.rs` bakes the probe
//! tables from them, and [`crate::probe::Probe`] takes the footprint as a type parameter,
//! `Probe<N, T, F>`, so that only the tables of the footprints a program uses are linked.
//!
//! ```
//! use sphere_quadrature::footprint::{CosinePower, Footprint, Gaussian, Kind, Point};
//!
//! assert_eq!(Point::KIND, Kind::Point);
//! assert_eq!(Gaussian::<8>::KIND, Kind::Gaussian { sharpness: 8 });
//! assert_eq!(CosinePower::<1>::KIND, Kind::CosinePower { exponent: 1 });
//! // Every footprint keeps constants: g₀ = 1; the photodiode's first gain is 2/3.
//! let g = |k: Kind, l| k.gain(l).unwrap();
//! assert!((g(Gaussian::<8>::KIND, 0) - 1.0).abs() < 1e-12);
//! assert!((g(CosinePower::<1>::KIND, 1) - 2.0 / 3.0).abs() < 1e-12);
//! assert_eq!(g(CosinePower::<1>::KIND, 3), 0.0);
//! ```

use crate::error::Error;
use crate::legendre;
use core::f64::consts::PI;

/// What one sample measures, as a run-time value (see the module docs).
///
/// # Examples
/// ```
/// use sphere_quadrature::footprint::Kind;
///
/// // The gains g_l of the Funk–Hecke theorem: g₀ = 1 (constants are kept), then they fall.
/// let k = Kind::Gaussian { sharpness: 8 };
/// assert!((k.gain(0)? - 1.0).abs() < 1e-12);
/// assert!(k.gain(1)? < 1.0 && k.gain(2)? < k.gain(1)?);
/// assert_eq!(Kind::Point.gain(5)?, 1.0);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Kind {
    /// The radiance in the sample's direction.
    Point,
    /// The normalised spherical Gaussian of this sharpness about the sample's direction.
    Gaussian {
        /// Sharpness `S ≥ 1` of `exp(S(t − 1))`.
        sharpness: u32,
    },
    /// The normalised cosine-power response `(P + 1)/(2π)·max(0, t)ᴾ`.
    CosinePower {
        /// The exponent `P ≥ 1`.
        exponent: u32,
    },
}

/// The largest Gaussian sharpness and cosine-power exponent a footprint may have.
pub const MAX_PARAMETER: u32 = 4096;

impl Kind {
    /// The normalised response `f(t)` at `t = xᵢ·x` (`∫ f = 1` over the sphere), in f64;
    /// `None` for [`Kind::Point`] (a delta) or a parameter of zero or above
    /// [`MAX_PARAMETER`]. `t` is clamped to `[−1, 1]`.
    #[must_use]
    pub fn response(self, t: f64) -> Option<f64> {
        let t = t.clamp(-1.0, 1.0);
        match self {
            Kind::Point => None,
            Kind::Gaussian { sharpness: s } if (1..=MAX_PARAMETER).contains(&s) => {
                let s = f64::from(s);
                // exp(S(t − 1))·S/(2π(1 − e^(−2S))).
                Some(libm::exp(s * (t - 1.0)) * s / (-2.0 * PI * libm::expm1(-2.0 * s)))
            }
            Kind::CosinePower { exponent: p } if (1..=MAX_PARAMETER).contains(&p) => {
                let p = f64::from(p);
                Some(if t > 0.0 { (p + 1.0) / (2.0 * PI) * libm::pow(t, p) } else { 0.0 })
            }
            _ => None,
        }
    }

    /// The Funk–Hecke gain `g_l = 2π ∫ f(t)·P_l(t) dt` of degree `l ≤ 1024`, in f64
    /// (`1` for every `l` of a point sample).
    ///
    /// Gaussian: `i_l(S)/i₀(S)` by the backward continued fraction
    /// `i_k/i_{k−1} = S/(2k + 1 + S·i_{k+1}/i_k)` started 32 steps above `max(l, S)`, where
    /// the start no longer matters (accurate to a few ulp). Cosine power: the moments
    /// `(P + 1)∫₀¹ tᴾ P_l(t) dt` by the two-step recurrence of its closed
    /// form (a product of `l/2` rational factors).
    ///
    /// # Errors
    /// [`Error::InvalidResponse`] for a parameter of zero or above [`MAX_PARAMETER`], or
    /// `l > 1024`.
    pub fn gain(self, l: usize) -> Result<f64, Error> {
        if l > 1024 {
            return Err(Error::InvalidResponse);
        }
        match self {
            Kind::Point => Ok(1.0),
            Kind::Gaussian { sharpness: s } if (1..=MAX_PARAMETER).contains(&s) => {
                Ok(legendre::gaussian_gain(f64::from(s), l))
            }
            Kind::CosinePower { exponent: p } if (1..=MAX_PARAMETER).contains(&p) => {
                Ok(legendre::CosinePowerGains::at(f64::from(p), l))
            }
            _ => Err(Error::InvalidResponse),
        }
    }
}

/// A footprint as a type, for [`crate::probe::Probe`]'s third parameter; sealed.
///
/// # Examples
/// ```
/// use sphere_quadrature::footprint::{CosinePower, Footprint, Kind, Point};
///
/// // The type names the footprint at compile time; KIND gives it at run time.
/// fn describe<F: Footprint>() -> Kind {
///     F::KIND
/// }
/// assert_eq!(describe::<Point>(), Kind::Point);
/// assert_eq!(describe::<CosinePower<1>>(), Kind::CosinePower { exponent: 1 });
/// ```
pub trait Footprint: sealed::Sealed + Copy + Default + core::fmt::Debug + 'static {
    /// The footprint as a run-time value.
    const KIND: Kind;
}

/// Point samples (the default): each sample is the radiance in its direction.
///
/// # Examples
/// ```
/// use sphere_quadrature::footprint::Point;
/// use sphere_quadrature::{probe::Probe, Vec3};
///
/// // `Probe<N>` is `Probe<N, f32, Point>`: each sample is the radiance in its direction.
/// let mut probe: Probe<16, f32, Point> = Probe::<16>::new();
/// probe.update(&[1.0; 16])?;
/// assert!((probe.irradiance(Vec3::Z)?.value - core::f32::consts::PI).abs() < 1e-4);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Point;

/// Samples that integrate the normalised spherical Gaussian of sharpness `S` about their
/// directions (see the module docs).
///
/// # Examples
/// ```
/// use sphere_quadrature::footprint::{Footprint, Gaussian};
/// use sphere_quadrature::{probe::Probe, Vec3};
///
/// // A probe of 64 prefiltered samples (a mip level, a cone): the SG of sharpness 8 = N/8.
/// let mut probe = Probe::<64, f32, Gaussian<8>>::new();
/// // A constant is unchanged by any normalised filter.
/// probe.update(&[2.0; 64])?;
/// let e = probe.irradiance(Vec3::X)?;
/// assert!((e.value - 2.0 * core::f32::consts::PI).abs() < 1e-3);
/// assert!(Gaussian::<8>::KIND.gain(1)? < 1.0);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Gaussian<const S: u32>;

/// Samples that integrate the normalised cosine-power response `max(0, t)ᴾ` about their
/// directions: a light sensor (`P = 1`: a bare photodiode).
///
/// # Examples
/// ```
/// use sphere_quadrature::footprint::CosinePower;
/// use sphere_quadrature::{probe::Probe, Vec3};
///
/// // Sixteen photodiodes; each reads E(xᵢ)/π, the irradiance at its own direction over π.
/// let mut probe = Probe::<16, f32, CosinePower<1>>::new();
/// // Under a constant sky of 1 every photodiode reads 1, and the irradiance is π.
/// probe.update(&[1.0; 16])?;
/// assert!((probe.irradiance(Vec3::Z)?.value - core::f32::consts::PI).abs() < 1e-3);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CosinePower<const P: u32>;

impl Footprint for Point {
    const KIND: Kind = Kind::Point;
}
impl<const S: u32> Footprint for Gaussian<S> {
    const KIND: Kind = Kind::Gaussian { sharpness: S };
}
impl<const P: u32> Footprint for CosinePower<P> {
    const KIND: Kind = Kind::CosinePower { exponent: P };
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for super::Point {}
    impl<const S: u32> Sealed for super::Gaussian<S> {}
    impl<const P: u32> Sealed for super::CosinePower<P> {}
}
