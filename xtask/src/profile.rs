//! `cargo xtask profile`: where one per-frame call's instructions go.
//!
//! Run the `profile` firmware on QEMU with an execution trace
//! (`-singlestep -d exec,nochain`: one trace line per instruction), count
//! the instructions executed at each address between the firmware's two
//! `marker` calls (one per-frame call), and attribute them with
//! `llvm-objdump -d -l` to functions and (innermost, inlined) source lines.
//! Beside the instructions it reports an estimate of Cortex-M4F cycles
//! (the model and its sources: [`crate::cycles`]), priced instruction by
//! instruction along the trace: the instruction sizes from the disassembly
//! give each one's fall-through address, and a branch is taken when the
//! next traced pc is elsewhere.
//!
//! The steps: trace, disassembly map, counting (instructions and cycles),
//! tables, annotation.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::cycles::{classify, Class, Model, Tally, SUMMARY};
use crate::firmware::{build_firmware, num, records};
use crate::setup::setup_emulator;
use crate::util::{capture, root, tool};

/// One instruction of the firmware's disassembly.
struct Insn {
    /// The (not inlined) function it belongs to, without the hash.
    func: String,
    /// Its innermost source line (`file.rs:line`), inlined code included.
    line: String,
    /// Mnemonic and operands, single-spaced.
    text: String,
    /// Its class in the cycle model.
    class: Class,
    /// The address after it (where execution falls through).
    fall_through: u64,
}

/// The firmware's code: every instruction by address, and the address of
/// `profile::marker`.
struct Disassembly {
    code: BTreeMap<u64, Insn>,
    marker: u64,
}

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

pub fn profile() -> Result<(), String> {
    setup_emulator()?;
    let elf = build_firmware("profile")?;
    let dir = root().join("target").join("profile");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let (log, trace_path) = trace(&elf, &dir)?;
    let points = records(&log, "profile points=")
        .first()
        .map_or(0, |r| num(r, "points"))
        .max(1);
    let dis = disassemble(&elf)?;
    let (counts, tally) = count(&trace_path, &dis)?;
    summary(&tally, points);
    let funcs = function_table(&dis, &counts, points);
    line_table(&dis, &counts, points);
    println!("\n{SUMMARY}");
    annotate(&dis, &counts, &funcs, &dir.join("annotated.txt"))
}

/// The per-frame call's instructions and estimated cycles, in total and
/// per point, and its mix per point.
fn summary(t: &Tally, points: u64) {
    let per = |c: u64| c as f64 / points as f64;
    println!(
        "\none per-frame call ({points} points): {} instructions, {:.1} per point; estimated {} Cortex-M4F cycles, {:.1} per point ({:.2} per instruction)",
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

/// Run the firmware on QEMU, one trace line per executed instruction into
/// `dir/trace.log`; return the decoded defmt log (echoed) and the trace's
/// path.
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

/// The disassembly (`llvm-objdump -d -l -C`): address -> (function, source
/// line, instruction), and where `profile::marker` starts.
fn disassemble(elf: &Path) -> Result<Disassembly, String> {
    let text = capture(
        &tool("llvm-objdump")?,
        &[
            "-d",
            "-l",
            "-C",
            "--no-show-raw-insn",
            &elf.to_string_lossy(),
        ],
    )?;
    let mut code = BTreeMap::new();
    let (mut func, mut line) = (String::new(), String::new());
    let mut marker = None;
    for l in text.lines() {
        if let Some(name) = l.strip_suffix(">:").and_then(|h| h.split_once(" <")) {
            func = strip_hash(name.1);
            line.clear();
            if func == "profile::marker" {
                marker = u64::from_str_radix(name.0.trim(), 16).ok();
            }
        } else if let Some(src) = l.strip_prefix("; ").filter(|s| s.contains(".rs:")) {
            line = short_path(src);
        } else if let Some((a, insn)) = l.trim_start().split_once(':') {
            if let Ok(addr) = u64::from_str_radix(a.trim(), 16) {
                let text = insn.split_whitespace().collect::<Vec<_>>().join(" ");
                code.insert(
                    addr,
                    Insn {
                        func: func.clone(),
                        line: line.clone(),
                        class: classify(&text),
                        text,
                        // Thumb-2 instructions are 2 or 4 bytes: the next
                        // address in the listing, filled in below.
                        fall_through: addr + 4,
                    },
                );
            }
        }
    }
    let marker = marker.ok_or("no profile::marker in the disassembly")?;
    let addrs: Vec<u64> = code.keys().copied().collect();
    for w in addrs.windows(2) {
        if let Some(i) = code.get_mut(&w[0]) {
            i.fall_through = w[1];
        }
    }
    Ok(Disassembly { code, marker })
}

/// The pc of a trace line `Trace 0: 0x… [flags/pc/…] symbol` (other lines:
/// none).
fn trace_pc(line: &str) -> Option<u64> {
    line.split_once('[')
        .and_then(|(_, r)| r.split('/').nth(1))
        .and_then(|h| u64::from_str_radix(h, 16).ok())
}

/// Executions and estimated cycles per address between the first and the
/// second entry into `marker`, and their tally. An instruction is priced
/// when the next one is traced: that says whether it was a taken branch.
fn count(trace: &Path, dis: &Disassembly) -> Result<(Counts, Tally), String> {
    let text = std::fs::read_to_string(trace).map_err(|e| format!("{}: {e}", trace.display()))?;
    let mut counts = Counts::new();
    let mut tally = Tally::default();
    let mut model = Model::default();
    let mut pending: Option<u64> = None;
    let mut seen = 0;
    for pc in text.lines().filter_map(trace_pc) {
        if let Some(prev) = pending.take() {
            let (class, fall_through) = dis
                .code
                .get(&prev)
                .map_or((Class::Other, prev + 2), |i| (i.class, i.fall_through));
            let taken = pc != fall_through;
            let cycles = model.step(class, taken);
            tally.add(class, taken, cycles);
            counts.entry(prev).or_default().add(Cost {
                instructions: 1,
                cycles,
            });
        }
        if pc == dis.marker {
            seen += 1;
            if seen == 2 {
                break;
            }
        } else if seen == 1 {
            pending = Some(pc);
        }
    }
    if seen < 2 {
        return Err("the trace does not hold both marker calls".into());
    }
    Ok((counts, tally))
}

/// Instructions and estimated cycles per (not inlined) function, most
/// instructions first; returns the functions in that order.
fn function_table<'a>(dis: &'a Disassembly, counts: &Counts, points: u64) -> Vec<&'a str> {
    let mut by_func = BTreeMap::<&str, Cost>::new();
    for (a, c) in counts {
        let f = dis.code.get(a).map_or("?", |i| i.func.as_str());
        by_func.entry(f).or_default().add(*c);
    }
    let mut funcs: Vec<_> = by_func.into_iter().collect();
    funcs.sort_by_key(|f| std::cmp::Reverse(f.1.instructions));
    let per = |c: u64| c as f64 / points as f64;
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
fn line_table(dis: &Disassembly, counts: &Counts, points: u64) {
    let mut by_line = BTreeMap::<(&str, &str), Cost>::new();
    for (a, c) in counts {
        let (f, l) = dis
            .code
            .get(a)
            .map_or(("?", "?"), |i| (i.func.as_str(), i.line.as_str()));
        by_line.entry((l, f)).or_default().add(*c);
    }
    let mut lines: Vec<_> = by_line.into_iter().collect();
    lines.sort_by_key(|l| std::cmp::Reverse(l.1.instructions));
    let per = |c: u64| c as f64 / points as f64;
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
/// estimated cycles of each instruction, written to `path`.
fn annotate(dis: &Disassembly, counts: &Counts, funcs: &[&str], path: &Path) -> Result<(), String> {
    let mut ann =
        String::from("# executions, estimated cycles, address: instruction, source line\n");
    let mut current = "";
    for (a, i) in &dis.code {
        if !funcs.contains(&i.func.as_str()) {
            continue;
        }
        if i.func != current {
            ann.push_str(&format!("\n{}:\n", i.func));
            current = &i.func;
        }
        let c = counts.get(a).copied().unwrap_or_default();
        ann.push_str(&format!(
            "{:8} {:8} {a:6x}: {:<44} {}\n",
            c.instructions, c.cycles, i.text, i.line
        ));
    }
    std::fs::write(path, ann).map_err(|e| format!("{}: {e}", path.display()))?;
    println!(
        "\nxtask: annotated disassembly (executions and estimated cycles per instruction): {}",
        path.display()
    );
    Ok(())
}

/// A demangled symbol without its `::h…` hash (and the legacy mangling's
/// `$LT$`/`$GT$` escapes undone).
fn strip_hash(name: &str) -> String {
    let name = match name.rsplit_once("::h") {
        Some((head, hash)) if hash.len() == 16 && hash.chars().all(|c| c.is_ascii_hexdigit()) => {
            head
        }
        _ => name,
    };
    name.replace("$LT$", "<").replace("$GT$", ">")
}

/// `…/src/x.rs:12` or `…/library/core/src/y.rs:34` without the prefix.
fn short_path(src: &str) -> String {
    for cut in ["/library/", "/src/bin/", "/src/"] {
        if let Some((_, tail)) = src.rsplit_once(cut) {
            return if cut == "/src/bin/" {
                format!("bin/{tail}")
            } else {
                tail.to_string()
            };
        }
    }
    src.to_string()
}
