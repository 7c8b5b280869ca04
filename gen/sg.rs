//! Generator of the spherical-Gaussian integral tables (issue #4), in f64.
//!
//! A unit spherical Gaussian G(v) = exp(λ(μ·v − 1)) whose axis makes cosine t with the normal n
//! has, over the hemisphere {v : n·v ≥ 0}, the integral H(λ, t) and, weighted by the clamped
//! cosine max(0, n·v), the integral C(λ, t). Both are normalised by the full-sphere integral
//! F(λ) = 2π(1 − e^(−2λ))/λ (Hn = H/F, Cn = C/F) and stored for t ≥ 0 only:
//!
//! - `hemi`: R = (Hn − 1/2)/(tanh(λ/2)/2) ∈ [0, 1]. Hn(−t) = 1 − Hn(t), and at the pole
//!   Hn(λ, 1) = 1/(1 + e^(−λ)) = 1/2 + tanh(λ/2)/2 exactly, so R runs from 0 at the horizon
//!   to 1 at the pole for every λ: the stored function is the shape of the transition only
//!   (the "interpolation factor" of Meder & Brüderlin 2018 and Tokuyoshi 2022, exactly).
//! - `clamped`: Z = Cn − t·L(λ), where L(λ) = coth λ − 1/λ is the Langevin function (the mean
//!   of μ·v under the normalised lobe). Since C(t) − C(−t) = ∫ G·(n·v) = t·F·L, Z is even in
//!   t; it is ≥ 0, concentrated at the horizon, and small and smooth where Cn itself grows
//!   like t. Cn(t) = Z(|t|) + max(t, 0)·L(λ).
//!
//! # Grid
//! Node (i, j) of a table of `lambda_nodes × t_nodes` values (row-major, λ rows) sits at
//!
//! - x_i = i/(lambda_nodes − 1) with x = √λ/(√λ + c_λ), so λ = (c_λ·x/(1 − x))²: the last row
//!   is λ = ∞, where the tables hold the exact limits (R = erf(s/√2), Z = 0), so every finite
//!   λ is inside the table;
//! - y_j = j/(t_nodes − 1) with y = t·√((1 + k²)/(1 + k²t²)), k = c_h·√λ: an algebraic sigmoid
//!   whose width 1/k follows the width ~1/√λ of the horizon transition, so that at large λ
//!   the table is a function of s = √λ·t (t = y/√(1 + k²(1 − y²))).
//!
//! c_λ (`lambda_scale`) and c_h (`horizon_scale`) are rounded to f32 first, so that the f32
//! run-time maps hit the nodes exactly.
//!
//! # Quadrature
//! In the frame of the SG axis, with u = μ·v and the azimuth φ about μ,
//! n·v = t·u + w·√(1 − u²)·cos φ with w = √(1 − t²). The φ-integrals are elementary: the measure
//! of {φ : n·v ≥ 0} is 2γ and ∫ max(0, n·v) dφ = 2(t·u·γ + w·√(1 − u²)·sin γ), with
//! γ = arccos(clamp(−t·u/(w√(1 − u²)))). For u ≥ w (t ≥ 0) the whole circle is above the
//! horizon (γ = π) and the u-integral is done in closed form; on |u| ≤ w the substitution
//! u = w·cos δ, δ ∈ [0, π], removes the square-root end singularities:
//! γ = arccos(−t·cos δ/√(t² + w² sin² δ)) and w√(1 − u²)·sin γ = w·sin δ. The δ-integral uses
//! 16-point Gauss–Legendre on panels graded geometrically towards both ends, down to 1/8 of
//! the smallest feature (the lobe width 1/√(λw) and the horizon-crossing width t/w).
//! No Bessel functions: the reference crate's quadrature (I₀ in the polar angle, adaptive
//! Gauss–Kronrod) is an independent check; they agree to ≈1e-15.

use std::f64::consts::PI;
use std::fmt::Write as _;

/// The file in `tables/` that says what to bake.
pub const CONFIG_FILE: &str = "tables/sg.txt";

/// The size of one table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Grid {
    /// Nodes along x = √λ/(√λ + c_λ) ∈ [0, 1] (the last one is λ = ∞).
    pub lambda_nodes: usize,
    /// Nodes along y ∈ [0, 1] (t ∈ [0, 1]).
    pub t_nodes: usize,
}

/// What to bake: read from [`CONFIG_FILE`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// The hemispherical table.
    pub hemi: Grid,
    /// The clamped-cosine table.
    pub clamped: Grid,
    /// c_λ: the λ at the middle of the x axis is c_λ².
    pub lambda_scale: f32,
    /// c_h: the horizon coordinate's steepness per √λ.
    pub horizon_scale: f32,
}

/// Parses `key = value` lines; `#` starts a comment; every key is required, unknown and
/// repeated keys are errors.
pub fn parse(text: &str) -> Result<Config, String> {
    const KEYS: [&str; 6] = [
        "hemi_lambda_nodes",
        "hemi_t_nodes",
        "clamped_lambda_nodes",
        "clamped_t_nodes",
        "lambda_scale",
        "horizon_scale",
    ];
    let mut vals: [Option<&str>; 6] = [None; 6];
    for (no, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let (k, v) = line
            .split_once('=')
            .ok_or_else(|| format!("line {}: expected `key = value`", no + 1))?;
        let (k, v) = (k.trim(), v.trim());
        let idx = KEYS
            .iter()
            .position(|&key| key == k)
            .ok_or_else(|| format!("line {}: unknown key `{k}`", no + 1))?;
        if vals[idx].replace(v).is_some() {
            return Err(format!("line {}: `{k}` given twice", no + 1));
        }
    }
    let get = |i: usize| vals[i].ok_or_else(|| format!("missing `{}`", KEYS[i]));
    let nodes = |i: usize| -> Result<usize, String> {
        let n: usize = get(i)?.parse().map_err(|e| format!("`{}`: {e}", KEYS[i]))?;
        if (4..=4096).contains(&n) {
            Ok(n)
        } else {
            Err(format!("`{}` = {n} must be in 4..=4096 (cubic stencils)", KEYS[i]))
        }
    };
    let scale = |i: usize| -> Result<f32, String> {
        let c: f32 = get(i)?.parse().map_err(|e| format!("`{}`: {e}", KEYS[i]))?;
        // c_h ≤ 1 keeps the run-time k² = c_h²·λ finite for every finite f32 λ.
        let max = if i == 5 { 1.0 } else { f32::MAX };
        if c.is_finite() && c > 0.0 && c <= max {
            Ok(c)
        } else {
            Err(format!("`{}` = {c} must be positive and at most {max}", KEYS[i]))
        }
    };
    Ok(Config {
        hemi: Grid { lambda_nodes: nodes(0)?, t_nodes: nodes(1)? },
        clamped: Grid { lambda_nodes: nodes(2)?, t_nodes: nodes(3)? },
        lambda_scale: scale(4)?,
        horizon_scale: scale(5)?,
    })
}

/// The tables, rounded once to f32, row-major with `t_nodes` values per λ row.
#[derive(Clone, Debug, PartialEq)]
pub struct Tables {
    /// R = (Hn − 1/2)/(tanh(λ/2)/2) at the nodes of `Config::hemi`.
    pub hemi: Vec<f32>,
    /// Z = C/F − t·L(λ) at the nodes of `Config::clamped`.
    pub clamped: Vec<f32>,
}

/// λ of row `i` (∞ for the last row).
pub fn node_lambda(cfg: &Config, grid: &Grid, i: usize) -> f64 {
    let x = i as f64 / (grid.lambda_nodes - 1) as f64;
    if i + 1 == grid.lambda_nodes {
        f64::INFINITY
    } else {
        let r = f64::from(cfg.lambda_scale) * x / (1.0 - x);
        r * r
    }
}

/// y of column `j`.
pub fn node_y(grid: &Grid, j: usize) -> f64 {
    j as f64 / (grid.t_nodes - 1) as f64
}

/// t = y/√(1 + k²(1 − y²)) with k = c_h·√λ, for finite λ.
pub fn t_of_y(cfg: &Config, lambda: f64, y: f64) -> f64 {
    let k2 = f64::from(cfg.horizon_scale).powi(2) * lambda;
    y / (1.0 + k2 * (1.0 - y) * (1.0 + y)).sqrt()
}

/// The horizon coordinate y of t ∈ [0, 1], for finite λ.
pub fn y_of_t(cfg: &Config, lambda: f64, t: f64) -> f64 {
    let k2 = f64::from(cfg.horizon_scale).powi(2) * lambda;
    t * ((1.0 + k2) / (1.0 + k2 * t * t)).sqrt()
}

/// The x coordinate of λ.
pub fn x_of_lambda(cfg: &Config, lambda: f64) -> f64 {
    let r = lambda.sqrt();
    r / (r + f64::from(cfg.lambda_scale))
}

/// s = √λ·t at λ = ∞ for the horizon coordinate y < 1.
fn s_at_infinity(cfg: &Config, y: f64) -> f64 {
    y / (f64::from(cfg.horizon_scale) * ((1.0 - y) * (1.0 + y)).sqrt())
}

/// Bakes both tables.
pub fn tables(cfg: &Config) -> Tables {
    let mut hemi = Vec::with_capacity(cfg.hemi.lambda_nodes * cfg.hemi.t_nodes);
    let g = &cfg.hemi;
    for i in 0..g.lambda_nodes {
        let lambda = node_lambda(cfg, g, i);
        for j in 0..g.t_nodes {
            let y = node_y(g, j);
            let last = j + 1 == g.t_nodes;
            let r = if i == 0 {
                y // λ = 0: Hn − 1/2 = λt/4 + O(λ²), tanh(λ/2)/2 = λ/4 + O(λ³), t = y
            } else if lambda.is_infinite() {
                // Hn → Φ(s), so R → 2Φ(s) − 1 = erf(s/√2).
                if last {
                    1.0
                } else {
                    1.0 - erfc(s_at_infinity(cfg, y) / std::f64::consts::SQRT_2)
                }
            } else {
                let t = if last { 1.0 } else { t_of_y(cfg, lambda, y) };
                let hn = fractions_upper(lambda, t).0;
                (hn - 0.5) / (0.5 * (0.5 * lambda).tanh())
            };
            hemi.push(r as f32);
        }
    }
    let mut clamped = Vec::with_capacity(cfg.clamped.lambda_nodes * cfg.clamped.t_nodes);
    let g = &cfg.clamped;
    for i in 0..g.lambda_nodes {
        let lambda = node_lambda(cfg, g, i);
        for j in 0..g.t_nodes {
            let z = if lambda.is_infinite() {
                0.0 // Z = O(1/√λ)
            } else {
                let t = if j + 1 == g.t_nodes { 1.0 } else { t_of_y(cfg, lambda, node_y(g, j)) };
                fractions_upper(lambda, t).1 - t * langevin(lambda)
            };
            clamped.push(z as f32);
        }
    }
    Tables { hemi, clamped }
}

/// The Rust source that `build.rs` writes to `$OUT_DIR/sg_tables.rs`.
pub fn render(cfg: &Config, tables: &Tables) -> String {
    let mut s = String::new();
    s.push_str("// @generated by build.rs; do not edit\n");
    let _ = writeln!(s, "// From gen/sg.rs and {CONFIG_FILE}.");
    let _ = writeln!(s, "\n/// c_λ of x = √λ/(√λ + c_λ).");
    let _ = writeln!(
        s,
        "pub(crate) const SG_LAMBDA_SCALE: f32 = {}; // {:?}",
        bits(cfg.lambda_scale),
        cfg.lambda_scale
    );
    let _ = writeln!(s, "/// c_h of y = t·√((1 + k²)/(1 + k²t²)), k = c_h·√λ.");
    let _ = writeln!(
        s,
        "pub(crate) const SG_HORIZON_SCALE: f32 = {}; // {:?}",
        bits(cfg.horizon_scale),
        cfg.horizon_scale
    );
    for (name, doc, g, v) in [
        ("HEMI", "R = (Hn − 1/2)/(tanh(λ/2)/2)", &cfg.hemi, &tables.hemi),
        ("CLAMPED", "Z = C/F − t·L(λ)", &cfg.clamped, &tables.clamped),
    ] {
        let _ = writeln!(s, "\n/// λ rows of `SG_{name}` (the last one is λ = ∞).");
        let _ = writeln!(s, "pub(crate) const SG_{name}_LAMBDA_NODES: usize = {};", g.lambda_nodes);
        let _ = writeln!(s, "/// Values per row of `SG_{name}` (y from 0 to 1).");
        let _ = writeln!(s, "pub(crate) const SG_{name}_T_NODES: usize = {};", g.t_nodes);
        let _ = writeln!(s, "/// {doc} at the nodes, row-major (λ rows).");
        let _ = writeln!(s, "pub(crate) static SG_{name}: [f32; {}] = [", v.len());
        for &x in v.iter() {
            let _ = writeln!(s, "    {}, // {x:?}", bits(x));
        }
        s.push_str("];\n");
    }
    s
}

/// `f32::from_bits(0x3f80_0000); // 1.0`-style text: the exact bits, then the value.
fn bits(x: f32) -> String {
    let b = x.to_bits();
    format!("f32::from_bits(0x{:04x}_{:04x})", b >> 16, b & 0xffff)
}

/// One panel of the δ-quadrature of [`fractions_upper`]: `k` halvings from `π/2`, or the last
/// one, `[0, π·2^(−k−1)]`.
struct Panel {
    /// `sin(lo/2)`: the exponent's smallest value on the panel is at `lo` (near side).
    sin_near_end: f64,
    /// `sin((π − hi)/2)`, likewise for the far side (`δ = π − e₀`).
    sin_far_end: f64,
    nodes: Vec<Node>,
}

/// A node `e₀ = c + r·x` of a panel, with the 16-point weight times `r` and the trigonometry
/// the integrand needs on either side (the same values every call: computing them per
/// call, and the rule itself, was most of an unoptimised bake).
struct Node {
    weight: f64,
    sin: f64,
    cos: f64,
    /// `sin(e₀/2)` (near side, `δ = e₀`).
    sin_half: f64,
    /// `sin((π − e₀)/2)` (far side, `δ = π − e₀`).
    sin_half_far: f64,
}

/// The panels `2k` (the `k`-th, `k ≤ 80`) and `2k + 1` (the `k`-th as the last one), built once.
fn panels() -> &'static [Panel] {
    static PANELS: std::sync::OnceLock<Vec<Panel>> = std::sync::OnceLock::new();
    PANELS.get_or_init(|| {
        let gl = gauss_legendre(16);
        let mut out = Vec::with_capacity(162);
        for k in 0..=80 {
            let hi = if k == 0 { 0.5 * PI } else { PI * 0.5f64.powi(k + 1) };
            for last in [false, true] {
                let lo = if last { 0.0 } else { PI * 0.5f64.powi(k + 2) };
                let (c, r) = (0.5 * (lo + hi), 0.5 * (hi - lo));
                let nodes =
                    gl.0.iter()
                        .zip(&gl.1)
                        .map(|(x, wt)| {
                            let e0 = c + r * x;
                            Node {
                                weight: wt * r,
                                sin: e0.sin(),
                                cos: e0.cos(),
                                sin_half: (0.5 * e0).sin(),
                                sin_half_far: (0.5 * (PI - e0)).sin(),
                            }
                        })
                        .collect();
                out.push(Panel {
                    sin_near_end: (0.5 * lo).sin(),
                    sin_far_end: (0.5 * (PI - hi)).sin(),
                    nodes,
                });
            }
        }
        out
    })
}

/// H/F for any finite λ ≥ 0 and t ∈ [−1, 1].
pub fn hemi_fraction(lambda: f64, t: f64) -> f64 {
    let h = fractions_upper(lambda, t.abs()).0;
    if t < 0.0 {
        1.0 - h
    } else {
        h
    }
}

/// C/F for any finite λ ≥ 0 and t ∈ [−1, 1].
pub fn clamped_fraction(lambda: f64, t: f64) -> f64 {
    let c = fractions_upper(lambda, t.abs()).1;
    if t < 0.0 {
        c - t.abs() * langevin(lambda)
    } else {
        c
    }
}

/// The full-sphere integral F(λ) = 2π(1 − e^(−2λ))/λ of a unit SG (4π at λ = 0).
pub fn full_integral(lambda: f64) -> f64 {
    if lambda == 0.0 {
        4.0 * PI
    } else {
        -2.0 * PI * (-2.0 * lambda).exp_m1() / lambda
    }
}

/// Langevin function L(λ) = coth λ − 1/λ (series below 0.05).
pub fn langevin(lambda: f64) -> f64 {
    if lambda < 0.05 {
        let l2 = lambda * lambda;
        lambda * (1.0 / 3.0 - l2 * (1.0 / 45.0 - l2 * (2.0 / 945.0 - l2 / 4725.0)))
    } else {
        let e = (-2.0 * lambda).exp();
        (1.0 + e) / (-(-2.0 * lambda).exp_m1()) - 1.0 / lambda
    }
}

/// (H/F, C/F) for finite λ ≥ 0 and t ∈ [0, 1].
fn fractions_upper(lambda: f64, t: f64) -> (f64, f64) {
    if lambda == 0.0 {
        return (0.5, 0.25);
    }
    let t = t.clamp(0.0, 1.0);
    let w = ((1.0 - t) * (1.0 + t)).sqrt();
    let d = t * t / (1.0 + w); // 1 − w without cancellation
    let em2 = -(-2.0 * lambda).exp_m1(); // 1 − e^(−2λ)
                                         // Outer cap u ∈ [w, 1] (γ = π): ∫ e^(λ(u−1)) du and ∫ u·e^(λ(u−1)) du, r = 1 − u ∈ [0, d].
    let ld = lambda * d;
    let e1 = if ld == 0.0 { d } else { -(-ld).exp_m1() / lambda };
    let e2 = d * d * g2(ld);
    let h_outer = 2.0 * PI * e1;
    let c_outer = 2.0 * PI * t * (e1 - e2);
    // Middle band |u| ≤ w, u = w·cos δ.
    let (mut h_mid, mut c_mid) = (0.0, 0.0);
    if w > 0.0 {
        let mut scale: f64 = (1.0 / (lambda * w).sqrt()).min(1.0);
        if t > 0.0 {
            scale = scale.min(t / w);
        }
        // Geometric panels towards both ends: δ = 0 (the lobe axis side, and the horizon
        // crossing u = w) and δ = π (the crossing u = −w); each side is [0, π/2] in its own
        // distance from the end. (Their nodes and trigonometry come from `panels`.)
        let k_max = ((4.0 * PI / scale).log2().ceil() as i32).clamp(3, 80);
        let panels = panels();
        for far in [false, true] {
            for k in 0..=k_max {
                let p = &panels[2 * k as usize + usize::from(k == k_max)];
                // Smallest exponent on the panel: at its end nearest δ = 0.
                let sl = if far { p.sin_far_end } else { p.sin_near_end };
                if lambda * (d + 2.0 * w * sl * sl) <= 60.0 {
                    for node in &p.nodes {
                        let sd = node.sin;
                        let cd = if far { -node.cos } else { node.cos };
                        let sh = if far { node.sin_half_far } else { node.sin_half };
                        let e = (-lambda * (d + 2.0 * w * sh * sh)).exp();
                        let q = (t * t + w * w * sd * sd).sqrt();
                        let arg = if q > 0.0 { (-t * cd / q).clamp(-1.0, 1.0) } else { 0.0 };
                        let gamma = arg.acos();
                        let jac = node.weight * w * sd;
                        h_mid += jac * e * 2.0 * gamma;
                        c_mid += jac * e * 2.0 * (t * w * cd * gamma + w * sd);
                    }
                }
            }
        }
    }
    // Divide by F = 2π(1 − e^(−2λ))/λ.
    let inv_f = lambda / (2.0 * PI * em2);
    ((h_outer + h_mid) * inv_f, (c_outer + c_mid) * inv_f)
}

/// (1 − e^(−z)(1 + z))/z², so that ∫₀^d r·e^(−λr) dr = d²·g2(λd).
fn g2(z: f64) -> f64 {
    if z < 1.0 {
        // Σ_j (−1)^j (j + 1)/(j + 2)! z^j
        let mut sum = 0.0;
        let mut fact = 2.0; // (j + 2)!
        let mut zp = 1.0;
        for j in 0..30 {
            let jf = j as f64;
            sum += zp * (jf + 1.0) / fact;
            zp *= -z;
            fact *= jf + 3.0;
        }
        sum
    } else {
        (1.0 - (-z).exp() * (1.0 + z)) / (z * z)
    }
}

/// Complementary error function for x ≥ 0 (series below 2, continued fraction above),
/// ≈1e-15 absolute.
pub fn erfc(x: f64) -> f64 {
    if x < 2.0 {
        // erf x = 2/√π·e^(−x²)·Σ 2ⁿx^(2n+1)/(1·3·…·(2n+1)), all terms positive.
        let mut term = x;
        let mut sum = x;
        let mut n = 0.0;
        while term > 1e-18 * sum {
            n += 1.0;
            term *= 2.0 * x * x / (2.0 * n + 1.0);
            sum += term;
        }
        1.0 - 2.0 / PI.sqrt() * (-x * x).exp() * sum
    } else {
        // erfc x = e^(−x²)/√π · 1/(x + (1/2)/(x + 1/(x + (3/2)/(x + …)))), evaluated backwards.
        let mut f = x;
        for k in (1..=60).rev() {
            f = x + 0.5 * k as f64 / f;
        }
        (-x * x).exp() / (PI.sqrt() * f)
    }
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on the three-term recurrence).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut xs = vec![0.0; n];
    let mut ws = vec![0.0; n];
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        xs[i] = x;
        ws[i] = 2.0 / ((1.0 - x * x) * dp * dp);
    }
    (xs, ws)
}
