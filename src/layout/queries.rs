//! Queries: irradiance, lobes and the SH export of the posterior mean, with their variances.

use super::linalg::project;
use super::*;

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
        let y = zonal_harmonics(n.z);
        times_r(&self.zonal_r, &[q[0] * y[0], q[1] * y[1], q[2] * y[2]])
    }

    /// The zonal part of a lobe's prior variance, `v(n)ᵀR·v(n)`.
    fn zonal_prior(&self, n: Vec3, q: &[f32; 3]) -> f32 {
        let y = zonal_harmonics(n.z);
        let rv = self.zonal_query(n, q);
        q[0] * y[0] * rv[0] + q[1] * y[1] * rv[1] + q[2] * y[2] * rv[2]
    }

    /// The mean basis's irradiance at `n`.
    fn mean_query(&self, n: Vec3) -> f32 {
        if self.mean_terms == 0 {
            return 0.0;
        }
        legendre_sum(&self.basis_query[0], n.z)
    }

    /// Irradiance `E(n) = ∫ L(x)·max(0, n·x) dx` with the direction-averaged posterior
    /// variance (O(K)). [`Error::InvalidDirection`] for a zero or non-finite normal; before
    /// the first update, zero with zero variance.
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
        Ok(Estimate { value, variance: self.average_variance, unit_variance: 1.0 })
    }

    /// The exact posterior variance of [`LayoutProbe::irradiance`] at `normal`, O(K²).
    pub fn irradiance_variance(&self, normal: Vec3) -> Result<T, Error> {
        let n = unit(normal)?;
        let z = self.query_covariances(n);
        let c = cosine_factors_lookup();
        let prior = self.prior_variance + self.zonal_prior(n, &[c[0], c[1], c[2]]);
        Ok(self.exact_variance(&z, self.mean_query(n), prior))
    }

    /// `s·V̄ − s²·z̃ᵀD⁻¹z̃ + RᵀA⁻¹R` per channel for unit-scale query covariances `z`, the
    /// query's mean basis value `h` and unit prior variance `prior`.
    fn exact_variance(&self, z: &[f32; K], h: f32, prior: f32) -> T {
        let zw: [f32; K] = core::array::from_fn(|i| z[i] * self.whitening[i]);
        let zt = project(&self.vectors, &zw);
        from_channels(|ch| {
            let s = self.scale.channel(ch);
            let nu = self.nugget.channel(ch);
            let mut v = s * prior;
            let (mut hz, mut hh) = (0.0f32, 0.0f32);
            for j in 0..K {
                let d = s * self.values[j] + nu;
                if d > 0.0 {
                    v -= s * s * zt[j] * zt[j] / d;
                    if self.mean_terms == 1 {
                        hz += self.basis[0][j] * zt[j] / d;
                        hh += self.basis[0][j] * self.basis[0][j] / d;
                    }
                }
            }
            if self.mean_terms == 1 && hh > 0.0 {
                let r = h - s * hz;
                v += r * r / hh;
            }
            v.max(0.0) * self.variance_scale
        })
    }

    /// The estimate of `∫ L(x)·f(axis·x) dx` for a zonal lobe `f` of Legendre coefficients
    /// `q_l = 2π∫ f(t)·P_l(t) dt`, with its exact posterior variance: O(K·DEGREES + K²).
    fn lobe(&self, axis: Vec3, q: &[f32; DEGREES]) -> Estimate<T> {
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
            legendre_sum(
                &series[self.class[i] as usize % MAX_RESPONSES],
                self.directions[i].dot(axis),
            ) + u[0] * rv[0]
                + u[1] * rv[1]
                + u[2] * rv[2]
        });
        let mean: [f32; 9] = core::array::from_fn(|l| self.profile[l] * q[l]);
        let h = if self.mean_terms == 1 { legendre_sum(&mean, axis.z) } else { 0.0 };
        let prior = (0..DEGREES).map(|l| self.spectrum[l] * q[l] * q[l] * weight(l)).sum::<f32>()
            + self.zonal_prior(axis, &[q[0], q[1], q[2]]);
        let mut value = self.beta[0].scale(h);
        for i in 0..K {
            value = value.mul_add(self.alpha[i], z[i]);
        }
        let variance = self.exact_variance(&z, h, prior);
        Estimate { value, variance, unit_variance: 1.0 }
    }

    /// The normalised Phong average `∫ L(x)·(e + 1)/(2π)·max(0, axis·x)ᵉ dx` (the glossy term
    /// about a mirror direction), with its exact posterior variance, O(K·DEGREES + K²).
    /// [`Error::InvalidDirection`] for a zero or non-finite axis, [`Error::InvalidExponent`]
    /// for an exponent that is negative, not finite or above 4096.
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
        let q = Response::CosinePower(exponent).gains().map_err(|_| Error::InvalidExponent)?;
        Ok(self.lobe(r, &q))
    }

    /// `∫ L(x)·G(x) dx` for a spherical-Gaussian lobe `G` (sharpness at most 4096), with its
    /// exact posterior variance, O(K·DEGREES + K²). [`Error::InvalidSharpness`] for a
    /// sharpness above 4096 (or not finite, or negative), [`Error::InvalidWeights`] for a
    /// non-finite amplitude, [`Error::InvalidDirection`] for a bad axis.
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
        if !(mu.is_finite() && (0.0..=4096.0).contains(&mu)) {
            return Err(Error::InvalidSharpness);
        }
        if !lobe.amplitude.is_finite() {
            return Err(Error::InvalidWeights);
        }
        let mut q = [0.0f32; DEGREES];
        q[0] = 1.0;
        if mu > 0.0 {
            q = Response::Gaussian(mu).gains().map_err(|_| Error::InvalidSharpness)?;
        }
        let total = lobe.integral();
        Ok(self.lobe(r, &q.map(|v| v * total)))
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
        ShL2::new(coefficients)
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
        self.scale
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
