//! The WebAssembly modules of the `sphere-quadrature` npm package (`examples/wasm/package`),
//! behind a handful of plain `extern "C"` exports that the package's `index.js` wraps in its
//! classes. Nothing else: no test or scenario exports, no imports. One build is one module:
//! - with a size feature (`n16`, `n32`, `n64`, `n128` or `n256`), `probe-N.wasm`: RGB
//!   Bayesian Monte Carlo probes `Probe<N, [f32; 3]>` of that baked size and RGB temporal
//!   probes of the same ray budget ([`probes`]);
//! - with the feature `layout` (alone), `layout.wasm`: RGB layout probes
//!   `LayoutProbe<K, [f32; 3]>` over a user's sensors for a fixed set of sensor counts `K`
//!   ([`layout`]).
//!
//! State without `unsafe`: the probes live in `std::sync::Mutex<Vec<…>>`s (on
//! `wasm32-unknown-unknown` without threads std's lock is a plain flag and its allocator
//! grows the memory with `memory.grow`, an instruction, not an import), addressed by
//! integer handles. Arrays cross the boundary through one static buffer of atomics, `IO`,
//! whose address `io_ptr` exports: JavaScript writes samples there before
//! `probe_update` and reads results from there after a query (atomics give the interior
//! mutability without `unsafe`; without the `atomics` target feature they are plain loads
//! and stores).
//!
//! Every export returns 0 or a positive error code ([`code`]); `probe_new`, `temporal_new`
//! and `layout_new` return a handle (≥ 0) or a negated code.
//!
//! ```text
//! cd examples/wasm/package-wasm
//! cargo build --release --target wasm32-unknown-unknown --features n64
//! cargo build --release --target wasm32-unknown-unknown --features layout
//! ```
// `#[no_mangle]` is the only construct the `unsafe_code` lint flags here (exports need their
// symbol names); it is allowed on the `exports` module only. No `unsafe` blocks.
#![deny(unsafe_code)]

use std::boxed::Box;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};
use std::sync::Mutex;
use std::vec::Vec;

use sphere_quadrature::Error;

#[cfg(not(any(
    feature = "n16",
    feature = "n32",
    feature = "n64",
    feature = "n128",
    feature = "n256",
    feature = "layout"
)))]
compile_error!("enable one size feature (n16, n32, n64, n128 or n256) or layout");

#[cfg(all(
    feature = "layout",
    any(feature = "n16", feature = "n32", feature = "n64", feature = "n128", feature = "n256")
))]
compile_error!("the layout module is built alone: no size feature with `layout`");

#[cfg(not(feature = "layout"))]
pub mod probes;

#[cfg(feature = "layout")]
pub mod layout;

/// Floats of the [`IO`] buffer.
#[cfg(not(feature = "layout"))]
const IO_LEN: usize = probes::IO_LEN;
/// Floats of the [`IO`] buffer.
#[cfg(feature = "layout")]
const IO_LEN: usize = layout::IO_LEN;

/// The exchange buffer (f32 bits), at `io_ptr()`.
static IO: [AtomicU32; IO_LEN] = [const { AtomicU32::new(0) }; IO_LEN];

/// Error code of a handle that names no live probe (never created, or freed).
const INVALID_HANDLE: i32 = 100;
/// Error code of anything else (an `Error` variant added later; a poisoned lock).
const OTHER: i32 = 255;

/// The error code of `e` (one per variant; `index.js` maps them back to names).
fn code(e: Error) -> i32 {
    match e {
        Error::InvalidDirection => 1,
        Error::InvalidExponent => 2,
        Error::LengthMismatch => 3,
        Error::InvalidSize => 4,
        // The JavaScript package names one error for every argument out of range.
        e if e.is_out_of_range() => 5,
        Error::InvalidSharpness => 6,
        Error::InvalidRadiance => 7,
        Error::TooManyMissing => 8,
        _ => OTHER,
    }
}

/// Writes `values` to the start of [`IO`].
fn store(values: impl IntoIterator<Item = f32>) {
    for (v, a) in values.into_iter().zip(&IO) {
        a.store(v.to_bits(), Relaxed);
    }
}

/// Stores `p` in the first free slot of `all`; its handle, or a negated error code.
fn insert<P>(all: &Mutex<Vec<Option<Box<P>>>>, p: Box<P>) -> i32 {
    let Ok(mut probes) = all.lock() else { return -OTHER };
    let slot = match probes.iter().position(Option::is_none) {
        Some(i) => i,
        None => {
            probes.push(None);
            probes.len() - 1
        }
    };
    let Ok(handle) = i32::try_from(slot) else { return -OTHER };
    if let Some(s) = probes.get_mut(slot) {
        *s = Some(p);
    }
    handle
}

/// Frees the probe `handle` of `all`; 0, or [`INVALID_HANDLE`].
fn free<P>(all: &Mutex<Vec<Option<Box<P>>>>, handle: u32) -> i32 {
    let Ok(mut probes) = all.lock() else { return OTHER };
    match probes.get_mut(handle as usize) {
        Some(slot @ Some(_)) => {
            *slot = None;
            0
        }
        _ => INVALID_HANDLE,
    }
}

/// `[r, g, b, var_r, var_g, var_b]` into [`IO`].
fn store_estimate([r, g, b]: [f32; 3], [vr, vg, vb]: [f32; 3]) {
    store([r, g, b, vr, vg, vb]);
}

/// Stores `u32` values (as their bits) to the start of [`IO`].
fn store_bits(values: impl IntoIterator<Item = u32>) {
    for (v, a) in values.into_iter().zip(&IO) {
        a.store(v, Relaxed);
    }
}
