//! Tables baked by `build.rs` (from `gen/` and `tables/`), included from `$OUT_DIR`.
//!
//! - `SG_HEMI`, `SG_CLAMPED`: the spherical-Gaussian hemispherical and clamped-cosine integral
//!   tables used by [`crate::sg`]; their layout is described in `gen/sg.rs`.

include!(concat!(env!("OUT_DIR"), "/sg_tables.rs"));
