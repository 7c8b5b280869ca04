//! Lighting tiers of `eval/src/bin/accuracy.rs` beyond `raw` and `clamp` (those are in
//! `compare.rs`): the `smooth` tier (a clamped map box-downsampled and convolved with a
//! normalised spherical Gaussian) and the `synthetic` tier (random spherical-Gaussian
//! mixtures with exact irradiance).

use std::f64::consts::PI;
use std::path::PathBuf;

use reference::analytic::SgLight;
use reference::envmap::EnvMap;
use reference::rng::Rng;
use reference::vec::dot;

/// Width of the `smooth` tier's grid.
pub const SMOOTH_WIDTH: usize = 128;
/// Height of the `smooth` tier's grid.
pub const SMOOTH_HEIGHT: usize = 64;
/// Sharpness of the `smooth` tier's convolution kernel `exp(λ(ω·ω′ − 1))`.
pub const SMOOTH_SHARPNESS: f64 = 10.0;

/// `map` box-downsampled to `width`×`height`: every output pixel is the solid-angle weighted
/// mean of the input pixels whose centres fall in its box (the integral over the sphere is
/// kept up to the boxes' edges).
pub fn downsample(map: &EnvMap, width: usize, height: usize) -> EnvMap {
    let mut acc = vec![[0.0f64; 3]; width * height];
    let mut area = vec![0.0f64; width * height];
    for v in 0..map.height {
        // The centre θ = π(v + ½)/H lies in output row ⌊(2v + 1)·h/(2H)⌋; same for columns.
        let row = ((2 * v + 1) * height / (2 * map.height)).min(height - 1);
        let omega = map.pixel_solid_angle(v);
        for u in 0..map.width {
            let col = ((2 * u + 1) * width / (2 * map.width)).min(width - 1);
            let k = row * width + col;
            let p = map.pixel(u, v);
            for c in 0..3 {
                acc[k][c] += omega * p[c];
            }
            area[k] += omega;
        }
    }
    let pixels = acc
        .iter()
        .zip(&area)
        .map(|(s, &a)| {
            if a > 0.0 {
                [(s[0] / a) as f32, (s[1] / a) as f32, (s[2] / a) as f32]
            } else {
                [0.0; 3]
            }
        })
        .collect();
    EnvMap::new(width, height, pixels)
}

/// `L′(ω) = Σ_q L(q)·Ω_q·exp(λ(ω·ω_q − 1)) / Σ_q Ω_q·exp(λ(ω·ω_q − 1))` at every pixel
/// centre `ω`, the sums over all pixels `q` with their solid angles `Ω_q`: the map convolved
/// with the normalised spherical Gaussian of sharpness `λ`, as a direct sum. The normaliser
/// is the same discrete sum, so a constant map stays constant exactly.
///
/// The kernel depends only on the two rows and the column difference, so it is tabulated
/// once (`H²·W` values) and the `(W·H)²` sum is multiply-adds.
pub fn convolve(map: &EnvMap, sharpness: f64) -> EnvMap {
    let (w, h) = (map.width, map.height);
    // kernel[(vp·h + vq)·w + du] = Ω_q · exp(λ(ω_p·ω_q − 1)) for pixels in rows vp, vq whose
    // columns differ by du.
    let mut kernel = vec![0.0f64; h * h * w];
    for vp in 0..h {
        let p = map.pixel_direction(0, vp);
        for vq in 0..h {
            let omega = map.pixel_solid_angle(vq);
            for du in 0..w {
                let q = map.pixel_direction(du, vq);
                kernel[(vp * h + vq) * w + du] = omega * (sharpness * (dot(p, q) - 1.0)).exp();
            }
        }
    }
    let src: Vec<[f64; 3]> =
        map.pixels.iter().map(|p| [p[0] as f64, p[1] as f64, p[2] as f64]).collect();
    let mut pixels = Vec::with_capacity(w * h);
    for vp in 0..h {
        for up in 0..w {
            let mut sum = [0.0f64; 3];
            let mut norm = 0.0f64;
            for vq in 0..h {
                let row = &kernel[(vp * h + vq) * w..(vp * h + vq + 1) * w];
                let pix = &src[vq * w..(vq + 1) * w];
                for (uq, l) in pix.iter().enumerate() {
                    let k = row[(uq + w - up) % w];
                    sum[0] += k * l[0];
                    sum[1] += k * l[1];
                    sum[2] += k * l[2];
                    norm += k;
                }
            }
            pixels.push([(sum[0] / norm) as f32, (sum[1] / norm) as f32, (sum[2] / norm) as f32]);
        }
    }
    EnvMap::new(w, h, pixels)
}

/// The `smooth` tier of a (clamped) map: downsampled to 128×64, then convolved with the
/// normalised spherical Gaussian of sharpness 10.
pub fn smooth(clamped: &EnvMap) -> EnvMap {
    convolve(&downsample(clamped, SMOOTH_WIDTH, SMOOTH_HEIGHT), SMOOTH_SHARPNESS)
}

/// The maps at `paths`, each as its `clamp` and `smooth` tiers, loaded on `threads` workers.
pub fn load_clamp_smooth(paths: &[PathBuf], threads: usize) -> Result<Vec<[EnvMap; 2]>, String> {
    crate::parallel::parallel_map(paths, threads, |_, path| {
        let map = EnvMap::load(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let clamp = crate::compare::clamped(&map);
        let smooth = smooth(&clamp);
        Ok::<_, String>([clamp, smooth])
    })
    .into_iter()
    .collect()
}

/// A `synthetic` tier light: a constant plus a sum of spherical Gaussians.
#[derive(Clone, Debug)]
pub struct Mixture {
    /// The lobes `a·exp(λ(μ·ω − 1))`.
    pub lobes: Vec<SgLight>,
    /// The constant term `c`.
    pub constant: f64,
}

impl Mixture {
    /// Radiance in direction `dir` (unit).
    pub fn value(&self, dir: [f64; 3]) -> f64 {
        self.constant + self.lobes.iter().map(|g| g.value(dir)).sum::<f64>()
    }

    /// Exact irradiance `∫ L(ω)·max(0, n·ω) dω`: `π·c` plus each lobe's (by
    /// `SgLight::irradiance`).
    pub fn irradiance(&self, n: [f64; 3]) -> f64 {
        PI * self.constant + self.lobes.iter().map(|g| g.irradiance(n)).sum::<f64>()
    }
}

/// `count` seeded mixtures: 1–4 lobes (uniform count) with uniform random axes, sharpness
/// uniform in [2, 20] and amplitude uniform in [0.2, 1], plus a constant uniform in [0, 0.5].
pub fn mixtures(count: usize, seed: u64) -> Vec<Mixture> {
    let mut rng = Rng::new(seed);
    (0..count)
        .map(|_| {
            let lobes = 1 + (rng.next_u64() % 4) as usize;
            let lobes = (0..lobes)
                .map(|_| {
                    let axis = rng.uniform_sphere();
                    let sharpness = 2.0 + 18.0 * rng.next_f64();
                    let amplitude = 0.2 + 0.8 * rng.next_f64();
                    SgLight { axis, sharpness, amplitude }
                })
                .collect();
            Mixture { lobes, constant: 0.5 * rng.next_f64() }
        })
        .collect()
}
