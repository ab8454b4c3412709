//! A caller's **deadline** for one per-frame call
//! ([`crate::Processor::process_within`]).
//!
//! The work budget ([`crate::Config::with_work_budget`]) bounds what the
//! searches spend, in units, but not what a point costs outside them, so
//! the worst case it gives is far past the frame period (README, "Worst
//! case"). A deadline bounds the call by the caller's own clock instead:
//! before each point's search (step 4), and before each point's fold query
//! where the fold test needs the index (step 2), the processor asks
//! [`Deadline::expired`]; once it says yes, every point not yet matched is
//! flagged [`crate::Status::OverBudget`], the rest of the frame's steps are
//! skipped and the call returns. The points done before keep their
//! results, and the output says the deadline cut the frame short
//! ([`crate::Processor::deadline_expired`]).
//!
//! What the caller can count on, after the clock says yes:
//! - **The point in progress ends within a bounded cost.** Between two
//!   questions a point's search may spend at most [`CARRY`] times the
//!   configured allowance (`work_per_point`) under a deadline (on the
//!   pseudo-angle path a point's walk and its deferred refinement are two
//!   such stretches; on the half-plane path the clock is asked between a
//!   point's walk and its stick's refinement too, which pays from what the
//!   walk left): the units cheap points leave still carry over to
//!   later points, but no single point can spend the whole frame's savings
//!   at once, which is what makes its cost bounded by a constant (`C_P +
//!   C_U · CARRY · w` instructions in the terms of README's "Worst case")
//!   rather than by the frame's size. (Before the first point, the band
//!   path builds the index's radial levels, asking the clock as below.)
//!   The cap moves the credit about, both ways: a point may come out
//!   [`crate::Status::OverBudget`] that `process` finishes, and one that
//!   `process` flags `over_budget` (the frame's credit spent by the
//!   points before it) may be finished, from the units the cap held back
//!   (an independent review counted 121 498 of the first and 15 916 of
//!   the second over 210 232 random pairs at the default carry).
//! - **Every other point costs a flag**: a store of a flagged result.
//! - **Nothing is left half done**: every point is either a complete
//!   result (the same checks as without a deadline: a stick that holds) or
//!   flagged. Without a deadline ([`NoDeadline`], what
//!   [`crate::Processor::process`] uses) nothing of this runs: the checks
//!   are compiled out.
//! - **No stretch between two questions grows with the boundary.** The
//!   passes over a whole boundary (the certified step 1, the fold test's
//!   rule from the keys, its index build and the envelopes' clearing, the
//!   frame-2 keys and index build, the band path's radial levels) ask the
//!   clock between parts of 64 items; a pass
//!   it stops leaves its index unused and the boundary's points flagged.
//!   So the longest stretch is one point's capped search, or up to 64
//!   items of each of a boundary's few passes (a few thousand
//!   instructions), not a boundary's worth. What does grow with `N` is
//!   the flags after the yes (a status store a point,
//!   [`crate::PointResult`]) and the number of questions. The bench
//!   measures the lateness where it is worst at 2 × 256 and 2 × 512
//!   (README, "Within a deadline"; how it got there, `docs/VEHICLE.md`).
//!
//! **What the cap costs.** The cap holds even while the clock says no, so
//! a point whose search needs more than `CARRY · w` units at once comes
//! out [`crate::Status::OverBudget`] where [`crate::Processor::process`]
//! would have finished it from the carried credit: at the default budget
//! no point of the certification's synthetic scenarios changes, and 462
//! of the adversarial family's (2 × 64 and 2 × 256 pairs) do, 453 of them
//! then `over_budget` (`host_tests/tests/deadline.rs` counts them); with
//! `w = 8` some random scenarios lose most of their points. Pairs across
//! several frames walk longer: on the fusion's random drives 24 of 304
//! have a pair where the cap changes points, 59 of them `over_budget`, 3
//! of those `ok` without the cap (`host_tests/tests/fusion/`,
//! `the_deadline_cap_on_the_drives`). A firmware
//! that needs `process`'s results whenever its clock does not fire should
//! give a larger `w`, or a clock whose [`Deadline::carry`] is larger.

use crate::search::Work;

/// Between two questions of the clock a point's search may spend at most
/// this many times the configured allowance per point under a deadline
/// (see the module docs).
pub const CARRY: u32 = 2;

/// The seal of [`Deadline::never`]: a public type in a private module,
/// which no other crate can name.
mod sealed {
    #[derive(Debug, Clone, Copy)]
    pub struct Token;
}

/// Whether `D` is [`NoDeadline`], whose checks are compiled out.
#[inline(always)]
pub(crate) fn never<D: Deadline>() -> bool {
    D::never(sealed::Token)
}

/// The caller's clock: whether the frame's time is up. Asked one to
/// three times a point (step 1 where the pair is not certified, the fold
/// queries, step 4) and a few times a boundary, so it should be cheap (a
/// cycle counter's read and a comparison); it may also rate-limit itself.
/// Any `FnMut() -> bool` is one (also `&mut dyn FnMut() -> bool`; the
/// trait itself is not object-safe).
///
/// Only [`NoDeadline`] has its checks compiled out; no other
/// implementation can claim that and have its clock ignored:
///
/// ```compile_fail
/// struct Clock;
/// impl roadstereo::Deadline for Clock {
///     fn expired(&mut self) -> bool {
///         true
///     }
///     fn never(_: roadstereo::deadline::sealed::Token) -> bool {
///         true
///     }
/// }
/// ```
pub trait Deadline {
    /// A deadline that never expires: the checks are compiled out. Not
    /// part of the API: [`NoDeadline`]'s alone. Sealed by its argument, a
    /// type no other crate can name, so no other implementation can say
    /// yes and have its clock ignored (until an integrator's review it
    /// was a hidden constant any implementation could set).
    #[doc(hidden)]
    #[inline(always)]
    fn never(_: sealed::Token) -> bool {
        false
    }

    /// Whether the time is up.
    fn expired(&mut self) -> bool;

    /// How many allowances (`work_per_point`) a point's search may spend
    /// between two questions: [`CARRY`] unless the clock says otherwise. A
    /// larger carry caps fewer points (`u32::MAX`: none, every result
    /// that of [`crate::Processor::process`] while the clock says no) and
    /// makes the stretches between questions longer, up to about `C_U · w`
    /// instructions more for each allowance (`docs/VEHICLE.md`, "Within a deadline").
    fn carry(&self) -> u32 {
        CARRY
    }
}

impl<F: FnMut() -> bool> Deadline for F {
    #[inline(always)]
    fn expired(&mut self) -> bool {
        self()
    }
}

/// No deadline: [`crate::Processor::process`]'s.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct NoDeadline;

impl Deadline for NoDeadline {
    #[inline(always)]
    fn never(_: sealed::Token) -> bool {
        true
    }

    #[inline(always)]
    fn expired(&mut self) -> bool {
        false
    }
}

/// The deadline of one per-frame call, with what it keeps of the carried
/// credit while a point's search is capped.
pub(crate) struct Guard<'d, D: Deadline> {
    deadline: &'d mut D,
    expired: bool,
    /// The most a point may spend ([`CARRY`] allowances).
    cap: u32,
    /// The carried units above the cap, held back from the point.
    reserve: u32,
}

impl<'d, D: Deadline> Guard<'d, D> {
    pub(crate) fn new(deadline: &'d mut D, allowance: u32) -> Self {
        let cap = allowance.saturating_mul(deadline.carry());
        Self {
            deadline,
            expired: false,
            cap,
            reserve: 0,
        }
    }

    /// Whether the next point may be worked on: `false` once the deadline
    /// has expired (asked now, remembered after). On `true`, `work`'s
    /// credit is capped for the point, the rest held back.
    #[inline(always)]
    pub(crate) fn proceed(&mut self, work: &mut Work) -> bool {
        if never::<D>() {
            return true;
        }
        if self.expired || self.deadline.expired() {
            self.expired = true;
            return false;
        }
        let total = work.credit().saturating_add(self.reserve);
        let now = total.min(self.cap);
        self.reserve = total.saturating_sub(now);
        work.set_credit(now);
        true
    }

    /// Whether the deadline has expired (asking the clock once more if it
    /// had not yet).
    #[inline(always)]
    pub(crate) fn check(&mut self) -> bool {
        if never::<D>() {
            return false;
        }
        self.expired = self.expired || self.deadline.expired();
        self.expired
    }

    /// Whether the deadline was seen to expire.
    #[inline(always)]
    pub(crate) fn has_expired(&self) -> bool {
        !never::<D>() && self.expired
    }

    /// The units held back given back to `work` (before it reports its
    /// usage).
    #[inline(always)]
    pub(crate) fn settle(&mut self, work: &mut Work) {
        if never::<D>() {
            return;
        }
        work.set_credit(work.credit().saturating_add(self.reserve));
        self.reserve = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cap holds a point to `CARRY` allowances, what it holds back
    /// comes back to later points and to the usage, and a clock that has
    /// said yes is not asked again.
    #[test]
    fn the_cap_holds_back_and_gives_back() {
        let mut asked = 0u32;
        let mut clock = || {
            asked += 1;
            asked > 3
        };
        let mut g = Guard::new(&mut clock, 10);
        let mut w = Work::new();
        w.grant(100);
        assert!(g.proceed(&mut w));
        assert_eq!((w.credit(), g.reserve), (20, 80));
        // The point spends 5; the next gets 20 of the 95 left.
        w.set_credit(15);
        assert!(g.proceed(&mut w));
        assert_eq!((w.credit(), g.reserve), (20, 75));
        // A point that spends it all: the next still gets 20.
        w.set_credit(0);
        assert!(g.proceed(&mut w));
        assert_eq!((w.credit(), g.reserve), (20, 55));
        assert!(!g.has_expired());
        // The fourth question: the time is up, and stays up unasked.
        assert!(!g.proceed(&mut w));
        assert!(!g.proceed(&mut w) && g.check() && g.has_expired());
        g.settle(&mut w);
        assert_eq!((w.credit(), g.reserve), (75, 0));
        assert_eq!(w.usage(), (25, 100));
        let _ = g;
        assert_eq!(asked, 4);
    }

    /// Without a deadline nothing is capped or asked.
    #[test]
    fn no_deadline_changes_nothing() {
        let mut never = NoDeadline;
        let mut g = Guard::new(&mut never, 10);
        let mut w = Work::new();
        w.grant(100);
        assert!(g.proceed(&mut w) && !g.check() && !g.has_expired());
        assert_eq!(w.credit(), 100);
        g.settle(&mut w);
        assert_eq!(w.usage(), (0, 100));
    }
}
