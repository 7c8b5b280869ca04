//! Missing samples: an update from the valid subset `V` of the `N`
//! samples, through the baked factors of the full set, by the Schur complement of the missing
//! block `M` (`m ≤ M` samples, the probe's capacity).
//!
//! With `P = Q⁻¹` (the baked half-block factors apply it in `N²/2` multiply-adds), the
//! inverse of the valid block is `Q_VV⁻¹ = P_VV − P_VM·P_MM⁻¹·P_MV`. Embedded in `N × N`
//! with zero rows and columns at `M`, that operator is `A = P − P_{·M}·P_MM⁻¹·P_{M·}`, and
//! `A·x = P·(x − E_M·c)` with `c = P_MM⁻¹·(P·x)_M` (`E_M` puts `c` at the missing indices):
//! `P` applied to `x` with the missing entries replaced by `−c`. For the residual
//! `x = Ỹ − β·1̃` (zero at `M`) that replacement is the GP's prediction of the missing
//! residuals from the valid ones, so the update is the full update of the samples with the
//! missing ones imputed, and `α = A·x` vanishes at `M`.
//!
//! Per family member:
//! - `P_MM` from the half-turn split: with `j ↦ (p, σ)` (pair `p < N/2`, `σ = +1` for
//!   `j = p`, `−1` for `j = N − 1 − p`), `E = LLᵀ` and `F = KKᵀ` the two baked blocks,
//!   `P_ij = ½·(lₚ·l_q + σᵢσⱼ·kₚ·k_q)` with `lₚ = L⁻¹eₚ`, `kₚ = K⁻¹eₚ` (forward substitutions
//!   of unit vectors, zero above `p`: `(N/2 − p)²/2` multiply-adds each, once per distinct
//!   pair); a Gram matrix, so symmetric and positive semi-definite as computed. Its inverse is
//!   the conditional covariance of the missing samples given the valid ones, whose
//!   eigenvalues lie in `[σ′², λ_max(Q_MM)]`: `cond(P_MM) ≤ (m + σ′²)/σ′²`.
//! - `P_MM = L_M·D·L_Mᵀ` (unit lower `L_M`, no square roots), in f32 on fixed-capacity
//!   storage (`heapless::Vec<[f32; M], M>`); `log det Q_VV = log det Q + log det P_MM`.
//! - `u = P·Ỹ` at `M` from the forward substitutions `L⁻¹s`, `K⁻¹d` of the samples' half sums
//!   and differences (`(E⁻¹s)ₚ = lₚ·(L⁻¹s)`), `1ᵀP·Ỹ = 2·gᵀs` (`g = E⁻¹1`, baked), and
//!   `t = P·1̃` at `M` as `g_{pⱼ} − (P_MM·1)ⱼ`: then `1̃ᵀA·Ỹ = 1̃ᵀu − t_Mᵀ·P_MM⁻¹·u_M`,
//!   `s₁ = 1̃ᵀA·1̃ = s₁(Q) − 2Σⱼ g_{pⱼ} + 1ᵀP_MM·1 − t_Mᵀ·P_MM⁻¹·t_M`, `β` their ratio.
//! - `α = P·(x − E_M·c)`: one solve through the baked factors, set to 0 at `M`;
//!   `rᵀQ_VV⁻¹r = Ỹ_V·α_V`; the REML likelihood with `N − m` samples and the constant
//!   `−½·log det Q_VV − ½·log s₁`.
//!
//! The exact variances need, for a query's `ζ`, `ζ_VᵀQ_VV⁻¹ζ_V = ζᵀPζ − w_Mᵀ·P_MM⁻¹·w_M` and
//! `1ᵀQ_VV⁻¹ζ_V = Σ_{i∉M} wᵢ − c₁ᵀw_M` with `w = P·ζ` (one more back substitution) and
//! `c₁ = P_MM⁻¹·t_M`: the probe keeps the missing indices, `L_M`, `D` and `c₁` of the selected
//! member ([`Missing`]).

use super::{cholesky_solve, forward_solve, scale, sealed, Probe, ProbeTables, Selection};
use crate::error::Error;
use crate::footprint::Footprint;
use crate::radiance::Radiance;
use crate::size::Size;

/// The samples the last update left out and the selected member's Schur-complement data.
#[derive(Clone, Debug)]
pub(super) struct Missing<const M: usize> {
    /// Indices of the missing samples, ascending.
    indices: heapless::Vec<u16, M>,
    /// `P_MM = L_M·D·L_Mᵀ`: row `i` holds `L_M` left of the diagonal and `1/Dᵢ` on it.
    factor: heapless::Vec<[f32; M], M>,
    /// `c₁ = P_MM⁻¹·(P·1̃)_M`, for `1ᵀQ_VV⁻¹ζ`.
    ones: [f32; M],
    /// `s₁ = 1ᵀQ_VV⁻¹1` of the valid samples.
    s1: f32,
}

impl<const M: usize> Missing<M> {
    /// None missing.
    pub(super) const fn new() -> Self {
        Self {
            indices: heapless::Vec::new(),
            factor: heapless::Vec::new(),
            ones: [0.0; M],
            s1: 0.0,
        }
    }

    pub(super) fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// Forgets the missing samples (the factor's storage is left as it is: nothing reads it
    /// without indices).
    pub(super) fn clear(&mut self) {
        self.indices.clear();
        self.factor.clear();
    }

    /// `(ζ_VᵀQ_VV⁻¹ζ_V, 1ᵀQ_VV⁻¹ζ_V, s₁)` of the valid samples, in f64, from `E⁻¹s` and
    /// `F⁻¹d` (`s`, `d` the sums and differences of mirrored `ζ`) and the full set's
    /// `quad = ζᵀPζ` and `one = 1ᵀPζ`.
    pub(super) fn correct(&self, es: &[f64], fd: &[f64], quad: f64, one: f64) -> (f64, f64, f64) {
        let h = es.len();
        // w = Pζ at the missing samples: ½·((E⁻¹s)ₚ + σ·(F⁻¹d)ₚ).
        let mut w = [0.0f64; M];
        let (mut sum, mut along) = (0.0f64, 0.0f64);
        for ((&j, wi), &c) in self.indices.iter().zip(w.iter_mut()).zip(&self.ones) {
            let (p, sign) = pair(usize::from(j), h);
            let e = es.get(p).copied().unwrap_or(0.0);
            let o = fd.get(p).copied().unwrap_or(0.0);
            *wi = 0.5 * (e + f64::from(sign) * o);
            sum += *wi;
            along += f64::from(c) * *wi;
        }
        // w_Mᵀ·P_MM⁻¹·w_M = Σᵢ (L_M⁻¹w)ᵢ²/Dᵢ.
        let mut correction = 0.0f64;
        for (i, row) in self.factor.iter().enumerate() {
            let Some((head, tail)) = w.split_at_mut_checked(i) else { break };
            let Some(wi) = tail.first_mut() else { break };
            let acc = row.iter().zip(head.iter()).fold(*wi, |a, (&l, &x)| a - f64::from(l) * x);
            *wi = acc;
            correction += acc * acc * f64::from(row.get(i).copied().unwrap_or(0.0));
        }
        (quad - correction, one - sum - along, f64::from(self.s1))
    }
}

/// Missing sample `j` in the half-turn split of `2h` samples: its pair `p < h` and sign
/// (`+1` for `j = p`, `−1` for `j = 2h − 1 − p`).
fn pair(j: usize, h: usize) -> (usize, f32) {
    if j < h {
        (j, 1.0)
    } else {
        ((2 * h).saturating_sub(j + 1), -1.0)
    }
}

/// One missing sample: its pair, sign and the slot of its pair's unit-vector substitutions.
#[derive(Clone, Copy)]
struct Entry {
    pair: usize,
    sign: f32,
    slot: usize,
}

/// What a member's fit to the valid samples gives besides `α` and its Schur data.
struct Fit<T> {
    beta: T,
    /// `rᵀQ_VV⁻¹r` per channel.
    q: T,
    /// `−½·log det Q_VV − ½·log s₁` of the valid set.
    constant: f32,
}

impl<const N: usize, T: Radiance, F: Footprint, const M: usize> Probe<N, T, F, M>
where
    Size<N>: ProbeTables<F>,
{
    /// Takes new samples of which some are missing (`valid[i] == false`: a ray not traced, a
    /// sensor that read nothing) and fits the valid ones exactly: `β`, `α`, `σ̂_f²`, the
    /// likelihood and the member selection are those of the `N − m` valid samples alone, and
    /// so is every query's value, [`Probe::irradiance_variance`], [`Probe::glossy_variance`],
    /// [`Probe::phong_variance`], [`Probe::signal_covariance`] and what builds on it
    /// ([`Probe::signal_variance_of`], [`Probe::combine`]), and the SH export
    /// ([`Probe::radiance_sh`], [`Probe::radiance_sh_variance`]). The O(1) variances of
    /// [`Probe::irradiance`], [`Probe::glossy`] and [`Probe::phong`] are σ̂_f² of the valid
    /// samples times the baked direction average of the full set's unit variance: they do not
    /// see the holes (module docs, "Missing samples").
    ///
    /// At most `M` samples may be missing, the probe's capacity (its fourth parameter:
    /// `Probe<64, f32, Point, 16>` takes up to 16). The values at missing positions are never
    /// read: NaN or infinite there is fine. With every sample valid this is
    /// [`Probe::update`], bit for bit.
    ///
    /// Cost: per family member, `m` forward substitutions of unit vectors and an `m × m`
    /// factorisation on top of [`Probe::update`]'s solve, and one more forward substitution
    /// of the samples (the crate's Cortex-M4 cost tables); stack `4·M·N` bytes for the substitutions
    /// plus `8·M²` for two factors.
    ///
    /// ```
    /// use sphere_quadrature::footprint::Point;
    /// use sphere_quadrature::{probe::Probe, Vec3};
    ///
    /// // Up to 16 of the 64 samples may be missing.
    /// let mut probe = Probe::<64, f32, Point, 16>::new();
    /// let mut samples = probe.directions().map(|d| 1.0 + 0.5 * d.z);
    /// let mut valid = [true; 64];
    /// for j in [3, 17, 40, 41] {
    ///     valid[j] = false;
    ///     samples[j] = f32::NAN; // never read
    /// }
    /// probe.update_masked(&samples, &valid)?;
    /// assert_eq!(probe.missing(), &[3, 17, 40, 41]);
    /// let e = probe.irradiance(Vec3::Z)?;
    /// assert!((e.value - 4.18879).abs() < 0.03); // π·(1 + 0.5·2/3)
    /// // The exact variance is that of the 60 valid samples: larger than with all 64.
    /// let with_holes = probe.irradiance_variance(Vec3::Z)?;
    /// probe.update(&probe.directions().map(|d| 1.0 + 0.5 * d.z))?;
    /// assert!(probe.missing().is_empty());
    /// // 17 missing is beyond the capacity: an error, and the probe keeps its data.
    /// let e_before = probe.irradiance(Vec3::Z)?;
    /// let mut many = [true; 64];
    /// many[..17].fill(false);
    /// assert_eq!(
    ///     probe.update_masked(&samples, &many),
    ///     Err(sphere_quadrature::Error::TooManyMissing)
    /// );
    /// assert_eq!(probe.irradiance(Vec3::Z)?, e_before);
    /// # assert!(with_holes >= 0.0);
    /// # Ok::<(), sphere_quadrature::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::TooManyMissing`] when more than `M` samples are missing or fewer than two are
    /// valid (or, not seen with the baked families, when the f32 factorisation of the missing
    /// block fails for every member); [`Error::InvalidRadiance`] when a valid sample has a NaN
    /// or infinite channel. Either way the probe keeps its previous data.
    pub fn update_masked(&mut self, samples: &[T; N], valid: &[bool; N]) -> Result<(), Error> {
        self.update_masked_with(samples, valid, Selection::MaxLikelihood)
    }

    /// [`Probe::update_masked`] with a chosen [`Selection`].
    ///
    /// # Errors
    /// As [`Probe::update_masked`]; [`Error::InvalidMember`] for a member index outside
    /// the family. Either way the probe keeps its previous data.
    pub fn update_masked_with(
        &mut self,
        samples: &[T; N],
        valid: &[bool; N],
        selection: Selection,
    ) -> Result<(), Error> {
        let missing = valid.iter().filter(|&&v| !v).count();
        if missing == 0 {
            return self.update_with(samples, selection);
        }
        if missing > M || N - missing < 2 {
            return Err(Error::TooManyMissing);
        }
        let finite = |y: &T| (0..T::CHANNELS).all(|c| y.channel(c).is_finite());
        if !samples.iter().zip(valid).all(|(y, &ok)| !ok || finite(y)) {
            return Err(Error::InvalidRadiance);
        }
        let range = match selection {
            Selection::MaxLikelihood => 0..Self::FAMILY.len(),
            Selection::Member(k) if k < Self::FAMILY.len() => k..k + 1,
            Selection::Member(_) => return Err(Error::InvalidMember),
        };
        let h = Self::HALF;
        // The missing samples, their pairs, and the distinct pairs (a pair with both samples
        // missing shares its substitutions).
        let mut indices = heapless::Vec::<u16, M>::new();
        let mut entries = heapless::Vec::<Entry, M>::new();
        let mut pairs = heapless::Vec::<usize, M>::new();
        for (j, _) in valid.iter().enumerate().filter(|(_, &ok)| !ok) {
            let index = u16::try_from(j).map_err(|_| Error::TooManyMissing)?;
            let (p, sign) = pair(j, h);
            let slot = match pairs.iter().position(|&q| q == p) {
                Some(slot) => slot,
                None => {
                    pairs.push(p).map_err(|_| Error::TooManyMissing)?;
                    pairs.len() - 1
                }
            };
            indices.push(index).map_err(|_| Error::TooManyMissing)?;
            entries.push(Entry { pair: p, sign, slot }).map_err(|_| Error::TooManyMissing)?;
        }
        // Missing samples take the first valid sample's value: centred on it (as `update`
        // centres on Y₀) they are exactly 0 and do not enter the scale.
        let first = samples.iter().zip(valid).find(|(_, &ok)| ok).map_or(T::ZERO, |(&y, _)| y);
        let filled: [T; N] = core::array::from_fn(|i| match (samples.get(i), valid.get(i)) {
            (Some(&y), Some(true)) => y,
            _ => first,
        });
        let c = filled.first().copied().unwrap_or(T::ZERO);
        let (centred, spread) = scale::normalise(&filled);
        let sd = Self::half_sums(&centred);
        let count = N - missing;
        let mut vectors = heapless::Vec::<[f32; N], M>::new();
        // Two slots for α and the Schur data: the best member's and the one being fitted
        // (no copies of the M × M factor per member).
        let mut alphas = [[T::ZERO; N]; 2];
        let mut schur = [Missing::<M>::new(), Missing::<M>::new()];
        let mut best: Option<(usize, f32, T, usize)> = None;
        for k in range {
            let Some(f) = Self::FAMILY.get(k) else { break };
            let slot = best.map_or(0, |b| 1 - b.3);
            let (Some(alpha), Some(data)) = (alphas.get_mut(slot), schur.get_mut(slot)) else {
                break;
            };
            let Some(fit) =
                Self::masked_fit(f, &centred, &sd, &entries, &pairs, &mut vectors, alpha, data)
            else {
                continue;
            };
            let mut ll = T::CHANNELS as f32 * fit.constant;
            for ch in 0..T::CHANNELS {
                let qc = fit.q.channel(ch).max(f32::MIN_POSITIVE);
                ll -= 0.5 * (count as f32 - 1.0) * crate::math::ln(qc);
            }
            if best.is_none_or(|(_, b, _, _)| ll > b) {
                best = Some((k, ll, fit.beta, slot));
            }
        }
        let Some((k, ll, beta, slot)) = best else { return Err(Error::TooManyMissing) };
        let (Some(alpha), Some(data)) = (alphas.get(slot), schur.get_mut(slot)) else {
            return Err(Error::TooManyMissing);
        };
        self.alpha = *alpha;
        data.indices = indices;
        core::mem::swap(&mut self.missing, data);
        self.store(k, ll, c, spread, beta);
        Ok(())
    }

    /// The indices of the samples the last update left out, ascending (empty after
    /// [`Probe::update`] and before any update).
    #[must_use]
    pub fn missing(&self) -> &[u16] {
        &self.missing.indices
    }

    /// The number of samples the last update used: `N` less [`Probe::missing`].
    pub(super) fn valid_count(&self) -> usize {
        N - self.missing.indices.len()
    }

    /// `P·x` through the baked half-block factors.
    fn apply_inverse(f: &sealed::Baked, x: &[T; N]) -> [T; N] {
        let h = Self::HALF;
        let mut ab = Self::half_sums(x);
        {
            let (a, b) = ab.split_at_mut(h);
            cholesky_solve(f.chol_even, a);
            cholesky_solve(f.chol_odd, b);
        }
        let mut out = [T::ZERO; N];
        let (a, b) = ab.split_at(h);
        let (lo, hi) = out.split_at_mut(h);
        for (((&ap, &bp), o_lo), o_hi) in
            a.iter().zip(b).zip(lo.iter_mut()).zip(hi.iter_mut().rev())
        {
            *o_lo = ap.add(bp);
            *o_hi = ap.add(bp.scale(-1.0));
        }
        out
    }

    /// Member `f` fitted to the valid samples (`centred` is 0 at the missing ones, `sd` its
    /// half sums and differences): `α` into `alpha`, the factor, `c₁` and `s₁` into `schur`
    /// (not its indices); `None` if the missing block is numerically singular.
    #[allow(clippy::too_many_arguments)]
    fn masked_fit(
        f: &sealed::Baked,
        centred: &[T; N],
        sd: &[T; N],
        entries: &[Entry],
        pairs: &[usize],
        vectors: &mut heapless::Vec<[f32; N], M>,
        alpha: &mut [T; N],
        schur: &mut Missing<M>,
    ) -> Option<Fit<T>> {
        Self::pair_vectors(f, pairs, vectors)?;
        let g = |p: usize| f.g.get(p).map_or(0.0, |&b| f32::from_bits(b));
        let factor = &mut schur.factor;
        let (rowsum, total) = Self::missing_block(entries, vectors, factor)?;
        // t = P·1̃ at M, and 1̃ᵀP·1̃.
        let mut t = [0.0f32; M];
        let mut sum_t = f.s1 + total;
        for ((ti, e), &rs) in t.iter_mut().zip(entries).zip(&rowsum) {
            *ti = g(e.pair) - rs;
            sum_t -= 2.0 * g(e.pair);
        }
        let log_det = ldl(factor)?;
        let (mut u, sum_u) = Self::missing_projection(f, sd, entries, vectors)?;
        // Whitened: a = L_M⁻¹u, b = L_M⁻¹t.
        let m = entries.len();
        unit_lower_solve(factor, &mut u);
        unit_lower_solve(factor, &mut t);
        let mut num = sum_u;
        let mut s1 = sum_t;
        for ((row, &ai), (i, &bi)) in factor.iter().zip(&u).zip(t.iter().enumerate()) {
            let inv = row.get(i).copied().unwrap_or(0.0);
            num = num.mul_add(ai, -bi * inv);
            s1 -= bi * bi * inv;
        }
        if !(s1 > 0.0 && s1.is_finite()) {
            return None;
        }
        let beta = num.scale(1.0 / s1);
        // c = P_MM⁻¹(u − β·t) = L_M⁻ᵀ·D⁻¹·(a − β·b); c₁ = L_M⁻ᵀ·D⁻¹·b.
        let mut c = [T::ZERO; M];
        let ones = &mut schur.ones;
        *ones = [0.0f32; M];
        for (i, ((ci, oi), (&ai, &bi))) in
            c.iter_mut().zip(ones.iter_mut()).zip(u.iter().zip(&t)).enumerate().take(m)
        {
            let inv = factor.get(i).and_then(|r| r.get(i)).copied().unwrap_or(0.0);
            *ci = ai.mul_add(beta, -bi).scale(inv);
            *oi = bi * inv;
        }
        unit_upper_solve(factor, &mut c);
        unit_upper_solve(factor, ones);
        *alpha = Self::imputed_weights(f, centred, entries, beta, &c);
        let q = centred.iter().zip(alpha.iter()).fold(T::ZERO, |acc, (y, a)| acc.add(y.mul(*a)));
        let constant = f.likelihood_constant + 0.5 * crate::math::ln(f.s1)
            - 0.5 * log_det
            - 0.5 * crate::math::ln(s1);
        schur.s1 = s1;
        Some(Fit { beta, q, constant })
    }

    /// `[lₚ | kₚ]` per distinct pair `p` into `vectors` (the forward substitutions of the unit
    /// vector in the even and odd factors).
    fn pair_vectors(
        f: &sealed::Baked,
        pairs: &[usize],
        vectors: &mut heapless::Vec<[f32; N], M>,
    ) -> Option<()> {
        let h = Self::HALF;
        vectors.clear();
        for &p in pairs {
            let mut v = [0.0f32; N];
            let (l, k) = v.split_at_mut(h);
            unit_forward(f.chol_even, p, l);
            unit_forward(f.chol_odd, p, k);
            vectors.push(v).ok()?;
        }
        Some(())
    }

    /// `P_MM` (its lower rows) into `factor`, with its row sums and total.
    fn missing_block(
        entries: &[Entry],
        vectors: &heapless::Vec<[f32; N], M>,
        factor: &mut heapless::Vec<[f32; M], M>,
    ) -> Option<([f32; M], f32)> {
        let h = Self::HALF;
        factor.clear();
        let mut rowsum = [0.0f32; M];
        let mut total = 0.0f32;
        for (i, ei) in entries.iter().enumerate() {
            let vi = vectors.get(ei.slot)?;
            let mut row = [0.0f32; M];
            for (j, (ej, r)) in entries.iter().zip(row.iter_mut()).take(i + 1).enumerate() {
                let vj = vectors.get(ej.slot)?;
                let from = ei.pair.max(ej.pair);
                let even = dot(vi.get(from..h)?, vj.get(from..h)?);
                let odd = dot(vi.get(h + from..)?, vj.get(h + from..)?);
                let pij = 0.5 * (even + ei.sign * ej.sign * odd);
                *r = pij;
                if let Some(s) = rowsum.get_mut(i) {
                    *s += pij;
                }
                if j < i {
                    if let Some(s) = rowsum.get_mut(j) {
                        *s += pij;
                    }
                    total += 2.0 * pij;
                } else {
                    total += pij;
                }
            }
            factor.push(row).ok()?;
        }
        Some((rowsum, total))
    }

    /// `u = P·Ỹ` at the missing entries, from the forward substitutions of the half sums and
    /// differences `sd`, and `1ᵀP·Ỹ − Σu` (with `1ᵀP·Ỹ = 2·gᵀs`).
    fn missing_projection(
        f: &sealed::Baked,
        sd: &[T; N],
        entries: &[Entry],
        vectors: &heapless::Vec<[f32; N], M>,
    ) -> Option<([T; M], T)> {
        let h = Self::HALF;
        let g = |p: usize| f.g.get(p).map_or(0.0, |&b| f32::from_bits(b));
        let mut fy = *sd;
        {
            let (lo, hi) = fy.split_at_mut(h);
            forward_solve(f.chol_even, lo);
            forward_solve(f.chol_odd, hi);
        }
        let (fy_lo, fy_hi) = fy.split_at(h);
        let mut u = [T::ZERO; M];
        let mut sum_u = T::ZERO;
        for (p, s) in sd.iter().take(h).enumerate() {
            sum_u = sum_u.mul_add(*s, 2.0 * g(p));
        }
        for (ui, e) in u.iter_mut().zip(entries) {
            let v = vectors.get(e.slot)?;
            let from = e.pair;
            let even = dot_t(v.get(from..h)?, fy_lo.get(from..)?);
            let odd = dot_t(v.get(h + from..)?, fy_hi.get(from..)?);
            *ui = even.mul_add(odd, e.sign);
            sum_u = sum_u.add(ui.scale(-1.0));
        }
        Some((u, sum_u))
    }

    /// `α = P·x`, 0 at the missing entries, for the residual `x = centred − β` with the
    /// missing entries imputed (`−c`).
    fn imputed_weights(
        f: &sealed::Baked,
        centred: &[T; N],
        entries: &[Entry],
        beta: T,
        c: &[T; M],
    ) -> [T; N] {
        let mut x: [T; N] = core::array::from_fn(|i| match centred.get(i) {
            Some(y) => y.add(beta.scale(-1.0)),
            None => T::ZERO,
        });
        let mut at = [0usize; M];
        for ((e, &ci), a) in entries.iter().zip(c).zip(at.iter_mut()) {
            let j = if e.sign > 0.0 { e.pair } else { N - 1 - e.pair };
            if let Some(xj) = x.get_mut(j) {
                *xj = ci.scale(-1.0);
            }
            *a = j;
        }
        let mut alpha = Self::apply_inverse(f, &x);
        for &j in at.iter().take(entries.len()) {
            if let Some(aj) = alpha.get_mut(j) {
                *aj = T::ZERO;
            }
        }
        alpha
    }
}

/// `out ← L⁻¹eₚ` for the packed factor of `cholesky_solve` (`out.len()` rows): zero above
/// `p`, so only rows `p…` are substituted, from column `p`.
fn unit_forward(packed: &[u32], p: usize, out: &mut [f32]) {
    out.fill(0.0);
    let mut offset = p * (p + 1) / 2;
    for i in p..out.len() {
        let Some(row) = packed.get(offset..offset + i + 1) else { return };
        offset += i + 1;
        let Some((&inv, off)) = row.split_last() else { return };
        let Some((head, tail)) = out.split_at_mut_checked(i) else { return };
        let Some(xi) = tail.first_mut() else { return };
        let start = if i == p { 1.0 } else { 0.0 };
        let acc = off
            .iter()
            .zip(head.iter())
            .skip(p)
            .fold(start, |acc, (&l, &xj)| acc - f32::from_bits(l) * xj);
        *xi = acc * f32::from_bits(inv);
    }
}

/// `a·b` in f32.
fn dot(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).fold(0.0, |acc, (&x, &y)| acc + x * y)
}

/// `Σ aᵢ·bᵢ` for f32 `a` and radiance `b`.
fn dot_t<T: Radiance>(a: &[f32], b: &[T]) -> T {
    a.iter().zip(b).fold(T::ZERO, |acc, (&x, y)| acc.mul_add(*y, x))
}

/// `P = L·D·Lᵀ` in place (unit lower `L` left of the diagonal, `1/Dᵢ` on it) for the lower
/// rows of a symmetric `P`; `Σ ln Dᵢ = log det P`, or `None` unless every `Dᵢ` is positive
/// and finite.
fn ldl<const M: usize>(rows: &mut heapless::Vec<[f32; M], M>) -> Option<f32> {
    let (mut mantissa, mut exponent) = (1.0f32, 0i32);
    for i in 0..rows.len() {
        let (done, rest) = rows.split_at_mut_checked(i)?;
        let row = rest.first_mut()?;
        // a_ij = P_ij − Σ_{k<j} a_ik·L_jk (a_ij = L_ij·D_j), then D_i = P_ii − Σ_k a_ik·L_ik.
        for (j, prev) in done.iter().enumerate() {
            let Some((head, tail)) = row.split_at_mut_checked(j) else { break };
            let Some(aij) = tail.first_mut() else { break };
            *aij = head.iter().zip(prev.iter()).fold(*aij, |acc, (&a, &l)| acc - a * l);
        }
        let mut d = row.get(i).copied().unwrap_or(0.0);
        for (a, prev) in
            row.iter_mut().zip(done.iter()).enumerate().map(|(k, (a, p))| (a, p.get(k)))
        {
            let inv = prev.copied().unwrap_or(0.0);
            let l = *a * inv;
            d -= *a * l;
            *a = l;
        }
        if !(d > 0.0 && d.is_finite()) {
            return None;
        }
        if let Some(diag) = row.get_mut(i) {
            *diag = 1.0 / d;
        }
        let (md, ed) = libm::frexpf(d);
        let (mm, em) = libm::frexpf(mantissa * md);
        mantissa = mm;
        exponent += ed + em;
    }
    Some(crate::math::ln(mantissa) + exponent as f32 * core::f32::consts::LN_2)
}

/// `x ← L⁻¹x` for the unit lower factor of [`ldl`].
fn unit_lower_solve<R: Radiance, const M: usize>(rows: &[[f32; M]], x: &mut [R; M]) {
    for (i, row) in rows.iter().enumerate() {
        let Some((head, tail)) = x.split_at_mut_checked(i) else { break };
        let Some(xi) = tail.first_mut() else { break };
        *xi = row.iter().zip(head.iter()).fold(*xi, |acc, (&l, &xj)| acc.mul_add(xj, -l));
    }
}

/// `x ← L⁻ᵀx` for the unit lower factor of [`ldl`].
fn unit_upper_solve<R: Radiance, const M: usize>(rows: &[[f32; M]], x: &mut [R; M]) {
    for (i, row) in rows.iter().enumerate().rev() {
        let Some((head, tail)) = x.split_at_mut_checked(i) else { continue };
        let Some(&xi) = tail.first() else { continue };
        for (&l, xj) in row.iter().zip(head.iter_mut()) {
            *xj = xj.mul_add(xi, -l);
        }
    }
}
