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
//! - [`bmc`]: Bayesian Monte Carlo with build-time weights, the renderer forms: diffuse
//!   irradiance, and the Phong lobe with the cosine factor ([`bmc::GlossyRenderer`]).
//! - [`probe`]: a Bayesian Monte Carlo lighting probe: N samples in, irradiance with a
//!   posterior variance for any normal out, with per-probe kernel selection by marginal
//!   likelihood. On the held-out maps of `eval/src/bin/accuracy.rs` it has 0.81–0.92× the error of
//!   the cosine-weighted average at N = 16…64 (`clamp` tier; mean of per-map ratios, 0.75–0.86×
//!   as a ratio of mean errors) and 0.68–0.89× the best of that average and SH L2 (`smooth`
//!   tier). Samples may be points or have a known footprint
//!   (`Probe<N, T, F>`): a probe whose samples integrate a lobe (a mip level, a cone, a
//!   photodiode) models it exactly, for 40–200× lower irradiance error on real maps than the
//!   cosine-weighted average of point samples (held-out maps, N = 16…256). Missing
//!   samples (a cut ray budget, a silent sensor) take a validity mask
//!   ([`probe::Probe::update_masked`]): the valid ones are fitted exactly, up to a capacity
//!   `M` fixed in the type.
//! - [`temporal`]: a probe updated as a stream under fresh rotations, pooling the evidence of
//!   every sample and detecting changes of the lighting.
//! - [`layout`]: a probe on the hardware's own sensor directions, angular responses and noise,
//!   with its tables computed at run time (or in a `static`).
//! - [`sh`]: spherical harmonics up to degree 2 (`ShL2`): a probe's posterior mean as the 9
//!   coefficients renderers take ([`probe::Probe::radiance_sh`]), O(9) irradiance, rotation,
//!   and the conventions of three.js, Filament and Unity.
//! - [`footprint`]: what a sample measures (point, Gaussian lobe, cosine-power sensor) and
//!   the footprints' Funk–Hecke gains.
//! - [`envmap`]: footprint samples of an equirectangular RGB map, exact (every pixel) or
//!   from a mip pyramid, in caller-provided buffers.
//! - [`rotation`]: rotation matrices and a seeded rotation sequence.
//! - [`metrics`]: point-set quality (energy, worst-case error, discrepancy, separation,
//!   covering radius, spectra, design strength) and the circle view.
//! - [`sg`]: spherical Gaussians (product, integrals, rotation, Phong and cosine fits) and
//!   their hemispherical and clamped-cosine integrals from build-time tables.
//! - [`radiance`] and [`Vec3`]: the sample values (`f32` or RGB) and directions.
//! - [`fixed_point`] (feature `fixed`) and [`interop`] (feature `mint`).
//! - [`costs`]: instructions per call, flash and RAM on a Cortex-M4F.
//!
//! # Conventions
//! One vocabulary for every type:
//! - **Data in.** `update` replaces a probe's data ([`Probe::update`],
//!   [`LayoutProbe::update`]); `pool` pools it with the evidence of earlier calls, forgetting
//!   it where the light changed ([`TemporalProbe::pool`], [`LayoutProbe::pool`]), returns what
//!   it did ([`temporal::Change`]), and `pooled_updates` is the weight of the pooled evidence
//!   in updates.
//! - **Answers out.** Every query returns an [`Estimate`] (value, variance and, where the
//!   channels share one model, [`Estimate::unit_variance`]); `combine(&estimate, weights)`
//!   gives a channel combination (luminance) with its variance on every probe.
//! - **Directions.** A renderer's `fill_directions` and `estimate` take what its lobe
//!   depends on: the normal for irradiance ([`bmc::Renderer`], whose set turns about the
//!   normal by [`bmc::Renderer::with_phase`]; `FootprintRenderer<N, Diffuse>`), the normal and
//!   the mirror direction for a glossy lobe ([`bmc::GlossyRenderer`],
//!   `FootprintRenderer<N, Phong<E>>`).
//! - `directions()` returns a probe's stored sample directions by reference; `fill` and
//!   `fill_directions` write computed directions into a buffer of exactly the right length
//!   and return a `Result` ([`Error::LengthMismatch`] otherwise).
//! - A query `q` has its posterior variance in `q_variance` (`irradiance_variance`,
//!   `glossy_variance`, `phong_variance`, `radiance_sh_variance`), and `q` itself returns an
//!   [`Estimate`] with both. The fitted prior's scale is `signal_variance`,
//!   `signal_covariance` (of two channels) and `signal_variance_of` (of a combination).
//! - `TABLE_BYTES` on a type is the flash that using the type links
//!   ([`probe::Probe::TABLE_BYTES`]); on a module it is the sum over every size that module
//!   bakes ([`bmc::TABLE_BYTES`], [`sg::TABLE_BYTES`]). A module's `BAKED_SIZES` lists the
//!   sizes baked for that module's type.
//! - Generic code over sizes writes the bound on [`Size`]: `Size<N>: probe::ProbeTables<F>`
//!   for a probe, `Size<N>: bmc::BakedSize` for the renderer.
//! - Constructors that need no run-time work are `const fn`, so probes and point sets can
//!   live in a `static`. [`probe::RgbProbe`], [`temporal::RgbTemporalProbe`] and
//!   [`layout::RgbLayoutProbe`] name the RGB forms.
//! - Every refusal is an [`Error`] naming its cause (a direction, a rotation, a channel, a
//!   response, a noise level, …); nothing panics on data the caller passes.
//!
//! # Accuracy
//! Measured by the tests in `tests/` against the independent f64 reference crate:
//! - Point sets: every spherical Fibonacci point is within 1.4·10⁻⁷ rad of the exact point for
//!   all N ≤ 2²⁴, under both math backends (the azimuth's sine and cosine come from exact
//!   integer range reduction and f32 polynomials).
//! - QMC irradiance of a constant is π to 2 ulp; of a smooth spherical-Gaussian light the
//!   relative RMS error falls as N^−1.08 over N = 64…4096 (random points: N^−0.53), reaching
//!   1.8·10⁻⁴ at N = 4096, under both backends.
//! - On a real map (`apartment`, 64 normals × 16 draws), relative RMSE of irradiance (QMC-SF,
//!   Sobol-QMC, Monte Carlo):
//!   N = 64: 9.0 %, 10.7 %, 17.1 %;
//!   N = 256: 3.3 %, 4.0 %, 9.4 %
//!   (`cargo run --release --example qmc_compare` prints the full tables; CI checks these figures
//!   against its output).
//! - Spherical Gaussians: hemispherical and clamped-cosine integrals from 16 KiB of build-time
//!   tables to 1.1·10⁻⁵ and 4.8·10⁻⁶ absolute (normalised by the full-sphere integral), 460×
//!   and 270× better than the best published closed forms (see [`sg`]).
//!
//! # What is baked
//! Weights and factorisations are computed in f64 by the build script from `tables/` and
//! rounded once to f32; only the types below compile. A type that is not baked is a compile
//! error whose note lists what this build baked and the table line that bakes it.
//!
//! | type | baked in a default build | another size or parameter |
//! | --- | --- | --- |
//! | `Probe<N, T, Point>` | N = 16, 32, 64, 128, 256 | any even N: a `probe = N …` line of a user table (`SPHERE_QUADRATURE_PROBE_TABLE`, `tables/README.md`) |
//! | `Probe<N, T, Gaussian<S>>` | (N, S) = (16, 2), (32, 4), (64, 8), (128, 16), (256, 32) | a `footprint = N gaussian S …` line |
//! | `Probe<N, T, CosinePower<P>>` | (N, P) = (16, 1), (32, 1) | a `footprint = N cosine P …` line |
//! | `bmc::Renderer<N>`, `fixed_point::BmcFixed<N>` | N = 16, 32, 64, 80, 128, 256 | a user table (`SPHERE_QUADRATURE_BMC_TABLE`) |
//! | `bmc::GlossyRenderer<N, E>` | (N, E) = (16, 10), (16, 50), (32, 50), (64, 50), (80, 50), (128, 50), (64, 200) | a `glossy = N e` line (`SPHERE_QUADRATURE_GLOSSY_TABLE`) |
//! | `bmc::GlossyRenderer<N, E, Optimal>` | (N, E) = (16, 50), (64, 50), (64, 200) | an optimal set (`tables/optimal_sets.txt`) |
//! | `bmc::FootprintRenderer<N, B>` | `Diffuse`, `Phong<10>`, `Phong<50>`, `Phong<200>` at N = 16, 32, 64; at N = 128 with the feature `footprint-128` | a `set` line of `tables/footprint_renderer.txt` |
//! | `TemporalProbe<N, T, F, S>` | no tables: any N ≥ 1 and footprint | — |
//! | `LayoutProbe<K, T>` | no tables (computed by `new`, at run time or in a `const`): any K ≤ 64 | — |
//! | `qmc` estimators | no tables: any N ≥ 1 | — |
//!
//! # Directions
//! A *valid direction* is any finite nonzero vector: it need not be unit, and may be as long
//! as `f32::MAX` or as short as a subnormal number in every component. Every function that
//! takes a direction (normal, mirror or lobe axis, query, sample direction, metric point)
//! normalises it with [`Vec3::try_normalize`] (or the same rule in f64), which divides by the
//! largest component magnitude first where the squared length would overflow or underflow.
//! Exactly the zero vector and vectors with a NaN or infinite component are refused, with
//! [`Error::InvalidDirection`]; the function docs that say "a zero or non-finite direction"
//! mean this.
//!
//! # Rotations
//! A *valid rotation* is a [`Mat3`] whose entries are finite, orthonormal within
//! [`rotation::ROTATION_TOLERANCE`] (10⁻³ on each entry of `MᵀM − I`) and of determinant `+1`
//! ([`Mat3::validate_rotation`]). Where a rotation enters a point set or a probe
//! ([`FibonacciPoints::with_rotation`], [`SphericalFibonacci::with_rotation`],
//! [`probe::Probe::set_rotation`]) anything else is refused with [`Error::InvalidRotation`].
//! The crate's own rotations ([`RotationSequence`], [`Mat3::from_quaternion`], …) are valid.
//!
//! # The contract of every estimator
//! Every estimator — [`probe::Probe`], [`temporal::TemporalProbe`], [`layout::LayoutProbe`],
//! [`bmc::Renderer`], [`bmc::GlossyRenderer`], [`bmc::FootprintRenderer`] and the [`qmc`]
//! estimators — makes the same promises, and one test suite asks every type the same
//! questions (`tests/hardening/contract.rs`):
//! - **Bad input** is an [`Error`] naming its cause, never a panic: a NaN or infinite sample,
//!   lookup or reading is [`Error::InvalidRadiance`]; a zero, NaN or infinite direction
//!   [`Error::InvalidDirection`] (see [Directions](#directions)); a negative, NaN, infinite or
//!   too large Phong exponent [`Error::InvalidExponent`]; an SG sharpness likewise
//!   [`Error::InvalidSharpness`]; `N = 0` is a compile-time error for the const-generic types and
//!   [`Error::InvalidSize`] for run-time sizes. A refused update leaves the state exactly as it
//!   was, and a query never changes it.
//! - **Any units.** Finite input of any size is good input, subnormal numbers included. For
//!   input `c·Y` every value is `c` times that of `Y` and every variance `c²` times, to f32
//!   rounding (bit for bit when `c` is a power of two), and every decision (a kernel member, a
//!   reset) is the same. A result is `±∞` only where it exceeds `f32::MAX` itself, and never
//!   NaN.
//! - **Error bars** are never 0 unless the answer is exact (a constant light, exact data): a
//!   variance below the least positive f32 is rounded up to it, not to 0. The one exception
//!   is a probe without data: before its first update every query answers 0 with variance 0
//!   (`TemporalProbe::updates` and `LayoutProbe::is_updated` tell).
//! - **One vocabulary**: the same names for the same acts in every type ([Conventions](#conventions)).
//!
//! # Limits
//! The same in every type that takes the parameter:
//!
//! | parameter | accepted | otherwise |
//! | --- | --- | --- |
//! | Phong exponent `e` (queries) | `0 ≤ e ≤ 10⁸` ([`probe::MAX_GLOSSY_SHARPNESS`]) | [`Error::InvalidExponent`] |
//! | SG lobe sharpness (queries) | `0 ≤ μ ≤ 10⁸` | [`Error::InvalidSharpness`] |
//! | footprint `Gaussian<S>`, `CosinePower<P>` | `1 ≤ S, P ≤ 4096` ([`footprint::MAX_PARAMETER`]) | a compile error |
//! | channels of a radiance type | 1 to 4 ([`radiance::MAX_CHANNELS`]) | a compile error |
//! | sensors of a layout | `K ≤ 64` ([`layout::MAX_SENSORS`]) | [`Error::InvalidSize`] |
//!
//! # MSRV
//! Rust 1.84, with every feature. CI checks every target of the workspace and runs the
//! library's unit tests on 1.84 with the committed lockfile (`.cargo/config.toml` resolves
//! dependencies to versions that declare a compatible `rust-version`). The `fixed` feature uses fixed 1.29 (Rust 1.83).
//!
//! # Features
//! None is on by default; `libm` is always linked and is the default math backend.
//! - `micromath`: fast approximate `sin`, `cos`, `atan2` and `exp` instead of `libm`'s
//!   (everything else stays `libm`: `micromath`'s other functions are too coarse for
//!   quadrature); the final binary's choice, which a library should leave off.
//! - `fixed`: [`fixed_point`] weighted sums on the `fixed` crate's `U16F16` / `I16F16`.
//! - `mint`: [`interop`], `From`/`Into` between [`Vec3`]/[`Mat3`] and `mint` types (glam,
//!   nalgebra, cgmath).
//! - `defmt`: `defmt::Format` on the public data types.
//! - `footprint-128`: [`bmc::FootprintRenderer`]'s N = 128 sets (32–85 KB of flash each when
//!   used).
//!
//! Two further features, `footprint-sweep` and `renderer-sweep`, bake extra tables for the
//! repository's evaluation programs; they add nothing a user calls.
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]
#![cfg_attr(docsrs, feature(doc_cfg))]
// CI's nightly docs build lists the public items without a rustdoc example
// (`--cfg sq_doc_examples`): every type and module must have one.
#![cfg_attr(sq_doc_examples, feature(rustdoc_missing_doc_code_examples))]
#![cfg_attr(sq_doc_examples, warn(rustdoc::missing_doc_code_examples))]

// `unbaked_size_diagnostic!`: the compile error of an unbaked renderer or fixed-point size,
// listing the sizes this build baked (generator `gen/bmc.rs`, `render_size_diagnostics`).
include!(concat!(env!("OUT_DIR"), "/bmc_size_diagnostics.rs"));

// The baked tables, and the macros of their compile errors (textual scope: before `bmc`).
#[macro_use]
mod tables;
pub mod bmc;
mod change;
pub mod costs;
pub mod envmap;
mod error;
mod estimate;
#[cfg(feature = "fixed")]
#[cfg_attr(docsrs, doc(cfg(feature = "fixed")))]
pub mod fixed_point;
pub mod footprint;
mod harmonics;
#[cfg(feature = "mint")]
#[cfg_attr(docsrs, doc(cfg(feature = "mint")))]
pub mod interop;
pub mod layout;
mod legendre;
#[doc(hidden)]
pub mod math;
pub mod metrics;
mod noise;
pub mod probe;
pub mod qmc;
pub mod radiance;
pub mod rotation;
pub mod sf;
pub mod sg;
pub mod sh;
mod size;
pub mod temporal;
mod vec3;
pub mod warp;

/// The README's code blocks, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

pub use error::Error;
pub use estimate::Estimate;
pub use layout::LayoutProbe;
pub use probe::Probe;
pub use radiance::Radiance;
pub use rotation::{Mat3, RotationSequence};
pub use sf::{FibonacciLattice, FibonacciPoints, HemisphericalFibonacci, SphericalFibonacci};
pub use size::Size;
pub use temporal::TemporalProbe;
pub use vec3::Vec3;
pub use warp::{Frame, Lobe};
