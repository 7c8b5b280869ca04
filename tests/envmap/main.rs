//! Environment maps: QMC-SF against the estimators a user would pick instead on a real map
//! (`envmap`), and the footprint samples of equirectangular maps (`envmap_sampling`).
//!
//! One test binary, one module per concept: `cargo test --test envmap envmap_sampling::` runs
//! one module.

mod envmap;
mod envmap_sampling;
