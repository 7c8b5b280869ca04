//! The layout probe against a textbook f64 Gaussian process, and its contracts.

extern crate std;
use super::*;
use std::vec::Vec;

fn cube() -> [Sensor; 6] {
    [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z].map(Sensor::cosine)
}

fn dome() -> [Sensor; 5] {
    let h = core::f32::consts::FRAC_1_SQRT_2;
    [
        Vec3::Z,
        Vec3::new(h, 0.0, h),
        Vec3::new(0.0, h, h),
        Vec3::new(-h, 0.0, h),
        Vec3::new(0.0, -h, h),
    ]
    .map(Sensor::cosine)
}

/// `P_l(t)` by the textbook recurrence.
fn legendre_at(l: usize, t: f64) -> f64 {
    let (mut p0, mut p1) = (1.0, t);
    if l == 0 {
        return 1.0;
    }
    for m in 2..=l {
        let p2 = ((2 * m - 1) as f64 * t * p1 - (m - 1) as f64 * p0) / m as f64;
        p0 = p1;
        p1 = p2;
    }
    p1
}

/// The posterior mean and variance from the textbook formulas in f64: the covariance by
/// direct Legendre sums, a dense Cholesky factor, GLS for the mean and `s` in closed
/// form (no noise).
#[allow(clippy::too_many_arguments)]
pub(super) fn reference(
    dirs: &[[f64; 3]],
    gains: &[f64],
    prior: &Prior,
    profile: Option<&[f64]>,
    y: &[f64],
    n: [f64; 3],
    noise: Option<(f64, &[f64])>,
    lobe: Option<&[f64]>,
) -> (f64, f64, f64) {
    let k = dirs.len();
    // c_l = 2π∫₀¹ t P_l(t) dt by a fine midpoint rule, once per thread (it depends on nothing).
    std::thread_local! {
        static CLAMPED_COSINE: Vec<f64> = (0..DEGREES)
            .map(|l| {
                let m = 20000;
                (0..m)
                    .map(|i| {
                        let t = (i as f64 + 0.5) / m as f64;
                        t * legendre_at(l, t)
                    })
                    .sum::<f64>()
                    * 2.0
                    * core::f64::consts::PI
                    / m as f64
            })
            .collect();
    }
    let c: Vec<f64> = lobe.map_or_else(|| CLAMPED_COSINE.with(Clone::clone), <[f64]>::to_vec);
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let w = |l: usize| (2 * l + 1) as f64 / (4.0 * core::f64::consts::PI);
    let sp = |l: usize| f64::from(prior.spectrum[l]);
    // The zonal covariances: Σ_{l≠l'} R_ll'·f_l Y_l0(x)·f'_l' Y_l'0(x') with the textbook
    // Y_l0(z) = √((2l + 1)/(4π))·P_l(z).
    let r = [
        [0.0, f64::from(prior.zonal[0]), f64::from(prior.zonal[2])],
        [f64::from(prior.zonal[0]), 0.0, f64::from(prior.zonal[1])],
        [f64::from(prior.zonal[2]), f64::from(prior.zonal[1]), 0.0],
    ];
    let y0 = |l: usize, z: f64| {
        ((2 * l + 1) as f64 / (4.0 * core::f64::consts::PI)).sqrt() * legendre_at(l, z)
    };
    let zonal = |f: &dyn Fn(usize) -> f64, x: [f64; 3], f2: &dyn Fn(usize) -> f64, x2: [f64; 3]| {
        let mut t = 0.0;
        for l in 0..3 {
            for m in 0..3 {
                t += r[l][m] * f(l) * y0(l, x[2]) * f2(m) * y0(m, x2[2]);
            }
        }
        t
    };
    let g = |l: usize| gains[l];
    let cov = |i: usize, j: usize| {
        (0..DEGREES)
            .map(|l| sp(l) * gains[l] * gains[l] * w(l) * legendre_at(l, dot(dirs[i], dirs[j])))
            .sum::<f64>()
            + zonal(&g, dirs[i], &g, dirs[j])
    };
    let cq = |l: usize| c[l];
    let zq: Vec<f64> = (0..k)
        .map(|i| {
            (0..DEGREES)
                .map(|l| sp(l) * gains[l] * c[l] * w(l) * legendre_at(l, dot(dirs[i], n)))
                .sum::<f64>()
                + zonal(&g, dirs[i], &cq, n)
        })
        .collect();
    // Without noise the scale cancels from the mean; with noise s·C + diag(nᵢ).
    let (scale, nz): (f64, Vec<f64>) = match noise {
        None => (1.0, std::vec![0.0; k]),
        Some((s, n)) => (s, n.to_vec()),
    };
    let mut a: Vec<f64> = (0..k * k)
        .map(|x| scale * cov(x / k, x % k) + if x / k == x % k { nz[x / k] } else { 0.0 })
        .collect();
    if FLOORED.with(core::cell::Cell::get) {
        floor_eigenvalues(&mut a, k);
    }
    // Cholesky.
    for j in 0..k {
        for i in j..k {
            let mut s = a[i * k + j];
            for m in 0..j {
                s -= a[i * k + m] * a[j * k + m];
            }
            a[i * k + j] = if i == j { s.sqrt() } else { s / a[j * k + j] };
        }
    }
    let solve = |b: &[f64]| {
        let mut x = b.to_vec();
        for i in 0..k {
            for m in 0..i {
                x[i] -= a[i * k + m] * x[m];
            }
            x[i] /= a[i * k + i];
        }
        for i in (0..k).rev() {
            for m in i + 1..k {
                x[i] -= a[m * k + i] * x[m];
            }
            x[i] /= a[i * k + i];
        }
        x
    };
    let ip = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(p, q)| p * q).sum::<f64>();
    let (h, hq): (Vec<f64>, f64) = match profile {
        None => (std::vec![0.0; k], 0.0),
        Some(p) => (
            (0..k)
                .map(|i| (0..p.len()).map(|l| p[l] * gains[l] * legendre_at(l, dirs[i][2])).sum())
                .collect(),
            (0..p.len()).map(|l| p[l] * c[l] * legendre_at(l, n[2])).sum(),
        ),
    };
    let qy = solve(y);
    let qh = solve(&h);
    let qz = solve(&zq);
    let (beta, hqh) =
        if profile.is_some() { (ip(&h, &qy) / ip(&h, &qh), ip(&h, &qh)) } else { (0.0, 0.0) };
    let r: Vec<f64> = (0..k).map(|i| y[i] - beta * h[i]).collect();
    let qr = solve(&r);
    let p = usize::from(profile.is_some());
    let s = ip(&r, &qr) / (k - p) as f64;
    let value = beta * hq + scale * ip(&zq, &qr);
    // REML without noise at s = rᵀC⁻¹r/(K − p):
    // −½·((K − p)·ln s + ln det C + ln hᵀC⁻¹h + (K − p)).
    let log_det: f64 = (0..k).map(|i| 2.0 * a[i * k + i].ln()).sum();
    let p_terms = usize::from(profile.is_some());
    let s_reml = ip(&r, &qr) / (k - p_terms) as f64;
    let free = (k - p_terms) as f64;
    let log_likelihood = -0.5
        * (free * s_reml.ln() + log_det + if profile.is_some() { hqh.ln() } else { 0.0 } + free);
    let vbar: f64 =
        (0..DEGREES).map(|l| sp(l) * c[l] * c[l] * w(l)).sum::<f64>() + zonal(&cq, n, &cq, n);
    let mut var = vbar - ip(&zq, &qz);
    if profile.is_some() {
        let rr = hq - ip(&h, &qz);
        var += rr * rr / hqh;
    }
    (value, s * var, log_likelihood)
}

std::thread_local! {
    /// Whether [`reference`] floors the eigenvalues of its system at 10⁻⁶ of the largest, as
    /// the probe does (the model's least noise), instead of taking them as they are.
    pub(super) static FLOORED: core::cell::Cell<bool> = const { core::cell::Cell::new(false) };
}

/// The symmetric `k × k` matrix `a` with its eigenvalues floored at `FLOOR` times the largest
/// (cyclic Jacobi in f64).
fn floor_eigenvalues(a: &mut [f64], k: usize) {
    let mut m = a.to_vec();
    let mut v: Vec<f64> = (0..k * k).map(|x| if x / k == x % k { 1.0 } else { 0.0 }).collect();
    for _ in 0..100 {
        let off: f64 = (0..k * k).filter(|x| x / k != x % k).map(|x| m[x] * m[x]).sum();
        if off < 1e-30 {
            break;
        }
        for p in 0..k {
            for q in p + 1..k {
                if m[p * k + q].abs() < 1e-300 {
                    continue;
                }
                let theta = (m[q * k + q] - m[p * k + p]) / (2.0 * m[p * k + q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for r in 0..k {
                    let (mp, mq) = (m[r * k + p], m[r * k + q]);
                    m[r * k + p] = c * mp - s * mq;
                    m[r * k + q] = s * mp + c * mq;
                }
                for r in 0..k {
                    let (mp, mq) = (m[p * k + r], m[q * k + r]);
                    m[p * k + r] = c * mp - s * mq;
                    m[q * k + r] = s * mp + c * mq;
                }
                for r in 0..k {
                    let (vp, vq) = (v[r * k + p], v[r * k + q]);
                    v[r * k + p] = c * vp - s * vq;
                    v[r * k + q] = s * vp + c * vq;
                }
            }
        }
    }
    let top = (0..k).fold(0.0f64, |t, i| t.max(m[i * k + i]));
    let values: Vec<f64> = (0..k).map(|i| m[i * k + i].max(f64::from(FLOOR) * top)).collect();
    for i in 0..k {
        for j in 0..k {
            a[i * k + j] = (0..k).map(|e| v[i * k + e] * values[e] * v[j * k + e]).sum();
        }
    }
}

pub(super) fn to64(v: Vec3) -> [f64; 3] {
    [f64::from(v.x), f64::from(v.y), f64::from(v.z)]
}

/// Against the f64 reference: a cube (zero mean) and a dome (zonal mean), arbitrary
/// readings, twenty normals.
#[test]
fn agrees_with_an_f64_reference() {
    let gains: Vec<f64> =
        Response::CosinePower(1.0).gains().unwrap().iter().map(|&g| f64::from(g)).collect();
    let se = Prior::squared_exponential(4.0).unwrap();
    let mut profile = [0.0f32; 9];
    profile[0] = 1.0;
    profile[1] = 0.9;
    profile[2] = 0.4;
    let normals: Vec<Vec3> = (0..20)
        .map(|i| {
            let t = i as f32 * 0.7;
            Vec3::new(libm::cosf(t), libm::sinf(1.3 * t), 0.2 + 0.05 * i as f32)
        })
        .collect();
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    // Cube, zero mean.
    let sensors = cube();
    let y = [1.3f32, 0.4, 0.9, 0.7, 2.1, 0.2];
    let mut probe = LayoutProbe::<6>::new(&sensors, se.with_mean(Mean::Zero), Noise::NONE).unwrap();
    probe.update(&y).unwrap();
    let dirs: Vec<[f64; 3]> = sensors.iter().map(|s| to64(s.direction)).collect();
    let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
    for &n in &normals {
        let (v, var, ll) =
            reference(&dirs, &gains, &se, None, &y64, to64(n.try_normalize().unwrap()), None, None);
        let e = probe.irradiance(n).unwrap();
        let ev = probe.irradiance_variance(n).unwrap();
        worst.0 = worst.0.max((f64::from(e.value) - v).abs() / 2.1);
        worst.2 = worst.2.max((f64::from(probe.log_likelihood()) - ll).abs());
        worst.1 = worst.1.max((f64::from(ev) - var).abs() / var.max(1e-3));
    }
    // Dome, zonal mean.
    let sensors = dome();
    let y = [2.0f32, 1.2, 1.5, 0.8, 1.1];
    let prior = se.with_mean(Mean::Zonal(profile));
    let mut probe = LayoutProbe::<5>::new(&sensors, prior, Noise::NONE).unwrap();
    probe.update(&y).unwrap();
    let dirs: Vec<[f64; 3]> =
        sensors.iter().map(|s| to64(s.direction.try_normalize().unwrap())).collect();
    let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
    let p64: Vec<f64> = profile.iter().map(|&v| f64::from(v)).collect();
    for &n in &normals {
        let (v, var, ll) = reference(
            &dirs,
            &gains,
            &se,
            Some(&p64),
            &y64,
            to64(n.try_normalize().unwrap()),
            None,
            None,
        );
        let e = probe.irradiance(n).unwrap();
        let ev = probe.irradiance_variance(n).unwrap();
        worst.0 = worst.0.max((f64::from(e.value) - v).abs() / 2.0);
        worst.2 = worst.2.max((f64::from(probe.log_likelihood()) - ll).abs());
        worst.1 = worst.1.max((f64::from(ev) - var).abs() / var.max(1e-3));
    }
    std::eprintln!("WORST {:?}", worst);
    assert!(
        worst.0 < 1e-5 && worst.1 < 5e-4 && worst.2 < 1e-5,
        "value {:e}, variance {:e}, log likelihood {:e}",
        worst.0,
        worst.1,
        worst.2
    );
}

/// With a relative noise the mean is that of the exact system `s·C + diag(η²Yᵢ²)` at the
/// probe's scale `s`, against the f64 reference.
#[test]
fn relative_noise_solves_the_exact_system() {
    let gains: Vec<f64> =
        Response::CosinePower(1.0).gains().unwrap().iter().map(|&g| f64::from(g)).collect();
    let se = Prior::squared_exponential(4.0).unwrap();
    let mut profile = [0.0f32; 9];
    profile[0] = 1.0;
    profile[1] = 0.9;
    let sensors = dome();
    let y = [2.0f32, 1.2, 1.5, 0.8, 1.1];
    let eta = 0.05f32;
    let prior = se.with_mean(Mean::Zonal(profile));
    let mut probe =
        LayoutProbe::<5>::new(&sensors, prior, Noise { absolute: 0.0, relative: eta }).unwrap();
    probe.update(&y).unwrap();
    let s = f64::from(probe.signal_variance());
    let dirs: Vec<[f64; 3]> =
        sensors.iter().map(|s| to64(s.direction.try_normalize().unwrap())).collect();
    let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
    let noise: Vec<f64> = y64.iter().map(|v| (f64::from(eta) * v).powi(2)).collect();
    let p64: Vec<f64> = profile.iter().map(|&v| f64::from(v)).collect();
    let mut worst = 0.0f64;
    for n in [Vec3::Z, Vec3::new(0.5, 0.2, 0.8), Vec3::new(-0.7, 0.1, 0.3), Vec3::X] {
        let (v, _, _) = reference(
            &dirs,
            &gains,
            &se,
            Some(&p64),
            &y64,
            to64(n.try_normalize().unwrap()),
            Some((s, &noise)),
            None,
        );
        worst = worst.max((f64::from(probe.irradiance(n).unwrap().value) - v).abs() / 2.0);
    }
    // Measured 8.8·10⁻⁷: the f32 factor of a system of condition about 10⁴, whose weights
    // (up to 20 times the answer) cancel, refined once (1.7·10⁻⁴ without the refinement).
    assert!(s > 0.0 && worst < 4e-6, "s {s}, worst {worst:e}");
}

/// A combination of channels: with an absolute noise, the same probe as one built for the
/// combined readings with noise `σ·|w|` (bit for bit); with a relative noise, the exact
/// system of the combined readings' noise `η²·Σ w_c²Y_c²` (f64 reference); channels in
/// proportion add their errors in proportion (not in quadrature); bad weights are errors.
#[test]
fn a_combination_of_channels_is_fitted_with_its_own_noise() {
    let sensors = dome();
    let se = Prior::squared_exponential(4.0).unwrap();
    let mut profile = [0.0f32; 9];
    profile[0] = 1.0;
    profile[1] = 0.9;
    let prior = se.with_mean(Mean::Zonal(profile));
    let y = [2.0f32, 1.2, 1.5, 0.8, 1.1];
    let rgb: [[f32; 3]; 5] = core::array::from_fn(|i| [y[i], 0.5 + 0.3 * y[i], 1.7 - 0.4 * y[i]]);
    let w = [0.2126f32, 0.7152, 0.0722];
    let combined: [f32; 5] = core::array::from_fn(|i| (0..3).map(|c| w[c] * rgb[i][c]).sum());
    let norm = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    let normals = [Vec3::Z, Vec3::new(0.5, 0.2, 0.8), Vec3::new(-0.7, 0.1, 0.3), Vec3::X];
    // Absolute noise.
    let noise = Noise { absolute: 0.02, relative: 0.0 };
    let mut probe = LayoutProbe::<5, [f32; 3]>::new(&sensors, prior, noise).unwrap();
    probe.update(&rgb).unwrap();
    let luminance = probe.combined_probe(w).unwrap();
    let mut direct =
        LayoutProbe::<5>::new(&sensors, prior, Noise { absolute: 0.02 * norm, relative: 0.0 })
            .unwrap();
    direct.update(&combined).unwrap();
    for n in normals {
        let (a, b) = (luminance.irradiance(n).unwrap(), direct.irradiance(n).unwrap());
        assert_eq!(
            (a.value.to_bits(), a.variance.to_bits()),
            (b.value.to_bits(), b.variance.to_bits())
        );
        let (a, b) =
            (luminance.irradiance_variance(n).unwrap(), direct.irradiance_variance(n).unwrap());
        assert_eq!(a.to_bits(), b.to_bits());
    }
    // Relative noise: the exact system at the combined probe's scale.
    let eta = 0.05f32;
    let mut probe =
        LayoutProbe::<5, [f32; 3]>::new(&sensors, prior, Noise { absolute: 0.0, relative: eta })
            .unwrap();
    probe.update(&rgb).unwrap();
    let luminance = probe.combined_probe(w).unwrap();
    let s = f64::from(luminance.signal_variance());
    let gains: Vec<f64> =
        Response::CosinePower(1.0).gains().unwrap().iter().map(|&g| f64::from(g)).collect();
    let dirs: Vec<[f64; 3]> =
        sensors.iter().map(|s| to64(s.direction.try_normalize().unwrap())).collect();
    let y64: Vec<f64> = combined.iter().map(|&v| f64::from(v)).collect();
    let noise64: Vec<f64> = rgb
        .iter()
        .map(|r| (0..3).map(|c| (f64::from(eta) * f64::from(w[c]) * f64::from(r[c])).powi(2)).sum())
        .collect();
    let p64: Vec<f64> = profile.iter().map(|&v| f64::from(v)).collect();
    let mut worst = 0.0f64;
    for n in normals {
        let (v, _, _) = reference(
            &dirs,
            &gains,
            &se,
            Some(&p64),
            &y64,
            to64(n.try_normalize().unwrap()),
            Some((s, &noise64)),
            None,
        );
        worst = worst.max((f64::from(luminance.irradiance(n).unwrap().value) - v).abs() / v);
    }
    assert!(s > 0.0 && worst < 5e-4, "s {s}, worst {worst:e}");
    // Channels in proportion, no noise: errors add linearly, 1 + 2 + 3 = 6 times the first
    // channel's, a variance 36 times (the channels' variances summed would give 14). (The
    // direction-averaged variance: at the sensors' own directions the exact one is at the
    // level of rounding without noise.)
    let mut probe = LayoutProbe::<5, [f32; 3]>::new(&sensors, prior, Noise::NONE).unwrap();
    probe.update(&y.map(|v| [v, 2.0 * v, 3.0 * v])).unwrap();
    let sum = probe.combined_probe([1.0, 1.0, 1.0]).unwrap();
    let one = probe.irradiance(Vec3::Z).unwrap().variance[0];
    let all = sum.irradiance(Vec3::Z).unwrap().variance;
    assert!(one > 0.0 && (all / one - 36.0).abs() < 36.0 * 1e-5, "{}", all / one);
    // Bad weights.
    assert_eq!(probe.combined_probe([f32::NAN, 1.0, 0.0]).unwrap_err(), Error::InvalidWeights);
    assert_eq!(probe.combined_probe([0.0; 3]).unwrap_err(), Error::InvalidWeights);
    let fresh = LayoutProbe::<5, [f32; 3]>::new(&sensors, prior, Noise::NONE).unwrap();
    assert!(!fresh.combined_probe(w).unwrap().is_updated());
}

/// Phong and SG lobes against the f64 reference with the lobes' Legendre coefficients
/// by a midpoint rule.
#[test]
fn lobes_agree_with_the_f64_reference() {
    let gains: Vec<f64> =
        Response::CosinePower(1.0).gains().unwrap().iter().map(|&g| f64::from(g)).collect();
    let se = Prior::squared_exponential(6.0).unwrap();
    let mut profile = [0.0f32; 9];
    profile[0] = 1.0;
    profile[1] = 0.7;
    let sensors = dome();
    let y = [2.0f32, 1.2, 1.5, 0.8, 1.1];
    let mut probe =
        LayoutProbe::<5>::new(&sensors, se.with_mean(Mean::Zonal(profile)), Noise::NONE).unwrap();
    probe.update(&y).unwrap();
    let dirs: Vec<[f64; 3]> =
        sensors.iter().map(|s| to64(s.direction.try_normalize().unwrap())).collect();
    let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
    let p64: Vec<f64> = profile.iter().map(|&v| f64::from(v)).collect();
    // q_l = 2π∫ f(t)·P_l(t) dt by a midpoint rule in t.
    let coefficients = |f: &dyn Fn(f64) -> f64| -> Vec<f64> {
        let m = 200_000;
        let mut q = std::vec![0.0f64; DEGREES];
        for i in 0..m {
            let t = -1.0 + 2.0 * (i as f64 + 0.5) / m as f64;
            let (mut p0, mut p1) = (1.0, t);
            let v = f(t) * 2.0 / m as f64 * 2.0 * core::f64::consts::PI;
            q[0] += v;
            q[1] += v * t;
            for (l, ql) in q.iter_mut().enumerate().skip(2) {
                let p2 = ((2 * l - 1) as f64 * t * p1 - (l - 1) as f64 * p0) / l as f64;
                *ql += v * p2;
                p0 = p1;
                p1 = p2;
            }
        }
        q
    };
    let e = 12.0f64;
    let phong =
        coefficients(&|t: f64| (e + 1.0) / (2.0 * core::f64::consts::PI) * t.max(0.0).powf(e));
    let (mu, a) = (9.0f64, 1.7f64);
    let sg = coefficients(&|t: f64| a * (mu * (t - 1.0)).exp());
    let mut worst = (0.0f64, 0.0f64);
    for axis in [Vec3::Z, Vec3::new(0.5, 0.2, 0.8), Vec3::new(-0.7, 0.1, 0.3)] {
        let r = to64(axis.try_normalize().unwrap());
        let (v, var, _) = reference(&dirs, &gains, &se, Some(&p64), &y64, r, None, Some(&phong));
        let est = probe.phong(axis, e as f32).unwrap();
        worst.0 = worst.0.max((f64::from(est.value) - v).abs() / v.abs());
        worst.1 = worst.1.max((f64::from(est.variance) - var).abs() / var);
        let lobe = SphericalGaussian::new(axis, mu as f32, a as f32).unwrap();
        let (v, var, _) = reference(&dirs, &gains, &se, Some(&p64), &y64, r, None, Some(&sg));
        let est = probe.glossy(&lobe).unwrap();
        worst.0 = worst.0.max((f64::from(est.value) - v).abs() / v.abs());
        worst.1 = worst.1.max((f64::from(est.variance) - var).abs() / var);
    }
    assert!(worst.0 < 2e-5 && worst.1 < 2e-5, "value {:e}, variance {:e}", worst.0, worst.1);
    assert_eq!(probe.phong(Vec3::Z, -1.0).err(), Some(Error::InvalidExponent));
    assert_eq!(probe.phong(Vec3::ZERO, 2.0).err(), Some(Error::InvalidDirection));
    let sharp = SphericalGaussian { axis: Vec3::Z, sharpness: 2e8, amplitude: 1.0 };
    assert_eq!(probe.glossy(&sharp).err(), Some(Error::InvalidSharpness));
}

/// With a spectrum of degrees ≤ 2 only, the SH export holds the whole posterior mean: its
/// irradiance is the probe's.
#[test]
fn radiance_sh_holds_the_posterior_mean() {
    let mut spectrum = [0.0f32; DEGREES];
    spectrum[..3].copy_from_slice(&[12.0, 3.0, 1.5]);
    for mean in [Mean::Zero, Mean::Constant] {
        let mut probe = LayoutProbe::<6, [f32; 3]>::new(
            &cube(),
            Prior { spectrum, zonal: [0.0; 3], mean, variance_scale: 1.0 },
            Noise::NONE,
        )
        .unwrap();
        probe
            .update(&[
                [1.3, 1.0, 0.2],
                [0.4, 1.1, 0.3],
                [0.9, 0.9, 0.4],
                [0.7, 1.0, 0.1],
                [2.1, 1.4, 0.6],
                [0.2, 0.5, 0.2],
            ])
            .unwrap();
        let sh = probe.radiance_sh();
        for n in [Vec3::Z, Vec3::new(0.3, -0.8, 0.1), Vec3::new(-1.0, 0.2, -0.4)] {
            let a = probe.irradiance(n).unwrap().value;
            let b = sh.irradiance(n).unwrap();
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() < 1e-4 * a[c].abs().max(1.0), "{a:?} {b:?}");
            }
        }
    }
}

/// A stream of noisy readings of static light: pooling cuts the noise's error; a change
/// resets; a non-finite reading is refused with the state kept.
#[test]
fn a_stream_pools_static_light_and_resets_on_a_change() {
    let eta = 0.05f32;
    let noise = Noise { absolute: 0.0, relative: eta };
    let mut probe = LayoutProbe::<6>::new(&cube(), Prior::ENVIRONMENT, noise).unwrap();
    // A linear sky 1 + 0.6·z + 0.3·x: a cosine sensor reads 1 + (2/3)·(0.6·d_z + 0.3·d_x).
    let light = |d: Vec3| 1.0 + 2.0 / 3.0 * (0.6 * d.z + 0.3 * d.x);
    let exact = cube().map(|s| light(s.direction));
    let truth = |n: Vec3| core::f32::consts::PI * (1.0 + 2.0 / 3.0 * (0.6 * n.z + 0.3 * n.x));
    let normals = [Vec3::Z, Vec3::X, Vec3::new(0.3, -0.5, 0.6), Vec3::new(-0.2, 0.7, -0.5)];
    let mut state = 12345u32;
    let mut gaussian = move || {
        // Sum of 12 uniforms minus 6: close to a standard normal.
        (0..12)
            .map(|_| {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (state >> 8) as f32 / (1u32 << 24) as f32
            })
            .sum::<f32>()
            - 6.0
    };
    // The deviation from the estimate of noise-free readings, which pooling approaches.
    let mut clean = LayoutProbe::<6>::new(&cube(), Prior::ENVIRONMENT, Noise::NONE).unwrap();
    clean.update(&exact).unwrap();
    let error = |p: &LayoutProbe<6>| {
        normals
            .iter()
            .map(|&n| (p.irradiance(n).unwrap().value - clean.irradiance(n).unwrap().value).abs())
            .sum::<f32>()
    };
    // The noise-free estimate is close to the truth.
    for &n in &normals {
        let e = clean.irradiance(n).unwrap().value;
        assert!((e - truth(n)).abs() < 0.05 * truth(n).abs().max(1.0), "{e} {}", truth(n));
    }
    let (mut first, mut pooled) = (0.0f32, 0.0f32);
    for trial in 0..16 {
        let mut p = probe.clone();
        for k in 0..64 {
            let y = exact.map(|v| v * (1.0 + eta * gaussian()));
            let change = p.pool(&y).unwrap();
            if k == 0 {
                assert_eq!(change, Change::First);
                first += error(&p);
            } else {
                assert_ne!(change, Change::Reset, "trial {trial}, update {k}");
            }
        }
        assert!(p.pooled_updates() > 60.0, "{}", p.pooled_updates());
        pooled += error(&p);
    }
    // Measured 0.15 (1/√64 = 0.125).
    assert!(pooled < 0.25 * first, "pooled {pooled}, first {first}");
    // The light dims to a half: a reset.
    probe.pool(&exact).unwrap();
    probe.pool(&exact).unwrap();
    let before = probe.irradiance(Vec3::Z).unwrap();
    assert_eq!(probe.pool(&[1.0, f32::NAN, 1.0, 1.0, 1.0, 1.0]), Err(Error::InvalidRadiance));
    assert_eq!(probe.irradiance(Vec3::Z).unwrap(), before);
    assert_eq!(probe.pool(&exact.map(|v| 0.5 * v)).unwrap(), Change::Reset);
    assert!(probe.last_change_probability() > 0.99 && probe.pooled_updates() < 1.01);
    for h in [0.0, 1.0, f32::NAN] {
        assert!(probe.clone().with_hazard(h).is_err());
    }
}

/// A prior with zonal covariances (light from above): values, exact variances, a lobe,
/// the likelihood and the direction-averaged variance against the f64 reference.
#[test]
fn zonal_covariances_agree_with_the_f64_reference() {
    let gains: Vec<f64> =
        Response::CosinePower(1.0).gains().unwrap().iter().map(|&g| f64::from(g)).collect();
    let mut spectrum = Prior::squared_exponential(4.0).unwrap().spectrum;
    spectrum[0] = 1.0;
    spectrum[1] = 1.0;
    spectrum[2] = 1.0;
    let zonal = [0.5, 0.5, 0.33];
    let sensors = dome();
    let y = [2.0f32, 1.2, 1.5, 0.8, 1.1];
    let dirs: Vec<[f64; 3]> =
        sensors.iter().map(|s| to64(s.direction.try_normalize().unwrap())).collect();
    let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
    let mut profile = [0.0f32; 9];
    profile[0] = 1.0;
    profile[1] = 0.8;
    let p64: Vec<f64> = profile.iter().map(|&v| f64::from(v)).collect();
    let e = 12.0f64;
    let phong: Vec<f64> =
        Response::CosinePower(e as f32).gains().unwrap().iter().map(|&g| f64::from(g)).collect();
    let mut worst = [0.0f64; 5];
    for mean in [Mean::Zero, Mean::Zonal(profile)] {
        let prior = Prior { spectrum, zonal, mean, variance_scale: 1.0 };
        let mut probe = LayoutProbe::<5>::new(&sensors, prior, Noise::NONE).unwrap();
        probe.update(&y).unwrap();
        let zonal_mean = if mean == Mean::Zero { None } else { Some(&p64[..]) };
        for n in [Vec3::Z, Vec3::new(0.5, 0.2, 0.8), Vec3::new(-0.7, 0.1, 0.3), Vec3::X] {
            let r = to64(n.try_normalize().unwrap());
            let (v, var, ll) = reference(&dirs, &gains, &prior, zonal_mean, &y64, r, None, None);
            let est = probe.irradiance(n).unwrap();
            worst[0] = worst[0].max((f64::from(est.value) - v).abs() / 2.0);
            // At +z the zenith sensor reads the irradiance itself: the exact variance is 0,
            // and the f32 one is the rounding of the prior (2.4 here) less the part explained,
            // measured 1.7·10⁻⁶ (6 ε of the prior); relative to 10⁻² there.
            worst[1] = worst[1].max(
                (f64::from(probe.irradiance_variance(n).unwrap()) - var).abs() / var.max(1e-2),
            );
            worst[2] = worst[2].max((f64::from(probe.log_likelihood()) - ll).abs());
            let (v, var, _) =
                reference(&dirs, &gains, &prior, zonal_mean, &y64, r, None, Some(&phong));
            let est = probe.phong(n, e as f32).unwrap();
            worst[3] = worst[3].max((f64::from(est.value) - v).abs() / v.abs());
            worst[3] = worst[3].max((f64::from(est.variance) - var).abs() / var);
        }
        // The O(1) variance: the mean of the exact ones over a Fibonacci sphere.
        let m = 4000;
        let mut sum = 0.0f64;
        for i in 0..m {
            let z = 1.0 - (2 * i + 1) as f32 / m as f32;
            let rr = libm::sqrtf(1.0 - z * z);
            let phi = i as f32 * 2.399_963;
            let n = Vec3::new(rr * libm::cosf(phi), rr * libm::sinf(phi), z);
            sum += f64::from(probe.irradiance_variance(n).unwrap()) / f64::from(m);
        }
        let average = f64::from(probe.irradiance(Vec3::Z).unwrap().variance);
        worst[4] = worst[4].max((average - sum).abs() / sum);
    }
    assert!(
        worst[0] < 1e-5 && worst[1] < 5e-4 && worst[2] < 1e-4 && worst[3] < 1e-4 && worst[4] < 1e-2,
        "{worst:?}"
    );
    // Zonal covariances beyond the diagonal's reach: not positive semi-definite.
    let bad = Prior { spectrum, zonal: [1.5, 0.0, 0.0], mean: Mean::Zero, variance_scale: 1.0 };
    assert_eq!(LayoutProbe::<5>::new(&sensors, bad, Noise::NONE).err(), Some(Error::InvalidPrior));
    let nan =
        Prior { spectrum, zonal: [f32::NAN, 0.0, 0.0], mean: Mean::Zero, variance_scale: 1.0 };
    assert_eq!(LayoutProbe::<5>::new(&sensors, nan, Noise::NONE).err(), Some(Error::InvalidPrior));
}

/// The O(1) variance is the direction average of the exact one.
#[test]
fn average_variance_is_the_mean_of_the_exact_ones() {
    let mut profile = [0.0f32; 9];
    profile[0] = 1.0;
    profile[1] = 0.8;
    for (prior, noise) in [
        (Prior::squared_exponential(3.0).unwrap().with_mean(Mean::Zero), Noise::NONE),
        (
            Prior::squared_exponential(3.0).unwrap().with_mean(Mean::Zonal(profile)),
            Noise { absolute: 0.05, relative: 0.02 },
        ),
    ] {
        let mut probe = LayoutProbe::<5, [f32; 3]>::new(&dome(), prior, noise).unwrap();
        probe
            .update(&[
                [2.0, 1.0, 0.5],
                [1.2, 0.9, 0.4],
                [1.5, 1.1, 0.6],
                [0.8, 1.0, 0.5],
                [1.1, 0.7, 0.3],
            ])
            .unwrap();
        let n = 4000;
        let mut sum = [0.0f64; 3];
        for i in 0..n {
            // A spherical Fibonacci set.
            let z = 1.0 - (2 * i + 1) as f32 / n as f32;
            let r = libm::sqrtf(1.0 - z * z);
            let phi = i as f32 * 2.399_963;
            let v = probe
                .irradiance_variance(Vec3::new(r * libm::cosf(phi), r * libm::sinf(phi), z))
                .unwrap();
            for c in 0..3 {
                sum[c] += f64::from(v[c]) / n as f64;
            }
        }
        let average = probe.irradiance(Vec3::Z).unwrap().variance;
        for c in 0..3 {
            let rel = (f64::from(average[c]) - sum[c]).abs() / sum[c];
            assert!(rel < 1e-2, "channel {c}: {} vs {}", average[c], sum[c]);
        }
    }
}

#[test]
fn bad_input_is_an_error_and_keeps_the_state() {
    let prior = Prior::squared_exponential(2.0).unwrap();
    let mut probe = LayoutProbe::<6>::new(&cube(), prior, Noise::NONE).unwrap();
    probe.update(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
    let before = probe.irradiance(Vec3::Z).unwrap();
    assert_eq!(probe.update(&[1.0, f32::NAN, 3.0, 4.0, 5.0, 6.0]), Err(Error::InvalidRadiance));
    assert_eq!(
        probe.update(&[1.0, 2.0, f32::INFINITY, 4.0, 5.0, 6.0]),
        Err(Error::InvalidRadiance)
    );
    assert_eq!(probe.irradiance(Vec3::Z).unwrap(), before);
    assert_eq!(probe.irradiance(Vec3::ZERO), Err(Error::InvalidDirection));
    assert_eq!(probe.irradiance(Vec3::new(f32::NAN, 0.0, 1.0)), Err(Error::InvalidDirection));
    let mut s = cube();
    s[2].direction = Vec3::new(f32::NAN, 0.0, 0.0);
    assert_eq!(LayoutProbe::<6>::new(&s, prior, Noise::NONE).err(), Some(Error::InvalidDirection));
    let mut s = cube();
    s[2].noise_scale = 0.0;
    assert_eq!(LayoutProbe::<6>::new(&s, prior, Noise::NONE).err(), Some(Error::InvalidNoise));
    let mut s = cube();
    s[2].response = Response::CosinePower(f32::NAN);
    assert_eq!(LayoutProbe::<6>::new(&s, prior, Noise::NONE).err(), Some(Error::InvalidResponse));
    let bad_noise = Noise { absolute: -1.0, relative: 0.0 };
    assert_eq!(LayoutProbe::<6>::new(&cube(), prior, bad_noise).err(), Some(Error::InvalidNoise));
    // Five distinct responses, one more than MAX_RESPONSES.
    let mut s = cube();
    for (i, sensor) in s.iter_mut().enumerate().take(5) {
        sensor.response = Response::CosinePower(1.0 + i as f32);
    }
    assert_eq!(LayoutProbe::<6>::new(&s, prior, Noise::NONE).err(), Some(Error::InvalidResponse));
    // More than MAX_SENSORS.
    let many = [Sensor::cosine(Vec3::Z); MAX_SENSORS + 1];
    assert_eq!(
        LayoutProbe::<{ MAX_SENSORS + 1 }>::new(&many, prior, Noise::NONE).err(),
        Some(Error::InvalidSize)
    );
    // One sensor cannot fit a constant mean.
    assert_eq!(
        LayoutProbe::<1>::new(&[Sensor::cosine(Vec3::Z)], prior, Noise::NONE).err(),
        Some(Error::InvalidSize)
    );
}

/// Duplicate sensors and antipodal cosine pairs make the system singular; the model's
/// least noise keeps it solvable, with and without a noise of the layout.
#[test]
fn dependent_readings_are_solvable() {
    let prior = Prior::squared_exponential(4.0).unwrap();
    let mut s = cube();
    s[1] = s[0];
    for noise in [Noise::NONE, Noise { absolute: 0.01, relative: 0.0 }] {
        let mut probe = LayoutProbe::<6>::new(&s, prior, noise).unwrap();
        // Consistent duplicate readings.
        probe.update(&[1.5, 1.5, 0.9, 0.7, 2.1, 0.2]).unwrap();
        let e = probe.irradiance(Vec3::X).unwrap();
        assert!(e.value.is_finite() && e.variance >= 0.0 && e.variance.is_finite());
        // The duplicate pair reads 1.5 each; the estimate near +x is near π·1.5.
        assert!((e.value / core::f32::consts::PI - 1.5).abs() < 0.3, "{}", e.value);
    }
}

/// Readings scaled by a power of two scale the answers exactly.
#[test]
fn scale_invariance() {
    let prior = Prior::squared_exponential(4.0).unwrap();
    let y = [1.3f32, 0.4, 0.9, 0.7, 2.1, 0.2];
    let mut a =
        LayoutProbe::<6>::new(&cube(), prior, Noise { absolute: 0.0, relative: 0.05 }).unwrap();
    let mut b = a.clone();
    a.update(&y).unwrap();
    b.update(&y.map(|v| v * 1024.0)).unwrap();
    let (ea, eb) = (a.irradiance(Vec3::Z).unwrap(), b.irradiance(Vec3::Z).unwrap());
    assert_eq!(ea.value * 1024.0, eb.value);
    assert_eq!(ea.variance * 1024.0 * 1024.0, eb.variance);
}

/// Eight cosine sensors on a ring at 20° elevation, 45° apart, no zenith sensor.
fn ring8() -> [Sensor; 8] {
    let e = 20f32.to_radians();
    core::array::from_fn(|k| {
        let a = (45 * k) as f32 * core::f32::consts::PI / 180.0;
        let c = math::cos(e);
        Sensor::cosine(Vec3::new(c * math::cos(a), c * math::sin(a), math::sin(e)))
    })
}

#[test]
fn the_recommended_prior_follows_what_the_layout_sees() {
    let h = 1.0 / 3f32.sqrt();
    let tetrahedron =
        [Vec3::new(h, h, h), Vec3::new(h, -h, -h), Vec3::new(-h, h, -h), Vec3::new(-h, -h, h)]
            .map(Sensor::cosine);
    let corners: [Sensor; 8] = core::array::from_fn(|k| {
        let s = |b: usize| if k >> b & 1 == 1 { -1.0 } else { 1.0 };
        Sensor::cosine(Vec3::new(s(0), s(1), s(2)))
    });
    for all_round in [&cube()[..], &tetrahedron, &corners] {
        assert_eq!(Prior::for_layout(all_round), Prior::ENVIRONMENT);
        assert_eq!(Prior::smooth_for_layout(all_round), Prior::SMOOTH_ENVIRONMENT);
    }
    // On a table (no −z face), a dome, a ring, a wall (+x), a great circle, one sensor, an
    // antipodal pair: a closed hemisphere holds them.
    let table = &cube()[..5];
    let wall: [Sensor; 3] =
        [Vec3::X, Vec3::new(0.5, 0.8, 0.0), Vec3::new(0.5, -0.3, -0.8)].map(Sensor::cosine);
    let circle = [Vec3::X, Vec3::Y, -Vec3::X, -Vec3::Y].map(Sensor::cosine);
    let pair = [Vec3::Z, -Vec3::Z].map(Sensor::cosine);
    for one_sided in [table, &dome(), &ring8(), &wall, &circle, &pair, &[Sensor::cosine(Vec3::Z)]] {
        assert_eq!(Prior::for_layout(one_sided), Prior::ONE_SIDED);
        assert_eq!(Prior::smooth_for_layout(one_sided), Prior::SMOOTH_ONE_SIDED);
    }
    // The table at a random rotation (directions rounded off its boundary): still one-sided;
    // one sensor 1° below that boundary makes it all round.
    let r = crate::Mat3::from_axis_angle(Vec3::new(0.3, -0.5, 0.8), 0.7);
    let turned: [Sensor; 5] = core::array::from_fn(|i| Sensor::cosine(r * table[i].direction));
    assert_eq!(Prior::for_layout(&turned), Prior::ONE_SIDED);
    let one = 1f32.to_radians();
    let mut below = cube();
    below[5] = Sensor::cosine(Vec3::new(math::cos(one), 0.0, -math::sin(one)));
    assert_eq!(Prior::for_layout(&below), Prior::ENVIRONMENT);
    // A zero or non-finite direction is skipped (`new` refuses it).
    let mut bad = cube();
    bad[1] = Sensor::cosine(Vec3::ZERO);
    bad[2] = Sensor::cosine(Vec3::new(f32::NAN, 0.0, 1.0));
    assert_eq!(Prior::for_layout(&bad), Prior::ONE_SIDED);
    assert_eq!(Prior::for_layout(&[]), Prior::ONE_SIDED);
    // At compile time.
    const OCTANT: Prior = Prior::for_layout(&[
        Sensor::cosine(Vec3::X),
        Sensor::cosine(Vec3::Y),
        Sensor::cosine(Vec3::Z),
    ]);
    assert_eq!(OCTANT, Prior::ONE_SIDED);
    // Only directions matter: lengths from 1e-30 to 1e30 (no overflow in the products).
    for scale in [1e-30, 1e-3, 1e30] {
        let big = cube().map(|c| Sensor::cosine(c.direction * scale));
        assert_eq!(Prior::for_layout(&big), Prior::ENVIRONMENT, "{scale}");
        let table: [Sensor; 5] = core::array::from_fn(|i| big[i]);
        assert_eq!(Prior::for_layout(&table), Prior::ONE_SIDED, "{scale}");
    }
}

/// A constant sky of 1 read by a ring at 20° elevation: the ring cannot tell the level from
/// the vertical gradient, and the recommended prior answers as the minimum-norm degree-2 SH
/// fit does (`E(+z) = 3.579`, `E(+x) = 2.777`, computed here in f64), not as
/// `Prior::SKY_ABOVE` (`E(+z) = 5.11`, `E(+x) = 2.35`): the tolerance is the SH fit's own
/// error on this sky, 0.437 at +z and 0.365 at +x, plus 1 %.
#[test]
fn a_ring_without_a_zenith_sensor_sees_a_constant_sky_as_the_sh_fit_does() {
    // The SH fit: the ring's 8 equal readings see the zonal coefficients through
    // u = (g_l·Y_l0(sin 20°)), and the minimum-norm solution is c = u/|u|².
    let z = 20f64.to_radians().sin();
    let y0 = 0.5 / core::f64::consts::PI.sqrt();
    let y1 = (3.0 / (4.0 * core::f64::consts::PI)).sqrt();
    let y2 = (5.0 / (16.0 * core::f64::consts::PI)).sqrt();
    let u = [y0, 2.0 / 3.0 * y1 * z, 0.25 * y2 * (3.0 * z * z - 1.0)];
    let norm = u.iter().map(|v| v * v).sum::<f64>();
    let pi = core::f64::consts::PI;
    // E(n) = Σ_l c_l·A_l·Y_l0(n_z), A = (π, 2π/3, π/4).
    let e = |nz: f64| {
        let y = [y0, y1 * nz, y2 * (3.0 * nz * nz - 1.0)];
        let a = [pi, 2.0 * pi / 3.0, pi / 4.0];
        (0..3).map(|l| u[l] / norm * a[l] * y[l]).sum::<f64>()
    };
    let (sh_up, sh_side) = (e(1.0), e(0.0));
    assert!((sh_up - 3.579).abs() < 1e-3 && (sh_side - 2.777).abs() < 1e-3, "{sh_up} {sh_side}");
    let sensors = ring8();
    let prior = Prior::for_layout(&sensors);
    assert_eq!(prior, Prior::ONE_SIDED);
    let answers = |prior: Prior| {
        let mut probe = LayoutProbe::<8>::new(&sensors, prior, Noise::NONE).expect("ring");
        probe.update(&[1.0; 8]).expect("readings");
        let up = probe.irradiance(Vec3::Z).expect("up").value as f64;
        let side = probe.irradiance(Vec3::X).expect("side").value as f64;
        (up, side)
    };
    let tolerance = |sh: f64| (sh - pi).abs() + 0.01 * pi;
    for prior in [Prior::for_layout(&sensors), Prior::smooth_for_layout(&sensors)] {
        let (up, side) = answers(prior);
        assert!((up - pi).abs() <= tolerance(sh_up), "E(+z) = {up}");
        assert!((side - pi).abs() <= tolerance(sh_side), "E(+x) = {side}");
    }
    // The sky-above prior on the same readings: far outside.
    let (up, side) = answers(Prior::SKY_ABOVE);
    assert!((up - pi).abs() > 3.0 * tolerance(sh_up), "E(+z) = {up}");
    assert!((side - pi).abs() > tolerance(sh_side), "E(+x) = {side}");
}

/// A relative noise far below the readings' rounding gives the probe without noise: both
/// paths fit the same model, the covariance with its eigenvalues floored. Measured 5.2·10⁻⁵
/// of the largest value; 1.4·10⁻³ when the exact system of the relative noise added the
/// floor to every eigenvalue instead.
#[test]
fn a_vanishing_relative_noise_fits_the_model_without_noise() {
    // A sky with a sun: 1 + 0.5·z + 40·e^(200(x·μ − 1)), read by cosine sensors (their
    // response cos⁺/π) by a midpoint rule on 200 000 Fibonacci points (f64).
    let mu = [0.48f64, -0.36, 0.8];
    let light = |x: [f64; 3]| {
        let t = x[0] * mu[0] + x[1] * mu[1] + x[2] * mu[2];
        1.0 + 0.5 * x[2] + 40.0 * (200.0 * (t - 1.0)).exp()
    };
    let m = 200_000usize;
    let golden = (1.0 + 5f64.sqrt()) / 2.0;
    let grid: Vec<[f64; 3]> = (0..m)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as f64 / m as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = 2.0 * core::f64::consts::PI * (i as f64 / golden).fract();
            [r * phi.cos(), r * phi.sin(), z]
        })
        .collect();
    let values: Vec<f64> = grid.iter().map(|&x| light(x)).collect();
    let dirs = crate::SphericalFibonacci::<64>::new().points();
    let sensors = dirs.map(Sensor::cosine);
    let readings: [f32; 64] = core::array::from_fn(|i| {
        let d = to64(dirs[i]);
        let sum: f64 = grid
            .iter()
            .zip(&values)
            .map(|(x, v)| v * (x[0] * d[0] + x[1] * d[1] + x[2] * d[2]).max(0.0))
            .sum();
        (sum * 4.0 * core::f64::consts::PI / m as f64 / core::f64::consts::PI) as f32
    });
    let prior = Prior::for_layout(&sensors);
    let fit = |noise: Noise| {
        let mut p = LayoutProbe::<64>::new(&sensors, prior, noise).unwrap();
        p.update(&readings).unwrap();
        p
    };
    let (plain, noisy) = (fit(Noise::NONE), fit(Noise { absolute: 0.0, relative: 1e-9 }));
    let normals = crate::SphericalFibonacci::<20>::new().points();
    let mut largest = 0.0f32;
    let mut worst = 0.0f32;
    for n in normals {
        let (a, b) = (plain.irradiance(n).unwrap().value, noisy.irradiance(n).unwrap().value);
        largest = largest.max(a.abs());
        worst = worst.max((a - b).abs());
    }
    assert!(worst <= 1e-4 * largest, "moved {:e} of the largest", worst / largest);
}
