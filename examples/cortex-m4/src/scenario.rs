//! The computation run both on the emulated Cortex-M4 and on the host. Every value is
//! printed as `key index bits` with the exact f32 bits (NaN as `nan`), so the two outputs
//! can be compared line by line. Shared with the host through `#[path]` (`eval/src/lib.rs`,
//! for `eval/src/bin/device_scenario.rs`); `no_std`, no allocation.
//!
//! The photodiode readings of the sensor part (and the noisy ones of the sensor-layout part)
//! are generated on the host (`xtask/writers/src/bin/sensor_readings.rs`) into `sensor_readings.rs`,
//! next to this file.

use core::fmt::Arguments;

// Relative to this file's directory, so the host twin finds it through its `#[path]` too.
#[path = "sensor_readings.rs"]
pub mod sensor_readings;

use sphere_quadrature::footprint::{CosinePower, Point};
use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
use sphere_quadrature::qmc::{self, LobeSampler};
use sphere_quadrature::{bmc, probe, sg};
use sphere_quadrature::{
    math, Error, HemisphericalFibonacci, Lobe, RotationSequence, SphericalFibonacci, Vec3,
};

/// Where the lines go: semihosting on the device, stdout on the host.
pub trait Sink {
    /// Writes one line.
    fn line(&mut self, args: Arguments<'_>);
}

fn value(out: &mut impl Sink, key: &str, index: usize, v: f32) {
    if v.is_nan() {
        out.line(format_args!("{key} {index} nan"));
    } else {
        out.line(format_args!("{key} {index} {:08x}", v.to_bits()));
    }
}

fn vector(out: &mut impl Sink, key: &str, index: usize, v: Vec3) {
    value(out, key, 3 * index, v.x);
    value(out, key, 3 * index + 1, v.y);
    value(out, key, 3 * index + 2, v.z);
}

fn error(out: &mut impl Sink, key: &str, r: Result<f32, Error>) {
    match r {
        Ok(v) => value(out, key, 0, v),
        Err(e) => out.line(format_args!("{key} 0 error {e:?}")),
    }
}

/// A procedural sky: a soft gradient and a spherical-Gaussian sun.
pub fn sky(d: Vec3) -> f32 {
    let up = if d.z > 0.0 { d.z } else { 0.0 };
    let sun = Vec3::new(0.3, 0.2, 0.9).try_normalize().unwrap_or(Vec3::Z);
    0.4 + 0.6 * up * up + 2.0 * math::exp(8.0 * (d.dot(sun) - 1.0))
}

/// RGB version of the sky.
pub fn sky_rgb(d: Vec3) -> [f32; 3] {
    let l = sky(d);
    [l, 0.9 * l + 0.05 * d.x, 0.8 * l]
}

/// Eight fixed normals (not unit: the estimators normalise).
pub const NORMALS: [Vec3; 8] = [
    Vec3::new(0.0, 0.0, 1.0),
    Vec3::new(0.0, 0.0, -1.0),
    Vec3::new(1.0, 0.0, 0.0),
    Vec3::new(0.3, -0.4, 0.5),
    Vec3::new(-0.7, 0.7, 0.1),
    Vec3::new(0.2, 0.9, -0.3),
    Vec3::new(-0.5, -0.5, -0.5),
    Vec3::new(0.01, 0.0, 1.0),
];

/// Runs the scenario.
pub fn run(out: &mut impl Sink) {
    // Point sets.
    for (j, p) in SphericalFibonacci::<64>::new().iter().enumerate() {
        vector(out, "sf64", j, p);
    }
    for (j, p) in HemisphericalFibonacci::<16>::new().with_angle(0.7).iter().enumerate() {
        vector(out, "hemi16", j, p);
    }
    let mut seq = RotationSequence::new(5);
    let rot = seq.next_rotation();
    if let Ok(set) = SphericalFibonacci::<32>::new().with_rotation(rot) {
        for (j, p) in set.iter().enumerate() {
            vector(out, "sf32rot", j, p);
        }
    }

    // QMC estimates of the procedural sky.
    for (i, &n) in NORMALS.iter().enumerate() {
        let phase = seq.next_phase();
        let e16 = qmc::irradiance::<16, f32, _>(n, phase, sky);
        let e64 = qmc::irradiance::<64, f32, _>(n, phase, sky);
        let e256 = qmc::irradiance::<256, f32, _>(n, phase, sky);
        for (key, e) in [("irr16", e16), ("irr64", e64), ("irr256", e256)] {
            value(out, key, i, e.unwrap_or(f32::NAN));
        }
        let rgb = qmc::irradiance::<64, [f32; 3], _>(n, phase, sky_rgb).unwrap_or([f32::NAN; 3]);
        for (c, v) in rgb.iter().enumerate() {
            value(out, "irr64rgb", 3 * i + c, *v);
        }
        let g = qmc::phong::<64, f32, _>(n, 20.0, phase, sky).unwrap_or(f32::NAN);
        value(out, "phong64", i, g);
    }

    // Slice form.
    let s = LobeSampler::new(Vec3::new(0.3, 0.1, 0.9), Lobe::Cosine, 64, 99);
    if let Ok(s) = s {
        let mut dirs = [Vec3::ZERO; 64];
        if s.fill(&mut dirs).is_ok() {
            let mut ys = [0.0f32; 64];
            for (y, d) in ys.iter_mut().zip(&dirs) {
                *y = sky(*d);
            }
            value(out, "slice64", 0, s.estimate(&ys).unwrap_or(f32::NAN));
            vector(out, "slice64dir", 7, dirs[7]);
        }
    }

    // Inverse mapping.
    let sf256 = SphericalFibonacci::<256>::new();
    let sf4096 = SphericalFibonacci::<4096>::new();
    for i in 0..32 {
        let q = seq.next_rotation() * Vec3::Z;
        let a = sf256.nearest_index(q).map_or(usize::MAX, |j| j);
        let b = sf4096.nearest_index(q).map_or(usize::MAX, |j| j);
        out.line(format_args!("nearest256 {i} {a}"));
        out.line(format_args!("nearest4096 {i} {b}"));
    }

    // Bad input: documented results, no panic.
    error(out, "zero_normal", qmc::irradiance::<16, f32, _>(Vec3::ZERO, 0, sky));
    error(out, "nan_normal", qmc::irradiance::<16, f32, _>(Vec3::new(f32::NAN, 0.0, 1.0), 0, sky));
    error(out, "negative_exponent", qmc::phong::<16, f32, _>(Vec3::Z, -1.0, 0, sky));
    error(out, "nan_radiance", qmc::irradiance::<16, f32, _>(Vec3::Z, 0, |_| f32::NAN));
    let bad = sf256.nearest_index(Vec3::ZERO);
    out.line(format_args!("nearest_zero 0 {bad:?}"));

    // BMC probe (issue #6): a rotated probe of the sky, RGB, per-probe selection, queries
    // with both variances; then bad input.
    let mut p = probe::Probe::<64, [f32; 3]>::new();
    if p.set_rotation(seq.next_rotation()).is_ok() {
        let ys: [[f32; 3]; 64] = p.directions().map(sky_rgb);
        let ok = p.update(&ys).is_ok();
        out.line(format_args!("probe_update 0 {ok} {}", p.selected()));
        for i in 0..8 {
            let n = seq.next_rotation() * Vec3::Z;
            if let (Ok(e), Ok(v)) = (p.irradiance(n), p.irradiance_variance(n)) {
                for (c, ((&ev, &var), &exact)) in
                    e.value.iter().zip(&e.variance).zip(&v).enumerate()
                {
                    value(out, "probe_e", 3 * i + c, ev);
                    value(out, "probe_var", 3 * i + c, var);
                    value(out, "probe_exact_var", 3 * i + c, exact);
                }
            }
        }
        // Glossy: normalised Phong lobes (SG fit) about random mirror directions, with the
        // exact variance.
        for (i, e) in [0.0f32, 5.0, 20.0, 100.0].into_iter().enumerate() {
            let r = seq.next_rotation() * Vec3::Z;
            let Ok(lobe) = sg::SphericalGaussian::phong_moments(r, e) else { continue };
            if let (Ok(g), Ok(v)) = (p.glossy(&lobe), p.glossy_variance(&lobe)) {
                for (c, ((&gv, &fast), &var)) in g.value.iter().zip(&g.variance).zip(&v).enumerate()
                {
                    value(out, "probe_glossy", 3 * i + c, gv);
                    value(out, "probe_glossy_fast_var", 3 * i + c, fast);
                    value(out, "probe_glossy_var", 3 * i + c, var);
                }
            }
        }
        // SH L2 export (issue #14): the coefficients, their variances, the O(9) irradiance at
        // the eight normals (unit and not), a rotation and the engines' forms.
        let sh = p.radiance_sh();
        for (k, (c, v)) in sh.coefficients.iter().zip(&p.radiance_sh_variance()).enumerate() {
            for ch in 0..3 {
                value(out, "probe_sh", 3 * k + ch, c[ch]);
                value(out, "probe_sh_var", 3 * k + ch, v[ch]);
            }
        }
        for (i, &n) in NORMALS.iter().enumerate() {
            let e = sh.irradiance(n).unwrap_or([f32::NAN; 3]);
            for (ch, &v) in e.iter().enumerate() {
                value(out, "probe_sh_e", 3 * i + ch, v);
            }
        }
        let rotated = sh.rotated(&seq.next_rotation());
        for (k, c) in rotated.coefficients.iter().enumerate() {
            for (ch, &v) in c.iter().enumerate() {
                value(out, "probe_sh_rotated", 3 * k + ch, v);
            }
        }
        for (k, c) in sh.filament_irradiance().iter().enumerate() {
            for (ch, &v) in c.iter().enumerate() {
                value(out, "probe_sh_filament", 3 * k + ch, v);
            }
        }
        for (k, v) in sh.unity_shader_constants().iter().flatten().enumerate() {
            value(out, "probe_sh_unity", k, *v);
        }
        out.line(format_args!("probe_sh_zero_normal 0 {:?}", sh.irradiance(Vec3::ZERO).err()));
        let flat = sg::SphericalGaussian { axis: Vec3::ZERO, sharpness: 5.0, amplitude: 1.0 };
        out.line(format_args!("probe_glossy_zero_axis 0 {:?}", p.glossy(&flat).err()));
        let nan = sg::SphericalGaussian { axis: Vec3::Z, sharpness: f32::NAN, amplitude: 1.0 };
        out.line(format_args!("probe_glossy_nan_sharpness 0 {:?}", p.glossy(&nan).err()));
        let mut bad = ys;
        bad[5][1] = f32::NAN;
        out.line(format_args!("probe_nan_sample 0 {:?}", p.update(&bad)));
        out.line(format_args!("probe_zero_normal 0 {:?}", p.irradiance(Vec3::ZERO).err()));
        out.line(format_args!("probe_selected_after_bad 0 {}", p.selected()));
    }
    missing_samples(out, &mut seq);
    let r = bmc::Renderer::<64>::new();
    error(out, "renderer64", r.with_phase(77).irradiance(Vec3::new(0.2, 0.3, 0.9), sky));

    // Light sensors (issue #11): N photodiodes with a cosine response, readings of a real map
    // taken on the host and embedded.
    sensor_probe(out, &sensor_readings::READINGS_16);
    sensor_probe(out, &sensor_readings::READINGS_32);

    // Sensor layouts: six photodiodes on a cube's faces, and 16 on the photodiode probe's
    // directions, readings with a multiplicative noise of 1 %, built at run time.
    layout_probe(out, "cube6", &sensor_readings::CUBE, &sensor_readings::CUBE_READINGS);
    let sf16 = *probe::Probe::<16, f32, CosinePower<1>>::new().directions();
    layout_probe(out, "sf16", &sf16, &sensor_readings::NOISY_READINGS_16);
}

/// The noise of the scenario's layout readings: 1 % of the reading.
pub const LAYOUT_NOISE: Noise = Noise { absolute: 0.0, relative: 0.01 };

/// A `LayoutProbe<K, [f32; 3]>` of cosine photodiodes at `directions` with
/// `Prior::ENVIRONMENT` and [`LAYOUT_NOISE`] (lines `layout_{label}_…`): the scale chosen by
/// the update, then at the query normals the irradiance, its direction-averaged and exact
/// variances and the relative error against the exact irradiance; then bad input (the probe
/// keeps its data).
fn layout_probe<const K: usize>(
    out: &mut impl Sink,
    label: &str,
    directions: &[Vec3; K],
    readings: &[[f32; 3]; K],
) {
    let sensors = directions.map(Sensor::cosine);
    let mut p = match LayoutProbe::<K, [f32; 3]>::new(&sensors, Prior::ENVIRONMENT, LAYOUT_NOISE) {
        Ok(p) => p,
        Err(e) => {
            out.line(format_args!("layout_{label}_new 0 error {e:?}"));
            return;
        }
    };
    out.line(format_args!("layout_{label}_update 0 {:?}", p.update(readings)));
    for (c, &s) in p.signal_variance().iter().enumerate() {
        layout_value(out, label, "scale", c, s);
    }
    let queries = sensor_readings::NORMALS.iter().zip(&sensor_readings::IRRADIANCE);
    for (i, (&n, truth)) in queries.enumerate() {
        let (Ok(e), Ok(exact)) = (p.irradiance(n), p.irradiance_variance(n)) else {
            out.line(format_args!("layout_{label}_query {i} failed"));
            continue;
        };
        for (c, &t) in truth.iter().enumerate() {
            let ev = e.value[c];
            layout_value(out, label, "e", 3 * i + c, ev);
            layout_value(out, label, "var", 3 * i + c, e.variance[c]);
            layout_value(out, label, "exact_var", 3 * i + c, exact[c]);
            layout_value(out, label, "rel_err", 3 * i + c, (ev - t) / t);
        }
    }
    let mut bad = *readings;
    bad[K - 1][2] = f32::NAN;
    out.line(format_args!("layout_{label}_nan_reading 0 {:?}", p.update(&bad)));
    out.line(format_args!("layout_{label}_zero_normal 0 {:?}", p.irradiance(Vec3::ZERO).err()));
    let zero_var = p.irradiance_variance(Vec3::ZERO).err();
    out.line(format_args!("layout_{label}_zero_normal_variance 0 {zero_var:?}"));
    // Still the data of the good update.
    let kept = p.irradiance(sensor_readings::NORMALS[0]).map_or([f32::NAN; 3], |e| e.value);
    for (c, &v) in kept.iter().enumerate() {
        layout_value(out, label, "e_after_bad", c, v);
    }
}

/// `layout_{label}_{what} index bits` (NaN as `nan`).
fn layout_value(out: &mut impl Sink, label: &str, what: &str, index: usize, v: f32) {
    if v.is_nan() {
        out.line(format_args!("layout_{label}_{what} {index} nan"));
    } else {
        out.line(format_args!("layout_{label}_{what} {index} {:08x}", v.to_bits()));
    }
}

/// Missing samples (issue #14): a rotated RGB probe of capacity 16 with 13 samples missing
/// (NaN there, never read), its member, irradiance with both variances and a glossy query;
/// then more missing than the capacity and a NaN valid sample (errors, data kept).
fn missing_samples(out: &mut impl Sink, seq: &mut RotationSequence) {
    let mut p = probe::Probe::<64, [f32; 3], Point, 16>::new();
    if p.set_rotation(seq.next_rotation()).is_err() {
        return;
    }
    let valid: [bool; 64] = core::array::from_fn(|i| (i * 7 + 3) % 5 != 0);
    let ys: [[f32; 3]; 64] =
        core::array::from_fn(|i| if valid[i] { sky_rgb(p.directions()[i]) } else { [f32::NAN; 3] });
    let ok = p.update_masked(&ys, &valid).is_ok();
    out.line(format_args!("masked_update 0 {ok} {} {}", p.selected(), p.missing().len()));
    for i in 0..8 {
        let n = seq.next_rotation() * Vec3::Z;
        if let (Ok(e), Ok(v)) = (p.irradiance(n), p.irradiance_variance(n)) {
            for (c, ((&ev, &var), &exact)) in e.value.iter().zip(&e.variance).zip(&v).enumerate() {
                value(out, "masked_e", 3 * i + c, ev);
                value(out, "masked_var", 3 * i + c, var);
                value(out, "masked_exact_var", 3 * i + c, exact);
            }
        }
    }
    if let Ok(lobe) = sg::SphericalGaussian::phong_moments(seq.next_rotation() * Vec3::Z, 20.0) {
        if let (Ok(g), Ok(v)) = (p.glossy(&lobe), p.glossy_variance(&lobe)) {
            for (c, (&gv, &var)) in g.value.iter().zip(&v).enumerate() {
                value(out, "masked_glossy", c, gv);
                value(out, "masked_glossy_var", c, var);
            }
        }
    }
    let luminance = p.signal_variance_of([0.2126, 0.7152, 0.0722]).unwrap_or(f32::NAN);
    value(out, "masked_luminance_variance", 0, luminance);
    let mut many = [true; 64];
    many[..17].fill(false);
    out.line(format_args!("masked_too_many 0 {:?}", p.update_masked(&ys, &many)));
    let mut bad = ys;
    bad[2][0] = f32::NAN; // sample 2 is valid
    out.line(format_args!("masked_nan_valid 0 {:?}", p.update_masked(&bad, &valid)));
    out.line(format_args!("masked_kept 0 {} {}", p.selected(), p.missing().len()));
}

/// `sensor{N}_{what} index bits` (NaN as `nan`).
fn sensor_value<const N: usize>(out: &mut impl Sink, what: &str, index: usize, v: f32) {
    if v.is_nan() {
        out.line(format_args!("sensor{N}_{what} {index} nan"));
    } else {
        out.line(format_args!("sensor{N}_{what} {index} {:08x}", v.to_bits()));
    }
}

/// A probe of `N` photodiodes (`CosinePower<1>`: each reading is the irradiance at the
/// sensor's normal over π), RGB: update with the embedded readings, then at the eight query
/// normals the irradiance, its O(1) and exact variances and the relative error against the
/// exact irradiance; one glossy query; then bad input (the probe keeps its data).
fn sensor_probe<const N: usize>(out: &mut impl Sink, readings: &[[f32; 3]; N])
where
    bmc::Size<N>: probe::ProbeTables<CosinePower<1>>,
{
    let mut p = probe::Probe::<N, [f32; 3], CosinePower<1>>::new();
    let ok = p.update(readings).is_ok();
    out.line(format_args!("sensor{N}_update 0 {ok} {}", p.selected()));
    let queries = sensor_readings::NORMALS.iter().zip(&sensor_readings::IRRADIANCE);
    for (i, (&n, truth)) in queries.enumerate() {
        let (Ok(e), Ok(exact)) = (p.irradiance(n), p.irradiance_variance(n)) else {
            out.line(format_args!("sensor{N}_query {i} failed"));
            continue;
        };
        for (c, &t) in truth.iter().enumerate() {
            let (ev, var, ex) = (e.value[c], e.variance[c], exact[c]);
            sensor_value::<N>(out, "e", 3 * i + c, ev);
            sensor_value::<N>(out, "var", 3 * i + c, var);
            sensor_value::<N>(out, "exact_var", 3 * i + c, ex);
            sensor_value::<N>(out, "rel_err", 3 * i + c, (ev - t) / t);
        }
    }
    // Glossy (the cosine footprint's Legendre-series path): a normalised Phong lobe, e = 5.
    if let Ok(lobe) = sg::SphericalGaussian::phong_moments(Vec3::new(0.3, -0.4, 0.5), 5.0) {
        if let (Ok(g), Ok(v)) = (p.glossy(&lobe), p.glossy_variance(&lobe)) {
            for (c, ((&gv, &fast), &var)) in g.value.iter().zip(&g.variance).zip(&v).enumerate() {
                sensor_value::<N>(out, "glossy", c, gv);
                sensor_value::<N>(out, "glossy_fast_var", c, fast);
                sensor_value::<N>(out, "glossy_var", c, var);
            }
        }
    }
    // The SH export of the unfiltered radiance (issue #14).
    for (k, c) in p.radiance_sh().coefficients.iter().enumerate() {
        for (ch, &v) in c.iter().enumerate() {
            sensor_value::<N>(out, "sh", 3 * k + ch, v);
        }
    }
    let mut bad = *readings;
    bad[3][1] = f32::NAN;
    out.line(format_args!("sensor{N}_nan_reading 0 {:?}", p.update(&bad)));
    out.line(format_args!("sensor{N}_zero_normal 0 {:?}", p.irradiance(Vec3::ZERO).err()));
    let zero_var = p.irradiance_variance(Vec3::ZERO).err();
    out.line(format_args!("sensor{N}_zero_normal_variance 0 {zero_var:?}"));
    // Still the data of the good update.
    let kept = p.irradiance(sensor_readings::NORMALS[0]).map_or([f32::NAN; 3], |e| e.value);
    for (c, &v) in kept.iter().enumerate() {
        sensor_value::<N>(out, "e_after_bad", c, v);
    }
}
