//! `--self-test`: the analytic gradient against central differences, and consistency checks.

use std::error::Error;

use reference::rng::Rng;

use super::hyperparameters::Hypers;
use super::objective::{brdf_of, sf_start, Problem, Target};
use super::optimiser::{jitter, round_f32};
use super::{FD_STEP, OPT_DENSITY, SEED, THETA_NODES};
use sphere_quadrature_eval::optimal::{self, unit, OptimalSet};
use sphere_quadrature_eval::renderer_engine as engine;
use sphere_quadrature_eval::renderer_engine::{Brdf, Gls, LobeFrame, Rule};

pub fn self_test(hypers: &Hypers) -> Result<(), Box<dyn Error>> {
    let mut failures = 0;
    let mut rng = Rng::new(SEED ^ 0x5E1F);
    println!("analytic gradient against central differences (Richardson, h = {FD_STEP:e} and h/2), random tangent");
    println!("directions at a jittered SF set; relative error of the directional derivative:");
    // Fixed (l, σ′), independent of the learned file: large and small nuggets, broad and
    // sharp lobes (cond(Q) up to ~10⁸ for σ′ = 0.001).
    let cases: [(&str, usize, f64, f64); 6] = [
        ("diffuse", 16, 0.9051, 1.0),
        ("phong5", 32, 0.64, 1.0),
        ("phong50", 16, 0.32, 0.5),
        ("phong200", 32, 0.32, 0.2),
        ("phong50", 32, 0.2263, 0.01),
        ("diffuse", 32, 0.9051, 0.001),
    ];
    let _ = hypers;
    for (key, n, l, s) in cases {
        let brdf = brdf_of(key)?;
        let p = Problem::new(brdf, n, l, s);
        let sf = sf_start(brdf, n, 0.0);
        let x = jitter(&sf, 0.05, &mut rng);
        let (_, g) = p.eval(&x, true).ok_or("Q not positive definite")?;
        let mut worst: f64 = 0.0;
        for trial in 0..4 {
            // Trials 0–2: every direction moves; trial 3: one direction only.
            let v: Vec<[f64; 3]> = x
                .iter()
                .enumerate()
                .map(|(i, &xi)| {
                    let (t1, t2) = reference::vec::frame(xi);
                    let (a, b) = (rng.next_f64() - 0.5, rng.next_f64() - 0.5);
                    let on = trial < 3 || i == n / 2;
                    let a = if on { a } else { 0.0 };
                    let b = if on { b } else { 0.0 };
                    std::array::from_fn(|k| a * t1[k] + b * t2[k])
                })
                .collect();
            let analytic: f64 = g.iter().zip(&v).map(|(a, b)| reference::vec::dot(*a, *b)).sum();
            let shift = |s: f64| -> Vec<[f64; 3]> {
                x.iter()
                    .zip(&v)
                    .map(|(a, b)| unit(std::array::from_fn(|k| a[k] + s * b[k])))
                    .collect()
            };
            let central = |h: f64| -> Result<f64, String> {
                let fp = p.eval(&shift(h), false).ok_or("Q")?.0;
                let fm = p.eval(&shift(-h), false).ok_or("Q")?.0;
                Ok((fp - fm) / (2.0 * h))
            };
            // Richardson: (4D(h/2) − D(h))/3 cancels the h² term.
            let (d1, d2, d4) =
                (central(FD_STEP)?, central(0.5 * FD_STEP)?, central(0.25 * FD_STEP)?);
            let numeric = (4.0 * d2 - d1) / 3.0;
            // The difference quotient's own error, from the same rule one step finer: rounding
            // in the objective (cond(Q) ~ 10⁸ at the small nuggets) dominates it there. The
            // check asks for agreement to 10⁻⁶ or to 10× that error, whichever is larger; a
            // wrong term in the gradient is off by O(1).
            let fd_error = (numeric - (4.0 * d4 - d2) / 3.0).abs();
            let rel = (analytic - numeric).abs() / numeric.abs().max(1e-300);
            let rel =
                if (analytic - numeric).abs() <= 10.0 * fd_error { rel.min(1e-6) } else { rel };
            worst = worst.max(rel);
            println!(
                "  {key:9} N = {n:3} σ′ = {s:<6} trial {trial}: analytic {analytic:+.10e}  \
                 numeric {numeric:+.10e}  rel {:.1e} (difference-quotient error {:.1e})",
                (analytic - numeric).abs() / numeric.abs().max(1e-300),
                fd_error / numeric.abs().max(1e-300)
            );
        }
        if worst > 1e-6 {
            println!("  FAIL: {key} N = {n}: worst relative error {worst:.1e} > 1e-6");
            failures += 1;
        }
    }

    println!(
        "\nthe optimiser's objective (node sums, density {OPT_DENSITY}) against the reported one"
    );
    println!("(the engine's closed-form z on its density-1 rule):");
    for (key, n) in [("diffuse", 32), ("phong1", 32), ("phong50", 64), ("phong500", 128)] {
        let (l, s, _) = hypers.get(key, n)?;
        let brdf = brdf_of(key)?;
        let p = Problem::new(brdf, n, l, s);
        let x = sf_start(brdf, n, 0.0);
        let a = p.eval(&x, false).ok_or("Q")?.0;
        let b = p.variance(&x).ok_or("Q")?;
        let mut zmax: f64 = 0.0;
        for t in &p.targets {
            let zc = t.rule.kernel_means(&x, p.lambda);
            for (xi, zi) in x.iter().zip(&zc) {
                let zn = t.z_grad(*xi, p.lambda, false).0;
                zmax = zmax.max((zn - zi).abs() / zi.abs().max(1e-300));
            }
        }
        let rel = (a - b).abs() / b;
        println!(
            "  {key:9} N = {n:3}: objective rel diff {rel:.1e}, largest z rel diff {zmax:.1e}"
        );
        if rel > 1e-6 {
            println!("  FAIL: the optimiser's objective and the reported one disagree");
            failures += 1;
        }
    }

    println!("\nV̄ by ring-pair Fourier sums against the engine's kernel_mean_mean:");
    for (key, n) in [("diffuse", 16), ("phong1", 16), ("phong50", 128), ("phong200", 128)] {
        let (l, s, _) = hypers.get(key, n)?;
        let brdf = brdf_of(key)?;
        let p = Problem::new(brdf, n, l, s);
        let ends = [0, p.targets.len() - 1];
        for t in ends[..if p.targets.len() > 1 { 2 } else { 1 }].iter().map(|&i| &p.targets[i]) {
            let engine = t.rule.kernel_mean_mean(p.lambda);
            let rel = (t.vbar - engine).abs() / engine;
            println!(
                "  {key:9} N = {n:3} t = {:.3}: {:.15e} vs {engine:.15e}: rel {rel:.1e}",
                t.t, t.vbar
            );
            if rel > 1e-10 {
                println!("  FAIL: V̄ disagrees");
                failures += 1;
            }
        }
    }

    println!("\nthe variance identity Var = V̄ − 2wᵀz + wᵀQw at the GLS weights (envelope form):");
    for (key, n) in [("diffuse", 16), ("phong20", 32)] {
        let (l, s, _) = hypers.get(key, n)?;
        let brdf = brdf_of(key)?;
        let p = Problem::new(brdf, n, l, s);
        let x = sf_start(brdf, n, 0.0);
        let gls = Gls::new(&x, p.lambda, s).ok_or("Q")?;
        let q = engine::gram(&x, p.lambda, s);
        for t in &p.targets {
            let z = t.rule.kernel_means(&x, p.lambda);
            let (w, var) = gls.weights(&z, t.mass, Some(t.vbar));
            let var = var.expect("V̄ given");
            let mut wqw = 0.0;
            for i in 0..n {
                for j in 0..n {
                    wqw += w[i] * q[i * n + j] * w[j];
                }
            }
            let wz: f64 = w.iter().zip(&z).map(|(a, b)| a * b).sum();
            let other = t.vbar - 2.0 * wz + wqw;
            let rel = (var - other).abs() / var;
            println!(
                "  {key:9} N = {n:3} t = {:.3}: Var = {var:.6e}, envelope {other:.6e}, rel {rel:.1e}, Σw − ∫p = {:.1e}",
                t.t,
                w.iter().sum::<f64>() - t.mass
            );
            if rel > 1e-8 {
                println!("  FAIL: the envelope form disagrees");
                failures += 1;
            }
        }
    }

    println!("\nθₙ rule of the Phong objective: {THETA_NODES} nodes against 12 (SF set):");
    for (key, n) in [("phong1", 32), ("phong10", 32), ("phong50", 64), ("phong500", 64)] {
        let (l, s, _) = hypers.get(key, n)?;
        let brdf = brdf_of(key)?;
        let x = sf_start(brdf, n, 0.0);
        let a = Problem::new(brdf, n, l, s).variance(&x).ok_or("Q")?;
        let b = Problem::with_nodes(brdf, n, l, s, 12).variance(&x).ok_or("Q")?;
        println!("  {key:9} N = {n:3}: {a:.8e} vs {b:.8e}: rel {:.1e}", (a - b).abs() / b);
    }

    println!(
        "\nOptimalSet::world: a set's variance in a query's world frame equals the lobe frame's:"
    );
    for (key, n) in [("diffuse", 16), ("phong20", 32), ("phong200", 16)] {
        let (l, s, _) = hypers.get(key, n)?;
        let brdf = brdf_of(key)?;
        let lambda = 2.0 / (l * l);
        let dirs = round_f32(&jitter(&sf_start(brdf, n, 0.0), 0.05, &mut rng));
        let set = OptimalSet {
            key: key.into(),
            e: optimal::exponent_of(key)?,
            n,
            l,
            sigma: s,
            var_sf: 0.0,
            var_opt: 0.0,
            dirs,
        };
        for q in engine::queries(2, SEED ^ 0x90) {
            let t = reference::vec::dot(q.n, q.r);
            let lobe = Target::new(brdf, t, 1.0, lambda);
            let xs = set.unit_dirs();
            let gls = Gls::new(&xs, lambda, s).ok_or("Q")?;
            let z = lobe.rule.kernel_means(&xs, lambda);
            let a = gls.weights(&z, lobe.mass, Some(lobe.vbar)).1.expect("V̄ given");
            let frame = LobeFrame::new(brdf, &q);
            let rule = Rule::new(brdf, &frame, lambda, 1.0);
            let world = set.world(&frame);
            let gls = Gls::new(&world, lambda, s).ok_or("Q")?;
            let z = rule.kernel_means(&world, lambda);
            let b = gls.weights(&z, rule.mass(), Some(lobe.vbar)).1.expect("V̄ given");
            let rel = (a - b).abs() / a;
            println!("  {key:9} N = {n:3} r·n = {t:.3}: {a:.12e} vs {b:.12e}: rel {rel:.1e}");
            if rel > 1e-9 {
                println!("  FAIL: world() does not map the lobe frame");
                failures += 1;
            }
        }
    }

    println!(
        "\nhyperparameter interpolation in log e (rows phong10: 0.64, 1 and phong50: 0.32, 0.5):"
    );
    let h = Hypers::parse("err phong10 32 0.64 1\nerr phong50 32 0.32 0.5\ncov phong20 32 9 9\n")?;
    let t = 2f64.ln() / 5f64.ln();
    for (key, want) in [
        ("phong5", (0.64, 1.0)),
        ("phong10", (0.64, 1.0)),
        // ln l and ln σ′ linear in ln e: both halve from e = 10 to 50.
        ("phong20", (0.64 * 0.5f64.powf(t), 0.5f64.powf(t))),
        ("phong500", (0.32, 0.5)),
    ] {
        let (l, s, src) = h.get(key, 32)?;
        let ok = (l - want.0).abs() < 1e-12 && (s - want.1).abs() < 1e-12;
        println!("  {key:9}: l = {l:.6}, σ′ = {s:.6} ({src}) {}", if ok { "ok" } else { "FAIL" });
        if !ok {
            failures += 1;
        }
    }

    println!("\ntable format round trip:");
    let set = OptimalSet {
        key: "phong50".into(),
        e: Some(50.0),
        n: 3,
        l: 0.2263,
        sigma: 0.5,
        var_sf: 1.25e-3,
        var_opt: 1.0e-3,
        dirs: round_f32(&jitter(&sf_start(Brdf::Phong(50.0), 3, 0.0), 0.1, &mut rng)),
    };
    let back = optimal::parse(&set.format())?;
    let ok = back.len() == 1 && back[0] == set;
    println!("  {}", if ok { "ok" } else { "FAIL" });
    if !ok {
        failures += 1;
    }
    if failures > 0 {
        return Err(format!("{failures} self-test failures").into());
    }
    println!("\nself-test passed");
    Ok(())
}
