//! The probes against independent f64 references: the probe form of Bayesian Monte Carlo
//! (`probe`), footprint probes (`footprint`), missing samples (`missing`), radiance scale and
//! channel covariance (`scale`), property tests (`properties`), spherical harmonics and the
//! probe's SH export (`sh`), and the temporal probe (`temporal`).
//!
//! One test binary, one module per concept: `cargo test --test probe missing::` runs one
//! module.

#[allow(dead_code)] // build.rs uses the rest
#[path = "../../gen/mod.rs"]
mod gen;

mod calibration;

mod footprint;
mod missing;
mod probe;
mod properties;
mod scale;
mod sh;
mod temporal;
