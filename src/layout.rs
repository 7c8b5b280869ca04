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
//! # Cost
//! [`LayoutProbe::new`] builds everything at run time, with no allocation: the `K × K`
//! covariance (Legendre series), its eigendecomposition after whitening by `wᵢ` (Householder
//! reflections, implicit QL and one polishing Jacobi sweep, O(K³)), and a 129-node table of the query covariance per distinct response.
//! Because the whitened covariance is `s·Λ + ν·I` in the eigenbasis for every `s` and noise
//! level `ν`, each update projects the readings (`K²` multiply-adds per channel), chooses
//! `s` by restricted maximum likelihood in O(K) per trial, and forms the weights (`K²`).
//! With a relative noise the sensors' noise levels differ: the scale is chosen with their
//! mean `ν̄`, and the mean and the weights come from the exact system `s·C̃ + diag(νᵢ)`,
//! factored once per channel (`K³/6`); the variances take the noise at its mean level.
//! An irradiance query is `K` table lookups; its error bar is the exact direction average
//! of the posterior variance, computed once per update; [`LayoutProbe::irradiance_variance`]
//! is the exact variance at one normal, O(K²).
//!
//! Channels are fitted one by one, each with its own scale. Their errors are correlated, so
//! the variance of a combination of channels (luminance from RGB) is not a sum of the
//! channels' variances: [`LayoutProbe::combined`] fits the combined readings as one channel.
//!
//! # Accuracy
//! - **Against an f64 reference** (the unit tests: textbook Gaussian-process formulas in
//!   f64): values within 5·10⁻⁶ relative, exact variances within 2·10⁻⁴, the log likelihood
//!   within 10⁻⁶; with a relative noise the weights solve an f32 system of condition about
//!   10⁴, and values agree within 2·10⁻⁴.
//! - **On real maps** (the repository's `sensors` benchmark: held-out environment maps, exact
//!   readings of every pixel, the learned priors), the irradiance error over the best of the
//!   nearest sensor, the cosine-weighted average and the degree-1 and degree-2 SH fits on the
//!   same readings, mean over maps: 0.57–1.00 for sensors all round (16 on a spherical
//!   Fibonacci set: 0.70 on sharp light, 0.57 on smooth light, without noise; a cube ties the
//!   degree-2 fit), 0.92–1.03 for upward layouts (a dome of 5, a ring of 6 and a zenith
//!   sensor). 2σ intervals hold for 93–99 % of the queries all round; for upward layouts
//!   they are wide without noise (100 %) and hold for 91–98 % at 5 % noise.
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
//!
//! # Cortex-M4
//! Instructions per call on a Cortex-M4F (QEMU `mps2-an386`, `-icount shift=0`, `libm`
//! backend; `examples/cortex-m4`, whose output CI checks these lines against), one channel
//! (`LayoutProbe<K, f32>`), cosine photodiodes on the faces of a cube (`K = 6`) and on the
//! directions of `Probe::<16, f32, CosinePower<1>>` (`K = 16`), [`Prior::ENVIRONMENT`], a
//! relative noise of 1 % and readings of a real environment map:
//! - `m4:layout_init K=6`: 77 800 instructions ([`LayoutProbe::new`])
//! - `m4:layout_init K=16`: 369 680 instructions
//! - `m4:layout_update K=6`: 3 950 instructions ([`LayoutProbe::update`])
//! - `m4:layout_update K=16`: 19 120 instructions
//! - `m4:layout_update_rgb K=6`: 12 500 instructions (`LayoutProbe<6, [f32; 3]>`)
//! - `m4:layout_update_rgb K=16`: 63 420 instructions (`LayoutProbe<16, [f32; 3]>`)
//! - `m4:layout_update_absolute K=6`: 2 960 instructions (an absolute noise of 1 % of the
//!   mean reading instead: no per-reading solve)
//! - `m4:layout_update_absolute K=16`: 6 720 instructions
//! - `m4:layout_irradiance K=6`: 358 instructions ([`LayoutProbe::irradiance`])
//! - `m4:layout_irradiance K=16`: 795 instructions
//! - `m4:layout_irradiance_variance K=6`: 624 instructions
//!   ([`LayoutProbe::irradiance_variance`])
//! - `m4:layout_irradiance_variance K=16`: 1 926 instructions
//!
//! Flash (release, LTO) that one call adds, the first on top of an empty program and the
//! others on top of [`LayoutProbe::new`] (`K = 6`, one channel):
//! - `flash:layout_new K=6`: 34 568 bytes of code and 320 bytes of tables
//! - `flash:layout_update K=6`: 11 760 bytes of code and 276 bytes of tables
//! - `flash:layout_irradiance K=6`: 4 104 bytes of code and 256 bytes of tables
//! - `flash:layout_irradiance_variance K=6`: 3 528 bytes of code and 256 bytes of tables
//!
//! RAM of the probe (`core::mem::size_of`), which [`LayoutProbe::new`] returns by value:
//! - `ram:layout_f32 K=6`: 3 824 bytes (`LayoutProbe<6, f32>`)
//! - `ram:layout_rgb K=6`: 3 960 bytes (`LayoutProbe<6, [f32; 3]>`)
//! - `ram:layout_f32 K=16`: 7 196 bytes (`LayoutProbe<16, f32>`)
//! - `ram:layout_rgb K=16`: 7 492 bytes (`LayoutProbe<16, [f32; 3]>`)

// Matrix code reads clearer with its indices.
#![allow(clippy::needless_range_loop)]

mod learned;

use crate::error::Error;
use crate::math;
use crate::probe::Estimate;
use crate::radiance::{from_channels, Radiance};
use crate::sg::SphericalGaussian;
use crate::sh::ShL2;
use crate::temporal::{gaussian_log_bf, log_odds, logistic, Change, DEFAULT_HAZARD};
use crate::vec3::Vec3;

/// The most sensors a layout may have.
pub const MAX_SENSORS: usize = 64;
/// Legendre degrees `0..DEGREES` of the spectra, gains and series.
pub const DEGREES: usize = 33;
/// The most distinct responses in one layout (each has its query table).
pub const MAX_RESPONSES: usize = 4;
/// Nodes of the query-covariance tables over `t = dᵢ·n ∈ [−1, 1]`.
const NODES: usize = 129;
/// The most channels a reading may have.
const MAX_CHANNELS: usize = 4;
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
    /// rounded once. [`Error::InvalidParameter`] for a parameter out of range or gains that
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
        let mut g = [0.0f64; DEGREES];
        match *self {
            Response::CosinePower(p) => {
                if !(p.is_finite() && p >= 0.0 && p <= 4096.0) {
                    return Err(Error::InvalidParameter);
                }
                // I_l = ∫₀¹ tᴾ P_l(t) dt: (P + l + 1)·I_l = (P − l + 2)·I_{l−2}.
                let p = p as f64;
                let mut integral = [0.0f64; DEGREES];
                integral[0] = 1.0 / (p + 1.0);
                integral[1] = 1.0 / (p + 2.0);
                let mut l = 2;
                while l < DEGREES {
                    let lf = l as f64;
                    integral[l] = (p - lf + 2.0) / (p + lf + 1.0) * integral[l - 2];
                    l += 1;
                }
                let mut l = 0;
                while l < DEGREES {
                    g[l] = (p + 1.0) * integral[l];
                    l += 1;
                }
            }
            Response::Gaussian(s) => {
                if !(s.is_finite() && s > 0.0 && s <= 4096.0) {
                    return Err(Error::InvalidParameter);
                }
                // g_l = i_l(S)/i₀(S): ratios r_l = i_l/i_{l−1} by the backward recurrence
                // r_l = 1/((2l + 1)/S + r_{l+1}), started far enough above DEGREES.
                let s = s as f64;
                let mut l = DEGREES + 40 + (2.0 * s) as usize;
                let mut r = 0.0f64;
                let mut ratios = [0.0f64; DEGREES];
                while l >= 1 {
                    r = 1.0 / ((2 * l + 1) as f64 / s + r);
                    if l < DEGREES {
                        ratios[l] = r;
                    }
                    l -= 1;
                }
                g[0] = 1.0;
                let mut l = 1;
                while l < DEGREES {
                    g[l] = g[l - 1] * ratios[l];
                    l += 1;
                }
            }
            Response::Gains(values) => {
                if absolute(values[0] - 1.0) > 1e-6 {
                    return Err(Error::InvalidParameter);
                }
                let mut l = 0;
                while l < DEGREES {
                    if !values[l].is_finite() || absolute(values[l]) > 1.0 + 1e-6 {
                        return Err(Error::InvalidParameter);
                    }
                    l += 1;
                }
                return Ok(values);
            }
        }
        let mut out = [0.0f32; DEGREES];
        let mut l = 0;
        while l < DEGREES {
            out[l] = g[l] as f32;
            l += 1;
        }
        Ok(out)
    }

    /// Gains from a measured response: `values[k]` at angle `angles_deg[k]` from the axis
    /// (increasing, from 0 to at most 180°; zero beyond the last angle, linear between),
    /// normalised so that `g₀ = 1`. [`Error::InvalidParameter`] for non-finite, negative or
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
            return Err(Error::InvalidParameter);
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
            return Err(Error::InvalidParameter);
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
    /// sensors; 2 for one twice as noisy).
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

/// The read noise of a layout: sensor `i` has variance `wᵢ²·σ² + η²·Yᵢ²` for its reading
/// `Yᵢ` (per channel) and noise scale `wᵢ`.
///
/// ```
/// use sphere_quadrature::layout::Noise;
///
/// let n = Noise { absolute: 0.01, relative: 0.05 };
/// assert_eq!(Noise::NONE.absolute, 0.0);
/// assert!(n.relative > 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Noise {
    /// `σ`, in the readings' units.
    pub absolute: f32,
    /// `η`, a fraction of the reading.
    pub relative: f32,
}

impl Noise {
    /// Exact readings.
    pub const NONE: Noise = Noise { absolute: 0.0, relative: 0.0 };
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
    /// Light in general, for layouts in any orientation: a zero mean and the mean angular
    /// power spectrum of the luminance (over its mean) of four real environment maps, indoor
    /// and outdoor, with pixels above 30 times the mean clamped (sun disks); computed in f64
    /// from the maps and rounded once to f32.
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
    /// Layouts that look up (a dome, a ceiling fixture) with `+z` up. A zero mean; degrees
    /// ≤ 2 flat (`K₀ = K₁ = K₂ = 1`, as the minimum-norm SH fit assumes) with zonal
    /// correlations from the same maps (about 0.50, 0.51 and 0.33: the level, the vertical
    /// gradient and the zonal degree 2 vary together), and above degree 2 their spectrum
    /// over the mean power per coefficient of degrees ≤ 2. Measured on held-out maps, this
    /// prior is within a few percent of the best of the standard estimators for upward
    /// layouts, a little better on most maps: what the sensors cannot see (how dark the
    /// ground is) differs from map to map more than four training maps can tell.
    pub const SKY_ABOVE: Prior = Prior {
        spectrum: learned::ENVIRONMENT_SKY_SPECTRUM,
        zonal: learned::ENVIRONMENT_SKY_ZONAL,
        mean: Mean::Zero,
        variance_scale: learned::ENVIRONMENT_SKY_CALIBRATION,
    };
    /// As [`Prior::SKY_ABOVE`] for light without sharp features.
    pub const SMOOTH_SKY_ABOVE: Prior = Prior {
        spectrum: learned::SMOOTH_SKY_SPECTRUM,
        zonal: learned::SMOOTH_SKY_ZONAL,
        mean: Mean::Zero,
        variance_scale: learned::SMOOTH_SKY_CALIBRATION,
    };

    /// The squared-exponential kernel `exp(λ(x·x′ − 1))`, `0 < λ ≤ 64`, with a constant
    /// mean: `K_l = 4π·e^{−λ}·i_l(λ)`, computed in f64.
    pub fn squared_exponential(lambda: f32) -> Result<Prior, Error> {
        if !(lambda.is_finite() && lambda > 0.0 && lambda <= 64.0) {
            return Err(Error::InvalidParameter);
        }
        let g = Response::Gaussian(lambda).gains()?;
        let x = f64::from(lambda);
        // e^{−λ} i₀(λ) = (1 − e^{−2λ})/(2λ).
        let k0 = 4.0 * core::f64::consts::PI * (1.0 - math::exp64(-2.0 * x)) / (2.0 * x);
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

/// Gains of the clamped cosine `max(0, t)`: `c_l = π·g_l(CosinePower(1))`.
const fn cosine_factors() -> [f32; DEGREES] {
    let mut c = [0.0f32; DEGREES];
    if let Ok(g) = Response::CosinePower(1.0).gains() {
        let mut l = 0;
        while l < DEGREES {
            c[l] = g[l] * core::f32::consts::PI;
            l += 1;
        }
    }
    c
}

/// `t` clamped to `[−1, 1]` (const).
const fn clamp_unit(t: f32) -> f32 {
    if t > 1.0 {
        1.0
    } else if t < -1.0 {
        -1.0
    } else {
        t
    }
}

/// `Σ_l coef_l·P_l(t)`, `l < D ≤ DEGREES`, by the three-term recurrence (f32).
const fn legendre_sum<const D: usize>(coef: &[f32; D], t: f32) -> f32 {
    let t = clamp_unit(t);
    let (mut p0, mut p1) = (1.0f32, t);
    let mut s = coef[0] + coef[1] * t;
    let mut l = 2;
    while l < D {
        let p2 = RECURRENCE[l].0 * t * p1 - RECURRENCE[l].1 * p0;
        s += coef[l] * p2;
        p0 = p1;
        p1 = p2;
        l += 1;
    }
    s
}

/// Two series at the same `t` from one recurrence: `(Σ a_l·P_l(t), Σ b_l·P_l(t))`.
const fn legendre_sums(a: &[f32; DEGREES], b: &[f32; DEGREES], t: f32) -> (f32, f32) {
    let t = clamp_unit(t);
    let (mut p0, mut p1) = (1.0f32, t);
    let mut sa = a[0] + a[1] * t;
    let mut sb = b[0] + b[1] * t;
    let mut l = 2;
    while l < DEGREES {
        let p2 = RECURRENCE[l].0 * t * p1 - RECURRENCE[l].1 * p0;
        sa += a[l] * p2;
        sb += b[l] * p2;
        p0 = p1;
        p1 = p2;
        l += 1;
    }
    (sa, sb)
}

/// The even- and odd-degree parts of `Σ_l coef_l·P_l(t)`, `t ∈ [0, 1]`: the series is
/// their sum at `t` and their difference at `−t` (`P_l(−t) = (−1)ˡ·P_l(t)`).
const fn legendre_parts(coef: &[f32; DEGREES], t: f32) -> (f32, f32) {
    let t = clamp_unit(t);
    let (mut p0, mut p1) = (1.0f32, t);
    let (mut even, mut odd) = (coef[0], coef[1] * t);
    let mut l = 2;
    while l < DEGREES {
        let p2 = RECURRENCE[l].0 * t * p1 - RECURRENCE[l].1 * p0;
        if l % 2 == 0 {
            even += coef[l] * p2;
        } else {
            odd += coef[l] * p2;
        }
        p0 = p1;
        p1 = p2;
        l += 1;
    }
    (even, odd)
}

/// The clamped cosine's factors, evaluated once.
const COSINE_FACTORS: [f32; DEGREES] = cosine_factors();

fn cosine_factors_lookup() -> [f32; DEGREES] {
    COSINE_FACTORS
}

/// `Y_l0(z)` for `l = 0, 1, 2` (real orthonormal harmonics about `+z`).
const fn zonal_harmonics(z: f32) -> [f32; 3] {
    [0.282_094_8, 0.488_602_5 * z, 0.315_391_57 * (3.0 * z * z - 1.0)]
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

/// `(2l + 1)/(4π)`.
const fn degree_weight(l: usize) -> f32 {
    (2 * l + 1) as f32 / FOUR_PI
}

/// The Legendre recurrence's factors `((2l − 1)/l, (l − 1)/l)`.
const RECURRENCE: [(f32, f32); DEGREES] = {
    let mut r = [(0.0f32, 0.0f32); DEGREES];
    let mut l = 1;
    while l < DEGREES {
        r[l] = ((2 * l - 1) as f32 / l as f32, (l - 1) as f32 / l as f32);
        l += 1;
    }
    r
};

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

/// The square root of a positive, finite `v`: Newton's iteration in f32 from the halved
/// exponent (const; the same bits at compile time and at run time, and cheap on a core
/// without f64). 0 otherwise.
const fn square_root(v: f32) -> f32 {
    if !(v > 0.0 && v.is_finite()) {
        return 0.0;
    }
    // Subnormals: scale up by 2^24 first (the root by 2^12).
    let (v, back) = if v < 1e-30 { (v * 16_777_216.0, 1.0 / 4096.0) } else { (v, 1.0) };
    let mut r = f32::from_bits((v.to_bits() >> 1) + 0x1fbd_1df5);
    let mut k = 0;
    while k < 4 {
        r = 0.5 * (r + v / r);
        k += 1;
    }
    r * back
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
    let length = square_root(x * x + y * y + z * z);
    Some(Vec3::new(x / length, y / length, z / length))
}

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
    /// The whitened covariance `C̃ = WCW` (unit scale).
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
    // Per update.
    /// Weights of the query covariances, per channel.
    alpha: [T; K],
    /// GLS coefficients of the mean.
    beta: [T; 2],
    /// `s` per channel.
    scale: T,
    /// `ν` per channel.
    nugget: T,
    /// Direction-averaged posterior variance per channel.
    average_variance: T,
    updated: bool,
    /// The stream's pooled mean readings.
    stream_mean: [T; K],
    /// Their weight (effective updates).
    stream_weight: f32,
    /// The prior probability of a change per stream update.
    hazard: f32,
    /// The REML log likelihood of the last fit, summed over channels.
    log_likelihood: f32,
    /// The posterior probability of a change at the last stream update.
    last_change: f32,
}

impl<const K: usize, T: Radiance> LayoutProbe<K, T> {
    /// Builds the probe's tables for these sensors, prior and noise: O(K³), no allocation.
    ///
    /// Errors:
    /// - [`Error::InvalidSize`]: `K = 0`, `K > MAX_SENSORS`, or `K` not above the number of
    ///   mean terms (a constant or zonal mean needs two sensors);
    /// - [`Error::InvalidDirection`]: a zero or non-finite direction;
    /// - [`Error::InvalidParameter`]: a response, noise scale (must be finite and positive),
    ///   noise (finite, non-negative), spectrum (finite, non-negative) or profile out of
    ///   range, or more than [`MAX_RESPONSES`] distinct responses.
    ///
    /// Readings that the prior makes linearly dependent are fine: two sensors with the same
    /// direction and response, or the antipodal pairs of cosine sensors (their differences
    /// see degree 1 only). The model's least noise, `10⁻⁶` of the largest eigenvalue of the
    /// whitened covariance, keeps the system solvable, and duplicates are averaged.
    pub const fn new(sensors: &[Sensor; K], prior: Prior, noise: Noise) -> Result<Self, Error> {
        let mean_terms = match prior.mean {
            Mean::Zero => 0,
            _ => 1,
        };
        if T::CHANNELS > MAX_CHANNELS {
            return Err(Error::InvalidParameter);
        }
        if K == 0 || K > MAX_SENSORS || K <= mean_terms {
            return Err(Error::InvalidSize);
        }
        if !non_negative(noise.absolute) || !non_negative(noise.relative) {
            return Err(Error::InvalidParameter);
        }
        let spectrum = prior.spectrum;
        let mut any = false;
        let mut l = 0;
        while l < DEGREES {
            if !non_negative(spectrum[l]) {
                return Err(Error::InvalidParameter);
            }
            any |= spectrum[l] > 0.0;
            l += 1;
        }
        if !any {
            return Err(Error::InvalidParameter);
        }
        let variance_scale = prior.variance_scale;
        if !(variance_scale.is_finite() && variance_scale > 0.0) {
            return Err(Error::InvalidParameter);
        }
        // The zonal covariances R (zero diagonal); with K₀, K₁, K₂ a PSD 3×3 matrix.
        let [z01, z12, z02] = prior.zonal;
        if !(z01.is_finite() && z12.is_finite() && z02.is_finite()) {
            return Err(Error::InvalidParameter);
        }
        let zonal_r = [[0.0, z01, z02], [z01, 0.0, z12], [z02, z12, 0.0]];
        let (k0, k1, k2) = (spectrum[0] as f64, spectrum[1] as f64, spectrum[2] as f64);
        let (z01, z12, z02) = (z01 as f64, z12 as f64, z02 as f64);
        let minor = k0 * k1 - z01 * z01;
        let det = k0 * (k1 * k2 - z12 * z12) - z01 * (z01 * k2 - z12 * z02)
            + z02 * (z01 * z12 - k1 * z02);
        let tolerance = 1e-6 * (k0 * k1 * k2 + k0 * k1 + 1e-30);
        if minor < -1e-6 * (k0 * k1 + 1e-30) || det < -tolerance || k0 * k2 - z02 * z02 < 0.0 {
            return Err(Error::InvalidParameter);
        }
        let mut profile = [0.0f32; 9];
        match prior.mean {
            Mean::Zero => {}
            Mean::Constant => profile[0] = 1.0,
            Mean::Zonal(p) => {
                let mut any = false;
                let mut l = 0;
                while l < 9 {
                    if !p[l].is_finite() {
                        return Err(Error::InvalidParameter);
                    }
                    any |= p[l] != 0.0;
                    l += 1;
                }
                if !any {
                    return Err(Error::InvalidParameter);
                }
                profile = p;
            }
        }
        let mut directions = [Vec3::ZERO; K];
        let mut whitening = [0.0f32; K];
        let mut class = [0u8; K];
        let mut distinct = [[0.0f32; DEGREES]; MAX_RESPONSES];
        let mut responses = [Response::CosinePower(1.0); MAX_RESPONSES];
        let mut classes = 0usize;
        let mut i = 0;
        while i < K {
            let sensor = &sensors[i];
            directions[i] = match normalized(sensor.direction) {
                Some(d) => d,
                None => return Err(Error::InvalidDirection),
            };
            let w = sensor.noise_scale;
            if !(w.is_finite() && w > 0.0) {
                return Err(Error::InvalidParameter);
            }
            whitening[i] = 1.0 / w;
            // A response seen before shares its class (and its gains, computed once).
            let mut found = classes;
            let mut c = 0;
            while c < classes && c < MAX_RESPONSES {
                if same_response(&responses[c], &sensor.response) {
                    found = c;
                    break;
                }
                c += 1;
            }
            if found == classes {
                if classes >= MAX_RESPONSES {
                    return Err(Error::InvalidParameter);
                }
                distinct[classes] = match sensor.response.gains() {
                    Ok(g) => g,
                    Err(e) => return Err(e),
                };
                responses[classes] = sensor.response;
                classes += 1;
            }
            class[i] = (found % MAX_RESPONSES) as u8;
            i += 1;
        }
        let mut scaled = [Vec3::ZERO; K];
        let mut i = 0;
        while i < K {
            let d = directions[i];
            let f = 0.5 * (NODES - 1) as f32;
            scaled[i] = Vec3::new(f * d.x, f * d.y, f * d.z);
            i += 1;
        }
        let c = COSINE_FACTORS;
        // Each sensor's zonal harmonics seen through its response, uᵢ = (g_l·Y_l0(dᵢ)), and
        // R·uᵢ.
        let mut zonal_u = [[0.0f32; 3]; K];
        let mut ru = [[0.0f32; 3]; K];
        let mut i = 0;
        while i < K {
            let y = zonal_harmonics(directions[i].z);
            let g = &distinct[class[i] as usize % MAX_RESPONSES];
            let mut l = 0;
            while l < 3 {
                zonal_u[i][l] = g[l] * y[l];
                l += 1;
            }
            ru[i] = times_r(&zonal_r, &zonal_u[i]);
            i += 1;
        }
        // Per class, the series of the sensor–query covariance (with (2l + 1)/(4π)), and
        // its table.
        let mut tables = [[0.0f32; NODES]; MAX_RESPONSES];
        let mut q = 0;
        while q < classes && q < MAX_RESPONSES {
            let mut coef = [0.0f32; DEGREES];
            let mut l = 0;
            while l < DEGREES {
                coef[l] = spectrum[l] * distinct[q][l] * c[l] * degree_weight(l);
                l += 1;
            }
            // Nodes k and NODES − 1 − k sit at ±t: one recurrence gives both.
            let mut k = NODES / 2;
            while k < NODES {
                let x = -1.0 + 2.0 * k as f32 / (NODES - 1) as f32;
                let (even, odd) = legendre_parts(&coef, x);
                tables[q][k] = even + odd;
                tables[q][NODES - 1 - k] = even - odd;
                k += 1;
            }
            q += 1;
        }
        // The Legendre series of the sensor covariance and of the average of z zᵀ per pair of
        // responses.
        let mut pair_cov = [[[0.0f32; DEGREES]; MAX_RESPONSES]; MAX_RESPONSES];
        let mut pair_zz = [[[0.0f32; DEGREES]; MAX_RESPONSES]; MAX_RESPONSES];
        let mut ci = 0;
        while ci < classes && ci < MAX_RESPONSES {
            let mut cj = 0;
            while cj < classes && cj < MAX_RESPONSES {
                let (gi, gj) = (&distinct[ci], &distinct[cj]);
                let mut l = 0;
                while l < DEGREES {
                    let k = spectrum[l] * gi[l] * gj[l] * degree_weight(l);
                    pair_cov[ci][cj][l] = k;
                    pair_zz[ci][cj][l] = k * spectrum[l] * c[l] * c[l] / FOUR_PI;
                    l += 1;
                }
                cj += 1;
            }
            ci += 1;
        }
        // The whitened covariance and the direction average of z zᵀ.
        let mut cov = [[0.0f32; K]; K];
        let mut zz = [[0.0f32; K]; K];
        let mut i = 0;
        while i < K {
            let mut j = 0;
            while j <= i {
                let (ci, cj) =
                    (class[i] as usize % MAX_RESPONSES, class[j] as usize % MAX_RESPONSES);
                let (gi, gj) = (&distinct[ci], &distinct[cj]);
                let (a, b) = (&pair_cov[ci][cj], &pair_zz[ci][cj]);
                let (di, dj) = (directions[i], directions[j]);
                let t = di.x * dj.x + di.y * dj.y + di.z * dj.z;
                let w = whitening[i] * whitening[j];
                // The zonal part: uᵢᵀRuⱼ; and in the average of z zᵀ the cross terms with
                // the isotropic part, (1/4π)·Σ_l (Ruⱼ)_l c_l K_l gᵢ_l c_l Y_l0(dᵢ) (and i ↔ j),
                // and (1/4π)·Σ_l (Ruᵢ)_l (Ruⱼ)_l c_l².
                let (yi, yj) = (zonal_harmonics(di.z), zonal_harmonics(dj.z));
                let mut zonal = 0.0f32;
                let mut zonal_zz = 0.0f32;
                let mut l = 0;
                while l < 3 {
                    zonal += zonal_u[i][l] * ru[j][l];
                    let ai = spectrum[l] * gi[l] * c[l];
                    let aj = spectrum[l] * gj[l] * c[l];
                    zonal_zz += (ru[j][l] * c[l] * ai * yi[l]
                        + ru[i][l] * c[l] * aj * yj[l]
                        + ru[i][l] * ru[j][l] * c[l] * c[l])
                        / FOUR_PI;
                    l += 1;
                }
                let (sa, sb) = legendre_sums(a, b, t);
                cov[i][j] = w * (sa + zonal);
                cov[j][i] = cov[i][j];
                zz[i][j] = w * (sb + zonal_zz);
                zz[j][i] = zz[i][j];
                j += 1;
            }
            i += 1;
        }
        let covariance = cov;
        let (mut values, vectors) = symmetric_eigen(cov);
        let mut top = 0.0f32;
        let mut j = 0;
        while j < K {
            if values[j] > top {
                top = values[j];
            }
            j += 1;
        }
        if !(top > 0.0 && top.is_finite()) {
            return Err(Error::InvalidParameter);
        }
        // The model's least noise: eigenvalues floored at 10⁻⁶ of the largest, so that
        // dependent readings (duplicate sensors; antipodal cosine pairs, whose differences
        // see degree 1 only) keep the system solvable.
        let mut j = 0;
        while j < K {
            // (A NaN eigenvalue, impossible from finite input, is floored too.)
            if values[j].is_nan() || values[j] <= FLOOR * top {
                values[j] = FLOOR * top;
            }
            j += 1;
        }
        // M̃ = Vᵀ·zz·V.
        let average_zz = congruence(&vectors, &zz);
        // Mean basis: sensor values h_i = Σ a_l g_l P_l(d_i·z), whitened and projected.
        let mut basis = [[0.0f32; K]; 2];
        let mut basis_sensor = [0.0f32; K];
        let mut basis_query = [[0.0f32; 9]; 2];
        let mut average_hz = [[0.0f32; K]; 2];
        let mut average_hh = [[0.0f32; 2]; 2];
        if mean_terms == 1 {
            let mut h = [0.0f32; K];
            let mut hz = [0.0f32; K];
            let mut i = 0;
            while i < K {
                let g = &distinct[class[i] as usize % MAX_RESPONSES];
                let mut a = [0.0f32; 9];
                let mut b = [0.0f32; 9];
                let mut l = 0;
                while l < 9 {
                    a[l] = profile[l] * g[l];
                    // avg[h(n)·z_i(n)] = (1/4π)·Σ_l Q_l·K_l g_l c_l·P_l(d_i·z), Q_l = a_l c_l.
                    b[l] = profile[l] * c[l] * spectrum[l] * g[l] * c[l] / FOUR_PI;
                    l += 1;
                }
                h[i] = whitening[i] * legendre_sum(&a, directions[i].z);
                // The zonal part: (1/4π)·Σ_l (Ruᵢ)_l c_l Q_l √(4π/(2l + 1)), Q_l = a_l c_l.
                let mut zonal = 0.0f32;
                let mut l = 0;
                while l < 3 {
                    let norm = square_root(FOUR_PI / (2 * l + 1) as f32);
                    zonal += ru[i][l] * c[l] * profile[l] * c[l] * norm / FOUR_PI;
                    l += 1;
                }
                hz[i] = whitening[i] * (legendre_sum(&b, directions[i].z) + zonal);
                i += 1;
            }
            basis[0] = project(&vectors, &h);
            basis_sensor = h;
            average_hz[0] = project(&vectors, &hz);
            let mut l = 0;
            while l < 9 {
                basis_query[0][l] = profile[l] * c[l];
                average_hh[0][0] += basis_query[0][l] * basis_query[0][l] / (2 * l + 1) as f32;
                l += 1;
            }
        }
        let mut prior_variance = 0.0f32;
        let mut l = 0;
        while l < DEGREES {
            prior_variance += spectrum[l] * c[l] * c[l] * degree_weight(l);
            l += 1;
        }
        Ok(LayoutProbe {
            directions,
            whitening,
            class,
            classes,
            scaled,
            gains: distinct,
            spectrum,
            zonal_r,
            isotropic: z01 == 0.0 && z12 == 0.0 && z02 == 0.0,
            zonal_u,
            profile,
            tables,
            covariance,
            vectors,
            values,
            basis,
            basis_sensor,
            log_whitening: {
                let mut product = LogProduct::ONE;
                let mut i = 0;
                while i < K {
                    product = product.times(whitening[i]);
                    i += 1;
                }
                product
            },
            basis_query,
            mean_terms,
            prior_variance,
            average_zz,
            average_hz,
            average_hh,
            noise,
            variance_scale,
            alpha: [T::ZERO; K],
            beta: [T::ZERO; 2],
            scale: T::ZERO,
            nugget: T::ZERO,
            average_variance: T::ZERO,
            updated: false,
            stream_mean: [T::ZERO; K],
            stream_weight: 0.0,
            hazard: DEFAULT_HAZARD,
            last_change: 0.0,
            log_likelihood: 0.0,
        })
    }

    /// The sensors' unit directions.
    #[must_use]
    pub const fn directions(&self) -> &[Vec3; K] {
        &self.directions
    }

    /// Takes one reading per sensor. [`Error::InvalidRadiance`] for a non-finite reading
    /// (the probe keeps its previous state).
    pub fn update(&mut self, readings: &[T; K]) -> Result<(), Error> {
        check_readings(readings)?;
        self.stream_mean = *readings;
        self.stream_weight = 1.0;
        self.last_change = 0.0;
        self.fit_all(readings, 1.0);
        Ok(())
    }

    /// Pools these readings with the earlier ones of a stream of static light, forgetting
    /// them by the posterior probability that the light changed (soft, partial resets).
    ///
    /// The state is each sensor's weighted mean reading and its weight `w` (the effective
    /// number of updates). Under unchanged light the new readings differ from the means by
    /// the noise, variance `nᵢ·(1 + 1/w)`; under a change by that plus `ψᵢ = 2·(mᵢ² + m̄²)`
    /// (the mean's square and the mean square of all means, per channel). The Bayes factor
    /// of all sensors and channels and the prior odds of a change `h/(1 − h)` (hazard `h`,
    /// [`LayoutProbe::with_hazard`], default 1/64) give the probability `π`; the old means
    /// keep the weight `(1 − π)·w/(1 + π·w)` (the mixture of "changed" and "unchanged"
    /// collapsed with the same mean). The probe then fits the pooled means with noise
    /// `nᵢ/w`: on static light the noise's share of the error falls like `1/√w`. Readings
    /// without noise ([`Noise::NONE`]) repeat exactly on static light, and any change of
    /// more than 10⁻⁵ of a reading resets.
    ///
    /// [`Error::InvalidRadiance`] for a non-finite reading (the state is kept).
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::temporal::Change;
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let noise = Noise { absolute: 0.01, relative: 0.0 };
    /// let mut probe = LayoutProbe::<6>::new(&faces.map(Sensor::cosine), Prior::ENVIRONMENT, noise)?;
    /// let light = [1.0, 1.2, 0.9, 1.1, 2.0, 0.3];
    /// assert_eq!(probe.accumulate(&light)?, Change::First);
    /// assert_eq!(probe.accumulate(&light.map(|v| v + 0.004))?, Change::Blended);
    /// assert!(probe.pooled_updates() > 1.9);
    /// // The lamp goes off: every sensor reads half.
    /// assert_eq!(probe.accumulate(&light.map(|v| 0.5 * v))?, Change::Reset);
    /// assert!(probe.pooled_updates() < 1.1);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn accumulate(&mut self, readings: &[T; K]) -> Result<Change, Error> {
        check_readings(readings)?;
        let w = self.stream_weight;
        if w <= 0.0 {
            self.stream_mean = *readings;
            self.stream_weight = 1.0;
            self.last_change = 1.0;
            self.fit_all(readings, 1.0);
            return Ok(Change::First);
        }
        let mut log_bf = 0.0f32;
        for ch in 0..T::CHANNELS {
            let square_mean =
                self.stream_mean.iter().map(|m| m.channel(ch) * m.channel(ch)).sum::<f32>()
                    / K as f32;
            for i in 0..K {
                let m = self.stream_mean[i].channel(ch);
                let r = readings[i].channel(ch) - m;
                let scale = self.whitening[i];
                let noise = self.noise.absolute * self.noise.absolute / (scale * scale)
                    + self.noise.relative * self.noise.relative * m * m;
                // Rounding is not a change.
                let tiny = 1e-5 * m.abs();
                let s0 = noise * (1.0 + 1.0 / w) + tiny * tiny;
                let psi = 2.0 * (m * m + square_mean);
                log_bf += gaussian_log_bf(r * r, 1.0, s0, psi);
            }
        }
        let probability = logistic(log_odds(self.hazard) + log_bf);
        let kept = (1.0 - probability) * w / (1.0 + probability * w);
        let weight = kept + 1.0;
        for (mean, &y) in self.stream_mean.iter_mut().zip(readings) {
            *mean = mean.scale(kept / weight).add(y.scale(1.0 / weight));
        }
        self.stream_weight = weight;
        self.last_change = probability;
        let pooled = self.stream_mean;
        self.fit_all(&pooled, weight);
        Ok(if probability >= 0.5 { Change::Reset } else { Change::Blended })
    }

    /// The effective number of updates pooled by [`LayoutProbe::accumulate`] (1 after
    /// [`LayoutProbe::update`], 0 before any).
    #[must_use]
    pub const fn pooled_updates(&self) -> f32 {
        self.stream_weight
    }

    /// The posterior probability of a change at the last [`LayoutProbe::accumulate`].
    #[must_use]
    pub const fn last_change_probability(&self) -> f32 {
        self.last_change
    }

    /// The same probe with hazard `h` (the prior probability of a change per update of
    /// [`LayoutProbe::accumulate`]), `0 < h < 1`; [`Error::InvalidParameter`] otherwise.
    pub fn with_hazard(mut self, h: f32) -> Result<Self, Error> {
        if !(h > 0.0 && h < 1.0) {
            return Err(Error::InvalidParameter);
        }
        self.hazard = h;
        Ok(self)
    }

    /// A one-channel probe of the combination `Σ_c w_c·Y_c` of this probe's channels
    /// (luminance from RGB readings, say), fitted to the combined (pooled) readings with their
    /// own scale by restricted maximum likelihood and their exact noise: absolute `σ·|w|`,
    /// relative `η²·Σ_c w_c²·Y_c²` per reading. Its queries give the combination with its
    /// posterior variance: the variance of a sum of channels, which the channels' own
    /// variances cannot give (their errors are correlated). Without noise its values are the
    /// combination of the channels' values (the weights do not depend on the scale); with
    /// noise each channel weighs its noise on its own, and the values differ by that.
    ///
    /// Later updates of the returned probe treat its readings as one channel, with noise
    /// `(σ·|w|, η)`. Before any update, the returned probe is not updated either.
    /// [`Error::InvalidParameter`] for non-finite weights or weights all zero.
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let mut rgb = LayoutProbe::<6, [f32; 3]>::new(&faces.map(Sensor::cosine), Prior::ENVIRONMENT, Noise::NONE)?;
    /// rgb.update(&faces.map(|d| [1.0 + 0.5 * d.z, 0.8 + 0.3 * d.x, 0.6]))?;
    /// let luminance = rgb.combined([0.2126, 0.7152, 0.0722])?;
    /// let (e, y) = (rgb.irradiance(Vec3::Z)?, luminance.irradiance(Vec3::Z)?);
    /// let sum = 0.2126 * e.value[0] + 0.7152 * e.value[1] + 0.0722 * e.value[2];
    /// assert!((y.value - sum).abs() < 1e-5 * sum);
    /// assert!(y.variance > 0.0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn combined(&self, weights: T) -> Result<LayoutProbe<K, f32>, Error> {
        let channels = T::CHANNELS.min(MAX_CHANNELS);
        let w: [f32; MAX_CHANNELS] =
            core::array::from_fn(|c| if c < channels { weights.channel(c) } else { 0.0 });
        if w.iter().any(|v| !v.is_finite()) || w.iter().all(|&v| v == 0.0) {
            return Err(Error::InvalidParameter);
        }
        let norm = math::sqrt(w.iter().map(|v| v * v).sum::<f32>());
        let noise = Noise { absolute: self.noise.absolute * norm, relative: self.noise.relative };
        let readings: [f32; K] = core::array::from_fn(|i| {
            (0..channels).map(|c| w[c] * self.stream_mean[i].channel(c)).sum::<f32>()
        });
        let eta2 = self.noise.relative * self.noise.relative;
        let relative: [f32; K] = core::array::from_fn(|i| {
            eta2 * (0..channels)
                .map(|c| {
                    let v = w[c] * self.stream_mean[i].channel(c);
                    v * v
                })
                .sum::<f32>()
        });
        let mut probe = LayoutProbe::<K, f32> {
            directions: self.directions,
            whitening: self.whitening,
            class: self.class,
            classes: self.classes,
            scaled: self.scaled,
            gains: self.gains,
            spectrum: self.spectrum,
            zonal_r: self.zonal_r,
            isotropic: self.isotropic,
            zonal_u: self.zonal_u,
            profile: self.profile,
            tables: self.tables,
            covariance: self.covariance,
            vectors: self.vectors,
            values: self.values,
            basis: self.basis,
            basis_sensor: self.basis_sensor,
            log_whitening: self.log_whitening,
            basis_query: self.basis_query,
            mean_terms: self.mean_terms,
            variance_scale: self.variance_scale,
            prior_variance: self.prior_variance,
            average_zz: self.average_zz,
            average_hz: self.average_hz,
            average_hh: self.average_hh,
            noise,
            alpha: [0.0; K],
            beta: [0.0; 2],
            scale: 0.0,
            nugget: 0.0,
            average_variance: 0.0,
            updated: false,
            stream_mean: readings,
            stream_weight: self.stream_weight,
            hazard: self.hazard,
            log_likelihood: 0.0,
            last_change: self.last_change,
        };
        if self.updated {
            let fit = probe.fit(&readings, self.stream_weight.max(1.0), Some(&relative));
            probe.alpha = fit.alpha;
            probe.beta = [fit.beta, 0.0];
            probe.scale = fit.scale;
            probe.nugget = fit.nugget;
            probe.average_variance = fit.average_variance;
            probe.log_likelihood = fit.log_likelihood;
            probe.updated = true;
        }
        Ok(probe)
    }

    /// Fits every channel of these (pooled) readings, whose noise variance is the layout's
    /// divided by `pooled`.
    fn fit_all(&mut self, readings: &[T; K], pooled: f32) {
        let mut alpha = [[0.0f32; K]; MAX_CHANNELS];
        let mut beta = [0.0f32; MAX_CHANNELS];
        let mut scale = [0.0f32; MAX_CHANNELS];
        let mut nugget = [0.0f32; MAX_CHANNELS];
        let mut average = [0.0f32; MAX_CHANNELS];
        let mut log_likelihood = 0.0f32;
        for ch in 0..T::CHANNELS.min(MAX_CHANNELS) {
            let y: [f32; K] = core::array::from_fn(|i| readings[i].channel(ch));
            let fit = self.fit(&y, pooled, None);
            alpha[ch] = fit.alpha;
            beta[ch] = fit.beta;
            scale[ch] = fit.scale;
            nugget[ch] = fit.nugget;
            average[ch] = fit.average_variance;
            log_likelihood += fit.log_likelihood;
        }
        self.log_likelihood = log_likelihood;
        self.alpha =
            core::array::from_fn(|i| from_channels(|ch| alpha[ch.min(MAX_CHANNELS - 1)][i]));
        self.beta = [from_channels(|ch| beta[ch.min(MAX_CHANNELS - 1)]), T::ZERO];
        self.scale = from_channels(|ch| scale[ch.min(MAX_CHANNELS - 1)]);
        self.nugget = from_channels(|ch| nugget[ch.min(MAX_CHANNELS - 1)]);
        self.average_variance = from_channels(|ch| average[ch.min(MAX_CHANNELS - 1)]);
        self.updated = true;
    }

    /// One channel's fit. `relative`: each reading's relative-noise variance in reading units
    /// (before pooling) where it is not `η²·yᵢ²` (a combination of channels).
    fn fit(&self, y: &[f32; K], pooled: f32, relative: Option<&[f32; K]>) -> Fit<K> {
        // Work relative to a power of two near the largest whitened reading.
        let top = (0..K).fold(0.0f32, |m, i| m.max((y[i] * self.whitening[i]).abs()));
        if top == 0.0 {
            return Fit {
                alpha: [0.0; K],
                beta: 0.0,
                scale: 0.0,
                nugget: 0.0,
                average_variance: 0.0,
                log_likelihood: 0.0,
            };
        }
        let unit = libm::scalbnf(1.0, libm::ilogbf(top));
        let inv = 1.0 / unit;
        let yw: [f32; K] = core::array::from_fn(|i| y[i] * self.whitening[i] * inv);
        let z = project(&self.vectors, &yw);
        // Whitened noise variances ν_i = σ² + η²·(Y_i/w_i)², and their mean ν̄ for the scale
        // and the variances.
        let absolute = (self.noise.absolute * inv) * (self.noise.absolute * inv) / pooled;
        let eta2 = self.noise.relative * self.noise.relative / pooled;
        let nus: [f32; K] = match relative {
            None => core::array::from_fn(|i| absolute + eta2 * yw[i] * yw[i]),
            Some(r) => core::array::from_fn(|i| {
                let w = self.whitening[i] * inv;
                absolute + r[i] * w * w / pooled
            }),
        };
        let per_reading = match relative {
            None => eta2 > 0.0,
            Some(r) => r.iter().any(|&v| v > 0.0),
        };
        let nu = nus.iter().sum::<f32>() / K as f32;
        let p = self.mean_terms;
        let h = &self.basis[0];
        let lam = &self.values;
        // REML objective at s (and the GLS pieces).
        let eval = |s: f32| -> (f32, f32, f32) {
            // Returns (objective, beta, A = hᵀD⁻¹h).
            let mut product = LogProduct::ONE;
            let (mut zz, mut hz, mut hh) = (0.0f32, 0.0f32, 0.0f32);
            for j in 0..K {
                let d = s * lam[j] + nu;
                product = product.times(d);
                zz += z[j] * z[j] / d;
                if p == 1 {
                    hz += h[j] * z[j] / d;
                    hh += h[j] * h[j] / d;
                }
            }
            let logdet = product.ln();
            if p == 1 && hh > 0.0 {
                let beta = hz / hh;
                (-0.5 * (logdet + math::ln(hh) + zz - hz * beta), beta, hh)
            } else {
                (-0.5 * (logdet + zz), 0.0, hh)
            }
        };
        // Without noise the closed form s = r̃ᵀΛ⁻¹r̃/(K − p); with noise, where the search starts.
        let noiseless = {
            let (mut zz, mut hz, mut hh) = (0.0f32, 0.0f32, 0.0f32);
            for j in 0..K {
                let inv = 1.0 / lam[j];
                zz += z[j] * z[j] * inv;
                if p == 1 {
                    hz += h[j] * z[j] * inv;
                    hh += h[j] * h[j] * inv;
                }
            }
            let q = if p == 1 && hh > 0.0 { zz - hz * hz / hh } else { zz };
            (q / (K - p) as f32).max(0.0)
        };
        let s = if nu == 0.0 {
            noiseless
        } else {
            // The root of the REML score in u = ln s by the Illinois variant of regula falsi:
            // s·dℓ/ds = −½·s·Σ λ_j/d_j + ½·s·Q′-terms, no logarithms, O(K) per trial.
            let score = |u: f32| -> f32 {
                let s = math::exp(u);
                let (mut tr, mut zz1, mut a, mut b, mut a1, mut b1) =
                    (0.0f32, 0.0f32, 0.0f32, 0.0f32, 0.0f32, 0.0f32);
                for j in 0..K {
                    let inv = 1.0 / (s * lam[j] + nu);
                    let l_inv = lam[j] * inv;
                    tr += l_inv;
                    zz1 += z[j] * z[j] * l_inv * inv;
                    if p == 1 {
                        a += h[j] * h[j] * inv;
                        b += h[j] * z[j] * inv;
                        a1 += h[j] * h[j] * l_inv * inv;
                        b1 += h[j] * z[j] * l_inv * inv;
                    }
                }
                // dℓ/ds = −½·(Σ λ/d − A′/A·(−1)… ): with A′ = −a1, b′ = −b1,
                // Q = Σ z²/d − b²/A, Q′ = −zz1 + (2b·b1·A − b²·a1)/A².
                let mut g = -tr + zz1;
                if p == 1 && a > 0.0 {
                    g += a1 / a - (2.0 * b * b1 * a - b * b * a1) / (a * a);
                }
                0.5 * s * g
            };
            // Noise only lowers the scale: a bracket just below the noiseless one first, and
            // the wide one about the readings' spread where that fails.
            let spread = z.iter().map(|v| v * v).sum::<f32>() / lam.iter().sum::<f32>();
            let centre = math::ln(spread.max(nu * 1e-6).max(1e-30));
            let start = math::ln(noiseless.max(nu * 1e-6).max(1e-30));
            let (mut lo, mut hi) = (start - 3.0, start + 0.5);
            let (mut f_lo, mut f_hi) = (score(lo), score(hi));
            if f_lo <= 0.0 {
                (hi, f_hi) = (lo, f_lo);
                lo = hi.min(centre) - 14.0;
                f_lo = score(lo);
            } else if f_hi >= 0.0 {
                (lo, f_lo) = (hi, f_hi);
                hi = lo.max(centre) + 6.0;
                f_hi = score(hi);
            }
            let u = if f_lo <= 0.0 {
                lo
            } else if f_hi >= 0.0 {
                hi
            } else {
                let mut side = 0i8;
                let mut u = 0.5 * (lo + hi);
                for _ in 0..24 {
                    u = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
                    let f = score(u);
                    if f > 0.0 {
                        lo = u;
                        f_lo = f;
                        if side == 1 {
                            f_hi *= 0.5;
                        }
                        side = 1;
                    } else {
                        hi = u;
                        f_hi = f;
                        if side == -1 {
                            f_lo *= 0.5;
                        }
                        side = -1;
                    }
                    if hi - lo < 1e-3 || f == 0.0 {
                        break;
                    }
                }
                u
            };
            math::exp(u)
        };
        let d: [f32; K] = core::array::from_fn(|j| s * lam[j] + nu);
        let (objective, beta, hh) = if s > 0.0 || nu > 0.0 {
            eval(s)
        } else {
            (
                f32::INFINITY,
                if p == 1 && h.iter().any(|&v| v != 0.0) { gls_exact(h, &z) } else { 0.0 },
                0.0,
            )
        };
        // Of the readings themselves: undo the working unit (each d_j scales by unit², A by
        // 1/unit²) and the whitening.
        let log_likelihood = objective - (K - p) as f32 * math::ln(unit) + self.log_whitening.ln();
        // r̃ = z − H̃ᵀβ; α (sensor space) = s·W·V·D⁻¹r̃.
        let r: [f32; K] = core::array::from_fn(|j| {
            let rj = z[j] - if p == 1 { h[j] * beta } else { 0.0 };
            if d[j] > 0.0 {
                rj / d[j]
            } else {
                0.0
            }
        });
        let mut beta = beta;
        let mut exact = None;
        // Relative noise differs between sensors: the mean and the weights from the exact
        // system s·C̃ + diag(ν_i), factored once (the scale and the variances keep ν̄).
        if per_reading && s > 0.0 {
            let h_sensor = &self.basis_sensor;
            let top = lam.iter().fold(0.0f32, |m, &v| m.max(v));
            // The lower triangle is all the factorization reads.
            let mut a = [[0.0f32; K]; K];
            for (i, (row, cov)) in a.iter_mut().zip(&self.covariance).enumerate() {
                for (x, c) in row[..=i].iter_mut().zip(cov) {
                    *x = s * c;
                }
                row[i] += nus[i] + s * FLOOR * top;
            }
            if cholesky(&mut a) {
                // Q = (s·C̃ + diag ν)⁻¹: β = hᵀQy/hᵀQh, and the weights Q(y − βh) = Qy − β·Qh.
                let mut weights = cholesky_solve(&a, &yw);
                if p == 1 {
                    let qh = cholesky_solve(&a, h_sensor);
                    let hqh: f32 = h_sensor.iter().zip(&qh).map(|(x, q)| x * q).sum();
                    if hqh > 0.0 {
                        beta = h_sensor.iter().zip(&weights).map(|(x, q)| x * q).sum::<f32>() / hqh;
                        for i in 0..K {
                            weights[i] -= beta * qh[i];
                        }
                    }
                }
                exact = Some(weights);
            }
        }
        let weights = match exact {
            Some(w) => w,
            None => core::array::from_fn(|i| {
                let mut acc = 0.0f32;
                for j in 0..K {
                    acc += self.vectors[i][j] * r[j];
                }
                acc
            }),
        };
        let mut alpha = [0.0f32; K];
        for i in 0..K {
            alpha[i] = s * self.whitening[i] * weights[i] * unit;
        }
        // Direction-averaged variance: s·V̄ − s²·Σ M̃_jj/d_j + avg[RᵀA⁻¹R].
        let mut average = s * self.prior_variance;
        for j in 0..K {
            if d[j] > 0.0 {
                average -= s * s * self.average_zz[j][j] / d[j];
            }
        }
        if p == 1 && hh > 0.0 {
            let hzq = &self.average_hz[0];
            let hd: [f32; K] = core::array::from_fn(|j| if d[j] > 0.0 { h[j] / d[j] } else { 0.0 });
            let mut cross = 0.0f32;
            let mut quad = 0.0f32;
            for j in 0..K {
                cross += hd[j] * hzq[j];
                let mut row = 0.0f32;
                for k in 0..K {
                    row += self.average_zz[j][k] * hd[k];
                }
                quad += hd[j] * row;
            }
            average += (self.average_hh[0][0] - 2.0 * s * cross + s * s * quad) / hh;
        }
        Fit {
            alpha,
            beta: beta * unit,
            scale: s * unit * unit,
            nugget: nu * unit * unit,
            average_variance: average.max(0.0) * unit * unit * self.variance_scale,
            log_likelihood,
        }
    }

    /// Sensor `i`'s isotropic `Cov(Yᵢ, E(n))` at unit scale, from its response's table.
    #[inline(always)]
    fn table_lookup(&self, i: usize, n: Vec3) -> f32 {
        lookup(&self.tables[self.class[i] as usize % MAX_RESPONSES], self.scaled[i], n)
    }

    /// `Cov(Yᵢ, E(n))` at unit scale for every sensor (table lookups).
    fn query_covariances(&self, n: Vec3) -> [f32; K] {
        let mut z = [0.0f32; K];
        for (i, zi) in z.iter_mut().enumerate() {
            *zi = self.table_lookup(i, n);
        }
        if !self.isotropic {
            let c = COSINE_FACTORS;
            let rv = self.zonal_query(n, &[c[0], c[1], c[2]]);
            for (zi, u) in z.iter_mut().zip(&self.zonal_u) {
                *zi += u[0] * rv[0] + u[1] * rv[1] + u[2] * rv[2];
            }
        }
        z
    }

    /// `R·v(n)` for a lobe of zonal factors `q₀, q₁, q₂`: `v_l = q_l·Y_l0(n)`.
    fn zonal_query(&self, n: Vec3, q: &[f32; 3]) -> [f32; 3] {
        let y = zonal_harmonics(n.z);
        times_r(&self.zonal_r, &[q[0] * y[0], q[1] * y[1], q[2] * y[2]])
    }

    /// The zonal part of a lobe's prior variance, `v(n)ᵀR·v(n)`.
    fn zonal_prior(&self, n: Vec3, q: &[f32; 3]) -> f32 {
        let y = zonal_harmonics(n.z);
        let rv = self.zonal_query(n, q);
        q[0] * y[0] * rv[0] + q[1] * y[1] * rv[1] + q[2] * y[2] * rv[2]
    }

    /// The mean basis's irradiance at `n`.
    fn mean_query(&self, n: Vec3) -> f32 {
        if self.mean_terms == 0 {
            return 0.0;
        }
        legendre_sum(&self.basis_query[0], n.z)
    }

    /// Irradiance `E(n) = ∫ L(x)·max(0, n·x) dx` with the direction-averaged posterior
    /// variance (O(K)). [`Error::InvalidDirection`] for a zero or non-finite normal; before
    /// the first update, zero with zero variance.
    pub fn irradiance(&self, normal: Vec3) -> Result<Estimate<T>, Error> {
        let n = unit(normal)?;
        let h = self.mean_query(n);
        let mut value = self.beta[0].scale(h);
        if self.isotropic && self.classes == 1 {
            let table = &self.tables[0];
            for i in 0..K {
                value = value.mul_add(self.alpha[i], lookup(table, self.scaled[i], n));
            }
        } else if self.isotropic {
            for i in 0..K {
                value = value.mul_add(self.alpha[i], self.table_lookup(i, n));
            }
        } else {
            let z = self.query_covariances(n);
            for i in 0..K {
                value = value.mul_add(self.alpha[i], z[i]);
            }
        }
        Ok(Estimate { value, variance: self.average_variance, unit_variance: 1.0 })
    }

    /// The exact posterior variance of [`LayoutProbe::irradiance`] at `normal`, O(K²).
    pub fn irradiance_variance(&self, normal: Vec3) -> Result<T, Error> {
        let n = unit(normal)?;
        let z = self.query_covariances(n);
        let c = cosine_factors_lookup();
        let prior = self.prior_variance + self.zonal_prior(n, &[c[0], c[1], c[2]]);
        Ok(self.exact_variance(&z, self.mean_query(n), prior))
    }

    /// `s·V̄ − s²·z̃ᵀD⁻¹z̃ + RᵀA⁻¹R` per channel for unit-scale query covariances `z`, the
    /// query's mean basis value `h` and unit prior variance `prior`.
    fn exact_variance(&self, z: &[f32; K], h: f32, prior: f32) -> T {
        let zw: [f32; K] = core::array::from_fn(|i| z[i] * self.whitening[i]);
        let zt = project(&self.vectors, &zw);
        from_channels(|ch| {
            let s = self.scale.channel(ch);
            let nu = self.nugget.channel(ch);
            let mut v = s * prior;
            let (mut hz, mut hh) = (0.0f32, 0.0f32);
            for j in 0..K {
                let d = s * self.values[j] + nu;
                if d > 0.0 {
                    v -= s * s * zt[j] * zt[j] / d;
                    if self.mean_terms == 1 {
                        hz += self.basis[0][j] * zt[j] / d;
                        hh += self.basis[0][j] * self.basis[0][j] / d;
                    }
                }
            }
            if self.mean_terms == 1 && hh > 0.0 {
                let r = h - s * hz;
                v += r * r / hh;
            }
            v.max(0.0) * self.variance_scale
        })
    }

    /// The estimate of `∫ L(x)·f(axis·x) dx` for a zonal lobe `f` of Legendre coefficients
    /// `q_l = 2π∫ f(t)·P_l(t) dt`, with its exact posterior variance: O(K·DEGREES + K²).
    fn lobe(&self, axis: Vec3, q: &[f32; DEGREES]) -> Estimate<T> {
        let weight = |l: usize| (2 * l + 1) as f32 / FOUR_PI;
        let mut series = [[0.0f32; DEGREES]; MAX_RESPONSES];
        for (c, g) in series.iter_mut().zip(&self.gains) {
            for l in 0..DEGREES {
                c[l] = self.spectrum[l] * g[l] * q[l] * weight(l);
            }
        }
        let rv = self.zonal_query(axis, &[q[0], q[1], q[2]]);
        let z: [f32; K] = core::array::from_fn(|i| {
            let u = &self.zonal_u[i];
            legendre_sum(
                &series[self.class[i] as usize % MAX_RESPONSES],
                self.directions[i].dot(axis),
            ) + u[0] * rv[0]
                + u[1] * rv[1]
                + u[2] * rv[2]
        });
        let mean: [f32; 9] = core::array::from_fn(|l| self.profile[l] * q[l]);
        let h = if self.mean_terms == 1 { legendre_sum(&mean, axis.z) } else { 0.0 };
        let prior = (0..DEGREES).map(|l| self.spectrum[l] * q[l] * q[l] * weight(l)).sum::<f32>()
            + self.zonal_prior(axis, &[q[0], q[1], q[2]]);
        let mut value = self.beta[0].scale(h);
        for i in 0..K {
            value = value.mul_add(self.alpha[i], z[i]);
        }
        let variance = self.exact_variance(&z, h, prior);
        Estimate { value, variance, unit_variance: 1.0 }
    }

    /// The normalised Phong average `∫ L(x)·(e + 1)/(2π)·max(0, axis·x)ᵉ dx` (the glossy term
    /// about a mirror direction), with its exact posterior variance, O(K·DEGREES + K²).
    /// [`Error::InvalidDirection`] for a zero or non-finite axis, [`Error::InvalidExponent`]
    /// for an exponent that is negative, not finite or above 4096.
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let prior = Prior::squared_exponential(2.0)?;
    /// let mut probe = LayoutProbe::<6>::new(&faces.map(Sensor::cosine), prior, Noise::NONE)?;
    /// probe.update(&[1.0; 6])?;
    /// // A constant radiance: every normalised lobe averages to it, with no variance.
    /// let e = probe.phong(Vec3::new(0.2, 0.3, 0.9), 20.0)?;
    /// assert!((e.value - 1.0).abs() < 1e-4 && e.variance < 1e-6);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn phong(&self, axis: Vec3, exponent: f32) -> Result<Estimate<T>, Error> {
        let r = unit(axis)?;
        let q = Response::CosinePower(exponent).gains().map_err(|_| Error::InvalidExponent)?;
        Ok(self.lobe(r, &q))
    }

    /// `∫ L(x)·G(x) dx` for a spherical-Gaussian lobe `G` (sharpness at most 4096), with its
    /// exact posterior variance, O(K·DEGREES + K²). [`Error::InvalidSharpness`] for a
    /// sharpness above 4096 (or not finite, or negative), [`Error::InvalidParameter`] for a
    /// non-finite amplitude, [`Error::InvalidDirection`] for a bad axis.
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::sg::SphericalGaussian;
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let prior = Prior::squared_exponential(2.0)?;
    /// let mut probe = LayoutProbe::<6>::new(&faces.map(Sensor::cosine), prior, Noise::NONE)?;
    /// probe.update(&[2.0; 6])?;
    /// let lobe = SphericalGaussian::new(Vec3::Z, 10.0, 1.0)?;
    /// let e = probe.glossy(&lobe)?;
    /// assert!((e.value - 2.0 * lobe.integral()).abs() < 1e-4 * e.value);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn glossy(&self, lobe: &SphericalGaussian) -> Result<Estimate<T>, Error> {
        let r = unit(lobe.axis)?;
        let mu = lobe.sharpness;
        if !(mu.is_finite() && (0.0..=4096.0).contains(&mu)) {
            return Err(Error::InvalidSharpness);
        }
        if !lobe.amplitude.is_finite() {
            return Err(Error::InvalidParameter);
        }
        let mut q = [0.0f32; DEGREES];
        q[0] = 1.0;
        if mu > 0.0 {
            q = Response::Gaussian(mu).gains().map_err(|_| Error::InvalidSharpness)?;
        }
        let total = lobe.integral();
        Ok(self.lobe(r, &q.map(|v| v * total)))
    }

    /// The posterior mean of the radiance's spherical-harmonic coefficients of degree ≤ 2
    /// (the 9 that renderers take; [`crate::sh`] evaluates, rotates and converts them):
    /// `c_lm = β·a_l·√(4π/(2l + 1))·δ_m0 + Σᵢ αᵢ·K_l gᵢ_l·Y_lm(dᵢ)`, O(9K).
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let prior = Prior::squared_exponential(2.0)?;
    /// let mut probe = LayoutProbe::<6>::new(&faces.map(Sensor::cosine), prior, Noise::NONE)?;
    /// probe.update(&[1.0; 6])?;
    /// // A constant radiance of 1 has c₀₀ = √(4π), and nothing else.
    /// let sh = probe.radiance_sh();
    /// assert!((sh.coefficients[0] - (4.0 * core::f32::consts::PI).sqrt()).abs() < 1e-4);
    /// assert!(sh.coefficients[1..].iter().all(|c| c.abs() < 1e-4));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub fn radiance_sh(&self) -> ShL2<T> {
        let mut coefficients = [T::ZERO; 9];
        if self.mean_terms == 1 {
            for l in 0..3 {
                let c = self.profile[l] * math::sqrt(FOUR_PI / (2 * l + 1) as f32);
                coefficients[l * l + l] = self.beta[0].scale(c);
            }
        }
        for i in 0..K {
            let Ok(basis) = ShL2::<f32>::basis(self.directions[i]) else { continue };
            let g = &self.gains[self.class[i] as usize % MAX_RESPONSES];
            for (k, c) in coefficients.iter_mut().enumerate() {
                let l = if k == 0 {
                    0
                } else if k < 4 {
                    1
                } else {
                    2
                };
                *c = c.mul_add(self.alpha[i], self.spectrum[l] * g[l] * basis[k]);
            }
        }
        ShL2::new(coefficients)
    }

    /// The scale `s = σ_f²` of the covariance chosen at the last update, per channel (0 before
    /// the first).
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let prior = Prior::squared_exponential(4.0)?;
    /// let mut probe = LayoutProbe::<6>::new(&faces.map(Sensor::cosine), prior, Noise::NONE)?;
    /// assert_eq!(probe.signal_variance(), 0.0);
    /// probe.update(&[1.0, 1.2, 0.9, 1.1, 2.0, 0.3])?;
    /// assert!(probe.signal_variance() > 0.0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub fn signal_variance(&self) -> T {
        self.scale
    }

    /// The restricted (REML) log likelihood of the last update's readings under the probe's
    /// prior and noise, up to a constant, summed over channels:
    /// `−½·(log det Σ + log det HᵀΣ⁻¹H + rᵀΣ⁻¹r)` at the chosen scale (with a relative noise,
    /// at its mean level). Compare it
    /// between probes of the same sensors and readings to choose a prior per update; `+∞`
    /// when the readings fit exactly (a constant under a constant mean), 0 before the first.
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let sensors = faces.map(Sensor::cosine);
    /// let readings = [1.0, 1.2, 0.9, 1.1, 2.0, 0.3];
    /// let mut best = (f32::NEG_INFINITY, 0.0);
    /// for lambda in [1.0, 4.0, 16.0] {
    ///     let prior = Prior::squared_exponential(lambda)?;
    ///     let mut probe = LayoutProbe::<6>::new(&sensors, prior, Noise::NONE)?;
    ///     probe.update(&readings)?;
    ///     if probe.log_likelihood() > best.0 {
    ///         best = (probe.log_likelihood(), lambda);
    ///     }
    /// }
    /// assert!(best.0.is_finite());
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub const fn log_likelihood(&self) -> f32 {
        self.log_likelihood
    }

    /// Whether the probe has had an update.
    #[must_use]
    pub const fn is_updated(&self) -> bool {
        self.updated
    }
}

struct Fit<const K: usize> {
    alpha: [f32; K],
    beta: f32,
    scale: f32,
    nugget: f32,
    average_variance: f32,
    log_likelihood: f32,
}

/// β by least squares when `s = ν = 0` (all readings equal to the mean): `hᵀz/hᵀh`.
fn gls_exact<const K: usize>(h: &[f32; K], z: &[f32; K]) -> f32 {
    let hh: f32 = h.iter().map(|v| v * v).sum();
    let hz: f32 = h.iter().zip(z).map(|(a, b)| a * b).sum();
    if hh > 0.0 {
        hz / hh
    } else {
        0.0
    }
}

fn check_readings<T: Radiance, const K: usize>(readings: &[T; K]) -> Result<(), Error> {
    for r in readings {
        for ch in 0..T::CHANNELS {
            if !r.channel(ch).is_finite() {
                return Err(Error::InvalidRadiance);
            }
        }
    }
    Ok(())
}

fn unit(v: Vec3) -> Result<Vec3, Error> {
    if !v.is_finite() {
        return Err(Error::InvalidDirection);
    }
    v.try_normalize().ok_or(Error::InvalidDirection)
}

/// In-place lower Cholesky factor of a symmetric positive-definite matrix; `false` if it is
/// not positive definite in f32.
fn cholesky<const K: usize>(a: &mut [[f32; K]; K]) -> bool {
    for j in 0..K {
        let (row_j, below) = match a[j..].split_first_mut() {
            Some(split) => split,
            None => return false,
        };
        let (left, right) = row_j.split_at_mut(j);
        let d = right[0] - dot(left, left);
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let root = math::sqrt(d);
        right[0] = root;
        let inverse = 1.0 / root;
        for row_i in below {
            let (left_i, right_i) = row_i.split_at_mut(j);
            right_i[0] = (right_i[0] - dot(left_i, left)) * inverse;
        }
    }
    true
}

/// `Σ aᵢbᵢ` over the shorter slice.
#[inline(always)]
fn dot(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).fold(0.0f32, |s, (x, y)| s + x * y)
}

/// `(LLᵀ)⁻¹b` for the factor of [`cholesky`] (its lower triangle, by rows).
fn cholesky_solve<const K: usize>(l: &[[f32; K]; K], b: &[f32; K]) -> [f32; K] {
    let mut x = *b;
    // Lz = b, row by row.
    for (i, row) in l.iter().enumerate() {
        let (done, rest) = x.split_at_mut(i);
        rest[0] = (rest[0] - dot(&row[..i], done)) / row[i];
    }
    // Lᵀx = z, by columns of Lᵀ (rows of L): x_i is final once the rows below took their part.
    for (i, row) in l.iter().enumerate().rev() {
        let (before, rest) = x.split_at_mut(i);
        rest[0] /= row[i];
        let xi = rest[0];
        for (xk, lik) in before.iter_mut().zip(&row[..i]) {
            *xk -= lik * xi;
        }
    }
    x
}

/// `Vᵀx` for the eigenvector columns `V`.
const fn project<const K: usize>(v: &[[f32; K]; K], x: &[f32; K]) -> [f32; K] {
    let mut out = [0.0f32; K];
    let mut i = 0;
    while i < K {
        let mut j = 0;
        while j < K {
            out[j] += v[i][j] * x[i];
            j += 1;
        }
        i += 1;
    }
    out
}

/// `VᵀAV`.
const fn congruence<const K: usize>(v: &[[f32; K]; K], a: &[[f32; K]; K]) -> [[f32; K]; K] {
    // AV first, then Vᵀ(AV).
    let mut av = [[0.0f32; K]; K];
    let mut i = 0;
    while i < K {
        let mut k = 0;
        while k < K {
            let aik = a[i][k];
            let mut j = 0;
            while j < K {
                av[i][j] += aik * v[k][j];
                j += 1;
            }
            k += 1;
        }
        i += 1;
    }
    let mut out = [[0.0f32; K]; K];
    let mut i = 0;
    while i < K {
        let mut a_ = 0;
        while a_ < K {
            let via = v[i][a_];
            let mut b = 0;
            while b < K {
                out[a_][b] += via * av[i][b];
                b += 1;
            }
            a_ += 1;
        }
        i += 1;
    }
    out
}

/// A product of positive numbers as a mantissa in `[1, 2)` and a power of two, so that the
/// logarithm of a long product takes one `ln` and never overflows or underflows.
#[derive(Clone, Copy, Debug)]
struct LogProduct {
    mantissa: f32,
    exponent: i32,
}

impl LogProduct {
    const ONE: LogProduct = LogProduct { mantissa: 1.0, exponent: 0 };

    /// The product times a positive, finite `x` (const).
    const fn times(self, x: f32) -> LogProduct {
        let (m, e) = split(x);
        let (m, e2) = split(self.mantissa * m);
        LogProduct { mantissa: m, exponent: self.exponent + e + e2 }
    }

    /// Its natural logarithm.
    fn ln(self) -> f32 {
        math::ln(self.mantissa) + self.exponent as f32 * core::f32::consts::LN_2
    }
}

/// `x = m·2ᵉ` with `m ∈ [1, 2)` for a positive, finite `x` (subnormals too; `(1, −149)` below
/// those) (const).
const fn split(x: f32) -> (f32, i32) {
    let (x, shift) = if x < f32::MIN_POSITIVE { (x * 16_777_216.0, -24) } else { (x, 0) };
    if x.is_nan() || x <= 0.0 {
        return (1.0, -149);
    }
    let bits = x.to_bits();
    let e = ((bits >> 23) & 0xff) as i32 - 127;
    (f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000), e + shift)
}

/// `√(a² + b²)` without overflow or underflow in the squares (const).
const fn hypotenuse(a: f32, b: f32) -> f32 {
    let (x, y) = (absolute(a), absolute(b));
    let m = if x > y { x } else { y };
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    let (x, y) = (x / m, y / m);
    m * square_root(x * x + y * y)
}

/// Eigenvalues and eigenvectors (columns) of a symmetric matrix (const: at compile time for a
/// probe in a `const` or `static`): Householder reflections to a tridiagonal matrix, then
/// implicit QL steps with Wilkinson shifts, accumulating every transformation in `V`, then
/// one Jacobi sweep. O(K³).
const fn symmetric_eigen<const K: usize>(mut a: [[f32; K]; K]) -> ([f32; K], [[f32; K]; K]) {
    let original = a;
    let mut v = [[0.0f32; K]; K];
    let mut i = 0;
    while i < K {
        v[i][i] = 1.0;
        i += 1;
    }
    // Householder: for column k, the unit u with (I − 2uuᵀ)·a[k+1.., k] = (α, 0, …, 0). On the
    // trailing block B (rows and columns k+1..): p = Bu, w = p − (uᵀp)u, and
    // (I − 2uuᵀ)B(I − 2uuᵀ) = B − 2uwᵀ − 2wuᵀ. V gathers the reflections from the right.
    let mut k = 0;
    while k + 2 < K {
        let mut scale = 0.0f32;
        let mut r = k + 1;
        while r < K {
            scale += absolute(a[r][k]);
            r += 1;
        }
        if scale > 0.0 {
            let mut u = [0.0f32; K];
            let mut norm = 0.0f32;
            let mut r = k + 1;
            while r < K {
                u[r] = a[r][k] / scale;
                norm += u[r] * u[r];
                r += 1;
            }
            let length = square_root(norm);
            // α takes the sign opposite to the first entry, so u₀ = x₀ − α does not cancel.
            let alpha = if u[k + 1] > 0.0 { -length } else { length };
            u[k + 1] -= alpha;
            // |u|² = |x|² − 2αx₀ + α² = 2(|x|² − αx₀).
            let u_norm = square_root(2.0 * (norm - alpha * (u[k + 1] + alpha)));
            if u_norm > 0.0 {
                let mut r = k + 1;
                while r < K {
                    u[r] /= u_norm;
                    r += 1;
                }
                let mut p = [0.0f32; K];
                let mut up = 0.0f32;
                let mut r = k + 1;
                while r < K {
                    let mut c = k + 1;
                    let mut acc = 0.0f32;
                    while c < K {
                        acc += a[r][c] * u[c];
                        c += 1;
                    }
                    p[r] = acc;
                    up += u[r] * acc;
                    r += 1;
                }
                let mut r = k + 1;
                while r < K {
                    p[r] -= up * u[r];
                    r += 1;
                }
                let mut r = k + 1;
                while r < K {
                    let mut c = k + 1;
                    while c <= r {
                        let x = a[r][c] - 2.0 * (u[r] * p[c] + p[r] * u[c]);
                        a[r][c] = x;
                        a[c][r] = x;
                        c += 1;
                    }
                    r += 1;
                }
                // The column below the subdiagonal becomes (α·scale, 0, …).
                a[k + 1][k] = alpha * scale;
                a[k][k + 1] = alpha * scale;
                let mut r = k + 2;
                while r < K {
                    a[r][k] = 0.0;
                    a[k][r] = 0.0;
                    r += 1;
                }
                // V ← V(I − 2uuᵀ).
                let mut row = 0;
                while row < K {
                    let mut dot = 0.0f32;
                    let mut c = k + 1;
                    while c < K {
                        dot += v[row][c] * u[c];
                        c += 1;
                    }
                    let mut c = k + 1;
                    while c < K {
                        v[row][c] -= 2.0 * dot * u[c];
                        c += 1;
                    }
                    row += 1;
                }
            }
        }
        k += 1;
    }
    // The tridiagonal matrix: diagonal d, off-diagonal e[i] between i and i + 1.
    let mut d = [0.0f32; K];
    let mut e = [0.0f32; K];
    let mut i = 0;
    while i < K {
        d[i] = a[i][i];
        if i + 1 < K {
            e[i] = a[i + 1][i];
        }
        i += 1;
    }
    // Implicit QL: deflate from the top. For each l, chase the bulge of a shifted QL step
    // through rows m − 1 … l by Givens rotations until e[l] is negligible.
    let mut l = 0;
    while l < K {
        let mut iterations = 0;
        loop {
            // The first negligible e[m] at or after l (m = K − 1: the end).
            let mut m = l;
            while m + 1 < K {
                let dd = absolute(d[m]) + absolute(d[m + 1]);
                if absolute(e[m]) <= f32::EPSILON * dd {
                    break;
                }
                m += 1;
            }
            if m == l || iterations >= 40 {
                break;
            }
            iterations += 1;
            // Wilkinson's shift: the eigenvalue of the leading 2×2 block nearer d[l].
            let g = (d[l + 1] - d[l]) / (2.0 * e[l]);
            let r = hypotenuse(g, 1.0);
            let root = if g < 0.0 { g - r } else { g + r };
            let mut g = d[m] - d[l] + e[l] / root;
            let (mut s, mut c, mut p) = (1.0f32, 1.0f32, 0.0f32);
            let mut underflow = false;
            let mut i = m;
            while i > l {
                i -= 1;
                let f = s * e[i];
                let b = c * e[i];
                let r = hypotenuse(f, g);
                e[i + 1] = r;
                if r == 0.0 {
                    // The rotation vanished: split the matrix here and restart.
                    d[i + 1] -= p;
                    e[m] = 0.0;
                    underflow = true;
                    break;
                }
                s = f / r;
                c = g / r;
                let h = d[i + 1] - p;
                let t = (d[i] - h) * s + 2.0 * c * b;
                p = s * t;
                d[i + 1] = h + p;
                g = c * t - b;
                let mut row = 0;
                while row < K {
                    let x = v[row][i + 1];
                    v[row][i + 1] = s * v[row][i] + c * x;
                    v[row][i] = c * v[row][i] - s * x;
                    row += 1;
                }
            }
            if underflow {
                continue;
            }
            d[l] -= p;
            e[l] = g;
            e[m] = 0.0;
        }
        l += 1;
    }
    // One cyclic Jacobi sweep on VᵀAV restores the small eigenvalues' relative accuracy that
    // the reflections' rounding (of the order of ε·|A|) took.
    let b = congruence(&v, &original);
    jacobi_sweeps(b, v, 1)
}

/// Cyclic Jacobi sweeps on a symmetric `a`, rotating the columns of `v` with it (at most
/// `sweeps`, fewer once `a` is diagonal to rounding): the eigenvalues (diagonal) and `v`.
const fn jacobi_sweeps<const K: usize>(
    mut a: [[f32; K]; K],
    mut v: [[f32; K]; K],
    sweeps: usize,
) -> ([f32; K], [[f32; K]; K]) {
    let mut sweep = 0;
    while sweep < sweeps {
        let mut off = 0.0f32;
        let mut diag = 0.0f32;
        let mut i = 0;
        while i < K {
            diag += a[i][i] * a[i][i];
            let mut j = 0;
            while j < i {
                off += a[i][j] * a[i][j];
                j += 1;
            }
            i += 1;
        }
        if off <= 1e-14 * diag {
            break;
        }
        let mut p = 0;
        while p < K {
            let mut q = p + 1;
            while q < K {
                let apq = a[p][q];
                // Negligible against both diagonal entries (the relative criterion that keeps
                // small eigenvalues accurate): no rotation.
                if apq * apq <= f32::EPSILON * f32::EPSILON * absolute(a[p][p] * a[q][q]) {
                    q += 1;
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
                let sign = if theta < 0.0 { -1.0 } else { 1.0 };
                // tan of the rotation angle, the smaller root of t² + 2θt − 1 = 0 (1/(2θ)
                // where θ² would overflow).
                let t = if absolute(theta) > 1e18 {
                    0.5 / theta
                } else {
                    sign / (absolute(theta) + square_root(theta * theta + 1.0))
                };
                let c = 1.0 / square_root(t * t + 1.0);
                let s = t * c;
                let mut k = 0;
                while k < K {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                    k += 1;
                }
                let mut k = 0;
                while k < K {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                    k += 1;
                }
                let mut k = 0;
                while k < K {
                    let (vp, vq) = (v[k][p], v[k][q]);
                    v[k][p] = c * vp - s * vq;
                    v[k][q] = s * vp + c * vq;
                    k += 1;
                }
                q += 1;
            }
            p += 1;
        }
        sweep += 1;
    }
    let mut values = [0.0f32; K];
    let mut i = 0;
    while i < K {
        values[i] = a[i][i];
        i += 1;
    }
    (values, v)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn cube() -> [Sensor; 6] {
        [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z].map(Sensor::cosine)
    }

    fn dome() -> [Sensor; 5] {
        let h = core::f32::consts::FRAC_1_SQRT_2;
        [
            Vec3::Z,
            Vec3::new(h, 0.0, h),
            Vec3::new(0.0, h, h),
            Vec3::new(-h, 0.0, h),
            Vec3::new(0.0, -h, h),
        ]
        .map(Sensor::cosine)
    }

    /// The posterior mean and variance from the textbook formulas in f64: the covariance by
    /// direct Legendre sums, a dense Cholesky factor, GLS for the mean and `s` in closed
    /// form (no noise).
    #[allow(clippy::too_many_arguments)]
    fn reference(
        dirs: &[[f64; 3]],
        gains: &[f64],
        prior: &Prior,
        profile: Option<&[f64]>,
        y: &[f64],
        n: [f64; 3],
        noise: Option<(f64, &[f64])>,
        lobe: Option<&[f64]>,
    ) -> (f64, f64, f64) {
        let k = dirs.len();
        let legendre = |l: usize, t: f64| {
            let (mut p0, mut p1) = (1.0, t);
            if l == 0 {
                return 1.0;
            }
            for m in 2..=l {
                let p2 = ((2 * m - 1) as f64 * t * p1 - (m - 1) as f64 * p0) / m as f64;
                p0 = p1;
                p1 = p2;
            }
            p1
        };
        let c: Vec<f64> = (0..DEGREES)
            .map(|l| {
                // c_l = 2π∫₀¹ t P_l(t) dt by a fine midpoint rule.
                let m = 20000;
                (0..m)
                    .map(|i| {
                        let t = (i as f64 + 0.5) / m as f64;
                        t * legendre(l, t)
                    })
                    .sum::<f64>()
                    * 2.0
                    * core::f64::consts::PI
                    / m as f64
            })
            .collect();
        let c: Vec<f64> = lobe.map_or(c, <[f64]>::to_vec);
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let w = |l: usize| (2 * l + 1) as f64 / (4.0 * core::f64::consts::PI);
        let sp = |l: usize| f64::from(prior.spectrum[l]);
        // The zonal covariances: Σ_{l≠l'} R_ll'·f_l Y_l0(x)·f'_l' Y_l'0(x') with the textbook
        // Y_l0(z) = √((2l + 1)/(4π))·P_l(z).
        let r = [
            [0.0, f64::from(prior.zonal[0]), f64::from(prior.zonal[2])],
            [f64::from(prior.zonal[0]), 0.0, f64::from(prior.zonal[1])],
            [f64::from(prior.zonal[2]), f64::from(prior.zonal[1]), 0.0],
        ];
        let y0 = |l: usize, z: f64| {
            ((2 * l + 1) as f64 / (4.0 * core::f64::consts::PI)).sqrt() * legendre(l, z)
        };
        let zonal =
            |f: &dyn Fn(usize) -> f64, x: [f64; 3], f2: &dyn Fn(usize) -> f64, x2: [f64; 3]| {
                let mut t = 0.0;
                for l in 0..3 {
                    for m in 0..3 {
                        t += r[l][m] * f(l) * y0(l, x[2]) * f2(m) * y0(m, x2[2]);
                    }
                }
                t
            };
        let g = |l: usize| gains[l];
        let cov = |i: usize, j: usize| {
            (0..DEGREES)
                .map(|l| sp(l) * gains[l] * gains[l] * w(l) * legendre(l, dot(dirs[i], dirs[j])))
                .sum::<f64>()
                + zonal(&g, dirs[i], &g, dirs[j])
        };
        let cq = |l: usize| c[l];
        let zq: Vec<f64> = (0..k)
            .map(|i| {
                (0..DEGREES)
                    .map(|l| sp(l) * gains[l] * c[l] * w(l) * legendre(l, dot(dirs[i], n)))
                    .sum::<f64>()
                    + zonal(&g, dirs[i], &cq, n)
            })
            .collect();
        // Without noise the scale cancels from the mean; with noise s·C + diag(nᵢ).
        let (scale, nz): (f64, Vec<f64>) = match noise {
            None => (1.0, std::vec![0.0; k]),
            Some((s, n)) => (s, n.to_vec()),
        };
        let mut a: Vec<f64> = (0..k * k)
            .map(|x| scale * cov(x / k, x % k) + if x / k == x % k { nz[x / k] } else { 0.0 })
            .collect();
        // Cholesky.
        for j in 0..k {
            for i in j..k {
                let mut s = a[i * k + j];
                for m in 0..j {
                    s -= a[i * k + m] * a[j * k + m];
                }
                a[i * k + j] = if i == j { s.sqrt() } else { s / a[j * k + j] };
            }
        }
        let solve = |b: &[f64]| {
            let mut x = b.to_vec();
            for i in 0..k {
                for m in 0..i {
                    x[i] -= a[i * k + m] * x[m];
                }
                x[i] /= a[i * k + i];
            }
            for i in (0..k).rev() {
                for m in i + 1..k {
                    x[i] -= a[m * k + i] * x[m];
                }
                x[i] /= a[i * k + i];
            }
            x
        };
        let ip = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(p, q)| p * q).sum::<f64>();
        let (h, hq): (Vec<f64>, f64) = match profile {
            None => (std::vec![0.0; k], 0.0),
            Some(p) => (
                (0..k)
                    .map(|i| (0..p.len()).map(|l| p[l] * gains[l] * legendre(l, dirs[i][2])).sum())
                    .collect(),
                (0..p.len()).map(|l| p[l] * c[l] * legendre(l, n[2])).sum(),
            ),
        };
        let qy = solve(y);
        let qh = solve(&h);
        let qz = solve(&zq);
        let (beta, hqh) =
            if profile.is_some() { (ip(&h, &qy) / ip(&h, &qh), ip(&h, &qh)) } else { (0.0, 0.0) };
        let r: Vec<f64> = (0..k).map(|i| y[i] - beta * h[i]).collect();
        let qr = solve(&r);
        let p = usize::from(profile.is_some());
        let s = ip(&r, &qr) / (k - p) as f64;
        let value = beta * hq + scale * ip(&zq, &qr);
        // REML without noise at s = rᵀC⁻¹r/(K − p):
        // −½·((K − p)·ln s + ln det C + ln hᵀC⁻¹h + (K − p)).
        let log_det: f64 = (0..k).map(|i| 2.0 * a[i * k + i].ln()).sum();
        let p_terms = usize::from(profile.is_some());
        let s_reml = ip(&r, &qr) / (k - p_terms) as f64;
        let free = (k - p_terms) as f64;
        let log_likelihood = -0.5
            * (free * s_reml.ln()
                + log_det
                + if profile.is_some() { hqh.ln() } else { 0.0 }
                + free);
        let vbar: f64 =
            (0..DEGREES).map(|l| sp(l) * c[l] * c[l] * w(l)).sum::<f64>() + zonal(&cq, n, &cq, n);
        let mut var = vbar - ip(&zq, &qz);
        if profile.is_some() {
            let rr = hq - ip(&h, &qz);
            var += rr * rr / hqh;
        }
        (value, s * var, log_likelihood)
    }

    fn to64(v: Vec3) -> [f64; 3] {
        [f64::from(v.x), f64::from(v.y), f64::from(v.z)]
    }

    /// Against the f64 reference: a cube (zero mean) and a dome (zonal mean), arbitrary
    /// readings, twenty normals.
    #[test]
    fn agrees_with_an_f64_reference() {
        let gains: Vec<f64> =
            Response::CosinePower(1.0).gains().unwrap().iter().map(|&g| f64::from(g)).collect();
        let se = Prior::squared_exponential(4.0).unwrap();
        let mut profile = [0.0f32; 9];
        profile[0] = 1.0;
        profile[1] = 0.9;
        profile[2] = 0.4;
        let normals: Vec<Vec3> = (0..20)
            .map(|i| {
                let t = i as f32 * 0.7;
                Vec3::new(libm::cosf(t), libm::sinf(1.3 * t), 0.2 + 0.05 * i as f32)
            })
            .collect();
        let mut worst = (0.0f64, 0.0f64, 0.0f64);
        // Cube, zero mean.
        let sensors = cube();
        let y = [1.3f32, 0.4, 0.9, 0.7, 2.1, 0.2];
        let mut probe =
            LayoutProbe::<6>::new(&sensors, se.with_mean(Mean::Zero), Noise::NONE).unwrap();
        probe.update(&y).unwrap();
        let dirs: Vec<[f64; 3]> = sensors.iter().map(|s| to64(s.direction)).collect();
        let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
        for &n in &normals {
            let (v, var, ll) = reference(
                &dirs,
                &gains,
                &se,
                None,
                &y64,
                to64(n.try_normalize().unwrap()),
                None,
                None,
            );
            let e = probe.irradiance(n).unwrap();
            let ev = probe.irradiance_variance(n).unwrap();
            worst.0 = worst.0.max((f64::from(e.value) - v).abs() / 2.1);
            worst.2 = worst.2.max((f64::from(probe.log_likelihood()) - ll).abs());
            worst.1 = worst.1.max((f64::from(ev) - var).abs() / var.max(1e-3));
        }
        // Dome, zonal mean.
        let sensors = dome();
        let y = [2.0f32, 1.2, 1.5, 0.8, 1.1];
        let prior = se.with_mean(Mean::Zonal(profile));
        let mut probe = LayoutProbe::<5>::new(&sensors, prior, Noise::NONE).unwrap();
        probe.update(&y).unwrap();
        let dirs: Vec<[f64; 3]> =
            sensors.iter().map(|s| to64(s.direction.try_normalize().unwrap())).collect();
        let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
        let p64: Vec<f64> = profile.iter().map(|&v| f64::from(v)).collect();
        for &n in &normals {
            let (v, var, ll) = reference(
                &dirs,
                &gains,
                &se,
                Some(&p64),
                &y64,
                to64(n.try_normalize().unwrap()),
                None,
                None,
            );
            let e = probe.irradiance(n).unwrap();
            let ev = probe.irradiance_variance(n).unwrap();
            worst.0 = worst.0.max((f64::from(e.value) - v).abs() / 2.0);
            worst.2 = worst.2.max((f64::from(probe.log_likelihood()) - ll).abs());
            worst.1 = worst.1.max((f64::from(ev) - var).abs() / var.max(1e-3));
        }
        std::eprintln!("WORST {:?}", worst);
        assert!(
            worst.0 < 1e-5 && worst.1 < 5e-4 && worst.2 < 1e-5,
            "value {:e}, variance {:e}, log likelihood {:e}",
            worst.0,
            worst.1,
            worst.2
        );
    }

    /// With a relative noise the mean is that of the exact system `s·C + diag(η²Yᵢ²)` at the
    /// probe's scale `s`, against the f64 reference.
    #[test]
    fn relative_noise_solves_the_exact_system() {
        let gains: Vec<f64> =
            Response::CosinePower(1.0).gains().unwrap().iter().map(|&g| f64::from(g)).collect();
        let se = Prior::squared_exponential(4.0).unwrap();
        let mut profile = [0.0f32; 9];
        profile[0] = 1.0;
        profile[1] = 0.9;
        let sensors = dome();
        let y = [2.0f32, 1.2, 1.5, 0.8, 1.1];
        let eta = 0.05f32;
        let prior = se.with_mean(Mean::Zonal(profile));
        let mut probe =
            LayoutProbe::<5>::new(&sensors, prior, Noise { absolute: 0.0, relative: eta }).unwrap();
        probe.update(&y).unwrap();
        let s = f64::from(probe.signal_variance());
        let dirs: Vec<[f64; 3]> =
            sensors.iter().map(|s| to64(s.direction.try_normalize().unwrap())).collect();
        let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
        let noise: Vec<f64> = y64.iter().map(|v| (f64::from(eta) * v).powi(2)).collect();
        let p64: Vec<f64> = profile.iter().map(|&v| f64::from(v)).collect();
        let mut worst = 0.0f64;
        for n in [Vec3::Z, Vec3::new(0.5, 0.2, 0.8), Vec3::new(-0.7, 0.1, 0.3), Vec3::X] {
            let (v, _, _) = reference(
                &dirs,
                &gains,
                &se,
                Some(&p64),
                &y64,
                to64(n.try_normalize().unwrap()),
                Some((s, &noise)),
                None,
            );
            worst = worst.max((f64::from(probe.irradiance(n).unwrap().value) - v).abs() / 2.0);
        }
        // Measured 1.6·10⁻⁴: the f32 factor of a system of condition about 10⁴, whose weights
        // (up to 20 times the answer) cancel.
        assert!(s > 0.0 && worst < 5e-4, "s {s}, worst {worst:e}");
    }

    /// A combination of channels: with an absolute noise, the same probe as one built for the
    /// combined readings with noise `σ·|w|` (bit for bit); with a relative noise, the exact
    /// system of the combined readings' noise `η²·Σ w_c²Y_c²` (f64 reference); channels in
    /// proportion add their errors in proportion (not in quadrature); bad weights are errors.
    #[test]
    fn a_combination_of_channels_is_fitted_with_its_own_noise() {
        let sensors = dome();
        let se = Prior::squared_exponential(4.0).unwrap();
        let mut profile = [0.0f32; 9];
        profile[0] = 1.0;
        profile[1] = 0.9;
        let prior = se.with_mean(Mean::Zonal(profile));
        let y = [2.0f32, 1.2, 1.5, 0.8, 1.1];
        let rgb: [[f32; 3]; 5] =
            core::array::from_fn(|i| [y[i], 0.5 + 0.3 * y[i], 1.7 - 0.4 * y[i]]);
        let w = [0.2126f32, 0.7152, 0.0722];
        let combined: [f32; 5] = core::array::from_fn(|i| (0..3).map(|c| w[c] * rgb[i][c]).sum());
        let norm = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        let normals = [Vec3::Z, Vec3::new(0.5, 0.2, 0.8), Vec3::new(-0.7, 0.1, 0.3), Vec3::X];
        // Absolute noise.
        let noise = Noise { absolute: 0.02, relative: 0.0 };
        let mut probe = LayoutProbe::<5, [f32; 3]>::new(&sensors, prior, noise).unwrap();
        probe.update(&rgb).unwrap();
        let luminance = probe.combined(w).unwrap();
        let mut direct =
            LayoutProbe::<5>::new(&sensors, prior, Noise { absolute: 0.02 * norm, relative: 0.0 })
                .unwrap();
        direct.update(&combined).unwrap();
        for n in normals {
            let (a, b) = (luminance.irradiance(n).unwrap(), direct.irradiance(n).unwrap());
            assert_eq!(
                (a.value.to_bits(), a.variance.to_bits()),
                (b.value.to_bits(), b.variance.to_bits())
            );
            let (a, b) =
                (luminance.irradiance_variance(n).unwrap(), direct.irradiance_variance(n).unwrap());
            assert_eq!(a.to_bits(), b.to_bits());
        }
        // Relative noise: the exact system at the combined probe's scale.
        let eta = 0.05f32;
        let mut probe = LayoutProbe::<5, [f32; 3]>::new(
            &sensors,
            prior,
            Noise { absolute: 0.0, relative: eta },
        )
        .unwrap();
        probe.update(&rgb).unwrap();
        let luminance = probe.combined(w).unwrap();
        let s = f64::from(luminance.signal_variance());
        let gains: Vec<f64> =
            Response::CosinePower(1.0).gains().unwrap().iter().map(|&g| f64::from(g)).collect();
        let dirs: Vec<[f64; 3]> =
            sensors.iter().map(|s| to64(s.direction.try_normalize().unwrap())).collect();
        let y64: Vec<f64> = combined.iter().map(|&v| f64::from(v)).collect();
        let noise64: Vec<f64> = rgb
            .iter()
            .map(|r| {
                (0..3).map(|c| (f64::from(eta) * f64::from(w[c]) * f64::from(r[c])).powi(2)).sum()
            })
            .collect();
        let p64: Vec<f64> = profile.iter().map(|&v| f64::from(v)).collect();
        let mut worst = 0.0f64;
        for n in normals {
            let (v, _, _) = reference(
                &dirs,
                &gains,
                &se,
                Some(&p64),
                &y64,
                to64(n.try_normalize().unwrap()),
                Some((s, &noise64)),
                None,
            );
            worst = worst.max((f64::from(luminance.irradiance(n).unwrap().value) - v).abs() / v);
        }
        assert!(s > 0.0 && worst < 5e-4, "s {s}, worst {worst:e}");
        // Channels in proportion, no noise: errors add linearly, 1 + 2 + 3 = 6 times the first
        // channel's, a variance 36 times (the channels' variances summed would give 14). (The
        // direction-averaged variance: at the sensors' own directions the exact one is at the
        // level of rounding without noise.)
        let mut probe = LayoutProbe::<5, [f32; 3]>::new(&sensors, prior, Noise::NONE).unwrap();
        probe.update(&y.map(|v| [v, 2.0 * v, 3.0 * v])).unwrap();
        let sum = probe.combined([1.0, 1.0, 1.0]).unwrap();
        let one = probe.irradiance(Vec3::Z).unwrap().variance[0];
        let all = sum.irradiance(Vec3::Z).unwrap().variance;
        assert!(one > 0.0 && (all / one - 36.0).abs() < 36.0 * 1e-5, "{}", all / one);
        // Bad weights.
        assert_eq!(probe.combined([f32::NAN, 1.0, 0.0]).unwrap_err(), Error::InvalidParameter);
        assert_eq!(probe.combined([0.0; 3]).unwrap_err(), Error::InvalidParameter);
        let fresh = LayoutProbe::<5, [f32; 3]>::new(&sensors, prior, Noise::NONE).unwrap();
        assert!(!fresh.combined(w).unwrap().is_updated());
    }

    /// Phong and SG lobes against the f64 reference with the lobes' Legendre coefficients
    /// by a midpoint rule.
    #[test]
    fn lobes_agree_with_the_f64_reference() {
        let gains: Vec<f64> =
            Response::CosinePower(1.0).gains().unwrap().iter().map(|&g| f64::from(g)).collect();
        let se = Prior::squared_exponential(6.0).unwrap();
        let mut profile = [0.0f32; 9];
        profile[0] = 1.0;
        profile[1] = 0.7;
        let sensors = dome();
        let y = [2.0f32, 1.2, 1.5, 0.8, 1.1];
        let mut probe =
            LayoutProbe::<5>::new(&sensors, se.with_mean(Mean::Zonal(profile)), Noise::NONE)
                .unwrap();
        probe.update(&y).unwrap();
        let dirs: Vec<[f64; 3]> =
            sensors.iter().map(|s| to64(s.direction.try_normalize().unwrap())).collect();
        let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
        let p64: Vec<f64> = profile.iter().map(|&v| f64::from(v)).collect();
        // q_l = 2π∫ f(t)·P_l(t) dt by a midpoint rule in t.
        let coefficients = |f: &dyn Fn(f64) -> f64| -> Vec<f64> {
            let m = 200_000;
            let mut q = std::vec![0.0f64; DEGREES];
            for i in 0..m {
                let t = -1.0 + 2.0 * (i as f64 + 0.5) / m as f64;
                let (mut p0, mut p1) = (1.0, t);
                let v = f(t) * 2.0 / m as f64 * 2.0 * core::f64::consts::PI;
                q[0] += v;
                q[1] += v * t;
                for (l, ql) in q.iter_mut().enumerate().skip(2) {
                    let p2 = ((2 * l - 1) as f64 * t * p1 - (l - 1) as f64 * p0) / l as f64;
                    *ql += v * p2;
                    p0 = p1;
                    p1 = p2;
                }
            }
            q
        };
        let e = 12.0f64;
        let phong =
            coefficients(&|t: f64| (e + 1.0) / (2.0 * core::f64::consts::PI) * t.max(0.0).powf(e));
        let (mu, a) = (9.0f64, 1.7f64);
        let sg = coefficients(&|t: f64| a * (mu * (t - 1.0)).exp());
        let mut worst = (0.0f64, 0.0f64);
        for axis in [Vec3::Z, Vec3::new(0.5, 0.2, 0.8), Vec3::new(-0.7, 0.1, 0.3)] {
            let r = to64(axis.try_normalize().unwrap());
            let (v, var, _) =
                reference(&dirs, &gains, &se, Some(&p64), &y64, r, None, Some(&phong));
            let est = probe.phong(axis, e as f32).unwrap();
            worst.0 = worst.0.max((f64::from(est.value) - v).abs() / v.abs());
            worst.1 = worst.1.max((f64::from(est.variance) - var).abs() / var);
            let lobe = SphericalGaussian::new(axis, mu as f32, a as f32).unwrap();
            let (v, var, _) = reference(&dirs, &gains, &se, Some(&p64), &y64, r, None, Some(&sg));
            let est = probe.glossy(&lobe).unwrap();
            worst.0 = worst.0.max((f64::from(est.value) - v).abs() / v.abs());
            worst.1 = worst.1.max((f64::from(est.variance) - var).abs() / var);
        }
        assert!(worst.0 < 2e-5 && worst.1 < 2e-5, "value {:e}, variance {:e}", worst.0, worst.1);
        assert_eq!(probe.phong(Vec3::Z, -1.0).err(), Some(Error::InvalidExponent));
        assert_eq!(probe.phong(Vec3::ZERO, 2.0).err(), Some(Error::InvalidDirection));
        let sharp = SphericalGaussian { axis: Vec3::Z, sharpness: 5000.0, amplitude: 1.0 };
        assert_eq!(probe.glossy(&sharp).err(), Some(Error::InvalidSharpness));
    }

    /// With a spectrum of degrees ≤ 2 only, the SH export holds the whole posterior mean: its
    /// irradiance is the probe's.
    #[test]
    fn radiance_sh_holds_the_posterior_mean() {
        let mut spectrum = [0.0f32; DEGREES];
        spectrum[..3].copy_from_slice(&[12.0, 3.0, 1.5]);
        for mean in [Mean::Zero, Mean::Constant] {
            let mut probe = LayoutProbe::<6, [f32; 3]>::new(
                &cube(),
                Prior { spectrum, zonal: [0.0; 3], mean, variance_scale: 1.0 },
                Noise::NONE,
            )
            .unwrap();
            probe
                .update(&[
                    [1.3, 1.0, 0.2],
                    [0.4, 1.1, 0.3],
                    [0.9, 0.9, 0.4],
                    [0.7, 1.0, 0.1],
                    [2.1, 1.4, 0.6],
                    [0.2, 0.5, 0.2],
                ])
                .unwrap();
            let sh = probe.radiance_sh();
            for n in [Vec3::Z, Vec3::new(0.3, -0.8, 0.1), Vec3::new(-1.0, 0.2, -0.4)] {
                let a = probe.irradiance(n).unwrap().value;
                let b = sh.irradiance(n).unwrap();
                for c in 0..3 {
                    assert!((a[c] - b[c]).abs() < 1e-4 * a[c].abs().max(1.0), "{a:?} {b:?}");
                }
            }
        }
    }

    /// A stream of noisy readings of static light: pooling cuts the noise's error; a change
    /// resets; a non-finite reading is refused with the state kept.
    #[test]
    fn a_stream_pools_static_light_and_resets_on_a_change() {
        let eta = 0.05f32;
        let noise = Noise { absolute: 0.0, relative: eta };
        let mut probe = LayoutProbe::<6>::new(&cube(), Prior::ENVIRONMENT, noise).unwrap();
        // A linear sky 1 + 0.6·z + 0.3·x: a cosine sensor reads 1 + (2/3)·(0.6·d_z + 0.3·d_x).
        let light = |d: Vec3| 1.0 + 2.0 / 3.0 * (0.6 * d.z + 0.3 * d.x);
        let exact = cube().map(|s| light(s.direction));
        let truth = |n: Vec3| core::f32::consts::PI * (1.0 + 2.0 / 3.0 * (0.6 * n.z + 0.3 * n.x));
        let normals = [Vec3::Z, Vec3::X, Vec3::new(0.3, -0.5, 0.6), Vec3::new(-0.2, 0.7, -0.5)];
        let mut state = 12345u32;
        let mut gaussian = move || {
            // Sum of 12 uniforms minus 6: close to a standard normal.
            (0..12)
                .map(|_| {
                    state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                    (state >> 8) as f32 / (1u32 << 24) as f32
                })
                .sum::<f32>()
                - 6.0
        };
        // The deviation from the estimate of noise-free readings, which pooling approaches.
        let mut clean = LayoutProbe::<6>::new(&cube(), Prior::ENVIRONMENT, Noise::NONE).unwrap();
        clean.update(&exact).unwrap();
        let error = |p: &LayoutProbe<6>| {
            normals
                .iter()
                .map(|&n| {
                    (p.irradiance(n).unwrap().value - clean.irradiance(n).unwrap().value).abs()
                })
                .sum::<f32>()
        };
        // The noise-free estimate is close to the truth.
        for &n in &normals {
            let e = clean.irradiance(n).unwrap().value;
            assert!((e - truth(n)).abs() < 0.05 * truth(n).abs().max(1.0), "{e} {}", truth(n));
        }
        let (mut first, mut pooled) = (0.0f32, 0.0f32);
        for trial in 0..16 {
            let mut p = probe.clone();
            for k in 0..64 {
                let y = exact.map(|v| v * (1.0 + eta * gaussian()));
                let change = p.accumulate(&y).unwrap();
                if k == 0 {
                    assert_eq!(change, Change::First);
                    first += error(&p);
                } else {
                    assert_ne!(change, Change::Reset, "trial {trial}, update {k}");
                }
            }
            assert!(p.pooled_updates() > 60.0, "{}", p.pooled_updates());
            pooled += error(&p);
        }
        // Measured 0.15 (1/√64 = 0.125).
        assert!(pooled < 0.25 * first, "pooled {pooled}, first {first}");
        // The light dims to a half: a reset.
        probe.accumulate(&exact).unwrap();
        probe.accumulate(&exact).unwrap();
        let before = probe.irradiance(Vec3::Z).unwrap();
        assert_eq!(
            probe.accumulate(&[1.0, f32::NAN, 1.0, 1.0, 1.0, 1.0]),
            Err(Error::InvalidRadiance)
        );
        assert_eq!(probe.irradiance(Vec3::Z).unwrap(), before);
        assert_eq!(probe.accumulate(&exact.map(|v| 0.5 * v)).unwrap(), Change::Reset);
        assert!(probe.last_change_probability() > 0.99 && probe.pooled_updates() < 1.01);
        for h in [0.0, 1.0, f32::NAN] {
            assert!(probe.clone().with_hazard(h).is_err());
        }
    }

    /// A prior with zonal covariances (light from above): values, exact variances, a lobe,
    /// the likelihood and the direction-averaged variance against the f64 reference.
    #[test]
    fn zonal_covariances_agree_with_the_f64_reference() {
        let gains: Vec<f64> =
            Response::CosinePower(1.0).gains().unwrap().iter().map(|&g| f64::from(g)).collect();
        let mut spectrum = Prior::squared_exponential(4.0).unwrap().spectrum;
        spectrum[0] = 1.0;
        spectrum[1] = 1.0;
        spectrum[2] = 1.0;
        let zonal = [0.5, 0.5, 0.33];
        let sensors = dome();
        let y = [2.0f32, 1.2, 1.5, 0.8, 1.1];
        let dirs: Vec<[f64; 3]> =
            sensors.iter().map(|s| to64(s.direction.try_normalize().unwrap())).collect();
        let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
        let mut profile = [0.0f32; 9];
        profile[0] = 1.0;
        profile[1] = 0.8;
        let p64: Vec<f64> = profile.iter().map(|&v| f64::from(v)).collect();
        let e = 12.0f64;
        let phong: Vec<f64> = Response::CosinePower(e as f32)
            .gains()
            .unwrap()
            .iter()
            .map(|&g| f64::from(g))
            .collect();
        let mut worst = [0.0f64; 5];
        for mean in [Mean::Zero, Mean::Zonal(profile)] {
            let prior = Prior { spectrum, zonal, mean, variance_scale: 1.0 };
            let mut probe = LayoutProbe::<5>::new(&sensors, prior, Noise::NONE).unwrap();
            probe.update(&y).unwrap();
            let zonal_mean = if mean == Mean::Zero { None } else { Some(&p64[..]) };
            for n in [Vec3::Z, Vec3::new(0.5, 0.2, 0.8), Vec3::new(-0.7, 0.1, 0.3), Vec3::X] {
                let r = to64(n.try_normalize().unwrap());
                let (v, var, ll) =
                    reference(&dirs, &gains, &prior, zonal_mean, &y64, r, None, None);
                let est = probe.irradiance(n).unwrap();
                worst[0] = worst[0].max((f64::from(est.value) - v).abs() / 2.0);
                // (At +z the zenith sensor reads the irradiance itself: no variance.)
                worst[1] = worst[1].max(
                    (f64::from(probe.irradiance_variance(n).unwrap()) - var).abs() / var.max(1e-3),
                );
                worst[2] = worst[2].max((f64::from(probe.log_likelihood()) - ll).abs());
                let (v, var, _) =
                    reference(&dirs, &gains, &prior, zonal_mean, &y64, r, None, Some(&phong));
                let est = probe.phong(n, e as f32).unwrap();
                worst[3] = worst[3].max((f64::from(est.value) - v).abs() / v.abs());
                worst[3] = worst[3].max((f64::from(est.variance) - var).abs() / var);
            }
            // The O(1) variance: the mean of the exact ones over a Fibonacci sphere.
            let m = 4000;
            let mut sum = 0.0f64;
            for i in 0..m {
                let z = 1.0 - (2 * i + 1) as f32 / m as f32;
                let rr = libm::sqrtf(1.0 - z * z);
                let phi = i as f32 * 2.399_963;
                let n = Vec3::new(rr * libm::cosf(phi), rr * libm::sinf(phi), z);
                sum += f64::from(probe.irradiance_variance(n).unwrap()) / f64::from(m);
            }
            let average = f64::from(probe.irradiance(Vec3::Z).unwrap().variance);
            worst[4] = worst[4].max((average - sum).abs() / sum);
        }
        assert!(
            worst[0] < 1e-5
                && worst[1] < 5e-4
                && worst[2] < 1e-4
                && worst[3] < 1e-4
                && worst[4] < 1e-2,
            "{worst:?}"
        );
        // Zonal covariances beyond the diagonal's reach: not positive semi-definite.
        let bad = Prior { spectrum, zonal: [1.5, 0.0, 0.0], mean: Mean::Zero, variance_scale: 1.0 };
        assert_eq!(
            LayoutProbe::<5>::new(&sensors, bad, Noise::NONE).err(),
            Some(Error::InvalidParameter)
        );
        let nan =
            Prior { spectrum, zonal: [f32::NAN, 0.0, 0.0], mean: Mean::Zero, variance_scale: 1.0 };
        assert_eq!(
            LayoutProbe::<5>::new(&sensors, nan, Noise::NONE).err(),
            Some(Error::InvalidParameter)
        );
    }

    /// The O(1) variance is the direction average of the exact one.
    #[test]
    fn average_variance_is_the_mean_of_the_exact_ones() {
        let mut profile = [0.0f32; 9];
        profile[0] = 1.0;
        profile[1] = 0.8;
        for (prior, noise) in [
            (Prior::squared_exponential(3.0).unwrap().with_mean(Mean::Zero), Noise::NONE),
            (
                Prior::squared_exponential(3.0).unwrap().with_mean(Mean::Zonal(profile)),
                Noise { absolute: 0.05, relative: 0.02 },
            ),
        ] {
            let mut probe = LayoutProbe::<5, [f32; 3]>::new(&dome(), prior, noise).unwrap();
            probe
                .update(&[
                    [2.0, 1.0, 0.5],
                    [1.2, 0.9, 0.4],
                    [1.5, 1.1, 0.6],
                    [0.8, 1.0, 0.5],
                    [1.1, 0.7, 0.3],
                ])
                .unwrap();
            let n = 4000;
            let mut sum = [0.0f64; 3];
            for i in 0..n {
                // A spherical Fibonacci set.
                let z = 1.0 - (2 * i + 1) as f32 / n as f32;
                let r = libm::sqrtf(1.0 - z * z);
                let phi = i as f32 * 2.399_963;
                let v = probe
                    .irradiance_variance(Vec3::new(r * libm::cosf(phi), r * libm::sinf(phi), z))
                    .unwrap();
                for c in 0..3 {
                    sum[c] += f64::from(v[c]) / n as f64;
                }
            }
            let average = probe.irradiance(Vec3::Z).unwrap().variance;
            for c in 0..3 {
                let rel = (f64::from(average[c]) - sum[c]).abs() / sum[c];
                assert!(rel < 1e-2, "channel {c}: {} vs {}", average[c], sum[c]);
            }
        }
    }

    #[test]
    fn bad_input_is_an_error_and_keeps_the_state() {
        let prior = Prior::squared_exponential(2.0).unwrap();
        let mut probe = LayoutProbe::<6>::new(&cube(), prior, Noise::NONE).unwrap();
        probe.update(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
        let before = probe.irradiance(Vec3::Z).unwrap();
        assert_eq!(probe.update(&[1.0, f32::NAN, 3.0, 4.0, 5.0, 6.0]), Err(Error::InvalidRadiance));
        assert_eq!(
            probe.update(&[1.0, 2.0, f32::INFINITY, 4.0, 5.0, 6.0]),
            Err(Error::InvalidRadiance)
        );
        assert_eq!(probe.irradiance(Vec3::Z).unwrap(), before);
        assert_eq!(probe.irradiance(Vec3::ZERO), Err(Error::InvalidDirection));
        assert_eq!(probe.irradiance(Vec3::new(f32::NAN, 0.0, 1.0)), Err(Error::InvalidDirection));
        let mut s = cube();
        s[2].direction = Vec3::new(f32::NAN, 0.0, 0.0);
        assert_eq!(
            LayoutProbe::<6>::new(&s, prior, Noise::NONE).err(),
            Some(Error::InvalidDirection)
        );
        let mut s = cube();
        s[2].noise_scale = 0.0;
        assert_eq!(
            LayoutProbe::<6>::new(&s, prior, Noise::NONE).err(),
            Some(Error::InvalidParameter)
        );
        let mut s = cube();
        s[2].response = Response::CosinePower(f32::NAN);
        assert_eq!(
            LayoutProbe::<6>::new(&s, prior, Noise::NONE).err(),
            Some(Error::InvalidParameter)
        );
        let bad_noise = Noise { absolute: -1.0, relative: 0.0 };
        assert_eq!(
            LayoutProbe::<6>::new(&cube(), prior, bad_noise).err(),
            Some(Error::InvalidParameter)
        );
        // Five distinct responses, one more than MAX_RESPONSES.
        let mut s = cube();
        for (i, sensor) in s.iter_mut().enumerate().take(5) {
            sensor.response = Response::CosinePower(1.0 + i as f32);
        }
        assert_eq!(
            LayoutProbe::<6>::new(&s, prior, Noise::NONE).err(),
            Some(Error::InvalidParameter)
        );
        // More than MAX_SENSORS.
        let many = [Sensor::cosine(Vec3::Z); MAX_SENSORS + 1];
        assert_eq!(
            LayoutProbe::<{ MAX_SENSORS + 1 }>::new(&many, prior, Noise::NONE).err(),
            Some(Error::InvalidSize)
        );
        // One sensor cannot fit a constant mean.
        assert_eq!(
            LayoutProbe::<1>::new(&[Sensor::cosine(Vec3::Z)], prior, Noise::NONE).err(),
            Some(Error::InvalidSize)
        );
    }

    /// Duplicate sensors and antipodal cosine pairs make the system singular; the model's
    /// least noise keeps it solvable, with and without a noise of the layout.
    #[test]
    fn dependent_readings_are_solvable() {
        let prior = Prior::squared_exponential(4.0).unwrap();
        let mut s = cube();
        s[1] = s[0];
        for noise in [Noise::NONE, Noise { absolute: 0.01, relative: 0.0 }] {
            let mut probe = LayoutProbe::<6>::new(&s, prior, noise).unwrap();
            // Consistent duplicate readings.
            probe.update(&[1.5, 1.5, 0.9, 0.7, 2.1, 0.2]).unwrap();
            let e = probe.irradiance(Vec3::X).unwrap();
            assert!(e.value.is_finite() && e.variance >= 0.0 && e.variance.is_finite());
            // The duplicate pair reads 1.5 each; the estimate near +x is near π·1.5.
            assert!((e.value / core::f32::consts::PI - 1.5).abs() < 0.3, "{}", e.value);
        }
    }

    /// Readings scaled by a power of two scale the answers exactly.
    #[test]
    fn scale_invariance() {
        let prior = Prior::squared_exponential(4.0).unwrap();
        let y = [1.3f32, 0.4, 0.9, 0.7, 2.1, 0.2];
        let mut a =
            LayoutProbe::<6>::new(&cube(), prior, Noise { absolute: 0.0, relative: 0.05 }).unwrap();
        let mut b = a.clone();
        a.update(&y).unwrap();
        b.update(&y.map(|v| v * 1024.0)).unwrap();
        let (ea, eb) = (a.irradiance(Vec3::Z).unwrap(), b.irradiance(Vec3::Z).unwrap());
        assert_eq!(ea.value * 1024.0, eb.value);
        assert_eq!(ea.variance * 1024.0 * 1024.0, eb.variance);
    }
}
