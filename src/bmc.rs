//! Bayesian Monte Carlo (BMC) irradiance with baked weights: the renderer form.
//!
//! Bayesian quadrature puts a Gaussian-process prior on the radiance and integrates the
//! posterior mean (Rasmussen and Ghahramani 2002, "Bayesian Monte Carlo"; for illumination
//! integrals with spherical Fibonacci samples, Marques, Bouville, Ribardière, Santos and
//! Bouatouch 2013, "A spherical Gaussian framework for Bayesian Monte Carlo rendering of
//! glossy surfaces", and Marques et al. 2014).
//!
//! # Model
//! - Kernel `k(x, x′) = σ_f²·exp(−|x − x′|²/l²) + σ_n²δ`, σ_f = 1, `σ′ = σ_n/σ_f`. On unit
//!   vectors `|x − x′|² = 2 − 2x·x′`, so `k(x, ·)` is a spherical Gaussian with axis `x` and
//!   sharpness `λ = 2/l²`.
//! - Samples: the `N`-point hemisphere spherical Fibonacci set about the normal
//!   (`uⱼ = 1 − (2j + 1)/(2N)`, golden azimuth, rotated about the normal by a phase), morphed
//!   onto the cosine (`cos θⱼ = √uⱼ`: the QMC-SF samples of irradiance) in the shipped tables
//!   or left uniform (`zⱼ = uⱼ`) in a table that says `uniform` ([`Renderer::lobe`]). The cosine
//!   is the known part `p(x) = cos θ/π` of the integrand either way. `Q = K + σ′²I` depends
//!   only on the set, not on the normal or the phase.
//! - `zᵢ = ∫ k(xᵢ, x) p(x) dx = C(λ, zᵢ)/π`, with `C` the spherical-Gaussian × clamped-cosine
//!   integral ([`crate::sg`]), `∫p = 1`.
//! - Constant prior mean estimated from the data by generalised least squares (Rasmussen and
//!   Williams 2006, eq. 2.42): `w = Q⁻¹z + (1 − 1ᵀQ⁻¹z)·Q⁻¹1/(1ᵀQ⁻¹1)`, so `Σw = 1` and
//!   constants are integrated exactly.
//! - Irradiance `E(n) = π·Σ wᵢ L(xᵢ)`; posterior variance of `E`
//!   `π²·(V̄ − zᵀQ⁻¹z + (1 − 1ᵀQ⁻¹z)²/(1ᵀQ⁻¹1))`, `V̄ = ∫∫ k p p`, in units of σ_f².
//!
//! `build.rs` solves in f64 (Cholesky with one step of iterative refinement; generator
//! `gen/bmc.rs`, sets in `tables/bmc.txt`) and bakes `w` rounded once to f32, one `static`
//! array per size. Only the baked sizes compile: `N` ∈ {16, 32, 64, 80, 128, 256}. The
//! hyperparameters are **learned** offline on real maps (`cargo writer renderer_hyperparameters`:
//! the (l, σ′) whose estimates have the smallest RMSE ratio to QMC-SF over the clamp and
//! smooth tiers of four training maps; the report is `docs/renderer.md`). On point-sampled
//! real lighting this renderer ties QMC-SF on the same samples; for light as smooth as
//! mixtures of spherical Gaussians of sharpness 2…20, the preset `tables/bmc_smooth.txt`
//! (uniform set, learned by `xtask/writers/src/bin/learn_hyperparameters.rs`) is many times better than
//! QMC-SF (`docs/hyperparameters.md`) — select it with the variable below. For a probe
//! that shares its samples among many normals, see [`crate::probe`].
//!
//! To bake other sizes or hyperparameters without forking the crate, point the environment
//! variable `SPHERE_QUADRATURE_BMC_TABLE` at a file in the format of `tables/bmc.txt` (for
//! example in your `.cargo/config.toml`:
//! `[env] SPHERE_QUADRATURE_BMC_TABLE = { value = "bmc.txt", relative = true }`); `build.rs`
//! reruns when it changes.
//!
//! ```
//! use sphere_quadrature::{bmc::Renderer, Vec3};
//!
//! let r = Renderer::<64>::new();
//! let mut dirs = [Vec3::Z; 64];
//! r.with_phase(0x1234).fill_directions(Vec3::new(0.0, 0.6, 0.8), &mut dirs)?;
//! // Trace the directions; here a sky brighter towards +z.
//! let samples = dirs.map(|d| 1.0 + 0.5 * d.z);
//! let e = r.estimate(&samples)?;
//! assert!(e > 3.0 && e < 5.0);
//! // A constant is integrated exactly (Σw = 1): E = π·c.
//! assert!((r.estimate(&[2.0f32; 64])? - 2.0 * core::f32::consts::PI).abs() < 1e-5);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! A size without baked weights does not compile ("no Bayesian Monte Carlo weights are baked
//! for `Size<17>`"):
//! ```compile_fail,E0277
//! let _ = sphere_quadrature::bmc::Renderer::<17>::new();
//! ```
//!
//! # Weights
//! Per baked set ([`Renderer::hyperparameters`], [`Renderer::abs_weight_ratio`],
//! [`Renderer::condition_number`], [`Renderer::variance`]). Every weight is positive
//! (`Σ|w|/Σw = 1`).
//!
//! | N | l | σ′ | Σ\|w\|/Σw | cond(Q) | σ(E) for σ_f = 1 |
//! | --- | --- | --- | --- | --- | --- |
//! | 16 | 0.9051 | 0.1 | 1.000 | 3.8·10² | 0.100 |
//! | 32 | 0.9051 | 0.1 | 1.000 | 1.3·10³ | 0.060 |
//! | 64 | 0.9051 | 0.1 | 1.000 | 2.6·10³ | 0.040 |
//! | 80 | 0.9051 | 0.03 | 1.000 | 3.6·10⁴ | 0.011 |
//! | 128 | 0.9051 | 0.1 | 1.000 | 5.2·10³ | 0.028 |
//! | 256 | 0.9051 | 0.1 | 1.000 | 1.0·10⁴ | 0.020 |
//!
//! 2 304 bytes of weights in all ([`TABLE_BYTES`]).
//!
//! # Accuracy
//! Measured by `tests/bmc/bmc.rs`, identical under `libm` and `micromath`:
//! - The baked f32 weights agree with the independent f64 reference (other point formula,
//!   `zᵢ` by I₀ₑ quadrature, LU solves) to 3.4–4.7·10⁻⁸ of the largest weight (f32
//!   rounding); `Σw − 1` is below 1.3·10⁻⁸.
//! - On real maps (`eval/src/bin/renderer.rs`, `docs/renderer.md`, held-out maps) the renderer
//!   ties QMC-SF on the same samples on the `clamp` tier (0.98–1.07× at N = 32–128) and is
//!   0.46–0.50× QMC-SF on the `smooth` tier.
//! - Relative RMS error of irradiance of single spherical-Gaussian lights (sharpness 2…20,
//!   400 seeded normals, axes and phases), BMC vs the QMC estimator
//!   [`crate::qmc::irradiance`]: N = 16: 14.6 % vs 11.7 %; 32: 4.4 % vs 3.4 %; 64: 1.36 % vs
//!   1.31 %; 80: 1.11 % vs 0.91 %; 128: 0.52 % vs 0.64 %; 256: 0.18 % vs 0.21 %. Lights this
//!   sharp want a shorter kernel: the preset `tables/bmc_smooth.txt` (uniform set, learned on
//!   such fields) gives 0.13× QMC-SF at N = 64 and 0.048× on the synthetic tier of
//!   `docs/accuracy.md` (the shipped table: 0.495×).
//! - Posterior variance: in units of σ_f² (σ_f = 1 here), for the plain model (the nugget as
//!   noise); the probe form estimates σ_f from its samples.
//!
//! # Bad input
//! A zero, NaN or infinite normal gives [`Error::InvalidDirection`]; NaN radiance propagates
//! to a NaN estimate.
//!
//!
//! # Cost
//! Instructions per call and flash on a Cortex-M4F: [`costs`](crate::costs#bmc-renderers).

pub mod footprint;
pub mod glossy;
mod scaled;
pub use footprint::{Diffuse, FootprintRenderer, FootprintSize, Phong};
pub use glossy::{GlossyRenderer, GlossySize};

use crate::error::Error;
use crate::qmc::LobeSampler;
use crate::radiance::Radiance;
use crate::vec3::Vec3;
use crate::warp::Lobe;

pub use crate::size::Size;

unbaked_size_diagnostic! { renderer,
    /// Implemented for exactly the sizes `N` whose weights are baked ([`BAKED_SIZES`]: the
    /// `set = …` lines of this build's table, `tables/bmc.txt` or the file named by
    /// `SPHERE_QUADRATURE_BMC_TABLE`); sealed. For any other `N` the compile error lists them.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::bmc::{BakedSize, Renderer, Size, BAKED_SIZES};
    ///
    /// fn variance<const N: usize>() -> f32
    /// where
    ///     Size<N>: BakedSize,
    /// {
    ///     Renderer::<N>::variance()
    /// }
    /// // More samples, less posterior variance.
    /// assert!(variance::<64>() < variance::<16>());
    /// assert!(BAKED_SIZES.contains(&64));
    /// ```
    pub trait BakedSize: sealed::Sealed {}
}

pub(crate) mod sealed {
    /// What `build.rs` baked for one size.
    #[derive(Clone, Copy, Debug)]
    pub struct Set {
        pub weights: &'static [f32],
        /// The cosine-morphed set rather than the uniform one.
        pub cosine: bool,
        pub variance: f32,
        pub length_scale: f32,
        pub noise: f32,
        pub abs_weight_ratio: f32,
        pub condition: f32,
    }

    pub trait Sealed {
        const SET: Set;
    }
}

/// The sizes with baked weights, ascending.
pub const BAKED_SIZES: &[usize] = &crate::tables::BMC_SIZES;

/// Flash footprint of all baked weight arrays in bytes (4 per weight).
pub const TABLE_BYTES: usize = {
    let mut sum = 0;
    let mut i = 0;
    while i < BAKED_SIZES.len() {
        sum += 4 * BAKED_SIZES[i];
        i += 1;
    }
    sum
};

/// BMC irradiance from `N` hemisphere spherical Fibonacci samples with baked weights.
///
/// Build it with [`Renderer::new`] (a `const fn`); it holds only the rotation of its set
/// about the normal ([`Renderer::with_phase`], none by default).
///
/// # Examples
/// ```
/// use sphere_quadrature::{bmc::Renderer, Vec3};
///
/// let r = Renderer::<64>::new();
/// let n = Vec3::new(0.0, 0.6, 0.8);
/// let mut dirs = [Vec3::ZERO; 64];
/// r.fill_directions(n, &mut dirs)?;
/// assert!(dirs.iter().all(|d| d.dot(n) > 0.0)); // all above the surface
/// // The radiance along each direction, then E = π·Σ wᵢYᵢ: a constant 1 gives π.
/// let samples = dirs.map(|_| 1.0f32);
/// assert!((r.estimate(&samples)? - core::f32::consts::PI).abs() < 1e-4);
/// // Callback form, same directions and weights.
/// assert_eq!(r.irradiance(n, |_| 1.0f32)?, r.estimate(&samples)?);
/// // Another rotation of the set about the normal (per pixel, say): the same weights.
/// let mut turned = [Vec3::ZERO; 64];
/// r.with_phase(0x9e37_79b9_7f4a_7c15).fill_directions(n, &mut turned)?;
/// assert!(turned.iter().zip(&dirs).all(|(a, b)| (a.dot(n) - b.dot(n)).abs() < 1e-5));
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Renderer<const N: usize>
where
    Size<N>: BakedSize,
{
    /// The rotation about the normal, in units of 2⁻⁶⁴ turn.
    phase_bits: u64,
}

impl<const N: usize> Renderer<N>
where
    Size<N>: BakedSize,
{
    const SET: sealed::Set = <Size<N> as sealed::Sealed>::SET;
    /// The lobe the set is morphed onto.
    const LOBE: Lobe = if Self::SET.cosine { Lobe::Cosine } else { Lobe::Uniform };
    const WEIGHTS: &'static [f32; N] = match Self::SET.weights.first_chunk::<N>() {
        Some(w) => w,
        None => panic!("baked weight count differs from N"),
    };

    /// The renderer.
    #[must_use]
    pub const fn new() -> Self {
        Self { phase_bits: 0 }
    }

    /// The same renderer with its set rotated about the normal by `phase_bits / 2⁶⁴` turn
    /// (a fresh phase per pixel or frame turns the set's structured error into noise). The
    /// weights do not depend on it.
    #[must_use]
    pub const fn with_phase(self, phase_bits: u64) -> Self {
        Self { phase_bits }
    }

    /// Writes the `N` sample directions about `normal` (normalised first), rotated about it by
    /// the renderer's phase ([`Renderer::with_phase`]): the hemisphere spherical Fibonacci set
    /// morphed onto [`Renderer::lobe`].
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite normal.
    pub fn fill_directions(&self, normal: Vec3, out: &mut [Vec3; N]) -> Result<(), Error> {
        LobeSampler::new(normal, Self::LOBE, N, self.phase_bits)?.fill(out)
    }

    /// The lobe the baked set is morphed onto: [`Lobe::Cosine`] (the shipped tables: the
    /// QMC-SF samples of irradiance) or [`Lobe::Uniform`] (`uniform` in a user table).
    #[must_use]
    pub const fn lobe() -> Lobe {
        Self::LOBE
    }

    /// The weights `w` (`Σw = 1` to f32 rounding), in the order of [`Renderer::fill_directions`].
    #[must_use]
    pub const fn weights() -> &'static [f32; N] {
        Self::WEIGHTS
    }

    /// Irradiance `E = π·Σ wᵢ Yᵢ` from the radiance in each direction, in order.
    ///
    /// # Cost
    /// Flash: `4·N` bytes of weights per size used ([`TABLE_BYTES`] for all of them).
    ///
    /// # Errors
    /// [`Error::InvalidRadiance`] for a NaN or infinite sample.
    pub fn estimate<T: Radiance>(&self, samples: &[T; N]) -> Result<T, Error> {
        let () = crate::radiance::Channels::<T>::VALID;
        let sum =
            samples.iter().zip(Self::WEIGHTS).fold(T::ZERO, |acc, (&y, &w)| acc.mul_add(y, w));
        let sum = if scaled::in_range(sum) {
            sum
        } else {
            // Not finite, or too small to trust: the samples checked and summed at their own
            // scale.
            scaled::rescaled_sum(samples, |j| Self::WEIGHTS.get(j).copied().unwrap_or(0.0))?
        };
        Ok(sum.scale(core::f32::consts::PI))
    }

    /// Irradiance with radiance from a callback, directions as in [`Renderer::fill_directions`]:
    /// [`Renderer::estimate`] of the callback's values.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite normal, [`Error::InvalidRadiance`]
    /// for a NaN or infinite value.
    pub fn irradiance<T: Radiance, F: FnMut(Vec3) -> T>(
        &self,
        normal: Vec3,
        mut radiance: F,
    ) -> Result<T, Error> {
        let mut samples = [T::ZERO; N];
        let s = LobeSampler::new(normal, Self::LOBE, N, self.phase_bits)?;
        for (slot, d) in samples.iter_mut().zip(s.iter()) {
            *slot = radiance(d);
        }
        self.estimate(&samples)
    }

    /// Posterior variance of the irradiance estimate for σ_f = 1 (multiply by σ_f²).
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::bmc::Renderer;
    ///
    /// // More samples, less posterior variance; never negative.
    /// assert!(Renderer::<256>::variance() < Renderer::<16>::variance());
    /// assert!(Renderer::<256>::variance() >= 0.0);
    /// ```
    #[must_use]
    pub const fn variance() -> f32 {
        Self::SET.variance
    }

    /// The kernel hyperparameters `(l, σ′)` the weights were baked with.
    #[must_use]
    pub const fn hyperparameters() -> (f32, f32) {
        (Self::SET.length_scale, Self::SET.noise)
    }

    /// `Σ|w|/Σw`: 1 when no weight is negative; larger values amplify sample noise.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::bmc::Renderer;
    ///
    /// // Σ|w| ≥ Σw = 1, with equality when no weight is negative.
    /// let negative = Renderer::<64>::weights().iter().any(|&w| w < 0.0);
    /// let ratio = Renderer::<64>::abs_weight_ratio();
    /// assert!(ratio >= 1.0 - 1e-6);
    /// if !negative {
    ///     assert!((ratio - 1.0).abs() < 1e-5);
    /// }
    /// ```
    #[must_use]
    pub const fn abs_weight_ratio() -> f32 {
        Self::SET.abs_weight_ratio
    }

    /// The estimated 2-norm condition number of `Q = K + σ′²I`.
    #[must_use]
    pub const fn condition_number() -> f32 {
        Self::SET.condition
    }
}
