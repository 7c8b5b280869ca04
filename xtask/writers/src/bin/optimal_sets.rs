//! Optimal BMC sample sets (issue #12 item 4; the seed's step 2): for every size N and BRDF,
//! the N directions that minimise the model's posterior variance of the BMC estimate, found
//! off line by gradient descent on the sphere and written to `tables/optimal_sets.txt`
//! (format: `common/optimal.rs`, which the renderer loads).
//!
//! ```text
//! cargo writer optimal_sets                     # target/eval/optimal_sets/optimal_sets.txt
//! cargo writer optimal_sets -- --write          # tables/optimal_sets.txt
//! cargo writer optimal_sets -- --write --out docs   # and docs/optimal_sets.md
//! cargo writer optimal_sets -- --check tables/optimal_sets.txt   # CI
//! cargo writer optimal_sets -- --self-test      # gradient vs differences
//! cargo writer optimal_sets -- --only phong50 --n 32   # one set (target/)
//! ```
//!
//! # Model (as `common/renderer_engine.rs`)
//! `k(x, x′) = exp(λ(x·x′ − 1))` (`λ = 2/l²`, σ_f = 1), `Q = K + σ′²I`, `zᵢ = ∫ k(xᵢ, x)p(x) dx`,
//! constant prior mean by GLS: `Var = V̄ − zᵀQ⁻¹z + (∫p − 1ᵀQ⁻¹z)²/(1ᵀQ⁻¹1)`. `(l, σ′)` per
//! (key, N) from the `err` rows (the hyperparameters the crate bakes) of `tables/renderer_hyperparameters.txt`: `diffuse-cos` for
//! diffuse; for `phongE` the row of that exponent, else `ln l` and `ln σ′` interpolated
//! linearly in `ln e` between the nearest available `phong*` keys (clamped at the ends) by
//! the crate's own rule, `gen::glossy::interpolate`, so that a set is optimised for what
//! `build.rs` bakes.
//!
//! # Objective
//! Diffuse: `Var` of `p = max(0, n·x)` in the frame of `n`. Phong: in the lobe frame (t₁
//! towards n, t₂, r) the normal is `n = (sin θₙ, 0, cos θₙ)`; the objective is the mean of
//! `Var(θₙ)` over the queries' distribution of `t = cos θₙ` (density 2t on [0, 1]), by a
//! [`THETA_NODES`]-node Gauss–Legendre rule in t with weights `wₖ·2tₖ`. `Q` does not depend
//! on θₙ, so one factor serves every node.
//!
//! # Gradient
//! With the GLS weights `w = Q⁻¹z̃`, `z̃ = z + c·1`, `c = (∫p − 1ᵀQ⁻¹z)/(1ᵀQ⁻¹1)`, the
//! variance is `V̄ − 2wᵀz + wᵀQw` at the constrained minimiser `w` of that quadratic
//! (`1ᵀw = ∫p`); differentiating (the terms in `dw` cancel: `Qw − z = c·1` and `1ᵀdw = 0`),
//! `dVar = −2wᵀdz + wᵀdQ w`, so
//! `∂Var/∂xᵢ = −2wᵢ ∂zᵢ/∂xᵢ + 2wᵢ Σ_{j≠i} wⱼ ∂k(xᵢ, xⱼ)/∂xᵢ` with
//! `∂k(xᵢ, xⱼ)/∂xᵢ = λ k (xⱼ − xᵢ)` and `∂zᵢ/∂xᵢ = λ ∫ (x − xᵢ) k(xᵢ, x) p(x) dx` (the
//! kernel as `exp(−λ|xᵢ − x|²/2)`; the `xᵢ` parts vanish in the projection), summed over
//! the θₙ nodes with their weights, projected on each tangent plane. `zᵢ` and its gradient
//! are sums over the nodes of the engine's lobe-frame `Rule` at node density
//! [`OPT_DENSITY`] (rings farther than e⁻⁴⁰ in the kernel skipped); `V̄` by ring-pair
//! Fourier sums ([`kernel_mean_mean`]). `--self-test` checks the gradient against central
//! differences and this objective against the reported one (density 1, closed-form `zᵢ`).
//!
//! # Optimiser
//! Riemannian gradient descent: `xᵢ ← (xᵢ − τgᵢ)/|…|`, τ from the Barzilai–Borwein ratio
//! `sᵀs/sᵀy` of the last step, made safe by non-monotone Armijo backtracking (the reference is
//! the largest of the last 8 values; `f(τ) ≤ f_ref − 10⁻⁴τ|g|²`), the largest move per step
//! capped at 0.25 rad; a start ends when its best value improved by less than [`STALL_TOL`]
//! over [`STALL`] iterations (or after `--iterations`). Starts: the morphed SF set at phase 0
//! (the renderer's BMC-SF set; cosine-morphed for diffuse), and restarts from the SF set at
//! phase ½ (Phong only: diffuse is invariant under rotation about n) and from seeded jitters
//! of the SF set; the best is kept. Directions are then rounded
//! to f32 (renormalised, rounded again), and `var_sf`, `var_opt` are computed in f64 with the
//! engine's closed-form `zᵢ` (`Rule::kernel_means`) from the stored numbers.
//!
//! [`THETA_NODES`]: xtask_writers::optimal_sets::THETA_NODES
//! [`OPT_DENSITY`]: xtask_writers::optimal_sets::OPT_DENSITY
//! [`kernel_mean_mean`]: xtask_writers::optimal_sets::objective::kernel_mean_mean
//! [`STALL_TOL`]: xtask_writers::optimal_sets::STALL_TOL
//! [`STALL`]: xtask_writers::optimal_sets::STALL

use sphere_quadrature_eval::{cli, parallel};

use parallel::parallel_map;
use std::error::Error;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use clap::Parser;
use xtask_writers::optimal_sets::check::check;
use xtask_writers::optimal_sets::hyperparameters::Hypers;
use xtask_writers::optimal_sets::optimiser::{cpu_seconds, optimise, Outcome};
use xtask_writers::optimal_sets::output::{report, table_text, SWEEP, SWEEP_SIGMAS};
use xtask_writers::optimal_sets::self_test::self_test;
use xtask_writers::optimal_sets::{Options, HYPER_FILE, KEYS, NS, TABLE_FILE};

/// optimal_sets: optimal BMC sample sets (issue #12 item 4): minimise the model's posterior
/// variance over N directions per (N, BRDF) and write them as a table
#[derive(Parser)]
#[command(bin_name = "cargo writer optimal_sets --", verbatim_doc_comment)]
struct Cli {
    /// Where to write the sets (default target/eval/optimal_sets/optimal_sets.txt)
    #[arg(long, value_name = "FILE", conflicts_with = "write")]
    table: Option<PathBuf>,
    /// Write the sets to tables/optimal_sets.txt (all keys and sizes: not
    /// with --only or --n)
    #[arg(long, conflicts_with_all = ["only", "n"], verbatim_doc_comment)]
    write: bool,
    /// Hyperparameters (default tables/renderer_hyperparameters.txt, `err` rows)
    #[arg(long, value_name = "FILE")]
    hyper_file: Option<PathBuf>,
    /// Also write DIR/optimal_sets.md (report; runs a σ′ sweep for it;
    /// `--write --out docs` regenerates the repository's docs)
    #[arg(long, value_name = "DIR", verbatim_doc_comment)]
    out: Option<PathBuf>,
    /// One key only: diffuse, phong1, phong5, phong10, phong20, phong50,
    /// phong100, phong200, phong500 (repeatable)
    #[arg(long, value_name = "KEY", value_parser = KEYS, verbatim_doc_comment)]
    #[arg(hide_possible_values = true)]
    only: Vec<String>,
    /// One size only: 16, 32, 64, 80, 128 (repeatable)
    #[arg(long, value_name = "N", value_parser = baked_size)]
    n: Vec<usize>,
    /// Iteration cap per start
    #[arg(long, value_name = "K", default_value_t = 400)]
    iterations: usize,
    /// Jittered restarts per set besides the SF starts
    #[arg(long, value_name = "R", default_value_t = 1)]
    restarts: usize,
    #[command(flatten)]
    threads: cli::Threads,
    /// Recompute var_sf and var_opt of every set of FILE and fail on a relative
    /// difference above 1e-9 or a direction that is not a unit vector; writes
    /// nothing
    #[arg(long, value_name = "FILE", verbatim_doc_comment)]
    check: Option<PathBuf>,
    /// Analytic gradient against central differences, and consistency checks
    #[arg(long)]
    self_test: bool,
}

/// clap value parser of `--n`: a size with baked sets.
fn baked_size(s: &str) -> Result<usize, String> {
    let n: usize = s.parse().map_err(|e| format!("{e}"))?;
    if NS.contains(&n) {
        Ok(n)
    } else {
        Err(format!("N = {n} is not baked (16, 32, 64, 80 or 128)"))
    }
}

fn parse_args() -> Options {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let c = Cli::parse();
    let root = cli::repo_root();
    Options {
        table: Some(if c.write {
            root.join(TABLE_FILE)
        } else {
            c.table.unwrap_or_else(|| cli::default_out("optimal_sets").join("optimal_sets.txt"))
        }),
        hyper_file: c.hyper_file.unwrap_or_else(|| root.join(HYPER_FILE)),
        out: c.out,
        only: c.only,
        ns: c.n,
        iterations: c.iterations,
        restarts: c.restarts,
        threads: c.threads.count(),
        check: c.check,
        self_test: c.self_test,
        args,
    }
}

fn main() -> Result<(), Box<dyn Error>> {
    let o = parse_args();
    if let Some(path) = &o.check {
        return check(path, o.threads);
    }
    let hyper_text = std::fs::read_to_string(&o.hyper_file)
        .map_err(|e| format!("cannot read {}: {e}", o.hyper_file.display()))?;
    let hypers = Hypers::parse(&hyper_text)?;
    if o.self_test {
        return self_test(&hypers);
    }
    let cpu0 = cpu_seconds();
    let clock = Instant::now();
    let keys: Vec<&str> = KEYS
        .iter()
        .copied()
        .filter(|k| o.only.is_empty() || o.only.iter().any(|x| x == k))
        .collect();
    let ns: Vec<usize> =
        NS.iter().copied().filter(|n| o.ns.is_empty() || o.ns.contains(n)).collect();
    let mut jobs: Vec<(String, usize, f64, f64, String)> = Vec::new();
    for &key in &keys {
        for &n in &ns {
            let (l, s, src) = hypers.get(key, n)?;
            jobs.push((key.to_string(), n, l, s, src));
        }
    }
    // Largest N first, for the workers' balance.
    let mut order: Vec<usize> = (0..jobs.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(jobs[i].1));
    let done = AtomicUsize::new(0);
    let results = parallel_map(&order, o.threads, |_, &i| {
        let (key, n, l, s, src) = &jobs[i];
        let r = optimise(key, *n, *l, *s, src, &o);
        if let Ok(oc) = &r {
            let k = done.fetch_add(1, Ordering::Relaxed) + 1;
            eprintln!(
                "[{k}/{}] {key} N = {n}: var_sf {:.4e} var_opt {:.4e} ({:.2}×), {} ({} it), {:.1} s",
                jobs.len(),
                oc.set.var_sf,
                oc.set.var_opt,
                oc.set.var_sf / oc.set.var_opt,
                oc.runs[oc.best].name,
                oc.runs[oc.best].iterations,
                oc.seconds
            );
        }
        (i, r)
    });
    let mut outcomes: Vec<Option<Outcome>> = vec![None; jobs.len()];
    for (i, r) in results {
        outcomes[i] = Some(r?);
    }
    let outcomes: Vec<Outcome> = outcomes.into_iter().map(|x| x.expect("every job ran")).collect();
    let secs = clock.elapsed().as_secs_f64();
    let cpu1 = cpu_seconds();
    let table = o.table.clone().expect("parse_args sets the table");
    if let Some(dir) = table.parent() {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(&table, table_text(&outcomes, &o, &o.hyper_file))?;
    let cpu = cpu0.zip(cpu1).map(|(a, b)| b - a);
    eprintln!(
        "wrote {} ({} sets) in {secs:.1} s wall ({} s CPU)",
        table.display(),
        outcomes.len(),
        cpu.map_or("?".into(), |c| format!("{c:.1}"))
    );
    if let Some(dir) = &o.out {
        let clock = Instant::now();
        let mut items = Vec::new();
        for (key, n) in SWEEP {
            let (l, _, src) = hypers.get(key, n)?;
            for s in SWEEP_SIGMAS {
                items.push((key, n, l, s, src.clone()));
            }
        }
        let sweep = parallel_map(&items, o.threads, |_, (key, n, l, s, src)| {
            let r = optimise(key, *n, *l, *s, src, &o);
            if let Ok(oc) = &r {
                eprintln!(
                    "sweep {key} N = {n} σ′ = {s}: var_sf {:.4e} var_opt {:.4e} ({:.2}×)",
                    oc.set.var_sf,
                    oc.set.var_opt,
                    oc.set.var_sf / oc.set.var_opt
                );
            }
            r
        })
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?;
        let sweep_secs =
            (clock.elapsed().as_secs_f64(), cpu1.zip(cpu_seconds()).map(|(a, b)| b - a));
        std::fs::create_dir_all(dir)?;
        let path = dir.join("optimal_sets.md");
        std::fs::write(&path, report(&outcomes, &sweep, &o, &table, (secs, cpu), sweep_secs))?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
