//! The missing-samples benchmark of issue #14 (item 3): irradiance from a probe some of whose
//! samples are missing, `Probe::update_masked` against the cosine-weighted average of the
//! valid samples, on the `clamp` tier of real maps.
//!
//! ```text
//! cargo eval missing                        # ten bundled maps, report to stdout
//! cargo eval missing -- --out docs          # regenerates docs/missing.md
//! cargo eval missing -- --quick --out target/missing   # CI smoke run
//! cargo eval missing -- a.hdr b.hdr         # your own maps
//! ```
//!
//! Options (`--help`): map paths as positional arguments, `--out DIR` (writes
//! `DIR/missing.md`; without it the report goes to stdout and nothing is written), `--csv
//! FILE` (the rows below), `--quick` (2 maps, N = 64 only, 64 normals, 8 rotations), `--threads
//! T` (default: all cores).
//!
//! # Setting
//! - Lighting: the `clamp` tier (luminance clamped at 30× the map's solid-angle mean,
//!   `compare::clamped`), nearest-pixel samples; ground truth of the luminance irradiance at
//!   256 seeded random normals summed over every pixel with exact cosine weights
//!   (`compare::weights`).
//! - Probe: the RGB `Probe<N, [f32; 3], Point, M>` (`M = N/2`, enough for 50 % missing) on the
//!   sphere SF set under 32 seeded random rotations per map, `N` = 16, 64, 256.
//! - Missing samples: for every rotation and missing fraction `f` (0, 5, 25, 50 %), a seeded
//!   random subset of `round(f·N)` of the N samples is missing (uniform over the subsets; the
//!   same subsets for every map). The missing samples are set to NaN before the update, which
//!   must not read them.
//! - Methods, on the same valid samples:
//!   - `bmc-masked`: `Probe::update_masked` (per-probe maximum-likelihood member), the
//!     luminance of `Probe::irradiance`;
//!   - `cos-avg-valid`: `probe::cosine_weighted_average` of the valid samples' luminance,
//!     `π·Σ max(0, n·xⱼ)Yⱼ / Σ max(0, n·xⱼ)` over the valid `j`.
//!
//! Relative RMSE of a map = RMSE over rotations × normals / mean |truth|. The probe's
//! hyperparameters were trained on apartment, bridge, forest and lab; city, dawn, hall,
//! lobby, night and park are held out. Per N and fraction the report gives, over the held-out
//! maps and over all maps: the mean over maps of bmc-masked / cos-avg-valid per map, the
//! ratio of the mean errors, the worst map, and the 2σ coverage of BMC's luminance error bar
//! (exact: `Probe::irradiance_variance`; O(1): `Probe::irradiance`, which after a masked update
//! is the full set's direction average and does not see the holes). Then the target of issue
//! #14 and the host cost of the masked update for several missing counts and capacities.
//!
//! `--csv FILE` writes a header and one row per (N, fraction, method, map):
//! `missing,clamp,<fraction>,<n>,<method>,<map>,<rel_rmse>` with methods `bmc-masked` and
//! `cos-avg-valid`.

use sphere_quadrature_eval::{cli, compare, luminance_bar, parallel, report};

use clap::Parser;
use luminance_bar::LuminanceBar;
use parallel::parallel_map;
use report::{pct, ratio, Case, MapRow, Maps};
use std::error::Error;
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::footprint::Point;
use sphere_quadrature::probe::{cosine_weighted_average, Probe, ProbeSize};
use sphere_quadrature::{RotationSequence, Vec3};

/// Sample counts (`--quick`: 64 only).
const NS: [usize; 3] = [16, 64, 256];
/// Missing fractions.
const FRACTIONS: [f64; 4] = [0.0, 0.05, 0.25, 0.5];
/// The methods, as the CSV rows name them.
const METHODS: [&str; 2] = ["bmc-masked", "cos-avg-valid"];
const TIER: &str = "clamp";
/// The issue's target: at 25 % missing, N = 64, BMC ≤ 0.9× the valid-sample average.
const TARGET: (f64, usize, f64) = (0.25, 64, 0.9);

const SEED_NORMALS: u64 = 0x3155_0001;
const SEED_ROTATIONS: u64 = 0x3155_0002;
const SEED_MASKS: u64 = 0x3155_0003;

struct Params {
    ns: Vec<usize>,
    normals: usize,
    rotations: usize,
    threads: usize,
}

struct Scene {
    name: String,
    held_out: bool,
    map: EnvMap,
    truth: Vec<f64>,
}

/// One scene at one N and fraction.
#[derive(Clone, Copy, Debug, Default)]
struct Outcome {
    /// Relative RMSE of `bmc-masked` and `cos-avg-valid`.
    rel: [f64; 2],
    /// BMC queries within 2σ of the luminance bar: exact, O(1).
    covered: [usize; 2],
    queries: usize,
}

fn vec32(d: [f64; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

fn vec64(d: Vec3) -> [f64; 3] {
    [d.x as f64, d.y as f64, d.z as f64]
}

/// How many of `n` samples fraction `f` leaves out.
fn missing_count(f: f64, n: usize) -> usize {
    (f * n as f64).round() as usize
}

/// The validity mask of rotation `r` at fraction index `fi`: a seeded uniform random subset
/// of `m` of the `N` samples is missing (partial Fisher–Yates).
fn mask<const N: usize>(m: usize, fi: usize, r: usize) -> [bool; N] {
    let mut rng = Rng::new(SEED_MASKS ^ ((N as u64) << 32) ^ ((fi as u64) << 24) ^ r as u64);
    let mut order: Vec<usize> = (0..N).collect();
    for i in 0..m.min(N) {
        let j = i + (rng.next_u64() % (N - i) as u64) as usize;
        order.swap(i, j);
    }
    let mut valid = [true; N];
    for &j in &order[..m.min(N)] {
        valid[j] = false;
    }
    valid
}

/// Both methods on one scene at one N, every fraction.
fn evaluate<const N: usize, const M: usize>(
    scene: &Scene,
    normals: &[[f64; 3]],
    p: &Params,
) -> Vec<Outcome>
where
    Size<N>: ProbeSize,
{
    let truth = &scene.truth;
    let mean_abs = truth.iter().map(|t| t.abs()).sum::<f64>() / truth.len() as f64;
    let normals32: Vec<Vec3> = normals.iter().map(|&n| vec32(n)).collect();
    let mut rotations = RotationSequence::new(SEED_ROTATIONS ^ N as u64);
    let mut probe = Probe::<N, [f32; 3], Point, M>::new();
    let mut se = vec![[0.0f64; 2]; FRACTIONS.len()];
    let mut out = vec![Outcome::default(); FRACTIONS.len()];
    for r in 0..p.rotations {
        probe.set_rotation(rotations.next_rotation()).expect("a rotation");
        let dirs = *probe.directions();
        let rgb: [[f32; 3]; N] = dirs.map(|d| scene.map.radiance(vec64(d)).map(|c| c as f32));
        for (fi, &f) in FRACTIONS.iter().enumerate() {
            let valid = mask::<N>(missing_count(f, N), fi, r);
            let samples: [[f32; 3]; N] =
                core::array::from_fn(|i| if valid[i] { rgb[i] } else { [f32::NAN; 3] });
            probe.update_masked(&samples, &valid).expect("valid samples are finite");
            let bar = LuminanceBar::new(&probe);
            let (vdirs, vlum): (Vec<Vec3>, Vec<f32>) = dirs
                .iter()
                .zip(&rgb)
                .zip(&valid)
                .filter(|(_, &ok)| ok)
                .map(|((&d, c), _)| (d, luminance(c.map(f64::from)) as f32))
                .unzip();
            for (&n, &t) in normals32.iter().zip(truth) {
                let e = probe.irradiance(n).expect("unit normal");
                let (bmc, var_fast) = bar.estimate(&e);
                let exact = bar.exact(&e, probe.irradiance_variance(n).expect("unit normal"));
                let (_, var_exact) = bar.estimate(&exact);
                let cos =
                    f64::from(cosine_weighted_average(&vdirs, &vlum, n).expect("unit normal"));
                se[fi][0] += (bmc - t).powi(2);
                se[fi][1] += (cos - t).powi(2);
                let err = (bmc - t).abs();
                out[fi].covered[0] += usize::from(err <= 2.0 * var_exact.sqrt());
                out[fi].covered[1] += usize::from(err <= 2.0 * var_fast.sqrt());
                out[fi].queries += 1;
            }
        }
    }
    for (o, s) in out.iter_mut().zip(&se) {
        let count = o.queries.max(1) as f64;
        o.rel = s.map(|x| (x / count).sqrt() / mean_abs);
    }
    out
}

fn evaluate_n(scene: &Scene, normals: &[[f64; 3]], p: &Params, n: usize) -> Vec<Outcome> {
    match n {
        16 => evaluate::<16, 8>(scene, normals, p),
        64 => evaluate::<64, 32>(scene, normals, p),
        256 => evaluate::<256, 128>(scene, normals, p),
        _ => unreachable!("N = {n} is not measured"),
    }
}

/// Host time of one call, in µs: the fastest of `rounds` timings of `reps` calls (the least
/// disturbed by other jobs on shared cores).
fn time_us(reps: usize, rounds: usize, mut f: impl FnMut()) -> f64 {
    (0..rounds)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..reps {
                f();
            }
            start.elapsed().as_secs_f64() * 1e6 / reps as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// `update` and `update_masked` of an RGB probe of a smooth sky at one N with capacity `M`:
/// `(m, µs)` for every missing count in `counts` (0 is `update`).
fn cost<const N: usize, const M: usize>(counts: &[usize], reps: usize) -> Vec<(usize, f64)>
where
    Size<N>: ProbeSize,
{
    let mut probe = Probe::<N, [f32; 3], Point, M>::new();
    let y: [[f32; 3]; N] =
        probe.directions().map(|d| [1.0 + 0.5 * d.z, 0.8 + 0.3 * d.x * d.y, 0.5 - 0.2 * d.x]);
    counts
        .iter()
        .map(|&m| {
            let valid = mask::<N>(m, 9, 0);
            let us = time_us(reps, 9, || {
                if m == 0 {
                    black_box(&mut probe).update(black_box(&y)).expect("finite");
                } else {
                    black_box(&mut probe).update_masked(black_box(&y), &valid).expect("finite");
                }
            });
            (m, us)
        })
        .collect()
}

fn cost_table(md: &mut String, quick: bool) {
    let reps = if quick { 5 } else { 200 };
    let mut rows: Vec<(usize, usize, usize, f64)> = Vec::new();
    for (m, us) in cost::<16, 8>(&[0, 1, 4, 8], reps * 8) {
        rows.push((16, 8, m, us));
    }
    for (m, us) in cost::<64, 32>(&[0, 3, 8, 16, 32], reps) {
        rows.push((64, 32, m, us));
    }
    for (m, us) in cost::<64, 4>(&[0, 3], reps) {
        rows.push((64, 4, m, us));
    }
    if !quick {
        for (m, us) in cost::<256, 128>(&[0, 13, 64, 128], 4) {
            rows.push((256, 128, m, us));
        }
    }
    let base = |n: usize, cap: usize| {
        rows.iter().find(|r| r.0 == n && r.1 == cap && r.2 == 0).map_or(f64::NAN, |r| r.3)
    };
    md.push_str(
        "## Cost\n\nHost time of one update of the RGB probe (`[f32; 3]`, every family member \
         tried), the fastest of 9 rounds on this machine (shared cores: a few per cent). `m = 0` is \
         `Probe::update`. The work grows with the missing count m (m unit-vector substitutions \
         and an m × m factor per member); the capacity M costs memory, `4M² + 6M` bytes in the \
         probe and `4·M·N + 8M²` of stack during the update, and the copies of the M × M \
         factor. The Cortex-M4 instruction counts at N = 64 are in docs/costs.md.\n\n\
         | N | capacity M | missing m | µs per update | × `update` | probe bytes |\n\
         | ---: | ---: | ---: | ---: | ---: | ---: |\n",
    );
    for &(n, cap, m, us) in &rows {
        let bytes = match (n, cap) {
            (16, 8) => std::mem::size_of::<Probe<16, [f32; 3], Point, 8>>(),
            (64, 32) => std::mem::size_of::<Probe<64, [f32; 3], Point, 32>>(),
            (64, 4) => std::mem::size_of::<Probe<64, [f32; 3], Point, 4>>(),
            _ => std::mem::size_of::<Probe<256, [f32; 3], Point, 128>>(),
        };
        let _ = writeln!(
            md,
            "| {n} | {cap} | {m} | {us:.1} | {} | {bytes} |",
            ratio(us / base(n, cap))
        );
    }
    let _ = writeln!(
        md,
        "\nWithout a capacity (`Probe<N, [f32; 3]>`, M = 0) the probe is {} bytes at N = 16, {} \
         at N = 64 and {} at N = 256.\n",
        std::mem::size_of::<Probe<16, [f32; 3]>>(),
        std::mem::size_of::<Probe<64, [f32; 3]>>(),
        std::mem::size_of::<Probe<256, [f32; 3]>>()
    );
}

/// The statistics of one (N, fraction) as a `report::Case` (the peer twice, the two bars).
fn case(scenes: &[Scene], outcomes: &[Vec<Vec<Outcome>>], ni: usize, n: usize, fi: usize) -> Case {
    let rows = scenes
        .iter()
        .zip(outcomes)
        .map(|(s, o)| {
            let o = o[ni][fi];
            MapRow {
                map: s.name.clone(),
                held_out: s.held_out,
                bmc: o.rel[0],
                peers: [o.rel[1], o.rel[1]],
                covered: o.covered,
                queries: o.queries,
            }
        })
        .collect();
    Case { tier: TIER.into(), query: format!("{:.2}", FRACTIONS[fi]), n, rows }
}

/// missing-samples benchmark: irradiance from a probe with missing samples (issue #14)
#[derive(Parser)]
#[command(
    bin_name = "cargo eval missing --",
    after_help = "Which samples are missing: for every rotation of the probe and missing \
                  fraction f (0, 5, 25,\n50 %), a seeded uniform random subset of round(f·N) \
                  samples (the same subsets for every map)."
)]
struct Args {
    #[command(flatten)]
    maps: cli::TrainingMaps,
    /// Write DIR/missing.md (`--out docs` regenerates the repository's docs); without
    /// it the report goes to stdout only
    #[arg(long, value_name = "DIR", verbatim_doc_comment)]
    out: Option<PathBuf>,
    /// Also write rows missing,clamp,<fraction>,<n>,<method>,<map>,<rel_rmse>
    /// (methods bmc-masked, cos-avg-valid)
    #[arg(long, value_name = "FILE", verbatim_doc_comment)]
    csv: Option<PathBuf>,
    /// 2 maps, N = 64 only, 64 normals, 8 rotations (CI)
    #[arg(long)]
    quick: bool,
    #[command(flatten)]
    threads: cli::Threads,
}

fn main() -> Result<(), Box<dyn Error>> {
    let start = Instant::now();
    let raw_args: Vec<String> = std::env::args().skip(1).collect();
    let Args { maps: cli::TrainingMaps { maps: mut paths }, out, csv, quick, threads } =
        Args::parse();
    let p = Params {
        ns: if quick { vec![64] } else { NS.to_vec() },
        normals: if quick { 64 } else { 256 },
        rotations: if quick { 8 } else { 32 },
        threads: threads.count(),
    };
    if paths.is_empty() {
        paths = cli::named_maps(quick);
    }
    let mut rng = Rng::new(SEED_NORMALS);
    let normals: Vec<[f64; 3]> = (0..p.normals).map(|_| rng.uniform_sphere()).collect();

    // The clamp tier and its ground truth (one set of pixel weights per grid size).
    let maps: Vec<EnvMap> = paths
        .iter()
        .map(|path| EnvMap::load(path).map(|m| compare::clamped(&m)))
        .collect::<Result<_, _>>()
        .map_err(|e| format!("cannot load a map: {e}"))?;
    let mut truths: Vec<Option<Vec<f64>>> = vec![None; maps.len()];
    for i in 0..maps.len() {
        if truths[i].is_some() {
            continue;
        }
        let size = (maps[i].width, maps[i].height);
        let weights = compare::weights(compare::Kind::Diffuse, &normals, size.0, size.1);
        for j in i..maps.len() {
            if (maps[j].width, maps[j].height) == size {
                truths[j] = Some(compare::truths(&maps[j], &weights));
            }
        }
    }
    eprintln!("ground truth ({:.1} s)", start.elapsed().as_secs_f64());
    let scenes: Vec<Scene> = paths
        .iter()
        .zip(maps)
        .zip(truths)
        .map(|((path, map), truth)| {
            let name = cli::map_name(path);
            let held_out = !cli::TRAINING_MAPS.contains(&name.as_str());
            Scene { name, held_out, map, truth: truth.unwrap_or_default() }
        })
        .collect();

    let jobs: Vec<(usize, usize)> =
        (0..scenes.len()).flat_map(|s| (0..p.ns.len()).map(move |ni| (s, ni))).collect();
    let done = AtomicUsize::new(0);
    let results = parallel_map(&jobs, p.threads, |_, &(s, ni)| {
        let o = evaluate_n(&scenes[s], &normals, &p, p.ns[ni]);
        let d = done.fetch_add(1, Ordering::Relaxed) + 1;
        eprintln!(
            "[{d}/{}] {} N = {} ({:.1} s)",
            jobs.len(),
            scenes[s].name,
            p.ns[ni],
            start.elapsed().as_secs_f64()
        );
        o
    });
    // outcomes[scene][N index][fraction index].
    let mut outcomes: Vec<Vec<Vec<Outcome>>> = vec![Vec::new(); scenes.len()];
    for (&(s, _), o) in jobs.iter().zip(results) {
        outcomes[s].push(o);
    }
    let seconds = start.elapsed().as_secs_f64();
    eprintln!("measured ({seconds:.1} s); timing the updates");

    // Report.
    let mut md = String::new();
    md.push_str("# Missing samples: irradiance from a probe with a validity mask\n\n");
    md.push_str(
        "@generated by `eval/src/bin/missing.rs` (issue #14 item 3); do not edit by hand. \
         Relative RMSE of the luminance irradiance E(n) = ∫ L(ω)·max(0, n·ω) dω = RMSE / mean \
         |truth| per map; ground truth summed over every pixel with exact per-pixel cosine \
         weights.\n\n",
    );
    let command = if raw_args.is_empty() {
        "cargo eval missing".to_string()
    } else {
        format!("cargo eval missing -- {}", raw_args.join(" "))
    };
    let held: Vec<&str> = scenes.iter().filter(|s| s.held_out).map(|s| s.name.as_str()).collect();
    let train: Vec<&str> = scenes.iter().filter(|s| !s.held_out).map(|s| s.name.as_str()).collect();
    let _ = writeln!(
        md,
        "## Run\n\n- Command: `{command}` ({seconds:.0} s wall for the measurement, {} \
         threads).\n- Maps, `clamp` tier (luminance clamped at {}× the solid-angle mean): \
         held-out {}; training maps of the probe's hyperparameters {}.\n- {} seeded random \
         normals (seed {SEED_NORMALS:#X}); {} seeded random rotations of the sphere SF set per \
         map and N (seed {SEED_ROTATIONS:#X}), RMSE pooled over rotations × normals.\n- Missing \
         samples: for every rotation and fraction f, a seeded uniform random subset of \
         round(f·N) samples (seed {SEED_MASKS:#X}; the same subsets for every map), set to NaN \
         before the update.\n- `bmc-masked`: `Probe<N, [f32; 3], Point, N/2>::update_masked` \
         (maximum-likelihood member), luminance of `Probe::irradiance`. `cos-avg-valid`: \
         `probe::cosine_weighted_average` of the valid samples' luminance.\n",
        p.threads,
        compare::CLAMP,
        if held.is_empty() { "none".into() } else { held.join(", ") },
        if train.is_empty() { "none".into() } else { train.join(", ") },
        p.normals,
        p.rotations,
    );

    // The target.
    let (tf, tn, limit) = TARGET;
    let target = p.ns.iter().position(|&n| n == tn).and_then(|ni| {
        let fi = FRACTIONS.iter().position(|&f| f == tf)?;
        let c = case(&scenes, &outcomes, ni, tn, fi);
        c.summary(Maps::HeldOut).or_else(|| c.summary(Maps::All)).map(|s| (s, c))
    });
    md.push_str("## Target (issue #14)\n\n");
    match &target {
        Some((s, _)) => {
            let met = if s.mean_of_ratios <= limit { "met" } else { "missed" };
            let _ = writeln!(
                md,
                "At {:.0} % missing, `clamp`, N = {tn}: bmc-masked ≤ {limit}× cos-avg-valid \
                 (mean of per-map ratios over {} {} maps): **{}** ({met}); ratio of means {}, \
                 worst map {} ({}).\n",
                100.0 * tf,
                s.maps,
                if held.is_empty() { "" } else { "held-out" },
                ratio(s.mean_of_ratios),
                ratio(s.ratio_of_means),
                s.worst.1,
                ratio(s.worst.0)
            );
        }
        None => md.push_str("Not measured in this run (N = 64 is not among the sizes).\n\n"),
    }
    // The same statistic at every fraction: what the probe gains over the valid samples'
    // average without missing samples is the ceiling of what it can keep with them.
    if let Some(ni) = p.ns.iter().position(|&n| n == tn) {
        let maps = if held.is_empty() { Maps::All } else { Maps::HeldOut };
        let cells: Vec<String> = FRACTIONS
            .iter()
            .enumerate()
            .filter_map(|(fi, &f)| {
                let s = case(&scenes, &outcomes, ni, tn, fi).summary(maps)?;
                Some(format!("{} at {:.0} %", ratio(s.mean_of_ratios), 100.0 * f))
            })
            .collect();
        let _ = writeln!(
            md,
            "The same statistic at N = {tn} for every fraction: {}. With no sample missing it \
             measures the full probe against the cosine-weighted average of all samples, the \
             advantage the masked probe starts from.\n",
            cells.join(", ")
        );
    }

    md.push_str(
        "## bmc-masked against cos-avg-valid\n\nPer N and missing fraction, over the held-out \
         maps and over all maps: mean relative RMSE of both; the mean over maps of bmc-masked \
         / cos-avg-valid taken per map; the ratio of the mean errors; the worst map's ratio; \
         and the fraction of queries within 2σ of BMC's luminance error bar, σ² from \
         `Probe::irradiance_variance` (exact for the valid samples) and from \
         `Probe::irradiance` (O(1): the full set's baked average, blind to the holes).\n\n",
    );
    for (ni, &n) in p.ns.iter().enumerate() {
        let _ = writeln!(md, "### N = {n} (capacity M = {})\n", n / 2);
        md.push_str(
            "| missing | maps | bmc-masked | cos-avg-valid | mean of ratios | ratio of means | \
             worst map | 2σ exact | 2σ O(1) |\n| ---: | --- | ---: | ---: | ---: | ---: | --- | \
             ---: | ---: |\n",
        );
        for (fi, &f) in FRACTIONS.iter().enumerate() {
            let c = case(&scenes, &outcomes, ni, n, fi);
            for (maps, label) in [(Maps::HeldOut, "held-out"), (Maps::All, "all")] {
                let Some(s) = c.summary(maps) else { continue };
                let _ = writeln!(
                    md,
                    "| {:.0} % ({}) | {label} ({}) | {} | {} | {} | {} | {} {} | {} | {} |",
                    100.0 * f,
                    missing_count(f, n),
                    s.maps,
                    pct(s.bmc),
                    pct(s.peers[0]),
                    ratio(s.mean_of_ratios),
                    ratio(s.ratio_of_means),
                    s.worst.1,
                    ratio(s.worst.0),
                    report::coverage(s.coverage[0]),
                    report::coverage(s.coverage[1]),
                );
            }
        }
        md.push('\n');
    }

    if let Some(ni) = p.ns.iter().position(|&n| n == 64) {
        md.push_str(
            "## Per map, N = 64\n\nbmc-masked / cos-avg-valid (bmc-masked's relative RMSE).\n\n",
        );
        let header: Vec<String> =
            FRACTIONS.iter().map(|f| format!("{:.0} % missing", 100.0 * f)).collect();
        let _ = writeln!(md, "| map | {} |", header.join(" | "));
        let _ = writeln!(md, "| --- |{}", " ---: |".repeat(FRACTIONS.len()));
        for (s, o) in scenes.iter().zip(&outcomes) {
            let cells: Vec<String> = o[ni]
                .iter()
                .map(|x| format!("{} ({})", ratio(x.rel[0] / x.rel[1]), pct(x.rel[0])))
                .collect();
            let mark = if s.held_out { "" } else { " (training)" };
            let _ = writeln!(md, "| {}{mark} | {} |", s.name, cells.join(" | "));
        }
        md.push('\n');
    }
    cost_table(&mut md, quick);

    if let Some(path) = &csv {
        let mut rows = String::from("benchmark,tier,fraction,n,method,map,rel_rmse\n");
        for (ni, &n) in p.ns.iter().enumerate() {
            for (fi, &f) in FRACTIONS.iter().enumerate() {
                for (mi, method) in METHODS.iter().enumerate() {
                    for (s, o) in scenes.iter().zip(&outcomes) {
                        let _ = writeln!(
                            rows,
                            "missing,{TIER},{f:.2},{n},{method},{},{:.6e}",
                            s.name, o[ni][fi].rel[mi]
                        );
                    }
                }
            }
        }
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(path, rows)?;
        eprintln!("wrote {}", path.display());
    }
    print!("{md}");
    let total = start.elapsed().as_secs_f64();
    match out {
        Some(out) => {
            std::fs::create_dir_all(&out)?;
            std::fs::write(out.join("missing.md"), &md)?;
            eprintln!("wrote {} ({total:.1} s)", out.join("missing.md").display());
        }
        None => eprintln!("done ({total:.1} s); --out DIR writes missing.md"),
    }
    Ok(())
}
