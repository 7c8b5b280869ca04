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
/// [`Error::LengthMismatch`] when `out` is empty; [`Error::InvalidParameter`] for a
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
        return Err(Error::InvalidParameter);
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
/// [`uniform_circle_nodes`] to 10⁻¹³ (`tests/metrics.rs`).
///
/// # Errors
/// [`Error::InvalidSize`] when `k = 0`; [`Error::InvalidParameter`] for a non-finite `a`.
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
        return Err(Error::InvalidParameter);
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

/// The circle analogue of [`super::design_strength`]: the largest `N ≤ n_max` with
/// `|cₙ| ≤ tol` for every `0 < n ≤ N` (then every trigonometric polynomial of degree `≤ N`
/// is integrated to within `tol·Σ|aₙ|`). The uniform pattern on the full circle has
/// strength `K − 1`. O(K·n_max).
///
/// # Errors
/// [`Error::LengthMismatch`] when `xs` is empty; [`Error::InvalidParameter`] for a negative or
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
        return Err(Error::InvalidParameter);
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
