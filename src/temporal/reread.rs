//! Re-reads: the `S` rays per update that look again where earlier updates looked, so that a
//! change shows as the difference of two readings of one direction, which aliasing cannot fake
//! (A-SVGF's re-shading of last frame's samples, for a probe).
//!
//! Each slot tracks one direction for [`TRACK`] updates or more (the slots in turn, so that
//! some are verified at every update), then moves to the brightest of the latest update's
//! rotated samples (a global change moves the bright readings most, and a light that
//! switches off was bright). Its readings pass through states:
//! - *new*: a rotated sample's reading, not yet re-read; the re-read verifies it, or the two
//!   disagree (*disputed*) and a third reading decides which was the outlier, without
//!   evidence either way;
//! - *verified*: a change from it is an alarm. An alarm counts at once only where alarms come
//!   from three octants of the sphere together (a global change; its evidence capped at
//!   [`CONTAMINATION`] each: one ray in 32 may be an outlier); else the slot becomes
//! - *suspect*: its next reading confirms the change (it agrees with the changed reading: the
//!   alarm's full evidence) or refutes it (back at the verified reading: a firefly or a
//!   flicker, no evidence).

use super::Vec3;
use crate::radiance::Radiance;

/// Updates a slot tracks one direction before it moves to another.
pub(super) const TRACK: u16 = 4;
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
