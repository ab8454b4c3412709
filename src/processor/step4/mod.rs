//! Step 4 of the per-frame call ([`super`]): **match** every point that
//! steps 1–3 left, against the indexed frame-2 boundary.
//!
//! Moving forwards without a translation error, a point's error band is
//! replaced by the wedge that holds it ([`crate::wedge`]), searched through
//! the index's lean view: [`lean`] for half-plane keys
//! ([`match_wedge_lean`]: its walks, with the index's aside entries merged
//! in or tested first, and a loose index's block tree), [`angular`] for
//! pseudo-angle keys ([`match_wedge_angular`]: the index's one copy of the
//! wedge's interval). Every other point, and those of the angular path
//! without a single copy, take the general band path ([`band`],
//! [`match_point`]; [`crate::depth`], [`crate::matching`]). Each path has
//! its reference ([`mod@reference`]: every segment offered in order, behind
//! the private `_reference` feature), and all end in the same depth and
//! stick ([`finish_point`]). This module dispatches ([`match_boundary`])
//! and holds what all of them end with.

use super::*;
use crate::deadline::{Deadline, Guard};

mod angular;
mod band;
mod lean;
mod reference;

use angular::match_wedge_angular;
use band::match_point;
use lean::match_wedge_lean;
#[cfg(test)]
pub(super) use lean::wedge_run_aside;
use reference::{match_wedge_angular_reference, match_wedge_reference};

/// Step 4 for every point of a boundary left by steps 1–2. (Out of line,
/// with the loop inside: the frame's constants stay in registers.)
/// With `counting` (the counting rule, [`super::Processor::set_fold_counting`];
/// `checking` the tests' switch of the loops' forms; `thinned` whether
/// `b2` was thinned, [`crate::thin`]) the points the rule gives back are
/// searched afterwards ([`super::counted::counted_search`]).
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
    (counting, checking, thinned): (bool, bool, bool),
) {
    match_points(
        pair,
        keying,
        near_foe,
        (&mut *slots, b2),
        index,
        (&mut *work, &mut *guard),
        matcher,
    );
    if !counting || !super::counted::applies(pair, keying) {
        return;
    }
    if guard.has_expired() {
        // The time ran out in the search: the rule does not run, and every
        // point that folds is one it might have searched (one pass; until a
        // tenth review the rule's own entry looked for a folded point first,
        // a pass more after the yes: 40 747 late with the rule on at 2 × 512).
        crate::fold::unsearched(slots);
    } else {
        super::counted::counted_search(
            (pair, keying),
            (slots, b2),
            index,
            (work, guard),
            (matcher, checking, thinned),
        );
    }
}

/// [`match_boundary`]'s search of every point still to be matched.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn match_points<const N: usize, D: Deadline>(
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
    if !crate::deadline::never::<D>()
        && matcher == Matcher::Indexed
        && matches!(keying.pencil, Pencil::Half { .. })
    {
        // Under a deadline: the radial levels the band queries use built
        // before the first point's search, not inside it, the clock asked
        // before and during the build (between parts of `CHUNK` blocks).
        let mut ask = || guard.check();
        if !ask() {
            index.build_radial_once(b2, &mut Some(&mut ask));
        }
        if guard.has_expired() {
            flag_pending(slots);
            *work = credit;
            return;
        }
    }
    let mut rest = slots.iter_mut();
    while let Some(r) = rest.next() {
        if r.status == Status::NoIntersection {
            if matcher == Matcher::Reference || guard.proceed(&mut credit) {
                *r = match_point(pair, keying, near_foe, r, b2, index, &mut credit, matcher);
            } else {
                // The time is up: this point and the rest flagged in a
                // loop of their own, out of this one's way.
                r.flag(Status::OverBudget);
                flag_pending(rest.into_slice());
                break;
            }
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

/// Every point still to be matched flagged [`Status::OverBudget`], once
/// the caller's deadline has expired ([`crate::deadline`]): a status a
/// point ([`PointResult::flag`]), step 1's values left in the bytes the
/// result does not give (no later pass reads them: the boundary's steps
/// end here).
#[cold]
#[inline(never)]
pub(super) fn flag_pending(slots: &mut [PointResult]) {
    for r in slots
        .iter_mut()
        .filter(|r| r.status == Status::NoIntersection)
    {
        r.flag(Status::OverBudget);
    }
}

/// Every point still to be matched given a clean
/// [`Status::NoIntersection`] (frame 2 lacks the boundary): step 1's
/// values cleared, since a `no_intersection` slot with `r₁ > 0` in its
/// `z_near` is what the passes over a boundary take for a point still to
/// be matched (the fold test, `refine_deferred`); a later pass over the
/// whole frame would take these for such. (Kept clean when the flags
/// after a deadline became a status, by a review of that change.)
#[cold]
#[inline(never)]
pub(super) fn unmatched(slots: &mut [PointResult]) {
    for r in slots
        .iter_mut()
        .filter(|r| r.status == Status::NoIntersection)
    {
        *r = PointResult::flagged(r.pixel1, Status::NoIntersection);
    }
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
    // κ = 2Δ/q_z (Δ/q_z ≤ ½ − 2⁻²⁰ by step 1, `HALF_KAPPA_MAX`), plus the
    // rounding of `iz`: below 1, so `1 − κ` keeps the near end's sign.
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
