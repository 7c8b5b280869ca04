//! Spherical Gaussians: the algebra, the fits, and the table lookups of the hemispherical and
//! clamped-cosine integrals against the reference crate's adaptive quadrature, side by side
//! with the published closed forms.
//!
//! `cargo test --test bmc sg:: -- --nocapture` prints the accuracy tables per λ decade.

use reference::sg_closed_forms as cf;
use reference::sg_reference as truth;
use reference::Rng;
use sphere_quadrature::sg::{self, SphericalGaussian};
use sphere_quadrature::{Error, Mat3, Vec3};
use std::f64::consts::PI;

fn v32(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
}

/// (λ, t) test points, exactly representable in f32.
fn point(lambda: f64, t: f64) -> (f32, f32) {
    (lambda as f32, (t.clamp(-1.0, 1.0)) as f32)
}

/// The dense grid: λ = 0 and 141 log-spaced values over 10⁻³…10⁴ plus a few beyond, each with
/// 81 uniform cosines and 40 within ±5/√λ of the horizon.
fn dense_grid() -> Vec<(f32, f32)> {
    let mut lambdas = vec![0.0];
    lambdas.extend((0..=140).map(|k| 10f64.powf(-3.0 + 7.0 * k as f64 / 140.0)));
    lambdas.extend([2e4, 1e5, 1e6, 1e8]);
    let mut pts = Vec::new();
    for &l in &lambdas {
        for j in 0..=80 {
            pts.push(point(l, -1.0 + j as f64 / 40.0));
        }
        for j in 0..40 {
            let s = -5.0 + 10.0 * (j as f64 + 0.5) / 40.0;
            pts.push(point(l, s / l.max(1.0).sqrt()));
        }
    }
    pts
}

/// Random points: λ log-uniform over 10⁻³…10⁴ (10⁻⁴… for one in 20), t uniform on [−1, 1]
/// for half of them and within ±6/√λ of the horizon for the other half.
fn random_points(n: usize, seed: u64) -> Vec<(f32, f32)> {
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|i| {
            let lo = if i % 20 == 0 { -4.0 } else { -3.0 };
            let l = 10f64.powf(lo + (4.0 - lo) * rng.next_f64());
            let u = 2.0 * rng.next_f64() - 1.0;
            let t = if i % 2 == 0 { u } else { 6.0 * u / l.max(1.0).sqrt() };
            point(l, t)
        })
        .collect()
}

/// Reference (H/F, C/F) at each point, computed on all cores.
fn references(pts: &[(f32, f32)]) -> Vec<(f64, f64)> {
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get()).min(16);
    let chunk = pts.len().div_ceil(threads);
    std::thread::scope(|s| {
        let handles: Vec<_> = pts
            .chunks(chunk)
            .map(|c| {
                s.spawn(move || {
                    c.iter()
                        .map(|&(l, t)| {
                            let (l, t) = (f64::from(l), f64::from(t));
                            (truth::hemi_fraction(l, t), truth::clamped_fraction(l, t))
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().unwrap()).collect()
    })
}

const METHODS: [&str; 7] = [
    "ours H",
    "Tokuyoshi 2022 H",
    "Meder & Brüderlin 2018 H",
    "ours C",
    "Tokuyoshi et al. 2024 C",
    "Tokuyoshi 2022 C",
    "Meder & Brüderlin 2018 C",
];

/// Errors of each method at one point, in the order of `METHODS`.
fn errors(l: f32, t: f32, h_ref: f64, c_ref: f64) -> [f64; 7] {
    let h = f64::from(sg::hemispherical_fraction(l, t).unwrap());
    let c = f64::from(sg::clamped_cosine_fraction(l, t).unwrap());
    let (l, t) = (f64::from(l), f64::from(t));
    [
        h - h_ref,
        cf::tokuyoshi2022_hemi_fraction(l, t) - h_ref,
        cf::meder2018_hemi_fraction(l, t) - h_ref,
        c - c_ref,
        cf::tokuyoshi2024_clamped_fraction(l, t) - c_ref,
        cf::tokuyoshi2022_clamped_fraction(l, t) - c_ref,
        cf::meder2018_clamped_fraction(l, t) - c_ref,
    ]
}

#[derive(Clone, Copy, Default)]
struct Stat {
    n: usize,
    max: f64,
    sq: f64,
}

impl Stat {
    fn add(&mut self, e: f64) {
        self.n += 1;
        self.max = self.max.max(e.abs());
        self.sq += e * e;
    }
    fn rms(&self) -> f64 {
        (self.sq / self.n.max(1) as f64).sqrt()
    }
}

/// Decade bins: [0, 10⁻³), [10⁻³, 10⁻²), …, [10³, 10⁴), [10⁴, ∞).
const BINS: [&str; 9] = [
    "< 1e-3",
    "1e-3..1e-2",
    "1e-2..1e-1",
    "1e-1..1",
    "1..10",
    "10..1e2",
    "1e2..1e3",
    "1e3..1e4",
    ">= 1e4",
];

fn bin(l: f32) -> usize {
    if l < 1e-3 {
        0
    } else {
        (((f64::from(l)).log10().floor() as i64 + 4) as usize).min(BINS.len() - 1)
    }
}

fn print_table(title: &str, stats: &[[Stat; 7]], total: &[Stat; 7], cols: std::ops::Range<usize>) {
    println!("\n{title}: max | RMS absolute error of the normalised integral");
    print!("{:<11} {:>6}", "λ", "points");
    for m in cols.clone() {
        print!(" | {:>25}", METHODS[m]);
    }
    println!();
    let row = |name: &str, s: &[Stat; 7]| {
        print!("{name:<11} {:>6}", s[0].n);
        for m in cols.clone() {
            print!(" | {:>12.2e} {:>12.2e}", s[m].max, s[m].rms());
        }
        println!();
    };
    for (b, s) in stats.iter().enumerate() {
        if s[0].n > 0 {
            row(BINS[b], s);
        }
    }
    row("all", total);
}

#[test]
fn tables_beat_the_closed_forms_tenfold_against_adaptive_quadrature() {
    let mut pts = dense_grid();
    let n_dense = pts.len();
    pts.extend(random_points(100_000, 0x5ca1_ab1e));
    let refs = references(&pts);
    let mut stats = [[Stat::default(); 7]; BINS.len()];
    let mut total = [Stat::default(); 7];
    for (&(l, t), &(h, c)) in pts.iter().zip(&refs) {
        let e = errors(l, t, h, c);
        for m in 0..7 {
            stats[bin(l)][m].add(e[m]);
            total[m].add(e[m]);
        }
    }
    println!(
        "{} points: {} on the dense grid, {} random (cargo test --release --test bmc sg:: -- --nocapture)",
        pts.len(),
        n_dense,
        pts.len() - n_dense
    );
    print_table("H/F (hemispherical)", &stats, &total, 0..3);
    print_table("C/F (clamped cosine)", &stats, &total, 3..7);
    let ratio_h = total[1].max.min(total[2].max) / total[0].max;
    let ratio_c = total[4].max.min(total[5].max).min(total[6].max) / total[3].max;
    println!("\nbest closed form / ours, max error: H {ratio_h:.0}×, C {ratio_c:.0}×");
    println!(
        "(Meder & Brüderlin 2018: the paper was not accessible; its formulas are taken from \
         Tokuyoshi's public transcription, see reference/src/sg_closed_forms.rs)"
    );

    // Ours: the issue asks ≤ 1e-4 (aim 1e-5); measured 1.1e-5 (H) and 4.8e-6 (C).
    assert!(total[0].max < 1.5e-5, "H max {:e}", total[0].max);
    assert!(total[3].max < 7e-6, "C max {:e}", total[3].max);
    assert!(total[0].rms() < 2e-6 && total[3].rms() < 1e-6);
    // At least ten times better than the best closed form, in max error.
    assert!(ratio_h >= 10.0 && ratio_c >= 10.0, "{ratio_h} {ratio_c}");
    // The harness sees the closed forms' published error levels (so it can see errors at all).
    assert!((1e-3..1e-2).contains(&total[1].max), "Tokuyoshi 2022 H {:e}", total[1].max);
    assert!((3e-3..3e-2).contains(&total[2].max), "Meder 2018 H {:e}", total[2].max);
    assert!((3e-4..3e-3).contains(&total[4].max), "Tokuyoshi 2024 C {:e}", total[4].max);
}

#[test]
fn limits_and_invariants() {
    let two_pi = 2.0 * std::f32::consts::PI;
    // λ → 0: H → 2π, C → π (exactly at 0, continuously below 1e-6).
    for t in [-1.0, -0.3, 0.0, 0.5, 1.0] {
        assert_eq!(sg::hemispherical_integral(0.0, t).unwrap(), two_pi);
        assert_eq!(sg::clamped_cosine_integral(0.0, t).unwrap(), std::f32::consts::PI);
        let h = sg::hemispherical_integral(1e-6, t).unwrap();
        let c = sg::clamped_cosine_integral(1e-6, t).unwrap();
        assert!((h / two_pi - 1.0).abs() < 3e-6, "{t} {h}");
        assert!((c / std::f32::consts::PI - 1.0).abs() < 3e-6, "{t} {c}");
    }
    // t = ±1: the exact path, H = 2π(1 − e^(−λ))/λ above and e^(−λ) times that below.
    for l in [1e-4f32, 0.3, 1.0, 7.0, 80.0, 1e4, 1e9] {
        let ld = f64::from(l);
        let up = -2.0 * PI * (-ld).exp_m1() / ld;
        let h1 = f64::from(sg::hemispherical_integral(l, 1.0).unwrap());
        let hm1 = f64::from(sg::hemispherical_integral(l, -1.0).unwrap());
        assert!((h1 / up - 1.0).abs() < 4e-7, "{l}: {h1} vs {up}");
        assert!((hm1 - up * (-ld).exp()).abs() < 4e-7 * up, "{l}");
        for t in [1.0f32, -1.0] {
            let c = f64::from(sg::clamped_cosine_fraction(l, t).unwrap());
            let want = truth::clamped_fraction(ld, f64::from(t));
            assert!((c - want).abs() < 2e-7, "{l} {t}: {c} vs {want}");
        }
    }
    // H(t) + H(−t) = F and C(t) − C(−t) = t·F·L(λ), over a grid, to f32 rounding.
    for l in [1e-3f32, 0.2, 2.0, 30.0, 500.0, 1e4, 1e7] {
        let f = sg::full_integral(l).unwrap();
        let ld = f64::from(l);
        let lang = 1.0 / ld.tanh() - 1.0 / ld;
        for k in 0..=40 {
            let t = -1.0 + k as f32 / 20.0;
            let h = sg::hemispherical_integral(l, t).unwrap()
                + sg::hemispherical_integral(l, -t).unwrap();
            assert!((h / f - 1.0).abs() < 3e-7, "{l} {t}");
            let d = sg::clamped_cosine_fraction(l, t).unwrap()
                - sg::clamped_cosine_fraction(l, -t).unwrap();
            assert!((f64::from(d) - f64::from(t) * lang).abs() < 5e-7, "{l} {t}");
        }
        // Monotone in t.
        let mut prev = -1.0;
        for k in 0..=400 {
            let h = sg::hemispherical_fraction(l, -1.0 + k as f32 / 200.0).unwrap();
            assert!(h >= prev - 1e-6, "{l} {k}");
            prev = h;
        }
    }
    // λ = 10⁴ and far beyond: the table's last row is λ = ∞, so large λ is in range.
    for l in [1e4f32, 1e6, 1e10, 1e20, f32::MAX] {
        for s in [-3.0f64, -0.5, 0.0, 0.7, 2.0] {
            let t = (s / f64::from(l).sqrt()) as f32;
            let h = f64::from(sg::hemispherical_fraction(l, t).unwrap());
            // Hn → Φ(s) as λ → ∞ with s = √λ·t fixed (O(1/λ) corrections).
            let phi = 0.5 * cf::erfc(-s / std::f64::consts::SQRT_2);
            let tol = if l <= 1e4 { 2e-4 } else { 2e-5 };
            assert!((h - phi).abs() < tol, "{l} {s}: {h} vs {phi}");
            let c = sg::clamped_cosine_fraction(l, t).unwrap();
            assert!(c.is_finite() && c >= 0.0);
        }
    }
    // Bad input: the documented errors, never NaN, never a panic.
    for bad in [f32::NAN, -1.0, -0.0 - 1e-30, f32::INFINITY, f32::NEG_INFINITY] {
        assert_eq!(sg::hemispherical_fraction(bad, 0.5), Err(Error::InvalidSharpness));
        assert_eq!(sg::clamped_cosine_fraction(bad, 0.5), Err(Error::InvalidSharpness));
        assert_eq!(sg::hemispherical_integral(bad, 0.5), Err(Error::InvalidSharpness));
        assert_eq!(sg::clamped_cosine_integral(bad, 0.5), Err(Error::InvalidSharpness));
        assert_eq!(sg::full_integral(bad), Err(Error::InvalidSharpness));
        assert_eq!(SphericalGaussian::new(Vec3::Z, bad, 1.0), Err(Error::InvalidSharpness));
    }
    assert_eq!(sg::hemispherical_fraction(1.0, f32::NAN), Err(Error::InvalidDirection));
    assert_eq!(sg::clamped_cosine_fraction(1.0, f32::NAN), Err(Error::InvalidDirection));
    // Cosines a rounding step outside [−1, 1] are clamped.
    assert_eq!(sg::hemispherical_fraction(3.0, 1.000_001), sg::hemispherical_fraction(3.0, 1.0));
    assert_eq!(sg::clamped_cosine_fraction(3.0, -1.5), sg::clamped_cosine_fraction(3.0, -1.0));
    let g = SphericalGaussian::new(Vec3::Z, 2.0, 1.0).unwrap();
    assert_eq!(g.hemispherical_integral(Vec3::ZERO), Err(Error::InvalidDirection));
    assert_eq!(
        g.clamped_cosine_integral(Vec3::new(f32::NAN, 0.0, 1.0)),
        Err(Error::InvalidDirection)
    );
    assert_eq!(SphericalGaussian::new(Vec3::ZERO, 1.0, 1.0), Err(Error::InvalidDirection));
    assert_eq!(SphericalGaussian::phong_lobe(Vec3::Z, -1.0), Err(Error::InvalidExponent));
    assert_eq!(SphericalGaussian::phong_lobe(Vec3::Z, f32::NAN), Err(Error::InvalidExponent));
}

#[test]
fn algebra_matches_pointwise_and_quadrature() {
    let mut rng = Rng::new(4);
    for i in 0..200 {
        let l1 = 10f64.powf(-2.0 + 5.0 * rng.next_f64()) as f32;
        let l2 = 10f64.powf(-2.0 + 5.0 * rng.next_f64()) as f32;
        let a = SphericalGaussian::new(v32(rng.uniform_sphere()), l1, 0.5 + rng.next_f64() as f32)
            .unwrap();
        let b = SphericalGaussian::new(v32(rng.uniform_sphere()), l2, 2.0).unwrap();
        let p = a.product(&b);
        // Pointwise: (G₁G₂)(v) = Gₘ(v), where the product is not underflowing.
        for _ in 0..20 {
            let v = v32(rng.uniform_sphere());
            let want = f64::from(a.evaluate(v)) * f64::from(b.evaluate(v));
            if want < 1e-30 {
                continue; // underflow of the f32 factors
            }
            let got = f64::from(p.evaluate(v));
            // f32 exponent rounding: relative error grows with |ln G|.
            let scale = f64::from(a.amplitude) * f64::from(b.amplitude);
            // micromath's exp is good to ≈2.4e-3 relative, and three of them meet here.
            let tol = if cfg!(feature = "micromath") {
                8e-3
            } else {
                3e-6 * (1.0 + (want / scale).ln().abs())
            };
            assert!((got - want).abs() <= tol * want + 1e-37, "{i}: {got} vs {want}");
        }
        // Commutative.
        let q = b.product(&a);
        assert!((q.sharpness - p.sharpness).abs() <= 1e-6 * p.sharpness);
        assert!((q.amplitude / p.amplitude - 1.0).abs() < 1e-5 || p.amplitude < 1e-30);
        // Rotation: evaluation and integrals follow the rotated axis and normal.
        let m =
            Mat3::uniform([rng.next_f64() as f32, rng.next_f64() as f32, rng.next_f64() as f32]);
        let r = a.rotated(&m);
        let n = v32(rng.uniform_sphere());
        let v = v32(rng.uniform_sphere());
        assert!((r.evaluate(m * v) - a.evaluate(v)).abs() <= 2e-5 * a.amplitude);
        let h0 = a.hemispherical_integral(n).unwrap();
        let h1 = r.hemispherical_integral(m * n).unwrap();
        assert!((h1 - h0).abs() <= 1e-4 * a.integral(), "{h0} {h1}");
    }
    // Full-sphere integral against the reference's exact form, and the inner product against a
    // 2-D Gauss–Legendre quadrature of the product.
    for l in [0.0f32, 1e-6, 0.01, 1.0, 10.0, 1e3, 1e6] {
        let g = SphericalGaussian::new(Vec3::X, l, 1.5).unwrap();
        let want = 1.5 * truth::full_integral(f64::from(l));
        assert!((f64::from(g.integral()) / want - 1.0).abs() < 3e-7, "{l}");
    }
    let (x, w) = reference::quad::gauss_legendre(200);
    for (l1, l2, ang) in [(2.0f32, 3.0f32, 0.7f32), (10.0, 0.5, 2.5), (40.0, 60.0, 0.2)] {
        let a = SphericalGaussian::new(Vec3::Z, l1, 1.0).unwrap();
        let b = SphericalGaussian::new(Vec3::new(ang.sin(), 0.0, ang.cos()), l2, 1.0).unwrap();
        let mut s = 0.0f64;
        for i in 0..200 {
            let ct = x[i];
            let st = (1.0 - ct * ct).sqrt();
            for j in 0..200 {
                let ph = PI * (x[j] + 1.0);
                let v = [st * ph.cos(), st * ph.sin(), ct];
                let g1 = (f64::from(l1) * (v[2] - 1.0)).exp();
                let mu = [f64::from(ang).sin(), 0.0, f64::from(ang).cos()];
                let g2 = (f64::from(l2) * (mu[0] * v[0] + mu[2] * v[2] - 1.0)).exp();
                s += w[i] * w[j] * PI * g1 * g2;
            }
        }
        let got = f64::from(a.inner_product(&b));
        let tol = if cfg!(feature = "micromath") { 3e-3 } else { 2e-5 };
        assert!((got / s - 1.0).abs() < tol, "{l1} {l2}: {got} vs {s}");
    }
}

/// ∫_{S²} (f − g)² by 1-D quadrature in u = cos θ about the common axis.
fn l2_error(f: impl Fn(f64) -> f64, g: impl Fn(f64) -> f64) -> (f64, f64) {
    let gap = reference::quad::integrate(|u| (f(u) - g(u)).powi(2), -1.0, 1.0, 1e-14, 1e-10);
    let norm = reference::quad::integrate(|u| f(u).powi(2), -1.0, 1.0, 1e-14, 1e-10);
    ((gap.value / norm.value).sqrt(), norm.value)
}

#[test]
fn fits_have_the_stated_errors() {
    // Clamped cosine: re-derive the least-squares (λ, a) by golden-section search.
    let cosine = |u: f64| u.max(0.0);
    let err = |l: f64| {
        let pg = reference::quad::integrate(
            |u| u.max(0.0) * (l * (u - 1.0)).exp(),
            -1.0,
            1.0,
            1e-15,
            1e-12,
        )
        .value;
        let gg = -(-4.0 * l).exp_m1() / (2.0 * l); // ∫ e^(2λ(u−1)) du
        let a = pg / gg;
        (l2_error(cosine, |u| a * (l * (u - 1.0)).exp()).0, a)
    };
    let (mut lo, mut hi) = (1.0, 4.0);
    for _ in 0..60 {
        let (m1, m2) = (lo + 0.382 * (hi - lo), lo + 0.618 * (hi - lo));
        if err(m1).0 < err(m2).0 {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    let l_opt = 0.5 * (lo + hi);
    let (e_opt, a_opt) = err(l_opt);
    let fit = SphericalGaussian::clamped_cosine(Vec3::Z).unwrap();
    println!("clamped cosine: λ = {l_opt:.5}, a = {a_opt:.5}, relative L² error {e_opt:.4}");
    assert!((f64::from(fit.sharpness) - l_opt).abs() < 2e-4);
    assert!((f64::from(fit.amplitude) - a_opt).abs() < 2e-4);
    assert!((0.175..0.179).contains(&e_opt));
    // Normalised Phong lobes (λ = e + 1, unit integral): relative L² error as documented.
    for (e, lo, hi) in [
        (1.0f32, 0.20, 0.215),
        (5.0, 0.060, 0.066),
        (50.0, 0.0067, 0.0073),
        (1000.0, 3.4e-4, 3.7e-4),
    ] {
        let fit = SphericalGaussian::phong_lobe(Vec3::Z, e).unwrap();
        let ed = f64::from(e);
        let phong = |u: f64| (ed + 1.0) / (2.0 * PI) * u.max(0.0).powf(ed);
        let (l, a) = (f64::from(fit.sharpness), f64::from(fit.amplitude));
        let (rel, _) = l2_error(phong, |u| a * (l * (u - 1.0)).exp());
        println!("Phong e = {e}: λ = {l}, relative L² error {rel:.3e}");
        assert!((lo..hi).contains(&rel), "{e}: {rel}");
        // Unit integral.
        assert!((fit.integral() - 1.0).abs() < 1e-6);
    }
}

#[test]
fn phong_moments_lobe_matches_the_first_legendre_moment() {
    // Moments ∫ lobe·P_l(cos θ) by quadrature (not the closed forms), Phong against the SG.
    let moment = |f: &dyn Fn(f64) -> f64, l: usize| {
        let m = 200_000;
        let h = 2.0 / m as f64;
        (0..m)
            .map(|i| {
                let u = -1.0 + (i as f64 + 0.5) * h;
                let p = match l {
                    0 => 1.0,
                    1 => u,
                    _ => 0.5 * (3.0 * u * u - 1.0),
                };
                2.0 * PI * f(u) * p * h
            })
            .sum::<f64>()
    };
    for e in [1.0f32, 5.0, 20.0, 100.0] {
        let ed = f64::from(e);
        let phong = |u: f64| (ed + 1.0) / (2.0 * PI) * u.max(0.0).powf(ed);
        let sg = SphericalGaussian::phong_moments(Vec3::Z, e).unwrap();
        let (l, a) = (f64::from(sg.sharpness), f64::from(sg.amplitude));
        let g = |u: f64| a * (l * (u - 1.0)).exp();
        let fit = SphericalGaussian::phong_lobe(Vec3::Z, e).unwrap();
        let (lf, af) = (f64::from(fit.sharpness), f64::from(fit.amplitude));
        let gf = |u: f64| af * (lf * (u - 1.0)).exp();
        let [p0, p1, p2] = [0, 1, 2].map(|k| moment(&phong, k));
        let [s0, s1, s2] = [0, 1, 2].map(|k| moment(&g, k));
        let [_, f1, f2] = [0, 1, 2].map(|k| moment(&gf, k));
        println!(
            "e = {e}: A₁ Phong {p1:.6} moments-SG {s1:.6} L²-fit {f1:.6}; A₂ {p2:.6} {s2:.6} {f2:.6}"
        );
        assert!((s0 - 1.0).abs() < 1e-6 && (p0 - 1.0).abs() < 1e-6);
        // A₁ = (e+1)/(e+2) up to coth λ − 1 ≈ 2e^(−2λ) (and the quadrature).
        assert!((s1 - p1).abs() < 2.2 * (-2.0 * l).exp() + 1e-6, "e = {e}: {s1} vs {p1}");
        // Closer in A₁ and A₂ than the L² fit of `phong_lobe`.
        assert!((s1 - p1).abs() < (f1 - p1).abs());
        // A₂ only asymptotically (at e = 1 the L² fit is closer: 0.194 vs 0.328, Phong 0.25).
        if e >= 5.0 {
            assert!((s2 - p2).abs() < (f2 - p2).abs(), "e = {e}: A₂ {s2} / {f2} vs {p2}");
        }
    }
}
