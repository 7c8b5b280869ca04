//! Spherical Gaussians (SGs) and their hemispherical integrals.
//!
//! An SG is `G(v) = a·exp(λ(μ·v − 1))` with unit axis `μ`, sharpness `λ ≥ 0` and amplitude `a`
//! (Wang et al. 2009, "All-frequency rendering of dynamic, spatially-varying reflectance").
//!
//! ```
//! use sphere_quadrature::sg::{self, SphericalGaussian};
//! use sphere_quadrature::Vec3;
//!
//! // An SG light 37° from the zenith, and its irradiance on an upward normal.
//! let light = SphericalGaussian::new(Vec3::new(0.0, 0.6, 0.8), 50.0, 3.0)?;
//! let e = light.clamped_cosine_integral(Vec3::Z)?;
//! // Far above the horizon, C ≈ t·L(λ)·F with L(λ) = coth λ − 1/λ, the lobe's mean cosine.
//! let mean_cosine = 0.8 * (1.0 - 1.0 / 50.0);
//! assert!((e / (mean_cosine * light.integral()) - 1.0).abs() < 1e-5);
//! // The same through the normalised functions: C/F and H/F.
//! let c = sg::clamped_cosine_fraction(50.0, 0.8)?;
//! assert!((c * light.integral() - e).abs() < 1e-6 * e);
//! assert!(sg::hemispherical_fraction(50.0, 0.8)? > 0.999);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Algebra (exact)
//! - Full-sphere integral: `∫ G = 2πa(1 − e^(−2λ))/λ = −2πa·expm1(−2λ)/λ` (`4πa` at `λ = 0`).
//! - Product: with `u = λ₁μ₁ + λ₂μ₂`, `λₘ = |u|`, `μₘ = u/λₘ` and
//!   `aₘ = a₁a₂·exp(λₘ − λ₁ − λ₂)`, where the exponent is formed without cancellation as
//!   `−λ₁λ₂|μ₁ − μ₂|²/(λₘ + λ₁ + λ₂)` (Tokuyoshi's stable form).
//! - Inner product: `∫ G₁G₂` = the full-sphere integral of the product.
//! - Rotation: rotate the axis.
//!
//! # Hemispherical integrals (tables baked at build time)
//! Over the hemisphere `{v : n·v ≥ 0}`, with `t = μ·n`, a unit SG has
//! `H(λ, t) = 2π e^(−λ) ∫₀¹ e^(λtu) I₀(λ√(1−t²)√(1−u²)) du` and, weighted by the clamped cosine
//! `max(0, n·v)`, `C(λ, t) = 2π e^(−λ) ∫₀¹ u·e^(λtu) I₀(…) du`. Neither has a closed form. This
//! module returns them normalised by the full-sphere integral `F(λ)`:
//! [`hemispherical_fraction`] `= H/F ∈ [0, 1]` and [`clamped_cosine_fraction`] `= C/F`.
//!
//! `build.rs` bakes two f32 tables in f64 (generator `gen/sg.rs`, sizes in `tables/sg.txt`),
//! 16 256 bytes together, on `x = √λ/(√λ + c_λ)` (the last row is `λ = ∞`, so every finite
//! `λ` is inside the table) and a horizon coordinate `y = t·√((1 + k²)/(1 + k²t²))`,
//! `k = c_h·√λ`, that follows the `~1/√λ` width of the horizon transition. What is stored
//! takes the exactly known parts out:
//! - `H/F = 1/2 + sign(t)·R(λ, |t|)·tanh(λ/2)/2`, with `R` tabulated (`R = 1` at the pole);
//! - `C/F = Z(λ, |t|) + max(t, 0)·L(λ)`, with `L(λ) = coth λ − 1/λ` (then
//!   `C(t) − C(−t) = t·F·L` holds exactly) and `Z` tabulated.
//!
//! Lookups are bicubic (4 × 4 Lagrange stencils, shifted inwards at the edges). The poles
//! `t = ±1` (`H = 2π(1 − e^(−λ))/λ` above, `2π e^(−λ)(1 − e^(−λ))/λ` below, and the matching
//! `C`) and `λ = 0` (`H = 2π`, `C = π`) take an exact path.
//!
//! # Accuracy
//! Measured by `tests/bmc/sg.rs` against the reference crate's adaptive Gauss–Kronrod quadrature
//! of the defining integral, on a dense grid and 10⁵ random `(λ, t)` with `λ` up to 10⁴ and
//! beyond: max absolute error of `H/F` 1.1·10⁻⁵ and of `C/F` 5·10⁻⁶ (`libm`). For comparison
//! the closed forms, on the same points: Tokuyoshi 2022 (`H`) 4.9·10⁻³, Meder & Brüderlin 2018
//! (`H`) 1.2·10⁻², Tokuyoshi et al. 2024 (`C`) 1.3·10⁻³. The repository's guide has the table per λ decade.
//!
//! # Fits
//! [`SphericalGaussian::phong_lobe`] fits the normalised Phong lobe `(e+1)/(2π)·max(0, cos θ)ᵉ`
//! with `λ = e + 1` (the least-squares optimum over the sphere is within 0.15 of it for every
//! `e ≥ 1`) and the amplitude that gives the SG unit integral (energy-preserving). Relative L²
//! error `‖P − G‖/‖P‖`: 21 % at `e = 1`, 6.3 % at 5, 0.70 % at 50, ≈ 0.35/e above.
//! [`SphericalGaussian::phong_moments`] instead matches the lobe's first Legendre moment
//! (`λ = e + 2`): the better stand-in when integrating smooth lighting (probe glossy queries).
//! [`SphericalGaussian::clamped_cosine`] is the least-squares fit of `max(0, n·v)`:
//! `λ = 2.1438`, `a = 1.1766`, relative L² error 17.7 %.
//!
//! # Bad input
//! Negative, NaN or infinite sharpness gives [`Error::InvalidSharpness`]; a zero, NaN or
//! infinite direction (or a NaN cosine) gives [`Error::InvalidDirection`]. Cosines outside
//! `[−1, 1]` are clamped. The plain-data methods ([`SphericalGaussian::evaluate`],
//! [`SphericalGaussian::product`], …) do not check and propagate NaN.
//!
//!
//! # Cost
//! Instructions per call and flash on a Cortex-M4F: [`costs`](crate::costs#spherical-gaussians).

use core::f64::consts::PI as PI64;

use crate::error::Error;
use crate::math;
use crate::rotation::Mat3;
use crate::tables::{
    SG_CLAMPED, SG_CLAMPED_LAMBDA_NODES, SG_CLAMPED_T_NODES, SG_HEMI, SG_HEMI_LAMBDA_NODES,
    SG_HEMI_T_NODES, SG_HORIZON_SCALE, SG_LAMBDA_SCALE,
};
use crate::vec3::Vec3;

const TWO_PI: f32 = 2.0 * core::f32::consts::PI;

/// Bytes of the two baked tables together (pinned by `tests/bmc/sg_tables.rs`).
pub const TABLE_BYTES: usize =
    core::mem::size_of::<[f32; SG_HEMI_LAMBDA_NODES * SG_HEMI_T_NODES]>()
        + core::mem::size_of::<[f32; SG_CLAMPED_LAMBDA_NODES * SG_CLAMPED_T_NODES]>();

/// The baked tables `(R, Z)`, row-major with λ rows (see the module docs and `gen/sg.rs`),
/// for the bit-exactness test. Internal: hidden, outside the semver contract.
#[doc(hidden)]
#[must_use]
pub fn tables() -> (&'static [f32], &'static [f32]) {
    (&SG_HEMI, &SG_CLAMPED)
}

/// A spherical Gaussian `a·exp(λ(μ·v − 1))`.
///
/// # Examples
/// ```
/// use sphere_quadrature::{sg::SphericalGaussian, Vec3};
///
/// let g = SphericalGaussian::new(Vec3::new(0.0, 0.0, 2.0), 4.0, 3.0)?;
/// assert!((g.axis.length() - 1.0).abs() < 1e-6); // the axis is normalised
/// assert!((g.evaluate(Vec3::Z) - 3.0).abs() < 1e-6); // the amplitude on the axis
/// // Full-sphere integral 2π·a·(1 − e^(−2λ))/λ.
/// let exact = 2.0 * core::f32::consts::PI * 3.0 * (1.0 - (-8.0f32).exp()) / 4.0;
/// assert!((g.integral() - exact).abs() < 1e-4 * exact);
/// // The normalised Phong fit integrates to 1; the hemisphere above the axis holds most of it.
/// let lobe = SphericalGaussian::phong_lobe(Vec3::Z, 20.0)?;
/// assert!((lobe.integral() - 1.0).abs() < 1e-5);
/// let h = lobe.hemispherical_integral(Vec3::Z)?;
/// assert!(h > 0.99 && h <= 1.0 + 1e-5);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SphericalGaussian {
    /// Lobe axis `μ` (unit length).
    pub axis: Vec3,
    /// Sharpness `λ ≥ 0`.
    pub sharpness: f32,
    /// Amplitude `a` (the value on the axis).
    pub amplitude: f32,
}

impl SphericalGaussian {
    /// An SG; the axis is normalised.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite axis (crate docs, "Directions");
    /// [`Error::InvalidSharpness`] for a negative, NaN or infinite sharpness.
    pub fn new(axis: Vec3, sharpness: f32, amplitude: f32) -> Result<Self, Error> {
        let axis = axis.try_normalize().ok_or(Error::InvalidDirection)?;
        check_sharpness(sharpness)?;
        Ok(Self { axis, sharpness, amplitude })
    }

    /// The fit of the normalised Phong lobe `(e+1)/(2π)·max(0, μ·v)ᵉ`: `λ = e + 1` and unit
    /// integral. Relative L² error 21 % at `e = 1`, 6.3 % at `e = 5`, ≈ 0.35/e for large `e`
    /// (module docs).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a bad axis; [`Error::InvalidExponent`] for a negative,
    /// NaN or infinite exponent.
    pub fn phong_lobe(axis: Vec3, e: f32) -> Result<Self, Error> {
        if !(e >= 0.0 && e.is_finite()) {
            return Err(Error::InvalidExponent);
        }
        let lambda = e + 1.0;
        Self::new(axis, lambda, 1.0 / full_integral_unchecked(lambda))
    }

    /// The SG with the normalised Phong lobe's integral (1) and first Legendre moment
    /// `∫ lobe·(μ·v) = (e+1)/(e+2)`: `λ = e + 2` (its moment `coth λ − 1/λ` is off by
    /// `≈ 2e^(−2λ)`, 1.7·10⁻⁶ at `e = 5`); its second moment is then within `O(1/e³)` (0.6327
    /// against Phong's 0.625 at `e = 5`; at `e = 1` it is 0.328 against 0.25, worse than
    /// [`Self::phong_lobe`]'s 0.194).
    /// Integrating *smooth* lighting, what matters is the low Legendre moments, not the
    /// pointwise fit: on the `smooth` maps of `eval/src/bin/glossy.rs` (held-out means) the probe's
    /// glossy error at `e = 5` is 1.3 % (N = 64) and 1.1 % (N = 256) with this lobe, against
    /// 2.5 % and 2.4 % with [`Self::phong_lobe`].
    ///
    /// # Errors
    /// As [`Self::phong_lobe`].
    pub fn phong_moments(axis: Vec3, e: f32) -> Result<Self, Error> {
        if !(e >= 0.0 && e.is_finite()) {
            return Err(Error::InvalidExponent);
        }
        let lambda = e + 2.0;
        Self::new(axis, lambda, 1.0 / full_integral_unchecked(lambda))
    }

    /// The least-squares SG fit of the clamped cosine `max(0, n·v)` over the sphere:
    /// `λ = 2.1438`, `a = 1.1766` (relative L² error 17.7 %).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a bad normal.
    pub fn clamped_cosine(n: Vec3) -> Result<Self, Error> {
        Self::new(n, CLAMPED_COSINE_SHARPNESS, CLAMPED_COSINE_AMPLITUDE)
    }

    /// `G(v)` for a unit `v`, as `a·exp(−λ|v − μ|²/2)` (accurate near the axis).
    #[inline]
    #[must_use]
    pub fn evaluate(&self, v: Vec3) -> f32 {
        let d = v - self.axis;
        self.amplitude * math::exp(-0.5 * self.sharpness * d.length_squared())
    }

    /// The SG equal to the pointwise product `G₁·G₂`: axis `u/|u|` and sharpness `|u|` with
    /// `u = λ₁μ₁ + λ₂μ₂`, amplitude `a₁a₂·exp(−λ₁λ₂|μ₁ − μ₂|²/(|u| + λ₁ + λ₂))`.
    ///
    /// Computed with both sharpnesses divided by the larger one, so any finite sharpnesses
    /// work (10¹⁹ does not overflow `|u|²`, 10⁻⁴⁴ does not underflow it): the axis is unit to
    /// f32 rounding. Where `u` nearly cancels (nearly opposite lobes of equal sharpness) and
    /// `|u|²` would be below the normal range, `|u|` is taken after scaling: the sharpness is
    /// `|u|` to f32 rounding however small (`6·10⁻²²`, not 0 or `6.001·10⁻²²`). Axes are taken
    /// as given (unit, as [`Self::new`] makes them). A zero `u` (both sharpnesses 0, or equal
    /// sharpnesses on opposite axes) keeps `self`'s axis with sharpness 0; NaN propagates.
    ///
    /// The amplitude is the true one rounded to f32 (up to the rounding of the exponent): finite
    /// amplitudes give a finite result or 0 wherever the true value is within f32, and ±∞ only
    /// where it is beyond (two aligned lobes of amplitude 10²⁰: ∞; opposite ones of sharpness
    /// 500: 10⁴⁰·e⁻¹⁰⁰⁰ = 0, not ∞·0 = NaN; `a₁a₂ = 10³⁰` with `e⁻¹²⁰`: 7.7·10⁻²³, not 0).
    /// Where `a₁a₂` overflows f32 or the exponential leaves the normal range, it is formed in
    /// f64 (a cold path; the common one is the f32 expression). A non-finite amplitude
    /// propagates as in the f32 product.
    #[must_use]
    pub fn product(&self, other: &Self) -> Self {
        let (l1, l2) = (self.sharpness, other.sharpness);
        let m = if l1 >= l2 { l1 } else { l2 };
        let a = self.amplitude * other.amplitude;
        if l1 == 0.0 && l2 == 0.0 {
            return Self { axis: self.axis, sharpness: 0.0, amplitude: a };
        }
        // λᵢ/m ≤ 1 (NaN for a NaN or infinite sharpness, which then propagates).
        let (s1, s2) = (l1 / m, l2 / m);
        let v = self.axis * s1 + other.axis * s2;
        // |v| of nearly opposite lobes of equal sharpness (v cancels): below the normal range
        // |v|² loses its relative precision (or is 0), so |v| is then taken after scaling.
        let len = v.length_precise();
        let (axis, sharpness) = match v.try_normalize() {
            Some(axis) => {
                // |v| = 1 + O(ε) when one lobe dominates: rounding must not take a sharpness
                // near f32::MAX to +∞. A true sharpness above f32::MAX (two sharp, nearly
                // aligned lobes) is +∞.
                let l = m * len;
                let rounding = l.is_infinite() && m.is_finite() && len <= 1.0 + 4.0 * f32::EPSILON;
                (axis, if rounding { f32::MAX } else { l })
            }
            None if v.is_finite() => (self.axis, 0.0),
            None => (self.axis, f32::NAN),
        };
        // λ₁λ₂|d|²/(|u| + λ₁ + λ₂) = (λₛ/(|v| + 1 + sₛ))·|d|² with λₛ the smaller sharpness
        // and sₛ = λₛ/m: every factor bounded, the same operations in either order, and an
        // sₛ below f32's range harmless (it is added to at least 1; as a factor it would take
        // the whole exponent with it).
        let d = self.axis - other.axis;
        let (small, s_small) = if l1 >= l2 { (l2, s2) } else { (l1, s1) };
        let log_a = -(small / (len + 1.0 + s_small)) * d.length_squared();
        let e = math::exp(log_a);
        let amplitude = a * e;
        // a₁a₂ beyond f32 (∞, and ∞·0 = NaN when e underflows), or e below the normal range
        // (a subnormal or 0 factor where a₁a₂ is large): the product again in f64.
        let amplitude = if amplitude.is_finite() && e >= f32::MIN_POSITIVE {
            amplitude
        } else {
            amplitude_wide(self.amplitude, other.amplitude, log_a)
        };
        Self { axis, sharpness, amplitude }
    }

    /// `∫_S² G = 2πa(1 − e^(−2λ))/λ` (exact; `4πa` at `λ = 0`).
    #[inline]
    #[must_use]
    pub fn integral(&self) -> f32 {
        self.amplitude * full_integral_unchecked(self.sharpness)
    }

    /// `∫_S² G₁·G₂`, exactly (the integral of [`Self::product`]).
    ///
    /// The true value rounded to f32 for any finite SGs: finite wherever it is within f32,
    /// ±∞ only beyond, never NaN, also where the product itself leaves f32 (`a₁a₂` or
    /// `λₘ` beyond f32::MAX, whose ∞ then met a small or zero factor: `∞·0 = NaN` for two
    /// lobes of sharpness near f32::MAX and amplitudes 10³⁰). Those cases (a non-finite f32
    /// result) are recomputed in f64; the common path is the f32 product's integral.
    #[must_use]
    pub fn inner_product(&self, other: &Self) -> f32 {
        let r = self.product(other).integral();
        if r.is_finite() {
            r
        } else {
            inner_product_wide(self, other)
        }
    }

    /// The SG rotated by `m`: `G′(v) = G(mᵀv)`.
    #[inline]
    #[must_use]
    pub fn rotated(&self, m: &Mat3) -> Self {
        Self { axis: m * self.axis, ..*self }
    }

    /// `∫ G(v) dv` over the hemisphere `{v : n·v ≥ 0}` (table lookup).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a bad `n`; [`Error::InvalidSharpness`] for a bad
    /// sharpness.
    pub fn hemispherical_integral(&self, n: Vec3) -> Result<f32, Error> {
        let t = self.cosine_to(n)?;
        Ok(self.amplitude * hemispherical_integral(self.sharpness, t)?)
    }

    /// `∫ G(v)·max(0, n·v) dv` (table lookup): the irradiance from an SG light on normal `n`.
    ///
    /// # Errors
    /// As [`Self::hemispherical_integral`].
    pub fn clamped_cosine_integral(&self, n: Vec3) -> Result<f32, Error> {
        let t = self.cosine_to(n)?;
        Ok(self.amplitude * clamped_cosine_integral(self.sharpness, t)?)
    }

    fn cosine_to(&self, n: Vec3) -> Result<f32, Error> {
        let n = n.try_normalize().ok_or(Error::InvalidDirection)?;
        let t = self.axis.dot(n);
        if t.is_nan() {
            return Err(Error::InvalidDirection);
        }
        Ok(t)
    }
}

/// `a₁a₂·e^x` in f64, rounded once to f32: finite or 0 where the true value is, ±∞ only
/// beyond f32 (`a₁a₂` of f32s is exact in f64, and where `e^x` underflows f64 the result is
/// below f32's range too). Non-finite amplitudes give what the f32 product gives.
#[cold]
#[inline(never)]
fn amplitude_wide(a1: f32, a2: f32, x: f32) -> f32 {
    (f64::from(a1) * f64::from(a2) * math::exp64(f64::from(x))) as f32
}

/// [`SphericalGaussian::inner_product`] in f64, rounded once: `a₁a₂·e^x·F(λₘ)` with the
/// product's `λₘ = |λ₁μ₁ + λ₂μ₂|` and `x = −λ₁λ₂|μ₁ − μ₂|²/(λₘ + λ₁ + λ₂)` (every term is
/// within f64 for f32 inputs); NaN and non-finite inputs propagate.
#[cold]
#[inline(never)]
fn inner_product_wide(g1: &SphericalGaussian, g2: &SphericalGaussian) -> f32 {
    let (l1, l2) = (f64::from(g1.sharpness), f64::from(g2.sharpness));
    let m1 = [g1.axis.x, g1.axis.y, g1.axis.z].map(f64::from);
    let m2 = [g2.axis.x, g2.axis.y, g2.axis.z].map(f64::from);
    let (mut u2, mut d2) = (0.0, 0.0);
    for (a, b) in m1.into_iter().zip(m2) {
        let (u, d) = (l1 * a + l2 * b, a - b);
        u2 += u * u;
        d2 += d * d;
    }
    let lm = math::sqrt64(u2);
    let x = if l1 == 0.0 && l2 == 0.0 { 0.0 } else { -l1 * l2 * d2 / (lm + l1 + l2) };
    let full = if lm < 1e-4 {
        4.0 * PI64 * (1.0 - lm * (1.0 - lm * (2.0 / 3.0)))
    } else {
        2.0 * PI64 * (1.0 - math::exp64(-2.0 * lm)) / lm
    };
    (f64::from(g1.amplitude) * f64::from(g2.amplitude) * math::exp64(x) * full) as f32
}

/// Least-squares SG sharpness for the clamped cosine (re-derived by `tests/bmc/sg.rs`).
const CLAMPED_COSINE_SHARPNESS: f32 = 2.143_77;
/// Least-squares SG amplitude for the clamped cosine (re-derived by `tests/bmc/sg.rs`).
const CLAMPED_COSINE_AMPLITUDE: f32 = 1.176_64;

fn check_sharpness(lambda: f32) -> Result<(), Error> {
    if lambda >= 0.0 && lambda.is_finite() {
        Ok(())
    } else {
        Err(Error::InvalidSharpness)
    }
}

fn check_cosine(t: f32) -> Result<f32, Error> {
    if t.is_nan() {
        Err(Error::InvalidDirection)
    } else {
        Ok(math::clamp_unit(t))
    }
}

/// `F(λ) = 2π(1 − e^(−2λ))/λ`; below `λ = 10⁻⁴` the series `4π(1 − λ + 2λ²/3)` (next term
/// `−λ³/3`, below 4·10⁻¹³ relative there): the closed form divides two products that, for a
/// subnormal λ, keep only a few bits (it gave 13.0 for 4π at λ = 10⁻⁴⁵).
pub(crate) fn full_integral_unchecked(lambda: f32) -> f32 {
    if lambda < 1e-4 {
        // Also λ = 0: 4π exactly.
        2.0 * TWO_PI * (1.0 - lambda * (1.0 - lambda * (2.0 / 3.0)))
    } else {
        -TWO_PI * math::expm1(-2.0 * lambda) / lambda
    }
}

/// `F(λ) = ∫_S² exp(λ(μ·v − 1)) dv = 2π(1 − e^(−2λ))/λ` (`4π` at `λ = 0`), exact: below
/// `λ = 10⁻⁴` from the series `4π(1 − λ + 2λ²/3 − …)`, so tiny and subnormal `λ` give `4π`.
///
/// # Errors
/// [`Error::InvalidSharpness`] for a negative, NaN or infinite `lambda`.
pub fn full_integral(lambda: f32) -> Result<f32, Error> {
    check_sharpness(lambda)?;
    Ok(full_integral_unchecked(lambda))
}

/// `H/F`: the fraction of a unit SG's integral that lies in the hemisphere of a normal at
/// cosine `t` from its axis, in `[0, 1]`; `1/(1 + e^(−λ))` at `t = 1`, `1/2` at `λ = 0` or
/// `t = 0`, and `H(t) + H(−t) = F`.
///
/// # Errors
/// [`Error::InvalidSharpness`] for a negative, NaN or infinite `lambda`;
/// [`Error::InvalidDirection`] for a NaN `t` (`t` is clamped to `[−1, 1]`).
///
/// # Examples
/// ```
/// use sphere_quadrature::sg::hemispherical_fraction;
///
/// // A lobe on the horizon is cut in half; H(t) + H(−t) = F.
/// assert!((hemispherical_fraction(5.0, 0.0)? - 0.5).abs() < 1e-6);
/// let (up, down) = (hemispherical_fraction(5.0, 0.4)?, hemispherical_fraction(5.0, -0.4)?);
/// assert!((up + down - 1.0).abs() < 1e-5 && up > 0.5);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
pub fn hemispherical_fraction(lambda: f32, t: f32) -> Result<f32, Error> {
    check_sharpness(lambda)?;
    let t = check_cosine(t)?;
    Ok(hemi_fraction_unchecked(lambda, t))
}

/// `C/F`: the clamped-cosine integral `∫ G·max(0, n·v)` of a unit SG at cosine `t` between
/// its axis and `n`, divided by `F(λ)`; `1/4` at `λ = 0`, and `C(t) − C(−t) = t·F·L(λ)`.
///
/// # Errors
/// As [`hemispherical_fraction`].
///
/// # Examples
/// ```
/// use sphere_quadrature::sg::clamped_cosine_fraction;
///
/// // A constant (λ = 0) gives ∫ max(0, n·v) / 4π = π/4π = 1/4 for every normal.
/// assert!((clamped_cosine_fraction(0.0, 0.3)? - 0.25).abs() < 1e-6);
/// // More of the lobe faces the normal as the axis turns towards it.
/// assert!(clamped_cosine_fraction(8.0, 0.9)? > clamped_cosine_fraction(8.0, 0.1)?);
/// assert!(clamped_cosine_fraction(-1.0, 0.5).is_err());
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
pub fn clamped_cosine_fraction(lambda: f32, t: f32) -> Result<f32, Error> {
    check_sharpness(lambda)?;
    let t = check_cosine(t)?;
    Ok(clamped_fraction_unchecked(lambda, t))
}

/// `H(λ, t) = ∫_{n·v ≥ 0} exp(λ(μ·v − 1)) dv` with `t = μ·n`.
///
/// # Errors
/// As [`hemispherical_fraction`].
pub fn hemispherical_integral(lambda: f32, t: f32) -> Result<f32, Error> {
    Ok(hemispherical_fraction(lambda, t)? * full_integral_unchecked(lambda))
}

/// `C(λ, t) = ∫ exp(λ(μ·v − 1))·max(0, n·v) dv` with `t = μ·n`.
///
/// # Errors
/// As [`hemispherical_fraction`].
pub fn clamped_cosine_integral(lambda: f32, t: f32) -> Result<f32, Error> {
    Ok(clamped_cosine_fraction(lambda, t)? * full_integral_unchecked(lambda))
}

#[inline]
fn hemi_fraction_unchecked(lambda: f32, t: f32) -> f32 {
    if lambda == 0.0 {
        return 0.5;
    }
    let em = -math::expm1(-lambda); // 1 − e^(−λ)
    let half_tanh = 0.5 * em / (2.0 - em); // tanh(λ/2)/2
    let a = math::abs(t);
    let r = if a == 1.0 {
        1.0 // exact path: H/F = 1/(1 + e^(∓λ)) at the poles
    } else {
        let (x, y) = coords(lambda, a);
        interpolate::<{ SG_HEMI_LAMBDA_NODES }, { SG_HEMI_T_NODES }>(&SG_HEMI, x, y)
    };
    (0.5 + math::copysign(r * half_tanh, t)).clamp(0.0, 1.0)
}

#[inline]
fn clamped_fraction_unchecked(lambda: f32, t: f32) -> f32 {
    if lambda == 0.0 {
        return 0.25;
    }
    let em = -math::expm1(-lambda); // 1 − e^(−λ)
    let a = math::abs(t);
    let z = if a == 1.0 {
        lower_pole_fraction(lambda, em) // exact path
    } else {
        let (x, y) = coords(lambda, a);
        interpolate::<{ SG_CLAMPED_LAMBDA_NODES }, { SG_CLAMPED_T_NODES }>(&SG_CLAMPED, x, y)
    };
    (z + t.max(0.0) * langevin(lambda, em)).max(0.0)
}

/// Langevin function `L(λ) = coth λ − 1/λ` given `em = 1 − e^(−λ)`; series below 0.5.
#[inline]
fn langevin(lambda: f32, em: f32) -> f32 {
    if lambda < 0.5 {
        let l2 = lambda * lambda;
        lambda
            * (1.0 / 3.0
                - l2 * (1.0 / 45.0
                    - l2 * (2.0 / 945.0 - l2 * (1.0 / 4725.0 - l2 * (2.0 / 93555.0)))))
    } else {
        let e = 1.0 - em;
        (1.0 + e * e) / (em * (2.0 - em)) - 1.0 / lambda
    }
}

/// `C(λ, −1)/F = e^(−λ)·λ·g(λ)/(1 − e^(−2λ))` with `g(z) = (1 − e^(−z)(1 + z))/z²`: the exact
/// clamped-cosine integral with the axis at the nadir (`Z` at `t = 1`).
fn lower_pole_fraction(lambda: f32, em: f32) -> f32 {
    let g = if lambda < 1.0 {
        // Σ_j (−1)^j (j + 1)/(j + 2)! λ^j, to λ⁹ (truncation < 3e-8 relative).
        const C: [f32; 10] = [
            1.0 / 2.0,
            -2.0 / 6.0,
            3.0 / 24.0,
            -4.0 / 120.0,
            5.0 / 720.0,
            -6.0 / 5040.0,
            7.0 / 40320.0,
            -8.0 / 362_880.0,
            9.0 / 3_628_800.0,
            -10.0 / 39_916_800.0,
        ];
        C.iter().rev().fold(0.0, |acc, &c| acc * lambda + c)
    } else {
        (em - lambda * (1.0 - em)) / (lambda * lambda)
    };
    (1.0 - em) * lambda * g / (em * (2.0 - em))
}

/// Table coordinates `(x, y)` of `λ > 0` and `a = |t| ∈ [0, 1)`.
#[inline]
fn coords(lambda: f32, a: f32) -> (f32, f32) {
    // k² ≤ c_h²·f32::MAX stays finite: the generator requires c_h ≤ 1.
    let r = math::sqrt(lambda);
    let x = r / (r + SG_LAMBDA_SCALE);
    let k2 = SG_HORIZON_SCALE * SG_HORIZON_SCALE * lambda;
    let y = a * math::sqrt((1.0 + k2) / (1.0 + k2 * a * a));
    (x, y.min(1.0))
}

/// 4-point Lagrange weights for nodes at −1, 0, 1, 2 relative to the stencil's second node.
#[inline]
fn lagrange(f: f32) -> [f32; 4] {
    let (a, b, c, d) = (f + 1.0, f, f - 1.0, f - 2.0);
    let (ab, cd) = (a * b, c * d);
    [-b * cd * (1.0 / 6.0), a * cd * 0.5, -ab * d * 0.5, ab * c * (1.0 / 6.0)]
}

/// First node of the 4-node stencil around `u ∈ [0, 1]` on `n` uniform nodes, and the weights.
#[inline]
fn stencil(u: f32, n: usize) -> (usize, [f32; 4]) {
    let p = u * (n - 1) as f32;
    // `as` saturates (NaN → 0); the stencil is shifted inwards at both ends.
    let i0 = (p as usize).saturating_sub(1).min(n - 4);
    (i0, lagrange(p - (i0 + 1) as f32))
}

#[inline]
fn interpolate<const NX: usize, const NY: usize>(table: &[f32], x: f32, y: f32) -> f32 {
    let (i0, wx) = stencil(x, NX);
    let (j0, wy) = stencil(y, NY);
    let mut sum = 0.0;
    for (a, wa) in wx.iter().enumerate() {
        let start = (i0 + a) * NY + j0;
        let row = &table[start..start + 4];
        sum += wa * (wy[0] * row[0] + wy[1] * row[1] + wy[2] * row[2] + wy[3] * row[3]);
    }
    sum
}
