//! Table generators, shared by `build.rs` and the host tests (through `#[path]`).
//!
//! Plain std Rust with no dependencies: every firmware build of a user runs this code, so it
//! must compile fast and run fast even in the unoptimised build-script profile.

pub mod bmc;
pub mod glossy;
pub mod probe;
pub mod sg;
