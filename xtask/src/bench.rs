//! `cargo xtask bench`: instruction counts, stack, memory
//! figures and the link-time proofs, every budget hard.
//!
//! The steps, in the order they print: build the three firmware binaries
//! (the `nopanic` link is itself a proof), run the bench firmware, the
//! budget table (instructions per point at every N, and at N = 256), the
//! stress pairs, the scaling and deadline checks, the adversarial family
//! (issue 11: a table per member and N, the per-member scaling and log-log
//! slope, the 2 × 256 worst case against the deadline), the work sweep and
//! the worst-case formula (`worst.rs`),
//! the memory table, the symbol checks, and the verdict.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::firmware::{build_firmware, field, num, records, run_firmware, Record};
use crate::setup::setup_emulator;
use crate::util::{capture, tool};

pub const BENCH_USAGE: &str =
    "usage: cargo xtask bench [--frame-ms 33] [--cpu-mhz 168] [--share-percent 5] [--per-point 400]
                         [--per-point-256 390]
  every budget is hard (exit code 1 when one is missed) except those an open issue owns, printed
  as \"budget NOT MET: [open: issue N] ...\" on every run and not enforced until the issue
  lands (today, issue 11: the per-point budgets, the 2 x 256 frame with and without the fusion,
  the adversarial worst case and scaling, the worst-case bound; issue 13: the 2 x 256 frame with
  the fusion once the matching alone fits, while the fusion's worst is a filling drive's);
  the deadline is share-percent of a
  frame-ms frame at cpu-mhz, one instruction = one cycle (default 277 200 instructions).
  The representative pair (the Fig. 6 set-up, one detector point per row, N = 32 ... 512):
    - instructions per point <= per-point (400) at every N
    - instructions per point <= per-point-256 (390) at N = 256
    - per-point scaling N = 512 / N = 64 <= 1.25
    - the 2 x 256 frame within the deadline
  The adversarial family (issue 11; host_tests/src/drive/adversarial.rs, N = 64 ... 512):
    - the 2 x 256 worst case over every member within the deadline
    - per-point scaling N = 512 / N = 64 <= 1.25 for every member
    - every member's frame 2 processed without an error
    (reported, not budgeted: per point, share of the deadline, ok points, points flagged by a
    status whose name contains `budget`, the other statuses, the log-log slope of cost vs N)
  The key-frame fusion over the demo drive (issue 13; 24 frames, 2 x 256 points):
    - the fusion's and the road map's own instructions per key-frame point <= fusion-per-point
      (--fusion-per-point 80) in every paired frame (the step minus the processor call inside it,
      replayed on a copy of the processor, which must give the same structure)
    - the representative 2 x 256 frame plus the fusion at its worst per point within the deadline
    - fusion state + road map (Fusion<256, 2, 512> beside its Processor) <= 24 KiB
    - the demo's matching (the processor call of each paired step) within the deadline in every
      frame, and its steps with the fusion (the matching, the fusion and the map) too
  The fusion over drives whose road map fills (issue 13; 80 frames, 2 x 256 points but where said: sideways,
  straight and turning, forwards zigzagging, sideways on a wobbling road and on a jumping road,
  the last two adversarial, outside the representative figure; and sideways with key frames of 90
  and of 32 points a boundary and with a key frame every frame, whose miss issue 13 owns, and every 2
  frames, enforced):
    - the fusion's own instructions per key-frame point <= fusion-per-point in every paired frame
      (the demo drive's map never fills, so its retiring frames drop nothing for room)
    (reported: the worst step's own work in instructions, and the same with the sight check on)
  Memory and proofs: worst-case stack of one per-frame call <= 4 KiB (painted on the
  representative pair and every adversarial member at N = 256; the fusion step's too), no
  software f64, no allocator, the panic-never link.
  Also printed (integration limits while the deadline budgets are missed, not budgets): the points
  per boundary that fit the deadline for the representative pair at its costliest measured
  per-point cost, with the fusion, and by the worst-case bound at the default budget and at w = 8;
  and the call within a deadline (Processor::process_within, SysTick as the clock, 2 x 256): on a
  grid of limits the instructions, overrun past the clock's yes, lateness past the limit and ok
  points, and the lateness where it is worst (cut after each pair's longest gaps between questions,
  at 2 x 256 and 2 x 512) with the limit that keeps every pair within the deadline, and the demo
  drive's fusion steps within a deadline. Budgets there: the lateness where it is worst <= 40 000
  instructions at both sizes (the margin README quotes), every demo-drive step within a deadline inside the deadline, the expiry flag agrees with
  the clock, a passed deadline leaves no point ok.
  Not here: the representative window's estimated Cortex-M4F cycles per point <= 718 is
  checked by `cargo xtask profile` (see its --help).";

/// The bench's budgets (`--help` lists the knobs).
pub struct Budget {
    per_point: u64,
    per_point_256: u64,
    frame_ms: f64,
    cpu_mhz: f64,
    share_percent: f64,
    stack: u64,
    scaling: f64,
    fusion_per_point: u64,
    fusion_bytes: u64,
}

impl Budget {
    /// Instructions one frame may take: `share_percent` of a `frame_ms`
    /// frame at `cpu_mhz`, one instruction = one cycle.
    fn deadline(&self) -> u64 {
        (self.frame_ms * 1e-3 * self.cpu_mhz * 1e6 * self.share_percent / 100.0) as u64
    }
}

/// The budgets from the command line (defaults: 400 per point, 390 at
/// N = 256, 5 % of a 33 ms frame at 168 MHz, 4 KiB of stack, scaling 1.25).
pub fn bench_args(args: &[String]) -> Result<Budget, String> {
    let mut b = Budget {
        per_point: 400,
        per_point_256: 390,
        frame_ms: 33.0,
        cpu_mhz: 168.0,
        share_percent: 5.0,
        stack: 4096,
        scaling: 1.25,
        fusion_per_point: 80,
        fusion_bytes: 24 * 1024,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut val = || {
            it.next()
                .and_then(|v| v.parse::<f64>().ok())
                .ok_or(format!("{a} needs a number"))
        };
        match a.as_str() {
            "--frame-ms" => b.frame_ms = val()?,
            "--cpu-mhz" => b.cpu_mhz = val()?,
            "--share-percent" => b.share_percent = val()?,
            "--per-point" => b.per_point = val()? as u64,
            "--per-point-256" => b.per_point_256 = val()? as u64,
            "--fusion-per-point" => b.fusion_per_point = val()? as u64,
            _ => return Err(BENCH_USAGE.into()),
        }
    }
    Ok(b)
}

/// Per N: (instructions per frame, per point).
type PerN = BTreeMap<u64, (u64, u64)>;

/// The prefix of a budget that an open issue owns: printed as not met
/// every run, not enforced until the issue lands its fix (the budget's
/// value stays).
pub const OPEN: &str = "[open: issue 11] ";

/// The prefix of a budget the fusion's issue owns (as [`OPEN`]).
pub const OPEN_FUSION: &str = "[open: issue 13] ";

/// Whether a miss is owned by an open issue ([`OPEN`], [`OPEN_FUSION`]).
fn owned(miss: &str) -> bool {
    miss.starts_with(OPEN) || miss.starts_with(OPEN_FUSION)
}

/// `cargo xtask bench`. Every budget is hard — any miss fails the task
/// (and CI), after every table is printed — except those an open issue
/// owns ([`OPEN`]), which are printed as not met on every run.
pub fn bench(b: &Budget) -> Result<(), String> {
    setup_emulator()?;
    let (elf, demo_elf) = build()?;
    let log = run_firmware(&elf)?;
    let mut misses = Vec::new();
    let per = budget_table(&log, b, &mut misses);
    stress_table(&log);
    scaling_and_deadline(&per, b, &mut misses);
    adversarial(&log, b, &mut misses);
    crate::worst::worst_case(&log, b.deadline(), OPEN, &mut misses);
    deadline_table(&log, b.deadline(), &mut misses);
    drive_within(&log, b.deadline(), &mut misses);
    drive_counted(&log, b.deadline(), &mut misses);
    drive_sighted(&log, &mut misses);
    let filling = fusion_filling(&log, b, &mut misses);
    fusion_table(&log, &per, b, filling, &mut misses);
    memory_table(&log, &demo_elf, b, &mut misses)?;
    wire_table(&log, &mut misses);
    symbol_checks(&[&elf, &demo_elf], &mut misses)?;
    verdict(&misses, b)
}

/// Build the bench and demo firmware (their ELF paths) and link `nopanic`.
fn build() -> Result<(PathBuf, PathBuf), String> {
    let elf = build_firmware("bench")?;
    let demo_elf = build_firmware("demo")?;
    // The link-time proof: this build fails if a panic path remains.
    build_firmware("nopanic")?;
    println!("xtask: panic-never check binary linked: no panicking branch in the per-frame code");
    Ok((elf, demo_elf))
}

/// The representative rows (`bench n=…`) with the per-point budget checked
/// at every N.
fn budget_table(log: &str, b: &Budget, misses: &mut Vec<String>) -> PerN {
    println!();
    println!("| N per boundary | points | instructions per frame | per point |");
    println!("|---:|---:|---:|---:|");
    let mut per = PerN::new();
    for r in &records(log, "bench n=") {
        println!(
            "| {} | {} | {} | {} |",
            num(r, "n"),
            num(r, "points"),
            num(r, "instr"),
            num(r, "per_point")
        );
        per.insert(num(r, "n"), (num(r, "instr"), num(r, "per_point")));
    }
    for (n, (_, pp)) in &per {
        if *pp > b.per_point {
            misses.push(format!(
                "{OPEN}N = {n}: {pp} instructions per point > budget {}",
                b.per_point
            ));
        }
    }
    match per.get(&256) {
        Some((_, pp)) => {
            println!(
                "representative N = 256: {pp} instructions per point (budget ≤ {})",
                b.per_point_256
            );
            if *pp > b.per_point_256 {
                misses.push(format!(
                    "{OPEN}representative N = 256: {pp} instructions per point > budget {}",
                    b.per_point_256
                ));
            }
        }
        None => misses.push("missing the representative N = 256 row".into()),
    }
    per
}

/// The stress pairs (`stress n=…`), reported, not budgeted.
fn stress_table(log: &str) {
    let stress = records(log, "stress n=");
    if stress.is_empty() {
        return;
    }
    println!(
        "\nstress pairs (not budgeted): the paper's 512 x 480 camera sampled at up to 3.4 points per image row"
    );
    println!("| N per boundary | points | instructions per frame | per point | ok |");
    println!("|---:|---:|---:|---:|---:|");
    for r in &stress {
        println!(
            "| {} | {} | {} | {} | {} |",
            num(r, "n"),
            num(r, "points"),
            num(r, "instr"),
            num(r, "per_point"),
            num(r, "ok")
        );
    }
}

/// Per-point cost at N = 512 against N = 64, and the 2 × 256 frame against
/// the deadline.
fn scaling_and_deadline(per: &PerN, b: &Budget, misses: &mut Vec<String>) {
    match (per.get(&64), per.get(&512)) {
        (Some((_, p64)), Some((_, p512))) => {
            let ratio = *p512 as f64 / (*p64).max(1) as f64;
            println!(
                "\nper-point cost at N = 512 / N = 64: {ratio:.3} (budget ≤ {:.2})",
                b.scaling
            );
            if ratio > b.scaling {
                misses.push(format!("scaling {ratio:.3} > {:.2}", b.scaling));
            }
        }
        _ => misses.push("missing N = 64 or N = 512 rows".into()),
    }
    let deadline = b.deadline();
    if let Some((i256, _)) = per.get(&256) {
        println!(
            "frame of 2 × 256 points: {i256} instructions; deadline {deadline} ({} % of {} ms at {} MHz, one instruction = one cycle): {:.0} % of it",
            b.share_percent,
            b.frame_ms,
            b.cpu_mhz,
            100.0 * *i256 as f64 / deadline as f64
        );
        // At the costliest per-point figure of any N measured (the cost is
        // nearly flat in N, "linear scaling" above), the representative
        // frame that fits: an integration limit, not a budget.
        let pp = costliest_point(per);
        println!(
            "  a representative frame of 2 × {} points fits the deadline at the costliest measured {pp} instructions a point (an integration limit, not a budget)",
            deadline / (2 * pp).max(1)
        );
        if *i256 > deadline {
            misses.push(format!(
                "{OPEN}2 × 256 frame: {i256} instructions > deadline {deadline}"
            ));
        }
    }
}

/// The largest per-point cost of the representative pairs over every N.
fn costliest_point(per: &PerN) -> u64 {
    per.values().map(|&(_, pp)| pp).max().unwrap_or(0)
}

/// One adversarial measurement (`adversarial name=… n=…`).
struct Adv {
    n: u64,
    instr: u64,
    per_point: u64,
    points: u64,
    processed: bool,
    /// Every `status.<name>=<count>` field, in log order.
    statuses: Vec<(String, u64)>,
}

impl Adv {
    fn status(&self, name: &str) -> u64 {
        self.statuses
            .iter()
            .find(|(n, _)| n == name)
            .map_or(0, |s| s.1)
    }
    /// Points flagged because the per-frame work budget was spent: every
    /// status whose name contains `budget` (the library has none yet).
    fn budget_flagged(&self) -> u64 {
        self.statuses
            .iter()
            .filter(|(n, _)| n.contains("budget"))
            .map(|s| s.1)
            .sum()
    }
}

/// The deadline sweep (`Processor::process_within` with SysTick as the
/// clock, firmware `deadline_sweep`): per pair, the call's instructions
/// past the clock's first yes (the overrun: the point or step in
/// progress, then the flags) and past the limit (the lateness: the
/// overrun and the time from the limit to the next time the clock is
/// asked), and the largest limit of the sweep at which every pair ends
/// within the deadline, with the `ok` points each keeps there (and
/// without a deadline, from the adversarial rows). Hard checks: the processor reports an expired
/// deadline exactly when the clock said yes, and a deadline already passed
/// leaves no point `ok`. The overrun and the limit are reported, not
/// budgeted (the argument for the overrun's bound is in `src/deadline.rs`).
/// The lateness README tells a firmware to allow for, up to 2 × 512
/// points ("Within a deadline": the limit is the deadline less this).
const LATENESS: u64 = 40_000;

fn deadline_table(log: &str, deadline: u64, misses: &mut Vec<String>) {
    let rows = records(log, "deadline name=");
    if rows.is_empty() {
        misses.push("no deadline rows in the bench log".into());
        return;
    }
    // By pair in log order: (limit, instr, expired, expired_at, ok).
    type Row = (u64, u64, bool, u64, u64);
    let mut pairs: Vec<(String, Vec<Row>)> = Vec::new();
    for r in &rows {
        let name = field(r, "name").unwrap_or("?").to_string();
        let expired = field(r, "expired") == Some("true");
        if (field(r, "reported") == Some("true")) != expired {
            misses.push(format!(
                "deadline {name} at {}: the processor's expiry flag disagrees with the clock",
                num(r, "limit")
            ));
        }
        if field(r, "processed") != Some("true") {
            misses.push(format!("deadline {name}: frame 2 not processed"));
        }
        if num(r, "limit") == 0 && num(r, "ok") != 0 {
            misses.push(format!("deadline {name}: a passed deadline left points ok"));
        }
        let row = (
            num(r, "limit"),
            num(r, "instr"),
            expired,
            num(r, "expired_at"),
            num(r, "ok"),
        );
        match pairs.iter_mut().find(|p| p.0 == name) {
            Some(p) => p.1.push(row),
            None => pairs.push((name, vec![row])),
        }
    }
    let limits: Vec<u64> = pairs
        .first()
        .map(|p| p.1.iter().map(|r| r.0).collect())
        .unwrap_or_default();
    // The largest limit at which every pair ends within the deadline.
    let fits = limits
        .iter()
        .copied()
        .filter(|&l| {
            pairs
                .iter()
                .all(|p| p.1.iter().filter(|r| r.0 == l).all(|r| r.1 <= deadline))
        })
        .max();
    println!(
        "
within a deadline (`Processor::process_within`, SysTick as the clock; 2 × 256, each pair's own configuration,
limits {} … {} instructions): the overrun is the call's instructions past the clock's first yes",
        limits.first().unwrap_or(&0),
        limits.last().unwrap_or(&0)
    );
    let at = fits.unwrap_or(0);
    // `ok` without a deadline: the representative pair's bench row and
    // the members' adversarial rows at N = 256.
    let mut full: BTreeMap<String, u64> = BTreeMap::new();
    for r in records(log, "bench n=256 ") {
        full.insert("representative".into(), num(&r, "ok"));
    }
    for r in records(log, "adversarial name=") {
        if num(&r, "n") == 256 {
            let name = field(&r, "name").unwrap_or("?").to_string();
            full.insert(name, num(&r, "status.ok"));
        }
    }
    println!(
        "| pair | ok without a deadline | limit 0: instructions | largest overrun | largest lateness | at limit {at}: instructions | ok |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    let (mut worst, mut late) = ((0u64, String::new()), (0u64, String::new()));
    for (name, r) in &pairs {
        let expired = || r.iter().filter(|x| x.2);
        let over = expired()
            .map(|x| x.1.saturating_sub(x.3))
            .max()
            .unwrap_or(0);
        let lateness = expired()
            .map(|x| x.1.saturating_sub(x.0))
            .max()
            .unwrap_or(0);
        if over > worst.0 {
            worst = (over, name.clone());
        }
        if lateness > late.0 {
            late = (lateness, name.clone());
        }
        let floor = r.iter().find(|x| x.0 == 0).map_or(0, |x| x.1);
        let here = r.iter().find(|x| x.0 == at);
        println!(
            "| {name} | {} | {floor} | {over} | {lateness} | {} | {} |",
            full.get(name).map_or("?".to_string(), |o| o.to_string()),
            here.map_or(0, |x| x.1),
            here.map_or(0, |x| x.4)
        );
    }
    println!(
        "on the limits' grid: largest overrun {} instructions ({}), largest lateness {} ({}); every pair ends within the deadline {deadline} at limits up to {}",
        worst.0,
        worst.1,
        late.0,
        late.1,
        fits.map_or("none of the sweep".to_string(), |l| l.to_string())
    );
    // Where it is worst: a limit just before each pair's longest gaps
    // between questions (firmware `deadline_gaps`).
    let gaps = records(log, "deadline_gap n=");
    if gaps.is_empty() {
        misses.push("no deadline_gap rows in the bench log".into());
        return;
    }
    let mut by: Vec<(String, u64, u64, u64, u64)> = Vec::new();
    for r in &gaps {
        if field(r, "reported") != Some("true") {
            misses.push(format!(
                "deadline_gap {}: the processor did not report the expiry",
                field(r, "name").unwrap_or("?")
            ));
        }
        let name = format!(
            "{}{} (2 × {})",
            field(r, "name").unwrap_or("?"),
            if field(r, "counting") == Some("true") {
                " with the counting rule"
            } else {
                ""
            },
            field(r, "n").unwrap_or("?")
        );
        let (g, o, l) = (num(r, "gap"), num(r, "overrun"), num(r, "lateness"));
        match by.iter_mut().find(|b| b.0 == name) {
            Some(b) => {
                b.1 = b.1.max(g);
                b.2 = b.2.max(o);
                b.3 = b.3.max(l);
            }
            None => by.push((name, g, o, l, num(r, "questions"))),
        }
    }
    by.sort_by_key(|b| std::cmp::Reverse(b.3));
    println!(
        "
lateness where it is worst (a limit just before each pair's four longest gaps between questions; every pair, the probes, `search_3+e_100`, at 2 × 256 and 2 × 512; each also with the counting rule for folded points on), the 8 latest:"
    );
    println!("| pair | questions | longest gap | overrun | lateness |");
    println!("|---|---:|---:|---:|---:|");
    for b in by.iter().take(8) {
        println!("| {} | {} | {} | {} | {} |", b.0, b.4, b.1, b.2, b.3);
    }
    for n in [256, 512] {
        let at: Vec<_> = by
            .iter()
            .filter(|b| b.0.ends_with(&format!("(2 × {n})")))
            .collect();
        println!(
            "at 2 × {n}: longest gap between two questions {}, largest overrun {}, largest lateness {} ({} pairs)",
            at.iter().map(|b| b.1).max().unwrap_or(0),
            at.iter().map(|b| b.2).max().unwrap_or(0),
            at.iter().map(|b| b.3).max().unwrap_or(0),
            at.len()
        );
    }
    let (lmax, omax) = (
        by.iter().map(|b| b.3).max().unwrap_or(0),
        by.iter().map(|b| b.2).max().unwrap_or(0),
    );
    println!(
        "largest lateness {lmax} instructions (budget ≤ {LATENESS}, the margin README quotes), largest overrun {omax}, over {} pairs: a limit of {} keeps every one within the deadline {deadline}",
        by.len(),
        deadline.saturating_sub(lmax)
    );
    if lmax > LATENESS {
        misses.push(format!(
            "the call within a deadline is {lmax} instructions late > {LATENESS} (README's margin)"
        ));
    }
}

/// The demo drive's fusion steps within a deadline (firmware
/// `fusion_within`: `Fusion::step_within`, SysTick as the clock at its
/// limit), against the same steps without one: per frame the step's
/// instructions, whether it was cut, the pair's `ok` points with and
/// without the cut and its `over_budget` points. Reported, not budgeted;
/// hard check: the rows are there.
fn drive_within(log: &str, deadline: u64, misses: &mut Vec<String>) {
    let rows = records(log, "fusion_within frame=");
    if rows.is_empty() {
        misses.push("no fusion_within rows in the bench log".into());
        return;
    }
    let full: BTreeMap<u64, u64> = records(log, "fusion frame=")
        .iter()
        .map(|r| (num(r, "frame"), num(r, "ok")))
        .collect();
    let limit = rows.first().map_or(0, |r| num(r, "limit"));
    println!(
        "
the demo drive's fusion steps within a deadline (`Fusion::step_within`, SysTick as the clock, limit {limit}; the fusion's own work after the matching is not cut):"
    );
    println!(
        "| frame | step | share of the deadline | cut | ok (without the deadline) | over_budget |"
    );
    println!("|---:|---:|---:|---|---:|---:|");
    let (mut worst, mut cut) = (0u64, 0usize);
    let (mut ok_within, mut ok_without) = (0u64, 0u64);
    for r in &rows {
        let f = num(r, "frame");
        let step = num(r, "step_instr");
        worst = worst.max(step);
        let is_cut = field(r, "cut") == Some("true");
        let ok = num(r, "ok");
        let without = full.get(&f).copied().unwrap_or(0);
        if is_cut {
            cut += 1;
        }
        if field(r, "paired") == Some("true") {
            ok_within += ok;
            ok_without += without;
            println!(
                "| {f} | {step} | {:.1} % | {} | {ok} ({without}) | {} |",
                100.0 * step as f64 / deadline as f64,
                if is_cut { "yes" } else { "" },
                num(r, "over_budget")
            );
        }
    }
    println!(
        "every step within {worst} instructions ({:.1} % of the deadline {deadline}; budget ≤ 100 %); {cut} steps cut; ok points over the drive's pairs {ok_within} within the deadline, {ok_without} without (after the first cut the key frames differ, so frames compare only roughly)",
        100.0 * worst as f64 / deadline as f64
    );
    if worst > deadline {
        misses.push(format!(
            "the demo drive within a deadline: a step of {worst} instructions > the deadline {deadline}"
        ));
    }
}

/// The demo drive's fusion steps with the counting rule for folded points
/// on (firmware `fusion_counted`: `Fusion::set_fold_counting`), against
/// the same steps without it: per paired frame the step's instructions and
/// the pair's `ok` and `folded` points. Reported, not budgeted (the rule
/// is off by default; the deadline's budgets are without it); hard check:
/// the rows are there.
fn drive_counted(log: &str, deadline: u64, misses: &mut Vec<String>) {
    let rows = records(log, "fusion_counted frame=");
    if rows.is_empty() {
        misses.push("no fusion_counted rows in the bench log".into());
        return;
    }
    let plain: BTreeMap<u64, (u64, u64, u64)> = records(log, "fusion frame=")
        .iter()
        .map(|r| {
            let f = num(r, "frame");
            (f, (num(r, "step_instr"), num(r, "ok"), num(r, "folded")))
        })
        .collect();
    println!(
        "
the demo drive's fusion steps with the counting rule for folded points (`Fusion::set_fold_counting`; off in every other figure):"
    );
    println!("| frame | step (without the rule) | share of the deadline | ok (without) | folded (without) |");
    println!("|---:|---:|---:|---:|---:|");
    let (mut worst, mut over) = (0u64, 0usize);
    let (mut ok, mut ok0, mut folded, mut folded0) = (0u64, 0u64, 0u64, 0u64);
    for r in &rows {
        if field(r, "paired") != Some("true") {
            continue;
        }
        let f = num(r, "frame");
        let step = num(r, "step_instr");
        let (s0, k0, f0) = plain.get(&f).copied().unwrap_or((0, 0, 0));
        worst = worst.max(step);
        over += usize::from(step > deadline);
        ok += num(r, "ok");
        ok0 += k0;
        folded += num(r, "folded");
        folded0 += f0;
        println!(
            "| {f} | {step} ({s0}) | {:.1} % | {} ({k0}) | {} ({f0}) |",
            100.0 * step as f64 / deadline as f64,
            num(r, "ok"),
            num(r, "folded")
        );
    }
    println!(
        "with the counting rule: every step within {worst} instructions ({:.1} % of the deadline {deadline}), {over} over it; ok points over the drive's pairs {ok} ({ok0} without the rule), folded {folded} ({folded0})",
        100.0 * worst as f64 / deadline as f64
    );
}

/// The demo drive's fusion steps with the sight check on (firmware
/// `fusion_sighted`: `FusionConfig::with_sight_check`), against the same
/// steps without it: per paired frame the fusion's and the map's own
/// instructions (the step less the matching of the run without it, the
/// same pair), per key-frame point, and the key frame's consistent,
/// widened and partly unseen points. Reported, not budgeted (the check is off by
/// default); hard check: the rows are there.
fn drive_sighted(log: &str, misses: &mut Vec<String>) {
    let rows = records(log, "fusion_sighted frame=");
    if rows.is_empty() {
        misses.push("no fusion_sighted rows in the bench log".into());
        return;
    }
    let plain: BTreeMap<u64, (u64, u64, u64, u64)> = records(log, "fusion frame=")
        .iter()
        .map(|r| {
            let f = num(r, "frame");
            (
                f,
                (
                    num(r, "step_instr"),
                    num(r, "matching_instr"),
                    num(r, "points"),
                    num(r, "map"),
                ),
            )
        })
        .collect();
    println!(
        "
the demo drive's fusion steps with the sight check on (`FusionConfig::with_sight_check`; off in every other figure):"
    );
    println!("| frame | step (without the check) | fusion and map (without) | per key-frame point (without) | consistent | widened | partly unseen | map points (without) |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|");
    let (mut worst, mut worst0) = (0u64, 0u64);
    for r in &rows {
        if field(r, "paired") != Some("true") {
            continue;
        }
        let f = num(r, "frame");
        let step = num(r, "step_instr");
        let (s0, m0, pts, map0) = plain.get(&f).copied().unwrap_or((0, 0, 1, 0));
        let own = step.saturating_sub(m0);
        let own0 = s0.saturating_sub(m0);
        let (pp, pp0) = (own / pts.max(1), own0 / pts.max(1));
        worst = worst.max(pp);
        worst0 = worst0.max(pp0);
        println!(
            "| {f} | {step} ({s0}) | {own} ({own0}) | {pp} ({pp0}) | {} | {} | {} | {} ({map0}) |",
            num(r, "consistent"),
            num(r, "widened"),
            num(r, "partly_unseen"),
            num(r, "map")
        );
    }
    let stack = records(log, "fusion_sighted_stack frame=")
        .iter()
        .map(|r| num(r, "bytes"))
        .max()
        .unwrap_or(0);
    println!(
        "with the sight check: the fusion and map's own work at most {worst} instructions a key-frame point ({worst0} without it); the stack of a step (frames 8 and 9) {stack} B"
    );
}

/// The adversarial family from the log, by member in log order.
fn adversarial_records(log: &str) -> Vec<(String, Vec<Adv>)> {
    let mut out: Vec<(String, Vec<Adv>)> = Vec::new();
    for r in records(log, "adversarial name=") {
        let name = field(&r, "name").unwrap_or("?").to_string();
        let a = Adv {
            n: num(&r, "n"),
            instr: num(&r, "instr"),
            per_point: num(&r, "per_point"),
            points: num(&r, "points"),
            processed: field(&r, "processed") == Some("true"),
            statuses: r
                .iter()
                .filter_map(|(k, v)| {
                    Some((k.strip_prefix("status.")?.to_string(), v.parse().ok()?))
                })
                .collect(),
        };
        match out.iter_mut().find(|(m, _)| *m == name) {
            Some((_, v)) => v.push(a),
            None => out.push((name, vec![a])),
        }
    }
    out
}

/// Least-squares slope of ln(instructions) on ln(N).
fn log_log_slope(rows: &[Adv]) -> f64 {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter(|a| a.n > 0 && a.instr > 0)
        .map(|a| ((a.n as f64).ln(), (a.instr as f64).ln()))
        .collect();
    let k = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / k;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / k;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    sxy / sxx
}

/// The adversarial family (issue 11): every member at every N, then per
/// member the per-point scaling N = 512 / N = 64 and the log-log slope;
/// budgets: the 2 × 256 worst case within the deadline, the scaling for
/// every member, every frame processed.
fn adversarial(log: &str, b: &Budget, misses: &mut Vec<String>) {
    let family = adversarial_records(log);
    if family.is_empty() {
        misses.push("the bench logged no adversarial member".into());
        return;
    }
    let deadline = b.deadline();
    println!(
        "\nadversarial family (issue 11; host_tests/src/drive/adversarial.rs), deadline {deadline} instructions:"
    );
    println!("| member | N | instructions per frame | per point | share of deadline | ok | budget-flagged | other statuses |");
    println!("|---|---:|---:|---:|---:|---:|---:|---|");
    for (name, rows) in &family {
        for a in rows {
            let others: Vec<String> = a
                .statuses
                .iter()
                .filter(|(n, c)| n != "ok" && !n.contains("budget") && *c > 0)
                .map(|(n, c)| format!("{n} {c}"))
                .collect();
            println!(
                "| {name} | {} | {} | {} | {:.0} % | {} | {} | {} |",
                a.n,
                a.instr,
                a.per_point,
                100.0 * a.instr as f64 / deadline as f64,
                a.status("ok"),
                a.budget_flagged(),
                others.join(", ")
            );
            if !a.processed {
                misses.push(format!("adversarial {name} N = {}: process failed", a.n));
            }
            if a.points != 2 * a.n {
                misses.push(format!(
                    "adversarial {name} N = {}: {} points, not 2 x N",
                    a.n, a.points
                ));
            }
        }
    }
    println!("\n| member | per point N = 64 | per point N = 512 | N = 512 / N = 64 (budget ≤ {:.2}) | log-log slope of cost vs N | 2 × 256 share of deadline |", b.scaling);
    println!("|---|---:|---:|---:|---:|---:|");
    let mut over_scaling = Vec::new();
    let mut worst: Option<(&str, u64)> = None;
    let mut over_deadline = 0;
    for (name, rows) in &family {
        let at = |n: u64| rows.iter().find(|a| a.n == n);
        let ratio = match (at(64), at(512)) {
            (Some(a), Some(c)) => Some(c.per_point as f64 / a.per_point.max(1) as f64),
            _ => {
                misses.push(format!("adversarial {name}: missing N = 64 or N = 512"));
                None
            }
        };
        let i256 = at(256).map(|a| a.instr);
        match i256 {
            Some(i) => {
                if worst.is_none_or(|w| i > w.1) {
                    worst = Some((name, i));
                }
                if i > deadline {
                    over_deadline += 1;
                }
            }
            None => misses.push(format!("adversarial {name}: missing N = 256")),
        }
        if let Some(r) = ratio.filter(|r| *r > b.scaling) {
            over_scaling.push(format!("{name} {r:.2}"));
        }
        println!(
            "| {name} | {} | {} | {} | {:.2} | {} |",
            at(64).map_or("-".into(), |a| a.per_point.to_string()),
            at(512).map_or("-".into(), |a| a.per_point.to_string()),
            ratio.map_or("-".into(), |r| format!("{r:.2}")),
            log_log_slope(rows),
            i256.map_or("-".into(), |i| format!(
                "{:.0} %",
                100.0 * i as f64 / deadline as f64
            ))
        );
    }
    if let Some((name, i)) = worst {
        println!(
            "adversarial 2 × 256 worst case: {i} instructions ({name}), {:.0} % of the deadline {deadline}; {over_deadline} of {} members over it",
            100.0 * i as f64 / deadline as f64,
            family.len()
        );
        if i > deadline {
            misses.push(format!(
                "{OPEN}adversarial 2 × 256 worst case: {i} instructions ({name}) > deadline {deadline} ({over_deadline} of {} members over it)",
                family.len()
            ));
        }
    }
    println!(
        "adversarial per-point scaling N = 512 / N = 64: {} of {} members over {:.2}",
        over_scaling.len(),
        family.len(),
        b.scaling
    );
    // Met from the fold test from the keys until the family gained the
    // members an adversarial review found (backward motion, forward
    // spirals about an FOE in the image, configured motion errors): open
    // again in issue 11.
    if !over_scaling.is_empty() {
        misses.push(format!(
            "{OPEN}adversarial per-point scaling N = 512 / N = 64 > {:.2}: {}",
            b.scaling,
            over_scaling.join(", ")
        ));
    }
}

/// The key-frame fusion over the demo drive (`fusion frame=…`): per frame
/// the step, the processor call inside it and the difference; the
/// per-point budget on every paired frame, the replay's agreement, the
/// representative frame plus the fusion against the deadline.
/// `filling`: the fusion's own work a key-frame point at its worst on the
/// drives whose map fills ([`fusion_filling`]), which the representative frame
/// with the fusion takes when it is the larger.
fn fusion_table(log: &str, per: &PerN, b: &Budget, filling: u64, misses: &mut Vec<String>) {
    let rows = records(log, "fusion frame=");
    if rows.is_empty() {
        misses.push("no fusion rows in the bench log".into());
        return;
    }
    println!(
        "
key-frame fusion over the demo drive (2 × 256 points, 8 partners, map of 2 × 512):"
    );
    println!(
        "| frame | key-frame points | step | of which matching | fusion and map | per point | |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---|");
    let (mut worst, mut total, mut points) = (0u64, 0u64, 0u64);
    let deadline = b.deadline();
    // The costliest paired frame's matching and step, and the steps over
    // the deadline.
    let (mut matching, mut step, mut over) = ((0u64, 0u64), (0u64, 0u64), 0usize);
    for r in &rows {
        let paired = field(r, "paired") == Some("true");
        let p = num(r, "points");
        let own = num(r, "fusion_instr");
        println!(
            "| {} | {p} | {} | {} | {own} | {} | {}{} |",
            num(r, "frame"),
            num(r, "step_instr"),
            num(r, "matching_instr"),
            if paired {
                own_per_point(r).to_string()
            } else {
                "–".into()
            },
            if field(r, "retired") == Some("true") {
                "a key frame retires"
            } else {
                ""
            },
            if paired { "" } else { "first frame: no pair" }
        );
        if field(r, "same_structure") != Some("true") {
            misses.push(format!(
                "fusion frame {}: the replayed processor call gave another structure",
                num(r, "frame")
            ));
        }
        if paired {
            worst = worst.max(own_per_point(r));
            total += own;
            points += p;
            let frame = num(r, "frame");
            matching = matching.max((num(r, "matching_instr"), frame));
            step = step.max((num(r, "step_instr"), frame));
            over += usize::from(num(r, "step_instr") > deadline);
        }
    }
    println!(
        "the demo drive's matching (the processor call of each paired step): at most {} instructions (frame {}), {:.1} % of the deadline {deadline} (budget ≤ 100 %)",
        matching.0,
        matching.1,
        100.0 * matching.0 as f64 / deadline as f64
    );
    // (Met since the block tree is built on a walk's first read: a hard
    // budget.)
    if matching.0 > deadline {
        misses.push(format!(
            "the demo drive's matching: {} instructions in frame {} > deadline {deadline}",
            matching.0, matching.1
        ));
    }
    println!(
        "the demo drive's steps with the fusion: at most {} instructions (frame {}), {:.1} % of the deadline; {over} of {} paired steps over it",
        step.0,
        step.1,
        100.0 * step.0 as f64 / deadline as f64,
        rows.iter().filter(|r| field(r, "paired") == Some("true")).count()
    );
    // (Met since a fresh key frame's first pair writes its unmatched
    // cells' counts only: a hard budget, as the matching's above.)
    if over > 0 {
        misses.push(format!(
            "the demo drive's steps with the fusion: {over} over the deadline {deadline} (at most {}, frame {})",
            step.0, step.1
        ));
    }
    println!(
        "fusion and map: worst paired frame {worst} instructions per key-frame point (budget ≤ {}), {:.1} on average",
        b.fusion_per_point,
        total as f64 / points.max(1) as f64
    );
    if worst > b.fusion_per_point {
        misses.push(format!(
            "fusion: {worst} instructions per point > budget {}",
            b.fusion_per_point
        ));
    }
    // The fusion at its worst over every drive (the filling drives' maps
    // fill, the demo drive's does not).
    let (worst, of) = if filling > worst {
        (filling, "a drive whose map fills")
    } else {
        (worst, "the demo drive's")
    };
    if let Some((i256, _)) = per.get(&256) {
        let with = i256 + worst * 512;
        println!(
            "the representative 2 × 256 frame with the fusion at its worst ({of}): {i256} + {worst} × 512 = {with} instructions, {:.0} % of the deadline {deadline}",
            100.0 * with as f64 / deadline as f64
        );
        let pp = costliest_point(per) + worst;
        println!(
            "  with the fusion, a representative frame of 2 × {} points fits the deadline ({pp} instructions a point; an integration limit, not a budget)",
            deadline / (2 * pp).max(1)
        );
        if with > deadline {
            // While the matching alone misses the deadline, issue 11 owns
            // this miss too; once it fits, the fusion must fit with it:
            // issue 13 owns it while its worst is a filling drive's (the
            // issue's "inside the frame deadline together with the
            // matching", open for the maps that fill), and with the demo
            // drive's it is a hard miss.
            let owner = if *i256 > deadline {
                OPEN
            } else if of == "a drive whose map fills" {
                OPEN_FUSION
            } else {
                ""
            };
            misses.push(format!(
                "{owner}2 × 256 frame with the fusion: {with} instructions > deadline {deadline}"
            ));
        }
    }
    for r in records(log, "fusion_stack ") {
        println!(
            "stack of one fusion step (frame {}): {} B",
            num(&r, "frame"),
            num(&r, "bytes")
        );
        if num(&r, "bytes") > b.stack {
            misses.push(format!(
                "fusion step stack {} B > {} B",
                num(&r, "bytes"),
                b.stack
            ));
        }
    }
}

/// The demo firmware's flash and RAM (`llvm-size`), the library's sizes
/// and the painted stack from the bench's log; the stack budget checked.
fn memory_table(
    log: &str,
    demo_elf: &Path,
    b: &Budget,
    misses: &mut Vec<String>,
) -> Result<(), String> {
    // The largest over the pairs painted: the representative and the
    // adversarial family at N = 256 (none logged: a miss).
    let (stack, stack_pair) = records(log, "stack per_frame_call=")
        .iter()
        .map(|r| {
            (
                num(r, "per_frame_call"),
                field(r, "pair").unwrap_or("?").to_string(),
            )
        })
        .max_by_key(|(b, _)| *b)
        .unwrap_or((u64::MAX, String::new()));
    let sizes: Record = records(log, "sizes ")
        .into_iter()
        .next()
        .unwrap_or_default();
    let size = capture(&tool("llvm-size")?, &["-A", &demo_elf.to_string_lossy()])?;
    let sec = |name: &str| -> u64 {
        size.lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|v| v.parse().ok())
            .unwrap_or(0)
    };
    let flash = sec(".vector_table") + sec(".text") + sec(".rodata") + sec(".data");
    let ram = sec(".data") + sec(".bss") + sec(".uninit");
    println!("\n| memory (demo firmware, linked ELF) | bytes |");
    println!("|---|---:|");
    println!("| flash: .vector_table + .text + .rodata (+ .data image) | {flash} |");
    println!(
        "|   of which .rodata (incl. the embedded 24-frame drive) | {} |",
        sec(".rodata")
    );
    println!("| RAM: .data + .bss | {ram} |");
    println!(
        "| `Processor<256, 2>` (state + output + search index) | {} |",
        num(&sizes, "processor_256_2")
    );
    println!(
        "|   `Frame<256, 2>` kept as the previous frame | {} |",
        num(&sizes, "frame_256_2")
    );
    println!(
        "|   `Structure<256, 2>` output | {} |",
        num(&sizes, "structure_256_2")
    );
    println!("|   search index | {} |", num(&sizes, "search_256"));
    let fusion: Record = records(log, "fusion_memory ")
        .into_iter()
        .next()
        .unwrap_or_default();
    let whole = num(&fusion, "fusion_256_2_512");
    let own = whole.saturating_sub(num(&fusion, "processor_256_2"));
    println!("| `Fusion<256, 2, 512>` (processor + fusion state + road map) | {whole} |");
    println!(
        "|   fusion state + road map, beside the processor (budget ≤ {}) | {own} |",
        b.fusion_bytes
    );
    println!(
        "|     `KeyFrame<256, 2>` | {} |",
        num(&fusion, "key_frame_256_2")
    );
    println!("|     `RoadMap<2, 512>` | {} |", num(&fusion, "map_2_512"));
    println!(
        "| worst-case stack of one per-frame call (painted; the largest over the representative pair and the adversarial family at N = 256: `{stack_pair}`) | {stack} |"
    );
    // The fusion (with its processor) is a static in .data (not zero: its
    // initial image is in flash); on main's stack the input frame, the
    // median's scratch (`widths`, 512 f32) and one fusion step, the
    // deepest call the demo makes (it includes the per-frame call).
    const DEMO_WIDTHS: u64 = 512 * 4;
    let step_stack = records(log, "fusion_stack ")
        .iter()
        .map(|r| num(r, "bytes"))
        .max()
        .unwrap_or(u64::MAX);
    let needed = ram
        .saturating_add(num(&sizes, "frame_256_2"))
        .saturating_add(DEMO_WIDTHS)
        .saturating_add(step_stack.max(stack));
    println!(
        "| RAM the demo needs: .data + .bss (the fusion with its processor, a static) + one frame and the median's scratch (on main's stack) + the larger of one fusion step's stack and one per-frame call's | {needed} |"
    );
    // The smaller board's RAM (src/bin/fw/boards/stm32f405.x).
    const F405_RAM: u64 = 128 * 1024;
    if needed > F405_RAM {
        misses.push(format!(
            "the demo needs {needed} B of RAM > the STM32F405's {F405_RAM} B"
        ));
    }
    if stack > b.stack {
        misses.push(format!("stack {stack} B > {} B", b.stack));
    }
    if whole == 0 || own > b.fusion_bytes {
        misses.push(format!(
            "fusion state + road map {own} B > {} B",
            b.fusion_bytes
        ));
    }
    Ok(())
}

/// No software double precision (`__aeabi_d*`) and no allocator symbols in
/// the given firmware (`llvm-nm`).
fn symbol_checks(elfs: &[&Path], misses: &mut Vec<String>) -> Result<(), String> {
    let mut found = Vec::new();
    for elf in elfs {
        let syms = capture(&tool("llvm-nm")?, &[&elf.to_string_lossy()])?;
        let bad_f64: Vec<&str> = syms.lines().filter(|l| l.contains("__aeabi_d")).collect();
        if !bad_f64.is_empty() {
            found.push(format!(
                "{}: software f64 linked: {bad_f64:?}",
                elf.display()
            ));
        }
        let alloc: Vec<&str> = syms
            .lines()
            .filter(|l| {
                l.contains("__rust_alloc") || l.contains("__rg_alloc") || l.contains("__rdl_alloc")
            })
            .collect();
        if !alloc.is_empty() {
            found.push(format!("{}: allocator linked: {alloc:?}", elf.display()));
        }
    }
    println!(
        "no __aeabi_d* (software f64) and no allocator symbols in the demo and bench firmware: {}",
        if found.is_empty() { "ok" } else { "FAILED" }
    );
    misses.extend(found);
    Ok(())
}

/// A fusion row's own work a key-frame point, rounded **up** (the
/// firmware's `per_point` is rounded down): `≤ budget` is then exactly
/// `fusion_instr ≤ budget · points`. (Until the twenty-first session the
/// budgets took the firmware's, so 80.25 passed as 80.)
fn own_per_point(r: &[(String, String)]) -> u64 {
    num(r, "fusion_instr").div_ceil(num(r, "points").max(1))
}

/// The drives whose road map fills (firmware `fusion_filling`), so that
/// each retiring key frame drops the oldest points for room: sideways,
/// straight and turning, forwards zigzagging (the room made in a batch
/// the camera is passing), and sideways on a road whose edges move every
/// frame (the pairs disagree: the pass's conflicts; an adversarial input
/// whose miss issue 13 owns, not in the returned worst). The fusion's own work a key-frame point, its
/// worst over the paired steps of each, against the same budget as the
/// demo drive's, enforced (until the twenty-third session issue 13 owned
/// the miss, the forward drive's 97.8), and the worst step's own work in
/// instructions (what a caller of `Fusion::step_within` leaves room for);
/// with the sight check, reported.
/// Returns the default policy's worst per key-frame point over the drives
/// (0 if none).
fn fusion_filling(log: &str, b: &Budget, misses: &mut Vec<String>) -> u64 {
    let rows = records(log, "fusion_filling run=");
    if rows.is_empty() {
        misses.push("no fusion_filling rows in the bench log".into());
        return 0;
    }
    let mut worst_default = 0;
    println!(
        "
the fusion over drives whose road map fills (Fusion<256, 2, 512>, 80 frames, turning back every 8 frames; `default`, `sight_check`: 0.05 a frame across a straight road; `turning`: the camera also turns 0.005 rad a frame, back and forth with the motion; `forward`: 0.2 forwards and 0.12 across a frame over a road 2.4 wide, turning 0.003 rad a frame; `wobbling`: `default` on a road whose edges move 0.1 across every frame, out and back, so the pairs disagree (adversarial); `jumping`: 0.08 a frame across a road whose edges but their 22 nearest points jump by up to 0.25 within each 8 frames, so most pairs disagree in a retiring step too (adversarial); `wobbling_forward`: 0.094 across and 0.067 forwards a frame, turning, on a road still for 32 frames and wobbling as `wobbling`'s after (adversarial); `small_90`, `small_32`: `default` with 90 and 32 points a boundary; `partners_2`, `partners_1`: `default` with a key frame every 2 frames and every frame; `shrinking`: `default` on rows 300–478 with 256 and 90 points a boundary by turns every 8 frames, so a retirement's rest enters in the first step of a key frame a third as large; `partners_1_near`: `partners_1` on rows 300–478, every matched point admitted; `partners_1_split`: the same from the near row on, consecutive frames sharing few rows for 17 frames, the map in small batches (issue 13 owns the miss of `small_32`, a step's constant part over fewer points, and of `shrinking` and `partners_1_split`, two of an adversary's three (twenty-eighth session): a retirement's rest over a smaller key frame, more entries in a step with the map in small batches; `small_90`, `partners_2`, `partners_1` and `partners_1_near` meet the budget and are enforced)):"
    );
    println!("| policy | paired steps | map full from frame | worst own work a step (frame) | its key-frame points | per point | worst per point (frame) | of a retiring step: entered / dropped |");
    println!("|---|---:|---:|---:|---:|---:|---:|---|");
    for run in [
        "default",
        "sight_check",
        "turning",
        "forward",
        "wobbling",
        "jumping",
        "wobbling_forward",
        "small_90",
        "small_32",
        "partners_2",
        "partners_1",
        "shrinking",
        "partners_1_near",
        "partners_1_split",
    ] {
        let mine: Vec<_> = rows
            .iter()
            .filter(|r| field(r, "run") == Some(run) && field(r, "paired") == Some("true"))
            .collect();
        if mine.is_empty() {
            misses.push(format!("no paired fusion_filling rows of {run}"));
            continue;
        }
        for r in &mine {
            if field(r, "same_structure") != Some("true") {
                misses.push(format!(
                    "fusion_filling {run} frame {}: the replayed processor call gave another structure",
                    num(r, "frame")
                ));
            }
        }
        let by_own = mine.iter().max_by_key(|r| num(r, "fusion_instr")).copied();
        let by_point = mine.iter().max_by_key(|r| own_per_point(r)).copied();
        let full = mine
            .iter()
            .find(|r| num(r, "dropped") > 0)
            .map_or("–".to_string(), |r| num(r, "frame").to_string());
        let (Some(o), Some(p)) = (by_own, by_point) else {
            continue;
        };
        println!(
            "| {run} | {} | {full} | {} ({}) | {} | {} | {} ({}) | {} / {} |",
            mine.len(),
            num(o, "fusion_instr"),
            num(o, "frame"),
            num(o, "points"),
            own_per_point(o),
            own_per_point(p),
            num(p, "frame"),
            num(o, "entered"),
            num(o, "dropped"),
        );
        // (The wobbling and jumping roads' pairs disagree: adversarial
        // inputs, kept out of the representative frame's figure with the
        // fusion, as the sight check is; their budget is enforced since
        // the twenty-fourth session's exact rival intervals and a
        // retirement's share cut by its pass's conflicts.)
        let adversarial = matches!(run, "wobbling" | "jumping" | "wobbling_forward");
        // (Smaller key frames, key frames that shrink, and a key frame
        // every frame or every 2 frames. None of the seven is the
        // representative frame's key frames. Issue 13 owns the miss of
        // `small_32` and of two of the twenty-eighth session's adversary's
        // three drives; `partners_2` meets the budget and is enforced,
        // `small_90` and `partners_1` too since the twenty-eighth
        // session's cheaper entries, `partners_1_near` since the
        // twenty-ninth's entry codes.)
        let open = matches!(run, "small_32" | "shrinking" | "partners_1_split");
        let fewer = open
            || matches!(
                run,
                "small_90" | "partners_2" | "partners_1" | "partners_1_near"
            );
        if run != "sight_check" && !adversarial && !fewer {
            worst_default = worst_default.max(own_per_point(p));
        }
        if run != "sight_check" {
            // (A drive whose map no longer fills would measure the case it
            // is for no more, and the owned miss below would vanish: a
            // hard miss.)
            if full == "–" {
                misses.push(format!(
                    "fusion_filling {run}: no retiring key frame dropped points for room (the map never filled)"
                ));
            }
        }
        if run != "sight_check" && own_per_point(p) > b.fusion_per_point {
            misses.push(format!(
                "{}fusion over a drive whose map fills, {run}: {} instructions per key-frame point (frame {}) > budget {}",
                if open { OPEN_FUSION } else { "" },
                own_per_point(p),
                num(p, "frame"),
                b.fusion_per_point
            ));
        }
    }
    worst_default
}

/// Every missed budget, then the verdict: a miss an open issue owns
/// ([`OPEN`], [`OPEN_FUSION`]) is printed and does not fail; any other fails.
fn verdict(misses: &[String], b: &Budget) -> Result<(), String> {
    for m in misses {
        println!("xtask: budget NOT MET: {m}");
    }
    let hard: Vec<&String> = misses.iter().filter(|m| !owned(m)).collect();
    if !hard.is_empty() {
        return Err(hard
            .iter()
            .map(|m| m.as_str())
            .collect::<Vec<_>>()
            .join("; "));
    }
    if !misses.is_empty() {
        println!(
            "xtask: {} budget(s) not met and owned by an open issue (printed above, not enforced until it lands); every other budget met",
            misses.len()
        );
        return Ok(());
    }
    println!(
        "xtask: all budgets met (≤ {} instructions per point at every N, ≤ {} at N = 256, scaling, deadline, the adversarial family's worst case and scaling, the fusion ≤ {} per point and ≤ {} B, the link decoder ≤ 60 per point, stack, no f64, no allocator, panic-never)",
        b.per_point, b.per_point_256, b.fusion_per_point, b.fusion_bytes
    );
    Ok(())
}

/// The link decoder's budget (issue 12): at most this many instructions
/// per point for decode + CRC + validation of a whole frame packet.
const WIRE_PER_POINT: f64 = 60.0;

/// The link decoder's cost (issue 12): the bench firmware's `wire` line,
/// the packet decoded correctly and within [`WIRE_PER_POINT`].
fn wire_table(log: &str, misses: &mut Vec<String>) {
    let Some(w) = records(log, "wire points=").into_iter().next() else {
        misses.push("the bench logged no `wire` line".into());
        return;
    };
    if field(&w, "ok") != Some("true") {
        misses.push("the link decoder decoded the bench's frame packet wrongly".into());
    }
    let (points, bytes) = (num(&w, "points").max(1), num(&w, "packet_bytes").max(1));
    let per = |k: &str| num(&w, k) as f64 / points as f64;
    let per_byte = |k: &str| num(&w, k) as f64 / bytes as f64;
    println!();
    println!(
        "Link decoder, one 2 x {} frame packet ({} bytes, {} on the link), decoded {}:",
        points / 2,
        bytes,
        num(&w, "link_bytes"),
        if field(&w, "ok") == Some("true") {
            "correctly"
        } else {
            "WRONGLY"
        }
    );
    println!("| what | instructions | per point | per byte |");
    println!("|---|---:|---:|---:|");
    for (name, k) in [
        (
            "decode (COBS + CRC + parse + validation), whole packet in one feed",
            "decode",
        ),
        (
            "decode, fed in the UART driver's 64-byte chunks",
            "decode_chunked",
        ),
        ("CRC-32 alone, no table (0 B of table)", "crc_none"),
        (
            "CRC-32 alone, 1 table (1 KiB; the library's choice)",
            "crc_table1",
        ),
        ("CRC-32 alone, 16 tables (16 KiB)", "crc_table16"),
    ] {
        println!(
            "| {name} | {} | {:.1} | {:.1} |",
            num(&w, k),
            per(k),
            per_byte(k)
        );
    }
    let d = per("decode");
    println!(
        "decode + CRC + validation: {d:.1} instructions per point (budget ≤ {WIRE_PER_POINT}); decoder state {} B",
        num(&w, "decoder_bytes")
    );
    if d > WIRE_PER_POINT {
        misses.push(format!(
            "link decoder: {d:.1} instructions per point > budget {WIRE_PER_POINT}"
        ));
    }
}
