//! Footprint samples of equirectangular maps (`sphere_quadrature::envmap`) against the
//! independent f64 reference crate: `reference::footprint` (per-pixel adaptive
//! Gauss–Legendre for the Gaussian lobe, the closed-form SG convolution) and
//! `reference::truth::phong` (the cosine power is the normalised Phong lobe).
//!
//! The quick tests use few directions. The measurements quoted in the module docs are
//! `#[ignore]`d and print tables:
//!
//! ```text
//! cargo test --release --test envmap -- --ignored --nocapture exact_accuracy_table
//! cargo test --release --test envmap -- --ignored --nocapture fast_accuracy_table
//! cargo test --release --test envmap -- --ignored --nocapture fis_comparison_table
//! ```

use core::f64::consts::PI;
use reference::analytic::SgLight;
use reference::{luminance, EnvMap, Rng};
use sphere_quadrature::envmap::{EquirectMap, MipPyramid, DEFAULT_RESOLUTION, MAX_DIMENSION};
use sphere_quadrature::footprint::{Kind, MAX_PARAMETER};
use sphere_quadrature::{Error, Vec3};
use std::time::Instant;

const MAPS: [&str; 10] =
    ["apartment", "bridge", "city", "dawn", "forest", "hall", "lab", "lobby", "night", "park"];

fn load(name: &str) -> EnvMap {
    let path = format!("{}/examples/envmaps/{name}.hdr", env!("CARGO_MANIFEST_DIR"));
    EnvMap::load(path).expect("bundled map")
}

/// The map with each pixel's luminance capped at 30× the map's (solid-angle weighted) mean
/// luminance, by scaling its RGB.
fn clamped(map: &EnvMap) -> EnvMap {
    let cap = 30.0 * luminance(map.mean_radiance());
    let mut out = map.clone();
    for p in &mut out.pixels {
        let l = luminance([p[0] as f64, p[1] as f64, p[2] as f64]);
        if l > cap {
            let s = (cap / l) as f32;
            *p = p.map(|c| c * s);
        }
    }
    out
}

fn view(map: &EnvMap) -> EquirectMap<'_> {
    EquirectMap::new(map.width, map.height, &map.pixels).expect("valid map")
}

/// A seeded direction as the crate sees it (f32) and as the reference should (that f32
/// vector, normalised in f64).
fn direction(rng: &mut Rng) -> (Vec3, [f64; 3]) {
    let d = rng.uniform_sphere();
    let v = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
    (v, unit(v))
}

fn unit(v: Vec3) -> [f64; 3] {
    let d = [v.x as f64, v.y as f64, v.z as f64];
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    d.map(|c| c / n)
}

/// The error measure of the docs: the largest channel error relative to the largest
/// channel of the truth.
fn rel_err(got: [f32; 3], want: [f64; 3]) -> f64 {
    let scale = want.iter().fold(0.0f64, |m, c| m.max(c.abs()));
    got.iter().zip(want).fold(0.0f64, |m, (g, w)| m.max((*g as f64 - w).abs())) / scale
}

fn to_f64(p: [f32; 3]) -> [f64; 3] {
    p.map(|c| c as f64)
}

/// The reference footprint sample of the map's piecewise-constant radiance.
fn reference_sample(map: &EnvMap, d: [f64; 3], kind: Kind) -> [f64; 3] {
    match kind {
        Kind::Gaussian { sharpness } => reference::footprint::gaussian(map, d, sharpness as f64),
        Kind::CosinePower { exponent } => {
            reference::footprint::cosine_power(map, d, exponent as f64)
        }
        Kind::Point => map.radiance(d),
    }
}

fn gaussian(sharpness: u32) -> Kind {
    Kind::Gaussian { sharpness }
}

fn power(exponent: u32) -> Kind {
    Kind::CosinePower { exponent }
}

#[test]
fn constant_maps_give_the_constant_exactly() {
    // Both forms divide by the sum of the same weights they apply to the radiance, so a
    // constant comes back to the last bit (in f64 the ratio is within a few ulp of 1, far
    // inside half an f32 ulp).
    let c = [0.3f32, 1.7, 1234.5];
    let mut rng = Rng::new(11);
    for (w, h) in [(512, 256), (100, 50), (7, 5)] {
        let map = EnvMap::constant(w, h, c);
        let m = view(&map);
        let mut buf = vec![[0.0; 3]; MipPyramid::buffer_len(w, h)];
        let pyramid = MipPyramid::new(&m, &mut buf).unwrap();
        let mut dirs = vec![Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.0, 1e-20, -1.0)];
        dirs.extend((0..3).map(|_| direction(&mut rng).0));
        for kind in [gaussian(1), gaussian(9), gaussian(300), gaussian(MAX_PARAMETER), power(1)] {
            for &d in &dirs {
                assert_eq!(m.footprint_sample(d, kind).unwrap(), c, "exact {w}x{h} {kind:?} {d:?}");
                assert_eq!(
                    pyramid.footprint_sample(d, kind).unwrap(),
                    c,
                    "fast {w}x{h} {kind:?} {d:?}"
                );
            }
        }
    }
}

#[test]
fn point_kind_is_the_nearest_pixel() {
    let map = load("city");
    let m = view(&map);
    let mut buf = vec![[0.0; 3]; MipPyramid::buffer_len(map.width, map.height)];
    let pyramid = MipPyramid::new(&m, &mut buf).unwrap();
    let mut rng = Rng::new(3);
    let mut dirs: Vec<Vec3> = (0..2000).map(|_| direction(&mut rng).0 * 3.0).collect();
    // Poles, the seam φ = 0 from both sides, and a pixel centre.
    dirs.extend([Vec3::Z, -Vec3::Z, Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, -1e-6, 0.2)]);
    let c = map.pixel_direction(37, 201);
    dirs.push(Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32));
    for d in dirs {
        let want = map.radiance([d.x as f64, d.y as f64, d.z as f64]).map(|c| c as f32);
        assert_eq!(m.radiance(d).unwrap(), want, "{d:?}");
        assert_eq!(m.footprint_sample(d, Kind::Point).unwrap(), want);
        assert_eq!(pyramid.footprint_sample(d, Kind::Point).unwrap(), want);
    }
    assert_eq!(m.radiance(Vec3::Z).unwrap(), map.pixels[0]);
    assert_eq!(m.radiance(Vec3::new(1.0, -1e-6, 0.0)).unwrap(), map.pixels[128 * 512 + 511]);
}

#[test]
fn exact_form_matches_subpixel_quadrature_on_a_real_map() {
    // The reference integrates each pixel by adaptive Gauss–Legendre to ~1e-14; the crate
    // uses the corrected midpoint rule (q·h² ≤ 0.06) or a small Gauss–Legendre rule. The
    // worst error measured over the ten maps (exact_accuracy_table) is 1.2e-6; the plain
    // one-point rule would be 1e-4…8e-4 at S = 8…128 and fail here.
    let map = load("park"); // the sun: the hardest map
    let m = view(&map);
    let mut rng = Rng::new(2026);
    let mut worst: f64 = 0.0;
    for kind in [gaussian(1), gaussian(8), gaussian(64), gaussian(700), power(1), power(4)] {
        for _ in 0..2 {
            let (v, d) = direction(&mut rng);
            let got = m.footprint_sample(v, kind).unwrap();
            let want = reference_sample(&map, d, kind);
            let e = rel_err(got, want);
            worst = worst.max(e);
            assert!(e < 3e-6, "{kind:?} {d:?}: {got:?} vs {want:?} ({e:.2e})");
        }
    }
    eprintln!("exact form vs sub-pixel quadrature on park: worst {worst:.2e}");
}

#[test]
fn sg_light_map_converges_to_the_closed_form_convolution() {
    // A map sampled at pixel centres from an SG light of sharpness λ, seen through a
    // Gaussian footprint of sharpness S, against the closed form of the smooth product.
    // The map is piecewise constant, so the sample differs from the smooth integral by the
    // midpoint-sampling error of L: per pixel −∫(∇L·Δ)(∇f·Δ) − ½ΔᵀH_LΔ·f (and the θ
    // centroid offset (h²/12)·cot θ·L_θ·f), Δ the offset in the pixel, so
    // |error| ≤ (h²/12)·(λS + λ² + λ + 2λ)·Y for lights and lobes within 60° of the
    // equator (|cot θ| ≤ 2 where L·f matters), h = π/H. Second order: halving h divides
    // the error by 4 (a half-pixel shift of the convention would be first order).
    let mut rng = Rng::new(77);
    for (lambda, s) in [(8.0, 8u32), (30.0, 4), (4.0, 40)] {
        let light = SgLight { axis: [0.8, 0.3, 0.2], sharpness: lambda, amplitude: 5.0 };
        let (_, d) = loop {
            let (v, d) = direction(&mut rng);
            if d[2].abs() < 0.5 && reference::vec::dot(d, [0.8, 0.3, 0.2]) > 0.5 {
                break (v, d);
            }
        };
        let v = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
        let d = unit(v);
        let want = reference::footprint::sg_convolution(&light, d, s as f64);
        let mut errors = Vec::new();
        for (w, h) in [(256, 128), (512, 256)] {
            let map = EnvMap::from_fn(w, h, |x| [light.value(x); 3]);
            let got = view(&map).footprint_sample(v, gaussian(s)).unwrap()[0] as f64;
            let e = (got - want) / want;
            let hh = PI / h as f64;
            let bound = hh * hh / 12.0 * (lambda * s as f64 + lambda * lambda + 3.0 * lambda);
            eprintln!("λ = {lambda}, S = {s}, {w}x{h}: error {e:.3e}, bound {bound:.2e}");
            assert!(e.abs() <= bound, "λ = {lambda}, S = {s}, {w}x{h}: {e:.3e} > {bound:.2e}");
            errors.push(e);
        }
        let ratio = errors[0] / errors[1];
        assert!((3.0..=5.0).contains(&ratio), "λ = {lambda}, S = {s}: ratio {ratio}");
        // Richardson extrapolation removes the h² term: what is left is O(h⁴) plus the
        // f32 rounding of the map and the sample (~1e-7).
        let extrapolated = (4.0 * errors[1] - errors[0]) / 3.0;
        eprintln!("λ = {lambda}, S = {s}: extrapolated error {extrapolated:.2e}");
        assert!(extrapolated.abs() < 5e-7, "λ = {lambda}, S = {s}: {extrapolated:.2e}");
    }
}

/// The fast form's stated bounds (module docs): relative error per sample at the default
/// resolution over the bundled maps, raw or clamped, at most 1.2·10⁻² for the Gaussian
/// (measured worst 8.4e-3) and 3·10⁻² for the cosine power (measured worst 2.2e-2, a sun
/// on the horizon).
fn fast_bound(kind: Kind) -> f64 {
    match kind {
        Kind::CosinePower { .. } => 3e-2,
        _ => 1.2e-2,
    }
}

#[test]
fn fast_form_is_within_its_stated_bound() {
    let raw = load("park");
    let maps = [clamped(&raw), raw];
    let mut rng = Rng::new(5);
    let dirs: Vec<Vec3> = (0..3).map(|_| direction(&mut rng).0).collect();
    let kinds = [gaussian(1), gaussian(4), gaussian(16), gaussian(64), power(1), power(4)];
    for map in &maps {
        let m = view(map);
        let mut buf = vec![[0.0; 3]; MipPyramid::buffer_len(map.width, map.height)];
        let pyramid = MipPyramid::new(&m, &mut buf).unwrap();
        let fine = pyramid.with_resolution(4.0).unwrap();
        let (mut sum2, mut sum2_fine) = (0.0, 0.0);
        for kind in kinds {
            for &d in &dirs {
                let exact = to_f64(m.footprint_sample(d, kind).unwrap());
                let e = rel_err(pyramid.footprint_sample(d, kind).unwrap(), exact);
                let e_fine = rel_err(fine.footprint_sample(d, kind).unwrap(), exact);
                assert!(e <= fast_bound(kind), "{kind:?} {d:?}: {e:.2e}");
                sum2 += e * e;
                sum2_fine += e_fine * e_fine;
            }
        }
        // Finer levels are more accurate (measured: 4–8× in RMS).
        assert!(sum2_fine < 0.25 * sum2, "{sum2_fine} vs {sum2}");
    }
}

#[test]
fn batch_forms_equal_single_samples_and_are_deterministic() {
    let map = load("dawn");
    let m = view(&map);
    let mut buf = vec![[0.0; 3]; MipPyramid::buffer_len(map.width, map.height)];
    let pyramid = MipPyramid::new(&m, &mut buf).unwrap();
    let mut rng = Rng::new(8);
    let dirs: Vec<Vec3> = (0..4).map(|_| direction(&mut rng).0).collect();
    for kind in [Kind::Point, gaussian(3), power(2)] {
        let mut out = vec![[0.0; 3]; dirs.len()];
        m.footprint_samples(&dirs, kind, &mut out).unwrap();
        let mut fast = vec![[0.0; 3]; dirs.len()];
        pyramid.footprint_samples(&dirs, kind, &mut fast).unwrap();
        for ((o, f), &d) in out.iter().zip(&fast).zip(&dirs) {
            assert_eq!(*o, m.footprint_sample(d, kind).unwrap());
            assert_eq!(*f, pyramid.footprint_sample(d, kind).unwrap());
        }
    }
}

#[test]
fn mirrored_map_gives_mirrored_samples() {
    // Rows are summed in mirror pairs; flipping the map upside down and the direction's z
    // must give the same sample (to rounding).
    let mut rng = Rng::new(21);
    let (w, h) = (64, 33);
    let pixels: Vec<[f32; 3]> =
        (0..w * h).map(|_| [rng.next_f64() as f32, (rng.next_f64() * 10.0) as f32, 0.5]).collect();
    let flipped: Vec<[f32; 3]> =
        (0..h).rev().flat_map(|v| pixels[v * w..(v + 1) * w].to_vec()).collect();
    let (a, b) =
        (EquirectMap::new(w, h, &pixels).unwrap(), EquirectMap::new(w, h, &flipped).unwrap());
    for kind in [gaussian(2), gaussian(60), power(3)] {
        for _ in 0..3 {
            let (v, _) = direction(&mut rng);
            let (ya, yb) = (
                a.footprint_sample(v, kind).unwrap(),
                b.footprint_sample(Vec3::new(v.x, v.y, -v.z), kind).unwrap(),
            );
            for (p, q) in ya.iter().zip(yb) {
                assert!((p - q).abs() <= 1e-6 * p.abs(), "{kind:?}: {ya:?} vs {yb:?}");
            }
        }
    }
}

#[test]
fn tiny_maps_and_extreme_parameters_stay_within_the_pixel_range() {
    // Every sample is a weighted mean with non-negative weights, so it lies between the
    // smallest and the largest pixel, whatever the map size and lobe.
    let mut rng = Rng::new(99);
    for (w, h) in [(1, 1), (2, 1), (1, 3), (3, 2), (7, 5), (9, 4)] {
        let pixels: Vec<[f32; 3]> =
            (0..w * h).map(|i| [i as f32, 1.0 + (i % 3) as f32, -2.0]).collect();
        let m = EquirectMap::new(w, h, &pixels).unwrap();
        let mut buf = vec![[0.0; 3]; MipPyramid::buffer_len(w, h)];
        let pyramid = MipPyramid::new(&m, &mut buf).unwrap();
        let lo = pixels.iter().fold([f32::MAX; 3], |a, p| [0, 1, 2].map(|c| a[c].min(p[c])));
        let hi = pixels.iter().fold([f32::MIN; 3], |a, p| [0, 1, 2].map(|c| a[c].max(p[c])));
        let mut dirs = vec![Vec3::Z, -Vec3::Z, Vec3::new(-1.0, -0.0, 0.0)];
        dirs.extend((0..3).map(|_| direction(&mut rng).0));
        for kind in [gaussian(1), gaussian(MAX_PARAMETER), power(1), power(MAX_PARAMETER)] {
            for &d in &dirs {
                for y in [
                    m.footprint_sample(d, kind).unwrap(),
                    pyramid.footprint_sample(d, kind).unwrap(),
                ] {
                    for c in 0..3 {
                        let slack = 1e-5 * (hi[c].abs() + 1.0);
                        assert!(
                            y[c] >= lo[c] - slack && y[c] <= hi[c] + slack,
                            "{w}x{h} {kind:?} {d:?}: {y:?}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn huge_radiance_stays_finite() {
    let pixels = vec![[f32::MAX, 0.0, -f32::MAX]; 8 * 4];
    let m = EquirectMap::new(8, 4, &pixels).unwrap();
    let mut buf = vec![[0.0; 3]; MipPyramid::buffer_len(8, 4)];
    let pyramid = MipPyramid::new(&m, &mut buf).unwrap();
    for y in [
        m.footprint_sample(Vec3::X, gaussian(3)).unwrap(),
        pyramid.footprint_sample(Vec3::X, gaussian(3)).unwrap(),
    ] {
        assert_eq!(y, [f32::MAX, 0.0, -f32::MAX]);
    }
}

#[test]
fn buffer_length_is_pinned() {
    // Four entries per texel of levels 2, 3, …: 128×64 + 64×32 + … + 1×1 texels.
    assert_eq!(MipPyramid::buffer_len(512, 256), 4 * 10_923);
    assert_eq!(
        MipPyramid::buffer_len(1000, 500),
        4 * (250 * 125 + 125 * 63 + 63 * 32 + 32 * 16 + 16 * 8 + 8 * 4 + 4 * 2 + 2 + 1)
    );
    assert_eq!(MipPyramid::buffer_len(2, 1), 0);
    assert_eq!(MipPyramid::buffer_len(0, 5), 0);
    assert_eq!(MipPyramid::buffer_len(1, 1), 0);
}

#[test]
fn bad_input_is_refused() {
    let pixels = vec![[1.0f32; 3]; 16 * 8];
    // Sizes and lengths.
    assert_eq!(EquirectMap::new(0, 8, &[]), Err(Error::InvalidSize));
    assert_eq!(EquirectMap::new(16, 0, &[]), Err(Error::InvalidSize));
    assert_eq!(EquirectMap::new(MAX_DIMENSION + 1, 1, &pixels), Err(Error::InvalidSize));
    assert_eq!(EquirectMap::new(16, 7, &pixels), Err(Error::LengthMismatch));
    assert_eq!(EquirectMap::new(usize::MAX / 2, 3, &pixels), Err(Error::InvalidSize));
    // Non-finite radiance is refused up front, so samples never see it.
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut p = pixels.clone();
        p[77][1] = bad;
        assert_eq!(EquirectMap::new(16, 8, &p), Err(Error::InvalidRadiance));
    }
    let m = EquirectMap::new(16, 8, &pixels).unwrap();
    assert_eq!((m.width(), m.height(), m.pixels().len()), (16, 8, 128));
    // Buffers.
    let need = MipPyramid::buffer_len(16, 8);
    let mut small = vec![[0.0; 3]; need - 1];
    assert_eq!(MipPyramid::new(&m, &mut small).err(), Some(Error::LengthMismatch));
    let mut buf = vec![[0.0; 3]; need + 5]; // longer is fine
    let pyramid = MipPyramid::new(&m, &mut buf).unwrap();
    for r in [0.0, 0.49, 64.5, f32::NAN, f32::INFINITY] {
        assert_eq!(pyramid.with_resolution(r).err(), Some(Error::InvalidResolution));
    }
    assert!(pyramid.with_resolution(DEFAULT_RESOLUTION).is_ok());
    // Directions.
    // (Any finite nonzero vector is valid, however short: crate docs, "Directions".)
    assert_eq!(m.radiance(Vec3::new(1e-20, 0.0, 0.0)), m.radiance(Vec3::X));
    let bad_dirs = [Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0), Vec3::new(0.0, f32::INFINITY, 1.0)];
    for d in bad_dirs {
        assert_eq!(m.radiance(d), Err(Error::InvalidDirection));
        for kind in [Kind::Point, gaussian(4), power(1)] {
            assert_eq!(m.footprint_sample(d, kind), Err(Error::InvalidDirection));
            assert_eq!(pyramid.footprint_sample(d, kind), Err(Error::InvalidDirection));
        }
    }
    // Parameters.
    for kind in [gaussian(0), gaussian(MAX_PARAMETER + 1), power(0), power(u32::MAX)] {
        assert_eq!(m.footprint_sample(Vec3::Z, kind), Err(Error::InvalidResponse));
        assert_eq!(pyramid.footprint_sample(Vec3::Z, kind), Err(Error::InvalidResponse));
    }
    // Batches: lengths, and nothing written on error.
    let dirs = [Vec3::Z, Vec3::ZERO];
    let mut out = [[7.0f32; 3]; 2];
    assert_eq!(m.footprint_samples(&dirs, gaussian(2), &mut out[..1]), Err(Error::LengthMismatch));
    assert_eq!(m.footprint_samples(&dirs, gaussian(2), &mut out), Err(Error::InvalidDirection));
    assert_eq!(
        pyramid.footprint_samples(&dirs, gaussian(2), &mut out),
        Err(Error::InvalidDirection)
    );
    assert_eq!(
        m.footprint_samples(&dirs[..1], gaussian(0), &mut out[..1]),
        Err(Error::InvalidResponse)
    );
    assert_eq!(out, [[7.0; 3]; 2]);
}

// ---------------------------------------------------------------------------------------
// Measurements (ignored): the tables behind the module docs.

fn kinds_for_tables() -> Vec<Kind> {
    let mut k: Vec<Kind> = [1, 2, 4, 8, 16, 32, 64, 128].map(gaussian).to_vec();
    k.extend([power(1), power(4)]);
    k
}

#[test]
#[ignore]
fn exact_accuracy_table() {
    // Exact form against the reference sub-pixel quadrature: 3 directions per map, all ten
    // maps; worst relative error per lobe.
    let mut kinds = kinds_for_tables();
    kinds.extend([gaussian(512), gaussian(4096), power(2), power(16), power(64), power(4096)]);
    let maps: Vec<EnvMap> = MAPS.iter().map(|n| load(n)).collect();
    println!("| lobe | worst relative error | mean time per sample |");
    println!("|---|---|---|");
    for kind in kinds {
        let mut rng = Rng::new(1234);
        let (mut worst, mut time, mut count) = (0.0f64, 0.0, 0);
        for map in &maps {
            let m = view(map);
            for _ in 0..3 {
                let (v, d) = direction(&mut rng);
                let t = Instant::now();
                let got = m.footprint_sample(v, kind).unwrap();
                time += t.elapsed().as_secs_f64();
                count += 1;
                worst = worst.max(rel_err(got, reference_sample(map, d, kind)));
            }
        }
        println!("| {kind:?} | {worst:.1e} | {:.0} µs |", 1e6 * time / count as f64);
    }
}

#[test]
#[ignore]
fn fast_accuracy_table() {
    // Fast form against the exact form: 64 directions per map, all ten maps, raw and
    // clamped; RMS and worst relative error over all samples, and the time per sample.
    const DIRS: usize = 64;
    for clamp in [false, true] {
        let maps: Vec<EnvMap> =
            MAPS.iter().map(|n| if clamp { clamped(&load(n)) } else { load(n) }).collect();
        let mut buffers: Vec<Vec<[f32; 3]>> = maps
            .iter()
            .map(|m| vec![[0.0; 3]; MipPyramid::buffer_len(m.width, m.height)])
            .collect();
        let views: Vec<EquirectMap<'_>> = maps.iter().map(view).collect();
        let t = Instant::now();
        let pyramids: Vec<MipPyramid<'_>> = views
            .iter()
            .zip(buffers.iter_mut())
            .map(|(m, b)| MipPyramid::new(m, b).unwrap())
            .collect();
        let build = t.elapsed().as_secs_f64() / maps.len() as f64;
        println!(
            "\n{} maps (pyramid build {:.1} ms per map)",
            if clamp { "clamped" } else { "raw" },
            1e3 * build
        );
        println!("| lobe | exact µs | r = 2: RMS | max | µs | speed-up | r = 4: RMS | max | µs | speed-up |");
        println!("|---|---|---|---|---|---|---|---|---|---|");
        for kind in kinds_for_tables() {
            let mut rng = Rng::new(42);
            let dirs: Vec<Vec3> = (0..DIRS).map(|_| direction(&mut rng).0).collect();
            let mut t_exact = 0.0;
            let mut exact = Vec::new();
            for m in &views {
                let t = Instant::now();
                let ys: Vec<[f32; 3]> =
                    dirs.iter().map(|&d| m.footprint_sample(d, kind).unwrap()).collect();
                t_exact += t.elapsed().as_secs_f64();
                exact.push(ys);
            }
            let n = (DIRS * maps.len()) as f64;
            let mut line = format!("| {kind:?} | {:.0} |", 1e6 * t_exact / n);
            for r in [2.0, 4.0] {
                let (mut sum2, mut worst, mut time) = (0.0, 0.0f64, 0.0);
                for (p, ys) in pyramids.iter().zip(&exact) {
                    let p = p.with_resolution(r).unwrap();
                    let t = Instant::now();
                    let fast: Vec<[f32; 3]> =
                        dirs.iter().map(|&d| p.footprint_sample(d, kind).unwrap()).collect();
                    time += t.elapsed().as_secs_f64();
                    for (f, y) in fast.iter().zip(ys) {
                        let e = rel_err(*f, to_f64(*y));
                        sum2 += e * e;
                        worst = worst.max(e);
                    }
                }
                line += &format!(
                    " {:.1e} | {:.1e} | {:.0} | {:.0}× |",
                    (sum2 / n).sqrt(),
                    worst,
                    1e6 * time / n,
                    t_exact / time
                );
            }
            println!("{line}");
        }
    }
}

/// Filtered importance sampling (Křivánek and Colbert 2008) on a plain mip pyramid of
/// solid-angle weighted 2×2 box averages, for comparison: `n` spherical-Fibonacci
/// sub-samples morphed onto the lobe, each read trilinearly at the level whose texel solid
/// angle matches its share of the lobe, `1/(n·pdf)`, plus K&C's bias of one level.
struct Fis {
    levels: Vec<(usize, usize, Vec<[f64; 3]>)>,
}

impl Fis {
    fn new(map: &EnvMap) -> Fis {
        let mut levels = vec![(
            map.width,
            map.height,
            map.pixels.iter().map(|p| to_f64(*p)).collect::<Vec<_>>(),
        )];
        while levels.last().unwrap().0 > 1 && levels.last().unwrap().1 > 1 {
            let (w, h, px) = levels.last().unwrap();
            let (nw, nh) = (w / 2, h / 2);
            let band = |v: usize| {
                let (a, b) = (PI * v as f64 / *h as f64, PI * (v + 1) as f64 / *h as f64);
                a.cos() - b.cos()
            };
            let mut next = vec![[0.0; 3]; nw * nh];
            for v in 0..nh {
                for u in 0..nw {
                    let (mut acc, mut wsum) = ([0.0; 3], 0.0);
                    for (du, dv) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let om = band(2 * v + dv);
                        let p = px[(2 * v + dv) * w + 2 * u + du];
                        for c in 0..3 {
                            acc[c] += om * p[c];
                        }
                        wsum += om;
                    }
                    next[v * nw + u] = acc.map(|a| a / wsum);
                }
            }
            levels.push((nw, nh, next));
        }
        Fis { levels }
    }

    fn bilinear(&self, level: usize, theta: f64, phi: f64) -> [f64; 3] {
        let (w, h, px) = &self.levels[level];
        let x = phi / (2.0 * PI) * *w as f64 - 0.5;
        let y = (theta / PI * *h as f64 - 0.5).clamp(0.0, *h as f64 - 1.0);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let u0 = (x0 as i64).rem_euclid(*w as i64) as usize;
        let u1 = (u0 + 1) % w;
        let v0 = y0 as usize;
        let v1 = (v0 + 1).min(h - 1);
        let p = |u: usize, v: usize| px[v * w + u];
        let (a, b, c, d) = (p(u0, v0), p(u1, v0), p(u0, v1), p(u1, v1));
        [0, 1, 2].map(|k| {
            (1.0 - fy) * ((1.0 - fx) * a[k] + fx * b[k]) + fy * ((1.0 - fx) * c[k] + fx * d[k])
        })
    }

    fn sample(&self, d: [f64; 3], kind: Kind, n: usize) -> [f64; 3] {
        let (w0, h0, _) = &self.levels[0];
        let (t1, t2) = reference::vec::frame(d);
        let golden = (5f64.sqrt() - 1.0) / 2.0;
        let mut acc = [0.0; 3];
        for j in 0..n {
            let u = (j as f64 + 0.5) / n as f64;
            let (t, pdf) = match kind {
                Kind::Gaussian { sharpness } => {
                    let s = sharpness as f64;
                    let g = -(-(u * -(-2.0 * s).exp_m1())).ln_1p() / s; // 1 − t
                    let t = 1.0 - g;
                    (t, s * (-s * g).exp() / (-2.0 * PI * (-2.0 * s).exp_m1()))
                }
                Kind::CosinePower { exponent } => {
                    let p = exponent as f64;
                    let t = u.powf(1.0 / (p + 1.0));
                    (t, (p + 1.0) / (2.0 * PI) * t.powf(p))
                }
                Kind::Point => unreachable!(),
            };
            let phi = 2.0 * PI * (j as f64 * golden).fract();
            let x = reference::vec::from_frame(t1, t2, d, t, (1.0 - t * t).max(0.0).sqrt(), phi);
            let theta = x[2].clamp(-1.0, 1.0).acos();
            let az = x[1].atan2(x[0]).rem_euclid(2.0 * PI);
            let texel0 = (2.0 * PI / *w0 as f64) * (PI / *h0 as f64) * theta.sin().max(1e-9);
            let lod = (0.5 * (1.0 / (n as f64 * pdf) / texel0).log2() + 1.0)
                .clamp(0.0, (self.levels.len() - 1) as f64);
            let l0 = lod.floor() as usize;
            let l1 = (l0 + 1).min(self.levels.len() - 1);
            let f = lod - l0 as f64;
            let (a, b) = (self.bilinear(l0, theta, az), self.bilinear(l1, theta, az));
            for c in 0..3 {
                acc[c] += (1.0 - f) * a[c] + f * b[c];
            }
        }
        acc.map(|a| a / n as f64)
    }
}

#[test]
#[ignore]
fn fis_comparison_table() {
    // FIS (N = 64, 256) against this crate's moment rule (default resolution), both against
    // the exact form: RMS and worst relative error over 16 directions × 10 maps, and time.
    const DIRS: usize = 16;
    for clamp in [false, true] {
        println!("\n{} maps", if clamp { "clamped" } else { "raw" });
        println!("| lobe | FIS 64: RMS | max | µs | FIS 256: RMS | max | µs | moment rule: RMS | max | µs |");
        println!("|---|---|---|---|---|---|---|---|---|---|");
        let maps: Vec<EnvMap> =
            MAPS.iter().map(|n| if clamp { clamped(&load(n)) } else { load(n) }).collect();
        for kind in [gaussian(1), gaussian(4), gaussian(16), gaussian(64), power(1), power(4)] {
            let mut stats = [(0.0, 0.0f64, 0.0); 3];
            for map in &maps {
                let m = view(map);
                let mut buf = vec![[0.0; 3]; MipPyramid::buffer_len(map.width, map.height)];
                let pyramid = MipPyramid::new(&m, &mut buf).unwrap();
                let fis = Fis::new(map);
                let mut rng = Rng::new(7);
                for _ in 0..DIRS {
                    let (v, d) = direction(&mut rng);
                    let exact = to_f64(m.footprint_sample(v, kind).unwrap());
                    for (k, st) in stats.iter_mut().enumerate() {
                        let t = Instant::now();
                        let y = match k {
                            0 => fis.sample(d, kind, 64).map(|c| c as f32),
                            1 => fis.sample(d, kind, 256).map(|c| c as f32),
                            _ => pyramid.footprint_sample(v, kind).unwrap(),
                        };
                        st.2 += t.elapsed().as_secs_f64();
                        let e = rel_err(y, exact);
                        st.0 += e * e;
                        st.1 = st.1.max(e);
                    }
                }
            }
            let n = (DIRS * maps.len()) as f64;
            let mut line = format!("| {kind:?} |");
            for (s2, worst, time) in stats {
                line +=
                    &format!(" {:.1e} | {:.1e} | {:.0} |", (s2 / n).sqrt(), worst, 1e6 * time / n);
            }
            println!("{line}");
        }
    }
}
