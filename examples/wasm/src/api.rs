//! The scalar API exported by the WebAssembly module: plain numbers in, plain numbers out,
//! errors as NaN (or −1 for indices). Shared with the host through `#[path]` (`eval/src/lib.rs`,
//! for `eval/src/bin/wasm_scenario.rs`, which calls the same functions natively); the crate root
//! must declare `mod scenario` (the Cortex-M4 scenario, for its procedural `sky`).

use sphere_quadrature::bmc::Size;
use sphere_quadrature::envmap::{EquirectMap, MipPyramid};
use sphere_quadrature::footprint::{Footprint, Kind, Point};
use sphere_quadrature::probe::{Probe, ProbeSize, ProbeTables};
use sphere_quadrature::qmc::{self, LobeSampler};
use sphere_quadrature::{sg, Error, Lobe, RotationSequence, SphericalFibonacci, Vec3};

use crate::scenario;

/// Largest sample count of the probe-style estimator (size of its shared buffers).
pub const PROBE_MAX: usize = 4096;

/// The 64-bit phase from its two 32-bit halves (JS numbers carry 32-bit integers exactly).
pub fn phase(lo: u32, hi: u32) -> u64 {
    (u64::from(hi) << 32) | u64::from(lo)
}

/// The Cortex-M4 scenario's procedural sky at direction `(x, y, z)` (expected unit).
pub fn sky(x: f32, y: f32, z: f32) -> f32 {
    scenario::sky(Vec3::new(x, y, z))
}

/// QMC irradiance of the procedural sky from 64 directions about `(nx, ny, nz)`; NaN on error.
pub fn qmc_irradiance_64(nx: f32, ny: f32, nz: f32, lo: u32, hi: u32) -> f32 {
    qmc::irradiance::<64, f32, _>(Vec3::new(nx, ny, nz), phase(lo, hi), scenario::sky)
        .unwrap_or(f32::NAN)
}

/// Normalised Phong glossy radiance of the procedural sky from 64 directions about
/// `(rx, ry, rz)` with exponent `e`; NaN on error.
pub fn phong_64(rx: f32, ry: f32, rz: f32, e: f32, lo: u32, hi: u32) -> f32 {
    qmc::phong::<64, f32, _>(Vec3::new(rx, ry, rz), e, phase(lo, hi), scenario::sky)
        .unwrap_or(f32::NAN)
}

/// Component `component` (0 = x, 1 = y, 2 = z) of point `j` of the spherical Fibonacci set
/// with N = 64, 256, 4096 for `n_kind` = 0, 1, 2; NaN for any other `n_kind`, `j ≥ N` or
/// `component > 2`.
pub fn sf_point_component(n_kind: u32, j: u32, component: u32) -> f32 {
    let j = j as usize;
    let p = match n_kind {
        0 => SphericalFibonacci::<64>::new().point(j),
        1 => SphericalFibonacci::<256>::new().point(j),
        2 => SphericalFibonacci::<4096>::new().point(j),
        _ => None,
    };
    match (p, component) {
        (Some(p), 0) => p.x,
        (Some(p), 1) => p.y,
        (Some(p), 2) => p.z,
        _ => f32::NAN,
    }
}

/// Index of the point of the 4096-point spherical Fibonacci set nearest to `(x, y, z)`; −1 on
/// error (zero or non-finite direction).
pub fn nearest_index_4096(x: f32, y: f32, z: f32) -> i32 {
    SphericalFibonacci::<4096>::new()
        .nearest_index(Vec3::new(x, y, z))
        .map_or(-1, |j| i32::try_from(j).unwrap_or(-1))
}

/// [`sg::hemispherical_fraction`]; NaN on error.
pub fn sg_hemispherical_fraction(lambda: f32, t: f32) -> f32 {
    sg::hemispherical_fraction(lambda, t).unwrap_or(f32::NAN)
}

/// The cosine-lobe sampler of the probe-style estimator: `n` directions about `(nx, ny, nz)`;
/// `None` on bad input or `n > PROBE_MAX`.
pub fn probe_sampler(nx: f32, ny: f32, nz: f32, lo: u32, hi: u32, n: u32) -> Option<LobeSampler> {
    let n = n as usize;
    if n > PROBE_MAX {
        return None;
    }
    LobeSampler::new(Vec3::new(nx, ny, nz), Lobe::Cosine, n, phase(lo, hi)).ok()
}

/// Sample count of the Bayesian Monte Carlo probe.
pub const BMC_N: usize = 64;

/// The Bayesian Monte Carlo probe of the exports: 64 RGB samples.
pub type BmcProbe = Probe<BMC_N, [f32; 3]>;

/// A BMC probe without data on the spherical Fibonacci set, rotated by the first rotation of
/// `RotationSequence::new(seed)`, or unrotated for `seed` = 0.
///
/// # Errors
/// Those of [`Probe::set_rotation`] (none for the rotations of the sequence).
pub fn bmc_probe(seed: u32) -> Result<BmcProbe, Error> {
    bmc_probe_n::<BMC_N>(seed)
}

/// [`bmc_probe`] for any baked size `N`.
///
/// # Errors
/// Those of [`Probe::set_rotation`] (none for the rotations of the sequence).
pub fn bmc_probe_n<const N: usize>(seed: u32) -> Result<Probe<N, [f32; 3]>, Error>
where
    Size<N>: ProbeSize,
{
    probe_nf::<N, Point>(seed)
}

/// [`bmc_probe_n`] for any baked pair of size `N` and footprint `F`.
///
/// # Errors
/// Those of [`Probe::set_rotation`] (none for the rotations of the sequence).
pub fn probe_nf<const N: usize, F: Footprint>(seed: u32) -> Result<Probe<N, [f32; 3], F>, Error>
where
    Size<N>: ProbeTables<F>,
{
    let mut p = Probe::new();
    if seed != 0 {
        p.set_rotation(RotationSequence::new(u64::from(seed)).next_rotation())?;
    }
    Ok(p)
}

/// Most pixels of a map the module samples (the bundled maps are 512×256).
pub const MAP_MAX: usize = 512 * 256;

/// `[f32; 3]` entries of the mip-pyramid buffer: a 512×256 map's pyramid (524 304 bytes).
/// Other shapes of at most [`MAP_MAX`] pixels fit unless far from 2:1 (then
/// [`map_footprint_samples`] fails with [`Error::LengthMismatch`]).
pub const PYRAMID_MAX: usize = MipPyramid::buffer_len(512, 256);

/// Pixels of a `width`×`height` map the module takes: `width·height`.
///
/// # Errors
/// [`Error::InvalidSize`] for a zero dimension or more than [`MAP_MAX`] pixels.
pub fn map_len(width: usize, height: usize) -> Result<usize, Error> {
    width.checked_mul(height).filter(|&len| (1..=MAP_MAX).contains(&len)).ok_or(Error::InvalidSize)
}

/// [`map_footprint_samples`]'s `sampler`: exact (`EquirectMap::footprint_samples`, every pixel).
pub const EXACT: u32 = 0;
/// [`map_footprint_samples`]'s `sampler`: the fast approximation (`MipPyramid::footprint_samples`).
pub const PYRAMID: u32 = 1;

/// Footprint samples of the `width`×`height` RGB map `pixels` (row-major, row 0 at +z) in the
/// directions `dirs`, into `out`: each the map filtered by the normalised spherical Gaussian
/// of sharpness `sharpness` about its direction (0: the nearest pixel), taken exactly
/// ([`EXACT`]) or from a mip pyramid built in `pyramid` ([`PYRAMID`]).
///
/// # Errors
/// [`Error::InvalidResponse`] for another `sampler` or a sharpness above 4096; those of
/// [`EquirectMap::new`] (bad size, pixel count, NaN or infinite pixel), of
/// [`MipPyramid::new`] (`pyramid` too short) and of `footprint_samples` (bad direction,
/// `out` and `dirs` of different lengths). `out` is left unchanged on error.
pub fn map_footprint_samples(
    pixels: &[[f32; 3]],
    (width, height): (usize, usize),
    dirs: &[Vec3],
    sharpness: u32,
    sampler: u32,
    pyramid: &mut [[f32; 3]],
    out: &mut [[f32; 3]],
) -> Result<(), Error> {
    let kind = if sharpness == 0 { Kind::Point } else { Kind::Gaussian { sharpness } };
    let map = EquirectMap::new(width, height, pixels)?;
    match sampler {
        EXACT => map.footprint_samples(dirs, kind, out),
        PYRAMID => MipPyramid::new(&map, pyramid)?.footprint_samples(dirs, kind, out),
        _ => Err(Error::InvalidResponse),
    }
}

/// The status code the exports return for an error (0 means success).
pub fn error_code(e: Error) -> i32 {
    match e {
        Error::InvalidDirection => 1,
        Error::InvalidRadiance => 2,
        e if e.is_out_of_range() => 3,
        Error::InvalidExponent | Error::InvalidSharpness => 4,
        Error::InvalidSize | Error::LengthMismatch => 5,
        _ => 255,
    }
}
