//! The crate's headline on real environment maps: a lighting probe of N radiance samples,
//! point samples against footprint samples, Bayesian Monte Carlo against the cosine-weighted
//! average of the same samples, with the 2σ coverage of the probe's error bars.
//!
//! ```text
//! cargo run --release --example probe                   # two bundled maps
//! cargo run --release --example probe -- a.hdr b.hdr    # your own maps (Radiance RGBE)
//! ```
//!
//! For each map, luminance clamped at 30× the map's mean (suns and lamps are direct light
//! that a renderer samples on its own), eight probes in random orientations answer the
//! irradiance of 64 random normals each. Point samples read the map's pixel in each
//! direction; footprint samples read it through a normalised spherical-Gaussian lobe of
//! sharpness N/8 (`footprint::Gaussian<S>`), as a mip level, a cone or a light sensor would.
//! The truth sums every pixel. Printed: the relative RMSE of luminance (RMSE / mean truth)
//! and, for BMC, the fraction of queries whose error is within two posterior standard
//! deviations (the error bar of `Probe::irradiance`, luminance via `Probe::combine`).

// The comparison code shared with the other examples; only part of it is used here.
#[path = "common/compare.rs"]
#[allow(dead_code)]
mod compare;

use std::path::{Path, PathBuf};

use compare::{clamped, truths, weights, Kind};
use reference::envmap::EnvMap;
use reference::rng::Rng;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::envmap::EquirectMap;
use sphere_quadrature::footprint::{Footprint, Gaussian, Point};
use sphere_quadrature::probe::{Probe, ProbeTables};
use sphere_quadrature::{Mat3, Vec3};

const NORMALS: usize = 64;
const ROTATIONS: usize = 8;
const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];
const DEFAULT_MAPS: [&str; 2] = ["apartment", "city"];

/// Squared errors of BMC and of the cosine-weighted average, Σ truth, count, 2σ hits.
#[derive(Default)]
struct Sums {
    bmc: f64,
    average: f64,
    truth: f64,
    count: usize,
    within: usize,
}

impl Sums {
    fn relative(&self, squares: f64) -> f64 {
        (squares / self.count as f64).sqrt() / (self.truth / self.count as f64)
    }
}

fn v32(d: [f64; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

fn luminance(c: [f32; 3]) -> f64 {
    (0..3).map(|i| f64::from(LUMA[i]) * f64::from(c[i])).sum()
}

/// Probes of footprint `F` in every rotation, each answering every normal.
fn run<const N: usize, F: Footprint>(
    map: &EquirectMap,
    normals: &[[f64; 3]],
    truth: &[f64],
    rotations: &[Mat3],
) -> Sums
where
    Size<N>: ProbeTables<F>,
{
    let mut sums = Sums::default();
    for &rotation in rotations {
        let mut probe = Probe::<N, [f32; 3], F>::new();
        probe.set_rotation(rotation).expect("a random rotation is orthonormal");
        let mut samples = [[0.0f32; 3]; N];
        map.footprint_samples(probe.directions(), F::KIND, &mut samples).expect("unit directions");
        probe.update(&samples).expect("finite samples");
        for (&n, &t) in normals.iter().zip(truth) {
            let e = probe.irradiance(v32(n)).expect("unit normal");
            let y = probe.combine(&e, LUMA).expect("finite weights");
            // The cosine-weighted average of the same samples, times π.
            let (mut num, mut den) = (0.0, 0.0);
            for (d, s) in probe.directions().iter().zip(&samples) {
                let w = f64::from(d.dot(v32(n)).max(0.0));
                num += w * luminance(*s);
                den += w;
            }
            let average = if den > 0.0 { std::f64::consts::PI * num / den } else { 0.0 };
            let error = f64::from(y.value) - t;
            sums.bmc += error * error;
            sums.average += (average - t).powi(2);
            sums.truth += t.abs();
            sums.count += 1;
            sums.within += usize::from(error.abs() <= 2.0 * f64::from(y.variance).sqrt());
        }
    }
    sums
}

fn row(n: usize, point: &Sums, footprint: &Sums) {
    let cell = |s: &Sums| {
        format!(
            "{:>11.2} % {:>7.2} % {:>4.0} %",
            100.0 * s.relative(s.average),
            100.0 * s.relative(s.bmc),
            100.0 * s.within as f64 / s.count as f64
        )
    };
    println!("{n:>4} {}    {}", cell(point), cell(footprint));
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/envmaps");
    let paths: Vec<PathBuf> = if args.is_empty() {
        DEFAULT_MAPS.iter().map(|n| dir.join(format!("{n}.hdr"))).collect()
    } else {
        args.iter().map(PathBuf::from).collect()
    };
    let mut rng = Rng::new(2024);
    let normals: Vec<[f64; 3]> = (0..NORMALS).map(|_| rng.uniform_sphere()).collect();
    let rotations: Vec<Mat3> = (0..ROTATIONS)
        .map(|_| {
            let m = rng.uniform_rotation();
            Mat3::from_rows(v32(m[0]), v32(m[1]), v32(m[2]))
        })
        .collect();
    for path in &paths {
        let raw = EnvMap::load(path).unwrap_or_else(|e| {
            eprintln!("cannot load {}: {e}", path.display());
            std::process::exit(1);
        });
        let map = clamped(&raw);
        let truth = truths(&map, &weights(Kind::Diffuse, &normals, map.width, map.height));
        let map = EquirectMap::new(map.width, map.height, &map.pixels).expect("a valid map");
        let name = path.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        println!(
            "\n{name}, luminance clamped at 30× its mean: irradiance error (relative RMSE) of \
             {NORMALS} normals × {ROTATIONS} probe rotations"
        );
        println!("       point samples                  footprint samples, S = N/8");
        println!("   N     cosine avg       BMC    2σ       cosine avg       BMC    2σ");
        let t = &truth;
        row(
            16,
            &run::<16, Point>(&map, &normals, t, &rotations),
            &run::<16, Gaussian<2>>(&map, &normals, t, &rotations),
        );
        row(
            64,
            &run::<64, Point>(&map, &normals, t, &rotations),
            &run::<64, Gaussian<8>>(&map, &normals, t, &rotations),
        );
    }
}
