//! The host reference of the JavaScript package (`examples/wasm/package`): for every baked size
//! and two rotation seeds, the RGB probe's directions, fixed samples, then irradiance, glossy
//! radiance (both with variances), the SH coefficients and their variances, and the errors of
//! bad queries, as `key n seed index value` lines (values as f32 bits, errors by name); then,
//! for every size, a stream of temporal updates (static light, then a switch of light) of a
//! point and of a footprint temporal probe, as `t_key n stream.update index value` lines: the
//! directions, samples and sentinel readings of each update, what it did with the old
//! evidence, the state (updates, degree, effective updates, change probability, log Bayes
//! factors), irradiance with variance at fixed normals, and the SH coefficients and variances
//! at the end of each light. The package's Node test (`examples/wasm/package/test/test.mjs`)
//! feeds the same samples to the WebAssembly modules through the package and requires every
//! line to be equal.
//!
//! ```text
//! cargo eval js_package_reference > reference.txt
//! ```

use clap::Parser;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::footprint::{Footprint, Gaussian, Point};
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
        let floats = [p.effective_updates(), p.last_change_probability(), rotated, sentinels];
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
            let change = match probe.update(&samples, &sentinels) {
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
    println!("t_err {n} {stream}.{u} 0 {:?}", probe.update(&samples, &sentinels).err());
    samples[R / 2][1] = 1.0;
    let mut bad = sentinels;
    bad[S - 1][2] = f32::INFINITY;
    println!("t_err {n} {stream}.{u} 1 {:?}", probe.update(&samples, &bad).err());
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
}
