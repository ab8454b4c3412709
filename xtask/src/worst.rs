//! The worst-case formula of one per-frame call (README, "Worst case"),
//! its constants measured from the bench firmware's log.
//!
//! Every loop of the per-frame call is bounded by a slice length, a
//! capacity or a constant, except the searches' walks and bisections, which
//! are paid from the frame's work budget (`w` units per frame-1 point; see
//! `src/processor.rs`, "Worst case"). So a frame of `B` boundaries of at
//! most `N` points costs at most
//!
//! ```text
//! I ≤ C0 + C_B·B + (C_P + C_U·w)·B·N
//! ```
//!
//! with `C0` the cost of a frame, `C_B` of a boundary, `C_P` of a point
//! outside its paid search, and `C_U` of one unit of work. The constants
//! are measured, not derived from the code:
//!
//! * `C0`, `C_B`: the `fixed` frames (one and two boundaries of two points
//!   each): `C_B` their difference, `C0` the one-boundary frame less `C_B`.
//! * `C_U`: the largest marginal cost of a unit, over the 2 × 256 members
//!   of the adversarial family run at budgets from the smallest accepted
//!   to 16 × the default (the `sweep` rows): per member, the largest
//!   rise of the instructions between two of its budgets over the units'
//!   rise (pairs whose units move by fewer than 256 are left out), and the
//!   same over the configuration probes (`PROBES` in `src/bin/bench/pairs.rs`:
//!   members' pairs, or windows of them, under other valid configurations),
//!   which the firmware logs as sweep rows too.
//! * `C_P`: the largest per-point remainder, `(I − C0 − C_B·B − C_U·u) /
//!   points`, over every frame the bench ran (the bench pairs, the stress
//!   pairs' are not logged with their units, the whole adversarial family
//!   at every N, and the sweep).
//!
//! So the formula is the upper envelope of everything measured: every
//! measured frame lies under it by construction, and a frame costlier per
//! point or per unit than any of them would exceed it. The adversarial
//! family and the seeded search are what make the envelope worth quoting.

use crate::firmware::{field, num, records};

/// The measured constants.
pub struct Formula {
    pub c0: u64,
    pub cb: u64,
    pub cp: u64,
    pub cu: u64,
}

impl Formula {
    /// The bound for `b` boundaries of `n` points with `w` units per point.
    pub fn bound(&self, b: u64, n: u64, w: u64) -> u64 {
        self.c0 + self.cb * b + (self.cp + self.cu * w) * b * n
    }

    /// The largest `n` whose [`Self::bound`] for `b` boundaries at `w`
    /// units a point is within `deadline` (0 when none is).
    pub fn fits(&self, b: u64, w: u64, deadline: u64) -> u64 {
        let fixed = self.c0 + self.cb * b;
        let per = (self.cp + self.cu * w) * b;
        deadline.saturating_sub(fixed) / per.max(1)
    }
}

/// The constants from the log, or why they cannot be measured.
fn measure(log: &str) -> Result<Formula, String> {
    let fixed = records(log, "fixed boundaries=");
    let instr_of = |b: u64| {
        fixed
            .iter()
            .find(|r| num(r, "boundaries") == b && field(r, "pushed") == Some("true"))
            .map(|r| num(r, "instr"))
    };
    let (Some(f1), Some(f2)) = (instr_of(1), instr_of(2)) else {
        return Err("the bench logged no fixed-cost frames".into());
    };
    let cb = f2.saturating_sub(f1);
    let c0 = f1.saturating_sub(cb);
    // C_U: per member, the largest rise between two of its budgets, in
    // the order of the units spent, over the units' rise (of 256 or
    // more). (Until a third review it was the rise from the cheapest
    // budget to the costliest, which averaged a dear middle away.)
    let sweep = records(log, "sweep name=");
    let mut cu = 0.0f64;
    let mut names: Vec<&str> = sweep.iter().filter_map(|r| field(r, "name")).collect();
    names.dedup();
    for name in &names {
        let mut rows: Vec<(u64, u64)> = sweep
            .iter()
            .filter(|r| field(r, "name") == Some(name))
            .map(|r| (num(r, "work_spent"), num(r, "instr")))
            .collect();
        rows.sort_unstable();
        for (i, lo) in rows.iter().enumerate() {
            for hi in rows.iter().skip(i + 1) {
                if hi.0 >= lo.0 + 256 {
                    let slope = (hi.1 as f64 - lo.1 as f64) / (hi.0 - lo.0) as f64;
                    cu = cu.max(slope);
                }
            }
        }
    }
    if cu <= 0.0 {
        return Err("the work sweep moved no member's units by 256 or more".into());
    }
    let cu = cu.ceil() as u64;
    // C_P: the largest per-point remainder over every frame with units.
    let mut cp = 0.0f64;
    let mut frames = 0;
    for prefix in ["bench n=", "adversarial name=", "sweep name="] {
        for r in records(log, prefix) {
            let points = num(&r, "points");
            if points == 0 || field(&r, "processed") != Some("true") {
                continue;
            }
            let rest = num(&r, "instr") as f64
                - (c0 + 2 * cb) as f64
                - (cu * num(&r, "work_spent")) as f64;
            cp = cp.max(rest / points as f64);
            frames += 1;
        }
    }
    if frames == 0 {
        return Err("the bench logged no frame with its units".into());
    }
    Ok(Formula {
        c0,
        cb,
        cp: cp.ceil().max(0.0) as u64,
        cu,
    })
}

/// Print the sweep, the constants and the bound; the bound at the library's
/// default budget for 2 × 256 against `deadline` goes to `misses` (an open issue's
/// budget, `open`), and a log the constants cannot be measured from is a
/// hard miss.
pub fn worst_case(
    log: &str,
    deadline: u64,
    open: &str,
    misses: &mut Vec<String>,
) -> Option<Formula> {
    println!();
    println!(
        "work sweep: the adversarial family at 2 × 256 under each work budget (units per point):"
    );
    println!(
        "| member | w | instructions | per point | units spent | units per point | over_budget |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for r in records(log, "sweep name=") {
        let points = num(&r, "points").max(1);
        println!(
            "| {} | {} | {} | {} | {} | {:.1} | {} |",
            field(&r, "name").unwrap_or("?"),
            num(&r, "w"),
            num(&r, "instr"),
            num(&r, "instr") / points,
            num(&r, "work_spent"),
            num(&r, "work_spent") as f64 / points as f64,
            num(&r, "over_budget")
        );
    }
    let f = match measure(log) {
        Ok(f) => f,
        Err(e) => {
            misses.push(format!("worst-case formula: {e}"));
            return None;
        }
    };
    // The library's default budget (`Config::DEFAULT_WORK_PER_POINT`).
    let default_w = records(log, "work default_per_point=")
        .first()
        .map_or(0, |r| num(r, "default_per_point"));
    if default_w == 0 {
        misses.push("worst-case formula: the bench logged no default work budget".into());
        return None;
    }
    let bound = f.bound(2, 256, default_w);
    println!(
        "worst case of one per-frame call: I ≤ C0 + C_B·B + (C_P + C_U·w)·B·N with C0 = {}, C_B = {}, C_P = {}, C_U = {} (measured envelope)",
        f.c0, f.cb, f.cp, f.cu
    );
    println!(
        "  at B = 2, N = 256, w = {default_w} (the default): {bound} instructions, {} % of the deadline {deadline}; at w = 8 (the smallest): {}",
        bound * 100 / deadline.max(1),
        f.bound(2, 256, 8)
    );
    println!(
        "  what the bound fits in the deadline today (B = 2): N ≤ {} a boundary at w = {default_w}, N ≤ {} at w = 8 (an integration limit until issue 11's budgets are met, not a budget)",
        f.fits(2, default_w, deadline),
        f.fits(2, 8, deadline)
    );
    if bound > deadline {
        misses.push(format!(
            "{open}worst-case bound at 2 × 256 with the default budget: {bound} instructions > deadline {deadline}"
        ));
    }
    Some(f)
}
