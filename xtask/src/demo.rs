//! `cargo xtask demo [--check]`: the demo drive on the emulated controller,
//! its summary table, and (with `--check`) the comparison with the host build.

use std::process::Command;

use crate::firmware::{build_firmware, field, num, records, run_firmware, Record};
use crate::setup::setup_emulator;
use crate::util::root;

/// Keys the firmware logs that the host cannot know.
const FIRMWARE_ONLY: [&str; 2] = ["instr", "budget_permille"];

pub fn demo(check: bool) -> Result<(), String> {
    setup_emulator()?;
    let elf = build_firmware("demo")?;
    let log = run_firmware(&elf)?;
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
