//! The footprint renderer form: Bayesian Monte Carlo of the renderer integrals from `N`
//! prefiltered lookups, each through a footprint matched to the local sample density, with an
//! error bar.
//!
//! The integrals are the renderer's: irradiance `E(n) = ∫ L(x)·max(0, n·x) dx` ([`Diffuse`])
//! and the normalised Phong lobe with the cosine factor and the horizon,
//! `I(n, r) = ∫ L(x)·(e+1)/(2π)·max(0, r·x)ᵉ·max(0, n·x) dx` ([`Phong<E>`]).
//! [`FootprintRenderer::fill_directions`] places the hemisphere spherical Fibonacci set
//! morphed onto the lobe (the [`GlossyRenderer`](super::GlossyRenderer) set for Phong, the
//! cosine-morphed set about `n` for irradiance). Sample `j` is not the radiance in direction
//! `xⱼ` but the map seen through the normalised spherical Gaussian of sharpness `sⱼ`
//! ([`FootprintRenderer::footprints`]): a footprint whose solid angle `2π/sⱼ` is a fixed
//! multiple `c` of the sample's share `1/(N·pdf(xⱼ))`, wide where the samples are sparse.
//! [`envmap::MipPyramid::footprint_sample`](crate::envmap::MipPyramid::footprint_sample)
//! (fast) or [`envmap::EquirectMap::footprint_sample`](crate::envmap::EquirectMap::footprint_sample)
//! (exact) read a map that way; a renderer with its own prefiltered mips reads the level whose
//! filter matches.
//!
//! # Model
//! The radiance is a Gaussian process with a constant mean and the kernel
//! `σ²·exp(−|x − x′|²/l²)`; a lookup through a spherical Gaussian footprint multiplies the
//! kernel's degree-`l` part by `i_l(s)/i₀(s)` (Funk–Hecke), so every covariance is an exact
//! series. The weights are the generalised-least-squares weights of one `(c, l, σ′)` per
//! `(N, BRDF)`, chosen on training maps, baked at build time on the glossy renderer's grid of
//! `θₙ = acos(r·n)` and interpolated the same way: [`FootprintRenderer::estimate`] is O(N).
//!
//! The error bar of [`FootprintRenderer::estimate_with_variance`] does not trust the weights'
//! own model: real maps are rougher than some kernels and smoother than others. From a family
//! of kernels (lengths `l` × nuggets `σ′`) it takes the one most likely for the query's own
//! lookups, with its signal variance `σ̂²` fitted to them, and returns the estimate's error
//! variance under that model; the likelihoods use `k` fixed contrasts of the lookups
//! (orthogonal to constants), so the call costs `O(kN + Lk² + LSk)` for `L` lengths and `S`
//! nuggets, not a factorisation. A factor learned on training maps scales the result.
//!
//! # Accuracy
//! On six held-out real environment maps (luminance clamped at 30× the mean, 32 queries each;
//! `cargo eval renderer`, `docs/renderer.md`), with `MipPyramid` lookups, the relative RMSE at
//! N = 32–128 is 0.07–0.08 of filtered importance sampling's on the same set for irradiance
//! and 0.001–0.016 for Phong 10, 50 and 200 (means of per-map ratios), and 0.002–0.041 of
//! split-sum's for Phong. The error bar holds 87–97 % of those queries inside 2σ, except
//! Phong 200 at N ≥ 32 (99–99.5 %); on smooth light at N ≥ 64 it is conservative (up to 100 %).
//!
//! # Sizes
//! Baked: [`Diffuse`], [`Phong<10>`], [`Phong<50>`] and [`Phong<200>`] at N = 16, 32 and 64,
//! and at N = 128 with the feature `footprint-128` ([`BAKED_SETS`] lists them). Another pair
//! is a compile error; `tables/footprint_renderer.txt` says how a set is baked and what it
//! costs in flash.
//!
//! ```
//! use sphere_quadrature::bmc::footprint::{FootprintRenderer, Phong};
//! use sphere_quadrature::Vec3;
//!
//! let r = FootprintRenderer::<32, Phong<50>>::new();
//! let (n, mirror) = (Vec3::Z, Vec3::new(0.6, 0.0, 0.8));
//! let mut dirs = [Vec3::ZERO; 32];
//! r.fill_directions(n, mirror, &mut dirs)?;
//! // Constant light c gives c·∫p; the error bar is then only the arithmetic's (f32 rounding
//! // and the interpolation between baked angles).
//! let e = r.estimate_with_variance(n, mirror, &[2.0f32; 32])?;
//! assert!(e.value > 1.4 && e.value < 1.8 && e.variance < 1e-8);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Lookup noise
//! Lookups read back from a GPU are rounded (to fp16, or to 8-bit sRGB after an exposure
//! scale). [`FootprintRenderer::set_lookup_noise`] declares that rounding as independent noise
//! of variance `σ² + η²·Yⱼ²` on lookup `Yⱼ` ([`Noise`]: `σ = absolute` in the lookups' units,
//! `η = relative`); the weights are fixed, so the estimate is unchanged and its variance gains
//! `Σ wⱼ²·(σ² + η²·Yⱼ²)` per channel, added after the calibration factor (the rounding is
//! known, not fitted). The default is [`Noise::NONE`], which adds nothing: the answers are
//! then those of a renderer that never heard of lookup noise, bit for bit. For fp16 lookups
//! `η = 2⁻¹¹/√3` covers the rounding (half an ulp, uniform, at the bottom of a binade); for
//! 8-bit sRGB the step of the curve depends on the value and on the exposure, and `cargo eval
//! lookup_precision` (`docs/lookup_precision.md`) says which `(σ, η)` it derives and what
//! coverage they give on real maps.
//!
//! ```
//! use sphere_quadrature::bmc::footprint::{Diffuse, FootprintRenderer};
//! use sphere_quadrature::layout::Noise;
//! use sphere_quadrature::Error;
//!
//! let mut r = FootprintRenderer::<32, Diffuse>::new();
//! let exact = r.estimate_with_variance(&[2.0f32; 32])?;
//! // fp16 lookups: relative rounding 2⁻¹¹/√3.
//! r.set_lookup_noise(Noise { absolute: 0.0, relative: 2f32.powi(-11) / 3f32.sqrt() })?;
//! let fp16 = r.estimate_with_variance(&[2.0f32; 32])?;
//! let mut w = [0.0f32; 32];
//! r.weights(&mut w)?;
//! let added: f32 = w.iter().map(|w| (w * 2.0 * 2f32.powi(-11) / 3f32.sqrt()).powi(2)).sum();
//! assert_eq!(fp16.value, exact.value);
//! assert!((fp16.variance - exact.variance - added).abs() <= 1e-5 * added);
//! // A negative or non-finite noise is refused, and the renderer keeps its noise.
//! assert_eq!(r.set_lookup_noise(Noise { absolute: -1.0, relative: 0.0 }), Err(Error::InvalidNoise));
//! assert!(r.lookup_noise().relative > 0.0);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Bad input
//! A zero or non-finite normal or mirror direction gives [`Error::InvalidDirection`]; a NaN or
//! infinite lookup gives [`Error::InvalidRadiance`]. A mirror direction below the horizon
//! (`r·n < 0`) is treated as grazing, as [`GlossyRenderer`](super::GlossyRenderer) does: as its
//! projection onto the tangent plane.
//!
//! Lookups of any finite size are good input. For lookups `c·Y` the estimate is `c` times
//! that of `Y` and the variance `c²` times, to f32 rounding (exactly, for a power of two `c`),
//! with `+∞` only where the result exceeds `f32::MAX`; each channel is computed at its own
//! scale. A variance below the least positive f32 is rounded up to it, never to 0.
//!
//! # Cost
//! Instructions per call and flash on a Cortex-M4F: [`costs`](crate::costs#bmc-renderers).

use super::glossy::{interval, lobe_frame};
use super::{scaled, Size};
use crate::error::Error;
use crate::estimate::Estimate;
use crate::footprint::Kind;
use crate::math;
use crate::noise::{Noise, MAX_RELATIVE_NOISE};
use crate::radiance::{from_channels, Radiance, MAX_CHANNELS};
use crate::sf::FibonacciPoints;
use crate::vec3::Vec3;
use crate::warp::{Frame, Lobe};

/// Irradiance, `p(x) = max(0, n·x)`.
///
/// # Examples
/// ```
/// use sphere_quadrature::bmc::footprint::{Diffuse, FootprintRenderer};
/// use sphere_quadrature::Vec3;
///
/// // Constant radiance 1 gives the irradiance π.
/// let e = FootprintRenderer::<64, Diffuse>::new().estimate(&[1.0f32; 64])?;
/// assert!((e - core::f32::consts::PI).abs() < 1e-4);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Diffuse;

/// The normalised Phong lobe of exponent `E` about the mirror direction, with the cosine
/// factor and the horizon.
///
/// # Examples
/// ```
/// use sphere_quadrature::bmc::footprint::{FootprintRenderer, Phong};
/// use sphere_quadrature::Vec3;
///
/// // At normal incidence constant radiance 1 gives ∫ (e + 1)/(2π)·cosᵉθ·cos θ = (e + 1)/(e + 2).
/// let e = FootprintRenderer::<64, Phong<10>>::new().estimate(Vec3::Z, Vec3::Z, &[1.0f32; 64])?;
/// assert!((e - 11.0 / 12.0).abs() < 1e-3);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Phong<const E: u32>;

/// The integrand of a [`FootprintRenderer`]: [`Diffuse`] or [`Phong<E>`]; sealed.
///
/// # Examples
/// ```
/// use sphere_quadrature::bmc::footprint::{Brdf, Diffuse, FootprintRenderer, Phong};
/// use sphere_quadrature::bmc::{FootprintSize, Size};
///
/// // The same code for any baked integrand: the widest footprint of the set.
/// fn widest<B: Brdf>() -> u32
/// where
///     Size<32>: FootprintSize<B>,
/// {
///     FootprintRenderer::<32, B>::new()
///         .footprints()
///         .iter()
///         .map(|k| match k {
///             sphere_quadrature::footprint::Kind::Gaussian { sharpness } => *sharpness,
///             _ => u32::MAX,
///         })
///         .min()
///         .unwrap_or(0)
/// }
/// assert!(widest::<Diffuse>() >= 1 && widest::<Phong<50>>() >= 1);
/// ```
pub trait Brdf: sealed::Kind {}
impl Brdf for Diffuse {}
impl<const E: u32> Brdf for Phong<E> {}

footprint_size_diagnostic! {
    /// Implemented for exactly the sizes `N` whose footprint renderer tables are baked for `B`;
    /// sealed.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::bmc::footprint::{FootprintRenderer, Phong, BAKED_SETS};
    /// use sphere_quadrature::bmc::{FootprintSize, Size};
    ///
    /// fn renderer<const N: usize>() -> FootprintRenderer<N, Phong<50>>
    /// where
    ///     Size<N>: FootprintSize<Phong<50>>,
    /// {
    ///     FootprintRenderer::new()
    /// }
    /// let _ = renderer::<64>();
    /// assert!(BAKED_SETS.contains(&(64, 50)));
    /// ```
    pub trait FootprintSize<B: Brdf>: sealed::Sealed<B> {}
}

/// The baked `(N, e)` pairs, `e = 0` for [`Diffuse`].
///
/// # Examples
/// ```
/// use sphere_quadrature::bmc::footprint::BAKED_SETS;
///
/// assert!(BAKED_SETS.contains(&(32, 0)) && BAKED_SETS.contains(&(32, 10)));
/// ```
pub const BAKED_SETS: &[(usize, u32)] = crate::tables::FOOTPRINT_SETS;

/// The most models an error bar family may have.
const MAX_MODELS: usize = 64;

pub(crate) mod sealed {
    /// What `build.rs` baked for one `(N, BRDF)` (f32 bits, `gen/fp.rs`).
    #[derive(Clone, Copy, Debug)]
    pub struct Set {
        /// θₙ nodes (1 for irradiance).
        pub nodes: usize,
        /// Contrasts.
        pub k: usize,
        /// Family lengths.
        pub lengths: usize,
        /// `nodes·N` weights, node-major.
        pub weights: &'static [u32],
        /// `nodes·lengths`: the weights' error variance per family length, no nugget.
        pub residual: &'static [u32],
        /// `nodes`: `|w|²`.
        pub weight_norm: &'static [u32],
        /// `N·k` contrasts, row-major.
        pub contrasts: &'static [u32],
        /// `lengths·k·k` eigenvectors (columns of row-major `k×k` blocks).
        pub eigenvectors: &'static [u32],
        /// `lengths·k` eigenvalues.
        pub eigenvalues: &'static [u32],
        /// `lengths·nuggets` log-determinants.
        pub log_det: &'static [u32],
        /// `2·(nodes − 1)`: per interval, the interpolated weights' mass error `|Σδw|` and norm
        /// `|δw|₂` at its midpoint (empty for irradiance).
        pub interpolation: &'static [u32],
        /// `N` footprint sharpnesses.
        pub sharpness: &'static [u16],
        /// The factor on the error bar's standard deviation.
        pub calibration: f32,
    }

    pub trait Sealed<B> {
        const SET: Set;
    }

    pub trait Kind {
        /// The Phong exponent, 0 for irradiance.
        const EXPONENT: u32;
    }
    impl Kind for super::Diffuse {
        const EXPONENT: u32 = 0;
    }
    impl<const E: u32> Kind for super::Phong<E> {
        const EXPONENT: u32 = E;
    }
}

/// Bayesian Monte Carlo of the integral `B` from `N` footprint lookups, with baked weights
/// and an error bar from the most likely of a family of models (module docs). Holds only the
/// lookups' declared noise ([`set_lookup_noise`](Self::set_lookup_noise); none by default):
/// 8 bytes.
///
/// # Examples
/// ```
/// use sphere_quadrature::bmc::footprint::{Diffuse, FootprintRenderer};
/// use sphere_quadrature::{Error, Vec3};
///
/// let r = FootprintRenderer::<32, Diffuse>::new();
/// let n = Vec3::new(0.0, 0.6, 0.8);
/// let mut dirs = [Vec3::ZERO; 32];
/// r.fill_directions(n, &mut dirs)?;
/// // Light 1 + x·n seen through any footprint is 1 + g₁·x·n: irradiance π + (2π/3)·g₁ …
/// let lookups: [f32; 32] = core::array::from_fn(|j| {
///     let g1 = r.footprints()[j].gain(1).unwrap() as f32;
///     1.0 + g1 * dirs[j].dot(n)
/// });
/// let e = r.estimate(&lookups)?;
/// assert!((e - (core::f32::consts::PI + 2.0 * core::f32::consts::PI / 3.0)).abs() < 1e-3);
/// // … and a NaN lookup is an error.
/// let mut bad = lookups;
/// bad[3] = f32::NAN;
/// assert_eq!(r.estimate(&bad), Err(Error::InvalidRadiance));
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FootprintRenderer<const N: usize, B: Brdf>
where
    Size<N>: FootprintSize<B>,
{
    /// The lookups' noise, finite and non-negative (`set_lookup_noise` refuses any other).
    noise: Noise,
    brdf: core::marker::PhantomData<B>,
}

impl<const N: usize, B: Brdf> Clone for FootprintRenderer<N, B>
where
    Size<N>: FootprintSize<B>,
{
    fn clone(&self) -> Self {
        *self
    }
}

impl<const N: usize, B: Brdf> Copy for FootprintRenderer<N, B> where Size<N>: FootprintSize<B> {}

/// Two renderers of one type are equal when their lookup noise is.
impl<const N: usize, B: Brdf> PartialEq for FootprintRenderer<N, B>
where
    Size<N>: FootprintSize<B>,
{
    fn eq(&self, other: &Self) -> bool {
        self.noise == other.noise
    }
}

/// The noise is never NaN (`set_lookup_noise` refuses it), so equality is an equivalence.
impl<const N: usize, B: Brdf> Eq for FootprintRenderer<N, B> where Size<N>: FootprintSize<B> {}

impl<const N: usize, B: Brdf> Default for FootprintRenderer<N, B>
where
    Size<N>: FootprintSize<B>,
{
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize, B: Brdf> FootprintRenderer<N, B>
where
    Size<N>: FootprintSize<B>,
{
    const SET: sealed::Set = <Size<N> as sealed::Sealed<B>>::SET;
    const E: u32 = <B as sealed::Kind>::EXPONENT;

    /// The renderer, with exact lookups ([`Noise::NONE`]).
    #[must_use]
    pub const fn new() -> Self {
        Self { noise: Noise::NONE, brdf: core::marker::PhantomData }
    }

    /// Declares the lookups' noise: lookup `Yⱼ` has an independent error of variance
    /// `σ² + η²·Yⱼ²` (`σ = absolute`, in the lookups' units; `η = relative`), as rounding to
    /// fp16 or 8-bit sRGB gives ("Lookup noise" in the module docs). The estimate does not
    /// change; [`estimate_with_variance`](Self::estimate_with_variance) adds
    /// `Σ wⱼ²·(σ² + η²·Yⱼ²)` to each channel's variance (after the calibration factor), and
    /// leaves `unit_variance`, the model's, as it was. [`Noise::NONE`] (the default) adds
    /// nothing.
    ///
    /// # Errors
    /// [`Error::InvalidNoise`] for a negative, NaN or infinite `σ` or `η`, or `η` above
    /// [`MAX_RELATIVE_NOISE`]; the renderer keeps its noise.
    pub fn set_lookup_noise(&mut self, noise: Noise) -> Result<(), Error> {
        let valid = |x: f32| x.is_finite() && x >= 0.0;
        if !valid(noise.absolute) || !valid(noise.relative) || noise.relative > MAX_RELATIVE_NOISE {
            return Err(Error::InvalidNoise);
        }
        self.noise = noise;
        Ok(())
    }

    /// The lookups' declared noise ([`set_lookup_noise`](Self::set_lookup_noise)).
    #[must_use]
    pub const fn lookup_noise(&self) -> Noise {
        self.noise
    }

    /// The lobe frame `(t₁, t₂, a)`: for Phong `a = r` with `t₁` towards `n`; for irradiance
    /// `a = n`. Both vectors normalised; errors as the public calls.
    fn frame(normal: Vec3, mirror: Vec3) -> Result<[Vec3; 3], Error> {
        if Self::E == 0 {
            let n = normal.try_normalize().ok_or(Error::InvalidDirection)?;
            mirror.try_normalize().ok_or(Error::InvalidDirection)?;
            let f = Frame::from_unit(n);
            return Ok([f.t, f.b, n]);
        }
        lobe_frame(normal, mirror)
    }

    /// The `N` lookup directions for normal `n` and mirror direction `r` (both normalised
    /// first; the irradiance lobe does not depend on `r`).
    fn fill_directions_at(
        &self,
        normal: Vec3,
        mirror: Vec3,
        out: &mut [Vec3; N],
    ) -> Result<(), Error> {
        let [t1, t2, a] = Self::frame(normal, mirror)?;
        let set = FibonacciPoints::hemisphere(N)?;
        let lobe = if Self::E == 0 { Lobe::Cosine } else { Lobe::Phong(Self::E as f32) };
        let frame = Frame { t: t1, b: t2, n: a };
        for (j, slot) in out.iter_mut().enumerate() {
            *slot = set.morphed(j, lobe, &frame);
        }
        Ok(())
    }

    /// The footprint of each lookup, in the order of the directions (`fill_directions`):
    /// normalised spherical Gaussians.
    #[must_use]
    pub fn footprints(&self) -> [Kind; N] {
        let s = Self::SET.sharpness;
        core::array::from_fn(|j| Kind::Gaussian {
            sharpness: u32::from(s.get(j).copied().unwrap_or(1)),
        })
    }

    /// The node interval and its coefficients for `(n, r)`.
    fn rows(normal: Vec3, mirror: Vec3) -> Result<(usize, [f32; 2]), Error> {
        if Self::SET.nodes == 1 {
            normal.try_normalize().ok_or(Error::InvalidDirection)?;
            mirror.try_normalize().ok_or(Error::InvalidDirection)?;
            return Ok((0, [1.0, 0.0]));
        }
        interval(normal, mirror)
    }

    /// Row `k` of a node-major table of `width` entries per node.
    fn row(table: &'static [u32], k: usize, width: usize) -> Result<&'static [u32], Error> {
        table.get(k * width..(k + 1) * width).ok_or(Error::Internal)
    }

    /// The interpolated weights for `(n, r)`, in the order of the directions.
    fn weights_at(&self, normal: Vec3, mirror: Vec3, out: &mut [f32; N]) -> Result<(), Error> {
        let (k, [alpha, beta]) = Self::rows(normal, mirror)?;
        let a = Self::row(Self::SET.weights, k, N)?;
        let b = if beta == 0.0 { a } else { Self::row(Self::SET.weights, k + 1, N)? };
        for ((o, &a), &b) in out.iter_mut().zip(a).zip(b) {
            *o = alpha * f32::from_bits(a) + beta * f32::from_bits(b);
        }
        Ok(())
    }

    /// `Σ wⱼYⱼ` for `(n, r)`.
    fn estimate_at<T: Radiance>(
        &self,
        normal: Vec3,
        mirror: Vec3,
        lookups: &[T; N],
    ) -> Result<T, Error> {
        let () = crate::radiance::Channels::<T>::VALID;
        let (k, [alpha, beta]) = Self::rows(normal, mirror)?;
        let a = Self::row(Self::SET.weights, k, N)?;
        // Σ wⱼYⱼ = α·Σ aⱼYⱼ + β·Σ bⱼYⱼ (the interpolation fused into the sums, as
        // `GlossyRenderer::estimate`); one row for irradiance.
        let sum = if beta == 0.0 {
            let mut s = T::ZERO;
            for (&y, &a) in lookups.iter().zip(a) {
                s = s.mul_add(y, f32::from_bits(a));
            }
            s.scale(alpha)
        } else {
            let b = Self::row(Self::SET.weights, k + 1, N)?;
            let (mut sa, mut sb) = (T::ZERO, T::ZERO);
            for ((&y, &a), &b) in lookups.iter().zip(a).zip(b) {
                sa = sa.mul_add(y, f32::from_bits(a));
                sb = sb.mul_add(y, f32::from_bits(b));
            }
            sa.scale(alpha).add(sb.scale(beta))
        };
        if scaled::in_range(sum) {
            return Ok(sum);
        }
        // Not finite, or too small to trust: the lookups checked and summed at their own scale.
        let b = if beta == 0.0 { a } else { Self::row(Self::SET.weights, k + 1, N)? };
        scaled::rescaled_sum(lookups, |j| {
            let w = |row: &[u32]| row.get(j).map_or(0.0, |&w| f32::from_bits(w));
            alpha * w(a) + beta * w(b)
        })
    }

    /// The lookups' relative noise in the units of the scaled lookups `y`: `η²·Σ(wⱼyⱼ)²`
    /// (added after the calibration; 0 without relative noise).
    fn relative_lookup_noise(&self, y: &[f32; N], w: &[f32; N]) -> f32 {
        if self.noise.relative > 0.0 {
            let sum_sq: f32 = y.iter().zip(w).map(|(&y, w)| (w * y) * (w * y)).sum();
            self.noise.relative * self.noise.relative * sum_sq
        } else {
            0.0
        }
    }

    /// The lookups' absolute noise in their own units: `(σ·|w|₂)²`, the same for every
    /// channel (the product first: `σ²` alone may overflow where the result does not).
    fn absolute_lookup_noise(&self, w: &[f32; N]) -> f32 {
        if self.noise.absolute > 0.0 {
            let s = self.noise.absolute * math::sqrt(w.iter().map(|w| w * w).sum::<f32>());
            s * s
        } else {
            0.0
        }
    }

    /// `estimate_at` with its error bar (the public calls' docs).
    fn estimate_with_variance_at<T: Radiance>(
        &self,
        normal: Vec3,
        mirror: Vec3,
        lookups: &[T; N],
    ) -> Result<Estimate<T>, Error> {
        let value = self.estimate_at(normal, mirror, lookups)?;
        let set = Self::SET;
        let (node, [alpha, beta]) = Self::rows(normal, mirror)?;
        let nuggets = &crate::tables::FOOTPRINT_NUGGETS;
        let models = set.lengths * nuggets.len();
        if models == 0 || models > MAX_MODELS || set.k == 0 || set.k > N {
            return Err(Error::Internal);
        }
        // (More channels than MAX_CHANNELS do not compile: `estimate` checks the type.)
        let channels = T::CHANNELS;
        if channels > MAX_CHANNELS {
            return Err(Error::Internal);
        }
        let unit = Self::model_errors(node, alpha, beta)?;
        let mut w = [0.0f32; N];
        self.weights_at(normal, mirror, &mut w)?;
        let interpolation =
            |i: usize| set.interpolation.get(2 * node + i).map_or(0.0, |&b| f32::from_bits(b));
        // Linear interpolation's error grows as 4αβ from the nodes to the midpoint.
        let shape = 4.0 * alpha * beta;
        let errors = if beta == 0.0 {
            (0.0, 0.0)
        } else {
            (shape * interpolation(0), shape * interpolation(1))
        };
        // Per channel and model: σ̂² of the centred channel scaled to max |y − ȳ| = 1, and the
        // log likelihood, pooled over the channels.
        let mut log_lik = [0.0f32; MAX_MODELS];
        let mut signal = [[0.0f32; MAX_MODELS]; MAX_CHANNELS];
        let mut stats = [ChannelStats::ZERO; MAX_CHANNELS];
        for (c, (signal, stats)) in signal.iter_mut().zip(&mut stats).take(channels).enumerate() {
            let y;
            (y, *stats) = self.channel_stats(lookups, c, &w, errors);
            if stats.scale > 0.0 {
                let t = Self::contrasts(&y, stats.mean, 1.0 / stats.scale)?;
                Self::accumulate_models(
                    t.get(..set.k).ok_or(Error::Internal)?,
                    signal,
                    &mut log_lik,
                )?;
            }
        }
        let log_lik = log_lik.get(..models).ok_or(Error::Internal)?;
        // The most likely model (the first of equals).
        let (best, _) = log_lik.iter().enumerate().fold((0, f32::NEG_INFINITY), |b, (i, &l)| {
            if l > b.1 {
                (i, l)
            } else {
                b
            }
        });
        let f2 = set.calibration * set.calibration;
        let unit_best = unit.get(best).copied().unwrap_or(0.0);
        let unit_variance = f2 * unit_best;
        let absolute = self.absolute_lookup_noise(&w);
        let variance = from_channels::<T>(|c| {
            let (Some(signal), Some(stats)) = (signal.get(c), stats.get(c)) else {
                return 0.0;
            };
            let normalised = if stats.scale == 0.0 {
                f2 * stats.numeric
            } else {
                let s = signal.get(best).copied().unwrap_or(0.0);
                f2 * (s * unit_best * stats.scale * stats.scale + stats.numeric)
            };
            if stats.lookup == 0.0 && absolute == 0.0 {
                return math::ldexp_variance(normalised, 2 * stats.binade);
            }
            math::ldexp_variance(normalised + stats.lookup, 2 * stats.binade) + absolute
        });
        Ok(Estimate { value, variance, unit_variance: Some(unit_variance) })
    }

    /// The weights' error variance under each model (length, then nugget): `a_l + σ′²·|w|²`,
    /// interpolated between the nodes as the weights are.
    fn model_errors(node: usize, alpha: f32, beta: f32) -> Result<[f32; MAX_MODELS], Error> {
        let set = Self::SET;
        let nuggets = &crate::tables::FOOTPRINT_NUGGETS;
        // A per-node table entry, interpolated as the weights are.
        let at = |table: &'static [u32], width: usize, i: usize| -> Result<f32, Error> {
            let get = |n: usize| table.get(n * width + i).map(|&b| f32::from_bits(b));
            let a = get(node).ok_or(Error::Internal)?;
            let b = if beta == 0.0 { a } else { get(node + 1).ok_or(Error::Internal)? };
            Ok(alpha * a + beta * b)
        };
        let norm = at(set.weight_norm, 1, 0)?;
        let mut unit = [0.0f32; MAX_MODELS];
        for (li, row) in unit.chunks_exact_mut(nuggets.len()).take(set.lengths).enumerate() {
            let a = at(set.residual, set.lengths, li)?.max(0.0);
            for (u, &s2) in row.iter_mut().zip(nuggets) {
                *u = a + f32::from_bits(s2) * norm;
            }
        }
        Ok(unit)
    }

    /// Channel `c` of the lookups divided by the power of two `2^k` at its largest |y| (exact:
    /// nothing after depends on the units, the variance is multiplied by `2^2k` last), and its
    /// statistics. `(mass_error, norm_error)`: the interpolation's error in `Σw` and `|w|₂`.
    fn channel_stats<T: Radiance>(
        &self,
        lookups: &[T; N],
        c: usize,
        w: &[f32; N],
        (mass_error, norm_error): (f32, f32),
    ) -> ([f32; N], ChannelStats) {
        let binade = scaled::channel_binade(lookups, c);
        let y: [f32; N] = core::array::from_fn(|j| {
            lookups.get(j).map_or(0.0, |y| math::ldexp(y.channel(c), -binade))
        });
        // Centred (the contrasts ignore constants; centring makes a constant channel's
        // contrasts exactly 0) and scaled to max |y − ȳ| = 1.
        let mean = y.iter().sum::<f32>() / N as f32;
        let top = y.iter().fold(0.0f32, |m, &y| m.max(math::abs(y - mean)));
        // The arithmetic's own error, apart from the model: f32 rounding of the weights and
        // the sum, about (√N + 1)·2⁻²⁴·Σ|wⱼyⱼ|, and the interpolation between the θₙ nodes,
        // about |Σδw|·|ȳ| + |δw|₂·max|y − ȳ| (δw measured at the interval's midpoint).
        let sum_abs: f32 = y.iter().zip(w).map(|(&y, w)| math::abs(w * y)).sum();
        let rounding = (math::sqrt(N as f32) + 1.0) * f32::EPSILON * 0.5 * sum_abs;
        let interp = mass_error * math::abs(mean) + norm_error * top;
        let stats = ChannelStats {
            binade,
            mean,
            scale: top,
            numeric: rounding * rounding + interp * interp,
            lookup: self.relative_lookup_noise(&y, w),
        };
        (y, stats)
    }

    /// `t = Aᵀ(y − ȳ)·inv`, the contrasts of the centred lookups (first `k` entries).
    fn contrasts(y: &[f32; N], mean: f32, inv: f32) -> Result<[f32; N], Error> {
        let k = Self::SET.k;
        let mut t = [0.0f32; N];
        let contrasts = Self::SET.contrasts.get(..N * k).ok_or(Error::Internal)?;
        for (&y, row) in y.iter().zip(contrasts.chunks_exact(k)) {
            let y = (y - mean) * inv;
            for (tj, &a) in t.iter_mut().zip(row) {
                *tj += f32::from_bits(a) * y;
            }
        }
        Ok(t)
    }

    /// For contrasts `t`, each model's `σ̂² = vᵀ(Λ + s²)⁻¹v/k` (`v = Wᵀt` in the eigenbasis of
    /// `AᵀK_lA`) into `signal`, and its log likelihood added to `log_lik`.
    fn accumulate_models(
        t: &[f32],
        signal: &mut [f32; MAX_MODELS],
        log_lik: &mut [f32; MAX_MODELS],
    ) -> Result<(), Error> {
        let set = Self::SET;
        let nuggets = &crate::tables::FOOTPRINT_NUGGETS;
        let (k, lengths) = (set.k, set.lengths);
        let models = lengths * nuggets.len();
        let vectors = set.eigenvectors.get(..lengths * k * k).ok_or(Error::Internal)?;
        let values = set.eigenvalues.get(..lengths * k).ok_or(Error::Internal)?;
        let log_det = set.log_det.get(..models).ok_or(Error::Internal)?;
        let blocks = vectors.chunks_exact(k * k).zip(values.chunks_exact(k));
        let per_length =
            signal.chunks_exact_mut(nuggets.len()).zip(log_lik.chunks_exact_mut(nuggets.len()));
        for (((vectors, values), (signal, log_lik)), log_det) in
            blocks.zip(per_length).zip(log_det.chunks_exact(nuggets.len()))
        {
            let mut v = [0.0f32; N];
            for (&ti, row) in t.iter().zip(vectors.chunks_exact(k)) {
                for (vj, &e) in v.iter_mut().zip(row) {
                    *vj += f32::from_bits(e) * ti;
                }
            }
            for (((s, ll), &d), &s2) in signal.iter_mut().zip(log_lik).zip(log_det).zip(nuggets) {
                let s2 = f32::from_bits(s2);
                let q: f32 =
                    v.iter().zip(values).map(|(&v, &lam)| v * v / (f32::from_bits(lam) + s2)).sum();
                *s = q / k as f32;
                if *s > 0.0 {
                    *ll += -0.5 * k as f32 * math::ln(*s) - 0.5 * f32::from_bits(d);
                }
            }
        }
        Ok(())
    }
}

/// One channel's statistics for the error bar, its lookups scaled by `2^−binade`.
#[derive(Clone, Copy)]
struct ChannelStats {
    binade: i32,
    /// The mean of the scaled lookups.
    mean: f32,
    /// `max |y − ȳ|`.
    scale: f32,
    /// The arithmetic's own error variance (rounding and interpolation).
    numeric: f32,
    /// The lookups' relative noise.
    lookup: f32,
}

impl ChannelStats {
    const ZERO: Self = Self { binade: 0, mean: 0.0, scale: 0.0, numeric: 0.0, lookup: 0.0 };
}

/// Irradiance: the lobe is the cosine about the normal, and its weights depend on nothing else.
impl<const N: usize> FootprintRenderer<N, Diffuse>
where
    Size<N>: FootprintSize<Diffuse>,
{
    /// Writes the `N` lookup directions about `normal` (normalised first), in the order of
    /// the weights and [`footprints`](Self::footprints).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite normal.
    pub fn fill_directions(&self, normal: Vec3, out: &mut [Vec3; N]) -> Result<(), Error> {
        self.fill_directions_at(normal, normal, out)
    }

    /// The weights, in the order of [`fill_directions`](Self::fill_directions) (one baked
    /// node: they depend on no direction).
    ///
    /// # Errors
    /// None for a baked set ([`Error::Internal`] would report a malformed table).
    pub fn weights(&self, out: &mut [f32; N]) -> Result<(), Error> {
        self.weights_at(Vec3::Z, Vec3::Z, out)
    }

    /// Irradiance from the lookups `Y` in the directions of
    /// [`fill_directions`](Self::fill_directions), through [`footprints`](Self::footprints):
    /// `Σ wⱼYⱼ`, O(N).
    ///
    /// # Errors
    /// [`Error::InvalidRadiance`] for a NaN or infinite lookup.
    pub fn estimate<T: Radiance>(&self, lookups: &[T; N]) -> Result<T, Error> {
        self.estimate_at(Vec3::Z, Vec3::Z, lookups)
    }

    /// [`estimate`](Self::estimate) with its error bar: the variance per channel under the
    /// family's model most likely for the lookups (the channels' likelihoods pooled), times
    /// the calibration factor squared. `unit_variance` is that model's error variance for a
    /// signal variance of 1. Added to each channel's variance before the calibration: the
    /// arithmetic's own error (f32 rounding of the weighted sum), which is all a channel
    /// whose lookups are equal has. Added after it: the declared lookup noise's
    /// `Σ wⱼ²·(σ² + η²·Yⱼ²)` ([`set_lookup_noise`](Self::set_lookup_noise); none by default).
    ///
    /// # Errors
    /// As [`estimate`](Self::estimate).
    pub fn estimate_with_variance<T: Radiance>(
        &self,
        lookups: &[T; N],
    ) -> Result<Estimate<T>, Error> {
        self.estimate_with_variance_at(Vec3::Z, Vec3::Z, lookups)
    }
}

/// A Phong lobe about the mirror direction, clipped by the surface: directions and weights
/// depend on the normal and the mirror direction.
impl<const N: usize, const E: u32> FootprintRenderer<N, Phong<E>>
where
    Size<N>: FootprintSize<Phong<E>>,
{
    /// Writes the `N` lookup directions for normal `n` and mirror direction `r` (both
    /// normalised first), in the order of the weights and [`footprints`](Self::footprints).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite vector.
    pub fn fill_directions(
        &self,
        normal: Vec3,
        mirror: Vec3,
        out: &mut [Vec3; N],
    ) -> Result<(), Error> {
        self.fill_directions_at(normal, mirror, out)
    }

    /// The weights for `(n, r)`, interpolated between the baked angles, in the order of
    /// [`fill_directions`](Self::fill_directions).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite vector.
    pub fn weights(&self, normal: Vec3, mirror: Vec3, out: &mut [f32; N]) -> Result<(), Error> {
        self.weights_at(normal, mirror, out)
    }

    /// The integral from the lookups `Y` in the directions of
    /// [`fill_directions`](Self::fill_directions), through [`footprints`](Self::footprints):
    /// `Σ wⱼYⱼ`, O(N).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite vector, [`Error::InvalidRadiance`]
    /// for a NaN or infinite lookup.
    pub fn estimate<T: Radiance>(
        &self,
        normal: Vec3,
        mirror: Vec3,
        lookups: &[T; N],
    ) -> Result<T, Error> {
        self.estimate_at(normal, mirror, lookups)
    }

    /// [`estimate`](Self::estimate) with its error bar: the variance per channel under the
    /// family's model most likely for the lookups (the channels' likelihoods pooled), times
    /// the calibration factor squared. `unit_variance` is that model's error variance for a
    /// signal variance of 1. Added to each channel's variance before the calibration: the
    /// arithmetic's own error (f32 rounding of the weighted sum, and the interpolation of the
    /// weights between the baked `θₙ` nodes: the error measured at each interval's midpoint
    /// when baked, times `4t(1 − t)` at the fraction `t` of the interval), which is all a
    /// channel whose lookups are equal has. Added after it: the declared lookup noise's
    /// `Σ wⱼ²·(σ² + η²·Yⱼ²)` ([`set_lookup_noise`](Self::set_lookup_noise); none by default).
    ///
    /// # Errors
    /// As [`estimate`](Self::estimate).
    pub fn estimate_with_variance<T: Radiance>(
        &self,
        normal: Vec3,
        mirror: Vec3,
        lookups: &[T; N],
    ) -> Result<Estimate<T>, Error> {
        self.estimate_with_variance_at(normal, mirror, lookups)
    }
}
