//! Analytic lights against independent quadratures and Monte Carlo.

use reference::analytic::{Cap, Constant, Light, Linear, SgLight};
use reference::quad::integrate;
use reference::truth::{irradiance_fn, phong_fn};
use reference::vec::{cross, dot, normalize, scale};
use reference::Rng;
use std::f64::consts::PI;

const EXPONENTS: [f64; 9] = [0.0, 0.5, 1.0, 2.0, 3.7, 10.0, 100.0, 1000.0, 1e4];

fn dirs(seed: u64, n: usize) -> Vec<[f64; 3]> {
    let mut r = Rng::new(seed);
    let mut v = vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]];
    v.extend((0..n).map(|_| r.uniform_sphere()));
    v
}

/// A unit vector at angle `beta` from `n`.
fn at_angle(n: [f64; 3], beta: f64, seed: u64) -> [f64; 3] {
    let t = normalize(cross(n, Rng::new(seed).uniform_sphere()));
    normalize([
        n[0] * beta.cos() + t[0] * beta.sin(),
        n[1] * beta.cos() + t[1] * beta.sin(),
        n[2] * beta.cos() + t[2] * beta.sin(),
    ])
}

#[test]
fn smooth_rules_reproduce_constant_linear_and_quadratic_closed_forms() {
    let c = Constant { c: 1.7 };
    let lin = Linear { a: 0.4, b: [0.3, -1.1, 0.6] };
    let mut worst = 0.0f64;
    for n in dirs(1, 20) {
        let got = irradiance_fn(|d| c.value(d), n, 8);
        worst = worst.max((got - c.irradiance(n)).abs());
        let got = irradiance_fn(|d| lin.value(d), n, 8);
        worst = worst.max((got - lin.irradiance(n)).abs());
        // (a·ω)²: irradiance π a_n²/2 + π a_t²/4, Phong (a_n²(e+1) + a_t²)/(e+3).
        let a = [0.5, 0.7, -0.2];
        let an = dot(a, normalize(n));
        let at2 = dot(a, a) - an * an;
        let got = irradiance_fn(|d| dot(a, d).powi(2), n, 8);
        worst = worst.max((got - (PI * an * an / 2.0 + PI * at2 / 4.0)).abs());
        for e in EXPONENTS {
            let got = phong_fn(|d| c.value(d), n, e, 8);
            worst = worst.max((got - c.phong(n, e)).abs());
            let got = phong_fn(|d| lin.value(d), n, e, 8);
            worst = worst.max((got - lin.phong(n, e)).abs());
            let got = phong_fn(|d| dot(a, d).powi(2), n, e, 8);
            worst = worst.max((got - (an * an * (e + 1.0) + at2) / (e + 3.0)).abs());
        }
    }
    eprintln!(
        "irradiance_fn / phong_fn vs closed forms (constant, linear, quadratic): {worst:.2e}"
    );
    assert!(worst < 1e-12);
}

#[test]
fn linear_closed_forms_match_adaptive_1d_integrals() {
    // Double-check of the Linear formulas by 1-D integrals in u (the tangential part of b
    // integrates to zero over φ).
    let lin = Linear { a: 0.4, b: [0.3, -1.1, 0.6] };
    for n in dirs(2, 5) {
        let bn = dot(lin.b, normalize(n));
        let e_irr = 2.0 * PI * integrate(|u| (lin.a + bn * u) * u, 0.0, 1.0, 0.0, 1e-15).value;
        assert!((e_irr - lin.irradiance(n)).abs() < 1e-14);
        for e in EXPONENTS {
            let p = integrate(|u| (e + 1.0) * u.powf(e) * (lin.a + bn * u), 0.0, 1.0, 0.0, 1e-15);
            assert!((p.value - lin.phong(n, e)).abs() < 1e-13, "e={e}");
        }
    }
}

fn cap_cases() -> Vec<(f64, f64)> {
    // (α, β): caps fully above, straddling, fully below, and larger than a hemisphere,
    // including the regime boundaries β = π/2 ± α.
    let mut v = Vec::new();
    for alpha in [1e-3, 0.01, 0.2, 0.7, 1.2, PI / 2.0, 1.9, 2.8, PI - 1e-3, PI] {
        for beta in [0.0, 0.1, 0.5, 1.0, PI / 2.0, 2.0, 2.9, PI] {
            v.push((alpha, beta));
        }
        for d in [-1e-9, 0.0, 1e-9, 0.03] {
            v.push((alpha, (PI / 2.0 - alpha + d).clamp(0.0, PI)));
            v.push((alpha, (PI / 2.0 + alpha + d).clamp(0.0, PI)));
        }
    }
    v
}

#[test]
fn cap_irradiance_closed_form_matches_quadrature() {
    let mut worst = 0.0f64;
    let mut worst_rel = 0.0f64;
    for (i, (alpha, beta)) in cap_cases().into_iter().enumerate() {
        let n = normalize([0.2, -0.4, 0.9]);
        let cap = Cap { axis: at_angle(n, beta, i as u64), cos_alpha: alpha.cos() };
        let closed = cap.irradiance(n);
        let numeric = cap.irradiance_numeric(n);
        worst = worst.max((closed - numeric).abs());
        if numeric > 1e-6 {
            let rel = (closed / numeric - 1.0).abs();
            if rel > 1e-12 {
                eprintln!(
                    "  α={alpha} β={beta}: closed {closed:e} numeric {numeric:e} rel {rel:.1e}"
                );
            }
            worst_rel = worst_rel.max(rel);
        }
        assert!(
            (0.0..=PI + 1e-15).contains(&closed),
            "α={alpha} β={beta}: {closed:e} vs {numeric:e}"
        );
        // Complement identity: cap + complementary cap = whole sphere (π).
        let comp = Cap { axis: scale(cap.axis, -1.0), cos_alpha: -cap.cos_alpha };
        assert!((closed + comp.irradiance(n) - PI).abs() < 1e-13, "α={alpha} β={beta}");
    }
    eprintln!("Cap irradiance closed form vs 1-D quadrature: abs {worst:.2e}, rel {worst_rel:.2e}");
    assert!(worst < 1e-12);
    assert!(worst_rel < 1e-10);
}

#[test]
fn cap_irradiance_matches_monte_carlo() {
    // 1e6 uniform directions, estimator 4π·1[cap]·max(0, n·ω), 5σ bound.
    let n = normalize([0.1, 0.3, 1.0]);
    let cases = [
        ("above", 0.4, 0.3),
        ("straddling", 0.5, 1.4),
        ("straddling, centre below", 0.6, 1.9),
        ("large", 2.2, 0.8),
        ("below", 0.3, 2.2),
    ];
    let mut rng = Rng::new(2024);
    for (name, alpha, beta) in cases {
        let cap = Cap { axis: at_angle(n, beta, 3), cos_alpha: f64::cos(alpha) };
        let m = 1_000_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..m {
            let d = rng.uniform_sphere();
            let f = 4.0 * PI * cap.value(d) * dot(n, d).max(0.0);
            s += f;
            s2 += f * f;
        }
        let mean = s / m as f64;
        let sigma = ((s2 / m as f64 - mean * mean).max(0.0) / m as f64).sqrt();
        let exact = cap.irradiance(n);
        eprintln!("Cap MC {name}: exact {exact:.6} MC {mean:.6} ± {sigma:.1e}");
        assert!((mean - exact).abs() <= 5.0 * sigma + 1e-15, "{name}");
    }
}

#[test]
fn cap_phong_closed_form_and_quadrature() {
    let r = normalize([0.3, 0.2, -0.7]);
    let mut worst = 0.0f64;
    for alpha in [0.01, 0.3, 1.0, PI / 2.0, 2.5] {
        for e in EXPONENTS {
            // Centred: closed form; 1e-9 off-centre: the quadrature, which must agree up
            // to the true change of the integral (≲ 1e-9 × its gradient).
            let cap = Cap { axis: r, cos_alpha: f64::cos(alpha) };
            let closed = cap.phong(r, e);
            let want = 1.0 - alpha.cos().max(0.0).powf(e + 1.0);
            assert!((closed - want).abs() < 1e-15);
            let off = Cap { axis: at_angle(r, 1e-9, 4), cos_alpha: f64::cos(alpha) };
            worst = worst.max((off.phong(r, e) - closed).abs());
            // Centred on −r.
            let anti = Cap { axis: scale(r, -1.0), cos_alpha: f64::cos(alpha) };
            let want = (-alpha.cos()).max(0.0).powf(e + 1.0);
            assert!((anti.phong(r, e) - want).abs() < 1e-15);
        }
    }
    eprintln!("Cap Phong: quadrature 1e-9 off-centre vs centred closed form {worst:.2e}");
    assert!(worst < 1e-8);
    // e = 0 is the solid angle inside the upper hemisphere over 2π.
    for (alpha, beta) in [(0.3, 0.2), (0.3, 1.4), (1.1, 0.5)] {
        let cap = Cap { axis: at_angle(r, beta, 5), cos_alpha: f64::cos(alpha) };
        if beta + alpha <= PI / 2.0 {
            assert!((cap.phong(r, 0.0) - cap.solid_angle() / (2.0 * PI)).abs() < 1e-13);
        }
        // e = 1 is irradiance/π.
        assert!((cap.phong(r, 1.0) * PI - cap.irradiance(r)).abs() < 1e-12);
    }
    // Monte Carlo with cosine-power sampling about r: ω ~ (e+1)/(2π) u^e, estimator 1[cap].
    let mut rng = Rng::new(99);
    let (t1, t2) = reference::vec::frame(r);
    for (e, alpha, beta) in [(20.0, 0.3, 0.25), (200.0, 0.05, 0.06), (3.0, 1.2, 1.0)] {
        let cap = Cap { axis: at_angle(r, beta, 6), cos_alpha: f64::cos(alpha) };
        let m = 1_000_000;
        let mut hits = 0u64;
        for _ in 0..m {
            let u = rng.next_f64().powf(1.0 / (e + 1.0));
            let s = ((1.0 - u) * (1.0 + u)).sqrt();
            let d = reference::vec::from_frame(t1, t2, r, u, s, 2.0 * PI * rng.next_f64());
            hits += cap.value(d) as u64;
        }
        let p = hits as f64 / m as f64;
        let sigma = (p * (1.0 - p) / m as f64).sqrt();
        let exact = cap.phong(r, e);
        eprintln!("Cap Phong MC e={e}: exact {exact:.6} MC {p:.6} ± {sigma:.1e}");
        assert!((p - exact).abs() <= 5.0 * sigma);
    }
}

#[test]
fn sg_integrals_match_2d_quadrature() {
    let mut worst_irr = 0.0f64;
    let mut worst_ph = 0.0f64;
    let n = normalize([0.2, 0.5, 0.8]);
    for (lambda, nodes) in [(0.5, 24), (5.0, 40), (50.0, 96), (300.0, 220)] {
        for (i, beta) in [0.0, 0.4, 1.2, PI / 2.0, 1.8, 2.5, PI].into_iter().enumerate() {
            let sg =
                SgLight { axis: at_angle(n, beta, i as u64), sharpness: lambda, amplitude: 1.3 };
            let one_d = sg.irradiance(n);
            let two_d = irradiance_fn(|d| sg.value(d), n, nodes);
            let scale = sg.integral() / 4.0; // typical magnitude
            worst_irr = worst_irr.max((one_d - two_d).abs() / scale);
            for e in [1.0, 10.0, 100.0] {
                let one_d = sg.phong(n, e);
                let two_d = phong_fn(|d| sg.value(d), n, e, nodes);
                worst_ph = worst_ph.max((one_d - two_d).abs() / (scale * (e + 1.0) / (2.0 * PI)));
            }
        }
    }
    eprintln!("SG 1-D vs 2-D quadrature (relative to ∫L/4): irradiance {worst_irr:.2e}, Phong {worst_ph:.2e}");
    assert!(worst_irr < 1e-9 && worst_ph < 1e-9);
}

#[test]
fn sg_special_cases() {
    for lambda in [1e-3, 0.7, 8.0, 120.0, 5000.0] {
        let a = 0.8;
        let axis = normalize([-0.3, 0.1, 0.5]);
        let sg = SgLight { axis, sharpness: lambda, amplitude: a };
        // Axis along n: 2πa ∫₀¹ u e^{λ(u−1)} du = 2πa (1/λ − (1 − e^{−λ})/λ²).
        let want = 2.0 * PI * a * (1.0 / lambda + (-lambda).exp_m1() / (lambda * lambda));
        let got = sg.irradiance(axis);
        assert!((got / want - 1.0).abs() < 1e-11, "λ={lambda}: {got} vs {want}");
        // Full-sphere integral against 1-D quadrature in u.
        let q = integrate(|u| 2.0 * PI * a * (lambda * (u - 1.0)).exp(), -1.0, 1.0, 0.0, 1e-15);
        assert!((sg.integral() / q.value - 1.0).abs() < 1e-13);
        // Irradiance from both sides of a plane adds up to ∫ L |n·ω|; with n ⊥ axis both
        // halves are equal.
        let nperp = normalize(cross(axis, [1.0, 0.0, 0.0]));
        let (p, m) = (sg.irradiance(nperp), sg.irradiance(scale(nperp, -1.0)));
        assert!((p / m - 1.0).abs() < 1e-12);
    }
    // λ → 0 is the constant a.
    let sg = SgLight { axis: [0.0, 0.0, 1.0], sharpness: 1e-14, amplitude: 2.0 };
    assert!((sg.irradiance([0.3, 0.1, -0.2]) - 2.0 * PI).abs() < 1e-12);
    assert!((sg.phong([0.3, 0.1, -0.2], 7.0) - 2.0).abs() < 1e-12);
    assert!((sg.integral() - 8.0 * PI).abs() < 1e-12);
    // Trait objects work.
    let lights: Vec<Box<dyn Light>> = vec![
        Box::new(Constant { c: 1.0 }),
        Box::new(sg),
        Box::new(Cap { axis: [0.0, 0.0, 1.0], cos_alpha: 0.5 }),
    ];
    for l in &lights {
        assert!(l.irradiance([0.0, 0.0, 1.0]) > 0.0);
        assert!(l.phong([0.0, 0.0, 1.0], 3.0) > 0.0);
        assert!(l.value([0.0, 0.0, 1.0]) > 0.0);
    }
}

#[test]
fn lu_solves_and_its_determinant_is_the_cofactor_expansion() {
    // A matrix that needs pivoting (a zero leading entry) with a known determinant.
    let a = [0.0, 2.0, 1.0, 3.0, -1.0, 4.0, 1.0, 5.0, -2.0];
    // det by cofactors along the first row: 0·(2 − 20) − 2·(−6 − 4) + 1·(15 + 1) = 36.
    let lu = reference::bmc::Lu::new(&a, 3);
    assert!((lu.log_abs_det() - 36f64.ln()).abs() < 1e-14);
    let b = [1.0, -2.0, 0.5];
    let x = lu.solve(&b);
    for r in 0..3 {
        let ax: f64 = (0..3).map(|k| a[r * 3 + k] * x[k]).sum();
        assert!((ax - b[r]).abs() < 1e-14, "row {r}: {ax} vs {}", b[r]);
    }
    // The same solution from the one-shot solve.
    assert_eq!(reference::bmc::lu_solve(&a, 3, &b), x);
}

#[test]
fn zonal_rule_integrates_polynomials_of_the_polar_cosine() {
    use std::f64::consts::PI;
    // 2π∫ sinθ·cos²θ dθ over the sphere = 4π/3; over the upper hemisphere of cos θ: π.
    let sphere = reference::quad::zonal_gl(PI, 4, |c| c * c);
    assert!((sphere - 4.0 * PI / 3.0).abs() < 1e-13, "{sphere}");
    let upper = reference::quad::zonal_gl(PI / 2.0, 4, |c| c);
    assert!((upper - PI).abs() < 1e-13, "{upper}");
}
