//! Tables baked by `build.rs` (from `gen/` and `tables/`), included from `$OUT_DIR`.
//!
//! - `SG_HEMI`, `SG_CLAMPED`: the spherical-Gaussian hemispherical and clamped-cosine integral
//!   tables used by [`crate::sg`]; their layout is described in `gen/sg.rs`.
//! - `BMC_WEIGHTS_<N>`: the Bayesian Monte Carlo weights of [`crate::bmc`], one array per
//!   baked size, and the sealed `BakedSize` impls that admit exactly those sizes.

include!(concat!(env!("OUT_DIR"), "/sg_tables.rs"));

// `BMC_SIZES`, `BMC_WEIGHTS_<N>` and the `bmc::BakedSize` impls of the baked sizes (generator
// `gen/bmc.rs`, sets in `tables/bmc.txt`).
include!(concat!(env!("OUT_DIR"), "/bmc_tables.rs"));

// `PROBE_SIZES`, the probe families and the `probe::ProbeSize` impls of the baked sizes
// (generator `gen/probe.rs`, families in `tables/probe.txt`).
include!(concat!(env!("OUT_DIR"), "/probe_tables.rs"));

// `GLOSSY_SETS`, the glossy renderer's weights and the `bmc::GlossySize` impls (generator
// `gen/glossy.rs`, sets in `tables/glossy.txt`).
include!(concat!(env!("OUT_DIR"), "/glossy_tables.rs"));

// `FOOTPRINT_SETS`, the footprint renderer's tables and the `bmc::FootprintSize` impls
// (generator `gen/fp.rs`, sets in `tables/footprint_renderer.txt`).
include!(concat!(env!("OUT_DIR"), "/footprint_tables.rs"));
