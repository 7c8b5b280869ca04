//! The probe form of Bayesian Monte Carlo against an independent f64 reference.
//!
//! The reference builds the full `Q` from the reference crate's points, solves by LU with
//! partial pivoting and takes `zᵢ` from I₀ₑ quadrature (no table, no block split), so it
//! shares nothing with `gen/probe.rs` but the model.

use reference::analytic::SgLight;
use reference::rng::Rng;
use sphere_quadrature::probe::{cosine_weighted_average, Probe, ProbeSize, Selection};
use sphere_quadrature::sg::SphericalGaussian;
use sphere_quadrature::{bmc::Size, Error, Mat3, Vec3};
use std::f64::consts::PI;

struct RefProbe {
    xs: Vec<[f64; 3]>,
    lambda: f64,
    /// `Q`, factored once by LU with partial pivoting.
    lu: reference::bmc::Lu,
    /// `Q⁻¹1` and `s₁ = 1ᵀQ⁻¹1`.
    qi_1: Vec<f64>,
    s1: f64,
    /// `V̄` of the cosine lobe (irradiance).
    vbar: f64,
}

struct RefEstimate {
    e: f64,
    /// rᵀQ⁻¹r.
    r2: f64,
    /// Unit posterior variance of E at n.
    v: f64,
    /// REML log-likelihood.
    ll: f64,
}

impl RefProbe {
    fn new(rotation: [[f64; 3]; 3], n: usize, lambda: f64, sigma: f64) -> Self {
        let xs: Vec<[f64; 3]> = (0..n as u64)
            .map(|j| {
                reference::vec::mat_mul_vec(rotation, reference::sf::sphere_point(j, n as u64))
            })
            .collect();
        let mut q = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let c = reference::vec::dot(xs[i], xs[j]);
                q[i * n + j] =
                    (lambda * (c - 1.0)).exp() + if i == j { sigma * sigma } else { 0.0 };
            }
        }
        let lu = reference::bmc::Lu::new(&q, n);
        let qi_1 = lu.solve(&vec![1.0; n]);
        let s1 = qi_1.iter().sum();
        let vbar = reference::bmc::kernel_mean_mean(lambda);
        RefProbe { xs, lambda, lu, qi_1, s1, vbar }
    }

    /// `(α, β)` of the GLS fit.
    fn weights(&self, y: &[f64]) -> (Vec<f64>, f64) {
        let qi_y = self.lu.solve(y);
        let beta = qi_y.iter().sum::<f64>() / self.s1;
        let alpha = qi_y.iter().zip(&self.qi_1).map(|(a, b)| a - beta * b).collect();
        (alpha, beta)
    }

    /// Glossy radiance `∫ L·G` for the lobe `G = exp(μ(r·x − 1))` (unit amplitude), with
    /// `rᵀQ⁻¹r` and the unit posterior variance; `zᵢ` and `V̄` by quadrature.
    fn glossy(&self, y: &[f64], r: [f64; 3], mu: f64, vbar: f64) -> (f64, f64, f64) {
        let (alpha, beta) = self.weights(y);
        let z: Vec<f64> =
            self.xs.iter().map(|&x| sg_pair(self.lambda, mu, reference::vec::dot(x, r))).collect();
        let integral = if mu == 0.0 { 4.0 * PI } else { 2.0 * PI * (1.0 - (-2.0 * mu).exp()) / mu };
        let value = beta * integral + z.iter().zip(&alpha).map(|(a, b)| a * b).sum::<f64>();
        let r2: f64 = y.iter().zip(&alpha).map(|(a, b)| a * b).sum();
        let qi_z = self.lu.solve(&z);
        let zqz: f64 = z.iter().zip(&qi_z).map(|(a, b)| a * b).sum();
        let one_z: f64 = qi_z.iter().sum();
        (value, r2, vbar - zqz + (integral - one_z).powi(2) / self.s1)
    }

    fn estimate(&self, y: &[f64], n: [f64; 3]) -> RefEstimate {
        let len = self.xs.len();
        let (alpha, beta) = self.weights(y);
        let z: Vec<f64> = self
            .xs
            .iter()
            .map(|&x| reference::bmc::kernel_mean(self.lambda, reference::vec::dot(x, n)))
            .collect();
        let e = PI * (beta + z.iter().zip(&alpha).map(|(a, b)| a * b).sum::<f64>());
        let r2: f64 = y.iter().zip(&alpha).map(|(a, b)| a * b).sum();
        let qi_z = self.lu.solve(&z);
        let zqz: f64 = z.iter().zip(&qi_z).map(|(a, b)| a * b).sum();
        let one_z: f64 = qi_z.iter().sum();
        let v = self.vbar - zqz + (1.0 - one_z).powi(2) / self.s1;
        let ll =
            -0.5 * self.lu.log_abs_det() - 0.5 * self.s1.ln() - 0.5 * (len as f64 - 1.0) * r2.ln();
        RefEstimate { e, r2, v: PI * PI * v, ll }
    }
}

/// `2π∫₀^θₘ sin θ·exp(μ(cos θ − 1))·g(cos θ) dθ` by composite Simpson (2000 intervals; θₘ
/// where the lobe has fallen below e⁻⁴⁵, else π): the integral over the sphere of the lobe
/// about the pole times a function of the polar cosine.
fn polar_integral(mu: f64, g: impl Fn(f64) -> f64) -> f64 {
    let top = if mu > 0.0 { (90.0 / mu).sqrt().min(PI) } else { PI };
    let m = 2000;
    let h = top / m as f64;
    let mut sum = 0.0;
    for i in 0..=m {
        let th = i as f64 * h;
        let w = if i == 0 || i == m {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        sum += w * th.sin() * (mu * (th.cos() - 1.0)).exp() * g(th.cos());
    }
    2.0 * PI * sum * h / 3.0
}

/// The integral of [`polar_integral`] by Gauss–Legendre, 16 panels of 20 points over [0, θₘ]:
/// the outer rule of `V̄ = ∫ G·z`, whose integrand is smooth and whose `z` is itself a
/// quadrature (320 outer points rather than 2001).
fn polar_integral_gl(mu: f64, g: impl Fn(f64) -> f64) -> f64 {
    let top = if mu > 0.0 { (90.0 / mu).sqrt().min(PI) } else { PI };
    reference::quad::zonal_gl(top, 16, |c| (mu * (c - 1.0)).exp() * g(c))
}

/// `∫ exp(λ(a·x − 1))·exp(μ(b·x − 1)) dx` for `a·b = t`, numerically: `b` at the pole, the
/// azimuth by `2π·I₀`, the polar angle by [`polar_integral`] (not the closed form).
fn sg_pair(lambda: f64, mu: f64, t: f64) -> f64 {
    let t = t.clamp(-1.0, 1.0);
    let s = (1.0 - t * t).sqrt();
    polar_integral(mu, |c| {
        let sn = (1.0 - c * c).max(0.0).sqrt();
        // exp(λ(c·t − 1))·I₀(λ·sn·s) = exp(λ(c·t + sn·s − 1))·I₀ₑ(λ·sn·s)
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

/// RMS and max difference of E (relative to the mean |E|), and the max relative difference of
/// the exact variance, f32 probe vs
/// f64 reference, every member, 3 fields × 32 normals, through the probe's own f32 directions
/// (so that both see the same samples).
fn compare<const N: usize>() -> (f64, f64, f64, Vec<(f32, f32, f64)>)
where
    Size<N>: ProbeSize,
{
    let mut rng = Rng::new(0x9B0B + N as u64);
    let (mut worst_e, mut worst_v, mut sum_sq, mut count) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let members: Vec<_> = Probe::<N>::family().collect();
    let mut member_sq = vec![0.0f64; members.len()];
    let mut member_count = 0.0f64;
    // The reference's z and V̄ are quadratures per sample: fewer cases at large N.
    let (fields, queries) = if N >= 128 { (1, 6) } else { (3, 32) };
    for _ in 0..fields {
        let rot = rng.uniform_rotation();
        let mut probe = Probe::<N>::new();
        probe.set_rotation(mat3(rot)).unwrap();
        let lights = field(&mut rng);
        let y64: Vec<f64> =
            probe.directions().iter().map(|&d| radiance(&lights, to64(d))).collect();
        let y: [f32; N] = core::array::from_fn(|i| y64[i] as f32);
        let y64: Vec<f64> = y.iter().map(|&v| v as f64).collect();
        let normals: Vec<[f64; 3]> = (0..queries).map(|_| rng.uniform_sphere()).collect();
        for (k, m) in Probe::<N>::family().enumerate() {
            probe.update_with(&y, Selection::Member(k)).unwrap();
            let r = RefProbe::new(rot, N, m.lambda as f64, m.sigma as f64);
            let refs: Vec<RefEstimate> = normals.iter().map(|&n| r.estimate(&y64, n)).collect();
            let mean = refs.iter().map(|e| e.e.abs()).sum::<f64>() / refs.len() as f64;
            for (n, re) in normals.iter().zip(&refs) {
                let nv = Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32);
                let got = probe.irradiance(nv).unwrap();
                let rel = (got.value as f64 - re.e).abs() / mean;
                worst_e = worst_e.max(rel);
                sum_sq += rel * rel;
                count += 1.0;
                member_sq[k] += rel * rel;
                if k == 0 {
                    member_count += 1.0;
                }
                // The model's variance times the member's documented irradiance calibration.
                let want_var = re.r2 / (N as f64 - 1.0) * re.v * f64::from(m.calibration[0]);
                let var = probe.irradiance_variance(nv).unwrap() as f64;
                worst_v = worst_v.max((var - want_var).abs() / want_var);
            }
        }
    }
    let per_member = members
        .iter()
        .zip(&member_sq)
        .map(|(m, sq)| (m.lambda, m.condition, (sq / member_count).sqrt()))
        .collect();
    ((sum_sq / count).sqrt(), worst_e, worst_v, per_member)
}

#[test]
fn f32_probe_matches_the_f64_reference() {
    for (n, (rms, e, v, members)) in [
        (16, compare::<16>()),
        (32, compare::<32>()),
        (64, compare::<64>()),
        (128, compare::<128>()),
        (256, compare::<256>()),
    ] {
        println!(
            "N = {n}: |ΔE|/mean|E| RMS {rms:.2e}, max {e:.2e}; max relative Δvariance {v:.2e}"
        );
        assert!(v < 1e-2, "N = {n}: exact variance differs by {v:e}");
        for (lambda, cond, rms) in members {
            println!("    λ = {lambda}: cond(Q) {cond:.2e}, |ΔE|/mean|E| RMS {rms:.2e}");
            // The bar is 1e-5 (RMS over queries). For the smoothest member with the
            // learned nugget (cond(Q) 3·10⁴–10⁵) the f32 triangular solves miss it: their
            // rounding (backward error ~(N/2)·ε₃₂ against ε₃₂ for storing the factor, which
            // alone moves an f64 solve by ~2·10⁻⁶) is amplified by cond(Q). Members with
            // cond(Q) ≤ 10⁴ must meet the bar; the others the textbook forward bound
            // cond(Q)·ε₃₂ (they measure 20–50× below it; the miss is reported in README).
            let bar = if cond <= 1e4 { 1e-5 } else { f64::from(cond) * f64::from(f32::EPSILON) };
            assert!(rms < bar, "N = {n}, λ = {lambda}: E differs by {rms:e} RMS (bar {bar:e})");
        }
    }
}

#[test]
fn selection_is_the_reference_likelihood_argmax() {
    let mut rng = Rng::new(77);
    let mut agree = 0;
    let mut total = 0;
    for _ in 0..20 {
        let rot = rng.uniform_rotation();
        let mut probe = Probe::<32>::new();
        probe.set_rotation(mat3(rot)).unwrap();
        // Fields from very smooth to rough.
        let lights: Vec<SgLight> = (0..4)
            .map(|_| SgLight {
                axis: rng.uniform_sphere(),
                sharpness: 1.0 + 80.0 * rng.next_f64().powi(2),
                amplitude: rng.next_f64(),
            })
            .collect();
        let y: [f32; 32] =
            core::array::from_fn(|i| radiance(&lights, to64(probe.directions()[i])) as f32);
        let y64: Vec<f64> = y.iter().map(|&v| v as f64).collect();
        let lls: Vec<f64> = Probe::<32>::family()
            .map(|m| {
                RefProbe::new(rot, 32, m.lambda as f64, m.sigma as f64)
                    .estimate(&y64, [0.0, 0.0, 1.0])
                    .ll
            })
            .collect();
        probe.update(&y).unwrap();
        total += 1;
        agree += usize::from(check_selection(probe.selected(), probe.log_likelihood(), &lls));
    }
    println!("selection agreed with the reference argmax in {agree}/{total}");
    assert!(agree >= total - 1);
}

/// Whether the probe selected the member of the largest reference log-likelihood in `lls`;
/// then its ℓ must be the reference's up to f32 rounding, and otherwise the two best must be a
/// near tie (only then may the choice go the other way).
pub(crate) fn check_selection(selected: usize, log_likelihood: f32, lls: &[f64]) -> bool {
    let best = (0..lls.len()).max_by(|&a, &b| lls[a].total_cmp(&lls[b])).unwrap();
    let mut sorted = lls.to_vec();
    sorted.sort_by(|a, b| b.total_cmp(a));
    if selected == best {
        assert!((log_likelihood as f64 - lls[best]).abs() < 1e-3 * lls[best].abs().max(1.0));
        true
    } else {
        assert!(sorted[0] - sorted[1] < 1e-3, "picked {selected} not {best}: {lls:?}");
        false
    }
}

#[test]
fn constants_are_exact_with_zero_variance() {
    // Miri interprets every operation: it takes N = 16 (the same code on a quarter of the
    // samples; N = 64 takes it about 20 s).
    if cfg!(miri) {
        constants_exact::<16>();
    } else {
        constants_exact::<64>();
    }
}

fn constants_exact<const N: usize>()
where
    Size<N>: ProbeSize,
{
    let mut probe = Probe::<N, [f32; 3]>::new();
    probe.set_rotation(Mat3::from_axis_angle(Vec3::new(1.0, 2.0, 3.0), 0.7)).unwrap();
    probe.update(&[[1.0, 0.5, 2.0]; N]).unwrap();
    for n in [Vec3::Z, Vec3::new(-0.3, 0.9, 0.1), Vec3::new(0.0, 0.0, -5.0)] {
        let e = probe.irradiance(n).unwrap();
        for (c, want) in [1.0f32, 0.5, 2.0].iter().enumerate() {
            let want = want * core::f32::consts::PI;
            assert!((e.value[c] - want).abs() <= 4e-7 * want, "{:?}", e.value);
            assert_eq!(e.variance[c], 0.0);
        }
    }
}

#[test]
fn rgb_equals_three_scalar_probes_for_a_fixed_member() {
    let mut rng = Rng::new(5);
    let rot = mat3(rng.uniform_rotation());
    let mut rgb = Probe::<32, [f32; 3]>::new();
    rgb.set_rotation(rot).unwrap();
    let fields: Vec<Vec<SgLight>> = (0..3).map(|_| field(&mut rng)).collect();
    let y: [[f32; 3]; 32] = core::array::from_fn(|i| {
        core::array::from_fn(|c| radiance(&fields[c], to64(rgb.directions()[i])) as f32)
    });
    for k in 0..Probe::<32>::family().len() {
        rgb.update_with(&y, Selection::Member(k)).unwrap();
        for c in 0..3 {
            let mut mono = Probe::<32>::new();
            mono.set_rotation(rot).unwrap();
            mono.update_with(&y.map(|v| v[c]), Selection::Member(k)).unwrap();
            for n in [Vec3::X, Vec3::new(0.2, -0.5, 0.8)] {
                let (a, b) = (rgb.irradiance(n).unwrap(), mono.irradiance(n).unwrap());
                assert_eq!(a.value[c], b.value);
                assert_eq!(a.variance[c], b.variance);
            }
        }
    }
    // Selection sums the channels' likelihoods: with identical channels it equals the scalar
    // probe's choice.
    let grey: [[f32; 3]; 32] = y.map(|v| [v[0]; 3]);
    rgb.update(&grey).unwrap();
    let mut mono = Probe::<32>::new();
    mono.set_rotation(rot).unwrap();
    mono.update(&y.map(|v| v[0])).unwrap();
    assert_eq!(rgb.selected(), mono.selected());
}

#[test]
fn rotating_set_and_field_together_rotates_the_answer() {
    let mut rng = Rng::new(11);
    let lights = field(&mut rng);
    let rot = rng.uniform_rotation();
    let mut a = Probe::<64>::new();
    let mut b = Probe::<64>::new();
    b.set_rotation(mat3(rot)).unwrap();
    let ya: [f32; 64] = core::array::from_fn(|i| radiance(&lights, to64(a.directions()[i])) as f32);
    // The same radiance, carried along with the rotation.
    a.update(&ya).unwrap();
    b.update(&ya).unwrap();
    assert_eq!(a.selected(), b.selected());
    for _ in 0..16 {
        let n = rng.uniform_sphere();
        let rn = reference::vec::mat_mul_vec(rot, n);
        let ea = a.irradiance(Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32)).unwrap();
        let eb = b.irradiance(Vec3::new(rn[0] as f32, rn[1] as f32, rn[2] as f32)).unwrap();
        assert!((ea.value - eb.value).abs() <= 2e-5 * ea.value.abs().max(1.0), "{ea:?} {eb:?}");
    }
}

#[test]
fn bad_input_is_refused_and_keeps_the_data() {
    let mut probe = Probe::<16>::new();
    // Before any update: zero irradiance and variance.
    assert_eq!(probe.irradiance(Vec3::Z).unwrap().value, 0.0);
    assert_eq!(probe.irradiance(Vec3::Z).unwrap().variance, 0.0);
    let good: [f32; 16] = core::array::from_fn(|i| 1.0 + i as f32 * 0.1);
    probe.update(&good).unwrap();
    let before = probe.irradiance(Vec3::Y).unwrap();
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut y = good;
        y[7] = bad;
        assert_eq!(probe.update(&y), Err(Error::InvalidRadiance));
        assert_eq!(probe.irradiance(Vec3::Y).unwrap(), before);
    }
    assert_eq!(probe.update_with(&good, Selection::Member(99)), Err(Error::InvalidMember));
    assert_eq!(probe.irradiance(Vec3::Y).unwrap(), before);
    for n in [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(f32::INFINITY, 0.0, 0.0),
    ] {
        assert_eq!(probe.irradiance(n), Err(Error::InvalidDirection));
        assert_eq!(probe.irradiance_variance(n), Err(Error::InvalidDirection));
        assert_eq!(
            cosine_weighted_average(probe.directions(), &good, n),
            Err(Error::InvalidDirection)
        );
    }
    let not_rotation = Mat3::from_rows(Vec3::X, Vec3::X, Vec3::Z);
    assert_eq!(probe.set_rotation(not_rotation), Err(Error::InvalidRotation));
    let nan = Mat3::from_rows(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y, Vec3::Z);
    assert_eq!(probe.set_rotation(nan), Err(Error::InvalidRotation));
    assert_eq!(probe.irradiance(Vec3::Y).unwrap(), before);
    assert_eq!(
        cosine_weighted_average(probe.directions(), &good[..15], Vec3::Z),
        Err(Error::LengthMismatch)
    );
}

#[test]
fn cosine_weighted_average_matches_its_formula() {
    let dirs = [Vec3::Z, Vec3::X, Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.6, 0.0, 0.8)];
    let y = [1.0f32, 2.0, 100.0, 3.0];
    // n = +z: weights 1, 0, 0, 0.8.
    let want = core::f32::consts::PI * (1.0 + 0.8 * 3.0) / 1.8;
    let got = cosine_weighted_average(&dirs, &y, Vec3::new(0.0, 0.0, 2.0)).unwrap();
    assert!((got - want).abs() < 1e-6 * want);
    // Nothing above the horizon: zero.
    assert_eq!(cosine_weighted_average(&dirs[..1], &y[..1], Vec3::new(0.0, 0.0, -1.0)), Ok(0.0));
}

#[test]
fn table_footprint_is_pinned() {
    // Per member: two packed 32×33/2 blocks, g (32), 8 scalars, the 12-point glossy variance
    // grid, a 129-node table of quadratics.
    assert_eq!(
        Probe::<64>::TABLE_BYTES,
        Probe::<64>::family().len() * 4 * (32 * 33 + 32 + 8 + 12 + 3 * 129)
    );
    println!(
        "probe tables: N=16 {} B, 32 {} B, 64 {} B, 128 {} B, 256 {} B",
        Probe::<16>::TABLE_BYTES,
        Probe::<32>::TABLE_BYTES,
        Probe::<64>::TABLE_BYTES,
        Probe::<128>::TABLE_BYTES,
        Probe::<256>::TABLE_BYTES
    );
    for m in Probe::<64>::family() {
        println!("N=64 member {m:?}");
    }
}

use crate::calibration::glossy_calibration;
use crate::gen;

#[test]
fn z_table_matches_the_reference_kernel_mean() {
    // The generator's quadratic table (what the library stores, before f32 rounding) against
    // the reference's I₀ₑ quadrature, over a fine grid of t, for the baked sharpnesses and
    // beyond.
    for lambda in [0.5f64, 1.0, 4.0, 16.0, 64.0, 256.0] {
        let table = gen::probe::z_table(lambda);
        let mut worst = 0.0f64;
        let peak = PI * reference::bmc::kernel_mean(lambda, 1.0);
        for i in 0..=2000 {
            let t = -1.0 + 2.0 * i as f64 / 2000.0;
            let want = PI * reference::bmc::kernel_mean(lambda, t);
            worst = worst.max((gen::probe::z_interpolate(&table, t) - want).abs());
        }
        println!(
            "λ = {lambda}: max |table − π·z| = {worst:.2e} ({:.2e} of the peak)",
            worst / peak
        );
        assert!(worst < 2e-6 * peak, "λ = {lambda}: {worst:e}");
    }
}

#[test]
fn probe_config_errors_are_clear() {
    for (bad, what) in [
        ("probe = 15 0.3 1 4\n", "even"),
        ("probe = 16 0.3\n", "at least one lambda"),
        ("probe = 16 -0.3 1\n", "sigma"),
        ("probe = 16 0.3 4 1\n", "increase strictly"),
        ("probe = 32 0.3 1\nprobe = 16 0.3 1\n", "must exceed"),
        ("probe = 16 0.3 1 2 3 4 5 6 7 8 9\n", "at most"),
        ("set = 16 0.3 1\n", "expected `probe"),
        ("# nothing\n", "no `probe"),
        ("calibration = 16 1 2 2 2 2\nprobe = 16 0.3 1\n", "no earlier `probe = 16"),
        ("probe = 16 0.3 1\ncalibration = 16 4 2 2 2 2\n", "not in its family"),
        ("probe = 16 0.3 1\ncalibration = 16 1 2 2 2\n", "expected `calibration"),
        ("probe = 16 0.3 1\ncalibration = 16 1 2 0 2 2\n", "calibration factor 0"),
        ("probe = 16 0.3 1\ncalibration = 16 1 2 inf 2 2\n", "calibration factor inf"),
    ] {
        let e = gen::probe::parse(bad).unwrap_err();
        assert!(e.contains(what), "{bad:?}: {e}");
    }
    let ok = gen::probe::parse("probe = 16 0.3 1 4 # c\nprobe = 64 1 2\n").unwrap();
    assert_eq!(ok.len(), 2);
    assert_eq!(ok[1].lambdas, vec![2.0]);
    assert_eq!(ok[0].calibration, vec![[1.0; 4]; 2]);
    let cal = gen::probe::parse("probe = 16 0.3 1 4\ncalibration = 16 4 2 3 4 5\n").unwrap();
    assert_eq!(cal[0].calibration, vec![[1.0; 4], [2.0, 3.0, 4.0, 5.0]]);
}

/// The baked members carry the `calibration = …` lines of `tables/probe.txt` (read here
/// independently of the build script), rounded once to f32; members without a line keep 1.
#[test]
fn baked_calibration_is_the_table_s() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/tables/probe.txt")).unwrap();
    let lines: Vec<Vec<f64>> = text
        .lines()
        .filter_map(|l| l.split('#').next()?.trim().strip_prefix("calibration"))
        .map(|rest| {
            rest.trim_start_matches([' ', '='])
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect()
        })
        .collect();
    assert!(!lines.is_empty(), "tables/probe.txt has calibration lines");
    fn check<const N: usize>(lines: &[Vec<f64>])
    where
        Size<N>: ProbeSize,
    {
        for m in Probe::<N>::family() {
            let want = lines
                .iter()
                .find(|l| l[0] == N as f64 && l[1] as f32 == m.lambda)
                .map_or([1.0f32; 4], |l| [l[2] as f32, l[3] as f32, l[4] as f32, l[5] as f32]);
            assert_eq!(m.calibration, want, "N = {N}, λ = {}", m.lambda);
        }
    }
    check::<16>(&lines);
    check::<32>(&lines);
    check::<64>(&lines);
    check::<128>(&lines);
    check::<256>(&lines);
}

/// Glossy queries (value and exact variance) against the f64 reference, every member, lobes
/// from flat (μ = 0) to a near-mirror (μ = 400), through the probe's own f32 directions.
fn compare_glossy<const N: usize>(fields: usize) -> Vec<(f32, f32, f64, f64)>
where
    Size<N>: ProbeSize,
{
    let mut rng = Rng::new(0x6105 + N as u64);
    let mut out = Vec::new();
    let mut probe = Probe::<N>::new();
    // V̄ = ∫ G(x)·z(r·x) dx, z itself by quadrature: nested 1-D rules (once per λ, μ).
    let mut vbars = std::collections::HashMap::new();
    for _ in 0..fields {
        let rot = rng.uniform_rotation();
        probe.set_rotation(mat3(rot)).unwrap();
        let lights = field(&mut rng);
        let y: [f32; N] =
            core::array::from_fn(|i| radiance(&lights, to64(probe.directions()[i])) as f32);
        let y64: Vec<f64> = y.iter().map(|&v| v as f64).collect();
        for (k, m) in Probe::<N>::family().enumerate() {
            probe.update_with(&y, Selection::Member(k)).unwrap();
            let r = RefProbe::new(rot, N, m.lambda as f64, m.sigma as f64);
            for mu in [0.0f64, 0.5, 5.0, 40.0, 400.0] {
                let axis = rng.uniform_sphere();
                let amp = 0.5 + rng.next_f64();
                let vbar = *vbars
                    .entry((k, mu.to_bits()))
                    .or_insert_with(|| polar_integral_gl(mu, |t| sg_pair(m.lambda as f64, mu, t)));
                let (want, r2, v) = r.glossy(&y64, axis, mu, vbar);
                let lobe = SphericalGaussian {
                    axis: Vec3::new(axis[0] as f32, axis[1] as f32, axis[2] as f32),
                    sharpness: mu as f32,
                    amplitude: amp as f32,
                };
                let got = probe.glossy(&lobe).unwrap().value as f64;
                let rel = (got - amp * want).abs() / (amp * want).abs();
                let want_var = r2 / (N as f64 - 1.0) * v * amp * amp * glossy_calibration(&m, mu);
                let var = probe.glossy_variance(&lobe).unwrap() as f64;
                let rel_var = (var - want_var).abs() / want_var;
                out.push((m.lambda, m.condition, rel, rel_var));
                if mu == 40.0 {
                    println!(
                        "N = {N}, λ = {}, μ = {mu}: value {got:.6e} (ref {:.6e}), variance \
                         {var:.4e} (ref {want_var:.4e})",
                        m.lambda,
                        amp * want
                    );
                }
            }
        }
    }
    out
}

#[test]
fn glossy_matches_the_f64_reference() {
    for (n, rows) in [
        (16, compare_glossy::<16>(2)),
        (64, compare_glossy::<64>(2)),
        (256, compare_glossy::<256>(1)),
    ] {
        let mut worst = std::collections::BTreeMap::<u32, (f32, f64, f64)>::new();
        for (lambda, cond, rel, rel_var) in rows {
            let e = worst.entry(lambda.to_bits()).or_insert((cond, 0.0, 0.0));
            e.1 = e.1.max(rel);
            e.2 = e.2.max(rel_var);
        }
        for (bits, (cond, rel, rel_var)) in worst {
            let lambda = f32::from_bits(bits);
            println!(
                "N = {n}, λ = {lambda}: cond {cond:.1e}, max relative Δvalue {rel:.2e}, Δvariance \
                 {rel_var:.2e}"
            );
            // The same bar as irradiance (f32 solves; see f32_probe_matches_the_f64_reference),
            // now per query rather than RMS.
            let bar = if cond <= 1e4 { 1e-5 } else { f64::from(cond) * f64::from(f32::EPSILON) };
            assert!(rel < bar, "N = {n}, λ = {lambda}: glossy differs by {rel:e} (bar {bar:e})");
            assert!(rel_var < 1e-2, "N = {n}, λ = {lambda}: variance differs by {rel_var:e}");
        }
    }
}

#[test]
fn glossy_of_a_constant_is_exact_with_zero_variance() {
    let mut probe = Probe::<64, [f32; 3]>::new();
    probe.set_rotation(Mat3::from_axis_angle(Vec3::new(-1.0, 2.0, 0.5), 1.1)).unwrap();
    probe.update(&[[1.0, 0.25, 3.0]; 64]).unwrap();
    for (mu, amp) in [(0.0f32, 1.0f32), (1.0, 2.0), (21.0, 0.5), (1e4, 1.0), (1e8, 3.0)] {
        let lobe =
            SphericalGaussian { axis: Vec3::new(0.3, -0.2, 0.9), sharpness: mu, amplitude: amp };
        let integral = if mu == 0.0 {
            4.0 * PI
        } else {
            2.0 * PI * (-(-2.0 * mu as f64).exp_m1()) / mu as f64
        } * amp as f64;
        let got = probe.glossy(&lobe).unwrap();
        let var = probe.glossy_variance(&lobe).unwrap();
        assert_eq!(got.variance, [0.0; 3]);
        let got = got.value;
        for (c, want) in [1.0f64, 0.25, 3.0].iter().enumerate() {
            let want = want * integral;
            assert!((got[c] as f64 - want).abs() <= 1e-6 * want, "μ = {mu}: {got:?} vs {want}");
            assert_eq!(var[c], 0.0);
        }
    }
}

#[test]
fn glossy_phong_lobe_tracks_the_truth_and_beats_the_lobe_weighted_average() {
    // Smooth fields (sharpness 1–8) whose Phong-lobe integrals the reference computes by
    // quadrature; the probe's estimate against the normalised lobe-weighted average of the
    // same samples, Σ G(xⱼ)Yⱼ / Σ G(xⱼ) (the glossy analogue of the cosine-weighted average).
    let mut rng = Rng::new(0x5EED);
    let (mut se_bmc, mut se_avg, mut sa, mut within) = (0.0, 0.0, 0.0, 0usize);
    let mut count = 0usize;
    let mut probe = Probe::<64>::new();
    for _ in 0..8 {
        probe.set_rotation(mat3(rng.uniform_rotation())).unwrap();
        let lights: Vec<SgLight> = (0..3)
            .map(|_| SgLight {
                axis: rng.uniform_sphere(),
                sharpness: 1.0 + 7.0 * rng.next_f64(),
                amplitude: 0.2 + 0.8 * rng.next_f64(),
            })
            .collect();
        let y: [f32; 64] =
            core::array::from_fn(|i| radiance(&lights, to64(probe.directions()[i])) as f32);
        probe.update(&y).unwrap();
        for _ in 0..8 {
            let r = rng.uniform_sphere();
            let e = 10.0f32;
            let lobe = SphericalGaussian::phong_moments(
                Vec3::new(r[0] as f32, r[1] as f32, r[2] as f32),
                e,
            )
            .unwrap();
            // Truth for the SG lobe itself: the constant plus each light's SG pair integral.
            let a = lobe.amplitude as f64;
            let mu = lobe.sharpness as f64;
            let truth = a
                * (0.3 * 2.0 * PI * (1.0 - (-2.0 * mu).exp()) / mu
                    + lights
                        .iter()
                        .map(|l| {
                            l.amplitude * sg_pair(l.sharpness, mu, reference::vec::dot(l.axis, r))
                        })
                        .sum::<f64>());
            let got = probe.glossy(&lobe).unwrap().value as f64;
            let sd = (probe.glossy_variance(&lobe).unwrap() as f64).sqrt();
            let (mut num, mut den) = (0.0f64, 0.0f64);
            for (x, &yj) in probe.directions().iter().zip(&y) {
                let g = lobe.evaluate(*x) as f64;
                num += g * yj as f64;
                den += g;
            }
            let avg = if den > 0.0 { num / den } else { 0.0 };
            se_bmc += (got - truth).powi(2);
            se_avg += (avg - truth).powi(2);
            sa += truth.abs();
            within += usize::from((got - truth).abs() <= 2.0 * sd);
            count += 1;
        }
    }
    let mean = sa / count as f64;
    let (bmc, avg) = ((se_bmc / count as f64).sqrt() / mean, (se_avg / count as f64).sqrt() / mean);
    println!(
        "N = 64, Phong e = 10 on smooth SG fields: relative RMSE BMC {bmc:.4}, lobe-weighted \
         average {avg:.4}; |error| ≤ 2σ in {within}/{count}"
    );
    assert!(bmc < 0.5 * avg, "BMC {bmc} vs lobe-weighted average {avg}");
    assert!(within * 10 >= count * 8, "2σ coverage {within}/{count}");
}

#[test]
fn glossy_bad_input_is_refused() {
    let mut probe = Probe::<16>::new();
    let lobe = |axis, sharpness, amplitude| SphericalGaussian { axis, sharpness, amplitude };
    // Before any update: zero.
    assert_eq!(
        probe.glossy(&lobe(Vec3::Z, 5.0, 1.0)).map(|g| (g.value, g.variance)),
        Ok((0.0, 0.0))
    );
    assert_eq!(probe.glossy_variance(&lobe(Vec3::Z, 5.0, 1.0)), Ok(0.0));
    probe.update(&core::array::from_fn(|i| 1.0 + 0.1 * i as f32)).unwrap();
    for (l, err) in [
        (lobe(Vec3::new(0.0, 0.0, 0.0), 5.0, 1.0), Error::InvalidDirection),
        (lobe(Vec3::new(f32::NAN, 0.0, 1.0), 5.0, 1.0), Error::InvalidDirection),
        (lobe(Vec3::Z, -1.0, 1.0), Error::InvalidSharpness),
        (lobe(Vec3::Z, f32::NAN, 1.0), Error::InvalidSharpness),
        (lobe(Vec3::Z, f32::INFINITY, 1.0), Error::InvalidSharpness),
        (lobe(Vec3::Z, 2e8, 1.0), Error::InvalidSharpness),
        (lobe(Vec3::Z, 5.0, f32::NAN), Error::InvalidWeights),
        (lobe(Vec3::Z, 5.0, f32::INFINITY), Error::InvalidWeights),
    ] {
        assert_eq!(probe.glossy(&l), Err(err), "{l:?}");
        assert_eq!(probe.glossy_variance(&l), Err(err), "{l:?}");
    }
    // The largest accepted sharpness still gives a finite answer.
    let sharp = lobe(Vec3::Z, sphere_quadrature::probe::MAX_GLOSSY_SHARPNESS, 1.0);
    let g = probe.glossy(&sharp).unwrap();
    assert!(g.value.is_finite() && g.variance.is_finite() && g.variance >= 0.0);
    assert!(probe.glossy_variance(&sharp).unwrap().is_finite());
}

/// The O(N) glossy variance (baked direction average on a μ grid, interpolated) against the
/// exact O(N²) variance averaged over many random mirror directions, for every member, on the
/// grid and between its points.
fn fast_glossy_variance<const N: usize>() -> f64
where
    Size<N>: ProbeSize,
{
    let mut rng = Rng::new(0xFA57 + N as u64);
    let lights = field(&mut rng);
    let mut probe = Probe::<N>::new();
    let y: [f32; N] =
        core::array::from_fn(|i| radiance(&lights, to64(probe.directions()[i])) as f32);
    let mut worst = 0.0f64;
    for k in 0..Probe::<N>::family().len() {
        probe.update_with(&y, Selection::Member(k)).unwrap();
        for mu in [0.0f32, 0.5, 1.0, 3.0, 8.0, 22.0, 100.0, 700.0, 5000.0] {
            let (mut exact, mut fast) = (0.0f64, 0.0f64);
            let count = 400;
            for _ in 0..count {
                let r = rng.uniform_sphere();
                let lobe = SphericalGaussian {
                    axis: Vec3::new(r[0] as f32, r[1] as f32, r[2] as f32),
                    sharpness: mu,
                    amplitude: 0.7,
                };
                exact += probe.glossy_variance(&lobe).unwrap() as f64;
                fast += probe.glossy(&lobe).unwrap().variance as f64;
            }
            let ratio = fast / exact;
            println!("N = {N}, member {k}, μ = {mu}: fast / mean exact = {ratio:.3}");
            worst = worst.max((ratio.ln()).abs());
        }
    }
    worst
}

#[test]
fn fast_glossy_variance_is_the_direction_average_of_the_exact_one() {
    for (n, worst) in [
        (16, fast_glossy_variance::<16>()),
        (64, fast_glossy_variance::<64>()),
        (256, fast_glossy_variance::<256>()),
    ] {
        println!("N = {n}: worst |ln(fast / mean exact)| = {worst:.3}");
        // 37 baked directions against 400 random ones, and interpolation between grid points:
        // agreement to within a factor 1.25.
        assert!(worst < 1.25f64.ln(), "N = {n}: fast glossy variance off by e^{worst}");
    }
}
