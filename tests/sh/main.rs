//! Spherical harmonics against independent f64 computations: the SH L2 type and the probes'
//! SH export (`sh`), and the temporal probe, which pools its samples' SH projections
//! (`temporal`).
//!
//! One test binary, one module per concept: `cargo test --test sh temporal::` runs one module.

mod sh;
mod temporal;
