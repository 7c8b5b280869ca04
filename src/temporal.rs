//! Temporal accumulation: a probe that takes a freshly rotated set of samples every frame and
//! combines the successive posteriors by their variances, with a change detector driven by
//! the error bar.
//!
//! Real-time probes (DDGI and its kin) update every frame with new ray directions and blend
//! over time with a fixed *hysteresis* `E ← h·E + (1 − h)·E_new`, which trades noise against lag
//! by a hand-tuned constant. [`TemporalProbe`] uses what the probe already knows instead:
//! - every update rotates the sample set anew ([`RotationSequence::next_rotation`]), so the
//!   aliasing errors of successive frames are close to independent;
//! - the state is the SH L2 projection of the posterior mean radiance
//!   ([`Probe::radiance_sh`], 9 coefficients per channel) with the posterior variance of
//!   each coefficient ([`Probe::radiance_sh_variance`], calibrated);
//! - the updates of a stationary stretch are averaged with equal weights (Welford), which is
//!   the inverse-variance combination when, as here, every update has the same error
//!   distribution; the per-update variances themselves are not used as weights, because the
//!   calibrated posterior variance jumps by up to 10³ between family members (see
//!   "Calibration" in [`crate::probe`]) and would let a few updates dominate. The variance of
//!   the mean is `s²/k`, with `s²` the frame-to-frame scatter of the updates' coefficients and
//!   the probe's own posterior variance as a prior worth [`PRIOR_UPDATES`] updates;
//! - **change detection**: before combining, the innovation `d = c − m` is tested against its
//!   variance `s²·(1 + 1/k)`: `χ² = Σ_lm d²/(s²(1 + 1/k))` per channel (9 degrees of freedom
//!   for Gaussian errors on static light). Above the threshold ([`DEFAULT_THRESHOLD`]) in any
//!   channel the light has changed: the state is reset to the new update alone.
//!
//! Queries answer from the state in O(9): [`TemporalProbe::irradiance`] (the SH L2
//! irradiance, `Σ Â_l·m_lm·Y_lm(n)`, with variance `Σ (Â_l·Y_lm(n))²·v_lm`, the coefficients
//! taken as independent) and [`TemporalProbe::radiance_sh`] for a renderer.
//!
//! Measured (`cargo eval temporal`, `docs/temporal.md`): see the README's
//! temporal section; on point-sampled real maps the error after 16 static updates is about a
//! third of one update's, and a switch between two similar maps can go undetected.
//!
//! ```
//! use sphere_quadrature::temporal::{Change, TemporalProbe};
//! use sphere_quadrature::Vec3;
//!
//! let mut probe = TemporalProbe::<64>::new(7);
//! for frame in 0..8 {
//!     // Trace or read the radiance in this frame's directions (here a sky brighter at +z).
//!     let samples = probe.directions().map(|d| 1.0 + 0.5 * d.z);
//!     let change = probe.update(&samples)?;
//!     assert_eq!(change, if frame == 0 { Change::First } else { Change::Blended });
//! }
//! let e = probe.irradiance(Vec3::Z)?;
//! // π·(1 + 0.5·2/3) = 4.18879.
//! assert!((e.value - 4.18879).abs() < 0.02);
//! // The light switches off: the innovation test resets the state at once.
//! assert_eq!(probe.update(&[0.0; 64])?, Change::Reset);
//! assert!(probe.irradiance(Vec3::Z)?.value.abs() < 1e-6);
//! # Ok::<(), sphere_quadrature::Error>(())
//! ```
//!
//! # Bad input
//! A non-finite sample: [`Error::InvalidRadiance`], the state and the directions unchanged
//! (retake the samples). A zero or non-finite normal: [`Error::InvalidDirection`]. A threshold
//! that is not finite and positive: [`Error::InvalidParameter`]. Before the first update every
//! query returns zero with zero variance.

use crate::bmc::Size;
use crate::error::Error;
use crate::footprint::{Footprint, Point};
use crate::probe::{Probe, ProbeTables};
use crate::radiance::Radiance;
use crate::rotation::RotationSequence;
use crate::sh::ShL2;
use crate::vec3::Vec3;
use core::f32::consts::PI;

/// The default threshold of the innovation test: `χ²` over the 9 coefficients of a channel.
/// Chosen on the training maps (apartment, bridge, forest, lab; `clamp` tier, N = 64) by
/// `eval/src/bin/temporal.rs -- --threshold T`: 10 and 20 reset on static light (the error after
/// 32 updates rose again to 24 % and 20 %), 30 did not (15 % after 16 updates against 46 %
/// for one), 50 detected fewer switches. See [`TemporalProbe::with_threshold`].
pub const DEFAULT_THRESHOLD: f32 = 30.0;

/// The weight, in updates, of the probe's own posterior variance in the frame-noise estimate
/// (see [`TemporalProbe::radiance_sh_variance`]).
pub const PRIOR_UPDATES: f32 = 2.0;

/// What [`TemporalProbe::update`] did with the new samples.
///
/// # Examples
/// ```
/// use sphere_quadrature::temporal::{Change, TemporalProbe};
///
/// let mut probe = TemporalProbe::<64>::new(3);
/// let frame = |p: &TemporalProbe<64>, level: f32| p.directions().map(|d| level + 0.25 * d.z);
/// assert_eq!(probe.update(&frame(&probe, 1.0))?, Change::First);
/// assert_eq!(probe.update(&frame(&probe, 1.0))?, Change::Blended);
/// // The lighting changes by far more than the noise: the state restarts.
/// assert_eq!(probe.update(&frame(&probe, 20.0))?, Change::Reset);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Change {
    /// The first update: the state is this update.
    First,
    /// Combined with the state by inverse variance.
    Blended,
    /// The innovation test found a change of lighting: the state is this update alone.
    Reset,
}

/// An estimate of the accumulated state: value and variance per channel.
///
/// # Examples
/// ```
/// use sphere_quadrature::{temporal::TemporalProbe, Vec3};
///
/// let mut probe = TemporalProbe::<64>::new(5);
/// for _ in 0..4 {
///     let samples = probe.directions().map(|_| 2.0);
///     probe.update(&samples)?;
/// }
/// let a = probe.irradiance(Vec3::new(0.0, 1.0, 0.0))?;
/// // A constant field of 2 has irradiance 2π everywhere.
/// assert!((a.value / (2.0 * core::f32::consts::PI) - 1.0).abs() < 1e-3);
/// assert!(a.variance >= 0.0);
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Accumulated<T> {
    /// The value.
    pub value: T,
    /// Its variance (the coefficients' variances, taken as independent).
    pub variance: T,
}

/// A [`Probe`] updated every frame under a fresh rotation, accumulating its SH L2 posterior
/// over time (see the module docs).
///
/// # Examples
/// ```
/// use sphere_quadrature::{temporal::TemporalProbe, Vec3};
///
/// // Every frame: take the samples along the current directions, then update.
/// let mut probe = TemporalProbe::<64, [f32; 3]>::new(11);
/// for _ in 0..8 {
///     let samples = probe.directions().map(|d| [1.0 + 0.5 * d.z; 3]);
///     probe.update(&samples)?;
/// }
/// assert_eq!(probe.updates(), 8);
/// let e = probe.irradiance(Vec3::Z)?;
/// // π·(1 + 0.5·2/3), per channel.
/// assert!(e.value.iter().all(|&v| (v - 4.18879).abs() < 0.02));
/// # Ok::<(), sphere_quadrature::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct TemporalProbe<const N: usize, T: Radiance = f32, F: Footprint = Point>
where
    Size<N>: ProbeTables<F>,
{
    probe: Probe<N, T, F>,
    rotations: RotationSequence,
    mean: ShL2<T>,
    /// `Σ (cᵢ − m)²` over the combined updates, per coefficient.
    scatter: [T; 9],
    /// Mean of the combined updates' own posterior variances, per coefficient.
    model_variance: [T; 9],
    updates: u32,
    threshold: f32,
    last_chi2: f32,
}

impl<const N: usize, T: Radiance, F: Footprint> TemporalProbe<N, T, F>
where
    Size<N>: ProbeTables<F>,
{
    /// A temporal probe whose rotations come from `seed`, with no data yet.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        let mut rotations = RotationSequence::new(seed);
        let mut probe = Probe::new();
        // A rotation from the sequence is orthonormal; on the impossible refusal the probe
        // keeps the unrotated set, which is valid too.
        let _ = probe.set_rotation(rotations.next_rotation());
        Self {
            probe,
            rotations,
            mean: ShL2::ZERO,
            scatter: [T::ZERO; 9],
            model_variance: [T::ZERO; 9],
            updates: 0,
            threshold: DEFAULT_THRESHOLD,
            last_chi2: 0.0,
        }
    }

    /// The same probe with another innovation threshold (`χ²` per channel over the 9
    /// coefficients): lower resets sooner on a real change and more often on noise.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] unless `threshold` is finite and positive.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{temporal::TemporalProbe, Error};
    ///
    /// let probe = TemporalProbe::<16>::new(0).with_threshold(50.0)?;
    /// assert_eq!(probe.updates(), 0);
    /// assert_eq!(TemporalProbe::<16>::new(0).with_threshold(0.0).err(), Some(Error::InvalidParameter));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn with_threshold(mut self, threshold: f32) -> Result<Self, Error> {
        if !(threshold.is_finite() && threshold > 0.0) {
            return Err(Error::InvalidParameter);
        }
        self.threshold = threshold;
        Ok(self)
    }

    /// The directions in which to take this frame's samples (a new rotation after every
    /// successful update).
    #[must_use]
    pub const fn directions(&self) -> &[Vec3; N] {
        self.probe.directions()
    }

    /// Takes this frame's samples (radiance in [`TemporalProbe::directions`], in order),
    /// combines them with the state, and rotates the set for the next frame.
    ///
    /// # Errors
    /// [`Error::InvalidRadiance`] for a non-finite sample: the state and the directions are
    /// unchanged.
    ///
    /// # Examples
    /// ```
    /// use sphere_quadrature::{temporal::TemporalProbe, Error};
    ///
    /// let mut probe = TemporalProbe::<16>::new(1);
    /// // A NaN sample is refused and nothing changes.
    /// let mut samples = [1.0f32; 16];
    /// samples[3] = f32::NAN;
    /// assert_eq!(probe.update(&samples), Err(Error::InvalidRadiance));
    /// assert_eq!(probe.updates(), 0);
    /// samples[3] = 1.0;
    /// probe.update(&samples)?;
    /// assert_eq!(probe.updates(), 1);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn update(&mut self, samples: &[T; N]) -> Result<Change, Error> {
        self.probe.update(samples)?;
        let c = self.probe.radiance_sh();
        let w = self.probe.radiance_sh_variance();
        let change = if self.updates == 0 {
            Change::First
        } else {
            // Innovation d = c − m against its variance s²·(1 + 1/k): the frame-to-frame
            // noise s² (below) for the new update plus s²/k for the mean.
            let k = self.updates as f32;
            let noise = self.frame_noise();
            let mut worst = 0.0f32;
            for ch in 0..T::CHANNELS {
                let mut chi2 = 0.0f32;
                for ((m, s2), c) in self.mean.coefficients.iter().zip(&noise).zip(&c.coefficients) {
                    let d = c.channel(ch) - m.channel(ch);
                    let s = s2.channel(ch) * (1.0 + 1.0 / k);
                    chi2 += if s > 0.0 {
                        d * d / s
                    } else if d == 0.0 {
                        0.0
                    } else {
                        f32::INFINITY
                    };
                }
                // NaN (an overflowing d²/s) counts as a change.
                worst = if chi2 > worst || chi2.is_nan() { chi2 } else { worst };
            }
            self.last_chi2 = worst;
            if worst > self.threshold || worst.is_nan() {
                Change::Reset
            } else {
                Change::Blended
            }
        };
        if change == Change::Blended {
            // Equal weights (Welford): the k-th update enters with weight 1/k; the scatter
            // M2 = Σ (cᵢ − m)² and the mean of the updates' own variances follow.
            self.updates = self.updates.saturating_add(1);
            let k = self.updates as f32;
            for (((m, m2), wbar), (c, w)) in self
                .mean
                .coefficients
                .iter_mut()
                .zip(&mut self.scatter)
                .zip(&mut self.model_variance)
                .zip(c.coefficients.iter().zip(&w))
            {
                let delta = c.add(m.scale(-1.0));
                *m = m.add(delta.scale(1.0 / k));
                *m2 = m2.add(delta.mul(c.add(m.scale(-1.0))));
                *wbar = wbar.add(w.add(wbar.scale(-1.0)).scale(1.0 / k));
            }
        } else {
            self.mean = c;
            self.scatter = [T::ZERO; 9];
            self.model_variance = w;
            self.updates = 1;
            if change == Change::First {
                self.last_chi2 = 0.0;
            }
        }
        let _ = self.probe.set_rotation(self.rotations.next_rotation());
        Ok(change)
    }

    /// The accumulated SH L2 radiance.
    #[must_use]
    pub const fn radiance_sh(&self) -> &ShL2<T> {
        &self.mean
    }

    /// The variance of each accumulated coefficient: the frame noise over the number of
    /// updates combined, `s²/k`.
    #[must_use]
    pub fn radiance_sh_variance(&self) -> [T; 9] {
        let k = self.updates.max(1) as f32;
        self.frame_noise().map(|s2| s2.scale(1.0 / k))
    }

    /// The frame-to-frame noise of each coefficient, `s² = (M2 + ν₀·w̄)/(k − 1 + ν₀)`: the
    /// scatter of the combined updates, with the probe's own posterior variance `w̄` as a
    /// prior worth [`PRIOR_UPDATES`] updates (it alone for the first).
    fn frame_noise(&self) -> [T; 9] {
        let k = self.updates.max(1) as f32;
        let mut out = [T::ZERO; 9];
        for ((o, m2), w) in out.iter_mut().zip(&self.scatter).zip(&self.model_variance) {
            *o = m2.add(w.scale(PRIOR_UPDATES)).scale(1.0 / (k - 1.0 + PRIOR_UPDATES));
        }
        out
    }

    /// Updates combined since the first update or the last reset (0 before any).
    #[must_use]
    pub const fn updates(&self) -> u32 {
        self.updates
    }

    /// The largest per-channel `χ²` of the last update's innovation test (0 for the first).
    #[must_use]
    pub const fn last_chi2(&self) -> f32 {
        self.last_chi2
    }

    /// Irradiance `E(n)` of the accumulated state, O(9), with its variance.
    ///
    /// # Errors
    /// [`Error::InvalidDirection`] for a zero or non-finite normal.
    pub fn irradiance(&self, normal: Vec3) -> Result<Accumulated<T>, Error> {
        let value = self.mean.irradiance(normal)?;
        let basis = ShL2::<T>::basis(normal)?;
        const GAIN: [f32; 9] = [
            PI,
            2.0 * PI / 3.0,
            2.0 * PI / 3.0,
            2.0 * PI / 3.0,
            PI / 4.0,
            PI / 4.0,
            PI / 4.0,
            PI / 4.0,
            PI / 4.0,
        ];
        let mut variance = T::ZERO;
        for ((v, b), g) in self.radiance_sh_variance().iter().zip(basis).zip(GAIN) {
            let f = g * b;
            variance = variance.mul_add(*v, f * f);
        }
        Ok(Accumulated { value, variance })
    }
}
