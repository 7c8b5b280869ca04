//! Spherical harmonics of degree ≤ 2 (`sphere_quadrature::sh`) and the probe's SH export
//! (issue #14, item 1) against independent f64 computations: the reference crate's real
//! spherical harmonics, quadrature for every integral, LU solves for the probe's model, and
//! the engines' published evaluation formulas, written out below from the cited sources.

use reference::quad::gauss_legendre_on;
use reference::rng::Rng;
use reference::sh::{legendre, real_sh};
use sphere_quadrature::bmc::Size;
use sphere_quadrature::footprint::{CosinePower, Footprint, Gaussian, Kind, Point};
use sphere_quadrature::probe::{Probe, ProbeTables, Selection};
use sphere_quadrature::sh::{ShL2, Y_UP_FROM_Z_UP};
use sphere_quadrature::{Error, Mat3, Vec3};
use std::f64::consts::PI;

fn vec32(d: [f64; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

fn vec64(d: Vec3) -> [f64; 3] {
    [d.x, d.y, d.z].map(f64::from)
}

/// `(l, m)` of index `k = l(l + 1) + m`.
fn lm(k: usize) -> (usize, i64) {
    let l = if k == 0 {
        0
    } else if k < 4 {
        1
    } else {
        2
    };
    (l, k as i64 - (l * (l + 1)) as i64)
}

/// `Y_lm(d)` for the 9 indices, from the reference crate.
fn sh9(d: [f64; 3]) -> [f64; 9] {
    let d = reference::vec::normalize(d);
    std::array::from_fn(|k| {
        let (l, m) = lm(k);
        real_sh(l, m, d)
    })
}

/// Random coefficients in [−1, 1] (the constant in [1, 2]), f32.
fn random_sh(rng: &mut Rng) -> [f32; 9] {
    std::array::from_fn(|k| {
        let u = 2.0 * rng.next_f64() - 1.0;
        (if k == 0 { 1.5 + 0.5 * u } else { u }) as f32
    })
}

fn f64s(c: &[f32; 9]) -> [f64; 9] {
    c.map(f64::from)
}

/// `Σ c_k·Y_k(d)` in f64.
fn expansion(c: &[f64; 9], d: [f64; 3]) -> f64 {
    c.iter().zip(sh9(d)).map(|(a, b)| a * b).sum()
}

/// `∫ f(x)·max(0, n·x) dx` by quadrature in a frame about `n`: Gauss–Legendre in `t = n·x`
/// on [0, 1] and the trapezoid rule in the azimuth, exact for the polynomials of degree ≤ 3
/// that `f·t` is for an expansion of degree ≤ 2.
fn irradiance_by_quadrature(f: impl Fn([f64; 3]) -> f64, n: [f64; 3]) -> f64 {
    let (u, v) = reference::vec::frame(n);
    let (ts, ws) = gauss_legendre_on(8, 0.0, 1.0);
    let phis = 16;
    let mut sum = 0.0;
    for (&t, &w) in ts.iter().zip(&ws) {
        let s = (1.0 - t * t).sqrt();
        for j in 0..phis {
            let phi = 2.0 * PI * j as f64 / phis as f64;
            let x = reference::vec::from_frame(u, v, n, t, s, phi);
            sum += w * 2.0 * PI / phis as f64 * t * f(x);
        }
    }
    sum
}

/// `∫ g(x)·Y_k(x) dx` for the 9 indices, exact for `g` of degree ≤ 2: Gauss–Legendre in `z`
/// (6 nodes) and the trapezoid rule in `φ` (16 points).
fn project(g: impl Fn([f64; 3]) -> f64) -> [f64; 9] {
    let (zs, ws) = gauss_legendre_on(6, -1.0, 1.0);
    let phis = 16;
    let mut c = [0.0; 9];
    for (&z, &w) in zs.iter().zip(&ws) {
        let s = (1.0 - z * z).sqrt();
        for j in 0..phis {
            let phi = 2.0 * PI * j as f64 / phis as f64;
            let x = [s * phi.cos(), s * phi.sin(), z];
            let gx = g(x) * w * 2.0 * PI / phis as f64;
            for (ck, y) in c.iter_mut().zip(sh9(x)) {
                *ck += gx * y;
            }
        }
    }
    c
}

/// The largest `|got − want|` over the 9 coefficients, relative to `Σ|want|`.
fn coefficient_error(got: &[f32; 9], want: &[f64; 9]) -> f64 {
    let norm: f64 = want.iter().map(|w| w.abs()).sum();
    got.iter().zip(want).map(|(g, w)| (f64::from(*g) - w).abs()).fold(0.0, f64::max) / norm
}

#[test]
fn basis_and_radiance_match_the_reference_harmonics() {
    let mut rng = Rng::new(0x5401);
    let mut worst = 0.0f64;
    let mut dirs: Vec<[f64; 3]> = (0..2000).map(|_| rng.uniform_sphere()).collect();
    dirs.extend([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]);
    for (i, &d) in dirs.iter().enumerate() {
        // Not unit: the basis normalises (both branches of the normalisation).
        let scale = [1.0, 1.0 + 1e-5, 3.7, 1e-12, 1e15][i % 5];
        let got = ShL2::<f32>::basis(vec32(reference::vec::scale(d, scale))).unwrap();
        for (g, w) in got.iter().zip(sh9(d)) {
            worst = worst.max((f64::from(*g) - w).abs());
        }
        let c = random_sh(&mut rng);
        let r = ShL2::new(c).radiance(vec32(reference::vec::scale(d, scale))).unwrap();
        let want = expansion(&f64s(&c), d);
        let norm: f64 = c.iter().map(|v| f64::from(v.abs())).sum();
        worst = worst.max((f64::from(r) - want).abs() / norm);
    }
    println!("basis and radiance: worst error {worst:.2e}");
    // A few f32 ulps of the largest basis value (1.09).
    assert!(worst < 5e-7, "{worst:e}");
}

#[test]
fn irradiance_is_the_cosine_integral_of_the_expansion() {
    let mut rng = Rng::new(0x5402);
    let mut worst = 0.0f64;
    for _ in 0..500 {
        let c = random_sh(&mut rng);
        let c64 = f64s(&c);
        let n = rng.uniform_sphere();
        let want = irradiance_by_quadrature(|x| expansion(&c64, x), n);
        let got = ShL2::new(c).irradiance(vec32(n)).unwrap();
        let norm: f64 = c64.iter().map(|v| v.abs()).sum();
        worst = worst.max((f64::from(got) - want).abs() / norm);
        // RGB: channel by channel the same.
        let rgb = ShL2::new(c.map(|v| [v, -2.0 * v, 0.5 * v])).irradiance(vec32(n)).unwrap();
        assert_eq!(rgb[0], got);
        assert!((rgb[1] + 2.0 * got).abs() <= 1e-6 * norm as f32 * 2.0);
    }
    println!("irradiance: worst error {worst:.2e} of Σ|c|");
    assert!(worst < 5e-7, "{worst:e}");
    // A constant radiance 1 has c₀₀ = √(4π) and irradiance π everywhere.
    let one = ShL2::new([(4.0 * std::f32::consts::PI).sqrt(), 0., 0., 0., 0., 0., 0., 0., 0.]);
    for n in [Vec3::Z, Vec3::new(0.3, -2.0, 0.1)] {
        let e = one.irradiance(n).unwrap();
        assert!((e - std::f32::consts::PI).abs() < 4e-7, "{e}");
        assert!((one.radiance(n).unwrap() - 1.0).abs() < 2e-7);
    }
}

#[test]
fn bad_directions_are_refused() {
    let sh = ShL2::new([1.0f32; 9]);
    for n in [Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0), Vec3::new(0.0, f32::INFINITY, 0.0)] {
        assert_eq!(sh.irradiance(n), Err(Error::InvalidDirection), "{n:?}");
        assert_eq!(sh.radiance(n), Err(Error::InvalidDirection), "{n:?}");
        assert_eq!(ShL2::<f32>::basis(n), Err(Error::InvalidDirection), "{n:?}");
        assert_eq!(
            ShL2::from_samples(&[Vec3::Z, n], &[1.0f32, 2.0], 1.0),
            Err(Error::InvalidDirection)
        );
    }
    // Any finite nonzero length normalises (crate docs, "Directions"), on the fast path
    // (|n|² in [10⁻³⁰, f32::MAX]) and off it.
    let unit = sh.irradiance(Vec3::X).unwrap();
    for s in [1e19f32, 3e19, 3e38, 1e-15, 1e-16, 1e-40] {
        let got = sh.irradiance(Vec3::new(s, 0.0, 0.0)).unwrap();
        assert!((got - unit).abs() <= 2e-7 * unit.abs(), "{s:e}: {got} {unit}");
    }
    let small = sh.irradiance(Vec3::new(0.0, 0.0, 1e-15)).unwrap();
    assert!((small - sh.irradiance(Vec3::Z).unwrap()).abs() <= 1e-6);
    assert_eq!(ShL2::from_samples(&[Vec3::Z], &[1.0f32, 2.0], 1.0), Err(Error::LengthMismatch));
    assert_eq!(ShL2::<f32>::from_samples(&[], &[], 1.0), Ok(ShL2::ZERO));
}

/// `L₀ + L₁(v) + L₂(v)` with `L_l` the homogeneous degree-`l` polynomial of band `l` (for a
/// unit `v` the expansion itself): `3z² − 1` is `2z² − x² − y²` on the sphere.
fn homogeneous(c: &[f64; 9], v: [f64; 3]) -> f64 {
    let [x, y, z] = v;
    let k1 = 0.5 * (3.0 / PI).sqrt();
    let k2 = 0.5 * (15.0 / PI).sqrt();
    let k20 = 0.25 * (5.0 / PI).sqrt();
    let k22 = 0.25 * (15.0 / PI).sqrt();
    0.5 / PI.sqrt() * c[0]
        + k1 * (c[1] * y + c[2] * z + c[3] * x)
        + k2 * (c[4] * x * y + c[5] * y * z + c[7] * x * z)
        + k20 * c[6] * (2.0 * z * z - x * x - y * y)
        + k22 * c[8] * (x * x - y * y)
}

fn transpose_apply(m: [[f64; 3]; 3], x: [f64; 3]) -> [f64; 3] {
    reference::vec::mat_mul_vec(reference::vec::transpose(m), x)
}

fn mat(m: [[f64; 3]; 3]) -> Mat3 {
    Mat3::from_rows(vec32(m[0]), vec32(m[1]), vec32(m[2]))
}

/// `rotated(m)` against the projection of `x ↦ L(mᵀx)` by exact quadrature: random rotations,
/// reflections (among them the swap to Unity's axes) and, for the documented general case,
/// matrices that are not orthogonal.
#[test]
fn rotation_matches_rotating_the_function() {
    let mut rng = Rng::new(0x5403);
    let mut worst = [0.0f64; 3];
    for case in 0..300 {
        let c = random_sh(&mut rng);
        let c64 = f64s(&c);
        let r = rng.uniform_rotation();
        let (m, kind) = match case % 3 {
            0 => (r, 0),
            // A reflection: the rotation followed by x ↦ −x.
            1 => ([[-r[0][0], -r[0][1], -r[0][2]], r[1], r[2]], 1),
            _ => {
                let mut g = r;
                for row in &mut g {
                    for v in row.iter_mut() {
                        *v += 0.5 * (rng.next_f64() - 0.5);
                    }
                }
                (g, 2)
            }
        };
        // The matrix as f32, and the reference with exactly that matrix.
        let m32 = mat(m);
        let m64 = m32.rows.map(vec64);
        let want = project(|x| homogeneous(&c64, transpose_apply(m64, x)));
        let got = ShL2::new(c).rotated(&m32).coefficients;
        worst[kind] = worst[kind].max(coefficient_error(&got, &want));
    }
    println!(
        "rotated: worst error {:.2e} (rotations), {:.2e} (reflections), {:.2e} (general)",
        worst[0], worst[1], worst[2]
    );
    assert!(worst.iter().all(|&w| w < 1e-6), "{worst:?}");

    // Unity's axes (x, y, z) ↦ (x, z, y): the l = 1 coefficients swap places.
    let c = random_sh(&mut rng);
    let swap = Mat3::from_rows(Vec3::X, Vec3::Z, Vec3::Y);
    let s = ShL2::new(c).rotated(&swap).coefficients;
    assert!((s[1] - c[2]).abs() < 1e-6 && (s[2] - c[1]).abs() < 1e-6 && (s[3] - c[3]).abs() < 1e-6);
    // Composition, the identity, and the per-degree energy of a rotation.
    let (a, b) = (rng.uniform_rotation(), rng.uniform_rotation());
    let sh = ShL2::new(c);
    let two = sh.rotated(&mat(a)).rotated(&mat(b)).coefficients;
    let once = sh.rotated(&(mat(b) * mat(a))).coefficients;
    assert!(coefficient_error(&two, &f64s(&once)) < 1e-6);
    assert!(coefficient_error(&sh.rotated(&Mat3::IDENTITY).coefficients, &f64s(&c)) < 2e-7);
    let energy = |v: &[f32; 9], ks: std::ops::Range<usize>| -> f64 {
        ks.map(|k| f64::from(v[k]).powi(2)).sum()
    };
    for band in [1..4, 4..9] {
        let (e0, e1) = (energy(&c, band.clone()), energy(&two, band));
        assert!((e0 - e1).abs() < 1e-6 * e0, "{e0} {e1}");
    }
    // NaN propagates.
    let nan = Mat3::from_rows(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y, Vec3::Z);
    assert!(sh.rotated(&nan).coefficients[3].is_nan());
}

#[test]
fn convolution_and_projection_of_samples() {
    let mut rng = Rng::new(0x5404);
    let c = random_sh(&mut rng);
    let g = [2.0, 0.5, -0.25];
    let got = ShL2::new(c).convolved(g).coefficients;
    for (k, (&a, &b)) in got.iter().zip(&c).enumerate() {
        assert_eq!(a, b * g[lm(k).0]);
    }
    // The irradiance is the radiance of the expansion convolved with Â = π, 2π/3, π/4.
    let pi = std::f32::consts::PI;
    let conv = ShL2::new(c).convolved([pi, 2.0 * pi / 3.0, pi / 4.0]);
    for _ in 0..50 {
        let n = vec32(rng.uniform_sphere());
        let (a, b) = (conv.radiance(n).unwrap(), ShL2::new(c).irradiance(n).unwrap());
        assert!((a - b).abs() < 2e-6 * c.iter().map(|v| v.abs()).sum::<f32>());
    }
    // from_samples: w·Σ Y(xⱼ)·Yⱼ, against f64.
    let dirs: Vec<[f64; 3]> = (0..100).map(|_| rng.uniform_sphere()).collect();
    let ys: Vec<f32> = (0..100).map(|_| rng.next_f64() as f32).collect();
    let w = 4.0 * PI / 100.0;
    let d32: Vec<Vec3> = dirs.iter().map(|&d| vec32(d)).collect();
    let got = ShL2::from_samples(&d32, &ys, w as f32).unwrap().coefficients;
    let mut want = [0.0f64; 9];
    for (d, &y) in d32.iter().zip(&ys) {
        for (wk, b) in want.iter_mut().zip(sh9(vec64(*d))) {
            *wk += w * f64::from(y) * b;
        }
    }
    assert!(coefficient_error(&got, &want) < 2e-6, "{:e}", coefficient_error(&got, &want));
}

// ---------------------------------------------------------------------------------------
// Engines. Each formula below is transcribed from the cited source.

/// three.js `SphericalHarmonics3.getAt` (src/math/SphericalHarmonics3.js).
fn three_get_at(c: &[f64; 9], n: [f64; 3]) -> f64 {
    let [x, y, z] = n;
    c[0] * 0.282095
        + c[1] * 0.488603 * y
        + c[2] * 0.488603 * z
        + c[3] * 0.488603 * x
        + c[4] * 1.092548 * (x * y)
        + c[5] * 1.092548 * (y * z)
        + c[6] * 0.315392 * (3.0 * z * z - 1.0)
        + c[7] * 1.092548 * (x * z)
        + c[8] * 0.546274 * (x * x - y * y)
}

/// three.js `SphericalHarmonics3.getIrradianceAt`, and the shader's `shGetIrradianceAt`
/// (src/renderers/shaders/ShaderChunk/lights_pars_begin.glsl.js), the same formula.
fn three_irradiance(c: &[f64; 9], n: [f64; 3]) -> f64 {
    let [x, y, z] = n;
    c[0] * 0.886227
        + c[1] * 2.0 * 0.511664 * y
        + c[2] * 2.0 * 0.511664 * z
        + c[3] * 2.0 * 0.511664 * x
        + c[4] * 2.0 * 0.429043 * x * y
        + c[5] * 2.0 * 0.429043 * y * z
        + c[6] * (0.743125 * z * z - 0.247708)
        + c[7] * 2.0 * 0.429043 * x * z
        + c[8] * 0.429043 * (x * x - y * y)
}

/// Filament's `Irradiance_SphericalHarmonics` (shaders/src/surface_light_indirect.fs), 3 bands.
fn filament_shader(sh: &[f64; 9], n: [f64; 3]) -> f64 {
    let [x, y, z] = n;
    (sh[0]
        + sh[1] * y
        + sh[2] * z
        + sh[3] * x
        + sh[4] * (y * x)
        + sh[5] * (y * z)
        + sh[6] * (3.0 * z * z - 1.0)
        + sh[7] * (z * x)
        + sh[8] * (x * x - y * y))
        .max(0.0)
}

/// `1/π·A_lm·Ĉ_l` of Filament's `IndirectLight::Builder::irradiance` table
/// (filament/include/filament/IndirectLight.h), the factors `Builder::radiance` applies
/// (filament/src/IndirectLight.cpp).
const FILAMENT_RADIANCE_TO_IRRADIANCE: [f64; 9] =
    [0.282095, -0.325735, 0.325735, -0.325735, 0.273137, -0.273137, 0.078848, -0.273137, 0.136569];

/// Unity's packing of a `SphericalHarmonicsL2` into the shader constants
/// (`SphericalHarmonicMath.PackCoefficients`, Unity-Technologies/Graphics,
/// com.unity.render-pipelines.high-definition/Runtime/Lighting/SphericalHarmonics.cs).
fn unity_pack(sh: &[[f32; 9]; 3]) -> [[f32; 4]; 7] {
    let mut packed = [[0.0f32; 4]; 7];
    for c in 0..3 {
        packed[c] = [sh[c][3], sh[c][1], sh[c][2], sh[c][0] - sh[c][6]];
    }
    for c in 0..3 {
        packed[3 + c] = [sh[c][4], sh[c][5], sh[c][6] * 3.0, sh[c][7]];
    }
    packed[6] = [sh[0][8], sh[1][8], sh[2][8], 1.0];
    packed
}

/// `ShadeSH9` in linear colour space = `SHEvalLinearL0L1 + SHEvalLinearL2` (UnityCG.cginc),
/// channel `c` of the result, for a unit normal with `w = 1`.
fn unity_shade_sh9(k: &[[f32; 4]; 7], n: [f64; 3], c: usize) -> f64 {
    let dot =
        |a: [f32; 4], b: [f64; 4]| a.iter().zip(b).map(|(&a, b)| f64::from(a) * b).sum::<f64>();
    let [x, y, z] = n;
    let normal = [x, y, z, 1.0];
    let l0l1 = dot(k[c], normal);
    // vB = normal.xyzz * normal.yzzx
    let vb = [x * y, y * z, z * z, z * x];
    let vc = x * x - y * y;
    l0l1 + dot(k[3 + c], vb) + f64::from(k[6][c]) * vc
}

/// A probe in the crate's z-up frame, handed to three.js (y-up) by `three_js_from_z_up`:
/// three.js's shader formula at the y-up image `(x, z, −y)` of a z-up normal `(x, y, z)` must
/// give `ShL2::irradiance` at that normal, and `getAt` the radiance, for light that is not
/// symmetric about any axis. With the coefficients handed over unrotated (what
/// `three_js_from_y_up` does, and the only export before the z-up one) the error is of the
/// order of the coefficients themselves.
#[test]
fn three_js_from_z_up_matches_three_js_at_the_rotated_normal() {
    let mut rng = Rng::new(0x7e5a);
    let (mut rotated_err, mut unrotated_err) = (0.0f64, 0.0f64);
    for _ in 0..500 {
        let c = random_sh(&mut rng);
        let sh = ShL2::new(c);
        let norm: f64 = c.iter().map(|v| f64::from(*v).abs()).sum();
        let n = rng.uniform_sphere();
        let y_up = [n[0], n[2], -n[1]];
        let e = f64::from(sh.irradiance(vec32(n)).unwrap());
        let l = f64::from(sh.radiance(vec32(n)).unwrap());
        let t = sh.three_js_from_z_up().map(f64::from);
        let via_rotated = sh.rotated(&Y_UP_FROM_Z_UP).three_js_from_y_up();
        for (a, b) in t.iter().zip(via_rotated) {
            rotated_err = rotated_err.max((a - f64::from(b)).abs() / norm);
        }
        rotated_err = rotated_err.max((three_irradiance(&t, y_up) - e).abs() / norm);
        rotated_err = rotated_err.max((three_get_at(&t, y_up) - l).abs() / norm);
        let raw = sh.three_js_from_y_up().map(f64::from);
        unrotated_err = unrotated_err.max((three_irradiance(&raw, y_up) - e).abs() / norm);
    }
    println!(
        "three.js from z-up (error of Σ|c|): {rotated_err:.2e}; unrotated {unrotated_err:.2e}"
    );
    // three.js's 6-digit constants, as in engine_conversions_match_the_engines_formulas.
    assert!(rotated_err < 3e-6, "three.js from z-up {rotated_err:e}");
    assert!(unrotated_err > 0.1, "the check cannot tell the frames apart: {unrotated_err:e}");
}

#[test]
fn engine_conversions_match_the_engines_formulas() {
    let mut rng = Rng::new(0x5405);
    // three.js's constants have 6 digits (0.511664 for 0.5116634, 1.3·10⁻⁶ relative); the
    // others are checked to f32 accuracy.
    let (mut three, mut filament, mut filament_rad, mut unity) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..500 {
        let rgb: [[f32; 3]; 9] = {
            let (a, b, c) = (random_sh(&mut rng), random_sh(&mut rng), random_sh(&mut rng));
            std::array::from_fn(|k| [a[k], b[k], c[k]])
        };
        let sh = ShL2::new(rgb);
        let n = rng.uniform_sphere();
        let e = sh.irradiance(vec32(n)).unwrap();
        let l = sh.radiance(vec32(n)).unwrap();
        let t = sh.three_js_from_y_up();
        let f = sh.filament_irradiance();
        let fr = sh.filament_radiance();
        let u = sh.unity();
        let packed = sh.unity_shader_constants();
        assert_eq!(packed, unity_pack(&u));
        for ch in 0..3 {
            let chan = |v: &[[f32; 3]; 9]| v.map(|x| f64::from(x[ch]));
            let norm: f64 = chan(&rgb).iter().map(|v| v.abs()).sum();
            let (e, l) = (f64::from(e[ch]), f64::from(l[ch]));
            let tc = chan(&t);
            three = three.max((three_irradiance(&tc, n) - e).abs() / norm);
            three = three.max((three_get_at(&tc, n) - l).abs() / norm);
            // Filament returns max(0, E/π).
            let fil = filament_shader(&chan(&f), n);
            filament = filament.max((fil - (e / PI).max(0.0)).abs() / norm);
            let from_radiance: [f64; 9] =
                std::array::from_fn(|k| chan(&fr)[k] * FILAMENT_RADIANCE_TO_IRRADIANCE[k]);
            let fil = filament_shader(&from_radiance, n);
            filament_rad = filament_rad.max((fil - (e / PI).max(0.0)).abs() / norm);
            // Unity: sh[c, i] as stored, ShadeSH9 = E/π.
            assert_eq!(u[ch].map(f64::from), chan(&f));
            unity = unity.max((unity_shade_sh9(&packed, n, ch) - e / PI).abs() / norm);
        }
    }
    println!(
        "engines (error of Σ|c|): three.js {three:.2e}, Filament {filament:.2e} (from radiance \
         {filament_rad:.2e}), Unity {unity:.2e}"
    );
    assert!(three < 3e-6, "three.js {three:e}");
    assert!(filament < 3e-7, "Filament {filament:e}");
    assert!(filament_rad < 2e-6, "Filament radiance {filament_rad:e}");
    assert!(unity < 3e-7, "Unity {unity:e}");
    // Filament's table of 1/π·A·Ĉ, to its 6 digits: our pre-scaling of a unit coefficient.
    for k in 0..9 {
        let mut c = [0.0f32; 9];
        c[k] = 1.0;
        let got = f64::from(ShL2::new(c).filament_irradiance()[k]);
        assert!((got - FILAMENT_RADIANCE_TO_IRRADIANCE[k].abs()).abs() < 1e-6, "{k}: {got}");
    }
    // A constant radiance L: three.js c₀ = √(4π)·L, Filament's and Unity's sh[0] = L (the
    // average irradiance over π, as IndirectLight.h notes).
    let l = 0.7f32;
    let sh = ShL2::new([
        [l * (4.0 * std::f32::consts::PI).sqrt(), 0.0, 0.0],
        [0.0; 3],
        [0.0; 3],
        [0.0; 3],
        [0.0; 3],
        [0.0; 3],
        [0.0; 3],
        [0.0; 3],
        [0.0; 3],
    ]);
    assert!((sh.unity()[0][0] - l).abs() < 2e-7, "{}", sh.unity()[0][0]);
}

// ---------------------------------------------------------------------------------------
// The probe's projection against an f64 reference of its model.

/// `2π∫₋₁¹ exp(λ(t − 1))·P_l(t) dt` for `l < len`, by 400-point Gauss–Legendre.
fn sg_coefficients(lambda: f64, len: usize) -> Vec<f64> {
    let (ts, ws) = gauss_legendre_on(400, -1.0, 1.0);
    (0..len)
        .map(|l| {
            2.0 * PI
                * ts.iter()
                    .zip(&ws)
                    .map(|(&t, &w)| w * (lambda * (t - 1.0)).exp() * legendre(l, t))
                    .sum::<f64>()
        })
        .collect()
}

/// `2π∫ f(t)·P_l(t) dt` of the normalised footprint, by quadrature.
fn footprint_gains(kind: Kind, len: usize) -> Vec<f64> {
    match kind {
        Kind::Point => vec![1.0; len],
        Kind::Gaussian { sharpness } => {
            let s = sg_coefficients(f64::from(sharpness), len);
            s.iter().map(|v| v / s[0]).collect()
        }
        Kind::CosinePower { exponent } => {
            let p = f64::from(exponent);
            let (ts, ws) = gauss_legendre_on(200, 0.0, 1.0);
            (0..len)
                .map(|l| {
                    (p + 1.0)
                        * ts.iter()
                            .zip(&ws)
                            .map(|(&t, &w)| w * t.powf(p) * legendre(l, t))
                            .sum::<f64>()
                })
                .collect()
        }
    }
}

/// The probe's model in f64: for degrees `l < L`, the Legendre coefficients of the
/// covariance of two samples (`K_l·g_l²`), of a sample with the radiance (`K_l·g_l`) and of
/// the radiance's prior (`K_l`), and the solved `α`, `β` for some samples.
struct Reference {
    xs: Vec<[f64; 3]>,
    q: Vec<f64>,
    cross: Vec<f64>,
    prior: Vec<f64>,
}

const DEGREES: usize = 160;

impl Reference {
    fn new(dirs: &[Vec3], kind: Kind, lambda: f64, sigma: f64) -> Self {
        let xs: Vec<[f64; 3]> = dirs.iter().map(|&d| vec64(d)).collect();
        let n = xs.len();
        let s = sg_coefficients(lambda, DEGREES);
        let g = footprint_gains(kind, DEGREES);
        // K_l: the squared exponential, or for a Gaussian footprint the SG of sharpness ν
        // deconvolved by the footprint (its sample–radiance covariance is the SG of ν).
        let (k, cross): (Vec<f64>, Vec<f64>) = match kind {
            Kind::Gaussian { .. } => (
                s.iter().zip(&g).map(|(a, b)| if *b > 0.0 { a / b } else { 0.0 }).collect(),
                s.clone(),
            ),
            _ => (s.clone(), s.iter().zip(&g).map(|(a, b)| a * b).collect()),
        };
        let cov: Vec<f64> = cross.iter().zip(&g).map(|(a, b)| a * b).collect();
        let mut q = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let t = reference::vec::dot(xs[i], xs[j]).clamp(-1.0, 1.0);
                let v = if kind == Kind::Point {
                    (lambda * (t - 1.0)).exp()
                } else {
                    (0..DEGREES)
                        .map(|l| cov[l] * (2 * l + 1) as f64 / (4.0 * PI) * legendre(l, t))
                        .sum()
                };
                q[i * n + j] = v + if i == j { sigma * sigma } else { 0.0 };
            }
        }
        Reference { xs, q, cross, prior: k }
    }

    /// `(α, β, Q⁻¹1)`.
    fn solve(&self, y: &[f64]) -> (Vec<f64>, f64, Vec<f64>) {
        let n = self.xs.len();
        let qi_y = reference::bmc::lu_solve(&self.q, n, y);
        let qi_1 = reference::bmc::lu_solve(&self.q, n, &vec![1.0; n]);
        let beta = qi_y.iter().sum::<f64>() / qi_1.iter().sum::<f64>();
        (qi_y.iter().zip(&qi_1).map(|(a, b)| a - beta * b).collect(), beta, qi_1)
    }

    fn coefficients(&self, y: &[f64]) -> [f64; 9] {
        let (alpha, beta, _) = self.solve(y);
        std::array::from_fn(|k| {
            let (l, _) = lm(k);
            let sum: f64 = self.xs.iter().zip(&alpha).map(|(&x, a)| a * sh9(x)[k]).sum();
            self.cross[l] * sum + if k == 0 { beta * (4.0 * PI).sqrt() } else { 0.0 }
        })
    }

    /// The posterior variances of the coefficients for σ̂_f² from `y`.
    fn variances(&self, y: &[f64]) -> [f64; 9] {
        let n = self.xs.len();
        let (alpha, _, qi_1) = self.solve(y);
        let r2: f64 = y.iter().zip(&alpha).map(|(a, b)| a * b).sum();
        let s1: f64 = qi_1.iter().sum();
        std::array::from_fn(|k| {
            let (l, _) = lm(k);
            let zeta: Vec<f64> = self.xs.iter().map(|&x| self.cross[l] * sh9(x)[k]).collect();
            let qz = reference::bmc::lu_solve(&self.q, n, &zeta);
            let zqz: f64 = zeta.iter().zip(&qz).map(|(a, b)| a * b).sum();
            let one_z: f64 = qz.iter().sum();
            let integral = if k == 0 { (4.0 * PI).sqrt() } else { 0.0 };
            r2 / (n as f64 - 1.0) * (self.prior[l] - zqz + (integral - one_z).powi(2) / s1)
        })
    }

    /// `E(n)` of the posterior mean minus that of its projection on degrees ≤ 2:
    /// `Σ_{l>2} Â_l·(2l + 1)/(4π)·k̂_l·Σᵢ αᵢ·P_l(xᵢ·n)`, `Â_l = 2π∫₀¹ t·P_l(t) dt` by quadrature.
    fn truncation(&self, y: &[f64], n: [f64; 3]) -> f64 {
        let (alpha, _, _) = self.solve(y);
        let (ts, ws) = gauss_legendre_on(200, 0.0, 1.0);
        (3..DEGREES)
            .map(|l| {
                let a_hat: f64 = 2.0
                    * PI
                    * ts.iter().zip(&ws).map(|(&t, &w)| w * t * legendre(l, t)).sum::<f64>();
                let sum: f64 = self
                    .xs
                    .iter()
                    .zip(&alpha)
                    .map(|(&x, a)| a * legendre(l, reference::vec::dot(x, n).clamp(-1.0, 1.0)))
                    .sum();
                a_hat * (2 * l + 1) as f64 / (4.0 * PI) * self.cross[l] * sum
            })
            .sum()
    }
}

fn field(rng: &mut Rng) -> Vec<reference::analytic::SgLight> {
    (0..3)
        .map(|_| reference::analytic::SgLight {
            axis: rng.uniform_sphere(),
            sharpness: 2.0 + 18.0 * rng.next_f64(),
            amplitude: 0.2 + 0.8 * rng.next_f64(),
        })
        .collect()
}

/// Every member of a probe of size `N` and footprint `F` on a smooth random field (the
/// samples are the field's values: what they measure does not matter for the algebra):
/// radiance_sh, its variances and the irradiance truncation against [`Reference`]. Returns
/// per member `(cond(Q), coefficient error, variance error, truncation error, |truncation|)`.
fn compare_probe<const N: usize, F: Footprint>(seed: u64) -> Vec<(f32, f64, f64, f64, f64)>
where
    Size<N>: ProbeTables<F>,
{
    let mut rng = Rng::new(seed);
    let mut probe = Probe::<N, f32, F>::new();
    probe.set_rotation(mat(rng.uniform_rotation())).unwrap();
    let lights = field(&mut rng);
    let y: [f32; N] = probe
        .directions()
        .map(|d| (0.3 + lights.iter().map(|l| l.value(vec64(d))).sum::<f64>()) as f32);
    let y64: Vec<f64> = y.iter().map(|&v| f64::from(v)).collect();
    let normals: Vec<[f64; 3]> = (0..16).map(|_| rng.uniform_sphere()).collect();
    let mut out = Vec::new();
    for (k, m) in Probe::<N, f32, F>::family().enumerate() {
        probe.update_with(&y, Selection::Member(k)).unwrap();
        let r =
            Reference::new(probe.directions(), F::KIND, f64::from(m.lambda), f64::from(m.sigma));
        let want = r.coefficients(&y64);
        let got = probe.radiance_sh();
        let c_err = coefficient_error(&got.coefficients, &want);
        let cal = f64::from(m.calibration[0]);
        let want_v = r.variances(&y64).map(|v| v * cal);
        let got_v = probe.radiance_sh_variance();
        let v_err = got_v
            .iter()
            .zip(&want_v)
            .map(|(g, w)| (f64::from(*g) - w).abs() / w)
            .fold(0.0, f64::max);
        let (mut t_err, mut t_size, mut mean) = (0.0f64, 0.0f64, 0.0f64);
        for &n in &normals {
            let e = f64::from(probe.irradiance(vec32(n)).unwrap().value);
            let e_sh = f64::from(got.irradiance(vec32(n)).unwrap());
            let d = r.truncation(&y64, n);
            t_err = t_err.max(((e - e_sh) - d).abs());
            t_size = t_size.max(d.abs());
            mean += e.abs() / normals.len() as f64;
        }
        out.push((m.condition, c_err, v_err, t_err / mean, t_size / mean));
    }
    out
}

fn check_members(label: &str, rows: &[(f32, f64, f64, f64, f64)]) {
    for (k, &(cond, c, v, t, size)) in rows.iter().enumerate() {
        println!(
            "{label} member {k} (cond {cond:.1e}): coefficients {c:.1e} of Σ|c|, variances \
             {v:.1e} relative, E − E_sh vs the degrees > 2: {t:.1e} of mean E (they are {size:.1e})"
        );
        // As tests/probe/probe.rs: 10⁻⁵ where cond(Q) ≤ 10⁴, else the forward bound cond(Q)·ε₃₂.
        let bar = if cond <= 1e4 { 1e-5 } else { f64::from(cond) * f64::from(f32::EPSILON) };
        assert!(c < bar, "{label} member {k}: coefficients off by {c:e} (bar {bar:e})");
        assert!(t < 2.0 * bar, "{label} member {k}: truncation off by {t:e} (bar {bar:e})");
        // The variances subtract ζᵀQ⁻¹ζ through the baked f32 factors: 10⁻², as
        // tests/probe/probe.rs's exact variance (measured ≤ 5.3·10⁻⁴ for point and photodiode
        // probes, ≤ 4.2·10⁻³ for the Gaussian footprint, also at cond(Q) = 9·10³).
        let v_bar = 1e-2;
        assert!(v < v_bar, "{label} member {k}: variances off by {v:e} (bar {v_bar:e})");
    }
}

#[test]
fn probe_projection_matches_the_f64_reference() {
    check_members("N = 16", &compare_probe::<16, Point>(0x5411));
    check_members("N = 64", &compare_probe::<64, Point>(0x5412));
    check_members("N = 64 Gaussian<8>", &compare_probe::<64, Gaussian<8>>(0x5413));
    check_members("N = 16 photodiode", &compare_probe::<16, CosinePower<1>>(0x5414));
}

/// Rotating the sample set and the radiance together rotates the exported coefficients.
#[test]
fn probe_projection_rotates_with_the_probe() {
    let mut rng = Rng::new(0x5415);
    let lights = field(&mut rng);
    let rot = rng.uniform_rotation();
    let mut a = Probe::<64, [f32; 3]>::new();
    let mut b = Probe::<64, [f32; 3]>::new();
    b.set_rotation(mat(rot)).unwrap();
    // The radiance at a's directions, carried along to b's (b's direction i is rot·aᵢ).
    let y: [[f32; 3]; 64] = a.directions().map(|d| {
        let v = 0.3 + lights.iter().map(|l| l.value(vec64(d))).sum::<f64>();
        [v as f32, 0.5 * v as f32, 0.1]
    });
    a.update(&y).unwrap();
    b.update(&y).unwrap();
    assert_eq!(a.selected(), b.selected());
    let want = a.radiance_sh().rotated(&mat(rot));
    let got = b.radiance_sh();
    for ch in 0..3 {
        let w = want.coefficients.map(|c| f64::from(c[ch]));
        let g = got.coefficients.map(|c| c[ch]);
        let err = coefficient_error(&g, &w);
        assert!(err < 2e-5, "channel {ch}: {err:e}");
    }
    // The constant channel: c₀₀ = √(4π)·0.1 and nothing else, rotated or not.
    assert!((got.coefficients[0][2] - 0.1 * (4.0 * std::f32::consts::PI).sqrt()).abs() < 1e-6);
    assert!(got.coefficients[1..].iter().all(|c| c[2] == 0.0));
}

/// Footprint samples of a radiance of degree ≤ 2 (each sample is `Σ g_l·L_lm·Y_lm(xᵢ)` by
/// Funk–Hecke): the export is the *unfiltered* radiance's coefficients, up to the model's
/// smoothing; dividing by the wrong gains would be off by `1 − g_l` (12 % and 30 % for the
/// Gaussian of sharpness 8, 33 % and 75 % for the photodiode).
#[test]
fn footprint_probes_export_the_unfiltered_radiance() {
    // L = 1 + 0.5·z + 0.3·xy: c₀₀ = √(4π), c₁₀ = 0.5/(½√(3/π)), c₂₋₂ = 0.3/(½√(15/π)).
    let y1 = 0.5 * (3.0 / PI).sqrt();
    let y2 = 0.5 * (15.0 / PI).sqrt();
    let mut want = [0.0; 9];
    want[0] = (4.0 * PI).sqrt();
    want[2] = 0.5 / y1;
    want[4] = 0.3 / y2;
    fn run<const N: usize, F: Footprint>(want: &[f64; 9]) -> f64
    where
        Size<N>: ProbeTables<F>,
    {
        let mut p = Probe::<N, f32, F>::new();
        let g = |l: usize| F::KIND.gain(l).unwrap();
        let y: [f32; N] = p.directions().map(|d| {
            (1.0 + 0.5 * g(1) * f64::from(d.z) + 0.3 * g(2) * f64::from(d.x * d.y)) as f32
        });
        p.update(&y).unwrap();
        coefficient_error(&p.radiance_sh().coefficients, want)
    }
    let gaussian = run::<64, Gaussian<8>>(&want);
    let photodiode = run::<32, CosinePower<1>>(&want);
    let point = run::<64, Point>(&want);
    println!("degree-2 radiance: error {gaussian:.1e} (Gaussian<8>), {photodiode:.1e} (photodiode), {point:.1e} (point) of Σ|c|");
    assert!(gaussian < 2e-3 && photodiode < 2e-3 && point < 2e-3);
}
