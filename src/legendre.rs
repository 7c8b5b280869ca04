//! Legendre polynomials and the Funk–Hecke gains of zonal lobes: the three-term recurrence,
//! the series sums built on it, the gains of cosine powers and of spherical Gaussians.
//!
//! Every other module takes these from here. Where a `const fn` (the layout's tables, built by
//! the compiler) needs what a hot path runs in f32, the const form sits beside its runtime
//! twin, and the tests below hold them to each other.

use crate::math::clamp_unit;

/// The float types the series run in: f32 on the glossy hot paths, f64 for the exact
/// variances.
pub(crate) trait Real:
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

/// The factors `(a_l, b_l) = ((2l − 1)/l, (l − 1)/l)` of the recurrence
/// `P_l(t) = a_l·t·P_{l−1}(t) − b_l·P_{l−2}(t)`, each rounded once to f32; `(0, 0)` for `l = 0`.
pub(crate) const fn factors(l: usize) -> (f32, f32) {
    if l == 0 {
        return (0.0, 0.0);
    }
    ((2 * l - 1) as f32 / l as f32, (l - 1) as f32 / l as f32)
}

/// [`factors`] of the degrees `l < len` (and `M`), the rest zero: a query's table, so that the
/// per-sample sums do not divide.
pub(crate) const fn factor_table<const M: usize>(len: usize) -> [(f32, f32); M] {
    let mut table = [(0.0f32, 0.0f32); M];
    let mut l = 1;
    while l < len && l < M {
        table[l] = factors(l);
        l += 1;
    }
    table
}

/// `P_0(t), P_1(t), …` at one `t ∈ [−1, 1]`, one degree per [`Polynomials::step`], in f32.
#[derive(Clone, Copy)]
pub(crate) struct Polynomials {
    t: f32,
    previous: f32,
    current: f32,
}

impl Polynomials {
    /// At `P_0(t) = 1`, with `t` clamped to `[−1, 1]` (NaN kept).
    pub(crate) const fn at(t: f32) -> Self {
        Polynomials { t: clamp_unit(t), previous: 0.0, current: 1.0 }
    }

    /// `P_l(t)` at the current degree `l`.
    pub(crate) const fn value(&self) -> f32 {
        self.current
    }

    /// To the next degree `l`, with its [`factors`] `(a_l, b_l)`.
    pub(crate) const fn step(&mut self, (a, b): (f32, f32)) {
        let next = a * self.t * self.current - b * self.previous;
        self.previous = self.current;
        self.current = next;
    }
}

/// `Σ_l c_l·P_l(t)` over `l < c.len()`, with the factors of `table` (at least as long as `c`;
/// the terms past it are dropped), in f32.
pub(crate) const fn sum(c: &[f32], table: &[(f32, f32)], t: f32) -> f32 {
    if c.is_empty() {
        return 0.0;
    }
    let mut p = Polynomials::at(t);
    let mut s = c[0];
    let mut l = 1;
    while l < c.len() && l < table.len() {
        p.step(table[l]);
        s += c[l] * p.value();
        l += 1;
    }
    s
}

/// Two series at one `t` from one recurrence: `(Σ a_l·P_l(t), Σ b_l·P_l(t))`, `l < D`.
pub(crate) const fn sums<const D: usize>(
    a: &[f32; D],
    b: &[f32; D],
    table: &[(f32, f32); D],
    t: f32,
) -> (f32, f32) {
    if D == 0 {
        return (0.0, 0.0);
    }
    let mut p = Polynomials::at(t);
    let (mut sa, mut sb) = (a[0], b[0]);
    let mut l = 1;
    while l < D {
        p.step(table[l]);
        sa += a[l] * p.value();
        sb += b[l] * p.value();
        l += 1;
    }
    (sa, sb)
}

/// The even- and odd-degree parts of `Σ_l c_l·P_l(t)`, `l < D`, `t ∈ [0, 1]`: the series is
/// their sum at `t` and their difference at `−t` (`P_l(−t) = (−1)ˡ·P_l(t)`).
pub(crate) const fn parts<const D: usize>(
    c: &[f32; D],
    table: &[(f32, f32); D],
    t: f32,
) -> (f32, f32) {
    if D < 2 {
        return if D == 0 { (0.0, 0.0) } else { (c[0], 0.0) };
    }
    let mut p = Polynomials::at(t);
    let even = c[0];
    p.step(table[1]);
    let (mut even, mut odd) = (even, c[1] * p.value());
    let mut l = 2;
    while l < D {
        p.step(table[l]);
        if l % 2 == 0 {
            even += c[l] * p.value();
        } else {
            odd += c[l] * p.value();
        }
        l += 1;
    }
    (even, odd)
}

/// `P_0(t), P_1(t), …` in f64 (the exact variances, the spectra of point sets), with the
/// recurrence in the form `P_{l+1} = ((2l + 1)·t·P_l − l·P_{l−1})/(l + 1)`: one division per
/// degree instead of a table of f64 factors (4 KB of stack at 256 terms).
pub(crate) struct Polynomials64 {
    t: f64,
    previous: f64,
    current: f64,
    l: usize,
}

impl Polynomials64 {
    /// At `P_0(t) = 1`, with `t` clamped to `[−1, 1]` (NaN kept).
    pub(crate) fn at(t: f64) -> Self {
        Polynomials64 { t: t.clamp(-1.0, 1.0), previous: 0.0, current: 1.0, l: 0 }
    }

    /// `P_l(t)` of the current degree `l`, then on to `l + 1`.
    pub(crate) fn next_value(&mut self) -> f64 {
        let (l, value) = (self.l, self.current);
        let next =
            ((2 * l + 1) as f64 * self.t * value - l as f64 * self.previous) / (l + 1) as f64;
        self.previous = value;
        self.current = next;
        self.l += 1;
        value
    }
}

/// `Σ_l h_l·P_l(t)` in f64 ([`Polynomials64`]).
pub(crate) fn sum_f64(h: &[f64], t: f64) -> f64 {
    let mut p = Polynomials64::at(t);
    h.iter().fold(0.0, |sum, &c| sum + c * p.next_value())
}

/// The gains `g_l = (p + 1)·∫₀¹ tᵖ·P_l(t) dt` of the normalised cosine-power lobe
/// `(p + 1)/(2π)·max(0, t)ᵖ`, any real `p ≥ 0` (a photodiode for `p = 1`, the normalised
/// Phong lobe for `p = e`), one degree per [`CosinePowerGains::next_gain`], in f64:
/// `g_l = (p + 1)·m_l` with `m₀ = 1/(p + 1)`, `m₁ = 1/(p + 2)` and
/// `m_{l+2} = m_l·(p − l)/(p + l + 3)` (the ratio of the closed form
/// `√π·2^(−p−1)·Γ(1 + p)/(Γ(1 + (p − l)/2)·Γ((p + l + 3)/2))`, Gradshteyn–Ryzhik 7.126.2).
/// [`apply_cosine_power_gains`] is its runtime twin in the precision of a [`Real`].
pub(crate) struct CosinePowerGains {
    p: f64,
    even: f64,
    odd: f64,
    l: usize,
}

impl CosinePowerGains {
    /// At degree 0.
    pub(crate) const fn new(p: f64) -> Self {
        CosinePowerGains { p, even: 1.0 / (p + 1.0), odd: 1.0 / (p + 2.0), l: 0 }
    }

    /// `g_l` of the current degree `l`, then on to `l + 1`.
    pub(crate) const fn next_gain(&mut self) -> f64 {
        let (p, l) = (self.p, self.l);
        let lf = l as f64;
        let gain = if l % 2 == 0 {
            let g = (p + 1.0) * self.even;
            self.even *= (p - lf) / (p + lf + 3.0);
            g
        } else {
            let g = (p + 1.0) * self.odd;
            self.odd *= (p - lf) / (p + lf + 3.0);
            g
        };
        self.l += 1;
        gain
    }

    /// `g_l` alone (O(l)).
    pub(crate) const fn at(p: f64, l: usize) -> f64 {
        let mut gains = CosinePowerGains::new(p);
        let mut k = 0;
        while k < l {
            gains.next_gain();
            k += 1;
        }
        gains.next_gain()
    }
}

/// The clamped cosine's Funk–Hecke gains `A_l = 2π∫₀¹ t·P_l(t) dt = π·g_l` (the
/// [`CosinePowerGains`] of `p = 1`: `π`, `2π/3`, `π/4`, 0, `−π/24`, 0, `π/64`, …), `l < D`,
/// in f64 and rounded once: irradiance from radiance, degree by degree.
pub(crate) const fn clamped_cosine_gains<const D: usize>() -> [f32; D] {
    let mut gains = CosinePowerGains::new(1.0);
    let mut a = [0.0f32; D];
    let mut l = 0;
    while l < D {
        a[l] = (core::f64::consts::PI * gains.next_gain()) as f32;
        l += 1;
    }
    a
}

/// Multiplies `out[l]` by the cosine-power gain `g_l` of exponent `p` ([`CosinePowerGains`]),
/// in the precision of `R` (f32 on the glossy hot path; in f64 the same bits as
/// [`CosinePowerGains`]).
pub(crate) fn apply_cosine_power_gains<R: Real>(p: R, out: &mut [R]) {
    let (one, two, three) = (R::ONE, R::of(2.0), R::of(3.0));
    let (mut even, mut odd) = (one / (p + one), one / (p + two));
    for (l, b) in out.iter_mut().enumerate() {
        let lf = R::of_usize(l);
        if l % 2 == 0 {
            *b *= (p + one) * even;
            even *= (p - lf) / (p + lf + three);
        } else {
            *b *= (p + one) * odd;
            odd *= (p - lf) / (p + lf + three);
        }
    }
}

/// Where the backward continued fraction of the Bessel ratios starts for `L = top` and
/// sharpness `x`: `max(L, x) + 32` (for `k ≥ x`, `r_k < 1/2`, so each step damps the start's
/// error by `r² < 1/4`: 32 steps give 10⁻¹⁹).
const fn bessel_start(x: f64, top: usize) -> usize {
    let x = x as usize;
    (if top > x { top } else { x }) + 32
}

/// The sharpness from which the run-time ratios ([`bessel_ratios`]) take the forward
/// recurrence (with `x ≥ L²/36`): per query, the continued fraction would take `x` steps.
pub(crate) const FORWARD_FROM: f64 = 40.0;

/// Whether the ratios to degree `top` at sharpness `x` take the forward recurrence: `x` at
/// least `forward_from` and `L²/36`, where its rounding, which grows like `e^{l²/(2x)}`
/// relative to `ρ₀`, stays below `e^{18}` ulp (10⁻⁸).
const fn takes_forward(x: f64, top: usize, forward_from: f64) -> bool {
    let top = top as f64;
    x >= forward_from && 36.0 * x >= top * top
}

/// `ρ_0(x), ρ_1(x), …` by the forward recurrence `ρ_{l+1} = ρ_{l−1} − (2l + 1)/x·ρ_l` from
/// `ρ₁ = coth x − 1/x` (`1 − 1/x` to f64 rounding for `x ≥ 40`: `e^{−2x} < 2⁻¹¹⁵`), in f64.
struct Forward {
    x: f64,
    previous: f64,
    current: f64,
    l: usize,
}

impl Forward {
    /// At `ρ₁`.
    const fn new(x: f64) -> Self {
        Forward { x, previous: 1.0, current: 1.0 - 1.0 / x, l: 1 }
    }

    /// `ρ_l` of the current degree `l ≥ 1`, then on to `l + 1`.
    const fn next_ratio(&mut self) -> f64 {
        let value = self.current;
        let next = self.previous - (2 * self.l + 1) as f64 / self.x * self.current;
        self.previous = self.current;
        self.current = next;
        self.l += 1;
        value
    }
}

/// `ρ_l(x) = i_l(x)/i₀(x)`, `l < out.len()` (modified spherical Bessel functions; the gains
/// `g_l` of the normalised spherical Gaussian of sharpness `x`), in f64 (const); zero past
/// `ρ₀ = 1` for `x ≤ 0` or NaN. The ratios `r_k = ρ_k/ρ_{k−1}` by the backward continued
/// fraction `r_k = x/(2k + 1 + x·r_{k+1})` from [`bessel_start`], then their running
/// products: a few ulp, at most `max(L, x) + 32` steps. From `x = forward_from` (and
/// `x ≥ L²/36`), the [`Forward`] recurrence instead. [`bessel_ratios`] is the run-time twin
/// (`forward_from` = [`FORWARD_FROM`]; in f64 the same bits).
pub(crate) const fn gaussian_gains(x: f64, out: &mut [f64], forward_from: f64) {
    if out.is_empty() {
        return;
    }
    out[0] = 1.0;
    let top = out.len() - 1;
    let mut l = 1;
    if x.is_nan() || x <= 0.0 {
        while l <= top {
            out[l] = 0.0;
            l += 1;
        }
        return;
    }
    if takes_forward(x, top, forward_from) {
        let mut forward = Forward::new(x);
        while l <= top {
            out[l] = forward.next_ratio();
            l += 1;
        }
        return;
    }
    let mut k = bessel_start(x, top);
    let mut ratio = 0.0;
    while k >= 1 {
        ratio = x / ((2 * k + 1) as f64 + x * ratio);
        if k <= top {
            out[k] = ratio;
        }
        k -= 1;
    }
    let mut product = 1.0;
    while l <= top {
        product *= out[l];
        out[l] = product;
        l += 1;
    }
}

/// `ρ_l(x)` alone by the continued fraction, the bits of [`gaussian_gains`] with `L = l`
/// (and no forward recurrence), without its buffer of `l + 1` values: the ratios are
/// recomputed from the same start for each run of 32 degrees (`⌈l/32⌉` passes of at most
/// `max(l, x) + 32` steps).
pub(crate) const fn gaussian_gain(x: f64, l: usize) -> f64 {
    if l == 0 {
        return 1.0;
    }
    if x.is_nan() || x <= 0.0 {
        return 0.0;
    }
    const RUN: usize = 32;
    let start = bessel_start(x, l);
    let mut product = 1.0;
    let mut low = 1;
    while low <= l {
        let high = if low + RUN - 1 < l { low + RUN - 1 } else { l };
        let mut run = [0.0f64; RUN];
        let (mut k, mut ratio) = (start, 0.0);
        while k >= low {
            ratio = x / ((2 * k + 1) as f64 + x * ratio);
            if k <= high {
                run[k - low] = ratio;
            }
            k -= 1;
        }
        let mut j = low;
        while j <= high {
            product *= run[j - low];
            j += 1;
        }
        low = high + 1;
    }
    product
}

/// `ρ_l(x) = i_l(x)/i₀(x)` for `l < out.len()`: [`gaussian_gains`] from [`FORWARD_FROM`], with
/// the continued fraction in the precision of `R` (f32 on the glossy hot path: each ratio to
/// a few ulp, `ρ_l` to about `l` ulp; f64 for the exact variances) and the forward recurrence
/// always in f64.
pub(crate) fn bessel_ratios<R: Real>(x: R, out: &mut [R]) {
    let Some((first, rest)) = out.split_first_mut() else { return };
    *first = R::ONE;
    let xf = x.to_f64();
    if xf.is_nan() || xf <= 0.0 {
        rest.iter_mut().for_each(|r| *r = R::ZERO);
        return;
    }
    if takes_forward(xf, rest.len(), FORWARD_FROM) {
        let mut forward = Forward::new(xf);
        rest.iter_mut().for_each(|r| *r = R::of(forward.next_ratio()));
        return;
    }
    let start = bessel_start(xf, rest.len());
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

#[cfg(test)]
mod tests {
    use super::*;

    /// `P_l(t)` by the explicit sum `2⁻ˡ·Σ_k (−1)ᵏ·C(l, k)·C(2l − 2k, l)·t^{l−2k}`, in f64.
    fn explicit(l: usize, t: f64) -> f64 {
        let choose =
            |n: usize, k: usize| (0..k).fold(1.0, |a, i| a * (n - i) as f64 / (i + 1) as f64);
        (0..=l / 2)
            .map(|k| {
                let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
                sign * choose(l, k) * choose(2 * l - 2 * k, l) * t.powi((l - 2 * k) as i32)
            })
            .sum::<f64>()
            / 2f64.powi(l as i32)
    }

    #[test]
    fn the_recurrence_gives_the_polynomials() {
        for t in [-1.0f32, -0.73, -0.2, 0.0, 0.31, 0.5, 0.99, 1.0] {
            let mut p = Polynomials::at(t);
            for l in 0..16 {
                if l > 0 {
                    p.step(factors(l));
                }
                let want = explicit(l, f64::from(t));
                // f32 rounding grows like l² at t = ±1 (measured: 1.2·10⁻⁸·(l² + 1) at most).
                let err = (f64::from(p.value()) - want).abs();
                assert!(err < 2.5e-8 * (l * l + 1) as f64, "l = {l}, t = {t}: {err}");
            }
        }
        // Clamped: beyond ±1 the value is that at ±1.
        assert_eq!(sum(&[0.3, 0.5, 0.7], &factor_table::<3>(3), 1.5), 1.5);
        assert!(sum(&[1.0, 1.0], &factor_table::<2>(2), f32::NAN).is_nan());
    }

    #[test]
    fn the_factors_are_rounded_once() {
        for l in 1..300 {
            let (a, b) = factors(l);
            assert_eq!(a, ((2 * l - 1) as f64 / l as f64) as f32, "l = {l}");
            assert_eq!(b, ((l - 1) as f64 / l as f64) as f32, "l = {l}");
        }
        let table = factor_table::<8>(5);
        assert_eq!(table[4], factors(4));
        assert_eq!(table[5], (0.0, 0.0));
    }

    #[test]
    fn the_sums_agree_with_each_other_and_with_f64() {
        const D: usize = 12;
        let table = factor_table::<D>(D);
        let a: [f32; D] = core::array::from_fn(|l| 1.0 / (l as f32 + 1.0));
        let b: [f32; D] = core::array::from_fn(|l| if l % 3 == 0 { -0.5 } else { 0.25 });
        let a64 = a.map(f64::from);
        for t in [-1.0f32, -0.4, 0.0, 0.6, 1.0] {
            let (sa, sb) = sums(&a, &b, &table, t);
            assert_eq!(sa.to_bits(), sum(&a, &table, t).to_bits());
            assert_eq!(sb.to_bits(), sum(&b, &table, t).to_bits());
            assert!((f64::from(sa) - sum_f64(&a64, f64::from(t))).abs() < 1e-5);
            let want: f64 = (0..D).map(|l| a64[l] * explicit(l, f64::from(t))).sum();
            assert!((sum_f64(&a64, f64::from(t)) - want).abs() < 1e-12, "t = {t}");
            if t >= 0.0 {
                let (even, odd) = parts(&a, &table, t);
                assert!((even + odd - sa).abs() < 1e-6);
                assert!((f64::from(even - odd) - sum_f64(&a64, -f64::from(t))).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn cosine_power_gains_agree_with_their_closed_form_and_their_twin() {
        // p = 1: g₀ = 1, g₁ = 2/3, g₂ = 1/4, g₃ = 0, g₄ = −1/24.
        let want = [1.0, 2.0 / 3.0, 0.25, 0.0, -1.0 / 24.0];
        let mut g = CosinePowerGains::new(1.0);
        for w in want {
            assert!((g.next_gain() - w).abs() < 1e-15);
        }
        // A_l = 2π·(−1)^(l/2+1)/((l + 2)(l − 1))·l!/(2^l·((l/2)!)²) for even l ≥ 2, 0 for odd.
        let pi = core::f64::consts::PI;
        let a: [f32; 12] = clamped_cosine_gains();
        let want = [pi, 2.0 * pi / 3.0, pi / 4.0, 0.0, -pi / 24.0, 0.0, pi / 64.0, 0.0];
        for (l, w) in want.into_iter().enumerate() {
            assert_eq!(a[l], w as f32, "l = {l}");
        }
        assert_eq!(a[8], (-pi / 128.0) as f32);
        assert_eq!(a[10], (7.0 * pi / 1536.0) as f32);
        for p in [0.0, 0.5, 1.0, 3.5, 20.0, 4096.0, 1e-30] {
            let mut ones = [1.0f64; 40];
            apply_cosine_power_gains(p, &mut ones);
            let mut ones32 = [1.0f32; 40];
            apply_cosine_power_gains(p as f32, &mut ones32);
            let mut g = CosinePowerGains::new(p);
            for l in 0..40 {
                let v = g.next_gain();
                assert_eq!(v.to_bits(), ones[l].to_bits(), "p = {p}, l = {l}");
                assert_eq!(v.to_bits(), CosinePowerGains::at(p, l).to_bits());
                assert!((f64::from(ones32[l]) - v).abs() < 1e-5, "p = {p}, l = {l}");
            }
        }
    }

    #[test]
    fn gaussian_gains_agree_with_their_twin() {
        // ρ₁(x) = coth x − 1/x, ρ₂ = 1 − 3ρ₁/x.
        for x in [0.5f64, 1.0, 8.0, 39.0, 40.0, 100.0, 4096.0, 1e6] {
            let mut g = [0.0f64; 33];
            gaussian_gains(x, &mut g, f64::INFINITY);
            let rho1 = 1.0 / libm::tanh(x) - 1.0 / x;
            // A few ulp: 7 at x = 10⁶ after 10⁶ steps.
            assert!((g[1] - rho1).abs() < 4e-15, "x = {x}: {}", g[1] - rho1);
            assert!((g[2] - (1.0 - 3.0 * rho1 / x)).abs() < 1e-13, "x = {x}");
            let mut fast = [0.0f64; 33];
            gaussian_gains(x, &mut fast, FORWARD_FROM);
            let mut twin = [0.0f64; 33];
            bessel_ratios(x, &mut twin);
            let mut twin32 = [0.0f32; 33];
            bessel_ratios(x as f32, &mut twin32);
            for l in 0..33 {
                assert_eq!(fast[l].to_bits(), twin[l].to_bits(), "x = {x}, l = {l}");
                // The forward recurrence: within 10⁻⁸ of ρ₀ (here 4·10⁻¹¹ at most).
                assert!((fast[l] - g[l]).abs() < 1e-10, "x = {x}, l = {l}");
                assert!((f64::from(twin32[l]) - g[l]).abs() < 1e-6 * (l as f64 + 1.0));
            }
        }
        for x in [0.3f64, 8.0, 100.0, 4096.0] {
            let mut g = [0.0f64; 101];
            gaussian_gains(x, &mut g, f64::INFINITY);
            for l in [0usize, 1, 2, 31, 32, 33, 64, 100] {
                let mut own = [0.0f64; 101];
                gaussian_gains(x, &mut own[..=l], f64::INFINITY);
                assert_eq!(gaussian_gain(x, l).to_bits(), own[l].to_bits(), "x = {x}, l = {l}");
                // A longer array starts its fraction higher: the same value to an ulp or two.
                assert!((gaussian_gain(x, l) - g[l]).abs() <= 1e-15 * g[l], "x = {x}, l = {l}");
            }
        }
        let mut g = [7.0f64; 4];
        gaussian_gains(f64::NAN, &mut g, FORWARD_FROM);
        assert_eq!(g, [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(gaussian_gain(-1.0, 3), 0.0);
    }
}
