//! One contract for every estimator, asked of every type by the same generic code: the
//! renderers' directions are unit for every valid pair of directions; values scale with the
//! input (`c×`) and variances with its square (`c²×`) from 10⁻³⁰ to 10³⁰, subnormal inputs
//! included, with `±∞` only where the true answer exceeds `f32::MAX` and never NaN; a
//! non-finite input is [`Error::InvalidRadiance`] everywhere.
//!
//! Each type enters through a small adapter ([`Renderer`]) that maps the suite's questions
//! onto its calls; the questions themselves are written once.

use reference::rng::Rng;
use sphere_quadrature::bmc::footprint::{Brdf, Diffuse, FootprintRenderer, Phong};
use sphere_quadrature::bmc::{self, BakedSize, FootprintSize, GlossyRenderer, GlossySize, Size};
use sphere_quadrature::layout::Noise;
use sphere_quadrature::{Error, Estimate, Vec3};

use crate::footprint_lookups::Lookups;

/// What the suite asks of a renderer: its sample directions for a normal and a mirror
/// direction, and its estimate (with an error bar where it has one) from one value per
/// direction.
trait Renderer {
    const NAME: &'static str;
    /// Whether the directions depend on the mirror direction.
    const USES_MIRROR: bool;
    fn directions(n: Vec3, r: Vec3) -> Result<Vec<Vec3>, Error>;
    fn estimate(n: Vec3, r: Vec3, y: &[f32]) -> Result<f32, Error>;
    /// `None` where the type has no error bar.
    fn estimate_with_variance(n: Vec3, r: Vec3, y: &[f32]) -> Option<Result<Estimate<f32>, Error>>;
    /// `None` where the type takes no lookup noise. Else: on a renderer whose noise is
    /// `first`, the answer of setting `then`, and whether the renderer then equals what it
    /// was (`true` when the call was refused and nothing changed, or when it was accepted
    /// and changed it as asked).
    fn set_lookup_noise(_first: Noise, _then: Noise) -> Option<(Result<(), Error>, bool)> {
        None
    }
    /// `estimate_with_variance` of a renderer with lookup noise `noise`, and its weights;
    /// `None` where the type takes no lookup noise.
    fn estimate_with_lookup_noise(
        _n: Vec3,
        _r: Vec3,
        _y: &[f32],
        _noise: Noise,
    ) -> Option<NoisyEstimate> {
        None
    }
}

/// An estimate with declared lookup noise, and the renderer's weights for the same query.
type NoisyEstimate = (Result<Estimate<f32>, Error>, Vec<f32>);

struct Irradiance<const N: usize>;
struct Glossy<const N: usize, const E: u32>;
struct Footprint<const N: usize, B>(core::marker::PhantomData<B>);

fn array<const N: usize>(y: &[f32]) -> [f32; N] {
    core::array::from_fn(|j| y[j])
}

impl<const N: usize> Renderer for Irradiance<N>
where
    Size<N>: BakedSize,
{
    const NAME: &'static str = "Renderer";
    const USES_MIRROR: bool = false;
    fn directions(n: Vec3, _r: Vec3) -> Result<Vec<Vec3>, Error> {
        let mut out = [Vec3::ZERO; N];
        bmc::Renderer::<N>::new().fill_directions(n, &mut out)?;
        Ok(out.to_vec())
    }
    fn estimate(_n: Vec3, _r: Vec3, y: &[f32]) -> Result<f32, Error> {
        bmc::Renderer::<N>::new().estimate(&array::<N>(y))
    }
    fn estimate_with_variance(_: Vec3, _: Vec3, _: &[f32]) -> Option<Result<Estimate<f32>, Error>> {
        None
    }
}

impl<const N: usize, const E: u32> Renderer for Glossy<N, E>
where
    Size<N>: GlossySize<E>,
{
    const NAME: &'static str = "GlossyRenderer";
    const USES_MIRROR: bool = true;
    fn directions(n: Vec3, r: Vec3) -> Result<Vec<Vec3>, Error> {
        let mut out = [Vec3::ZERO; N];
        GlossyRenderer::<N, E>::new().fill_directions(n, r, &mut out)?;
        Ok(out.to_vec())
    }
    fn estimate(n: Vec3, r: Vec3, y: &[f32]) -> Result<f32, Error> {
        GlossyRenderer::<N, E>::new().estimate(n, r, &array::<N>(y))
    }
    fn estimate_with_variance(_: Vec3, _: Vec3, _: &[f32]) -> Option<Result<Estimate<f32>, Error>> {
        None
    }
}

impl<const N: usize, B: Brdf> Renderer for Footprint<N, B>
where
    Size<N>: FootprintSize<B>,
    FootprintRenderer<N, B>: Lookups<N>,
{
    const NAME: &'static str = "FootprintRenderer";
    const USES_MIRROR: bool = <FootprintRenderer<N, B> as Lookups<N>>::MIRROR;
    fn directions(n: Vec3, r: Vec3) -> Result<Vec<Vec3>, Error> {
        let mut out = [Vec3::ZERO; N];
        FootprintRenderer::<N, B>::new().fill(n, r, &mut out)?;
        Ok(out.to_vec())
    }
    fn estimate(n: Vec3, r: Vec3, y: &[f32]) -> Result<f32, Error> {
        FootprintRenderer::<N, B>::new().estimate_for(n, r, &array::<N>(y))
    }
    fn estimate_with_variance(n: Vec3, r: Vec3, y: &[f32]) -> Option<Result<Estimate<f32>, Error>> {
        Some(FootprintRenderer::<N, B>::new().estimate_with_variance_for(n, r, &array::<N>(y)))
    }
    fn set_lookup_noise(first: Noise, then: Noise) -> Option<(Result<(), Error>, bool)> {
        let mut renderer = FootprintRenderer::<N, B>::new();
        renderer.set_lookup_noise(first).expect("a valid first noise");
        let before = renderer;
        let result = renderer.set_lookup_noise(then);
        let as_expected = match result {
            Ok(()) => renderer.lookup_noise() == then,
            Err(_) => renderer == before && renderer.lookup_noise() == first,
        };
        Some((result, as_expected))
    }
    fn estimate_with_lookup_noise(
        n: Vec3,
        r: Vec3,
        y: &[f32],
        noise: Noise,
    ) -> Option<NoisyEstimate> {
        let mut renderer = FootprintRenderer::<N, B>::new();
        if let Err(e) = renderer.set_lookup_noise(noise) {
            return Some((Err(e), Vec::new()));
        }
        let mut w = [0.0f32; N];
        renderer.weights_for(n, r, &mut w).expect("valid directions");
        Some((renderer.estimate_with_variance_for(n, r, &array::<N>(y)), w.to_vec()))
    }
}

fn v32(d: [f64; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

/// Pairs `(n, r)` of valid directions: random pairs (half of them below the horizon), `r = n`
/// and `r = −n` for random and axis normals, `r` within a few ulps of `±n`, and the audit's
/// `n = r = (1, −1, 1)`; each also with lengths far from 1.
fn pairs(seed: u64) -> Vec<(Vec3, Vec3)> {
    let mut rng = Rng::new(seed);
    let mut out = vec![(Vec3::new(1.0, -1.0, 1.0), Vec3::new(1.0, -1.0, 1.0))];
    for _ in 0..400 {
        let n = v32(rng.uniform_sphere());
        let r = v32(rng.uniform_sphere());
        out.push((n, r));
        out.push((n, n));
        out.push((n, -n));
        let tiny = v32(rng.uniform_sphere()) * 3e-7;
        out.push((n, n + tiny));
        out.push((n, -n + tiny));
    }
    for axis in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
        out.push((axis, axis));
        out.push((axis, -axis));
    }
    let scaled: Vec<_> = out
        .iter()
        .step_by(7)
        .flat_map(|&(n, r)| [(n * 1e-30, r * 1e30), (n * 1e20, r * 1e-20)])
        .collect();
    out.extend(scaled);
    out
}

/// Every direction of every valid pair is unit to 10⁻⁶.
fn directions_are_unit<R: Renderer>() {
    let mut worst = 0.0f64;
    for (n, r) in pairs(1) {
        let dirs = R::directions(n, r).unwrap_or_else(|e| panic!("{}: {n:?} {r:?}: {e}", R::NAME));
        for d in dirs {
            let len =
                (f64::from(d.x).powi(2) + f64::from(d.y).powi(2) + f64::from(d.z).powi(2)).sqrt();
            assert!((len - 1.0).abs() <= 1e-6, "{}: n = {n:?}, r = {r:?}: |d| = {len}", R::NAME);
            worst = worst.max((len - 1.0).abs());
        }
    }
    eprintln!("{}: largest |len − 1| = {worst:.1e}", R::NAME);
}

/// How far the directions stray from the great circle through the first one and the one
/// farthest from it (0 when they all lie in one plane through the origin).
fn spread(dirs: &[Vec3]) -> f32 {
    let far =
        dirs.iter().fold(dirs[0], |f, d| if d.dot(dirs[0]) < f.dot(dirs[0]) { *d } else { f });
    let m = dirs[0].cross(far).try_normalize().expect("two distinct directions");
    dirs.iter().map(|d| d.dot(m).abs()).fold(0.0, f32::max)
}

/// A mirror below the horizon is grazing: the directions are those of its projection onto
/// the tangent plane (to 10⁻⁵), and not all in one plane.
fn below_the_horizon_is_grazing<R: Renderer>() {
    if !R::USES_MIRROR {
        return;
    }
    let mut rng = Rng::new(2);
    for _ in 0..200 {
        let n = v32(rng.uniform_sphere());
        let mut r = v32(rng.uniform_sphere());
        if r.dot(n) > 0.0 {
            r = -r;
        }
        let grazing = r - n * r.dot(n);
        if grazing.length() < 1e-3 {
            continue;
        }
        let below = R::directions(n, r).unwrap();
        let at = R::directions(n, grazing).unwrap();
        for (a, b) in below.iter().zip(&at) {
            assert!((*a - *b).length() <= 1e-5, "{}: {n:?} {r:?}: {a:?} vs {b:?}", R::NAME);
        }
        assert!(
            spread(&below) > 1e-2,
            "{}: the directions of {n:?} {r:?} lie on a great circle",
            R::NAME
        );
    }
    // r = −n: grazing along some tangent; unit and spread.
    for n in [Vec3::Z, Vec3::new(1.0, -1.0, 1.0), Vec3::new(0.3, 0.4, -0.2)] {
        let dirs = R::directions(n, -n).unwrap();
        assert!(
            spread(&dirs) > 1e-2,
            "{}: the directions of r = −n lie on a great circle",
            R::NAME
        );
    }
}

#[test]
fn renderer_directions_are_unit() {
    directions_are_unit::<Irradiance<16>>();
    directions_are_unit::<Irradiance<64>>();
    directions_are_unit::<Glossy<64, 50>>();
    directions_are_unit::<Glossy<16, 10>>();
    directions_are_unit::<Footprint<16, Diffuse>>();
    directions_are_unit::<Footprint<32, Phong<10>>>();
    directions_are_unit::<Footprint<64, Phong<50>>>();
    directions_are_unit::<Footprint<32, Phong<200>>>();
}

#[test]
fn renderer_mirror_below_the_horizon_is_grazing() {
    below_the_horizon_is_grazing::<Glossy<64, 50>>();
    below_the_horizon_is_grazing::<Footprint<32, Phong<10>>>();
    below_the_horizon_is_grazing::<Footprint<64, Phong<200>>>();
}

const MAX: f64 = f32::MAX as f64;
const TINY: f64 = f32::MIN_POSITIVE as f64;

/// `got` against the f64 `want`: within `tol` relative where `want` is a normal f32 number
/// (with a margin of `tol` at both ends of the range), `±∞` above `f32::MAX`, 0 or subnormal
/// of the same sign below the normal range; never NaN.
fn check(got: f32, want: f64, tol: f64, what: &str) {
    assert!(!got.is_nan(), "{what}: NaN (want {want:e})");
    let mag = want.abs();
    if mag > MAX * (1.0 + tol) {
        assert_eq!(got, f32::INFINITY.copysign(want as f32), "{what}: want {want:e}");
    } else if mag < TINY * (1.0 - tol) {
        assert!(
            got.abs() <= f32::MIN_POSITIVE
                && (got == 0.0 || (got as f64).signum() == want.signum()),
            "{what}: {got:e}, want {want:e} (below the normal range)"
        );
    } else if mag < MAX * (1.0 - tol) && mag > TINY * (1.0 + tol) {
        let rel = (got as f64 - want).abs() / mag;
        assert!(rel <= tol, "{what}: {got:e}, want {want:e} (relative {rel:e})");
    }
}

/// [`check`] for a variance, which is also never 0 where `want` is not.
fn check_variance(got: f32, want: f64, tol: f64, what: &str) {
    check(got, want, tol, what);
    assert!(got >= 0.0, "{what}: negative variance {got:e}");
    if want > 0.0 {
        assert!(got > 0.0, "{what}: variance 0, want {want:e}");
    }
}

/// Scales from 10⁻³⁰ to 10³⁰ and powers of two (exact), and subnormal ones (10⁻⁴⁰, 2⁻¹⁴⁰).
fn scales() -> Vec<f64> {
    let mut c = vec![1e-40, 1e-30, 1e-20, 1e-10, 1e-3, 1.0, 1e3, 1e10, 1e20, 1e30, 1e37];
    c.extend([-140, -100, -60, -1, 1, 60, 100].map(|k| 2f64.powi(k)));
    c
}

/// A light with structure at several scales (positive, 0.1 to about 12).
fn light(d: Vec3) -> f64 {
    let lobe = |axis: Vec3, sharpness: f32| f64::from((sharpness * (d.dot(axis) - 1.0)).exp());
    0.1 + 0.5 * f64::from(d.z + 1.0)
        + 8.0 * lobe(Vec3::new(0.6, 0.0, 0.8), 30.0)
        + 3.0 * lobe(Vec3::new(-0.3, 0.9, 0.3).try_normalize().unwrap(), 4.0)
}

/// Queries `(n, r)` of every kind: random pairs, normal incidence, below the horizon.
fn queries() -> Vec<(Vec3, Vec3)> {
    let mut rng = Rng::new(3);
    let mut out = vec![(Vec3::Z, Vec3::Z), (Vec3::Z, Vec3::new(0.6, 0.0, 0.8))];
    for _ in 0..6 {
        let n = v32(rng.uniform_sphere());
        out.push((n, v32(rng.uniform_sphere())));
    }
    out
}

/// Values scale as `c` and variances as `c²` for lookups `c·Y`, with `±∞` only beyond
/// `f32::MAX`, never NaN, and variances never 0 where the unscaled one is not.
fn answers_scale<R: Renderer>() {
    for (n, r) in queries() {
        let dirs = R::directions(n, r).unwrap();
        let y: Vec<f64> = dirs.iter().map(|&d| light(d)).collect();
        let base_y: Vec<f32> = y.iter().map(|&v| v as f32).collect();
        let value = f64::from(R::estimate(n, r, &base_y).unwrap());
        let variance = R::estimate_with_variance(n, r, &base_y).map(|e| {
            let e = e.unwrap();
            assert_eq!(f64::from(e.value), value, "{}: the two calls' values differ", R::NAME);
            f64::from(e.variance)
        });
        // A decimal scale rounds every lookup anew: the variance moves by as much as it does
        // under one-ulp changes of the lookups (measured here) on top of the stated 10⁻⁴.
        let spread = variance.map_or(0.0, |v| ulp_spread::<R>(n, r, &base_y, v));
        for c in scales() {
            let scaled: Vec<f32> = y.iter().map(|&v| (v * c) as f32).collect();
            // The exact answer for the rounded lookups is c·value up to their rounding; below the
            // normal range the lookups lose relative precision, so the tolerance follows.
            let tol = if y.iter().any(|&v| v * c < TINY) { 1e-3 } else { 1e-5 };
            let what = format!("{} n = {n:?} r = {r:?} c = {c:e}", R::NAME);
            check(R::estimate(n, r, &scaled).unwrap(), value * c, tol, &format!("{what} value"));
            if let (Some(v), Some(e)) = (variance, R::estimate_with_variance(n, r, &scaled)) {
                let e = e.unwrap();
                check(e.value, value * c, tol, &format!("{what} value of estimate_with_variance"));
                let exact = c.log2().fract() == 0.0;
                let tol = if exact { 1e-6 } else { 1e-4 + 2.0 * spread };
                check_variance(e.variance, v * c * c, tol, &format!("{what} variance"));
            }
        }
        // Lookups at f32::MAX: the answer exceeds f32::MAX exactly when the light's does.
        let top = y.iter().copied().fold(0.0, f64::max);
        let huge: Vec<f32> = y.iter().map(|&v| (v / top * MAX) as f32).collect();
        let want = value / top * MAX;
        check(R::estimate(n, r, &huge).unwrap(), want, 1e-5, &format!("{} huge", R::NAME));
        let all_max = vec![f32::MAX; dirs.len()];
        let ones = f64::from(R::estimate(n, r, &vec![1.0; dirs.len()]).unwrap());
        check(R::estimate(n, r, &all_max).unwrap(), ones * MAX, 1e-5, &format!("{} MAX", R::NAME));
        if let Some(e) = R::estimate_with_variance(n, r, &all_max) {
            let e = e.unwrap();
            assert!(!e.variance.is_nan() && e.variance >= 0.0, "{}: variance {e:?}", R::NAME);
        }
    }
}

/// The largest relative change of the variance over a few random one-ulp changes of every
/// lookup.
fn ulp_spread<R: Renderer>(n: Vec3, r: Vec3, y: &[f32], variance: f64) -> f64 {
    let mut rng = Rng::new(9);
    let mut spread = 0.0f64;
    for _ in 0..16 {
        let moved: Vec<f32> = y
            .iter()
            .map(|&v| match rng.next_u64() % 3 {
                0 => f32::from_bits(v.to_bits() + 1),
                1 => f32::from_bits(v.to_bits() - 1),
                _ => v,
            })
            .collect();
        let e = R::estimate_with_variance(n, r, &moved).unwrap().unwrap();
        spread = spread.max((f64::from(e.variance) - variance).abs() / variance);
    }
    spread
}

/// A NaN or infinite lookup anywhere is [`Error::InvalidRadiance`], from every call.
fn non_finite_lookups_are_refused<R: Renderer>() {
    let (n, r) = (Vec3::new(0.2, 0.3, 0.9), Vec3::new(0.5, -0.1, 0.8));
    let len = R::directions(n, r).unwrap().len();
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for at in [0, len / 2, len - 1] {
            let mut y = vec![1.0f32; len];
            y[at] = bad;
            assert_eq!(
                R::estimate(n, r, &y),
                Err(Error::InvalidRadiance),
                "{} {bad} at {at}",
                R::NAME
            );
            if let Some(e) = R::estimate_with_variance(n, r, &y) {
                assert_eq!(e, Err(Error::InvalidRadiance), "{} {bad} at {at}", R::NAME);
            }
        }
    }
}

#[test]
fn renderer_answers_scale_with_the_input() {
    answers_scale::<Irradiance<16>>();
    answers_scale::<Irradiance<256>>();
    answers_scale::<Glossy<16, 10>>();
    answers_scale::<Glossy<64, 50>>();
    answers_scale::<Footprint<16, Diffuse>>();
    answers_scale::<Footprint<64, Diffuse>>();
    answers_scale::<Footprint<32, Phong<10>>>();
    answers_scale::<Footprint<64, Phong<50>>>();
    answers_scale::<Footprint<32, Phong<200>>>();
}

/// A lookup noise with a negative, NaN or infinite part, or a relative part above
/// `MAX_RELATIVE_NOISE`, is [`Error::InvalidNoise`] and leaves the renderer as it was; any
/// other is taken as given.
fn lookup_noise_is_validated<R: Renderer>() {
    let first = Noise { absolute: 0.25, relative: 0.01 };
    let max = sphere_quadrature::layout::MAX_RELATIVE_NOISE;
    let bad = [-1.0, -f32::MIN_POSITIVE, f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
    let mut refused: Vec<Noise> = bad
        .iter()
        .flat_map(|&b| [Noise { absolute: b, relative: 0.0 }, Noise { absolute: 0.0, relative: b }])
        .collect();
    refused.push(Noise { absolute: 0.0, relative: max * 1.01 });
    for noise in refused {
        let Some((result, unchanged)) = R::set_lookup_noise(first, noise) else { return };
        assert_eq!(result, Err(Error::InvalidNoise), "{}: {noise:?}", R::NAME);
        assert!(unchanged, "{}: a refused noise {noise:?} changed the renderer", R::NAME);
    }
    let accepted = [
        Noise::NONE,
        Noise { absolute: 0.0, relative: 2f32.powi(-11) / 3f32.sqrt() },
        Noise { absolute: f32::MAX, relative: max },
        Noise { absolute: f32::from_bits(1), relative: 0.0 },
    ];
    for noise in accepted {
        let Some((result, as_asked)) = R::set_lookup_noise(first, noise) else { return };
        assert_eq!(result, Ok(()), "{}: {noise:?}", R::NAME);
        assert!(as_asked, "{}: {noise:?} was not taken as given", R::NAME);
    }
}

/// Declared lookup noise `(σ, η)` leaves the estimate as it was, bit for bit, and adds
/// `Σ wⱼ²·(σ² + η²·Yⱼ²)` (computed here in f64 from the renderer's weights) to the variance,
/// within 10⁻⁵ of the total; `Noise::NONE` changes nothing, bit for bit. At lookups `c·Y`
/// with relative noise only, the same holds at every scale whose answer is a normal f32.
fn lookup_noise_adds_its_variance<R: Renderer>() {
    let noises = [
        Noise { absolute: 0.0, relative: 2f32.powi(-11) / 3f32.sqrt() },
        Noise { absolute: 0.0, relative: 0.05 },
        Noise { absolute: 0.1, relative: 0.0 },
        Noise { absolute: 0.02, relative: 0.01 },
    ];
    for (n, r) in queries() {
        let dirs = R::directions(n, r).unwrap();
        let light: Vec<f64> = dirs.iter().map(|&d| light(d)).collect();
        let y: Vec<f32> = light.iter().map(|&v| v as f32).collect();
        let Some(base) = R::estimate_with_variance(n, r, &y) else { return };
        let base = base.unwrap();
        let (none, _) =
            R::estimate_with_lookup_noise(n, r, &y, Noise::NONE).expect("the same type");
        assert_eq!(none.unwrap(), base, "{}: Noise::NONE changed the answer", R::NAME);
        for noise in noises {
            for c in [1.0f64, 1e-15, 3e15, 2f64.powi(-40)] {
                if noise.absolute > 0.0 && c != 1.0 {
                    continue; // σ is in the lookups' units: it does not scale with them.
                }
                let yc: Vec<f32> = light.iter().map(|&v| (v * c) as f32).collect();
                let (got, w) = R::estimate_with_lookup_noise(n, r, &yc, noise).unwrap();
                let got = got.unwrap();
                let plain = R::estimate_with_variance(n, r, &yc).unwrap().unwrap();
                let what = format!("{} n = {n:?} r = {r:?} {noise:?} c = {c:e}", R::NAME);
                assert_eq!(got.value, plain.value, "{what}: the value moved");
                assert_eq!(got.unit_variance, plain.unit_variance, "{what}: unit variance");
                let (sigma, eta) = (f64::from(noise.absolute), f64::from(noise.relative));
                let added: f64 = w
                    .iter()
                    .zip(&yc)
                    .map(|(&w, &y)| {
                        f64::from(w).powi(2) * (sigma.powi(2) + (eta * f64::from(y)).powi(2))
                    })
                    .sum();
                let want = f64::from(plain.variance) + added;
                check_variance(got.variance, want, 1e-5, &format!("{what}: variance"));
                // Where the noise's share exceeds the tolerance, the variance must have grown.
                if added > 1e-4 * want && want > TINY {
                    assert!(got.variance > plain.variance, "{what}: nothing added");
                }
            }
        }
    }
}

#[test]
fn renderer_lookup_noise_is_validated_and_adds_its_variance() {
    lookup_noise_is_validated::<Footprint<16, Diffuse>>();
    lookup_noise_is_validated::<Footprint<64, Phong<50>>>();
    // Types without lookup noise answer None and are skipped by the same code.
    lookup_noise_is_validated::<Irradiance<16>>();
    lookup_noise_adds_its_variance::<Footprint<16, Diffuse>>();
    lookup_noise_adds_its_variance::<Footprint<64, Diffuse>>();
    lookup_noise_adds_its_variance::<Footprint<32, Phong<10>>>();
    lookup_noise_adds_its_variance::<Footprint<64, Phong<200>>>();
}

#[test]
fn renderer_non_finite_lookups_are_refused() {
    non_finite_lookups_are_refused::<Irradiance<16>>();
    non_finite_lookups_are_refused::<Irradiance<64>>();
    non_finite_lookups_are_refused::<Glossy<16, 10>>();
    non_finite_lookups_are_refused::<Glossy<64, 50>>();
    non_finite_lookups_are_refused::<Footprint<16, Diffuse>>();
    non_finite_lookups_are_refused::<Footprint<64, Phong<50>>>();
}

// ---------------------------------------------------------------------------------------------
// Probes: N samples (or readings) in, queries out; streams of them.

use sphere_quadrature::footprint::{CosinePower, Footprint as SampleFootprint, Gaussian, Point};
use sphere_quadrature::layout::{LayoutProbe, Prior, Sensor};
use sphere_quadrature::probe::{Probe, ProbeTables};
use sphere_quadrature::temporal::TemporalProbe;

/// What the suite asks of a probe: where it samples, how it takes one value per direction,
/// and its queries with their error bars. A query the type does not have is `None`.
trait Estimator: Sized {
    const NAME: &'static str;
    /// Updates of one stream in the scale sweep (1 for a probe that replaces its data).
    const UPDATES: usize;
    fn fresh() -> Self;
    /// The directions the next update's samples are taken in, in order.
    fn sample_directions(&self) -> Vec<Vec3>;
    /// Takes one value per direction; what it decided (a member, a reset).
    fn update(&mut self, y: &[f32]) -> Result<String, Error>;
    fn irradiance(&self, n: Vec3) -> Result<Estimate<f32>, Error>;
    /// The exact variance at one normal.
    fn irradiance_variance(&self, _n: Vec3) -> Option<Result<f32, Error>> {
        None
    }
    fn phong(&self, _axis: Vec3, _e: f32) -> Option<Result<Estimate<f32>, Error>> {
        None
    }
    /// The channel combination of one of its estimates (every probe has `combine`).
    fn combine(&self, e: &Estimate<f32>, w: f32) -> Result<Estimate<f32>, Error>;
    /// The whole state, to check that a refused call left it as it was.
    fn state(&self) -> String;
}

struct PointProbe<const N: usize, F: SampleFootprint>(Probe<N, f32, F>)
where
    Size<N>: ProbeTables<F>;

impl<const N: usize, F: SampleFootprint> Estimator for PointProbe<N, F>
where
    Size<N>: ProbeTables<F>,
{
    const NAME: &'static str = "Probe";
    const UPDATES: usize = 1;
    fn fresh() -> Self {
        Self(Probe::new())
    }
    fn sample_directions(&self) -> Vec<Vec3> {
        self.0.directions().to_vec()
    }
    fn update(&mut self, y: &[f32]) -> Result<String, Error> {
        self.0.update(&array::<N>(y))?;
        Ok(format!("member {}", self.0.selected()))
    }
    fn irradiance(&self, n: Vec3) -> Result<Estimate<f32>, Error> {
        self.0.irradiance(n)
    }
    fn irradiance_variance(&self, n: Vec3) -> Option<Result<f32, Error>> {
        Some(self.0.irradiance_variance(n))
    }
    fn phong(&self, axis: Vec3, e: f32) -> Option<Result<Estimate<f32>, Error>> {
        Some(self.0.phong(axis, e))
    }
    fn combine(&self, e: &Estimate<f32>, w: f32) -> Result<Estimate<f32>, Error> {
        self.0.combine(e, w)
    }
    fn state(&self) -> String {
        format!("{:?}", self.0)
    }
}

/// A temporal probe's stream: `N` rotated directions then `S` sentinels per update.
struct Stream<const N: usize, F: SampleFootprint, const S: usize>(TemporalProbe<N, f32, F, S>);

impl<const N: usize, F: SampleFootprint, const S: usize> Estimator for Stream<N, F, S> {
    const NAME: &'static str = "TemporalProbe";
    const UPDATES: usize = 6;
    fn fresh() -> Self {
        Self(TemporalProbe::new(5))
    }
    fn sample_directions(&self) -> Vec<Vec3> {
        self.0.directions().iter().chain(self.0.sentinels()).copied().collect()
    }
    fn update(&mut self, y: &[f32]) -> Result<String, Error> {
        let change = self.0.pool(&array::<N>(y), &array::<S>(&y[N..]))?;
        Ok(format!("{change:?}"))
    }
    fn irradiance(&self, n: Vec3) -> Result<Estimate<f32>, Error> {
        self.0.irradiance(n)
    }
    fn combine(&self, e: &Estimate<f32>, w: f32) -> Result<Estimate<f32>, Error> {
        self.0.combine(e, w)
    }
    fn state(&self) -> String {
        format!("{:?}", self.0)
    }
}

/// A layout probe: cosine photodiodes on the directions of a 16-point spherical Fibonacci
/// set (`STREAM`: pooled by `accumulate`; otherwise replaced by `update`), with a relative
/// noise of 1 % or none.
struct Layout<const STREAM: bool, const NOISY: bool>(LayoutProbe<16>);

impl<const STREAM: bool, const NOISY: bool> Estimator for Layout<STREAM, NOISY> {
    const NAME: &'static str = "LayoutProbe";
    const UPDATES: usize = if STREAM { 6 } else { 1 };
    fn fresh() -> Self {
        let dirs = sphere_quadrature::SphericalFibonacci::<16>::new().points();
        let noise = Noise { absolute: 0.0, relative: if NOISY { 0.01 } else { 0.0 } };
        Self(LayoutProbe::new(&dirs.map(Sensor::cosine), Prior::ENVIRONMENT, noise).unwrap())
    }
    fn sample_directions(&self) -> Vec<Vec3> {
        self.0.directions().to_vec()
    }
    fn update(&mut self, y: &[f32]) -> Result<String, Error> {
        if STREAM {
            Ok(format!("{:?}", self.0.pool(&array::<16>(y))?))
        } else {
            self.0.update(&array::<16>(y)).map(|()| String::new())
        }
    }
    fn irradiance(&self, n: Vec3) -> Result<Estimate<f32>, Error> {
        self.0.irradiance(n)
    }
    fn irradiance_variance(&self, n: Vec3) -> Option<Result<f32, Error>> {
        Some(self.0.irradiance_variance(n))
    }
    fn phong(&self, axis: Vec3, e: f32) -> Option<Result<Estimate<f32>, Error>> {
        Some(self.0.phong(axis, e))
    }
    fn combine(&self, e: &Estimate<f32>, w: f32) -> Result<Estimate<f32>, Error> {
        self.0.combine(e, w)
    }
    fn state(&self) -> String {
        format!("{:?}", self.0)
    }
}

/// Normals of every kind, with lengths far from 1.
fn normals() -> Vec<Vec3> {
    let mut rng = Rng::new(4);
    let mut out = vec![Vec3::Z, -Vec3::Z, Vec3::new(1.0, -1.0, 1.0) * 1e-30];
    for _ in 0..6 {
        out.push(v32(rng.uniform_sphere()) * 1e20);
        out.push(v32(rng.uniform_sphere()));
    }
    out
}

/// Every query of a probe: values and variances, in one order.
fn answers<E: Estimator>(p: &E) -> (Vec<f64>, Vec<f64>) {
    let (mut values, mut variances) = (Vec::new(), Vec::new());
    for n in normals() {
        let e = p.irradiance(n).unwrap();
        values.push(f64::from(e.value));
        variances.push(f64::from(e.variance));
        if let Some(v) = p.irradiance_variance(n) {
            variances.push(f64::from(v.unwrap()));
        }
        for ex in [0.0, 1.0, 20.0, 1000.0] {
            if let Some(e) = p.phong(n, ex) {
                let e = e.unwrap();
                values.push(f64::from(e.value));
                variances.push(f64::from(e.variance));
            }
        }
    }
    (values, variances)
}

/// The light of update `k` of a stream at scale `c`: the same light for the first updates,
/// then a fifth of it (a change every type must see the same way at every scale).
fn stream_light(k: usize, updates: usize, d: Vec3) -> f64 {
    if updates > 1 && k + 2 >= updates {
        0.2 * light(d)
    } else {
        light(d)
    }
}

/// A stream of [`Estimator::UPDATES`] updates at scale `c`, sample `bump` (in every update)
/// one ulp up when given: the probe and its decisions.
fn run_stream<E: Estimator>(c: f64, bump: Option<usize>) -> (E, Vec<String>) {
    run_stream_lifted(c, 0, bump)
}

/// [`run_stream`] with every sample, once rounded to f32 at scale `c`, multiplied by `2^lift`
/// (exact within the f32 range: a sub-normal sample keeps the bits it has).
fn run_stream_lifted<E: Estimator>(c: f64, lift: i32, bump: Option<usize>) -> (E, Vec<String>) {
    let mut p = E::fresh();
    let mut decisions = Vec::new();
    let lift = 2f64.powi(lift);
    for k in 0..E::UPDATES {
        let mut y: Vec<f32> = p
            .sample_directions()
            .iter()
            .map(|&d| (f64::from((stream_light(k, E::UPDATES, d) * c) as f32) * lift) as f32)
            .collect();
        if let Some(j) = bump {
            y[j] = f32::from_bits(y[j].to_bits() + 1);
        }
        decisions.push(p.update(&y).unwrap());
    }
    (p, decisions)
}

/// Samples `c·Y` give `c` times every value and `c²` times every variance (to f32 rounding;
/// exactly for powers of two), `±∞` only beyond `f32::MAX`, never NaN, no variance 0 where the
/// unscaled one is not, and the same decisions.
fn probe_answers_scale<E: Estimator>() {
    let (p, decisions) = run_stream::<E>(1.0, None);
    let (values, variances) = answers(&p);
    // A decimal scale rounds every sample anew, each by at most half an ulp: an answer moves
    // by at most the sum over the samples of what one ulp of each moves it (measured here,
    // one sample at a time), on top of the stated tolerance.
    let mut spread_values = vec![0.0f64; values.len()];
    let mut spread_variances = vec![0.0f64; variances.len()];
    for j in 0..E::fresh().sample_directions().len() {
        let (q, _) = run_stream::<E>(1.0, Some(j));
        let (v, w) = answers(&q);
        for (s, (a, b)) in spread_values.iter_mut().zip(v.iter().zip(&values)) {
            *s += (a - b).abs() / b.abs().max(f64::MIN_POSITIVE);
        }
        for (s, (a, b)) in spread_variances.iter_mut().zip(w.iter().zip(&variances)) {
            *s += (a - b).abs() / b.abs().max(f64::MIN_POSITIVE);
        }
    }
    let top = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let smallest = {
        let p = E::fresh();
        p.sample_directions().iter().map(|&d| 0.2 * light(d)).fold(f64::MAX, f64::min)
    };
    let samples = E::fresh().sample_directions().len() as f64;
    for c in scales() {
        let (q, got_decisions) = run_stream::<E>(c, None);
        let what = format!("{} c = {c:e}", std::any::type_name::<E>());
        let exact = c.log2().fract() == 0.0;
        let subnormal = smallest * c < TINY;
        let (vq, wq) = answers(&q);
        if subnormal {
            // Below the normal range a sample keeps only the bits f32 has there (2.5 % of the
            // smallest sample here), which moves the answers far more than rounding does: they
            // are those of the samples as rounded, which `2^lift` carries to the normal range
            // exactly, up to the rounding of a sum of `samples` terms in the sub-normal range.
            let lift = -c.log2().floor() as i32;
            let (lifted, lifted_decisions) = run_stream_lifted::<E>(c, lift, None);
            assert_eq!(got_decisions, lifted_decisions, "{what}: decisions of the rounded samples");
            let back = 2f64.powi(-lift);
            let ulp = f64::from(f32::from_bits(1));
            for (i, (&got, &want)) in vq.iter().zip(&answers(&lifted).0).enumerate() {
                let want = want * back;
                assert!(
                    !(got as f32).is_nan()
                        && (got - want).abs() <= 1e-6 * want.abs() + samples * ulp,
                    "{what} value {i}: {got:e}, want {want:e} (the rounded samples' answer)"
                );
            }
        } else {
            let tol_value = if exact { 1e-6 } else { 1e-5 };
            assert_eq!(got_decisions, decisions, "{what}: decisions");
            for (i, (&got, &want)) in vq.iter().zip(&values).enumerate() {
                // Values near zero are as accurate as the others in absolute terms.
                let want_c = want * c;
                if (want.abs() / top) < 1e-3 {
                    assert!(
                        !(got as f32).is_nan() && (got - want_c).abs() <= 1e-3 * top * c + TINY,
                        "{what} value {i}: {got:e}, want {want_c:e}"
                    );
                } else {
                    let tol = if exact { tol_value } else { tol_value + 2.0 * spread_values[i] };
                    check(got as f32, want_c, tol, &format!("{what} value {i}"));
                }
            }
        }
        // Variances scale as c², which is below f32's range at every sub-normal scale here.
        let tol_variance = match (exact, subnormal) {
            (_, true) => 1e-2,
            (true, false) => 1e-6,
            (false, false) => 1e-4,
        };
        for (i, (&got, &want)) in wq.iter().zip(&variances).enumerate() {
            let tol = if exact { tol_variance } else { tol_variance + 2.0 * spread_variances[i] };
            check_variance(got as f32, want * c * c, tol, &format!("{what} variance {i}"));
        }
    }
}

#[test]
fn probe_answers_scale_with_the_input() {
    probe_answers_scale::<PointProbe<16, Point>>();
    probe_answers_scale::<PointProbe<64, Point>>();
    probe_answers_scale::<PointProbe<64, Gaussian<8>>>();
    probe_answers_scale::<PointProbe<16, CosinePower<1>>>();
    probe_answers_scale::<Stream<16, Point, 1>>();
    probe_answers_scale::<Stream<64, Point, 0>>();
    probe_answers_scale::<Stream<32, Gaussian<4>, 2>>();
    probe_answers_scale::<Layout<false, false>>();
    probe_answers_scale::<Layout<false, true>>();
    probe_answers_scale::<Layout<true, true>>();
}

/// `combine` on one channel scales: weight `w` gives `w` times the value and `w²` times the
/// variance (to rounding), `unit_variance` passed through; a NaN or infinite weight is
/// `InvalidWeights`.
fn combine_scales_one_channel<E: Estimator>() {
    let (p, _) = run_stream::<E>(1.0, None);
    for n in normals() {
        let e = p.irradiance(n).unwrap();
        for w in [1.0f32, -2.5, 1e-20, 3e15, 0.0] {
            let c = p.combine(&e, w).unwrap();
            let what = format!("{} combine {w:e} at {n:?}", E::NAME);
            check(c.value, f64::from(w) * f64::from(e.value), 1e-6, &what);
            check_variance(c.variance, f64::from(w).powi(2) * f64::from(e.variance), 1e-6, &what);
            assert_eq!(c.unit_variance, e.unit_variance, "{what}");
        }
        for w in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert_eq!(p.combine(&e, w), Err(Error::InvalidWeights), "{} weight {w}", E::NAME);
        }
    }
}

#[test]
fn combine_is_the_same_call_on_every_probe() {
    combine_scales_one_channel::<PointProbe<64, Point>>();
    combine_scales_one_channel::<PointProbe<64, Gaussian<8>>>();
    combine_scales_one_channel::<Stream<16, Point, 1>>();
    combine_scales_one_channel::<Layout<false, false>>();
    combine_scales_one_channel::<Layout<true, true>>();
}

/// Degenerate data: every sample equal (a constant light of radiance `c`, at any scale) gives
/// `π·c` at every normal, exactly (to `tol`) where the type's error bar says so and within
/// the bar otherwise (a layout's learned prior does not know that the light is constant);
/// the bar is never NaN, and `+∞` only where the rounding's variance exceeds `f32::MAX`.
fn constant_light_is_exact<E: Estimator>() {
    for c in [1.0f32, 3e-30, 7e29, 1e-40] {
        let mut p = E::fresh();
        for _ in 0..E::UPDATES {
            let y = vec![c; p.sample_directions().len()];
            p.update(&y).unwrap();
        }
        let want = core::f64::consts::PI * f64::from(c);
        for n in normals() {
            let e = p.irradiance(n).unwrap();
            let what = format!("{} constant {c:e} at {n:?}: {e:?}", E::NAME);
            let tol = if c < f32::MIN_POSITIVE { 1e-3 } else { 1e-5 };
            let v = f64::from(e.variance);
            assert!(v >= 0.0, "{what}");
            assert!(v.is_finite() || (tol * want).powi(2) > f64::from(f32::MAX), "{what}");
            let err = (f64::from(e.value) - want).abs();
            assert!(err <= tol * want + 2.0 * v.sqrt(), "{what}: error {err:e}");
        }
    }
}

#[test]
fn constant_light_is_exact_on_every_probe() {
    constant_light_is_exact::<PointProbe<16, Point>>();
    constant_light_is_exact::<PointProbe<64, Gaussian<8>>>();
    constant_light_is_exact::<PointProbe<16, CosinePower<1>>>();
    constant_light_is_exact::<Stream<16, Point, 1>>();
    constant_light_is_exact::<Stream<64, Point, 0>>();
    constant_light_is_exact::<Layout<false, false>>();
    constant_light_is_exact::<Layout<true, true>>();
}

/// The bad-input table: each cause gives its one error, and a refused call (or any query)
/// leaves the state exactly as it was.
fn probe_bad_input<E: Estimator>() {
    let (mut p, _) = run_stream::<E>(1.0, None);
    let y: Vec<f32> = p.sample_directions().iter().map(|&d| light(d) as f32).collect();
    let before = p.state();
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for at in [0, y.len() / 2, y.len() - 1] {
            let mut z = y.clone();
            z[at] = bad;
            assert_eq!(
                p.update(&z),
                Err(Error::InvalidRadiance),
                "{} sample {bad} at {at}",
                E::NAME
            );
            // Miri formats the whole state slowly (about 0.7 s for a probe, 2.5 s for a
            // stream): it compares it once after the refused updates; the native run after each.
            if !cfg!(miri) {
                assert_eq!(p.state(), before, "{}: a refused update changed the state", E::NAME);
            }
        }
    }
    assert_eq!(p.state(), before, "{}: a refused update changed the state", E::NAME);
    let bad_directions = [
        Vec3::ZERO,
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, f32::INFINITY, 1.0),
        Vec3::new(0.0, 0.0, f32::NEG_INFINITY),
    ];
    for d in bad_directions {
        assert_eq!(p.irradiance(d), Err(Error::InvalidDirection), "{} normal {d:?}", E::NAME);
        if let Some(v) = p.irradiance_variance(d) {
            assert_eq!(v, Err(Error::InvalidDirection), "{} normal {d:?}", E::NAME);
        }
        if let Some(g) = p.phong(d, 10.0) {
            assert_eq!(g, Err(Error::InvalidDirection), "{} axis {d:?}", E::NAME);
        }
    }
    for e in [-1.0, -f32::MIN_POSITIVE, f32::NAN, f32::INFINITY, 2e8] {
        if let Some(g) = p.phong(Vec3::Z, e) {
            assert_eq!(g, Err(Error::InvalidExponent), "{} exponent {e}", E::NAME);
        }
    }
    // The exponents every type takes: 0 to 10⁸.
    for e in [0.0, 1e-30, 1.0, 20.0, 5000.0, 1e6, 1e8] {
        if let Some(g) = p.phong(Vec3::new(0.3, 0.4, 0.8), e) {
            let g = g.unwrap_or_else(|err| panic!("{} e = {e}: {err}", E::NAME));
            assert!(
                g.value.is_finite() && g.variance.is_finite() && g.variance >= 0.0,
                "{} e = {e}: {g:?}",
                E::NAME
            );
        }
    }
    assert_eq!(p.state(), before, "{}: a query changed the state", E::NAME);
}

#[test]
fn probe_bad_input_is_refused_and_leaves_the_state() {
    probe_bad_input::<PointProbe<16, Point>>();
    probe_bad_input::<PointProbe<16, CosinePower<1>>>();
    probe_bad_input::<Stream<16, Point, 1>>();
    // Miri interprets every operation: it takes the Gaussian footprint and the stream without
    // sentinels at N = 16 (the same code as at N = 64, on a quarter of the samples).
    if cfg!(miri) {
        probe_bad_input::<PointProbe<16, Gaussian<2>>>();
        probe_bad_input::<Stream<16, CosinePower<1>, 0>>();
    } else {
        probe_bad_input::<PointProbe<64, Gaussian<8>>>();
        probe_bad_input::<Stream<64, CosinePower<1>, 0>>();
    }
}

/// The same table for layouts, apart so that Miri, which runs the test above, is not kept for
/// minutes by the layouts' O(K³) set-up (Miri runs the layout module's own bad-input test).
#[test]
fn layout_refuses_bad_readings_and_keeps_the_state() {
    probe_bad_input::<Layout<false, true>>();
    probe_bad_input::<Layout<true, false>>();
}

// ---------------------------------------------------------------------------------------------
// What is baked: the table of the crate docs and the README, against the baked lists.

/// The lines of the "What is baked" table in `src/lib.rs` (without the `//! ` prefix).
fn baked_table_in_lib() -> Vec<String> {
    let lib = std::fs::read_to_string("src/lib.rs").unwrap();
    let lines: Vec<&str> = lib.lines().collect();
    let start = lines.iter().position(|l| *l == "//! # What is baked").expect("the section");
    lines[start..]
        .iter()
        .map(|l| l.trim_start_matches("//!").trim_start())
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .map(str::to_string)
        .collect()
}

fn listed<A: std::fmt::Display, B: std::fmt::Display>(p: impl Iterator<Item = (A, B)>) -> String {
    p.map(|(a, b)| format!("({a}, {b})")).collect::<Vec<_>>().join(", ")
}

#[test]
fn what_is_baked_is_current() {
    use sphere_quadrature::footprint::Kind;
    use sphere_quadrature::{bmc::footprint, bmc::glossy, probe};
    let table = baked_table_in_lib();
    assert!(table.len() > 5, "{table:?}");
    // The README carries the same table, between its markers.
    let readme = std::fs::read_to_string("README.md").unwrap();
    let quoted: Vec<&str> = readme
        .lines()
        .skip_while(|l| !l.starts_with("<!-- baked: src/lib.rs -->"))
        .skip(1)
        .take_while(|l| !l.starts_with("<!-- /baked -->"))
        .collect();
    assert_eq!(quoted, table, "README.md's \"What is baked\" differs from src/lib.rs's");
    let row = |start: &str| -> String {
        table
            .iter()
            .find(|l| l.starts_with(start))
            .unwrap_or_else(|| panic!("no row {start}"))
            .clone()
    };
    let sizes = |kind: fn(&Kind) -> bool| -> Vec<usize> {
        probe::BAKED_TABLES.iter().filter(|(_, k)| kind(k)).map(|&(n, _)| n).collect()
    };
    let points = sizes(|k| matches!(k, Kind::Point));
    let list = |v: &[usize]| v.iter().map(usize::to_string).collect::<Vec<_>>().join(", ");
    assert!(row("| `Probe<N, T, Point>`").contains(&format!("| N = {} |", list(&points))));
    let gaussians = listed(probe::BAKED_TABLES.iter().filter_map(|&(n, k)| match k {
        Kind::Gaussian { sharpness } => Some((n, sharpness)),
        _ => None,
    }));
    assert!(row("| `Probe<N, T, Gaussian<S>>`").contains(&format!("| (N, S) = {gaussians} |")));
    let cosines = listed(probe::BAKED_TABLES.iter().filter_map(|&(n, k)| match k {
        Kind::CosinePower { exponent } => Some((n, exponent)),
        _ => None,
    }));
    assert!(row("| `Probe<N, T, CosinePower<P>>`").contains(&format!("| (N, P) = {cosines} |")));
    assert!(row("| `bmc::Renderer<N>`").contains(&format!("| N = {} |", list(bmc::BAKED_SIZES))));
    let fibonacci = listed(glossy::BAKED_SETS.iter().copied());
    assert!(row("| `bmc::GlossyRenderer<N, E>`").contains(&format!("| (N, E) = {fibonacci} |")));
    let optimal = listed(glossy::BAKED_OPTIMAL_SETS.iter().copied());
    assert!(
        row("| `bmc::GlossyRenderer<N, E, Optimal>`").contains(&format!("| (N, E) = {optimal} |"))
    );
    // The footprint renderer: every BRDF at N = 16, 32, 64, and at 128 with its feature.
    let mut want: Vec<(usize, u32)> =
        [0, 10, 50, 200].iter().flat_map(|&e| [16, 32, 64].map(|n| (n, e))).collect();
    if cfg!(feature = "footprint-128") {
        want.extend([0, 10, 50, 200].map(|e| (128, e)));
    }
    let mut got = footprint::BAKED_SETS.to_vec();
    got.sort_unstable();
    want.sort_unstable();
    assert_eq!(got, want, "bmc::footprint::BAKED_SETS");
    let fp = row("| `bmc::FootprintRenderer<N, B>`");
    assert!(fp.contains("`Diffuse`, `Phong<10>`, `Phong<50>`, `Phong<200>` at N = 16, 32, 64; at N = 128 with the feature `footprint-128`"), "{fp}");
}
