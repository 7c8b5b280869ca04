//! The optimiser: Riemannian gradient descent with Barzilai–Borwein steps and non-monotone
//! Armijo backtracking from several starts, and the outcome of one (key, N).

use std::path::Path;
use std::time::Instant;

use reference::rng::Rng;

use super::objective::{brdf_of, sf_start, Problem};
use super::{Options, ARMIJO, MAX_MOVE, MEMORY, SEED, STALL, STALL_TOL};
use sphere_quadrature_eval::optimal::{self, unit, OptimalSet};
use sphere_quadrature_eval::renderer_engine::Brdf;

fn norm2(v: &[[f64; 3]]) -> f64 {
    v.iter().map(|a| a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sum()
}

fn max_norm(v: &[[f64; 3]]) -> f64 {
    v.iter().map(|a| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()).fold(0.0, f64::max)
}

/// `xᵢ − τgᵢ`, normalised.
fn retract(xs: &[[f64; 3]], g: &[[f64; 3]], tau: f64) -> Vec<[f64; 3]> {
    xs.iter()
        .zip(g)
        .map(|(x, d)| unit([x[0] - tau * d[0], x[1] - tau * d[1], x[2] - tau * d[2]]))
        .collect()
}

/// The outcome of one start.
#[derive(Clone, Debug)]
pub struct Run {
    pub name: String,
    pub xs: Vec<[f64; 3]>,
    /// Objective (node sums) at the start and at the end.
    pub f0: f64,
    pub f: f64,
    pub iterations: usize,
    pub evaluations: usize,
}

/// Gradient descent from `start` (module docs): at most `max_iter` iterations; stops when the
/// best value improved by less than [`STALL_TOL`] (relative) over the last [`STALL`]
/// iterations.
fn descend(p: &Problem, name: &str, start: Vec<[f64; 3]>, max_iter: usize) -> Run {
    let mut x = start;
    let (mut f, mut g) = p.eval(&x, true).expect("Q of the start is positive definite");
    let f0 = f;
    let mut evaluations = 1;
    let mut history = vec![f];
    let mut best = (f, x.clone());
    let mut best_at: Vec<f64> = vec![f];
    let mut tau = 0.02 / max_norm(&g).max(1e-300);
    let mut iterations = 0;
    while iterations < max_iter {
        let gmax = max_norm(&g);
        let g2 = norm2(&g);
        if gmax == 0.0 || !g2.is_finite() {
            break;
        }
        let reference = history.iter().rev().take(MEMORY).copied().fold(f64::MIN, f64::max);
        let mut t = tau.min(MAX_MOVE / gmax);
        let mut accepted = None;
        while t * gmax > 1e-13 {
            let xn = retract(&x, &g, t);
            evaluations += 1;
            if let Some((fnew, gnew)) = p.eval(&xn, true) {
                if fnew <= reference - ARMIJO * t * g2 {
                    accepted = Some((xn, fnew, gnew));
                    break;
                }
            }
            t *= 0.25;
        }
        let Some((xn, fnew, gnew)) = accepted else { break };
        iterations += 1;
        // Barzilai–Borwein: s = Δx, y = Δg (tangent vectors at nearby points).
        let (mut ss, mut sy) = (0.0, 0.0);
        for i in 0..x.len() {
            for k in 0..3 {
                let s = xn[i][k] - x[i][k];
                ss += s * s;
                sy += s * (gnew[i][k] - g[i][k]);
            }
        }
        tau = if sy > 0.0 { ss / sy } else { 4.0 * t };
        x = xn;
        f = fnew;
        g = gnew;
        history.push(f);
        if f < best.0 {
            best = (f, x.clone());
        }
        best_at.push(best.0);
        if best_at.len() > STALL {
            let old = best_at[best_at.len() - STALL - 1];
            if old - best.0 < STALL_TOL * best.0.abs() {
                break;
            }
        }
    }
    Run { name: name.into(), xs: best.1, f0, f: best.0, iterations, evaluations }
}

/// Rounds each direction to f32 and renormalises it in f32-representable form.
pub fn round_f32(xs: &[[f64; 3]]) -> Vec<[f64; 3]> {
    xs.iter()
        .map(|x| {
            let r = x.map(|v| v as f32 as f64);
            unit(r).map(|v| v as f32 as f64)
        })
        .collect()
}

/// A seeded jitter of `xs`: each direction moved by a random tangent vector of length up
/// to `amount` radians.
pub fn jitter(xs: &[[f64; 3]], amount: f64, rng: &mut Rng) -> Vec<[f64; 3]> {
    xs.iter()
        .map(|&x| {
            let (t1, t2) = reference::vec::frame(x);
            let phi = 2.0 * std::f64::consts::PI * rng.next_f64();
            let r = amount * rng.next_f64().sqrt();
            let (s, c) = phi.sin_cos();
            unit(std::array::from_fn(|k| x[k] + r * (c * t1[k] + s * t2[k])))
        })
        .collect()
}

fn seed_of(key: &str, n: usize) -> u64 {
    let mut h = SEED ^ ((n as u64) << 32);
    for b in key.bytes() {
        h = (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01B3);
    }
    h
}

/// Geometry of a set in the lobe frame (degrees).
#[derive(Clone, Copy, Debug, Default)]
pub struct Geometry {
    pub mean_theta: f64,
    pub max_theta: f64,
    pub min_sep: f64,
    pub mean_nn: f64,
}

fn geometry(xs: &[[f64; 3]]) -> Geometry {
    let deg = 180.0 / std::f64::consts::PI;
    let angle = |a: [f64; 3], b: [f64; 3]| reference::vec::angle_between(a, b) * deg;
    let n = xs.len() as f64;
    let thetas: Vec<f64> = xs.iter().map(|&x| angle(x, [0.0, 0.0, 1.0])).collect();
    let nn: Vec<f64> = xs
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            xs.iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(_, &y)| angle(x, y))
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    Geometry {
        mean_theta: thetas.iter().sum::<f64>() / n,
        max_theta: thetas.iter().copied().fold(0.0, f64::max),
        min_sep: nn.iter().copied().fold(f64::INFINITY, f64::min),
        mean_nn: nn.iter().sum::<f64>() / n,
    }
}

/// One optimised set with its record.
#[derive(Clone, Debug)]
pub struct Outcome {
    pub set: OptimalSet,
    pub source: String,
    pub vbar: f64,
    pub floor: f64,
    pub runs: Vec<Run>,
    pub best: usize,
    pub seconds: f64,
    pub geo_sf: Geometry,
    pub geo_opt: Geometry,
}

/// Optimises one set: every start, the best kept, rounded, reported with the engine's
/// closed form.
pub fn optimise(
    key: &str,
    n: usize,
    l: f64,
    sigma: f64,
    source: &str,
    o: &Options,
) -> Result<Outcome, String> {
    let clock = Instant::now();
    let brdf = brdf_of(key)?;
    let p = Problem::new(brdf, n, l, sigma);
    let sf = sf_start(brdf, n, 0.0);
    let mut starts: Vec<(String, Vec<[f64; 3]>)> = vec![("sf".into(), sf.clone())];
    if let Brdf::Phong(_) = brdf {
        starts.push(("sf-phase-0.5".into(), sf_start(brdf, n, 0.5)));
    }
    let mut rng = Rng::new(seed_of(key, n));
    // Jitter of about half the SF set's mean nearest-neighbour angle.
    let spacing = geometry(&sf).mean_nn.to_radians();
    for r in 0..o.restarts {
        starts.push((format!("sf-jitter-{r}"), jitter(&sf, 0.5 * spacing, &mut rng)));
    }
    let runs: Vec<Run> =
        starts.into_iter().map(|(name, s)| descend(&p, &name, s, o.iterations)).collect();
    let best = (0..runs.len())
        .min_by(|&a, &b| runs[a].f.total_cmp(&runs[b].f))
        .expect("at least one start");
    let dirs = round_f32(&runs[best].xs);
    let var_sf = p.variance(&sf).ok_or("Q of the SF set is not positive definite")?;
    let unit_dirs: Vec<[f64; 3]> = dirs.iter().map(|&d| unit(d)).collect();
    let var_opt = p.variance(&unit_dirs).ok_or("Q of the optimal set is not positive definite")?;
    let geo_sf = geometry(&sf);
    let geo_opt = geometry(&unit_dirs);
    Ok(Outcome {
        set: OptimalSet {
            key: key.into(),
            e: optimal::exponent_of(key)?,
            n,
            l,
            sigma,
            var_sf,
            var_opt,
            dirs,
        },
        source: source.into(),
        vbar: p.vbar(),
        floor: p.floor(),
        runs,
        best,
        seconds: clock.elapsed().as_secs_f64(),
        geo_sf,
        geo_opt,
    })
}

/// `path` relative to the crate root when it lies inside it.
pub fn rel(path: &Path) -> String {
    let root = sphere_quadrature_eval::cli::repo_root();
    path.strip_prefix(root).unwrap_or(path).display().to_string()
}

/// CPU time of this process (user + system) from `/proc/self/stat` (Linux; `None` elsewhere),
/// assuming the usual 100 clock ticks per second.
pub fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which is in parentheses and may contain spaces).
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = f.get(11)?.parse().ok()?;
    let stime: f64 = f.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}
