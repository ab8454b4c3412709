//! The index's own queries: the visits that offer every segment meeting a
//! query to a [`Visitor`] (the band path and the references), and the fold
//! test's queries built on them.

use super::*;
use crate::matching::{Radial, RADIAL_UNITS};

impl<const N: usize> Index<N> {
    /// Whether vertex `i`, whose raw key is `key`, may lie on a ray that
    /// meets a segment outside `i − w ..= i + w − 1` other than those set
    /// aside (the envelopes leave them out): `false` is certain
    /// (its widened key lies above every interval before that window and
    /// below every one after it, in the oriented order: the envelopes say
    /// so in `O(1)`, for each copy of a periodic key that can meet the
    /// keys' range), `true` needs the query ([`Self::visit`]) to decide.
    #[inline(always)]
    pub(crate) fn may_fold(&self, i: usize, key: f32, w: usize) -> bool {
        let k = self.orient * key;
        let e = self.margin(i);
        let test = |(lo, hi): (f32, f32)| {
            let before = i
                .checked_sub(w + 1)
                .and_then(|j| self.seg.get(j))
                .is_some_and(|g| lo <= g.pm);
            let after = self
                .seg
                .get(i + w)
                .filter(|_| i + w < self.segments)
                .is_some_and(|g| hi >= g.sm);
            before || after
        };
        if self.period <= 0.0 {
            return test((k - e, k + e));
        }
        // Periodic keys: every copy of the key that can meet the keys'
        // range (the envelopes hold the unwrapped keys).
        let mut c = [(0.0f32, 0.0f32); MAX_COPIES];
        match self.copies(k - e, k + e, &mut c) {
            Some(n) => c.iter().take(n).any(|&q| test(q)),
            None => true,
        }
    }

    /// [`Self::folds`] for every item of `items` in order (vertex `i` the
    /// `i`-th, `key` its raw key where it is to be tested), each bringing
    /// `allowance` to `work` first; `flag` gets the answer of each tested
    /// one. Without a period and with nothing aside, the envelopes' `O(1)`
    /// answer ([`Self::may_fold`]) is taken in the loop itself, and only the
    /// vertices it cannot clear go through [`Self::folds`]. Before each
    /// query `proceed(Some(work))` is asked (the caller's deadline,
    /// [`crate::deadline::Guard::proceed`]): `false` stops the general
    /// loop, that item and the rest left as they are (for the caller's
    /// flags), and answers [`OutOfWork`] without a query in the loop that
    /// clears vertices by the envelopes, where `proceed(None)` is also
    /// asked before every [`CHUNK`] vertices (whether the time is not up
    /// yet): `false` stops that loop, the items from there on left as they
    /// are.
    #[inline(always)]
    pub(crate) fn folds_all<T>(
        &mut self,
        items: &mut [T],
        (w, allowance): (usize, u32),
        work: &mut Work,
        mut proceed: impl FnMut(Option<&mut Work>) -> bool,
        key: impl Fn(&T) -> Option<f32>,
        mut flag: impl FnMut(&mut T, Result<bool, OutOfWork>),
    ) {
        let lean = self.period <= 0.0 && self.aside.is_empty();
        if !lean {
            for (i, it) in items.iter_mut().enumerate() {
                work.grant(allowance);
                let Some(k) = key(it) else {
                    continue;
                };
                if !proceed(Some(work)) {
                    // The caller's clock said the time is up: this item
                    // and the rest are left as they are, for the caller to
                    // flag in one pass (a seventh review measured this loop
                    // going on to the boundary's end after the yes, about
                    // 40 instructions an item with a key).
                    return;
                }
                let r = self.folds(i, k, w, work);
                flag(it, r);
            }
            return;
        }
        let (s, o) = (self.segments.min(N), self.orient);
        // The allowances of the items since the last grant: given before
        // the next query and at the end (saturating sums, so the credit
        // each query sees is the one granting item by item gives).
        let mut owed = 0u32;
        for (i, it) in items.iter_mut().enumerate() {
            if i % CHUNK == CHUNK - 1 && !proceed(None) {
                break;
            }
            owed = owed.saturating_add(allowance);
            let Some(k) = key(it) else {
                continue;
            };
            let (ko, e) = (o * k, self.margin.get(i).copied().unwrap_or(0.0));
            let before = i
                .checked_sub(w + 1)
                .and_then(|j| self.seg.get(j))
                .is_some_and(|g| ko - e <= g.pm);
            let after = i + w < s && self.seg.get(i + w).is_some_and(|g| ko + e >= g.sm);
            if !(before || after) {
                continue;
            }
            work.grant(owed);
            owed = 0;
            let r = if !proceed(Some(work)) {
                Err(OutOfWork)
            } else if self.strict {
                self.folds(i, k, w, work)
            } else {
                self.folds_query(i, k, w, work)
            };
            flag(it, r);
        }
        work.grant(owed);
    }

    /// The fold test of vertex `i` with raw key `key`: whether its key
    /// (widened by its margin) meets a segment outside `i − w ..= i + w −
    /// 1` (the aside list, [`Self::may_fold`] for the rest, then the query;
    /// each segment looked at one unit of `work`).
    #[inline(always)]
    pub(crate) fn folds(
        &mut self,
        i: usize,
        key: f32,
        w: usize,
        work: &mut Work,
    ) -> Result<bool, OutOfWork> {
        if self.strict {
            return Ok(false);
        }
        let e = self.margin(i);
        let skip = (i.saturating_sub(w), i.saturating_add(w).saturating_sub(1));
        if !self.aside.is_empty() {
            // The segments set aside first (the envelopes leave them out),
            // all for one unit: a spurious detector point's two segments
            // meet most keys and settle the test at once.
            work.spend(1)?;
            let k = self.orient * key;
            let mut c = [(0.0f32, 0.0f32); MAX_COPIES];
            let copies = match self.copies(k - e, k + e, &mut c) {
                Some(n) => c.get(..n).unwrap_or(&[]),
                None => return Ok(true),
            };
            let outside = |j: u16| usize::from(j) < skip.0 || usize::from(j) > skip.1;
            let met = self.aside.iter().any(|&(j, lo, hi)| {
                outside(j) && copies.iter().any(|&(ql, qh)| lo <= qh && hi >= ql)
            });
            if met {
                return Ok(true);
            }
        }
        if !self.may_fold(i, key, w) {
            return Ok(false);
        }
        self.folds_query(i, key, w, work)
    }

    /// The query of [`Self::folds`] (the index's segments outside `i − w
    /// ..= i + w − 1`, each one unit of `work`), for a vertex neither the
    /// aside list nor the envelopes settled.
    fn folds_query(
        &mut self,
        i: usize,
        key: f32,
        w: usize,
        work: &mut Work,
    ) -> Result<bool, OutOfWork> {
        let e = self.margin(i);
        let skip = (i.saturating_sub(w), i.saturating_add(w).saturating_sub(1));
        let mut met = Met(false);
        self.visit(
            Query::Keys(key - e, key + e),
            false,
            Some(skip),
            work,
            &mut met,
        )?;
        Ok(met.0)
    }

    /// Visit, in increasing index, every segment whose interval may meet
    /// `query` (a superset of those that do: the caller tests each), plus
    /// the FOE-near list when `with_near`; segments in `skip` (an inclusive
    /// range of indices) are left out. Each segment looked at costs one
    /// unit of `work`, each one visited what the visitor reports,
    /// each bisection step one.
    #[inline(always)]
    pub(crate) fn visit<'b>(
        &mut self,
        query: Query,
        with_near: bool,
        skip: Option<(usize, usize)>,
        work: &mut Work,
        visit: &mut (impl Visitor<'b> + Copy),
    ) -> Result<(), OutOfWork> {
        // The usual case: one run, no lists to merge; next, a run and the
        // aside list. Periodic keys take this way when at most one copy of
        // the query meets the keys' range (none: only unkeyed segments
        // aside can meet it, so the query is made empty).
        let near = with_near && (!self.near.is_empty() || self.near_overflow);
        // A band query's radial test, its levels built on the first one.
        let rad = self.radial_for(visit.radial());
        let mut one = None;
        if let (Query::Keys(q0, q1), false) = (query, near) {
            let (ql, qh) = if self.orient < 0.0 {
                (-q1, -q0)
            } else {
                (q0, q1)
            };
            if self.period <= 0.0 {
                one = Some((ql, qh));
            } else {
                let mut c = [(0.0f32, 0.0f32); MAX_COPIES];
                match self.copies(ql, qh, &mut c) {
                    Some(0) => one = Some((f32::INFINITY, f32::NEG_INFINITY)),
                    Some(1) => one = c.first().copied(),
                    _ => {}
                }
            }
        }
        if let Some((ql, qh)) = one {
            if self.aside.is_empty() {
                return self.visit_run(ql, qh, (skip, rad), work, visit);
            }
            let (mut v, mut w) = (*visit, *work);
            let skip = skip.unwrap_or((usize::MAX, 0));
            // (Without a radial test, a walk without its code: the test's
            // values kept in the loop cost a forward band walk 20 % there.)
            let r = match rad {
                Some(_) => self.visit_run_aside::<true>((ql, qh), (skip, rad), &mut w, &mut v),
                None => self.visit_run_aside::<false>((ql, qh), (skip, None), &mut w, &mut v),
            };
            (*visit, *work) = (v, w);
            return r;
        }
        // The rare paths take the visitor by reference to a copy, so that
        // the caller's visitor (and work) never has its address taken and
        // stays in registers on the usual path.
        let (mut v, mut w) = (*visit, *work);
        let r = self.visit_general(query, with_near, (skip, rad), &mut w, &mut v);
        (*visit, *work) = (v, w);
        r
    }

    /// [`Self::visit`] for one oriented interval and no lists (`rad`: a
    /// band query's radial test, with the radial levels built).
    #[inline(always)]
    fn visit_run<'b>(
        &mut self,
        ql: f32,
        qh: f32,
        (skip, rad): (Option<(usize, usize)>, Option<Radial>),
        work: &mut Work,
        visit: &mut (impl Visitor<'b> + Copy),
    ) -> Result<(), OutOfWork> {
        // (A query that cannot meet the keys' range finds an empty run: its
        // start is past every segment, or its first suffix minimum above it.)
        let a = self.run_start(ql, work)?;
        if a < self.segments {
            self.hint = a;
        }
        let (skip0, skip1) = skip.unwrap_or((usize::MAX, 0));
        if self.levels > 0 || rad.is_some() {
            let (mut v, mut w) = (*visit, *work);
            let r = match rad {
                Some(_) => {
                    self.visit_run_loose::<true>(a, (ql, qh), (skip0, skip1, rad), &mut w, &mut v)
                }
                None => {
                    self.visit_run_loose::<false>(a, (ql, qh), (skip0, skip1, None), &mut w, &mut v)
                }
            };
            (*visit, *work) = (v, w);
            return r;
        }
        let run = self.seg.get(a..self.segments.min(N)).unwrap_or(&[]);
        // The credit in a local while the run is walked (bounded by the
        // slice `run`).
        let mut credit = work.credit;
        let mut result = Ok(());
        for (j, g) in (a..).zip(run) {
            if g.sm > qh {
                break;
            }
            if credit == 0 {
                result = Err(OutOfWork);
                break;
            }
            credit -= 1;
            if g.lo <= qh && g.hi >= ql && !(j >= skip0 && j <= skip1) {
                let (flow, units) = visit.segment(j, (g.lo, g.hi));
                if credit < units {
                    credit = 0;
                    result = Err(OutOfWork);
                    break;
                }
                credit -= units;
                if flow == Flow::Stop {
                    break;
                }
            }
        }
        work.credit = credit;
        result
    }

    /// [`Self::visit_run`] through a loose index or with a radial test
    /// `rad`: the block tree skips the blocks the query misses, and those
    /// the radial test rejects whole (each skip one unit). Bounded by the
    /// segment count: every step advances `j`. `RAD`: whether `rad` may
    /// hold a radial test (as [`Self::visit_run_aside`]).
    #[inline(never)]
    fn visit_run_loose<'b, const RAD: bool>(
        &mut self,
        mut j: usize,
        (ql, qh): (f32, f32),
        (skip0, skip1, rad): (usize, usize, Option<Radial>),
        work: &mut Work,
        visit: &mut dyn Visitor<'b>,
    ) -> Result<(), OutOfWork> {
        let s = self.segments.min(N);
        let meets = |l: f32, h: f32| l <= qh && h >= ql;
        while let Some(g) = self.seg.get(j).filter(|_| j < s) {
            if g.sm > qh {
                break;
            }
            work.spend(1)?;
            let k = self.block_skip(j, meets, if RAD { rad.as_ref() } else { None });
            if k > 0 {
                j += k;
                continue;
            }
            if meets(g.lo, g.hi) && !(j >= skip0 && j <= skip1) {
                let (flow, units) = visit.segment(j, (g.lo, g.hi));
                work.spend(units)?;
                if flow == Flow::Stop {
                    break;
                }
            }
            j += 1;
        }
        Ok(())
    }

    /// [`Self::visit`] for one oriented interval through a run and the aside
    /// list, merged in index order (the block tree skips the run's blocks
    /// the query misses). Each step advances the run or the list; every
    /// segment looked at and every skip costs one unit, and so does the
    /// step that finds both at their ends. `RAD`: whether `rad` may hold a
    /// radial test.
    #[inline(never)]
    fn visit_run_aside<'b, const RAD: bool>(
        &mut self,
        (ql, qh): (f32, f32),
        ((skip0, skip1), rad): ((usize, usize), Option<Radial>),
        work: &mut Work,
        visit: &mut impl Visitor<'b>,
    ) -> Result<(), OutOfWork> {
        let a = self.run_start(ql, work)?;
        if a < self.segments {
            self.hint = a;
        }
        // The credit in a local copy while the lists are merged (written
        // back at every return, as [`Work::spend`] leaves it).
        let mut w = *work;
        let r = self.merge_aside::<RAD>(a, (ql, qh), ((skip0, skip1), rad), &mut w, visit);
        *work = w;
        r
    }

    /// The merge of [`Self::visit_run_aside`] from run start `j`, the
    /// credit in `work` (a local copy). The run's stretch before the list's next entry
    /// is walked in a loop of its own (the list's next index is read once
    /// a stretch, not once a step; the same steps, units and offers in the
    /// same order as one loop over both). Bounded: every step advances the
    /// run (a skip by at least one) or the list.
    #[inline(always)]
    fn merge_aside<'b, const RAD: bool>(
        &self,
        mut j: usize,
        (ql, qh): (f32, f32),
        ((skip0, skip1), rad): ((usize, usize), Option<Radial>),
        work: &mut Work,
        visit: &mut impl Visitor<'b>,
    ) -> Result<(), OutOfWork> {
        let s = self.segments.min(N);
        let meets = |l: f32, h: f32| l <= qh && h >= ql;
        let skipped = |k: usize| k >= skip0 && k <= skip1;
        let mut ia = 0usize;
        loop {
            let aside_next = self
                .aside
                .get(ia)
                .map_or(usize::MAX, |&(k, _, _)| usize::from(k));
            // The run's segments up to the entry's index (a run segment
            // with the entry's index comes first).
            loop {
                work.spend(1)?;
                let Some(g) = self
                    .seg
                    .get(j)
                    .filter(|g| j < s && g.sm <= qh && aside_next >= j)
                else {
                    break;
                };
                let skip = if self.levels > 0 || RAD {
                    self.block_skip(j, meets, if RAD { rad.as_ref() } else { None })
                } else {
                    0
                };
                if skip > 0 {
                    j += skip;
                    continue;
                }
                if meets(g.lo, g.hi) && !skipped(j) {
                    let (flow, units) = visit.segment(j, (g.lo, g.hi));
                    work.spend(units)?;
                    if flow == Flow::Stop {
                        return Ok(());
                    }
                }
                j += 1;
            }
            // The list's entry (before the run's next segment, or past the
            // run's end), its unit spent above; or the end of both.
            let Some(&(_, l, h)) = self.aside.get(ia) else {
                return Ok(());
            };
            ia += 1;
            if meets(l, h) && !skipped(aside_next) {
                let (flow, units) = visit.segment(aside_next, (l, h));
                work.spend(units)?;
                if flow == Flow::Stop {
                    return Ok(());
                }
            }
        }
    }

    /// [`Self::visit`] in general: the copies of a periodic key, the aside
    /// list and the FOE-near list merged into the run in index order. (The
    /// visitor by reference: this rare path keeps the usual one's visitor
    /// inlined.)
    #[inline(never)]
    fn visit_general<'b>(
        &mut self,
        query: Query,
        with_near: bool,
        (skip, rad): (Option<(usize, usize)>, Option<Radial>),
        work: &mut Work,
        visit: &mut dyn Visitor<'b>,
    ) -> Result<(), OutOfWork> {
        let s = self.segments;
        let mut copies = [(0.0f32, 0.0f32); MAX_COPIES];
        let mut ncopies = 0usize;
        let mut everything = with_near && self.near_overflow;
        if let (Query::Keys(q0, q1), false) = (query, everything) {
            let (ql, qh) = if self.orient < 0.0 {
                (-q1, -q0)
            } else {
                (q0, q1)
            };
            match self.copies(ql, qh, &mut copies) {
                Some(c) => ncopies = c,
                None => everything = true,
            }
        } else {
            everything = true;
        }
        let copies = copies.get(..ncopies).unwrap_or(&[]);
        // The run: from the first start over the copies to where the
        // suffix minimum passes the last copy's high end.
        let (mut j, mut top) = (s, f32::NEG_INFINITY);
        if everything {
            j = 0;
            top = f32::INFINITY;
        } else {
            for &(cl, ch) in copies {
                j = j.min(self.run_start_out_of_line(cl, work)?);
                top = fmax(top, ch);
            }
            if j < s {
                self.hint = j;
            }
        }
        let run = (j, top, everything);
        // One copy (every non-periodic query, most periodic ones): its test
        // without the loop over the copies (the same test).
        // (The merge counts the credit in a copy, which lives in a
        // register: not stored back at every unit.)
        let mut w = *work;
        // (Without `skip`: only the fold test's queries have one, and
        // those come here with several copies; the loop over one copy is
        // the same test.)
        let r = if let ([(cl, ch)], false, None) = (copies, everything, skip) {
            let (cl, ch) = (*cl, *ch);
            let meets = |l: f32, h: f32| l <= ch && h >= cl;
            self.merge(run, meets, with_near, (None, rad), &mut w, visit)
        } else {
            let meets = |l: f32, h: f32| copies.iter().any(|&(cl, ch)| l <= ch && h >= cl);
            self.merge(run, meets, with_near, (skip, rad), &mut w, visit)
        };
        *work = w;
        r
    }

    /// The merge of [`Self::visit_general`], from run start `j` to where the
    /// suffix minimum passes `top` (`everything`: every segment), with
    /// `meets` the copies' test of an interval and `rad` the radial test
    /// whose rejected blocks are skipped.
    #[inline(always)]
    fn merge<'b>(
        &mut self,
        (mut j, top, everything): (usize, f32, bool),
        meets: impl Fn(f32, f32) -> bool + Copy,
        with_near: bool,
        (skip, rad): (Option<(usize, usize)>, Option<Radial>),
        work: &mut Work,
        visit: &mut dyn Visitor<'b>,
    ) -> Result<(), OutOfWork> {
        let s = self.segments;
        let hits = |l: f32, h: f32| l <= h && (everything || l == f32::NEG_INFINITY || meets(l, h));
        let skipped = |k: usize| skip.is_some_and(|(x, y)| k >= x && k <= y);
        // The merge of three sorted streams: the run, the aside list and
        // (optionally) the near list, each bounded by its length; every
        // step advances one of them.
        let near: &[u16] = if with_near { &self.near } else { &[] };
        let (mut ia, mut inear) = (0usize, 0usize);
        // A loose index's skips (the same test at every step), and the
        // radial test's (whatever the query: it rejects on its own). (Tried
        // at every aligned step of a query: without levels and without a
        // radial test a skip passes over nothing, so only `everything`,
        // whose test of a loose index's empty blocks would skip them, is
        // left out; the one-copy merge has no test here then.)
        let skips = !everything || rad.is_some();
        // The visitor's cheap rejection, if it has one (the band walk's
        // `Radial`): made here for the run's segments, the same units.
        let quick = visit.radial();
        // (Its polyline empty without one: no segment has both ends there.)
        let (qrad, qb) = match quick {
            Some((r, b)) => (r, b),
            None => (Radial::NONE, &[][..]),
        };
        let segs = self.seg.get(..s.min(N)).unwrap_or(&[]);
        loop {
            let next_aside = self
                .aside
                .get(ia)
                .map_or(usize::MAX, |&(k, _, _)| usize::from(k));
            let next_near = near.get(inear).map_or(usize::MAX, |&k| usize::from(k));
            let lists = next_aside.min(next_near);
            // The run's stretch before the lists' next entry: the steps of
            // the merge below that take the run's segment alone, in a loop
            // of their own (the same steps, units and offers in the same
            // order: a skip is tried first at every step, as below).
            // Bounded by the run: every pass advances `j`.
            let g = loop {
                // The run's next segment, while its suffix minimum is not
                // past the query.
                let g = segs.get(j).copied().filter(|g| g.sm <= top);
                // A loose index: skip the blocks of the run no copy meets
                // (the aside and near entries in them keep their own
                // streams, which the merge still takes in index order).
                if skips && g.is_some() {
                    let k = self.block_skip(j, |l, h| everything || meets(l, h), rad.as_ref());
                    if k > 0 {
                        j += k;
                        work.spend(1)?;
                        continue;
                    }
                }
                match g {
                    Some(g) if j < lists => {
                        work.spend(1)?;
                        // (The merge's union of the streams' intervals is
                        // the run's own here: `fmin(∞, l) = l`, `fmax(−∞,
                        // h) = h` for every `l`, `h`, NaN included.)
                        if hits(g.lo, g.hi) && !skipped(j) {
                            // The visitor's whole radial test, here: the
                            // segments it rejects cost no call, and those it
                            // keeps go to the visitor past it.
                            let mut kept = false;
                            if let Some([a, b]) = qb.get(j..j + 2) {
                                if qrad.rejects(a.arr(), b.arr(), (g.lo, g.hi)) {
                                    work.spend(RADIAL_UNITS)?;
                                    j += 1;
                                    continue;
                                }
                                kept = true;
                            }
                            let (flow, units) = if kept {
                                visit.segment_kept(j, (g.lo, g.hi))
                            } else {
                                visit.segment(j, (g.lo, g.hi))
                            };
                            work.spend(units)?;
                            if flow == Flow::Stop {
                                return Ok(());
                            }
                        }
                        j += 1;
                    }
                    _ => break g,
                }
            };
            let next_run = if g.is_some() { j } else { usize::MAX };
            let next = next_run.min(next_aside).min(next_near);
            if next == usize::MAX {
                return Ok(());
            }
            let mut take = false;
            // The segment's interval: the union of its streams' (an aside
            // segment's is empty in the run).
            let (mut il, mut ih) = (f32::INFINITY, f32::NEG_INFINITY);
            if next == next_aside {
                if let Some(&(_, l, h)) = self.aside.get(ia) {
                    take |= hits(l, h);
                    (il, ih) = (fmin(il, l), fmax(ih, h));
                }
                ia += 1;
            }
            if next == next_near {
                take = true;
                (il, ih) = (f32::NEG_INFINITY, f32::INFINITY);
                inear += 1;
            }
            if next == next_run {
                if let Some(g) = g {
                    take |= hits(g.lo, g.hi);
                    (il, ih) = (fmin(il, g.lo), fmax(ih, g.hi));
                }
                j += 1;
            }
            work.spend(1)?;
            if take && !skipped(next) {
                let (flow, units) = visit.segment(next, (il, ih));
                work.spend(units)?;
                if flow == Flow::Stop {
                    return Ok(());
                }
            }
        }
    }
}

impl<const N: usize> Index<N> {
    /// The segments from `j` on that a block skip passes over: the larger
    /// of the key levels' skip ([`Self::skip_at`], a loose index) and the
    /// radial levels' ([`Self::radial_skip_at`], with `rad`). Either costs
    /// the one unit of the look at `j`. (Two units for a radial skip, a
    /// rejected segment's, measured dearer: the budget binds more often on
    /// backward frames and their walks cost more per point, `back_spiral`
    /// +5 % at 2 × 256, the worst-case bound +3 %.)
    #[inline(always)]
    fn block_skip(
        &self,
        j: usize,
        meets: impl Fn(f32, f32) -> bool,
        rad: Option<&Radial>,
    ) -> usize {
        let k = self.skip_at(j, meets);
        match rad {
            Some(r) => k.max(self.radial_skip_at(j, r)),
            None => k,
        }
    }
}

/// The fold test's visitor: any segment offered meets the key.
#[derive(Clone, Copy)]
struct Met(bool);

impl Visitor<'_> for Met {
    fn segment(&mut self, _: usize, _: (f32, f32)) -> (Flow, u32) {
        self.0 = true;
        (Flow::Stop, 0)
    }
}
