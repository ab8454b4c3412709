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
//! tree. The wedge path walks the runs of every index itself
//! (`Index::lean`; for periodic keys the one copy of its query that can
//! meet the keys, `Lean::copy`): it merges the aside entries in by index
//! and, on a loose index, skips from a segment that misses the query over
//! the largest aligned block that misses it too ([`Blocks::skip_at`]).
//!
//! The fold test of a polyline whose vertices all have keys (no period)
//! needs no index at all (`crate::fold`).
//!
//! Periodic keys (pseudo-angles) are searched at each copy `q + 4m` that
//! can meet the keys' range (at most [`MAX_COPIES`], else every segment is
//! visited).

use crate::math::{fmax, fmin};
use crate::pencil::NO_KEY;

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
/// The first unwrapped key lies in `[4, 8)`, or `(0, 4]` for keys
/// oriented the other way (a flip at the rebuild negates them all), and a
/// boundary (monotone in `v`, [`crate::Frame::push_boundary`]) turns less
/// than once round the FOE, so its keys usually span less than 4 and lie
/// within 12 of 0. Not always: across the unkeyed disc round the FOE the
/// unwrapping guesses the turn, and a boundary that zig-zags through the
/// disc many times can pile the guesses up; hence the check in
/// [`copies_in`], for every query (the band path visits every segment, the
/// fold test assumes a fold, the wedge path gives the point to the band).
const COPY_REACH: f32 = 32.0;
/// The fan-out of the block tree, `2^FAN_BITS`.
const FAN_BITS: u32 = 3;
const FAN: usize = 1 << FAN_BITS;
/// The levels of the block tree (blocks of up to `FAN^LEVELS` segments).
const LEVELS: usize = 4;

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
/// index.
pub(crate) trait Visitor {
    /// Segment `j` with its key interval (oriented; infinite for a segment
    /// listed as near the FOE): whether to go on, and the units of work
    /// its test took beyond the unit of looking at it (charged after).
    fn segment(&mut self, j: usize, interval: (f32, f32)) -> (Flow, u32);
}

/// An index's view for a caller that walks runs itself ([`Index::lean`]).
#[derive(Clone, Copy)]
pub(crate) struct Lean<'a> {
    pub(crate) segs: &'a [Seg],
    pub(crate) orient: f32,
    pub(crate) aside: &'a [Aside],
    pub(crate) blocks: Blocks<'a>,
    /// The keys' period (0: none) and range `[kmin, kmax]` ([`copies_in`]).
    period: f32,
    range: (f32, f32),
}

impl Lean<'_> {
    /// The one copy of the oriented query `[ql, qh]` to walk
    /// ([`copies_in`]): for keys without a period the query itself; for
    /// periodic keys the copy `[ql + 4m, qh + 4m]` that can meet the keys'
    /// range, or, when none can, `(−∞, −∞)` (it meets only intervals that
    /// reach `−∞`, those of segments with an unkeyed end: a walk's run
    /// starts where its probes from the hint, then a bisection, reach
    /// segment 0, a few units, and its low-end tests end the run at the
    /// first segment that does not reach `−∞`); `None` when two or more
    /// can, or when the keys lie beyond [`COPY_REACH`] of 0.
    #[inline(always)]
    pub(crate) fn copy(&self, ql: f32, qh: f32) -> Option<(f32, f32)> {
        if self.period <= 0.0 {
            return Some((ql, qh));
        }
        let mut c = [(0.0f32, 0.0f32); MAX_COPIES];
        match copies_in((self.period, self.range), ql, qh, &mut c) {
            Some(0) => Some((f32::NEG_INFINITY, f32::NEG_INFINITY)),
            Some(1) => c.first().copied(),
            _ => None,
        }
    }
}

/// A loose index's block tree (module docs): the `(min lo, max hi)` of
/// every aligned block of `FAN^l` segments, level after level.
#[derive(Clone, Copy)]
pub(crate) struct Blocks<'a> {
    tree: &'a [f32],
    levels: usize,
    segments: usize,
}

impl Blocks<'_> {
    /// Whether there is a tree (a loose index).
    #[inline(always)]
    pub(crate) fn any(&self) -> bool {
        self.levels > 0
    }

    /// At segment `j` of a loose index's run: how many segments from `j`
    /// on a block skip passes over: the largest block aligned at `j` whose
    /// key range `meets` does not accept (0: look at segment `j` itself).
    /// At most [`LEVELS`] steps.
    #[inline(always)]
    pub(crate) fn skip_at(&self, j: usize, meets: impl Fn(f32, f32) -> bool) -> usize {
        // Only a position aligned to a block starts one.
        if j & (FAN - 1) != 0 {
            return 0;
        }
        let (mut base, mut n, mut skip) = (0usize, self.segments, 0usize);
        let mut shift = 0u32;
        for _ in 0..self.levels.min(LEVELS) {
            shift += FAN_BITS;
            n = n.div_ceil(FAN);
            // (`shift` ≤ 3 · LEVELS = 12.)
            let size = 1usize << shift;
            if j & (size - 1) != 0 {
                break;
            }
            let b = j >> shift;
            let (lo, hi) = (
                self.tree
                    .get(base + 2 * b)
                    .copied()
                    .unwrap_or(f32::NEG_INFINITY),
                self.tree
                    .get(base + 2 * b + 1)
                    .copied()
                    .unwrap_or(f32::INFINITY),
            );
            // A block that meets the query holds every larger block's
            // range too: stop there.
            if lo <= hi && meets(lo, hi) {
                break;
            }
            skip = size;
            base += 2 * n;
        }
        skip
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
    /// `l − 1`, flattened; `levels` levels are built (0: no tree).
    tree: [f32; N],
    levels: usize,
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
    /// the order: [`Builder::push_all`]'s lean loop.)
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

    /// Start indexing a polyline: push its vertex keys and their margins
    /// in order ([`Builder::push`]), then [`Builder::finish`]. `period` 4
    /// for pseudo-angles; `orient` the likely orientation of the keys (+1
    /// rising, −1 falling: any value gives the same index, a wrong one
    /// costs a rebuild). A segment's interval is that of its end keys,
    /// each widened by its margin.
    #[inline(always)]
    pub(crate) fn builder(
        &mut self,
        (period, orient): (f32, f32),
        unkeyed: Unkeyed,
    ) -> Builder<'_, N> {
        self.period = period;
        self.hint = 0;
        self.levels = 0;
        self.aside.clear();
        self.near.clear();
        self.near_overflow = false;
        Builder {
            o: if orient < 0.0 { -1.0 } else { 1.0 },
            period,
            unkeyed,
            n: 0,
            order: KeyOrder::NEW,
            keyed: NO_KEY,
            offset: 0.0,
            first: NO_KEY,
            last: NO_KEY,
            run: f32::NEG_INFINITY,
            sum: 0.0,
            index: self,
        }
    }

    /// The suffix minima `sm`; whether somewhere the envelopes are more
    /// than `wide` apart.
    fn suffix_minima(&mut self, wide: f32) -> bool {
        let s = self.segments;
        let Some(seg) = self.seg.get_mut(..s) else {
            return false;
        };
        let (mut run, mut gap) = (f32::INFINITY, f32::NEG_INFINITY);
        for g in seg.iter_mut().rev() {
            run = fmin(run, g.lo);
            g.sm = run;
            gap = fmax(gap, g.pm - run);
        }
        // (A NaN gap fails: loose.)
        !(gap <= wide)
    }

    /// The slow path of [`Self::build`]: orient the intervals as `orient`,
    /// set aside the unkeyed segments and those of outlying vertices, and
    /// rebuild the envelopes without them.
    fn rebuild(&mut self, orient: f32, wide: f32) {
        let s = self.segments;
        let Some(seg) = self.seg.get_mut(..s) else {
            return;
        };
        if orient != self.orient {
            for g in seg.iter_mut() {
                (g.lo, g.hi) = (-g.hi, -g.lo);
            }
            self.orient = orient;
        }
        // Outliers: a segment whose interval reaches more than `wide`
        // beyond those of the segments two places before and after it
        // (both segments of a spurious vertex do; along a boundary whose
        // keys move one way, neither end of an interval passes both of
        // those). A heuristic for speed only: any choice gives the same
        // results.
        // (An empty interval, `(∞, −∞)`, or a missing neighbour leaves the
        // neighbours' hull as it is; with neither there is no hull, `hi =
        // −∞`: intervals are never otherwise inverted, and a non-empty one
        // has `hi > −∞`.)
        let mut aside = heapless::Vec::<(u16, f32, f32), MAX_ASIDE>::new();
        let ends = |i: usize| {
            seg.get(i)
                .map_or((f32::INFINITY, f32::NEG_INFINITY), |x| (x.lo, x.hi))
        };
        for (j, g) in seg.iter().enumerate() {
            let all = g.lo == f32::NEG_INFINITY;
            let out = g.lo.is_finite() && g.hi.is_finite() && {
                let (bl, bh) = j
                    .checked_sub(2)
                    .map_or((f32::INFINITY, f32::NEG_INFINITY), ends);
                let (al, ah) = ends(j + 2);
                let (lo, hi) = (fmin(bl, al), fmax(bh, ah));
                hi > f32::NEG_INFINITY && (g.hi - hi > wide || lo - g.lo > wide)
            };
            if (all || out) && !aside.is_full() {
                if let Ok(jj) = u16::try_from(j) {
                    let _ = aside.push((jj, g.lo, g.hi));
                }
            }
        }
        for &(j, _, _) in aside.iter() {
            if let Some(g) = seg.get_mut(usize::from(j)) {
                (g.lo, g.hi) = (f32::INFINITY, f32::NEG_INFINITY);
            }
        }
        self.aside = aside;
        let Some(seg) = self.seg.get_mut(..s) else {
            return;
        };
        let mut run = f32::NEG_INFINITY;
        for g in seg.iter_mut() {
            run = fmax(run, g.hi);
            g.pm = run;
        }
        // The block tree for runs through the rebuilt envelopes, when they
        // are still loose (tight runs are short: no tree needed).
        self.loose = self.suffix_minima(wide);
        if self.loose {
            self.build_tree();
        }
    }

    /// The block tree over the current intervals (module docs): as many
    /// levels as fit in the `tree` array (each level `l` has
    /// `⌈s / FAN^l⌉` blocks of two values), at most [`LEVELS`]; every loop
    /// bounded by the array or by the blocks of the level below.
    fn build_tree(&mut self) {
        let s = self.segments;
        self.levels = 0;
        let (mut base, mut below_base, mut below_n, mut size) = (0usize, 0usize, s, 1usize);
        for level in 1..=LEVELS {
            size = size.saturating_mul(FAN);
            let n = s.div_ceil(size);
            let Some(end) = base.checked_add(2 * n).filter(|&e| e <= N) else {
                return;
            };
            for b in 0..n {
                let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
                for c in b * FAN..((b + 1) * FAN).min(below_n) {
                    let (l, h) = if level == 1 {
                        self.seg
                            .get(c)
                            .map_or((f32::INFINITY, f32::NEG_INFINITY), |g| (g.lo, g.hi))
                    } else {
                        let i = below_base + 2 * c;
                        (
                            self.tree.get(i).copied().unwrap_or(f32::INFINITY),
                            self.tree.get(i + 1).copied().unwrap_or(f32::NEG_INFINITY),
                        )
                    };
                    lo = fmin(lo, l);
                    hi = fmax(hi, h);
                }
                if let Some(t) = self.tree.get_mut(base + 2 * b) {
                    *t = lo;
                }
                if let Some(t) = self.tree.get_mut(base + 2 * b + 1) {
                    *t = hi;
                }
            }
            self.levels = level;
            below_base = base;
            below_n = n;
            base = end;
            if n <= 1 {
                return;
            }
        }
    }

    /// The block tree as [`Blocks`] (no levels when none is built).
    #[inline(always)]
    fn blocks(&self) -> Blocks<'_> {
        Blocks {
            tree: &self.tree,
            levels: self.levels,
            segments: self.segments,
        }
    }

    /// [`Blocks::skip_at`] on this index's tree.
    #[inline(always)]
    fn skip_at(&self, j: usize, meets: impl Fn(f32, f32) -> bool) -> usize {
        self.blocks().skip_at(j, meets)
    }

    /// Whether vertex `i`, whose raw key is `key`, may lie on a ray that
    /// meets a segment outside `i − w ..= i + w − 1` other than those set
    /// aside (the envelopes leave them out): `false` is certain
    /// (its widened key lies above every interval before that window and
    /// below every one after it, in the oriented order: the envelopes say
    /// so in `O(1)`, for each copy of a periodic key that can meet the
    /// keys' range), `true` needs the query ([`Self::visit`]) to decide.
    #[inline(always)]
    pub(crate) fn may_fold(&self, i: usize, key: f32, w: usize) -> bool {
        let k = self.orient * key;
        let e = self.margin(i);
        let test = |k: f32| {
            let before = i
                .checked_sub(w + 1)
                .and_then(|j| self.seg.get(j))
                .is_some_and(|g| k - e <= g.pm);
            let after = self
                .seg
                .get(i + w)
                .filter(|_| i + w < self.segments)
                .is_some_and(|g| k + e >= g.sm);
            before || after
        };
        if self.period <= 0.0 {
            return test(k);
        }
        // Periodic keys: every copy of the key that can meet the keys'
        // range (the envelopes hold the unwrapped keys).
        let mut c = [(0.0f32, 0.0f32); MAX_COPIES];
        match self.copies(k - e, k + e, &mut c) {
            Some(n) => c.iter().take(n).any(|&(lo, _)| test(lo + e)),
            None => true,
        }
    }

    /// [`Self::folds`] for every item of `items` in order (vertex `i` the
    /// `i`-th, `key` its raw key where it is to be tested), each bringing
    /// `allowance` to `work` first; `flag` gets the answer of each tested
    /// one. Without a period and with nothing aside, the envelopes' `O(1)`
    /// answer ([`Self::may_fold`]) is taken in the loop itself, and only the
    /// vertices it cannot clear go through [`Self::folds`].
    #[inline(always)]
    pub(crate) fn folds_all<T>(
        &mut self,
        items: &mut [T],
        (w, allowance): (usize, u32),
        work: &mut Work,
        key: impl Fn(&T) -> Option<f32>,
        mut flag: impl FnMut(&mut T, Result<bool, OutOfWork>),
    ) {
        let lean = self.period <= 0.0 && self.aside.is_empty();
        if !lean {
            for (i, it) in items.iter_mut().enumerate() {
                work.grant(allowance);
                let Some(k) = key(it) else {
                    continue;
                };
                let r = self.folds(i, k, w, work);
                flag(it, r);
            }
            return;
        }
        let (s, o) = (self.segments.min(N), self.orient);
        // The allowances of the items since the last grant: given before
        // the next query and at the end (saturating sums, so the credit
        // each query sees is the one granting item by item gives).
        let mut owed = 0u32;
        for (i, it) in items.iter_mut().enumerate() {
            owed = owed.saturating_add(allowance);
            let Some(k) = key(it) else {
                continue;
            };
            let (ko, e) = (o * k, self.margin.get(i).copied().unwrap_or(0.0));
            let before = i
                .checked_sub(w + 1)
                .and_then(|j| self.seg.get(j))
                .is_some_and(|g| ko - e <= g.pm);
            let after = i + w < s && self.seg.get(i + w).is_some_and(|g| ko + e >= g.sm);
            if !(before || after) {
                continue;
            }
            work.grant(owed);
            owed = 0;
            let r = if self.strict {
                self.folds(i, k, w, work)
            } else {
                self.folds_query(i, k, w, work)
            };
            flag(it, r);
        }
        work.grant(owed);
    }

    /// Whether no vertex's key meets a segment other than its own two (so
    /// no vertex of this polyline folds); `false` says nothing.
    pub(crate) fn strict(&self) -> bool {
        self.strict
    }

    /// The fold test of vertex `i` with raw key `key`: whether its key
    /// (widened by its margin) meets a segment outside `i − w ..= i + w −
    /// 1` (the aside list, [`Self::may_fold`] for the rest, then the query;
    /// each segment looked at one unit of `work`).
    #[inline(always)]
    pub(crate) fn folds(
        &mut self,
        i: usize,
        key: f32,
        w: usize,
        work: &mut Work,
    ) -> Result<bool, OutOfWork> {
        if self.strict {
            return Ok(false);
        }
        let e = self.margin(i);
        let skip = (i.saturating_sub(w), i.saturating_add(w).saturating_sub(1));
        if !self.aside.is_empty() {
            // The segments set aside first (the envelopes leave them out),
            // all for one unit: a spurious detector point's two segments
            // meet most keys and settle the test at once.
            work.spend(1)?;
            let k = self.orient * key;
            let mut c = [(0.0f32, 0.0f32); MAX_COPIES];
            let copies = match self.copies(k - e, k + e, &mut c) {
                Some(n) => c.get(..n).unwrap_or(&[]),
                None => return Ok(true),
            };
            let outside = |j: u16| usize::from(j) < skip.0 || usize::from(j) > skip.1;
            let met = self.aside.iter().any(|&(j, lo, hi)| {
                outside(j) && copies.iter().any(|&(ql, qh)| lo <= qh && hi >= ql)
            });
            if met {
                return Ok(true);
            }
        }
        if !self.may_fold(i, key, w) {
            return Ok(false);
        }
        self.folds_query(i, key, w, work)
    }

    /// The query of [`Self::folds`] (the index's segments outside `i − w
    /// ..= i + w − 1`, each one unit of `work`), for a vertex neither the
    /// aside list nor the envelopes settled.
    fn folds_query(
        &mut self,
        i: usize,
        key: f32,
        w: usize,
        work: &mut Work,
    ) -> Result<bool, OutOfWork> {
        let e = self.margin(i);
        let skip = (i.saturating_sub(w), i.saturating_add(w).saturating_sub(1));
        let mut met = Met(false);
        self.visit(
            Query::Keys(key - e, key + e),
            false,
            Some(skip),
            work,
            &mut met,
        )?;
        Ok(met.0)
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
    /// the build ([`Builder::push_all_stored`]).
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

    /// Visit, in increasing index, every segment whose interval may meet
    /// `query` (a superset of those that do: the caller tests each), plus
    /// the FOE-near list when `with_near`; segments in `skip` (an inclusive
    /// range of indices) are left out. Each segment looked at costs one
    /// unit of `work`, each one visited what the visitor reports,
    /// each bisection step one.
    #[inline(always)]
    pub(crate) fn visit(
        &mut self,
        query: Query,
        with_near: bool,
        skip: Option<(usize, usize)>,
        work: &mut Work,
        visit: &mut (impl Visitor + Copy),
    ) -> Result<(), OutOfWork> {
        // The usual case: one run, no lists to merge; next, a run and the
        // aside list. Periodic keys take this way when at most one copy of
        // the query meets the keys' range (none: only unkeyed segments
        // aside can meet it, so the query is made empty).
        let near = with_near && (!self.near.is_empty() || self.near_overflow);
        let mut one = None;
        if let (Query::Keys(q0, q1), false) = (query, near) {
            let (ql, qh) = if self.orient < 0.0 {
                (-q1, -q0)
            } else {
                (q0, q1)
            };
            if self.period <= 0.0 {
                one = Some((ql, qh));
            } else {
                let mut c = [(0.0f32, 0.0f32); MAX_COPIES];
                match self.copies(ql, qh, &mut c) {
                    Some(0) => one = Some((f32::INFINITY, f32::NEG_INFINITY)),
                    Some(1) => one = c.first().copied(),
                    _ => {}
                }
            }
        }
        if let Some((ql, qh)) = one {
            if self.aside.is_empty() {
                return self.visit_run(ql, qh, skip, work, visit);
            }
            let (mut v, mut w) = (*visit, *work);
            let skip = skip.unwrap_or((usize::MAX, 0));
            let r = self.visit_run_aside((ql, qh), skip, &mut w, &mut v);
            (*visit, *work) = (v, w);
            return r;
        }
        // The rare paths take the visitor by reference to a copy, so that
        // the caller's visitor (and work) never has its address taken and
        // stays in registers on the usual path.
        let (mut v, mut w) = (*visit, *work);
        let r = self.visit_general(query, with_near, skip, &mut w, &mut v);
        (*visit, *work) = (v, w);
        r
    }

    /// [`Self::visit`] for one oriented interval and no lists.
    #[inline(always)]
    fn visit_run(
        &mut self,
        ql: f32,
        qh: f32,
        skip: Option<(usize, usize)>,
        work: &mut Work,
        visit: &mut (impl Visitor + Copy),
    ) -> Result<(), OutOfWork> {
        // (A query that cannot meet the keys' range finds an empty run: its
        // start is past every segment, or its first suffix minimum above it.)
        let a = self.run_start(ql, work)?;
        if a < self.segments {
            self.hint = a;
        }
        let (skip0, skip1) = skip.unwrap_or((usize::MAX, 0));
        if self.levels > 0 {
            let (mut v, mut w) = (*visit, *work);
            let r = self.visit_run_loose(a, (ql, qh), (skip0, skip1), &mut w, &mut v);
            (*visit, *work) = (v, w);
            return r;
        }
        let run = self.seg.get(a..self.segments.min(N)).unwrap_or(&[]);
        // The credit in a local while the run is walked (bounded by the
        // slice `run`).
        let mut credit = work.credit;
        let mut result = Ok(());
        for (j, g) in (a..).zip(run) {
            if g.sm > qh {
                break;
            }
            if credit == 0 {
                result = Err(OutOfWork);
                break;
            }
            credit -= 1;
            if g.lo <= qh && g.hi >= ql && !(j >= skip0 && j <= skip1) {
                let (flow, units) = visit.segment(j, (g.lo, g.hi));
                if credit < units {
                    credit = 0;
                    result = Err(OutOfWork);
                    break;
                }
                credit -= units;
                if flow == Flow::Stop {
                    break;
                }
            }
        }
        work.credit = credit;
        result
    }

    /// [`Self::visit_run`] through a loose index: the block tree skips the
    /// blocks the query misses (each skip one unit). Bounded by the segment
    /// count: every step advances `j`.
    #[inline(never)]
    fn visit_run_loose(
        &mut self,
        mut j: usize,
        (ql, qh): (f32, f32),
        (skip0, skip1): (usize, usize),
        work: &mut Work,
        visit: &mut dyn Visitor,
    ) -> Result<(), OutOfWork> {
        let s = self.segments.min(N);
        let meets = |l: f32, h: f32| l <= qh && h >= ql;
        while let Some(g) = self.seg.get(j).filter(|_| j < s) {
            if g.sm > qh {
                break;
            }
            work.spend(1)?;
            let k = self.skip_at(j, meets);
            if k > 0 {
                j += k;
                continue;
            }
            if meets(g.lo, g.hi) && !(j >= skip0 && j <= skip1) {
                let (flow, units) = visit.segment(j, (g.lo, g.hi));
                work.spend(units)?;
                if flow == Flow::Stop {
                    break;
                }
            }
            j += 1;
        }
        Ok(())
    }

    /// [`Self::visit`] for one oriented interval through a run and the aside
    /// list, merged in index order (the block tree skips the run's blocks
    /// the query misses). Each step advances the run or the list; every
    /// segment looked at and every skip costs one unit.
    #[inline(never)]
    fn visit_run_aside(
        &mut self,
        (ql, qh): (f32, f32),
        (skip0, skip1): (usize, usize),
        work: &mut Work,
        visit: &mut impl Visitor,
    ) -> Result<(), OutOfWork> {
        let a = self.run_start(ql, work)?;
        if a < self.segments {
            self.hint = a;
        }
        let s = self.segments.min(N);
        let meets = |l: f32, h: f32| l <= qh && h >= ql;
        let (mut j, mut ia) = (a, 0usize);
        loop {
            let run_next = match self.seg.get(j) {
                Some(g) if j < s && g.sm <= qh => j,
                _ => usize::MAX,
            };
            let aside = self.aside.get(ia).copied();
            let aside_next = aside.map_or(usize::MAX, |(k, _, _)| usize::from(k));
            work.spend(1)?;
            let (k, l, h) = match aside {
                Some((_, l, h)) if aside_next < run_next => {
                    ia += 1;
                    (aside_next, l, h)
                }
                _ => {
                    let Some(g) = self.seg.get(j).filter(|_| run_next != usize::MAX) else {
                        return Ok(());
                    };
                    let skip = if self.levels > 0 {
                        self.skip_at(j, meets)
                    } else {
                        0
                    };
                    if skip > 0 {
                        j += skip;
                        continue;
                    }
                    j += 1;
                    (run_next, g.lo, g.hi)
                }
            };
            if meets(l, h) && !(k >= skip0 && k <= skip1) {
                let (flow, units) = visit.segment(k, (l, h));
                work.spend(units)?;
                if flow == Flow::Stop {
                    return Ok(());
                }
            }
        }
    }

    /// [`Self::visit`] in general: the copies of a periodic key, the aside
    /// list and the FOE-near list merged into the run in index order. (The
    /// visitor by reference: this rare path keeps the usual one's visitor
    /// inlined.)
    #[inline(never)]
    fn visit_general(
        &mut self,
        query: Query,
        with_near: bool,
        skip: Option<(usize, usize)>,
        work: &mut Work,
        visit: &mut dyn Visitor,
    ) -> Result<(), OutOfWork> {
        let s = self.segments;
        let mut copies = [(0.0f32, 0.0f32); MAX_COPIES];
        let mut ncopies = 0usize;
        let mut everything = with_near && self.near_overflow;
        if let (Query::Keys(q0, q1), false) = (query, everything) {
            let (ql, qh) = if self.orient < 0.0 {
                (-q1, -q0)
            } else {
                (q0, q1)
            };
            match self.copies(ql, qh, &mut copies) {
                Some(c) => ncopies = c,
                None => everything = true,
            }
        } else {
            everything = true;
        }
        let copies = copies.get(..ncopies).unwrap_or(&[]);
        // The run: from the first start over the copies to where the
        // suffix minimum passes the last copy's high end.
        let (mut j, mut top) = (s, f32::NEG_INFINITY);
        if everything {
            j = 0;
            top = f32::INFINITY;
        } else {
            for &(cl, ch) in copies {
                j = j.min(self.run_start(cl, work)?);
                top = fmax(top, ch);
            }
            if j < s {
                self.hint = j;
            }
        }
        let hits = |l: f32, h: f32| {
            l <= h
                && (everything
                    || l == f32::NEG_INFINITY
                    || copies.iter().any(|&(cl, ch)| l <= ch && h >= cl))
        };
        let skipped = |k: usize| skip.is_some_and(|(x, y)| k >= x && k <= y);
        // The merge of three sorted streams: the run, the aside list and
        // (optionally) the near list, each bounded by its length; every
        // step advances one of them.
        let near: &[u16] = if with_near { &self.near } else { &[] };
        let (mut ia, mut inear) = (0usize, 0usize);
        loop {
            // A loose index: skip the blocks of the run no copy meets (the
            // aside and near entries in them keep their own streams, which
            // the merge below still takes in index order).
            if self.levels > 0
                && !everything
                && self.seg.get(j).is_some_and(|g| j < s && g.sm <= top)
            {
                let k = self.skip_at(j, |l, h| copies.iter().any(|&(cl, ch)| l <= ch && h >= cl));
                if k > 0 {
                    j += k;
                    work.spend(1)?;
                    continue;
                }
            }
            let next_aside = self
                .aside
                .get(ia)
                .map_or(usize::MAX, |&(k, _, _)| usize::from(k));
            let next_near = near.get(inear).map_or(usize::MAX, |&k| usize::from(k));
            let next_run = match self.seg.get(j) {
                Some(g) if j < s && g.sm <= top => j,
                _ => usize::MAX,
            };
            let next = next_run.min(next_aside).min(next_near);
            if next == usize::MAX {
                return Ok(());
            }
            let mut take = false;
            // The segment's interval: the union of its streams' (an aside
            // segment's is empty in the run).
            let (mut il, mut ih) = (f32::INFINITY, f32::NEG_INFINITY);
            if next == next_aside {
                if let Some(&(_, l, h)) = self.aside.get(ia) {
                    take |= hits(l, h);
                    (il, ih) = (fmin(il, l), fmax(ih, h));
                }
                ia += 1;
            }
            if next == next_near {
                take = true;
                (il, ih) = (f32::NEG_INFINITY, f32::INFINITY);
                inear += 1;
            }
            if next == next_run {
                if let Some(g) = self.seg.get(j) {
                    take |= hits(g.lo, g.hi);
                    (il, ih) = (fmin(il, g.lo), fmax(ih, g.hi));
                }
                j += 1;
            }
            work.spend(1)?;
            if take && !skipped(next) {
                let (flow, units) = visit.segment(next, (il, ih));
                work.spend(units)?;
                if flow == Flow::Stop {
                    return Ok(());
                }
            }
        }
    }

    /// The copies `[ql + 4m, qh + 4m]` of an oriented query that can meet
    /// the keys' range `[kmin, kmax]` (for non-periodic keys the query
    /// itself, if it can), into `out`; `None` when there are more than
    /// [`MAX_COPIES`].
    fn copies(&self, ql: f32, qh: f32, out: &mut [(f32, f32); MAX_COPIES]) -> Option<usize> {
        copies_in((self.period, (self.kmin, self.kmax)), ql, qh, out)
    }

    /// The first segment `a` with `pm[a] ≥ t` ([`run_start_in`] from the
    /// hint).
    #[inline(always)]
    pub(crate) fn run_start(&self, t: f32, work: &mut Work) -> Result<usize, OutOfWork> {
        let n = self.segments.min(N);
        run_start_in(self.seg.get(..n).unwrap_or(&[]), self.hint, t, work)
    }
}

/// The copies `[ql + 4m, qh + 4m]` of an oriented query that can meet
/// the keys' range `[kmin, kmax]` of an index with keys of `period` (for
/// non-periodic keys the query itself, if it can), into `out`; `None` when
/// there are more than [`MAX_COPIES`].
fn copies_in(
    (period, (kmin, kmax)): (f32, (f32, f32)),
    ql: f32,
    qh: f32,
    out: &mut [(f32, f32); MAX_COPIES],
) -> Option<usize> {
    if period <= 0.0 {
        if let Some(o) = out.first_mut() {
            *o = (ql, qh);
        }
        return Some(usize::from(ql <= kmax && qh >= kmin));
    }
    // No keyed segment: no copy. (A NaN fails, and the next test takes it.)
    if kmin > kmax {
        return Some(0);
    }
    // Keys beyond `COPY_REACH` of 0 may be off by more than their margins:
    // as many copies as can be (every segment visited, or a fold assumed).
    // (A NaN fails.)
    if !(kmin >= -COPY_REACH && kmax <= COPY_REACH) {
        return None;
    }
    // The smallest m with qh + 4m ≥ kmin. Keys change by less than half
    // a turn per segment, so |kmin|, |kmax| ≤ 2N + 4 and the quotient
    // is small; it is clamped anyway before the (saturating) conversion.
    let m0 = ((kmin - qh) * 0.25).clamp(-1.0e7, 1.0e7);
    let mut m = m0 as i32;
    if (m as f32) < m0 {
        m = m.saturating_add(1);
    }
    let mut c = 0usize;
    for slot in out.iter_mut() {
        let shift = 4.0 * m as f32;
        if ql + shift > kmax {
            return Some(c);
        }
        *slot = (ql + shift, qh + shift);
        c += 1;
        m = m.saturating_add(1);
    }
    // All slots used: a further copy would overflow.
    (ql + 4.0 * m as f32 > kmax).then_some(c)
}

/// The first segment `a` of `seg` with `pm[a] ≥ t`: probes from `hint`,
/// then bisection after [`PROBES`] (each bisection step one unit of work).
#[inline(always)]
pub(crate) fn run_start_in(
    seg: &[Seg],
    hint: usize,
    t: f32,
    work: &mut Work,
) -> Result<usize, OutOfWork> {
    let n = seg.len();
    let at = |j: usize| seg.get(j).map_or(f32::INFINITY, |g| g.pm);
    let mut j = hint.min(n.saturating_sub(1));
    let mut probes = PROBES;
    if at(j) >= t {
        // Back while the one before still reaches t.
        while j > 0 && at(j - 1) >= t {
            if probes == 0 {
                return bisect(seg, 0, j, t, work);
            }
            probes -= 1;
            j -= 1;
        }
        Ok(j)
    } else {
        // Forward to the first that reaches t.
        while j < n && at(j) < t {
            if probes == 0 {
                return bisect(seg, j, n, t, work);
            }
            probes -= 1;
            j += 1;
        }
        Ok(j)
    }
}

/// The fold test's visitor: any segment offered meets the key.
#[derive(Clone, Copy)]
struct Met(bool);

impl Visitor for Met {
    fn segment(&mut self, _: usize, _: (f32, f32)) -> (Flow, u32) {
        self.0 = true;
        (Flow::Stop, 0)
    }
}

/// Whether the widened keys of a polyline's vertices, in order, each lie
/// wholly above the one before (`up`) or wholly below (`down`), and
/// whether one of them is unkeyed (`odd`): fed one vertex at a time.
/// Strictly ordered keys ([`KeyOrder::strict`]) meet no segment but their
/// own two, so nothing folds and the envelopes are the intervals
/// themselves.
#[derive(Debug, Clone, Copy)]
pub(crate) struct KeyOrder {
    /// The previous vertex's key and its widened ends.
    prev: f32,
    plo: f32,
    phi: f32,
    first: bool,
    up: bool,
    down: bool,
    odd: bool,
}

impl KeyOrder {
    pub(crate) const NEW: KeyOrder = KeyOrder {
        prev: NO_KEY,
        plo: 0.0,
        phi: 0.0,
        first: true,
        up: true,
        down: true,
        odd: false,
    };

    /// The next vertex's key ([`NO_KEY`] where none) and margin; whether
    /// it and the one before are both keyed, with their widened ends
    /// `((previous lo, previous hi), (lo, hi))`.
    #[inline(always)]
    pub(crate) fn push(&mut self, k: f32, e: f32) -> Option<((f32, f32), (f32, f32))> {
        let (vlo, vhi) = (k - e, k + e);
        let (plo, phi) = (self.plo, self.phi);
        let both = (k + self.prev).is_finite();
        let first = self.first;
        (self.prev, self.plo, self.phi, self.first) = (k, vlo, vhi, false);
        if first {
            return None;
        }
        if !both {
            self.odd = true;
            return None;
        }
        self.up &= vlo > phi;
        self.down &= vhi < plo;
        Some(((plo, phi), (vlo, vhi)))
    }

    /// Whether [`Self::strict`] is false whatever vertices come next (one
    /// was unkeyed, or the keys went both ways): only pushes clear `up`
    /// and `down` and set `odd`.
    #[inline(always)]
    pub(crate) fn settled(&self) -> bool {
        self.odd || !(self.up || self.down)
    }

    /// Every vertex keyed and the widened keys strictly ordered one way,
    /// for keys without a period (`period` 0).
    pub(crate) fn strict(&self, period: f32) -> bool {
        !self.odd && period <= 0.0 && (self.up || self.down)
    }
}

/// Builds an [`Index`] one vertex at a time (pass 1 of the module docs:
/// oriented, unwrapped keys, intervals, prefix maxima and the widths' sum,
/// in locals while the vertices come).
pub(crate) struct Builder<'a, const N: usize> {
    index: &'a mut Index<N>,
    o: f32,
    period: f32,
    unkeyed: Unkeyed,
    n: usize,
    order: KeyOrder,
    keyed: f32,
    offset: f32,
    first: f32,
    last: f32,
    run: f32,
    sum: f32,
}

impl<const N: usize> Builder<'_, N> {
    /// Push every vertex `keys` gives, raw key ([`NO_KEY`] where none) and
    /// margin, in order (through [`Self::push_run`]); at most `N` count.
    #[inline(always)]
    pub(crate) fn push_all(&mut self, keys: impl Iterator<Item = (f32, f32)>) {
        let mut keys = keys;
        self.push_run(|m| {
            let (raw, e) = keys.next()?;
            *m = e;
            Some(raw)
        });
    }

    /// [`Self::push_stored`] for every raw key `keys` gives, in order
    /// (through [`Self::push_run`]).
    #[inline(always)]
    pub(crate) fn push_all_stored(&mut self, keys: impl Iterator<Item = f32>) {
        let mut keys = keys;
        self.push_run(|_| keys.next());
    }

    /// Push vertices while `next` gives their raw keys, each with its
    /// margin put in (or already in) the slot it is handed; at most `N`.
    /// While the keys have no period and are finite (the usual polyline)
    /// a lean loop writes the intervals and prefix maxima (the values
    /// [`Self::push_stored`] gives) without the key-order test (the index
    /// is then not [`Index::strict`], a shortcut of the fold test only);
    /// from the first vertex it cannot take on, [`Self::push_stored`].
    #[inline(always)]
    fn push_run(&mut self, mut next: impl FnMut(&mut f32) -> Option<f32>) {
        let mut pending = None;
        if self.n == 0 && self.period <= 0.0 {
            let Some(raw) = self.index.margin.first_mut().and_then(&mut next) else {
                return;
            };
            self.push_stored(raw);
            let k = self.o * raw;
            let (Some(&e), true) = (self.index.margin.first(), k.is_finite()) else {
                return self.push_rest(next);
            };
            let o = self.o;
            let (mut prev, mut plo, mut phi) = (k, k - e, k + e);
            let (mut run, mut sum) = (self.run, self.sum);
            let mut n = 1usize;
            let slots = self
                .index
                .margin
                .iter_mut()
                .skip(1)
                .zip(self.index.seg.iter_mut());
            for (m, g) in slots {
                let Some(raw) = next(m) else {
                    break;
                };
                let k = o * raw;
                if !(k + prev).is_finite() {
                    pending = Some(raw);
                    break;
                }
                let e = *m;
                let (vlo, vhi) = (k - e, k + e);
                g.lo = fmin(plo, vlo);
                g.hi = fmax(phi, vhi);
                sum += g.hi - g.lo;
                run = fmax(run, g.hi);
                g.pm = run;
                (prev, plo, phi) = (k, vlo, vhi);
                n += 1;
            }
            if n > 1 {
                self.order = KeyOrder {
                    prev,
                    plo,
                    phi,
                    first: false,
                    up: false,
                    down: false,
                    odd: false,
                };
                (self.n, self.run, self.sum, self.last) = (n, run, sum, prev);
            }
        }
        if let Some(raw) = pending {
            self.push_stored(raw);
        }
        self.push_rest(next);
    }

    /// One vertex, raw key and margin, through [`Self::push_stored`] (the
    /// tests' way past the lean loop).
    #[cfg(test)]
    fn push(&mut self, raw: f32, e: f32) {
        if let Some(m) = self.index.margin.get_mut(self.n) {
            *m = e;
            self.push_stored(raw);
        }
    }

    /// The rest of [`Self::push_run`], one [`Self::push_stored`] at a time.
    fn push_rest(&mut self, mut next: impl FnMut(&mut f32) -> Option<f32>) {
        while let Some(raw) = self.index.margin.get_mut(self.n).and_then(&mut next) {
            self.push_stored(raw);
        }
    }

    /// The next vertex's raw key ([`NO_KEY`] where none), its margin
    /// already in place (in `margin[n]`); at most `N` count.
    #[inline(always)]
    fn push_stored(&mut self, raw: f32) {
        let i = self.n;
        let Some(&e) = self.index.margin.get(i) else {
            return;
        };
        let mut k = self.o * raw;
        // Whether the segment ending here may go either way round the FOE.
        let mut doubtful = false;
        if self.period > 0.0 && k.is_finite() {
            // Consecutive keys are less than half a turn apart.
            k += self.offset;
            let d = k - self.keyed;
            if d > 2.0 {
                self.offset -= 4.0;
                k -= 4.0;
            } else if d < -2.0 {
                self.offset += 4.0;
                k += 4.0;
            }
            // A segment that passes (nearly) through the FOE has ends half
            // a turn apart: within its ends' margins of that (each key is
            // computed to within a quarter of its margin, `crate::pencil`)
            // the way round it goes, and so its interval, is not known, and
            // it is taken as an unkeyed one (below). Only where an unkeyed
            // end meets every key, frame 2's index: the fold index's "meets
            // none" would be the less careful answer there. (For the first
            // vertex `d` is infinite, and there is no segment.)
            if self.unkeyed == Unkeyed::MeetAll {
                let m = e + i
                    .checked_sub(1)
                    .and_then(|j| self.index.margin.get(j))
                    .copied()
                    .unwrap_or(0.0);
                doubtful = 2.0 - (k - self.keyed).abs() <= 2.0 * m;
            }
            self.keyed = k;
        }
        let ends = self.order.push(k, e);
        if let Some(g) = i.checked_sub(1).and_then(|j| self.index.seg.get_mut(j)) {
            if let (Some(((plo, phi), (vlo, vhi))), false) = (ends, doubtful) {
                g.lo = fmin(plo, vlo);
                g.hi = fmax(phi, vhi);
                self.sum += g.hi - g.lo;
            } else {
                // An unkeyed end (or a doubtful way round): the rebuild
                // sorts it out.
                (g.lo, g.hi) = match self.unkeyed {
                    Unkeyed::MeetAll => (f32::NEG_INFINITY, f32::INFINITY),
                    Unkeyed::MeetNone => (f32::INFINITY, f32::NEG_INFINITY),
                };
            }
            self.run = fmax(self.run, g.hi);
            g.pm = self.run;
        }
        if k.is_finite() {
            if !self.first.is_finite() {
                self.first = k;
            }
            self.last = k;
        }
        self.n = i + 1;
    }

    /// Pass 2 and, when needed, the slow path (module docs); `near(j)`
    /// says whether segment `j` comes within the FOE-near radius (frame 2
    /// with `W' < 0`; `None` otherwise).
    pub(crate) fn finish(self, near: Option<&dyn Fn(usize) -> bool>) {
        let Builder {
            index,
            o,
            n,
            first,
            last,
            sum,
            order,
            period,
            ..
        } = self;
        let s = n.saturating_sub(1);
        index.segments = s;
        index.strict = order.strict(period);
        let odd = order.odd;
        // The keys (oriented by `o`) fall overall: orient them the other way.
        let flip = last < first;
        index.orient = o;
        let wide = WIDE * sum / fmax(s as f32, 1.0);
        let loose = index.suffix_minima(wide);
        index.loose = loose;
        if loose || odd || flip {
            index.rebuild(if flip { -o } else { o }, wide);
        }
        index.kmin = index.seg.first().map_or(f32::INFINITY, |g| g.sm);
        index.kmax = index
            .seg
            .get(s.wrapping_sub(1))
            .map_or(f32::NEG_INFINITY, |g| g.pm);
        for &(_, l, h) in index.aside.iter() {
            if l.is_finite() && h.is_finite() {
                index.kmin = fmin(index.kmin, l);
                index.kmax = fmax(index.kmax, h);
            }
        }
        if let Some(is_near) = near {
            for j in 0..s {
                if is_near(j) {
                    match u16::try_from(j).ok().map(|jj| index.near.push(jj)) {
                        Some(Ok(())) => {}
                        _ => index.near_overflow = true,
                    }
                }
            }
        }
    }
}

/// First index in `[lo, hi)` with `v[j] ≥ t` (non-decreasing `v`), or `hi`;
/// each step one unit of work.
fn bisect(
    v: &[Seg],
    mut lo: usize,
    mut hi: usize,
    t: f32,
    work: &mut Work,
) -> Result<usize, OutOfWork> {
    hi = hi.min(v.len());
    while lo < hi {
        work.spend(1)?;
        let m = lo + (hi - lo) / 2;
        if v.get(m).map_or(f32::INFINITY, |g| g.pm) >= t {
            hi = m;
        } else {
            lo = m + 1;
        }
    }
    Ok(hi)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::test_rng::Rng;
    extern crate std;
    use std::vec::Vec;

    pub(crate) const CAP: usize = 96;

    /// A random key sequence of one of several shapes, with margins; some
    /// keys missing ([`NO_KEY`]); periodic ones in `[0, 4)` when `period`.
    pub(crate) fn keys(rng: &mut Rng, shape: u32, n: usize, period: bool) -> Vec<(f32, f32)> {
        let mut k = rng.next() * 2.0 - 1.0;
        let step = 0.002 + 0.05 * rng.next();
        let mut out = Vec::new();
        for i in 0..n {
            let e = 1.0e-4 * rng.next();
            k += match shape {
                // Monotone.
                0 => step,
                // Monotone with jitter.
                1 => step * (1.0 + 1.5 * (rng.next() - 0.5)),
                // A fold halfway.
                2 if i > n / 2 => -step,
                2 => step,
                // Nearly constant (radial).
                3 => 1.0e-4 * (rng.next() - 0.5),
                // Zig-zag.
                _ => {
                    if i % 2 == 0 {
                        step
                    } else {
                        -0.8 * step
                    }
                }
            };
            let mut v = k;
            // Spikes (spurious points).
            if rng.next() < 0.04 {
                v += (rng.next() - 0.5) * 3.0;
            }
            if period {
                v = v.rem_euclid(4.0);
            }
            if rng.next() < 0.02 {
                out.push((NO_KEY, 0.0));
            } else {
                out.push((v, e));
            }
        }
        out
    }

    /// The segments' intervals as the builder forms them, in raw keys
    /// unwrapped along the polyline for periodic keys (`None`: an end
    /// without a key).
    pub(crate) fn intervals(ks: &[(f32, f32)], period: bool) -> Vec<Option<(f32, f32)>> {
        let mut unwrapped = Vec::new();
        let (mut offset, mut last) = (0.0f32, NO_KEY);
        for &(k, e) in ks {
            if !k.is_finite() {
                unwrapped.push((k, e));
                continue;
            }
            let mut v = k + offset;
            if period {
                let d = v - last;
                if d > 2.0 {
                    offset -= 4.0;
                    v -= 4.0;
                } else if d < -2.0 {
                    offset += 4.0;
                    v += 4.0;
                }
                last = v;
            }
            unwrapped.push((v, e));
        }
        unwrapped
            .windows(2)
            .map(|w| {
                let ((a, ea), (b, eb)) = (w[0], w[1]);
                (a.is_finite() && b.is_finite())
                    .then(|| (fmin(a - ea, b - eb), fmax(a + ea, b + eb)))
            })
            .collect()
    }

    /// Whether an interval meets `[lo, hi]` or one of its copies `+ 4m`.
    pub(crate) fn meets(iv: (f32, f32), (lo, hi): (f32, f32), period: bool) -> bool {
        if !period {
            return iv.0 <= hi && iv.1 >= lo;
        }
        (-40..=40).any(|m| {
            let s = 4.0 * m as f32;
            iv.0 <= hi + s && iv.1 >= lo + s
        })
    }

    /// The segments offered, and whether in increasing order.
    #[derive(Clone, Copy)]
    struct Record {
        seen: [bool; CAP],
        last: Option<usize>,
        ordered: bool,
    }
    impl Visitor for Record {
        fn segment(&mut self, j: usize, _: (f32, f32)) -> (Flow, u32) {
            self.ordered &= self.last.is_none_or(|l| j > l);
            self.last = Some(j);
            if let Some(s) = self.seen.get_mut(j) {
                *s = true;
            }
            (Flow::Continue, 0)
        }
    }

    #[derive(Clone, Copy)]
    struct Count(usize, usize);
    impl Visitor for Count {
        fn segment(&mut self, j: usize, _: (f32, f32)) -> (Flow, u32) {
            // Increasing indices, counted.
            assert!(self.1 == usize::MAX || j > self.1, "{j} after {}", self.1);
            self.1 = j;
            self.0 += 1;
            (Flow::Continue, 0)
        }
    }

    /// The index offers every segment whose interval meets the query (a
    /// segment with an unkeyed end meets every query, in frame 2's index),
    /// in increasing order, whatever the shape of the keys: monotone,
    /// jittering, folding, radial, zig-zag, with spikes and missing keys,
    /// periodic or not, either orientation guess.
    #[test]
    fn visit_offers_every_segment_that_meets_the_query() {
        let mut rng = Rng(0x5ea7_c401);
        let mut index = Index::<CAP>::new();
        for case in 0..3000 {
            let (shape, period) = (case % 5, case % 3 == 0);
            let n = 2 + (rng.next() * (CAP - 2) as f32) as usize;
            let ks = keys(&mut rng, shape, n, period);
            let orient = if rng.next() < 0.5 { 1.0 } else { -1.0 };
            let mut b = index.builder((if period { 4.0 } else { 0.0 }, orient), Unkeyed::MeetAll);
            if case % 2 == 0 {
                b.push_all(ks.iter().copied());
            } else {
                for &(k, e) in &ks {
                    b.push(k, e);
                }
            }
            b.finish(None);
            let ivs = intervals(&ks, period);
            for _ in 0..8 {
                let c = if period {
                    4.0 * rng.next()
                } else {
                    rng.next() * 3.0 - 1.5
                };
                let w = 0.2 * rng.next() * rng.next();
                let q = (c - w, c + w);
                let mut rec = Record {
                    seen: [false; CAP],
                    last: None,
                    ordered: true,
                };
                let mut work = Work::new();
                work.grant(u32::MAX);
                assert!(index
                    .visit(Query::Keys(q.0, q.1), false, None, &mut work, &mut rec)
                    .is_ok());
                assert!(rec.ordered, "case {case}: out of order");
                for (j, iv) in ivs.iter().enumerate() {
                    let must = iv.is_none_or(|iv| meets(iv, q, period));
                    assert!(
                        !must || rec.seen[j],
                        "case {case} (shape {shape}, period {period}): segment {j} {iv:?} meets {q:?} but was not offered"
                    );
                }
                let mut count = Count(0, usize::MAX);
                let mut work = Work::new();
                work.grant(u32::MAX);
                assert!(index
                    .visit(Query::Everything, false, None, &mut work, &mut count)
                    .is_ok());
                assert_eq!(count.0, n - 1, "case {case}: every segment for Everything");
            }
        }
    }

    /// The fold test (the `strict` certificate, the envelopes' `O(1)`
    /// answer and the query) equals the brute force: a vertex folds when its
    /// widened key meets a segment outside its window (a segment with an
    /// unkeyed end meets nothing here).
    #[test]
    fn folds_equals_brute_force() {
        let mut rng = Rng(0xf01d_0002);
        let mut index = Index::<CAP>::new();
        let w = 4;
        for case in 0..3000 {
            let (shape, period) = (case % 5, case % 3 == 0);
            let n = 2 + (rng.next() * (CAP - 2) as f32) as usize;
            let ks = keys(&mut rng, shape, n, period);
            let orient = if rng.next() < 0.5 { 1.0 } else { -1.0 };
            let mut b = index.builder((if period { 4.0 } else { 0.0 }, orient), Unkeyed::MeetNone);
            if case % 2 == 0 {
                b.push_all(ks.iter().copied());
            } else {
                for &(k, e) in &ks {
                    b.push(k, e);
                }
            }
            b.finish(None);
            let ivs = intervals(&ks, period);
            for (i, &(k, e)) in ks.iter().enumerate() {
                if !k.is_finite() {
                    continue;
                }
                let brute = ivs.iter().enumerate().any(|(j, iv)| {
                    let outside = j + w < i || j > i + w - 1;
                    outside && iv.is_some_and(|iv| meets(iv, (k - e, k + e), period))
                });
                let mut work = Work::new();
                work.grant(u32::MAX);
                let fast = index.folds(i, k, w, &mut work);
                assert_eq!(
                    fast,
                    Ok(brute),
                    "case {case} (shape {shape}, period {period}) vertex {i} key {k}"
                );
            }
        }
    }

    /// [`Lean::copy`] on pseudo-angle keys: the one copy of a query that can
    /// meet the keys' range, the query that meets none (`(−∞, −∞)`), none
    /// when two copies can (the keys span nearly a turn, or many turns);
    /// and the query itself without a period.
    #[test]
    fn lean_copy_picks_the_single_copy() {
        let mut index = Index::<16>::new();
        let mut b = index.builder((4.0, 1.0), Unkeyed::MeetAll);
        b.push_all([0.5f32, 1.5, 2.5, 3.5, 3.9].iter().map(|&k| (k, 0.0)));
        b.finish(None);
        let lean = index.lean();
        let none = Some((f32::NEG_INFINITY, f32::NEG_INFINITY));
        // (The unwrapped keys start at some whole number of turns.)
        let o = lean.range.0 - 0.5;
        assert_eq!(lean.range, (0.5 + o, 3.9 + o));
        assert_eq!(lean.copy(1.0, 1.2), Some((1.0 + o, 1.2 + o)));
        assert_eq!(lean.copy(5.0, 5.2), Some((1.0 + o, 1.2 + o)));
        assert_eq!(lean.copy(-3.0, -2.8), Some((1.0 + o, 1.2 + o)));
        assert_eq!(lean.copy(0.1, 0.3), none);
        assert_eq!(lean.copy(4.1, 4.3), none);
        // [-0.2, 0.6] and [3.8, 4.6] both meet [0.5, 3.9].
        assert_eq!(lean.copy(-0.2, 0.6), None);
        let mut wound = Index::<64>::new();
        let mut b = wound.builder((4.0, 1.0), Unkeyed::MeetAll);
        // Nine turns at 1.5 a step: a query meets many copies.
        b.push_all((0..26).map(|i| ((1.5 * i as f32) % 4.0, 0.0)));
        b.finish(None);
        let lean = wound.lean();
        assert!(lean.range.1 - lean.range.0 > 36.0, "{:?}", lean.range);
        assert_eq!(lean.copy(1.0, 1.1), None, "many copies");
        // More copies than searched one by one (and keys past COPY_REACH):
        // a query visits every segment.
        assert!(lean.range.1 > COPY_REACH, "{:?}", lean.range);
        let mut seen = Record {
            seen: [false; CAP],
            last: None,
            ordered: true,
        };
        let mut work = Work::new();
        work.grant(10_000);
        let q = Query::Keys(40.0, 40.1);
        assert!(wound.visit(q, false, None, &mut work, &mut seen).is_ok());
        assert!(
            seen.seen.iter().take(25).all(|&x| x),
            "every segment offered"
        );
        // Keys beyond COPY_REACH of 0 (hand-made): no walk, whether one
        // copy meets them or none.
        let far = |range| Lean {
            segs: &[],
            orient: 1.0,
            aside: &[],
            blocks: Blocks {
                tree: &[],
                levels: 0,
                segments: 0,
            },
            period: 4.0,
            range,
        };
        assert_eq!(far((30.0, 31.0)).copy(2.2, 2.4), Some((30.2, 30.4)));
        assert_eq!(far((31.0, 33.0)).copy(3.2, 3.4), None, "one copy");
        assert_eq!(far((31.0, 33.0)).copy(2.0, 2.5), None, "no copy");
        assert_eq!(far((-34.0, -33.0)).copy(2.2, 2.4), None);
        assert_eq!(far((-34.0, f32::NAN)).copy(2.2, 2.4), None);
        // No keyed segment (an empty range): the empty copy.
        assert_eq!(
            far((f32::INFINITY, f32::NEG_INFINITY)).copy(2.2, 2.4),
            Some((f32::NEG_INFINITY, f32::NEG_INFINITY))
        );
        // Without a period: the query itself.
        let mut flat = Index::<16>::new();
        let mut b = flat.builder((0.0, 1.0), Unkeyed::MeetAll);
        b.push_all([0.1f32, 0.2, 0.3].iter().map(|&k| (k, 0.0)));
        b.finish(None);
        assert_eq!(flat.lean().copy(5.0, 6.0), Some((5.0, 6.0)));
    }

    /// A segment of pseudo-angle keys whose ends are half a turn apart to
    /// within their margins (it passes within a hair of the FOE) may go
    /// either way round: it is offered to every query, as a segment with
    /// an unkeyed end is, not to the half-turn its rounded keys suggest.
    /// (Here the keys say 2 + 10⁻⁶ apart, unwrapped to the other way
    /// round, while a ray of key 2 may well meet it.)
    #[test]
    fn a_segment_half_a_turn_long_meets_every_key() {
        for (a, b) in [(1.0f32, 3.000_001f32), (3.000_001, 1.0), (0.5, 2.499_999)] {
            let mut index = Index::<8>::new();
            let mut builder = index.builder((4.0, 1.0), Unkeyed::MeetAll);
            builder.push_all([(a, 1.0e-5), (b, 1.0e-5)].into_iter());
            builder.finish(None);
            let mid = 0.5 * (a + b);
            let mut seen = Record {
                seen: [false; CAP],
                last: None,
                ordered: true,
            };
            let mut work = Work::new();
            work.grant(1000);
            let q = Query::Keys(mid - 0.01, mid + 0.01);
            assert!(index.visit(q, false, None, &mut work, &mut seen).is_ok());
            assert!(
                seen.seen[0],
                "({a}, {b}): the segment was not offered for key {mid}"
            );
        }
    }
}
