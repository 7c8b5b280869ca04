//! Scenes (a tier's map or a synthetic mixture) and their ground truth per query.

use reference::envmap::{luminance, EnvMap};

use super::{FIS_BIAS, MIXTURE_SHARPNESS, TRUTH_TOL};
use crate::cli::TRAINING_MAPS;
use crate::parallel::parallel_map;
use crate::renderer_engine as engine;
use crate::renderer_engine::{Brdf, LobeFrame, LumPyramid, Query, Rule};
use crate::tiers;

pub enum Light {
    Map { map: EnvMap, lum: Vec<f64>, pyramid: LumPyramid },
    Mixture(tiers::Mixture),
}

pub struct Scene {
    pub name: String,
    pub tier: usize,
    pub held_out: bool,
    pub light: Light,
}

impl Scene {
    pub fn map(tier: usize, name: &str, map: EnvMap) -> Self {
        let lum =
            map.pixels.iter().map(|p| luminance([p[0] as f64, p[1] as f64, p[2] as f64])).collect();
        let pyramid = LumPyramid::new(&map);
        Self {
            name: name.into(),
            tier,
            held_out: !TRAINING_MAPS.contains(&name),
            light: Light::Map { map, lum, pyramid },
        }
    }

    pub fn lum(&self, d: [f64; 3]) -> f64 {
        match &self.light {
            Light::Map { map, lum, .. } => {
                let (u, v) = map.pixel_of(d);
                lum[v * map.width + u]
            }
            Light::Mixture(m) => m.value(reference::vec::normalize(d)),
        }
    }

    /// FIS read for a sample of solid angle `omega_s`.
    pub fn filtered(&self, d: [f64; 3], omega_s: f64) -> f64 {
        match &self.light {
            Light::Map { pyramid, .. } => pyramid.filtered(d, omega_s, FIS_BIAS),
            Light::Mixture(m) => {
                // Bilinear read of a texel of area A = 4^bias·Ω_s: per-axis variance A/4, the
                // SG's is 1/λ_f, so λ_f = 4/A.
                let lf = 4.0 / (4f64.powf(FIS_BIAS) * omega_s);
                let d = reference::vec::normalize(d);
                m.constant
                    + m.lobes
                        .iter()
                        .map(|g| engine::sg_filtered(g.axis, g.sharpness, g.amplitude, d, lf))
                        .sum::<f64>()
            }
        }
    }
}

/// Ground truth of every scene for every query: `[scene][query]`.
pub fn truths(brdf: Brdf, scenes: &[Scene], queries: &[Query], threads: usize) -> Vec<Vec<f64>> {
    let mut out = vec![Vec::new(); scenes.len()];
    // Maps, grouped by grid size: one weight vector per (query, grid) serves the group.
    let mut sizes: Vec<(usize, usize)> = Vec::new();
    for s in scenes {
        if let Light::Map { map, .. } = &s.light {
            if !sizes.contains(&(map.width, map.height)) {
                sizes.push((map.width, map.height));
            }
        }
    }
    for (w, h) in sizes {
        let members: Vec<usize> = (0..scenes.len())
            .filter(|&i| matches!(&scenes[i].light, Light::Map { map, .. } if (map.width, map.height) == (w, h)))
            .collect();
        let per_query = parallel_map(queries, threads, |_, q| {
            let weights = match brdf {
                Brdf::Diffuse => reference::truth::cosine_weights(w, h, q.n),
                Brdf::Phong(e) => engine::phong_cos_weights(w, h, Some(q.n), q.r, e, TRUTH_TOL),
            };
            members
                .iter()
                .map(|&i| match &scenes[i].light {
                    Light::Map { lum, .. } => weights.iter().zip(lum).map(|(a, b)| a * b).sum(),
                    Light::Mixture(_) => unreachable!("members are maps"),
                })
                .collect::<Vec<f64>>()
        });
        for (k, &i) in members.iter().enumerate() {
            out[i] = per_query.iter().map(|v| v[k]).collect();
        }
    }
    let mixtures: Vec<usize> =
        (0..scenes.len()).filter(|&i| matches!(scenes[i].light, Light::Mixture(_))).collect();
    let values = parallel_map(&mixtures, threads, |_, &i| {
        let Light::Mixture(m) = &scenes[i].light else { unreachable!("a mixture") };
        queries
            .iter()
            .map(|q| match brdf {
                Brdf::Diffuse => m.irradiance(q.n),
                Brdf::Phong(_) => {
                    let frame = LobeFrame::new(brdf, q);
                    Rule::new(brdf, &frame, MIXTURE_SHARPNESS, 2.0).integrate(|x| m.value(x))
                }
            })
            .collect::<Vec<f64>>()
    });
    for (&i, v) in mixtures.iter().zip(values) {
        out[i] = v;
    }
    out
}
