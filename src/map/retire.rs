//! A retiring key frame's points into the map: the room made for them,
//! their entries, and the rest of a retirement cut at its share
//! ([`crate::fusion`], "The retirement over two steps").

use super::*;

/// What a retirement cut at its share leaves for the next step
/// ([`RoadMap::finish`]): the batch is the map's newest, its ring slots
/// were made room for, and the key frame's cells and the reconstruction of
/// its pixels stay as they were until then ([`crate::fusion`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Rest<const B: usize> {
    key: u32,
    /// Per boundary: the next cell the scan looks at, the points still to
    /// enter (room made), and the admitted points not accounted for yet
    /// (entered, unbounded or unfit); 0 for a boundary done.
    at: [u16; B],
    want: [u16; B],
    open: [u16; B],
    extent: Extent,
    ray: f32,
    far_limit: u16,
}

/// A retiring batch's bounds over its points: the smallest and largest
/// normalised `y` of a ray, and the smallest near code and largest far
/// code (the codes are monotone in the depth they stand for).
#[derive(Debug, Clone, Copy)]
pub(super) struct Extent {
    pub(super) y: (f32, f32),
    pub(super) codes: (u16, u16),
}

impl Extent {
    pub(super) const EMPTY: Self = Self {
        y: (f32::INFINITY, f32::NEG_INFINITY),
        codes: (u16::MAX, 0),
    };

    /// Take the `y` range of a run of entries, monotone in `y`, whose
    /// first and last entries' are `a` and `b`, in.
    #[inline(always)]
    fn take_y(&mut self, a: f32, b: f32) {
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        self.y = (fmin(self.y.0, lo), fmax(self.y.1, hi));
    }

    /// Take entry `e`'s codes in.
    #[inline(always)]
    pub(super) fn take_codes(&mut self, e: &Entry) {
        self.codes = (self.codes.0.min(e.near), self.codes.1.max(e.far));
    }

    /// Take the codes of the `n ≤ M` entries of `ring` from slot `start`
    /// on (modulo `M`, which is above 0: the map's is checked at compile
    /// time) in. Over the ring's two runs, the slots from `start % M` up
    /// to its end and those from its start, not by index modulo `M`:
    /// about 2 instructions an entry fewer since the twenty-eighth
    /// session (`tests::codes_over_the_rings_two_runs` holds it to the
    /// modulo form).
    #[inline(always)]
    pub(super) fn take_codes_of<const M: usize>(
        &mut self,
        ring: &[Entry; M],
        start: usize,
        n: usize,
    ) {
        let first = start % M;
        let head = n.min(M - first);
        for e in ring.get(first..first + head).unwrap_or(&[]) {
            self.take_codes(e);
        }
        for e in ring.get(..n - head).unwrap_or(&[]) {
            self.take_codes(e);
        }
    }

    /// Take one entry in, whatever its order (the tests' batches).
    #[cfg(test)]
    pub(super) fn take(&mut self, e: &Entry) {
        self.take_y(e.y, e.y);
        self.take_codes(e);
    }

    /// Into `b`, with its points' ray bound `ray` ([`ray_bound`]), the
    /// camera's tilt (sine and cosine) and the map's depth codes `scale`:
    /// the depths are the decoded ends' (exactly what the map's readers
    /// use), widened by `2⁻¹¹` of themselves, slack the bound's own
    /// rounding rests on ([`View`]); the reach, `ray` times the largest
    /// depth, by `2⁻¹⁰` (it bounds the radius's rest, [`View`], and the
    /// products round). (Until the twenty-first session the extent took
    /// the fused ends, within `2⁻¹²` of the decoded ones, and the widening
    /// covered that too.) A ray's forward rate, `w · (x,
    /// y, 1)` or `cos − sin · y`, is monotone in `y`, and so is its `f32`
    /// value (rounding is monotone): the rates at the two ends of the `y`
    /// range are the smallest and largest of the batch's, as each point's
    /// would be computed. (Nothing for an empty extent: a batch without
    /// points is never bounded.)
    pub(super) fn widen_into<const B: usize>(
        &self,
        (ray, scale): (f32, &DepthScale),
        (ts, tc): (f32, f32),
        b: &mut Batch<B>,
    ) {
        if !(self.y.0 <= self.y.1) {
            return;
        }
        let (d0, d1) = (tc - ts * self.y.0, tc - ts * self.y.1);
        b.dir = (fmin(d0, d1), fmax(d0, d1));
        b.ray = ray;
        // (An entry's far code is at most `UNBOUNDED − 1`: finite.)
        let (z0, z1) = (scale.depth(self.codes.0), scale.depth(self.codes.1));
        b.depth = (z0 * (1.0 - 1.0 / 2048.0), z1 * (1.0 + 1.0 / 2048.0));
        b.reach = z1 * ray * (1.0 + 1.0 / 1024.0);
    }
}

/// An upper bound `c` of `1 + ½((|x| + λ)² + (|y| + λ)²)` over every pixel
/// `cam`'s image (with its margin, [`crate::IMAGE_MARGIN_PX`]) can hold, in
/// normalised coordinates `(x, y)`, `λ = lat`: so of every key-frame ray's
/// `|(x, y, 1)|` (`√(1 + u) ≤ 1 + u/2`) and, times its far end, of a
/// point's `|P_K|` on the true ray ([`radius`]). A batch's points are that
/// camera's pixels (`Frame::push_boundary` refuses any other), so one
/// bound serves them all: no per-point maximum. Rounded up by `2⁻¹⁶`
/// (the normalisation's and the sum's rounding).
pub(super) fn ray_bound(cam: &Camera, lat: f32) -> f32 {
    let [dx, dy] = cam.reach_uv();
    let (x, y) = (dx / cam.fx() + lat, dy / cam.fy() + lat);
    (1.0 + 0.5 * (x * x + y * y)) * ROUND_UP
}

/// The largest far code an entry may have in a batch whose points may lie
/// up to `max_far` deep ([`MAX_REACH`] over its ray bound, [`ray_bound`]):
/// the largest code standing for a depth not above `max_far`
/// ([`DepthScale::down`]), so at most `UNBOUNDED − 1`; 0 (no entry) for a
/// NaN or one below the smallest far code's depth.
pub(super) fn far_limit(max_far: f32, scale: &DepthScale) -> u16 {
    scale.down(max_far)
}

/// [`RoadMap::enter`]'s next admitted point of a key-frame boundary
/// (its `cells` and reconstruction `points`, as iterators side by side,
/// both left after it; a key frame has a cell for each of its points, so
/// neither runs out first): `Some` of its entry ([`entry_of`]; `None`
/// inside: left out), or `None` when no admitted point is left.
#[inline(always)]
fn next_entry<'a>(
    (cells, points): (
        &mut core::slice::Iter<'a, Cell>,
        &mut core::slice::Iter<'a, PointResult>,
    ),
    min_pairs: u8,
    (cam, limit, scale): (&Camera, i32, &DepthScale),
) -> Option<Option<Entry>> {
    // (A tight scan: on most drives most points are not admitted.)
    loop {
        let (c, r) = (cells.next()?, points.next()?);
        if c.admitted(min_pairs) {
            return Some(entry_of(cam.normalise(r.pixel1()), c.ends(), limit, scale));
        }
    }
}

/// The map's far limit ([`far_limit`]) as [`entry_of`] compares it with
/// a far code before the code's clamp to 1: the limit itself, or for 0
/// (no entry at all) `i32::MIN`, below every code.
#[inline(always)]
pub(super) fn entry_limit(limit: u16) -> i32 {
    if limit == 0 {
        i32::MIN
    } else {
        i32::from(limit)
    }
}

/// A retiring point's entry: its key-frame ray `[x, y]` (normalised) and
/// fused ends, coded outwards ([`DepthScale`]). `None`: a far code past
/// `limit` ([`far_limit`]): a far end the codes cannot hold, or a decoded
/// one whose distance bound (times the batch's ray bound) is past
/// [`MAX_REACH`] ([`Retired::unbounded`]). The batch's extent takes the
/// entries' `y` range from the first and last of them and their codes in
/// a pass of their own after them ([`RoadMap::enter`], [`Extent::take_y`],
/// [`Extent::take_codes`]).
///
/// The near code is [`DepthScale::down_for_entry`]'s, which has no clamp
/// at the top: the same entry as with [`DepthScale::down`]'s for every
/// cell whose ends are in order, `z_near ≤ z_far`, as every admitted
/// cell's are (a pair's stick, a range's validated interval, their
/// intersections when not empty, a widened interval's `[H, max(far, U)]`
/// with `H` the lowest near end: [`crate::fusion`]'s cells). Where the two
/// codes differ, `z_near/s` is at or above `2 − 2⁻¹²`; then so is `z_far`,
/// whose far code is at least `UNBOUNDED` (codes are monotone in depth),
/// past every limit: no entry either way (`tests::entries_against_the_clamped_codes`).
/// Out of order, either code gives an entry of no meaning.
#[inline(always)]
pub(super) fn entry_of(
    [x, y]: [f32; 2],
    (z_near, z_far): (f32, f32),
    limit: i32,
    scale: &DepthScale,
) -> Option<Entry> {
    // (Below `2⁻¹⁵ s` a near end is code 0, depth 0, and a far end code 1,
    // about `2⁻¹⁵ s`: the decoded ends hold the fused ones whatever they
    // are.)
    // (The ends are never NaN: a cell's, `DepthScale::down_for_entry`.)
    let (near, far) = (
        scale.down_for_entry(z_near),
        scale.up_no_nan_unclamped(z_far),
    );
    // `|P_K|`'s bound on the true ray, the decoded far end times the
    // batch's ray bound: past `10³⁰` (a far ray of a wide-angle camera, or
    // such a scale) the map's `f32` arithmetic could overflow, so such a
    // point is left out too, as is one whose far end the codes cannot hold
    // (`UNBOUNDED` is above every limit).
    // (The far code is `up_no_nan`'s, `far.max(1)`: with `limit` from
    // [`entry_limit`], `far > limit` is `far.max(1) > ` the map's limit,
    // the clamp's constant out of the comparison.)
    if far > limit {
        return None;
    }
    // (At most `limit`, below `UNBOUNDED`: a `u16`.)
    let far = far.max(1) as u16;
    Some(Entry { x, y, near, far })
}

impl<const B: usize, const M: usize> RoadMap<B, M> {
    /// Free `need` slots on `boundary` by dropping its oldest points;
    /// returns the live points dropped for room ([`Self::taken`]).
    ///
    /// The slots leave the ring's used part: no reader looks at a slot
    /// outside a batch's range ([`Self::range`]), and [`Self::enter`]
    /// writes every slot it gives a batch, so the freed entries are left
    /// as they are.
    fn free_slots(&mut self, boundary: usize, need: usize) -> u32 {
        let mut dropped = 0u32;
        let mut need = need;
        // Slots are taken from the oldest batches that hold any on this
        // boundary (at most MAP_BATCHES of them).
        for i in 0..usize::from(self.count) {
            if need == 0 {
                break;
            }
            let slot = self.slot(i);
            let Some(b) = self.batches.get(slot).copied() else {
                break;
            };
            let (start, len) = self.range(i, boundary);
            let take = len.min(need);
            let live = self.taken(&b, boundary, (start, len, take));
            if let (Some(b), Some(t), Some(u), Some(c)) = (
                self.batches.get_mut(slot),
                self.tail.get_mut(boundary),
                self.used.get_mut(boundary),
                self.sweep.get_mut(boundary),
            ) {
                if let (Some(l), Some(lv)) = (b.len.get_mut(boundary), b.live.get_mut(boundary)) {
                    *l = l.saturating_sub(take as u16);
                    *lv = lv.saturating_sub(live);
                }
                // This batch's slots start at the ring's tail: every older
                // batch has none left on this boundary.
                *t = ((usize::from(*t) + take) % M) as u16;
                *u = u.saturating_sub(take as u16);
                *c = c.saturating_sub(take as u16);
            }
            dropped += u32::from(live);
            need -= take;
        }
        dropped
    }

    /// Of the first `take` of batch `b`'s `len` slots on `boundary` (from
    /// ring slot `start`), the live ones: all of the batch's at once when
    /// the whole of it goes (its live count), or when none of its slots
    /// was dropped (every taken one live); otherwise one look a taken
    /// slot. A live point is one the sweep has not reclaimed
    /// ([`Self::carry`]): one behind the camera that the sweep has not
    /// reached yet is dropped for room and counted so, not tested (module
    /// docs, "What leaves the map").
    pub(super) fn taken(
        &self,
        b: &Batch<B>,
        boundary: usize,
        (start, len, take): (usize, usize, usize),
    ) -> u16 {
        let batch_live = b.live.get(boundary).copied().unwrap_or(0);
        if batch_live == 0 {
            return 0;
        }
        if take == len {
            return batch_live;
        }
        if usize::from(batch_live) == len {
            return take as u16;
        }
        let Some(ring) = self.entries.get(boundary) else {
            return 0;
        };
        let mut live = 0u16;
        for j in start..start + take {
            if ring.get(j % M).is_some_and(Entry::live) {
                live += 1;
            }
        }
        live
    }

    /// Move a retiring key frame's fused points into the map: those with at
    /// least `min_pairs` agreeing pairs and a bounded interval, as one
    /// batch posed by `chain` (the key frame's motion to the current
    /// frame). `s` is a reconstruction of the key frame (its pixels), `e1`
    /// the key frame's localisation error (the radius, module docs). The
    /// oldest points make room. An admitted point whose far end the depth
    /// codes cannot hold, or whose distance bound (its far end times the
    /// camera's ray bound, [`ray_bound`]) passes [`MAX_REACH`], is
    /// left out ([`Retired::unbounded`]; the room made for it goes to the
    /// next admitted point, and what the scan does not reach is
    /// [`Retired::unfit`]).
    ///
    /// Admitted points up to `permille` ‰ of the key frame's points
    /// (rounded up), less half the `conflicts` of the pass this step
    /// fused (rounded up; not below 0, and not at 1000 ‰), are looked at
    /// now, entered or left out, boundary by boundary; room is made for
    /// all, and the rest enter with
    /// [`Self::finish`], which must come before anything else changes the
    /// map, `key` or `s` ([`Retired::pending`] counts them). Until then
    /// the batch holds the points entered, bounded over them. 1000 ‰: all
    /// now.
    ///
    /// Work: two passes over the key frame's points (`B·N`), plus the
    /// points dropped for room; the entries, the dearest part, at most
    /// the share of the key frame's points.
    pub(crate) fn retire<const N: usize>(
        &mut self,
        key: &KeyFrame<N, B>,
        s: &Structure<N, B>,
        chain: &Chain,
        (e1, permille, conflicts): (f32, u16, u32),
    ) -> Retired {
        // (An unfinished retirement is finished by the caller first; one
        // left is forgotten with its points, never written over a batch.)
        self.rest = None;
        let mut out = Retired {
            key: key.id(),
            ..Retired::default()
        };
        // 1. How many, per boundary (the key frame keeps the counts).
        let mut want = [0usize; B];
        for (k, w) in want.iter_mut().enumerate() {
            let (admitted, inconsistent) = key.admission(k);
            *w = usize::from(admitted);
            out.inconsistent += u32::from(inconsistent);
            out.unverified +=
                (key.len(k) - usize::from(admitted) - usize::from(inconsistent)) as u32;
        }
        if want.iter().all(|&w| w == 0) {
            return out;
        }
        // 2. Room: a batch slot, then ring slots, oldest first.
        let admitted = want;
        // The share is of the key frame's points, admitted or not: with the
        // pass over its last pair, what a step can afford a point. (At most
        // `B·N` < 2³² of them, times at most 1000: no overflow in `u64`.)
        let total: usize = (0..B).map(|k| key.len(k)).sum();
        let share = (total as u64 * u64::from(permille.min(1000))).div_ceil(1000) as usize;
        // Less half the pass's conflicts: each cost the pass about 40
        // instructions more than an agreeing point, about half what an
        // entry costs, and none of those points is admitted, so the next
        // step enters no more than it would without the cut (`docs/FUSION.md`,
        // "The fusion's own work"; the fusion's module docs, "The
        // retirement over two steps"). 1000 ‰ stays whole.
        let share = if permille >= 1000 {
            share
        } else {
            share.saturating_sub(conflicts.div_ceil(2) as usize)
        };
        self.make_room(&mut want, &mut out);
        // 3. The batch: its pose, each boundary's points (up to the share),
        // the bounds over them.
        let (a, b, rho, phi) = chain.pose();
        let cam = s.camera1();
        let lat = e1 / fmin(cam.fx(), cam.fy()) * ROUND_UP;
        let mut batch = Batch::<B> {
            a,
            b,
            rho,
            phi,
            // (A camera's focal lengths are positive and finite, `e₁` at
            // most 100: finite; the guard keeps a NaN out regardless.)
            lat: if lat.is_finite() { lat } else { 0.0 },
            key: key.id(),
            ..Batch::EMPTY
        };
        let ray = ray_bound(cam, batch.lat);
        let mut rest = Rest {
            key: key.id(),
            at: [0; B],
            want: [0; B],
            open: [0; B],
            extent: Extent::EMPTY,
            ray,
            // (A NaN bound leaves every point out, an infinite one only
            // those the codes cannot hold.)
            far_limit: far_limit(MAX_REACH / ray, &self.scale),
        };
        let mut left = share;
        for (k, &w) in want.iter().enumerate() {
            let mut at = 0;
            let (n, unbounded) = self.enter(
                k,
                (w, left),
                &mut at,
                (key, s, rest.far_limit),
                &mut rest.extent,
            );
            let looked = n + unbounded as usize;
            left = left.saturating_sub(looked);
            out.unbounded += unbounded;
            let a = admitted.get(k).copied().unwrap_or(0);
            let open = a.saturating_sub(looked);
            if n < w && left == 0 {
                // Cut at the share: the rest next step.
                if let (Some(r_at), Some(r_want), Some(r_open)) = (
                    rest.at.get_mut(k),
                    rest.want.get_mut(k),
                    rest.open.get_mut(k),
                ) {
                    *r_at = at as u16;
                    *r_want = (w - n) as u16;
                    *r_open = open as u16;
                }
                out.pending += open as u32;
            } else {
                // The admitted points the scan did not reach: an unbounded
                // point it passed over left room for one more (each point
                // is counted once, under one reason).
                out.unfit += open as u32;
            }
            self.grow(&mut batch, k, n);
            out.entered += n as u32;
        }
        rest.extent
            .widen_into((ray, &self.scale), self.tilt, &mut batch);
        let slot = self.slot(usize::from(self.count));
        if let Some(b) = self.batches.get_mut(slot) {
            *b = batch;
            self.count += 1;
        }
        // (A boundary cut where its scan had nothing left to look at has
        // nothing pending: no rest, and no `finished` to report, as the
        // count says. A review found one reported.)
        if out.pending > 0 {
            self.rest = Some(rest);
        }
        out
    }

    /// The rest of a retirement [`Self::retire`] cut at its share: its
    /// points entered into its batch (the map's newest), which is bounded
    /// over all of them again. `key` and `s` must be the ones `retire` had
    /// (unchanged since). `None` without one. The counts are the rest's
    /// (`entered`, `unbounded`, `unfit`; `key` the key frame's id, the
    /// others 0).
    ///
    /// Work: the points entered (at most `B·N` less the share), and a scan
    /// over the cells `retire` did not look at.
    pub(crate) fn finish<const N: usize>(
        &mut self,
        key: &KeyFrame<N, B>,
        s: &Structure<N, B>,
    ) -> Option<Retired> {
        let mut rest = self.rest.take()?;
        let mut out = Retired {
            key: rest.key,
            ..Retired::default()
        };
        let newest = usize::from(self.count).checked_sub(1)?;
        let slot = self.slot(newest);
        let mut batch = self.batches.get(slot).copied()?;
        if batch.key != rest.key || key.id() != rest.key {
            return None;
        }
        for k in 0..B {
            let (Some(&at), Some(&w), Some(&open)) =
                (rest.at.get(k), rest.want.get(k), rest.open.get(k))
            else {
                continue;
            };
            let mut at = usize::from(at);
            let (n, unbounded) = self.enter(
                k,
                (usize::from(w), usize::MAX),
                &mut at,
                (key, s, rest.far_limit),
                &mut rest.extent,
            );
            out.unbounded += unbounded;
            out.unfit += u32::from(open).saturating_sub(n as u32 + unbounded);
            self.grow(&mut batch, k, n);
            out.entered += n as u32;
        }
        rest.extent
            .widen_into((rest.ray, &self.scale), self.tilt, &mut batch);
        if let Some(b) = self.batches.get_mut(slot) {
            *b = batch;
        }
        Some(out)
    }

    /// `n` more points of `batch` on boundary `k`, in the ring slots after
    /// the used ones.
    fn grow(&mut self, batch: &mut Batch<B>, k: usize, n: usize) {
        let n16 = n as u16;
        if let (Some(l), Some(lv), Some(u)) = (
            batch.len.get_mut(k),
            batch.live.get_mut(k),
            self.used.get_mut(k),
        ) {
            *l = l.saturating_add(n16);
            *lv = lv.saturating_add(n16);
            *u = u.saturating_add(n16);
        }
    }

    /// [`Self::retire`]'s room: a batch slot (the oldest batch goes when
    /// all are taken), then on each boundary the ring slots for its
    /// `want` points (cut to at most `M`: the caller counts what its scan
    /// does not reach unfit), oldest first.
    pub(super) fn make_room(&mut self, want: &mut [usize; B], out: &mut Retired) {
        if usize::from(self.count) >= MAP_BATCHES {
            if let Some(b) = self.batches.get(usize::from(self.first)).copied() {
                out.dropped += b.live_total();
                self.pop_oldest(&b.len);
            }
        }
        for (k, w) in want.iter_mut().enumerate() {
            // (The points beyond `M` are counted unfit by the caller.)
            *w = (*w).min(M);
            let used = self.used.get(k).map_or(0, |&u| usize::from(u));
            let free = M - used.min(M);
            if free < *w {
                out.dropped += self.free_slots(k, *w - free);
            }
        }
        self.pop_dead();
        self.drops.capacity = self.drops.capacity.wrapping_add(out.dropped);
    }

    /// [`Self::retire`]'s entries on boundary `k`: the next `w` admitted
    /// points of the key frame from cell `*at` on (left after the last one
    /// looked at), no more than `look` looked at (entered or left out),
    /// written into the ring after its used slots (`w ≤ M` and as many
    /// slots free: [`Self::make_room`]; the test build checks `w ≤ M`), their rays' forward
    /// rates and their depths taken into `extent`. Returns how many
    /// entered, and how many were left out for a far end the codes cannot
    /// hold or past `limit` (a distance bound past [`MAX_REACH`],
    /// [`entry_of`]).
    fn enter<const N: usize>(
        &mut self,
        k: usize,
        (w, look): (usize, usize),
        at_out: &mut usize,
        (key, s, limit): (&KeyFrame<N, B>, &Structure<N, B>, u16),
        extent: &mut Extent,
    ) -> (usize, u32) {
        let min_pairs = key.min_pairs();
        // (Locals, the loop's registers: through the references its stores
        // might reach, the camera and the extent were loaded and stored
        // again for every point.)
        let (cam, scale) = (*s.camera1(), self.scale);
        let start = self.tail.get(k).map_or(0, |&t| usize::from(t))
            + self.used.get(k).map_or(0, |&u| usize::from(u));
        let (Some(ring), Some(results)) = (self.entries.get_mut(k), s.boundaries().get(k)) else {
            return (0, 0);
        };
        let mut unbounded = 0u32;
        // The key-frame boundary's cells and reconstruction points from
        // `*at_out` on, as two iterators side by side; `*at_out` is left
        // after the last one looked at. (Until the twenty-eighth session an
        // index into both slices: its bounds checks and the registers they
        // took measured about 3 instructions an entry more on the bench's
        // `partners_1` drive.)
        let from = *at_out;
        // (The callers' `w ≤ M`, and a cell for each point: the test build
        // checks both.)
        #[cfg(test)]
        assert!(w <= M && key.cells(k).len() == results.points().len());
        let mut cells = key.cells(k).get(from..).unwrap_or(&[]).iter();
        let mut points = results.points().get(from..).unwrap_or(&[]).iter();
        let total = cells.len();
        let limit = entry_limit(limit);
        let mut next = || next_entry((&mut cells, &mut points), min_pairs, (&cam, limit, &scale));
        // The points left out count against `look` too: at most `look`
        // looked at, `n + unbounded`. (A review found the share passed by
        // as many points as were left out before the entries, when the
        // loop went on past them.) Between two points left out the bound
        // is fixed, so the inner loop tests `pos` alone; a point left out
        // lowers it. (Until the twenty-seventh session the loop after the
        // first point left out tested the three bounds at every entry,
        // about 4 instructions an entry dearer: on a drive whose far
        // points come first and are left out, every entry took it, the
        // bench's `partners_1` drive 100 instructions a key-frame point
        // then, 96 with this loop. A bound lowered inside one loop had
        // measured 3 instructions an entry dearer on the bench's drives.)
        // (`pos`, the ring position of the next entry, `start + n`: the
        // loop's registers hold one count, not two, about 4 instructions
        // an entry fewer since the twenty-eighth session.)
        let mut pos = start;
        'entries: loop {
            let stop = start.saturating_add(w.min(look.saturating_sub(unbounded as usize)));
            while pos < stop {
                let Some(next) = next() else {
                    break 'entries;
                };
                let Some(e) = next else {
                    unbounded += 1;
                    continue 'entries;
                };
                if let Some(slot) = ring.get_mut(pos % M) {
                    *slot = e;
                }
                pos += 1;
            }
            break;
        }
        // (None of the three overflows: `pos` only grew from `start`, the iterator
        // only shrank from `total`, and `from` plus what it gave is at
        // most the boundary's length, or `from` itself past it.)
        let n = pos - start;
        *at_out = from + (total - cells.len());
        // The entries' extent, in a pass of their own: in the loop above
        // it cost the loop's registers, about 3 instructions an entry
        // more. (They are `start .. start + n`, in order.) Their `y` is
        // monotone along them: a boundary's rows are strictly monotone
        // ([`crate::boundary`]), and `y = (v − c_y)/f_y` with `f_y > 0`
        // rounds monotonically, so the first and the last entry hold its
        // range; only the codes are taken entry by entry. (Until the
        // twenty-seventh session `y` was too, about 11 instructions an
        // entry more.)
        let mut ext = *extent;
        #[cfg(test)]
        let codes_before = ext.codes;
        let last = (start + n).checked_sub(1).filter(|_| n > 0);
        if let (Some(a), Some(b)) = (ring.get(start % M), last.and_then(|l| ring.get(l % M))) {
            ext.take_y(a.y, b.y);
            // (The tests check that this call's own range, from its first
            // and last entry, holds every one of its entries' `y`, and so
            // does the extent.)
            #[cfg(test)]
            {
                let (lo, hi) = (fmin(a.y, b.y), fmax(a.y, b.y));
                for e in (start..start + n).filter_map(|j| ring.get(j % M)) {
                    assert!(lo <= e.y && e.y <= hi, "{lo} {hi} {}", e.y);
                    assert!(ext.y.0 <= e.y && e.y <= ext.y.1, "{:?} {}", ext.y, e.y);
                }
            }
        }
        ext.take_codes_of(ring, start, n);
        // (The tests check the codes taken against those of this call's
        // entries by index modulo `M`, exactly, and count the calls whose
        // entries run past the ring's end, in the test's own thread.)
        #[cfg(test)]
        {
            let mut oracle = Extent {
                codes: codes_before,
                ..Extent::EMPTY
            };
            for e in (start..start + n).filter_map(|j| ring.get(j % M)) {
                oracle.take_codes(e);
            }
            assert_eq!(ext.codes, oracle.codes);
            if start % M + n > M {
                tests::WRAPPED.with(|c| c.set(c.get() + 1));
            }
        }
        *extent = ext;
        (n, unbounded)
    }
}
