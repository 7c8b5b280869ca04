//! The footprint renderer on real maps: the crate's `bmc::FootprintRenderer` and its f64 model
//! (`gen/fp.rs`), Bayesian Monte Carlo of the renderer integrals from lookups whose footprints
//! follow the sample density, against filtered importance sampling, QMC and split-sum, with
//! the error bars' 2σ coverage; and the choice of each baked set's `(c, l, σ′)` and
//! calibration factor on the training maps.
//!
//! ```text
//! cargo eval renderer_fp --                       # ten bundled maps, 48 queries, N = 32, 64
//! cargo eval renderer_fp -- --select              # choose (c, l, σ′) per (BRDF, N) first
//! cargo eval renderer_fp -- --brdfs 50 --ns 64 --c 16 --l 0.35 --sigma 1e-5 a.hdr b.hdr --csv rows.csv
//! ```
//!
//! # Estimators
//! Per query (the renderer benchmark's queries), the lobe-morphed hemisphere spherical
//! Fibonacci set at phase 0 in the lobe frame (`t₁` towards the normal: the `GlossyRenderer`
//! set; the cosine-morphed set about `n` for diffuse):
//! - `bmc-fp-f64`: sample `j` reads the map through the normalised spherical Gaussian of
//!   sharpness `sⱼ = round(2π·N·pdf(xⱼ)/c)` with `MipPyramid::footprint_sample`; the GLS
//!   weights of the model `(c, l, σ′)` (`--c`, `--l`, `--sigma`, or `--select`), exact for the
//!   query's `θₙ`, in f64;
//! - `bmc-fp-pyramid`: the crate's renderer (its baked f32 weights, interpolated in `θₙ`) on
//!   the same pyramid lookups, for the sets the crate bakes;
//! - `qmc-fis`, `qmc-sf`: as the renderer benchmark, on the same directions;
//! - `split-sum` (Phong): one `CosinePower` lookup of the lobe's exponent along the mirror
//!   direction, times the lobe's exact `∫p`.
//!
//! # Error bars
//! - `single`: `σ̂²·u` of the weights' own model (`σ̂²` by REML);
//! - `average`: over the family `l ∈ --family-l` × `σ′ ∈ --family-sigma` (same footprints),
//!   `Σ πₘ·σ̂²ₘ·uₘ(w)`, `uₘ(w)` the error variance of the chosen weights under model `m` and
//!   `πₘ ∝` its restricted likelihood;
//! - `reduced`: the same average with each model's `σ̂²` and likelihood from `--reduce k`
//!   contrasts of the lookups;
//! - `crate`: the crate's `estimate_with_variance`;
//! - `best`: the reduced family's most likely model alone, `σ̂²ₘ·uₘ(w)` (the crate's model
//!   part, which adds the arithmetic's own error).
//!
//! Each bar is reported as is and with the factor on σ that puts 95 % of the training maps'
//! clamp and smooth queries inside 2σ (`raw→calibrated`).
//!
//! # Output
//! Per (BRDF, N, tier): over the held-out maps the mean of per-map RMSE ratios (worst map)
//! and the 2σ coverage on held-out and training maps. `--csv FILE` writes rows
//! `renderer,<tier>,<estimator>,<n>,<brdf>,<map>,<rel_rmse>` and
//! `coverage,<tier>,<bar>,<n>,<brdf>,<map>,<fraction>`.

use std::error::Error;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Parser;
use reference::envmap::EnvMap;
use sphere_quadrature::footprint::Kind;
use sphere_quadrature_eval::fp::{
    degree_cut, footprints, lobe_set, Contrasts, Design, Integrand, Model, Reduced,
};
use sphere_quadrature_eval::parallel::parallel_map;
use sphere_quadrature_eval::renderer::footprint::{crate_fn, exponent, v32, with_lookups};
use sphere_quadrature_eval::renderer::scenes::{truths, Light, Scene};
use sphere_quadrature_eval::renderer::{SEED_QUERIES, SEED_SYNTHETIC};
use sphere_quadrature_eval::renderer_engine::{self as engine, Brdf, LobeFrame, Query};
use sphere_quadrature_eval::{cli, compare, tiers};

/// renderer_fp: Bayesian Monte Carlo on footprint lookups, on real maps
#[derive(Parser)]
#[command(bin_name = "cargo eval renderer_fp --")]
struct Cli {
    #[command(flatten)]
    maps: cli::TrainingMaps,
    /// Queries per map
    #[arg(long, default_value_t = 48)]
    queries: usize,
    /// Sample counts
    #[arg(long, value_delimiter = ',', default_values_t = [32, 64])]
    ns: Vec<usize>,
    /// BRDFs: diffuse or a Phong exponent
    #[arg(long, value_delimiter = ',', default_values = ["diffuse", "10", "50"])]
    brdfs: Vec<String>,
    /// Footprint solid angle in samples' shares, diffuse and Phong
    #[arg(long, value_delimiter = ',', default_values_t = [8.0, 16.0])]
    c: Vec<f64>,
    /// The weights' kernel length
    #[arg(long, default_value_t = 0.6)]
    l: f64,
    /// The weights' nugget σ′
    #[arg(long, default_value_t = 1e-4)]
    sigma: f64,
    /// The error bar family's kernel lengths
    #[arg(long, value_delimiter = ',', default_values_t = [0.35, 0.6, 1.0, 1.5, 2.2, 3.0])]
    family_l: Vec<f64>,
    /// The error bar family's nuggets
    #[arg(long, value_delimiter = ',', default_values_t = [1e-5, 1e-4, 1e-3, 1e-2])]
    family_sigma: Vec<f64>,
    /// Choose (c, l, σ′) per (BRDF, N) on the training maps from the --grid-* values
    #[arg(long)]
    select: bool,
    /// --select's footprint sizes
    #[arg(long, value_delimiter = ',', default_values_t = [8.0, 16.0, 32.0])]
    grid_c: Vec<f64>,
    /// --select's kernel lengths
    #[arg(long, value_delimiter = ',', default_values_t = [0.2, 0.35, 0.6, 1.0])]
    grid_l: Vec<f64>,
    /// --select's nuggets
    #[arg(long, value_delimiter = ',', default_values_t = [1e-5, 1e-4, 1e-3, 1e-2])]
    grid_sigma: Vec<f64>,
    /// Contrasts of the reduced error bar (eigenvectors of the weights' model)
    #[arg(long, default_value_t = 12)]
    reduce: usize,
    /// Synthetic mixtures
    #[arg(long, default_value_t = 10)]
    mixtures: usize,
    /// Also write CSV rows
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    #[command(flatten)]
    threads: cli::Threads,
}

const TIERS: [&str; 4] = ["raw", "clamp", "smooth", "synthetic"];
/// Estimators: bmc-fp (pyramid lookups), qmc-fis, qmc-sf, split-sum.
const EST: [&str; 5] = ["bmc-fp-f64", "qmc-fis", "qmc-sf", "split-sum", "bmc-fp-pyramid"];
/// The error bars: the f64 model's (single, average, reduced) and the crate's.
const BARS: [&str; 5] = ["single", "average", "reduced", "crate", "best"];

/// Per (query, N): everything that does not depend on the map.
struct Plan {
    world: Vec<[f64; 3]>,
    sharpness: Vec<u32>,
    w: Vec<f64>,
    /// `uₘ(w)` per family model, and of the weights' own model (last).
    u: Vec<f64>,
    mass: f64,
}

fn parse_brdf(s: &str) -> Result<Brdf, String> {
    if s == "diffuse" {
        return Ok(Brdf::Diffuse);
    }
    s.parse::<u32>().map(|e| Brdf::Phong(f64::from(e))).map_err(|_| format!("unknown BRDF {s}"))
}

fn main() {
    cli::run_main("renderer_fp", || Ok(Cli::parse()), run);
}

fn run(o: &Cli) -> Result<(), Box<dyn Error>> {
    let threads = o.threads.count();
    let paths = if o.maps.maps.is_empty() { cli::named_maps(false) } else { o.maps.maps.clone() };
    let names: Vec<String> = paths.iter().map(|p| cli::map_name(p)).collect();
    let raw: Vec<EnvMap> = paths
        .iter()
        .map(EnvMap::load)
        .collect::<Result<_, _>>()
        .map_err(|e| format!("cannot load a map: {e}"))?;
    let clamped: Vec<EnvMap> = raw.iter().map(compare::clamped).collect();
    let smooth: Vec<EnvMap> = parallel_map(&clamped, threads, |_, m| tiers::smooth(m));
    let mut scenes = Vec::new();
    for (t, tier) in [raw, clamped, smooth].into_iter().enumerate() {
        for (k, map) in tier.into_iter().enumerate() {
            scenes.push(Scene::map(t, &names[k], map));
        }
    }
    for (k, m) in tiers::mixtures(o.mixtures, SEED_SYNTHETIC).into_iter().enumerate() {
        scenes.push(Scene {
            name: format!("mixture{k}"),
            tier: 3,
            held_out: true,
            light: Light::Mixture(m),
        });
    }
    let queries = engine::queries(o.queries, SEED_QUERIES);
    let brdfs: Vec<Brdf> = o.brdfs.iter().map(|s| parse_brdf(s)).collect::<Result<_, _>>()?;
    let mut csv = String::new();
    let mut report = String::new();
    for &brdf in &brdfs {
        let truth = truths(brdf, &scenes, &queries, threads);
        for &n in &o.ns {
            let cx = Context {
                brdf,
                n,
                scenes: &scenes,
                truth: &truth,
                queries: &queries,
                family_l: &o.family_l,
                family_sigma: &o.family_sigma,
                reduce: o.reduce,
                threads,
            };
            let setting = choose(o, &cx)?;
            let all: Vec<usize> = (0..scenes.len()).collect();
            let per_scene = study(&cx, setting, &all)?;
            // Report.
            let bname = brdf.name();
            // Calibration: the factor on σ that puts 95 % of the training maps' clamp and smooth
            // queries inside 2σ.
            let factors: [f64; 5] = std::array::from_fn(|k| {
                let mut z: Vec<f64> = (0..scenes.len())
                    .filter(|&i| {
                        !scenes[i].held_out && (scenes[i].tier == 1 || scenes[i].tier == 2)
                    })
                    .flat_map(|i| per_scene[i].1[k].iter().copied())
                    .collect();
                z.sort_by(f64::total_cmp);
                if z.is_empty() {
                    return 1.0;
                }
                z[((0.95 * z.len() as f64) as usize).min(z.len() - 1)] / 2.0
            });
            let _ = writeln!(
                report,
                "{bname:>8} N={n:<3} calibration factors single {:.3} average {:.3} reduced {:.3} crate {:.3} best {:.3}",
                factors[0], factors[1], factors[2], factors[3], factors[4]
            );
            for (t, tier) in TIERS.iter().enumerate() {
                let members: Vec<usize> =
                    (0..scenes.len()).filter(|&i| scenes[i].tier == t).collect();
                if members.is_empty() {
                    continue;
                }
                for &i in &members {
                    for (k, est) in EST.iter().enumerate() {
                        if per_scene[i].0[k].is_finite() {
                            let _ = writeln!(
                                csv,
                                "renderer,{tier},{est},{n},{bname},{},{:.6e}",
                                scenes[i].name, per_scene[i].0[k]
                            );
                        }
                    }
                    for (k, bar) in BARS.iter().enumerate() {
                        let z = &per_scene[i].1[k];
                        if z.is_empty() {
                            continue;
                        }
                        let fraction =
                            z.iter().filter(|&&z| z <= 2.0).count() as f64 / z.len() as f64;
                        let _ = writeln!(
                            csv,
                            "coverage,{tier},{bar},{n},{bname},{},{:.4}",
                            scenes[i].name, fraction
                        );
                    }
                }
                let held: Vec<usize> =
                    members.iter().copied().filter(|&i| scenes[i].held_out).collect();
                let train: Vec<usize> =
                    members.iter().copied().filter(|&i| !scenes[i].held_out).collect();
                let ratio = |a: usize, b: usize| -> String {
                    if held.is_empty()
                        || !per_scene[held[0]].0[b].is_finite()
                        || !per_scene[held[0]].0[a].is_finite()
                    {
                        return "–".into();
                    }
                    let r: Vec<f64> =
                        held.iter().map(|&i| per_scene[i].0[a] / per_scene[i].0[b]).collect();
                    let mean = r.iter().sum::<f64>() / r.len() as f64;
                    let worst = r.iter().cloned().fold(0.0, f64::max);
                    format!("{mean:.3} ({worst:.3})")
                };
                let cover = |set: &[usize], k: usize| -> String {
                    if set.is_empty() || per_scene[set[0]].1[k].is_empty() {
                        return "–".into();
                    }
                    let f = |scale: f64| {
                        let z: Vec<f64> =
                            set.iter().flat_map(|&i| per_scene[i].1[k].iter().copied()).collect();
                        z.iter().filter(|&&z| z * scale <= 2.0).count() as f64 / z.len() as f64
                    };
                    format!("{:.3}→{:.3}", f(1.0), f(1.0 / factors[k]))
                };
                let fp_abs = if held.is_empty() {
                    f64::NAN
                } else {
                    held.iter().map(|&i| per_scene[i].0[0]).sum::<f64>() / held.len() as f64
                };
                let _ = writeln!(
                    report,
                    "{bname:>8} N={n:<3} {tier:<9} fp {:.4}%  fp/fis {}  fp/sf {}  fp/split {}  crate/fis {} crate/split {}  2σ crate {} / {} (train)  single {} / {} (train)  average {} / {} (train)  reduced {} / {} (train)  best {} / {} (train)",
                    100.0 * fp_abs,
                    ratio(0, 1),
                    ratio(0, 2),
                    ratio(0, 3),
                    ratio(4, 1),
                    ratio(4, 3),
                    cover(&held, 3),
                    cover(&train, 3),
                    cover(&held, 0),
                    cover(&train, 0),
                    cover(&held, 1),
                    cover(&train, 1),
                    cover(&held, 2),
                    cover(&train, 2),
                    cover(&held, 4),
                    cover(&train, 4),
                );
            }
            eprintln!("{bname} N = {n} done");
        }
    }
    print!("{report}");
    if let Some(path) = &o.csv {
        std::fs::write(path, csv)?;
    }
    Ok(())
}

/// Relative RMSE per estimator ([`EST`]) and `|error|/σ` per query of the error bars (single,
/// average, reduced) of one scene.
type SceneResult = ([f64; 5], [Vec<f64>; 5]);

/// One weight setting.
#[derive(Clone, Copy, Debug)]
struct Setting {
    c: f64,
    l: f64,
    sigma: f64,
}

/// The model's context for one (BRDF, N).
struct Context<'a> {
    brdf: Brdf,
    n: usize,
    scenes: &'a [Scene],
    truth: &'a [Vec<f64>],
    queries: &'a [Query],
    family_l: &'a [f64],
    family_sigma: &'a [f64],
    threads: usize,
    reduce: usize,
}

/// Relative RMSE per estimator ([`EST`]) and 2σ coverage (single, average) of the scenes
/// `which` with weights of `setting`.
fn study(cx: &Context, setting: Setting, which: &[usize]) -> Result<Vec<SceneResult>, String> {
    let Context { brdf, n, scenes, truth, queries, family_l, family_sigma, threads, .. } = *cx;
    let morph = brdf.exponent() as u32;
    let c = setting.c;
    let lmax =
        family_l.iter().chain([&setting.l]).map(|&l| degree_cut(2.0 / (l * l))).max().unwrap_or(40);
    let xs = lobe_set(n, morph);
    let sharp = footprints(&xs, f64::from(morph), c);
    let design = Design::new(xs.clone(), sharp.clone(), lmax);
    let own = Model::new(&design, setting.l, setting.sigma)
        .ok_or("the weights' Q is not positive definite")?;
    let mut family = Vec::new();
    for &l in family_l {
        for &s in family_sigma {
            family.push(Model::new(&design, l, s).ok_or("a family Q is not positive definite")?);
        }
    }
    let contrasts = Contrasts::new(&own, cx.reduce.clamp(1, n - 1));
    let reduced: Vec<Reduced> = family
        .iter()
        .map(|m| m.reduced(&contrasts).ok_or("a reduced covariance is not positive definite"))
        .collect::<Result<_, _>>()?;
    // Plans per query.
    let plans: Vec<Plan> = parallel_map(queries, threads, |_, q| {
        let frame = LobeFrame::new(brdf, q);
        let p = match brdf {
            Brdf::Diffuse => Integrand::irradiance(),
            Brdf::Phong(e) => Integrand::phong(e, frame.cos_alpha.clamp(-1.0, 1.0).acos()),
        };
        let coef = p.coefficients(lmax, 160);
        let w = own.weights(&design, &coef);
        let residual = design.residual_power(&coef, &w);
        let mut u: Vec<f64> = family.iter().map(|m| m.unit_variance(&residual, &w)).collect();
        u.push(own.unit_variance(&residual, &w));
        let world = xs
            .iter()
            .map(|x| frame.direction(x[2], (x[0] * x[0] + x[1] * x[1]).sqrt(), x[1].atan2(x[0])))
            .collect();
        let sharpness = sharp.iter().map(|&s| s as u32).collect();
        Plan { world, sharpness, w, u, mass: (4.0 * PI).sqrt() * coef[0] }
    });
    // Per scene: estimates and coverage.
    let per_scene: Vec<SceneResult> = parallel_map(which, threads, |_, &si| {
        let scene = &scenes[si];
        with_lookups(scene, |lookups| {
            let read =
                |x: [f64; 3], s: u32| lookups.read(v32(x), Kind::Gaussian { sharpness: s }, false);
            let mut se = [0.0f64; 5];
            let mut abs = 0.0;
            let mut zs: [Vec<f64>; 5] = Default::default();
            let crate_fn = crate_fn(n, exponent(brdf));
            for (qi, (q, plan)) in queries.iter().zip(&plans).enumerate() {
                let t = truth[si][qi];
                let y: Vec<f64> =
                    plan.world.iter().zip(&plan.sharpness).map(|(&x, &s)| read(x, s)).collect();
                let fp: f64 = plan.w.iter().zip(&y).map(|(w, y)| w * y).sum();
                let mut fis = 0.0;
                let mut sf = 0.0;
                for &x in &plan.world {
                    let omega = (1.0 / (n as f64 * brdf.pdf(q, x))).min(4.0 * PI);
                    fis += scene.filtered(x, omega) * brdf.qmc_factor(q, x);
                    sf += scene.lum(x) * brdf.qmc_factor(q, x);
                }
                let (fis, sf) = (fis / n as f64, sf / n as f64);
                let split = match brdf {
                    Brdf::Phong(e) => lookups.split_sum(e as u32, q.r, plan.mass),
                    Brdf::Diffuse => f64::NAN,
                };
                let r = if brdf == Brdf::Diffuse { q.n } else { q.r };
                let (crate_value, crate_variance) =
                    crate_fn.map_or((f64::NAN, f64::NAN), |f| lookups.render(f, q.n, r, false));
                for (k, est) in [fp, fis, sf, split, crate_value].into_iter().enumerate() {
                    se[k] += (est - t).powi(2);
                }
                abs += t.abs();
                // Error bars.
                let (s2_own, _) = own.reml(&y);
                let single = s2_own * plan.u[family.len()];
                let fits: Vec<(f64, f64)> = family.iter().map(|m| m.reml(&y)).collect();
                let average = likelihood_average(&fits, &plan.u);
                let tv = contrasts.apply(&y);
                let fits: Vec<(f64, f64)> = reduced.iter().map(|m| m.fit(&tv)).collect();
                let reduced_bar = likelihood_average(&fits, &plan.u);
                let best = fits
                    .iter()
                    .zip(&plan.u)
                    .max_by(|a, b| a.0 .1.total_cmp(&b.0 .1))
                    .map_or(f64::NAN, |((s2, _), u)| s2 * u);
                zs[4].push((fp - t).abs() / best.sqrt());
                let err = (fp - t).abs();
                for (z, v) in zs.iter_mut().zip([single, average, reduced_bar]) {
                    z.push(err / v.sqrt());
                }
                if crate_value.is_finite() {
                    zs[3].push((crate_value - t).abs() / crate_variance.sqrt());
                }
            }
            let nq = queries.len() as f64;
            let rel = se.map(|s| (s / nq).sqrt() / (abs / nq));
            (rel, zs)
        })
    });
    Ok(per_scene)
}

/// `Σ πₘ·σ̂²ₘ·uₘ / Σ πₘ` over the models' fits `(σ̂²ₘ, ℓₘ)`, `πₘ ∝ exp(ℓₘ)`.
fn likelihood_average(fits: &[(f64, f64)], u: &[f64]) -> f64 {
    let top = fits.iter().map(|f| f.1).fold(f64::NEG_INFINITY, f64::max);
    let (mut num, mut den) = (0.0, 0.0);
    for ((s2, ll), u) in fits.iter().zip(u) {
        let pi = (ll - top).exp();
        num += pi * s2 * u;
        den += pi;
    }
    num / den
}

/// The setting of `--c`, `--l`, `--sigma`, or with `--select` the grid point with the
/// smallest mean over the training maps of `ln(fp/fis)` on `clamp` plus `ln(fp/sf)` on
/// `smooth`.
fn choose(o: &Cli, cx: &Context) -> Result<Setting, String> {
    let c_given = if cx.brdf == Brdf::Diffuse { o.c[0] } else { *o.c.last().unwrap_or(&16.0) };
    if !o.select {
        return Ok(Setting { c: c_given, l: o.l, sigma: o.sigma });
    }
    let train: Vec<usize> = (0..cx.scenes.len())
        .filter(|&i| !cx.scenes[i].held_out && (cx.scenes[i].tier == 1 || cx.scenes[i].tier == 2))
        .collect();
    if train.is_empty() {
        return Err("--select needs training maps".into());
    }
    let mut best = (f64::INFINITY, Setting { c: c_given, l: o.l, sigma: o.sigma });
    for &c in &o.grid_c {
        for &l in &o.grid_l {
            for &sigma in &o.grid_sigma {
                let setting = Setting { c, l, sigma };
                let Ok(r) = study(cx, setting, &train) else { continue };
                let score: f64 = train
                    .iter()
                    .zip(&r)
                    .map(|(&i, (rel, _))| {
                        let b = if cx.scenes[i].tier == 1 { 1 } else { 2 };
                        (rel[0] / rel[b]).ln()
                    })
                    .sum::<f64>()
                    / train.len() as f64;
                if score < best.0 {
                    best = (score, setting);
                }
            }
        }
    }
    let s = best.1;
    eprintln!(
        "{} N = {}: chose c = {}, l = {}, σ′ = {} (score {:.3})",
        cx.brdf.name(),
        cx.n,
        s.c,
        s.l,
        s.sigma,
        best.0
    );
    Ok(s)
}
