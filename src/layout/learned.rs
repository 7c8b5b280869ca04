//! The learned priors of [`super::Prior`]: `tables/sensor_priors.rs`, generated from the
//! bundled training maps by `cargo writer sensor_priors -- --write` (in f64, rounded once to
//! f32) and checked by CI against a fresh computation.

include!("../../tables/sensor_priors.rs");
