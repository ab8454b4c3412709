//! Step 4 of the per-frame call ([`super`]): **match** every point that
//! steps 1–3 left, against the indexed frame-2 boundary.
//!
//! Moving forwards without a translation error, a point's error band is
//! replaced by the wedge that holds it ([`crate::wedge`]), searched through
//! the index's lean view: [`match_wedge_lean`] for half-plane keys (its
//! walks, [`wedge_run`] and [`wedge_run_aside`], with the aside entries
//! merged in or tested first, [`aside_idle`]), [`match_wedge_angular`] for
//! pseudo-angle keys (the index's one copy of the wedge's interval). Every
//! other point, and those of the angular path without a single copy, take
//! the general band path ([`match_point`], [`crate::depth`],
//! [`crate::matching`]). Each path has its reference beside it (every
//! segment offered in order, behind the private `_reference` feature),
//! and all end in the same depth and stick ([`finish_point`]).

use super::*;
use crate::deadline::{Deadline, Guard};

/// Step 4 for every point of a boundary left by steps 1–2. (Out of line,
/// with the loop inside: the frame's constants stay in registers.)
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub(super) fn match_boundary<const N: usize, D: Deadline>(
    pair: &Pair,
    keying: &Keying,
    near_foe: f32,
    (slots, b2): (&mut [PointResult], &[Pixel]),
    index: &mut Index<N>,
    (work, guard): (&mut Work, &mut Guard<'_, D>),
    matcher: Matcher,
) {
    let mut credit = *work;
    let wedge = wedge_path(pair);
    match (keying.pencil, wedge) {
        (Pencil::Half { foe, side, .. }, true) => {
            match matcher {
                Matcher::Indexed => match_wedge_lean(
                    pair,
                    keying,
                    (foe, side),
                    (slots, b2),
                    index,
                    (&mut credit, guard),
                ),
                Matcher::Reference => match_wedge_reference(pair, keying, (foe, side), slots, b2),
            }
            *work = credit;
            return;
        }
        (Pencil::Angular { foe }, true) => {
            let args = (pair, keying, near_foe, foe);
            match matcher {
                Matcher::Indexed => {
                    match_wedge_angular(args, (slots, b2), index, (&mut credit, guard))
                }
                Matcher::Reference => match_wedge_angular_reference(args, slots, b2, index),
            }
            *work = credit;
            return;
        }
        _ => {}
    }
    if !D::NEVER && matcher == Matcher::Indexed && matches!(keying.pencil, Pencil::Half { .. }) {
        // Under a deadline: the radial levels the band queries use built
        // before the first point's search, not inside it, the clock asked
        // before and during the build (between parts of `CHUNK` blocks).
        let mut ask = || guard.check();
        if !ask() {
            index.build_radial_once(b2, &mut Some(&mut ask));
        }
        if guard.has_expired() {
            flag_pending(slots, Status::OverBudget);
            *work = credit;
            return;
        }
    }
    for r in slots.iter_mut() {
        if r.status == Status::NoIntersection {
            *r = if matcher == Matcher::Reference || guard.proceed(&mut credit) {
                match_point(pair, keying, near_foe, r, b2, index, &mut credit, matcher)
            } else {
                PointResult::flagged(r.pixel1, Status::OverBudget)
            };
        }
    }
    *work = credit;
}

/// Whether a pair's points take the wedge path ([`crate::wedge`]): moving
/// forwards without a translation error. With half-plane keys, the lean
/// walks ([`match_wedge_lean`]), the one search of frame 2's index: the
/// index's build leaves a loose index's block tree to them then, without
/// a clock ([`Builder::finish_deferring_tree`]). (No other path checks
/// for a tree left to build: to every other reader it is no tree, which
/// is never wrong, and `match_boundary`'s band loop measured dearer with
/// the check, `foe_row_rot_err` +3.6 % at N = 512.)
#[inline(always)]
pub(super) fn wedge_path(pair: &Pair) -> bool {
    pair.geom.w() > 0.0 && pair.translation <= 0.0
}

/// The wedge path through an index's lean view ([`Index::lean`]): every
/// point's run walked in locals ([`LeanWalk::point`]); the aside entries,
/// if any, merged in by index, and on a loose index the block tree's skips
/// taken too ([`LeanWalk::aside_walk`]); each walk's points in one loop
/// ([`LeanWalk::points`]).
#[inline(never)]
fn match_wedge_lean<const N: usize, D: Deadline>(
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

/// The wedge path for pseudo-angle keys ([`Pencil::Angular`]: a frame-2
/// boundary that comes close to the FOE's row, or crosses it). Each
/// point's wedge gets its pseudo-angle interval ([`Wedge::new_angular`]),
/// and the index the one copy of it to walk ([`Lean::copy`]: the keys are
/// unwrapped along the polyline, a ray's key is known up to turns); the
/// copy's run is walked as a loose index's, with the aside entries merged
/// in ([`wedge_run_aside`]). A point whose wedge has no single copy (the
/// boundary's keys span nearly a turn or more, or lie out of reach, or the
/// point has no key) takes the band path ([`match_point`]), as every point
/// of these boundaries did before.
#[inline(never)]
fn match_wedge_angular<const N: usize, D: Deadline>(
    (pair, keying, near_foe, foe): (&Pair, &Keying, f32, [f32; 2]),
    (slots, b2): (&mut [PointResult], &[Pixel]),
    index: &mut Index<N>,
    (work, guard): (&mut Work, &mut Guard<'_, D>),
) {
    // A piece's end (at most `N`) is kept in an `f32` for
    // [`refine_deferred`]: exact below 2²⁴. (At compile time, no cost.)
    const { assert!(N < 1 << 24, "a boundary capacity below 2^24 points") };
    let (e2, e2_csc, cot_twice) = (pair.e2(), pair.e2_csc(), pair.config.cot_twice);
    let segments = b2.len().saturating_sub(1);
    let mut deferred = false;
    for r in slots.iter_mut() {
        if r.status != Status::NoIntersection {
            continue;
        }
        let (p1, iz, r1) = (r.pixel1, r.z, r.z_near);
        if !guard.proceed(work) {
            *r = PointResult::flagged(p1, Status::OverBudget);
            continue;
        }
        let lean = index.lean();
        let wedge = match angular_wedge(r, (foe, e2, e2_csc), keying, &lean) {
            AngularPoint::Walk(w) => w,
            AngularPoint::AtFoe => {
                *r = PointResult::flagged(p1, Status::AtFoe);
                continue;
            }
            AngularPoint::Band => {
                #[cfg(test)]
                super::tests::ANGULAR.with(|c| c.set((c.get().0, c.get().1 + 1)));
                *r = band_point((pair, keying, near_foe), r, b2, index, work);
                continue;
            }
        };
        #[cfg(test)]
        super::tests::ANGULAR.with(|c| c.set((c.get().0 + 1, c.get().1)));
        let (outcome, a) = wedge_run_aside::<true>(
            &wedge,
            (lean.segs, b2, lean.aside),
            (index.hint(), lean.blocks),
            (segments, cot_twice),
            work,
        );
        index.set_hint(a);
        match wedge.refines(&outcome) {
            // Left for [`refine_deferred`] (out of this loop: a call here
            // cost every point 30 instructions): the slot keeps steps
            // 1–2's values, `z_far` (the key, no longer needed) the
            // piece's end, below `N` and so exact as an `f32` (the
            // assertion above).
            Some(end) => {
                r.z_far = end as f32;
                deferred = true;
            }
            None => *r = conclude_coarse(pair, (p1, iz, r1), &wedge, outcome),
        }
    }
    if deferred {
        refine_deferred((pair, foe), slots, b2, (work, guard));
    }
}

/// The points [`match_wedge_angular`] left to refine: still
/// [`Status::NoIntersection`] with steps 1–2's `r₁ > 0` in `z_near` (every
/// point it concluded or flagged has a clean result, `z_near` 0 where it
/// is flagged) and the piece's end in `z_far`. Each gets its wedge's
/// geometry again (the same bits; the keys are not needed) and the refined
/// stick ([`conclude_refined`]), its lines paid from `credit`, what the
/// walks left of the frame's work budget. (So under a tight budget this
/// path keeps its walks and loses tightening, where the half-plane path,
/// which refines each point as it goes, may spend on a refinement what a
/// later point's walk needed: both valid, the sticks held either way.)
/// Each asks the caller's deadline first (`guard`): once it has expired,
/// the points left are [`Status::OverBudget`].
#[cold]
#[inline(never)]
fn refine_deferred<D: Deadline>(
    (pair, foe): (&Pair, [f32; 2]),
    slots: &mut [PointResult],
    b2: &[Pixel],
    (work, guard): (&mut Work, &mut Guard<'_, D>),
) {
    let errors = (pair.e2(), pair.e2_csc());
    for r in slots
        .iter_mut()
        .filter(|r| r.status == Status::NoIntersection && r.z_near > 0.0)
    {
        let (p1, p, iz, r1) = (r.pixel1, r.pixel2.arr(), r.z, r.z_near);
        if !guard.proceed(work) {
            *r = PointResult::flagged(p1, Status::OverBudget);
            continue;
        }
        // (Finite, integral and below 2²⁴: the loop stored only such.)
        let end = r.z_far as usize;
        let no_key = (crate::pencil::NO_KEY, 1.0, 1.0);
        let mut credit = work.credit();
        *r = match Wedge::new_angular(p, foe, (r1, errors.0, errors.1), no_key) {
            Ok(wedge) => conclude_refined(pair, (p1, iz, r1), &wedge, b2, end, &mut credit),
            // (Not reached: the loop had this wedge.)
            Err(_) => PointResult::flagged(p1, Status::AtFoe),
        };
        work.set_credit(credit);
    }
}

/// What the wedge path for pseudo-angle keys does with a point left by
/// steps 1–2 ([`angular_wedge`]).
enum AngularPoint {
    /// Its wedge, with the one copy of its key interval to walk.
    Walk(Wedge),
    /// Within `3 (r₁ + e₂)` of the FOE ([`Status::AtFoe`]).
    AtFoe,
    /// No single copy of its key interval (or no key): the band path.
    Band,
}

/// The point in `r`'s wedge for the FOE `foe` and errors `e2`, `e2_csc`
/// ([`Wedge::new_angular`]), its key interval replaced by the copy the
/// index's lean view gives ([`Lean::copy`]); the same for the fast path
/// and its reference.
#[inline(always)]
fn angular_wedge(
    r: &PointResult,
    (foe, e2, e2_csc): ([f32; 2], f32, f32),
    keying: &Keying,
    lean: &Lean,
) -> AngularPoint {
    let (p, r1, key) = (r.pixel2.arr(), r.z_near, r.z_far);
    let keys = (key, keying.key_scale, lean.orient);
    let Ok(mut wedge) = Wedge::new_angular(p, foe, (r1, e2, e2_csc), keys) else {
        return AngularPoint::AtFoe;
    };
    match lean.copy(wedge.kl, wedge.kh) {
        Some((kl, kh)) => {
            (wedge.kl, wedge.kh) = (kl, kh);
            AngularPoint::Walk(wedge)
        }
        None => AngularPoint::Band,
    }
}

/// [`match_point`] for a point of [`match_wedge_angular`] whose wedge has
/// no single copy (rare: out of line, not a second inlined band path).
#[cold]
#[inline(never)]
fn band_point<const N: usize>(
    (pair, keying, near_foe): (&Pair, &Keying, f32),
    r: &PointResult,
    b2: &[Pixel],
    index: &mut Index<N>,
    work: &mut Work,
) -> PointResult {
    match_point(pair, keying, near_foe, r, b2, index, work, Matcher::Indexed)
}

/// [`match_wedge_angular`]'s reference: the same wedges, every segment
/// offered to the walk in order with no key filter at all (the interval
/// `(−∞, ∞)`), so that the geometry alone decides: a segment the indexed
/// walk leaves out (its key interval, unwrapped, misses the copy of the
/// wedge's) must have no part in the wedge, which checks the keys, their
/// unwrapping, the keys' range and the copy as well as the run search.
/// (Which points take the band path, those whose wedge has no single
/// copy, is the index's answer for both; they take the band path's
/// reference.)
#[cfg_attr(not(any(test, feature = "_reference")), allow(dead_code))]
#[inline(never)]
fn match_wedge_angular_reference<const N: usize>(
    (pair, keying, near_foe, foe): (&Pair, &Keying, f32, [f32; 2]),
    slots: &mut [PointResult],
    b2: &[Pixel],
    index: &mut Index<N>,
) {
    let (e2, e2_csc, cot_twice) = (pair.e2(), pair.e2_csc(), pair.config.cot_twice);
    let segments = b2.len().saturating_sub(1);
    let mut work = Work::new();
    for r in slots.iter_mut() {
        if r.status != Status::NoIntersection {
            continue;
        }
        let (p1, iz, r1) = (r.pixel1, r.z, r.z_near);
        let lean = index.lean();
        let wedge = match angular_wedge(r, (foe, e2, e2_csc), keying, &lean) {
            AngularPoint::Walk(w) => w,
            AngularPoint::AtFoe => {
                *r = PointResult::flagged(p1, Status::AtFoe);
                continue;
            }
            AngularPoint::Band => {
                *r = match_point(
                    pair,
                    keying,
                    near_foe,
                    r,
                    b2,
                    index,
                    &mut work,
                    Matcher::Reference,
                );
                continue;
            }
        };
        let mut walker = WedgeWalker::new(wedge, b2, cot_twice);
        let every = (f32::NEG_INFINITY, f32::INFINITY);
        for j in 0..segments {
            if Visitor::segment(&mut walker, j, every).0 == Flow::Stop {
                break;
            }
        }
        *r = conclude_wedge(pair, (p1, iz, r1), &wedge, walker.outcome(), b2);
    }
}

/// Every point still to be matched flagged `status` (a clean result,
/// step 1's values gone): [`Status::NoIntersection`] where frame 2 lacks
/// the boundary, [`Status::OverBudget`] once the caller's deadline has
/// expired ([`crate::deadline`]).
#[cold]
#[inline(never)]
pub(super) fn flag_pending(slots: &mut [PointResult], status: Status) {
    for r in slots
        .iter_mut()
        .filter(|r| r.status == Status::NoIntersection)
    {
        *r = PointResult::flagged(r.pixel1, status);
    }
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
        if D::NEVER {
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
        for r in slots.iter_mut() {
            if r.status == Status::NoIntersection {
                if !guard.proceed(work) {
                    *r = PointResult::flagged(r.pixel1, Status::OverBudget);
                    continue;
                }
                let (h, refine) = self.walk_out::<WALK>(r, hint, work);
                hint = h;
                if refine != 0 {
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

/// The wedge path's reference: every segment offered to the walk, with
/// the interval the index would hold ([`raw_interval`]), no work budget.
#[cfg_attr(not(any(test, feature = "_reference")), allow(dead_code))]
#[inline(never)]
fn match_wedge_reference(
    pair: &Pair,
    keying: &Keying,
    (foe, side): ([f32; 2], f32),
    slots: &mut [PointResult],
    b2: &[Pixel],
) {
    let (e2, e2_csc, cot_twice) = (pair.e2(), pair.e2_csc(), pair.config.cot_twice);
    let segments = b2.len().saturating_sub(1);
    for r in slots.iter_mut() {
        if r.status != Status::NoIntersection {
            continue;
        }
        let (p1, p, iz, r1, key) = (r.pixel1, r.pixel2.arr(), r.z, r.z_near, r.z_far);
        let key3 = (key, keying.key_scale, 1.0);
        let Ok(wedge) = Wedge::new(p, (foe, side), (r1, e2, e2_csc), key3) else {
            *r = PointResult::flagged(p1, Status::AtFoe);
            continue;
        };
        let mut walker = WedgeWalker::new(wedge, b2, cot_twice);
        for j in 0..segments {
            let iv = match (b2.get(j), b2.get(j + 1)) {
                (Some(a), Some(b)) => raw_interval(keying, a.arr(), b.arr()),
                _ => (f32::INFINITY, f32::NEG_INFINITY),
            };
            if Visitor::segment(&mut walker, j, iv).0 == Flow::Stop {
                break;
            }
        }
        *r = conclude_wedge(pair, (p1, iz, r1), &wedge, walker.outcome(), b2);
    }
}

/// A segment's key interval as the index builds it, from raw keys (the
/// reference's view of [`crate::search`]).
#[cfg_attr(not(any(test, feature = "_reference")), allow(dead_code))]
fn raw_interval(keying: &Keying, a: [f32; 2], b: [f32; 2]) -> (f32, f32) {
    let ((ka, ea), (kb, eb)) = (keying.key(a), keying.key(b));
    if (ka + kb).is_finite() {
        (
            crate::math::fmin(ka - ea, kb - eb),
            crate::math::fmax(ka + ea, kb + eb),
        )
    } else {
        (f32::NEG_INFINITY, f32::INFINITY)
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
pub(super) fn wedge_run_aside<const SKIP: bool>(
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

/// The point's result from a wedge walk's outcome: depth and stick
/// from the piece's range ([`Wedge::depths`]), for an outcome that
/// [`Wedge::refines`] leaves alone.
#[inline(always)]
fn conclude_coarse(
    pair: &Pair,
    (p1, iz, r1): (Pixel, f32, f32),
    wedge: &Wedge,
    outcome: Outcome,
) -> PointResult {
    let (lam, lo, hi) = match outcome {
        Outcome::Match { lam, lo, hi, .. } => (lam, lo, hi),
        Outcome::Flag(s) => return PointResult::flagged(p1, s),
    };
    let p2 = wedge.point_at(lam);
    let depths = wedge.depths(pair.w_stick, r1, (lam, lo, hi));
    finish_point(pair, p1, p2, iz, depths)
}

/// The point's result from a wedge walk's outcome: depth and stick
/// ([`crate::wedge`]), tightened by the piece's lines where
/// [`Wedge::refines`] says (the references' conclusion: no work budget).
fn conclude_wedge(
    pair: &Pair,
    (p1, iz, r1): (Pixel, f32, f32),
    wedge: &Wedge,
    outcome: Outcome,
    b2: &[Pixel],
) -> PointResult {
    match wedge.refines(&outcome) {
        Some(end) => {
            let mut unlimited = u32::MAX;
            conclude_refined(pair, (p1, iz, r1), wedge, b2, end, &mut unlimited)
        }
        None => conclude_coarse(pair, (p1, iz, r1), wedge, outcome),
    }
}

/// [`conclude_wedge`] for a walk whose piece ends at `end` and whose
/// outcome [`Wedge::refines`] ([`Wedge::refined`], its lines paid from
/// `credit`; a stick left unbounded because the credit fell short is
/// flagged [`Status::OverBudget`]). (Out of line: the usual point does not
/// take it.)
#[cold]
#[inline(never)]
fn conclude_refined(
    pair: &Pair,
    (p1, iz, r1): (Pixel, f32, f32),
    wedge: &Wedge,
    b2: &[Pixel],
    end: usize,
    credit: &mut u32,
) -> PointResult {
    match wedge.refined(b2, end, (pair.w_stick, r1), credit) {
        // Unbounded only because the credit fell short: the budget's flag.
        Some((_, None, true)) => PointResult::flagged(p1, Status::OverBudget),
        Some((x, depths, _)) => finish_point(pair, p1, wedge.point_at(x), iz, depths),
        // (Not reached: the walk found this piece with this wedge.)
        None => PointResult::flagged(p1, Status::NoIntersection),
    }
}

/// Step 4 for one point left by steps 1–2 in `r`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn match_point<const N: usize>(
    pair: &Pair,
    keying: &Keying,
    near_foe: f32,
    r: &PointResult,
    b2: &[Pixel],
    index: &mut Index<N>,
    work: &mut Work,
    matcher: Matcher,
) -> PointResult {
    let (p1, p, iz, r1, key) = (r.pixel1, r.pixel2.arr(), r.z, r.z_near, r.z_far);
    let geom = &pair.geom;
    let a = geom.epipolar_vector(p);
    let spread_a = if pair.translation > 0.0 {
        crate::motion_error::spread(
            geom.rotation(),
            geom.camera2_intrinsics(),
            p,
            pair.translation,
        )
        .0
    } else {
        0.0
    };
    let errors = PointErrors {
        r1,
        e2: pair.e2(),
        e2_csc: pair.e2_csc(),
        spread_a,
        spread_w: pair.spread_w,
    };
    let Ok(band) = Band::new(p, a, geom.w(), &errors, near_foe) else {
        return PointResult::flagged(p1, Status::AtFoe);
    };
    let cot_twice = pair.config.cot_twice;
    // Moving backwards, a cheap test rejects most of the wide key
    // interval's segments (half-plane keys; see `Radial`).
    let orient = match matcher {
        Matcher::Indexed => index.orient(),
        Matcher::Reference => 1.0,
    };
    let radial = match (keying.pencil, pair.foe) {
        (Pencil::Half { side, .. }, Some(foe)) => {
            let (k, m) = keying.key(p);
            let own = if orient < 0.0 {
                (-k - m, -k + m)
            } else {
                (k - m, k + m)
            };
            Radial::new(&band, (foe, side), own, near_foe)
        }
        _ => None,
    };
    let mut walk = Walker::new(band, b2, cot_twice, radial);
    let outcome = match matcher {
        Matcher::Reference => {
            for j in 0..b2.len().saturating_sub(1) {
                let iv = match (b2.get(j), b2.get(j + 1)) {
                    (Some(a), Some(b)) => raw_interval(keying, a.arr(), b.arr()),
                    _ => (f32::NEG_INFINITY, f32::INFINITY),
                };
                if Visitor::segment(&mut walk, j, iv).0 == Flow::Stop {
                    break;
                }
            }
            walk.outcome()
        }
        Matcher::Indexed => {
            let query = band_query(pair, keying, &band, key, near_foe);
            let with_near = geom.w() < 0.0;
            match index.visit(query, with_near, None, work, &mut walk) {
                Err(OutOfWork) => return PointResult::flagged(p1, Status::OverBudget),
                Ok(()) => walk.outcome(),
            }
        }
    };
    conclude(pair, p1, iz, &band, &errors, outcome)
}

/// The key interval to search for a band (see [`Band::key_half_width`]
/// and [`Keying::around`]).
fn band_query(pair: &Pair, keying: &Keying, band: &Band, key: f32, near_foe: f32) -> Query {
    const NOTHING: Query = Query::Keys(f32::INFINITY, f32::NEG_INFINITY);
    if keying.angular() {
        match band.key_half_width(near_foe, pair.exhaustive(), keying.key_scale) {
            crate::depth::Reach::Within(t, m) => match keying.around(band.p, key, t, m) {
                Some((lo, hi)) => Query::Keys(lo, hi),
                None => NOTHING,
            },
            crate::depth::Reach::Everything => Query::Everything,
        }
    } else {
        // The hull of the corners' keys, within the image's reach.
        let from_p = (band.p[0] - pair.geom.c2()[0]).abs()
            + (band.p[1] - pair.geom.c2()[1]).abs()
            + pair.reach;
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for c in band.corners(from_p) {
            let (k, m) = keying.key(c);
            if !k.is_finite() {
                return Query::Everything;
            }
            lo = crate::math::fmin(lo, k - m);
            hi = crate::math::fmax(hi, k + m);
        }
        Query::Keys(lo, hi)
    }
}

/// The point's result from the walk's outcome: depth (eq. 2.3) and stick.
fn conclude(
    pair: &Pair,
    p1: Pixel,
    iz: f32,
    band: &Band,
    errors: &PointErrors,
    outcome: Outcome,
) -> PointResult {
    let (lam, lo, hi) = match outcome {
        Outcome::Match { lam, lo, hi, .. } => (lam, lo, hi),
        Outcome::Flag(s) => return PointResult::flagged(p1, s),
    };
    let p2 = band.point_at(lam);
    finish_point(pair, p1, p2, iz, band.depths(errors, lam, lo, hi))
}

/// A matched point's result from its frame-2 point and `(s, s_near,
/// s_far)` (`None`: the stick is unbounded): eq. 2.3's depth `Z = s/q_z`,
/// the checks on it, and the stick widened by `q_z`'s uncertainty.
#[inline(always)]
fn finish_point(
    pair: &Pair,
    p1: Pixel,
    p2: [f32; 2],
    iz: f32,
    depths: Option<(f32, f32, f32)>,
) -> PointResult {
    let mut r = PointResult {
        pixel1: p1,
        pixel2: Pixel::new(p2[0], p2[1]),
        status: Status::Unbounded,
        ..PointResult::EMPTY
    };
    let Some((s, s_near, s_far)) = depths else {
        return r;
    };
    let z = s * iz;
    // (A NaN fails. Both flags rare: laid out of the usual point's way.)
    if !(z > 0.0) {
        core::hint::cold_path();
        r.status = Status::NonPositiveDepth;
        return r;
    }
    if z > pair.config.max_depth {
        core::hint::cold_path();
        r.status = Status::BeyondMaxDepth;
        return r;
    }
    // κ = 2Δ/q_z (Δ/q_z ≤ 1/2 by step 1), plus the rounding of `iz`.
    let kappa = 2.0 * pair.depth_scale_error * iz + 2.4e-7;
    let Some(stick) = interval(s_near, s_far, iz, kappa) else {
        return r;
    };
    r.z = z;
    r.z_near = stick.z_near;
    r.z_far = stick.z_far;
    r.status = Status::Ok;
    r
}
