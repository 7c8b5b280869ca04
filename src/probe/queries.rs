//! Queries: irradiance, glossy and Phong radiance, with their variances.

use super::*;
use crate::legendre::{self, apply_cosine_power_gains, bessel_ratios};

impl<const N: usize, T: Radiance, F: Footprint, const M: usize> Probe<N, T, F, M>
where
    Size<N>: ProbeTables<F>,
{
    /// Irradiance `E(n)` with the direction-averaged posterior variance, O(N); `±∞` where a
    /// result exceeds `f32::MAX` (module docs, "Radiance scale").
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite normal.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{probe::Probe, Vec3};
    ///
    /// let mut probe = Probe::<32>::new();
    /// // Before the first update every query is zero with zero variance.
    /// assert_eq!(probe.irradiance(Vec3::Z)?.value, 0.0);
    /// // Radiance 1 + x: irradiance π ± 2π/3 at ±x, a normal need not be unit.
    /// probe.update(&probe.directions().map(|d| 1.0 + d.x))?;
    /// let (plus, minus) = (probe.irradiance(Vec3::new(2.0, 0.0, 0.0))?, probe.irradiance(-Vec3::X)?);
    /// let pi = core::f32::consts::PI;
    /// assert!((plus.value - (pi + 2.0 * pi / 3.0)).abs() < 0.05);
    /// assert!((minus.value - (pi - 2.0 * pi / 3.0)).abs() < 0.05);
    /// assert!(plus.variance >= 0.0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn irradiance(&self, normal: Vec3) -> Result<Estimate<T>, Error> {
        let n = normal.try_normalize().ok_or(Error::InvalidDirection)?;
        let f = self.member_in_use()?;
        // Two passes: node indices and offsets for every sample (branch-free arithmetic the
        // compiler vectorises), then the table reads and the weighted sum.
        const SCALE: f32 = (Z_NODES - 1) as f32 * 0.5;
        // Adding 1.5·2²³ rounds u ∈ [0, 128] to the nearest integer, which lands in the low
        // mantissa bits: no float-to-integer conversion.
        const ROUND: f32 = 12_582_912.0;
        let mut node = [0u32; N];
        let mut offset = [0.0f32; N];
        for ((x, k), t) in self.directions.iter().zip(&mut node).zip(&mut offset) {
            let u = (x.dot(n).clamp(-1.0, 1.0) + 1.0) * SCALE;
            let r = u + ROUND;
            *k = r.to_bits() & 0xff;
            *t = u - (r - ROUND);
        }
        let mut acc = T::ZERO;
        for ((&k, &t), &a) in node.iter().zip(&offset).zip(&self.alpha) {
            let [v, s, c] = f.z[(k as usize).min(Z_NODES - 1)];
            acc = acc.mul_add(a, v + t * (s + t * c));
        }
        let unit = f.mean_variance * f.calibration[0];
        Ok(Estimate {
            value: self.absolute(PI, acc),
            variance: self.scaled(unit),
            unit_variance: Some(unit),
        })
    }

    /// `g·β + s·Σ` per channel for a normalised sum `Σ` and a gain `g ∈ (0, 4π]`: in f32 when
    /// that is finite, else apart in mantissas and exponents ([`scale::rescaled`]), which
    /// gives `±∞` only when the result exceeds `f32::MAX` (or `β` does).
    #[inline]
    pub(super) fn absolute(&self, g: f32, sum: T) -> T {
        let fast = self.beta.scale(g).add(sum.mul(self.scale));
        if (0..T::CHANNELS).all(|c| fast.channel(c).is_finite()) {
            return fast;
        }
        self.rescaled(g, sum, 1.0)
    }

    /// `a·(g·β + s·Σ)` per channel by [`scale::rescaled`].
    pub(super) fn rescaled(&self, g: f32, sum: T, a: f32) -> T {
        from_channels(|c| {
            scale::rescaled(self.beta.channel(c), g, self.scale.channel(c), sum.channel(c), a)
        })
    }

    /// `s²·σ̂′²·unit` per channel: σ̂′²·unit is a normal number (or 0), and s·(s·x) is
    /// monotone, so no intermediate overflows or underflows; a positive variance below the
    /// least positive f32 is rounded up to it ([`scale::at_least_tiny`]).
    #[inline]
    fn scaled(&self, unit: f32) -> T {
        let normalised = self.signal_variance.scale(unit);
        scale::at_least_tiny(normalised.mul(self.scale).mul(self.scale), normalised)
    }

    /// `a²·s²·σ̂′²·unit` per channel by [`scale::scaled_variance`].
    pub(super) fn rescaled_variance(&self, unit: f32, a: f32) -> T {
        from_channels(|c| {
            scale::scaled_variance(self.signal_variance.channel(c) * unit, self.scale.channel(c), a)
        })
    }

    /// `σ̂′²·s²·a²·v` per channel for an f64 unit variance `v`, rounded once (a positive
    /// variance below the least positive f32 rounded up to it).
    pub(super) fn variance_of_unit(&self, v: f64, a: f64) -> T {
        from_channels(|c| {
            let sa = f64::from(self.scale.channel(c)) * a;
            let x = f64::from(self.signal_variance.channel(c)) * v * sa * sa;
            if x > 0.0 && x < f64::from(f32::from_bits(1)) {
                f32::from_bits(1)
            } else {
                x as f32
            }
        })
    }

    /// The exact posterior variance of `E(n)` (σ̂_f² times the unit variance at `n`), O(N²);
    /// `+∞` where it exceeds `f32::MAX`.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite normal.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{probe::Probe, Vec3};
    ///
    /// let mut probe = Probe::<32>::new();
    /// probe.update(&probe.directions().map(|d| 1.0 + d.x * d.z))?;
    /// // The exact variance at one normal, and the O(1) direction-averaged one of `irradiance`.
    /// let exact = probe.irradiance_variance(Vec3::Z)?;
    /// let averaged = probe.irradiance(Vec3::Z)?.variance;
    /// assert!(exact >= 0.0 && averaged >= 0.0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn irradiance_variance(&self, normal: Vec3) -> Result<T, Error> {
        let n = normal.try_normalize().ok_or(Error::InvalidDirection)?;
        let f = self.member_in_use()?;
        let zeta: [f64; N] = core::array::from_fn(|i| match self.directions.get(i) {
            Some(x) => f64::from(z_lookup(f.z, x.dot(n))),
            None => 0.0,
        });
        let v = self.unit_variance(f, &zeta, core::f64::consts::PI, f64::from(f.vbar));
        Ok(self.variance_of_unit(v * f64::from(f.calibration[0]), 1.0))
    }

    /// Glossy radiance `∫ L(x)·G(x) dx` for a spherical-Gaussian lobe
    /// `G(x) = a·exp(μ(r·x − 1))`, with a direction-averaged posterior variance, O(N) (one
    /// `exp`, at most one `expm1` and one `sqrt` per sample).
    ///
    /// With `G = SphericalGaussian::phong_moments(r, e)` (unit integral, `μ = e + 2`, the
    /// Phong lobe's first Legendre moment) this is the normalised Phong-lobe average of the
    /// radiance about the mirror direction `r`: the glossy term of a prefiltered environment.
    /// The SG stands in for the Phong lobe: on smooth lighting that leaves an error floor of
    /// about 1 % at `e = 5` (`eval/src/bin/glossy.rs`, `docs/glossy.md`), less for sharper lobes.
    /// The lobe is integrated over the whole sphere (no horizon clipping, no cosine factor:
    /// below the horizon a lobe of `μ = 22` keeps `e^(−22)` of its peak).
    ///
    /// The kernel is an SG of sharpness `λ` too, so `zᵢ = ∫ k(xᵢ, x)·G(x) dx` is closed:
    /// `4πa·exp(w − λ − μ)·(1 − e^(−2w))/(2w)` with `w = |λxᵢ + μr|` (the integral of the
    /// product SG), evaluated as `exp(2λμ(t − 1)/(w + λ + μ))` so that sharp lobes do not
    /// cancel, and with `libm` whatever the math backend (`Σ αᵢzᵢ` cancels by up to cond(Q),
    /// so `zᵢ` needs full f32 accuracy). The estimate is `β·a·F(μ) + Σᵢ αᵢzᵢ` with
    /// `F(μ) = 2π(1 − e^(−2μ))/μ`. As `μ` grows it tends to `a·F(μ)` times the posterior mean
    /// of the radiance at `r` (the GP interpolant).
    ///
    /// The variance is σ̂_f²·a²·F(μ)² times the unit variance over `F(μ)²` averaged over 37
    /// mirror directions, baked per member at `μ = 0, 1, 2, 4, …, 1024` and interpolated
    /// linearly in `μ` (constant above 1024); [`Probe::glossy_variance`] is exact for `r`.
    ///
    /// The amplitude `a` is applied last, with the probe's scale, in mantissa and exponent
    /// apart: any finite `a` (10²⁰ or 10⁻²⁰ say) scales the value by `a` and the variance by
    /// `a²`, `±∞` only where the result exceeds `f32::MAX`. [`Estimate::unit_variance`] is
    /// `a²·F(μ)²` times the baked unit variance.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite axis; [`Error::InvalidSharpness`]
    /// for a sharpness that is negative, not finite or above [`MAX_GLOSSY_SHARPNESS`];
    /// [`Error::InvalidWeights`] for a non-finite amplitude.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{probe::Probe, sg::SphericalGaussian, Vec3};
    ///
    /// let mut probe = Probe::<64>::new();
    /// probe.update(&[2.0; 64])?;
    /// // ∫ L·G over the sphere: for a constant L, L times the lobe's integral.
    /// let lobe = SphericalGaussian::phong_moments(Vec3::Z, 20.0)?; // unit integral
    /// let e = probe.glossy(&lobe)?;
    /// assert!((e.value - 2.0).abs() < 1e-3 && e.variance >= 0.0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn glossy(&self, lobe: &SphericalGaussian) -> Result<Estimate<T>, Error> {
        let (r, mu, amp) = check_lobe(lobe)?;
        let f = self.member_in_use()?;
        if let Kind::CosinePower { exponent } = F::KIND {
            return Ok(self.glossy_by_series(f, exponent, r, mu, amp));
        }
        let lambda = f.lambda;
        let top = lambda + mu;
        let two_lm = 2.0 * lambda * mu;
        // Unit amplitude: `a` and the scale s are applied last (see `scale::rescaled`).
        let scale = 4.0 * PI;
        let full = full_integral_unchecked(mu);
        let mut acc = T::ZERO;
        // Always `libm`, whatever the math backend: Σ αᵢzᵢ cancels heavily for the smooth
        // members (cond(Q) up to 10⁵), so zᵢ needs full f32 accuracy (micromath's `exp` made
        // the λ = 1 estimate 25 % wrong).
        for (x, &a) in self.directions.iter().zip(&self.alpha) {
            // t − 1 = −|x − r|²/2, accurate near the lobe's axis.
            let d = -0.5 * (*x - r).length_squared();
            let w = libm::sqrtf((top * top + two_lm * d).max(0.0));
            let e = libm::expf(two_lm * d / (w + top));
            // (1 − e^(−2w))/(2w): e^(−2w) < 2⁻²⁵ past w = 9; → 1 − w as w → 0.
            let h = if w > 9.0 {
                0.5 / w
            } else if w > 1e-3 {
                -libm::expm1f(-2.0 * w) / (2.0 * w)
            } else {
                1.0 - w
            };
            acc = acc.mul_add(a, scale * e * h);
        }
        let unit = full * full * glossy_grid_lookup(&f.glossy_variance, mu) * calibration(f, mu);
        Ok(Estimate {
            value: self.rescaled(full, acc, amp),
            variance: self.rescaled_variance(unit, amp),
            unit_variance: Some(amp * (amp * unit)),
        })
    }

    /// The exact posterior variance of [`Probe::glossy`] for `lobe` (σ̂_f² times the unit
    /// variance), O(N²), in f64; the amplitude's `a²` and the probe's scale are applied last
    /// (`+∞` only where the variance exceeds `f32::MAX`).
    ///
    /// `V̄ = ∫∫ G(x)·k(x, x′)·G(x′)` reduces, with `s = λ + μ − |λx + μr|`, to
    /// `a²·8π²/(λμ)·∫₀^{2 min(λ, μ)} exp(s²/(2λ) − s(2λ + μ)/λ)·(1 − e^(−2(λ + μ − s)))/2 ds`,
    /// summed by 8-point Gauss–Legendre on panels of width `2λ/(2λ + μ)` until the integrand
    /// has fallen by `e^(−40)` (at most 41 panels: about 0.8·10⁶ Cortex-M4 instructions of soft
    /// f64 at N = 16, 1.2·10⁶ at N = 64).
    ///
    /// # Errors
    /// As [`Probe::glossy`].
    pub fn glossy_variance(&self, lobe: &SphericalGaussian) -> Result<T, Error> {
        let (r, mu, amp) = check_lobe(lobe)?;
        let f = self.member_in_use()?;
        let lambda = f64::from(f.lambda);
        // Unit amplitude; a² is applied with the scale at the end.
        let mu = f64::from(mu);
        let integral = glossy_full_integral(mu);
        if let Kind::CosinePower { exponent } = F::KIND {
            // zᵢ = a·F(μ)·Σ_l K_l·g_l·(2l + 1)/(4π)·ρₗ(μ)·P_l(xᵢ·r); V̄ as for point samples.
            let mut h = [0.0f64; MAX_SERIES];
            let len = cosine_series(lambda, exponent, &mut h);
            let mut rho = [0.0f64; MAX_SERIES];
            bessel_ratios(mu, &mut rho[..len]);
            for (h, &p) in h.iter_mut().zip(&rho[..len]) {
                *h *= integral * p;
            }
            let zeta: [f64; N] = core::array::from_fn(|i| match self.directions.get(i) {
                Some(x) => legendre::sum_f64(&h[..len], f64::from(x.dot(r))),
                None => 0.0,
            });
            let vbar = glossy_vbar(lambda, mu);
            let v = self.unit_variance(f, &zeta, integral, vbar);
            return Ok(
                self.variance_of_unit(v * f64::from(calibration(f, mu as f32)), f64::from(amp))
            );
        }
        let top = lambda + mu;
        let two_lm = 2.0 * lambda * mu;
        let scale = 4.0 * core::f64::consts::PI;
        let zeta: [f64; N] = core::array::from_fn(|i| match self.directions.get(i) {
            Some(x) => {
                let dx = [x.x - r.x, x.y - r.y, x.z - r.z].map(f64::from);
                let d = -0.5 * (dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]);
                let w = crate::math::sqrt64((top * top + two_lm * d).max(0.0));
                let h = if w > 1e-8 { -libm::expm1(-2.0 * w) / (2.0 * w) } else { 1.0 - w };
                scale * libm::exp(two_lm * d / (w + top)) * h
            }
            None => 0.0,
        });
        let vbar = if let Kind::Gaussian { sharpness } = F::KIND {
            integral * integral * deconvolved_vbar(lambda, sharpness, mu)
        } else {
            glossy_vbar(lambda, mu)
        };
        let v = self.unit_variance(f, &zeta, integral, vbar);
        Ok(self.variance_of_unit(v * f64::from(calibration(f, mu as f32)), f64::from(amp)))
    }

    /// The normalised Phong lobe average `∫ L(x)·(e + 1)/(2π)·max(0, r·x)ᵉ dx` about the mirror
    /// direction `r`, exact under the model (no spherical-Gaussian stand-in), with a
    /// direction-averaged posterior variance; O(N·L).
    ///
    /// By Funk–Hecke the lobe acts on degree `l` as the gain
    /// `Φ_l = (e + 1)∫₀¹ tᵉ P_l(t) dt` (two-term recurrence), so the covariance of sample `i`
    /// with the integral is `zᵢ = Σ_l C_l·Φ_l·P_l(xᵢ·r)`, where `C_l` are the Legendre
    /// coefficients of the sample's covariance with the radiance: the kernel's spherical
    /// Gaussian (point samples; of sharpness `ν` for a Gaussian footprint) or that times the
    /// footprint's gains (cosine power). The sum runs over `L = 16 + ⌊9.1√λ⌋` degrees (past
    /// them the kernel's coefficients are below `e^{−41}` of the first), once per sample: about
    /// `L` multiply-adds more per sample than [`Probe::glossy`] (the crate's Cortex-M4 cost tables).
    ///
    /// [`Probe::glossy`] with [`SphericalGaussian::phong_moments`] approximates the same lobe
    /// by a spherical Gaussian, exact in its integral and first moment only: for broad lobes
    /// that leaves a floor (about 3 % at `e = 5` on the footprint benchmark's maps) which this
    /// query does not have. The variance is the baked glossy grid at `μ = e + 2` (the SG of
    /// the same first moment); [`Probe::phong_variance`] is exact.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite axis; [`Error::InvalidExponent`]
    /// for an exponent that is negative, not finite or above [`MAX_GLOSSY_SHARPNESS`].
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{probe::Probe, Error, Vec3};
    ///
    /// let mut probe = Probe::<64>::new();
    /// probe.update(&[0.5; 64])?;
    /// // The normalised Phong lobe integrates to 1: a constant radiance comes back.
    /// let e = probe.phong(Vec3::new(0.0, 0.6, 0.8), 20.0)?;
    /// assert!((e.value - 0.5).abs() < 1e-3);
    /// assert_eq!(probe.phong(Vec3::Z, f32::NAN), Err(Error::InvalidExponent));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn phong(&self, axis: Vec3, exponent: f32) -> Result<Estimate<T>, Error> {
        let r = axis.try_normalize().ok_or(Error::InvalidDirection)?;
        if !(0.0..=MAX_GLOSSY_SHARPNESS).contains(&exponent) {
            return Err(Error::InvalidExponent);
        }
        let f = self.member_in_use()?;
        let mut h = [0.0f32; MAX_SERIES];
        let len = match F::KIND {
            Kind::CosinePower { exponent: p } => cosine_series_f32(f.lambda, p, &mut h),
            _ => sg_series_f32(f.lambda, &mut h),
        };
        let Some(h) = h.get_mut(..len) else { return Err(Error::Internal) };
        apply_cosine_power_gains(exponent, h);
        let rec = legendre::factor_table::<MAX_SERIES>(len);
        let mut acc = T::ZERO;
        for (x, &a) in self.directions.iter().zip(&self.alpha) {
            acc = acc.mul_add(a, legendre::sum(h, &rec, x.dot(r)));
        }
        let mu = exponent + 2.0;
        let unit = glossy_grid_lookup(&f.glossy_variance, mu) * calibration(f, mu);
        Ok(Estimate {
            value: self.absolute(1.0, acc),
            variance: self.scaled(unit),
            unit_variance: Some(unit),
        })
    }

    /// The exact posterior variance of [`Probe::phong`] (σ̂_f² times the unit variance),
    /// O(N² + N·L), in f64: `V̄ = Σ_l K_l·Φ_l²·(2l + 1)/(4π)` with the kernel's coefficients
    /// `K_l`.
    ///
    /// # Errors
    /// As [`Probe::phong`].
    pub fn phong_variance(&self, axis: Vec3, exponent: f32) -> Result<T, Error> {
        let r = axis.try_normalize().ok_or(Error::InvalidDirection)?;
        if !(0.0..=MAX_GLOSSY_SHARPNESS).contains(&exponent) {
            return Err(Error::InvalidExponent);
        }
        let f = self.member_in_use()?;
        let (lambda, e) = (f64::from(f.lambda), f64::from(exponent));
        let mut k = [0.0f64; MAX_SERIES];
        let len = kernel_coefficients(F::KIND, lambda, &mut k);
        let Some(k) = k.get_mut(..len) else { return Err(Error::Internal) };
        // Cross-covariance coefficients: SG(λ or ν) for point and Gaussian samples, K·g for
        // the cosine power; then the lobe's gains.
        let mut h = [0.0f64; MAX_SERIES];
        let cross = match F::KIND {
            Kind::Gaussian { .. } => {
                let n = (16 + (9.1 * crate::math::sqrt64(lambda)) as usize).min(MAX_SERIES);
                let Some(h) = h.get_mut(..n) else { return Err(Error::Internal) };
                bessel_ratios(lambda, h);
                let full = glossy_full_integral(lambda);
                for (l, c) in h.iter_mut().enumerate() {
                    *c *= full * (2 * l + 1) as f64 / (4.0 * core::f64::consts::PI);
                }
                n
            }
            Kind::CosinePower { exponent: p } => {
                for (c, &kl) in h.iter_mut().zip(k.iter()) {
                    *c = kl;
                }
                if let Some(h) = h.get_mut(..len) {
                    apply_cosine_power_gains(f64::from(p), h);
                }
                len
            }
            _ => {
                for (c, &kl) in h.iter_mut().zip(k.iter()) {
                    *c = kl;
                }
                len
            }
        };
        let Some(h) = h.get_mut(..cross) else { return Err(Error::Internal) };
        apply_cosine_power_gains(e, h);
        let zeta: [f64; N] = core::array::from_fn(|i| match self.directions.get(i) {
            Some(x) => legendre::sum_f64(h, f64::from(x.dot(r))),
            None => 0.0,
        });
        // Applied twice: K_l·Φ_l²·(2l + 1)/(4π).
        apply_cosine_power_gains(e, k);
        apply_cosine_power_gains(e, k);
        let vbar: f64 = k.iter().sum();
        let v = self.unit_variance(f, &zeta, 1.0, vbar);
        Ok(self.variance_of_unit(v * f64::from(calibration(f, exponent + 2.0)), 1.0))
    }

    /// [`Probe::glossy`] for a cosine-power footprint: `zᵢ = a·F(μ)·Σ_l bₗ·ρₗ(μ)·P_l(xᵢ·r)`
    /// with `bₗ = K_l·g_l·(2l + 1)/(4π)` ([`cosine_series`]) and `ρₗ(μ) = i_l(μ)/i₀(μ)`.
    pub(super) fn glossy_by_series(
        &self,
        f: &sealed::Baked,
        exponent: u32,
        r: Vec3,
        mu: f32,
        amp: f32,
    ) -> Estimate<T> {
        // Unit amplitude: `a` and the scale s are applied last.
        let full = full_integral_unchecked(mu);
        let mut h = [0.0f32; MAX_SERIES];
        let len = cosine_series_f32(f.lambda, exponent, &mut h);
        let mut rho = [0.0f32; MAX_SERIES];
        let Some(rho) = rho.get_mut(..len) else {
            return Estimate { value: T::ZERO, variance: T::ZERO, unit_variance: Some(0.0) };
        };
        bessel_ratios(mu, rho);
        for (h, &p) in h.iter_mut().zip(rho.iter()) {
            *h *= full * p;
        }
        let rec = legendre::factor_table::<MAX_SERIES>(len);
        let mut acc = T::ZERO;
        for (x, &a) in self.directions.iter().zip(&self.alpha) {
            acc = acc.mul_add(a, legendre::sum(&h[..len], &rec, x.dot(r)));
        }
        let unit = full * full * glossy_grid_lookup(&f.glossy_variance, mu) * calibration(f, mu);
        Estimate {
            value: self.rescaled(full, acc, amp),
            variance: self.rescaled_variance(unit, amp),
            unit_variance: Some(amp * (amp * unit)),
        }
    }

    pub(super) fn member_in_use(&self) -> Result<&'static sealed::Baked, Error> {
        Self::FAMILY.get(self.selected).ok_or(Error::Internal)
    }

    /// `V̄ − ζᵀQ⁻¹ζ + (I − 1ᵀQ⁻¹ζ)²/1ᵀQ⁻¹1` for `ζᵢ = ∫ k(xᵢ, x)·φ(x) dx`, `I = ∫ φ` and
    /// `V̄ = ∫∫ φ·k·φ` of a weight function `φ`, clamped at zero.
    pub(super) fn unit_variance(
        &self,
        f: &sealed::Baked,
        zeta: &[f64; N],
        integral: f64,
        vbar: f64,
    ) -> f64 {
        let m = Self::HALF;
        // With s, d the sums and differences of mirrored ζ and E = LLᵀ, F = MMᵀ:
        // ζᵀQ⁻¹ζ = ½‖L⁻¹s‖² + ½‖M⁻¹d‖² and 1ᵀQ⁻¹ζ = gᵀs. Forward substitutions only, in
        // f64: the variance is a small difference of large terms when σ′ is small.
        let (lo, hi) = zeta.split_at(m);
        let mut s = [0.0f64; N];
        {
            let (sv, dv) = s.split_at_mut(m);
            for (((a, b), sp), dp) in lo.iter().zip(hi.iter().rev()).zip(sv).zip(dv) {
                *sp = a + b;
                *dp = a - b;
            }
        }
        let (sv, dv) = s.split_at_mut(m);
        let one: f64 = sv.iter().zip(f.g).map(|(x, &g)| x * f64::from(f32::from_bits(g))).sum();
        forward_substitution(f.chol_even, sv);
        forward_substitution(f.chol_odd, dv);
        let quad =
            0.5 * (sv.iter().map(|x| x * x).sum::<f64>() + dv.iter().map(|x| x * x).sum::<f64>());
        let (quad, one, s1) = if self.missing.is_empty() {
            (quad, one, f64::from(f.s1))
        } else {
            // The valid subset's ζ_VᵀQ_VV⁻¹ζ_V, 1ᵀQ_VV⁻¹ζ_V and s₁ by the Schur complement of
            // the missing block, from E⁻¹s and F⁻¹d (`missing.rs`).
            back_substitution(f.chol_even, sv);
            back_substitution(f.chol_odd, dv);
            self.missing.correct(sv, dv, quad, one)
        };
        let v = vbar - quad + (integral - one) * (integral - one) / s1;
        v.max(0.0)
    }

    /// The family member in use (index into [`Probe::family`]).
    #[must_use]
    pub const fn selected(&self) -> usize {
        self.selected
    }

    /// The restricted log marginal likelihood of the last update's samples under the
    /// selected member (up to a constant shared by the family), of the samples as given:
    /// `ℓ(c·Y) = ℓ(Y) − (N − 1)·C·ln c` for `C` channels.
    #[must_use]
    pub const fn log_likelihood(&self) -> f32 {
        self.log_likelihood
    }

    /// `σ̂_f² = rᵀQ⁻¹r/(N − 1)` of the last update, per channel: the diagonal of
    /// [`Probe::signal_covariance`]. Stored relative to the samples' spread, so it is exact
    /// at any radiance scale; `+∞` where `σ̂_f²` itself exceeds `f32::MAX` (samples spread
    /// wider than about 10¹⁹), 0 or subnormal below the normal range (spread under 10⁻¹⁹).
    #[must_use]
    pub fn signal_variance(&self) -> T {
        self.signal_variance.mul(self.scale).mul(self.scale)
    }

    /// `π·β`: the irradiance of the fitted constant mean (`β` is the GLS mean radiance);
    /// `±∞` where it exceeds `f32::MAX`.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::probe::Probe;
    ///
    /// let mut probe = Probe::<16>::new();
    /// probe.update(&[3.0; 16])?;
    /// // A constant's fitted mean is the constant: π·3.
    /// assert!((probe.mean_irradiance() - 3.0 * core::f32::consts::PI).abs() < 1e-4);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub fn mean_irradiance(&self) -> T {
        self.beta.scale(PI)
    }
}

pub(super) fn member_of(b: &sealed::Baked, footprint: Kind) -> Member {
    Member {
        footprint,
        lambda: b.lambda,
        length_scale: crate::math::sqrt(2.0 / b.lambda),
        sigma: b.sigma,
        condition: b.condition,
        mean_variance: b.mean_variance,
        max_variance: b.max_variance,
        calibration: b.calibration,
    }
}

pub(super) fn check_lobe(lobe: &SphericalGaussian) -> Result<(Vec3, f32, f32), Error> {
    let r = lobe.axis.try_normalize().ok_or(Error::InvalidDirection)?;
    let mu = lobe.sharpness;
    if !(0.0..=MAX_GLOSSY_SHARPNESS).contains(&mu) {
        return Err(Error::InvalidSharpness);
    }
    if !lobe.amplitude.is_finite() {
        return Err(Error::InvalidWeights);
    }
    Ok((r, mu, lobe.amplitude))
}

/// The lobe sharpnesses of the glossy calibration factors.
pub(super) const CALIBRATION_MU: [f32; 3] = [7.0, 22.0, 102.0];

/// Member `f`'s glossy calibration factor at lobe sharpness `μ`: the baked factors at
/// [`CALIBRATION_MU`], linear in `ln μ` between them, constant outside.
pub(super) fn calibration(f: &sealed::Baked, mu: f32) -> f32 {
    let [_, c7, c22, c102] = f.calibration;
    let [m0, m1, m2] = CALIBRATION_MU;
    if mu <= m0 {
        return c7;
    }
    if mu >= m2 {
        return c102;
    }
    let (lo, hi, a, b) = if mu < m1 { (m0, m1, c7, c22) } else { (m1, m2, c22, c102) };
    let t = crate::math::ln(mu / lo) / crate::math::ln(hi / lo);
    a + t.clamp(0.0, 1.0) * (b - a)
}

/// The glossy variance grid at `μ`: linear between `μ = 0` and 1, then linear in `μ` within
/// each octave `[2^k, 2^(k+1)]` (the octave from the float's exponent bits), the last value
/// above 1024.
pub(super) fn glossy_grid_lookup(grid: &[f32; GLOSSY_GRID], mu: f32) -> f32 {
    let at = |k: usize| grid.get(k).copied().unwrap_or(0.0);
    if mu < 1.0 {
        return at(0) + mu * (at(1) - at(0));
    }
    let top = (1u32 << (GLOSSY_GRID - 2)) as f32;
    if mu >= top {
        return at(GLOSSY_GRID - 1);
    }
    // μ = 2^e·(1 + m), e = 0…9: grid points e + 1 and e + 2.
    let e = ((mu.to_bits() >> 23) as usize).saturating_sub(127);
    let base = (1u32 << e.min(31)) as f32;
    let f = mu / base - 1.0;
    at(e + 1) + f * (at(e + 2) - at(e + 1))
}

/// `F(μ) = 2π(1 − e^(−2μ))/μ` in f64 (`4π` at `μ = 0`).
pub(super) fn glossy_full_integral(mu: f64) -> f64 {
    let two_pi = 2.0 * core::f64::consts::PI;
    if mu == 0.0 {
        2.0 * two_pi
    } else {
        -two_pi * libm::expm1(-2.0 * mu) / mu
    }
}

/// `∫∫ exp(μ(r·x − 1))·exp(λ(x·x′ − 1))·exp(μ(r·x′ − 1)) dx dx′` (see
/// [`Probe::glossy_variance`]).
pub(super) fn glossy_vbar(lambda: f64, mu: f64) -> f64 {
    let pi = core::f64::consts::PI;
    if mu == 0.0 {
        // ∫∫ k = 4π·F(λ).
        return 4.0 * pi * glossy_full_integral(lambda);
    }
    let rate = (2.0 * lambda + mu) / lambda;
    let end = 2.0 * lambda.min(mu);
    let width = 2.0 / rate;
    let exponent = |s: f64| s * s / (2.0 * lambda) - s * rate;
    let mut sum = 0.0;
    let mut a = 0.0;
    for _ in 0..64 {
        let b = (a + width).min(end);
        let h = b - a;
        for &(x, w) in &crate::tables::GAUSS_LEGENDRE_8 {
            let s = a + h * x;
            // 1 − e^(−2w), w = λ + μ − s; e^(−40) is below f64 resolution.
            let two_w = 2.0 * (lambda + mu - s);
            let tail = if two_w > 40.0 { 1.0 } else { -libm::expm1(-two_w) };
            sum += w * h * libm::exp(exponent(s)) * 0.5 * tail;
        }
        if b >= end || exponent(b) < -40.0 {
            break;
        }
        a = b;
    }
    8.0 * pi * pi / (lambda * mu) * sum
}

/// `π·z(t)` from the 129-node table: the nearest node's quadratic in the offset `f`,
/// `|f| ≤ ½`. `t` is clamped to [−1, 1].
#[inline]
pub(super) fn z_lookup(z: &[[f32; 3]; Z_NODES], t: f32) -> f32 {
    const SCALE: f32 = (Z_NODES - 1) as f32 * 0.5;
    // Adding 1.5·2²³ rounds u ∈ [0, 128] to the nearest integer, which lands in the low
    // mantissa bits: no float-to-integer conversion (NaN gives node 0 and a NaN offset).
    const ROUND: f32 = 12_582_912.0;
    let u = (t.clamp(-1.0, 1.0) + 1.0) * SCALE;
    let r = u + ROUND;
    let k = ((r.to_bits() & 0xff) as usize).min(Z_NODES - 1);
    let f = u - (r - ROUND);
    let [v, s, c] = z[k];
    v + f * (s + f * c)
}
