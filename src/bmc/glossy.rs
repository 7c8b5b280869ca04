//! The glossy renderer form: Bayesian Monte Carlo of the Phong lobe with the cosine factor,
//! with weights baked per `(N, e)` on a grid of the angle between the normal and the mirror
//! direction (generator `gen/glossy.rs`, sets in `tables/glossy.txt`).
//!
//! The integral is `I(n, r) = ∫ L(x)·(e+1)/(2π)·max(0, r·x)ᵉ·max(0, n·x) dx`: the normalised
//! Phong lobe about the mirror direction `r`, with the cosine factor and the horizon at the
//! normal `n`. [`GlossyRenderer::fill_directions`] places the `N`-point hemisphere spherical
//! Fibonacci set morphed onto the lobe (the QMC-SF samples, at phase 0) in the frame whose first
//! axis points from `r` towards `n`; in that frame the kernel matrix is fixed and the weights
//! depend on the query only through `θₙ = acos(r·n)`, so they are baked on [`GRID`] nodes of
//! `θₙ ∈ [0, π/2]` graded towards grazing (388·N bytes per `(N, e)`, and 1.5 KB of
//! per-interval constants shared by all sets).
//! [`GlossyRenderer::estimate`] (O(N), no transcendental function) finds the interval from
//! `r·n` and interpolates between its two weight rows with `sin(θₖ₊₁ − θₙ)` and
//! `sin(θₙ − θₖ)`: exact while the horizon misses the lobe (there the weights are
//! `A·cos θₙ + B·sin θₙ`), second order near grazing (error: `tests/bmc/glossy.rs`).
//! `zᵢ` comes from the seed's spherical-Gaussian route (a 5-SG fit of the lobe, SG products,
//! the clamped-cosine integral's f64 generator), so constants are integrated exactly for the
//! fitted lobe (fit error: `tests/bmc/glossy.rs`).
//!
//! # Model and hyperparameters
//! Squared-exponential kernel `exp(−|x − x′|²/l²)` plus a nugget σ′², constant prior mean by
//! generalised least squares. The nugget is read as a rough part of the radiance (white at the
//! sample spacing, the aliasing of point samples of a real map) whose integral the set's own
//! QMC rule estimates, `Σ max(0, n·xᵢ)/N·εᵢ`: `z` becomes `z + σ′²q`. So the weights tend to
//! QMC-SF's as σ′ grows and to plain BMC's as σ′ → 0 (`gen/glossy.rs`). `(l, σ′)` per
//! `(N, e)` are learned on real maps (`cargo writer renderer_hyperparameters`, the `err` rows of
//! `tables/renderer_hyperparameters.txt`: the smallest geometric-mean RMSE ratio to QMC-SF over
//! the clamp and smooth tiers of four training maps), interpolated in `ln e` for exponents
//! that were not learned ([`GlossyRenderer::hyperparameters`]). Accuracy on held-out maps:
//! `docs/renderer.md`.
//!
//! ```
//! use sphere_quadrature::{bmc::GlossyRenderer, Vec3};
//!
//! let r = GlossyRenderer::<64, 50>::new();
//! let (n, mirror) = (Vec3::Z, Vec3::new(0.6, 0.0, 0.8));
//! let mut dirs = [Vec3::Z; 64];
//! r.fill_directions(n, mirror, &mut dirs)?;
//! // A constant radiance c gives c·∫p (the lobe's cosine-weighted integral).
//! let e = r.estimate(n, mirror, &[2.0f32; 64])?;
//! assert!(e > 1.4 && e < 1.8);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Optimal sets
//! `GlossyRenderer<N, E, Optimal>` samples the optimal set of `(N, e)` instead (the
//! directions minimising the model's posterior variance; `xtask/writers/src/bin/optimal_sets.rs`,
//! `docs/optimal_sets.md`), with plain BMC weights for the `(l, σ′)` it was optimised for.
//! It is many times better than the Fibonacci set on smooth light and no better on
//! point-sampled real maps (`docs/renderer.md`, estimator `bmc-opt`).
//!
//! ```
//! use sphere_quadrature::bmc::{glossy::Optimal, GlossyRenderer};
//! use sphere_quadrature::Vec3;
//!
//! let r = GlossyRenderer::<64, 50, Optimal>::new();
//! let (n, mirror) = (Vec3::Z, Vec3::new(0.6, 0.0, 0.8));
//! let mut dirs = [Vec3::Z; 64];
//! r.fill_directions(n, mirror, &mut dirs)?;
//! let e = r.estimate(n, mirror, &[2.0f32; 64])?;
//! assert!(e > 1.4 && e < 1.8);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Bad input
//! A zero or non-finite normal or mirror direction gives [`Error::InvalidDirection`]; a NaN or
//! infinite sample gives [`Error::InvalidRadiance`]. A mirror direction below the horizon
//! (`r·n < 0`) is treated as grazing (`θₙ = π/2`): as its projection onto the tangent plane
//! (any tangent for `r = −n`). Samples of any finite size are good input: the estimate of
//! `c·Y` is `c` times that of `Y` to f32 rounding, `±∞` only where it exceeds `f32::MAX`.
//!
//! # Cost
//! Instructions per call and flash on a Cortex-M4F: [`costs`](crate::costs#bmc-renderers).

use super::{scaled, Size};
use crate::error::Error;
use crate::math;
use crate::radiance::Radiance;
use crate::sf::FibonacciPoints;
use crate::vec3::Vec3;
use crate::warp::{Frame, Lobe};

/// Nodes of `θₙ = acos(r·n)` over `[0, π/2]`, at `cos θₙ = (1 − g)/(1 + 2.5g)`,
/// `g = k/(GRID − 1)`: node 0 at normal incidence, node `GRID − 1` at grazing, 12.25 times
/// denser in `r·n` there (`gen/glossy.rs` emits tables of `GRID·N` weights).
pub const GRID: usize = 97;

glossy_size_diagnostic! {
    /// Implemented for exactly the sizes `N` whose glossy weights are baked for exponent `E` and
    /// sample set `S`; sealed.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::bmc::{glossy::BAKED_SETS, GlossyRenderer, GlossySize, Size};
    ///
    /// // Generic over the sample count for one baked exponent (e = 50).
    /// fn kernel_length<const N: usize>() -> f32
    /// where
    ///     Size<N>: GlossySize<50>,
    /// {
    ///     GlossyRenderer::<N, 50>::hyperparameters().0
    /// }
    /// assert!(kernel_length::<64>() > 0.0);
    /// assert!(BAKED_SETS.contains(&(64, 50)));
    /// ```
    pub trait GlossySize<const E: u32, S: SampleSet = Fibonacci>: sealed::Sealed<E, S> {}
}

/// The sample set of a [`GlossyRenderer`]; sealed: [`Fibonacci`] or [`Optimal`].
///
/// # Examples
/// ```
/// use sphere_quadrature::bmc::glossy::{Fibonacci, Optimal, SampleSet};
/// use sphere_quadrature::bmc::{GlossyRenderer, GlossySize, Size};
/// use sphere_quadrature::Vec3;
///
/// // The same code for either set. At normal incidence the weights sum to about the lobe's
/// // cosine-weighted integral, ∫ (e + 1)/(2π)·cosᵉθ·cos θ dω = (e + 1)/(e + 2).
/// fn weight_sum<S: SampleSet>() -> f32
/// where
///     Size<64>: GlossySize<50, S>,
/// {
///     let mut w = [0.0f32; 64];
///     GlossyRenderer::<64, 50, S>::new().weights(Vec3::Z, Vec3::Z, &mut w).unwrap();
///     w.iter().sum()
/// }
/// let (fib, opt) = (weight_sum::<Fibonacci>(), weight_sum::<Optimal>());
/// let exact = 51.0 / 52.0;
/// assert!((fib - exact).abs() < 0.02 && (opt - exact).abs() < 0.02, "{fib} {opt}");
/// ```
pub trait SampleSet: sealed::Kind {}

/// The lobe-morphed hemisphere spherical Fibonacci set (the QMC-SF samples), the default; the
/// weights read the nugget as a rough part that the set's QMC rule integrates.
///
/// # Examples
/// ```
/// use sphere_quadrature::bmc::{glossy::Fibonacci, GlossyRenderer};
/// use sphere_quadrature::Vec3;
///
/// // `GlossyRenderer<N, E>` is `GlossyRenderer<N, E, Fibonacci>`.
/// let r: GlossyRenderer<64, 50, Fibonacci> = GlossyRenderer::<64, 50>::new();
/// let mut dirs = [Vec3::ZERO; 64];
/// let mirror = Vec3::new(0.6, 0.0, 0.8);
/// r.fill_directions(Vec3::Z, mirror, &mut dirs)?;
/// // The Phong e = 50 lobe is narrow: every direction is near the mirror direction.
/// assert!(dirs.iter().all(|d| d.dot(mirror) > 0.5));
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Fibonacci;

/// The optimal set of `tables/optimal_sets.txt` for `(N, e)`: the `N` directions that minimise
/// the model's posterior variance (`xtask/writers/src/bin/optimal_sets.rs`), with plain BMC
/// weights for the `(l, σ′)` it was optimised for. Baked for the pairs of the `optimal = N e`
/// lines of `tables/glossy.txt` ([`BAKED_OPTIMAL_SETS`]); `12·N` more bytes of directions.
///
/// # Examples
/// ```
/// use sphere_quadrature::bmc::{glossy::Optimal, GlossyRenderer};
/// use sphere_quadrature::Vec3;
///
/// let r = GlossyRenderer::<64, 50, Optimal>::new();
/// let (n, mirror) = (Vec3::Z, Vec3::new(0.0, 0.6, 0.8));
/// let mut dirs = [Vec3::ZERO; 64];
/// r.fill_directions(n, mirror, &mut dirs)?;
/// assert!(dirs.iter().all(|d| (d.length() - 1.0).abs() < 1e-5));
/// // Linear in the samples: twice the radiance, twice the estimate.
/// let one = r.estimate(n, mirror, &[1.0f32; 64])?;
/// let two = r.estimate(n, mirror, &[2.0f32; 64])?;
/// assert!((two - 2.0 * one).abs() < 1e-5);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Optimal;

impl SampleSet for Fibonacci {}
impl SampleSet for Optimal {}

pub(crate) mod sealed {
    /// What `build.rs` baked for one `(N, e)`.
    #[derive(Clone, Copy, Debug)]
    pub struct Set {
        /// `GRID·N` weights (f32 bits), node-major.
        pub weights: &'static [u32],
        /// `3·N` lobe-frame coordinates `(t₁, t₂, r)` (f32 bits) of an optimal set; empty for
        /// the Fibonacci set.
        pub directions: &'static [u32],
        pub length_scale: f32,
        pub noise: f32,
    }

    pub trait Sealed<const E: u32, S> {
        const SET: Set;
    }

    pub trait Kind {
        const OPTIMAL: bool;
    }
    impl Kind for super::Fibonacci {
        const OPTIMAL: bool = false;
    }
    impl Kind for super::Optimal {
        const OPTIMAL: bool = true;
    }
}

/// The baked `(N, e)` pairs of the Fibonacci set.
pub const BAKED_SETS: &[(usize, u32)] = &crate::tables::GLOSSY_SETS;

/// The baked `(N, e)` pairs of the optimal sets.
pub const BAKED_OPTIMAL_SETS: &[(usize, u32)] = &crate::tables::GLOSSY_OPTIMAL_SETS;

/// Flash of all baked glossy weights in bytes (`4·GRID·N` per set; only the sets a program
/// uses are linked).
pub const TABLE_BYTES: usize = {
    let mut sum = 0;
    let mut i = 0;
    while i < BAKED_SETS.len() {
        sum += 4 * GRID * BAKED_SETS[i].0;
        i += 1;
    }
    sum
};

/// Bayesian Monte Carlo of the Phong lobe (exponent `E`) with the cosine factor, from `N`
/// samples of the set `S` ([`Fibonacci`] by default, or [`Optimal`]) with baked weights.
/// Zero-sized.
///
/// # Examples
/// ```
/// use sphere_quadrature::{bmc::GlossyRenderer, Error, Vec3};
///
/// let r = GlossyRenderer::<64, 50>::new();
/// let (n, mirror) = (Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.3, 0.0, 0.95));
/// let mut dirs = [Vec3::ZERO; 64];
/// r.fill_directions(n, mirror, &mut dirs)?;
/// let samples = dirs.map(|d| 1.0 + d.z);
/// let e = r.estimate(n, mirror, &samples)?;
/// // Linear in the radiance: the estimate of 1 + z is that of 1 plus that of z.
/// let one = r.estimate(n, mirror, &[1.0f32; 64])?;
/// let z = r.estimate(n, mirror, &dirs.map(|d| d.z))?;
/// assert!((e - (one + z)).abs() < 1e-5 && one > 0.0);
/// assert_eq!(r.estimate(Vec3::ZERO, mirror, &samples), Err(Error::InvalidDirection));
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GlossyRenderer<const N: usize, const E: u32, S: SampleSet = Fibonacci>(
    core::marker::PhantomData<S>,
)
where
    Size<N>: GlossySize<E, S>;

impl<const N: usize, const E: u32, S: SampleSet> GlossyRenderer<N, E, S>
where
    Size<N>: GlossySize<E, S>,
{
    const SET: sealed::Set = <Size<N> as sealed::Sealed<E, S>>::SET;

    /// The renderer.
    #[must_use]
    pub const fn new() -> Self {
        Self(core::marker::PhantomData)
    }

    /// The kernel's `(l, σ′)`.
    #[must_use]
    pub const fn hyperparameters() -> (f32, f32) {
        (Self::SET.length_scale, Self::SET.noise)
    }

    /// Writes the `N` sample directions for normal `n` and mirror direction `r` (both
    /// normalised first): the set `S` in the frame `(t₁, t₂, r)`, `t₁` towards `n`.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite vector.
    pub fn fill_directions(
        &self,
        normal: Vec3,
        mirror: Vec3,
        out: &mut [Vec3; N],
    ) -> Result<(), Error> {
        let [t1, t2, r] = lobe_frame(normal, mirror)?;
        if <S as sealed::Kind>::OPTIMAL {
            let local = Self::SET.directions.chunks_exact(3);
            if local.len() != N {
                return Err(Error::Internal);
            }
            for (slot, d) in out.iter_mut().zip(local) {
                let [x, y, z] = [d[0], d[1], d[2]].map(f32::from_bits);
                *slot = t1 * x + t2 * y + r * z;
            }
            return Ok(());
        }
        let set = FibonacciPoints::hemisphere(N)?;
        let lobe = Lobe::Phong(E as f32);
        let frame = crate::warp::Frame { t: t1, b: t2, n: r };
        for (j, slot) in out.iter_mut().enumerate() {
            *slot = set.morphed(j, lobe, &frame);
        }
        Ok(())
    }

    /// The two weight rows around `θₙ` and their interpolation coefficients `(α, β)`.
    #[inline(always)]
    fn rows(normal: Vec3, mirror: Vec3) -> Result<(Rows, [f32; 2]), Error> {
        let (k, coefficients) = interval(normal, mirror)?;
        let Some(rows) = Self::SET.weights.get(k * N..(k + 2) * N) else {
            return Err(Error::Internal);
        };
        Ok((rows.split_at(N), coefficients))
    }

    /// The interpolated weights for `(n, r)`, in the order of [`GlossyRenderer::fill_directions`].
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite vector.
    pub fn weights(&self, normal: Vec3, mirror: Vec3, out: &mut [f32; N]) -> Result<(), Error> {
        let ((a, b), [alpha, beta]) = Self::rows(normal, mirror)?;
        for ((o, &a), &b) in out.iter_mut().zip(a).zip(b) {
            *o = alpha * f32::from_bits(a) + beta * f32::from_bits(b);
        }
        Ok(())
    }

    /// `I(n, r) ≈ Σ wⱼ·Yⱼ` from the radiance in each direction of
    /// [`GlossyRenderer::fill_directions`], in order; O(N) (the interpolation is fused into the sum).
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite vector, [`Error::InvalidRadiance`]
    /// for a NaN or infinite sample.
    pub fn estimate<T: Radiance>(
        &self,
        normal: Vec3,
        mirror: Vec3,
        samples: &[T; N],
    ) -> Result<T, Error> {
        let () = crate::radiance::Channels::<T>::VALID;
        let ((rows_a, rows_b), [alpha, beta]) = Self::rows(normal, mirror)?;
        // Σ wⱼYⱼ = α·Σ aⱼYⱼ + β·Σ bⱼYⱼ. The sums start from the first products, and run in
        // blocks of 32 (unrolled: the loop's own instructions are negligible per sample).
        let (Some((&y0, y)), Some((&a0, a)), Some((&b0, b))) =
            (samples.split_first(), rows_a.split_first(), rows_b.split_first())
        else {
            return Ok(T::ZERO);
        };
        let (mut sa, mut sb) = (y0.scale(f32::from_bits(a0)), y0.scale(f32::from_bits(b0)));
        let mut step = |y: &[T], a: &[u32], b: &[u32]| {
            for ((&y, &a), &b) in y.iter().zip(a).zip(b) {
                sa = sa.mul_add(y, f32::from_bits(a));
                sb = sb.mul_add(y, f32::from_bits(b));
            }
        };
        let (y32, a32, b32) = (y.chunks_exact(32), a.chunks_exact(32), b.chunks_exact(32));
        let (yr, ar, br) = (y32.remainder(), a32.remainder(), b32.remainder());
        for ((y, a), b) in y32.zip(a32).zip(b32) {
            step(y, a, b);
        }
        step(yr, ar, br);
        let sum = sa.scale(alpha).add(sb.scale(beta));
        if scaled::in_range(sum) {
            return Ok(sum);
        }
        // Not finite, or too small to trust: the samples checked and summed at their own scale.
        scaled::rescaled_sum(samples, |j| {
            let w = |row: &[u32]| row.get(j).map_or(0.0, |&w| f32::from_bits(w));
            alpha * w(rows_a) + beta * w(rows_b)
        })
    }
}

/// The lobe frame `(t₁, t₂, a)` of a mirror direction `r` at the normal `n` (both normalised
/// first): `a = r` with `t₁` towards `n`. A mirror below the horizon (`r·n < 0`) is grazing:
/// `a` is then `r` projected onto the tangent plane of `n` (any tangent for `r = −n`), where
/// the weights of `θₙ = π/2` apply. The three vectors are orthonormal to f32 rounding for
/// every pair of valid directions, `r = ±n` included.
pub(crate) fn lobe_frame(normal: Vec3, mirror: Vec3) -> Result<[Vec3; 3], Error> {
    let n = normal.try_normalize().ok_or(Error::InvalidDirection)?;
    let r = mirror.try_normalize().ok_or(Error::InvalidDirection)?;
    let a = if r.dot(n) < 0.0 { perpendicular_towards(n, r) } else { r };
    let t1 = perpendicular_towards(a, n);
    Ok([t1, a.cross(t1), a])
}

/// The unit vector perpendicular to the unit `a` in the plane of `a` and `v` (unit), on `v`'s
/// side: Gram–Schmidt, and again where the first pass left `|a·u| > 2⁻²⁰` (it loses
/// orthogonality as `v` nears `±a`). Where `v` is within 10⁻⁶ rad of `±a` the plane is not
/// defined by f32 data, and any perpendicular of `a` serves.
fn perpendicular_towards(a: Vec3, v: Vec3) -> Vec3 {
    let u = v - a * a.dot(v);
    if u.length_squared() >= 1e-12 {
        if let Some(u) = u.try_normalize() {
            let d = a.dot(u);
            if math::abs(d) <= 1.0 / 1_048_576.0 {
                return u;
            }
            if let Some(u) = (u - a * d).try_normalize() {
                return u;
            }
        }
    }
    Frame::from_unit(a).t
}

/// Two weight rows (f32 bits).
type Rows = (&'static [u32], &'static [u32]);

/// The interval `k` (nodes `k`, `k + 1`) holding `θₙ`, the angle between `normal` and
/// `mirror`, and the coefficients `(α, β)` of its two weight rows:
/// `w(θₙ) ≈ α·w_k + β·w_{k+1}` with `α = sin(θ_{k+1} − θₙ)/sin Δ`, `β = sin(θₙ − θ_k)/sin Δ`,
/// exact for weights of the form `A·cos θₙ + B·sin θₙ`. Neither vector is normalised:
/// `c = cos θₙ = n·r/R`, `s = sin θₙ = |n×r|/R` with `R = √(|n|²|r|²)` (two square roots, no
/// other function; `s` from the cross product stays accurate near normal incidence). `r·n ≤ 0`
/// is grazing (`θₙ = π/2`).
#[inline(always)]
pub(crate) fn interval(normal: Vec3, mirror: Vec3) -> Result<(usize, [f32; 2]), Error> {
    let (nn, rr) = (normal.length_squared(), mirror.length_squared());
    // Fast path: |n|² and |r|² in [2⁻¹⁶, 2¹⁶), both tested by one unsigned comparison of their
    // bits (the range is 2²⁸ bit patterns wide; l² ≥ 0 or NaN, whose bits are above ∞'s).
    // There n·r, |n×r|² and |n|²|r|² are finite and, where |n×r|² is subnormal or 0 (where
    // `sqrt` is only good to ~10⁻¹⁹ absolute), sin θₙ < 10⁻¹⁴.
    const LOW: u32 = 0x3780_0000; // 2⁻¹⁶
    const SPAN: u32 = 0x1000_0000; // 32 binades, to 2¹⁶
    let (n, r, p) = if (nn.to_bits().wrapping_sub(LOW) | rr.to_bits().wrapping_sub(LOW)) < SPAN {
        (normal, mirror, nn * rr)
    } else {
        // Scalars: a `Vec3` argument would be passed through a copy on the stack, made on the
        // fast path too.
        let ([nx, ny, nz], [rx, ry, rz]) = (normal.to_array(), mirror.to_array());
        normalised(nx, ny, nz, rx, ry, rz)?
    };
    let d = n.dot(r);
    if d <= 0.0 {
        // Grazing (θₙ = π/2: node GRID − 1, whose cos θ is 0).
        return Ok((GRID - 2, [0.0, 1.0]));
    }
    let root = sqrt(p);
    let (c, s) = (d / root, sqrt(r.cross(n).length_squared()) / root);
    // Node index u = (GRID − 1)·(1 − c)/(1 + a·c) = (K₁/a)/(c + 1/a) − K₂, K₁ = (GRID − 1)(1 + a)/a,
    // K₂ = (GRID − 1)/a; K₁ a hair small so that c → 0 stays below GRID − 1 (the formula
    // holds a little outside its interval: choosing the neighbour costs nothing). `as`
    // saturates (c > 1 by rounding: 0).
    const A: f64 = GRADING;
    const Q: f32 = ((GRID - 1) as f64 * (1.0 + A) / A * (1.0 - 1.0 / 65536.0) / A) as f32;
    const K2: f32 = ((GRID - 1) as f64 / A) as f32;
    let k = (Q / (c + (1.0 / A) as f32) - K2) as usize;
    let Some(&[p0, p1, p2, p3]) = INTERVALS.get(k) else {
        return Err(Error::Internal);
    };
    Ok((k, [p0 * c - p1 * s, p2 * s - p3 * c]))
}

/// The slow path of [`interval`]: both vectors normalised by [`Vec3::try_normalize`] (any finite
/// nonzero vector), and `|n|²|r|²` of the results.
#[cold]
#[inline(never)]
fn normalised(
    nx: f32,
    ny: f32,
    nz: f32,
    rx: f32,
    ry: f32,
    rz: f32,
) -> Result<(Vec3, Vec3, f32), Error> {
    let n = Vec3::new(nx, ny, nz).try_normalize().ok_or(Error::InvalidDirection)?;
    let r = Vec3::new(rx, ry, rz).try_normalize().ok_or(Error::InvalidDirection)?;
    Ok((n, r, n.length_squared() * r.length_squared()))
}

/// `√x` for finite `x ≥ 0`, relative error below 4·10⁻⁷ for normal `x` (a few instructions:
/// no FPU square root is reachable from stable `no_std` Rust, and `libm::sqrtf` is integer
/// code): a first guess from the bits (halving the exponent; the offset minimises the largest
/// relative error, ±3.5 %), then two Heron steps `y ← (x/2)/y + y/2` (3.5 % → 6·10⁻⁴ →
/// 2·10⁻⁷). `√0` gives ~2·10⁻²⁰.
#[inline(always)]
fn sqrt(x: f32) -> f32 {
    let h = 0.5 * x;
    let y = f32::from_bits((x.to_bits() >> 1) + 0x1FBB_4F1C);
    let y = h / y + 0.5 * y;
    h / y + 0.5 * y
}

/// The grading `a` of the nodes: node `k` at `cos θₖ = (1 − g)/(1 + a·g)`, `g = k/(GRID − 1)`
/// (as `gen/glossy.rs`).
const GRADING: f64 = 2.5;

/// `(cos θₖ, sin θₖ)` of node `k`, in f64.
const fn node(k: usize) -> (f64, f64) {
    let g = k as f64 / (GRID - 1) as f64;
    let a = GRADING;
    // 1 − c = g(1 + a)/(1 + a·g), 1 + c = (2 + (a − 1)g)/(1 + a·g).
    let den = 1.0 + a * g;
    let sin2 = g * (1.0 + a) * (2.0 + (a - 1.0) * g) / (den * den);
    (((1.0 - g) / den), const_sqrt(sin2))
}

/// `√x` for `x ∈ [0, 1]` in a `const` context (Newton's method from above, to convergence).
const fn const_sqrt(x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let mut y = 1.0;
    loop {
        let next = 0.5 * (y + x / y);
        if next >= y {
            return y;
        }
        y = next;
    }
}

/// Per interval `k`: `[sin θₖ₊₁, cos θₖ₊₁, cos θₖ, sin θₖ]/sin(θₖ₊₁ − θₖ)`.
static INTERVALS: [[f32; 4]; GRID - 1] = {
    let mut out = [[0.0; 4]; GRID - 1];
    let mut k = 0;
    while k < GRID - 1 {
        let ((c0, s0), (c1, s1)) = (node(k), node(k + 1));
        let d = s1 * c0 - c1 * s0;
        out[k] = [(s1 / d) as f32, (c1 / d) as f32, (c0 / d) as f32, (s0 / d) as f32];
        k += 1;
    }
    out
};
