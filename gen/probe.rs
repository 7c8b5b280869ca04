//! Generator of the Bayesian Monte Carlo *probe* tables (issue #6), in f64.
//!
//! A probe holds `N` radiance samples in the directions of the `N`-point spherical Fibonacci
//! sphere set `xⱼ` (`zⱼ = 1 − (2j + 1)/N`, `φⱼ = 2π·frac(j/Φ)`, optionally rotated as a whole)
//! and answers irradiance queries for any normal. Kernel `exp(λ(x·x′ − 1)) + σ′²δ` as in
//! [`super::bmc`]; the probe bakes a *family* of sharpnesses `λ₁ < λ₂ < …` with one `σ′`, and
//! picks per update the member of highest marginal likelihood.
//!
//! # The antipodal symmetry
//! Point `N − 1 − j` of the set is point `j` turned by π about a horizontal axis:
//! `z ↦ −z` exactly, and `φ ↦ 2π·frac((N − 1)/Φ) − φ`. Write `J` for the index map
//! `j ↦ N − 1 − j`. Dot products are invariant under the rotation, so `Q_{Ji,Jj} = Qᵢⱼ`, and
//! for even `N` (pairs `p < m = N/2` with `Jp`) `Q` splits into two `m × m` blocks:
//! `E_pq = Q_pq + Q_{p,Jq}` acting on sums `s_p = y_p + y_{Jp}`, and `F_pq = Q_pq − Q_{p,Jq}`
//! on differences `d_p = y_p − y_{Jp}`. With `a = E⁻¹s`, `b = F⁻¹d`:
//! `(Q⁻¹y)_p = (a_p + b_p)/2`, `(Q⁻¹y)_{Jp} = (a_p − b_p)/2`.
//! So the probe stores the Cholesky factors of `E` and `F` (packed lower triangles,
//! `m(m + 1)` numbers instead of `N²`), and `Q⁻¹y` costs `N²/2` multiply-adds instead of
//! `N²`. Factors, not inverses: a factor rounded to f32 is the exact factor of a matrix within
//! f32 rounding of `Q` (backward error ε), while a rounded inverse is the inverse of a matrix
//! up to `cond(Q)·ε` away from `Q`, and the learned nuggets make `cond(Q)` reach 10⁴–10⁵.
//!
//! # What is baked per member
//! - the Cholesky factors of `E` and `F` (packed rows of the lower triangle, each diagonal
//!   entry stored as its reciprocal so the device never divides);
//! - `g = E⁻¹1` (`m` numbers): `Q⁻¹1 = (g, Jg)`, and `s₁ = 1ᵀQ⁻¹1 = 2Σg`;
//! - the likelihood constant `−½·log det Q − ½·log s₁` (`log det Q = log det E + log det F`);
//! - `π²V̄` (`V̄ = ∫∫ k p p` for the clamped cosine `p = max(0, n·x)/π`);
//! - the posterior variance of `E(n)` for σ_f = 1, averaged over 256 spherical Fibonacci
//!   query normals (it varies little with `n` for a near-uniform set; the exact value is an
//!   O(N²) query).
//!
//! Shared by every `N` with the same `λ`: the table `π·z(t)` of the kernel mean
//! `z(t) = ∫ exp(λ(μ·x − 1))·max(0, n·x)/π dx` at `μ·n = t`: [`Z_NODES`] equally spaced nodes
//! over `t ∈ [−1, 1]`, each with the quadratic that interpolates `π·z` over the half-spacing
//! either side (the library evaluates the nearest node's quadratic; no float-to-integer
//! conversion is needed to find it).

use std::f64::consts::PI;
use std::fmt::Write as _;

/// The file in `tables/` that says what to bake.
pub const CONFIG_FILE: &str = "tables/probe.txt";

/// The extra footprints baked with the feature `footprint-sweep` (same format, no `probe`
/// line needed).
pub const SWEEP_FILE: &str = "tables/probe_sweep.txt";

/// Parses a file of `footprint = …` lines only (the [`SWEEP_FILE`]).
pub fn parse_extra(text: &str) -> Result<Vec<Spec>, String> {
    // Borrow the main parser's checks with a placeholder point line, then drop it.
    let mut specs =
        parse(&format!("probe = 2 1 1\n{text}")).map_err(|e| e.replace("line ", "line (+1) "))?;
    specs.retain(|s| s.footprint != Footprint::Point);
    for s in &mut specs {
        s.line -= 1;
    }
    Ok(specs)
}

/// The largest N a config may ask for.
pub const MAX_N: usize = 1024;

/// The smallest noise ratio `σ′` a config may ask for.
pub const MIN_SIGMA: f32 = 1e-4;

/// The largest noise ratio `σ′` a config may ask for.
pub const MAX_SIGMA: f32 = 10.0;

/// The smallest kernel sharpness `λ` (or footprint `ν`) a config may ask for (`λ = 2/l²`:
/// a length scale of 45 rad).
pub const MIN_LAMBDA: f32 = 1e-3;

/// The most members one family may have.
pub const MAX_MEMBERS: usize = 8;

/// Nodes of the `π·z(t)` table over `t ∈ [−1, 1]`.
pub const Z_NODES: usize = 129;

/// Query normals for the direction-averaged posterior variance.
pub const VARIANCE_NORMALS: usize = 256;

/// Points of the baked glossy variance grid: lobe sharpness `μ = 0`, then `2^(k−1)` for
/// `k = 1…11` (1 to 1024).
pub const GLOSSY_GRID: usize = 12;

/// Mirror directions over which the glossy variance is averaged: the SF sphere set of this
/// size (unrelated to any probe size, so no direction sits on a sample by construction).
pub const GLOSSY_DIRECTIONS: usize = 37;

/// `μ` of grid point `k`.
pub fn glossy_grid(k: usize) -> f64 {
    if k == 0 {
        0.0
    } else {
        f64::from(1u32 << (k - 1))
    }
}

/// `ζ(t) = ∫ exp(λ(x·y − 1))·exp(μ(r·y − 1)) dy` at `x·r = t`: the integral of the product
/// SG, `4π·exp(w − λ − μ)·(1 − e^(−2w))/(2w)`, `w = |λx + μr|`.
pub fn glossy_zeta(lambda: f64, mu: f64, t: f64) -> f64 {
    let w = (lambda * lambda + mu * mu + 2.0 * lambda * mu * t.clamp(-1.0, 1.0)).max(0.0).sqrt();
    let h = if w > 1e-8 { -(-2.0 * w).exp_m1() / (2.0 * w) } else { 1.0 };
    4.0 * PI * (w - lambda - mu).exp() * h
}

/// `F(μ) = ∫ exp(μ(r·y − 1)) dy = 2π(1 − e^(−2μ))/μ` (`4π` at 0).
pub fn glossy_full(mu: f64) -> f64 {
    if mu == 0.0 {
        4.0 * PI
    } else {
        -2.0 * PI * (-2.0 * mu).exp_m1() / mu
    }
}

/// `V̄ = ∫∫ G·k·G = 2π∫ exp(μ(t − 1))·ζ(t) dt` over `t ∈ [−1, 1]`, by 16-point Gauss–Legendre
/// on 16 panels in `u = 1 − t` graded geometrically towards the lobe's axis (`[0, 2⁻¹⁴]`,
/// then doubling up to `[1, 2]`).
pub fn glossy_vbar(lambda: f64, mu: f64) -> f64 {
    let (xs, ws) = super::sg::gauss_legendre(16);
    let mut edges = vec![0.0];
    edges.extend((0..16).map(|k| 2.0 * 0.5f64.powi(15 - k)));
    let mut sum = 0.0;
    for pair in edges.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        for (x, w) in xs.iter().zip(&ws) {
            let u = 0.5 * (a + b) + 0.5 * (b - a) * x;
            sum += 0.5 * (b - a) * w * (-mu * u).exp() * glossy_zeta(lambda, mu, 1.0 - u);
        }
    }
    2.0 * PI * sum
}

/// `round(2⁶⁴/Φ)`: the crate's golden phase step (`sf::GOLDEN_PHASE`).
const GOLDEN_PHASE: u64 = 0x9E37_79B9_7F4A_7C16;

/// What each sample measures (see `src/footprint.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Footprint {
    /// The radiance in the sample's direction.
    Point,
    /// The normalised spherical Gaussian of this integer sharpness `S`.
    Gaussian(u32),
    /// The normalised cosine-power response `(P + 1)/(2π)·max(0, t)ᴾ`.
    Cosine(u32),
}

impl Footprint {
    /// The Rust type of the footprint marker.
    pub fn type_name(self) -> String {
        match self {
            Footprint::Point => "crate::footprint::Point".into(),
            Footprint::Gaussian(s) => format!("crate::footprint::Gaussian<{s}>"),
            Footprint::Cosine(p) => format!("crate::footprint::CosinePower<{p}>"),
        }
    }

    /// A short name for static identifiers (`P`, `G8`, `C1`).
    pub fn tag(self) -> String {
        match self {
            Footprint::Point => "P".into(),
            Footprint::Gaussian(s) => format!("G{s}"),
            Footprint::Cosine(p) => format!("C{p}"),
        }
    }

    /// The Funk–Hecke gains `g_l`, `l < count`.
    pub fn gains(self, count: usize) -> Vec<f64> {
        match self {
            Footprint::Point => vec![1.0; count],
            Footprint::Gaussian(s) => bessel_ratios(f64::from(s), count),
            Footprint::Cosine(p) => cosine_power_gains(p, count),
        }
    }
}

/// The largest footprint parameter (Gaussian sharpness, cosine-power exponent).
pub const MAX_FOOTPRINT: u32 = 4096;

/// The most Legendre terms a member's series may need (the parser refuses members whose
/// kernel series has not converged by then).
pub const MAX_SERIES: usize = 256;

/// `ρ_l(x) = i_l(x)/i₀(x)` for `l < count` (modified spherical Bessel functions of the first
/// kind), by the backward continued fraction `r_k = i_k/i_{k−1} = x/(2k + 1 + x·r_{k+1})`
/// started at `count + 2x + 60` (past `k ≈ 2x` each step damps the start's error by `r² < 1/9`).
pub fn bessel_ratios(x: f64, count: usize) -> Vec<f64> {
    let mut out = vec![0.0; count];
    if count == 0 {
        return out;
    }
    out[0] = 1.0;
    if x == 0.0 {
        return out;
    }
    let start = count + 2 * (x.min(1e6) as usize) + 60;
    let mut r = 0.0;
    let mut ratios = vec![0.0; count];
    for k in (1..=start).rev() {
        r = x / ((2 * k + 1) as f64 + x * r);
        if k < count {
            ratios[k] = r;
        }
    }
    for l in 1..count {
        out[l] = out[l - 1] * ratios[l];
    }
    out
}

/// `(p + 1)∫₀¹ tᵖ P_l(t) dt` for `l < count`: `m₀ = 1/(p + 1)`, `m₁ = 1/(p + 2)`,
/// `m_{l+2} = m_l·(p − l)/(p + l + 3)` (Gradshteyn–Ryzhik 7.126.2).
pub fn cosine_power_gains(p: u32, count: usize) -> Vec<f64> {
    let pf = f64::from(p);
    let mut m = vec![0.0; count];
    for l in 0..count {
        m[l] = if l < 2 {
            1.0 / (pf + 1.0 + l as f64)
        } else {
            m[l - 2] * (pf - (l - 2) as f64) / (pf + (l - 2) as f64 + 3.0)
        };
    }
    m.iter().map(|x| (pf + 1.0) * x).collect()
}

/// The clamped cosine's Funk–Hecke gains `c_l = 2π∫₀¹ t·P_l(t) dt` (`π`, `2π/3`, `π/4`, 0,
/// `−π/24`, …), `l < count`.
pub fn clamped_cosine_gains(count: usize) -> Vec<f64> {
    cosine_power_gains(1, count).iter().map(|g| PI * g).collect()
}

/// The Funk–Hecke coefficients `K_l = 2π∫ exp(x(t − 1))·P_l(t) dt = F(x)·ρ_l(x)` of a unit
/// spherical Gaussian of sharpness `x`, `l < count`.
pub fn sg_coefficients(x: f64, count: usize) -> Vec<f64> {
    let f = glossy_full(x);
    bessel_ratios(x, count).iter().map(|r| f * r).collect()
}

/// `Σ_l a_l·(2l + 1)/(4π)·P_l(t)`.
pub fn legendre_series(a: &[f64], t: f64) -> f64 {
    let t = t.clamp(-1.0, 1.0);
    let (mut p0, mut p1) = (1.0, t);
    let mut sum = 0.0;
    for (l, &c) in a.iter().enumerate() {
        let p = match l {
            0 => 1.0,
            1 => t,
            _ => {
                let p2 = ((2 * l - 1) as f64 * t * p1 - (l - 1) as f64 * p0) / l as f64;
                p0 = p1;
                p1 = p2;
                p2
            }
        };
        sum += c * (2 * l + 1) as f64 / (4.0 * PI) * p;
    }
    sum
}

/// The sample model of one member: the covariances a footprint probe needs, in f64.
///
/// - Point, kernel `exp(λ(t − 1))` (as before).
/// - Gaussian footprint `S`: the kernel on the radiance is the spherical Gaussian of sharpness
///   `ν` *deconvolved* by the footprint, `K_l = F(ν)·ρ_l(ν)/ρ_l(S)` (positive and summable for
///   `ν < S`; close to the squared exponential of sharpness `νS/(S − ν)`), chosen so that the
///   covariance of a sample with the radiance, `K_l·g_l`, is exactly the spherical Gaussian
///   `exp(ν(t − 1))`. Then everything that involves one sample is the point model with `λ = ν`
///   (the irradiance table, the glossy `zᵢ`), `Cov(Yᵢ, Yⱼ) = ∫ SG_ν(xᵢ·y)·f(xⱼ·y) dy` is the
///   closed-form integral of a product of spherical Gaussians, and only `V̄` (the prior
///   variance of the integral of the unfiltered radiance) needs the series `Σ K_l c_l²…`.
/// - Cosine-power footprint `P`: the squared-exponential kernel `K_l = F(λ)·ρ_l(λ)`;
///   `Cov(Yᵢ, Yⱼ) = Σ K_l g_l²(2l + 1)/(4π)·P_l`, `Cov(Yᵢ, E(n)) = Σ K_l g_l c_l…`, and the
///   glossy `zᵢ = Σ K_l g_l Λ_l(μ)…` (a Legendre series the library sums per query).
#[derive(Clone, Debug)]
pub struct Model {
    /// The footprint.
    pub footprint: Footprint,
    /// `λ` (point, cosine power) or `ν` (Gaussian footprint).
    pub lambda: f64,
    /// Kernel coefficients `K_l` (`l < series.len()`), converged to `10⁻¹⁸·K₀`.
    pub kernel: Vec<f64>,
    /// The footprint's gains on the same degrees.
    pub gains: Vec<f64>,
    /// `K_l·g_l²`: the sample covariance's coefficients.
    sample: Vec<f64>,
}

impl Model {
    /// The model of `footprint` with member sharpness `lambda`.
    pub fn new(footprint: Footprint, lambda: f64) -> Result<Model, String> {
        // Enough degrees for the kernel series to converge: K_l·(2l + 1) < 10⁻¹⁸·K₀.
        let count = MAX_SERIES + 64;
        let kernel: Vec<f64> = match footprint {
            Footprint::Gaussian(s) => {
                let s = f64::from(s);
                if lambda >= s {
                    return Err(format!(
                        "ν = {lambda} must be below the footprint's sharpness {s}"
                    ));
                }
                let (rn, rs) = (bessel_ratios(lambda, count), bessel_ratios(s, count));
                let f = glossy_full(lambda);
                // ρ_l(S) underflows only far past convergence; stop there.
                rn.iter().zip(&rs).map(|(a, b)| if *b > 0.0 { f * a / b } else { 0.0 }).collect()
            }
            _ => sg_coefficients(lambda, count),
        };
        let k0 = kernel[0];
        let used = kernel
            .iter()
            .enumerate()
            .rposition(|(l, k)| k * (2 * l + 1) as f64 > 1e-18 * k0)
            .map_or(1, |p| p + 1);
        if used > MAX_SERIES {
            return Err(format!(
                "the kernel series needs {used} > {MAX_SERIES} Legendre terms (ν too close to S?)"
            ));
        }
        let gains = footprint.gains(used);
        let sample = kernel.iter().zip(&gains).map(|(k, g)| k * g * g).collect();
        Ok(Model { footprint, lambda, kernel: kernel[..used].to_vec(), gains, sample })
    }

    /// `Cov(Yᵢ, Yⱼ)` without the nugget, for `xᵢ·xⱼ = t` and `|xᵢ − xⱼ|² = d2`.
    pub fn sample_covariance(&self, t: f64, d2: f64) -> f64 {
        match self.footprint {
            Footprint::Point => (-0.5 * self.lambda * d2).exp(),
            Footprint::Gaussian(s) => {
                let (nu, s) = (self.lambda, f64::from(s));
                // ∫ e^{ν(xᵢ·y − 1)} e^{S(xⱼ·y − 1)} dy / F(S), w = |νxᵢ + Sxⱼ|.
                let w = ((nu + s) * (nu + s) - nu * s * d2).max(0.0).sqrt();
                let h = if w > 1e-8 { -(-2.0 * w).exp_m1() / (2.0 * w) } else { 1.0 - w };
                4.0 * PI * (-nu * s * d2 / (w + nu + s)).exp() * h / glossy_full(s)
            }
            Footprint::Cosine(_) => legendre_series(&self.sample, t),
        }
    }

    /// `Cov(Yᵢ, E(n)) = π·z(t)` for `xᵢ·n = t` (σ_f = 1).
    pub fn irradiance_covariance(&self, t: f64) -> f64 {
        match self.footprint {
            Footprint::Point | Footprint::Gaussian(_) => PI * kernel_mean(self.lambda, t),
            Footprint::Cosine(_) => legendre_series(&self.irradiance_coefficients(), t),
        }
    }

    fn irradiance_coefficients(&self) -> Vec<f64> {
        let c = clamped_cosine_gains(self.kernel.len());
        self.kernel.iter().zip(&self.gains).zip(&c).map(|((k, g), c)| k * g * c).collect()
    }

    /// `π²V̄ = Var(E(n))` under the prior (σ_f = 1).
    pub fn irradiance_vbar(&self) -> f64 {
        match self.footprint {
            Footprint::Point | Footprint::Cosine(_) => {
                PI * PI * super::bmc::kernel_mean_mean(self.lambda)
            }
            Footprint::Gaussian(_) => {
                let c = clamped_cosine_gains(self.kernel.len());
                self.kernel
                    .iter()
                    .zip(&c)
                    .enumerate()
                    .map(|(l, (k, c))| k * c * c * (2 * l + 1) as f64 / (4.0 * PI))
                    .sum()
            }
        }
    }

    /// `Cov(Yᵢ, ∫ L·exp(μ(r·y − 1)) dy)` for `xᵢ·r = t`.
    pub fn glossy_covariance(&self, mu: f64, t: f64) -> f64 {
        self.glossy_covariance_fn(mu)(t)
    }

    /// [`Model::glossy_covariance`] at a fixed `μ`, as a function of `t`.
    pub fn glossy_covariance_fn(&self, mu: f64) -> impl Fn(f64) -> f64 + '_ {
        let a: Vec<f64> = match self.footprint {
            Footprint::Cosine(_) => {
                let lobe = sg_coefficients(mu, self.kernel.len());
                self.kernel
                    .iter()
                    .zip(&self.gains)
                    .zip(&lobe)
                    .map(|((k, g), b)| k * g * b)
                    .collect()
            }
            _ => Vec::new(),
        };
        move |t| match self.footprint {
            Footprint::Point | Footprint::Gaussian(_) => glossy_zeta(self.lambda, mu, t),
            Footprint::Cosine(_) => legendre_series(&a, t),
        }
    }

    /// The prior variance of `∫ L·exp(μ(r·y − 1)) dy`.
    pub fn glossy_vbar(&self, mu: f64) -> f64 {
        match self.footprint {
            Footprint::Point | Footprint::Cosine(_) => glossy_vbar(self.lambda, mu),
            Footprint::Gaussian(_) => {
                let lobe = sg_coefficients(mu, self.kernel.len());
                self.kernel
                    .iter()
                    .zip(&lobe)
                    .enumerate()
                    .map(|(l, (k, b))| k * b * b * (2 * l + 1) as f64 / (4.0 * PI))
                    .sum()
            }
        }
    }

    /// The Legendre coefficients the library keeps: `K_l·g_l·(2l + 1)/(4π)` for a
    /// cosine-power footprint (summed per glossy query), `K_l·(2l + 1)/(4π)` for a Gaussian
    /// footprint (the exact glossy `V̄`), none for point samples.
    pub fn glossy_series(&self) -> Vec<f64> {
        match self.footprint {
            Footprint::Gaussian(_) => self
                .kernel
                .iter()
                .enumerate()
                .map(|(l, k)| k * (2 * l + 1) as f64 / (4.0 * PI))
                .collect(),
            Footprint::Cosine(_) => self
                .kernel
                .iter()
                .zip(&self.gains)
                .enumerate()
                .map(|(l, (k, g))| k * g * (2 * l + 1) as f64 / (4.0 * PI))
                .collect(),
            _ => Vec::new(),
        }
    }
}

/// One probe size to bake: `N`, the footprint, `σ′` and the family of sharpnesses.
#[derive(Clone, Debug, PartialEq)]
pub struct Spec {
    /// The 1-based line of the config it comes from (for error messages).
    pub line: usize,
    /// Number of samples (even).
    pub n: usize,
    /// What each sample measures.
    pub footprint: Footprint,
    /// Noise ratio `σ′` (rounded to f32 first).
    pub sigma: f32,
    /// Sharpnesses `λ` of the family, strictly increasing (rounded to f32 first).
    pub lambdas: Vec<f32>,
    /// Per member, the error-bar calibration factors `[irradiance, μ = 7, μ = 22, μ = 102]`
    /// (`calibration = …` lines; 1 where none is given).
    pub calibration: Vec<[f32; 4]>,
}

/// The largest calibration factor a config may give.
pub const MAX_CALIBRATION: f32 = 1e6;

/// Parses the config: `probe = N sigma lambda1 lambda2 …` lines (point samples),
/// `footprint = N gaussian S sigma nu1 nu2 …` and `footprint = N cosine P sigma lambda1 …`
/// lines (footprint samples), and `calibration = N lambda c_irradiance c_7 c_22 c_102` lines
/// (error-bar factors of the point member `λ` of size `N`, after its `probe` line); `#` starts
/// a comment.
///
/// `N` even, in 2..=[`MAX_N`]; point lines strictly increasing in `N`; no `(N, footprint)`
/// twice; `σ′` in [[`MIN_SIGMA`], [`MAX_SIGMA`]]; 1..=[`MAX_MEMBERS`] sharpnesses in
/// [[`MIN_LAMBDA`], 10⁴],
/// strictly increasing, and below `S` for a Gaussian footprint; footprint parameters in
/// 1..=[`MAX_FOOTPRINT`].
pub fn parse(text: &str) -> Result<Vec<Spec>, String> {
    let mut specs: Vec<Spec> = Vec::new();
    for (no, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let at = |msg: String| format!("line {}: {msg}", no + 1);
        let key_value = |key: &str| {
            line.strip_prefix(key)
                .and_then(|r| r.trim_start().strip_prefix('='))
                .map(|r| r.split_whitespace().collect::<Vec<&str>>())
        };
        if let Some(f) = key_value("calibration") {
            calibration_line(&f, &mut specs).map_err(at)?;
            continue;
        }
        let (footprint, fields) = if let Some(f) = key_value("probe") {
            (Footprint::Point, f)
        } else if let Some(f) = key_value("footprint") {
            if f.len() < 3 {
                return Err(at(
                    "expected `footprint = N gaussian|cosine PARAMETER sigma lambda…`".into()
                ));
            }
            let p: u32 =
                f[2].parse().map_err(|e| at(format!("footprint parameter `{}`: {e}", f[2])))?;
            if !(1..=MAX_FOOTPRINT).contains(&p) {
                return Err(at(format!("footprint parameter {p} must be in 1..={MAX_FOOTPRINT}")));
            }
            let fp = match f[1] {
                "gaussian" => Footprint::Gaussian(p),
                "cosine" => Footprint::Cosine(p),
                other => {
                    return Err(at(format!(
                        "footprint kind `{other}`: expected `gaussian` or `cosine`"
                    )))
                }
            };
            let mut rest = vec![f[0]];
            rest.extend_from_slice(&f[3..]);
            (fp, rest)
        } else {
            return Err(at(format!(
                "expected `probe = N sigma lambda…` or `footprint = …`, found `{line}`"
            )));
        };
        if fields.len() < 3 {
            return Err(at("expected N, sigma and at least one lambda".into()));
        }
        let n: usize = fields[0].parse().map_err(|e| at(format!("N `{}`: {e}", fields[0])))?;
        if !(2..=MAX_N).contains(&n) || n % 2 != 0 {
            return Err(at(format!("N = {n} must be even and in 2..={MAX_N}")));
        }
        if footprint == Footprint::Point {
            if let Some(last) = specs.iter().rev().find(|s| s.footprint == Footprint::Point) {
                if n <= last.n {
                    return Err(at(format!(
                        "N = {n} must exceed the previous probe line's {}",
                        last.n
                    )));
                }
            }
        } else if specs.iter().any(|s| s.n == n && s.footprint == footprint) {
            return Err(at(format!("N = {n} with this footprint appears twice")));
        }
        let number = |s: &str, what: &str| -> Result<f32, String> {
            let x: f32 = s.parse().map_err(|e| at(format!("{what} `{s}`: {e}")))?;
            if x.is_finite() && x > 0.0 {
                Ok(x)
            } else {
                Err(at(format!("{what} = {s} must be finite and positive")))
            }
        };
        let sigma = number(fields[1], "sigma")?;
        // σ′ = σ_n/σ_f: outside [10⁻⁴, 10] the factors are singular to f64 or the kernel is
        // lost in the noise (σ′ = 10²⁰ baked every output as NaN).
        if !(MIN_SIGMA..=MAX_SIGMA).contains(&sigma) {
            return Err(at(format!(
                "sigma = {} must be in [{MIN_SIGMA:e}, {MAX_SIGMA}]",
                fields[1]
            )));
        }
        let mut lambdas = Vec::new();
        for f in &fields[2..] {
            let l = number(f, "lambda")?;
            if !(MIN_LAMBDA..=1e4).contains(&l) {
                return Err(at(format!("lambda = {f} must be in [{MIN_LAMBDA:e}, 10⁴]")));
            }
            if lambdas.last().is_some_and(|&p| l <= p) {
                return Err(at(format!("lambdas must increase strictly (`{f}`)")));
            }
            if let Footprint::Gaussian(s) = footprint {
                if f64::from(l) >= f64::from(s) {
                    return Err(at(format!("nu = {f} must be below the footprint sharpness {s}")));
                }
            }
            lambdas.push(l);
        }
        if lambdas.len() > MAX_MEMBERS {
            return Err(at(format!("at most {MAX_MEMBERS} lambdas per size")));
        }
        let calibration = vec![[1.0; 4]; lambdas.len()];
        specs.push(Spec { line: no + 1, n, footprint, sigma, lambdas, calibration });
    }
    if !specs.iter().any(|s| s.footprint == Footprint::Point) {
        return Err("no `probe = …` line".into());
    }
    Ok(specs)
}

/// Applies one `calibration = N lambda c…` line to the point member it names.
fn calibration_line(f: &[&str], specs: &mut [Spec]) -> Result<(), String> {
    let [n, lambda, c @ ..] = f else {
        return Err("expected `calibration = N lambda c_irradiance c_7 c_22 c_102`".into());
    };
    if c.len() != 4 {
        return Err("expected `calibration = N lambda c_irradiance c_7 c_22 c_102`".into());
    }
    let n: usize = n.parse().map_err(|e| format!("N `{n}`: {e}"))?;
    let l: f32 = lambda.parse().map_err(|e| format!("lambda `{lambda}`: {e}"))?;
    let mut factors = [1.0f32; 4];
    for (x, s) in factors.iter_mut().zip(c) {
        *x = s.parse().map_err(|e| format!("calibration factor `{s}`: {e}"))?;
        if !(x.is_finite() && *x > 0.0 && *x <= MAX_CALIBRATION) {
            return Err(format!("calibration factor {s} must be in (0, {MAX_CALIBRATION:e}]"));
        }
    }
    let spec = specs
        .iter_mut()
        .find(|s| s.n == n && s.footprint == Footprint::Point)
        .ok_or_else(|| format!("calibration for N = {n}: no earlier `probe = {n} …` line"))?;
    let k =
        spec.lambdas.iter().position(|&x| x == l).ok_or_else(|| {
            format!("calibration for N = {n}: lambda {lambda} is not in its family")
        })?;
    if let Some(slot) = spec.calibration.get_mut(k) {
        *slot = factors;
    }
    Ok(())
}

/// Direction j of the N-point sphere spherical Fibonacci set (the crate's
/// `SphericalFibonacci::<N>` order): `z = 1 − (2j + 1)/N`, `φ = 2π·frac(j·round(2⁶⁴/Φ)/2⁶⁴)`.
pub fn sphere_direction(j: usize, n: usize) -> [f64; 3] {
    let a = (2 * j + 1) as f64 / n as f64; // 1 − z
    let z = 1.0 - a;
    let s = (a * (2.0 - a)).max(0.0).sqrt();
    let turns = (j as u64).wrapping_mul(GOLDEN_PHASE) as f64 / 18_446_744_073_709_551_616.0;
    let (sp, cp) = (2.0 * PI * turns).sin_cos();
    [s * cp, s * sp, z]
}

/// The kernel mean `z(t) = ∫ exp(λ(μ·x − 1))·max(0, n·x)/π dx` for `μ·n = t`.
pub fn kernel_mean(lambda: f64, t: f64) -> f64 {
    super::bmc::kernel_mean(lambda, t.clamp(-1.0, 1.0))
}

/// Node spacing of the `π·z` table in `t`.
pub fn z_step() -> f64 {
    2.0 / (Z_NODES - 1) as f64
}

/// The `π·z` table: per node `tₖ = −1 + k·h` the coefficients `[v, s, c]` of the quadratic
/// `v + f·s + f²·c` in `f = (t − tₖ)/h` that interpolates `π·z` at the two ends and the
/// middle of the stretch of `t` the node serves (`|f| ≤ ½`, inside [−1, 1]).
pub fn z_table(lambda: f64) -> Vec<[f64; 3]> {
    z_table_of(|t| PI * kernel_mean(lambda, t))
}

/// [`z_table`] of any `π·z(t)` (for a footprint model, [`Model::irradiance_covariance`]).
pub fn z_table_of(pz: impl Fn(f64) -> f64) -> Vec<[f64; 3]> {
    let h = z_step();
    let z = |f: f64, tk: f64| pz(tk + f * h);
    (0..Z_NODES)
        .map(|k| {
            let tk = -1.0 + k as f64 * h;
            // Served offsets: [−½, ½], cut to [0, ½] at t = −1 and [−½, 0] at t = 1.
            let (lo, hi) = if k == 0 {
                (0.0, 0.5)
            } else if k == Z_NODES - 1 {
                (-0.5, 0.0)
            } else {
                (-0.5, 0.5)
            };
            let mid = 0.5 * (lo + hi);
            let (f0, f1, f2) = (lo, mid, hi);
            let (y0, y1, y2) = (z(f0, tk), z(f1, tk), z(f2, tk));
            // Newton form, then expanded in powers of f.
            let d01 = (y1 - y0) / (f1 - f0);
            let d12 = (y2 - y1) / (f2 - f1);
            let c = (d12 - d01) / (f2 - f0);
            let s = d01 - c * (f0 + f1);
            let v = y0 - s * f0 - c * f0 * f0;
            [v, s, c]
        })
        .collect()
}

/// The library's lookup, in f64: the nearest node's quadratic, `k = round(u)`,
/// `u = (t + 1)/h`, `f = u − k`.
pub fn z_interpolate(table: &[[f64; 3]], t: f64) -> f64 {
    let u = (t.clamp(-1.0, 1.0) + 1.0) / z_step();
    let k = (u.round() as usize).min(Z_NODES - 1);
    let f = u - k as f64;
    let [v, s, c] = table[k];
    v + f * (s + f * c)
}

/// One baked family member.
#[derive(Clone, Debug)]
pub struct Member {
    /// `N`.
    pub n: usize,
    /// The sample model (footprint and kernel).
    pub model: Model,
    /// The member's `π·z` table.
    pub z: Vec<[f64; 3]>,
    /// Sharpness `λ` (f32-exact).
    pub lambda: f64,
    /// `σ′` (f32-exact).
    pub sigma: f64,
    /// `E⁻¹/2`, packed rows of the lower triangle (`m(m + 1)/2`; f64 only, not baked).
    pub inv_even: Vec<f64>,
    /// `F⁻¹/2`, packed likewise.
    pub inv_odd: Vec<f64>,
    /// The Cholesky factor `L` of `E = LLᵀ`, packed rows of the lower triangle with the
    /// diagonal stored as its reciprocal `1/Lᵢᵢ` (what is baked, as f32).
    pub chol_even: Vec<f64>,
    /// The factor of `F`, packed likewise.
    pub chol_odd: Vec<f64>,
    /// `g = E⁻¹1` (`m`); `Q⁻¹1 = (g, Jg)`.
    pub g: Vec<f64>,
    /// `s₁ = 1ᵀQ⁻¹1`.
    pub s1: f64,
    /// `log det Q`.
    pub log_det: f64,
    /// `π²V̄`.
    pub vbar: f64,
    /// Posterior variance of `E(n)` (σ_f = 1), mean over [`VARIANCE_NORMALS`] normals.
    pub mean_variance: f64,
    /// Its maximum over the same normals.
    pub max_variance: f64,
    /// Per [`GLOSSY_GRID`] point: the posterior variance of `∫ L·exp(μ(r·y − 1)) dy`
    /// (σ_f = 1), mean over [`GLOSSY_DIRECTIONS`] mirror directions, divided by `F(μ)²`.
    pub glossy_variance: Vec<f64>,
    /// `λ_max/λ_min` of `Q` (from the blocks' extreme eigenvalues).
    pub condition: f64,
}

impl Member {
    /// `Ok` when every value that is baked is a finite f32 (a table with absurd
    /// hyperparameters could otherwise build a probe whose every output is NaN); otherwise
    /// which value is not.
    pub fn check_finite(&self) -> Result<(), String> {
        let finite = |x: f64| (x as f32).is_finite();
        let fields: [(&str, &[f64]); 5] = [
            ("the Cholesky factor of E", &self.chol_even),
            ("the Cholesky factor of F", &self.chol_odd),
            ("g = E⁻¹1", &self.g),
            ("the glossy variance grid", &self.glossy_variance),
            ("the π·z table", self.z.as_flattened()),
        ];
        for (what, values) in fields {
            if let Some(x) = values.iter().find(|&&x| !finite(x)) {
                return Err(format!("{what} has a non-finite f32 value ({x:e})"));
            }
        }
        let scalars = [
            ("s1", self.s1),
            ("the likelihood constant", self.likelihood_constant()),
            ("vbar", self.vbar),
            ("the mean variance", self.mean_variance),
            ("the max variance", self.max_variance),
            ("the condition number", self.condition),
        ];
        for (what, x) in scalars {
            if !finite(x) {
                return Err(format!("{what} is not a finite f32 ({x:e})"));
            }
        }
        Ok(())
    }

    /// The likelihood constant `−½·log det Q − ½·log s₁`.
    pub fn likelihood_constant(&self) -> f64 {
        -0.5 * self.log_det - 0.5 * self.s1.ln()
    }

    /// `Q⁻¹y` through the blocks, in f64 (the library's algorithm).
    pub fn solve(&self, y: &[f64]) -> Vec<f64> {
        let n = self.n;
        let m = n / 2;
        let s: Vec<f64> = (0..m).map(|p| y[p] + y[n - 1 - p]).collect();
        let d: Vec<f64> = (0..m).map(|p| y[p] - y[n - 1 - p]).collect();
        let a = packed_mul(&self.inv_even, m, &s);
        let b = packed_mul(&self.inv_odd, m, &d);
        let mut x = vec![0.0; n];
        for p in 0..m {
            x[p] = a[p] + b[p];
            x[n - 1 - p] = a[p] - b[p];
        }
        x
    }
}

/// `A·x` for a symmetric `A` stored as packed lower-triangle rows.
pub fn packed_mul(a: &[f64], m: usize, x: &[f64]) -> Vec<f64> {
    // Plain loops over slices: this runs unoptimised in a dependant's build script.
    let mut out = vec![0.0; m];
    let o = &mut out[..];
    let mut k = 0;
    let mut i = 0;
    while i < m {
        let xi = x[i];
        let mut j = 0;
        while j < i {
            let ak = a[k];
            o[i] += ak * x[j];
            o[j] += ak * xi;
            k += 1;
            j += 1;
        }
        o[i] += a[k] * xi;
        k += 1;
        i += 1;
    }
    out
}

/// The symmetric inverse of the SPD `a` (`m × m`, row-major) by Cholesky with one step of
/// iterative refinement per column, its Cholesky factor (row-major), and `log det a`.
fn spd_inverse(a: &[f64], m: usize) -> Result<(Vec<f64>, Vec<f64>, f64), String> {
    let l = super::bmc::cholesky(a, m)?;
    let log_det = 2.0 * (0..m).map(|i| l[i * m + i].ln()).sum::<f64>();
    let mut inv = vec![0.0; m * m];
    for c in 0..m {
        let e: Vec<f64> = (0..m).map(|i| if i == c { 1.0 } else { 0.0 }).collect();
        let mut x = super::bmc::chol_solve(&l, m, &e);
        let r = super::bmc::residual(a, m, &x, &e);
        for (x, d) in x.iter_mut().zip(super::bmc::chol_solve(&l, m, &r)) {
            *x += d;
        }
        for i in 0..m {
            inv[i * m + c] = x[i];
        }
    }
    // Symmetrise the rounding.
    for i in 0..m {
        for j in 0..i {
            let v = 0.5 * (inv[i * m + j] + inv[j * m + i]);
            inv[i * m + j] = v;
            inv[j * m + i] = v;
        }
    }
    Ok((inv, l, log_det))
}

/// A row-major lower factor packed by rows, the diagonal replaced by its reciprocal.
fn pack_factor(l: &[f64], m: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(m * (m + 1) / 2);
    for i in 0..m {
        for j in 0..i {
            out.push(l[i * m + j]);
        }
        out.push(1.0 / l[i * m + i]);
    }
    out
}

/// `x = (LLᵀ)⁻¹b` from a [`pack_factor`] layout, in f64: the library's algorithm (forward
/// substitution by rows, back substitution by columns through the same rows).
pub fn packed_cholesky_solve(packed: &[f64], m: usize, b: &[f64]) -> Vec<f64> {
    let mut x = b.to_vec();
    let row = |i: usize| &packed[i * (i + 1) / 2..(i + 1) * (i + 2) / 2];
    for i in 0..m {
        let r = row(i);
        let acc: f64 = (0..i).map(|j| r[j] * x[j]).sum();
        x[i] = (x[i] - acc) * r[i];
    }
    for i in (0..m).rev() {
        let r = row(i);
        x[i] *= r[i];
        for j in 0..i {
            x[j] -= r[j] * x[i];
        }
    }
    x
}

/// Largest eigenvalue of the symmetric `a` by power iteration.
fn largest_eigenvalue(a: &[f64], m: usize) -> f64 {
    let mut v: Vec<f64> = (0..m).map(|i| 1.0 + 0.37 * (i as f64).sin()).collect();
    let mut est = 0.0;
    for _ in 0..200 {
        let norm = super::bmc::dot(&v, &v).sqrt();
        v.iter_mut().for_each(|x| *x /= norm);
        let w = super::bmc::mat_vec(a, m, &v);
        est = super::bmc::dot(&v, &w);
        v = w;
    }
    est
}

/// The posterior variance of `E(n)` for σ_f = 1 given `ζ = π·z(n)` at each sample:
/// `π²V̄ − ζᵀQ⁻¹ζ + (π − 1ᵀQ⁻¹ζ)²/s₁`.
pub fn posterior_variance(member: &Member, zeta: &[f64]) -> f64 {
    let u = member.solve(zeta);
    let quad: f64 = zeta.iter().zip(&u).map(|(a, b)| a * b).sum();
    let one: f64 = u.iter().sum();
    member.vbar - quad + (PI - one).powi(2) / member.s1
}

/// Bakes one point-sample member: `N` samples, sharpness `λ`, noise ratio `σ′`.
pub fn bake_member(n: usize, lambda: f32, sigma: f32) -> Result<Member, String> {
    bake_footprint_member(n, Footprint::Point, lambda, sigma)
}

/// Bakes one member of a probe whose samples have `footprint`: `N` samples, sharpness `λ`
/// (`ν` for a Gaussian footprint, see [`Model`]), noise ratio `σ′`.
pub fn bake_footprint_member(
    n: usize,
    footprint: Footprint,
    lambda: f32,
    sigma: f32,
) -> Result<Member, String> {
    if n < 2 || n % 2 != 0 {
        return Err(format!("probe N = {n} must be even and at least 2"));
    }
    let m = n / 2;
    let (lambda, sigma) = (f64::from(lambda), f64::from(sigma));
    let model = Model::new(footprint, lambda)?;
    let xs: Vec<[f64; 3]> = (0..n).map(|j| sphere_direction(j, n)).collect();
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let k = |i: usize, j: usize| {
        // |xᵢ − xⱼ|² = 2 − 2xᵢ·xⱼ, from the difference for accuracy near 0.
        let d2: f64 = (0..3).map(|c| (xs[i][c] - xs[j][c]).powi(2)).sum();
        model.sample_covariance(dot(xs[i], xs[j]), d2) + if i == j { sigma * sigma } else { 0.0 }
    };
    let mut e = vec![0.0; m * m];
    let mut f = vec![0.0; m * m];
    for p in 0..m {
        for q in 0..m {
            let direct = k(p, q);
            let mirrored = k(p, n - 1 - q);
            e[p * m + q] = direct + mirrored;
            f[p * m + q] = direct - mirrored;
        }
    }
    // Symmetrise (the mirrored terms agree only to rounding).
    for p in 0..m {
        for q in 0..p {
            let (a, b) = (0.5 * (e[p * m + q] + e[q * m + p]), 0.5 * (f[p * m + q] + f[q * m + p]));
            e[p * m + q] = a;
            e[q * m + p] = a;
            f[p * m + q] = b;
            f[q * m + p] = b;
        }
    }
    let (e_inv, e_chol, log_det_e) = spd_inverse(&e, m).map_err(|s| format!("E block: {s}"))?;
    let (f_inv, f_chol, log_det_f) = spd_inverse(&f, m).map_err(|s| format!("F block: {s}"))?;
    let pack = |a: &[f64]| -> Vec<f64> {
        let mut out = Vec::with_capacity(m * (m + 1) / 2);
        for i in 0..m {
            for j in 0..=i {
                out.push(0.5 * a[i * m + j]);
            }
        }
        out
    };
    let chol_even = pack_factor(&e_chol, m);
    // g = E⁻¹1 through the f32-rounded factor the library stores (in f64 arithmetic), so that
    // `Q⁻¹1` is the one the library's solves imply.
    let rounded: Vec<f64> = chol_even.iter().map(|&x| f64::from(x as f32)).collect();
    let g = packed_cholesky_solve(&rounded, m, &vec![1.0; m]);
    let s1 = 2.0 * g.iter().sum::<f64>();
    // Extreme eigenvalues of Q are those of E and F.
    let max_eig = largest_eigenvalue(&e, m).max(largest_eigenvalue(&f, m));
    let min_eig = 1.0 / largest_eigenvalue(&e_inv, m).max(largest_eigenvalue(&f_inv, m));
    let table = z_table_of(|t| model.irradiance_covariance(t));
    let vbar = model.irradiance_vbar();
    let mut member = Member {
        n,
        model: model.clone(),
        z: table.clone(),
        lambda,
        sigma,
        inv_even: pack(&e_inv),
        inv_odd: pack(&f_inv),
        chol_even,
        chol_odd: pack_factor(&f_chol, m),
        g,
        s1,
        log_det: log_det_e + log_det_f,
        vbar,
        mean_variance: 0.0,
        max_variance: 0.0,
        glossy_variance: Vec::new(),
        condition: max_eig / min_eig,
    };
    let (mut sum, mut max) = (0.0f64, 0.0f64);
    for q in 0..VARIANCE_NORMALS {
        let nq = sphere_direction(q, VARIANCE_NORMALS);
        let zeta: Vec<f64> = xs.iter().map(|&x| z_interpolate(&table, dot(x, nq))).collect();
        let v = posterior_variance(&member, &zeta);
        sum += v;
        max = max.max(v);
    }
    member.mean_variance = sum / VARIANCE_NORMALS as f64;
    member.max_variance = max;
    member.glossy_variance = (0..GLOSSY_GRID)
        .map(|k| {
            let mu = glossy_grid(k);
            let (vbar, full) = (model.glossy_vbar(mu), glossy_full(mu));
            let zeta_of = model.glossy_covariance_fn(mu);
            let mean = (0..GLOSSY_DIRECTIONS)
                .map(|q| {
                    let r = sphere_direction(q, GLOSSY_DIRECTIONS);
                    let zeta: Vec<f64> = xs.iter().map(|&x| zeta_of(dot(x, r))).collect();
                    let u = member.solve(&zeta);
                    let quad: f64 = zeta.iter().zip(&u).map(|(a, b)| a * b).sum();
                    let one: f64 = u.iter().sum();
                    (vbar - quad + (full - one).powi(2) / member.s1).max(0.0)
                })
                .sum::<f64>()
                / GLOSSY_DIRECTIONS as f64;
            mean / (full * full)
        })
        .collect();
    Ok(member)
}

/// Every member of every spec, in order.
pub fn bake_all(specs: &[Spec]) -> Result<Vec<Vec<Member>>, String> {
    specs
        .iter()
        .map(|s| {
            s.lambdas
                .iter()
                .map(|&l| {
                    bake_footprint_member(s.n, s.footprint, l, s.sigma)
                        .and_then(|m| m.check_finite().map(|()| m))
                        .map_err(|e| {
                            format!(
                                "line {}: N = {}, λ = {l} ({:?}): {e}",
                                s.line, s.n, s.footprint
                            )
                        })
                })
                .collect()
        })
        .collect()
}

/// The distinct sharpnesses over all point specs, ascending.
pub fn distinct_lambdas(specs: &[Spec]) -> Vec<f32> {
    let mut all: Vec<f32> = specs
        .iter()
        .filter(|s| s.footprint == Footprint::Point)
        .flat_map(|s| s.lambdas.iter().copied())
        .collect();
    all.sort_by(f32::total_cmp);
    all.dedup();
    all
}

/// Flash bytes of one size's family: per member the two packed blocks, `g`, eight scalars,
/// the glossy grid and `series` glossy Legendre coefficients; plus a quadratic `π·z` table per
/// member (shared with other sizes and footprints of the same table).
pub fn family_bytes(n: usize, members: usize) -> usize {
    let m = n / 2;
    members * 4 * (m * (m + 1) + m + 8 + GLOSSY_GRID + 3 * Z_NODES)
}

/// The name of a member's `π·z` table: point and Gaussian-footprint members of the same
/// sharpness share one (the cross-covariance is the same spherical Gaussian).
fn z_name(footprint: Footprint, lambda: f32) -> String {
    match footprint {
        Footprint::Cosine(p) => format!("PROBE_Z_C{p}_{:08X}", lambda.to_bits()),
        _ => format!("PROBE_Z_{:08X}", lambda.to_bits()),
    }
}

/// The Rust source that `build.rs` writes to `$OUT_DIR/probe_size.rs`, included by
/// `src/probe.rs`: the `ProbeSize` trait, whose compile error for an unbaked `N` lists the
/// sizes this build actually baked (a user table may bake others than the default).
pub fn render_size_trait(specs: &[Spec]) -> String {
    let sizes: Vec<String> =
        specs.iter().filter(|s| s.footprint == Footprint::Point).map(|s| s.n.to_string()).collect();
    let list = sizes.join(", ");
    let types: Vec<String> = sizes.iter().map(|n| format!("`Size<{n}>`")).collect();
    let mut s = String::new();
    s.push_str(
        "// @generated by build.rs; do not edit
",
    );
    let _ = writeln!(
        s,
        "/// Implemented for exactly the sizes `N` with a baked point-sample probe family \
         ({}: the `probe = …` lines of this build's table, `{CONFIG_FILE}` or the file named \
         by `SPHERE_QUADRATURE_PROBE_TABLE`); sealed.",
        types.join(", ")
    );
    // An example for the docs (the crate ships N = 64; a user table may not: `ignore` then).
    let fence = if specs.iter().any(|sp| sp.n == 16) && specs.iter().any(|sp| sp.n == 64) {
        "```"
    } else {
        "```ignore"
    };
    for line in [
        "///",
        "/// # Examples",
        &format!("/// {fence}"),
        "/// use sphere_quadrature::bmc::Size;",
        "/// use sphere_quadrature::probe::{Probe, ProbeSize, BAKED_SIZES};",
        "///",
        "/// // Generic code over the baked sizes: the bound admits exactly them.",
        "/// fn table_bytes<const N: usize>() -> usize",
        "/// where",
        "///     Size<N>: ProbeSize,",
        "/// {",
        "///     Probe::<N>::TABLE_BYTES",
        "/// }",
        "/// assert!(table_bytes::<16>() < table_bytes::<64>());",
        "/// assert!(BAKED_SIZES.contains(&64));",
        "/// ```",
    ] {
        let _ = writeln!(s, "{line}");
    }
    let _ = writeln!(s, "#[diagnostic::on_unimplemented(");
    let _ = writeln!(
        s,
        "    message = \"no Bayesian Monte Carlo probe family is baked for `{{Self}}`\","
    );
    let _ = writeln!(s, "    label = \"this sample count has no baked probe tables\",");
    let _ = writeln!(
        s,
        "    note = \"the baked sizes are N = {list} (this build's probe table: {CONFIG_FILE} or \
         SPHERE_QUADRATURE_PROBE_TABLE; even N only; tables/README.md)\""
    );
    s.push_str(")]\npub trait ProbeSize: ProbeTables<Point> {}\n");
    s.push_str(&render_tables_diagnostic(specs));
    s
}

/// The `probe_tables_diagnostic!` macro: the compile error of an unbaked `(N, footprint)`
/// pair, listing every pair this build baked and the table line that bakes another.
pub fn render_tables_diagnostic(specs: &[Spec]) -> String {
    let pairs: Vec<String> = specs
        .iter()
        .map(|s| {
            let f = match s.footprint {
                Footprint::Point => "Point".to_string(),
                Footprint::Gaussian(g) => format!("Gaussian<{g}>"),
                Footprint::Cosine(p) => format!("CosinePower<{p}>"),
            };
            format!("({}, {f})", s.n)
        })
        .collect();
    let list = if pairs.is_empty() { "none".to_string() } else { pairs.join(", ") };
    let mut s = String::new();
    s.push_str(
        "\n/// The compile error of an unbaked (N, footprint) pair, listing this build's pairs.\n",
    );
    s.push_str("macro_rules! probe_tables_diagnostic {\n    ($item:item) => {\n");
    s.push_str("        #[diagnostic::on_unimplemented(\n");
    s.push_str("            message = \"no Bayesian Monte Carlo probe family is baked for `{Self}` with footprint `{F}`\",\n");
    s.push_str(
        "            label = \"this sample count and footprint have no baked probe tables\",\n",
    );
    let _ = writeln!(
        s,
        "            note = \"the baked (N, footprint) pairs are {list} (this build's probe table: \
         {CONFIG_FILE} or SPHERE_QUADRATURE_PROBE_TABLE); bake another with a `probe = N …` \
         line (point samples) or `footprint = N gaussian S …` / `footprint = N cosine P …` \
         (tables/README.md)\""
    );
    s.push_str("        )]\n        $item\n    };\n}\n");
    s
}

/// The Rust source that `build.rs` writes to `$OUT_DIR/probe_tables.rs`.
pub fn render(specs: &[Spec], baked: &[Vec<Member>]) -> String {
    let mut s = String::new();
    s.push_str("// @generated by build.rs; do not edit\n");
    let _ = writeln!(s, "// From gen/probe.rs and {CONFIG_FILE}.");
    let points: Vec<&Spec> = specs.iter().filter(|b| b.footprint == Footprint::Point).collect();
    let sizes: Vec<String> = points.iter().map(|b| b.n.to_string()).collect();
    let _ = writeln!(s, "\n/// The sizes N with a baked point-sample probe family.");
    let _ = writeln!(
        s,
        "pub(crate) const PROBE_SIZES: [usize; {}] = [{}];",
        points.len(),
        sizes.join(", ")
    );
    let kinds: Vec<String> = specs
        .iter()
        .map(|b| {
            let kind = match b.footprint {
                Footprint::Point => "crate::footprint::Kind::Point".to_string(),
                Footprint::Gaussian(x) => {
                    format!("crate::footprint::Kind::Gaussian {{ sharpness: {x} }}")
                }
                Footprint::Cosine(x) => {
                    format!("crate::footprint::Kind::CosinePower {{ exponent: {x} }}")
                }
            };
            format!("({}, {kind})", b.n)
        })
        .collect();
    let _ = writeln!(s, "\n/// Every baked (N, footprint) pair, in table order.");
    let _ = writeln!(
        s,
        "pub(crate) const PROBE_TABLES: [(usize, crate::footprint::Kind); {}] = [{}];",
        kinds.len(),
        kinds.join(", ")
    );
    let (xs, ws) = super::sg::gauss_legendre(8);
    let _ = writeln!(
        s,
        "\n/// 8-point Gauss–Legendre nodes and weights on [0, 1] (for `Probe::glossy_variance`)."
    );
    let _ = writeln!(s, "pub(crate) const GAUSS_LEGENDRE_8: [(f64, f64); 8] = [");
    for (x, w) in xs.iter().zip(&ws) {
        let _ = writeln!(s, "    ({:?}, {:?}),", 0.5 * (x + 1.0), 0.5 * w);
    }
    s.push_str("];\n");
    let mut emitted: Vec<String> = Vec::new();
    for (spec, members) in specs.iter().zip(baked) {
        for (k, mb) in members.iter().enumerate() {
            let name = z_name(spec.footprint, spec.lambdas[k]);
            if emitted.contains(&name) {
                continue;
            }
            let _ = writeln!(
                s,
                "\n/// π·z(t) ≈ v + f·(s + f·c) about t = −1 + 2k/{} for λ = {:?} ({:?}).",
                Z_NODES - 1,
                spec.lambdas[k],
                spec.footprint
            );
            let _ = writeln!(s, "static {name}: [[f32; 3]; {Z_NODES}] = [");
            for &[v, d, c] in &mb.z {
                let _ = writeln!(
                    s,
                    "    [{}, {}, {}], // {:?}",
                    bits(v as f32),
                    bits(d as f32),
                    bits(c as f32),
                    v as f32
                );
            }
            s.push_str("];\n");
            emitted.push(name);
        }
    }
    for (spec, members) in specs.iter().zip(baked) {
        let n = spec.n;
        let m = n / 2;
        let tag = spec.footprint.tag();
        let ty = spec.footprint.type_name();
        for (k, mb) in members.iter().enumerate() {
            for (name, data) in [("EVEN", &mb.chol_even), ("ODD", &mb.chol_odd), ("G", &mb.g)] {
                // f32 bits: exact, and a third of the source of `f32::from_bits(…)` items.
                let _ =
                    writeln!(s, "\nstatic PROBE_{n}_{tag}_{k}_{name}: [u32; {}] = [", data.len());
                for row in data.chunks(8) {
                    let items: Vec<String> =
                        row.iter().map(|&x| format!("0x{:08x}", (x as f32).to_bits())).collect();
                    let _ = writeln!(s, "    {},", items.join(", "));
                }
                s.push_str("];\n");
            }
        }
        let _ = writeln!(
            s,
            "\n/// Family for N = {n}, {:?}, σ′ = {:?}: {} member(s).",
            spec.footprint,
            spec.sigma,
            members.len()
        );
        let _ = writeln!(
            s,
            "static PROBE_{n}_{tag}_FAMILY: [crate::probe::sealed::Baked; {}] = [",
            members.len()
        );
        for (k, mb) in members.iter().enumerate() {
            let l = spec.lambdas[k];
            s.push_str("    crate::probe::sealed::Baked {\n");
            let _ = writeln!(s, "        chol_even: &PROBE_{n}_{tag}_{k}_EVEN,");
            let _ = writeln!(s, "        chol_odd: &PROBE_{n}_{tag}_{k}_ODD,");
            let _ = writeln!(s, "        g: &PROBE_{n}_{tag}_{k}_G,");
            let _ = writeln!(s, "        z: &{},", z_name(spec.footprint, l));
            let grid: Vec<String> = mb.glossy_variance.iter().map(|&v| bits(v as f32)).collect();
            let _ = writeln!(s, "        glossy_variance: [{}],", grid.join(", "));
            let cal: Vec<String> = spec.calibration[k].iter().map(|&c| bits(c)).collect();
            let _ = writeln!(s, "        calibration: [{}],", cal.join(", "));
            for (name, x) in [
                ("lambda", l),
                ("sigma", spec.sigma),
                ("s1", mb.s1 as f32),
                ("likelihood_constant", mb.likelihood_constant() as f32),
                ("vbar", mb.vbar as f32),
                ("mean_variance", mb.mean_variance as f32),
                ("max_variance", mb.max_variance as f32),
                ("condition", mb.condition as f32),
            ] {
                let _ = writeln!(s, "        {name}: {}, // {x:?}", bits(x));
            }
            s.push_str("    },\n");
        }
        s.push_str("];\n");
        let _ = writeln!(s, "impl crate::probe::sealed::Tables<{ty}> for crate::bmc::Size<{n}> {{");
        let _ = writeln!(s, "    const HALF: usize = {m};");
        let _ = writeln!(
            s,
            "    const FAMILY: &'static [crate::probe::sealed::Baked] = &PROBE_{n}_{tag}_FAMILY;"
        );
        s.push_str("}\n");
        let _ = writeln!(s, "impl crate::probe::ProbeTables<{ty}> for crate::bmc::Size<{n}> {{}}");
        if spec.footprint == Footprint::Point {
            let _ = writeln!(s, "impl crate::probe::ProbeSize for crate::bmc::Size<{n}> {{}}");
        }
    }
    s
}

/// `f32::from_bits(0x3f80_0000)`-style text: the exact bits.
fn bits(x: f32) -> String {
    let b = x.to_bits();
    format!("f32::from_bits(0x{:04x}_{:04x})", b >> 16, b & 0xffff)
}
