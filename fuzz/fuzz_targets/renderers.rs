//! The renderers (`bmc::Renderer`, `bmc::GlossyRenderer`, `bmc::FootprintRenderer`) on
//! arbitrary f32 bits: nothing panics; a zero or non-finite direction is
//! `InvalidDirection` and every other one is accepted; every direction written is unit to
//! 10⁻⁶; a NaN or infinite sample is `InvalidRadiance`; otherwise the estimate is never NaN,
//! is `Σ wⱼYⱼ` (the renderer's own weights, summed in f64) to 10⁻⁴ of `Σ|wⱼYⱼ|` wherever that
//! sum is within f32, and `±∞` only where it exceeds `f32::MAX`; the error bar is never NaN or
//! negative.
#![no_main]

use fuzz_support::{direction_rejected, Bytes};
use libfuzzer_sys::fuzz_target;
use sphere_quadrature::bmc::footprint::{Brdf, Diffuse, FootprintRenderer, Phong};
use sphere_quadrature::bmc::{FootprintSize, GlossyRenderer, Renderer, Size};
use sphere_quadrature::{Error, Vec3};

#[path = "../../tests/shared/footprint_lookups.rs"]
mod footprint_lookups;
use footprint_lookups::Lookups;

/// Checks a direction error against the documented contract.
fn check_directions<R: core::fmt::Debug>(what: &str, r: &Result<R, Error>, dirs: &[Vec3]) {
    let rejected = dirs.iter().map(|&d| direction_rejected(d));
    if rejected.clone().any(|x| x == Some(true)) {
        assert_eq!(r.as_ref().err(), Some(&Error::InvalidDirection), "{what}: {dirs:?}");
    } else if rejected.clone().all(|x| x == Some(false)) {
        assert!(r.is_ok(), "{what}: {dirs:?}: {r:?}");
    }
}

fn check_unit(what: &str, out: &[Vec3]) {
    for d in out {
        let l = (f64::from(d.x).powi(2) + f64::from(d.y).powi(2) + f64::from(d.z).powi(2)).sqrt();
        assert!((l - 1.0).abs() <= 1e-6, "{what}: |d| = {l}");
    }
}

/// The estimate of finite samples against the f64 sum of the renderer's weights.
fn check_estimate(what: &str, got: Result<f32, Error>, y: &[f32], w: &[f32], factor: f64) {
    if y.iter().any(|v| !v.is_finite()) {
        assert_eq!(got, Err(Error::InvalidRadiance), "{what}");
        return;
    }
    let got = got.unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(!got.is_nan(), "{what}: NaN");
    let sum: f64 =
        y.iter().zip(w).map(|(&y, &w)| f64::from(y) * f64::from(w)).sum::<f64>() * factor;
    let abs: f64 =
        y.iter().zip(w).map(|(&y, &w)| (f64::from(y) * f64::from(w)).abs()).sum::<f64>() * factor;
    let max = f64::from(f32::MAX);
    if sum.abs() > max * 1.0001 {
        assert_eq!(got, f32::INFINITY.copysign(sum as f32), "{what}: want {sum:e}");
    } else if sum.abs() < max * 0.9999 {
        let err = (f64::from(got) - sum).abs();
        assert!(err <= 1e-4 * abs + 1e-44, "{what}: {got:e} against {sum:e} (Σ|wy| {abs:e})");
    }
}

fn samples(b: &mut Bytes, n: usize) -> Vec<f32> {
    // Most inputs: one value scaled over all samples (any scale), a few of them replaced by
    // arbitrary bits; the rest arbitrary bits throughout.
    let base = b.f32();
    let mixed = b.bool();
    (0..n)
        .map(
            |j| {
                if mixed && b.u8() % 8 != 0 {
                    base * (1.0 + (j % 7) as f32 / 8.0)
                } else {
                    b.f32()
                }
            },
        )
        .collect()
}

fn renderer<const N: usize>(b: &mut Bytes)
where
    Size<N>: sphere_quadrature::bmc::BakedSize,
{
    let r = Renderer::<N>::new();
    let n = b.vec3();
    let mut out = [Vec3::ZERO; N];
    let res = r.with_phase(b.u64()).fill_directions(n, &mut out);
    check_directions("Renderer::fill_directions", &res, &[n]);
    if res.is_ok() {
        check_unit("Renderer", &out);
    }
    let y = samples(b, N);
    let w = Renderer::<N>::weights();
    check_estimate(
        "Renderer::estimate",
        r.estimate(&core::array::from_fn(|j| y[j])),
        &y,
        w,
        core::f64::consts::PI,
    );
}

fn glossy<const N: usize, const E: u32>(b: &mut Bytes)
where
    Size<N>: sphere_quadrature::bmc::GlossySize<E>,
{
    let r = GlossyRenderer::<N, E>::new();
    let (n, m) = (b.vec3(), b.vec3());
    let mut out = [Vec3::ZERO; N];
    let res = r.fill_directions(n, m, &mut out);
    check_directions("GlossyRenderer::fill_directions", &res, &[n, m]);
    if res.is_err() {
        return;
    }
    check_unit("GlossyRenderer", &out);
    let y = samples(b, N);
    let mut w = [0.0f32; N];
    r.weights(n, m, &mut w).unwrap();
    check_estimate(
        "GlossyRenderer::estimate",
        r.estimate(n, m, &core::array::from_fn(|j| y[j])),
        &y,
        &w,
        1.0,
    );
}

fn footprint<const N: usize, B: Brdf>(b: &mut Bytes)
where
    Size<N>: FootprintSize<B>,
    FootprintRenderer<N, B>: Lookups<N>,
{
    let r = FootprintRenderer::<N, B>::new();
    let (n, m) = (b.vec3(), b.vec3());
    let mut out = [Vec3::ZERO; N];
    let res = r.fill(n, m, &mut out);
    check_directions("FootprintRenderer::fill_directions", &res, &[n, m]);
    if res.is_err() {
        return;
    }
    check_unit("FootprintRenderer", &out);
    let y = samples(b, N);
    let ya: [f32; N] = core::array::from_fn(|j| y[j]);
    let mut w = [0.0f32; N];
    r.weights_for(n, m, &mut w).unwrap();
    check_estimate("FootprintRenderer::estimate", r.estimate_for(n, m, &ya), &y, &w, 1.0);
    match r.estimate_with_variance_for(n, m, &ya) {
        Ok(e) => {
            assert!(y.iter().all(|v| v.is_finite()));
            assert_eq!(Ok(e.value), r.estimate_for(n, m, &ya), "the two calls' values differ");
            assert!(!e.variance.is_nan() && e.variance >= 0.0, "variance {e:?}");
            let unit = e.unit_variance.expect("one model for every channel");
            assert!(!unit.is_nan() && unit >= 0.0, "unit variance {e:?}");
        }
        Err(err) => {
            assert_eq!(err, Error::InvalidRadiance);
            assert!(y.iter().any(|v| !v.is_finite()));
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes::new(data);
    match b.u8() % 9 {
        0 => renderer::<16>(&mut b),
        1 => renderer::<64>(&mut b),
        2 => glossy::<16, 10>(&mut b),
        3 => glossy::<64, 50>(&mut b),
        4 => footprint::<16, Diffuse>(&mut b),
        5 => footprint::<32, Phong<10>>(&mut b),
        6 => footprint::<64, Phong<50>>(&mut b),
        7 => footprint::<32, Phong<200>>(&mut b),
        _ => footprint::<64, Diffuse>(&mut b),
    }
});
