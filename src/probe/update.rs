//! Updates: the family member chosen by marginal likelihood, and the solve of the weights.

use super::*;

impl<const N: usize, T: Radiance, F: Footprint, const M: usize> Probe<N, T, F, M>
where
    Size<N>: ProbeTables<F>,
{
    /// Takes new samples (radiance in [`Probe::directions`], in order) and picks the family
    /// member of highest marginal likelihood. Any finite radiance scale: see "Radiance scale"
    /// in the module docs.
    ///
    /// # Errors
    /// [`Error::InvalidRadiance`] if a sample has a NaN or infinite channel; the probe keeps
    /// its previous data.
    ///
    /// # Cost
    /// Flash: the size's baked tables, [`Probe::TABLE_BYTES`].
    pub fn update(&mut self, samples: &[T; N]) -> Result<(), Error> {
        self.update_with(samples, Selection::MaxLikelihood)
    }

    /// [`Probe::update`] with a chosen [`Selection`].
    ///
    /// # Errors
    /// [`Error::InvalidRadiance`] for a non-finite sample; [`Error::InvalidMember`] for a
    /// member index outside the family. Either way the probe keeps its previous data.
    pub fn update_with(&mut self, samples: &[T; N], selection: Selection) -> Result<(), Error> {
        if !samples.iter().all(|y| (0..T::CHANNELS).all(|c| y.channel(c).is_finite())) {
            return Err(Error::InvalidRadiance);
        }
        let range = match selection {
            Selection::MaxLikelihood => 0..Self::FAMILY.len(),
            Selection::Member(k) if k < Self::FAMILY.len() => k..k + 1,
            Selection::Member(_) => return Err(Error::InvalidMember),
        };
        // Work with (Y − c·1)/s, c = Y₀: α and ℓ are unchanged (β shifts by c), but the
        // ill-conditioned products then see only the samples' spread, not their mean, and a
        // constant gives exactly α = 0. The power of two s = 2^k per channel (the exponent of
        // the largest |Yᵢ − Y₀|) brings the spread to O(1), so that rᵀQ⁻¹r neither overflows
        // nor underflows whatever the radiance units: α/s and σ̂_f²/s² are stored, the queries
        // apply s last.
        let c = samples.first().copied().unwrap_or(T::ZERO);
        let (centred, spread) = scale::normalise(samples);
        let sd = Self::half_sums(&centred);
        let mut best: Option<(usize, f32, T)> = None;
        let mut work = [T::ZERO; N];
        for k in range {
            let Some(f) = Self::FAMILY.get(k) else { break };
            let (alpha, beta, q) = Self::solve(f, &centred, &sd, &mut work);
            // ℓ of the normalised samples: the scale shifts every member's ℓ alike.
            let mut ll = T::CHANNELS as f32 * f.likelihood_constant;
            for c in 0..T::CHANNELS {
                let qc = q.channel(c).max(f32::MIN_POSITIVE);
                ll -= 0.5 * (N as f32 - 1.0) * crate::math::ln(qc);
            }
            if best.is_none_or(|(_, b, _)| ll > b) {
                best = Some((k, ll, beta));
                self.alpha = *alpha;
            }
        }
        if let Some((k, ll, beta)) = best {
            self.missing.clear();
            self.store(k, ll, c, spread, beta);
        }
        Ok(())
    }

    /// The end of an update, after `α/s` is in place (and [`Probe::missing`] set): stores
    /// member `k`, the absolute `β = Y₀ + s·β′` from the centre `c = Y₀`, the scale `s`, the
    /// REML channel variance and `ℓ` of the samples as given, from `ℓ′` of the normalised
    /// ones, for the valid samples.
    pub(super) fn store(&mut self, k: usize, ll: f32, c: T, spread: T, beta: T) {
        let Some(f) = Self::FAMILY.get(k) else { return };
        // β = Y₀ + s·β′; where that overflows f32, again in f64 (±∞ only if β itself
        // exceeds f32::MAX).
        let absolute = c.add(spread.mul(beta));
        self.beta = if (0..T::CHANNELS).all(|ch| absolute.channel(ch).is_finite()) {
            absolute
        } else {
            from_channels(|ch| {
                (f64::from(c.channel(ch))
                    + f64::from(spread.channel(ch)) * f64::from(beta.channel(ch)))
                    as f32
            })
        };
        self.scale = spread;
        let valid = self.valid_count();
        // σ̂_f²/s² = α′ᵀQα′/(n − 1), the REML channel variance, computed as
        // [`Probe::signal_covariance`] does (so that the two agree bit for bit).
        self.signal_variance = Self::channel_quadratic(f, &self.alpha, valid);
        self.selected = k;
        // ℓ of the samples themselves: rᵀQ⁻¹r = s²·r′ᵀQ⁻¹r′ per channel.
        let shift: i32 = (0..T::CHANNELS).map(|ch| scale::exponent(spread.channel(ch))).sum();
        self.log_likelihood = ll - (valid as f32 - 1.0) * core::f32::consts::LN_2 * shift as f32;
    }

    /// Half sums `(y_p + y_{N−1−p})/2` in the first half, half differences in the second:
    /// what the two baked blocks act on (`gen/probe.rs`, "The antipodal symmetry").
    pub(super) fn half_sums<R: Radiance>(y: &[R; N]) -> [R; N] {
        let m = Self::HALF;
        let mut sd = [R::ZERO; N];
        let (lo, hi) = y.split_at(m);
        let (s, d) = sd.split_at_mut(m);
        for (((ya, yb), sp), dp) in lo.iter().zip(hi.iter().rev()).zip(s).zip(d) {
            *sp = ya.add(*yb).scale(0.5);
            *dp = ya.add(yb.scale(-1.0)).scale(0.5);
        }
        sd
    }

    /// `α = Q⁻¹(Y − β1)` (in `work`), `β` and `rᵀQ⁻¹r = Σ Yᵢ ⊙ αᵢ` for member `f`, from
    /// the half sums and differences `sd` of `samples`.
    pub(super) fn solve<'w>(
        f: &sealed::Baked,
        samples: &[T; N],
        sd: &[T; N],
        work: &'w mut [T; N],
    ) -> (&'w [T; N], T, T) {
        let m = Self::HALF;
        // a = E⁻¹(s/2), b = F⁻¹(d/2): (Q⁻¹Y)_p = a_p + b_p, (Q⁻¹Y)_{N−1−p} = a_p − b_p.
        let mut ab = *sd;
        {
            let (a, b) = ab.split_at_mut(m);
            cholesky_solve(f.chol_even, a);
            cholesky_solve(f.chol_odd, b);
        }
        let (a, b) = ab.split_at(m);
        // 1ᵀQ⁻¹Y = 2·Σa; β = that / s₁.
        let beta = a.iter().fold(T::ZERO, |acc, &x| acc.add(x)).scale(2.0 / f.s1);
        let mut q = T::ZERO;
        {
            let (lo, hi) = work.split_at_mut(m);
            let (ylo, yhi) = samples.split_at(m);
            for ((((&ap, &bp), g), (out_lo, out_hi)), (yp, yq)) in a
                .iter()
                .zip(b)
                .zip(f.g.iter().map(|&b| f32::from_bits(b)))
                .zip(lo.iter_mut().zip(hi.iter_mut().rev()))
                .zip(ylo.iter().zip(yhi.iter().rev()))
            {
                let even = ap.mul_add(beta, -g);
                *out_lo = even.add(bp);
                *out_hi = even.add(bp.scale(-1.0));
                q = q.add(yp.mul(*out_lo)).add(yq.mul(*out_hi));
            }
        }
        (work, beta, q)
    }
}
