//! Temporal accumulation: a probe that takes a freshly rotated set of samples at every update
//! and pools the evidence of all of them, with a change signal that aliasing cannot fake.
//!
//! Real-time probes (DDGI and its kin) trace new rays every frame and blend the results over
//! time with a fixed *hysteresis* `E ← h·E + (1 − h)·E_new`, which trades noise against lag by
//! a hand-tuned constant. [`TemporalProbe`] pools the samples themselves instead.
//!
//! # Model
//! - **Evidence, not posteriors.** Each update rotates the spherical Fibonacci set of `N`
//!   directions anew ([`RotationSequence::next_rotation`]). Under a uniformly random rotation
//!   the equal-weight projection of the samples on the real spherical harmonics,
//!   `p_lm = (4π/N)·Σⱼ (Yⱼ − Ȳ)·Y_lm(xⱼ)` (`p₀₀ = √(4π)·Ȳ`), is an unbiased estimate of the
//!   radiance's coefficient `c_lm` (of `g_l·c_lm` for a footprint of Funk–Hecke gains `g_l`),
//!   and successive updates err independently. The state is the running sum of these
//!   projections up to degree `L` (`L = 4` at `N = 16`, 6 at 64, 8 at 256: `round(log₂ N)` in
//!   `[2, 8]`, [`TemporalProbe::degree`]; a very blurry footprint stops below the first degree
//!   whose deconvolved irradiance gain `|A_l/g_l|` exceeds `2π`, which caps `Gaussian<2>` at
//!   degree 3: there the aliasing of degree 4, amplified 80×, cost 21 % error after one
//!   update on a linear sky at `N = 15`, and costs 1.1 % without it), so the estimate after
//!   `k` updates is that of all
//!   `k·N` directions: its error keeps falling like the unbiased running mean of the
//!   cosine-weighted averages does. A running mean of per-update Bayesian posteriors would
//!   not: each posterior is pulled towards the prior in the same way at every update, and
//!   that pull does not average away.
//! - **Shrinkage.** The aliasing error of a projection is close to white: the same variance
//!   `v` for every coefficient. The probe estimates `v` from the scatter of the updates about
//!   their mean (`(k − 1)·(L + 1)²` degrees of freedom) with a prior worth one update, the
//!   smallest mean square `Σ_m p_lm²/(2l + 1)` of the top three degrees of each update, and
//!   shrinks each degree of the mean towards zero by the positive-part James–Stein factor
//!   `s_l = max(0, 1 − (2l − 1)·(v/k)/Σ_m p̄_lm²)` (`s₀ = 1`). Degrees the samples resolve keep
//!   `s_l ≈ 1`; degrees lost in aliasing are damped; as `k` grows every `s_l → 1` and the
//!   estimate becomes the unbiased projection.
//! - **Queries.** Irradiance `E(n) = Σ_l A_l·s_l·Σ_m p̄_lm·Y_lm(n)/g_l` with the clamped
//!   cosine's gains `A_l` (only `l = 0, 1` and even `l` contribute), and its variance, the
//!   same for every normal: `Σ_l (A_l/g_l)²·(2l + 1)/(4π)·e_l` with `e_l` the error of one
//!   shrunk coefficient, `s_l·(v/k)` from the aliasing left after pooling plus
//!   `(1 − s_l)²·Σ_m p̄_lm²/(2l + 1)` from the shrinkage (so that a degree damped to zero
//!   keeps an error bar; [`TemporalProbe::radiance_sh_variance`] is `e_l/g_l²` of the
//!   degrees `l ≤ 2`), plus a floor for the degrees above `L`, which are not in the state and which
//!   no number of updates removes: `T_L·P̂` with
//!   `T_L = Σ_{l > L} A_l²·(2l + 1)/(4π)` (`4.1·10⁻³` at `L = 4`, `7.8·10⁻⁴` at `L = 8`) and
//!   `P̂` the largest power per coefficient `s_l·Σ_m p̄_lm²/(g_l²·(2l + 1))` of the degrees
//!   `L − 1` and `L` (the mean square over normals of the truncated irradiance of a light
//!   whose spectrum stays flat above `L`, as a point light's does). On the training maps the
//!   degrees above `L` change the irradiance by 0.1–1 % at `L = 4` and 0.07–0.4 % at `L = 8`
//!   on `clamp` light, by less than 0.02 % at `L ≥ 6` on `smooth` light
//!   (`eval/src/bin/temporal.rs`). After 10⁴ and 10⁵ static updates without forgetting
//!   (hazard 10⁻¹²) on four maps (apartment, city, night, dawn; 48 normals; `N = 16` with one
//!   sentinel, `N = 64` with none or two), every truth lies within 3σ (largest |error|/σ
//!   2.3, median 0.25–0.31: the floor is conservative; the aliasing term alone covers 65.6 %
//!   after 10⁵ at `N = 16`, largest 12.8σ) (`tests/sh/temporal.rs`).
//!   [`TemporalProbe::radiance_sh`] exports the degrees `l ≤ 2` for a renderer.
//!
//! # Change
//! Each update weighs the evidence that the light changed, as the posterior probability `π`
//! of a change since the last update (prior [`DEFAULT_HAZARD`],
//! [`TemporalProbe::with_hazard`]), and forgets old evidence accordingly: a soft, partial
//! reset, `π ≈ 1` restarting from the new update.
//! - **Sentinels re-read**: `S` of the rays per update (the const parameter,
//!   [`TemporalProbe::sentinels`]) look again where earlier updates looked, so that a change
//!   shows as the difference of two readings of one direction, which aliasing cannot fake
//!   (A-SVGF's re-shading of last frame's samples). Each sentinel tracks one direction for 4
//!   updates or more (the sentinels in turn, so that some are verified at every update), then
//!   moves to the brightest reading of the latest update's rotated samples, or returns to the
//!   brightest reading verified since the last reset (the *spot*) where that is brighter and
//!   no other sentinel watches it: a global change moves the bright readings most, and a
//!   light that switches off was bright, even a lamp that a rotated ray hits in one update of
//!   two. A reading is
//!   *verified* once its re-read repeats it; a new reading that its re-read does not repeat
//!   is decided by a third (two of three agree; no evidence either way).
//! - **A sentinel's evidence** is the Bayes factor of the change `r = y − y₀` from its
//!   verified reading `y₀` under "changed" (the new reading unrelated to the old: variance
//!   twice `y₀²` plus the samples' second moment) against "unchanged" (variance `y₀²` times
//!   the state level's relative variance, clamped to `[0.05², 0.1²]`: a change of 10 % always
//!   matters, one of 5 % never does, so that a slow drift between two readings is not a
//!   change). Only evidence *for* a change counts. A change alone at one sentinel may be an
//!   outlier (a firefly) or a flicker: the sentinel keeps its direction, and its next reading
//!   confirms the change (it repeats the changed reading: the evidence counts, a reset after
//!   two updates) or refutes it (back at the verified reading: no evidence). Changes seen
//!   together in three octants of the sphere count at once, each capped at `ln 32`.
//! - **Novel readings**: a lamp that switches on lights few directions, and a rotated ray
//!   that hits it reads far brighter than anything its octant showed before. The update's
//!   brightest rotated reading is *novel* where it exceeds the brightest reading of its
//!   octant since the last reset (over 8 pooled updates or more) by `2048/N` within
//!   `[8, 32]`, and carries over a tenth of the state's level. Two sentinels (`S ≥ 2`)
//!   re-read it at the next update, taken from their directions if none is free: both
//!   repeat it, and the change counts with `ln 64 + ln(ratio/bar)` (a reset at the default
//!   hazard, the innovation's evidence against it set aside); one does not, and it was an
//!   outlier (no evidence, no alarm). A small bright spot that a static light shows for the
//!   first time looks the same: the bar keeps such first sightings rare.
//! - **Noisy rays**: a path tracer's readings of one direction differ even where nothing
//!   changed. The probe learns the 90th percentile of `(b − a)²/(a² + b²)` over its pairs of
//!   readings (their brightness) and adds it, times the readings' mean square, to the
//!   "unchanged" variance; readings that repeat exactly, as a map's do, leave it at 0.
//!   Where re-reads disagree often, a sentinel's evidence is capped at what such
//!   disagreements are worth under static light.
//! - **The level**: capped re-reads can miss a light that switches off while the scene's
//!   interreflection remains, but every update's level moves. The mean brightness of the
//!   update's rotated samples, the brightest left out, is compared with the state's level;
//!   the probe learns the 95th percentile of their log ratio and counts a level beyond it as
//!   evidence, a dark level against a lit one as a certain change (module `level`).
//! - **Regions**: a lamp that switches on beside a brighter sun is not novel, and a change
//!   over part of the sphere is diluted in every global statistic. The probe also keeps the
//!   mean reading of each of eight overlapping regions fixed in the world ([`local_region`]),
//!   the heaviest sample left out, and learns how far it strays; a region off by five times
//!   that (and by a tenth of its level) twice in a row, the same way (a brightening from the
//!   same place), is a change for certain (with 35 rotated rays or more: a region's reading
//!   must rest on a dozen samples or so): the state restarts, and
//!   [`TemporalProbe::last_changed_regions`] names the regions. (Forgetting in the changed regions alone was measured and gave no gain over
//!   the restart: module `region` says why.)
//! - **Drift**: light that brightens or dims a little at every update shows in no single
//!   update, but the pooled state lags behind it. The probe keeps the running mean of the
//!   update's level against the state's, in units of its own noise; a lag beyond its noise
//!   by more than the hazard's odds is a drift, and the state then pools no more updates
//!   than minimise its level's error under that drift (bias against noise), without a reset
//!   (module `level`). On the held-out maps of `docs/temporal.md`, under a drift of 1 % per
//!   update, the error / the best of hysteresis and DDGI at `k = 16` is 1.09, 1.27, 1.11 at
//!   `N = 16, 64, 256` on `clamp` light and 0.98, 0.10, 0.05 on `smooth` light.
//! - **Innovation**: the new update's projection of degrees `l ≤ 2` (every channel) against
//!   the state's mean, `d = p − p̄`: variance `v·(1 + 1/k)` on static light, more by twice each
//!   degree's power when the light is new, both multivariate Student t of 3 degrees of
//!   freedom (an aliasing outlier inflates every coefficient of its update at once). Without
//!   sentinels it is the change signal. With them only its evidence *against* a change
//!   counts: aliasing can fake a change, and forgetting the old evidence for an outlier would
//!   make the outlier weigh more.
//! - **Forgetting**: for a change (with sentinels `π ≥ ½`, without them a positive log Bayes
//!   factor of the innovation), the mixture of "changed" (the new update alone)
//!   and "unchanged" (pooled with the old evidence) is collapsed to one pooled state with the
//!   same mean: the old evidence keeps the weight `w′ = (1 − π)·w/(1 + π·w)` of its `w`.
//!   Otherwise it keeps `(1 − π)·w`, with `π` at most the hazard where nothing sees a
//!   change, so that static light pools
//!   towards `1/h` updates even where aliasing makes the evidence weak (repeated collapses
//!   would cap the weight at `1/√π`). Without sentinels a static map with a sun or lamps
//!   pools 28–49 updates on average at `N = 16` (513–754 on `city`), where collapsing at every
//!   update pooled 15–21 (67–69) (`tests/sh/temporal.rs`).
//! - **The price**: sentinels are rays that add nothing to the estimate. Measured
//!   (`eval/src/bin/temporal.rs`, `docs/temporal.md`, held-out maps, `clamp` light),
//!   1, 2, 4 sentinels of 16, 64, 256 rays detect a ×0.5 or a switch between maps within two
//!   updates in 99–100 % of sequences (a ×10 or ×0.1 within one in 56–100 %), a ×1.3 in 67,
//!   98, 100 % and a 30° turn of the light in 77, 98, 100 %, where the innovation alone
//!   misses most switches between maps; a small lamp switching on (1 % of the sphere, as
//!   bright as the rest of the light together) in 2, 35, 86 %, and its switching off in 55,
//!   99, 100 %. Point rays bound what any test can see there: one of the probe's rays fell
//!   in such a lamp within two updates in 29, 85, 100 % of sequences, two of them (what
//!   tells a lamp from a firefly) in 15, 65, 100 %. Static light stays at
//!   1.03–1.13× the oracle's error after 64 updates, with 0.2, 0.9, 0.6 false resets per
//!   1 000 static updates; with 1 % of the rays fireflies, 1.0, 3.6, 12.7.
//!
//! ```
//! use sphere_quadrature::footprint::Point;
//! use sphere_quadrature::temporal::{Change, TemporalProbe};
//! use sphere_quadrature::Vec3;
//!
//! // 60 rotated directions and 4 sentinels: 64 rays per update.
//! let mut probe = TemporalProbe::<60, f32, Point, 4>::new(7);
//! let sky = |d: Vec3| 1.0 + 0.5 * d.z;
//! for frame in 0..8 {
//!     let samples = probe.directions().map(sky);
//!     let sentinels = probe.sentinels().map(sky);
//!     let change = probe.pool(&samples, &sentinels)?;
//!     assert_eq!(change, if frame == 0 { Change::First } else { Change::Blended });
//! }
//! let e = probe.irradiance(Vec3::Z)?;
//! // π·(1 + 0.5·2/3) = 4.18879.
//! assert!((e.value - 4.18879).abs() < 0.01);
//! // The light switches off: the sentinels see it, and the state restarts within two
//! // updates (at once where three octants' sentinels see it together).
//! let first = probe.pool(&[0.0; 60], &[0.0; 4])?;
//! if first != Change::Reset {
//!     assert_eq!(probe.pool(&[0.0; 60], &[0.0; 4])?, Change::Reset);
//! }
//! // What the old evidence keeps is below 1 % of the estimate.
//! assert!(probe.irradiance(Vec3::Z)?.value.abs() < 0.04);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Radiance scale
//! Samples may be in any units: for `c·Y` every value is `c` times and every variance `c²`
//! times the answer for `Y`, and every decision ([`Change`], the pooled updates) is the
//! same, for `c` from 10⁻³⁰ to 10³⁰ (subnormal samples included; `±∞` only where the answer
//! itself exceeds `f32::MAX`, 0 or subnormal where it is below the normal range). The state
//! is kept in units of a power of two `2^e` (channels together), moved to an update's largest
//! sample when that is more than `2^20` above it, or more than `2^20` below it at a reset
//! (the old evidence dropped), so that no square or sum of squares overflows or underflows;
//! the queries apply `2^e` last. Powers of two are exact: for `c` a
//! power of two the answers are `c` (`c²`) times bit for bit where they are normal numbers.
//! Samples whose largest magnitude stays within `2^±20` of 1 never move the scale from 1
//! (and pay for no rescaling). Measured (`tests/sh/temporal.rs`, `c` from 10⁻³⁰
//! to 10³⁰ and `2^±100`, a light with a part 10⁻¹² as bright): values within 9.8·10⁻⁷ and
//! variances within 4.1·10⁻⁶ relative of `c` (`c²`) times the answers at `c = 1`, and the
//! same decisions, over a schedule with a switch, a switch-off and a switch-on; a switch-off
//! is a reset at any brightness after 10⁵ updates (and 10⁶, in an ignored test). A single
//! finite sample of any size leaves no later answer NaN: it is data, pooled into the mean
//! with its error bar (`±∞` where that exceeds `f32::MAX`) until the light changes.
//!
//! # Bad input
//! A non-finite sample or sentinel reading: [`Error::InvalidRadiance`], the state and the
//! directions unchanged (retake the samples). A zero or non-finite normal:
//! [`Error::InvalidDirection`]. A hazard outside `(0, 1)`: [`Error::InvalidHazard`]. A
//! footprint whose parameter is 0 or above [`MAX_PARAMETER`] does not compile
//! ([`TemporalProbe::new`]). Before the first update there is no data: every query returns
//! zero with zero variance (and [`TemporalProbe::updates`] is 0).
//!
//!
//! # Cost
//! Instructions per call and flash on a Cortex-M4F: [`costs`](crate::costs#the-temporal-probe).

use crate::error::Error;
use crate::estimate::Estimate;
use crate::footprint::{Footprint, Kind, Point, MAX_PARAMETER};
use crate::harmonics::{self, Factors, Tables};
use crate::math;
use crate::radiance::Radiance;
use crate::rotation::RotationSequence;
use crate::sf::{FibonacciPoints, SphericalFibonacci};
use crate::sh::ShL2;
use crate::vec3::Vec3;
use core::cell::Cell;
use core::f32::consts::PI;
use core::marker::PhantomData;

/// The highest spherical-harmonic degree a temporal probe holds.
pub const MAX_DEGREE: usize = 8;
const _: () = assert!(MAX_DEGREE <= harmonics::TABLE_DEGREE);

/// The degrees of freedom of the Student t of the change test's innovation.
const TAIL: f32 = 3.0;

/// How far (in powers of two) a sample's magnitude may stray from the state's scale before
/// the state is rescaled: within it every square and sum of squares of the state is a normal
/// f32 number far from overflow.
const SCALE_WINDOW: i32 = 20;
/// `√(4π)`: the degree-0 coefficient of a constant 1.
const SQRT_4PI: f32 = 3.544_907_7;

/// The smallest and largest relative change of a re-read that the change test tolerates as
/// within the state's error.
const TOLERANCE: (f32, f32) = (0.05, 0.1);

/// Coefficients of degrees `0..=MAX_DEGREE`.
const COEFFICIENTS: usize = (MAX_DEGREE + 1) * (MAX_DEGREE + 1);

/// The clamped cosine's Funk–Hecke gains `A_l` for `l ≤ 8` (`π`, `2π/3`, `π/4`, 0, `−π/24`,
/// 0, `π/64`, 0, `−π/128`).
const IRRADIANCE_GAIN: [f32; MAX_DEGREE + 1] = crate::legendre::clamped_cosine_gains();

/// `T_L = Σ_{l > L} A_l²·(2l + 1)/(4π)` for `L ≤ 8`: the mean square over normals of the
/// irradiance of the degrees above `L` of a radiance of unit power per coefficient (computed
/// in f64 as `2π/3 − Σ_{l ≤ L} A_l²·(2l + 1)/(4π)`, rounded once; the unit tests below
/// recompute them).
const TRUNCATION: [f32; MAX_DEGREE + 1] = [
    1.3089969,
    0.2617994,
    0.016362462,
    0.016362462,
    0.0040906155,
    0.0040906155,
    0.0015978967,
    0.0015978967,
    0.00078296935,
];

/// Real spherical harmonics `Y_lm(u)` of degrees `l ≤ degree` at index `l(l + 1) + m`, for
/// `u` of unit length (the basis of [`crate::sh`]), in f32.
fn basis(degree: usize, u: Vec3, out: &mut [f32; COEFFICIENTS]) {
    harmonics::for_each(&Tables, [u.x, u.y, u.z], degree, |i, v| {
        if let Some(o) = out.get_mut(i) {
            *o = v;
        }
    });
}

/// The degree capped below the first degree whose irradiance gain after deconvolution,
/// `|A_l/g_l|`, exceeds `2π` (twice the level's `π`): a blurrier footprint would amplify that
/// degree's aliasing into the irradiance more than its signal is worth. At least 2.
fn degree_for_footprint(degree: usize, inverse_gain: &[f32; MAX_DEGREE + 1]) -> usize {
    let limit = 2.0 * PI;
    for l in 3..=degree {
        if (IRRADIANCE_GAIN[l] * inverse_gain[l]).abs() > limit {
            return l - 1;
        }
    }
    degree
}

/// `p[i] += v` (nothing past the end).
fn add_at<T: Radiance>(p: &mut [T; COEFFICIENTS], i: usize, v: T) {
    if let Some(pi) = p.get_mut(i) {
        *pi = pi.add(v);
    }
}

/// Whether a footprint's parameter is one [`Kind::gain`] accepts: `1..=MAX_PARAMETER`.
const fn valid_footprint(kind: Kind) -> bool {
    match kind {
        Kind::Point => true,
        Kind::Gaussian { sharpness: p } | Kind::CosinePower { exponent: p } => {
            p >= 1 && p <= MAX_PARAMETER
        }
    }
}

/// The degree a probe of `n` directions holds: `round(log₂ n)` in `[2, MAX_DEGREE]`.
const fn degree_for(n: usize) -> usize {
    // round(log₂ n) = ⌊log₂(n·√2)⌋; n·√2 ≥ 2^k ⇔ 2n² ≥ 4^k.
    let mut k = 0;
    while k < MAX_DEGREE && 2 * (n as u128) * (n as u128) >= 1u128 << (2 * (k + 1)) {
        k += 1;
    }
    if k < 2 {
        2
    } else {
        k
    }
}

/// The spherical Fibonacci set of `N` points, unrotated, evaluated at compile time (`12·N`
/// bytes of flash): bit for bit [`SphericalFibonacci::points`].
struct BaseSet<const N: usize>;

impl<const N: usize> BaseSet<N> {
    const POINTS: [Vec3; N] = SphericalFibonacci::<N>::new().dynamic().unrotated_points::<N>();
}

/// Region `o` of the local change test ([`TemporalProbe::last_changed_regions`]), `o < 8`: its centre
/// `(±1, ±1, ±1)/√3` (bit 0 of `o` set for `x < 0`, bit 1 for `y < 0`, bit 2 for `z < 0`) and
/// the cosine of its radius (72.5°). `None` for `o ≥ 8`.
///
/// ```
/// use sphere_quadrature::temporal::local_region;
///
/// let (centre, cos_radius) = local_region(0).unwrap();
/// assert!(centre.x > 0.0 && centre.y > 0.0 && centre.z > 0.0);
/// assert!((cos_radius - 0.3).abs() < 1e-6);
/// assert!(local_region(8).is_none());
/// ```
#[must_use]
pub fn local_region(o: u32) -> Option<(Vec3, f32)> {
    (o < region::REGIONS as u32).then(|| (region::centre(o as usize), region::COS_RADIUS))
}

/// An RGB temporal probe: [`TemporalProbe`] with `[f32; 3]` samples.
///
/// ```
/// use sphere_quadrature::temporal::RgbTemporalProbe;
///
/// let probe = RgbTemporalProbe::<64>::new(7);
/// assert_eq!(probe.directions().len(), 64);
/// ```
pub type RgbTemporalProbe<const N: usize, F = Point, const S: usize = 0> =
    TemporalProbe<N, [f32; 3], F, S>;

/// A probe updated again and again under fresh rotations of `N` directions, pooling the
/// evidence of every sample (see the module docs), with `S` sentinels that re-read earlier
/// directions for the change signal. `T` is `f32` or RGB `[f32; C]`, `F` the samples' footprint
/// ([`crate::footprint`]). Any `N ≥ 1` works: the probe needs no baked tables.
///
/// It holds its directions and three sets of 81 coefficients per channel (the sums, their
/// rounding errors and the queries'): 4 696 bytes for `N = 64`, RGB, `S = 4`; 2 256 for
/// `N = 64`, one channel, no sentinels, on a 64-bit host (a unit test pins both).
///
/// # Examples
/// ```
/// use sphere_quadrature::{temporal::TemporalProbe, Vec3};
///
/// // Every frame: take the samples along the current directions, then update.
/// let mut probe = TemporalProbe::<64, [f32; 3]>::new(11);
/// for _ in 0..8 {
///     let samples = probe.directions().map(|d| [1.0 + 0.5 * d.z; 3]);
///     probe.pool(&samples, &[])?;
/// }
/// assert_eq!(probe.updates(), 8);
/// let e = probe.irradiance(Vec3::Z)?;
/// // π·(1 + 0.5·2/3), per channel.
/// assert!(e.value.iter().all(|&v| (v - 4.18879).abs() < 0.01));
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct TemporalProbe<
    const N: usize,
    T: Radiance = f32,
    F: Footprint = Point,
    const S: usize = 0,
> {
    rotations: RotationSequence,
    directions: [Vec3; N],
    sentinel_directions: [Vec3; S],
    degree: usize,
    /// `1/g_l`, 0 where the footprint's gain vanishes (that degree is not observed).
    inverse_gain: [f32; MAX_DEGREE + 1],
    /// The hazard's prior log odds `ln(h/(1 − h))`.
    prior_log_odds: f32,
    /// `Σ w·p` over the updates, `w` the weight each keeps after the soft resets.
    sum: [T; COEFFICIENTS],
    /// The rounding error of `sum` (compensated summation: the exact sum is `sum − sum_error`).
    sum_error: [T; COEFFICIENTS],
    /// `Σ w`.
    weight: f32,
    /// The weighted scatter of the projections about their mean, per channel.
    scatter: T,
    /// Its degrees of freedom.
    dof: f32,
    /// `Σ w·v₁`, the per-update noise estimates (smallest top-degree mean square).
    noise_prior: T,
    /// `Σ w·v̄₁`, the conservative per-update noise estimates (mean top-degree mean square)
    /// of the change test.
    noise_prior_test: T,
    /// The re-read slots: what each slot's reading is compared with.
    slots: [reread::Slot<T>; S],
    /// The brightest rotated sample seen in each octant since the last reset (brightness, in
    /// units of `2^scale`): what makes a reading novel.
    peaks: [f32; 8],
    /// The brightest verified reading since the last reset and its direction (brightness 0:
    /// none): a free slot returns to it unless the latest update read brighter.
    spot: (Vec3, T),
    novel_confirmed: bool,
    /// The running 90th percentile of `(b − a)²/(a² + b²)` over pairs of readings of one
    /// direction (their brightness): 0 where readings repeat exactly.
    repeat_noise: f32,
    /// The running share of re-reads that disagree with the reading they re-read: what a
    /// re-read's evidence can be worth at most.
    disagree_rate: f32,
    /// The running 95th percentile of how far an update's level strays from the state's
    /// (module `level`).
    level_spread: f32,
    /// The level's drift (module `level`).
    drift: level::Drift,
    /// What the probe knows of each region (module `region`).
    regions: [region::Region<T>; region::REGIONS],
    /// The regions whose test confirmed a change at the last update (bit `o` for region `o`).
    last_regions: u8,

    /// The state's scale: every statistic above is in units of `2^scale` (second moments in
    /// units of `4^scale`), so that none depends on the units of the samples.
    scale: i32,
    /// The queries' coefficients `A_l·s_l·p̄_lm/g_l` (0 for the degrees without `A_l`), in
    /// units of `2^scale`.
    irradiance_coefficients: [T; COEFFICIENTS],
    /// The aliasing variance of an irradiance query, in units of `4^scale`.
    irradiance_variance: T,
    /// The variance of an irradiance query, in the samples' units squared.
    query_variance: T,
    /// The shrunk, deconvolved coefficients of degrees `l ≤ 2` and their variances, in the
    /// samples' units.
    sh: ShL2<T>,
    sh_variance: [T; 9],
    updates: u32,
    last_change_probability: f32,
    last_evidence: (f32, f32),
    footprint: PhantomData<F>,
}

/// The per-channel sum of squares of `x`.
fn sum_squares<T: Radiance>(x: &[T]) -> T {
    x.iter().fold(T::ZERO, |acc, &v| acc.add(v.mul(v)))
}

impl<const N: usize, T: Radiance, F: Footprint, const S: usize> TemporalProbe<N, T, F, S> {
    /// A temporal probe whose rotations come from `seed`, with no data yet.
    ///
    /// A footprint whose parameter is 0 or above [`MAX_PARAMETER`] (`Gaussian<0>`,
    /// `CosinePower<5000>`) does not compile:
    /// ```compile_fail,E0080
    /// use sphere_quadrature::footprint::Gaussian;
    /// use sphere_quadrature::temporal::TemporalProbe;
    ///
    /// let _ = TemporalProbe::<64, f32, Gaussian<0>>::new(1);
    /// ```
    /// ```compile_fail,E0080
    /// use sphere_quadrature::footprint::CosinePower;
    /// use sphere_quadrature::temporal::TemporalProbe;
    ///
    /// let _ = TemporalProbe::<64, f32, CosinePower<5000>>::new(1);
    /// ```
    /// ```
    /// use sphere_quadrature::footprint::{CosinePower, Gaussian};
    /// use sphere_quadrature::temporal::TemporalProbe;
    ///
    /// // The extremes of the range compile.
    /// let _ = TemporalProbe::<64, f32, Gaussian<4096>>::new(1);
    /// let _ = TemporalProbe::<64, f32, CosinePower<1>>::new(1);
    /// ```
    #[must_use]
    pub fn new(seed: u64) -> Self {
        let () = crate::radiance::Channels::<T>::VALID;
        const {
            assert!(
                valid_footprint(F::KIND),
                "TemporalProbe: a footprint's sharpness or exponent must be in 1..=4096"
            )
        };
        let mut inverse_gain = [0.0f32; MAX_DEGREE + 1];
        for (l, g) in inverse_gain.iter_mut().enumerate() {
            // Every footprint type has a valid parameter (sealed), so gain() succeeds.
            let gain = F::KIND.gain(l).unwrap_or(0.0);
            *g = if gain.abs() > 1e-6 { (1.0 / gain) as f32 } else { 0.0 };
        }
        let mut probe = Self {
            rotations: RotationSequence::new(seed),
            directions: [Vec3::ZERO; N],
            // (The dynamic set: `SphericalFibonacci::<0>` is a compile-time error, `S = 0` is
            // allowed here.)
            sentinel_directions: match FibonacciPoints::sphere(S) {
                Ok(set) => core::array::from_fn(|j| set.point(j).unwrap_or(Vec3::Z)),
                Err(_) => [Vec3::Z; S],
            },
            degree: degree_for_footprint(degree_for(N), &inverse_gain),
            inverse_gain,
            prior_log_odds: log_odds(DEFAULT_HAZARD),
            sum: [T::ZERO; COEFFICIENTS],
            sum_error: [T::ZERO; COEFFICIENTS],
            weight: 0.0,
            scatter: T::ZERO,
            dof: 0.0,
            noise_prior: T::ZERO,
            noise_prior_test: T::ZERO,
            slots: [reread::Slot::EMPTY; S],
            peaks: [0.0; 8],
            spot: (Vec3::Z, T::ZERO),
            novel_confirmed: false,
            repeat_noise: 0.0,
            disagree_rate: reread::DISAGREE_FLOOR,
            level_spread: level::SPREAD_START,
            drift: level::Drift::EMPTY,
            regions: [region::Region::EMPTY; region::REGIONS],
            last_regions: 0,
            scale: 0,
            irradiance_coefficients: [T::ZERO; COEFFICIENTS],
            irradiance_variance: T::ZERO,
            query_variance: T::ZERO,
            sh: ShL2::ZERO,
            sh_variance: [T::ZERO; 9],
            updates: 0,
            last_change_probability: 0.0,
            last_evidence: (0.0, 0.0),
            footprint: PhantomData,
        };
        probe.rotate();
        probe
    }

    /// The same probe with another prior probability `h` that the light changes at an update:
    /// higher resets sooner on weak evidence, lower needs stronger evidence.
    ///
    /// # Errors
    /// [`Error::InvalidHazard`] unless `0 < h < 1`.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{temporal::TemporalProbe, Error};
    ///
    /// let probe = TemporalProbe::<16>::new(0).with_hazard(0.001)?;
    /// assert_eq!(probe.updates(), 0);
    /// assert_eq!(TemporalProbe::<16>::new(0).with_hazard(1.0).err(), Some(Error::InvalidHazard));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn with_hazard(mut self, h: f32) -> Result<Self, Error> {
        if !(h > 0.0 && h < 1.0) {
            return Err(Error::InvalidHazard);
        }
        self.prior_log_odds = log_odds(h);
        Ok(self)
    }

    /// The directions in which to take this update's samples (a new rotation after every
    /// successful update).
    #[must_use]
    pub const fn directions(&self) -> &[Vec3; N] {
        &self.directions
    }

    /// The directions in which to take this update's sentinel readings: directions of earlier
    /// updates, re-read (module docs; before the first update, the spherical Fibonacci set of
    /// `S` points).
    #[must_use]
    pub const fn sentinels(&self) -> &[Vec3; S] {
        &self.sentinel_directions
    }

    /// The spherical-harmonic degree `L` of the state: `round(log₂ N)` in `[2, 8]`, lower for
    /// a very blurry footprint (module docs).
    #[must_use]
    pub const fn degree(&self) -> usize {
        self.degree
    }

    /// Rotates the set for the next update: the unrotated set (evaluated at compile time)
    /// times a fresh rotation, orthonormal by construction (Shoemake's, from a unit
    /// quaternion).
    fn rotate(&mut self) {
        let r = self.rotations.next_rotation_turns();
        for (d, &x) in self.directions.iter_mut().zip(&BaseSet::<N>::POINTS) {
            *d = r * x;
        }
    }

    /// Takes this update's samples (radiance in [`TemporalProbe::directions`], in order) and
    /// sentinel readings (in [`TemporalProbe::sentinels`]), weighs the evidence of a change,
    /// pools the samples with the state and rotates the set for the next update.
    ///
    /// # Errors
    /// [`Error::InvalidRadiance`] for a non-finite sample or reading: the state and the
    /// directions are unchanged.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{temporal::TemporalProbe, Error};
    ///
    /// let mut probe = TemporalProbe::<16>::new(1);
    /// // A NaN sample is refused and nothing changes.
    /// let mut samples = [1.0f32; 16];
    /// samples[3] = f32::NAN;
    /// assert_eq!(probe.pool(&samples, &[]), Err(Error::InvalidRadiance));
    /// assert_eq!(probe.updates(), 0);
    /// samples[3] = 1.0;
    /// probe.pool(&samples, &[])?;
    /// assert_eq!(probe.updates(), 1);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn pool(&mut self, samples: &[T; N], sentinels: &[T; S]) -> Result<Change, Error> {
        let (original_samples, original_sentinels) = (samples, sentinels);
        let own = self.enter_units(samples, sentinels)?;
        let first = self.weight <= 0.0;
        let (scaled, scaled_sentinels);
        let (mut samples, mut sentinels) = (samples, sentinels);
        if self.scale != 0 {
            scaled = in_units(samples, self.scale);
            scaled_sentinels = in_units(sentinels, self.scale);
            (samples, sentinels) = (&scaled, &scaled_sentinels);
        }
        let count = (self.degree + 1) * (self.degree + 1);
        let (mut p, mut v1, mut v1_test) = self.project_with_noise(samples);
        let mut level_now = level::trimmed_mean(samples);
        let w = self.weight;
        let mut innovation = [T::ZERO; COEFFICIENTS];
        let (mut log_bf_rotated, mut log_bf_sentinel) = (0.0f32, 0.0f32);
        if !first {
            for (d, (&pi, &si)) in innovation.iter_mut().zip(p.iter().zip(&self.sum)).take(count) {
                *d = pi.add(si.scale(-1.0 / w));
            }
            log_bf_rotated = self.innovation_evidence(&innovation);
            // Re-reads: evidence for a change only (module `reread`).
            let second_moment = sum_squares(samples).scale(1.0 / N as f32);
            log_bf_sentinel = self.weigh_rereads(sentinels, second_moment);
            if S > 0 {
                log_bf_sentinel += self.weigh_level(level_now);
            }
        }
        // With sentinels the innovation alone does not forget: aliasing can fake it, and an
        // outlier that made the old evidence weigh less would weigh more itself. It adds to
        // the evidence of a change the sentinels see.
        let raw_rotated = log_bf_rotated;
        if S > 0 {
            // A novel reading its re-reads confirmed is seen directly: the innovation's
            // evidence against a change (an aliasing outlier's) does not weigh against it.
            log_bf_rotated = if self.novel_confirmed { 0.0 } else { log_bf_rotated.min(0.0) };
        }
        let mut probability = if first {
            1.0
        } else {
            logistic(self.prior_log_odds + log_bf_rotated + log_bf_sentinel)
        };
        // Where the light changed in part of the sphere (module `region`): a change for
        // certain.
        self.last_regions =
            if first || probability >= 0.5 { 0 } else { self.weigh_regions(samples) };
        if self.last_regions != 0 {
            probability = 1.0;
        }
        if probability >= 0.5 {
            self.regions = [region::Region::EMPTY; region::REGIONS];
        }
        let novelty =
            if S >= reread::NOVEL_REREADS && !first { self.novelty(samples) } else { None };
        let confirmed = if S == 0 { log_bf_rotated > 0.0 } else { probability >= 0.5 };
        let kept = if first { 0.0 } else { self.kept_weight(probability, confirmed) };
        if probability >= 0.5 {
            self.drift.restart(level_now);
        } else {
            self.drift.observe(level_now, w);
        }
        let (restart_samples, restart_sentinels);
        if let (Some(e), true) = (own, kept <= 0.0) {
            // The old evidence is dropped and the new is far smaller: restart at its scale.
            self.restart_at(e);
            restart_samples = in_units(original_samples, e);
            restart_sentinels = in_units(original_sentinels, e);
            (samples, sentinels) = (&restart_samples, &restart_sentinels);
            (p, v1, v1_test) = self.project_with_noise(samples);
            level_now = level::trimmed_mean(samples);
        }
        self.pool_projection(&p, (v1, v1_test), &innovation, kept, level_now);
        if S > 0 {
            self.move_sentinels(samples, sentinels, probability >= 0.5, first, novelty);
        }
        self.last_change_probability = if first { 0.0 } else { probability };
        self.last_evidence = (raw_rotated, log_bf_sentinel);
        self.updates = self.updates.saturating_add(1);
        self.refresh();
        self.rotate();
        Ok(if first {
            Change::First
        } else if probability >= 0.5 {
            Change::Reset
        } else {
            Change::Blended
        })
    }

    /// Checks the samples and sentinel readings (all finite) and moves the state to units
    /// that hold them: rescaled when they leave its window upwards, or at a first update;
    /// samples far below it return their own scale (`Some(e)`), where the state restarts if
    /// the old evidence is then dropped (until then they are taken at the state's).
    fn enter_units(&mut self, samples: &[T; N], sentinels: &[T; S]) -> Result<Option<i32>, Error> {
        let channels = |&y: &T| (0..T::CHANNELS).map(move |c| y.channel(c));
        let peak = scale::peak_bits(samples.iter().chain(sentinels).flat_map(channels))
            .ok_or(Error::InvalidRadiance)?;
        let first = self.weight <= 0.0;
        let mut own = None;
        if peak > 0 {
            let e = math::binade(f32::from_bits(peak));
            if first && (e - self.scale).abs() > SCALE_WINDOW {
                self.scale = e;
            } else if e - self.scale > SCALE_WINDOW {
                self.rescale(e);
            } else if e - self.scale < -SCALE_WINDOW {
                own = Some(e);
            }
        }
        Ok(own)
    }

    /// The innovation's log Bayes factor of a change: the degrees `l ≤ 2` (all channels) of
    /// `innovation` against `v·(1 + 1/k)` (static) or that plus twice the degree's power (new
    /// light), both multivariate Student t of `TAIL` degrees of freedom (an aliasing outlier
    /// inflates every coefficient of its update together).
    fn innovation_evidence(&self, innovation: &[T; COEFFICIENTS]) -> f32 {
        let w = self.weight;
        let vt = self.noise_with(self.noise_prior_test);
        let (mut z0, mut z1, mut log_det, mut q) = (0.0f32, 0.0f32, 0.0f32, 0.0f32);
        for ch in 0..T::CHANNELS {
            let vc = vt.channel(ch);
            // A floor of 10⁻⁵ of the mean level: rounding is not a change.
            let floor = 1e-5 * self.sum[0].channel(ch) / w;
            let s0 = vc * (1.0 + 1.0 / w) + floor * floor;
            for l in 0..=2usize {
                let range = l * l..(l + 1) * (l + 1);
                let mean_power = sum_squares(&self.sum[range.clone()]).channel(ch)
                    / (w * w * (2 * l + 1) as f32);
                let psi = 2.0 * (mean_power - vc / w).max(vc / w);
                let ss = sum_squares(&innovation[range]).channel(ch);
                let m = (2 * l + 1) as f32;
                if s0 > 0.0 {
                    z0 += ss / s0;
                    z1 += ss / (s0 + psi);
                    log_det += m * math::ln_1p(psi / s0);
                    q += m;
                } else if ss > 0.0 {
                    // No noise: any change is certain.
                    z0 = f32::INFINITY;
                } else if psi > 0.0 {
                    // No noise and an exact repeat: no change.
                    log_det = f32::INFINITY;
                }
            }
        }
        if z0 == f32::INFINITY {
            f32::INFINITY
        } else if log_det == f32::INFINITY {
            f32::NEG_INFINITY
        } else {
            -0.5 * log_det - 0.5 * (TAIL + q) * (math::ln_1p(z1 / TAIL) - math::ln_1p(z0 / TAIL))
        }
    }

    /// The regions where this update confirms a local change (module `region`), tested where
    /// the probe has directions enough.
    fn weigh_regions(&mut self, samples: &[T; N]) -> u8 {
        if !region::tested(N) {
            return 0;
        }
        let found = region::readings(&self.directions, samples, &self.regions);
        region::weigh(&mut self.regions, &found)
    }

    /// The old evidence's weight after an update with change probability `probability`, under
    /// drift no more than the drift leaves current (module `level`). For a change
    /// (`confirmed`: a sentinel's evidence, or without sentinels the innovation's) the mixture
    /// of "changed" (the new update alone) and "unchanged" (pooled with the old evidence)
    /// collapsed to one pooled state with the same mean, so the old evidence keeps the weight
    /// `w′` with `w′/(w′ + 1) = (1 − π)·w/(w + 1)`. Otherwise (π at most the hazard): the old
    /// weight times `1 − π`. (Collapsing at every update would cap the weight at `1/√π`:
    /// static light with weak evidence, such as a bright spot's aliasing, would never pool.)
    fn kept_weight(&self, probability: f32, confirmed: bool) -> f32 {
        let w = self.weight;
        let kept = if confirmed { soft_reset(probability, w) } else { (1.0 - probability) * w };
        kept.min(self.drift.cap(w, self.prior_log_odds))
    }

    /// Pools this update's projection `p` (its noise estimates `v₁`, `v̄₁`, its `innovation`
    /// and trimmed level `level_now`) into the state, the old evidence keeping weight `kept`.
    fn pool_projection(
        &mut self,
        p: &[T; COEFFICIENTS],
        (v1, v1_test): (T, T),
        innovation: &[T; COEFFICIENTS],
        kept: f32,
        level_now: f32,
    ) {
        let count = (self.degree + 1) * (self.degree + 1);
        let w = self.weight;
        let keep = if w > 0.0 { kept / w } else { 0.0 };
        if kept > 0.0 {
            let innovation_squares = sum_squares(&innovation[..count]);
            self.scatter =
                self.scatter.scale(keep).add(innovation_squares.scale(kept / (kept + 1.0)));
            self.dof = self.dof * keep + count as f32;
        } else {
            self.scatter = T::ZERO;
            self.dof = 0.0;
        }
        // Compensated (Kahan) summation: `sum` stays within an ulp or two of the exact sum
        // however many updates it pools, `sum_error` holds what its rounding lost.
        let terms = self.sum.iter_mut().zip(&mut self.sum_error).zip(p).take(count);
        for ((s, e), &pi) in terms {
            let old = s.scale(keep);
            let y = pi.add(e.scale(-keep));
            let t = old.add(y);
            *e = t.add(old.scale(-1.0)).add(y.scale(-1.0));
            *s = t;
        }
        self.drift.pool(keep, level_now);
        self.noise_prior = self.noise_prior.scale(keep).add(v1);
        self.noise_prior_test = self.noise_prior_test.scale(keep).add(v1_test);
        self.weight = kept + 1.0;
    }

    /// After an update: the slots start again from the readings at a change (`changed`), the
    /// octants' peaks learn the samples, and the free slots choose what they re-read next.
    fn move_sentinels(
        &mut self,
        samples: &[T; N],
        sentinels: &[T; S],
        changed: bool,
        first: bool,
        novelty: Option<(usize, f32)>,
    ) {
        if changed {
            // Every reading is of the new light: the slots start again from it.
            for (slot, &y) in self.slots.iter_mut().zip(sentinels) {
                if slot.kind != reread::Kind::Empty && slot.kind != reread::Kind::Verified {
                    *slot = reread::Slot {
                        kind: reread::Kind::New,
                        reference: y,
                        other: y,
                        evidence: 0.0,
                        age: 0,
                    };
                }
            }
        }
        self.update_peaks(samples, changed || first);
        self.choose_rereads(samples, novelty);
    }

    /// The log Bayes factor (positive part, summed over the channels) of a change from the
    /// reading `before` to `y` of one direction: "changed" (`y` unrelated to `before`:
    /// variance twice its square plus the samples' second moment) against "unchanged" (the
    /// difference no larger than `before` times the relative error `relative` of the state's
    /// level: a change too small to matter to the estimate is not one).
    fn reread_evidence(&self, y: T, before: T, second_moment: T, relative: T) -> f32 {
        let r = y.add(before.scale(-1.0));
        let mut bf = 0.0f32;
        for ch in 0..T::CHANNELS {
            let m = before.channel(ch);
            // Rounding is not a change.
            let tiny = 1e-5 * m.abs();
            // The state's relative error, but a change of 10 % always matters, and one of 5 %
            // never does (a slow drift between two readings of a direction).
            let tolerance =
                relative.channel(ch).clamp(TOLERANCE.0 * TOLERANCE.0, TOLERANCE.1 * TOLERANCE.1);
            // What two readings of one direction differ by where nothing changed (a path
            // tracer's rays are noisy): the learned percentile, as a variance.
            let yc = y.channel(ch);
            let repeat = self.repeat_noise * 0.5 * (m * m + yc * yc);
            let s0 = tolerance * m * m + repeat + tiny * tiny;
            let psi = 2.0 * (second_moment.channel(ch) + m * m);
            bf += gaussian_log_bf(r.channel(ch) * r.channel(ch), 1.0, s0, psi).max(0.0);
        }
        bf
    }

    /// The log Bayes factor of a change from the re-read slots' readings (module `reread`),
    /// moving each slot to its next state.
    fn weigh_rereads(&mut self, readings: &[T; S], second_moment: T) -> f32 {
        use reread::{Kind, Slot};
        self.learn_repeat_noise(readings);
        let relative_level = self.relative_level_variance();
        let evidence =
            |y: T, before: T| self.reread_evidence(y, before, second_moment, relative_level);
        let prior = self.prior_log_odds;
        let agrees = |y: T, before: T| prior + evidence(y, before) < 0.0;
        let (cap_alarm, cap_confirmed) = self.reread_caps();
        let (mut compared, mut disagreements) = (0u32, 0u32);
        let (mut confirmed, mut fresh) = (0.0f32, 0.0f32);
        // A novel reading's re-reads: all must repeat it.
        let (mut novel, mut refuted) = (0.0f32, false);
        // The octants of the alarms, as a bit set.
        let mut alarms = 0u32;
        let mut next = self.slots;
        let slots = self.slots.iter().zip(&self.sentinel_directions);
        for ((slot, &d), (next, &y)) in slots.zip(next.iter_mut().zip(readings)) {
            let mut alarm = |b: f32| {
                alarms |= 1 << reread::octant(d);
                fresh += b.min(reread::CONTAMINATION).min(cap_alarm);
            };
            if slot.kind == Kind::Empty {
                *next = Slot::EMPTY;
                continue;
            }
            // The evidence of a change from the reference reading; whether this reading is
            // back at it, and whether it agrees with the changed one.
            let b = evidence(y, slot.reference);
            let back = prior + b < 0.0;
            let with_other =
                matches!(slot.kind, Kind::Disputed | Kind::Suspect) && agrees(y, slot.other);
            // Whether this re-read adds a disagreement (or an agreement) to their share: an
            // alarm's waits for the next reading, and a change that it confirms is not one.
            let counted = match slot.kind {
                Kind::New | Kind::Verified => back.then_some(false),
                _ => (back || !with_other).then_some(true),
            };
            if let Some(disagree) = counted {
                compared += 1;
                disagreements += u32::from(disagree);
            }
            let age = slot.age.saturating_add(1);
            let to = |kind: Kind, reference: T, other: T, evidence: f32| Slot {
                kind,
                reference,
                other,
                evidence,
                age,
            };
            *next = match slot.kind {
                Kind::Empty => Slot::EMPTY,
                Kind::New if back => {
                    novel = novel.max(slot.evidence);
                    to(Kind::Verified, slot.reference, y, 0.0)
                }
                Kind::New => {
                    refuted |= slot.evidence > 0.0;
                    // A change, or an outlier in one of the two readings: an alarm that counts
                    // only beside alarms in two other octants.
                    // (A novel reading that does not repeat was an outlier: no alarm.)
                    if slot.evidence == 0.0 {
                        alarm(b);
                    }
                    to(Kind::Disputed, slot.reference, y, 0.0)
                }
                // Two readings of three agree: the odd one was an outlier (or the light
                // changed once, unseen: no evidence either way).
                Kind::Disputed if back => to(Kind::Verified, slot.reference, y, 0.0),
                Kind::Disputed => to(Kind::Verified, y, y, 0.0),
                Kind::Verified if back => to(Kind::Verified, slot.reference, y, 0.0),
                Kind::Verified => {
                    alarm(b);
                    // Capped by the share of disagreeing re-reads before this one.
                    to(Kind::Suspect, slot.reference, y, b.min(cap_confirmed))
                }
                // Back at the verified reading (even if near the changed one too): refuted.
                Kind::Suspect if back => to(Kind::Verified, slot.reference, y, 0.0),
                Kind::Suspect if with_other => {
                    confirmed += slot.evidence;
                    to(Kind::Verified, y, y, 0.0)
                }
                Kind::Suspect => to(Kind::New, y, y, 0.0),
            };
        }
        self.slots = next;
        self.remember_spot();
        self.learn_disagreements(compared, disagreements);
        self.novel_confirmed = !refuted && novel > 0.0;
        if !refuted {
            confirmed += novel;
        }
        // One alarm alone may be an outlier, and alarms in one or two octants a flicker: they
        // wait for their confirmation.
        if alarms.count_ones() >= 3 {
            confirmed + fresh
        } else {
            confirmed
        }
    }

    /// Keeps the brightest verified reading as the spot (refreshed where a slot verifies the
    /// spot's own direction).
    fn remember_spot(&mut self) {
        use reread::{brightness, Kind};
        for (slot, &d) in self.slots.iter().zip(&self.sentinel_directions) {
            if slot.kind != Kind::Verified {
                continue;
            }
            // The latest reading, not the one chosen for being the brightest: re-read later,
            // a reading chosen as a maximum of noisy ones would read darker.
            if d == self.spot.0 || brightness(slot.other) > brightness(self.spot.1) {
                self.spot = (d, slot.other);
            }
        }
    }

    /// The state's level: its mean brightness ([`reread::brightness`]) per direction (`sum[0]/w`
    /// is `√(4π)` times the mean radiance).
    fn mean_level(&self) -> f32 {
        reread::brightness(self.sum[0]) / (self.weight * SQRT_4PI)
    }

    /// The level test's evidence of a change for an update of trimmed level `update` (module
    /// `level`), 0 before the spread is learned; learns the spread.
    fn weigh_level(&mut self, update: f32) -> f32 {
        let state = self.mean_level();
        // Against a state of `w` updates the distance strays `√(1 + 1/w)` times as far as
        // against a noiseless one: the spread is learned, and tested, without that factor.
        let (x, dark) = level::distance(update, state);
        let x = x / math::sqrt(1.0 + 1.0 / self.weight);
        let (evidence, spread) = level::weigh((x, dark), self.level_spread);
        self.level_spread = spread;
        if self.updates >= level::HISTORY {
            evidence
        } else {
            0.0
        }
    }

    /// The relative variance of the state's level (its mean radiance), per channel.
    fn relative_level_variance(&self) -> T {
        let (v, w) = (self.noise(), self.weight);
        let relative = v.map(|x| x / w);
        let mut relative_level = T::ZERO;
        for ch in 0..T::CHANNELS {
            let level = self.sum[0].channel(ch) / w;
            let x = if level != 0.0 { relative.channel(ch) / (level * level) } else { 0.0 };
            relative_level = set_channel(relative_level, ch, x);
        }
        relative_level
    }

    /// What one alarm, and an alarm and its confirmation, are worth at most: as rare as one
    /// and two disagreeing re-reads of one of the `S` slots where nothing changed,
    /// `−ln(S·r)` and `−ln(S·r²)` for the share `r` of disagreeing re-reads.
    fn reread_caps(&self) -> (f32, f32) {
        let rate = self.disagree_rate.max(reread::DISAGREE_FLOOR);
        (-math::ln(rate * S as f32), -math::ln(rate * rate * S as f32))
    }

    /// Adds `compared` re-reads, `disagreements` of them disagreeing, to the running share of
    /// disagreeing ones (the disagreements first).
    fn learn_disagreements(&mut self, compared: u32, disagreements: u32) {
        for k in 0..compared {
            let x = if k < disagreements { 1.0 } else { 0.0 };
            self.disagree_rate += (x - self.disagree_rate) * reread::DISAGREE_GAIN;
        }
    }

    /// Adds each slot's pair of readings, `q` apart ([`reread::repeat_q`]), to the repeat
    /// noise: a running 90th percentile, up by `REPEAT_UP` where `q` exceeds it and down by
    /// `REPEAT_STEP` else.
    fn learn_repeat_noise(&mut self, readings: &[T; S]) {
        for (slot, &y) in self.slots.iter().zip(readings) {
            if slot.kind != reread::Kind::Empty {
                let q = reread::repeat_q(slot.reference, y);
                let e = self.repeat_noise.max(reread::REPEAT_FLOOR);
                self.repeat_noise =
                    if q > e { e * reread::REPEAT_UP } else { e / reread::REPEAT_STEP };
            }
        }
    }

    /// This update's brightest rotated sample, if it is novel: brighter than
    /// [`reread::novelty`] times the brightest one its octant has seen since the last reset,
    /// and carrying over a tenth of the state's level (a change of 10 % always matters).
    /// Its index and the evidence its confirmation brings: `ln(k + 1)` for the `k` updates
    /// that saw nothing so bright there, plus `ln(ratio/NOVELTY)`.
    fn novelty(&self, samples: &[T; N]) -> Option<(usize, f32)> {
        use reread::brightness;
        let w = self.weight;
        let (mut j, mut top, mut total) = (0usize, -1.0f32, 0.0f32);
        for (i, &y) in samples.iter().enumerate() {
            let b = brightness(y);
            total += b;
            if b > top {
                (j, top) = (i, b);
            }
        }
        let peak = self.peaks[reread::octant(self.directions[j]) as usize];
        let mean_level = self.mean_level();
        let excess = (top - total / N as f32) / (N as f32 * mean_level);
        let ratio = top / peak;
        (w >= reread::NOVEL_HISTORY
            && ratio > reread::novelty(N)
            && excess > TOLERANCE.1
            && peak > 0.0)
            .then(|| (j, reread::NOVEL_EVIDENCE + math::ln(ratio / reread::novelty(N))))
    }

    /// Raises each octant's peak to this update's brightest rotated sample there (restarts
    /// them at a reset).
    fn update_peaks(&mut self, samples: &[T; N], restart: bool) {
        if restart {
            self.peaks = [0.0; 8];
            self.spot.1 = T::ZERO;
        }
        for (d, &y) in self.directions.iter().zip(samples) {
            let p = &mut self.peaks[reread::octant(*d) as usize];
            *p = p.max(reread::brightness(y));
        }
    }

    /// After an update: the directions the free slots re-read next (an empty slot, or one
    /// that has tracked its direction for [`reread::TRACK`] updates or more, the slots in
    /// turn), the brightest of this update's rotated samples.
    fn choose_rereads(&mut self, samples: &[T; N], novelty: Option<(usize, f32)>) {
        use reread::{brightness, Kind, Slot};
        // A novel reading whose confirmation would be a change: two slots re-read it, so that
        // a firefly must repeat twice to pass for a change. Free slots first, else the ones
        // that have verified their direction longest (the others keep watching).
        let track = usize::from(reread::TRACK);
        let free = |slots: &[reread::Slot<T>; S], slot: usize| {
            let s = &slots[slot];
            // The slots move in turn, so that some are verified at every update.
            let turn = ((slot * track / S) % track) as u16;
            s.kind == Kind::Empty || (s.kind == Kind::Verified && s.age >= reread::TRACK + turn)
        };
        let novelty = novelty.filter(|&(_, b)| S >= 2 && self.prior_log_odds + b >= 0.0);
        if let Some((j, evidence)) = novelty {
            for _ in 0..reread::NOVEL_REREADS {
                let slot = (0..S).find(|&i| free(&self.slots, i)).or_else(|| {
                    (0..S)
                        .filter(|&i| self.slots[i].kind == Kind::Verified)
                        .max_by_key(|&i| self.slots[i].age)
                });
                // Fewer than two slots to spare: the novel reading is re-read as any other.
                let Some(i) = slot else { break };
                self.sentinel_directions[i] = self.directions[j];
                let y = samples[j];
                self.slots[i] = Slot { kind: Kind::New, reference: y, other: y, evidence, age: 0 };
            }
            let novel = self.slots.iter().filter(|s| s.evidence > 0.0 && s.kind == Kind::New);
            if novel.count() < reread::NOVEL_REREADS {
                for s in &mut self.slots {
                    if s.kind == Kind::New {
                        s.evidence = 0.0;
                    }
                }
            }
        }
        let mut key = samples.map(brightness);
        if let Some((j, _)) = novelty {
            key[j] = -1.0;
        }
        for slot in 0..S {
            if !free(&self.slots, slot) {
                continue;
            }
            let mut best: Option<usize> = None;
            for (j, &k) in key.iter().enumerate() {
                if k >= 0.0 && best.is_none_or(|b| k > key[b]) {
                    best = Some(j);
                }
            }
            let spot = brightness(self.spot.1);
            if spot > 0.0 && best.is_none_or(|b| spot > key[b]) {
                let watched = (0..S).position(|i| self.sentinel_directions[i] == self.spot.0);
                match watched {
                    // The slot watching the spot stays on it.
                    Some(i) if i == slot => {
                        self.slots[slot].age = 0;
                        continue;
                    }
                    Some(_) => {}
                    None => {
                        self.sentinel_directions[slot] = self.spot.0;
                        let y = self.spot.1;
                        self.slots[slot] =
                            Slot { kind: Kind::New, reference: y, other: y, evidence: 0.0, age: 0 };
                        continue;
                    }
                }
            }
            let Some(j) = best else { continue };
            key[j] = -1.0;
            self.sentinel_directions[slot] = self.directions[j];
            let y = samples[j];
            self.slots[slot] =
                Slot { kind: Kind::New, reference: y, other: y, evidence: 0.0, age: 0 };
        }
    }

    /// The projection of this update's samples and its per-update noise estimates `v₁`, the
    /// smallest mean square of the top three degrees, and `v̄₁`, their mean.
    fn project_with_noise(&self, samples: &[T; N]) -> ([T; COEFFICIENTS], T, T) {
        let degree = self.degree;
        let p = self.project(samples);
        let (mut v1, mut v1_test) = (T::ZERO, T::ZERO);
        let top = (degree - 2).max(1)..=degree;
        let bands = top.clone().count() as f32;
        for ch in 0..T::CHANNELS {
            let (mut least, mut mean) = (f32::INFINITY, 0.0f32);
            for l in top.clone() {
                let band = sum_squares(&p[l * l..(l + 1) * (l + 1)]).channel(ch);
                least = least.min(band / (2 * l + 1) as f32);
                mean += band / ((2 * l + 1) as f32 * bands);
            }
            v1 = set_channel(v1, ch, least);
            v1_test = set_channel(v1_test, ch, mean);
        }
        (p, v1, v1_test)
    }

    /// Rescales the state to units of `2^e` (exact, except for what falls below the normal
    /// range: the negligible part of the old evidence).
    fn rescale(&mut self, e: i32) {
        let (k1, k2) = (self.scale - e, 2 * (self.scale - e));
        let one = |t: T| t.map(|x| scale::ldexp_saturating(x, k1));
        let two = |t: T| t.map(|x| scale::ldexp_saturating(x, k2));
        for s in self.sum.iter_mut().chain(&mut self.sum_error) {
            *s = one(*s);
        }
        self.scatter = two(self.scatter);
        self.noise_prior = two(self.noise_prior);
        self.noise_prior_test = two(self.noise_prior_test);
        for slot in &mut self.slots {
            (slot.reference, slot.other) = (one(slot.reference), one(slot.other));
        }
        for p in &mut self.peaks {
            *p = scale::ldexp_saturating(*p, k1);
        }
        self.spot.1 = one(self.spot.1);
        self.drift.rescale(k1);
        for r in &mut self.regions {
            r.rescale(&one);
        }
        self.irradiance_variance = two(self.irradiance_variance);
        self.scale = e;
    }

    /// Drops the pooled evidence and moves to units of `2^e`; what outlives a reset (the
    /// sentinels' learned noise and their readings before a suspect change) is rescaled,
    /// saturating where the new units would overflow it.
    fn restart_at(&mut self, e: i32) {
        self.sum = [T::ZERO; COEFFICIENTS];
        self.sum_error = [T::ZERO; COEFFICIENTS];
        (self.scatter, self.noise_prior, self.noise_prior_test) = (T::ZERO, T::ZERO, T::ZERO);
        self.rescale(e);
    }

    /// The projection of this update's samples: `p₀₀ = √(4π)·Ȳ`,
    /// `p_lm = (4π/N)·Σ (Yⱼ − Ȳ)·Y_lm(xⱼ)`.
    fn project(&self, samples: &[T; N]) -> [T; COEFFICIENTS] {
        let degree = self.degree;
        let count = (degree + 1) * (degree + 1);
        let mut p = [T::ZERO; COEFFICIENTS];
        let mean = samples.iter().fold(T::ZERO, |a, &y| a.add(y)).scale(1.0 / N as f32);
        // By chunks of samples, sample-innermost: each coefficient's sum over a chunk stays in
        // a register, and the sample's weight rides on its azimuth term, `(Yⱼ − Ȳ)·(x + iy)ᵐ`.
        const CHUNK: usize = 16;
        for (directions, ys) in self.directions.chunks(CHUNK).zip(samples.chunks(CHUNK)) {
            let n = directions.len();
            let (mut z, mut x, mut y) = ([0.0f32; CHUNK], [0.0f32; CHUNK], [0.0f32; CHUNK]);
            // wc + i·ws = (Yⱼ − Ȳ)·(x + iy)ᵐ, per channel.
            let (mut wc, mut ws) = ([T::ZERO; CHUNK], [T::ZERO; CHUNK]);
            for (j, (d, &v)) in directions.iter().zip(ys).enumerate().take(CHUNK) {
                (z[j], x[j], y[j]) = (d.z, d.x, d.y);
                wc[j] = v.add(mean.scale(-1.0));
            }
            for (m, sectoral) in Tables.sectorals(degree).enumerate() {
                if m > 0 {
                    let terms = wc.iter_mut().zip(&mut ws).zip(x.iter().zip(&y)).take(n);
                    for ((c, s), (&xj, &yj)) in terms {
                        (*c, *s) = (c.scale(xj).add(s.scale(-yj)), s.scale(xj).add(c.scale(yj)));
                    }
                }
                // Degree l = m: Q_m^m is the constant `sectoral`.
                let sum = |w: &[T; CHUNK]| w.iter().take(n).fold(T::ZERO, |a, &t| a.add(t));
                let mut i = m * (m + 1);
                if m > 0 {
                    add_at(&mut p, i + m, sum(&wc).scale(sectoral));
                    add_at(&mut p, i - m, sum(&ws).scale(sectoral));
                }
                let (mut q1, mut q2) = ([sectoral; CHUNK], [0.0f32; CHUNK]);
                for (l, &pair) in (m + 1..).zip(Tables::slice(m, degree)) {
                    i += 2 * l;
                    let (mut c, mut s) = (T::ZERO, T::ZERO);
                    let per_sample = q1.iter_mut().zip(&mut q2).zip(&z).zip(wc.iter().zip(&ws));
                    for (((q1j, q2j), &zj), (&cj, &sj)) in per_sample.take(n) {
                        let q = harmonics::step(pair, zj, *q1j, *q2j);
                        (*q2j, *q1j) = (*q1j, q);
                        c = c.mul_add(cj, q);
                        if m > 0 {
                            s = s.mul_add(sj, q);
                        }
                    }
                    add_at(&mut p, i + m, c);
                    if m > 0 {
                        add_at(&mut p, i - m, s);
                    }
                }
            }
        }
        let weight = 4.0 * PI / N as f32;
        for pi in &mut p[1..count] {
            *pi = pi.scale(weight);
        }
        p[0] = mean.scale(math::sqrt(4.0 * PI));
        p
    }

    /// The aliasing noise variance per coefficient of one update:
    /// `(ν₀·v̄₁ + scatter)/(ν₀ + dof)` with `ν₀ = (L + 1)²`.
    fn noise(&self) -> T {
        self.noise_with(self.noise_prior)
    }

    /// [`Self::noise`] with another sum of per-update estimates.
    fn noise_with(&self, noise_prior: T) -> T {
        let nu0 = ((self.degree + 1) * (self.degree + 1)) as f32;
        let prior = noise_prior.scale(nu0 / self.weight);
        prior.add(self.scatter).scale(1.0 / (nu0 + self.dof))
    }

    /// Recomputes the queries' coefficients from the state.
    fn refresh(&mut self) {
        let w = self.weight;
        let v = self.noise();
        let (mut variance, mut reported) = (T::ZERO, T::ZERO);
        // The largest power per coefficient of the top two degrees, shrunk and deconvolved.
        let mut top_power = T::ZERO;
        self.irradiance_coefficients = [T::ZERO; COEFFICIENTS];
        let gains = IRRADIANCE_GAIN.iter().zip(self.inverse_gain).take(self.degree + 1);
        for (l, (&gain, g)) in gains.enumerate() {
            let range = l * l..(l + 1) * (l + 1);
            let band = sum_squares(&self.sum[range.clone()]).scale(1.0 / (w * w));
            // s_l per channel: 1 for l = 0, the positive-part James–Stein factor above.
            let shrink = if l == 0 {
                T::ZERO.map(|_| 1.0)
            } else {
                let factor = (2 * l - 1) as f32 / w;
                let mut s = T::ZERO;
                for ch in 0..T::CHANNELS {
                    let b = band.channel(ch);
                    let x = if b > 0.0 { (1.0 - factor * v.channel(ch) / b).max(0.0) } else { 0.0 };
                    s = set_channel(s, ch, x);
                }
                s
            };
            let a = gain * g;
            if l + 1 >= self.degree {
                let power = shrink.mul(band).scale(g * g / (2 * l + 1) as f32);
                top_power = max_per_channel(top_power, power);
            }
            let term = shrink.mul(v).scale(a * a / w * (2 * l + 1) as f32 / (4.0 * PI));
            variance = variance.add(term);
            // The error of a shrunk coefficient: s·v/k from the aliasing and (1 − s)²·c² from
            // the shrinkage, c² bounded by the degree's mean square (so that a degree damped
            // to zero keeps an error bar).
            let damped = T::ONE.add(shrink.scale(-1.0));
            let error = shrink
                .mul(v)
                .scale(1.0 / w)
                .add(damped.mul(damped).mul(band).scale(1.0 / (2 * l + 1) as f32));
            reported = reported.add(error.scale(a * a * (2 * l + 1) as f32 / (4.0 * PI)));
            for i in range.clone() {
                let c = self.sum[i].scale(1.0 / w).mul(shrink);
                self.irradiance_coefficients[i] = c.scale(a);
                if l <= 2 {
                    self.sh.coefficients[i] = c.scale(g);
                    self.sh_variance[i] = error.scale(g * g);
                }
            }
        }
        // (The change test's tolerance takes the aliasing term alone.)
        self.irradiance_variance = variance;
        // The degrees above L are not in the state: their irradiance, at the power per
        // coefficient of the top degrees, is an error that no number of updates removes.
        self.query_variance = reported.add(top_power.scale(TRUNCATION[self.degree]));
        if self.scale != 0 {
            let (e, e2) = (self.scale, 2 * self.scale);
            let one = |t: T| t.map(|x| math::ldexp(x, e));
            for c in &mut self.sh.coefficients {
                *c = one(*c);
            }
            // A positive variance below the least positive f32 is rounded up to it, never
            // to 0.
            for v in &mut self.sh_variance {
                *v = v.map(|x| math::ldexp_variance(x, e2));
            }
            self.query_variance = self.query_variance.map(|x| math::ldexp_variance(x, e2));
        }
    }

    /// The accumulated SH L2 radiance: the shrunk, deconvolved coefficients of degrees
    /// `l ≤ 2`.
    #[must_use]
    pub const fn radiance_sh(&self) -> &ShL2<T> {
        &self.sh
    }

    /// The variance of each coefficient of [`TemporalProbe::radiance_sh`]: the aliasing left
    /// after pooling and the shrinkage's error (module docs); 0 only before the first update
    /// or where the degree's projections are exactly zero.
    #[must_use]
    pub const fn radiance_sh_variance(&self) -> &[T; 9] {
        &self.sh_variance
    }

    /// Updates since the first, as a count (the soft resets do not change it).
    #[must_use]
    pub const fn updates(&self) -> u32 {
        self.updates
    }

    /// The weight of the pooled evidence in updates: the number of updates since the last
    /// full reset when nothing was forgotten in between, less after partial resets.
    #[must_use]
    pub const fn pooled_updates(&self) -> f32 {
        self.weight
    }

    /// The log Bayes factors of a change at the last update: from the rotated samples'
    /// innovation (its full value; with sentinels only its evidence against a change counts,
    /// and none where a novel reading was confirmed) and from the sentinels (0 for the first).
    #[must_use]
    pub const fn last_evidence(&self) -> (f32, f32) {
        self.last_evidence
    }

    /// The regions ([`local_region`]) where the last update confirmed that the light changed
    /// in part of the sphere, as bits (bit `o` for region `o`): that update reported
    /// [`Change::Reset`] with probability 1. 0 where no region saw a change (a reset by the
    /// global tests included).
    ///
    /// ```
    /// use sphere_quadrature::temporal::TemporalProbe;
    ///
    /// let mut probe = TemporalProbe::<64>::new(1);
    /// probe.pool(&probe.directions().map(|d| 1.0 + 0.5 * d.z), &[])?;
    /// assert_eq!(probe.last_changed_regions(), 0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub const fn last_changed_regions(&self) -> u8 {
        self.last_regions
    }

    /// The posterior probability of a change at the last update (0 for the first).
    #[must_use]
    pub const fn last_change_probability(&self) -> f32 {
        self.last_change_probability
    }

    /// Irradiance `E(n)` of the accumulated state, with its variance (the same for every
    /// normal).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite normal.
    pub fn irradiance(&self, normal: Vec3) -> Result<Estimate<T>, Error> {
        let n = normal.try_normalize().ok_or(Error::InvalidDirection)?;
        let mut y = [0.0f32; COEFFICIENTS];
        basis(self.degree, n, &mut y);
        let count = (self.degree + 1) * (self.degree + 1);
        let mut value = T::ZERO;
        for (&c, &b) in self.irradiance_coefficients.iter().zip(&y).take(count) {
            value = value.mul_add(c, b);
        }
        // The sum in the state's units, `2^e` applied last: coefficients of opposite signs
        // taken to the samples' units first could overflow to +∞ and −∞.
        if self.scale != 0 {
            value = value.map(|x| math::ldexp(x, self.scale));
        }
        Ok(Estimate { value, variance: self.query_variance, unit_variance: None })
    }

    /// The channel combination `Σ_c w_c·value_c` of an estimate of this probe, with the
    /// largest variance that any correlation of the channels' errors allows,
    /// `(Σ_c |w_c|·σ_c)²`: reached when the errors are perfectly correlated (a grey light),
    /// exact for one channel. The probe shrinks each channel on its own and keeps no
    /// covariance between them. The same call as [`Probe::combine`](crate::Probe::combine).
    ///
    /// # Errors
    /// [`Error::InvalidWeights`] for a NaN or infinite weight.
    ///
    /// ```
    /// use sphere_quadrature::{TemporalProbe, Vec3};
    ///
    /// let mut probe = TemporalProbe::<64, [f32; 3]>::new(11);
    /// for _ in 0..4 {
    ///     let samples = probe.directions().map(|d| [1.0 + 0.5 * d.z, 0.8 + 0.3 * d.x * d.y, 0.6]);
    ///     probe.pool(&samples, &[])?;
    /// }
    /// let e = probe.irradiance(Vec3::Z)?;
    /// let y = probe.combine(&e, [0.2126, 0.7152, 0.0722])?;
    /// let sum = 0.2126 * e.value[0] + 0.7152 * e.value[1] + 0.0722 * e.value[2];
    /// assert!((y.value - sum).abs() < 1e-5 * sum);
    /// assert!(y.variance >= 0.7152f32.powi(2) * e.variance[1]);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn combine(&self, estimate: &Estimate<T>, weights: T) -> Result<Estimate<f32>, Error> {
        crate::estimate::combine_bound(estimate, weights)
    }
}

/// `values` in units of `2^e`.
fn in_units<T: Radiance, const K: usize>(values: &[T; K], e: i32) -> [T; K] {
    values.map(|y| y.map(|x| math::ldexp(x, -e)))
}

/// `T` with channel `ch` replaced by `x`.
fn set_channel<T: Radiance>(t: T, ch: usize, x: f32) -> T {
    let k = Cell::new(0);
    t.map(|v| {
        let out = if k.get() == ch { x } else { v };
        k.set(k.get() + 1);
        out
    })
}

/// The per-channel maximum.
fn max_per_channel<T: Radiance>(a: T, b: T) -> T {
    let mut out = a;
    for ch in 0..T::CHANNELS {
        out = set_channel(out, ch, a.channel(ch).max(b.channel(ch)));
    }
    out
}

mod level;
mod region;
mod reread;
mod scale;
pub(crate) use crate::change::{gaussian_log_bf, log_odds, logistic, soft_reset};
pub use crate::change::{Change, DEFAULT_HAZARD};

#[cfg(test)]
mod tests;
