//! Light functions on the sphere with exactly (or 1-D-quadrature) known integrals.
//!
//! For every light L:
//! * `irradiance(n)` = ∫_{S²} L(ω) max(0, n·ω) dω;
//! * `phong(r, e)` = ∫_{S²} L(ω) (e+1)/(2π) max(0, r·ω)^e dω (normalised lobe: it
//!   integrates to 1, so a constant light of value c gives c; no surface clipping).
//!
//! Directions passed in need not be unit length; they are normalised.

use crate::quad::integrate_with_breaks;
use crate::special::bessel_i0e;
use crate::vec::{cross, dot, norm, normalize};
use core::f64::consts::PI;

/// Common interface of the analytic lights.
pub trait Light {
    /// Radiance in direction `dir`.
    fn value(&self, dir: [f64; 3]) -> f64;
    /// ∫ L(ω) max(0, n·ω) dω.
    fn irradiance(&self, n: [f64; 3]) -> f64;
    /// ∫ L(ω) (e+1)/(2π) max(0, r·ω)^e dω.
    fn phong(&self, r: [f64; 3], e: f64) -> f64;
}

/// L(ω) = c.
#[derive(Clone, Copy, Debug)]
pub struct Constant {
    /// The constant radiance.
    pub c: f64,
}

impl Constant {
    /// c.
    pub fn value(&self, _dir: [f64; 3]) -> f64 {
        self.c
    }
    /// π c (∫ max(0, n·ω) dω = 2π ∫₀¹ u du = π).
    pub fn irradiance(&self, _n: [f64; 3]) -> f64 {
        PI * self.c
    }
    /// c (the lobe is normalised).
    pub fn phong(&self, _r: [f64; 3], _e: f64) -> f64 {
        self.c
    }
}

/// L(ω) = a + b·ω.
#[derive(Clone, Copy, Debug)]
pub struct Linear {
    /// Constant part.
    pub a: f64,
    /// Gradient part.
    pub b: [f64; 3],
}

impl Linear {
    /// a + b·ω (ω = normalised `dir`).
    pub fn value(&self, dir: [f64; 3]) -> f64 {
        self.a + dot(self.b, normalize(dir))
    }
    /// π a + (2π/3)(b·n).
    ///
    /// In the frame of n write ω = u n + √(1−u²)(cosφ t₁ + sinφ t₂): the tangential part
    /// of b·ω integrates to 0 over φ, leaving ∫ (a + (b·n) u) u du dφ over u ∈ [0, 1]
    /// = 2π (a/2 + (b·n)/3).
    pub fn irradiance(&self, n: [f64; 3]) -> f64 {
        PI * self.a + 2.0 * PI / 3.0 * dot(self.b, normalize(n))
    }
    /// a + (b·r)(e+1)/(e+2).
    ///
    /// As above: (e+1)/(2π) · 2π ∫₀¹ (a + (b·r) u) u^e du = a + (b·r)(e+1)/(e+2).
    pub fn phong(&self, r: [f64; 3], e: f64) -> f64 {
        self.a + dot(self.b, normalize(r)) * (e + 1.0) / (e + 2.0)
    }
}

/// Indicator of the spherical cap {ω : ω·axis ≥ cos α}.
#[derive(Clone, Copy, Debug)]
pub struct Cap {
    /// Cap centre (normalised when used).
    pub axis: [f64; 3],
    /// Cosine of the cap's angular radius α, in [−1, 1].
    pub cos_alpha: f64,
}

/// atan(w) − w without cancellation for small w.
fn atan_minus_id(w: f64) -> f64 {
    if w.abs() < 0.5 {
        // Σ_{k≥1} (−1)^k w^{2k+1}/(2k+1)
        let w2 = w * w;
        let mut p = w * w2;
        let mut sum = 0.0;
        let mut k = 1.0;
        loop {
            let term = p / (2.0 * k + 1.0);
            sum += if (k as i64) % 2 == 1 { -term } else { term };
            if term.abs() <= 1e-18 * sum.abs() {
                break;
            }
            p *= w2;
            k += 1.0;
        }
        sum
    } else {
        w.atan() - w
    }
}

/// Irradiance from a cap of angular radius α whose axis makes angle β with the normal
/// (cb = cosβ, sb = sinβ ≥ 0, ca = cosα, sa = sinα ≥ 0).
fn cap_irradiance(cb: f64, sb: f64, ca: f64, sa: f64) -> f64 {
    if ca < 0.0 {
        // Larger than a hemisphere: whole sphere (π) minus the complementary cap about
        // −axis with radius π − α.
        return PI - cap_irradiance(-cb, sb, -ca, sa);
    }
    if cb >= sa {
        // β ≤ π/2 − α: the whole cap is above the horizon and
        // ∫_cap n·ω dω = n·(π sin²α axis).
        return PI * sa * sa * cb;
    }
    if cb <= -sa {
        return 0.0; // β ≥ π/2 + α: entirely below
    }
    // Partially below the horizon (|cosβ| < sinα, hence sinα, sinβ > 0). With
    // x = cot α, y = −x cot β, q = sinβ √(1 − y²), the classic result (Snyder 1996,
    // "Area light sources for real-time graphics"; as used for horizon-clipped sphere
    // lights) is  E = (cosβ·acos y − x q) sin²α + atan(q/x).
    // For small w = q/x = q tan α the last two terms cancel to O(w³); rewrite with
    // x q sin²α = w cos²α as  E = sin²α (cosβ·acos y + w) + (atan w − w).
    let x = ca / sa;
    let y = (-x * cb / sb).clamp(-1.0, 1.0);
    let q = sb * ((1.0 - y) * (1.0 + y)).sqrt();
    let ay = y.acos();
    let e = if q < x {
        let w = q / x;
        sa * sa * (cb * ay + w) + atan_minus_id(w)
    } else {
        (cb * ay - x * q) * sa * sa + q.atan2(x)
    };
    // Slivers just above the horizon cancel to ≈1e-22 absolute; keep the sign right.
    e.max(0.0)
}

/// Break points and endpoint-regularised adaptive integration of `g` over [0, π/2] in
/// the polar angle θ; every piece [θa, θb] is mapped by θ = θa + (θb − θa)(1 − cos τ)/2 so
/// that square-root behaviour at its ends becomes smooth.
fn integrate_theta(mut g: impl FnMut(f64) -> f64, breaks: &[f64], rel_tol: f64) -> f64 {
    let mut pts = vec![0.0, 0.5 * PI];
    pts.extend(breaks.iter().copied().filter(|b| *b > 0.0 && *b < 0.5 * PI));
    pts.sort_by(|a, b| a.partial_cmp(b).unwrap());
    pts.dedup();
    let mut total = 0.0;
    for seg in pts.windows(2) {
        let (ta, tb) = (seg[0], seg[1]);
        let h = tb - ta;
        let r = integrate_with_breaks(
            |tau: f64| {
                let th = ta + h * 0.5 * (1.0 - tau.cos());
                g(th) * 0.5 * h * tau.sin()
            },
            0.0,
            PI,
            &[],
            1e-17,
            rel_tol,
        );
        total += r.value;
    }
    total
}

impl Cap {
    /// 1 if the direction of `dir` is inside the cap (ω·axis ≥ cos α), else 0.
    pub fn value(&self, dir: [f64; 3]) -> f64 {
        if dot(normalize(dir), normalize(self.axis)) >= self.cos_alpha {
            1.0
        } else {
            0.0
        }
    }

    /// Solid angle 2π(1 − cos α).
    pub fn solid_angle(&self) -> f64 {
        2.0 * PI * (1.0 - self.cos_alpha)
    }

    fn sin_alpha(&self) -> f64 {
        let c = self.cos_alpha.clamp(-1.0, 1.0);
        ((1.0 - c) * (1.0 + c)).sqrt()
    }

    /// Closed-form irradiance, valid for every position of the cap relative to the
    /// horizon (fully above: π sin²α cosβ; fully below: 0; straddling: Snyder's formula,
    /// see the source; caps larger than a hemisphere via the complement). Verified
    /// against [`Cap::irradiance_numeric`] and Monte Carlo in the tests.
    pub fn irradiance(&self, n: [f64; 3]) -> f64 {
        let a = normalize(self.axis);
        let n = normalize(n);
        let cb = dot(a, n);
        let sb = norm(cross(a, n));
        cap_irradiance(cb, sb, self.cos_alpha.clamp(-1.0, 1.0), self.sin_alpha())
    }

    /// Irradiance by 1-D quadrature (π × [`Cap::phong_numeric`] with e = 1), an
    /// independent check of the closed form, accurate to ≈1e-13.
    pub fn irradiance_numeric(&self, n: [f64; 3]) -> f64 {
        PI * self.phong_numeric(n, 1.0)
    }

    /// Phong integral of the cap. Closed form 1 − max(0, cos α)^{e+1} when the cap is
    /// centred on r (axis ∥ r: (e+1)∫_{cos α}^1 u^e du), max(0, −cos α)^{e+1} when
    /// centred on −r; otherwise [`Cap::phong_numeric`] (1-D quadrature, ≈1e-12).
    pub fn phong(&self, r: [f64; 3], e: f64) -> f64 {
        let a = normalize(self.axis);
        let r = normalize(r);
        if norm(cross(a, r)) == 0.0 {
            let ca = self.cos_alpha.clamp(-1.0, 1.0);
            if dot(a, r) > 0.0 {
                return 1.0 - ca.max(0.0).powf(e + 1.0);
            } else {
                return (-ca).max(0.0).powf(e + 1.0);
            }
        }
        self.phong_numeric(r, e)
    }

    /// Phong integral by quadrature in the frame of r:
    /// (e+1)/(2π) ∫₀^{π/2} cos^eθ sinθ ℓ(θ) dθ, where ℓ(θ) ∈ [0, 2π] is the length in φ of
    /// the circle at angle θ from r that lies inside the cap: with γ = angle(r, axis),
    /// ℓ = 2 acos((cos α − cosθ cosγ)/(sinθ sinγ)) (clamped). ℓ has square-root
    /// behaviour at θ = |γ − α|, γ + α, 2π − γ − α; the integral is split there (and at
    /// multiples of 1/√(e+1) for sharp lobes), each piece regularised by a cosine
    /// substitution and integrated by adaptive Gauss–Kronrod to 1e-13 relative.
    pub fn phong_numeric(&self, r: [f64; 3], e: f64) -> f64 {
        let a = normalize(self.axis);
        let r = normalize(r);
        let cg = dot(a, r);
        let sg = norm(cross(a, r));
        let gamma = sg.atan2(cg);
        let ca = self.cos_alpha.clamp(-1.0, 1.0);
        let alpha = self.sin_alpha().atan2(ca);
        let ell = |th: f64| -> f64 {
            let (st, ct) = th.sin_cos();
            let den = st * sg;
            if den <= 0.0 {
                return if ct * cg >= ca { 2.0 * PI } else { 0.0 };
            }
            // c = (cos α − cosθ cosγ)/(sinθ sinγ) = 1 − δ with, free of cancellation,
            // δ = (cos(θ − γ) − cos α)/(sinθ sinγ)
            //   = 2 sin((α + θ − γ)/2) sin((α − θ + γ)/2)/(sinθ sinγ),
            // and acos(1 − δ) = 2 asin(√(δ/2)).
            let delta =
                2.0 * (0.5 * (alpha + th - gamma)).sin() * (0.5 * (alpha - th + gamma)).sin() / den;
            if delta <= 0.0 {
                0.0
            } else if delta >= 2.0 {
                2.0 * PI
            } else if delta <= 1.0 {
                4.0 * (0.5 * delta).sqrt().asin()
            } else {
                2.0 * (1.0 - delta).acos()
            }
        };
        let mut breaks = vec![(gamma - alpha).abs(), gamma + alpha, 2.0 * PI - gamma - alpha];
        let w = 1.0 / (e + 1.0).sqrt();
        breaks.extend([w, 4.0 * w, 16.0 * w]);
        let v = integrate_theta(
            |th| {
                let (st, ct) = th.sin_cos();
                ct.powf(e) * st * ell(th)
            },
            &breaks,
            1e-13,
        );
        (e + 1.0) / (2.0 * PI) * v
    }
}

/// Spherical Gaussian L(ω) = a·exp(λ(axis·ω − 1)).
#[derive(Clone, Copy, Debug)]
pub struct SgLight {
    /// Lobe axis (normalised when used).
    pub axis: [f64; 3],
    /// Sharpness λ ≥ 0.
    pub sharpness: f64,
    /// Amplitude a (the value at the axis).
    pub amplitude: f64,
}

impl SgLight {
    /// a·exp(λ(axis·ω − 1)), evaluated as a·exp(−λ|ω − axis|²/2) (accurate near the
    /// axis).
    pub fn value(&self, dir: [f64; 3]) -> f64 {
        let d = crate::vec::sub(normalize(dir), normalize(self.axis));
        self.amplitude * (-0.5 * self.sharpness * dot(d, d)).exp()
    }

    /// ∫_{S²} L dω = 2πa(1 − e^{−2λ})/λ (4πa at λ = 0), via expm1.
    pub fn integral(&self) -> f64 {
        let l = self.sharpness;
        if l == 0.0 {
            4.0 * PI * self.amplitude
        } else {
            -2.0 * PI * self.amplitude * (-2.0 * l).exp_m1() / l
        }
    }

    /// Common 1-D integral a·∫₀^{π/2} w(θ) sinθ e^{−2λ sin²((θ−θa)/2)} I0e(λ sinθa sinθ) dθ
    /// with θa = angle(axis, n).
    fn hemi_integral(&self, n: [f64; 3], weight: impl Fn(f64) -> f64, lobe_width: f64) -> f64 {
        let a = normalize(self.axis);
        let n = normalize(n);
        let ta = norm(cross(a, n)).atan2(dot(a, n));
        let sa = ta.sin();
        let l = self.sharpness;
        let mut breaks = vec![ta];
        if l > 0.0 {
            let w = 1.0 / l.sqrt();
            for k in [1.0, 3.0, 10.0] {
                breaks.push(ta - k * w);
                breaks.push(ta + k * w);
            }
        }
        breaks.extend([lobe_width, 4.0 * lobe_width, 16.0 * lobe_width]);
        let v = integrate_theta(
            |th| {
                let (st, _) = th.sin_cos();
                let h = (0.5 * (th - ta)).sin();
                weight(th) * st * (-2.0 * l * h * h).exp() * bessel_i0e(l * sa * st)
            },
            &breaks,
            1e-14,
        );
        self.amplitude * v
    }

    /// Irradiance by a 1-D integral (no closed form for a general axis).
    ///
    /// In the frame of n, with t = axis·n = cosθa and u = cosθ,
    /// axis·ω = t u + √(1−t²)√(1−u²) cosφ, and ∫₀^{2π} e^{κ cosφ} dφ = 2π I₀(κ), so
    /// E = 2π a e^{−λ} ∫₀¹ u e^{λtu} I₀(λ√(1−t²)√(1−u²)) du. It is evaluated in θ with the
    /// exponentially scaled I0e: λ(tu − 1) + λ sinθa sinθ = −2λ sin²((θ − θa)/2), so
    /// E = 2πa ∫₀^{π/2} cosθ sinθ e^{−2λ sin²((θ−θa)/2)} I0e(λ sinθa sinθ) dθ, by
    /// adaptive Gauss–Kronrod split at θa and θa ± {1, 3, 10}/√λ: accurate to ≈1e-13
    /// relative (a quadrature, not a closed form).
    pub fn irradiance(&self, n: [f64; 3]) -> f64 {
        2.0 * PI * self.hemi_integral(n, |th| th.cos(), 1.0)
    }

    /// Phong integral by the same 1-D reduction with weight (e+1)/(2π)·cos^eθ:
    /// a (e+1) ∫₀^{π/2} cos^eθ sinθ e^{−2λ sin²((θ−θa)/2)} I0e(λ sinθa sinθ) dθ
    /// (≈1e-13 relative; a quadrature, not a closed form).
    pub fn phong(&self, r: [f64; 3], e: f64) -> f64 {
        (e + 1.0) * self.hemi_integral(r, |th| th.cos().powf(e), 1.0 / (e + 1.0).sqrt())
    }
}

macro_rules! impl_light {
    ($t:ty) => {
        impl Light for $t {
            fn value(&self, dir: [f64; 3]) -> f64 {
                <$t>::value(self, dir)
            }
            fn irradiance(&self, n: [f64; 3]) -> f64 {
                <$t>::irradiance(self, n)
            }
            fn phong(&self, r: [f64; 3], e: f64) -> f64 {
                <$t>::phong(self, r, e)
            }
        }
    };
}
impl_light!(Constant);
impl_light!(Linear);
impl_light!(Cap);
impl_light!(SgLight);

/// One seeded test query: a normal, a spherical-Gaussian light and its exact irradiance.
#[derive(Clone, Debug)]
pub struct SgQuery {
    /// The surface normal (unit).
    pub normal: [f64; 3],
    /// The light: unit amplitude, sharpness in [2, 20], axis at least 0.35 in cosine above
    /// the normal's horizon.
    pub light: SgLight,
    /// `light.irradiance(normal)`.
    pub truth: f64,
    /// Random 64 bits, e.g. a rotation phase for the estimator under test.
    pub phase: u64,
}

/// `count` seeded smooth-light queries (the synthetic tier shared by the QMC and BMC tests):
/// a uniform random normal, an SG light of sharpness uniform in [2, 20] whose axis is
/// uniform among directions with cosine > 0.35 to the normal, its exact irradiance, and a
/// random phase.
#[must_use]
pub fn sg_queries(count: usize, seed: u64) -> Vec<SgQuery> {
    let mut rng = crate::rng::Rng::new(seed);
    (0..count)
        .map(|_| {
            let normal = rng.uniform_sphere();
            let axis = loop {
                let a = rng.uniform_sphere();
                if dot(a, normal) > 0.35 {
                    break a;
                }
            };
            let light = SgLight { axis, sharpness: 2.0 + 18.0 * rng.next_f64(), amplitude: 1.0 };
            SgQuery { normal, truth: light.irradiance(normal), light, phase: rng.next_u64() }
        })
        .collect()
}
