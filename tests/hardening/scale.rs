//! Radiance scale (issue #13, item 3): the probe and the QMC estimators give `c` times the
//! value and `c²` times the variance for samples `c·Y`, `c` from 10⁻³⁰ to 10³⁰, and `±∞`
//! (never 0 or NaN) where the result itself exceeds `f32::MAX`; and the probe's channel
//! covariance (item 2) against an independent f64 computation.

use reference::analytic::SgLight;
use reference::rng::Rng;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::footprint::{CosinePower, Footprint, Gaussian, Point};
use sphere_quadrature::probe::{Probe, ProbeTables, Selection};
use sphere_quadrature::qmc::{self, LobeSampler};
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::{Error, Lobe, Radiance, Vec3};

/// The scales, and powers of two (exact scalings: the normalised samples, hence every
/// intermediate, are then the same bits as at `c = 1`).
fn scales() -> Vec<f64> {
    let mut c = vec![1e-30, 1e-20, 1e-10, 1e-3, 1.0, 1e3, 1e10, 1e20, 1e30];
    c.extend([-100, -60, -1, 1, 60, 100].map(|k| 2f64.powi(k)));
    c
}

const VALUE_TOLERANCE: f64 = 1e-4;
const VARIANCE_TOLERANCE: f64 = 1e-3;
const MAX: f64 = f32::MAX as f64;
const TINY: f64 = f32::MIN_POSITIVE as f64;

/// `got` against `want` (an f64 target): within `tol` relative where `want` is a normal f32
/// number (with a margin of `tol` at both ends of the range), exactly `±∞` above `f32::MAX`,
/// 0 or subnormal (same sign) below the normal range.
fn check(got: f32, want: f64, tol: f64, what: &str) -> f64 {
    check_norm(got, want, want.abs(), tol, what)
}

/// [`check`] with the error measured relative to `norm ≥ |want|` (the size of the vector
/// `want` belongs to, for a spherical-harmonic coefficient).
fn check_norm(got: f32, want: f64, norm: f64, tol: f64, what: &str) -> f64 {
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
        let rel = (got as f64 - want).abs() / norm.max(mag);
        assert!(rel <= tol, "{what}: {got:e}, want {want:e} (relative {rel:e})");
        rel
    } else {
        0.0
    }
}

/// Every query of a probe, channel by channel: values (which scale by `c·a`) and variances
/// (by `c²a²`), with the lobe amplitude multiplied by `amp`. `norms[i]` is the size
/// `values[i]` is measured against: `|values[i]|`, or for a spherical-harmonic coefficient
/// the sum of its channel's `|c_lm|` (a coefficient near zero is as accurate as the others
/// in absolute terms, not relative to itself).
#[derive(Debug)]
struct Answers {
    values: Vec<(String, f64)>,
    variances: Vec<(String, f64)>,
    norms: Vec<f64>,
}

fn channels<T: Radiance>(x: T) -> Vec<f64> {
    (0..T::CHANNELS).map(|c| x.channel(c) as f64).collect()
}

fn answers<const N: usize, T: Radiance, F: Footprint>(p: &Probe<N, T, F>, amp: f32) -> Answers
where
    Size<N>: ProbeTables<F>,
{
    let mut a = Answers { values: Vec::new(), variances: Vec::new(), norms: Vec::new() };
    let mut push = |values: bool, name: String, x: T| {
        for (c, v) in channels(x).into_iter().enumerate() {
            if values {
                a.values.push((format!("{name} ch{c}"), v));
                a.norms.push(v.abs());
            } else {
                a.variances.push((format!("{name} ch{c}"), v));
            }
        }
    };
    for n in [Vec3::Z, Vec3::new(0.3, -0.4, 0.5), Vec3::new(-0.8, 0.1, -0.2)] {
        let e = p.irradiance(n).unwrap();
        push(true, format!("irradiance {n:?}"), e.value);
        push(false, format!("irradiance variance {n:?}"), e.variance);
        push(false, format!("irradiance_variance {n:?}"), p.irradiance_variance(n).unwrap());
    }
    for (axis, e) in [(Vec3::new(0.6, 0.0, 0.8), 20.0), (Vec3::new(-0.2, 0.9, 0.1), 3.0)] {
        let lobe = SphericalGaussian::phong_moments(axis, e).unwrap();
        let lobe = SphericalGaussian { amplitude: lobe.amplitude * amp, ..lobe };
        let g = p.glossy(&lobe).unwrap();
        push(true, format!("glossy e = {e}"), g.value);
        push(false, format!("glossy variance e = {e}"), g.variance);
        push(false, format!("glossy_variance e = {e}"), p.glossy_variance(&lobe).unwrap());
        let ph = p.phong(axis, e).unwrap();
        push(true, format!("phong e = {e}"), ph.value);
        push(false, format!("phong variance e = {e}"), ph.variance);
        push(false, format!("phong_variance e = {e}"), p.phong_variance(axis, e).unwrap());
    }
    push(true, "mean_irradiance".into(), p.mean_irradiance());
    push(false, "signal_variance".into(), p.signal_variance());
    // The SH export (issue #14): coefficients, measured against their channel's Σ|c|, and
    // their variances.
    let sh = p.radiance_sh().coefficients;
    for (k, (&c, &v)) in sh.iter().zip(&p.radiance_sh_variance()).enumerate() {
        push(true, format!("radiance_sh {k}"), c);
        push(false, format!("radiance_sh_variance {k}"), v);
    }
    let start = a.norms.len() - 9 * T::CHANNELS;
    for ch in 0..T::CHANNELS {
        let sum: f64 = sh.iter().map(|c| f64::from(c.channel(ch)).abs()).sum();
        for k in 0..9 {
            a.norms[start + k * T::CHANNELS + ch] = sum;
        }
    }
    a
}

/// `scaled` against `c·base` (values; phong has no amplitude) and `c²·base` (variances), each
/// within its tolerance (`tolerance.values[i]`, `tolerance.variances[i]`).
fn compare(base: &Answers, scaled: &Answers, c: f64, amp: f64, tol: &Answers, what: &str) -> f64 {
    let mut worst = 0.0f64;
    let norms = base.norms.iter().map(Some).chain(std::iter::repeat(None));
    let pairs = base.values.iter().zip(&scaled.values).zip(&tol.values).map(|p| (p, true));
    let var_pairs =
        base.variances.iter().zip(&scaled.variances).zip(&tol.variances).map(|p| (p, false));
    for (((((name, b), (_, s)), (_, t)), is_value), norm) in pairs.chain(var_pairs).zip(norms) {
        let a = if name.starts_with("glossy") { amp } else { 1.0 };
        let want = if is_value { c * a * b } else { c * c * a * a * b };
        if !is_value && *b == 0.0 {
            assert_eq!(*s, 0.0, "{what}: {name}");
            continue;
        }
        let norm = norm.map_or(want.abs(), |n| (c * a).abs() * n);
        let rel = check_norm(*s as f32, want, norm, *t, &format!("{what}: {name}"));
        if *t > 0.0 {
            worst = worst.max(rel / t);
        }
    }
    worst
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

/// Every answer with the same tolerance.
fn uniform(like: &Answers, value: f64, variance: f64) -> Answers {
    Answers {
        values: like.values.iter().map(|(n, _)| (n.clone(), value)).collect(),
        variances: like.variances.iter().map(|(n, _)| (n.clone(), variance)).collect(),
        norms: Vec::new(),
    }
}

/// For every member and every scale `c`, every query of the probe of `Y_c = fl(c·Y)`:
/// - exactly `2^k` (`4^k`) times the answer for `Y_c·2^−k`, `2^k ≤ c < 2^(k+1)`, wherever
///   that is a normal f32 number, `±∞` above and 0 or subnormal below: the normalised
///   samples are then the same bits, so this checks the scaling itself, with no rounding
///   allowance, from 10⁻³⁰ to 10³⁰;
/// - within 10⁻⁴ (values) and 10⁻³ (variances) of `c` (`c²`) times the `c = 1` answer, the
///   issue's target. By the first check this compares the probe of `Y` with that of
///   `m·Y`, `m = c/2^k ∈ [1, 2)`: two f32 inputs that differ by rounding, which the BMC weights
///   of the smoothest members amplify like any f32 perturbation of the samples (one ulp moves
///   an answer of the Gaussian-footprint member of `cond(Q)` 2.8·10⁵ by 6·10⁻⁴). As in
///   `tests/probe/probe.rs`, members with `cond(Q)` above 10⁴ are held to the forward bound
///   `cond(Q)·ε₃₂` for values instead; the worst deviation is printed.
///
/// `Selection::Member`: with a `c` that is not a power of two, `c·Y` rounds differently from
/// `Y`, which can flip a near tie of two members' likelihoods, and the answers would then
/// differ by the member, not by the scale.
fn scale_invariance<const N: usize, T: Radiance, F: Footprint>(
    make: impl Fn(Vec3) -> T,
    label: &str,
) where
    Size<N>: ProbeTables<F>,
{
    let mut probe = Probe::<N, T, F>::new();
    let samples: [T; N] = probe.directions().map(&make);
    let mut worst = Vec::new();
    for (k, member) in Probe::<N, T, F>::family().enumerate() {
        probe.update_with(&samples, Selection::Member(k)).unwrap();
        let base = answers(&probe, 1.0);
        let cond = f64::from(member.condition);
        let value_bar = if cond <= 1e4 { VALUE_TOLERANCE } else { cond * f64::from(f32::EPSILON) };
        let target = uniform(&base, value_bar, VARIANCE_TOLERANCE);
        let exact = uniform(&base, 0.0, 0.0);
        let mut member_worst = (0.0f64, 0.0f64);
        for c in scales() {
            let c32 = c as f32;
            let scaled = samples.map(|y| y.scale(c32));
            let what = format!("{label} member {k}, c = {c:e}");
            probe.update_with(&scaled, Selection::Member(k)).unwrap();
            let got = answers(&probe, 1.0);
            // The exact check.
            let shift = c.log2().floor() as i32;
            let unit = 2f32.powi(shift);
            let reduced = scaled.map(|y| y.scale(1.0 / unit));
            probe.update_with(&reduced, Selection::Member(k)).unwrap();
            let at_one = answers(&probe, 1.0);
            compare(&at_one, &got, f64::from(unit), 1.0, &exact, &format!("{what} (exact)"));
            // The target.
            let ratio = compare(&base, &got, f64::from(c32), 1.0, &target, &what);
            let rel = ratio * value_bar;
            member_worst.0 = member_worst.0.max(rel);
            member_worst.1 = member_worst.1.max(ratio);
        }
        worst.push(format!(
            "member {k} (cond {cond:.1e}): {:.1e} of bar {value_bar:.0e}",
            member_worst.0
        ));
    }
    println!("{label}: worst relative deviation from c × (c = 1): {}", worst.join("; "));
}

#[test]
fn point_probes_are_scale_invariant() {
    let l = lights(1);
    let rgb = [lights(2), lights(3)];
    let colour = |d: Vec3| [field(&l, d), 0.5 * field(&rgb[0], d), 1e-3 * field(&rgb[1], d)];
    scale_invariance::<16, f32, Point>(|d| field(&l, d), "N = 16 f32");
    scale_invariance::<64, f32, Point>(|d| field(&l, d), "N = 64 f32");
    scale_invariance::<16, [f32; 3], Point>(colour, "N = 16 RGB");
    scale_invariance::<64, [f32; 3], Point>(colour, "N = 64 RGB");
}

#[test]
fn footprint_probes_are_scale_invariant() {
    let l = lights(4);
    // Footprint samples of a smooth field: the field itself stands in (scale invariance does
    // not depend on what the samples are).
    scale_invariance::<64, f32, Gaussian<8>>(|d| field(&l, d), "N = 64 Gaussian<8>");
    scale_invariance::<16, [f32; 3], CosinePower<1>>(
        |d| [field(&l, d), 2.0 * field(&l, -d), 0.25],
        "N = 16 photodiode RGB",
    );
}

/// [`Probe::update`] on data whose likelihood has a clear winner (a margin of more than one
/// nat, checked): the same member at every scale, the answers as above, and the log
/// likelihood shifted by `−(N − 1)·C·ln c` (`ℓ` of `c·Y` is that of `Y` less the Jacobian).
#[test]
fn selection_and_likelihood_follow_the_scale() {
    let l = lights(9);
    let mut probe = Probe::<64, [f32; 3]>::new();
    let samples: [[f32; 3]; 64] =
        probe.directions().map(|d| [field(&l, d), 0.7 * field(&l, d), 0.2 + 0.1 * d.z]);
    let mut lls: Vec<f32> = (0..Probe::<64>::family().len())
        .map(|k| {
            probe.update_with(&samples, Selection::Member(k)).unwrap();
            probe.log_likelihood()
        })
        .collect();
    probe.update(&samples).unwrap();
    let (best, ll1) = (probe.selected(), probe.log_likelihood());
    lls.sort_by(|a, b| b.total_cmp(a));
    assert!(lls[0] - lls[1] > 1.0, "no clear winner: {lls:?}");
    let base = answers(&probe, 1.0);
    let cond = f64::from(Probe::<64>::member(best).unwrap().condition);
    let bar = if cond <= 1e4 { VALUE_TOLERANCE } else { cond * f64::from(f32::EPSILON) };
    let tol = uniform(&base, bar, VARIANCE_TOLERANCE);
    for c in scales() {
        let c32 = c as f32;
        probe.update(&samples.map(|y| y.scale(c32))).unwrap();
        assert_eq!(probe.selected(), best, "c = {c:e}");
        compare(&base, &answers(&probe, 1.0), f64::from(c32), 1.0, &tol, &format!("c = {c:e}"));
        let want = f64::from(ll1) - 63.0 * 3.0 * f64::from(c32).ln();
        let got = f64::from(probe.log_likelihood());
        assert!((got - want).abs() <= 1e-5 * want.abs().max(100.0), "c = {c:e}: ℓ {got} vs {want}");
    }
}

/// Glossy lobe amplitudes of 10²⁰ and 10⁻²⁰, alone and against samples scaled the other way
/// (`a·c = 1`: the variance fits though `a²` and `c²` alone do not).
#[test]
fn lobe_amplitudes_scale_the_glossy_answers() {
    let l = lights(5);
    for_three_probes(&l, |label, base_of, answers_of| {
        let base = base_of();
        for (amp, c) in
            [(1e20f32, 1.0f32), (1e-20, 1.0), (1e20, 1e-20), (1e-20, 1e20), (1e30, 1e-30)]
        {
            let got = answers_of(amp, c);
            let what = format!("{label}: amplitude {amp:e}, c = {c:e}");
            let tol = uniform(&base, VALUE_TOLERANCE, VARIANCE_TOLERANCE);
            compare(&base, &got, f64::from(c), f64::from(amp), &tol, &what);
            // Finite where it fits: the a = 10²⁰ values are ~10²⁰.
            for (name, v) in got.values.iter().filter(|(n, _)| n.starts_with("glossy")) {
                assert!(v.is_finite() && *v != 0.0, "{what}: {name} = {v:e}");
            }
        }
    });
}

/// Runs `f` on a point, a Gaussian-footprint and a photodiode probe (member 0, the smoothest,
/// is avoided for the Gaussian footprint: see [`scale_invariance`]), with closures giving the
/// `c = 1`, unit-amplitude answers and the answers for amplitude `a` on samples `c·Y`.
fn for_three_probes(
    l: &[SgLight],
    f: impl Fn(&str, &dyn Fn() -> Answers, &dyn Fn(f32, f32) -> Answers),
) {
    macro_rules! run {
        ($label:expr, $n:literal, $t:ty, $fp:ty, $k:expr, $make:expr) => {{
            let mut probe = Probe::<$n, $t, $fp>::new();
            let samples: [$t; $n] = probe.directions().map($make);
            probe.update_with(&samples, Selection::Member($k)).unwrap();
            let base = answers(&probe, 1.0);
            let probe = std::cell::RefCell::new(probe);
            f($label, &|| base.clone_answers(), &|a, c| {
                let mut p = probe.borrow_mut();
                p.update_with(&samples.map(|y| y.scale(c)), Selection::Member($k)).unwrap();
                answers(&p, a)
            });
        }};
    }
    run!("N = 64 RGB point", 64, [f32; 3], Point, 1, |d| [field(l, d), 0.5 * field(l, -d), 0.3]);
    run!("N = 64 Gaussian<8>", 64, f32, Gaussian<8>, 3, |d| field(l, d));
    run!("N = 16 photodiode", 16, f32, CosinePower<1>, 1, |d| field(l, d));
}

impl Answers {
    fn clone_answers(&self) -> Answers {
        Answers {
            values: self.values.clone(),
            variances: self.variances.clone(),
            norms: self.norms.clone(),
        }
    }
}

/// Results beyond `f32::MAX` are `±∞`, never 0 or NaN; constant samples keep `α = 0` and
/// zero variance at any scale; samples near `±f32::MAX` (whose differences overflow) give
/// `2¹⁰⁰` times the answers for the samples scaled by `2⁻¹⁰⁰`.
#[test]
fn overflowing_results_are_infinite() {
    let mut probe = Probe::<32, [f32; 3]>::new();
    let pi = core::f32::consts::PI;
    // Constants: exact values (π·c overflows for c above f32::MAX/π), zero variance.
    for c in [0.0f32, 1e-38, 1e-30, 1e30, 1e37, 1e38, 2e38, f32::MAX, -f32::MAX] {
        probe.update(&[[c, -c, 0.5 * c]; 32]).unwrap();
        // The SH export: c₀₀ = √(4π)·c (+∞ past f32::MAX/√(4π)), the rest exactly 0, zero
        // variances.
        let sh = probe.radiance_sh().coefficients;
        for (ch, y) in [c, -c, 0.5 * c].into_iter().enumerate() {
            let want = (4.0 * core::f64::consts::PI).sqrt() * f64::from(y);
            check(sh[0][ch], want, 1e-6, &format!("c₀₀ of {y:e}"));
            assert!(sh[1..].iter().all(|v| v[ch] == 0.0), "{sh:?}");
            assert!(probe.radiance_sh_variance().iter().all(|v| v[ch] == 0.0));
        }
        for n in [Vec3::Z, Vec3::new(0.2, 0.9, -0.3)] {
            let e = probe.irradiance(n).unwrap();
            for (ch, y) in [c, -c, 0.5 * c].into_iter().enumerate() {
                check(e.value[ch], f64::from(pi) * f64::from(y), 1e-6, &format!("E of {y:e}"));
                assert_eq!(e.variance[ch], 0.0);
                assert_eq!(probe.irradiance_variance(n).unwrap()[ch], 0.0);
                assert_eq!(probe.signal_covariance(ch, ch), Ok(0.0));
            }
            // The normalised Phong lobe and a unit-integral SG average the radiance: they
            // fit where π·c does not.
            let ph = probe.phong(n, 10.0).unwrap();
            let g = probe.glossy(&SphericalGaussian::phong_moments(n, 10.0).unwrap()).unwrap();
            for (ch, y) in [c, -c, 0.5 * c].into_iter().enumerate() {
                check(ph.value[ch], f64::from(y), 1e-6, &format!("phong of {y:e}"));
                check(g.value[ch], f64::from(y), 1e-5, &format!("glossy of {y:e}"));
                assert_eq!((ph.variance[ch], g.variance[ch]), (0.0, 0.0));
            }
        }
    }
    // Huge spread: σ̂² ~ 10⁷⁶ overflows, so the variances are +∞; the values are exact.
    let l = lights(6);
    let samples: [[f32; 3]; 32] =
        probe.directions().map(|d| [1e37 * field(&l, d), -1e37 * field(&l, d), field(&l, d)]);
    probe.update_with(&samples, Selection::Member(1)).unwrap();
    let big = answers(&probe, 1.0);
    probe
        .update_with(&samples.map(|y| [y[0] * 1e-37, y[1] * 1e-37, y[2]]), Selection::Member(1))
        .unwrap();
    let small = answers(&probe, 1.0);
    for ((name, b), (_, s)) in big.variances.iter().zip(&small.variances) {
        if name.ends_with("ch2") {
            assert_eq!(b, s, "{name}");
        } else {
            assert!(*b == f64::INFINITY && s.is_finite() && *s > 0.0, "{name}: {b:e} ({s:e})");
        }
    }
    for (((name, b), (_, s)), norm) in big.values.iter().zip(&small.values).zip(&small.norms) {
        let c = if name.ends_with("ch2") { 1.0 } else { 1e37 };
        check_norm(*b as f32, c * s, c * norm, 1e-4, name);
    }
    // Samples near ±f32::MAX: Yᵢ − Y₀ overflows f32 (the channel is centred at half scale).
    let wild: [f32; 32] = core::array::from_fn(|i| if i % 3 == 0 { 3e38 } else { -3.2e38 });
    let mut scalar = Probe::<32>::new();
    scalar.update_with(&wild, Selection::Member(2)).unwrap();
    let huge = answers(&scalar, 1.0);
    let unit = 2f32.powi(-100);
    scalar.update_with(&wild.map(|y| y * unit), Selection::Member(2)).unwrap();
    let reduced = answers(&scalar, 1.0);
    let tol = uniform(&reduced, 1e-6, 1e-6);
    compare(&reduced, &huge, 2f64.powi(100), 1.0, &tol, "±3·10³⁸");
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
    // A NaN among huge samples is found by the second sum and refused.
    assert_eq!(qmc::irradiance::<16, f32, _>(n, 0, |_| f32::NAN), Err(Error::InvalidRadiance));
    let s = LobeSampler::new(n, Lobe::Phong(5.0), 16, 3).unwrap();
    let mut ys = [1e38f32; 16];
    ys[3] = f32::NAN;
    assert_eq!(s.estimate(&ys), Err(Error::InvalidRadiance));

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

/// `S_ab = r_aᵀQ⁻¹r_b/(N − 1)` in f64 (`r = Y − β1` per channel, `β` by GLS), with `Q` built
/// from the probe's directions and the member's `λ`, `σ′` and solved by LU: nothing shared
/// with the probe's half-block factors.
fn reference_covariance(dirs: &[Vec3], y: &[[f32; 3]], lambda: f64, sigma: f64) -> [[f64; 3]; 3] {
    let n = dirs.len();
    let xs: Vec<[f64; 3]> = dirs.iter().map(|d| [d.x, d.y, d.z].map(f64::from)).collect();
    let mut q = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            let c = reference::vec::dot(xs[i], xs[j]);
            q[i * n + j] = (lambda * (c - 1.0)).exp() + if i == j { sigma * sigma } else { 0.0 };
        }
    }
    let q1 = reference::bmc::lu_solve(&q, n, &vec![1.0; n]);
    let s1: f64 = q1.iter().sum();
    let r: Vec<Vec<f64>> = (0..3)
        .map(|c| {
            let yc: Vec<f64> = y.iter().map(|v| f64::from(v[c])).collect();
            let beta = reference::bmc::lu_solve(&q, n, &yc).iter().sum::<f64>() / s1;
            yc.iter().map(|v| v - beta).collect()
        })
        .collect();
    let qr: Vec<Vec<f64>> = r.iter().map(|rc| reference::bmc::lu_solve(&q, n, rc)).collect();
    core::array::from_fn(|a| {
        core::array::from_fn(|b| {
            r[a].iter().zip(&qr[b]).map(|(x, y)| x * y).sum::<f64>() / (n as f64 - 1.0)
        })
    })
}

/// [`Probe::signal_covariance`] and [`Probe::signal_variance_of`] against the f64 reference
/// for every member of an RGB probe (channels correlated, one of them nearly constant):
/// within 10⁻⁵ of `√(S_aa·S_bb)` (`Σ|w_a w_b|√(S_aa S_bb)` for combinations; the members'
/// `cond(Q)` are at most 10⁴, and the f32 solves measure 5·10⁻⁷).
#[test]
fn signal_covariance_matches_the_f64_reference() {
    let l = lights(10);
    let m = lights(11);
    let mut probe = Probe::<32, [f32; 3]>::new();
    let y: [[f32; 3]; 32] = probe.directions().map(|d| {
        let (a, b) = (field(&l, d), field(&m, d));
        [a, 0.6 * a + 0.4 * b, 2.0 + 1e-3 * b]
    });
    let weights = [[0.2126, 0.7152, 0.0722], [1.0, -1.0, 0.0], [0.0, 0.0, 1e6], [-3.0, 0.5, 2.0]];
    let mut worst = 0.0f64;
    for (k, member) in Probe::<32>::family().enumerate() {
        assert!(member.condition <= 1e4);
        probe.update_with(&y, Selection::Member(k)).unwrap();
        let s = reference_covariance(
            probe.directions(),
            &y,
            f64::from(member.lambda),
            f64::from(member.sigma),
        );
        let scale = |a: usize, b: usize| (s[a][a] * s[b][b]).sqrt();
        for (a, row) in s.iter().enumerate() {
            for (b, &want) in row.iter().enumerate() {
                let got = f64::from(probe.signal_covariance(a, b).unwrap());
                let err = (got - want).abs() / scale(a, b);
                assert!(err < 1e-5, "member {k}: S[{a}][{b}] {got:e} vs {want:e} ({err:e})");
                worst = worst.max(err);
                assert_eq!(probe.signal_covariance(a, b), probe.signal_covariance(b, a));
            }
            assert_eq!(probe.signal_covariance(a, a), Ok(probe.signal_variance()[a]));
        }
        for w in weights {
            let want: f64 = (0..3)
                .flat_map(|a| (0..3).map(move |b| (a, b)))
                .map(|(a, b)| f64::from(w[a]) * f64::from(w[b]) * s[a][b])
                .sum();
            let norm: f64 = (0..3)
                .flat_map(|a| (0..3).map(move |b| (a, b)))
                .map(|(a, b)| f64::from(w[a] * w[b]).abs() * scale(a, b))
                .sum();
            let got = f64::from(probe.signal_variance_of(w).unwrap());
            let err = (got - want).abs() / norm;
            assert!(err < 1e-5, "member {k}: wᵀSw for {w:?}: {got:e} vs {want:e} ({err:e})");
            worst = worst.max(err);
        }
    }
    println!("channel covariance: worst error {worst:.1e} of √(S_aa·S_bb)");
    // Outside the channels, and before any update.
    assert_eq!(probe.signal_covariance(0, 3), Err(Error::InvalidChannel));
    assert_eq!(probe.signal_covariance(7, 1), Err(Error::InvalidChannel));
    let fresh = Probe::<32, [f32; 3]>::new();
    assert_eq!(fresh.signal_covariance(1, 1), Ok(0.0));
    assert_eq!(fresh.signal_variance_of([1.0, 2.0, 3.0]), Ok(0.0));
    assert_eq!(probe.signal_variance_of([f32::NAN, 0.0, 0.0]), Err(Error::InvalidWeights));
    assert_eq!(probe.signal_variance_of([0.0; 3]), Ok(0.0));
}

/// [`Probe::combine`]: a single channel's weights reproduce that channel's variance (to
/// rounding: the same normalised product, scaled once more), the value is the weighted sum,
/// the variance is `unit_variance × wᵀSw`, and `variance_c = unit_variance × S_cc` for every
/// query, also at scales where `S` itself overflows f32 but the variance does not.
#[test]
fn combine_reproduces_the_channels() {
    let l = lights(12);
    let mut probe = Probe::<64, [f32; 3]>::new();
    let y: [[f32; 3]; 64] =
        probe.directions().map(|d| [field(&l, d), 0.5 * field(&l, -d), 0.1 + 0.05 * d.x]);
    let lobe = SphericalGaussian::phong_moments(Vec3::new(0.0, 0.6, 0.8), 30.0).unwrap();
    let close = |a: f32, b: f32, what: &str| {
        assert!(a == b || (a - b).abs() <= 1e-6 * a.abs().max(b.abs()), "{what}: {a:e} vs {b:e}");
    };
    let mut luminance = std::collections::HashMap::new();
    for c in [1.0f32, 1e-20, 1e20, 2f32.powi(100), 2f32.powi(-70)] {
        probe.update_with(&y.map(|v| v.map(|x| x * c)), Selection::Member(1)).unwrap();
        let estimates = [
            ("irradiance", probe.irradiance(Vec3::new(0.3, 0.1, -0.9)).unwrap()),
            ("glossy", probe.glossy(&lobe).unwrap()),
            ("phong", probe.phong(Vec3::X, 12.0).unwrap()),
        ];
        for (name, e) in estimates {
            let what = format!("{name}, c = {c:e}");
            for ch in 0..3 {
                let mut w = [0.0; 3];
                w[ch] = 1.0;
                let one = probe.combine(&e, w).unwrap();
                assert_eq!(one.value, e.value[ch], "{what}");
                assert_eq!(one.unit_variance, e.unit_variance);
                close(one.variance, e.variance[ch], &format!("{what} channel {ch}"));
                let s = probe.signal_covariance(ch, ch).unwrap();
                let unit = e.unit_variance.expect("a Probe's channels share one model");
                if s.is_normal() && (s * unit).is_normal() {
                    close(unit * s, e.variance[ch], &format!("{what}: unit × S"));
                }
            }
            let w = [0.2126, 0.7152, 0.0722];
            let y = probe.combine(&e, w).unwrap();
            let want: f64 = (0..3).map(|i| f64::from(w[i]) * f64::from(e.value[i])).sum();
            check(y.value, want, 1e-6, &what);
            let s = probe.signal_variance_of(w).unwrap();
            let unit = e.unit_variance.expect("a Probe's channels share one model");
            if s.is_normal() && (s * unit).is_normal() {
                close(y.variance, unit * s, &format!("{what}: luminance"));
            }
            // c² times the c = 1 variance, also where S alone overflows (c = 10²⁰: S ~ 10⁴⁰,
            // the variance 10³⁶) or the variance underflows.
            let base = luminance.get(name).copied().unwrap_or(f64::from(y.variance));
            luminance.insert(name, base);
            check(y.variance, f64::from(c) * f64::from(c) * base, 1e-5, &what);
        }
    }
}
