//! Point-set metrics on arbitrary f32/f64 bits (`metrics` module docs, "Errors"): an empty
//! slice gives `LengthMismatch`, a zero, NaN or infinite direction `InvalidDirection`, `s ∉
//! (1, 2)` `InvalidSmoothness`, a NaN or negative tolerance `InvalidTolerance`, a bad spectrum
//! entry `InvalidSpectrum`, a non-finite circle offset `NonFinite`, nothing panics; Ok results are
//! finite and in range (`E_N ∈ [0, √(4/3)]`, `L₂ = E_N/2`, `wce(3/2) = E_N`, `energy_f32`
//! close to `energy`, separations and covering radii in `[0, 2]`, `C₀ = 1/(4π)` and
//! `0 ≤ C_l ≤ C₀`, `Σₘ Y_lm² = (2l+1)/(4π)`, `Σₘ c_lm² = (2l+1)·C_l`); `sh_index` is
//! `l(l+1) + m` or `None`; the circle functions keep their documented errors.
#![no_main]

use std::f64::consts::PI;

use fuzz_support::{known_defect, max_abs, non_finite, Bytes};
use libfuzzer_sys::fuzz_target;
use sphere_quadrature::metrics::{self, SobolevWeights};
use sphere_quadrature::{Error, Vec3};

/// `Some(true)`: the set must be rejected with `InvalidDirection`; `Some(false)`: accepted;
/// `None`: a direction shorter than 10⁻¹⁵ ("too short to normalise") may go either way.
fn set_bad(points: &[Vec3]) -> Option<bool> {
    if points.iter().any(|&p| non_finite(p) || max_abs(p) == 0.0) {
        Some(true)
    } else if points.iter().any(|&p| f64::from(max_abs(p)) < 1e-15) {
        None
    } else {
        Some(false)
    }
}

fn check<R: std::fmt::Debug>(
    what: &str,
    r: &Result<R, Error>,
    checks: &[(Option<bool>, Error)],
) -> bool {
    for &(bad, err) in checks {
        match bad {
            Some(true) => {
                assert_eq!(r.as_ref().err(), Some(&err), "{what}: want {err:?}, got {r:?}");
                return false;
            }
            Some(false) => {}
            None => {
                // Either way for this argument; then a later check may decide.
                if let Err(e) = r {
                    let later = checks.iter().any(|&(b, e2)| b != Some(false) && e2 == *e);
                    assert!(*e == err || later, "{what}: unexpected {e:?}");
                }
                return r.is_ok();
            }
        }
    }
    assert!(r.is_ok(), "{what}: valid input gave {r:?}");
    true
}

fn read_points(b: &mut Bytes) -> Vec<Vec3> {
    let count = usize::from(b.u8() % 40);
    (0..count).map(|_| b.vec3()).collect()
}

fn s_param(b: &mut Bytes) -> f64 {
    if b.bool() {
        1.0 + f64::from(b.u16()) / 65536.0
    } else {
        b.f64()
    }
}

fn s_bad(s: f64) -> bool {
    !(s > 1.0 && s < 2.0)
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes::new(data);
    let op = b.u8() % 8;
    let points = read_points(&mut b);
    let empty = Some(points.is_empty());
    let bad = set_bad(&points);
    let dir_check = [(empty, Error::LengthMismatch), (bad, Error::InvalidDirection)];
    match op {
        0 => {
            let e = metrics::energy(&points);
            let cap = metrics::cap_discrepancy(&points);
            if check("energy", &e, &dir_check) {
                let e = e.unwrap();
                assert!(
                    e.is_finite() && (0.0..=(4.0f64 / 3.0).sqrt() + 1e-12).contains(&e),
                    "energy {e}"
                );
                assert_eq!(cap, Ok(0.5 * e));
                let w = metrics::wce(&points, 1.5).unwrap();
                assert!((w - e).abs() <= 1e-9 * e + 1e-7, "wce(3/2) {w} ≠ energy {e}");
            }
            let f = metrics::energy_f32(&points);
            // Known defect 3: vectors longer than about 10¹⁹ (|v|² beyond f32).
            if known_defect(3) && points.iter().any(|&p| max_abs(p) > 1e18) {
                return;
            }
            if check("energy_f32", &f, &dir_check) {
                let (f, e) = (f64::from(f.unwrap()), e.unwrap());
                assert!(f.is_finite() && f >= 0.0, "energy_f32 {f}");
                // E_N² is a mean of N² terms of size 1 with f32 rounding each: E_N² to about
                // 10⁻⁶ absolute, so E_N to 10⁻³ relative wherever E_N ≥ 10⁻³.
                assert!(
                    (f * f - e * e).abs() <= 2e-6 + 1e-3 * e * e,
                    "energy_f32 {f} vs energy {e} ({points:?})"
                );
            }
        }
        1 => {
            let s = s_param(&mut b);
            let r = metrics::wce(&points, s);
            let mut checks = vec![(Some(s_bad(s)), Error::InvalidSmoothness)];
            checks.extend(dir_check);
            if check("wce", &r, &checks) {
                let w = r.unwrap();
                assert!(w.is_finite() && w >= 0.0 && w <= 2.0, "wce({s}) = {w}");
            }
        }
        2 => {
            let r = metrics::min_separation(&points);
            let checks =
                [(Some(points.len() < 2), Error::InvalidSize), (bad, Error::InvalidDirection)];
            if check("min_separation", &r, &checks) {
                let d = r.unwrap();
                assert!((0.0..=2.0 + 1e-12).contains(&d), "min_separation {d}");
            }
            let probes = read_points(&mut b);
            let r = metrics::covering_radius(&points, probes.iter().copied());
            let checks = [
                (empty, Error::LengthMismatch),
                (bad, Error::InvalidDirection),
                (set_bad(&probes).map(|x| x && !probes.is_empty()), Error::InvalidDirection),
                (Some(probes.is_empty()), Error::LengthMismatch),
            ];
            // A bad probe after the first is found in order; an empty probe list only when no
            // probe is bad: the checks above are in the function's order up to that.
            if check("covering_radius", &r, &checks) {
                let h = r.unwrap();
                assert!((0.0..=2.0 + 1e-12).contains(&h), "covering_radius {h}");
                if let Ok(m) = metrics::mesh_ratio(&points, probes.iter().copied()) {
                    assert!(!(m < 0.0), "mesh_ratio {m}");
                }
            }
        }
        3 => {
            let len = usize::from(b.u8() % 24);
            let mut out = vec![f64::NAN; len];
            let r = metrics::spectrum(&points, &mut out);
            let checks = [(Some(len == 0), Error::LengthMismatch), dir_check[0], dir_check[1]];
            if check("spectrum", &r, &checks) {
                let c0 = 1.0 / (4.0 * PI);
                assert!((out[0] - c0).abs() <= 1e-12, "C₀ = {}", out[0]);
                for (l, &c) in out.iter().enumerate() {
                    assert!(c.is_finite() && c >= -1e-12 && c <= c0 + 1e-12, "C_{l} = {c}");
                }
                // Σₘ c_lm² = (2l+1)·C_l from the explicit coefficients.
                let l_max = len.min(8) - 1;
                let mut coef = vec![0.0; (l_max + 1) * (l_max + 1)];
                metrics::sh_coefficients(&points, l_max, &mut coef).unwrap();
                for l in 0..=l_max {
                    let sum: f64 = (0..2 * l + 1).map(|k| coef[l * l + k].powi(2)).sum();
                    let want = (2 * l + 1) as f64 * out[l];
                    assert!(
                        (sum - want).abs() <= 1e-10,
                        "Σₘ c_lm² = {sum}, (2l+1)C_l = {want} at l = {l}"
                    );
                }
                let tol = b.f64();
                let r = metrics::design_strength(&points, tol, &mut out);
                if tol.is_nan() || tol < 0.0 {
                    assert_eq!(r, Err(Error::InvalidTolerance));
                } else {
                    assert!(r.unwrap() < len);
                }
                let s = s_param(&mut b);
                let kind =
                    if b.bool() { SobolevWeights::Exact } else { SobolevWeights::Asymptotic };
                let r = metrics::wce_spectral(&points, s, kind, &mut out);
                if s_bad(s) {
                    assert_eq!(r, Err(Error::InvalidSmoothness));
                } else {
                    let w = r.unwrap();
                    assert!(w.is_finite() && w >= 0.0, "wce_spectral {w}");
                }
            }
        }
        4 => {
            let dir = b.vec3();
            let l_max = usize::from(b.u8() % 48);
            let len =
                if b.bool() { (l_max + 1) * (l_max + 1) } else { usize::from(b.u16() % 2500) };
            let mut out = vec![f64::NAN; len];
            let r = metrics::real_sh(dir, l_max, &mut out);
            let checks = [
                (Some(len < (l_max + 1) * (l_max + 1)), Error::LengthMismatch),
                (set_bad(&[dir]), Error::InvalidDirection),
            ];
            if check("real_sh", &r, &checks) {
                for l in 0..=l_max {
                    let sum: f64 = (0..2 * l + 1).map(|k| out[l * l + k].powi(2)).sum();
                    let want = (2 * l + 1) as f64 / (4.0 * PI);
                    assert!(
                        (sum - want).abs() <= 1e-10 * want,
                        "Σₘ Y_lm² = {sum}, want {want} (l = {l}, {dir:?})"
                    );
                }
            }
        }
        5 => {
            let len = usize::from(b.u8() % 40);
            let spectrum: Vec<f64> = (0..len).map(|_| b.f64()).collect();
            let s = s_param(&mut b);
            let kind = if b.bool() { SobolevWeights::Exact } else { SobolevWeights::Asymptotic };
            let r = metrics::wce_from_spectrum(&spectrum, s, kind);
            if s_bad(s) {
                assert_eq!(r, Err(Error::InvalidSmoothness), "wce_from_spectrum s = {s}");
                return;
            }
            // A spectrum is finite and non-negative (every entry, C₀ included): anything else
            // is refused (defect 2).
            let invalid = spectrum.iter().any(|&c| !c.is_finite() || c < 0.0);
            if invalid {
                assert_eq!(r, Err(Error::InvalidSpectrum), "wce_from_spectrum({spectrum:?})");
            } else {
                let w = r.expect("valid spectrum");
                assert!(!w.is_nan() && w >= 0.0, "wce_from_spectrum {w}");
            }
            let l = usize::from(b.u16() % 4096);
            let r = metrics::sobolev_weight(l, s, kind);
            let a = r.expect("valid s");
            assert!(a.is_finite() && a >= 0.0, "a_{l}({s}) = {a}");
        }
        6 => {
            let l = if b.bool() { b.u64() as usize } else { usize::from(b.u16()) };
            let m = if b.bool() { b.u64() as isize } else { isize::from(b.u16() as i16) };
            // Known defect 1: l(l + 1) overflows for l ≥ 2³² (panics with overflow checks).
            if known_defect(1) && l >= 1 << 32 {
                return;
            }
            let r = metrics::sh_index(l, m);
            if m.unsigned_abs() > l {
                assert_eq!(r, None, "sh_index({l}, {m})");
            } else {
                // l(l + 1) + m, exactly: l(l + 1) < 2¹²⁸ and |m| ≤ l.
                let base = (l as u128) * (l as u128 + 1);
                let want = if m < 0 { base - m.unsigned_abs() as u128 } else { base + m as u128 };
                // Beyond usize the index cannot be returned: None then.
                match r {
                    Some(i) => assert_eq!(i as u128, want, "sh_index({l}, {m})"),
                    None => assert!(want > usize::MAX as u128, "sh_index({l}, {m}) = None"),
                }
            }
            let _ = metrics::min_points_for_design(b.u64() as usize);
        }
        _ => {
            let len = usize::from(b.u8() % 32);
            let xs: Vec<f64> = (0..len).map(|_| b.f64()).collect();
            let n = b.u64() as i64;
            let r = metrics::circle_coefficient(&xs, n);
            if xs.is_empty() {
                assert_eq!(r, Err(Error::LengthMismatch));
            }
            let tol = b.f64();
            let n_max = usize::from(b.u8());
            let r = metrics::circle_strength(&xs, tol, n_max);
            if xs.is_empty() && (tol.is_nan() || tol < 0.0) {
                assert!(matches!(r, Err(Error::LengthMismatch | Error::InvalidTolerance)), "{r:?}");
            } else if xs.is_empty() {
                assert_eq!(r, Err(Error::LengthMismatch));
            } else if tol.is_nan() || tol < 0.0 {
                assert_eq!(r, Err(Error::InvalidTolerance));
            } else {
                assert!(r.unwrap() <= n_max);
            }
            let a = b.f64();
            let mut out = vec![0.0; len];
            let r = metrics::uniform_circle_nodes(a, &mut out);
            // Both errors documented, in no stated order.
            if len == 0 && !a.is_finite() {
                assert!(matches!(r, Err(Error::LengthMismatch | Error::NonFinite)), "{r:?}");
            } else if len == 0 {
                assert_eq!(r, Err(Error::LengthMismatch));
            } else if !a.is_finite() {
                assert_eq!(r, Err(Error::NonFinite));
            } else {
                assert_eq!(r, Ok(()));
            }
            let k = usize::from(b.u16());
            let r = metrics::uniform_circle_coefficient(n, k, a);
            if k == 0 {
                assert_eq!(r, Err(Error::InvalidSize));
            } else if !a.is_finite() {
                assert_eq!(r, Err(Error::NonFinite));
            } else {
                // Any n and finite a, however large n·a (defect 11: NaN once n·a overflowed).
                let c = r.unwrap();
                assert!(
                    c.is_finite() && c.abs() <= 1.0 + 1e-9,
                    "uniform_circle_coefficient({n}, {k}, {a}) = {c}"
                );
            }
        }
    }
});
