//! Footprint probes (issue #11) against an independent f64 reference.
//!
//! The reference here takes every Legendre coefficient by Gauss–Legendre quadrature of the
//! defining integral `a_l = 2π∫ φ(t)·P_l(t) dt` (no Bessel functions, no continued fractions,
//! no closed forms of SG products), builds the full `Q` of a footprint probe from the series
//! `Σ K_l g_l² (2l + 1)/(4π)·P_l`, and solves by LU: it shares nothing with `gen/probe.rs` or
//! `src/probe.rs` but the model.

use reference::analytic::SgLight;
use reference::rng::Rng;
use sphere_quadrature::footprint::{CosinePower, Footprint, Gaussian, Kind, Point};
use sphere_quadrature::probe::{cosine_weighted_average, Probe, ProbeTables, Selection};
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::{bmc::Size, Error, Mat3, Vec3};
use std::f64::consts::PI;

use crate::calibration::glossy_calibration;
use crate::gen;

fn legendre(l: usize, t: f64) -> f64 {
    let (mut p0, mut p1) = (1.0, t);
    if l == 0 {
        return 1.0;
    }
    for k in 1..l {
        let p2 = ((2 * k + 1) as f64 * t * p1 - k as f64 * p0) / (k + 1) as f64;
        p0 = p1;
        p1 = p2;
    }
    p1
}

/// `a_l = 2π∫₋₁¹ φ(t)·P_l(t) dt` for `l < count`, by 24-point Gauss–Legendre on panels in
/// `u = 1 − t` graded geometrically towards `t = 1` (`[0, 2⁻²⁰]`, then doubling to `[1, 2]`),
/// with a break at `t = 0` (where the clamped functions have a kink).
fn coefficients(phi: impl Fn(f64) -> f64, count: usize) -> Vec<f64> {
    let mut edges = vec![0.0];
    edges.extend((0..=21).map(|k| 2.0 * 0.5f64.powi(21 - k)));
    let (xs, ws) = reference::quad::gauss_legendre(24);
    let mut out = vec![0.0; count];
    for pair in edges.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        for (x, w) in xs.iter().zip(&ws) {
            let u = 0.5 * (a + b) + 0.5 * (b - a) * x;
            let t = 1.0 - u;
            let fw = 0.5 * (b - a) * w * phi(t);
            let (mut p0, mut p1) = (1.0, t);
            for (l, o) in out.iter_mut().enumerate() {
                let p = match l {
                    0 => 1.0,
                    1 => t,
                    _ => {
                        let p2 = ((2 * l - 1) as f64 * t * p1 - (l - 1) as f64 * p0) / l as f64;
                        p0 = p1;
                        p1 = p2;
                        p2
                    }
                };
                *o += 2.0 * PI * fw * p;
            }
        }
    }
    out
}

/// `a_l = 2π∫ exp(x(t − 1))·P_l(t) dt` for `l < count` by Rodrigues' formula and `l`
/// integrations by parts, `a_l = 2π·xˡ/(2ˡ·l!)·∫₋₁¹ exp(x(t − 1))·(1 − t²)ˡ dt`: a positive
/// integrand, so the quadrature keeps full relative precision where `a_l` is tiny (the
/// direct form cancels to ~10⁻¹⁶ absolute).
fn sg_coefficients(x: f64, count: usize) -> Vec<f64> {
    let (xs, ws) = reference::quad::gauss_legendre(24);
    let panels = 96;
    let mut ln_factorial = 0.0;
    (0..count)
        .map(|l| {
            if l > 0 {
                ln_factorial += (l as f64).ln();
            }
            let mut j = 0.0;
            for p in 0..panels {
                let (a, b) = (
                    -1.0 + 2.0 * p as f64 / panels as f64,
                    -1.0 + 2.0 * (p + 1) as f64 / panels as f64,
                );
                for (u, w) in xs.iter().zip(&ws) {
                    let t = 0.5 * (a + b) + 0.5 * (b - a) * u;
                    j += 0.5 * (b - a) * w * (x * (t - 1.0) + l as f64 * (1.0 - t * t).ln()).exp();
                }
            }
            2.0 * PI * (l as f64 * (0.5 * x).ln() - ln_factorial).exp() * j
        })
        .collect()
}

/// The footprint's gains `g_l` by quadrature.
fn gains(kind: Kind, count: usize) -> Vec<f64> {
    match kind {
        Kind::Point => vec![1.0; count],
        Kind::Gaussian { sharpness } => {
            let a = sg_coefficients(f64::from(sharpness), count);
            a.iter().map(|x| x / a[0]).collect()
        }
        Kind::CosinePower { exponent } => {
            let p = f64::from(exponent);
            coefficients(|t| if t > 0.0 { (p + 1.0) / (2.0 * PI) * t.powf(p) } else { 0.0 }, count)
        }
    }
}

/// The model's Legendre coefficients by quadrature: kernel `K_l` and footprint gains `g_l`.
fn model(kind: Kind, lambda: f64, count: usize) -> (Vec<f64>, Vec<f64>) {
    let g = gains(kind, count);
    let s = sg_coefficients(lambda, count);
    let k = match kind {
        // The SG of sharpness ν deconvolved by the footprint.
        Kind::Gaussian { .. } => s.iter().zip(&g).map(|(a, b)| a / b).collect(),
        _ => s,
    };
    (k, g)
}

fn series(a: &[f64], t: f64) -> f64 {
    a.iter().enumerate().map(|(l, c)| c * (2 * l + 1) as f64 / (4.0 * PI) * legendre(l, t)).sum()
}

#[test]
fn gains_match_quadrature() {
    let mut worst = 0.0f64;
    for kind in [
        Kind::Gaussian { sharpness: 1 },
        Kind::Gaussian { sharpness: 8 },
        Kind::Gaussian { sharpness: 128 },
        Kind::CosinePower { exponent: 1 },
        Kind::CosinePower { exponent: 4 },
    ] {
        let want = gains(kind, 60);
        let gen_gains = match kind {
            Kind::Gaussian { sharpness } => gen::probe::bessel_ratios(f64::from(sharpness), 60),
            Kind::CosinePower { exponent } => gen::probe::cosine_power_gains(exponent, 60),
            _ => unreachable!(),
        };
        for (l, w) in want.iter().enumerate() {
            let lib = kind.gain(l).unwrap();
            worst = worst.max((lib - w).abs()).max((gen_gains[l] - w).abs());
            // Two-sided: absolute 10⁻¹³ and, where the gain is not tiny, relative 10⁻¹¹.
            let tol = 1e-13f64.max(1e-11 * w.abs());
            assert!((lib - w).abs() < tol, "{kind:?} l = {l}: {lib} vs {w}");
            assert!((gen_gains[l] - w).abs() < tol, "gen {kind:?} l = {l}");
        }
    }
    println!("gains: worst |library − quadrature| = {worst:.1e}");
    assert_eq!(Kind::Point.gain(7), Ok(1.0));
    assert_eq!(Kind::Gaussian { sharpness: 0 }.gain(1), Err(Error::InvalidResponse));
    assert_eq!(Kind::CosinePower { exponent: 5000 }.gain(1), Err(Error::InvalidResponse));
    assert_eq!(Kind::Gaussian { sharpness: 2 }.gain(2000), Err(Error::InvalidResponse));
}

#[test]
fn generator_model_matches_the_series() {
    let count = 200;
    let c = coefficients(|t: f64| t.max(0.0), count);
    for (fp, kind, lambda) in [
        (gen::probe::Footprint::Gaussian(8), Kind::Gaussian { sharpness: 8 }, 1.0),
        (gen::probe::Footprint::Gaussian(8), Kind::Gaussian { sharpness: 8 }, 6.0),
        (gen::probe::Footprint::Gaussian(32), Kind::Gaussian { sharpness: 32 }, 24.0),
        (gen::probe::Footprint::Cosine(1), Kind::CosinePower { exponent: 1 }, 1.0),
        (gen::probe::Footprint::Cosine(1), Kind::CosinePower { exponent: 1 }, 64.0),
    ] {
        let m = gen::probe::Model::new(fp, lambda).unwrap();
        let (k, g) = model(kind, lambda, count);
        let cov: Vec<f64> = k.iter().zip(&g).map(|(k, g)| k * g * g).collect();
        let irr: Vec<f64> = k.iter().zip(&g).zip(&c).map(|((k, g), c)| k * g * c).collect();
        let scale = series(&cov, 1.0);
        let mut worst = [0.0f64; 4];
        for i in 0..=200 {
            let t = -1.0 + i as f64 / 100.0;
            let d2 = 2.0 - 2.0 * t;
            worst[0] = worst[0].max((m.sample_covariance(t, d2) - series(&cov, t)).abs() / scale);
            let irr_scale = series(&irr, 1.0);
            worst[1] =
                worst[1].max((m.irradiance_covariance(t) - series(&irr, t)).abs() / irr_scale);
        }
        let vbar: f64 = k
            .iter()
            .zip(&c)
            .enumerate()
            .map(|(l, (k, c))| k * c * c * (2 * l + 1) as f64 / (4.0 * PI))
            .sum();
        worst[2] = (m.irradiance_vbar() - vbar).abs() / vbar;
        for mu in [0.5, 20.0, 500.0] {
            let lobe = sg_coefficients(mu, count);
            let vg: f64 = k
                .iter()
                .zip(&lobe)
                .enumerate()
                .map(|(l, (k, b))| k * b * b * (2 * l + 1) as f64 / (4.0 * PI))
                .sum();
            worst[3] = worst[3].max((m.glossy_vbar(mu) - vg).abs() / vg);
            let zc: Vec<f64> = k.iter().zip(&g).zip(&lobe).map(|((k, g), b)| k * g * b).collect();
            let zs = series(&zc, 1.0);
            for i in 0..=40 {
                let t = -1.0 + i as f64 / 20.0;
                worst[3] = worst[3].max((m.glossy_covariance(mu, t) - series(&zc, t)).abs() / zs);
            }
        }
        println!("{kind:?} λ = {lambda}: sample cov {:.1e}, E cov {:.1e}, V̄ {:.1e}, glossy {:.1e} (relative to the peak)", worst[0], worst[1], worst[2], worst[3]);
        // The generator's closed forms and continued fractions against quadrature: f64
        // rounding in both (the point model's kernel mean is itself a quadrature, 1e-9).
        assert!(worst[0] < 1e-10, "{kind:?} λ = {lambda}: sample covariance {:e}", worst[0]);
        assert!(worst[1] < 1e-8, "{kind:?} λ = {lambda}: E covariance {:e}", worst[1]);
        assert!(worst[2] < 1e-8, "{kind:?} λ = {lambda}: V̄ {:e}", worst[2]);
        assert!(worst[3] < 1e-8, "{kind:?} λ = {lambda}: glossy {:e}", worst[3]);
    }
}

/// The footprint probe's f64 twin: full `Q` from the quadrature series, LU solves.
struct RefProbe {
    xs: Vec<[f64; 3]>,
    q: Vec<f64>,
    k: Vec<f64>,
    g: Vec<f64>,
}

impl RefProbe {
    fn new(rotation: [[f64; 3]; 3], n: usize, kind: Kind, lambda: f64, sigma: f64) -> Self {
        let xs: Vec<[f64; 3]> = (0..n as u64)
            .map(|j| {
                reference::vec::mat_mul_vec(rotation, reference::sf::sphere_point(j, n as u64))
            })
            .collect();
        let (k, g) = model(kind, lambda, 160);
        let cov: Vec<f64> = k.iter().zip(&g).map(|(k, g)| k * g * g).collect();
        let mut q = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let t = reference::vec::dot(xs[i], xs[j]).clamp(-1.0, 1.0);
                q[i * n + j] = series(&cov, t) + if i == j { sigma * sigma } else { 0.0 };
            }
        }
        RefProbe { xs, q, k, g }
    }

    /// Posterior mean and unit variance of `∫ L·w` for a zonal weight with Legendre
    /// coefficients `w_l` about `axis`; also `rᵀQ⁻¹r`.
    fn estimate(&self, y: &[f64], w: &[f64], axis: [f64; 3]) -> (f64, f64, f64) {
        let (value, r2, unit, _) = self.estimate_with_sensitivity(y, w, axis);
        (value, r2, unit)
    }

    /// [`RefProbe::estimate`] and `‖Q‖∞·‖Q⁻¹ζ‖²`, the first-order sensitivity of `ζᵀQ⁻¹ζ` to a
    /// relative perturbation of `Q` (what storing its factor in f32 is).
    fn estimate_with_sensitivity(
        &self,
        y: &[f64],
        w: &[f64],
        axis: [f64; 3],
    ) -> (f64, f64, f64, f64) {
        let len = self.xs.len();
        let qi_y = reference::bmc::lu_solve(&self.q, len, y);
        let qi_1 = reference::bmc::lu_solve(&self.q, len, &vec![1.0; len]);
        let s1: f64 = qi_1.iter().sum();
        let beta = qi_y.iter().sum::<f64>() / s1;
        let alpha: Vec<f64> = qi_y.iter().zip(&qi_1).map(|(a, b)| a - beta * b).collect();
        let zc: Vec<f64> = self.k.iter().zip(&self.g).zip(w).map(|((k, g), w)| k * g * w).collect();
        let z: Vec<f64> =
            self.xs.iter().map(|&x| series(&zc, reference::vec::dot(x, axis))).collect();
        let integral = w[0];
        let value = beta * integral + z.iter().zip(&alpha).map(|(a, b)| a * b).sum::<f64>();
        let r2: f64 = y.iter().zip(&alpha).map(|(a, b)| a * b).sum();
        let qi_z = reference::bmc::lu_solve(&self.q, len, &z);
        let zqz: f64 = z.iter().zip(&qi_z).map(|(a, b)| a * b).sum();
        let one_z: f64 = qi_z.iter().sum();
        let vbar: f64 = self
            .k
            .iter()
            .zip(w)
            .enumerate()
            .map(|(l, (k, w))| k * w * w * (2 * l + 1) as f64 / (4.0 * PI))
            .sum();
        let norm_q = (0..len)
            .map(|i| self.q[i * len..(i + 1) * len].iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max);
        let sensitivity = norm_q * qi_z.iter().map(|x| x * x).sum::<f64>();
        (value, r2, vbar - zqz + (integral - one_z).powi(2) / s1, sensitivity)
    }
}

/// The normalised Phong lobe's Legendre coefficients by quadrature.
fn phong_coefficients(e: f64, count: usize) -> Vec<f64> {
    coefficients(|t| if t > 0.0 { (e + 1.0) / (2.0 * PI) * t.powf(e) } else { 0.0 }, count)
}

/// [`Probe::phong`] and [`Probe::phong_variance`] against the f64 twin, every member, Phong
/// exponents 0…1000; the same bars as `compare_with_reference`.
fn phong_against_reference<const N: usize, F: Footprint>()
where
    Size<N>: ProbeTables<F>,
{
    let mut rng = Rng::new(0x0F00_7001 + N as u64);
    let rotation = rng.uniform_rotation();
    let field = lights(&mut rng, 2.0, 20.0);
    for (k, member) in Probe::<N, f32, F>::family().enumerate() {
        let r =
            RefProbe::new(rotation, N, F::KIND, f64::from(member.lambda), f64::from(member.sigma));
        let y = if F::KIND == Kind::Point {
            r.xs.iter().map(|&x| field.iter().map(|l| l.value(x)).sum()).collect()
        } else {
            footprint_samples(&field, F::KIND, &r.xs)
        };
        let mut probe = Probe::<N, f32, F>::new();
        probe.set_rotation(mat3(rotation)).unwrap();
        let y32: [f32; N] = core::array::from_fn(|i| y[i] as f32);
        probe.update_with(&y32, Selection::Member(k)).unwrap();
        let mean = y.iter().sum::<f64>() / N as f64;
        let (mut value, mut var) = (0.0f64, 0.0f64);
        for e in [0.0, 1.0, 5.0, 20.0, 100.0, 1000.0] {
            let axis = rng.uniform_sphere();
            let w = phong_coefficients(e, 160);
            let (want, r2, unit, sensitivity) = r.estimate_with_sensitivity(&y, &w, axis);
            let got = probe.phong(to_vec3(axis), e as f32).unwrap();
            let v = probe.phong_variance(to_vec3(axis), e as f32).unwrap() as f64;
            let scale = r2 / (N as f64 - 1.0);
            // The model's variance times the member's documented calibration at μ = e + 2
            // (1 for footprint probes, which have no calibration lines).
            let want_var = scale * unit * glossy_calibration(&member, e + 2.0);
            value = value.max((f64::from(got.value) - want).abs() / want.abs().max(mean.abs()));
            // The variance is a difference V̄ − ζᵀQ⁻¹ζ: the f32 factor (backward error about
            // (N/2)·ε₃₂ from storage and the substitutions) moves ζᵀQ⁻¹ζ by up to
            // (N/2)·ε₃₂·‖Q‖·‖Q⁻¹ζ‖² to first order; beyond that, 1 %.
            let allowed =
                1e-2 * want_var + 0.5 * N as f64 * f64::from(f32::EPSILON) * sensitivity * scale;
            var = var.max((v - want_var).abs() / allowed);
            if std::env::var_os("FP_DEBUG").is_some() {
                println!("  e = {e}: variance {v:e} vs {want_var:e}; unit {unit:e}");
            }
        }
        let cond = f64::from(member.condition);
        println!(
            "phong N = {N} {:?} member {k} (λ = {}, cond {cond:.1e}): value {value:.1e}, variance {var:.2} of its bound",
            F::KIND,
            member.lambda
        );
        let bar = if cond <= 1e4 { 1e-5 } else { cond * f64::from(f32::EPSILON) };
        assert!(value < bar, "N = {N} {:?} member {k}: phong {value:e} (bar {bar:e})", F::KIND);
        assert!(var < 1.0, "N = {N} {:?} member {k}: phong variance {var:e} of its bound", F::KIND);
    }
}

#[test]
fn phong_queries_match_the_f64_reference() {
    phong_against_reference::<16, Point>();
    phong_against_reference::<64, Point>();
    phong_against_reference::<16, Gaussian<2>>();
    phong_against_reference::<64, Gaussian<8>>();
    phong_against_reference::<16, CosinePower<1>>();
}

#[test]
fn phong_of_a_constant_is_the_constant() {
    let mut probe = Probe::<64, f32, Gaussian<8>>::new();
    probe.update(&[1.75; 64]).unwrap();
    for e in [0.0f32, 5.0, 300.0] {
        let p = probe.phong(Vec3::new(0.2, 0.3, -0.9), e).unwrap();
        assert!((p.value / 1.75 - 1.0).abs() < 1e-6, "e = {e}: {}", p.value);
        assert_eq!(p.variance, 0.0);
    }
    assert_eq!(probe.phong(Vec3::ZERO, 5.0).unwrap_err(), Error::InvalidDirection);
    assert_eq!(probe.phong(Vec3::Z, -1.0).unwrap_err(), Error::InvalidExponent);
    assert_eq!(probe.phong(Vec3::Z, f32::NAN).unwrap_err(), Error::InvalidExponent);
    assert_eq!(probe.phong_variance(Vec3::Z, f32::INFINITY).unwrap_err(), Error::InvalidExponent);
}

/// Footprint samples of a light with Legendre-expandable structure: sums of SG lights, each
/// sample `∫ L·f(xᵢ·y) dy = Σ a·Σ_l S_l(λ)·g_l·(2l + 1)/(4π)·P_l(xᵢ·μ)` by the series.
fn footprint_samples(lights: &[SgLight], kind: Kind, xs: &[[f64; 3]]) -> Vec<f64> {
    let g = gains(kind, 160);
    let coefficients: Vec<Vec<f64>> =
        lights.iter().map(|l| sg_coefficients(l.sharpness, 160)).collect();
    xs.iter()
        .map(|&x| {
            lights
                .iter()
                .zip(&coefficients)
                .map(|(l, s)| {
                    let a: Vec<f64> = s.iter().zip(&g).map(|(s, g)| s * g).collect();
                    l.amplitude * series(&a, reference::vec::dot(x, l.axis))
                })
                .sum::<f64>()
        })
        .collect()
}

/// Three SG lights of sharpness in `[lo, hi]`.
fn lights(rng: &mut Rng, lo: f64, hi: f64) -> Vec<SgLight> {
    (0..3)
        .map(|_| SgLight {
            axis: rng.uniform_sphere(),
            sharpness: lo + (hi - lo) * rng.next_f64(),
            amplitude: 0.5 + rng.next_f64(),
        })
        .collect()
}

fn to_vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

fn mat3(r: [[f64; 3]; 3]) -> Mat3 {
    Mat3::from_rows(to_vec3(r[0]), to_vec3(r[1]), to_vec3(r[2]))
}

/// Every member of `Probe<N, f32, F>` against its f64 twin: irradiance (RMS over queries,
/// relative to the mean |E|), glossy values (worst query, relative) and both variances
/// (worst, relative; glossy relative to the larger of |value| and the lobe's integral of the
/// mean sample). Asserts the point probe's bars (`tests/probe/probe.rs`): 10⁻⁵ for members
/// with cond(Q) ≤ 10⁴, else the forward bound cond(Q)·ε₃₂; variances to 10⁻².
fn compare_with_reference<const N: usize, F: Footprint>()
where
    Size<N>: ProbeTables<F>,
{
    let mut rng = Rng::new(0x0F00_7000 + N as u64);
    let rotation = rng.uniform_rotation();
    let field = lights(&mut rng, 2.0, 20.0);
    let c = coefficients(|t: f64| t.max(0.0), 160);
    for (k, member) in Probe::<N, f32, F>::family().enumerate() {
        let r =
            RefProbe::new(rotation, N, F::KIND, f64::from(member.lambda), f64::from(member.sigma));
        let y = footprint_samples(&field, F::KIND, &r.xs);
        let mut probe = Probe::<N, f32, F>::new();
        probe.set_rotation(mat3(rotation)).unwrap();
        let y32: [f32; N] = core::array::from_fn(|i| y[i] as f32);
        probe.update_with(&y32, Selection::Member(k)).unwrap();
        let (mut sq, mut mean, mut glossy, mut var) = (0.0, 0.0, 0.0f64, 0.0f64);
        let queries = 8;
        for q in 0..queries {
            let n = rng.uniform_sphere();
            let (want, r2, unit) = r.estimate(&y, &c, n);
            let got = probe.irradiance(to_vec3(n)).unwrap().value as f64;
            let v = probe.irradiance_variance(to_vec3(n)).unwrap() as f64;
            let want_var = r2 / (N as f64 - 1.0) * unit;
            sq += (got - want).powi(2);
            mean += want.abs();
            var = var.max((v - want_var).abs() / want_var);
            // Glossy: unit-amplitude SG lobes of sharpness 0.5…200.
            let mu = [0.5, 5.0, 22.0, 60.0, 200.0, 3.0, 102.0, 7.0][q];
            let lobe = sg_coefficients(mu, 160);
            let (gwant, _, gunit) = r.estimate(&y, &lobe, n);
            let sgl = SphericalGaussian::new(to_vec3(n), mu as f32, 1.0).unwrap();
            let ggot = probe.glossy(&sgl).unwrap().value as f64;
            let gvar = probe.glossy_variance(&sgl).unwrap() as f64;
            let gwant_var = r2 / (N as f64 - 1.0) * gunit;
            // Relative to the lobe's integral of the mean sample (a value crossing zero
            // has no relative error of its own).
            let scale = gwant.abs().max(lobe[0] * y.iter().sum::<f64>() / N as f64);
            glossy = glossy.max((ggot - gwant).abs() / scale);
            if std::env::var_os("FP_DEBUG").is_some() {
                println!(
                    "  μ = {mu}: got {ggot} want {gwant} rel {:.1e}; E {got} vs {want}",
                    (ggot - gwant).abs() / gwant.abs()
                );
            }
            var = var.max((gvar - gwant_var).abs() / gwant_var);
        }
        let rms = (sq / queries as f64).sqrt() / (mean / queries as f64);
        let cond = f64::from(member.condition);
        println!(
            "N = {N} {:?} member {k} (λ = {}, cond {cond:.1e}): E {rms:.1e} RMS, glossy {glossy:.1e}, variances {var:.1e}",
            F::KIND,
            member.lambda
        );
        let bar = if cond <= 1e4 { 1e-5 } else { cond * f64::from(f32::EPSILON) };
        assert!(rms < bar, "N = {N} {:?} member {k}: E {rms:e} (bar {bar:e})", F::KIND);
        assert!(glossy < bar, "N = {N} {:?} member {k}: glossy {glossy:e} (bar {bar:e})", F::KIND);
        assert!(var < 1e-2, "N = {N} {:?} member {k}: variance {var:e}", F::KIND);
    }
}

#[test]
fn footprint_probes_match_the_f64_reference() {
    compare_with_reference::<16, Gaussian<2>>();
    compare_with_reference::<64, Gaussian<8>>();
    compare_with_reference::<16, CosinePower<1>>();
    compare_with_reference::<32, CosinePower<1>>();
}

fn constants_exact<const N: usize, F: Footprint>()
where
    Size<N>: ProbeTables<F>,
{
    let mut probe = Probe::<N, f32, F>::new();
    probe.update(&[2.5; N]).unwrap();
    let e = probe.irradiance(Vec3::new(0.3, -0.2, 0.9)).unwrap();
    assert!((e.value / (2.5 * std::f32::consts::PI) - 1.0).abs() < 1e-6, "{:?}", F::KIND);
    assert_eq!(e.variance, 0.0);
    let lobe = SphericalGaussian::new(Vec3::X, 20.0, 1.5).unwrap();
    let g = probe.glossy(&lobe).unwrap();
    let want = 2.5 * lobe.integral();
    assert!((g.value / want - 1.0).abs() < 1e-6, "{:?}: {} vs {want}", F::KIND, g.value);
    assert_eq!(probe.glossy_variance(&lobe).unwrap(), 0.0);
}

#[test]
fn constants_are_integrated_exactly() {
    constants_exact::<16, Gaussian<2>>();
    constants_exact::<64, Gaussian<8>>();
    constants_exact::<256, Gaussian<32>>();
    constants_exact::<16, CosinePower<1>>();
    constants_exact::<32, CosinePower<1>>();
}

#[test]
fn footprint_tables_cost_what_the_point_tables_cost() {
    assert_eq!(Probe::<64, f32, Gaussian<8>>::TABLE_BYTES, Probe::<64>::TABLE_BYTES);
    assert_eq!(Probe::<16, f32, CosinePower<1>>::TABLE_BYTES, Probe::<16>::TABLE_BYTES);
    assert_eq!(Probe::<64, f32, Gaussian<8>>::footprint(), Kind::Gaussian { sharpness: 8 });
    assert_eq!(Probe::<64>::footprint(), Kind::Point);
    assert_eq!(Probe::<64, f32, Point>::footprint(), Kind::Point);
    let baked = sphere_quadrature::probe::BAKED_TABLES;
    assert!(baked.contains(&(64, Kind::Gaussian { sharpness: 8 })));
    assert!(baked.contains(&(16, Kind::CosinePower { exponent: 1 })));
}

#[test]
fn bad_input_keeps_the_data() {
    let mut probe = Probe::<16, f32, CosinePower<1>>::new();
    let y: [f32; 16] = core::array::from_fn(|i| 1.0 + 0.1 * i as f32);
    probe.update(&y).unwrap();
    let before = probe.irradiance(Vec3::Z).unwrap();
    let mut bad = y;
    bad[3] = f32::NAN;
    assert_eq!(probe.update(&bad), Err(Error::InvalidRadiance));
    assert_eq!(probe.irradiance(Vec3::Z).unwrap(), before);
    assert_eq!(probe.irradiance(Vec3::ZERO), Err(Error::InvalidDirection));
    let lobe = SphericalGaussian { axis: Vec3::Z, sharpness: -1.0, amplitude: 1.0 };
    assert_eq!(probe.glossy(&lobe).unwrap_err(), Error::InvalidSharpness);
    // Huge and zero sharpness take the forward recurrence and the constant path: finite.
    for mu in [0.0, 1e-6, 39.0, 41.0, 1e4, 1e8] {
        let lobe = SphericalGaussian { axis: Vec3::Y, sharpness: mu, amplitude: 1.0 };
        let g = probe.glossy(&lobe).unwrap();
        let v = probe.glossy_variance(&lobe).unwrap();
        assert!(g.value.is_finite() && g.variance >= 0.0 && v >= 0.0, "μ = {mu}: {g:?} {v}");
    }
}

/// On small light sources (SG lights of sharpness 100–300, which point samples alias),
/// footprint samples with footprint-aware BMC against the cosine-weighted average of point
/// samples in the same directions, and against BMC with the point model on the same footprint
/// samples ("the model must know the footprint").
#[test]
fn footprint_bmc_beats_point_samples_on_small_lights() {
    let mut rng = Rng::new(11);
    let (mut e_fp, mut e_point, mut e_point_model) = (0.0, 0.0, 0.0);
    for _ in 0..8 {
        let field = lights(&mut rng, 100.0, 300.0);
        let rotation = rng.uniform_rotation();
        let mut probe = Probe::<64, f32, Gaussian<8>>::new();
        probe.set_rotation(mat3(rotation)).unwrap();
        let mut point_model = Probe::<64>::new();
        point_model.set_rotation(mat3(rotation)).unwrap();
        let xs: Vec<[f64; 3]> = probe
            .directions()
            .iter()
            .map(|d| [f64::from(d.x), f64::from(d.y), f64::from(d.z)])
            .collect();
        let y = footprint_samples(&field, Kind::Gaussian { sharpness: 8 }, &xs);
        let y32: [f32; 64] = core::array::from_fn(|i| y[i] as f32);
        let yp: Vec<f32> =
            xs.iter().map(|&x| field.iter().map(|l| l.value(x)).sum::<f64>() as f32).collect();
        probe.update(&y32).unwrap();
        point_model.update(&y32).unwrap();
        for _ in 0..16 {
            let n = rng.uniform_sphere();
            let truth: f64 = field.iter().map(|l| l.irradiance(n)).sum();
            let nv = to_vec3(n);
            let fp = probe.irradiance(nv).unwrap().value as f64;
            let pt = cosine_weighted_average(probe.directions(), &yp, nv).unwrap() as f64;
            let pm = point_model.irradiance(nv).unwrap().value as f64;
            e_fp += (fp - truth).powi(2);
            e_point += (pt - truth).powi(2);
            e_point_model += (pm - truth).powi(2);
        }
    }
    let ratio = (e_fp / e_point).sqrt();
    let model_ratio = (e_fp / e_point_model).sqrt();
    println!(
        "small lights, N = 64, S = 8: footprint BMC / point cosine average = {ratio:.4}, / point-model BMC on the same samples = {model_ratio:.4}"
    );
    // The bar for the worst real map (0.25), and a clear win over the point model.
    assert!(ratio < 0.25, "{ratio}");
    assert!(model_ratio < 0.5, "{model_ratio}");
}
