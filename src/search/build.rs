//! Building an index: the keys pushed vertex by vertex ([`Builder`], with
//! the order tracker [`KeyOrder`] that step 1 shares), the envelopes, the
//! outlier pass and the rebuild, the block tree.

use super::*;
use core::cell::Cell;

impl<const N: usize> Index<N> {
    /// Start indexing a polyline: push its vertex keys and their margins
    /// in order ([`Builder::push_all`] and its kin), then
    /// [`Builder::finish`]. `period` 4
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
        self.tree_end = 0;
        self.radial_levels = UNBUILT;
        self.aside.clear();
        self.near.clear();
        self.near_overflow = false;
        Builder {
            uneven: false,
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
    /// than `wide` apart (`None`: `tick`'s clock stopped the pass). With
    /// `stop_once_loose` only that answer is wanted where it is yes (a
    /// rebuild follows, which computes the minima anew, to the end: it
    /// has no clock here either): without a clock the pass stops when the
    /// last two segments tell (an outlier at a boundary's far end, often),
    /// the minima before them left as they were.
    fn suffix_minima(
        &mut self,
        (wide, uneven): (f32, bool),
        tick: &mut Tick<'_>,
        stop_once_loose: bool,
    ) -> Option<bool> {
        // (Two forms: the even one is the pass it was, without the
        // widths' test, about 5 instructions a segment.)
        if uneven {
            self.suffix_minima_of::<true>(wide, tick, stop_once_loose)
        } else {
            self.suffix_minima_of::<false>(wide, tick, stop_once_loose)
        }
    }

    /// [`Self::suffix_minima`], for an uneven polyline or not.
    #[inline(always)]
    fn suffix_minima_of<const UNEVEN: bool>(
        &mut self,
        wide: f32,
        tick: &mut Tick<'_>,
        stop_once_loose: bool,
    ) -> Option<bool> {
        let s = self.segments;
        let Some(seg) = self.seg.get_mut(..s) else {
            return Some(false);
        };
        let (mut run, mut gap) = (f32::INFINITY, f32::NEG_INFINITY);
        // (A thinned polyline's segments are uneven, [`Builder::uneven`]:
        // a long chord is as wide in keys as the run it stands for, and
        // only what its envelope adds to its own interval is a fold's.)
        let mut one = |g: &mut Seg| {
            run = fmin(run, g.lo);
            g.sm = run;
            if UNEVEN {
                let w = g.hi - g.lo;
                let own = if w > 0.0 && w < f32::INFINITY { w } else { 0.0 };
                gap = fmax(gap, (g.pm - run) - own);
            } else {
                gap = fmax(gap, g.pm - run);
            }
            gap
        };
        match tick {
            None => {
                // (The last two peeled off the loop, not a loop of their
                // own: the rest is the loop it was.)
                let head = match seg {
                    [head @ .., a, b] => {
                        one(b);
                        // (The gap only grows from here: `fmax` keeps the
                        // larger of two numbers, and `pm − run` is never
                        // NaN in a first pass, which needs `pm` and `run`
                        // the same infinity. In frame 2's index the
                        // intervals are finite or `(−∞, ∞)`, so `pm` is
                        // finite or `+∞` and `run` finite or `−∞`; in the
                        // fold test's they are finite or empty, `(∞, −∞)`,
                        // so `pm` is finite or `−∞` and `run` finite or
                        // `+∞`. Once over `wide` the whole pass's answer
                        // is yes.)
                        if one(a) > wide && stop_once_loose {
                            return Some(true);
                        }
                        head
                    }
                    seg => seg,
                };
                head.iter_mut().rev().for_each(|g| {
                    one(g);
                });
            }
            Some(t) => {
                for (c, part) in seg.rchunks_mut(CHUNK).enumerate() {
                    if c > 0 && t() {
                        return None;
                    }
                    part.iter_mut().rev().for_each(|g| {
                        one(g);
                    });
                }
            }
        }
        // (A NaN gap fails: loose.)
        Some(!(gap <= wide))
    }

    /// The slow path of [`Builder::finish`]: orient the intervals as `orient`,
    /// set aside the unkeyed segments and those of outlying vertices, and
    /// rebuild the envelopes without them; `false` when `tick`'s clock
    /// stopped it (the index then unfit for queries).
    #[inline(never)]
    fn rebuild(
        &mut self,
        orient: f32,
        (wide, uneven): (f32, bool),
        tick: &mut Tick<'_>,
        defer: bool,
    ) -> bool {
        let s = self.segments;
        let Some(seg) = self.seg.get_mut(..s) else {
            return true;
        };
        let flip = orient != self.orient;
        if flip {
            for (j, g) in seg.iter_mut().enumerate() {
                if j % CHUNK == CHUNK - 1 && expired(tick) {
                    return false;
                }
                (g.lo, g.hi) = (-g.hi, -g.lo);
            }
            self.orient = orient;
        }
        // The unkeyed segments and the outliers aside ([`outliers`]),
        // listed in the index's own list (not a list returned and copied:
        // two copies of its 100 bytes).
        let aside = &mut self.aside;
        if !outliers(seg, wide, tick, aside) {
            aside.clear();
            return false;
        }
        for &(j, _, _) in aside.iter() {
            if let Some(g) = seg.get_mut(usize::from(j)) {
                (g.lo, g.hi) = (f32::INFINITY, f32::NEG_INFINITY);
            }
        }
        // The prefix maxima anew from the first segment set aside (before
        // it the intervals are those the pushes left, and so are their
        // prefix maxima, the same running maximum), from the first segment
        // where the intervals were flipped. (Outliers are mostly near a
        // boundary's ends: `demo_13` 937.4 → 930.2 instructions a point.
        // Over `enumerate().skip(from)` instead of the slice from `from`
        // the bench firmware measured dearer, `worst_found` +2.7 %.)
        let from = match aside.first() {
            _ if flip => 0,
            Some(&(j, _, _)) => usize::from(j),
            None => s,
        };
        let Some(seg) = self.seg.get_mut(..s) else {
            return true;
        };
        let mut run = from
            .checked_sub(1)
            .and_then(|i| seg.get(i))
            .map_or(f32::NEG_INFINITY, |g| g.pm);
        for (k, g) in seg
            .get_mut(from..)
            .unwrap_or_default()
            .iter_mut()
            .enumerate()
        {
            if (from + k) % CHUNK == CHUNK - 1 && expired(tick) {
                return false;
            }
            run = fmax(run, g.hi);
            g.pm = run;
        }
        // The block tree for runs through the rebuilt envelopes, when they
        // are still loose (tight runs are short: no tree needed).
        let Some(loose) = self.suffix_minima((wide, uneven), tick, false) else {
            return false;
        };
        self.loose = loose;
        if loose && defer {
            // Left for the lean wedge walks ([`LazyBlocks`]).
            (self.levels, self.tree_end) = (0, PENDING);
            return true;
        }
        !loose || self.build_tree(tick)
    }

    /// The block tree over the current intervals (module docs): the key
    /// levels, `(min lo, max hi)` of each block ([`build_levels`]); `false`
    /// when `tick`'s clock stopped it.
    fn build_tree(&mut self, tick: &mut Tick<'_>) -> bool {
        // (The segments as [`Self::lean_lazy`] takes them: one tree.)
        let seg = self.seg.get(..self.segments.min(N)).unwrap_or(&[]);
        let tree = Cell::from_mut(self.tree.as_mut_slice()).as_slice_of_cells();
        match key_levels(seg, tree, tick) {
            Some(built) => {
                (self.levels, self.tree_end) = built;
                true
            }
            None => false,
        }
    }

    /// The block tree's radial levels (module docs) for the polyline `b`
    /// this index was built from, after the key levels: `(min lo, max hi)`
    /// of each block's intervals and `(min v, max v)` of its vertices'
    /// rows (the `FAN^l + 1` vertices of its segments) ([`build_levels`]).
    /// Built once until the next build of the index; none when `b` is not
    /// this index's polyline, or when `tick`'s clock stops the build (the
    /// queries then go without them).
    pub(super) fn build_radial(&mut self, b: &[crate::camera::Pixel], tick: &mut Tick<'_>) {
        self.radial_levels = 0;
        let s = self.segments;
        // (A key tree left to build, `tree_end` [`PENDING`]: no radial
        // levels either; only the lean walks search such an index.)
        if s == 0 || b.len() != s + 1 || self.tree_end == PENDING {
            return;
        }
        let seg = &self.seg;
        let leaf = |c0: usize, c1: usize| {
            let mut q = [
                f32::INFINITY,
                f32::NEG_INFINITY,
                f32::INFINITY,
                f32::NEG_INFINITY,
            ];
            for g in seg.get(c0..c1).unwrap_or(&[]) {
                (q[0], q[1]) = (fmin(q[0], g.lo), fmax(q[1], g.hi));
            }
            // A block whose rows cannot be read gets the widest (no
            // rejection).
            match b.get(c0..=c1) {
                Some(vs) => {
                    for p in vs {
                        (q[2], q[3]) = (fmin(q[2], p.v), fmax(q[3], p.v));
                    }
                }
                None => (q[2], q[3]) = (f32::NEG_INFINITY, f32::INFINITY),
            }
            q
        };
        let leaves = (0..s.div_ceil(FAN)).map(|k| leaf(k * FAN, ((k + 1) * FAN).min(s)));
        let tree = Cell::from_mut(self.tree.as_mut_slice()).as_slice_of_cells();
        let Some((levels, _)) = build_levels(tree, s, self.tree_end, leaves, tick) else {
            return;
        };
        // (`levels` ≤ LEVELS = 4.)
        self.radial_levels = u8::try_from(levels).unwrap_or(0);
    }
}

/// The block tree's key levels over the segments `seg` in `tree`
/// ([`build_levels`] with each block's `(min lo, max hi)`): how many were
/// built and where they end; `None` when `tick`'s clock stopped it.
pub(super) fn key_levels(
    seg: &[Seg],
    tree: &[Cell<f32>],
    tick: &mut Tick<'_>,
) -> Option<(usize, usize)> {
    let hull = |c: &[Seg]| {
        let mut q = [f32::INFINITY, f32::NEG_INFINITY];
        for g in c {
            q = [fmin(q[0], g.lo), fmax(q[1], g.hi)];
        }
        q
    };
    // (Whole blocks, then the short last one: the same blocks as
    // `chunks(FAN)`, the whole ones each in one straight run.)
    let blocks = seg.chunks_exact(FAN);
    let last = Some(blocks.remainder()).filter(|r| !r.is_empty());
    let leaves = blocks.map(hull).chain(last.map(hull));
    build_levels(tree, seg.len(), 0, leaves, tick)
}

/// Levels of a block tree over `s` segments in `tree` from `base` on,
/// `W` values a block: level 1's block `k` is the `k`-th of `leaves` (the
/// values of segments `k·FAN .. min((k + 1)·FAN, s)`; the widest where
/// there are fewer), each higher level's block the hull of the
/// `FAN` blocks below it (values at even places the minimum, at odd places
/// the maximum: `(min, max)` pairs). As many levels as fit in `tree` (level
/// `l` has `⌈s / FAN^l⌉` blocks), at most [`LEVELS`], stopping at the level
/// of one block; returns how many were built and where the last one ends.
/// Every loop is bounded by the array or by the blocks of the level below;
/// an entry that cannot be read counts as the widest (`−∞` at even places,
/// `∞` at odd ones). `None` when `tick`'s clock stopped it (asked before
/// every `CHUNK / FAN` blocks: about `CHUNK` segments' or blocks' work).
fn build_levels<const W: usize>(
    tree: &[Cell<f32>],
    s: usize,
    mut base: usize,
    leaves: impl Iterator<Item = [f32; W]>,
    tick: &mut Tick<'_>,
) -> Option<(usize, usize)> {
    let mut leaves = leaves;
    let mut widest = [0.0f32; W];
    for (i, v) in widest.iter_mut().enumerate() {
        *v = if i % 2 == 0 {
            f32::NEG_INFINITY
        } else {
            f32::INFINITY
        };
    }
    let (mut built, mut end_of) = (0usize, base);
    let (mut below_base, mut below_n, mut size) = (0usize, s, 1usize);
    for level in 1..=LEVELS {
        size = size.saturating_mul(FAN);
        let n = s.div_ceil(size);
        let Some(end) = base.checked_add(W * n).filter(|&e| e <= tree.len()) else {
            break;
        };
        if level == 1 {
            // (The same blocks, written in order.)
            let blocks = tree.get(base..end).unwrap_or_default();
            for (k, t) in blocks.chunks_exact(W).enumerate() {
                if k % (CHUNK / FAN) == CHUNK / FAN - 1 && expired(tick) {
                    return None;
                }
                for (t, v) in t.iter().zip(leaves.next().unwrap_or(widest)) {
                    t.set(v);
                }
            }
        } else {
            for k in 0..n {
                if k % (CHUNK / FAN) == CHUNK / FAN - 1 && expired(tick) {
                    return None;
                }
                let mut q = [0.0f32; W];
                for (i, v) in q.iter_mut().enumerate() {
                    *v = if i % 2 == 0 {
                        f32::INFINITY
                    } else {
                        f32::NEG_INFINITY
                    };
                }
                for c in k * FAN..((k + 1) * FAN).min(below_n) {
                    for (i, v) in q.iter_mut().enumerate() {
                        let at = tree.get(below_base + W * c + i).map(Cell::get);
                        *v = if i % 2 == 0 {
                            fmin(*v, at.unwrap_or(f32::NEG_INFINITY))
                        } else {
                            fmax(*v, at.unwrap_or(f32::INFINITY))
                        };
                    }
                }
                if let Some(t) = tree.get(base + W * k..base + W * (k + 1)) {
                    for (t, v) in t.iter().zip(q) {
                        t.set(v);
                    }
                }
            }
        }
        (built, end_of) = (level, end);
        below_base = base;
        below_n = n;
        base = end;
        if n <= 1 {
            break;
        }
    }
    Some((built, end_of))
}

/// The segments of `seg` to set aside ([`Index::rebuild`]), in order, at
/// most [`MAX_ASIDE`]: the unkeyed ones (an interval from `−∞`, frame 2's)
/// and the outliers, whose interval reaches more than `wide` beyond those
/// of the segments two places before and after it (both segments of a
/// spurious vertex do; along a boundary whose keys move one way, neither
/// end of an interval passes both of those). A heuristic for speed only:
/// any choice gives the same results. (An empty interval, `(∞, −∞)`, or a
/// missing neighbour leaves the neighbours' hull as it is; with neither
/// there is no hull, `hi = −∞`: intervals are never otherwise inverted,
/// and a non-empty one has `hi > −∞`.) Listed in `aside` (cleared first);
/// `false` when `tick`'s clock stopped the pass.
#[inline(always)]
pub(super) fn outliers(
    seg: &[Seg],
    wide: f32,
    tick: &mut Tick<'_>,
    aside: &mut heapless::Vec<Aside, MAX_ASIDE>,
) -> bool {
    aside.clear();
    // Segment `j` (interval `g`) between the intervals `b` two places
    // before and `a` two places after. The reach first (most segments fail
    // it; a NaN fails), then whether the ends and the hull are those of
    // keyed segments.
    let mut test = |j: usize, g: &Seg, (bl, bh): (f32, f32), (al, ah): (f32, f32)| {
        let (lo, hi) = (fmin(bl, al), fmax(bh, ah));
        let all = g.lo == f32::NEG_INFINITY;
        let far = g.hi - hi > wide || lo - g.lo > wide;
        let out = far && g.lo.is_finite() && g.hi.is_finite() && hi > f32::NEG_INFINITY;
        if (all || out) && !aside.is_full() {
            if let Ok(jj) = u16::try_from(j) {
                let _ = aside.push((jj, g.lo, g.hi));
            }
        }
    };
    let ends = |i: Option<usize>| {
        i.and_then(|i| seg.get(i))
            .map_or((f32::INFINITY, f32::NEG_INFINITY), |x| (x.lo, x.hi))
    };
    // The first two segments and the last two look their neighbours up
    // (one may be missing); those between, which have both, come from
    // windows of five, without a look-up's bound checks. (With a look-up
    // of both neighbours for every segment, and the test of the ends'
    // finiteness first, the pass cost about 50 instructions a segment;
    // from three zipped slices 36, `demo_13` 953.9 → 936.7 instructions a
    // point; from the windows 34, → 913.6 with the later steps.)
    let s = seg.len();
    let head = s.min(2);
    let tail = s.saturating_sub(2).max(head);
    for j in 0..head {
        if let Some(g) = seg.get(j) {
            test(j, g, ends(j.checked_sub(2)), ends(Some(j + 2)));
        }
    }
    // `wide`, finite (the first filter below; with `wide` infinite or NaN
    // no reach passes `test`, and `f32::MAX` lets every unkeyed segment
    // through).
    let reach = if wide < f32::INFINITY { wide } else { f32::MAX };
    let mut window = |k: usize, w: &[Seg]| {
        let [b, _, g, _, a] = w else {
            return;
        };
        // `test` sets `g` aside only if it reaches more than `wide` beyond
        // `b` alone (the hull's ends are beyond `b`'s, or NaN, and then
        // `test`'s reach fails; a rounded difference is monotone in what
        // it subtracts), or if it is unkeyed: then `b.lo − g.lo` is `+∞`
        // or NaN, beyond any finite `reach`. So only such segments are
        // tested (a NaN passes to the test).
        if !(g.hi - b.hi <= reach) || !(b.lo - g.lo <= reach) {
            test(k + 2, g, (b.lo, b.hi), (a.lo, a.hi));
        }
    };
    match tick {
        // (Without a clock a loop without its question: about 4
        // instructions a segment fewer.)
        None => seg.windows(5).enumerate().for_each(|(k, w)| window(k, w)),
        Some(t) => {
            for (k, w) in seg.windows(5).enumerate() {
                if (k + 2) % CHUNK == CHUNK - 1 && t() {
                    return false;
                }
                window(k, w);
            }
        }
    }
    for j in tail..s {
        if j % CHUNK == CHUNK - 1 && expired(tick) {
            return false;
        }
        if let Some(g) = seg.get(j) {
            test(j, g, ends(j.checked_sub(2)), ends(Some(j + 2)));
        }
    }
    true
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

    /// [`Self::push`] for every key and margin `keys` gives, in order,
    /// until [`Self::settled`] (pushes after it cannot change
    /// [`Self::strict`]): the same state as those pushes (but `prev`,
    /// `plo`, `phi` once settled). Once one direction is left, a loop that
    /// tests only it. `BOUNDED`: every key is [`NO_KEY`] or finite and at
    /// most 2 in magnitude (half-plane keys, [`crate::pencil::half_key`]),
    /// so that a key is finite with the one before exactly when it is not
    /// `NO_KEY`: that loop asks so. Returns how many of `keys` were
    /// pushed: once settled, the last of them settled it, and those
    /// before it since the first push were all keyed and their widened
    /// keys strictly ordered one way (the fold test's lead,
    /// `crate::fold`).
    #[inline(always)]
    pub(crate) fn push_until_settled<const BOUNDED: bool>(
        &mut self,
        keys: impl ExactSizeIterator<Item = (f32, f32)>,
    ) -> usize {
        let mut keys = keys;
        let all = keys.len();
        while !self.settled() && (self.first || (self.up && self.down)) {
            let Some((k, e)) = keys.next() else {
                return all;
            };
            self.push(k, e);
        }
        if self.settled() {
            return all - keys.len();
        }
        // Every pair keyed so far, one direction left: `push` with the
        // other's test dropped (it stays false), a loop for each. (One
        // loop choosing the test measured 678.2 instructions a point on
        // the representative window, a generic helper for both 672.3,
        // the two loops written out 670.8; pushes one at a time 673.7.)
        let (mut prev, mut plo, mut phi) = (self.prev, self.plo, self.phi);
        let (odd, unordered) = if self.up {
            let mut r = (false, false);
            for (k, e) in keys.by_ref() {
                let (vlo, vhi) = (k - e, k + e);
                // (`prev` keyed: one direction is left.)
                let both = if BOUNDED {
                    k != NO_KEY
                } else {
                    (k + prev).is_finite()
                };
                let o = vlo > phi;
                (prev, plo, phi) = (k, vlo, vhi);
                if !both {
                    r = (true, false);
                    break;
                }
                if !o {
                    r = (false, true);
                    break;
                }
            }
            r
        } else {
            let mut r = (false, false);
            for (k, e) in keys.by_ref() {
                let (vlo, vhi) = (k - e, k + e);
                // (`prev` keyed: one direction is left.)
                let both = if BOUNDED {
                    k != NO_KEY
                } else {
                    (k + prev).is_finite()
                };
                let o = vhi < plo;
                (prev, plo, phi) = (k, vlo, vhi);
                if !both {
                    r = (true, false);
                    break;
                }
                if !o {
                    r = (false, true);
                    break;
                }
            }
            r
        };
        self.odd |= odd;
        if unordered {
            (self.up, self.down) = (false, false);
        }
        (self.prev, self.plo, self.phi) = (prev, plo, phi);
        all - keys.len()
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
    /// The polyline was thinned ([`Self::uneven`]).
    uneven: bool,
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
            Some(Some(raw))
        });
    }

    /// [`Self::push_all`] for the keys `key` gives the points `pts`, `None`
    /// where there is none ([`NO_KEY`], margin 0), otherwise finite and at
    /// most 2 in magnitude (half-plane keys,
    /// [`crate::pencil::half_key_or_none`], are at most 1; any bound far
    /// below `f32::MAX / 2` would do): then a key and the one before sum to
    /// a finite value exactly when there is a key, the lean loop's test,
    /// asked where the key is made (the same index). [`Self::push_run`]
    /// with its lean loop over the points, the margins and the segments
    /// together: one count for the three.
    #[inline(always)]
    pub(crate) fn push_all_bounded<P>(
        &mut self,
        pts: &[P],
        key: impl Fn(&P) -> Option<(f32, f32)>,
    ) {
        let mut rest = pts;
        // The next point's key through `push_run`'s `next`.
        let next_of = |rest: &mut &[P], m: &mut f32| {
            let (p, tail) = rest.split_first()?;
            *rest = tail;
            Some(key(p).map(|(raw, e)| {
                *m = e;
                raw
            }))
        };
        let unkeyed = |m: &mut f32, raw: Option<f32>| {
            if raw.is_none() {
                *m = 0.0;
            }
            raw
        };
        if self.period <= 0.0 {
            if self.n == 0 {
                let first = self.index.margin.first_mut();
                let Some(raw) = first.and_then(|m| next_of(&mut rest, m).map(|r| unkeyed(m, r)))
                else {
                    return;
                };
                self.push_stored(raw.unwrap_or(NO_KEY));
            }
            let n0 = self.n;
            let k = self.order.prev;
            let last = n0.checked_sub(1).and_then(|i| self.index.margin.get(i));
            let (Some(&e), true) = (last, k.is_finite()) else {
                return self.push_rest(|m| next_of(&mut rest, m).map(|r| unkeyed(m, r)));
            };
            let o = self.o;
            let (mut prev, mut plo, mut phi) = (k, k - e, k + e);
            let (mut run, mut sum) = (self.run, self.sum);
            let margins = self.index.margin.get_mut(n0..).unwrap_or_default();
            let segs = self
                .index
                .seg
                .get_mut(n0.saturating_sub(1)..)
                .unwrap_or_default();
            let (mut taken, mut pending) = (0usize, false);
            for ((m, g), p) in margins.iter_mut().zip(segs.iter_mut()).zip(rest) {
                let Some((raw, e)) = key(p) else {
                    *m = 0.0;
                    pending = true;
                    break;
                };
                *m = e;
                let k = o * raw;
                let (vlo, vhi) = (k - e, k + e);
                g.lo = fmin(plo, vlo);
                g.hi = fmax(phi, vhi);
                sum += g.hi - g.lo;
                run = fmax(run, g.hi);
                g.pm = run;
                (prev, plo, phi) = (k, vlo, vhi);
                taken += 1;
            }
            if taken > 0 {
                self.order = KeyOrder {
                    prev,
                    plo,
                    phi,
                    first: false,
                    up: false,
                    down: false,
                    odd: self.order.odd,
                };
                (self.n, self.run, self.sum, self.last) = (n0 + taken, run, sum, prev);
            }
            rest = rest.get(taken..).unwrap_or_default();
            if pending {
                rest = rest.get(1..).unwrap_or_default();
                self.push_stored(NO_KEY);
            }
        }
        self.push_rest(|m| next_of(&mut rest, m).map(|r| unkeyed(m, r)));
    }

    /// [`Self::push_stored`] for every raw key `keys` gives, in order
    /// (through [`Self::push_run`]).
    #[inline(always)]
    pub(crate) fn push_all_stored(&mut self, keys: impl Iterator<Item = f32>) {
        let mut keys = keys;
        self.push_run(|_| keys.next().map(Some));
    }

    /// Push vertices while `next` gives their raw keys, each with its
    /// margin put in (or already in) the slot it is handed; at most `N`.
    /// While the keys have no period and are finite (the usual polyline)
    /// a lean loop writes the intervals and prefix maxima (the values
    /// [`Self::push_stored`] gives) without the key-order test (the index
    /// is then not [`Index::strict`], a shortcut of the fold test only);
    /// from the first vertex it cannot take on, [`Self::push_stored`]. A
    /// polyline may come in parts (a caller's deadline asked between them):
    /// a part that follows a finite key goes on in the lean loop, with the
    /// same values one call would give. `next` gives `None` at the end,
    /// `Some(None)` for a vertex without a key (a raw [`NO_KEY`]). (Keys
    /// known bounded take [`Self::push_all_bounded`]'s loop instead.)
    #[inline(always)]
    fn push_run(&mut self, mut next: impl FnMut(&mut f32) -> Option<Option<f32>>) {
        let mut pending = None;
        if self.period <= 0.0 {
            if self.n == 0 {
                let Some(raw) = self.index.margin.first_mut().and_then(&mut next) else {
                    return;
                };
                self.push_stored(raw.unwrap_or(NO_KEY));
            }
            // The last vertex's oriented key and margin (`push_stored`
            // keeps the key in the order tracker, the lean loop below too).
            let n0 = self.n;
            let k = self.order.prev;
            let last = n0.checked_sub(1).and_then(|i| self.index.margin.get(i));
            let (Some(&e), true) = (last, k.is_finite()) else {
                return self.push_rest(next);
            };
            let o = self.o;
            let (mut prev, mut plo, mut phi) = (k, k - e, k + e);
            let (mut run, mut sum) = (self.run, self.sum);
            let mut n = n0;
            let margins = self.index.margin.get_mut(n0..).unwrap_or_default();
            let segs = self
                .index
                .seg
                .get_mut(n0.saturating_sub(1)..)
                .unwrap_or_default();
            for (m, g) in margins.iter_mut().zip(segs.iter_mut()) {
                let Some(key) = next(m) else {
                    break;
                };
                let Some(raw) = key else {
                    pending = Some(NO_KEY);
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
            if n > n0 {
                self.order = KeyOrder {
                    prev,
                    plo,
                    phi,
                    first: false,
                    up: false,
                    down: false,
                    odd: self.order.odd,
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
    pub(super) fn push(&mut self, raw: f32, e: f32) {
        if let Some(m) = self.index.margin.get_mut(self.n) {
            *m = e;
            self.push_stored(raw);
        }
    }

    /// The rest of [`Self::push_run`], one [`Self::push_stored`] at a time.
    fn push_rest(&mut self, mut next: impl FnMut(&mut f32) -> Option<Option<f32>>) {
        while let Some(raw) = self.index.margin.get_mut(self.n).and_then(&mut next) {
            self.push_stored(raw.unwrap_or(NO_KEY));
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
            // (`keyed` holds the last key times `o`, in the raw keys'
            // orientation, `NO_KEY` before the first: the first key is `o`
            // times its raw key plus a turn, and either guess holds the
            // other's keys negated, bit for bit, through the same
            // decisions and roundings.)
            let d = k - self.o * self.keyed;
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
                doubtful = 2.0 - (k - self.o * self.keyed).abs() <= 2.0 * m;
            }
            self.keyed = self.o * k;
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
    /// with `W' < 0`; `None` otherwise). `false` when `tick`'s clock
    /// stopped a pass ([`Tick`]): the index is then unfit for queries.
    pub(crate) fn finish(self, near: Option<&dyn Fn(usize) -> bool>, tick: &mut Tick<'_>) -> bool {
        self.finish_with(near, tick, false)
    }

    /// Mark the polyline as thinned ([`crate::thin`]) when `on`: its
    /// segments' lengths are then uneven (a chord stands for a run of the
    /// detected ones), so a wide interval is not by itself a fold or an
    /// outlier, and the index is loose only where an envelope reaches more
    /// than [`WIDE`] average widths beyond the segment's own interval (a
    /// run's length depends on that excess, not on the width). Only which
    /// structure the queries walk changes, never what they find.
    pub(crate) fn uneven(mut self, on: bool) -> Self {
        self.uneven = on;
        self
    }

    /// [`Self::finish`] without a clock, a loose index's block tree left
    /// until a walk reads it ([`LazyBlocks`], [`Index::lean_lazy`]): for an
    /// index searched only by the lean wedge walks, which build it at their
    /// first aligned segment that misses their keys, the build's tree
    /// exactly. Along most road boundaries whose keys fold somewhere no
    /// walk gets there, and the tree (about 8 instructions a segment) is
    /// never built. Any other reader of the index sees no tree (`levels`
    /// 0), which skips nothing and so is never wrong, only slower, and no
    /// radial levels are built; the caller takes this build only where
    /// the lean walks are the one search
    /// ([`crate::processor`]'s `frame2_index`).
    pub(crate) fn finish_deferring_tree(self, near: Option<&dyn Fn(usize) -> bool>) -> bool {
        self.finish_with(near, &mut None, true)
    }

    /// [`Self::finish`], the block tree left to build with `defer`.
    /// (Inlined into both: the per-frame call's build measured the
    /// representative window 488 067 estimated cycles so, 488 809 with one
    /// copy out of line, 488 823 with one call taking `defer`.)
    #[inline(always)]
    fn finish_with(
        self,
        near: Option<&dyn Fn(usize) -> bool>,
        tick: &mut Tick<'_>,
        defer: bool,
    ) -> bool {
        let Builder {
            index,
            o,
            n,
            first,
            last,
            sum,
            order,
            period,
            uneven,
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
        // (Loose envelopes are rebuilt, and their minima computed anew:
        // this pass may stop once it knows, `answer`. Where an outlier at
        // the boundary's far end tells, the whole pass is saved: `demo_13`
        // 930.2 → 915.7 instructions a point.)
        let Some(loose) = index.suffix_minima((wide, uneven), tick, true) else {
            return false;
        };
        index.loose = loose;
        if (loose || odd || flip)
            && !index.rebuild(if flip { -o } else { o }, (wide, uneven), tick, defer)
        {
            return false;
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
                if j % CHUNK == CHUNK - 1 && expired(tick) {
                    return false;
                }
                if is_near(j) {
                    match u16::try_from(j).ok().map(|jj| index.near.push(jj)) {
                        Some(Ok(())) => {}
                        _ => index.near_overflow = true,
                    }
                }
            }
        }
        true
    }
}
