//! Probe updates and queries on arbitrary f32 bits (`probe` module docs, "Bad input" and
//! "Radiance scale"): nothing panics; every error is the documented one for the first bad
//! argument; an update or rotation that fails leaves the probe exactly as it was; before the
//! first update every query is zero; after an update no value or variance is NaN, variances
//! are non-negative, and for moderate samples (|y| ≤ 10¹⁵) and amplitudes (|a| ≤ 10³) every
//! answer is finite.
#![no_main]

use core::fmt::Debug;

use fuzz_support::{direction_rejected, Bytes};
use libfuzzer_sys::fuzz_target;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::footprint::{CosinePower, Footprint, Gaussian, Point};
use sphere_quadrature::probe::{Probe, ProbeTables, Selection, MAX_GLOSSY_SHARPNESS};
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::{Error, Mat3, Radiance, Vec3};

/// A sample value from the reader.
trait Sample: Radiance + Debug {
    fn read(b: &mut Bytes) -> Self;
}

impl Sample for f32 {
    fn read(b: &mut Bytes) -> Self {
        b.f32()
    }
}

impl Sample for [f32; 3] {
    fn read(b: &mut Bytes) -> Self {
        [b.f32(), b.f32(), b.f32()]
    }
}

fn channels<T: Radiance>(t: T) -> impl Iterator<Item = f32> {
    (0..T::CHANNELS).map(move |c| t.channel(c))
}

fn all_finite<T: Radiance>(t: T) -> bool {
    channels(t).all(f32::is_finite)
}

/// What the samples of the last successful update were like.
#[derive(Clone, Copy, PartialEq, Eq)]
enum State {
    /// No update yet: every query is zero.
    Empty,
    /// Samples of any finite size: no NaN, variances ≥ 0.
    Any,
    /// Every valid sample within ±10¹⁵: every answer finite too.
    Moderate,
}

/// Checks a query result against the documented errors: `checks` in order (the first failing
/// one decides the error), `None` where the argument may go either way.
fn check_errors<R: Debug>(what: &str, r: &Result<R, Error>, checks: &[(Option<bool>, Error)]) {
    for &(bad, err) in checks {
        match bad {
            Some(true) => {
                assert_eq!(r.as_ref().err(), Some(&err), "{what}: expected {err:?}, got {r:?}");
                return;
            }
            Some(false) => {}
            None => {
                // Either way is allowed for this argument; a later one must not be blamed.
                if let Err(e) = r {
                    assert!(
                        *e == err || checks.iter().any(|&(b, e2)| b != Some(false) && e2 == *e),
                        "{what}: unexpected {e:?}"
                    );
                }
                return;
            }
        }
    }
    assert!(r.is_ok(), "{what}: valid arguments gave {r:?}");
}

fn check_value<T: Radiance + Debug>(what: &str, v: T, state: State, bounded: bool) {
    match state {
        State::Empty => assert!(channels(v).all(|x| x == 0.0), "{what}: {v:?} before any update"),
        State::Any | State::Moderate => {
            assert!(channels(v).all(|x| !x.is_nan()), "{what}: NaN {v:?}");
            if state == State::Moderate && bounded {
                assert!(all_finite(v), "{what}: {v:?} not finite for moderate samples");
            }
        }
    }
}

fn check_variance<T: Radiance + Debug>(what: &str, v: T, state: State, bounded: bool) {
    check_value(what, v, state, bounded);
    assert!(channels(v).all(|x| x >= 0.0), "{what}: negative or NaN variance {v:?}");
}

/// A rotation matrix: a proper one from a quaternion of moderate size, or arbitrary rows.
fn matrix(b: &mut Bytes) -> (Mat3, bool) {
    if b.bool() {
        let q = [b.u16(), b.u16(), b.u16(), b.u16()].map(|x| f32::from(x) - 32767.5);
        (Mat3::from_quaternion(q), true)
    } else {
        (Mat3::from_rows(b.vec3(), b.vec3(), b.vec3()), false)
    }
}

/// Whether `m` is clearly not finite-and-orthonormal-to-10⁻³ (`Probe::set_rotation`).
fn clearly_not_rotation(m: &Mat3) -> bool {
    let r = m.rows;
    if r.iter().any(|v| fuzz_support::non_finite(*v)) {
        return true;
    }
    (0..3).any(|i| {
        (0..3).any(|j| {
            let want = if i == j { 1.0 } else { 0.0 };
            let (a, c) = (fuzz_support::to64(r[i]), fuzz_support::to64(r[j]));
            let dot = a[0] * c[0] + a[1] * c[1] + a[2] * c[2];
            (dot - want).abs() > 1.1e-3
        })
    })
}

fn run<T: Sample, F: Footprint, const N: usize, const M: usize>(b: &mut Bytes)
where
    Size<N>: ProbeTables<F>,
{
    let mut probe = Probe::<N, T, F, M>::new();
    let members = Probe::<N, T, F, M>::family().len();
    let mut state = State::Empty;
    for _ in 0..16 {
        if b.is_empty() {
            break;
        }
        let before = format!("{probe:?}");
        match b.u8() % 12 {
            0 => {
                let (m, proper) = matrix(b);
                let r = probe.set_rotation(m);
                if proper {
                    assert_eq!(r, Ok(()), "set_rotation of a proper rotation {m:?}");
                } else if clearly_not_rotation(&m) {
                    assert_eq!(r, Err(Error::InvalidRotation), "set_rotation({m:?})");
                }
                match r {
                    Ok(()) => {
                        state = State::Empty;
                        for d in probe.directions() {
                            let l = d.length();
                            assert!((l - 1.0).abs() <= 3e-3, "direction {d:?} after {m:?}");
                        }
                    }
                    Err(_) => {
                        assert_eq!(before, format!("{probe:?}"), "rotation error changed the probe")
                    }
                }
            }
            op @ 1..=3 => {
                let samples: [T; N] = core::array::from_fn(|_| T::read(b));
                let selection = if op == 3 {
                    Selection::Member(usize::from(b.u8() % 8))
                } else {
                    Selection::MaxLikelihood
                };
                let r = probe.update_with(&samples, selection);
                let finite = samples.iter().all(|&y| all_finite(y));
                let expected = if !finite {
                    Err(Error::InvalidRadiance)
                } else if matches!(selection, Selection::Member(k) if k >= members) {
                    Err(Error::InvalidMember)
                } else {
                    Ok(())
                };
                assert_eq!(r, expected, "update_with({samples:?}, {selection:?})");
                if r.is_ok() {
                    let moderate = samples.iter().all(|&y| channels(y).all(|x| x.abs() <= 1e15));
                    state = if moderate { State::Moderate } else { State::Any };
                    assert!(probe.missing().is_empty());
                    assert!(!probe.log_likelihood().is_nan(), "ℓ NaN for {samples:?}");
                    assert!(probe.selected() < members);
                    if let Selection::Member(k) = selection {
                        assert_eq!(probe.selected(), k);
                    }
                } else {
                    assert_eq!(before, format!("{probe:?}"), "failed update changed the probe");
                }
            }
            4 => {
                let samples: [T; N] = core::array::from_fn(|_| T::read(b));
                // Few missing samples most of the time, any mask sometimes.
                let dense = b.u8() % 4 == 0;
                let valid: [bool; N] =
                    core::array::from_fn(|_| if dense { b.bool() } else { b.u8() % 8 != 0 });
                let r = probe.update_masked(&samples, &valid);
                let missing = valid.iter().filter(|&&v| !v).count();
                let finite = samples.iter().zip(&valid).all(|(&y, &ok)| !ok || all_finite(y));
                let expected = if missing == 0 {
                    if finite {
                        Ok(())
                    } else {
                        Err(Error::InvalidRadiance)
                    }
                } else if missing > M || N - missing < 2 {
                    Err(Error::TooManyMissing)
                } else if !finite {
                    Err(Error::InvalidRadiance)
                } else {
                    Ok(())
                };
                match (expected, r) {
                    // "never seen with the baked families": a singular missing block.
                    (Ok(()), Err(Error::TooManyMissing)) => {
                        panic!(
                            "TooManyMissing for {missing} ≤ M = {M} missing: {samples:?} {valid:?}"
                        )
                    }
                    _ => assert_eq!(r, expected, "update_masked({samples:?}, {valid:?})"),
                }
                if r.is_ok() {
                    let moderate = samples
                        .iter()
                        .zip(&valid)
                        .all(|(&y, &ok)| !ok || channels(y).all(|x| x.abs() <= 1e15));
                    state = if moderate { State::Moderate } else { State::Any };
                    assert_eq!(probe.missing().len(), missing);
                    for &i in probe.missing() {
                        assert!(!valid[usize::from(i)], "index {i} reported missing but valid");
                    }
                } else {
                    assert_eq!(
                        before,
                        format!("{probe:?}"),
                        "failed masked update changed the probe"
                    );
                }
            }
            5 => {
                let n = b.vec3();
                let r = probe.irradiance(n);
                check_errors("irradiance", &r, &[(direction_rejected(n), Error::InvalidDirection)]);
                if let Ok(e) = r {
                    check_value("irradiance value", e.value, state, true);
                    check_variance("irradiance variance", e.variance, state, true);
                    assert!(e.unit_variance.is_some_and(|u| u >= 0.0 && u.is_finite()));
                }
                let r = probe.irradiance_variance(n);
                check_errors(
                    "irradiance_variance",
                    &r,
                    &[(direction_rejected(n), Error::InvalidDirection)],
                );
                if let Ok(v) = r {
                    check_variance("irradiance_variance", v, state, true);
                }
            }
            op @ (6 | 7) => {
                let axis = b.vec3();
                let sharpness = b.f32();
                let amplitude = b.f32();
                let lobe = SphericalGaussian { axis, sharpness, amplitude };
                let bad_sharpness = !(sharpness >= 0.0
                    && sharpness.is_finite()
                    && sharpness <= MAX_GLOSSY_SHARPNESS);
                let checks = [
                    (direction_rejected(axis), Error::InvalidDirection),
                    (Some(bad_sharpness), Error::InvalidSharpness),
                    (Some(!amplitude.is_finite()), Error::InvalidWeights),
                ];
                let bounded = amplitude.abs() <= 1e3;
                if op == 6 {
                    let r = probe.glossy(&lobe);
                    check_errors("glossy", &r, &checks);
                    if let Ok(e) = r {
                        check_value("glossy value", e.value, state, bounded);
                        check_variance("glossy variance", e.variance, state, bounded);
                        assert!(e.unit_variance.is_some_and(|u| u >= 0.0));
                    }
                } else {
                    let r = probe.glossy_variance(&lobe);
                    check_errors("glossy_variance", &r, &checks);
                    if let Ok(v) = r {
                        check_variance("glossy_variance", v, state, bounded);
                    }
                }
            }
            8 => {
                let axis = b.vec3();
                let e = b.f32();
                let bad = !(e >= 0.0 && e.is_finite() && e <= MAX_GLOSSY_SHARPNESS);
                let checks = [
                    (direction_rejected(axis), Error::InvalidDirection),
                    (Some(bad), Error::InvalidExponent),
                ];
                // The O(N·L) series grows with √λ only, but keep exponents moderate on most
                // inputs so that the target stays fast.
                let r = probe.phong(axis, e);
                check_errors("phong", &r, &checks);
                if let Ok(est) = r {
                    check_value("phong value", est.value, state, true);
                    check_variance("phong variance", est.variance, state, true);
                }
                let r = probe.phong_variance(axis, e);
                check_errors("phong_variance", &r, &checks);
                if let Ok(v) = r {
                    check_variance("phong_variance", v, state, true);
                }
            }
            9 => {
                let (a, c) = (usize::from(b.u8() % 5), usize::from(b.u8() % 5));
                let r = probe.signal_covariance(a, c);
                if a >= T::CHANNELS || c >= T::CHANNELS {
                    assert_eq!(r, Err(Error::InvalidChannel), "signal_covariance({a}, {c})");
                } else {
                    let s = r.expect("channels in range");
                    assert!(!s.is_nan(), "signal_covariance({a}, {c}) NaN");
                    if a == c {
                        assert!(s >= 0.0);
                        assert_eq!(s.to_bits(), probe.signal_variance().channel(a).to_bits());
                    }
                    if state == State::Empty {
                        assert_eq!(s, 0.0);
                    }
                }
                let w = T::read(b);
                let v = probe.signal_variance_of(w);
                if all_finite(w) {
                    let v = v.expect("finite weights");
                    assert!(!v.is_nan() && v >= 0.0, "signal_variance_of({w:?}) = {v}");
                } else {
                    assert_eq!(v, Err(Error::InvalidWeights));
                }
                if let Ok(e) = probe.irradiance(Vec3::Z) {
                    let c = probe.combine(&e, w);
                    if !all_finite(w) {
                        assert_eq!(c, Err(Error::InvalidWeights));
                    } else {
                        let c = c.expect("finite weights");
                        assert!(
                            !c.variance.is_nan() && c.variance >= 0.0,
                            "combine variance {c:?}"
                        );
                        assert_eq!(
                            c.unit_variance.map(f32::to_bits),
                            e.unit_variance.map(f32::to_bits)
                        );
                    }
                }
            }
            _ => {
                let sh = probe.radiance_sh();
                for c in sh.coefficients {
                    check_value("radiance_sh", c, state, true);
                }
                for v in probe.radiance_sh_variance() {
                    check_variance("radiance_sh_variance", v, state, true);
                }
                check_variance("signal_variance", probe.signal_variance(), state, true);
                check_value("mean_irradiance", probe.mean_irradiance(), state, true);
            }
        }
        // Queries never change the probe.
        if !matches!(b.u8() % 4, 0) {
            continue;
        }
        let now = format!("{probe:?}");
        let _ = probe.irradiance(Vec3::Z);
        let _ = probe.irradiance_variance(Vec3::X);
        assert_eq!(now, format!("{probe:?}"));
    }
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes::new(data);
    match b.u8() % 7 {
        0 => run::<f32, Point, 16, 0>(&mut b),
        1 => run::<[f32; 3], Point, 16, 0>(&mut b),
        2 => run::<f32, Point, 16, 6>(&mut b),
        3 => run::<[f32; 3], Point, 32, 4>(&mut b),
        4 => run::<f32, Gaussian<2>, 16, 3>(&mut b),
        5 => run::<f32, CosinePower<1>, 16, 2>(&mut b),
        _ => run::<f32, Point, 64, 0>(&mut b),
    }
});
