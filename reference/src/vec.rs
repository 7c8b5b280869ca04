//! Helpers on 3-vectors `[f64; 3]` and 3×3 matrices stored as rows.

/// Dot product.
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product `a × b`.
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// Euclidean norm (overflow-safe scaling is not needed for the directions used here).
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|`. Returns NaNs for the zero vector.
pub fn normalize(a: [f64; 3]) -> [f64; 3] {
    scale(a, 1.0 / norm(a))
}

/// `a − b`.
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a + b`.
pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `s · a`.
pub fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Two unit tangents `(t1, t2)` such that `(t1, t2, n)` is a right-handed orthonormal
/// basis (`t1 × t2 = n`) for a unit vector `n`.
///
/// Branch-free construction of Duff et al., "Building an Orthonormal Basis, Revisited"
/// (JCGT 2017): with s = sign(n_z) and a = −1/(s + n_z), b = n_x n_y a,
/// t1 = (1 + s n_x² a, s b, −s n_x), t2 = (b, s + n_y² a, −n_y). It has no singularity:
/// s + n_z has magnitude ≥ 1.
pub fn frame(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let s = 1.0f64.copysign(n[2]);
    let a = -1.0 / (s + n[2]);
    let b = n[0] * n[1] * a;
    let t1 = [1.0 + s * n[0] * n[0] * a, s * b, -s * n[0]];
    let t2 = [b, s + n[1] * n[1] * a, -n[1]];
    (t1, t2)
}

/// Angle between two (not necessarily unit) vectors, accurate for tiny and for
/// nearly opposite angles: `atan2(|a × b|, a · b)`.
pub fn angle_between(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm(cross(a, b)).atan2(dot(a, b))
}

/// Matrix (rows) times vector.
pub fn mat_mul_vec(m: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// Transpose of a 3×3 matrix (the inverse of a rotation).
pub fn transpose(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    [[m[0][0], m[1][0], m[2][0]], [m[0][1], m[1][1], m[2][1]], [m[0][2], m[1][2], m[2][2]]]
}

/// Direction `u·n + √(1−u²)(cosφ·t1 + sinφ·t2)` in the frame `(t1, t2, n)` given
/// `u = cosθ`, `sinθ` (passed separately so that callers can keep pole accuracy) and φ.
pub fn from_frame(
    t1: [f64; 3],
    t2: [f64; 3],
    n: [f64; 3],
    cos_theta: f64,
    sin_theta: f64,
    phi: f64,
) -> [f64; 3] {
    let (sp, cp) = phi.sin_cos();
    let a = sin_theta * cp;
    let b = sin_theta * sp;
    [
        a * t1[0] + b * t2[0] + cos_theta * n[0],
        a * t1[1] + b * t2[1] + cos_theta * n[1],
        a * t1[2] + b * t2[2] + cos_theta * n[2],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn frames_are_orthonormal_and_right_handed() {
        let mut r = Rng::new(11);
        let mut dirs: Vec<[f64; 3]> = (0..10_000).map(|_| r.uniform_sphere()).collect();
        dirs.extend([
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [1.0, 0.0, 0.0],
            [0.0, -1.0, 0.0],
            normalize([1e-9, 0.0, -1.0]),
        ]);
        for n in dirs {
            let (t1, t2) = frame(n);
            for (x, y, want) in
                [(t1, t1, 1.0), (t2, t2, 1.0), (t1, t2, 0.0), (t1, n, 0.0), (t2, n, 0.0)]
            {
                assert!((dot(x, y) - want).abs() < 1e-14, "{n:?}");
            }
            assert!(norm(sub(cross(t1, t2), n)) < 1e-14);
        }
    }

    #[test]
    fn angle_between_is_accurate_for_tiny_angles() {
        let a = [1.0, 0.0, 0.0];
        for eps in [1e-3f64, 1e-8, 1e-12, 1e-15] {
            let b = [eps.cos(), eps.sin(), 0.0];
            assert!((angle_between(a, b) - eps).abs() <= 1e-15 * eps.max(1e-3));
            let c = [-eps.cos(), eps.sin(), 0.0];
            assert!((angle_between(a, c) - (core::f64::consts::PI - eps)).abs() < 1e-15);
        }
        assert_eq!(angle_between(a, a), 0.0);
    }
}
