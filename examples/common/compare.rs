//! Shared by `examples/probe.rs`, `examples/qmc_compare.rs`, `tests/envmap/envmap.rs` and the
//! evaluation programs (`eval/src/lib.rs`): ground truth on environment maps and the relative
//! RMSE of Monte Carlo, Sobol-QMC and this crate's QMC-SF.

use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use sphere_quadrature::qmc::LobeSampler;
use sphere_quadrature::{Lobe, RotationSequence, Vec3};

/// Luminance clamp of the `clamp` tier, in multiples of the map's solid-angle mean.
pub const CLAMP: f64 = 30.0;

/// Which integral.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    /// Irradiance `∫ L·max(0, n·ω) dω`.
    Diffuse,
    /// Normalised Phong lobe `∫ L·(e+1)/(2π)·max(0, r·ω)ᵉ dω` with this exponent.
    Glossy(f64),
}

impl Kind {
    pub fn exponent(self) -> f64 {
        match self {
            Kind::Diffuse => 1.0,
            Kind::Glossy(e) => e,
        }
    }

    fn lobe(self) -> Lobe {
        match self {
            Kind::Diffuse => Lobe::Cosine,
            Kind::Glossy(e) => Lobe::Phong(e as f32),
        }
    }

    /// The integral is `scale · E[L]` under the lobe's density: π for irradiance.
    fn scale(self) -> f64 {
        match self {
            Kind::Diffuse => std::f64::consts::PI,
            Kind::Glossy(_) => 1.0,
        }
    }
}

/// The map with each pixel's luminance clamped at `CLAMP` × the solid-angle mean (hue kept).
pub fn clamped(map: &EnvMap) -> EnvMap {
    let limit = CLAMP * luminance(map.mean_radiance());
    let pixels = map
        .pixels
        .iter()
        .map(|p| {
            let l = luminance([p[0] as f64, p[1] as f64, p[2] as f64]);
            if l > limit {
                let s = (limit / l) as f32;
                [p[0] * s, p[1] * s, p[2] * s]
            } else {
                *p
            }
        })
        .collect();
    EnvMap { width: map.width, height: map.height, pixels }
}

/// Per-pixel integration weights of every query axis, computed on all cores. They depend
/// only on the grid, so one set serves every map and tier: the ground truth of a map is
/// Σ weight × luminance.
pub fn weights(kind: Kind, axes: &[[f64; 3]], width: usize, height: usize) -> Vec<Vec<f64>> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let chunk = axes.len().div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        let handles: Vec<_> = axes
            .chunks(chunk)
            .map(|part| {
                scope.spawn(move || {
                    part.iter()
                        .map(|&a| match kind {
                            Kind::Diffuse => reference::truth::cosine_weights(width, height, a),
                            Kind::Glossy(e) => reference::truth::phong_weights(width, height, a, e),
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles.into_iter().flat_map(|h| h.join().expect("weights thread")).collect()
    })
}

/// Ground-truth luminance integral of `map` for every axis.
pub fn truths(map: &EnvMap, weights: &[Vec<f64>]) -> Vec<f64> {
    let lum: Vec<f64> =
        map.pixels.iter().map(|p| luminance([p[0] as f64, p[1] as f64, p[2] as f64])).collect();
    weights.iter().map(|w| w.iter().zip(&lum).map(|(a, b)| a * b).sum()).collect()
}

/// Relative RMSE (RMSE over all estimates / mean |truth|) of each estimator at one `N`.
#[derive(Clone, Copy, Debug, Default)]
pub struct Errors {
    pub mc: f64,
    pub sobol: f64,
    pub sf: f64,
}

/// Estimates every axis `draws` times with independent randomisation (new random
/// directions for MC, a new Owen scramble for Sobol, a new rotation about the axis for SF)
/// and returns the relative RMSE of each estimator.
pub fn evaluate(
    map: &EnvMap,
    kind: Kind,
    axes: &[[f64; 3]],
    truth: &[f64],
    n: usize,
    draws: usize,
    seed: u64,
) -> Errors {
    let lum = |d: [f64; 3]| luminance(map.radiance(d));
    let e = kind.exponent();
    let mut rng = Rng::new(seed ^ n as u64);
    let mut rotations = RotationSequence::new(seed.wrapping_add(n as u64));
    let mut se = Errors::default();
    for (q, (&axis, &t)) in axes.iter().zip(truth).enumerate() {
        let axis32 = Vec3::new(axis[0] as f32, axis[1] as f32, axis[2] as f32);
        for draw in 0..draws {
            let mc = kind.scale() * reference::peers::monte_carlo(lum, axis, e, n, &mut rng);
            let scramble =
                (seed as u32) ^ ((q * draws + draw) as u32).wrapping_mul(0x9E37_79B9) ^ n as u32;
            let sobol = kind.scale() * reference::peers::sobol(lum, axis, e, n as u32, scramble);
            let sampler = LobeSampler::new(axis32, kind.lobe(), n, rotations.next_phase())
                .expect("unit axis and valid lobe");
            let mean = sampler
                .integrate(|d| lum([d.x as f64, d.y as f64, d.z as f64]) as f32)
                .expect("finite radiance") as f64
                / kind.lobe().integral() as f64;
            let sf = kind.scale() * mean;
            se.mc += (mc - t).powi(2);
            se.sobol += (sobol - t).powi(2);
            se.sf += (sf - t).powi(2);
        }
    }
    let mean_abs = truth.iter().map(|t| t.abs()).sum::<f64>() / truth.len() as f64;
    let rel = |s: f64| (s / (truth.len() * draws) as f64).sqrt() / mean_abs;
    Errors { mc: rel(se.mc), sobol: rel(se.sobol), sf: rel(se.sf) }
}
