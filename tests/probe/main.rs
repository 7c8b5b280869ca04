//! The probe form of Bayesian Monte Carlo against independent f64 references: point probes
//! (`probe`), footprint probes (`footprint`) and missing samples (`missing`).
//!
//! One test binary, one module per concept: `cargo test --test probe missing::` runs one
//! module.

use sphere_quadrature_gen as gen;

mod calibration;

mod footprint;
mod missing;
mod probe;
