//! The fast form: a mip pyramid of the map, read through a footprint.

use super::*;

/// Pixel range `[a, b)` of level-0 rows or columns covered by texel `i` of level `l` of a
/// side of `n0` pixels.
pub(super) fn span(i: usize, l: usize, n0: usize) -> (usize, usize) {
    let shift = l.min(63) as u32;
    let n0 = n0 as u64;
    let a = ((i as u64) << shift).min(n0);
    let b = ((i as u64 + 1) << shift).min(n0);
    (a as usize, b as usize)
}

/// Entries of the pyramid buffer per texel: the mean RGB, then for each channel the offset
/// of its radiance-weighted mean vector from the texel's geometric mean vector.
pub(super) const TEXEL_ENTRIES: usize = 4;

/// `(cos θ₀ − cos θ₁, ∫ sin²θ dθ, ∫ sinθ cosθ dθ)` over a band `θ ∈ [θ₀, θ₁]`, in forms
/// without cancellation.
#[derive(Clone, Copy)]
pub(super) struct Band {
    pub(super) height: f64,
    pub(super) s_int: f64,
    pub(super) z_int: f64,
}

impl Band {
    pub(super) fn new(th0: f64, th1: f64) -> Self {
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
    pub(super) fn mean_vector(&self, e0: (f64, f64), e1: (f64, f64), dphi: f64) -> [f64; 3] {
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
pub(super) struct Level {
    pub(super) level: usize,
    pub(super) w: usize,
    pub(super) h: usize,
    pub(super) w0: usize,
    pub(super) h0: usize,
}

impl Level {
    pub(super) fn new(level: usize, w0: usize, h0: usize) -> Self {
        let (mut w, mut h) = (w0, h0);
        for _ in 0..level {
            w = w.div_ceil(2);
            h = h.div_ceil(2);
        }
        Self { level, w, h, w0, h0 }
    }

    /// Width of a full texel in azimuth.
    pub(super) fn dphi(&self) -> f64 {
        TAU / self.w0 as f64 * (1u64 << self.level.min(63)) as f64
    }

    /// Polar range of row `v`.
    pub(super) fn theta(&self, v: usize) -> (f64, f64) {
        let (r0, r1) = span(v, self.level, self.h0);
        (PI * r0 as f64 / self.h0 as f64, PI * r1 as f64 / self.h0 as f64)
    }

    /// Azimuth range of column `u` (the last one ends at 2π).
    pub(super) fn phi(&self, u: usize) -> (f64, f64) {
        let (c0, c1) = span(u, self.level, self.w0);
        (TAU * c0 as f64 / self.w0 as f64, TAU * c1 as f64 / self.w0 as f64)
    }

    /// `(solid angle, geometric mean vector)` of texel `(u, v)`.
    pub(super) fn texel(&self, u: usize, v: usize) -> (f64, [f64; 3]) {
        let (th0, th1) = self.theta(v);
        let (ph0, ph1) = self.phi(u);
        let band = Band::new(th0, th1);
        let m = band.mean_vector(libm::sincos(ph0), libm::sincos(ph1), ph1 - ph0);
        ((ph1 - ph0) * band.height, m)
    }
}

/// `(t, s²)` of a mean vector `m` seen from the unit direction `d`: `t = d·m̂` and the
/// spread `s² = 1 − |m|²` (the mean squared distance of the directions from their mean).
pub(super) fn t_spread(d: &[f64; 3], m: [f64; 3]) -> (f64, f64) {
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
    pub(super) map: EquirectMap<'a>,
    /// Levels 1, 2, …: [`TEXEL_ENTRIES`] entries per texel.
    pub(super) levels: &'a [[f32; 3]],
    pub(super) count: usize,
    pub(super) resolution: f64,
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
    /// [`Error::InvalidResolution`] unless `0.5 ≤ resolution ≤ 64`.
    pub fn with_resolution(mut self, resolution: f32) -> Result<Self, Error> {
        if !(0.5..=64.0).contains(&resolution) {
            return Err(Error::InvalidResolution);
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

    pub(super) fn level_slice(&self, level: usize) -> Option<&'a [[f32; 3]]> {
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
    pub(super) fn level_for(&self, q: f64) -> usize {
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
        let Some(lobe) = lobe_of(kind)? else {
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
    pub(super) fn coarse(&self, d: &Dir, lobe: Kind, level: usize) -> [f64; 3] {
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
            Kind::CosinePower { .. } => 0.51 * libm::sqrt(dth * dth + dphi * dphi),
            Kind::Gaussian { .. } | Kind::Point => -1.0,
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
                azimuth_reach(d, theta_star.max(top).min(bottom), cos_alpha)
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
                        moment_terms(d, lobe, (t, s2), m_geo, cell)
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

/// The half-width in azimuth of the lobe's cap `t ≥ cos α` on the parallel at polar angle
/// `th` (π where the parallel lies in the cap all round or `d` is at a pole).
fn azimuth_reach(d: &Dir, th: f64, cos_alpha: f64) -> f64 {
    let (st, ct) = libm::sincos(th);
    let den = d.sin_theta * st;
    if den > 0.0 {
        libm::acos(((cos_alpha - d.cos_theta * ct) / den).clamp(-1.0, 1.0))
    } else {
        PI
    }
}

/// `[F_geo, L_r·F_r, L_g·F_g, L_b·F_b]` of a texel by the moment rule (see
/// [`MipPyramid::coarse`]): `F` at the geometric mean vector (`(t, s²)` given) and at each
/// channel's.
fn moment_terms(
    d: &Dir,
    lobe: Kind,
    (t, s2): (f64, f64),
    m_geo: [f64; 3],
    cell: &[[f32; 3]; TEXEL_ENTRIES],
) -> [f64; 4] {
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
}

/// `[F_geo, L_r·F_r, L_g·F_g, L_b·F_b]` of a texel the lobe's kink crosses (see
/// [`MipPyramid::coarse`]): box averages, each channel's box moved along `t` to its mean
/// vector and scaled by its spread relative to the geometric one.
#[inline(never)]
pub(super) fn kink_terms(
    d: &Dir,
    lobe: Kind,
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
pub(super) fn box_average(
    d: &Dir,
    lobe: Kind,
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
pub(super) fn build_level(
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
