//! Updates: the fit of each channel (REML scale, GLS mean, weights), streams and channel
//! combinations.

use super::linalg::{ldl, ldl_solve, project, refine, LogProduct};
use super::*;

impl<const K: usize, T: Radiance> LayoutProbe<K, T> {
    /// Takes one reading per sensor: any finite value, negative ones included (an
    /// offset-corrected sensor in the dark; module docs), in any units. [`Error::InvalidRadiance`]
    /// for a non-finite reading (the probe keeps its previous state).
    pub fn update(&mut self, readings: &[T; K]) -> Result<(), Error> {
        check_readings(readings)?;
        self.stream_mean = *readings;
        self.stream_exponent = [0; MAX_CHANNELS];
        self.stream_weight = 1.0;
        self.last_change = 0.0;
        self.fit_all(readings, &[0; MAX_CHANNELS], 1.0);
        Ok(())
    }

    /// Pools these readings with the earlier ones of a stream of static light, forgetting
    /// them by the posterior probability that the light changed (soft, partial resets).
    ///
    /// The state is each sensor's weighted mean reading and its weight `w` (the effective
    /// number of updates). Under unchanged light the new readings differ from the means by
    /// the noise, variance `nᵢ·(1 + 1/w)`; under a change by that plus `ψᵢ = 2·(mᵢ² + m̄²)`
    /// (the mean's square and the mean square of all means, per channel). The Bayes factor
    /// of all sensors and channels and the prior odds of a change `h/(1 − h)` (hazard `h`,
    /// [`LayoutProbe::with_hazard`], default 1/64) give the probability `π`; the old means
    /// keep the weight `(1 − π)·w/(1 + π·w)` (the mixture of "changed" and "unchanged"
    /// collapsed with the same mean). The probe then fits the pooled means with noise
    /// `nᵢ/w`: on static light the noise's share of the error falls like `1/√w`. Readings
    /// without noise ([`Noise::NONE`]) repeat exactly on static light, and any change of
    /// more than 10⁻⁵ of a reading resets.
    ///
    /// [`Error::InvalidRadiance`] for a non-finite reading (the state is kept).
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::temporal::Change;
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let noise = Noise { absolute: 0.01, relative: 0.0 };
    /// let mut probe = LayoutProbe::<6>::new(&faces.map(Sensor::cosine), Prior::ENVIRONMENT, noise)?;
    /// let light = [1.0, 1.2, 0.9, 1.1, 2.0, 0.3];
    /// assert_eq!(probe.pool(&light)?, Change::First);
    /// assert_eq!(probe.pool(&light.map(|v| v + 0.004))?, Change::Blended);
    /// assert!(probe.pooled_updates() > 1.9);
    /// // The lamp goes off: every sensor reads half.
    /// assert_eq!(probe.pool(&light.map(|v| 0.5 * v))?, Change::Reset);
    /// assert!(probe.pooled_updates() < 1.1);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn pool(&mut self, readings: &[T; K]) -> Result<Change, Error> {
        check_readings(readings)?;
        let w = self.stream_weight;
        if w <= 0.0 {
            self.stream_mean = *readings;
            self.stream_exponent = [0; MAX_CHANNELS];
            self.stream_weight = 1.0;
            self.last_change = 1.0;
            self.fit_all(readings, &[0; MAX_CHANNELS], 1.0);
            return Ok(Change::First);
        }
        let old = self.stream_exponent;
        // Each channel's new means in units of a power of two near the largest mean or reading.
        let mut exponent = [0i32; MAX_CHANNELS];
        let mut log_bf = 0.0f32;
        // The largest sensor noise, the same for every channel.
        let top_noise = (0..K).fold(0.0f32, |t, i| t.max(self.absolute / self.whitening[i]));
        for ch in 0..T::CHANNELS {
            let old = old[ch.min(MAX_CHANNELS - 1)];
            // In units of a power of two near the largest reading, mean or noise: the
            // decision does not depend on the readings' units.
            let (mut top_mean, mut top_reading) = (0.0f32, 0.0f32);
            for i in 0..K {
                top_mean = top_mean.max(self.stream_mean[i].channel(ch).abs());
                top_reading = top_reading.max(readings[i].channel(ch).abs());
            }
            let data = binade(top_mean).map(|e| e + old).max(binade(top_reading));
            exponent[ch.min(MAX_CHANNELS - 1)] = data.unwrap_or(0);
            let e = data.max(binade(top_noise)).unwrap_or(0);
            let working = |v: f32| libm::scalbnf(v, -e);
            let mean = |i: usize| libm::scalbnf(self.stream_mean[i].channel(ch), old - e);
            let square_mean = (0..K).map(|i| mean(i) * mean(i)).sum::<f32>() / K as f32;
            for i in 0..K {
                let m = mean(i);
                let r = working(readings[i].channel(ch)) - m;
                let a = working(self.absolute / self.whitening[i]);
                let noise = a * a + self.noise.relative * self.noise.relative * m * m;
                // Rounding is not a change.
                let tiny = 1e-5 * m.abs();
                let s0 = noise * (1.0 + 1.0 / w) + tiny * tiny;
                let psi = 2.0 * (m * m + square_mean);
                log_bf += gaussian_log_bf(r * r, 1.0, s0, psi);
            }
        }
        let probability = logistic(log_odds(self.hazard) + log_bf);
        let kept = soft_reset(probability, w);
        let weight = kept + 1.0;
        let (kept_share, new_share) = (kept / weight, 1.0 / weight);
        for (mean, &y) in self.stream_mean.iter_mut().zip(readings) {
            *mean = from_channels(|ch| {
                let (old, new) =
                    (old[ch.min(MAX_CHANNELS - 1)], exponent[ch.min(MAX_CHANNELS - 1)]);
                libm::scalbnf(mean.channel(ch), old - new) * kept_share
                    + libm::scalbnf(y.channel(ch), -new) * new_share
            });
        }
        self.stream_exponent = exponent;
        self.stream_weight = weight;
        self.last_change = probability;
        let pooled = self.stream_mean;
        self.fit_all(&pooled, &exponent, weight);
        Ok(if probability >= 0.5 { Change::Reset } else { Change::Blended })
    }

    /// The effective number of updates pooled by [`LayoutProbe::pool`] (1 after
    /// [`LayoutProbe::update`], 0 before any).
    #[must_use]
    pub const fn pooled_updates(&self) -> f32 {
        self.stream_weight
    }

    /// The posterior probability of a change at the last [`LayoutProbe::pool`].
    #[must_use]
    pub const fn last_change_probability(&self) -> f32 {
        self.last_change
    }

    /// The same probe with hazard `h` (the prior probability of a change per update of
    /// [`LayoutProbe::pool`]), `0 < h < 1`; [`Error::InvalidHazard`] otherwise.
    pub fn with_hazard(mut self, h: f32) -> Result<Self, Error> {
        if !(h > 0.0 && h < 1.0) {
            return Err(Error::InvalidHazard);
        }
        self.hazard = h;
        Ok(self)
    }

    /// The channel combination `Σ_c w_c·value_c` of an estimate of this probe, with the
    /// largest variance that any correlation of the channels' errors allows,
    /// `(Σ_c |w_c|·σ_c)²`: reached when the errors are perfectly correlated (a grey light),
    /// exact for one channel. The same call as [`Probe::combine`](crate::Probe::combine); for
    /// the combination's own posterior variance, fit it as one channel:
    /// [`LayoutProbe::combined_probe`].
    ///
    /// # Errors
    /// [`Error::InvalidWeights`] for a NaN or infinite weight.
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let mut rgb = LayoutProbe::<6, [f32; 3]>::new(&faces.map(Sensor::cosine), Prior::ENVIRONMENT, Noise::NONE)?;
    /// rgb.update(&faces.map(|d| [1.0 + 0.5 * d.z, 0.8 + 0.3 * d.x, 0.6]))?;
    /// let e = rgb.irradiance(Vec3::Z)?;
    /// let y = rgb.combine(&e, [0.2126, 0.7152, 0.0722])?;
    /// let sum = 0.2126 * e.value[0] + 0.7152 * e.value[1] + 0.0722 * e.value[2];
    /// assert!((y.value - sum).abs() < 1e-5 * sum);
    /// // Never below the variance of independent channel errors.
    /// let independent = 0.2126f32.powi(2) * e.variance[0] + 0.7152f32.powi(2) * e.variance[1];
    /// assert!(y.variance >= independent);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn combine(&self, estimate: &Estimate<T>, weights: T) -> Result<Estimate<f32>, Error> {
        crate::estimate::combine_bound(estimate, weights)
    }

    /// A one-channel probe of the combination `Σ_c w_c·Y_c` of this probe's channels
    /// (luminance from RGB readings, say), fitted to the combined (pooled) readings with their
    /// own scale by restricted maximum likelihood and their exact noise: absolute `σ·|w|`,
    /// relative `η²·Σ_c w_c²·Y_c²` per reading. Its queries give the combination with its
    /// posterior variance: the variance of a sum of channels, which the channels' own
    /// variances cannot give (their errors are correlated). Without noise its values are the
    /// combination of the channels' values (the weights do not depend on the scale); with
    /// noise each channel weighs its noise on its own, and the values differ by that.
    ///
    /// Later updates of the returned probe treat its readings as one channel, with noise
    /// `(σ·|w|, η)`. Before any update, the returned probe is not updated either.
    /// [`Error::InvalidWeights`] for non-finite weights, weights all zero, or weights whose
    /// combined readings or noise exceed `f32::MAX`.
    ///
    /// ```
    /// use sphere_quadrature::layout::{LayoutProbe, Noise, Prior, Sensor};
    /// use sphere_quadrature::Vec3;
    ///
    /// let faces = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    /// let mut rgb = LayoutProbe::<6, [f32; 3]>::new(&faces.map(Sensor::cosine), Prior::ENVIRONMENT, Noise::NONE)?;
    /// rgb.update(&faces.map(|d| [1.0 + 0.5 * d.z, 0.8 + 0.3 * d.x, 0.6]))?;
    /// let luminance = rgb.combined_probe([0.2126, 0.7152, 0.0722])?;
    /// let (e, y) = (rgb.irradiance(Vec3::Z)?, luminance.irradiance(Vec3::Z)?);
    /// let sum = 0.2126 * e.value[0] + 0.7152 * e.value[1] + 0.0722 * e.value[2];
    /// assert!((y.value - sum).abs() < 1e-5 * sum);
    /// assert!(y.variance > 0.0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn combined_probe(&self, weights: T) -> Result<LayoutProbe<K, f32>, Error> {
        let channels = T::CHANNELS.min(MAX_CHANNELS);
        let w: [f32; MAX_CHANNELS] =
            core::array::from_fn(|c| if c < channels { weights.channel(c) } else { 0.0 });
        if w.iter().any(|v| !v.is_finite()) || w.iter().all(|&v| v == 0.0) {
            return Err(Error::InvalidWeights);
        }
        let norm = magnitude(&w);
        let noise = Noise { absolute: self.noise.absolute * norm, relative: self.noise.relative };
        let absolute = self.absolute * norm;
        // The combined readings in units of the largest channel's power of two.
        let exponent = self.stream_exponent[..channels].iter().copied().max().unwrap_or(0);
        let terms = |i: usize| -> [f32; MAX_CHANNELS] {
            core::array::from_fn(|c| {
                let mean = self.stream_mean[i].channel(c);
                if c < channels {
                    w[c] * libm::scalbnf(mean, self.stream_exponent[c] - exponent)
                } else {
                    0.0
                }
            })
        };
        let readings: [f32; K] = core::array::from_fn(|i| terms(i)[..channels].iter().sum::<f32>());
        // Finite in the readings' own units too.
        let finite = |v: f32| v.is_finite() && libm::scalbnf(v, exponent).is_finite();
        if readings.iter().any(|&v| !finite(v)) || !absolute.is_finite() {
            return Err(Error::InvalidWeights);
        }
        // The combined reading's relative noise: η·|(w_c·Y_c)_c|.
        let magnitudes: [f32; K] = core::array::from_fn(|i| magnitude(&terms(i)));
        if magnitudes.iter().any(|m| !finite(self.noise.relative * m)) {
            return Err(Error::InvalidWeights);
        }
        let mut probe = LayoutProbe::<K, f32> {
            directions: self.directions,
            whitening: self.whitening,
            class: self.class,
            classes: self.classes,
            scaled: self.scaled,
            gains: self.gains,
            spectrum: self.spectrum,
            zonal_r: self.zonal_r,
            isotropic: self.isotropic,
            zonal_u: self.zonal_u,
            profile: self.profile,
            tables: self.tables,
            covariance: self.covariance,
            vectors: self.vectors,
            values: self.values,
            basis: self.basis,
            basis_sensor: self.basis_sensor,
            log_whitening: self.log_whitening,
            basis_query: self.basis_query,
            mean_terms: self.mean_terms,
            variance_scale: self.variance_scale,
            prior_variance: self.prior_variance,
            average_zz: self.average_zz,
            average_hz: self.average_hz,
            average_hh: self.average_hh,
            noise,
            absolute,
            spectrum_exponent: self.spectrum_exponent,
            rank: self.rank,
            alpha: [0.0; K],
            beta: [0.0; 2],
            unit: 0.0,
            scale: 0.0,
            nugget: 0.0,
            average_variance: 0.0,
            average_unit_variance: 0.0,
            updated: false,
            stream_mean: readings,
            stream_exponent: [exponent; MAX_CHANNELS],
            stream_weight: self.stream_weight,
            hazard: self.hazard,
            log_likelihood: 0.0,
            last_change: self.last_change,
        };
        if self.updated {
            let fit =
                probe.fit(&readings, exponent, self.stream_weight.max(1.0), Some(&magnitudes));
            probe.alpha = fit.alpha;
            probe.beta = [fit.beta, 0.0];
            probe.unit = fit.unit;
            probe.scale = fit.scale;
            probe.nugget = fit.nugget;
            probe.average_variance = fit.average_variance;
            probe.average_unit_variance = fit.average_unit_variance;
            probe.log_likelihood = fit.log_likelihood;
            probe.updated = true;
        }
        Ok(probe)
    }

    /// Fits every channel of these (pooled) readings, whose noise variance is the layout's
    /// divided by `pooled`.
    fn fit_all(&mut self, readings: &[T; K], exponent: &[i32; MAX_CHANNELS], pooled: f32) {
        let mut alpha = [[0.0f32; K]; MAX_CHANNELS];
        let mut beta = [0.0f32; MAX_CHANNELS];
        let mut unit = [0.0f32; MAX_CHANNELS];
        let mut scale = [0.0f32; MAX_CHANNELS];
        let mut nugget = [0.0f32; MAX_CHANNELS];
        let mut average = [0.0f32; MAX_CHANNELS];
        let mut average_unit = [0.0f32; MAX_CHANNELS];
        let mut log_likelihood = 0.0f32;
        for ch in 0..T::CHANNELS.min(MAX_CHANNELS) {
            let y: [f32; K] = core::array::from_fn(|i| readings[i].channel(ch));
            let fit = self.fit(&y, exponent[ch], pooled, None);
            alpha[ch] = fit.alpha;
            beta[ch] = fit.beta;
            unit[ch] = fit.unit;
            scale[ch] = fit.scale;
            nugget[ch] = fit.nugget;
            average[ch] = fit.average_variance;
            average_unit[ch] = fit.average_unit_variance;
            log_likelihood += fit.log_likelihood;
        }
        self.log_likelihood = log_likelihood;
        self.alpha =
            core::array::from_fn(|i| from_channels(|ch| alpha[ch.min(MAX_CHANNELS - 1)][i]));
        self.beta = [from_channels(|ch| beta[ch.min(MAX_CHANNELS - 1)]), T::ZERO];
        self.unit = from_channels(|ch| unit[ch.min(MAX_CHANNELS - 1)]);
        self.scale = from_channels(|ch| scale[ch.min(MAX_CHANNELS - 1)]);
        self.nugget = from_channels(|ch| nugget[ch.min(MAX_CHANNELS - 1)]);
        self.average_variance = from_channels(|ch| average[ch.min(MAX_CHANNELS - 1)]);
        self.average_unit_variance = from_channels(|ch| average_unit[ch.min(MAX_CHANNELS - 1)]);
        self.updated = true;
    }

    /// One channel's fit of readings `y` in units of `2^exponent`. `magnitude`: each reading's
    /// size (same units) for the relative noise (its variance `η²·mᵢ²`, before pooling) where
    /// it is not `|yᵢ|` (a combination of channels).
    fn fit(
        &self,
        y: &[f32; K],
        exponent: i32,
        pooled: f32,
        magnitude: Option<&[f32; K]>,
    ) -> Fit<K> {
        let Some(units) = self.working_unit(y, exponent, magnitude) else {
            // Every reading 0 without noise: an exact fit of zero.
            return Fit {
                alpha: [0.0; K],
                beta: 0.0,
                unit: 1.0,
                scale: 0.0,
                nugget: 0.0,
                average_variance: 0.0,
                average_unit_variance: self.unit_average(0.0, 0.0),
                log_likelihood: f32::INFINITY,
            };
        };
        let yw: [f32; K] = core::array::from_fn(|i| units.of_readings(y[i] * self.whitening[i]));
        let z = project(&self.vectors, &yw);
        let nus = self.noise_variances(&units, &yw, pooled, magnitude);
        let per_reading = self.noise.relative * self.noise.relative / pooled > 0.0;
        let nu = nus.iter().sum::<f32>() / K as f32;
        let p = self.mean_terms;
        let h = &self.basis[0];
        let noiseless = self.noiseless_scale(&z);
        let s = if nu == 0.0 { noiseless } else { self.reml_scale(&z, nu, noiseless) };
        let d: [f32; K] = core::array::from_fn(|j| s * self.values[j] + nu);
        let (objective, beta, _) = if s > 0.0 || nu > 0.0 {
            self.reml_objective(&z, s, nu)
        } else {
            (
                f32::INFINITY,
                if p == 1 && h.iter().any(|&v| v != 0.0) { gls_exact(h, &z) } else { 0.0 },
                0.0,
            )
        };
        // Of the readings themselves: undo the working unit (each d_j scales by unit², A by
        // 1/unit²) and the whitening.
        let log_likelihood =
            objective - (K - p) as f32 * math::ln(units.unit) + self.log_whitening.ln();
        // Relative noise differs between sensors: the mean and the weights from the exact
        // system s·C̃ + diag(ν_i) (the scale and the variances keep ν̄); otherwise in the
        // eigenbasis, r̃ = z − H̃ᵀβ and the weights V·D⁻¹r̃.
        let exact = if per_reading && s > 0.0 { self.exact_weights(&yw, &nus, s) } else { None };
        let (weights, beta) = match exact {
            Some((w, exact_beta)) => (w, exact_beta.unwrap_or(beta)),
            None => {
                let r: [f32; K] = core::array::from_fn(|j| {
                    let rj = z[j] - if p == 1 { h[j] * beta } else { 0.0 };
                    if d[j] > 0.0 {
                        rj / d[j]
                    } else {
                        0.0
                    }
                });
                let weights = core::array::from_fn(|i| {
                    let mut acc = 0.0f32;
                    for j in 0..K {
                        acc += self.vectors[i][j] * r[j];
                    }
                    acc
                });
                (weights, beta)
            }
        };
        // α (sensor space) = s·W·weights.
        let mut alpha = [0.0f32; K];
        for i in 0..K {
            alpha[i] = s * self.whitening[i] * weights[i];
        }
        // Direction-averaged variance, s·(unit variance), in working units.
        let average_unit = self.unit_average(s, nu);
        let average = s * average_unit + self.average_mean_noise(s, nu);
        Fit {
            alpha,
            beta,
            unit: units.unit,
            scale: s,
            nugget: nu,
            average_variance: math::ldexp_variance(
                average.max(0.0) * self.variance_scale,
                2 * units.e,
            ),
            average_unit_variance: math::ldexp_variance(
                average_unit.max(0.0) * self.variance_scale,
                self.spectrum_exponent,
            ),
            log_likelihood,
        }
    }

    /// The working unit: a power of two 2ᵉ near the largest whitened reading (or the absolute
    /// noise, if larger), relative to which every statistic of the fit is free of the units;
    /// `None` for readings all 0 without noise.
    fn working_unit(
        &self,
        y: &[f32; K],
        exponent: i32,
        magnitude: Option<&[f32; K]>,
    ) -> Option<WorkingUnit> {
        let mut top = 0.0f32;
        for i in 0..K {
            top = top.max(y[i].abs() * self.whitening[i]);
        }
        // A combination's relative noise may dwarf its readings (channels that cancel): the
        // unit covers it too, so that the noise stays within f32 in working units.
        if let Some(m) = magnitude {
            for i in 0..K {
                top = top.max((self.noise.relative * m[i] * self.whitening[i]).min(f32::MAX));
            }
        }
        let e = binade(top).map(|e| e + exponent).max(binade(self.absolute))?;
        let e = e.clamp(-149, 127);
        // 2ᵉ and 2⁻ᵉ are normal numbers for every e but the subnormal range's.
        let (unit, inv) = if e >= -126 {
            let unit = libm::scalbnf(1.0, e);
            (unit, 1.0 / unit)
        } else {
            (libm::scalbnf(1.0, e), 0.0)
        };
        Some(WorkingUnit { e, unit, inv, exponent })
    }

    /// Whitened noise variances in working units, `νᵢ = σ² + η²·(mᵢ/wᵢ)²`, divided by `pooled`.
    fn noise_variances(
        &self,
        units: &WorkingUnit,
        yw: &[f32; K],
        pooled: f32,
        magnitude: Option<&[f32; K]>,
    ) -> [f32; K] {
        let sigma = units.of(self.absolute);
        let absolute = sigma * sigma / pooled;
        let eta = self.noise.relative;
        let eta2 = eta * eta / pooled;
        match magnitude {
            None => core::array::from_fn(|i| absolute + eta2 * yw[i] * yw[i]),
            Some(m) => core::array::from_fn(|i| {
                // η first: η·mᵢ is within the unit, mᵢ alone may not be (or η = 0, ∞·0).
                let r = units.of_readings(eta * (m[i] * self.whitening[i]));
                absolute + r * r / pooled
            }),
        }
    }

    /// The REML objective at scale `s` and mean noise `ν` for the projected readings `z`:
    /// (objective, GLS mean β, `A = hᵀD⁻¹h`).
    fn reml_objective(&self, z: &[f32; K], s: f32, nu: f32) -> (f32, f32, f32) {
        let (p, h, lam) = (self.mean_terms, &self.basis[0], &self.values);
        let mut product = LogProduct::ONE;
        let (mut zz, mut hz, mut hh) = (0.0f32, 0.0f32, 0.0f32);
        for j in 0..K {
            let d = s * lam[j] + nu;
            product = product.times(d);
            zz += z[j] * z[j] / d;
            if p == 1 {
                hz += h[j] * z[j] / d;
                hh += h[j] * h[j] / d;
            }
        }
        let logdet = product.ln();
        if p == 1 && hh > 0.0 {
            let beta = hz / hh;
            (-0.5 * (logdet + math::ln(hh) + zz - hz * beta), beta, hh)
        } else {
            (-0.5 * (logdet + zz), 0.0, hh)
        }
    }

    /// The scale without noise, the closed form `s = r̃ᵀΛ⁻¹r̃/(K − p)`; with noise, where the
    /// search starts.
    fn noiseless_scale(&self, z: &[f32; K]) -> f32 {
        let (p, h, lam) = (self.mean_terms, &self.basis[0], &self.values);
        let (mut zz, mut hz, mut hh) = (0.0f32, 0.0f32, 0.0f32);
        for j in 0..K {
            let inv = 1.0 / lam[j];
            zz += z[j] * z[j] * inv;
            if p == 1 {
                hz += h[j] * z[j] * inv;
                hh += h[j] * h[j] * inv;
            }
        }
        // The residual after the mean is a difference known to rounding, ε·r̃ᵀΛ⁻¹r̃ before
        // the mean: readings that fit the mean exactly leave s at that level, not 0.
        let q = if p == 1 && hh > 0.0 { zz - hz * hz / hh } else { zz };
        let q = q.max(f32::EPSILON * zz);
        // Degrees of freedom: the rank, not K (a duplicate sensor's copy says nothing new).
        (q / self.rank.saturating_sub(p).max(1) as f32).max(0.0)
    }

    /// The REML score `s·dℓ/ds` at `s` with every `1/d_j` taken as `c/d_j` (`c` the least
    /// `d_j`, or 1 where the plain sums stay finite): `s·g·c²` has the sign of `s·dℓ/ds`, and
    /// readings far above a tiny noise (`1/d` near `1/ν`) no longer overflow its sums to
    /// `∞ − ∞`. No logarithms, O(K).
    fn reml_score(&self, z: &[f32; K], nu: f32, s: f32, c: f32) -> f32 {
        let (p, h, lam) = (self.mean_terms, &self.basis[0], &self.values);
        let (mut tr, mut zz1, mut a, mut b, mut a1, mut b1) =
            (0.0f32, 0.0f32, 0.0f32, 0.0f32, 0.0f32, 0.0f32);
        for j in 0..K {
            let inv = c / (s * lam[j] + nu);
            let l_inv = lam[j] * inv;
            tr += l_inv;
            zz1 += z[j] * z[j] * l_inv * inv;
            if p == 1 {
                a += h[j] * h[j] * inv;
                b += h[j] * z[j] * inv;
                a1 += h[j] * h[j] * l_inv * inv;
                b1 += h[j] * z[j] * l_inv * inv;
            }
        }
        // dℓ/ds = −½·(Σ λ/d − A′/A·(−1)… ): with A′ = −a1, b′ = −b1,
        // Q = Σ z²/d − b²/A, Q′ = −zz1 + (2b·b1·A − b²·a1)/A², taken through the GLS
        // mean t = b/A (A and b reach 1/ν where the mean's direction has no prior
        // variance: A² and b² would overflow for readings far above the noise).
        // With the factor c: g·c² = (−tr + a1/a)·c + zz1 − 2t·b1 + t²·a1.
        let mut linear = -tr;
        let mut square = zz1;
        if p == 1 && a > 0.0 {
            let t = b / a;
            linear += a1 / a;
            square += t * t * a1 - 2.0 * t * b1;
        }
        0.5 * s * (linear * c + square)
    }

    /// The scale with noise `ν > 0`: the root of the REML score in `u = ln s` by the Illinois
    /// variant of regula falsi, from a bracket about the noiseless scale.
    fn reml_scale(&self, z: &[f32; K], nu: f32, noiseless: f32) -> f32 {
        let lam = &self.values;
        let score = |u: f32| -> f32 {
            #[cfg(test)]
            SCORES.with(|c| c.set(c.get() + 1));
            let s = math::exp_accurate(u);
            let plain = self.reml_score(z, nu, s, 1.0);
            if plain.is_finite() {
                return plain;
            }
            let least = lam.iter().fold(f32::INFINITY, |c, &l| c.min(s * l + nu));
            self.reml_score(z, nu, s, least)
        };
        // Noise only lowers the scale: a bracket just below the noiseless one first, and
        // the wide one about the readings' spread where that fails.
        let spread = z.iter().map(|v| v * v).sum::<f32>() / lam.iter().sum::<f32>();
        let centre = math::ln(spread.max(nu * 1e-6).max(1e-30));
        let start = math::ln(noiseless.max(nu * 1e-6).max(1e-30));
        let (mut lo, mut hi) = (start - 3.0, start + 0.5);
        let (mut f_lo, mut f_hi) = (score(lo), score(hi));
        if f_lo <= 0.0 {
            (hi, f_hi) = (lo, f_lo);
            lo = hi.min(centre) - 14.0;
            f_lo = score(lo);
        } else if f_hi >= 0.0 {
            (lo, f_lo) = (hi, f_hi);
            hi = lo.max(centre) + 6.0;
            f_hi = score(hi);
        }
        let u = if f_lo <= 0.0 {
            lo
        } else if f_hi >= 0.0 {
            hi
        } else {
            illinois(score, (lo, f_lo), (hi, f_hi))
        };
        math::exp_accurate(u)
    }

    /// With a relative noise: the weights `Q(y − βh)` and, with a mean term, the GLS mean
    /// `β = hᵀQy/hᵀQh` of the exact system `Q = (s·C̃ + diag νᵢ)⁻¹`, factored once and each
    /// solve refined once; `None` where the factorization fails.
    fn exact_weights(
        &self,
        yw: &[f32; K],
        nus: &[f32; K],
        s: f32,
    ) -> Option<([f32; K], Option<f32>)> {
        let h_sensor = &self.basis_sensor;
        // The lower triangle is all the factorization reads; the covariance holds the
        // model's floor already (`init::lift_floored`).
        let mut a = [[0.0f32; K]; K];
        for (i, (row, cov)) in a.iter_mut().zip(&self.covariance).enumerate() {
            for (x, c) in row[..=i].iter_mut().zip(cov) {
                *x = s * c;
            }
            row[i] += nus[i];
        }
        let mut inverse = [0.0f32; K];
        if !ldl(&mut a, &mut inverse) {
            return None;
        }
        let solve = |b: &[f32; K]| {
            let x = ldl_solve(&a, &inverse, b);
            refine(&self.covariance, s, nus, (&a, &inverse), b, &x)
        };
        let mut weights = solve(yw);
        let mut beta = None;
        if self.mean_terms == 1 {
            let qh = solve(h_sensor);
            let hqh: f32 = h_sensor.iter().zip(&qh).map(|(x, q)| x * q).sum();
            if hqh > 0.0 {
                let b = h_sensor.iter().zip(&weights).map(|(x, q)| x * q).sum::<f32>() / hqh;
                for i in 0..K {
                    weights[i] -= b * qh[i];
                }
                beta = Some(b);
            }
        }
        Some((weights, beta))
    }

    /// The direction average of the posterior variance for `s = 1` at the noise ratio `ν/s`
    /// (`ν/s = 0` without noise): `V̄ − Σ_j M̃_jj·q_j + avg[r²]/Σ h̃_j²q_j`, `q_j = 1/(λ_j + ν/s)`,
    /// `r(n) = h(n) − Σ_j h̃_j·z̃_j(n)·q_j`. (`s = 0` with noise: the mean's part alone is
    /// unbounded; [`Self::average_mean_noise`] has it in absolute terms.)
    fn unit_average(&self, s: f32, nu: f32) -> f32 {
        let q = self.noise_ratio_weights(s, nu);
        let mut average = self.prior_variance;
        for j in 0..K {
            average -= self.average_zz[j][j] * q[j];
        }
        // Resolved to rounding, of the order of ε·V̄ (as the exact variances).
        average = average.max(f32::EPSILON / 16.0 * self.prior_variance);
        if self.mean_terms == 1 {
            let (r2, hh) = self.average_residual(&q);
            if hh > 0.0 {
                average += r2.max(0.0) / hh;
            }
        }
        average
    }

    /// `q_j = s/(s·λ_j + ν) = 1/(λ_j + ν/s)` (`1/λ_j` without noise, whatever `s`; 0 where
    /// `s = 0 < ν`): a function of the noise ratio alone, so that it does not move with the
    /// rounding of `s`.
    pub(super) fn noise_ratio_weights(&self, s: f32, nu: f32) -> [f32; K] {
        let ratio = if nu == 0.0 {
            0.0
        } else if s > 0.0 {
            nu / s
        } else {
            f32::INFINITY
        };
        core::array::from_fn(|j| 1.0 / (self.values[j] + ratio))
    }

    /// `(avg[r(n)²], Σ h̃_j²·q_j)` for the mean's residual `r(n) = h(n) − Σ_j h̃_j q_j z̃_j(n)`.
    fn average_residual(&self, q: &[f32; K]) -> (f32, f32) {
        let h = &self.basis[0];
        let hq: [f32; K] = core::array::from_fn(|j| h[j] * q[j]);
        let hzq = &self.average_hz[0];
        let (mut cross, mut quad, mut hh) = (0.0f32, 0.0f32, 0.0f32);
        for j in 0..K {
            hh += h[j] * hq[j];
            cross += hq[j] * hzq[j];
            let mut row = 0.0f32;
            for k in 0..K {
                row += self.average_zz[j][k] * hq[k];
            }
            quad += hq[j] * row;
        }
        (self.average_hh[0][0] - 2.0 * cross + quad, hh)
    }

    /// The mean's share of the averaged variance where `s = 0 < ν` (the readings are all
    /// noise): `avg[h²]·ν/Σ h̃_j²`; 0 otherwise (it is in `s`·unit variance).
    fn average_mean_noise(&self, s: f32, nu: f32) -> f32 {
        if self.mean_terms == 1 && s == 0.0 && nu > 0.0 {
            let hh: f32 = self.basis[0].iter().map(|h| h * h).sum();
            if hh > 0.0 {
                return self.average_hh[0][0] * nu / hh;
            }
        }
        0.0
    }
}

#[cfg(test)]
extern crate std;
#[cfg(test)]
std::thread_local! {
    /// Calls of the REML score (a cost measure for the tests).
    pub(super) static SCORES: core::cell::Cell<usize> = const { core::cell::Cell::new(0) };
}

/// A fit's working unit `2ᵉ`, and the readings' unit `2^exponent`.
struct WorkingUnit {
    e: i32,
    unit: f32,
    /// `2⁻ᵉ`, or 0 where it is not a normal number.
    inv: f32,
    exponent: i32,
}

impl WorkingUnit {
    /// A value in working units.
    fn of(&self, v: f32) -> f32 {
        if self.inv != 0.0 {
            v * self.inv
        } else {
            libm::scalbnf(v, -self.e)
        }
    }

    /// A value in the readings' units, in working units (exactly [`Self::of`] for exponent 0).
    fn of_readings(&self, v: f32) -> f32 {
        if self.exponent == 0 {
            self.of(v)
        } else {
            libm::scalbnf(v, self.exponent - self.e)
        }
    }
}

/// The root of `f` in `[lo, hi]` (`f(lo) > 0 > f(hi)`) by the Illinois variant of regula
/// falsi, to f32 resolution: the bracket within a few ulps of the root, or a step that no
/// longer moves it (a looser stop made the scale, and through it the values, jump with the
/// rounding of the readings); at most 24 steps.
fn illinois(
    f: impl Fn(f32) -> f32,
    (mut lo, mut f_lo): (f32, f32),
    (mut hi, mut f_hi): (f32, f32),
) -> f32 {
    let mut side = 0i8;
    let mut u = 0.5 * (lo + hi);
    for _ in 0..24 {
        let previous = u;
        u = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
        let fu = f(u);
        if fu > 0.0 {
            lo = u;
            f_lo = fu;
            if side == 1 {
                f_hi *= 0.5;
            }
            side = 1;
        } else {
            hi = u;
            f_hi = fu;
            if side == -1 {
                f_lo *= 0.5;
            }
            side = -1;
        }
        let ulps = 4.0 * f32::EPSILON * (1.0 + math::abs(u));
        if hi - lo < ulps || (u - previous).abs() < ulps || fu == 0.0 {
            break;
        }
    }
    u
}

struct Fit<const K: usize> {
    alpha: [f32; K],
    beta: f32,
    unit: f32,
    average_unit_variance: f32,
    scale: f32,
    nugget: f32,
    average_variance: f32,
    log_likelihood: f32,
}

/// β by least squares when `s = ν = 0` (all readings equal to the mean): `hᵀz/hᵀh`.
fn gls_exact<const K: usize>(h: &[f32; K], z: &[f32; K]) -> f32 {
    let hh: f32 = h.iter().map(|v| v * v).sum();
    let hz: f32 = h.iter().zip(z).map(|(a, b)| a * b).sum();
    if hh > 0.0 {
        hz / hh
    } else {
        0.0
    }
}

/// `|v|` without overflow or underflow in the squares (`+∞` where it exceeds `f32::MAX`).
fn magnitude(v: &[f32; MAX_CHANNELS]) -> f32 {
    let plain: f32 = v.iter().map(|x| x * x).sum();
    if plain >= f32::MIN_POSITIVE && plain.is_finite() {
        return math::sqrt(plain);
    }
    let top = v.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    if top == 0.0 || !top.is_finite() {
        return top;
    }
    let e = libm::ilogbf(top);
    let sum: f32 = v.iter().map(|x| libm::scalbnf(*x, -e)).map(|x| x * x).sum();
    libm::scalbnf(math::sqrt(sum), e)
}

/// `⌊log₂ x⌋` of a positive, finite `x` (subnormals included), `None` otherwise.
fn binade(x: f32) -> Option<i32> {
    (x > 0.0 && x.is_finite()).then(|| math::binade(x))
}

fn check_readings<T: Radiance, const K: usize>(readings: &[T; K]) -> Result<(), Error> {
    for r in readings {
        for ch in 0..T::CHANNELS {
            if !r.channel(ch).is_finite() {
                return Err(Error::InvalidRadiance);
            }
        }
    }
    Ok(())
}
