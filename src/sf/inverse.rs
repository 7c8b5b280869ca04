//! Inverse spherical Fibonacci mapping: the index of the point of a set nearest to a
//! direction.
//!
//! # Method
//! After Keinert, Innmann, Sänger and Stamminger, "Spherical Fibonacci Mapping", ACM TOG
//! 34(6), 2015: in the cylinder coordinates (phase `t` in turns, index `u`) the points
//! `(tⱼ, j)`, `tⱼ = frac(j·g + P)`, are the part `0 ≤ j < N` of the planar lattice
//! `L = {(j·g + P + m, j) : j, m ∈ ℤ}` (`g` the golden step, `P` the pole phase). For
//! consecutive Fibonacci numbers `Fₖ, Fₖ₊₁` the vectors `bₖ = (εₖ, Fₖ)`,
//! `bₖ₊₁ = (εₖ₊₁, Fₖ₊₁)` with `εₖ = wrap(Fₖ·g) ≈ (−1)ᵏ⁻¹Φ⁻ᵏ` are a basis of `L` with
//! determinant ±1 (Cassini's identity), so lattice coordinates of any point are
//! `c = ±(Fₖ₊₁·t − εₖ₊₁·u, −Fₖ·t + εₖ·u)`. On the sphere the azimuth step of `bₖ` is
//! `2π·sinθ·|εₖ|` and its height step `Fₖ·Δ/sinθ` (`Δ = 2/N` on the sphere, `1/N` on the
//! hemisphere); they balance at `Φ²ᵏ ≈ 2π√5·sin²θ/Δ`, which is `√5·π·N·(1 − z²)` on the
//! sphere as in the paper.
//!
//! The paper solves for the lattice cell of the query in `f32` and tests its four corners.
//! Here the search is organised so that it is exact by construction rather than by a
//! heuristic neighbourhood:
//!
//! 1. Every point within chord distance `r` of the query lies in a band of indices
//!    `[j_lo, j_hi]` (from the height range `θ_q ± 2·asin(r/2)`) and, within the band, in
//!    an azimuth window `|φⱼ − φ_q| ≤ W` (from `r² ≥ m² + 4·sinθⱼ·sinθ_q·sin²(Δφ/2)`, `m`
//!    the meridian chord from the query to the band, with the smallest `sinθ` of the
//!    band). Both bounds are widened by the rounding tolerances of this module.
//! 2. The lattice points of that box are enumerated with the Fibonacci basis `(Fₖ, Fₖ₊₁)`
//!    whose cells best fit the box (for the usual box this is the paper's `k`; for the thin
//!    boxes near a hemisphere's horizon it is larger). Lattice coordinates are formed in
//!    exact 64-bit integer arithmetic: the fractional coordinates of the box centre are
//!    `±Fₖ₊₁·D` and `∓Fₖ·D` (mod 1), `D = Q − phase(j₀)` the query's phase relative to an
//!    anchor index `j₀`, as wrapping `u64` products, and the index of the cell corner is
//!    `j₀ − (f₀·Fₖ + f₁·Fₖ₊₁)`, an exact integer (`u128`). No phase of a point is ever
//!    formed in floating point. That is what breaks `f32` ports of the published shader:
//!    `frac(j·Φ⁻¹)` in `f32` puts points of the `N = 2¹⁶` set up to a whole point spacing
//!    from where they are (14 % of them by more than half a spacing; see the test
//!    `naive_f32_phase_is_off_by_more_than_the_spacing`). The 2π wrap of the azimuth needs
//!    no care: a full turn is a lattice vector that leaves every index unchanged.
//! 3. Each candidate of the box is tested with two integer comparisons (band, exact phase
//!    window); the survivors are evaluated (below) and the nearest is kept. If it lies
//!    within `r`, it is the nearest point of the whole set; otherwise the search is repeated
//!    with `r` = that distance (or `2r` if the box held no point). The first `r` is
//!    `0.6·√(area/N)`, just below the typical distance to the nearest point's competitors,
//!    which minimised the total work; 3–4 % of the queries take a second pass. The polar
//!    caps (where the window is the whole circle) are scanned index by index, a handful of
//!    points. Below the horizon of a hemisphere set the first `r` reaches past the lowest
//!    ring by the amount that holds about two points.
//!
//! Candidates are compared by the chord distance in the cancellation-free form
//! `Δz² + (sinθⱼ − sinθ_q)² + 4·sinθⱼ·sinθ_q·sin²(Δφ/2)`, with `Δφ` the exact 64-bit phase
//! difference, heights `1 ∓ z` formed from integers near each pole, and the query phase
//! from an octant-reduced `atan2` (error ≤ 1.1·10⁻⁷ rad). The result is the exact nearest
//! point up to near-ties: the tests found every other answer within 1.1·10⁻⁷ (chord) of the
//! nearest distance, and allow 10⁻⁶.
//!
//! The Fibonacci-number lattice (`N = Fₘ`, phase `j·Fₘ₋₁/Fₘ` reduced in integers) is the
//! same lattice problem with a rational step and uses the same code, with bases up to
//! `Fₖ₊₁ ≤ Fₘ₋₂` (so that the determinant stays ±1). An arbitrary rotation is undone by
//! applying its transpose to the query; the pole phase needs nothing, since candidate
//! phases come from `phase_of`, which includes it.
//!
//! # Range
//! Every set the crate can build (`N ≤ 2²⁴`) is supported: sphere, hemisphere (queries on
//! the whole sphere) and lattice, plain, phase-rotated and rotated. The tests compare 10⁵
//! random queries per `N` for `N` up to `2²⁴` with an exact `f64` search. The index
//! arithmetic assumes `N ≤ 2²⁴` (index margins in `f32`); larger sets cannot be built.
//!
//! # Cost
//! This module uses `f32` and integer arithmetic only; no `f64`. Per call: one square root
//! and a division to normalise, one `atan2`, about five square roots and four divisions
//! for the box, three `floor`s, a few 64×64-bit multiplies (two into `u128`), and per
//! candidate a 64-bit multiply and two comparisons; per *evaluated* candidate one square
//! root, one [`math::sin_cos_turns`] (a short f32 polynomial on the exact phase difference),
//! one division and about a dozen multiply-adds. Measured over random
//! queries (`search_cost`): on the sphere 1.5–1.7 evaluations and 3–3.3 lattice points on
//! average for `N ≥ 1000` (at most 8 evaluations), for a hemisphere set queried on the
//! whole sphere 2.3–2.6 (at most 15); small sets (`N ≈ 100`) 2.4, mostly polar caps.
//! Sets of up to 8 points are scanned whole.
//!
//! # Math backends
//! The result does not depend on the backend: the query's phase always uses `libm`'s
//! `atan2f` ([`math::atan2_accurate`], f32 arithmetic; micromath's 2.8·10⁻³ rad error would
//! turn the exact search into a near-nearest one), and the points' sines and cosines come
//! from [`math::sin_cos_turns`] under both backends.

use super::{Domain, FibonacciPoints, Step, GOLDEN_PHASE};
use crate::error::Error;
use crate::math;
use crate::vec3::Vec3;

/// 2⁶⁴: one turn in phase units.
const TURN: f32 = 18_446_744_073_709_551_616.0;
/// 2⁻⁶⁴.
const INV_TURN: f32 = 1.0 / TURN;
/// Half a turn in phase units.
const HALF_TURN: u64 = 1 << 63;
/// A quarter turn in phase units.
const QUARTER_TURN: u64 = 1 << 62;

/// Relative widening of the search radius (chord): a few `f32` roundings in the band and
/// window formulas.
const REL_TOL: f32 = 4e-6;
/// Absolute widening of the search radius (chord): how far the query as this module
/// represents it (normalised, rotated, height and `atan2` phase in `f32`) may be from the
/// direction passed in, about 10⁻⁶.
const ABS_TOL: f32 = 2e-6;

/// Relative error allowed for heights `1 ∓ z` when they are turned into indices.
const HEIGHT_TOL: f32 = 2e-6;

/// Initial search radius in units of `√(area per point)`.
const START_RADIUS: f32 = 0.6;

/// Sets this small are searched exhaustively.
const BRUTE_FORCE_MAX: usize = 8;

/// Passes of the search after which the best point found so far is returned (never
/// reached in the tests).
const MAX_PASSES: u32 = 40;

/// Largest Fibonacci index used for a lattice basis.
const KMAX: usize = 44;

/// `F₀ … F_{KMAX+1}`.
const FIB: [u64; KMAX + 2] = fib_table();

/// `Fₖ` as `f32`.
const FIB_F32: [f32; KMAX + 2] = fib_f32_table();

/// `|εₖ|` of the golden step in turns (`Fₖ × GOLDEN_PHASE` as a signed fraction of a turn);
/// the Fibonacci-number lattice has nearly the same values for the `k` it uses.
const EPS_F32: [f32; KMAX + 2] = eps_f32_table();

const fn fib_table() -> [u64; KMAX + 2] {
    let mut t = [0u64; KMAX + 2];
    t[1] = 1;
    let mut i = 2;
    while i < KMAX + 2 {
        t[i] = t[i - 1] + t[i - 2];
        i += 1;
    }
    t
}

const fn fib_f32_table() -> [f32; KMAX + 2] {
    let f = fib_table();
    let mut t = [0f32; KMAX + 2];
    let mut i = 0;
    while i < KMAX + 2 {
        t[i] = f[i] as f32;
        i += 1;
    }
    t
}

const fn eps_f32_table() -> [f32; KMAX + 2] {
    let f = fib_table();
    let mut t = [0f32; KMAX + 2];
    let mut i = 0;
    while i < KMAX + 2 {
        t[i] = (f[i].wrapping_mul(GOLDEN_PHASE) as i64).unsigned_abs() as f32 * INV_TURN;
        i += 1;
    }
    t
}

/// The query in the set's own frame.
#[derive(Clone, Copy, Debug)]
struct Query {
    /// Height `z = cos θ`.
    z: f32,
    /// `1 − z`, to full relative precision when `z ≥ 0`.
    a: f32,
    /// `1 + z`, to full relative precision when `z < 0`.
    b: f32,
    /// `sin θ`.
    s: f32,
    /// Azimuth as a 64-bit fraction of a turn (absolute, like `phase_of`).
    phase: u64,
    /// Continuous index of the query's height (`j` at which `zⱼ = z`).
    u: f32,
}

/// Best candidate so far.
#[derive(Clone, Copy, Debug)]
struct Best {
    j: usize,
    d2: f32,
    /// Work counters (for the cost figures in the docs and the tests).
    evals: u32,
    visits: u32,
    passes: u32,
}

impl Best {
    const NONE: Self = Self { j: usize::MAX, d2: f32::INFINITY, evals: 0, visits: 0, passes: 0 };

    #[inline]
    fn offer(&mut self, j: usize, d2: f32) {
        self.evals += 1;
        if d2 < self.d2 || (d2 == self.d2 && j < self.j) {
            self.j = j;
            self.d2 = d2;
        }
    }
}

/// Indices and azimuth window that contain every point within the search radius.
#[derive(Clone, Copy, Debug)]
struct SearchBox {
    lo: usize,
    hi: usize,
    /// Half-width of the phase window; `None` for the full circle.
    window: Option<u64>,
}

/// Azimuth of `(x, y)` as a 64-bit fraction of a turn, from an `atan2` of an argument
/// reduced to the first octant (error about 10⁻⁷ rad with `libm`).
fn phase_of_xy(x: f32, y: f32) -> u64 {
    const SCALE: f32 = TURN / core::f32::consts::TAU;
    let (ax, ay) = (math::abs(x), math::abs(y));
    let in_quadrant = if ay <= ax {
        (math::atan2_accurate(ay, ax) * SCALE) as u64
    } else {
        QUARTER_TURN.saturating_sub((math::atan2_accurate(ax, ay) * SCALE) as u64)
    };
    match (x < 0.0, y < 0.0) {
        (false, false) => in_quadrant,
        (true, false) => HALF_TURN - in_quadrant,
        (true, true) => HALF_TURN + in_quadrant,
        (false, true) => in_quadrant.wrapping_neg(),
    }
}

/// `v / |v|` for any finite non-zero `v` ([`Vec3::try_normalize`]).
#[inline]
fn unit(v: Vec3) -> Option<Vec3> {
    v.try_normalize()
}

impl FibonacciPoints {
    /// Index of the point of the set nearest to the direction `dir` (normalised first; it
    /// need not be a unit vector): the inverse spherical Fibonacci mapping.
    ///
    /// After Keinert, Innmann, Sänger and Stamminger, "Spherical Fibonacci Mapping" (ACM
    /// TOG 34(6), 2015), organised as an exact search: the candidates are the lattice
    /// points of a box in (phase, index) space that provably holds every point within a
    /// search radius, enumerated with a Fibonacci lattice basis in exact 64-bit integer
    /// arithmetic (no point phase is formed in floating point, which is what makes `f32`
    /// ports of the published shader fail at large `N`).
    ///
    /// - **Result:** the nearest point by chord (equivalently angular) distance, up to
    ///   near-ties: any other answer is within 10⁻⁶ of the nearest distance (measured:
    ///   1.1·10⁻⁷). Holds for every set the crate builds (`N ≤ 2²⁴`): sphere, hemisphere
    ///   (for directions anywhere on the sphere, including below its horizon),
    ///   Fibonacci-number lattice, with pole phase and arbitrary rotation. Tested with 10⁵
    ///   random directions per `N` up to `2²⁴` against an exact `f64` search.
    /// - **Cost:** no `f64`; one `atan2`, about seven `f32` square roots, and on average
    ///   1.6 (sphere) to 2.6 (hemisphere queried everywhere) candidate evaluations of one
    ///   short polynomial sine and one square root each, at most about 15; sets of up to 8
    ///   points are scanned whole.
    /// - **Backends:** the same answer under `libm` and `micromath` (the query phase always
    ///   uses `libm`'s `atan2f`).
    ///
    /// The index is always valid (`< len()`).
    ///
    /// ```
    /// use sphere_quadrature::{FibonacciPoints, Vec3};
    /// let set = FibonacciPoints::sphere(1000).unwrap();
    /// let p = set.point(417).unwrap();
    /// assert_eq!(set.nearest_index(p), Ok(417));
    /// assert_eq!(set.nearest_index(Vec3::Z), Ok(0));
    /// ```
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] when `dir` is zero or has a NaN or infinite component
    /// (any other vector is normalised, however short or long: crate docs, "Directions").
    pub fn nearest_index(&self, dir: Vec3) -> Result<usize, Error> {
        self.locate(dir).map(|best| best.j)
    }

    /// The search behind [`Self::nearest_index`], with its work counters.
    fn locate(&self, dir: Vec3) -> Result<Best, Error> {
        let world = unit(dir).ok_or(Error::InvalidDirection)?;
        let mut v = world;
        if let Some(r) = &self.rotation {
            v = r.transpose() * v;
        }
        // One Newton step on the length undoes the rotation's rounding (|v| = 1 ± 3·10⁻⁷).
        let l2 = v.length_squared();
        v = v * (1.5 - 0.5 * l2);
        let mut best = Best::NONE;
        if self.n == 1 {
            best.j = 0;
            return Ok(best);
        }
        let q = self.query(v);
        if self.n <= BRUTE_FORCE_MAX {
            for j in 0..self.n {
                best.offer(j, self.dist2(&q, j));
            }
            return Ok(best);
        }
        Ok(self.search(&q))
    }

    /// `1/Δ`: index steps per unit of `1 − z`.
    #[inline]
    fn inv_delta(&self) -> f32 {
        match self.domain {
            Domain::Sphere => 0.5 * self.n as f32,
            Domain::Hemisphere => self.n as f32,
        }
    }

    /// Area of the domain per point.
    #[inline]
    fn area_per_point(&self) -> f32 {
        let area = match self.domain {
            Domain::Sphere => 2.0 * core::f32::consts::TAU,
            Domain::Hemisphere => core::f32::consts::TAU,
        };
        area / self.n as f32
    }

    /// `(1 − zⱼ, 1 + zⱼ)` of point `j`, the smaller one formed from integers (full
    /// relative precision at both poles).
    #[inline]
    fn heights(&self, j: usize) -> (f32, f32) {
        let n = self.n as u64;
        let j = j as u64;
        match self.domain {
            Domain::Sphere => {
                if 2 * j < n {
                    let a = (2 * j + 1) as f32 / n as f32;
                    (a, 2.0 - a)
                } else {
                    let b = (2 * (n - 1 - j) + 1) as f32 / n as f32;
                    (2.0 - b, b)
                }
            }
            Domain::Hemisphere => {
                let a = (2 * j + 1) as f32 / (2 * n) as f32;
                (a, 2.0 - a)
            }
        }
    }

    /// Phase step of an index offset `f` (without the pole phase), as a signed fraction of
    /// a turn.
    #[inline]
    fn step_phase(&self, f: u64) -> i64 {
        match self.step {
            Step::Golden => f.wrapping_mul(GOLDEN_PHASE) as i64,
            Step::Fibonacci { prev } => {
                let n = self.n as u64;
                let r = (f % n) * prev % n;
                (((r as u128) << 64) / (n as u128)) as u64 as i64
            }
        }
    }

    /// Continuous index of the height with `1 − z = a`.
    #[inline]
    fn index_of_a(&self, a: f32) -> f32 {
        a * self.inv_delta() - 0.5
    }

    /// Continuous index of the height with `1 + z = b` (sphere only:
    /// `1 + zⱼ = (2(N−1−j)+1)/N`).
    #[inline]
    fn index_of_b(&self, b: f32) -> f32 {
        self.n as f32 - 0.5 - b * self.inv_delta()
    }

    /// The query from its unit direction `v` in the set's frame (`world`: before the
    /// rotation).
    fn query(&self, v: Vec3) -> Query {
        let rho2 = v.x * v.x + v.y * v.y;
        let (a, b) = if v.z >= 0.0 {
            (rho2 / (1.0 + v.z), 1.0 + v.z)
        } else {
            (1.0 - v.z, rho2 / (1.0 - v.z))
        };
        let u = match self.domain {
            Domain::Sphere if a > 1.0 => self.index_of_b(b),
            _ => self.index_of_a(a),
        };
        Query { z: v.z, a, b, s: math::sqrt(rho2), phase: phase_of_xy(v.x, v.y), u }
    }

    /// `z_j − z_q` and `sin θⱼ` without cancellation near the poles.
    #[inline]
    fn dz_and_sin(&self, q: &Query, j: usize) -> (f32, f32) {
        let (a, b) = self.heights(j);
        let s = math::sqrt(a * b);
        let dz = if a <= 1.0 && q.a <= 1.0 {
            q.a - a
        } else if b <= 1.0 && q.b <= 1.0 {
            b - q.b
        } else {
            let z = if a <= 1.0 { 1.0 - a } else { b - 1.0 };
            z - q.z
        };
        (dz, s)
    }

    /// Squared chord distance from the query to point `j` (`j < N`) in the
    /// cancellation-free form `Δz² + (sinθⱼ − sinθ_q)² + 4·sinθⱼ·sinθ_q·sin²(Δφ/2)` with
    /// the exact phase difference.
    #[inline]
    fn dist2(&self, q: &Query, j: usize) -> f32 {
        let (dz, s) = self.dz_and_sin(q, j);
        let ds = s - q.s;
        // Sine of half the exact phase difference: a signed half of the difference, as a
        // fraction of a turn.
        let half = (self.phase_of(j).wrapping_sub(q.phase) as i64 >> 1) as u64;
        let h = math::sin_cos_turns(half).0;
        dz * dz + ds * ds + 4.0 * s * q.s * h * h
    }

    /// Squared chord from the query to the circle of heights of point `j`.
    #[inline]
    fn height_dist2(&self, q: &Query, j: usize) -> f32 {
        let (dz, s) = self.dz_and_sin(q, j);
        let ds = s - q.s;
        dz * dz + ds * ds
    }

    /// The exact search (see the module docs).
    fn search(&self, q: &Query) -> Best {
        let area = self.area_per_point();
        // Lower bound of the distance to the set: only below a hemisphere's lowest ring.
        let mut floor2 = 0.0f32;
        let mut extra = START_RADIUS * START_RADIUS * area;
        if self.domain == Domain::Hemisphere && q.u > (self.n - 1) as f32 {
            floor2 = self.height_dist2(q, self.n - 1);
            // Radius beyond the ring sized so that about two points are expected: the
            // region 2·sinβ·h + cosβ·w² ≤ C has area (2/3)·C^{3/2}/(sinβ·√cosβ).
            let sin_beta = -q.z;
            if sin_beta > 0.0 {
                let c = math::powf(3.0 * area * sin_beta * math::sqrt(q.s), 2.0 / 3.0);
                if c > extra {
                    extra = c;
                }
            }
        }
        let mut r2 = floor2 + extra;
        let mut best = Best::NONE;
        for _ in 0..MAX_PASSES {
            best.passes += 1;
            let full = r2 >= 4.0;
            if let Some(bx) = self.search_box(q, r2) {
                self.scan(q, &bx, &mut best);
            }
            if best.j != usize::MAX && (best.d2 <= r2 || full) {
                return best;
            }
            r2 = if best.j != usize::MAX { best.d2 } else { floor2 + 4.0 * (r2 - floor2) };
        }
        if best.j == usize::MAX {
            best.j = 0;
        }
        best
    }

    /// The box of indices and phases that contains every point within chord `√r2`
    /// (widened by the tolerances), or `None` when it holds no index of the set.
    fn search_box(&self, q: &Query, r2: f32) -> Option<SearchBox> {
        let n = self.n;
        let r = math::sqrt(r2) * (1.0 + REL_TOL) + ABS_TOL;
        let r2 = r * r;
        if r2 >= 4.0 {
            return Some(SearchBox { lo: 0, hi: n - 1, window: None });
        }
        let half_r2 = 0.5 * r2;
        let cos_g = 1.0 - half_r2;
        let sin_g = r * math::sqrt(1.0 - 0.25 * r2);
        let tol = HEIGHT_TOL * (q.a.min(q.b) + r);
        let sphere = self.domain == Domain::Sphere;
        // Northern end θ_q − γ.
        let lo_f = if q.a <= half_r2 {
            0.0
        } else {
            let a_lo = q.a * cos_g + half_r2 - q.s * sin_g;
            if a_lo <= 1.0 {
                self.index_of_a(a_lo - tol)
            } else if sphere {
                let b_lo = q.b * cos_g + half_r2 + q.s * sin_g;
                self.index_of_b(b_lo + tol)
            } else {
                // The whole band is below the hemisphere's horizon.
                self.index_of_a(a_lo - tol)
            }
        };
        // Southern end θ_q + γ.
        let hi_f = if q.b <= half_r2 {
            n as f32
        } else {
            let a_hi = q.a * cos_g + half_r2 + q.s * sin_g;
            if a_hi <= 1.0 || !sphere {
                self.index_of_a(a_hi + tol)
            } else {
                let b_hi = q.b * cos_g + half_r2 - q.s * sin_g;
                self.index_of_b(b_hi - tol)
            }
        };
        let lo = math::floor(lo_f) - 1.0;
        let hi = math::floor(hi_f) + 2.0;
        let nonempty = lo <= hi && hi >= 0.0 && lo <= (n - 1) as f32;
        if !nonempty {
            return None;
        }
        let lo = if lo < 0.0 { 0 } else { lo as usize };
        let hi = if hi > (n - 1) as f32 { n - 1 } else { hi as usize };
        // Azimuth window.
        // sin θ along the band is smallest at one of its ends.
        let (a_lo, b_lo) = self.heights(lo);
        let (a_hi, b_hi) = self.heights(hi);
        let s_min = math::sqrt((a_lo * b_lo).min(a_hi * b_hi));
        let margin = 2.0 + HEIGHT_TOL * q.u;
        let m2 = if q.u < lo as f32 - margin {
            self.height_dist2(q, lo)
        } else if q.u > hi as f32 + margin {
            self.height_dist2(q, hi)
        } else {
            0.0
        };
        // A lower bound of the true m² (the height chord is accurate to ~5·10⁻⁷).
        let m2 = if m2 > 0.0 { m2 - 2e-6 * math::sqrt(m2) } else { 0.0 };
        let denom = 4.0 * s_min * q.s;
        let x2 = (r2 - m2) / denom;
        let narrow = denom > 0.0 && x2 < 0.5;
        let window = if !narrow {
            None
        } else {
            // |Δφ|/2 ≤ asin(√x2) ≤ tan(asin(√x2)); in turns |Δφ| ≤ that/π.
            let half_w = math::sqrt(x2 / (1.0 - x2));
            let turns = half_w * (1.0 / core::f32::consts::PI) * (1.0 + 1e-5) + 1e-9;
            if turns >= 0.5 {
                None
            } else {
                Some((turns * TURN) as u64)
            }
        };
        Some(SearchBox { lo, hi, window })
    }

    /// Evaluates every point of the box that passes the exact band and window tests.
    fn scan(&self, q: &Query, bx: &SearchBox, best: &mut Best) {
        let Some(w) = bx.window else {
            for j in bx.lo..=bx.hi {
                best.offer(j, self.dist2(q, j));
            }
            return;
        };
        let in_window =
            |j: usize| (self.phase_of(j).wrapping_sub(q.phase) as i64).unsigned_abs() <= w;
        let count = bx.hi - bx.lo + 1;
        if count > 4 && self.scan_lattice(q, bx, w, best) {
            return;
        }
        for j in bx.lo..=bx.hi {
            best.visits += 1;
            if in_window(j) {
                best.offer(j, self.dist2(q, j));
            }
        }
    }

    /// Enumerates the lattice points of the box with the best-fitting Fibonacci basis.
    /// Returns `false` (nothing done) when scanning the band index by index is cheaper.
    fn scan_lattice(&self, q: &Query, bx: &SearchBox, w: u64, best: &mut Best) -> bool {
        let th = w as f32 * INV_TURN;
        let j0 = bx.lo + (bx.hi - bx.lo) / 2;
        let uu = (bx.hi - j0) as f32;
        // Extents of the box along the two basis directions, in lattice units.
        let extent = |k: usize| FIB_F32[k] * th + EPS_F32[k] * uu;
        // The cells fit the box best where Fₖ·th ≈ |εₖ|·uu, i.e. Φ²ᵏ ≈ √5·uu/th, so
        // k ≈ log₂(√5·uu/th) / (2·log₂ Φ) = 0.72·log₂(…); the bit pattern of a positive f32
        // is a piecewise-linear log₂ (error < 0.09). The neighbours of the estimate are tried.
        let ratio = 2.236_068 * uu / th;
        let log2 = ratio.to_bits() as f32 * (1.0 / 8_388_608.0) - 127.0;
        let k_est = (0.720_210_4 * log2) as i32;
        let limit = self.k_limit() as i32;
        let mut best_cost = (bx.hi - bx.lo + 1) as f32;
        let mut best_k = 0;
        for k in (k_est - 1).max(2)..(k_est + 2).min(limit) {
            let k = k as usize;
            let cost = (2.0 * extent(k) + 1.0) * (2.0 * extent(k + 1) + 1.0);
            if cost < best_cost {
                best_cost = cost;
                best_k = k;
            }
        }
        if best_k == 0 {
            return false;
        }
        let k = best_k;
        // `k < k_limit() ≤ KMAX`, so both exist; the `else` (never taken) falls back to the
        // band scan and spares a bounds-check panic path the optimiser cannot remove.
        let (Some(&fk), Some(&fk1)) = (FIB.get(k), FIB.get(k + 1)) else {
            return false;
        };
        let (ek, ek1) = (self.step_phase(fk), self.step_phase(fk1));
        let det = ek as i128 * fk1 as i128 - ek1 as i128 * fk as i128;
        let one = 1i128 << 64;
        let positive = if (det - one).abs() < (1i128 << 32) {
            true
        } else if (det + one).abs() < (1i128 << 32) {
            false
        } else {
            return false;
        };
        let widen = |x: f32| x * (1.0 + 1e-5) + 1e-5;
        let r0 = widen(fk1 as f32 * th + ek1.unsigned_abs() as f32 * INV_TURN * uu);
        let r1 = widen(fk as f32 * th + ek.unsigned_abs() as f32 * INV_TURN * uu);
        // Fractional lattice coordinates of the box centre (query phase, index j0).
        let d = q.phase.wrapping_sub(self.phase_of(j0));
        let p0 = fk1.wrapping_mul(d);
        let p1 = fk.wrapping_mul(d);
        let (f0b, f1b) = if positive { (p0, p1.wrapping_neg()) } else { (p0.wrapping_neg(), p1) };
        // Index of the cell corner: j0 − (f0·Fₖ + f1·Fₖ₊₁), an integer.
        let sum = f0b as u128 * fk as u128 + f1b as u128 * fk1 as u128;
        let corner = j0 as i64 - ((sum + (1u128 << 63)) >> 64) as i64;
        let f0 = f0b as f32 * INV_TURN;
        let f1 = f1b as f32 * INV_TURN;
        let a_min = -math::floor(r0 - f0) as i64;
        let a_max = math::floor(f0 + r0) as i64;
        let b_min = -math::floor(r1 - f1) as i64;
        let b_max = math::floor(f1 + r1) as i64;
        let (lo, hi) = (bx.lo as i64, bx.hi as i64);
        let (fk, fk1) = (fk as i64, fk1 as i64);
        for a in a_min..=a_max {
            let ja = corner + a * fk;
            for b in b_min..=b_max {
                best.visits += 1;
                let j = ja + b * fk1;
                if j < lo || j > hi {
                    continue;
                }
                let j = j as usize;
                if (self.phase_of(j).wrapping_sub(q.phase) as i64).unsigned_abs() <= w {
                    best.offer(j, self.dist2(q, j));
                }
            }
        }
        true
    }

    /// Exclusive upper limit of `k` for a basis `(Fₖ, Fₖ₊₁)`. The golden step has one for
    /// every `k`; the Fibonacci-number lattice `N = Fₘ` needs `k + 1 ≤ m − 2` so that
    /// `|εₖ₊₁| < 1/2` and the determinant is ±1.
    fn k_limit(&self) -> usize {
        match self.step {
            Step::Golden => KMAX,
            Step::Fibonacci { .. } => {
                let n = self.n as u64;
                let mut k = 2;
                while k + 3 < KMAX + 2 && FIB[k + 3] <= n {
                    k += 1;
                }
                k
            }
        }
    }
}

impl<const N: usize> super::SphericalFibonacci<N> {
    /// Index of the point nearest to `dir`; see [`FibonacciPoints::nearest_index`].
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero, NaN or infinite `dir`.
    pub fn nearest_index(&self, dir: Vec3) -> Result<usize, Error> {
        self.set.nearest_index(dir)
    }
}

impl<const N: usize> super::HemisphericalFibonacci<N> {
    /// Index of the point nearest to `dir` (which may point below the horizon); see
    /// [`FibonacciPoints::nearest_index`].
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero, NaN or infinite `dir`.
    pub fn nearest_index(&self, dir: Vec3) -> Result<usize, Error> {
        self.set.nearest_index(dir)
    }
}

impl<const N: usize> super::FibonacciLattice<N> {
    /// Index of the point nearest to `dir`; see [`FibonacciPoints::nearest_index`].
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero, NaN or infinite `dir`.
    pub fn nearest_index(&self, dir: Vec3) -> Result<usize, Error> {
        self.set.nearest_index(dir)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;
    use crate::rotation::RotationSequence;
    use std::println;

    fn uniform_dir(seq: &mut RotationSequence) -> Vec3 {
        let z = 1.0 - 2.0 * seq.next_f32();
        let phi = core::f32::consts::TAU * seq.next_f32();
        let s = math::sqrt((1.0 - z) * (1.0 + z));
        Vec3::new(s * math::cos(phi), s * math::sin(phi), z)
    }

    /// Cassini: consecutive Fibonacci offsets span the phase lattice (determinant ±1 turn),
    /// for every basis the search may use.
    #[test]
    fn fibonacci_offsets_form_lattice_bases() {
        let golden = FibonacciPoints::sphere(1 << 24).unwrap();
        let lattices =
            [89usize, 987, 46_368, 14_930_352].map(|n| FibonacciPoints::lattice(n).unwrap());
        for set in core::iter::once(&golden).chain(lattices.iter()) {
            for k in 2..set.k_limit() {
                let (fk, fk1) = (FIB[k], FIB[k + 1]);
                let (ek, ek1) = (set.step_phase(fk), set.step_phase(fk1));
                let det = ek as i128 * fk1 as i128 - ek1 as i128 * fk as i128;
                assert!((det.abs() - (1i128 << 64)).abs() <= 4 * fk1 as i128, "k={k} {set:?}");
                // |εₖ| ≈ Φ⁻ᵏ, the value the basis choice assumes.
                let eps = ek.unsigned_abs() as f64 / 18_446_744_073_709_551_616.0;
                let want = 1.618_033_988_749_895_f64.powi(-(k as i32));
                if set.step == Step::Golden {
                    // Not exact: the 64-bit step differs from 1/Φ by 2.6·10⁻²¹.
                    assert!((eps / want - 1.0).abs() < 1e-2, "k={k}");
                    assert_eq!(eps as f32, EPS_F32[k]);
                }
            }
        }
    }

    #[test]
    fn query_phase_is_accurate() {
        let mut seq = RotationSequence::new(9);
        let mut worst = 0.0f64;
        for _ in 0..200_000 {
            let v = uniform_dir(&mut seq);
            let got = phase_of_xy(v.x, v.y) as f64 / 18_446_744_073_709_551_616.0;
            let want = (v.y as f64).atan2(v.x as f64) / core::f64::consts::TAU;
            let d = (got - want).rem_euclid(1.0);
            worst = worst.max(d.min(1.0 - d) * core::f64::consts::TAU);
        }
        println!("query phase: worst error {worst:.2e} rad");
        assert!(worst < 2e-7, "{worst}");
    }

    /// The cost figures of the module docs: candidate evaluations (one `sin`, one `sqrt`
    /// each), lattice points visited (one 64-bit multiply each) and search passes.
    #[test]
    fn search_cost() {
        for n in [16usize, 100, 1000, 1 << 16, 1 << 20, 1 << 24] {
            for set in
                [FibonacciPoints::sphere(n).unwrap(), FibonacciPoints::hemisphere(n).unwrap()]
            {
                let mut seq = RotationSequence::new(n as u64);
                let count = 50_000u32;
                let (mut evals, mut visits, mut passes) = (0u64, 0u64, 0u64);
                let (mut max_evals, mut max_visits, mut max_passes) = (0, 0, 0);
                for _ in 0..count {
                    let b = set.locate(uniform_dir(&mut seq)).unwrap();
                    evals += b.evals as u64;
                    visits += b.visits as u64;
                    passes += b.passes as u64;
                    max_evals = max_evals.max(b.evals);
                    max_visits = max_visits.max(b.visits);
                    max_passes = max_passes.max(b.passes);
                }
                let mean = evals as f64 / count as f64;
                println!(
                    "{:?} N={n}: evaluations mean {mean:.2} max {max_evals}, lattice points \
                     mean {:.2} max {max_visits}, passes mean {:.3} max {max_passes}",
                    set.domain(),
                    visits as f64 / count as f64,
                    passes as f64 / count as f64
                );
                // Small sets are mostly polar cap.
                let mean_bound = if n < 1000 { 6.0 } else { 3.0 };
                assert!(mean < mean_bound && max_evals <= 24 && max_passes <= 2, "N={n}");
                assert!(max_visits <= 48, "N={n}");
            }
        }
    }
}
