//! Sample sets and weights per query: everything one query at one N needs, independent of
//! the map, and the per-query σ′ selection families.

use std::f64::consts::PI;
use std::sync::atomic::{AtomicUsize, Ordering};

use reference::rng::Rng;
use reference::vec::dot;
use sphere_quadrature::qmc::LobeSampler;
use sphere_quadrature::{Lobe, Vec3};

use super::footprint::v32;
use super::hyperparameters::{hyper, key_sf, HyperMap};
use super::{Options, KEYS, NS, SEED_MC, SEED_PHASE, SEED_SOBOL, SEL_L_FACTORS, SEL_SIGMAS};
use crate::optimal;
use crate::parallel::parallel_map;
use crate::renderer_engine as engine;
use crate::renderer_engine::{Brdf, Gls, LobeFrame, Query, Reml, Rule};

/// Everything one query at one N needs, independent of the map.
#[derive(Clone, Debug, Default)]
pub struct Plan {
    pub mc: Vec<[f64; 3]>,
    pub sobol: Vec<[f64; 3]>,
    pub sf: Vec<[f64; 3]>,
    pub bmc_sf: Vec<[f64; 3]>,
    pub w_sf: Vec<f64>,
    /// The crate's renderer: its directions (f32) and weights (f32, `∫p` scale).
    pub crate_dirs: Vec<[f64; 3]>,
    pub w_crate: Vec<f64>,
    /// Weights on `sobol`; empty when the query is not in the bmc-sobol subset.
    pub w_sobol: Vec<f64>,
    /// `z` of `bmc_sf` for every l of the selection family (index 1: the learned l).
    pub z_sf: Vec<Vec<f64>>,
    /// The QMC weights of `bmc_sf` ([`rough_z`]).
    pub qw: Vec<f64>,
    /// `bmc-opt`: the optimal set (world) and its weights; empty without a set.
    pub opt: Vec<[f64; 3]>,
    pub w_opt: Vec<f64>,
    /// `∫p`.
    pub mass: f64,
}

fn mix(seed: u64, q: usize, n: usize) -> u64 {
    let mut r = Rng::new(seed ^ ((q as u64) << 20) ^ n as u64);
    r.next_u64()
}

/// The phase (turns) of the diffuse BMC-SF sets of query `q` at size `n`.
fn diffuse_phase(q: usize, n: usize) -> f64 {
    (mix(SEED_PHASE ^ 0xD1FF, q, n) >> 11) as f64 / (1u64 << 53) as f64
}

/// [`diffuse_phase`] as the crate's phase bits (`turns·2⁶⁴`, exactly).
fn diffuse_phase_bits(q: usize, n: usize) -> u64 {
    (mix(SEED_PHASE ^ 0xD1FF, q, n) >> 11) << 11
}

/// The BMC-SF set of hyperparameter key `key` for query `q` (world directions).
pub fn bmc_sf_set(key: &str, q: &Query, qi: usize, n: usize) -> Vec<[f64; 3]> {
    let (_, brdf, e) = *KEYS.iter().find(|k| k.0 == key).expect("a known key");
    let frame = LobeFrame::new(brdf, q);
    let phase = if brdf == Brdf::Diffuse { diffuse_phase(qi, n) } else { 0.0 };
    engine::sf_set(&frame, n, e, phase)
}

/// `z + σ′²·q`: the nugget read as a rough component of the radiance (white at the sample
/// spacing) whose integral is `Σ qᵢ·εᵢ` with the QMC weights `qᵢ = p(xᵢ)/(N·pdf(xᵢ))` of the
/// set (its lobe `cosᵉ` about the key's axis): `Cov(∫ε·p, εᵢ) = σ′²·qᵢ`. The estimate is then
/// `β∫p + (z + σ′²q)ᵀQ⁻¹(Y − β1)`: QMC as σ′ → ∞, plain BMC as σ′ → 0.
pub fn rough_z(z: &[f64], key: &str, q: &Query, xs: &[[f64; 3]], sigma: f64) -> Vec<f64> {
    let (_, brdf, e) = *KEYS.iter().find(|k| k.0 == key).expect("a known key");
    let axis = brdf.axis(q);
    let n = xs.len() as f64;
    z.iter()
        .zip(xs)
        .map(|(&z, &x)| {
            let pdf = (e + 1.0) / (2.0 * PI) * dot(axis, x).max(0.0).powf(e);
            z + sigma * sigma * brdf.p(q, x) / (n * pdf)
        })
        .collect()
}

fn v64(d: Vec3) -> [f64; 3] {
    [d.x as f64, d.y as f64, d.z as f64]
}

/// One member of a per-query selection family: its REML likelihood and GLS solver, the
/// index of its l in `SEL_L_FACTORS` and its index in the family.
pub struct Member {
    pub reml: Reml,
    pub gls: Gls,
    pub sigma: f64,
    pub l_index: usize,
    pub index: usize,
}

/// Per N index: the selection family of the BMC-SF set: l = learned l × [`SEL_L_FACTORS`],
/// σ′ ∈ [`SEL_SIGMAS`] (members whose `Q` is not numerically positive definite are left out).
/// `Q` of a BMC-SF set is the same for every query, so one family per (BRDF, N) serves all
/// queries.
#[derive(Default)]
pub struct Families {
    pub sf: Vec<Vec<Member>>,
}

pub fn family(xs: &[[f64; 3]], l: f64) -> Vec<Member> {
    let mut out = Vec::new();
    for (li, f) in SEL_L_FACTORS.iter().enumerate() {
        let lambda = 2.0 / (l * f).powi(2);
        for (si, &s) in SEL_SIGMAS.iter().enumerate() {
            if let (Some(reml), Some(gls)) = (Reml::new(xs, lambda, s), Gls::new(xs, lambda, s)) {
                out.push(Member {
                    reml,
                    gls,
                    sigma: s,
                    l_index: li,
                    index: li * SEL_SIGMAS.len() + si,
                });
            }
        }
    }
    out
}

/// `z` of `xs` for every l of the selection family (`rules[k]` resolves the kernels of l
/// factor k).
fn family_z(rules: &[Rule], xs: &[[f64; 3]], l: f64) -> Vec<Vec<f64>> {
    SEL_L_FACTORS
        .iter()
        .zip(rules)
        .map(|(f, rule)| rule.kernel_means(xs, 2.0 / (l * f).powi(2)))
        .collect()
}

/// The plans of every query at every N for one BRDF (`[query][N index]`) and the selection
/// families; counts the bmc-sobol solves that failed.
pub fn plans(
    brdf: Brdf,
    queries: &[Query],
    h: &HyperMap,
    sets: &[optimal::OptimalSet],
    o: &Options,
    failures: &AtomicUsize,
) -> Result<(Vec<Vec<Plan>>, Families), String> {
    // bmc-opt: the seed's model (no rough part) with the hyperparameters the set was
    // optimised for; Q is fixed in the lobe frame.
    let opt_key = if brdf == Brdf::Diffuse { "diffuse".to_string() } else { brdf.name() };
    let opt: Vec<Option<(&optimal::OptimalSet, Gls)>> = NS
        .iter()
        .map(|&n| {
            let set = optimal::find(sets, &opt_key, n)?;
            Some((set, Gls::new(&set.unit_dirs(), set.lambda(), set.sigma)?))
        })
        .collect();
    // BMC-SF: Q is the same for every query (the set is fixed in the lobe frame, or rotated
    // about the normal for diffuse).
    let key = key_sf(brdf);
    let mut gls_sf: Vec<Gls> = Vec::new();
    let mut fam = Families::default();
    let mut hyper_sf = Vec::new();
    for &n in &NS {
        let hs = hyper(h, &key, n)?;
        hyper_sf.push(hs);
        let xs = bmc_sf_set(&key, &queries[0], 0, n);
        gls_sf.push(
            Gls::new(&xs, hs.lambda(), hs.sigma)
                .ok_or(format!("Q of {key} N = {n} is not positive definite"))?,
        );
        fam.sf.push(family(&xs, hs.l));
    }
    // One rule per l factor, each resolving the sharpest kernel of that factor.
    let lambda_max = hyper_sf
        .iter()
        .map(|h| h.lambda())
        .chain(opt.iter().flatten().map(|(s, _)| s.lambda()))
        .fold(0.0, f64::max);
    // Diffuse: z depends only on xᵢ·n, so the sets' z (rotated about n by any phase) are the
    // same for every query: computed once per N in the frame of +z.
    let diffuse_z: Vec<Vec<Vec<f64>>> = if brdf == Brdf::Diffuse {
        let q = Query { n: [0.0, 0.0, 1.0], r: [0.0, 0.0, 1.0] };
        let frame = LobeFrame::new(brdf, &q);
        let rules: Vec<Rule> = SEL_L_FACTORS
            .iter()
            .map(|f| Rule::new(brdf, &frame, lambda_max / (f * f), 1.0))
            .collect();
        NS.iter()
            .enumerate()
            .map(|(ni, &n)| family_z(&rules, &engine::sf_set(&frame, n, 1.0, 0.0), hyper_sf[ni].l))
            .collect()
    } else {
        Vec::new()
    };
    let e = brdf.exponent();
    let lobe = match brdf {
        Brdf::Diffuse => Lobe::Cosine,
        Brdf::Phong(e) => Lobe::Phong(e as f32),
    };
    let plans = parallel_map(queries, o.threads, |qi, q| {
        let frame = LobeFrame::new(brdf, q);
        let rules: Vec<Rule> = SEL_L_FACTORS
            .iter()
            .map(|f| Rule::new(brdf, &frame, lambda_max / (f * f), 1.0))
            .collect();
        let rule = &rules[1]; // SEL_L_FACTORS[1] = 1: the learned l.
        let axis = brdf.axis(q);
        NS.iter()
            .enumerate()
            .map(|(ni, &n)| {
                let mut p = Plan { mass: rule.mass(), ..Plan::default() };
                let mut rng = Rng::new(mix(SEED_MC, qi, n));
                p.mc = (0..n)
                    .map(|_| {
                        reference::peers::lobe_direction(axis, e, rng.next_f64(), rng.next_f64())
                    })
                    .collect();
                let scramble = SEED_SOBOL ^ (qi as u32).wrapping_mul(0x9E37_79B9) ^ n as u32;
                p.sobol = (0..n as u32)
                    .map(|i| {
                        let u1 = sobol_burley::sample(i, 0, scramble) as f64;
                        let u2 = sobol_burley::sample(i, 1, scramble) as f64;
                        reference::peers::lobe_direction(axis, e, u1, u2)
                    })
                    .collect();
                let sampler = LobeSampler::new(v32(axis), lobe, n, mix(SEED_PHASE, qi, n))
                    .expect("unit axis, valid lobe");
                p.sf = sampler.iter().map(v64).collect();
                p.bmc_sf = bmc_sf_set(&key, q, qi, n);
                p.z_sf = match diffuse_z.get(ni) {
                    Some(z) => z.clone(),
                    None => family_z(&rules, &p.bmc_sf, hyper_sf[ni].l),
                };
                p.qw = rough_z(&vec![0.0; n], &key, q, &p.bmc_sf, 1.0);
                let s2 = hyper_sf[ni].sigma.powi(2);
                let zr: Vec<f64> = p.z_sf[1].iter().zip(&p.qw).map(|(z, w)| z + s2 * w).collect();
                p.w_sf = gls_sf[ni].weights(&zr, p.mass, None).0;
                if let Some((set, gls)) = &opt[ni] {
                    p.opt = set.world(&frame);
                    let z = rule.kernel_means(&p.opt, set.lambda());
                    p.w_opt = gls.weights(&z, p.mass, None).0;
                }
                if let Some((dirs, w)) = crate_renderer(brdf, n, q, qi) {
                    p.crate_dirs = dirs;
                    p.w_crate = w;
                }
                if qi < o.sobol_queries {
                    let hs = hyper_sf[ni];
                    match Gls::new(&p.sobol, hs.lambda(), hs.sigma) {
                        Some(gls) => {
                            let z = rule.kernel_means(&p.sobol, hs.lambda());
                            let zr = rough_z(&z, &key, q, &p.sobol, hs.sigma);
                            p.w_sobol = gls.weights(&zr, p.mass, None).0;
                        }
                        None => {
                            failures.fetch_add(1, Ordering::Relaxed);
                        }
                    }
                }
                p
            })
            .collect()
    });
    Ok((plans, fam))
}

/// The crate's renderer for `(brdf, N)` at query `q`: its directions and its weights scaled
/// to `∫p` (`π·w` for `bmc::Renderer`, whose estimate is `π·Σ wᵢYᵢ`), or `None` when that
/// `(N, e)` is not baked. Diffuse takes the query's random phase, as `bmc-sf-f64` does.
fn crate_renderer(brdf: Brdf, n: usize, q: &Query, qi: usize) -> Option<(Vec<[f64; 3]>, Vec<f64>)> {
    use sphere_quadrature::bmc::{GlossyRenderer, Renderer};
    let (normal, mirror) = (v32(q.n), v32(q.r));
    let phase_bits = diffuse_phase_bits(qi, n);
    macro_rules! diffuse {
        ($($n:literal)*) => {
            match n {
                $($n => {
                    let mut d = [Vec3::Z; $n];
                    Renderer::<$n>::new().with_phase(phase_bits).fill_directions(normal, &mut d).ok()?;
                    let w = Renderer::<$n>::weights().iter().map(|&w| PI * f64::from(w));
                    Some((d.iter().map(|&x| v64(x)).collect(), w.collect()))
                })*
                _ => None,
            }
        };
    }
    macro_rules! glossy {
        ($(($n:literal, $e:literal))*) => {
            match (n, brdf.exponent() as u32) {
                $(($n, $e) => {
                    let r = GlossyRenderer::<$n, $e>::new();
                    let (mut d, mut w) = ([Vec3::Z; $n], [0.0f32; $n]);
                    r.fill_directions(normal, mirror, &mut d).ok()?;
                    r.weights(normal, mirror, &mut w).ok()?;
                    Some((d.iter().map(|&x| v64(x)).collect(), w.iter().map(|&w| f64::from(w)).collect()))
                })*
                _ => None,
            }
        };
    }
    match brdf {
        Brdf::Diffuse => diffuse!(16 32 64 80 128),
        Brdf::Phong(_) => {
            glossy!((16, 10)(32, 10)(64, 10)(80, 10)(128, 10)(16, 50)(32, 50)(64, 50)(80, 50)(
                128, 50
            )(16, 200)(32, 200)(64, 200)(80, 200)(128, 200))
        }
    }
}
