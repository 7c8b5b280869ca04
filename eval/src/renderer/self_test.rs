//! `--self-test`: convergence and consistency checks of the f64 engine.

use std::error::Error;
use std::f64::consts::PI;
use std::time::Instant;

use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use sphere_quadrature::Lobe;

use super::hyperparameters::HyperMap;
use super::{Options, BRDFS, FIS_BIAS, SEED_QUERIES, TRUTH_TOL};
use crate::renderer_engine as engine;
use crate::renderer_engine::{Brdf, Gls, LobeFrame, LumPyramid, Query, Rule};
use crate::{compare, tiers};

pub fn self_test(o: &Options, h: Option<&HyperMap>) -> Result<(), Box<dyn Error>> {
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
