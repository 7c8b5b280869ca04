//! The probe's Legendre series: the coefficients of its kernel, footprints and lobes (the
//! recurrences and gains they are built from are [`crate::legendre`]'s).

use super::*;
use crate::legendre::{apply_cosine_power_gains, bessel_ratios};

/// The most Legendre terms a baked series may have (`gen/probe.rs` refuses longer ones).
pub(super) const MAX_SERIES: usize = 256;

/// `cₗ = S_l(λ)·(2l + 1)/(4π)`, the Legendre coefficients of the unit spherical Gaussian of
/// sharpness `λ` (`S_l = F(λ)·ρ_l(λ)`), in f32, into `out`; returns the number of terms kept:
/// `16 + ⌊9.1√λ⌋` (capped at [`MAX_SERIES`]), past which `S_l/S₀ < e^{−41}`.
pub(super) fn sg_series_f32(lambda: f32, out: &mut [f32; MAX_SERIES]) -> usize {
    let len = (16 + (9.1 * crate::math::sqrt(lambda)) as usize).min(MAX_SERIES);
    let Some(out) = out.get_mut(..len) else { return 0 };
    bessel_ratios(lambda, out);
    let full = full_integral_unchecked(lambda);
    for (l, b) in out.iter_mut().enumerate() {
        *b *= full * (2 * l + 1) as f32 / (4.0 * PI);
    }
    len
}

/// [`cosine_series`] in f32 (the glossy hot path).
pub(super) fn cosine_series_f32(lambda: f32, exponent: u32, out: &mut [f32; MAX_SERIES]) -> usize {
    let len = sg_series_f32(lambda, out);
    if let Some(out) = out.get_mut(..len) {
        apply_cosine_power_gains(exponent as f32, out);
    }
    len
}

/// `bₗ = K_l·g_l·(2l + 1)/(4π)` of a cosine-power footprint `max(0, t)ᵖ` under the
/// squared-exponential kernel of sharpness `λ` (`K_l = F(λ)·ρₗ(λ)`, `g_l` the footprint's
/// gains), into `out`; returns the number of terms kept: `16 + ⌊9.1√λ⌋` (capped at
/// [`MAX_SERIES`]), past which `K_l/K₀ < e^{−41}`.
pub(super) fn cosine_series(lambda: f64, exponent: u32, out: &mut [f64; MAX_SERIES]) -> usize {
    let len = (16 + (9.1 * crate::math::sqrt64(lambda)) as usize).min(MAX_SERIES);
    let Some(out) = out.get_mut(..len) else { return 0 };
    bessel_ratios(lambda, out);
    let full = glossy_full_integral(lambda);
    for (l, b) in out.iter_mut().enumerate() {
        *b *= full * (2 * l + 1) as f64 / (4.0 * core::f64::consts::PI);
    }
    apply_cosine_power_gains(f64::from(exponent), out);
    len
}

/// `K_l·(2l + 1)/(4π)`, the kernel's Legendre coefficients, in f64, into `out`; returns the
/// number of terms. Point and cosine-power footprints: the squared exponential,
/// `K_l = F(λ)·ρₗ(λ)`, `16 + ⌊9.1√λ⌋` terms. Gaussian footprint of sharpness `S`: the
/// deconvolved kernel `K_l = F(ν)·ρₗ(ν)/ρₗ(S)` (`λ = ν`), which falls like `(ν/S)^l`:
/// [`MAX_SERIES`] terms (`gen/probe.rs` refuses members whose series has not converged by
/// then).
pub(super) fn kernel_coefficients(kind: Kind, lambda: f64, out: &mut [f64; MAX_SERIES]) -> usize {
    let pi4 = 4.0 * core::f64::consts::PI;
    let full = glossy_full_integral(lambda);
    if let Kind::Gaussian { sharpness } = kind {
        let mut rs = [0.0f64; MAX_SERIES];
        bessel_ratios(lambda, out);
        bessel_ratios(f64::from(sharpness), &mut rs);
        for (l, (a, &b)) in out.iter_mut().zip(&rs).enumerate() {
            *a = if b > 0.0 { full * *a / b * (2 * l + 1) as f64 / pi4 } else { 0.0 };
        }
        return MAX_SERIES;
    }
    let len = (16 + (9.1 * crate::math::sqrt64(lambda)) as usize).min(MAX_SERIES);
    let Some(out) = out.get_mut(..len) else { return 0 };
    bessel_ratios(lambda, out);
    for (l, a) in out.iter_mut().enumerate() {
        *a *= full * (2 * l + 1) as f64 / pi4;
    }
    len
}

/// `V̄/F(μ)² = Σ_l K_l·(2l + 1)/(4π)·ρₗ(μ)²` for the Gaussian footprint's deconvolved kernel.
pub(super) fn deconvolved_vbar(nu: f64, sharpness: u32, mu: f64) -> f64 {
    let mut k = [0.0f64; MAX_SERIES];
    let len = kernel_coefficients(Kind::Gaussian { sharpness }, nu, &mut k);
    let mut rho = [0.0f64; MAX_SERIES];
    bessel_ratios(mu, &mut rho);
    k.iter().zip(&rho).take(len).map(|(&k, &p)| k * p * p).sum()
}
