//! The temporal probe's contracts: pooling, resets, flicker and footprints.

use super::*;

#[test]
fn the_truncation_table_is_its_f64_value_rounded_once() {
    // A_l in f64: π, 2π/3, then 2π·(−1)^(l/2+1)/((l + 2)(l − 1))·l!/(2^l·((l/2)!)²) for even l.
    let gain = |l: usize| -> f64 {
        let pi = core::f64::consts::PI;
        match l {
            0 => pi,
            1 => 2.0 * pi / 3.0,
            _ if l % 2 == 1 => 0.0,
            _ => {
                let mut f = 1.0;
                for j in 1..=l / 2 {
                    f *= (l / 2 + j) as f64 / (4 * j) as f64;
                }
                let sign = if (l / 2) % 2 == 0 { -1.0 } else { 1.0 };
                2.0 * pi * sign / ((l + 2) as f64 * (l as f64 - 1.0)) * f
            }
        }
    };
    for (l, &a) in IRRADIANCE_GAIN.iter().enumerate() {
        assert!((f64::from(a) - gain(l)).abs() < 1e-7, "A_{l}");
    }
    // ∫ max(0, cos θ)² dω = 2π/3 = Σ_l A_l²·(2l + 1)/(4π) (Parseval).
    let mut tail = 2.0 * core::f64::consts::PI / 3.0;
    for (l, &t) in TRUNCATION.iter().enumerate() {
        tail -= gain(l) * gain(l) * (2 * l + 1) as f64 / (4.0 * core::f64::consts::PI);
        assert_eq!(t, tail as f32, "L = {l}");
    }
    // And the tail summed directly (to degree 2000, where it is below 10⁻¹⁰ of T₈).
    let direct: f64 = (9..=2000)
        .map(|l| {
            // (Stirling-free: the ratio A_{l+2}/A_l from the closed form, in logs.)
            let mut log = 0.0f64;
            for j in 1..=l / 2 {
                log += ((l / 2 + j) as f64 / (4 * j) as f64).ln();
            }
            let a = if l % 2 == 1 {
                0.0
            } else {
                2.0 * core::f64::consts::PI / ((l + 2) as f64 * (l as f64 - 1.0)) * log.exp()
            };
            a * a * (2 * l + 1) as f64 / (4.0 * core::f64::consts::PI)
        })
        .sum();
    assert!((direct / f64::from(TRUNCATION[8]) - 1.0).abs() < 1e-6, "{direct}");
}

/// The textbook real harmonic in f64: the associated Legendre function by the classical
/// recurrence in `l` from `P_m^m = (2m − 1)!!·sinᵐθ`, normalised by factorials, and the
/// azimuth through `atan2` (no Condon–Shortley phase).
fn textbook(l: usize, m: i64, v: [f64; 3]) -> f64 {
    let am = m.unsigned_abs() as usize;
    let (z, sin) = (v[2], v[0].hypot(v[1]));
    let mut pmm = 1.0;
    for i in 1..=am {
        pmm *= (2 * i - 1) as f64 * sin;
    }
    let (mut prev, mut p) = (0.0, pmm);
    for ll in am + 1..=l {
        let next = ((2 * ll - 1) as f64 * z * p - (ll + am - 1) as f64 * prev) / (ll - am) as f64;
        (prev, p) = (p, next);
    }
    let mut ratio = 1.0;
    for j in (l - am + 1)..=(l + am) {
        ratio /= j as f64;
    }
    let n = ((2 * l + 1) as f64 / (4.0 * core::f64::consts::PI) * ratio).sqrt();
    let phi = v[1].atan2(v[0]);
    match m {
        0 => n * p,
        m if m > 0 => 2f64.sqrt() * n * p * (m as f64 * phi).cos(),
        m => 2f64.sqrt() * n * p * ((-m) as f64 * phi).sin(),
    }
}

#[test]
fn the_basis_is_the_textbook_real_harmonics() {
    // Every degree ≤ 8, at scattered directions including the poles (the reference
    // crate's `real_sh` is the same definition; the packaged crate's tests cannot use it).
    let dirs = [
        Vec3::new(0.3, -0.5, 0.812),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(-0.7, 0.1, -0.2),
        Vec3::new(1.0, 0.0, 0.0),
    ];
    for d in dirs {
        let u = d.try_normalize().unwrap();
        let mut y = [0.0f32; COEFFICIENTS];
        basis(MAX_DEGREE, u, &mut y);
        let v = [f64::from(u.x), f64::from(u.y), f64::from(u.z)];
        for l in 0..=MAX_DEGREE {
            for m in -(l as i64)..=(l as i64) {
                let want = textbook(l, m, v);
                let got = f64::from(y[((l * (l + 1)) as i64 + m) as usize]);
                assert!((got - want).abs() < 2e-6, "l = {l}, m = {m}, {d:?}: {got} vs {want}");
            }
        }
    }
}

#[test]
fn the_state_size_is_pinned() {
    // The sums, their compensation and the queries' coefficients: three sets of 81 per
    // channel, beside the directions.
    use crate::footprint::Point;
    assert_eq!(core::mem::size_of::<TemporalProbe<64, [f32; 3], Point, 4>>(), 4696);
    assert_eq!(core::mem::size_of::<TemporalProbe<64>>(), 2256);
}

/// The projection of `f` at the probe's directions in f64 from the textbook harmonics.
fn projection_f64<const N: usize>(
    probe: &TemporalProbe<N>,
    f: impl Fn(Vec3) -> f32,
) -> [f64; COEFFICIENTS] {
    let d = probe.directions();
    let ys = d.map(|x| f64::from(f(x)));
    let mean = ys.iter().sum::<f64>() / N as f64;
    let mut p = [0.0; COEFFICIENTS];
    p[0] = mean * (4.0 * core::f64::consts::PI).sqrt();
    for l in 1..=probe.degree() {
        for m in -(l as i64)..=l as i64 {
            let v = d.iter().zip(&ys).map(|(x, &y)| {
                let v = [f64::from(x.x), f64::from(x.y), f64::from(x.z)];
                (y - mean) * textbook(l, m, v)
            });
            let i = ((l * (l + 1)) as i64 + m) as usize;
            p[i] = v.sum::<f64>() * 4.0 * core::f64::consts::PI / N as f64;
        }
    }
    p
}

#[test]
fn the_projection_is_the_textbook_sum_in_chunks_and_at_every_size() {
    fn check<const N: usize>() {
        let f = |x: Vec3| 1.0 + x.x - 0.5 * x.y * x.z + 2.0 * x.z * x.z * x.x + x.y.powi(5);
        for seed in 0..4 {
            let probe = TemporalProbe::<N>::new(seed);
            let want = projection_f64(&probe, f);
            let got = probe.project(&probe.directions().map(f));
            for (i, (&g, &w)) in got.iter().zip(&want).enumerate() {
                let g = f64::from(g);
                assert!((g - w).abs() < 2e-5 * (1.0 + w.abs()), "N = {N}, {i}: {g} vs {w}");
            }
        }
    }
    check::<1>();
    check::<15>();
    check::<16>();
    check::<40>();
    check::<252>();
}
