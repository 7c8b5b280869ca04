//! Queries: irradiance, lobes and the SH export of the posterior mean, with their variances.

use super::linalg::project;
use super::*;
use crate::estimate::MAX_GLOSSY_SHARPNESS;

impl<const K: usize, T: Radiance> LayoutProbe<K, T> {
    /// The sensors' unit directions.
    #[must_use]
    pub const fn directions(&self) -> &[Vec3; K] {
        &self.directions
    }

    /// Sensor `i`'s isotropic `Cov(Yᵢ, E(n))` at unit scale, from its response's table.
    #[inline(always)]
    fn table_lookup(&self, i: usize, n: Vec3) -> f32 {
        lookup(&self.tables[self.class[i] as usize % MAX_RESPONSES], self.scaled[i], n)
    }

    /// `Cov(Yᵢ, E(n))` at unit scale for every sensor (table lookups).
    fn query_covariances(&self, n: Vec3) -> [f32; K] {
        let mut z = [0.0f32; K];
        for (i, zi) in z.iter_mut().enumerate() {
            *zi = self.table_lookup(i, n);
        }
        if !self.isotropic {
            let c = COSINE_FACTORS;
            let rv = self.zonal_query(n, &[c[0], c[1], c[2]]);
            for (zi, u) in z.iter_mut().zip(&self.zonal_u) {
                *zi += u[0] * rv[0] + u[1] * rv[1] + u[2] * rv[2];
            }
        }
        z
    }

    /// `R·v(n)` for a lobe of zonal factors `q₀, q₁, q₂`: `v_l = q_l·Y_l0(n)`.
    fn zonal_query(&self, n: Vec3, q: &[f32; 3]) -> [f32; 3] {
        let y = harmonics::zonal(n.z);
        times_r(&self.zonal_r, &[q[0] * y[0], q[1] * y[1], q[2] * y[2]])
    }

    /// The zonal part of a lobe's prior variance, `v(n)ᵀR·v(n)`.
    fn zonal_prior(&self, n: Vec3, q: &[f32; 3]) -> f32 {
        let y = harmonics::zonal(n.z);
        let rv = self.zonal_query(n, q);
        q[0] * y[0] * rv[0] + q[1] * y[1] * rv[1] + q[2] * y[2] * rv[2]
    }

    /// The mean basis's irradiance at `n`.
    fn mean_query(&self, n: Vec3) -> f32 {
        if self.mean_terms == 0 {
            return 0.0;
        }
        legendre::sum(&self.basis_query[0], &RECURRENCE, n.z)
    }

    /// Irradiance `E(n) = ∫ L(x)·max(0, n·x) dx` with the direction-averaged posterior
    /// variance (O(K)), and for one channel as [`Estimate::unit_variance`] that variance for a
    /// signal variance `s` of 1 (`variance` is `unit_variance ·`[`LayoutProbe::signal_variance`];
    /// `None` for more channels: each channel has its own noise ratio). [`Error::InvalidDirection`]
    /// for a zero or non-finite normal; before the first update, zero with zero variance.
    pub fn irradiance(&self, normal: Vec3) -> Result<Estimate<T>, Error> {
        let n = unit(normal)?;
        let h = self.mean_query(n);
        let mut value = self.beta[0].scale(h);
        if self.isotropic && self.classes == 1 {
            let table = &self.tables[0];
            for i in 0..K {
                value = value.mul_add(self.alpha[i], lookup(table, self.scaled[i], n));
            }
        } else if self.isotropic {
            for i in 0..K {
                value = value.mul_add(self.alpha[i], self.table_lookup(i, n));
            }
        } else {
            let z = self.query_covariances(n);
            for i in 0..K {
                value = value.mul_add(self.alpha[i], z[i]);
            }
        }
        Ok(Estimate {
            value: self.to_readings(value),
            variance: self.average_variance,
            unit_variance: (T::CHANNELS == 1).then_some(self.average_unit_variance.channel(0)),
        })
    }

    /// Values in working units to reading units, per channel.
    fn to_readings(&self, value: T) -> T {
        from_channels(|ch| value.channel(ch) * self.unit.channel(ch))
    }

    /// The exact posterior variance of [`LayoutProbe::irradiance`] at `normal`, O(K²).
    pub fn irradiance_variance(&self, normal: Vec3) -> Result<T, Error> {
        let n = unit(normal)?;
        let z = self.query_covariances(n);
        let c = cosine_factors_lookup();
        let prior = self.prior_variance + self.zonal_prior(n, &[c[0], c[1], c[2]]);
        Ok(self.exact_variance(&z, self.mean_query(n), prior, 1.0, 0).0)
    }

    /// The posterior variance per channel, in reading units times `amplitude²`, and the
    /// unit variance (`s = 1`) of channel 0, for unit-scale query covariances `z`, the
    /// query's mean basis value `h` and unit prior variance `prior`: with
    /// `q_j = s/(s·λ_j + ν)`, `s·(prior − Σ_j z̃_j²·q_j) + r²/Σ_j (h̃_j²/d_j)`,
    /// `r = h − Σ_j h̃_j·z̃_j·q_j` (factored: no power of `s` beyond the first).
    fn exact_variance(
        &self,
        z: &[f32; K],
        h: f32,
        prior: f32,
        mantissa: f32,
        exponent: i32,
    ) -> (T, f32) {
        let zw: [f32; K] = core::array::from_fn(|i| z[i] * self.whitening[i]);
        let zt = project(&self.vectors, &zw);
        let mut unit_variance = 0.0f32;
        let mut variances = [0.0f32; MAX_CHANNELS];
        for (ch, out) in variances.iter_mut().enumerate().take(T::CHANNELS) {
            let s = self.scale.channel(ch);
            let nu = self.nugget.channel(ch);
            let q = self.noise_ratio_weights(s, nu);
            let mut explained = prior;
            let (mut hz, mut hq, mut hd) = (0.0f32, 0.0f32, 0.0f32);
            for j in 0..K {
                explained -= zt[j] * zt[j] * q[j];
                if self.mean_terms == 1 {
                    let b = self.basis[0][j];
                    hz += b * zt[j] * q[j];
                    hq += b * b * q[j];
                    let d = s * self.values[j] + nu;
                    if d > 0.0 {
                        hd += b * b / d;
                    }
                }
            }
            // What f32 resolves: the explained part is known to rounding, of the order of
            // ε·prior; a posterior variance below that is reported at that level, not 0.
            let explained = explained.max(f32::EPSILON / 16.0 * prior);
            let (mut v, mut unit) = (s * explained, explained);
            if self.mean_terms == 1 {
                let r = h - hz;
                if hd > 0.0 {
                    v += r * r / hd;
                }
                if hq > 0.0 {
                    unit += r * r / hq;
                }
            }
            if ch == 0 {
                unit_variance = math::ldexp_variance(
                    unit * self.variance_scale * mantissa * mantissa,
                    2 * exponent.clamp(-200, 200) + self.spectrum_exponent,
                );
            }
            // v·(u·a)² by exponents: u·a may leave the range while the result does not.
            let u = self.unit.channel(ch);
            if u == 0.0 || v == 0.0 {
                continue;
            }
            *out = math::ldexp_variance(
                v * self.variance_scale * mantissa * mantissa,
                2 * (libm::ilogbf(u) + exponent),
            );
        }
        (from_channels(|ch| variances[ch.min(MAX_CHANNELS - 1)]), unit_variance)
    }

    /// The estimate of `∫ L(x)·f(axis·x) dx` for a zonal lobe `f` of Legendre coefficients
    /// `q_l = 2π∫ f(t)·P_l(t) dt`, with its exact posterior variance: O(K·DEGREES + K²).
    /// The lobe is `q` times `mantissa·2^exponent` (an amplitude kept apart from `q`, so that
    /// neither it nor the answers overflow before they must).
    fn lobe(&self, axis: Vec3, q: &[f32; DEGREES], mantissa: f32, exponent: i32) -> Estimate<T> {
        let weight = |l: usize| (2 * l + 1) as f32 / FOUR_PI;
        let mut series = [[0.0f32; DEGREES]; MAX_RESPONSES];
        for (c, g) in series.iter_mut().zip(&self.gains) {
            for l in 0..DEGREES {
                c[l] = self.spectrum[l] * g[l] * q[l] * weight(l);
            }
        }
        let rv = self.zonal_query(axis, &[q[0], q[1], q[2]]);
        let z: [f32; K] = core::array::from_fn(|i| {
            let u = &self.zonal_u[i];
            legendre::sum(
                &series[self.class[i] as usize % MAX_RESPONSES],
                &RECURRENCE,
                self.directions[i].dot(axis),
            ) + u[0] * rv[0]
                + u[1] * rv[1]
                + u[2] * rv[2]
        });
        let mean: [f32; 9] = core::array::from_fn(|l| self.profile[l] * q[l]);
        let h = if self.mean_terms == 1 { legendre::sum(&mean, &RECURRENCE, axis.z) } else { 0.0 };
        let prior = (0..DEGREES).map(|l| self.spectrum[l] * q[l] * q[l] * weight(l)).sum::<f32>()
            + self.zonal_prior(axis, &[q[0], q[1], q[2]]);
        let mut value = self.beta[0].scale(h);
        for i in 0..K {
            value = value.mul_add(self.alpha[i], z[i]);
        }
        let value = from_channels(|ch| {
            let u = self.unit.channel(ch);
            if u == 0.0 {
                return 0.0;
            }
            libm::scalbnf(value.channel(ch) * mantissa, libm::ilogbf(u) + exponent)
        });
        let (variance, unit) = self.exact_variance(&z, h, prior, mantissa, exponent);
        Estimate { value, variance, unit_variance: (T::CHANNELS == 1).then_some(unit) }
    }

    /// The normalised Phong average `∫ L(x)·(e + 1)/(2π)·max(0, axis·x)ᵉ dx` (the glossy term
    /// about a mirror direction), with its exact posterior variance, O(K·DEGREES + K²).
    /// [`Error::InvalidDirection`] for a zero or non-finite axis, [`Error::InvalidExponent`]
    /// for an exponent that is negative, not finite or above [`MAX_GLOSSY_SHARPNESS`] (the
    /// limit of [`crate::probe::Probe::phong`]). [`Estimate::unit_variance`] is as in
    /// [`LayoutProbe::irradiance`].
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let prior = Prior::squared_exponential(2.0)?;
    /// let mut probe = LayoutProbe::<6>::new(&faces.map(Sensor::cosine), prior, Noise::NONE)?;
    /// probe.update(&[1.0; 6])?;
    /// // A constant radiance: every normalised lobe averages to it, with no variance.
    /// let e = probe.phong(Vec3::new(0.2, 0.3, 0.9), 20.0)?;
    /// assert!((e.value - 1.0).abs() < 1e-4 && e.variance < 1e-6);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn phong(&self, axis: Vec3, exponent: f32) -> Result<Estimate<T>, Error> {
        let r = unit(axis)?;
        if !(0.0..=MAX_GLOSSY_SHARPNESS).contains(&exponent) {
            return Err(Error::InvalidExponent);
        }
        Ok(self.lobe(r, &cosine_power_gains(f64::from(exponent)), 1.0, 0))
    }

    /// `∫ L(x)·G(x) dx` for a spherical-Gaussian lobe `G`, with its exact posterior variance,
    /// O(K·DEGREES + K²). [`Error::InvalidSharpness`] for a sharpness above
    /// [`MAX_GLOSSY_SHARPNESS`] (the limit of [`crate::probe::Probe::glossy`]; or not finite,
    /// or negative), [`Error::InvalidWeights`] for a non-finite amplitude,
    /// [`Error::InvalidDirection`] for a bad axis. The amplitude is kept apart from the
    /// lobe's shape: the value is `±∞` only where `∫ L·G` itself exceeds `f32::MAX`, the
    /// variance where its square does. [`Estimate::unit_variance`] is as in
    /// [`LayoutProbe::irradiance`] (with the amplitude's square).
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::sg::SphericalGaussian;
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let prior = Prior::squared_exponential(2.0)?;
    /// let mut probe = LayoutProbe::<6>::new(&faces.map(Sensor::cosine), prior, Noise::NONE)?;
    /// probe.update(&[2.0; 6])?;
    /// let lobe = SphericalGaussian::new(Vec3::Z, 10.0, 1.0)?;
    /// let e = probe.glossy(&lobe)?;
    /// assert!((e.value - 2.0 * lobe.integral()).abs() < 1e-4 * e.value);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn glossy(&self, lobe: &SphericalGaussian) -> Result<Estimate<T>, Error> {
        let r = unit(lobe.axis)?;
        let mu = lobe.sharpness;
        if !(0.0..=MAX_GLOSSY_SHARPNESS).contains(&mu) {
            return Err(Error::InvalidSharpness);
        }
        let a = lobe.amplitude;
        if !a.is_finite() {
            return Err(Error::InvalidWeights);
        }
        if a == 0.0 {
            return Ok(self.lobe(r, &[0.0; DEGREES], 0.0, 0));
        }
        let mut q = [0.0f32; DEGREES];
        q[0] = 1.0;
        if mu > 0.0 {
            q = gaussian_gains(f64::from(mu));
        }
        // ∫G = a·2π(1 − e^{−2μ})/μ, as a mantissa and an exponent.
        let unit_lobe = SphericalGaussian { amplitude: 1.0, ..*lobe };
        let integral = unit_lobe.integral();
        let (ea, ei) = (libm::ilogbf(a), libm::ilogbf(integral));
        let mantissa = libm::scalbnf(a, -ea) * libm::scalbnf(integral, -ei);
        Ok(self.lobe(r, &q, mantissa, ea + ei))
    }

    /// The posterior mean of the radiance's spherical-harmonic coefficients of degree ≤ 2
    /// (the 9 that renderers take; [`crate::sh`] evaluates, rotates and converts them):
    /// `c_lm = β·a_l·√(4π/(2l + 1))·δ_m0 + Σᵢ αᵢ·K_l gᵢ_l·Y_lm(dᵢ)`, O(9K).
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let prior = Prior::squared_exponential(2.0)?;
    /// let mut probe = LayoutProbe::<6>::new(&faces.map(Sensor::cosine), prior, Noise::NONE)?;
    /// probe.update(&[1.0; 6])?;
    /// // A constant radiance of 1 has c₀₀ = √(4π), and nothing else.
    /// let sh = probe.radiance_sh();
    /// assert!((sh.coefficients[0] - (4.0 * core::f32::consts::PI).sqrt()).abs() < 1e-4);
    /// assert!(sh.coefficients[1..].iter().all(|c| c.abs() < 1e-4));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub fn radiance_sh(&self) -> ShL2<T> {
        let mut coefficients = [T::ZERO; 9];
        if self.mean_terms == 1 {
            for l in 0..3 {
                let c = self.profile[l] * math::sqrt(FOUR_PI / (2 * l + 1) as f32);
                coefficients[l * l + l] = self.beta[0].scale(c);
            }
        }
        for i in 0..K {
            let Ok(basis) = ShL2::<f32>::basis(self.directions[i]) else { continue };
            let g = &self.gains[self.class[i] as usize % MAX_RESPONSES];
            for (k, c) in coefficients.iter_mut().enumerate() {
                let l = if k == 0 {
                    0
                } else if k < 4 {
                    1
                } else {
                    2
                };
                *c = c.mul_add(self.alpha[i], self.spectrum[l] * g[l] * basis[k]);
            }
        }
        ShL2::new(coefficients.map(|c| self.to_readings(c)))
    }

    /// The scale `s = σ_f²` of the covariance chosen at the last update, per channel (0 before
    /// the first).
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let prior = Prior::squared_exponential(4.0)?;
    /// let mut probe = LayoutProbe::<6>::new(&faces.map(Sensor::cosine), prior, Noise::NONE)?;
    /// assert_eq!(probe.signal_variance(), 0.0);
    /// probe.update(&[1.0, 1.2, 0.9, 1.1, 2.0, 0.3])?;
    /// assert!(probe.signal_variance() > 0.0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub fn signal_variance(&self) -> T {
        from_channels(|ch| {
            let (s, u) = (self.scale.channel(ch), self.unit.channel(ch));
            if s == 0.0 || u == 0.0 {
                return 0.0;
            }
            libm::scalbnf(s, 2 * libm::ilogbf(u) - self.spectrum_exponent)
        })
    }

    /// The restricted (REML) log likelihood of the last update's readings under the probe's
    /// prior and noise, up to a constant, summed over channels:
    /// `−½·(log det Σ + log det HᵀΣ⁻¹H + rᵀΣ⁻¹r)` at the chosen scale (with a relative noise,
    /// at its mean level). Compare it
    /// between probes of the same sensors and readings to choose a prior per update; `+∞`
    /// when the readings fit exactly (a constant under a constant mean), 0 before the first.
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let sensors = faces.map(Sensor::cosine);
    /// let readings = [1.0, 1.2, 0.9, 1.1, 2.0, 0.3];
    /// let mut best = (f32::NEG_INFINITY, 0.0);
    /// for lambda in [1.0, 4.0, 16.0] {
    ///     let prior = Prior::squared_exponential(lambda)?;
    ///     let mut probe = LayoutProbe::<6>::new(&sensors, prior, Noise::NONE)?;
    ///     probe.update(&readings)?;
    ///     if probe.log_likelihood() > best.0 {
    ///         best = (probe.log_likelihood(), lambda);
    ///     }
    /// }
    /// assert!(best.0.is_finite());
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    #[must_use]
    pub const fn log_likelihood(&self) -> f32 {
        self.log_likelihood
    }

    /// Whether the probe has had an update.
    #[must_use]
    pub const fn is_updated(&self) -> bool {
        self.updated
    }
}
