//! The inverse spherical Fibonacci mapping on arbitrary f32 bits (`sf` module docs and
//! `FibonacciPoints::nearest_index`): zero, NaN or infinite directions give
//! `InvalidDirection`, any other direction (however short or long) an index `< len()`; for
//! sets of up to 4096 points the answer is the nearest point up to near-ties (within 10⁻⁶ of
//! the nearest chord, against an f64 brute-force search over the set's own points), for larger
//! sphere sets it is within the covering radius; the const-generic sets agree with the
//! run-time one. Also `Mat3::from_quaternion` (the rotations used here): a finite non-zero
//! quaternion gives the rotation of the normalised quaternion.
#![no_main]

use fuzz_support::{dist2, known_defect, max_abs, non_finite, to64, unit64, Bytes};
use libfuzzer_sys::fuzz_target;
use sphere_quadrature::sf::{Domain, MAX_POINTS};
use sphere_quadrature::{Error, FibonacciPoints, Mat3, SphericalFibonacci, Vec3};

/// Brute-force search up to this size.
const BRUTE_MAX: usize = 4096;

/// The rotation of the quaternion `q` in f64 (`None` for zero or non-finite `q`).
fn rotation64(q: [f32; 4]) -> Option<[[f64; 3]; 3]> {
    if q.iter().any(|x| !x.is_finite()) || q.iter().all(|&x| x == 0.0) {
        return None;
    }
    let m = q.iter().fold(0.0f64, |m, &x| m.max(f64::from(x).abs()));
    let [x, y, z, w] = q.map(|v| f64::from(v) / m);
    let n = (x * x + y * y + z * z + w * w).sqrt();
    let [x, y, z, w] = [x / n, y / n, z / n, w / n];
    Some([
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
        [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
        [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
    ])
}

fn check_quaternion(q: [f32; 4]) -> Mat3 {
    let m = Mat3::from_quaternion(q);
    let Some(want) = rotation64(q) else {
        assert_eq!(m, Mat3::IDENTITY, "from_quaternion({q:?}) of a zero or non-finite q");
        return m;
    };
    // Known defect 6: huge or tiny quaternions (|q|² outside the f32 range) give the identity.
    let n = q.iter().fold(0.0f64, |m, &x| m.max(f64::from(x).abs()));
    if known_defect(6) && !(1e-15..=1e15).contains(&n) {
        return m;
    }
    // Sign convention: a quaternion and its negative are the same rotation; compare both
    // conventions (row/column) loosely by the entries' agreement.
    let got = m.rows.map(to64);
    let err = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .map(|(i, j)| (got[i][j] - want[i][j]).abs())
        .fold(0.0, f64::max);
    let err_t = (0..3)
        .flat_map(|i| (0..3).map(move |j| (i, j)))
        .map(|(i, j)| (got[i][j] - want[j][i]).abs())
        .fold(0.0, f64::max);
    assert!(err.min(err_t) <= 1e-5, "from_quaternion({q:?}) = {m:?}, want {want:?}");
    m
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes::new(data);
    let kind = b.u8() % 3;
    // Small sizes most of the time (brute force), any size up to MAX_POINTS sometimes.
    let n = if b.u8() % 4 == 0 {
        (b.u32() as usize) % (MAX_POINTS + 2)
    } else {
        usize::from(b.u16()) % (BRUTE_MAX + 1)
    };
    let set = match kind {
        0 => FibonacciPoints::sphere(n),
        1 => FibonacciPoints::hemisphere(n),
        _ => FibonacciPoints::lattice(n),
    };
    let valid_size = (1..=MAX_POINTS).contains(&n)
        && (kind != 2 || sphere_quadrature::sf::fibonacci_predecessor(n).is_some());
    let Ok(mut set) = set else {
        assert!(!valid_size, "size {n} of kind {kind} rejected");
        return;
    };
    assert!(valid_size, "size {n} of kind {kind} accepted");
    assert_eq!(set.len(), n);
    let mut rotated = false;
    match b.u8() % 4 {
        0 => {}
        1 => set = set.with_phase_bits(b.u64()),
        2 => set = set.with_angle(b.f32()),
        _ => {
            let q = [b.f32(), b.f32(), b.f32(), b.f32()];
            let m = check_quaternion(q);
            // Any matrix: a valid rotation (`Mat3::validate_rotation`) is taken, anything else
            // (NaN, scaled, a reflection) is refused with InvalidRotation (defect 8).
            let m = if b.u8() % 8 == 0 { Mat3::from_rows(b.vec3(), b.vec3(), b.vec3()) } else { m };
            match set.with_rotation(m) {
                Ok(s) => {
                    assert!(m.validate_rotation().is_ok(), "with_rotation took {m:?}");
                    set = s;
                    rotated = true;
                }
                Err(e) => {
                    assert_eq!(e, Error::InvalidRotation, "with_rotation({m:?})");
                    assert!(m.validate_rotation().is_err(), "with_rotation refused {m:?}");
                }
            }
        }
    }
    let proper = set
        .rotation()
        .is_none_or(|m| m.rows.iter().all(|r| !non_finite(*r) && (r.length() - 1.0).abs() < 1e-3));
    let points: Vec<[f64; 3]> =
        if n <= BRUTE_MAX { set.iter().map(to64).collect() } else { Vec::new() };
    for _ in 0..8 {
        if b.is_empty() {
            break;
        }
        let dir = b.vec3();
        let r = set.nearest_index(dir);
        if non_finite(dir) || max_abs(dir) == 0.0 {
            assert_eq!(r, Err(Error::InvalidDirection), "nearest_index({dir:?})");
            continue;
        }
        let j = r.unwrap_or_else(|e| panic!("nearest_index({dir:?}) = {e:?}"));
        assert!(j < n, "index {j} ≥ {n}");
        if !proper {
            continue;
        }
        let q = unit64(dir);
        let d = dist2(to64(set.point(j).unwrap()), q).sqrt();
        if n <= BRUTE_MAX {
            let best = points.iter().map(|&p| dist2(p, q)).fold(f64::INFINITY, f64::min).sqrt();
            assert!(
                d <= best + 1e-6,
                "n = {n} kind {kind}: nearest_index({dir:?}) = {j} at {d}, best {best}"
            );
        } else if set.domain() == Domain::Sphere || (!rotated && q[2] >= 0.0) {
            // The covering radius of SF sets is about 2.7/√N (metrics::covering_radius docs).
            let bound = 4.0 / (n as f64).sqrt();
            assert!(d <= bound, "n = {n}: nearest_index({dir:?}) = {j} at {d} > {bound}");
        }
        // The const-generic set is the same engine.
        if n == 64 && kind == 0 && set.rotation().is_none() {
            let s = SphericalFibonacci::<64>::new().with_phase_bits(set.phase_bits());
            assert_eq!(s.nearest_index(dir), Ok(j));
        }
        let _: Option<Vec3> = set.point(j);
    }
});
