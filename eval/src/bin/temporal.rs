//! Temporal accumulation: probes updated again and again under fresh rotations, on static
//! light and across changes of the light, against DDGI's blends and the oracle.
//!
//! ```text
//! cargo eval temporal                      # report to stdout
//! cargo eval temporal -- --out docs        # writes docs/temporal.md and docs/temporal.png
//! cargo eval temporal -- a.hdr b.hdr --csv rows.csv
//! ```
//!
//! Every method gets the same `N` rays per update and the same rotation sequence
//! (`RotationSequence`, a fresh uniformly random rotation of the spherical Fibonacci set per
//! update). Maps are RGB, nearest-pixel lookups, each scaled to a mean irradiance of 1 (DDGI's
//! thresholds are absolute); the error is the relative RMSE of RGB irradiance at seeded random
//! normals against every-pixel ground truth, over sequences × normals × channels.
//!
//! Scenarios (`k` counts updates since the start for `static`, since the change otherwise,
//! after a warm start of 16 updates of the light before the change):
//! `static` (64 updates), `switch` (from the previous map in the argument list, cyclically),
//! `bright2`, `dark2`, `bright4`, `dark4`, `bright10`, `dark10` (the same map scaled), `hue`
//! (each pixel's RGB rotated `(r, g, b) → (b, r, g)` and rescaled to its luminance) and
//! `rotate30` (the map turned by 30° about its vertical axis: the lights move).
//!
//! Methods:
//! - `bmc-temporal`: the crate's `TemporalProbe`, with `S` of the `N` rays as fixed sentinels
//!   (`--sentinels`: by default `S` = 1, 2, 4 at `N` = 16, 64, 256) and `N − S` rotated;
//! - `oracle`: the running mean of the per-update cosine-weighted average of the `N` samples,
//!   restarted at the true change (unbiased, and it knows when the light changed);
//! - `oracle-bmc`: the running mean of `Probe::irradiance` of each update, restarted at the
//!   true change;
//! - `ema-0.9`, `ema-0.97`: `E ← h·E + (1 − h)·E_new` of the cosine-weighted averages;
//! - `ddgi-default`, `ddgi-sample`: RTXGI-DDGI v1.3.7's probe blending per normal, in gamma-5
//!   encoded space, hysteresis 0.97, lowered by 0.75 when the largest component of
//!   `(mean − new)` exceeds the irradiance threshold, the step times 0.25 when the luminance of
//!   `(new − mean)` exceeds the brightness threshold, a darkening at least 1/1024; thresholds
//!   0.25 / 0.10 (SDK defaults) and 0.2 / 1.0 (sample configs);
//! - `capped-mean`: `α = max(1/n, 1/32)`;
//! - `asvgf`: A-SVGF's rule per normal on the luminance of the new average `c` against the
//!   blended `p`: `g = (|c − p|/max(c, p))²`, `λ = clamp(g, 0, 1)`,
//!   `n ← min(n·(1 − λ)¹⁰ + 1, 256)`, `α = lerp(max(1/256, 1/n), 1, λ)`.
//!
//! Rows of `--csv FILE`: `temporal,<scenario>,<tier>,<method>,<n>,<k>,<map>,<rel_rmse>` and
//! `resets,<tier>,<method>,<n>,<map>,<false_resets>,<updates>` (the crate's probe: updates
//! of static light it reported as a reset, `π ≥ ½`).

// Per-channel loops over RGB triples read clearer with the channel index.
#![allow(clippy::needless_range_loop)]

use sphere_quadrature_eval::{cli, compare, parallel, tiers};

use std::error::Error;
use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Parser;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::footprint::Point;
use sphere_quadrature::probe::{cosine_weighted_average, Probe, ProbeSize};
use sphere_quadrature::temporal::{Change, TemporalProbe};
use sphere_quadrature::{RotationSequence, SphericalFibonacci, Vec3};

const TIERS: [&str; 2] = ["clamp", "smooth"];
const NS: [usize; 3] = [16, 64, 256];
const SCENARIOS: [&str; 10] = [
    "static", "switch", "bright2", "dark2", "bright4", "dark4", "bright10", "dark10", "hue",
    "rotate30",
];
const METHODS: [&str; 9] = [
    "bmc-temporal",
    "oracle",
    "oracle-bmc",
    "ema-0.9",
    "ema-0.97",
    "ddgi-default",
    "ddgi-sample",
    "capped-mean",
    "asvgf",
];
/// Updates of the light before a change.
const WARM: usize = 16;
/// Updates measured (after the change, or from the start for `static`).
const UPDATES: usize = 64;
const SEED_NORMALS: u64 = 0x7E3A_0001;
const SEED_ROTATIONS: u64 = 0x7E3A_0002;
/// The training maps (the crate's defaults were chosen on these); the report's targets are
/// over the others.
const TRAINING: [&str; 4] = ["apartment", "bridge", "forest", "lab"];

/// temporal benchmark: probes updated under fresh rotations, static and across changes
#[derive(Parser)]
#[command(bin_name = "cargo eval temporal --")]
struct Args {
    /// Equirectangular .hdr maps (default: examples/envmaps/*.hdr); the switch
    /// goes from each map's predecessor in this list to it
    #[arg(value_name = "MAPS", value_parser = cli::map_file, verbatim_doc_comment)]
    maps: Vec<PathBuf>,
    /// Rows temporal,<scenario>,<tier>,<method>,<n>,<k>,<map>,<rel_rmse> and
    /// resets,<tier>,<method>,<n>,<map>,<false_resets>,<updates>
    #[arg(long, value_name = "FILE", verbatim_doc_comment)]
    csv: Option<PathBuf>,
    /// Also write DIR/temporal.md and DIR/temporal.png (`--out docs` updates the docs)
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Independent sequences per map and change scenario (four times as many for static
    /// light)
    #[arg(long, value_name = "S", default_value_t = 16, verbatim_doc_comment)]
    #[arg(value_parser = cli::positive)]
    sequences: usize,
    /// Query normals per map
    #[arg(long, value_name = "Q", default_value_t = 64)]
    #[arg(value_parser = cli::positive)]
    normals: usize,
    /// Sentinels of the crate's probe among the N rays: `none` (all N rotated, the change
    /// signal from the innovation alone), `few` (1, 2, 4 at N = 16, 64, 256), `more` (2, 4, 8)
    #[arg(long, value_name = "S", default_value = "few", value_parser = ["none", "few", "more"])]
    sentinels: String,
    /// Two maps, N = 16 and 64, one sequence, 16 normals (CI)
    #[arg(long)]
    quick: bool,
    #[command(flatten)]
    threads: cli::Threads,
}

fn parse_args() -> Result<Args, Box<dyn Error>> {
    let mut a = Args::parse();
    if a.maps.is_empty() {
        a.maps = cli::all_bundled_maps_or(a.quick, ["apartment", "lobby"])?;
    }
    if a.quick {
        a.sequences = 1;
        a.normals = a.normals.min(16);
    }
    Ok(a)
}

fn main() {
    cli::run_main("temporal", parse_args, run);
}

/// Per normal, per pixel: the irradiance truth weights of one grid.
type TruthWeights = Vec<Vec<f64>>;

/// One light: the map and its RGB irradiance at every query normal.
struct Scene {
    map: EnvMap,
    truth: Vec<[f64; 3]>,
}

fn scene(map: EnvMap, weights: &[Vec<f64>]) -> Scene {
    let truth = weights
        .iter()
        .map(|w| {
            let mut t = [0.0; 3];
            for (wi, p) in w.iter().zip(&map.pixels) {
                for c in 0..3 {
                    t[c] += wi * p[c] as f64;
                }
            }
            t
        })
        .collect();
    Scene { map, truth }
}

fn scaled(map: &EnvMap, s: f64) -> EnvMap {
    let s = s as f32;
    EnvMap::new(map.width, map.height, map.pixels.iter().map(|p| p.map(|c| c * s)).collect())
}

/// `(r, g, b) → (b, r, g)`, rescaled to the pixel's luminance.
fn hue_turned(map: &EnvMap) -> EnvMap {
    let pixels = map
        .pixels
        .iter()
        .map(|p| {
            let q = [p[2], p[0], p[1]];
            let l0 = luminance([p[0] as f64, p[1] as f64, p[2] as f64]);
            let l1 = luminance([q[0] as f64, q[1] as f64, q[2] as f64]);
            let s = if l1 > 0.0 { (l0 / l1) as f32 } else { 0.0 };
            q.map(|c| c * s)
        })
        .collect();
    EnvMap::new(map.width, map.height, pixels)
}

/// The map turned about its vertical axis by a twelfth of a turn (whole columns).
fn turned(map: &EnvMap) -> EnvMap {
    let shift = map.width / 12;
    let mut pixels = map.pixels.clone();
    for v in 0..map.height {
        for u in 0..map.width {
            pixels[v * map.width + (u + shift) % map.width] = map.pixels[v * map.width + u];
        }
    }
    EnvMap::new(map.width, map.height, pixels)
}

/// Squared errors per (method, k), Σ|truth| and counts per k, resets, of one run kind.
#[derive(Clone)]
struct Curve {
    se: Vec<Vec<f64>>,
    abs_truth: Vec<f64>,
    count: Vec<usize>,
    /// Static updates (k ≥ 2, warm-up included) and the crate's resets among them.
    static_updates: usize,
    false_resets: usize,
    /// Sequences, and those whose change the crate's probe reported within two updates.
    changes: usize,
    detected: usize,
    /// Σ over sequences of the change's RMS size (truth after − before, absolute).
    change_size: f64,
}

impl Curve {
    fn new() -> Self {
        Self {
            se: vec![vec![0.0; UPDATES]; METHODS.len()],
            abs_truth: vec![0.0; UPDATES],
            count: vec![0; UPDATES],
            static_updates: 0,
            false_resets: 0,
            changes: 0,
            detected: 0,
            change_size: 0.0,
        }
    }

    fn rel(&self, method: usize, k: usize) -> f64 {
        (self.se[method][k] / self.count[k] as f64).sqrt()
            / (self.abs_truth[k] / self.count[k] as f64)
    }
}

/// DDGI v1.3.7's blend of one texel, in gamma-5 encoded space.
fn ddgi_blend(prev: [f64; 3], new: [f64; 3], thresholds: (f64, f64)) -> [f64; 3] {
    let enc = |x: [f64; 3]| x.map(|c| c.max(0.0).powf(0.2));
    let (p, r) = (enc(prev), enc(new));
    let mut hysteresis = 0.97f64;
    let max3 = |x: [f64; 3]| x[0].max(x[1]).max(x[2]);
    if max3([p[0] - r[0], p[1] - r[1], p[2] - r[2]]) > thresholds.0 {
        hysteresis = (hysteresis - 0.75).max(0.0);
    }
    let mut delta = [r[0] - p[0], r[1] - p[1], r[2] - p[2]];
    if luminance(delta) > thresholds.1 {
        delta = delta.map(|d| d * 0.25);
    }
    let mut step = delta.map(|d| (1.0 - hysteresis) * d);
    if max3(r) < max3(p) {
        for (s, d) in step.iter_mut().zip(delta) {
            *s = s.abs().max(1.0 / 1024.0).min(d.abs()) * s.signum();
        }
    }
    [p[0] + step[0], p[1] + step[1], p[2] + step[2]].map(|c| c.powi(5))
}

/// The blends' state per normal.
struct Blends {
    ema: [Vec<[f64; 3]>; 2],
    ddgi: [Vec<[f64; 3]>; 2],
    capped: Vec<[f64; 3]>,
    asvgf: Vec<[f64; 3]>,
    asvgf_n: Vec<f64>,
    n: f64,
}

fn run_sequence<const N: usize, const NR: usize, const S: usize>(
    before: Option<&Scene>,
    after: &Scene,
    normals: &[Vec3],
    seed: u64,
    curve: &mut Curve,
) where
    Size<N>: ProbeSize,
{
    let q = normals.len();
    let mut temporal = TemporalProbe::<NR, [f32; 3], Point, S>::new(seed);
    let mut rotations = RotationSequence::new(seed);
    let set = SphericalFibonacci::<N>::new();
    let mut bmc = Probe::<N, [f32; 3]>::new();
    let mut blends: Option<Blends> = None;
    let mut oracle = vec![[0.0f64; 3]; q];
    let mut oracle_bmc = vec![[0.0f64; 3]; q];
    let mut oracle_count = 0usize;
    let phases: Vec<(&Scene, usize, bool)> = match before {
        Some(b) => vec![(b, WARM, false), (after, UPDATES, true)],
        None => vec![(after, UPDATES, true)],
    };
    let mut total = 0usize;
    for (scene, updates, measured) in phases {
        if let (true, Some(b)) = (measured, before) {
            oracle_count = 0;
            curve.changes += 1;
            let d2: f64 = scene
                .truth
                .iter()
                .zip(&b.truth)
                .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>())
                .sum();
            curve.change_size += (d2 / (3 * q) as f64).sqrt();
        }
        let mut detected = false;
        for k in 0..updates {
            let rotation = rotations.next_rotation();
            let dirs = set.with_rotation(rotation).expect("a rotation").points();
            let lookup = |d: &Vec3| {
                scene.map.radiance([d.x as f64, d.y as f64, d.z as f64]).map(|c| c as f32)
            };
            let samples: [[f32; 3]; N] = std::array::from_fn(|j| lookup(&dirs[j]));
            // The crate's probe: N − S rotated by the same rotation, S sentinels.
            let rotated: [[f32; 3]; NR] =
                std::array::from_fn(|j| lookup(&temporal.directions()[j]));
            let sentinels: [[f32; 3]; S] =
                std::array::from_fn(|j| lookup(&temporal.sentinels()[j]));
            let change = temporal.pool(&rotated, &sentinels).expect("finite samples");
            if total > 0 && change == Change::Reset {
                if measured && before.is_some() {
                    detected |= k < 2;
                } else {
                    curve.false_resets += 1;
                }
            }
            if total > 0 && !(measured && before.is_some()) {
                curve.static_updates += 1;
            }
            bmc.set_rotation(rotation).expect("a rotation");
            bmc.update(&samples).expect("finite samples");
            let cos: Vec<[f64; 3]> = normals
                .iter()
                .map(|&n| {
                    cosine_weighted_average(&dirs, &samples, n).expect("unit normal").map(f64::from)
                })
                .collect();
            oracle_count += 1;
            let w = 1.0 / oracle_count as f64;
            for (qi, &n) in normals.iter().enumerate() {
                let b = bmc.irradiance(n).expect("unit normal").value.map(f64::from);
                for c in 0..3 {
                    oracle[qi][c] += (cos[qi][c] - oracle[qi][c]) * w;
                    oracle_bmc[qi][c] += (b[c] - oracle_bmc[qi][c]) * w;
                }
            }
            match &mut blends {
                None => {
                    blends = Some(Blends {
                        ema: [cos.clone(), cos.clone()],
                        ddgi: [cos.clone(), cos.clone()],
                        capped: cos.clone(),
                        asvgf: cos.clone(),
                        asvgf_n: vec![1.0; q],
                        n: 1.0,
                    })
                }
                Some(b) => {
                    b.n += 1.0;
                    let alpha = (1.0 / b.n).max(1.0 / 32.0);
                    for qi in 0..q {
                        let c = cos[qi];
                        for (e, h) in b.ema.iter_mut().zip([0.9, 0.97]) {
                            for ch in 0..3 {
                                e[qi][ch] = h * e[qi][ch] + (1.0 - h) * c[ch];
                            }
                        }
                        for (d, t) in b.ddgi.iter_mut().zip([(0.25, 0.10), (0.2, 1.0)]) {
                            d[qi] = ddgi_blend(d[qi], c, t);
                        }
                        for ch in 0..3 {
                            b.capped[qi][ch] += alpha * (c[ch] - b.capped[qi][ch]);
                        }
                        let (lc, lp) = (luminance(c), luminance(b.asvgf[qi]));
                        let den = lc.max(lp);
                        let g = if den > 0.0 { ((lc - lp).abs() / den).powi(2) } else { 0.0 };
                        let lambda = g.clamp(0.0, 1.0);
                        let n = (b.asvgf_n[qi] * (1.0 - lambda).powi(10) + 1.0).min(256.0);
                        b.asvgf_n[qi] = n;
                        let a = (1.0 / n).max(1.0 / 256.0);
                        let a = a + (1.0 - a) * lambda;
                        for ch in 0..3 {
                            b.asvgf[qi][ch] += a * (c[ch] - b.asvgf[qi][ch]);
                        }
                    }
                }
            }
            total += 1;
            if !measured {
                continue;
            }
            let b = blends.as_ref().expect("set above");
            curve.count[k] += 3 * q;
            for (qi, &n) in normals.iter().enumerate() {
                let t = scene.truth[qi];
                curve.abs_truth[k] += t.iter().map(|x| x.abs()).sum::<f64>();
                let e = temporal.irradiance(n).expect("unit normal").value.map(f64::from);
                let est = [
                    e,
                    oracle[qi],
                    oracle_bmc[qi],
                    b.ema[0][qi],
                    b.ema[1][qi],
                    b.ddgi[0][qi],
                    b.ddgi[1][qi],
                    b.capped[qi],
                    b.asvgf[qi],
                ];
                for (m, v) in est.iter().enumerate() {
                    curve.se[m][k] += (0..3).map(|c| (v[c] - t[c]).powi(2)).sum::<f64>();
                }
            }
        }
        if measured && before.is_some() && detected {
            curve.detected += 1;
        }
    }
}

/// The curve of one (scenario, N) over `sequences`.
fn curve(
    n: usize,
    sentinels: &str,
    before: Option<&Scene>,
    after: &Scene,
    normals: &[Vec3],
    sequences: usize,
    seed: u64,
) -> Curve {
    let mut c = Curve::new();
    macro_rules! go {
        ($n:literal, $nr:literal, $s:literal) => {
            for s in 0..sequences {
                let seed = seed ^ (s as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
                run_sequence::<$n, $nr, $s>(before, after, normals, seed, &mut c);
            }
        };
    }
    match (n, sentinels) {
        (16, "few") => go!(16, 15, 1),
        (64, "few") => go!(64, 62, 2),
        (256, "few") => go!(256, 252, 4),
        (16, "more") => go!(16, 14, 2),
        (64, "more") => go!(64, 60, 4),
        (256, "more") => go!(256, 248, 8),
        (16, _) => go!(16, 16, 0),
        (64, _) => go!(64, 64, 0),
        (256, _) => go!(256, 256, 0),
        _ => unreachable!("N = {n} is not benchmarked"),
    }
    c
}

/// The post-change light of `scenario` for map `m` of a tier, and the light before it.
fn lights<'a>(
    scenario: &str,
    m: usize,
    scenes: &'a [Vec<Scene>],
) -> (Option<&'a Scene>, &'a Scene) {
    // scenes[m]: [base, bright2, dark2, bright4, dark4, bright10, dark10, hue, rotate30]
    let base = &scenes[m][0];
    match scenario {
        "static" => (None, base),
        "switch" => (Some(&scenes[(m + scenes.len() - 1) % scenes.len()][0]), base),
        other => {
            let i = SCENARIOS.iter().position(|s| *s == other).expect("a scenario") - 1;
            (Some(base), &scenes[m][i])
        }
    }
}

fn run(args: &Args) -> Result<(), Box<dyn Error>> {
    let start = std::time::Instant::now();
    let threads = args.threads.count();
    let mut rng = Rng::new(SEED_NORMALS);
    let normals64: Vec<[f64; 3]> = (0..args.normals).map(|_| rng.uniform_sphere()).collect();
    let normals: Vec<Vec3> =
        normals64.iter().map(|d| Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)).collect();
    let names: Vec<String> = args.maps.iter().map(|p| cli::map_name(p)).collect();
    let loaded: Vec<[EnvMap; 2]> = parallel::parallel_map(&args.maps, threads, |_, path| {
        let map = EnvMap::load(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let clamp = compare::clamped(&map);
        let smooth = tiers::smooth(&clamp);
        Ok::<_, String>([clamp, smooth])
    })
    .into_iter()
    .collect::<Result<_, _>>()?;
    let mut grids: Vec<((usize, usize), TruthWeights)> = Vec::new();
    for m in loaded.iter().flatten() {
        if !grids.iter().any(|(g, _)| *g == (m.width, m.height)) {
            grids.push((
                (m.width, m.height),
                compare::weights(compare::Kind::Diffuse, &normals64, m.width, m.height),
            ));
        }
    }
    // Per tier, per map: the base light scaled to a mean irradiance of 1, then its variants.
    let jobs_maps: Vec<(usize, usize)> =
        (0..TIERS.len()).flat_map(|t| (0..loaded.len()).map(move |m| (t, m))).collect();
    let built = parallel::parallel_map(&jobs_maps, threads, |_, &(t, m)| {
        let map = &loaded[m][t];
        let w = &grids.iter().find(|(g, _)| *g == (map.width, map.height)).expect("weights").1;
        let base = scaled(map, 1.0 / (std::f64::consts::PI * luminance(map.mean_radiance())));
        let variants = [
            scaled(&base, 2.0),
            scaled(&base, 0.5),
            scaled(&base, 4.0),
            scaled(&base, 0.25),
            scaled(&base, 10.0),
            scaled(&base, 0.1),
            hue_turned(&base),
            turned(&base),
        ];
        let mut out = vec![scene(base, w)];
        out.extend(variants.into_iter().map(|v| scene(v, w)));
        out
    });
    let scenes: Vec<Vec<Vec<Scene>>> = {
        let mut it = built.into_iter();
        (0..TIERS.len())
            .map(|_| (0..loaded.len()).map(|_| it.next().expect("built")).collect())
            .collect()
    };
    let ns: Vec<usize> = if args.quick { vec![16, 64] } else { NS.to_vec() };
    let count = loaded.len();
    let jobs: Vec<(usize, usize, usize, usize)> = (0..TIERS.len())
        .flat_map(|t| {
            ns.iter().flat_map(move |&n| {
                (0..SCENARIOS.len()).flat_map(move |s| (0..count).map(move |m| (t, n, s, m)))
            })
        })
        .collect();
    let results = parallel::parallel_map(&jobs, threads, |_, &(t, n, s, m)| {
        let (before, after) = lights(SCENARIOS[s], m, &scenes[t]);
        let seed = SEED_ROTATIONS ^ (n as u64) << 32 ^ (s as u64) << 16 ^ m as u64;
        // Static light, the scenario of the finest comparisons, gets four times the sequences.
        let sequences = if s == 0 { 4 * args.sequences } else { args.sequences };
        curve(n, &args.sentinels, before, after, &normals, sequences, seed)
    });
    let secs = start.elapsed().as_secs_f64();
    let report = render(args, &names, &ns, &jobs, &results, secs);
    print!("{report}");
    if let Some(csv) = &args.csv {
        if let Some(dir) = csv.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        let mut s = String::new();
        for (&(t, n, sc, m), c) in jobs.iter().zip(&results) {
            for (mi, method) in METHODS.iter().enumerate() {
                for k in 0..UPDATES {
                    let _ = writeln!(
                        s,
                        "temporal,{},{},{method},{n},{},{},{:.6e}",
                        SCENARIOS[sc],
                        TIERS[t],
                        k + 1,
                        names[m],
                        c.rel(mi, k)
                    );
                }
            }
        }
        for &t in &[0usize, 1] {
            for &n in &ns {
                for m in 0..count {
                    let (fr, up) = jobs
                        .iter()
                        .zip(&results)
                        .filter(|((jt, jn, _, jm), _)| *jt == t && *jn == n && *jm == m)
                        .fold((0, 0), |(a, b), (_, c)| (a + c.false_resets, b + c.static_updates));
                    let _ =
                        writeln!(s, "resets,{},bmc-temporal,{n},{},{fr},{up}", TIERS[t], names[m]);
                }
            }
        }
        std::fs::write(csv, s)?;
        eprintln!("wrote {}", csv.display());
    }
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)?;
        std::fs::write(dir.join("temporal.md"), &report)?;
        plot(&names, &ns, &jobs, &results, &dir.join("temporal.png"))?;
        eprintln!("wrote {} and temporal.png", dir.join("temporal.md").display());
    }
    Ok(())
}

/// The curves of (tier, N, scenario) over the maps `held` selects.
fn select<'a>(
    jobs: &[(usize, usize, usize, usize)],
    results: &'a [Curve],
    names: &[String],
    t: usize,
    n: usize,
    s: usize,
    held: bool,
) -> Vec<&'a Curve> {
    jobs.iter()
        .zip(results)
        .filter(|((jt, jn, js, jm), _)| {
            *jt == t && *jn == n && *js == s && (!held || !TRAINING.contains(&names[*jm].as_str()))
        })
        .map(|(_, c)| c)
        .collect()
}

/// Mean over maps of the ratio of `method` to `peer` at update `k` (1-based).
fn mean_ratio(curves: &[&Curve], method: usize, peer: usize, k: usize) -> f64 {
    curves.iter().map(|c| c.rel(method, k - 1) / c.rel(peer, k - 1)).sum::<f64>()
        / curves.len().max(1) as f64
}

/// Mean over maps of the ratio of `method` to the best of `peers` (per map) at update `k`.
fn mean_ratio_best(curves: &[&Curve], method: usize, peers: &[usize], k: usize) -> f64 {
    curves
        .iter()
        .map(|c| {
            let best = peers.iter().map(|&p| c.rel(p, k - 1)).fold(f64::INFINITY, f64::min);
            c.rel(method, k - 1) / best
        })
        .sum::<f64>()
        / curves.len().max(1) as f64
}

fn mean_rel(curves: &[&Curve], method: usize, k: usize) -> f64 {
    curves.iter().map(|c| c.rel(method, k - 1)).sum::<f64>() / curves.len().max(1) as f64
}

/// The first k from which the mean per-map ratio to the oracle stays ≤ 1.25 (None: never).
fn settle(curves: &[&Curve], method: usize) -> Option<usize> {
    let ok: Vec<bool> = (1..=UPDATES).map(|k| mean_ratio(curves, method, 1, k) <= 1.25).collect();
    (0..UPDATES).find(|&i| ok[i..].iter().all(|&b| b)).map(|i| i + 1)
}

fn render(
    args: &Args,
    names: &[String],
    ns: &[usize],
    jobs: &[(usize, usize, usize, usize)],
    results: &[Curve],
    secs: f64,
) -> String {
    let held: Vec<&String> = names.iter().filter(|n| !TRAINING.contains(&n.as_str())).collect();
    let use_held = !held.is_empty();
    let maps_label = if use_held {
        format!("held-out maps {}", held.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", "))
    } else {
        format!("maps {}", names.join(", "))
    };
    let mut md = String::new();
    let _ = writeln!(md, "# Temporal accumulation\n");
    let _ = writeln!(
        md,
        "Generated by `cargo eval temporal` ({} sequences per map and change scenario, four times as many for `static`, {} normals; {:.0} s). \
         Maps: {}. Every table is over the {maps_label} (the crate's settings were chosen on {}); \
         relative RMSE of RGB irradiance, each map scaled to a mean irradiance of 1. Ratios are \
         means of per-map ratios. See the program's docs for the methods.\n",
        args.sequences,
        args.normals,
        secs,
        names.join(", "),
        TRAINING.join(", ")
    );
    let ks = [1usize, 2, 3, 4, 8, 16, 32, 64];
    let krow = ks.map(|k| k.to_string()).join(" | ");
    for (t, tier) in TIERS.iter().enumerate() {
        for &n in ns {
            let stat = select(jobs, results, names, t, n, 0, use_held);
            let _ = writeln!(md, "## `{tier}`, N = {n}\n");
            let _ = writeln!(md, "### static: error / the oracle's, after update k\n");
            let _ = writeln!(md, "| method | {krow} |");
            let _ = writeln!(md, "|---|{}", "---|".repeat(ks.len()));
            let _ = write!(md, "| oracle (relative RMSE) |");
            for &k in &ks {
                let _ = write!(md, " {:.2}% |", 100.0 * mean_rel(&stat, 1, k));
            }
            let _ = writeln!(md);
            for (mi, method) in METHODS.iter().enumerate().filter(|(m, _)| *m != 1) {
                let _ = write!(md, "| `{method}` |");
                for &k in &ks {
                    let _ = write!(md, " {:.3} |", mean_ratio(&stat, mi, 1, k));
                }
                let _ = writeln!(md);
            }
            let _ = write!(md, "| `bmc-temporal` / best of `ema-0.9`, `ddgi-*` |");
            for &k in &ks {
                let _ = write!(md, " {:.3} |", mean_ratio_best(&stat, 0, &[3, 5, 6], k));
            }
            let _ = writeln!(md, "\n");
            let _ = writeln!(
                md,
                "### after a change: error / the oracle's at k = 1, 2, 4, 16; updates until ≤ 1.25× the oracle for good; `bmc-temporal` / best peer at k = 16\n"
            );
            let _ = writeln!(
                md,
                "| scenario | change / σ₁ | detected ≤ 2 updates | `bmc-temporal` k = 1 | 2 | 4 | 16 | settles | `ema-0.9` k = 16 | `ddgi-default` 16 | `ddgi-sample` 16 | `asvgf` 16 | / best peer, 16 |"
            );
            let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|---|");
            // σ₁: the oracle's first-update RMSE on static light, absolute.
            for (s, scenario) in SCENARIOS.iter().enumerate().skip(1) {
                let c = select(jobs, results, names, t, n, s, use_held);
                let sizes: f64 = c
                    .iter()
                    .zip(&stat)
                    .map(|(c, st)| {
                        let sigma1 = (st.se[1][0] / st.count[0] as f64).sqrt();
                        c.change_size / c.changes.max(1) as f64 / sigma1
                    })
                    .sum::<f64>()
                    / c.len().max(1) as f64;
                let det: usize = c.iter().map(|c| c.detected).sum();
                let all: usize = c.iter().map(|c| c.changes).sum();
                let settles = settle(&c, 0).map_or("never".to_string(), |k| k.to_string());
                let _ = write!(
                    md,
                    "| {scenario} | {sizes:.1} | {det}/{all} | {:.3} | {:.3} | {:.3} | {:.3} | {settles} |",
                    mean_ratio(&c, 0, 1, 1),
                    mean_ratio(&c, 0, 1, 2),
                    mean_ratio(&c, 0, 1, 4),
                    mean_ratio(&c, 0, 1, 16)
                );
                for p in [3usize, 5, 6, 8] {
                    let _ = write!(md, " {:.3} |", mean_ratio(&c, p, 1, 16));
                }
                let _ = writeln!(md, " {:.3} |", mean_ratio_best(&c, 0, &[3, 4, 5, 6, 7, 8], 16));
            }
            let _ = writeln!(md);
        }
    }
    targets(&mut md, names, ns, jobs, results, use_held);
    let _ = writeln!(md, "## False resets of `bmc-temporal` on static light\n");
    let _ = writeln!(md, "Updates after the first of a static light (the `static` scenario and the warm-up before each change) that the probe reported as a reset (`π ≥ ½`), all maps.\n");
    let _ = writeln!(md, "| tier | N | resets / updates | per 1 000 | worst map (per 1 000) |");
    let _ = writeln!(md, "|---|---|---|---|---|");
    for (t, tier) in TIERS.iter().enumerate() {
        for &n in ns {
            let mut per_map = vec![(0usize, 0usize); names.len()];
            for (&(jt, jn, _, jm), c) in jobs.iter().zip(results) {
                if jt == t && jn == n {
                    per_map[jm].0 += c.false_resets;
                    per_map[jm].1 += c.static_updates;
                }
            }
            let (fr, up) = per_map.iter().fold((0, 0), |(a, b), (x, y)| (a + x, b + y));
            let (wi, w) = per_map
                .iter()
                .enumerate()
                .map(|(i, (x, y))| (i, 1000.0 * *x as f64 / (*y).max(1) as f64))
                .fold((0, -1.0), |a, b| if b.1 > a.1 { b } else { a });
            let _ = writeln!(
                md,
                "| `{tier}` | {n} | {fr} / {up} | {:.2} | {} ({w:.2}) |",
                1000.0 * fr as f64 / up.max(1) as f64,
                names[wi]
            );
        }
    }
    md
}

/// The issue's targets, each with the measured figure (held-out maps, mean of per-map ratios).
fn targets(
    md: &mut String,
    names: &[String],
    ns: &[usize],
    jobs: &[(usize, usize, usize, usize)],
    results: &[Curve],
    held: bool,
) {
    let _ = writeln!(md, "## Targets\n");
    let _ = writeln!(md, "| target | tier, N | measured | met |\n|---|---|---|---|");
    let mut row = |target: &str, case: String, measured: String, met: bool| {
        let _ = writeln!(
            md,
            "| {target} | {case} | {measured} | {} |",
            if met { "yes" } else { "**no**" }
        );
    };
    let max_over =
        |c: &[&Curve], m: usize, peers: &[usize], ks: std::ops::RangeInclusive<usize>| {
            ks.map(|k| (k, mean_ratio_best(c, m, peers, k))).fold((0, 0.0f64), |a, b| {
                if b.1 > a.1 {
                    b
                } else {
                    a
                }
            })
        };
    for (t, tier) in TIERS.iter().enumerate() {
        for &n in ns {
            let case = format!("`{tier}`, {n}");
            let stat = select(jobs, results, names, t, n, 0, held);
            let (k, r) = max_over(&stat, 0, &[1], 1..=UPDATES);
            row(
                "static: ≤ 1.05× the oracle at every k ≤ 64",
                case.clone(),
                format!("worst {r:.3} (k = {k})"),
                r <= 1.05,
            );
            if n == 16 || n == 64 {
                let bar = if n == 16 { 0.9 } else { 0.95 };
                let (k, r) = max_over(&stat, 0, &[1], 1..=4);
                row(
                    &format!("static: ≤ {bar}× the oracle at k ≤ 4"),
                    case.clone(),
                    format!("worst {r:.3} (k = {k})"),
                    r <= bar,
                );
            }
            for (k, bar) in [(16usize, 0.9), (32, 0.8), (64, 0.8)] {
                let r = mean_ratio_best(&stat, 0, &[3, 5, 6], k);
                row(
                    &format!("static: ≤ {bar}× the best of `ema-0.9`, `ddgi-*` at k = {k}"),
                    case.clone(),
                    format!("{r:.3}"),
                    r <= bar,
                );
            }
            if *tier == "smooth" {
                let r = mean_ratio(&stat, 0, 3, 32);
                row("`smooth`: ≤ `ema-0.9` at k = 32", case.clone(), format!("{r:.3}"), r <= 1.0);
            }
            for (s, scenario) in SCENARIOS.iter().enumerate().skip(1) {
                let c = select(jobs, results, names, t, n, s, held);
                let size = c
                    .iter()
                    .zip(&stat)
                    .map(|(c, st)| {
                        c.change_size
                            / c.changes.max(1) as f64
                            / (st.se[1][0] / st.count[0] as f64).sqrt()
                    })
                    .sum::<f64>()
                    / c.len().max(1) as f64;
                let big = ["switch", "bright4", "dark4", "bright10", "dark10"].contains(scenario);
                if big && size >= 3.0 {
                    let (k, r) = max_over(&c, 0, &[1], 2..=UPDATES);
                    row(
                        &format!("{scenario} ({size:.1} σ₁): ≤ 1.3× the oracle from k = 2"),
                        case.clone(),
                        format!("worst {r:.3} (k = {k})"),
                        r <= 1.3,
                    );
                }
                let r = mean_ratio_best(&c, 0, &[3, 4, 5, 6, 7, 8], 16);
                row(
                    &format!("{scenario}: ≤ the best peer at k = 16"),
                    case.clone(),
                    format!("{r:.3}"),
                    r <= 1.0,
                );
            }
            let mut worst = 0.0f64;
            for (&(jt, jn, _, jm), c) in jobs.iter().zip(results) {
                let _ = jm;
                if jt == t && jn == n && c.static_updates > 0 {
                    worst = worst.max(1000.0 * c.false_resets as f64 / c.static_updates as f64);
                }
            }
            row(
                "false resets ≤ 1 per 1 000 static updates, every map",
                case,
                format!("worst {worst:.2}"),
                worst <= 1.0,
            );
        }
    }
    let _ = writeln!(md);
}

fn plot(
    names: &[String],
    ns: &[usize],
    jobs: &[(usize, usize, usize, usize)],
    results: &[Curve],
    path: &std::path::Path,
) -> Result<(), Box<dyn Error>> {
    register_font("sans-serif", FontStyle::Normal, ttf_noto_sans::REGULAR)
        .map_err(|_| "cannot register the embedded font")?;
    let root = BitMapBackend::new(path, (1200, 520)).into_drawing_area();
    root.fill(&WHITE)?;
    let n = if ns.contains(&64) { 64 } else { ns[0] };
    let held = names.iter().any(|n| !TRAINING.contains(&n.as_str()));
    let panels = root.split_evenly((1, 2));
    for (panel, (s, title)) in panels.iter().zip([(0usize, "static"), (1, "after a switch")]) {
        let c = select(jobs, results, names, 0, n, s, held);
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("clamp, N = {n}: {title}"), ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d((1f64..64.0).log_scale(), (0.01f64..4.0).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("updates k")
            .y_desc("relative RMSE (mean over maps)")
            .label_style(("sans-serif", 13))
            .draw()?;
        for (mi, method) in METHODS.iter().enumerate() {
            let color = Palette99::pick(mi).to_rgba();
            let pts: Vec<(f64, f64)> =
                (1..=UPDATES).map(|k| (k as f64, mean_rel(&c, mi, k).max(0.01))).collect();
            let width = if mi < 2 { 3 } else { 1 };
            chart
                .draw_series(LineSeries::new(pts, color.stroke_width(width)))?
                .label(*method)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 12))
            .draw()?;
    }
    root.present()?;
    Ok(())
}
