//! The walks' view of an index ([`Lean`], [`Blocks`]): the copies of a
//! periodic query, the block tree's skips, and the run's start (probes,
//! then bisection), shared by the wedge path and the index's own visits.

use super::*;
use crate::camera::Pixel;
use crate::matching::Radial;
use build::key_levels;

/// An index's view for a caller that walks runs itself ([`Index::lean`];
/// its block tree as `B`, [`Blocks`] or [`LazyBlocks`]).
#[derive(Clone, Copy)]
pub(crate) struct Lean<'a, B = Blocks<'a>> {
    pub(crate) segs: &'a [Seg],
    pub(crate) orient: f32,
    pub(crate) aside: &'a [Aside],
    pub(crate) blocks: B,
    /// The keys' period (0: none) and range `[kmin, kmax]` ([`copies_in`]).
    pub(super) period: f32,
    pub(super) range: (f32, f32),
}

impl<B> Lean<'_, B> {
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
    pub(super) tree: &'a [f32],
    pub(super) levels: usize,
    pub(super) segments: usize,
}

/// The skips of a block tree, as a walk takes them ([`Blocks`], or
/// [`LazyBlocks`], which builds a tree left to build on its first read).
pub(crate) trait BlockSkip: Copy {
    /// At segment `j` of a loose index's run: how many segments from `j`
    /// on a block skip passes over: the largest block aligned at `j` whose
    /// key range `meets` does not accept (0: look at segment `j` itself).
    /// At most [`LEVELS`] steps.
    fn skip_at(&self, j: usize, meets: impl Fn(f32, f32) -> bool) -> usize;
}

impl Blocks<'_> {
    /// No tree (a walk without skips).
    pub(crate) const NONE: Blocks<'static> = Blocks {
        tree: &[],
        levels: 0,
        segments: 0,
    };

    /// Whether there is a tree (a loose index).
    #[cfg(test)]
    pub(crate) fn any(&self) -> bool {
        self.levels > 0
    }
}

impl BlockSkip for Blocks<'_> {
    /// (A tree left to build has no levels here, and skips nothing: only
    /// the lean walks search such an index,
    /// [`Builder::finish_deferring_tree`].)
    #[inline(always)]
    fn skip_at(&self, j: usize, meets: impl Fn(f32, f32) -> bool) -> usize {
        // Only a position aligned to a block starts one.
        if j & (FAN - 1) != 0 {
            return 0;
        }
        // (The loop of [`skip_in`], written out here: through it the bench
        // firmware's pseudo-angle walks measured dearer, `fwd_spiral` +0.8 %
        // at N = 512, and through a trait for the stored value +0.9 %. Keep
        // the two the same.)
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

/// The block tree of a loose index as the lean wedge walks read it
/// ([`Index::lean_lazy`]): its values as cells, so that a tree the build
/// left ([`Builder::finish_deferring_tree`]) is built on the first read,
/// at a walk's first aligned segment that misses its keys. The same tree
/// as the build's (the same intervals), so the same skips, units and
/// results; along most boundaries whose keys fold somewhere no walk reads
/// it, and it is never built.
#[derive(Clone, Copy)]
pub(crate) struct LazyBlocks<'a> {
    tree: &'a [core::cell::Cell<f32>],
    levels: &'a core::cell::Cell<usize>,
    pub(super) tree_end: &'a core::cell::Cell<usize>,
    segs: &'a [Seg],
}

impl LazyBlocks<'_> {
    /// Whether there is a tree, built or left to build (a loose index).
    #[inline(always)]
    pub(crate) fn any(&self) -> bool {
        self.levels.get() > 0 || self.tree_end.get() == PENDING
    }

    /// The tree built now (it was left to build): its levels.
    #[cold]
    #[inline(never)]
    fn build(&self) -> usize {
        // (Without a clock: the build defers only without one.)
        let (levels, end) = key_levels(self.segs, self.tree, &mut None).unwrap_or((0, 0));
        self.levels.set(levels);
        self.tree_end.set(end);
        levels
    }
}

impl BlockSkip for LazyBlocks<'_> {
    #[inline(always)]
    fn skip_at(&self, j: usize, meets: impl Fn(f32, f32) -> bool) -> usize {
        if j & (FAN - 1) != 0 {
            return 0;
        }
        let mut levels = self.levels.get();
        if self.tree_end.get() == PENDING {
            levels = self.build();
        }
        let tree = self.tree;
        let segments = self.segs.len();
        skip_in(
            |i| tree.get(i).map(core::cell::Cell::get),
            (levels, segments),
            j,
            meets,
        )
    }
}

/// [`BlockSkip::skip_at`] at an aligned `j`, in a tree of `levels` levels
/// over `segments` segments whose values `read` gives.
#[inline(always)]
fn skip_in(
    read: impl Fn(usize) -> Option<f32>,
    (levels, segments): (usize, usize),
    j: usize,
    meets: impl Fn(f32, f32) -> bool,
) -> usize {
    let (mut base, mut n, mut skip) = (0usize, segments, 0usize);
    let mut shift = 0u32;
    for _ in 0..levels.min(LEVELS) {
        shift += FAN_BITS;
        n = n.div_ceil(FAN);
        // (`shift` ≤ 3 · LEVELS = 12.)
        let size = 1usize << shift;
        if j & (size - 1) != 0 {
            break;
        }
        let b = j >> shift;
        let (lo, hi) = (
            read(base + 2 * b).unwrap_or(f32::NEG_INFINITY),
            read(base + 2 * b + 1).unwrap_or(f32::INFINITY),
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

impl<const N: usize> Index<N> {
    /// The block tree as [`Blocks`] (no levels when none is built).
    #[inline(always)]
    pub(super) fn blocks(&self) -> Blocks<'_> {
        Blocks {
            tree: &self.tree,
            levels: self.levels,
            segments: self.segments,
        }
    }

    /// [`Self::lean`] with the block tree as [`LazyBlocks`]: built on a
    /// walk's first read if the build left it.
    #[inline(always)]
    pub(crate) fn lean_lazy(&mut self) -> Lean<'_, LazyBlocks<'_>> {
        let segs = self.seg.get(..self.segments.min(N)).unwrap_or(&[]);
        let tree = core::cell::Cell::from_mut(self.tree.as_mut_slice()).as_slice_of_cells();
        Lean {
            segs,
            orient: self.orient,
            aside: self.aside.as_slice(),
            blocks: LazyBlocks {
                tree,
                levels: core::cell::Cell::from_mut(&mut self.levels),
                tree_end: core::cell::Cell::from_mut(&mut self.tree_end),
                segs,
            },
            period: self.period,
            range: (self.kmin, self.kmax),
        }
    }

    /// [`Blocks::skip_at`] on this index's tree.
    #[inline(always)]
    pub(super) fn skip_at(&self, j: usize, meets: impl Fn(f32, f32) -> bool) -> usize {
        self.blocks().skip_at(j, meets)
    }

    /// The radial test of a band query, when it has one and the radial
    /// levels are built ([`Self::build_radial`], on the first such query).
    #[inline(always)]
    pub(super) fn radial_for(&mut self, quick: Option<(Radial, &[Pixel])>) -> Option<Radial> {
        let (rad, b) = quick?;
        if self.radial_levels == UNBUILT {
            self.build_radial(b, &mut None);
        }
        (self.radial_levels > 0).then_some(rad)
    }

    /// The radial levels built now if they are not yet
    /// ([`Self::build_radial`]; the same levels the first band query with
    /// a radial test would build). Under a caller's deadline the band path
    /// builds them before its first point, so that the build and that
    /// point's search are two stretches between the clock's questions,
    /// and the build asks `tick` too (if its clock stops the build, the
    /// index has no radial levels).
    pub(crate) fn build_radial_once(&mut self, b: &[Pixel], tick: &mut Tick<'_>) {
        if self.radial_levels == UNBUILT {
            self.build_radial(b, tick);
        }
    }

    /// At segment `j` of a run: how many segments from `j` on the radial
    /// levels pass over, the largest block aligned at `j` that `rad`
    /// rejects as a whole ([`Radial::rejects_block`]; 0: look at segment
    /// `j` itself). At most [`LEVELS`] steps.
    #[inline(always)]
    pub(super) fn radial_skip_at(&self, j: usize, rad: &Radial) -> usize {
        if j & (FAN - 1) != 0 {
            return 0;
        }
        self.radial_skip_aligned(j, rad)
    }

    /// [`Self::radial_skip_at`] at an aligned `j` (out of line: one copy
    /// for every visit that skips, 1 in 8 of its steps). (Each block's four
    /// values as one slice look, and the test's `c₀²` made once: 804 → 698
    /// instructions a point on the `back_spiral` profile window.)
    #[inline(never)]
    fn radial_skip_aligned(&self, j: usize, rad: &Radial) -> usize {
        let (mut base, mut n, mut skip) = (self.tree_end, self.segments, 0usize);
        let mut shift = 0u32;
        let c0sq = rad.block_c0sq();
        for _ in 0..usize::from(self.radial_levels).min(LEVELS) {
            shift += FAN_BITS;
            n = n.div_ceil(FAN);
            // (`shift` ≤ 3 · LEVELS = 12.)
            let size = 1usize << shift;
            if j & (size - 1) != 0 {
                break;
            }
            let i = base + 4 * (j >> shift);
            let Some(&[lo, hi, v0, v1]) = self.tree.get(i..i + 4) else {
                break;
            };
            // A larger block holds this one: stop at the first kept.
            if !rad.rejects_block((lo, hi), (v0, v1), c0sq) {
                break;
            }
            skip = size;
            base += 4 * n;
        }
        skip
    }

    /// The copies `[ql + 4m, qh + 4m]` of an oriented query that can meet
    /// the keys' range `[kmin, kmax]` (for non-periodic keys the query
    /// itself, if it can), into `out`; `None` when there are more than
    /// [`MAX_COPIES`].
    pub(super) fn copies(
        &self,
        ql: f32,
        qh: f32,
        out: &mut [(f32, f32); MAX_COPIES],
    ) -> Option<usize> {
        copies_in((self.period, (self.kmin, self.kmax)), ql, qh, out)
    }

    /// [`Self::run_start`] out of line (the general visit: its probes
    /// inlined there cost their set-up at every query).
    #[inline(never)]
    pub(super) fn run_start_out_of_line(
        &self,
        t: f32,
        work: &mut Work,
    ) -> Result<usize, OutOfWork> {
        self.run_start(t, work)
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
    // The copies are tested as they round: the copy one turn lower may
    // still reach `kmin` (`qh + 4(m − 1)` rounds up to it on its binade's
    // coarser grid though the exact `kmin − qh` lies above `4(m − 1)`),
    // and then it counts. (The mirror case, the copy at `m` rounding just
    // below `kmin` where the quotient is whole, is left in: a copy too
    // many, harmless but where it makes more than `MAX_COPIES`, a fold
    // assumed; its test here measured the representative window 958.5
    // cycles a point, `docs/PERFORMANCE.md`.) (`m` is within 10⁷ + 1 of 0.)
    if qh + 4.0 * m.wrapping_sub(1) as f32 >= kmin {
        m = m.wrapping_sub(1);
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
