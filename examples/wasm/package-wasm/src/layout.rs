//! The layout module, `layout.wasm` (built with the feature `layout` alone): RGB layout
//! probes `LayoutProbe<K, [f32; 3]>` over a user's sensors, for `K` in [`CAPACITIES`]. The
//! sensor count is a const generic in Rust and every sensor must be a real one (a padded
//! layout would be another layout), so each `K` is its own instantiation, about 18 KB of
//! code: the module carries a fixed set, the counts of common boards (a tetrahedron, a dome
//! of five, a cube, a hemisphere of seven, a ring of eight, an icosahedron, sixteen).
//!
//! A probe is built from the sensors in the exchange buffer ([`IO`]): `3·K` direction
//! components, then `K` cosine powers, then `K` noise scales; readings cross the same way
//! (`3·K` floats, r, g, b per sensor).

use std::boxed::Box;
use std::sync::atomic::Ordering::Relaxed;
use std::sync::Mutex;
use std::vec::Vec;

use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Response, Sensor};
use sphere_quadrature::temporal::Change;
use sphere_quadrature::{Error, Vec3};

use super::{code, insert, store, store_bits, INVALID_HANDLE, IO, OTHER};

/// Defines [`CAPACITIES`], [`Layout`], `each!` and [`build`] from the one list of sizes
/// (`$d` is a `$` for the inner macro).
macro_rules! define {
    ($d:tt $($k:literal $v:ident),*) => {
        /// The sensor counts `K` a layout probe may have (each its own instantiation).
        pub(crate) const CAPACITIES: &[u32] = &[$($k),*];

        /// A layout probe of one of the [`CAPACITIES`] (each boxed: about 3 KB at `K` = 4,
        /// 7 KB at 16).
        enum Layout {
            $($v(Box<LayoutProbe<$k, [f32; 3]>>),)*
        }

        /// `$body` with `$p` bound to the probe of whatever size in `$l`.
        macro_rules! each {
            ($d l:expr, $d p:ident => $d body:expr) => {
                match $d l {
                    $(Layout::$v(b) => {
                        let $d p = &mut **b;
                        $d body
                    })*
                }
            };
        }

        /// A new layout probe of `k` sensors from [`IO`]; [`Error::InvalidSize`] for a `k`
        /// not in [`CAPACITIES`].
        fn build(k: usize, prior: Prior, noise: Noise, hazard: f32) -> Result<Box<Layout>, Error> {
            match k {
                $($k => Ok(Box::new(Layout::$v(Box::new(
                    LayoutProbe::new(&sensors::<$k>(), prior, noise)?.with_hazard(hazard)?,
                )))),)*
                _ => Err(Error::InvalidSize),
            }
        }
    };
}

define! {
    $ 4 K4, 5 K5, 6 K6, 7 K7, 8 K8, 12 K12, 16 K16
}

/// The largest of [`CAPACITIES`] (which increase).
const MAX_K: usize = 16;
const _: () = assert!(CAPACITIES[CAPACITIES.len() - 1] as usize == MAX_K);

/// Floats of the [`IO`] buffer: a layout's `5·K` sensor floats (directions, powers, noise
/// scales), `3·K` readings, 27 SH coefficients, 6 query results.
pub(crate) const IO_LEN: usize = if 5 * MAX_K > 27 { 5 * MAX_K } else { 27 };

/// The live layout probes; `None` marks a freed handle.
static LAYOUTS: Mutex<Vec<Option<Box<Layout>>>> = Mutex::new(Vec::new());

/// Float `i` of [`IO`] (0 past its end).
fn load(i: usize) -> f32 {
    IO.get(i).map_or(0.0, |a| f32::from_bits(a.load(Relaxed)))
}

/// The `K` sensors in [`IO`]: directions (`3·K`), cosine powers (`K`), noise scales (`K`).
fn sensors<const K: usize>() -> [Sensor; K] {
    core::array::from_fn(|i| {
        let d = Vec3::new(load(3 * i), load(3 * i + 1), load(3 * i + 2));
        Sensor::new(d, Response::CosinePower(load(3 * K + i))).with_noise_scale(load(4 * K + i))
    })
}

/// The `K` RGB readings at the start of [`IO`].
fn readings<const K: usize>() -> [[f32; 3]; K] {
    core::array::from_fn(|i| [0, 1, 2].map(|c| load(3 * i + c)))
}

/// The prior of code `prior` (0 environment, 1 smooth environment, 2 sky above, 3 smooth sky
/// above, 4 the squared exponential of `lambda`).
fn prior_of(prior: u32, lambda: f32) -> Result<Prior, Error> {
    match prior {
        0 => Ok(Prior::ENVIRONMENT),
        1 => Ok(Prior::SMOOTH_ENVIRONMENT),
        2 => Ok(Prior::SKY_ABOVE),
        3 => Ok(Prior::SMOOTH_SKY_ABOVE),
        4 => Prior::squared_exponential(lambda),
        _ => Err(Error::InvalidPrior),
    }
}

/// A new layout probe (see `exports::layout_new`); its handle, or a negated error code.
fn new_layout(k: u32, prior: u32, lambda: f32, absolute: f32, relative: f32, hazard: f32) -> i32 {
    let built = prior_of(prior, lambda)
        .and_then(|p| build(k as usize, p, Noise { absolute, relative }, hazard));
    match built {
        Ok(l) => insert(&LAYOUTS, l),
        Err(e) => -code(e),
    }
}

/// Runs `f` on layout probe `handle`; 0, or the error code.
fn with_layout(handle: u32, f: impl FnOnce(&mut Layout) -> Result<(), Error>) -> i32 {
    let Ok(mut all) = LAYOUTS.lock() else { return OTHER };
    let Some(Some(l)) = all.get_mut(handle as usize) else { return INVALID_HANDLE };
    f(l).map_or_else(code, |()| 0)
}

/// The probe's unit directions, x, y, z each, into [`IO`].
fn directions<const K: usize>(p: &LayoutProbe<K, [f32; 3]>) -> Result<(), Error> {
    store(p.directions().iter().flat_map(|d| [d.x, d.y, d.z]));
    Ok(())
}

/// Updates with (`pool` false) or pools the readings in [`IO`]; writes what pooling did
/// (1 first, 2 blended, 3 reset; 0 for an update) to `IO[0]` as u32.
fn take<const K: usize>(p: &mut LayoutProbe<K, [f32; 3]>, pool: bool) -> Result<(), Error> {
    let ys = readings::<K>();
    let change = if pool {
        match p.pool(&ys)? {
            Change::First => 1,
            Change::Blended => 2,
            Change::Reset => 3,
        }
    } else {
        p.update(&ys)?;
        0
    };
    store_bits([change]);
    Ok(())
}

/// The probe's state into [`IO`]: `K` and whether it has had an update (u32), then the
/// pooled updates, the last change probability and the signal variance per channel (f32).
fn state<const K: usize>(p: &LayoutProbe<K, [f32; 3]>) -> Result<(), Error> {
    let [sr, sg, sb] = p.signal_variance();
    let floats = [p.pooled_updates(), p.last_change_probability(), sr, sg, sb];
    store_bits([K as u32, u32::from(p.is_updated())].into_iter().chain(floats.map(f32::to_bits)));
    Ok(())
}

#[allow(unsafe_code)] // `#[no_mangle]` only; every body is one safe call.
mod exports {
    use super::{with_layout, Layout, Vec3, CAPACITIES, LAYOUTS};
    use crate::{store, store_bits, store_estimate, IO, IO_LEN};

    /// Address of the exchange buffer (`io_len()` f32) in the module's memory.
    #[no_mangle]
    pub extern "C" fn io_ptr() -> usize {
        IO.as_ptr() as usize
    }

    /// Length of the exchange buffer in f32: `5·K` for the largest `K`.
    #[no_mangle]
    pub extern "C" fn io_len() -> u32 {
        IO_LEN as u32
    }

    /// Writes the supported sensor counts `K` (u32, increasing) to the exchange buffer;
    /// returns how many there are.
    #[no_mangle]
    pub extern "C" fn layout_capacities() -> u32 {
        store_bits(CAPACITIES.iter().copied());
        CAPACITIES.len() as u32
    }

    /// A new RGB layout probe of `k` sensors whose directions (`3k` floats, x, y, z each; need
    /// not be unit), cosine powers (`k` floats; 1: a bare photodiode) and noise scales (`k`
    /// floats; 1: the layout's absolute noise) are in the exchange buffer, in that order;
    /// prior 0 environment, 1 smooth environment, 2 sky above (`+z` up), 3 smooth sky above,
    /// 4 the squared exponential of `lambda`; read noise `absolute` (σ) and `relative` (η);
    /// prior probability `hazard` of a change per `layout_pool`. Its handle (≥ 0), or
    /// a negated error code (4: `k` is not a supported count; 1: a zero or non-finite
    /// direction; 5: a bad power, noise scale, noise, prior, λ or hazard, or more than four
    /// distinct powers).
    #[no_mangle]
    pub extern "C" fn layout_new(
        k: u32,
        prior: u32,
        lambda: f32,
        absolute: f32,
        relative: f32,
        hazard: f32,
    ) -> i32 {
        super::new_layout(k, prior, lambda, absolute, relative, hazard)
    }

    /// Frees layout probe `handle`; 0, or 100 (no such probe).
    #[no_mangle]
    pub extern "C" fn layout_free(handle: u32) -> i32 {
        crate::free(&LAYOUTS, handle)
    }

    /// Writes the probe's `k` unit sensor directions (x, y, z each) to the exchange buffer;
    /// 0, or an error code.
    #[no_mangle]
    pub extern "C" fn layout_directions(handle: u32) -> i32 {
        with_layout(handle, |l| each!(l, p => super::directions(p)))
    }

    /// Fits the `k` RGB readings (r, g, b each, in the order of the sensors) in the exchange
    /// buffer, forgetting earlier ones; 0, or an error code (7: a NaN or infinite reading;
    /// the probe keeps its state).
    #[no_mangle]
    pub extern "C" fn layout_update(handle: u32) -> i32 {
        with_layout(handle, |l| each!(l, p => super::take(p, false)))
    }

    /// Pools the `k` RGB readings in the exchange buffer with the earlier ones of a stream,
    /// forgetting them by the posterior probability of a change, and writes what it did to
    /// the first word (u32: 1 first, 2 blended, 3 reset); 0, or an error code (7: a NaN or
    /// infinite reading; the probe keeps its state).
    #[no_mangle]
    pub extern "C" fn layout_pool(handle: u32) -> i32 {
        with_layout(handle, |l| each!(l, p => super::take(p, true)))
    }

    /// Writes `[r, g, b, var_r, var_g, var_b]`, the irradiance about `(nx, ny, nz)` and its
    /// direction-averaged posterior variance, to the exchange buffer; 0, or an error code
    /// (1: a zero or non-finite normal).
    #[no_mangle]
    pub extern "C" fn layout_irradiance(handle: u32, nx: f32, ny: f32, nz: f32) -> i32 {
        let n = Vec3::new(nx, ny, nz);
        with_layout(
            handle,
            |l: &mut Layout| each!(l, p => p.irradiance(n).map(|e| store_estimate(e.value, e.variance))),
        )
    }

    /// Writes the exact posterior variance of the irradiance about `(nx, ny, nz)` (r, g, b)
    /// to the exchange buffer; 0, or an error code (1: a zero or non-finite normal).
    #[no_mangle]
    pub extern "C" fn layout_irradiance_variance(handle: u32, nx: f32, ny: f32, nz: f32) -> i32 {
        let n = Vec3::new(nx, ny, nz);
        with_layout(handle, |l| each!(l, p => p.irradiance_variance(n).map(store)))
    }

    /// Writes `[r, g, b, var_r, var_g, var_b]`, the normalised Phong average about
    /// `(ax, ay, az)` with exponent `e` and its exact posterior variance, to the exchange
    /// buffer; 0, or an error code (1: a bad axis; 2: a negative, non-finite or too large
    /// exponent).
    #[no_mangle]
    pub extern "C" fn layout_phong(handle: u32, ax: f32, ay: f32, az: f32, e: f32) -> i32 {
        let axis = Vec3::new(ax, ay, az);
        with_layout(
            handle,
            |l| each!(l, p => p.phong(axis, e).map(|e| store_estimate(e.value, e.variance))),
        )
    }

    /// Writes the 9 RGB spherical-harmonic coefficients of the posterior mean radiance
    /// (index `l(l + 1) + m`, r, g, b each) to the exchange buffer; 0, or an error code.
    #[no_mangle]
    pub extern "C" fn layout_radiance_sh(handle: u32) -> i32 {
        with_layout(handle, |l| {
            each!(l, p => store(p.radiance_sh().coefficients.into_iter().flatten()));
            Ok(())
        })
    }

    /// Writes the probe's state to the exchange buffer: `k` and whether it has had an update
    /// (u32), then the pooled updates, the last change probability and the signal variance
    /// r, g, b (f32); 0, or an error code.
    #[no_mangle]
    pub extern "C" fn layout_state(handle: u32) -> i32 {
        with_layout(handle, |l| each!(l, p => super::state(p)))
    }
}
