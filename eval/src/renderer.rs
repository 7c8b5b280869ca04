//! The parts of the renderer benchmark (`src/bin/renderer.rs`, whose module docs describe
//! it): its constants and options, and a module per stage.

use std::path::PathBuf;

use crate::renderer_engine::Brdf;

pub mod evaluation;
pub mod footprint;
pub mod hyperparameters;
pub mod plans;
pub mod report;
pub mod scenes;
pub mod self_test;

pub const NS: [usize; 5] = [16, 32, 64, 80, 128];
pub const BRDFS: [Brdf; 4] =
    [Brdf::Diffuse, Brdf::Phong(10.0), Brdf::Phong(50.0), Brdf::Phong(200.0)];
pub const TIERS: [&str; 4] = ["raw", "clamp", "smooth", "synthetic"];
pub const CLAMP: usize = 1;
pub const SMOOTH: usize = 2;
pub const SYNTHETIC: usize = 3;
pub const ESTIMATORS: [&str; E] = [
    "mc",
    "qmc-sobol",
    "qmc-sf",
    "qmc-fis",
    "bmc-sf",
    "bmc-sf-f64",
    "bmc-sobol",
    "bmc-sf-sel",
    "bmc-opt",
    "bmc-fp",
    "bmc-fp-pyramid",
    "split-sum",
];
/// Number of estimators.
pub const E: usize = 12;
pub const MC: usize = 0;
pub const SOBOL: usize = 1;
pub const SF: usize = 2;
pub const FIS: usize = 3;
pub const BMC_SF: usize = 4;
pub const BMC_F64: usize = 5;
pub const BMC_SOBOL: usize = 6;
pub const BMC_SF_SEL: usize = 7;
pub const BMC_OPT: usize = 8;
/// The crate's footprint renderer with exact lookups (on the first `exact_queries` queries).
pub const BMC_FP: usize = 9;
/// The crate's footprint renderer with `MipPyramid` lookups.
pub const BMC_FP_PYRAMID: usize = 10;
pub const SPLIT_SUM: usize = 11;
/// The family of `bmc-sf-sel` (per-query REML selection): σ′ ∈ `SEL_SIGMAS` × l ∈ the learned
/// l times `SEL_L_FACTORS`.
pub const SEL_SIGMAS: [f64; 6] = [1e-4, 1e-3, 1e-2, 0.1, 0.3, 1.0];
pub const SEL_L_FACTORS: [f64; 4] = [0.5, 1.0, 2.0, 4.0];
/// Family size.
pub const SEL: usize = SEL_SIGMAS.len() * SEL_L_FACTORS.len();

pub const SEED_QUERIES: u64 = 0x12E0_0001;
pub const SEED_MC: u64 = 0x12E0_0002;
pub const SEED_PHASE: u64 = 0x12E0_0003;
pub const SEED_SOBOL: u32 = 0x12E0_0004;
/// The synthetic mixtures of `eval/src/bin/accuracy.rs`.
pub const SEED_SYNTHETIC: u64 = 0xE7A1_0002;

/// Křivánek and Colbert's level bias (`lod = ½·log₂(Ω_s/Ω_p) + 1`).
pub const FIS_BIAS: f64 = 1.0;
/// Absolute per-pixel tolerance of the Phong × cosine truth weights (`∫p ≤ 1`).
pub const TRUTH_TOL: f64 = 4e-9;
/// Largest sharpness of the synthetic mixtures' lobes (`tiers::mixtures`).
pub const MIXTURE_SHARPNESS: f64 = 20.0;

pub const HYPER_FILE: &str = "tables/renderer_hyperparameters.txt";
/// The optimal sets of `bmc-opt` (`xtask/writers/src/bin/optimal_sets.rs`).
pub const OPTIMAL_FILE: &str = "tables/optimal_sets.txt";
/// Hyperparameter keys: the BMC-SF sample set each was learned on.
pub const KEYS: [(&str, Brdf, f64); 10] = [
    ("diffuse", Brdf::Diffuse, 0.0),
    ("diffuse-cos", Brdf::Diffuse, 1.0),
    ("phong1", Brdf::Phong(1.0), 1.0),
    ("phong5", Brdf::Phong(5.0), 5.0),
    ("phong10", Brdf::Phong(10.0), 10.0),
    ("phong20", Brdf::Phong(20.0), 20.0),
    ("phong50", Brdf::Phong(50.0), 50.0),
    ("phong100", Brdf::Phong(100.0), 100.0),
    ("phong200", Brdf::Phong(200.0), 200.0),
    ("phong500", Brdf::Phong(500.0), 500.0),
];
/// The error-minimising fit (`err` rows): l = 0.08·√2^k, k = 0…ERR_L − 1 (0.08 … 2.56), ×
/// σ′ ∈ `ERR_SIGMAS` (large σ′ turns the `-r` estimator into QMC).
pub const ERR_L: usize = 11;
pub const ERR_SIGMAS: [f64; 14] =
    [1e-4, 1e-3, 1e-2, 0.03, 0.1, 0.2, 0.3, 0.5, 1.0, 1.5, 2.0, 4.0, 8.0, 16.0];
/// Learning grid: l = 0.01·2^(k/2), k = 0…17 (0.01 … 2.56).
const L_STEPS: usize = 17;
pub const SIGMAS: [f64; 11] = [1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.2, 0.5, 1.0, 2.0];

pub fn l_grid() -> Vec<f64> {
    (0..L_STEPS).map(|k| 0.01 * 2f64.powf(k as f64 / 2.0)).collect()
}

/// `x` to 4 decimals without trailing zeros (the hyperparameter file's and the report's `l`).
pub fn fmt_g(x: f64) -> String {
    format!("{:.4}", x).trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The program's options, as `src/bin/renderer.rs` parses them from its command line.
#[derive(Clone, Debug)]
pub struct Options {
    pub out: PathBuf,
    pub csv: Option<PathBuf>,
    pub self_test: bool,
    pub hyper_file: PathBuf,
    pub hyper_method: String,
    pub threads: usize,
    pub queries: usize,
    pub mixtures: usize,
    pub sobol_queries: usize,
    /// Queries per map of `bmc-fp-pyramid` (the first ones).
    pub footprint_queries: usize,
    /// Queries per map of `bmc-fp` (exact lookups; the first ones).
    pub exact_queries: usize,
    pub paths: Vec<PathBuf>,
    pub args: Vec<String>,
}
