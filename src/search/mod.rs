//! The search structure: which segments of a polyline can meet the rays
//! whose keys lie in a given interval.
//!
//! Every segment `j` (from vertex `j` to `j + 1`) gets the interval of its
//! end points' keys, each widened by its rounding margin ([`crate::pencil`]);
//! a ray can only meet the segment if its key lies in it. The index answers
//! "every segment whose interval meets `[q_lo, q_hi]`", in increasing `j`,
//! with the guarantee that no such segment is left out (the caller then
//! decides with the exact geometry, so any superset gives the same result
//! as a scan of every segment). Its invariants:
//!
//! 1. Keys are *oriented* (multiplied by ±1) so that they rise from the
//!    first to the last keyed vertex, and pseudo-angles are *unwrapped*
//!    along the polyline (consecutive keys less than half a turn apart; in
//!    an index whose unkeyed ends meet every key, frame 2's, a segment
//!    whose ends are half a turn apart to within their margins, one
//!    passing within a hair of the FOE, may go either way round and is
//!    taken as one with an unkeyed end).
//! 2. A few segments are kept *aside*, in a short sorted list that every
//!    query checks: segments with an unkeyable end (frame 2: they may meet
//!    any ray) and *outlying* segments, whose interval reaches far beyond
//!    those two places before and after (the two segments of a spurious
//!    detector point): a few such would otherwise stretch every run. Their
//!    place in the arrays holds the empty interval.
//! 3. For the others, `pm[j]` is the running maximum of the intervals' high
//!    ends up to `j` and `sm[j]` the running minimum of the low ends from
//!    `j` on. Both are non-decreasing, so the segments meeting the query
//!    all lie in the one run `a ≤ j < b` with `a` the first `j` with
//!    `pm[j] ≥ q_lo` and `b` the first with `sm[j] > q_hi`.
//!
//! A query finds `a` by probing from where the last one found it (queries
//! come along a boundary, so usually a step or two away), bisecting after
//! [`PROBES`] probes, then walks the run testing each interval. Along a
//! road boundary the keys move mostly one way and the run holds the two or
//! three segments around the crossing; a spurious point costs one look at
//! the aside list, not a long run. Where a boundary really folds across the
//! rays the run is long, and every step of it is paid from the frame's
//! [`Work`] budget, so the frame's cost stays bounded whatever the input.
//!
//! The build is two linear passes (keys, intervals and `pm` forwards; `sm`
//! backwards). Only when the envelopes come out loose (somewhere `pm[j] −
//! sm[j]` exceeds [`WIDE`] average widths: a fold, an outlier), a segment is
//! unkeyed, or the orientation was guessed wrong does a third pass look
//! for outliers and the envelopes get rebuilt without them; where they are
//! still loose, a **block tree** is built: the key range of every aligned
//! block of [`FAN`], `FAN²`, … segments. A run through a loose index skips every block whose
//! range misses the query (at an aligned position, the largest such block),
//! so a long run costs about one step per block it crosses and per segment
//! it visits, not one per segment. A tight index never builds or reads the
//! tree. Built without a clock for the lean wedge walks alone, a loose
//! index leaves the tree ([`Builder::finish_deferring_tree`]) until a walk
//! first reads it, at its first aligned segment that misses its keys
//! ([`LazyBlocks`]: built there, the build's tree exactly, so the same
//! skips, units and results; along most road boundaries no walk gets
//! there). The wedge path walks the runs of every index itself
//! (`Index::lean`; for periodic keys the one copy of its query that can
//! meet the keys, `Lean::copy`): it merges the aside entries in by index
//! and, on a loose index, skips from a segment that misses the query over
//! the largest aligned block that misses it too ([`Blocks::skip_at`]).
//!
//! Moving backwards, the band path's key interval is wide (the band's part
//! near the FOE is wide in angle), and its visitor rejects most segments
//! of the run with a cheap test ([`crate::matching::Radial`]): a segment
//! whose key lies far from the point's own and which keeps far from the
//! FOE's row. For those queries the tree gets **radial levels**, built
//! once per index on the first such query (one pass over the intervals and
//! the vertices' rows, after the key levels in the same array: four values
//! a block, `(min lo, max hi)` of its intervals and `(min v, max v)` of
//! its vertices: about `0.57 s` values for `s` segments beside the key
//! levels' `0.29 s`, as many levels as fit in the array's `N`). At an
//! aligned position of the run the visits pass over the largest block the
//! test rejects as a whole ([`crate::matching::Radial::rejects_block`]:
//! then it rejects each of the block's segments), for one unit (a key
//! skip's) where its `FAN^l` segments would cost two each.
//! The same segments reach the visitor in the same order, so the results
//! are the same unless the budget binds (then a point's walk gets further
//! for the same units).
//!
//! The fold test of a polyline whose vertices all have keys (no period)
//! needs no index at all (`crate::fold`).
//!
//! Periodic keys (pseudo-angles) are searched at each copy `q + 4m` that
//! can meet the keys' range (at most [`MAX_COPIES`], else every segment is
//! visited).

use crate::math::{fmax, fmin};
use crate::pencil::NO_KEY;

mod build;
mod lean;
mod visit;

pub(crate) use build::{Builder, KeyOrder};
pub(crate) use lean::{run_start_in, BlockSkip, Blocks, LazyBlocks, Lean};

/// Segments kept aside (see the module docs).
pub(crate) const MAX_ASIDE: usize = 8;
/// An aside segment: its index and (oriented) interval.
pub(crate) type Aside = (u16, f32, f32);
/// Frame-2 segments near the FOE listed for bands that run into it.
pub(crate) const MAX_NEAR: usize = 8;
/// Linear probes before a search for the run's start falls back to
/// bisection.
const PROBES: u32 = 6;
/// At most this many copies of a periodic key are searched one by one.
pub(crate) const MAX_COPIES: usize = 3;
/// How far from 0 an unwrapped pseudo-angle key may lie for a walk of
/// its copy ([`Lean::copy`]): a key in `[0, 4)` is computed to within a
/// quarter of its margin `2⁻²⁰ (S/D + 4)` ([`crate::pencil`]), and adding
/// turns rounds it by at most `2⁻²⁴ |k|` more, which the rest of the
/// margin covers while `|k| ≤ 12 (S/D + 4)`, at least 48 (`S/D ≥ 0`).
/// The first unwrapped key lies in `[4, 8)`, or `(−8, −4]` for keys
/// oriented the other way (the negation of the first's, bit for bit, as
/// every key: a flip at the rebuild negates them all), and a
/// boundary (monotone in `v`, [`crate::Frame::push_boundary`]) turns less
/// than once round the FOE, so its keys usually span less than 4 and lie
/// within 12 of 0. Not always: across the unkeyed disc round the FOE the
/// unwrapping guesses the turn, and a boundary that zig-zags through the
/// disc many times can pile the guesses up; hence the check in
/// `copies_in` ([`Lean::copy`], [`Index::copies`]), for every query (the
/// band path visits every segment, the fold test assumes a fold, the
/// wedge path gives the point to the band).
const COPY_REACH: f32 = 32.0;
/// The fan-out of the block tree, `2^FAN_BITS`.
const FAN_BITS: u32 = 3;
const FAN: usize = 1 << FAN_BITS;
/// The levels of the block tree (blocks of up to `FAN^LEVELS` segments).
const LEVELS: usize = 4;

/// `Index::radial_levels` before the radial levels are built.
const UNBUILT: u8 = u8::MAX;

/// `Index::tree_end` of a loose index whose block tree is left to build
/// ([`Builder::finish_deferring_tree`]), its `levels` 0 meanwhile: every
/// reader but the lean wedge walks ([`LazyBlocks`]) sees no tree, which
/// skips nothing (so is never wrong), and no radial levels are built.
const PENDING: usize = usize::MAX;

/// The caller's clock inside a pass over a polyline ([`crate::deadline`]):
/// asked before every [`CHUNK`] items of each pass of a build, so that no
/// stretch between two questions grows with the polyline; `None` without
/// a deadline. A pass it stops leaves the index unfit for queries (the
/// caller flags the points instead and builds it anew for the next
/// boundary).
pub(crate) type Tick<'t> = Option<&'t mut dyn FnMut() -> bool>;

/// Items (vertices, segments, blocks) a pass handles between two
/// questions of the clock ([`Tick`]).
pub(crate) const CHUNK: usize = 64;

/// Whether `tick`'s clock says the time is up (never without one).
#[inline(always)]
pub(crate) fn expired(tick: &mut Tick<'_>) -> bool {
    match tick {
        Some(t) => t(),
        None => false,
    }
}

/// The looseness of the envelopes (in average interval widths) that makes
/// the build look for outliers, and how far an outlier's interval reaches
/// beyond its neighbours'.
const WIDE: f32 = 8.0;

/// Work units a segment's exact test (the band's or the wedge's clip)
/// costs on top of the unit of looking at it: it is about three times as
/// long.
pub(crate) const CLIP_UNITS: u32 = 2;

/// Work units: every segment a query looks at costs one, every bisection
/// step one; the visitor reports what its own test cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Work {
    credit: u32,
    /// Every unit granted so far.
    granted: u32,
}

/// The frame's work budget was spent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct OutOfWork;

impl Work {
    pub(crate) const fn new() -> Self {
        Self {
            credit: 0,
            granted: 0,
        }
    }

    /// Add a point's allowance.
    #[inline(always)]
    pub(crate) fn grant(&mut self, units: u32) {
        self.credit = self.credit.saturating_add(units);
        self.granted = self.granted.saturating_add(units);
    }

    /// `(spent, granted)` so far.
    pub(crate) fn usage(&self) -> (u32, u32) {
        (self.granted.saturating_sub(self.credit), self.granted)
    }

    /// The units left.
    #[inline(always)]
    pub(crate) fn credit(&self) -> u32 {
        self.credit
    }

    /// Set the units left (a caller that counts them in a local).
    #[inline(always)]
    pub(crate) fn set_credit(&mut self, credit: u32) {
        self.credit = credit;
    }

    /// Pay `units`, or fail (and keep nothing) when there are not enough.
    #[inline(always)]
    pub(crate) fn spend(&mut self, units: u32) -> Result<(), OutOfWork> {
        match self.credit.checked_sub(units) {
            Some(c) => {
                self.credit = c;
                Ok(())
            }
            None => {
                self.credit = 0;
                Err(OutOfWork)
            }
        }
    }
}

/// What a visitor wants next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Flow {
    Continue,
    Stop,
}

/// Takes the segments a query offers ([`Index::visit`]), in increasing
/// index; `'b` the lifetime of the polyline it walks, if any.
pub(crate) trait Visitor<'b> {
    /// Segment `j` with its key interval (oriented; infinite for a segment
    /// listed as near the FOE): whether to go on, and the units of work
    /// its test took beyond the unit of looking at it (charged after).
    fn segment(&mut self, j: usize, interval: (f32, f32)) -> (Flow, u32);

    /// The band walk's [`crate::matching::Radial`] test and its polyline,
    /// if the visitor makes that test first for every segment it is
    /// offered (rejecting for [`crate::matching::RADIAL_UNITS`] and
    /// nothing else): the general visit then makes the test itself
    /// ([`crate::matching::Radial::rejects`]) for the run's segments and
    /// offers only those it keeps, through [`Self::segment_kept`]. The
    /// same units and outcome, without the call.
    #[inline(always)]
    fn radial(&self) -> Option<(crate::matching::Radial, &'b [crate::camera::Pixel])> {
        None
    }

    /// [`Self::segment`] for a segment whose whole radial test
    /// ([`crate::matching::Radial::rejects`]: `by_row`, then the exact
    /// distance where that is undecided) the general visit has made with
    /// this visitor's [`Self::radial`] test, its interval and its two end
    /// vertices, and which the test kept: the visitor need not make it
    /// again. The same outcome and units as [`Self::segment`].
    #[inline(always)]
    fn segment_kept(&mut self, j: usize, interval: (f32, f32)) -> (Flow, u32) {
        self.segment(j, interval)
    }
}

/// How segments with an unkeyable end count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Unkeyed {
    /// They may meet any ray (frame 2: an end within a pixel of the FOE).
    MeetAll,
    /// They meet none (the fold test: an end behind the camera, out of
    /// view or too close to the FOE to say).
    MeetNone,
}

/// A key interval to search (raw keys, not oriented).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Query {
    Keys(f32, f32),
    /// Every segment.
    Everything,
}

/// One segment's entry: its (oriented) key interval and the suffix minimum
/// of the low ends from it on.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Seg {
    pub(crate) lo: f32,
    pub(crate) hi: f32,
    pub(crate) sm: f32,
    /// The prefix maximum of the high ends up to this segment.
    pm: f32,
}

const EMPTY_SEG: Seg = Seg {
    lo: f32::INFINITY,
    hi: f32::NEG_INFINITY,
    sm: f32::INFINITY,
    pm: f32::NEG_INFINITY,
};

/// The index of one polyline (see the module docs). Memory: `20 N` bytes
/// plus the two short lists.
#[derive(Debug, Clone)]
pub(crate) struct Index<const N: usize> {
    seg: [Seg; N],
    /// Each vertex's key margin ([`crate::pencil`]).
    margin: [f32; N],
    /// The block tree (loose indexes only): the `(min lo, max hi)` of each
    /// aligned block of `FAN^l` segments, level `l = 1 …` after level
    /// `l − 1`, flattened; `levels` levels are built (0: no tree, or one
    /// left to build: `tree_end` [`PENDING`]).
    tree: [f32; N],
    levels: usize,
    /// Where the key levels end in `tree`, and the block tree's *radial*
    /// levels after them (module docs): built on the first band query
    /// that brings a [`crate::matching::Radial`] test, `radial_levels` of
    /// them (0: none fit; [`UNBUILT`]: not built yet).
    tree_end: usize,
    radial_levels: u8,
    segments: usize,
    orient: f32,
    period: f32,
    /// Range of the oriented keys of every keyed segment (aside included).
    kmin: f32,
    kmax: f32,
    /// Aside segments: index and (oriented) interval, sorted by index.
    aside: heapless::Vec<(u16, f32, f32), MAX_ASIDE>,
    /// Frame-2 segments within the FOE-near radius, sorted, and whether
    /// there were more than fit.
    near: heapless::Vec<u16, MAX_NEAR>,
    near_overflow: bool,
    hint: usize,
    /// Every vertex is keyed and its widened key lies wholly above the one
    /// before, or wholly below (no period): no vertex's key meets a
    /// segment but its own two. (`false` too where the build did not test
    /// the order: [`build::Builder::push_all`]'s lean loop.)
    strict: bool,
    /// The envelopes, the aside segments left out, are more than
    /// [`WIDE`] average widths apart somewhere: runs may be long.
    loose: bool,
}

impl<const N: usize> Default for Index<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Index<N> {
    /// An empty index.
    pub(crate) const fn new() -> Self {
        Self {
            seg: [EMPTY_SEG; N],
            margin: [0.0; N],
            tree: [0.0; N],
            levels: 0,
            tree_end: 0,
            radial_levels: UNBUILT,
            segments: 0,
            orient: 1.0,
            period: 0.0,
            kmin: 0.0,
            kmax: 0.0,
            aside: heapless::Vec::new(),
            near: heapless::Vec::new(),
            near_overflow: false,
            hint: 0,
            strict: false,
            loose: false,
        }
    }

    /// Whether no vertex's key meets a segment other than its own two (so
    /// no vertex of this polyline folds); `false` says nothing.
    pub(crate) fn strict(&self) -> bool {
        self.strict
    }

    /// Its segments, orientation, aside list and block tree, for a caller
    /// that walks the run itself and merges the aside entries into it by
    /// index ([`run_start_in`], then `sm`, `lo`, `hi` as [`Self::visit`]
    /// does, and, on a loose index, the tree's skips at aligned
    /// positions); for periodic keys, with the copy of a query to walk
    /// ([`Lean::copy`]).
    #[inline(always)]
    pub(crate) fn lean(&self) -> Lean<'_> {
        Lean {
            segs: self.seg.get(..self.segments.min(N)).unwrap_or(&[]),
            orient: self.orient,
            aside: self.aside.as_slice(),
            blocks: self.blocks(),
            period: self.period,
            range: (self.kmin, self.kmax),
        }
    }

    /// Where the last run started (the next query's probes start there).
    pub(crate) fn hint(&self) -> usize {
        self.hint
    }

    /// Remember where a run started (for the next query's probes).
    #[inline(always)]
    pub(crate) fn set_hint(&mut self, a: usize) {
        if a < self.segments {
            self.hint = a;
        }
    }

    /// The orientation of the keys (+1 or −1; the index holds the keys
    /// times it).
    pub(crate) fn orient(&self) -> f32 {
        self.orient
    }

    /// The vertices' key margins, for a caller that writes them before
    /// the build ([`build::Builder::push_all_stored`]).
    pub(crate) fn margins_mut(&mut self) -> &mut [f32; N] {
        &mut self.margin
    }

    /// The vertices' key margins as written ([`Self::margins_mut`]).
    pub(crate) fn margins(&self) -> &[f32] {
        &self.margin
    }

    /// The key margin of vertex `i` (0 when out of range).
    pub(crate) fn margin(&self, i: usize) -> f32 {
        self.margin.get(i).copied().unwrap_or(0.0)
    }
}

#[cfg(test)]
pub(crate) mod tests;
