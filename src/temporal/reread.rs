//! Re-reads: the `S` rays per update that look again where earlier updates looked, so that a
//! change shows as the difference of two readings of one direction, which aliasing cannot fake
//! (A-SVGF's re-shading of last frame's samples, for a probe).
//!
//! Each slot tracks one direction for [`TRACK`] updates or more (the slots in turn, so that
//! some are verified at every update), then moves to the brightest of the latest update's
//! rotated samples (a global change moves the bright readings most, and a light that
//! switches off was bright), or to the *spot*, the brightest reading verified since the last
//! reset, where that is brighter and unwatched: a small lamp that the rotated rays hit only
//! now and then keeps a slot on it. Its readings pass through states:
//! - *new*: a rotated sample's reading, not yet re-read; the re-read verifies it, or the two
//!   disagree (*disputed*) and a third reading decides which was the outlier, without
//!   evidence either way;
//! - *verified*: a change from it is an alarm. An alarm counts at once only where alarms come
//!   from three octants of the sphere together (a global change; its evidence capped at
//!   [`CONTAMINATION`] each: one ray in 32 may be an outlier); else the slot becomes
//! - *suspect*: its next reading refutes the change (back at the verified reading: a firefly
//!   or a flicker, no evidence) or confirms it (it agrees with the changed reading: the
//!   alarm's full evidence).
//!
//! A *novel* reading, the update's brightest and far brighter than anything its octant has
//! seen since the last reset ([`novelty`]), is re-read by two slots at once (taken from the
//! directions they verify if none is free): a lamp that switched on is then confirmed at the
//! next update, where a firefly would have to repeat twice.
//!
//! Readings of one direction need not repeat exactly: a path tracer's rays are noisy. The
//! probe learns the 90th percentile of `(b − a)²/(a² + b²)` over its pairs of readings and
//! counts a difference within it as no change.
//!
//! Where readings are that noisy, a change seen by one slot proves little: two readings in a
//! row may stray by chance. The probe therefore also keeps the share `r` of re-reads that
//! disagree with the reading they re-read where no change followed (an alarm that its next
//! reading confirms is left out), and an alarm and its confirmation are worth at most
//! `−ln(S·r²)`, a fresh alarm `−ln(S·r)`: as rare as that under static light. Where readings
//! repeat exactly (a map) `r` stays near zero and the caps do not bind; in a path-traced room
//! they cut false resets about fivefold (`docs/room.md`).

use super::Vec3;
use crate::radiance::Radiance;

/// Updates a slot tracks one direction before it moves to another.
pub(super) const TRACK: u16 = 4;
/// How much brighter than the brightest earlier reading in its octant a reading of `rays`
/// rotated rays per update must be to be novel: `2048/rays` within `[8, 32]` (32 at 64 rays,
/// 8 at 256). On static light a first hit of a small bright spot looks the same; the
/// fewer the rays, the later an octant's peak settles, and the higher the bar that keeps
/// such hits below one in a thousand updates on the training maps (`docs/temporal.md`).
pub(super) const fn novelty(rays: usize) -> f32 {
    let r = 2048.0 / rays as f32;
    if r < 8.0 {
        8.0
    } else if r > 32.0 {
        32.0
    } else {
        r
    }
}
/// The log Bayes factor of a confirmed novel reading at the bar [`novelty`]: `ln 64`, a
/// change at the default hazard (more above the bar by `ln(ratio/bar)`).
pub(super) const NOVEL_EVIDENCE: f32 = 4.158_883;
/// The pooled updates an octant's peak must rest on before a reading can be novel.
pub(super) const NOVEL_HISTORY: f32 = 8.0;
/// The repeat noise's running 90th percentile steps down by this factor for a pair below
/// it (`e^(1/32)`), and up by its ninth power for one above.
pub(super) const REPEAT_STEP: f32 = 1.031_743;
/// `REPEAT_STEP⁹`.
pub(super) const REPEAT_UP: f32 = 1.324_784;
/// Below this the repeat noise is nil (readings that repeat exactly, as a map's do).
pub(super) const REPEAT_FLOOR: f32 = 1e-6;
/// The weight of each re-read in the running share of disagreeing ones.
pub(super) const DISAGREE_GAIN: f32 = 1.0 / 32.0;
/// The share's floor, and where a new state starts (`2⁻²⁰`: on exact re-reads the caps never
/// bind).
pub(super) const DISAGREE_FLOOR: f32 = 1.0 / 1_048_576.0;
/// The slots that re-read a novel reading (at most).
pub(super) const NOVEL_REREADS: usize = 2;
/// The log Bayes factor one fresh slot can add at most: `ln 32`, as if one reading in 32
/// were an outlier.
pub(super) const CONTAMINATION: f32 = 3.465_736;

/// A slot's state: what its next reading is compared with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    /// No direction to re-read (before the first update).
    Empty,
    /// A rotated sample's reading, not yet re-read.
    New,
    /// Two readings that disagree: the third decides which was the outlier.
    Disputed,
    /// A reading that its re-read repeated: a change from it is evidence.
    Verified,
    /// The last reading changed from the verified one: this one confirms or refutes it.
    Suspect,
}

/// One re-read slot, in the state's units: its kind, the reference reading (verified, or
/// the one to verify), the other (the latest, changed reading), the evidence a confirmation
/// brings, and the updates it has tracked its direction.
#[derive(Clone, Copy, Debug)]
pub(super) struct Slot<T> {
    pub kind: Kind,
    pub reference: T,
    pub other: T,
    pub evidence: f32,
    pub age: u16,
}

impl<T: Radiance> Slot<T> {
    pub const EMPTY: Self =
        Self { kind: Kind::Empty, reference: T::ZERO, other: T::ZERO, evidence: 0.0, age: 0 };
}

/// The octant of a direction (the signs of its components): the regions whose alarms count
/// apart.
pub(super) fn octant(d: Vec3) -> u32 {
    u32::from(d.x < 0.0) | u32::from(d.y < 0.0) << 1 | u32::from(d.z < 0.0) << 2
}

/// The brightness that ranks the readings to re-read: the sum of the channels' positive
/// parts.
pub(super) fn brightness<T: Radiance>(y: T) -> f32 {
    (0..T::CHANNELS).map(|c| y.channel(c).max(0.0)).sum()
}

/// `(b − a)²/(a² + b²)` of two readings' brightness (0 for two dark ones): how far apart two
/// readings of one direction are, from 0 (equal) to 1 (one of them dark).
pub(super) fn repeat_q<T: Radiance>(a: T, b: T) -> f32 {
    let (a, b) = (brightness(a), brightness(b));
    if a + b > 0.0 {
        (b - a) * (b - a) / (a * a + b * b)
    } else {
        0.0
    }
}
