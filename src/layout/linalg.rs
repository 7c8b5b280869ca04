//! The layout probe's linear algebra in f32: the symmetric eigendecomposition (`const`, for
//! compile-time tables), LDLᵀ solves and products of many factors.

use super::absolute;
use crate::math;

/// In-place `LDLᵀ` factor of a symmetric positive-definite matrix (its lower triangle, by
/// rows): `L` unit lower triangular below the diagonal, `D` on it; the reciprocals of `D` in
/// `inverse`. No square roots, one division per row. `false` if it is not positive definite
/// in f32.
pub(super) fn ldl<const K: usize>(a: &mut [[f32; K]; K], inverse: &mut [f32; K]) -> bool {
    let mut w = [0.0f32; K];
    for j in 0..K {
        // w_k = L_jk·d_k.
        let mut d = a[j][j];
        for k in 0..j {
            w[k] = a[j][k] * a[k][k];
            d -= a[j][k] * w[k];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        a[j][j] = d;
        let r = 1.0 / d;
        inverse[j] = r;
        for i in j + 1..K {
            let mut x = a[i][j];
            for k in 0..j {
                x -= a[i][k] * w[k];
            }
            a[i][j] = x * r;
        }
    }
    true
}

/// `(LDLᵀ)⁻¹b` for the factor of [`ldl`].
pub(super) fn ldl_solve<const K: usize>(
    a: &[[f32; K]; K],
    inverse: &[f32; K],
    b: &[f32; K],
) -> [f32; K] {
    let mut x = *b;
    for i in 0..K {
        let mut v = x[i];
        for k in 0..i {
            v -= a[i][k] * x[k];
        }
        x[i] = v;
    }
    for i in 0..K {
        x[i] *= inverse[i];
    }
    for i in (0..K).rev() {
        let xi = x[i];
        for k in 0..i {
            x[k] -= a[i][k] * xi;
        }
    }
    x
}

/// `x` refined once: `x + (LDLᵀ)⁻¹(b − Ax)` for `A = s·C + diag(ν)` (`C` symmetric, full) and
/// its factor from [`ldl`], the residual summed in compensated arithmetic (each product's
/// rounding error recovered exactly by Veltkamp's split, each sum's by Knuth's two-sum), as if
/// in twice the precision. The f32 factor of a system of condition `κ` leaves an error of
/// `κ·ε` in `x`; one such step leaves about `(κ·ε)²`.
pub(super) fn refine<const K: usize>(
    c: &[[f32; K]; K],
    s: f32,
    nu: &[f32; K],
    factor: (&[[f32; K]; K], &[f32; K]),
    b: &[f32; K],
    x: &[f32; K],
) -> [f32; K] {
    // Each x_k split once: x = hi + lo, hi with 12 significant bits.
    let parts: [(f32, f32); K] = core::array::from_fn(|k| veltkamp(-x[k]));
    let mut r = [0.0f32; K];
    for i in 0..K {
        // b − ν_i·x_i − Σ_k (s·C_ik)·x_k, the products s·C_ik rounded as the factor's are.
        let (mut sum, mut err) = two_product(nu[i], -x[i], parts[i]);
        let (t, te) = two_sum(b[i], sum);
        (sum, err) = (t, err + te);
        for k in 0..K {
            let (p, pe) = two_product(s * c[i][k], -x[k], parts[k]);
            let (t, te) = two_sum(sum, p);
            sum = t;
            err += te + pe;
        }
        r[i] = sum + err;
    }
    let d = ldl_solve(factor.0, factor.1, &r);
    core::array::from_fn(|i| x[i] + d[i])
}

/// `a + b` and its rounding error (Knuth).
fn two_sum(a: f32, b: f32) -> (f32, f32) {
    let s = a + b;
    let v = s - a;
    (s, (a - (s - v)) + (b - v))
}

/// `x = hi + lo` with `hi` of 12 significant bits (Veltkamp's split at 2¹² + 1).
fn veltkamp(x: f32) -> (f32, f32) {
    let c = 4097.0 * x;
    let hi = c - (c - x);
    (hi, x - hi)
}

/// `a·b` and its rounding error (Dekker), `b`'s split given; exact for products within the
/// normal range.
fn two_product(a: f32, b: f32, (bh, bl): (f32, f32)) -> (f32, f32) {
    let p = a * b;
    let (ah, al) = veltkamp(a);
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

/// `Vᵀx` for the eigenvector columns `V`.
pub(super) const fn project<const K: usize>(v: &[[f32; K]; K], x: &[f32; K]) -> [f32; K] {
    let mut out = [0.0f32; K];
    let mut i = 0;
    while i < K {
        let mut j = 0;
        while j < K {
            out[j] += v[i][j] * x[i];
            j += 1;
        }
        i += 1;
    }
    out
}

/// `AB`, row by row in the order `Σ_k a_ik·b_kj` (the order [`congruence`] and
/// [`congruence_diagonal`] share, so that their diagonals agree bit for bit).
const fn product<const K: usize>(a: &[[f32; K]; K], b: &[[f32; K]; K]) -> [[f32; K]; K] {
    let mut out = [[0.0f32; K]; K];
    let mut i = 0;
    while i < K {
        let mut k = 0;
        while k < K {
            let aik = a[i][k];
            let mut j = 0;
            while j < K {
                out[i][j] += aik * b[k][j];
                j += 1;
            }
            k += 1;
        }
        i += 1;
    }
    out
}

/// `VᵀAV`.
pub(super) const fn congruence<const K: usize>(
    v: &[[f32; K]; K],
    a: &[[f32; K]; K],
) -> [[f32; K]; K] {
    // AV first, then Vᵀ(AV).
    let av = product(a, v);
    let mut out = [[0.0f32; K]; K];
    let mut i = 0;
    while i < K {
        let mut a_ = 0;
        while a_ < K {
            let via = v[i][a_];
            let mut b = 0;
            while b < K {
                out[a_][b] += via * av[i][b];
                b += 1;
            }
            a_ += 1;
        }
        i += 1;
    }
    out
}

/// The diagonal of `VᵀAV` (the rest zero): the same bits as [`congruence`]'s, at half its cost.
pub(super) const fn congruence_diagonal<const K: usize>(
    v: &[[f32; K]; K],
    a: &[[f32; K]; K],
) -> [[f32; K]; K] {
    let av = product(a, v);
    let mut out = [[0.0f32; K]; K];
    let mut i = 0;
    while i < K {
        let mut b = 0;
        while b < K {
            out[b][b] += v[i][b] * av[i][b];
            b += 1;
        }
        i += 1;
    }
    out
}

/// A product of positive numbers as a mantissa in `[1, 2)` and a power of two, so that the
/// logarithm of a long product takes one `ln` and never overflows or underflows.
#[derive(Clone, Copy, Debug)]
pub(super) struct LogProduct {
    mantissa: f32,
    exponent: i32,
}

impl LogProduct {
    pub(super) const ONE: LogProduct = LogProduct { mantissa: 1.0, exponent: 0 };

    /// The product times a positive, finite `x` (const).
    pub(super) const fn times(self, x: f32) -> LogProduct {
        let (m, e) = split(x);
        let (m, e2) = split(self.mantissa * m);
        LogProduct { mantissa: m, exponent: self.exponent + e + e2 }
    }

    /// Its natural logarithm.
    pub(super) fn ln(self) -> f32 {
        math::ln(self.mantissa) + self.exponent as f32 * core::f32::consts::LN_2
    }
}

/// `x = m·2ᵉ` with `m ∈ [1, 2)` for a positive, finite `x` (subnormals too; `(1, −149)` below
/// those) (const).
const fn split(x: f32) -> (f32, i32) {
    let (x, shift) = if x < f32::MIN_POSITIVE { (x * 16_777_216.0, -24) } else { (x, 0) };
    if x.is_nan() || x <= 0.0 {
        return (1.0, -149);
    }
    let bits = x.to_bits();
    let e = ((bits >> 23) & 0xff) as i32 - 127;
    (f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000), e + shift)
}

/// `√(a² + b²)` without overflow or underflow in the squares (const).
const fn hypotenuse(a: f32, b: f32) -> f32 {
    let (x, y) = (absolute(a), absolute(b));
    let m = if x > y { x } else { y };
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    let (x, y) = (x / m, y / m);
    m * math::sqrt_newton(x * x + y * y)
}

/// Eigenvalues and eigenvectors (columns) of a symmetric matrix (const: at compile time for a
/// probe in a `const` or `static`): Householder reflections to a tridiagonal matrix, then
/// implicit QL steps with Wilkinson shifts, accumulating every transformation in `V`, then
/// one Jacobi sweep. O(K³).
pub(super) const fn symmetric_eigen<const K: usize>(
    mut a: [[f32; K]; K],
) -> ([f32; K], [[f32; K]; K]) {
    let original = a;
    let mut v = [[0.0f32; K]; K];
    let mut i = 0;
    while i < K {
        v[i][i] = 1.0;
        i += 1;
    }
    let mut k = 0;
    while k + 2 < K {
        reflect_column(&mut a, &mut v, k);
        k += 1;
    }
    // The tridiagonal matrix: diagonal d, off-diagonal e[i] between i and i + 1.
    let mut d = [0.0f32; K];
    let mut e = [0.0f32; K];
    let mut i = 0;
    while i < K {
        d[i] = a[i][i];
        if i + 1 < K {
            e[i] = a[i + 1][i];
        }
        i += 1;
    }
    implicit_ql(&mut d, &mut e, &mut v);
    // One cyclic Jacobi sweep on VᵀAV restores the small eigenvalues' relative accuracy that
    // the reflections' rounding (of the order of ε·|A|) took.
    let b = congruence(&v, &original);
    jacobi_sweeps(b, v, 1)
}

/// One Householder step on column `k`: the unit u with (I − 2uuᵀ)·a[k+1.., k] = (α, 0, …, 0).
/// On the trailing block B (rows and columns k+1..): p = Bu, w = p − (uᵀp)u, and
/// (I − 2uuᵀ)B(I − 2uuᵀ) = B − 2uwᵀ − 2wuᵀ. `v` gathers the reflection from the right.
#[inline(never)]
const fn reflect_column<const K: usize>(a: &mut [[f32; K]; K], v: &mut [[f32; K]; K], k: usize) {
    if K < 3 || k > K - 3 {
        return;
    }
    let mut scale = 0.0f32;
    let mut r = k + 1;
    while r < K {
        scale += absolute(a[r][k]);
        r += 1;
    }
    if scale.is_nan() || scale <= 0.0 {
        return;
    }
    let mut u = [0.0f32; K];
    let mut norm = 0.0f32;
    let mut r = k + 1;
    while r < K {
        u[r] = a[r][k] / scale;
        norm += u[r] * u[r];
        r += 1;
    }
    let length = math::sqrt_newton(norm);
    // α takes the sign opposite to the first entry, so u₀ = x₀ − α does not cancel.
    let alpha = if u[k + 1] > 0.0 { -length } else { length };
    u[k + 1] -= alpha;
    // |u|² = |x|² − 2αx₀ + α² = 2(|x|² − αx₀).
    let u_norm = math::sqrt_newton(2.0 * (norm - alpha * (u[k + 1] + alpha)));
    if u_norm.is_nan() || u_norm <= 0.0 {
        return;
    }
    let mut r = k + 1;
    while r < K {
        u[r] /= u_norm;
        r += 1;
    }
    let mut p = [0.0f32; K];
    let mut up = 0.0f32;
    let mut r = k + 1;
    while r < K {
        let mut c = k + 1;
        let mut acc = 0.0f32;
        while c < K {
            acc += a[r][c] * u[c];
            c += 1;
        }
        p[r] = acc;
        up += u[r] * acc;
        r += 1;
    }
    let mut r = k + 1;
    while r < K {
        p[r] -= up * u[r];
        r += 1;
    }
    let mut r = k + 1;
    while r < K {
        let mut c = k + 1;
        while c <= r {
            let x = a[r][c] - 2.0 * (u[r] * p[c] + p[r] * u[c]);
            a[r][c] = x;
            a[c][r] = x;
            c += 1;
        }
        r += 1;
    }
    // The column below the subdiagonal becomes (α·scale, 0, …).
    a[k + 1][k] = alpha * scale;
    a[k][k + 1] = alpha * scale;
    let mut r = k + 2;
    while r < K {
        a[r][k] = 0.0;
        a[k][r] = 0.0;
        r += 1;
    }
    // V ← V(I − 2uuᵀ).
    let mut row = 0;
    while row < K {
        let mut dot = 0.0f32;
        let mut c = k + 1;
        while c < K {
            dot += v[row][c] * u[c];
            c += 1;
        }
        let mut c = k + 1;
        while c < K {
            v[row][c] -= 2.0 * dot * u[c];
            c += 1;
        }
        row += 1;
    }
}

/// Implicit QL on the tridiagonal matrix of diagonal `d` and off-diagonal `e`, rotating the
/// columns of `v`: `d` becomes the eigenvalues. Deflates from the top: for each l, chases the
/// bulge of a shifted QL step through rows m − 1 … l by Givens rotations until `e[l]` is
/// negligible: against its neighbours on the diagonal, or against the matrix (a cluster of
/// eigenvalues at zero, from duplicate sensors, has neighbours of the order of rounding and
/// would never deflate on the relative test alone). At most 40 steps per eigenvalue.
#[inline(never)]
const fn implicit_ql<const K: usize>(d: &mut [f32; K], e: &mut [f32; K], v: &mut [[f32; K]; K]) {
    let mut norm = 0.0f32;
    let mut i = 0;
    while i < K {
        let row = absolute(d[i]) + absolute(e[i]);
        if row > norm {
            norm = row;
        }
        i += 1;
    }
    let negligible = f32::EPSILON * 1e-6 * norm;
    let mut l = 0;
    while l < K {
        let mut iterations = 0;
        loop {
            // The first negligible e[m] at or after l (m = K − 1: the end).
            let mut m = l;
            while m + 1 < K {
                let dd = absolute(d[m]) + absolute(d[m + 1]);
                if absolute(e[m]) <= f32::EPSILON * dd || absolute(e[m]) <= negligible {
                    break;
                }
                m += 1;
            }
            if m == l || iterations >= 40 {
                break;
            }
            iterations += 1;
            ql_step(d, e, v, l, m);
        }
        l += 1;
    }
}

/// One implicit QL step with Wilkinson's shift on rows `l..=m`; where a rotation vanishes,
/// the matrix splits there (the caller restarts).
const fn ql_step<const K: usize>(
    d: &mut [f32; K],
    e: &mut [f32; K],
    v: &mut [[f32; K]; K],
    l: usize,
    m: usize,
) {
    if l >= m || m >= K {
        return;
    }
    // Wilkinson's shift: the eigenvalue of the leading 2×2 block nearer d[l].
    let g = (d[l + 1] - d[l]) / (2.0 * e[l]);
    let r = hypotenuse(g, 1.0);
    let root = if g < 0.0 { g - r } else { g + r };
    let mut g = d[m] - d[l] + e[l] / root;
    let (mut s, mut c, mut p) = (1.0f32, 1.0f32, 0.0f32);
    let mut i = m;
    while i > l {
        i -= 1;
        let f = s * e[i];
        let b = c * e[i];
        let r = hypotenuse(f, g);
        e[i + 1] = r;
        if r == 0.0 {
            // The rotation vanished: split the matrix here.
            d[i + 1] -= p;
            e[m] = 0.0;
            return;
        }
        s = f / r;
        c = g / r;
        let h = d[i + 1] - p;
        let t = (d[i] - h) * s + 2.0 * c * b;
        p = s * t;
        d[i + 1] = h + p;
        g = c * t - b;
        let mut row = 0;
        while row < K {
            let x = v[row][i + 1];
            v[row][i + 1] = s * v[row][i] + c * x;
            v[row][i] = c * v[row][i] - s * x;
            row += 1;
        }
    }
    d[l] -= p;
    e[l] = g;
    e[m] = 0.0;
}

/// Cyclic Jacobi sweeps on a symmetric `a`, rotating the columns of `v` with it (at most
/// `sweeps`, fewer once `a` is diagonal to rounding): the eigenvalues (diagonal) and `v`.
const fn jacobi_sweeps<const K: usize>(
    mut a: [[f32; K]; K],
    mut v: [[f32; K]; K],
    sweeps: usize,
) -> ([f32; K], [[f32; K]; K]) {
    let mut sweep = 0;
    while sweep < sweeps {
        let mut off = 0.0f32;
        let mut diag = 0.0f32;
        let mut i = 0;
        while i < K {
            diag += a[i][i] * a[i][i];
            let mut j = 0;
            while j < i {
                off += a[i][j] * a[i][j];
                j += 1;
            }
            i += 1;
        }
        if off <= 1e-14 * diag {
            break;
        }
        let mut p = 0;
        while p < K {
            let mut q = p + 1;
            while q < K {
                let apq = a[p][q];
                // Negligible against both diagonal entries (the relative criterion that keeps
                // small eigenvalues accurate): no rotation.
                if apq * apq <= f32::EPSILON * f32::EPSILON * absolute(a[p][p] * a[q][q]) {
                    q += 1;
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
                let sign = if theta < 0.0 { -1.0 } else { 1.0 };
                // tan of the rotation angle, the smaller root of t² + 2θt − 1 = 0 (1/(2θ)
                // where θ² would overflow).
                let t = if absolute(theta) > 1e18 {
                    0.5 / theta
                } else {
                    sign / (absolute(theta) + math::sqrt_newton(theta * theta + 1.0))
                };
                let c = 1.0 / math::sqrt_newton(t * t + 1.0);
                let s = t * c;
                let mut k = 0;
                while k < K {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                    k += 1;
                }
                let mut k = 0;
                while k < K {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                    k += 1;
                }
                let mut k = 0;
                while k < K {
                    let (vp, vq) = (v[k][p], v[k][q]);
                    v[k][p] = c * vp - s * vq;
                    v[k][q] = s * vp + c * vq;
                    k += 1;
                }
                q += 1;
            }
            p += 1;
        }
        sweep += 1;
    }
    let mut values = [0.0f32; K];
    let mut i = 0;
    while i < K {
        values[i] = a[i][i];
        i += 1;
    }
    (values, v)
}
