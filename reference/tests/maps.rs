//! Ground truth over environment maps: constant, linear and cap-shaped synthetic maps
//! with known integrals, and self-consistency of the adaptive rules.

use reference::analytic::{Cap, Linear};
use reference::truth::{irradiance, phong, phong_with_subgrid};
use reference::vec::{dot, normalize};
use reference::{EnvMap, Rng};
use std::f64::consts::PI;
use std::time::Instant;

const W: usize = 512;
const H: usize = 256;

fn test_dirs(seed: u64, n: usize) -> Vec<[f64; 3]> {
    let mut r = Rng::new(seed);
    let mut v = vec![
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        normalize([1.0, 1.0, 1e-9]),
        normalize([0.3, -0.2, 0.9]),
    ];
    v.extend((0..n).map(|_| r.uniform_sphere()));
    v
}

/// A map whose radiance function is exactly 1 on the union of the rows v < `rows` (the
/// polar cap θ ≤ π·rows/H about +z), 0 elsewhere.
fn cap_map(rows: usize) -> (EnvMap, Cap) {
    let mut px = vec![[0.0f32; 3]; W * H];
    for p in px.iter_mut().take(rows * W) {
        *p = [1.0, 2.0, 0.5];
    }
    let cap = Cap { axis: [0.0, 0.0, 1.0], cos_alpha: (PI * (rows as f64 / H as f64)).cos() };
    (EnvMap::new(W, H, px), cap)
}

#[test]
fn irradiance_of_constant_map_is_pi_c() {
    let c = [1.0f32, 0.25, 3.0];
    let map = EnvMap::constant(W, H, c);
    let mut worst = 0.0f64;
    let t = Instant::now();
    let dirs = test_dirs(1, 30);
    for n in &dirs {
        let e = irradiance(&map, *n);
        for k in 0..3 {
            worst = worst.max((e[k] / (PI * c[k] as f64) - 1.0).abs());
        }
    }
    let ms = t.elapsed().as_secs_f64() * 1e3 / dirs.len() as f64;
    eprintln!("constant map irradiance: max rel err {worst:.2e}, {ms:.1} ms per normal");
    assert!(worst < 1e-12);
}

#[test]
fn irradiance_of_polar_cap_map_matches_cap_closed_form() {
    // The union of the first rows is exactly a cap, so the map's irradiance must equal
    // Cap::irradiance to rounding: this checks the straddling-pixel integration against
    // the closed form, for caps above, across and below the horizon.
    let mut worst = 0.0f64;
    for rows in [1usize, 5, 64, 128, 200, 255] {
        let (map, cap) = cap_map(rows);
        for n in test_dirs(rows as u64, 12) {
            let want = cap.irradiance(n);
            let got = irradiance(&map, n);
            for (k, s) in [1.0, 2.0, 0.5].iter().enumerate() {
                worst = worst.max((got[k] - s * want).abs() / s);
            }
        }
    }
    eprintln!("polar-cap map irradiance vs Cap closed form: max abs err {worst:.2e} (E ≤ π)");
    assert!(worst < 1e-13);
}

#[test]
fn phong_of_polar_cap_map_matches_cap_quadrature() {
    let mut worst = 0.0f64;
    for (rows, e) in [(5usize, 1.0), (40, 10.0), (128, 3.5), (100, 200.0), (20, 1000.0)] {
        let (map, cap) = cap_map(rows);
        let alpha = PI * rows as f64 / H as f64;
        // Lobes centred on the pole, on the cap boundary and elsewhere.
        let mut dirs = test_dirs(7 + rows as u64, 2);
        for d in [alpha - 0.01, alpha, alpha + 0.003] {
            dirs.push([d.sin() * 0.6, d.sin() * 0.8, d.cos()]);
        }
        for r in dirs {
            let want = cap.phong(r, e);
            let got = phong(&map, r, e)[0];
            worst = worst.max((got - want).abs());
        }
    }
    eprintln!("polar-cap map Phong vs Cap::phong: max abs err {worst:.2e}");
    assert!(worst < 1e-11);
}

#[test]
fn irradiance_of_linear_map_is_close_to_linear_closed_form() {
    // Pixels hold a + b·(pixel-centre direction): a piecewise-constant approximation of
    // the linear function, so only O(pixel²) agreement is expected.
    let lin = Linear { a: 1.0, b: [0.3, -0.5, 0.7] };
    let map = EnvMap::from_fn(W, H, |d| {
        let v = lin.value(d);
        [v, v, v]
    });
    let mut worst = 0.0f64;
    for n in test_dirs(3, 6) {
        let want = lin.irradiance(n);
        let got = irradiance(&map, n)[0];
        worst = worst.max((got / want - 1.0).abs());
        // Phong lobes as well.
        for e in [1.0, 30.0] {
            let want = lin.phong(n, e);
            let got = phong(&map, n, e)[0];
            worst = worst.max((got / want - 1.0).abs());
        }
    }
    eprintln!("linear map vs Linear closed forms: max rel err {worst:.2e}");
    assert!(worst < 2e-4);
}

#[test]
fn phong_of_constant_map_is_c() {
    let map = EnvMap::constant(W, H, [2.0, 1.0, 0.5]);
    let mut worst = 0.0f64;
    let t = Instant::now();
    let mut calls = 0;
    for e in [0.0, 1.0, 2.5, 10.0, 100.0, 1000.0, 1e5] {
        for r in test_dirs(e as u64 + 11, 3) {
            let got = phong(&map, r, e);
            calls += 1;
            worst = worst.max((got[1] - 1.0).abs());
            assert!((got[0] / got[1] - 2.0).abs() < 1e-15);
        }
    }
    let ms = t.elapsed().as_secs_f64() * 1e3 / calls as f64;
    eprintln!("constant map Phong (e = 0 … 1e5): max abs err {worst:.2e}, {ms:.1} ms per call");
    assert!(worst < 1e-12);
}

fn structured_map() -> EnvMap {
    // Smooth sky, a bright small "sun" and pixel-level noise.
    let mut rng = Rng::new(77);
    let sun = normalize([0.4, -0.3, 0.6]);
    let mut m = EnvMap::from_fn(W, H, |d| {
        let sky = 0.5 + 0.5 * d[2].max(0.0);
        let s = if dot(d, sun) > (0.02f64).cos() { 500.0 } else { 0.0 };
        [sky + s, 0.8 * sky + s, 1.2 * sky]
    });
    for p in m.pixels.iter_mut() {
        p[0] *= 0.5 + rng.next_f64() as f32;
    }
    m
}

#[test]
fn phong_subgrid_converges_to_adaptive() {
    // Midpoint sub-grids converge as O(1/k²): k = 16 vs 32 for e = 200 (k = 8 vs 16 for
    // the broader lobes, whose non-negligible region covers far more pixels, to keep the
    // test fast), and the adaptive rule agrees with the finest.
    let map = structured_map();
    let mut worst_k = 0.0f64;
    let mut worst_ad = 0.0f64;
    let sun = normalize([0.4, -0.3, 0.6]);
    let cases = [
        (1.0, 8, sun),
        (20.0, 8, normalize([0.45, -0.3, 0.6])),
        (200.0, 16, normalize([0.43, -0.3, 0.6])),
        (200.0, 16, [0.0, 0.0, 1.0]),
    ];
    for (e, k, r) in cases {
        let coarse = phong_with_subgrid(&map, r, e, k);
        let fine = phong_with_subgrid(&map, r, e, 2 * k);
        let ad = phong(&map, r, e);
        for c in 0..3 {
            worst_k = worst_k.max((coarse[c] / fine[c] - 1.0).abs());
            worst_ad = worst_ad.max((ad[c] / fine[c] - 1.0).abs());
        }
    }
    eprintln!("Phong sub-grid: |k/2k − 1| ≤ {worst_k:.2e}, |adaptive/2k − 1| ≤ {worst_ad:.2e}");
    assert!(worst_k < 1e-4);
    assert!(worst_ad < 1e-4);
}

#[test]
fn irradiance_and_phong_e1_agree_on_a_noisy_map() {
    // e = 1: (e+1)/(2π) max(0, t) = max(0, t)/π, so π·phong(r, 1) = irradiance(r); the
    // two use different per-pixel methods (closed form vs tensor Gauss).
    let map = structured_map();
    let mut worst = 0.0f64;
    for n in test_dirs(9, 10) {
        let a = irradiance(&map, n);
        let b = phong(&map, n, 1.0);
        for k in 0..3 {
            worst = worst.max((a[k] / (PI * b[k]) - 1.0).abs());
        }
    }
    eprintln!("irradiance vs π·phong(e = 1) on a noisy map: max rel diff {worst:.2e}");
    assert!(worst < 1e-12);
}

#[test]
fn small_maps_are_handled() {
    // Coarse maps exercise box splitting (pixels much larger than the lobe).
    for (w, h) in [(1usize, 1usize), (2, 1), (4, 2), (9, 5), (32, 16)] {
        let map = EnvMap::constant(w, h, [1.0; 3]);
        for n in test_dirs(w as u64, 5) {
            let e = irradiance(&map, n)[0];
            assert!((e - PI).abs() < 1e-12, "{w}x{h}: {e}");
            for ex in [1.0, 50.0] {
                let p = phong(&map, n, ex)[0];
                assert!((p - 1.0).abs() < 1e-10, "{w}x{h} e={ex}: {p}");
            }
        }
    }
}
