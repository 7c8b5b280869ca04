//! Status: complete for issue #12 item 6: every estimator (`bmc-opt` once
//! `tables/optimal_sets.txt` exists), the four tiers, `--learn` (REML, the seed's covariance
//! fit and the error-minimising fit), `--csv`, `--quick`, `--self-test`, report and plot.
//! `bmc-sf` is the crate's own renderers; `bmc-sf-f64` the same model on the host engine.
//!
//! The renderer benchmark of issue #12 (item 6): per-query shading integrals on environment
//! maps, every estimator at N ∈ {16, 32, 64, 80, 128}, against ground truth over every pixel.
//!
//! ```text
//! R="cargo eval renderer --"
//! $R                           # ten bundled maps, target/renderer
//! $R --out docs                # docs/renderer.md + .png
//! $R --quick                   # CI smoke run (seconds)
//! $R --learn                   # target/renderer/renderer_hyperparameters.txt
//! $R --learn --write           # tables/renderer_hyperparameters.txt
//! $R --self-test               # engine convergence checks
//! $R a.hdr b.hdr --csv rows.csv
//! ```
//!
//! # Integrals and queries
//! 256 seeded queries `(n, r)` per map (the same for every map): `n` uniform on the sphere,
//! `r = 2(n·v)n − v` for `v` cosine-distributed about `n`. BRDFs: `diffuse`
//! (`I = ∫ L·max(0, n·x) dx`) and `phong10`, `phong50`, `phong200`
//! (`I = ∫ L·(e+1)/(2π)·max(0, r·x)ᵉ·max(0, n·x) dx`). Luminance; relative RMSE of a map =
//! RMSE over the queries / mean |truth|.
//!
//! # Estimators (one draw per query; seeds depend on the query and N, not on the map)
//! - `mc`: independent directions from the lobe `(e+1)/(2π)·cosᵉ` about `r` (cosine about `n`
//!   for diffuse), `I ≈ (1/N)·Σ L·max(0, n·x)` (`π/N·Σ L` for diffuse);
//! - `qmc-sobol`: the same with Owen-scrambled Sobol points (`sobol_burley`, a scramble per
//!   query);
//! - `qmc-sf`: the crate's `LobeSampler` (hemisphere SF set morphed onto the lobe, f32), a
//!   random phase per query;
//! - `qmc-fis`: `qmc-sf` with filtered importance sampling (Křivánek and Colbert 2008): sample
//!   `x` reads the luminance pyramid at `lod = max(0, ½·log₂(Ω_s/Ω_p) + 1)`,
//!   `Ω_s = 1/(N·pdf(x))`, `Ω_p` the map pixel's solid angle there, trilinearly (levels ≥ 2
//!   from the crate's `MipPyramid::texel`); on the synthetic tier the mixture convolved with
//!   the normalised SG of sharpness `1/Ω_s` (the same variance as a bilinear read of a texel
//!   of `4Ω_s`; exact SG convolution);
//! - `bmc-sf`: the crate's renderers with their baked f32 weights and their own f32
//!   directions: `bmc::Renderer<N>` for diffuse (the cosine-morphed hemisphere SF set about
//!   `n`, a random phase per query), `bmc::GlossyRenderer<N, e>` for Phong (the set morphed
//!   onto the lobe, fixed in the frame `(r, t₁ ∝ n − (n·r)r)`, weights interpolated in θₙ);
//! - `bmc-sf-f64`: the same sets and model in f64 (`common/renderer_engine.rs`) with `z`
//!   computed exactly per query (no θₙ grid, no SG fit of the lobe): the difference to `bmc-sf`
//!   is the crate's grid, fit and f32 error (reported). The model reads the nugget σ′ as a rough
//!   part of the radiance that the set's own QMC weights integrate ([`rough_z`]), so that as
//!   σ′ grows the weights tend to QMC's;
//! - `bmc-sobol`: f64 BMC (same model) on the query's scrambled Sobol set (the `qmc-sobol`
//!   samples), one N×N solve per query (`--sobol-queries Q` restricts it to the first Q
//!   queries; the default runs it on all of them);
//! - `bmc-sf-sel`: `bmc-sf-f64` with (l, σ′) chosen per query by maximum REML likelihood of the
//!   query's own N samples among l = learned l × {0.5, 1, 2, 4} and σ′ ∈ {10⁻⁴, 10⁻³, 10⁻²,
//!   0.1, 0.3, 1} (what `Probe::update` does with its family): `Q`, its factor and `z` do not
//!   depend on the map, so the selection costs O(N²) per member and query;
//! - `bmc-opt`: the seed's BMC (no rough part) on the optimal set of `tables/optimal_sets.txt`
//!   (`eval/src/bin/optimal_sets.rs`: the set minimising the model's posterior variance, in the lobe
//!   frame) with the hyperparameters it was optimised for.
//!
//! # Tiers
//! `raw`, `clamp` (luminance ≤ 30× the map mean), `smooth` (clamp → 128×64 → SG blur of
//! sharpness 10) and `synthetic` (10 seeded SG mixtures), as `eval/src/bin/accuracy.rs`.
//! Hyperparameters `(l, σ′)` per (BRDF, N) are read from
//! `tables/renderer_hyperparameters.txt` (written by `--learn --write` on the training maps' clamp
//! tier: `err`, the grid point whose estimates have the smallest mean RMSE ratio to QMC on the
//! same samples — what the crate bakes; `ml`, REML; `cov`, the seed's covariance fit; `--hyper`
//! picks the rows the f64 estimators use); held-out figures exclude the training maps
//! apartment, bridge, forest, lab.
//!
//! # Ground truth
//! Every pixel of the tier's map with per-pixel weights `∫_pixel p`: exact for diffuse
//! (`reference::truth::cosine_weights`), an adaptive k×k sub-grid for Phong × cosine
//! (`renderer_engine::phong_cos_weights`, k ≤ 64 from a midpoint-error bound; measured by
//! `--self-test` against `reference::truth::phong_weights` without the cosine: 3·10⁻⁶
//! (e = 200) to 2·10⁻⁵ (e = 10) relative on a clamped map, far below every RMSE measured
//! on the map tiers (≥ 10⁻³)). The weights depend only on the grid: computed once per (query,
//! grid) and applied to every map of that size. Synthetic: exact irradiance
//! (`SgLight::irradiance`), the lobe-frame rule of the engine at double density for Phong.
//!
//! # Output
//! `--out DIR/renderer.md` (tables: targets, the seed's 80-sample table, σ′ selection, relative
//! RMSE per tier and BRDF) and `DIR/renderer.png` (log-log RMSE against N, tier × BRDF), and
//! with `--csv FILE` one row `renderer,<tier>,<estimator>,<n>,<brdf>,<map>,<rel_rmse>` per
//! (tier, estimator, N, BRDF, map). The full run takes about 3 minutes on 2 cores, `--quick`
//! under 20 s, `--learn` 30 s.

use sphere_quadrature_eval::{cli, compare, optimal, parallel, renderer_engine as engine, tiers};

use parallel::parallel_map;
use std::collections::BTreeMap;
use std::error::Error;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use clap::Parser;
use cli::TRAINING_MAPS;
use engine::{Brdf, Gls, LobeFrame, LumPyramid, Query, Reml, Rule};
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use reference::vec::dot;
use sphere_quadrature::qmc::LobeSampler;
use sphere_quadrature::{Lobe, Vec3};

const NS: [usize; 5] = [16, 32, 64, 80, 128];
const BRDFS: [Brdf; 4] = [Brdf::Diffuse, Brdf::Phong(10.0), Brdf::Phong(50.0), Brdf::Phong(200.0)];
const TIERS: [&str; 4] = ["raw", "clamp", "smooth", "synthetic"];
const CLAMP: usize = 1;
const SMOOTH: usize = 2;
const SYNTHETIC: usize = 3;
const ESTIMATORS: [&str; E] = [
    "mc",
    "qmc-sobol",
    "qmc-sf",
    "qmc-fis",
    "bmc-sf",
    "bmc-sf-f64",
    "bmc-sobol",
    "bmc-sf-sel",
    "bmc-opt",
];
/// Number of estimators.
const E: usize = 9;
const MC: usize = 0;
const SOBOL: usize = 1;
const SF: usize = 2;
const FIS: usize = 3;
const BMC_SF: usize = 4;
const BMC_F64: usize = 5;
const BMC_SOBOL: usize = 6;
const BMC_SF_SEL: usize = 7;
const BMC_OPT: usize = 8;
/// The family of `bmc-sf-sel` (per-query REML selection): σ′ ∈ `SEL_SIGMAS` × l ∈ the learned
/// l times `SEL_L_FACTORS`.
const SEL_SIGMAS: [f64; 6] = [1e-4, 1e-3, 1e-2, 0.1, 0.3, 1.0];
const SEL_L_FACTORS: [f64; 4] = [0.5, 1.0, 2.0, 4.0];
/// Family size.
const SEL: usize = SEL_SIGMAS.len() * SEL_L_FACTORS.len();

const SEED_QUERIES: u64 = 0x12E0_0001;
const SEED_MC: u64 = 0x12E0_0002;
const SEED_PHASE: u64 = 0x12E0_0003;
const SEED_SOBOL: u32 = 0x12E0_0004;
/// The synthetic mixtures of `eval/src/bin/accuracy.rs`.
const SEED_SYNTHETIC: u64 = 0xE7A1_0002;

/// Křivánek and Colbert's level bias (`lod = ½·log₂(Ω_s/Ω_p) + 1`).
const FIS_BIAS: f64 = 1.0;
/// Absolute per-pixel tolerance of the Phong × cosine truth weights (`∫p ≤ 1`).
const TRUTH_TOL: f64 = 4e-9;
/// Largest sharpness of the synthetic mixtures' lobes (`tiers::mixtures`).
const MIXTURE_SHARPNESS: f64 = 20.0;

const HYPER_FILE: &str = "tables/renderer_hyperparameters.txt";
/// The optimal sets of `bmc-opt` (`eval/src/bin/optimal_sets.rs`).
const OPTIMAL_FILE: &str = "tables/optimal_sets.txt";
/// Hyperparameter keys: the BMC-SF sample set each was learned on.
const KEYS: [(&str, Brdf, f64); 10] = [
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
const ERR_L: usize = 11;
const ERR_SIGMAS: [f64; 14] =
    [1e-4, 1e-3, 1e-2, 0.03, 0.1, 0.2, 0.3, 0.5, 1.0, 1.5, 2.0, 4.0, 8.0, 16.0];
/// Learning grid: l = 0.01·2^(k/2), k = 0…17 (0.01 … 2.56).
const L_STEPS: usize = 17;
const SIGMAS: [f64; 11] = [1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.2, 0.5, 1.0, 2.0];

fn l_grid() -> Vec<f64> {
    (0..L_STEPS).map(|k| 0.01 * 2f64.powf(k as f64 / 2.0)).collect()
}

#[derive(Clone, Debug)]
struct Options {
    out: PathBuf,
    csv: Option<PathBuf>,
    learn: bool,
    write: bool,
    self_test: bool,
    hyper_file: PathBuf,
    hyper_method: String,
    threads: usize,
    queries: usize,
    mixtures: usize,
    sobol_queries: usize,
    paths: Vec<PathBuf>,
    args: Vec<String>,
}

/// renderer: the BMC renderer benchmark of issue #12 (item 6)
#[derive(Parser)]
#[command(bin_name = "cargo eval renderer --")]
struct Cli {
    /// Equirectangular .hdr maps (default: the ten in examples/envmaps/; two with
    /// --quick)
    #[arg(value_name = "MAPS", value_parser = cli::map_file, verbatim_doc_comment)]
    maps: Vec<PathBuf>,
    /// Output directory (default target/renderer; docs/renderer.md and
    /// docs/renderer.png only with --out docs)
    #[arg(long, value_name = "DIR", verbatim_doc_comment)]
    out: Option<PathBuf>,
    /// Also write rows `renderer,<tier>,<estimator>,<n>,<brdf>,<map>,<rel_rmse>`
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// CI smoke run: 2 maps, 2 mixtures, 32 queries (seconds)
    #[arg(long)]
    quick: bool,
    /// Queries per map (default 256; 32 with --quick)
    #[arg(long, value_name = "Q", value_parser = cli::positive)]
    queries: Option<usize>,
    /// bmc-sobol on the first Q queries only (default: all)
    #[arg(long, value_name = "Q")]
    sobol_queries: Option<usize>,
    /// Learn (l, σ′) per (BRDF, N) on the training maps' clamp tier (REML, the
    /// seed's covariance fit, and the error-minimising fit) and write the
    /// hyperparameter file into --out (with --write: the --hyper-file)
    #[arg(long, verbatim_doc_comment)]
    learn: bool,
    /// With --learn: write the learned rows to --hyper-file (by default
    /// tables/renderer_hyperparameters.txt)
    #[arg(long, requires = "learn", conflicts_with = "quick", verbatim_doc_comment)]
    write: bool,
    /// Hyperparameter file (default tables/renderer_hyperparameters.txt)
    #[arg(long, value_name = "FILE")]
    hyper_file: Option<PathBuf>,
    /// Which learned rows the f64 estimators use (default err: the smallest
    /// training RMSE ratio to QMC, as the crate bakes; ml: maximum marginal
    /// likelihood; cov: the seed's covariance fit). bmc-sf is the crate's
    /// renderer with its baked hyperparameters whatever this says.
    #[arg(long = "hyper", value_name = "err|ml|cov", verbatim_doc_comment)]
    #[arg(value_parser = ["err", "ml", "cov"], default_value = "err")]
    #[arg(hide_possible_values = true, hide_default_value = true)]
    hyper_method: String,
    /// Convergence and consistency checks of the f64 engine
    #[arg(long)]
    self_test: bool,
    #[command(flatten)]
    threads: cli::Threads,
}

fn parse_args() -> Options {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let c = Cli::parse();
    let root = cli::repo_root();
    let paths = if c.maps.is_empty() { cli::named_maps(c.quick) } else { c.maps };
    Options {
        out: c.out.unwrap_or_else(|| root.join("target/renderer")),
        csv: c.csv,
        learn: c.learn,
        write: c.write,
        self_test: c.self_test,
        hyper_file: c.hyper_file.unwrap_or_else(|| root.join(HYPER_FILE)),
        hyper_method: c.hyper_method,
        threads: c.threads.count(),
        queries: c.queries.unwrap_or(if c.quick { 32 } else { 256 }),
        mixtures: if c.quick { 2 } else { 10 },
        sobol_queries: c.sobol_queries.unwrap_or(usize::MAX),
        paths,
        args,
    }
}

// ---------------------------------------------------------------------------------------
// Hyperparameters

#[derive(Clone, Copy, Debug)]
struct Hyper {
    l: f64,
    sigma: f64,
}

impl Hyper {
    fn lambda(self) -> f64 {
        2.0 / (self.l * self.l)
    }
}

type HyperMap = BTreeMap<(String, usize), Hyper>;

/// Reads `<method> <key> <N> <l> <sigma>` rows of one method; `#` starts a comment.
fn parse_hyper(text: &str, method: &str) -> Result<HyperMap, String> {
    let mut map = HyperMap::new();
    for (no, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split_whitespace().collect();
        let err = |m: &str| format!("line {}: {m}", no + 1);
        if f.len() != 5 {
            return Err(err("expected `<method> <key> <N> <l> <sigma>`"));
        }
        if !["ml", "cov", "err"].contains(&f[0]) {
            return Err(err("method must be ml, cov or err"));
        }
        if !KEYS.iter().any(|k| k.0 == f[1]) {
            return Err(err(&format!("unknown key {}", f[1])));
        }
        let n: usize = f[2].parse().map_err(|e| err(&format!("N: {e}")))?;
        let l: f64 = f[3].parse().map_err(|e| err(&format!("l: {e}")))?;
        let sigma: f64 = f[4].parse().map_err(|e| err(&format!("sigma: {e}")))?;
        if !(l > 0.0 && l.is_finite() && sigma > 0.0 && sigma.is_finite()) {
            return Err(err("l and sigma must be finite and positive"));
        }
        if f[0] == method {
            map.insert((f[1].to_string(), n), Hyper { l, sigma });
        }
    }
    Ok(map)
}

/// The key of BMC-SF's set for `brdf`: the set morphed onto the BRDF's lobe (the cosine
/// for diffuse), as the crate's renderers and `qmc-sf` sample.
fn key_sf(brdf: Brdf) -> String {
    match brdf {
        Brdf::Diffuse => "diffuse-cos".into(),
        b => b.name(),
    }
}

fn hyper(h: &HyperMap, key: &str, n: usize) -> Result<Hyper, String> {
    h.get(&(key.to_string(), n)).copied().ok_or_else(|| {
        format!("no hyperparameters for ({key}, N = {n}): run with --learn --write (see --help)")
    })
}

// ---------------------------------------------------------------------------------------
// Scenes

enum Light {
    Map { map: EnvMap, lum: Vec<f64>, pyramid: LumPyramid },
    Mixture(tiers::Mixture),
}

struct Scene {
    name: String,
    tier: usize,
    held_out: bool,
    light: Light,
}

impl Scene {
    fn map(tier: usize, name: &str, map: EnvMap) -> Self {
        let lum =
            map.pixels.iter().map(|p| luminance([p[0] as f64, p[1] as f64, p[2] as f64])).collect();
        let pyramid = LumPyramid::new(&map);
        Self {
            name: name.into(),
            tier,
            held_out: !TRAINING_MAPS.contains(&name),
            light: Light::Map { map, lum, pyramid },
        }
    }

    fn lum(&self, d: [f64; 3]) -> f64 {
        match &self.light {
            Light::Map { map, lum, .. } => {
                let (u, v) = map.pixel_of(d);
                lum[v * map.width + u]
            }
            Light::Mixture(m) => m.value(reference::vec::normalize(d)),
        }
    }

    /// FIS read for a sample of solid angle `omega_s`.
    fn filtered(&self, d: [f64; 3], omega_s: f64) -> f64 {
        match &self.light {
            Light::Map { pyramid, .. } => pyramid.filtered(d, omega_s, FIS_BIAS),
            Light::Mixture(m) => {
                // Bilinear read of a texel of area A = 4^bias·Ω_s: per-axis variance A/4, the
                // SG's is 1/λ_f, so λ_f = 4/A.
                let lf = 4.0 / (4f64.powf(FIS_BIAS) * omega_s);
                let d = reference::vec::normalize(d);
                m.constant
                    + m.lobes
                        .iter()
                        .map(|g| engine::sg_filtered(g.axis, g.sharpness, g.amplitude, d, lf))
                        .sum::<f64>()
            }
        }
    }
}

/// Ground truth of every scene for every query: `[scene][query]`.
fn truths(brdf: Brdf, scenes: &[Scene], queries: &[Query], threads: usize) -> Vec<Vec<f64>> {
    let mut out = vec![Vec::new(); scenes.len()];
    // Maps, grouped by grid size: one weight vector per (query, grid) serves the group.
    let mut sizes: Vec<(usize, usize)> = Vec::new();
    for s in scenes {
        if let Light::Map { map, .. } = &s.light {
            if !sizes.contains(&(map.width, map.height)) {
                sizes.push((map.width, map.height));
            }
        }
    }
    for (w, h) in sizes {
        let members: Vec<usize> = (0..scenes.len())
            .filter(|&i| matches!(&scenes[i].light, Light::Map { map, .. } if (map.width, map.height) == (w, h)))
            .collect();
        let per_query = parallel_map(queries, threads, |_, q| {
            let weights = match brdf {
                Brdf::Diffuse => reference::truth::cosine_weights(w, h, q.n),
                Brdf::Phong(e) => engine::phong_cos_weights(w, h, Some(q.n), q.r, e, TRUTH_TOL),
            };
            members
                .iter()
                .map(|&i| match &scenes[i].light {
                    Light::Map { lum, .. } => weights.iter().zip(lum).map(|(a, b)| a * b).sum(),
                    Light::Mixture(_) => unreachable!("members are maps"),
                })
                .collect::<Vec<f64>>()
        });
        for (k, &i) in members.iter().enumerate() {
            out[i] = per_query.iter().map(|v| v[k]).collect();
        }
    }
    let mixtures: Vec<usize> =
        (0..scenes.len()).filter(|&i| matches!(scenes[i].light, Light::Mixture(_))).collect();
    let values = parallel_map(&mixtures, threads, |_, &i| {
        let Light::Mixture(m) = &scenes[i].light else { unreachable!("a mixture") };
        queries
            .iter()
            .map(|q| match brdf {
                Brdf::Diffuse => m.irradiance(q.n),
                Brdf::Phong(_) => {
                    let frame = LobeFrame::new(brdf, q);
                    Rule::new(brdf, &frame, MIXTURE_SHARPNESS, 2.0).integrate(|x| m.value(x))
                }
            })
            .collect::<Vec<f64>>()
    });
    for (&i, v) in mixtures.iter().zip(values) {
        out[i] = v;
    }
    out
}

// ---------------------------------------------------------------------------------------
// Sample sets and weights per query

/// Everything one query at one N needs, independent of the map.
#[derive(Clone, Debug, Default)]
struct Plan {
    mc: Vec<[f64; 3]>,
    sobol: Vec<[f64; 3]>,
    sf: Vec<[f64; 3]>,
    bmc_sf: Vec<[f64; 3]>,
    w_sf: Vec<f64>,
    /// The crate's renderer: its directions (f32) and weights (f32, `∫p` scale).
    crate_dirs: Vec<[f64; 3]>,
    w_crate: Vec<f64>,
    /// Weights on `sobol`; empty when the query is not in the bmc-sobol subset.
    w_sobol: Vec<f64>,
    /// `z` of `bmc_sf` for every l of the selection family (index 1: the learned l).
    z_sf: Vec<Vec<f64>>,
    /// The QMC weights of `bmc_sf` ([`rough_z`]).
    qw: Vec<f64>,
    /// `bmc-opt`: the optimal set (world) and its weights; empty without a set.
    opt: Vec<[f64; 3]>,
    w_opt: Vec<f64>,
    /// `∫p`.
    mass: f64,
}

fn mix(seed: u64, q: usize, n: usize) -> u64 {
    let mut r = Rng::new(seed ^ ((q as u64) << 20) ^ n as u64);
    r.next_u64()
}

/// The phase (turns) of the diffuse BMC-SF sets of query `q` at size `n`.
fn diffuse_phase(q: usize, n: usize) -> f64 {
    (mix(SEED_PHASE ^ 0xD1FF, q, n) >> 11) as f64 / (1u64 << 53) as f64
}

/// [`diffuse_phase`] as the crate's phase bits (`turns·2⁶⁴`, exactly).
fn diffuse_phase_bits(q: usize, n: usize) -> u64 {
    (mix(SEED_PHASE ^ 0xD1FF, q, n) >> 11) << 11
}

/// The BMC-SF set of hyperparameter key `key` for query `q` (world directions).
fn bmc_sf_set(key: &str, q: &Query, qi: usize, n: usize) -> Vec<[f64; 3]> {
    let (_, brdf, e) = *KEYS.iter().find(|k| k.0 == key).expect("a known key");
    let frame = LobeFrame::new(brdf, q);
    let phase = if brdf == Brdf::Diffuse { diffuse_phase(qi, n) } else { 0.0 };
    engine::sf_set(&frame, n, e, phase)
}

/// `z + σ′²·q`: the nugget read as a rough component of the radiance (white at the sample
/// spacing) whose integral is `Σ qᵢ·εᵢ` with the QMC weights `qᵢ = p(xᵢ)/(N·pdf(xᵢ))` of the
/// set (its lobe `cosᵉ` about the key's axis): `Cov(∫ε·p, εᵢ) = σ′²·qᵢ`. The estimate is then
/// `β∫p + (z + σ′²q)ᵀQ⁻¹(Y − β1)`: QMC as σ′ → ∞, plain BMC as σ′ → 0.
fn rough_z(z: &[f64], key: &str, q: &Query, xs: &[[f64; 3]], sigma: f64) -> Vec<f64> {
    let (_, brdf, e) = *KEYS.iter().find(|k| k.0 == key).expect("a known key");
    let axis = brdf.axis(q);
    let n = xs.len() as f64;
    z.iter()
        .zip(xs)
        .map(|(&z, &x)| {
            let pdf = (e + 1.0) / (2.0 * PI) * dot(axis, x).max(0.0).powf(e);
            z + sigma * sigma * brdf.p(q, x) / (n * pdf)
        })
        .collect()
}

fn v64(d: Vec3) -> [f64; 3] {
    [d.x as f64, d.y as f64, d.z as f64]
}

fn v32(d: [f64; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

/// One member of a per-query selection family: its REML likelihood and GLS solver, the
/// index of its l in `SEL_L_FACTORS` and its index in the family.
struct Member {
    reml: Reml,
    gls: Gls,
    sigma: f64,
    l_index: usize,
    index: usize,
}

/// Per N index: the selection family of the BMC-SF set: l = learned l × [`SEL_L_FACTORS`],
/// σ′ ∈ [`SEL_SIGMAS`] (members whose `Q` is not numerically positive definite are left out).
/// `Q` of a BMC-SF set is the same for every query, so one family per (BRDF, N) serves all
/// queries.
#[derive(Default)]
struct Families {
    sf: Vec<Vec<Member>>,
}

fn family(xs: &[[f64; 3]], l: f64) -> Vec<Member> {
    let mut out = Vec::new();
    for (li, f) in SEL_L_FACTORS.iter().enumerate() {
        let lambda = 2.0 / (l * f).powi(2);
        for (si, &s) in SEL_SIGMAS.iter().enumerate() {
            if let (Some(reml), Some(gls)) = (Reml::new(xs, lambda, s), Gls::new(xs, lambda, s)) {
                out.push(Member {
                    reml,
                    gls,
                    sigma: s,
                    l_index: li,
                    index: li * SEL_SIGMAS.len() + si,
                });
            }
        }
    }
    out
}

/// `z` of `xs` for every l of the selection family (`rules[k]` resolves the kernels of l
/// factor k).
fn family_z(rules: &[Rule], xs: &[[f64; 3]], l: f64) -> Vec<Vec<f64>> {
    SEL_L_FACTORS
        .iter()
        .zip(rules)
        .map(|(f, rule)| rule.kernel_means(xs, 2.0 / (l * f).powi(2)))
        .collect()
}

/// The plans of every query at every N for one BRDF (`[query][N index]`) and the selection
/// families; counts the bmc-sobol solves that failed.
fn plans(
    brdf: Brdf,
    queries: &[Query],
    h: &HyperMap,
    sets: &[optimal::OptimalSet],
    o: &Options,
    failures: &AtomicUsize,
) -> Result<(Vec<Vec<Plan>>, Families), String> {
    // bmc-opt: the seed's model (no rough part) with the hyperparameters the set was
    // optimised for; Q is fixed in the lobe frame.
    let opt_key = if brdf == Brdf::Diffuse { "diffuse".to_string() } else { brdf.name() };
    let opt: Vec<Option<(&optimal::OptimalSet, Gls)>> = NS
        .iter()
        .map(|&n| {
            let set = optimal::find(sets, &opt_key, n)?;
            Some((set, Gls::new(&set.unit_dirs(), set.lambda(), set.sigma)?))
        })
        .collect();
    // BMC-SF: Q is the same for every query (the set is fixed in the lobe frame, or rotated
    // about the normal for diffuse).
    let key = key_sf(brdf);
    let mut gls_sf: Vec<Gls> = Vec::new();
    let mut fam = Families::default();
    let mut hyper_sf = Vec::new();
    for &n in &NS {
        let hs = hyper(h, &key, n)?;
        hyper_sf.push(hs);
        let xs = bmc_sf_set(&key, &queries[0], 0, n);
        gls_sf.push(
            Gls::new(&xs, hs.lambda(), hs.sigma)
                .ok_or(format!("Q of {key} N = {n} is not positive definite"))?,
        );
        fam.sf.push(family(&xs, hs.l));
    }
    // One rule per l factor, each resolving the sharpest kernel of that factor.
    let lambda_max = hyper_sf
        .iter()
        .map(|h| h.lambda())
        .chain(opt.iter().flatten().map(|(s, _)| s.lambda()))
        .fold(0.0, f64::max);
    // Diffuse: z depends only on xᵢ·n, so the sets' z (rotated about n by any phase) are the
    // same for every query: computed once per N in the frame of +z.
    let diffuse_z: Vec<Vec<Vec<f64>>> = if brdf == Brdf::Diffuse {
        let q = Query { n: [0.0, 0.0, 1.0], r: [0.0, 0.0, 1.0] };
        let frame = LobeFrame::new(brdf, &q);
        let rules: Vec<Rule> = SEL_L_FACTORS
            .iter()
            .map(|f| Rule::new(brdf, &frame, lambda_max / (f * f), 1.0))
            .collect();
        NS.iter()
            .enumerate()
            .map(|(ni, &n)| family_z(&rules, &engine::sf_set(&frame, n, 1.0, 0.0), hyper_sf[ni].l))
            .collect()
    } else {
        Vec::new()
    };
    let e = brdf.exponent();
    let lobe = match brdf {
        Brdf::Diffuse => Lobe::Cosine,
        Brdf::Phong(e) => Lobe::Phong(e as f32),
    };
    let plans = parallel_map(queries, o.threads, |qi, q| {
        let frame = LobeFrame::new(brdf, q);
        let rules: Vec<Rule> = SEL_L_FACTORS
            .iter()
            .map(|f| Rule::new(brdf, &frame, lambda_max / (f * f), 1.0))
            .collect();
        let rule = &rules[1]; // SEL_L_FACTORS[1] = 1: the learned l.
        let axis = brdf.axis(q);
        NS.iter()
            .enumerate()
            .map(|(ni, &n)| {
                let mut p = Plan { mass: rule.mass(), ..Plan::default() };
                let mut rng = Rng::new(mix(SEED_MC, qi, n));
                p.mc = (0..n)
                    .map(|_| {
                        reference::peers::lobe_direction(axis, e, rng.next_f64(), rng.next_f64())
                    })
                    .collect();
                let scramble = SEED_SOBOL ^ (qi as u32).wrapping_mul(0x9E37_79B9) ^ n as u32;
                p.sobol = (0..n as u32)
                    .map(|i| {
                        let u1 = sobol_burley::sample(i, 0, scramble) as f64;
                        let u2 = sobol_burley::sample(i, 1, scramble) as f64;
                        reference::peers::lobe_direction(axis, e, u1, u2)
                    })
                    .collect();
                let sampler = LobeSampler::new(v32(axis), lobe, n, mix(SEED_PHASE, qi, n))
                    .expect("unit axis, valid lobe");
                p.sf = sampler.iter().map(v64).collect();
                p.bmc_sf = bmc_sf_set(&key, q, qi, n);
                p.z_sf = match diffuse_z.get(ni) {
                    Some(z) => z.clone(),
                    None => family_z(&rules, &p.bmc_sf, hyper_sf[ni].l),
                };
                p.qw = rough_z(&vec![0.0; n], &key, q, &p.bmc_sf, 1.0);
                let s2 = hyper_sf[ni].sigma.powi(2);
                let zr: Vec<f64> = p.z_sf[1].iter().zip(&p.qw).map(|(z, w)| z + s2 * w).collect();
                p.w_sf = gls_sf[ni].weights(&zr, p.mass, None).0;
                if let Some((set, gls)) = &opt[ni] {
                    p.opt = set.world(&frame);
                    let z = rule.kernel_means(&p.opt, set.lambda());
                    p.w_opt = gls.weights(&z, p.mass, None).0;
                }
                if let Some((dirs, w)) = crate_renderer(brdf, n, q, qi) {
                    p.crate_dirs = dirs;
                    p.w_crate = w;
                }
                if qi < o.sobol_queries {
                    let hs = hyper_sf[ni];
                    match Gls::new(&p.sobol, hs.lambda(), hs.sigma) {
                        Some(gls) => {
                            let z = rule.kernel_means(&p.sobol, hs.lambda());
                            let zr = rough_z(&z, &key, q, &p.sobol, hs.sigma);
                            p.w_sobol = gls.weights(&zr, p.mass, None).0;
                        }
                        None => {
                            failures.fetch_add(1, Ordering::Relaxed);
                        }
                    }
                }
                p
            })
            .collect()
    });
    Ok((plans, fam))
}

/// The crate's renderer for `(brdf, N)` at query `q`: its directions and its weights scaled
/// to `∫p` (`π·w` for `bmc::Renderer`, whose estimate is `π·Σ wᵢYᵢ`), or `None` when that
/// `(N, e)` is not baked. Diffuse takes the query's random phase, as `bmc-sf-f64` does.
fn crate_renderer(brdf: Brdf, n: usize, q: &Query, qi: usize) -> Option<(Vec<[f64; 3]>, Vec<f64>)> {
    use sphere_quadrature::bmc::{GlossyRenderer, Renderer};
    let (normal, mirror) = (v32(q.n), v32(q.r));
    let phase_bits = diffuse_phase_bits(qi, n);
    macro_rules! diffuse {
        ($($n:literal)*) => {
            match n {
                $($n => {
                    let mut d = [Vec3::Z; $n];
                    Renderer::<$n>::new().fill_directions(normal, phase_bits, &mut d).ok()?;
                    let w = Renderer::<$n>::weights().iter().map(|&w| PI * f64::from(w));
                    Some((d.iter().map(|&x| v64(x)).collect(), w.collect()))
                })*
                _ => None,
            }
        };
    }
    macro_rules! glossy {
        ($(($n:literal, $e:literal))*) => {
            match (n, brdf.exponent() as u32) {
                $(($n, $e) => {
                    let r = GlossyRenderer::<$n, $e>::new();
                    let (mut d, mut w) = ([Vec3::Z; $n], [0.0f32; $n]);
                    r.fill_directions(normal, mirror, &mut d).ok()?;
                    r.weights(normal, mirror, &mut w).ok()?;
                    Some((d.iter().map(|&x| v64(x)).collect(), w.iter().map(|&w| f64::from(w)).collect()))
                })*
                _ => None,
            }
        };
    }
    match brdf {
        Brdf::Diffuse => diffuse!(16 32 64 80 128),
        Brdf::Phong(_) => {
            glossy!((16, 10)(32, 10)(64, 10)(80, 10)(128, 10)(16, 50)(32, 50)(64, 50)(80, 50)(
                128, 50
            )(16, 200)(32, 200)(64, 200)(80, 200)(128, 200))
        }
    }
}

// ---------------------------------------------------------------------------------------
// Evaluation

/// One scene's results for one BRDF: relative RMSE per N index and estimator (NaN where not
/// applicable), and how often each family member was selected by `bmc-sf-sel`.
#[derive(Clone, Copy, Debug)]
struct Outcome {
    rel: [[f64; E]; 5],
    selected: [[usize; SEL]; 5],
    /// RMS over the queries of (crate renderer − f64 engine) / mean |truth| per N index (NaN
    /// where the crate has no baked set).
    crate_diff: [f64; 5],
}

/// `Σ wᵢYᵢ` with the weights of the family member of highest REML likelihood for `y`, and
/// that member's index (`qw`: the set's QMC weights, for [`rough_z`]).
fn select(members: &[Member], y: &[f64], z: &[Vec<f64>], qw: &[f64], mass: f64) -> (f64, usize) {
    let mut best = (f64::NEG_INFINITY, 0);
    for (k, m) in members.iter().enumerate() {
        if let Some(ll) = m.reml.log_likelihood(y) {
            if ll > best.0 {
                best = (ll, k);
            }
        }
    }
    let m = &members[best.1];
    let zr: Vec<f64> =
        z[m.l_index].iter().zip(qw).map(|(z, q)| z + m.sigma * m.sigma * q).collect();
    let w = m.gls.weights(&zr, mass, None).0;
    (w.iter().zip(y).map(|(w, y)| w * y).sum(), m.index)
}

fn evaluate(
    scene: &Scene,
    brdf: Brdf,
    queries: &[Query],
    plans: &[Vec<Plan>],
    fam: &Families,
    truth: &[f64],
) -> Outcome {
    let mut se = [[0.0f64; E]; 5];
    let mut count = [[0usize; E]; 5];
    let mut abs = [[0.0f64; E]; 5];
    let mut selected = [[0usize; SEL]; 5];
    let mut diff = [(0.0f64, 0usize, 0.0f64); 5];
    let mean = |dirs: &[[f64; 3]], q: &Query| -> f64 {
        dirs.iter().map(|&x| scene.lum(x) * brdf.qmc_factor(q, x)).sum::<f64>() / dirs.len() as f64
    };
    let lums = |dirs: &[[f64; 3]]| -> Vec<f64> { dirs.iter().map(|&x| scene.lum(x)).collect() };
    let dot_w = |y: &[f64], w: &[f64]| -> f64 { y.iter().zip(w).map(|(y, w)| y * w).sum() };
    for (qi, (q, &t)) in queries.iter().zip(truth).enumerate() {
        for (ni, &n) in NS.iter().enumerate() {
            let p = &plans[qi][ni];
            let fis =
                p.sf.iter()
                    .map(|&x| {
                        let omega = (1.0 / (n as f64 * brdf.pdf(q, x))).min(4.0 * PI);
                        scene.filtered(x, omega) * brdf.qmc_factor(q, x)
                    })
                    .sum::<f64>()
                    / n as f64;
            let mut est = [f64::NAN; E];
            est[MC] = mean(&p.mc, q);
            est[SOBOL] = mean(&p.sobol, q);
            est[SF] = mean(&p.sf, q);
            est[FIS] = fis;
            let y_sf = lums(&p.bmc_sf);
            est[BMC_F64] = dot_w(&y_sf, &p.w_sf);
            if !p.w_crate.is_empty() {
                est[BMC_SF] = dot_w(&lums(&p.crate_dirs), &p.w_crate);
                diff[ni].0 += (est[BMC_SF] - est[BMC_F64]).powi(2);
                diff[ni].1 += 1;
                diff[ni].2 += t.abs();
            }
            let (v, k) = select(&fam.sf[ni], &y_sf, &p.z_sf, &p.qw, p.mass);
            est[BMC_SF_SEL] = v;
            selected[ni][k] += 1;
            if !p.w_sobol.is_empty() {
                est[BMC_SOBOL] = dot_w(&lums(&p.sobol), &p.w_sobol);
            }
            if !p.w_opt.is_empty() {
                est[BMC_OPT] = dot_w(&lums(&p.opt), &p.w_opt);
            }
            for k in 0..E {
                if est[k].is_finite() {
                    se[ni][k] += (est[k] - t).powi(2);
                    count[ni][k] += 1;
                    abs[ni][k] += t.abs();
                }
            }
        }
    }
    let mut rel = [[f64::NAN; E]; 5];
    for ni in 0..5 {
        for k in 0..E {
            if count[ni][k] > 0 {
                let c = count[ni][k] as f64;
                rel[ni][k] = (se[ni][k] / c).sqrt() / (abs[ni][k] / c);
            }
        }
    }
    let crate_diff =
        diff.map(
            |(sq, c, a)| {
                if c == 0 {
                    f64::NAN
                } else {
                    (sq / c as f64).sqrt() / (a / c as f64)
                }
            },
        );
    Outcome { rel, selected, crate_diff }
}

/// Per (tier, BRDF): the scenes' names, held-out flags and results.
#[derive(Clone, Default)]
struct TierResult {
    names: Vec<String>,
    held_out: Vec<bool>,
    rel: Vec<[[f64; E]; 5]>,
    selected: Vec<[[usize; SEL]; 5]>,
    crate_diff: Vec<[f64; 5]>,
}

impl TierResult {
    fn subset(&self) -> Vec<usize> {
        let held: Vec<usize> = (0..self.names.len()).filter(|&k| self.held_out[k]).collect();
        if held.is_empty() {
            (0..self.names.len()).collect()
        } else {
            held
        }
    }

    /// Mean over the held-out maps of estimator `e` at N index `ni`.
    fn mean(&self, ni: usize, e: usize) -> f64 {
        let s = self.subset();
        s.iter().map(|&k| self.rel[k][ni][e]).sum::<f64>() / s.len().max(1) as f64
    }

    /// (mean of per-map ratios a/b, ratio of means, worst (ratio, map)) over the held-out maps.
    fn ratios(&self, ni: usize, a: usize, b: usize) -> (f64, f64, f64, String) {
        let s = self.subset();
        let mut sum = 0.0;
        let mut worst = (f64::NEG_INFINITY, String::new());
        for &k in &s {
            let r = self.rel[k][ni][a] / self.rel[k][ni][b];
            sum += r;
            if r > worst.0 || r.is_nan() {
                worst = (r, self.names[k].clone());
            }
        }
        (sum / s.len().max(1) as f64, self.mean(ni, a) / self.mean(ni, b), worst.0, worst.1)
    }
}

// ---------------------------------------------------------------------------------------
// Learning

/// Fits `c(d²) = a·exp(−d²/l²)` to binned products by pair-count weighted least squares
/// (`a` closed-form, `l` on a log grid then golden section): the seed's covariance fit, as
/// `eval/src/bin/learn_hyperparameters.rs` does it. Returns `(a, l)`.
fn fit_covariance(points: &[(f64, f64, f64)]) -> (f64, f64) {
    let eval = |l: f64| {
        let (mut see, mut sce) = (0.0, 0.0);
        for &(d2, c, w) in points {
            let e = (-d2 / (l * l)).exp();
            see += w * e * e;
            sce += w * c * e;
        }
        let a = if see > 0.0 { (sce / see).max(0.0) } else { 0.0 };
        let res: f64 =
            points.iter().map(|&(d2, c, w)| w * (c - a * (-d2 / (l * l)).exp()).powi(2)).sum();
        (res, a)
    };
    let (lo, hi, steps) = (0.003f64.ln(), 8.0f64.ln(), 400);
    let node = |k: usize| lo + (hi - lo) * k as f64 / steps as f64;
    let k = (0..=steps)
        .min_by(|&a, &b| eval(node(a).exp()).0.total_cmp(&eval(node(b).exp()).0))
        .unwrap_or(0);
    let (mut a, mut b) = (node(k.saturating_sub(1)), node((k + 1).min(steps)));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..80 {
        let (c, d) = (b - g * (b - a), a + g * (b - a));
        if eval(c.exp()).0 < eval(d.exp()).0 {
            b = d;
        } else {
            a = c;
        }
    }
    let l = (0.5 * (a + b)).exp();
    (eval(l).1, l)
}

struct Learned {
    key: &'static str,
    n: usize,
    ml: Hyper,
    /// ℓ at the optimum minus ℓ at the best cell with the next-larger / smaller l.
    edge: bool,
    cov: Hyper,
    surface: Vec<Vec<f64>>,
    /// The `err` fit and its training objective (mean over training maps of the RMSE ratio
    /// to QMC on the same samples); `None` for keys the fit skips.
    err: Option<(Hyper, f64)>,
}

fn learn(o: &Options, names: &[String], clamped: &[EnvMap], queries: &[Query]) -> Vec<Learned> {
    let training: Vec<(usize, Vec<f64>)> = names
        .iter()
        .enumerate()
        .filter(|(_, n)| TRAINING_MAPS.contains(&n.as_str()))
        .map(|(i, _)| {
            let lum = clamped[i]
                .pixels
                .iter()
                .map(|p| luminance([p[0] as f64, p[1] as f64, p[2] as f64]))
                .collect();
            (i, lum)
        })
        .collect();
    let ls = l_grid();
    let mut out = Vec::new();
    for &(key, _, _) in &KEYS {
        for &n in &NS {
            // Samples per (map, query); Q is the same for every query (the set is fixed in the
            // lobe frame, up to a rotation).
            let sets: Vec<Vec<[f64; 3]>> =
                queries.iter().enumerate().map(|(qi, q)| bmc_sf_set(key, q, qi, n)).collect();
            let mut ys: Vec<Vec<f64>> = Vec::new();
            for (i, lum) in &training {
                let map = &clamped[*i];
                for set in &sets {
                    ys.push(
                        set.iter()
                            .map(|&x| {
                                let (u, v) = map.pixel_of(x);
                                lum[v * map.width + u]
                            })
                            .collect(),
                    );
                }
            }
            let xs = &sets[0];
            let cells: Vec<(usize, usize)> =
                (0..ls.len()).flat_map(|a| (0..SIGMAS.len()).map(move |b| (a, b))).collect();
            let lls = parallel_map(&cells, o.threads, |_, &(a, b)| {
                let lambda = 2.0 / (ls[a] * ls[a]);
                match Reml::new(xs, lambda, SIGMAS[b]) {
                    Some(m) => ys.iter().filter_map(|y| m.log_likelihood(y)).sum::<f64>(),
                    None => f64::NEG_INFINITY,
                }
            });
            let mut surface = vec![vec![f64::NEG_INFINITY; SIGMAS.len()]; ls.len()];
            let mut best = (f64::NEG_INFINITY, 0, 0);
            for (&(a, b), &ll) in cells.iter().zip(&lls) {
                surface[a][b] = ll;
                if ll > best.0 {
                    best = (ll, a, b);
                }
            }
            let edge =
                best.1 == 0 || best.1 == ls.len() - 1 || best.2 == 0 || best.2 == SIGMAS.len() - 1;
            // The seed's covariance fit: standardised samples, products binned by d².
            let d2: Vec<f64> = xs
                .iter()
                .flat_map(|a| {
                    xs.iter().map(move |b| {
                        let d: [f64; 3] = std::array::from_fn(|k| a[k] - b[k]);
                        dot(d, d)
                    })
                })
                .collect();
            let dmax = d2.iter().copied().fold(0.0, f64::max).max(1e-12);
            const BINS: usize = 40;
            let (mut sum, mut sum_d, mut cnt) = ([0.0; BINS], [0.0; BINS], [0.0; BINS]);
            let (mut diag, mut diag_n) = (0.0f64, 0.0f64);
            for y in &ys {
                let m = y.iter().sum::<f64>() / n as f64;
                let sd = (y.iter().map(|v| (v - m).powi(2)).sum::<f64>() / n as f64).sqrt();
                if sd.is_nan() || sd <= 0.0 {
                    continue;
                }
                let s: Vec<f64> = y.iter().map(|v| (v - m) / sd).collect();
                for i in 0..n {
                    diag += s[i] * s[i];
                    diag_n += 1.0;
                    for j in 0..n {
                        if i != j {
                            let d = d2[i * n + j];
                            let b = ((d / dmax * BINS as f64) as usize).min(BINS - 1);
                            sum[b] += s[i] * s[j];
                            sum_d[b] += d;
                            cnt[b] += 1.0;
                        }
                    }
                }
            }
            let points: Vec<(f64, f64, f64)> = (0..BINS)
                .filter(|&b| cnt[b] > 0.0)
                .map(|b| (sum_d[b] / cnt[b], sum[b] / cnt[b], cnt[b]))
                .collect();
            let (a, l) = fit_covariance(&points);
            let c0 = diag / diag_n.max(1.0);
            let sigma = if a > 0.0 { ((c0 - a) / a).max(1e-8).sqrt() } else { 1.0 };
            eprintln!(
                "learn {key} N = {n}: ML l = {:.4}, σ′ = {} (ℓ = {:.1}{}); covariance fit l = {l:.4}, σ′ = {sigma:.3e}",
                ls[best.1],
                SIGMAS[best.2],
                best.0,
                if edge { ", at the grid's edge" } else { "" }
            );
            out.push(Learned {
                key,
                n,
                ml: Hyper { l: ls[best.1], sigma: SIGMAS[best.2] },
                edge,
                cov: Hyper { l, sigma },
                surface,
                err: None,
            });
        }
    }
    out
}

fn hyper_file_text(learned: &[Learned], o: &Options, names: &[String], nq: usize) -> String {
    let mut t = String::new();
    let training: Vec<&str> =
        names.iter().map(String::as_str).filter(|n| TRAINING_MAPS.contains(n)).collect();
    let command = format!("cargo eval renderer -- {}", o.args.join(" "));
    let ls = l_grid();
    let _ = writeln!(t, "# Bayesian Monte Carlo hyperparameters of eval/src/bin/renderer.rs (issue #12, item 3, first form).");
    let _ = writeln!(t, "# @generated by `{}`; do not edit by hand.", command.trim_end());
    let _ = writeln!(t, "#");
    let _ = writeln!(t, "# Format: one row per (method, key, N): `<method> <key> <N> <l> <sigma>`; `#` starts a comment.");
    let _ = writeln!(t, "#   method: ml  = maximum restricted (REML) marginal likelihood, σ_f profiled out (src/probe.rs),");
    let _ = writeln!(
        t,
        "#                 over l ∈ {{{}}} × σ′ ∈ {{{}}};",
        ls.iter().map(|l| format!("{l:.4}")).collect::<Vec<_>>().join(", "),
        SIGMAS.map(|s| s.to_string()).join(", ")
    );
    let _ = writeln!(t, "#           cov = the seed's covariance fit: each query's samples standardised, products binned");
    let _ = writeln!(t, "#                 by |xᵢ − xⱼ|² (40 bins), a·exp(−d²/l²) fitted by weighted least squares,");
    let _ =
        writeln!(t, "#                 σ′² = (c(0) − a)/a (c(0) = 1, the standardised variance).");
    let _ = writeln!(t, "#   key: the BMC-SF sample set learned on: diffuse = uniform hemisphere SF set about n (random");
    let _ = writeln!(
        t,
        "#        phase), diffuse-cos = cosine-morphed set (also used by bmc-sobol for diffuse),"
    );
    let _ = writeln!(
        t,
        "#        phongE = set morphed onto cosᵉ about r, fixed in the frame (r, t₁ ∝ n − (n·r)r)."
    );
    let _ = writeln!(t, "#   l: kernel length scale of exp(−|x − x′|²/l²) (λ = 2/l²); sigma: σ′ = σ_n/σ_f, Q = K + σ′²I.");
    let _ = writeln!(t, "# Training data: luminance at the BMC-SF samples of {nq} seeded queries (seed {SEED_QUERIES:#X}) on the");
    let _ = writeln!(
        t,
        "# clamp tier (luminance ≤ 30× the map's mean) of {}; ℓ summed over maps × queries.",
        training.join(", ")
    );
    let _ = writeln!(t, "#           err = the grid point l ∈ 0.08·√2^k (k = 0…{}) × σ′ ∈ {{{}}} whose estimates have the", ERR_L - 1, ERR_SIGMAS.map(|s| s.to_string()).join(", "));
    let _ = writeln!(t, "#                 smallest geometric mean, over the clamp AND smooth tiers of the training maps, of");
    let _ = writeln!(t, "#                 RMSE(BMC)/RMSE(QMC on the same samples), on each map's ground truth; the nugget is read");
    let _ = writeln!(t, "#                 as a rough part of the radiance integrated by the set's QMC weights (renderer.rs rough_z).");
    let _ = writeln!(t, "#                 Keys diffuse-cos and phongE only. The crate bakes these (tables/bmc.txt, tables/glossy.txt).");
    let _ = writeln!(t, "# Rows marked `edge` have their optimum on the grid's boundary.");
    for lr in learned {
        let _ = writeln!(
            t,
            "ml {} {} {} {}{}",
            lr.key,
            lr.n,
            fmt_g(lr.ml.l),
            lr.ml.sigma,
            if lr.edge { " # edge" } else { "" }
        );
    }
    for lr in learned {
        let _ = writeln!(t, "cov {} {} {} {}", lr.key, lr.n, fmt_g(lr.cov.l), fmt_g(lr.cov.sigma));
    }
    for lr in learned {
        if let Some((h, objective)) = lr.err {
            let l_max = 0.08 * 2f64.sqrt().powi(ERR_L as i32 - 1);
            let edge = (h.l - 0.08).abs() < 1e-9
                || (h.l - l_max).abs() < 1e-9
                || h.sigma == ERR_SIGMAS[0]
                || h.sigma == ERR_SIGMAS[ERR_SIGMAS.len() - 1];
            let _ = writeln!(
                t,
                "err {} {} {} {} # training geometric mean of RMSE ratios to QMC on the same samples: {objective:.4}{}",
                lr.key,
                lr.n,
                fmt_g(h.l),
                h.sigma,
                if edge { "; edge" } else { "" }
            );
        }
    }
    t
}

/// The `err` fit of one key at every N: the (l, σ′) of the error-minimising grid whose
/// estimator (with [`rough_z`]) has the smallest geometric mean over the training scenes (the
/// clamp and smooth tiers of the training maps) of RMSE(BMC)/RMSE(QMC on the same samples),
/// on the scenes' ground truth. (On the clamp tier alone the surface is flat — training ratios
/// 0.90–1.00 — and its argmin is noise that costs up to 1.8× on smooth light.)
fn learn_err(o: &Options, key: &str, scenes: &[Scene], queries: &[Query]) -> Vec<(Hyper, f64)> {
    let (_, brdf, _) = *KEYS.iter().find(|k| k.0 == key).expect("a known key");
    let truth = truths(brdf, scenes, queries, o.threads);
    let ls: Vec<f64> = (0..ERR_L).map(|k| 0.08 * 2f64.sqrt().powi(k as i32)).collect();
    let lambda_max = 2.0 / (ls[0] * ls[0]);
    let mut out = Vec::new();
    for &n in &NS {
        let sets: Vec<Vec<[f64; 3]>> =
            queries.iter().enumerate().map(|(qi, q)| bmc_sf_set(key, q, qi, n)).collect();
        // Per query: z for every l, ∫p, the QMC weights, and the luminance per scene.
        let per_query = parallel_map(queries, o.threads, |qi, q| {
            let frame = LobeFrame::new(brdf, q);
            let rule = Rule::new(brdf, &frame, lambda_max, 1.0);
            let xs = &sets[qi];
            let zs: Vec<Vec<f64>> =
                ls.iter().map(|l| rule.kernel_means(xs, 2.0 / (l * l))).collect();
            let qw = rough_z(&vec![0.0; n], key, q, xs, 1.0);
            let ys: Vec<Vec<f64>> =
                scenes.iter().map(|s| xs.iter().map(|&x| s.lum(x)).collect()).collect();
            (zs, rule.mass(), qw, ys)
        });
        let xs0 = &sets[0];
        let cells: Vec<(usize, usize)> =
            (0..ERR_L).flat_map(|a| (0..ERR_SIGMAS.len()).map(move |b| (a, b))).collect();
        let objective = parallel_map(&cells, o.threads, |_, &(a, b)| {
            let sigma = ERR_SIGMAS[b];
            let Some(gls) = Gls::new(xs0, 2.0 / (ls[a] * ls[a]), sigma) else {
                return f64::INFINITY;
            };
            let (mut se_b, mut se_q) = (vec![0.0; scenes.len()], vec![0.0; scenes.len()]);
            for (qi, (zs, mass, qw, ys)) in per_query.iter().enumerate() {
                let zr: Vec<f64> =
                    zs[a].iter().zip(qw).map(|(z, w)| z + sigma * sigma * w).collect();
                let w = gls.weights(&zr, *mass, None).0;
                for (si, y) in ys.iter().enumerate() {
                    let t = truth[si][qi];
                    let b: f64 = w.iter().zip(y).map(|(w, y)| w * y).sum();
                    let qm: f64 = qw.iter().zip(y).map(|(w, y)| w * y).sum();
                    se_b[si] += (b - t).powi(2);
                    se_q[si] += (qm - t).powi(2);
                }
            }
            let mean_log: f64 = se_b.iter().zip(&se_q).map(|(b, q)| 0.5 * (b / q).ln()).sum();
            (mean_log / scenes.len() as f64).exp()
        });
        let (best, value) = cells
            .iter()
            .zip(&objective)
            .min_by(|x, y| x.1.total_cmp(y.1))
            .map(|(&c, &v)| (c, v))
            .expect("a non-empty grid");
        let h = Hyper { l: ls[best.0], sigma: ERR_SIGMAS[best.1] };
        eprintln!(
            "learn err {key} N = {n}: l = {:.4}, σ′ = {} (training geometric mean ratio {value:.4})",
            h.l, h.sigma
        );
        out.push((h, value));
    }
    out
}

fn fmt_g(x: f64) -> String {
    format!("{:.4}", x).trim_end_matches('0').trim_end_matches('.').to_string()
}

// ---------------------------------------------------------------------------------------
// Self-test

fn self_test(o: &Options, h: Option<&HyperMap>) -> Result<(), Box<dyn Error>> {
    use reference::analytic::SgLight;
    let mut rng = Rng::new(0x5E1F_7E57);
    println!("# Engine self-test\n");
    // 1. The rule against the independent 1-D reductions of reference::analytic::SgLight.
    println!("## Rule vs SgLight (independent Bessel-I₀ quadrature)\n");
    println!("| case | λ_light | worst relative error |\n| --- | ---: | ---: |");
    for (name, brdf) in [
        ("diffuse", Brdf::Diffuse),
        ("phong10 (no horizon)", Brdf::Phong(10.0)),
        ("phong200 (no horizon)", Brdf::Phong(200.0)),
    ] {
        for lambda in [2.0, 20.0, 200.0] {
            let mut worst = 0.0f64;
            for _ in 0..20 {
                let q = Query { n: rng.uniform_sphere(), r: rng.uniform_sphere() };
                let mut frame = LobeFrame::new(brdf, &q);
                frame.horizon = false;
                // The light sits near the lobe so the integral is not negligible.
                let axis = reference::vec::normalize(std::array::from_fn(|k| {
                    brdf.axis(&q)[k] + 0.3 * rng.uniform_sphere()[k]
                }));
                let g = SgLight { axis, sharpness: lambda, amplitude: 1.0 };
                let rule = Rule::new(brdf, &frame, lambda, 1.0);
                let got = rule.integrate(|x| g.value(x));
                let want = match brdf {
                    Brdf::Diffuse => g.irradiance(q.n),
                    Brdf::Phong(e) => g.phong(q.r, e),
                };
                worst = worst.max((got / want - 1.0).abs());
            }
            println!("| {name} | {lambda} | {worst:.1e} |");
        }
    }
    // 1b. The Bessel functions of the closed-form ring sums.
    let mut worst_i1 = 0.0f64;
    for x in [1e-3, 0.1, 1.0, 5.0, 19.9, 20.1, 50.0, 500.0, 5000.0] {
        // e^(−x)·I₁(x) = (1/π)∫₀^π e^(x(cos t − 1))·cos t dt by 2000-point Gauss–Legendre.
        let (t, w) = reference::quad::gauss_legendre_on(2000, 0.0, PI);
        let want: f64 =
            t.iter().zip(&w).map(|(t, w)| w * (x * (t.cos() - 1.0)).exp() * t.cos()).sum::<f64>()
                / PI;
        worst_i1 = worst_i1.max((engine::bessel_i1e(x) / want - 1.0).abs());
    }
    println!("\nI1e against quadrature, x from 10⁻³ to 5000: worst relative error {worst_i1:.1e}");
    let mut worst_ring = 0.0f64;
    for (qi, q) in engine::queries(8, 0x99).iter().enumerate() {
        for brdf in BRDFS {
            let frame = LobeFrame::new(brdf, q);
            for lambda in [3.0, 300.0] {
                let rule = Rule::new(brdf, &frame, lambda, 2.0);
                let pairs: Vec<(f64, f64)> = (0..16u32)
                    .map(|i| {
                        let x = reference::peers::lobe_direction(
                            brdf.axis(q),
                            brdf.exponent(),
                            sobol_burley::sample(i, 0, qi as u32) as f64,
                            sobol_burley::sample(i, 1, qi as u32) as f64,
                        );
                        (rule.kernel_mean(x, lambda), rule.kernel_mean_nodes(x, lambda))
                    })
                    .collect();
                let top = pairs.iter().map(|p| p.1).fold(0.0, f64::max);
                for (a, b) in pairs {
                    worst_ring = worst_ring.max((a - b).abs() / top);
                }
            }
        }
    }
    println!(
        "z with closed-form full rings vs the trapezoid rule on their nodes (density 2): worst \
         difference relative to the largest z {worst_ring:.1e}\n"
    );
    // 2. Convergence with the horizon: density 1 vs 2.
    println!(
        "\n## Rule convergence with the horizon (density 1 vs 2; 20 random queries, V̄ on 2)\n"
    );
    println!("| BRDF | λ | nodes | ∫p | z (worst of 64 samples, rel. to max z) | V̄ | mixture |\n| --- | ---: | ---: | ---: | ---: | ---: | ---: |");
    let mixtures = tiers::mixtures(4, 0xAB);
    for brdf in BRDFS {
        for lambda in [20.0, 500.0, 5000.0] {
            let (mut dm, mut dz, mut dv, mut dmix, mut nodes) =
                (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0usize);
            let qs = engine::queries(20, 0x77);
            for (qi, q) in qs.iter().enumerate() {
                let frame = LobeFrame::new(brdf, q);
                let a = Rule::new(brdf, &frame, lambda, 1.0);
                let b = Rule::new(brdf, &frame, lambda, 2.0);
                nodes = nodes.max(a.len());
                dm = dm.max((a.mass() / b.mass() - 1.0).abs());
                let xs: Vec<[f64; 3]> = (0..64u32)
                    .map(|i| {
                        reference::peers::lobe_direction(
                            brdf.axis(q),
                            brdf.exponent(),
                            sobol_burley::sample(i, 0, qi as u32) as f64,
                            sobol_burley::sample(i, 1, qi as u32) as f64,
                        )
                    })
                    .collect();
                let (za, zb) = (a.kernel_means(&xs, lambda), b.kernel_means(&xs, lambda));
                let zmax = zb.iter().copied().fold(0.0, f64::max);
                for (x, y) in za.iter().zip(&zb) {
                    dz = dz.max((x - y).abs() / zmax);
                }
                if lambda <= 20.0 && qi < 2 {
                    let (va, vb) = (a.kernel_mean_mean(lambda), b.kernel_mean_mean(lambda));
                    dv = dv.max((va / vb - 1.0).abs());
                }
                let m = &mixtures[qi % mixtures.len()];
                let (ma, mb) = (a.integrate(|x| m.value(x)), b.integrate(|x| m.value(x)));
                dmix = dmix.max((ma / mb - 1.0).abs());
            }
            println!(
                "| {} | {lambda} | {nodes} | {dm:.1e} | {dz:.1e} | {} | {dmix:.1e} |",
                brdf.name(),
                if lambda <= 20.0 { format!("{dv:.1e}") } else { "—".into() }
            );
        }
    }
    // 3. The engine against the crate's baked diffuse renderer (tables/bmc.txt, N = 64).
    {
        use sphere_quadrature::bmc::Renderer;
        let (l, s) = Renderer::<64>::hyperparameters();
        let (l, s) = (l as f64, s as f64);
        let q = Query { n: [0.0, 0.0, 1.0], r: [0.0, 0.0, 1.0] };
        let frame = LobeFrame::new(Brdf::Diffuse, &q);
        let cosine = Renderer::<64>::lobe() == Lobe::Cosine;
        let xs = engine::sf_set(&frame, 64, if cosine { 1.0 } else { 0.0 }, 0.0);
        let lambda = 2.0 / (l * l);
        let rule = Rule::new(Brdf::Diffuse, &frame, lambda, 1.0);
        let gls = Gls::new(&xs, lambda, s).ok_or("Q not positive definite")?;
        let (w, _) = gls.weights(&rule.kernel_means(&xs, lambda), rule.mass(), None);
        let baked = Renderer::<64>::weights();
        let wmax = baked.iter().copied().fold(0.0f32, f32::max) as f64;
        let diff = w.iter().zip(baked).map(|(a, &b)| (a / PI - b as f64).abs()).fold(0.0, f64::max);
        println!("\n## Engine vs the crate's baked `bmc::Renderer::<64>` (l = {l}, σ′ = {s})\n\nlargest weight difference / largest weight: {:.1e}", diff / wmax);
    }
    // 4. Truth weights.
    println!("\n## Phong × cosine truth weights (512×256, clamp tier of the first map)\n");
    let map =
        compare::clamped(&EnvMap::load(&o.paths[0]).map_err(|e| format!("cannot load: {e}"))?);
    let lum: Vec<f64> =
        map.pixels.iter().map(|p| luminance([p[0] as f64, p[1] as f64, p[2] as f64])).collect();
    let (w, hgt) = (map.width, map.height);
    println!("| e | query | no cosine vs reference::truth::phong_weights | tol {TRUTH_TOL:.0e} vs tol/16 (with cosine) | time (ms) |\n| ---: | ---: | ---: | ---: | ---: |");
    let qs = engine::queries(4, SEED_QUERIES);
    for e in [10.0, 50.0, 200.0] {
        for (k, q) in qs.iter().enumerate() {
            let dot_l = |v: &[f64]| v.iter().zip(&lum).map(|(a, b)| a * b).sum::<f64>();
            let exact = dot_l(&reference::truth::phong_weights(w, hgt, q.r, e));
            let mine = dot_l(&engine::phong_cos_weights(w, hgt, None, q.r, e, TRUTH_TOL));
            let t0 = Instant::now();
            let a = dot_l(&engine::phong_cos_weights(w, hgt, Some(q.n), q.r, e, TRUTH_TOL));
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            let b = dot_l(&engine::phong_cos_weights(w, hgt, Some(q.n), q.r, e, TRUTH_TOL / 16.0));
            println!(
                "| {e} | {k} | {:.1e} | {:.1e} | {ms:.0} |",
                (mine / exact - 1.0).abs(),
                (a / b - 1.0).abs()
            );
        }
    }
    // 5. FIS on a constant map.
    let c = EnvMap::constant(64, 32, [2.0; 3]);
    let p = LumPyramid::new(&c);
    let mut worst = 0.0f64;
    for _ in 0..100 {
        let d = rng.uniform_sphere();
        let om = 10f64.powf(-5.0 + 6.0 * rng.next_f64());
        worst = worst.max((p.filtered(d, om, FIS_BIAS) - 2.0).abs());
    }
    println!("\nFIS on a constant map: worst |error| {worst:.1e} ({} levels)", p.len());
    if let Some(h) = h {
        println!("\nHyperparameters read: {} rows", h.len());
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Report

fn pct(x: f64) -> String {
    if !x.is_finite() {
        return "—".into();
    }
    let p = 100.0 * x;
    if p >= 100.0 {
        format!("{p:.0}%")
    } else if p >= 10.0 {
        format!("{p:.1}%")
    } else if p >= 1.0 {
        format!("{p:.2}%")
    } else {
        format!("{p:.3}%")
    }
}

fn ratio(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3}")
    } else {
        "—".into()
    }
}

/// `(slope, intercept)` of ln y against ln N over the estimator's finite means.
fn convergence(tr: &TierResult, e: usize) -> Option<(f64, f64)> {
    let pts: Vec<(f64, f64)> = NS
        .iter()
        .enumerate()
        .map(|(ni, &n)| (n as f64, tr.mean(ni, e)))
        .filter(|(_, y)| y.is_finite() && *y > 0.0)
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let xs: Vec<f64> = pts.iter().map(|p| p.0).collect();
    let ys: Vec<f64> = pts.iter().map(|p| p.1).collect();
    let b = reference::fit::loglog_slope(&xs, &ys);
    let a = ys.iter().zip(&xs).map(|(y, x)| y.ln() - b * x.ln()).sum::<f64>() / xs.len() as f64;
    Some((b, a))
}

fn seed_table(md: &mut String, results: &[Vec<TierResult>]) {
    let n80 = NS.iter().position(|&n| n == 80).expect("N = 80 is measured");
    md.push_str("## The seed's table at N = 80\n\n");
    md.push_str(
        "Relative RMSE at N = 80 relative to BMC with an optimal set (`bmc-opt`, the seed's \
         reference; where it is missing, the best of bmc-sf, bmc-sobol and bmc-sf-sel), and \"rays for the same quality\": the N at which each method's \
         fitted convergence `rmse ≈ A·N^b` (least squares in log-log over N ∈ {16, 32, 64, 80, \
         128}, held-out means) reaches that reference RMSE. Published (Marques et al. 2013, \
         Dragon / Horse, relative to BMC-opt): QMC Sobol +38.4 / +31.8 % (≈ 129 / 127 rays), \
         BMC Sobol +30.0 / +28.9 % (≈ 119 / 120), QMC SF +7.0 / +5.2 % (≈ 88 / 86), BMC SF \
         +5.3 / +2.9 % (≈ 86 / 83).\n\n",
    );
    let published = [
        (SOBOL, "+38.4 / +31.8 %", "129 / 127"),
        (BMC_SOBOL, "+30.0 / +28.9 %", "119 / 120"),
        (SF, "+7.0 / +5.2 %", "88 / 86"),
        (BMC_SF, "+5.3 / +2.9 %", "86 / 83"),
        (BMC_OPT, "0 (reference)", "80"),
        (BMC_F64, "—", "—"),
        (BMC_SF_SEL, "—", "—"),
        (MC, "—", "—"),
        (FIS, "—", "—"),
    ];
    for (bi, e) in [(2usize, 50), (1, 10), (3, 200)] {
        let _ = writeln!(md, "### Phong e = {e}\n");
        md.push_str("| method | published |");
        for t in [CLAMP, SMOOTH, SYNTHETIC] {
            let _ = write!(
                md,
                " {} RMSE vs best BMC | {} rays | {} slope |",
                TIERS[t], TIERS[t], TIERS[t]
            );
        }
        md.push('\n');
        md.push_str("| --- | --- |");
        md.push_str(&" ---: | ---: | ---: |".repeat(3));
        md.push('\n');
        for (est, pub_rmse, pub_rays) in published {
            let _ = write!(md, "| {} | {pub_rmse} ({pub_rays} rays) |", ESTIMATORS[est]);
            for t in [CLAMP, SMOOTH, SYNTHETIC] {
                let tr = &results[t][bi];
                let opt = tr.mean(n80, BMC_OPT);
                let reference = if opt.is_finite() {
                    opt
                } else {
                    [BMC_SF, BMC_SOBOL, BMC_SF_SEL]
                        .iter()
                        .map(|&e| tr.mean(n80, e))
                        .fold(f64::INFINITY, f64::min)
                };
                let m = tr.mean(n80, est);
                let (rays, slope) = match convergence(tr, est) {
                    Some((b, a)) if b < 0.0 => (((reference.ln() - a) / b).exp(), b),
                    Some((b, _)) => (f64::NAN, b),
                    None => (f64::NAN, f64::NAN),
                };
                let _ = write!(
                    md,
                    " {:+.1}% | {} | {} |",
                    100.0 * (m / reference - 1.0),
                    if !rays.is_finite() {
                        "—".into()
                    } else if rays > 1e5 {
                        "> 10⁵".into()
                    } else {
                        format!("{rays:.0}")
                    },
                    if slope.is_finite() { format!("{slope:.2}") } else { "—".into() }
                );
            }
            md.push('\n');
        }
        md.push('\n');
    }
}

/// The crate's baked renderers (`bmc-sf`) against the f64 engine's same model with exact `z`
/// (`bmc-sf-f64`): the RMS difference of the estimates relative to the mean |truth| (the
/// glossy renderer's θₙ interpolation, its SG fit of the lobe and f32), worst over the
/// held-out scenes of the tier, per BRDF and N.
fn crate_table(md: &mut String, results: &[Vec<TierResult>]) {
    md.push_str(
        "## The crate's renderers against the f64 engine

`bmc-sf` is the crate's \
         `bmc::Renderer<N>` (diffuse) and `bmc::GlossyRenderer<N, e>` (Phong) with their baked \
         f32 weights (θₙ interpolation, SG fit of the lobe) and their own f32 directions; \
         `bmc-sf-f64` is the same model in f64 with exact `z` per query. Largest RMS \
         difference of the two estimates over the held-out scenes, relative to the mean \
         |truth|:\n\n",
    );
    md.push_str("| tier | BRDF | N = 16 | 32 | 64 | 80 | 128 |\n| --- | --- | ---: | ---: | ---: | ---: | ---: |\n");
    for (t, per_brdf) in results.iter().enumerate() {
        for (bi, tr) in per_brdf.iter().enumerate() {
            if tr.names.is_empty() {
                continue;
            }
            let s = tr.subset();
            let cells: Vec<String> = (0..NS.len())
                .map(|ni| {
                    let worst = s.iter().map(|&k| tr.crate_diff[k][ni]).fold(f64::NAN, f64::max);
                    if worst.is_finite() {
                        format!("{worst:.1e}")
                    } else {
                        "—".into()
                    }
                })
                .collect();
            let _ = writeln!(md, "| {} | {} | {} |", TIERS[t], BRDFS[bi].name(), cells.join(" | "));
        }
    }
    md.push('\n');
}

fn targets(md: &mut String, results: &[Vec<TierResult>]) {
    md.push_str("## Targets of issue #12 (held-out maps)\n\n");
    md.push_str(
        "Mean of per-map ratios to qmc-sf (and the worst map's ratio), per BRDF and N. \
         Targets for bmc-sf (the crate's renderers): clamp ≤ 1.00 at N ≥ 32 with no map above \
         1.10; smooth ≤ 0.5 at N ≥ 32; synthetic ≤ 0.1 at N ≥ 64. The f64 engine's same model \
         (`bmc-sf-f64`), the per-query selection (`bmc-sf-sel`) and the optimal sets \
         (`bmc-opt`) are judged by the same bounds for comparison; the last rows are the \
         issue's bmc-opt / bmc-sf ≤ 0.3 on synthetic (N ≥ 64).\n\n",
    );
    md.push_str("| tier | BRDF | N = 16 | 32 | 64 | 80 | 128 | target met |\n| --- | --- | ---: | ---: | ---: | ---: | ---: | --- |\n");
    let row = |md: &mut String, t: usize, brdf: Brdf, tr: &TierResult, est, base, label: &str| {
        let mut cells = Vec::new();
        let mut met = true;
        let mut any = false;
        for (ni, &n) in NS.iter().enumerate() {
            let (mr, _, worst, wmap) = tr.ratios(ni, est, base);
            if mr.is_finite() {
                any = true;
                cells.push(format!("{} ({} {wmap})", ratio(mr), ratio(worst)));
            } else {
                cells.push("—".into());
            }
            let ok = match (t, base) {
                (_, BMC_SF) => n < 64 || mr <= 0.3,
                (CLAMP, _) => n < 32 || (mr <= 1.0 && worst <= 1.10),
                (SMOOTH, _) => n < 32 || mr <= 0.5,
                _ => n < 64 || mr <= 0.1,
            };
            met &= ok;
        }
        if any {
            let _ = writeln!(
                md,
                "| {} | {} {label} | {} | {} |",
                TIERS[t],
                brdf.name(),
                cells.join(" | "),
                if met { "yes" } else { "**no**" }
            );
        }
    };
    for t in [CLAMP, SMOOTH, SYNTHETIC] {
        for (bi, &brdf) in BRDFS.iter().enumerate() {
            let tr = &results[t][bi];
            for (est, label) in [
                (BMC_SF, "bmc-sf"),
                (BMC_F64, "bmc-sf-f64"),
                (BMC_SF_SEL, "bmc-sf-sel"),
                (BMC_OPT, "bmc-opt"),
            ] {
                row(md, t, brdf, tr, est, SF, label);
            }
        }
    }
    for (bi, &brdf) in BRDFS.iter().enumerate() {
        row(md, SYNTHETIC, brdf, &results[SYNTHETIC][bi], BMC_OPT, BMC_SF, "bmc-opt / bmc-sf");
    }
    md.push('\n');
}

fn tier_tables(md: &mut String, results: &[Vec<TierResult>]) {
    md.push_str("## Relative RMSE per tier and BRDF\n\n");
    md.push_str(
        "Means over the held-out maps (synthetic: all mixtures). `bmc-sf / qmc-sf`: the mean of \
         per-map ratios, the ratio of the means, and the worst map's ratio.\n\n",
    );
    for (t, tier) in TIERS.iter().enumerate() {
        for (bi, brdf) in BRDFS.iter().enumerate() {
            let tr = &results[t][bi];
            if tr.names.is_empty() {
                continue;
            }
            let ests: Vec<usize> = (0..E)
                .filter(|&e| tr.rel.iter().any(|r| r.iter().any(|v| v[e].is_finite())))
                .collect();
            let _ = writeln!(md, "### {tier}, {}\n", brdf.name());
            let _ = writeln!(
                md,
                "| N | {} | bmc-sf / qmc-sf: mean of ratios | ratio of means | worst map |",
                ests.iter().map(|&e| ESTIMATORS[e]).collect::<Vec<_>>().join(" | ")
            );
            let _ = writeln!(md, "| ---: |{} ---: | ---: | --- |", " ---: |".repeat(ests.len()));
            for (ni, n) in NS.iter().enumerate() {
                let cells: Vec<String> = ests.iter().map(|&e| pct(tr.mean(ni, e))).collect();
                let (mr, rm, worst, wmap) = tr.ratios(ni, BMC_SF, SF);
                let _ = writeln!(
                    md,
                    "| {n} | {} | {} | {} | {} ({wmap}) |",
                    cells.join(" | "),
                    ratio(mr),
                    ratio(rm),
                    ratio(worst)
                );
            }
            md.push('\n');
        }
    }
}

fn selection_table(md: &mut String, results: &[Vec<TierResult>]) {
    md.push_str("## Hyperparameters chosen by bmc-sf-sel\n\n");
    md.push_str(
        "Per-query maximum REML likelihood over the family l = learned l × {0.5, 1, 2, 4} × σ′ \
         ∈ {10⁻⁴, 10⁻³, 10⁻², 0.1, 0.3, 1}, as `Probe::update` selects its member: fraction of \
         queries choosing each σ′ and each l factor (marginals), all maps of the tier, N = 16 \
         and N = 128.\n\n",
    );
    let mut header: Vec<String> = SEL_SIGMAS.iter().map(|s| format!("σ′ = {s}")).collect();
    header.extend(SEL_L_FACTORS.iter().map(|f| format!("l × {f}")));
    let _ = writeln!(md, "| tier | BRDF | N | {} |", header.join(" | "));
    let _ = writeln!(md, "| --- | --- | ---: |{}", " ---: |".repeat(header.len()));
    for (t, tier) in TIERS.iter().enumerate() {
        for (bi, brdf) in BRDFS.iter().enumerate() {
            let tr = &results[t][bi];
            for ni in [0, NS.len() - 1] {
                let counts: Vec<usize> =
                    (0..SEL).map(|k| tr.selected.iter().map(|s| s[ni][k]).sum()).collect();
                let total: usize = counts.iter().sum();
                if total == 0 {
                    continue;
                }
                let ns = SEL_SIGMAS.len();
                let by_sigma = (0..ns).map(|si| {
                    (0..SEL_L_FACTORS.len()).map(|li| counts[li * ns + si]).sum::<usize>()
                });
                let by_l = (0..SEL_L_FACTORS.len())
                    .map(|li| (0..ns).map(|si| counts[li * ns + si]).sum::<usize>());
                let cells: Vec<String> = by_sigma
                    .chain(by_l)
                    .map(|c| format!("{:.0}%", 100.0 * c as f64 / total as f64))
                    .collect();
                let _ = writeln!(
                    md,
                    "| {tier} | {} | {} | {} |",
                    brdf.name(),
                    NS[ni],
                    cells.join(" | ")
                );
            }
        }
    }
    md.push('\n');
}

fn colour(e: usize) -> RGBColor {
    [
        RGBColor(150, 150, 150),
        RGBColor(200, 130, 0),
        RGBColor(30, 90, 200),
        RGBColor(0, 160, 170),
        RGBColor(200, 30, 30),
        RGBColor(140, 60, 170),
        RGBColor(30, 150, 60),
        RGBColor(120, 40, 40),
        RGBColor(0, 0, 0),
    ][e % 9]
}

fn plot(results: &[Vec<TierResult>], path: &Path) -> Result<(), Box<dyn Error>> {
    let root = BitMapBackend::new(path, (1800, 1500)).into_drawing_area();
    root.fill(&WHITE)?;
    let panels = root.split_evenly((TIERS.len(), BRDFS.len()));
    for (k, area) in panels.iter().enumerate() {
        let (t, bi) = (k / BRDFS.len(), k % BRDFS.len());
        let tr = &results[t][bi];
        if tr.names.is_empty() {
            continue;
        }
        let series: Vec<(usize, Vec<(f64, f64)>)> = (0..E)
            .map(|e| {
                let pts = (0..NS.len())
                    .map(|ni| ((NS[ni] as f64).log2(), tr.mean(ni, e)))
                    .filter(|(_, v)| v.is_finite() && *v > 0.0)
                    .collect();
                (e, pts)
            })
            .collect();
        let values = series.iter().flat_map(|(_, p)| p.iter().map(|&(_, v)| v));
        let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let (lo, hi) = if lo.is_finite() { (lo / 1.5, hi * 4.0) } else { (1e-4, 1.0) };
        let mut chart = ChartBuilder::on(area)
            .caption(format!("{}, {}", TIERS[t], BRDFS[bi].name()), ("sans-serif", 20))
            .margin(8)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d(3.8f64..7.2f64, (lo..hi).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("N")
            .x_labels(4)
            .x_label_formatter(&|x| format!("{:.0}", 2f64.powf(*x)))
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .label_style(("sans-serif", 13))
            .draw()?;
        for (e, pts) in series {
            if pts.is_empty() {
                continue;
            }
            let c = colour(e);
            chart
                .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))?
                .label(ESTIMATORS[e])
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2))
                });
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))?;
        }
        if k == 0 {
            chart
                .configure_series_labels()
                .label_font(("sans-serif", 12))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(SeriesLabelPosition::LowerLeft)
                .draw()?;
        }
    }
    root.present()?;
    Ok(())
}

// ---------------------------------------------------------------------------------------

fn main() -> Result<(), Box<dyn Error>> {
    let o = parse_args();
    let start = Instant::now();
    let root = cli::repo_root();
    let hyper_text = std::fs::read_to_string(&o.hyper_file).ok();
    if o.self_test {
        let h = hyper_text.as_deref().map(|t| parse_hyper(t, &o.hyper_method)).transpose()?;
        return self_test(&o, h.as_ref());
    }
    let names: Vec<String> = o.paths.iter().map(|p| cli::map_name(p)).collect();
    let raw: Vec<EnvMap> = o
        .paths
        .iter()
        .map(EnvMap::load)
        .collect::<Result<_, _>>()
        .map_err(|e| format!("cannot load a map: {e}"))?;
    let clamped: Vec<EnvMap> = raw.iter().map(compare::clamped).collect();
    let queries = engine::queries(o.queries, SEED_QUERIES);

    if o.learn {
        let mut learned = learn(&o, &names, &clamped, &queries);
        if learned.is_empty() {
            return Err("no training maps among the inputs".into());
        }
        // The error-minimising fit on the training maps' clamp and smooth tiers, for the sets
        // the crate bakes (cosine-morphed for diffuse, lobe-morphed for Phong).
        let mut training: Vec<Scene> = Vec::new();
        for (n, m) in names.iter().zip(&clamped) {
            if TRAINING_MAPS.contains(&n.as_str()) {
                training.push(Scene::map(CLAMP, n, m.clone()));
                training.push(Scene::map(SMOOTH, n, tiers::smooth(m)));
            }
        }
        for &(key, _, _) in KEYS.iter().filter(|k| k.0 != "diffuse") {
            for ((_, fit), lr) in NS
                .iter()
                .zip(learn_err(&o, key, &training, &queries))
                .zip(learned.iter_mut().filter(|lr| lr.key == key))
            {
                lr.err = Some(fit);
            }
        }
        let text = hyper_file_text(&learned, &o, &names, queries.len());
        let path =
            if o.write { o.hyper_file.clone() } else { o.out.join("renderer_hyperparameters.txt") };
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(&path, &text)?;
        print!("{text}");
        // The REML surfaces, for the record.
        let mut md = String::new();
        for lr in &learned {
            let _ = writeln!(md, "{} N = {}: ℓ − ℓ_max over l (rows) × σ′ (columns)", lr.key, lr.n);
            let best = lr.surface.iter().flatten().copied().fold(f64::NEG_INFINITY, f64::max);
            for (a, row) in lr.surface.iter().enumerate() {
                let cells: Vec<String> = row.iter().map(|v| format!("{:9.1}", v - best)).collect();
                let _ = writeln!(md, "  l = {:.4}: {}", l_grid()[a], cells.join(" "));
            }
        }
        std::fs::create_dir_all(&o.out)?;
        std::fs::write(o.out.join("renderer_reml_surfaces.txt"), md)?;
        eprintln!("wrote {} ({:.1} s)", path.display(), start.elapsed().as_secs_f64());
        return Ok(());
    }

    let hyper_text = hyper_text.ok_or(format!(
        "cannot read {}: run with --learn --write first (see --help)",
        o.hyper_file.display()
    ))?;
    let h = parse_hyper(&hyper_text, &o.hyper_method)?;

    // Scenes: raw, clamp, smooth, synthetic.
    let smooth: Vec<EnvMap> = parallel_map(&clamped, o.threads, |_, m| tiers::smooth(m));
    let mut scenes: Vec<Scene> = Vec::new();
    for (t, tier) in [raw, clamped, smooth].into_iter().enumerate() {
        for (k, map) in tier.into_iter().enumerate() {
            scenes.push(Scene::map(t, &names[k], map));
        }
    }
    for (k, m) in tiers::mixtures(o.mixtures, SEED_SYNTHETIC).into_iter().enumerate() {
        scenes.push(Scene {
            name: format!("sg{k}"),
            tier: SYNTHETIC,
            held_out: true,
            light: Light::Mixture(m),
        });
    }
    eprintln!("scenes built ({:.1} s)", start.elapsed().as_secs_f64());

    // bmc-opt's sets, when the table exists (`eval/src/bin/optimal_sets.rs` writes it).
    let optimal_sets = match std::fs::read_to_string(root.join(OPTIMAL_FILE)) {
        Ok(text) => optimal::parse(&text).map_err(|e| format!("{OPTIMAL_FILE}: {e}"))?,
        Err(_) => {
            eprintln!("no {OPTIMAL_FILE}: bmc-opt is left out");
            Vec::new()
        }
    };
    let mut results: Vec<Vec<TierResult>> =
        vec![vec![TierResult::default(); BRDFS.len()]; TIERS.len()];
    let mut timings = Vec::new();
    let failures = AtomicUsize::new(0);
    for (bi, &brdf) in BRDFS.iter().enumerate() {
        let t0 = Instant::now();
        let truth = truths(brdf, &scenes, &queries, o.threads);
        let t1 = Instant::now();
        let (plan, fam) = plans(brdf, &queries, &h, &optimal_sets, &o, &failures)?;
        let t2 = Instant::now();
        let rel = parallel_map(&scenes, o.threads, |i, s| {
            evaluate(s, brdf, &queries, &plan, &fam, &truth[i])
        });
        for (s, r) in scenes.iter().zip(rel) {
            let tr = &mut results[s.tier][bi];
            tr.names.push(s.name.clone());
            tr.held_out.push(s.held_out);
            tr.rel.push(r.rel);
            tr.selected.push(r.selected);
            tr.crate_diff.push(r.crate_diff);
        }
        let t3 = Instant::now();
        let times = ((t1 - t0).as_secs_f64(), (t2 - t1).as_secs_f64(), (t3 - t2).as_secs_f64());
        eprintln!(
            "{}: truth {:.1} s, sample sets and BMC weights {:.1} s, estimates {:.1} s ({:.1} s total)",
            brdf.name(),
            times.0,
            times.1,
            times.2,
            start.elapsed().as_secs_f64()
        );
        timings.push((brdf.name(), times));
    }
    let seconds = start.elapsed().as_secs_f64();

    // CSV.
    let mut csv = String::new();
    for (t, per_brdf) in results.iter().enumerate() {
        for (bi, tr) in per_brdf.iter().enumerate() {
            for (k, name) in tr.names.iter().enumerate() {
                for (ni, n) in NS.iter().enumerate() {
                    for (e, est) in ESTIMATORS.iter().enumerate() {
                        let v = tr.rel[k][ni][e];
                        if v.is_finite() {
                            let _ = writeln!(
                                csv,
                                "renderer,{},{est},{n},{},{name},{v:.6e}",
                                TIERS[t],
                                BRDFS[bi].name()
                            );
                        }
                    }
                }
            }
        }
    }
    if let Some(path) = &o.csv {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(path, &csv)?;
        eprintln!("wrote {}", path.display());
    }

    // Markdown.
    let mut md = String::new();
    md.push_str("# Renderer benchmark: BMC and QMC shading integrals on environment maps\n\n");
    md.push_str(
        "@generated by `eval/src/bin/renderer.rs` (issue #12, item 6); do not edit by hand.\n\n",
    );
    let command = if o.args.is_empty() {
        "cargo eval renderer".to_string()
    } else {
        format!("cargo eval renderer -- {}", o.args.join(" "))
    };
    let _ = writeln!(
        md,
        "## Run\n\n- Command: `{command}` ({seconds:.0} s wall, {} threads).",
        o.threads
    );
    for (name, (a, b, c)) in &timings {
        let _ = writeln!(md, "  - {name}: ground truth {a:.1} s, sample sets and BMC weights {b:.1} s, estimates {c:.1} s.");
    }
    let held: Vec<&str> =
        names.iter().map(String::as_str).filter(|n| !TRAINING_MAPS.contains(n)).collect();
    let _ = writeln!(
        md,
        "- Maps: {}; held out (not used to learn the hyperparameters): {}. Synthetic: {} mixtures (seed {SEED_SYNTHETIC:#X}).",
        names.join(", "),
        if held.is_empty() { "none (means over all maps)".into() } else { held.join(", ") },
        o.mixtures
    );
    let _ = writeln!(
        md,
        "- {} seeded queries per map (seed {SEED_QUERIES:#X}), one draw each; bmc-sobol on {} of them{}.",
        queries.len(),
        queries.len().min(o.sobol_queries),
        match failures.load(Ordering::Relaxed) {
            0 => String::new(),
            f => format!(" ({f} solves failed: Q not positive definite)"),
        }
    );
    let _ = writeln!(
        md,
        "- Hyperparameters: `{}` rows of `{}` (l, σ′ per key and N):",
        o.hyper_method,
        o.hyper_file.strip_prefix(root).unwrap_or(&o.hyper_file).display()
    );
    md.push_str("\n| key | N = 16 | 32 | 64 | 80 | 128 |\n| --- | --- | --- | --- | --- | --- |\n");
    for (key, _, _) in KEYS {
        let cells: Vec<String> = NS
            .iter()
            .map(|&n| {
                h.get(&(key.to_string(), n))
                    .map_or("—".into(), |p| format!("{}, {}", fmt_g(p.l), p.sigma))
            })
            .collect();
        let _ = writeln!(md, "| {key} | {} |", cells.join(" | "));
    }
    md.push('\n');
    md.push_str(
        "- Ground truth: maps, every pixel with per-pixel weights (diffuse: \
         `reference::truth::cosine_weights`, exact; Phong × cosine: adaptive k×k sub-grid \
         midpoint rule per pixel, `renderer_engine::phong_cos_weights`); synthetic: exact \
         irradiance, and the lobe-frame rule at double density for Phong.\n\n",
    );
    targets(&mut md, &results);
    crate_table(&mut md, &results);
    seed_table(&mut md, &results);
    selection_table(&mut md, &results);
    tier_tables(&mut md, &results);
    md.push_str("![relative RMSE against N, means over held-out maps](renderer.png)\n");

    std::fs::create_dir_all(&o.out)?;
    std::fs::write(o.out.join("renderer.md"), &md)?;
    register_font("sans-serif", FontStyle::Normal, ttf_noto_sans::REGULAR)
        .map_err(|_| "the embedded font did not parse")?;
    plot(&results, &o.out.join("renderer.png"))?;
    print!("{md}");
    eprintln!("wrote {} ({seconds:.1} s)", o.out.join("renderer.md").display());
    Ok(())
}
