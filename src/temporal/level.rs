//! The level test: does this update's mean radiance agree with the state's?
//!
//! Re-reads see a change where a slot looks, and only as far as their own noise allows: in a
//! path-traced scene the caps of module `reread` hold a slot's evidence to a few nats, and a
//! light that switches off there, leaving the interreflection of the rest, goes unseen. It
//! moves the level of every update, though. The probe compares the mean brightness of each
//! update's rotated samples, without the brightest one (a single outlier of a path tracer
//! does not move it), with the state's level, as `x = |ln(update/state)|`, divided by
//! `√(1 + 1/w)` for a state of `w` updates (its own noise).
//!
//! How far `x` strays under static light depends on the scene (its aliasing, the tracer's
//! noise), so the probe learns it: the spread `s` is a running 95th percentile of `x`, up by
//! [`SPREAD_UP`] where `x` exceeds it and down by [`SPREAD_DOWN`] else. A level beyond the
//! spread is evidence of a change, `(x − s)·ln 20/s`: as if the tail beyond the 95th
//! percentile fell twentyfold with each further `s`. A level below [`DARK`] times the other
//! is dark: a change for certain (the light switched off, or on in the dark). The test
//! counts after [`HISTORY`] updates and adds to the re-reads' evidence. The spread starts at
//! [`SPREAD_START`] and comes down by `e^(1/64)` per update, so over the first hundred or so
//! updates only a level off by a factor of 1.5 or more counts. On the training maps it changes
//! no decision (their re-reads already see every global change); in the path-traced room it
//! detects the light switching off and on (`docs/room.md`).

use crate::radiance::Radiance;

use super::reread::brightness;

/// Where the spread starts (`x` of a level off by a factor `e^0.5`).
pub(super) const SPREAD_START: f32 = 0.5;
/// The spread's step up for an `x` above it (`e^(19/64)`): with the step down, it settles
/// where one `x` in 20 exceeds it.
pub(super) const SPREAD_UP: f32 = 1.345_647;
/// The spread's step down for an `x` within it (`e^(1/64)`).
pub(super) const SPREAD_DOWN: f32 = 1.015_748;
/// The spread's floor: a level within 2 % of the state's is never evidence.
pub(super) const SPREAD_FLOOR: f32 = 0.02;
/// The updates the spread learns from before the test counts.
pub(super) const HISTORY: u32 = 8;
/// `ln 20`: the evidence of a level one spread beyond the spread.
const TAIL: f32 = 2.995_732;
/// A level below this share (`2⁻²⁰`) of the other is dark: a change no noise makes, which the
/// spread does not learn.
pub(super) const DARK: f32 = 1.0 / 1_048_576.0;
/// The evidence of a dark level against a lit one: beyond any prior and any evidence of the
/// innovation against a change, so that the old evidence is dropped exactly (a reset that
/// kept a trace of the old light would leave a lit state beside dark updates).
const DECISIVE: f32 = 64.0;

/// The mean brightness ([`brightness`]) of `readings` without the brightest one (all of them
/// for one reading).
pub(super) fn trimmed_mean<T: Radiance>(readings: &[T]) -> f32 {
    let (mut total, mut top) = (0.0f32, 0.0f32);
    for &y in readings {
        let b = brightness(y);
        total += b;
        top = top.max(b);
    }
    match readings.len() {
        0 => 0.0,
        1 => total,
        n => (total - top) / (n - 1) as f32,
    }
}

/// `|ln(update/state)|`, the lower level taken as at least [`DARK`] times the higher (two
/// levels of 0 are 0 apart), and whether one of them is dark.
pub(super) fn distance(update: f32, state: f32) -> (f32, bool) {
    let (low, high) = if update < state { (update, state) } else { (state, update) };
    if high > 0.0 {
        let dark = low < DARK * high;
        (crate::math::ln(high / low.max(DARK * high)), dark)
    } else {
        (0.0, false)
    }
}

/// The evidence of a change from a level `x` away, against the spread `s`, and the spread
/// after learning `x` (unchanged for a dark level against a lit one).
pub(super) fn weigh((x, dark): (f32, bool), spread: f32) -> (f32, f32) {
    if dark {
        (DECISIVE, spread)
    } else if x > spread {
        ((x - spread) * TAIL / spread, spread * SPREAD_UP)
    } else {
        (0.0, (spread / SPREAD_DOWN).max(SPREAD_FLOOR))
    }
}

/// Drift: a level that moves steadily leaves the pooled state behind by about
/// `g·(w + 1)/2` for a drift `g` (in `ln` per update) and a state of `w` updates, which no
/// single update shows. Levels here are trimmed means ([`trimmed_mean`]), the state's the
/// same pooling of the updates' trimmed levels (so that the brightest sample's skew cancels).
/// The probe keeps the running mean `z̄` of the lag standardised by its noise,
/// `z = (update/state − 1)/(σ·√(1 + 1/w))` (relative, not in logs: a mean of levels has the
/// mean level, a mean of their logs does not), each `z` clipped to ±[`CLIP`] (an outlier
/// moves it little), with `σ` the updates' own relative level noise, learned from their
/// changes from one update to the next (`σ² ≈ E[d²]/2`). A drift is a change of the light
/// like any other, as rare as the hazard `h` says: where `z̄` lies beyond
/// `k = √(2·ln(1/h)) + 1` standard errors (its evidence, `z̄²/2se²`, beyond the prior odds,
/// and one more for the drift fitted and the heavy tails of aliasing; `k ≈ 3.9` at the
/// default hazard), the drift beyond that noise is `g = 2·(|z̄| − k·se)·σ·√(1 + 1/w)/(w + 1)`
/// and the state pools no more than the `w* = ∛(2σ²/g²)` updates that minimise its level
/// error `g²w²/4 + σ²/w`. Elsewhere static light pools as before.
#[derive(Clone, Copy, Debug)]
pub(super) struct Drift {
    /// The last update's level.
    last: f32,
    /// The updates' levels pooled as the state pools them.
    pooled: f32,
    /// The running mean of `d²/2` for `d` the relative change of level between updates.
    noise: f32,
    /// The running mean of the clipped standardised lag `z`.
    lag: f32,
    /// Updates observed (saturating), and since the last reset.
    count: u16,
    since: u16,
}

/// The lag's gain (about 15 updates' memory) and the noise's (31).
const LAG_GAIN: f32 = 1.0 / 8.0;
const NOISE_GAIN: f32 = 1.0 / 16.0;
/// The standard errors a drift must add to the prior odds' (for the drift fitted, and for the
/// heavy tails of aliasing).
const OCCAM: f32 = 1.0;
/// A standardised lag is clipped to this.
const CLIP: f32 = 4.0;

impl Drift {
    pub(super) const EMPTY: Self =
        Self { last: 0.0, pooled: 0.0, noise: 0.0, lag: 0.0, count: 0, since: 0 };

    /// Pools an update's level `update` into the state's, the old times `keep`.
    pub(super) fn pool(&mut self, keep: f32, update: f32) {
        self.pooled = self.pooled * keep + update;
    }

    /// Observes an update's level `update` against the state of `w` updates (a level of 0 or
    /// less teaches nothing).
    pub(super) fn observe(&mut self, update: f32, w: f32) {
        let state = if w > 0.0 { self.pooled / w } else { 0.0 };
        if !(update > 0.0 && state > 0.0 && update.is_finite() && state.is_finite()) {
            return;
        }
        if self.count > 0 {
            let d = (update - self.last) / state;
            let n = f32::from(self.count);
            self.noise += (0.5 * d * d - self.noise) * (1.0 / n).max(NOISE_GAIN);
        }
        self.last = update;
        self.count = self.count.saturating_add(1);
        if self.noise > 0.0 {
            let scale = crate::math::sqrt(self.noise * (1.0 + 1.0 / w));
            let z = ((update / state - 1.0) / scale).clamp(-CLIP, CLIP);
            self.since = self.since.saturating_add(1);
            let gain = (1.0 / f32::from(self.since)).max(LAG_GAIN);
            self.lag += (z - self.lag) * gain;
        }
    }

    /// The most old evidence (in updates) a state of `w` updates should keep under the drift
    /// seen, for a prior log odds `prior_log_odds` of a change: `w* − 1`, or infinity where no
    /// drift is significant.
    pub(super) fn cap(&self, w: f32, prior_log_odds: f32) -> f32 {
        // The standard error of the running mean of independent z (`1/√15` for the gain).
        let se = crate::math::sqrt(LAG_GAIN / (2.0 - LAG_GAIN));
        let k = crate::math::sqrt(2.0 * (-prior_log_odds).max(0.0)) + OCCAM;
        if u32::from(self.since) < HISTORY || self.lag.abs() <= k * se {
            return f32::INFINITY;
        }
        // The lag beyond its noise: a barely significant one caps little.
        let beyond = self.lag.abs() - k * se;
        let g = 2.0 * beyond * crate::math::sqrt(self.noise * (1.0 + 1.0 / w)) / (w + 1.0);
        let best = crate::math::powf(2.0 * self.noise / (g * g), 1.0 / 3.0);
        (best - 1.0).max(0.0)
    }

    /// After a reset to an update of level `update`: the state lags no more.
    pub(super) fn restart(&mut self, update: f32) {
        (self.lag, self.since) = (0.0, 0);
        if update > 0.0 && update.is_finite() {
            self.last = update;
            self.count = self.count.max(1);
        }
    }

    /// Levels rescaled by `2^k`.
    pub(super) fn rescale(&mut self, k: i32) {
        self.last = super::scale::ldexp_saturating(self.last, k);
        self.pooled = super::scale::ldexp_saturating(self.pooled, k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_brightest_reading_is_left_out() {
        assert_eq!(trimmed_mean(&[1.0f32, 3.0, 1e6]), 2.0);
        assert_eq!(trimmed_mean(&[[1.0f32, 1.0, 1.0], [2.0, 2.0, 2.0]]), 3.0);
        assert_eq!(trimmed_mean(&[5.0f32]), 5.0);
        assert_eq!(trimmed_mean::<f32>(&[]), 0.0);
    }

    #[test]
    fn the_spread_settles_where_one_level_in_20_exceeds_it() {
        // x uniform on [0, 1) (a fixed low-discrepancy sequence); then x scaled by 10: the
        // spread follows, and one x in 20 exceeds it either way.
        for scale in [1.0f32, 10.0] {
            let mut s = SPREAD_START;
            let mut above = 0u32;
            for k in 0..20_000u32 {
                let x = scale * (k as f32 * 0.618_034).fract();
                if k >= 10_000 && x > s {
                    above += 1;
                }
                s = weigh((x, false), s).1;
            }
            let share = above as f32 / 10_000.0;
            assert!((share - 0.05).abs() < 0.005, "{share}");
        }
    }

    #[test]
    fn evidence_grows_beyond_the_spread() {
        let lit = |x: f32| (x, false);
        assert_eq!(weigh(lit(0.1), 0.2).0, 0.0);
        assert!((weigh(lit(0.4), 0.2).0 - TAIL).abs() < 1e-6);
        assert!(weigh(lit(0.6), 0.2).0 > weigh(lit(0.4), 0.2).0);
        assert_eq!(weigh(lit(0.0), SPREAD_FLOOR).1, SPREAD_FLOOR);
        // Dark against lit: evidence, and the spread does not learn it.
        let (e, s) = weigh(distance(0.0, 1.0), 0.5);
        assert!(e == DECISIVE && s == 0.5, "{e}, {s}");
    }

    #[test]
    fn levels_are_compared_in_logs_down_to_dark() {
        let (x, dark) = distance(0.5, 1.0);
        assert!((x - core::f32::consts::LN_2).abs() < 1e-6 && !dark);
        let (x, dark) = distance(0.0, 1.0);
        assert!((x - 13.862_944).abs() < 1e-4 && dark);
        assert_eq!(distance(1.0, 0.0), distance(0.0, 1.0));
        // Ratios only: the same at any scale.
        assert_eq!(distance(0.0, 1e-30), distance(0.0, 1.0));
        assert!(!distance(1e-31, 1e-30).1);
        assert_eq!(distance(0.0, 0.0), (0.0, false));
    }

    /// Runs `levels` through a drift estimator pooled as the probe pools (no other
    /// forgetting); returns the mean weight over the second half and the share of updates
    /// whose cap was below 64 (the probe's prior keeps about 64 updates anyway).
    fn pool_levels(levels: &[f32]) -> (f32, f32) {
        let (mut drift, mut w, mut capped, mut late) = (Drift::EMPTY, 0.0f32, 0u32, 0.0f32);
        for (k, &level) in levels.iter().enumerate() {
            let cap = drift.cap(w, -4.143_135);
            let kept = w.min(cap);
            if w > 0.0 {
                drift.observe(level, w);
                capped += u32::from(cap < 64.0);
            }
            drift.pool(if w > 0.0 { kept / w } else { 0.0 }, level);
            w = kept + 1.0;
            if 2 * k >= levels.len() {
                late += w;
            }
        }
        let n = levels.len() as f32;
        (2.0 * late / n, capped as f32 / (n - 1.0))
    }

    /// Lognormal noise of `sigma` from a fixed sequence, with a sun hit (×1.5) one update in
    /// ten: skewed, as the trimmed levels of a map with a sun are.
    fn noisy(k: u32, sigma: f32) -> f32 {
        let mut r = crate::rotation::RotationSequence::new(u64::from(k));
        let (u, v, hit) = (r.next_f32().max(1e-7), r.next_f32(), r.next_f32());
        let normal = crate::math::sqrt(-2.0 * crate::math::ln(u))
            * crate::math::cos(core::f32::consts::TAU * v);
        crate::math::exp(sigma * normal) * if hit < 0.1 { 1.5 } else { 1.0 }
    }

    #[test]
    fn static_levels_pool_without_a_cap() {
        let levels: [f32; 4000] = core::array::from_fn(|k| noisy(k as u32, 0.05));
        let (_, capped) = pool_levels(&levels);
        assert!(capped < 0.01, "capped {capped}");
    }

    #[test]
    fn a_steady_drift_pools_a_short_window() {
        // 1 % per update: pooling everything would lag by a factor e^(0.01·w/2) (a mean
        // weight of 300 over the second half); the best window for σ = 0.05 (and the sun's
        // skew) is ∛(2σ²/g²) ≈ 3.7 updates, and the drift beyond the noise estimates a few
        // times that.
        let levels: [f32; 400] =
            core::array::from_fn(|k| crate::math::exp(0.01 * k as f32) * noisy(k as u32, 0.05));
        let (w, capped) = pool_levels(&levels);
        assert!((3.0..40.0).contains(&w) && capped > 0.1, "w = {w}, capped {capped}");
    }
}
