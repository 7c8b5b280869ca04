//! Temporal accumulation (issue #14): a probe that takes a freshly rotated set of N samples
//! every frame and blends over time, on static lighting and across a switch of environment.
//!
//! ```text
//! cargo eval temporal                      # report to stdout
//! cargo eval temporal -- --out docs        # writes docs/temporal.md
//! cargo eval temporal -- a.hdr b.hdr --csv rows.csv
//! ```
//!
//! Each sequence rotates the probe's sphere SF set by a fresh seeded random rotation every
//! update (`RotationSequence::next_rotation`, what a renderer does to decorrelate frames),
//! samples the tier's map at the rotated directions (nearest pixel, luminance) and answers
//! irradiance for 128 seeded random normals after every update; error against every-pixel
//! ground truth, relative RMSE over sequences × normals.
//! - `static`: 32 updates of one map (4 sequences per map).
//! - `switch`: 16 updates of map A (the previous map in the argument list, cyclically), then
//!   map B; `k` counts the updates after the switch and `<map>` is B.
//!
//! Methods:
//! - `bmc-temporal`: `TemporalProbe`, the probe's SH L2 posterior combined across updates by
//!   inverse variance, with an innovation test against the error bar (see its docs);
//! - `hysteresis-0.97`, `hysteresis-0.9`: DDGI's fixed blend `E ← h·E + (1 − h)·E_new` of the
//!   cosine-weighted average of each update's samples (the first update is taken whole);
//! - `bmc-hysteresis-0.97`: the same blend of `Probe::irradiance`.
//!
//! Rows of `--csv FILE`: `temporal,<static|switch>,<tier>,<method>,<n>,<k>,<map>,<rel_rmse>`.
//! Tiers `clamp` and `smooth` as in `eval/src/bin/accuracy.rs`.

#[allow(dead_code)]
#[path = "../common/cli.rs"]
mod cli;
#[allow(dead_code)]
#[path = "../../../examples/common/compare.rs"]
mod compare;
#[path = "../common/parallel.rs"]
mod parallel;
#[allow(dead_code)]
#[path = "../common/tiers.rs"]
mod tiers;

use std::error::Error;
use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Parser;
use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::probe::{cosine_weighted_average, Probe, ProbeSize};
use sphere_quadrature::temporal::TemporalProbe;
use sphere_quadrature::{RotationSequence, Vec3};

const TIERS: [&str; 2] = ["clamp", "smooth"];
const NS: [usize; 3] = [16, 64, 256];
const STATIC_UPDATES: usize = 32;
const SWITCH_BEFORE: usize = 16;
const SWITCH_AFTER: usize = 16;
const METHODS: [&str; 4] =
    ["bmc-temporal", "hysteresis-0.97", "hysteresis-0.9", "bmc-hysteresis-0.97"];
/// `--threshold`: the temporal probe's innovation threshold, a whole χ².
static THRESHOLD: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(30);
const SEED_NORMALS: u64 = 0x7E3A_0001;
const SEED_ROTATIONS: u64 = 0x7E3A_0002;

/// temporal benchmark (issue #14): a probe updated every frame with fresh rotations
#[derive(Parser)]
#[command(bin_name = "cargo eval temporal --")]
struct Args {
    /// Equirectangular .hdr maps (default: examples/envmaps/*.hdr); the switch
    /// sequence goes from each map's predecessor in this list to it
    #[arg(value_name = "MAPS", value_parser = cli::map_file, verbatim_doc_comment)]
    maps: Vec<PathBuf>,
    /// Rows temporal,<static|switch>,<tier>,<method>,<n>,<k>,<map>,<rel_rmse>
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Also write DIR/temporal.md (`--out docs` updates the docs)
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Independent sequences per map
    #[arg(long, value_name = "S", default_value_t = 4)]
    #[arg(value_parser = cli::positive)]
    sequences: usize,
    /// Query normals per map
    #[arg(long, value_name = "Q", default_value_t = 128)]
    #[arg(value_parser = cli::positive)]
    normals: usize,
    /// The temporal probe's innovation threshold, a whole χ² (default 30,
    /// temporal::DEFAULT_THRESHOLD)
    #[arg(long, value_name = "T", verbatim_doc_comment)]
    #[arg(value_parser = clap::value_parser!(u32).range(1..))]
    threshold: Option<u32>,
    /// Two maps, N = 16 and 64, one sequence, 32 normals (CI)
    #[arg(long)]
    quick: bool,
    #[command(flatten)]
    threads: cli::Threads,
}

/// The arguments, defaults filled in.
fn parse_args() -> Result<Args, Box<dyn Error>> {
    let mut a = Args::parse();
    if let Some(t) = a.threshold {
        THRESHOLD.store(t, std::sync::atomic::Ordering::Relaxed);
    }
    if a.maps.is_empty() {
        a.maps = cli::all_bundled_maps_or(a.quick, ["apartment", "lobby"])?;
    }
    if a.quick {
        a.sequences = 1;
        a.normals = a.normals.min(32);
    }
    Ok(a)
}

fn main() {
    cli::run_main("temporal", parse_args, run);
}

/// Per normal, per pixel: the irradiance truth weights of one grid.
type TruthWeights = Vec<Vec<f64>>;

/// One map in one tier: the map and the truth at every query normal.
struct Scene {
    map: EnvMap,
    truth: Vec<f64>,
}

/// Squared errors per (method, k) and Σ|truth| per k, of one (tier, map, N, sequence kind).
#[derive(Clone)]
struct Curve {
    se: Vec<Vec<f64>>,
    abs_truth: Vec<f64>,
    count: Vec<usize>,
}

impl Curve {
    fn new(len: usize) -> Self {
        Self {
            se: vec![vec![0.0; len]; METHODS.len()],
            abs_truth: vec![0.0; len],
            count: vec![0; len],
        }
    }

    fn rel(&self, method: usize, k: usize) -> f64 {
        (self.se[method][k] / self.count[k] as f64).sqrt()
            / (self.abs_truth[k] / self.count[k] as f64)
    }
}

/// The methods' state through one sequence.
struct Methods<const N: usize>
where
    Size<N>: ProbeSize,
{
    probe: Probe<N>,
    temporal: TemporalProbe<N>,
    blends: [Option<Vec<f64>>; 3],
}

impl<const N: usize> Methods<N>
where
    Size<N>: ProbeSize,
{
    /// `seed` seeds the temporal probe's rotations: the same sequence as the benchmark's
    /// `RotationSequence::new(seed)`, so every method sees the same samples.
    fn new(seed: u64) -> Self {
        let temporal = TemporalProbe::new(seed)
            .with_threshold(THRESHOLD.load(std::sync::atomic::Ordering::Relaxed) as f32)
            .expect("a positive threshold");
        Self { probe: Probe::new(), temporal, blends: [None, None, None] }
    }

    /// One update from `map` under a fresh rotation; the estimates of every method at every
    /// normal, `out[method][q]`.
    fn step(
        &mut self,
        map: &EnvMap,
        rotations: &mut RotationSequence,
        normals: &[Vec3],
        out: &mut [Vec<f64>],
    ) {
        self.probe
            .set_rotation(rotations.next_rotation())
            .expect("a random rotation is orthonormal");
        let dirs = *self.probe.directions();
        let samples: [f32; N] = std::array::from_fn(|j| {
            let d = dirs[j];
            luminance(map.radiance([d.x as f64, d.y as f64, d.z as f64])) as f32
        });
        self.probe.update(&samples).expect("finite samples");
        let cos: Vec<f64> = normals
            .iter()
            .map(|&n| f64::from(cosine_weighted_average(&dirs, &samples, n).expect("unit normal")))
            .collect();
        let bmc: Vec<f64> = normals
            .iter()
            .map(|&n| f64::from(self.probe.irradiance(n).expect("unit normal").value))
            .collect();
        for (slot, (h, fresh)) in
            self.blends.iter_mut().zip([(0.97, &cos), (0.9, &cos), (0.97, &bmc)])
        {
            match slot {
                Some(acc) => {
                    acc.iter_mut().zip(fresh).for_each(|(a, f)| *a = h * *a + (1.0 - h) * f)
                }
                None => *slot = Some(fresh.clone()),
            }
        }
        assert!(self.temporal.directions() == &dirs, "the temporal probe's rotation differs");
        self.temporal.update(&samples).expect("finite samples");
        for (o, &n) in out[0].iter_mut().zip(normals) {
            *o = f64::from(self.temporal.irradiance(n).expect("unit normal").value);
        }
        for (o, b) in out[1..].iter_mut().zip(&self.blends) {
            o.clone_from(b.as_ref().expect("set above"));
        }
    }
}

fn run_sequence<const N: usize>(
    scenes: &[(&Scene, usize)],
    normals: &[Vec3],
    seed: u64,
    curve: &mut Curve,
) where
    Size<N>: ProbeSize,
{
    let mut methods = Methods::<N>::new(seed);
    let mut rotations = RotationSequence::new(seed);
    let mut est = vec![vec![0.0; normals.len()]; METHODS.len()];
    let mut k = 0;
    for &(scene, updates) in scenes {
        for _ in 0..updates {
            methods.step(&scene.map, &mut rotations, normals, &mut est);
            if let (Some(t), Some(c)) = (curve.abs_truth.get_mut(k), curve.count.get_mut(k)) {
                *t += scene.truth.iter().map(|x| x.abs()).sum::<f64>();
                *c += normals.len();
                for (m, e) in est.iter().enumerate() {
                    curve.se[m][k] +=
                        e.iter().zip(&scene.truth).map(|(e, t)| (e - t).powi(2)).sum::<f64>();
                }
            }
            k += 1;
        }
    }
}

/// `static` and `switch` curves of one tier, map and N.
fn curves(
    n: usize,
    a: &Scene,
    b: &Scene,
    normals: &[Vec3],
    sequences: usize,
    seed: u64,
) -> (Curve, Curve) {
    let mut stat = Curve::new(STATIC_UPDATES);
    let mut switch = Curve::new(SWITCH_AFTER);
    macro_rules! go {
        ($n:literal) => {{
            for s in 0..sequences {
                let seed = seed ^ (s as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
                run_sequence::<$n>(&[(b, STATIC_UPDATES)], normals, seed, &mut stat);
                let mut full = Curve::new(SWITCH_BEFORE + SWITCH_AFTER);
                run_sequence::<$n>(
                    &[(a, SWITCH_BEFORE), (b, SWITCH_AFTER)],
                    normals,
                    seed ^ 1,
                    &mut full,
                );
                for m in 0..METHODS.len() {
                    for k in 0..SWITCH_AFTER {
                        switch.se[m][k] += full.se[m][SWITCH_BEFORE + k];
                    }
                }
                for k in 0..SWITCH_AFTER {
                    switch.abs_truth[k] += full.abs_truth[SWITCH_BEFORE + k];
                    switch.count[k] += full.count[SWITCH_BEFORE + k];
                }
            }
        }};
    }
    match n {
        16 => go!(16),
        64 => go!(64),
        256 => go!(256),
        _ => unreachable!("N = {n} is not benchmarked"),
    }
    (stat, switch)
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
    let scenes: Vec<[Scene; 2]> = loaded
        .into_iter()
        .map(|tiers| {
            tiers.map(|map| {
                let w =
                    &grids.iter().find(|(g, _)| *g == (map.width, map.height)).expect("weights").1;
                let truth = compare::truths(&map, w);
                Scene { map, truth }
            })
        })
        .collect();
    let ns: Vec<usize> = if args.quick { vec![16, 64] } else { NS.to_vec() };
    let count = scenes.len();
    let jobs: Vec<(usize, usize, usize)> = (0..TIERS.len())
        .flat_map(|t| ns.iter().flat_map(move |&n| (0..count).map(move |m| (t, n, m))))
        .collect();
    let results = parallel::parallel_map(&jobs, threads, |_, &(t, n, m)| {
        let prev = (m + scenes.len() - 1) % scenes.len();
        curves(
            n,
            &scenes[prev][t],
            &scenes[m][t],
            &normals,
            args.sequences,
            SEED_ROTATIONS ^ (n as u64) << 32 ^ m as u64,
        )
    });
    let report = render(args, &names, &ns, &jobs, &results, start.elapsed().as_secs_f64());
    print!("{report}");
    if let Some(csv) = &args.csv {
        if let Some(dir) = csv.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        let mut s = String::from("bench,sequence,tier,method,n,k,map,rel_rmse\n");
        for (&(t, n, m), (stat, switch)) in jobs.iter().zip(&results) {
            for (kind, curve) in [("static", stat), ("switch", switch)] {
                for (mi, method) in METHODS.iter().enumerate() {
                    for k in 0..curve.count.len() {
                        let _ = writeln!(
                            s,
                            "temporal,{kind},{},{method},{n},{},{},{:.6e}",
                            TIERS[t],
                            k + 1,
                            names[m],
                            curve.rel(mi, k)
                        );
                    }
                }
            }
        }
        std::fs::write(csv, s)?;
        eprintln!("wrote {}", csv.display());
    }
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)?;
        std::fs::write(dir.join("temporal.md"), &report)?;
        eprintln!("wrote {}", dir.join("temporal.md").display());
    }
    Ok(())
}

/// Mean over maps of the relative RMSE of `method` at update `k` (1-based).
fn mean_rel(curves: &[&Curve], method: usize, k: usize) -> f64 {
    curves.iter().map(|c| c.rel(method, k - 1)).sum::<f64>() / curves.len().max(1) as f64
}

fn render(
    args: &Args,
    names: &[String],
    ns: &[usize],
    jobs: &[(usize, usize, usize)],
    results: &[(Curve, Curve)],
    secs: f64,
) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Temporal accumulation (issue #14)\n");
    let _ = writeln!(
        md,
        "Generated by `cargo eval temporal` ({} sequences per map, {} normals; {:.0} s). Maps: {}. \
         Relative RMSE of irradiance (luminance) after update k, mean over maps; see the program's docs.\n",
        args.sequences,
        args.normals,
        secs,
        names.join(", ")
    );
    let static_ks = [1usize, 2, 4, 8, 16, 32];
    let switch_ks = [1usize, 2, 4, 8, 16];
    for (t, tier) in TIERS.iter().enumerate() {
        for &n in ns {
            let pick = |f: fn(&(Curve, Curve)) -> &Curve| -> Vec<&Curve> {
                jobs.iter()
                    .zip(results)
                    .filter(|((jt, jn, _), _)| *jt == t && *jn == n)
                    .map(|(_, r)| f(r))
                    .collect()
            };
            let stat = pick(|r| &r.0);
            let switch = pick(|r| &r.1);
            let _ = writeln!(md, "## `{tier}`, N = {n}\n");
            let _ = write!(
                md,
                "| method | static: k = {} |",
                static_ks.map(|k| k.to_string()).join(" | ")
            );
            let _ = writeln!(md, " switch: k = {} |", switch_ks.map(|k| k.to_string()).join(" | "));
            let _ = writeln!(md, "|---|{}", "---|".repeat(static_ks.len() + switch_ks.len()));
            for (mi, method) in METHODS.iter().enumerate() {
                let _ = write!(md, "| `{method}` |");
                for &k in &static_ks {
                    let _ = write!(md, " {:.1}% |", 100.0 * mean_rel(&stat, mi, k));
                }
                for &k in &switch_ks {
                    let _ = write!(md, " {:.1}% |", 100.0 * mean_rel(&switch, mi, k));
                }
                let _ = writeln!(md);
            }
            let _ = writeln!(md);
        }
    }
    md
}
