//! The probe's posterior mean as spherical harmonics of degree `l ≤ 2`:
//! the exact projection and the posterior variance of every coefficient.
//!
//! The posterior mean radiance is `L̄(x) = β + Σᵢ αᵢ·k(xᵢ, x)`, where `k(xᵢ, x)` is the
//! covariance of sample `i` with the radiance at `x`: the kernel for point samples, the kernel
//! times the footprint for footprint samples. It depends on `xᵢ·x` only, so by Funk–Hecke its
//! projection on `Y_lm` is `k̂_l·Y_lm(xᵢ)` with `k̂_l = 2π∫k(t)·P_l(t) dt`, and
//! `c_lm = β·√(4π)·δ_l0 + k̂_l·Σᵢ αᵢ·Y_lm(xᵢ)`. With the Legendre coefficients `K_l` of the
//! kernel and the gains `g_l` of the footprint (module docs, "Footprints"), `k̂_l = K_l·g_l`:
//! `F(λ)·ρ_l(λ)` for point samples (`ρ_l = i_l/i₀`, `F(λ) = 2π(1 − e^(−2λ))/λ`), the same with
//! `λ = ν` for a Gaussian footprint (whose sample–radiance covariance is the spherical
//! Gaussian of sharpness `ν`), and `F(λ)·ρ_l(λ)·g_l` for a cosine-power footprint. The
//! expansion is of the *unfiltered* radiance in every case.

use super::{glossy_full_integral, Probe, ProbeTables};
use crate::footprint::{Footprint, Kind};
use crate::harmonics;
use crate::legendre::{apply_cosine_power_gains, bessel_ratios};
use crate::radiance::Radiance;
use crate::sg::full_integral_unchecked;
use crate::sh::ShL2;
use crate::size::Size;

/// `√(4π)`: `∫ Y₀₀ = √(4π)`, and a constant `β` has `c₀₀ = β·√(4π)`.
const SQRT_4PI: f32 = SQRT_4PI64 as f32;
/// [`SQRT_4PI`] in f64.
const SQRT_4PI64: f64 = 3.544_907_701_811_032;

impl<const N: usize, T: Radiance, F: Footprint, const M: usize> Probe<N, T, F, M>
where
    Size<N>: ProbeTables<F>,
{
    /// The spherical-harmonic coefficients of degree `l ≤ 2` of the posterior mean radiance,
    /// exactly (no quadrature): `c_lm = β·√(4π)·δ_l0 + k̂_l·Σᵢ αᵢ·Y_lm(xᵢ)`, with `k̂_l` the
    /// Funk–Hecke coefficient of the covariance of a sample with the radiance (module
    /// `probe`, "Footprints"; for a footprint probe the expansion is of the unfiltered
    /// radiance). O(9N) multiply-adds per channel, in f32, the radiance scale applied last
    /// as [`Probe::irradiance`] applies it (`±∞` only for a coefficient beyond `f32::MAX`;
    /// `c₀₀ = √(4π)·β` can exceed it where the radiance does not). Zero before the first
    /// update.
    ///
    /// [`ShL2::irradiance`] of the result differs from [`Probe::irradiance`] only by the
    /// degrees above 2 of the clamped cosine (`Â₄ = −π/24`, `Â₆ = π/64`, …) applied to the
    /// posterior mean, which an SH L2 consumer cannot represent (module [`crate::sh`]).
    ///
    /// ```
    /// use sphere_quadrature::{probe::Probe, Vec3};
    ///
    /// let mut probe = Probe::<64>::new();
    /// probe.update(&probe.directions().map(|d| 1.0 + 0.5 * d.z))?;
    /// let sh = probe.radiance_sh();
    /// // Exactly representable: c₀₀ = √(4π), c₁₀ = 0.5·√(4π/3); the model smooths a little.
    /// assert!((sh.coefficients[0] - 3.5449).abs() < 2e-3);
    /// assert!((sh.coefficients[2] - 1.0233).abs() < 1e-2);
    /// let (a, b) = (sh.irradiance(Vec3::Z)?, probe.irradiance(Vec3::Z)?.value);
    /// assert!((a - b).abs() < 1e-3 * b);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub fn radiance_sh(&self) -> ShL2<T> {
        let Ok(f) = self.member_in_use() else { return ShL2::ZERO };
        let gains = cross_gains(F::KIND, f.lambda);
        let mut sums = [T::ZERO; 9];
        for (x, &a) in self.directions.iter().zip(&self.alpha) {
            let p = harmonics::polynomials(*x);
            for (s, &pk) in sums.iter_mut().zip(&p) {
                *s = s.mul_add(a, pk);
            }
        }
        let mut c = [T::ZERO; 9];
        for (k, ((ck, &sum), (&constant, &l))) in c
            .iter_mut()
            .zip(&sums)
            .zip(harmonics::CONSTANTS.iter().zip(&harmonics::DEGREE))
            .enumerate()
        {
            let g = gains.get(l).copied().unwrap_or(0.0);
            let normalised = sum.scale(constant * g);
            // Σαᵢ = 0 (the GLS β), so c₀₀ is √(4π)·β up to rounding.
            *ck = if k == 0 {
                self.absolute(SQRT_4PI, normalised)
            } else {
                normalised.mul(self.scale)
            };
        }
        ShL2::new(c)
    }

    /// The posterior variance of each coefficient of [`Probe::radiance_sh`] (index
    /// `l(l + 1) + m`): σ̂_f² times `V_l − ζᵀQ⁻¹ζ + (I_lm − 1ᵀQ⁻¹ζ)²/1ᵀQ⁻¹1` (Rasmussen and
    /// Williams 2006, eq. 2.42) with `ζᵢ = k̂_l·Y_lm(xᵢ)`, the prior variance `V_l = K_l` (the
    /// kernel's Funk–Hecke coefficient on the radiance; `k̂_l` for point samples) and
    /// `I_lm = ∫ Y_lm = √(4π)·δ_l0` (the constant mean's share), O(9·N²/2) in f64 as
    /// [`Probe::irradiance_variance`]; `+∞` where a variance exceeds `f32::MAX`.
    ///
    /// Every variance is multiplied by the member's irradiance calibration factor
    /// (`Member::calibration[0]`, module docs "Calibration"), the factor
    /// [`Probe::irradiance`] and [`Probe::irradiance_variance`] use: the coefficients are
    /// diffuse-scale functionals of the same posterior.
    #[must_use]
    pub fn radiance_sh_variance(&self) -> [T; 9] {
        let Ok(f) = self.member_in_use() else { return [T::ZERO; 9] };
        let lambda = f64::from(f.lambda);
        let mut rho = [0.0f64; 3];
        bessel_ratios(lambda, &mut rho);
        let full = glossy_full_integral(lambda);
        let sg = rho.map(|r| full * r);
        let (cross, prior) = match F::KIND {
            Kind::Gaussian { sharpness } => {
                // K_l = F(ν)ρ_l(ν)/ρ_l(S): the deconvolved kernel.
                let mut rs = [0.0f64; 3];
                bessel_ratios(f64::from(sharpness), &mut rs);
                let mut prior = sg;
                for (p, &r) in prior.iter_mut().zip(&rs) {
                    *p = if r > 0.0 { *p / r } else { 0.0 };
                }
                (sg, prior)
            }
            Kind::CosinePower { exponent } => {
                let mut cross = sg;
                apply_cosine_power_gains(f64::from(exponent), &mut cross);
                (cross, sg)
            }
            Kind::Point => (sg, sg),
        };
        let calibration = f64::from(f.calibration[0]);
        let mut out = [T::ZERO; 9];
        for (k, (slot, (&constant, &l))) in
            out.iter_mut().zip(harmonics::CONSTANTS64.iter().zip(&harmonics::DEGREE)).enumerate()
        {
            let gain = cross.get(l).copied().unwrap_or(0.0) * constant;
            let zeta: [f64; N] = core::array::from_fn(|i| match self.directions.get(i) {
                Some(x) => {
                    let p = harmonics::polynomials64([x.x, x.y, x.z].map(f64::from));
                    gain * p.get(k).copied().unwrap_or(0.0)
                }
                None => 0.0,
            });
            let integral = if k == 0 { SQRT_4PI64 } else { 0.0 };
            let v = self.unit_variance(f, &zeta, integral, prior.get(l).copied().unwrap_or(0.0));
            *slot = self.variance_of_unit(v * calibration, 1.0);
        }
        out
    }
}

/// `k̂_l`, `l = 0, 1, 2`, in f32: `F(λ)·ρ_l(λ)`, times the cosine-power gains for that
/// footprint.
fn cross_gains(kind: Kind, lambda: f32) -> [f32; 3] {
    let mut g = [0.0f32; 3];
    bessel_ratios(lambda, &mut g);
    let full = full_integral_unchecked(lambda);
    for v in &mut g {
        *v *= full;
    }
    if let Kind::CosinePower { exponent } = kind {
        apply_cosine_power_gains(exponent as f32, &mut g);
    }
    g
}
