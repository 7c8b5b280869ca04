//! Legendre series of footprints and lobes: Bessel ratios, cosine-power gains, sums.

use super::*;

/// The most Legendre terms a baked series may have (`gen/probe.rs` refuses longer ones).
pub(super) const MAX_SERIES: usize = 256;

/// The float types the series helpers run in: f32 on the glossy hot path, f64 for the exact
/// variances.
pub(super) trait Real:
    Copy
    + PartialOrd
    + core::ops::Add<Output = Self>
    + core::ops::Sub<Output = Self>
    + core::ops::Mul<Output = Self>
    + core::ops::Div<Output = Self>
    + core::ops::MulAssign
{
    const ZERO: Self;
    const ONE: Self;
    fn of(x: f64) -> Self;
    fn of_usize(n: usize) -> Self;
    fn to_f64(self) -> f64;
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    fn of(x: f64) -> Self {
        x as f32
    }
    fn of_usize(n: usize) -> Self {
        n as f32
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    fn of(x: f64) -> Self {
        x
    }
    fn of_usize(n: usize) -> Self {
        n as f64
    }
    fn to_f64(self) -> f64 {
        self
    }
}

/// `ρ_l(x) = i_l(x)/i₀(x)` for `l < out.len()` (modified spherical Bessel functions), in the
/// precision of `R` (f32 on the glossy hot path: each ratio to a few ulp, `ρ_l` to about `l`
/// ulp; f64 for the exact variances).
///
/// Large `x` (`x ≥ 40` and `x ≥ L²/36`, `L = out.len() − 1`): the forward recurrence
/// `ρ_{l+1} = ρ_{l−1} − (2l + 1)/x·ρ_l` from `ρ₁ = coth x − 1/x`, always in f64, whose
/// rounding grows like `e^{l²/(2x)} ≤ e^{18}` relative to `ρ₀` (below 10⁻⁸). Otherwise the
/// backward continued fraction `r_k = x/(2k + 1 + x·r_{k+1})` for `r_k = ρ_k/ρ_{k−1}`, started
/// at `max(L, x) + 32` (for `k ≥ x`, `r_k < 1/2`, so every step damps the start's error by
/// `r² < 1/4`: 32 steps give 10⁻¹⁹), at most `L + L²/36 + 72` steps.
pub(super) fn bessel_ratios<R: Real>(x: R, out: &mut [R]) {
    let Some((first, rest)) = out.split_first_mut() else { return };
    *first = R::ONE;
    let xf = x.to_f64();
    if xf.is_nan() || xf <= 0.0 {
        rest.iter_mut().for_each(|r| *r = R::ZERO);
        return;
    }
    let top = rest.len() as f64;
    if xf >= 40.0 && 36.0 * xf >= top * top {
        // coth x − 1/x with e^{−2x} < 2⁻¹¹⁵: 1 − 1/x to f64 rounding.
        let mut prev = 1.0;
        let mut cur = 1.0 - 1.0 / xf;
        for (l, r) in rest.iter_mut().enumerate() {
            *r = R::of(cur);
            let next = prev - (2 * l + 3) as f64 / xf * cur;
            prev = cur;
            cur = next;
        }
        return;
    }
    let start = rest.len().max(xf as usize) + 32;
    let mut ratio = R::ZERO;
    for k in (1..=start).rev() {
        ratio = x / (R::of_usize(2 * k + 1) + x * ratio);
        if let Some(r) = rest.get_mut(k - 1) {
            *r = ratio;
        }
    }
    let mut product = R::ONE;
    for r in rest.iter_mut() {
        product *= *r;
        *r = product;
    }
}

/// `cₗ = S_l(λ)·(2l + 1)/(4π)`, the Legendre coefficients of the unit spherical Gaussian of
/// sharpness `λ` (`S_l = F(λ)·ρ_l(λ)`), in f32, into `out`; returns the number of terms kept:
/// `16 + ⌈9.1√λ⌉` (capped at [`MAX_SERIES`]), past which `S_l/S₀ < e^{−41}`.
pub(super) fn sg_series_f32(lambda: f32, out: &mut [f32; MAX_SERIES]) -> usize {
    let len = (16 + (9.1 * crate::math::sqrt(lambda)) as usize).min(MAX_SERIES);
    let Some(out) = out.get_mut(..len) else { return 0 };
    bessel_ratios(lambda, out);
    let full = full_integral_unchecked(lambda);
    for (l, b) in out.iter_mut().enumerate() {
        *b *= full * (2 * l + 1) as f32 / (4.0 * PI);
    }
    len
}

/// Multiplies `out` by the gains `(p + 1)∫₀¹ tᵖ P_l(t) dt` of the normalised cosine-power lobe
/// of any real exponent `p ≥ 0` (a photodiode's response for `p = 1`, the normalised Phong
/// lobe for `p = e`): `m₀ = 1/(p + 1)`, `m₁ = 1/(p + 2)`, `m_{l+2} = m_l·(p − l)/(p + l + 3)`.
pub(super) fn apply_cosine_power_gains<R: Real>(p: R, out: &mut [R]) {
    let (one, two, three) = (R::ONE, R::of(2.0), R::of(3.0));
    let (mut even, mut odd) = (one / (p + one), one / (p + two));
    for (l, b) in out.iter_mut().enumerate() {
        let m = if l % 2 == 0 { even } else { odd };
        *b *= (p + one) * m;
        let lf = R::of_usize(l);
        if l % 2 == 0 {
            even *= (p - lf) / (p + lf + three);
        } else {
            odd *= (p - lf) / (p + lf + three);
        }
    }
}

/// [`cosine_series`] in f32 (the glossy hot path).
pub(super) fn cosine_series_f32(lambda: f32, exponent: u32, out: &mut [f32; MAX_SERIES]) -> usize {
    let len = sg_series_f32(lambda, out);
    if let Some(out) = out.get_mut(..len) {
        apply_cosine_power_gains(exponent as f32, out);
    }
    len
}

/// `bₗ = K_l·g_l·(2l + 1)/(4π)` of a cosine-power footprint `max(0, t)ᵖ` under the
/// squared-exponential kernel of sharpness `λ` (`K_l = F(λ)·ρₗ(λ)`, `g_l` the footprint's
/// gains), into `out`; returns the number of terms kept: `16 + ⌈9.1√λ⌉` (capped at
/// [`MAX_SERIES`]), past which `K_l/K₀ < e^{−41}`.
pub(super) fn cosine_series(lambda: f64, exponent: u32, out: &mut [f64; MAX_SERIES]) -> usize {
    let len = (16 + (9.1 * crate::math::sqrt64(lambda)) as usize).min(MAX_SERIES);
    let Some(out) = out.get_mut(..len) else { return 0 };
    bessel_ratios(lambda, out);
    let full = glossy_full_integral(lambda);
    let p = f64::from(exponent);
    // (p + 1)·m_l with m₀ = 1/(p + 1), m₁ = 1/(p + 2), m_l = m_{l−2}·(p − l + 2)/(p + l + 1).
    let (mut even, mut odd) = (1.0 / (p + 1.0), 1.0 / (p + 2.0));
    for (l, b) in out.iter_mut().enumerate() {
        let m = if l % 2 == 0 { even } else { odd };
        *b *= full * (p + 1.0) * m * (2 * l + 1) as f64 / (4.0 * core::f64::consts::PI);
        let lf = l as f64;
        if l % 2 == 0 {
            even *= (p - lf) / (p + lf + 3.0);
        } else {
            odd *= (p - lf) / (p + lf + 3.0);
        }
    }
    len
}

/// `K_l·(2l + 1)/(4π)`, the kernel's Legendre coefficients, in f64, into `out`; returns the
/// number of terms. Point and cosine-power footprints: the squared exponential,
/// `K_l = F(λ)·ρₗ(λ)`, `16 + ⌈9.1√λ⌉` terms. Gaussian footprint of sharpness `S`: the
/// deconvolved kernel `K_l = F(ν)·ρₗ(ν)/ρₗ(S)` (`λ = ν`), which falls like `(ν/S)^l`:
/// [`MAX_SERIES`] terms (`gen/probe.rs` refuses members whose series has not converged by
/// then).
pub(super) fn kernel_coefficients(kind: Kind, lambda: f64, out: &mut [f64; MAX_SERIES]) -> usize {
    let pi4 = 4.0 * core::f64::consts::PI;
    let full = glossy_full_integral(lambda);
    if let Kind::Gaussian { sharpness } = kind {
        let mut rs = [0.0f64; MAX_SERIES];
        bessel_ratios(lambda, out);
        bessel_ratios(f64::from(sharpness), &mut rs);
        for (l, (a, &b)) in out.iter_mut().zip(&rs).enumerate() {
            *a = if b > 0.0 { full * *a / b * (2 * l + 1) as f64 / pi4 } else { 0.0 };
        }
        return MAX_SERIES;
    }
    let len = (16 + (9.1 * crate::math::sqrt64(lambda)) as usize).min(MAX_SERIES);
    let Some(out) = out.get_mut(..len) else { return 0 };
    bessel_ratios(lambda, out);
    for (l, a) in out.iter_mut().enumerate() {
        *a *= full * (2 * l + 1) as f64 / pi4;
    }
    len
}

/// `V̄/F(μ)² = Σ_l K_l·(2l + 1)/(4π)·ρₗ(μ)²` for the Gaussian footprint's deconvolved kernel.
pub(super) fn deconvolved_vbar(nu: f64, sharpness: u32, mu: f64) -> f64 {
    let mut k = [0.0f64; MAX_SERIES];
    let len = kernel_coefficients(Kind::Gaussian { sharpness }, nu, &mut k);
    let mut rho = [0.0f64; MAX_SERIES];
    bessel_ratios(mu, &mut rho);
    k.iter().zip(&rho).take(len).map(|(&k, &p)| k * p * p).sum()
}

/// `Σ_l hₗ·P_l(t)` by the forward recurrence of `P_l`, in f64.
pub(super) fn legendre_sum(h: &[f64], t: f64) -> f64 {
    let t = t.clamp(-1.0, 1.0);
    let (mut p0, mut p1) = (0.0, 1.0);
    let mut sum = 0.0;
    for (l, &c) in h.iter().enumerate() {
        sum += c * p1;
        let next = ((2 * l + 1) as f64 * t * p1 - l as f64 * p0) / (l + 1) as f64;
        p0 = p1;
        p1 = next;
    }
    sum
}

/// The forward recurrence's coefficients `((2l + 1)/(l + 1), l/(l + 1))` for `l < len`, once
/// per query so that the per-sample sums do not divide.
pub(super) fn legendre_recurrence(len: usize) -> [(f32, f32); MAX_SERIES] {
    let mut c = [(0.0f32, 0.0f32); MAX_SERIES];
    for (l, slot) in c.iter_mut().enumerate().take(len) {
        let lf = l as f32;
        let inv = 1.0 / (lf + 1.0);
        *slot = ((2.0 * lf + 1.0) * inv, lf * inv);
    }
    c
}

/// `Σ_l hₗ·P_l(t)` by the forward recurrence of `P_l` with the coefficients of
/// [`legendre_recurrence`], in f32 (the glossy hot path).
pub(super) fn legendre_sum_f32(h: &[f32], rec: &[(f32, f32)], t: f32) -> f32 {
    let t = t.clamp(-1.0, 1.0);
    let (mut p0, mut p1) = (0.0f32, 1.0f32);
    let mut sum = 0.0f32;
    for (&c, &(a, b)) in h.iter().zip(rec) {
        sum += c * p1;
        let next = a * t * p1 - b * p0;
        p0 = p1;
        p1 = next;
    }
    sum
}
