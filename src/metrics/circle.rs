//! The circle (S¹) view of sampling and integration (seed, "Fourier series view of
//! integration", "Frequency domain view for uniform sampling", "Integration and sampling
//! theorem").
//!
//! For a 2π-periodic `f(x) = Σₙ aₙ e^{inx}` and a pattern `{x_k}` of K samples, the
//! estimate `(1/K) Σₖ f(x_k) = Σₙ aₙ cₙ` with `cₙ = (1/K) Σₖ e^{inx_k}`, while the mean over
//! `[−a/2, a/2]` is `Σₙ aₙ sinc(na/2)`. The seed's uniform pattern
//! `x_k = ka/K + (a/2)(1−K)/K` has `cₙ = sinc(na/2)/sinc(na/(2K)) = sin(na/2)/(K sin(na/(2K)))`;
//! at `a = 2π` that is 0 for `0 < |n| < K`, so every trigonometric polynomial of degree
//! `< K` is integrated exactly, and `c_{mK} = (−1)^{m(K−1)}`: the seed's "`cₙ = 1` if
//! `n = mK`" holds for odd `K` (or even `m`); for even `K` the centred pattern gives
//! `c_K = −1`.

use core::f64::consts::PI;
use core::num::NonZeroU128;

use crate::error::Error;
use crate::math;

/// `cₙ = (1/K) Σₖ e^{inx_k}` of a sampling pattern, as `(re, im)`. O(K); `n·x_k` is formed
/// in f64, so the result loses about `|n·x_k|·10⁻¹⁶` absolute.
///
/// # Errors
/// [`Error::LengthMismatch`] when `xs` is empty.
///
/// # Examples
/// ```
/// use sphere_quadrature::metrics::{circle_coefficient, uniform_circle_nodes};
///
/// // K = 8 uniform samples of the full circle cancel every frequency 0 < |n| < 8.
/// let mut xs = [0.0f64; 8];
/// uniform_circle_nodes(core::f64::consts::TAU, &mut xs)?;
/// let (re, im) = circle_coefficient(&xs, 3)?;
/// assert!(re.abs() < 1e-12 && im.abs() < 1e-12);
/// assert!((circle_coefficient(&xs, 0)?.0 - 1.0).abs() < 1e-12);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
pub fn circle_coefficient(xs: &[f64], n: i64) -> Result<(f64, f64), Error> {
    if xs.is_empty() {
        return Err(Error::LengthMismatch);
    }
    let nf = n as f64;
    let (mut re, mut im) = (0.0, 0.0);
    for &x in xs {
        re += math::cos64(nf * x);
        im += math::sin64(nf * x);
    }
    let k = xs.len() as f64;
    Ok((re / k, im / k))
}

/// Writes the seed's uniform pattern on `[−a/2, a/2]`, `x_k = ka/K + (a/2)(1−K)/K`
/// (the midpoints of K equal cells), into `out` (`K = out.len()`).
///
/// # Errors
/// [`Error::LengthMismatch`] when `out` is empty; [`Error::NonFinite`] for a
/// non-finite `a`.
///
/// # Examples
/// ```
/// use sphere_quadrature::metrics::uniform_circle_nodes;
///
/// // Midpoints of 4 equal cells of [−1, 1]: symmetric about 0, spaced by a/K.
/// let mut xs = [0.0f64; 4];
/// uniform_circle_nodes(2.0, &mut xs)?;
/// assert!((xs[0] + xs[3]).abs() < 1e-15 && (xs[1] - xs[0] - 0.5).abs() < 1e-15);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
pub fn uniform_circle_nodes(a: f64, out: &mut [f64]) -> Result<(), Error> {
    if out.is_empty() {
        return Err(Error::LengthMismatch);
    }
    if !a.is_finite() {
        return Err(Error::NonFinite);
    }
    let k = out.len() as f64;
    let h = 0.5 * (k - 1.0);
    for (i, x) in out.iter_mut().enumerate() {
        *x = a * ((i as f64 - h) / k);
    }
    Ok(())
}

/// The closed form of `cₙ` for the uniform pattern of K samples on `[−a/2, a/2]`:
/// `sinc(na/2)/sinc(na/(2K))`, `sinc x = sin x / x` (real: the pattern is symmetric).
///
/// Evaluated as the Dirichlet kernel `sin(Kθ)/(K sin θ)`, `θ = na/(2K)`, after reducing
/// `θ = mπ + r`, `|r| ≤ π/2`, which gives `(−1)^{m(K−1)} sin(Kr)/(K sin r)` and the exact
/// limit `(−1)^{m(K−1)}` on the aliases `r = 0`. Matches [`circle_coefficient`] of
/// [`uniform_circle_nodes`] to 10⁻¹³ (`tests/points/metrics.rs`).
///
/// Any `n` and any finite `a` give a value in `[−1, 1]`, never NaN. `n`, `K` and `a` are taken
/// as the exact numbers they are: where `|n·a/2| < 2²⁰`, θ is formed in f64 (its rounding
/// costs at most about `|n·a|·10⁻¹⁶` absolute, below 10⁻⁹ there); from `2²⁰` on, the phase
/// `n·a/2` is reduced exactly modulo `2πK` (an integer product with 1280 bits of `1/π`, as
/// `libm` reduces the argument of `sin`), so even where `n·a` is far beyond f64
/// (`n = 2⁶³`, `a = 10³⁰⁰`) the result is the coefficient of those exact inputs to about
/// 10⁻¹⁵. Whether such a coefficient means anything for an `a` that carries rounding is the
/// caller's question: a relative error δ in `a` moves the phase by `|n·a|·δ/2`.
///
/// # Errors
/// [`Error::InvalidSize`] when `k = 0`; [`Error::NonFinite`] for a non-finite `a`.
///
/// # Examples
/// ```
/// use sphere_quadrature::metrics::{circle_coefficient, uniform_circle_coefficient, uniform_circle_nodes};
///
/// // The closed form agrees with the sum over the pattern's nodes.
/// let (k, a) = (6, 1.3);
/// let mut xs = [0.0f64; 6];
/// uniform_circle_nodes(a, &mut xs)?;
/// for n in [1, 5, 6, 7] {
///     let closed = uniform_circle_coefficient(n, k, a)?;
///     assert!((closed - circle_coefficient(&xs, n)?.0).abs() < 1e-12);
/// }
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
pub fn uniform_circle_coefficient(n: i64, k: usize, a: f64) -> Result<f64, Error> {
    if k == 0 {
        return Err(Error::InvalidSize);
    }
    if !a.is_finite() {
        return Err(Error::NonFinite);
    }
    if 0.5 * (n as f64).abs() * a.abs() >= EXACT_REDUCTION_FROM {
        // c is even in θ: the phase's magnitude is enough.
        return Ok(dirichlet_reduced(n.unsigned_abs(), k, a.abs()));
    }
    let kf = k as f64;
    let theta = n as f64 * a / (2.0 * kf);
    let m = math::round64(theta / PI);
    let r = theta - m * PI;
    // (−1)^{m(K−1)}: negative when m is odd and K is even.
    let m_odd = math::floor64(0.5 * m) * 2.0 != m;
    let sign = if m_odd && k % 2 == 0 { -1.0 } else { 1.0 };
    if r == 0.0 {
        return Ok(sign);
    }
    Ok(sign * math::sin64(kf * r) / (kf * math::sin64(r)))
}

/// `|n·a/2|` from which [`uniform_circle_coefficient`] reduces the phase exactly (2²⁰).
const EXACT_REDUCTION_FROM: f64 = 1_048_576.0;

/// `⌊2¹²⁸⁰/π⌋` as 20 little-endian 64-bit limbs (1279 bits).
const INV_PI_2_1280: [u64; 20] = [
    0xf867_de10_4d7a_1b0e,
    0x2b01_9823_7e3d_b5d5,
    0x35fd_afd8_8fc6_ae84,
    0x9e83_9cfb_c529_4975,
    0xba93_dd63_f5f2_f8bd,
    0xa7a3_1fb3_4f2f_f516,
    0xb69b_3f67_93e5_84db,
    0xf797_88c5_ad05_368f,
    0x8ffc_4bff_ef02_cc07,
    0x4e42_2fc5_defc_941d,
    0x9cc8_eb1c_c1a9_9cfa,
    0x74ce_3813_5a2f_bf20,
    0x7441_1afa_975d_a242,
    0x7f0e_f58e_5894_d39f,
    0x0324_9775_04e8_c90e,
    0xdb92_371d_2126_e970,
    0xff28_b1d5_ef5d_e2b0,
    0x6db1_4acc_9e21_c820,
    0xfe13_abe8_fa9a_6ee0,
    0x517c_c1b7_2722_0a94,
];

/// The 64 bits of the little-endian integer `p` from bit `pos` up (zeros beyond its end).
fn bits_at(p: &[u64], pos: usize) -> u64 {
    let (q, r) = (pos / 64, pos % 64);
    let lo = p.get(q).copied().unwrap_or(0) >> r;
    let hi = if r == 0 { 0 } else { p.get(q + 1).copied().unwrap_or(0) << (64 - r) };
    lo | hi
}

/// [`uniform_circle_coefficient`] for `n ≥ 0`, `k ≥ 1`, finite `a ≥ 0` with `n·a/2 ≥ 2²⁰`,
/// with the phase `φ = n·a/2` reduced exactly.
///
/// `a = M·2^e` (`M < 2⁵³`), so `φ/π = nM·2^(e−1)/π ≈ P/2^v` with the integer
/// `P = nM·⌊2¹²⁸⁰/π⌋` and `v = 1281 − e` (`310 ≤ v ≤ 1376` here: `e ≤ 971`, and `nM < 2¹¹⁶`
/// with `φ ≥ 2²⁰`); the truncated `1/π` costs below `2⁻¹⁹⁰` of a unit. The integer part of
/// `φ/π` modulo `2K` and 128 bits of its fraction give `φ/π ≡ j + h (mod 2K)`,
/// `h ∈ [−½, ½]`, and then `sin(Kθ) = sin φ = (−1)^j sin(πh)` and, with the multiple
/// `mK` of `K` nearest `j` and `x = j − mK + h`, `sin θ = (−1)^m sin(πx/K)`: both to full
/// relative precision, also next to the aliases.
fn dirichlet_reduced(n: u64, k: usize, a: f64) -> f64 {
    let kk = k as u128;
    let Some(m2) = NonZeroU128::new(2 * kk) else { return 1.0 }; // (k ≥ 1)
    let bits = a.to_bits();
    let biased = ((bits >> 52) & 0x7ff) as i32;
    let fraction = bits & ((1 << 52) - 1);
    let (mantissa, e) =
        if biased == 0 { (fraction, -1074) } else { (fraction | 1 << 52, biased - 1075) };
    let nm = u128::from(n) * u128::from(mantissa);
    // P = nM·T, schoolbook over 64-bit limbs (23 limbs hold 116 + 1279 bits).
    let mut p = [0u64; 23];
    for (j, nj) in [nm as u64, (nm >> 64) as u64].into_iter().enumerate() {
        let mut carry = 0u128;
        for (i, &t) in INV_PI_2_1280.iter().enumerate() {
            let cur = u128::from(p[i + j]) + u128::from(nj) * u128::from(t) + carry;
            p[i + j] = cur as u64;
            carry = cur >> 64;
        }
        p[INV_PI_2_1280.len() + j] = carry as u64;
    }
    let v = (1281 - e).clamp(128, 23 * 64) as usize;
    // The integer part of φ/π modulo 2K, 32 bits at a time from the top (rem < 2K ≤ 2⁶⁵).
    let mut j = 0u128;
    let chunks = (23 * 64 - v).div_ceil(32);
    for c in (0..chunks).rev() {
        j = ((j << 32) | u128::from(bits_at(&p, v + 32 * c) & 0xffff_ffff)) % m2;
    }
    // The fraction, rounded to the nearest integer: h ∈ [−½, ½].
    let frac = u128::from(bits_at(&p, v - 128)) | u128::from(bits_at(&p, v - 64)) << 64;
    const TWO_M128: f64 = 1.0 / 340_282_366_920_938_463_463_374_607_431_768_211_456.0;
    let h = if frac >> 127 == 1 {
        j = (j + 1) % m2;
        -(frac.wrapping_neg() as f64) * TWO_M128
    } else {
        frac as f64 * TWO_M128
    };
    let m = if 2 * j < kk {
        0
    } else if 2 * j < 3 * kk {
        1
    } else {
        2
    };
    let x = (j as i128 - (m * kk) as i128) as f64 + h;
    if x == 0.0 {
        // The alias limit (−1)^{m(K−1)}.
        return if m == 1 && k % 2 == 0 { -1.0 } else { 1.0 };
    }
    let kf = k as f64;
    let sign = if (j + m) % 2 == 1 { -1.0 } else { 1.0 };
    sign * math::sin64(PI * h) / (kf * math::sin64(PI * x / kf))
}

/// The circle analogue of [`super::design_strength`]: the largest `N ≤ n_max` with
/// `|cₙ| ≤ tol` for every `0 < n ≤ N` (then every trigonometric polynomial of degree `≤ N`
/// is integrated to within `tol·Σ|aₙ|`). The uniform pattern on the full circle has
/// strength `K − 1`. O(K·n_max).
///
/// # Errors
/// [`Error::LengthMismatch`] when `xs` is empty; [`Error::InvalidTolerance`] for a negative or
/// NaN `tol`.
///
/// # Examples
/// ```
/// use sphere_quadrature::metrics::{circle_strength, uniform_circle_nodes};
///
/// // The uniform pattern of K points on the full circle has strength K − 1.
/// let mut xs = [0.0f64; 10];
/// uniform_circle_nodes(core::f64::consts::TAU, &mut xs)?;
/// assert_eq!(circle_strength(&xs, 1e-9, 50)?, 9);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
pub fn circle_strength(xs: &[f64], tol: f64, n_max: usize) -> Result<usize, Error> {
    if tol.is_nan() || tol < 0.0 {
        return Err(Error::InvalidTolerance);
    }
    for n in 1..=n_max {
        let (re, im) = circle_coefficient(xs, n as i64)?;
        let size = math::sqrt64(re * re + im * im);
        if size.is_nan() || size > tol {
            return Ok(n - 1);
        }
    }
    if xs.is_empty() {
        return Err(Error::LengthMismatch);
    }
    Ok(n_max)
}
