//! The footprint renderer: its directions, weights and error bar against the generator's f64
//! model (`gen/fp.rs`) at the query's exact `θₙ`, its estimate of irradiance against the
//! reference's closed form, and bad input.

use reference::analytic::SgLight;
use reference::rng::Rng;
use sphere_quadrature::bmc::footprint::{Brdf, Diffuse, FootprintRenderer, Phong};
use sphere_quadrature::bmc::{FootprintSize, Size};
use sphere_quadrature::footprint::Kind;
use sphere_quadrature::{Error, Vec3};
use std::f64::consts::PI;

use crate::footprint_lookups::Lookups;
use crate::gen;
use crate::gen::fp::{Design, Integrand, Model};

fn v64(v: Vec3) -> [f64; 3] {
    [f64::from(v.x), f64::from(v.y), f64::from(v.z)]
}

/// The crate's config and the spec of `(N, e)`.
fn spec(n: usize, e: u32) -> (gen::fp::Family, gen::fp::Spec) {
    let text = std::fs::read_to_string(gen::fp::CONFIG_FILE).unwrap();
    let (family, specs) = gen::fp::parse(&text).unwrap();
    let s = specs.iter().find(|s| s.n == n && s.e == e).expect("a baked set").clone();
    (family, s)
}

/// The generator's design and weight model of a spec.
fn model(family: &gen::fp::Family, s: &gen::fp::Spec) -> (Design, Model, usize) {
    let lmax = family
        .lengths
        .iter()
        .chain([&s.l])
        .map(|&l| gen::fp::degree_cut(2.0 / (l * l)))
        .max()
        .unwrap();
    let xs = gen::fp::lobe_set(s.n, s.morph());
    let sharp = gen::fp::footprints(&xs, f64::from(s.morph()), s.c);
    let design = Design::new(xs, sharp, lmax);
    let own = Model::new(&design, s.l, s.sigma).unwrap();
    (design, own, lmax)
}

/// A query `(n, r)` with `r·n = cos θₙ`, and the lobe frame `(t₁, t₂, a)` the crate uses.
fn query(rng: &mut Rng, theta_n: f64) -> (Vec3, Vec3) {
    let r = rng.uniform_sphere();
    let h = rng.uniform_sphere();
    let t = reference::vec::normalize(reference::vec::cross(r, h));
    let n: [f64; 3] = std::array::from_fn(|k| theta_n.cos() * r[k] + theta_n.sin() * t[k]);
    let v = |d: [f64; 3]| Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
    (v(n), v(r))
}

/// The crate's directions are the generator's set in the lobe frame, and its footprints the
/// generator's sharpnesses; its weights are the generator's exact GLS weights at the query's
/// `θₙ` up to the interpolation between the baked nodes (measured here: 8·10⁻⁴ of the largest
/// weight for Phong 10 at N = 32, 1.6·10⁻³ for Phong 50 at N = 64, 3·10⁻⁴ for Phong 200 at
/// N = 32, 1.5·10⁻² for Phong 10 at N = 128; 3–5·10⁻⁸ for irradiance, which has no θₙ). The
/// interpolation error is part of the error bar (the bake measures it at every interval's
/// midpoint).
fn check_weights<const N: usize, B: Brdf>(e: u32, tolerance: f64)
where
    Size<N>: FootprintSize<B>,
    FootprintRenderer<N, B>: Lookups<N>,
{
    let (family, s) = spec(N, e);
    let (design, own, lmax) = model(&family, &s);
    let r = FootprintRenderer::<N, B>::new();
    for (j, k) in r.footprints().iter().enumerate() {
        assert_eq!(*k, Kind::Gaussian { sharpness: design.sharpness[j] as u32 });
    }
    let mut rng = Rng::new(u64::from(e) * 100 + N as u64);
    let angles: Vec<f64> = if e == 0 {
        vec![0.0, 0.7]
    } else {
        // Nodes 0, 40, 96 and points between nodes.
        let mut a: Vec<f64> = [0, 40, 96].iter().map(|&k| gen::glossy::grid_angle(k)).collect();
        a.extend((0..6).map(|_| rng.next_f64() * PI / 2.0));
        a
    };
    let mut worst = 0.0f64;
    for theta in angles {
        let (n, mirror) = query(&mut rng, theta);
        let mut dirs = [Vec3::ZERO; N];
        r.fill(n, if e == 0 { n } else { mirror }, &mut dirs).unwrap();
        let mut w = [0.0f32; N];
        r.weights_for(n, if e == 0 { n } else { mirror }, &mut w).unwrap();
        // The exact weights at the crate's own θₙ (from the f32 vectors).
        let (n64, r64) = (v64(n), v64(mirror));
        let nn = reference::vec::normalize(n64);
        let rr = reference::vec::normalize(r64);
        let theta = reference::vec::dot(nn, rr).clamp(-1.0, 1.0).acos();
        let p =
            if e == 0 { Integrand::irradiance() } else { Integrand::phong(f64::from(e), theta) };
        let exact = own.weights(&design, &p.coefficients(lmax, gen::fp::P_NODES));
        let top = exact.iter().fold(0.0f64, |m, w| m.max(w.abs()));
        for (j, (&got, want)) in w.iter().zip(&exact).enumerate() {
            worst = worst.max((f64::from(got) - want).abs() / top);
            // Direction j is the generator's x_j in the frame (t₁, t₂, a).
            let a = if e == 0 { nn } else { rr };
            let x = design.xs[j];
            let d = v64(dirs[j]);
            assert!((reference::vec::dot(d, a) - x[2]).abs() < 2e-5, "{e} {N}: direction {j}");
        }
    }
    assert!(worst < tolerance, "e = {e}, N = {N}: weights off by {worst:.3e} of the largest");
}

#[test]
fn weights_are_the_generators() {
    check_weights::<32, Diffuse>(0, 1e-6);
    check_weights::<64, Diffuse>(0, 1e-6);
    check_weights::<32, Phong<10>>(10, 3e-3);
    check_weights::<64, Phong<50>>(50, 3e-3);
    check_weights::<16, Diffuse>(0, 1e-6);
    check_weights::<16, Phong<200>>(200, 3e-3);
    check_weights::<32, Phong<200>>(200, 3e-3);
}

/// The N = 128 sets (feature `footprint-128`).
#[cfg(feature = "footprint-128")]
#[test]
fn weights_of_the_largest_sets_are_the_generators() {
    check_weights::<128, Diffuse>(0, 1e-6);
    // Its weights change fastest with θₙ: 1.5·10⁻² measured.
    check_weights::<128, Phong<10>>(10, 2e-2);
}

/// `a·exp(λ(μ·y − 1))` seen through the normalised SG footprint of sharpness `s` about `x`:
/// `a·s·e^{w−λ−s}(1 − e^{−2w})/(w(1 − e^{−2s}))`, `w = |λμ + sx|` (closed form).
fn sg_lookup(g: &SgLight, x: [f64; 3], s: f64) -> f64 {
    let v: [f64; 3] = std::array::from_fn(|k| g.sharpness * g.axis[k] + s * x[k]);
    let w = reference::vec::dot(v, v).sqrt();
    g.amplitude * s * (w - g.sharpness - s).exp() * (-(-2.0 * w).exp_m1())
        / (w * -(-2.0 * s).exp_m1())
}

/// Irradiance from footprint lookups of smooth light (a constant plus spherical Gaussians)
/// against the reference's closed form: relative error below 1.5·10⁻³ at N = 64 (measured here:
/// at most 9.1·10⁻⁴ over 20 seeded lights; 1.3·10⁻⁴ with the nugget σ′ = 10⁻⁵ the set had
/// before, whose weights amplified lookup noise: `tables/footprint_renderer.txt`), with the
/// error inside twice the error bar for at least 17 of the 20 (measured: 20).
#[test]
fn irradiance_of_smooth_light() {
    const N: usize = 64;
    let r = FootprintRenderer::<N, Diffuse>::new();
    let mut rng = Rng::new(7);
    let mut inside = 0;
    let mut worst = 0.0f64;
    for _ in 0..20 {
        let lights: Vec<SgLight> = (0..3)
            .map(|_| SgLight {
                axis: rng.uniform_sphere(),
                sharpness: 2.0 + 8.0 * rng.next_f64(),
                amplitude: 0.2 + rng.next_f64(),
            })
            .collect();
        let base = 0.3;
        let n = rng.uniform_sphere();
        let nv = Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32);
        let mut dirs = [Vec3::ZERO; N];
        r.fill_directions(nv, &mut dirs).unwrap();
        let kinds = r.footprints();
        let lookups: [f32; N] = std::array::from_fn(|j| {
            let Kind::Gaussian { sharpness } = kinds[j] else { unreachable!("Gaussian") };
            let x = reference::vec::normalize(v64(dirs[j]));
            (base + lights.iter().map(|g| sg_lookup(g, x, f64::from(sharpness))).sum::<f64>())
                as f32
        });
        let truth = PI * base + lights.iter().map(|g| g.irradiance(v64(nv))).sum::<f64>();
        let e = r.estimate_with_variance(&lookups).unwrap();
        let err = (f64::from(e.value) - truth).abs();
        worst = worst.max(err / truth);
        inside += usize::from(err <= 2.0 * f64::from(e.variance).sqrt());
    }
    assert!(worst < 1.5e-3, "relative error {worst:.3e}");
    assert!(inside >= 17, "{inside} of 20 inside 2σ");
}

/// The error bar is the error variance under the family's most likely model, computed in f64
/// from the same baked pieces' definitions, at a node of θₙ (no interpolation): within 10⁻⁴
/// relative (measured here: at most 7·10⁻⁶).
#[test]
fn variance_is_the_most_likely_models() {
    const N: usize = 32;
    let (family, s) = spec(N, 50);
    let (design, own, lmax) = model(&family, &s);
    let contrasts = gen::fp::Contrasts::new(&own, family.contrasts.min(N - 1));
    let models: Vec<(Model, f64)> = family
        .lengths
        .iter()
        .flat_map(|&l| family.nuggets.iter().map(move |&sg| (l, sg)))
        .map(|(l, sg)| (Model::new(&design, l, sg).unwrap(), sg))
        .collect();
    let r = FootprintRenderer::<N, Phong<50>>::new();
    let mut rng = Rng::new(11);
    let theta = gen::glossy::grid_angle(40);
    for _ in 0..5 {
        let (n, mirror) = query(&mut rng, theta);
        let lookups: [f32; N] = std::array::from_fn(|_| (1.0 + rng.next_f64()) as f32);
        let got = r.estimate_with_variance(n, mirror, &lookups).unwrap();
        // f64: contrasts of the centred lookups, each model's σ̂² and likelihood, the weights'
        // error variance under it.
        let theta = reference::vec::dot(
            reference::vec::normalize(v64(n)),
            reference::vec::normalize(v64(mirror)),
        )
        .clamp(-1.0, 1.0)
        .acos();
        let p = Integrand::phong(50.0, theta).coefficients(lmax, gen::fp::P_NODES);
        let w = own.weights(&design, &p);
        let residual = design.residual_power(&p, &w);
        let y: Vec<f64> = lookups.iter().map(|&v| f64::from(v)).collect();
        let t = contrasts.apply(&y);
        let mut fits = Vec::new();
        for (m, _) in &models {
            let (s2, ll) = m.reduced(&contrasts).unwrap().fit(&t);
            fits.push((s2, ll, m.unit_variance(&residual, &w)));
        }
        let (s2, _, u) =
            fits.iter().fold((0.0, f64::NEG_INFINITY, 0.0), |b, &f| if f.1 > b.1 { f } else { b });
        let want = s.calibration * s.calibration * s2 * u;
        let rel = (f64::from(got.variance) - want).abs() / want;
        assert!(rel < 1e-4, "variance {} against {want}: {rel:.2e}", got.variance);
    }
}

#[test]
fn bad_input_is_an_error() {
    let r = FootprintRenderer::<32, Phong<10>>::new();
    let mut dirs = [Vec3::ZERO; 32];
    let ones = [1.0f32; 32];
    assert_eq!(r.fill_directions(Vec3::ZERO, Vec3::Z, &mut dirs), Err(Error::InvalidDirection));
    assert_eq!(
        r.estimate(Vec3::Z, Vec3::new(f32::NAN, 0.0, 1.0), &ones),
        Err(Error::InvalidDirection)
    );
    let mut bad = ones;
    bad[5] = f32::INFINITY;
    assert_eq!(r.estimate(Vec3::Z, Vec3::Z, &bad), Err(Error::InvalidRadiance));
    assert_eq!(r.estimate_with_variance(Vec3::Z, Vec3::Z, &bad), Err(Error::InvalidRadiance));
    bad[5] = f32::NAN;
    assert_eq!(r.estimate(Vec3::Z, Vec3::Z, &bad), Err(Error::InvalidRadiance));
    // Four channels, the most any estimator takes (five do not compile:
    // `radiance::MAX_CHANNELS`), each with its error bar.
    let four = [[1.0f32, 2.0, 0.5, 3.0]; 32];
    let e = r.estimate_with_variance(Vec3::Z, Vec3::Z, &four).unwrap();
    assert!(e
        .value
        .iter()
        .zip([1.0, 2.0, 0.5, 3.0])
        .all(|(v, c)| (v / c - e.value[0]).abs() < 1e-5));
    // A mirror direction below the horizon is grazing, not an error.
    let below = r.estimate_with_variance(Vec3::Z, Vec3::new(1.0, 0.0, -0.2), &ones).unwrap();
    assert!(below.value.is_finite() && below.variance < 1e-10);
}

/// A `set` line may name the feature its set is compiled under; every item of the set is
/// then behind that `#[cfg]`, and a malformed line names its line.
#[test]
fn a_set_behind_a_feature_is_compiled_under_it() {
    let head = "family_l = 1.0 3.0\nfamily_sigma = 1e-3\ncontrasts = 4\n";
    let text = format!("{head}set = diffuse 8 8 1.0 1e-3 1.0 feature=extra-sets\n");
    let (family, specs) = gen::fp::parse(&text).unwrap();
    assert_eq!(specs[0].feature.as_deref(), Some("extra-sets"));
    let baked = gen::fp::bake(&specs[0], &family).unwrap();
    let source = gen::fp::render(&family, &[baked]);
    let cfg = "#[cfg(feature = \"extra-sets\")]";
    assert!(source.contains(&format!("    {cfg}\n    (8, 0),")), "the pair is behind it");
    let items = source.lines().filter(|l| l.starts_with("static ") || l.starts_with("impl "));
    let lines: Vec<&str> = source.lines().collect();
    let mut count = 0;
    for item in items {
        let at = lines.iter().position(|l| *l == item).unwrap();
        assert_eq!(lines[at - 1], cfg, "{item}");
        count += 1;
    }
    assert!(count >= 10, "{count} items");
    for bad in ["feature=", "feat=extra", "feature=a;b"] {
        let text = format!("{head}set = diffuse 8 8 1.0 1e-3 1.0 {bad}\n");
        let err = gen::fp::parse(&text).unwrap_err();
        assert!(err.starts_with("line 4:"), "{bad}: {err}");
    }
}
