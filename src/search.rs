//! The search structure: which segments of a polyline can meet the rays
//! whose keys lie in a given interval.
//!
//! Every segment `j` (from vertex `j` to `j + 1`) gets the interval of its
//! end points' keys ([`crate::pencil`]); a ray can only meet the segment if
//! its key lies in it. The index answers "every segment whose interval
//! meets `[q_lo, q_hi]`", in increasing `j`, with the guarantee that no such
//! segment is left out (the caller then decides with the exact geometry,
//! so any superset gives the same result as a scan of every segment). Its
//! invariants:
//!
//! 1. Keys are *oriented* (multiplied by ±1) so that they rise from the
//!    first to the last keyed vertex, and pseudo-angles are *unwrapped*
//!    along the polyline (consecutive keys less than half a turn apart).
//! 2. A few segments are kept *aside*, in a short sorted list that every
//!    query checks: segments with an unkeyable end (frame 2: they may meet
//!    any ray) and the two segments of each *outlying* vertex, one whose key
//!    lies far outside its neighbours' (a spurious detector point): a few
//!    such vertices would otherwise stretch every run. Their place in the
//!    arrays holds the empty interval.
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
//! Periodic keys (pseudo-angles) are searched at each copy `q + 4m` that
//! can meet the keys' range (at most [`MAX_COPIES`], else every segment is
//! visited).

use crate::math::{fmax, fmin};
use crate::pencil::NO_KEY;

/// Segments kept aside (see the module docs).
pub(crate) const MAX_ASIDE: usize = 8;
/// Frame-2 segments near the FOE listed for bands that run into it.
pub(crate) const MAX_NEAR: usize = 8;
/// Linear probes before a search for the run's start falls back to
/// bisection.
const PROBES: usize = 8;
/// At most this many copies of a periodic key are searched one by one.
pub(crate) const MAX_COPIES: usize = 3;
/// A vertex is an outlier when its key lies outside its neighbours' by more
/// than this many times their own difference, and by more than [`WIDE`]
/// times the average width of a segment's interval.
const OUTLYING: f32 = 4.0;
/// See [`OUTLYING`].
const WIDE: f32 = 8.0;
/// Outlying vertices whose segments an index keeps aside.
const MAX_OUTLIERS: usize = MAX_ASIDE / 2;

/// Work units: every segment a query looks at costs one, every bisection
/// step one; the caller pays its own exact tests.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Work {
    credit: u32,
}

/// The frame's work budget was spent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct OutOfWork;

/// TEMPORARY instrumentation.
#[cfg(feature = "_reference")]
#[doc(hidden)]
pub mod probe {
    use core::sync::atomic::{AtomicU32, Ordering};
    pub static RUN: AtomicU32 = AtomicU32::new(0);
    pub static TAKEN: AtomicU32 = AtomicU32::new(0);
    pub static BISECT: AtomicU32 = AtomicU32::new(0);
    pub static QUERIES: AtomicU32 = AtomicU32::new(0);
    pub static ASIDE: AtomicU32 = AtomicU32::new(0);
    pub fn add(c: &AtomicU32, n: u32) {
        c.fetch_add(n, Ordering::Relaxed);
    }
    pub fn take(c: &AtomicU32) -> u32 {
        c.swap(0, Ordering::Relaxed)
    }
}

impl Work {
    pub(crate) const fn new() -> Self {
        Self { credit: 0 }
    }

    /// Add a point's allowance.
    #[inline(always)]
    pub(crate) fn grant(&mut self, units: u32) {
        self.credit = self.credit.saturating_add(units);
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

/// The index of one polyline (see the module docs). Memory: `20 N` bytes
/// plus the two short lists.
#[derive(Debug, Clone)]
pub(crate) struct Index<const N: usize> {
    /// Each vertex's key margin ([`crate::pencil`]).
    margin: [f32; N],
    lo: [f32; N],
    hi: [f32; N],
    pm: [f32; N],
    sm: [f32; N],
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
    /// Outlying vertex candidates of the last build: vertex and how far its
    /// key lies outside its neighbours'.
    outliers: heapless::Vec<(usize, f32), MAX_OUTLIERS>,
    hint: usize,
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
            margin: [0.0; N],
            lo: [0.0; N],
            hi: [0.0; N],
            pm: [0.0; N],
            sm: [0.0; N],
            segments: 0,
            orient: 1.0,
            period: 0.0,
            kmin: 0.0,
            kmax: 0.0,
            aside: heapless::Vec::new(),
            near: heapless::Vec::new(),
            near_overflow: false,
            outliers: heapless::Vec::new(),
            hint: 0,
        }
    }

    /// Index the polyline whose vertex keys and their margins (raw keys,
    /// [`NO_KEY`] where none) `keys` yields, at most `N` of them; `period` 4
    /// for pseudo-angles. A segment's interval is that of its end keys,
    /// each widened by its margin.
    ///
    /// `near(j)` says whether segment `j` comes within the FOE-near radius
    /// (frame 2 with `W' < 0`; `None` otherwise).
    pub(crate) fn build(
        &mut self,
        keys: impl Iterator<Item = (f32, f32)>,
        period: f32,
        unkeyed: Unkeyed,
        near: Option<&dyn Fn(usize) -> bool>,
    ) {
        self.period = period;
        self.hint = 0;
        self.aside.clear();
        self.near.clear();
        self.near_overflow = false;
        self.outliers.clear();
        // Unwrapped vertex keys and the per-segment intervals (raw
        // orientation); the orientation from the first and last keyed
        // vertex; the outlying vertices, from a window of three keys.
        // Bounded by `N` (the arrays).
        let mut window = [NO_KEY; 3];
        let (mut before, mut keyed, mut offset) = ((NO_KEY, 0.0f32), NO_KEY, 0.0f32);
        let (mut first, mut last) = (NO_KEY, NO_KEY);
        let mut n = 0usize;
        for ((i, (raw, e)), m) in keys.enumerate().zip(self.margin.iter_mut()) {
            *m = e;
            let mut k = raw;
            if k.is_finite() {
                k += offset;
                if period > 0.0 && keyed.is_finite() {
                    // Consecutive keys are less than half a turn apart.
                    let d = k - keyed;
                    if d > 2.0 {
                        offset -= 4.0;
                        k -= 4.0;
                    } else if d < -2.0 {
                        offset += 4.0;
                        k += 4.0;
                    }
                }
                if !first.is_finite() {
                    first = k;
                }
                last = k;
                keyed = k;
            }
            if let Some(j) = i.checked_sub(1) {
                if let (Some(l), Some(h)) = (self.lo.get_mut(j), self.hi.get_mut(j)) {
                    (*l, *h) = segment_interval(before, (k, e), unkeyed);
                }
            }
            before = (k, e);
            window = [window[1], window[2], k];
            if i >= 2 {
                let [k0, k1, k2] = window;
                outlier_candidate(&mut self.outliers, i - 1, k1, k0, k2);
                if i == 2 {
                    outlier_candidate(&mut self.outliers, 0, k0, k1, k2);
                }
            }
            n = i + 1;
        }
        if n >= 3 {
            let [k0, k1, k2] = window;
            outlier_candidate(&mut self.outliers, n - 1, k2, k1, k0);
        }
        self.segments = n.saturating_sub(1);
        self.orient = if last >= first || !first.is_finite() {
            1.0
        } else {
            -1.0
        };
        self.finish(near);
    }

    /// Orientation, the aside list, the envelopes and the near list.
    fn finish(&mut self, near: Option<&dyn Fn(usize) -> bool>) {
        let s = self.segments;
        let o = self.orient;
        let (Some(lo), Some(hi)) = (self.lo.get_mut(..s), self.hi.get_mut(..s)) else {
            return;
        };
        // Orient; the keys' range and the average width.
        let (mut kmin, mut kmax, mut sum, mut count) =
            (f32::INFINITY, f32::NEG_INFINITY, 0.0f32, 0u32);
        for (l, h) in lo.iter_mut().zip(hi.iter_mut()) {
            if o < 0.0 {
                (*l, *h) = (-*h, -*l);
            }
            if l.is_finite() && h.is_finite() {
                kmin = fmin(kmin, *l);
                kmax = fmax(kmax, *h);
                sum += *h - *l;
                count += 1;
            }
        }
        self.kmin = kmin;
        self.kmax = kmax;
        let wide = if count > 0 {
            WIDE * sum / count as f32
        } else {
            f32::INFINITY
        };
        // Aside: the segments meeting every key, then those next to an
        // outlying vertex, in index order while there is room; their slots
        // become empty.
        let outliers = &self.outliers;
        let outlying = |j: usize| {
            outliers
                .iter()
                .any(|&(v, dev)| dev > wide && (v == j || v == j + 1))
        };
        for (j, (l, h)) in lo.iter_mut().zip(hi.iter_mut()).enumerate() {
            let all = *l == f32::NEG_INFINITY;
            if (all || (l.is_finite() && outlying(j))) && !self.aside.is_full() {
                if let Ok(jj) = u16::try_from(j) {
                    if self.aside.push((jj, *l, *h)).is_ok() {
                        (*l, *h) = (f32::INFINITY, f32::NEG_INFINITY);
                    }
                }
            }
        }
        // Envelopes over the rest (the empty interval changes neither).
        let (Some(pm), Some(sm)) = (self.pm.get_mut(..s), self.sm.get_mut(..s)) else {
            return;
        };
        let mut run = f32::NEG_INFINITY;
        for (p, &h) in pm.iter_mut().zip(hi.iter()) {
            run = fmax(run, h);
            *p = run;
        }
        let mut run = f32::INFINITY;
        for (m, &l) in sm.iter_mut().zip(lo.iter()).rev() {
            run = fmin(run, l);
            *m = run;
        }
        if let Some(is_near) = near {
            for j in 0..s {
                if is_near(j) {
                    match u16::try_from(j).ok().map(|jj| self.near.push(jj)) {
                        Some(Ok(())) => {}
                        _ => self.near_overflow = true,
                    }
                }
            }
        }
    }

    /// The key margin of vertex `i` (0 when out of range).
    pub(crate) fn margin(&self, i: usize) -> f32 {
        self.margin.get(i).copied().unwrap_or(0.0)
    }

    /// Visit, in increasing index, every segment whose interval may meet
    /// `query` (a superset of those that do: the caller tests each), plus
    /// the FOE-near list when `with_near`; segments in `skip` (an inclusive
    /// range of indices) are left out. Each segment looked at costs one
    /// unit of `work`, each one visited `extra` more (the caller's test),
    /// each bisection step one.
    pub(crate) fn visit(
        &mut self,
        query: Query,
        with_near: bool,
        skip: Option<(usize, usize)>,
        (work, extra): (&mut Work, u32),
        mut visit: impl FnMut(usize) -> Flow,
    ) -> Result<(), OutOfWork> {
        let s = self.segments;
        #[cfg(feature = "_reference")]
        {
            probe::add(&probe::QUERIES, 1);
            probe::add(&probe::ASIDE, self.aside.len() as u32);
        }
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
            everything
                || l == f32::NEG_INFINITY
                || copies.iter().any(|&(cl, ch)| l <= ch && h >= cl)
        };
        let skipped = |k: usize| skip.is_some_and(|(x, y)| k >= x && k <= y);
        // The merge of three sorted streams: the run, the aside list and
        // (optionally) the near list, each bounded by its length; every
        // step advances one of them.
        let near: &[u16] = if with_near { &self.near } else { &[] };
        let (mut ia, mut inear) = (0usize, 0usize);
        loop {
            let next_aside = self
                .aside
                .get(ia)
                .map_or(usize::MAX, |&(k, _, _)| usize::from(k));
            let next_near = near.get(inear).map_or(usize::MAX, |&k| usize::from(k));
            let next_run = match self.sm.get(j) {
                Some(&m) if j < s && m <= top => j,
                _ => usize::MAX,
            };
            let next = next_run.min(next_aside).min(next_near);
            if next == usize::MAX {
                return Ok(());
            }
            let mut take = false;
            if next == next_aside {
                if let Some(&(_, l, h)) = self.aside.get(ia) {
                    take |= hits(l, h);
                }
                ia += 1;
            }
            if next == next_near {
                take = true;
                inear += 1;
            }
            if next == next_run {
                if let (Some(&l), Some(&h)) = (self.lo.get(j), self.hi.get(j)) {
                    take |= hits(l, h);
                }
                j += 1;
                #[cfg(feature = "_reference")]
                probe::add(&probe::RUN, 1);
            }
            #[cfg(feature = "_reference")]
            if take {
                probe::add(&probe::TAKEN, 1);
            }
            work.spend(1)?;
            if take && !skipped(next) {
                work.spend(extra)?;
                if visit(next) == Flow::Stop {
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
        if self.period <= 0.0 {
            if let Some(o) = out.first_mut() {
                *o = (ql, qh);
            }
            return Some(usize::from(ql <= self.kmax && qh >= self.kmin));
        }
        if !(self.kmin <= self.kmax) {
            return Some(0);
        }
        // The smallest m with qh + 4m ≥ kmin. Keys change by less than half
        // a turn per segment, so |kmin|, |kmax| ≤ 2N + 4 and the quotient
        // is small; it is clamped anyway before the (saturating) conversion.
        let m0 = ((self.kmin - qh) * 0.25).clamp(-1.0e7, 1.0e7);
        let mut m = m0 as i32;
        if (m as f32) < m0 {
            m = m.saturating_add(1);
        }
        let mut c = 0usize;
        for slot in out.iter_mut() {
            let shift = 4.0 * m as f32;
            if ql + shift > self.kmax {
                return Some(c);
            }
            *slot = (ql + shift, qh + shift);
            c += 1;
            m = m.saturating_add(1);
        }
        // All slots used: a further copy would overflow.
        (ql + 4.0 * m as f32 > self.kmax).then_some(c)
    }

    /// The first segment `a` with `pm[a] ≥ t`: probes from the hint, then
    /// bisection (each step one unit of work).
    #[inline(always)]
    fn run_start(&self, t: f32, work: &mut Work) -> Result<usize, OutOfWork> {
        let n = self.segments;
        let pm = self.pm.get(..n).unwrap_or(&[]);
        let at = |j: usize| pm.get(j).copied().unwrap_or(f32::INFINITY);
        if n == 0 {
            return Ok(0);
        }
        let mut j = self.hint.min(n - 1);
        if at(j) >= t {
            for _ in 0..PROBES {
                if j == 0 || at(j - 1) < t {
                    return Ok(j);
                }
                j -= 1;
            }
            bisect(pm, 0, j, t, work)
        } else {
            for _ in 0..PROBES {
                j += 1;
                if j >= n || at(j) >= t {
                    return Ok(j);
                }
            }
            bisect(pm, j + 1, n, t, work)
        }
    }
}

/// Note vertex `v` (key `k`) as an outlier candidate when `k` lies
/// outside `[min(a, b), max(a, b)]` by more than [`OUTLYING`] times
/// `|a − b|`, keeping the [`MAX_OUTLIERS`] farthest.
#[inline(always)]
fn outlier_candidate(
    outliers: &mut heapless::Vec<(usize, f32), MAX_OUTLIERS>,
    v: usize,
    k: f32,
    a: f32,
    b: f32,
) {
    let (lo, hi) = (fmin(a, b), fmax(a, b));
    let dev = fmax(lo - k, k - hi);
    // (Unkeyed neighbours give NaN or infinities: no candidate.)
    if !(dev > OUTLYING * (hi - lo)) || !dev.is_finite() {
        return;
    }
    if outliers.push((v, dev)).is_err() {
        // Full: replace the nearest, if this one is farther.
        let mut least = 0usize;
        for (i, &(_, d)) in outliers.iter().enumerate() {
            if d < outliers.get(least).map_or(f32::INFINITY, |o| o.1) {
                least = i;
            }
        }
        if let Some(o) = outliers.get_mut(least) {
            if o.1 < dev {
                *o = (v, dev);
            }
        }
    }
}

/// A segment's interval from its two end keys (unwrapped) and their
/// margins; an unkeyed end makes it meet every key or none.
#[inline(always)]
fn segment_interval((k0, e0): (f32, f32), (k1, e1): (f32, f32), unkeyed: Unkeyed) -> (f32, f32) {
    if k0.is_finite() && k1.is_finite() {
        (fmin(k0 - e0, k1 - e1), fmax(k0 + e0, k1 + e1))
    } else {
        match unkeyed {
            Unkeyed::MeetAll => (f32::NEG_INFINITY, f32::INFINITY),
            Unkeyed::MeetNone => (f32::INFINITY, f32::NEG_INFINITY),
        }
    }
}

/// First index in `[lo, hi)` with `v[j] ≥ t` (non-decreasing `v`), or `hi`;
/// each step one unit of work.
fn bisect(
    v: &[f32],
    mut lo: usize,
    mut hi: usize,
    t: f32,
    work: &mut Work,
) -> Result<usize, OutOfWork> {
    hi = hi.min(v.len());
    while lo < hi {
        work.spend(1)?;
        #[cfg(feature = "_reference")]
        probe::add(&probe::BISECT, 1);
        let m = lo + (hi - lo) / 2;
        if v.get(m).copied().unwrap_or(f32::INFINITY) >= t {
            hi = m;
        } else {
            lo = m + 1;
        }
    }
    Ok(hi)
}
