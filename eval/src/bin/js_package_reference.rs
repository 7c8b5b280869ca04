//! The host reference of the JavaScript package (`examples/wasm/package`): for every baked size
//! and two rotation seeds, the RGB probe's directions, fixed samples, then irradiance, glossy
//! radiance (both with variances), the SH coefficients and their variances, and the errors of
//! bad queries, as `key n seed index value` lines (values as f32 bits, errors by name). The
//! package's Node test (`examples/wasm/package/test/test.mjs`) feeds the same samples to the
//! WebAssembly modules through the package and requires every line to be equal.
//!
//! ```text
//! cargo eval js_package_reference > reference.txt
//! ```

use clap::Parser;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::probe::{Probe, ProbeSize};
use sphere_quadrature::sg::SphericalGaussian;
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
}
