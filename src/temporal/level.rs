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
}
