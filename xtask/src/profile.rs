//! `cargo xtask profile`: where a per-frame call's instructions go.
//!
//! Run the `profile` firmware on QEMU with an execution trace
//! (`-singlestep -d exec,nochain`: one trace line per instruction). The
//! firmware processes a list of named windows (`src/bin/profile.rs`), each
//! one per-frame call between two entries into `marker`; window `k` is the
//! code between the entries `2k + 1` and `2k + 2`, and the firmware logs its
//! name and point count. For each window, count the instructions executed
//! at each address and attribute them with `llvm-objdump -d -l` to
//! functions and (innermost, inlined) source lines.
//! Beside the instructions it reports an estimate of Cortex-M4F cycles
//! (the model and its sources: [`crate::cycles`]), priced instruction by
//! instruction along the trace: the instruction sizes from the disassembly
//! give each one's fall-through address, and a branch is taken when the
//! next traced pc is elsewhere.
//!
//! The steps: trace, disassembly map, counting (instructions and cycles),
//! tables, annotation, and the budget: the `representative` window's
//! estimated cycles per point at most [`CYCLES_PER_POINT`] (issue 11: no
//! rise above the 718 measured when the estimate was introduced; override
//! with `--cycles-per-point`), a hard failure after everything is printed.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::cycles::{Class, Model, Tally, SUMMARY};
use crate::disasm::{disassemble, Disassembly};
use crate::firmware::{build_firmware, build_firmware_with, field, num, records, Board};
use crate::setup::setup_emulator;
use crate::util::root;

/// What one instruction address executed: how often, at what estimated
/// cost.
#[derive(Clone, Copy, Default)]
struct Cost {
    instructions: u64,
    cycles: u64,
}

impl Cost {
    fn add(&mut self, other: Cost) {
        self.instructions += other.instructions;
        self.cycles += other.cycles;
    }
}

/// Executions and cycles per instruction address.
type Counts = BTreeMap<u64, Cost>;

/// One traced window: what the firmware logged about it, and what it
/// executed.
struct Window {
    name: String,
    points: u64,
    digest: String,
    counts: Counts,
    tally: Tally,
}

impl Window {
    fn per_point(&self, c: u64) -> f64 {
        c as f64 / self.points.max(1) as f64
    }
}

/// The representative window's budget: estimated Cortex-M4F cycles per
/// point (issue 11; owned by it, reported while missed).
pub const CYCLES_PER_POINT: f64 = 718.0;

/// Issue 11: the representative window's estimate "must not rise above
/// today's": the figure when the estimate landed and every round since
/// kept, enforced (a rise fails the task, and CI) while the budget above
/// is open.
pub const CYCLES_CEILING: f64 = 953.3;

/// The window the budget applies to (`src/bin/profile.rs`).
pub const REPRESENTATIVE: &str = "representative";

pub const PROFILE_USAGE: &str = "usage: cargo xtask profile [--cycles-per-point 718] [--fusion]
  traces every window of the profile firmware (src/bin/profile.rs) and reports instructions and
  estimated Cortex-M4F cycles (xtask/src/cycles.rs) per function, per source line and per window;
  budget, owned by open issue 11 (printed as not met, not enforced until the issue lands): the
  `representative` window (the bench's N = 256 pair) at most cycles-per-point (718) estimated
  cycles per point; hard (exit code 1): that window's estimate at most 953.3 cycles per point,
  the figure issue 11 says must not rise.
  --fusion: the firmware with feature profile-fusion, one window more, `fusion_13`: the bench's
  demo fusion step of frame 13 whole (the matching, the fusion and the map). A second
  monomorphisation lays the other windows' code out anew (the representative's estimate moves by
  a few cycles a point), so the budgets are not checked in that build: a tool, not a figure.";

/// What `cargo xtask profile` was asked for.
pub struct ProfileArgs {
    budget: f64,
    fusion: bool,
}

impl ProfileArgs {
    /// The default run: the budget of issue 11, without the fusion window.
    pub const DEFAULT: Self = Self {
        budget: CYCLES_PER_POINT,
        fusion: false,
    };
}

/// The budget from the command line.
pub fn profile_args(args: &[String]) -> Result<ProfileArgs, String> {
    let mut budget = CYCLES_PER_POINT;
    let mut fusion = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--fusion" => fusion = true,
            "--cycles-per-point" => {
                budget = it
                    .next()
                    .and_then(|v| v.parse().ok())
                    .ok_or(format!("{a} needs a number"))?
            }
            _ => return Err(PROFILE_USAGE.into()),
        }
    }
    Ok(ProfileArgs { budget, fusion })
}

/// `cargo xtask profile`: trace the firmware, map its disassembly, count
/// each window, print each window's summary and tables, the table of all
/// windows and the cycle model, write the annotated disassembly, and check
/// the representative window's cycles per point against `budget`.
pub fn profile(args: ProfileArgs) -> Result<(), String> {
    let ProfileArgs { budget, fusion } = args;
    setup_emulator()?;
    let elf = if fusion {
        build_firmware_with("profile", Board::Mps2, "profile-fusion")?
    } else {
        build_firmware("profile")?
    };
    let dir = root().join("target").join("profile");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let (log, trace_path) = trace(&elf, &dir)?;
    let dis = disassemble(&elf)?;
    let counted = count(&trace_path, &dis, &log);
    // (The trace is several GB, 11 with `--fusion`, and read only here: it
    // goes either way, so that runs do not fill the disk.)
    let _ = std::fs::remove_file(&trace_path);
    let windows = counted?;
    let mut funcs = Vec::new();
    for w in &windows {
        summary(w);
        for f in function_table(&dis, w) {
            if !funcs.contains(&f) {
                funcs.push(f);
            }
        }
        line_table(&dis, w);
    }
    window_table(&windows);
    println!("\n{SUMMARY}");
    annotate(&dis, &windows, &funcs, &dir.join("annotated.txt"))?;
    if fusion {
        println!("\nxtask: built with profile-fusion (--fusion): the budgets are not checked in this build");
        return Ok(());
    }
    cycles_budget(&windows, budget)
}

/// The representative window's estimated cycles per point against the
/// budget (printed either way).
fn cycles_budget(windows: &[Window], budget: f64) -> Result<(), String> {
    let Some(w) = windows.iter().find(|w| w.name == REPRESENTATIVE) else {
        return Err(format!("no `{REPRESENTATIVE}` window in the profile"));
    };
    let per = w.per_point(w.tally.cycles);
    let met = per <= budget;
    println!(
        "\nxtask: `{REPRESENTATIVE}` window: {per:.1} estimated Cortex-M4F cycles per point (budget ≤ {budget}): {}",
        if met { "met" } else { "NOT MET" }
    );
    if !met {
        // Owned by an open issue: printed, not enforced until it lands.
        println!(
            "xtask: budget NOT MET: {}`{REPRESENTATIVE}` window {per:.1} estimated cycles per point > {budget}",
            crate::bench::OPEN
        );
    }
    // The ceiling is enforced: printed to one decimal, compared so.
    if (per * 10.0).round() > (CYCLES_CEILING * 10.0).round() {
        return Err(format!(
            "`{REPRESENTATIVE}` window: {per:.1} estimated cycles per point rose above {CYCLES_CEILING} (issue 11: must not rise)"
        ));
    }
    println!("xtask: `{REPRESENTATIVE}` window within the ceiling of {CYCLES_CEILING} estimated cycles per point (issue 11: must not rise): met");
    Ok(())
}

/// A window's instructions and estimated cycles, in total and per point,
/// and its mix per point.
fn summary(w: &Window) {
    let t = &w.tally;
    let per = |c: u64| w.per_point(c);
    println!(
        "\nwindow `{}`: one per-frame call ({} points, digest {}): {} instructions, {:.1} per point; estimated {} Cortex-M4F cycles, {:.1} per point ({:.2} per instruction)",
        w.name,
        w.points,
        w.digest,
        t.instructions,
        per(t.instructions),
        t.cycles,
        per(t.cycles),
        t.cpi()
    );
    println!(
        "per point: {:.1} VDIV/VSQRT ({:.0} cycles), {:.1} loads, {:.1} taken branches",
        per(t.div_sqrt),
        per(t.div_sqrt * crate::cycles::DIV_SQRT),
        per(t.loads),
        per(t.taken)
    );
}

/// Every window in one table, per point.
fn window_table(windows: &[Window]) {
    println!("\n| window | points | instructions | instr/point | est. cycles | cycles/point | cycles/instr | VDIV+VSQRT/point | loads/point | taken branches/point |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for w in windows {
        let t = &w.tally;
        println!(
            "| {} | {} | {} | {:.1} | {} | {:.1} | {:.2} | {:.1} | {:.1} | {:.1} |",
            w.name,
            w.points,
            t.instructions,
            w.per_point(t.instructions),
            t.cycles,
            w.per_point(t.cycles),
            t.cpi(),
            w.per_point(t.div_sqrt),
            w.per_point(t.loads),
            w.per_point(t.taken)
        );
    }
}

/// Run the firmware on QEMU, one trace line per executed instruction into
/// `dir/trace.log` (removed once counted, [`profile`]); return the
/// decoded defmt log (echoed) and the trace's path.
fn trace(elf: &Path, dir: &Path) -> Result<(String, PathBuf), String> {
    let elf_s = elf.to_string_lossy().to_string();
    let trace = dir.join("trace.log");
    println!(
        "xtask: tracing {} on QEMU (one line per instruction)",
        elf.display()
    );
    let out = Command::new("bash")
        .args([
            "-c",
            "set -o pipefail; qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
             -semihosting-config enable=on,target=native -icount shift=5 \
             -singlestep -d exec,nochain -D \"$2\" -kernel \"$1\" | defmt-print -e \"$1\"",
            "profile",
            &elf_s,
            &trace.to_string_lossy(),
        ])
        .output()
        .map_err(|e| format!("cannot start QEMU: {e}"))?;
    let log = String::from_utf8_lossy(&out.stdout).to_string();
    print!("{log}");
    if !out.status.success() {
        return Err(format!("profile firmware failed ({})", out.status));
    }
    Ok((log, trace))
}

/// The pc of a trace line `Trace 0: 0x… [flags/pc/…] symbol` (other lines:
/// none).
fn trace_pc(line: &str) -> Option<u64> {
    line.split_once('[')
        .and_then(|(_, r)| r.split('/').nth(1))
        .and_then(|h| u64::from_str_radix(h, 16).ok())
}

/// The windows the firmware logged (`profile window=k name=… points=…`),
/// in order, with nothing counted yet.
fn logged_windows(log: &str) -> Result<Vec<Window>, String> {
    let windows: Vec<Window> = records(log, "profile window=")
        .iter()
        .enumerate()
        .map(|(k, r)| Window {
            name: field(r, "name").map_or_else(|| format!("window {k}"), str::to_string),
            points: num(r, "points"),
            digest: field(r, "digest").unwrap_or("?").to_string(),
            counts: Counts::new(),
            tally: Tally::default(),
        })
        .collect();
    if windows.is_empty() {
        return Err("the profile firmware logged no window".into());
    }
    Ok(windows)
}

/// Executions and estimated cycles per address in each window, and their
/// tally, reading the trace line by line (it holds every instruction the
/// firmware ran). An instruction is priced when the next one is traced:
/// that says whether it was a taken branch.
fn count(trace: &Path, dis: &Disassembly, log: &str) -> Result<Vec<Window>, String> {
    let mut windows = logged_windows(log)?;
    let err = |e: std::io::Error| format!("{}: {e}", trace.display());
    let mut reader = BufReader::new(File::open(trace).map_err(err)?);
    let mut line = String::new();
    let mut model = Model::default();
    // The window being traced, and its last instruction, not yet priced.
    let mut inside: Option<usize> = None;
    let mut pending: Option<u64> = None;
    let mut entries = 0;
    while entries < 2 * windows.len() {
        line.clear();
        if reader.read_line(&mut line).map_err(err)? == 0 {
            break;
        }
        let Some(pc) = trace_pc(&line) else {
            continue;
        };
        if let (Some(k), Some(prev)) = (inside, pending.take()) {
            let (class, fall_through) = dis
                .code
                .get(&prev)
                .map_or((Class::Other, prev + 2), |i| (i.class, i.fall_through));
            let taken = pc != fall_through;
            let cycles = model.step(class, taken);
            let w = &mut windows[k];
            w.tally.add(class, taken, cycles);
            w.counts.entry(prev).or_default().add(Cost {
                instructions: 1,
                cycles,
            });
        }
        if pc == dis.marker {
            entries += 1;
            // Odd entries open window (entries - 1) / 2, even ones close it.
            inside = (entries % 2 == 1).then_some(entries / 2);
            model = Model::default();
        } else if inside.is_some() {
            pending = Some(pc);
        }
    }
    if entries < 2 * windows.len() {
        return Err(format!(
            "the trace holds {entries} marker calls, the {} logged windows need {} \
             (a truncated trace: it takes several GB, 11 with --fusion; is the disk full?)",
            windows.len(),
            2 * windows.len()
        ));
    }
    Ok(windows)
}

/// Instructions and estimated cycles per (not inlined) function, most
/// instructions first; returns the functions in that order.
fn function_table<'a>(dis: &'a Disassembly, w: &Window) -> Vec<&'a str> {
    let mut by_func = BTreeMap::<&str, Cost>::new();
    for (a, c) in &w.counts {
        let f = dis.code.get(a).map_or("?", |i| i.func.as_str());
        by_func.entry(f).or_default().add(*c);
    }
    let mut funcs: Vec<_> = by_func.into_iter().collect();
    funcs.sort_by_key(|f| std::cmp::Reverse(f.1.instructions));
    let per = |c: u64| w.per_point(c);
    println!(
        "\n| function (not inlined) | instructions | instr/point | est. cycles | cycles/point |"
    );
    println!("|---|---:|---:|---:|---:|");
    for (f, c) in &funcs {
        println!(
            "| `{f}` | {} | {:.1} | {} | {:.1} |",
            c.instructions,
            per(c.instructions),
            c.cycles,
            per(c.cycles)
        );
    }
    funcs.into_iter().map(|(f, _)| f).collect()
}

/// The 30 source lines with the most instructions (innermost, inlined code
/// included), each with the function it was inlined into.
fn line_table(dis: &Disassembly, w: &Window) {
    let mut by_line = BTreeMap::<(&str, &str), Cost>::new();
    for (a, c) in &w.counts {
        let (f, l) = dis
            .code
            .get(a)
            .map_or(("?", "?"), |i| (i.func.as_str(), i.line.as_str()));
        by_line.entry((l, f)).or_default().add(*c);
    }
    let mut lines: Vec<_> = by_line.into_iter().collect();
    lines.sort_by_key(|l| std::cmp::Reverse(l.1.instructions));
    let per = |c: u64| w.per_point(c);
    println!("\n| source line (innermost, inlined code included) | in function | instr/point | cycles/point |");
    println!("|---|---|---:|---:|");
    for ((l, f), c) in lines.iter().take(30) {
        println!(
            "| {l} | `{f}` | {:.1} | {:.1} |",
            per(c.instructions),
            per(c.cycles)
        );
    }
}

/// Every executed function's disassembly with the executions and
/// estimated cycles of each instruction in each window, side by side,
/// written to `path`.
fn annotate(
    dis: &Disassembly,
    windows: &[Window],
    funcs: &[&str],
    path: &Path,
) -> Result<(), String> {
    let names: Vec<&str> = windows.iter().map(|w| w.name.as_str()).collect();
    let mut ann = format!(
        "# per window ({}): executions, estimated cycles; then address: instruction, source line\n",
        names.join(", ")
    );
    let mut current = "";
    for (a, i) in &dis.code {
        if !funcs.contains(&i.func.as_str()) {
            continue;
        }
        if i.func != current {
            ann.push_str(&format!("\n{}:\n", i.func));
            current = &i.func;
        }
        for w in windows {
            let c = w.counts.get(a).copied().unwrap_or_default();
            ann.push_str(&format!("{:8} {:8} ", c.instructions, c.cycles));
        }
        ann.push_str(&format!("{a:6x}: {:<44} {}\n", i.text, i.line));
    }
    std::fs::write(path, ann).map_err(|e| format!("{}: {e}", path.display()))?;
    println!(
        "\nxtask: annotated disassembly (executions and estimated cycles per instruction, per window): {}",
        path.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trace_lines_give_their_pc() {
        let l = "Trace 0: 0x7fa550000240 [00800408/0000b0ec/00000110/ff020201] DefaultPreInit";
        assert_eq!(trace_pc(l), Some(0xb0ec));
        assert_eq!(
            trace_pc("cpu_io_recompile: rewound execution of TB to 00000428"),
            None
        );
        assert_eq!(
            trace_pc("Stopped execution of TB chain before 0x7fbbf000b100 [0000bd18] memcpy"),
            None
        );
    }
}
