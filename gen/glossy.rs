//! Generator of the *glossy* Bayesian Monte Carlo renderer weights (issue #12), in f64.
//!
//! The integral: `I(n, r) = ∫ L(x)·p(x) dx` with `p(x) = (e+1)/(2π)·max(0, r·x)ᵉ·max(0, n·x)`,
//! the normalised Phong lobe about the mirror direction `r` with the cosine factor and the
//! horizon at the normal `n` (QMC-SF estimates it as `(1/N)·Σ L(xⱼ)·max(0, n·xⱼ)` on the
//! lobe-morphed set).
//!
//! # The sample set and why one table per `r·n` suffices
//! The `N`-point hemisphere spherical Fibonacci set about `r`, morphed onto the lobe
//! (`cos θ′ = u^{1/(e+1)}`, `u = 1 − (2j + 1)/(2N)`, golden azimuth: exactly the crate's
//! `LobeSampler` with `Lobe::Phong(e)` and phase 0), placed in the frame `(t₁, t₂, r)` with
//! `t₁` along `n − (n·r)r`. In that frame `n = (sin θₙ, 0, cos θₙ)` with `cos θₙ = r·n`, so
//! `Q` depends on nothing and `z`, `∫p` and the weights only on `θₙ`: the weights are baked
//! on [`GRID`] nodes ([`grid_angle`]) and the library interpolates between two neighbours with
//! `sin(θₖ₊₁ − θₙ)` and `sin(θₙ − θₖ)`. While the horizon misses the lobe, `z` and `∫p` are
//! linear in `n`, so the weights are `A·cos θₙ + B·sin θₙ` and that interpolation is exact;
//! near grazing the horizon sweeps across the lobe, hence nodes graded towards `r·n = 0`.
//!
//! # `zᵢ` (the seed's step 4)
//! `zᵢ = ∫ k(xᵢ, x)·p(x) dx` through spherical Gaussians: the Phong lobe is fitted by
//! [`FIT_TERMS`] SGs `Σ aₖ·exp(λₖ(r·x − 1))` (sharpnesses `(e+1)·ρ^{k−2}`, `ρ` =
//! [`FIT_RATIO`], amplitudes by least squares over the sphere), each term's product with the
//! kernel SG is an SG (closed form), and its clamped-cosine integral about `n` comes from the
//! f64 generator of the crate's tables ([`super::sg::clamped_fraction`]). `∫p` is the fit's
//! own integral, so constants are integrated exactly *for the fitted lobe*; the fit's relative
//! L2 error is measured by `tests/bmc/glossy.rs` (e = 10: 5·10⁻⁴, e = 50: 8·10⁻⁶).
//!
//! Weights: `w = Q⁻¹z̃ + (∫p − 1ᵀQ⁻¹z̃)·Q⁻¹1/(1ᵀQ⁻¹1)` (GLS constant mean, as [`super::bmc`])
//! with `z̃ = z + σ′²q`, the nugget read as a rough part of the radiance that the set's QMC
//! weights `q` integrate ([`System::weights_at`]); the estimate is `Σ wⱼ·L(xⱼ)`.

use std::f64::consts::PI;
use std::fmt::Write as _;

/// The file in `tables/` that says what to bake.
pub const CONFIG_FILE: &str = "tables/glossy.txt";

/// The renderer benchmark's further sets, baked with the feature `renderer-sweep`.
pub const SWEEP_FILE: &str = "tables/glossy_sweep.txt";

/// Nodes of `θₙ = acos(r·n)` over `[0, π/2]`, graded towards grazing ([`grid_angle`]).
pub const GRID: usize = 97;

/// SG terms of the Phong-lobe fit.
pub const FIT_TERMS: usize = 5;

/// Ratio of consecutive fit sharpnesses.
pub const FIT_RATIO: f64 = 1.2;

/// The largest N.
pub const MAX_N: usize = 512;

/// `round(2⁶⁴/Φ)`.
const GOLDEN_PHASE: u64 = 0x9E37_79B9_7F4A_7C16;

/// One set to bake.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    /// Samples.
    pub n: usize,
    /// Phong exponent.
    pub e: u32,
    /// Kernel length scale `l` (`λ = 2/l²`), rounded to f32 first.
    pub length_scale: f32,
    /// Noise ratio `σ′`, rounded to f32 first.
    pub noise: f32,
    /// The optimal set of [`OPTIMAL_FILE`] for `(N, e)` (plain BMC, its own `(l, σ′)`) rather
    /// than the lobe-morphed spherical Fibonacci set.
    pub optimal: bool,
}

impl Spec {
    /// `λ = 2/l²`.
    pub fn lambda(&self) -> f64 {
        2.0 / f64::from(self.length_scale).powi(2)
    }
}

/// The learned hyperparameters `tables/glossy.txt` refers to (`err` rows of
/// `cargo xtask regen renderer-hyperparameters`).
pub const LEARNED_FILE: &str = "tables/renderer_hyperparameters.txt";

/// One learned row `err phongE N l sigma`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Learned {
    /// Phong exponent.
    pub e: u32,
    /// Samples.
    pub n: usize,
    /// Length scale.
    pub l: f64,
    /// Noise ratio σ′.
    pub sigma: f64,
}

/// The `err phongE N l sigma` rows of [`LEARNED_FILE`] (other rows and comments skipped).
pub fn parse_learned(text: &str) -> Result<Vec<Learned>, String> {
    let mut out = Vec::new();
    for (no, raw) in text.lines().enumerate() {
        let f: Vec<&str> = raw.split('#').next().unwrap_or("").split_whitespace().collect();
        if f.first() != Some(&"err") {
            continue;
        }
        let Some(e) = f.get(1).and_then(|k| k.strip_prefix("phong")) else { continue };
        let at = |m: &str| format!("{LEARNED_FILE} line {}: {m}", no + 1);
        if f.len() != 5 {
            return Err(at("expected `err phongE N l sigma`"));
        }
        let e: u32 = e.parse().map_err(|x| at(&format!("exponent: {x}")))?;
        let n: usize = f[2].parse().map_err(|x| at(&format!("N: {x}")))?;
        let l: f64 = f[3].parse().map_err(|x| at(&format!("l: {x}")))?;
        let sigma: f64 = f[4].parse().map_err(|x| at(&format!("sigma: {x}")))?;
        if !(l.is_finite() && l > 0.0 && sigma.is_finite() && sigma > 0.0) {
            return Err(at("l and sigma must be finite and positive"));
        }
        out.push(Learned { e, n, l, sigma });
    }
    Ok(out)
}

/// `(l, σ′)` for `(N, e)` from the learned rows of the same `N`: `ln l` and `ln σ′`
/// interpolated linearly in `ln e` between the nearest learned exponents (the end values
/// outside them).
pub fn interpolate(learned: &[Learned], n: usize, e: u32) -> Result<(f64, f64), String> {
    let mut rows: Vec<&Learned> = learned.iter().filter(|r| r.n == n).collect();
    rows.sort_by_key(|r| r.e);
    let (Some(first), Some(last)) = (rows.first(), rows.last()) else {
        return Err(format!(
            "no learned hyperparameters for N = {n} in {LEARNED_FILE}: give `l sigma`"
        ));
    };
    if e <= first.e {
        return Ok((first.l, first.sigma));
    }
    if e >= last.e {
        return Ok((last.l, last.sigma));
    }
    if let Some(r) = rows.iter().find(|r| r.e == e) {
        // A learned exponent is its row, exactly (not exp(ln x) of it).
        return Ok((r.l, r.sigma));
    }
    let k = rows.iter().position(|r| r.e > e).unwrap_or(rows.len() - 1);
    let (a, b) = (rows[k - 1], rows[k]);
    let t = (f64::from(e).ln() - f64::from(a.e).ln()) / (f64::from(b.e).ln() - f64::from(a.e).ln());
    let mix = |x: f64, y: f64| (x.ln() + t * (y.ln() - x.ln())).exp();
    Ok((mix(a.l, b.l), mix(a.sigma, b.sigma)))
}

/// The optimal sample sets `optimal = N e` lines refer to (`xtask/writers/src/bin/optimal_sets.rs`).
pub const OPTIMAL_FILE: &str = "tables/optimal_sets.txt";

/// One optimal set of [`OPTIMAL_FILE`]: `set phongE N l sigma var_sf var_opt` and `N` lines
/// `x y z` in the lobe frame.
#[derive(Clone, Debug, PartialEq)]
pub struct OptimalSet {
    /// Phong exponent.
    pub e: u32,
    /// Length scale the set was optimised for.
    pub l: f64,
    /// Noise ratio the set was optimised for.
    pub sigma: f64,
    /// Directions (lobe frame, `(t₁, t₂, r)`), normalised in f64.
    pub directions: Vec<[f64; 3]>,
}

/// The `phongE` sets of [`OPTIMAL_FILE`] (the `diffuse` ones are skipped).
pub fn parse_optimal(text: &str) -> Result<Vec<OptimalSet>, String> {
    let mut out: Vec<OptimalSet> = Vec::new();
    let mut lines = text.lines().enumerate().filter_map(|(no, raw)| {
        let line = raw.split('#').next().unwrap_or("").trim();
        (!line.is_empty()).then_some((no + 1, line))
    });
    while let Some((no, line)) = lines.next() {
        let at = |m: &str| format!("{OPTIMAL_FILE} line {no}: {m}");
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() != 7 || f[0] != "set" {
            return Err(at("expected `set <key> <N> <l> <sigma> <var_sf> <var_opt>`"));
        }
        let n: usize = f[2].parse().map_err(|x| at(&format!("N: {x}")))?;
        let l: f64 = f[3].parse().map_err(|x| at(&format!("l: {x}")))?;
        let sigma: f64 = f[4].parse().map_err(|x| at(&format!("sigma: {x}")))?;
        let valid = (1..=MAX_N).contains(&n) && l > 0.0 && l.is_finite() && sigma > 0.0;
        if !(valid && sigma.is_finite()) {
            return Err(at("N in 1..=512, l and sigma finite and positive"));
        }
        let mut directions = Vec::with_capacity(n);
        for _ in 0..n {
            let (no, line) = lines.next().ok_or_else(|| at("the set ends early"))?;
            let v: Vec<f32> = line
                .split_whitespace()
                .map(str::parse::<f32>)
                .collect::<Result<_, _>>()
                .map_err(|x| format!("{OPTIMAL_FILE} line {no}: {x}"))?;
            let norm = v.iter().map(|&c| f64::from(c).powi(2)).sum::<f64>().sqrt();
            if v.len() != 3 || !(norm - 1.0).abs().lt(&1e-5) {
                return Err(format!("{OPTIMAL_FILE} line {no}: expected a unit `x y z`"));
            }
            directions.push([0, 1, 2].map(|k| f64::from(v[k]) / norm));
        }
        if let Some(e) = f[1].strip_prefix("phong") {
            let e: u32 = e.parse().map_err(|x| at(&format!("exponent: {x}")))?;
            out.push(OptimalSet { e, l, sigma, directions });
        }
    }
    Ok(out)
}

/// Parses `glossy = N e [l sigma]` lines; `#` starts a comment. `N` in 1..=[`MAX_N`], `e` in
/// 1..=10⁴, no `(N, e)` twice, `l` and `σ′` finite and positive; without them the learned
/// rows give them ([`interpolate`]), and `optimal = N e` lines (the optimal set of
/// [`OPTIMAL_FILE`] with the `(l, σ′)` it was optimised for). An empty file bakes nothing.
pub fn parse(text: &str, learned: &[Learned], optimal: &[OptimalSet]) -> Result<Vec<Spec>, String> {
    let mut specs: Vec<Spec> = Vec::new();
    for (no, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let at = |m: String| format!("line {}: {m}", no + 1);
        if let Some(rest) =
            line.strip_prefix("optimal").and_then(|r| r.trim_start().strip_prefix('='))
        {
            let f: Vec<&str> = rest.split_whitespace().collect();
            let (Some(n), Some(e), 2) = (
                f.first().and_then(|x| x.parse::<usize>().ok()),
                f.get(1).and_then(|x| x.parse::<u32>().ok()),
                f.len(),
            ) else {
                return Err(at("expected `optimal = N e`".into()));
            };
            let set = optimal
                .iter()
                .find(|s| s.e == e && s.directions.len() == n)
                .ok_or_else(|| at(format!("no optimal set phong{e} N = {n} in {OPTIMAL_FILE}")))?;
            if specs.iter().any(|s| s.n == n && s.e == e && s.optimal) {
                return Err(at(format!("optimal N = {n}, e = {e} appears twice")));
            }
            let (length_scale, noise) = (set.l as f32, set.sigma as f32);
            specs.push(Spec { n, e, length_scale, noise, optimal: true });
            continue;
        }
        let f: Vec<&str> = line
            .strip_prefix("glossy")
            .and_then(|r| r.trim_start().strip_prefix('='))
            .ok_or_else(|| at(format!("expected `glossy = N e [l sigma]`, found `{line}`")))?
            .split_whitespace()
            .collect();
        if f.len() != 2 && f.len() != 4 {
            return Err(at("expected `glossy = N e [l sigma]`".into()));
        }
        let n: usize = f[0].parse().map_err(|e| at(format!("N `{}`: {e}", f[0])))?;
        if !(1..=MAX_N).contains(&n) {
            return Err(at(format!("N = {n} must be in 1..={MAX_N}")));
        }
        let e: u32 = f[1].parse().map_err(|x| at(format!("e `{}`: {x}", f[1])))?;
        if !(1..=10_000).contains(&e) {
            return Err(at(format!("e = {e} must be in 1..=10000")));
        }
        if specs.iter().any(|s| s.n == n && s.e == e && !s.optimal) {
            return Err(at(format!("N = {n}, e = {e} appears twice")));
        }
        let pos = |s: &str, what: &str| -> Result<f32, String> {
            let x: f32 = s.parse().map_err(|e| at(format!("{what}: {e}")))?;
            if x.is_finite() && x > 0.0 {
                Ok(x)
            } else {
                Err(at(format!("{what} = {s} must be finite and positive")))
            }
        };
        let (length_scale, noise) = if f.len() == 4 {
            (pos(f[2], "l")?, pos(f[3], "sigma")?)
        } else {
            let (l, s) = interpolate(learned, n, e).map_err(at)?;
            (l as f32, s as f32)
        };
        specs.push(Spec { n, e, length_scale, noise, optimal: false });
    }
    Ok(specs)
}

/// Direction `j` of the morphed set in the lobe frame (pole = `r`).
pub fn local_direction(j: usize, n: usize, e: u32) -> [f64; 3] {
    let a = (2 * j + 1) as f64 / (2 * n) as f64; // 1 − u
                                                 // cos θ′ = u^{1/(e+1)}, 1 − cos θ′ without cancellation.
    let omc = -((-a).ln_1p() / (f64::from(e) + 1.0)).exp_m1();
    let c = 1.0 - omc;
    let s = (omc * (1.0 + c)).sqrt();
    let turns = (j as u64).wrapping_mul(GOLDEN_PHASE) as f64 / 18_446_744_073_709_551_616.0;
    let (sp, cp) = (2.0 * PI * turns).sin_cos();
    [s * cp, s * sp, c]
}

/// `θₙ` of grid node `k`: `cos θₙ = (1 − g)/(1 + 2.5g)`, `g = k/(GRID − 1)`, so the library
/// finds the interval from `r·n` by one division (`g = (1 − r·n)/(1 + 2.5·r·n)`). Nodes are
/// spaced like `√g` in `θₙ` near normal incidence (where the interpolation is exact) and 12.25
/// times denser in `r·n` at grazing than at normal incidence (the horizon sweeps across the
/// lobe there); the grading is the best of this form for e = 10 and is within a factor 2 of
/// the optimal placement for e = 10 … 200 (`tests/bmc/glossy.rs` measures the error).
pub fn grid_angle(k: usize) -> f64 {
    let g = k as f64 / (GRID - 1) as f64;
    ((1.0 - g) / (1.0 + 2.5 * g)).acos()
}

/// The least-squares SG fit `Σ aₖ·exp(λₖ(t − 1))` of the normalised Phong lobe
/// `(e+1)/(2π)·max(0, t)ᵉ` over `t ∈ [−1, 1]` (the sphere's measure is `2π·dt`):
/// `(λₖ, aₖ)` pairs.
pub fn phong_fit(e: u32) -> Vec<(f64, f64)> {
    let ef = f64::from(e);
    let lambdas: Vec<f64> = (0..FIT_TERMS)
        .map(|k| (ef + 1.0) * FIT_RATIO.powf(k as f64 - (FIT_TERMS - 1) as f64 / 2.0))
        .collect();
    // Normal equations on a composite Gauss–Legendre rule in t (panels graded towards t = 1).
    let (xs, ws) = super::sg::gauss_legendre(24);
    let mut edges = vec![-1.0, 0.0];
    for k in 1..16 {
        edges.push(1.0 - 0.5f64.powi(k));
    }
    edges.push(1.0);
    // Weighted least squares by modified Gram–Schmidt QR (the SG columns are nearly
    // collinear: normal equations lose half the digits).
    let m = FIT_TERMS;
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); m];
    let mut rhs = Vec::new();
    for p in edges.windows(2) {
        let (lo, hi) = (p[0], p[1]);
        for (x, w) in xs.iter().zip(&ws) {
            let t = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x;
            let sw = (0.5 * (hi - lo) * w).sqrt();
            let f = if t > 0.0 { (ef + 1.0) / (2.0 * PI) * t.powf(ef) } else { 0.0 };
            rhs.push(sw * f);
            for (c, l) in cols.iter_mut().zip(&lambdas) {
                c.push(sw * (l * (t - 1.0)).exp());
            }
        }
    }
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let mut r = vec![0.0; m * m];
    for j in 0..m {
        for i in 0..j {
            let (qi, cj) = (cols[i].clone(), &mut cols[j]);
            let rij = dot(&qi, cj);
            r[i * m + j] = rij;
            for (c, q) in cj.iter_mut().zip(&qi) {
                *c -= rij * q;
            }
        }
        let norm = dot(&cols[j], &cols[j]).sqrt();
        r[j * m + j] = norm;
        cols[j].iter_mut().for_each(|c| *c /= norm);
    }
    let qtb: Vec<f64> = cols.iter().map(|q| dot(q, &rhs)).collect();
    let mut amp = vec![0.0; m];
    for i in (0..m).rev() {
        let s: f64 = (i + 1..m).map(|j| r[i * m + j] * amp[j]).sum();
        amp[i] = (qtb[i] - s) / r[i * m + i];
    }
    lambdas.into_iter().zip(amp).collect()
}

/// `∫ exp(λ(μ·x − 1))·max(0, n·x) dx` for `μ·n = t`: `F(λ)·C/F(λ, t)`.
fn clamped(lambda: f64, t: f64) -> f64 {
    super::sg::full_integral(lambda) * super::sg::clamped_fraction(lambda, t.clamp(-1.0, 1.0))
}

/// `∫ p(x) dx` of the fitted lobe for `r·n = cos θₙ`.
pub fn lobe_integral(fit: &[(f64, f64)], theta_n: f64) -> f64 {
    fit.iter().map(|&(l, a)| a * clamped(l, theta_n.cos())).sum()
}

/// `zᵢ = ∫ exp(λ(xᵢ·x − 1))·p(x) dx` (fitted lobe) for a direction `x` in the lobe frame and
/// `n = (sin θₙ, 0, cos θₙ)`.
pub fn kernel_mean(lambda: f64, fit: &[(f64, f64)], x: [f64; 3], theta_n: f64) -> f64 {
    let n = [theta_n.sin(), 0.0, theta_n.cos()];
    fit.iter()
        .map(|&(lk, ak)| {
            // Product of exp(λ(x·y − 1)) and aₖ·exp(λₖ(ẑ·y − 1)): u = λx + λₖẑ.
            let u = [lambda * x[0], lambda * x[1], lambda * x[2] + lk];
            let lm = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            // exp(λₘ − λ − λₖ), stable: −λλₖ|x − ẑ|²/(λₘ + λ + λₖ).
            let d2 = x[0] * x[0] + x[1] * x[1] + (x[2] - 1.0) * (x[2] - 1.0);
            let am = ak * (-lambda * lk * d2 / (lm + lambda + lk)).exp();
            let t = if lm > 0.0 { (u[0] * n[0] + u[2] * n[2]) / lm } else { 0.0 };
            am * clamped(lm, t)
        })
        .sum()
}

/// The baked weights of one set.
#[derive(Clone, Debug)]
pub struct Baked {
    /// What was baked.
    pub spec: Spec,
    /// Weights, node-major: `weights[k·N + j]`.
    pub weights: Vec<f64>,
    /// The fit's `∫p` per node.
    pub integral: Vec<f64>,
    /// The optimal set's directions (lobe frame); empty for the Fibonacci set.
    pub directions: Vec<[f64; 3]>,
}

/// The factorised kernel matrix of one set, for weights at any `θₙ`.
pub struct System {
    spec: Spec,
    xs: Vec<[f64; 3]>,
    q: Vec<f64>,
    l: Vec<f64>,
    ones: Vec<f64>,
    fit: Vec<(f64, f64)>,
}

impl System {
    /// `Q = K + σ′²I` of the lobe-morphed spherical Fibonacci set, factorised.
    pub fn new(spec: &Spec) -> Result<System, String> {
        let xs: Vec<[f64; 3]> = (0..spec.n).map(|j| local_direction(j, spec.n, spec.e)).collect();
        Self::with_directions(spec, xs)
    }

    /// `Q = K + σ′²I` of the set `xs` (lobe frame), factorised.
    pub fn with_directions(spec: &Spec, xs: Vec<[f64; 3]>) -> Result<System, String> {
        let n = spec.n;
        let lambda = spec.lambda();
        let nugget = f64::from(spec.noise).powi(2);
        let mut q = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let d2: f64 = (0..3).map(|c| (xs[i][c] - xs[j][c]).powi(2)).sum();
                q[i * n + j] = (-0.5 * lambda * d2).exp() + if i == j { nugget } else { 0.0 };
            }
        }
        let l = super::bmc::cholesky(&q, n).map_err(|e| format!("N = {n}, e = {}: {e}", spec.e))?;
        let mut sys = System { spec: *spec, xs, q, l, ones: Vec::new(), fit: phong_fit(spec.e) };
        sys.ones = sys.solve(&vec![1.0; n]);
        Ok(sys)
    }

    /// `Q⁻¹b` with one step of iterative refinement.
    pub fn solve(&self, b: &[f64]) -> Vec<f64> {
        let n = self.spec.n;
        let mut x = super::bmc::chol_solve(&self.l, n, b);
        let r = super::bmc::residual(&self.q, n, &x, b);
        for (x, d) in x.iter_mut().zip(super::bmc::chol_solve(&self.l, n, &r)) {
            *x += d;
        }
        x
    }

    /// The sample directions in the lobe frame.
    pub fn directions(&self) -> &[[f64; 3]] {
        &self.xs
    }

    /// The lobe fit.
    pub fn fit(&self) -> &[(f64, f64)] {
        &self.fit
    }

    /// The weights at `θₙ` and the fitted lobe's `∫p` there.
    ///
    /// The nugget is read as a rough component `ε` of the radiance (white at the sample
    /// spacing, variance `σ′²`) whose integral the QMC rule of the set estimates:
    /// `∫ε·p ≈ Σ qᵢεᵢ` with `qᵢ = max(0, n·xᵢ)/N` (the lobe-morphed set's importance weights),
    /// so `Cov(∫ε·p, εᵢ) = σ′²qᵢ` and `z` becomes `z + σ′²q`. The estimate is
    /// `β∫p + (z + σ′²q)ᵀQ⁻¹(Y − β1)`: plain BMC as σ′ → 0, the QMC average as σ′ → ∞.
    /// An optimal set has no QMC rule: its weights are plain BMC's (`q = 0`), as it was
    /// optimised.
    pub fn weights_at(&self, theta_n: f64) -> (Vec<f64>, f64) {
        let lambda = self.spec.lambda();
        let nugget = if self.spec.optimal { 0.0 } else { f64::from(self.spec.noise).powi(2) };
        let (sn, cn) = theta_n.sin_cos();
        let inv_n = 1.0 / self.spec.n as f64;
        let z: Vec<f64> = self
            .xs
            .iter()
            .map(|&x| {
                let q = (sn * x[0] + cn * x[2]).max(0.0) * inv_n;
                kernel_mean(lambda, &self.fit, x, theta_n) + nugget * q
            })
            .collect();
        let a = self.solve(&z);
        let ip = lobe_integral(&self.fit, theta_n);
        let s1: f64 = self.ones.iter().sum();
        let gls = (ip - a.iter().sum::<f64>()) / s1;
        (a.iter().zip(&self.ones).map(|(a, b)| a + gls * b).collect(), ip)
    }
}

/// Bakes one set.
pub fn bake(spec: &Spec, optimal: &[OptimalSet]) -> Result<Baked, String> {
    let sys = if spec.optimal {
        let set = optimal
            .iter()
            .find(|s| s.e == spec.e && s.directions.len() == spec.n)
            .ok_or_else(|| format!("no optimal set phong{} N = {}", spec.e, spec.n))?;
        System::with_directions(spec, set.directions.clone())?
    } else {
        System::new(spec)?
    };
    let mut weights = Vec::with_capacity(spec.n * GRID);
    let mut integral = Vec::with_capacity(GRID);
    for k in 0..GRID {
        let (w, ip) = sys.weights_at(grid_angle(k));
        weights.extend(w);
        integral.push(ip);
    }
    let directions = if spec.optimal { sys.directions().to_vec() } else { Vec::new() };
    Ok(Baked { spec: *spec, weights, integral, directions })
}

/// Bakes every set.
pub fn bake_all(specs: &[Spec], optimal: &[OptimalSet]) -> Result<Vec<Baked>, String> {
    specs
        .iter()
        .map(|s| {
            let b = bake(s, optimal)?;
            // A user table (SPHERE_QUADRATURE_GLOSSY_TABLE) with absurd hyperparameters must
            // not bake NaN weights into a program that builds.
            let finite = |x: &f64| (*x as f32).is_finite();
            if b.weights.iter().all(finite) && b.integral.iter().all(finite) {
                Ok(b)
            } else {
                Err(format!("N = {}, e = {}: the baked weights are not finite", s.n, s.e))
            }
        })
        .collect()
}

/// The Rust source that `build.rs` writes to `$OUT_DIR/glossy_tables.rs`.
pub fn render(sets: &[Baked]) -> String {
    let mut s = String::new();
    s.push_str("// @generated by build.rs; do not edit\n");
    let _ = writeln!(s, "// From gen/glossy.rs, {CONFIG_FILE} and {OPTIMAL_FILE}.");
    let list = |optimal: bool| -> Vec<String> {
        sets.iter()
            .filter(|b| b.spec.optimal == optimal)
            .map(|b| format!("({}, {})", b.spec.n, b.spec.e))
            .collect()
    };
    let or_none = |v: Vec<String>| if v.is_empty() { "none".to_string() } else { v.join(", ") };
    let _ = writeln!(
        s,
        "\n/// The compile error of an unbaked (N, e, set), listing this build's pairs.\n\
         macro_rules! glossy_size_diagnostic {{\n    ($item:item) => {{\n        \
         #[diagnostic::on_unimplemented(\n            \
         message = \"no glossy Bayesian Monte Carlo weights are baked for `{{Self}}`, e = {{E}} and the set `{{S}}`\",\n            \
         label = \"this sample count, Phong exponent and sample set have no baked weights\",\n            \
         note = \"the baked (N, e) pairs are {} for the Fibonacci set and {} for the optimal one \
         (this build's table: {CONFIG_FILE} or SPHERE_QUADRATURE_GLOSSY_TABLE; bake another with a \
         `glossy = N e` line, tables/README.md)\"\n        )]\n        $item\n    }};\n}}",
        or_none(list(false)),
        or_none(list(true)),
    );
    for (name, optimal, what) in
        [("GLOSSY_SETS", false, "spherical Fibonacci"), ("GLOSSY_OPTIMAL_SETS", true, "optimal")]
    {
        let pairs = list(optimal);
        let _ = writeln!(s, "\n/// The baked (N, e) pairs of the glossy renderer, {what} sets.");
        let _ = writeln!(
            s,
            "pub(crate) const {name}: [(usize, u32); {}] = [{}];",
            pairs.len(),
            pairs.join(", ")
        );
    }
    for b in sets {
        let (n, e) = (b.spec.n, b.spec.e);
        let (tag, kind) = if b.spec.optimal { ("OPT_", "Optimal") } else { ("", "Fibonacci") };
        let _ = writeln!(
            s,
            "\n/// N = {n}, e = {e}, {kind} set, l = {:?}, σ′ = {:?}: weights node-major, {GRID} nodes of θₙ.",
            b.spec.length_scale, b.spec.noise
        );
        let _ = writeln!(s, "static GLOSSY_{tag}{n}_{e}: [u32; {}] = [", b.weights.len());
        for row in b.weights.chunks(8) {
            let items: Vec<String> =
                row.iter().map(|&x| format!("0x{:08x}", (x as f32).to_bits())).collect();
            let _ = writeln!(s, "    {},", items.join(", "));
        }
        s.push_str("];\n");
        let dirs = if b.spec.optimal {
            let _ = writeln!(s, "static GLOSSY_{tag}DIRS_{n}_{e}: [u32; {}] = [", 3 * n);
            for d in &b.directions {
                let items: Vec<String> =
                    d.iter().map(|&x| format!("0x{:08x}", (x as f32).to_bits())).collect();
                let _ = writeln!(s, "    {},", items.join(", "));
            }
            s.push_str("];\n");
            format!("&GLOSSY_{tag}DIRS_{n}_{e}")
        } else {
            "&[]".to_string()
        };
        let _ = writeln!(
            s,
            "impl crate::bmc::glossy::sealed::Sealed<{e}, crate::bmc::glossy::{kind}> for crate::bmc::Size<{n}> {{\n    \
             const SET: crate::bmc::glossy::sealed::Set = crate::bmc::glossy::sealed::Set {{\n        \
             weights: &GLOSSY_{tag}{n}_{e},\n        directions: {dirs},\n        length_scale: f32::from_bits(0x{:08x}),\n        \
             noise: f32::from_bits(0x{:08x}),\n    }};\n}}",
            b.spec.length_scale.to_bits(),
            b.spec.noise.to_bits()
        );
        let _ = writeln!(
            s,
            "impl crate::bmc::GlossySize<{e}, crate::bmc::glossy::{kind}> for crate::bmc::Size<{n}> {{}}"
        );
    }
    s
}
