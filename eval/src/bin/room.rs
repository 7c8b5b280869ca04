//! Probes in a real scene: a 4 × 4 × 4 grid in the Cornell box, updated every frame by path
//! traced rays, against DDGI's blending, hysteresis blends and the oracle.
//!
//! ```text
//! cargo eval room                      # report to stdout
//! cargo eval room -- --out docs        # writes docs/room.md
//! cargo eval room -- --csv rows.csv
//! ```
//!
//! The scene is built in (no map arguments): the Cornell box as published by the Cornell
//! University Program of Computer Graphics ("Cornell Box Data",
//! <https://www.graphics.cornell.edu/online/box/data.html>), with the simplifications listed
//! in `eval/src/room/scene.rs`. A probe's ray sees the radiance at its first hit: emission,
//! direct light with shadow rays, and path-traced interreflection (Russian roulette), so that
//! every ray carries real Monte Carlo noise. The emission is scaled so that the mean
//! irradiance (luminance) over the probes and query normals of the static scene is 1, as the
//! temporal benchmark scales its maps (DDGI's thresholds are absolute).
//!
//! Reference: per probe, scene state and query normal, the irradiance of the same estimator
//! from `--reference-rays` rays in two independent halves (each a spherical Fibonacci set under
//! its own random rotation, each ray one path); its error is estimated from the halves'
//! difference and stated in the report.
//!
//! Each frame each probe traces `N` rays (16, 64, 256), the crate's probe taking `S` of them
//! as sentinels (1, 2, 4, as `cargo eval temporal`): `TemporalProbe::<N − S, [f32; 3], Point,
//! S>`. The peers get the radiance of the same traced rays: the `N − S` rotated ones (uniformly
//! spread; the sentinels re-read bright directions and would bias a uniform average):
//! - `oracle`: the running mean of the per-frame cosine-weighted averages, restarted at each
//!   true change of the scene (under `drift` it knows the brightness and rescales);
//! - `ema-0.9`, `ema-0.97`: `E ← h·E + (1 − h)·E_new`;
//! - `ddgi-default`, `ddgi-sample`: RTXGI-DDGI v1.3.7's probe blending (as in `cargo eval
//!   temporal`), thresholds 0.25 / 0.10 and 0.2 / 1.0.
//!
//! Events (after a warm start of 16 frames of the static scene, 64 frames measured after the
//! event; `static` 64 frames from the start): `static`; `off-on` (the light off for 16 frames,
//! then on again: the frames are counted from the switch on); `corner-light` (a second small
//! light turns on in a corner); `block-moved` (the tall block 10 cm towards the back wall);
//! `wall-blue` (the red wall turns blue); `drift` (the light's intensity × (1 + 0.01·k) at
//! frame k; no single change, every reset a false one).
//!
//! Rows of `--csv FILE`: `room,<event>,<method>,<n>,<frame>,<rel_rmse>,<coverage2s>` (the
//! relative RMSE of RGB irradiance over probes, query normals, channels and seeds at frame k
//! after the event; the 2σ coverage of `bmc-temporal`'s bar at that frame, empty for the other
//! methods) and `room-detect,<event>,<n>,<within1>,<within2>,<within4>,<never>,<false_per_1000>`
//! (the shares of the changed probes' changes detected within 1, 2, 4 frames or never, empty
//! without a change; false resets per 1 000 probe updates whose light did not change).

// Per-channel loops over RGB triples read clearer with the channel index.
#![allow(clippy::needless_range_loop)]

#[path = "../room/report.rs"]
mod report;
#[path = "../room/scene.rs"]
mod scene;

use scene::{Scene, Setup, V};
use sphere_quadrature_eval::blends::ddgi_blend;
use sphere_quadrature_eval::{cli, parallel};

use std::error::Error;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use reference::envmap::luminance;
use reference::rng::Rng;
use sphere_quadrature::footprint::Point;
use sphere_quadrature::probe::cosine_weighted_average;
use sphere_quadrature::temporal::{Change, TemporalProbe};
use sphere_quadrature::Vec3;

const NS: [usize; 3] = [16, 64, 256];
const EVENTS: [&str; 6] = ["static", "off-on", "corner-light", "block-moved", "wall-blue", "drift"];
const METHODS: [&str; 6] =
    ["bmc-temporal", "oracle", "ema-0.9", "ema-0.97", "ddgi-default", "ddgi-sample"];
/// The peers (indices into `METHODS`).
const PEERS: [usize; 4] = [2, 3, 4, 5];
/// Frames of the static scene before an event.
const WARM: usize = 16;
/// Frames measured after the event.
const FRAMES: usize = 64;
/// `off-on`: frames with the light off.
const OFF: usize = 16;
/// The traced scene states: base, the corner light on, the block moved, the wall blue.
const STATES: [Setup; 4] = [
    Setup::BASE,
    Setup { corner_light: true, ..Setup::BASE },
    Setup { block_moved: true, ..Setup::BASE },
    Setup { blue_wall: true, ..Setup::BASE },
];
const SEED_NORMALS: u64 = 0x800A_0001;
const SEED_REFERENCE: u64 = 0x800A_0002;
const SEED_RUNS: u64 = 0x800A_0003;
const SEED_REREAD: u64 = 0x800A_0004;

/// room benchmark: probes in the Cornell box (built in: no map arguments) updated every frame
/// by path-traced rays, against DDGI's blending, hysteresis and the oracle
#[derive(Parser)]
#[command(bin_name = "cargo eval room --")]
struct Args {
    /// Rows room,<event>,<method>,<n>,<frame>,<rel_rmse>,<coverage2s> and
    /// room-detect,<event>,<n>,<within1>,<within2>,<within4>,<never>,<false_per_1000>
    #[arg(long, value_name = "FILE", verbatim_doc_comment)]
    csv: Option<PathBuf>,
    /// Also write DIR/room.md (`--out docs` updates the docs)
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Independent runs (seeds) per event and N
    #[arg(long, value_name = "S", default_value_t = 3)]
    #[arg(value_parser = cli::positive)]
    seeds: usize,
    /// Query normals per probe
    #[arg(long, value_name = "Q", default_value_t = 32)]
    #[arg(value_parser = cli::positive)]
    normals: usize,
    /// Rays (paths) of the reference per probe and scene state, in two halves
    #[arg(long, value_name = "R", default_value_t = 262_144)]
    #[arg(value_parser = cli::positive)]
    reference_rays: usize,
    /// One seed, N = 16 and 64, 16 normals, 2^15 reference rays (CI smoke test)
    #[arg(long)]
    quick: bool,
    #[command(flatten)]
    threads: cli::Threads,
}

fn parse_args() -> Result<Args, Box<dyn Error>> {
    let mut a = Args::parse();
    if a.quick {
        a.seeds = 1;
        a.normals = a.normals.min(16);
        a.reference_rays = a.reference_rays.min(1 << 15);
    }
    if a.reference_rays < 2 {
        return Err("--reference-rays must be at least 2 (two halves)".into());
    }
    Ok(a)
}

fn main() {
    cli::run_main("room", parse_args, run);
}

/// Splits a seed (SplitMix64's finaliser of `a` mixed with `b`).
fn mix(a: u64, b: u64) -> u64 {
    let mut z = a ^ b.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn apply(m: &[[f64; 3]; 3], v: V) -> V {
    m.map(|r| r[0] * v[0] + r[1] * v[1] + r[2] * v[2])
}

/// The reference of one probe and state: the irradiance at every normal from `rays`
/// spherical Fibonacci directions under a random rotation, one path each.
fn reference_half(scene: &Scene, p: V, normals: &[V], rays: usize, seed: u64) -> Vec<V> {
    let mut rng = Rng::new(seed);
    let rotation = rng.uniform_rotation();
    let mut e = vec![[0.0; 3]; normals.len()];
    for j in 0..rays {
        let d = apply(&rotation, reference::sf::sphere_point(j as u64, rays as u64));
        let l = scene.radiance(p, d, &mut rng);
        for (ei, n) in e.iter_mut().zip(normals) {
            let c = scene::dot(*n, d);
            if c > 0.0 {
                for ch in 0..3 {
                    ei[ch] += l[ch] * c;
                }
            }
        }
    }
    let w = 4.0 * std::f64::consts::PI / rays as f64;
    e.into_iter().map(|x| x.map(|c| c * w)).collect()
}

/// Two readings of one direction differ by path-tracing noise alone: over the probes and
/// 256 directions each (static scene), the shares of pairs whose luminances differ by more than
/// 10 % and 50 % of their mean, the median relative difference, and the pairs (both zero left out).
fn reread_noise(scene: &Scene, probes: &[V], threads: usize) -> ([f64; 3], usize) {
    let per = parallel::parallel_map(probes, threads, |i, &p| {
        let mut rng = Rng::new(mix(SEED_REREAD, i as u64));
        let rotation = rng.uniform_rotation();
        (0..256u64)
            .filter_map(|j| {
                let d = apply(&rotation, reference::sf::sphere_point(j, 256));
                let a = luminance(scene.radiance(p, d, &mut rng));
                let b = luminance(scene.radiance(p, d, &mut rng));
                (a + b > 0.0).then(|| (a - b).abs() / (0.5 * (a + b)))
            })
            .collect::<Vec<f64>>()
    });
    let mut all: Vec<f64> = per.into_iter().flatten().collect();
    all.sort_by(f64::total_cmp);
    let n = all.len().max(1) as f64;
    let share = |x: f64| all.iter().filter(|&&r| r > x).count() as f64 / n;
    let median = all.get(all.len() / 2).copied().unwrap_or(0.0);
    ([share(0.1), share(0.5), median], all.len())
}

/// The references: per state, per probe, per normal (unit emission), and their estimated
/// error per state (relative RMS over probes, normals and channels).
struct Reference {
    truth: Vec<Vec<Vec<V>>>,
    half_diff: Vec<f64>,
}

fn reference(probes: &[V], normals: &[V], rays: usize, threads: usize) -> Reference {
    let jobs: Vec<(usize, usize, usize)> = (0..STATES.len())
        .flat_map(|s| (0..probes.len()).flat_map(move |p| (0..2).map(move |h| (s, p, h))))
        .collect();
    let scenes: Vec<Scene> = STATES.iter().map(|&s| Scene::new(s, 1.0)).collect();
    let halves = parallel::parallel_map(&jobs, threads, |_, &(s, p, h)| {
        let seed = mix(SEED_REFERENCE, ((s * 1000 + p) * 2 + h) as u64);
        reference_half(&scenes[s], probes[p], normals, rays / 2, seed)
    });
    let mut truth = vec![vec![Vec::new(); probes.len()]; STATES.len()];
    let mut half_diff = vec![0.0; STATES.len()];
    for s in 0..STATES.len() {
        let (mut se, mut abs, mut count) = (0.0, 0.0, 0usize);
        for p in 0..probes.len() {
            let i = (s * probes.len() + p) * 2;
            let (a, b) = (&halves[i], &halves[i + 1]);
            truth[s][p] =
                a.iter().zip(b).map(|(x, y)| [0, 1, 2].map(|c| 0.5 * (x[c] + y[c]))).collect();
            for (x, y) in a.iter().zip(b) {
                for c in 0..3 {
                    // The mean's error: half the halves' difference, in the RMS sense.
                    se += (0.5 * (x[c] - y[c])).powi(2);
                    abs += 0.5 * (x[c] + y[c]).abs();
                    count += 1;
                }
            }
        }
        half_diff[s] = (se / count as f64).sqrt() / (abs / count as f64);
    }
    Reference { truth, half_diff }
}

/// One frame of an event: the scene state (an index into `STATES`, None: every light off) and
/// the main light's brightness, whether a true change happens at it (its slot), and the
/// measured frame index `k − 1`.
#[derive(Clone, Copy)]
struct Frame {
    state: Option<usize>,
    brightness: f64,
    change: Option<usize>,
    measured: Option<usize>,
}

fn timeline(event: &str) -> Vec<Frame> {
    let plain =
        |state: Option<usize>| Frame { state, brightness: 1.0, change: None, measured: None };
    let warm = (0..WARM).map(|_| plain(Some(0)));
    let after = |state: usize, slot: usize| {
        (0..FRAMES).map(move |k| Frame {
            change: (k == 0).then_some(slot),
            measured: Some(k),
            ..plain(Some(state))
        })
    };
    match event {
        "static" => (0..FRAMES).map(|k| Frame { measured: Some(k), ..plain(Some(0)) }).collect(),
        "off-on" => warm
            .chain((0..OFF).map(|k| Frame { change: (k == 0).then_some(0), ..plain(None) }))
            .chain(after(0, 1))
            .collect(),
        "corner-light" => warm.chain(after(1, 0)).collect(),
        "block-moved" => warm.chain(after(2, 0)).collect(),
        "wall-blue" => warm.chain(after(3, 0)).collect(),
        "drift" => warm
            .chain((0..FRAMES).map(|k| Frame {
                brightness: 1.0 + 0.01 * (k + 1) as f64,
                measured: Some(k),
                ..plain(Some(0))
            }))
            .collect(),
        other => unreachable!("no event {other}"),
    }
}

/// What one probe's run of an event records.
struct Run {
    /// Σ squared error per method and measured frame, over normals and channels.
    se: Vec<[f64; FRAMES]>,
    abs_truth: [f64; FRAMES],
    /// `bmc-temporal`'s queries within 2σ per measured frame (of 3·Q).
    covered: [usize; FRAMES],
    /// Whether the probe reported a reset, per frame of the timeline.
    resets: Vec<bool>,
    /// Seconds spent tracing and in `TemporalProbe::pool`, and the paths traced.
    trace_secs: f64,
    pool_secs: f64,
    paths: usize,
}

/// The truth of a frame at a probe (scaled units).
fn frame_truth(f: &Frame, truth: &[Vec<Vec<V>>], probe: usize, scale: f64) -> Vec<V> {
    match f.state {
        None => vec![[0.0; 3]; truth[0][probe].len()],
        Some(s) => truth[s][probe].iter().map(|t| t.map(|c| c * scale * f.brightness)).collect(),
    }
}

/// One probe's run of one event at `N = NR + S` rays per frame.
#[allow(clippy::too_many_arguments)]
fn run_probe<const NR: usize, const S: usize>(
    frames: &[Frame],
    scenes: &[Scene],
    position: V,
    probe: usize,
    normals: &[V],
    truth: &[Vec<Vec<V>>],
    scale: f64,
    seed: u64,
) -> Run {
    let q = normals.len();
    let world: Vec<Vec3> =
        normals.iter().map(|n| Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32)).collect();
    let mut temporal = TemporalProbe::<NR, [f32; 3], Point, S>::new(seed);
    let mut run = Run {
        se: vec![[0.0; FRAMES]; METHODS.len()],
        abs_truth: [0.0; FRAMES],
        covered: [0; FRAMES],
        resets: Vec::with_capacity(frames.len()),
        trace_secs: 0.0,
        pool_secs: 0.0,
        paths: 0,
    };
    let mut oracle = vec![[0.0f64; 3]; q];
    let mut oracle_count = 0usize;
    let mut ema = [vec![[0.0f64; 3]; q], vec![[0.0f64; 3]; q]];
    let mut ddgi = [vec![[0.0f64; 3]; q], vec![[0.0f64; 3]; q]];
    let off = Scene::new(Setup { main: 0.0, ..Setup::BASE }, scale);
    for (t, f) in frames.iter().enumerate() {
        let drift_scene;
        let scene = match f.state {
            None => &off,
            Some(s) if f.brightness != 1.0 => {
                drift_scene = Scene::new(Setup { main: f.brightness, ..STATES[s] }, scale);
                &drift_scene
            }
            Some(s) => &scenes[s],
        };
        let mut rng = Rng::new(mix(seed, t as u64));
        let start = Instant::now();
        let to = |d: &Vec3| [d.x as f64, d.y as f64, d.z as f64];
        let trace =
            |d: &Vec3, rng: &mut Rng| scene.radiance(position, to(d), rng).map(|c| c as f32);
        let dirs = *temporal.directions();
        let rotated: [[f32; 3]; NR] = std::array::from_fn(|j| trace(&dirs[j], &mut rng));
        let sentinels: [[f32; 3]; S] =
            std::array::from_fn(|j| trace(&temporal.sentinels()[j], &mut rng));
        run.trace_secs += start.elapsed().as_secs_f64();
        run.paths += NR + S;
        let start = Instant::now();
        let change = temporal.pool(&rotated, &sentinels).expect("finite samples");
        run.pool_secs += start.elapsed().as_secs_f64();
        run.resets.push(change == Change::Reset);
        let cos: Vec<V> = world
            .iter()
            .map(|&n| {
                cosine_weighted_average(&dirs, &rotated, n).expect("unit normal").map(f64::from)
            })
            .collect();
        if f.change.is_some() {
            oracle_count = 0;
        }
        oracle_count += 1;
        let w = 1.0 / oracle_count as f64;
        for qi in 0..q {
            for c in 0..3 {
                oracle[qi][c] += (cos[qi][c] / f.brightness - oracle[qi][c]) * w;
            }
            if t == 0 {
                for b in ema.iter_mut().chain(ddgi.iter_mut()) {
                    b[qi] = cos[qi];
                }
            } else {
                for (e, h) in ema.iter_mut().zip([0.9, 0.97]) {
                    for c in 0..3 {
                        e[qi][c] = h * e[qi][c] + (1.0 - h) * cos[qi][c];
                    }
                }
                for (d, th) in ddgi.iter_mut().zip([(0.25, 0.10), (0.2, 1.0)]) {
                    d[qi] = ddgi_blend(d[qi], cos[qi], th);
                }
            }
        }
        let Some(k) = f.measured else { continue };
        let truth = frame_truth(f, truth, probe, scale);
        for (qi, &n) in world.iter().enumerate() {
            let tr = truth[qi];
            let e = temporal.irradiance(n).expect("unit normal");
            let v = e.value.map(f64::from);
            for c in 0..3 {
                let sigma = f64::from(e.variance[c]).max(0.0).sqrt();
                run.covered[k] += usize::from((v[c] - tr[c]).abs() <= 2.0 * sigma);
            }
            run.abs_truth[k] += tr.iter().map(|x| x.abs()).sum::<f64>();
            let est = [
                v,
                oracle[qi].map(|x| x * f.brightness),
                ema[0][qi],
                ema[1][qi],
                ddgi[0][qi],
                ddgi[1][qi],
            ];
            for (m, v) in est.iter().enumerate() {
                run.se[m][k] += (0..3).map(|c| (v[c] - tr[c]).powi(2)).sum::<f64>();
            }
        }
    }
    run
}

/// `run_probe` at one `N`.
type ProbeRunner = fn(&[Frame], &[Scene], V, usize, &[V], &[Vec<Vec<V>>], f64, u64) -> Run;

/// Everything measured: the runs per (event, N) (seeds × probes, seed-major), the references
/// and the scale.
struct Results {
    ns: Vec<usize>,
    seeds: usize,
    probes: Vec<V>,
    normals: usize,
    runs: Vec<Vec<Run>>,
    reference: Reference,
    scale: f64,
    reference_rays: usize,
    secs: (f64, f64),
    reread: ([f64; 3], usize),
}

impl Results {
    fn runs(&self, e: usize, n: usize) -> &[Run] {
        let ni = self.ns.iter().position(|&x| x == n).expect("a benchmarked N");
        &self.runs[e * self.ns.len() + ni]
    }

    fn count(&self) -> f64 {
        (self.seeds * self.probes.len() * 3 * self.normals) as f64
    }

    /// Relative RMSE of `method` at frame `k` (1-based).
    fn rel(&self, e: usize, n: usize, method: usize, k: usize) -> f64 {
        let runs = self.runs(e, n);
        let se: f64 = runs.iter().map(|r| r.se[method][k - 1]).sum();
        let abs: f64 = runs.iter().map(|r| r.abs_truth[k - 1]).sum();
        (se / self.count()).sqrt() / (abs / self.count())
    }

    fn best_peer(&self, e: usize, n: usize, k: usize) -> f64 {
        PEERS.iter().map(|&p| self.rel(e, n, p, k)).fold(f64::INFINITY, f64::min)
    }

    fn coverage(&self, e: usize, n: usize, ks: std::ops::RangeInclusive<usize>) -> f64 {
        let runs = self.runs(e, n);
        let covered: usize =
            runs.iter().map(|r| ks.clone().map(|k| r.covered[k - 1]).sum::<usize>()).sum();
        covered as f64 / (self.count() * ks.count() as f64)
    }

    /// Per probe: the oracle's RMSE (absolute) at frame 1 of event `e`.
    fn sigma1(&self, e: usize, n: usize) -> Vec<f64> {
        let runs = self.runs(e, n);
        let p = self.probes.len();
        (0..p)
            .map(|pi| {
                let se: f64 = (0..self.seeds).map(|s| runs[s * p + pi].se[1][0]).sum();
                (se / (self.seeds * 3 * self.normals) as f64).sqrt()
            })
            .collect()
    }
}

/// The true changes of an event: (frame, state before, state after).
fn changes(frames: &[Frame]) -> Vec<(usize, Option<usize>, Option<usize>)> {
    frames
        .iter()
        .enumerate()
        .filter(|(_, f)| f.change.is_some())
        .map(|(t, f)| (t, frames[t - 1].state, f.state))
        .collect()
}

/// Detection of one event's changes (slot by slot): per slot the counts within 1, 2, 4
/// frames, never, and of all changed probes' changes; the false resets and quiet updates.
struct Detection {
    slots: Vec<([usize; 3], usize, usize)>,
    false_resets: usize,
    quiet: usize,
    /// Per slot: the changed probes.
    changed: Vec<usize>,
}

fn detection(r: &Results, e: usize, n: usize) -> Detection {
    let frames = timeline(EVENTS[e]);
    let runs = r.runs(e, n);
    let p = r.probes.len();
    let (stat, own) = (r.sigma1(0, n), r.sigma1(e, n));
    let scaled = |state: Option<usize>, probe: usize| -> Vec<V> {
        match state {
            None => vec![[0.0; 3]; r.normals],
            Some(s) => r.reference.truth[s][probe].iter().map(|t| t.map(|c| c * r.scale)).collect(),
        }
    };
    let ch = changes(&frames);
    let mut d = Detection { slots: Vec::new(), false_resets: 0, quiet: 0, changed: Vec::new() };
    // Quiet: every frame after the first before the first change (the warm start, `static`,
    // `drift`), and from its change on for a probe whose change was below its one-frame error.
    let first = ch.first().map_or(frames.len(), |c| c.0);
    for run in runs {
        d.quiet += first - 1;
        d.false_resets += run.resets[1..first].iter().filter(|&&x| x).count();
    }
    for (i, &(at, before, after)) in ch.iter().enumerate() {
        let end = ch.get(i + 1).map_or(frames.len(), |c| c.0);
        let (mut within, mut never, mut all, mut changed) = ([0usize; 3], 0, 0, 0);
        for pi in 0..p {
            let (a, b) = (scaled(before, pi), scaled(after, pi));
            let size = (a
                .iter()
                .zip(&b)
                .map(|(x, y)| (0..3).map(|c| (x[c] - y[c]).powi(2)).sum::<f64>())
                .sum::<f64>()
                / (3 * r.normals) as f64)
                .sqrt();
            let moved = size > stat[pi].max(own[pi]);
            changed += usize::from(moved);
            for s in 0..r.seeds {
                let resets = &r.runs(e, n)[s * p + pi].resets[at..end];
                if moved {
                    all += 1;
                    match resets.iter().position(|&x| x) {
                        Some(k) => {
                            for (j, bar) in [1, 2, 4].into_iter().enumerate() {
                                within[j] += usize::from(k < bar);
                            }
                        }
                        None => never += 1,
                    }
                } else {
                    d.quiet += resets.len();
                    d.false_resets += resets.iter().filter(|&&x| x).count();
                }
            }
        }
        d.slots.push((within, never, all));
        d.changed.push(changed);
    }
    d
}

fn run(args: &Args) -> Result<(), Box<dyn Error>> {
    let start = Instant::now();
    let threads = args.threads.count();
    let probes = scene::probe_grid();
    let mut rng = Rng::new(SEED_NORMALS);
    let normals: Vec<V> = (0..args.normals).map(|_| rng.uniform_sphere()).collect();
    let reference = reference(&probes, &normals, args.reference_rays, threads);
    let reference_secs = start.elapsed().as_secs_f64();
    // Mean irradiance (luminance) 1 over the probes and normals of the static scene.
    let (sum, count) = reference.truth[0]
        .iter()
        .flatten()
        .fold((0.0, 0usize), |(s, c), t| (s + luminance(*t), c + 1));
    let scale = count as f64 / sum;
    let scenes: Vec<Scene> = STATES.iter().map(|&s| Scene::new(s, scale)).collect();
    let reread = reread_noise(&scenes[0], &probes, threads);
    let ns: Vec<usize> = if args.quick { vec![16, 64] } else { NS.to_vec() };
    let p = probes.len();
    let jobs: Vec<(usize, usize, usize, usize)> = (0..EVENTS.len())
        .flat_map(|e| {
            let ns = &ns;
            ns.iter().flat_map(move |&n| {
                (0..args.seeds).flat_map(move |s| (0..p).map(move |pi| (e, n, s, pi)))
            })
        })
        .collect();
    let timelines: Vec<Vec<Frame>> = EVENTS.iter().map(|e| timeline(e)).collect();
    let runs_start = Instant::now();
    let mut flat = parallel::parallel_map(&jobs, threads, |_, &(e, n, s, pi)| {
        let seed = mix(SEED_RUNS, (((e * 1000 + n) * 1000 + s) * 1000 + pi) as u64);
        let go = |f: ProbeRunner| {
            f(&timelines[e], &scenes, probes[pi], pi, &normals, &reference.truth, scale, seed)
        };
        match n {
            16 => go(run_probe::<15, 1>),
            64 => go(run_probe::<62, 2>),
            256 => go(run_probe::<252, 4>),
            _ => unreachable!("N = {n} is not benchmarked"),
        }
    })
    .into_iter();
    let runs_secs = runs_start.elapsed().as_secs_f64();
    let runs: Vec<Vec<Run>> = (0..EVENTS.len() * ns.len())
        .map(|_| flat.by_ref().take(args.seeds * p).collect())
        .collect();
    let results = Results {
        ns,
        seeds: args.seeds,
        probes,
        normals: args.normals,
        runs,
        reference,
        scale,
        reference_rays: args.reference_rays,
        secs: (reference_secs, runs_secs),
        reread,
    };
    let secs = start.elapsed().as_secs_f64();
    let report = report::render(args, &results, secs, threads);
    print!("{report}");
    if let Some(csv) = &args.csv {
        if let Some(dir) = csv.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(csv, csv_rows(&results))?;
        eprintln!("wrote {}", csv.display());
    }
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)?;
        std::fs::write(dir.join("room.md"), &report)?;
        eprintln!("wrote {}", dir.join("room.md").display());
    }
    Ok(())
}

/// A detection row's shares (within 1, 2, 4, never), empty without a change.
fn shares(slot: Option<&([usize; 3], usize, usize)>) -> [String; 4] {
    match slot {
        Some((w, never, all)) if *all > 0 => {
            let d = *all as f64;
            [w[0], w[1], w[2], *never].map(|x| format!("{:.4}", x as f64 / d))
        }
        _ => Default::default(),
    }
}

/// The detection rows of an event: (label, slot); the slot None for an event without a change.
fn detection_rows(event: &str) -> Vec<(String, Option<usize>)> {
    match event {
        "static" | "drift" => vec![(event.to_string(), None)],
        "off-on" => vec![("off-on-off".to_string(), Some(0)), ("off-on".to_string(), Some(1))],
        _ => vec![(event.to_string(), Some(0))],
    }
}

fn csv_rows(r: &Results) -> String {
    let mut s = String::new();
    for (e, event) in EVENTS.iter().enumerate() {
        for &n in &r.ns {
            for (m, method) in METHODS.iter().enumerate() {
                for k in 1..=FRAMES {
                    let cov = if m == 0 {
                        format!("{:.4}", r.coverage(e, n, k..=k))
                    } else {
                        String::new()
                    };
                    let _ = writeln!(
                        s,
                        "room,{event},{method},{n},{k},{:.6e},{cov}",
                        r.rel(e, n, m, k)
                    );
                }
            }
        }
    }
    for (e, event) in EVENTS.iter().enumerate() {
        for &n in &r.ns {
            let d = detection(r, e, n);
            let per = 1000.0 * d.false_resets as f64 / d.quiet.max(1) as f64;
            for (label, slot) in detection_rows(event) {
                let [a, b, c, never] = shares(slot.and_then(|i| d.slots.get(i)));
                let _ = writeln!(s, "room-detect,{label},{n},{a},{b},{c},{never},{per:.3}");
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each event's timeline: its length, its true changes (frame, before, after) and its
    /// measured frames.
    #[test]
    fn timelines_put_the_changes_where_the_events_say() {
        for event in EVENTS {
            let frames = timeline(event);
            let measured: Vec<usize> = frames.iter().filter_map(|f| f.measured).collect();
            assert_eq!(measured, (0..FRAMES).collect::<Vec<_>>(), "{event}");
            let ch = changes(&frames);
            match event {
                "static" => assert!(frames.len() == FRAMES && ch.is_empty()),
                "drift" => {
                    assert!(frames.len() == WARM + FRAMES && ch.is_empty());
                    assert!((frames[WARM + 9].brightness - 1.1).abs() < 1e-12);
                }
                "off-on" => {
                    assert_eq!(frames.len(), WARM + OFF + FRAMES);
                    assert_eq!(ch, [(WARM, Some(0), None), (WARM + OFF, None, Some(0))]);
                    assert_eq!(frames[WARM + OFF].measured, Some(0));
                }
                _ => {
                    let state = ["corner-light", "block-moved", "wall-blue"]
                        .iter()
                        .position(|e| *e == event)
                        .expect("an event with one change")
                        + 1;
                    assert_eq!(frames.len(), WARM + FRAMES, "{event}");
                    assert_eq!(ch, [(WARM, Some(0), Some(state))], "{event}");
                }
            }
        }
    }

    /// The reference of a probe: two halves agree within their noise, and a normal facing the
    /// light from under it gets more than one facing the floor.
    #[test]
    fn reference_halves_agree_and_face_the_light() {
        let scene = Scene::new(Setup::BASE, 1.0);
        let p = [0.278, 0.3, 0.28];
        let normals = [[0.0, 1.0, 0.0], [0.0, -1.0, 0.0]];
        let a = reference_half(&scene, p, &normals, 20_000, 1);
        let b = reference_half(&scene, p, &normals, 20_000, 2);
        // Measured: the halves within 1 % of each other; up / down ≈ 3.
        for c in 0..3 {
            assert!((a[0][c] / b[0][c] - 1.0).abs() < 0.03, "{a:?} {b:?}");
            assert!(a[0][c] > 2.0 * a[1][c], "{a:?}");
        }
    }
}
