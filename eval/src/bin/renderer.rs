//! Status: complete for issue #12 item 6: every estimator (`bmc-opt` once
//! `tables/optimal_sets.txt` exists), the four tiers, `--csv`, `--quick`, `--self-test`,
//! report and plot. Its hyperparameters are learned by `cargo writer renderer_hyperparameters`
//! (REML, the seed's covariance fit and the error-minimising fit).
//! `bmc-sf` is the crate's own renderers; `bmc-sf-f64` the same model on the host engine.
//!
//! The renderer benchmark of issue #12 (item 6): per-query shading integrals on environment
//! maps, every estimator at N ∈ {16, 32, 64, 80, 128}, against ground truth over every pixel.
//!
//! ```text
//! R="cargo eval renderer --"
//! $R                           # the six held-out bundled maps, target/renderer
//! $R --out docs                # docs/renderer.md + .png
//! $R --quick                   # CI smoke run (seconds)
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
//!   (`xtask/writers/src/bin/optimal_sets.rs`: the set minimising the model's posterior variance, in the lobe
//!   frame) with the hyperparameters it was optimised for;
//! - `bmc-fp-pyramid`: the crate's footprint renderer `bmc::FootprintRenderer<N, B>` (N = 16,
//!   32, 64, 128; the lobe-morphed SF set, each sample read through a normalised spherical
//!   Gaussian footprint matched to the sample density, baked f32 weights interpolated in θₙ)
//!   on `MipPyramid::footprint_sample` lookups, and its error bar's 2σ coverage, on the first
//!   `--footprint-queries` queries (default 32) of each held-out map and mixture (its lookups
//!   are most of the run's time; its ratios to other estimators are on the same queries);
//! - `bmc-fp`: the same on exact lookups (`EquirectMap::footprint_sample`, every pixel of the
//!   map), on the first `--exact-queries` of those queries (default 4);
//! - `split-sum` (Phong, maps; Karis 2013): one lookup of the map prefiltered by the lobe
//!   `cosᵉ` along `r` (`MipPyramid`'s `CosinePower` footprint), times the exact `∫p`.
//!
//! On the synthetic tier both footprint renderers read the mixture's exact convolution with
//! the footprint.
//!
//! # Tiers
//! `raw`, `clamp` (luminance ≤ 30× the map mean), `smooth` (clamp → 128×64 → SG blur of
//! sharpness 10) and `synthetic` (10 seeded SG mixtures), as `eval/src/bin/accuracy.rs`.
//! Hyperparameters `(l, σ′)` per (BRDF, N) are read from
//! `tables/renderer_hyperparameters.txt` (written by `cargo xtask regen renderer-hyperparameters`
//! on the training maps' clamp tier: `err`, the grid point whose estimates have the smallest mean RMSE ratio to QMC on the
//! same samples — what the crate bakes; `ml`, REML; `cov`, the seed's covariance fit; `--hyper`
//! picks the rows the f64 estimators use). By default it runs on the six held-out maps only;
//! a training map given on the command line (apartment, bridge, forest, lab) is evaluated but
//! left out of every mean (its CSV rows are written).
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
//! (tier, estimator, N, BRDF, map), and one row
//! `coverage,<tier>,bmc-fp-pyramid,<n>,<brdf>,<map>,<fraction>` per (tier, N, BRDF, map) with
//! a footprint renderer set (held-out maps and mixtures). The default run's time is in its
//! report; `--quick` takes under 30 s.
//!
//! [`rough_z`]: sphere_quadrature_eval::renderer::plans::rough_z

use sphere_quadrature_eval::{cli, compare, optimal, parallel, renderer_engine as engine, tiers};

use parallel::parallel_map;
use std::error::Error;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use clap::Parser;
use cli::TRAINING_MAPS;
use plotters::style::{register_font, FontStyle};
use reference::envmap::EnvMap;
use sphere_quadrature_eval::renderer::evaluation::{evaluate, TierResult};
use sphere_quadrature_eval::renderer::hyperparameters::parse_hyper;
use sphere_quadrature_eval::renderer::plans::plans;
use sphere_quadrature_eval::renderer::report::{
    crate_table, footprint_tables, plot, seed_table, selection_table, targets, tier_tables,
};
use sphere_quadrature_eval::renderer::scenes::{truths, Light, Scene};
use sphere_quadrature_eval::renderer::self_test::self_test;
use sphere_quadrature_eval::renderer::{
    fmt_g, Options, BRDFS, ESTIMATORS, HYPER_FILE, KEYS, NS, OPTIMAL_FILE, SEED_QUERIES,
    SEED_SYNTHETIC, SYNTHETIC, TIERS,
};

/// renderer: the BMC renderer benchmark of issue #12 (item 6)
#[derive(Parser)]
#[command(bin_name = "cargo eval renderer --")]
struct Cli {
    /// Equirectangular .hdr maps (default: the six held-out maps of examples/envmaps/,
    /// those the hyperparameters were not learned on; two with --quick)
    #[arg(value_name = "MAPS", value_parser = cli::map_file, verbatim_doc_comment)]
    maps: Vec<PathBuf>,
    /// Output directory (default target/renderer; docs/renderer.md and
    /// docs/renderer.png only with --out docs)
    #[arg(long, value_name = "DIR", verbatim_doc_comment)]
    out: Option<PathBuf>,
    /// Also write rows `renderer,<tier>,<estimator>,<n>,<brdf>,<map>,<rel_rmse>`,
    /// and `coverage,<tier>,bmc-fp-pyramid,<n>,<brdf>,<map>,<fraction>`: the
    /// footprint renderer's queries inside 2σ
    #[arg(long, value_name = "FILE", verbatim_doc_comment)]
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
    /// bmc-fp-pyramid (the footprint renderer on MipPyramid lookups, about 0.2 ms
    /// each) on the first Q queries of each held-out map and mixture (default 32)
    #[arg(long, value_name = "Q", verbatim_doc_comment)]
    footprint_queries: Option<usize>,
    /// bmc-fp (the footprint renderer with exact lookups) on the first Q of the
    /// bmc-fp-pyramid queries only (default 4)
    #[arg(long, value_name = "Q", verbatim_doc_comment)]
    exact_queries: Option<usize>,
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
    let paths = if c.maps.is_empty() { cli::held_out_maps(c.quick) } else { c.maps };
    Options {
        out: c.out.unwrap_or_else(|| root.join("target/renderer")),
        csv: c.csv,
        self_test: c.self_test,
        hyper_file: c.hyper_file.unwrap_or_else(|| root.join(HYPER_FILE)),
        hyper_method: c.hyper_method,
        threads: c.threads.count(),
        queries: c.queries.unwrap_or(if c.quick { 32 } else { 256 }),
        mixtures: if c.quick { 2 } else { 10 },
        sobol_queries: c.sobol_queries.unwrap_or(usize::MAX),
        footprint_queries: c.footprint_queries.unwrap_or(32),
        exact_queries: c.exact_queries.unwrap_or(4),
        paths,
        args,
    }
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

    let hyper_text = hyper_text.ok_or(format!(
        "cannot read {}: run `cargo xtask regen renderer-hyperparameters` first",
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

    // bmc-opt's sets, when the table exists (`xtask/writers/src/bin/optimal_sets.rs` writes it).
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
            evaluate(
                s,
                brdf,
                &queries,
                &plan,
                &fam,
                &truth[i],
                o.footprint_queries,
                o.exact_queries,
            )
        });
        for (s, r) in scenes.iter().zip(rel) {
            let tr = &mut results[s.tier][bi];
            tr.names.push(s.name.clone());
            tr.held_out.push(s.held_out);
            tr.rel.push(r.rel);
            tr.selected.push(r.selected);
            tr.crate_diff.push(r.crate_diff);
            tr.exact.push(r.exact);
            tr.inside.push(r.inside);
            tr.fp_rel.push(r.fp_rel);
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
                    let [inside, total] = tr.inside[k][ni];
                    if total > 0 {
                        let _ = writeln!(
                            csv,
                            "coverage,{},bmc-fp-pyramid,{n},{},{name},{:.4}",
                            TIERS[t],
                            BRDFS[bi].name(),
                            inside as f64 / total as f64
                        );
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
    footprint_tables(&mut md, &results, o.footprint_queries, o.exact_queries);
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
