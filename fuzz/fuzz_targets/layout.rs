//! `LayoutProbe` construction, updates, streams, queries and channel combinations on arbitrary
//! f32 bits (`layout` module docs; `LayoutProbe::new`'s errors; lib docs, "Bad input" and
//! "Any units"): nothing panics; `new` returns `Ok` for a valid layout and otherwise one of the
//! documented errors whose cause is present; a non-finite reading is `InvalidRadiance` and
//! leaves the probe bit for bit as it was; zero, NaN or infinite directions are
//! `InvalidDirection` and valid ones are accepted; bad Phong exponents, SG sharpnesses,
//! amplitudes, weights and hazards are their documented errors; queries do not change the
//! probe; before the first update irradiance, signal variance and log likelihood are 0; after
//! finite readings no value, variance or likelihood is NaN and variances are ≥ 0; with
//! readings within ±10¹⁵, default noise (none, 1 % absolute or 1 % relative, equal noise
//! scales), a moderate mean profile (coefficients within 10^±15, seen by some sensor to within
//! 1/16 of the largest) and an ordinary spectrum every answer is finite.
//! `LAYOUT_DEBUG=1` prints the layout, the readings and Phong queries of an input.
#![no_main]

use core::fmt::Debug;

use fuzz_support::{direction_rejected, Bytes};
use libfuzzer_sys::fuzz_target;
use sphere_quadrature::layout::{
    LayoutProbe, Mean, Noise, Prior, Response, Sensor, MAX_NOISE_SCALE_RATIO, MAX_RELATIVE_NOISE,
    MAX_RESPONSES,
};
use sphere_quadrature::probe::MAX_GLOSSY_SHARPNESS;
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::temporal::Change;
use sphere_quadrature::{Error, Radiance, SphericalFibonacci, Vec3};

/// A reading (or channel weight) from the reader.
trait Reading: Radiance + Debug {
    fn read(b: &mut Bytes) -> Self;
    /// `v·p` with `p` a small per-channel pattern from the reader.
    fn pattern(v: f32, b: &mut Bytes) -> Self;
    /// The same with channel `c` replaced by `x`.
    fn with_channel(self, c: usize, x: f32) -> Self;
}

/// A small pattern factor, `k/64` for a signed byte `k` (exact).
fn factor(b: &mut Bytes) -> f32 {
    f32::from(b.u8() as i8) / 64.0
}

impl Reading for f32 {
    fn read(b: &mut Bytes) -> Self {
        b.f32()
    }
    fn pattern(v: f32, b: &mut Bytes) -> Self {
        v * factor(b)
    }
    fn with_channel(self, _: usize, x: f32) -> Self {
        x
    }
}

impl Reading for [f32; 3] {
    fn read(b: &mut Bytes) -> Self {
        [b.f32(), b.f32(), b.f32()]
    }
    fn pattern(v: f32, b: &mut Bytes) -> Self {
        [v * factor(b), v * factor(b), v * factor(b)]
    }
    fn with_channel(mut self, c: usize, x: f32) -> Self {
        self[c % 3] = x;
        self
    }
}

fn channels<T: Radiance>(t: T) -> impl Iterator<Item = f32> {
    (0..T::CHANNELS).map(move |c| t.channel(c))
}

fn all_finite<T: Radiance>(t: T) -> bool {
    channels(t).all(f32::is_finite)
}

fn moderate<T: Radiance>(t: T) -> bool {
    channels(t).all(|x| x.abs() <= 1e15)
}

/// Readings: one value at any scale times a pattern with a few arbitrary values, or arbitrary
/// throughout.
fn readings<T: Reading, const K: usize>(b: &mut Bytes) -> [T; K] {
    if b.u8() % 4 == 0 {
        return core::array::from_fn(|_| T::read(b));
    }
    let v = b.f32();
    let mut r: [T; K] = core::array::from_fn(|_| T::pattern(v, b));
    for _ in 0..b.u8() % 4 {
        let i = usize::from(b.u8());
        let c = usize::from(b.u8());
        let x = if b.bool() { f32::from_bits(b.u32()) } else { b.f32() };
        if K > 0 {
            r[i % K] = r[i % K].with_channel(c, x);
        }
    }
    r
}

/// Checks a result against documented errors: `(cause, error)` where the cause is
/// `Some(true)` present (its error is allowed, and some error required), `Some(false)` absent,
/// `None` undecided (its error allowed, not required). With no cause present the result must
/// be `Ok` or the error of an undecided cause; with some, one of the allowed errors.
fn check_errors<R: Debug>(what: &str, r: &Result<R, Error>, causes: &[(Option<bool>, Error)]) {
    let allowed = |e: &Error| causes.iter().any(|&(c, err)| c != Some(false) && err == *e);
    let required = causes.iter().any(|&(c, _)| c == Some(true));
    match r {
        Ok(_) => assert!(!required, "{what}: Ok where {causes:?} require an error"),
        Err(e) => assert!(allowed(e), "{what}: {e:?}, allowed {causes:?}"),
    }
}

/// What the probe's last readings were like.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum State {
    /// No update yet.
    Empty,
    /// Finite readings: no NaN, variances ≥ 0.
    Any,
    /// Readings within ±10¹⁵ (all of them since the last `update`, for a stream) and a
    /// default layout: every answer finite too.
    Moderate,
    /// Finite readings on a layout of known defect 17: no check of the values.
    Unchecked,
}

fn check_value<T: Radiance + Debug>(what: &str, v: T, state: State, bounded: bool) {
    if state == State::Unchecked {
        return;
    }
    assert!(channels(v).all(|x| !x.is_nan()), "{what}: NaN {v:?} ({state:?})");
    if state == State::Moderate && bounded {
        assert!(all_finite(v), "{what}: {v:?} not finite for moderate readings");
    }
}

fn check_variance<T: Radiance + Debug>(what: &str, v: T, state: State, bounded: bool) {
    if state == State::Unchecked {
        return;
    }
    check_value(what, v, state, bounded);
    assert!(channels(v).all(|x| x >= 0.0), "{what}: negative or NaN variance {v:?}");
}

/// Queries of `probe` (any channel type) with the arguments from the reader, checked; the probe
/// must not change.
fn query<T: Reading, const K: usize>(
    probe: &LayoutProbe<K, T>,
    op: u8,
    state: State,
    ordinary: bool,
    b: &mut Bytes,
) {
    let before = format!("{probe:?}");
    match op {
        0 => {
            let n = b.vec3();
            let causes = [(direction_rejected(n), Error::InvalidDirection)];
            let r = probe.irradiance(n);
            check_errors("irradiance", &r, &causes);
            if let Ok(e) = r {
                if state == State::Empty {
                    assert!(channels(e.value).chain(channels(e.variance)).all(|x| x == 0.0));
                    assert!(e.unit_variance.unwrap_or(0.0) == 0.0, "{e:?} before any update");
                }
                check_value("irradiance value", e.value, state, true);
                check_variance("irradiance variance", e.variance, state, true);
                assert!(
                    state == State::Unchecked || e.unit_variance.unwrap_or(0.0) >= 0.0,
                    "unit variance {e:?}"
                );
            }
            let r = probe.irradiance_variance(n);
            check_errors("irradiance_variance", &r, &causes);
            if let Ok(v) = r {
                check_variance("irradiance_variance", v, state, true);
            }
        }
        1 => {
            let axis = b.vec3();
            let e = b.f32();
            let bad = !(e >= 0.0 && e <= MAX_GLOSSY_SHARPNESS);
            let r = probe.phong(axis, e);
            if std::env::var_os("LAYOUT_DEBUG").is_some() {
                eprintln!("phong({axis:?}, {e:e}) = {r:?}");
            }
            check_errors(
                "phong",
                &r,
                &[
                    (direction_rejected(axis), Error::InvalidDirection),
                    (Some(bad), Error::InvalidExponent),
                ],
            );
            if let Ok(est) = r {
                check_value("phong value", est.value, state, true);
                check_variance("phong variance", est.variance, state, true);
                assert!(
                    state == State::Unchecked || est.unit_variance.unwrap_or(0.0) >= 0.0,
                    "phong {est:?}"
                );
            }
        }
        2 => {
            let axis = b.vec3();
            let sharpness = b.f32();
            let amplitude = b.f32();
            let lobe = SphericalGaussian { axis, sharpness, amplitude };
            let r = probe.glossy(&lobe);
            check_errors(
                "glossy",
                &r,
                &[
                    (direction_rejected(axis), Error::InvalidDirection),
                    (
                        Some(!(sharpness >= 0.0 && sharpness <= MAX_GLOSSY_SHARPNESS)),
                        Error::InvalidSharpness,
                    ),
                    (Some(!amplitude.is_finite()), Error::InvalidWeights),
                ],
            );
            if let Ok(est) = r {
                // The value is ±∞ only where ∫L·G exceeds f32::MAX: bounded amplitudes only.
                let bounded = amplitude.abs() <= 1e3;
                check_value("glossy value", est.value, state, bounded);
                check_variance("glossy variance", est.variance, state, bounded);
                assert!(
                    state == State::Unchecked || est.unit_variance.unwrap_or(0.0) >= 0.0,
                    "glossy {est:?}"
                );
            }
        }
        3 => {
            for c in probe.radiance_sh().coefficients {
                check_value("radiance_sh", c, state, true);
            }
            let s = probe.signal_variance();
            check_variance("signal_variance", s, state, true);
            let l = probe.log_likelihood();
            assert!(state == State::Unchecked || !l.is_nan(), "log likelihood NaN");
            if state == State::Empty {
                assert!(channels(s).all(|x| x == 0.0) && l == 0.0, "{s:?} {l} before any update");
                assert!(!probe.is_updated());
            } else {
                assert!(probe.is_updated());
            }
            let p = probe.pooled_updates();
            assert!(p.is_finite() && p >= if state == State::Empty { 0.0 } else { 1.0 }, "{p}");
        }
        _ => {
            let w = T::read(b);
            let r = probe.combined_probe(w);
            if std::env::var_os("LAYOUT_DEBUG").is_some() {
                eprintln!("combined_probe({w:?}): {:?}", r.as_ref().err());
            }
            let nonzero = channels(w).any(|x| x != 0.0);
            if !all_finite(w) || !nonzero {
                assert_eq!(r.as_ref().err(), Some(&Error::InvalidWeights), "combined({w:?})");
            } else if (state == State::Moderate || state == State::Empty && ordinary)
                && channels(w).all(|x| x.abs() <= 1e3)
            {
                // Moderate readings, default noise and moderate weights: the combination
                // and its noise are within f32 (an arbitrary σ times |w| may not be).
                assert!(r.is_ok(), "combined({w:?}): {:?}", r.as_ref().err());
            } else if let Err(e) = &r {
                assert_eq!(*e, Error::InvalidWeights, "combined({w:?})");
            }
            if let Ok(c) = r {
                assert_eq!(c.is_updated(), probe.is_updated(), "combined({w:?})");
                // Weights within ±1 keep moderate readings moderate (|Σ w_c·Y_c| ≤ 3·10¹⁵)
                // and the noise default or smaller.
                let small = channels(w).all(|x| x.abs() <= 1.0);
                let cstate = match state {
                    State::Empty | State::Unchecked => state,
                    State::Moderate if small => State::Moderate,
                    _ => State::Any,
                };
                query::<f32, K>(&c, b.u8() % 4, cstate, ordinary && small, b);
                // An update of the combined probe takes one channel.
                if b.bool() {
                    let mut c = c;
                    let y = readings::<f32, K>(b);
                    let r = c.update(&y);
                    if y.iter().all(|v| v.is_finite()) {
                        assert_eq!(r, Ok(()), "combined probe's update({y:?})");
                        let m = ordinary && small && y.iter().all(|&v| moderate(v));
                        let s = match (state, m) {
                            (State::Unchecked, _) => State::Unchecked,
                            (_, true) => State::Moderate,
                            (_, false) => State::Any,
                        };
                        query::<f32, K>(&c, b.u8() % 4, s, ordinary && small, b);
                    } else {
                        assert_eq!(r, Err(Error::InvalidRadiance));
                    }
                }
            }
        }
    }
    assert_eq!(before, format!("{probe:?}"), "a query changed the probe");
}

/// A response from the reader: the default cosine, a cosine power or a Gaussian of any
/// parameter.
fn response(b: &mut Bytes) -> Response {
    match b.u8() % 4 {
        0 | 1 => Response::CosinePower(1.0),
        2 => Response::CosinePower(b.f32()),
        _ => Response::Gaussian(b.f32()),
    }
}

/// Two responses are the same for `new` (their parameters bit for bit).
fn same(a: &Response, b: &Response) -> bool {
    match (a, b) {
        (Response::CosinePower(x), Response::CosinePower(y))
        | (Response::Gaussian(x), Response::Gaussian(y)) => x.to_bits() == y.to_bits(),
        _ => false,
    }
}

fn run<T: Reading, const K: usize>(b: &mut Bytes, directions: [Vec3; K]) {
    // Responses: all cosine, one shared, or each from a pool of six.
    let mode = b.u8() % 4;
    let pool: [Response; 6] = core::array::from_fn(|_| response(b));
    let responses: [Response; K] = core::array::from_fn(|_| match mode {
        0 | 1 => Response::CosinePower(1.0),
        2 => pool[0],
        _ => pool[usize::from(b.u8()) % 6],
    });
    // Noise scales: all 1 (default), or each from the reader.
    let equal_scales = b.u8() % 4 != 0;
    let scales: [f32; K] = core::array::from_fn(|_| if equal_scales { 1.0 } else { b.f32() });
    let sensors: [Sensor; K] = core::array::from_fn(|i| {
        let s = Sensor::new(directions[i], responses[i]);
        if equal_scales {
            s
        } else {
            s.with_noise_scale(scales[i])
        }
    });
    // Noise: none, 1 % absolute or relative (default), or arbitrary.
    let noise = match b.u8() % 5 {
        0 => Noise::NONE,
        1 => Noise { absolute: 0.01, relative: 0.0 },
        2 => Noise { absolute: 0.0, relative: 0.01 },
        _ => Noise { absolute: b.f32(), relative: b.f32() },
    };
    let default_noise = [
        Noise::NONE,
        Noise { absolute: 0.01, relative: 0.0 },
        Noise { absolute: 0.0, relative: 0.01 },
    ]
    .contains(&noise);
    // Prior: the environment's, a squared exponential of any λ, with any mean.
    let mut prior = Prior::ENVIRONMENT;
    // Whether the spectrum is an ordinary one (ENVIRONMENT, or λ ≥ 1/2): for a tiny λ the
    // K_l of degrees ≥ 1 are about λˡ, and the scale s that explains moderate readings
    // (signal_variance) may rightly exceed f32::MAX.
    let mut ordinary_prior = true;
    if b.bool() {
        let lambda = b.f32();
        let r = Prior::squared_exponential(lambda);
        let bad = !(lambda > 0.0 && lambda <= 64.0);
        assert_eq!(r.is_err(), bad, "squared_exponential({lambda}): {r:?}");
        if let Err(e) = r {
            assert_eq!(e, Error::InvalidPrior);
        }
        if let Ok(p) = r {
            prior = p;
            ordinary_prior = lambda >= 0.5;
        }
    }
    let mut moderate_profile = true;
    let mut profile_bad = false;
    let mut profile = None;
    match b.u8() % 5 {
        0 => prior = prior.with_mean(Mean::Zero),
        1 => prior = prior.with_mean(Mean::Constant),
        2 => {
            let mut p = [0.0f32; 9];
            p[0] = 1.0;
            p[1] = factor(b);
            profile = Some(p);
            prior = prior.with_mean(Mean::Zonal(p));
        }
        3 => {
            let p: [f32; 9] = core::array::from_fn(|_| if b.bool() { b.f32() } else { 0.0 });
            profile = Some(p);
            profile_bad = p.iter().any(|x| !x.is_finite()) || p.iter().all(|&x| x == 0.0);
            moderate_profile = p.iter().all(|&x| x == 0.0 || (1e-15..=1e15).contains(&x.abs()));
            prior = prior.with_mean(Mean::Zonal(p));
        }
        _ => {}
    }
    let mean_terms = usize::from(prior.mean != Mean::Zero);

    let used: Vec<Response> = responses.iter().fold(Vec::new(), |mut v, r| {
        if !v.iter().any(|u| same(u, r)) {
            v.push(*r);
        }
        v
    });
    let response_bad = used.len() > MAX_RESPONSES || used.iter().any(|r| r.gains().is_err());
    for r in &used {
        let bad = match *r {
            Response::CosinePower(p) => !(p >= 0.0 && p <= 4096.0),
            Response::Gaussian(s) => !(s > 0.0 && s <= 4096.0),
            Response::Gains(_) => continue,
        };
        assert_eq!(r.gains().is_err(), bad, "{r:?}.gains()");
    }
    let (least, most) =
        scales.iter().fold((f32::INFINITY, 0.0f32), |(l, m), &w| (l.min(w), m.max(w)));
    let noise_bad = !(noise.absolute >= 0.0 && noise.absolute.is_finite())
        || !(noise.relative >= 0.0 && noise.relative <= MAX_RELATIVE_NOISE)
        || scales.iter().any(|&w| !(w > 0.0 && w.is_finite()))
        || (noise.absolute > 0.0 && most > MAX_NOISE_SCALE_RATIO * least);
    let direction =
        directions.iter().fold(Some(false), |acc, &d| match (acc, direction_rejected(d)) {
            (Some(true), _) | (_, Some(true)) => Some(true),
            (None, _) | (_, None) => None,
            _ => Some(false),
        });
    // σ times the least noise scale (rounded down to a power of two) beyond f32.
    let product = f64::from(noise.absolute) * f64::from(least);
    let noise_overflow = if noise.absolute > 0.0 && product > 2.0 * f64::from(f32::MAX) {
        Some(true)
    } else if product > 0.25 * f64::from(f32::MAX) {
        None
    } else {
        Some(false)
    };
    // A zonal mean the sensors do not see (its basis below 2⁻⁸⁹ of the profile's largest
    // coefficient at every sensor, in f32) is `InvalidPrior`; one they see at 2⁻⁸⁵ or more,
    // less what f32 may lose of the sum (its cancellation, subnormal products), is not.
    let unseen_mean = match profile {
        Some(p) if !profile_bad => {
            let top = p.iter().fold(0.0f64, |m, &x| m.max(f64::from(x).abs()));
            let seen = (0..K).fold(0.0f64, |m, i| {
                let g = responses[i].gains().unwrap_or([1.0; 33]);
                let (sum, size) = zonal_sum(&p, &g, directions[i]);
                m.max(sum.abs() - size * 2f64.powi(-16) - top * 2f64.powi(-100))
            });
            if seen >= top * 2f64.powi(-85) {
                Some(false)
            } else {
                None
            }
        }
        _ => Some(false),
    };
    // A moderate profile is also one some sensor sees well: its basis there at least 1/16 of
    // the profile's largest coefficient. Where the sensors barely see it, the mean's
    // coefficient is known only to within readings/seen, and the variance of an answer, that
    // uncertainty squared times the profile's size at the query, may rightly exceed f32::MAX.
    if let Some(p) = profile {
        let top = p.iter().fold(0.0f64, |m, &x| m.max(f64::from(x).abs()));
        let seen = (0..K).fold(0.0f64, |m, i| {
            let g = responses[i].gains().unwrap_or([1.0; 33]);
            m.max(zonal_sum(&p, &g, directions[i]).0.abs())
        });
        moderate_profile &= seen >= top / 16.0;
    }
    let r = LayoutProbe::<K, T>::new(&sensors, prior, noise);
    if std::env::var_os("LAYOUT_DEBUG").is_some() {
        eprintln!("K = {K}, {sensors:?}, {prior:?}, {noise:?}: {:?}", r.as_ref().err());
    }
    check_errors(
        "new",
        &r,
        &[
            (Some(K == 0 || K <= mean_terms), Error::InvalidSize),
            (Some(noise_bad), Error::InvalidNoise),
            (noise_overflow, Error::InvalidNoise),
            (Some(profile_bad), Error::InvalidPrior),
            (unseen_mean, Error::InvalidPrior),
            (direction, Error::InvalidDirection),
            (Some(response_bad), Error::InvalidResponse),
        ],
    );
    let Ok(mut probe) = r else { return };
    // Every answer is finite for moderate readings only on a default layout.
    let ordinary = default_noise && equal_scales && moderate_profile && ordinary_prior;

    let mut state = State::Empty;
    for _ in 0..12 {
        if b.is_empty() {
            break;
        }
        match b.u8() % 10 {
            op @ (0 | 1) => {
                let y = readings::<T, K>(b);
                if std::env::var_os("LAYOUT_DEBUG").is_some() {
                    eprintln!("op {op}: {y:?}");
                }
                let before = format!("{probe:?}");
                let finite = y.iter().all(|&v| all_finite(v));
                let r =
                    if op == 0 { probe.update(&y).map(|()| Change::First) } else { probe.pool(&y) };
                if !finite {
                    assert_eq!(r, Err(Error::InvalidRadiance), "update/accumulate({y:?})");
                    assert_eq!(before, format!("{probe:?}"), "a refused update changed the probe");
                    continue;
                }
                let change = r.unwrap_or_else(|e| panic!("finite readings {y:?}: {e:?}"));
                if op == 1 && state == State::Empty {
                    assert_eq!(change, Change::First);
                }
                let m = ordinary && y.iter().all(|&v| moderate(v));
                // `update` replaces the stream; `accumulate` pools with the old readings (even
                // a reset keeps some of their weight).
                state = if m && (op == 0 || state != State::Any) {
                    State::Moderate
                } else {
                    State::Any
                };
                let p = probe.last_change_probability();
                assert!((0.0..=1.0).contains(&p), "change probability {p}");
            }
            2 => {
                let h = b.f32();
                let r = probe.clone().with_hazard(h);
                if h > 0.0 && h < 1.0 {
                    probe = r.expect("a hazard in (0, 1)");
                } else {
                    assert_eq!(r.err(), Some(Error::InvalidHazard), "with_hazard({h})");
                }
            }
            op => query::<T, K>(&probe, (op - 3) % 5, state, ordinary, b),
        }
    }
}

/// `Σ_l p_l·g_l·P_l(d·z)` in f64 for the unit direction of `d`, and `Σ_l |p_l·g_l|` (0 for a
/// bad direction).
fn zonal_sum(p: &[f32; 9], g: &[f32; 33], d: Vec3) -> (f64, f64) {
    let (x, y, z) = (f64::from(d.x), f64::from(d.y), f64::from(d.z));
    let norm = (x * x + y * y + z * z).sqrt();
    if !(norm > 0.0 && norm.is_finite()) {
        return (0.0, 0.0);
    }
    let size = (0..9).map(|l| (f64::from(p[l]) * f64::from(g[l])).abs()).sum::<f64>();
    let t = (z / norm).clamp(-1.0, 1.0);
    let (mut p0, mut p1) = (1.0f64, t);
    let mut sum = f64::from(p[0]) * f64::from(g[0]) + f64::from(p[1]) * f64::from(g[1]) * t;
    for l in 2..9 {
        let lf = l as f64;
        let p2 = ((2.0 * lf - 1.0) * t * p1 - (lf - 1.0) * p0) / lf;
        sum += f64::from(p[l]) * f64::from(g[l]) * p2;
        p0 = p1;
        p1 = p2;
    }
    (sum, size)
}

/// The six faces of a cube.
const FACES: [Vec3; 6] = [
    Vec3::X,
    Vec3::new(-1.0, 0.0, 0.0),
    Vec3::Y,
    Vec3::new(0.0, -1.0, 0.0),
    Vec3::Z,
    Vec3::new(0.0, 0.0, -1.0),
];

fn arbitrary<T: Reading, const K: usize>(b: &mut Bytes) {
    // Directions: arbitrary, or faces of a cube with a few arbitrary ones.
    let dirs: [Vec3; K] = if b.bool() {
        core::array::from_fn(|_| b.vec3())
    } else {
        let mut d: [Vec3; K] = core::array::from_fn(|i| FACES[i % 6]);
        for _ in 0..b.u8() % 3 {
            let i = usize::from(b.u8());
            if K > 0 {
                d[i % K] = b.vec3();
            }
        }
        d
    };
    run::<T, K>(b, dirs);
}

fn layout<T: Reading>(b: &mut Bytes) {
    match b.u8() % 4 {
        0 => run::<T, 6>(b, FACES),
        1 => run::<T, 16>(b, SphericalFibonacci::<16>::new().points()),
        _ => match b.u8() % 13 {
            0 => arbitrary::<T, 0>(b),
            1 => arbitrary::<T, 1>(b),
            2 => arbitrary::<T, 2>(b),
            3 => arbitrary::<T, 3>(b),
            4 => arbitrary::<T, 4>(b),
            5 => arbitrary::<T, 5>(b),
            6 => arbitrary::<T, 6>(b),
            7 => arbitrary::<T, 7>(b),
            8 => arbitrary::<T, 8>(b),
            9 => arbitrary::<T, 9>(b),
            10 => arbitrary::<T, 10>(b),
            11 => arbitrary::<T, 11>(b),
            _ => arbitrary::<T, 12>(b),
        },
    }
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes::new(data);
    if b.u8() % 3 == 0 {
        layout::<[f32; 3]>(&mut b);
    } else {
        layout::<f32>(&mut b);
    }
});
