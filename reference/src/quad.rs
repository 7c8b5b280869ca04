//! One-dimensional quadrature: Gauss–Legendre and Gauss–Jacobi rules of any order and
//! adaptive Gauss–Kronrod (7, 15) integration.

use core::f64::consts::PI;

/// Gauss–Legendre nodes and weights on `[-1, 1]`, nodes ascending.
///
/// Exact for polynomials of degree ≤ 2n − 1. Nodes are the roots of the Legendre
/// polynomial P_n, found by Newton's method on the three-term recurrence
/// k P_k = (2k − 1) x P_{k−1} − (k − 1) P_{k−2}, starting from
/// cos(π(i + 3/4)/(n + 1/2)); weights 2/((1 − x²) P_n'(x)²) with
/// P_n'(x) = n (x P_n − P_{n−1})/(x² − 1).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(n >= 1, "gauss_legendre needs at least one node");
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    let eval = |t: f64| -> (f64, f64) {
        // (P_n(t), P_n'(t))
        let (mut p0, mut p1) = (1.0, t);
        for k in 2..=n {
            let k = k as f64;
            let p2 = ((2.0 * k - 1.0) * t * p1 - (k - 1.0) * p0) / k;
            p0 = p1;
            p1 = p2;
        }
        if n == 1 {
            return (t, 1.0);
        }
        let dp = n as f64 * (p0 - t * p1) / ((1.0 - t) * (1.0 + t));
        (p1, dp)
    };
    for i in 0..n.div_ceil(2) {
        let mut t = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (p, dp) = eval(t);
            let dt = p / dp;
            t -= dt;
            if dt.abs() <= 1e-16 {
                break;
            }
        }
        // One more step at convergence for the last bits.
        let (p, dp) = eval(t);
        t -= p / dp;
        let (_, dp) = eval(t);
        let wi = 2.0 / ((1.0 - t) * (1.0 + t) * dp * dp);
        // i = 0 is the largest root.
        x[n - 1 - i] = t;
        w[n - 1 - i] = wi;
        x[i] = -t;
        w[i] = wi;
    }
    if n % 2 == 1 {
        x[n / 2] = 0.0;
    }
    (x, w)
}

/// Gauss–Legendre nodes and weights mapped to `[a, b]`, nodes ascending.
pub fn gauss_legendre_on(n: usize, a: f64, b: f64) -> (Vec<f64>, Vec<f64>) {
    let (x, w) = gauss_legendre(n);
    let h = 0.5 * (b - a);
    let c = 0.5 * (a + b);
    (x.iter().map(|&t| c + h * t).collect(), w.iter().map(|&v| v * h).collect())
}

/// `2π∫₀^top sin θ·f(cos θ) dθ`: the integral over the sphere (up to the polar angle `top`)
/// of a function of the polar cosine, by `panels` equal panels of 20-point Gauss–Legendre
/// in `θ` (for integrands smooth on `[0, top]`: put a kink at `top`).
pub fn zonal_gl(top: f64, panels: usize, f: impl Fn(f64) -> f64) -> f64 {
    let mut sum = 0.0;
    for k in 0..panels {
        let (a, b) = (top * k as f64 / panels as f64, top * (k + 1) as f64 / panels as f64);
        let (ths, ws) = gauss_legendre_on(20, a, b);
        for (th, w) in ths.iter().zip(&ws) {
            sum += w * th.sin() * f(th.cos());
        }
    }
    2.0 * std::f64::consts::PI * sum
}

/// Gauss–Jacobi rule for `∫₀¹ u^e g(u) du` (any real `e > −1`), returned in the
/// variable `s = 1 − u` so that nodes next to `u = 1` keep full relative precision:
/// `∫₀¹ u^e g(u) du ≈ Σ w_i g(1 − s_i)`. The weights sum to `1/(e + 1)`; the rule is
/// exact when `g` is a polynomial of degree ≤ 2n − 1.
///
/// The measure (1 − s)^e ds on [0, 1] is the Jacobi weight (1 − x)^α (1 + x)^β with
/// α = e, β = 0 under s = (1 + x)/2. Its monic recurrence
/// p_{k+1} = (s − a_k) p_k − b_k p_{k−1} has (in s)
/// a_k = (2k² + 2kα + 2k + α)/((2k + α)(2k + α + 2))  (a_0 = 1/(α + 2)) and
/// b_k = k²(k + α)²/((2k + α)²(2k + α + 1)(2k + α − 1)).
/// The nodes are the eigenvalues of the Jacobi matrix (diagonal a_k, off-diagonal
/// √b_k), located by Sturm-sequence bisection and polished by Newton's method on the
/// orthonormal recurrence; the weights are the Christoffel numbers
/// μ₀ / Σ_k p̂_k(s_i)², with μ₀ = 1/(e + 1) and p̂_k orthonormal.
pub fn gauss_jacobi_unit(n: usize, e: f64) -> (Vec<f64>, Vec<f64>) {
    assert!(n >= 1, "gauss_jacobi_unit needs at least one node");
    assert!(e > -1.0 && e.is_finite(), "exponent must be finite and > -1");
    let al = e;
    let mut a = vec![0.0; n];
    let mut sb = vec![0.0; n]; // sb[k] = √b_k, sb[0] unused
    for (k, ak) in a.iter_mut().enumerate() {
        let kf = k as f64;
        *ak = if k == 0 {
            1.0 / (al + 2.0)
        } else {
            (2.0 * kf * kf + 2.0 * kf * al + 2.0 * kf + al)
                / ((2.0 * kf + al) * (2.0 * kf + al + 2.0))
        };
    }
    for (k, s) in sb.iter_mut().enumerate().skip(1) {
        let kf = k as f64;
        let t = 2.0 * kf + al;
        let b = kf * kf * (kf + al) * (kf + al) / (t * t * (t + 1.0) * (t - 1.0));
        *s = b.sqrt();
    }
    // Number of eigenvalues < x (Sturm count via the LDLᵀ pivots of T − xI).
    let count_below = |x: f64| -> usize {
        let mut c = 0;
        let mut q = a[0] - x;
        if q < 0.0 {
            c += 1;
        }
        for k in 1..n {
            let qq = if q == 0.0 { f64::MIN_POSITIVE } else { q };
            q = a[k] - x - sb[k] * sb[k] / qq;
            if q < 0.0 {
                c += 1;
            }
        }
        c
    };
    // Orthonormal polynomials: returns (p̂_n(x), p̂_n'(x), Σ_{k<n} p̂_k(x)²), with
    // √b_{k+1} p̂_{k+1} = (x − a_k) p̂_k − √b_k p̂_{k−1} and √b_n := 1 for the last step
    // (only the root location and sign matter there).
    let eval = |x: f64| -> (f64, f64, f64) {
        let (mut pm, mut p) = (0.0, 1.0);
        let (mut dm, mut d) = (0.0, 0.0);
        let mut sum = 0.0;
        for k in 0..n {
            sum += p * p;
            let next_sb = if k + 1 < n { sb[k + 1] } else { 1.0 };
            let pn = ((x - a[k]) * p - sb[k] * pm) / next_sb;
            let dn = (p + (x - a[k]) * d - sb[k] * dm) / next_sb;
            pm = p;
            p = pn;
            dm = d;
            d = dn;
        }
        (p, d, sum)
    };
    let mut s = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        // i-th smallest eigenvalue: smallest x with count_below(x) > i.
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..2000 {
            // Halve towards 0 first, then geometric steps, then plain bisection, so
            // that tiny eigenvalues are found to full relative precision.
            let mid = if lo == 0.0 {
                0.5 * hi
            } else if hi / lo > 4.0 {
                (lo * hi).sqrt()
            } else {
                0.5 * (lo + hi)
            };
            if mid <= lo || mid >= hi {
                break;
            }
            if count_below(mid) > i {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let mut x = 0.5 * (lo + hi);
        for _ in 0..3 {
            let (p, d, _) = eval(x);
            if d == 0.0 {
                break;
            }
            let step = p / d;
            // Polish only: a large step would mean a failed bisection, keep that root.
            if step.abs() <= 1e-8 * x {
                x -= step;
            }
        }
        let (_, _, sum) = eval(x);
        s[i] = x;
        w[i] = 1.0 / ((e + 1.0) * sum);
    }
    (s, w)
}

/// Result of an adaptive integration.
#[derive(Clone, Copy, Debug)]
pub struct Integral {
    /// Estimate of the integral.
    pub value: f64,
    /// Estimated absolute error (sum over panels of |K15 − G7|, conservative for
    /// smooth integrands).
    pub error: f64,
    /// Number of integrand evaluations.
    pub evaluations: usize,
}

// Gauss–Kronrod (7, 15) abscissae (non-negative half, descending) and weights: the
// classical QUADPACK values. `quad` tests check the exactness degrees (G7: 13, K15: 22)
// and the Gauss nodes against `gauss_legendre(7)`.
#[allow(clippy::excessive_precision)] // the published digits, rounded by the compiler
const XGK: [f64; 8] = [
    0.991_455_371_120_812_639_206_854_697_526_329,
    0.949_107_912_342_758_524_526_189_684_047_851,
    0.864_864_423_359_769_072_789_712_788_640_926,
    0.741_531_185_599_394_439_863_864_773_280_788,
    0.586_087_235_467_691_130_294_144_845_693_013,
    0.405_845_151_377_397_166_906_606_412_076_961,
    0.207_784_955_007_898_467_600_689_403_773_245,
    0.0,
];
#[allow(clippy::excessive_precision)] // the published digits, rounded by the compiler
const WGK: [f64; 8] = [
    0.022_935_322_010_529_224_963_732_008_058_970,
    0.063_092_092_629_978_553_290_700_663_189_204,
    0.104_790_010_322_250_183_839_876_322_541_518,
    0.140_653_259_715_525_918_745_189_590_510_238,
    0.169_004_726_639_267_902_826_583_426_598_550,
    0.190_350_578_064_785_409_913_256_402_421_014,
    0.204_432_940_075_298_892_414_161_999_234_649,
    0.209_482_141_084_727_828_012_999_174_891_714,
];
// Gauss weights for XGK[1], XGK[3], XGK[5], XGK[7].
#[allow(clippy::excessive_precision)] // the published digits, rounded by the compiler
const WG: [f64; 4] = [
    0.129_484_966_168_869_693_270_611_432_679_082,
    0.279_705_391_489_276_667_901_467_771_423_780,
    0.381_830_050_505_118_944_950_369_775_488_975,
    0.417_959_183_673_469_387_755_102_040_816_327,
];

/// One Gauss–Kronrod (7, 15) panel on `[a, b]`: `(K15 estimate, G7 estimate)`.
pub fn gk15(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut k = WGK[7] * fc;
    let mut g = WG[3] * fc;
    for j in 0..7 {
        let dx = h * XGK[j];
        let s = f(c - dx) + f(c + dx);
        k += WGK[j] * s;
        if j % 2 == 1 {
            g += WG[j / 2] * s;
        }
    }
    (k * h, g * h)
}

/// Globally adaptive Gauss–Kronrod (7, 15) integration of `f` over `[a, b]`.
///
/// The panel with the largest error estimate |K15 − G7| is bisected until the total
/// estimate is ≤ max(`abs_tol`, `rel_tol`·|value|), or 5000 panels were used, or panels
/// became too narrow to split. For smooth integrands the true error of the K15 sums is
/// far below the reported estimate.
pub fn integrate(
    mut f: impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    abs_tol: f64,
    rel_tol: f64,
) -> Integral {
    if a == b {
        return Integral { value: 0.0, error: 0.0, evaluations: 0 };
    }
    // (a, b, value, error)
    let mut panels: Vec<(f64, f64, f64, f64)> = Vec::new();
    let (k, g) = gk15(&mut f, a, b);
    panels.push((a, b, k, (k - g).abs()));
    let mut evaluations = 15;
    loop {
        let value: f64 = panels.iter().map(|p| p.2).sum();
        let error: f64 = panels.iter().map(|p| p.3).sum();
        if error <= abs_tol.max(rel_tol * value.abs()) || panels.len() >= 5000 {
            return Integral { value, error, evaluations };
        }
        let (idx, _) =
            panels
                .iter()
                .enumerate()
                .fold((0, -1.0), |best, (i, p)| if p.3 > best.1 { (i, p.3) } else { best });
        let (pa, pb, _, perr) = panels[idx];
        let m = 0.5 * (pa + pb);
        if m <= pa.min(pb) || m >= pa.max(pb) || perr == 0.0 {
            return Integral { value, error, evaluations };
        }
        let (k1, g1) = gk15(&mut f, pa, m);
        let (k2, g2) = gk15(&mut f, m, pb);
        evaluations += 30;
        panels[idx] = (pa, m, k1, (k1 - g1).abs());
        panels.push((m, pb, k2, (k2 - g2).abs()));
    }
}

/// [`integrate`] over consecutive sub-intervals split at the sorted `breaks`
/// (points outside `(a, b)` are ignored), each to the same tolerances.
pub fn integrate_with_breaks(
    mut f: impl FnMut(f64) -> f64,
    a: f64,
    b: f64,
    breaks: &[f64],
    abs_tol: f64,
    rel_tol: f64,
) -> Integral {
    let mut pts = vec![a];
    let mut inner: Vec<f64> = breaks.iter().copied().filter(|&x| x > a && x < b).collect();
    inner.sort_by(|x, y| x.partial_cmp(y).unwrap());
    pts.extend(inner);
    pts.push(b);
    let mut out = Integral { value: 0.0, error: 0.0, evaluations: 0 };
    for w in pts.windows(2) {
        if w[1] > w[0] {
            let r = integrate(&mut f, w[0], w[1], abs_tol, rel_tol);
            out.value += r.value;
            out.error += r.error;
            out.evaluations += r.evaluations;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫_{-1}^{1} x^k dx
    fn moment(k: u32) -> f64 {
        if k % 2 == 1 {
            0.0
        } else {
            2.0 / (k as f64 + 1.0)
        }
    }

    #[test]
    fn gauss_legendre_is_exact_to_degree_2n_minus_1() {
        for n in [1usize, 2, 3, 5, 8, 16, 20, 33, 64, 100] {
            let (x, w) = gauss_legendre(n);
            assert!(x.windows(2).all(|p| p[0] < p[1]));
            let wsum: f64 = w.iter().sum();
            assert!((wsum - 2.0).abs() < 1e-14, "n={n} sum {wsum}");
            for k in 0..(2 * n as u32) {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k as i32)).sum();
                assert!((q - moment(k)).abs() < 2e-15 * (n as f64), "n={n} k={k}: {q}");
            }
            // Degree 2n is not integrated exactly (sanity check that the test can fail).
            if n > 8 {
                continue;
            }
            let k = 2 * n as i32;
            let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k)).sum();
            assert!((q - moment(k as u32)).abs() > 1e-6 * moment(k as u32));
        }
    }

    #[test]
    fn gauss_legendre_on_interval() {
        let (x, w) = gauss_legendre_on(12, 0.0, 1.0);
        let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(23)).sum();
        assert!((q - 1.0 / 24.0).abs() < 1e-16);
        let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.exp()).sum();
        assert!((q - (1f64.exp() - 1.0)).abs() < 1e-15);
    }

    #[test]
    fn gauss_jacobi_is_exact_for_weighted_polynomials() {
        for e in [0.0, 0.5, 1.0, 2.0, 7.3, 10.0, 100.0, 1000.0, 20000.0] {
            for n in [1usize, 2, 5, 12, 24, 40] {
                let (s, w) = gauss_jacobi_unit(n, e);
                assert!(s.windows(2).all(|p| p[0] < p[1]), "e={e} n={n}");
                assert!(s[0] > 0.0 && s[n - 1] < 1.0);
                for m in 0..(2 * n as i32) {
                    // ∫₀¹ u^e u^m du = 1/(e + m + 1)
                    let q: f64 = s.iter().zip(&w).map(|(s, w)| w * (1.0 - s).powi(m)).sum();
                    let want = 1.0 / (e + m as f64 + 1.0);
                    assert!((q / want - 1.0).abs() < 1e-13, "e={e} n={n} m={m}: {q} vs {want}");
                    // ∫₀¹ u^e s^m du, s = 1 − u: Beta(e+1, m+1); checks the small-s nodes.
                    let q: f64 = s.iter().zip(&w).map(|(s, w)| w * s.powi(m)).sum();
                    let mut want = 1.0 / (e + 1.0);
                    for j in 1..=m {
                        want *= j as f64 / (e + 1.0 + j as f64);
                    }
                    assert!((q / want - 1.0).abs() < 1e-12, "e={e} n={n} m={m}: {q} vs {want}");
                }
            }
        }
        // e = 0 is Gauss–Legendre on [0, 1].
        let (s, w) = gauss_jacobi_unit(9, 0.0);
        let (x, v) = gauss_legendre_on(9, 0.0, 1.0);
        for i in 0..9 {
            assert!((s[i] - x[i]).abs() < 1e-15 && (w[i] - v[i]).abs() < 1e-15);
        }
    }

    #[test]
    fn kronrod_rule_exactness_and_gauss_nodes() {
        let (x7, w7) = gauss_legendre(7);
        for j in 0..4 {
            assert!((XGK[2 * j + 1] + x7[j]).abs() < 1e-15);
            assert!((WG[j] - w7[j]).abs() < 1e-15);
        }
        for k in 0..=22u32 {
            let mut f = |x: f64| x.powi(k as i32);
            let (kq, gq) = gk15(&mut f, -1.0, 1.0);
            assert!((kq - moment(k)).abs() < 1e-15, "K15 degree {k}");
            if k <= 13 {
                assert!((gq - moment(k)).abs() < 1e-15, "G7 degree {k}");
            }
        }
        let mut f = |x: f64| x.powi(24);
        let (kq, _) = gk15(&mut f, -1.0, 1.0);
        assert!((kq - moment(24)).abs() > 1e-9);
    }

    #[test]
    fn adaptive_integration() {
        let r = integrate(|x: f64| x.sqrt(), 0.0, 1.0, 0.0, 1e-13);
        assert!((r.value - 2.0 / 3.0).abs() < 1e-13, "{r:?}");
        let r = integrate(|x: f64| 1.0 / (1e-4 + x * x), -1.0, 1.0, 0.0, 1e-13);
        let want = 2.0 * (1.0f64 / 1e-2).atan() / 1e-2;
        assert!((r.value / want - 1.0).abs() < 1e-13, "{r:?}");
        let r = integrate_with_breaks(|x: f64| (x - 0.3).abs(), 0.0, 1.0, &[0.3], 0.0, 1e-14);
        assert!((r.value - (0.045 + 0.245)).abs() < 1e-15, "{r:?}");
        let r = integrate(|x: f64| x.cos(), 1.0, 0.0, 0.0, 1e-14);
        assert!((r.value + 1f64.sin()).abs() < 1e-15);
    }
}
