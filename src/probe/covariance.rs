//! The REML channel covariance of a probe and the variance of linear combinations of its
//! channels.
//!
//! One kernel serves every channel, so the posterior covariance of two channels of an estimate
//! is `S_ab` times the unit posterior variance, where `S_ab = r_aᵀQ⁻¹r_b/(N − 1)` is the REML
//! covariance of the channels' residuals `r = Y − β1`. Since `r = Qα`,
//! `S_ab = α_aᵀQα_b/(N − 1)`, and with the half-turn split of `Q` (sums `u = α_p + α_{N−1−p}`
//! on `E = LLᵀ`, differences `v` on `F = MMᵀ`, as in `Probe::solve`)
//! `αᵀQα′ = ½·((Lᵀu)·(Lᵀu′) + (Mᵀv)·(Mᵀv′))`: one pass over the two baked factors, `N²/2`
//! multiply-adds.

use super::scale;
use super::{sealed, Estimate, Probe, ProbeTables};
use crate::error::Error;
use crate::footprint::Footprint;
use crate::radiance::{from_channels, Radiance};
use crate::size::Size;

impl<const N: usize, T: Radiance, F: Footprint, const M: usize> Probe<N, T, F, M>
where
    Size<N>: ProbeTables<F>,
{
    /// `xᵀQx/(n − 1)` per channel of `x` (any [`Radiance`]: the probe's channels at update,
    /// two channels side by side for a covariance, one for a combination) for `n` valid
    /// samples. With `x` zero at the missing samples `xᵀQx = x_VᵀQ_VVx_V`: the valid
    /// subset's quadratic form (`missing.rs`).
    pub(super) fn channel_quadratic<R: Radiance>(f: &sealed::Baked, x: &[R; N], n: usize) -> R {
        let w = Self::factor_products(f, x);
        let sum = w.iter().fold(R::ZERO, |acc, wi| acc.add(wi.mul(*wi)));
        sum.scale(0.5 / (n as f32 - 1.0))
    }

    /// `(Lᵀu, Mᵀv)` for the mirrored sums `u_p = x_p + x_{N−1−p}` and differences
    /// `v_p = x_p − x_{N−1−p}` of `x`: `xᵀQx′ = ½·Σᵢ wᵢ·w′ᵢ`.
    fn factor_products<R: Radiance>(f: &sealed::Baked, x: &[R; N]) -> [R; N] {
        let m = Self::HALF;
        let mut w = [R::ZERO; N];
        let (lo, hi) = x.split_at(m);
        let (u, v) = w.split_at_mut(m);
        for ((a, b), (up, vp)) in lo.iter().zip(hi.iter().rev()).zip(u.iter_mut().zip(v.iter_mut()))
        {
            *up = a.add(*b);
            *vp = a.add(b.scale(-1.0));
        }
        transpose_product(f.chol_even, u);
        transpose_product(f.chol_odd, v);
        w
    }

    /// The REML covariance `S_ab = r_aᵀQ⁻¹r_b/(N − 1)` of channels `a` and `b` of the last
    /// update's samples (`r = Y − β1` per channel, the selected member's `Q`), O(N²); 0 before
    /// the first update. After
    /// [`Probe::update_masked`], that of the `n` valid samples: `r_VᵀQ_VV⁻¹r_V/(n − 1)`.
    ///
    /// `S_cc` is [`Probe::signal_variance`] of channel `c` (σ̂_f²), bit for bit, and
    /// `S_ab = S_ba`. The posterior
    /// covariance of channels `a` and `b` of an [`Estimate`] is
    /// `estimate.unit_variance × S_ab` (`unit_variance` is always `Some` for a `Probe`). Computed relative to the samples' spread: `±∞` only
    /// where `S_ab` itself exceeds `f32::MAX`.
    ///
    /// # Errors
    /// [`Error::InvalidChannel`] for a channel index of `T::CHANNELS` or more.
    ///
    /// ```
    /// use sphere_quadrature::{probe::Probe, Error, Vec3};
    ///
    /// let mut probe = Probe::<32, [f32; 3]>::new();
    /// // Green is twice red plus a constant: perfectly correlated, S_gg = 4·S_rr.
    /// let samples = probe.directions().map(|d| {
    ///     let r = 1.0 + 0.5 * d.z;
    ///     [r, 2.0 * r + 1.0, 0.3 - 0.1 * d.x]
    /// });
    /// probe.update(&samples)?;
    /// let rr = probe.signal_covariance(0, 0)?;
    /// let (rg, gg) = (probe.signal_covariance(0, 1)?, probe.signal_covariance(1, 1)?);
    /// assert!((rg / rr - 2.0).abs() < 1e-3 && (gg / rr - 4.0).abs() < 1e-3);
    /// assert_eq!(rr, probe.signal_variance()[0]);
    /// // An RGB probe has no fourth channel.
    /// assert_eq!(probe.signal_covariance(0, 3), Err(Error::InvalidChannel));
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn signal_covariance(&self, a: usize, b: usize) -> Result<f32, Error> {
        if a >= T::CHANNELS || b >= T::CHANNELS {
            return Err(Error::InvalidChannel);
        }
        let Ok(f) = self.member_in_use() else { return Ok(0.0) };
        let pair = self.alpha.map(|x| [x.channel(a), x.channel(b)]);
        let w = Self::factor_products(f, &pair);
        let sum = w.iter().fold(0.0f32, |acc, wi| acc + wi[0] * wi[1]);
        let normalised = sum * (0.5 / (self.valid_count() as f32 - 1.0));
        let shift = scale::exponent(self.scale.channel(a)) + scale::exponent(self.scale.channel(b));
        Ok(libm::scalbnf(normalised, shift))
    }

    /// `wᵀSw`, the REML variance of the channel combination `Σ_c w_c·Y_c` (for example
    /// luminance, `w = [0.2126, 0.7152, 0.0722]`), with `S` of [`Probe::signal_covariance`];
    /// O(N²) in one pass over `α_w = Σ_c w_c·α_c`. The posterior variance of the combination
    /// of an estimate's channels is `estimate.unit_variance` times this
    /// ([`Probe::combine`]). Computed relative to the samples' spread: `+∞` only where the
    /// result exceeds `f32::MAX`.
    ///
    /// # Errors
    /// [`Error::InvalidWeights`] for a NaN or infinite weight.
    pub fn signal_variance_of(&self, weights: T) -> Result<f32, Error> {
        check_weights(weights)?;
        let (normalised, shift) = self.combination_parts(weights);
        Ok(crate::math::ldexp_variance(normalised, shift))
    }

    /// `(v, k)` with `wᵀSw = v·2^k` and `v` a normal number or 0 (or NaN for NaN weights).
    fn combination_parts(&self, weights: T) -> (f32, i32) {
        let Ok(f) = self.member_in_use() else { return (0.0, 0) };
        // w_c·s_c = m_c·2^(e_c + k_c) with |m_c| ∈ [½, 1): α_w/2^K with K the largest
        // e_c + k_c keeps every coefficient at most 1 in magnitude, whatever the weights'
        // and the samples' scales.
        let parts = |c: usize| {
            let (m, e) = libm::frexpf(weights.channel(c));
            (m, e + scale::exponent(self.scale.channel(c)))
        };
        let top = (0..T::CHANNELS)
            .filter_map(|c| {
                let (m, e) = parts(c);
                (m != 0.0).then_some(e)
            })
            .max();
        let Some(top) = top else { return (0.0, 0) };
        let coefficient: T = from_channels(|c| {
            let (m, e) = parts(c);
            libm::scalbnf(m, e - top)
        });
        let combined: [f32; N] = self.alpha.map(|x| {
            (0..T::CHANNELS).fold(0.0f32, |acc, c| acc + coefficient.channel(c) * x.channel(c))
        });
        (Self::channel_quadratic(f, &combined, self.valid_count()), 2 * top)
    }

    /// The channel combination `Σ_c w_c·value_c` of an estimate of this probe (after the
    /// last update) with its posterior variance `unit_variance × wᵀSw`
    /// ([`Probe::signal_variance_of`]); `unit_variance` is passed through. The same call on
    /// every probe: [`TemporalProbe::combine`](crate::TemporalProbe::combine),
    /// [`LayoutProbe::combine`](crate::LayoutProbe::combine).
    ///
    /// This costs O(N²) per call (the quadratic form over the baked factors). For many
    /// queries with the same weights, call [`Probe::signal_variance_of`] once per update and
    /// multiply each estimate's `unit_variance` by it (`combine` only avoids the overflow of
    /// that product in its intermediates). An estimate without a `unit_variance` (not one of
    /// this probe's) gets the bound of [`TemporalProbe::combine`](crate::TemporalProbe::combine).
    ///
    /// # Errors
    /// [`Error::InvalidWeights`] for a NaN or infinite weight.
    ///
    /// ```
    /// use sphere_quadrature::{Probe, Vec3};
    ///
    /// let mut probe = Probe::<64, [f32; 3]>::new();
    /// let samples = probe.directions().map(|d| [1.0 + 0.5 * d.z, 0.8 + 0.4 * d.x, 0.5]);
    /// probe.update(&samples)?;
    /// let luminance = [0.2126, 0.7152, 0.0722];
    /// let e = probe.irradiance(Vec3::Z)?;
    /// let y = probe.combine(&e, luminance)?;
    /// assert!((y.value - (0.2126 * e.value[0] + 0.7152 * e.value[1] + 0.0722 * e.value[2])).abs() < 1e-5);
    /// // Once per update, then one multiplication per query:
    /// let s_y = probe.signal_variance_of(luminance)?;
    /// let unit = e.unit_variance.expect("a Probe's channels share one model");
    /// assert!((y.variance - unit * s_y).abs() <= 1e-6 * y.variance);
    /// // A single channel's weights give that channel's variance.
    /// let red = probe.combine(&e, [1.0, 0.0, 0.0])?;
    /// assert!((red.variance - e.variance[0]).abs() <= 1e-6 * e.variance[0]);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    pub fn combine(&self, estimate: &Estimate<T>, weights: T) -> Result<Estimate<f32>, Error> {
        check_weights(weights)?;
        let Some(unit) = estimate.unit_variance else {
            return crate::estimate::combine_bound(estimate, weights);
        };
        let value = (0..T::CHANNELS).fold(0.0f64, |acc, c| {
            acc + f64::from(weights.channel(c)) * f64::from(estimate.value.channel(c))
        }) as f32;
        let (normalised, shift) = self.combination_parts(weights);
        let variance = if normalised == 0.0 || unit == 0.0 {
            0.0
        } else {
            let (m, e) = libm::frexpf(unit);
            crate::math::ldexp_variance(m * normalised, shift + e)
        };
        Ok(Estimate { value, variance, unit_variance: Some(unit) })
    }
}

/// [`Error::InvalidWeights`] unless every weight is finite.
fn check_weights<T: Radiance>(weights: T) -> Result<(), Error> {
    if (0..T::CHANNELS).all(|c| weights.channel(c).is_finite()) {
        Ok(())
    } else {
        Err(Error::InvalidWeights)
    }
}

/// `x ← Lᵀx` for `L` stored (as f32 bits) as packed lower-triangle rows with a reciprocal
/// diagonal: row `i` scatters `L_ij·x_i` into `j < i` (positions already past their own row)
/// and scales `x_i` by `L_ii`.
fn transpose_product<R: Radiance>(packed: &[u32], x: &mut [R]) {
    let mut rest = packed;
    for i in 0..x.len() {
        let Some((row, r)) = rest.split_at_checked(i + 1) else { return };
        rest = r;
        let Some((&inv, off)) = row.split_last() else { return };
        let (head, tail) = x.split_at_mut(i);
        let Some(xi) = tail.first_mut() else { return };
        let v = *xi;
        for (&l, xj) in off.iter().zip(head.iter_mut()) {
            *xj = xj.mul_add(v, f32::from_bits(l));
        }
        *xi = v.scale(1.0 / f32::from_bits(inv));
    }
}
