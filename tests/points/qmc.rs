//! QMC estimators against closed forms and 1-D f64 quadratures from the reference crate.

use reference::analytic::{sg_queries, Constant, Linear, SgLight, SgQuery};
use reference::fit::loglog_slope;
use reference::rng::Rng;
use sphere_quadrature::qmc::{self, LobeSampler};
use sphere_quadrature::{Error, Lobe, RotationSequence, Vec3};

const PI: f32 = core::f32::consts::PI;

/// How far from unit length a direction may be: a few f32 roundings.
const UNIT_TOL: f32 = 1e-5;

fn v32(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
}

fn v64(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

#[test]
fn constant_radiance_is_exact_to_f32_precision() {
    let mut rng = Rng::new(1);
    let mut seq = RotationSequence::new(1);
    for _ in 0..50 {
        let n = v32(rng.uniform_sphere());
        let phase = seq.next_phase();
        for (e, got) in [
            (PI, qmc::irradiance::<1, f32, _>(n, phase, |_| 1.0).unwrap()),
            (PI, qmc::irradiance::<64, f32, _>(n, phase, |_| 1.0).unwrap()),
            (PI, qmc::irradiance::<4096, f32, _>(n, phase, |_| 1.0).unwrap()),
            (1.0, qmc::phong::<256, f32, _>(n, 37.0, phase, |_| 1.0).unwrap()),
        ] {
            // N ones sum exactly; the weight π/N costs one or two roundings.
            assert!(((got - e) / e).abs() <= 2.0 * f32::EPSILON, "{got} vs {e}");
        }
    }
}

#[test]
fn linear_radiance_matches_closed_form() {
    let mut rng = Rng::new(2);
    for _ in 0..50 {
        let n = rng.uniform_sphere();
        let b = rng.uniform_sphere();
        let lin = Linear { a: 1.0, b: [0.7 * b[0], 0.7 * b[1], 0.7 * b[2]] };
        let f = |d: Vec3| lin.value(v64(d)) as f32;
        let got = qmc::irradiance::<256, f32, _>(v32(n), rng.next_u64(), f).unwrap() as f64;
        let exact = lin.irradiance(n);
        assert!(((got - exact) / exact).abs() < 2e-3, "{got} vs {exact}");
        let got = qmc::phong::<256, f32, _>(v32(n), 20.0, rng.next_u64(), f).unwrap() as f64;
        let exact = lin.phong(n, 20.0);
        assert!(((got - exact) / exact).abs() < 2e-3, "{got} vs {exact}");
    }
    // The constant part alone is exact.
    let c = Constant { c: 2.5 };
    let got = qmc::irradiance::<100, f32, _>(Vec3::X, 0, |d| c.value(v64(d)) as f32).unwrap();
    assert!(
        ((got as f64 - c.irradiance([1.0, 0.0, 0.0])) / (2.5 * std::f64::consts::PI)).abs() < 3e-7
    );
}

fn dispatch_sf(n: usize, c: &SgQuery) -> f64 {
    let s = LobeSampler::new(v32(c.normal), Lobe::Cosine, n, c.phase).unwrap();
    s.integrate(|d| c.light.value(v64(d)) as f32).unwrap() as f64
}

#[test]
fn sf_converges_at_least_as_n_to_the_minus_three_quarters_and_random_as_minus_half() {
    let ns = [64usize, 128, 256, 512, 1024, 2048, 4096];
    let cs = sg_queries(64, 10);
    let sf_rms: Vec<f64> = ns
        .iter()
        .map(|&n| {
            let se: f64 =
                cs.iter().map(|c| ((dispatch_sf(n, c) - c.truth) / c.truth).powi(2)).sum();
            (se / cs.len() as f64).sqrt()
        })
        .collect();

    // Random (Monte Carlo) cosine-distributed directions, independent per configuration.
    let mc_cs = sg_queries(256, 20);
    let mut rng = Rng::new(99);
    let mc_rms: Vec<f64> = ns
        .iter()
        .map(|&n| {
            let se: f64 = mc_cs
                .iter()
                .map(|c| {
                    let (t, b) = reference::vec::frame(c.normal);
                    let mut sum = 0.0;
                    for _ in 0..n {
                        let l = rng.cosine_hemisphere();
                        let d = [
                            l[0] * t[0] + l[1] * b[0] + l[2] * c.normal[0],
                            l[0] * t[1] + l[1] * b[1] + l[2] * c.normal[1],
                            l[0] * t[2] + l[1] * b[2] + l[2] * c.normal[2],
                        ];
                        sum += c.light.value(d);
                    }
                    let est = std::f64::consts::PI * sum / n as f64;
                    ((est - c.truth) / c.truth).powi(2)
                })
                .sum();
            (se / mc_cs.len() as f64).sqrt()
        })
        .collect();

    let nsf: Vec<f64> = ns.iter().map(|&n| n as f64).collect();
    let sf_slope = loglog_slope(&nsf, &sf_rms);
    let mc_slope = loglog_slope(&nsf, &mc_rms);
    println!("N      SF rel RMS   random rel RMS");
    for ((n, s), m) in ns.iter().zip(&sf_rms).zip(&mc_rms) {
        println!("{n:<6} {s:.3e}    {m:.3e}");
    }
    println!("fitted slopes: SF {sf_slope:.3}, random {mc_slope:.3}");
    assert!((-0.6..=-0.4).contains(&mc_slope), "random slope {mc_slope}");
    assert!(sf_slope <= -0.75, "SF slope {sf_slope}");
    // SF beats random at every N.
    assert!(sf_rms.iter().zip(&mc_rms).all(|(s, m)| s < m));
}

#[test]
fn phong_of_sg_light_matches_reference_quadrature() {
    let mut rng = Rng::new(4);
    for e in [1.0f32, 10.0, 100.0, 1000.0] {
        let mut worst = 0.0f64;
        for _ in 0..30 {
            let r = rng.uniform_sphere();
            let axis = rng.uniform_sphere();
            let light = SgLight { axis, sharpness: 4.0, amplitude: 1.0 };
            let got = qmc::phong::<1024, f32, _>(v32(r), e, rng.next_u64(), |d| {
                light.value(v64(d)) as f32
            })
            .unwrap() as f64;
            let exact = light.phong(r, e as f64);
            // Relative to the light's peak value (1): some lobes see almost no light.
            worst = worst.max((got - exact).abs());
        }
        println!("Phong e = {e}: max abs error {worst:.2e} (N = 1024, SG λ = 4)");
        assert!(worst < 2e-3, "e = {e}: {worst}");
    }
}

#[test]
fn directions_lie_on_the_lobe() {
    let mut rng = Rng::new(8);
    for lobe in [Lobe::Uniform, Lobe::Cosine, Lobe::Phong(0.0), Lobe::Phong(30.0), Lobe::Phong(1e6)]
    {
        let axis = v32(rng.uniform_sphere());
        let s = LobeSampler::new(axis, lobe, 4096, rng.next_u64()).unwrap();
        let e = lobe.exponent() as f64;
        let mut mean_cos = 0.0;
        for d in s.iter() {
            assert!((d.length() - 1.0).abs() < UNIT_TOL, "{d:?}");
            let c = d.dot(s.frame().n) as f64;
            assert!(c >= -1e-6, "{lobe:?}: {c}");
            mean_cos += c;
        }
        mean_cos /= 4096.0;
        // Under the density (e+1)/(2π)·cosᵉ θ, E[cos θ] = (e+1)/(e+2).
        let expected = (e + 1.0) / (e + 2.0);
        assert!((mean_cos - expected).abs() < 1e-4, "{lobe:?}: {mean_cos} vs {expected}");
    }
}

#[test]
fn slice_form_equals_callback_form_and_rgb_equals_scalar() {
    let light = |d: Vec3| 1.0 + d.x * d.x + 0.3 * d.z;
    let n = Vec3::new(0.2, -0.5, 0.8);
    let s = LobeSampler::new(n, Lobe::Cosine, 128, 12345).unwrap();
    let mut dirs = [Vec3::ZERO; 128];
    s.fill(&mut dirs).unwrap();
    let ys: Vec<f32> = dirs.iter().map(|&d| light(d)).collect();
    let slice = s.estimate(&ys).unwrap();
    let cb = qmc::irradiance::<128, f32, _>(n, 12345, light).unwrap();
    assert_eq!(slice, cb);
    let rgb = qmc::irradiance::<128, [f32; 3], _>(n, 12345, |d| {
        let y = light(d);
        [y, 2.0 * y, 0.0]
    })
    .unwrap();
    assert_eq!(rgb[0], cb);
    assert_eq!(rgb[1], 2.0 * cb);
    assert_eq!(rgb[2], 0.0);
    assert_eq!(s.estimate(&ys[..127]), Err(Error::LengthMismatch));
    assert_eq!(s.fill(&mut dirs[..3]), Err(Error::LengthMismatch));
    assert_eq!(s.direction(128), None);
}

#[test]
fn bad_input_gives_documented_results() {
    let one = |_: Vec3| 1.0f32;
    for bad in [Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0), Vec3::new(f32::INFINITY, 0.0, 0.0)] {
        assert_eq!(qmc::irradiance::<16, f32, _>(bad, 0, one), Err(Error::InvalidDirection));
        assert_eq!(qmc::phong::<16, f32, _>(bad, 10.0, 0, one), Err(Error::InvalidDirection));
    }
    for bad in [-1.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        assert_eq!(qmc::phong::<16, f32, _>(Vec3::Z, bad, 0, one), Err(Error::InvalidExponent));
        assert_eq!(Lobe::phong(bad), Err(Error::InvalidExponent));
        assert_eq!(LobeSampler::new(Vec3::Z, Lobe::Phong(bad), 16, 0), Err(Error::InvalidExponent));
    }
    assert_eq!(LobeSampler::new(Vec3::Z, Lobe::Cosine, 0, 0), Err(Error::InvalidSize));
    // Non-unit normals are normalised.
    let a = qmc::irradiance::<32, f32, _>(Vec3::new(0.0, 0.0, 5.0), 7, |d| d.z).unwrap();
    let b = qmc::irradiance::<32, f32, _>(Vec3::Z, 7, |d| d.z).unwrap();
    assert_eq!(a, b);
    // A NaN or infinite radiance value is refused, in any channel and either form.
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let radiance = |d: Vec3| if d.z > 0.5 { [1.0, bad] } else { [1.0, 1.0] };
        assert_eq!(
            qmc::irradiance::<16, [f32; 2], _>(Vec3::Z, 0, radiance),
            Err(Error::InvalidRadiance)
        );
        assert_eq!(
            qmc::phong::<16, [f32; 2], _>(Vec3::Z, 10.0, 0, radiance),
            Err(Error::InvalidRadiance)
        );
        let s = LobeSampler::new(Vec3::Z, Lobe::Cosine, 16, 0).unwrap();
        let mut dirs = [Vec3::ZERO; 16];
        s.fill(&mut dirs).unwrap();
        assert_eq!(s.estimate(&dirs.map(radiance)), Err(Error::InvalidRadiance));
    }
    // Huge but finite exponents are fine: all directions hug the axis.
    let g = qmc::phong::<64, f32, _>(Vec3::X, 1e9, 0, |d| d.x).unwrap();
    assert!((g - 1.0).abs() < 1e-6, "{g}");
}
