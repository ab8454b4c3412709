//! `cargo xtask profile`: where one per-frame call's instructions go.
//!
//! Run the `profile` firmware on QEMU with an execution trace
//! (`-singlestep -d exec,nochain`: one trace line per instruction), count
//! the instructions executed at each address between the firmware's two
//! `marker` calls (one per-frame call), and attribute them with
//! `llvm-objdump -d -l` to functions and (innermost, inlined) source lines.
//!
//! The steps: trace, disassembly map, counting, tables, annotation.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

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
}

/// The firmware's code: every instruction by address, and the address of
/// `profile::marker`.
struct Disassembly {
    code: BTreeMap<u64, Insn>,
    marker: u64,
}

/// Executions per instruction address.
type Counts = BTreeMap<u64, u64>;

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
    let counts = count(&trace_path, dis.marker)?;
    let total: u64 = counts.values().sum();
    let per = |c: u64| c as f64 / points as f64;
    println!(
        "\none per-frame call ({points} points): {total} instructions, {:.1} per point",
        per(total)
    );
    let funcs = function_table(&dis, &counts, points);
    line_table(&dis, &counts, points);
    annotate(&dis, &counts, &funcs, &dir.join("annotated.txt"))
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
                        text,
                    },
                );
            }
        }
    }
    let marker = marker.ok_or("no profile::marker in the disassembly")?;
    Ok(Disassembly { code, marker })
}

/// The pc of a trace line `Trace 0: 0x… [flags/pc/…] symbol` (other lines:
/// none).
fn trace_pc(line: &str) -> Option<u64> {
    line.split_once('[')
        .and_then(|(_, r)| r.split('/').nth(1))
        .and_then(|h| u64::from_str_radix(h, 16).ok())
}

/// Executions per address between the first and the second entry into
/// `marker`.
fn count(trace: &Path, marker: u64) -> Result<Counts, String> {
    let text = std::fs::read_to_string(trace).map_err(|e| format!("{}: {e}", trace.display()))?;
    let mut counts = Counts::new();
    let mut seen = 0;
    for pc in text.lines().filter_map(trace_pc) {
        if pc == marker {
            seen += 1;
            if seen == 2 {
                break;
            }
        } else if seen == 1 {
            *counts.entry(pc).or_default() += 1;
        }
    }
    if seen < 2 {
        return Err("the trace does not hold both marker calls".into());
    }
    Ok(counts)
}

/// Instructions per (not inlined) function, costliest first; returns the
/// functions in that order.
fn function_table<'a>(dis: &'a Disassembly, counts: &Counts, points: u64) -> Vec<(&'a str, u64)> {
    let mut by_func = BTreeMap::<&str, u64>::new();
    for (a, c) in counts {
        let f = dis.code.get(a).map_or("?", |i| i.func.as_str());
        *by_func.entry(f).or_default() += c;
    }
    let mut funcs: Vec<_> = by_func.into_iter().collect();
    funcs.sort_by_key(|f| std::cmp::Reverse(f.1));
    println!("\n| function (not inlined) | instructions | per point |");
    println!("|---|---:|---:|");
    for (f, c) in &funcs {
        println!("| `{f}` | {c} | {:.1} |", *c as f64 / points as f64);
    }
    funcs
}

/// The 30 costliest source lines (innermost, inlined code included), each
/// with the function it was inlined into.
fn line_table(dis: &Disassembly, counts: &Counts, points: u64) {
    let mut by_line = BTreeMap::<(&str, &str), u64>::new();
    for (a, c) in counts {
        let (f, l) = dis
            .code
            .get(a)
            .map_or(("?", "?"), |i| (i.func.as_str(), i.line.as_str()));
        *by_line.entry((l, f)).or_default() += c;
    }
    let mut lines: Vec<_> = by_line.into_iter().collect();
    lines.sort_by_key(|l| std::cmp::Reverse(l.1));
    println!("\n| source line (innermost, inlined code included) | in function | per point |");
    println!("|---|---|---:|");
    for ((l, f), c) in lines.iter().take(30) {
        println!("| {l} | `{f}` | {:.1} |", *c as f64 / points as f64);
    }
}

/// Every executed function's disassembly with the executions of each
/// instruction, written to `path`.
fn annotate(
    dis: &Disassembly,
    counts: &Counts,
    funcs: &[(&str, u64)],
    path: &Path,
) -> Result<(), String> {
    let mut ann = String::new();
    let mut current = "";
    for (a, i) in &dis.code {
        if !funcs.iter().any(|(g, _)| *g == i.func) {
            continue;
        }
        if i.func != current {
            ann.push_str(&format!("\n{}:\n", i.func));
            current = &i.func;
        }
        let c = counts.get(a).copied().unwrap_or(0);
        ann.push_str(&format!("{c:8} {a:6x}: {:<44} {}\n", i.text, i.line));
    }
    std::fs::write(path, ann).map_err(|e| format!("{}: {e}", path.display()))?;
    println!(
        "\nxtask: annotated disassembly (executions per instruction): {}",
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
