//! The crate's footprint renderer (`bmc::FootprintRenderer`) and the split-sum peer on one
//! scene: the lookups a renderer reads (the map's `MipPyramid`, the map itself exactly, or a
//! mixture convolved with the footprint in closed form), and the renderer of each baked
//! `(N, e)` as a plain function.

use reference::envmap::luminance;
use sphere_quadrature::bmc::footprint::{Diffuse, FootprintRenderer, Phong};
use sphere_quadrature::bmc::{FootprintSize, Size};
use sphere_quadrature::envmap::{EquirectMap, MipPyramid};
use sphere_quadrature::footprint::Kind;
use sphere_quadrature::{Estimate, Vec3};

use super::scenes::{Light, Scene};
use crate::renderer_engine as engine;

/// The crate's renderer on one query `(n, r)`: `(estimate, variance)` from the lookups
/// `read(direction, sharpness)`.
pub type CrateFn = fn(Vec3, Vec3, &dyn Fn(Vec3, u32) -> f64) -> (f64, f64);

/// The lookups `read(direction, sharpness)` of each direction through its footprint.
fn lookups<const N: usize>(
    dirs: &[Vec3; N],
    kinds: [Kind; N],
    read: &dyn Fn(Vec3, u32) -> f64,
) -> [f32; N] {
    std::array::from_fn(|j| match kinds[j] {
        Kind::Gaussian { sharpness } => read(dirs[j], sharpness) as f32,
        _ => f32::NAN,
    })
}

fn pair(e: Result<Estimate<f32>, sphere_quadrature::Error>) -> (f64, f64) {
    match e {
        Ok(e) => (f64::from(e.value), f64::from(e.variance)),
        Err(_) => (f64::NAN, f64::NAN),
    }
}

/// Irradiance: the renderer takes the normal only.
fn diffuse_query<const N: usize>(n: Vec3, _r: Vec3, read: &dyn Fn(Vec3, u32) -> f64) -> (f64, f64)
where
    Size<N>: FootprintSize<Diffuse>,
{
    let fr = FootprintRenderer::<N, Diffuse>::new();
    let mut dirs = [Vec3::ZERO; N];
    if fr.fill_directions(n, &mut dirs).is_err() {
        return (f64::NAN, f64::NAN);
    }
    pair(fr.estimate_with_variance(&lookups(&dirs, fr.footprints(), read)))
}

fn phong_query<const N: usize, const E: u32>(
    n: Vec3,
    r: Vec3,
    read: &dyn Fn(Vec3, u32) -> f64,
) -> (f64, f64)
where
    Size<N>: FootprintSize<Phong<E>>,
{
    let fr = FootprintRenderer::<N, Phong<E>>::new();
    let mut dirs = [Vec3::ZERO; N];
    if fr.fill_directions(n, r, &mut dirs).is_err() {
        return (f64::NAN, f64::NAN);
    }
    pair(fr.estimate_with_variance(n, r, &lookups(&dirs, fr.footprints(), read)))
}

/// The crate's renderer for `(N, e)` (`e = 0`: irradiance), if it bakes that set.
pub fn crate_fn(n: usize, e: u32) -> Option<CrateFn> {
    Some(match (n, e) {
        (16, 0) => diffuse_query::<16>,
        (32, 0) => diffuse_query::<32>,
        (64, 0) => diffuse_query::<64>,
        (128, 0) => diffuse_query::<128>,
        (16, 10) => phong_query::<16, 10>,
        (32, 10) => phong_query::<32, 10>,
        (64, 10) => phong_query::<64, 10>,
        (128, 10) => phong_query::<128, 10>,
        (16, 50) => phong_query::<16, 50>,
        (32, 50) => phong_query::<32, 50>,
        (64, 50) => phong_query::<64, 50>,
        (128, 50) => phong_query::<128, 50>,
        (16, 200) => phong_query::<16, 200>,
        (32, 200) => phong_query::<32, 200>,
        (64, 200) => phong_query::<64, 200>,
        (128, 200) => phong_query::<128, 200>,
        _ => return None,
    })
}

/// `e` of the crate's sets for a benchmark BRDF (0: diffuse).
pub fn exponent(brdf: engine::Brdf) -> u32 {
    match brdf {
        engine::Brdf::Diffuse => 0,
        engine::Brdf::Phong(e) => e as u32,
    }
}

/// `f32` of an `f64` direction.
pub fn v32(d: [f64; 3]) -> Vec3 {
    Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32)
}

/// A scene's footprint lookups: of a map, its pyramid and the map itself (built by
/// [`with_lookups`]); of a mixture, the exact convolution (both kinds are then the same).
pub struct Lookups<'a> {
    scene: &'a Scene,
    map: Option<&'a EquirectMap<'a>>,
    pyramid: Option<&'a MipPyramid<'a>>,
}

/// Runs `f` with the lookups of `scene`.
pub fn with_lookups<R>(scene: &Scene, f: impl FnOnce(&Lookups) -> R) -> R {
    match &scene.light {
        Light::Map { map, .. } => {
            let eq = EquirectMap::new(map.width, map.height, &map.pixels).expect("a valid map");
            let mut buffer = vec![[0.0f32; 3]; MipPyramid::buffer_len(map.width, map.height)];
            let pyramid = MipPyramid::new(&eq, &mut buffer).expect("a pyramid of a valid map");
            f(&Lookups { scene, map: Some(&eq), pyramid: Some(&pyramid) })
        }
        Light::Mixture(_) => f(&Lookups { scene, map: None, pyramid: None }),
    }
}

impl Lookups<'_> {
    /// The luminance of a footprint at `d`: through the pyramid, or (`exact`) from every
    /// pixel of the map; a mixture's exact convolution with the normalised spherical Gaussian
    /// of the footprint, or NaN for a footprint that is not Gaussian.
    pub fn read(&self, d: Vec3, kind: Kind, exact: bool) -> f64 {
        let rgb = match (self.pyramid, self.map, &self.scene.light) {
            (Some(p), _, _) if !exact => p.footprint_sample(d, kind),
            (_, Some(m), _) => m.footprint_sample(d, kind),
            (_, _, Light::Mixture(m)) => {
                let Kind::Gaussian { sharpness } = kind else { return f64::NAN };
                let x = [f64::from(d.x), f64::from(d.y), f64::from(d.z)];
                let x = reference::vec::normalize(x);
                return m.constant
                    + m.lobes
                        .iter()
                        .map(|g| {
                            engine::sg_filtered(
                                g.axis,
                                g.sharpness,
                                g.amplitude,
                                x,
                                f64::from(sharpness),
                            )
                        })
                        .sum::<f64>();
            }
            _ => return f64::NAN,
        };
        rgb.map_or(f64::NAN, |c| luminance(c.map(f64::from)))
    }

    /// The crate's renderer `f` on query `(n, r)` (`r = n` for diffuse), reading through the
    /// pyramid or (`exact`) the map.
    pub fn render(&self, f: CrateFn, n: [f64; 3], r: [f64; 3], exact: bool) -> (f64, f64) {
        f(v32(n), v32(r), &|d, s| self.read(d, Kind::Gaussian { sharpness: s }, exact))
    }

    /// Split-sum (Phong `e`): one lookup of the map prefiltered by the lobe `cosᵉ` along the
    /// mirror direction `r`, through the pyramid, times `mass = ∫p` (the lobe against the
    /// cosine, exactly); NaN for a mixture.
    pub fn split_sum(&self, e: u32, r: [f64; 3], mass: f64) -> f64 {
        match self.pyramid {
            Some(_) => self.read(v32(r), Kind::CosinePower { exponent: e }, false) * mass,
            None => f64::NAN,
        }
    }
}
