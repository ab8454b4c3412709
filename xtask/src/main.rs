//! `cargo xtask <task>`: the project's automation, in plain Rust.
//!
//! * `test`    — every host test: the library's unit and doc tests, and the
//!   `host_tests` crate (synthetic roads with ground truth).
//! * `demo`    — the demo on the emulated vehicle controller (QEMU
//!   mps2-an386, Cortex-M4F): installs what is missing (thumb target,
//!   `qemu-system-arm`, `defmt-print`), builds the firmware in release mode,
//!   runs it and prints a summary table. `--check` also compares every
//!   frame's results with the host build of the same code.
//! * `bench`   — instruction counts, stage costs, stack, memory figures and
//!   the link-time proofs (panic-never, no `f64`, no allocator), with the
//!   budgets checked (see `--help` of the task).
//! * `profile` — where one per-frame call's instructions go: the N = 256
//!   bench frame traced instruction by instruction on QEMU, counted per
//!   function and per source line, with an annotated disassembly written
//!   to `target/profile/annotated.txt`.
//! * `figures` — re-render `docs/` (figures and the replay example).
//! * `ci`      — what `.ci/run` runs: toolchain setup, formatting, clippy,
//!   thumb builds with and without `defmt`, `test`, then `demo --check`,
//!   `bench` and `profile`.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

const TOOLCHAIN: &str = "1.95.0";
const THUMB: &str = "thumbv7em-none-eabihf";

fn root() -> PathBuf {
    // xtask/ lives directly under the repository root.
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn run(dir: &Path, program: &str, args: &[&str]) -> Result<(), String> {
    println!("xtask: ({}) {} {}", dir.display(), program, args.join(" "));
    let status = Command::new(program)
        .args(args)
        .current_dir(dir)
        .status()
        .map_err(|e| format!("cannot start {program}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("`{program} {}` failed ({status})", args.join(" ")))
    }
}

/// Install the thumb target and components of the pinned toolchain
/// (idempotent; `RUSTUP_AUTO_INSTALL=0` means nobody else will).
fn setup_toolchain() -> Result<(), String> {
    let r = root();
    run(
        &r,
        "rustup",
        &["target", "add", THUMB, "--toolchain", TOOLCHAIN],
    )?;
    run(
        &r,
        "rustup",
        &[
            "component",
            "add",
            "llvm-tools",
            "clippy",
            "rustfmt",
            "--toolchain",
            TOOLCHAIN,
        ],
    )
}

fn test() -> Result<(), String> {
    let r = root();
    run(&r, "cargo", &["test", "--target", "host-tuple", "--lib"])?;
    run(&r, "cargo", &["test", "--target", "host-tuple", "--doc"])?;
    run(&r.join("host_tests"), "cargo", &["test"])
}

fn figures() -> Result<(), String> {
    run(
        &root().join("host_tests"),
        "cargo",
        &["run", "--release", "--bin", "figures", "--", "../docs"],
    )
}

fn ci() -> Result<(), String> {
    let r = root();
    let h = r.join("host_tests");
    setup_toolchain()?;
    let cargo = |dir: &Path, args: &[&str]| run(dir, "cargo", args);
    cargo(&r, &["fmt", "--check"])?;
    cargo(&h, &["fmt", "--check"])?;
    cargo(&r.join("xtask"), &["fmt", "--check"])?;
    // The library for the vehicle controller, without and with defmt.
    cargo(&r, &["build", "--release", "--target", THUMB])?;
    cargo(
        &r,
        &[
            "build",
            "--release",
            "--target",
            THUMB,
            "--features",
            "defmt",
        ],
    )?;
    cargo(&r, &["clippy", "--target", THUMB, "--", "-D", "warnings"])?;
    cargo(
        &r,
        &[
            "clippy",
            "--target",
            THUMB,
            "--features",
            "defmt",
            "--",
            "-D",
            "warnings",
        ],
    )?;
    cargo(
        &r,
        &[
            "clippy",
            "--target",
            "host-tuple",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ],
    )?;
    cargo(&h, &["clippy", "--all-targets", "--", "-D", "warnings"])?;
    cargo(
        &r,
        &[
            "clippy",
            "--release",
            "--target",
            THUMB,
            "--features",
            "firmware",
            "--bins",
            "--",
            "-D",
            "warnings",
        ],
    )?;
    // The README's test command.
    test()?;
    // The firmware on the emulated controller: the demo, compared frame by
    // frame with the host build, then the benchmark, budgets and proofs.
    demo(true)?;
    bench(&bench_args(&[])?)?;
    // The profiler too, so it cannot rot (about ten seconds).
    profile()
}

fn have(program: &str, arg: &str) -> bool {
    Command::new(program)
        .arg(arg)
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
}

/// Install what the emulated controller needs, if missing.
fn setup_emulator() -> Result<(), String> {
    setup_toolchain()?;
    let r = root();
    if !have("qemu-system-arm", "--version") {
        let sudo = if have("id", "-u")
            && Command::new("id")
                .arg("-u")
                .output()
                .map(|o| String::from_utf8_lossy(&o.stdout).trim() != "0")
                .unwrap_or(false)
        {
            vec!["sudo"]
        } else {
            vec![]
        };
        let apt = |args: &[&str]| -> Result<(), String> {
            let mut all: Vec<&str> = sudo.clone();
            all.push("apt-get");
            all.extend_from_slice(args);
            let (p, rest) = all.split_first().ok_or("empty command")?;
            run(&r, p, rest)
        };
        apt(&["update", "-qq"])?;
        apt(&["install", "-y", "-qq", "qemu-system-arm"])?;
    }
    if !have("defmt-print", "--version") {
        run(
            &r,
            "cargo",
            &["install", "defmt-print", "--version", "1.2.0", "--locked"],
        )?;
    }
    Ok(())
}

/// Build a firmware binary (release) and return its ELF path.
fn build_firmware(bin: &str) -> Result<PathBuf, String> {
    let r = root();
    run(
        &r,
        "cargo",
        &[
            "build",
            "--release",
            "--target",
            THUMB,
            "--features",
            "firmware",
            "--bin",
            bin,
        ],
    )?;
    Ok(r.join("target").join(THUMB).join("release").join(bin))
}

/// Run a firmware ELF on QEMU with the defmt log decoded; echo and return it.
fn run_firmware(elf: &Path) -> Result<String, String> {
    let r = root();
    let elf_s = elf.to_string_lossy().to_string();
    println!(
        "xtask: running {} on QEMU mps2-an386 (Cortex-M4F)",
        elf.display()
    );
    let out = Command::new("bash")
        .arg(r.join(".cargo").join("qemu-run.sh"))
        .arg(&elf_s)
        .current_dir(&r)
        .output()
        .map_err(|e| format!("cannot start QEMU: {e}"))?;
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    print!("{text}");
    eprint!("{}", String::from_utf8_lossy(&out.stderr));
    if !out.status.success() {
        return Err(format!(
            "firmware {} failed ({})",
            elf.display(),
            out.status
        ));
    }
    Ok(text)
}

/// `key=value` pairs of the log lines containing `marker`.
fn records(text: &str, marker: &str) -> Vec<Vec<(String, String)>> {
    text.lines()
        .filter(|l| l.contains(marker))
        .map(|l| {
            l.split_whitespace()
                .filter_map(|w| w.split_once('='))
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

fn field<'a>(rec: &'a [(String, String)], key: &str) -> Option<&'a str> {
    rec.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
}

fn num(rec: &[(String, String)], key: &str) -> u64 {
    field(rec, key).and_then(|v| v.parse().ok()).unwrap_or(0)
}

fn demo(check: bool) -> Result<(), String> {
    setup_emulator()?;
    let elf = build_firmware("demo")?;
    let log = run_firmware(&elf)?;
    let frames = records(&log, " frame=");
    let frames: Vec<_> = frames
        .into_iter()
        .filter(|r| field(r, "points").is_some())
        .collect();
    println!();
    println!("| frame | points | ok | flagged | instructions | instr/point | frame budget used |");
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    for f in &frames {
        let points = num(f, "points");
        let ok = num(f, "ok");
        let instr = num(f, "instr");
        println!(
            "| {} | {} | {} | {} | {} | {} | {:.1} % |",
            num(f, "frame"),
            points,
            ok,
            points - ok,
            instr,
            instr / points.max(1),
            num(f, "budget_permille") as f64 / 10.0
        );
    }
    if frames.len() < 20 {
        return Err(format!(
            "the demo logged {} frames, expected at least 20",
            frames.len()
        ));
    }
    if check {
        let r = root();
        let out = Command::new("cargo")
            .args(["run", "--quiet", "--release", "--bin", "fwref"])
            .current_dir(r.join("host_tests"))
            .output()
            .map_err(|e| format!("cannot run the host reference: {e}"))?;
        if !out.status.success() {
            return Err("host reference failed".into());
        }
        let host = records(&String::from_utf8_lossy(&out.stdout), "frame=");
        // The firmware also logs instructions, which the host cannot know.
        let frames: Vec<Vec<(String, String)>> = frames
            .iter()
            .map(|f| {
                f.iter()
                    .filter(|(k, _)| k != "instr" && k != "budget_permille")
                    .cloned()
                    .collect()
            })
            .collect();
        if host.len() != frames.len() {
            return Err(format!(
                "host has {} frames, firmware {}",
                host.len(),
                frames.len()
            ));
        }
        for (h, f) in host.iter().zip(&frames) {
            for (k, v) in h {
                if field(f, k) != Some(v.as_str()) {
                    return Err(format!(
                        "frame {}: firmware {k}={:?}, host {k}={v}",
                        num(h, "frame"),
                        field(f, k)
                    ));
                }
            }
        }
        println!(
            "xtask: firmware and host agree bit for bit on all {} frames (status counts and result digests)",
            frames.len()
        );
    }
    Ok(())
}

fn tool(name: &str) -> Result<PathBuf, String> {
    let out = Command::new("rustc")
        .args(["--print", "sysroot"])
        .current_dir(root())
        .output()
        .map_err(|e| format!("rustc: {e}"))?;
    let sysroot = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    let host = Command::new("rustc")
        .args(["-vV"])
        .output()
        .map_err(|e| format!("rustc: {e}"))?;
    let triple = String::from_utf8_lossy(&host.stdout)
        .lines()
        .find_map(|l| l.strip_prefix("host: ").map(str::to_string))
        .ok_or("cannot find the host triple")?;
    Ok(sysroot
        .join("lib/rustlib")
        .join(triple)
        .join("bin")
        .join(name))
}

fn capture(program: &Path, args: &[&str]) -> Result<String, String> {
    let out = Command::new(program)
        .args(args)
        .output()
        .map_err(|e| format!("{}: {e}", program.display()))?;
    if !out.status.success() {
        return Err(format!("{} failed", program.display()));
    }
    Ok(String::from_utf8_lossy(&out.stdout).to_string())
}

const BENCH_USAGE: &str =
    "usage: cargo xtask bench [--frame-ms 33] [--cpu-mhz 168] [--share-percent 5] [--per-point 400]
  every budget is hard (exit code 1 when one is missed): instructions per point at every N,
  per-point scaling N = 512 / N = 64 <= 1.25, the 2 x 256 frame within share-percent of a
  frame-ms frame at cpu-mhz (one instruction = one cycle), stack <= 4 KiB, no software f64,
  no allocator, the panic-never link";

struct Budget {
    per_point: u64,
    frame_ms: f64,
    cpu_mhz: f64,
    share_percent: f64,
    stack: u64,
    scaling: f64,
}

fn bench(b: &Budget) -> Result<(), String> {
    setup_emulator()?;
    let elf = build_firmware("bench")?;
    let demo_elf = build_firmware("demo")?;
    // The link-time proof: this build fails if a panic path remains.
    build_firmware("nopanic")?;
    println!("xtask: panic-never check binary linked: no panicking branch in the per-frame code");
    let log = run_firmware(&elf)?;
    // Every budget is hard: any miss fails the task (and CI).
    let mut hard = Vec::new();
    let rows = records(&log, "bench n=");
    println!();
    println!("| N per boundary | points | instructions per frame | per point |");
    println!("|---:|---:|---:|---:|");
    let mut per = std::collections::BTreeMap::new();
    for r in &rows {
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
            hard.push(format!(
                "N = {n}: {pp} instructions per point > budget {}",
                b.per_point
            ));
        }
    }
    let stress = records(&log, "stress n=");
    if !stress.is_empty() {
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
    let deadline = (b.frame_ms * 1e-3 * b.cpu_mhz * 1e6 * b.share_percent / 100.0) as u64;
    match (per.get(&64), per.get(&512)) {
        (Some((_, p64)), Some((_, p512))) => {
            let ratio = *p512 as f64 / (*p64).max(1) as f64;
            println!(
                "\nper-point cost at N = 512 / N = 64: {ratio:.3} (budget ≤ {:.2})",
                b.scaling
            );
            if ratio > b.scaling {
                hard.push(format!("scaling {ratio:.3} > {:.2}", b.scaling));
            }
        }
        _ => hard.push("missing N = 64 or N = 512 rows".into()),
    }
    if let Some((i256, _)) = per.get(&256) {
        println!(
            "frame of 2 × 256 points: {i256} instructions; deadline {deadline} ({} % of {} ms at {} MHz, one instruction = one cycle): {:.0} % of it",
            b.share_percent,
            b.frame_ms,
            b.cpu_mhz,
            100.0 * *i256 as f64 / deadline as f64
        );
        if *i256 > deadline {
            hard.push(format!(
                "2 × 256 frame: {i256} instructions > deadline {deadline}"
            ));
        }
    }
    println!("\nwhere the instructions go (N = 256, through the public API):");
    for s in records(&log, "stage name=") {
        println!(
            "  {:22} {:>9} instructions, {:>4} per point",
            field(&s, "name").unwrap_or("?"),
            num(&s, "instr"),
            num(&s, "per_point")
        );
    }
    let stack = records(&log, "stack per_frame_call=")
        .first()
        .map(|r| num(r, "per_frame_call"))
        .unwrap_or(u64::MAX);
    let sizes = records(&log, "sizes ")
        .into_iter()
        .next()
        .unwrap_or_default();
    // Memory figures from the linked demo firmware.
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
        hard.push(format!("stack {stack} B > {} B", b.stack));
    }
    // Symbols: no software double precision, no allocator.
    for elf in [&elf, &demo_elf] {
        let syms = capture(&tool("llvm-nm")?, &[&elf.to_string_lossy()])?;
        let bad_f64: Vec<&str> = syms.lines().filter(|l| l.contains("__aeabi_d")).collect();
        if !bad_f64.is_empty() {
            hard.push(format!(
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
            hard.push(format!("{}: allocator linked: {alloc:?}", elf.display()));
        }
    }
    println!(
        "no __aeabi_d* (software f64) and no allocator symbols in the demo and bench firmware: {}",
        if hard
            .iter()
            .any(|h| h.contains("f64") || h.contains("allocator"))
        {
            "FAILED"
        } else {
            "ok"
        }
    );
    for h in &hard {
        println!("xtask: budget NOT MET: {h}");
    }
    if !hard.is_empty() {
        return Err(hard.join("; "));
    }
    println!(
        "xtask: all budgets met (≤ {} instructions per point at every N, scaling, deadline, stack, no f64, no allocator, panic-never)",
        b.per_point
    );
    Ok(())
}

fn bench_args(args: &[String]) -> Result<Budget, String> {
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

/// `cargo xtask profile`: run the `profile` firmware on QEMU with an
/// execution trace (`-singlestep -d exec,nochain`: one trace line per
/// instruction), count the instructions executed at each address between
/// the firmware's two `marker` calls (one per-frame call), and attribute
/// them with `llvm-objdump -d -l` to functions and (innermost, inlined)
/// source lines.
fn profile() -> Result<(), String> {
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

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let task = args.first().cloned().unwrap_or_default();
    let rest = args.get(1..).unwrap_or(&[]);
    let result = match task.as_str() {
        "test" => test(),
        "demo" => demo(rest.iter().any(|a| a == "--check")),
        "bench" if rest.iter().any(|a| a == "--help" || a == "-h") => {
            println!("{BENCH_USAGE}");
            Ok(())
        }
        "bench" => bench_args(rest).and_then(|b| bench(&b)),
        "figures" => figures(),
        "ci" => ci(),
        "profile" => profile(),
        "setup" => setup_emulator(),
        _ => {
            eprintln!(
                "usage: cargo xtask <test|demo [--check]|bench [options]|profile|figures|ci|setup>"
            );
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}
