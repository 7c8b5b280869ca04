//! Evaluation: every estimator on one scene, and the results per tier and BRDF.

use std::f64::consts::PI;

use super::footprint::{crate_fn, exponent, with_lookups};
use super::plans::{Families, Member, Plan};
use super::scenes::Scene;
use super::{
    BMC_F64, BMC_FP, BMC_FP_PYRAMID, BMC_OPT, BMC_SF, BMC_SF_SEL, BMC_SOBOL, E, FIS, MC, NS, SEL,
    SF, SOBOL, SPLIT_SUM,
};
use crate::renderer_engine::{Brdf, Query};

/// One scene's results for one BRDF: relative RMSE per N index and estimator (NaN where not
/// applicable), and how often each family member was selected by `bmc-sf-sel`.
#[derive(Clone, Copy, Debug)]
pub struct Outcome {
    pub rel: [[f64; E]; 5],
    pub selected: [[usize; SEL]; 5],
    /// RMS over the queries of (crate renderer − f64 engine) / mean |truth| per N index (NaN
    /// where the crate has no baked set).
    pub crate_diff: [f64; 5],
    /// The footprint renderer on the queries of `bmc-fp` (exact lookups): relative RMSE of
    /// `bmc-fp` and of `bmc-fp-pyramid` on the same queries, per N index (NaN without a set).
    pub exact: [[f64; 2]; 5],
    /// `bmc-fp-pyramid`'s error bar: queries inside 2σ and queries, per N index.
    pub inside: [[usize; 2]; 5],
    /// Relative RMSE per N index and estimator on the queries of `bmc-fp-pyramid` (the first
    /// `footprint_queries`), so that its ratios to the other estimators are on the same queries.
    pub fp_rel: [[f64; E]; 5],
}

/// `Σ wᵢYᵢ` with the weights of the family member of highest REML likelihood for `y`, and
/// that member's index (`qw`: the set's QMC weights, for [`rough_z`](super::plans::rough_z)).
fn select(members: &[Member], y: &[f64], z: &[Vec<f64>], qw: &[f64], mass: f64) -> (f64, usize) {
    let mut best = (f64::NEG_INFINITY, 0);
    for (k, m) in members.iter().enumerate() {
        if let Some(ll) = m.reml.log_likelihood(y) {
            if ll > best.0 {
                best = (ll, k);
            }
        }
    }
    let m = &members[best.1];
    let zr: Vec<f64> =
        z[m.l_index].iter().zip(qw).map(|(z, q)| z + m.sigma * m.sigma * q).collect();
    let w = m.gls.weights(&zr, mass, None).0;
    (w.iter().zip(y).map(|(w, y)| w * y).sum(), m.index)
}

/// Relative RMSE per N index and estimator from sums of squared errors, counts and sums of
/// |truth| (NaN where nothing was counted).
fn relative(se: &[[f64; E]; 5], count: &[[usize; E]; 5], abs: &[[f64; E]; 5]) -> [[f64; E]; 5] {
    let mut rel = [[f64::NAN; E]; 5];
    for ni in 0..5 {
        for k in 0..E {
            if count[ni][k] > 0 {
                let c = count[ni][k] as f64;
                rel[ni][k] = (se[ni][k] / c).sqrt() / (abs[ni][k] / c);
            }
        }
    }
    rel
}

/// Every estimator on one scene; on a held-out scene, `bmc-fp-pyramid` on the first
/// `footprint_queries` queries and `bmc-fp` on the first `exact_queries` of those.
#[allow(clippy::too_many_arguments)]
pub fn evaluate(
    scene: &Scene,
    brdf: Brdf,
    queries: &[Query],
    plans: &[Vec<Plan>],
    fam: &Families,
    truth: &[f64],
    footprint_queries: usize,
    exact_queries: usize,
) -> Outcome {
    // The footprint renderer's lookups are most of the benchmark's time: they run on the
    // held-out scenes only (the report's figures are over those).
    let footprint_queries = if scene.held_out { footprint_queries } else { 0 };
    let exact_queries = exact_queries.min(footprint_queries);
    with_lookups(scene, |lookups| {
        let mut exact_se = [[0.0f64; 2]; 5];
        let mut exact_abs = [0.0f64; 5];
        let mut inside = [[0usize; 2]; 5];
        let crate_fns: Vec<_> = NS.iter().map(|&n| crate_fn(n, exponent(brdf))).collect();
        let mut se = [[0.0f64; E]; 5];
        let mut count = [[0usize; E]; 5];
        let mut abs = [[0.0f64; E]; 5];
        let (mut fp_se, mut fp_count, mut fp_abs) = (se, count, abs);
        let mut selected = [[0usize; SEL]; 5];
        let mut diff = [(0.0f64, 0usize, 0.0f64); 5];
        let mean = |dirs: &[[f64; 3]], q: &Query| -> f64 {
            dirs.iter().map(|&x| scene.lum(x) * brdf.qmc_factor(q, x)).sum::<f64>()
                / dirs.len() as f64
        };
        let lums = |dirs: &[[f64; 3]]| -> Vec<f64> { dirs.iter().map(|&x| scene.lum(x)).collect() };
        let dot_w = |y: &[f64], w: &[f64]| -> f64 { y.iter().zip(w).map(|(y, w)| y * w).sum() };
        for (qi, (q, &t)) in queries.iter().zip(truth).enumerate() {
            for (ni, &n) in NS.iter().enumerate() {
                let p = &plans[qi][ni];
                let fis =
                    p.sf.iter()
                        .map(|&x| {
                            let omega = (1.0 / (n as f64 * brdf.pdf(q, x))).min(4.0 * PI);
                            scene.filtered(x, omega) * brdf.qmc_factor(q, x)
                        })
                        .sum::<f64>()
                        / n as f64;
                let mut est = [f64::NAN; E];
                est[MC] = mean(&p.mc, q);
                est[SOBOL] = mean(&p.sobol, q);
                est[SF] = mean(&p.sf, q);
                est[FIS] = fis;
                let y_sf = lums(&p.bmc_sf);
                est[BMC_F64] = dot_w(&y_sf, &p.w_sf);
                if !p.w_crate.is_empty() {
                    est[BMC_SF] = dot_w(&lums(&p.crate_dirs), &p.w_crate);
                    diff[ni].0 += (est[BMC_SF] - est[BMC_F64]).powi(2);
                    diff[ni].1 += 1;
                    diff[ni].2 += t.abs();
                }
                let (v, k) = select(&fam.sf[ni], &y_sf, &p.z_sf, &p.qw, p.mass);
                est[BMC_SF_SEL] = v;
                selected[ni][k] += 1;
                if !p.w_sobol.is_empty() {
                    est[BMC_SOBOL] = dot_w(&lums(&p.sobol), &p.w_sobol);
                }
                if !p.w_opt.is_empty() {
                    est[BMC_OPT] = dot_w(&lums(&p.opt), &p.w_opt);
                }
                if let Brdf::Phong(_) = brdf {
                    est[SPLIT_SUM] = lookups.split_sum(exponent(brdf), q.r, p.mass);
                }
                if let Some(f) = crate_fns[ni].filter(|_| qi < footprint_queries) {
                    let r = if brdf == Brdf::Diffuse { q.n } else { q.r };
                    let (v, var) = lookups.render(f, q.n, r, false);
                    est[BMC_FP_PYRAMID] = v;
                    inside[ni][0] += usize::from((v - t).abs() <= 2.0 * var.sqrt());
                    inside[ni][1] += 1;
                    if qi < exact_queries {
                        let (x, _) = lookups.render(f, q.n, r, true);
                        est[BMC_FP] = x;
                        exact_se[ni][0] += (x - t).powi(2);
                        exact_se[ni][1] += (v - t).powi(2);
                        exact_abs[ni] += t.abs();
                    }
                }
                for k in 0..E {
                    if est[k].is_finite() {
                        se[ni][k] += (est[k] - t).powi(2);
                        count[ni][k] += 1;
                        abs[ni][k] += t.abs();
                        if qi < footprint_queries {
                            fp_se[ni][k] += (est[k] - t).powi(2);
                            fp_count[ni][k] += 1;
                            fp_abs[ni][k] += t.abs();
                        }
                    }
                }
            }
        }
        let rel = relative(&se, &count, &abs);
        let fp_rel = relative(&fp_se, &fp_count, &fp_abs);
        let crate_diff =
            diff.map(
                |(sq, c, a)| {
                    if c == 0 {
                        f64::NAN
                    } else {
                        (sq / c as f64).sqrt() / (a / c as f64)
                    }
                },
            );
        let nq = queries.len().min(exact_queries) as f64;
        let exact: [[f64; 2]; 5] = std::array::from_fn(|ni| {
            exact_se[ni].map(|s| {
                if exact_abs[ni] > 0.0 {
                    (s / nq).sqrt() / (exact_abs[ni] / nq)
                } else {
                    f64::NAN
                }
            })
        });
        Outcome { rel, selected, crate_diff, exact, inside, fp_rel }
    })
}

/// Per (tier, BRDF): the scenes' names, held-out flags and results.
#[derive(Clone, Default)]
pub struct TierResult {
    pub names: Vec<String>,
    pub held_out: Vec<bool>,
    pub rel: Vec<[[f64; E]; 5]>,
    pub selected: Vec<[[usize; SEL]; 5]>,
    pub crate_diff: Vec<[f64; 5]>,
    pub exact: Vec<[[f64; 2]; 5]>,
    pub inside: Vec<[[usize; 2]; 5]>,
    /// Per scene: [`Outcome::fp_rel`].
    pub fp_rel: Vec<[[f64; E]; 5]>,
}

impl TierResult {
    pub fn subset(&self) -> Vec<usize> {
        let held: Vec<usize> = (0..self.names.len()).filter(|&k| self.held_out[k]).collect();
        if held.is_empty() {
            (0..self.names.len()).collect()
        } else {
            held
        }
    }

    /// The same results with `rel` on the footprint renderer's queries ([`Outcome::fp_rel`]).
    pub fn on_footprint_queries(&self) -> Self {
        Self { rel: self.fp_rel.clone(), ..self.clone() }
    }

    /// Mean over the held-out maps of estimator `e` at N index `ni`.
    pub fn mean(&self, ni: usize, e: usize) -> f64 {
        let s = self.subset();
        s.iter().map(|&k| self.rel[k][ni][e]).sum::<f64>() / s.len().max(1) as f64
    }

    /// (mean of per-map ratios a/b, ratio of means, worst (ratio, map)) over the held-out maps.
    pub fn ratios(&self, ni: usize, a: usize, b: usize) -> (f64, f64, f64, String) {
        let s = self.subset();
        let mut sum = 0.0;
        let mut worst = (f64::NEG_INFINITY, String::new());
        for &k in &s {
            let r = self.rel[k][ni][a] / self.rel[k][ni][b];
            sum += r;
            if r > worst.0 || r.is_nan() {
                worst = (r, self.names[k].clone());
            }
        }
        (sum / s.len().max(1) as f64, self.mean(ni, a) / self.mean(ni, b), worst.0, worst.1)
    }
}
