//! A lighting probe: `N` radiance samples in, irradiance with an error bar for any normal out,
//! by Bayesian Monte Carlo with per-probe hyperparameter selection.
//!
//! The probe samples radiance in the `N` directions of the spherical Fibonacci sphere set
//! (optionally rotated as a whole, for example anew at every update), then answers any number
//! of irradiance queries `E(n) = ∫ L(x)·max(0, n·x) dx`.
//!
//! # Model
//! The Gaussian-process model of [`crate::bmc`] (Rasmussen and Ghahramani 2002): kernel
//! `k(x, x′) = σ_f²·(exp(λ(x·x′ − 1)) + σ′²δ)`, constant prior mean `β` by generalised least
//! squares, `Q = K + σ′²I`. With an isotropic kernel `Q` depends only on the set's dot
//! products, so one baked `Q⁻¹` serves every rotation of the set.
//! - [`Probe::update`]: `β = 1ᵀQ⁻¹Y/1ᵀQ⁻¹1` and `α = Q⁻¹(Y − β1)`, O(N²) (`N²/2`
//!   multiply-adds per family member: the set is symmetric under a half-turn, which splits
//!   `Q` into two `N/2` blocks, each solved with its baked f32 Cholesky factor; see
//!   `gen/probe.rs`).
//! - [`Probe::irradiance`]: `E(n) = π·β + Σᵢ π·z(xᵢ·n)·αᵢ`, O(N), where
//!   `z(t) = ∫ exp(λ(μ·x − 1))·max(0, n·x)/π dx` at `μ·n = t` comes from a baked
//!   129-node table of local quadratics.
//! - [`Probe::glossy`]: `∫ L·G` for a spherical-Gaussian lobe `G` (normalised Phong about the
//!   mirror direction with [`SphericalGaussian::phong_moments`]), `β·∫G + Σᵢ zᵢ·αᵢ` in O(N)
//!   with `zᵢ` in closed form (the kernel is an SG as well), and a baked direction-averaged
//!   variance interpolated in the lobe sharpness; [`Probe::glossy_variance`] is its exact
//!   posterior variance in O(N²).
//! - [`Probe::radiance_sh`]: the posterior mean as the 9 spherical-harmonic coefficients
//!   (`l ≤ 2`) that renderers take, exactly (Funk–Hecke: `c_lm = β·√(4π)·δ_l0 +
//!   k̂_l·Σᵢ αᵢ·Y_lm(xᵢ)`), O(9N); [`Probe::radiance_sh_variance`] their posterior variances,
//!   O(9·N²/2). [`crate::sh`] evaluates irradiance from them in O(9), rotates them and
//!   converts them to three.js, Filament and Unity.
//! - **Per-probe selection** (local adaptation): `build.rs` bakes a small *family* of
//!   sharpnesses `λ` (one `σ′`); each update computes, for every member, the restricted
//!   (REML) log marginal likelihood with `σ_f` profiled out,
//!   `ℓ = −½·log det Q − ½·log 1ᵀQ⁻¹1 − ((N − 1)/2)·log(rᵀQ⁻¹r)`, `r = Y − β1`
//!   (per channel, summed over channels for RGB), and keeps the member with the highest `ℓ`.
//! - **Error bar**: `σ̂_f² = rᵀQ⁻¹r/(N − 1)` per channel (the REML estimate) times the unit
//!   posterior variance `π²(V̄ − zᵀQ⁻¹z + (1 − 1ᵀQ⁻¹z)²/1ᵀQ⁻¹1)` (Rasmussen and Williams
//!   2006, eq. 2.42). [`Probe::irradiance`] uses the unit variance averaged over directions
//!   (baked; O(1)); [`Probe::irradiance_variance`] computes it exactly for `n` in O(N²).
//! - **Calibration**: on real lighting that bar is too narrow (point samples alias bright
//!   features the model does not see: 2σ held for 51–60 % of irradiance queries on the
//!   `clamp` tier of the held-out maps). Every variance the probe reports is therefore
//!   multiplied by a per-member factor [`Member::calibration`] (irradiance; glossy at lobe
//!   sharpness μ = 7, 22, 102, linear in `ln μ` between), fitted offline so that 95 % of the
//!   errors on the training maps fall within 2σ (`xtask/writers/src/bin/probe_calibration.rs` writes the
//!   `calibration = …` lines of `tables/probe.txt`; `docs/probe_trust.md`). On the held-out
//!   maps, with the f64 engine of that program, 2σ then holds for 94–99 % of the `clamp`
//!   queries and 96–100 % of the `smooth` ones at N = 16 … 256 (irradiance and Phong
//!   e = 5, 20, 100); the crate's own figures are in `docs/accuracy.md` and `docs/glossy.md`.
//!   The factors range from 0.2 to 744: a member chosen mostly on aliased data gets wide bars
//!   on smooth data too (the smooth tier's N = 16 bars over-cover, 100 %). Divide by the
//!   factor for the model's own variance.
//! - **Channel covariance**: one kernel serves every channel, so the covariance of channels
//!   `a`, `b` of an estimate is the REML channel covariance `S_ab = r_aᵀQ⁻¹r_b/(N − 1)`
//!   ([`Probe::signal_covariance`]; `S_cc = σ̂_f²`) times the query's unit variance
//!   ([`Estimate::unit_variance`]). [`Probe::signal_variance_of`] gives `wᵀSw` for channel
//!   weights `w` (luminance, say) and [`Probe::combine`] an estimate of `Σ_c w_c·value_c` with
//!   its variance.
//!
//! ```
//! use sphere_quadrature::{probe::Probe, Vec3};
//!
//! let mut probe = Probe::<64>::new();
//! // Measure the radiance in each direction; here a sky brighter towards +z.
//! let samples = probe.directions().map(|d| 1.0 + 0.5 * d.z);
//! probe.update(&samples)?;
//! let e = probe.irradiance(Vec3::Z)?;
//! // Exact: π·(1 + 0.5·2/3) = 4.18879; the nugget σ′ smooths a little.
//! assert!((e.value - 4.18879).abs() < 0.02);
//! assert!(e.variance >= 0.0);
//! // A constant is exact, with zero variance.
//! probe.update(&[2.0; 64])?;
//! let e = probe.irradiance(Vec3::new(0.3, -0.4, 0.2))?;
//! assert!((e.value - 2.0 * core::f32::consts::PI).abs() < 1e-5 && e.variance == 0.0);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Footprints
//! A sample may integrate the radiance against a known lobe instead of reading it at a point:
//! a mip level or prefiltered map, a cone, a light sensor's angular response. The third type
//! parameter says which: `Probe<N, T, F>` with `F` one of [`crate::footprint`]'s
//! [`Point`] (the default), [`Gaussian<S>`](crate::footprint::Gaussian) (the normalised SG of
//! sharpness `S`) or [`CosinePower<P>`](crate::footprint::CosinePower) (a photodiode for
//! `P = 1`). The model then accounts for the footprint exactly: with the kernel's Legendre
//! coefficients `K_l` and the footprint's gains `g_l`,
//! `Cov(Yᵢ, Yⱼ) = Σ K_l g_l² (2l + 1)/(4π)·P_l(xᵢ·xⱼ) + σ′²δ` and
//! `Cov(Yᵢ, E(n)) = Σ K_l g_l c_l (2l + 1)/(4π)·P_l(xᵢ·n)`, while the prior variance `V̄` of
//! the integral of the *unfiltered* radiance keeps `c_l²`; `Q` stays rotation invariant, so
//! one bake serves every rotation, and every query costs what it costs for point samples.
//! - Gaussian footprint: the kernel on the radiance is the spherical Gaussian of sharpness
//!   `ν < S` *deconvolved* by the footprint, `K_l = F(ν)·ρ_l(ν)/ρ_l(S)` (`ρ_l = i_l/i₀`, close to
//!   the squared exponential of sharpness `νS/(S − ν)`), chosen so that a sample's
//!   covariance with the radiance is exactly `exp(ν(x·xᵢ − 1))`: the irradiance table and the
//!   glossy `zᵢ` are those of a point member of sharpness `ν`, and the family's
//!   [`Member::lambda`] is `ν`.
//! - Cosine-power footprint: the squared-exponential kernel; the irradiance table comes from
//!   the Legendre series at build time, and [`Probe::glossy`] sums
//!   `Σ_l K_l g_l Λ_l(μ)(2l + 1)/(4π)·P_l(xᵢ·r)` per sample (`16 + 9.1√λ` terms, the Bessel
//!   ratios `Λ_l/Λ₀ = i_l(μ)/i₀(μ)` once per query), so its glossy query costs more than a
//!   point probe's (the crate's Cortex-M4 cost tables).
//!
//! On real maps footprint samples cut the irradiance error by 40–200× against the
//! cosine-weighted average of point samples at the same `N` (held-out maps, N = 16…256, mean of
//! per-map ratios; `eval/src/bin/footprint.rs`,
//! `docs/footprint.md`). [`crate::envmap`] takes footprint samples of an equirectangular map.
//!
//! ```
//! use sphere_quadrature::footprint::Gaussian;
//! use sphere_quadrature::{probe::Probe, Vec3};
//!
//! // 64 samples, each the map filtered by the normalised SG of sharpness 8 (N/8).
//! let mut probe = Probe::<64, f32, Gaussian<8>>::new();
//! // A sky 1 + 0.5·z filtered by any normalised lobe is 1 + 0.5·g₁·z (Funk–Hecke).
//! let g1 = sphere_quadrature::footprint::Kind::Gaussian { sharpness: 8 }.gain(1)? as f32;
//! let samples = probe.directions().map(|d| 1.0 + 0.5 * g1 * d.z);
//! probe.update(&samples)?;
//! let e = probe.irradiance(Vec3::Z)?;
//! // The irradiance of the *unfiltered* sky: π·(1 + 0.5·2/3).
//! assert!((e.value - 4.18879).abs() < 0.02);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! A size without a baked family does not compile, nor does a footprint without one:
//! ```compile_fail,E0277
//! let _ = sphere_quadrature::probe::Probe::<18>::new();
//! ```
//! ```compile_fail,E0277
//! use sphere_quadrature::footprint::Gaussian;
//! let _ = sphere_quadrature::probe::Probe::<64, f32, Gaussian<5>>::new();
//! ```
//!
//! # Radiance scale
//! Samples may be in any units: for `c·Y` every value is `c` times and every variance `c²`
//! times the answer for `Y`. The update centres each channel on its first sample `Y₀` and
//! divides it by the power of two `s = 2^k` nearest below its largest `|Yᵢ − Y₀|` (exact),
//! so the solves, `rᵀQ⁻¹r` and the likelihood see O(1) numbers whatever the units; the probe
//! stores `α/s`, `σ̂_f²/s²`, `s` and `β`, and every query applies `s` (and a glossy lobe's
//! amplitude `a`) last, in mantissa and exponent apart where f32 could overflow or underflow
//! in between.
//! - For `c` a power of two the answers are `c` (`c²`) times, bit for bit, wherever they
//!   are normal f32 numbers. For other `c` the samples `c·Y` round differently from `Y`,
//!   which moves an answer as any f32 perturbation of the samples does: measured from
//!   `c = 10⁻³⁰` to `10³⁰`, 10⁻⁷–7·10⁻⁵ relative for members with `cond(Q) ≤ 10⁴`, up to
//!   1.1·10⁻³ for the smoothest (`cond(Q)` 3·10⁴–3·10⁵: one ulp of input moves their
//!   answers by up to 6·10⁻⁴; `tests/hardening/scale.rs`).
//! - A result beyond `f32::MAX` is `±∞`, never 0, NaN or a wrong finite value: the
//!   variances once the samples spread over more than about 10¹⁹ (`σ̂_f² > f32::MAX`) or a
//!   glossy amplitude times that spread does; a value when it exceeds `f32::MAX` itself (the
//!   irradiance of a constant above `f32::MAX/π`, while the normalised Phong and glossy
//!   averages of the same constant stay finite); all of them when the GLS mean `β` itself
//!   exceeds `f32::MAX` (samples near `±f32::MAX` with weights that extrapolate). A result
//!   below the normal range is 0 or subnormal.
//! - [`Estimate::unit_variance`] is a plain f32 product: `+∞` when a glossy amplitude `a`
//!   makes `a²` times the unit variance exceed `f32::MAX`, though the estimate's variance
//!   fits.
//! - Channels are scaled each by its own `s`: a channel 10³⁸ times smaller than another
//!   loses nothing.
//! - The log likelihood is that of the samples as given: `ℓ(c·Y) = ℓ(Y) − (N − 1)·C·ln c`
//!   for `C` channels; the selection does not depend on `c` (up to near ties, which the
//!   rounding of `c·Y` can flip).
//!
//! # Missing samples
//! A ray budget is cut, a ray hits a back face, a sensor reads nothing:
//! [`Probe::update_masked`] takes the samples with a validity mask and fits the valid ones
//! exactly, as if the probe had only their directions. The fourth type parameter is the
//! capacity, the most samples that may be missing: `Probe<64, [f32; 3], Point, 16>` (the
//! default `M = 0` takes all-valid masks only). Values at missing positions are never read.
//! - **Method**: the baked factors of the full `Q`, corrected for the `m ≤ M` missing
//!   indices by the block inverse `Q_VV⁻¹ = P_VV − P_VM·P_MM⁻¹·P_MV` (`P = Q⁻¹`): `P_MM`
//!   from `m` forward substitutions of unit vectors through the two half blocks, an `m × m`
//!   LDLᵀ factor in f32 on fixed-capacity `heapless` storage, and one solve of the residual
//!   with the missing entries replaced by the GP's prediction of them (`src/probe/missing.rs`).
//!   `β`, `α` (zero at the missing samples), `σ̂_f²` with `N − m` samples, the REML likelihood
//!   (`log det Q_VV = log det Q + log det P_MM`) and the member selection are those of the
//!   valid subset.
//! - **Queries**: every value, the exact variances ([`Probe::irradiance_variance`],
//!   [`Probe::glossy_variance`], [`Probe::phong_variance`]: the probe keeps the selected
//!   member's `P_MM` factor for their Schur correction) and the channel covariance
//!   ([`Probe::signal_covariance`], [`Probe::signal_variance_of`], [`Probe::combine`]) and
//!   the SH export ([`Probe::radiance_sh`], [`Probe::radiance_sh_variance`]) answer for the
//!   valid subset. The O(1) variances of [`Probe::irradiance`],
//!   [`Probe::glossy`] and [`Probe::phong`] are σ̂_f² of the valid samples times the *full*
//!   set's baked direction-averaged unit variance (and [`Estimate::unit_variance`] is that
//!   average): they do not see the holes, which raise the variance near the missing
//!   directions. Measured at `N = 64` (`λ = 4`, `tests/probe/missing.rs`), the direction average
//!   of the exact variance is 3.5× the O(1) one with 3 samples missing, 55× with 16 and 160×
//!   with 32: after a masked update, take error bars from the exact queries.
//! - **Accuracy** (`tests/probe/missing.rs`, against an f64 reference that builds `Q_VV` from the
//!   valid directions and solves it by LU; every member, N = 16, 64, 256, 1 to 50 % missing):
//!   irradiance within 10⁻⁵ RMS for members with `cond(Q) ≤ 10⁴` (measured ≤ 6·10⁻⁶), the
//!   forward bound `cond(Q)·ε₃₂` for the smoother ones (measured 4·10⁻⁵–2·10⁻³, a few times
//!   the full update's own error); exact irradiance, glossy and Phong variances within
//!   5·10⁻³; σ̂_f² within 10⁻⁴; ℓ within 10⁻⁴ (3·10⁻³ for `λ = 1` at `N = 256` with 128
//!   missing, inside the forward bound); the selection is the reference's argmax. Gaussian
//!   footprints (`Gaussian<8>`, N = 64, 16 missing) against a closed-form reference of their
//!   sample covariance: irradiance within the same bars (9·10⁻⁴ at `cond(Q)` 2.8·10⁵), the
//!   exact variance's increase over the full set's within 4·10⁻³.
//! - **On real maps** (`eval/src/bin/missing.rs`, `docs/missing.md`; `clamp` tier, held-out maps,
//!   a seeded random subset missing): the masked probe's irradiance error over the
//!   cosine-weighted average of the valid samples, mean of per-map ratios at 5 / 25 / 50 %
//!   missing, is 0.83 / 0.83 / 0.84 at N = 16, 0.92 / 0.95 / 0.90 at N = 64 and
//!   0.96 / 0.90 / 0.96 at N = 256: it keeps the full probe's advantage (0.84, 0.94, 0.995
//!   with none missing) but does not add to it.
//! - **Cost**: per family member, forward substitutions of the distinct missing pairs' unit
//!   vectors (`(N/2 − p)²/2` multiply-adds each), their Gram products (`m²·N/6` on average),
//!   an `m³/6` factorisation and one forward substitution of the samples on top of
//!   [`Probe::update`]'s solve. Cortex-M4 at `N = 64`: 297 460 instructions with 8 missing,
//!   573 860 with 16, against 88 800 for [`Probe::update`]. Memory: the probe grows by
//!   the missing indices and factor, `4M² + 6M` bytes and a few words; the update uses
//!   another `4·M·N + 8M²` bytes of stack. Each exact-variance query does one more back
//!   substitution (`N²/4` f64 multiply-adds: 261 700 → 547 330 M4 instructions for
//!   [`Probe::irradiance_variance`] with 16 missing) and `m²/2`.
//!
//! # Bad input
//! - A NaN or infinite sample: [`Probe::update`] returns [`Error::InvalidRadiance`] and the
//!   probe keeps its previous data. Finite samples of any size are accepted (see "Radiance
//!   scale"). [`Probe::update_masked`] checks the valid samples only, and returns
//!   [`Error::TooManyMissing`] (keeping the data) when more than `M` are missing or fewer than
//!   two are valid.
//! - A zero, NaN or infinite normal or lobe axis: [`Error::InvalidDirection`].
//! - A lobe sharpness that is negative, not finite or above [`MAX_GLOSSY_SHARPNESS`]:
//!   [`Error::InvalidSharpness`]; a non-finite lobe amplitude: [`Error::InvalidWeights`].
//! - A rotation that is not a finite orthonormal matrix: [`Error::InvalidRotation`].
//! - A [`Selection::Member`] index outside the family: [`Error::InvalidMember`].
//! - Before the first update every query returns zero irradiance and zero variance.
//!
//!
//! # Cost
//! Instructions per call and flash on a Cortex-M4F: [`costs`](crate::costs#the-probe).

use crate::error::Error;
use crate::footprint::{Footprint, Kind, Point};
use crate::radiance::{from_channels, Radiance};
use crate::rotation::Mat3;
use crate::sf::SphericalFibonacci;
use crate::sg::{full_integral_unchecked, SphericalGaussian};
use crate::size::Size;
use crate::vec3::Vec3;
use core::f32::consts::PI;
use core::marker::PhantomData;

#[doc(no_inline)]
pub use crate::estimate::Estimate;

mod covariance;
mod missing;
mod queries;
mod scale;
mod series;
mod sh;
mod solve;
mod update;

pub use crate::estimate::MAX_GLOSSY_SHARPNESS;
use queries::*;
use series::*;
use solve::*;

/// Nodes of each baked `π·z(t)` table over `t ∈ [−1, 1]` (`gen/probe.rs` emits arrays of
/// this length; a mismatch does not compile).
pub(crate) const Z_NODES: usize = 129;

/// Points of each member's baked glossy variance grid: lobe sharpness `μ = 0`, then
/// `μ = 2^(k−1)` for `k = 1…11` (1 to 1024); see [`Probe::glossy`].
pub(crate) const GLOSSY_GRID: usize = 12;

// `ProbeSize`, generated by build.rs (gen/probe.rs, `render_size_trait`) so that the compile
// error for an unbaked N lists the sizes this build baked.
include!(concat!(env!("OUT_DIR"), "/probe_size.rs"));

// The compile error of an unbaked pair lists this build's pairs (generated by build.rs:
// gen/probe.rs, `render_tables_diagnostic`).
probe_tables_diagnostic! {
    /// Implemented for exactly the pairs (sample count `N`, footprint `F`) with a baked probe
    /// family; sealed. By default: point samples and [`Gaussian`](crate::footprint::Gaussian)
    /// footprints of sharpness `N/8` for `N` = 16, 32, 64, 128, 256, and the photodiode
    /// [`CosinePower<1>`](crate::footprint::CosinePower) for `N` = 16, 32 ([`BAKED_TABLES`] lists
    /// them; the crate docs' "What is baked" has every type; `tables/README.md` says how to bake
    /// others). The compile error for another pair lists the pairs this build baked.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::footprint::{Footprint, Gaussian, Point};
    /// use sphere_quadrature::probe::{Probe, ProbeTables, BAKED_TABLES};
    /// use sphere_quadrature::{Size, Vec3};
    ///
    /// // Code generic over the footprint: a constant field integrates to π times the constant.
    /// fn constant_irradiance<const N: usize, F: Footprint>() -> f32
    /// where
    ///     Size<N>: ProbeTables<F>,
    /// {
    ///     let mut p = Probe::<N, f32, F>::new();
    ///     p.update(&[1.0; N]).unwrap();
    ///     p.irradiance(Vec3::Z).unwrap().value
    /// }
    /// assert!((constant_irradiance::<64, Point>() - core::f32::consts::PI).abs() < 1e-4);
    /// assert!((constant_irradiance::<64, Gaussian<8>>() - core::f32::consts::PI).abs() < 1e-4);
    /// assert!(BAKED_TABLES.contains(&(64, Gaussian::<8>::KIND)));
    /// ```
    pub trait ProbeTables<F: Footprint>: sealed::Tables<F> {}
}

pub(crate) mod sealed {
    /// One baked family member (see `gen/probe.rs`).
    #[derive(Debug)]
    pub struct Baked {
        /// Cholesky factor of `E`, packed lower-triangle rows, reciprocal diagonal.
        pub chol_even: &'static [u32],
        /// Cholesky factor of `F`, likewise.
        pub chol_odd: &'static [u32],
        /// `g = E⁻¹1`.
        pub g: &'static [u32],
        /// `[v, s, c]` per node: `π·z ≈ v + f·(s + f·c)`.
        pub z: &'static [[f32; 3]; super::Z_NODES],
        /// Direction-averaged unit glossy variance over `F(μ)²` on the grid.
        pub glossy_variance: [f32; super::GLOSSY_GRID],
        /// Error-bar calibration `[irradiance, μ = 7, μ = 22, μ = 102]`.
        pub calibration: [f32; 4],
        pub lambda: f32,
        pub sigma: f32,
        pub s1: f32,
        pub likelihood_constant: f32,
        pub vbar: f32,
        pub mean_variance: f32,
        pub max_variance: f32,
        pub condition: f32,
    }

    pub trait Tables<F> {
        const HALF: usize;
        const FAMILY: &'static [Baked];
    }
}

/// The sizes with a baked point-sample probe family, ascending.
pub const BAKED_SIZES: &[usize] = &crate::tables::PROBE_SIZES;

/// Every baked (sample count, footprint) pair.
pub const BAKED_TABLES: &[(usize, Kind)] = &crate::tables::PROBE_TABLES;

/// An RGB probe: [`Probe`] with `[f32; 3]` samples (point samples unless `F` says otherwise).
///
/// ```
/// use sphere_quadrature::footprint::Gaussian;
/// use sphere_quadrature::probe::{Probe, RgbProbe};
///
/// let a: RgbProbe<64> = Probe::new();
/// let b: RgbProbe<64, Gaussian<8>> = Probe::new();
/// assert_eq!(a.directions(), b.directions());
/// ```
pub type RgbProbe<const N: usize, F = Point, const M: usize = 0> = Probe<N, [f32; 3], F, M>;

/// One member of a baked family: the kernel hyperparameters and figures of its `Q`.
///
/// # Examples
/// ```
/// use sphere_quadrature::probe::Probe;
///
/// // The baked family of the 64-sample probe: every member's length scale is √(2/λ).
/// assert!(Probe::<64>::family().len() >= 1);
/// for m in Probe::<64>::family() {
///     assert!((m.length_scale - (2.0 / m.lambda).sqrt()).abs() < 1e-3 * m.length_scale);
///     assert!(m.condition >= 1.0 && m.mean_variance <= m.max_variance);
/// }
/// assert_eq!(Probe::<64>::member(0), Probe::<64>::family().next());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Member {
    /// What the samples measure.
    pub footprint: Kind,
    /// Kernel sharpness `λ = 2/l²`; for a [`Gaussian`](crate::footprint::Gaussian) footprint
    /// of sharpness `S`, the sharpness `ν < S` of the covariance of a sample with the radiance
    /// (the kernel is close to the squared exponential of sharpness `νS/(S − ν)`; see
    /// "Footprints" in the module docs).
    pub lambda: f32,
    /// Length scale `l = √(2/λ)`.
    pub length_scale: f32,
    /// Noise ratio `σ′ = σ_n/σ_f`.
    pub sigma: f32,
    /// 2-norm condition number of `Q = K + σ′²I`.
    pub condition: f32,
    /// Posterior variance of `E(n)` for σ_f = 1, averaged over 256 normals.
    pub mean_variance: f32,
    /// Its maximum over the same normals.
    pub max_variance: f32,
    /// The error-bar calibration of this member: the factors by which every variance the
    /// probe reports is multiplied, `[irradiance, glossy at μ = 7, μ = 22, μ = 102]` (glossy:
    /// linear in `ln μ` between, constant outside; see "Error bars" in the module docs).
    /// 1 for a member without a `calibration = …` line.
    pub calibration: [f32; 4],
}

/// How [`Probe::update_with`] picks the family member.
///
/// # Examples
/// ```
/// use sphere_quadrature::probe::{Probe, Selection};
/// use sphere_quadrature::Vec3;
///
/// let mut probe = Probe::<64>::new();
/// let samples = probe.directions().map(|d| 1.0 + 0.5 * d.z);
/// probe.update_with(&samples, Selection::Member(0))?;
/// assert_eq!(probe.selected(), 0);
/// // The default rule picks the member of highest marginal likelihood.
/// probe.update_with(&samples, Selection::MaxLikelihood)?;
/// assert!(probe.selected() < Probe::<64>::family().len());
/// assert!(probe.irradiance(Vec3::Z)?.value > 0.0);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Selection {
    /// The member of highest marginal likelihood for these samples (what [`Probe::update`]
    /// does).
    MaxLikelihood,
    /// Always this member (index into [`Probe::family`]).
    Member(usize),
}

/// A Bayesian Monte Carlo lighting probe of `N` samples (`f32` or RGB `[f32; 3]`).
///
/// Holds its sample directions, `α` and `β`: `12N + 4CN` bytes plus a few words (1 KiB for
/// `N = 64`, one channel). The baked tables are in flash ([`Probe::TABLE_BYTES`]).
///
/// `M` is the capacity for missing samples of [`Probe::update_masked`] (0 by default: every
/// sample must be valid); a probe with `M > 0` also holds the missing indices and an `M × M`
/// factor, `4M² + 6M` bytes more (module docs, "Missing samples").
///
/// # Examples
/// ```
/// use sphere_quadrature::{probe::Probe, RotationSequence, Vec3};
///
/// // Rotate the rays, take one RGB sample along each, query irradiance with an error bar.
/// let mut probe = Probe::<64, [f32; 3]>::new();
/// probe.set_rotation(RotationSequence::new(1).next_rotation())?;
/// let sky = |d: Vec3| [1.0 + 0.5 * d.z, 1.0, 1.0 - 0.5 * d.z];
/// let samples = probe.directions().map(sky);
/// probe.update(&samples)?;
/// let e = probe.irradiance(Vec3::Z)?;
/// // The exact irradiance about +z is π·(1 ± 0.5·2/3).
/// let exact = [4.18879, core::f32::consts::PI, 2.09440];
/// for c in 0..3 {
///     assert!((e.value[c] - exact[c]).abs() < 0.02 && e.variance[c] >= 0.0);
/// }
/// // A zero normal is an error, not a panic.
/// assert_eq!(probe.irradiance(Vec3::ZERO), Err(sphere_quadrature::Error::InvalidDirection));
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Probe<const N: usize, T: Radiance = f32, F: Footprint = Point, const M: usize = 0>
where
    Size<N>: ProbeTables<F>,
{
    directions: [Vec3; N],
    /// `α/s` per channel.
    alpha: [T; N],
    /// `β`, absolute (`±∞` only where the GLS mean itself exceeds `f32::MAX`).
    beta: T,
    /// `σ̂_f²/s²` per channel.
    signal_variance: T,
    /// `s = 2^k` per channel: the samples' spread (see `scale::normalise`).
    scale: T,
    selected: usize,
    log_likelihood: f32,
    footprint: PhantomData<F>,
    /// The samples the last update left out (at most `M`) and the selected member's Schur
    /// complement data for the exact variances (`missing.rs`); empty after [`Probe::update`].
    missing: missing::Missing<M>,
}

impl<const N: usize, T: Radiance, F: Footprint, const M: usize> Default for Probe<N, T, F, M>
where
    Size<N>: ProbeTables<F>,
{
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize, T: Radiance, F: Footprint, const M: usize> Probe<N, T, F, M>
where
    Size<N>: ProbeTables<F>,
{
    const FAMILY: &'static [sealed::Baked] = <Size<N> as sealed::Tables<F>>::FAMILY;
    const HALF: usize = {
        assert!(2 * <Size<N> as sealed::Tables<F>>::HALF == N, "baked block size differs from N/2");
        <Size<N> as sealed::Tables<F>>::HALF
    };

    /// A probe on the unrotated spherical Fibonacci sphere set, with no data yet. A `const
    /// fn`, so a probe can live in a `static` (on a device, typically behind a critical-section
    /// mutex) and needs no run-time constructor.
    ///
    /// ```
    /// use core::cell::RefCell;
    /// use std::sync::Mutex;
    /// use sphere_quadrature::{probe::Probe, sf::SphericalFibonacci};
    ///
    /// static PROBE: Mutex<RefCell<Probe<64, [f32; 3]>>> = Mutex::new(RefCell::new(Probe::new()));
    ///
    /// let probe = PROBE.lock().unwrap();
    /// // The same directions as the run-time set, bit for bit.
    /// assert_eq!(*probe.borrow().directions(), SphericalFibonacci::<64>::new().points());
    /// ```
    #[must_use]
    pub const fn new() -> Self {
        let () = crate::radiance::Channels::<T>::VALID;
        Self {
            directions: SphericalFibonacci::<N>::new().dynamic().unrotated_points(),
            alpha: [T::ZERO; N],
            beta: T::ZERO,
            signal_variance: T::ZERO,
            scale: T::ONE,
            selected: 0,
            log_likelihood: 0.0,
            footprint: PhantomData,
            missing: missing::Missing::new(),
        }
    }

    /// What each sample measures (the footprint `F` as a value).
    #[must_use]
    pub const fn footprint() -> Kind {
        F::KIND
    }

    /// Rotates the sample set as a whole (from the unrotated set, not cumulatively) and
    /// clears the data: take the next samples in the new [`Probe::directions`].
    ///
    /// # Errors
    /// [`Error::InvalidRotation`] unless `m` is a valid rotation: finite, orthonormal within
    /// [`ROTATION_TOLERANCE`](crate::rotation::ROTATION_TOLERANCE) (10⁻³) and of determinant
    /// `+1` ([`Mat3::validate_rotation`]); the probe is then left unchanged.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{probe::Probe, Error, Mat3, RotationSequence, Vec3};
    ///
    /// let mut probe = Probe::<16>::new();
    /// let m = RotationSequence::new(4).next_rotation();
    /// probe.set_rotation(m)?;
    /// // The directions are the unrotated set's, rotated by m.
    /// let plain = Probe::<16>::new();
    /// assert!((probe.directions()[0] - m * plain.directions()[0]).length() < 1e-5);
    /// // A matrix that is not a rotation is refused and nothing changes.
    /// let scaled = Mat3::from_rows(Vec3::X * 2.0, Vec3::Y, Vec3::Z);
    /// assert_eq!(probe.set_rotation(scaled), Err(Error::InvalidRotation));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn set_rotation(&mut self, m: Mat3) -> Result<(), Error> {
        let set = SphericalFibonacci::<N>::new().with_rotation(m)?;
        *self = Self { directions: set.points(), ..Self::new() };
        Ok(())
    }

    /// The `N` unit directions in which to sample radiance, in the order [`Probe::update`]
    /// expects.
    #[must_use]
    pub const fn directions(&self) -> &[Vec3; N] {
        &self.directions
    }

    /// The baked family, in order of increasing `λ`.
    pub fn family() -> impl ExactSizeIterator<Item = Member> + Clone {
        Self::FAMILY.iter().map(|b| member_of(b, F::KIND))
    }

    /// Family member `k`, or `None` past the end.
    #[must_use]
    pub fn member(k: usize) -> Option<Member> {
        Self::FAMILY.get(k).map(|b| member_of(b, F::KIND))
    }

    /// Flash bytes of this size's baked tables: per member two packed `N/2` factors, `g`,
    /// eight scalars and the glossy variance grid, plus its quadratic `π·z` table (shared with
    /// other sizes of the same `λ`). As everywhere in the crate, a type's `TABLE_BYTES` is what
    /// using that type links, a module's `TABLE_BYTES` the sum over every size it bakes.
    ///
    /// # Cost
    /// Flash bytes of the point probe's tables, checked by this example: N = 16: 7 792,
    /// N = 32: 11 120, N = 64: 23 920, N = 128: 74 096, N = 256: 272 752. Only the sizes a binary
    /// uses are linked.
    /// ```
    /// use sphere_quadrature::footprint::Gaussian;
    /// use sphere_quadrature::probe::Probe;
    ///
    /// assert_eq!(Probe::<16>::TABLE_BYTES, 7_792);
    /// assert_eq!(Probe::<32>::TABLE_BYTES, 11_120);
    /// assert_eq!(Probe::<64>::TABLE_BYTES, 23_920);
    /// assert_eq!(Probe::<128>::TABLE_BYTES, 74_096);
    /// assert_eq!(Probe::<256>::TABLE_BYTES, 272_752);
    /// // A footprint probe's tables are the same size as the point probe's.
    /// assert_eq!(Probe::<64, f32, Gaussian<8>>::TABLE_BYTES, Probe::<64>::TABLE_BYTES);
    /// ```
    pub const TABLE_BYTES: usize = {
        let m = N / 2;
        4 * (m * (m + 1) + m + 8 + GLOSSY_GRID + 3 * Z_NODES) * Self::FAMILY.len()
    };
}

/// The normalised cosine-weighted average used by ray-traced irradiance-field probes, the
/// cheapest peer of [`Probe::irradiance`]:
/// `E ≈ π·Σ max(0, n·xⱼ)·Yⱼ / Σ max(0, n·xⱼ)` (zero when no direction is above the horizon).
///
/// # Errors
/// [`Error::InvalidDirection`] for a zero or non-finite normal; [`Error::LengthMismatch`] when
/// the slices differ in length.
pub fn cosine_weighted_average<T: Radiance>(
    directions: &[Vec3],
    samples: &[T],
    normal: Vec3,
) -> Result<T, Error> {
    if directions.len() != samples.len() {
        return Err(Error::LengthMismatch);
    }
    let n = normal.try_normalize().ok_or(Error::InvalidDirection)?;
    let mut acc = T::ZERO;
    let mut weight = 0.0f32;
    for (x, &y) in directions.iter().zip(samples) {
        let c = x.dot(n).max(0.0);
        acc = acc.mul_add(y, c);
        weight += c;
    }
    Ok(if weight > 0.0 { acc.scale(PI / weight) } else { T::ZERO })
}
