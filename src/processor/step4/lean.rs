//! Step 4's wedge path for half-plane keys ([`match_wedge_lean`]): each
//! point's run walked through the index's lean view, the aside entries
//! merged in or tested first, a loose index's block tree skipped by.

use super::*;

/// The wedge path through an index's lean view ([`Index::lean`]): every
/// point's run walked in locals ([`LeanWalk::point`]); the aside entries,
/// if any, merged in by index, and on a loose index the block tree's skips
/// taken too ([`LeanWalk::aside_walk`]); each walk's points in one loop
/// ([`LeanWalk::points`]).
#[inline(never)]
pub(super) fn match_wedge_lean<const N: usize, D: Deadline>(
    pair: &Pair,
    keying: &Keying,
    (foe, side): ([f32; 2], f32),
    (slots, b2): (&mut [PointResult], &[Pixel]),
    index: &mut Index<N>,
    (work, guard): (&mut Work, &mut Guard<'_, D>),
) {
    let mut hint = index.hint();
    // (A loose index's tree built on a walk's first read if the build
    // left it, [`LazyBlocks`].)
    let Lean {
        segs,
        orient,
        aside,
        blocks,
        ..
    } = index.lean_lazy();
    let walk = LeanWalk {
        pair,
        segs,
        aside,
        blocks,
        b2,
        foe,
        side,
        e2: pair.e2(),
        e2_csc: pair.e2_csc(),
        key_scale: keying.key_scale,
        orient,
        cot_twice: pair.config.cot_twice,
        segments: b2.len().saturating_sub(1),
    };
    if blocks.any() {
        // A loose index (the keys fold somewhere): the tree's skips too.
        hint = walk.points_for::<2, D>(slots, hint, (work, guard));
    } else if aside.is_empty() {
        hint = walk.points_for::<0, D>(slots, hint, (work, guard));
    } else {
        hint = walk.points_for::<1, D>(slots, hint, (work, guard));
    }
    index.set_hint(hint);
}

/// What every point of a boundary shares on the lean wedge path.
struct LeanWalk<'a> {
    pair: &'a Pair<'a>,
    segs: &'a [crate::search::Seg],
    aside: &'a [crate::search::Aside],
    blocks: LazyBlocks<'a>,
    b2: &'a [Pixel],
    foe: [f32; 2],
    side: f32,
    e2: f32,
    e2_csc: f32,
    key_scale: f32,
    orient: f32,
    cot_twice: f32,
    segments: usize,
}

impl LeanWalk<'_> {
    /// [`Self::points`], or under a caller's deadline
    /// [`Self::points_within`].
    #[inline(always)]
    fn points_for<const WALK: u8, D: Deadline>(
        &self,
        slots: &mut [PointResult],
        hint: usize,
        (work, guard): (&mut Work, &mut Guard<'_, D>),
    ) -> usize {
        if crate::deadline::never::<D>() {
            self.points::<WALK, D>(slots, hint, (work, guard))
        } else {
            self.points_within::<WALK, D>(slots, hint, (work, guard))
        }
    }

    /// Step 4 for every point of `slots` left by steps 1–2, from the run
    /// start `hint`; returns the last run's start. `WALK` 0: the plain
    /// walk ([`Self::point`]); 1: with the index's aside entries merged
    /// into the run ([`Self::aside_walk`]); 2: through a loose index, the
    /// run's blocks that miss the wedge's keys skipped by the tree
    /// ([`Self::aside_walk`], [`wedge_run_aside`]). (The aside and loose
    /// walks in this loop, not out of line per point: `spur_f2` 977.0 →
    /// 966.0, `demo_9` 961.9 → 932.3, `demo_13` 1 005.5 → 977.4
    /// instructions a point.) (Out of line,
    /// the loop inside with [`Self::point`] inlined: the registers a point
    /// uses are saved once a boundary, not once a point. With the point's
    /// `p₁` and `1/q_z` read only after its walk this measured 711.5 →
    /// 681.5 instructions and 1 067.6 → 986.7 estimated cycles a point on
    /// the representative window; either alone was dearer on some window:
    /// the loop alone `demo_15` +6.1 instructions a point, the late reads
    /// alone every plain window.)
    #[inline(never)]
    fn points<const WALK: u8, D: Deadline>(
        &self,
        slots: &mut [PointResult],
        mut hint: usize,
        (work, guard): (&mut Work, &mut Guard<'_, D>),
    ) -> usize {
        for r in slots.iter_mut() {
            if r.status == Status::NoIntersection {
                if !guard.proceed(work) {
                    *r = PointResult::flagged(r.pixel1, Status::OverBudget);
                    continue;
                }
                let (h, refine) = match WALK {
                    0 => self.point::<true>(r, hint, work),
                    1 => self.aside_walk::<false, false>(r, hint, work),
                    _ => self.aside_walk::<true, true>(r, hint, work),
                };
                hint = h;
                if refine != 0 {
                    self.refine(r, refine, work);
                }
            }
        }
        hint
    }

    /// [`Self::points`] under a caller's deadline, whose question before
    /// each point ([`Guard::proceed`]) is a call: each point's walk out of
    /// line ([`Self::walk_out`]), its registers its own. (With the walks
    /// inlined into the loop, as without a deadline, the bench's demo drive
    /// within 212 000 measured frames 1–5 +2.4 to +4.4 %, two of them then
    /// cut.)
    #[inline(always)]
    fn points_within<const WALK: u8, D: Deadline>(
        &self,
        slots: &mut [PointResult],
        mut hint: usize,
        (work, guard): (&mut Work, &mut Guard<'_, D>),
    ) -> usize {
        let mut rest = slots.iter_mut();
        while let Some(r) = rest.next() {
            if r.status == Status::NoIntersection {
                if !guard.proceed(work) {
                    // The time is up: this point and the rest flagged in a
                    // loop of their own.
                    r.flag(Status::OverBudget);
                    super::flag_pending(rest.into_slice());
                    break;
                }
                let (h, refine) = self.walk_out::<WALK>(r, hint, work);
                hint = h;
                if refine != 0 {
                    // The refinement a stretch of its own: the clock asked
                    // between the walk and it, the credit left as the walk
                    // left it (so the same results while the clock says
                    // no). Until a tenth review it followed the walk
                    // unasked: a capped walk of 150 units, then its 48
                    // piece segments twice over, 18 886 instructions
                    // between two questions. (Asking through `proceed`,
                    // which caps the credit anew, let the refinement pay
                    // more lines: 20 640.)
                    if guard.check() {
                        r.flag(Status::OverBudget);
                        super::flag_pending(rest.into_slice());
                        break;
                    }
                    self.refine(r, refine, work);
                }
            }
        }
        hint
    }

    /// One point's walk `WALK` ([`Self::points`]) out of line, `p₁` and
    /// `1/q_z` read before it ([`Self::points_within`]).
    #[inline(never)]
    fn walk_out<const WALK: u8>(
        &self,
        r: &mut PointResult,
        hint: usize,
        work: &mut Work,
    ) -> (usize, usize) {
        match WALK {
            0 => self.point::<false>(r, hint, work),
            1 => self.aside_walk::<false, false>(r, hint, work),
            _ => self.aside_walk::<true, false>(r, hint, work),
        }
    }

    /// Step 4 for the point left by steps 1–2 in `r`: its wedge, the walk
    /// over its run (from the last run's start `hint`), the result in `r`;
    /// returns where the run started. (Inlined into [`Self::points`], with
    /// `LATE`: `p₁` and `1/q_z` read after the walk; into
    /// [`Self::walk_out`] without, read before it.)
    #[inline(always)]
    fn point<const LATE: bool>(
        &self,
        r: &mut PointResult,
        hint: usize,
        work: &mut Work,
    ) -> (usize, usize) {
        let (p, r1, key) = (r.pixel2.arr(), r.z_near, r.z_far);
        // (Not read at all here with `LATE`: a read left for the optimiser
        // to drop measured two register moves more per flagged point in
        // the bench firmware's loop, `straight_exact` +1.0 %.)
        let early = if LATE { None } else { Some((r.pixel1, r.z)) };
        let Ok(wedge) = Wedge::new(
            p,
            (self.foe, self.side),
            (r1, self.e2, self.e2_csc),
            (key, self.key_scale, self.orient),
        ) else {
            *r = PointResult::flagged(r.pixel1, Status::AtFoe);
            return (hint, 0);
        };
        let (outcome, a) = wedge_run(
            &wedge,
            (self.segs, self.b2),
            hint,
            self.segments,
            self.cot_twice,
            work,
        );
        // (`r` as steps 1–2 left it: with `LATE` what only the conclusion
        // needs read after the walk, not kept through it.)
        let (p1, iz) = early.unwrap_or((r.pixel1, r.z));
        (a, self.conclude(r, (p1, iz, r1), &wedge, outcome))
    }

    /// The point's result in `r` from its walk's outcome, or, where the
    /// stick is to be tightened by the piece's lines ([`Wedge::refines`]),
    /// `r` left as steps 1–2 left it and the piece's end returned for
    /// [`Self::refine`] (0: done). (The refinement out of the walk's
    /// function: there it cost the usual point 30 instructions.)
    #[inline(always)]
    fn conclude(
        &self,
        r: &mut PointResult,
        (p1, iz, r1): (Pixel, f32, f32),
        wedge: &Wedge,
        outcome: Outcome,
    ) -> usize {
        if let Some(end) = wedge.refines(&outcome) {
            return end;
        }
        *r = conclude_coarse(self.pair, (p1, iz, r1), wedge, outcome);
        0
    }

    /// The result of a point whose walk ended with the piece that ends at
    /// `end` and whose stick [`Self::conclude`] left to tighten: its
    /// wedge again (the same arithmetic: the same bits), then the piece's
    /// crossing and refined stick ([`Wedge::refined`], its lines paid from
    /// `work`).
    #[cold]
    #[inline(never)]
    fn refine(&self, r: &mut PointResult, end: usize, work: &mut Work) {
        let mut credit = work.credit();
        let (p1, p, iz, r1, key) = (r.pixel1, r.pixel2.arr(), r.z, r.z_near, r.z_far);
        *r = match Wedge::new(
            p,
            (self.foe, self.side),
            (r1, self.e2, self.e2_csc),
            (key, self.key_scale, self.orient),
        ) {
            Ok(wedge) => {
                conclude_refined(self.pair, (p1, iz, r1), &wedge, self.b2, end, &mut credit)
            }
            // (Not reached: the walk had this wedge.)
            Err(_) => PointResult::flagged(p1, Status::AtFoe),
        };
        work.set_credit(credit);
    }

    /// [`Self::point`] with the index's aside entries merged into the run
    /// ([`wedge_run_aside`]), through a loose index (`SKIP`) with the
    /// tree's skips too; inlined into [`Self::points`]. (Without `SKIP`,
    /// `p₁` and `1/q_z` read after the walk measured `demo_15` +17.2
    /// instructions a point, read before it as here none dearer.)
    #[inline(always)]
    fn aside_walk<const SKIP: bool, const LATE: bool>(
        &self,
        r: &mut PointResult,
        hint: usize,
        work: &mut Work,
    ) -> (usize, usize) {
        let (p1, p, iz, r1, key) = (r.pixel1, r.pixel2.arr(), r.z, r.z_near, r.z_far);
        let Ok(wedge) = Wedge::new(
            p,
            (self.foe, self.side),
            (r1, self.e2, self.e2_csc),
            (key, self.key_scale, self.orient),
        ) else {
            *r = PointResult::flagged(p1, Status::AtFoe);
            return (hint, 0);
        };
        // When no aside entry has a part in the wedge, offered in their
        // places they would change nothing: the run is walked without
        // them, their units paid first (all of them, where the merge
        // charges only those before a walk that stops early: the results
        // are the merge's unless the budget binds). The test is not
        // charged, and when an entry has a part the merge tests the
        // entries again: at most `MAX_ASIDE` tests a point, a constant.
        // (Not on a loose index: there the test measured dearer than the
        // merge.)
        if !SKIP {
            if let Some(units) = aside_idle(&wedge, self.b2, self.aside) {
                let (outcome, a) = match work.spend(units) {
                    Ok(()) => wedge_run(
                        &wedge,
                        (self.segs, self.b2),
                        hint,
                        self.segments,
                        self.cot_twice,
                        work,
                    ),
                    Err(OutOfWork) => (Outcome::Flag(Status::OverBudget), hint),
                };
                return (a, self.conclude(r, (p1, iz, r1), &wedge, outcome));
            }
        }
        let (outcome, a) = wedge_run_aside::<SKIP>(
            &wedge,
            (self.segs, self.b2, self.aside),
            (hint, self.blocks),
            (self.segments, self.cot_twice),
            work,
        );
        // (On a loose index, in [`Self::points`]: what only the conclusion
        // needs read after the walk, as [`Self::point`] does.)
        let (p1, iz) = if SKIP && LATE {
            (r.pixel1, r.z)
        } else {
            (p1, iz)
        };
        (a, self.conclude(r, (p1, iz, r1), &wedge, outcome))
    }
}

/// The wedge walk over the run of an index's lean view without aside
/// entries (the segments [`Index::visit`] would offer, each looked at a
/// unit, each whose interval meets the query [`CLIP_UNITS`] more, as the
/// reference's [`WedgeWalker`] takes them): [`wedge_run_aside`] with no
/// entries and no block tree. Returns the outcome and where the run
/// started.
#[inline(always)]
fn wedge_run(
    wedge: &Wedge,
    (segs, b2): (&[crate::search::Seg], &[Pixel]),
    hint: usize,
    segments: usize,
    cot_twice: f32,
    work: &mut Work,
) -> (Outcome, usize) {
    wedge_run_aside::<false>(
        wedge,
        (segs, b2, &[]),
        (hint, Blocks::NONE),
        (segments, cot_twice),
        work,
    )
}

/// [`wedge_run`] through an index with aside entries: each one offered
/// in its place by index ([`offer`]: a look one unit, a met one
/// [`CLIP_UNITS`] more), before the run's segments after it and, past the
/// run, in order. With `SKIP` (a loose index, whose runs can be long where
/// the keys fold), a segment that misses the wedge's keys also passes over
/// the largest aligned block of the tree from it that misses them
/// ([`Blocks::skip_at`]; a block holding a segment that meets them meets
/// them too, so only a miss can start a skip), for the look's unit.
/// Returns the outcome and where the run started.
#[inline(always)]
pub(in crate::processor) fn wedge_run_aside<const SKIP: bool>(
    wedge: &Wedge,
    (segs, b2, aside): (&[crate::search::Seg], &[Pixel], &[crate::search::Aside]),
    (hint, blocks): (usize, impl BlockSkip),
    (segments, cot_twice): (usize, f32),
    work: &mut Work,
) -> (Outcome, usize) {
    let (kl, kh) = (wedge.kl, wedge.kh);
    let a = match run_start_in(segs, hint, kl, work) {
        Ok(a) => a,
        Err(OutOfWork) => return (Outcome::Flag(Status::OverBudget), hint),
    };
    let mut walk = WedgeWalk::NEW;
    let mut c = work.credit();
    // The vertex that starts segment `cached`, when it is `va`.
    let mut cached = usize::MAX;
    let mut va = WVertex::NONE;
    let mut stop = None;
    // The aside entries not yet offered, and the segment index of the
    // next one (`usize::MAX`: none left).
    let mut rest = aside.iter();
    let mut next = rest.next();
    let at_of = |e: Option<&crate::search::Aside>| e.map_or(usize::MAX, |e| usize::from(e.0));
    let mut next_at = at_of(next);
    let cx = (segments, cot_twice);
    let end = segs.len().min(b2.len().saturating_sub(1));
    // The vertices up to the run's last end (the aside entries take theirs
    // from `b2`).
    let run = b2.get(..end + 1).unwrap_or(&[]);
    let meets = |l: f32, h: f32| l <= kh && h >= kl;
    // The next segment to look at (bounded: every step moves it on).
    let mut at = a;
    'walk: while at < end {
        let j = at;
        at += 1;
        let (Some(g), Some(v1)) = (segs.get(j), run.get(j + 1)) else {
            break;
        };
        // The aside entries before segment `j` come first. (On a loose
        // index a look tests only `next_at`, one integer comparison: the
        // entry's `Option` and its index took 9 instructions a look there,
        // `demo_9` 920.6 → 893.4, `demo_13` 977.4 → 953.9 instructions a
        // point. On a tight index the same form made the usual walk
        // beside it dearer, `demo_15` +0.6 %: there the test is as before,
        // and `next_at` unused.)
        loop {
            // (`next_at` is `next`'s segment index, `usize::MAX` when none
            // is left: the two change together.)
            let due = if SKIP {
                next_at < j
            } else {
                next.is_some_and(|e| usize::from(e.0) < j)
            };
            let (true, Some(&(k, l, h))) = (due, next) else {
                break;
            };
            let k = usize::from(k);
            next = rest.next();
            next_at = at_of(next);
            if let Err(s) = offer(
                wedge,
                b2,
                k,
                (l, h),
                &mut c,
                &mut walk,
                (&mut cached, &mut va),
                cx,
            ) {
                stop = Some(s);
                break 'walk;
            }
        }
        // The interval's low end decides first: above `kh` it misses (and
        // past the suffix minimum, at most the low end, the run ends).
        // One comparison per end: every wedge's query is ordered, `kl ≤
        // kh` (a key less and plus margins that are not negative, the
        // edges' keys in order, or `(−∞, −∞)`; [`Wedge::new`],
        // [`Wedge::new_angular`] and a copy of its interval,
        // [`Lean::copy`]), so `lo ≤ kh` is the `lo < kl || lo ≤ kh` this
        // walk tested before (below `kl` the segment reaches past the low
        // edge), and `hi ≥ kl` its `hi > kh || hi ≥ kl`: the test of
        // [`offer`] and the references'. (The same decisions, 3 VFP
        // comparisons a look and a take fewer: the representative window
        // 728.0 → 711.5 instructions a point.) (A NaN fails.)
        let lo_meets = g.lo <= kh;
        if !SKIP && !lo_meets {
            // (On a tight index about once a run, at its end: laid out of
            // the walk's way. As `SKIP`'s below, without the skip.)
            core::hint::cold_path();
            if g.sm > kh {
                break;
            }
            if c == 0 {
                stop = Some(Status::OverBudget);
                break;
            }
            c -= 1;
            continue;
        }
        if SKIP && !lo_meets {
            if g.sm > kh {
                break;
            }
            if c == 0 {
                stop = Some(Status::OverBudget);
                break;
            }
            c -= 1;
            if SKIP {
                at = j.saturating_add(blocks.skip_at(j, meets).max(1));
            }
            continue;
        }
        let hi_meets = g.hi >= kl;
        if !SKIP && !hi_meets {
            // (Rare on a tight index: laid out of the walk's way. As
            // `SKIP`'s below, without the skip.)
            core::hint::cold_path();
            if c == 0 {
                stop = Some(Status::OverBudget);
                break;
            }
            c -= 1;
            continue;
        }
        if SKIP && !hi_meets {
            if c == 0 {
                stop = Some(Status::OverBudget);
                break;
            }
            c -= 1;
            if SKIP {
                at = j.saturating_add(blocks.skip_at(j, meets).max(1));
            }
            continue;
        }
        // The look's unit and the clip's together (short of them, the
        // walk stops with the credit spent, as a look then a clip would).
        if c <= CLIP_UNITS {
            c = 0;
            stop = Some(Status::OverBudget);
            break;
        }
        c -= CLIP_UNITS + 1;
        if cached != j {
            if let Some(v0) = run.get(j) {
                va = wedge.vertex(v0.arr());
            }
        }
        let vb = wedge.vertex(v1.arr());
        if let Err(s) = walk.take_met(wedge, j, (&va, &vb), segments, cot_twice) {
            stop = Some(s);
            break;
        }
        va = vb;
        cached = j + 1;
    }
    // The aside entries past the run.
    if stop.is_none() {
        while let Some(&(k, l, h)) = next {
            next = rest.next();
            if let Err(s) = offer(
                wedge,
                b2,
                usize::from(k),
                (l, h),
                &mut c,
                &mut walk,
                (&mut cached, &mut va),
                cx,
            ) {
                stop = Some(s);
                break;
            }
        }
    }
    work.set_credit(c);
    let outcome = match stop {
        Some(s) => Outcome::Flag(s),
        None => walk.outcome(),
    };
    (outcome, a)
}

/// An aside segment `k` with its interval `(l, h)` offered to the walk
/// as [`wedge_run`] takes a run's segment: one unit to look at it,
/// [`CLIP_UNITS`] more when its interval meets the wedge's; `Err` when the
/// walk stops ([`Status::OverBudget`] included).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn offer(
    wedge: &Wedge,
    b2: &[Pixel],
    k: usize,
    (l, h): (f32, f32),
    c: &mut u32,
    walk: &mut WedgeWalk,
    (cached, va): (&mut usize, &mut WVertex),
    (segments, cot_twice): (usize, f32),
) -> Result<(), Status> {
    if *c == 0 {
        return Err(Status::OverBudget);
    }
    *c -= 1;
    // (A NaN fails.)
    if !(l <= wedge.kh && h >= wedge.kl) {
        return Ok(());
    }
    // (Two tests here: the run's one test for the look and the clip
    // together measured dearer in this function, `foe_row` +0.6 %.)
    if *c < CLIP_UNITS {
        *c = 0;
        return Err(Status::OverBudget);
    }
    *c -= CLIP_UNITS;
    let Some(v1) = b2.get(k + 1) else {
        return Ok(());
    };
    if *cached != k {
        if let Some(v0) = b2.get(k) {
            *va = wedge.vertex(v0.arr());
        }
    }
    let vb = wedge.vertex(v1.arr());
    // An aside segment (a spurious point's) often lies wholly before
    // `X_min`: then the walk finds no part (within three roundings the
    // clip's ends stay below the larger end's `X`), and its clip is skipped.
    let r = if wedge.before(&*va, &vb) {
        Ok(())
    } else {
        walk.take_met(wedge, k, (va, &vb), segments, cot_twice)
    };
    (*cached, *va) = (k + 1, vb);
    r
}

/// Whether no aside entry has a part in the wedge, tested as [`offer`]
/// tests each (an interval that misses the wedge's keys, an end beyond
/// the polyline, [`Wedge::before`], then [`Wedge::part`]); if so, the
/// units offering them all would cost (one each, [`CLIP_UNITS`] more for
/// each whose interval meets the keys).
#[inline(always)]
fn aside_idle(wedge: &Wedge, b2: &[Pixel], aside: &[crate::search::Aside]) -> Option<u32> {
    let mut units = 0u32;
    // The vertex that starts segment `cached`, when it is `va`.
    let mut cached = usize::MAX;
    let mut va = WVertex::NONE;
    for &(k, l, h) in aside {
        units = units.saturating_add(1);
        // (A NaN fails.)
        if !(l <= wedge.kh && h >= wedge.kl) {
            continue;
        }
        units = units.saturating_add(CLIP_UNITS);
        let k = usize::from(k);
        let (Some(v0), Some(v1)) = (b2.get(k), b2.get(k + 1)) else {
            continue;
        };
        if cached != k {
            va = wedge.vertex(v0.arr());
        }
        let vb = wedge.vertex(v1.arr());
        if !wedge.before(&va, &vb) && wedge.part(&va, &vb).is_some() {
            return None;
        }
        (cached, va) = (k + 1, vb);
    }
    Some(units)
}
