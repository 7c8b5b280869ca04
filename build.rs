//! Build script. The tables that issues #4 (hemispherical spherical-Gaussian integrals) and
//! #6 (Bayesian Monte Carlo weights) bake will be generated here, in f64, from the generator
//! in `gen/` and the sizes and hyperparameters listed in `tables/`. Nothing is baked yet: the
//! point sets and QMC estimators need no tables (their constants are exact integers computed
//! by `const fn`). Only the rerun directives are emitted, so that the script never reruns
//! needlessly.

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-changed=tables");
}
