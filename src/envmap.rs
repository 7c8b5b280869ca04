//! Footprint samples of an equirectangular radiance map: what a probe sample sees through a
//! lobe, exactly or fast; `no_std`, no allocation, caller-provided buffers.
//!
//! A footprint sample in direction `d` is `Y(d) = ∫ L(x)·f(d·x) dx` for a normalised lobe
//! `f` ([`crate::footprint`]: the Gaussian `exp(S(t − 1))·S/(2π(1 − e^(−2S)))` or the cosine
//! power `(P + 1)/(2π)·max(0, t)ᴾ`) and the map's piecewise-constant radiance `L`.
//!
//! ```
//! use sphere_quadrature::envmap::{EquirectMap, MipPyramid};
//! use sphere_quadrature::footprint::Kind;
//! use sphere_quadrature::Vec3;
//!
//! // A 16×8 sky: 1 everywhere, 10 in the upper hemisphere's first column.
//! let mut pixels = [[1.0f32; 3]; 16 * 8];
//! for v in 0..4 {
//!     pixels[v * 16] = [10.0; 3];
//! }
//! let map = EquirectMap::new(16, 8, &pixels)?;
//! let up = Vec3::Z;
//! // The radiance straight up, and what a photodiode pointing up reads.
//! assert_eq!(map.radiance(up)?, [10.0; 3]);
//! let diode = map.footprint_sample(up, Kind::CosinePower { exponent: 1 })?;
//! assert!(diode[0] > 1.0 && diode[0] < 10.0);
//! // The same from a mip pyramid in a caller's buffer.
//! let mut buffer = [[0.0f32; 3]; MipPyramid::buffer_len(16, 8)];
//! let pyramid = MipPyramid::new(&map, &mut buffer)?;
//! let fast = pyramid.footprint_sample(up, Kind::Gaussian { sharpness: 2 })?;
//! let exact = map.footprint_sample(up, Kind::Gaussian { sharpness: 2 })?;
//! assert!((fast[0] - exact[0]).abs() < 0.05 * exact[0]);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Pixel convention
//! That of `reference/src/envmap.rs`: a `W×H` map, row-major, row `v` (0 at the top) covers
//! polar angles `θ ∈ [πv/H, π(v+1)/H]` from +z, column `u` covers azimuths
//! `φ ∈ [2πu/W, 2π(u+1)/W]` from +x towards +y, direction `(sinθ cosφ, sinθ sinφ, cosθ)`;
//! pixel `p` has solid angle `Ω_p = (2π/W)(cos θ_top − cos θ_bottom)`. [`EquirectMap::radiance`]
//! (and [`Kind::Point`]) returns the pixel whose box holds the direction; boundaries go to
//! the larger index, `θ = π` to the last row, `φ → 2π` to column 0.
//!
//! # Exact form
//! [`EquirectMap::footprint_sample`] returns `Y = Σ_p L_p w_p / Σ_p w_p` with
//! `w_p ≈ ∫_p f(d·x) dx` over every pixel box, accumulated in f64. Dividing by the sum of
//! the same weights (instead of by `∫ f = 1`) makes a constant map return exactly that
//! constant. It is deterministic (fixed order, no threads, no table look-ups but its own).
//!
//! With `t = cosθ_d cosθ + sinθ_d sinθ cos(φ − φ_d) = a + b·c`, `a` and `b` are per row and
//! `c = cos(φ − φ_d)` is advanced along a row by a rotation recurrence (two interleaved
//! lanes). The Gaussian factors as `exp(S(a + b − 1))·exp(κ(c − 1))`, `κ = S·b`; a row and
//! its mirror image about the equator (`−a`, same `b`) share the column factors, so a pair
//! of pixels costs one `exp` (a private table-driven f64 `exp`, within 5·10⁻¹⁶ of `libm`'s).
//! Rows where the lobe stays below 10⁻¹³ of its peak are skipped, and in the others only the
//! columns within the cap where it exceeds 10⁻¹³.
//!
//! The one-point (pixel-centre) rule is not accurate enough: measured against the reference
//! below, its error is 1–8·10⁻⁴ of the sample at `S = 8…128` and `P = 4`, because the lobe's
//! curvature across a pixel (`S·h²/24`, `h` the pixel size) is not small. The rule used
//! depends on `z = q·h²` (`q = S` or `P`, `h = max(π/H, 2π/W)`):
//! - `z ≤ 0.06` (`q ≤ 398` at 512×256): the *corrected midpoint rule*, `Ω_p·f·(1 + ε_θ + ε_φ)`
//!   at the pixel centre, with the leading Euler–Maclaurin terms `ε_φ = (Δφ²/24)·f_φφ/f` and
//!   `ε_θ = (Δθ²/12)·(cot θ·f_θ/f + f_θθ/(2f))` (the cotangent comes from the measure `sin θ`)
//!   in closed form: for the Gaussian `f_φφ/f = κ² sin²δ − κ cos δ`, `f_θ/f = S·t_θ`,
//!   `f_θθ/f = S²t_θ² − S·t`, which are quadratics in `c` with per-row coefficients, so a
//!   pixel still costs one `exp`. Its error is `O(h⁴)`, 2.5× that of the 2×2 Gauss–Legendre
//!   rule at a quarter of the cost;
//! - larger `z`: a k×k Gauss–Legendre rule in `(θ, φ)` per pixel, `k = 3…8` up to `z = 24`
//!   (`k = 4` at `S = 4096` on 512×256), then composites of 2…4 panels of order 8 up to
//!   `z = 384` (beyond that, lobes narrower than about a twentieth of a pixel, the error
//!   grows: 3·10⁻⁵ at `z = 600`). The ladder was measured on a 64×32 map of random pixels
//!   to keep the error near 10⁻⁶.
//! - The cosine power's kink at the horizon: pixels whose centre is within the pixel's
//!   angular radius of `t = 0` are integrated exactly in φ over the arc where `t > 0`
//!   (binomial expansion of `∫(a + b cos δ)ᴾ dδ`) and by 4-point Gauss–Legendre in θ; pixels
//!   with a channel above 16× the mean over pixels of their largest channel (suns, lamps)
//!   take θ-pieces split where the horizon leaves the pixel and where it is tangent to a
//!   parallel, with an endpoint-clustered 8-point rule each (without it, park's sun on the
//!   horizon costs 9·10⁻⁵ of the sample at `P = 1`).
//!
//! If a lobe falls between all nodes (only on tiny maps with very sharp lobes) the sample is
//! the pixel holding `d`.
//!
//! # Fast form
//! [`MipPyramid`] stores levels `l = 2, 3, …` of solid-angle weighted box averages
//! (`⌈W/2ˡ⌉×⌈H/2ˡ⌉` texels, the last row and column covering what is left of the map), about
//! a third of the map's own size, and for each texel and channel the mean direction vector
//! `m` of that channel's radiance over the texel (weights `Ω·max(0, L)`), stored as its
//! offset from the texel's geometric mean vector. [`MipPyramid::footprint_sample`] reads the
//! coarsest level whose texels are at most `1/(r·√q)` across (`r` =
//! [`DEFAULT_RESOLUTION`] = 2, or [`MipPyramid::with_resolution`]); where that is level 0 or
//! 1, it returns the exact form. On level `l` it is a *moment rule*:
//! `Y_c = Σ_T Ω_T L_{T,c} F(m_{T,c}) / Σ_T Ω_T F(m_T)`, where `F(m) = f(d·m̂) + (s²/4)·Δf` is the
//! lobe's mean over a small isotropic spread of directions with mean vector `m`,
//! `s² = 1 − |m|²` (exactly the mean squared distance from the mean), `Δ` the surface
//! Laplacian, and `m_T` the texel's geometric mean vector. A sun inside a texel thus counts at
//! its own position, and a colour gradient inside a texel at each channel's own centroid. For
//! the cosine power, texels within their half-diagonal of the horizon take the box average of
//! the lobe by a 4×4 rule, moved and scaled to each channel's mean and spread. Texels below
//! 10⁻⁸ of the lobe's peak are skipped (the convex hull of a texel, which holds its mean
//! vectors, bounds the rows and columns visited).
//!
//! This was chosen over filtered importance sampling (Křivánek and Colbert 2008:
//! sub-samples morphed onto the lobe, each read trilinearly at the level matching its share
//! of the lobe), measured against the exact form by `fis_comparison_table` below:
//! FIS with 64 spherical-Fibonacci sub-samples has RMS errors of 6·10⁻²…3·10⁻¹ (worst
//! 1.4…240 %) at 12–22 µs per sample, with 256 sub-samples 3.5·10⁻²…1.1·10⁻¹ at 41–71 µs; the
//! moment rule 2.5·10⁻⁴…3.4·10⁻³ at 9–190 µs.
//!
//! # Accuracy and cost (measured)
//! Relative error of a sample: the largest channel error over the largest channel of the
//! truth. Times are per sample on the development machine (2 shared cores of an AMD EPYC
//! VM, release build, the bundled 512×256 maps), ±30 % between runs.
//!
//! Exact form against the reference crate's per-pixel adaptive quadrature
//! (`reference::footprint::gaussian`, and `reference::truth::phong` for the cosine power),
//! 3 directions on each of the ten bundled maps
//! (`cargo test --release --test envmap -- --ignored --nocapture exact_accuracy_table`):
//!
//! | lobe | worst error | time |
//! |---|---|---|
//! | Gaussian `S` = 1, 2, 4, 8, 16 | 5.0–5.7·10⁻⁸ | 0.55–0.8 ms |
//! | Gaussian `S` = 32, 64, 128 | 6.7·10⁻⁸, 1.7·10⁻⁷, 3.3·10⁻⁷ | 0.5, 0.3, 0.15 ms |
//! | Gaussian `S` = 512, 4096 | 4.8·10⁻⁸, 5.1·10⁻⁸ | 0.3, 0.08 ms |
//! | cosine power `P` = 1, 2, 4 | 1.3·10⁻⁷, 4.4·10⁻⁸, 4.9·10⁻⁸ | 0.5–0.9 ms |
//! | cosine power `P` = 16, 64, 4096 | 5.3·10⁻⁸, 2.1·10⁻⁷, 4.6·10⁻⁸ | 0.45, 0.35, 0.05 ms |
//!
//! The errors are the f32 rounding of the sample plus the rule's. On a map sampled from an
//! SG light the sample converges to the closed-form SG convolution as `h²` (the map's own
//! discretisation), and Richardson extrapolation from 256×128 and 512×256 leaves 4·10⁻⁸
//! (`tests/envmap/envmap_sampling.rs`).
//!
//! Fast form against the exact form, 64 directions on each of the ten maps, raw and with each
//! pixel's luminance capped at 30× the map's mean
//! (`cargo test --release --test envmap -- --ignored --nocapture fast_accuracy_table`),
//! RMS / worst error and speed-up over the exact form:
//!
//! | lobe | raw, `r` = 2 | clamped, `r` = 2 | speed-up | raw, `r` = 4 | speed-up |
//! |---|---|---|---|---|---|
//! | Gaussian `S` = 1 | 3.2·10⁻⁴ / 1.4·10⁻³ | 2.5·10⁻⁴ / 9.7·10⁻⁴ | 55–90× | 7.8·10⁻⁵ / 3.7·10⁻⁴ | 15–23× |
//! | Gaussian `S` = 2, 4 | 2.7–8.1·10⁻⁴ / 5.0·10⁻³ | 2.1–6.1·10⁻⁴ / 3.1·10⁻³ | 12–19× | 2.0·10⁻⁴ / 1.2·10⁻³ | 4× |
//! | Gaussian `S` = 8, 16 | 4.7–8.6·10⁻⁴ / 7.1·10⁻³ | 3.1–6.3·10⁻⁴ / 4.3·10⁻³ | 3–6× | 2.0·10⁻⁴ / 1.8·10⁻³ | 1× |
//! | Gaussian `S` = 32, 64 | 4.5–8.2·10⁻⁴ / 8.4·10⁻³ | 3.2–6.2·10⁻⁴ / 5.7·10⁻³ | 1–3× | exact | 1× |
//! | Gaussian `S` ≥ 128 | exact | exact | 1× | exact | 1× |
//! | cosine power `P` = 1 | 2.1·10⁻³ / 2.1·10⁻² | 1.6·10⁻³ / 8.7·10⁻³ | 12–17× | 6.8·10⁻⁴ / 8.1·10⁻³ | 5–7× |
//! | cosine power `P` = 4 | 1.6·10⁻³ / 1.3·10⁻² | 1.1·10⁻³ / 6.5·10⁻³ | 9× | 4.0·10⁻⁴ / 3.2·10⁻³ | 3–4× |
//!
//! So the fast form pays off for broad lobes, where the exact form visits the whole map
//! (0.5–0.8 ms); lobes a few pixels wide cost the exact form little. The worst cosine-power
//! error is a sun on the horizon. Building the pyramid of a 512×256 map takes 6–13 ms.
//!
//! # Bad input
//! Nothing panics on caller data. [`EquirectMap::new`] refuses a zero dimension or one above
//! [`MAX_DIMENSION`] ([`Error::InvalidSize`]), a pixel slice of the wrong length
//! ([`Error::LengthMismatch`]) and NaN or infinite pixels ([`Error::InvalidRadiance`]: checked
//! once there, so no sample ever sees them; negative radiance is allowed). Zero or non-finite
//! directions give [`Error::InvalidDirection`] (any other length is fine: crate docs,
//! "Directions"); a
//! sharpness or exponent of 0 or above [`MAX_PARAMETER`] gives [`Error::InvalidResponse`];
//! a pyramid buffer shorter than [`MipPyramid::buffer_len`], or batch slices of different
//! lengths, give [`Error::LengthMismatch`] (the batch forms check everything before writing).

use crate::error::Error;
use crate::footprint::{Kind, MAX_PARAMETER};
use crate::vec3::Vec3;
use core::f64::consts::{PI, TAU};

mod horizon;
mod pyramid;
mod rules;

use horizon::*;
pub use pyramid::MipPyramid;
use rules::*;

/// The largest width or height an [`EquirectMap`] may have.
pub const MAX_DIMENSION: usize = 1 << 16;

/// Texels of the pyramid level the fast form reads per lobe width `1/√q` (see
/// [`MipPyramid::with_resolution`]).
pub const DEFAULT_RESOLUTION: f32 = 2.0;

/// `ln(10⁻¹³)`: lobe values below this fraction of the peak are not summed by the exact
/// form.
const LN_CUTOFF: f64 = -29.933_606_208_922_594;

/// `ln(10⁻⁸)`: the fast form's cutoff (far below its own error, see the module docs).
const LN_FAST_CUTOFF: f64 = -18.420_680_743_952_367;

/// The finest pyramid level stored: level 1 would cost as much to read as the map itself
/// (four lobe evaluations per texel of four pixels), so the fast form reads the map there.
const FIRST_LEVEL: usize = 2;

/// Highest Gauss–Legendre order; sharper lobes use composite rules of this order.
const MAX_ORDER: usize = 8;

/// Most panels of a composite rule per pixel axis.
const MAX_PANELS: usize = 4;

/// Most nodes per pixel axis.
const MAX_NODES: usize = MAX_ORDER * MAX_PANELS;

/// Gauss–Legendre nodes per axis on pixels that straddle a cosine power's horizon.
const HORIZON_ORDER: usize = 4;

/// An equirectangular RGB radiance map borrowed from the caller: `width` columns of azimuth,
/// `height` rows of polar angle, row-major, row 0 at the top (+z).
///
/// # Examples
/// ```
/// use sphere_quadrature::envmap::EquirectMap;
/// use sphere_quadrature::footprint::Kind;
/// use sphere_quadrature::{Error, Vec3};
///
/// // An 8×4 map: the top half 3, the bottom half 1.
/// let pixels: Vec<[f32; 3]> = (0..32).map(|i| if i < 16 { [3.0; 3] } else { [1.0; 3] }).collect();
/// let map = EquirectMap::new(8, 4, &pixels)?;
/// assert_eq!(map.radiance(Vec3::Z)?, [3.0; 3]);
/// assert_eq!(map.radiance(-Vec3::Z)?, [1.0; 3]);
/// // A filtered sample lies between the darkest and the brightest pixel.
/// let y = map.footprint_sample(Vec3::X, Kind::Gaussian { sharpness: 4 })?;
/// assert!(y[0] > 1.0 && y[0] < 3.0);
/// assert_eq!(EquirectMap::new(8, 4, &pixels[..31]).err(), Some(Error::LengthMismatch));
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EquirectMap<'a> {
    width: usize,
    height: usize,
    pixels: &'a [[f32; 3]],
    /// 16 times the mean over pixels of the largest channel: pixels brighter than this get
    /// a finer rule where a cosine power's horizon crosses them.
    bright: f32,
}

impl<'a> EquirectMap<'a> {
    /// A map over `pixels` (row-major, row 0 at the top).
    ///
    /// # Errors
    /// [`Error::InvalidSize`] when a dimension is 0 or above [`MAX_DIMENSION`];
    /// [`Error::LengthMismatch`] when `pixels.len() != width·height`;
    /// [`Error::InvalidRadiance`] when a pixel has a NaN or infinite channel.
    pub fn new(width: usize, height: usize, pixels: &'a [[f32; 3]]) -> Result<Self, Error> {
        let size_ok = |n: usize| (1..=MAX_DIMENSION).contains(&n);
        if !size_ok(width) || !size_ok(height) {
            return Err(Error::InvalidSize);
        }
        if width.checked_mul(height) != Some(pixels.len()) {
            return Err(Error::LengthMismatch);
        }
        if pixels.iter().flatten().any(|c| !c.is_finite()) {
            return Err(Error::InvalidRadiance);
        }
        let total: f64 = pixels.iter().map(|p| f64::from(p[0].max(p[1]).max(p[2]))).sum();
        let bright = (16.0 * total / pixels.len() as f64).max(0.0) as f32;
        Ok(Self { width, height, pixels, bright })
    }

    /// Number of columns (azimuth).
    #[must_use]
    pub fn width(&self) -> usize {
        self.width
    }

    /// Number of rows (polar angle).
    #[must_use]
    pub fn height(&self) -> usize {
        self.height
    }

    /// The pixels, row-major, row 0 at the top.
    #[must_use]
    pub fn pixels(&self) -> &'a [[f32; 3]] {
        self.pixels
    }

    /// Row `v` (empty if out of range).
    fn row(&self, v: usize) -> &'a [[f32; 3]] {
        let start = v.saturating_mul(self.width);
        self.pixels.get(start..start.saturating_add(self.width)).unwrap_or(&[])
    }

    /// The pixel `(u, v)` whose box contains the direction (boundaries go to the larger
    /// index; θ = π to the last row, φ → 2π wraps to column 0).
    fn pixel_of(&self, dir: Vec3) -> (usize, usize) {
        let (x, y, z) = (f64::from(dir.x), f64::from(dir.y), f64::from(dir.z));
        let theta = libm::atan2(libm::hypot(x, y), z);
        let mut phi = libm::atan2(y, x);
        if phi < 0.0 {
            phi += TAU;
        }
        let v = (libm::floor(theta / PI * self.height as f64) as usize)
            .min(self.height.saturating_sub(1));
        let mut u = libm::floor(phi / TAU * self.width as f64) as usize;
        if u >= self.width {
            u = 0;
        }
        (u, v)
    }

    fn nearest(&self, dir: Vec3) -> [f32; 3] {
        let (u, v) = self.pixel_of(dir);
        self.row(v).get(u).copied().unwrap_or([0.0; 3])
    }

    /// The radiance in direction `dir` (need not be unit length): the pixel whose box
    /// contains it, the map's piecewise-constant radiance function.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite `dir`.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{envmap::EquirectMap, Error, Vec3};
    ///
    /// // 4×2: the top row red, the bottom row blue.
    /// let pixels = [[1.0, 0.0, 0.0]; 4].into_iter().chain([[0.0, 0.0, 1.0]; 4]).collect::<Vec<_>>();
    /// let map = EquirectMap::new(4, 2, &pixels)?;
    /// assert_eq!(map.radiance(Vec3::new(0.3, 0.2, 0.9))?, [1.0, 0.0, 0.0]);
    /// assert_eq!(map.radiance(Vec3::new(0.3, 0.2, -0.9))?, [0.0, 0.0, 1.0]);
    /// assert_eq!(map.radiance(Vec3::ZERO), Err(Error::InvalidDirection));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn radiance(&self, dir: Vec3) -> Result<[f32; 3], Error> {
        if dir.try_normalize().is_none() {
            return Err(Error::InvalidDirection);
        }
        Ok(self.nearest(dir))
    }

    /// The exact footprint sample `Σ_p L_p ∫_p f(d·x) dx / Σ_p ∫_p f(d·x) dx` in direction
    /// `dir` (see the module docs); [`Kind::Point`] gives [`radiance`](Self::radiance).
    ///
    /// # Errors
    /// [`Error::InvalidResponse`] for a sharpness or exponent of 0 or above
    /// [`MAX_PARAMETER`]; [`Error::InvalidDirection`] for a zero or non-finite
    /// `dir`.
    pub fn footprint_sample(&self, dir: Vec3, kind: Kind) -> Result<[f32; 3], Error> {
        match lobe_of(kind)? {
            None => self.radiance(dir),
            Some(lobe) => {
                let d = Dir::new(dir)?;
                Ok(to_f32(self.exact(&d, lobe)))
            }
        }
    }

    /// [`footprint_sample`](Self::footprint_sample) for every direction of `dirs`, into
    /// `out`. Every input is checked before anything is written, so `out` is left unchanged
    /// on error.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `out.len() != dirs.len()`, then the errors of
    /// [`footprint_sample`](Self::footprint_sample).
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::envmap::EquirectMap;
    /// use sphere_quadrature::footprint::Kind;
    /// use sphere_quadrature::{probe::Probe, Error};
    ///
    /// // Fill a probe's samples from a map; a constant map gives that constant.
    /// let pixels = [[1.5f32; 3]; 16 * 8];
    /// let map = EquirectMap::new(16, 8, &pixels)?;
    /// let probe = Probe::<16, [f32; 3]>::new();
    /// let mut samples = [[0.0f32; 3]; 16];
    /// map.footprint_samples(probe.directions(), Kind::Gaussian { sharpness: 2 }, &mut samples)?;
    /// assert!(samples.iter().flatten().all(|&c| (c - 1.5).abs() < 1e-5));
    /// // One output per direction.
    /// let err = map.footprint_samples(probe.directions(), Kind::Point, &mut samples[..15]);
    /// assert_eq!(err, Err(Error::LengthMismatch));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn footprint_samples(
        &self,
        dirs: &[Vec3],
        kind: Kind,
        out: &mut [[f32; 3]],
    ) -> Result<(), Error> {
        check_batch(dirs, kind, out)?;
        for (o, &d) in out.iter_mut().zip(dirs) {
            *o = self.footprint_sample(d, kind)?;
        }
        Ok(())
    }

    /// The exact form (see the module docs).
    fn exact(&self, d: &Dir, lobe: Kind) -> [f64; 3] {
        let dth = PI / self.height as f64;
        let dphi = TAU / self.width as f64;
        let rule = Rule::for_lobe(lobe.sharpness(), dth.max(dphi));
        let nearest =
            || to_f64(self.nearest(Vec3::new(d.v[0] as f32, d.v[1] as f32, d.v[2] as f32)));
        let sums = match lobe {
            Kind::Gaussian { sharpness } => self.gaussian_sums(d, sharpness, &rule),
            Kind::CosinePower { exponent } => self.power_sums(d, exponent, &rule),
            Kind::Point => return nearest(),
        };
        // A lobe far narrower than the node spacing can fall between all nodes.
        sums.mean().unwrap_or_else(nearest)
    }

    /// Rows `[v_lo, v_hi]` whose centres are within the cap `t ≥ t_cut` widened by a row.
    fn row_range(&self, d: &Dir, t_cut: f64) -> (usize, usize) {
        let dth = PI / self.height as f64;
        let alpha = if t_cut > -1.0 { libm::acos(t_cut.min(1.0)) } else { PI };
        let theta = d.theta();
        let row = |x: f64| (libm::floor(x / dth).max(0.0) as usize).min(self.height - 1);
        (row(theta - alpha - dth), row(theta + alpha + dth))
    }

    /// Gaussian sums over the pixels, rows paired with their mirror images about the
    /// equator: `exp(S(t − 1)) = exp(S(a + b − 1))·exp(κ(c − 1))` with `a = cosθ_d cosθ`,
    /// `b = sinθ_d sinθ`, `κ = S·b` and `c = cos(φ − φ_d)`; the mirror row has `−a` and the
    /// same `b`, so the column factors are shared.
    ///
    /// Order 1 is the corrected midpoint rule: per pixel `Ω·f·(1 + ε_θ + ε_φ)` with the
    /// leading Euler–Maclaurin terms `ε_φ = (Δφ²/24)·f_φφ/f` and
    /// `ε_θ = (Δθ²/12)·(cot θ·f_θ/f + f_θθ/(2f))` (the cotangent from the measure sinθ),
    /// where for `f = e^{S(t−1)}`: `f_φφ/f = κ²sin²δ − κ cos δ`, `f_θ/f = S·t_θ` and
    /// `f_θθ/f = S²t_θ² − S·t`. Both are quadratics in `c = cos δ` with per-row
    /// coefficients, so a pixel costs one `exp`.
    fn gaussian_sums(&self, d: &Dir, sharpness: u32, rule: &Rule) -> Sums {
        let s = f64::from(sharpness);
        let (w, h) = (self.width, self.height);
        let dth = PI / h as f64;
        let dphi = TAU / w as f64;
        let sub = SubColumns::new(rule, dphi);
        let half_row = libm::sin(0.5 * dth);
        let corrected = rule.len == 1;
        let (k_theta, k_phi) = (dth * dth / 12.0, dphi * dphi / 24.0);
        let (v_lo, v_hi) = self.row_range(d, Kind::Gaussian { sharpness }.t_cut());
        let mut sums = Sums::default();
        for v in 0..h.div_ceil(2) {
            let v2 = h - 1 - v;
            if !(v_lo..=v_hi).contains(&v) && !(v_lo..=v_hi).contains(&v2) {
                continue;
            }
            let (row_a, row_b) = (self.row(v), self.row(v2));
            for &(x, wx) in rule.nodes() {
                let (st, ct) = libm::sincos((v as f64 + 0.5 + 0.5 * x) * dth);
                let w_theta = if corrected { 2.0 * st * half_row } else { 0.5 * dth * wx * st };
                let a = d.cos_theta * ct;
                let b = d.sin_theta * st;
                let kappa = s * b;
                let e1 = s * (a + b - 1.0);
                let e2 = if v2 == v { f64::NEG_INFINITY } else { s * (b - a - 1.0) };
                let e_max = e1.max(e2);
                if e_max.is_nan() || e_max < LN_CUTOFF {
                    continue;
                }
                let c_min = 1.0 + (LN_CUTOFF - e_max) / kappa;
                let delta = if c_min > -1.0 { libm::acos(c_min.min(1.0)) } else { PI };
                let (ra, rb) = (libm::exp(e1), libm::exp(e2));
                let pair = if corrected {
                    // t_θ = S⁻¹·f_θ/f is `be·c − al` in row a and `−(be·c + al)` in the
                    // mirror row (θ′ = π − θ, cot θ′ = −cot θ).
                    let cot = ct / st;
                    let (al, be) = (d.cos_theta * st, d.sin_theta * ct);
                    let (p0, p1, p2) =
                        (1.0 + k_phi * kappa * kappa, -k_phi * kappa, -k_phi * kappa * kappa);
                    let q2 = p2 + k_theta * 0.5 * s * s * be * be;
                    let qa0 = p0 + k_theta * s * (0.5 * s * al * al - cot * al - 0.5 * a);
                    let qa1 = p1 + k_theta * s * (cot * be - s * al * be - 0.5 * b);
                    let qb0 = p0 + k_theta * s * (0.5 * s * al * al + cot * al + 0.5 * a);
                    let qb1 = p1 + k_theta * s * (cot * be + s * al * be - 0.5 * b);
                    row_sums::<true>(row_a, row_b, d.phi, delta, dphi, |c, _, _| {
                        let g = exp(kappa * (c - 1.0));
                        (g * (qa0 + c * (qa1 + c * q2)), g * (qb0 + c * (qb1 + c * q2)))
                    })
                } else {
                    row_sums::<true>(row_a, row_b, d.phi, delta, dphi, |c, sn, _| {
                        let g = sub.sum(c, sn, |cj| exp(kappa * (cj - 1.0)));
                        (g, g)
                    })
                };
                sums.add(w_theta * ra, pair.a);
                sums.add(w_theta * rb, pair.b);
                sums.weight += w_theta * (ra * pair.weight_a + rb * pair.weight_b);
            }
        }
        sums
    }

    /// Cosine-power sums over the pixels: `max(0, a + b·c)ᴾ` with `a`, `b`, `c` as in
    /// [`gaussian_sums`](Self::gaussian_sums).
    ///
    /// Order 1 is the corrected midpoint rule as there, with `f = tᴾ`:
    /// `f_θ = P·tᴾ⁻¹·t_θ`, `f_θθ = P·tᴾ⁻²·((P − 1)t_θ² − t²)`,
    /// `f_φφ = P·tᴾ⁻²·((P − 1)b²sin²δ − t·b·cos δ)`, on pixels whose centre is further than
    /// the pixel's angular radius `ρ` above the horizon; pixels within `ρ` of it, where
    /// `max(0, t)` has its kink, are integrated exactly in φ over the arc where `t > 0`
    /// ([`horizon_pixel`], [`bright_horizon_pixel`]).
    fn power_sums(&self, d: &Dir, p: u32, rule: &Rule) -> Sums {
        let (w, h) = (self.width, self.height);
        let dth = PI / h as f64;
        let dphi = TAU / w as f64;
        let sub = SubColumns::new(rule, dphi);
        let half_row = libm::sin(0.5 * dth);
        let corrected = rule.len == 1;
        let (k_theta, k_phi) = (dth * dth / 12.0, dphi * dphi / 24.0);
        let horizon = Rule::gauss_legendre(HORIZON_ORDER, 1);
        let (half_s, half_c) = libm::sincos(0.5 * dphi);
        let half_pixel = (0.5 * dphi, (half_c, half_s));
        // Angular radius of a pixel (with margin): |t − t_centre| ≤ ρ inside it.
        let rho = 0.51 * libm::sqrt(dth * dth + dphi * dphi);
        let pf = f64::from(p);
        // With the corrected midpoint rule, pixels whose centre is within ρ below the
        // horizon still hold part of the lobe: the windows reach down to t = −ρ while the
        // horizon is above the cutoff.
        let t_cut = Kind::CosinePower { exponent: p }.t_cut();
        let t_cut = if corrected && t_cut < rho { -rho } else { t_cut };
        let (v_lo, v_hi) = self.row_range(d, t_cut);
        let mut sums = Sums::default();
        for v in v_lo..=v_hi {
            let row = self.row(v);
            let theta_c = (v as f64 + 0.5) * dth;
            for &(x, wx) in rule.nodes() {
                let (st, ct) = libm::sincos(theta_c + 0.5 * x * dth);
                let w_theta = if corrected { 2.0 * st * half_row } else { 0.5 * dth * wx * st };
                let a = d.cos_theta * ct;
                let b = d.sin_theta * st;
                if (a + b).is_nan() || a + b < t_cut {
                    continue;
                }
                let c_min = (t_cut - a) / b;
                let delta = if c_min > -1.0 { libm::acos(c_min.min(1.0)) } else { PI };
                let one = if corrected {
                    let cot = ct / st;
                    let (al, be) = (d.cos_theta * st, d.sin_theta * ct);
                    // Sub-rows of the horizon rule: (a_i, b_i, weight relative to w_θ).
                    let mut sub_rows = [(0.0, 0.0, 0.0); HORIZON_ORDER];
                    for (slot, &(xi, wi)) in sub_rows.iter_mut().zip(horizon.nodes()) {
                        let (si, ci) = libm::sincos(theta_c + 0.5 * xi * dth);
                        *slot = (d.cos_theta * ci, d.sin_theta * si, 0.5 * dth * wi * si / w_theta);
                    }
                    row_sums::<false>(row, row, d.phi, delta, dphi, |c, sn, pixel| {
                        let t = a + b * c;
                        let g = if t >= rho {
                            let tt = be * c - al;
                            if p == 1 {
                                t + k_theta * (cot * tt - 0.5 * t) - k_phi * b * c
                            } else {
                                let body = t * t
                                    + k_theta
                                        * pf
                                        * (cot * t * tt + 0.5 * ((pf - 1.0) * tt * tt - t * t))
                                    + k_phi * pf * ((pf - 1.0) * b * b * sn * sn - t * b * c);
                                powi(t, p - 2) * body
                            }
                        } else if t > -rho {
                            if pixel.iter().any(|&l| l > self.bright) {
                                let band = (theta_c - 0.5 * dth, theta_c + 0.5 * dth);
                                let pixel_box = (band, (c, sn), half_pixel);
                                bright_horizon_pixel(d, pixel_box, p) / w_theta
                            } else {
                                horizon_pixel(&sub_rows, (c, sn), half_pixel, p)
                            }
                        } else {
                            0.0
                        };
                        (g, g)
                    })
                } else {
                    row_sums::<false>(row, row, d.phi, delta, dphi, |c, sn, _| {
                        let g = sub.sum(c, sn, |cj| powi((a + b * cj).max(0.0), p));
                        (g, g)
                    })
                };
                sums.add(w_theta, one.a);
                sums.weight += w_theta * one.weight_a;
            }
        }
        sums
    }
}

fn check_batch(dirs: &[Vec3], kind: Kind, out: &[[f32; 3]]) -> Result<(), Error> {
    if dirs.len() != out.len() {
        return Err(Error::LengthMismatch);
    }
    lobe_of(kind)?;
    if dirs.iter().any(|d| d.try_normalize().is_none()) {
        return Err(Error::InvalidDirection);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    //! The private kernels against `libm` and brute force (the public API is tested against
    //! the f64 reference crate in `tests/envmap/envmap_sampling.rs`).
    use super::*;

    #[test]
    fn exp_matches_libm() {
        let mut worst: f64 = 0.0;
        let n = 200_000;
        for i in 0..=n {
            let x = -708.0 + 717.0 * f64::from(i) / f64::from(n);
            worst = worst.max(libm::fabs(exp(x) / libm::exp(x) - 1.0));
        }
        assert!(worst < 5e-16, "{worst:e}");
        assert_eq!(exp(0.0), 1.0);
        assert!(exp(-1e4) > 0.0 && exp(-1e4) < 1e-307);
    }

    #[test]
    fn rules_integrate_polynomials() {
        // Order k (and composites of it) is exact for degree 2k − 1.
        for (k, panels) in [(1, 1), (2, 1), (3, 1), (5, 1), (8, 1), (8, 3)] {
            let rule = Rule::gauss_legendre(k, panels);
            assert_eq!(rule.nodes().len(), k * panels);
            for deg in 0..2 * k {
                let got: f64 = rule.nodes().iter().map(|&(x, w)| w * powi(x, deg as u32)).sum();
                let want = if deg % 2 == 0 { 2.0 / (deg + 1) as f64 } else { 0.0 };
                assert!(libm::fabs(got - want) < 1e-14, "k = {k}, degree {deg}: {got}");
            }
        }
    }

    #[test]
    fn arc_integral_matches_brute_force() {
        // ∫ max(0, a + b cos δ)ᴾ over pixels straddling the arc's end and δ = ±π.
        for (a, b, p, lo, hi) in [
            (0.1, 0.5, 1, 1.2, 1.9),
            (-0.2, 0.9, 3, -1.9, -1.5),
            (0.05, 0.3, 8, 2.9, 3.4),
            (0.4, 0.2, 2, 3.0, 3.3),
            (0.01, 0.7, 12, 1.4, 1.7),
        ] {
            let edges = [lo, hi].map(|x: f64| (x, (libm::cos(x), libm::sin(x))));
            let got = arc_integral(a, b, p, &edges);
            let n = 200_000;
            let h = (hi - lo) / f64::from(n);
            let want: f64 = (0..n)
                .map(|i| {
                    let x = lo + h * (f64::from(i) + 0.5);
                    h * powi((a + b * libm::cos(x)).max(0.0), p)
                })
                .sum();
            assert!(libm::fabs(got - want) < 1e-9 * want.max(1e-3), "{a} {b} {p}: {got} {want}");
        }
    }

    #[test]
    fn column_ranges_cover_the_window() {
        let n = 16;
        let dphi = TAU / n as f64;
        assert_eq!(column_ranges(1.0, PI, dphi, n), [(0, n), (0, 0)]);
        assert_eq!(column_ranges(1.0, f64::NAN, dphi, n), [(0, n), (0, 0)]);
        // φ = 1.0 ± 0.3 lies in columns 1..=3.
        assert_eq!(column_ranges(1.0, 0.3, dphi, n), [(1, 4), (0, 0)]);
        // Wrapping below 0 and above 2π.
        assert_eq!(column_ranges(0.1, 0.3, dphi, n), [(0, 2), (15, 16)]);
        assert_eq!(column_ranges(TAU - 0.1, 0.3, dphi, n), [(14, 16), (0, 1)]);
    }
}
