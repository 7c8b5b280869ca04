//! The spherical-harmonic view of a point set: spectrum by the addition theorem, real
//! spherical harmonics, the spectral worst-case error and spherical designs.

use core::f64::consts::PI;

use super::{for_each_pair, unit64, validate};
use crate::error::Error;
use crate::legendre::Polynomials64;
use crate::math;
use crate::vec3::Vec3;

/// The spectrum `C_l = (1/(2l+1)) Σₘ |c_{l,m}|² = (1/(4πN²)) ΣⱼΣₖ P_l(ωⱼ·ωₖ)` for
/// `l = 0 … out.len() − 1`, written to `out` (seed, "Visualization of spectrum of spherical
/// point sets"; Lessig et al. 2010 average over m).
///
/// Uses the addition theorem `Σₘ Y_{l,m}(x) Y_{l,m}(y) = (2l+1)/(4π) P_l(x·y)` and the
/// Legendre recurrence `(l+1) P_{l+1} = (2l+1) t P_l − l P_{l−1}`, so no spherical harmonics
/// are evaluated. `C_0 = 1/(4π)` always; uniform random points have `E[C_l] = 1/(4πN)`;
/// a spherical `t`-design has `C_l = 0` for `1 ≤ l ≤ t`. Agrees with the explicit projection
/// onto spherical harmonics to 10⁻¹⁵ absolute (`tests/points/metrics.rs`); a value that rounding
/// takes below zero is returned as 0 (`C_l ≥ 0` always). O(N²·L) in f64.
///
/// # Errors
/// [`Error::LengthMismatch`] when `points` or `out` is empty; [`Error::InvalidDirection`] for a
/// zero or non-finite direction.
pub fn spectrum(points: &[Vec3], out: &mut [f64]) -> Result<(), Error> {
    if out.is_empty() {
        return Err(Error::LengthMismatch);
    }
    validate(points)?;
    out.fill(0.0);
    for_each_pair(points, |d2| {
        // x·y = 1 − |x − y|²/2, accurate for close pairs.
        let mut p = Polynomials64::at(1.0 - 0.5 * d2);
        for c in out.iter_mut() {
            *c += 2.0 * p.next_value();
        }
    });
    // The diagonal: N terms P_l(1) = 1.
    let n = points.len() as f64;
    let scale = 1.0 / (4.0 * PI * n * n);
    // C_l is a sum of squares: clamp the rounding of a near-zero value (an exact design's
    // C_l ≈ ±10⁻¹⁸) to 0, so the spectrum is always a valid `wce_from_spectrum` input.
    for c in out.iter_mut() {
        *c = ((*c + n) * scale).max(0.0);
    }
    Ok(())
}

/// Index of `Y_{l,m}` in the arrays of [`real_sh`] and [`sh_coefficients`]: `l(l+1) + m`, or
/// `None` when `|m| > l` or the index does not fit in `usize` (`l ≥ 2³²` on a 64-bit
/// target, `l ≥ 2¹⁶` on a 32-bit one).
#[must_use]
pub const fn sh_index(l: usize, m: isize) -> Option<usize> {
    if m.unsigned_abs() > l {
        return None;
    }
    // l(l + 1) − l ≥ 0, so only the product and a positive m can overflow.
    let Some(l1) = l.checked_add(1) else {
        return None;
    };
    let Some(block) = l.checked_mul(l1) else {
        return None;
    };
    block.checked_add_signed(m)
}

/// Number of real spherical harmonics of degree `≤ l_max`: `(l_max + 1)²` (saturating).
const fn sh_count(l_max: usize) -> usize {
    let k = l_max.saturating_add(1);
    k.saturating_mul(k)
}

/// All real spherical harmonics `Y_{l,m}(dir)`, `l ≤ l_max`, into `out[l(l+1) + m]`
/// (see [`sh_index`]). Orthonormal over dΩ, real form without the Condon–Shortley phase:
/// `Y_{l,m} ∝ P_l^m(cos θ) cos mφ` for `m > 0` and `∝ P_l^{|m|}(cos θ) sin |m|φ` for `m < 0`
/// (so `Y_{1,1} = (3/(4π))^½ x`, `Y_{1,−1} = (3/(4π))^½ y`, `Y_{1,0} = (3/(4π))^½ z`).
/// `dir` need not be unit. O(l_max²); stable to high degree (matched against an independent
/// f64 reference to 10⁻¹³ for `l ≤ 80`, poles included).
///
/// # Errors
/// [`Error::LengthMismatch`] when `out.len() < (l_max + 1)²`; [`Error::InvalidDirection`] for
/// a zero or non-finite `dir`.
pub fn real_sh(dir: Vec3, l_max: usize, out: &mut [f64]) -> Result<(), Error> {
    if out.len() < sh_count(l_max) {
        return Err(Error::LengthMismatch);
    }
    let u = unit64(dir).ok_or(Error::InvalidDirection)?;
    // Every index is below `(l_max + 1)² ≤ out.len()`; `get_mut` (always `Some`) spares a
    // bounds-check panic path the optimiser cannot remove.
    crate::harmonics::for_each(&crate::harmonics::Computed, u, l_max, |i, v| {
        if let Some(slot) = out.get_mut(i) {
            *slot = v;
        }
    });
    Ok(())
}

/// The Fourier coefficients of the sampling pattern, `c_{l,m} = (1/N) Σₖ Y_{l,m}(ωₖ)` (seed,
/// "Spherical designs"), for `l ≤ l_max`, into `out[l(l+1) + m]` with [`real_sh`]'s
/// harmonics. `Σₘ c_{l,m}² = (2l+1) C_l` ([`spectrum`]). O(N·l_max²): meant for small
/// degrees; use [`spectrum`] for the m-averaged power at high degree.
///
/// # Errors
/// [`Error::LengthMismatch`] when `points` is empty or `out.len() < (l_max + 1)²`;
/// [`Error::InvalidDirection`] for a zero or non-finite direction.
pub fn sh_coefficients(points: &[Vec3], l_max: usize, out: &mut [f64]) -> Result<(), Error> {
    let count = sh_count(l_max);
    if out.len() < count {
        return Err(Error::LengthMismatch);
    }
    validate(points)?;
    let out = &mut out[..count];
    out.fill(0.0);
    for &p in points {
        if let Some(u) = unit64(p) {
            // As in `real_sh`: `i < count`, so `get_mut` is always `Some`.
            crate::harmonics::for_each(&crate::harmonics::Computed, u, l_max, |i, v| {
                if let Some(slot) = out.get_mut(i) {
                    *slot += v;
                }
            });
        }
    }
    let inv = 1.0 / points.len() as f64;
    for c in out.iter_mut() {
        *c *= inv;
    }
    Ok(())
}

/// Which frequency weights `a_l` the spectral worst-case error uses,
/// `wce² = Σ_{l≥1} a_l Σₘ |c_{l,m}|²` (seed, "Worst case error over Hˢ(S²)"), with `c_{l,m}`
/// over dΩ-orthonormal harmonics as everywhere in [`crate::metrics`].
///
/// # Examples
/// ```
/// use sphere_quadrature::metrics::{sobolev_weight, SobolevWeights};
///
/// // The two weightings agree as l → ∞ and differ at low degrees.
/// let ratio = |l| {
///     sobolev_weight(l, 1.5, SobolevWeights::Asymptotic).unwrap()
///         / sobolev_weight(l, 1.5, SobolevWeights::Exact).unwrap()
/// };
/// assert!(ratio(1) < 0.5);
/// assert!((ratio(100_000) - 1.0).abs() < 1e-3);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SobolevWeights {
    /// `a_l = 4π·2^(2s−2)·(s−1)·Γ(s)·Γ(l+1−s) / (Γ(2−s)·Γ(l+1+s))`: minus the Funk–Hecke
    /// eigenvalue of the distance kernel `|x − y|^(2s−2)` on (S², dΩ), i.e.
    /// `a_l = −2π ∫₋₁¹ (2 − 2t)^(s−1) P_l(t) dt`. With these weights the spectral form
    /// equals the distance formula of [`super::wce`] exactly (derived by Rodrigues' formula
    /// and integration by parts; checked against numerical quadrature of the integral and
    /// against the distance formula in `tests/points/metrics.rs`). Computed by the recurrence
    /// `a_1 = 4π·2^(2s−2)(s−1)/(s(s+1))`, `a_{l+1} = a_l·(l+1−s)/(l+1+s)`.
    Exact,
    /// The seed's `a_l = k_s·(1+l)^(−2s)` (BSSW's asymptotic order), with
    /// `k_s = 4π·2^(2s−2)·(s−1)·Γ(s)/Γ(2−s)` chosen so that `a_l / a_l^Exact → 1` as
    /// `l → ∞`. It defines an equivalent norm on the same space `Hˢ`, so the same sets are
    /// good, but it is not the distance formula: at `s = 3/2` it is 4.3× smaller at `l = 1`,
    /// 7 % smaller at `l = 20` and within 2·10⁻⁵ at `l = 10⁵`; the resulting wce is 39 %
    /// below the distance formula for 64 random points and 4 % below it for 64 SF points.
    Asymptotic,
}

/// `a_l` of [`SobolevWeights`] for `1 < s < 2`; `a_0 = 0` (the `l = 0` term carries no
/// error: equal weights integrate constants exactly). `Exact` costs O(l).
///
/// # Errors
/// [`Error::InvalidSmoothness`] unless `1 < s < 2`.
pub fn sobolev_weight(l: usize, s: f64, weights: SobolevWeights) -> Result<f64, Error> {
    let mut w = Weights::new(s, weights)?;
    let mut a = 0.0;
    for _ in 0..l {
        a = w.next();
    }
    Ok(a)
}

/// Iterator state over `a_1, a_2, …`.
struct Weights {
    s: f64,
    kind: SobolevWeights,
    l: f64,
    a: f64,
    k_s: f64,
}

impl Weights {
    fn new(s: f64, kind: SobolevWeights) -> Result<Self, Error> {
        if !(s > 1.0 && s < 2.0) {
            return Err(Error::InvalidSmoothness);
        }
        let c = 4.0 * PI * math::pow64(2.0, 2.0 * s - 2.0) * (s - 1.0);
        let k_s = c * math::gamma64(s) / math::gamma64(2.0 - s);
        Ok(Self { s, kind, l: 0.0, a: c / (s * (s + 1.0)), k_s })
    }

    /// The next weight `a_l`, `l = 1, 2, …`.
    #[inline]
    fn next(&mut self) -> f64 {
        self.l += 1.0;
        match self.kind {
            SobolevWeights::Exact => {
                let a = self.a;
                self.a *= (self.l + 1.0 - self.s) / (self.l + 1.0 + self.s);
                a
            }
            SobolevWeights::Asymptotic => self.k_s * math::pow64(1.0 + self.l, -2.0 * self.s),
        }
    }
}

/// The spectral worst-case error `(Σ_{l=1}^{L} a_l (2l+1) C_l)^½` from a spectrum
/// `C_0 … C_L` ([`spectrum`]).
///
/// The sum is truncated at `L = spectrum.len() − 1`; every omitted term is non-negative, so
/// with [`SobolevWeights::Exact`] this is a lower bound that increases to [`super::wce`] as
/// `L` grows. For `L` well above the set's "sampling frequency" (≈ 2√N) the omitted tail is
/// close to `(1/N) Σ_{l>L} (2l+1) a_l/(4π)`, which falls like `L^(2−2s)`.
///
/// A spectrum is a sum of squares: every `C_l` is finite and non-negative ([`spectrum`]
/// returns such values), and anything else is refused rather than summed into a meaningless
/// (possibly perfect, 0) score.
///
/// # Errors
/// [`Error::InvalidSmoothness`] unless `1 < s < 2`; [`Error::InvalidSpectrum`] when an entry
/// is NaN, infinite or negative.
pub fn wce_from_spectrum(spectrum: &[f64], s: f64, weights: SobolevWeights) -> Result<f64, Error> {
    let mut w = Weights::new(s, weights)?;
    if !spectrum.iter().all(|&c| c.is_finite() && c >= 0.0) {
        return Err(Error::InvalidSpectrum);
    }
    let mut sum = 0.0;
    for (l, &c) in spectrum.iter().enumerate().skip(1) {
        sum += w.next() * (2 * l + 1) as f64 * c;
    }
    Ok(math::sqrt64(sum.max(0.0)))
}

/// [`spectrum`] of `points` into `spectrum`, then [`wce_from_spectrum`]. O(N²·L).
///
/// # Errors
/// [`Error::InvalidSmoothness`] unless `1 < s < 2`; otherwise as [`spectrum`].
pub fn wce_spectral(
    points: &[Vec3],
    s: f64,
    weights: SobolevWeights,
    spectrum_out: &mut [f64],
) -> Result<f64, Error> {
    Weights::new(s, weights)?;
    spectrum(points, spectrum_out)?;
    wce_from_spectrum(spectrum_out, s, weights)
}

/// The design strength: the largest `L ≤ spectrum_out.len() − 1` with `C_l ≤ tol` for every
/// `0 < l ≤ L` (0 when already `C_1 > tol`). The spectrum is left in `spectrum_out`.
///
/// A set is a spherical `L`-design (it integrates every polynomial of degree `≤ L` exactly
/// with equal weights) exactly when `C_l = 0` for `1 ≤ l ≤ L` (seed, "Spherical designs";
/// Delsarte, Goethals and Seidel 1977). With f32 coordinates an exact design shows
/// `C_l ≲ 10⁻¹⁵`, so `tol = 10⁻¹²` separates designs from near-designs; compare `tol` with
/// `C_0 = 1/(4π)` and with the random level `1/(4πN)`. A result equal to
/// `spectrum_out.len() − 1` is only a lower bound.
///
/// # Errors
/// [`Error::InvalidTolerance`] for a negative or NaN `tol`; otherwise as [`spectrum`].
pub fn design_strength(
    points: &[Vec3],
    tol: f64,
    spectrum_out: &mut [f64],
) -> Result<usize, Error> {
    if tol.is_nan() || tol < 0.0 {
        return Err(Error::InvalidTolerance);
    }
    spectrum(points, spectrum_out)?;
    let first_bad = spectrum_out.iter().skip(1).position(|&c| c.is_nan() || c > tol);
    Ok(match first_bad {
        Some(i) => i,
        None => spectrum_out.len() - 1,
    })
}

/// The fewest points a spherical `l`-design on S² can have (Delsarte, Goethals and Seidel
/// 1977): `(l+1)(l+3)/4` for odd `l`, `(l+2)²/4` for even `l` (saturating at `usize::MAX`).
///
/// The seed quotes it as "exact integration is possible if K ≥ …"; it is a necessary
/// condition (no design with fewer points exists), not a sufficient one. It is attained
/// only by the tight designs: 2 antipodal points (`l = 1`), the tetrahedron (`l = 2`), the
/// octahedron (`l = 3`) and the icosahedron (`l = 5`).
#[must_use]
pub const fn min_points_for_design(l: usize) -> usize {
    let a = l.saturating_add(1);
    let b = l.saturating_add(3);
    let c = l.saturating_add(2);
    if l % 2 == 1 {
        a.saturating_mul(b) / 4
    } else {
        c.saturating_mul(c) / 4
    }
}
