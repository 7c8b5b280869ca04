//! Every transcendental function the crate uses, as free functions over one backend.
//!
//! Internal: hidden from the documentation and outside the semver contract. It is public only
//! so that the crate's own tests and device examples can evaluate bit for bit what the library
//! evaluates.
//!
//! All f32 math in the crate goes through these functions (never method syntax on `f32`), so
//! the backend is chosen in one place:
//!
//! - **`libm`** (default): correctly rounded or sub-ULP accurate `libm` ports.
//! - **`micromath`**: fast approximations for cores where speed and code size matter more than
//!   the last digits. When both features are on, `micromath` wins: `libm` is on by default, so
//!   enabling `micromath` is always an explicit opt-in. Choosing approximate math is the final
//!   binary's decision; a library that depends on this crate should not enable `micromath`.
//!
//! `micromath` supplies only `sin`, `cos`, `atan2` and `exp`. Everything else always comes from
//! `libm`, which is therefore always linked (functions that are not called cost no flash):
//! micromath's other functions are too coarse for quadrature. Measured here over their
//! domains (2·10⁶ points, against f64): micromath `sin`/`cos` 1.1·10⁻³ absolute, `atan2`
//! 2.8·10⁻³ absolute, `exp` 2.4·10⁻³ relative on `[−10, 0]` — but `sqrt` 6·10⁻² relative,
//! `ln` 0.12 absolute, `acos` 2.9·10⁻² absolute and `powf` 5.9·10⁻³ relative, so `sqrt`,
//! `acos`, `ln`, `powf`, `expm1`, `ln_1p`, `floor`, `abs`, `copysign` and every f64 function
//! use `libm` under both backends. With neither feature on, `libm` is used.
//!
//! # Example
//! ```
//! use sphere_quadrature::math;
//!
//! // The same functions under either backend (`libm` or `micromath`).
//! let (s, c) = math::sin_cos_turns(1 << 61); // an eighth of a turn
//! assert!((s - core::f32::consts::FRAC_1_SQRT_2).abs() < 1e-6);
//! assert!((s * s + c * c - 1.0).abs() < 1e-6);
//! assert!((math::inv_sqrt(4.0) - 0.5).abs() < 1e-7);
//! assert!((math::sqrt(2.0) * math::sqrt(2.0) - 2.0).abs() < 1e-6);
//! ```

#[cfg(feature = "micromath")]
mod backend {
    use micromath::F32Ext;

    #[inline]
    pub fn sin(x: f32) -> f32 {
        F32Ext::sin(x)
    }
    #[inline]
    pub fn cos(x: f32) -> f32 {
        F32Ext::cos(x)
    }
    #[inline]
    pub fn atan2(y: f32, x: f32) -> f32 {
        F32Ext::atan2(y, x)
    }
    #[inline]
    pub fn exp(x: f32) -> f32 {
        F32Ext::exp(x)
    }
}

#[cfg(not(feature = "micromath"))]
mod backend {
    #[inline]
    pub fn sin(x: f32) -> f32 {
        libm::sinf(x)
    }
    #[inline]
    pub fn cos(x: f32) -> f32 {
        libm::cosf(x)
    }
    #[inline]
    pub fn atan2(y: f32, x: f32) -> f32 {
        libm::atan2f(y, x)
    }
    #[inline]
    pub fn exp(x: f32) -> f32 {
        libm::expf(x)
    }
}

/// Square root; NaN for negative input.
#[inline]
#[must_use]
pub fn sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}

/// The square root of a positive, finite `v` within one ulp of [`sqrt`]: Newton's iteration
/// in f32 from the halved exponent, usable in constant evaluation (the same bits at compile
/// time and at run time) and cheaper than [`sqrt_const`] on a core without f64, for code
/// that needs no correct rounding (the layout probe's tables). 0 otherwise.
pub(crate) const fn sqrt_newton(v: f32) -> f32 {
    if !(v > 0.0 && v.is_finite()) {
        return 0.0;
    }
    // Subnormals: scale up by 2^24 first (the root by 2^12).
    let (v, back) = if v < 1e-30 { (v * 16_777_216.0, 1.0 / 4096.0) } else { (v, 1.0) };
    let mut r = f32::from_bits((v.to_bits() >> 1) + 0x1fbd_1df5);
    let mut k = 0;
    while k < 4 {
        r = 0.5 * (r + v / r);
        k += 1;
    }
    r * back
}

/// Square root of a positive normal `x`, correctly rounded (so equal to [`sqrt`] bit for
/// bit), usable in constant evaluation: the integer square root of the significand shifted
/// by 38 bits, with a sticky bit for inexact roots, rounded once by the cast to f32. Outside
/// the positive normal numbers the result is meaningless; callers check `x` first.
#[must_use]
pub const fn sqrt_const(x: f32) -> f32 {
    let bits = x.to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 150;
    let mut m = (bits & 0x7f_ffff | 0x80_0000) as u64;
    if e & 1 != 0 {
        m <<= 1;
        e -= 1;
    }
    // x = m·2^e with e even and m < 2²⁵; √x = √(m·2³⁸)·2^(e/2 − 19), the root of 31 or 32
    // bits: 7 or more below the rounding position, the last one sticky.
    // Digit by digit (no table: `u64::isqrt` links a 256-byte one): r = ⌊√(m·2³⁸)⌋, and
    // `rest` the remainder.
    let mut rest = m << 38;
    let mut r = 0u64;
    let mut bit = 1u64 << 62;
    while bit != 0 {
        if rest >= r + bit {
            rest -= r + bit;
            r = (r >> 1) + bit;
        } else {
            r >>= 1;
        }
        bit >>= 2;
    }
    if rest != 0 {
        r |= 1;
    }
    let p = e / 2 - 19;
    r as f32 * f32::from_bits(((127 + p) as u32) << 23)
}

/// `1/√x` for `2⁻¹²⁵ ≤ x ≤ f32::MAX` (so that `x/2` is a normal number), in plain f32
/// arithmetic under every backend: no square root and no division, about twenty
/// instructions on a Cortex-M4, where `libm`'s `sqrtf` is a bit-by-bit software loop.
///
/// The estimate from the exponent bits (`0x5F37_5A86 − bits/2`, within 3.5 % of `1/√x`) is
/// refined by three Newton steps `y ← y + y·(1/2 − (x/2·y)·y)`, each of which squares the
/// relative error (to 1.8·10⁻³, 5·10⁻⁶, then below f32 rounding): the result is within
/// 1.2 ulp of `1/√x` over the whole domain (`tests/points/math.rs`). `(x/2·y)·y` keeps every
/// intermediate in the normal range. Outside the domain the result is meaningless; callers
/// check `x` first.
///
/// # Examples
/// ```
/// use sphere_quadrature::math::inv_sqrt;
///
/// for x in [1e-30f32, 0.5, 2.0, 9.0, 1e30] {
///     let y = inv_sqrt(x);
///     assert!((y * y * x - 1.0).abs() < 1e-6);
/// }
/// ```
#[inline]
#[must_use]
pub fn inv_sqrt(x: f32) -> f32 {
    let h = 0.5 * x;
    let mut y = f32::from_bits(0x5F37_5A86u32.wrapping_sub(x.to_bits() >> 1));
    y *= 1.5 - h * y * y;
    y *= 1.5 - h * y * y;
    // The last step as a correction to y, whose own rounding is then far below an ulp.
    y + y * (0.5 - h * y * y)
}

/// Sine of an angle in radians.
#[inline]
#[must_use]
pub fn sin(x: f32) -> f32 {
    backend::sin(x)
}

/// Cosine of an angle in radians.
#[inline]
#[must_use]
pub fn cos(x: f32) -> f32 {
    backend::cos(x)
}

/// Four-quadrant arctangent of `y / x`, in `[−π, π]`.
#[inline]
#[must_use]
pub fn atan2(y: f32, x: f32) -> f32 {
    backend::atan2(y, x)
}

/// Four-quadrant arctangent from `libm` under every backend (its `atan2f` is f32
/// arithmetic, accurate to about 1 ulp): for code whose correctness, not only its accuracy,
/// depends on the angle, such as the inverse spherical Fibonacci mapping.
///
/// # Examples
/// ```
/// use sphere_quadrature::math::atan2_accurate;
///
/// assert!((atan2_accurate(1.0, 1.0) - core::f32::consts::FRAC_PI_4).abs() < 1e-6);
/// assert!((atan2_accurate(1.0, -1.0) - 3.0 * core::f32::consts::FRAC_PI_4).abs() < 1e-6);
/// ```
#[inline]
#[must_use]
pub fn atan2_accurate(y: f32, x: f32) -> f32 {
    libm::atan2f(y, x)
}

/// `eˣ` from `libm` under every backend: for code whose result must follow its input
/// smoothly, such as a root search (`micromath`'s approximation is piecewise, and a root
/// found through it jumps with the rounding of the data).
///
/// # Examples
/// ```
/// use sphere_quadrature::math::exp_accurate;
///
/// assert!((exp_accurate(1.0) - core::f32::consts::E).abs() < 1e-6);
/// ```
#[inline]
#[must_use]
pub fn exp_accurate(x: f32) -> f32 {
    libm::expf(x)
}

/// Arccosine in `[0, π]`; the argument is clamped to `[−1, 1]` first (NaN stays NaN), so
/// rounding just outside the domain does not produce NaN.
///
/// # Examples
/// ```
/// use sphere_quadrature::math::acos;
///
/// assert_eq!(acos(1.0), 0.0);
/// // Rounding just past 1 is clamped instead of giving NaN.
/// assert_eq!(acos(1.000_000_1), 0.0);
/// assert!((acos(-1.0) - core::f32::consts::PI).abs() < 1e-6);
/// ```
#[inline]
#[must_use]
pub fn acos(x: f32) -> f32 {
    libm::acosf(clamp_unit(x))
}

/// eˣ.
#[inline]
#[must_use]
pub fn exp(x: f32) -> f32 {
    backend::exp(x)
}

/// eˣ − 1, accurate near 0 (always `libm`).
///
/// # Examples
/// ```
/// use sphere_quadrature::math::{exp, expm1};
///
/// // Near 0, eˣ − 1 keeps the digits that exp(x) − 1 loses.
/// let x = 1e-6f32;
/// assert!((expm1(x) - x).abs() < 1e-12);
/// assert!((expm1(1.0) - (exp(1.0) - 1.0)).abs() < 1e-2);
/// ```
#[inline]
#[must_use]
pub fn expm1(x: f32) -> f32 {
    libm::expm1f(x)
}

/// Natural logarithm.
#[inline]
#[must_use]
pub fn ln(x: f32) -> f32 {
    libm::logf(x)
}

/// ln(1 + x), accurate near 0 (always `libm`).
///
/// # Examples
/// ```
/// use sphere_quadrature::math::ln_1p;
///
/// let x = 1e-7f32;
/// assert!((ln_1p(x) - x).abs() < 1e-13);
/// assert!((ln_1p(core::f32::consts::E - 1.0) - 1.0).abs() < 1e-6);
/// ```
#[inline]
#[must_use]
pub fn ln_1p(x: f32) -> f32 {
    libm::log1pf(x)
}

/// xʸ.
#[inline]
#[must_use]
pub fn powf(x: f32, y: f32) -> f32 {
    libm::powf(x, y)
}

/// Largest integer not greater than `x` (exact; always `libm`).
#[inline]
#[must_use]
pub fn floor(x: f32) -> f32 {
    libm::floorf(x)
}

/// `|x|` (exact).
#[inline]
#[must_use]
pub fn abs(x: f32) -> f32 {
    libm::fabsf(x)
}

/// `|x|` with the sign of `s` (exact).
#[inline]
#[must_use]
pub fn copysign(x: f32, s: f32) -> f32 {
    libm::copysignf(x, s)
}

/// f64 square root (always `libm`).
#[inline]
#[must_use]
pub fn sqrt64(x: f64) -> f64 {
    libm::sqrt(x)
}

/// f64 natural logarithm (always `libm`).
#[inline]
#[must_use]
pub fn ln64(x: f64) -> f64 {
    libm::log(x)
}

/// f64 exponential eˣ (always `libm`).
#[inline]
#[must_use]
pub fn exp64(x: f64) -> f64 {
    libm::exp(x)
}

/// f64 largest integer not greater than `x` (always `libm`).
#[inline]
#[must_use]
pub fn floor64(x: f64) -> f64 {
    libm::floor(x)
}

/// f64 four-quadrant arctangent (always `libm`).
#[inline]
#[must_use]
pub fn atan2_64(y: f64, x: f64) -> f64 {
    libm::atan2(y, x)
}

/// f64 `xʸ` (always `libm`).
#[inline]
#[must_use]
pub fn pow64(x: f64, y: f64) -> f64 {
    libm::pow(x, y)
}

/// f64 sine of an angle in radians (always `libm`).
#[inline]
#[must_use]
pub fn sin64(x: f64) -> f64 {
    libm::sin(x)
}

/// f64 cosine of an angle in radians (always `libm`).
#[inline]
#[must_use]
pub fn cos64(x: f64) -> f64 {
    libm::cos(x)
}

/// f64 gamma function Γ(x) (always `libm`).
///
/// # Examples
/// ```
/// use sphere_quadrature::math::gamma64;
///
/// // Γ(n) = (n − 1)!, Γ(1/2) = √π.
/// assert!((gamma64(5.0) - 24.0).abs() < 1e-10);
/// assert!((gamma64(0.5) - core::f64::consts::PI.sqrt()).abs() < 1e-12);
/// ```
#[inline]
#[must_use]
pub fn gamma64(x: f64) -> f64 {
    libm::tgamma(x)
}

/// f64 `|x|` (exact; always `libm`).
#[inline]
#[must_use]
pub fn abs64(x: f64) -> f64 {
    libm::fabs(x)
}

/// f64 nearest integer, halfway cases away from zero (always `libm`).
#[inline]
#[must_use]
pub fn round64(x: f64) -> f64 {
    libm::round(x)
}

/// `(sin θ, cos θ)` of `θ = 2π·phase/2⁶⁴`: an angle given as an exact 64-bit fraction of a
/// turn, as the spherical Fibonacci phase is.
///
/// The range reduction is exact integer arithmetic (the nearest quarter turn is the top bits
/// of `phase`), leaving `|a| ≤ π/4` for Taylor polynomials to degree 9 (sine) and 10
/// (cosine) in f32, whose truncation errors are below 2·10⁻⁹. No f64 is involved, so this
/// costs a few dozen instructions on an FPU-only-f32 core where `libm`'s `sinf`/`cosf` (which
/// evaluate in f64) cost thousands. The same code runs under both backends: measured
/// against f64 over 10⁶ phases, both outputs are within 1.2·10⁻⁷ absolute.
///
/// # Examples
/// ```
/// use sphere_quadrature::math::sin_cos_turns;
///
/// assert_eq!(sin_cos_turns(0), (0.0, 1.0));
/// let (s, c) = sin_cos_turns(1 << 62); // a quarter turn
/// assert!((s - 1.0).abs() < 1e-7 && c.abs() < 1e-7);
/// let (s, c) = sin_cos_turns(0x1234_5678_9ABC_DEF0);
/// assert!((s * s + c * c - 1.0).abs() < 1e-6);
/// ```
#[inline]
#[must_use]
pub const fn sin_cos_turns(phase: u64) -> (f32, f32) {
    const QUARTER: u64 = 1 << 62;
    // Nearest quarter turn k and the signed remainder d in [−2⁶¹, 2⁶¹).
    let k = (phase.wrapping_add(QUARTER / 2) >> 62) & 3;
    let d = phase.wrapping_sub(k << 62) as i64;
    // a = 2π·d/2⁶⁴ ∈ [−π/4, π/4); the top 32 bits of d carry the f32 precision needed.
    let a = (d >> 32) as i32 as f32 * (core::f32::consts::TAU / 4_294_967_296.0);
    let a2 = a * a;
    let s = a
        * (1.0
            + a2 * (-1.0 / 6.0
                + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0 + a2 * (1.0 / 362_880.0)))));
    let c = 1.0
        + a2 * (-0.5
            + a2 * (1.0 / 24.0
                + a2 * (-1.0 / 720.0 + a2 * (1.0 / 40_320.0 + a2 * (-1.0 / 3_628_800.0)))));
    // sin(a + kπ/2), cos(a + kπ/2).
    match k {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// Clamps to `[−1, 1]`, keeping NaN.
#[inline]
#[must_use]
pub(crate) const fn clamp_unit(x: f32) -> f32 {
    // `f32::clamp`'s order (not const before Rust 1.85).
    let mut x = x;
    if x < -1.0 {
        x = -1.0;
    }
    if x > 1.0 {
        x = 1.0;
    }
    x
}

/// `2^e`, exact for `e ∈ [−149, 127]` (subnormal below −126); `e` is clamped to that range.
#[must_use]
pub(crate) fn pow2(e: i32) -> f32 {
    let e = e.clamp(-149, 127);
    if e >= -126 {
        f32::from_bits(((e + 127) as u32) << 23)
    } else {
        f32::from_bits(1u32 << (e + 149))
    }
}

/// `⌊log₂ x⌋` for a positive normal `x` (the exponent field); −127 for zero and subnormals,
/// 128 for infinities and NaN.
#[must_use]
pub(crate) fn exponent(x: f32) -> i32 {
    ((x.to_bits() >> 23) & 0xff) as i32 - 127
}

/// `⌊log₂ |x|⌋` for any finite non-zero `x`, subnormals included (0 for zero); from the bits,
/// no `libm` call (the cold paths that use it stay small in flash).
#[must_use]
pub(crate) fn binade(x: f32) -> i32 {
    let bits = x.to_bits() & 0x7FFF_FFFF;
    if bits == 0 {
        return 0;
    }
    let biased = (bits >> 23) as i32;
    if biased == 0 {
        // Subnormal: m·2^−149 with m < 2^23.
        (31 - bits.leading_zeros() as i32) - 149
    } else {
        biased - 127
    }
}

/// `x·2^e` for any `e`, by at most three exact multiplications by powers of two (no `libm`
/// call): `±∞` beyond `f32::MAX`; rounded once where the result is a normal number, and
/// subnormal or 0 below the normal range.
#[must_use]
pub(crate) fn ldexp(x: f32, e: i32) -> f32 {
    if (-126..=127).contains(&e) {
        return x * pow2(e);
    }
    // Three factors of the same direction: the intermediates lie between x and the result,
    // so they stay normal when both ends are (and then every step but the last is exact).
    // Beyond ±3·126 every finite x has overflowed or underflowed: the thirds stay in range.
    let k = e.clamp(-378, 381);
    let a = k / 3;
    let b = (k - a) / 2;
    x * pow2(a) * pow2(b) * pow2(k - a - b)
}

/// A variance `v ≥ 0` times `2^e`, rounded up where it is positive but below the least
/// positive f32: an error bar is never rounded to 0 unless it is 0.
#[must_use]
pub(crate) fn ldexp_variance(v: f32, e: i32) -> f32 {
    let scaled = ldexp(v, e);
    if scaled == 0.0 && v > 0.0 {
        f32::from_bits(1)
    } else {
        scaled
    }
}

#[cfg(test)]
mod tests {
    /// Newton's square root is within one ulp of the correctly rounded one, subnormals included,
    /// and 0 outside the positive finite numbers.
    #[test]
    fn newton_square_root_is_within_an_ulp() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut worst = 0u32;
        for k in 0..1_000_000u32 {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let bits =
                if k % 10 == 0 { (state >> 41) as u32 } else { (state >> 33) as u32 % 0x7f80_0000 };
            let x = f32::from_bits(bits.max(1));
            let want = (f64::from(x)).sqrt() as f32;
            let got = super::sqrt_newton(x);
            worst = worst.max(got.to_bits().abs_diff(want.to_bits()));
        }
        assert!(worst <= 1, "{worst} ulp");
        for x in [0.0, -0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert_eq!(super::sqrt_newton(x), 0.0, "{x}");
        }
    }
}
