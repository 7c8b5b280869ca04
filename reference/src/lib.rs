//! Independent f64 ground truth for testing `sphere-quadrature`.
//!
//! Everything here is written from the mathematics, in plain std f64, and shares no code
//! with the crate under test:
//!
//! * [`rng`]: seeded SplitMix64 generator and sphere / hemisphere / cosine / rotation
//!   samplers;
//! * [`vec`](mod@vec): small 3-vector helpers;
//! * [`sf`]: spherical Fibonacci sphere, hemisphere and lattice points with a
//!   double-double golden phase, and exact nearest-point search;
//! * [`envmap`]: equirectangular environment maps (Radiance `.hdr` loading) and their
//!   nearest-pixel radiance function;
//! * [`truth`]: accurate irradiance and Phong integrals of environment maps and of smooth
//!   functions;
//! * [`analytic`]: lights with closed-form (or 1-D quadrature) integrals;
//! * [`fit`]: the least-squares log-log slope used for convergence rates;
//! * [`peers`]: the Monte Carlo and Sobol-QMC estimators this crate is compared with;
//! * [`quad`]: Gauss–Legendre, Gauss–Jacobi and adaptive Gauss–Kronrod quadrature;
//! * [`special`]: the modified Bessel function I₀ (exponentially scaled);
//! * [`sg_reference`]: hemispherical and clamped-cosine integrals of a spherical Gaussian by
//!   adaptive quadrature;
//! * [`sg_closed_forms`]: the published closed-form approximations of those integrals.
//!
//! Conventions: directions are `[f64; 3]`, z is the pole (up) axis; θ is the polar angle
//! from +z and φ the azimuth from +x towards +y.
//!
//! ```
//! use reference::analytic::Cap;
//! use reference::{truth, EnvMap};
//! use std::f64::consts::PI;
//!
//! // The top 16 rows of a 64×32 map are exactly the polar cap θ ≤ π/2.
//! let mut map = EnvMap::constant(64, 32, [0.0; 3]);
//! map.pixels[..64 * 16].fill([1.0; 3]);
//! let cap = Cap { axis: [0.0, 0.0, 1.0], cos_alpha: 0.0 };
//! let n = [0.6, 0.0, 0.8];
//! assert!((truth::irradiance(&map, n)[0] - cap.irradiance(n)).abs() < 1e-13);
//! assert!((cap.irradiance(n) - PI / 2.0 * (1.0 + 0.8)).abs() < 1e-15);
//! ```

#![forbid(unsafe_code)]
#![deny(missing_docs)]

pub mod analytic;
pub mod bmc;
pub mod discrepancy;
pub mod envmap;
pub mod fit;
pub mod footprint;
pub mod peers;
pub mod pointsets;
pub mod quad;
pub mod rng;
pub mod sf;
pub mod sg_closed_forms;
pub mod sg_reference;
pub mod sh;
pub mod special;
pub mod truth;
pub mod vec;

pub use envmap::{luminance, EnvMap};
pub use rng::Rng;
pub use sf::Nearest;
