//! Footprint samples of environment maps: the integral of a map's radiance against a
//! normalised lobe about a direction, `Y(d) = ∫ L(ω)·f(d·ω) dω`, for testing
//! `sphere_quadrature::envmap`.
//!
//! * [`gaussian`]: the normalised spherical Gaussian
//!   f(t) = S·e^{S(t−1)}/(2π(1 − e^{−2S})) against the piecewise-constant radiance of an
//!   [`EnvMap`] (the function [`EnvMap::radiance`] defines): Σ_p L_p ∫_p f(d·ω) dω, every
//!   pixel box θ ∈ [πv/H, π(v+1)/H], φ ∈ [2πu/W, 2π(u+1)/W] integrated by tensor
//!   Gauss–Legendre in (θ, φ) (weight sinθ in the integrand) of an order chosen from the
//!   lobe's log-variation over the box, and boxes that would need more than
//!   [`MAX_ORDER`] nodes per axis split 2×2. [`gaussian_weights`] returns the per-pixel
//!   integrals ∫_p f, which sum to 1 (the tests check 1e-13).
//! * [`cosine_power`]: the normalised cosine power (P+1)/(2π)·max(0, t)^P is the
//!   normalised Phong lobe, so this is [`crate::truth::phong`] (a different method:
//!   adaptive rules with exact horizon arcs).
//! * [`sg_convolution`]: the closed form of a spherical-Gaussian light seen through a
//!   Gaussian footprint, ∫ a·e^{λ(μ·ω−1)}·f(d·ω) dω
//!   = a·S·e^{r−λ−S}(1 − e^{−2r})/(r(1 − e^{−2S})), r = |λμ + S·d|.
//!
//! Written from the mathematics in plain std f64; shares no code with the crate under test.

use crate::envmap::EnvMap;
use crate::quad::gauss_legendre;
use crate::vec::{dot, normalize};
use core::f64::consts::PI;

/// Most Gauss–Legendre nodes per axis on one box before it is split 2×2.
pub const MAX_ORDER: usize = 32;
/// Per-box tolerance of the a-priori order choice, relative to the box's largest value.
const TOL: f64 = 1e-15;
/// Boxes where the lobe stays below e^{LN_SKIP} of its peak are skipped.
const LN_SKIP: f64 = -40.0;
const MAX_DEPTH: u32 = 12;

/// The normalised spherical Gaussian f(t) = S·e^{S(t−1)}/(2π(1 − e^{−2S})) of sharpness
/// `s > 0`, evaluated from the gap `g = 1 − t` (accurate near the peak).
pub fn gaussian_response_from_gap(g: f64, s: f64) -> f64 {
    s * (-s * g).exp() / (-2.0 * PI * (-2.0 * s).exp_m1())
}

struct Rules {
    /// (nodes, weights) on [−1, 1] for orders 1..=MAX_ORDER (index = order).
    gl: Vec<(Vec<f64>, Vec<f64>)>,
    /// Gauss–Legendre error constants c_k = 2^{2k}(k!)⁴/((2k+1)((2k)!)³) on [−1, 1].
    ck: Vec<f64>,
    /// (2k)!/k!, the growth of the 2k-th derivative of e^{−q x²} (divided by q^k).
    gk: Vec<f64>,
}

impl Rules {
    fn new() -> Self {
        let mut gl = vec![(Vec::new(), Vec::new())];
        let mut ck = vec![f64::INFINITY];
        let mut gk = vec![1.0];
        for k in 1..=MAX_ORDER {
            gl.push(gauss_legendre(k));
            let kf = k as f64;
            // log c_k by lgamma-free sums (k ≤ 32 keeps the factorials finite in f64).
            let mut ln = 2.0 * kf * 2f64.ln() - (2.0 * kf + 1.0).ln();
            for i in 1..=k {
                ln += 4.0 * (i as f64).ln();
            }
            for i in 1..=2 * k {
                ln -= 3.0 * (i as f64).ln();
            }
            ck.push(ln.exp());
            let mut g = 0.0;
            for i in k + 1..=2 * k {
                g += (i as f64).ln();
            }
            gk.push(g.exp());
        }
        Rules { gl, ck, gk }
    }

    /// Smallest order whose a-priori errors are below [`TOL`] for an integrand on
    /// [−1, 1] of log-variation `v` (error c_k (V/2)^{2k}, linear exponent) and
    /// log-curvature `q` (error c_k (2k)!/k! q^k, Gaussian exponent e^{−q x²}), if any.
    fn order(&self, v: f64, q: f64) -> Option<usize> {
        (1..=MAX_ORDER).find(|&k| {
            self.ck[k] * (0.5 * v).powi(2 * k as i32) < TOL
                && self.ck[k] * self.gk[k] * q.powi(k as i32) < TOL
        })
    }
}

#[derive(Clone, Copy)]
struct PixelBox {
    th0: f64,
    th1: f64,
    phi0: f64,
    phi1: f64,
}

fn polar(theta: f64, phi: f64) -> [f64; 3] {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    [st * cp, st * sp, ct]
}

impl PixelBox {
    /// Largest and smallest t = d·ω over the box, bounded through the angular distance
    /// from d to the box centre and the box's angular radius (largest angle from the
    /// centre to a corner or edge midpoint, which for Δφ ≤ π bounds the box).
    fn t_range(&self, d: [f64; 3]) -> (f64, f64) {
        let (tc, pc) = (0.5 * (self.th0 + self.th1), 0.5 * (self.phi0 + self.phi1));
        let c = polar(tc, pc);
        let mut rho: f64 = 0.0;
        for th in [self.th0, tc, self.th1] {
            for ph in [self.phi0, pc, self.phi1] {
                let p = polar(th, ph);
                rho = rho.max(crate::vec::angle_between(c, p));
            }
        }
        let rho = rho * (1.0 + 1e-6) + 1e-12;
        let s = crate::vec::angle_between(d, c);
        let tmax = if s <= rho { 1.0 } else { (s - rho).cos() };
        let tmin = if s + rho >= PI { -1.0 } else { (s + rho).cos() };
        (tmin, tmax)
    }

    fn split(&self) -> [PixelBox; 4] {
        let tm = 0.5 * (self.th0 + self.th1);
        let pm = 0.5 * (self.phi0 + self.phi1);
        [
            PixelBox { th0: self.th0, th1: tm, phi0: self.phi0, phi1: pm },
            PixelBox { th0: self.th0, th1: tm, phi0: pm, phi1: self.phi1 },
            PixelBox { th0: tm, th1: self.th1, phi0: self.phi0, phi1: pm },
            PixelBox { th0: tm, th1: self.th1, phi0: pm, phi1: self.phi1 },
        ]
    }

    /// ∫_box f(d·ω) dω for the normalised Gaussian of sharpness `s`.
    fn gaussian(&self, d: [f64; 3], s: f64, rules: &Rules, depth: u32) -> f64 {
        let (tmin, tmax) = self.t_range(d);
        if s * (tmax - 1.0) < LN_SKIP {
            return 0.0;
        }
        // Log-variation of e^{S t} over the box plus the unit-frequency geometry.
        let v = s * (tmax - tmin) + (self.th1 - self.th0) + (self.phi1 - self.phi0);
        // Curvature: S·t has second derivatives ≤ S in angle, so S·h²/2 on [−1, 1] for the
        // larger half-width h (φ measured in angle is shorter by sinθ).
        let h = 0.5 * (self.th1 - self.th0).max(self.phi1 - self.phi0);
        let q = 0.5 * s * h * h + h * h;
        let k = match rules.order(v, q) {
            Some(k) => k,
            None if depth < MAX_DEPTH => {
                return self.split().iter().map(|b| b.gaussian(d, s, rules, depth + 1)).sum();
            }
            None => MAX_ORDER,
        };
        let (x, w) = &rules.gl[k];
        let (ht, hp) = (0.5 * (self.th1 - self.th0), 0.5 * (self.phi1 - self.phi0));
        let (ct, cp) = (0.5 * (self.th0 + self.th1), 0.5 * (self.phi0 + self.phi1));
        let mut total = 0.0;
        for (xi, wi) in x.iter().zip(w) {
            let theta = ct + ht * xi;
            let mut row = 0.0;
            for (xj, wj) in x.iter().zip(w) {
                let p = polar(theta, cp + hp * xj);
                let g = [p[0] - d[0], p[1] - d[1], p[2] - d[2]];
                row += wj * gaussian_response_from_gap(0.5 * dot(g, g), s);
            }
            total += wi * theta.sin() * row;
        }
        total * ht * hp
    }
}

/// Per-pixel integrals ∫_p f(d·ω) dω of the normalised spherical Gaussian of sharpness
/// `s > 0` about `d` (normalised first) over a `width`×`height` equirectangular grid,
/// row-major, row 0 at the top. They sum to 1.
pub fn gaussian_weights(width: usize, height: usize, d: [f64; 3], s: f64) -> Vec<f64> {
    assert!(s > 0.0 && s.is_finite(), "sharpness must be positive and finite");
    let d = normalize(d);
    let rules = Rules::new();
    let mut out = Vec::with_capacity(width * height);
    for v in 0..height {
        for u in 0..width {
            let bx = PixelBox {
                th0: PI * v as f64 / height as f64,
                th1: PI * (v + 1) as f64 / height as f64,
                phi0: 2.0 * PI * u as f64 / width as f64,
                phi1: 2.0 * PI * (u + 1) as f64 / width as f64,
            };
            out.push(bx.gaussian(d, s, &rules, 0));
        }
    }
    out
}

/// Σ_p L_p ∫_p f(d·ω) dω: the Gaussian footprint sample of the map's piecewise-constant
/// radiance, per channel.
pub fn gaussian(map: &EnvMap, d: [f64; 3], s: f64) -> [f64; 3] {
    let w = gaussian_weights(map.width, map.height, d, s);
    let mut acc = [0.0; 3];
    for (p, wi) in map.pixels.iter().zip(&w) {
        for c in 0..3 {
            acc[c] += wi * p[c] as f64;
        }
    }
    acc
}

/// ∫ L(ω)·(P+1)/(2π)·max(0, d·ω)^P dω of the map's piecewise-constant radiance, per
/// channel: [`crate::truth::phong`] with e = P.
pub fn cosine_power(map: &EnvMap, d: [f64; 3], p: f64) -> [f64; 3] {
    crate::truth::phong(map, d, p)
}

/// Closed form of ∫ a·e^{λ(μ·ω−1)}·f(d·ω) dω for the normalised Gaussian footprint f of
/// sharpness `s > 0`: the product of two spherical Gaussians is a spherical Gaussian with
/// axis λμ + S·d, and ∫ e^{r·ω} dω = 4π sinh(r)/r, so the sample is
/// a·S·e^{r−λ−S}(1 − e^{−2r})/(r(1 − e^{−2S})) with r = |λμ + S·d| (all exponents ≤ 0).
pub fn sg_convolution(light: &crate::analytic::SgLight, d: [f64; 3], s: f64) -> f64 {
    let (mu, d) = (normalize(light.axis), normalize(d));
    let l = light.sharpness;
    let m = [l * mu[0] + s * d[0], l * mu[1] + s * d[1], l * mu[2] + s * d[2]];
    let r = dot(m, m).sqrt();
    // (1 − e^{−2r})/r → 2 as r → 0.
    let shell = if r < 1e-8 { 2.0 - 2.0 * r } else { -(-2.0 * r).exp_m1() / r };
    light.amplitude * s * (r - l - s).exp() * shell / -(-2.0 * s).exp_m1()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::SgLight;
    use crate::rng::Rng;

    #[test]
    fn weights_sum_to_one_and_do_not_depend_on_the_order_choice() {
        let mut rng = Rng::new(77);
        for (w, h, s) in [(64, 32, 1.0), (64, 32, 30.0), (128, 64, 700.0), (16, 8, 4096.0)] {
            for _ in 0..3 {
                let d = rng.uniform_sphere();
                let sum: f64 = gaussian_weights(w, h, d, s).iter().sum();
                assert!((sum - 1.0).abs() < 1e-13, "{w}x{h} S={s}: {sum}");
            }
        }
        // A pole and a direction on a pixel corner.
        for d in [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]] {
            let sum: f64 = gaussian_weights(32, 16, d, 200.0).iter().sum();
            assert!((sum - 1.0).abs() < 1e-13, "{d:?}: {sum}");
        }
    }

    #[test]
    fn sg_closed_form_matches_quadrature_of_the_smooth_product() {
        // ∫ SG_light · f over the sphere by a fine product rule in the frame of d.
        let mut rng = Rng::new(5);
        for (lambda, s) in [(0.0, 3.0), (8.0, 1.0), (8.0, 40.0), (50.0, 200.0)] {
            let light = SgLight { axis: rng.uniform_sphere(), sharpness: lambda, amplitude: 2.0 };
            let d = rng.uniform_sphere();
            let closed = sg_convolution(&light, d, s);
            // Gauss–Legendre in u = cosθ about d (clustered near u = 1 by u = 1 − x²·2),
            // trapezoid in φ.
            let (x, w) = crate::quad::gauss_legendre_on(400, 0.0, 2.0f64.sqrt());
            let (t1, t2) = crate::vec::frame(normalize(d));
            let m = 800;
            let mut total = 0.0;
            for (xi, wi) in x.iter().zip(&w) {
                let g = xi * xi; // 1 − u ∈ [0, 2], dg = 2x dx
                let u = 1.0 - g;
                let st = (g * (2.0 - g)).sqrt();
                let mut ring = 0.0;
                for j in 0..m {
                    let phi = 2.0 * PI * j as f64 / m as f64;
                    let p = crate::vec::from_frame(t1, t2, normalize(d), u, st, phi);
                    ring += light.value(p);
                }
                total += wi * 2.0 * xi * gaussian_response_from_gap(g, s) * ring;
            }
            let numeric = total * 2.0 * PI / m as f64;
            assert!(
                (closed - numeric).abs() < 1e-11 * closed.abs().max(1e-3),
                "{closed} {numeric}"
            );
        }
    }

    #[test]
    fn constant_map_gives_the_constant() {
        let map = EnvMap::constant(48, 24, [0.5, 2.0, 3.0]);
        let y = gaussian(&map, [0.3, -0.2, 0.9], 17.0);
        for (c, want) in y.iter().zip([0.5, 2.0, 3.0]) {
            assert!((c - want).abs() < 1e-13 * want, "{y:?}");
        }
    }
}
