//! What `cargo eval sensors` and `cargo writer sensor_priors` share: the benchmark's sensor
//! layouts, the crate's fit of a layout's readings, the maps' SH power spectra, and the
//! learned priors of `tables/sensor_priors.rs` computed from the training maps.

// Per-degree and per-sensor loops read clearer with their indices.
#![allow(clippy::needless_range_loop)]

use crate::{cli, tiers};

use std::f64::consts::PI;
use std::fmt::Write as _;

use reference::envmap::{luminance, EnvMap};
use reference::rng::Rng;
use reference::sh::{legendre, real_sh};
use reference::vec::{mat_mul_vec, normalize};
use sphere_quadrature::footprint::Kind;
use sphere_quadrature::layout::{
    LayoutProbe, Mean as CrateMean, Noise, Prior, Response, Sensor, DEGREES,
};
use sphere_quadrature::Vec3;

/// The lighting tiers the priors are learned on (`clamp` the default's).
pub const TIERS: [&str; 2] = ["clamp", "smooth"];

/// Legendre degrees summed in the f64 series.
pub const L: usize = 48;

pub const NOISES: [f64; 3] = [0.0, 0.01, 0.05];

pub const SEED: u64 = 0x5e45_0a11;

#[derive(Clone)]
pub struct Layout {
    pub name: &'static str,
    pub dirs: Vec<[f64; 3]>,
    /// Cosine power of each sensor's response.
    pub power: Vec<u32>,
    /// Where a layout that does not cover the sphere looks (before its rotation about `z`):
    /// it is queried at the normals of that hemisphere only.
    pub look: Option<[f64; 3]>,
}

pub const UP: Option<[f64; 3]> = Some([0.0, 0.0, 1.0]);

pub fn elevated(elevation_deg: f64, azimuth_deg: f64) -> [f64; 3] {
    let (e, a) = (elevation_deg.to_radians(), azimuth_deg.to_radians());
    [e.cos() * a.cos(), e.cos() * a.sin(), e.sin()]
}

pub fn layouts() -> Vec<Layout> {
    let cube: Vec<[f64; 3]> = vec![
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ];
    let mut dome = vec![[0.0, 0.0, 1.0]];
    dome.extend((0..4).map(|k| elevated(45.0, 90.0 * k as f64)));
    let mut hemi = vec![[0.0, 0.0, 1.0]];
    hemi.extend((0..6).map(|k| elevated(30.0, 60.0 * k as f64)));
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut ico = Vec::new();
    for s1 in [-1.0, 1.0] {
        for s2 in [-1.0, 1.0] {
            ico.push(normalize([0.0, s1, s2 * phi]));
            ico.push(normalize([s1, s2 * phi, 0.0]));
            ico.push(normalize([s2 * phi, 0.0, s1]));
        }
    }
    let sf: Vec<[f64; 3]> = {
        let p = sphere_quadrature::probe::Probe::<16>::new();
        p.directions().iter().map(|d| [d.x as f64, d.y as f64, d.z as f64]).collect()
    };
    let tetra: Vec<[f64; 3]> =
        [[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]]
            .into_iter()
            .map(normalize)
            .collect();
    let corners: Vec<[f64; 3]> = (0..8)
        .map(|k| {
            let s = |b: usize| if k >> b & 1 == 1 { -1.0 } else { 1.0 };
            normalize([s(0), s(1), s(2)])
        })
        .collect();
    let ring: Vec<[f64; 3]> = (0..8).map(|k| elevated(20.0, 45.0 * k as f64)).collect();
    let mut random = Rng::new(SEED ^ 0x0a4d_0010);
    let rand10: Vec<[f64; 3]> = (0..10).map(|_| random.uniform_sphere()).collect();
    // On a wall facing +x: one sensor along +x and five at 60° from it, 72° apart (the first
    // straight above it).
    let mut wall = vec![[1.0, 0.0, 0.0]];
    wall.extend((0..5).map(|k| {
        let (s, c) = (90.0 + 72.0 * k as f64).to_radians().sin_cos();
        let (st, ct) = 60f64.to_radians().sin_cos();
        [ct, st * c, st * s]
    }));
    vec![
        Layout { name: "cube6", dirs: cube.clone(), power: vec![1; 6], look: None },
        Layout { name: "dome5", dirs: dome, power: vec![1; 5], look: UP },
        Layout { name: "hemi7", dirs: hemi, power: vec![1; 7], look: UP },
        Layout { name: "ico12", dirs: ico, power: vec![1; 12], look: None },
        Layout { name: "sf16", dirs: sf, power: vec![1; 16], look: None },
        Layout {
            name: "cube6-cos2",
            dirs: cube.clone(),
            power: vec![2, 2, 2, 2, 1, 1],
            look: None,
        },
        Layout { name: "tetra4", dirs: tetra, power: vec![1; 4], look: None },
        Layout { name: "cube5", dirs: cube[..5].to_vec(), power: vec![1; 5], look: UP },
        Layout { name: "ring8", dirs: ring, power: vec![1; 8], look: UP },
        Layout { name: "corners8", dirs: corners, power: vec![1; 8], look: None },
        Layout { name: "rand10", dirs: rand10, power: vec![1; 10], look: None },
        Layout { name: "wall6", dirs: wall, power: vec![1; 6], look: Some([1.0, 0.0, 0.0]) },
    ]
}

/// `g_l` of the normalised cosine power `P`.
pub fn gains(p: u32) -> Vec<f64> {
    (0..=L).map(|l| Kind::CosinePower { exponent: p }.gain(l).expect("gain")).collect()
}

/// The clamped cosine's zonal factors `c_l` (`c₀ = π`).
pub fn cosine_factors() -> Vec<f64> {
    gains(1).iter().map(|g| g * PI).collect()
}

/// One layout's fixed geometry for the GP.
pub struct Geometry {
    pub g: Vec<Vec<f64>>,
    pub dirs: Vec<[f64; 3]>,
    pub c: Vec<f64>,
}

/// The crate's layout probe at this layout's size.
pub fn crate_fit_k<const K: usize>(
    geo: &Geometry,
    powers: &[u32],
    priors: &[Prior],
    relative: f64,
    y: &[f64],
    normals: &[[f64; 3]],
) -> Option<CrateFit> {
    let sensors: [Sensor; K] = std::array::from_fn(|i| {
        let d = geo.dirs[i];
        Sensor::new(
            Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32),
            Response::CosinePower(powers[i] as f32),
        )
    });
    let noise = Noise { absolute: 0.0, relative: relative as f32 };
    let readings: [f32; K] = std::array::from_fn(|i| y[i] as f32);
    // With several priors, the one of the highest REML likelihood for these readings.
    let mut probe: Option<LayoutProbe<K>> = None;
    for prior in priors {
        let mut candidate = LayoutProbe::<K>::new(&sensors, *prior, noise).ok()?;
        candidate.update(&readings).ok()?;
        if probe.as_ref().is_none_or(|p| candidate.log_likelihood() > p.log_likelihood()) {
            probe = Some(candidate);
        }
    }
    let probe = probe?;
    let mut fit = CrateFit { values: Vec::new(), exact: Vec::new(), averaged: Vec::new() };
    for n in normals {
        let v = Vec3::new(n[0] as f32, n[1] as f32, n[2] as f32);
        let e = probe.irradiance(v).ok()?;
        fit.values.push(e.value as f64);
        fit.averaged.push(e.variance as f64);
        fit.exact.push(probe.irradiance_variance(v).ok()? as f64);
    }
    Some(fit)
}

/// The crate probe's values at the normals, with the exact variance at each
/// (`irradiance_variance`) and the direction-averaged one that `irradiance` returns.
pub struct CrateFit {
    pub values: Vec<f64>,
    pub exact: Vec<f64>,
    pub averaged: Vec<f64>,
}

pub fn crate_fit(
    geo: &Geometry,
    powers: &[u32],
    prior: &[Prior],
    relative: f64,
    y: &[f64],
    normals: &[[f64; 3]],
) -> Option<CrateFit> {
    match y.len() {
        4 => crate_fit_k::<4>(geo, powers, prior, relative, y, normals),
        5 => crate_fit_k::<5>(geo, powers, prior, relative, y, normals),
        6 => crate_fit_k::<6>(geo, powers, prior, relative, y, normals),
        7 => crate_fit_k::<7>(geo, powers, prior, relative, y, normals),
        8 => crate_fit_k::<8>(geo, powers, prior, relative, y, normals),
        10 => crate_fit_k::<10>(geo, powers, prior, relative, y, normals),
        12 => crate_fit_k::<12>(geo, powers, prior, relative, y, normals),
        16 => crate_fit_k::<16>(geo, powers, prior, relative, y, normals),
        _ => None,
    }
}

pub fn spectrum_f32(k: &[f64]) -> [f32; DEGREES] {
    std::array::from_fn(|l| k.get(l).copied().unwrap_or(0.0) as f32)
}

/// Rotationally averaged SH power `C_l` (l ≤ 24) of `lum/mean − profile(z)` on a 128×64
/// downsample of `map` (`profile` empty: of `lum/mean`).
pub fn spectrum(map: &EnvMap, profile: &[f64]) -> Vec<f64> {
    const LS: usize = DEGREES - 1;
    let m = tiers::downsample(map, 128, 64);
    let mean = luminance(m.mean_radiance());
    let mut c = vec![0.0; (LS + 1) * (LS + 1)];
    for v in 0..m.height {
        let omega = m.pixel_solid_angle(v);
        for u in 0..m.width {
            let d = m.pixel_direction(u, v);
            let prof: f64 = (0..profile.len()).map(|l| profile[l] * legendre(l, d[2])).sum();
            let f = luminance(m.pixel(u, v)) / mean - prof;
            let mut k = 0;
            for l in 0..=LS {
                for mm in -(l as i64)..=l as i64 {
                    c[k] += f * omega * real_sh(l, mm, d);
                    k += 1;
                }
            }
        }
    }
    let mut out = vec![0.0; L + 1];
    let mut k = 0;
    for l in 0..=LS {
        let mut p = 0.0;
        for _ in 0..(2 * l + 1) {
            p += c[k] * c[k];
            k += 1;
        }
        out[l] = p / (2 * l + 1) as f64;
    }
    out
}

/// The second moments `c_a·c_b` (row-major 3×3) of a map's zonal coefficients `c₀₀, c₁₀, c₂₀`
/// of luminance over its mean (orthonormal harmonics about `+z`).
pub fn zonal_moments(map: &EnvMap) -> Vec<f64> {
    let mut c = [0.0f64; 3];
    let mean = luminance(map.mean_radiance());
    for v in 0..map.height {
        let omega = map.pixel_solid_angle(v);
        for u in 0..map.width {
            let d = map.pixel_direction(u, v);
            let f = luminance(map.pixel(u, v)) / mean;
            for (l, cl) in c.iter_mut().enumerate() {
                *cl += f * omega * real_sh(l, 0, d);
            }
        }
    }
    (0..9).map(|k| c[k / 3] * c[k % 3]).collect()
}

/// The prior of light from above from the maps `use_maps`: degrees ≤ 2 flat with the zonal
/// correlations of ½M + ½·diag(C₀, C₁, C₂), above them the spectrum over
/// τ = (C₀ + 3C₁ + 5C₂)/9.
pub fn sky_prior(
    spectra: &[Vec<f64>],
    moments: &[Vec<f64>],
    use_maps: &[usize],
) -> (Vec<f64>, [f64; 3]) {
    let n = use_maps.len() as f64;
    let spec: Vec<f64> = (0..spectra[0].len())
        .map(|l| use_maps.iter().map(|&m| spectra[m][l]).sum::<f64>() / n)
        .collect();
    let mom: Vec<f64> =
        (0..9).map(|k| use_maps.iter().map(|&m| moments[m][k]).sum::<f64>() / n).collect();
    let s_ab = |a: usize, b: usize| 0.5 * mom[3 * a + b] + if a == b { 0.5 * spec[a] } else { 0.0 };
    let rho = |a: usize, b: usize| s_ab(a, b) / (s_ab(a, a) * s_ab(b, b)).sqrt();
    let tau = (spec[0] + 3.0 * spec[1] + 5.0 * spec[2]) / 9.0;
    let mut sky: Vec<f64> = spec.iter().map(|c| c / tau).collect();
    sky[0] = 1.0;
    sky[1] = 1.0;
    sky[2] = 1.0;
    (sky, [rho(0, 1), rho(1, 2), rho(0, 2)])
}

/// |error|/σ (exact variance) of the crate's probe with `prior` on the upward layouts of the
/// benchmark over `map`: 8 turns about z, 32 normals above, noise 0, 1 and 5 %.
pub fn upward_errors(map: &EnvMap, prior: Prior, seed: u64) -> Vec<f64> {
    let mut rng = Rng::new(SEED ^ 0xca11 ^ seed);
    let normals: Vec<[f64; 3]> = (0..32).map(|_| rng.uniform_hemisphere()).collect();
    let lum: Vec<f64> =
        map.pixels.iter().map(|p| luminance([p[0] as f64, p[1] as f64, p[2] as f64])).collect();
    let integrate = |w: &[f64]| w.iter().zip(&lum).map(|(a, b)| a * b).sum::<f64>();
    let truth: Vec<f64> = normals
        .iter()
        .map(|&n| integrate(&reference::truth::cosine_weights(map.width, map.height, n)))
        .collect();
    let c = cosine_factors();
    let mut out = Vec::new();
    // The two upward layouts the sky priors were learned on (the later ones are held out).
    for lay in layouts().into_iter().filter(|l| matches!(l.name, "dome5" | "hemi7")) {
        for r in 0..8 {
            let (sn, cs) = (2.0 * PI * (r as f64 + 0.3) / 8.0).sin_cos();
            let rot = [[cs, -sn, 0.0], [sn, cs, 0.0], [0.0, 0.0, 1.0]];
            let geo = Geometry {
                g: lay.power.iter().map(|&p| gains(p)).collect(),
                dirs: lay.dirs.iter().map(|&d| mat_mul_vec(rot, d)).collect(),
                c: c.clone(),
            };
            let exact: Vec<f64> = geo
                .dirs
                .iter()
                .map(|&d| {
                    integrate(&reference::truth::cosine_weights(map.width, map.height, d)) / PI
                })
                .collect();
            for eta in NOISES {
                let y: Vec<f64> = exact
                    .iter()
                    .map(|v| {
                        let (u1, u2) = (rng.next_f64().max(1e-300), rng.next_f64());
                        v * (1.0 + eta * (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos())
                    })
                    .collect();
                if let Some(f) = crate_fit(&geo, &lay.power, &[prior], eta, &y, &normals) {
                    for q in 0..normals.len() {
                        out.push((f.values[q] - truth[q]).abs() / f.exact[q].max(1e-300).sqrt());
                    }
                }
            }
        }
    }
    out
}

/// The file of the crate's learned priors.
pub const LEARNED: &str = "tables/sensor_priors.rs";

/// The crate's learned priors from the training maps (examples/envmaps/), as the Rust
/// source of `tables/sensor_priors.rs`: per tier (`clamp` as the default, `smooth`), the mean
/// SH power spectrum of luminance over its mean (degrees < DEGREES, on a 128×64 downsample),
/// and the prior of light from above (below); in f64, rounded once to f32.
pub fn learned_priors(threads: usize) -> Result<String, String> {
    let paths = cli::bundled_maps(&cli::TRAINING_MAPS);
    let maps = tiers::load_clamp_smooth(&paths, threads)?;
    let average = |f: &dyn Fn(&EnvMap) -> Vec<f64>, t: usize| -> Vec<f64> {
        let all: Vec<Vec<f64>> = maps.iter().map(|m| f(&m[t])).collect();
        (0..all[0].len())
            .map(|l| all.iter().map(|p| p[l]).sum::<f64>() / all.len() as f64)
            .collect()
    };
    let list = |v: &[f64], n: usize| -> String {
        v.iter().take(n).map(|x| format!("{:?}", *x as f32)).collect::<Vec<_>>().join(", ")
    };
    let mut out = String::from(
        "// The learned priors of `layout::Prior`, included by src/layout/learned.rs: generated by\n\
         // `cargo writer sensor_priors -- --write` from the bundled training maps (apartment,\n\
         // bridge, forest, lab) in f64, rounded once to f32. Do not edit; CI regenerates and\n\
         // compares it (`cargo writer sensor_priors`).\n\n",
    );
    for (t, tier) in ["ENVIRONMENT", "SMOOTH"].iter().enumerate() {
        let spec = average(&|m: &EnvMap| spectrum(m, &[]), t);
        let _ = writeln!(out, "/// Spectrum `K_l` of the {} tier.", TIERS[t]);
        let _ = writeln!(
            out,
            "pub(super) const {tier}_SPECTRUM: [f32; super::DEGREES] = [{}];",
            list(&spec, DEGREES)
        );
        // Light from above: a flat prior on degrees ≤ 2 (K₀ = K₁ = K₂ = 1) with the zonal
        // correlations of S = ½M + ½·diag(C₀, C₁, C₂), M the maps' second moments of their
        // zonal coefficients (c₀₀, c₁₀, c₂₀) of luminance over its mean, and above degree 2
        // the spectrum over τ = (C₀ + 3C₁ + 5C₂)/9, the mean power per coefficient of
        // degrees ≤ 2.
        let spectra: Vec<Vec<f64>> = maps.iter().map(|m| spectrum(&m[t], &[])).collect();
        let moments: Vec<Vec<f64>> = maps.iter().map(|m| zonal_moments(&m[t])).collect();
        let all: Vec<usize> = (0..maps.len()).collect();
        let (sky, zonal) = sky_prior(&spectra, &moments, &all);
        let _ = writeln!(
            out,
            "/// Spectrum of light from above (flat to degree 2), {} tier.",
            TIERS[t]
        );
        let _ = writeln!(
            out,
            "pub(super) const {tier}_SKY_SPECTRUM: [f32; super::DEGREES] = [{}];",
            list(&sky, DEGREES)
        );
        let _ = writeln!(out, "/// Zonal correlations of light from above, {} tier.", TIERS[t]);
        let _ =
            writeln!(out, "pub(super) const {tier}_SKY_ZONAL: [f32; 3] = [{}];", list(&zonal, 3));
        // Its variance factor, leave one map out: the prior of the other three on the upward
        // layouts (rotations about z, normals above) at noise 0, 1 and 5 %, the smallest
        // power of 2^¼ for which 2σ holds for 95 % of the errors.
        let calibrate = |name: &str, isotropic: bool| -> f64 {
            let mut ratios: Vec<f64> = Vec::new();
            for m in 0..maps.len() {
                let others: Vec<usize> = all.iter().copied().filter(|&o| o != m).collect();
                let (sky, zonal) = sky_prior(&spectra, &moments, &others);
                let zonal = if isotropic { [0.0; 3] } else { zonal };
                let prior = Prior {
                    spectrum: spectrum_f32(&sky),
                    zonal: [zonal[0] as f32, zonal[1] as f32, zonal[2] as f32],
                    mean: CrateMean::Zero,
                    variance_scale: 1.0,
                };
                ratios.extend(upward_errors(&maps[m][t], prior, m as u64));
            }
            ratios.sort_by(f64::total_cmp);
            let q95 = ratios[(0.95 * ratios.len() as f64) as usize];
            let mut k = -24i32;
            while 2f64.powf(k as f64 / 4.0) < (q95 / 2.0).powi(2) {
                k += 1;
            }
            let calibration = 2f64.powf(k as f64 / 4.0);
            eprintln!(
                "{} tier, {name}: 95 % of |error|/σ ≤ {q95:.3} over {} errors: variance \
                 factor 2^({k}/4) = {calibration:.4}",
                TIERS[t],
                ratios.len()
            );
            calibration
        };
        let calibration = calibrate("light from above", false);
        let _ = writeln!(
            out,
            "/// Variance factor of light from above (leave one map out), {} tier.",
            TIERS[t]
        );
        let _ = writeln!(
            out,
            "pub(super) const {tier}_SKY_CALIBRATION: f32 = {:?};",
            calibration as f32
        );
        // The one-sided prior: the same spectrum, isotropic; its variance factor likewise.
        let calibration = calibrate("one-sided", true);
        let _ = writeln!(
            out,
            "/// Variance factor of the one-sided prior (leave one map out), {} tier.",
            TIERS[t]
        );
        let _ = writeln!(
            out,
            "pub(super) const {tier}_ONE_SIDED_CALIBRATION: f32 = {:?};",
            calibration as f32
        );
    }
    rustfmt(&out)
}

/// The text as `rustfmt` (of the toolchain, the workspace's `rustfmt.toml`) lays it out, so
/// that the committed file passes `cargo fmt --check`.
pub fn rustfmt(text: &str) -> Result<String, String> {
    use std::io::Write as _;
    let mut child = std::process::Command::new("rustfmt")
        .args(["--edition", "2021", "--emit", "stdout"])
        .current_dir(cli::repo_root())
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .map_err(|e| format!("rustfmt: {e}"))?;
    child
        .stdin
        .take()
        .ok_or("rustfmt: no stdin")?
        .write_all(text.as_bytes())
        .map_err(|e| format!("rustfmt: {e}"))?;
    let output = child.wait_with_output().map_err(|e| format!("rustfmt: {e}"))?;
    if !output.status.success() {
        return Err("rustfmt failed on the generated priors".into());
    }
    String::from_utf8(output.stdout).map_err(|e| format!("rustfmt: {e}"))
}
