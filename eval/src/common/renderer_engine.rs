//! Host-side f64 Bayesian Monte Carlo for arbitrary sample sets, and the other pieces of
//! `eval/src/bin/renderer.rs` that the crate does not provide: the query distribution, the
//! lobe-frame quadrature rule, Phong × cosine ground-truth pixel weights, and filtered
//! importance sampling (FIS) reads of a luminance mip pyramid.
//!
//! # Integrals
//! Per query `(n, r)` (normal, mirror direction, `r·n ≥ 0`) and BRDF:
//! - `diffuse`: `I = ∫ L(x)·p(x) dx` with `p(x) = max(0, n·x)` (irradiance, `∫p = π`);
//! - `phongE`: `p(x) = (e+1)/(2π)·max(0, r·x)ᵉ·max(0, n·x)`, the normalised Phong lobe about
//!   `r` with the cosine factor and the horizon of `n` (`∫p ≤ 1`).
//!
//! # Bayesian Monte Carlo (Rasmussen and Ghahramani 2002)
//! Kernel `k(x, x′) = exp(λ(x·x′ − 1)) + σ′²δ` (`λ = 2/l²`, σ_f = 1), `Q = K + σ′²I`,
//! `zᵢ = ∫ k(xᵢ, x)·p(x) dx`, constant prior mean by generalised least squares
//! (Rasmussen and Williams 2006, eq. 2.42):
//! `w = Q⁻¹z + (∫p − 1ᵀQ⁻¹z)·Q⁻¹1/(1ᵀQ⁻¹1)`, `I ≈ wᵀY`, `Σw = ∫p`; posterior variance
//! `V̄ − zᵀQ⁻¹z + (∫p − 1ᵀQ⁻¹z)²/(1ᵀQ⁻¹1)` with `V̄ = ∫∫ k p p`. Solves by Cholesky in f64
//! with one step of iterative refinement. Hyperparameters by the restricted (REML) marginal
//! likelihood with σ_f profiled out, as `src/probe.rs` documents:
//! `ℓ = −½ log det Q − ½ log 1ᵀQ⁻¹1 − ((N − 1)/2) log(rᵀQ⁻¹r)`, `r = Y − β1`.
//!
//! # The lobe-frame rule ([`Rule`])
//! `zᵢ`, `∫p`, `V̄` and the ground truth of smooth lights are sums over one product rule in the
//! frame of the lobe axis `a` (`r` for Phong, `n` for diffuse), with `c = a·x = cos θ`:
//! - the warp `u = c^(e+1)` (`e = 1` for diffuse) makes the lobe's measure uniform:
//!   `∫ g·p = S·∫₀¹ du · (1/2π)∫ dφ g·h` with `S = 1, h = max(0, n·x)` for Phong and `S = π,
//!   h = 1` for diffuse;
//! - `u` is split into pieces `[2⁻ᵏ⁻¹, 2⁻ᵏ]` (k < 40; the mass below 2⁻⁴⁰ ≈ 10⁻¹² is dropped),
//!   which keeps the branch point of `c = u^(1/(e+1))` at `u = 0` away from every piece, plus
//!   a break at the horizon `u* = sin^(e+1) α` (`cos α = r·n`) graded towards it from below;
//!   Gauss–Legendre on each piece with a node count from its θ-extent times `√λ`;
//! - in φ: rings entirely above the horizon of `n` (`c ≥ sin α`) take the periodic trapezoid
//!   rule; rings cut by it take Gauss–Legendre on the arc `|φ| ≤ arccos(−cot α·cot θ)` (the
//!   frame's first tangent points at `n`), where the integrand is smooth and vanishes
//!   linearly at the ends. Node counts scale with the ring's circumference times `√λ`.
//!
//! Its convergence is measured by `renderer --self-test` (doubling every node count, and
//! against `reference::analytic::SgLight` for diffuse and for Phong without a horizon).

use std::f64::consts::PI;

use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use reference::vec::{cross, dot, frame, normalize};
use sphere_quadrature::envmap::{EquirectMap, MipPyramid};

/// The BRDF of a query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Brdf {
    /// Irradiance, `p = max(0, n·x)`.
    Diffuse,
    /// Normalised Phong about the mirror direction with the cosine factor, exponent `e`.
    Phong(f64),
}

impl Brdf {
    /// `diffuse` or `phongE`.
    pub fn name(self) -> String {
        match self {
            Brdf::Diffuse => "diffuse".into(),
            Brdf::Phong(e) => format!("phong{e}"),
        }
    }

    /// The exponent of the lobe `cosᵉ θ` about the axis the samples are drawn from (the
    /// cosine, `e = 1`, for diffuse).
    pub fn exponent(self) -> f64 {
        match self {
            Brdf::Diffuse => 1.0,
            Brdf::Phong(e) => e,
        }
    }

    /// The lobe axis: `n` for diffuse, `r` for Phong.
    pub fn axis(self, q: &Query) -> [f64; 3] {
        match self {
            Brdf::Diffuse => q.n,
            Brdf::Phong(_) => q.r,
        }
    }

    /// The known part `p(x)` of the integrand.
    pub fn p(self, q: &Query, x: [f64; 3]) -> f64 {
        match self {
            Brdf::Diffuse => dot(q.n, x).max(0.0),
            Brdf::Phong(e) => {
                (e + 1.0) / (2.0 * PI) * dot(q.r, x).max(0.0).powf(e) * dot(q.n, x).max(0.0)
            }
        }
    }

    /// Density of the lobe the QMC/MC samples follow: `(e+1)/(2π)·max(0, a·x)ᵉ`.
    pub fn pdf(self, q: &Query, x: [f64; 3]) -> f64 {
        let e = self.exponent();
        (e + 1.0) / (2.0 * PI) * dot(self.axis(q), x).max(0.0).powf(e)
    }

    /// `p(x)/pdf(x)`: the factor of `L(x)` in the importance-sampled estimate
    /// `I ≈ (1/N)·Σ L(xⱼ)·factor(xⱼ)` (π for diffuse, `max(0, n·x)` for Phong).
    pub fn qmc_factor(self, q: &Query, x: [f64; 3]) -> f64 {
        match self {
            Brdf::Diffuse => PI,
            Brdf::Phong(_) => dot(q.n, x).max(0.0),
        }
    }
}

/// One shading query: the normal `n` and the mirror direction `r` (unit, `r·n ≥ 0`).
#[derive(Clone, Copy, Debug)]
pub struct Query {
    /// Normal.
    pub n: [f64; 3],
    /// Mirror direction.
    pub r: [f64; 3],
}

/// `count` seeded queries: `n` uniform on the sphere, `r = 2(n·v)n − v` for `v`
/// cosine-distributed about `n` (so `r·n = n·v ≥ 0`, with density `2t` in `t = r·n`).
pub fn queries(count: usize, seed: u64) -> Vec<Query> {
    let mut rng = Rng::new(seed);
    (0..count)
        .map(|_| {
            let n = rng.uniform_sphere();
            let l = rng.cosine_hemisphere();
            let (t, b) = frame(n);
            let v: [f64; 3] = std::array::from_fn(|k| l[0] * t[k] + l[1] * b[k] + l[2] * n[k]);
            let nv = dot(n, v);
            let r = normalize(std::array::from_fn(|k| 2.0 * nv * n[k] - v[k]));
            Query { n, r }
        })
        .collect()
}

/// The frame of a query's lobe: axis `a`, first tangent `t₁` towards `n` (Phong), `t₂ = a × t₁`.
#[derive(Clone, Copy, Debug)]
pub struct LobeFrame {
    /// First tangent.
    pub t1: [f64; 3],
    /// Second tangent.
    pub t2: [f64; 3],
    /// The lobe axis.
    pub axis: [f64; 3],
    /// `cos α = a·n` (1 for diffuse).
    pub cos_alpha: f64,
    /// `sin α = |n − (n·a)a|` (0 for diffuse).
    pub sin_alpha: f64,
    /// Whether `p` has the horizon of `n` as well as the lobe's own (Phong).
    pub horizon: bool,
}

impl LobeFrame {
    /// The frame of `brdf` for query `q`: for Phong, `t₁ = (n − (n·r)r)/|…|`, so `n` lies in
    /// the (t₁, a) half-plane at angle α from the axis; for diffuse the frame of
    /// `reference::vec::frame(n)`.
    pub fn new(brdf: Brdf, q: &Query) -> Self {
        match brdf {
            Brdf::Diffuse => {
                let (t1, t2) = frame(q.n);
                Self { t1, t2, axis: q.n, cos_alpha: 1.0, sin_alpha: 0.0, horizon: false }
            }
            Brdf::Phong(_) => {
                let r = q.r;
                let nr = dot(q.n, r);
                let w: [f64; 3] = std::array::from_fn(|k| q.n[k] - nr * r[k]);
                let s = dot(w, w).sqrt();
                let (t1, t2) = if s > 1e-12 {
                    let t1 = w.map(|x| x / s);
                    (t1, cross(r, t1))
                } else {
                    frame(r)
                };
                Self { t1, t2, axis: r, cos_alpha: nr.clamp(0.0, 1.0), sin_alpha: s, horizon: true }
            }
        }
    }

    /// The direction with `cos θ = c`, `sin θ = s` and azimuth φ from `t₁`.
    pub fn direction(&self, c: f64, s: f64, phi: f64) -> [f64; 3] {
        let (sp, cp) = phi.sin_cos();
        std::array::from_fn(|k| s * cp * self.t1[k] + s * sp * self.t2[k] + c * self.axis[k])
    }
}

/// `(cos θ, sin θ)` of the lobe warp: `cos θ = u^(1/(e+1))`, with `1 − cos θ` formed by
/// `expm1` so that heights near the axis keep full precision.
pub fn morph(u: f64, e: f64) -> (f64, f64) {
    let omc = -(u.ln() / (e + 1.0)).exp_m1();
    let c = 1.0 - omc;
    (c, (omc * (2.0 - omc)).max(0.0).sqrt())
}

/// The `n`-point hemisphere spherical Fibonacci set morphed onto the lobe `cosᵉ θ`
/// (`e = 0`: uniform; `e = 1`: cosine) in `frame`, rotated about its axis by `phase` turns:
/// height `uⱼ = 1 − (2j+1)/(2n)`, `cos θⱼ = uⱼ^(1/(e+1))`, `φⱼ = 2π(frac(j/Φ) + phase)`
/// (`reference::sf`, the crate's `LobeSampler` set up to f32 rounding and phase).
pub fn sf_set(frame: &LobeFrame, n: usize, e: f64, phase: f64) -> Vec<[f64; 3]> {
    (0..n as u64)
        .map(|j| {
            let (z, phi) = reference::sf::hemisphere_z_phi(j, n as u64);
            let (c, s) = morph(z, e);
            frame.direction(c, s, phi + 2.0 * PI * phase)
        })
        .collect()
}

/// One ring of a [`Rule`]: its local `(cos θ, sin θ)` and node range.
#[derive(Clone, Copy, Debug)]
struct Ring {
    c: f64,
    s: f64,
    start: usize,
    end: usize,
    /// A full ring (no horizon cut) with `h = A cos φ + B` and weight `wu` in u: its kernel
    /// sum is taken in closed form (Bessel I₀, I₁) instead of over its nodes.
    full: Option<FullRing>,
}

#[derive(Clone, Copy, Debug)]
struct FullRing {
    wu: f64,
    a: f64,
    b: f64,
}

/// A product quadrature rule in the lobe frame for `∫ g(x)·p(x) dx` (module docs): world
/// nodes and weights that include `p`'s horizon factor.
#[derive(Clone, Debug)]
pub struct Rule {
    /// Node directions (world).
    pub nodes: Vec<[f64; 3]>,
    /// Weights: `Σ wₐ g(xₐ) ≈ ∫ g·p`.
    pub weights: Vec<f64>,
    rings: Vec<Ring>,
    axis: [f64; 3],
    t1: [f64; 3],
}

/// Gauss–Legendre rules on `[-1, 1]` by node count, computed once.
fn gl(n: usize) -> &'static (Vec<f64>, Vec<f64>) {
    use std::sync::OnceLock;
    static RULES: OnceLock<Vec<(Vec<f64>, Vec<f64>)>> = OnceLock::new();
    let rules = RULES
        .get_or_init(|| (0..=MAX_GL).map(|k| reference::quad::gauss_legendre(k.max(1))).collect());
    &rules[n.clamp(1, MAX_GL)]
}

const MAX_GL: usize = 256;
/// The `u`-pieces stop at 2⁻ᵏ for k = [`TAIL_PIECES`]: the mass left out is 2⁻⁴⁰ ≈ 9·10⁻¹³.
const TAIL_PIECES: i32 = 40;
/// Kernel terms below e^(−CUT) are skipped.
const CUT: f64 = 40.0;

impl Rule {
    /// The rule for `brdf` in `frame`, resolving kernels (or lights) of sharpness up to
    /// `sharpness`; `density` multiplies every node count (1 is the benchmark's choice;
    /// `--self-test` doubles it to measure convergence).
    pub fn new(brdf: Brdf, frame: &LobeFrame, sharpness: f64, density: f64) -> Self {
        let e = brdf.exponent();
        let scale = match brdf {
            Brdf::Diffuse => PI,
            Brdf::Phong(_) => 1.0,
        };
        let root = sharpness.max(e + 2.0).max(4.0).sqrt();
        let theta_of = |u: f64| {
            let (c, s) = morph(u, e);
            s.atan2(c)
        };
        // Break points in u.
        let mut breaks: Vec<f64> = (0..=TAIL_PIECES).map(|k| 0.5f64.powi(k)).collect();
        let c_star = if frame.horizon { frame.sin_alpha } else { 0.0 };
        let u_star = if c_star > 0.0 { c_star.powf(e + 1.0) } else { 0.0 };
        let u_min = 0.5f64.powi(TAIL_PIECES);
        if u_star > u_min && u_star < 1.0 {
            breaks.push(u_star);
            for j in 1..=8 {
                breaks.push(u_star * (1.0 - 0.5f64.powi(2 * j)));
            }
        }
        breaks.retain(|&b| b >= u_min);
        breaks.sort_by(f64::total_cmp);
        breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-15 * b.abs());

        let mut nodes = Vec::new();
        let mut weights = Vec::new();
        let mut rings = Vec::new();
        for piece in breaks.windows(2) {
            let (a, b) = (piece[0], piece[1]);
            let extent = theta_of(a) - theta_of(b);
            // A piece [a, 2a] keeps the branch point at u = 0 one width away (Bernstein
            // ellipse ρ ≈ 5.8), so its error is about (b − a)·ρ^(−2n): the base count grows
            // with the piece's mass, 2 nodes at 10⁻¹³ to 9 at ½.
            let base = (2.0 + (0.5 * ((b - a) / 1e-13).log10()).ceil()).clamp(2.0, 9.0);
            let count = (density * (base + 1.3 * extent * root)).ceil() as usize;
            let (x, w) = gl(count);
            for (xk, wk) in x.iter().zip(w) {
                let u = 0.5 * (a + b) + 0.5 * (b - a) * xk;
                let wu = 0.5 * (b - a) * wk * scale;
                let (c, s) = morph(u, e);
                let start = nodes.len();
                let full = !frame.horizon || c >= c_star;
                let mut closed = None;
                if full {
                    closed = Some(if frame.horizon {
                        FullRing { wu, a: frame.sin_alpha * s, b: frame.cos_alpha * c }
                    } else {
                        FullRing { wu, a: 0.0, b: 1.0 }
                    });
                    let m = ((density * (8.0 + 1.6 * 2.0 * PI * s * root)).ceil() as usize)
                        .clamp(8, 8192)
                        .next_multiple_of(2);
                    for j in 0..m {
                        let phi = 2.0 * PI * (j as f64 + 0.5) / m as f64;
                        let h = if frame.horizon {
                            (frame.sin_alpha * s * phi.cos() + frame.cos_alpha * c).max(0.0)
                        } else {
                            1.0
                        };
                        nodes.push(frame.direction(c, s, phi));
                        weights.push(wu * h / m as f64);
                    }
                } else {
                    let arg = -c * frame.cos_alpha / (s * frame.sin_alpha);
                    let phi_m = arg.clamp(-1.0, 1.0).acos();
                    if phi_m <= 0.0 {
                        continue;
                    }
                    let m = ((density * (8.0 + 1.6 * 2.0 * phi_m * s * root)).ceil() as usize)
                        .clamp(8, MAX_GL);
                    let (xp, wp) = gl(m);
                    for (xj, wj) in xp.iter().zip(wp) {
                        let phi = phi_m * xj;
                        let h = (frame.sin_alpha * s * phi.cos() + frame.cos_alpha * c).max(0.0);
                        nodes.push(frame.direction(c, s, phi));
                        weights.push(wu * phi_m * wj / (2.0 * PI) * h);
                    }
                }
                rings.push(Ring { c, s, start, end: nodes.len(), full: closed });
            }
        }
        Self { nodes, weights, rings, axis: frame.axis, t1: frame.t1 }
    }

    /// `Σ wₐ g(xₐ) ≈ ∫ g·p`.
    pub fn integrate(&self, g: impl Fn([f64; 3]) -> f64) -> f64 {
        self.nodes.iter().zip(&self.weights).map(|(&x, &w)| w * g(x)).sum()
    }

    /// `∫p`.
    pub fn mass(&self) -> f64 {
        self.weights.iter().sum()
    }

    /// `zᵢ = ∫ exp(λ(xᵢ·x − 1))·p(x) dx` for every sample; rings and nodes where the kernel
    /// is below e⁻⁴⁰ are skipped.
    pub fn kernel_means(&self, xs: &[[f64; 3]], lambda: f64) -> Vec<f64> {
        xs.iter().map(|&x| self.kernel_mean(x, lambda)).collect()
    }

    /// One `zᵢ`. On a full ring (`c`, `s`) with horizon factor `A cos φ + B` the φ-mean of the
    /// kernel is exact: `e^(λ(cₓc + sₓs − 1))·(B·I0e(κ) + A cos φₓ·I1e(κ))`, `κ = λsₓs`
    /// (Bessel generating function); rings cut by the horizon sum their nodes.
    pub fn kernel_mean(&self, x: [f64; 3], lambda: f64) -> f64 {
        self.kernel_mean_with(x, lambda, true)
    }

    /// [`Rule::kernel_mean`] summing every ring's nodes (the periodic trapezoid rule on full
    /// rings), for checking the closed form.
    pub fn kernel_mean_nodes(&self, x: [f64; 3], lambda: f64) -> f64 {
        self.kernel_mean_with(x, lambda, false)
    }

    fn kernel_mean_with(&self, x: [f64; 3], lambda: f64, closed: bool) -> f64 {
        let cx = dot(x, self.axis);
        let sx = {
            let c = cross(x, self.axis);
            dot(c, c).sqrt()
        };
        let cos_phi = if sx > 0.0 { dot(x, self.t1) / sx } else { 0.0 };
        let limit = CUT / lambda;
        let mut sum = 0.0;
        for ring in &self.rings {
            // Largest x·y on the ring is cos(θ − θₓ); 1 − that ≥ limit ⇒ all terms negligible.
            let gap = 1.0 - (ring.c * cx + ring.s * sx);
            if gap > limit {
                continue;
            }
            if let (true, Some(f)) = (closed, ring.full) {
                let kappa = lambda * sx * ring.s;
                let i0 = reference::special::bessel_i0e(kappa);
                let i1 = if f.a == 0.0 { 0.0 } else { bessel_i1e(kappa) };
                sum += f.wu * (-lambda * gap).exp() * (f.b * i0 + f.a * cos_phi * i1);
                continue;
            }
            for a in ring.start..ring.end {
                let y = self.nodes[a];
                let d = [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
                let half = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
                if half < limit {
                    sum += self.weights[a] * (-lambda * half).exp();
                }
            }
        }
        sum
    }

    /// `V̄ = ∫∫ exp(λ(x·x′ − 1))·p(x)·p(x′) dx dx′` by the rule in both variables.
    pub fn kernel_mean_mean(&self, lambda: f64) -> f64 {
        self.nodes.iter().zip(&self.weights).map(|(&x, &w)| w * self.kernel_mean(x, lambda)).sum()
    }

    /// Number of nodes.
    #[allow(clippy::len_without_is_empty)]
    pub fn len(&self) -> usize {
        self.nodes.len()
    }
}

/// `I1e(x) = e^(−x)·I₁(x)` for `x ≥ 0`, as `reference::special::bessel_i0e` computes I0e:
/// the power series `Σ (x/2)^(2k+1)/(k!(k+1)!)` (positive terms) for `x ≤ 20`, the asymptotic
/// expansion `(2πx)^(−½)·Σ tₖ`, `tₖ = tₖ₋₁·((2k − 1)² − 4)/(8kx)`, beyond.
pub fn bessel_i1e(x: f64) -> f64 {
    if x <= 20.0 {
        let q = 0.25 * x * x;
        let mut term = 0.5 * x;
        let mut sum = term;
        let mut k = 1.0;
        while term > 1e-17 * sum {
            term *= q / (k * (k + 1.0));
            sum += term;
            k += 1.0;
        }
        sum * (-x).exp()
    } else {
        let (mut term, mut sum, mut k) = (1.0f64, 1.0f64, 1.0f64);
        loop {
            let next = term * ((2.0 * k - 1.0).powi(2) - 4.0) / (8.0 * k * x);
            if next.abs() >= term.abs() {
                break; // the asymptotic series started to diverge (not reached for x > 20)
            }
            term = next;
            sum += term;
            if term.abs() < 1e-17 * sum.abs() {
                break;
            }
            k += 1.0;
        }
        sum / (2.0 * PI * x).sqrt()
    }
}

/// `Q = K + σ′²I` (row-major), `Kᵢⱼ = exp(−λ|xᵢ − xⱼ|²/2)`.
pub fn gram(xs: &[[f64; 3]], lambda: f64, sigma: f64) -> Vec<f64> {
    let n = xs.len();
    let mut q = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let d: [f64; 3] = std::array::from_fn(|k| xs[i][k] - xs[j][k]);
            let v = (-0.5 * lambda * dot(d, d)).exp();
            q[i * n + j] = v;
            q[j * n + i] = v;
        }
        q[i * n + i] += sigma * sigma;
    }
    q
}

/// A Cholesky factor `Q = LLᵀ` (lower, row-major) with the matrix kept for refinement.
#[derive(Clone, Debug)]
pub struct Cholesky {
    n: usize,
    a: Vec<f64>,
    l: Vec<f64>,
}

impl Cholesky {
    /// Factors the symmetric `n×n` matrix `a`; `None` unless it is numerically positive
    /// definite.
    pub fn new(a: Vec<f64>, n: usize) -> Option<Self> {
        let mut l = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..=i {
                let mut s = a[i * n + j];
                for k in 0..j {
                    s -= l[i * n + k] * l[j * n + k];
                }
                if i == j {
                    if s.is_nan() || s <= 0.0 {
                        return None;
                    }
                    l[i * n + i] = s.sqrt();
                } else {
                    l[i * n + j] = s / l[j * n + j];
                }
            }
        }
        Some(Self { n, a, l })
    }

    /// Size.
    pub fn n(&self) -> usize {
        self.n
    }

    /// `L⁻¹b`.
    pub fn forward(&self, b: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut y = b.to_vec();
        for i in 0..n {
            let s: f64 = (0..i).map(|k| self.l[i * n + k] * y[k]).sum();
            y[i] = (y[i] - s) / self.l[i * n + i];
        }
        y
    }

    fn backward(&self, y: &mut [f64]) {
        let n = self.n;
        for i in (0..n).rev() {
            let s: f64 = (i + 1..n).map(|k| self.l[k * n + i] * y[k]).sum();
            y[i] = (y[i] - s) / self.l[i * n + i];
        }
    }

    /// `Q⁻¹b` with one step of iterative refinement.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let mut x = self.forward(b);
        self.backward(&mut x);
        let n = self.n;
        let r: Vec<f64> =
            (0..n).map(|i| b[i] - (0..n).map(|k| self.a[i * n + k] * x[k]).sum::<f64>()).collect();
        let mut d = self.forward(&r);
        self.backward(&mut d);
        for (xi, di) in x.iter_mut().zip(d) {
            *xi += di;
        }
        x
    }

    /// `log det Q`.
    pub fn log_det(&self) -> f64 {
        (0..self.n).map(|i| 2.0 * self.l[i * self.n + i].ln()).sum()
    }
}

/// The GLS pieces that depend only on the sample set: the factor of `Q`, `Q⁻¹1`, `1ᵀQ⁻¹1`.
#[derive(Clone, Debug)]
pub struct Gls {
    /// The factor of `Q`.
    pub chol: Cholesky,
    ones: Vec<f64>,
    sum_ones: f64,
}

impl Gls {
    /// For the samples `xs` and hyperparameters `(λ, σ′)`; `None` if `Q` is not numerically
    /// positive definite.
    pub fn new(xs: &[[f64; 3]], lambda: f64, sigma: f64) -> Option<Self> {
        let n = xs.len();
        let chol = Cholesky::new(gram(xs, lambda, sigma), n)?;
        let ones = chol.solve(&vec![1.0; n]);
        let sum_ones = ones.iter().sum();
        Some(Self { chol, ones, sum_ones })
    }

    /// Weights `w = Q⁻¹z + (∫p − 1ᵀQ⁻¹z)·Q⁻¹1/(1ᵀQ⁻¹1)` and the posterior variance when
    /// `V̄` is given.
    pub fn weights(&self, z: &[f64], mass: f64, vbar: Option<f64>) -> (Vec<f64>, Option<f64>) {
        let a = self.chol.solve(z);
        let gap = mass - a.iter().sum::<f64>();
        let w = a.iter().zip(&self.ones).map(|(a, b)| a + gap * b / self.sum_ones).collect();
        let var = vbar.map(|v| v - dot_n(z, &a) + gap * gap / self.sum_ones);
        (w, var)
    }
}

fn dot_n(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The REML log marginal likelihood of one sample set for one `(λ, σ′)`, σ_f profiled out.
#[derive(Clone, Debug)]
pub struct Reml {
    chol: Cholesky,
    l1: Vec<f64>,
    s11: f64,
    constant: f64,
}

impl Reml {
    /// For the samples `xs`; `None` if `Q` is not numerically positive definite.
    pub fn new(xs: &[[f64; 3]], lambda: f64, sigma: f64) -> Option<Self> {
        let n = xs.len();
        let chol = Cholesky::new(gram(xs, lambda, sigma), n)?;
        let l1 = chol.forward(&vec![1.0; n]);
        let s11 = dot_n(&l1, &l1);
        let constant = -0.5 * chol.log_det() - 0.5 * s11.ln();
        Some(Self { chol, l1, s11, constant })
    }

    /// `ℓ(Y) = −½ log det Q − ½ log 1ᵀQ⁻¹1 − ((N − 1)/2) log(rᵀQ⁻¹r)`; `None` when the
    /// residual vanishes (a constant `Y`).
    pub fn log_likelihood(&self, y: &[f64]) -> Option<f64> {
        let ly = self.chol.forward(y);
        let s1y = dot_n(&self.l1, &ly);
        let syy = dot_n(&ly, &ly);
        let rqr = syy - s1y * s1y / self.s11;
        if rqr.is_nan() || rqr <= 1e-13 * syy {
            return None;
        }
        Some(self.constant - 0.5 * (self.chol.n() as f64 - 1.0) * rqr.ln())
    }
}

/// Per-pixel ground-truth weights `∫_pixel p(x) dx` of a `width`×`height` equirectangular
/// grid for the normalised Phong lobe about `r` times `max(0, n·x)` (or without the cosine
/// factor when `n` is `None`, for checking against `reference::truth::phong_weights`).
///
/// Each pixel is split into k×k cells (equal steps in θ and φ), each taken at its centre
/// with its exact solid angle; `k` is chosen per pixel so that the midpoint rule's estimated error
/// `Ω·f_max·h²·C/(24k²)` is at most `tol` (absolute, against `∫p ≤ 1`), where `h` is the
/// pixel's angular size, `f_max` the lobe's largest value on the pixel and
/// `C = e²tan²s + e·sec²s` bounds the lobe's relative curvature at the pixel's farthest
/// angle `s` from `r`; pixels cut by the horizon of `n` get k ≥ 8; k ≤ 64. Pixels where the
/// lobe stays below 10⁻¹⁸ of its peak take the centre value.
pub fn phong_cos_weights(
    width: usize,
    height: usize,
    n: Option<[f64; 3]>,
    r: [f64; 3],
    e: f64,
    tol: f64,
) -> Vec<f64> {
    let norm = (e + 1.0) / (2.0 * PI);
    let dphi = 2.0 * PI / width as f64;
    let dtheta = PI / height as f64;
    // Sub-cell trigonometry per column and k (per row and k below).
    let mut col_cache: Vec<Vec<Vec<(f64, f64)>>> = vec![vec![Vec::new(); 65]; width];
    let mut out = vec![0.0; width * height];
    let lobe = |x: [f64; 3]| -> f64 {
        let d = [x[0] - r[0], x[1] - r[1], x[2] - r[2]];
        let gap = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        let f = if gap >= 1.0 { 0.0 } else { (e * (-gap).ln_1p()).exp() };
        let c = n.map_or(1.0, |n| dot(n, x).max(0.0));
        f * c
    };
    for v in 0..height {
        let (th0, th1) = (dtheta * v as f64, dtheta * (v + 1) as f64);
        let (c0, c1) = (th0.cos(), th1.cos());
        let omega = dphi * (c0 - c1);
        let thc = 0.5 * (th0 + th1);
        let (stc, ctc) = thc.sin_cos();
        let smax = if th0 <= 0.5 * PI && th1 >= 0.5 * PI { 1.0 } else { th0.sin().max(th1.sin()) };
        let h = dtheta.max(smax * dphi);
        // Angular radius of the pixel about its centre (half the diagonal, generously).
        let rho = 0.5 * (dtheta * dtheta + (smax * dphi).powi(2)).sqrt();
        let mut row_cache: Vec<Vec<(f64, f64, f64)>> = vec![Vec::new(); 65];
        for u in 0..width {
            let phc = dphi * (u as f64 + 0.5);
            let (sp, cp) = phc.sin_cos();
            let xc = [stc * cp, stc * sp, ctc];
            let s_r = dot(r, xc).clamp(-1.0, 1.0).acos();
            if s_r - rho >= 0.5 * PI {
                continue;
            }
            if let Some(n) = n {
                if dot(n, xc).clamp(-1.0, 1.0).acos() - rho >= 0.5 * PI {
                    continue;
                }
            }
            let near = (s_r - rho).max(0.0);
            let far = (s_r + rho).min(0.5 * PI - 1e-9);
            let f_max = norm * near.cos().powf(e);
            if f_max < 1e-18 * norm {
                out[v * width + u] = norm * lobe(xc) * omega;
                continue;
            }
            let tan = far.tan();
            let curvature = e * e * tan * tan + e * (1.0 + tan * tan) + 1.0;
            let mut k = (h * (omega * f_max * curvature / (24.0 * tol)).sqrt()).ceil() as usize;
            if let Some(n) = n {
                let sn = dot(n, xc).clamp(-1.0, 1.0).acos();
                if (sn - 0.5 * PI).abs() < rho {
                    k = k.max(8);
                }
            }
            let k = k.clamp(1, 64);
            if row_cache[k].is_empty() {
                // Equal steps in θ, each cell at its θ-midpoint with its exact share of the
                // pixel's solid angle (cos θᵢ − cos θᵢ₊₁ = 2 sin θ_mid sin(Δθ/2k)).
                let half = (0.5 * dtheta / k as f64).sin();
                row_cache[k] = (0..k)
                    .map(|i| {
                        let th = th0 + dtheta * (i as f64 + 0.5) / k as f64;
                        let (st, ct) = th.sin_cos();
                        (ct, st, 2.0 * st * half * dphi / omega)
                    })
                    .collect();
            }
            if col_cache[u][k].is_empty() {
                col_cache[u][k] = (0..k)
                    .map(|j| {
                        let (s, c) = (dphi * (u as f64 + (j as f64 + 0.5) / k as f64)).sin_cos();
                        (c, s)
                    })
                    .collect();
            }
            let mut sum = 0.0;
            for &(ct, st, share) in &row_cache[k] {
                let mut row = 0.0;
                for &(cph, sph) in &col_cache[u][k] {
                    row += lobe([st * cph, st * sph, ct]);
                }
                sum += share * row;
            }
            out[v * width + u] = norm * sum * omega / k as f64;
        }
    }
    out
}

/// A luminance mip pyramid for filtered importance sampling: level 0 is the map, level 1
/// the solid-angle weighted 2×2 means (the crate's [`MipPyramid`] stores levels ≥ 2 only),
/// levels ≥ 2 read through [`MipPyramid::texel`].
#[derive(Clone, Debug)]
pub struct LumPyramid {
    levels: Vec<(usize, usize, Vec<f64>)>,
}

impl LumPyramid {
    /// The pyramid of `map`'s luminance.
    pub fn new(map: &EnvMap) -> Self {
        let (w0, h0) = (map.width, map.height);
        let lum0: Vec<f64> =
            map.pixels.iter().map(|p| luminance([p[0] as f64, p[1] as f64, p[2] as f64])).collect();
        let eq = EquirectMap::new(w0, h0, &map.pixels).expect("a valid map");
        let mut buffer = vec![[0.0f32; 3]; MipPyramid::buffer_len(w0, h0)];
        let pyramid = MipPyramid::new(&eq, &mut buffer).expect("buffer of buffer_len");
        let mut levels = vec![(w0, h0, lum0)];
        // Level 1: solid-angle weighted means of 2×2 blocks (the last may be partial).
        let (w1, h1) = (w0.div_ceil(2), h0.div_ceil(2));
        let mut l1 = vec![0.0; w1 * h1];
        for v in 0..h1 {
            for u in 0..w1 {
                let (mut s, mut a) = (0.0, 0.0);
                for vv in 2 * v..(2 * v + 2).min(h0) {
                    let om = map.pixel_solid_angle(vv);
                    for uu in 2 * u..(2 * u + 2).min(w0) {
                        s += om * levels[0].2[vv * w0 + uu];
                        a += om;
                    }
                }
                l1[v * w1 + u] = s / a;
            }
        }
        levels.push((w1, h1, l1));
        for level in 2..pyramid.levels() {
            let (w, h) = pyramid.level_size(level).expect("level in range");
            let mut l = Vec::with_capacity(w * h);
            for v in 0..h {
                for u in 0..w {
                    let t = pyramid.texel(level, u, v).expect("texel in range");
                    l.push(luminance([t[0] as f64, t[1] as f64, t[2] as f64]));
                }
            }
            levels.push((w, h, l));
        }
        Self { levels }
    }

    /// Number of levels.
    #[allow(clippy::len_without_is_empty)]
    pub fn len(&self) -> usize {
        self.levels.len()
    }

    /// Bilinear read of level `l` at `(θ, φ)`: texel centres at `((u + ½)Δφ, (v + ½)Δθ)`,
    /// wrapping in φ, clamped in θ.
    fn bilinear(&self, l: usize, theta: f64, phi: f64) -> f64 {
        let (w, h, data) = &self.levels[l];
        let (w, h) = (*w, *h);
        let fu = phi / (2.0 * PI) * w as f64 - 0.5;
        let fv = (theta / PI * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
        let (u0, v0) = (fu.floor(), fv.floor());
        let (a, b) = (fu - u0, fv - v0);
        let u0 = (u0 as i64).rem_euclid(w as i64) as usize;
        let u1 = (u0 + 1) % w;
        let v0 = v0 as usize;
        let v1 = (v0 + 1).min(h - 1);
        let at = |u: usize, v: usize| data[v * w + u];
        (1.0 - b) * ((1.0 - a) * at(u0, v0) + a * at(u1, v0))
            + b * ((1.0 - a) * at(u0, v1) + a * at(u1, v1))
    }

    /// The filtered luminance in direction `dir` for a sample of solid angle `omega_s`
    /// (Křivánek and Colbert 2008): `lod = max(0, ½·log₂(Ω_s/Ω_p) + bias)` with `Ω_p` the
    /// level-0 pixel's solid angle at `dir`'s row, trilinear between the levels.
    pub fn filtered(&self, dir: [f64; 3], omega_s: f64, bias: f64) -> f64 {
        let (w0, h0, _) = &self.levels[0];
        let rho = dir[0].hypot(dir[1]);
        let theta = rho.atan2(dir[2]);
        let phi = dir[1].atan2(dir[0]).rem_euclid(2.0 * PI);
        let row = ((theta / PI * *h0 as f64) as usize).min(h0 - 1);
        let th0 = PI * row as f64 / *h0 as f64;
        let th1 = PI * (row + 1) as f64 / *h0 as f64;
        let omega_p = 2.0 * PI / *w0 as f64 * (th0.cos() - th1.cos());
        let lod = (0.5 * (omega_s / omega_p).log2() + bias).max(0.0);
        let top = (self.levels.len() - 1) as f64;
        let lod = lod.min(top);
        let l0 = lod.floor() as usize;
        let t = lod - l0 as f64;
        let a = self.bilinear(l0, theta, phi);
        if t > 0.0 && l0 + 1 < self.levels.len() {
            (1.0 - t) * a + t * self.bilinear(l0 + 1, theta, phi)
        } else {
            a
        }
    }
}

/// `∫ a·exp(λ_g(μ·v − 1))·G_f(v·x) dv` for the normalised spherical Gaussian filter
/// `G_f(t) = λ_f/(2π(1 − e^(−2λ_f)))·exp(λ_f(t − 1))`: exact,
/// `a·λ_f/(1 − e^(−2λ_f))·e^(λₘ − λ_g − λ_f)·(1 − e^(−2λₘ))/λₘ`, `λₘ = |λ_g μ + λ_f x|`.
pub fn sg_filtered(axis: [f64; 3], sharpness: f64, amplitude: f64, x: [f64; 3], lf: f64) -> f64 {
    let mu = normalize(axis);
    let u: [f64; 3] = std::array::from_fn(|k| sharpness * mu[k] + lf * x[k]);
    let lm = dot(u, u).sqrt();
    let norm = lf / -(-2.0 * lf).exp_m1();
    let body = if lm < 1e-12 { 2.0 } else { -(-2.0 * lm).exp_m1() / lm };
    amplitude * norm * (lm - sharpness - lf).exp() * body
}
