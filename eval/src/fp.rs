//! The footprint renderer's model ([`crate::gen::fp`], the generator of its tables), with the
//! checks that need the evaluation engine: `p_lm`, `z` and `V̄` against the engine's product
//! rule.

pub use crate::gen::fp::*;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gen::sg::gauss_legendre;
    use crate::renderer_engine::{Brdf, LobeFrame, Query, Rule};
    use std::f64::consts::PI;

    /// The real harmonics are orthonormal (a fine product rule).
    #[test]
    fn harmonics_are_orthonormal() {
        let lmax = 12;
        let width = (lmax + 1) * (lmax + 1);
        let mut gram = vec![0.0; width * width];
        let (x, w) = gauss_legendre(40);
        let m = 80;
        for (xk, wk) in x.iter().zip(&w) {
            let s = (1.0 - xk * xk).sqrt();
            for j in 0..m {
                let phi = 2.0 * PI * j as f64 / m as f64;
                let y = sh(lmax, [s * phi.cos(), s * phi.sin(), *xk]);
                let weight = wk * 2.0 * PI / m as f64;
                for a in 0..width {
                    for b in 0..width {
                        gram[a * width + b] += weight * y[a] * y[b];
                    }
                }
            }
        }
        for a in 0..width {
            for b in 0..width {
                let want = if a == b { 1.0 } else { 0.0 };
                assert!(
                    (gram[a * width + b] - want).abs() < 1e-12,
                    "{a} {b} {}",
                    gram[a * width + b]
                );
            }
        }
    }

    /// `p_lm` against the engine's product rule, and `z` and `V̄` of point samples against
    /// its kernel means.
    #[test]
    fn coefficients_match_the_engine_rule() {
        let l = 0.6;
        let lambda = 2.0 / (l * l);
        let lmax = degree_cut(lambda);
        for (e, alpha) in [(0.0, 0.0), (10.0, 1.2), (50.0, 1.45)] {
            let p = if e == 0.0 { Integrand::irradiance() } else { Integrand::phong(e, alpha) };
            let coef = p.coefficients(lmax, 160);
            // The engine's frame: n in the (t₁, a) plane at angle α.
            let (brdf, q) = if e == 0.0 {
                (Brdf::Diffuse, Query { n: [0.0, 0.0, 1.0], r: [0.0, 0.0, 1.0] })
            } else {
                (Brdf::Phong(e), Query { n: [alpha.sin(), 0.0, alpha.cos()], r: [0.0, 0.0, 1.0] })
            };
            let frame = LobeFrame::new(brdf, &q);
            let rule = Rule::new(brdf, &frame, lambda.max(100.0), 1.0);
            let mass = (4.0 * PI).sqrt() * coef[0];
            assert!(
                (mass - rule.mass()).abs() < 1e-10 * rule.mass(),
                "{e} {alpha}: {mass} {}",
                rule.mass()
            );
            // Point samples: z.
            let xs = lobe_set(16, if e == 0.0 { 1 } else { e as u32 });
            let world: Vec<[f64; 3]> = xs
                .iter()
                .map(|x| {
                    frame.direction(x[2], (x[0] * x[0] + x[1] * x[1]).sqrt(), x[1].atan2(x[0]))
                })
                .collect();
            let design = Design::new(xs, vec![0.0; 16], lmax);
            let model = Model::new(&design, l, 1e-2).unwrap();
            let z = model.z(&design, &coef);
            let z_rule = rule.kernel_means(&world, lambda);
            let top = z_rule.iter().cloned().fold(0.0, f64::max);
            for (a, b) in z.iter().zip(&z_rule) {
                assert!((a - b).abs() < 1e-9 * top, "{e} {alpha}: z {a} {b}");
            }
            let vbar: f64 = (0..=lmax)
                .map(|l| {
                    model.kappa[l]
                        * (l * l..(l + 1) * (l + 1)).map(|k| coef[k] * coef[k]).sum::<f64>()
                })
                .sum();
            let vbar_rule = rule.kernel_mean_mean(lambda);
            assert!(
                (vbar - vbar_rule).abs() < 1e-8 * vbar_rule,
                "{e} {alpha}: V̄ {vbar} {vbar_rule}"
            );
        }
    }

    /// `u(w)` equals `V̄ − 2wᵀz + wᵀQw` where that does not cancel.
    #[test]
    fn unit_variance_is_the_quadratic_form() {
        let lmax = degree_cut(2.0 / 0.36);
        let p = Integrand::phong(10.0, 0.7).coefficients(lmax, 120);
        let xs = lobe_set(24, 10);
        let sharp = footprints(&xs, 10.0, 16.0);
        let design = Design::new(xs, sharp, lmax);
        let model = Model::new(&design, 0.6, 0.05).unwrap();
        let w: Vec<f64> = (0..24).map(|j| 0.03 + 0.001 * j as f64).collect();
        let u = model.unit_variance(&design.residual_power(&p, &w), &w);
        let z = model.z(&design, &p);
        let vbar: f64 = (0..=lmax)
            .map(|l| model.kappa[l] * (l * l..(l + 1) * (l + 1)).map(|k| p[k] * p[k]).sum::<f64>())
            .sum();
        // wᵀQw.
        let n = 24;
        let q = model.matrix();
        let wqw: f64 =
            (0..n).map(|i| (0..n).map(|j| w[i] * q[i * n + j] * w[j]).sum::<f64>()).sum();
        let direct = vbar - 2.0 * w.iter().zip(&z).map(|(a, b)| a * b).sum::<f64>() + wqw;
        assert!((u - direct).abs() < 1e-9 * vbar, "{u} {direct}");
    }

    /// With all `N − 1` contrasts the reduced fit is REML: the same `σ̂²`, and likelihoods
    /// that differ between models by the same constant.
    #[test]
    fn all_contrasts_give_reml() {
        let lmax = degree_cut(2.0 / 0.36);
        let xs = lobe_set(12, 10);
        let sharp = footprints(&xs, 10.0, 16.0);
        let design = Design::new(xs, sharp, lmax);
        let a = Model::new(&design, 0.6, 1e-3).unwrap();
        let b = Model::new(&design, 1.0, 1e-2).unwrap();
        let c = Contrasts::new(&a, 11);
        let y: Vec<f64> = (0..12).map(|j| 1.0 + (j as f64 * 0.7).sin()).collect();
        let t = c.apply(&y);
        let (fa, fb) = (a.reduced(&c).unwrap().fit(&t), b.reduced(&c).unwrap().fit(&t));
        let (ra, rb) = (a.reml(&y), b.reml(&y));
        assert!((fa.0 - ra.0).abs() < 1e-9 * ra.0 && (fb.0 - rb.0).abs() < 1e-9 * rb.0);
        assert!(((fa.1 - fb.1) - (ra.1 - rb.1)).abs() < 1e-7, "{fa:?} {fb:?} {ra:?} {rb:?}");
    }
}
