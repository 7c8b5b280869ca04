//! The host twin of the WebAssembly test (`examples/wasm/test.mjs`): prints the Cortex-M4
//! scenario, then the wasm module's scalar API (`examples/wasm/src/api.rs`, compiled natively
//! here) and the probe-style estimate on the same inputs, as `key index bits` lines, so
//! `.ci/run` can compare them with Node's output bit for bit.
//!
//! ```text
//! cargo eval wasm_scenario
//! ```

use sphere_quadrature_eval::{api, scenario};

use clap::Parser;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::footprint::{Footprint, Gaussian, Kind};
use sphere_quadrature::probe::{Probe, ProbeSize, ProbeTables};
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::{Error, Vec3};

struct Stdout;

impl scenario::Sink for Stdout {
    fn line(&mut self, args: std::fmt::Arguments<'_>) {
        println!("{args}");
    }
}

fn bits(v: f32) -> String {
    if v.is_nan() {
        "nan".into()
    } else {
        format!("{:08x}", v.to_bits())
    }
}

fn value(key: &str, index: usize, v: f32) {
    println!("{key} {index} {}", bits(v));
}

/// Same inputs as `test.mjs` (dyadic rationals: exact in f64 and f32).
const COUNT: usize = 27;

fn normal(i: usize) -> [f32; 3] {
    match i {
        24 => [0.0, 0.0, 0.0],
        25 => [f32::NAN, 0.0, 1.0],
        26 => [f32::INFINITY, 0.0, 0.0],
        _ => [
            ((i * 5) % 9) as f32 / 4.0 - 1.0,
            ((i * 7) % 11) as f32 / 4.0 - 1.25,
            ((i * 3) % 7) as f32 / 2.0 - 1.5,
        ],
    }
}

fn lo(i: usize) -> u32 {
    (i as u32).wrapping_mul(0x9e37_79b9)
}

fn hi(i: usize) -> u32 {
    (i as u32).wrapping_mul(0x85eb_ca6b)
}

fn exponent(i: usize) -> f32 {
    ((i % 8) * 8) as f32 - 4.0
}

/// wasm_scenario: the host twin of the WebAssembly test, as `key index bits` lines
/// (no options; `--features micromath` for that backend)
#[derive(Parser)]
#[command(bin_name = "cargo eval wasm_scenario", verbatim_doc_comment)]
struct Args {}

fn main() {
    Args::parse();
    scenario::run(&mut Stdout);

    for i in 0..COUNT {
        let [x, y, z] = normal(i);
        value("w_irr64", i, api::qmc_irradiance_64(x, y, z, lo(i), hi(i)));
        value("w_phong64", i, api::phong_64(x, y, z, exponent(i), lo(i), hi(i)));
        value("w_sky", i, api::sky(x, y, z));
        println!("w_nearest4096 {i} {}", api::nearest_index_4096(x, y, z));
    }

    let js = [0, 1, 17, 63, 64, 255, 256, 4095, 4096];
    for kind in 0..4 {
        for (jj, &j) in js.iter().enumerate() {
            for c in 0..4 {
                value(
                    &format!("w_sf{kind}"),
                    4 * jj + c as usize,
                    api::sf_point_component(kind, j, c),
                );
            }
        }
    }

    let lambdas = [0.0, 0.5, 1.0, 4.0, 16.0, 100.0, 1000.0, -1.0, f32::NAN, f32::INFINITY];
    let ts = [-1.0, -0.5, 0.0, 0.25, 1.0, 2.0, f32::NAN];
    for (li, &l) in lambdas.iter().enumerate() {
        for (ti, &t) in ts.iter().enumerate() {
            value("w_sghemi", li * ts.len() + ti, api::sg_hemispherical_fraction(l, t));
        }
    }

    // The probe style computed directly through the library: directions, sky, estimate.
    let sizes = [16u32, 64, 4096, 0, 5000];
    for i in 0..8 {
        let [x, y, z] = normal(i);
        for (ni, &n) in sizes.iter().enumerate() {
            let k = i * sizes.len() + ni;
            let Some(s) = api::probe_sampler(x, y, z, lo(i), hi(i), n) else {
                value("w_probe", k, f32::NAN);
                continue;
            };
            let dirs: Vec<_> = s.iter().collect();
            let ys: Vec<f32> = dirs.iter().map(|&d| scenario::sky(d)).collect();
            value("w_probe", k, s.estimate(&ys).unwrap_or(f32::NAN));
            let last = dirs[dirs.len() - 1];
            for (c, v) in [last.x, last.y, last.z].into_iter().enumerate() {
                value("w_probedir", 3 * k + c, v);
            }
        }
    }
    // The Bayesian Monte Carlo probe, kept as one value here (the module rebuilds it from its
    // seed and stored samples in every call): directions, RGB sky, update, irradiance.
    let seeds = [0u32, 1, 0xdead_beef];
    let normals = [0, 1, 2, 3, 4, 5, 6, 7, 24, 25, 26];
    // (normal index, Phong exponent); the last two are bad.
    let glossy = [(0, 5.0f32), (1, 20.0), (4, 100.0), (7, 0.0), (25, -1.0), (26, f32::NAN)];
    for (s, &seed) in seeds.iter().enumerate() {
        let (mut probe, code) = match api::bmc_probe(seed) {
            Ok(p) => (p, 0),
            Err(e) => (api::BmcProbe::new(), api::error_code(e)),
        };
        println!("w_bmc_reset {s} {code}");
        println!("w_bmc_selected {} {}", 3 * s, probe.selected());
        bmc_irradiance(&probe, "w_bmc_empty", s, normal(0));
        let dirs = *probe.directions();
        for (j, d) in dirs.iter().enumerate() {
            for (c, v) in [d.x, d.y, d.z].into_iter().enumerate() {
                value("w_bmc_dir", 3 * api::BMC_N * s + 3 * j + c, v);
            }
        }
        let mut samples = dirs.map(scenario::sky_rgb);
        println!("w_bmc_update {} {}", 3 * s, update_code(probe.update(&samples)));
        println!("w_bmc_selected {} {}", 3 * s + 1, probe.selected());
        for (ni, &i) in normals.iter().enumerate() {
            bmc_irradiance(&probe, "w_bmc_irr", normals.len() * s + ni, normal(i));
        }
        for (gi, &(i, e)) in glossy.iter().enumerate() {
            bmc_glossy(&probe, "w_bmc_glossy", glossy.len() * s + gi, normal(i), e);
        }
        let good = samples[17][1];
        samples[17][1] = f32::NAN;
        println!("w_bmc_update {} {}", 3 * s + 1, update_code(probe.update(&samples)));
        samples[17][1] = good;
        samples[40][2] = f32::NEG_INFINITY;
        println!("w_bmc_update {} {}", 3 * s + 2, update_code(probe.update(&samples)));
        println!("w_bmc_selected {} {}", 3 * s + 2, probe.selected());
        bmc_irradiance(&probe, "w_bmc_kept", s, normal(3));
    }
    // The batch form for every baked N, then its bad input.
    let mirror_of = |i: usize| if i >= 24 { 26 } else { (i + 7) % 24 };
    let queries: Vec<(usize, usize)> =
        [0, 1, 2, 3, 5, 24, 25].into_iter().map(|i| (i, mirror_of(i))).collect();
    shade::<16>(0, 7, &queries);
    shade::<32>(1, 8, &queries);
    shade::<64>(2, 9, &queries);
    shade::<128>(3, 10, &queries);
    shade::<256>(4, 11, &queries);
    // N = 17 has no baked family (the documented −1 and code 5); more than 1 024 queries is
    // the documented code 5; the other two come from the library.
    println!("w_shade_bad 0 -1");
    println!("w_shade_bad 1 {}", api::error_code(Error::InvalidSize));
    println!("w_shade_bad 2 {}", api::error_code(Error::InvalidSize));
    let exponent =
        SphericalGaussian::phong_moments(Vec3::Z, -1.0).map_or_else(api::error_code, |_| 0);
    println!("w_shade_bad 3 {exponent}");
    // The module's buffer holds the N = 256 sky of seed 11 (its first 16 samples), one NaN.
    let Ok(big) = api::bmc_probe_n::<256>(11) else { return };
    let mut ys: [[f32; 3]; 16] = core::array::from_fn(|j| scenario::sky_rgb(big.directions()[j]));
    ys[1][1] = f32::NAN;
    let nan = api::bmc_probe_n::<16>(1).and_then(|mut p| p.update(&ys));
    println!("w_shade_bad 4 {}", update_code(nan));
    footprints(&queries);
}

/// The batch form (`bmc_shade`) for one baked `N`: `(seed, queries)`, printed as the module
/// does (irradiance RGB, glossy RGB per query; NaN for a bad direction).
fn shade<const N: usize>(s: usize, seed: u32, queries: &[(usize, usize)])
where
    Size<N>: ProbeSize,
{
    let Ok(mut p) = api::bmc_probe_n::<N>(seed) else {
        println!("w_shade_dirs {s} -1");
        return;
    };
    println!("w_shade_dirs {s} {N}");
    let samples = p.directions().map(scenario::sky_rgb);
    let code = update_code(p.update(&samples));
    println!("w_shade_code {s} {code}");
    answer(&p, "w_shade", s, queries);
}

/// The queries of `bmc_shade`/`footprint_shade` (Phong exponent 20) as `key` values.
fn answer<const N: usize, F: Footprint>(
    p: &Probe<N, [f32; 3], F>,
    key: &str,
    s: usize,
    queries: &[(usize, usize)],
) where
    Size<N>: ProbeTables<F>,
{
    let v = |[x, y, z]: [f32; 3]| Vec3::new(x, y, z);
    for (k, &(i, j)) in queries.iter().enumerate() {
        let irr = p.irradiance(v(normal(i))).map_or([f32::NAN; 3], |e| e.value);
        let glossy = SphericalGaussian::phong_moments(v(normal(j)), 20.0)
            .and_then(|lobe| p.glossy(&lobe).map(|g| g.value))
            .unwrap_or([f32::NAN; 3]);
        for (c, x) in irr.into_iter().chain(glossy).enumerate() {
            value(key, 6 * queries.len() * s + 6 * k + c, x);
        }
    }
}

/// Width and height of the footprint test map (as `test.mjs`).
const MW: usize = 256;
const MH: usize = 128;

/// The footprint test map's pixel `(u, v)` (dyadic values, as `mapPixel` in `test.mjs`).
fn map_pixel(u: usize, v: usize) -> [f32; 3] {
    if (40..44).contains(&u) && (20..23).contains(&v) {
        return [64.0, 60.0, 48.0];
    }
    let base = if v < MH / 2 { 2.0 } else { 0.25 };
    [
        base + ((u * 3 + v * 5) % 16) as f32 / 16.0,
        base + ((u ^ v) & 7) as f32 / 8.0,
        base / 2.0 + (v % 4) as f32 / 4.0,
    ]
}

/// `map_footprint_samples` as the module runs it: the pyramid buffer has the module's size.
fn samples_code(
    map: &[[f32; 3]],
    size: (usize, usize),
    dirs: &[Vec3],
    sharpness: u32,
    sampler: u32,
    out: &mut [[f32; 3]],
) -> i32 {
    let mut pyramid = vec![[0.0f32; 3]; api::PYRAMID_MAX];
    let result = api::map_len(size.0, size.1).and_then(|len| {
        let pixels = map.get(..len).ok_or(sphere_quadrature::Error::InvalidSize)?;
        api::map_footprint_samples(pixels, size, dirs, sharpness, sampler, &mut pyramid, out)
    });
    result.map_or_else(api::error_code, |()| 0)
}

/// The footprint probe of one baked `N` (footprint `F`) on the test map: its sharpness and
/// directions, the pyramid's and the exact samples, then the queries of `bmc_shade`.
fn footprint<const N: usize, F: Footprint>(
    s: usize,
    seed: u32,
    map: &[[f32; 3]],
    queries: &[(usize, usize)],
) where
    Size<N>: ProbeTables<F>,
{
    let sharpness = match F::KIND {
        Kind::Gaussian { sharpness } => sharpness,
        _ => 0,
    };
    println!("w_fp_sharpness {s} {sharpness}");
    let Ok(mut p) = api::probe_nf::<N, F>(seed) else {
        println!("w_fp_dirs {s} -1");
        return;
    };
    println!("w_fp_dirs {s} {N}");
    let dirs = *p.directions();
    for (jj, d) in [dirs[0], dirs[N - 1]].into_iter().enumerate() {
        for (c, x) in [d.x, d.y, d.z].into_iter().enumerate() {
            value("w_fp_dir", 6 * s + 3 * jj + c, x);
        }
    }
    let mut exact = [[0.0f32; 3]; N];
    for sampler in [api::PYRAMID, api::EXACT] {
        let mut out = [[0.0f32; 3]; N];
        let code = samples_code(map, (MW, MH), &dirs, sharpness, sampler, &mut out);
        println!("w_fp_sample_code {} {code}", 2 * s + sampler as usize);
        for (k, &x) in out.iter().flatten().enumerate() {
            value(&format!("w_fp_sample{sampler}"), 3 * 256 * s + k, x);
        }
        if sampler == api::EXACT {
            exact = out;
        }
    }
    println!("w_fp_shade_code {s} {}", update_code(p.update(&exact)));
    answer(&p, "w_fp_shade", s, queries);
}

/// Section 6 of `test.mjs`: footprint probes of every baked `N` on the test map, nearest-pixel
/// samples, and bad input.
fn footprints(queries: &[(usize, usize)]) {
    // The module's map buffer: the test map, then zeros.
    let mut map = vec![[0.0f32; 3]; api::MAP_MAX];
    for v in 0..MH {
        for u in 0..MW {
            map[v * MW + u] = map_pixel(u, v);
        }
    }
    footprint::<16, Gaussian<2>>(0, 21, &map, queries);
    footprint::<32, Gaussian<4>>(1, 22, &map, queries);
    footprint::<64, Gaussian<8>>(2, 23, &map, queries);
    footprint::<128, Gaussian<16>>(3, 24, &map, queries);
    footprint::<256, Gaussian<32>>(4, 25, &map, queries);
    let Ok(dirs) = api::probe_nf::<16, Gaussian<2>>(21).map(|p| *p.directions()) else { return };
    let mut point = [[0.0f32; 3]; 16];
    println!(
        "w_fp_point_code 0 {}",
        samples_code(&map, (MW, MH), &dirs, 0, api::EXACT, &mut point)
    );
    for (k, &x) in point.iter().flatten().enumerate() {
        value("w_fp_point", k, x);
    }
    let mut out = [[0.0f32; 3]; 16];
    let mut sample = |map: &[[f32; 3]], size, dirs: &[Vec3], sharpness, sampler| {
        samples_code(map, size, dirs, sharpness, sampler, &mut out)
    };
    let invalid = api::error_code(Error::InvalidSize);
    // n = 17 has no footprint probe (the documented −1 and code 5), nor are more than 1 024
    // queries or samples taken (code 5); the rest comes from the library.
    let exponent = api::probe_nf::<16, Gaussian<2>>(1)
        .and_then(|mut p| p.update(&point))
        .and_then(|()| SphericalGaussian::phong_moments(Vec3::Z, -1.0).map(|_| ()));
    let mut zero = dirs;
    zero[1] = Vec3::ZERO;
    let mut nan = map.clone();
    nan[5][1] = f32::NAN;
    let bad: [String; 13] = [
        "-1".into(),
        "-1".into(),
        invalid.to_string(),
        invalid.to_string(),
        update_code(exponent).to_string(),
        sample(&map, (0, MH), &dirs, 2, api::EXACT).to_string(),
        sample(&map, (1024, 256), &dirs, 2, api::EXACT).to_string(),
        invalid.to_string(),
        sample(&map, (MW, MH), &dirs, 4097, api::EXACT).to_string(),
        sample(&map, (MW, MH), &dirs, 2, 2).to_string(),
        sample(&map, (16384, 8), &dirs, 2, api::PYRAMID).to_string(),
        format!(
            "{},{}",
            sample(&map, (MW, MH), &zero, 2, api::EXACT),
            sample(&map, (MW, MH), &zero, 2, api::PYRAMID)
        ),
        format!(
            "{},{}",
            sample(&nan, (MW, MH), &dirs, 2, api::EXACT),
            sample(&nan, (MW, MH), &dirs, 2, api::PYRAMID)
        ),
    ];
    for (k, code) in bad.iter().enumerate() {
        println!("w_fp_bad {k} {code}");
    }
    println!("w_fp_bad 13 {}", sample(&map, (16384, 8), &dirs, 2, api::EXACT));
    // The module's sample buffer now holds the 16384×8 map's samples; one NaN.
    let mut ys = out;
    ys[1][1] = f32::NAN;
    let nan_sample = api::probe_nf::<16, Gaussian<2>>(21).and_then(|mut p| p.update(&ys));
    println!("w_fp_bad 14 {}", update_code(nan_sample));
}

fn update_code(r: Result<(), sphere_quadrature::Error>) -> i32 {
    r.map_or_else(api::error_code, |()| 0)
}

/// `key_code k code`, then on success the six values `[r, g, b, var_r, var_g, var_b]`.
fn bmc_irradiance(probe: &api::BmcProbe, key: &str, k: usize, [x, y, z]: [f32; 3]) {
    match probe.irradiance(sphere_quadrature::Vec3::new(x, y, z)) {
        Ok(e) => {
            println!("{key}_code {k} 0");
            for (c, v) in e.value.into_iter().chain(e.variance).enumerate() {
                value(key, 6 * k + c, v);
            }
        }
        Err(e) => println!("{key}_code {k} {}", api::error_code(e)),
    }
}

/// `key_code k code`, then on success `[r, g, b, var_r, var_g, var_b]` of the Phong glossy
/// query (as the module's `bmc_probe_glossy`).
fn bmc_glossy(probe: &api::BmcProbe, key: &str, k: usize, [x, y, z]: [f32; 3], e: f32) {
    let result = sphere_quadrature::sg::SphericalGaussian::phong_moments(
        sphere_quadrature::Vec3::new(x, y, z),
        e,
    )
    .and_then(|lobe| Ok((probe.glossy(&lobe)?.value, probe.glossy_variance(&lobe)?)));
    match result {
        Ok((v, var)) => {
            println!("{key}_code {k} 0");
            for (c, x) in v.into_iter().chain(var).enumerate() {
                value(key, 6 * k + c, x);
            }
        }
        Err(e) => println!("{key}_code {k} {}", api::error_code(e)),
    }
}
