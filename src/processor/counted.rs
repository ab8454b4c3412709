//! The counting rule for folded points ([`Processor::set_fold_counting`],
//! `src/fold/count.rs`, `docs/TESTS.md`, "The counting rule"), the
//! processor's side: after a boundary's search, step 1's values again, both
//! indexes again, the partners and images, and the points given back
//! searched as every other point was. (Out of line after the usual steps:
//! `docs/PERFORMANCE.md`, "The counting rule for folded points: where its
//! code could go".)

use super::*;

/// Items of the rule's passes over frame 1's points between two questions
/// to the clock: a quarter of [`CHUNK`], as each item compensates its
/// point again ([`recompensate`], about 100 instructions where step 1 is
/// certified, more where not) and a rebuild whose keys are not all there
/// pushes each item on its slow path (about 120 more). (Until a
/// thirteenth review these passes asked every [`CHUNK`] items, and the
/// fold test's rebuild not before its first part: the first pass's last
/// part and the rebuild's first ran between two questions, 23 687
/// instructions on a review's pair, 34 449 late.)
const RULE_CHUNK: usize = CHUNK / 4;

/// Step 1's values of the frame-1 point `p1`, as step 1 computed them
/// ([`compensate_all_certified`] on a certified pair, [`compensate_point`]
/// otherwise) with its key's margin: `None` where step 1 would have
/// flagged it.
fn recompensate(pair: &Pair, keying: &Keying, p1: Pixel) -> Option<(PointResult, f32)> {
    match (pair.certified_r1, keying.pencil) {
        (Some(r1), Pencil::Half { foe, side, min_t }) => {
            let stretch = pair.geom.frame_stretch().unwrap_or(0.0);
            let c = pair.geom.compensate_certified(p1, stretch);
            let (k, e) = half_key(c.pixel, (foe, side, min_t), keying.key_scale);
            let r = PointResult {
                pixel1: p1,
                pixel2: Pixel::new(c.pixel[0], c.pixel[1]),
                z: c.inv_depth_scale,
                z_near: r1,
                z_far: k,
                status: Status::NoIntersection,
            };
            Some((r, e))
        }
        _ => {
            let mut r1_max = 0.0;
            compensate_point(pair, keying, p1, &mut r1_max)
                .ok()
                .map(|(r, (_, e))| (r, e))
        }
    }
}

/// Whether the counting rule applies to the pair's boundary: the lean
/// wedge path (half-plane keys, moving forwards without a translation
/// error). Elsewhere a point the fold test flags stays
/// [`Status::Folded`], the rule on or off.
#[inline(always)]
pub(super) fn applies(pair: &Pair, keying: &Keying) -> bool {
    matches!(keying.pencil, Pencil::Half { .. }) && step4::wedge_path(pair)
}

/// The counting rule ([`Processor::set_fold_counting`]) for one boundary,
/// after its search, where it [`applies`] (the lean wedge path: half-plane
/// keys, moving forwards without a translation error) and a point was
/// flagged [`Status::Folded`]: step 1's values again ([`recompensate`]:
/// the same arithmetic) for the fold test's index of the boundary and for
/// each point that folds, their partners ([`crate::fold::partners`]), the
/// frame-2 index again, the points the rule gives back
/// ([`crate::fold::images`]) searched as every other point was, and every
/// point that folds given its flag ([`crate::fold::settle`]). (Out of
/// line, after the usual steps, which stay as they were; it asks the
/// clock and spends units as they do.)
#[cold]
#[inline(never)]
pub(super) fn counted_search<const N: usize, D: Deadline>(
    (pair, keying): (&Pair, &Keying),
    (slots, b2): (&mut [PointResult], &[Pixel]),
    index: &mut Index<N>,
    (work, guard): (&mut Work, &mut Guard<'_, D>),
    (matcher, checking, thinned): (Matcher, bool, bool),
) {
    let Pencil::Half { foe, side, min_t } = keying.pencil else {
        return;
    };
    // (Its one caller, `match_boundary`, runs it only where it
    // [`applies`].)
    if !slots.iter().any(|r| r.status == Status::Folded) {
        return;
    }
    // What the usual steps had: the keys' orientation, the largest `r₁`.
    let orient = orientation(keying, b2.first(), b2.last());
    let mut r1_max = 0.0f32;
    // Each pass over the boundary in parts of `RULE_CHUNK` items (of
    // `CHUNK` over frame 2's), the clock asked before each part, the
    // first included (as every such pass of the usual steps); once it
    // says yes the rule stops, its points `over_budget`.
    // Step 1's margins, and its values for the points that fold.
    let margins = index.margins_mut();
    for i in 0..slots.len() {
        if i % RULE_CHUNK == 0 && guard.check() {
            // (Before the partners' pass: no standings to settle by.)
            crate::fold::unsearched(slots);
            return;
        }
        let (Some(r), Some(m)) = (slots.get_mut(i), margins.get_mut(i)) else {
            break;
        };
        let c = recompensate(pair, keying, r.pixel1);
        *m = c.map_or(0.0, |(_, e)| e);
        if let Some((c, _)) = c {
            r1_max = crate::math::fmax(r1_max, c.z_near);
        }
        if r.status == Status::Folded {
            // (Step 1 kept every point the fold test looked at; one it
            // would not keep now, which cannot happen, stays `folded`.)
            *r = match c {
                Some((c, _)) => PointResult {
                    status: Status::Folded,
                    ..c
                },
                None => PointResult {
                    z_far: f32::NAN,
                    ..*r
                },
            };
        }
    }
    // The fold test's index again, from step 1's keys.
    let key = |r: &PointResult| match r.status {
        Status::Folded if r.z_far.is_finite() => r.z_far,
        Status::Folded => NO_KEY,
        _ => recompensate(pair, keying, r.pixel1).map_or(NO_KEY, |(c, _)| c.z_far),
    };
    let mut builder = index.builder((keying.period, orient), Unkeyed::MeetNone);
    let mut stopped = false;
    for part in slots.chunks(RULE_CHUNK) {
        if guard.check() {
            stopped = true;
            break;
        }
        builder.push_all_stored(part.iter().map(key));
    }
    let mut ask = || guard.check();
    let mut tick: Tick = if crate::deadline::never::<D>() {
        None
    } else {
        Some(&mut ask)
    };
    if stopped || !builder.finish(None, &mut tick) {
        crate::fold::unsearched(slots);
        return;
    }
    let at = |p: Pixel| recompensate(pair, keying, p).map(|(c, _)| c.pixel2.arr());
    let e2 = pair.e2();
    match crate::fold::partners(index, slots, at, (foe, e2), work, guard) {
        // The time ran out in the pass: its points settled there (no
        // frame-2 index either).
        None => return,
        // No point has a partner: nothing to look for in frame 2.
        Some(false) => {
            crate::fold::settle(slots, guard.has_expired());
            return;
        }
        Some(true) if guard.has_expired() => {
            crate::fold::settle(slots, true);
            return;
        }
        Some(true) => {}
    }
    // The frame-2 index again (its block tree built at once: the tree the
    // walks would build), and the points given back searched.
    let ks = keying.key_scale;
    let mut builder = index
        .builder((keying.period, orient), Unkeyed::MeetAll)
        .uneven(thinned);
    for part in b2.chunks(CHUNK) {
        if guard.check() {
            stopped = true;
            break;
        }
        let pencil = (foe, side, min_t);
        if checking {
            builder.push_all(part.iter().map(|p| half_key(p.arr(), pencil, ks)));
        } else {
            builder.push_all_bounded(part, |p| half_key_or_none(p.arr(), pencil, ks));
        }
    }
    let mut ask = || guard.check();
    let mut tick: Tick = if crate::deadline::never::<D>() {
        None
    } else {
        Some(&mut ask)
    };
    if stopped || !builder.finish(None, &mut tick) {
        crate::fold::settle(slots, true);
        return;
    }
    let near_foe = pair.near_foe(r1_max);
    // (The search of `match_boundary` without its tail, this function: no
    // recursion, so the matcher the per-frame call passes stays a constant
    // the compiler can see, and the reference walks stay out of the
    // firmware.)
    let search = |one: &mut [PointResult],
                  index: &mut Index<N>,
                  work: &mut Work,
                  guard: &mut Guard<'_, D>| {
        step4::match_points(
            pair,
            keying,
            near_foe,
            (one, b2),
            index,
            (work, guard),
            matcher,
        );
    };
    let e = (keying, foe, e2);
    crate::fold::images(index, slots, b2, e, (&mut *work, &mut *guard), search);
    crate::fold::settle(slots, guard.has_expired());
}
