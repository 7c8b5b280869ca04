//! Regions: where on the sphere the light changed.
//!
//! A lamp that switches on, a door that opens, light one part of the sphere. Every global
//! statistic dilutes such a change in the noise of the rest of the sphere, and no single
//! reading need stand out (a lamp beside a brighter sun is not novel). The probe therefore
//! also watches eight overlapping regions, fixed in the world: smooth bumps
//! `m_o(x) = f(x·c_o)` about the directions `c_o = (±1, ±1, ±1)/√3`, with
//! `f(t) = ((t − t₀)/(1 − t₀))²` for `t > t₀ = 0.3` (72.5° from the centre; every direction
//! lies in one to four of them).
//!
//! - **The reading.** A region's reading is the bump-weighted mean of the update's rotated
//!   samples, without the sample that weighs most in it: a firefly, or a single hit of a
//!   lamp, moves it no further (the re-reads see those). The rest must weigh [`WEIGHT`] or
//!   more (a dozen samples or so): with fewer, in a path-traced room at `N = 16`, two readings
//!   in a row strayed alike too often, and a probe of fewer than 35 rotated directions takes
//!   no readings ([`tested`]).
//! - **What is usual.** The probe keeps each region's running mean reading (the mean of all
//!   updates at first, then over the last 16 or so: [`GAIN`]) and a running 95th percentile
//!   of the relative deviation `q = |y − ȳ|/|ȳ|` (channels summed), learned as the level
//!   test learns its spread. While a region learns (its first [`LEARN`] updates) the spread
//!   is the largest deviation seen, a cautious start.
//! - **A change.** A deviation beyond [`FLAG`] times the spread and beyond a tenth of the
//!   region's reading flags the region; the next update's deviation there, flagged too and
//!   of the same sign, confirms it. Two updates in a row make a firefly's double hit or a
//!   sun's unlucky draw rare; one of them would make every such draw a change.
//! - **From one place.** A brightening is confirmed only if both readings were brightened
//!   most from the same place: the samples that rose most above the region's mean lie
//!   within 30° ([`REPEAT_ANGLE`]). Outliers in two updates in a row lie anywhere in the
//!   region; a lamp's hits lie on the lamp. On the training maps at `N = 256`, with 1 % of
//!   rays reading 100×, this halved the false resets (27 → 13 per 1 000, `smooth` light;
//!   11 → 7 `clamp`) at the cost of one sequence in 24 of the 30° rotation at `N = 64`.
//!   A darkening needs no place: outliers do not darken. Re-reading the brightest sample of
//!   a flagged region instead (as a novel reading is re-read) was measured too and not
//!   kept: a static bright sample repeats as well as a lamp, and at `N = 64` false resets
//!   on static light rose from 2 to 11 per 1 000.
//! - **Then.** A confirmed change is certain: the state restarts, as at any reset, and
//!   [`super::TemporalProbe::last_changed_regions`] names the regions.
//!
//! # Why a restart, not forgetting in the region alone
//! Forgetting only where the light changed was built and measured first, and not kept:
//! - **The design.** The state's mean moved, in the changed regions, towards a running mean
//!   restarted at the change: the projection of the update's innovations `yⱼ − ŷⱼ` weighted
//!   by the regions' share `M(x)`. With `M = Σ (1 + √3·x·c_o)²/16` (a partition of unity of
//!   degree 2) and the correction confined to the degrees `l ≤ L − 2`, the light's degrees
//!   above `L` leak nothing into it.
//! - **Measured on the training maps** (6 sequences per map and scenario) it gave what the
//!   restart gives, within noise: a lamp switching on at `N = 256`, error / oracle 1.93
//!   against 1.80 at `k = 4` and 2.61 against 2.70 at `k = 16`; static light the same.
//! - **And it was wrong over long static streams.** The share `M` is below one half even at
//!   a region's centre (a smooth mask of low degree cannot be sharp), so the restarted mean
//!   converged like `k^(−M)`, not `1/k`. After 10⁴ static updates without forgetting, a
//!   false local change at `N = 16` left errors 5–12 times the error bar, where a restart
//!   leaves none. A second state for the changed region, blended with a mask at the
//!   queries, would converge properly; it would also double the state.

use super::Vec3;
use crate::radiance::Radiance;

/// The regions: bumps about the eight directions `(±1, ±1, ±1)/√3`.
pub(super) const REGIONS: usize = 8;
/// Where a bump ends: `t₀ = cos 72.5°`.
const EDGE: f64 = 0.3;
/// The running means' gain once they have 16 updates.
const GAIN: f32 = 1.0 / 16.0;
/// Updates a region learns before it is tested.
const LEARN: u16 = 8;
/// A deviation flags its region beyond this many times its spread.
const FLAG: f32 = 5.0;
/// The spread's step up for a deviation above it (`e^(19/64)`): with the step down, it
/// settles where one deviation in 20 exceeds it.
const SPREAD_UP: f32 = 1.345_647;
/// The spread's step down (`e^(1/64)`).
const SPREAD_DOWN: f32 = 1.015_748;
/// The least bump weight a region's reading must rest on (about 12 samples in the bump, whose
/// mean weight is 1/3): readings of fewer samples stray alike twice in a row too often, and
/// a probe of a few dozen rays has no region test.
const WEIGHT: f32 = 4.0;
/// Whether a probe of `n` rotated directions tests its regions: where a region's expected
/// weight, `n·(1 − EDGE)/6`, reaches [`WEIGHT`] (`n ≥ 35`). Below, a reading would rarely
/// rest on enough samples, and the readings are not taken.
pub(super) const fn tested(n: usize) -> bool {
    n as f64 * (1.0 - EDGE) / 6.0 >= WEIGHT as f64
}

/// The cosine of the largest angle between where two brightenings in a row lay (30°).
const REPEAT_ANGLE: f32 = 0.866_025_4;
/// A deviation below this share of the region's level is no change.
const RELEVANT: f32 = 0.1;

/// The bump's weight at `t = x·c`.
pub(super) fn bump(t: f32) -> f32 {
    let edge = EDGE as f32;
    if t > edge {
        let u = (t - edge) / (1.0 - edge);
        u * u
    } else {
        0.0
    }
}

/// The centre of region `o`: bit 0 of `o` set for `x < 0`, bit 1 for `y < 0`, bit 2 for
/// `z < 0`.
pub(super) fn centre(o: usize) -> Vec3 {
    const S: f32 = 0.577_350_26;
    let sign = |bit: usize| if o & (1 << bit) != 0 { -S } else { S };
    Vec3::new(sign(0), sign(1), sign(2))
}

/// The cosine of a bump's radius.
pub(super) const COS_RADIUS: f32 = EDGE as f32;

/// What the probe knows of one region.
#[derive(Clone, Copy, Debug)]
pub(super) struct Region<T> {
    /// The running mean of the region's reading.
    mean: T,
    /// The running 95th percentile of the deviation's relative size.
    spread: f32,
    /// Updates learned since the last reset (saturating).
    learned: u16,
    /// The deviation of the last update and its reading's [`Reading::at`], if it flagged the
    /// region.
    flagged: Option<(T, Vec3)>,
}

impl<T: Radiance> Region<T> {
    pub(super) const EMPTY: Self = Self { mean: T::ZERO, spread: 0.0, learned: 0, flagged: None };

    /// Rescales the region's statistics by `one`.
    pub(super) fn rescale(&mut self, one: impl Fn(T) -> T) {
        self.mean = one(self.mean);
        self.flagged = self.flagged.map(|(d, at)| (one(d), at));
    }
}

/// One update's reading of a region.
#[derive(Clone, Copy, Debug)]
pub(super) struct Reading<T> {
    /// The bump-weighted mean of the samples without the one that weighs most (`m·|y|`).
    pub(super) value: T,
    /// The direction of the sample, among the rest, that brightens the reading most above
    /// the region's mean (`m·(|y| − |ȳ|)`).
    pub(super) at: Vec3,
}

/// Each region's [`Reading`] (`None` where the rest weigh less than [`WEIGHT`]).
pub(super) fn readings<T: Radiance, const N: usize>(
    directions: &[Vec3; N],
    samples: &[T; N],
    regions: &[Region<T>; REGIONS],
) -> [Option<Reading<T>>; REGIONS] {
    // Regions o and 7 − o are opposite: one dot product serves both, and at most one of
    // them holds a direction.
    let centres: [Vec3; REGIONS / 2] = core::array::from_fn(centre);
    let means = regions.each_ref().map(|r| size(r.mean));
    let mut acc = [Accumulator::<T>::EMPTY; REGIONS];
    for (j, (&x, &y)) in directions.iter().zip(samples).enumerate() {
        let b = size(y);
        for (o, c) in centres.iter().enumerate() {
            let t = x.dot(*c);
            let (r, m) = if t >= 0.0 { (o, bump(t)) } else { (REGIONS - 1 - o, bump(-t)) };
            let a = &mut acc[r];
            if m <= 0.0 {
                continue;
            }
            a.sum = a.sum.mul_add(y, m);
            a.total += m;
            let (key, above) = (m * b, m * (b - means[r]));
            if key > a.heaviest.key {
                // The old heaviest joins the rest.
                if a.heaviest.above > a.brightest.1 {
                    a.brightest = (a.heaviest.index, a.heaviest.above);
                }
                a.heaviest = Heaviest { m, index: j, key, above };
            } else if above > a.brightest.1 {
                a.brightest = (j, above);
            }
        }
    }
    acc.map(|a| {
        let rest = a.total - a.heaviest.m;
        (rest >= WEIGHT).then(|| Reading {
            value: a.sum.mul_add(samples[a.heaviest.index], -a.heaviest.m).scale(1.0 / rest),
            at: directions[a.brightest.0],
        })
    })
}

/// One region's sums over an update's samples.
#[derive(Clone, Copy)]
struct Accumulator<T> {
    /// `Σ m·y` and `Σ m`.
    sum: T,
    total: f32,
    /// The sample that weighs most (`m·|y|`).
    heaviest: Heaviest,
    /// Among the rest, the index and `m·(|y| − |ȳ|)` of the one most above the mean.
    brightest: (usize, f32),
}

/// The sample of a region that weighs most: its bump weight, index, `m·|y|` and
/// `m·(|y| − |ȳ|)`.
#[derive(Clone, Copy)]
struct Heaviest {
    m: f32,
    index: usize,
    key: f32,
    above: f32,
}

impl<T: Radiance> Accumulator<T> {
    const EMPTY: Self = Self {
        sum: T::ZERO,
        total: 0.0,
        heaviest: Heaviest { m: 0.0, index: 0, key: -1.0, above: 0.0 },
        brightest: (0, f32::NEG_INFINITY),
    };
}

/// Weighs one update's region readings: learns the regions, and returns the regions where
/// this update confirmed a local change (bit `o` for region `o`), whose readings restart.
pub(super) fn weigh<T: Radiance>(
    regions: &mut [Region<T>; REGIONS],
    found: &[Option<Reading<T>>; REGIONS],
) -> u8 {
    let mut confirmed = 0u8;
    for (o, (region, found)) in regions.iter_mut().zip(found).enumerate() {
        let Some(Reading { value: y, at }) = *found else {
            region.flagged = None;
            continue;
        };
        if region.learned == 0 {
            (region.mean, region.learned) = (y, 1);
            continue;
        }
        let d = y.add(region.mean.scale(-1.0));
        if region.learned >= LEARN && flags(d, region.spread, region.mean) {
            if region.flagged.is_some_and(|(b, before)| repeats(b, before, d, at)) {
                // The region's light changed: its reading restarts here, and is tested again
                // once it has learned anew (a restart at an outlier would otherwise call the
                // next ordinary readings a change).
                (region.mean, region.learned) = (y, 1);
                region.flagged = None;
                confirmed |= 1 << o;
            } else {
                region.flagged = Some((d, at));
            }
        } else {
            region.flagged = None;
            learn(region, d);
        }
    }
    confirmed
}

/// The size of a reading or deviation: the sum of its channels' magnitudes.
fn size<T: Radiance>(d: T) -> f32 {
    (0..T::CHANNELS).map(|c| d.channel(c).abs()).sum()
}

/// Whether deviation `d` flags a region of spread `spread` and mean reading `mean`.
fn flags<T: Radiance>(d: T, spread: f32, mean: T) -> bool {
    let q = size(d) / size(mean);
    q > FLAG * spread && q > RELEVANT
}

/// Whether deviation `d` of a reading brightened most at `at` ([`Reading::at`]) repeats
/// deviation `b` of the previous one (at `before`): the same way (their channels' dot
/// product), and, for a brightening, from the same place (within [`REPEAT_ANGLE`]): two
/// outliers in a row brighten a region from unrelated places, a lamp from its own.
fn repeats<T: Radiance>(b: T, before: Vec3, d: T, at: Vec3) -> bool {
    let dot: f32 = (0..T::CHANNELS).map(|c| b.channel(c) * d.channel(c)).sum();
    let brighter: f32 = (0..T::CHANNELS).map(|c| d.channel(c)).sum();
    dot > 0.0 && (brighter <= 0.0 || before.dot(at) > REPEAT_ANGLE)
}

/// Adds deviation `d` from the region's mean to its running mean and spread.
fn learn<T: Radiance>(region: &mut Region<T>, d: T) {
    region.learned = region.learned.saturating_add(1);
    let g = (1.0 / f32::from(region.learned)).max(GAIN);
    let q = size(d) / size(region.mean);
    region.mean = region.mean.mul_add(d, g);
    // While it learns, the spread is the largest deviation seen (the early means are
    // rough, so their deviations are large: a cautious start); then a running percentile.
    // A region lit after a dark start deviates infinitely far: no spread learns that.
    if !q.is_finite() {
        return;
    }
    region.spread = if region.learned <= LEARN {
        region.spread.max(q)
    } else if q > region.spread {
        region.spread * SPREAD_UP
    } else {
        region.spread / SPREAD_DOWN
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feeds `readings` to one region, returning the updates that confirmed a change.
    fn run(readings: &[f32]) -> ([bool; 64], Region<f32>) {
        run_at(readings, |_| Vec3::Z)
    }

    /// [`run`] with update `k`'s reading brightened most at `at(k)`.
    fn run_at(readings: &[f32], at: impl Fn(usize) -> Vec3) -> ([bool; 64], Region<f32>) {
        let mut regions = [Region::<f32>::EMPTY; REGIONS];
        let mut confirmed = [false; 64];
        for (k, &y) in readings.iter().enumerate() {
            let mut found = [None; REGIONS];
            found[0] = Some(Reading { value: y, at: at(k) });
            confirmed[k] = weigh(&mut regions, &found) & 1 != 0;
        }
        (confirmed, regions[0])
    }

    #[test]
    fn a_region_lit_after_a_dark_start_keeps_a_finite_spread() {
        let mut readings = [1.0f32; 40];
        readings[..3].fill(0.0);
        let (confirmed, region) = run(&readings);
        assert!(region.spread.is_finite(), "{region:?}");
        assert!(!confirmed.iter().any(|&c| c), "{confirmed:?}");
    }

    #[test]
    fn a_step_is_confirmed_on_its_second_update_and_noise_is_not() {
        // A reading alternating ±5 % about 1, then ×2 from update 30 on.
        let mut readings = [0.0f32; 40];
        for (k, y) in readings.iter_mut().enumerate() {
            let noise = if k % 2 == 0 { 1.05 } else { 0.95 };
            *y = if k < 30 { noise } else { 2.0 * noise };
        }
        let (confirmed, _) = run(&readings);
        let at: [usize; 1] = [31];
        for (k, &c) in confirmed.iter().enumerate().take(40) {
            assert_eq!(c, at.contains(&k), "update {k}: {confirmed:?}");
        }
    }

    #[test]
    fn a_brightening_is_confirmed_from_one_place_and_not_from_two() {
        // Noise about 1, then ×2 at updates 30 and 31 (outliers) and from 40 on (a lamp).
        let mut readings = [0.0f32; 50];
        for (k, y) in readings.iter_mut().enumerate() {
            let noise = if k % 2 == 0 { 1.05 } else { 0.95 };
            *y = if k == 30 || k == 31 || k >= 40 { 2.0 * noise } else { noise };
        }
        // The outliers lie 40° apart; the lamp's heaviest samples 10° apart.
        let at = |k: usize| {
            let degrees: f32 = match k {
                31 => 40.0,
                _ if k >= 40 && k % 2 == 1 => 10.0,
                _ => 0.0,
            };
            let r = degrees.to_radians();
            Vec3::new(crate::math::sin(r), 0.0, crate::math::cos(r))
        };
        let (confirmed, _) = run_at(&readings, at);
        for (k, &c) in confirmed.iter().enumerate().take(50) {
            assert_eq!(c, k == 41, "update {k}: {confirmed:?}");
        }
        // A darkening needs no place: the same readings ÷ 2 are confirmed at update 31.
        let darker = readings.map(|y| if y > 1.5 { y / 4.0 } else { y });
        let (confirmed, _) = run_at(&darker, at);
        assert!(confirmed[31], "{confirmed:?}");
    }
}

#[cfg(test)]
mod size_tests {
    use super::*;
    use crate::{RotationSequence, SphericalFibonacci};

    /// The share of region readings taken over `rotations` rotations of an `N`-point set.
    fn share_read<const N: usize>(rotations: usize) -> f64 {
        let mut seq = RotationSequence::new(5);
        let (mut read, mut total) = (0usize, 0usize);
        for _ in 0..rotations {
            let set = SphericalFibonacci::<N>::new();
            let Ok(set) = set.with_rotation(seq.next_rotation()) else { continue };
            let found = readings(&set.points(), &[1.0f32; N], &[Region::EMPTY; REGIONS]);
            read += found.iter().filter(|r| r.is_some()).count();
            total += REGIONS;
        }
        read as f64 / total as f64
    }

    /// Below `tested`'s threshold no reading would have been taken anyway: skipping them
    /// changes nothing. Above it, readings are taken.
    #[test]
    fn sizes_without_a_region_test_never_had_a_reading() {
        assert!(!tested(34) && tested(35));
        assert_eq!(share_read::<15>(500), 0.0);
        assert_eq!(share_read::<30>(500), 0.0);
        assert_eq!(share_read::<34>(500), 0.0);
        assert!(share_read::<62>(100) > 0.99);
    }
}
