//! Spherical harmonics up to degree 2 (9 coefficients per channel): the form in which
//! renderers take a lighting probe, with O(9) irradiance, rotation, and the conventions of
//! three.js, Filament and Unity.
//!
//! # Basis
//! [`ShL2`] holds the coefficients `c_lm = ∫ L(x)·Y_lm(x) dx` of a radiance function `L` on
//! the real spherical harmonics `Y_lm`, orthonormal over the solid angle (`∫ Y_lm·Y_l′m′ =
//! δ`), at index `l(l + 1) + m`, **without the Condon–Shortley phase** (the basis of
//! [`crate::metrics::real_sh`], Ramamoorthi and Hanrahan 2001, Sloan's "Stupid Spherical
//! Harmonics (SH) Tricks" and three.js). For a unit direction `(x, y, z)`:
//!
//! | index | l | m | `Y_lm` |
//! | --- | --- | --- | --- |
//! | 0 | 0 | 0 | `½·√(1/π)` = 0.282095 |
//! | 1 | 1 | −1 | `½·√(3/π)·y` = 0.488603·y |
//! | 2 | 1 | 0 | `½·√(3/π)·z` |
//! | 3 | 1 | 1 | `½·√(3/π)·x` |
//! | 4 | 2 | −2 | `½·√(15/π)·xy` = 1.092548·xy |
//! | 5 | 2 | −1 | `½·√(15/π)·yz` |
//! | 6 | 2 | 0 | `¼·√(5/π)·(3z² − 1)` = 0.315392·(3z² − 1) |
//! | 7 | 2 | 1 | `½·√(15/π)·xz` |
//! | 8 | 2 | 2 | `¼·√(15/π)·(x² − y²)` = 0.546274·(x² − y²) |
//!
//! Every `Y_lm` is positive on its positive axes: the l = 1 coefficients multiply `y`, `z`,
//! `x` in that order (`c₁₋₁ = ½·√(3/π)·∫ L(x)·y dx`, the first moment along y, and so on). The axes are the caller's (the crate's point sets take z as
//! the pole); see "Axes" below for the engines'.
//!
//! # Irradiance
//! By the Funk–Hecke theorem the clamped cosine `max(0, n·x)` acts on degree `l` as a gain
//! `Â_l = 2π∫₀¹ t·P_l(t) dt`: `Â₀ = π`, `Â₁ = 2π/3`, `Â₂ = π/4` (Ramamoorthi and Hanrahan,
//! "An Efficient Representation for Irradiance Environment Maps", SIGGRAPH 2001, section
//! 3), so [`ShL2::irradiance`] is `E(n) = Σ Â_l·c_lm·Y_lm(n)`: 9 multiply-adds after a
//! check of `n` (57 Cortex-M4 instructions per call for one channel and a unit normal, 88
//! for a normal that must be normalised). It is exact for a radiance without
//! harmonics above degree 2; for any other it is the irradiance of the projection, which
//! drops the terms of `Â₄ = −π/24`, `Â₆ = π/64`, … (the odd `Â_l` above 1 vanish):
//! Ramamoorthi and Hanrahan report average errors of about 1 % on their environment maps.
//! [`ShL2::radiance`] evaluates the expansion itself; [`ShL2::convolved`] applies any zonal
//! gains (a Phong lobe's `1, (e + 1)/(e + 2), e/(e + 3)`, say).
//!
//! # Rotation
//! [`ShL2::rotated`]`(m)` gives the coefficients of `x ↦ L(mᵀx)` (what `L` sent to direction
//! `d` now sends to `m·d`, as [`crate::probe::Probe::set_rotation`] rotates the sample set):
//! degree 1 transforms by `m` itself (with the coefficients ordered `x, y, z`, that is
//! indices 3, 1, 2), and degree 2, a trace-free quadratic form `xᵀAx`, by `A ↦ m·A·mᵀ`.
//!
//! # Engines
//! Each conversion keeps the axes (see "Axes") and is checked in `tests/sh/sh.rs` against that
//! engine's published evaluation formula, written out in the test from the cited source.
//! - **three.js** `SphericalHarmonics3` (`src/math/SphericalHarmonics3.js` in mrdoob/three.js:
//!   `getBasisAt`, `getAt`, `getIrradianceAt`; the shader's `shGetIrradianceAt` in
//!   `src/renderers/shaders/ShaderChunk/lights_pars_begin.glsl.js`): its `coefficients`, 9
//!   `Vector3` (RGB), are radiance coefficients in this very basis and order (constants
//!   0.282095, 0.488603·y, z, x, 1.092548·xy, yz, 0.315392·(3z² − 1), 1.092548·xz,
//!   0.546274·(x² − y²)), and the shader returns the irradiance `E(n)` (it then multiplies
//!   by `BRDF_Lambert`, albedo/π, so a white `MeshLambertMaterial` lit by a `LightProbe` of
//!   intensity 1 shows `E(n)/π`). three.js's world is y-up, so the export names the frame of
//!   the probe's directions: [`ShL2::three_js_from_z_up`] rotates a z-up probe (the crate's
//!   point sets take z as the pole) by `(x, y, z) ↦ (x, z, −y)`;
//!   [`ShL2::three_js_from_y_up`] hands over coefficients already in three.js's axes
//!   unchanged (a probe sampled in three.js world directions). `examples/threejs` renders a
//!   sphere lit by the export in three.js and compares its pixels with
//!   [`ShL2::irradiance`].
//! - **Filament** (google/filament): `IndirectLight::Builder::irradiance(3, sh)`
//!   (`filament/include/filament/IndirectLight.h`) takes the irradiance pre-convolved with
//!   the clamped cosine, pre-multiplied by the Lambertian `1/π` and pre-scaled by the
//!   polynomial constants, `sh[i] = L_lm·(1/π)·A_lm·Ĉ_l`, as `cmgen` writes it; the shader
//!   (`Irradiance_SphericalHarmonics` in `shaders/src/surface_light_indirect.fs`) returns
//!   `max(0, sh[0] + sh[1]·y + sh[2]·z + sh[3]·x + sh[4]·yx + sh[5]·yz + sh[6]·(3z² − 1) +
//!   sh[7]·zx + sh[8]·(x² − y²))` = `E(n)/π`. Filament's `L_lm` are in the basis *with* the
//!   Condon–Shortley phase (its `A_lm` are negative for `m = ±1`), which the signs of `A_lm`
//!   undo: [`ShL2::filament_irradiance`] is `c_lm` times the positive factors 0.282095,
//!   0.325735 (three times), 0.273137, 0.273137, 0.078848, 0.273137, 0.136569.
//!   `Builder::radiance(3, sh)` takes `L_lm` itself: [`ShL2::filament_radiance`] (our
//!   coefficients with the sign of `m = ±1` flipped).
//! - **Unity** `SphericalHarmonicsL2` (27 floats, `sh[channel, coefficient]`, channel 0…2 for
//!   R, G, B, coefficient in the order above: Unity Manual, "Light Probes: technical
//!   information"): Unity stores the coefficients already convolved with the clamped cosine,
//!   divided by π and multiplied by the polynomial constants (`kNormalizationConstants`,
//!   whose inverse `invNormConsts` and `UndoCosineRescaling` are in `SphericalHarmonicMath`,
//!   `com.unity.render-pipelines.high-definition/Runtime/Lighting/SphericalHarmonics.cs` in
//!   Unity-Technologies/Graphics): the same numbers as Filament's, which
//!   [`ShL2::unity`] returns per channel. The shader constants (`PackCoefficients` in the same
//!   file; `SetSHEMapConstants` of Sloan's paper, appendix A10) are `unity_SHA{r,g,b} =
//!   (sh[c,3], sh[c,1], sh[c,2], sh[c,0] − sh[c,6])`, `unity_SHB{r,g,b} = (sh[c,4], sh[c,5],
//!   3·sh[c,6], sh[c,7])`, `unity_SHC = (sh[0,8], sh[1,8], sh[2,8], 1)`
//!   ([`ShL2::unity_shader_constants`]); `SHEvalLinearL0L1(n) + SHEvalLinearL2(n)`, i.e.
//!   `ShadeSH9` in linear colour space (`UnityCG.cginc`), returns `E(n)/π`.
//!
//! # Axes
//! The engines evaluate their polynomials in the components of a world-space direction:
//! three.js and Filament are right-handed with y up, Unity left-handed with y up. A probe
//! whose frame has z up converts to three.js with [`ShL2::three_js_from_z_up`] (the rotation
//! [`Y_UP_FROM_Z_UP`], `(x, y, z) ↦ (x, z, −y)`), and with [`ShL2::rotated`] first for the
//! others: to Filament's right-handed y-up frame by [`Y_UP_FROM_Z_UP`], to Unity's by the
//! reflection `(x, y, z) ↦ (x, z, y)` (any orthogonal matrix is accepted).
//!
//! ```
//! use sphere_quadrature::{probe::Probe, sh::{ShL2, Y_UP_FROM_Z_UP}, Vec3};
//!
//! let mut probe = Probe::<64, [f32; 3]>::new();
//! let sky = |d: Vec3| [1.0 + 0.5 * d.z, 1.0, 0.8 + 0.2 * d.x];
//! probe.update(&probe.directions().map(sky))?;
//! let sh: ShL2<[f32; 3]> = probe.radiance_sh(); // 9 RGB coefficients of the posterior mean
//! // Irradiance in O(9): π·(1 + 0.5·2/3) for the red channel at +z.
//! let e = sh.irradiance(Vec3::Z)?;
//! assert!((e[0] - 4.18879).abs() < 0.02);
//! // The probe's frame is z-up, three.js's y-up: the export rotates z to y, and the 9 RGB
//! // triples go to `SphericalHarmonics3.coefficients`.
//! let three: [[f32; 3]; 9] = sh.three_js_from_z_up();
//! // three.js's y (index 1) is our z (index 2), its z (index 2) our −y (index 1).
//! assert!((three[1][0] - sh.coefficients[2][0]).abs() < 1e-5);
//! assert!((three[2][0] + sh.coefficients[1][0]).abs() < 1e-5);
//! // The same as rotating first and handing the result over unchanged, to f32 rounding.
//! let rotated = sh.rotated(&Y_UP_FROM_Z_UP).three_js_from_y_up();
//! assert!(three.iter().zip(&rotated).all(|(a, b)| (a[0] - b[0]).abs() < 1e-5));
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Accuracy
//! Against f64 references (`tests/sh/sh.rs`, largest error over random coefficients and
//! directions, relative to `Σ|c_lm|`): the basis and [`ShL2::radiance`] 1.8·10⁻⁷,
//! [`ShL2::irradiance`] against quadrature of the cosine integral 7·10⁻⁸, [`ShL2::rotated`]
//! against the quadrature projection of the rotated function 4·10⁻⁸; the engines' formulas
//! on the converted coefficients: Filament and Unity 3·10⁻⁸, three.js 4·10⁻⁷ (its constants
//! have 6 digits). [`crate::probe::Probe::radiance_sh`] matches an f64 solve of the probe's
//! model to 10⁻⁷–10⁻⁶ of `Σ|c_lm|` for members with `cond(Q) ≤ 10⁴`.
//!
//! On the benchmark's real maps (`docs/accuracy.md`) the irradiance of the export has the
//! probe's own error wherever that error is large against what 9 coefficients cannot hold:
//! the SH L2 projection of the exact maps is off by 1.8 % (`clamp` tier) and 0.6 % (`smooth`),
//! so the export's error is within 1 % of the probe's at N ≤ 128 on `clamp` and N = 16 on
//! `smooth`, and approaches that floor where the probe is better than it (2.7× the probe's
//! 0.24 % at N = 256 on `smooth`).
//!
//! # Bad input
//! A zero, NaN or infinite direction gives [`Error::InvalidDirection`]; slices of different
//! lengths give [`Error::LengthMismatch`]. Coefficients, weights, gains and matrices are used
//! as given in plain f32 arithmetic: NaN propagates, and a result beyond `f32::MAX` is `±∞`.
//!
//!
//! # Cost
//! Instructions per call and flash on a Cortex-M4F: [`costs`](crate::costs#spherical-harmonics).

use crate::error::Error;
use crate::harmonics;
use crate::math;
use crate::radiance::Radiance;
use crate::rotation::Mat3;
use crate::vec3::Vec3;

/// The rotation from a right-handed z-up frame (the crate's point sets' pole) to a
/// right-handed y-up one (three.js, Filament): `(x, y, z) ↦ (x, z, −y)`, so `+z ↦ +y` and
/// `+y ↦ −z`. [`ShL2::three_js_from_z_up`] applies it; [`ShL2::rotated`] takes it for the
/// other y-up engines.
///
/// ```
/// use sphere_quadrature::{sh::Y_UP_FROM_Z_UP, Vec3};
///
/// assert_eq!(Y_UP_FROM_Z_UP * Vec3::Z, Vec3::Y);
/// assert_eq!(Y_UP_FROM_Z_UP * Vec3::Y, -Vec3::Z);
/// ```
pub const Y_UP_FROM_Z_UP: Mat3 =
    Mat3::from_rows(Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, -1.0, 0.0));

/// The degree-2 constants `Y₀₀ = ½·√(1/π)`, `½·√(3/π)` (degree 1), `½·√(15/π)` (`xy`, `yz`,
/// `xz`), `¼·√(5/π)` (`3z² − 1`) and `¼·√(15/π)` (`x² − y²`).
const Y00: f32 = harmonics::CONSTANTS[0];
const Y1: f32 = harmonics::CONSTANTS[1];
const Y2: f32 = harmonics::CONSTANTS[4];
const Y20: f32 = harmonics::CONSTANTS[6];
const Y22: f32 = harmonics::CONSTANTS[8];

/// The factors of an evaluation, per term: `[0, 1, 2, 3, 4, 5]` multiply the constant, the
/// degree-1 sum, the `xy, yz, xz` sum, `z²` and `−1` of `3z² − 1`, and `x² − y²`.
type Factors = [f32; 6];

/// `Y_lm` itself.
const RADIANCE: Factors = [Y00, Y1, Y2, 3.0 * Y20, Y20, Y22];

/// `Â_l·Y_lm` with `Â = π, 2π/3, π/4`, each constant rounded once from f64.
const IRRADIANCE: Factors = [
    0.886_226_925_452_757_9_f64 as f32,  // π·Y₀₀
    1.023_326_707_946_488_3_f64 as f32,  // (2π/3)·½√(3/π)
    0.858_085_530_809_783_4_f64 as f32,  // (π/4)·½√(15/π)
    0.743_123_868_301_127_1_f64 as f32,  // 3·(π/4)·¼√(5/π)
    0.247_707_956_100_375_71_f64 as f32, // (π/4)·¼√(5/π)
    0.429_042_765_404_891_7_f64 as f32,  // (π/4)·¼√(15/π)
];

/// `Â_l·Y_lm/π` per index, positive: Filament's and Unity's pre-scaled coefficients are
/// `c_lm` times these (see the module docs).
const PRESCALED: [f32; 9] = [
    0.282_094_791_773_878_14_f64 as f32, // Y₀₀
    0.325_735_007_935_279_95_f64 as f32, // ⅔·½√(3/π)
    0.325_735_007_935_279_95_f64 as f32,
    0.325_735_007_935_279_95_f64 as f32,
    0.273_137_107_648_019_8_f64 as f32, // ¼·½√(15/π)
    0.273_137_107_648_019_8_f64 as f32,
    0.078_847_891_313_130_01_f64 as f32, // ¼·¼√(5/π)
    0.273_137_107_648_019_8_f64 as f32,
    0.136_568_553_824_009_9_f64 as f32, // ¼·¼√(15/π)
];

/// A direction whose squared length is one of the eight f32 numbers nearest 1, from
/// `1 − 2⁻²²` to `1 + 3·2⁻²³` (bit patterns `0x3F7F_FFFC` to `0x3F80_0003`: `bits + 4` has
/// the top 29 bits of [`UNIT_BITS`]), is unit to f32 precision, its length within
/// `1.8·10⁻⁷` of 1, and is used as given: normalising it would change the degree-1 terms
/// by at most that, the degree-2 terms by twice that. An f32 vector normalised in f32 is in
/// this set 99.96 % of the time. The test is on the bits (an add, a shift, a compare; NaN
/// and every other length fail it).
const UNIT_BITS: u32 = 0x3F80_0004;

/// Spherical-harmonic coefficients of degree `l ≤ 2` of a radiance function (`f32` or RGB
/// `[f32; 3]` per coefficient): orthonormal real harmonics without the Condon–Shortley phase,
/// at index `l(l + 1) + m` (the table in the module docs).
///
/// # Examples
/// ```
/// use sphere_quadrature::{sh::ShL2, SphericalFibonacci, Vec3};
///
/// // A constant radiance of 1 has c₀₀ = ∫ Y₀₀ = 2√π and nothing else.
/// let two_sqrt_pi = 2.0 * core::f32::consts::PI.sqrt();
/// let constant = ShL2::new([two_sqrt_pi, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
/// // Its irradiance is π for every normal (unit or not), its radiance 1.
/// for n in [Vec3::Z, Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, -3.0, 0.0)] {
///     assert!((constant.irradiance(n)? - core::f32::consts::PI).abs() < 1e-5);
/// }
/// assert!((constant.radiance(Vec3::X)? - 1.0).abs() < 1e-6);
/// assert_eq!(constant.irradiance(Vec3::ZERO), Err(sphere_quadrature::Error::InvalidDirection));
/// // Projecting samples with equal weights 4π/N finds the same c₀₀.
/// let dirs = SphericalFibonacci::<64>::new().points();
/// let sh = ShL2::<f32>::from_samples(&dirs, &[1.0; 64], 4.0 * core::f32::consts::PI / 64.0)?;
/// assert!((sh.coefficients[0] - two_sqrt_pi).abs() < 1e-4);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ShL2<T: Radiance = f32> {
    /// `c_lm = ∫ L(x)·Y_lm(x) dx` at index `l(l + 1) + m`.
    pub coefficients: [T; 9],
}

impl<T: Radiance> Default for ShL2<T> {
    fn default() -> Self {
        Self::ZERO
    }
}

/// A unit direction and the squares of its components.
struct Unit {
    x: f32,
    y: f32,
    z: f32,
    xx: f32,
    yy: f32,
    zz: f32,
}

/// `n` normalised: `None` for a zero, NaN or infinite `n`, as [`Vec3::try_normalize`], but
/// without a square root ([`math::inv_sqrt`]) where the squared length is in
/// `[10⁻³⁰, f32::MAX]` (outside it, [`Vec3::try_normalize`]'s scaled path), and as given when
/// it is unit to f32 precision ([`UNIT_BITS`]).
#[inline]
fn unit(n: Vec3) -> Option<Unit> {
    let Vec3 { x, y, z } = n;
    let (xx, yy, zz) = (x * x, y * y, z * z);
    let l2 = xx + yy + zz;
    if l2.to_bits().wrapping_add(4) >> 3 == UNIT_BITS >> 3 {
        return Some(Unit { x, y, z, xx, yy, zz });
    }
    if !(l2 >= 1e-30 && l2.is_finite()) {
        let Vec3 { x, y, z } = n.try_normalize()?;
        return Some(Unit { x, y, z, xx: x * x, yy: y * y, zz: z * z });
    }
    let r = math::inv_sqrt(l2);
    let (x, y, z) = (x * r, y * r, z * r);
    Some(Unit { x, y, z, xx: x * x, yy: y * y, zz: z * z })
}

impl<T: Radiance> ShL2<T> {
    /// All coefficients zero.
    pub const ZERO: Self = Self { coefficients: [T::ZERO; 9] };

    /// The expansion from its coefficients (index `l(l + 1) + m`).
    #[must_use]
    pub const fn new(coefficients: [T; 9]) -> Self {
        Self { coefficients }
    }

    /// The 9 basis functions `Y_lm(n/|n|)` at index `l(l + 1) + m`.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero, NaN or infinite `n`.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{sh::ShL2, Vec3};
    ///
    /// let y = ShL2::<f32>::basis(Vec3::new(0.3, -0.5, 0.8))?;
    /// // Y₀₀ = 1/(2√π) everywhere; the squares sum to 9/(4π) (the addition theorem).
    /// assert!((y[0] - 0.5 / core::f32::consts::PI.sqrt()).abs() < 1e-6);
    /// let sum: f32 = y.iter().map(|v| v * v).sum();
    /// assert!((sum - 9.0 / (4.0 * core::f32::consts::PI)).abs() < 1e-5);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn basis(n: Vec3) -> Result<[f32; 9], Error> {
        let u = unit(n).ok_or(Error::InvalidDirection)?;
        Ok(basis_of_unit(&u))
    }

    /// The projection of samples by a quadrature rule with one weight: `c_lm = w·Σⱼ
    /// Y_lm(xⱼ)·Yⱼ` (each direction normalised). With `w = 4π/N` on a uniform point set
    /// (the spherical Fibonacci sets) this is the equal-weight SH projection of the samples,
    /// the "SH L2" peer of the benchmarks; empty slices give zero.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when the slices differ in length; [`Error::InvalidDirection`]
    /// for a zero, NaN or infinite direction.
    pub fn from_samples(directions: &[Vec3], samples: &[T], weight: f32) -> Result<Self, Error> {
        if directions.len() != samples.len() {
            return Err(Error::LengthMismatch);
        }
        let mut c = [T::ZERO; 9];
        for (&d, &y) in directions.iter().zip(samples) {
            let b = Self::basis(d)?;
            for (ck, &bk) in c.iter_mut().zip(&b) {
                *ck = ck.mul_add(y, bk);
            }
        }
        Ok(Self { coefficients: c.map(|v| v.scale(weight)) })
    }

    /// The radiance of the expansion, `Σ c_lm·Y_lm(n/|n|)`, O(9).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero, NaN or infinite `n`.
    #[inline]
    pub fn radiance(&self, n: Vec3) -> Result<T, Error> {
        self.evaluate(n, &RADIANCE)
    }

    /// The irradiance `E(n) = ∫ L(x)·max(0, n̂·x) dx` of the expansion, `Σ Â_l·c_lm·Y_lm(n̂)`
    /// with `Â = π, 2π/3, π/4` (Ramamoorthi and Hanrahan 2001), O(9): 57 Cortex-M4
    /// instructions per call for one channel. `n` need not be unit: a normal that
    /// is unit to f32 precision is used as given, any other normalised without a square
    /// root ([`crate::math::inv_sqrt`]; 88 instructions).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero, NaN or infinite `n`.
    #[inline]
    pub fn irradiance(&self, n: Vec3) -> Result<T, Error> {
        self.evaluate(n, &IRRADIANCE)
    }

    /// `Σ c_lm·f_lm·p_lm(n̂)` for the polynomials `p` of the basis and per-term factors `k`.
    #[inline]
    fn evaluate(&self, n: Vec3, k: &Factors) -> Result<T, Error> {
        let Unit { x, y, z, xx, yy, zz } = unit(n).ok_or(Error::InvalidDirection)?;
        let [c0, c1, c2, c3, c4, c5, c6, c7, c8] = self.coefficients;
        let band1 = c3.scale(x).mul_add(c1, y).mul_add(c2, z);
        // c₂₋₂·xy + c₂₋₁·yz + c₂₁·xz with one product fewer.
        let band2 = c4.scale(y).mul_add(c7, z).scale(x).mul_add(c5, y * z);
        let zonal = zz * k[3] - k[4];
        let sectoral = (xx - yy) * k[5];
        Ok(c0
            .scale(k[0])
            .mul_add(band1, k[1])
            .mul_add(band2, k[2])
            .mul_add(c6, zonal)
            .mul_add(c8, sectoral))
    }

    /// Degree `l` multiplied by `gains[l]`: the convolution with a zonal (axially symmetric)
    /// kernel whose Funk–Hecke gains are `gains` (`[π, 2π/3, π/4]` turns radiance into
    /// irradiance; the normalised Phong lobe of exponent `e` has `[1, (e + 1)/(e + 2),
    /// e/(e + 3)]`).
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{sh::ShL2, Vec3};
    ///
    /// // The gains [π, 2π/3, π/4] turn radiance into irradiance.
    /// let pi = core::f32::consts::PI;
    /// let sh = ShL2::new([1.0f32, 0.2, -0.3, 0.1, 0.05, 0.0, -0.1, 0.2, 0.3]);
    /// let e = sh.convolved([pi, 2.0 * pi / 3.0, pi / 4.0]);
    /// let n = Vec3::new(0.0, 0.6, 0.8);
    /// assert!((e.radiance(n)? - sh.irradiance(n)?).abs() < 1e-5);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub fn convolved(&self, gains: [f32; 3]) -> Self {
        let [g0, g1, g2] = gains;
        let [c0, c1, c2, c3, c4, c5, c6, c7, c8] = self.coefficients;
        Self {
            coefficients: [
                c0.scale(g0),
                c1.scale(g1),
                c2.scale(g1),
                c3.scale(g1),
                c4.scale(g2),
                c5.scale(g2),
                c6.scale(g2),
                c7.scale(g2),
                c8.scale(g2),
            ],
        }
    }

    /// The coefficients of `x ↦ L(mᵀx)`: the radiance rotated by `m` (see "Rotation" in the
    /// module docs), exact for any orthogonal `m` (rotations and reflections, such as the
    /// swap to Unity's axes). Degree 1 is `m` applied to `(c₁₁, c₁₋₁, c₁₀)`, degree 2 the
    /// quadratic form `A ↦ m·A·mᵀ`; degree 0 is unchanged.
    ///
    /// `m` is used as given: for a matrix that is not orthogonal the result is the
    /// projection of `L₀ + L₁(mᵀx) + L₂(mᵀx)`, with `L_l` the degree-`l` homogeneous
    /// polynomial of the expansion (the trace that `m·A·mᵀ` then gains is a constant on the
    /// sphere and goes to degree 0), which is not a rotation of `L`. A NaN entry gives NaN
    /// coefficients.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{sh::ShL2, Mat3, Vec3};
    ///
    /// // A lobe along +x, turned a quarter about z, points along +y.
    /// let dirs = [Vec3::X];
    /// let sh = ShL2::<f32>::from_samples(&dirs, &[1.0], 1.0)?;
    /// let m = Mat3::about_z(core::f32::consts::FRAC_PI_2);
    /// let turned = sh.rotated(&m);
    /// assert!((turned.radiance(Vec3::Y)? - sh.radiance(Vec3::X)?).abs() < 1e-5);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub fn rotated(&self, m: &Mat3) -> Self {
        let [c0, c1, c2, c3, c4, c5, c6, c7, c8] = self.coefficients;
        let [r0, r1, r2] = m.rows.map(Vec3::to_array);
        // `row·(a, b, c)` for f32 `row` and T components.
        let dot = |row: &[f32; 3], v: &[T; 3]| {
            v[0].scale(row[0]).mul_add(v[1], row[1]).mul_add(v[2], row[2])
        };
        // Degree 1: (c₁₁, c₁₋₁, c₁₀) are the x, y, z components of a vector v; v′ = m·v.
        let v = [c3, c1, c2];
        let (x1, y1, z1) = (dot(&r0, &v), dot(&r1, &v), dot(&r2, &v));
        // Degree 2 as the symmetric trace-free A with L₂(x) = xᵀAx on the sphere:
        // a·xy + b·yz + c·(3z² − 1) + d·xz + e·(x² − y²) = a·xy + b·yz + d·xz +
        // c·(2z² − x² − y²) + e·(x² − y²).
        let half = 0.5 * Y2;
        let (axy, ayz, axz) = (c4.scale(half), c5.scale(half), c7.scale(half));
        let (c, e) = (c6.scale(Y20), c8.scale(Y22));
        let rows = [
            [e.add(c.scale(-1.0)), axy, axz],
            [axy, e.add(c).scale(-1.0), ayz],
            [axz, ayz, c.scale(2.0)],
        ];
        // Column j of B = A·mᵀ is A·(row j of m); A′ᵢⱼ = (row i of m)·(column j of B).
        let column = |w: &[f32; 3]| {
            let [a0, a1, a2] = &rows;
            [dot(w, a0), dot(w, a1), dot(w, a2)]
        };
        let (b0, b1, b2) = (column(&r0), column(&r1), column(&r2));
        let (pxx, pyy, pzz) = (dot(&r0, &b0), dot(&r1, &b1), dot(&r2, &b2));
        let (pxy, pyz, pxz) = (dot(&r0, &b1), dot(&r1, &b2), dot(&r0, &b2));
        let from_half = 2.0 / Y2;
        let trace = pxx.add(pyy).add(pzz);
        Self {
            coefficients: [
                c0.mul_add(trace, 1.0 / (3.0 * Y00)),
                y1,
                z1,
                x1,
                pxy.scale(from_half),
                pyz.scale(from_half),
                pzz.scale(2.0).add(pxx.add(pyy).scale(-1.0)).scale(1.0 / (6.0 * Y20)),
                pxz.scale(from_half),
                pxx.add(pyy.scale(-1.0)).scale(1.0 / (2.0 * Y22)),
            ],
        }
    }

    /// three.js `SphericalHarmonics3.coefficients` (one `Vector3` per index for RGB) of a
    /// probe whose directions are in a z-up frame (the crate's point sets take z as the
    /// pole): the coefficients rotated into three.js's y-up world by [`Y_UP_FROM_Z_UP`],
    /// `(x, y, z) ↦ (x, z, −y)` (module docs, "Engines", "Axes"). three.js's
    /// `getIrradianceAt(m)` and the shader's `shGetIrradianceAt(m)` at the y-up normal
    /// `m = (x, z, −y)` then return [`ShL2::irradiance`]`((x, y, z))`, to the 6 digits of
    /// three.js's constants; a white `MeshLambertMaterial` lit by a `LightProbe` of these
    /// coefficients renders `E/π` (`BRDF_Lambert`). The rotation is a signed permutation of
    /// degrees 0 and 1 (exact) and, on degree 2, `c′₂₀ = −½·c₂₀ − (√3/2)·c₂₂`,
    /// `c′₂₂ = ½·c₂₂ − (√3/2)·c₂₀` with the rest permuted: [`ShL2::rotated`]`(&`
    /// [`Y_UP_FROM_Z_UP`]`)` to f32 rounding, in 4 multiplies.
    ///
    /// ```
    /// use sphere_quadrature::sh::ShL2;
    ///
    /// // Light from +z (up in the probe's frame) only.
    /// let mut c = [0.0f32; 9];
    /// c[0] = 1.0;
    /// c[2] = 0.8;
    /// let three = ShL2::new(c).three_js_from_z_up();
    /// // In three.js the gradient is along +y (index 1), and none is left along z (index 2).
    /// assert!((three[1] - 0.8).abs() < 1e-6 && three[2].abs() < 1e-6);
    /// ```
    #[must_use]
    pub fn three_js_from_z_up(&self) -> [T; 9] {
        // Y_lm((x, z, −y)) in the basis at (x, y, z): y′ = z, z′ = −y, x′y′ = xz, y′z′ = −yz,
        // x′z′ = −xy, and 3z′² − 1 = 3y² − 1, x′² − y′² = x² − z² mix the zonal and the
        // (x² − y²) harmonics on the unit sphere.
        const HALF_SQRT3: f32 = 0.866_025_403_784_438_6_f64 as f32;
        let [c0, c1, c2, c3, c4, c5, c6, c7, c8] = self.coefficients;
        [
            c0,
            c2,
            c1.scale(-1.0),
            c3,
            c7,
            c5.scale(-1.0),
            c6.scale(-0.5).mul_add(c8, -HALF_SQRT3),
            c4.scale(-1.0),
            c8.scale(0.5).mul_add(c6, -HALF_SQRT3),
        ]
    }

    /// three.js `SphericalHarmonics3.coefficients` of a probe whose directions are already
    /// three.js world directions (y up): the radiance coefficients in the same basis and
    /// order, unchanged (module docs, "Engines"). `getIrradianceAt(n)` and the shader's
    /// `shGetIrradianceAt(n)` then return [`ShL2::irradiance`]`(n)`, `getAt(n)`
    /// [`ShL2::radiance`]`(n)`, to the 6 digits of three.js's constants. For a probe in the
    /// crate's z-up frame use [`ShL2::three_js_from_z_up`].
    ///
    /// ```
    /// use sphere_quadrature::sh::ShL2;
    ///
    /// let sh = ShL2::new([1.0f32, 0.5, 0.25, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    /// assert_eq!(sh.three_js_from_y_up(), sh.coefficients);
    /// ```
    #[must_use]
    pub const fn three_js_from_y_up(&self) -> [T; 9] {
        self.coefficients
    }

    /// Filament's pre-convolved, pre-scaled SH irradiance for
    /// `IndirectLight::Builder::irradiance(3, sh)`: `sh[i] = c_lm·Â_l·Y_lm-constant/π`
    /// (module docs, "Engines"). Filament's shader then returns `max(0, E(n)/π)`.
    #[must_use]
    pub fn filament_irradiance(&self) -> [T; 9] {
        let mut c = self.coefficients;
        for (ck, &f) in c.iter_mut().zip(&PRESCALED) {
            *ck = ck.scale(f);
        }
        c
    }

    /// The radiance coefficients in Filament's basis, with the Condon–Shortley phase, for
    /// `IndirectLight::Builder::radiance(3, sh)`: ours with the sign of `m = ±1` (indices 1,
    /// 3, 5, 7) flipped.
    #[must_use]
    pub fn filament_radiance(&self) -> [T; 9] {
        let mut c = self.coefficients;
        for k in [1, 3, 5, 7] {
            if let Some(ck) = c.get_mut(k) {
                *ck = ck.scale(-1.0);
            }
        }
        c
    }
}

impl ShL2<[f32; 3]> {
    /// Unity's `SphericalHarmonicsL2` as `sh[channel][coefficient]` (R, G, B; the order of
    /// the module docs): the coefficients convolved with the clamped cosine, divided by π and
    /// multiplied by the polynomial constants (the same numbers as
    /// [`ShL2::filament_irradiance`]; module docs, "Engines"). Set them with
    /// `sh[c, i] = unity[c][i]`.
    #[must_use]
    pub fn unity(&self) -> [[f32; 9]; 3] {
        let pre = self.filament_irradiance();
        core::array::from_fn(|c| pre.map(|v| v[c]))
    }

    /// The seven shader constants `unity_SHAr, unity_SHAg, unity_SHAb, unity_SHBr,
    /// unity_SHBg, unity_SHBb, unity_SHC` that `SHEvalLinearL0L1`, `SHEvalLinearL2` and
    /// `ShadeSH9` read, packed from [`ShL2::unity`] as Unity packs a `SphericalHarmonicsL2`
    /// (module docs, "Engines"): `ShadeSH9(n)` (linear colour space) is then `E(n)/π`.
    #[must_use]
    pub fn unity_shader_constants(&self) -> [[f32; 4]; 7] {
        let sh = self.unity();
        let a = |c: usize| {
            let s = sh[c];
            [s[3], s[1], s[2], s[0] - s[6]]
        };
        let b = |c: usize| {
            let s = sh[c];
            [s[4], s[5], 3.0 * s[6], s[7]]
        };
        [a(0), a(1), a(2), b(0), b(1), b(2), [sh[0][8], sh[1][8], sh[2][8], 1.0]]
    }
}

/// `Y_lm(u)` for a unit `u`.
#[inline]
fn basis_of_unit(u: &Unit) -> [f32; 9] {
    harmonics::degree2(Vec3::new(u.x, u.y, u.z))
}
