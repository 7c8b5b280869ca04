//! Probes over sensor layouts: the hardware's own directions, angular responses and noise.
//!
//! A [`LayoutProbe`] takes `K` readings from sensors wherever a board puts them (six
//! photodiodes on the faces of a cube, a dome of five, a ring on a ceiling fixture), each with
//! its own angular response, and answers irradiance for any normal with an error bar.
//!
//! # Model
//! Sensor `i` looks along `dᵢ` with a normalised response `fᵢ` (`∫ fᵢ = 1`) and reads
//! `Yᵢ = ∫ L(x)·fᵢ(dᵢ·x) dx + εᵢ`. By the Funk–Hecke theorem a response acts on the
//! spherical harmonics of degree `l` as a gain `g_l` ([`Response::gains`]). The radiance is a
//! Gaussian process with an isotropic covariance of Legendre spectrum `K_l`
//! ([`Prior::spectrum`]) scaled by `s = σ_f²`, so
//! - `Cov(Yᵢ, Yⱼ) = s·Σ_l K_l gᵢ_l gⱼ_l (2l + 1)/(4π)·P_l(dᵢ·dⱼ) + δᵢⱼ·nᵢ`,
//! - `Cov(Yᵢ, E(n)) = s·Σ_l K_l gᵢ_l c_l (2l + 1)/(4π)·P_l(dᵢ·n)` with the clamped cosine's
//!   factors `c_l` (`c₀ = π`),
//!
//! and a prior mean that is zero, a constant, or a multiple of a zonal profile about the
//! layout's `+z` (light from above: [`Mean`]), its coefficients by generalised least squares.
//! The noise of sensor `i` has variance `nᵢ = wᵢ²·σ² + η²·Yᵢ²`: `σ` absolute, scaled by the
//! sensor's [`Sensor::noise_scale`] `wᵢ`, and `η` relative to the reading ([`Noise`]).
//!
//! A reading may be negative (an offset-corrected sensor reads a little below zero in the
//! dark): the model is linear in the readings, so it is data like any other, and its
//! relative noise is `η²·Yᵢ²` all the same. Without noise the values are linear in the
//! readings; negating every reading negates every value and keeps every variance.
//!
//! A prior whose level dwarfs the rest (`K₀` above 2⁸ times every other `K_l`, with a zero
//! mean and no zonal covariance of the level) is taken in its limit, an unknown constant
//! fitted by generalised least squares: f32 could not hold the rest of the covariance beside
//! a level of 10⁶ times its variance, and the limit is within 8.3·10⁻⁶ of the largest value
//! from 2⁸ on (measured on a cube against the f64 reference, `K₀` from 10² to 10³⁰). Sensors
//! that see little but the level (gains of degree ≥ 1 below about 10⁻⁹) keep the prior as
//! given: the limit would leave them a covariance they barely see.
//!
//! # Units
//! Every statistic is computed relative to a power of two near the largest reading (or the
//! absolute noise, if larger) and the spectrum relative to a power of two near its largest
//! `K_l`: readings times `c` give values `c` times and variances `c²` times, for `c` from
//! 10⁻³⁰ to 10³⁰, subnormal readings included (measured on 16 Fibonacci sensors: within 10⁻⁵
//! and 10⁻⁴ wherever the scaled answer is a normal f32, with the same decisions). A result is
//! `±∞` only where it exceeds `f32::MAX` (the variances of readings spread over more than
//! about 10¹⁹; a glossy lobe whose integral exceeds it), and 0 or subnormal only below the
//! normal range. A stream ([`LayoutProbe::pool`]) keeps its pooled readings in units of a
//! power of two near the largest, so powers of two are exact below the normal range too:
//! there the readings keep only the bits f32 has, and the answers are those of these
//! readings, to the rounding of a sub-normal result. The spectrum times `c` gives the same
//! values within 10⁻⁵ and [`LayoutProbe::signal_variance`] `1/c` times within 5·10⁻⁵ (the
//! scale's search stops within 10⁻⁵ in `ln s`); its variances move as an ε change of the
//! prior moves them ("Accuracy").
//!
//! # Cost
//! [`LayoutProbe::new`] builds everything at run time, with no allocation: the `K × K`
//! covariance (Legendre series), its eigendecomposition after whitening by `wᵢ` (Householder
//! reflections, implicit QL and one polishing Jacobi sweep, O(K³)), a 129-node table of the
//! query covariance per distinct response, and the direction average of the query covariances'
//! products (their degrees ≤ 2 from the nine projected coefficients, the rest as a product of
//! matrices).
//! Because the whitened covariance is `s·Λ + ν·I` in the eigenbasis for every `s` and noise
//! level `ν`, each update projects the readings (`K²` multiply-adds per channel), chooses
//! `s` by restricted maximum likelihood in O(K) per trial, and forms the weights (`K²`).
//! With a relative noise the sensors' noise levels differ: the scale is chosen with their
//! mean `ν̄`, and the mean and the weights come from the exact system `s·C̃ + diag(νᵢ)`
//! (`C̃` with the eigenvalues the model floors, as in the eigenbasis, so that a vanishing
//! relative noise gives the answers without noise), factored once per channel (`LDLᵀ`,
//! `K³/6` multiply-adds, no square roots) and each solve refined once with its residual
//! summed in compensated arithmetic (`K²` exact products); the variances take the noise at
//! its mean level.
//! An irradiance query is `K` table lookups; its error bar is the exact direction average
//! of the posterior variance, computed once per update; [`LayoutProbe::irradiance_variance`]
//! is the exact variance at one normal, O(K²).
//! Instructions per call, flash and RAM on a Cortex-M4F: [`costs`](crate::costs#the-layout-probe).
//!
//! Channels are fitted one by one, each with its own scale. Their errors are correlated, so
//! the variance of a combination of channels (luminance from RGB) is not a sum of the
//! channels' variances: [`LayoutProbe::combined_probe`] fits the combined readings as one channel.
//!
//! # Accuracy
//! - **Against an f64 reference** (the unit tests: textbook Gaussian-process formulas in
//!   f64, the same model: eigenvalues floored at 10⁻⁶ of the largest): values within
//!   4.7·10⁻⁶ of the largest value for the readings of a light (icosahedron, 16 Fibonacci
//!   sensors, cube corners, cube and 10 random sensors, [`Prior::ENVIRONMENT`] and
//!   `squared_exponential(1)`, without noise; 2.4·10⁻² for readings no light can produce,
//!   "Rounding"),
//!   exact variances within 2·10⁻⁴ (cube, dome), the log likelihood within 10⁻⁶; with a
//!   relative noise the weights solve an f32 system of condition about 10⁴, refined once,
//!   and values agree within 9·10⁻⁷.
//! - **Rounding**: one ulp on one reading of a light moves no value by more than 1.8·10⁻⁶ of
//!   the largest and `s` by 4.9·10⁻⁵ (the layouts above and 64 Fibonacci sensors, with and
//!   without noise). Readings that no light can produce (cosine sensors at antipodes that
//!   disagree about degree 1, all their difference sees: at random, or with offset or gain
//!   errors) are explained by a large scale and weights of 10⁴ and more; without noise one
//!   ulp then moves values by up to 1.9·10⁻² of the largest (0.4–0.9·10⁻² on an icosahedron
//!   and the corners of a cube, 1.9·10⁻² on 64 sensors). Declare a noise that covers the
//!   disagreement: at an absolute noise as large as the readings' random part, 4.4·10⁻⁵. A
//!   variance is the
//!   prior's less the part the readings explain, down to 1/30 000 of the prior at a normal
//!   for 16 sensors without noise: an ε change of the prior (its spectrum times a number
//!   that is not a power of two) moves the exact variances there by up to 2.8·10⁻² and the
//!   averaged one by 1.1·10⁻³ (with noise, 1.4·10⁻³). A variance below what f32 resolves is
//!   reported at `ε/16` of the prior's, never 0; readings that fit the mean exactly
//!   (identical readings under a constant mean) leave the scale at the rounding of that fit,
//!   `ε·r̃ᵀΛ⁻¹r̃/(K − p)`, not 0.
//! - **The O(1) variance** of [`LayoutProbe::irradiance`] is within 1 % of the mean of
//!   [`LayoutProbe::irradiance_variance`] over directions (measured 0.8 % on the layouts
//!   above and 64 Fibonacci sensors, without noise and at 1 % absolute, 1 % relative and
//!   10 %/5 % noise) wherever the posterior variance is at least 10⁻⁵ of the prior's; below
//!   that (a smooth prior without noise: 10⁻⁸ for 64 sensors and `squared_exponential(1)`),
//!   within 24 %.
//! - **On real maps** (the repository's `sensors` benchmark: held-out environment maps, exact
//!   readings of every pixel, the prior of [`Prior::for_layout`]), the irradiance error over
//!   the degree-2 SH fit's on the same readings, mean over maps: 0.57–1.00 for sensors all
//!   round (16 on a spherical Fibonacci set: 0.70 on sharp light, 0.57 on smooth light,
//!   without noise; a cube ties the fit), 0.96–1.04 for layouts that look into one
//!   hemisphere (a dome, rings with and without a zenith sensor, a cube on a table, a
//!   wall), where they look; no map above 1.14. Over the best of the nearest sensor, the
//!   cosine-weighted average and the degree-1 and degree-2 fits, per map: 0.57–1.00 all
//!   round, 0.96–1.10 one-sided (a ring of 8 without a zenith sensor 1.07–1.10, its worst
//!   map 1.57: there the degree-1 fit or the cosine average beats the degree-2 fit on some
//!   maps). 2σ of the direction-averaged variance holds for 94–99 % of the queries all
//!   round and 97–100 % where one-sided layouts look (the average includes the half they
//!   cannot see); 2σ of the exact variance for 86–100 %.
//!
//! # Tables at compile time
//! [`LayoutProbe::new`] is a `const fn`: a probe in a `static` or `const` has its tables
//! computed by the compiler (in flash, no run-time cost), and a bad layout is a compile error
//! at that line. The same code runs at run time for a layout learned at boot, with the same
//! bits. Large layouts take the compiler a while: at `K = 64` its `long_running_const_eval`
//! lint stops the build unless the `static` carries `#[allow(long_running_const_eval)]`, and
//! the evaluation took 17 s in one measurement (`K = 16` needs no attribute).
//! ```
//! use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
//! use sphere_quadrature::Vec3;
//!
//! const FACES: [Sensor; 6] = [
//!     Sensor::cosine(Vec3::X),
//!     Sensor::cosine(Vec3::new(-1.0, 0.0, 0.0)),
//!     Sensor::cosine(Vec3::Y),
//!     Sensor::cosine(Vec3::new(0.0, -1.0, 0.0)),
//!     Sensor::cosine(Vec3::Z),
//!     Sensor::cosine(Vec3::new(0.0, 0.0, -1.0)),
//! ];
//! const NOISE: Noise = Noise { absolute: 0.0, relative: 0.01 };
//! static CUBE: LayoutProbe<6> = match LayoutProbe::new(&FACES, Prior::ENVIRONMENT, NOISE) {
//!     Ok(probe) => probe,
//!     Err(_) => panic!("bad sensor layout"),
//! };
//!
//! let mut probe = CUBE.clone();
//! probe.update(&[1.0, 1.2, 0.9, 1.1, 2.0, 0.3])?;
//! let runtime = LayoutProbe::<6>::new(&FACES, Prior::ENVIRONMENT, NOISE)?;
//! let mut twin = runtime.clone();
//! twin.update(&[1.0, 1.2, 0.9, 1.1, 2.0, 0.3])?;
//! assert_eq!(probe.irradiance(Vec3::Z)?, twin.irradiance(Vec3::Z)?);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//! ```compile_fail,E0080
//! use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
//! use sphere_quadrature::Vec3;
//!
//! // A zero direction: the build fails here.
//! const BAD: [Sensor; 2] = [Sensor::cosine(Vec3::ZERO), Sensor::cosine(Vec3::Z)];
//! static PROBE: LayoutProbe<2> = match LayoutProbe::new(&BAD, Prior::ENVIRONMENT, Noise::NONE) {
//!     Ok(probe) => probe,
//!     Err(_) => panic!("bad sensor layout"),
//! };
//! ```
//!
//! # Example
//! ```
//! use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
//! use sphere_quadrature::Vec3;
//!
//! // Six bare photodiodes on the faces of a cube.
//! let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
//! let sensors = faces.map(Sensor::cosine);
//! let mut probe = LayoutProbe::<6>::new(&sensors, Prior::squared_exponential(4.0)?, Noise::NONE)?;
//! // A sky 1 + 0.5·z: a cosine sensor along d reads (1 + 0.5·(2/3)·d_z).
//! let readings = faces.map(|d| 1.0 + 0.5 * 2.0 / 3.0 * d.z);
//! probe.update(&readings)?;
//! let e = probe.irradiance(Vec3::Z)?;
//! assert!((e.value - 4.18879).abs() < 0.05, "{}", e.value);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```

// Matrix code reads clearer with its indices.
#![allow(clippy::needless_range_loop)]

mod init;
mod learned;
mod linalg;
mod queries;
mod update;

#[cfg(test)]
mod contracts;
#[cfg(test)]
mod tests;

use linalg::LogProduct;

use crate::change::{gaussian_log_bf, log_odds, logistic, soft_reset, Change, DEFAULT_HAZARD};
use crate::error::Error;
use crate::estimate::Estimate;
use crate::harmonics;
use crate::legendre;
use crate::math;
pub use crate::noise::{Noise, MAX_RELATIVE_NOISE};
use crate::radiance::{from_channels, Radiance, MAX_CHANNELS};
use crate::sg::SphericalGaussian;
use crate::sh::ShL2;
use crate::vec3::Vec3;

/// The most sensors a layout may have.
pub const MAX_SENSORS: usize = 64;
/// Legendre degrees `0..DEGREES` of the spectra, gains and series.
pub const DEGREES: usize = 33;
/// The most distinct responses in one layout (each has its query table).
pub const MAX_RESPONSES: usize = 4;
/// Nodes of the query-covariance tables over `t = dᵢ·n ∈ [−1, 1]`.
const NODES: usize = 129;
/// The least eigenvalue of the whitened covariance, relative to the largest.
const FLOOR: f32 = 1e-6;
const FOUR_PI: f32 = 4.0 * core::f32::consts::PI;

/// A sensor's angular response, normalised to `∫ f = 1` over the sphere.
///
/// ```
/// use sphere_quadrature::layout::Response;
///
/// // A bare photodiode (cosine response): g₁ = 2/3, g₂ = 1/4, g₃ = 0.
/// let g = Response::CosinePower(1.0).gains()?;
/// assert!((g[0] - 1.0).abs() < 1e-7 && (g[1] - 2.0 / 3.0).abs() < 1e-7);
/// assert!((g[2] - 0.25).abs() < 1e-7 && g[3].abs() < 1e-7);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Response {
    /// `(P + 1)/(2π)·max(0, t)ᴾ`, `P ≥ 0` (`P = 1`: a bare photodiode; larger: a lens or a
    /// diffuser; `P = 0`: a hemisphere).
    CosinePower(f32),
    /// The normalised spherical Gaussian `exp(S(t − 1))/F(S)`, `0 < S ≤ 4096`.
    Gaussian(f32),
    /// Legendre gains `g_l`, `l < DEGREES`, with `g₀ = 1` (from a measured table:
    /// [`Response::from_table`]).
    Gains([f32; DEGREES]),
}

impl Response {
    /// The Legendre gains `g_l = 2π∫ f(t)·P_l(t) dt`, `l < DEGREES`, computed in f64 and
    /// rounded once. [`Error::InvalidResponse`] for a parameter out of range or gains that
    /// are not finite, do not start with `g₀ = 1` or exceed 1 in magnitude.
    ///
    /// ```
    /// use sphere_quadrature::layout::Response;
    ///
    /// assert!(Response::Gaussian(-1.0).gains().is_err());
    /// let g = Response::Gaussian(8.0).gains()?;
    /// assert!(g[1] < 1.0 && g[2] < g[1]);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub const fn gains(&self) -> Result<[f32; DEGREES], Error> {
        match *self {
            Response::CosinePower(p) => {
                if !(p.is_finite() && p >= 0.0 && p <= 4096.0) {
                    return Err(Error::InvalidResponse);
                }
                Ok(cosine_power_gains(p as f64))
            }
            Response::Gaussian(s) => {
                if !(s.is_finite() && s > 0.0 && s <= 4096.0) {
                    return Err(Error::InvalidResponse);
                }
                Ok(gaussian_gains(s as f64))
            }
            Response::Gains(values) => {
                if absolute(values[0] - 1.0) > 1e-6 {
                    return Err(Error::InvalidResponse);
                }
                let mut l = 0;
                while l < DEGREES {
                    if !values[l].is_finite() || absolute(values[l]) > 1.0 + 1e-6 {
                        return Err(Error::InvalidResponse);
                    }
                    l += 1;
                }
                Ok(values)
            }
        }
    }

    /// Gains from a measured response: `values[k]` at angle `angles_deg[k]` from the axis
    /// (increasing, from 0 to at most 180°; zero beyond the last angle, linear between),
    /// normalised so that `g₀ = 1`. [`Error::InvalidResponse`] for non-finite, negative or
    /// unsorted input, fewer than two points, or a response that integrates to zero;
    /// [`Error::LengthMismatch`] when the slices differ in length.
    ///
    /// The integrals `2π∫ f(t)·P_l(t) dt` are taken in f64 over each linear piece (in angle)
    /// with a 16-point Gauss–Legendre rule.
    ///
    /// ```
    /// use sphere_quadrature::layout::Response;
    ///
    /// // A cosine response tabulated every 5°: the gains of CosinePower(1) within 1e-4.
    /// let angles: Vec<f32> = (0..=18).map(|k| 5.0 * k as f32).collect();
    /// let values: Vec<f32> = angles.iter().map(|a| a.to_radians().cos().max(0.0)).collect();
    /// let table = Response::from_table(&angles, &values)?.gains()?;
    /// let exact = Response::CosinePower(1.0).gains()?;
    /// assert!(table.iter().zip(exact).all(|(a, b)| (a - b).abs() < 1e-3));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn from_table(angles_deg: &[f32], values: &[f32]) -> Result<Response, Error> {
        if angles_deg.len() != values.len() {
            return Err(Error::LengthMismatch);
        }
        if angles_deg.len() < 2
            || angles_deg.iter().chain(values).any(|v| !v.is_finite())
            || values.iter().any(|&v| v < 0.0)
            || angles_deg.windows(2).any(|w| w[1] <= w[0])
            || angles_deg[0] < 0.0
            || angles_deg[angles_deg.len() - 1] > 180.0
        {
            return Err(Error::InvalidResponse);
        }
        let mut sums = [0.0f64; DEGREES];
        for (a, v) in angles_deg.windows(2).zip(values.windows(2)) {
            let (t0, t1) = (f64::from(a[0]).to_radians(), f64::from(a[1]).to_radians());
            let (v0, v1) = (f64::from(v[0]), f64::from(v[1]));
            for (x, w) in GAUSS_16 {
                for sign in [-1.0, 1.0] {
                    let u = 0.5 * (1.0 + sign * x);
                    let theta = t0 + u * (t1 - t0);
                    let f = v0 + u * (v1 - v0);
                    let weight = 0.5 * w * (t1 - t0) * math::sin64(theta) * f;
                    let t = math::cos64(theta);
                    let (mut p0, mut p1) = (1.0, t);
                    sums[0] += weight;
                    sums[1] += weight * t;
                    for (l, s) in sums.iter_mut().enumerate().skip(2) {
                        let lf = l as f64;
                        let p2 = ((2.0 * lf - 1.0) * t * p1 - (lf - 1.0) * p0) / lf;
                        *s += weight * p2;
                        p0 = p1;
                        p1 = p2;
                    }
                }
            }
        }
        if sums[0] <= 0.0 || !sums[0].is_finite() {
            return Err(Error::InvalidResponse);
        }
        let norm = sums[0];
        Ok(Response::Gains(sums.map(|s| (s / norm) as f32)))
    }
}

/// Nodes `x > 0` and weights of the 16-point Gauss–Legendre rule on `[−1, 1]`.
const GAUSS_16: [(f64, f64); 8] = [
    (0.095_012_509_837_637_44, 0.189_450_610_455_068_5),
    (0.281_603_550_779_258_9, 0.182_603_415_044_923_6),
    (0.458_016_777_657_227_4, 0.169_156_519_395_002_5),
    (0.617_876_244_402_643_7, 0.149_595_988_816_576_7),
    (0.755_404_408_355_003, 0.124_628_971_255_533_9),
    (0.865_631_202_387_831_7, 0.095_158_511_682_492_8),
    (0.944_575_023_073_232_6, 0.062_253_523_938_647_9),
    (0.989_400_934_991_649_9, 0.027_152_459_411_754_1),
];

/// One sensor of a layout.
///
/// ```
/// use sphere_quadrature::layout::{Response, Sensor};
/// use sphere_quadrature::Vec3;
///
/// let s = Sensor::cosine(Vec3::Z);
/// assert_eq!(s.response, Response::CosinePower(1.0));
/// let lens = Sensor::new(Vec3::X, Response::CosinePower(2.0)).with_noise_scale(2.0);
/// assert_eq!(lens.noise_scale, 2.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sensor {
    /// Where the sensor looks (normalised by [`LayoutProbe::new`]).
    pub direction: Vec3,
    /// Its angular response.
    pub response: Response,
    /// `wᵢ`: its absolute noise relative to the layout's [`Noise::absolute`] (1 for equal
    /// sensors; 2 for one twice as noisy). Finite and positive; only ratios matter, up to
    /// [`MAX_NOISE_SCALE_RATIO`] within a layout with an absolute noise.
    pub noise_scale: f32,
}

impl Sensor {
    /// A sensor with this response and noise scale 1.
    #[must_use]
    pub const fn new(direction: Vec3, response: Response) -> Self {
        Sensor { direction, response, noise_scale: 1.0 }
    }

    /// A bare photodiode: cosine response, noise scale 1.
    #[must_use]
    pub const fn cosine(direction: Vec3) -> Self {
        Sensor::new(direction, Response::CosinePower(1.0))
    }

    /// The same sensor with noise scale `w`.
    #[must_use]
    pub const fn with_noise_scale(self, w: f32) -> Self {
        Sensor { noise_scale: w, ..self }
    }
}

/// The prior mean of the radiance.
///
/// ```
/// use sphere_quadrature::layout::Mean;
///
/// // Brighter above: 1 + 0.8·z (Legendre coefficients about +z).
/// let mut profile = [0.0; 9];
/// profile[0] = 1.0;
/// profile[1] = 0.8;
/// let m = Mean::Zonal(profile);
/// assert_ne!(m, Mean::Constant);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mean {
    /// Zero: the level is part of the covariance.
    Zero,
    /// An unknown constant (generalised least squares).
    Constant,
    /// An unknown multiple of the zonal profile `Σ_l a_l·P_l(z)` about the layout's `+z`.
    Zonal([f32; 9]),
}

/// The Gaussian-process prior of a [`LayoutProbe`]: the covariance spectrum and the mean.
///
/// ```
/// use sphere_quadrature::layout::{Mean, Prior};
///
/// let p = Prior::squared_exponential(4.0)?;
/// assert_eq!(p.mean, Mean::Constant);
/// // exp(λ(t − 1)) at t = 1 is 1: Σ K_l (2l + 1)/(4π) = 1.
/// let at_one: f32 = p.spectrum.iter().enumerate().map(|(l, k)| k * (2 * l + 1) as f32).sum();
/// assert!((at_one / (4.0 * core::f32::consts::PI) - 1.0).abs() < 1e-5);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Prior {
    /// `K_l ≥ 0`: the covariance `Σ_l K_l (2l + 1)/(4π)·P_l(x·x′)` (before the scale `s`),
    /// that is `K_l` for every coefficient of degree `l`.
    pub spectrum: [f32; DEGREES],
    /// Covariances between the zonal coefficients about `+z` of degrees 0, 1 and 2 (before
    /// the scale): `(c₀₀, c₁₀)`, `(c₁₀, c₂₀)`, `(c₀₀, c₂₀)`; zero for an isotropic prior. With
    /// the spectrum's `K₀`, `K₁`, `K₂` on the diagonal they must form a positive
    /// semi-definite matrix. Light that comes from above: the level, the vertical gradient
    /// and the zonal degree 2 vary together.
    pub zonal: [f32; 3],
    /// The prior mean.
    pub mean: Mean,
    /// A factor on every variance the probe reports (finite, positive; 1 for the model's own
    /// variances): the learned priors carry one fitted so that 2σ intervals hold for 95 % of
    /// the errors on their training maps.
    pub variance_scale: f32,
}

impl Prior {
    /// Light in general, for layouts that look all round, in any orientation (what
    /// [`Prior::for_layout`] gives them; for sensors that all look into one hemisphere see
    /// [`Prior::ONE_SIDED`]): a zero mean and the mean angular power spectrum of the
    /// luminance (over its mean) of four real environment maps, indoor and outdoor, with
    /// pixels above 30 times the mean clamped (sun disks); computed in f64 from the maps and
    /// rounded once to f32.
    pub const ENVIRONMENT: Prior = Prior {
        spectrum: learned::ENVIRONMENT_SPECTRUM,
        zonal: [0.0; 3],
        mean: Mean::Zero,
        variance_scale: 1.0,
    };
    /// As [`Prior::ENVIRONMENT`] for light without sharp features: the same maps convolved
    /// with a spherical Gaussian of sharpness 10.
    pub const SMOOTH_ENVIRONMENT: Prior = Prior {
        spectrum: learned::SMOOTH_SPECTRUM,
        zonal: [0.0; 3],
        mean: Mean::Zero,
        variance_scale: 1.0,
    };
    /// Light from above, `+z` up, learned on a dome of 5 and a zenith sensor with a ring of
    /// 6 at 30°. A zero mean; degrees ≤ 2 flat (`K₀ = K₁ = K₂ = 1`, as the minimum-norm SH
    /// fit assumes) with zonal correlations from the same maps (about 0.50, 0.51 and 0.33:
    /// the level, the vertical gradient and the zonal degree 2 vary together), and above
    /// degree 2 their spectrum over the mean power per coefficient of degrees ≤ 2.
    ///
    /// Not a default: the zonal correlations extrapolate what a layout cannot see from
    /// what it sees, and where a layout cannot tell the level from the vertical gradient
    /// the extrapolation runs away. Eight sensors on a ring at 20° elevation, no zenith
    /// sensor, read a constant sky of 1 and this prior answers `E(+z) = 5.11` and
    /// `E(+x) = 2.35` where both are π; on held-out maps its error there is 3.0–5.3 times
    /// the degree-2 SH fit's on the same readings (its worst map 4.1–10.7 times), on a
    /// cube, its corners and a tetrahedron 1.24–1.66 times. [`Prior::for_layout`] is the
    /// recommendation for every layout.
    pub const SKY_ABOVE: Prior = Prior {
        spectrum: learned::ENVIRONMENT_SKY_SPECTRUM,
        zonal: learned::ENVIRONMENT_SKY_ZONAL,
        mean: Mean::Zero,
        variance_scale: learned::ENVIRONMENT_SKY_CALIBRATION,
    };
    /// As [`Prior::SKY_ABOVE`] for light without sharp features (not a default either).
    pub const SMOOTH_SKY_ABOVE: Prior = Prior {
        spectrum: learned::SMOOTH_SKY_SPECTRUM,
        zonal: learned::SMOOTH_SKY_ZONAL,
        mean: Mean::Zero,
        variance_scale: learned::SMOOTH_SKY_CALIBRATION,
    };
    /// Layouts whose sensors all look into one hemisphere (a dome, a ring, a device on a
    /// table or a wall), in any orientation: what the minimum-norm degree-2 SH fit assumes
    /// on degrees ≤ 2 (`K₀ = K₁ = K₂ = 1`, a zero mean, no preferred direction), and above
    /// degree 2 the spectrum of [`Prior::ENVIRONMENT`] over its mean power per coefficient
    /// of degrees ≤ 2. Its variance factor is fitted, leaving one training map out, so
    /// that 2σ of [`LayoutProbe::irradiance_variance`] holds for 95 % of the errors on the
    /// training maps where a dome of 5 and a ring of 6 with a zenith sensor look (without
    /// noise and at 1 % and 5 %).
    ///
    /// Why flat: such a layout cannot tell the level of the light from its gradient along
    /// the axis it looks along (a ring sees one mix of the level, the vertical gradient and
    /// the zonal degree 2, and nothing of the rest). A prior whose level dominates
    /// ([`Prior::ENVIRONMENT`], or a constant mean) credits the level with all of it and
    /// extrapolates the horizon's brightness to the zenith: on held-out maps a ring of 8 at
    /// 20° then errs up to 1.42 times as much as the degree-2 SH fit on the same readings
    /// (its worst map 4.1 times; with a constant mean up to 1.82 and 5.5 times), a dome of 5
    /// up to 1.68 times. The flat form shares the readings among the three as the SH fit
    /// does, which real light (brighter above the horizon than at it) rewards: 0.96–1.04
    /// times the SH fit's error on the one-sided layouts measured ([`Prior::for_layout`]).
    /// Its price is a constant sky, which the ring sees as brighter above: `E(+z) = 3.58`
    /// and `E(+x) = 2.78` instead of π, the SH fit's answers too.
    ///
    /// Where the half a layout cannot see is like the half it sees (a wall with `+z` up:
    /// sensors that look sideways, above and below the horizon), [`Prior::ENVIRONMENT`]
    /// does better: on 6 sensors on a wall, 0.59–0.87 times the SH fit's error against
    /// 1.00–1.04 for this prior. Choose it there if you know the orientation.
    pub const ONE_SIDED: Prior = Prior {
        spectrum: learned::ENVIRONMENT_SKY_SPECTRUM,
        zonal: [0.0; 3],
        mean: Mean::Zero,
        variance_scale: learned::ENVIRONMENT_ONE_SIDED_CALIBRATION,
    };
    /// As [`Prior::ONE_SIDED`] for light without sharp features: above degree 2 the
    /// spectrum of [`Prior::SMOOTH_ENVIRONMENT`].
    pub const SMOOTH_ONE_SIDED: Prior = Prior {
        spectrum: learned::SMOOTH_SKY_SPECTRUM,
        zonal: [0.0; 3],
        mean: Mean::Zero,
        variance_scale: learned::SMOOTH_ONE_SIDED_CALIBRATION,
    };

    /// The prior this crate recommends for these sensors, from their directions alone:
    /// [`Prior::ENVIRONMENT`] when they look all round (no closed hemisphere holds every
    /// direction: every direction of the sphere is in front of some sensor), else
    /// [`Prior::ONE_SIDED`]. A direction that is zero or not finite is skipped
    /// ([`LayoutProbe::new`] refuses it).
    ///
    /// Measured on held-out maps against the degree-2 SH fit on the same readings
    /// (minimum norm below 9 sensors, least squares from 9), mean over maps of the ratio of
    /// errors, without noise and at 1 % and 5 % relative noise, sharp and smooth light (the
    /// repository's `sensors` report): 0.57–1.00 on the layouts that see all round (a
    /// tetrahedron, a cube, its corners, an icosahedron, 10 random and 16 Fibonacci
    /// directions), 0.96–1.04 on the others (a cube on a table without its bottom face, a
    /// dome of 5, a ring of 6 with a zenith sensor, a ring of 8 at 20° without one, 6 on a
    /// wall), no map above 1.14. 2σ of the variance [`LayoutProbe::irradiance`] returns
    /// holds for 94–99 % of the queries all round; where one-sided layouts look, for
    /// 97–100 % (that variance is a direction average, and half the directions are out of
    /// their sight), and 2σ of [`LayoutProbe::irradiance_variance`] for 86–100 %.
    ///
    /// ```
    /// use sphere_quadrature::layout::{Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// assert_eq!(Prior::for_layout(&faces.map(Sensor::cosine)), Prior::ENVIRONMENT);
    /// // The same cube on a table, without its bottom face: every sensor looks into z ≥ 0.
    /// let table = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z].map(Sensor::cosine);
    /// assert_eq!(Prior::for_layout(&table), Prior::ONE_SIDED);
    /// ```
    #[must_use]
    pub const fn for_layout(sensors: &[Sensor]) -> Prior {
        if looks_all_round(sensors) {
            Prior::ENVIRONMENT
        } else {
            Prior::ONE_SIDED
        }
    }

    /// As [`Prior::for_layout`] for light without sharp features:
    /// [`Prior::SMOOTH_ENVIRONMENT`] or [`Prior::SMOOTH_ONE_SIDED`].
    #[must_use]
    pub const fn smooth_for_layout(sensors: &[Sensor]) -> Prior {
        if looks_all_round(sensors) {
            Prior::SMOOTH_ENVIRONMENT
        } else {
            Prior::SMOOTH_ONE_SIDED
        }
    }

    /// The squared-exponential kernel `exp(λ(x·x′ − 1))`, `0 < λ ≤ 64`, with a constant
    /// mean: `K_l = 4π·e^{−λ}·i_l(λ)`, computed in f64.
    pub fn squared_exponential(lambda: f32) -> Result<Prior, Error> {
        if !(lambda.is_finite() && lambda > 0.0 && lambda <= 64.0) {
            return Err(Error::InvalidPrior);
        }
        let g = Response::Gaussian(lambda).gains()?;
        let x = f64::from(lambda);
        // e^{−λ} i₀(λ) = (1 − e^{−2λ})/(2λ); below 10⁻⁴ its series 1 − λ + ⅔λ² − ⅓λ³ (the
        // difference cancels there: to 0 below about 5·10⁻¹⁷), within 10⁻¹⁶.
        let level = if x < 1e-4 {
            1.0 - x * (1.0 - x * (2.0 / 3.0 - x / 3.0))
        } else {
            (1.0 - math::exp64(-2.0 * x)) / (2.0 * x)
        };
        let k0 = 4.0 * core::f64::consts::PI * level;
        Ok(Prior {
            spectrum: g.map(|r| (k0 * f64::from(r)) as f32),
            zonal: [0.0; 3],
            mean: Mean::Constant,
            variance_scale: 1.0,
        })
    }

    /// The same prior with another mean.
    #[must_use]
    pub const fn with_mean(self, mean: Mean) -> Self {
        Prior { mean, ..self }
    }
}

/// Whether no closed hemisphere holds every sensor's direction (const; directions that are
/// zero or not finite are skipped). If one does, its axis can be turned until its boundary
/// holds two independent directions (or all of them, when they lie on one great circle), so
/// it suffices to try `±dᵢ × dⱼ` for every pair; a direction counts as inside when it is at
/// most 10⁻⁶ below the boundary (the rounding of a direction on it), in units of the largest
/// component of each vector. No square roots: O(K³) multiply-adds.
const fn looks_all_round(sensors: &[Sensor]) -> bool {
    let mut any_pair = false;
    let mut i = 0;
    while i < sensors.len() {
        let Some(a) = boxed(sensors[i].direction) else {
            i += 1;
            continue;
        };
        let mut j = i + 1;
        while j < sensors.len() {
            let Some(b) = boxed(sensors[j].direction) else {
                j += 1;
                continue;
            };
            let axis =
                Vec3::new(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
            if let Some(v) = boxed(axis) {
                any_pair = true;
                // Whether every direction lies in front of v, or every one behind it.
                let (mut front, mut back) = (true, true);
                let mut k = 0;
                while k < sensors.len() && (front || back) {
                    if let Some(d) = boxed(sensors[k].direction) {
                        let t = v.x * d.x + v.y * d.y + v.z * d.z;
                        front &= t >= -1e-6;
                        back &= t <= 1e-6;
                    }
                    k += 1;
                }
                if front || back {
                    return false;
                }
            }
            j += 1;
        }
        i += 1;
    }
    // Pairs but no hemisphere: all round. No two independent directions: one direction
    // (and its opposite) lies in a hemisphere.
    any_pair
}

/// `v` over its largest component's magnitude (const): each component in `[−1, 1]`; `None`
/// for a zero or non-finite vector.
const fn boxed(v: Vec3) -> Option<Vec3> {
    if !(v.x.is_finite() && v.y.is_finite() && v.z.is_finite()) {
        return None;
    }
    let (ax, ay, az) = (absolute(v.x), absolute(v.y), absolute(v.z));
    let m = if ax > ay { ax } else { ay };
    let m = if m > az { m } else { az };
    if m == 0.0 {
        return None;
    }
    Some(Vec3::new(v.x / m, v.y / m, v.z / m))
}

/// The Legendre gains of the normalised `(P + 1)/(2π)·max(0, t)ᴾ`, `P ≥ 0` (any size),
/// in f64 and rounded once.
const fn cosine_power_gains(p: f64) -> [f32; DEGREES] {
    let mut gains = legendre::CosinePowerGains::new(p);
    let mut g = [0.0f32; DEGREES];
    let mut l = 0;
    while l < DEGREES {
        g[l] = gains.next_gain() as f32;
        l += 1;
    }
    g
}

/// The Legendre gains `g_l = i_l(S)/i₀(S)` of the normalised spherical Gaussian of sharpness
/// `S > 0` (any size), in f64 and rounded once: by the continued fraction up to `S = 4096`
/// (every sensor), and the forward recurrence above (glossy lobes, where its rounding is
/// below 10⁻¹⁵ at these degrees).
const fn gaussian_gains(s: f64) -> [f32; DEGREES] {
    let mut g = [0.0f64; DEGREES];
    legendre::gaussian_gains(s, &mut g, f64::from_bits(4096f64.to_bits() + 1));
    let mut out = [0.0f32; DEGREES];
    let mut l = 0;
    while l < DEGREES {
        out[l] = g[l] as f32;
        l += 1;
    }
    out
}

/// The clamped cosine's gains `c_l = π·g_l(CosinePower(1))`, evaluated once.
const COSINE_FACTORS: [f32; DEGREES] = legendre::clamped_cosine_gains();

fn cosine_factors_lookup() -> [f32; DEGREES] {
    COSINE_FACTORS
}

/// `R·u` for the 3×3 zonal covariances.
const fn times_r(r: &[[f32; 3]; 3], u: &[f32; 3]) -> [f32; 3] {
    [
        r[0][0] * u[0] + r[0][1] * u[1] + r[0][2] * u[2],
        r[1][0] * u[0] + r[1][1] * u[1] + r[1][2] * u[2],
        r[2][0] * u[0] + r[2][1] * u[1] + r[2][2] * u[2],
    ]
}

/// Finite and at least 0 (const).
const fn non_negative(v: f32) -> bool {
    v.is_finite() && v >= 0.0
}

/// `e` with `2ᵉ ≤ x < 2ᵉ⁺¹` for a positive, finite `x` (subnormals too) (const); 0 otherwise.
const fn exponent_of(x: f32) -> i32 {
    if !(x > 0.0 && x.is_finite()) {
        return 0;
    }
    let bits = x.to_bits();
    let biased = ((bits >> 23) & 0xff) as i32;
    if biased > 0 {
        return biased - 127;
    }
    // Subnormal: the position of the leading bit of the mantissa.
    -118 - (bits.leading_zeros() as i32)
}

/// `x·2ᵉ`, rounded once (const): in steps that stay in the normal range.
const fn times_power_of_two(x: f32, e: i32) -> f32 {
    let mut x = x;
    let mut e = e;
    while e > 127 {
        x *= f32::from_bits(254 << 23);
        e -= 127;
    }
    while e < -126 {
        // 2⁻¹²⁶ at a time, with the last step exact where the result is normal.
        x *= f32::from_bits(1 << 23);
        e += 126;
    }
    x * f32::from_bits(((e + 127) as u32) << 23)
}

/// The largest ratio of two sensors' noise scales in one layout (2²⁰).
pub const MAX_NOISE_SCALE_RATIO: f32 = 1_048_576.0;

/// `(2l + 1)/(4π)`.
const fn degree_weight(l: usize) -> f32 {
    (2 * l + 1) as f32 / FOUR_PI
}

/// The Legendre recurrence's factors for the degrees below [`DEGREES`].
const RECURRENCE: [(f32, f32); DEGREES] = legendre::factor_table(DEGREES);

/// Two responses are the same (their parameters bit for bit).
const fn same_response(a: &Response, b: &Response) -> bool {
    match (a, b) {
        (Response::CosinePower(x), Response::CosinePower(y))
        | (Response::Gaussian(x), Response::Gaussian(y)) => x.to_bits() == y.to_bits(),
        (Response::Gains(x), Response::Gains(y)) => {
            let mut l = 0;
            while l < DEGREES {
                if x[l].to_bits() != y[l].to_bits() {
                    return false;
                }
                l += 1;
            }
            true
        }
        _ => false,
    }
}

/// `|x|` (const).
const fn absolute(x: f32) -> f32 {
    if x < 0.0 {
        -x
    } else {
        x
    }
}

/// A response's isotropic `Cov(Y, E(n))` at unit scale from its table, for a sensor whose
/// direction scaled by `(NODES − 1)/2` is `scaled`: the quadratic through the three nodes
/// nearest `t = d·n`. (The saturating cast and the clamp keep every index in range.)
#[inline(always)]
fn lookup(table: &[f32; NODES], scaled: Vec3, n: Vec3) -> f32 {
    let x = 0.5 * (NODES - 1) as f32 + scaled.dot(n);
    let k = ((x + 0.5) as usize).clamp(1, NODES - 2);
    let u = x - k as f32;
    let (a, b, c) = (table[k - 1], table[k], table[k + 1]);
    b + u * (0.5 * (c - a) + u * (0.5 * (a + c) - b))
}

/// `v/|v|`, or `None` for a zero or non-finite vector (const).
const fn normalized(v: Vec3) -> Option<Vec3> {
    if !(v.x.is_finite() && v.y.is_finite() && v.z.is_finite()) {
        return None;
    }
    let (ax, ay, az) = (absolute(v.x), absolute(v.y), absolute(v.z));
    let m = if ax > ay { ax } else { ay };
    let m = if m > az { m } else { az };
    if m == 0.0 {
        return None;
    }
    let (x, y, z) = (v.x / m, v.y / m, v.z / m);
    let length = math::sqrt_newton(x * x + y * y + z * z);
    Some(Vec3::new(x / length, y / length, z / length))
}

/// An RGB layout probe: [`LayoutProbe`] with `[f32; 3]` readings.
///
/// ```
/// use sphere_quadrature::layout::{Noise, Prior, RgbLayoutProbe, Sensor};
/// use sphere_quadrature::Vec3;
///
/// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z].map(Sensor::cosine);
/// let probe = RgbLayoutProbe::<6>::new(&faces, Prior::ENVIRONMENT, Noise::NONE)?;
/// assert_eq!(probe.directions().len(), 6);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
pub type RgbLayoutProbe<const K: usize> = LayoutProbe<K, [f32; 3]>;

/// A probe over `K` sensors of a user's layout, `f32` or RGB `[f32; 3]` readings (module
/// docs).
///
/// ```
/// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
/// use sphere_quadrature::Vec3;
///
/// // Too many different responses, a zero direction: errors, not panics.
/// let bad = [Sensor::cosine(Vec3::ZERO), Sensor::cosine(Vec3::Z)];
/// let prior = Prior::squared_exponential(2.0)?;
/// assert!(LayoutProbe::<2>::new(&bad, prior, Noise::NONE).is_err());
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct LayoutProbe<const K: usize, T: Radiance = f32> {
    directions: [Vec3; K],
    /// `1/wᵢ`.
    whitening: [f32; K],
    /// Index of each sensor's response table.
    class: [u8; K],
    /// The number of distinct responses.
    classes: usize,
    /// The directions times `(NODES − 1)/2` (exact: a power of two), for table lookups.
    scaled: [Vec3; K],
    /// The distinct responses' gains.
    gains: [[f32; DEGREES]; MAX_RESPONSES],
    /// The prior's spectrum.
    spectrum: [f32; DEGREES],
    /// The prior's zonal covariances `R` (zero diagonal).
    zonal_r: [[f32; 3]; 3],
    /// Whether `R` is zero.
    isotropic: bool,
    /// Each sensor's `uᵢ = (g_l·Y_l0(dᵢ))`, `l ≤ 2`.
    zonal_u: [[f32; 3]; K],
    /// The mean's zonal profile (zero for a zero mean).
    profile: [f32; 9],
    /// Unit-scale `Cov(Yᵢ, E(n))` against `t = dᵢ·n` per distinct response.
    tables: [[f32; NODES]; MAX_RESPONSES],
    /// The whitened covariance `C̃ = WCW` (unit scale), its floored eigenvalues raised to the
    /// floor: the matrix of [`Self::vectors`] and [`Self::values`].
    covariance: [[f32; K]; K],
    /// Eigenvectors (columns) of the whitened covariance.
    vectors: [[f32; K]; K],
    /// Its eigenvalues.
    values: [f32; K],
    /// The mean basis at the sensors, whitened, in the eigenbasis: `H̃ = VᵀWH`.
    basis: [[f32; K]; 2],
    /// The same in sensor space, `WH` (`V·H̃`).
    basis_sensor: [f32; K],
    /// `Πᵢ 1/wᵢ`, for the likelihood.
    log_whitening: LogProduct,
    /// The mean basis's irradiance factors per Legendre degree about `+z` (`a_l·c_l`).
    basis_query: [[f32; 9]; 2],
    /// Number of mean basis functions (0, 1).
    mean_terms: usize,
    /// The prior's factor on every reported variance.
    variance_scale: f32,
    /// `V̄`: the prior variance of the irradiance (unit scale).
    prior_variance: f32,
    /// Direction averages, eigenbasis: `M̃ = VᵀW·avg[z zᵀ]·WV`.
    average_zz: [[f32; K]; K],
    /// `avg[h_a(n)·z̃_j(n)]`.
    average_hz: [[f32; K]; 2],
    /// `avg[h_a h_b]`.
    average_hh: [[f32; 2]; 2],
    noise: Noise,
    /// The whitened absolute noise `σ·2ᵏ` (the whitening is `2ᵏ/wᵢ`).
    absolute: f32,
    /// The spectrum is the prior's times `2^−spectrum_exponent`.
    spectrum_exponent: i32,
    /// The number of eigenvalues above the floor: the readings' degrees of freedom without
    /// noise (duplicate sensors add none).
    rank: usize,
    // Per update.
    /// Weights of the query covariances, per channel, in working units.
    alpha: [T; K],
    /// GLS coefficients of the mean, in working units.
    beta: [T; 2],
    /// The working unit per channel (a power of two near the largest whitened reading).
    unit: T,
    /// `s` per channel, in working units.
    scale: T,
    /// `ν` per channel, in working units.
    nugget: T,
    /// Direction-averaged posterior variance per channel (reading units).
    average_variance: T,
    /// Direction-averaged posterior variance per channel for `s = 1`.
    average_unit_variance: T,
    updated: bool,
    /// The stream's pooled mean readings, channel `c` in units of `2^stream_exponent[c]`.
    stream_mean: [T; K],
    /// The power of two of each channel's pooled means: a power of two near the largest
    /// mean or reading, so that pooling is exact under powers of two, below the normal range too.
    stream_exponent: [i32; MAX_CHANNELS],
    /// Their weight (effective updates).
    stream_weight: f32,
    /// The prior probability of a change per stream update.
    hazard: f32,
    /// The REML log likelihood of the last fit, summed over channels.
    log_likelihood: f32,
    /// The posterior probability of a change at the last stream update.
    last_change: f32,
}

fn unit(v: Vec3) -> Result<Vec3, Error> {
    if !v.is_finite() {
        return Err(Error::InvalidDirection);
    }
    v.try_normalize().ok_or(Error::InvalidDirection)
}
