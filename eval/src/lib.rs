//! The shared code of the evaluation programs (`src/bin/*.rs`), compiled once for all of them:
//! the command-line pieces, lighting tiers, parallel map, report helpers, the luminance error
//! bar, the f64 renderer engine and the optimal-set loader (files in `src/common/`), and the
//! files the programs share with the rest of the repository, each included here once: the
//! comparison estimators of the examples (`compare`), the build script's table generator
//! (`gen`), and the Cortex-M4 scenario and WebAssembly API that the host twins run natively
//! (`scenario`, `api`). Each program takes what it needs:
//! `use sphere_quadrature_eval::{cli, tiers};`.
//!
//! The library also holds the stages of the largest program, [`renderer`] (its constants,
//! options and a module per stage), so that its file in `src/bin/` keeps only its
//! documentation, command line and `main`, and the probe-trust engine, [`probe_trust`]. The
//! writers of `xtask/writers/` (the programs that write library inputs) use this library too.

/// The files of `src/common/`, re-exported at the crate root (they keep that folder, which the
/// reports and tables cite).
mod common {
    pub mod blends;
    pub mod cli;
    pub mod luminance_bar;
    pub mod optimal;
    pub mod parallel;
    pub mod renderer_engine;
    pub mod report;
    pub mod tiers;
}

pub use common::{blends, cli, luminance_bar, optimal, parallel, renderer_engine, report, tiers};

#[path = "../../examples/common/compare.rs"]
pub mod compare;

/// The table generators of `gen/` (the `sphere-quadrature-gen` crate).
pub use sphere_quadrature_gen as gen;

/// The Cortex-M4 scenario (`examples/cortex-m4/src/scenario.rs`); at the crate root, where
/// `api` finds it as `crate::scenario`.
#[path = "../../examples/cortex-m4/src/scenario.rs"]
pub mod scenario;

#[path = "../../examples/wasm/src/api.rs"]
pub mod api;

/// The footprint renderer's model (the generator's prototype).
pub mod fp;

// The stages of `src/bin/renderer.rs`.
pub mod renderer;

/// The engine and report of `src/bin/probe_trust.rs`, which `cargo writer probe_calibration`
/// shares.
pub mod probe_trust;

/// The sensor layouts, the crate's fit and the learned priors of `src/bin/sensors.rs`, which
/// `cargo writer sensor_priors` shares.
pub mod sensors;
