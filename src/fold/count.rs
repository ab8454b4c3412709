//! The **counting rule**: which points the fold test flagged are searched
//! after all (issue 11 §4, the yield on curves that do fold).
//!
//! A point `p₁` folds ([`super`]) when its ray from the FOE `F` meets the
//! compensated frame-1 polyline again at some `q`: a frame-2 crossing in
//! `p₁`'s band could then be `q`'s image, which two views cannot tell from
//! `p₁`'s own. Moving forwards (`W' > 0`) an image lies on its point's ray
//! **beyond** the point: `q`'s image is at `q` or farther from `F`. So
//! where the polyline meets the ray exactly once more, at `q` **nearer**
//! `F` than `p₁`'s band (the near side of an S-bend, whose far side folds
//! back across the rays), and the frame-2 polyline crosses the ray between
//! `q` and `p₁`'s band, that crossing can be `q`'s image and nothing on the
//! ray is left to be the source of a crossing in `p₁`'s band but `p₁`
//! itself: the point is searched as if it did not fold.
//!
//! Like the fold test this is a rule about the points whose correspondent
//! is *not* in frame 2, not part of the stick's guarantee (which holds for
//! every point whose correspondent is there, folded or not: "What the fold
//! test buys", `docs/TESTS.md`). What it assumes is the fold test's own
//! assumption: a frame-2 crossing comes from a frame-1 point the detector
//! saw. A crossing between `q` and the band from a stretch frame 1 did not
//! see, with `p₁`'s correspondent missing from frame 2 and `q`'s image
//! beyond `p₁`, would let a wrong match through; over the certification's
//! scenarios none did (`docs/TESTS.md`, "The counting rule").
//!
//! Precisely, for a point the fold test flagged, on a pair that takes the
//! lean wedge path (moving forwards without a translation error,
//! half-plane keys), with `d = p₁' − F`, `R = |d|²`, `X = d·(x − F)` the
//! place of `x` along the ray and `n = ρ₁ (r₁ + e₂)` (the band's reach
//! towards `F` in `X`, [`crate::wedge`]), after the boundary's search
//! (`counted_search` in `src/processor/counted.rs`, which computes step 1's
//! values of the boundary again, the same arithmetic, and builds the fold
//! test's index and then frame 2's again):
//!
//! 1. **Partners** ([`partners`]): the frame-1 segments the fold test's
//!    index offers for the point's widened key, outside its window, each
//!    tested against the exact line through `F` and `p₁'`. The point stays
//!    `folded` unless exactly one crosses it, on `F`'s side of the band
//!    (`0 < X_q < R − n`); a segment along the line, a second crossing or
//!    one in or beyond the band keeps the fold.
//! 2. **Images** ([`images`]): the frame-2 segments the index offers for
//!    the point's key widened by its margin, the same test: the point is
//!    searched (on its own slot, the same search as every other point's)
//!    when one crosses the line at `X_q − n ≤ X < R − n`, and stays
//!    `folded` otherwise.
//!
//! Both count crossings of the exact ray on the *detected* polylines, as
//! the fold test does: a place the detection moves off the ray is no
//! partner to them (a limit the rule shares with the fold test, pinned by
//! `tests/fold_counting.rs`).
//!
//! Each segment looked at is a unit of the frame's work budget, each one
//! tested one more, and each point asks the caller's deadline first
//! ([`Guard::proceed`]): a point the budget or the deadline stops is
//! `over_budget`, so a cut frame gives each point its result or
//! `over_budget`, as everywhere. Between the steps a point the fold test
//! flagged keeps its step-1 values and its status [`Status::Folded`], its
//! `z_far` saying where it stands ([`Standing`]); [`settle`] gives every one
//! left its flag.

use crate::camera::Pixel;
use crate::deadline::{Deadline, Guard};
use crate::math::sqrt;
use crate::pencil::{Keying, NO_KEY};
use crate::search::{Flow, Index, OutOfWork, Query, Visitor, Work, CHUNK};
use crate::structure::{PointResult, Status, FOLD_WINDOW};

/// Where a point the fold test flagged stands between the steps, kept in
/// its `z_far` (its key until [`partners`], NaN if step 1's values could
/// not be had again; the key is a function of `p₁'`, [`Keying::key`], and
/// [`images`] computes it again).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Standing {
    /// It stays `folded`.
    Folded,
    /// The budget or the deadline stopped the rule: `over_budget`.
    OverBudget,
    /// One partner, at `X_q − R` (negative).
    Partner(f32),
}

impl Standing {
    /// Whether a `z_far` holds a [`Standing::Partner`]: below 0 (finite:
    /// partners stores `X_q − R > −R`, and `R` is finite); `+∞` is
    /// [`Standing::OverBudget`], anything else [`Standing::Folded`]. (Two
    /// tests where a match on a decoded standing compiled to about 30
    /// instructions of integer tests: [`settle`].)
    #[inline(always)]
    fn is_partner(z_far: f32) -> bool {
        z_far < 0.0
    }

    /// Whether the point whose `z_far` holds its standing stays `folded`
    /// when settled ([`settle`]): not when it is
    /// [`Standing::OverBudget`], nor when it has a partner and the
    /// boundary's steps were `cut`.
    #[inline(always)]
    fn stays_folded(z_far: f32, cut: bool) -> bool {
        !(z_far == f32::INFINITY || (cut && Self::is_partner(z_far)))
    }

    fn z_far(self) -> f32 {
        match self {
            Self::Folded => f32::NAN,
            Self::OverBudget => f32::INFINITY,
            Self::Partner(x) => x,
        }
    }
}

/// The exact line through `F` and `p₁'` ([`Self::crossing`]).
#[derive(Debug, Clone, Copy)]
struct Ray {
    p: [f32; 2],
    d: [f32; 2],
    /// `R = |d|²`.
    r: f32,
    /// `n = ρ₁ (r₁ + e₂)`.
    n: f32,
}

/// Where a segment meets a [`Ray`]'s line.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Meets {
    /// Not at all (both ends strictly on one side).
    No,
    /// At `X − R` (the place along the ray less `p₁'`'s).
    At(f32),
    /// Along it (both ends on it), or the arithmetic cannot say (a NaN).
    Unknown,
}

impl Ray {
    /// The line of the point `p` (`p₁'`) with error `r1` about the FOE
    /// `foe`, frame-2 error `e2`; `None` where the numbers are not finite
    /// and positive.
    fn of(p: [f32; 2], foe: [f32; 2], r1: f32, e2: f32) -> Option<Self> {
        let d = [p[0] - foe[0], p[1] - foe[1]];
        let r = d[0] * d[0] + d[1] * d[1];
        let n = sqrt(r) * (r1 + e2);
        // (A NaN fails.)
        (r > 0.0 && r < f32::INFINITY && n < f32::INFINITY).then_some(Self { p, d, r, n })
    }

    /// Where segment `a → b` meets the line, from the ends' sides of it
    /// (`d × (x − p₁')`) and, between them, the crossing's place `d·(x −
    /// p₁')`: differences from `p₁'`, not products of large coordinates.
    fn crossing(&self, a: [f32; 2], b: [f32; 2]) -> Meets {
        let (a, b) = (
            [a[0] - self.p[0], a[1] - self.p[1]],
            [b[0] - self.p[0], b[1] - self.p[1]],
        );
        let sa = self.d[0] * a[1] - self.d[1] * a[0];
        let sb = self.d[0] * b[1] - self.d[1] * b[0];
        if (sa > 0.0 && sb > 0.0) || (sa < 0.0 && sb < 0.0) {
            return Meets::No;
        }
        let den = sa - sb;
        // (Both on the line, or a NaN: `den` is 0 or NaN.)
        if !(den != 0.0 && den.is_finite()) {
            return Meets::Unknown;
        }
        // (`sa` and `sb` on opposite sides or one 0: `u` in [0, 1].)
        let u = sa / den;
        let x = [a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])];
        let at = self.d[0] * x[0] + self.d[1] * x[1];
        if at.is_finite() {
            Meets::At(at)
        } else {
            Meets::Unknown
        }
    }
}

/// Work units a segment offered to [`partners`]' visitor costs on top of
/// the look: both its ends compensated again (step 1's arithmetic, a
/// division and a key each) and the ray's crossing, about 270 instructions
/// with the look on a certified pair and 320 on one whose step 1 is not
/// certified (each point compensated on its own), so at six units a unit
/// costs about 45–53, under the band path's (`docs/VEHICLE.md`, "Worst
/// case": `C_U`). At one (a unit about 140 instructions) a partners
/// query's capped stretch between two of the clock's questions reached
/// 22 077 instructions at 2 × 512, and an eighth review's pair was 47 616
/// late with it (README allows 40 000); at three a ninth review's
/// uncertified pair was 39 711 late.
const PARTNER_UNITS: u32 = 5;

/// The frame-1 visitor of [`partners`]: the compensated vertex `j` is
/// `at(slots[j].pixel1)` (step 1's arithmetic again; `None` where step 1
/// flagged the point).
#[derive(Clone, Copy)]
struct Partners<'a, C> {
    ray: Ray,
    slots: &'a [PointResult],
    at: C,
    /// The one partner so far (`X_q − R`), if any.
    partner: Option<f32>,
    /// The fold stays.
    keep: bool,
}

impl<C: Fn(Pixel) -> Option<[f32; 2]> + Copy> Visitor<'_> for Partners<'_, C> {
    fn segment(&mut self, j: usize, _: (f32, f32)) -> (Flow, u32) {
        let vertex = |j: usize| self.slots.get(j).and_then(|r| (self.at)(r.pixel1));
        let (Some(a), Some(b)) = (vertex(j), vertex(j + 1)) else {
            // (Not offered: a segment with an unkeyed end meets no key in
            // the fold test's index.)
            return (Flow::Continue, PARTNER_UNITS);
        };
        match self.ray.crossing(a, b) {
            Meets::No => (Flow::Continue, PARTNER_UNITS),
            // Behind `F`: the other half of the line.
            Meets::At(x) if x <= -self.ray.r => (Flow::Continue, PARTNER_UNITS),
            Meets::At(x) if x < -self.ray.n && self.partner.is_none() => {
                self.partner = Some(x);
                (Flow::Continue, PARTNER_UNITS)
            }
            // A second partner, one in or beyond the band, or one that
            // cannot be placed.
            _ => {
                self.keep = true;
                (Flow::Stop, PARTNER_UNITS)
            }
        }
    }
}

/// The frame-2 visitor of [`images`].
#[derive(Clone, Copy)]
struct Images<'a> {
    ray: Ray,
    b2: &'a [Pixel],
    /// `X_q − n − R`: the nearest place a partner's image can be.
    from: f32,
    found: bool,
}

impl Visitor<'_> for Images<'_> {
    fn segment(&mut self, j: usize, _: (f32, f32)) -> (Flow, u32) {
        let (Some(a), Some(b)) = (self.b2.get(j), self.b2.get(j + 1)) else {
            return (Flow::Continue, 1);
        };
        match self.ray.crossing(a.arr(), b.arr()) {
            Meets::At(x) if x >= self.from && x < -self.ray.n => {
                self.found = true;
                (Flow::Stop, 1)
            }
            _ => (Flow::Continue, 1),
        }
    }
}

/// The rule's first part for one boundary's `slots`, after its search:
/// each point flagged [`Status::Folded`] (holding step 1's values again)
/// gets its partner on its ray, or its standing ([`Standing`]), in its
/// `z_far`. `index` is the fold test's index of the boundary (step 1's
/// keys and margins), `at` step 1's compensation of a frame-1 pixel. The
/// points take their units from `work`, each asking `guard` first. The FOE
/// `foe`, the frame-2 error `e2`. Returns whether any point has a partner,
/// or `None` where the clock stopped the pass: then every point that folds
/// has its flag ([`settle`] for those before the stop, `over_budget` for
/// the rest), in one pass over the boundary (two passes after the yes, the
/// rest's and then [`settle`]'s over all, made an eighth review's pair
/// later).
#[cold]
#[inline(never)]
pub(crate) fn partners<const N: usize, D: Deadline>(
    index: &mut Index<N>,
    slots: &mut [PointResult],
    at: impl Fn(Pixel) -> Option<[f32; 2]> + Copy,
    (foe, e2): ([f32; 2], f32),
    work: &mut Work,
    guard: &mut Guard<'_, D>,
) -> Option<bool> {
    let mut any = false;
    for i in 0..slots.len() {
        // (The clock asked every `CHUNK` slots looked at too, as in
        // [`images`]: a slot without a key asks nothing below.)
        if i % CHUNK == CHUNK - 1 && guard.check() {
            let (done, rest) = slots.split_at_mut(i.min(slots.len()));
            settle(done, true);
            unsearched(rest);
            return None;
        }
        let Some(r) = slots.get(i).filter(|r| r.status == Status::Folded) else {
            continue;
        };
        let key = r.z_far;
        // (The clock before the ray: once it has said yes, the points left
        // cost a flag each, not a ray and its square root; a sixth
        // review's pair was 73 943 late with them after the yes.)
        let standing = if !key.is_finite() {
            // (Without step 1's values: no key.)
            Standing::Folded
        } else if !guard.proceed(work) {
            // Out of time: the points before this one settled (the
            // boundary's steps cut), this point and the rest of the
            // boundary's that fold `over_budget` (their `z_far` holds no
            // standing yet).
            let (done, rest) = slots.split_at_mut(i.min(slots.len()));
            settle(done, true);
            unsearched(rest);
            return None;
        } else {
            match Ray::of(r.pixel2.arr(), foe, r.z_near, e2) {
                None => Standing::Folded,
                Some(ray) => {
                    let e = index.margin(i);
                    let skip = (
                        i.saturating_sub(FOLD_WINDOW),
                        i.saturating_add(FOLD_WINDOW).saturating_sub(1),
                    );
                    let mut v = Partners {
                        ray,
                        slots,
                        at,
                        partner: None,
                        keep: false,
                    };
                    match index.visit(
                        Query::Keys(key - e, key + e),
                        false,
                        Some(skip),
                        work,
                        &mut v,
                    ) {
                        Err(OutOfWork) => Standing::OverBudget,
                        Ok(()) => match (v.keep, v.partner) {
                            (false, Some(x)) => Standing::Partner(x),
                            _ => Standing::Folded,
                        },
                    }
                }
            }
        };
        any |= matches!(standing, Standing::Partner(_));
        if let Some(r) = slots.get_mut(i) {
            r.z_far = standing.z_far();
        }
    }
    Some(any)
}

/// Step 4's part of the rule for one boundary (after its search): each
/// point with a partner ([`partners`]) whose ray the frame-2 polyline `b2`
/// crosses between the partner and the band (through the frame-2 `index`)
/// is made a point still to be matched again, its key back in `z_far`, and
/// searched at once by `search` on its own slot (the other slots hold
/// results, some of them [`Status::NoIntersection`], which a search of the
/// whole boundary would take for points still to be matched). Units and
/// deadline as [`partners`]. (Inlined into its one caller, so that the
/// matcher `search` captures stays a constant there.)
#[inline(always)]
pub(crate) fn images<const N: usize, D: Deadline>(
    index: &mut Index<N>,
    slots: &mut [PointResult],
    b2: &[Pixel],
    (keying, foe, e2): (&Keying, [f32; 2], f32),
    (work, guard): (&mut Work, &mut Guard<'_, D>),
    mut search: impl FnMut(&mut [PointResult], &mut Index<N>, &mut Work, &mut Guard<'_, D>),
) {
    for i in 0..slots.len() {
        // The clock asked every `CHUNK` slots looked at, as well as before
        // each partner's query below: the look at a slot is not paid from
        // the work budget, so on its own this loop would run on from one
        // partner to the next unasked. (Until a twelfth review it did: 13
        // instructions a slot, about 6 760 over 500 points that fold
        // without a partner, of a pair's 42 494 late.)
        if i % CHUNK == CHUNK - 1 && guard.check() {
            return;
        }
        let Some(r) = slots.get_mut(i).filter(|r| r.status == Status::Folded) else {
            continue;
        };
        let xq = r.z_far;
        if !Standing::is_partner(xq) {
            continue;
        }
        // (The clock before the key and the ray, as in [`partners`]: once
        // it has said yes the points left keep their standings, which
        // [`settle`] gives their flags.)
        if !guard.proceed(work) {
            r.z_far = Standing::OverBudget.z_far();
            return;
        }
        let p = r.pixel2.arr();
        let (key, e) = keying.key(p);
        let found = match Ray::of(p, foe, r.z_near, e2) {
            // (Not reached: step 1 keyed the point, `partners` placed it.)
            None => Ok(false),
            Some(_) if key == NO_KEY => Ok(false),
            Some(ray) => {
                let mut v = Images {
                    ray,
                    b2,
                    from: xq - ray.n,
                    found: false,
                };
                index
                    .visit(Query::Keys(key - e, key + e), false, None, work, &mut v)
                    .map(|()| v.found)
            }
        };
        match found {
            Ok(true) => {
                r.z_far = key;
                r.status = Status::NoIntersection;
                if let Some(one) = slots.get_mut(i..=i) {
                    search(one, index, work, guard);
                }
                // The clock said yes in that search: the points left keep
                // their standings for [`settle`]. (Until an eleventh review
                // the loop went on over the rest of the boundary, a look at
                // each slot after the yes: 5 639 instructions of a pair's
                // 41 404 late.)
                if guard.has_expired() {
                    return;
                }
            }
            Ok(false) => r.z_far = Standing::Folded.z_far(),
            Err(OutOfWork) => r.z_far = Standing::OverBudget.z_far(),
        }
    }
}

/// A boundary whose steps the deadline cut after its fold test and before
/// its search ([`Processor`](crate::Processor)'s per-frame call): every
/// point still to be matched, and with the counting rule on every point
/// flagged [`Status::Folded`], is `over_budget` (the rule might have
/// searched it had the clock not stopped the boundary first; on a cut
/// frame `over_budget` may stand for any result). One pass over the
/// boundary, as the flags of a cut without the rule (`counting` false:
/// only the points still to be matched). (A cut inside the rule's part
/// settles its points there, [`settle`]; boundaries done before the cut
/// keep their results.) (One cold call for both: the two calls at each of
/// the per-frame call's exits measured the representative window 0.4
/// estimated cycles a point dearer.)
#[cold]
#[inline(never)]
pub(crate) fn cut_short(slots: &mut [PointResult], counting: bool) {
    for r in slots
        .iter_mut()
        .filter(|r| r.status == Status::NoIntersection || (counting && r.status == Status::Folded))
    {
        r.flag(Status::OverBudget);
    }
}

/// Every point the fold test flagged (`folded`) made `over_budget`, where
/// the deadline stopped the rule before it looked for their partners (their `z_far`
/// does not hold a [`Standing`] yet, so [`settle`] cannot tell them
/// apart): the rule might have searched any of them.
#[cold]
#[inline(never)]
pub(crate) fn unsearched(slots: &mut [PointResult]) {
    for r in slots.iter_mut().filter(|r| r.status == Status::Folded) {
        r.flag(Status::OverBudget);
    }
}

/// Every point the fold test flagged and the rule left given its flag:
/// [`Status::Folded`] (its slot keeping what the rule kept there, which
/// the result does not give: [`PointResult`]), or [`Status::OverBudget`] where the budget or
/// the deadline stopped the rule, or where `cut` (the boundary's steps
/// were cut short by the deadline) left a point with a partner that might
/// have been searched.
#[cold]
#[inline(never)]
pub(crate) fn settle(slots: &mut [PointResult], cut: bool) {
    for r in slots.iter_mut().filter(|r| r.status == Status::Folded) {
        // A point that stays `folded` keeps its standing in the bytes its
        // status does not give ([`PointResult`]): no store. (Until the
        // seventeenth session each was written clean after a match on its
        // decoded standing, about 35 instructions a point: 17 800 after
        // the clock's yes on a review's pair.)
        if !Standing::stays_folded(r.z_far, cut) {
            r.flag(Status::OverBudget);
        }
    }
}
