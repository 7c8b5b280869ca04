//! The probes of a size module, `probe-N.wasm` (built with one of the features `n16`, `n32`,
//! `n64`, `n128`, `n256`): RGB Bayesian Monte Carlo probes `Probe<N, [f32; 3]>` of the baked
//! size `N` and RGB temporal probes of the same ray budget,
//! `TemporalProbe<N − S, [f32; 3], F, S>` with `S` sentinels ([`SENTINELS`]) and the point
//! (`F = Point`) or the Gaussian footprint of sharpness `N/8` ([`SHARPNESS`]).

use std::boxed::Box;
use std::sync::atomic::Ordering::Relaxed;
use std::sync::Mutex;
use std::vec::Vec;

use sphere_quadrature::footprint::{Footprint, Gaussian, Point};
use sphere_quadrature::probe::Probe;
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::sh::ShL2;
use sphere_quadrature::temporal::{Change, TemporalProbe};
use sphere_quadrature::{Error, RotationSequence, Vec3};

use super::{code, insert, store, store_bits, store_estimate, INVALID_HANDLE, IO, OTHER};

// More than one size feature defines `N` twice, which fails to compile too.
/// The probe's sample count, fixed per build.
#[cfg(feature = "n16")]
const N: usize = 16;
/// The probe's sample count, fixed per build.
#[cfg(feature = "n32")]
const N: usize = 32;
/// The probe's sample count, fixed per build.
#[cfg(feature = "n64")]
const N: usize = 64;
/// The probe's sample count, fixed per build.
#[cfg(feature = "n128")]
const N: usize = 128;
/// The probe's sample count, fixed per build.
#[cfg(feature = "n256")]
const N: usize = 256;

/// The probe of this module: `N` RGB point samples.
type RgbProbe = Probe<N, [f32; 3]>;

/// The sentinels of the temporal probes among their `N` rays per update: `round(√N/4)`
/// (1, 1, 2, 3, 4 for `N` = 16, 32, 64, 128, 256).
const SENTINELS: usize = match N {
    16 | 32 => 1,
    64 => 2,
    128 => 3,
    _ => 4,
};

/// The rotated directions of a temporal probe: the rest of the `N` rays.
const ROTATED: usize = N - SENTINELS;

/// The sharpness `N/8` of the footprint temporal probe's normalised spherical Gaussian.
const SHARPNESS: u32 = (N / 8) as u32;

/// The temporal probe of point samples.
type PointTemporal = TemporalProbe<ROTATED, [f32; 3], Point, SENTINELS>;

/// The temporal probe of footprint samples (the Gaussian of sharpness [`SHARPNESS`]).
type FootprintTemporal = TemporalProbe<ROTATED, [f32; 3], Gaussian<SHARPNESS>, SENTINELS>;

/// A temporal probe of either footprint.
enum Temporal {
    Point(PointTemporal),
    Footprint(FootprintTemporal),
}

/// Floats of the [`IO`] buffer: `3·N` samples or directions (a temporal update: `3·(N − S)`
/// samples, then `3·S` sentinel readings), 27 SH coefficients or variances, 6 query
/// results.
pub(crate) const IO_LEN: usize = if 3 * N > 27 { 3 * N } else { 27 };

/// The live probes; `None` marks a freed handle (reused by the next `probe_new`).
static PROBES: Mutex<Vec<Option<Box<RgbProbe>>>> = Mutex::new(Vec::new());

/// The live temporal probes, as [`PROBES`] (handles of their own).
static TEMPORAL: Mutex<Vec<Option<Box<Temporal>>>> = Mutex::new(Vec::new());

/// Runs `f` on probe `handle`; 0, or the error code.
fn with_probe(handle: u32, f: impl FnOnce(&mut RgbProbe) -> Result<(), Error>) -> i32 {
    let Ok(mut probes) = PROBES.lock() else { return OTHER };
    let Some(Some(p)) = probes.get_mut(handle as usize) else { return INVALID_HANDLE };
    f(p).map_or_else(code, |()| 0)
}

/// A new probe (rotation `seed`); its handle, or a negated error code.
fn new_probe(seed: u32) -> i32 {
    let mut p = Box::new(RgbProbe::new());
    if seed != 0 {
        if let Err(e) = p.set_rotation(RotationSequence::new(u64::from(seed)).next_rotation()) {
            return -code(e);
        }
    }
    insert(&PROBES, p)
}

/// The probe's directions, x, y, z each, into [`IO`].
fn directions(p: &mut RgbProbe) -> Result<(), Error> {
    store(p.directions().iter().flat_map(|d| [d.x, d.y, d.z]));
    Ok(())
}

/// Updates the probe with the `3·N` floats (r, g, b per direction) at the start of [`IO`].
fn update(p: &mut RgbProbe) -> Result<(), Error> {
    let mut ys = [[0.0f32; 3]; N];
    for (y, a) in ys.iter_mut().zip(IO.chunks_exact(3)) {
        for (c, v) in y.iter_mut().zip(a) {
            *c = f32::from_bits(v.load(Relaxed));
        }
    }
    p.update(&ys)
}

/// Irradiance about `normal` with its variance into [`IO`].
fn irradiance(p: &RgbProbe, normal: Vec3) -> Result<(), Error> {
    let e = p.irradiance(normal)?;
    store_estimate(e.value, e.variance);
    Ok(())
}

/// Normalised Phong glossy radiance about `r` (exponent `e`, the lobe
/// `SphericalGaussian::phong_moments`) with its exact variance into [`IO`].
fn glossy(p: &RgbProbe, r: Vec3, e: f32) -> Result<(), Error> {
    let lobe = SphericalGaussian::phong_moments(r, e)?;
    let value = p.glossy(&lobe)?.value;
    store_estimate(value, p.glossy_variance(&lobe)?);
    Ok(())
}

/// The probe's 9 RGB SH coefficients, computed in one place for every export that needs them
/// (inlined into each, the module would carry the computation several times).
#[inline(never)]
fn sh_of(p: &RgbProbe) -> ShL2<[f32; 3]> {
    p.radiance_sh()
}

/// The 9 RGB SH coefficients (r, g, b each) into [`IO`].
fn radiance_sh(p: &RgbProbe) -> Result<(), Error> {
    store(sh_of(p).coefficients.into_iter().flatten());
    Ok(())
}

/// Error code of a `frame` other than 0 (y-up) and 1 (z-up): `index.js`'s `InvalidParameter`.
const INVALID_FRAME: i32 = 5;

/// three.js `SphericalHarmonics3` coefficients (r, g, b each) of `sh` into [`IO`]: the
/// probe's directions are in a z-up frame (`z_up`: rotated to y-up) or a y-up one (unchanged).
#[inline(never)]
fn three_js_sh(sh: &ShL2<[f32; 3]>, z_up: bool) -> Result<(), Error> {
    let c = if z_up { sh.three_js_from_z_up() } else { sh.three_js_from_y_up() };
    store(c.into_iter().flatten());
    Ok(())
}

/// The 9 RGB SH coefficient variances (r, g, b each) into [`IO`].
fn radiance_sh_variance(p: &RgbProbe) -> Result<(), Error> {
    store(p.radiance_sh_variance().into_iter().flatten());
    Ok(())
}

/// A new temporal probe (rotations from `seed`, point samples for `footprint` 0, Gaussian
/// footprint samples for 1, prior change probability `hazard`); its handle, or a negated
/// error code (5 for another `footprint` or a hazard outside (0, 1)).
fn new_temporal(seed: u32, footprint: u32, hazard: f32) -> i32 {
    let t = match footprint {
        0 => PointTemporal::new(u64::from(seed)).with_hazard(hazard).map(Temporal::Point),
        1 => FootprintTemporal::new(u64::from(seed)).with_hazard(hazard).map(Temporal::Footprint),
        _ => Err(Error::InvalidResponse),
    };
    match t {
        Ok(t) => insert(&TEMPORAL, Box::new(t)),
        Err(e) => -code(e),
    }
}

/// Runs `f` on temporal probe `handle`; 0, or the error code.
fn with_temporal(handle: u32, f: impl FnOnce(&mut Temporal) -> Result<(), Error>) -> i32 {
    let Ok(mut probes) = TEMPORAL.lock() else { return OTHER };
    let Some(Some(t)) = probes.get_mut(handle as usize) else { return INVALID_HANDLE };
    f(t).map_or_else(code, |()| 0)
}

/// `$body` with `$p` bound to the temporal probe of either footprint in `$t`.
macro_rules! either {
    ($t:expr, $p:ident => $body:expr) => {
        match $t {
            Temporal::Point($p) => $body,
            Temporal::Footprint($p) => $body,
        }
    };
}

/// The temporal probe's `S` sentinel directions, x, y, z each, into [`IO`].
fn temporal_sentinels<F: Footprint>(
    p: &TemporalProbe<ROTATED, [f32; 3], F, SENTINELS>,
) -> Result<(), Error> {
    store(p.sentinels().iter().flat_map(|d| [d.x, d.y, d.z]));
    Ok(())
}

/// The temporal probe's `N − S` current directions, x, y, z each, into [`IO`].
fn temporal_directions<F: Footprint>(
    p: &TemporalProbe<ROTATED, [f32; 3], F, SENTINELS>,
) -> Result<(), Error> {
    store(p.directions().iter().flat_map(|d| [d.x, d.y, d.z]));
    Ok(())
}

/// Pools the `3·(N − S)` samples and then `3·S` sentinel readings at the start of [`IO`]
/// into the temporal probe; writes what it did with the old evidence (1 first, 2 blended,
/// 3 reset, as u32) to `IO[0]`.
fn temporal_pool<F: Footprint>(
    p: &mut TemporalProbe<ROTATED, [f32; 3], F, SENTINELS>,
) -> Result<(), Error> {
    let load = |i: usize| IO.get(i).map_or(0.0, |a| f32::from_bits(a.load(Relaxed)));
    let samples: [[f32; 3]; ROTATED] = core::array::from_fn(|j| [0, 1, 2].map(|c| load(3 * j + c)));
    let sentinels: [[f32; 3]; SENTINELS] =
        core::array::from_fn(|j| [0, 1, 2].map(|c| load(3 * (ROTATED + j) + c)));
    let change = p.pool(&samples, &sentinels)?;
    store_bits([match change {
        Change::First => 1,
        Change::Blended => 2,
        Change::Reset => 3,
    }]);
    Ok(())
}

/// The temporal probe's irradiance about `normal` with its variance into [`IO`].
fn temporal_irradiance<F: Footprint>(
    p: &TemporalProbe<ROTATED, [f32; 3], F, SENTINELS>,
    normal: Vec3,
) -> Result<(), Error> {
    let e = p.irradiance(normal)?;
    store_estimate(e.value, e.variance);
    Ok(())
}

/// The temporal probe's 9 RGB SH coefficients (`variance`: their variances) into [`IO`].
fn temporal_sh<F: Footprint>(
    p: &TemporalProbe<ROTATED, [f32; 3], F, SENTINELS>,
    variance: bool,
) -> Result<(), Error> {
    if variance {
        store(p.radiance_sh_variance().iter().flatten().copied());
    } else {
        store(p.radiance_sh().coefficients.iter().flatten().copied());
    }
    Ok(())
}

/// The temporal probe's three.js SH coefficients (`frame` as in [`three_js_sh`]) into [`IO`].
fn temporal_three_js_sh<F: Footprint>(
    p: &TemporalProbe<ROTATED, [f32; 3], F, SENTINELS>,
    z_up: bool,
) -> Result<(), Error> {
    three_js_sh(p.radiance_sh(), z_up)
}

/// The temporal probe's state into [`IO`]: updates and degree (u32 bits), then the pooled
/// updates, the last change probability and its two log Bayes factors (f32).
fn temporal_state<F: Footprint>(
    p: &TemporalProbe<ROTATED, [f32; 3], F, SENTINELS>,
) -> Result<(), Error> {
    let (rotated, sentinels) = p.last_evidence();
    let floats = [p.pooled_updates(), p.last_change_probability(), rotated, sentinels];
    let degree = u32::try_from(p.degree()).unwrap_or(u32::MAX);
    store_bits([p.updates(), degree].into_iter().chain(floats.map(f32::to_bits)));
    Ok(())
}

#[allow(unsafe_code)] // `#[no_mangle]` only; every body is one safe call.
mod exports {
    use super::{with_probe, with_temporal, Temporal, Vec3, IO, N};
    use super::{INVALID_FRAME, SENTINELS, SHARPNESS};
    use crate::IO_LEN;

    /// The module's probe size `N`.
    #[no_mangle]
    pub extern "C" fn probe_size() -> u32 {
        N as u32
    }

    /// Address of the exchange buffer (`io_len()` f32) in the module's memory.
    #[no_mangle]
    pub extern "C" fn io_ptr() -> usize {
        IO.as_ptr() as usize
    }

    /// Length of the exchange buffer in f32: `max(3·N, 27)`.
    #[no_mangle]
    pub extern "C" fn io_len() -> u32 {
        IO_LEN as u32
    }

    /// A new probe without data, on the spherical Fibonacci set rotated by
    /// `RotationSequence::new(seed).next_rotation()` (unrotated for `seed` = 0); its handle
    /// (≥ 0), or a negated error code.
    #[no_mangle]
    pub extern "C" fn probe_new(seed: u32) -> i32 {
        super::new_probe(seed)
    }

    /// Frees probe `handle`; 0, or 100 (no such probe).
    #[no_mangle]
    pub extern "C" fn probe_free(handle: u32) -> i32 {
        crate::free(&super::PROBES, handle)
    }

    /// Writes the probe's `N` unit directions (x, y, z each) to the exchange buffer; 0, or an
    /// error code.
    #[no_mangle]
    pub extern "C" fn probe_directions(handle: u32) -> i32 {
        with_probe(handle, super::directions)
    }

    /// Updates the probe with the `N` RGB samples (r, g, b each, in the order of the
    /// directions) in the exchange buffer; 0, or an error code (7: a NaN or infinite sample;
    /// the probe keeps its previous data).
    #[no_mangle]
    pub extern "C" fn probe_update(handle: u32) -> i32 {
        with_probe(handle, super::update)
    }

    /// Writes `[r, g, b, var_r, var_g, var_b]`, the irradiance about `(nx, ny, nz)` and its
    /// posterior variance, to the exchange buffer; 0, or an error code (1: a zero or
    /// non-finite normal).
    #[no_mangle]
    pub extern "C" fn probe_irradiance(handle: u32, nx: f32, ny: f32, nz: f32) -> i32 {
        with_probe(handle, |p| super::irradiance(p, Vec3::new(nx, ny, nz)))
    }

    /// Writes `[r, g, b, var_r, var_g, var_b]`, the normalised Phong glossy radiance about
    /// `(rx, ry, rz)` with exponent `e` (lobe `SphericalGaussian::phong_moments`) and its
    /// exact posterior variance, to the exchange buffer; 0, or an error code (1: a zero or
    /// non-finite direction; 2: a negative or non-finite exponent).
    #[no_mangle]
    pub extern "C" fn probe_glossy(handle: u32, rx: f32, ry: f32, rz: f32, e: f32) -> i32 {
        with_probe(handle, |p| super::glossy(p, Vec3::new(rx, ry, rz), e))
    }

    /// Writes the 9 RGB spherical-harmonic coefficients of the posterior mean radiance
    /// (index `l(l + 1) + m`, r, g, b each) to the exchange buffer; 0, or an error code.
    #[no_mangle]
    pub extern "C" fn probe_radiance_sh(handle: u32) -> i32 {
        with_probe(handle, |p| super::radiance_sh(p))
    }

    /// Writes the posterior variances of the 9 RGB coefficients to the exchange buffer; 0,
    /// or an error code.
    #[no_mangle]
    pub extern "C" fn probe_radiance_sh_variance(handle: u32) -> i32 {
        with_probe(handle, |p| super::radiance_sh_variance(p))
    }

    /// Writes the 27 floats of three.js `SphericalHarmonics3.coefficients` (r, g, b of each
    /// of the 9, for `fromArray`) of the posterior mean radiance to the exchange buffer: the
    /// probe's directions are three.js world directions (`frame` 0, y-up: unchanged) or in a
    /// z-up frame (`frame` 1: rotated to y-up by `(x, y, z) ↦ (x, z, −y)`); 0, or an error
    /// code (5, `InvalidParameter`: another `frame`).
    #[no_mangle]
    pub extern "C" fn probe_three_js_sh(handle: u32, frame: u32) -> i32 {
        if frame > 1 {
            return INVALID_FRAME;
        }
        with_probe(handle, |p| super::three_js_sh(&super::sh_of(p), frame == 1))
    }

    /// The sentinels `S` of the module's temporal probes (of `N` rays per update, `N − S`
    /// rotated).
    #[no_mangle]
    pub extern "C" fn temporal_sentinel_count() -> u32 {
        SENTINELS as u32
    }

    /// The sharpness `N/8` of the footprint temporal probe's normalised spherical Gaussian.
    #[no_mangle]
    pub extern "C" fn temporal_sharpness() -> u32 {
        SHARPNESS
    }

    /// A new temporal probe without data, its rotations from `RotationSequence::new(seed)`:
    /// point samples (`footprint` 0) or samples of the normalised spherical Gaussian of
    /// sharpness `N/8` (`footprint` 1), prior probability `hazard` of a change per update;
    /// its handle (≥ 0), or a negated error code (5: another `footprint`, a hazard outside
    /// (0, 1)).
    #[no_mangle]
    pub extern "C" fn temporal_new(seed: u32, footprint: u32, hazard: f32) -> i32 {
        super::new_temporal(seed, footprint, hazard)
    }

    /// Frees temporal probe `handle`; 0, or 100 (no such probe).
    #[no_mangle]
    pub extern "C" fn temporal_free(handle: u32) -> i32 {
        crate::free(&super::TEMPORAL, handle)
    }

    /// Writes the `N − S` directions of this update (x, y, z each) to the exchange buffer; 0,
    /// or an error code.
    #[no_mangle]
    pub extern "C" fn temporal_directions(handle: u32) -> i32 {
        with_temporal(handle, |t| either!(t, p => super::temporal_directions(p)))
    }

    /// Writes this update's `S` sentinel directions (x, y, z each) to the exchange buffer; 0, or
    /// an error code.
    #[no_mangle]
    pub extern "C" fn temporal_sentinels(handle: u32) -> i32 {
        with_temporal(handle, |t| either!(t, p => super::temporal_sentinels(p)))
    }

    /// Pools the `N − S` RGB samples (in the order of the directions) followed by the `S`
    /// RGB sentinel readings in the exchange buffer into the temporal probe and writes what it did with the old evidence to its first word (u32: 1 first, 2 blended,
    /// 3 reset); 0, or an error code (7: a NaN or infinite value; the probe keeps its state
    /// and its directions).
    #[no_mangle]
    pub extern "C" fn temporal_pool(handle: u32) -> i32 {
        with_temporal(handle, |t| either!(t, p => super::temporal_pool(p)))
    }

    /// Writes `[r, g, b, var_r, var_g, var_b]`, the accumulated irradiance about
    /// `(nx, ny, nz)` and its variance, to the exchange buffer; 0, or an error code (1: a
    /// zero or non-finite normal).
    #[no_mangle]
    pub extern "C" fn temporal_irradiance(handle: u32, nx: f32, ny: f32, nz: f32) -> i32 {
        let normal = Vec3::new(nx, ny, nz);
        with_temporal(handle, |t| either!(t, p => super::temporal_irradiance(p, normal)))
    }

    /// Writes the 9 accumulated RGB SH coefficients (r, g, b each) to the exchange buffer;
    /// 0, or an error code.
    #[no_mangle]
    pub extern "C" fn temporal_radiance_sh(handle: u32) -> i32 {
        with_temporal(handle, |t| either!(t, p => super::temporal_sh(p, false)))
    }

    /// Writes the variances of the 27 numbers of `temporal_radiance_sh` to the exchange
    /// buffer; 0, or an error code.
    #[no_mangle]
    pub extern "C" fn temporal_radiance_sh_variance(handle: u32) -> i32 {
        with_temporal(handle, |t| either!(t, p => super::temporal_sh(p, true)))
    }

    /// Writes the 27 floats of three.js `SphericalHarmonics3.coefficients` of the
    /// accumulated radiance to the exchange buffer, `frame` as in `probe_three_js_sh`; 0, or
    /// an error code (5, `InvalidParameter`: another `frame`).
    #[no_mangle]
    pub extern "C" fn temporal_three_js_sh(handle: u32, frame: u32) -> i32 {
        if frame > 1 {
            return INVALID_FRAME;
        }
        let z_up = frame == 1;
        with_temporal(handle, |t| either!(t, p => super::temporal_three_js_sh(p, z_up)))
    }

    /// Writes the temporal probe's state to the exchange buffer: updates and SH degree
    /// (u32), then pooled updates, the last change probability and the last log Bayes
    /// factors of a change from the rotated samples and from the sentinels (f32); 0, or an
    /// error code.
    #[no_mangle]
    pub extern "C" fn temporal_state(handle: u32) -> i32 {
        with_temporal(handle, |t| either!(t, p => super::temporal_state(p)))
    }
}
