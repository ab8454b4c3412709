//! `cargo xtask demo [--check]`: the demo drive on the emulated controller,
//! its summary table, and (with `--check`) the comparison with the host build.

use std::process::Command;

use crate::firmware::{build_firmware, field, num, records, run_firmware};
use crate::setup::setup_emulator;
use crate::util::root;

pub fn demo(check: bool) -> Result<(), String> {
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
