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
//! sharpness or exponent of 0 or above [`MAX_PARAMETER`] gives [`Error::InvalidParameter`];
//! a pyramid buffer shorter than [`MipPyramid::buffer_len`], or batch slices of different
//! lengths, give [`Error::LengthMismatch`] (the batch forms check everything before writing).

use crate::error::Error;
use crate::footprint::{Kind, MAX_PARAMETER};
use crate::vec3::Vec3;
use core::f64::consts::{PI, TAU};

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

/// Gauss–Legendre rules on `[−1, 1]` of orders 1 to [`MAX_ORDER`]: the non-negative nodes
/// with their weights (the rules are symmetric).
const GAUSS_LEGENDRE: [&[(f64, f64)]; MAX_ORDER] = [
    &[(0.0, 2.0)],
    &[(0.577_350_269_189_625_8, 1.0)],
    &[(0.0, 8.0 / 9.0), (0.774_596_669_241_483_4, 5.0 / 9.0)],
    &[
        (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    ],
    &[
        (0.0, 0.568_888_888_888_888_9),
        (0.538_469_310_105_683_1, 0.478_628_670_499_366_4),
        (0.906_179_845_938_664, 0.236_926_885_056_189_1),
    ],
    &[
        (0.238_619_186_083_196_9, 0.467_913_934_572_691_3),
        (0.661_209_386_466_264_5, 0.360_761_573_048_138_6),
        (0.932_469_514_203_152, 0.171_324_492_379_170_3),
    ],
    &[
        (0.0, 0.417_959_183_673_469_4),
        (0.405_845_151_377_397_2, 0.381_830_050_505_119),
        (0.741_531_185_599_394_5, 0.279_705_391_489_276_7),
        (0.949_107_912_342_758_5, 0.129_484_966_168_869_7),
    ],
    &[
        (0.183_434_642_495_649_8, 0.362_683_783_378_362_1),
        (0.525_532_409_916_329, 0.313_706_645_877_887_4),
        (0.796_666_477_413_626_7, 0.222_381_034_453_374_4),
        (0.960_289_856_497_536_3, 0.101_228_536_290_376_2),
    ],
];

/// A quadrature rule on `[−1, 1]` with all its nodes: Gauss–Legendre of order ≤
/// [`MAX_ORDER`], or a composite of up to [`MAX_PANELS`] equal panels of order
/// [`MAX_ORDER`]. A one-node rule stands for the corrected midpoint rule.
#[derive(Clone, Copy)]
struct Rule {
    nodes: [(f64, f64); MAX_NODES],
    len: usize,
}

impl Rule {
    /// The Gauss–Legendre rule of order `k` (clamped to `1..=MAX_ORDER`) on `panels` equal
    /// panels (clamped to `1..=MAX_PANELS`).
    fn gauss_legendre(k: usize, panels: usize) -> Self {
        let k = k.clamp(1, MAX_ORDER);
        let m = panels.clamp(1, MAX_PANELS);
        let half = GAUSS_LEGENDRE.get(k - 1).copied().unwrap_or(&[(0.0, 2.0)]);
        // One panel's nodes: the negative ones (mirrored), then the non-negative ones.
        let negative = half.iter().rev().filter(|n| n.0 > 0.0).map(|&(x, w)| (-x, w));
        let panel = negative.chain(half.iter().copied());
        let mut nodes = [(0.0, 0.0); MAX_NODES];
        let mut len = 0;
        let mf = m as f64;
        for j in 0..m {
            let centre = -1.0 + (2 * j + 1) as f64 / mf;
            for (x, w) in panel.clone() {
                if let Some(slot) = nodes.get_mut(len) {
                    *slot = (centre + x / mf, w / mf);
                    len += 1;
                }
            }
        }
        Self { nodes, len }
    }

    /// The rule for a lobe of sharpness `q` on pixels of angular size `h` (see the module
    /// docs, "Exact form"): the corrected midpoint rule while `z = q·h² ≤ 0.06`, then
    /// Gauss–Legendre of orders 3 to 8 up to `z = 24`, then composites of 2 to 4 panels of
    /// order 8 up to `z = 24·panels²`.
    fn for_lobe(q: f64, h: f64) -> Self {
        let z = q * h * h;
        // (largest z, order) pairs measured to keep the relative error near 10⁻⁶.
        const LADDER: [(f64, usize); 7] =
            [(0.06, 1), (0.6, 3), (2.0, 4), (5.0, 5), (10.0, 6), (16.0, 7), (24.0, 8)];
        for (z_max, k) in LADDER {
            if z <= z_max {
                return Self::gauss_legendre(k, 1);
            }
        }
        let mut m = 2;
        while m < MAX_PANELS && z > 24.0 * (m * m) as f64 {
            m += 1;
        }
        Self::gauss_legendre(MAX_ORDER, m)
    }

    fn nodes(&self) -> &[(f64, f64)] {
        self.nodes.get(..self.len).unwrap_or(&[])
    }
}

/// A lobe with a validated parameter.
#[derive(Clone, Copy, Debug)]
enum Lobe {
    /// `exp(S(t − 1))`.
    Gaussian(f64),
    /// `max(0, t)ᴾ`.
    Power(u32),
}

impl Lobe {
    /// `None` for [`Kind::Point`].
    fn new(kind: Kind) -> Result<Option<Self>, Error> {
        match kind {
            Kind::Point => Ok(None),
            Kind::Gaussian { sharpness: s } if (1..=MAX_PARAMETER).contains(&s) => {
                Ok(Some(Lobe::Gaussian(f64::from(s))))
            }
            Kind::CosinePower { exponent: p } if (1..=MAX_PARAMETER).contains(&p) => {
                Ok(Some(Lobe::Power(p)))
            }
            _ => Err(Error::InvalidParameter),
        }
    }

    /// The sharpness `q` (`S` or `P`): the lobe's angular width is about `1/√q`.
    fn sharpness(self) -> f64 {
        match self {
            Lobe::Gaussian(s) => s,
            Lobe::Power(p) => f64::from(p),
        }
    }

    /// The `t` below which the lobe is under `10⁻¹³` of its peak (may be below −1).
    fn t_cut(self) -> f64 {
        self.t_below(LN_CUTOFF)
    }

    /// The `t` below which the lobe is under `e^ln_fraction` of its peak.
    fn t_below(self, ln_fraction: f64) -> f64 {
        match self {
            Lobe::Gaussian(s) => 1.0 + ln_fraction / s,
            Lobe::Power(p) => libm::exp(ln_fraction / f64::from(p)),
        }
    }

    /// `g(t) + (s²/4)·Δg(t)`, clamped at 0: the mean of the lobe `g` over a small
    /// isotropic spread of directions about a direction at `t`, with
    /// `s² = E|x − E x|²` and the surface Laplacian `Δg = (1 − t²)·g″(t) − 2t·g′(t)`.
    #[inline]
    fn value_with_spread(self, t: f64, spread: f64) -> f64 {
        let t = t.clamp(-1.0, 1.0);
        let q = 0.25 * spread;
        let v = match self {
            Lobe::Gaussian(s) => exp(s * (t - 1.0)) * (1.0 + q * s * (s * (1.0 - t * t) - 2.0 * t)),
            Lobe::Power(p) => {
                if t <= 0.0 {
                    return 0.0;
                }
                let pf = f64::from(p);
                let low = if p >= 2 { powi(t, p - 2) } else { 1.0 / t };
                low * (t * t + q * pf * ((pf - 1.0) * (1.0 - t * t) - 2.0 * t * t))
            }
        };
        v.max(0.0)
    }

    /// The lobe, unnormalised (peak 1 at `t = 1`).
    #[inline]
    fn value(self, t: f64) -> f64 {
        match self {
            Lobe::Gaussian(s) => exp(s * (t - 1.0)),
            Lobe::Power(p) => powi(t.max(0.0), p),
        }
    }
}

/// `2^(j/32)` for `j = 0..32`, correctly rounded.
const EXP2_TABLE: [f64; 32] = [
    f64::from_bits(0x3ff0000000000000), // 1.0
    f64::from_bits(0x3ff059b0d3158574), // 1.0218971486541166
    f64::from_bits(0x3ff0b5586cf9890f), // 1.0442737824274138
    f64::from_bits(0x3ff11301d0125b51), // 1.0671404006768237
    f64::from_bits(0x3ff172b83c7d517b), // 1.0905077326652577
    f64::from_bits(0x3ff1d4873168b9aa), // 1.1143867425958924
    f64::from_bits(0x3ff2387a6e756238), // 1.1387886347566916
    f64::from_bits(0x3ff29e9df51fdee1), // 1.1637248587775775
    f64::from_bits(0x3ff306fe0a31b715), // 1.189207115002721
    f64::from_bits(0x3ff371a7373aa9cb), // 1.215247359980469
    f64::from_bits(0x3ff3dea64c123422), // 1.241857812073484
    f64::from_bits(0x3ff44e086061892d), // 1.2690509571917332
    f64::from_bits(0x3ff4bfdad5362a27), // 1.2968395546510096
    f64::from_bits(0x3ff5342b569d4f82), // 1.3252366431597413
    f64::from_bits(0x3ff5ab07dd485429), // 1.3542555469368927
    f64::from_bits(0x3ff6247eb03a5585), // 1.383909881963832
    f64::from_bits(0x3ff6a09e667f3bcd), // 1.4142135623730951
    f64::from_bits(0x3ff71f75e8ec5f74), // 1.4451808069770467
    f64::from_bits(0x3ff7a11473eb0187), // 1.4768261459394993
    f64::from_bits(0x3ff82589994cce13), // 1.5091644275934228
    f64::from_bits(0x3ff8ace5422aa0db), // 1.5422108254079407
    f64::from_bits(0x3ff93737b0cdc5e5), // 1.5759808451078865
    f64::from_bits(0x3ff9c49182a3f090), // 1.6104903319492543
    f64::from_bits(0x3ffa5503b23e255d), // 1.645755478153965
    f64::from_bits(0x3ffae89f995ad3ad), // 1.681792830507429
    f64::from_bits(0x3ffb7f76f2fb5e47), // 1.718619298122478
    f64::from_bits(0x3ffc199bdd85529c), // 1.7562521603732995
    f64::from_bits(0x3ffcb720dcef9069), // 1.7947090750031072
    f64::from_bits(0x3ffd5818dcfba487), // 1.8340080864093424
    f64::from_bits(0x3ffdfc97337b9b5f), // 1.8741676341103
    f64::from_bits(0x3ffea4afa2a490da), // 1.9152065613971474
    f64::from_bits(0x3fff50765b6e4540), // 1.9571441241754002
];

/// `eˣ` in f64 for the lobe weights: `x = (k/32)·ln 2 + r` with `|r| ≤ ln 2/64`, then
/// `2^⌊k/32⌋·2^((k mod 32)/32)·p(r)` with the degree-6 Taylor polynomial `p` (truncation
/// below 2·10⁻¹⁶). Within 4.5·10⁻¹⁶ relative of `libm::exp` on `[−708, 709]` (tested); about
/// twice as fast in the summation loops, where it is the dominant cost. Arguments are
/// clamped to that range (`e^−708 ≈ 3·10⁻³⁰⁸` stands for anything smaller).
#[inline(always)]
fn exp(x: f64) -> f64 {
    const SHIFTER: f64 = 6_755_399_441_055_744.0; // 1.5·2⁵²: adding it rounds to an integer
    const INV_STEP: f64 = 46.166_241_308_446_83; // 32/ln 2
    const STEP_HI: f64 = 0.021_660_849_386_535_12; // ln 2/32 with 21 trailing zero bits
    const STEP_LO: f64 = 5.963_171_653_970_586_6e-12; // ln 2/32 − STEP_HI
    let x = x.clamp(-708.0, 709.0);
    let kf = (x * INV_STEP + SHIFTER) - SHIFTER;
    // kf·STEP_HI is exact for |k| < 2²¹.
    let r = (x - kf * STEP_HI) - kf * STEP_LO;
    let k = kf as i64;
    let scale = f64::from_bits((((k >> 5) + 1023) as u64) << 52);
    // Estrin's scheme: a short dependency chain.
    let r2 = r * r;
    let p = (1.0 + r)
        + r2 * ((0.5 + r * (1.0 / 6.0)) + r2 * ((1.0 / 24.0 + r * (1.0 / 120.0)) + r2 / 720.0));
    EXP2_TABLE.get((k & 31) as usize).copied().unwrap_or(1.0) * p * scale
}

/// `xⁿ` by binary powering (deterministic, no `libm`).
#[inline]
fn powi(mut x: f64, mut n: u32) -> f64 {
    let mut r = 1.0;
    while n > 0 {
        if n & 1 == 1 {
            r *= x;
        }
        x *= x;
        n >>= 1;
    }
    r
}

/// A validated direction in f64 with its polar form.
#[derive(Clone, Copy, Debug)]
struct Dir {
    v: [f64; 3],
    cos_theta: f64,
    sin_theta: f64,
    /// Azimuth in `[0, 2π]`.
    phi: f64,
}

impl Dir {
    fn new(dir: Vec3) -> Result<Self, Error> {
        if dir.try_normalize().is_none() {
            return Err(Error::InvalidDirection);
        }
        let (x, y, z) = (f64::from(dir.x), f64::from(dir.y), f64::from(dir.z));
        let n = libm::sqrt(x * x + y * y + z * z);
        let (x, y, z) = (x / n, y / n, z / n);
        let mut phi = libm::atan2(y, x);
        if phi < 0.0 {
            phi += TAU;
        }
        Ok(Self { v: [x, y, z], cos_theta: z, sin_theta: libm::hypot(x, y), phi })
    }

    fn theta(&self) -> f64 {
        libm::atan2(self.sin_theta, self.cos_theta)
    }
}

/// Weighted sums `Σ w·L` and `Σ w`.
#[derive(Clone, Copy, Default)]
struct Sums {
    acc: [f64; 3],
    weight: f64,
}

impl Sums {
    fn add(&mut self, w: f64, rgb: [f64; 3]) {
        for (a, c) in self.acc.iter_mut().zip(rgb) {
            *a += w * c;
        }
    }

    /// `Σ w·L / Σ w`, or `None` when no weight was summed.
    fn mean(&self) -> Option<[f64; 3]> {
        if self.weight > 0.0 {
            Some(self.acc.map(|a| a / self.weight))
        } else {
            None
        }
    }
}

fn to_f64(p: [f32; 3]) -> [f64; 3] {
    p.map(f64::from)
}

fn to_f32(p: [f64; 3]) -> [f32; 3] {
    p.map(|c| c as f32)
}

/// Index ranges `[a, b)` of the `n` columns of width `dphi` (the last one ends at 2π, so it
/// may be narrower) whose azimuth intervals meet `[φ − δ, φ + δ]` modulo 2π; the second
/// range is empty unless the window wraps.
fn column_ranges(phi: f64, delta: f64, dphi: f64, n: usize) -> [(usize, usize); 2] {
    let full = [(0, n), (0, 0)];
    // NaN or a window of the whole circle.
    if delta.is_nan() || delta >= PI || n == 0 {
        return full;
    }
    let last = n - 1;
    let index = |x: f64| -> usize { (libm::floor(x / dphi).max(0.0) as usize).min(last) };
    let (lo, hi) = (phi - delta, phi + delta);
    if lo < 0.0 {
        let (a, b) = (index(lo + TAU), index(hi));
        if a <= b + 1 {
            full
        } else {
            [(0, b + 1), (a, n)]
        }
    } else if hi >= TAU {
        let (a, b) = (index(lo), index(hi - TAU));
        if a <= b + 1 {
            full
        } else {
            [(a, n), (0, b + 1)]
        }
    } else {
        [(index(lo), index(hi) + 1), (0, 0)]
    }
}

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
    /// [`Error::InvalidParameter`] for a sharpness or exponent of 0 or above
    /// [`MAX_PARAMETER`]; [`Error::InvalidDirection`] for a zero or non-finite
    /// `dir`.
    pub fn footprint_sample(&self, dir: Vec3, kind: Kind) -> Result<[f32; 3], Error> {
        match Lobe::new(kind)? {
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
    fn exact(&self, d: &Dir, lobe: Lobe) -> [f64; 3] {
        let dth = PI / self.height as f64;
        let dphi = TAU / self.width as f64;
        let rule = Rule::for_lobe(lobe.sharpness(), dth.max(dphi));
        let sums = match lobe {
            Lobe::Gaussian(s) => self.gaussian_sums(d, s, &rule),
            Lobe::Power(p) => self.power_sums(d, p, &rule),
        };
        // A lobe far narrower than the node spacing can fall between all nodes.
        sums.mean().unwrap_or_else(|| {
            to_f64(self.nearest(Vec3::new(d.v[0] as f32, d.v[1] as f32, d.v[2] as f32)))
        })
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
    fn gaussian_sums(&self, d: &Dir, s: f64, rule: &Rule) -> Sums {
        let (w, h) = (self.width, self.height);
        let dth = PI / h as f64;
        let dphi = TAU / w as f64;
        let sub = SubColumns::new(rule, dphi);
        let half_row = libm::sin(0.5 * dth);
        let corrected = rule.len == 1;
        let (k_theta, k_phi) = (dth * dth / 12.0, dphi * dphi / 24.0);
        let (v_lo, v_hi) = self.row_range(d, Lobe::Gaussian(s).t_cut());
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
        let t_cut = Lobe::Power(p).t_cut();
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

/// `∫ max(0, t)ᴾ` over a pixel the horizon crosses, relative to its solid angle: a
/// Gauss–Legendre rule in θ (`sub_rows`: `(a_i, b_i, weight)`), and in φ the exact integral
/// over the part of the pixel where `t = a_i + b_i·cos δ > 0` ([`arc_integral`]).
/// `(c, s)` is `(cos δ, sin δ)` of the pixel centre, `half` its half-width with its
/// `(cos, sin)`. Out of line: it is rare, and inlining it would keep the common path of
/// [`EquirectMap::power_sums`] from being inlined.
#[inline(never)]
fn horizon_pixel(
    sub_rows: &[(f64, f64, f64); HORIZON_ORDER],
    centre: (f64, f64),
    half: (f64, (f64, f64)),
    p: u32,
) -> f64 {
    let edges = pixel_edges(centre, half);
    let mut total = 0.0;
    for &(ai, bi, wi) in sub_rows {
        total += wi * arc_integral(ai, bi, p, &edges) / (2.0 * half.0);
    }
    total
}

/// `(δ, (cos δ, sin δ))` of the two azimuth edges of a pixel with centre `(cos δ, sin δ)`
/// and half-width `half` (with its `(cos, sin)`); `δ` of the centre in `(−π, π]`.
fn pixel_edges((c, s): (f64, f64), (half, (hc, hs)): (f64, (f64, f64))) -> [(f64, (f64, f64)); 2] {
    let centre = libm::atan2(s, c);
    [
        (centre - half, (c * hc + s * hs, s * hc - c * hs)),
        (centre + half, (c * hc - s * hs, s * hc + c * hs)),
    ]
}

/// `∫ max(0, a + b·cos δ)ᴾ dδ` over the pixel between `edges`: the arc `|δ| < arccos(−a/b)`
/// where the integrand is positive (and its 2π translates, for pixels at δ = ±π) clipped to
/// the pixel, integrated in closed form by [`power_arc_integral`].
fn arc_integral(a: f64, b: f64, p: u32, edges: &[(f64, (f64, f64)); 2]) -> f64 {
    let (end, cos_end) = if b > 0.0 && libm::fabs(a) < b {
        (libm::acos(-a / b), -a / b)
    } else if a > 0.0 {
        (PI, -1.0)
    } else {
        return 0.0;
    };
    let sin_end = libm::sqrt((1.0 - cos_end * cos_end).max(0.0));
    let [first, last] = *edges;
    let mut total = 0.0;
    for shift in [-TAU, 0.0, TAU] {
        let (lo_arc, hi_arc) = (shift - end, shift + end);
        let lo = if first.0 >= lo_arc { first } else { (lo_arc, (cos_end, -sin_end)) };
        let hi = if last.0 <= hi_arc { last } else { (hi_arc, (cos_end, sin_end)) };
        if hi.0 > lo.0 {
            total += power_arc_integral(a, b, p, lo, hi);
        }
    }
    total
}

/// A pixel for [`bright_horizon_pixel`]: its polar band `(θ₀, θ₁)`, the `(cos δ, sin δ)` of
/// its centre's azimuth offset, and its half-width with the half-width's `(cos, sin)`.
type PixelBox = ((f64, f64), (f64, f64), (f64, (f64, f64)));

/// `∫∫ max(0, t)ᴾ sin θ dθ dφ / Δφ` over a pixel the horizon crosses, for pixels bright
/// enough that the kink must be integrated to the last digits: exact in φ ([`arc_integral`])
/// and in θ split where the horizon leaves the pixel through its azimuth edges and where it
/// is tangent to a parallel (θ = |π/2 − θ_d| and π − |π/2 − θ_d|), each piece by an 8-point
/// Gauss–Legendre rule clustered at both ends (θ = θ₀ + (θ₁ − θ₀)(1 − cos τ)/2), which
/// absorbs the square-root behaviour at tangencies. `pixel_box` is the polar band, the
/// centre `(cos δ, sin δ)` and the half-width with its `(cos, sin)`.
#[inline(never)]
fn bright_horizon_pixel(d: &Dir, pixel_box: PixelBox, p: u32) -> f64 {
    let ((th0, th1), centre, half) = pixel_box;
    let edges = pixel_edges(centre, half);
    let mut cuts = [th0, th1, th1, th1, th1, th1];
    let mut n = 2;
    let mut push = |x: f64| {
        if x > th0 && x < th1 {
            if let Some(slot) = cuts.get_mut(n) {
                *slot = x;
                n += 1;
            }
        }
    };
    // cos θ_d cos θ + sin θ_d cos δ_e sin θ = 0 at an edge δ_e, with sin θ ≥ 0.
    for (_, (cos_e, _)) in edges {
        let (ca, cb) = (d.cos_theta, d.sin_theta * cos_e);
        push(if ca >= 0.0 { libm::atan2(ca, -cb) } else { libm::atan2(-ca, cb) });
    }
    let extreme = libm::fabs(0.5 * PI - d.theta());
    push(extreme);
    push(PI - extreme);
    // Sort the cuts (at most six).
    let cuts = cuts.get_mut(..n).unwrap_or(&mut []);
    cuts.sort_unstable_by(f64::total_cmp);
    let rule = Rule::gauss_legendre(MAX_ORDER, 1);
    let mut total = 0.0;
    for piece in cuts.windows(2) {
        let [ta, tb] = [piece.first(), piece.get(1)].map(|x| x.copied().unwrap_or(0.0));
        for &(x, w) in rule.nodes() {
            let tau = 0.5 * PI * (x + 1.0);
            let (sin_tau, cos_tau) = libm::sincos(tau);
            let theta = ta + (tb - ta) * 0.5 * (1.0 - cos_tau);
            let jacobian = 0.5 * PI * 0.5 * (tb - ta) * sin_tau;
            let (st, ct) = libm::sincos(theta);
            let (a, b) = (d.cos_theta * ct, d.sin_theta * st);
            total += w * jacobian * st * arc_integral(a, b, p, &edges);
        }
    }
    total / (2.0 * half.0)
}

/// `∫ (a + b·cos δ)ᴾ dδ` from `δ₀` to `δ₁`, given `(δ, (cos δ, sin δ))` of both ends: the
/// binomial expansion over `J_k = ∫ cosᵏ δ dδ`, `J_k = [cosᵏ⁻¹δ·sin δ]/k + (k − 1)/k·J_{k−2}`
/// for `P ≤ 8` (the terms are at most `(|a| + |b|)ᴾ ≤ 16`, so cancellation near the horizon
/// costs at most 16 ulp of the pixel's peak value), else a 4-point Gauss–Legendre rule
/// (there the horizon band is below 10⁻¹³ of the lobe's peak).
fn power_arc_integral(a: f64, b: f64, p: u32, lo: (f64, (f64, f64)), hi: (f64, (f64, f64))) -> f64 {
    let (d0, (c0, s0)) = lo;
    let (d1, (c1, s1)) = hi;
    if p > 8 {
        let rule = Rule::gauss_legendre(HORIZON_ORDER, 1);
        let (mid, hw) = (0.5 * (d0 + d1), 0.5 * (d1 - d0));
        return rule
            .nodes()
            .iter()
            .map(|&(x, w)| hw * w * powi((a + b * libm::cos(mid + hw * x)).max(0.0), p))
            .sum();
    }
    // J_k for k = 0..=P, and the binomial sum.
    let mut j = [0.0; 9];
    let (mut pow0, mut pow1) = (1.0, 1.0); // cosᵏ⁻¹ at both ends
    for k in 0..=p as usize {
        let jk = match k {
            0 => d1 - d0,
            1 => s1 - s0,
            _ => {
                let kf = k as f64;
                let prev = j.get(k - 2).copied().unwrap_or(0.0);
                (pow1 * s1 - pow0 * s0) / kf + (kf - 1.0) / kf * prev
            }
        };
        if k >= 1 {
            pow0 *= c0;
            pow1 *= c1;
        }
        if let Some(slot) = j.get_mut(k) {
            *slot = jk;
        }
    }
    let mut total = 0.0;
    let mut binom = 1.0;
    for k in 0..=p {
        let jk = j.get(k as usize).copied().unwrap_or(0.0);
        total += binom * powi(a, p - k) * powi(b, k) * jk;
        binom = binom * f64::from(p - k) / f64::from(k + 1);
    }
    total.max(0.0)
}

/// The sub-columns of a pixel: `cos(δ + ψ_j) = cos δ·cos ψ_j − sin δ·sin ψ_j` for the node
/// offsets `ψ_j` from the pixel centre, with weights summing to 1.
struct SubColumns {
    nodes: [(f64, f64, f64); MAX_NODES],
    len: usize,
}

impl SubColumns {
    fn new(rule: &Rule, dphi: f64) -> Self {
        let mut nodes = [(1.0, 0.0, 0.0); MAX_NODES];
        let mut len = 0;
        for (slot, &(x, w)) in nodes.iter_mut().zip(rule.nodes()) {
            let (s, c) = libm::sincos(0.5 * dphi * x);
            *slot = (c, s, 0.5 * w);
            len += 1;
        }
        Self { nodes, len }
    }

    #[inline]
    fn sum(&self, c: f64, s: f64, f: impl Fn(f64) -> f64) -> f64 {
        let mut total = 0.0;
        for &(cj, sj, wj) in self.nodes.get(..self.len).unwrap_or(&[]) {
            total += wj * f(c * cj - s * sj);
        }
        total
    }
}

/// Column sums of one row (or of a row and its mirror image, which share the column
/// weights).
struct RowSums {
    a: [f64; 3],
    b: [f64; 3],
    weight_a: f64,
    weight_b: f64,
}

impl RowSums {
    #[inline(always)]
    fn add<const PAIR: bool>(&mut self, (ka, kb): (f64, f64), pa: &[f32; 3], pb: &[f32; 3]) {
        self.weight_a += ka;
        for (acc, &l) in self.a.iter_mut().zip(pa) {
            *acc += ka * f64::from(l);
        }
        if PAIR {
            self.weight_b += kb;
            for (acc, &l) in self.b.iter_mut().zip(pb) {
                *acc += kb * f64::from(l);
            }
        }
    }
}

/// `Σ_u w_u·L_u` over the columns whose boxes meet the window `[φ_d − δ, φ_d + δ]`, for
/// `row_a` (and `row_b` when `PAIR`), with `w_u = weight(cos δ_u, sin δ_u)` at the pixel
/// centre offset `δ_u = φ_u − φ_d` (advanced by a rotation recurrence along the row,
/// restarted at each range).
#[inline(always)]
fn row_sums<const PAIR: bool>(
    row_a: &[[f32; 3]],
    row_b: &[[f32; 3]],
    phi_d: f64,
    delta: f64,
    dphi: f64,
    weight: impl Fn(f64, f64, &[f32; 3]) -> (f64, f64),
) -> RowSums {
    // Two interleaved lanes (even and odd columns), each advanced by 2Δφ, so that two
    // independent lobe evaluations are in flight.
    let (step_s, step_c) = libm::sincos(2.0 * dphi);
    let mut out = RowSums { a: [0.0; 3], b: [0.0; 3], weight_a: 0.0, weight_b: 0.0 };
    for (start, end) in column_ranges(phi_d, delta, dphi, row_a.len()) {
        let (Some(ra), Some(rb)) = (row_a.get(start..end), row_b.get(start..end)) else {
            continue;
        };
        let first = (start as f64 + 0.5) * dphi - phi_d;
        let (mut s0, mut c0) = libm::sincos(first);
        let (mut s1, mut c1) = libm::sincos(first + dphi);
        let mut pairs_a = ra.chunks_exact(2);
        let mut pairs_b = rb.chunks_exact(2);
        for (qa, qb) in (&mut pairs_a).zip(&mut pairs_b) {
            if let ([pa0, pa1], [pb0, pb1]) = (qa, qb) {
                let (ka0, kb0) = weight(c0, s0, pa0);
                let (ka1, kb1) = weight(c1, s1, pa1);
                out.add::<PAIR>((ka0, kb0), pa0, pb0);
                out.add::<PAIR>((ka1, kb1), pa1, pb1);
            }
            (c0, s0) = (c0 * step_c - s0 * step_s, s0 * step_c + c0 * step_s);
            (c1, s1) = (c1 * step_c - s1 * step_s, s1 * step_c + c1 * step_s);
        }
        if let (Some(pa), Some(pb)) = (pairs_a.remainder().first(), pairs_b.remainder().first()) {
            out.add::<PAIR>(weight(c0, s0, pa), pa, pb);
        }
    }
    out
}

fn check_batch(dirs: &[Vec3], kind: Kind, out: &[[f32; 3]]) -> Result<(), Error> {
    if dirs.len() != out.len() {
        return Err(Error::LengthMismatch);
    }
    Lobe::new(kind)?;
    if dirs.iter().any(|d| d.try_normalize().is_none()) {
        return Err(Error::InvalidDirection);
    }
    Ok(())
}

/// Pixel range `[a, b)` of level-0 rows or columns covered by texel `i` of level `l` of a
/// side of `n0` pixels.
fn span(i: usize, l: usize, n0: usize) -> (usize, usize) {
    let shift = l.min(63) as u32;
    let n0 = n0 as u64;
    let a = ((i as u64) << shift).min(n0);
    let b = ((i as u64 + 1) << shift).min(n0);
    (a as usize, b as usize)
}

/// Entries of the pyramid buffer per texel: the mean RGB, then for each channel the offset
/// of its radiance-weighted mean vector from the texel's geometric mean vector.
const TEXEL_ENTRIES: usize = 4;

/// `(cos θ₀ − cos θ₁, ∫ sin²θ dθ, ∫ sinθ cosθ dθ)` over a band `θ ∈ [θ₀, θ₁]`, in forms
/// without cancellation.
#[derive(Clone, Copy)]
struct Band {
    height: f64,
    s_int: f64,
    z_int: f64,
}

impl Band {
    fn new(th0: f64, th1: f64) -> Self {
        let (dt, tc) = (th1 - th0, 0.5 * (th0 + th1));
        let (sdt, stc) = (libm::sin(dt), libm::sin(tc));
        Self {
            height: 2.0 * stc * libm::sin(0.5 * dt),
            s_int: 0.5 * (dt - sdt) + sdt * stc * stc,
            z_int: 0.5 * sdt * libm::sin(2.0 * tc),
        }
    }

    /// `∫ x dω / Ω` over the band's box between the azimuths with `(sin, cos)` `e0` and `e1`,
    /// `Δφ` apart: `(S·(sin φ₁ − sin φ₀), S·(cos φ₀ − cos φ₁), Z·Δφ)/Ω`.
    fn mean_vector(&self, e0: (f64, f64), e1: (f64, f64), dphi: f64) -> [f64; 3] {
        let omega = dphi * self.height;
        [
            self.s_int * (e1.0 - e0.0) / omega,
            self.s_int * (e0.1 - e1.1) / omega,
            self.z_int * dphi / omega,
        ]
    }
}

/// The geometry of pyramid level `level` of a `w0`×`h0` map: texel `(u, v)` covers the
/// map's rows [`span`]`(v)` and columns `span(u)`.
#[derive(Clone, Copy)]
struct Level {
    level: usize,
    w: usize,
    h: usize,
    w0: usize,
    h0: usize,
}

impl Level {
    fn new(level: usize, w0: usize, h0: usize) -> Self {
        let (mut w, mut h) = (w0, h0);
        for _ in 0..level {
            w = w.div_ceil(2);
            h = h.div_ceil(2);
        }
        Self { level, w, h, w0, h0 }
    }

    /// Width of a full texel in azimuth.
    fn dphi(&self) -> f64 {
        TAU / self.w0 as f64 * (1u64 << self.level.min(63)) as f64
    }

    /// Polar range of row `v`.
    fn theta(&self, v: usize) -> (f64, f64) {
        let (r0, r1) = span(v, self.level, self.h0);
        (PI * r0 as f64 / self.h0 as f64, PI * r1 as f64 / self.h0 as f64)
    }

    /// Azimuth range of column `u` (the last one ends at 2π).
    fn phi(&self, u: usize) -> (f64, f64) {
        let (c0, c1) = span(u, self.level, self.w0);
        (TAU * c0 as f64 / self.w0 as f64, TAU * c1 as f64 / self.w0 as f64)
    }

    /// `(solid angle, geometric mean vector)` of texel `(u, v)`.
    fn texel(&self, u: usize, v: usize) -> (f64, [f64; 3]) {
        let (th0, th1) = self.theta(v);
        let (ph0, ph1) = self.phi(u);
        let band = Band::new(th0, th1);
        let m = band.mean_vector(libm::sincos(ph0), libm::sincos(ph1), ph1 - ph0);
        ((ph1 - ph0) * band.height, m)
    }
}

/// `(t, s²)` of a mean vector `m` seen from the unit direction `d`: `t = d·m̂` and the
/// spread `s² = 1 − |m|²` (the mean squared distance of the directions from their mean).
fn t_spread(d: &[f64; 3], m: [f64; 3]) -> (f64, f64) {
    let n2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    if n2.is_nan() || n2 <= 0.0 {
        return (0.0, 1.0);
    }
    let t = (d[0] * m[0] + d[1] * m[1] + d[2] * m[2]) / libm::sqrt(n2);
    (t, (1.0 - n2).max(0.0))
}

/// A mip pyramid of an [`EquirectMap`] for fast approximate footprint samples, in a
/// caller-provided buffer: levels of solid-angle weighted 2×2 box averages, each texel with
/// the radiance-weighted mean direction vector of each channel (see the module docs,
/// "Fast form").
///
/// # Examples
/// ```
/// use sphere_quadrature::envmap::{EquirectMap, MipPyramid};
/// use sphere_quadrature::footprint::Kind;
/// use sphere_quadrature::Vec3;
///
/// // A constant map stays constant under every filter, exact or fast.
/// let pixels = [[0.5f32; 3]; 32 * 16];
/// let map = EquirectMap::new(32, 16, &pixels)?;
/// let mut buffer = vec![[0.0f32; 3]; MipPyramid::buffer_len(32, 16)];
/// let pyramid = MipPyramid::new(&map, &mut buffer)?;
/// assert!(pyramid.levels() > 1);
/// let y = pyramid.footprint_sample(Vec3::new(1.0, 1.0, 0.0), Kind::Gaussian { sharpness: 2 })?;
/// assert!(y.iter().all(|&c| (c - 0.5).abs() < 1e-5));
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct MipPyramid<'a> {
    map: EquirectMap<'a>,
    /// Levels 1, 2, …: [`TEXEL_ENTRIES`] entries per texel.
    levels: &'a [[f32; 3]],
    count: usize,
    resolution: f64,
}

impl<'a> MipPyramid<'a> {
    /// How many `[f32; 3]` the buffer of a `width`×`height` map's pyramid must hold: four per
    /// texel of levels 2, 3, … (`⌈w/2ˡ⌉×⌈h/2ˡ⌉` texels, until 1×1), about a third of the
    /// map's own length. 0 for a zero dimension.
    #[must_use]
    pub const fn buffer_len(width: usize, height: usize) -> usize {
        if width == 0 || height == 0 {
            return 0;
        }
        let (mut w, mut h, mut total) = (width, height, 0usize);
        let mut level = 0;
        while w > 1 || h > 1 {
            w = w.div_ceil(2);
            h = h.div_ceil(2);
            level += 1;
            if level >= FIRST_LEVEL {
                total = total.saturating_add(TEXEL_ENTRIES.saturating_mul(w.saturating_mul(h)));
            }
        }
        total
    }

    /// Builds the pyramid of `map` in `buffer` (its first
    /// [`buffer_len`](Self::buffer_len) entries; O(W·H)). The pyramid borrows the map's
    /// pixels for level 0.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `buffer` is shorter than
    /// [`buffer_len`](Self::buffer_len).
    pub fn new(map: &EquirectMap<'a>, buffer: &'a mut [[f32; 3]]) -> Result<Self, Error> {
        let need = Self::buffer_len(map.width, map.height);
        let buffer = buffer.get_mut(..need).ok_or(Error::LengthMismatch)?;
        let (w0, h0) = (map.width, map.height);
        // Level 2 is built from the pixels, each further level from the one before.
        let mut source = Level::new(0, w0, h0);
        let mut source_start = 0;
        let mut start = 0;
        let mut count = 0;
        for level in FIRST_LEVEL.. {
            let next = Level::new(level, w0, h0);
            let len = TEXEL_ENTRIES * next.w * next.h;
            let Some((done, rest)) = buffer.split_at_mut_checked(start) else {
                return Err(Error::LengthMismatch);
            };
            let Some(out) = rest.get_mut(..len) else {
                break;
            };
            if len == 0 {
                break;
            }
            build_level(map, source, done.get(source_start..).unwrap_or(&[]), next, out);
            source = next;
            source_start = start;
            start += len;
            count = level;
            if next.w <= 1 && next.h <= 1 {
                break;
            }
        }
        let levels: &'a [[f32; 3]] = buffer;
        Ok(Self { map: *map, levels, count, resolution: f64::from(DEFAULT_RESOLUTION) })
    }

    /// The same pyramid read at `resolution` texels per lobe width `1/√q` instead of
    /// [`DEFAULT_RESOLUTION`]: finer is more accurate and slower (see the module docs).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `0.5 ≤ resolution ≤ 64`.
    pub fn with_resolution(mut self, resolution: f32) -> Result<Self, Error> {
        if !(0.5..=64.0).contains(&resolution) {
            return Err(Error::InvalidParameter);
        }
        self.resolution = f64::from(resolution);
        Ok(self)
    }

    /// The map the pyramid was built from (level 0).
    #[must_use]
    pub fn map(&self) -> EquirectMap<'a> {
        self.map
    }

    /// Number of levels, the map included.
    #[must_use]
    pub fn levels(&self) -> usize {
        self.count + 1
    }

    /// `(width, height)` of level `level` (0 is the map), or `None` past the last level.
    #[must_use]
    pub fn level_size(&self, level: usize) -> Option<(usize, usize)> {
        if level > self.count {
            return None;
        }
        let l = Level::new(level, self.map.width, self.map.height);
        Some((l.w, l.h))
    }

    /// The solid-angle weighted mean radiance of texel `(u, v)` of level `level` (the pixel
    /// itself for level 0), or `None` when out of range.
    #[must_use]
    pub fn texel(&self, level: usize, u: usize, v: usize) -> Option<[f32; 3]> {
        let (w, h) = self.level_size(level)?;
        if u >= w || v >= h {
            return None;
        }
        if level == 0 {
            return self.map.row(v).get(u).copied();
        }
        self.level_slice(level)?.get(TEXEL_ENTRIES * (v * w + u)).copied()
    }

    fn level_slice(&self, level: usize) -> Option<&'a [[f32; 3]]> {
        if level < FIRST_LEVEL || level > self.count {
            return None;
        }
        let mut start = 0;
        for l in FIRST_LEVEL..level {
            let g = Level::new(l, self.map.width, self.map.height);
            start += TEXEL_ENTRIES * g.w * g.h;
        }
        let g = Level::new(level, self.map.width, self.map.height);
        self.levels.get(start..start + TEXEL_ENTRIES * g.w * g.h)
    }

    /// The level the fast form reads for a lobe of sharpness `q`: the coarsest whose texels
    /// are at most `1/(resolution·√q)` across.
    fn level_for(&self, q: f64) -> usize {
        let h0 = (PI / self.map.height as f64).max(TAU / self.map.width as f64);
        let width = 1.0 / (self.resolution * libm::sqrt(q));
        let mut l = 0;
        let mut size = 2.0 * h0;
        while l < self.count && size <= width {
            l += 1;
            size *= 2.0;
        }
        if l < FIRST_LEVEL {
            0
        } else {
            l
        }
    }

    /// The fast approximate footprint sample in direction `dir` (see the module docs, "Fast
    /// form"): the exact form on the map when the lobe is at most a few pixels wide,
    /// otherwise a moment rule on the coarsest pyramid level with at least
    /// [`DEFAULT_RESOLUTION`] (or [`with_resolution`](Self::with_resolution)) texels per
    /// lobe width. [`Kind::Point`] gives the map's [`radiance`](EquirectMap::radiance).
    ///
    /// # Errors
    /// As [`EquirectMap::footprint_sample`].
    pub fn footprint_sample(&self, dir: Vec3, kind: Kind) -> Result<[f32; 3], Error> {
        let Some(lobe) = Lobe::new(kind)? else {
            return self.map.radiance(dir);
        };
        let d = Dir::new(dir)?;
        let level = self.level_for(lobe.sharpness());
        let y = if level == 0 { self.map.exact(&d, lobe) } else { self.coarse(&d, lobe, level) };
        Ok(to_f32(y))
    }

    /// [`footprint_sample`](Self::footprint_sample) for every direction of `dirs`, into
    /// `out`; `out` is left unchanged on error.
    ///
    /// # Errors
    /// As [`EquirectMap::footprint_samples`].
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

    /// The moment rule on level `level`:
    /// `Y_c = Σ_T Ω_T·L_{T,c}·F(m_{T,c}) / Σ_T Ω_T·F(m_T)` with `F(m) = f(d·m̂) + (s²/4)·Δf`
    /// (the lobe's mean over directions of mean vector `m`, `s² = 1 − |m|²`), `m_{T,c}` the
    /// texel's radiance-weighted mean vector of channel `c` and `m_T` its geometric one.
    /// Only texels whose box's convex hull (which holds every mean vector's direction)
    /// meets the cap where the lobe exceeds 10⁻¹³ of its peak are visited. For a cosine
    /// power, texels within their diameter of the horizon take the box average of the lobe
    /// by a 4×4 Gauss–Legendre rule instead (the kink of `max(0, t)`).
    fn coarse(&self, d: &Dir, lobe: Lobe, level: usize) -> [f64; 3] {
        let fallback =
            || to_f64(self.map.nearest(Vec3::new(d.v[0] as f32, d.v[1] as f32, d.v[2] as f32)));
        let Some(texels) = self.level_slice(level) else {
            return fallback();
        };
        let g = Level::new(level, self.map.width, self.map.height);
        let t_cut = lobe.t_below(LN_FAST_CUTOFF);
        let alpha = if t_cut > -1.0 { libm::acos(t_cut.min(1.0)) } else { PI };
        let theta_d = d.theta();
        let dphi = g.dphi();
        let dth = PI / self.map.height as f64 * (1u64 << level.min(63)) as f64;
        // Texels wider than a half-turn are not convex in azimuth: read whole rows.
        let wide = dphi > PI;
        let pole_in_cap = theta_d <= alpha || PI - theta_d <= alpha;
        let cos_alpha = libm::cos(alpha);
        let theta_star =
            if pole_in_cap { 0.0 } else { libm::acos((d.cos_theta / cos_alpha).clamp(-1.0, 1.0)) };
        // The great-circle chord between a parallel's two texel corners comes closest to
        // the pole at tan θ′ = tan θ·cos(Δφ/2).
        let hull = libm::cos(0.5 * dphi.min(PI)).max(0.0);
        let kink = match lobe {
            // Half the texel's diagonal bounds the angle from its centroid to any point.
            Lobe::Power(_) => 0.51 * libm::sqrt(dth * dth + dphi * dphi),
            Lobe::Gaussian(_) => -1.0,
        };
        let step = libm::sincos(dphi);
        let (mut n0, mut n1, mut n2, mut den) = (0.0, 0.0, 0.0, 0.0);
        for v in 0..g.h {
            let (th0, th1) = g.theta(v);
            let top = if th0 < 0.5 * PI { libm::atan(libm::tan(th0) * hull) } else { th0 };
            let bottom =
                if th1 > 0.5 * PI { PI - libm::atan(libm::tan(PI - th1) * hull) } else { th1 };
            let gap = (top - theta_d).max(theta_d - bottom).max(0.0);
            if gap > alpha {
                continue;
            }
            let delta = if pole_in_cap || wide {
                PI
            } else {
                // max/min, not clamp: clamp panics when top > bottom (or on NaN).
                let th = theta_star.max(top).min(bottom);
                let (st, ct) = libm::sincos(th);
                let den = d.sin_theta * st;
                if den > 0.0 {
                    libm::acos(((cos_alpha - d.cos_theta * ct) / den).clamp(-1.0, 1.0))
                } else {
                    PI
                }
            };
            let band = Band::new(th0, th1);
            let start = TEXEL_ENTRIES * v * g.w;
            let row = texels.get(start..start + TEXEL_ENTRIES * g.w).unwrap_or(&[]);
            for (a, b) in column_ranges(d.phi, delta, dphi, g.w) {
                let Some(cells) = row.get(TEXEL_ENTRIES * a..TEXEL_ENTRIES * b) else {
                    continue;
                };
                // Azimuth edges by a rotation recurrence; the last column ends at 2π.
                let mut e0 = libm::sincos(a as f64 * dphi);
                for (u, cell) in (a..).zip(cells.chunks_exact(TEXEL_ENTRIES)) {
                    let last = u + 1 == g.w;
                    let e1 = if last {
                        (0.0, 1.0)
                    } else {
                        (e0.0 * step.1 + e0.1 * step.0, e0.1 * step.1 - e0.0 * step.0)
                    };
                    let width = if last { TAU - u as f64 * dphi } else { dphi };
                    let omega = width * band.height;
                    let m_geo = band.mean_vector(e0, e1, width);
                    e0 = e1;
                    let Ok(cell) = <&[[f32; 3]; TEXEL_ENTRIES]>::try_from(cell) else {
                        continue;
                    };
                    let (t, s2) = t_spread(&d.v, m_geo);
                    let terms = if libm::fabs(t) < kink {
                        let (ph0, _) = g.phi(u);
                        kink_terms(d, lobe, ((th0, th1), (ph0, ph0 + width)), m_geo, cell)
                    } else {
                        let [rgb, dr, dg, db] = *cell;
                        let mean = |off: [f32; 3]| {
                            let m = [
                                m_geo[0] + f64::from(off[0]),
                                m_geo[1] + f64::from(off[1]),
                                m_geo[2] + f64::from(off[2]),
                            ];
                            let (t, s2) = t_spread(&d.v, m);
                            lobe.value_with_spread(t, s2)
                        };
                        [
                            lobe.value_with_spread(t, s2),
                            f64::from(rgb[0]) * mean(dr),
                            f64::from(rgb[1]) * mean(dg),
                            f64::from(rgb[2]) * mean(db),
                        ]
                    };
                    den += omega * terms[0];
                    n0 += omega * terms[1];
                    n1 += omega * terms[2];
                    n2 += omega * terms[3];
                }
            }
        }
        let num = [n0, n1, n2];
        if den > 0.0 {
            num.map(|n| n / den)
        } else {
            fallback()
        }
    }
}

/// `[F_geo, L_r·F_r, L_g·F_g, L_b·F_b]` of a texel the lobe's kink crosses (see
/// [`MipPyramid::coarse`]): box averages, each channel's box moved along `t` to its mean
/// vector and scaled by its spread relative to the geometric one.
#[inline(never)]
fn kink_terms(
    d: &Dir,
    lobe: Lobe,
    bx: ((f64, f64), (f64, f64)),
    m_geo: [f64; 3],
    cell: &[[f32; 3]; TEXEL_ENTRIES],
) -> [f64; 4] {
    let (t, s2) = t_spread(&d.v, m_geo);
    let [rgb, dr, dg, db] = *cell;
    let mut terms = [box_average(d, lobe, bx, (t, t, 1.0)), 0.0, 0.0, 0.0];
    for ((term, l), off) in terms.iter_mut().skip(1).zip(rgb).zip([dr, dg, db]) {
        let m = [0, 1, 2].map(|i| m_geo[i] + f64::from(off[i]));
        let (tc, sc) = t_spread(&d.v, m);
        let k = if s2 > 0.0 { libm::sqrt(sc / s2).min(2.0) } else { 1.0 };
        *term = f64::from(l) * box_average(d, lobe, bx, (t, tc, k));
    }
    terms
}

/// The mean of the (unnormalised) lobe over the box `θ ∈ [θ₀, θ₁]`, `φ ∈ [φ₀, φ₁]` by a 4×4
/// Gauss–Legendre rule in `(θ, φ)` with the weight `sin θ`, for a distribution of directions
/// shaped like the box but centred at `t_c` and scaled by `k` about it: the lobe is read at
/// `t_c + k·(t − t_geo)`, `t_geo` the box centroid's.
fn box_average(
    d: &Dir,
    lobe: Lobe,
    bx: ((f64, f64), (f64, f64)),
    (t_geo, t_c, k): (f64, f64, f64),
) -> f64 {
    let ((th0, th1), (ph0, ph1)) = bx;
    let rule = Rule::gauss_legendre(HORIZON_ORDER, 1);
    let (mut sum, mut weight) = (0.0, 0.0);
    for &(xi, wi) in rule.nodes() {
        let (st, ct) = libm::sincos(th0 + 0.5 * (1.0 + xi) * (th1 - th0));
        let (a, b) = (d.cos_theta * ct, d.sin_theta * st);
        for &(xj, wj) in rule.nodes() {
            let c = libm::cos(ph0 + 0.5 * (1.0 + xj) * (ph1 - ph0) - d.phi);
            sum += wi * wj * st * lobe.value(t_c + k * (a + b * c - t_geo));
            weight += wi * wj * st;
        }
    }
    if weight > 0.0 {
        sum / weight
    } else {
        0.0
    }
}

/// Builds level `next` (`out`) from the finer level `source` (`source_texels`, or the map
/// for level 0): per texel the solid-angle weighted mean radiance and, per channel, the mean
/// of the children's mean vectors weighted by `Ω·max(0, L_c)` (the geometric mean vector
/// when that weight is zero), stored as its offset from the texel's geometric mean vector.
fn build_level(
    map: &EquirectMap<'_>,
    source: Level,
    source_texels: &[[f32; 3]],
    next: Level,
    out: &mut [[f32; 3]],
) {
    let factor = 1usize << (next.level - source.level).min(8);
    // Child texel (u, v): (radiance, per-channel mean vectors, solid angle).
    let child = |u: usize, v: usize| -> Option<([f64; 3], [[f64; 3]; 3], f64)> {
        if u >= source.w || v >= source.h {
            return None;
        }
        let (omega, m_geo) = source.texel(u, v);
        if source.level == 0 {
            let rgb = to_f64(map.row(v).get(u).copied()?);
            return Some((rgb, [m_geo; 3], omega));
        }
        let i = TEXEL_ENTRIES * (v * source.w + u);
        let rgb = to_f64(*source_texels.get(i)?);
        let mut m = [m_geo; 3];
        for (k, mk) in m.iter_mut().enumerate() {
            let off = to_f64(*source_texels.get(i + 1 + k)?);
            *mk = [mk[0] + off[0], mk[1] + off[1], mk[2] + off[2]];
        }
        Some((rgb, m, omega))
    };
    let row_len = (TEXEL_ENTRIES * next.w).max(1); // chunks_exact_mut(0) would panic
    for (v, row) in out.chunks_exact_mut(row_len).take(next.h).enumerate() {
        for (u, cell) in row.chunks_exact_mut(TEXEL_ENTRIES).enumerate() {
            let mut area = 0.0;
            let mut rgb = [0.0; 3];
            let mut weight = [0.0; 3];
            let mut moment = [[0.0; 3]; 3];
            for dv in 0..factor {
                for du in 0..factor {
                    let Some((l, m, om)) = child(factor * u + du, factor * v + dv) else {
                        continue;
                    };
                    area += om;
                    for c in 0..3 {
                        rgb[c] += om * l[c];
                        let w = om * l[c].max(0.0);
                        weight[c] += w;
                        for k in 0..3 {
                            moment[c][k] += w * m[c][k];
                        }
                    }
                }
            }
            let (_, m_geo) = next.texel(u, v);
            let mean = if area > 0.0 { rgb.map(|x| x / area) } else { [0.0; 3] };
            if let Some(first) = cell.first_mut() {
                *first = to_f32(mean);
            }
            for (c, slot) in cell.iter_mut().skip(1).enumerate().take(3) {
                let (Some(&wc), Some(mc)) = (weight.get(c), moment.get(c)) else {
                    continue;
                };
                *slot = if wc > 0.0 {
                    to_f32([0, 1, 2].map(|k| mc[k] / wc - m_geo[k]))
                } else {
                    [0.0; 3]
                };
            }
        }
    }
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
