//! Inverse spherical Fibonacci mapping (`nearest_index`) against exact `f64` nearest-point
//! searches built on the independent `reference` crate.
//!
//! Every random query is rounded to `f32`; the exact search looks for the nearest point to
//! the `f64` normalisation of that rounded query. A different index counts as a tie only
//! when our point is farther than the best by less than `TIE` (chord, computed in `f64`
//! from the reference points); any other difference is a mismatch and fails the test.
//!
//! The reference crate's `nearest_brute_force*` evaluate every point of a height band of
//! `O(d·N)` points per query (about a minute for 10⁵ queries at `N = 2²²`), and the
//! hemisphere version most of the set for queries far below the horizon. `ExactSet::nearest`
//! below visits the same rows but skips the evaluation of points that a lower bound of the
//! chord (with the reference phase) excludes, which is exact and fast enough for 10⁵ queries
//! at every `N`; `fast_search_agrees_with_reference_brute_force` checks it against the
//! reference brute force (sphere and hemisphere) and the reference lattice points.
//!
//! Statistics are printed with `cargo test --test points inverse:: -- --nocapture`.

use std::f64::consts::{PI, TAU};

use reference::rng::Rng;
use reference::sf as rsf;
use sphere_quadrature::sf::{FibonacciLattice, HemisphericalFibonacci, SphericalFibonacci};
use sphere_quadrature::{Error, FibonacciPoints, Mat3, RotationSequence, Vec3};

/// Largest excess distance (chord) of a returned point over the exact nearest that counts
/// as a tie: a few `f32` roundings of unit vectors.
const TIE: f64 = 1e-6;

/// Largest excess distance allowed anywhere (both math backends give the same answers).
const EXCESS: f64 = TIE;

type Point = [f64; 3];

fn chord(p: Point, q: Point) -> f64 {
    let d = [p[0] - q[0], p[1] - q[1], p[2] - q[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

fn normalize(q: Point) -> Point {
    let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
    [q[0] / l, q[1] / l, q[2] / l]
}

fn to_f64(v: Vec3) -> Point {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// The query as the `f32` vector we pass, and the `f64` direction the exact search uses.
fn round_query(q: Point) -> (Vec3, Point) {
    let v = Vec3::new(q[0] as f32, q[1] as f32, q[2] as f32);
    (v, normalize(to_f64(v)))
}

/// `m · p` for a matrix given as `f32` rows, in `f64`.
fn mat_mul(m: &Mat3, p: Point) -> Point {
    let r = |v: Vec3| v.x as f64 * p[0] + v.y as f64 * p[1] + v.z as f64 * p[2];
    [r(m.rows[0]), r(m.rows[1]), r(m.rows[2])]
}

/// Exact inverse of a matrix given as `f32` rows, in `f64` (adjugate over determinant).
fn mat_inverse(m: &Mat3) -> [[f64; 3]; 3] {
    let a: Vec<Point> = m.rows.iter().map(|&r| to_f64(r)).collect();
    let c = |i: usize, j: usize| {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1]
    };
    let det = a[0][0] * c(0, 0) + a[0][1] * c(0, 1) + a[0][2] * c(0, 2);
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = c(j, i) / det;
        }
    }
    inv
}

fn mul_rows(m: &[[f64; 3]; 3], p: Point) -> Point {
    let r = |v: &[f64; 3]| v[0] * p[0] + v[1] * p[1] + v[2] * p[2];
    [r(&m[0]), r(&m[1]), r(&m[2])]
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Sphere,
    Hemisphere,
    /// Fibonacci-number lattice `n = Fₘ` with predecessor `prev`.
    Lattice {
        prev: u64,
    },
}

/// A point set evaluated in `f64` from its definition, with the reference crate's phase,
/// and an exact nearest-point search.
#[derive(Clone, Copy, Debug)]
struct ExactSet {
    n: u64,
    kind: Kind,
    /// Pole rotation in turns.
    offset: f64,
}

impl ExactSet {
    fn new(n: usize, kind: Kind) -> Self {
        Self { n: n as u64, kind, offset: 0.0 }
    }

    fn lattice(n: usize) -> Self {
        let prev = rsf::fibonacci_predecessor(n as u64).unwrap();
        Self::new(n, Kind::Lattice { prev })
    }

    fn with_phase_bits(mut self, bits: u64) -> Self {
        self.offset = bits as f64 / 18_446_744_073_709_551_616.0;
        self
    }

    /// `(z, 1 − z, 1 + z)` of point `j`, each a ratio of integers.
    fn heights(&self, j: u64) -> (f64, f64, f64) {
        let n = self.n as i128;
        let j = j as i128;
        let (num_z, num_a, num_b, d) = match self.kind {
            Kind::Hemisphere => (2 * n - 2 * j - 1, 2 * j + 1, 4 * n - 2 * j - 1, 2 * n),
            _ => (n - 2 * j - 1, 2 * j + 1, 2 * n - 2 * j - 1, n),
        };
        let d = d as f64;
        (num_z as f64 / d, num_a as f64 / d, num_b as f64 / d)
    }

    /// Phase in turns (not wrapped), from the reference definitions.
    fn phase(&self, j: u64) -> f64 {
        let t = match self.kind {
            Kind::Lattice { prev } => {
                ((j as u128 * prev as u128) % self.n as u128) as f64 / self.n as f64
            }
            _ => rsf::golden_phase(j),
        };
        t + self.offset
    }

    fn point(&self, j: u64) -> Point {
        let (z, a, b) = self.heights(j);
        let s = (a * b).sqrt();
        let (sn, cs) = (TAU * self.phase(j)).sin_cos();
        [s * cs, s * sn, z]
    }

    /// Phase step from one index to the next, in turns (rounded; only for pruning).
    fn phase_step(&self) -> f64 {
        match self.kind {
            Kind::Lattice { prev } => prev as f64 / self.n as f64,
            _ => 0.618_033_988_749_894_9,
        }
    }

    /// Exact nearest point `(index, chord)` to the unit vector `q`: rows are visited outward
    /// from the query's height and the scan stops once the meridian chord alone exceeds the
    /// best distance; within a row, `chord² ≥ chord²_meridian + 4·sθⱼ·sθ_q·(|Δφ|/π)²`
    /// (`sin x ≥ 2x/π`) skips the evaluation of points that cannot win. For that bound the
    /// phase is advanced by adding the step (error < 10⁻¹¹ turn over any scan, covered by
    /// `PHASE_SLACK`); candidates that pass are evaluated from the exact definition.
    fn nearest(&self, q: Point) -> (u64, f64) {
        const PHASE_SLACK: f64 = 1e-9;
        let n = self.n;
        let sq = (q[0] * q[0] + q[1] * q[1]).sqrt();
        let tq = q[1].atan2(q[0]) / TAU;
        let u = match self.kind {
            Kind::Hemisphere => (2.0 * n as f64 * (1.0 - q[2]) - 1.0) * 0.5,
            _ => (n as f64 * (1.0 - q[2]) - 1.0) * 0.5,
        };
        let start = u.round().clamp(0.0, (n - 1) as f64) as u64;
        let mut best = (start, chord(self.point(start), q));
        // Generous: the pruning quantities below are rounded a little differently from the
        // exact evaluation.
        let slack = 1.0 + 1e-6;
        // Heights by multiplication (within an ulp; pruning only).
        let (inv_d, two_n) = match self.kind {
            Kind::Hemisphere => (0.5 / n as f64, 2 * n),
            _ => (1.0 / n as f64, n),
        };
        for dir in [-1i64, 1] {
            let mut j = start as i64 + dir;
            if j < 0 || j as u64 >= n {
                continue;
            }
            let step = dir as f64 * self.phase_step();
            let mut t = (self.phase(j as u64) - tq).rem_euclid(1.0);
            while j >= 0 && (j as u64) < n {
                let ju = j as u64;
                let dt = if t > 0.5 { 1.0 - t } else { t };
                j += dir;
                t += step;
                if t >= 1.0 {
                    t -= 1.0;
                } else if t < 0.0 {
                    t += 1.0;
                }
                let a = (2 * ju + 1) as f64 * inv_d;
                let b = (2 * (two_n - ju) - 1) as f64 * inv_d;
                let z = 0.5 * (b - a);
                let s = (a * b).sqrt();
                let meridian2 = (z - q[2]).powi(2) + (s - sq).powi(2);
                let best2 = best.1 * best.1 * slack;
                if meridian2 > best2 {
                    break;
                }
                let dt = (dt - PHASE_SLACK).max(0.0);
                if meridian2 + 4.0 * s * sq * (2.0 * dt).powi(2) > best2 {
                    continue;
                }
                let d = chord(self.point(ju), q);
                if d < best.1 || (d == best.1 && ju < best.0) {
                    best = (ju, d);
                }
            }
        }
        best
    }
}

#[derive(Debug, Default, Clone, Copy)]
struct Stats {
    queries: usize,
    exact: usize,
    ties: usize,
    mismatches: usize,
    /// Largest excess over the exact nearest distance among different answers.
    worst_excess: f64,
}

impl Stats {
    fn add(&mut self, o: &Stats) {
        self.queries += o.queries;
        self.exact += o.exact;
        self.ties += o.ties;
        self.mismatches += o.mismatches;
        self.worst_excess = self.worst_excess.max(o.worst_excess);
    }

    fn record(&mut self, got: usize, best: u64, best_dist: f64, got_dist: f64) {
        self.queries += 1;
        if got as u64 == best {
            self.exact += 1;
            return;
        }
        let excess = got_dist - best_dist;
        self.worst_excess = self.worst_excess.max(excess);
        if excess < TIE {
            self.ties += 1;
        } else {
            self.mismatches += 1;
        }
    }
}

/// Runs `f` over `queries` on the available threads and sums the statistics.
fn parallel(queries: &[Point], f: impl Fn(&[Point]) -> Stats + Sync) -> Stats {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(8);
    let chunk = queries.len().div_ceil(threads).max(1);
    let mut total = Stats::default();
    std::thread::scope(|s| {
        let handles: Vec<_> = queries.chunks(chunk).map(|c| s.spawn(|| f(c))).collect();
        for h in handles {
            total.add(&h.join().unwrap());
        }
    });
    total
}

fn sphere_queries(seed: u64, count: usize) -> Vec<Point> {
    let mut rng = Rng::new(seed);
    (0..count).map(|_| rng.uniform_sphere()).collect()
}

/// `count` random queries for `set` (unrotated) against the exact search of `exact`.
fn check(set: &FibonacciPoints, exact: ExactSet, count: usize, seed: u64) -> Stats {
    let queries = sphere_queries(seed, count);
    let stats = parallel(&queries, |qs| {
        let mut st = Stats::default();
        for &q in qs {
            let (v, qn) = round_query(q);
            let got = set.nearest_index(v).unwrap();
            let (best, dist) = exact.nearest(qn);
            st.record(got, best, dist, chord(exact.point(got as u64), qn));
        }
        st
    });
    println!("{:?} N={}: {stats:?}", exact.kind, exact.n);
    stats
}

fn check_sphere(n: usize, count: usize) -> Stats {
    let set = FibonacciPoints::sphere(n).unwrap();
    check(&set, ExactSet::new(n, Kind::Sphere), count, 0x5EED_0000 + n as u64)
}

fn check_hemisphere(n: usize, count: usize) -> Stats {
    let set = FibonacciPoints::hemisphere(n).unwrap();
    check(&set, ExactSet::new(n, Kind::Hemisphere), count, 0x4E41_0000 + n as u64)
}

fn check_lattice(n: usize, count: usize) -> Stats {
    let set = FibonacciPoints::lattice(n).unwrap();
    check(&set, ExactSet::lattice(n), count, 0x1A77_0000 + n as u64)
}

/// Random rotations and pole phases: `rotations` sets with `per` queries each. The truth
/// is `R·p` with `R` the `f32` matrix in `f64`; the exact search runs in the set's frame
/// (`R⁻¹` exact in `f64`) and the two answers are compared by their world distances.
fn check_rotated(n: usize, kind: Kind, rotations: usize, per: usize) -> Stats {
    let mut seq = RotationSequence::new(0xC0FF_EE00 + n as u64);
    let mut total = Stats::default();
    for i in 0..rotations {
        let r = seq.next_rotation();
        let bits = seq.next_phase();
        let base = match kind {
            Kind::Sphere => FibonacciPoints::sphere(n),
            Kind::Hemisphere => FibonacciPoints::hemisphere(n),
            Kind::Lattice { .. } => FibonacciPoints::lattice(n),
        }
        .unwrap();
        let set = base.with_phase_bits(bits).with_rotation(r).unwrap();
        let exact = match kind {
            Kind::Lattice { .. } => ExactSet::lattice(n),
            k => ExactSet::new(n, k),
        }
        .with_phase_bits(bits);
        let inv = mat_inverse(&r);
        let queries = sphere_queries(0xAB00_0000 + 97 * n as u64 + i as u64, per);
        let st = parallel(&queries, |qs| {
            let mut st = Stats::default();
            for &q in qs {
                let (v, qn) = round_query(q);
                let got = set.nearest_index(v).unwrap();
                let (best, _) = exact.nearest(normalize(mul_rows(&inv, qn)));
                let world = |j: u64| chord(normalize(mat_mul(&r, exact.point(j))), qn);
                st.record(got, best, world(best), world(got as u64));
            }
            st
        });
        total.add(&st);
    }
    println!("rotated {kind:?} N={n}: {total:?}");
    total
}

fn assert_clean(s: &Stats, what: &str) {
    assert_eq!(s.exact + s.ties + s.mismatches, s.queries);
    assert_eq!(s.mismatches, 0, "{what}: {s:?}");
}

#[test]
fn fast_search_agrees_with_reference_brute_force() {
    let mut rng = Rng::new(77);
    for n in [1u64, 2, 3, 100, 1000, 1 << 14, 1 << 20] {
        let count = if n >= 1 << 20 { 300 } else { 2000 };
        let sphere = ExactSet::new(n as usize, Kind::Sphere);
        let hemi = ExactSet::new(n as usize, Kind::Hemisphere);
        for i in 0..count {
            let q = match i {
                0 => [0.0, 0.0, 1.0],
                1 => [0.0, 0.0, -1.0],
                _ => rng.uniform_sphere(),
            };
            let r = rsf::nearest_brute_force(q, n);
            let (j, d) = sphere.nearest(q);
            assert!(j == r.index || d == r.dist, "sphere n={n} q={q:?}: {j} vs {r:?}");
            assert!((d - r.dist).abs() <= 1e-15, "sphere n={n}: {d} vs {r:?}");
            assert_eq!(sphere.point(j), rsf::sphere_point(j, n));
            if n <= 1 << 14 {
                let r = rsf::nearest_brute_force_hemisphere(q, n);
                let (j, d) = hemi.nearest(q);
                assert!(j == r.index || d == r.dist, "hemi n={n} q={q:?}: {j} vs {r:?}");
                assert!((d - r.dist).abs() <= 1e-15, "hemi n={n}: {d} vs {r:?}");
                assert_eq!(hemi.point(j), rsf::hemisphere_point(j, n));
            }
        }
    }
    // The lattice phase and points agree with the reference definition too.
    for n in [2u64, 13, 987, 46_368] {
        let l = ExactSet::lattice(n as usize);
        for j in (0..n).step_by(7) {
            let (p, r) = (l.point(j), rsf::lattice_point(j, n));
            assert!(chord(p, r) < 1e-15, "lattice n={n} j={j}");
        }
    }
}

mod exact {
    use super::*;

    #[test]
    fn sphere_small_n() {
        for (n, count) in
            [(1, 10_000), (2, 10_000), (3, 10_000), (5, 10_000), (16, 100_000), (100, 100_000)]
        {
            assert_clean(&check_sphere(n, count), "sphere");
        }
    }

    #[test]
    fn sphere_up_to_2_16() {
        for n in [1000, 4096, 1 << 14, 1 << 16] {
            assert_clean(&check_sphere(n, 100_000), "sphere");
        }
    }

    #[test]
    fn sphere_2_18_to_2_20() {
        for n in [1 << 18, 1 << 20] {
            assert_clean(&check_sphere(n, 100_000), "sphere");
        }
    }

    #[test]
    fn sphere_2_22() {
        assert_clean(&check_sphere(1 << 22, 100_000), "sphere");
    }

    #[test]
    fn sphere_2_24() {
        assert_clean(&check_sphere(1 << 24, 100_000), "sphere");
    }

    #[test]
    fn hemisphere_with_queries_on_the_whole_sphere() {
        for (n, count) in [(1, 10_000), (2, 10_000), (3, 10_000), (16, 50_000), (100, 50_000)] {
            assert_clean(&check_hemisphere(n, count), "hemisphere");
        }
        for n in [1000, 1 << 14, 1 << 16, 1 << 20, 1 << 24] {
            assert_clean(&check_hemisphere(n, 100_000), "hemisphere");
        }
    }

    #[test]
    fn fibonacci_lattice() {
        for (n, count) in [(2, 10_000), (3, 10_000), (5, 10_000), (13, 20_000), (89, 20_000)] {
            assert_clean(&check_lattice(n, count), "lattice");
        }
        // F₁₉, F₂₄, F₃₀, F₃₆ (the largest Fibonacci number ≤ 2²⁴).
        for n in [4181, 46_368, 832_040, 14_930_352] {
            assert_clean(&check_lattice(n, 100_000), "lattice");
        }
    }

    #[test]
    fn rotated_sets() {
        for n in [5, 100, 4096, 1 << 16, 1 << 20] {
            assert_clean(&check_rotated(n, Kind::Sphere, 10, 2_000), "rotated sphere");
        }
        for n in [100, 1 << 16] {
            assert_clean(&check_rotated(n, Kind::Hemisphere, 10, 2_000), "rotated hemisphere");
        }
        assert_clean(
            &check_rotated(987, Kind::Lattice { prev: 610 }, 10, 2_000),
            "rotated lattice",
        );
    }
}

#[test]
fn poles() {
    for n in [1usize, 2, 3, 5, 16, 100, 1000, 4096, 1 << 14, 1 << 16, 1 << 20, 1 << 24] {
        let s = FibonacciPoints::sphere(n).unwrap();
        let h = FibonacciPoints::hemisphere(n).unwrap();
        let pole = |set: &FibonacciPoints, q: Vec3, want: usize| {
            let got = set.nearest_index(q).unwrap();
            assert_eq!(got, want, "n={n} q={q:?}");
        };
        let (es, eh) = (ExactSet::new(n, Kind::Sphere), ExactSet::new(n, Kind::Hemisphere));
        pole(&s, Vec3::Z, 0);
        pole(&s, -Vec3::Z, n - 1);
        pole(&s, Vec3::new(0.0, 0.0, 1e-20), 0);
        pole(&h, Vec3::Z, 0);
        // Every point is equally far in azimuth from the south pole; the lowest is nearest.
        pole(&h, -Vec3::Z, n - 1);
        // Just off the poles, against the exact search.
        let mut rng = Rng::new(n as u64);
        for kind in [Kind::Sphere, Kind::Hemisphere] {
            let (set, exact) = match kind {
                Kind::Sphere => (s, es),
                _ => (h, eh),
            };
            for i in 0..400 {
                let eps = 10f64.powf(-1.0 - 7.0 * rng.next_f64());
                let phi = TAU * rng.next_f64();
                let z = if i % 2 == 0 { 1.0 } else { -1.0 };
                let (v, qn) = round_query([eps * phi.cos(), eps * phi.sin(), z]);
                let got = set.nearest_index(v).unwrap();
                let (best, dist) = exact.nearest(qn);
                let excess = chord(exact.point(got as u64), qn) - dist;
                assert!(got as u64 == best || excess < EXCESS, "{kind:?} n={n} q={qn:?}");
            }
        }
    }
}

#[test]
fn every_point_maps_to_itself() {
    let max_n = 1 << 24;
    let mut seq = RotationSequence::new(3);
    for n in [1usize, 2, 3, 5, 16, 100, 1000, 4096, 1 << 14, 1 << 16, 1 << 20, 1 << 24] {
        if n > max_n {
            continue;
        }
        let step = (n / 20_000).max(1);
        let sets = [
            FibonacciPoints::sphere(n).unwrap(),
            FibonacciPoints::hemisphere(n).unwrap(),
            FibonacciPoints::sphere(n)
                .unwrap()
                .with_phase_bits(seq.next_phase())
                .with_rotation(seq.next_rotation())
                .unwrap(),
            FibonacciPoints::hemisphere(n).unwrap().with_rotation(seq.next_rotation()).unwrap(),
        ];
        for set in sets {
            for j in (0..n).step_by(step).chain([n - 1]) {
                let p = set.point(j).unwrap();
                assert_eq!(set.nearest_index(p), Ok(j), "n={n} j={j} {set:?}");
                // Non-unit input is normalised.
                assert_eq!(set.nearest_index(p * 7.5), Ok(j), "n={n} j={j}");
            }
        }
    }
    for n in [1usize, 2, 3, 5, 8, 13, 89, 987, 46_368, 14_930_352] {
        if n > max_n {
            continue;
        }
        let set = FibonacciPoints::lattice(n).unwrap();
        for j in (0..n).step_by((n / 20_000).max(1)) {
            assert_eq!(set.nearest_index(set.point(j).unwrap()), Ok(j), "lattice n={n} j={j}");
        }
    }
}

#[test]
fn const_generic_sets_delegate() {
    let s = SphericalFibonacci::<4096>::new();
    let h = HemisphericalFibonacci::<256>::new();
    let l = FibonacciLattice::<233>::new();
    let mut rng = Rng::new(11);
    for _ in 0..2000 {
        let (v, _) = round_query(rng.uniform_sphere());
        assert_eq!(s.nearest_index(v), s.dynamic().nearest_index(v));
        assert_eq!(h.nearest_index(v), h.dynamic().nearest_index(v));
        assert_eq!(l.nearest_index(v), l.dynamic().nearest_index(v));
    }
    let r = RotationSequence::new(5).next_rotation();
    let s = s.with_rotation(r).unwrap().with_phase_bits(12345);
    for j in [0, 1, 2047, 4095] {
        assert_eq!(s.nearest_index(s.point(j).unwrap()), Ok(j));
    }
}

#[test]
fn bad_directions_are_rejected() {
    let s = FibonacciPoints::sphere(100).unwrap();
    let h = HemisphericalFibonacci::<64>::new();
    let one = FibonacciPoints::sphere(1).unwrap();
    for v in [
        Vec3::ZERO,
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, f32::INFINITY, 0.0),
        Vec3::new(0.0, 0.0, f32::NEG_INFINITY),
        Vec3::new(-0.0, 0.0, -0.0),
    ] {
        assert_eq!(s.nearest_index(v), Err(Error::InvalidDirection), "{v:?}");
        assert_eq!(h.nearest_index(v), Err(Error::InvalidDirection), "{v:?}");
        assert_eq!(one.nearest_index(v), Err(Error::InvalidDirection), "{v:?}");
    }
    // Any finite non-zero vector is a direction, however long or short.
    assert_eq!(s.nearest_index(Vec3::new(0.0, 0.0, 3e38)), Ok(0));
    assert_eq!(s.nearest_index(Vec3::new(0.0, 1e-30, -1e-20)), Ok(99));
    assert_eq!(s.nearest_index(Vec3::new(0.0, 0.0, 1e-45)), Ok(0));
    let p = s.point(37).unwrap();
    assert_eq!(s.nearest_index(p * 1e-25), Ok(37));
    assert_eq!(s.nearest_index(p * 1e25), Ok(37));
}

#[test]
fn single_point_set() {
    let s = FibonacciPoints::sphere(1).unwrap();
    let h = FibonacciPoints::hemisphere(1).unwrap();
    let mut rng = Rng::new(1);
    for _ in 0..1000 {
        let (v, _) = round_query(rng.uniform_sphere());
        assert_eq!(s.nearest_index(v), Ok(0));
        assert_eq!(h.nearest_index(v), Ok(0));
    }
    assert_eq!(SphericalFibonacci::<1>::new().nearest_index(-Vec3::Z), Ok(0));
}

/// Why the phase must be exact: `frac(j·Φ⁻¹)` in `f32` (as in a direct `f32` port of the
/// published shader) puts points of the `N = 2¹⁶` set more than a point spacing away from
/// where they are, so a nearest-point search built on it cannot be right.
#[test]
fn naive_f32_phase_is_off_by_more_than_the_spacing() {
    let n = 1u64 << 16;
    let exact = ExactSet::new(n as usize, Kind::Sphere);
    let inv_phi = 0.618_034_f32;
    let spacing = (4.0 * PI / n as f64).sqrt();
    let (mut worst, mut beyond_half) = (0.0f64, 0usize);
    for j in 0..n {
        let t32 = (j as f32 * inv_phi).fract() as f64;
        let p = exact.point(j);
        let (sn, cs) = (TAU * t32).sin_cos();
        let s = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let err = chord([s * cs, s * sn, p[2]], p);
        worst = worst.max(err);
        if err > 0.5 * spacing {
            beyond_half += 1;
        }
    }
    println!(
        "naive f32 phase, N=2^16: worst point error {worst:.5} = {:.3} spacings, \
         {beyond_half} points off by more than half a spacing",
        worst / spacing
    );
    assert!(worst > spacing, "{worst} vs spacing {spacing}");
    assert!(beyond_half > (n / 100) as usize);
    // The crate's exact phase keeps every point far inside its own cell.
    let set = FibonacciPoints::sphere(n as usize).unwrap();
    for j in (0..n).step_by(3) {
        let p = to_f64(set.point(j as usize).unwrap());
        assert!(chord(p, exact.point(j)) < 1e-3 * spacing);
    }
}
