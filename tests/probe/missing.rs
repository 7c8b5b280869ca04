//! Missing samples (issue #14, item 3): `Probe::update_masked` against an independent f64
//! reference that builds `Q_VV` from the valid directions alone and the member's `(λ, σ′)`,
//! and solves it by LU (no baked factor, no block split, no Schur complement).

use reference::analytic::SgLight;
use reference::rng::Rng;
use sphere_quadrature::bmc::Size;
use sphere_quadrature::footprint::{Gaussian, Point};
use sphere_quadrature::probe::{Probe, ProbeSize, Selection};
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::{Error, Mat3, Radiance, Vec3};
use std::f64::consts::PI;

/// The f64 model of the valid samples alone.
struct Subset {
    xs: Vec<[f64; 3]>,
    lambda: f64,
    /// `Q_VV`, and its factors by LU with partial pivoting.
    q: Vec<f64>,
    lu: reference::bmc::Lu,
}

/// The GLS fit of the valid samples.
struct Fit {
    alpha: Vec<f64>,
    beta: f64,
    /// `rᵀQ_VV⁻¹r`.
    r2: f64,
    /// `1ᵀQ_VV⁻¹1`.
    s1: f64,
    /// REML log likelihood `−½·log det Q_VV − ½·log s₁ − ((n − 1)/2)·log rᵀQ_VV⁻¹r`.
    ll: f64,
    /// `V̄` of the cosine lobe (irradiance), once per fit.
    vbar: f64,
}

impl Subset {
    /// The reference crate's points of the `n`-point set, rotated, at the valid indices.
    fn new(rotation: [[f64; 3]; 3], valid: &[bool], lambda: f64, sigma: f64) -> Self {
        let n = valid.len() as u64;
        let xs: Vec<[f64; 3]> = (0..n)
            .filter(|&j| valid[j as usize])
            .map(|j| reference::vec::mat_mul_vec(rotation, reference::sf::sphere_point(j, n)))
            .collect();
        let len = xs.len();
        let mut q = vec![0.0; len * len];
        for i in 0..len {
            for j in 0..len {
                let c = reference::vec::dot(xs[i], xs[j]);
                q[i * len + j] =
                    (lambda * (c - 1.0)).exp() + if i == j { sigma * sigma } else { 0.0 };
            }
        }
        let lu = reference::bmc::Lu::new(&q, len);
        Subset { xs, lambda, q, lu }
    }

    fn len(&self) -> usize {
        self.xs.len()
    }

    fn solve(&self, b: &[f64]) -> Vec<f64> {
        self.lu.solve(b)
    }

    /// The fit to the valid samples `y` (in the order of `xs`).
    fn fit(&self, y: &[f64]) -> Fit {
        let len = self.len();
        let qi_y = self.solve(y);
        let qi_1 = self.solve(&vec![1.0; len]);
        let s1: f64 = qi_1.iter().sum();
        let beta = qi_y.iter().sum::<f64>() / s1;
        let alpha: Vec<f64> = qi_y.iter().zip(&qi_1).map(|(a, b)| a - beta * b).collect();
        let r2: f64 = y.iter().zip(&alpha).map(|(a, b)| a * b).sum();
        let ll = -0.5 * self.lu.log_abs_det() - 0.5 * s1.ln() - 0.5 * (len as f64 - 1.0) * r2.ln();
        Fit { alpha, beta, r2, s1, ll, vbar: reference::bmc::kernel_mean_mean(self.lambda) }
    }

    /// `V̄ − ζᵀQ_VV⁻¹ζ + (I − 1ᵀQ_VV⁻¹ζ)²/s₁` for the valid samples' `ζ`.
    fn unit_variance(&self, fit: &Fit, zeta: &[f64], integral: f64, vbar: f64) -> f64 {
        let qi_z = self.solve(zeta);
        let zqz: f64 = zeta.iter().zip(&qi_z).map(|(a, b)| a * b).sum();
        let one: f64 = qi_z.iter().sum();
        vbar - zqz + (integral - one).powi(2) / fit.s1
    }

    /// Irradiance `E(n)` and its unit variance (`V̄` of the cosine lobe from `fit`).
    fn irradiance(&self, fit: &Fit, n: [f64; 3]) -> (f64, f64) {
        let z: Vec<f64> = self
            .xs
            .iter()
            .map(|&x| reference::bmc::kernel_mean(self.lambda, reference::vec::dot(x, n)))
            .collect();
        let e = PI * (fit.beta + z.iter().zip(&fit.alpha).map(|(a, b)| a * b).sum::<f64>());
        let v = self.unit_variance(fit, &z, 1.0, fit.vbar);
        (e, PI * PI * v)
    }

    /// `∫ L·p` and the unit variance for a zonal weight `p(r·x)` about `r` (nonzero for polar
    /// angles up to `top`), its integral, `zᵢ` and `V̄` by quadrature ([`polar_gl`],
    /// [`zonal_cross`]).
    fn zonal(&self, fit: &Fit, r: [f64; 3], p: &dyn Fn(f64) -> f64, top: f64) -> (f64, f64) {
        let integral = polar_gl(p, top, |_| 1.0);
        let z: Vec<f64> = self
            .xs
            .iter()
            .map(|&x| zonal_cross(self.lambda, p, top, reference::vec::dot(x, r)))
            .collect();
        let vbar = polar_gl(p, top, |c| zonal_cross(self.lambda, p, top, c));
        let value = fit.beta * integral + z.iter().zip(&fit.alpha).map(|(a, b)| a * b).sum::<f64>();
        (value, self.unit_variance(fit, &z, integral, vbar))
    }
}

/// `2π∫₀^π p(cos θ)·g(cos θ)·sin θ dθ` by composite Simpson, 4000 intervals, graded towards
/// θ = 0 (θ = π·u², so sharp lobes about the pole are resolved).
fn polar(p: &dyn Fn(f64) -> f64, g: impl Fn(f64) -> f64) -> f64 {
    let m = 4000;
    let h = 1.0 / m as f64;
    let mut sum = 0.0;
    for i in 0..=m {
        let u = i as f64 * h;
        let th = PI * u * u;
        let w = if i == 0 || i == m {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let c = th.cos();
        sum += w * th.sin() * p(c) * g(c) * 2.0 * PI * u;
    }
    2.0 * PI * sum * h / 3.0
}

/// The integral of [`polar`] over `θ ∈ [0, top]` by Gauss–Legendre, 24 panels of 20 points,
/// `top` where `p` ends (π/2 for the clamped Phong lobes, whose kink Simpson's rule straddled):
/// the rule of the lobes' integrals, of `zᵢ` and, as the outer rule, of `V̄ = ∫ p·z`.
fn polar_gl(p: &dyn Fn(f64) -> f64, top: f64, g: impl Fn(f64) -> f64) -> f64 {
    reference::quad::zonal_gl(top, 24, |c| p(c) * g(c))
}

/// `∫ exp(λ(a·x − 1))·p(b·x) dx` for `a·b = t`: `b` at the pole, the azimuth by `2π·I₀`, the
/// polar angle by [`polar_gl`] over `[0, top]`, where `p` is nonzero.
fn zonal_cross(lambda: f64, p: &dyn Fn(f64) -> f64, top: f64, t: f64) -> f64 {
    let t = t.clamp(-1.0, 1.0);
    let s = (1.0 - t * t).sqrt();
    polar_gl(p, top, |c| {
        let sn = (1.0 - c * c).max(0.0).sqrt();
        (lambda * (c * t + sn * s - 1.0)).exp() * reference::special::bessel_i0e(lambda * sn * s)
    })
}

/// A smooth random radiance field: a constant plus a few SG lobes.
fn field(rng: &mut Rng) -> Vec<SgLight> {
    (0..3)
        .map(|_| SgLight {
            axis: rng.uniform_sphere(),
            sharpness: 2.0 + 18.0 * rng.next_f64(),
            amplitude: 0.2 + 0.8 * rng.next_f64(),
        })
        .collect()
}

fn radiance(lights: &[SgLight], d: [f64; 3]) -> f64 {
    0.3 + lights.iter().map(|l| l.value(d)).sum::<f64>()
}

fn mat3(r: [[f64; 3]; 3]) -> Mat3 {
    let row = |v: [f64; 3]| Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
    Mat3::from_rows(row(r[0]), row(r[1]), row(r[2]))
}

fn to64(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

fn to32(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

/// A seeded random subset of `missing` of the `N` samples: `false` there.
fn random_mask<const N: usize>(rng: &mut Rng, missing: usize) -> [bool; N] {
    let mut order: Vec<usize> = (0..N).collect();
    for i in 0..missing {
        let j = i + (rng.next_u64() % (N - i) as u64) as usize;
        order.swap(i, j);
    }
    let mut valid = [true; N];
    for &j in &order[..missing] {
        valid[j] = false;
    }
    valid
}

/// Every answer of a probe as f32 bits (values, both kinds of variance, glossy and Phong
/// queries, σ̂_f², the channel covariance, ℓ, the member and the missing indices), for
/// bit-for-bit comparisons.
fn fingerprint<const N: usize, T: Radiance, const M: usize>(p: &Probe<N, T, Point, M>) -> Vec<u32>
where
    Size<N>: ProbeSize,
{
    let mut out = Vec::new();
    let mut push = |x: T| out.extend((0..T::CHANNELS).map(|c| x.channel(c).to_bits()));
    for n in [Vec3::Z, Vec3::new(0.3, -0.4, 0.5), Vec3::new(-0.8, 0.1, -0.2)] {
        let e = p.irradiance(n).unwrap();
        push(e.value);
        push(e.variance);
        push(p.irradiance_variance(n).unwrap());
    }
    let lobe = SphericalGaussian::phong_moments(Vec3::new(0.6, 0.0, 0.8), 20.0).unwrap();
    let g = p.glossy(&lobe).unwrap();
    push(g.value);
    push(g.variance);
    push(p.glossy_variance(&lobe).unwrap());
    let ph = p.phong(Vec3::new(-0.2, 0.9, 0.1), 3.0).unwrap();
    push(ph.value);
    push(ph.variance);
    push(p.phong_variance(Vec3::new(-0.2, 0.9, 0.1), 3.0).unwrap());
    push(p.signal_variance());
    push(p.mean_irradiance());
    for a in 0..T::CHANNELS {
        for b in 0..T::CHANNELS {
            out.push(p.signal_covariance(a, b).unwrap().to_bits());
        }
    }
    out.push(p.log_likelihood().to_bits());
    out.push(p.selected() as u32);
    out.extend(p.missing().iter().map(|&j| u32::from(j)));
    out
}

/// The samples of `lights` in the probe's directions, NaN where `valid` is false.
fn masked_samples<const N: usize, const M: usize>(
    probe: &Probe<N, f32, Point, M>,
    lights: &[SgLight],
    valid: &[bool; N],
) -> [f32; N]
where
    Size<N>: ProbeSize,
{
    core::array::from_fn(|i| {
        if valid[i] {
            radiance(lights, to64(probe.directions()[i])) as f32
        } else {
            f32::NAN
        }
    })
}

fn valid_values(y: &[f32], valid: &[bool]) -> Vec<f64> {
    y.iter().zip(valid).filter(|(_, &ok)| ok).map(|(&v, _)| v as f64).collect()
}

/// The value bar of `tests/probe/probe.rs`: 10⁻⁵ relative for members with `cond(Q) ≤ 10⁴`, the
/// forward bound `cond(Q)·ε₃₂` for the smoother ones.
fn value_bar(cond: f32) -> f64 {
    if cond <= 1e4 {
        1e-5
    } else {
        f64::from(cond) * f64::from(f32::EPSILON)
    }
}

/// One random rotation, field and mask of `missing` of the `N` samples (drawn in that order):
/// a probe of capacity `M` set to the rotation, the field's samples in its directions (NaN
/// where missing) and the valid ones.
struct Masked<const N: usize, const M: usize>
where
    Size<N>: ProbeSize,
{
    rot: [[f64; 3]; 3],
    probe: Probe<N, f32, Point, M>,
    valid: [bool; N],
    y: [f32; N],
    y_valid: Vec<f64>,
}

fn masked<const N: usize, const M: usize>(rng: &mut Rng, missing: usize) -> Masked<N, M>
where
    Size<N>: ProbeSize,
{
    let rot = rng.uniform_rotation();
    let mut probe = Probe::<N, f32, Point, M>::new();
    probe.set_rotation(mat3(rot)).unwrap();
    let lights = field(rng);
    let valid = random_mask::<N>(rng, missing);
    let y = masked_samples(&probe, &lights, &valid);
    let y_valid = valid_values(&y, &valid);
    Masked { rot, probe, valid, y, y_valid }
}

/// Every member on one random field, rotation and mask of `missing` samples against the
/// reference: irradiance (RMS over `queries` normals relative to the mean |E|, held to
/// [`value_bar`]), its exact variance (10⁻², as `tests/probe/probe.rs`), σ̂_f² and ℓ (10⁻⁴
/// relative, or [`value_bar`] if larger); each printed.
fn compare<const N: usize, const M: usize>(rng: &mut Rng, missing: usize, queries: usize)
where
    Size<N>: ProbeSize,
{
    let Masked { rot, mut probe, valid, y, y_valid } = masked::<N, M>(rng, missing);
    let normals: Vec<[f64; 3]> = (0..queries).map(|_| rng.uniform_sphere()).collect();
    let count = (N - missing) as f64;
    for (k, m) in Probe::<N>::family().enumerate() {
        probe.update_masked_with(&y, &valid, Selection::Member(k)).unwrap();
        assert_eq!(probe.missing().len(), missing);
        let sub = Subset::new(rot, &valid, m.lambda as f64, m.sigma as f64);
        let fit = sub.fit(&y_valid);
        let refs: Vec<(f64, f64)> = normals.iter().map(|&n| sub.irradiance(&fit, n)).collect();
        let mean = refs.iter().map(|r| r.0.abs()).sum::<f64>() / refs.len() as f64;
        let (mut sq, mut worst_v) = (0.0f64, 0.0f64);
        for (&n, &(e, v)) in normals.iter().zip(&refs) {
            let got = probe.irradiance(to32(n)).unwrap();
            sq += ((got.value as f64 - e) / mean).powi(2);
            let want = fit.r2 / (count - 1.0) * v * f64::from(m.calibration[0]);
            let var = probe.irradiance_variance(to32(n)).unwrap() as f64;
            worst_v = worst_v.max((var - want).abs() / want);
        }
        let rms = (sq / queries as f64).sqrt();
        let want_s = fit.r2 / (count - 1.0);
        let signal = (probe.signal_variance() as f64 - want_s).abs() / want_s;
        let ll = (probe.log_likelihood() as f64 - fit.ll).abs() / fit.ll.abs().max(1.0);
        let what =
            format!("N = {N}, {missing} missing, λ = {} (cond {:.1e})", m.lambda, m.condition);
        println!(
            "{what}: |ΔE| RMS {rms:.2e} (bar {:.0e}), Δvariance {worst_v:.2e}, Δσ̂² {signal:.2e}, \
             Δℓ {ll:.2e}",
            value_bar(m.condition)
        );
        assert!(rms < value_bar(m.condition), "{what}: E differs by {rms:e} RMS");
        assert!(worst_v < 1e-2, "{what}: exact variance differs by {worst_v:e}");
        // σ̂_f² and ℓ: 10⁻⁴ relative, or the forward bound for the smoothest members (the
        // f32 factor D of P_MM enters log det Q_VV through m terms).
        let bar = value_bar(m.condition).max(1e-4);
        assert!(signal < bar, "{what}: σ̂_f² differs by {signal:e}");
        assert!(ll < bar, "{what}: ℓ differs by {ll:e}");
    }
}

#[test]
fn masked_update_matches_the_f64_reference() {
    let mut rng = Rng::new(0x4D15);
    for missing in [1, 4, 8] {
        compare::<16, 8>(&mut rng, missing, 16);
    }
    for missing in [2, 8, 16, 32] {
        compare::<64, 32>(&mut rng, missing, 16);
    }
    // The reference factors Q_VV afresh for every solve: few queries at N = 256.
    for missing in [13, 64, 128] {
        compare::<256, 128>(&mut rng, missing, 4);
    }
}

/// A mask that removes sample 0 (the centre of `update`'s normalisation), the last sample,
/// and both samples of several mirrored pairs (`j` and `N − 1 − j` share the baked blocks'
/// pair `j`).
#[test]
fn masks_with_mirrored_pairs_and_the_first_sample() {
    let mut rng = Rng::new(0x9A1);
    let rot = rng.uniform_rotation();
    let lights = field(&mut rng);
    let mut probe = Probe::<32, f32, Point, 12>::new();
    probe.set_rotation(mat3(rot)).unwrap();
    let mut valid = [true; 32];
    for j in [0, 31, 5, 26, 6, 25, 15, 16, 9] {
        valid[j] = false;
    }
    let y = masked_samples(&probe, &lights, &valid);
    let y_valid = valid_values(&y, &valid);
    for (k, m) in Probe::<32>::family().enumerate() {
        probe.update_masked_with(&y, &valid, Selection::Member(k)).unwrap();
        assert_eq!(probe.missing(), &[0, 5, 6, 9, 15, 16, 25, 26, 31]);
        let sub = Subset::new(rot, &valid, m.lambda as f64, m.sigma as f64);
        let fit = sub.fit(&y_valid);
        for _ in 0..8 {
            let n = rng.uniform_sphere();
            let (e, v) = sub.irradiance(&fit, n);
            let got = probe.irradiance(to32(n)).unwrap().value as f64;
            assert!((got - e).abs() < 10.0 * value_bar(m.condition) * e.abs(), "λ = {}", m.lambda);
            let want = fit.r2 / 22.0 * v * f64::from(m.calibration[0]);
            let var = probe.irradiance_variance(to32(n)).unwrap() as f64;
            assert!((var - want).abs() < 1e-2 * want, "λ = {}: {var} vs {want}", m.lambda);
        }
        assert!((probe.log_likelihood() as f64 - fit.ll).abs() < 1e-4 * fit.ll.abs().max(1.0));
    }
}

/// Glossy (the SG lobe, O(N) value and exact variance) and Phong (value and exact variance)
/// queries of a masked probe against the reference's quadrature of the lobes.
#[test]
fn masked_glossy_and_phong_match_the_f64_reference() {
    let mut rng = Rng::new(0x6105);
    let Masked { rot, mut probe, valid, y, y_valid } = masked::<64, 16>(&mut rng, 16);
    for (k, m) in Probe::<64>::family().enumerate() {
        probe.update_masked_with(&y, &valid, Selection::Member(k)).unwrap();
        let sub = Subset::new(rot, &valid, m.lambda as f64, m.sigma as f64);
        let fit = sub.fit(&y_valid);
        let noise = fit.r2 / 47.0;
        let bar = 10.0 * value_bar(m.condition);
        for mu in [0.0f64, 5.0, 40.0] {
            let r = rng.uniform_sphere();
            let p = move |c: f64| (mu * (c - 1.0)).exp();
            let (want, v) = sub.zonal(&fit, r, &p, PI);
            let lobe = SphericalGaussian { axis: to32(r), sharpness: mu as f32, amplitude: 1.0 };
            let got = probe.glossy(&lobe).unwrap().value as f64;
            let cal = glossy_calibration(&m.calibration, mu);
            let var = probe.glossy_variance(&lobe).unwrap() as f64;
            let want_var = noise * v * cal;
            println!(
                "λ = {}, μ = {mu}: glossy {got:.6e} (ref {want:.6e}), variance {var:.4e} (ref \
                 {want_var:.4e})",
                m.lambda
            );
            assert!((got - want).abs() < bar * want.abs(), "λ = {}, μ = {mu}", m.lambda);
            assert!((var - want_var).abs() < 1e-2 * want_var, "λ = {}, μ = {mu}", m.lambda);
        }
        for e in [1.0f64, 20.0] {
            let r = rng.uniform_sphere();
            let p = move |c: f64| (e + 1.0) / (2.0 * PI) * c.max(0.0).powf(e);
            let (want, v) = sub.zonal(&fit, r, &p, PI / 2.0);
            let got = probe.phong(to32(r), e as f32).unwrap().value as f64;
            let var = probe.phong_variance(to32(r), e as f32).unwrap() as f64;
            let want_var = noise * v * glossy_calibration(&m.calibration, e + 2.0);
            println!(
                "λ = {}, Phong e = {e}: {got:.6e} (ref {want:.6e}), variance {var:.4e} (ref \
                 {want_var:.4e})",
                m.lambda
            );
            assert!((got - want).abs() < bar * want.abs(), "λ = {}, e = {e}", m.lambda);
            assert!((var - want_var).abs() < 1e-2 * want_var, "λ = {}, e = {e}", m.lambda);
        }
    }
}

/// The documented glossy calibration (`Member::calibration`): `c₇` below μ = 7, `c₁₀₂`
/// above 102, linear in `ln μ` between the grid points 7, 22, 102.
fn glossy_calibration(c: &[f32; 4], mu: f64) -> f64 {
    let [_, c7, c22, c102] = c.map(f64::from);
    if mu <= 7.0 {
        c7
    } else if mu >= 102.0 {
        c102
    } else if mu < 22.0 {
        c7 + (mu / 7.0).ln() / (22.0f64 / 7.0).ln() * (c22 - c7)
    } else {
        c22 + (mu / 22.0).ln() / (102.0f64 / 22.0).ln() * (c102 - c22)
    }
}

#[test]
fn selection_is_the_reference_likelihood_argmax_of_the_valid_samples() {
    let mut rng = Rng::new(78);
    let (mut agree, mut total) = (0, 0);
    for round in 0..20 {
        let rot = rng.uniform_rotation();
        let mut probe = Probe::<32, f32, Point, 16>::new();
        probe.set_rotation(mat3(rot)).unwrap();
        let lights: Vec<SgLight> = (0..4)
            .map(|_| SgLight {
                axis: rng.uniform_sphere(),
                sharpness: 1.0 + 80.0 * rng.next_f64().powi(2),
                amplitude: rng.next_f64(),
            })
            .collect();
        let valid = random_mask::<32>(&mut rng, [2, 8, 16][round % 3]);
        let y = masked_samples(&probe, &lights, &valid);
        let y_valid = valid_values(&y, &valid);
        let lls: Vec<f64> = Probe::<32>::family()
            .map(|m| Subset::new(rot, &valid, m.lambda as f64, m.sigma as f64).fit(&y_valid).ll)
            .collect();
        probe.update_masked(&y, &valid).unwrap();
        total += 1;
        agree += usize::from(crate::probe::check_selection(
            probe.selected(),
            probe.log_likelihood(),
            &lls,
        ));
    }
    println!("selection agreed with the reference argmax in {agree}/{total}");
    assert!(agree >= total - 1);
}

/// The REML channel covariance of the valid samples, `S_ab = r_aᵀQ_VV⁻¹r_b/(n − 1)`, and the
/// luminance variance built on it.
#[test]
fn masked_signal_covariance_matches_the_f64_reference() {
    let mut rng = Rng::new(0xC0F);
    let rot = rng.uniform_rotation();
    let fields: Vec<Vec<SgLight>> = (0..3).map(|_| field(&mut rng)).collect();
    let mut probe = Probe::<64, [f32; 3], Point, 24>::new();
    probe.set_rotation(mat3(rot)).unwrap();
    let valid = random_mask::<64>(&mut rng, 24);
    let y: [[f32; 3]; 64] = core::array::from_fn(|i| {
        core::array::from_fn(|c| radiance(&fields[c], to64(probe.directions()[i])) as f32)
    });
    for (k, m) in Probe::<64>::family().enumerate() {
        probe.update_masked_with(&y, &valid, Selection::Member(k)).unwrap();
        let sub = Subset::new(rot, &valid, m.lambda as f64, m.sigma as f64);
        let fits: Vec<Fit> = (0..3)
            .map(|c| {
                let yc: Vec<f32> = y.iter().map(|v| v[c]).collect();
                sub.fit(&valid_values(&yc, &valid))
            })
            .collect();
        // r_c = Q_VV·α_c, so S_ab = α_aᵀ·Q_VV·α_b/(n − 1).
        let len = sub.len();
        let s = |a: usize, b: usize| -> f64 {
            let mut sum = 0.0;
            for i in 0..len {
                for j in 0..len {
                    sum += fits[a].alpha[i] * sub.q[i * len + j] * fits[b].alpha[j];
                }
            }
            sum / (len as f64 - 1.0)
        };
        for a in 0..3 {
            for b in 0..3 {
                let want = s(a, b);
                let scale = (s(a, a) * s(b, b)).sqrt();
                let got = probe.signal_covariance(a, b).unwrap() as f64;
                assert!(
                    (got - want).abs() < 1e-5 * scale,
                    "λ = {}: S_{a}{b} = {got:e}, want {want:e}",
                    m.lambda
                );
            }
        }
        let w = [0.2126f32, 0.7152, 0.0722];
        let want: f64 = (0..3)
            .flat_map(|a| (0..3).map(move |b| (a, b)))
            .map(|(a, b)| w[a] as f64 * w[b] as f64 * s(a, b))
            .sum();
        let got = probe.signal_variance_of(w).unwrap() as f64;
        assert!((got - want).abs() < 1e-5 * want, "λ = {}: wᵀSw {got:e} vs {want:e}", m.lambda);
        let e = probe.irradiance(Vec3::new(0.1, 0.2, 0.9)).unwrap();
        let y_var = probe.combine(&e, w).unwrap().variance as f64;
        assert!((y_var - f64::from(e.unit_variance.unwrap()) * got).abs() <= 1e-6 * y_var);
    }
}

/// All samples valid: `update_masked` is `update`, bit for bit, for every answer; and after
/// a masked update, `update` (or an all-valid mask) forgets the missing samples.
#[test]
fn all_valid_is_update_bit_for_bit() {
    let mut rng = Rng::new(0xA11);
    let lights = field(&mut rng);
    let rot = mat3(rng.uniform_rotation());
    let mut masked = Probe::<64, [f32; 3], Point, 8>::new();
    let mut plain = Probe::<64, [f32; 3]>::new();
    masked.set_rotation(rot).unwrap();
    plain.set_rotation(rot).unwrap();
    let y: [[f32; 3]; 64] = masked.directions().map(|d| {
        let v = radiance(&lights, to64(d)) as f32;
        [v, 0.5 * v + 0.1, 2.0 - v]
    });
    plain.update(&y).unwrap();
    masked.update_masked(&y, &[true; 64]).unwrap();
    assert_eq!(fingerprint(&masked), fingerprint(&plain));
    for k in 0..Probe::<64>::family().len() {
        plain.update_with(&y, Selection::Member(k)).unwrap();
        masked.update_masked_with(&y, &[true; 64], Selection::Member(k)).unwrap();
        assert_eq!(fingerprint(&masked), fingerprint(&plain));
    }
    // A masked update, then the full one again.
    let valid = random_mask::<64>(&mut rng, 8);
    masked.update_masked(&y, &valid).unwrap();
    assert_eq!(masked.missing().len(), 8);
    assert_ne!(fingerprint(&masked), fingerprint(&plain));
    masked.update_with(&y, Selection::Member(Probe::<64>::family().len() - 1)).unwrap();
    assert!(masked.missing().is_empty());
    assert_eq!(fingerprint(&masked), fingerprint(&plain));
    masked.update_masked(&y, &valid).unwrap();
    masked.update_masked(&y, &[true; 64]).unwrap();
    plain.update(&y).unwrap();
    assert_eq!(fingerprint(&masked), fingerprint(&plain));
    // The default capacity M = 0 takes all-valid masks.
    let mut zero = Probe::<64, [f32; 3]>::new();
    zero.set_rotation(rot).unwrap();
    zero.update_masked(&y, &[true; 64]).unwrap();
    assert_eq!(fingerprint(&zero), fingerprint(&plain));
}

/// Values at missing positions are never read: NaN, ±∞ or any finite garbage there give the
/// same probe, bit for bit.
#[test]
fn values_at_missing_positions_are_ignored() {
    let mut rng = Rng::new(0x1A);
    let lights = field(&mut rng);
    let mut a = Probe::<32, f32, Point, 8>::new();
    let valid = random_mask::<32>(&mut rng, 8);
    let y = masked_samples(&a, &lights, &valid);
    a.update_masked(&y, &valid).unwrap();
    let want = fingerprint(&a);
    for garbage in [f32::INFINITY, f32::NEG_INFINITY, 0.0, -1e30, 3e38, 7.5] {
        let z: [f32; 32] = core::array::from_fn(|i| if valid[i] { y[i] } else { garbage });
        let mut b = Probe::<32, f32, Point, 8>::new();
        b.update_masked(&z, &valid).unwrap();
        assert_eq!(fingerprint(&b), want, "garbage {garbage}");
    }
}

/// Bad masks and samples: a clear error, and the probe keeps its data.
#[test]
fn bad_masks_are_refused_and_keep_the_data() {
    let mut rng = Rng::new(0xBAD);
    let lights = field(&mut rng);
    let mut probe = Probe::<16, f32, Point, 4>::new();
    let before_valid = random_mask::<16>(&mut rng, 3);
    let y = masked_samples(&probe, &lights, &before_valid);
    probe.update_masked(&y, &before_valid).unwrap();
    let kept = fingerprint(&probe);
    let full: [f32; 16] = probe.directions().map(|d| radiance(&lights, to64(d)) as f32);
    // Five missing, capacity four.
    let mut five = [true; 16];
    five[..5].fill(false);
    assert_eq!(probe.update_masked(&full, &five), Err(Error::TooManyMissing));
    assert_eq!(fingerprint(&probe), kept);
    // Fewer than two valid samples, with a capacity that would allow them.
    let mut big = Probe::<16, f32, Point, 16>::new();
    big.update(&full).unwrap();
    let big_kept = fingerprint(&big);
    let mut one = [false; 16];
    one[7] = true;
    assert_eq!(big.update_masked(&full, &one), Err(Error::TooManyMissing));
    assert_eq!(big.update_masked(&full, &[false; 16]), Err(Error::TooManyMissing));
    assert_eq!(fingerprint(&big), big_kept);
    // Two valid samples are enough.
    let mut two = [false; 16];
    two[3] = true;
    two[12] = true;
    big.update_masked(&full, &two).unwrap();
    assert_eq!(big.missing().len(), 14);
    assert!(big.irradiance(Vec3::Z).unwrap().value.is_finite());
    // A NaN or infinite valid sample.
    for bad in [f32::NAN, f32::INFINITY] {
        let mut z = full;
        z[9] = bad;
        assert!(before_valid[9] || five[9]);
        let mut valid = [true; 16];
        valid[2] = false;
        assert_eq!(probe.update_masked(&z, &valid), Err(Error::InvalidRadiance));
        assert_eq!(fingerprint(&probe), kept);
    }
    // A member outside the family.
    assert_eq!(
        probe.update_masked_with(&full, &five.map(|_| true).map(|v| v), Selection::Member(99)),
        Err(Error::InvalidMember)
    );
    let mut valid = [true; 16];
    valid[0] = false;
    assert_eq!(
        probe.update_masked_with(&full, &valid, Selection::Member(99)),
        Err(Error::InvalidMember)
    );
    assert_eq!(fingerprint(&probe), kept);
    // The default capacity is 0: any missing sample is too many.
    let mut zero = Probe::<16>::new();
    assert_eq!(zero.update_masked(&full, &valid), Err(Error::TooManyMissing));
    assert_eq!(zero.irradiance(Vec3::Z).unwrap().value, 0.0);
    assert_eq!(
        Error::TooManyMissing.to_string(),
        "more samples missing than the probe's capacity M, or fewer than two valid"
    );
}

/// Rotating the set and the field together, with the same mask, rotates the answers.
#[test]
fn rotating_set_field_and_mask_together_rotates_the_answer() {
    let mut rng = Rng::new(12);
    let lights = field(&mut rng);
    let rot = rng.uniform_rotation();
    let mut a = Probe::<64, f32, Point, 16>::new();
    let mut b = Probe::<64, f32, Point, 16>::new();
    b.set_rotation(mat3(rot)).unwrap();
    let valid = random_mask::<64>(&mut rng, 16);
    let y = masked_samples(&a, &lights, &valid);
    a.update_masked(&y, &valid).unwrap();
    b.update_masked(&y, &valid).unwrap();
    assert_eq!(a.selected(), b.selected());
    for _ in 0..16 {
        let n = rng.uniform_sphere();
        let rn = reference::vec::mat_mul_vec(rot, n);
        let (ea, eb) = (a.irradiance(to32(n)).unwrap(), b.irradiance(to32(rn)).unwrap());
        assert!((ea.value - eb.value).abs() <= 2e-5 * ea.value.abs().max(1.0), "{ea:?} {eb:?}");
        let (va, vb) =
            (a.irradiance_variance(to32(n)).unwrap(), b.irradiance_variance(to32(rn)).unwrap());
        assert!((va - vb).abs() <= 1e-3 * va, "{va} {vb}");
    }
}

/// RGB equals three scalar probes for a fixed member, bit for bit, with the same mask.
#[test]
fn masked_rgb_equals_three_scalar_probes() {
    let mut rng = Rng::new(6);
    let rot = mat3(rng.uniform_rotation());
    let mut rgb = Probe::<32, [f32; 3], Point, 10>::new();
    rgb.set_rotation(rot).unwrap();
    let fields: Vec<Vec<SgLight>> = (0..3).map(|_| field(&mut rng)).collect();
    let valid = random_mask::<32>(&mut rng, 10);
    let y: [[f32; 3]; 32] = core::array::from_fn(|i| {
        core::array::from_fn(|c| radiance(&fields[c], to64(rgb.directions()[i])) as f32)
    });
    for k in 0..Probe::<32>::family().len() {
        rgb.update_masked_with(&y, &valid, Selection::Member(k)).unwrap();
        for c in 0..3 {
            let mut mono = Probe::<32, f32, Point, 10>::new();
            mono.set_rotation(rot).unwrap();
            mono.update_masked_with(&y.map(|v| v[c]), &valid, Selection::Member(k)).unwrap();
            for n in [Vec3::X, Vec3::new(0.2, -0.5, 0.8)] {
                let (a, b) = (rgb.irradiance(n).unwrap(), mono.irradiance(n).unwrap());
                assert_eq!(a.value[c], b.value);
                assert_eq!(a.variance[c], b.variance);
                assert_eq!(
                    rgb.irradiance_variance(n).unwrap()[c],
                    mono.irradiance_variance(n).unwrap()
                );
            }
            assert_eq!(rgb.signal_covariance(c, c).unwrap(), mono.signal_variance());
        }
    }
    let grey: [[f32; 3]; 32] = y.map(|v| [v[0]; 3]);
    rgb.update_masked(&grey, &valid).unwrap();
    let mut mono = Probe::<32, f32, Point, 10>::new();
    mono.set_rotation(rot).unwrap();
    mono.update_masked(&y.map(|v| v[0]), &valid).unwrap();
    assert_eq!(rgb.selected(), mono.selected());
}

/// A constant is exact with zero variance, whichever samples are missing; and powers of two
/// scale every answer bit for bit (the radiance-scale normalisation of `update`).
#[test]
fn constants_and_powers_of_two() {
    let mut rng = Rng::new(0xC0);
    let mut probe = Probe::<64, [f32; 3], Point, 32>::new();
    probe.set_rotation(mat3(rng.uniform_rotation())).unwrap();
    let valid = random_mask::<64>(&mut rng, 32);
    probe.update_masked(&[[1.0, 0.5, 2.0]; 64], &valid).unwrap();
    for n in [Vec3::Z, Vec3::new(-0.3, 0.9, 0.1)] {
        let e = probe.irradiance(n).unwrap();
        for (c, want) in [1.0f32, 0.5, 2.0].iter().enumerate() {
            let want = want * core::f32::consts::PI;
            assert!((e.value[c] - want).abs() <= 4e-7 * want, "{:?}", e.value);
            assert_eq!(e.variance[c], 0.0);
            assert_eq!(probe.irradiance_variance(n).unwrap()[c], 0.0);
        }
    }
    let lights = field(&mut rng);
    let mut scalar = Probe::<64, f32, Point, 32>::new();
    let y = masked_samples(&scalar, &lights, &valid);
    for k in 0..Probe::<64>::family().len() {
        scalar.update_masked_with(&y, &valid, Selection::Member(k)).unwrap();
        let base = fingerprint(&scalar);
        for shift in [-100i32, -3, 5, 90] {
            let c = 2f32.powi(shift);
            scalar.update_masked_with(&y.map(|v| v * c), &valid, Selection::Member(k)).unwrap();
            let e = scalar.irradiance(Vec3::new(0.3, -0.4, 0.5)).unwrap();
            let v = scalar.irradiance_variance(Vec3::new(0.3, -0.4, 0.5)).unwrap();
            scalar.update_masked_with(&y, &valid, Selection::Member(k)).unwrap();
            assert_eq!(fingerprint(&scalar), base);
            let e1 = scalar.irradiance(Vec3::new(0.3, -0.4, 0.5)).unwrap();
            let v1 = scalar.irradiance_variance(Vec3::new(0.3, -0.4, 0.5)).unwrap();
            assert_eq!(e.value, e1.value * c, "2^{shift}");
            // A positive variance below the least positive f32 is rounded up to it.
            let want = e1.variance * c * c;
            let want = if want == 0.0 && e1.variance > 0.0 { f32::from_bits(1) } else { want };
            assert_eq!(e.variance, want, "2^{shift}");
            // The exact variance is rounded once from f64: to one ulp; +∞ beyond f32::MAX, 0 or
            // subnormal below the normal range.
            let want = f64::from(v1) * f64::from(c) * f64::from(c);
            if want > f64::from(f32::MAX) {
                assert_eq!(v, f32::INFINITY, "2^{shift}");
            } else if want < f64::from(f32::MIN_POSITIVE) {
                assert!((0.0..=f32::MIN_POSITIVE).contains(&v), "2^{shift}: {v}");
            } else {
                let rel = (f64::from(v) - want).abs() / want;
                assert!(rel <= f64::from(f32::EPSILON), "2^{shift}: {v} vs {want}");
            }
        }
    }
}

/// The O(1) variances are σ̂_f² of the valid samples times the full set's baked direction
/// average (documented): measured here against the direction average of the exact variance
/// of the valid subset, which they under-state when samples are missing.
#[test]
fn fast_variances_are_the_full_sets_average() {
    let mut rng = Rng::new(0xFA5);
    let lights = field(&mut rng);
    let mut probe = Probe::<64, f32, Point, 32>::new();
    let member = Probe::<64>::member(1).unwrap();
    for missing in [0, 3, 16, 32] {
        let valid = random_mask::<64>(&mut rng, missing);
        let y = masked_samples(&probe, &lights, &valid);
        probe.update_masked_with(&y, &valid, Selection::Member(1)).unwrap();
        let unit = member.mean_variance * member.calibration[0];
        let (mut exact, mut fast) = (0.0f64, 0.0f64);
        let count = 400;
        for _ in 0..count {
            let n = to32(rng.uniform_sphere());
            let e = probe.irradiance(n).unwrap();
            assert_eq!(e.unit_variance, Some(unit));
            assert!((e.variance - probe.signal_variance() * unit).abs() <= 1e-6 * e.variance);
            fast += e.variance as f64;
            exact += probe.irradiance_variance(n).unwrap() as f64;
        }
        let ratio = exact / fast;
        println!(
            "N = 64, λ = {}, {missing} missing: mean exact / O(1) variance {ratio:.3}",
            member.lambda
        );
        if missing == 0 {
            assert!((ratio - 1.0).abs() < 0.25, "{ratio}");
        } else if missing >= 16 {
            assert!(ratio > 1.25, "{ratio}");
        }
    }
}

/// Footprint probes take masks too: a constant stays exact, an all-valid mask is `update`.
#[test]
fn footprint_probes_take_masks() {
    let mut probe = Probe::<64, f32, Gaussian<8>, 16>::new();
    let mut rng = Rng::new(0xF0);
    let valid = random_mask::<64>(&mut rng, 16);
    probe.update_masked(&[3.0; 64], &valid).unwrap();
    let e = probe.irradiance(Vec3::new(0.2, 0.4, -0.7)).unwrap();
    assert!((e.value - 3.0 * core::f32::consts::PI).abs() < 1e-5 * e.value);
    assert_eq!(e.variance, 0.0);
    let lights = field(&mut rng);
    let y: [f32; 64] = probe.directions().map(|d| radiance(&lights, to64(d)) as f32);
    probe.update_masked(&y, &valid).unwrap();
    let masked = probe.irradiance(Vec3::Z).unwrap();
    let var = probe.irradiance_variance(Vec3::Z).unwrap();
    assert!(masked.value.is_finite() && var.is_finite() && var > 0.0);
    let mut plain = Probe::<64, f32, Gaussian<8>>::new();
    plain.update(&y).unwrap();
    probe.update_masked(&y, &[true; 64]).unwrap();
    assert_eq!(probe.irradiance(Vec3::Z).unwrap(), plain.irradiance(Vec3::Z).unwrap());
    // The valid subset's answer is near the full one on a smooth field.
    assert!((masked.value - plain.irradiance(Vec3::Z).unwrap().value).abs() < 0.05 * masked.value);
}

/// What the capacity costs in the probe: the missing indices (`u16`), the `M × M` factor and
/// `c₁` (`f32`), `4M² + 6M` bytes and a few words over the default `M = 0`.
#[test]
fn capacity_footprint_is_pinned() {
    use std::mem::size_of;
    let base = size_of::<Probe<64>>();
    for (m, size) in [
        (8, size_of::<Probe<64, f32, Point, 8>>()),
        (16, size_of::<Probe<64, f32, Point, 16>>()),
        (32, size_of::<Probe<64, f32, Point, 32>>()),
    ] {
        let extra = size - base;
        println!("Probe<64, f32, Point, {m}>: {size} bytes, {extra} more than M = 0 ({base})");
        assert!((4 * m * m + 6 * m..=4 * m * m + 6 * m + 16).contains(&extra), "M = {m}: {extra}");
    }
}

/// Gaussian-footprint probes (`Gaussian<8>`, N = 64) against an f64 reference of their own:
/// a sample's covariance with the radiance is the SG `exp(ν(xᵢ·x − 1))` (the family's `λ` is
/// `ν`), so `Cov(Yᵢ, Yⱼ)` is that SG seen through the footprint of sample `j`, in closed form
/// (`reference::footprint::sg_convolution`), and `Cov(Yᵢ, E(n))` its irradiance
/// (`reference::bmc::kernel_mean`): `Q_VV` from the valid directions, LU solves, no Legendre
/// series. `V̄` (of the deconvolved radiance kernel) has no closed form, so the variances are
/// compared through their increase over the all-valid probe's, where it cancels.
#[test]
fn masked_gaussian_footprint_matches_the_f64_reference() {
    const S: u32 = 8;
    let mut rng = Rng::new(0xF008);
    let rot = rng.uniform_rotation();
    let lights = field(&mut rng);
    let mut probe = Probe::<64, f32, Gaussian<S>, 16>::new();
    probe.set_rotation(mat3(rot)).unwrap();
    let mut full = Probe::<64, f32, Gaussian<S>>::new();
    full.set_rotation(mat3(rot)).unwrap();
    let xs: Vec<[f64; 3]> = (0..64u64)
        .map(|j| reference::vec::mat_mul_vec(rot, reference::sf::sphere_point(j, 64)))
        .collect();
    // Footprint samples of the constant-plus-SG field, in closed form.
    let y: Vec<f64> = xs
        .iter()
        .map(|&x| {
            0.3 + lights
                .iter()
                .map(|l| reference::footprint::sg_convolution(l, x, S.into()))
                .sum::<f64>()
        })
        .collect();
    let y32: [f32; 64] = core::array::from_fn(|i| y[i] as f32);
    let y64: Vec<f64> = y32.iter().map(|&v| f64::from(v)).collect();
    let valid = random_mask::<64>(&mut rng, 16);
    let normals: Vec<[f64; 3]> = (0..8).map(|_| rng.uniform_sphere()).collect();
    for (k, m) in Probe::<64, f32, Gaussian<S>>::family().enumerate() {
        let nu = f64::from(m.lambda);
        let sigma = f64::from(m.sigma);
        let build = |keep: &dyn Fn(usize) -> bool| -> (Vec<usize>, Vec<f64>) {
            let idx: Vec<usize> = (0..64).filter(|&i| keep(i)).collect();
            let len = idx.len();
            let mut q = vec![0.0; len * len];
            for (a, &i) in idx.iter().enumerate() {
                for (b, &j) in idx.iter().enumerate() {
                    let light = SgLight { axis: xs[i], sharpness: nu, amplitude: 1.0 };
                    q[a * len + b] = reference::footprint::sg_convolution(&light, xs[j], S.into())
                        + if a == b { sigma * sigma } else { 0.0 };
                }
            }
            (idx, q)
        };
        // (E(n), ζᵀQ⁻¹ζ − (1 − 1ᵀQ⁻¹ζ)²/s₁: the variance without V̄, negated) per normal.
        let fit = |idx: &[usize], q: &[f64]| -> (Vec<(f64, f64)>, f64) {
            let len = idx.len();
            let yv: Vec<f64> = idx.iter().map(|&i| y64[i]).collect();
            let qi_y = reference::bmc::lu_solve(q, len, &yv);
            let qi_1 = reference::bmc::lu_solve(q, len, &vec![1.0; len]);
            let s1: f64 = qi_1.iter().sum();
            let beta = qi_y.iter().sum::<f64>() / s1;
            let alpha: Vec<f64> = qi_y.iter().zip(&qi_1).map(|(a, b)| a - beta * b).collect();
            let r2: f64 = yv.iter().zip(&alpha).map(|(a, b)| a * b).sum();
            let out = normals
                .iter()
                .map(|&n| {
                    let z: Vec<f64> = idx
                        .iter()
                        .map(|&i| {
                            PI * reference::bmc::kernel_mean(nu, reference::vec::dot(xs[i], n))
                        })
                        .collect();
                    let e = PI * beta + z.iter().zip(&alpha).map(|(a, b)| a * b).sum::<f64>();
                    let qi_z = reference::bmc::lu_solve(q, len, &z);
                    let zqz: f64 = z.iter().zip(&qi_z).map(|(a, b)| a * b).sum();
                    let one: f64 = qi_z.iter().sum();
                    (e, zqz - (PI - one).powi(2) / s1)
                })
                .collect();
            (out, r2 / (len as f64 - 1.0))
        };
        let (vi, qv) = build(&|i| valid[i]);
        let (ai, qa) = build(&|_| true);
        let (masked_ref, noise) = fit(&vi, &qv);
        let (full_ref, full_noise) = fit(&ai, &qa);
        probe.update_masked_with(&y32, &valid, Selection::Member(k)).unwrap();
        full.update_with(&y32, Selection::Member(k)).unwrap();
        let cal = f64::from(m.calibration[0]);
        let mean = masked_ref.iter().map(|r| r.0.abs()).sum::<f64>() / normals.len() as f64;
        let (mut worst_e, mut worst_v) = (0.0f64, 0.0f64);
        for ((&n, &(e, q_masked)), &(_, q_full)) in normals.iter().zip(&masked_ref).zip(&full_ref) {
            let got = probe.irradiance(to32(n)).unwrap().value as f64;
            worst_e = worst_e.max((got - e).abs() / mean);
            // Unit variances' difference: (V̄ − q_masked) − (V̄ − q_full).
            let want = q_full - q_masked;
            let masked_unit = probe.irradiance_variance(to32(n)).unwrap() as f64 / (noise * cal);
            let full_unit = full.irradiance_variance(to32(n)).unwrap() as f64 / (full_noise * cal);
            let got_v = masked_unit - full_unit;
            worst_v = worst_v.max((got_v - want).abs() / want);
        }
        let signal = (probe.signal_variance() as f64 - noise).abs() / noise;
        println!(
            "Gaussian<{S}>, 16 of 64 missing, ν = {} (cond {:.1e}): |ΔE|/mean {worst_e:.2e}, \
             Δ(variance increase) {worst_v:.2e}, Δσ̂² {signal:.2e}",
            m.lambda, m.condition
        );
        // The sample covariance here is the closed form, the probe's the baked Legendre
        // series of the deconvolved kernel (converged to 10⁻⁸ of K₀): the bars of
        // `tests/probe/probe.rs`, ten times the value bar for the single-query maximum.
        let bar = 10.0 * value_bar(m.condition);
        assert!(worst_e < bar, "ν = {}: E differs by {worst_e:e}", m.lambda);
        assert!(worst_v < 1e-2, "ν = {}: variance increase differs by {worst_v:e}", m.lambda);
        assert!(signal < value_bar(m.condition).max(1e-4), "ν = {}: σ̂_f² {signal:e}", m.lambda);
    }
}

/// The SH L2 export of a masked probe (`Probe::radiance_sh` from `α`, `radiance_sh_variance`
/// through the Schur-corrected exact variance) against the reference: `c_lm = β·√(4π)·δ_l0 +
/// k̂_l·Σ_V αᵢ·Y_lm(xᵢ)` with `k̂_l = 2π∫exp(λ(t − 1))·P_l(t) dt` by quadrature and the
/// reference crate's real SH, and the variances `σ̂_f²·(k̂_l − ζᵀQ_VV⁻¹ζ + (I_lm −
/// 1ᵀQ_VV⁻¹ζ)²/s₁)` with `ζᵢ = k̂_l·Y_lm(xᵢ)`.
#[test]
fn masked_sh_export_matches_the_f64_reference() {
    let mut rng = Rng::new(0x5405);
    let Masked { rot, mut probe, valid, y, y_valid } = masked::<64, 16>(&mut rng, 16);
    let degree = [0usize, 1, 1, 1, 2, 2, 2, 2, 2];
    let order = [0i64, -1, 0, 1, -2, -1, 0, 1, 2];
    for (k, m) in Probe::<64>::family().enumerate() {
        probe.update_masked_with(&y, &valid, Selection::Member(k)).unwrap();
        let lambda = f64::from(m.lambda);
        let sub = Subset::new(rot, &valid, lambda, f64::from(m.sigma));
        let fit = sub.fit(&y_valid);
        let kernel = move |t: f64| (lambda * (t - 1.0)).exp();
        let k_hat: Vec<f64> =
            (0..3).map(|l| polar(&kernel, |t| reference::sh::legendre(l, t))).collect();
        let sh = probe.radiance_sh().coefficients;
        let var = probe.radiance_sh_variance();
        let noise = fit.r2 / 47.0 * f64::from(m.calibration[0]);
        let (mut diff, mut norm, mut worst_v) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..9 {
            let (l, o) = (degree[i], order[i]);
            let ylm: Vec<f64> = sub.xs.iter().map(|&x| reference::sh::real_sh(l, o, x)).collect();
            let constant = if i == 0 { fit.beta * (4.0 * PI).sqrt() } else { 0.0 };
            let want =
                constant + k_hat[l] * ylm.iter().zip(&fit.alpha).map(|(a, b)| a * b).sum::<f64>();
            diff += (f64::from(sh[i]) - want).powi(2);
            norm += want * want;
            let zeta: Vec<f64> = ylm.iter().map(|v| k_hat[l] * v).collect();
            let integral = if i == 0 { (4.0 * PI).sqrt() } else { 0.0 };
            let want_var = noise * sub.unit_variance(&fit, &zeta, integral, k_hat[l]);
            worst_v = worst_v.max((f64::from(var[i]) - want_var).abs() / want_var);
        }
        let rel = (diff / norm).sqrt();
        println!(
            "SH export, 16 of 64 missing, λ = {} (cond {:.1e}): |Δc|/|c| {rel:.2e}, Δvariance \
             {worst_v:.2e}",
            m.lambda, m.condition
        );
        assert!(rel < 10.0 * value_bar(m.condition), "λ = {}: coefficients {rel:e}", m.lambda);
        assert!(worst_v < 1e-2, "λ = {}: variances {worst_v:e}", m.lambda);
    }
}
