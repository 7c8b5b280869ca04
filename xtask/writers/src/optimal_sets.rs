//! The parts of the optimal-set program (`src/bin/optimal_sets.rs`, whose module docs
//! describe the model, objective and optimiser): its constants and options, and a module per
//! stage.

use std::path::PathBuf;

pub mod check;
pub mod hyperparameters;
pub mod objective;
pub mod optimiser;
pub mod output;
pub mod self_test;

/// The baked sizes.
pub const NS: [usize; 5] = [16, 32, 64, 80, 128];
/// The baked keys.
pub const KEYS: [&str; 9] = [
    "diffuse", "phong1", "phong5", "phong10", "phong20", "phong50", "phong100", "phong200",
    "phong500",
];
/// Gauss–Legendre nodes in `t = cos θₙ` of the Phong objective.
pub const THETA_NODES: usize = 5;
/// Seed of the jittered restarts (mixed with the key and N).
pub const SEED: u64 = 0x12E0_0004;
/// Kernel terms below e⁻⁴⁰ are skipped (as the engine does).
pub const CUT: f64 = 40.0;
/// Node density of the optimiser's rule (the engine's is 1): its objective agrees with the
/// reported one to about 10⁻⁸ (`--self-test`), at about half the cost.
pub const OPT_DENSITY: f64 = 0.75;
/// Armijo constant and memory of the non-monotone reference.
pub const ARMIJO: f64 = 1e-4;
pub const MEMORY: usize = 8;
/// A start stops when its best value improved by less than `STALL_TOL` (relative) over the
/// last `STALL` iterations.
pub const STALL: usize = 20;
pub const STALL_TOL: f64 = 3e-5;
/// Largest move of a direction in one step (radians).
pub const MAX_MOVE: f64 = 0.25;
/// Step (radians) of the finite differences of `--self-test`.
pub const FD_STEP: f64 = 2e-4;
/// Relative tolerance of `--check`.
pub const CHECK_TOL: f64 = 1e-9;
/// Largest `| |x| − 1 |` of a stored direction.
pub const UNIT_TOL: f64 = 1e-6;

pub const HYPER_FILE: &str = "tables/renderer_hyperparameters.txt";
pub const TABLE_FILE: &str = "tables/optimal_sets.txt";

/// The program's options, as `src/bin/optimal_sets.rs` parses them from its command line.
#[derive(Clone, Debug)]
pub struct Options {
    pub table: Option<PathBuf>,
    pub hyper_file: PathBuf,
    pub out: Option<PathBuf>,
    pub only: Vec<String>,
    pub ns: Vec<usize>,
    pub iterations: usize,
    pub restarts: usize,
    pub threads: usize,
    pub check: Option<PathBuf>,
    pub self_test: bool,
    pub args: Vec<String>,
}
