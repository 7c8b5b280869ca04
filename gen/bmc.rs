//! Generator of the Bayesian Monte Carlo weights (issue #6), in f64.
//!
//! Kernel `k(x, x′) = exp(−|x − x′|²/l²) + σ′²δ` on unit vectors: `exp(λ(x·x′ − 1))` with
//! `λ = 2/l²`, a spherical Gaussian with axis `x` (σ_f = 1). Samples: the `N`-point hemisphere
//! spherical Fibonacci set about the normal, `zⱼ = 1 − (2j + 1)/(2N)`, `φⱼ = 2π·frac(j/Φ)` (the
//! uniform set, not cosine-morphed: the cosine is the known part `p(x) = cos θ/π`, `∫p = 1`).
//! The set is rotation-invariant about the normal as a kernel matrix, so one weight vector per
//! `(N, l, σ′)` serves every normal and every phase.
//!
//! - `Q = K + σ′²I`, `Kᵢⱼ = exp(−λ|xᵢ − xⱼ|²/2)`.
//! - `zᵢ = ∫_{H²} k(xᵢ, x)·cos θ/π dx = C(λ, tᵢ)/π` with `tᵢ = xᵢ·n`, where `C` is the SG ×
//!   clamped-cosine integral of `gen/sg.rs` ([`super::sg::clamped_fraction`] × F(λ)).
//! - `V̄ = ∫∫ k p p = (2/π)∫₀¹ t·C(λ, t) dt` (the inner integral is `C(λ, x·n)/π`, and the
//!   outer one is over the hemisphere in `t = x·n`), by 8 × 16-point Gauss–Legendre.
//! - GLS constant mean (Rasmussen & Williams 2006, eq. 2.42): with `a = Q⁻¹z`, `b = Q⁻¹1`,
//!   `w = a + (1 − 1ᵀa)·b/(1ᵀb)` (so `Σw = 1`), and the posterior variance of `∫ f p`
//!   `v = V̄ − zᵀa + (1 − 1ᵀa)²/(1ᵀb)`. The irradiance is `E = π·Σwᵢ Yᵢ` and its variance
//!   `π²·v` (units of σ_f²).
//!
//! Solves: Cholesky `Q = LLᵀ` plus one step of iterative refinement. The condition number
//! is estimated as `λ_max/λ_min` by power and inverse power iteration.

use std::f64::consts::PI;
use std::fmt::Write as _;

/// The file in `tables/` that says what to bake.
pub const CONFIG_FILE: &str = "tables/bmc.txt";

/// The largest N a config may ask for (the O(N³) solve runs in every user's build).
pub const MAX_N: usize = 1024;

/// `round(2⁶⁴/Φ)`: the crate's golden phase step (`sf::GOLDEN_PHASE`).
const GOLDEN_PHASE: u64 = 0x9E37_79B9_7F4A_7C16;

/// One set to bake.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    /// Number of samples.
    pub n: usize,
    /// Kernel length scale `l` (rounded to f32 first, so the library reports what was used).
    pub length_scale: f32,
    /// Noise ratio `σ′ = σ_n/σ_f` (rounded to f32 first).
    pub noise: f32,
    /// The cosine-morphed set (`cosine`) rather than the uniform one (`uniform`, the default).
    pub cosine: bool,
}

impl Spec {
    /// `λ = 2/l²`.
    pub fn lambda(&self) -> f64 {
        2.0 / f64::from(self.length_scale).powi(2)
    }
}

/// Parses `set = N l sigma [uniform|cosine]` lines; `#` starts a comment. N must be in
/// 1..=[`MAX_N`] and strictly increasing; `l` and `σ′` finite and positive; the sample set is
/// the uniform hemisphere spherical Fibonacci set unless `cosine` says the cosine-morphed one.
pub fn parse(text: &str) -> Result<Vec<Spec>, String> {
    let mut specs: Vec<Spec> = Vec::new();
    for (no, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let at = |m: String| format!("line {}: {m}", no + 1);
        let (k, v) = line.split_once('=').ok_or_else(|| at("expected `set = N l sigma`".into()))?;
        if k.trim() != "set" {
            return Err(at(format!("unknown key `{}`", k.trim())));
        }
        let f: Vec<&str> = v.split_whitespace().collect();
        if f.len() != 3 && f.len() != 4 {
            return Err(at("expected `set = N l sigma [uniform|cosine]`".into()));
        }
        let cosine = match f.get(3) {
            None | Some(&"uniform") => false,
            Some(&"cosine") => true,
            Some(x) => return Err(at(format!("sample set `{x}`: expected uniform or cosine"))),
        };
        let n: usize = f[0].parse().map_err(|e| at(format!("N: {e}")))?;
        if !(1..=MAX_N).contains(&n) {
            return Err(at(format!("N = {n} must be in 1..={MAX_N}")));
        }
        if specs.last().is_some_and(|s| s.n >= n) {
            return Err(at(format!("N = {n}: sizes must be strictly increasing")));
        }
        let pos = |s: &str, what: &str| -> Result<f32, String> {
            let x: f32 = s.parse().map_err(|e| at(format!("{what}: {e}")))?;
            if x.is_finite() && x > 0.0 {
                Ok(x)
            } else {
                Err(at(format!("{what} = {x} must be finite and positive")))
            }
        };
        specs.push(Spec { n, length_scale: pos(f[1], "l")?, noise: pos(f[2], "sigma")?, cosine });
    }
    if specs.is_empty() {
        return Err("no `set = N l sigma` line".into());
    }
    Ok(specs)
}

/// The baked quantities of one set.
#[derive(Clone, Debug, PartialEq)]
pub struct Baked {
    /// What was baked.
    pub spec: Spec,
    /// The weights in f64 (`Σw = 1`).
    pub weights_f64: Vec<f64>,
    /// The weights rounded once to f32.
    pub weights: Vec<f32>,
    /// Posterior variance of the irradiance `E = π·Σ wᵢYᵢ` for σ_f = 1 (`π²·v`).
    pub variance: f64,
    /// `Σ|w|/Σw` (1 when no weight is negative).
    pub abs_weight_ratio: f64,
    /// Estimated 2-norm condition number of `Q`.
    pub condition: f64,
}

/// Direction j of the N-point hemisphere SF set in the normal's frame (normal = +z): height
/// `u = 1 − (2j + 1)/(2N)`, or `cos θ = √u` for the cosine-morphed set.
pub fn direction(j: usize, n: usize, cosine: bool) -> [f64; 3] {
    let d = 2.0 * n as f64;
    let a = (2 * j + 1) as f64 / d; // 1 − u
    let (z, s) =
        if cosine { ((1.0 - a).sqrt(), a.sqrt()) } else { (1.0 - a, (a * (2.0 - a)).sqrt()) };
    let turns = (j as u64).wrapping_mul(GOLDEN_PHASE) as f64 / 18_446_744_073_709_551_616.0;
    let (sp, cp) = (2.0 * PI * turns).sin_cos();
    [s * cp, s * sp, z]
}

/// `∫_{H²} exp(λ(μ·x − 1))·cos θ/π dx` for an axis μ with `μ·n = t`: `C(λ, t)/π`.
pub fn kernel_mean(lambda: f64, t: f64) -> f64 {
    super::sg::clamped_fraction(lambda, t) * super::sg::full_integral(lambda) / PI
}

/// `V̄ = ∫∫ k(x, x′) p(x) p(x′) dx dx′ = 2∫₀¹ t·kernel_mean(λ, t) dt` (σ′ excluded).
pub fn kernel_mean_mean(lambda: f64) -> f64 {
    let (xs, ws) = super::sg::gauss_legendre(16);
    let panels = 8;
    let h = 1.0 / panels as f64;
    let mut sum = 0.0;
    for p in 0..panels {
        let c = (p as f64 + 0.5) * h;
        for (x, w) in xs.iter().zip(&ws) {
            let t = c + 0.5 * h * x;
            sum += 0.5 * h * w * t * kernel_mean(lambda, t);
        }
    }
    2.0 * sum
}

/// `Q = K + σ′²I`, row-major.
pub fn gram(spec: &Spec) -> Vec<f64> {
    let n = spec.n;
    let lambda = spec.lambda();
    let xs: Vec<[f64; 3]> = (0..n).map(|j| direction(j, n, spec.cosine)).collect();
    let nugget = f64::from(spec.noise).powi(2);
    let mut q = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            let d2: f64 = (0..3).map(|k| (xs[i][k] - xs[j][k]).powi(2)).sum();
            q[i * n + j] = (-0.5 * lambda * d2).exp() + if i == j { nugget } else { 0.0 };
        }
    }
    q
}

// The loops below run in every dependant's unoptimised build script when it bakes (a user
// table, a feature sweep): plain `while` loops over slices (no iterator adapters or `Vec`
// indexing calls), summing in the same order as `Iterator::sum` (from −0.0, left to right),
// so that the results are the same bits as the iterator forms they replace.

/// Lower Cholesky factor of the SPD row-major `q`.
pub fn cholesky(q: &[f64], n: usize) -> Result<Vec<f64>, String> {
    let mut l = vec![0.0; n * n];
    let lm = &mut l[..];
    let mut i = 0;
    while i < n {
        let mut j = 0;
        while j <= i {
            let mut s = q[i * n + j];
            let (ri, rj) = (i * n, j * n);
            let mut k = 0;
            while k < j {
                s -= lm[ri + k] * lm[rj + k];
                k += 1;
            }
            if i == j {
                if s <= 0.0 || !s.is_finite() {
                    return Err(format!("Q is not positive definite (pivot {i}: {s:e})"));
                }
                lm[ri + i] = s.sqrt();
            } else {
                lm[ri + j] = s / lm[rj + j];
            }
            j += 1;
        }
        i += 1;
    }
    Ok(l)
}

/// `x = (LLᵀ)⁻¹b` for the row-major lower factor `l` of [`cholesky`].
pub fn chol_solve(l: &[f64], n: usize, b: &[f64]) -> Vec<f64> {
    let mut out = b.to_vec();
    let y = &mut out[..];
    let mut i = 0;
    while i < n {
        let mut s = y[i];
        let row = &l[i * n..i * n + i];
        let mut k = 0;
        while k < i {
            s -= row[k] * y[k];
            k += 1;
        }
        y[i] = s / l[i * n + i];
        i += 1;
    }
    let mut i = n;
    while i > 0 {
        i -= 1;
        let mut s = y[i];
        let mut k = i + 1;
        while k < n {
            s -= l[k * n + i] * y[k];
            k += 1;
        }
        y[i] = s / l[i * n + i];
    }
    out
}

/// `q·x` for the row-major `n × n` matrix `q`.
pub fn mat_vec(q: &[f64], n: usize, x: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; n];
    let o = &mut out[..];
    let mut i = 0;
    while i < n {
        let row = &q[i * n..i * n + n];
        let mut s = -0.0;
        let mut j = 0;
        while j < n {
            s += row[j] * x[j];
            j += 1;
        }
        o[i] = s;
        i += 1;
    }
    out
}

/// `Σ aᵢbᵢ`, left to right from −0.0 (as `Iterator::sum`).
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let mut s = -0.0;
    let mut i = 0;
    while i < n {
        s += a[i] * b[i];
        i += 1;
    }
    s
}

/// `b − q·x` (the residual of iterative refinement).
pub fn residual(q: &[f64], n: usize, x: &[f64], b: &[f64]) -> Vec<f64> {
    let mut r = mat_vec(q, n, x);
    let rs = &mut r[..];
    let mut i = 0;
    while i < n {
        rs[i] = b[i] - rs[i];
        i += 1;
    }
    r
}

/// `Q⁻¹b` by Cholesky and one step of iterative refinement.
fn solve(q: &[f64], l: &[f64], n: usize, b: &[f64]) -> Vec<f64> {
    let mut x = chol_solve(l, n, b);
    let r = residual(q, n, &x, b);
    let d = chol_solve(l, n, &r);
    let xs = &mut x[..];
    let mut i = 0;
    while i < n {
        xs[i] += d[i];
        i += 1;
    }
    x
}

/// `λ_max/λ_min` of the SPD `q` by 100 steps each of power and inverse power iteration.
fn condition(q: &[f64], l: &[f64], n: usize) -> f64 {
    let rayleigh = |f: &dyn Fn(&[f64]) -> Vec<f64>| {
        // A start vector with every eigencomponent almost surely non-zero.
        let mut v: Vec<f64> = (0..n).map(|i| 1.0 + 0.37 * (i as f64).sin()).collect();
        let mut est = 0.0;
        for _ in 0..100 {
            let norm = dot(&v, &v).sqrt();
            let vs = &mut v[..];
            let mut i = 0;
            while i < n {
                vs[i] /= norm;
                i += 1;
            }
            let w = f(&v);
            est = dot(&v, &w);
            v = w;
        }
        est
    };
    let max = rayleigh(&|v| mat_vec(q, n, v));
    let inv_min = rayleigh(&|v| chol_solve(l, n, v));
    max * inv_min
}

/// Bakes one set.
pub fn bake(spec: &Spec) -> Result<Baked, String> {
    let n = spec.n;
    let lambda = spec.lambda();
    let q = gram(spec);
    let l = cholesky(&q, n)?;
    let z: Vec<f64> =
        (0..n).map(|j| kernel_mean(lambda, direction(j, n, spec.cosine)[2])).collect();
    let a = solve(&q, &l, n, &z);
    let b = solve(&q, &l, n, &vec![1.0; n]);
    let sa: f64 = a.iter().sum();
    let sb: f64 = b.iter().sum();
    let gls = (1.0 - sa) / sb;
    let w: Vec<f64> = a.iter().zip(&b).map(|(a, b)| a + gls * b).collect();
    let za: f64 = z.iter().zip(&a).map(|(z, a)| z * a).sum();
    let v = kernel_mean_mean(lambda) - za + (1.0 - sa) * (1.0 - sa) / sb;
    let sum: f64 = w.iter().sum();
    Ok(Baked {
        spec: *spec,
        weights: w.iter().map(|&x| x as f32).collect(),
        abs_weight_ratio: w.iter().map(|x| x.abs()).sum::<f64>() / sum,
        weights_f64: w,
        variance: PI * PI * v,
        condition: condition(&q, &l, n),
    })
}

/// Bakes every set.
pub fn bake_all(specs: &[Spec]) -> Result<Vec<Baked>, String> {
    specs
        .iter()
        .map(|s| {
            let b = bake(s)?;
            // A user table (SPHERE_QUADRATURE_BMC_TABLE) with absurd l or σ′ must not bake
            // NaN weights into a program that builds.
            let finite = b.weights.iter().all(|w| w.is_finite()) && (b.variance as f32).is_finite();
            if finite {
                Ok(b)
            } else {
                Err(format!(
                    "N = {}, l = {}, sigma = {}: the baked weights or variance are not finite",
                    s.n, s.length_scale, s.noise
                ))
            }
        })
        .collect()
}

/// The Rust source that `build.rs` writes to `$OUT_DIR/bmc_tables.rs`: one `static` weight
/// array per set and the sealed-trait impls that admit exactly the baked sizes.
pub fn render(sets: &[Baked]) -> String {
    let mut s = String::new();
    s.push_str("// @generated by build.rs; do not edit\n");
    let _ = writeln!(s, "// From gen/bmc.rs and {CONFIG_FILE}.");
    let sizes: Vec<String> = sets.iter().map(|b| b.spec.n.to_string()).collect();
    let _ = writeln!(s, "\n/// The sizes N with baked Bayesian Monte Carlo weights.");
    let _ = writeln!(
        s,
        "pub(crate) const BMC_SIZES: [usize; {}] = [{}];",
        sets.len(),
        sizes.join(", ")
    );
    for b in sets {
        let n = b.spec.n;
        let _ = writeln!(
            s,
            "\n/// Weights for N = {n}, l = {:?}, σ′ = {:?}: Σ|w|/Σw = {:.6}, cond(Q) ≈ {:.3e}.",
            b.spec.length_scale, b.spec.noise, b.abs_weight_ratio, b.condition
        );
        let _ = writeln!(s, "pub(crate) static BMC_WEIGHTS_{n}: [f32; {n}] = [");
        for &x in &b.weights {
            let _ = writeln!(s, "    {}, // {x:?}", bits(x));
        }
        s.push_str("];\n");
        let _ = writeln!(s, "impl crate::bmc::sealed::Sealed for crate::bmc::Size<{n}> {{");
        s.push_str("    const SET: crate::bmc::sealed::Set = crate::bmc::sealed::Set {\n");
        let _ = writeln!(s, "        weights: &BMC_WEIGHTS_{n},");
        let _ = writeln!(s, "        cosine: {},", b.spec.cosine);
        for (name, x) in [
            ("variance", b.variance as f32),
            ("length_scale", b.spec.length_scale),
            ("noise", b.spec.noise),
            ("abs_weight_ratio", b.abs_weight_ratio as f32),
            ("condition", b.condition as f32),
        ] {
            let _ = writeln!(s, "        {name}: {}, // {x:?}", bits(x));
        }
        s.push_str("    };\n}\n");
        let _ = writeln!(s, "impl crate::bmc::BakedSize for crate::bmc::Size<{n}> {{}}");
    }
    s
}

/// `f32::from_bits(0x3f80_0000)`-style text: the exact bits.
fn bits(x: f32) -> String {
    let b = x.to_bits();
    format!("f32::from_bits(0x{:04x}_{:04x})", b >> 16, b & 0xffff)
}

/// The weights as unsigned Q1.31 integers summing to exactly 2³¹: `floor(w·2³¹)` of the f64
/// weights, plus one on the `2³¹ − Σ floor` weights with the largest remainders (ties to the
/// lower index). Every `q` is within one unit (2⁻³¹) of `w·2³¹`, and `Σq = 2³¹` makes the
/// fixed-point sum of a constant exact and its accumulator bounded.
///
/// # Errors
/// A negative, non-finite or ≥ 1 weight, or a sum too far from 1 to fix with ±1 per weight.
pub fn q31(weights: &[f64]) -> Result<Vec<u32>, String> {
    const ONE: f64 = 2_147_483_648.0;
    let mut q = Vec::with_capacity(weights.len());
    let mut rem = Vec::with_capacity(weights.len());
    for (i, &w) in weights.iter().enumerate() {
        if !(w.is_finite() && (0.0..1.0).contains(&w)) {
            return Err(format!("weight {i} = {w:e} is not in [0, 1) (unsigned Q1.31)"));
        }
        let f = (w * ONE).floor();
        q.push(f as u32);
        rem.push((w * ONE - f, i));
    }
    let sum: u64 = q.iter().map(|&x| u64::from(x)).sum();
    let deficit = (1u64 << 31)
        .checked_sub(sum)
        .filter(|&d| d <= weights.len() as u64)
        .ok_or_else(|| format!("Σ floor(w·2³¹) = {sum} cannot be rounded to 2³¹"))?;
    rem.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    for &(_, i) in &rem[..deficit as usize] {
        q[i] += 1;
    }
    Ok(q)
}

/// The Rust source that `build.rs` writes to `$OUT_DIR/bmc_size_diagnostics.rs`, included
/// by `src/lib.rs`: the macro `unbaked_size_diagnostic!` that puts on `bmc::BakedSize`
/// (`renderer`) and `fixed_point::FixedSize` (`fixed`) the compile error for an unbaked `N`,
/// listing the sizes this build actually baked (a table of the user's own,
/// `SPHERE_QUADRATURE_BMC_TABLE`, may bake others than the default; a size with a negative
/// weight gets no fixed-point form).
pub fn render_size_diagnostics(sets: &[Baked]) -> String {
    let list = |sizes: Vec<usize>| {
        let sizes: Vec<String> = sizes.iter().map(usize::to_string).collect();
        if sizes.is_empty() {
            "none".to_string()
        } else {
            format!("N = {}", sizes.join(", "))
        }
    };
    let renderer = list(sets.iter().map(|b| b.spec.n).collect());
    let fixed =
        list(sets.iter().filter(|b| q31(&b.weights_f64).is_ok()).map(|b| b.spec.n).collect());
    let table = format!("this build's table: {CONFIG_FILE} or SPHERE_QUADRATURE_BMC_TABLE");
    let mut s = String::new();
    s.push_str("// @generated by build.rs; do not edit\n");
    let _ = writeln!(s, "// From gen/bmc.rs and {CONFIG_FILE}.");
    s.push_str("/// The compile error of an unbaked size, listing the sizes this build baked.\n");
    s.push_str("macro_rules! unbaked_size_diagnostic {\n");
    for (arm, message, label, sizes) in [
        (
            "renderer",
            "no Bayesian Monte Carlo weights are baked for `{Self}`",
            "this sample count has no baked weights",
            &renderer,
        ),
        (
            "fixed",
            "no fixed-point Bayesian Monte Carlo weights are baked for `{Self}`",
            "this sample count has no baked fixed-point weights",
            &fixed,
        ),
    ] {
        let _ = writeln!(s, "    ({arm}, $item:item) => {{");
        let _ = writeln!(s, "        #[diagnostic::on_unimplemented(");
        let _ = writeln!(s, "            message = \"{message}\",");
        let _ = writeln!(s, "            label = \"{label}\",");
        let _ = writeln!(s, "            note = \"the baked sizes are {sizes} ({table})\"");
        s.push_str("        )]\n        $item\n    };\n");
    }
    s.push_str("}\n");
    s
}

/// The Rust source of `$OUT_DIR/bmc_fixed_tables.rs`: the weights as Q1.31 `u32` constants
/// ([`q31`]) for `src/fixed_point.rs` (feature `fixed`), one sealed `FixedSize` impl per
/// baked size whose weights all lie in [0, 1). A size with a negative weight (possible with
/// a user's own hyperparameters) gets no fixed-point form, and a comment saying why, instead
/// of failing every build: `BmcFixed<N>` then does not compile for it.
pub fn render_fixed(sets: &[Baked]) -> String {
    let mut s = String::new();
    s.push_str("// @generated by build.rs; do not edit\n");
    let _ = writeln!(s, "// From gen/bmc.rs and {CONFIG_FILE}: Q1.31 weights, Σ = 2³¹ exactly.");
    for b in sets {
        let n = b.spec.n;
        let q = match q31(&b.weights_f64) {
            Ok(q) => q,
            Err(e) => {
                let _ = writeln!(s, "// N = {n}: no fixed-point weights ({e}).");
                continue;
            }
        };
        let _ = writeln!(s, "impl sealed::FixedSet for crate::bmc::Size<{n}> {{");
        let _ = writeln!(s, "    const WEIGHTS_Q31: &'static [u32] = &[");
        for (q, w) in q.iter().zip(&b.weights_f64) {
            let _ = writeln!(s, "        0x{q:08x}, // {w:e}");
        }
        s.push_str("    ];\n}\n");
        let _ = writeln!(s, "impl FixedSize for crate::bmc::Size<{n}> {{}}");
    }
    s
}
