//! Pixels cut by a clamped lobe's horizon: exact integrals in φ over the part above it.

use super::*;

/// `∫ max(0, t)ᴾ` over a pixel the horizon crosses, relative to its solid angle: a
/// Gauss–Legendre rule in θ (`sub_rows`: `(a_i, b_i, weight)`), and in φ the exact integral
/// over the part of the pixel where `t = a_i + b_i·cos δ > 0` ([`arc_integral`]).
/// `(c, s)` is `(cos δ, sin δ)` of the pixel centre, `half` its half-width with its
/// `(cos, sin)`. Out of line: it is rare, and inlining it would keep the common path of
/// [`EquirectMap::power_sums`] from being inlined.
#[inline(never)]
pub(super) fn horizon_pixel(
    sub_rows: &[(f64, f64, f64); HORIZON_ORDER],
    centre: (f64, f64),
    half: (f64, (f64, f64)),
    p: u32,
) -> f64 {
    let edges = pixel_edges(centre, half);
    let mut total = 0.0;
    for &(ai, bi, wi) in sub_rows {
        total += wi * arc_integral(ai, bi, p, &edges) / (2.0 * half.0);
    }
    total
}

/// `(δ, (cos δ, sin δ))` of the two azimuth edges of a pixel with centre `(cos δ, sin δ)`
/// and half-width `half` (with its `(cos, sin)`); `δ` of the centre in `(−π, π]`.
pub(super) fn pixel_edges(
    (c, s): (f64, f64),
    (half, (hc, hs)): (f64, (f64, f64)),
) -> [(f64, (f64, f64)); 2] {
    let centre = libm::atan2(s, c);
    [
        (centre - half, (c * hc + s * hs, s * hc - c * hs)),
        (centre + half, (c * hc - s * hs, s * hc + c * hs)),
    ]
}

/// `∫ max(0, a + b·cos δ)ᴾ dδ` over the pixel between `edges`: the arc `|δ| < arccos(−a/b)`
/// where the integrand is positive (and its 2π translates, for pixels at δ = ±π) clipped to
/// the pixel, integrated in closed form by [`power_arc_integral`].
pub(super) fn arc_integral(a: f64, b: f64, p: u32, edges: &[(f64, (f64, f64)); 2]) -> f64 {
    let (end, cos_end) = if b > 0.0 && libm::fabs(a) < b {
        (libm::acos(-a / b), -a / b)
    } else if a > 0.0 {
        (PI, -1.0)
    } else {
        return 0.0;
    };
    let sin_end = libm::sqrt((1.0 - cos_end * cos_end).max(0.0));
    let [first, last] = *edges;
    let mut total = 0.0;
    for shift in [-TAU, 0.0, TAU] {
        let (lo_arc, hi_arc) = (shift - end, shift + end);
        let lo = if first.0 >= lo_arc { first } else { (lo_arc, (cos_end, -sin_end)) };
        let hi = if last.0 <= hi_arc { last } else { (hi_arc, (cos_end, sin_end)) };
        if hi.0 > lo.0 {
            total += power_arc_integral(a, b, p, lo, hi);
        }
    }
    total
}

/// A pixel for [`bright_horizon_pixel`]: its polar band `(θ₀, θ₁)`, the `(cos δ, sin δ)` of
/// its centre's azimuth offset, and its half-width with the half-width's `(cos, sin)`.
type PixelBox = ((f64, f64), (f64, f64), (f64, (f64, f64)));

/// `∫∫ max(0, t)ᴾ sin θ dθ dφ / Δφ` over a pixel the horizon crosses, for pixels bright
/// enough that the kink must be integrated to the last digits: exact in φ ([`arc_integral`])
/// and in θ split where the horizon leaves the pixel through its azimuth edges and where it
/// is tangent to a parallel (θ = |π/2 − θ_d| and π − |π/2 − θ_d|), each piece by an 8-point
/// Gauss–Legendre rule clustered at both ends (θ = θ₀ + (θ₁ − θ₀)(1 − cos τ)/2), which
/// absorbs the square-root behaviour at tangencies. `pixel_box` is the polar band, the
/// centre `(cos δ, sin δ)` and the half-width with its `(cos, sin)`.
#[inline(never)]
pub(super) fn bright_horizon_pixel(d: &Dir, pixel_box: PixelBox, p: u32) -> f64 {
    let ((th0, th1), centre, half) = pixel_box;
    let edges = pixel_edges(centre, half);
    let mut cuts = [th0, th1, th1, th1, th1, th1];
    let mut n = 2;
    let mut push = |x: f64| {
        if x > th0 && x < th1 {
            if let Some(slot) = cuts.get_mut(n) {
                *slot = x;
                n += 1;
            }
        }
    };
    // cos θ_d cos θ + sin θ_d cos δ_e sin θ = 0 at an edge δ_e, with sin θ ≥ 0.
    for (_, (cos_e, _)) in edges {
        let (ca, cb) = (d.cos_theta, d.sin_theta * cos_e);
        push(if ca >= 0.0 { libm::atan2(ca, -cb) } else { libm::atan2(-ca, cb) });
    }
    let extreme = libm::fabs(0.5 * PI - d.theta());
    push(extreme);
    push(PI - extreme);
    // Sort the cuts (at most six).
    let cuts = cuts.get_mut(..n).unwrap_or(&mut []);
    cuts.sort_unstable_by(f64::total_cmp);
    let rule = Rule::gauss_legendre(MAX_ORDER, 1);
    let mut total = 0.0;
    for piece in cuts.windows(2) {
        let [ta, tb] = [piece.first(), piece.get(1)].map(|x| x.copied().unwrap_or(0.0));
        for &(x, w) in rule.nodes() {
            let tau = 0.5 * PI * (x + 1.0);
            let (sin_tau, cos_tau) = libm::sincos(tau);
            let theta = ta + (tb - ta) * 0.5 * (1.0 - cos_tau);
            let jacobian = 0.5 * PI * 0.5 * (tb - ta) * sin_tau;
            let (st, ct) = libm::sincos(theta);
            let (a, b) = (d.cos_theta * ct, d.sin_theta * st);
            total += w * jacobian * st * arc_integral(a, b, p, &edges);
        }
    }
    total / (2.0 * half.0)
}

/// `∫ (a + b·cos δ)ᴾ dδ` from `δ₀` to `δ₁`, given `(δ, (cos δ, sin δ))` of both ends: the
/// binomial expansion over `J_k = ∫ cosᵏ δ dδ`, `J_k = [cosᵏ⁻¹δ·sin δ]/k + (k − 1)/k·J_{k−2}`
/// for `P ≤ 8` (the terms are at most `(|a| + |b|)ᴾ ≤ 16`, so cancellation near the horizon
/// costs at most 16 ulp of the pixel's peak value), else a 4-point Gauss–Legendre rule
/// (there the horizon band is below 10⁻¹³ of the lobe's peak).
pub(super) fn power_arc_integral(
    a: f64,
    b: f64,
    p: u32,
    lo: (f64, (f64, f64)),
    hi: (f64, (f64, f64)),
) -> f64 {
    let (d0, (c0, s0)) = lo;
    let (d1, (c1, s1)) = hi;
    if p > 8 {
        let rule = Rule::gauss_legendre(HORIZON_ORDER, 1);
        let (mid, hw) = (0.5 * (d0 + d1), 0.5 * (d1 - d0));
        return rule
            .nodes()
            .iter()
            .map(|&(x, w)| hw * w * powi((a + b * libm::cos(mid + hw * x)).max(0.0), p))
            .sum();
    }
    // J_k for k = 0..=P, and the binomial sum.
    let mut j = [0.0; 9];
    let (mut pow0, mut pow1) = (1.0, 1.0); // cosᵏ⁻¹ at both ends
    for k in 0..=p as usize {
        let jk = match k {
            0 => d1 - d0,
            1 => s1 - s0,
            _ => {
                let kf = k as f64;
                let prev = j.get(k - 2).copied().unwrap_or(0.0);
                (pow1 * s1 - pow0 * s0) / kf + (kf - 1.0) / kf * prev
            }
        };
        if k >= 1 {
            pow0 *= c0;
            pow1 *= c1;
        }
        if let Some(slot) = j.get_mut(k) {
            *slot = jk;
        }
    }
    let mut total = 0.0;
    let mut binom = 1.0;
    for k in 0..=p {
        let jk = j.get(k as usize).copied().unwrap_or(0.0);
        total += binom * powi(a, p - k) * powi(b, k) * jk;
        binom = binom * f64::from(p - k) / f64::from(k + 1);
    }
    total.max(0.0)
}
