//! The host reference of the JavaScript package (`examples/wasm/package`): for every baked size
//! and two rotation seeds, the RGB probe's directions, fixed samples, then irradiance, glossy
//! radiance (both with variances), the SH coefficients and their variances, and the errors of
//! bad queries, as `key n seed index value` lines (values as f32 bits, errors by name); then,
//! for every size, a stream of temporal updates (static light, then a switch of light) of a
//! point and of a footprint temporal probe, as `t_key n stream.update index value` lines: the
//! directions, samples and sentinel readings of each update, what its `pool` did with the old
//! evidence, the state (updates, degree, pooled updates, change probability, log Bayes
//! factors), irradiance with variance at fixed normals, and the SH coefficients and variances
//! at the end of each light; then layout probes (a cube of six sensors of two responses, a
//! dome of five with the sky-above prior, the cube under the other priors), as
//! `l_key layout.step index value` lines: the sensors, the readings of each step, what each
//! `pool` did, the state (sensor count, updated, pooled updates, change probability,
//! signal variance), irradiance with its averaged and its exact variance at fixed normals,
//! Phong averages with variances and SH coefficients, and the errors. The package's Node test
//! (`examples/wasm/package/test/test.mjs`) feeds the same samples and readings to the
//! WebAssembly modules through the package and requires every line to be equal.
//!
//! ```text
//! cargo eval js_package_reference > reference.txt
//! ```

use clap::Parser;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::footprint::{Footprint, Gaussian, Point};
use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Response, Sensor};
use sphere_quadrature::probe::{Probe, ProbeSize};
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::temporal::TemporalProbe;
use sphere_quadrature::{Error, RotationSequence, Vec3};

/// Rotation seeds (0: unrotated).
const SEEDS: [u32; 2] = [0, 7];
/// Query directions (normals and reflection directions; dyadic, not unit).
const QUERIES: [[f32; 3]; 8] = [
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
    [1.0, 0.0, 0.0],
    [0.5, -0.25, 0.75],
    [-1.5, 2.0, 0.5],
    [0.125, 0.5, -1.0],
    [3.0, 3.0, 3.0],
    [-0.25, -0.75, 0.0],
];
/// Phong exponents of the glossy queries (the i-th with the i-th direction).
const EXPONENTS: [f32; 8] = [0.0, 1.0, 5.0, 20.0, 100.0, 7.5, 50.0, 2.0];

fn line(key: &str, n: usize, seed: u32, index: usize, v: f32) {
    println!("{key} {n} {seed} {index} {:08x}", v.to_bits());
}

fn values(key: &str, n: usize, seed: u32, vs: impl IntoIterator<Item = f32>) {
    for (i, v) in vs.into_iter().enumerate() {
        line(key, n, seed, i, v);
    }
}

fn error<T>(key: &str, n: usize, seed: u32, index: usize, r: Result<T, Error>) {
    let what = match r {
        Ok(_) => "ok".to_string(),
        Err(e) => format!("{e:?}"),
    };
    println!("{key} {n} {seed} {index} {what}");
}

/// The fixed RGB radiance of direction `d` (every channel positive, none constant).
fn radiance(d: Vec3) -> [f32; 3] {
    let up = d.z.max(0.0);
    [1.0 + 0.5 * d.x, 0.25 + 4.0 * up * up, 0.5 + 0.25 * d.x * d.y]
}

fn run<const N: usize>()
where
    Size<N>: ProbeSize,
{
    for seed in SEEDS {
        let mut p = Probe::<N, [f32; 3]>::new();
        if seed != 0 {
            let Ok(()) = p.set_rotation(RotationSequence::new(u64::from(seed)).next_rotation())
            else {
                println!("rotation {N} {seed} 0 failed");
                continue;
            };
        }
        values("dir", N, seed, p.directions().iter().flat_map(|d| [d.x, d.y, d.z]));
        let ys = p.directions().map(radiance);
        values("sample", N, seed, ys.iter().flatten().copied());
        // Before the first update every query answers zero.
        if let Ok(est) = p.irradiance(Vec3::Z) {
            values("fresh", N, seed, est.value.into_iter().chain(est.variance));
        }
        values("fresh_sh", N, seed, p.radiance_sh().coefficients.into_iter().flatten());
        error("update", N, seed, 0, p.update(&ys));
        for (i, (q, e)) in QUERIES.iter().zip(EXPONENTS).enumerate() {
            let q = Vec3::new(q[0], q[1], q[2]);
            if let Ok(est) = p.irradiance(q) {
                values(&format!("irr{i}"), N, seed, est.value.into_iter().chain(est.variance));
            }
            error("irr_ok", N, seed, i, p.irradiance(q));
            let g = SphericalGaussian::phong_moments(q, e)
                .and_then(|lobe| Ok((p.glossy(&lobe)?.value, p.glossy_variance(&lobe)?)));
            if let Ok((value, variance)) = g {
                values(&format!("glossy{i}"), N, seed, value.into_iter().chain(variance));
            }
            error("glossy_ok", N, seed, i, g);
        }
        values("sh", N, seed, p.radiance_sh().coefficients.into_iter().flatten());
        values("shvar", N, seed, p.radiance_sh_variance().into_iter().flatten());
        // Errors: the probe keeps its data after a refused update.
        let mut bad = ys;
        bad[N / 2][1] = f32::NAN;
        error("err_update", N, seed, 0, p.update(&bad));
        bad[N / 2][1] = f32::INFINITY;
        error("err_update", N, seed, 1, p.update(&bad));
        values("sh_after_err", N, seed, p.radiance_sh().coefficients.into_iter().flatten());
        error("err_irr", N, seed, 0, p.irradiance(Vec3::ZERO));
        error("err_irr", N, seed, 1, p.irradiance(Vec3::new(f32::NAN, 0.0, 1.0)));
        error("err_irr", N, seed, 2, p.irradiance(Vec3::new(f32::INFINITY, 0.0, 0.0)));
        let glossy = |r: Vec3, e: f32| {
            SphericalGaussian::phong_moments(r, e).and_then(|lobe| p.glossy(&lobe))
        };
        error("err_glossy", N, seed, 0, glossy(Vec3::Z, -1.0));
        error("err_glossy", N, seed, 1, glossy(Vec3::Z, f32::NAN));
        error("err_glossy", N, seed, 2, glossy(Vec3::Z, f32::INFINITY));
        error("err_glossy", N, seed, 3, glossy(Vec3::ZERO, 20.0));
    }
}

/// Temporal updates of the first light, of the second (a switch), then of the second a few
/// per cent brighter (a change of uncertain evidence).
const TEMPORAL_UPDATES: [usize; 3] = [12, 8, 6];
/// The third light: the second times this.
const BRIGHTER: f32 = 1.03;
/// Normals of the temporal irradiance queries (not unit).
const TEMPORAL_NORMALS: [[f32; 3]; 4] =
    [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [-0.5, 0.75, -0.25], [0.125, -1.0, 0.5]];

/// The second light of the point stream: a different sky with a bright lobe (every channel
/// positive).
fn switched(d: Vec3) -> [f32; 3] {
    let lobe = (8.0 * (0.6 * d.x - 0.8 * d.y - 1.0)).exp();
    [0.75 + 6.0 * lobe, 2.0 - 0.5 * d.z + 3.0 * lobe, 1.5 + 0.5 * d.y]
}

/// The footprint stream's light `which` (0, 1) as its samples of the normalised spherical
/// Gaussian of sharpness `sharpness` give it: `a + b·d + c·P₂(d_z)` per channel, whose
/// filtered reading is `a + g₁·b·d + g₂·c·P₂(d_z)`.
fn filtered(which: usize, sharpness: u32, d: Vec3) -> [f32; 3] {
    let kind = sphere_quadrature::footprint::Kind::Gaussian { sharpness };
    let g1 = kind.gain(1).unwrap_or(0.0) as f32;
    let g2 = kind.gain(2).unwrap_or(0.0) as f32;
    let p2 = 1.5 * d.z * d.z - 0.5;
    let (a, b, c) = if which == 0 {
        ([1.0, 2.0, 0.5], [[0.5, 0.0, 0.25], [0.0, -1.0, 0.5], [0.25, 0.25, 0.0]], [0.5, 1.0, 0.25])
    } else {
        ([4.0, 1.0, 3.0], [[-1.5, 0.5, 0.0], [0.5, 0.25, -0.5], [0.0, 1.0, 1.0]], [-1.0, 0.5, 2.0])
    };
    core::array::from_fn(|ch| {
        a[ch] + g1 * (b[ch][0] * d.x + b[ch][1] * d.y + b[ch][2] * d.z) + g2 * c[ch] * p2
    })
}

/// A stream of temporal updates of `probe` (`stream`: its name in the lines), the light
/// `light(which, d)` for `which` = 0, 1 and 2 ([`TEMPORAL_UPDATES`]), then its errors.
fn temporal_stream<const R: usize, const S: usize, F: Footprint>(
    n: usize,
    stream: &str,
    mut probe: TemporalProbe<R, [f32; 3], F, S>,
    light: impl Fn(usize, Vec3) -> [f32; 3],
) {
    let out = |key: &str, u: usize, vs: &mut dyn Iterator<Item = f32>| {
        for (i, v) in vs.enumerate() {
            println!("t_{key} {n} {stream}.{u} {i} {:08x}", v.to_bits());
        }
    };
    let xyz = |ds: &[Vec3]| ds.iter().flat_map(|d| [d.x, d.y, d.z]).collect::<Vec<_>>();
    let state = |key: &str, u: usize, p: &TemporalProbe<R, [f32; 3], F, S>| {
        println!("t_{key} {n} {stream}.{u} 0 {}", p.updates());
        println!("t_{key} {n} {stream}.{u} 1 {}", p.degree());
        let (rotated, sentinels) = p.last_evidence();
        let floats = [p.pooled_updates(), p.last_change_probability(), rotated, sentinels];
        for (i, v) in floats.into_iter().enumerate() {
            println!("t_{key} {n} {stream}.{u} {} {:08x}", i + 2, v.to_bits());
        }
    };
    let irradiance = |u: usize, p: &TemporalProbe<R, [f32; 3], F, S>| {
        for (i, q) in TEMPORAL_NORMALS.iter().enumerate() {
            if let Ok(e) = p.irradiance(Vec3::new(q[0], q[1], q[2])) {
                out(&format!("irr{i}"), u, &mut e.value.into_iter().chain(e.variance));
            }
        }
    };
    out("sentinel_dir", 0, &mut xyz(probe.sentinels()).into_iter());
    irradiance(0, &probe);
    out("fresh_sh", 0, &mut probe.radiance_sh().coefficients.into_iter().flatten());
    let mut u = 0;
    for (which, &count) in TEMPORAL_UPDATES.iter().enumerate() {
        for k in 0..count {
            u += 1;
            out("dir", u, &mut xyz(probe.directions()).into_iter());
            let samples = probe.directions().map(|d| light(which, d));
            let sentinels = probe.sentinels().map(|d| light(which, d));
            out("sample", u, &mut samples.iter().flatten().copied());
            out("reading", u, &mut sentinels.iter().flatten().copied());
            let change = match probe.pool(&samples, &sentinels) {
                Ok(c) => format!("{c:?}").to_lowercase(),
                Err(e) => format!("{e:?}"),
            };
            println!("t_change {n} {stream}.{u} 0 {change}");
            state("state", u, &probe);
            irradiance(u, &probe);
            if k + 1 == count {
                out("sh", u, &mut probe.radiance_sh().coefficients.into_iter().flatten());
                out("shvar", u, &mut probe.radiance_sh_variance().iter().flatten().copied());
            }
        }
    }
    // Errors: a refused update keeps the state and the directions.
    let before = *probe.directions();
    let mut samples = before.map(|d| light(2, d));
    let sentinels = probe.sentinels().map(|d| light(2, d));
    samples[R / 2][1] = f32::NAN;
    println!("t_err {n} {stream}.{u} 0 {:?}", probe.pool(&samples, &sentinels).err());
    samples[R / 2][1] = 1.0;
    let mut bad = sentinels;
    bad[S - 1][2] = f32::INFINITY;
    println!("t_err {n} {stream}.{u} 1 {:?}", probe.pool(&samples, &bad).err());
    println!("t_err {n} {stream}.{u} 2 {}", probe.directions() == &before);
    state("state_after_err", u, &probe);
    println!("t_err {n} {stream}.{u} 3 {:?}", probe.irradiance(Vec3::ZERO).err());
    println!(
        "t_err {n} {stream}.{u} 4 {:?}",
        probe.irradiance(Vec3::new(0.0, f32::NAN, 1.0)).err()
    );
}

/// The temporal streams of the package's module of `N` rays per update: `R = N − S` rotated
/// directions, `S` sentinels (the module's `round(√N/4)`), sharpness `G = N/8`.
fn temporal<const N: usize, const R: usize, const S: usize, const G: u32>() {
    assert_eq!((R + S, G as usize), (N, N / 8), "the module's shape");
    let point = TemporalProbe::<R, [f32; 3], Point, S>::new(5);
    temporal_stream(N, "point", point, |which, d| match which {
        0 => radiance(d),
        1 => switched(d),
        _ => switched(d).map(|c| c * BRIGHTER),
    });
    match TemporalProbe::<R, [f32; 3], Gaussian<G>, S>::new(11).with_hazard(1.0 / 256.0) {
        Ok(footprint) => temporal_stream(N, "gaussian", footprint, |which, d| {
            filtered(which.min(1), G, d).map(|c| if which == 2 { c * BRIGHTER } else { c })
        }),
        Err(e) => println!("t_err {N} gaussian.0 0 {e:?}"),
    }
}

/// Normals of the layout probes' irradiance queries (not unit).
const LAYOUT_NORMALS: [[f32; 3]; 5] =
    [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [-0.5, 0.75, -0.25], [0.125, -1.0, 0.5], [0.0, 0.0, -1.0]];
/// Axes and exponents of the layout probes' Phong queries.
const LAYOUT_PHONG: [([f32; 3], f32); 4] = [
    ([0.0, 0.0, 1.0], 20.0),
    ([1.0, 0.5, 0.25], 5.0),
    ([-0.25, -1.0, 0.5], 1.0),
    ([0.0, 0.0, -1.0], 0.0),
];
/// `pool` calls of a layout stream: of the first light, then of the second (a switch).
const LAYOUT_STREAM: [usize; 2] = [6, 4];

/// A deterministic noise in [−1, 1) from its indices.
fn jitter(a: usize, b: usize, c: usize) -> f32 {
    let mut x = (a as u32).wrapping_mul(0x9e37_79b9) ^ (b as u32).wrapping_mul(0x85eb_ca6b);
    x ^= (c as u32).wrapping_mul(0xc2b2_ae35);
    x ^= x >> 15;
    x = x.wrapping_mul(0x2c1b_3c6d);
    x ^= x >> 12;
    (x >> 8) as f32 / (1u32 << 23) as f32 - 1.0
}

/// The readings of `light` (0 or 1: a switch to a dimmer, bluer light from the side) by
/// sensors looking along `dirs`, with a noise of `amount` (`step` varies it).
fn layout_readings<const K: usize>(
    dirs: &[Vec3; K],
    light: usize,
    step: usize,
    amount: f32,
) -> [[f32; 3]; K] {
    core::array::from_fn(|i| {
        let d = dirs[i];
        let clean = if light == 0 {
            [1.5 + 0.75 * d.z + 0.25 * d.x, 1.25 + 0.5 * d.z, 0.75 + 0.5 * d.z - 0.125 * d.y]
        } else {
            [0.5 + 0.25 * d.x, 0.5 + 0.125 * d.y, 1.0 + 0.5 * d.x - 0.25 * d.z]
        };
        core::array::from_fn(|c| clean[c] + amount * jitter(step, i, c))
    })
}

/// A layout probe's lines: its sensors and directions, an update, a stream of `pool` calls
/// ([`LAYOUT_STREAM`]; `stream` false: the update only), then its errors. `noise_amount`:
/// the readings' noise.
fn layout_case<const K: usize>(
    name: &str,
    sensors: &[Sensor; K],
    prior: Prior,
    noise: Noise,
    hazard: f32,
    noise_amount: f32,
    stream: bool,
) {
    let out = |key: &str, step: usize, vs: &mut dyn Iterator<Item = f32>| {
        for (i, v) in vs.enumerate() {
            println!("l_{key} {name}.{step} {i} {:08x}", v.to_bits());
        }
    };
    // The sensors as the package takes them: directions, cosine powers, noise scales.
    let power = |s: &Sensor| match s.response {
        Response::CosinePower(p) => p,
        _ => f32::NAN,
    };
    out(
        "sensor",
        0,
        &mut sensors.iter().flat_map(|s| [s.direction.x, s.direction.y, s.direction.z]),
    );
    out("sensor", 1, &mut sensors.iter().map(power));
    out("sensor", 2, &mut sensors.iter().map(|s| s.noise_scale));
    let probe =
        LayoutProbe::<K, [f32; 3]>::new(sensors, prior, noise).and_then(|p| p.with_hazard(hazard));
    let mut probe = match probe {
        Ok(p) => p,
        Err(e) => {
            println!("l_new {name}.0 0 {e:?}");
            return;
        }
    };
    println!("l_new {name}.0 0 ok");
    let xyz = |ds: &[Vec3; K]| ds.iter().flat_map(|d| [d.x, d.y, d.z]).collect::<Vec<_>>();
    out("dir", 0, &mut xyz(probe.directions()).into_iter());
    let state = |step: usize, p: &LayoutProbe<K, [f32; 3]>| {
        println!("l_state {name}.{step} 0 {K}");
        println!("l_state {name}.{step} 1 {}", p.is_updated());
        let [sr, sg, sb] = p.signal_variance();
        let floats = [p.pooled_updates(), p.last_change_probability(), sr, sg, sb];
        out("state", step, &mut floats.into_iter());
    };
    let queries = |step: usize, p: &LayoutProbe<K, [f32; 3]>| {
        for (i, q) in LAYOUT_NORMALS.iter().enumerate() {
            let n = Vec3::new(q[0], q[1], q[2]);
            if let Ok(e) = p.irradiance(n) {
                out(&format!("irr{i}"), step, &mut e.value.into_iter().chain(e.variance));
            }
            if let Ok(v) = p.irradiance_variance(n) {
                out(&format!("irrvar{i}"), step, &mut v.into_iter());
            }
        }
    };
    let lobes = |step: usize, p: &LayoutProbe<K, [f32; 3]>| {
        for (i, (a, e)) in LAYOUT_PHONG.iter().enumerate() {
            if let Ok(est) = p.phong(Vec3::new(a[0], a[1], a[2]), *e) {
                out(&format!("phong{i}"), step, &mut est.value.into_iter().chain(est.variance));
            }
        }
        out("sh", step, &mut p.radiance_sh().coefficients.into_iter().flatten());
    };
    state(0, &probe);
    queries(0, &probe);
    out("sh", 0, &mut probe.radiance_sh().coefficients.into_iter().flatten());
    // An update, then (`stream`) `pool` calls: of the first light, then of the second.
    let dirs = *probe.directions();
    let readings = layout_readings(&dirs, 0, 0, noise_amount);
    out("reading", 1, &mut readings.iter().flatten().copied());
    println!("l_update {name}.1 0 {:?}", probe.update(&readings).err());
    state(1, &probe);
    queries(1, &probe);
    lobes(1, &probe);
    let mut step = 1;
    if stream {
        for (light, &count) in LAYOUT_STREAM.iter().enumerate() {
            for k in 0..count {
                step += 1;
                let readings = layout_readings(&dirs, light, step, noise_amount);
                out("reading", step, &mut readings.iter().flatten().copied());
                let change = match probe.pool(&readings) {
                    Ok(c) => format!("{c:?}").to_lowercase(),
                    Err(e) => format!("{e:?}"),
                };
                println!("l_change {name}.{step} 0 {change}");
                state(step, &probe);
                queries(step, &probe);
                if k + 1 == count {
                    lobes(step, &probe);
                }
            }
        }
    }
    // Errors: a refused `update` or `pool` keeps the state.
    let mut bad = layout_readings(&dirs, 0, step + 1, noise_amount);
    bad[K / 2][1] = f32::NAN;
    println!("l_err {name}.{step} 0 {:?}", probe.update(&bad).err());
    bad[K / 2][1] = f32::INFINITY;
    println!("l_err {name}.{step} 1 {:?}", probe.pool(&bad).err());
    state(step + 1, &probe);
    queries(step + 1, &probe);
    println!("l_err {name}.{step} 2 {:?}", probe.irradiance(Vec3::ZERO).err());
    println!(
        "l_err {name}.{step} 3 {:?}",
        probe.irradiance_variance(Vec3::new(f32::NAN, 0.0, 1.0)).err()
    );
    println!("l_err {name}.{step} 4 {:?}", probe.phong(Vec3::Z, -1.0).err());
    println!("l_err {name}.{step} 5 {:?}", probe.phong(Vec3::ZERO, 2.0).err());
}

/// The layout probes of the package's layout module: a cube of six sensors (two responses,
/// one noisier sensor) under the learned environment prior, a dome of five (the zenith and
/// four at 45° elevation) under the sky-above prior, streams of both, the cube under the
/// other priors, and refused layouts.
fn layouts() {
    let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    let powers = [1.0, 1.0, 1.0, 1.0, 2.0, 2.0];
    let scales = [1.0, 1.0, 1.0, 1.0, 1.0, 1.5];
    let cube: [Sensor; 6] = core::array::from_fn(|i| {
        Sensor::new(faces[i], Response::CosinePower(powers[i])).with_noise_scale(scales[i])
    });
    // Dyadic noise levels and hazards: the same f32 from a JavaScript number.
    let cube_noise = Noise { absolute: 1.0 / 64.0, relative: 1.0 / 32.0 };
    layout_case("cube6", &cube, Prior::ENVIRONMENT, cube_noise, 1.0 / 64.0, 0.01, true);
    let dome_dirs = [
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(-1.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
        Vec3::new(0.0, -1.0, 1.0),
    ];
    let dome = dome_dirs.map(Sensor::cosine);
    let dome_noise = Noise { absolute: 3.0 / 128.0, relative: 0.0 };
    layout_case("dome5", &dome, Prior::SKY_ABOVE, dome_noise, 1.0 / 32.0, 0.02, true);
    // The other priors: one update each.
    let priors = [
        ("smooth-environment", Prior::SMOOTH_ENVIRONMENT),
        ("smooth-sky-above", Prior::SMOOTH_SKY_ABOVE),
        ("se4", Prior::squared_exponential(4.0).unwrap_or(Prior::ENVIRONMENT)),
    ];
    for (prior_name, prior) in priors {
        layout_case(
            &format!("cube6-{prior_name}"),
            &cube,
            prior,
            cube_noise,
            1.0 / 64.0,
            0.01,
            false,
        );
    }
    // Refused layouts: a zero direction, more sensors than a layout may have, five distinct
    // responses, a bad noise, λ or hazard.
    let mut zero = cube;
    zero[2].direction = Vec3::ZERO;
    let new = |sensors: &[Sensor; 6], prior: Prior, noise: Noise, hazard: f32| {
        js_error(
            LayoutProbe::<6, [f32; 3]>::new(sensors, prior, noise)
                .and_then(|p| p.with_hazard(hazard))
                .err(),
        )
    };
    println!("l_bad zero 0 {:?}", new(&zero, Prior::ENVIRONMENT, cube_noise, 1.0 / 64.0));
    let many = [Sensor::cosine(Vec3::Z); 65];
    println!(
        "l_bad k65 0 {:?}",
        LayoutProbe::<65, [f32; 3]>::new(&many, Prior::ENVIRONMENT, cube_noise).err()
    );
    let mut five = cube;
    for (i, s) in five.iter_mut().enumerate() {
        s.response = Response::CosinePower(1.0 + i as f32);
    }
    println!("l_bad responses 0 {:?}", new(&five, Prior::ENVIRONMENT, cube_noise, 1.0 / 64.0));
    let negative = Noise { absolute: -1.0, relative: 0.0 };
    println!("l_bad noise 0 {:?}", new(&cube, Prior::ENVIRONMENT, negative, 1.0 / 64.0));
    println!("l_bad lambda 0 {:?}", js_error(Prior::squared_exponential(0.0).err()));
    println!("l_bad hazard 0 {:?}", new(&cube, Prior::ENVIRONMENT, cube_noise, 1.0));
    let mut scale = cube;
    scale[0].noise_scale = 0.0;
    println!("l_bad scale 0 {:?}", new(&scale, Prior::ENVIRONMENT, cube_noise, 1.0 / 64.0));
}

/// `e` as the JavaScript package names it: the crate's errors for an argument out of range
/// are all `InvalidParameter` there (`package-wasm/src/lib.rs`, `code`).
fn js_error(e: Option<Error>) -> Option<JsError> {
    e.map(|e| if e.is_out_of_range() { JsError::InvalidParameter } else { JsError::Crate(e) })
}

/// An error name of the JavaScript package.
enum JsError {
    InvalidParameter,
    Crate(Error),
}

impl core::fmt::Debug for JsError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            JsError::InvalidParameter => f.write_str("InvalidParameter"),
            JsError::Crate(e) => e.fmt(f),
        }
    }
}

/// The host reference of the JavaScript package's Node test: every baked size, two rotation
/// seeds, directions, queries with variances, SH coefficients and error names, one value per
/// line on stdout (`cargo eval js_package_reference > reference.txt`).
#[derive(Parser)]
#[command(bin_name = "cargo eval js_package_reference", verbatim_doc_comment)]
struct Args {}

fn main() {
    let Args {} = Args::parse();
    run::<16>();
    run::<32>();
    run::<64>();
    run::<128>();
    run::<256>();
    temporal::<16, 15, 1, 2>();
    temporal::<32, 31, 1, 4>();
    temporal::<64, 62, 2, 8>();
    temporal::<128, 125, 3, 16>();
    temporal::<256, 252, 4, 32>();
    layouts();
}
