//! The temporal probe (`sphere_quadrature::temporal`): accumulation, change detection and bad
//! input.

use sphere_quadrature::temporal::{Change, TemporalProbe};
use sphere_quadrature::{Error, Vec3};
use std::f32::consts::PI;

/// A smooth sky with a bright lobe: not in the kernel's span exactly, so every rotation's
/// samples alias a little and successive updates differ.
fn sky(d: Vec3) -> f32 {
    let lobe = Vec3::new(0.6, 0.0, 0.8);
    1.0 + 0.5 * d.z + 4.0 * (12.0 * (d.dot(lobe) - 1.0)).exp()
}

#[test]
fn before_any_update_everything_is_zero() {
    let probe = TemporalProbe::<16>::new(1);
    let e = probe.irradiance(Vec3::Z).unwrap();
    assert_eq!((e.value, e.variance), (0.0, 0.0));
    assert_eq!(probe.updates(), 0);
}

#[test]
fn a_constant_is_exact_and_a_new_constant_resets() {
    let mut probe = TemporalProbe::<64, [f32; 3]>::new(2);
    for k in 0..5 {
        let change = probe.update(&[[2.0, 1.0, 0.5]; 64]).unwrap();
        assert_eq!(change, if k == 0 { Change::First } else { Change::Blended });
    }
    assert_eq!(probe.updates(), 5);
    let e = probe.irradiance(Vec3::new(0.3, -0.2, 0.9)).unwrap();
    for (c, want) in [2.0f32, 1.0, 0.5].into_iter().enumerate() {
        assert!((e.value[c] - PI * want).abs() <= 2e-5 * PI * want, "{:?}", e.value);
        assert_eq!(e.variance[c], 0.0);
    }
    // Any change of a constant is infinitely unlikely under zero scatter.
    assert_eq!(probe.update(&[[2.0, 1.0, 0.6]; 64]).unwrap(), Change::Reset);
    assert_eq!(probe.updates(), 1);
    assert!((probe.irradiance(Vec3::Z).unwrap().value[2] - PI * 0.6).abs() < 2e-5);
}

#[test]
fn every_update_rotates_the_set_and_the_rotations_follow_the_seed() {
    let mut a = TemporalProbe::<32>::new(7);
    let b = TemporalProbe::<32>::new(7);
    let c = TemporalProbe::<32>::new(8);
    assert_eq!(a.directions(), b.directions());
    assert_ne!(a.directions(), c.directions());
    let first = *a.directions();
    let samples = first.map(sky);
    a.update(&samples).unwrap();
    assert_ne!(a.directions(), &first);
}

#[test]
fn static_light_averages_down() {
    // The accumulated estimate after 16 updates is closer to the truth than one update, on
    // average over normals, and its variance falls with the number of updates.
    let normals: Vec<Vec3> = (0..64)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as f32 / 64.0;
            let phi = i as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect();
    // Truth by a fine quadrature of the same sky (Fibonacci points, 2¹⁶).
    let fine = sphere_quadrature::FibonacciPoints::sphere(1 << 16).unwrap();
    let truth: Vec<f64> = normals
        .iter()
        .map(|n| {
            fine.iter().map(|x| f64::from(sky(x)) * f64::from(x.dot(*n).max(0.0))).sum::<f64>()
                * 4.0
                * std::f64::consts::PI
                / f64::from(1u32 << 16)
        })
        .collect();
    let rms = |p: &TemporalProbe<16>| {
        let se: f64 = normals
            .iter()
            .zip(&truth)
            .map(|(&n, t)| (f64::from(p.irradiance(n).unwrap().value) - t).powi(2))
            .sum();
        (se / normals.len() as f64).sqrt()
    };
    let (mut one, mut sixteen) = (0.0, 0.0);
    let mut resets = 0;
    for seed in 0..8 {
        let mut p = TemporalProbe::<16>::new(seed);
        let mut variances = Vec::new();
        for k in 0..16 {
            let samples = p.directions().map(sky);
            if p.update(&samples).unwrap() == Change::Reset {
                resets += 1;
            }
            if k == 0 {
                one += rms(&p);
            }
            variances.push(p.irradiance(Vec3::Z).unwrap().variance);
        }
        sixteen += rms(&p);
        if p.updates() == 16 {
            assert!(variances[15] < 0.25 * variances[1], "{variances:?}");
        }
    }
    println!(
        "RMS after one update {:.4}, after 16 {:.4}; {resets} resets",
        one / 8.0,
        sixteen / 8.0
    );
    assert!(resets <= 1, "{resets} resets on static light");
    assert!(sixteen < 0.6 * one, "16 updates {sixteen} vs one {one}");
}

#[test]
fn bad_input_is_refused_and_keeps_the_state() {
    let mut probe = TemporalProbe::<16>::new(3);
    let samples = probe.directions().map(sky);
    probe.update(&samples).unwrap();
    let dirs = *probe.directions();
    let before = probe.irradiance(Vec3::Z).unwrap();
    let mut bad = dirs.map(sky);
    bad[3] = f32::NAN;
    assert_eq!(probe.update(&bad), Err(Error::InvalidRadiance));
    assert_eq!(probe.directions(), &dirs);
    assert_eq!(probe.irradiance(Vec3::Z).unwrap(), before);
    assert_eq!(probe.updates(), 1);
    assert_eq!(probe.irradiance(Vec3::ZERO).map(|e| e.value), Err(Error::InvalidDirection));
    for t in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert!(TemporalProbe::<16>::new(1).with_threshold(t).is_err(), "{t}");
    }
    assert!(TemporalProbe::<16>::new(1).with_threshold(5.0).is_ok());
}
