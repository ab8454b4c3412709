//! Step 4's wedge path for pseudo-angle keys ([`match_wedge_angular`]),
//! its deferred refinement, and the band path for the points whose wedge
//! has no single copy of its key interval.

use super::lean::wedge_run_aside;
use super::*;

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
pub(super) fn match_wedge_angular<const N: usize, D: Deadline>(
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
    let mut rest = slots.iter_mut();
    while let Some(r) = rest.next() {
        if r.status != Status::NoIntersection {
            continue;
        }
        let (p1, iz, r1) = (r.pixel1, r.z, r.z_near);
        if !guard.proceed(work) {
            // The time is up: this point and the rest flagged in a loop of
            // their own (those left for the deferred refinement too).
            r.flag(Status::OverBudget);
            super::flag_pending(rest.into_slice());
            break;
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
                super::super::tests::ANGULAR.with(|c| c.set((c.get().0, c.get().1 + 1)));
                *r = band_point((pair, keying, near_foe), r, b2, index, work);
                continue;
            }
        };
        #[cfg(test)]
        super::super::tests::ANGULAR.with(|c| c.set((c.get().0 + 1, c.get().1)));
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
/// point it concluded has a clean result, `z_near` 0 where it is
/// `no_intersection`; one it flagged `over_budget` may keep step 1's
/// values, [`PointResult::flag`], but not the status) and the piece's end
/// in `z_far`. Each gets its wedge's
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
            r.flag(Status::OverBudget);
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
pub(super) enum AngularPoint {
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
pub(super) fn angular_wedge(
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
