//! `cargo xtask bench`: instruction counts, stage costs, stack, memory
//! figures and the link-time proofs, every budget hard.
//!
//! The steps, in the order they print: build the three firmware binaries
//! (the `nopanic` link is itself a proof), run the bench firmware, the
//! budget table (instructions per point at every N), the stress pairs, the
//! scaling and deadline checks, the stage costs, the memory table, the
//! symbol checks, and the verdict.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::firmware::{build_firmware, field, num, records, run_firmware, Record};
use crate::setup::setup_emulator;
use crate::util::{capture, tool};

pub const BENCH_USAGE: &str =
    "usage: cargo xtask bench [--frame-ms 33] [--cpu-mhz 168] [--share-percent 5] [--per-point 400]
  every budget is hard (exit code 1 when one is missed): instructions per point at every N,
  per-point scaling N = 512 / N = 64 <= 1.25, the 2 x 256 frame within share-percent of a
  frame-ms frame at cpu-mhz (one instruction = one cycle), stack <= 4 KiB, no software f64,
  no allocator, the panic-never link";

/// The bench's budgets (`--help` lists the knobs).
pub struct Budget {
    per_point: u64,
    frame_ms: f64,
    cpu_mhz: f64,
    share_percent: f64,
    stack: u64,
    scaling: f64,
}

impl Budget {
    /// Instructions one frame may take: `share_percent` of a `frame_ms`
    /// frame at `cpu_mhz`, one instruction = one cycle.
    fn deadline(&self) -> u64 {
        (self.frame_ms * 1e-3 * self.cpu_mhz * 1e6 * self.share_percent / 100.0) as u64
    }
}

/// The budgets from the command line (defaults: 400 per point, 5 % of a
/// 33 ms frame at 168 MHz, 4 KiB of stack, scaling 1.25).
pub fn bench_args(args: &[String]) -> Result<Budget, String> {
    let mut b = Budget {
        per_point: 400,
        frame_ms: 33.0,
        cpu_mhz: 168.0,
        share_percent: 5.0,
        stack: 4096,
        scaling: 1.25,
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
            _ => return Err(BENCH_USAGE.into()),
        }
    }
    Ok(b)
}

/// Per N: (instructions per frame, per point).
type PerN = BTreeMap<u64, (u64, u64)>;

/// `cargo xtask bench`. Every budget is hard: any miss fails the task (and
/// CI), after every table is printed.
pub fn bench(b: &Budget) -> Result<(), String> {
    setup_emulator()?;
    let (elf, demo_elf) = build()?;
    let log = run_firmware(&elf)?;
    let mut misses = Vec::new();
    let per = budget_table(&log, b, &mut misses);
    stress_table(&log);
    scaling_and_deadline(&per, b, &mut misses);
    stage_costs(&log);
    memory_table(&log, &demo_elf, b, &mut misses)?;
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
                "N = {n}: {pp} instructions per point > budget {}",
                b.per_point
            ));
        }
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
        if *i256 > deadline {
            misses.push(format!(
                "2 × 256 frame: {i256} instructions > deadline {deadline}"
            ));
        }
    }
}

/// Where the N = 256 frame's instructions go, stage by stage.
fn stage_costs(log: &str) {
    println!("\nwhere the instructions go (N = 256, through the public API):");
    for s in records(log, "stage name=") {
        println!(
            "  {:22} {:>9} instructions, {:>4} per point",
            field(&s, "name").unwrap_or("?"),
            num(&s, "instr"),
            num(&s, "per_point")
        );
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
    let stack = records(log, "stack per_frame_call=")
        .first()
        .map(|r| num(r, "per_frame_call"))
        .unwrap_or(u64::MAX);
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
    println!("| worst-case stack of one per-frame call (painted) | {stack} |");
    println!(
        "| RAM the demo needs: .data + .bss + processor + one frame (both on main's stack) + one call's stack | {} |",
        ram + num(&sizes, "processor_256_2") + num(&sizes, "frame_256_2") + stack
    );
    if stack > b.stack {
        misses.push(format!("stack {stack} B > {} B", b.stack));
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

/// Every missed budget, then the verdict.
fn verdict(misses: &[String], b: &Budget) -> Result<(), String> {
    for m in misses {
        println!("xtask: budget NOT MET: {m}");
    }
    if !misses.is_empty() {
        return Err(misses.join("; "));
    }
    println!(
        "xtask: all budgets met (≤ {} instructions per point at every N, scaling, deadline, stack, no f64, no allocator, panic-never)",
        b.per_point
    );
    Ok(())
}
