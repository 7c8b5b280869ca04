//! The exact form's rules: Gauss–Legendre rules in θ and φ, the lobe, and the sums over the
//! pixels a footprint covers.

use super::*;

/// Gauss–Legendre rules on `[−1, 1]` of orders 1 to [`MAX_ORDER`]: the non-negative nodes
/// with their weights (the rules are symmetric).
pub(super) const GAUSS_LEGENDRE: [&[(f64, f64)]; MAX_ORDER] = [
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
pub(super) struct Rule {
    pub(super) nodes: [(f64, f64); MAX_NODES],
    pub(super) len: usize,
}

impl Rule {
    /// The Gauss–Legendre rule of order `k` (clamped to `1..=MAX_ORDER`) on `panels` equal
    /// panels (clamped to `1..=MAX_PANELS`).
    pub(super) fn gauss_legendre(k: usize, panels: usize) -> Self {
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
    pub(super) fn for_lobe(q: f64, h: f64) -> Self {
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

    pub(super) fn nodes(&self) -> &[(f64, f64)] {
        self.nodes.get(..self.len).unwrap_or(&[])
    }
}

/// `kind` checked: `None` for [`Kind::Point`] (a lookup answers it from the map's radiance),
/// the Gaussian or cosine-power kind itself otherwise; [`Error::InvalidResponse`] for a
/// parameter of 0 or above [`MAX_PARAMETER`].
pub(super) fn lobe_of(kind: Kind) -> Result<Option<Kind>, Error> {
    match kind {
        Kind::Point => Ok(None),
        Kind::Gaussian { sharpness: q } | Kind::CosinePower { exponent: q }
            if (1..=MAX_PARAMETER).contains(&q) =>
        {
            Ok(Some(kind))
        }
        _ => Err(Error::InvalidResponse),
    }
}

/// The shape of a footprint's lobe, unnormalised (peak 1 at `t = 1`), for the lookups: the
/// Gaussian `exp(S(t − 1))` and the cosine power `max(0, t)ᴾ`. A point (never passed: see
/// [`lobe_of`]) is the limit of infinite sharpness, `1` at `t = 1` and `0` below.
pub(super) trait Lobe: Copy {
    /// The sharpness `q` (`S` or `P`): the lobe's angular width is about `1/√q`.
    fn sharpness(self) -> f64;

    /// The `t` below which the lobe is under `e^ln_fraction` of its peak (may be below −1).
    fn t_below(self, ln_fraction: f64) -> f64;

    /// The `t` below which the lobe is under `10⁻¹³` of its peak (may be below −1).
    fn t_cut(self) -> f64 {
        self.t_below(LN_CUTOFF)
    }

    /// `g(t) + (s²/4)·Δg(t)`, clamped at 0: the mean of the lobe `g` over a small
    /// isotropic spread of directions about a direction at `t`, with
    /// `s² = E|x − E x|²` and the surface Laplacian `Δg = (1 − t²)·g″(t) − 2t·g′(t)`.
    fn value_with_spread(self, t: f64, spread: f64) -> f64;

    /// The lobe at `t`.
    fn value(self, t: f64) -> f64;
}

impl Lobe for Kind {
    fn sharpness(self) -> f64 {
        match self {
            Kind::Gaussian { sharpness: q } | Kind::CosinePower { exponent: q } => f64::from(q),
            Kind::Point => f64::INFINITY,
        }
    }

    fn t_below(self, ln_fraction: f64) -> f64 {
        match self {
            Kind::Gaussian { sharpness: s } => 1.0 + ln_fraction / f64::from(s),
            Kind::CosinePower { exponent: p } => libm::exp(ln_fraction / f64::from(p)),
            Kind::Point => 1.0,
        }
    }

    #[inline]
    fn value_with_spread(self, t: f64, spread: f64) -> f64 {
        let t = t.clamp(-1.0, 1.0);
        let q = 0.25 * spread;
        let v = match self {
            Kind::Gaussian { sharpness } => {
                let s = f64::from(sharpness);
                exp(s * (t - 1.0)) * (1.0 + q * s * (s * (1.0 - t * t) - 2.0 * t))
            }
            Kind::CosinePower { exponent: p } => {
                if t <= 0.0 {
                    return 0.0;
                }
                let pf = f64::from(p);
                let low = if p >= 2 { powi(t, p - 2) } else { 1.0 / t };
                low * (t * t + q * pf * ((pf - 1.0) * (1.0 - t * t) - 2.0 * t * t))
            }
            Kind::Point => self.value(t),
        };
        v.max(0.0)
    }

    #[inline]
    fn value(self, t: f64) -> f64 {
        match self {
            Kind::Gaussian { sharpness: s } => exp(f64::from(s) * (t - 1.0)),
            Kind::CosinePower { exponent: p } => powi(t.max(0.0), p),
            Kind::Point => {
                if t >= 1.0 {
                    1.0
                } else {
                    0.0
                }
            }
        }
    }
}

/// `2^(j/32)` for `j = 0..32`, correctly rounded.
pub(super) const EXP2_TABLE: [f64; 32] = [
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
pub(super) fn exp(x: f64) -> f64 {
    pub(super) const SHIFTER: f64 = 6_755_399_441_055_744.0; // 1.5·2⁵²: adding it rounds to an integer
    pub(super) const INV_STEP: f64 = 46.166_241_308_446_83; // 32/ln 2
    pub(super) const STEP_HI: f64 = 0.021_660_849_386_535_12; // ln 2/32 with 21 trailing zero bits
    pub(super) const STEP_LO: f64 = 5.963_171_653_970_586_6e-12; // ln 2/32 − STEP_HI
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
pub(super) fn powi(mut x: f64, mut n: u32) -> f64 {
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
pub(super) struct Dir {
    pub(super) v: [f64; 3],
    pub(super) cos_theta: f64,
    pub(super) sin_theta: f64,
    /// Azimuth in `[0, 2π]`.
    pub(super) phi: f64,
}

impl Dir {
    pub(super) fn new(dir: Vec3) -> Result<Self, Error> {
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

    pub(super) fn theta(&self) -> f64 {
        libm::atan2(self.sin_theta, self.cos_theta)
    }
}

/// Weighted sums `Σ w·L` and `Σ w`.
#[derive(Clone, Copy, Default)]
pub(super) struct Sums {
    pub(super) acc: [f64; 3],
    pub(super) weight: f64,
}

impl Sums {
    pub(super) fn add(&mut self, w: f64, rgb: [f64; 3]) {
        for (a, c) in self.acc.iter_mut().zip(rgb) {
            *a += w * c;
        }
    }

    /// `Σ w·L / Σ w`, or `None` when no weight was summed.
    pub(super) fn mean(&self) -> Option<[f64; 3]> {
        if self.weight > 0.0 {
            Some(self.acc.map(|a| a / self.weight))
        } else {
            None
        }
    }
}

pub(super) fn to_f64(p: [f32; 3]) -> [f64; 3] {
    p.map(f64::from)
}

pub(super) fn to_f32(p: [f64; 3]) -> [f32; 3] {
    p.map(|c| c as f32)
}

/// Index ranges `[a, b)` of the `n` columns of width `dphi` (the last one ends at 2π, so it
/// may be narrower) whose azimuth intervals meet `[φ − δ, φ + δ]` modulo 2π; the second
/// range is empty unless the window wraps.
pub(super) fn column_ranges(phi: f64, delta: f64, dphi: f64, n: usize) -> [(usize, usize); 2] {
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

/// The sub-columns of a pixel: `cos(δ + ψ_j) = cos δ·cos ψ_j − sin δ·sin ψ_j` for the node
/// offsets `ψ_j` from the pixel centre, with weights summing to 1.
pub(super) struct SubColumns {
    pub(super) nodes: [(f64, f64, f64); MAX_NODES],
    pub(super) len: usize,
}

impl SubColumns {
    pub(super) fn new(rule: &Rule, dphi: f64) -> Self {
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
    pub(super) fn sum(&self, c: f64, s: f64, f: impl Fn(f64) -> f64) -> f64 {
        let mut total = 0.0;
        for &(cj, sj, wj) in self.nodes.get(..self.len).unwrap_or(&[]) {
            total += wj * f(c * cj - s * sj);
        }
        total
    }
}

/// Column sums of one row (or of a row and its mirror image, which share the column
/// weights).
pub(super) struct RowSums {
    pub(super) a: [f64; 3],
    pub(super) b: [f64; 3],
    pub(super) weight_a: f64,
    pub(super) weight_b: f64,
}

impl RowSums {
    #[inline(always)]
    pub(super) fn add<const PAIR: bool>(
        &mut self,
        (ka, kb): (f64, f64),
        pa: &[f32; 3],
        pb: &[f32; 3],
    ) {
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
pub(super) fn row_sums<const PAIR: bool>(
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
