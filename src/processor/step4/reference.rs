//! The references of step 4's wedge paths (behind the private
//! `_reference` feature): every segment offered in order, no key filter,
//! no work budget.

use super::angular::{angular_wedge, AngularPoint};
use super::*;

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
pub(super) fn match_wedge_angular_reference<const N: usize>(
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

/// The wedge path's reference: every segment offered to the walk, with
/// the interval the index would hold ([`raw_interval`]), no work budget.
#[cfg_attr(not(any(test, feature = "_reference")), allow(dead_code))]
#[inline(never)]
pub(super) fn match_wedge_reference(
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
