//! Regression tests for the defects of the adversarial pass (issue #16, item 4): one
//! `defect_NN_…` test per defect, each failing before its fix (see the commit messages).

use crate::gen;

use sphere_quadrature::envmap::EquirectMap;
use sphere_quadrature::metrics::{self, SobolevWeights};
use sphere_quadrature::probe::Probe;
use sphere_quadrature::sg::{self, SphericalGaussian};
use sphere_quadrature::sh::ShL2;
use sphere_quadrature::{qmc, Error, FibonacciPoints, Frame, Mat3, Vec3};

const FOUR_PI: f32 = 4.0 * core::f32::consts::PI;

fn rel(got: f32, want: f32) -> f32 {
    (got - want).abs() / want.abs().max(f32::MIN_POSITIVE)
}

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).length() <= tol
}

#[test]
fn defect_01_sh_index_overflow() {
    // l(l + 1) overflows usize: no index, and no panic in a debug build.
    assert_eq!(metrics::sh_index(1 << 32, 0), None);
    assert_eq!(metrics::sh_index(usize::MAX, 0), None);
    assert_eq!(metrics::sh_index(usize::MAX, -1), None);
    // Representable indices are unchanged.
    assert_eq!(metrics::sh_index(0, 0), Some(0));
    assert_eq!(metrics::sh_index(3, -3), Some(9));
    assert_eq!(metrics::sh_index(3, 3), Some(15));
    assert_eq!(metrics::sh_index(2, 3), None);
    // The largest l whose block fits.
    let l = (1usize << (usize::BITS / 2)) - 2;
    assert_eq!(metrics::sh_index(l, 0), Some(l * (l + 1)));
}

#[test]
fn defect_02_wce_from_spectrum_rejects_nan_and_negative() {
    let bad = [[0.1, f64::NAN, 0.2], [0.1, -0.5, -0.2], [0.1, 0.2, f64::INFINITY]];
    for spectrum in bad {
        for w in [SobolevWeights::Exact, SobolevWeights::Asymptotic] {
            assert_eq!(
                metrics::wce_from_spectrum(&spectrum, 1.5, w),
                Err(Error::InvalidSpectrum),
                "{spectrum:?}"
            );
        }
    }
    // A good spectrum still works, and the spectral path of a real set is accepted.
    assert!(metrics::wce_from_spectrum(&[0.1, 0.0, 0.2], 1.5, SobolevWeights::Exact).is_ok());
    let set = FibonacciPoints::sphere(64).unwrap();
    let points: Vec<Vec3> = set.iter().collect();
    let mut spec = [0.0f64; 40];
    let w = metrics::wce_spectral(&points, 1.5, SobolevWeights::Exact, &mut spec).unwrap();
    assert!(w > 0.0 && w.is_finite());
    assert!(spec.iter().all(|&c| c >= 0.0));
}

#[test]
fn defect_03_energy_f32_long_vectors() {
    for pts in [
        [Vec3::X * 1e20, -Vec3::X],
        [Vec3::X * 1e-20, -Vec3::X],
        [Vec3::new(1e38, 3e38, 0.0), Vec3::new(0.0, -1e-40, 0.0)],
    ] {
        let e = metrics::energy(&pts).unwrap();
        let e32 = metrics::energy_f32(&pts).unwrap();
        assert!((e32 as f64 - e).abs() <= 1e-6 * e, "{pts:?}: {e32} against {e}");
    }
}

#[test]
fn defect_04_sg_product_extreme_sharpness() {
    let a = SphericalGaussian::new(Vec3::Z, 2e19, 1.0).unwrap();
    let b = SphericalGaussian::new(Vec3::X, 1.0, 1.0).unwrap();
    let p = a.product(&b);
    assert!(p.sharpness.is_finite() && rel(p.sharpness, 2e19) < 1e-6, "{p:?}");
    assert!(close(p.axis, Vec3::Z, 1e-6), "{p:?}");
    // exp(−λ₁λ₂|μ₁ − μ₂|²/(|λ₁μ₁ + λ₂μ₂| + λ₁ + λ₂)) ≈ e^(−1).
    assert!(rel(p.amplitude, (-1.0f32).exp()) < 1e-5, "{p:?}");

    let a = SphericalGaussian::new(Vec3::Z, 1e-22, 1.0).unwrap();
    let b = SphericalGaussian::new(Vec3::X, 1e-44, 1.0).unwrap();
    let p = a.product(&b);
    assert!((p.axis.length() - 1.0).abs() < 1e-6, "{p:?}");
    assert!(close(p.axis, Vec3::Z, 1e-6), "{p:?}");
    assert!(rel(p.sharpness, 1e-22) < 1e-6, "{p:?}");
    assert!(rel(p.amplitude, 1.0) < 1e-6, "{p:?}");

    // Ordinary lobes: the closed form.
    let a = SphericalGaussian::new(Vec3::new(1.0, 2.0, 3.0), 5.0, 2.0).unwrap();
    let b = SphericalGaussian::new(Vec3::new(-1.0, 0.5, 1.0), 3.0, 0.5).unwrap();
    let p = a.product(&b);
    let u = a.axis * 5.0 + b.axis * 3.0;
    assert!(rel(p.sharpness, u.length()) < 1e-6);
    assert!(close(p.axis, u * (1.0 / u.length()), 1e-6));
    let d2 = (a.axis - b.axis).length_squared();
    let want = 1.0 * (-15.0 * d2 / (u.length() + 8.0)).exp();
    assert!(rel(p.amplitude, want) < 1e-5, "{} against {want}", p.amplitude);
}

#[test]
fn defect_05_full_integral_tiny_sharpness() {
    for lambda in [1e-45f32, 1e-40, 1e-30, 1e-10, 1e-6] {
        let f = sg::full_integral(lambda).unwrap();
        let want = (4.0 * core::f64::consts::PI * (1.0 - lambda as f64)) as f32;
        assert!(rel(f, want) < 1e-6, "λ = {lambda:e}: {f}");
    }
    // Continuity at the switch between the series and the closed form.
    for lambda in [1e-4f32, 1.1e-4, 0.9e-4, 1e-3, 0.5, 2.0] {
        let f = sg::full_integral(lambda).unwrap();
        let l = lambda as f64;
        let want = (2.0 * core::f64::consts::PI * -(-2.0 * l).exp_m1() / l) as f32;
        assert!(rel(f, want) < 1e-6, "λ = {lambda:e}: {f} against {want}");
    }
    // The probe's glossy path: a constant field with a lobe of sharpness 10⁻⁴⁵ is the lobe's
    // integral (4π) times the radiance.
    let mut probe = Probe::<64>::new();
    probe.update(&[2.0; 64]).unwrap();
    let lobe = SphericalGaussian::new(Vec3::Z, 1e-45, 1.0).unwrap();
    let g = probe.glossy(&lobe).unwrap().value;
    assert!(rel(g, 2.0 * FOUR_PI) < 1e-5, "{g}");
}

#[test]
fn defect_06_quaternion_of_any_finite_scale() {
    // π about y: diag(−1, 1, −1).
    let want = Mat3::from_rows(-Vec3::X, Vec3::Y, -Vec3::Z);
    for s in [1.0f32, 1e20, 1e-16, 3e38, 1e-44] {
        let m = Mat3::from_quaternion([0.0, s, 0.0, 0.0]);
        for (r, w) in m.rows.iter().zip(want.rows) {
            assert!(close(*r, w, 1e-6), "scale {s:e}: {m:?}");
        }
    }
    // Mixed scales: a huge and a tiny component.
    let m = Mat3::from_quaternion([3e37, 0.0, 0.0, 4e37]);
    let r = Mat3::from_quaternion([0.6, 0.0, 0.0, 0.8]);
    for (a, b) in m.rows.iter().zip(r.rows) {
        assert!(close(*a, b, 1e-6), "{m:?} against {r:?}");
    }
    // Zero and non-finite quaternions still give the identity.
    for q in [[0.0; 4], [f32::NAN, 0.0, 0.0, 1.0], [f32::INFINITY, 0.0, 0.0, 1.0]] {
        assert_eq!(Mat3::from_quaternion(q), Mat3::IDENTITY);
    }
}

#[test]
fn defect_07_any_finite_nonzero_direction_is_valid() {
    let u = Vec3::new(0.36, -0.48, 0.8);
    let scales = [1e30f32, 3e19, 1e-20, 1e-30, 1e-38];
    let map_pixels: Vec<[f32; 3]> = (0..32 * 16).map(|i| [i as f32, 1.0, 2.0]).collect();
    let map = EquirectMap::new(32, 16, &map_pixels).unwrap();
    let set = FibonacciPoints::sphere(1000).unwrap();
    let mut probe = Probe::<64>::new();
    let samples: [f32; 64] = probe.directions().map(|d| 1.0 + d.z + 0.5 * d.x);
    probe.update(&samples).unwrap();
    let sky = |d: Vec3| 1.0 + d.z + 0.5 * d.x;
    for s in scales {
        let v = u * s;
        let what = format!("{v:?}");
        let n = v.try_normalize().unwrap_or_else(|| panic!("try_normalize {what}"));
        assert!(close(n, u, 1e-5), "{what}: {n:?}");
        assert!(close(Frame::from_normal(v).unwrap().to_world(Vec3::Z), u, 1e-5), "{what}");
        assert!(close(SphericalGaussian::new(v, 1.0, 1.0).unwrap().axis, u, 1e-5), "{what}");
        let e = metrics::energy(&[v, Vec3::X]).unwrap();
        assert!((e - metrics::energy(&[u, Vec3::X]).unwrap()).abs() < 1e-6, "{what}");
        let q = qmc::irradiance::<64, f32, _>(v, 0, sky).unwrap();
        assert!(rel(q, qmc::irradiance::<64, f32, _>(u, 0, sky).unwrap()) < 1e-5, "{what}");
        let p = probe.irradiance(v).unwrap().value;
        assert!(rel(p, probe.irradiance(u).unwrap().value) < 1e-5, "{what}");
        let b = ShL2::<f32>::basis(v).unwrap();
        for (x, y) in b.iter().zip(ShL2::<f32>::basis(u).unwrap()) {
            assert!((x - y).abs() < 1e-5, "{what}");
        }
        assert_eq!(map.radiance(v), map.radiance(u), "{what}");
        assert_eq!(set.nearest_index(v), set.nearest_index(u), "{what}");
    }
    // Subnormal components (a few significant bits): the direction of the vector as given.
    for v in [Vec3::new(3e-43, -5e-43, 8e-43), Vec3::new(0.0, 0.0, -1e-45)] {
        let n = v.try_normalize().unwrap();
        let (x, y, z) = (v.x as f64, v.y as f64, v.z as f64);
        let l = (x * x + y * y + z * z).sqrt();
        let want = Vec3::new((x / l) as f32, (y / l) as f32, (z / l) as f32);
        assert!(close(n, want, 1e-6), "{v:?}: {n:?}");
        assert!(set.nearest_index(v).is_ok() && probe.irradiance(v).is_ok());
    }
    // Zero and non-finite vectors are still invalid, everywhere.
    for v in [Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0), Vec3::new(f32::INFINITY, 0.0, 1.0)] {
        assert_eq!(v.try_normalize(), None);
        assert_eq!(Frame::from_normal(v).err(), Some(Error::InvalidDirection));
        assert_eq!(probe.irradiance(v).err(), Some(Error::InvalidDirection));
        assert_eq!(ShL2::<f32>::basis(v).err(), Some(Error::InvalidDirection));
        assert_eq!(metrics::energy(&[v]).err(), Some(Error::InvalidDirection));
        assert_eq!(set.nearest_index(v).err(), Some(Error::InvalidDirection));
        assert_eq!(map.radiance(v).err(), Some(Error::InvalidDirection));
    }
}

#[test]
fn defect_08_rotations_validated_where_they_enter() {
    let set = FibonacciPoints::sphere(1000).unwrap();
    let nan = Mat3::from_rows(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y, Vec3::Z);
    let scaled = Mat3::from_rows(Vec3::X * 2.0, Vec3::Y * 2.0, Vec3::Z * 2.0);
    let mirror = Mat3::from_rows(Vec3::X, Vec3::Y, -Vec3::Z);
    let sheared = Mat3::from_rows(Vec3::X, Vec3::new(0.1, 1.0, 0.0), Vec3::Z);
    for m in [nan, scaled, mirror, sheared] {
        assert_eq!(set.with_rotation(m).err(), Some(Error::InvalidRotation), "{m:?}");
        assert_eq!(m.validate_rotation(), Err(Error::InvalidRotation), "{m:?}");
        let mut probe = Probe::<16>::new();
        probe.update(&[1.0; 16]).unwrap();
        let before = format!("{probe:?}");
        assert_eq!(probe.set_rotation(m), Err(Error::InvalidRotation), "{m:?}");
        assert_eq!(format!("{probe:?}"), before);
    }
    // Rotations from the crate, and ones within the documented tolerance, are accepted.
    let mut seq = sphere_quadrature::RotationSequence::new(7);
    for _ in 0..100 {
        let r = seq.next_rotation();
        assert_eq!(r.validate_rotation(), Ok(()));
        assert!(set.with_rotation(r).is_ok());
    }
    let t = sphere_quadrature::rotation::ROTATION_TOLERANCE;
    let near = Mat3::from_rows(Vec3::X * (1.0 + 0.4 * t), Vec3::Y, Vec3::Z);
    assert_eq!(near.validate_rotation(), Ok(()));
    let off = Mat3::from_rows(Vec3::X * (1.0 + 2.0 * t), Vec3::Y, Vec3::Z);
    assert_eq!(off.validate_rotation(), Err(Error::InvalidRotation));
    // A set rotated within the tolerance still finds the nearest of its own points.
    let rotated = set.with_rotation(near).unwrap();
    for j in (0..1000).step_by(37) {
        let p = rotated.point(j).unwrap();
        assert_eq!(rotated.nearest_index(p), Ok(j));
    }
}

#[test]
fn defect_09_table_with_non_finite_outputs_is_rejected() {
    // σ′ = 10²⁰ baked every output as NaN.
    let e = gen::probe::parse("# user table\nprobe = 48 1e20 2 8 32\n").unwrap_err();
    assert!(e.starts_with("line 2: ") && e.contains("sigma"), "{e}");
    let e = gen::probe::parse("probe = 48 1e-9 2 8 32\n").unwrap_err();
    assert!(e.starts_with("line 1: ") && e.contains("sigma"), "{e}");
    let e = gen::probe::parse("probe = 48 0.05 2 8 1e-30\n").unwrap_err();
    assert!(e.starts_with("line 1: "), "{e}");
    // The bake checks that every baked value is finite, and names the line.
    let specs = gen::probe::parse("\n\nprobe = 8 0.05 2\n").unwrap();
    assert_eq!(specs[0].line, 3);
    let baked = gen::probe::bake_all(&specs).unwrap();
    assert!(baked[0][0].check_finite().is_ok());
    let mut broken = gen::probe::bake_all(&specs).unwrap();
    broken[0][0].vbar = f64::NAN;
    let e = broken[0][0].check_finite().unwrap_err();
    assert!(e.contains("vbar"), "{e}");
    // The renderer tables (user-replaceable too) are checked the same way: σ′ = 10²⁰ gave NaN
    // weights.
    let specs = gen::bmc::parse("set = 16 0.5 1e20").unwrap();
    let e = gen::bmc::bake_all(&specs).unwrap_err();
    assert!(e.contains("not finite"), "{e}");
    // The one-line error of the build script: file, line, problem.
    let msg = gen::error_line("lighting/probe.txt", &e);
    assert!(msg.starts_with("error: lighting/probe.txt: ") && !msg.contains('\n'), "{msg}");
}

#[test]
fn defect_10_unbaked_size_note_lists_the_baked_sizes() {
    let specs = gen::probe::parse("probe = 24 0.05 2\nprobe = 48 0.05 2 8\n").unwrap();
    let src = gen::probe::render_size_trait(&specs);
    assert!(src.contains("the baked sizes are N = 24, 48"), "{src}");
    assert!(!src.contains("16, 32"), "{src}");
    // The crate's own table: the default sizes.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tables/probe.txt");
    let specs = gen::probe::parse(&std::fs::read_to_string(path).unwrap()).unwrap();
    let src = gen::probe::render_size_trait(&specs);
    assert!(src.contains("the baked sizes are N = 16, 32, 64, 128, 256"), "{src}");
}

/// Found by the `sg` fuzz target after defect 4's fix: SG(λ = f32::MAX) × SG(λ = 0) has the
/// first lobe's sharpness, f32::MAX, but the rounding of |μ₁| = 1 + O(ε) took it to +∞.
#[test]
fn defect_14_product_with_the_largest_sharpness_stays_finite() {
    // Many axes: for some, the f32 unit axis has length 1 + ε.
    let g2 = SphericalGaussian::new(Vec3::X, 0.0, 1.0).unwrap();
    for k in 0..1000 {
        let t = k as f32 * 0.01;
        let axis = Vec3::new(t.cos() * (0.3 * t).sin(), t.sin() * (0.3 * t).sin(), (0.3 * t).cos());
        let g1 = SphericalGaussian::new(axis, f32::MAX, 1.0).unwrap();
        for p in [g1.product(&g2), g2.product(&g1)] {
            assert!(p.sharpness.is_finite() && p.sharpness >= f32::MAX * (1.0 - 1e-6), "{p:?}");
            assert!((p.axis.length() - 1.0).abs() < 1e-6, "{p:?}");
        }
    }
    // Two aligned lobes of sharpness 3·10³⁸: the true sharpness, 6·10³⁸, is beyond f32: +∞.
    let g3 = SphericalGaussian::new(Vec3::Z, 3e38, 1.0).unwrap();
    assert_eq!(g3.product(&g3).sharpness, f32::INFINITY);
}

/// Found by the `sg` fuzz target: SG(λ = f32::MAX) × SG(λ = 2.3·10⁻⁷) of nearly opposite
/// axes. Taken in the order (sharp, broad) the amplitude's exponent −λ₁λ₂|d|²/(|u| + λ₁ + λ₂)
/// was right, but in the order (broad, sharp) it went through λ₂/λ₁ = 7·10⁻⁴⁶, which f32
/// rounds to 0, so that the exponent was lost: the two orders differed by 5·10⁻⁷ relative.
/// Both orders now give the same bits, and the amplitude equals the f64 formula to rounding.
#[test]
fn product_of_the_sharpest_and_a_very_broad_lobe_is_symmetric_and_exact() {
    let sharp = SphericalGaussian::new(-Vec3::X, f32::MAX, 122.414_06).unwrap();
    let axis = Vec3::new(1.0, 0.0, -3.189_386e-5);
    for broad_sharpness in [2.332_762_1e-7f32, 1e-12, 3e-9, 1e-6] {
        let broad = SphericalGaussian::new(axis, broad_sharpness, 4.431_269e33).unwrap();
        let (p, q) = (sharp.product(&broad), broad.product(&sharp));
        assert_eq!(p.amplitude.to_bits(), q.amplitude.to_bits(), "{p:?} {q:?}");
        assert_eq!(p.sharpness.to_bits(), q.sharpness.to_bits());
        // a₁a₂·exp(−λ₁λ₂|d|²/(|u| + λ₁ + λ₂)) in f64, from the lobes' stored f32 values.
        let (l1, l2) = (f64::from(sharp.sharpness), f64::from(broad.sharpness));
        let (m1, m2) = (sharp.axis, broad.axis);
        let u: [f64; 3] = [
            l1 * f64::from(m1.x) + l2 * f64::from(m2.x),
            l1 * f64::from(m1.y) + l2 * f64::from(m2.y),
            l1 * f64::from(m1.z) + l2 * f64::from(m2.z),
        ];
        let u_len = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
        let d2 = [m1.x - m2.x, m1.y - m2.y, m1.z - m2.z]
            .iter()
            .map(|&c| f64::from(c) * f64::from(c))
            .sum::<f64>();
        let want = f64::from(sharp.amplitude)
            * f64::from(broad.amplitude)
            * (-l1 * l2 * d2 / (u_len + l1 + l2)).exp();
        let rel = (f64::from(p.amplitude) - want).abs() / want;
        assert!(
            rel < 3e-7,
            "λ₂ = {broad_sharpness}: amplitude {} vs {want:e} ({rel:e})",
            p.amplitude
        );
    }
}

/// Defect 10 for the renderer and fixed-point sizes (found after the probe's fix): their
/// compile errors said "N = 16, 32, 64, 80, 128, 256" whatever a user table
/// (`SPHERE_QUADRATURE_BMC_TABLE`) baked. `.ci/unbaked-size.sh` compiles the real error.
#[test]
fn defect_10_renderer_and_fixed_notes_list_the_baked_sizes() {
    let specs = gen::bmc::parse("set = 24 0.9 0.1 cosine\nset = 48 0.9 0.1 cosine\n").unwrap();
    let sets = gen::bmc::bake_all(&specs).unwrap();
    let src = gen::bmc::render_size_diagnostics(&sets);
    assert_eq!(src.matches("the baked sizes are N = 24, 48 (").count(), 2, "{src}");
    assert!(!src.contains("16, 32"), "{src}");
    // The crate's own table: the shipped sizes, for both traits.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tables/bmc.txt");
    let specs = gen::bmc::parse(&std::fs::read_to_string(path).unwrap()).unwrap();
    let sets = gen::bmc::bake_all(&specs).unwrap();
    let src = gen::bmc::render_size_diagnostics(&sets);
    let sizes: Vec<String> =
        sphere_quadrature::bmc::BAKED_SIZES.iter().map(usize::to_string).collect();
    let shipped = format!("N = {}", sizes.join(", "));
    assert_eq!(src.matches(&format!("the baked sizes are {shipped} (")).count(), 2, "{src}");
}

/// Found by the `metrics` fuzz target: `uniform_circle_coefficient` formed `θ = n·a/(2K)` in
/// f64 and reduced it by `round(θ/π)·π`, which loses every digit once `|θ|` passes about 2⁵⁰ and
/// gives NaN once `n·a` overflows f64 (`n = 2⁴⁰`, `a = 10³⁰⁰`). The phase is now reduced
/// exactly; the references below are products of f64 cosines, whose arguments `libm` reduces
/// exactly: `sin(2ᵏθ)/(2ᵏ sin θ) = Π_{i<k} cos(2ⁱθ)`.
#[test]
fn defect_11_circle_coefficient_of_huge_phases() {
    let cos_product = |theta: f64, k: u32| -> f64 {
        (0..k).map(|i| (theta * 2f64.powi(i as i32)).cos()).product()
    };
    // K = 2: c = cos θ, θ = n·a/4 = 10³⁰⁰ (n = 4) and 2⁻⁴⁰·… (n = 2⁴², a = 10³⁰⁰·2⁻⁴⁰).
    for (n, a) in [(4i64, 1e300), (1 << 42, 1e300 * 2f64.powi(-40)), (-4, 1e300), (4, -1e300)] {
        let c = metrics::uniform_circle_coefficient(n, 2, a).unwrap();
        let want = 1e300f64.cos();
        assert!((c - want).abs() <= 1e-14, "n = {n}, a = {a:e}: {c} against {want}");
    }
    // K = 2⁶¹, n = 2⁶², a = 10²⁹⁰: θ = 10²⁹⁰, but n·a/2 = 2.3·10³⁰⁸ is beyond f64.
    let c = metrics::uniform_circle_coefficient(1 << 62, 1 << 61, 1e290).unwrap();
    let want = cos_product(1e290, 61);
    assert!((c - want).abs() <= 1e-12 * want.abs() + 1e-300, "{c:e} against {want:e}");
    // The fuzz target's input, and the largest phases: finite, in [−1, 1]; K = 1 is exactly 1.
    for (n, k, a) in [
        (1i64 << 40, 3usize, 1e300),
        (i64::MIN, 3, f64::MAX),
        (i64::MAX, usize::MAX, -f64::MAX),
        (i64::MAX, 65535, 1e-300),
        (1 << 62, 256, 1.7e308),
        (1 << 40, 1, 1e300),
    ] {
        let c = metrics::uniform_circle_coefficient(n, k, a).unwrap();
        assert!(c.is_finite() && c.abs() <= 1.0 + 1e-15, "({n}, {k}, {a:e}): {c}");
        if k == 1 {
            assert_eq!(c, 1.0);
        }
    }
    // Across the switch to the exact reduction (|n·a/2| = 2²⁰) the closed form still matches
    // the sum over the nodes (whose own phases n·xₖ lose about |n·xₖ|·10⁻¹⁶).
    for (n, k, a) in [(1_000_003i64, 7usize, 2.1), (3_000_001, 64, 0.77), (1 << 20, 5, 2.0)] {
        let mut xs = vec![0.0; k];
        metrics::uniform_circle_nodes(a, &mut xs).unwrap();
        let (re, _) = metrics::circle_coefficient(&xs, n).unwrap();
        let c = metrics::uniform_circle_coefficient(n, k, a).unwrap();
        assert!((c - re).abs() <= 1e-9, "({n}, {k}, {a}): {c} against the sum {re}");
    }
}

/// Found by the `sg` fuzz target: the product's amplitude `a₁a₂·exp(x)` was formed in f32, so
/// `a₁a₂` beyond f32 gave ∞ (or ∞·0 = NaN) where the true amplitude is finite or 0, and a large
/// `a₁a₂` times an exponential below the normal range lost its digits or became 0.
#[test]
fn defect_12_product_amplitude_beyond_f32_in_between() {
    let sg = |axis: Vec3, l: f32, a: f32| SphericalGaussian::new(axis, l, a).unwrap();
    // Opposite lobes: u = 0, x = −λ₁λ₂·4/(λ₁ + λ₂) = −2λ exactly.
    for (l, a, want) in [
        (500.0f32, 1e20f32, 0.0f64),            // 10⁴⁰·e⁻¹⁰⁰⁰
        (50.0, 1e15, 1e30 * (-100.0f64).exp()), // e⁻¹⁰⁰ is subnormal in f32
        (60.0, 1e15, 1e30 * (-120.0f64).exp()), // e⁻¹²⁰ is 0 in f32
        (10.0, 1e20, 1e40 * (-20.0f64).exp()),  // 2·10³¹: a₁a₂ = ∞ in f32
        (10.0, -1e20, -1e40 * (-20.0f64).exp()),
    ] {
        let p = sg(Vec3::X, l, a).product(&sg(-Vec3::X, l, a.abs()));
        let got = f64::from(p.amplitude);
        assert!(
            (got - want).abs() <= 1e-6 * want.abs(),
            "λ = {l}, a = {a:e}: {} against {want:e}",
            p.amplitude
        );
    }
    // Not opposite: |u| = λ√2, |μ₁ − μ₂|² = 2, x = −2λ²/(λ√2 + 2λ).
    let (p, l) = (sg(Vec3::Z, 10.0, 1e20).product(&sg(Vec3::X, 10.0, 1e20)), 10.0f64);
    let want = 1e40 * (-2.0 * l * l / (l * 2f64.sqrt() + 2.0 * l)).exp();
    assert!(rel(p.amplitude, want as f32) < 1e-5, "{} against {want:e}", p.amplitude);
    // Beyond f32 it is +∞ (aligned lobes: e⁰ = 1).
    assert_eq!(sg(Vec3::Z, 3.0, 1e20).product(&sg(Vec3::Z, 5.0, 1e20)).amplitude, f32::INFINITY);
    assert_eq!(
        sg(Vec3::Z, 3.0, -1e20).product(&sg(Vec3::Z, 5.0, 1e20)).amplitude,
        f32::NEG_INFINITY
    );
    // The ordinary range is unchanged, and the inner product is no longer NaN.
    let q = sg(Vec3::Z, 3.0, 2.0).product(&sg(Vec3::X, 5.0, 0.5));
    let want = (-15.0f64 * 2.0 / (34f64.sqrt() + 8.0)).exp();
    assert!(rel(q.amplitude, want as f32) < 1e-6, "{q:?}");
    let ip = sg(Vec3::X, 500.0, 1e20).inner_product(&sg(-Vec3::X, 500.0, 1e20));
    assert_eq!(ip, 0.0);
}

/// Found by the `sg` fuzz target: nearly opposite lobes of equal sharpness cancel in
/// `u = λ₁μ₁ + λ₂μ₂`; where `|u|²` is below the normal range the fuzz target saw an axis of
/// length 0.99981 (before `Vec3::try_normalize` learned to scale) and the sharpness `|u|` is
/// still taken from the subnormal `|u|²`: 6.0011·10⁻²² for 6·10⁻²², 0 for 10⁻²⁰·….
#[test]
fn defect_13_product_of_nearly_opposite_lobes() {
    let sg = |axis: Vec3, l: f32| SphericalGaussian::new(axis, l, 1.0).unwrap();
    // (μ₁, μ₂, λ) and the exact u = λ(μ₁ + μ₂) (the axes are unit as given: 1 + t² = 1 in f32).
    for (m1, m2, l, u) in [
        (Vec3::new(0.0, -1.0, 6e-22), Vec3::Y, 1.0f32, Vec3::new(0.0, 0.0, 6e-22)),
        (Vec3::new(3e-21, -1.0, 4e-21), Vec3::Y, 2.0, Vec3::new(6e-21, 0.0, 8e-21)),
        (
            Vec3::new(3e-21, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 4e-21),
            1e10,
            Vec3::new(3e-11, 0.0, 4e-11),
        ),
        (Vec3::new(-1.0, 1e-44, 0.0), Vec3::new(1.0, 0.0, 0.0), 1.0, Vec3::new(0.0, 1e-44, 0.0)),
    ] {
        let (g1, g2) = (sg(m1, l), sg(m2, l));
        assert_eq!(g1.axis, m1);
        assert_eq!(g2.axis, m2);
        let ul = (f64::from(u.x).powi(2) + f64::from(u.y).powi(2) + f64::from(u.z).powi(2)).sqrt();
        for p in [g1.product(&g2), g2.product(&g1)] {
            assert!((p.axis.length() - 1.0).abs() < 1e-6, "{p:?}");
            let want = Vec3::new(
                (f64::from(u.x) / ul) as f32,
                (f64::from(u.y) / ul) as f32,
                (f64::from(u.z) / ul) as f32,
            );
            assert!(close(p.axis, want, 1e-6), "{p:?} against {want:?}");
            assert!(rel(p.sharpness, ul as f32) < 1e-6, "{p:?}: sharpness against {ul:e}");
            // exp(−λ²·|μ₁ − μ₂|²/(|u| + 2λ)) with |μ₁ − μ₂|² = 4: e^(−2λ) (micromath's exp is
            // good to about 10⁻³).
            let want = (-2.0 * f64::from(l)).exp() as f32;
            let tol = if cfg!(feature = "micromath") { 5e-3 } else { 1e-6 };
            assert!(rel(p.amplitude, want) < tol || want == 0.0 && p.amplitude == 0.0, "{p:?}");
        }
    }
}

/// Found by the `sg` fuzz target after defect 12's fix: `inner_product` is the product's
/// integral in f32, so a product beyond f32 (`a₁a₂` = ∞, or `λₘ` = ∞ with `F(∞) = 0`) gave ∞
/// or ∞·0 = NaN where `∫G₁G₂` is well within f32 (two lobes of sharpness f32::MAX and
/// 3.3·10³⁵, amplitudes 3.3·10³⁵ and 5.2·10³⁴: NaN, want 3.1·10³¹).
#[test]
fn defect_15_inner_product_of_products_beyond_f32() {
    let sg = |axis: Vec3, l: f32, a: f32| SphericalGaussian::new(axis, l, a).unwrap();
    // ∫G₁G₂ for aligned lobes: a₁a₂·F(λ₁ + λ₂), F(λ) = 2π(1 − e^(−2λ))/λ.
    let full = |l: f64| 2.0 * core::f64::consts::PI * -(-2.0 * l).exp_m1() / l;
    for (l1, a1, l2, a2) in [
        (f32::MAX, 1e30f32, 1e36f32, 1e30f32), // λₘ = ∞ in f32, a₁a₂ = ∞: NaN before
        (1e3, 1e20, 1e3, 1e20),                // a₁a₂ = ∞, F = π/1000: ∞ before
        (f32::MAX, 3.2513958e35, 3.2513958e35, 5.1747567e34), // the fuzz target's input
        (f32::MAX, -1e30, 1e36, 1e30),
    ] {
        let (g1, g2) = (sg(Vec3::X, l1, a1), sg(Vec3::X, l2, a2));
        let want = f64::from(a1) * f64::from(a2) * full(f64::from(l1) + f64::from(l2));
        for ip in [g1.inner_product(&g2), g2.inner_product(&g1)] {
            assert!(ip.is_finite() && rel(ip, want as f32) < 1e-6, "{ip:e} against {want:e}");
        }
    }
    // Beyond f32 it is ±∞; the ordinary range is unchanged.
    let g = sg(Vec3::Z, 1.0, 1e20);
    assert_eq!(g.inner_product(&g), f32::INFINITY);
    assert_eq!(g.inner_product(&sg(Vec3::Z, 1.0, -1e20)), f32::NEG_INFINITY);
    let (g1, g2) = (sg(Vec3::Z, 3.0, 2.0), sg(Vec3::X, 5.0, 0.5));
    assert_eq!(g1.inner_product(&g2), g1.product(&g2).integral());
}
