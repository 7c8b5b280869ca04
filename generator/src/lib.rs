//! The table generators of `sphere-quadrature` (`gen/`): the one crate that the tests and the
//! evaluation programs use. The crate's build script includes the same files by `#[path]`:
//! a published build script cannot depend on an unpublished crate, and `gen/` must ship in the
//! crate's tarball (a `Cargo.toml` inside it would exclude it from the package).

// The build script uses parts that no test or program calls.
#[allow(dead_code)]
#[path = "../../gen/mod.rs"]
mod generators;

pub use generators::*;
