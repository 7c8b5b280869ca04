//! sphere-quadrature as a WebAssembly module (`wasm32-unknown-unknown`, `no_std`, no
//! allocation, no wasm-bindgen): plain `extern "C"` exports taking and returning numbers.
//!
//! Arrays cross the boundary through fixed static buffers of atomics: the module exports
//! their addresses (`*_ptr`) and JavaScript reads or writes them through typed-array views of
//! the module's memory. Atomics give the interior mutability without any `unsafe` (on
//! wasm32 without the `atomics` target feature they compile to plain loads and stores).
//!
//! `examples/wasm/test.mjs` (Node) calls every export; `.ci/run` compares its output with the
//! host's (`eval/src/bin/device_scenario.rs` + `eval/src/bin/wasm_scenario.rs`) bit for bit.
//!
//! ```text
//! cd examples/wasm && cargo build --release --target wasm32-unknown-unknown
//! node examples/wasm/test.mjs
//! ```
#![no_std]
// `#[no_mangle]` is the only construct the `unsafe_code` lint flags here (exports need
// their symbol names); it is allowed on the `exports` module only. No `unsafe` blocks.
#![deny(unsafe_code)]

mod api;
#[path = "../../cortex-m4/src/scenario.rs"]
mod scenario;

use core::fmt::{Arguments, Write};
use core::sync::atomic::{AtomicBool, AtomicU32, AtomicU8, Ordering::Relaxed};

use api::{BmcProbe, BMC_N, MAP_MAX, PROBE_MAX, PYRAMID_MAX};
use sphere_quadrature::bmc::Size;
use sphere_quadrature::footprint::{Footprint, Gaussian, Kind, Point};
use sphere_quadrature::probe::ProbeTables;
use sphere_quadrature::qmc::LobeSampler;
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::{Error, Lobe, Vec3};

/// Capacity of the scenario's text buffer in bytes.
const OUT_CAP: usize = 32 * 1024;

/// The scenario's output text (`key index bits` lines, `\n`-terminated).
static OUT: [AtomicU8; OUT_CAP] = [const { AtomicU8::new(0) }; OUT_CAP];
/// Radiance samples written by JavaScript (f32 bits).
static SAMPLES: [AtomicU32; PROBE_MAX] = [const { AtomicU32::new(0) }; PROBE_MAX];
/// Directions written by `probe_directions` (x, y, z per sample, f32 bits).
static DIRS: [AtomicU32; 3 * PROBE_MAX] = [const { AtomicU32::new(0) }; 3 * PROBE_MAX];

/// Seed of the BMC probe's rotation (0: unrotated), set by `bmc_probe_reset`.
static BMC_SEED: AtomicU32 = AtomicU32::new(0);
/// Whether [`BMC_DATA`] holds the probe's accepted samples (false after a reset).
static BMC_HAS_DATA: AtomicBool = AtomicBool::new(false);
/// The BMC probe's last accepted RGB samples (f32 bits, r, g, b per direction). The probe is
/// rebuilt from the seed and these samples in every call: no probe state in statics.
static BMC_DATA: [AtomicU32; 3 * BMC_N] = [const { AtomicU32::new(0) }; 3 * BMC_N];
/// The last `bmc_probe_irradiance`: `[r, g, b, var_r, var_g, var_b]` (f32 bits).
static BMC_OUT: [AtomicU32; 6] = [const { AtomicU32::new(0) }; 6];

/// Most queries of one `bmc_shade` call (a 32×32 grid).
const SHADE_MAX: usize = 1024;
/// `bmc_shade` queries: normal and reflection direction per query (6 f32 bits), written by
/// JavaScript.
static QUERIES: [AtomicU32; 6 * SHADE_MAX] = [const { AtomicU32::new(0) }; 6 * SHADE_MAX];
/// `bmc_shade` results: irradiance RGB and glossy RGB per query (6 f32 bits).
static SHADED: [AtomicU32; 6 * SHADE_MAX] = [const { AtomicU32::new(0) }; 6 * SHADE_MAX];

/// An RGB equirectangular map written by JavaScript (r, g, b per pixel, row-major, row 0 at
/// +z; f32 bits), read by `map_footprint_samples`.
static MAP: [AtomicU32; 3 * MAP_MAX] = [const { AtomicU32::new(0) }; 3 * MAP_MAX];

// `bmc_probe_update` reads its RGB samples from [`SAMPLES`]; `map_footprint_samples` writes up
// to `SHADE_MAX` RGB samples there and reads as many directions from [`DIRS`].
const _: () = assert!(3 * BMC_N <= PROBE_MAX && 3 * SHADE_MAX <= PROBE_MAX);

/// Writes the scenario's lines into [`OUT`].
struct Buffer {
    len: usize,
    overflow: bool,
}

impl Write for Buffer {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        for &b in s.as_bytes() {
            let Some(slot) = OUT.get(self.len) else {
                self.overflow = true;
                return Err(core::fmt::Error);
            };
            slot.store(b, Relaxed);
            self.len += 1;
        }
        Ok(())
    }
}

impl scenario::Sink for Buffer {
    fn line(&mut self, args: Arguments<'_>) {
        if self.write_fmt(args).and_then(|()| self.write_str("\n")).is_err() {
            self.overflow = true;
        }
    }
}

/// Runs the shared scenario into [`OUT`]; its length in bytes, or −1 if it did not fit.
fn scenario_text() -> i32 {
    let mut b = Buffer { len: 0, overflow: false };
    scenario::run(&mut b);
    if b.overflow {
        -1
    } else {
        i32::try_from(b.len).unwrap_or(-1)
    }
}

/// Fills [`DIRS`] with the probe sampler's directions; their number, or −1 on bad input.
fn fill_directions(nx: f32, ny: f32, nz: f32, lo: u32, hi: u32, n: u32) -> i32 {
    api::probe_sampler(nx, ny, nz, lo, hi, n).map_or(-1, |s| store_directions(&s))
}

/// Fills [`DIRS`] with the glossy probe sampler's directions; their number, or −1 on bad input.
fn fill_directions_phong(rx: f32, ry: f32, rz: f32, e: f32, lo: u32, hi: u32, n: u32) -> i32 {
    phong_sampler(rx, ry, rz, e, lo, hi, n).map_or(-1, |s| store_directions(&s))
}

/// The Phong-lobe sampler of the probe-style glossy estimator: `n` directions about the
/// reflection direction `(rx, ry, rz)` with exponent `e`; `None` on bad input or
/// `n > PROBE_MAX`.
fn phong_sampler(
    rx: f32,
    ry: f32,
    rz: f32,
    e: f32,
    lo: u32,
    hi: u32,
    n: u32,
) -> Option<LobeSampler> {
    let n = n as usize;
    if n > PROBE_MAX {
        return None;
    }
    let lobe = Lobe::phong(e).ok()?;
    LobeSampler::new(Vec3::new(rx, ry, rz), lobe, n, api::phase(lo, hi)).ok()
}

/// Writes the sampler's directions into [`DIRS`]; their number.
fn store_directions(s: &LobeSampler) -> i32 {
    store_vectors(s.iter());
    i32::try_from(s.len()).unwrap_or(-1)
}

/// Writes directions into [`DIRS`] (x, y, z each), as many as fit.
fn store_vectors(dirs: impl Iterator<Item = Vec3>) {
    for (d, slot) in dirs.zip(DIRS.chunks_exact(3)) {
        slot[0].store(d.x.to_bits(), Relaxed);
        slot[1].store(d.y.to_bits(), Relaxed);
        slot[2].store(d.z.to_bits(), Relaxed);
    }
}

/// The probe estimate from the first `n` values of [`SAMPLES`]; NaN on bad input.
fn estimate_samples(nx: f32, ny: f32, nz: f32, lo: u32, hi: u32, n: u32) -> f32 {
    let Some(s) = api::probe_sampler(nx, ny, nz, lo, hi, n) else { return f32::NAN };
    let mut ys = [0.0f32; PROBE_MAX];
    for (y, a) in ys.iter_mut().zip(&SAMPLES).take(s.len()) {
        *y = f32::from_bits(a.load(Relaxed));
    }
    s.estimate(&ys[..s.len()]).unwrap_or(f32::NAN)
}

/// The normalised Phong glossy estimate `∫ L·(e+1)/(2π)·max(0, r·ω)ᵉ dω` from the first `n`
/// values of [`SAMPLES`]: their mean (the lobe's 2π/(e+1) cancels); NaN on bad input.
fn estimate_samples_phong(rx: f32, ry: f32, rz: f32, e: f32, lo: u32, hi: u32, n: u32) -> f32 {
    let Some(s) = phong_sampler(rx, ry, rz, e, lo, hi, n) else { return f32::NAN };
    let sum: f32 = SAMPLES.iter().take(s.len()).map(|a| f32::from_bits(a.load(Relaxed))).sum();
    sum / s.len() as f32
}

/// `3·N` floats of `buffer` as RGB samples.
fn load_rgb<const N: usize>(buffer: &[AtomicU32]) -> [[f32; 3]; N] {
    let mut ys = [[0.0f32; 3]; N];
    for (y, a) in ys.iter_mut().zip(buffer.chunks_exact(3)) {
        for (c, v) in y.iter_mut().zip(a) {
            *c = f32::from_bits(v.load(Relaxed));
        }
    }
    ys
}

/// The BMC probe in its current state: rebuilt from [`BMC_SEED`] and updated with
/// [`BMC_DATA`] when it holds samples.
fn bmc_current() -> Result<BmcProbe, sphere_quadrature::Error> {
    let mut p = api::bmc_probe(BMC_SEED.load(Relaxed))?;
    if BMC_HAS_DATA.load(Relaxed) {
        p.update(&load_rgb(&BMC_DATA))?;
    }
    Ok(p)
}

/// A new BMC probe (rotation seed `seed`, no data); 0, or an error code (state unchanged).
fn bmc_reset(seed: u32) -> i32 {
    match api::bmc_probe(seed) {
        Ok(_) => {
            BMC_SEED.store(seed, Relaxed);
            BMC_HAS_DATA.store(false, Relaxed);
            0
        }
        Err(e) => api::error_code(e),
    }
}

/// Writes the BMC probe's directions into [`DIRS`]; their number, or −1 on error.
fn bmc_directions() -> i32 {
    let Ok(p) = api::bmc_probe(BMC_SEED.load(Relaxed)) else { return -1 };
    store_vectors(p.directions().iter().copied());
    i32::try_from(BMC_N).unwrap_or(-1)
}

/// Updates the BMC probe with the `3·BMC_N` floats at the start of [`SAMPLES`]; 0, or an
/// error code (the probe keeps its previous data).
fn bmc_update() -> i32 {
    let ys = load_rgb(&SAMPLES);
    let result = api::bmc_probe(BMC_SEED.load(Relaxed)).and_then(|mut p| p.update(&ys));
    match result {
        Ok(()) => {
            for (y, slot) in ys.iter().zip(BMC_DATA.chunks_exact(3)) {
                for (c, a) in y.iter().zip(slot) {
                    a.store(c.to_bits(), Relaxed);
                }
            }
            BMC_HAS_DATA.store(true, Relaxed);
            0
        }
        Err(e) => api::error_code(e),
    }
}

/// The BMC probe's irradiance about `(nx, ny, nz)` into [`BMC_OUT`] (NaN on error); 0, or an
/// error code.
fn bmc_irradiance(nx: f32, ny: f32, nz: f32) -> i32 {
    let (values, code) = match bmc_current().and_then(|p| p.irradiance(Vec3::new(nx, ny, nz))) {
        Ok(e) => {
            let [r, g, b] = e.value;
            let [vr, vg, vb] = e.variance;
            ([r, g, b, vr, vg, vb], 0)
        }
        Err(e) => ([f32::NAN; 6], api::error_code(e)),
    };
    for (v, a) in values.iter().zip(&BMC_OUT) {
        a.store(v.to_bits(), Relaxed);
    }
    code
}

/// The BMC probe's normalised Phong-lobe glossy radiance about `(rx, ry, rz)` (exponent `e`,
/// the lobe `SphericalGaussian::phong_moments`) with its exact variance into [`BMC_OUT`] (NaN on
/// error); 0, or an error code.
fn bmc_glossy(rx: f32, ry: f32, rz: f32, e: f32) -> i32 {
    let result = bmc_current().and_then(|p| {
        let lobe = SphericalGaussian::phong_moments(Vec3::new(rx, ry, rz), e)?;
        Ok((p.glossy(&lobe)?.value, p.glossy_variance(&lobe)?))
    });
    let (values, code) = match result {
        Ok(([r, g, b], [vr, vg, vb])) => ([r, g, b, vr, vg, vb], 0),
        Err(e) => ([f32::NAN; 6], api::error_code(e)),
    };
    for (v, a) in values.iter().zip(&BMC_OUT) {
        a.store(v.to_bits(), Relaxed);
    }
    code
}

/// The footprint probe of `n` samples: `$run::<N, Gaussian<N/8>>($args)` for each baked `N`,
/// `$other` for any other `n` (const generic arithmetic is not stable, so the sizes are
/// spelled out once, here).
macro_rules! with_footprint_probe {
    ($n:expr, $run:ident($($args:expr),*), $other:expr) => {
        match $n {
            16 => $run::<16, Gaussian<2>>($($args),*),
            32 => $run::<32, Gaussian<4>>($($args),*),
            64 => $run::<64, Gaussian<8>>($($args),*),
            128 => $run::<128, Gaussian<16>>($($args),*),
            256 => $run::<256, Gaussian<32>>($($args),*),
            _ => $other,
        }
    };
}

/// The point-sample probe of `n` samples, as [`with_footprint_probe`].
macro_rules! with_point_probe {
    ($n:expr, $run:ident($($args:expr),*), $other:expr) => {
        match $n {
            16 => $run::<16, Point>($($args),*),
            32 => $run::<32, Point>($($args),*),
            64 => $run::<64, Point>($($args),*),
            128 => $run::<128, Point>($($args),*),
            256 => $run::<256, Point>($($args),*),
            _ => $other,
        }
    };
}

/// Writes the directions of an `N`-sample probe of footprint `F` rotated by `seed` (as
/// `bmc_probe_reset`) into [`DIRS`]; `N`, or −1.
fn shade_directions<const N: usize, F: Footprint>(seed: u32) -> i32
where
    Size<N>: ProbeTables<F>,
{
    let Ok(p) = api::probe_nf::<N, F>(seed) else { return -1 };
    store_vectors(p.directions().iter().copied());
    i32::try_from(N).unwrap_or(-1)
}

/// One update of an `N`-sample RGB probe of footprint `F` (rotation `seed`, samples from
/// [`SAMPLES`]), then `count` queries from [`QUERIES`]: irradiance about each normal and Phong
/// glossy radiance (exponent `e`) about each reflection direction into [`SHADED`] (NaN for a
/// query with a bad direction).
fn shade<const N: usize, F: Footprint>(seed: u32, count: usize, e: f32) -> Result<(), Error>
where
    Size<N>: ProbeTables<F>,
{
    let mut p = api::probe_nf::<N, F>(seed)?;
    p.update(&load_rgb::<N>(&SAMPLES))?;
    // Checks the exponent once, before any query.
    SphericalGaussian::phong_moments(Vec3::Z, e)?;
    for (q, out) in QUERIES.chunks_exact(6).zip(SHADED.chunks_exact(6)).take(count) {
        let (nq, rq) = q.split_at(3);
        let irr = p.irradiance(load_vector(nq)).map_or([f32::NAN; 3], |v| v.value);
        let glossy = SphericalGaussian::phong_moments(load_vector(rq), e)
            .and_then(|lobe| p.glossy(&lobe).map(|g| g.value))
            .unwrap_or([f32::NAN; 3]);
        for (v, a) in irr.iter().chain(&glossy).zip(out) {
            a.store(v.to_bits(), Relaxed);
        }
    }
    Ok(())
}

/// The first three values of `a` as a vector (NaN where missing).
fn load_vector(a: &[AtomicU32]) -> Vec3 {
    let [x, y, z] =
        [0, 1, 2].map(|i| a.get(i).map_or(f32::NAN, |v| f32::from_bits(v.load(Relaxed))));
    Vec3::new(x, y, z)
}

/// [`shade`] for the point (`footprint` false) or footprint probe of `n` samples; 0, or an
/// error code (5: `n` without a baked family or `count` above 1024; 4: a bad exponent; 2: a
/// NaN or infinite sample).
fn shade_code(footprint: bool, n: u32, seed: u32, count: u32, e: f32) -> i32 {
    let count = count as usize;
    if count > SHADE_MAX {
        return api::error_code(Error::InvalidSize);
    }
    let other = Err(Error::InvalidSize);
    let result = if footprint {
        with_footprint_probe!(n, shade(seed, count, e), other)
    } else {
        with_point_probe!(n, shade(seed, count, e), other)
    };
    result.map_or_else(api::error_code, |()| 0)
}

/// The Gaussian footprint sharpness of the `n`-sample footprint probe; −1 for an `n` without
/// one.
fn footprint_sharpness(n: u32) -> i32 {
    fn run<const N: usize, F: Footprint>() -> i32 {
        match F::KIND {
            Kind::Gaussian { sharpness } => i32::try_from(sharpness).unwrap_or(-1),
            _ => -1,
        }
    }
    with_footprint_probe!(n, run(), -1)
}

/// Footprint samples of the `width`×`height` map in [`MAP`] in the first `count` directions of
/// [`DIRS`] into [`SAMPLES`] (see [`api::map_footprint_samples`]); 0, or an error code (the
/// samples are then unchanged).
fn map_samples(width: u32, height: u32, count: u32, sharpness: u32, sampler: u32) -> i32 {
    let (w, h, count) = (width as usize, height as usize, count as usize);
    if count > SHADE_MAX {
        return api::error_code(Error::InvalidSize);
    }
    let len = match api::map_len(w, h) {
        Ok(len) => len,
        Err(e) => return api::error_code(e),
    };
    // The crate borrows plain slices: copy the map and directions out of the atomics. These
    // arrays (2.1 MB) live on the stack, which build.rs makes 4 MiB.
    let mut pixels = [[0.0f32; 3]; MAP_MAX];
    for (p, a) in pixels.iter_mut().zip(MAP.chunks_exact(3)).take(len) {
        *p = [0, 1, 2].map(|c| a.get(c).map_or(f32::NAN, |v| f32::from_bits(v.load(Relaxed))));
    }
    let mut dirs = [Vec3::ZERO; SHADE_MAX];
    for (d, a) in dirs.iter_mut().zip(DIRS.chunks_exact(3)).take(count) {
        *d = load_vector(a);
    }
    let mut pyramid = [[0.0f32; 3]; PYRAMID_MAX];
    let mut out = [[0.0f32; 3]; SHADE_MAX];
    let (Some(pixels), Some(dirs), Some(out)) =
        (pixels.get(..len), dirs.get(..count), out.get_mut(..count))
    else {
        return api::error_code(Error::InvalidSize);
    };
    let result =
        api::map_footprint_samples(pixels, (w, h), dirs, sharpness, sampler, &mut pyramid, out);
    match result {
        Ok(()) => {
            for (y, slot) in out.iter().zip(SAMPLES.chunks_exact(3)) {
                for (c, a) in y.iter().zip(slot) {
                    a.store(c.to_bits(), Relaxed);
                }
            }
            0
        }
        Err(e) => api::error_code(e),
    }
}

/// The BMC probe's selected family member; −1 on error.
fn bmc_selected() -> i32 {
    bmc_current().map_or(-1, |p| i32::try_from(p.selected()).unwrap_or(-1))
}

#[allow(unsafe_code)] // `#[no_mangle]` only; every body is one safe call.
mod exports {
    use super::{api, shade_directions, Gaussian, Point, BMC_OUT, DIRS, MAP, OUT, QUERIES};
    use super::{SAMPLES, SHADED};

    /// Runs the Cortex-M4 scenario; the text is at `out_ptr()`, this many bytes (−1: overflow).
    #[no_mangle]
    pub extern "C" fn scenario_run() -> i32 {
        super::scenario_text()
    }

    /// Address of the scenario's text buffer in the module's memory.
    #[no_mangle]
    pub extern "C" fn out_ptr() -> usize {
        OUT.as_ptr() as usize
    }

    /// Address of the radiance-sample buffer (`PROBE_MAX` f32), written by JavaScript.
    #[no_mangle]
    pub extern "C" fn samples_ptr() -> usize {
        SAMPLES.as_ptr() as usize
    }

    /// Address of the direction buffer (`3·PROBE_MAX` f32), filled by `probe_directions`.
    #[no_mangle]
    pub extern "C" fn dirs_ptr() -> usize {
        DIRS.as_ptr() as usize
    }

    /// Capacity of the sample buffer.
    #[no_mangle]
    pub extern "C" fn probe_max() -> u32 {
        api::PROBE_MAX as u32
    }

    /// Writes the `n` cosine-lobe directions about `(nx, ny, nz)` to `dirs_ptr()`; returns
    /// `n`, or −1 on bad input.
    #[no_mangle]
    pub extern "C" fn probe_directions(nx: f32, ny: f32, nz: f32, lo: u32, hi: u32, n: u32) -> i32 {
        super::fill_directions(nx, ny, nz, lo, hi, n)
    }

    /// Irradiance from the `n` radiance samples at `samples_ptr()` (taken at the directions of
    /// `probe_directions` with the same arguments); NaN on bad input.
    #[no_mangle]
    pub extern "C" fn probe_estimate(nx: f32, ny: f32, nz: f32, lo: u32, hi: u32, n: u32) -> f32 {
        super::estimate_samples(nx, ny, nz, lo, hi, n)
    }

    /// Writes the `n` normalised-Phong-lobe directions (exponent `e`) about the reflection
    /// direction `(rx, ry, rz)` to `dirs_ptr()`; returns `n`, or −1 on bad input.
    #[no_mangle]
    pub extern "C" fn probe_directions_phong(
        rx: f32,
        ry: f32,
        rz: f32,
        e: f32,
        lo: u32,
        hi: u32,
        n: u32,
    ) -> i32 {
        super::fill_directions_phong(rx, ry, rz, e, lo, hi, n)
    }

    /// Normalised Phong glossy radiance from the `n` radiance samples at `samples_ptr()`
    /// (taken at the directions of `probe_directions_phong` with the same arguments): their
    /// mean; NaN on bad input.
    #[no_mangle]
    pub extern "C" fn probe_estimate_phong(
        rx: f32,
        ry: f32,
        rz: f32,
        e: f32,
        lo: u32,
        hi: u32,
        n: u32,
    ) -> f32 {
        super::estimate_samples_phong(rx, ry, rz, e, lo, hi, n)
    }

    /// Starts a new 64-sample RGB Bayesian Monte Carlo probe without data, rotated by
    /// `RotationSequence::new(seed).next_rotation()` (unrotated for `seed` = 0); 0, or an
    /// error code.
    #[no_mangle]
    pub extern "C" fn bmc_probe_reset(seed: u32) -> i32 {
        super::bmc_reset(seed)
    }

    /// Writes the BMC probe's 64 directions (x, y, z each) to `dirs_ptr()`; returns 64, or −1.
    #[no_mangle]
    pub extern "C" fn bmc_probe_directions() -> i32 {
        super::bmc_directions()
    }

    /// Updates the BMC probe with the 64 RGB radiance samples (r, g, b each, in the order of
    /// `bmc_probe_directions`) at `samples_ptr()`; 0, or an error code (2: a NaN or infinite
    /// sample; the probe then keeps its previous data).
    #[no_mangle]
    pub extern "C" fn bmc_probe_update() -> i32 {
        super::bmc_update()
    }

    /// Writes the BMC probe's irradiance about `(nx, ny, nz)`, `[r, g, b, var_r, var_g,
    /// var_b]`, to `bmc_out_ptr()`; 0, or an error code (1: a zero or non-finite normal; the
    /// six values are then NaN). Zero before the first update.
    #[no_mangle]
    pub extern "C" fn bmc_probe_irradiance(nx: f32, ny: f32, nz: f32) -> i32 {
        super::bmc_irradiance(nx, ny, nz)
    }

    /// Writes the BMC probe's normalised Phong glossy radiance about the reflection direction
    /// `(rx, ry, rz)` with exponent `e` (lobe `SphericalGaussian::phong_moments`), `[r, g, b,
    /// var_r, var_g, var_b]` with the exact variance, to `bmc_out_ptr()`; 0, or an error code
    /// (1: a zero or non-finite direction, 4: a negative or non-finite exponent; the six
    /// values are then NaN). Zero before the first update.
    #[no_mangle]
    pub extern "C" fn bmc_probe_glossy(rx: f32, ry: f32, rz: f32, e: f32) -> i32 {
        super::bmc_glossy(rx, ry, rz, e)
    }

    /// Writes the directions of an `n`-sample BMC probe (n = 16, 32, 64, 128 or 256) rotated as
    /// by `bmc_probe_reset(seed)` to `dirs_ptr()`; returns `n`, or −1 for any other `n`.
    #[no_mangle]
    pub extern "C" fn bmc_shade_directions(n: u32, seed: u32) -> i32 {
        with_point_probe!(n, shade_directions(seed), -1)
    }

    /// Shades many points from one probe: updates an `n`-sample RGB probe (rotation `seed`)
    /// with the `3n` samples at `samples_ptr()` (at the directions of `bmc_shade_directions`),
    /// then for each of `count` ≤ 1024 queries at `queries_ptr()` (normal x, y, z, reflection
    /// x, y, z) writes irradiance RGB and normalised Phong glossy RGB (exponent `e`) to
    /// `shaded_ptr()` (NaN for a bad direction). 0, or an error code (2: a NaN or infinite
    /// sample; 5: bad `n` or `count`; 4: bad exponent).
    #[no_mangle]
    pub extern "C" fn bmc_shade(n: u32, seed: u32, count: u32, e: f32) -> i32 {
        super::shade_code(false, n, seed, count, e)
    }

    /// The Gaussian footprint sharpness `S = n/8` of the footprint probe of `n` samples (n =
    /// 16, 32, 64, 128 or 256); −1 for any other `n`.
    #[no_mangle]
    pub extern "C" fn footprint_sharpness(n: u32) -> i32 {
        super::footprint_sharpness(n)
    }

    /// `bmc_shade_directions` for the footprint probe `Probe<n, [f32; 3], Gaussian<n/8>>`.
    #[no_mangle]
    pub extern "C" fn footprint_shade_directions(n: u32, seed: u32) -> i32 {
        with_footprint_probe!(n, shade_directions(seed), -1)
    }

    /// `bmc_shade` for the footprint probe `Probe<n, [f32; 3], Gaussian<n/8>>`: the `3n`
    /// samples at `samples_ptr()` are the map filtered by the normalised spherical Gaussian of
    /// sharpness `footprint_sharpness(n)` about each direction of
    /// `footprint_shade_directions` (as `map_footprint_samples` takes them).
    #[no_mangle]
    pub extern "C" fn footprint_shade(n: u32, seed: u32, count: u32, e: f32) -> i32 {
        super::shade_code(true, n, seed, count, e)
    }

    /// Address of the map buffer (`3·map_max()` f32: r, g, b per pixel, row-major, row 0 at
    /// +z), written by JavaScript.
    #[no_mangle]
    pub extern "C" fn map_ptr() -> usize {
        MAP.as_ptr() as usize
    }

    /// Capacity of the map buffer in pixels (512·256).
    #[no_mangle]
    pub extern "C" fn map_max() -> u32 {
        api::MAP_MAX as u32
    }

    /// Footprint samples of the `width`×`height` map at `map_ptr()` in the first `count` ≤ 1024
    /// directions at `dirs_ptr()`, RGB into `samples_ptr()`: each the map filtered by the
    /// normalised spherical Gaussian of sharpness `sharpness` (0: the nearest pixel), exact
    /// over every pixel (`sampler` 0, `EquirectMap::footprint_samples`) or from a mip pyramid
    /// (`sampler` 1, `MipPyramid::footprint_samples`, fast and approximate). 0, or an error
    /// code (1: a bad direction; 2: a NaN or infinite pixel; 3: bad `sharpness` or `sampler`;
    /// 5: a bad `count`, a zero size, more than `map_max()` pixels, or a shape whose pyramid
    /// does not fit); the samples are then unchanged.
    #[no_mangle]
    pub extern "C" fn map_footprint_samples(
        width: u32,
        height: u32,
        count: u32,
        sharpness: u32,
        sampler: u32,
    ) -> i32 {
        super::map_samples(width, height, count, sharpness, sampler)
    }

    /// Address of the `bmc_shade` query buffer (6·1024 f32).
    #[no_mangle]
    pub extern "C" fn queries_ptr() -> usize {
        QUERIES.as_ptr() as usize
    }

    /// Address of the `bmc_shade` result buffer (6·1024 f32).
    #[no_mangle]
    pub extern "C" fn shaded_ptr() -> usize {
        SHADED.as_ptr() as usize
    }

    /// The BMC probe's selected family member (index into its baked family); −1 on error.
    #[no_mangle]
    pub extern "C" fn bmc_probe_selected() -> i32 {
        super::bmc_selected()
    }

    /// Address of the BMC irradiance output (6 f32).
    #[no_mangle]
    pub extern "C" fn bmc_out_ptr() -> usize {
        BMC_OUT.as_ptr() as usize
    }

    /// The procedural sky of the scenario.
    #[no_mangle]
    pub extern "C" fn sky(x: f32, y: f32, z: f32) -> f32 {
        api::sky(x, y, z)
    }

    /// See [`api::qmc_irradiance_64`].
    #[no_mangle]
    pub extern "C" fn qmc_irradiance_64(nx: f32, ny: f32, nz: f32, lo: u32, hi: u32) -> f32 {
        api::qmc_irradiance_64(nx, ny, nz, lo, hi)
    }

    /// See [`api::phong_64`].
    #[no_mangle]
    pub extern "C" fn phong_64(rx: f32, ry: f32, rz: f32, e: f32, lo: u32, hi: u32) -> f32 {
        api::phong_64(rx, ry, rz, e, lo, hi)
    }

    /// See [`api::sf_point_component`].
    #[no_mangle]
    pub extern "C" fn sf_point_component(n_kind: u32, j: u32, component: u32) -> f32 {
        api::sf_point_component(n_kind, j, component)
    }

    /// See [`api::nearest_index_4096`].
    #[no_mangle]
    pub extern "C" fn nearest_index_4096(x: f32, y: f32, z: f32) -> i32 {
        api::nearest_index_4096(x, y, z)
    }

    /// See [`api::sg_hemispherical_fraction`].
    #[no_mangle]
    pub extern "C" fn sg_hemispherical_fraction(lambda: f32, t: f32) -> f32 {
        api::sg_hemispherical_fraction(lambda, t)
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    core::arch::wasm32::unreachable()
}
