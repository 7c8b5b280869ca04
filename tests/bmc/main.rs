//! Bayesian Monte Carlo renderers and the baked tables, against the table generator (`gen/`,
//! compiled once here for every module) and the independent reference crate: the renderer
//! (`bmc`), its glossy form (`glossy`), the fixed-point weighted sums (`fixed_point`, feature
//! `fixed`), the spherical Gaussians (`sg`) and their baked tables (`sg_tables`), and the
//! prebaked store `baked/` (`baked`).
//!
//! One test binary, one module per concept: `cargo test --test bmc glossy::` runs one module.

#[path = "../shared/footprint_lookups.rs"]
mod footprint_lookups;
use sphere_quadrature_gen as gen;

// Before the modules that use its macros (textual scope).
#[macro_use]
mod common;

mod baked;
mod bmc;
mod fixed_point;
mod footprint;
mod glossy;
mod sg;
mod sg_tables;
