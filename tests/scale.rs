//! Radiance scale (issue #13, item 3): the QMC estimators give `c` times the estimate for
//! radiance `c·L`, `c` from 10⁻³⁰ to 10³⁰, and `±∞` (never 0 or NaN) where the result itself
//! exceeds `f32::MAX`.

use reference::analytic::SgLight;
use reference::rng::Rng;
use sphere_quadrature::qmc::{self, LobeSampler};
use sphere_quadrature::{Lobe, Vec3};

/// The scales, and powers of two (exact scalings: the normalised samples, hence every
/// intermediate, are then the same bits as at `c = 1`).
fn scales() -> Vec<f64> {
    let mut c = vec![1e-30, 1e-20, 1e-10, 1e-3, 1.0, 1e3, 1e10, 1e20, 1e30];
    c.extend([-100, -60, -1, 1, 60, 100].map(|k| 2f64.powi(k)));
    c
}

const MAX: f64 = f32::MAX as f64;
const TINY: f64 = f32::MIN_POSITIVE as f64;

/// `got` against `want` (an f64 target): within `tol` relative where `want` is a normal f32
/// number (with a margin of `tol` at both ends of the range), exactly `±∞` above `f32::MAX`,
/// 0 or subnormal (same sign) below the normal range.
fn check(got: f32, want: f64, tol: f64, what: &str) -> f64 {
    assert!(!got.is_nan(), "{what}: NaN (want {want:e})");
    let mag = want.abs();
    if mag > MAX * (1.0 + tol) {
        assert_eq!(got, f32::INFINITY.copysign(want as f32), "{what}: want {want:e}");
        0.0
    } else if mag < TINY * (1.0 - tol) {
        assert!(
            got.abs() <= f32::MIN_POSITIVE && (got == 0.0 || got.signum() as f64 == want.signum()),
            "{what}: {got:e}, want {want:e} (below the normal range)"
        );
        0.0
    } else if mag < MAX * (1.0 - tol) && mag > TINY * (1.0 + tol) {
        let rel = (got as f64 - want).abs() / mag;
        assert!(rel <= tol, "{what}: {got:e}, want {want:e} (relative {rel:e})");
        rel
    } else {
        0.0
    }
}

fn lights(seed: u64) -> Vec<SgLight> {
    let mut rng = Rng::new(seed);
    (0..3)
        .map(|_| SgLight {
            axis: rng.uniform_sphere(),
            sharpness: 2.0 + 18.0 * rng.next_f64(),
            amplitude: 0.2 + 0.8 * rng.next_f64(),
        })
        .collect()
}

fn field(lights: &[SgLight], d: Vec3) -> f32 {
    (0.3 + lights.iter().map(|l| l.value([d.x as f64, d.y as f64, d.z as f64])).sum::<f64>()) as f32
}

/// QMC estimators: a constant `10³⁷` (whose plain sum overflows) gives `π·10³⁷` irradiance and
/// `10³⁷` Phong radiance; a constant past `f32::MAX/π` gives `+∞` irradiance but finite
/// Phong radiance; and `c·f` gives `c` times the estimate of `f` (exactly for powers of two,
/// where the plain sum is the same bits; within 10⁻⁵ else: per-sample rounding of `c·f`, a
/// sum of positive terms).
#[test]
fn qmc_estimators_work_at_any_scale() {
    let pi = core::f64::consts::PI;
    let n = Vec3::new(0.3, -0.4, 0.5);
    // A recursive sum of N equal terms is within (N − 1)·2⁻²⁴ relative, the weight and the
    // product within 2⁻²³ more.
    let bar = |n: usize| (n as f64 - 1.0) * 2f64.powi(-24) + 2f64.powi(-23);
    for y in [1e37f32, 1e38, 3e38, f32::MAX, -f32::MAX] {
        let e = qmc::irradiance::<64, [f32; 2], _>(n, 7, |_| [y, 1.0]).unwrap();
        check(e[0], pi * f64::from(y), bar(64), &format!("irradiance of {y:e}"));
        check(e[1], pi, bar(64), "irradiance of 1 beside a huge channel");
        let p = qmc::phong::<256, f32, _>(n, 20.0, 7, |_| y).unwrap();
        check(p, f64::from(y), bar(256), &format!("phong of {y:e}"));
        let s = LobeSampler::new(n, Lobe::Cosine, 100, 3).unwrap();
        check(s.estimate(&[y; 100]).unwrap(), pi * f64::from(y), bar(100), "estimate");
    }
    // NaN still propagates through the second sum.
    assert!(qmc::irradiance::<16, f32, _>(n, 0, |_| f32::NAN).unwrap().is_nan());
    let s = LobeSampler::new(n, Lobe::Phong(5.0), 16, 3).unwrap();
    let mut ys = [1e38f32; 16];
    ys[3] = f32::NAN;
    assert!(s.estimate(&ys).unwrap().is_nan());

    let l = lights(8);
    let f = |d: Vec3| field(&l, d);
    let e1 = qmc::irradiance::<64, f32, _>(n, 11, f).unwrap();
    let p1 = qmc::phong::<64, f32, _>(n, 30.0, 11, f).unwrap();
    let s = LobeSampler::new(n, Lobe::Cosine, 64, 11).unwrap();
    let ys: Vec<f32> = s.iter().map(f).collect();
    let q1 = s.estimate(&ys).unwrap();
    for c in scales() {
        let c32 = c as f32;
        let tol = if c == 2f64.powi(c.log2().round() as i32) { 0.0 } else { 1e-5 };
        let e = qmc::irradiance::<64, f32, _>(n, 11, |d| c32 * f(d)).unwrap();
        check(e, f64::from(c32) * f64::from(e1), tol, &format!("irradiance, c = {c:e}"));
        let p = qmc::phong::<64, f32, _>(n, 30.0, 11, |d| c32 * f(d)).unwrap();
        check(p, f64::from(c32) * f64::from(p1), tol, &format!("phong, c = {c:e}"));
        let scaled: Vec<f32> = ys.iter().map(|y| c32 * y).collect();
        let q = s.estimate(&scaled).unwrap();
        check(q, f64::from(c32) * f64::from(q1), tol, &format!("estimate, c = {c:e}"));
    }
}
