//! Robustness: the regression tests of the adversarial pass's defects (`hardening`), property
//! tests of the probe's invariances (`properties`), and radiance at any scale with the
//! channel covariance (`scale`).
//!
//! One test binary, one module per concept: `cargo test --test hardening properties::` runs one
//! module.

#[path = "../shared/footprint_lookups.rs"]
mod footprint_lookups;
use sphere_quadrature_gen as gen;

mod contract;
mod hardening;
mod properties;
mod scale;
