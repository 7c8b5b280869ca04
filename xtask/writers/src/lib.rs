//! The stages of the writers (`src/bin/*.rs`) that are more than a `main`: the optimal-set
//! search, [`optimal_sets`] (its constants, options and a module per stage), and the renderer's
//! hyperparameter fits, [`renderer_hyperparameters`], so that their files in `src/bin/` keep
//! only their documentation, command line and `main`. What the writers share with the
//! benchmarks (command line, maps, tiers, the f64 renderer engine and the renderer benchmark's
//! sample sets and scenes, the optimal-set loader) is the evaluation crate's library,
//! `sphere_quadrature_eval`.

pub mod optimal_sets;
pub mod renderer_hyperparameters;
