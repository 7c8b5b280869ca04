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
//!   (baked; O(1)); [`Probe::posterior_variance`] computes it exactly for `n` in O(N²).
//! - **Calibration**: on real lighting that bar is too narrow (point samples alias bright
//!   features the model does not see: 2σ held for 51–60 % of irradiance queries on the
//!   `clamp` tier of the held-out maps). Every variance the probe reports is therefore
//!   multiplied by a per-member factor [`Member::calibration`] (irradiance; glossy at lobe
//!   sharpness μ = 7, 22, 102, linear in `ln μ` between), fitted offline so that 95 % of the
//!   errors on the training maps fall within 2σ (`eval/src/bin/probe_trust.rs` writes the
//!   `calibration = …` lines of `tables/probe.txt`; `docs/probe_trust.md`). On the held-out
//!   maps, with the f64 engine of that program, 2σ then holds for 94–99 % of the `clamp`
//!   queries and 96–100 % of the `smooth` ones at N = 16 … 256 (irradiance and Phong
//!   e = 5, 20, 100); the crate's own figures are in `docs/accuracy.md` and `docs/glossy.md`.
//!   The factors range from 0.2 to 744: a member chosen mostly on aliased data gets wide bars
//!   on smooth data too (the smooth tier's N = 16 bars over-cover, 100 %). Divide by the
//!   factor for the model's own variance.
//! - **Channel covariance**: one kernel serves every channel, so the covariance of channels
//!   `a`, `b` of an estimate is the REML channel covariance `S_ab = r_aᵀQ⁻¹r_b/(N − 1)`
//!   ([`Probe::channel_covariance`]; `S_cc = σ̂_f²`) times the query's unit variance
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
//!   point probe's (README, Cortex-M4 table).
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
//! - **Queries**: every value, the exact variances ([`Probe::posterior_variance`],
//!   [`Probe::glossy_variance`], [`Probe::phong_variance`]: the probe keeps the selected
//!   member's `P_MM` factor for their Schur correction) and the channel covariance
//!   ([`Probe::channel_covariance`], [`Probe::signal_variance_of`], [`Probe::combine`]) and
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
//!   573 860 with 16, against 88 800 for [`Probe::update`] (README). Memory: the probe grows by
//!   the missing indices and factor, `4M² + 6M` bytes and a few words; the update uses
//!   another `4·M·N + 8M²` bytes of stack. Each exact-variance query does one more back
//!   substitution (`N²/4` f64 multiply-adds: 261 700 → 547 330 M4 instructions for
//!   [`Probe::posterior_variance`] with 16 missing) and `m²/2`.
//!
//! # Bad input
//! - A NaN or infinite sample: [`Probe::update`] returns [`Error::InvalidRadiance`] and the
//!   probe keeps its previous data. Finite samples of any size are accepted (see "Radiance
//!   scale"). [`Probe::update_masked`] checks the valid samples only, and returns
//!   [`Error::TooManyMissing`] (keeping the data) when more than `M` are missing or fewer than
//!   two are valid.
//! - A zero, NaN or infinite normal or lobe axis: [`Error::InvalidDirection`].
//! - A lobe sharpness that is negative, not finite or above [`MAX_GLOSSY_SHARPNESS`]:
//!   [`Error::InvalidSharpness`]; a non-finite lobe amplitude: [`Error::InvalidParameter`].
//! - A rotation that is not a finite orthonormal matrix: [`Error::InvalidParameter`].
//! - A [`Selection::Member`] index outside the family: [`Error::InvalidParameter`].
//! - Before the first update every query returns zero irradiance and zero variance.

use crate::bmc::Size;
use crate::error::Error;
use crate::footprint::{Footprint, Kind, Point};
use crate::radiance::{from_channels, Radiance};
use crate::rotation::Mat3;
use crate::sf::SphericalFibonacci;
use crate::sg::{full_integral_unchecked, SphericalGaussian};
use crate::vec3::Vec3;
use core::f32::consts::PI;
use core::marker::PhantomData;

mod covariance;
mod missing;
mod scale;
mod sh;

/// Nodes of each baked `π·z(t)` table over `t ∈ [−1, 1]` (`gen/probe.rs` emits arrays of
/// this length; a mismatch does not compile).
pub const Z_NODES: usize = 129;

/// Points of each member's baked glossy variance grid: lobe sharpness `μ = 0`, then
/// `μ = 2^(k−1)` for `k = 1…11` (1 to 1024); see [`Probe::glossy`].
pub const GLOSSY_GRID: usize = 12;

// `ProbeSize`, generated by build.rs (gen/probe.rs, `render_size_trait`) so that the compile
// error for an unbaked N lists the sizes this build baked.
include!(concat!(env!("OUT_DIR"), "/probe_size.rs"));

/// Implemented for exactly the pairs (sample count `N`, footprint `F`) with a baked probe
/// family; sealed. By default: point samples and [`Gaussian`](crate::footprint::Gaussian)
/// footprints of sharpness `N/16`, `N/8`, `N/4` and `N/2` for `N` = 16, 32, 64, 128, 256, and
/// the photodiode [`CosinePower<1>`](crate::footprint::CosinePower) for `N` = 16, 32, 64
/// ([`BAKED_TABLES`] lists them; `tables/probe.txt` says how to bake others).
///
/// # Examples
/// ```
/// use sphere_quadrature::bmc::Size;
/// use sphere_quadrature::footprint::{Footprint, Gaussian, Point};
/// use sphere_quadrature::probe::{Probe, ProbeTables, BAKED_TABLES};
/// use sphere_quadrature::Vec3;
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
#[diagnostic::on_unimplemented(
    message = "no Bayesian Monte Carlo probe family is baked for `{Self}` with footprint `{F}`",
    label = "this sample count and footprint have no baked probe tables",
    note = "`probe::BAKED_TABLES` lists the baked pairs; bake others with a `footprint = …` line (tables/README.md)"
)]
pub trait ProbeTables<F: Footprint>: sealed::Tables<F> {}

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

/// An estimate and its posterior variance (per channel for RGB).
///
/// # Examples
/// ```
/// use sphere_quadrature::{probe::Probe, Vec3};
///
/// let mut probe = Probe::<64, [f32; 3]>::new();
/// let samples = probe.directions().map(|d| [1.0 + d.x * d.y, 0.5, 2.0 + d.z]);
/// probe.update(&samples)?;
/// let e = probe.irradiance(Vec3::new(0.0, 0.6, 0.8))?;
/// // A variance per channel, each the unit variance times that channel's signal variance.
/// for c in 0..3 {
///     assert!(e.variance[c] >= 0.0);
///     let product = e.unit_variance * probe.channel_covariance(c, c);
///     assert!((e.variance[c] - product).abs() <= 1e-5 * e.variance[c].max(1e-30));
/// }
/// // The constant green channel is exact: π·0.5, no variance.
/// assert!((e.value[1] - 0.5 * core::f32::consts::PI).abs() < 1e-5 && e.variance[1] == 0.0);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Estimate<T> {
    /// The posterior mean.
    pub value: T,
    /// The posterior variance (σ̂_f² from the samples times the unit variance).
    pub variance: T,
    /// The unit (σ_f = 1) posterior variance the query used, one for every channel (one
    /// kernel serves them all): `variance` of channel `c` is `unit_variance` times
    /// [`Probe::channel_covariance`]`(c, c)`, and [`Probe::combine`] gives the variance of
    /// any linear combination of the channels. It carries the query's weight function
    /// (a glossy lobe's amplitude `a` as `a²`), the channel covariance the radiance units.
    ///
    /// The query computes `variance` apart from this product, without intermediate overflow;
    /// the product reproduces it to rounding whenever both factors are normal f32 numbers
    /// (`unit_variance` is `+∞` when `a²` times the unit variance exceeds `f32::MAX`).
    pub unit_variance: f32,
}

/// A Bayesian Monte Carlo lighting probe of `N` samples (`f32` or RGB `[f32; 3]`).
///
/// Holds its sample directions, `α` and `β`: `12N + 4CN` bytes plus a few words (1 KiB for
/// `N = 64`, one channel). The baked tables are in flash ([`Probe::table_bytes`]).
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

    /// A probe on the unrotated spherical Fibonacci sphere set, with no data yet.
    ///
    /// # Cost
    /// Flash, one call in a release build with LTO (`.ci/m4-flash.sh`, which CI checks
    /// these lines against; the tables come with the first query or update):
    /// - `flash:probe_new N=64`: 1 856 bytes of code and 256 bytes of tables
    #[must_use]
    pub fn new() -> Self {
        Self {
            directions: SphericalFibonacci::<N>::new().points(),
            alpha: [T::ZERO; N],
            beta: T::ZERO,
            signal_variance: T::ZERO,
            scale: T::ZERO.map(|_| 1.0),
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
    /// [`Error::InvalidParameter`] unless `m` is a valid rotation: finite, orthonormal within
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
    /// assert_eq!(probe.set_rotation(scaled), Err(Error::InvalidParameter));
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
    /// other sizes of the same `λ`).
    ///
    /// # Cost
    /// Flash bytes of the point probe's tables, checked by this example: N = 16: 7 792,
    /// N = 32: 11 120, N = 64: 23 920, N = 128: 74 096, N = 256: 272 752. Only the sizes a binary
    /// uses are linked.
    /// ```
    /// use sphere_quadrature::footprint::Gaussian;
    /// use sphere_quadrature::probe::Probe;
    ///
    /// assert_eq!(Probe::<16>::table_bytes(), 7_792);
    /// assert_eq!(Probe::<32>::table_bytes(), 11_120);
    /// assert_eq!(Probe::<64>::table_bytes(), 23_920);
    /// assert_eq!(Probe::<128>::table_bytes(), 74_096);
    /// assert_eq!(Probe::<256>::table_bytes(), 272_752);
    /// // A footprint probe's tables are the same size as the point probe's.
    /// assert_eq!(Probe::<64, f32, Gaussian<8>>::table_bytes(), Probe::<64>::table_bytes());
    /// ```
    #[must_use]
    pub const fn table_bytes() -> usize {
        let m = N / 2;
        let mut bytes = 0;
        let mut k = 0;
        while k < Self::FAMILY.len() {
            bytes += 4 * (m * (m + 1) + m + 8 + GLOSSY_GRID + 3 * Z_NODES);
            k += 1;
        }
        bytes
    }

    /// Takes new samples (radiance in [`Probe::directions`], in order) and picks the family
    /// member of highest marginal likelihood. Any finite radiance scale: see "Radiance scale"
    /// in the module docs.
    ///
    /// # Errors
    /// [`Error::InvalidRadiance`] if a sample has a NaN or infinite channel; the probe keeps
    /// its previous data.
    ///
    /// # Cost
    /// Cortex-M4F instructions per call (QEMU `mps2-an386`, `-icount shift=0`, `libm` backend;
    /// `examples/cortex-m4`, whose output CI checks these lines against):
    /// - `m4:probe_update N=16`: 2 716 instructions (four-member selection)
    /// - `m4:probe_update N=32`: 33 968 instructions (four-member selection)
    /// - `m4:probe_update N=64`: 88 800 instructions (four-member selection)
    /// - `m4:probe_update N=256`: 790 440 instructions (four-member selection)
    ///
    /// Flash, one call in a release build with LTO (`.ci/m4-flash.sh`, which CI checks
    /// these lines against):
    /// - `flash:probe_update N=64`: 18 388 bytes of code and 24 096 bytes of tables
    ///   (on top of `Probe::new`)
    ///
    /// Flash: the size's baked tables, [`Probe::table_bytes`].
    pub fn update(&mut self, samples: &[T; N]) -> Result<(), Error> {
        self.update_with(samples, Selection::MaxLikelihood)
    }

    /// [`Probe::update`] with a chosen [`Selection`].
    ///
    /// # Errors
    /// [`Error::InvalidRadiance`] for a non-finite sample; [`Error::InvalidParameter`] for a
    /// member index outside the family. Either way the probe keeps its previous data.
    ///
    /// # Cost
    /// Cortex-M4F instructions per call (QEMU `mps2-an386`, `-icount shift=0`, `libm` backend;
    /// `examples/cortex-m4`, whose output CI checks these lines against):
    /// - `m4:probe_update_one_member N=16`: 1 272 instructions (one member)
    /// - `m4:probe_update_one_member N=32`: 11 876 instructions (one member)
    /// - `m4:probe_update_one_member N=64`: 31 080 instructions (one member)
    /// - `m4:probe_update_one_member N=256`: 274 880 instructions (one member)
    ///
    /// Flash, one call in a release build with LTO (`.ci/m4-flash.sh`, which CI checks
    /// these lines against):
    /// - `flash:probe_update_one_member N=64`: 18 188 bytes of code and 24 096 bytes of tables
    ///   (on top of `Probe::new`)
    pub fn update_with(&mut self, samples: &[T; N], selection: Selection) -> Result<(), Error> {
        if !samples.iter().all(|y| (0..T::CHANNELS).all(|c| y.channel(c).is_finite())) {
            return Err(Error::InvalidRadiance);
        }
        let range = match selection {
            Selection::MaxLikelihood => 0..Self::FAMILY.len(),
            Selection::Member(k) if k < Self::FAMILY.len() => k..k + 1,
            Selection::Member(_) => return Err(Error::InvalidParameter),
        };
        // Work with (Y − c·1)/s, c = Y₀: α and ℓ are unchanged (β shifts by c), but the
        // ill-conditioned products then see only the samples' spread, not their mean, and a
        // constant gives exactly α = 0. The power of two s = 2^k per channel (the exponent of
        // the largest |Yᵢ − Y₀|) brings the spread to O(1), so that rᵀQ⁻¹r neither overflows
        // nor underflows whatever the radiance units: α/s and σ̂_f²/s² are stored, the queries
        // apply s last.
        let c = samples.first().copied().unwrap_or(T::ZERO);
        let (centred, spread) = scale::normalise(samples);
        let sd = Self::half_sums(&centred);
        let mut best: Option<(usize, f32, T)> = None;
        let mut work = [T::ZERO; N];
        for k in range {
            let Some(f) = Self::FAMILY.get(k) else { break };
            let (alpha, beta, q) = Self::solve(f, &centred, &sd, &mut work);
            // ℓ of the normalised samples: the scale shifts every member's ℓ alike.
            let mut ll = T::CHANNELS as f32 * f.likelihood_constant;
            for c in 0..T::CHANNELS {
                let qc = q.channel(c).max(f32::MIN_POSITIVE);
                ll -= 0.5 * (N as f32 - 1.0) * crate::math::ln(qc);
            }
            if best.is_none_or(|(_, b, _)| ll > b) {
                best = Some((k, ll, beta));
                self.alpha = *alpha;
            }
        }
        if let Some((k, ll, beta)) = best {
            self.missing.clear();
            self.store(k, ll, c, spread, beta);
        }
        Ok(())
    }

    /// The end of an update, after `α/s` is in place (and [`Probe::missing`] set): stores
    /// member `k`, the absolute `β = Y₀ + s·β′` from the centre `c = Y₀`, the scale `s`, the
    /// REML channel variance and `ℓ` of the samples as given, from `ℓ′` of the normalised
    /// ones, for the valid samples.
    fn store(&mut self, k: usize, ll: f32, c: T, spread: T, beta: T) {
        let Some(f) = Self::FAMILY.get(k) else { return };
        // β = Y₀ + s·β′; where that overflows f32, again in f64 (±∞ only if β itself
        // exceeds f32::MAX).
        let absolute = c.add(spread.mul(beta));
        self.beta = if (0..T::CHANNELS).all(|ch| absolute.channel(ch).is_finite()) {
            absolute
        } else {
            from_channels(|ch| {
                (f64::from(c.channel(ch))
                    + f64::from(spread.channel(ch)) * f64::from(beta.channel(ch)))
                    as f32
            })
        };
        self.scale = spread;
        let valid = self.valid_count();
        // σ̂_f²/s² = α′ᵀQα′/(n − 1), the REML channel variance, computed as
        // [`Probe::channel_covariance`] does (so that the two agree bit for bit).
        self.signal_variance = Self::channel_quadratic(f, &self.alpha, valid);
        self.selected = k;
        // ℓ of the samples themselves: rᵀQ⁻¹r = s²·r′ᵀQ⁻¹r′ per channel.
        let shift: i32 = (0..T::CHANNELS).map(|ch| scale::exponent(spread.channel(ch))).sum();
        self.log_likelihood = ll - (valid as f32 - 1.0) * core::f32::consts::LN_2 * shift as f32;
    }

    /// Half sums `(y_p + y_{N−1−p})/2` in the first half, half differences in the second:
    /// what the two baked blocks act on (`gen/probe.rs`, "The antipodal symmetry").
    fn half_sums<R: Radiance>(y: &[R; N]) -> [R; N] {
        let m = Self::HALF;
        let mut sd = [R::ZERO; N];
        let (lo, hi) = y.split_at(m);
        let (s, d) = sd.split_at_mut(m);
        for (((ya, yb), sp), dp) in lo.iter().zip(hi.iter().rev()).zip(s).zip(d) {
            *sp = ya.add(*yb).scale(0.5);
            *dp = ya.add(yb.scale(-1.0)).scale(0.5);
        }
        sd
    }

    /// `α = Q⁻¹(Y − β1)` (in `work`), `β` and `rᵀQ⁻¹r = Σ Yᵢ ⊙ αᵢ` for member `f`, from
    /// the half sums and differences `sd` of `samples`.
    fn solve<'w>(
        f: &sealed::Baked,
        samples: &[T; N],
        sd: &[T; N],
        work: &'w mut [T; N],
    ) -> (&'w [T; N], T, T) {
        let m = Self::HALF;
        // a = E⁻¹(s/2), b = F⁻¹(d/2): (Q⁻¹Y)_p = a_p + b_p, (Q⁻¹Y)_{N−1−p} = a_p − b_p.
        let mut ab = *sd;
        {
            let (a, b) = ab.split_at_mut(m);
            cholesky_solve(f.chol_even, a);
            cholesky_solve(f.chol_odd, b);
        }
        let (a, b) = ab.split_at(m);
        // 1ᵀQ⁻¹Y = 2·Σa; β = that / s₁.
        let beta = a.iter().fold(T::ZERO, |acc, &x| acc.add(x)).scale(2.0 / f.s1);
        let mut q = T::ZERO;
        {
            let (lo, hi) = work.split_at_mut(m);
            let (ylo, yhi) = samples.split_at(m);
            for ((((&ap, &bp), g), (out_lo, out_hi)), (yp, yq)) in a
                .iter()
                .zip(b)
                .zip(f.g.iter().map(|&b| f32::from_bits(b)))
                .zip(lo.iter_mut().zip(hi.iter_mut().rev()))
                .zip(ylo.iter().zip(yhi.iter().rev()))
            {
                let even = ap.mul_add(beta, -g);
                *out_lo = even.add(bp);
                *out_hi = even.add(bp.scale(-1.0));
                q = q.add(yp.mul(*out_lo)).add(yq.mul(*out_hi));
            }
        }
        (work, beta, q)
    }

    /// Irradiance `E(n)` with the direction-averaged posterior variance, O(N); `±∞` where a
    /// result exceeds `f32::MAX` (module docs, "Radiance scale").
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite normal.
    ///
    /// # Cost
    /// Cortex-M4F instructions per call (QEMU `mps2-an386`, `-icount shift=0`, `libm` backend;
    /// `examples/cortex-m4`, whose output CI checks these lines against):
    /// - `m4:probe_irradiance N=16`: 835 instructions
    /// - `m4:probe_irradiance N=32`: 1 562 instructions
    /// - `m4:probe_irradiance N=64`: 2 916 instructions
    /// - `m4:probe_irradiance N=256`: 11 640 instructions
    /// - `m4:gaussian8_probe_irradiance N=64`: 2 956 instructions (`Gaussian<8>` footprint)
    /// - `m4:photodiode_probe_irradiance N=16`: 837 instructions (`CosinePower<1>`)
    ///
    /// Flash, one call in a release build with LTO (`.ci/m4-flash.sh`, which CI checks
    /// these lines against):
    /// - `flash:probe_irradiance N=64`: 1 772 bytes of code and 24 096 bytes of tables
    ///   (on top of `Probe::new`)
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{probe::Probe, Vec3};
    ///
    /// let mut probe = Probe::<32>::new();
    /// // Before the first update every query is zero with zero variance.
    /// assert_eq!(probe.irradiance(Vec3::Z)?.value, 0.0);
    /// // Radiance 1 + x: irradiance π ± 2π/3 at ±x, a normal need not be unit.
    /// probe.update(&probe.directions().map(|d| 1.0 + d.x))?;
    /// let (plus, minus) = (probe.irradiance(Vec3::new(2.0, 0.0, 0.0))?, probe.irradiance(-Vec3::X)?);
    /// let pi = core::f32::consts::PI;
    /// assert!((plus.value - (pi + 2.0 * pi / 3.0)).abs() < 0.05);
    /// assert!((minus.value - (pi - 2.0 * pi / 3.0)).abs() < 0.05);
    /// assert!(plus.variance >= 0.0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn irradiance(&self, normal: Vec3) -> Result<Estimate<T>, Error> {
        let n = normal.try_normalize().ok_or(Error::InvalidDirection)?;
        let f = self.member_in_use()?;
        // Two passes: node indices and offsets for every sample (branch-free arithmetic the
        // compiler vectorises), then the table reads and the weighted sum.
        const SCALE: f32 = (Z_NODES - 1) as f32 * 0.5;
        // Adding 1.5·2²³ rounds u ∈ [0, 128] to the nearest integer, which lands in the low
        // mantissa bits: no float-to-integer conversion.
        const ROUND: f32 = 12_582_912.0;
        let mut node = [0u32; N];
        let mut offset = [0.0f32; N];
        for ((x, k), t) in self.directions.iter().zip(&mut node).zip(&mut offset) {
            let u = (x.dot(n).clamp(-1.0, 1.0) + 1.0) * SCALE;
            let r = u + ROUND;
            *k = r.to_bits() & 0xff;
            *t = u - (r - ROUND);
        }
        let mut acc = T::ZERO;
        for ((&k, &t), &a) in node.iter().zip(&offset).zip(&self.alpha) {
            let [v, s, c] = f.z[(k as usize).min(Z_NODES - 1)];
            acc = acc.mul_add(a, v + t * (s + t * c));
        }
        let unit = f.mean_variance * f.calibration[0];
        Ok(Estimate {
            value: self.absolute(PI, acc),
            // σ̂′²·unit is a normal number (or 0), and s·(s·x) is monotone: no intermediate
            // overflow or underflow.
            variance: self.signal_variance.scale(unit).mul(self.scale).mul(self.scale),
            unit_variance: unit,
        })
    }

    /// `g·β + s·Σ` per channel for a normalised sum `Σ` and a gain `g ∈ (0, 4π]`: in f32 when
    /// that is finite, else apart in mantissas and exponents ([`scale::rescaled`]), which
    /// gives `±∞` only when the result exceeds `f32::MAX` (or `β` does).
    #[inline]
    fn absolute(&self, g: f32, sum: T) -> T {
        let fast = self.beta.scale(g).add(sum.mul(self.scale));
        if (0..T::CHANNELS).all(|c| fast.channel(c).is_finite()) {
            return fast;
        }
        self.rescaled(g, sum, 1.0)
    }

    /// `a·(g·β + s·Σ)` per channel by [`scale::rescaled`].
    fn rescaled(&self, g: f32, sum: T, a: f32) -> T {
        from_channels(|c| {
            scale::rescaled(self.beta.channel(c), g, self.scale.channel(c), sum.channel(c), a)
        })
    }

    /// `a²·s²·σ̂′²·unit` per channel by [`scale::scaled_variance`].
    fn rescaled_variance(&self, unit: f32, a: f32) -> T {
        from_channels(|c| {
            scale::scaled_variance(self.signal_variance.channel(c) * unit, self.scale.channel(c), a)
        })
    }

    /// `σ̂′²·s²·a²·v` per channel for an f64 unit variance `v`, rounded once.
    fn variance_of_unit(&self, v: f64, a: f64) -> T {
        from_channels(|c| {
            let sa = f64::from(self.scale.channel(c)) * a;
            (f64::from(self.signal_variance.channel(c)) * v * sa * sa) as f32
        })
    }

    /// The exact posterior variance of `E(n)` (σ̂_f² times the unit variance at `n`), O(N²);
    /// `+∞` where it exceeds `f32::MAX`.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite normal.
    ///
    /// # Cost
    /// Cortex-M4F instructions per call (QEMU `mps2-an386`, `-icount shift=0`, `libm` backend;
    /// `examples/cortex-m4`, whose output CI checks these lines against):
    /// - `m4:probe_masked_posterior_variance_M16_m0 N=64`: 261 700 instructions (none missing)
    /// - `m4:probe_masked_posterior_variance_M8_m8 N=64`: 518 420 instructions (8 missing)
    /// - `m4:probe_masked_posterior_variance_M16_m16 N=64`: 547 330 instructions (16 missing)
    ///
    /// `M8`, `M16` in the names: the probe's capacity `M` for missing samples.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{probe::Probe, Vec3};
    ///
    /// let mut probe = Probe::<32>::new();
    /// probe.update(&probe.directions().map(|d| 1.0 + d.x * d.z))?;
    /// // The exact variance at one normal, and the O(1) direction-averaged one of `irradiance`.
    /// let exact = probe.posterior_variance(Vec3::Z)?;
    /// let averaged = probe.irradiance(Vec3::Z)?.variance;
    /// assert!(exact >= 0.0 && averaged >= 0.0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn posterior_variance(&self, normal: Vec3) -> Result<T, Error> {
        let n = normal.try_normalize().ok_or(Error::InvalidDirection)?;
        let f = self.member_in_use()?;
        let zeta: [f64; N] = core::array::from_fn(|i| match self.directions.get(i) {
            Some(x) => f64::from(z_lookup(f.z, x.dot(n))),
            None => 0.0,
        });
        let v = self.unit_variance(f, &zeta, core::f64::consts::PI, f64::from(f.vbar));
        Ok(self.variance_of_unit(v * f64::from(f.calibration[0]), 1.0))
    }

    /// Glossy radiance `∫ L(x)·G(x) dx` for a spherical-Gaussian lobe
    /// `G(x) = a·exp(μ(r·x − 1))`, with a direction-averaged posterior variance, O(N) (one
    /// `exp`, at most one `expm1` and one `sqrt` per sample).
    ///
    /// With `G = SphericalGaussian::phong_moments(r, e)` (unit integral, `μ = e + 2`, the
    /// Phong lobe's first Legendre moment) this is the normalised Phong-lobe average of the
    /// radiance about the mirror direction `r`: the glossy term of a prefiltered environment.
    /// The SG stands in for the Phong lobe: on smooth lighting that leaves an error floor of
    /// about 1 % at `e = 5` (`eval/src/bin/glossy.rs`, `docs/glossy.md`), less for sharper lobes.
    /// The lobe is integrated over the whole sphere (no horizon clipping, no cosine factor:
    /// below the horizon a lobe of `μ = 22` keeps `e^(−22)` of its peak).
    ///
    /// The kernel is an SG of sharpness `λ` too, so `zᵢ = ∫ k(xᵢ, x)·G(x) dx` is closed:
    /// `4πa·exp(w − λ − μ)·(1 − e^(−2w))/(2w)` with `w = |λxᵢ + μr|` (the integral of the
    /// product SG), evaluated as `exp(2λμ(t − 1)/(w + λ + μ))` so that sharp lobes do not
    /// cancel, and with `libm` whatever the math backend (`Σ αᵢzᵢ` cancels by up to cond(Q),
    /// so `zᵢ` needs full f32 accuracy). The estimate is `β·a·F(μ) + Σᵢ αᵢzᵢ` with
    /// `F(μ) = 2π(1 − e^(−2μ))/μ`. As `μ` grows it tends to `a·F(μ)` times the posterior mean
    /// of the radiance at `r` (the GP interpolant).
    ///
    /// The variance is σ̂_f²·a²·F(μ)² times the unit variance over `F(μ)²` averaged over 37
    /// mirror directions, baked per member at `μ = 0, 1, 2, 4, …, 1024` and interpolated
    /// linearly in `μ` (constant above 1024); [`Probe::glossy_variance`] is exact for `r`.
    ///
    /// The amplitude `a` is applied last, with the probe's scale, in mantissa and exponent
    /// apart: any finite `a` (10²⁰ or 10⁻²⁰ say) scales the value by `a` and the variance by
    /// `a²`, `±∞` only where the result exceeds `f32::MAX`. [`Estimate::unit_variance`] is
    /// `a²·F(μ)²` times the baked unit variance.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite axis; [`Error::InvalidSharpness`]
    /// for a sharpness that is negative, not finite or above [`MAX_GLOSSY_SHARPNESS`];
    /// [`Error::InvalidParameter`] for a non-finite amplitude.
    ///
    /// # Cost
    /// Cortex-M4F instructions per call (QEMU `mps2-an386`, `-icount shift=0`, `libm` backend;
    /// `examples/cortex-m4`, whose output CI checks these lines against):
    /// - `m4:probe_glossy N=16`: 2 675 instructions (SG lobe of Phong e = 20)
    /// - `m4:probe_glossy N=32`: 4 904 instructions (SG lobe of Phong e = 20)
    /// - `m4:probe_glossy N=64`: 9 272 instructions (SG lobe of Phong e = 20)
    /// - `m4:probe_glossy N=256`: 38 175 instructions (SG lobe of Phong e = 20)
    /// - `m4:gaussian8_probe_glossy N=64`: 9 394 instructions (`Gaussian<8>`)
    /// - `m4:photodiode_probe_glossy N=16`: 11 538 instructions (photodiodes)
    ///
    /// Flash, one call in a release build with LTO (`.ci/m4-flash.sh`, which CI checks
    /// these lines against):
    /// - `flash:probe_glossy N=64`: 3 768 bytes of code and 24 104 bytes of tables
    ///   (on top of `Probe::new`)
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{probe::Probe, sg::SphericalGaussian, Vec3};
    ///
    /// let mut probe = Probe::<64>::new();
    /// probe.update(&[2.0; 64])?;
    /// // ∫ L·G over the sphere: for a constant L, L times the lobe's integral.
    /// let lobe = SphericalGaussian::phong_moments(Vec3::Z, 20.0)?; // unit integral
    /// let e = probe.glossy(&lobe)?;
    /// assert!((e.value - 2.0).abs() < 1e-3 && e.variance >= 0.0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn glossy(&self, lobe: &SphericalGaussian) -> Result<Estimate<T>, Error> {
        let (r, mu, amp) = check_lobe(lobe)?;
        let f = self.member_in_use()?;
        if let Kind::CosinePower { exponent } = F::KIND {
            return Ok(self.glossy_by_series(f, exponent, r, mu, amp));
        }
        let lambda = f.lambda;
        let top = lambda + mu;
        let two_lm = 2.0 * lambda * mu;
        // Unit amplitude: `a` and the scale s are applied last (see `scale::rescaled`).
        let scale = 4.0 * PI;
        let full = full_integral_unchecked(mu);
        let mut acc = T::ZERO;
        // Always `libm`, whatever the math backend: Σ αᵢzᵢ cancels heavily for the smooth
        // members (cond(Q) up to 10⁵), so zᵢ needs full f32 accuracy (micromath's `exp` made
        // the λ = 1 estimate 25 % wrong).
        for (x, &a) in self.directions.iter().zip(&self.alpha) {
            // t − 1 = −|x − r|²/2, accurate near the lobe's axis.
            let d = -0.5 * (*x - r).length_squared();
            let w = libm::sqrtf((top * top + two_lm * d).max(0.0));
            let e = libm::expf(two_lm * d / (w + top));
            // (1 − e^(−2w))/(2w): e^(−2w) < 2⁻²⁵ past w = 9; → 1 − w as w → 0.
            let h = if w > 9.0 {
                0.5 / w
            } else if w > 1e-3 {
                -libm::expm1f(-2.0 * w) / (2.0 * w)
            } else {
                1.0 - w
            };
            acc = acc.mul_add(a, scale * e * h);
        }
        let unit = full * full * glossy_grid_lookup(&f.glossy_variance, mu) * calibration(f, mu);
        Ok(Estimate {
            value: self.rescaled(full, acc, amp),
            variance: self.rescaled_variance(unit, amp),
            unit_variance: amp * (amp * unit),
        })
    }

    /// The exact posterior variance of [`Probe::glossy`] for `lobe` (σ̂_f² times the unit
    /// variance), O(N²), in f64; the amplitude's `a²` and the probe's scale are applied last
    /// (`+∞` only where the variance exceeds `f32::MAX`).
    ///
    /// `V̄ = ∫∫ G(x)·k(x, x′)·G(x′)` reduces, with `s = λ + μ − |λx + μr|`, to
    /// `a²·8π²/(λμ)·∫₀^{2 min(λ, μ)} exp(s²/(2λ) − s(2λ + μ)/λ)·(1 − e^(−2(λ + μ − s)))/2 ds`,
    /// summed by 8-point Gauss–Legendre on panels of width `2λ/(2λ + μ)` until the integrand
    /// has fallen by `e^(−40)` (at most 41 panels: about 0.8·10⁶ Cortex-M4 instructions of soft
    /// f64 at N = 16, 1.2·10⁶ at N = 64; README).
    ///
    /// # Errors
    /// As [`Probe::glossy`].
    ///
    /// # Cost
    /// Cortex-M4F instructions per call (QEMU `mps2-an386`, `-icount shift=0`, `libm` backend;
    /// `examples/cortex-m4`, whose output CI checks these lines against):
    /// - `m4:probe_glossy_variance N=16`: 773 836 instructions (soft f64 quadrature)
    /// - `m4:probe_glossy_variance N=32`: 894 020 instructions (soft f64 quadrature)
    /// - `m4:probe_glossy_variance N=64`: 1 217 180 instructions (soft f64 quadrature)
    /// - `m4:probe_glossy_variance N=256`: 5 495 440 instructions (soft f64 quadrature)
    ///
    /// Flash, one call in a release build with LTO (`.ci/m4-flash.sh`, which CI checks
    /// these lines against):
    /// - `flash:probe_glossy_variance N=64`: 19 448 bytes of code and 24 112 bytes of tables
    ///   (on top of `Probe::new`)
    pub fn glossy_variance(&self, lobe: &SphericalGaussian) -> Result<T, Error> {
        let (r, mu, amp) = check_lobe(lobe)?;
        let f = self.member_in_use()?;
        let lambda = f64::from(f.lambda);
        // Unit amplitude; a² is applied with the scale at the end.
        let mu = f64::from(mu);
        let integral = glossy_full_integral(mu);
        if let Kind::CosinePower { exponent } = F::KIND {
            // zᵢ = a·F(μ)·Σ_l K_l·g_l·(2l + 1)/(4π)·ρₗ(μ)·P_l(xᵢ·r); V̄ as for point samples.
            let mut h = [0.0f64; MAX_SERIES];
            let len = cosine_series(lambda, exponent, &mut h);
            let mut rho = [0.0f64; MAX_SERIES];
            bessel_ratios(mu, &mut rho[..len]);
            for (h, &p) in h.iter_mut().zip(&rho[..len]) {
                *h *= integral * p;
            }
            let zeta: [f64; N] = core::array::from_fn(|i| match self.directions.get(i) {
                Some(x) => legendre_sum(&h[..len], f64::from(x.dot(r))),
                None => 0.0,
            });
            let vbar = glossy_vbar(lambda, mu);
            let v = self.unit_variance(f, &zeta, integral, vbar);
            return Ok(
                self.variance_of_unit(v * f64::from(calibration(f, mu as f32)), f64::from(amp))
            );
        }
        let top = lambda + mu;
        let two_lm = 2.0 * lambda * mu;
        let scale = 4.0 * core::f64::consts::PI;
        let zeta: [f64; N] = core::array::from_fn(|i| match self.directions.get(i) {
            Some(x) => {
                let dx = [x.x - r.x, x.y - r.y, x.z - r.z].map(f64::from);
                let d = -0.5 * (dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
                let w = crate::math::sqrt64((top * top + two_lm * d).max(0.0));
                let h = if w > 1e-8 { -libm::expm1(-2.0 * w) / (2.0 * w) } else { 1.0 - w };
                scale * libm::exp(two_lm * d / (w + top)) * h
            }
            None => 0.0,
        });
        let vbar = if let Kind::Gaussian { sharpness } = F::KIND {
            integral * integral * deconvolved_vbar(lambda, sharpness, mu)
        } else {
            glossy_vbar(lambda, mu)
        };
        let v = self.unit_variance(f, &zeta, integral, vbar);
        Ok(self.variance_of_unit(v * f64::from(calibration(f, mu as f32)), f64::from(amp)))
    }

    /// The normalised Phong lobe average `∫ L(x)·(e + 1)/(2π)·max(0, r·x)ᵉ dx` about the mirror
    /// direction `r`, exact under the model (no spherical-Gaussian stand-in), with a
    /// direction-averaged posterior variance; O(N·L).
    ///
    /// By Funk–Hecke the lobe acts on degree `l` as the gain
    /// `Φ_l = (e + 1)∫₀¹ tᵉ P_l(t) dt` (two-term recurrence), so the covariance of sample `i`
    /// with the integral is `zᵢ = Σ_l C_l·Φ_l·P_l(xᵢ·r)`, where `C_l` are the Legendre
    /// coefficients of the sample's covariance with the radiance: the kernel's spherical
    /// Gaussian (point samples; of sharpness `ν` for a Gaussian footprint) or that times the
    /// footprint's gains (cosine power). The sum runs over `L = 16 + ⌈9.1√λ⌉` degrees (past
    /// them the kernel's coefficients are below `e^{−41}` of the first), once per sample: about
    /// `L` multiply-adds more per sample than [`Probe::glossy`] (README, Cortex-M4 table).
    ///
    /// [`Probe::glossy`] with [`SphericalGaussian::phong_moments`] approximates the same lobe
    /// by a spherical Gaussian, exact in its integral and first moment only: for broad lobes
    /// that leaves a floor (about 3 % at `e = 5` on the footprint benchmark's maps) which this
    /// query does not have. The variance is the baked glossy grid at `μ = e + 2` (the SG of
    /// the same first moment); [`Probe::phong_variance`] is exact.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite axis; [`Error::InvalidExponent`]
    /// for an exponent that is negative, not finite or above [`MAX_GLOSSY_SHARPNESS`].
    ///
    /// # Cost
    /// Cortex-M4F instructions per call (QEMU `mps2-an386`, `-icount shift=0`, `libm` backend;
    /// `examples/cortex-m4`, whose output CI checks these lines against):
    /// - `m4:probe_phong N=16`: 9 472 instructions (e = 20)
    /// - `m4:probe_phong N=32`: 13 509 instructions (e = 20)
    /// - `m4:probe_phong N=64`: 21 318 instructions (e = 20)
    /// - `m4:probe_phong N=256`: 66 520 instructions (e = 20)
    ///
    /// Flash, one call in a release build with LTO (`.ci/m4-flash.sh`, which CI checks
    /// these lines against):
    /// - `flash:probe_phong N=64`: 9 468 bytes of code and 24 096 bytes of tables
    ///   (on top of `Probe::new`)
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{probe::Probe, Error, Vec3};
    ///
    /// let mut probe = Probe::<64>::new();
    /// probe.update(&[0.5; 64])?;
    /// // The normalised Phong lobe integrates to 1: a constant radiance comes back.
    /// let e = probe.phong(Vec3::new(0.0, 0.6, 0.8), 20.0)?;
    /// assert!((e.value - 0.5).abs() < 1e-3);
    /// assert_eq!(probe.phong(Vec3::Z, f32::NAN), Err(Error::InvalidExponent));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn phong(&self, axis: Vec3, exponent: f32) -> Result<Estimate<T>, Error> {
        let r = axis.try_normalize().ok_or(Error::InvalidDirection)?;
        if !(0.0..=MAX_GLOSSY_SHARPNESS).contains(&exponent) {
            return Err(Error::InvalidExponent);
        }
        let f = self.member_in_use()?;
        let mut h = [0.0f32; MAX_SERIES];
        let len = match F::KIND {
            Kind::CosinePower { exponent: p } => cosine_series_f32(f.lambda, p, &mut h),
            _ => sg_series_f32(f.lambda, &mut h),
        };
        let Some(h) = h.get_mut(..len) else { return Err(Error::InvalidParameter) };
        apply_cosine_power_gains(exponent, h);
        let rec = legendre_recurrence(len);
        let mut acc = T::ZERO;
        for (x, &a) in self.directions.iter().zip(&self.alpha) {
            acc = acc.mul_add(a, legendre_sum_f32(h, &rec, x.dot(r)));
        }
        let mu = exponent + 2.0;
        let unit = glossy_grid_lookup(&f.glossy_variance, mu) * calibration(f, mu);
        Ok(Estimate {
            value: self.absolute(1.0, acc),
            variance: self.signal_variance.scale(unit).mul(self.scale).mul(self.scale),
            unit_variance: unit,
        })
    }

    /// The exact posterior variance of [`Probe::phong`] (σ̂_f² times the unit variance),
    /// O(N² + N·L), in f64: `V̄ = Σ_l K_l·Φ_l²·(2l + 1)/(4π)` with the kernel's coefficients
    /// `K_l`.
    ///
    /// # Errors
    /// As [`Probe::phong`].
    ///
    /// # Cost
    /// Cortex-M4F instructions per call (QEMU `mps2-an386`, `-icount shift=0`, `libm` backend;
    /// `examples/cortex-m4`, whose output CI checks these lines against):
    /// - `m4:probe_phong_variance N=16`: 422 710 instructions (e = 20)
    /// - `m4:probe_phong_variance N=32`: 778 064 instructions (e = 20)
    /// - `m4:probe_phong_variance N=64`: 1 568 680 instructions (e = 20)
    /// - `m4:probe_phong_variance N=256`: 8 657 080 instructions (e = 20)
    ///
    /// Flash, one call in a release build with LTO (`.ci/m4-flash.sh`, which CI checks
    /// these lines against):
    /// - `flash:probe_phong_variance N=64`: 20 892 bytes of code and 24 096 bytes of tables
    ///   (on top of `Probe::new`)
    pub fn phong_variance(&self, axis: Vec3, exponent: f32) -> Result<T, Error> {
        let r = axis.try_normalize().ok_or(Error::InvalidDirection)?;
        if !(0.0..=MAX_GLOSSY_SHARPNESS).contains(&exponent) {
            return Err(Error::InvalidExponent);
        }
        let f = self.member_in_use()?;
        let (lambda, e) = (f64::from(f.lambda), f64::from(exponent));
        let mut k = [0.0f64; MAX_SERIES];
        let len = kernel_coefficients(F::KIND, lambda, &mut k);
        let Some(k) = k.get_mut(..len) else { return Err(Error::InvalidParameter) };
        // Cross-covariance coefficients: SG(λ or ν) for point and Gaussian samples, K·g for
        // the cosine power; then the lobe's gains.
        let mut h = [0.0f64; MAX_SERIES];
        let cross = match F::KIND {
            Kind::Gaussian { .. } => {
                let n = (16 + (9.1 * crate::math::sqrt64(lambda)) as usize).min(MAX_SERIES);
                let Some(h) = h.get_mut(..n) else { return Err(Error::InvalidParameter) };
                bessel_ratios(lambda, h);
                let full = glossy_full_integral(lambda);
                for (l, c) in h.iter_mut().enumerate() {
                    *c *= full * (2 * l + 1) as f64 / (4.0 * core::f64::consts::PI);
                }
                n
            }
            Kind::CosinePower { exponent: p } => {
                for (c, &kl) in h.iter_mut().zip(k.iter()) {
                    *c = kl;
                }
                if let Some(h) = h.get_mut(..len) {
                    apply_cosine_power_gains(f64::from(p), h);
                }
                len
            }
            _ => {
                for (c, &kl) in h.iter_mut().zip(k.iter()) {
                    *c = kl;
                }
                len
            }
        };
        let Some(h) = h.get_mut(..cross) else { return Err(Error::InvalidParameter) };
        apply_cosine_power_gains(e, h);
        let zeta: [f64; N] = core::array::from_fn(|i| match self.directions.get(i) {
            Some(x) => legendre_sum(h, f64::from(x.dot(r))),
            None => 0.0,
        });
        // Applied twice: K_l·Φ_l²·(2l + 1)/(4π).
        apply_cosine_power_gains(e, k);
        apply_cosine_power_gains(e, k);
        let vbar: f64 = k.iter().sum();
        let v = self.unit_variance(f, &zeta, 1.0, vbar);
        Ok(self.variance_of_unit(v * f64::from(calibration(f, exponent + 2.0)), 1.0))
    }

    /// [`Probe::glossy`] for a cosine-power footprint: `zᵢ = a·F(μ)·Σ_l bₗ·ρₗ(μ)·P_l(xᵢ·r)`
    /// with `bₗ = K_l·g_l·(2l + 1)/(4π)` ([`cosine_series`]) and `ρₗ(μ) = i_l(μ)/i₀(μ)`.
    fn glossy_by_series(
        &self,
        f: &sealed::Baked,
        exponent: u32,
        r: Vec3,
        mu: f32,
        amp: f32,
    ) -> Estimate<T> {
        // Unit amplitude: `a` and the scale s are applied last.
        let full = full_integral_unchecked(mu);
        let mut h = [0.0f32; MAX_SERIES];
        let len = cosine_series_f32(f.lambda, exponent, &mut h);
        let mut rho = [0.0f32; MAX_SERIES];
        let Some(rho) = rho.get_mut(..len) else {
            return Estimate { value: T::ZERO, variance: T::ZERO, unit_variance: 0.0 };
        };
        bessel_ratios(mu, rho);
        for (h, &p) in h.iter_mut().zip(rho.iter()) {
            *h *= full * p;
        }
        let rec = legendre_recurrence(len);
        let mut acc = T::ZERO;
        for (x, &a) in self.directions.iter().zip(&self.alpha) {
            acc = acc.mul_add(a, legendre_sum_f32(&h[..len], &rec, x.dot(r)));
        }
        let unit = full * full * glossy_grid_lookup(&f.glossy_variance, mu) * calibration(f, mu);
        Estimate {
            value: self.rescaled(full, acc, amp),
            variance: self.rescaled_variance(unit, amp),
            unit_variance: amp * (amp * unit),
        }
    }

    fn member_in_use(&self) -> Result<&'static sealed::Baked, Error> {
        Self::FAMILY.get(self.selected).ok_or(Error::InvalidParameter)
    }

    /// `V̄ − ζᵀQ⁻¹ζ + (I − 1ᵀQ⁻¹ζ)²/1ᵀQ⁻¹1` for `ζᵢ = ∫ k(xᵢ, x)·φ(x) dx`, `I = ∫ φ` and
    /// `V̄ = ∫∫ φ·k·φ` of a weight function `φ`, clamped at zero.
    fn unit_variance(&self, f: &sealed::Baked, zeta: &[f64; N], integral: f64, vbar: f64) -> f64 {
        let m = Self::HALF;
        // With s, d the sums and differences of mirrored ζ and E = LLᵀ, F = MMᵀ:
        // ζᵀQ⁻¹ζ = ½‖L⁻¹s‖² + ½‖M⁻¹d‖² and 1ᵀQ⁻¹ζ = gᵀs. Forward substitutions only, in
        // f64: the variance is a small difference of large terms when σ′ is small.
        let (lo, hi) = zeta.split_at(m);
        let mut s = [0.0f64; N];
        {
            let (sv, dv) = s.split_at_mut(m);
            for (((a, b), sp), dp) in lo.iter().zip(hi.iter().rev()).zip(sv).zip(dv) {
                *sp = a + b;
                *dp = a - b;
            }
        }
        let (sv, dv) = s.split_at_mut(m);
        let one: f64 = sv.iter().zip(f.g).map(|(x, &g)| x * f64::from(f32::from_bits(g))).sum();
        forward_substitution(f.chol_even, sv);
        forward_substitution(f.chol_odd, dv);
        let quad =
            0.5 * (sv.iter().map(|x| x * x).sum::<f64>() + dv.iter().map(|x| x * x).sum::<f64>());
        let (quad, one, s1) = if self.missing.is_empty() {
            (quad, one, f64::from(f.s1))
        } else {
            // The valid subset's ζ_VᵀQ_VV⁻¹ζ_V, 1ᵀQ_VV⁻¹ζ_V and s₁ by the Schur complement of
            // the missing block, from E⁻¹s and F⁻¹d (`missing.rs`).
            back_substitution(f.chol_even, sv);
            back_substitution(f.chol_odd, dv);
            self.missing.correct(sv, dv, quad, one)
        };
        let v = vbar - quad + (integral - one) * (integral - one) / s1;
        v.max(0.0)
    }

    /// The family member in use (index into [`Probe::family`]).
    #[must_use]
    pub const fn selected(&self) -> usize {
        self.selected
    }

    /// The restricted log marginal likelihood of the last update's samples under the
    /// selected member (up to a constant shared by the family), of the samples as given:
    /// `ℓ(c·Y) = ℓ(Y) − (N − 1)·C·ln c` for `C` channels.
    #[must_use]
    pub const fn log_likelihood(&self) -> f32 {
        self.log_likelihood
    }

    /// `σ̂_f² = rᵀQ⁻¹r/(N − 1)` of the last update, per channel: the diagonal of
    /// [`Probe::channel_covariance`]. Stored relative to the samples' spread, so it is exact
    /// at any radiance scale; `+∞` where `σ̂_f²` itself exceeds `f32::MAX` (samples spread
    /// wider than about 10¹⁹), 0 or subnormal below the normal range (spread under 10⁻¹⁹).
    #[must_use]
    pub fn signal_variance(&self) -> T {
        self.signal_variance.mul(self.scale).mul(self.scale)
    }

    /// `π·β`: the irradiance of the fitted constant mean (`β` is the GLS mean radiance);
    /// `±∞` where it exceeds `f32::MAX`.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::probe::Probe;
    ///
    /// let mut probe = Probe::<16>::new();
    /// probe.update(&[3.0; 16])?;
    /// // A constant's fitted mean is the constant: π·3.
    /// assert!((probe.mean_irradiance() - 3.0 * core::f32::consts::PI).abs() < 1e-4);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub fn mean_irradiance(&self) -> T {
        self.beta.scale(PI)
    }
}

fn member_of(b: &sealed::Baked, footprint: Kind) -> Member {
    Member {
        footprint,
        lambda: b.lambda,
        length_scale: crate::math::sqrt(2.0 / b.lambda),
        sigma: b.sigma,
        condition: b.condition,
        mean_variance: b.mean_variance,
        max_variance: b.max_variance,
        calibration: b.calibration,
    }
}

/// The largest lobe sharpness [`Probe::glossy`] accepts (an angular width of 10⁻⁴ rad:
/// a mirror, for any sample count).
pub const MAX_GLOSSY_SHARPNESS: f32 = 1e8;

fn check_lobe(lobe: &SphericalGaussian) -> Result<(Vec3, f32, f32), Error> {
    let r = lobe.axis.try_normalize().ok_or(Error::InvalidDirection)?;
    let mu = lobe.sharpness;
    if !(0.0..=MAX_GLOSSY_SHARPNESS).contains(&mu) {
        return Err(Error::InvalidSharpness);
    }
    if !lobe.amplitude.is_finite() {
        return Err(Error::InvalidParameter);
    }
    Ok((r, mu, lobe.amplitude))
}

/// The lobe sharpnesses of the glossy calibration factors.
const CALIBRATION_MU: [f32; 3] = [7.0, 22.0, 102.0];

/// Member `f`'s glossy calibration factor at lobe sharpness `μ`: the baked factors at
/// [`CALIBRATION_MU`], linear in `ln μ` between them, constant outside.
fn calibration(f: &sealed::Baked, mu: f32) -> f32 {
    let [_, c7, c22, c102] = f.calibration;
    let [m0, m1, m2] = CALIBRATION_MU;
    if mu <= m0 {
        return c7;
    }
    if mu >= m2 {
        return c102;
    }
    let (lo, hi, a, b) = if mu < m1 { (m0, m1, c7, c22) } else { (m1, m2, c22, c102) };
    let t = crate::math::ln(mu / lo) / crate::math::ln(hi / lo);
    a + t.clamp(0.0, 1.0) * (b - a)
}

/// The glossy variance grid at `μ`: linear between `μ = 0` and 1, then linear in `μ` within
/// each octave `[2^k, 2^(k+1)]` (the octave from the float's exponent bits), the last value
/// above 1024.
fn glossy_grid_lookup(grid: &[f32; GLOSSY_GRID], mu: f32) -> f32 {
    let at = |k: usize| grid.get(k).copied().unwrap_or(0.0);
    if mu < 1.0 {
        return at(0) + mu * (at(1) - at(0));
    }
    let top = (1u32 << (GLOSSY_GRID - 2)) as f32;
    if mu >= top {
        return at(GLOSSY_GRID - 1);
    }
    // μ = 2^e·(1 + m), e = 0…9: grid points e + 1 and e + 2.
    let e = ((mu.to_bits() >> 23) as usize).saturating_sub(127);
    let base = (1u32 << e.min(31)) as f32;
    let f = mu / base - 1.0;
    at(e + 1) + f * (at(e + 2) - at(e + 1))
}

/// `F(μ) = 2π(1 − e^(−2μ))/μ` in f64 (`4π` at `μ = 0`).
fn glossy_full_integral(mu: f64) -> f64 {
    let two_pi = 2.0 * core::f64::consts::PI;
    if mu == 0.0 {
        2.0 * two_pi
    } else {
        -two_pi * libm::expm1(-2.0 * mu) / mu
    }
}

/// `∫∫ exp(μ(r·x − 1))·exp(λ(x·x′ − 1))·exp(μ(r·x′ − 1)) dx dx′` (see
/// [`Probe::glossy_variance`]).
fn glossy_vbar(lambda: f64, mu: f64) -> f64 {
    let pi = core::f64::consts::PI;
    if mu == 0.0 {
        // ∫∫ k = 4π·F(λ).
        return 4.0 * pi * glossy_full_integral(lambda);
    }
    let rate = (2.0 * lambda + mu) / lambda;
    let end = 2.0 * lambda.min(mu);
    let width = 2.0 / rate;
    let exponent = |s: f64| s * s / (2.0 * lambda) - s * rate;
    let mut sum = 0.0;
    let mut a = 0.0;
    for _ in 0..64 {
        let b = (a + width).min(end);
        let h = b - a;
        for &(x, w) in &crate::tables::GAUSS_LEGENDRE_8 {
            let s = a + h * x;
            // 1 − e^(−2w), w = λ + μ − s; e^(−40) is below f64 resolution.
            let two_w = 2.0 * (lambda + mu - s);
            let tail = if two_w > 40.0 { 1.0 } else { -libm::expm1(-two_w) };
            sum += w * h * libm::exp(exponent(s)) * 0.5 * tail;
        }
        if b >= end || exponent(b) < -40.0 {
            break;
        }
        a = b;
    }
    8.0 * pi * pi / (lambda * mu) * sum
}

/// `π·z(t)` from the 129-node table: the nearest node's quadratic in the offset `f`,
/// `|f| ≤ ½`. `t` is clamped to [−1, 1].
#[inline]
fn z_lookup(z: &[[f32; 3]; Z_NODES], t: f32) -> f32 {
    const SCALE: f32 = (Z_NODES - 1) as f32 * 0.5;
    // Adding 1.5·2²³ rounds u ∈ [0, 128] to the nearest integer, which lands in the low
    // mantissa bits: no float-to-integer conversion (NaN gives node 0 and a NaN offset).
    const ROUND: f32 = 12_582_912.0;
    let u = (t.clamp(-1.0, 1.0) + 1.0) * SCALE;
    let r = u + ROUND;
    let k = ((r.to_bits() & 0xff) as usize).min(Z_NODES - 1);
    let f = u - (r - ROUND);
    let [v, s, c] = z[k];
    v + f * (s + f * c)
}

/// `x ← (LLᵀ)⁻¹x` for `L` stored (as f32 bits) as packed lower-triangle rows with a reciprocal
/// diagonal:
/// forward substitution by rows, then back substitution by columns through the same rows.
fn cholesky_solve<T: Radiance>(packed: &[u32], x: &mut [T]) {
    forward_solve(packed, x);
    back_solve(packed, x);
}

/// `x ← L⁻¹x` (forward substitution by rows) for the packed factor of [`cholesky_solve`].
fn forward_solve<T: Radiance>(packed: &[u32], x: &mut [T]) {
    let mut rest = packed;
    for i in 0..x.len() {
        let Some((row, r)) = rest.split_at_checked(i + 1) else { return };
        rest = r;
        let Some((&inv, off)) = row.split_last() else { return };
        let (head, tail) = x.split_at_mut(i);
        let Some(xi) = tail.first_mut() else { return };
        let acc = off
            .iter()
            .zip(head.iter())
            .fold(*xi, |acc, (&l, &xj)| acc.mul_add(xj, -f32::from_bits(l)));
        *xi = acc.scale(f32::from_bits(inv));
    }
}

/// `x ← L⁻ᵀx` (back substitution by columns through the rows) for the packed factor of
/// [`cholesky_solve`].
fn back_solve<T: Radiance>(packed: &[u32], x: &mut [T]) {
    let mut end = packed.len();
    for i in (0..x.len()).rev() {
        let start = end.saturating_sub(i + 1);
        let Some(row) = packed.get(start..end) else { return };
        end = start;
        let Some((&inv, off)) = row.split_last() else { return };
        let (head, tail) = x.split_at_mut(i);
        let Some(xi) = tail.first_mut() else { return };
        *xi = xi.scale(f32::from_bits(inv));
        let v = *xi;
        for (&l, xj) in off.iter().zip(head.iter_mut()) {
            *xj = xj.mul_add(v, -f32::from_bits(l));
        }
    }
}

/// `x ← L⁻¹x` (forward substitution only), in f64, for the packed factor as above.
fn forward_substitution(packed: &[u32], x: &mut [f64]) {
    let mut rest = packed;
    for i in 0..x.len() {
        let Some((row, r)) = rest.split_at_checked(i + 1) else { return };
        rest = r;
        let Some((&inv, off)) = row.split_last() else { return };
        let (head, tail) = x.split_at_mut(i);
        let Some(xi) = tail.first_mut() else { return };
        let acc: f64 =
            off.iter().zip(head.iter()).map(|(&l, &xj)| f64::from(f32::from_bits(l)) * xj).sum();
        *xi = (*xi - acc) * f64::from(f32::from_bits(inv));
    }
}

/// `x ← L⁻ᵀx` (back substitution), in f64, for the packed factor as above.
fn back_substitution(packed: &[u32], x: &mut [f64]) {
    let mut end = packed.len();
    for i in (0..x.len()).rev() {
        let start = end.saturating_sub(i + 1);
        let Some(row) = packed.get(start..end) else { return };
        end = start;
        let Some((&inv, off)) = row.split_last() else { return };
        let (head, tail) = x.split_at_mut(i);
        let Some(xi) = tail.first_mut() else { return };
        *xi *= f64::from(f32::from_bits(inv));
        let v = *xi;
        for (&l, xj) in off.iter().zip(head.iter_mut()) {
            *xj -= f64::from(f32::from_bits(l)) * v;
        }
    }
}

/// The most Legendre terms a baked series may have (`gen/probe.rs` refuses longer ones).
const MAX_SERIES: usize = 256;

/// The float types the series helpers run in: f32 on the glossy hot path, f64 for the exact
/// variances.
trait Real:
    Copy
    + PartialOrd
    + core::ops::Add<Output = Self>
    + core::ops::Sub<Output = Self>
    + core::ops::Mul<Output = Self>
    + core::ops::Div<Output = Self>
    + core::ops::MulAssign
{
    const ZERO: Self;
    const ONE: Self;
    fn of(x: f64) -> Self;
    fn of_usize(n: usize) -> Self;
    fn to_f64(self) -> f64;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    fn of(x: f64) -> Self {
        x as f32
    }
    fn of_usize(n: usize) -> Self {
        n as f32
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    fn of(x: f64) -> Self {
        x
    }
    fn of_usize(n: usize) -> Self {
        n as f64
    }
    fn to_f64(self) -> f64 {
        self
    }
}

/// `ρ_l(x) = i_l(x)/i₀(x)` for `l < out.len()` (modified spherical Bessel functions), in the
/// precision of `R` (f32 on the glossy hot path: each ratio to a few ulp, `ρ_l` to about `l`
/// ulp; f64 for the exact variances).
///
/// Large `x` (`x ≥ 40` and `x ≥ L²/36`, `L = out.len() − 1`): the forward recurrence
/// `ρ_{l+1} = ρ_{l−1} − (2l + 1)/x·ρ_l` from `ρ₁ = coth x − 1/x`, always in f64, whose
/// rounding grows like `e^{l²/(2x)} ≤ e^{18}` relative to `ρ₀` (below 10⁻⁸). Otherwise the
/// backward continued fraction `r_k = x/(2k + 1 + x·r_{k+1})` for `r_k = ρ_k/ρ_{k−1}`, started
/// at `max(L, x) + 32` (for `k ≥ x`, `r_k < 1/2`, so every step damps the start's error by
/// `r² < 1/4`: 32 steps give 10⁻¹⁹), at most `L + L²/36 + 72` steps.
fn bessel_ratios<R: Real>(x: R, out: &mut [R]) {
    let Some((first, rest)) = out.split_first_mut() else { return };
    *first = R::ONE;
    let xf = x.to_f64();
    if xf.is_nan() || xf <= 0.0 {
        rest.iter_mut().for_each(|r| *r = R::ZERO);
        return;
    }
    let top = rest.len() as f64;
    if xf >= 40.0 && 36.0 * xf >= top * top {
        // coth x − 1/x with e^{−2x} < 2⁻¹¹⁵: 1 − 1/x to f64 rounding.
        let mut prev = 1.0;
        let mut cur = 1.0 - 1.0 / xf;
        for (l, r) in rest.iter_mut().enumerate() {
            *r = R::of(cur);
            let next = prev - (2 * l + 3) as f64 / xf * cur;
            prev = cur;
            cur = next;
        }
        return;
    }
    let start = rest.len().max(xf as usize) + 32;
    let mut ratio = R::ZERO;
    for k in (1..=start).rev() {
        ratio = x / (R::of_usize(2 * k + 1) + x * ratio);
        if let Some(r) = rest.get_mut(k - 1) {
            *r = ratio;
        }
    }
    let mut product = R::ONE;
    for r in rest.iter_mut() {
        product *= *r;
        *r = product;
    }
}

/// `cₗ = S_l(λ)·(2l + 1)/(4π)`, the Legendre coefficients of the unit spherical Gaussian of
/// sharpness `λ` (`S_l = F(λ)·ρ_l(λ)`), in f32, into `out`; returns the number of terms kept:
/// `16 + ⌈9.1√λ⌉` (capped at [`MAX_SERIES`]), past which `S_l/S₀ < e^{−41}`.
fn sg_series_f32(lambda: f32, out: &mut [f32; MAX_SERIES]) -> usize {
    let len = (16 + (9.1 * crate::math::sqrt(lambda)) as usize).min(MAX_SERIES);
    let Some(out) = out.get_mut(..len) else { return 0 };
    bessel_ratios(lambda, out);
    let full = full_integral_unchecked(lambda);
    for (l, b) in out.iter_mut().enumerate() {
        *b *= full * (2 * l + 1) as f32 / (4.0 * PI);
    }
    len
}

/// Multiplies `out` by the gains `(p + 1)∫₀¹ tᵖ P_l(t) dt` of the normalised cosine-power lobe
/// of any real exponent `p ≥ 0` (a photodiode's response for `p = 1`, the normalised Phong
/// lobe for `p = e`): `m₀ = 1/(p + 1)`, `m₁ = 1/(p + 2)`, `m_{l+2} = m_l·(p − l)/(p + l + 3)`.
fn apply_cosine_power_gains<R: Real>(p: R, out: &mut [R]) {
    let (one, two, three) = (R::ONE, R::of(2.0), R::of(3.0));
    let (mut even, mut odd) = (one / (p + one), one / (p + two));
    for (l, b) in out.iter_mut().enumerate() {
        let m = if l % 2 == 0 { even } else { odd };
        *b *= (p + one) * m;
        let lf = R::of_usize(l);
        if l % 2 == 0 {
            even *= (p - lf) / (p + lf + three);
        } else {
            odd *= (p - lf) / (p + lf + three);
        }
    }
}

/// [`cosine_series`] in f32 (the glossy hot path).
fn cosine_series_f32(lambda: f32, exponent: u32, out: &mut [f32; MAX_SERIES]) -> usize {
    let len = sg_series_f32(lambda, out);
    if let Some(out) = out.get_mut(..len) {
        apply_cosine_power_gains(exponent as f32, out);
    }
    len
}

/// `bₗ = K_l·g_l·(2l + 1)/(4π)` of a cosine-power footprint `max(0, t)ᵖ` under the
/// squared-exponential kernel of sharpness `λ` (`K_l = F(λ)·ρₗ(λ)`, `g_l` the footprint's
/// gains), into `out`; returns the number of terms kept: `16 + ⌈9.1√λ⌉` (capped at
/// [`MAX_SERIES`]), past which `K_l/K₀ < e^{−41}`.
fn cosine_series(lambda: f64, exponent: u32, out: &mut [f64; MAX_SERIES]) -> usize {
    let len = (16 + (9.1 * crate::math::sqrt64(lambda)) as usize).min(MAX_SERIES);
    let Some(out) = out.get_mut(..len) else { return 0 };
    bessel_ratios(lambda, out);
    let full = glossy_full_integral(lambda);
    let p = f64::from(exponent);
    // (p + 1)·m_l with m₀ = 1/(p + 1), m₁ = 1/(p + 2), m_l = m_{l−2}·(p − l + 2)/(p + l + 1).
    let (mut even, mut odd) = (1.0 / (p + 1.0), 1.0 / (p + 2.0));
    for (l, b) in out.iter_mut().enumerate() {
        let m = if l % 2 == 0 { even } else { odd };
        *b *= full * (p + 1.0) * m * (2 * l + 1) as f64 / (4.0 * core::f64::consts::PI);
        let lf = l as f64;
        if l % 2 == 0 {
            even *= (p - lf) / (p + lf + 3.0);
        } else {
            odd *= (p - lf) / (p + lf + 3.0);
        }
    }
    len
}

/// `K_l·(2l + 1)/(4π)`, the kernel's Legendre coefficients, in f64, into `out`; returns the
/// number of terms. Point and cosine-power footprints: the squared exponential,
/// `K_l = F(λ)·ρₗ(λ)`, `16 + ⌈9.1√λ⌉` terms. Gaussian footprint of sharpness `S`: the
/// deconvolved kernel `K_l = F(ν)·ρₗ(ν)/ρₗ(S)` (`λ = ν`), which falls like `(ν/S)^l`:
/// [`MAX_SERIES`] terms (`gen/probe.rs` refuses members whose series has not converged by
/// then).
fn kernel_coefficients(kind: Kind, lambda: f64, out: &mut [f64; MAX_SERIES]) -> usize {
    let pi4 = 4.0 * core::f64::consts::PI;
    let full = glossy_full_integral(lambda);
    if let Kind::Gaussian { sharpness } = kind {
        let mut rs = [0.0f64; MAX_SERIES];
        bessel_ratios(lambda, out);
        bessel_ratios(f64::from(sharpness), &mut rs);
        for (l, (a, &b)) in out.iter_mut().zip(&rs).enumerate() {
            *a = if b > 0.0 { full * *a / b * (2 * l + 1) as f64 / pi4 } else { 0.0 };
        }
        return MAX_SERIES;
    }
    let len = (16 + (9.1 * crate::math::sqrt64(lambda)) as usize).min(MAX_SERIES);
    let Some(out) = out.get_mut(..len) else { return 0 };
    bessel_ratios(lambda, out);
    for (l, a) in out.iter_mut().enumerate() {
        *a *= full * (2 * l + 1) as f64 / pi4;
    }
    len
}

/// `V̄/F(μ)² = Σ_l K_l·(2l + 1)/(4π)·ρₗ(μ)²` for the Gaussian footprint's deconvolved kernel.
fn deconvolved_vbar(nu: f64, sharpness: u32, mu: f64) -> f64 {
    let mut k = [0.0f64; MAX_SERIES];
    let len = kernel_coefficients(Kind::Gaussian { sharpness }, nu, &mut k);
    let mut rho = [0.0f64; MAX_SERIES];
    bessel_ratios(mu, &mut rho);
    k.iter().zip(&rho).take(len).map(|(&k, &p)| k * p * p).sum()
}

/// `Σ_l hₗ·P_l(t)` by the forward recurrence of `P_l`, in f64.
fn legendre_sum(h: &[f64], t: f64) -> f64 {
    let t = t.clamp(-1.0, 1.0);
    let (mut p0, mut p1) = (0.0, 1.0);
    let mut sum = 0.0;
    for (l, &c) in h.iter().enumerate() {
        sum += c * p1;
        let next = ((2 * l + 1) as f64 * t * p1 - l as f64 * p0) / (l + 1) as f64;
        p0 = p1;
        p1 = next;
    }
    sum
}

/// The forward recurrence's coefficients `((2l + 1)/(l + 1), l/(l + 1))` for `l < len`, once
/// per query so that the per-sample sums do not divide.
fn legendre_recurrence(len: usize) -> [(f32, f32); MAX_SERIES] {
    let mut c = [(0.0f32, 0.0f32); MAX_SERIES];
    for (l, slot) in c.iter_mut().enumerate().take(len) {
        let lf = l as f32;
        let inv = 1.0 / (lf + 1.0);
        *slot = ((2.0 * lf + 1.0) * inv, lf * inv);
    }
    c
}

/// `Σ_l hₗ·P_l(t)` by the forward recurrence of `P_l` with the coefficients of
/// [`legendre_recurrence`], in f32 (the glossy hot path).
fn legendre_sum_f32(h: &[f32], rec: &[(f32, f32)], t: f32) -> f32 {
    let t = t.clamp(-1.0, 1.0);
    let (mut p0, mut p1) = (0.0f32, 1.0f32);
    let mut sum = 0.0f32;
    for (&c, &(a, b)) in h.iter().zip(rec) {
        sum += c * p1;
        let next = a * t * p1 - b * p0;
        p0 = p1;
        p1 = next;
    }
    sum
}

/// The normalised cosine-weighted average used by ray-traced irradiance-field probes, the
/// cheapest peer of [`Probe::irradiance`]:
/// `E ≈ π·Σ max(0, n·xⱼ)·Yⱼ / Σ max(0, n·xⱼ)` (zero when no direction is above the horizon).
///
/// # Errors
/// [`Error::InvalidDirection`] for a zero or non-finite normal; [`Error::LengthMismatch`] when
/// the slices differ in length.
///
/// # Cost
/// Cortex-M4F instructions per call (QEMU `mps2-an386`, `-icount shift=0`, `libm` backend;
/// `examples/cortex-m4`, whose output CI checks these lines against):
/// - `m4:cosine_weighted_average N=16`: 514 instructions
/// - `m4:cosine_weighted_average N=32`: 894 instructions
/// - `m4:cosine_weighted_average N=64`: 1 651 instructions
/// - `m4:cosine_weighted_average N=256`: 6 187 instructions
///
/// Flash, one call in a release build with LTO (`.ci/m4-flash.sh`, which CI checks
/// these lines against):
/// - `flash:cosine_weighted_average N=64`: 948 bytes of code and 0 bytes of tables
///   (on top of the `Probe::new` that gives the directions)
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
