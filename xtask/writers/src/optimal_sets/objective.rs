//! The objective: the model's posterior variance of a set and its analytic gradient.

use super::{CUT, OPT_DENSITY, THETA_NODES};
use sphere_quadrature_eval::optimal;
use sphere_quadrature_eval::renderer_engine as engine;
use sphere_quadrature_eval::renderer_engine::{Brdf, Gls, LobeFrame, Query, Rule};

/// The brdf of a key.
pub fn brdf_of(key: &str) -> Result<Brdf, String> {
    Ok(match optimal::exponent_of(key)? {
        None => Brdf::Diffuse,
        Some(e) => Brdf::Phong(e),
    })
}

/// The lobe frame as world coordinates: `t₁ = x`, `t₂ = y`, axis `z`.
fn identity_frame() -> LobeFrame {
    LobeFrame {
        t1: [1.0, 0.0, 0.0],
        t2: [0.0, 1.0, 0.0],
        axis: [0.0, 0.0, 1.0],
        cos_alpha: 1.0,
        sin_alpha: 0.0,
        horizon: false,
    }
}

/// The morphed SF set of `brdf` at `phase` in the lobe frame.
pub fn sf_start(brdf: Brdf, n: usize, phase: f64) -> Vec<[f64; 3]> {
    engine::sf_set(&identity_frame(), n, brdf.exponent(), phase)
}

/// `(x, y, z, w)` of a rule's nodes (world = lobe frame).
type Nodes = Vec<[f64; 4]>;
/// Rings `(cos θ, sin θ, start, end)`: runs of nodes at equal height about the axis.
type Rings = Vec<(f64, f64, usize, usize)>;

/// The nodes and rings of `rule` (world = lobe frame, so the height is `z`; the engine's
/// `LobeFrame::direction` puts every node of a ring at exactly the same `z`).
fn rings_of(rule: &Rule) -> (Nodes, Rings) {
    let nodes: Nodes =
        rule.nodes.iter().zip(&rule.weights).map(|(x, &w)| [x[0], x[1], x[2], w]).collect();
    let mut rings: Rings = Vec::new();
    for (a, x) in nodes.iter().enumerate() {
        match rings.last_mut() {
            Some(r) if r.0 == x[2] => r.3 = a + 1,
            _ => rings.push((x[2], x[0].hypot(x[1]), a, a + 1)),
        }
    }
    (nodes, rings)
}

/// `V̄ = Σₐ Σ_b wₐ w_b exp(λ(yₐ·y_b − 1))` over a rule's nodes, ring pair by ring pair: for
/// rings at heights `(c, s)`, `(c′, s′)`, `e^(λ(cc′ + ss′ − 1))·Σₘ εₘ Iₘe(κ)·(Pₘ P′ₘ + Sₘ S′ₘ)`
/// with `κ = λss′`, `ε₀ = 1`, `εₘ = 2`, `Pₘ = Σ w cos mφ`, `Sₘ = Σ w sin mφ` (the generating
/// function `e^(κ cos ψ) = I₀(κ) + 2Σ Iₘ(κ) cos mψ`), orders while `Iₘ/I₀ ≥ 10⁻¹⁸`. The same
/// double sum as the engine's `Rule::kernel_mean_mean` up to its closed form on full rings
/// (`--self-test` compares them: 10⁻¹⁵), in a fraction of a second instead of seconds.
pub fn kernel_mean_mean(
    nodes: &[[f64; 4]],
    rings: &[(f64, f64, usize, usize)],
    lambda: f64,
) -> f64 {
    let m_max = orders(lambda);
    // Fourier sums of each ring's weights (cos mφ, sin mφ by rotation).
    let fourier: Vec<Vec<(f64, f64)>> = rings
        .iter()
        .map(|&(_, s, start, end)| {
            let mut acc = vec![(0.0, 0.0); m_max + 1];
            for y in &nodes[start..end] {
                let (cp, sp) = (y[0] / s, y[1] / s);
                let (mut cm, mut sm) = (1.0, 0.0);
                for a in acc.iter_mut() {
                    a.0 += y[3] * cm;
                    a.1 += y[3] * sm;
                    (cm, sm) = (cm * cp - sm * sp, sm * cp + cm * sp);
                }
            }
            acc
        })
        .collect();
    let limit = CUT / lambda;
    let mut buf = Vec::new();
    let mut total = 0.0;
    for (i, &(c1, s1, _, _)) in rings.iter().enumerate() {
        for (j, &(c2, s2, _, _)) in rings.iter().enumerate().skip(i) {
            let gap = 1.0 - (c1 * c2 + s1 * s2);
            if gap > limit {
                continue;
            }
            bessel_ie_orders(lambda * s1 * s2, m_max, &mut buf);
            let (f1, f2) = (&fourier[i], &fourier[j]);
            let mut sum = 0.5 * buf[0] * (f1[0].0 * f2[0].0 + f1[0].1 * f2[0].1);
            for (m, b) in buf.iter().enumerate().skip(1) {
                sum += b * (f1[m].0 * f2[m].0 + f1[m].1 * f2[m].1);
            }
            let v = 2.0 * (-lambda * gap).exp() * sum;
            total += if i == j { v } else { 2.0 * v };
        }
    }
    total
}

/// One node of the objective: `p` at one `t = cos θₙ` (or diffuse), with two rules: the
/// engine's (density 1) for the reported variance, and a coarser one (density
/// [`OPT_DENSITY`]) whose node sums the optimiser uses.
pub struct Target {
    /// Weight in the objective (the weights sum to 1).
    omega: f64,
    /// `cos θₙ` (1 for diffuse).
    pub t: f64,
    /// The engine's rule and its `∫p`, `V̄` (reported objective).
    pub rule: Rule,
    pub mass: f64,
    pub vbar: f64,
    /// The optimiser's rule: nodes, rings, `∫p`, `V̄`.
    rings: Rings,
    /// The nodes as separate x, y, z, w arrays.
    soa: [Vec<f64>; 4],
    opt_mass: f64,
    opt_vbar: f64,
}

impl Target {
    pub fn new(brdf: Brdf, t: f64, omega: f64, lambda: f64) -> Self {
        // The query whose lobe frame is the identity: r = z, n in the (x, z) half-plane.
        let q = match brdf {
            Brdf::Diffuse => Query { n: [0.0, 0.0, 1.0], r: [0.0, 0.0, 1.0] },
            Brdf::Phong(_) => {
                Query { n: [(1.0 - t * t).max(0.0).sqrt(), 0.0, t], r: [0.0, 0.0, 1.0] }
            }
        };
        let frame = LobeFrame::new(brdf, &q);
        for (a, b) in [(frame.t1, [1.0, 0.0, 0.0]), (frame.t2, [0.0, 1.0, 0.0])] {
            assert!((0..3).all(|k| (a[k] - b[k]).abs() < 1e-15), "lobe frame is not the identity");
        }
        let rule = Rule::new(brdf, &frame, lambda, 1.0);
        let mass = rule.mass();
        let (full_nodes, full_rings) = rings_of(&rule);
        let vbar = kernel_mean_mean(&full_nodes, &full_rings, lambda);
        let coarse = Rule::new(brdf, &frame, lambda, OPT_DENSITY);
        let opt_mass = coarse.mass();
        let (nodes, rings) = rings_of(&coarse);
        let opt_vbar = kernel_mean_mean(&nodes, &rings, lambda);
        let soa = std::array::from_fn(|k| nodes.iter().map(|y| y[k]).collect());
        Self { omega, t, rule, mass, vbar, rings, soa, opt_mass, opt_vbar }
    }

    /// `z(x) = Σ wₐ exp(−λ|x − yₐ|²/2)` and, with `grad`, its gradient in R³
    /// `λ Σ wₐ (yₐ − x) exp(…)`; rings and nodes where the kernel is below e⁻⁴⁰ are skipped.
    pub fn z_grad(&self, x: [f64; 3], lambda: f64, grad: bool) -> (f64, [f64; 3]) {
        let limit = CUT / lambda;
        let (cx, sx) = (x[2], x[0].hypot(x[1]));
        let (mut z, mut g) = (0.0, [0.0; 3]);
        let [nx, ny, nz, nw] = &self.soa;
        for &(c, s, start, end) in &self.rings {
            if 1.0 - (c * cx + s * sx) > limit {
                continue;
            }
            let (xs, ys, zs, ws) =
                (&nx[start..end], &ny[start..end], &nz[start..end], &nw[start..end]);
            if grad {
                let (mut a, mut b0, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0);
                for k in 0..xs.len() {
                    let (d0, d1, d2) = (x[0] - xs[k], x[1] - ys[k], x[2] - zs[k]);
                    let h = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2);
                    if h >= limit {
                        continue;
                    }
                    let v = ws[k] * (-lambda * h).exp();
                    a += v;
                    b0 += v * xs[k];
                    b1 += v * ys[k];
                    b2 += v * zs[k];
                }
                z += a;
                g[0] += b0;
                g[1] += b1;
                g[2] += b2;
            } else {
                let mut a = 0.0;
                for k in 0..xs.len() {
                    let (d0, d1, d2) = (x[0] - xs[k], x[1] - ys[k], x[2] - zs[k]);
                    let h = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2);
                    if h < limit {
                        a += ws[k] * (-lambda * h).exp();
                    }
                }
                z += a;
            }
        }
        let g =
            [lambda * (g[0] - z * x[0]), lambda * (g[1] - z * x[1]), lambda * (g[2] - z * x[2])];
        (z, g)
    }
}

/// The number of Bessel orders `V̄` may need at sharpness `λ` (`κ ≤ λ`): `Iₘ(κ)/I₀(κ)` is
/// below 10⁻¹⁸ beyond `16 + √(90κ)` (`≈ exp(−m²/2κ)` for large κ, `(κ/2)ᵐ/m!` for small).
fn orders(lambda: f64) -> usize {
    16 + (90.0 * lambda).sqrt().ceil() as usize
}

/// `e^(−κ)·Iₘ(κ)` for `m = 0, 1, …` into `out`, stopping after the first order below
/// `10⁻¹⁸·I₀e` or at `m_max`: the ratios `ρₘ = Iₘ/Iₘ₋₁ = κ/(2m + κρₘ₊₁)` by backward
/// recurrence from well beyond the last order (Miller), scaled by `I₀e` of
/// `reference::special`.
fn bessel_ie_orders(kappa: f64, m_max: usize, out: &mut Vec<f64>) {
    out.clear();
    let i0 = reference::special::bessel_i0e(kappa);
    out.push(i0);
    if kappa <= 0.0 {
        return;
    }
    let need = orders(kappa).min(m_max);
    let start = 2 * need + 20;
    let mut ratios = vec![0.0; need + 1];
    let mut rho = 0.0;
    for m in (1..=start).rev() {
        rho = kappa / (2.0 * m as f64 + kappa * rho);
        if m <= need {
            ratios[m] = rho;
        }
    }
    let mut v = i0;
    for &r in &ratios[1..] {
        v *= r;
        out.push(v);
        if v < 1e-18 * i0 {
            break;
        }
    }
}

/// The optimisation problem of one (BRDF, N, l, σ′).
pub struct Problem {
    pub n: usize,
    pub lambda: f64,
    pub sigma: f64,
    pub targets: Vec<Target>,
}

impl Problem {
    pub fn new(brdf: Brdf, n: usize, l: f64, sigma: f64) -> Self {
        Self::with_nodes(brdf, n, l, sigma, THETA_NODES)
    }

    pub fn with_nodes(brdf: Brdf, n: usize, l: f64, sigma: f64, nodes: usize) -> Self {
        let lambda = 2.0 / (l * l);
        let targets = match brdf {
            Brdf::Diffuse => vec![Target::new(brdf, 1.0, 1.0, lambda)],
            Brdf::Phong(_) => {
                let (x, w) = reference::quad::gauss_legendre(nodes);
                x.iter()
                    .zip(&w)
                    .map(|(&xk, &wk)| {
                        let t = 0.5 * (1.0 + xk);
                        // ∫₀¹ 2t f(t) dt = Σ (wₖ/2)·2tₖ·f(tₖ).
                        Target::new(brdf, t, wk * t, lambda)
                    })
                    .collect()
            }
        };
        Self { n, lambda, sigma, targets }
    }

    /// `Σ ω V̄`.
    pub fn vbar(&self) -> f64 {
        self.targets.iter().map(|t| t.omega * t.vbar).sum()
    }

    /// The nugget's floor `Σ ω (∫p)²σ′²/N`: a lower bound of the objective for every set of
    /// N directions. Even with the zero-mean part `g` of `f = β + g` known everywhere, the
    /// constant β (flat prior, the GLS limit) is seen only through `yᵢ − g(xᵢ) = β + εᵢ`,
    /// so `Var(∫f p) ≥ (∫p)²·σ′²/N`; conditioning on more cannot raise a Gaussian posterior
    /// variance.
    pub fn floor(&self) -> f64 {
        let s2 = self.sigma * self.sigma / self.n as f64;
        self.targets.iter().map(|t| t.omega * t.mass * t.mass * s2).sum()
    }

    /// The reported objective: the engine's closed-form `zᵢ` and GLS variance, averaged over
    /// the θₙ nodes. `None` if `Q` is not numerically positive definite.
    pub fn variance(&self, xs: &[[f64; 3]]) -> Option<f64> {
        let gls = Gls::new(xs, self.lambda, self.sigma)?;
        let mut f = 0.0;
        for t in &self.targets {
            let z = t.rule.kernel_means(xs, self.lambda);
            f += t.omega * gls.weights(&z, t.mass, Some(t.vbar)).1?;
        }
        Some(f)
    }

    /// The objective by node sums and, with `grad`, its gradient projected on each tangent
    /// plane (module docs).
    pub fn eval(&self, xs: &[[f64; 3]], grad: bool) -> Option<(f64, Vec<[f64; 3]>)> {
        let n = xs.len();
        let lambda = self.lambda;
        let gls = Gls::new(xs, lambda, self.sigma)?;
        let mut f = 0.0;
        let mut g = vec![[0.0; 3]; if grad { n } else { 0 }];
        let mut m = vec![0.0; if grad { n * n } else { 0 }];
        for t in &self.targets {
            let zg: Vec<(f64, [f64; 3])> = xs.iter().map(|&x| t.z_grad(x, lambda, grad)).collect();
            let z: Vec<f64> = zg.iter().map(|p| p.0).collect();
            let (w, var) = gls.weights(&z, t.opt_mass, Some(t.opt_vbar));
            f += t.omega * var?;
            if grad {
                for (i, (gi, (_, dz))) in g.iter_mut().zip(&zg).enumerate() {
                    let a = -2.0 * t.omega * w[i];
                    for (gk, dk) in gi.iter_mut().zip(dz) {
                        *gk += a * dk;
                    }
                    let b = t.omega * w[i];
                    for (mij, wj) in m[i * n..(i + 1) * n].iter_mut().zip(&w) {
                        *mij += b * wj;
                    }
                }
            }
        }
        if grad {
            for i in 0..n {
                for j in 0..n {
                    if i == j {
                        continue;
                    }
                    let d = [xs[j][0] - xs[i][0], xs[j][1] - xs[i][1], xs[j][2] - xs[i][2]];
                    let k = (-0.5 * lambda * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])).exp();
                    let a = 2.0 * lambda * m[i * n + j] * k;
                    for c in 0..3 {
                        g[i][c] += a * d[c];
                    }
                }
                let x = xs[i];
                let r = g[i][0] * x[0] + g[i][1] * x[1] + g[i][2] * x[2];
                for c in 0..3 {
                    g[i][c] -= r * x[c];
                }
            }
        }
        Some((f, g))
    }
}
