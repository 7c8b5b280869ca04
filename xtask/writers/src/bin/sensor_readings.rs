//! Simulated photodiode readings for the Cortex-M4 sensor scenario (issue #11, item 5).
//!
//! ```text
//! cargo writer sensor_readings             # check the committed file, report
//! cargo writer sensor_readings -- --write  # regenerate it
//! cargo xtask regen sensor-readings        # regenerate it, in the pipeline's order
//! ```
//!
//! A bare photodiode with a cosine response reads `Yᵢ = ∫ L(x)·max(0, xᵢ·x)/π dx`: the
//! irradiance at normal `xᵢ` divided by π, the sample that
//! `Probe<N, [f32; 3], CosinePower<1>>` models. This program takes the readings of 16 and 32
//! such sensors in the unrotated probe directions (`Probe::new().directions()`) from the
//! bundled map `examples/envmaps/apartment.hdr`, with the exact per-pixel integration of
//! `reference::truth::irradiance` in f64 (the map's nearest-pixel radiance, no clamping: a
//! sensor integrates, so bright lamps need no special treatment), rounds them once to f32 and
//! emits their bits into `examples/cortex-m4/src/sensor_readings.rs`, with eight query
//! normals (not sample directions) and the exact irradiance there. The device and its host
//! twin (`eval/src/bin/device_scenario.rs`) update the two probes with these readings and print
//! irradiance, both variances and the relative error at the query normals as exact bits.
//!
//! Without `--write` it regenerates in memory, fails if the committed file differs (CI runs
//! it that way), and prints the same probes' errors against the truth in decimal: what the
//! device computes, since both sides are bit-identical.
//!
//! For the sensor-layout probe (`LayoutProbe`) it also emits noisy readings: six cosine
//! photodiodes on the faces of a cube (`±x`, `±y`, `±z`) and the 16 directions above, each
//! exact reading multiplied (in f64, before the one rounding) by `1 + 0.01·g`, `g` an
//! approximately standard normal deviate (the sum of twelve uniforms minus six) from a fixed
//! seed (SplitMix64): a multiplicative noise of 1 %, the same on every run and platform. The
//! report then prints the layout probes' errors (`Prior::ENVIRONMENT`, a relative noise of
//! 1 %) next to the same peers.
//!
//! The unrotated probe directions do not depend on the math backend (`sqrt` is always `libm`,
//! the azimuth comes from the crate's own polynomials), so one file serves both backends; the
//! check passes with `--no-default-features --features micromath` too.

use std::fmt::Write as _;
use std::process::ExitCode;

use clap::Parser;
use reference::envmap::EnvMap;
use sphere_quadrature::footprint::CosinePower;
use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
use sphere_quadrature::probe::{cosine_weighted_average, Probe, ProbeTables};
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::{bmc::Size, Vec3};
use sphere_quadrature_eval::cli;

/// The bundled map the sensors see (in `examples/envmaps/`).
const MAP: &str = "apartment";

/// The generated file, relative to the repository root.
const OUT: &str = "examples/cortex-m4/src/sensor_readings.rs";

/// Query normals: not unit (the probe normalises), none a sample direction of N = 16 or 32.
const NORMALS: [[f32; 3]; 8] = [
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
    [1.0, 0.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.3, -0.4, 0.5],
    [-0.7, 0.7, 0.1],
    [0.2, 0.9, -0.3],
    [-0.5, -0.5, -0.5],
];

/// The cube's six face normals, in the order of the cube readings.
const CUBE: [[f32; 3]; 6] = [
    [1.0, 0.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
];

/// The relative standard deviation of the layout readings' noise.
const RELATIVE_NOISE: f64 = 0.01;

/// The seed of the layout readings' noise.
const SEED: u64 = 0x5eed_1a70_u64;

/// SplitMix64: a deterministic stream of 64-bit words.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1), 53 bits.
    fn uniform(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Mean 0, variance 1: the sum of twelve uniforms minus six (exact in f64, no
    /// transcendental function, so the same bits on every platform).
    fn normal(&mut self) -> f64 {
        (0..12).map(|_| self.uniform()).sum::<f64>() - 6.0
    }
}

/// The Phong exponent of the scenario's glossy query (its axis is `(0.3, -0.4, 0.5)`).
const GLOSSY_EXPONENT: f32 = 5.0;

fn to_f64(v: Vec3) -> [f64; 3] {
    [f64::from(v.x), f64::from(v.y), f64::from(v.z)]
}

/// The exact irradiance of the map at `n`, per channel, rounded once to f32.
fn irradiance(map: &EnvMap, n: [f64; 3]) -> [f32; 3] {
    reference::truth::irradiance(map, n).map(|e| e as f32)
}

/// Exact readings `E(xᵢ)/π` (f64) of cosine photodiodes at `directions`.
fn exact_readings<const N: usize>(map: &EnvMap, directions: &[Vec3; N]) -> [[f64; 3]; N] {
    directions
        .map(|x| reference::truth::irradiance(map, to_f64(x)).map(|e| e / std::f64::consts::PI))
}

/// The directions of the unrotated `N`-sample photodiode probe.
fn probe_directions<const N: usize>() -> [Vec3; N]
where
    Size<N>: ProbeTables<CosinePower<1>>,
{
    *Probe::<N, [f32; 3], CosinePower<1>>::new().directions()
}

/// Readings rounded once to f32.
fn rounded<const N: usize>(exact: &[[f64; 3]; N]) -> [[f32; 3]; N] {
    exact.map(|r| r.map(|v| v as f32))
}

/// Readings with the multiplicative noise `1 + RELATIVE_NOISE·g` (one `g` per sensor and
/// channel, in order), rounded once to f32.
fn noisy<const N: usize>(exact: &[[f64; 3]; N], rng: &mut SplitMix) -> [[f32; 3]; N] {
    exact.map(|r| r.map(|v| (v * (1.0 + RELATIVE_NOISE * rng.normal())) as f32))
}

/// One `[f32; 3]` row as exact bits, with its decimal value on the line above.
fn emit_row(s: &mut String, label: &str, v: [f32; 3]) {
    let _ = writeln!(s, "    // {label}: {}, {}, {}", v[0], v[1], v[2]);
    let bits = v.map(|x| {
        let b = x.to_bits();
        format!("f32::from_bits(0x{:04x}_{:04x})", b >> 16, b & 0xffff)
    });
    let _ = writeln!(s, "    [{}, {}, {}],", bits[0], bits[1], bits[2]);
}

fn emit_table(s: &mut String, doc: &str, name: &str, rows: &[[f32; 3]]) {
    let _ = writeln!(s, "\n{doc}");
    let _ = writeln!(s, "pub static {name}: [[f32; 3]; {}] = [", rows.len());
    for (i, &r) in rows.iter().enumerate() {
        emit_row(s, &i.to_string(), r);
    }
    let _ = writeln!(s, "];");
}

/// The readings the generated file holds.
struct Readings {
    r16: [[f32; 3]; 16],
    r32: [[f32; 3]; 32],
    cube: [[f32; 3]; 6],
    noisy16: [[f32; 3]; 16],
    truth: [[f32; 3]; 8],
}

/// The whole generated file.
fn generate(r: &Readings) -> String {
    let mut s = String::new();
    s.push_str(
        "// @generated by `cargo xtask regen sensor-readings`; do not edit.\n\
         // `cargo writer sensor_readings` checks that this file is current.\n\
         \n",
    );
    let _ = writeln!(
        s,
        "//! Simulated photodiode readings of `examples/envmaps/{MAP}.hdr` for the sensor\n\
         //! scenario (`scenario.rs`): `Yᵢ = E(xᵢ)/π` per RGB channel, `E` the exact irradiance of the\n\
         //! map's nearest-pixel radiance (`reference::truth::irradiance`, f64, rounded once to f32),\n\
         //! `xᵢ` the directions of the unrotated `Probe::<N, [f32; 3], CosinePower<1>>`; and the\n\
         //! exact irradiance at the query normals. For the layout probe, readings of six photodiodes\n\
         //! on a cube's faces and of the 16 above with a multiplicative noise of 1 % (fixed seed).\n\
         //! See `xtask/writers/src/bin/sensor_readings.rs`."
    );
    let _ = writeln!(s, "\nuse sphere_quadrature::Vec3;");
    emit_table(
        &mut s,
        "/// Readings of the 16 photodiodes of `Probe::<16, [f32; 3], CosinePower<1>>::new()`.",
        "READINGS_16",
        &r.r16,
    );
    emit_table(
        &mut s,
        "/// Readings of the 32 photodiodes of `Probe::<32, [f32; 3], CosinePower<1>>::new()`.",
        "READINGS_32",
        &r.r32,
    );
    let _ = writeln!(s, "\n/// The cube's face normals, in the order of [`CUBE_READINGS`].");
    let _ = writeln!(s, "pub const CUBE: [Vec3; {}] = [", CUBE.len());
    for n in CUBE {
        let _ = writeln!(s, "    Vec3::new({:?}, {:?}, {:?}),", n[0], n[1], n[2]);
    }
    let _ = writeln!(s, "];");
    emit_table(
        &mut s,
        "/// Readings of six photodiodes on the faces of a cube ([`CUBE`]), noise of 1 %.",
        "CUBE_READINGS",
        &r.cube,
    );
    emit_table(
        &mut s,
        "/// Readings of the photodiodes of [`READINGS_16`], noise of 1 %.",
        "NOISY_READINGS_16",
        &r.noisy16,
    );
    let _ = writeln!(s, "\n/// Query normals (not unit; none is a sample direction).");
    let _ = writeln!(s, "pub const NORMALS: [Vec3; {}] = [", NORMALS.len());
    for n in NORMALS {
        let _ = writeln!(s, "    Vec3::new({:?}, {:?}, {:?}),", n[0], n[1], n[2]);
    }
    let _ = writeln!(s, "];");
    emit_table(
        &mut s,
        "/// The exact irradiance at [`NORMALS`] (normalised), per channel.",
        "IRRADIANCE",
        &r.truth,
    );
    s
}

/// Relative errors and error bars of the probe at the query normals, as the device computes
/// them, in decimal.
fn report<const N: usize>(
    readings: &[[f32; 3]; N],
    truth: &[[f32; 3]; 8],
    glossy_truth: [f64; 3],
) -> Result<(), String>
where
    Size<N>: ProbeTables<CosinePower<1>>,
{
    let mut p = Probe::<N, [f32; 3], CosinePower<1>>::new();
    p.update(readings).map_err(|e| format!("N = {N}: update: {e}"))?;
    let lambda =
        Probe::<N, [f32; 3], CosinePower<1>>::member(p.selected()).map_or(0.0, |m| m.lambda);
    println!("N = {N} photodiodes: member {} (λ = {lambda})", p.selected());
    println!(
        "  normal                 rel. error R, G, B               |error|/σ (exact σ) R, G, B"
    );
    let (mut sum, mut worst, mut count, mut within) = (0.0f64, 0.0f64, 0, 0);
    let (mut peer_sum, mut peer_worst) = (0.0f64, 0.0f64);
    let (mut nearest_sum, mut nearest_worst) = (0.0f64, 0.0f64);
    for (n, t) in NORMALS.iter().zip(truth) {
        let normal = Vec3::new(n[0], n[1], n[2]);
        let e = p.irradiance(normal).map_err(|e| format!("irradiance: {e}"))?;
        let var = p.irradiance_variance(normal).map_err(|e| format!("variance: {e}"))?;
        let peer = cosine_weighted_average(p.directions(), readings, normal)
            .map_err(|e| format!("peer: {e}"))?;
        // The sensor whose normal is closest: E ≈ π·Y.
        let unit = normal.try_normalize().unwrap_or(Vec3::Z);
        let nearest = p
            .directions()
            .iter()
            .zip(readings)
            .max_by(|a, b| a.0.dot(unit).total_cmp(&b.0.dot(unit)))
            .map_or([0.0; 3], |(_, y)| *y);
        let mut rel = [0.0f64; 3];
        let mut z = [0.0f64; 3];
        for c in 0..3 {
            let err = f64::from(e.value[c]) - f64::from(t[c]);
            rel[c] = err / f64::from(t[c]);
            z[c] = err.abs() / f64::from(var[c]).sqrt();
            sum += rel[c].abs();
            worst = worst.max(rel[c].abs());
            count += 1;
            within += usize::from(z[c] <= 2.0);
            let peer_rel = (f64::from(peer[c]) / f64::from(t[c]) - 1.0).abs();
            peer_sum += peer_rel;
            peer_worst = peer_worst.max(peer_rel);
            let nearest_rel =
                (std::f64::consts::PI * f64::from(nearest[c]) / f64::from(t[c]) - 1.0).abs();
            nearest_sum += nearest_rel;
            nearest_worst = nearest_worst.max(nearest_rel);
        }
        println!(
            "  {:>22} {:+9.2e} {:+9.2e} {:+9.2e}   {:6.2} {:6.2} {:6.2}",
            format!("({}, {}, {})", n[0], n[1], n[2]),
            rel[0],
            rel[1],
            rel[2],
            z[0],
            z[1],
            z[2]
        );
    }
    println!(
        "  mean |rel. error| {:.2e}, max {:.2e}; within 2σ (exact variance): {within} of {count}",
        sum / count as f64,
        worst
    );
    println!(
        "  peer (cosine-weighted average of the readings): mean |rel. error| {:.2e}, max {:.2e}",
        peer_sum / count as f64,
        peer_worst
    );
    println!(
        "  peer (π × the reading of the nearest sensor): mean |rel. error| {:.2e}, max {:.2e}",
        nearest_sum / count as f64,
        nearest_worst
    );
    // The scenario's glossy query: normalised Phong e = 5 (SG stand-in) about GLOSSY_AXIS.
    let lobe = SphericalGaussian::phong_moments(Vec3::new(0.3, -0.4, 0.5), GLOSSY_EXPONENT)
        .map_err(|e| format!("lobe: {e}"))?;
    let g = p.glossy(&lobe).map_err(|e| format!("glossy: {e}"))?;
    let rel = core::array::from_fn::<f64, 3, _>(|c| f64::from(g.value[c]) / glossy_truth[c] - 1.0);
    println!(
        "  glossy (Phong e = {GLOSSY_EXPONENT} about (0.3, -0.4, 0.5)): rel. error {:+.2e} {:+.2e} {:+.2e}",
        rel[0], rel[1], rel[2]
    );
    Ok(())
}

/// The layout probe's errors at the query normals, as the device computes them, in decimal:
/// `Prior::ENVIRONMENT`, a relative noise of 1 %; next to π × the nearest sensor's reading.
fn layout_report<const K: usize>(
    label: &str,
    directions: &[Vec3; K],
    readings: &[[f32; 3]; K],
    truth: &[[f32; 3]; 8],
) -> Result<(), String> {
    let sensors = directions.map(Sensor::cosine);
    let noise = Noise { absolute: 0.0, relative: RELATIVE_NOISE as f32 };
    let mut p = LayoutProbe::<K, [f32; 3]>::new(&sensors, Prior::ENVIRONMENT, noise)
        .map_err(|e| format!("{label}: new: {e}"))?;
    p.update(readings).map_err(|e| format!("{label}: update: {e}"))?;
    println!("{label}: LayoutProbe::<{K}, [f32; 3]>, Prior::ENVIRONMENT, relative noise 1 %");
    println!(
        "  normal                 rel. error R, G, B               |error|/σ (exact σ) R, G, B"
    );
    let (mut sum, mut worst, mut count, mut within) = (0.0f64, 0.0f64, 0, 0);
    let (mut nearest_sum, mut nearest_worst) = (0.0f64, 0.0f64);
    for (n, t) in NORMALS.iter().zip(truth) {
        let normal = Vec3::new(n[0], n[1], n[2]);
        let e = p.irradiance(normal).map_err(|e| format!("irradiance: {e}"))?;
        let var = p.irradiance_variance(normal).map_err(|e| format!("variance: {e}"))?;
        let unit = normal.try_normalize().unwrap_or(Vec3::Z);
        let nearest = directions
            .iter()
            .zip(readings)
            .max_by(|a, b| a.0.dot(unit).total_cmp(&b.0.dot(unit)))
            .map_or([0.0; 3], |(_, y)| *y);
        let mut rel = [0.0f64; 3];
        let mut z = [0.0f64; 3];
        for c in 0..3 {
            let err = f64::from(e.value[c]) - f64::from(t[c]);
            rel[c] = err / f64::from(t[c]);
            z[c] = err.abs() / f64::from(var[c]).sqrt();
            sum += rel[c].abs();
            worst = worst.max(rel[c].abs());
            count += 1;
            within += usize::from(z[c] <= 2.0);
            let nearest_rel =
                (std::f64::consts::PI * f64::from(nearest[c]) / f64::from(t[c]) - 1.0).abs();
            nearest_sum += nearest_rel;
            nearest_worst = nearest_worst.max(nearest_rel);
        }
        println!(
            "  {:>22} {:+9.2e} {:+9.2e} {:+9.2e}   {:6.2} {:6.2} {:6.2}",
            format!("({}, {}, {})", n[0], n[1], n[2]),
            rel[0],
            rel[1],
            rel[2],
            z[0],
            z[1],
            z[2]
        );
    }
    println!(
        "  mean |rel. error| {:.2e}, max {:.2e}; within 2σ (exact variance): {within} of {count}",
        sum / count as f64,
        worst
    );
    println!(
        "  peer (π × the reading of the nearest sensor): mean |rel. error| {:.2e}, max {:.2e}",
        nearest_sum / count as f64,
        nearest_worst
    );
    Ok(())
}

/// sensor_readings: the photodiode readings of the Cortex-M4 sensor scenario, checked against
/// (or, with --write, written to) examples/cortex-m4/src/sensor_readings.rs
#[derive(Parser)]
#[command(bin_name = "cargo writer sensor_readings --", verbatim_doc_comment)]
struct Args {
    /// Regenerate examples/cortex-m4/src/sensor_readings.rs instead of
    /// checking that it is current
    #[arg(long, verbatim_doc_comment)]
    write: bool,
}

fn main() -> ExitCode {
    let write = Args::parse().write;
    let root = cli::repo_root();
    let map = match EnvMap::load(root.join(format!("examples/envmaps/{MAP}.hdr"))) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("sensor_readings: {e}");
            return ExitCode::FAILURE;
        }
    };
    let d16 = probe_directions::<16>();
    let exact16 = exact_readings(&map, &d16);
    let cube_directions = CUBE.map(|n| Vec3::new(n[0], n[1], n[2]));
    let mut rng = SplitMix(SEED);
    let cube = noisy(&exact_readings(&map, &cube_directions), &mut rng);
    let noisy16 = noisy(&exact16, &mut rng);
    let r = Readings {
        r16: rounded(&exact16),
        r32: rounded(&exact_readings(&map, &probe_directions::<32>())),
        cube,
        noisy16,
        truth: NORMALS.map(|n| irradiance(&map, n.map(f64::from))),
    };
    let text = generate(&r);
    let path = root.join(OUT);
    if write {
        if let Err(e) = std::fs::write(&path, &text) {
            eprintln!("sensor_readings: {}: {e}", path.display());
            return ExitCode::FAILURE;
        }
        println!("wrote {OUT}");
    } else if std::fs::read_to_string(&path).ok().as_deref() != Some(text.as_str()) {
        eprintln!("sensor_readings: {OUT} is not current; run with --write");
        return ExitCode::FAILURE;
    } else {
        println!("{OUT} is current");
    }
    println!("map {MAP}: {}×{}", map.width, map.height);
    let glossy_truth = reference::truth::phong(&map, [0.3, -0.4, 0.5], f64::from(GLOSSY_EXPONENT));
    for result in [
        report(&r.r16, &r.truth, glossy_truth),
        report(&r.r32, &r.truth, glossy_truth),
        layout_report("cube, 6 photodiodes", &cube_directions, &r.cube, &r.truth),
        layout_report("16 photodiodes", &d16, &r.noisy16, &r.truth),
    ] {
        if let Err(e) = result {
            eprintln!("sensor_readings: {e}");
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}
