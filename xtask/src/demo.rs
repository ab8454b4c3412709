//! `cargo xtask demo [--check] [--board f405]`: the demo drive on the
//! emulated controller (mps2-an386 by default, or the STM32F405 build on
//! QEMU's netduinoplus2), its summary table, and (with `--check`) the
//! comparison with the host build.

use std::process::Command;

use crate::firmware::{
    build_firmware_for, field, num, records, run_firmware_on, vector_table, Board, Record,
};
use crate::setup::setup_emulator;
use crate::util::root;

/// Keys the firmware logs that the host cannot know.
const FIRMWARE_ONLY: [&str; 2] = ["instr", "budget_permille"];

/// `cargo xtask demo [--check] [--board mps2|f405|both]` (`both`: on each
/// board, checked, and the boards compared).
pub fn demo_args(args: &[String]) -> Result<(), String> {
    let (mut check, mut name) = (false, "mps2");
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--check" => check = true,
            "--board" => name = it.next().map(String::as_str).unwrap_or(""),
            other => {
                return Err(format!(
                    "unknown argument {other:?} (usage: cargo xtask demo [--check] [--board mps2|f405|both])"
                ))
            }
        }
    }
    if name == "both" {
        return demo_on_both_boards();
    }
    let board = Board::from_name(name)
        .ok_or_else(|| format!("unknown board {name:?} (mps2, f405 or both)"))?;
    demo_on(check, board).map(|_| ())
}

/// The demo on `board`; with `check`, compared with the host build. Returns
/// the frames' records.
pub fn demo_on(check: bool, board: Board) -> Result<Vec<Record>, String> {
    setup_emulator()?;
    let elf = build_firmware_for("demo", board)?;
    // Linked with the board's own map.
    let vma = vector_table(&elf)?;
    if vma != board.flash_origin() {
        return Err(format!(
            "the demo for {board:?} has its vector table at 0x{vma}, not at the board's flash origin 0x{}",
            board.flash_origin()
        ));
    }
    let log = run_firmware_on(&elf, board)?;
    let frames: Vec<Record> = records(&log, " frame=")
        .into_iter()
        .filter(|r| field(r, "points").is_some())
        .collect();
    frame_table(&frames);
    if frames.len() < 20 {
        return Err(format!(
            "the demo logged {} frames, expected at least 20",
            frames.len()
        ));
    }
    if check {
        compare_with_host(&frames)?;
    }
    Ok(frames)
}

/// The demo on both boards: the same results, and the same instruction
/// counts up to [`BOARD_SPREAD`], which holds only if each board converts
/// its ticks with its own core clock (a wrong one is off by 168/25 = 6.7×).
/// The two are separate LTO builds (the board feature changes the crates'
/// hashes and with them the order LLVM sees the functions in), so their
/// machine code differs a little: an instruction trace of both demos
/// showed `Processor::reconstruct` 3 738 instructions apart over the drive
/// (0.3 %), the rest within a few, all results bit for bit equal.
/// How far the two boards' instruction counts may be apart in a frame
/// (relative): the two builds' codegen noise, measured up to 0.4 % (frame
/// 9 of the drive, 2026-12-04), with room; a wrong clock is 570 % off.
const BOARD_SPREAD: f64 = 0.01;

pub fn demo_on_both_boards() -> Result<(), String> {
    let mps2 = demo_on(true, Board::Mps2)?;
    let f405 = demo_on(true, Board::F405)?;
    if mps2.len() != f405.len() {
        return Err(format!(
            "mps2-an386 logged {} frames, stm32f405 {}",
            mps2.len(),
            f405.len()
        ));
    }
    let mut worst = 0.0f64;
    for (a, b) in mps2.iter().zip(&f405) {
        let frame = num(a, "frame");
        if field(a, "digest") != field(b, "digest")
            || field(a, "fusion_digest") != field(b, "fusion_digest")
        {
            return Err(format!("frame {frame}: the boards' digests differ"));
        }
        let (ia, ib) = (num(a, "instr") as f64, num(b, "instr") as f64);
        let rel = (ia - ib).abs() / ia.max(1.0);
        worst = worst.max(rel);
        if rel > BOARD_SPREAD {
            return Err(format!(
                "frame {frame}: {ia} instructions on mps2-an386, {ib} on stm32f405 (a board's clock is wrong)"
            ));
        }
    }
    println!(
        "xtask: mps2-an386 and stm32f405 agree on all {} frames (digests equal, instruction counts within {:.3} %)",
        mps2.len(),
        worst * 100.0
    );
    Ok(())
}

/// One row per frame: points, matched, flagged, instructions, share of the
/// frame budget; and the fusion: key frame and partner, fused points, their
/// median relative width, inconsistent points, the road map.
fn frame_table(frames: &[Record]) {
    println!();
    println!("| frame | points | ok | flagged | instructions | instr/point | frame budget used | key frame (partner) | fused | median fused width | inconsistent | map points ahead (dropped behind) |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for f in frames {
        let points = num(f, "points");
        let ok = num(f, "ok");
        let instr = num(f, "instr");
        println!(
            "| {} | {} | {} | {} | {} | {} | {:.1} % | {} ({}){} | {} | {:.1} % | {} | {} ({}) |",
            num(f, "frame"),
            points,
            ok,
            points - ok,
            instr,
            instr / points.max(1),
            num(f, "budget_permille") as f64 / 10.0,
            num(f, "key"),
            num(f, "partner"),
            if field(f, "retired") == Some("true") {
                ", retires"
            } else {
                ""
            },
            num(f, "fused"),
            num(f, "width_permille") as f64 / 10.0,
            num(f, "inconsistent"),
            num(f, "map"),
            num(f, "map_behind")
        );
    }
}

/// Run the host build of the same drive (`host_tests`' `fwref`) and require
/// every frame's status counts and result digest to equal the firmware's.
fn compare_with_host(frames: &[Record]) -> Result<(), String> {
    let out = Command::new("cargo")
        .args(["run", "--quiet", "--release", "--bin", "fwref"])
        .current_dir(root().join("host_tests"))
        .output()
        .map_err(|e| format!("cannot run the host reference: {e}"))?;
    if !out.status.success() {
        return Err("host reference failed".into());
    }
    let host = records(&String::from_utf8_lossy(&out.stdout), "frame=");
    let frames: Vec<Record> = frames
        .iter()
        .map(|f| {
            f.iter()
                .filter(|(k, _)| !FIRMWARE_ONLY.contains(&k.as_str()))
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
    Ok(())
}
