//! Step 2 of the per-frame call ([`crate::processor`]): the **fold test**.
//!
//! A compensated frame-1 point *folds* when its own epipolar line, the ray
//! from the FOE through it, meets the compensated frame-1 polyline again
//! away from it: then a frame-2 crossing on that line may belong to the
//! other place (a wrong match no two-view test could tell from a right
//! one), and the point is flagged [`Status::Folded`] (the certification's
//! "without a correspondent" column counts what slips past it). In keys
//! ([`crate::pencil`]): vertex `i` folds when its widened key `[k − e, k +
//! e]` meets the key interval of a segment `j ≤ i − w − 1` or `j ≥ i + w`
//! (`w` = [`FOLD_WINDOW`]; segment `j` from vertex `j` to `j + 1`, its
//! interval the hull of its ends' widened keys, as the search index builds
//! it; a segment with an unkeyed end meets nothing here).
//!
//! One rule, decided the cheapest way the boundary allows, each giving the
//! brute force's answer, bit for bit and whichever orientation step 1
//! guessed (the third unless the work budget runs out first: then the
//! point is [`Status::OverBudget`]; or unless the index finds more copies
//! of a query of pseudo-angle keys than it handles, `crate::search`'s
//! `MAX_COPIES`: a polyline winding about three turns round the FOE, or,
//! where a copy's rounding meets the keys' range to the last bit, three
//! copies and a fourth counted that falls just short; then a fold is
//! assumed where a keyed segment lies outside the window):
//!
//! 1. The keys are strictly ordered along the polyline (step 1 tracks the
//!    order, [`KeyOrder`]): no key meets a segment but its own two, nothing
//!    folds.
//! 2. Every point has a key, without a period (half-plane or projective
//!    keys): the test from the keys alone, `O(1)` per point, no index, no
//!    work ([`folds_by_hulls`]).
//! 3. Otherwise (a point without a key breaks the polyline's chain of
//!    intervals; pseudo-angle keys repeat every turn): the polyline is
//!    indexed ([`crate::search`]) and each point the envelopes cannot clear
//!    is queried, each segment looked at paid from the frame's work budget
//!    ([`Status::OverBudget`] when it runs out).

mod count;

pub(crate) use count::{cut_short, images, partners, settle, unsearched};

use crate::deadline::{Deadline, Guard};
use crate::math::{fmax, fmin};
use crate::pencil::NO_KEY;
use crate::search::{Index, KeyOrder, OutOfWork, Tick, Unkeyed, Work, CHUNK};
use crate::structure::{PointResult, Status, FOLD_WINDOW};

/// Step 2 for one boundary's points in `slots` (step 1's results: a point
/// still to be matched holds its raw key in `z_far`, its margin in the
/// index's margins), whose key order step 1 tracked in `order` (`pushed`:
/// how many points it took, [`KeyOrder::push_until_settled`]), keys of
/// the given `period` and likely orientation `orient` (`bounded`: every
/// point is still to be matched, its key [`NO_KEY`] or finite with a finite
/// margin ≥ 0, half-plane keys of a certified step 1); each point brings
/// `allowance` units to `work`. Flags the points that fold; a point rule 3
/// would query once `guard`'s deadline has expired is
/// [`Status::OverBudget`].
///
/// (Out of line: the fold test's passes compiled into the caller changed
/// the registers of step 1's loop there whenever they changed, `docs/PERFORMANCE.md`,
/// "A strict tail in the fold test".)
#[inline(never)]
pub(crate) fn step<const N: usize, D: Deadline>(
    index: &mut Index<N>,
    slots: &mut [PointResult],
    (order, pushed, period, orient, bounded): (&KeyOrder, usize, f32, f32, bool),
    allowance: u32,
    work: &mut Work,
    guard: &mut Guard<'_, D>,
) {
    let n = u32::try_from(slots.len()).unwrap_or(u32::MAX);
    if order.strict(period) {
        // No key meets a segment but its own two: nothing folds.
        work.grant(allowance.saturating_mul(n));
        return;
    }
    if period <= 0.0 {
        let margins = index.margins();
        let hulls = if bounded {
            // The points before the one that settled the order are keyed
            // and their widened keys strictly ordered one way (bounded
            // keys: all are valid, each keyed with a finite margin ≥ 0),
            // where there are two or more of them (a lead of 1 may be an
            // unkeyed point 0; `by_hulls` takes a lead longer than the
            // window + 1 only).
            let lead = if order.settled() {
                pushed.saturating_sub(1)
            } else {
                0
            };
            by_hulls::<true>(slots, margins, lead, || guard.check())
        } else {
            by_hulls::<false>(slots, margins, 0, || guard.check())
        };
        match hulls {
            Hulls::Decided => {
                work.grant(allowance.saturating_mul(n));
                return;
            }
            // Out of time: the caller flags the points left.
            Hulls::Stopped => return,
            Hulls::Undecided => {}
        }
    }
    let mut fold_index = index.builder((period, orient), Unkeyed::MeetNone);
    let key = |r: &PointResult| {
        if r.status == Status::NoIntersection {
            r.z_far
        } else {
            NO_KEY
        }
    };
    if crate::deadline::never::<D>() {
        fold_index.push_all_stored(slots.iter().map(key));
    } else {
        // Under a deadline, in parts of `CHUNK` points with the clock
        // asked between them (out of time: the caller flags the points
        // left).
        for (c, part) in slots.chunks(CHUNK).enumerate() {
            if c > 0 && guard.check() {
                return;
            }
            fold_index.push_all_stored(part.iter().map(key));
        }
    }
    let mut ask = || guard.check();
    let mut tick: Tick = if crate::deadline::never::<D>() {
        None
    } else {
        Some(&mut ask)
    };
    if !fold_index.finish(None, &mut tick) {
        return;
    }
    by_index(index, slots, allowance, work, guard);
}

/// Rule 3: the query on the index of the compensated frame-1 polyline
/// built from step 1's keys (points flagged there have none). Each point
/// brings its allowance to the frame's work budget here.
fn by_index<const N: usize, D: Deadline>(
    index: &mut Index<N>,
    slots: &mut [PointResult],
    allowance: u32,
    work: &mut Work,
    guard: &mut Guard<'_, D>,
) {
    if index.strict() {
        // No key meets a segment but its own two: nothing folds.
        let n = u32::try_from(slots.len()).unwrap_or(u32::MAX);
        work.grant(allowance.saturating_mul(n));
        return;
    }
    index.folds_all(
        slots,
        (FOLD_WINDOW, allowance),
        work,
        |w: Option<&mut Work>| match w {
            Some(w) => guard.proceed(w),
            None => !guard.check(),
        },
        |r| (r.status == Status::NoIntersection && r.z_far.is_finite()).then_some(r.z_far),
        |r, folds| match folds {
            Err(OutOfWork) => *r = PointResult::flagged(r.pixel1, Status::OverBudget),
            Ok(true) => *r = PointResult::flagged(r.pixel1, Status::Folded),
            Ok(false) => {}
        },
    );
}

/// What [`folds_by_hulls`] came to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Hulls {
    /// Every item tested.
    Decided,
    /// An item has no key (nothing changed): the index decides.
    Undecided,
    /// The caller's clock said the time is up: the items marked so far
    /// fold, the others are untested.
    Stopped,
}

/// Rule 2 on the processor's slots ([`folds_by_hulls`], `expired` its
/// clock); [`Hulls::Undecided`], with nothing changed, when a point has no
/// key. The points marked are flagged (also when the clock stopped the
/// test: they do fold).
fn by_hulls<const BOUNDED: bool>(
    slots: &mut [PointResult],
    margins: &[f32],
    lead: usize,
    expired: impl FnMut() -> bool,
) -> Hulls {
    let valid = |r: &PointResult| r.status == Status::NoIntersection;
    // Marked points keep their key (`z_far`) until both passes are done.
    let mark = |r: &mut PointResult| r.status = Status::Folded;
    let unmark = |r: &mut PointResult| r.status = Status::NoIntersection;
    let hulls = folds_by_hulls::<_, BOUNDED>(
        slots,
        margins,
        (FOLD_WINDOW, lead),
        (valid, |r| r.z_far),
        (mark, unmark),
        expired,
    );
    if hulls == Hulls::Undecided {
        return hulls;
    }
    for r in slots.iter_mut().filter(|r| r.status == Status::Folded) {
        *r = PointResult::flagged(r.pixel1, Status::Folded);
    }
    hulls
}

/// The fold test ([`Index::folds`]'s answer) of every vertex of a
/// polyline whose vertices all have a key (no period), straight from the
/// keys: no index, no work. Item `i` is vertex `i`; `valid` says whether it is to be
/// tested (it has a key, and `mark` has not marked it), `key` gives its
/// raw key (read whatever `mark` did to it), `margins[i]` its margin;
/// `mark` gets every item that folds, once. Returns `false` when there are
/// fewer margins than items, or an item is not valid, or its margin is not
/// a number `≥ 0`, or its `k + e` is not finite (its key is not, or the sum
/// overflows): then the items marked so far get `unmark` (which must make
/// them valid again) and the index decides ([`Index::folds_all`]):
/// [`Hulls::Undecided`]. `expired` (the caller's clock) is asked before
/// every [`CHUNK`] items of each pass: once it says yes the test stops,
/// [`Hulls::Stopped`], the items marked so far marked (they fold: each
/// pass marks only those that do). `BOUNDED`: the caller knows every item
/// valid and its key [`NO_KEY`] or finite with a finite margin `≥ 0`
/// (then an item passes those checks exactly when its key is not
/// `NO_KEY`, which is all the forward pass asks); with it, `lead` (else
/// ignored): items `0 .. lead` are keyed and their widened keys strictly
/// ordered one way (each wholly above the one before, or each wholly
/// below: step 1's key order, [`KeyOrder::push_until_settled`]), so the
/// forward pass marks none of them and its hull there is that of the
/// lead's first and last vertices before the window, where it starts.
/// Also with `BOUNDED`: a **strict tail**, the longest run of keyed items
/// ending the polyline whose widened keys are strictly ordered one way
/// (found by a scan from the end, [`strict_tail`]; taken when it holds
/// [`TAIL_MIN`] items or more): the forward pass stops in it at the first
/// item wholly beyond its hull (every later one is too). Measured on the
/// representative pair, where one boundary's keys are strictly ordered from
/// its 21st point on: 648 → 642 instructions a point.
///
/// Vertex `i` folds when its widened key `[k − e, k + e]` meets the
/// interval of a segment `j ≤ i − w − 1` or `j ≥ i + w` (segment `j` from
/// vertex `j` to `j + 1`, its interval the hull of its ends' widened keys,
/// `search::Builder`). Consecutive segments share a vertex, so both
/// intervals hold its (non-empty) widened key, and the union of the intervals of a
/// run of consecutive segments is one interval: the hull of the widened
/// keys of the run's vertices (by induction along the run). So the vertex
/// folds exactly when its widened key meets the hull of vertices `0 ..= i
/// − w` (for `i ≥ w + 1`: the run before the window has a segment) or of
/// vertices `i + w ..= n − 1` (for `i + w ≤ n − 2`): a segment it meets
/// lies in the hull; and where it meets the hull, at some value `x`, `x`
/// lies in the interval of one of the run's segments (their union covers
/// every value between its ends), which therefore meets it. A forward
/// pass keeps the first hull, a backward pass the second: `O(1)` per
/// vertex. Orientation does not matter (negating every key negates every
/// interval exactly); `folds_by_hulls_equals_brute_force` compares it
/// with the segments' brute force.
fn folds_by_hulls<T, const BOUNDED: bool>(
    items: &mut [T],
    margins: &[f32],
    (w, lead): (usize, usize),
    (valid, key): (impl Fn(&T) -> bool, impl Fn(&T) -> f32),
    (mut mark, mut unmark): (impl FnMut(&mut T), impl FnMut(&mut T)),
    mut expired: impl FnMut() -> bool,
) -> Hulls {
    let n = items.len();
    if margins.len() < n {
        return Hulls::Undecided;
    }
    let widened = |items: &[T], i: usize| match (items.get(i), margins.get(i)) {
        (Some(it), Some(&e)) => {
            let k = key(it);
            (k - e, k + e)
        }
        _ => (f32::INFINITY, f32::NEG_INFINITY),
    };
    let join = |(a, b): (f32, f32), (c, d): (f32, f32)| (fmin(a, c), fmax(b, d));
    let meets = |(lo, hi): (f32, f32), (ulo, uhi): (f32, f32)| lo <= uhi && hi >= ulo;
    // The strict tail (`BOUNDED` only): items `tail ..= n − 1` keyed and
    // their widened keys strictly ordered one way (`up`: each wholly above
    // the one before), the longest such run that ends the polyline (`tail
    // = n`: none of two items or more). Found by a scan from the end; its
    // items fold backward never (the hull of items `i + w ..` lies wholly
    // beyond item `i`), and forward not past the first that lies wholly
    // beyond its hull.
    let (tail, up) = if BOUNDED {
        let at = |i: usize| match (items.get(i), margins.get(i)) {
            (Some(it), Some(&e)) => {
                let k = key(it);
                (k != NO_KEY).then_some((k - e, k + e))
            }
            _ => None,
        };
        match (n.checked_sub(2), n.checked_sub(1).and_then(at)) {
            (Some(t), Some(last)) => match at(t) {
                Some(w0) if last.0 > w0.1 => {
                    let Some(t) =
                        strict_tail::<_, true>(items, margins, &key, (t, w0), &mut expired)
                    else {
                        return Hulls::Stopped;
                    };
                    (t, true)
                }
                Some(w0) if last.1 < w0.0 => {
                    let Some(t) =
                        strict_tail::<_, false>(items, margins, &key, (t, w0), &mut expired)
                    else {
                        return Hulls::Stopped;
                    };
                    (t, false)
                }
                _ => (n, true),
            },
            _ => (n, true),
        }
    } else {
        (n, true)
    };
    // (A tail of fewer than [`TAIL_MIN`] items is not taken: the passes
    // then run as without one, which their plain loops do for less. Nor
    // is one with a window of 0, where an item's own key is in its hull
    // and the tail's first `stop` would be the item before it.)
    let tail = if w > 0 && tail.saturating_add(TAIL_MIN) <= n {
        #[cfg(test)]
        tests::TAILS.with(|c| c.set(c.get() + 1));
        tail
    } else {
        n
    };
    let stop = if tail < n {
        tail.saturating_add(w).saturating_sub(1)
    } else {
        usize::MAX
    };
    // Forward: each item checked as it comes (valid, its margin a number
    // ≥ 0, `k + e` finite: then `k − e ≤ k + e`, the low end perhaps −∞,
    // as the index computes it too), the hull of vertices 0 ..= i − w, the
    // test from i = w + 1 on.
    // From item `from` on, with the hull of items `0 ..= from − w − 1`
    // (the loop written four times below: the plain pass from 0, as it
    // was, and the pass after a lead, which knows `from > w + 1`, each to
    // the end or to a strict tail's `stop`: a variable end in the plain
    // loops measured dearer on the demo's frames).
    macro_rules! forward {
        ($from:expr, $hull:expr, $end:expr) => {{
            let mut hull = $hull;
            for i in $from..$end {
                if i % CHUNK == CHUNK - 1 && expired() {
                    return Hulls::Stopped;
                }
                let e = margins.get(i).copied().unwrap_or(f32::NAN);
                let checked = if BOUNDED {
                    // (Every item valid, each key NO_KEY or finite with a
                    // finite margin ≥ 0: the test below, asked that way.)
                    items.get(i).map(&key).filter(|&k| k != NO_KEY)
                } else {
                    // (A NaN fails.)
                    // (`k + e` finite with `e ≥ 0`: both finite, and no
                    // overflow.)
                    let checked = items.get(i).filter(|&it| valid(it)).map(&key);
                    checked.filter(|k| e >= 0.0 && (k + e).is_finite())
                };
                let Some(wi) = checked else {
                    // Undo: every item before `i` was valid, so those
                    // that are no longer are the ones marked here.
                    for it in items.iter_mut().take(i).filter(|it| !valid(it)) {
                        unmark(it);
                    }
                    return Hulls::Undecided;
                };
                let wi = (wi - e, wi + e);
                if let Some(v) = i.checked_sub(w) {
                    hull = join(hull, widened(items, v));
                }
                if i > w && meets(wi, hull) {
                    if let Some(it) = items.get_mut(i) {
                        mark(it);
                    }
                }
            }
            hull
        }};
    }
    let none = (f32::INFINITY, f32::NEG_INFINITY);
    let (end, mut hull) = if BOUNDED && lead > w.saturating_add(1) && lead <= n {
        // A strictly ordered lead: its item `i > w` lies wholly beyond the
        // hull of items `0 ..= i − w` (each widened key is non-empty, so
        // both ends move strictly one way), which `fmin` and `fmax` make
        // from the first and the last of them, bit for bit; the pass
        // starts after the lead with that hull.
        let first = join(none, widened(items, 0));
        let hull = join(first, widened(items, lead - 1 - w));
        if tail < n {
            let end = stop.max(lead).min(n);
            (end, forward!(lead, hull, end))
        } else {
            (n, forward!(lead, hull, n))
        }
    } else if tail < n {
        let end = stop.min(n);
        (end, forward!(0, none, end))
    } else {
        (n, forward!(0, none, n))
    };
    // The strict tail's items from `end` (≥ `stop`) on: keyed, their test
    // the forward pass's, until the first that lies wholly beyond its hull
    // (on the tail's side): every later item does too (the hull takes
    // only tail items before it, each wholly before it), so none of them
    // folds forward.
    for i in end..n {
        if i % CHUNK == CHUNK - 1 && expired() {
            return Hulls::Stopped;
        }
        let wi = widened(items, i);
        if let Some(v) = i.checked_sub(w) {
            hull = join(hull, widened(items, v));
        }
        if if up { wi.0 > hull.1 } else { wi.1 < hull.0 } {
            break;
        }
        if i > w && meets(wi, hull) {
            if let Some(it) = items.get_mut(i) {
                mark(it);
            }
        }
    }
    // Backward: the hull of vertices i + w ..= n − 1, tested for
    // i + w ≤ n − 2, that is i < n − w − 1: it starts as vertex n − 1 alone
    // and takes vertex i + w (< n − 1) at each tested i.
    let tested = n.saturating_sub(w.saturating_add(1));
    if tested == 0 {
        return Hulls::Decided;
    }
    let mut hull = widened(items, n - 1);
    for i in (0..tested).rev() {
        if i % CHUNK == 0 && expired() {
            return Hulls::Stopped;
        }
        hull = join(hull, widened(items, i + w));
        // (An item the forward pass marked is no longer `valid`.)
        if items.get(i).is_some_and(&valid) && meets(widened(items, i), hull) {
            if let Some(it) = items.get_mut(i) {
                mark(it);
            }
        }
    }
    Hulls::Decided
}

/// The shortest strict tail [`folds_by_hulls`] takes (items).
const TAIL_MIN: usize = 32;

/// The first item of the strict tail [`folds_by_hulls`] takes (`BOUNDED`
/// keys, `NO_KEY` with margin 0 or finite): from item `t`, whose widened
/// key is `(plo, phi)`, back while each item's widened key lies wholly
/// below (`UP`) or above the next one's; `None` when `expired` (asked
/// before every [`CHUNK`] items) said the time is up.
#[inline(never)]
fn strict_tail<T, const UP: bool>(
    items: &[T],
    margins: &[f32],
    key: &impl Fn(&T) -> f32,
    (mut t, (mut plo, mut phi)): (usize, (f32, f32)),
    expired: &mut impl FnMut() -> bool,
) -> Option<usize> {
    let m = items.len().min(margins.len()).min(t);
    let (Some(its), Some(ms)) = (items.get(..m), margins.get(..m)) else {
        return Some(t);
    };
    for (i, (it, &e)) in its.iter().zip(ms).enumerate().rev() {
        if i % CHUNK == CHUNK - 1 && expired() {
            return None;
        }
        let k = key(it);
        let (lo, hi) = (k - e, k + e);
        // (An unkeyed item, `NO_KEY = +∞` with margin 0: its `hi` fails
        // the first test; the second needs its own.)
        let strict = if UP {
            plo > hi
        } else {
            phi < lo && k != NO_KEY
        };
        if !strict {
            break;
        }
        (t, plo, phi) = (i, lo, hi);
    }
    Some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::search::tests::{intervals, keys, meets, CAP};
    use crate::test_rng::Rng;
    extern crate std;
    use std::vec::Vec;

    std::thread_local! {
        /// Strict tails [`folds_by_hulls`] took on this thread.
        pub(super) static TAILS: core::cell::Cell<usize> = const { core::cell::Cell::new(0) };
    }

    /// The fold test straight from the keys ([`folds_by_hulls`]) equals
    /// the brute force over the segments on every key sequence with all
    /// vertices keyed and no period, and declines the others.
    #[test]
    fn folds_by_hulls_equals_brute_force() {
        let mut rng = Rng(0xf01d_0003);
        let (w, mut taken, mut cuts, mut leads) = (4, 0, 0, 0);
        for case in 0..3000 {
            let shape = case % 5;
            let n = 1 + (rng.next() * (CAP - 1) as f32) as usize;
            let mut ks = keys(&mut rng, shape, n, false);
            // Most cases with every vertex keyed.
            if case % 4 != 0 {
                for k in ks.iter_mut().filter(|k| !k.0.is_finite()) {
                    *k = (rng.next(), 1.0e-5);
                }
            }
            let ivs = intervals(&ks, false);
            let margins: Vec<f32> = ks.iter().map(|k| k.1).collect();
            // (raw key, marks).
            let mut items: Vec<(f32, u32)> = ks.iter().map(|k| (k.0, 0)).collect();
            let valid = |it: &(f32, u32)| it.0.is_finite() && it.1 == 0;
            let marks = (
                |it: &mut (f32, u32)| it.1 += 1,
                |it: &mut (f32, u32)| it.1 -= 1,
            );
            // Stopped by a clock after `q` questions first: every item
            // marked then folds (the brute force's answer, below).
            let q = case % 7;
            let mut asked = 0;
            let clock = || {
                asked += 1;
                asked > q
            };
            let mut cut = items.clone();
            let stopped = folds_by_hulls::<_, false>(
                &mut cut,
                &margins,
                (w, 0),
                (valid, |it| it.0),
                marks,
                clock,
            );
            // The items here are valid but where the key is NO_KEY, their
            // keys small and margins ≥ 0: the bounded test is the same.
            let mut bounded = items.clone();
            let took_bounded = folds_by_hulls::<_, true>(
                &mut bounded,
                &margins,
                (w, 0),
                (valid, |it| it.0),
                marks,
                || false,
            );
            // With the lead step 1's key order gives (`step`): the same.
            let mut order = KeyOrder::NEW;
            let pushed = order.push_until_settled::<true>(ks.iter().copied());
            let lead = if order.settled() {
                pushed.saturating_sub(1)
            } else {
                0
            };
            leads += usize::from(lead > w + 1 && lead < n);
            let mut led = items.clone();
            let took_led = folds_by_hulls::<_, true>(
                &mut led,
                &margins,
                (w, lead),
                (valid, |it| it.0),
                marks,
                || false,
            );
            let took = folds_by_hulls::<_, false>(
                &mut items,
                &margins,
                (w, 0),
                (valid, |it| it.0),
                marks,
                || false,
            );
            assert_eq!(took, took_bounded, "case {case}: bounded");
            assert_eq!(items, bounded, "case {case}: bounded");
            assert_eq!(took, took_led, "case {case}: lead {lead}");
            assert_eq!(items, led, "case {case}: lead {lead}");
            let took = took == Hulls::Decided;
            let brute = |i: usize, (k, e): (f32, f32)| {
                ivs.iter().enumerate().any(|(j, iv)| {
                    let outside = j + w < i || j > i + w - 1;
                    outside && iv.is_some_and(|iv| meets(iv, (k - e, k + e), false))
                })
            };
            if stopped == Hulls::Stopped {
                cuts += 1;
                for (i, (c, &k)) in cut.iter().zip(&ks).enumerate() {
                    assert!(
                        c.1 == 0 || brute(i, k),
                        "case {case}: vertex {i} marked by a stopped test, does not fold"
                    );
                }
            } else {
                assert_eq!(cut, items, "case {case}: not stopped, the same marks");
            }
            let all_keyed = ks.iter().all(|k| k.0.is_finite());
            assert_eq!(
                took, all_keyed,
                "case {case}: taken only with every vertex keyed"
            );
            if !took {
                assert!(
                    items.iter().all(|it| it.1 == 0),
                    "case {case}: marked when declined"
                );
                continue;
            }
            taken += 1;
            for (i, (&k, it)) in ks.iter().zip(&items).enumerate() {
                assert_eq!(
                    it.1,
                    u32::from(brute(i, k)),
                    "case {case} (shape {shape}) vertex {i} of {n}"
                );
            }
        }
        assert!(taken > 2000, "{taken} cases taken");
        assert!(cuts > 500, "{cuts} cases stopped");
        assert!(leads > 300, "{leads} cases with a lead");
        // A long rising lead, then keys falling back into the lead's first
        // intervals (only the hull of the whole lead, from its first
        // vertex, meets them): with the lead as without it.
        for back in [0.0f32, 0.05, 0.15, 0.3, 0.55, 0.9] {
            let e = 0.01;
            let mut ks: Vec<(f32, f32)> = (0..40).map(|i| (0.025 * i as f32, e)).collect();
            ks.extend((0..12).map(|i| (back + 0.002 * i as f32, e)));
            let margins: Vec<f32> = ks.iter().map(|k| k.1).collect();
            let items: Vec<(f32, u32)> = ks.iter().map(|k| (k.0, 0)).collect();
            let valid = |it: &(f32, u32)| it.0.is_finite() && it.1 == 0;
            let marks = (
                |it: &mut (f32, u32)| it.1 += 1,
                |it: &mut (f32, u32)| it.1 -= 1,
            );
            let mut order = KeyOrder::NEW;
            let pushed = order.push_until_settled::<true>(ks.iter().copied());
            assert!(
                order.settled() && pushed == 41,
                "back {back}: lead {pushed}"
            );
            let (mut plain, mut led) = (items.clone(), items);
            let got = folds_by_hulls::<_, true>(
                &mut plain,
                &margins,
                (w, 0),
                (valid, |it| it.0),
                marks,
                || false,
            );
            let got_led = folds_by_hulls::<_, true>(
                &mut led,
                &margins,
                (w, pushed - 1),
                (valid, |it| it.0),
                marks,
                || false,
            );
            assert_eq!((got, &led), (got_led, &plain), "back {back}");
            assert!(plain.iter().any(|it| it.1 > 0), "back {back}: some fold");
        }
        // A strictly ordered tail of `TAIL_MIN` items or more after a head
        // whose keys reach into it, rising or falling: the tail's first
        // items meet the head's hull and fold (the forward pass must mark
        // them before it stops), the head folds back onto the tail's start
        // (the backward pass from before the tail); an unkeyed item in
        // the tail (the tail after it only), and the clock stopping the
        // test. Bounded (which takes the tail) equals the plain test and
        // the brute force.
        let (mut tails, mut cut_in_tail) = (0, 0);
        let cases = [31usize, 32, 33, 40, 90]
            .into_iter()
            .flat_map(|len| [1.0f32, -1.0].map(|d| (len, d)))
            .flat_map(|(len, d)| [None, Some(len / 2), Some(len - 3)].map(|u| (len, d, u)))
            .flat_map(|c| [0.3f32, 1.0].map(|h| (c, h)))
            .flat_map(|c| [w, 1, 0].map(|ww| (c, ww)));
        for (case, (((len, dir, unkeyed), high), ww)) in cases.enumerate() {
            let e = 1.0e-3;
            // The head: a zig-zag over [0.1, high], then the tail from 0.2
            // up by 0.01 a vertex (its first items within the head's
            // range: 10 of them, or 80 with the high head).
            let mut ks: Vec<(f32, f32)> = (0..12)
                .map(|i| (if i % 2 == 0 { 0.1 } else { high } + 0.001 * i as f32, e))
                .collect();
            ks.extend((0..len).map(|i| (0.2 + 0.01 * i as f32, e)));
            for k in ks.iter_mut() {
                k.0 *= dir;
            }
            if let Some(u) = unkeyed {
                if let Some(k) = ks.get_mut(12 + u) {
                    *k = (NO_KEY, 0.0);
                }
            }
            let n = ks.len();
            let ivs = intervals(&ks, false);
            let brute = |i: usize, (k, e): (f32, f32)| {
                ivs.iter().enumerate().any(|(j, iv)| {
                    let outside = j + ww < i || j + 1 > i + ww;
                    outside && iv.is_some_and(|iv| meets(iv, (k - e, k + e), false))
                })
            };
            let margins: Vec<f32> = ks.iter().map(|k| k.1).collect();
            let items: Vec<(f32, u32)> = ks.iter().map(|k| (k.0, 0)).collect();
            let marks = (
                |it: &mut (f32, u32)| it.1 += 1,
                |it: &mut (f32, u32)| it.1 -= 1,
            );
            let (mut plain, mut bounded) = (items.clone(), items.clone());
            // The bounded form's items: every one valid (an unkeyed one
            // too, its key NO_KEY with margin 0), unmarked. The tail it
            // takes: the items after the unkeyed one, or all after the
            // head, if 32 or more, with a window.
            let taken = TAILS.with(|c| c.get());
            let got = folds_by_hulls::<_, true>(
                &mut bounded,
                &margins,
                (ww, 0),
                (|it: &(f32, u32)| it.1 == 0, |it| it.0),
                marks,
                || false,
            );
            let tail = unkeyed.map_or(len, |u| len - u - 1);
            assert_eq!(
                TAILS.with(|c| c.get()) - taken,
                usize::from(ww > 0 && tail >= TAIL_MIN),
                "case {case}: the tail of {tail} taken or not"
            );
            tails += TAILS.with(|c| c.get()) - taken;
            let want = folds_by_hulls::<_, false>(
                &mut plain,
                &margins,
                (ww, 0),
                (|it: &(f32, u32)| it.0.is_finite() && it.1 == 0, |it| it.0),
                marks,
                || false,
            );
            assert_eq!((got, &bounded), (want, &plain), "case {case}");
            if unkeyed.is_some() {
                // Both decline an unkeyed item (the index decides), the
                // bounded one too although the tail after it is strict:
                // nothing marked.
                assert_eq!(got, Hulls::Undecided, "case {case}");
                assert!(bounded.iter().all(|it| it.1 == 0), "case {case}");
                continue;
            }
            assert_eq!(got, Hulls::Decided, "case {case}");
            if ww == 0 {
                // (Every item meets its own key: the same as the plain
                // test is all that is asked.)
                continue;
            }
            let mut folds = 0;
            for (i, (&k, it)) in ks.iter().zip(&bounded).enumerate() {
                let f = brute(i, k);
                folds += usize::from(f && i >= 12);
                assert_eq!(it.1, u32::from(f), "case {case} vertex {i} of {n}");
            }
            assert!(folds > 0, "case {case}: some of the tail's items fold");
            // Stopped by the clock after `q` questions (the scan from the
            // end asks at item 63, the tail's loop at 63 too when its
            // items fold past it): whatever is marked folds.
            for q in 0..4 {
                let mut asked = 0;
                let mut cut = items.clone();
                let r = folds_by_hulls::<_, true>(
                    &mut cut,
                    &margins,
                    (ww, 0),
                    (|it: &(f32, u32)| it.1 == 0, |it| it.0),
                    marks,
                    || {
                        asked += 1;
                        asked > q
                    },
                );
                for (i, (&k, it)) in ks.iter().zip(&cut).enumerate() {
                    assert!(
                        it.1 == 0 || brute(i, k),
                        "case {case} q {q} ({r:?}): vertex {i} marked, does not fold"
                    );
                }
                // The long tail under the high head: the second question
                // is the tail loop's at item 63, and the test stops there,
                // its folding items from 63 on unmarked.
                if len == 90 && high > 0.5 && ww == w && q == 1 {
                    assert_eq!(r, Hulls::Stopped, "case {case}");
                    let left = (63..n).filter(|&i| {
                        cut.get(i).is_some_and(|it| it.1 == 0)
                            && ks.get(i).is_some_and(|&k| brute(i, k))
                    });
                    assert!(
                        left.count() > 20,
                        "case {case}: not stopped in the tail's loop"
                    );
                    cut_in_tail += 1;
                }
            }
        }
        assert!(tails >= 20, "{tails} tails taken");
        assert_eq!(cut_in_tail, 2, "stopped inside a tail's loop, both ways");
        // A window past every vertex (no run on either side): nothing
        // folds, and no index arithmetic overflows.
        let mut items: Vec<(f32, u32)> = (0..5).map(|i| ((i % 2) as f32, 0)).collect();
        for w in [usize::MAX, usize::MAX - 1, usize::MAX / 2] {
            let marks = (
                |it: &mut (f32, u32)| it.1 += 1,
                |it: &mut (f32, u32)| it.1 -= 1,
            );
            let valid = |it: &(f32, u32)| it.1 == 0;
            let r = folds_by_hulls::<_, false>(
                &mut items,
                &[0.5; 5],
                (w, 0),
                (valid, |it| it.0),
                marks,
                || false,
            );
            assert_eq!(r, Hulls::Decided);
            assert!(items.iter().all(|it| it.1 == 0), "w = {w}: nothing folds");
        }
    }
}
