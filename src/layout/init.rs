//! `LayoutProbe::new`: the tables of a layout, at run time or by the compiler.

use super::linalg::{congruence, congruence_diagonal, project, symmetric_eigen, LogProduct};
use super::*;

impl<const K: usize, T: Radiance> LayoutProbe<K, T> {
    /// Builds the probe's tables for these sensors, prior and noise: O(K³), no allocation.
    ///
    /// Errors:
    /// - [`Error::InvalidSize`]: `K = 0`, `K > MAX_SENSORS`, or `K` not above the number of
    ///   mean terms (a constant or zonal mean needs two sensors);
    /// - [`Error::InvalidDirection`]: a zero or non-finite direction;
    /// - [`Error::InvalidResponse`]: a response out of range, or more than [`MAX_RESPONSES`]
    ///   distinct responses;
    /// - [`Error::InvalidNoise`]: a noise scale that is not finite and positive, noise that
    ///   is not finite and non-negative, a relative noise above [`MAX_RELATIVE_NOISE`], or,
    ///   with an absolute noise, noise scales that differ by more than
    ///   [`MAX_NOISE_SCALE_RATIO`] or an absolute noise whose product with the least noise
    ///   scale exceeds `f32::MAX` (to within a factor 2: that scale rounded down to a power of
    ///   two);
    /// - [`Error::InvalidPrior`]: a spectrum (finite, non-negative, not all zero), variance
    ///   scale, zonal covariance or mean profile out of range, or a covariance the sensors
    ///   barely see: the largest eigenvalue of their covariance (divided by the squared
    ///   noise scales, relative to the least) below 2⁻⁶⁰ of the spectrum's largest `K_l`
    ///   (a spectrum of degrees ≥ 1 alone for responses that see little but the level: a
    ///   `Gaussian` of sharpness below about 10⁻⁸), or a zonal mean the sensors do not see:
    ///   its basis `Σ_l a_l·g_l·P_l(dᵢ·z)` below 2⁻⁸⁹ of the profile's largest `|a_l|` at
    ///   every sensor, zero included (degrees their responses do not see: odd degrees from 3
    ///   for cosine sensors, or sensors where those degrees' `P_l` vanish), which leaves its
    ///   multiple undetermined.
    ///
    /// Sensors that see (almost) only the level under a prior whose level dwarfs the rest are
    /// accepted: where the level taken in its limit (module docs) would leave them a
    /// covariance they barely see, the prior is kept as given, the level a random effect of
    /// variance `s·K₀`.
    ///
    /// A radiance type of more than [`MAX_CHANNELS`] channels
    /// does not compile.
    ///
    /// Readings that the prior makes linearly dependent are fine: two sensors with the same
    /// direction and response, or the antipodal pairs of cosine sensors (their differences
    /// see degree 1 only). The model's least noise, `10⁻⁶` of the largest eigenvalue of the
    /// whitened covariance, keeps the system solvable, and duplicates are averaged: without
    /// noise, sixteen sensors that are eight copies each of two give the answers and the
    /// error bars of the two (their copies add no degrees of freedom to the scale's fit).
    pub const fn new(sensors: &[Sensor; K], prior: Prior, noise: Noise) -> Result<Self, Error> {
        // One call site (no second copy of the code in flash).
        let mut limit = true;
        loop {
            match Self::build(sensors, prior, noise, limit) {
                // The level taken in its limit left a covariance the sensors barely see
                // (responses that see little but the level): the prior as given, the level a
                // random effect.
                Err(Error::InvalidPrior) if limit => limit = false,
                result => return result,
            }
        }
    }

    /// [`LayoutProbe::new`], a dominant level taken in its limit where `limit` allows.
    const fn build(
        sensors: &[Sensor; K],
        prior: Prior,
        noise: Noise,
        limit: bool,
    ) -> Result<Self, Error> {
        let () = crate::radiance::Channels::<T>::VALID;
        let mean_terms = match prior.mean {
            Mean::Zero => 0,
            _ => 1,
        };
        if K == 0 || K > MAX_SENSORS || K <= mean_terms {
            return Err(Error::InvalidSize);
        }
        if !non_negative(noise.absolute)
            || !non_negative(noise.relative)
            || noise.relative > MAX_RELATIVE_NOISE
        {
            return Err(Error::InvalidNoise);
        }
        let model = match Model::new(&prior, limit, K) {
            Ok(m) => m,
            Err(e) => return Err(e),
        };
        let (whitening, absolute) = match whitening(sensors, noise) {
            Ok(w) => w,
            Err(e) => return Err(e),
        };
        let seen = match Seen::new(sensors, whitening, &model.zonal_r) {
            Ok(s) => s,
            Err(e) => return Err(e),
        };
        let (cov, zz) = whitened_covariances(&seen, &model.spectrum);
        let eigen = match Eigen::floored(cov, model.largest, model.spectrum_exponent) {
            Ok(e) => e,
            Err(e) => return Err(e),
        };
        let average_zz =
            average_products(&seen, &model.spectrum, &eigen.vectors, &zz, model.mean_terms);
        let mut profile = model.profile;
        let mean = if model.mean_terms == 1 {
            match MeanBasis::new(&seen, &model.spectrum, &mut profile, &eigen.vectors) {
                Ok(m) => m,
                Err(e) => return Err(e),
            }
        } else {
            MeanBasis::NONE
        };
        Ok(LayoutProbe {
            directions: seen.directions,
            whitening: seen.whitening,
            class: seen.class,
            classes: seen.classes,
            scaled: scaled_directions(&seen.directions),
            gains: seen.gains,
            spectrum: model.spectrum,
            zonal_r: model.zonal_r,
            isotropic: model.isotropic,
            zonal_u: seen.zonal_u,
            profile,
            tables: query_tables(&seen, &model.spectrum),
            covariance: eigen.covariance,
            vectors: eigen.vectors,
            values: eigen.values,
            basis: mean.basis,
            basis_sensor: mean.basis_sensor,
            log_whitening: log_product(&seen.whitening),
            basis_query: mean.basis_query,
            mean_terms: model.mean_terms,
            prior_variance: prior_variance(&model.spectrum),
            average_zz,
            average_hz: mean.average_hz,
            average_hh: mean.average_hh,
            noise,
            absolute,
            spectrum_exponent: model.spectrum_exponent,
            rank: eigen.rank,
            variance_scale: model.variance_scale,
            alpha: [T::ZERO; K],
            beta: [T::ZERO; 2],
            unit: T::ZERO,
            scale: T::ZERO,
            nugget: T::ZERO,
            average_variance: T::ZERO,
            average_unit_variance: T::ZERO,
            updated: false,
            stream_mean: [T::ZERO; K],
            stream_exponent: [0; MAX_CHANNELS],
            stream_weight: 0.0,
            hazard: DEFAULT_HAZARD,
            last_change: 0.0,
            log_likelihood: 0.0,
        })
    }
}

/// The prior as the probe holds it: spectrum, mean, zonal covariances, checked.
struct Model {
    /// `K_l` times `2^−spectrum_exponent`.
    spectrum: [f32; DEGREES],
    spectrum_exponent: i32,
    /// The largest `K_l` as the prior gives it (before the power of two).
    largest: f32,
    /// 0 or 1.
    mean_terms: usize,
    /// The mean's profile `a_l` (0 without a mean), near 1 by a power of two.
    profile: [f32; 9],
    variance_scale: f32,
    /// The zonal covariances `R` (zero diagonal), scaled with the spectrum.
    zonal_r: [[f32; 3]; 3],
    isotropic: bool,
}

impl Model {
    /// The prior's spectrum and mean for `sensors` sensors, the level taken in its limit where
    /// `limit` allows and it dwarfs the rest; [`Error::InvalidPrior`] for any part out of range.
    #[inline(never)]
    const fn new(prior: &Prior, limit: bool, sensors: usize) -> Result<Self, Error> {
        let mut spectrum = prior.spectrum;
        let mut any = false;
        let mut l = 0;
        while l < DEGREES {
            if !non_negative(spectrum[l]) {
                return Err(Error::InvalidPrior);
            }
            any |= spectrum[l] > 0.0;
            l += 1;
        }
        if !any {
            return Err(Error::InvalidPrior);
        }
        // A level whose prior variance dwarfs the rest's (K₀ above 2⁸ times every other K_l,
        // uncorrelated with them) is taken in its limit, an unknown constant fitted by
        // generalised least squares: f32 would hold the rest beside it less well than the limit
        // approximates it (measured on a cube: within 8.3·10⁻⁶ of the largest value either
        // side of the switch; the proper prior in f32 erred by 14 % at K₀ = 10⁶·K₁).
        let mut mean = prior.mean;
        let mut mean_terms = match prior.mean {
            Mean::Zero => 0,
            _ => 1,
        };
        let mut rest = 0.0f32;
        let mut l = 1;
        while l < DEGREES {
            if spectrum[l] > rest {
                rest = spectrum[l];
            }
            l += 1;
        }
        if limit
            && matches!(mean, Mean::Zero)
            && sensors >= 2
            && prior.zonal[0] == 0.0
            && prior.zonal[2] == 0.0
            && rest > 0.0
            && spectrum[0] > 256.0 * rest
        {
            spectrum[0] = 0.0;
            mean = Mean::Constant;
            mean_terms = 1;
        }
        // A spectrum far from 1 is brought near it by a power of two (exact), which the
        // scale s takes back: the model is the same, and no product of spectra overflows.
        let mut largest = 0.0f32;
        let mut l = 0;
        while l < DEGREES {
            if spectrum[l] > largest {
                largest = spectrum[l];
            }
            l += 1;
        }
        let spectrum_exponent = near_one(largest);
        let mut l = 0;
        while l < DEGREES {
            spectrum[l] = times_power_of_two(spectrum[l], -spectrum_exponent);
            l += 1;
        }
        let variance_scale = prior.variance_scale;
        if !(variance_scale.is_finite() && variance_scale > 0.0) {
            return Err(Error::InvalidPrior);
        }
        let zonal_r = match zonal_covariances(prior.zonal, &spectrum, spectrum_exponent) {
            Ok(r) => r,
            Err(e) => return Err(e),
        };
        let profile = match profile(mean) {
            Ok(p) => p,
            Err(e) => return Err(e),
        };
        Ok(Model {
            spectrum,
            spectrum_exponent,
            largest,
            mean_terms,
            profile,
            variance_scale,
            zonal_r,
            isotropic: zonal_r[0][1] == 0.0 && zonal_r[1][2] == 0.0 && zonal_r[0][2] == 0.0,
        })
    }
}

/// The exponent `e` that brings `x` near 1 by `2^−e`: 0 within `2^±20`.
const fn near_one(x: f32) -> i32 {
    if x > 1_048_576.0 || x < 1.0 / 1_048_576.0 {
        exponent_of(x)
    } else {
        0
    }
}

/// The zonal covariances `R` (zero diagonal) of the prior's `[R₀₁, R₁₂, R₀₂]`, scaled by
/// `2^−exponent` like the spectrum; [`Error::InvalidPrior`] unless they are finite and, with
/// `K₀, K₁, K₂`, a positive semi-definite 3×3 matrix.
const fn zonal_covariances(
    zonal: [f32; 3],
    spectrum: &[f32; DEGREES],
    exponent: i32,
) -> Result<[[f32; 3]; 3], Error> {
    let [z01, z12, z02] = zonal;
    if !(z01.is_finite() && z12.is_finite() && z02.is_finite()) {
        return Err(Error::InvalidPrior);
    }
    let (z01, z12, z02) = (
        times_power_of_two(z01, -exponent),
        times_power_of_two(z12, -exponent),
        times_power_of_two(z02, -exponent),
    );
    let zonal_r = [[0.0, z01, z02], [z01, 0.0, z12], [z02, z12, 0.0]];
    let (k0, k1, k2) = (spectrum[0] as f64, spectrum[1] as f64, spectrum[2] as f64);
    let (z01, z12, z02) = (z01 as f64, z12 as f64, z02 as f64);
    let minor = k0 * k1 - z01 * z01;
    let det =
        k0 * (k1 * k2 - z12 * z12) - z01 * (z01 * k2 - z12 * z02) + z02 * (z01 * z12 - k1 * z02);
    let tolerance = 1e-6 * (k0 * k1 * k2 + k0 * k1 + 1e-30);
    if minor < -1e-6 * (k0 * k1 + 1e-30) || det < -tolerance || k0 * k2 - z02 * z02 < 0.0 {
        return Err(Error::InvalidPrior);
    }
    Ok(zonal_r)
}

/// The mean's profile `a_l`: 0 without a mean, 1 at degree 0 for a constant, a zonal
/// profile brought near 1 by a power of two (only its shape matters: its multiple is fitted);
/// [`Error::InvalidPrior`] for a non-finite or all-zero zonal profile.
const fn profile(mean: Mean) -> Result<[f32; 9], Error> {
    let mut profile = [0.0f32; 9];
    match mean {
        Mean::Zero => {}
        Mean::Constant => profile[0] = 1.0,
        Mean::Zonal(p) => {
            let mut any = false;
            let mut largest = 0.0f32;
            let mut l = 0;
            while l < 9 {
                if !p[l].is_finite() {
                    return Err(Error::InvalidPrior);
                }
                any |= p[l] != 0.0;
                if absolute(p[l]) > largest {
                    largest = absolute(p[l]);
                }
                l += 1;
            }
            if !any {
                return Err(Error::InvalidPrior);
            }
            // No product of its coefficients overflows or underflows.
            let e = near_one(largest);
            let mut l = 0;
            while l < 9 {
                profile[l] = times_power_of_two(p[l], -e);
                l += 1;
            }
        }
    }
    Ok(profile)
}

/// Each sensor's whitening and the whitened absolute noise. Noise scales: only their ratios
/// and the absolute noise matter. Without an absolute noise they have no effect (whitening by
/// 1); with one, the whitening is 2ᵏ/wᵢ ≤ 1 for the power of two 2ᵏ ≤ the least wᵢ, and the
/// whitened absolute noise is σ·2ᵏ. [`Error::InvalidNoise`] for a scale that is not finite and
/// positive, scales that differ by more than [`MAX_NOISE_SCALE_RATIO`], or `σ·2ᵏ` beyond f32.
#[inline(never)]
const fn whitening<const K: usize>(
    sensors: &[Sensor; K],
    noise: Noise,
) -> Result<([f32; K], f32), Error> {
    let (mut least, mut most) = (f32::MAX, 0.0f32);
    let mut i = 0;
    while i < K {
        let w = sensors[i].noise_scale;
        if !(w.is_finite() && w > 0.0) {
            return Err(Error::InvalidNoise);
        }
        if w < least {
            least = w;
        }
        if w > most {
            most = w;
        }
        i += 1;
    }
    let whiten = noise.absolute > 0.0;
    if whiten && most > MAX_NOISE_SCALE_RATIO * least {
        return Err(Error::InvalidNoise);
    }
    let noise_exponent = if whiten { exponent_of(least) } else { 0 };
    let absolute = times_power_of_two(noise.absolute, noise_exponent);
    if !absolute.is_finite() {
        // σ times the least noise scale beyond f32: no sensor's noise is a number.
        return Err(Error::InvalidNoise);
    }
    let mut whitening = [1.0f32; K];
    if whiten {
        let mut i = 0;
        while i < K {
            whitening[i] = times_power_of_two(1.0, noise_exponent) / sensors[i].noise_scale;
            i += 1;
        }
    }
    Ok((whitening, absolute))
}

/// What the sensors see: unit directions, whitening, response classes and their gains, and
/// the zonal harmonics through each response.
struct Seen<const K: usize> {
    directions: [Vec3; K],
    whitening: [f32; K],
    /// Each sensor's response class.
    class: [u8; K],
    /// The gains `g_l` per class.
    gains: [[f32; DEGREES]; MAX_RESPONSES],
    classes: usize,
    /// `uᵢ = (g_l·Y_l0(dᵢ))`, degrees 0 to 2.
    zonal_u: [[f32; 3]; K],
    /// `R·uᵢ`.
    ru: [[f32; 3]; K],
}

impl<const K: usize> Seen<K> {
    /// [`Error::InvalidDirection`] for a zero or non-finite direction, [`Error::InvalidResponse`]
    /// for a response out of range or more than [`MAX_RESPONSES`] distinct ones.
    #[inline(never)]
    const fn new(
        sensors: &[Sensor; K],
        whitening: [f32; K],
        zonal_r: &[[f32; 3]; 3],
    ) -> Result<Self, Error> {
        let mut directions = [Vec3::ZERO; K];
        let mut class = [0u8; K];
        let mut gains = [[0.0f32; DEGREES]; MAX_RESPONSES];
        let mut responses = [Response::CosinePower(1.0); MAX_RESPONSES];
        let mut classes = 0usize;
        let mut i = 0;
        while i < K {
            let sensor = &sensors[i];
            directions[i] = match normalized(sensor.direction) {
                Some(d) => d,
                None => return Err(Error::InvalidDirection),
            };
            // A response seen before shares its class (and its gains, computed once).
            let mut found = classes;
            let mut c = 0;
            while c < classes && c < MAX_RESPONSES {
                if same_response(&responses[c], &sensor.response) {
                    found = c;
                    break;
                }
                c += 1;
            }
            if found == classes {
                if classes >= MAX_RESPONSES {
                    return Err(Error::InvalidResponse);
                }
                gains[classes] = match sensor.response.gains() {
                    Ok(g) => g,
                    Err(e) => return Err(e),
                };
                responses[classes] = sensor.response;
                classes += 1;
            }
            class[i] = (found % MAX_RESPONSES) as u8;
            i += 1;
        }
        let mut zonal_u = [[0.0f32; 3]; K];
        let mut ru = [[0.0f32; 3]; K];
        let mut i = 0;
        while i < K {
            let y = harmonics::zonal(directions[i].z);
            let g = &gains[class[i] as usize % MAX_RESPONSES];
            let mut l = 0;
            while l < 3 {
                zonal_u[i][l] = g[l] * y[l];
                l += 1;
            }
            ru[i] = times_r(zonal_r, &zonal_u[i]);
            i += 1;
        }
        Ok(Seen { directions, whitening, class, gains, classes, zonal_u, ru })
    }

    /// Sensor `i`'s gains.
    const fn gains_of(&self, i: usize) -> &[f32; DEGREES] {
        let class = if i < K { self.class[i] as usize } else { 0 };
        &self.gains[class % MAX_RESPONSES]
    }
}

/// `Πᵢ wᵢ` as a [`LogProduct`] (no overflow or underflow).
const fn log_product<const K: usize>(w: &[f32; K]) -> LogProduct {
    let mut product = LogProduct::ONE;
    let mut i = 0;
    while i < K {
        product = product.times(w[i]);
        i += 1;
    }
    product
}

/// The directions scaled to the query tables' node spacing.
const fn scaled_directions<const K: usize>(directions: &[Vec3; K]) -> [Vec3; K] {
    let mut scaled = [Vec3::ZERO; K];
    let mut i = 0;
    while i < K {
        let d = directions[i];
        let f = 0.5 * (NODES - 1) as f32;
        scaled[i] = Vec3::new(f * d.x, f * d.y, f * d.z);
        i += 1;
    }
    scaled
}

/// Per class, the table of the sensor–query covariance against `t = d·n` (its Legendre
/// series with `(2l + 1)/(4π)`).
#[inline(never)]
const fn query_tables<const K: usize>(
    seen: &Seen<K>,
    spectrum: &[f32; DEGREES],
) -> [[f32; NODES]; MAX_RESPONSES] {
    let c = COSINE_FACTORS;
    let mut tables = [[0.0f32; NODES]; MAX_RESPONSES];
    let mut q = 0;
    while q < seen.classes && q < MAX_RESPONSES {
        let mut coef = [0.0f32; DEGREES];
        let mut l = 0;
        while l < DEGREES {
            coef[l] = spectrum[l] * seen.gains[q][l] * c[l] * degree_weight(l);
            l += 1;
        }
        // Nodes k and NODES − 1 − k sit at ±t: one recurrence gives both.
        let mut k = NODES / 2;
        while k < NODES {
            let x = -1.0 + 2.0 * k as f32 / (NODES - 1) as f32;
            let (even, odd) = legendre::parts(&coef, &RECURRENCE, x);
            tables[q][k] = even + odd;
            tables[q][NODES - 1 - k] = even - odd;
            k += 1;
        }
        q += 1;
    }
    tables
}

/// The whitened covariance of the readings and the direction average of z zᵀ above degree 2
/// (`z` the readings' covariances with the radiance at a direction).
#[inline(never)]
const fn whitened_covariances<const K: usize>(
    seen: &Seen<K>,
    spectrum: &[f32; DEGREES],
) -> ([[f32; K]; K], [[f32; K]; K]) {
    let c = COSINE_FACTORS;
    // The Legendre series of the sensor covariance and of the average of z zᵀ per pair of
    // responses.
    let mut pair_cov = [[[0.0f32; DEGREES]; MAX_RESPONSES]; MAX_RESPONSES];
    let mut pair_zz = [[[0.0f32; DEGREES]; MAX_RESPONSES]; MAX_RESPONSES];
    let mut ci = 0;
    while ci < seen.classes && ci < MAX_RESPONSES {
        let mut cj = 0;
        while cj < seen.classes && cj < MAX_RESPONSES {
            let (gi, gj) = (&seen.gains[ci], &seen.gains[cj]);
            let mut l = 0;
            while l < DEGREES {
                let k = spectrum[l] * gi[l] * gj[l] * degree_weight(l);
                pair_cov[ci][cj][l] = k;
                // Degrees ≤ 2 are added in `average_products` from their coefficients.
                if l > 2 {
                    pair_zz[ci][cj][l] = k * spectrum[l] * c[l] * c[l] / FOUR_PI;
                }
                l += 1;
            }
            cj += 1;
        }
        ci += 1;
    }
    let mut cov = [[0.0f32; K]; K];
    let mut zz = [[0.0f32; K]; K];
    let mut i = 0;
    while i < K {
        let mut j = 0;
        while j <= i {
            let (ci, cj) =
                (seen.class[i] as usize % MAX_RESPONSES, seen.class[j] as usize % MAX_RESPONSES);
            let (a, b) = (&pair_cov[ci][cj], &pair_zz[ci][cj]);
            let (di, dj) = (seen.directions[i], seen.directions[j]);
            let t = di.x * dj.x + di.y * dj.y + di.z * dj.z;
            let w = seen.whitening[i] * seen.whitening[j];
            // The zonal part: uᵢᵀRuⱼ.
            let mut zonal = 0.0f32;
            let mut l = 0;
            while l < 3 {
                zonal += seen.zonal_u[i][l] * seen.ru[j][l];
                l += 1;
            }
            let (sa, sb) = legendre::sums(a, b, &RECURRENCE, t);
            cov[i][j] = w * (sa + zonal);
            cov[j][i] = cov[i][j];
            zz[i][j] = w * sb;
            zz[j][i] = zz[i][j];
            j += 1;
        }
        i += 1;
    }
    (cov, zz)
}

/// The eigendecomposition of the whitened covariance, its eigenvalues floored.
struct Eigen<const K: usize> {
    /// The covariance with its floored eigenvalues raised to the floor ([`lift_floored`]).
    covariance: [[f32; K]; K],
    values: [f32; K],
    vectors: [[f32; K]; K],
    /// The number of eigenvalues above the floor.
    rank: usize,
}

impl<const K: usize> Eigen<K> {
    /// The model's least noise: eigenvalues floored at 10⁻⁶ of the largest, so that dependent
    /// readings (duplicate sensors; antipodal cosine pairs, whose differences see degree 1
    /// only) keep the system solvable. [`Error::InvalidPrior`] for a covariance the sensors
    /// see at less than 2⁻⁶⁰ of the spectrum's largest `K_l` (`largest·2^exponent`) or not at
    /// all: its floored eigenvalues would be near or below the normal range, and the fit's
    /// `Σ z²/λ` beyond f32.
    #[inline(never)]
    const fn floored(cov: [[f32; K]; K], largest: f32, exponent: i32) -> Result<Self, Error> {
        let mut covariance = cov;
        let (mut values, vectors) = symmetric_eigen(cov);
        let mut top = 0.0f32;
        let mut j = 0;
        while j < K {
            if values[j] > top {
                top = values[j];
            }
            j += 1;
        }
        if !(top.is_finite() && top >= times_power_of_two(largest, -60 - exponent)) {
            return Err(Error::InvalidPrior);
        }
        let mut rank = 0;
        let mut lift = [0.0f32; K];
        let mut j = 0;
        while j < K {
            // (A NaN eigenvalue, impossible from finite input, is floored too.)
            if values[j].is_nan() || values[j] <= FLOOR * top {
                lift[j] = if values[j].is_nan() { FLOOR * top } else { FLOOR * top - values[j] };
                values[j] = FLOOR * top;
            } else {
                rank += 1;
            }
            j += 1;
        }
        lift_floored(&mut covariance, &vectors, &lift);
        Ok(Eigen { covariance, values, vectors, rank })
    }
}

/// M̃ = Vᵀ·avg[z zᵀ]·V (only its diagonal without a mean term). Degrees ≤ 2 carry nearly all
/// of avg[z zᵀ], and a product of matrices would lose the small eigenvalues' share of it to
/// rounding: their part is (1/4π)·Σ_lm c_l²·b̃_lm b̃_lmᵀ with b̃_lm = Vᵀ·(the whitened
/// covariances of the readings with the radiance's coefficient lm), projected one vector at a
/// time; `zz` holds the degrees above 2.
#[inline(never)]
const fn average_products<const K: usize>(
    seen: &Seen<K>,
    spectrum: &[f32; DEGREES],
    vectors: &[[f32; K]; K],
    zz: &[[f32; K]; K],
    mean_terms: usize,
) -> [[f32; K]; K] {
    let c = COSINE_FACTORS;
    let mut average_zz =
        if mean_terms == 1 { congruence(vectors, zz) } else { congruence_diagonal(vectors, zz) };
    let mut coefficient = [[0.0f32; K]; 9];
    let mut i = 0;
    while i < K {
        let g = seen.gains_of(i);
        let y = harmonics::degree2(seen.directions[i]);
        let mut k = 0;
        while k < 9 {
            let l = harmonics::DEGREE[k];
            coefficient[k][i] = seen.whitening[i] * spectrum[l] * g[l] * y[k];
            k += 1;
        }
        // The zonal covariances: coefficient l0 gains Σ_l' R_ll'·g_l'·Y_l'0(dᵢ).
        let mut l = 0;
        while l < 3 {
            coefficient[l * l + l][i] += seen.whitening[i] * seen.ru[i][l];
            l += 1;
        }
        i += 1;
    }
    let mut k = 0;
    while k < 9 {
        let b = project(vectors, &coefficient[k]);
        let f = c[harmonics::DEGREE[k]] * c[harmonics::DEGREE[k]] / FOUR_PI;
        let mut j = 0;
        while j < K {
            let fb = f * b[j];
            if mean_terms == 1 {
                let mut m = 0;
                while m < K {
                    average_zz[j][m] += fb * b[m];
                    m += 1;
                }
            } else {
                average_zz[j][j] += fb * b[j];
            }
            j += 1;
        }
        k += 1;
    }
    average_zz
}

/// The prior variance of the irradiance at a direction: `Σ_l K_l c_l² (2l + 1)/(4π)`.
const fn prior_variance(spectrum: &[f32; DEGREES]) -> f32 {
    let c = COSINE_FACTORS;
    let mut prior_variance = 0.0f32;
    let mut l = 0;
    while l < DEGREES {
        prior_variance += spectrum[l] * c[l] * c[l] * degree_weight(l);
        l += 1;
    }
    prior_variance
}

/// The mean's basis: sensor values `hᵢ = Σ a_l g_l P_l(dᵢ·z)`, whitened and projected, and
/// the direction averages the variances take.
struct MeanBasis<const K: usize> {
    basis: [[f32; K]; 2],
    basis_sensor: [f32; K],
    basis_query: [[f32; 9]; 2],
    average_hz: [[f32; K]; 2],
    average_hh: [[f32; 2]; 2],
}

impl<const K: usize> MeanBasis<K> {
    /// Without a mean term.
    const NONE: Self = MeanBasis {
        basis: [[0.0; K]; 2],
        basis_sensor: [0.0; K],
        basis_query: [[0.0; 9]; 2],
        average_hz: [[0.0; K]; 2],
        average_hh: [[0.0; 2]; 2],
    };

    /// The basis of the `profile` at the sensors may be far below the profile (coefficients
    /// of degrees the responses barely see): its squares and the GLS mean would leave f32 in
    /// the fit. Below 2⁻²⁰ it is brought near 1 by a power of two on the profile (exact: β
    /// takes it back), by at most what keeps the profile's largest coefficient below 2⁶¹ (the
    /// squares of the query's basis within f32), and computed again. [`Error::InvalidPrior`]
    /// for a mean the sensors do not see (below 2⁻⁸⁹ of its profile, or not at all): its
    /// multiple is not determined by the readings.
    #[inline(never)]
    const fn new(
        seen: &Seen<K>,
        spectrum: &[f32; DEGREES],
        profile: &mut [f32; 9],
        vectors: &[[f32; K]; K],
    ) -> Result<Self, Error> {
        let c = COSINE_FACTORS;
        let mut pass = 0;
        let (h, hz) = loop {
            let (h, hz, seen_most, top) = sensor_basis(seen, spectrum, profile);
            let mut largest = 0.0f32;
            let mut l = 0;
            while l < 9 {
                if super::absolute(profile[l]) > largest {
                    largest = super::absolute(profile[l]);
                }
                l += 1;
            }
            if seen_most < times_power_of_two(largest, -89) {
                return Err(Error::InvalidPrior);
            }
            if pass > 0 || !(top > 0.0 && top < 1.0 / 1_048_576.0) {
                break (h, hz);
            }
            let up = -exponent_of(top);
            let room = 60 - exponent_of(largest);
            let up = if up < room { up } else { room };
            if up <= 0 {
                break (h, hz);
            }
            let mut l = 0;
            while l < 9 {
                profile[l] = times_power_of_two(profile[l], up);
                l += 1;
            }
            pass += 1;
        };
        let mut mean = MeanBasis::NONE;
        mean.basis[0] = project(vectors, &h);
        mean.basis_sensor = h;
        mean.average_hz[0] = project(vectors, &hz);
        let mut l = 0;
        while l < 9 {
            mean.basis_query[0][l] = profile[l] * c[l];
            mean.average_hh[0][0] +=
                mean.basis_query[0][l] * mean.basis_query[0][l] / (2 * l + 1) as f32;
            l += 1;
        }
        Ok(mean)
    }
}

/// The whitened mean basis at the sensors `hᵢ`, its direction averages with the readings'
/// covariances `avg[h(n)·zᵢ(n)]`, the largest `|hᵢ|` not whitened and the largest whitened.
#[inline(never)]
const fn sensor_basis<const K: usize>(
    seen: &Seen<K>,
    spectrum: &[f32; DEGREES],
    profile: &[f32; 9],
) -> ([f32; K], [f32; K], f32, f32) {
    let c = COSINE_FACTORS;
    let mut h = [0.0f32; K];
    let mut hz = [0.0f32; K];
    let mut top = 0.0f32;
    let mut seen_most = 0.0f32;
    let mut i = 0;
    while i < K {
        let g = seen.gains_of(i);
        let mut a = [0.0f32; 9];
        let mut b = [0.0f32; 9];
        let mut l = 0;
        while l < 9 {
            a[l] = profile[l] * g[l];
            // avg[h(n)·z_i(n)] = (1/4π)·Σ_l Q_l·K_l g_l c_l·P_l(d_i·z), Q_l = a_l c_l.
            b[l] = profile[l] * c[l] * spectrum[l] * g[l] * c[l] / FOUR_PI;
            l += 1;
        }
        let v = legendre::sum(&a, &RECURRENCE, seen.directions[i].z);
        if super::absolute(v) > seen_most {
            seen_most = super::absolute(v);
        }
        h[i] = seen.whitening[i] * v;
        if super::absolute(h[i]) > top {
            top = super::absolute(h[i]);
        }
        // The zonal part: (1/4π)·Σ_l (Ruᵢ)_l c_l Q_l √(4π/(2l + 1)), Q_l = a_l c_l.
        let mut zonal = 0.0f32;
        let mut l = 0;
        while l < 3 {
            let norm = math::sqrt_newton(FOUR_PI / (2 * l + 1) as f32);
            zonal += seen.ru[i][l] * c[l] * profile[l] * c[l] * norm / FOUR_PI;
            l += 1;
        }
        hz[i] = seen.whitening[i] * (legendre::sum(&b, &RECURRENCE, seen.directions[i].z) + zonal);
        i += 1;
    }
    (h, hz, seen_most, top)
}

/// `C̃ + V·diag(lift)·Vᵀ`: the whitened covariance with the eigenvalues that the model floors
/// raised to the floor (`lift` the rise per eigenvector, 0 for the others), the matrix that
/// the eigenvalues in the probe describe. The relative-noise fit factors it: taken as it is,
/// the floor would be lost (a rounded covariance of 64 sensors has eigenvalues far below it,
/// some negative), and adding the floor to every eigenvalue instead damps the small ones
/// that carry the light (at `K = 64` on real maps, 18 % more error than the floored model).
/// The rise is small beside `C̃`: added to it, it loses no precision.
const fn lift_floored<const K: usize>(c: &mut [[f32; K]; K], v: &[[f32; K]; K], lift: &[f32; K]) {
    let mut e = 0;
    while e < K {
        if lift[e] > 0.0 {
            let mut i = 0;
            while i < K {
                let vi = v[i][e] * lift[e];
                let mut k = 0;
                while k < K {
                    c[i][k] += vi * v[k][e];
                    k += 1;
                }
                i += 1;
            }
        }
        e += 1;
    }
}
