//! The probe-trust benchmark's engine (`src/bin/probe_trust.rs`, whose module docs describe
//! it): an independent f64 Gaussian-process engine, the member-choice rules and the error-bar
//! calibration measured per map, tier and size, and the report. The calibration factors a run
//! fits are what `cargo writer probe_calibration` writes to `tables/probe.txt`.

use crate::{cli, compare, parallel, tiers};

use std::error::Error;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::PathBuf;

use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use reference::sh::real_sh;

/// Legendre degrees of every kernel series.
const DEGREES: usize = 256;
/// Nodes of the `z` tables (linear interpolation).
const TABLE: usize = 4097;
/// Query kinds: 0 = irradiance, otherwise the Phong exponent.
const KINDS: [f64; 4] = [0.0, 5.0, 20.0, 100.0];
const KIND_NAMES: [&str; 4] = ["irradiance", "glossy-5", "glossy-20", "glossy-100"];
const TIERS: [&str; 2] = ["clamp", "smooth"];
/// Sizes of the member-choice comparison and of the calibration.
const CHOICE_NS: [usize; 3] = [16, 32, 64];
const ALL_NS: [usize; 5] = [16, 32, 64, 128, 256];
/// The coverage the calibration aims at on the training maps.
const QUANTILE: f64 = 0.95;
/// Fewer training queries than this for a member: it takes the size's pooled factor.
const MIN_QUERIES: usize = 256;
const SEED: u64 = 0x7157_0001;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kernel {
    /// Squared exponential `exp(λ(t − 1))`.
    Se(f64),
    /// Power-law spectrum `(1 + l(l + 1)/κ²)^(−s)`.
    Power { kappa: f64, s: f64 },
}

impl Kernel {
    fn name(self) -> String {
        match self {
            Kernel::Se(l) => format!("SE λ={l}"),
            Kernel::Power { kappa, s } => format!("power κ={kappa} s={s}"),
        }
    }
}

/// One model: kernel, nugget, and the candidate sets it belongs to (bit mask of `SET_*`).
#[derive(Clone, Copy, Debug)]
struct Model {
    kernel: Kernel,
    sigma: f64,
    /// Member of the baked family (index), if it is one.
    family: Option<usize>,
    sets: u32,
}

const SET_FAMILY: u32 = 1;
const SET_LADDER: u32 = 2;
const SET_GRID: u32 = 4;
const SET_POWER6: u32 = 8;
const SET_POWER4: u32 = 16;

/// The selection rules compared in part 1.
const RULES: [&str; 10] = [
    "reml",
    "loo-lpd",
    "loo-mse",
    "bma",
    "reml-ladder7",
    "reml-nugget",
    "reml-power",
    "reml-se+power",
    "reml-power-k4",
    "oracle",
];
/// The candidate set each rule searches (the BMA and the oracle: the family).
const RULE_SETS: [u32; 10] = [
    SET_FAMILY,
    SET_FAMILY,
    SET_FAMILY,
    SET_FAMILY,
    SET_LADDER,
    SET_GRID,
    SET_POWER6,
    SET_FAMILY | SET_POWER6,
    SET_POWER4,
    SET_FAMILY,
];
const ORACLE: usize = 9;
const RULE_NOTES: [&str; 10] = [
    "argmax of the REML likelihood over the baked family (the crate's rule)",
    "argmax of the leave-one-out log predictive density (closed form from Q⁻¹), baked family",
    "argmin of the leave-one-out squared error, baked family",
    "Bayesian model average over the baked family, weights ∝ exp(ℓ)",
    "REML over λ = 1, 2, 4, …, 64 (seven rungs), the family's σ′",
    "REML over λ ∈ {1, 4, 16, 64} × σ′ ∈ {0.03, 0.1, 0.3, 1} and the family: a nugget per probe",
    "REML over six power-law kernels, κ ∈ {1, 3, 10} × s ∈ {1.5, 2.5}, the family's σ′",
    "REML over the baked family and the six power-law kernels",
    "REML over five power-law kernels, κ = 4 × s ∈ {1.25, 1.5, 2, 3, 5} (the best κ of a sweep over 0.5–8), the family's σ′",
    "the family member of least error for this probe and query (knows the truth: a bound)",
];

/// A `probe = N sigma λ…` line of `tables/probe.txt`: a size's family.
pub struct Family {
    pub n: usize,
    pub sigma: f64,
    pub lambdas: Vec<f64>,
}

/// `probe = N sigma λ…` lines of `tables/probe.txt`, and its `calibration = N λ c…` lines.
/// A `calibration = N λ c…` line.
type CalibrationLine = (usize, f64, [f64; 4]);

/// One size's models and its cells per map and tier.
pub type SizeResult = (usize, Vec<Prepared>, Vec<[Vec<Cell>; 2]>);

/// Per query kind, per axis, per pixel: the truth weights of one grid.
type GridWeights = Vec<Vec<Vec<f64>>>;

fn read_table(text: &str) -> Result<(Vec<Family>, Vec<CalibrationLine>), String> {
    let mut families = Vec::new();
    let mut calibration = Vec::new();
    for line in text.lines() {
        let line = line.split('#').next().unwrap_or("").trim();
        let Some((key, rest)) = line.split_once('=') else { continue };
        if !matches!(key.trim(), "probe" | "calibration") {
            continue;
        }
        let nums: Result<Vec<f64>, _> = rest.split_whitespace().map(str::parse).collect();
        let nums = nums.map_err(|e| format!("tables/probe.txt: `{line}`: {e}"))?;
        match key.trim() {
            "probe" if nums.len() >= 3 => families.push(Family {
                n: nums[0] as usize,
                sigma: nums[1],
                lambdas: nums[2..].to_vec(),
            }),
            "calibration" if nums.len() == 6 => {
                calibration.push((nums[0] as usize, nums[1], [nums[2], nums[3], nums[4], nums[5]]))
            }
            _ => {}
        }
    }
    Ok((families, calibration))
}

fn models_for(family: &Family, candidates: bool) -> Vec<Model> {
    let mut models: Vec<Model> = family
        .lambdas
        .iter()
        .enumerate()
        .map(|(k, &l)| Model {
            kernel: Kernel::Se(l),
            sigma: family.sigma,
            family: Some(k),
            sets: SET_FAMILY | SET_LADDER | SET_GRID,
        })
        .collect();
    if !candidates {
        return models;
    }
    let mut push = |kernel: Kernel, sigma: f64, sets: u32| {
        if let Some(old) = models.iter_mut().find(|o| o.kernel == kernel && o.sigma == sigma) {
            old.sets |= sets;
        } else {
            models.push(Model { kernel, sigma, family: None, sets });
        }
    };
    for l in [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0] {
        push(Kernel::Se(l), family.sigma, SET_LADDER);
    }
    for l in [1.0, 4.0, 16.0, 64.0] {
        for s in [0.03, 0.1, 0.3, 1.0] {
            push(Kernel::Se(l), s, SET_GRID);
        }
    }
    for (kappa, s) in [(1.0, 1.5), (3.0, 1.5), (10.0, 1.5), (1.0, 2.5), (3.0, 2.5), (10.0, 2.5)] {
        push(Kernel::Power { kappa, s }, family.sigma, SET_POWER6);
    }
    for s in [1.25, 1.5, 2.0, 3.0, 5.0] {
        push(Kernel::Power { kappa: 4.0, s }, family.sigma, SET_POWER4);
    }
    models
}

/// Gauss–Legendre nodes and weights on `[a, b]`.
fn gauss(n: usize, a: f64, b: f64) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 1..n {
                    let p2 = ((2 * k + 1) as f64 * x * p1 - k as f64 * p0) / (k + 1) as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            (0.5 * (a + b) + 0.5 * (b - a) * x, 0.5 * (b - a) * w)
        })
        .collect()
}

fn legendre_all(t: f64, out: &mut [f64]) {
    if let Some(p) = out.first_mut() {
        *p = 1.0;
    }
    if let Some(p) = out.get_mut(1) {
        *p = t;
    }
    for l in 1..out.len().saturating_sub(1) {
        out[l + 1] = ((2 * l + 1) as f64 * t * out[l] - l as f64 * out[l - 1]) / (l + 1) as f64;
    }
}

/// `Σ c_l (2l + 1)/(4π)·P_l(t)`.
fn series(c: &[f64], t: f64, p: &mut [f64]) -> f64 {
    legendre_all(t, p);
    c.iter()
        .zip(p.iter())
        .enumerate()
        .map(|(l, (c, p))| c * (2 * l + 1) as f64 / (4.0 * PI) * p)
        .sum()
}

/// The kernel's `a_l`, normalised to `k(1) = 1`.
fn kernel_coefficients(k: Kernel, gl: &[(f64, f64)]) -> Vec<f64> {
    let mut a = vec![0.0; DEGREES];
    match k {
        Kernel::Se(lambda) => {
            let mut p = vec![0.0; DEGREES];
            for &(t, w) in gl {
                legendre_all(t, &mut p);
                let f = (lambda * (t - 1.0)).exp();
                for (a, p) in a.iter_mut().zip(&p) {
                    *a += 2.0 * PI * w * f * p;
                }
            }
        }
        Kernel::Power { kappa, s } => {
            for (l, a) in a.iter_mut().enumerate() {
                *a = (1.0 + (l * (l + 1)) as f64 / (kappa * kappa)).powf(-s);
            }
        }
    }
    let k1: f64 = a.iter().enumerate().map(|(l, a)| a * (2 * l + 1) as f64 / (4.0 * PI)).sum();
    a.iter_mut().for_each(|x| *x /= k1);
    a
}

/// The query's weight function: `max(0, t)` for irradiance, `(e + 1)/(2π)·max(0, t)ᵉ`.
fn weight(kind: f64, t: f64) -> f64 {
    if t <= 0.0 {
        0.0
    } else if kind == 0.0 {
        t
    } else {
        (kind + 1.0) / (2.0 * PI) * t.powf(kind)
    }
}

/// Funk–Hecke gains `Λ_l = 2π∫ weight(t)·P_l(t) dt`.
fn gains(kind: f64, gl01: &[(f64, f64)]) -> Vec<f64> {
    let mut g = vec![0.0; DEGREES];
    let mut p = vec![0.0; DEGREES];
    for &(t, w) in gl01 {
        legendre_all(t, &mut p);
        let f = weight(kind, t);
        for (g, p) in g.iter_mut().zip(&p) {
            *g += 2.0 * PI * w * f * p;
        }
    }
    g
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A model prepared for one point set: `Q⁻¹`, its GLS pieces and a `z` table per query kind.
pub struct Prepared {
    model: Model,
    qinv: Vec<f64>,
    qinv1: Vec<f64>,
    s1: f64,
    logdet: f64,
    pdiag: Vec<f64>,
    /// Per kind: `z(t)` on [−1, 1], `V̄`, `∫ weight`.
    tables: Vec<(Vec<f64>, f64, f64)>,
}

fn prepare(
    model: Model,
    pts: &[[f64; 3]],
    kind_gains: &[Vec<f64>],
    gl: &[(f64, f64)],
) -> Result<Prepared, String> {
    let n = pts.len();
    let a = kernel_coefficients(model.kernel, gl);
    let mut p = vec![0.0; DEGREES];
    let mut q = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            let t = dot(pts[i], pts[j]).clamp(-1.0, 1.0);
            let k = match model.kernel {
                Kernel::Se(lambda) => (lambda * (t - 1.0)).exp(),
                Kernel::Power { .. } => series(&a, t, &mut p),
            };
            q[i * n + j] = k + if i == j { model.sigma * model.sigma } else { 0.0 };
        }
    }
    // Cholesky, then the inverse column by column.
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let s = q[i * n + j] - (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum::<f64>();
            if i == j {
                if s <= 0.0 {
                    return Err(format!(
                        "{} σ′ = {}: Q not positive definite",
                        model.kernel.name(),
                        model.sigma
                    ));
                }
                l[i * n + i] = s.sqrt();
            } else {
                l[i * n + j] = s / l[j * n + j];
            }
        }
    }
    let logdet = 2.0 * (0..n).map(|i| l[i * n + i].ln()).sum::<f64>();
    let mut qinv = vec![0.0; n * n];
    for c in 0..n {
        let mut x = vec![0.0; n];
        x[c] = 1.0;
        for i in 0..n {
            let s: f64 = (0..i).map(|k| l[i * n + k] * x[k]).sum();
            x[i] = (x[i] - s) / l[i * n + i];
        }
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|k| l[k * n + i] * x[k]).sum();
            x[i] = (x[i] - s) / l[i * n + i];
        }
        for (i, x) in x.iter().enumerate() {
            qinv[i * n + c] = *x;
        }
    }
    let qinv1: Vec<f64> = (0..n).map(|i| qinv[i * n..(i + 1) * n].iter().sum()).collect();
    let s1: f64 = qinv1.iter().sum();
    let pdiag = (0..n).map(|i| qinv[i * n + i] - qinv1[i] * qinv1[i] / s1).collect();
    let tables = kind_gains
        .iter()
        .map(|g| {
            let c: Vec<f64> = a.iter().zip(g).map(|(a, g)| a * g).collect();
            let table = (0..TABLE)
                .map(|k| series(&c, -1.0 + 2.0 * k as f64 / (TABLE - 1) as f64, &mut p))
                .collect();
            let vbar = a
                .iter()
                .zip(g)
                .enumerate()
                .map(|(l, (a, g))| a * g * g * (2 * l + 1) as f64 / (4.0 * PI))
                .sum();
            (table, vbar, g[0])
        })
        .collect();
    Ok(Prepared { model, qinv, qinv1, s1, logdet, pdiag, tables })
}

fn lookup(table: &[f64], t: f64) -> f64 {
    let u = (t.clamp(-1.0, 1.0) + 1.0) * 0.5 * (TABLE - 1) as f64;
    let k = (u as usize).min(TABLE - 2);
    let f = u - k as f64;
    table[k] * (1.0 - f) + table[k + 1] * f
}

/// One model's fit to one probe's samples.
struct Fit {
    alpha: Vec<f64>,
    beta: f64,
    /// REML log likelihood (σ_f profiled), LOO log predictive density, LOO mean squared error.
    ll: f64,
    lpd: f64,
    mse: f64,
    /// `σ̂_f² = rᵀQ⁻¹r/(N − 1)`.
    s2: f64,
}

fn fit(pr: &Prepared, y: &[f64]) -> Fit {
    let n = y.len();
    let qy: Vec<f64> = (0..n)
        .map(|i| pr.qinv[i * n..(i + 1) * n].iter().zip(y).map(|(a, b)| a * b).sum())
        .collect();
    let beta = qy.iter().sum::<f64>() / pr.s1;
    let alpha: Vec<f64> = qy.iter().zip(&pr.qinv1).map(|(q, o)| q - beta * o).collect();
    let quad = alpha.iter().zip(y).map(|(a, y)| a * y).sum::<f64>().max(1e-300);
    let s2 = quad / (n - 1) as f64;
    let ll = -0.5 * pr.logdet - 0.5 * pr.s1.ln() - 0.5 * (n - 1) as f64 * quad.ln();
    let (mut lpd, mut mse) = (0.0, 0.0);
    for (a, p) in alpha.iter().zip(&pr.pdiag) {
        let e = a / p;
        let v = s2 / p;
        mse += e * e / n as f64;
        lpd += -0.5 * v.ln() - 0.5 * e * e / v;
    }
    Fit { alpha, beta, ll, lpd, mse, s2 }
}

/// Sums of one (tier, map, N, kind) cell.
#[derive(Clone, Default)]
pub struct Cell {
    /// Σ squared error per rule, then lobe-avg, SH L2.
    se: Vec<f64>,
    abs_truth: f64,
    count: usize,
    /// Calibration data: (member, |error|/σ_raw) per query of the crate's rule.
    z: Vec<(usize, f64)>,
}

/// One map: its name, whether it is a training map, its `clamp` and `smooth` tiers.
pub struct MapJob {
    pub name: String,
    pub training: bool,
    pub tiers: [EnvMap; 2],
}

/// What a run measures: the maps, which of them train, and the sampling.
pub struct Setup {
    pub maps: Vec<PathBuf>,
    /// Training map stems.
    pub train: Vec<String>,
    /// Random probe rotations per map.
    pub rotations: usize,
    /// Query axes per map.
    pub normals: usize,
    /// N = 16 and 32 only.
    pub quick: bool,
    pub threads: usize,
}

/// A run: the table it read, the maps, every size's models and cells, and the calibration
/// factors per size and member (fitted on the training maps, or those of `tables/probe.txt`
/// when there are none).
pub struct Run {
    /// `tables/probe.txt` as read.
    pub table_text: String,
    pub families: Vec<Family>,
    pub jobs: Vec<MapJob>,
    pub results: Vec<SizeResult>,
    /// Per size: per family member, the factor per query kind.
    pub factors: Vec<(usize, Vec<[f64; 4]>)>,
    pub any_training: bool,
    pub any_held: bool,
}

pub fn run(setup: &Setup) -> Result<Run, Box<dyn Error>> {
    let start = std::time::Instant::now();
    let table_path = cli::repo_root().join("tables/probe.txt");
    let table_text = std::fs::read_to_string(&table_path)?;
    let (families, baked_calibration) = read_table(&table_text)?;
    let threads = setup.threads;
    let jobs: Vec<MapJob> = parallel::parallel_map(&setup.maps, threads, |_, path| {
        let map = EnvMap::load(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let clamp = compare::clamped(&map);
        let smooth = tiers::smooth(&clamp);
        let name = cli::map_name(path);
        Ok::<_, String>(MapJob {
            training: setup.train.contains(&name),
            name,
            tiers: [clamp, smooth],
        })
    })
    .into_iter()
    .collect::<Result<_, _>>()?;
    let any_training = jobs.iter().any(|j| j.training);
    let any_held = jobs.iter().any(|j| !j.training);
    let mut rng = Rng::new(SEED);
    let axes: Vec<[f64; 3]> = (0..setup.normals).map(|_| rng.uniform_sphere()).collect();
    let rotations: Vec<[[f64; 3]; 3]> =
        (0..setup.rotations).map(|_| rng.uniform_rotation()).collect();
    let gl = gauss(400, -1.0, 1.0);
    let gl01 = gauss(400, 0.0, 1.0);
    let kind_gains: Vec<Vec<f64>> = KINDS.iter().map(|&k| gains(k, &gl01)).collect();
    // Truth weights for both grids (the smooth tier is 128×64).
    let kinds: Vec<compare::Kind> = KINDS
        .iter()
        .map(|&k| if k == 0.0 { compare::Kind::Diffuse } else { compare::Kind::Glossy(k) })
        .collect();
    let mut truths: Vec<[Vec<Vec<f64>>; 2]> = Vec::new();
    {
        let grids: Vec<(usize, usize)> =
            jobs.iter().flat_map(|j| j.tiers.iter().map(|m| (m.width, m.height))).collect();
        let mut cache: Vec<((usize, usize), GridWeights)> = Vec::new();
        for g in grids {
            if !cache.iter().any(|(c, _)| *c == g) {
                cache.push((
                    g,
                    kinds.iter().map(|&k| compare::weights(k, &axes, g.0, g.1)).collect(),
                ));
            }
        }
        for j in &jobs {
            truths.push(std::array::from_fn(|t| {
                let m = &j.tiers[t];
                let w = &cache.iter().find(|(c, _)| *c == (m.width, m.height)).expect("cached").1;
                w.iter().map(|wk| compare::truths(m, wk)).collect()
            }));
        }
    }
    let ns: Vec<usize> = if setup.quick { vec![16, 32] } else { ALL_NS.to_vec() };
    let mut results: Vec<SizeResult> = Vec::new();
    for &n in &ns {
        let Some(family) = families.iter().find(|f| f.n == n) else {
            return Err(format!("tables/probe.txt has no `probe = {n} …` line").into());
        };
        let candidates = CHOICE_NS.contains(&n);
        let base: Vec<[f64; 3]> = sphere_quadrature::FibonacciPoints::sphere(n)?
            .iter()
            .map(|p| [p.x as f64, p.y as f64, p.z as f64])
            .collect();
        let models = models_for(family, candidates);
        let prepared: Vec<Prepared> =
            parallel::parallel_map(&models, threads, |_, &m| prepare(m, &base, &kind_gains, &gl))
                .into_iter()
                .collect::<Result<_, _>>()?;
        let items: Vec<(usize, usize)> = (0..jobs.len()).flat_map(|j| [(j, 0), (j, 1)]).collect();
        let cells: Vec<Vec<Cell>> = parallel::parallel_map(&items, threads, |_, &(j, tier)| {
            probe_cells(
                &jobs[j].tiers[tier],
                &truths[j][tier],
                &base,
                &rotations,
                &axes,
                &prepared,
                &kind_gains,
                candidates,
            )
        });
        let mut per_map: Vec<[Vec<Cell>; 2]> = Vec::new();
        let mut it = cells.into_iter();
        for _ in &jobs {
            let clamp = it.next().unwrap_or_default();
            let smooth = it.next().unwrap_or_default();
            per_map.push([clamp, smooth]);
        }
        eprintln!("N = {n}: {:.0} s", start.elapsed().as_secs_f64());
        results.push((n, prepared, per_map));
    }
    // Calibration: fitted on the training maps, or read from tables/probe.txt.
    let mut factors: Vec<(usize, Vec<[f64; 4]>)> = Vec::new();
    for (n, prepared, per_map) in &results {
        let members = prepared.iter().filter(|p| p.model.family.is_some()).count();
        let f: Vec<[f64; 4]> = if any_training {
            let mut out = vec![[1.0; 4]; members];
            for kind in 0..KINDS.len() {
                let all: Vec<(usize, f64)> = jobs
                    .iter()
                    .zip(per_map)
                    .filter(|(j, _)| j.training)
                    .flat_map(|(_, cells)| {
                        cells.iter().flat_map(move |c| c[kind].z.iter().copied())
                    })
                    .collect();
                let pooled = factor(all.iter().map(|&(_, z)| z).collect());
                for (k, o) in out.iter_mut().enumerate() {
                    let mine: Vec<f64> =
                        all.iter().filter(|(m, _)| *m == k).map(|&(_, z)| z).collect();
                    o[kind] = if mine.len() >= MIN_QUERIES { factor(mine) } else { pooled };
                }
            }
            out
        } else {
            let fam = families.iter().find(|f| f.n == *n).map_or(&[][..], |f| &f.lambdas[..]);
            fam.iter()
                .map(|&l| {
                    baked_calibration
                        .iter()
                        .find(|(cn, cl, _)| cn == n && *cl == l)
                        .map_or([1.0; 4], |(_, _, c)| *c)
                })
                .collect()
        };
        factors.push((*n, f));
    }
    Ok(Run { table_text, families, jobs, results, factors, any_training, any_held })
}

/// `c` with the `QUANTILE` of `z/√c` at 2: `(q/2)²`.
fn factor(mut z: Vec<f64>) -> f64 {
    if z.is_empty() {
        return 1.0;
    }
    z.sort_by(f64::total_cmp);
    let q = z[((z.len() as f64 * QUANTILE).ceil() as usize).clamp(1, z.len()) - 1];
    (q / 2.0).powi(2)
}

/// All cells of one (map, tier) at one N: per kind.
#[allow(clippy::too_many_arguments)]
fn probe_cells(
    map: &EnvMap,
    truth: &[Vec<f64>],
    base: &[[f64; 3]],
    rotations: &[[[f64; 3]; 3]],
    axes: &[[f64; 3]],
    prepared: &[Prepared],
    kind_gains: &[Vec<f64>],
    candidates: bool,
) -> Vec<Cell> {
    let n = base.len();
    let rules = if candidates { RULES.len() } else { 1 };
    let mut cells = vec![Cell { se: vec![0.0; rules + 2], ..Cell::default() }; KINDS.len()];
    let family: Vec<usize> =
        (0..prepared.len()).filter(|&i| prepared[i].model.family.is_some()).collect();
    let sets: Vec<Vec<usize>> = RULE_SETS
        .iter()
        .map(|&m| (0..prepared.len()).filter(|&i| prepared[i].model.sets & m != 0).collect())
        .collect();
    let argmax = |set: &[usize], score: &dyn Fn(usize) -> f64| -> usize {
        set.iter()
            .copied()
            .fold(None, |b: Option<usize>, i| match b {
                Some(j) if score(j) >= score(i) => Some(j),
                _ => Some(i),
            })
            .unwrap_or(0)
    };
    for rot in rotations {
        let pts: Vec<[f64; 3]> =
            base.iter().map(|p| [dot(rot[0], *p), dot(rot[1], *p), dot(rot[2], *p)]).collect();
        let y: Vec<f64> = pts.iter().map(|&d| luminance(map.radiance(d))).collect();
        let fits: Vec<Fit> = prepared.iter().map(|p| fit(p, &y)).collect();
        let reml = argmax(&family, &|i| fits[i].ll);
        // Rule → chosen model (None: the BMA or the oracle, handled per query).
        let chosen: Vec<Option<usize>> = if candidates {
            (0..RULES.len())
                .map(|r| match r {
                    1 => Some(argmax(&family, &|i| fits[i].lpd)),
                    2 => Some(argmax(&family, &|i| -fits[i].mse)),
                    3 | ORACLE => None,
                    _ => Some(argmax(&sets[r], &|i| fits[i].ll)),
                })
                .collect()
        } else {
            vec![Some(reml)]
        };
        let top = family.iter().map(|&i| fits[i].ll).fold(f64::NEG_INFINITY, f64::max);
        let bma: Vec<(usize, f64)> =
            family.iter().map(|&i| (i, (fits[i].ll - top).exp())).collect();
        let bma_total: f64 = bma.iter().map(|b| b.1).sum();
        let coef: [f64; 9] = std::array::from_fn(|i| {
            4.0 * PI / n as f64 * pts.iter().zip(&y).map(|(&d, y)| y * sh(i, d)).sum::<f64>()
        });
        for (kind, cell) in cells.iter_mut().enumerate() {
            let g = &kind_gains[kind];
            // The oracle is chosen per probe (over all axes) for this kind.
            let mut estimates: Vec<Vec<f64>> = Vec::with_capacity(axes.len());
            let mut reml_var = Vec::with_capacity(axes.len());
            for (qi, &ax) in axes.iter().enumerate() {
                let t: Vec<f64> = pts.iter().map(|&p| dot(p, ax)).collect();
                let w: Vec<f64> = t.iter().map(|&t| weight(KINDS[kind], t)).collect();
                let wsum: f64 = w.iter().sum();
                let lobe = if wsum > 0.0 {
                    g[0] * w.iter().zip(&y).map(|(w, y)| w * y).sum::<f64>() / wsum
                } else {
                    0.0
                };
                let shl2: f64 = (0..9).map(|i| g[band(i)] * coef[i] * sh(i, ax)).sum();
                let truth = truth[kind][qi];
                let est_of = |i: usize| {
                    let (table, _, integral) = &prepared[i].tables[kind];
                    integral * fits[i].beta
                        + t.iter()
                            .zip(&fits[i].alpha)
                            .map(|(&t, a)| lookup(table, t) * a)
                            .sum::<f64>()
                };
                let ests: Vec<f64> = (0..prepared.len())
                    .map(|i| if candidates || i == reml { est_of(i) } else { 0.0 })
                    .collect();
                // Raw REML error bar of the crate's rule.
                let pr = &prepared[reml];
                let (table, vbar, integral) = &pr.tables[kind];
                let z: Vec<f64> = t.iter().map(|&t| lookup(table, t)).collect();
                let mut quad = 0.0;
                for i in 0..n {
                    quad += z[i]
                        * pr.qinv[i * n..(i + 1) * n]
                            .iter()
                            .zip(&z)
                            .map(|(a, b)| a * b)
                            .sum::<f64>();
                }
                let one: f64 = pr.qinv1.iter().zip(&z).map(|(a, b)| a * b).sum();
                let unit = (vbar - quad + (integral - one).powi(2) / pr.s1).max(0.0);
                let var = fits[reml].s2 * unit;
                let member = pr.model.family.unwrap_or(0);
                let err = ests[reml] - truth;
                cell.z.push((
                    member,
                    if var > 0.0 {
                        err.abs() / var.sqrt()
                    } else if err == 0.0 {
                        0.0
                    } else {
                        f64::INFINITY
                    },
                ));
                reml_var.push(var);
                cell.se[rules] += (lobe - truth).powi(2);
                cell.se[rules + 1] += (shl2 - truth).powi(2);
                cell.abs_truth += truth.abs();
                cell.count += 1;
                let mut row = Vec::with_capacity(rules);
                for (r, c) in chosen.iter().enumerate() {
                    let e = match (c, r) {
                        (Some(i), _) => ests[*i],
                        (None, 3) => bma.iter().map(|&(i, w)| w * ests[i]).sum::<f64>() / bma_total,
                        _ => f64::NAN,
                    };
                    row.push(e - truth);
                }
                row.extend(family.iter().map(|&i| ests[i] - truth));
                estimates.push(row);
            }
            // Oracle: the family member of least squared error over this probe's axes.
            let oracle = if candidates {
                (0..family.len())
                    .map(|k| estimates.iter().map(|r| r[rules + k].powi(2)).sum::<f64>())
                    .enumerate()
                    .min_by(|a, b| a.1.total_cmp(&b.1))
                    .map_or(0, |(k, _)| k)
            } else {
                0
            };
            for row in &estimates {
                for r in 0..rules {
                    let e = if candidates && r == ORACLE { row[rules + oracle] } else { row[r] };
                    cell.se[r] += e * e;
                }
            }
        }
    }
    cells
}

fn band(i: usize) -> usize {
    match i {
        0 => 0,
        1..=3 => 1,
        _ => 2,
    }
}

fn sh(i: usize, d: [f64; 3]) -> f64 {
    let l = band(i);
    real_sh(l, i as i64 - (l * (l + 1)) as i64, d)
}

/// Relative RMSE of a cell's estimator `e`.
fn rel(c: &Cell, e: usize) -> f64 {
    (c.se[e] / c.count as f64).sqrt() / (c.abs_truth / c.count as f64)
}

/// Mean of per-map ratios, ratio of means, worst map (name, ratio) of estimator `e` against
/// the smaller peer per map, over the maps selected by `keep`.
fn stats(cells: &[(&str, &Cell)], e: usize) -> (f64, f64, String, f64) {
    let rules = cells[0].1.se.len() - 2;
    let mut ratios = Vec::new();
    let (mut num, mut den) = (0.0, 0.0);
    for (name, c) in cells {
        let peer = rel(c, rules).min(rel(c, rules + 1));
        let mine = rel(c, e);
        ratios.push((name.to_string(), mine / peer));
        num += mine;
        den += peer;
    }
    let mean = ratios.iter().map(|r| r.1).sum::<f64>() / ratios.len() as f64;
    let worst = ratios.iter().cloned().max_by(|a, b| a.1.total_cmp(&b.1)).unwrap_or_default();
    (mean, num / den, worst.0, worst.1)
}

fn coverage(cell: &Cell, factors: &[[f64; 4]], kind: usize, calibrated: bool) -> f64 {
    let hits = cell
        .z
        .iter()
        .filter(|(m, z)| {
            let c = if calibrated { factors.get(*m).map_or(1.0, |f| f[kind]) } else { 1.0 };
            *z <= 2.0 * c.sqrt()
        })
        .count();
    hits as f64 / cell.z.len().max(1) as f64
}

/// The report (Markdown) of a run that took `secs`.
pub fn render(setup: &Setup, run: &Run, secs: f64) -> String {
    let Run { jobs, results, factors, families, any_training, any_held, .. } = run;
    let (any_training, any_held) = (*any_training, *any_held);
    let mut md = String::new();
    let held: Vec<&str> = jobs.iter().filter(|j| !j.training).map(|j| j.name.as_str()).collect();
    let train: Vec<&str> = jobs.iter().filter(|j| j.training).map(|j| j.name.as_str()).collect();
    let _ = writeln!(md, "# Probe trust: member choice and error-bar calibration (issue #13)\n");
    let _ = writeln!(
        md,
        "Generated by `cargo eval probe_trust{}` ({} rotations × {} axes per map and tier; {:.0} s). \
         Luminance probes of the sphere SF set, an independent f64 Gaussian-process engine; see the program's docs.\n",
        if setup.quick { " -- --quick" } else { "" },
        setup.rotations,
        setup.normals,
        secs
    );
    let _ = writeln!(md, "Training maps: {}. Held-out maps: {}.\n", list(&train), list(&held));
    let scope: Vec<usize> = (0..jobs.len()).filter(|&j| !jobs[j].training || !any_held).collect();
    let scope_name = if any_held { "held-out maps" } else { "all maps (none held out)" };
    let _ = writeln!(md, "## 1. Member choice\n");
    let _ = writeln!(
        md,
        "Per map, the rule's relative RMSE over the smaller of the two peers' (cosine- or lobe-weighted average, SH L2) \
         on the same samples; `mean` is the mean of the per-map ratios, `of means` the ratio of the mean errors, then \
         the worst map, over the {scope_name}. Below 1 the rule beats both peers.\n"
    );
    for (r, note) in RULES.iter().zip(RULE_NOTES) {
        let _ = writeln!(md, "- `{r}`: {note}.");
    }
    let _ = writeln!(md);
    for (tier, tier_name) in TIERS.iter().enumerate() {
        for (kind, kind_name) in KIND_NAMES.iter().enumerate() {
            let rows: Vec<(usize, Vec<(&str, &Cell)>)> = results
                .iter()
                .filter(|(n, _, _)| CHOICE_NS.contains(n))
                .map(|(n, _, per_map)| {
                    (
                        *n,
                        scope
                            .iter()
                            .map(|&j| (jobs[j].name.as_str(), &per_map[j][tier][kind]))
                            .collect(),
                    )
                })
                .collect();
            if rows.is_empty() || rows[0].1.is_empty() {
                continue;
            }
            let _ = writeln!(md, "### `{tier_name}`, {kind_name}\n");
            let _ = write!(md, "| rule |");
            for (n, _) in &rows {
                let _ = write!(md, " N = {n}: mean | of means | worst |");
            }
            let _ = writeln!(md);
            let _ = writeln!(md, "|---|{}", "---|---|---|".repeat(rows.len()));
            for (r, rule) in RULES.iter().enumerate() {
                let _ = write!(md, "| `{rule}` |");
                for (_, cells) in &rows {
                    let (mean, of_means, worst, w) = stats(cells, r);
                    let _ = write!(md, " {mean:.3} | {of_means:.3} | {w:.2} {worst} |");
                }
                let _ = writeln!(md);
            }
            let _ = writeln!(md);
        }
    }
    let _ = writeln!(md, "## 2. Error-bar calibration\n");
    if any_training {
        let _ = writeln!(
            md,
            "The crate's rule (`reml`) with its raw REML bar `2√(σ̂_f²·v(n))` (exact unit variance) and with the \
             calibrated bar `2√(c·σ̂_f²·v(n))`: `c` per size, member and query is `(q/2)²` with `q` the {:.0} % \
             quantile of |error|/σ over the training maps' queries that chose the member, both tiers pooled (a member \
             chosen by fewer than {MIN_QUERIES} training queries takes the size's pooled factor). Coverage over the {scope_name}.\n",
            QUANTILE * 100.0
        );
    } else {
        let _ = writeln!(
            md,
            "No training maps: the factors baked in `tables/probe.txt` are checked, not fitted.\n"
        );
    }
    let _ = writeln!(md, "| N | member λ | irradiance | glossy-5 | glossy-20 | glossy-100 |\n|---|---|---|---|---|---|");
    for (n, f) in factors {
        let lambdas = families.iter().find(|x| x.n == *n).map_or(vec![], |x| x.lambdas.clone());
        for (k, c) in f.iter().enumerate() {
            let _ = writeln!(
                md,
                "| {n} | {} | {:.3} | {:.3} | {:.3} | {:.3} |",
                lambdas.get(k).copied().unwrap_or(f64::NAN),
                c[0],
                c[1],
                c[2],
                c[3]
            );
        }
    }
    let _ = writeln!(md, "\n2σ coverage, raw → calibrated (target 88–99 %), {scope_name}:\n");
    let _ = writeln!(
        md,
        "| tier | N | irradiance | glossy-5 | glossy-20 | glossy-100 |\n|---|---|---|---|---|---|"
    );
    for (tier, tier_name) in TIERS.iter().enumerate() {
        for ((n, _, per_map), (_, f)) in results.iter().zip(factors) {
            let _ = write!(md, "| {tier_name} | {n} |");
            for (kind, _) in KINDS.iter().enumerate() {
                let pooled = pool(scope.iter().map(|&j| &per_map[j][tier][kind]));
                let raw = coverage(&pooled, f, kind, false);
                let cal = coverage(&pooled, f, kind, true);
                let mark = if (0.88..=0.99).contains(&cal) { "" } else { " ✗" };
                let _ = write!(md, " {:.1} → {:.1} %{mark} |", raw * 100.0, cal * 100.0);
            }
            let _ = writeln!(md);
        }
    }
    let _ = writeln!(md, "\n## Rerun\n\n```text\ncargo eval probe_trust -- --out docs\n```");
    md
}

fn pool<'a>(cells: impl Iterator<Item = &'a Cell>) -> Cell {
    let mut out = Cell::default();
    for c in cells {
        out.z.extend_from_slice(&c.z);
    }
    out
}

fn list(names: &[&str]) -> String {
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}

/// The CSV rows of a run.
pub fn csv_rows(run: &Run) -> String {
    let Run { jobs, results, factors, .. } = run;
    let mut s = String::from("bench,part,tier,query,n,method,map,rel_rmse,coverage2s\n");
    for ((n, _, per_map), (_, f)) in results.iter().zip(factors) {
        for (j, job) in jobs.iter().enumerate() {
            for (tier, tier_name) in TIERS.iter().enumerate() {
                for (kind, kind_name) in KIND_NAMES.iter().enumerate() {
                    let c = &per_map[j][tier][kind];
                    let rules = c.se.len() - 2;
                    let names: Vec<&str> = if rules == 1 { vec!["reml"] } else { RULES.to_vec() };
                    let peer_name = if kind == 0 { "cos-avg" } else { "lobe-avg" };
                    for (e, name) in names.iter().chain([&peer_name, &"sh-l2"]).enumerate() {
                        let _ = writeln!(
                            s,
                            "probe_trust,choice,{tier_name},{kind_name},{n},{name},{},{:.6e},",
                            job.name,
                            rel(c, e)
                        );
                    }
                    for (cal, label) in [(false, "raw"), (true, "calibrated")] {
                        let _ = writeln!(
                            s,
                            "probe_trust,coverage,{tier_name},{kind_name},{n},{label},{},{:.6e},{:.4}",
                            job.name,
                            rel(c, 0),
                            coverage(c, f, kind, cal)
                        );
                    }
                }
            }
        }
    }
    s
}
