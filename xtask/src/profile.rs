//! `cargo xtask profile`: where one per-frame call's instructions go.

use std::process::Command;

use crate::firmware::{build_firmware, num, records};
use crate::setup::setup_emulator;
use crate::util::{capture, root, tool};

/// `cargo xtask profile`: run the `profile` firmware on QEMU with an
/// execution trace (`-singlestep -d exec,nochain`: one trace line per
/// instruction), count the instructions executed at each address between
/// the firmware's two `marker` calls (one per-frame call), and attribute
/// them with `llvm-objdump -d -l` to functions and (innermost, inlined)
/// source lines.
pub fn profile() -> Result<(), String> {
    setup_emulator()?;
    let elf = build_firmware("profile")?;
    let elf_s = elf.to_string_lossy().to_string();
    let dir = root().join("target").join("profile");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
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
    let points = records(&log, "profile points=")
        .first()
        .map_or(0, |r| num(r, "points"))
        .max(1);
    // The disassembly: address -> (function, source line, instruction).
    let dis = capture(
        &tool("llvm-objdump")?,
        &["-d", "-l", "-C", "--no-show-raw-insn", &elf_s],
    )?;
    let mut code = std::collections::BTreeMap::new();
    let (mut func, mut line) = (String::new(), String::new());
    let mut marker = None;
    for l in dis.lines() {
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
                let insn = insn.split_whitespace().collect::<Vec<_>>().join(" ");
                code.insert(addr, (func.clone(), line.clone(), insn));
            }
        }
    }
    let marker = marker.ok_or("no profile::marker in the disassembly")?;
    // The trace: `Trace 0: 0x… [flags/pc/…]`, counted between the markers.
    let text = std::fs::read_to_string(&trace).map_err(|e| format!("{}: {e}", trace.display()))?;
    let mut counts = std::collections::BTreeMap::<u64, u64>::new();
    let mut seen = 0;
    for l in text.lines() {
        let Some(pc) = l
            .split_once('[')
            .and_then(|(_, r)| r.split('/').nth(1))
            .and_then(|h| u64::from_str_radix(h, 16).ok())
        else {
            continue;
        };
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
    let total: u64 = counts.values().sum();
    let per = |c: u64| c as f64 / points as f64;
    println!(
        "\none per-frame call ({points} points): {total} instructions, {:.1} per point",
        per(total)
    );
    let mut by_func = std::collections::BTreeMap::<&str, u64>::new();
    let mut by_line = std::collections::BTreeMap::<(&str, &str), u64>::new();
    for (a, c) in &counts {
        let (f, l) = code
            .get(a)
            .map_or(("?", "?"), |(f, l, _)| (f.as_str(), l.as_str()));
        *by_func.entry(f).or_default() += c;
        *by_line.entry((l, f)).or_default() += c;
    }
    let mut funcs: Vec<_> = by_func.into_iter().collect();
    funcs.sort_by_key(|f| std::cmp::Reverse(f.1));
    println!("\n| function (not inlined) | instructions | per point |");
    println!("|---|---:|---:|");
    for (f, c) in &funcs {
        println!("| `{f}` | {c} | {:.1} |", per(*c));
    }
    let mut lines: Vec<_> = by_line.into_iter().collect();
    lines.sort_by_key(|l| std::cmp::Reverse(l.1));
    println!("\n| source line (innermost, inlined code included) | in function | per point |");
    println!("|---|---|---:|");
    for ((l, f), c) in lines.iter().take(30) {
        println!("| {l} | `{f}` | {:.1} |", per(*c));
    }
    // Every executed function's disassembly with its counts.
    let mut ann = String::new();
    let mut current = "";
    for (a, (f, l, insn)) in &code {
        if !funcs.iter().any(|(g, _)| g == f) {
            continue;
        }
        if f != current {
            ann.push_str(&format!("\n{f}:\n"));
            current = f;
        }
        let c = counts.get(a).copied().unwrap_or(0);
        ann.push_str(&format!("{c:8} {a:6x}: {insn:<44} {l}\n"));
    }
    let path = dir.join("annotated.txt");
    std::fs::write(&path, ann).map_err(|e| format!("{}: {e}", path.display()))?;
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
            let tail = if cut == "/library/" {
                tail.to_string()
            } else if cut == "/src/bin/" {
                format!("bin/{tail}")
            } else {
                tail.to_string()
            };
            return tail;
        }
    }
    src.to_string()
}
