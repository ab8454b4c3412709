//! The fused intervals of one key frame's boundary points.
//!
//! Each later frame paired with the key frame gives every matched key-frame
//! point a guaranteed stick on the **same key-frame ray**
//! ([`crate::Processor::process_against_kept`]), so a point's sticks are
//! intervals of one number, its depth `Z`, and the intersection of
//! guaranteed intervals is guaranteed: the fused interval. No interpolation
//! and no tracking of points: the association is exact. A pair that flags
//! the point (grazing, at the FOE, ...) gives it nothing.
//!
//! # Consistency
//! If the true point lies in every stick, the sticks share a point. An
//! interval that misses the fused one therefore means a wrong pair (a wrong
//! match, typically where the partner frame does not see the stretch of the
//! boundary the point is on). The point is then
//! [`FusedStatus::Inconsistent`] for good, and the interval kept is the one
//! the most pairs agree on, by a two-candidate form of Marzullo's
//! q-relaxed intersection:
//!
//! * the **majority** candidate is the intersection of the intervals that
//!   agreed with it, stored exactly (`f32`), with their count;
//! * the **rival** is the intersection of the intervals that missed the
//!   majority but agree with each other, with their count (also `f32`,
//!   exact);
//! * an interval that misses both is counted as disagreeing with both;
//! * when the rival's count exceeds the majority's the two swap.
//!
//! Every pair counts once, so `pairs = majority + rival + others`, and the
//! kept interval is supported by `pairs − disagreeing` of them. Compared
//! with Marzullo's algorithm over every interval (`O(m log m)` and `m`
//! stored intervals), this keeps a point in 20 bytes and costs `O(1)` per
//! pair; it finds the same majority whenever the intervals fall into at
//! most two mutually consistent groups (the right matches, and the wrong
//! ones from partners that see another stretch), and a flagged point's
//! interval is advice, not a guarantee, either way. An interval that does
//! not narrow the fused one is still checked against it: the pairs that add
//! no information still vote.
//!
//! A point with one pair is [`FusedStatus::Single`]: a two-view stick that
//! nothing has checked (a wrong two-view match cannot be told there); two
//! or more agreeing pairs make it [`FusedStatus::Consistent`].

use core::fmt;

use super::code::DepthScale;
use super::sight::Sight;
use crate::boundary::Frame;
use crate::camera::Pixel;
use crate::depth::DepthInterval;
use crate::math::{fmax, fmin};
use crate::structure::{PointResult, Status, Structure};

/// What the fusion knows about a key-frame point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum FusedStatus {
    /// No pair has given the point an interval yet.
    Unmatched,
    /// One pair has: its stick, guaranteed like any two-view stick where
    /// the point's true correspondent is in the partner's data, but
    /// nothing has checked the match.
    Single,
    /// Two or more pairs have, and all their intervals share the fused one.
    /// (Agreement is evidence, not proof: pairs whose partners all see
    /// another stretch of the boundary along the same rays, e.g. one the
    /// key frame's view hid behind a crest, can agree on its depth; `docs/FUSION.md`,
    /// "Limits".)
    Consistent,
    /// Some interval missed the others: a pair matched wrongly. The
    /// interval given is the one most pairs agree on (module docs), not a
    /// guarantee.
    Inconsistent,
    /// The pairs agree, but some partner was shown to see none of the
    /// point's ray (its window, its image's columns and its boundary's
    /// rows less the margins, is empty or misses the ray's far end): its
    /// match may be of another stretch, and nothing bounds where the truth
    /// is then (`src/fusion/sight.rs`). The interval given is the
    /// intersection, not a guarantee; the point stays out of the map.
    /// (Sight check only, [`crate::fusion::FusionConfig::with_sight_check`].)
    PartlyUnseen,
    /// The pairs agree, but their sticks reach depths some partner was not
    /// shown to see along the point's ray (it left that partner's image,
    /// or its boundary's rows, there): that partner's match may be of
    /// another stretch inside a wider right stick, so the interval given is
    /// the pairs' intersection **widened** over those depths, from the
    /// lowest near end of the point's sticks to the largest depth from
    /// which every partner was shown to see the ray (where it is above the
    /// intersection's far end). It holds the truth whenever one pair is
    /// right (`src/fusion/sight.rs`, "The rule"), so the point is not
    /// flagged and enters the map like a consistent one. (Sight check
    /// only, [`crate::fusion::FusionConfig::with_sight_check`].)
    Widened,
}

impl FusedStatus {
    /// Whether the point is flagged ([`FusedStatus::Inconsistent`],
    /// [`FusedStatus::PartlyUnseen`]).
    pub fn is_flagged(self) -> bool {
        matches!(self, FusedStatus::Inconsistent | FusedStatus::PartlyUnseen)
    }

    /// Short lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            FusedStatus::Unmatched => "unmatched",
            FusedStatus::Single => "single",
            FusedStatus::Consistent => "consistent",
            FusedStatus::Inconsistent => "inconsistent",
            FusedStatus::PartlyUnseen => "partly_unseen",
            FusedStatus::Widened => "widened",
        }
    }
}

impl core::fmt::Display for FusedStatus {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// One key-frame point's fusion.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FusedPoint {
    /// The status.
    pub status: FusedStatus,
    /// The fused interval (the majority's for an inconsistent point), if
    /// any: finite, the exact intersection of the intervals it counts,
    /// widened where the sight check widened it (a
    /// [`FusedStatus::Widened`] point, and one flagged after it was
    /// widened keeps the widened ends).
    pub interval: Option<DepthInterval>,
    /// Pairs (and range constraints) that gave the point an interval.
    pub pairs: u8,
    /// Of those, the ones whose interval misses the one given.
    pub disagreeing: u8,
}

/// A key-frame point in 3-D ([`crate::fusion::Fusion::key_point`]): its
/// detected pixel, its ray and its fusion.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct KeyPoint {
    /// The detected pixel in the key frame.
    pub pixel: crate::camera::Pixel,
    /// The detected pixel's ray `(x, y, 1)` in key-frame camera
    /// coordinates (normalised: [`crate::Camera::normalise`]): depth `z` is
    /// the point `z · ray`, as [`crate::Structure::point`] makes a pair's.
    /// The true point lies on a ray through a pixel within `e₁` of the
    /// detected one ([`crate::Config::e1`]).
    pub ray: [f32; 3],
    /// The point's fusion.
    pub fused: FusedPoint,
}

impl KeyPoint {
    /// The fused interval's ends (near, far) on the ray, in key-frame
    /// camera coordinates, if the point has a bounded interval whose ends
    /// are finite points (`None` also for a far end whose coordinates
    /// overflow `f32`: a depth near `f32::MAX / |x|`, with a `max_depth`
    /// that large).
    pub fn stick(&self) -> Option<([f32; 3], [f32; 3])> {
        let i = self.fused.interval?;
        let [x, y, _] = self.ray;
        let far = [x * i.z_far, y * i.z_far, i.z_far];
        // (The near end is at most the far one: finite if it is.)
        far.iter()
            .all(|c| c.is_finite())
            .then_some(([x * i.z_near, y * i.z_near, i.z_near], far))
    }
}

/// What one interval did to a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Added {
    /// It agreed with the fused interval (or was the first).
    Agreed,
    /// It agreed, but some partner was shown to see none of the point's
    /// ray where the pairs' hull reaches below what it could see: the point
    /// is `PartlyUnseen` now ([`super::sight`]). The packed counts before
    /// it. (An interval that only widens the point, [`FusedStatus::Widened`],
    /// agreed.)
    Unseen { was_counts: u32 },
    /// It missed it: the point is inconsistent now (or was already). The
    /// packed counts before it.
    Conflict { was_counts: u32 },
}

/// `Cell::counts`' flag of a [`FusedStatus::PartlyUnseen`] point (bit 24):
/// a partner was shown to see none of its ray where that mattered.
const UNSEEN: u32 = 1 << 24;

/// The depth from which a partner sees a point's ray, for an interval
/// from no partner (a range constraint): no partner to see.
pub(crate) const SEEN_ANY: f32 = 0.0;
/// The same for a partner shown to see none of the ray worth having: none
/// of it, or only from [`DepthScale::unbounded_from`] on, where the map's
/// codes hold no far end ([`sight_exact`]).
pub(crate) const SEEN_NONE: f32 = f32::INFINITY;

/// The state of one point (20 bytes). An unmatched cell (no interval:
/// the majority byte 0) has every count 0 and `rival` `[0, 0]`, but may
/// hold anything in `near` and `far`: a fresh key frame's first pair
/// without the sight check leaves them as an earlier key frame (or one
/// before a reset) had them ([`Cell::unmatch`], [`first_pair`]). So
/// every reader of the ends asks for an interval first ([`Cell::add`]
/// writes them when there is none; [`Cell::interval`], [`Cell::hull_near`]
/// and the map's [`Cell::admitted`] test come before [`Cell::ends`]), and
/// `Debug` and the digest show such a cell as [`Cell::EMPTY`]
/// ([`Cell::shown`]; [`Cell::words`] gives the raw bits).
#[derive(Clone, Copy)]
pub(crate) struct Cell {
    near: f32,
    far: f32,
    /// Rival interval, exact like the majority's (a conflict costs a few
    /// comparisons and moves, no depth codes: "Exact rival intervals" in
    /// `docs/PERFORMANCE.md`). While no interval has missed the majority
    /// (no rival yet), the sight's state instead ([`super::sight`]): `H`,
    /// the lowest near end of the point's intervals, and `U`, a depth from
    /// which every partner so far was shown to see the ray ([`SEEN_NONE`],
    /// infinite: one was not). With two or more pairs and no other flag,
    /// `H < U` is what makes the point [`FusedStatus::Widened`] (its
    /// interval widened when that began, [`Cell::add_sighted`]); without
    /// the sight check both stay 0. Never NaN: every interval fused is
    /// finite, and every `U` finite, 0 or infinite.
    rival: [f32; 2],
    /// The pair counts, a byte each: bits 0–7 the pairs in the majority
    /// (0: no interval yet), 8–15 the pairs in the rival (0: none), 16–23
    /// the pairs that missed both; bit 24 [`UNSEEN`], bits 25–31 zero.
    /// Packed so that one comparison tells a clean point with a given
    /// majority ([`Cell::is_clean_with`]; a widened point is clean).
    counts: u32,
}

impl fmt::Debug for Cell {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = self.shown();
        f.debug_struct("Cell")
            .field("near", &c.near)
            .field("far", &c.far)
            .field("rival", &c.rival)
            .field("counts", &c.counts)
            .finish()
    }
}

/// The pair counts of a [`Cell`], packed.
const fn pack(major: u8, rival_n: u8, others: u8) -> u32 {
    major as u32 | (rival_n as u32) << 8 | (others as u32) << 16
}

impl Cell {
    pub(crate) const EMPTY: Cell = Cell {
        near: 0.0,
        far: 0.0,
        rival: [0.0; 2],
        counts: 0,
    };

    /// Make the cell unmatched: no interval, no pairs, `rival` `[0, 0]`;
    /// its ends are left as they are (unread while it is unmatched).
    #[inline(always)]
    fn unmatch(&mut self) {
        self.rival = [0.0; 2];
        self.counts = 0;
    }

    /// The cell as its state reads: an unmatched cell as [`Cell::EMPTY`]
    /// (its ends are not its state).
    #[inline]
    fn shown(&self) -> &Cell {
        if self.major() == 0 {
            &Cell::EMPTY
        } else {
            self
        }
    }

    /// Pairs in the majority.
    #[inline(always)]
    fn major(&self) -> u8 {
        (self.counts & 0xFF) as u8
    }

    /// Pairs in the rival.
    #[inline(always)]
    fn rival_n(&self) -> u8 {
        (self.counts >> 8 & 0xFF) as u8
    }

    /// Pairs that missed both.
    #[inline(always)]
    fn others(&self) -> u8 {
        (self.counts >> 16 & 0xFF) as u8
    }

    /// Fuse the interval `[near, far]` (`near ≤ far`, both finite).
    #[inline(always)]
    pub(crate) fn add(&mut self, near: f32, far: f32) -> Added {
        let major = self.major();
        if major == 0 {
            self.near = near;
            self.far = far;
            // (The majority byte 0 to 1.)
            self.counts += 1;
            return Added::Agreed;
        }
        let (lo, hi) = (fmax(self.near, near), fmin(self.far, far));
        if lo <= hi {
            self.near = lo;
            self.far = hi;
            // (The majority byte saturating at 255.)
            if major < u8::MAX {
                self.counts += 1;
            }
            return Added::Agreed;
        }
        let was_counts = self.counts;
        self.conflict(near, far);
        Added::Conflict { was_counts }
    }

    /// [`Self::add`] with the sight check ([`super::sight`]): the interval's
    /// sight `(h, u)` is its near end and a depth from which its
    /// partner sees the ray (for a range constraint: its near end and
    /// [`SEEN_ANY`]). While no interval has missed the point, `H` and `U`
    /// take them in, and where `H < U` the interval is widened to `[H,
    /// max(far, U)]` ([`FusedStatus::Widened`]; module docs of
    /// [`super::sight`], "The rule"), or, where `U` is [`SEEN_NONE`] (a
    /// partner shown to see none of the ray), the point is flagged
    /// [`FusedStatus::PartlyUnseen`].
    ///
    /// The widened interval is kept as the point's interval, and later
    /// pairs intersect it: where the exact state would keep the pairs'
    /// intersection `F` apart, `[H, max(F.far, U)]` read from it, this
    /// gives the same interval (`H` and `U` only move outwards, so the
    /// near end stays `H`, and a far end the widened interval holds past
    /// `F`'s is at most the `U` it was widened to, which the new `U` is not
    /// below).
    #[inline(always)]
    pub(crate) fn add_sighted(&mut self, near: f32, far: f32, (h, u): (f32, f32)) -> Added {
        let was_counts = self.counts;
        let added = self.add(near, far);
        if was_counts == 0 {
            self.rival = [h, u];
            return added;
        }
        if let (Added::Agreed, 0) = (added, was_counts >> 8) {
            let h = fmin(self.rival[0], h);
            let u = fmax(self.rival[1], u);
            self.rival = [h, u];
            if h < u {
                if u == SEEN_NONE {
                    self.counts |= UNSEEN;
                    return Added::Unseen { was_counts };
                }
                // (`H < U` in the rival slot is the widened state,
                // [`Self::status`].)
                self.near = h;
                self.far = fmax(self.far, u);
            }
        }
        added
    }

    /// Whether the sight's state is kept (the point has an interval, no
    /// interval missed it, and it is not `PartlyUnseen`), or it has no
    /// interval yet: the two cases where a pair's sight counts.
    #[inline(always)]
    pub(crate) fn watches(&self) -> bool {
        self.counts >> 8 == 0
    }

    /// `H`, the lowest near end of the point's intervals, while
    /// [`Self::watches`] and it has an interval.
    #[inline(always)]
    pub(crate) fn hull_near(&self) -> Option<f32> {
        (self.major() > 0).then_some(self.rival[0])
    }

    /// No interval has missed the majority, the point is not
    /// `PartlyUnseen`, and `major` pairs are in it.
    #[inline(always)]
    fn is_clean_with(&self, major: u8) -> bool {
        self.counts == u32::from(major)
    }

    /// An interval that missed the majority (out of line: rare on a
    /// still road; every matched point where the pairs disagree).
    #[inline(never)]
    fn conflict(&mut self, near: f32, far: f32) {
        // (On the packed counts, [`Cell::counts`]: the rival's byte is bits
        // 8–15, the others' 16–23, each saturating at 255. [`UNSEEN`] goes:
        // an inconsistent point's status does not read it.)
        let mut counts = self.counts & !UNSEEN;
        if counts & 0xFF00 == 0 {
            self.rival = [near, far];
            counts += 0x100;
        } else {
            let lo = fmax(self.rival[0], near);
            let hi = fmin(self.rival[1], far);
            if lo <= hi {
                self.rival = [lo, hi];
                if counts & 0xFF00 != 0xFF00 {
                    counts += 0x100;
                }
            } else if counts & 0xFF_0000 != 0xFF_0000 {
                counts += 0x1_0000;
            }
        }
        let (major, rival_n) = (counts & 0xFF, counts >> 8 & 0xFF);
        if rival_n > major {
            let [r0, r1] = self.rival;
            self.rival = [self.near, self.far];
            (self.near, self.far) = (r0, r1);
            counts = counts & !0xFFFF | major << 8 | rival_n;
        }
        self.counts = counts;
    }

    pub(crate) fn status(&self) -> FusedStatus {
        match (self.major(), self.rival_n(), self.others()) {
            (0, _, _) => FusedStatus::Unmatched,
            (_, 0, 0) if self.counts & UNSEEN != 0 => FusedStatus::PartlyUnseen,
            (1, 0, 0) => FusedStatus::Single,
            // (A first pair keeps its own `H < U` without widening: one
            // stick, nothing to check.)
            (_, 0, 0) if self.rival[0] < self.rival[1] => FusedStatus::Widened,
            (_, 0, 0) => FusedStatus::Consistent,
            _ => FusedStatus::Inconsistent,
        }
    }

    /// Whether the point goes into the map with at least `min_pairs`
    /// agreeing pairs (no disagreeing one, not `PartlyUnseen`, a bounded
    /// interval; a widened one counts), in one range test on the packed
    /// counts: clean (nothing above the majority byte, [`UNSEEN`]
    /// included) with at least `min_pairs`, and at least one, pairs in the
    /// majority. (Every interval fused is finite, and a widened one is
    /// widened to a finite depth, so a fused interval is bounded.)
    #[inline(always)]
    pub(crate) fn admitted(&self, min_pairs: u8) -> bool {
        // `lo ≤ counts ≤ 0xFF` in one comparison (`lo` from 1 to 255):
        // below `lo` the difference wraps past `0xFF − lo`.
        let lo = u32::from(min_pairs.max(1));
        self.counts.wrapping_sub(lo) <= 0xFF - lo
    }

    /// The fused interval's ends: meaningful only when there is one (an
    /// unmatched cell's are whatever an earlier key frame left, [`Cell`];
    /// callers ask first).
    #[inline]
    pub(crate) fn ends(&self) -> (f32, f32) {
        (self.near, self.far)
    }

    pub(crate) fn interval(&self) -> Option<DepthInterval> {
        (self.major() > 0).then_some(DepthInterval {
            z_near: self.near,
            z_far: self.far,
        })
    }

    pub(crate) fn public(&self) -> FusedPoint {
        let disagreeing = self.rival_n().saturating_add(self.others());
        FusedPoint {
            status: self.status(),
            interval: self.interval(),
            pairs: self.major().saturating_add(disagreeing),
            disagreeing,
        }
    }

    /// The bits, for digests (raw: an unmatched cell's ends too, so the
    /// digest takes [`Cell::shown`]'s).
    pub(crate) fn words(&self) -> [u32; 5] {
        [
            self.near.to_bits(),
            self.far.to_bits(),
            self.rival[0].to_bits(),
            self.rival[1].to_bits(),
            self.counts,
        ]
    }
}

/// Keep a boundary's admitted and inconsistent counts after `added` made
/// cell `c` what it is: a point is admitted the moment its agreeing pairs
/// reach `min` (they grow one at a time while it is consistent; `min` is
/// at most 64, below the count's saturation), and leaves the admitted and
/// joins the inconsistent at its first conflict.
#[inline(always)]
fn count(added: Added, c: &Cell, min: u8, admitted: &mut u16, inconsistent: &mut u16) {
    // (Admitted before: clean with at least `min` pairs, `Cell::admitted`.)
    let was_admitted = |was: u32| (u32::from(min.max(1))..=0xFF).contains(&was);
    match added {
        Added::Agreed => {
            if c.is_clean_with(min) {
                *admitted = admitted.saturating_add(1);
            }
        }
        Added::Unseen { was_counts } => {
            if was_admitted(was_counts) {
                *admitted = admitted.saturating_sub(1);
            }
        }
        Added::Conflict { was_counts } => {
            // (Consistent, widened or `PartlyUnseen` before: no interval
            // had missed.)
            if was_counts & 0x00FF_FF00 == 0 {
                *inconsistent = inconsistent.saturating_add(1);
            }
            if was_admitted(was_counts) {
                *admitted = admitted.saturating_sub(1);
            }
        }
    }
}

/// The sight of the pair's interval for `r`'s point, for its cell `c`
/// ([`Cell::add_sighted`], [`super::sight`]): its near end, and a depth
/// from which the partner sees the ray, probed at half the pairs' lowest
/// near end `H` (this pair's counted); where that fails, the exact depth
/// ([`SEEN_NONE`] if the partner sees none of the ray). A cell whose sight
/// is no longer watched gets `(0, SEEN_ANY)` (not looked at); a partner
/// that sees nothing of the boundary (`sight` `None`), `(near, SEEN_NONE)`.
#[inline(always)]
fn sight_of(c: &Cell, r: &PointResult, sight: Option<&Sight>, scale: &DepthScale) -> (f32, f32) {
    if !c.watches() {
        return (0.0, SEEN_ANY);
    }
    let near = r.z_near;
    let Some(sight) = sight else {
        return (near, SEEN_NONE);
    };
    let h = c.hull_near().map_or(near, |h| fmin(h, near));
    let half = 0.5 * h;
    if sight.sees_from(r.pixel1, half) {
        return (near, half);
    }
    (near, sight_exact(r.pixel1, sight, scale))
}

/// [`sight_of`] where the probe failed: the exact depth, or
/// [`SEEN_NONE`] where the partner sees none of the ray (`seen_from`
/// infinite) or only from [`DepthScale::unbounded_from`] on, beyond any
/// far end the map can hold (as the coded `U` was until the
/// twenty-fourth session: such a point is flagged `PartlyUnseen`, not
/// widened to a depth the map would leave out as unbounded). Out of
/// line: rare.
#[inline(never)]
pub(super) fn sight_exact(p: Pixel, sight: &Sight, scale: &DepthScale) -> f32 {
    let e = sight.seen_from(p);
    if e >= scale.unbounded_from() {
        SEEN_NONE
    } else {
        e
    }
}

/// The first pair of a fresh key frame on one boundary ([`KeyFrame::fuse`]):
/// every cell written, an `Ok` point's as what [`Cell::add`] makes of an
/// empty cell (its stick, one agreeing pair: admitted when `min` is 1),
/// any other unmatched ([`Cell::unmatch`]: as [`Cell::EMPTY`] but for its
/// unread ends).
fn first_pair(
    cells: &mut [Cell],
    results: &[PointResult],
    min: u8,
    adm: &mut u16,
    out: &mut PairFused,
) {
    let mut matched = 0u32;
    let n = cells.len().min(results.len());
    // (An unmatched cell is 8 bytes written, its ends left: most points
    // of a pair are flagged.)
    for (c, r) in cells.iter_mut().zip(results) {
        if r.status == Status::Ok {
            matched += 1;
            *c = Cell {
                near: r.z_near,
                far: r.z_far,
                rival: [0.0; 2],
                counts: pack(1, 0, 0),
            };
        } else {
            c.unmatch();
        }
    }
    // (A boundary without results: its cells unmatched too.)
    for c in cells.iter_mut().skip(n) {
        c.unmatch();
    }
    out.matched += matched;
    if min == 1 {
        // (At most `N` points: no saturation before the sum.)
        *adm = adm.saturating_add(u16::try_from(matched).unwrap_or(u16::MAX));
    }
}

/// What fusing one pair's structure did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PairFused {
    /// Key-frame points the pair matched (status `Ok`): each gave an interval.
    pub matched: u32,
    /// Of those, the ones whose interval missed the point's fused interval.
    pub conflicts: u32,
}

/// Per-status counts of a key frame's points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub struct FusedCounts {
    /// [`FusedStatus::Unmatched`] points.
    pub unmatched: u32,
    /// [`FusedStatus::Single`] points.
    pub single: u32,
    /// [`FusedStatus::Consistent`] points.
    pub consistent: u32,
    /// [`FusedStatus::Inconsistent`] points.
    pub inconsistent: u32,
    /// [`FusedStatus::PartlyUnseen`] points.
    pub partly_unseen: u32,
    /// [`FusedStatus::Widened`] points.
    pub widened: u32,
}

/// The fusion state of one key frame: a `Cell` per boundary point.
///
/// Size: `20·B·N` bytes and a few words (`10 KiB + 32 B` for `N = 256`,
/// `B = 2`).
///
/// Its `Debug` shows each boundary's live cells only (none while the key
/// frame is fresh: a fresh key frame's cells still hold the previous one's,
/// which no reader sees).
#[derive(Clone)]
pub struct KeyFrame<const N: usize, const B: usize> {
    cells: [[Cell; N]; B],
    lens: [u16; B],
    /// Per boundary, the points with at least `min_pairs` agreeing pairs
    /// and no disagreeing one (the map's admission), and the inconsistent
    /// ones: kept as the pairs come, so a retiring key frame need not
    /// count them.
    admitted: [u16; B],
    inconsistent: [u16; B],
    min_pairs: u8,
    id: u32,
    /// Frames paired with this key frame so far.
    partners: u16,
    /// The most points any of its pairs matched.
    best_matched: u32,
    /// The map's depth scale: from its [`DepthScale::unbounded_from`] on a
    /// partner's sight is worth nothing ([`sight_exact`]).
    scale: DepthScale,
    /// Since [`KeyFrame::start`], no pair and no range constraint: every
    /// point is unmatched, whatever its cell holds.
    fresh: bool,
}

/// The live cells of a key frame, boundary by boundary ([`KeyFrame`]'s
/// `Debug`).
struct LiveCells<'a, const N: usize, const B: usize>(&'a KeyFrame<N, B>);

impl<const N: usize, const B: usize> fmt::Debug for LiveCells<'_, N, B> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list()
            .entries((0..B).map(|k| self.0.cells(k)))
            .finish()
    }
}

impl<const N: usize, const B: usize> fmt::Debug for KeyFrame<N, B> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("KeyFrame")
            .field("id", &self.id)
            .field("lens", &self.lens)
            .field("partners", &self.partners)
            .field("fresh", &self.fresh)
            .field("admitted", &self.admitted)
            .field("inconsistent", &self.inconsistent)
            .field("min_pairs", &self.min_pairs)
            .field("best_matched", &self.best_matched)
            .field("scale", &self.scale)
            .field("cells", &LiveCells(self))
            .finish()
    }
}

impl<const N: usize, const B: usize> KeyFrame<N, B> {
    /// A key frame's lengths and counts are `u16`: `N` at most 65 535. (An
    /// adversary's find: with `N` past it, the points past 65 534 were
    /// never fused, uncounted, and [`super::Fusion::constrain`] on one
    /// passed its check, entered a pending retirement's rest, then
    /// refused it.)
    const CHECK: () = assert!(N <= u16::MAX as usize, "N <= 65535");

    pub(crate) const fn new(scale: DepthScale, min_pairs: u8) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::CHECK;
        Self {
            cells: [[Cell::EMPTY; N]; B],
            lens: [0; B],
            admitted: [0; B],
            inconsistent: [0; B],
            min_pairs,
            id: 0,
            partners: 0,
            best_matched: 0,
            scale,
            fresh: false,
        }
    }

    /// Start over for the key frame with id `id` whose boundaries have
    /// `lens` points: every point [`FusedStatus::Unmatched`]. The cells
    /// are not cleared here: the key frame is *fresh* until its first pair
    /// writes every cell ([`KeyFrame::fuse`]) or a range constraint clears
    /// them; until then every reader takes its cells as empty.
    pub(crate) fn start(&mut self, id: u32, lens: [u16; B]) {
        self.id = id;
        self.partners = 0;
        self.best_matched = 0;
        self.lens = lens;
        self.admitted = [0; B];
        self.inconsistent = [0; B];
        self.fresh = true;
    }

    /// Clear a fresh key frame's cells (before a range constraint, the one
    /// change to a fresh key frame other than its first pair).
    fn unfresh(&mut self) {
        if !core::mem::replace(&mut self.fresh, false) {
            return;
        }
        for (&len, cells) in self.lens.iter().zip(self.cells.iter_mut()) {
            for c in cells.iter_mut().take(usize::from(len)) {
                *c = Cell::EMPTY;
            }
        }
    }

    /// The point counts of `frame`'s boundaries (at most `N`).
    pub(crate) fn lens_of(frame: &Frame<N, B>) -> [u16; B] {
        let mut lens = [0u16; B];
        for (l, b) in lens.iter_mut().zip(frame.boundaries()) {
            *l = u16::try_from(b.points().len().min(N)).unwrap_or(u16::MAX);
        }
        lens
    }

    /// Fuse one pair's reconstruction (the key frame against a later
    /// frame): every `Ok` point's stick into its cell. The first pair of a
    /// fresh key frame writes every cell instead: an `Ok` point's stick as
    /// its one agreeing pair, any other point unmatched, its ends left
    /// ([`first_pair`]): what fusing it into cleared cells gives, without
    /// clearing them first.
    ///
    /// Work: one pass over the structure's points (at most `B·N`), `O(1)`
    /// each.
    /// With the sight check on, [`Self::fuse_sighted`] instead.
    pub(crate) fn fuse(&mut self, s: &Structure<N, B>) -> PairFused {
        let mut out = PairFused::default();
        let min = self.min_pairs;
        let fresh = core::mem::replace(&mut self.fresh, false);
        for (k, (((cells, len), adm), inc)) in self
            .cells
            .iter_mut()
            .zip(self.lens.iter())
            .zip(self.admitted.iter_mut())
            .zip(self.inconsistent.iter_mut())
            .enumerate()
        {
            let cells = cells.get_mut(..usize::from(*len)).unwrap_or(&mut []);
            let results = s.boundaries().get(k).map_or(&[][..], |b| b.points());
            if fresh {
                first_pair(cells, results, min, adm, &mut out);
                continue;
            }
            let n = cells.len().min(results.len());
            let (Some(cells), Some(results)) = (cells.get_mut(..n), results.get(..n)) else {
                continue;
            };
            let mut fuse_run = |cells: &mut [Cell], results: &[PointResult]| {
                for (c, r) in cells.iter_mut().zip(results) {
                    if r.status != Status::Ok {
                        continue;
                    }
                    out.matched += 1;
                    let added = c.add(r.z_near, r.z_far);
                    if let Added::Conflict { .. } = added {
                        out.conflicts += 1;
                    }
                    count(added, c, min, adm, inc);
                }
            };
            // Four points at a time, skipping fours with no `Ok` point
            // (most points of a pair are flagged, in runs).
            let mut cs = cells.chunks_exact_mut(4);
            let mut rs = results.chunks_exact(4);
            for (c4, r4) in cs.by_ref().zip(rs.by_ref()) {
                if r4.iter().any(|r| r.status == Status::Ok) {
                    fuse_run(c4, r4);
                }
            }
            fuse_run(cs.into_remainder(), rs.remainder());
        }
        self.partners = self.partners.saturating_add(1);
        if out.matched > self.best_matched {
            self.best_matched = out.matched;
        }
        out
    }

    /// [`Self::fuse`] with the sight check on
    /// ([`super::FusionConfig::with_sight_check`]): `sights` says what the
    /// partner sees of each boundary's rays ([`super::sight`]; `None`:
    /// nothing). One pass over the points, `O(1)` each (a probe of the
    /// partner's sight, and where it fails the depth it sees from).
    pub(crate) fn fuse_sighted(
        &mut self,
        s: &Structure<N, B>,
        sights: &[Option<Sight>; B],
    ) -> PairFused {
        let mut out = PairFused::default();
        let (scale, min) = (self.scale, self.min_pairs);
        let fresh = core::mem::replace(&mut self.fresh, false);
        for (k, ((((cells, len), adm), inc), sight)) in self
            .cells
            .iter_mut()
            .zip(self.lens.iter())
            .zip(self.admitted.iter_mut())
            .zip(self.inconsistent.iter_mut())
            .zip(sights.iter())
            .enumerate()
        {
            let cells = cells.get_mut(..usize::from(*len)).unwrap_or(&mut []);
            let results = s.boundaries().get(k).map_or(&[][..], |b| b.points());
            let mut results = results.iter();
            for c in cells.iter_mut() {
                if fresh {
                    *c = Cell::EMPTY;
                }
                let Some(r) = results.next().filter(|r| r.status == Status::Ok) else {
                    continue;
                };
                out.matched += 1;
                let sight = sight_of(c, r, sight.as_ref(), &scale);
                let added = c.add_sighted(r.z_near, r.z_far, sight);
                if let Added::Conflict { .. } = added {
                    out.conflicts += 1;
                }
                count(added, c, min, adm, inc);
            }
        }
        self.partners = self.partners.saturating_add(1);
        if out.matched > self.best_matched {
            self.best_matched = out.matched;
        }
        out
    }

    /// A new policy's map admission (before the next key frame starts:
    /// [`super::Fusion::reset_with`]).
    pub(crate) fn reconfigure(&mut self, min_pairs: u8) {
        self.min_pairs = min_pairs;
    }

    /// Fuse an outside interval into point `index` of `boundary` (with the
    /// sight check when `sighted`).
    pub(crate) fn constrain(
        &mut self,
        boundary: usize,
        index: usize,
        (near, far): (f32, f32),
        sighted: bool,
    ) -> Option<Added> {
        let len = usize::from(*self.lens.get(boundary)?);
        if index >= len {
            return None;
        }
        self.unfresh();
        let min = self.min_pairs;
        let c = self.cells.get_mut(boundary)?.get_mut(index)?;
        let added = if sighted {
            c.add_sighted(near, far, (near, SEEN_ANY))
        } else {
            c.add(near, far)
        };
        if let (Some(adm), Some(inc)) = (
            self.admitted.get_mut(boundary),
            self.inconsistent.get_mut(boundary),
        ) {
            count(added, c, min, adm, inc);
        }
        Some(added)
    }

    /// Points of `boundary` the map would admit now, and inconsistent ones.
    pub(crate) fn admission(&self, boundary: usize) -> (u16, u16) {
        (
            self.admitted.get(boundary).copied().unwrap_or(0),
            self.inconsistent.get(boundary).copied().unwrap_or(0),
        )
    }

    /// The map's minimum of agreeing pairs.
    pub(crate) fn min_pairs(&self) -> u8 {
        self.min_pairs
    }

    /// The key frame's id.
    pub fn id(&self) -> u32 {
        self.id
    }

    /// Frames paired with the key frame so far.
    pub fn partners(&self) -> u16 {
        self.partners
    }

    /// The most points any pair of this key frame matched.
    pub fn best_matched(&self) -> u32 {
        self.best_matched
    }

    /// The number of boundaries: up to the key frame's last boundary with
    /// points (one pushed absent, `Frame::push_absent`, before it counts,
    /// with no points; one after it does not, as it has none either).
    pub fn boundaries(&self) -> usize {
        self.lens.len() - self.lens.iter().rev().take_while(|&&l| l == 0).count()
    }

    /// The number of points of `boundary` (0 beyond the key frame's).
    pub fn len(&self, boundary: usize) -> usize {
        self.lens.get(boundary).map_or(0, |&l| usize::from(l))
    }

    /// Whether the key frame has no points at all.
    pub fn is_empty(&self) -> bool {
        self.lens.iter().all(|&l| l == 0)
    }

    /// Point `index` of `boundary`, if the key frame has it.
    pub fn point(&self, boundary: usize, index: usize) -> Option<FusedPoint> {
        Some(self.cell(boundary, index)?.public())
    }

    /// The cells of `boundary`'s points (none while the key frame is
    /// fresh: no point has an interval).
    pub(crate) fn cells(&self, boundary: usize) -> &[Cell] {
        let n = if self.fresh { 0 } else { self.len(boundary) };
        self.cells
            .get(boundary)
            .and_then(|c| c.get(..n))
            .unwrap_or(&[])
    }

    pub(crate) fn cell(&self, boundary: usize, index: usize) -> Option<&Cell> {
        if index >= self.len(boundary) {
            return None;
        }
        if self.fresh {
            return Some(&Cell::EMPTY);
        }
        self.cells.get(boundary)?.get(index)
    }

    /// The points of `boundary`, in order.
    pub fn points(&self, boundary: usize) -> impl Iterator<Item = FusedPoint> + '_ {
        let n = self.len(boundary);
        let fresh = self.fresh;
        self.cells
            .get(boundary)
            .map(|c| c.get(..n).unwrap_or(&[]))
            .unwrap_or(&[])
            .iter()
            .map(move |c| if fresh { &Cell::EMPTY } else { c })
            .map(Cell::public)
    }

    /// How many points have each status.
    pub fn counts(&self) -> FusedCounts {
        let mut c = FusedCounts::default();
        for k in 0..B {
            for p in self.points(k) {
                match p.status {
                    FusedStatus::Unmatched => c.unmatched += 1,
                    FusedStatus::Single => c.single += 1,
                    FusedStatus::Consistent => c.consistent += 1,
                    FusedStatus::Inconsistent => c.inconsistent += 1,
                    FusedStatus::PartlyUnseen => c.partly_unseen += 1,
                    FusedStatus::Widened => c.widened += 1,
                }
            }
        }
        c
    }

    pub(crate) fn digest_into(&self, eat: &mut impl FnMut(u32)) {
        eat(self.id);
        eat(u32::from(self.partners));
        for k in 0..B {
            eat(0xCE11_0000 | self.len(k) as u32);
            if let Some(cells) = self.cells.get(k) {
                for c in cells.iter().take(self.len(k)) {
                    let c = if self.fresh { &Cell::EMPTY } else { c.shown() };
                    for w in c.words() {
                        eat(w);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sc() -> DepthScale {
        DepthScale::for_max_depth(1000.0)
    }

    #[test]
    fn intersection_of_agreeing_sticks() {
        let mut c = Cell::EMPTY;
        assert_eq!(c.status(), FusedStatus::Unmatched);
        assert_eq!(c.add(2.0, 4.0), Added::Agreed);
        assert_eq!(c.status(), FusedStatus::Single);
        assert_eq!(c.add(3.0, 5.0), Added::Agreed);
        assert_eq!(c.add(2.5, 3.5), Added::Agreed);
        assert_eq!(c.status(), FusedStatus::Consistent);
        assert_eq!(
            c.interval(),
            Some(DepthInterval {
                z_near: 3.0,
                z_far: 3.5
            })
        );
        // An interval that adds nothing still agrees.
        assert_eq!(c.add(1.0, 9.0), Added::Agreed);
        assert_eq!(c.public().pairs, 4);
        // Touching ends agree (a point in common).
        assert_eq!(c.add(3.5, 6.0), Added::Agreed);
        assert_eq!(c.interval().map(|i| (i.z_near, i.z_far)), Some((3.5, 3.5)));
    }

    /// The sight check's rule (`super::sight`) on an adversarial review's
    /// numbers: a right but wide stick `[9.21, 371]` whose partner sees the
    /// ray from 4.6, and a wrong `[14.7, 16.9]` whose partner sees it only
    /// from 13 (the truth, 11.7, was off its image): in either order the
    /// point is `Widened` to `[9.21, 16.9]` exactly, which
    /// holds the truth, and is admitted to the map; a third pair keeps the
    /// near end at the lowest near end and the far end at least the
    /// largest depth seen from; a missing one makes it inconsistent. A right
    /// narrow stick seen from 6 instead leaves it `Consistent`; a range
    /// constraint that lowers `H` below `U` widens it; a partner shown to
    /// see none of the ray flags it `PartlyUnseen` (out of the map).
    #[test]
    fn the_sight_check_widens_over_what_a_partner_could_not_see() {
        let wide = (9.21, 371.0, (9.21, 4.6));
        let wrong = (14.7, 16.9, (14.7, 13.0));
        let narrow = (11.0, 12.5, (11.0, 6.0));
        let fuse = |a: (f32, f32, (f32, f32)), b: (f32, f32, (f32, f32))| {
            let mut c = Cell::EMPTY;
            assert_eq!(c.add_sighted(a.0, a.1, a.2), Added::Agreed);
            let added = c.add_sighted(b.0, b.1, b.2);
            (c, added)
        };
        let truth = 11.7;
        for (a, b) in [(wide, wrong), (wrong, wide)] {
            let (c, added) = fuse(a, b);
            assert_eq!(added, Added::Agreed);
            assert_eq!(c.status(), FusedStatus::Widened);
            assert!(!c.status().is_flagged());
            assert!(c.admitted(1) && c.admitted(2) && !c.admitted(3));
            let p = c.public();
            assert_eq!((p.pairs, p.disagreeing), (2, 0));
            let (n, f) = p.interval.map(|i| (i.z_near, i.z_far)).unwrap();
            assert_eq!((n, f), (9.21, 16.9));
            assert!(n <= truth && truth <= f);
            // A third agreeing pair: the near end stays `H`, the far end
            // is the intersection's or `U`, whichever is larger.
            let mut c2 = c;
            let _ = c2.add_sighted(15.0, 16.0, (15.0, 7.0));
            assert_eq!(c2.status(), FusedStatus::Widened);
            let (n2, f2) = c2.ends();
            assert!(n2 == n && f2 == 16.0, "{n2} {f2}");
            let mut c3 = c2;
            let _ = c3.add_sighted(15.0, 15.5, (15.0, 15.8));
            let (n3, f3) = c3.ends();
            assert_eq!((n3, f3), (n, 15.8));
            assert!(matches!(
                c2.add_sighted(30.0, 31.0, (30.0, 0.0)),
                Added::Conflict { .. }
            ));
            assert_eq!(c2.status(), FusedStatus::Inconsistent);
        }
        let (c, added) = fuse(wide, narrow);
        assert_eq!(added, Added::Agreed);
        assert_eq!(c.status(), FusedStatus::Consistent);
        assert!(c.admitted(2));
        assert_eq!(c.ends(), (11.0, 12.5));
        // A range constraint down to 5 (below U = 6): widened, still
        // admitted, and counted so.
        let mut c3 = c;
        let added = c3.add_sighted(5.0, 12.0, (5.0, SEEN_ANY));
        assert_eq!(added, Added::Agreed);
        assert_eq!(c3.status(), FusedStatus::Widened);
        let (n, f) = c3.ends();
        assert_eq!((n, f), (5.0, 12.0));
        let (mut adm, mut inc) = (1u16, 0u16);
        count(added, &c3, 2, &mut adm, &mut inc);
        assert_eq!((adm, inc), (1, 0));
        // A partner that sees none of the ray: flagged, out of the map.
        let mut c4 = c;
        let added = c4.add_sighted(11.5, 12.0, (11.5, SEEN_NONE));
        assert!(matches!(added, Added::Unseen { .. }));
        assert_eq!(c4.status(), FusedStatus::PartlyUnseen);
        assert!(c4.status().is_flagged() && !c4.admitted(2));
        // A conflict after it: inconsistent, the flag's bit gone from the
        // counts (as the packed counts were rebuilt before the
        // twenty-fourth session: the same digest).
        let mut c6 = c4;
        assert!(matches!(
            c6.add_sighted(30.0, 31.0, (0.0, SEEN_ANY)),
            Added::Conflict { .. }
        ));
        assert_eq!(c6.status(), FusedStatus::Inconsistent);
        assert_eq!(c6.counts, pack(3, 1, 0));
        let (mut adm, mut inc) = (1u16, 0u16);
        count(added, &c4, 2, &mut adm, &mut inc);
        assert_eq!((adm, inc), (0, 0));
        // A widened point reaching the map's minimum is admitted then.
        let mut c5 = Cell::EMPTY;
        let (mut adm, mut inc) = (0u16, 0u16);
        for (i, x) in [wide, wrong, narrow].into_iter().enumerate() {
            let added = c5.add_sighted(x.0, x.1, x.2);
            count(added, &c5, 3, &mut adm, &mut inc);
            assert_eq!(adm, u16::from(i == 2), "{i}");
        }
        assert_eq!(c5.status(), FusedStatus::Widened);
    }

    #[test]
    fn a_wrong_pair_is_flagged_and_outvoted() {
        let mut c = Cell::EMPTY;
        for (n, f) in [(2.0, 4.0), (3.0, 5.0), (2.8, 3.6)] {
            c.add(n, f);
        }
        assert!(matches!(c.add(6.0, 7.0), Added::Conflict { .. }));
        let p = c.public();
        assert_eq!(p.status, FusedStatus::Inconsistent);
        assert_eq!((p.pairs, p.disagreeing), (4, 1));
        assert_eq!(p.interval.map(|i| (i.z_near, i.z_far)), Some((3.0, 3.6)));
        // A later agreeing pair still narrows the majority.
        assert_eq!(c.add(3.1, 3.4), Added::Agreed);
        assert_eq!(c.interval().map(|i| (i.z_near, i.z_far)), Some((3.1, 3.4)));
        // One missing both counts against both.
        assert!(matches!(c.add(0.5, 1.0), Added::Conflict { .. }));
        assert_eq!((c.public().pairs, c.public().disagreeing), (6, 2));
    }

    #[test]
    fn the_rival_takes_over_when_it_has_more_pairs() {
        let mut c = Cell::EMPTY;
        c.add(2.0, 2.5);
        // Three later pairs agree with each other, not with the first.
        c.add(3.0, 4.0);
        c.add(3.2, 4.2);
        assert_eq!(c.public().disagreeing, 1, "tie: the first keeps it");
        c.add(3.1, 3.9);
        let p = c.public();
        assert_eq!((p.pairs, p.disagreeing), (4, 1));
        let iv = p.interval.unwrap();
        // The rival's interval, exact (as the majority's), and the first
        // pair's now the rival.
        assert_eq!((iv.z_near, iv.z_far), (3.2, 3.9));
        assert_eq!(c.rival, [2.0, 2.5]);
        assert_eq!(p.status, FusedStatus::Inconsistent);
    }

    /// Key frame 1 of one boundary with three points, each given an
    /// interval `[7, 7.5 + i]` by a range constraint.
    fn three_constrained() -> KeyFrame<4, 1> {
        let mut k = KeyFrame::<4, 1>::new(sc(), 1);
        k.start(1, [3]);
        for i in 0..3 {
            k.constrain(0, i, (7.0, 7.5 + i as f32), false);
        }
        k
    }

    #[test]
    fn a_fresh_key_frame_shows_none_of_the_previous_ones_cells() {
        extern crate std;
        use std::format;
        let mut k = three_constrained();
        assert_eq!(k.point(0, 2).unwrap().status, FusedStatus::Single);
        // The next key frame: its cells are not cleared, but nothing sees
        // the old ones, neither the readers nor `Debug`.
        k.start(2, [3]);
        assert!(k.points(0).all(|p| p.status == FusedStatus::Unmatched));
        assert!(k.cells(0).is_empty());
        let shown = format!("{k:?}");
        assert!(
            shown.contains("fresh: true") && !shown.contains("7.5"),
            "{shown}"
        );
        // A range constraint on a fresh key frame: that point only.
        k.constrain(0, 1, (3.0, 4.0), false);
        let st: [FusedStatus; 3] = core::array::from_fn(|i| k.point(0, i).unwrap().status);
        let (u, s1) = (FusedStatus::Unmatched, FusedStatus::Single);
        assert_eq!(st, [u, s1, u]);
        assert_eq!(k.admission(0), (1, 0));
        assert!(!format!("{k:?}").contains("7.5"));
    }

    /// A pair's structure of one boundary: point `i`'s result `Ok` with
    /// the stick `sticks[i]` where it is `Some`, flagged `Grazing` (its
    /// ends `junk`) where it is not.
    fn pair_of(sticks: &[Option<(f32, f32)>], junk: f32) -> Structure<4, 1> {
        let mut s = Structure::<4, 1>::EMPTY;
        s.count = 1;
        let b = &mut s.slots[0].points;
        b.set_len(sticks.len());
        for (i, (r, st)) in b.as_mut_slice().iter_mut().zip(sticks).enumerate() {
            let mut p = PointResult::flagged(Pixel::new(i as f32, 0.0), Status::Grazing);
            (p.z_near, p.z_far) = (junk, junk + 1.0);
            if let &Some((near, far)) = st {
                (p.status, p.z_near, p.z_far) = (Status::Ok, near, far);
            }
            *r = p;
        }
        s
    }

    #[test]
    fn a_first_pair_over_old_cells_shows_and_fuses_none_of_them() {
        extern crate std;
        use std::format;
        // Key frame 1's three points with intervals; then key frame 2,
        // whose first pair matches only point 1 (the flagged results'
        // ends junk): its unmatched cells keep key frame 1's ends.
        let mut k = three_constrained();
        k.start(2, [3]);
        // The same key frame 2 in cells that never held anything.
        let mut clean = KeyFrame::<4, 1>::new(sc(), 1);
        clean.start(2, [3]);
        let pairs = [
            pair_of(&[None, Some((3.0, 4.0)), None], 1.0e30),
            pair_of(&[Some((2.0, 3.0)), Some((3.5, 5.0)), None], -5.0),
        ];
        for s in &pairs {
            let (a, b) = (k.fuse(s), clean.fuse(s));
            assert_eq!(a, b);
            let st: [FusedStatus; 3] = core::array::from_fn(|i| k.point(0, i).unwrap().status);
            let st_clean: [FusedStatus; 3] =
                core::array::from_fn(|i| clean.point(0, i).unwrap().status);
            assert_eq!(st, st_clean);
            let (mut h, mut h_clean) = (0u32, 0u32);
            k.digest_into(&mut |w| h = h.rotate_left(5) ^ w);
            clean.digest_into(&mut |w| h_clean = h_clean.rotate_left(5) ^ w);
            assert_eq!(h, h_clean, "the digest reads an unmatched cell as empty");
            let shown = format!("{k:?}");
            assert!(!shown.contains("7.5") && !shown.contains("8.5"), "{shown}");
            assert_eq!(shown, format!("{clean:?}"));
        }
        // Point 0's interval is its one stick (not cut by the old ends),
        // point 1's the intersection, point 2 unmatched.
        let iv = |i| k.point(0, i).unwrap().interval.map(|v| (v.z_near, v.z_far));
        assert_eq!(iv(0), Some((2.0, 3.0)));
        assert_eq!(iv(1), Some((3.5, 4.0)));
        assert_eq!(iv(2), None);
        assert_eq!(k.point(0, 1).unwrap().status, FusedStatus::Consistent);
        assert_eq!(k.admission(0), clean.admission(0));
    }

    #[test]
    fn cell_is_20_bytes() {
        assert_eq!(core::mem::size_of::<Cell>(), 20);
    }
}
