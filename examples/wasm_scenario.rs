//! The host twin of the WebAssembly test (`examples/wasm/test.mjs`): prints the Cortex-M4
//! scenario, then the wasm module's scalar API (`examples/wasm/src/api.rs`, compiled natively
//! here) and the probe-style estimate on the same inputs, as `key index bits` lines, so
//! `.ci/run` can compare them with Node's output bit for bit.
//!
//! ```text
//! cargo run --release --example wasm_scenario
//! ```

#[path = "cortex-m4/src/scenario.rs"]
mod scenario;

#[path = "wasm/src/api.rs"]
mod api;

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

fn main() {
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
    // N = 17 has no baked family (the documented −1 and code 3); more than 1 024 queries is
    // the documented code 3; the other two come from the library.
    use sphere_quadrature::{sg::SphericalGaussian, Error, Vec3};
    println!("w_shade_bad 0 -1");
    println!("w_shade_bad 1 {}", api::error_code(Error::InvalidParameter));
    println!("w_shade_bad 2 {}", api::error_code(Error::InvalidParameter));
    let exponent =
        SphericalGaussian::phong_moments(Vec3::Z, -1.0).map_or_else(api::error_code, |_| 0);
    println!("w_shade_bad 3 {exponent}");
    // The module's buffer holds the N = 256 sky of seed 11 (its first 16 samples), one NaN.
    let Ok(big) = api::bmc_probe_n::<256>(11) else { return };
    let mut ys: [[f32; 3]; 16] = core::array::from_fn(|j| scenario::sky_rgb(big.directions()[j]));
    ys[1][1] = f32::NAN;
    let nan = api::bmc_probe_n::<16>(1).and_then(|mut p| p.update(&ys));
    println!("w_shade_bad 4 {}", update_code(nan));
}

/// The batch form (`bmc_shade`) for one baked `N`: `(seed, queries)`, printed as the module
/// does (irradiance RGB, glossy RGB per query; NaN for a bad direction).
fn shade<const N: usize>(s: usize, seed: u32, queries: &[(usize, usize)])
where
    sphere_quadrature::bmc::Size<N>: sphere_quadrature::probe::ProbeSize,
{
    use sphere_quadrature::{sg::SphericalGaussian, Vec3};
    let Ok(mut p) = api::bmc_probe_n::<N>(seed) else {
        println!("w_shade_dirs {s} -1");
        return;
    };
    println!("w_shade_dirs {s} {N}");
    let samples = p.directions().map(scenario::sky_rgb);
    let code = update_code(p.update(&samples));
    println!("w_shade_code {s} {code}");
    let v = |[x, y, z]: [f32; 3]| Vec3::new(x, y, z);
    for (k, &(i, j)) in queries.iter().enumerate() {
        let irr = p.irradiance(v(normal(i))).map_or([f32::NAN; 3], |e| e.value);
        let glossy = SphericalGaussian::phong_moments(v(normal(j)), 20.0)
            .and_then(|lobe| p.glossy(&lobe).map(|g| g.value))
            .unwrap_or([f32::NAN; 3]);
        for (c, x) in irr.into_iter().chain(glossy).enumerate() {
            value("w_shade", 6 * queries.len() * s + 6 * k + c, x);
        }
    }
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
