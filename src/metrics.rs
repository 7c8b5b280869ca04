//! Point-set quality metrics and the frequency view: how well does a set of directions
//! integrate?
//!
//! Seed tutorial, "Frequency Domain View", "Worst Case (Integration) Error", "Stolarsky's
//! Invariance Principle" and "Spherical designs"; Brauchart, Saff, Sloan and Womersley,
//! "QMC designs: optimal order quasi Monte Carlo integration schemes on the sphere" (2014,
//! BSSW) and Brauchart and Womersley, "Numerical integration over the unit sphere, L₂-discrepancy
//! and sum of distances" (2012). Every function takes a slice of directions (`&[Vec3]`, any
//! length; each is normalised in f64 first, so they need not be exactly unit), allocates
//! nothing, and works on the host or on a device.
//!
//! # Measure and normalisation
//! σ is the normalised surface measure (σ(S²) = 1), dΩ = 4π dσ the solid angle. Spherical
//! harmonics `Y_{l,m}` are real and orthonormal over dΩ (as in the seed's `f_{l,m}`), and the
//! coefficients of a point set `{ω₁ … ω_N}` are `c_{l,m} = (1/N) Σₖ Y_{l,m}(ωₖ)`.
//!
//! # The metrics
//! - [`energy`]: the seed's sum-of-distances criterion
//!   `E_N = (4/3 − N⁻² ΣᵣΣₖ |ωᵣ − ωₖ|)^½`. It is the worst-case error in `H^{3/2}(S²)`.
//! - [`cap_discrepancy`]: the spherical cap L₂ discrepancy
//!   `L₂ = [∫₋₁¹ ∫ (#{k : ωₖ·ω ≥ t}/N − σ(cap(ω, t)))² dσ(ω) dt]^½ = E_N / 2` by Stolarsky's
//!   invariance principle `N⁻² ΣΣ |ωᵣ − ωₖ| + 4 L₂² = 4/3`.
//! - [`wce`]: the worst-case error in `H^s(S²)`, `1 < s < 2`, by the distance-kernel formula
//!   `wce² = V_s − N⁻² ΣᵣΣₖ |ωᵣ − ωₖ|^(2s−2)`, `V_s = ∫∫ |x − y|^(2s−2) dσ dσ = 2^(2s−2)/s`
//!   (`s = 3/2` gives `4/3` and `wce = E_N`).
//! - [`wce_spectral`] / [`wce_from_spectrum`]: the same quantity in the frequency domain,
//!   `wce² = Σ_{l≥1} a_l Σₘ |c_{l,m}|² = Σ_{l≥1} a_l (2l+1) C_l` (see [`SobolevWeights`] for
//!   which `a_l` equal the distance formula).
//! - [`min_separation`], [`covering_radius`], [`mesh_ratio`]: the packing and covering
//!   geometry (chordal distances `|x − y|`; the geodesic angle is `2·asin(d/2)`).
//! - [`spectrum`]: `C_l = (1/(2l+1)) Σₘ |c_{l,m}|² = (1/(4πN²)) ΣⱼΣₖ P_l(ωⱼ·ωₖ)` by the
//!   addition theorem `Σₘ Y_{l,m}(x) Y_{l,m}(y) = (2l+1)/(4π) P_l(x·y)`, with the Legendre
//!   recurrence; no spherical harmonics are needed. `C_0 = 1/(4π)`; independent uniform
//!   random points have `E[C_l] = 1/(4πN)` for `l ≥ 1`.
//! - [`real_sh`], [`sh_coefficients`]: the `c_{l,m}` themselves, for small degrees.
//! - [`design_strength`], [`min_points_for_design`]: the spherical-design view.
//! - [`circle_coefficient`], [`uniform_circle_coefficient`], [`uniform_circle_nodes`],
//!   [`circle_strength`]: the circle (S¹) view the seed starts from.
//!
//! # Cost
//! The pair sums ([`energy`], [`wce`], [`min_separation`]) visit the N(N−1)/2 pairs once:
//! O(N²) (N = 4096 is 8.4·10⁶ pairs, about 0.1 s on a desktop core). [`spectrum`] costs
//! O(N²·L), [`sh_coefficients`] O(N·L²), [`covering_radius`] O(N·M) for M probes.
//!
//! # Accuracy
//! Pair sums are accumulated in f64 (each row summed, rows combined with Neumaier
//! compensation), and `V_s − |x − y|^(2s−2)` is formed per pair so the small difference is
//! never the difference of two large totals. The worst-case rounding bound on `E_N²` is then
//! about `N·2⁻⁵⁴` absolute, against `E_N² ≈ 0.81 N^(−3/2)` for SF: below 10⁻⁷ relative for
//! N ≤ 4096 and 10⁻⁴ for N ≤ 65 536 (random rounding makes the actual error far smaller).
//!
//! [`energy_f32`] is an all-f32 path for cores without a double-precision FPU (compensated
//! f32 sums, `4/3` split into two f32 parts, bias-free renormalisation). Measured against
//! the f64 path on spherical Fibonacci sets (`tests/points/metrics.rs`), its relative error in
//! `E_N` is 6·10⁻⁷ at N = 256, 2·10⁻⁵ at 1024, 2·10⁻⁴ at 4096, then 2.5·10⁻³ at 8192 and
//! 5·10⁻³ at 16 384: **it is accurate to 10⁻³ for N ≤ 4096**. The limit is the rounding of
//! `|ωᵣ − ωₖ|²` in f32, biased by about 10⁻⁸ on SF's structured coordinates, against
//! `E_N² ≈ 0.81 N^(−3/2)`.
//!
//! # Errors
//! An empty slice gives [`Error::LengthMismatch`]; a zero, NaN or infinite direction gives
//! [`Error::InvalidDirection`]; `s ∉ (1, 2)`, a NaN or negative tolerance give
//! [`Error::InvalidSmoothness`] and [`Error::InvalidTolerance`]; a negative or non-finite
//! spectrum entry [`Error::InvalidSpectrum`]. Nothing panics.
//!
//! # Example
//! ```
//! use sphere_quadrature::{metrics, SphericalFibonacci};
//!
//! let points = SphericalFibonacci::<64>::new().points();
//! // C₀ = 1/(4π) for every set; C_l is far below random points' 1/(4πN) at low l.
//! let mut c = [0.0f64; 4];
//! metrics::spectrum(&points, &mut c)?;
//! assert!((c[0] - 1.0 / (4.0 * core::f64::consts::PI)).abs() < 1e-12);
//! assert!(c[1] < 1.0 / (4.0 * core::f64::consts::PI * 64.0));
//! // No two points closer than the closest pair.
//! let d = metrics::min_separation(&points)?;
//! assert!(d > 0.0 && d < 2.0);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```

mod circle;
mod harmonics;

pub use circle::{
    circle_coefficient, circle_strength, uniform_circle_coefficient, uniform_circle_nodes,
};
pub use harmonics::{
    design_strength, min_points_for_design, real_sh, sh_coefficients, sh_index, sobolev_weight,
    spectrum, wce_from_spectrum, wce_spectral, SobolevWeights,
};

use crate::error::Error;
use crate::math;
use crate::vec3::Vec3;

/// The direction of `v` as an f64 unit vector, or `None` when `v` is zero or not finite (the
/// crate's valid directions, crate docs "Directions": in f64 the squared length of any
/// finite f32 vector, from subnormal to `f32::MAX` components, neither overflows nor
/// underflows).
#[inline]
fn unit64(v: Vec3) -> Option<[f64; 3]> {
    let (x, y, z) = (v.x as f64, v.y as f64, v.z as f64);
    let l2 = x * x + y * y + z * z;
    if !(l2.is_finite() && l2 > 0.0) {
        return None;
    }
    let r = 1.0 / math::sqrt64(l2);
    Some([x * r, y * r, z * r])
}

/// [`unit64`] for a point already accepted by [`validate`].
#[inline]
fn unit64_unchecked(v: Vec3) -> [f64; 3] {
    unit64(v).unwrap_or([f64::NAN; 3])
}

/// Checks that the set is non-empty and that every direction can be normalised.
fn validate(points: &[Vec3]) -> Result<(), Error> {
    if points.is_empty() {
        return Err(Error::LengthMismatch);
    }
    if points.iter().all(|&p| unit64(p).is_some()) {
        Ok(())
    } else {
        Err(Error::InvalidDirection)
    }
}

/// Squared chordal distance.
#[inline]
fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    dx * dx + dy * dy + dz * dz
}

/// Neumaier's compensated sum.
#[derive(Clone, Copy, Default)]
struct Neumaier {
    sum: f64,
    comp: f64,
}

impl Neumaier {
    #[inline]
    fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if math::abs64(self.sum) >= math::abs64(x) {
            self.comp += (self.sum - t) + x;
        } else {
            self.comp += (x - t) + self.sum;
        }
        self.sum = t;
    }

    #[inline]
    fn value(self) -> f64 {
        self.sum + self.comp
    }
}

/// Calls `f(|ωⱼ − ωₖ|²)` for every pair `j < k` of a validated set.
#[inline]
fn for_each_pair(points: &[Vec3], mut f: impl FnMut(f64)) {
    // `split_first` walks the rows without slicing, so no bounds-check panic path remains.
    let mut rest = points;
    while let Some((&pj, tail)) = rest.split_first() {
        let a = unit64_unchecked(pj);
        for &pk in tail {
            f(dist2(a, unit64_unchecked(pk)));
        }
        rest = tail;
    }
}

/// `N⁻² ΣⱼΣₖ (v − g(|ωⱼ − ωₖ|²))` for a kernel with `g(0) = 0`, each row summed in f64 and
/// the rows combined with compensation.
fn centred_pair_mean(points: &[Vec3], v: f64, g: impl Fn(f64) -> f64) -> f64 {
    let mut total = Neumaier::default();
    let mut rest = points;
    while let Some((&pj, tail)) = rest.split_first() {
        let a = unit64_unchecked(pj);
        let mut row = 0.0;
        for &pk in tail {
            row += v - g(dist2(a, unit64_unchecked(pk)));
        }
        // Row j's pairs count twice (j, k) and (k, j); the diagonal term is v − g(0) = v.
        total.add(v + 2.0 * row);
        rest = tail;
    }
    let n = points.len() as f64;
    total.value() / (n * n)
}

/// `V_s = ∫∫ |x − y|^(2s−2) dσ dσ = 2^(2s−2)/s`, after checking `1 < s < 2`.
fn kernel_mean(s: f64) -> Result<f64, Error> {
    if !(s > 1.0 && s < 2.0) {
        return Err(Error::InvalidSmoothness);
    }
    Ok(math::pow64(2.0, 2.0 * s - 2.0) / s)
}

/// The sum-of-distances energy `E_N = (4/3 − N⁻² ΣᵣΣₖ |ωᵣ − ωₖ|)^½` (seed, "Assess the
/// Quality of the Samples Set"); smaller is better. It equals [`wce`] at `s = 3/2` and twice
/// the [`cap_discrepancy`]. Optimal sets reach the rate `N^(−3/4)`; independent uniform random
/// points have `E[E_N²] = 4/(3N)`.
///
/// O(N²) in f64. `N = 1` gives `(4/3)^½`.
///
/// # Errors
/// [`Error::LengthMismatch`] for an empty slice, [`Error::InvalidDirection`] for a zero or
/// non-finite direction.
///
/// ```
/// use sphere_quadrature::{metrics, Vec3};
/// // Two antipodal points: mean distance (0 + 2 + 2 + 0)/4 = 1.
/// let e = metrics::energy(&[Vec3::Z, -Vec3::Z]).unwrap();
/// assert!((e - (1.0f64 / 3.0).sqrt()).abs() < 1e-15);
/// ```
pub fn energy(points: &[Vec3]) -> Result<f64, Error> {
    validate(points)?;
    let e2 = centred_pair_mean(points, 4.0 / 3.0, math::sqrt64);
    Ok(math::sqrt64(e2.max(0.0)))
}

/// [`energy`] computed entirely in f32, for cores without double-precision hardware.
///
/// Each pair contributes `4/3 − |ωᵣ − ωₖ|` (with `4/3` split into an f32 head and tail, so
/// its rounding does not bias the result), and rows and totals are Kahan-compensated; what
/// remains is the rounding of the individual distances. Measured relative error against
/// [`energy`] on spherical Fibonacci sets: 2·10⁻⁴ at N = 4096 (below 10⁻³ for every
/// N ≤ 4096), 2.5·10⁻³ at N = 8192. Use the f64 path beyond N = 4096.
///
/// # Errors
/// As [`energy`].
pub fn energy_f32(points: &[Vec3]) -> Result<f32, Error> {
    validate(points)?;
    const HEAD: f32 = 4.0 / 3.0;
    const TAIL: f32 = (4.0 / 3.0 - HEAD as f64) as f32;
    let unit = |v: Vec3| {
        // `v·(1/√|v|²)` rounds to lengths biased by +2.5·10⁻⁸ (the f32 grid is twice as fine
        // below 1 as above), which shifts E_N² at large N; instead add a small second-order
        // correction `v·(−δ/2 + 3δ²/8)`, `δ = |v|² − 1`, to a vector that is already nearly
        // unit, so only the correction is rounded.
        // A vector far from unit is normalised robustly first (Vec3::try_normalize scales by
        // the largest component where |v|² would overflow or underflow in f32); `validate`
        // accepted it, so it is finite and nonzero.
        let l2 = v.length_squared();
        let u = if math::abs(l2 - 1.0) > 1e-3 { v.try_normalize().unwrap_or(v) } else { v };
        let d = u.length_squared() - 1.0;
        u - u * (d * (0.5 - 0.375 * d))
    };
    let (mut total, mut total_c) = (0.0f32, 0.0f32);
    let kahan = |sum: &mut f32, c: &mut f32, x: f32| {
        let y = x - *c;
        let t = *sum + y;
        *c = (t - *sum) - y;
        *sum = t;
    };
    let mut rest = points;
    while let Some((&pj, tail)) = rest.split_first() {
        let a = unit(pj);
        let (mut row, mut row_c) = (0.0f32, 0.0f32);
        for &pk in tail {
            let d = (a - unit(pk)).length();
            kahan(&mut row, &mut row_c, HEAD - d);
        }
        kahan(&mut total, &mut total_c, HEAD + 2.0 * (row - row_c));
        rest = tail;
    }
    let nf = points.len() as f32;
    let e2 = (total - total_c) / nf / nf + TAIL;
    Ok(math::sqrt(e2.max(0.0)))
}

/// The spherical cap L₂ discrepancy, `E_N / 2` by Stolarsky's invariance principle (seed,
/// "Stolarsky's Invariance Principle"; the outer integral uses the normalised measure σ).
///
/// # Errors
/// As [`energy`].
pub fn cap_discrepancy(points: &[Vec3]) -> Result<f64, Error> {
    Ok(0.5 * energy(points)?)
}

/// The worst-case integration error in the Sobolev space `H^s(S²)`, `1 < s < 2`, by the
/// distance-kernel formula of Brauchart and Womersley (2012),
/// `wce² = 2^(2s−2)/s − N⁻² ΣᵣΣₖ |ωᵣ − ωₖ|^(2s−2)` (seed, "Worst Case (Integration) Error").
/// The norm of `H^s` this refers to is the one with reproducing kernel
/// `C − |x − y|^(2s−2)` for a constant `C > V_s` (the constant only weights the constant
/// functions, which equal weights integrate exactly, so the wce does not depend on it);
/// [`SobolevWeights::Exact`] gives its spectral form.
///
/// O(N²) in f64.
///
/// # Errors
/// [`Error::InvalidSmoothness`] unless `1 < s < 2`; otherwise as [`energy`].
pub fn wce(points: &[Vec3], s: f64) -> Result<f64, Error> {
    let v = kernel_mean(s)?;
    validate(points)?;
    let p = s - 1.0;
    let e2 = centred_pair_mean(points, v, |d2| math::pow64(d2, p));
    Ok(math::sqrt64(e2.max(0.0)))
}

/// The smallest chordal distance `minⱼ≠ₖ |ωⱼ − ωₖ|` (the seed's `δ_K`); larger is better.
/// The geodesic separation is `2·asin(δ/2)`. O(N²).
///
/// # Errors
/// [`Error::InvalidSize`] for fewer than two points; [`Error::InvalidDirection`] for a zero or
/// non-finite direction.
pub fn min_separation(points: &[Vec3]) -> Result<f64, Error> {
    if points.len() < 2 {
        return Err(Error::InvalidSize);
    }
    validate(points)?;
    let mut best = f64::INFINITY;
    for_each_pair(points, |d2| best = best.min(d2));
    Ok(math::sqrt64(best))
}

/// An estimate of the covering radius `h = max_{x∈S²} minₖ |x − ωₖ|` (chordal): the largest
/// distance from a probe direction to its nearest point. O(N·M) for M probes.
///
/// The true covering radius lies in `[estimate, estimate + h_P]`, where `h_P` is the covering
/// radius of the probe set (triangle inequality), so use dense, even probes: a spherical
/// Fibonacci set of M points has `h_P ≈ 2.7/√M` (measured with 2²⁰ probes: 2.72/√M at
/// M = 256, 2.69/√M at M = 4096; so 1.1·10⁻² for M = 2¹⁶ probes, 2.7·10⁻³ for 2²⁰), and its
/// mesh ratio is about 1.74.
///
/// ```
/// use sphere_quadrature::{metrics, sf::FibonacciPoints, Vec3};
/// // The six octahedron vertices: the deepest holes are the face centres, h = (2 − 2/√3)^½.
/// let octa = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
/// let probes = FibonacciPoints::sphere(1 << 16).unwrap();
/// let h = metrics::covering_radius(&octa, &probes).unwrap();
/// let exact = (2.0 - 2.0 / 3f64.sqrt()).sqrt();
/// assert!(h <= exact + 1e-6 && h > exact - 1.1e-2);
/// ```
///
/// # Errors
/// [`Error::LengthMismatch`] when `points` or `probes` is empty; [`Error::InvalidDirection`]
/// for a zero or non-finite point or probe.
pub fn covering_radius<I>(points: &[Vec3], probes: I) -> Result<f64, Error>
where
    I: IntoIterator<Item = Vec3>,
{
    validate(points)?;
    let mut worst = f64::NEG_INFINITY;
    for probe in probes {
        let q = unit64(probe).ok_or(Error::InvalidDirection)?;
        let nearest =
            points.iter().map(|&p| dist2(q, unit64_unchecked(p))).fold(f64::INFINITY, f64::min);
        worst = worst.max(nearest);
    }
    if worst == f64::NEG_INFINITY {
        return Err(Error::LengthMismatch);
    }
    Ok(math::sqrt64(worst))
}

/// The mesh ratio `ρ = h / q`, covering radius over separation radius `q = δ/2` (BSSW),
/// with `h` estimated from `probes` as in [`covering_radius`]. `ρ ≥ 1` for any set; bounded
/// `ρ` as N grows is a quasi-uniform sequence of sets.
///
/// # Errors
/// As [`min_separation`] and [`covering_radius`].
pub fn mesh_ratio<I>(points: &[Vec3], probes: I) -> Result<f64, Error>
where
    I: IntoIterator<Item = Vec3>,
{
    let delta = min_separation(points)?;
    let h = covering_radius(points, probes)?;
    Ok(2.0 * h / delta)
}
