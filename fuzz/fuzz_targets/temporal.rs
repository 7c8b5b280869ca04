//! `temporal::TemporalProbe` updates and queries on arbitrary f32 bits (`temporal` module docs,
//! "Bad input" and "Radiance scale", and the type's docs): nothing panics; a non-finite sample
//! or sentinel reading is `InvalidRadiance` and leaves the probe (its `Debug` form, its
//! directions) exactly as it was; a zero, NaN or infinite normal is `InvalidDirection` and
//! every other one is accepted; a hazard outside `(0, 1)` is `InvalidHazard`; before the first
//! update every query is zero with zero variance; after any finite updates no value or
//! variance is NaN and variances are non-negative, and while every sample has been within
//! ±10¹⁵ every answer is finite; queries do not change the probe.
#![no_main]

use core::fmt::Debug;

use fuzz_support::{direction_rejected, Bytes};
use libfuzzer_sys::fuzz_target;
use sphere_quadrature::footprint::{CosinePower, Footprint, Gaussian, Point};
use sphere_quadrature::temporal::{Change, TemporalProbe};
use sphere_quadrature::{Error, Radiance, Vec3};

/// A sample value: from the reader, or from one function per channel.
trait Sample: Radiance + Debug {
    fn read(b: &mut Bytes) -> Self;
    fn from_fn(f: impl Fn(usize) -> f32) -> Self;
}

impl Sample for f32 {
    fn read(b: &mut Bytes) -> Self {
        b.f32()
    }
    fn from_fn(f: impl Fn(usize) -> f32) -> Self {
        f(0)
    }
}

impl Sample for [f32; 3] {
    fn read(b: &mut Bytes) -> Self {
        [b.f32(), b.f32(), b.f32()]
    }
    fn from_fn(f: impl Fn(usize) -> f32) -> Self {
        core::array::from_fn(f)
    }
}

fn channels<T: Radiance>(t: T) -> impl Iterator<Item = f32> {
    (0..T::CHANNELS).map(move |c| t.channel(c))
}

/// What the updates so far were like (sticky: a finite sample of any size is pooled "until
/// the light changes", so one huge update may leave later answers infinite).
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum State {
    /// No update yet: every query is zero with zero variance.
    Empty,
    /// Some sample beyond ±10¹⁵ (finite): no NaN, variances ≥ 0.
    Any,
    /// Every sample of every update within ±10¹⁵: every answer finite too.
    Moderate,
}

fn check_value<T: Radiance + Debug>(what: &str, v: T, state: State) {
    match state {
        State::Empty => assert!(channels(v).all(|x| x == 0.0), "{what}: {v:?} before any update"),
        State::Any => assert!(channels(v).all(|x| !x.is_nan()), "{what}: NaN {v:?}"),
        State::Moderate => {
            assert!(channels(v).all(f32::is_finite), "{what}: {v:?} not finite, moderate samples")
        }
    }
}

fn check_variance<T: Radiance + Debug>(what: &str, v: T, state: State) {
    check_value(what, v, state);
    assert!(channels(v).all(|x| x >= 0.0), "{what}: negative or NaN variance {v:?}");
}

/// A smooth light of one sign: `1 + a·z + b·xy` plus a spot `c·max(0, x)⁸`, negated by the
/// top bit (`a ≤ 0.75`, `b ≤ 1.5`, `c ≤ 16`), channels slightly apart.
fn pattern(k: u8, d: Vec3, channel: usize) -> f32 {
    let a = f32::from(k & 3) * 0.25;
    let b = f32::from((k >> 2) & 3) * 0.5;
    let c = [0.0, 1.0, 4.0, 16.0][usize::from((k >> 4) & 3)];
    let t = d.x.max(0.0);
    let (t2, sign) = (t * t, if k & 0x80 != 0 { -1.0 } else { 1.0 });
    let t8 = (t2 * t2) * (t2 * t2);
    sign * (1.0 + a * d.z + b * d.x * d.y + c * t8) * (1.0 + channel as f32 / 8.0)
}

/// The light of one update: the scale and pattern of the smooth part, whether a few samples
/// are arbitrary bits instead.
#[derive(Clone, Copy)]
struct Light {
    base: f32,
    pattern: u8,
    mixed: bool,
}

/// `K` samples along `dirs`: the light's smooth values, or arbitrary bits (about one in eight
/// when the light is mixed), or arbitrary bits throughout when `light` is `None`.
fn samples<T: Sample, const K: usize>(
    b: &mut Bytes,
    dirs: &[Vec3; K],
    light: Option<Light>,
) -> [T; K] {
    core::array::from_fn(|j| match light {
        Some(l) if !(l.mixed && b.u8() % 8 == 0) => {
            T::from_fn(|c| l.base * pattern(l.pattern, dirs[j], c))
        }
        _ => T::read(b),
    })
}

fn within(t: impl Iterator<Item = f32>, bound: f32) -> bool {
    t.into_iter().all(|x| x.abs() <= bound)
}

/// Every query of the probe against the state; `normal` is an extra normal to try.
fn check_queries<T: Sample, F: Footprint, const N: usize, const S: usize>(
    probe: &TemporalProbe<N, T, F, S>,
    state: State,
    normal: Vec3,
) {
    let before = format!("{probe:?}");
    let reference = probe.irradiance(Vec3::Z).expect("+z is a valid normal");
    check_value("irradiance(+z)", reference.value, state);
    check_variance("irradiance(+z) variance", reference.variance, state);
    for n in [normal, -Vec3::Z, Vec3::new(1.0, -1.0, 1.0), Vec3::new(3e-15, 1e15, -2e-15)] {
        let r = probe.irradiance(n);
        match direction_rejected(n) {
            Some(true) => assert_eq!(r.err(), Some(Error::InvalidDirection), "irradiance({n:?})"),
            Some(false) => assert!(r.is_ok(), "irradiance({n:?}) = {r:?}"),
            None => assert!(matches!(r, Ok(_) | Err(Error::InvalidDirection)), "{n:?}: {r:?}"),
        }
        if let Ok(e) = r {
            check_value("irradiance", e.value, state);
            // "the same for every normal"
            let same = channels(e.variance).zip(channels(reference.variance));
            assert!(same.into_iter().all(|(a, c)| a.to_bits() == c.to_bits()), "variance at {n:?}");
        }
    }
    for c in probe.radiance_sh().coefficients {
        check_value("radiance_sh", c, state);
    }
    for v in *probe.radiance_sh_variance() {
        check_variance("radiance_sh_variance", v, state);
    }
    let (k, w) = (probe.updates(), probe.pooled_updates());
    if state == State::Empty {
        assert_eq!((k, w), (0, 0.0), "updates, effective updates before any update");
    } else {
        // The weight of the pooled evidence, the update just taken counting 1, less than
        // the count after partial resets.
        assert!(w >= 1.0 && w <= k as f32, "pooled_updates {w} after {k} updates");
    }
    assert_eq!(before, format!("{probe:?}"), "a query changed the probe");
}

fn run<T: Sample, F: Footprint, const N: usize, const S: usize>(b: &mut Bytes) {
    let mut probe = TemporalProbe::<N, T, F, S>::new(b.u64());
    if b.bool() {
        let h = b.f32();
        match probe.clone().with_hazard(h) {
            Ok(p) => {
                assert!(h > 0.0 && h < 1.0, "with_hazard({h:e}) accepted");
                probe = p;
            }
            Err(e) => {
                assert_eq!(e, Error::InvalidHazard, "with_hazard({h:e})");
                assert!(!(h > 0.0 && h < 1.0), "with_hazard({h:e}) refused");
            }
        }
    }
    let mut state = State::Empty;
    let mut updates = 0u32;
    let mut last: Option<Light> = None;
    for _ in 0..16 {
        if b.is_empty() {
            break;
        }
        let before = format!("{probe:?}");
        match b.u8() % 8 {
            0..=3 => {
                // Mostly one value at any scale times a smooth pattern (a few samples
                // arbitrary), sometimes the last update's light again (static light), or
                // arbitrary bits throughout.
                let light = match b.u8() % 8 {
                    0 => None,
                    1 if last.is_some() => last.map(|l| Light { mixed: false, ..l }),
                    _ => Some(Light { base: b.f32(), pattern: b.u8(), mixed: b.bool() }),
                };
                last = light.or(last);
                let dirs = *probe.directions();
                let ys: [T; N] = samples(b, &dirs, light);
                let ss: [T; S] = samples(b, probe.sentinels(), light);
                let all = || ys.iter().chain(&ss).flat_map(|&y| channels(y));
                let r = probe.pool(&ys, &ss);
                if !all().all(f32::is_finite) {
                    assert_eq!(r, Err(Error::InvalidRadiance), "update({ys:?}, {ss:?})");
                    assert_eq!(before, format!("{probe:?}"), "a refused update changed the probe");
                    assert_eq!(probe.directions(), &dirs, "a refused update moved the directions");
                } else {
                    let change = r.unwrap_or_else(|e| panic!("update({ys:?}, {ss:?}): {e:?}"));
                    updates = updates.saturating_add(1);
                    assert_eq!(probe.updates(), updates);
                    let p = probe.last_change_probability();
                    if state == State::Empty {
                        assert_eq!(change, Change::First);
                        assert_eq!(p, 0.0);
                        assert_eq!(probe.last_evidence(), (0.0, 0.0));
                    } else {
                        // Change's docs: Reset where π ≥ 1/2, Blended below.
                        assert!((0.0..=1.0).contains(&p), "change probability {p}");
                        let want = if p >= 0.5 { Change::Reset } else { Change::Blended };
                        assert_eq!(change, want, "π = {p}");
                        let (a, c) = probe.last_evidence();
                        assert!(!a.is_nan() && !c.is_nan(), "evidence {a}, {c}");
                    }
                    let moderate = within(ys.iter().flat_map(|&y| channels(y)), 1e15);
                    state = match (state, moderate) {
                        (State::Empty | State::Moderate, true) => State::Moderate,
                        _ => State::Any,
                    };
                }
            }
            4 => {
                let n = b.vec3();
                check_queries(&probe, state, n);
            }
            5 => {
                // Another hazard on a copy: refused, the probe is as it was.
                let h = b.f32();
                match probe.clone().with_hazard(h) {
                    Ok(p) => {
                        assert!(h > 0.0 && h < 1.0, "with_hazard({h:e}) accepted");
                        assert_eq!(p.updates(), probe.updates());
                        probe = p;
                    }
                    Err(e) => {
                        assert_eq!(e, Error::InvalidHazard, "with_hazard({h:e})");
                        assert!(!(h > 0.0 && h < 1.0), "with_hazard({h:e}) refused");
                    }
                }
            }
            _ => {
                let n = b.vec3();
                let r = probe.irradiance(n);
                match direction_rejected(n) {
                    Some(true) => {
                        assert_eq!(r.err(), Some(Error::InvalidDirection), "irradiance({n:?})")
                    }
                    Some(false) => assert!(r.is_ok(), "irradiance({n:?}) = {r:?}"),
                    None => {}
                }
                if let Ok(e) = r {
                    check_value("irradiance", e.value, state);
                    check_variance("irradiance variance", e.variance, state);
                }
                assert_eq!(before, format!("{probe:?}"), "irradiance changed the probe");
            }
        }
    }
    check_queries(&probe, state, Vec3::X);
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes::new(data);
    match b.u8() % 9 {
        0 => run::<f32, Point, 16, 0>(&mut b),
        1 => run::<f32, Point, 16, 1>(&mut b),
        2 => run::<[f32; 3], Point, 16, 4>(&mut b),
        3 => run::<f32, Gaussian<2>, 16, 1>(&mut b),
        4 => run::<f32, CosinePower<1>, 16, 0>(&mut b),
        5 => run::<f32, Point, 64, 0>(&mut b),
        6 => run::<[f32; 3], Point, 64, 1>(&mut b),
        7 => run::<f32, Gaussian<2>, 64, 4>(&mut b),
        _ => run::<[f32; 3], CosinePower<1>, 64, 4>(&mut b),
    }
});
