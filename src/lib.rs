//! Spherical quadrature for illumination integrals on lighting probes: spherical Fibonacci
//! point sets and quasi-Monte Carlo estimators, `#![no_std]` and allocation-free.
//!
//! The method follows Marques, Bouville and Bouatouch, "Bayesian and Quasi Monte Carlo
//! Spherical Integration for Illumination Integrals" (2014).
//!
//! ```
//! use sphere_quadrature::{qmc, Vec3};
//!
//! // A sky that is brighter towards +z.
//! let sky = |d: Vec3| 1.0 + 0.5 * d.z;
//! // Irradiance on an upward normal from 64 spherical Fibonacci samples.
//! let e = qmc::irradiance::<64, f32, _>(Vec3::Z, 0, sky).unwrap();
//! // Exact: π·1 + (2π/3)·0.5.
//! let exact = core::f32::consts::PI * (1.0 + 0.5 * 2.0 / 3.0);
//! assert!((e - exact).abs() / exact < 1e-3);
//! ```
//!
//! # Modules
//! - [`sf`]: spherical Fibonacci point sets on the sphere and the hemisphere, const-generic in
//!   `N`, with exact integer phase, rotations, and the inverse mapping.
//! - [`warp`]: orthonormal frames and the lobe morphs (cosine, Phong).
//! - [`qmc`]: QMC estimators of irradiance and normalised Phong glossy radiance.
//! - [`rotation`]: rotation matrices and a seeded rotation sequence.
//! - [`math`]: the f32 math backend (`libm` or `micromath`).
//!
//! # Feature flags
//! - `libm` (default): accurate f32 math.
//! - `micromath`: fast approximate f32 math; wins over `libm` when both are on. The final
//!   binary's decision (see [`math`]).
//! - `defmt`: `defmt::Format` on the public data types.
//!
//! # Bad input
//! No function panics on data the caller passes. Zero, NaN or infinite directions give
//! [`Error::InvalidDirection`]; negative, NaN or infinite Phong exponents give
//! [`Error::InvalidExponent`]; `N = 0` is a compile-time error for the const-generic sets and
//! [`Error::InvalidSize`] for run-time sizes; NaN radiance propagates to a NaN estimate.
//!
//! # MSRV
//! Rust 1.84 (declared; CI builds with the current stable toolchain only).
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]

mod error;
pub mod math;
pub mod qmc;
pub mod radiance;
pub mod rotation;
pub mod sf;
mod vec3;
pub mod warp;

pub use error::Error;
pub use radiance::Radiance;
pub use rotation::{Mat3, RotationSequence};
pub use sf::{FibonacciLattice, FibonacciPoints, HemisphericalFibonacci, SphericalFibonacci};
pub use vec3::Vec3;
pub use warp::{Frame, Lobe};
