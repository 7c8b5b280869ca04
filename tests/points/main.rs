//! Point sets and what is built on them, against the independent f64 reference crate: the
//! spherical Fibonacci sets (`sf`) and their inverse mapping (`inverse`), the QMC estimators
//! (`qmc`), the point-set quality metrics (`metrics`), and the math kernels beneath them
//! (`math`).
//!
//! One test binary, one module per concept: `cargo test --test points sf::` runs one module.

mod inverse;
mod math;
mod metrics;
mod qmc;
mod sf;
