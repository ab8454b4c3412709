//! `cargo xtask stream FILE.jsonl [--drive] [--corrupt P] [--drop P]
//! [--duplicate P] [--seed S] [--radius PX] [--frames K] [--within] [--fused]`: a
//! recorded drive streamed into the link firmware on the emulated
//! controller over UART0, every result compared bit for bit with the host
//! build (the comparison and the tables are `host_tests`' `stream` tool);
//! with `--within` the firmware runs each frame within a deadline (feature
//! `link-deadline`), and each of its results must be the host's point for
//! point or `over_budget`, within the frame budget; with `--fused` it runs
//! each frame through a key-frame fusion (feature `link-fused`), and the
//! fusion's digest after every frame must be the host's too.

use crate::firmware::{build_firmware_with, Board};
use crate::setup::setup_emulator;
use crate::util::{root, run};

pub const STREAM_USAGE: &str = "usage: cargo xtask stream FILE.jsonl [--drive] [--corrupt P] [--drop P] [--duplicate P] [--seed S] [--radius PX] [--frames K] [--within] [--fused]
  FILE.jsonl   replay JSON Lines (README, \"Replay\"); with --drive, the firmware drive format (src/bin/data/drive.bin)
  --corrupt P  flip one bit in a packet with probability P (per packet)
  --drop P     drop a packet with probability P
  --duplicate P  send a packet twice with probability P
  --seed S     the fault injection's seed (default 0)
  --radius PX  every boundary's localisation-error radius (default 0.5)
  --frames K   only the first K frames
  --within     each frame within a deadline on the firmware (SysTick, the frame budget less 40 000):
               every result the host's point for point or over_budget, every frame within the budget
  --fused      each frame through a key-frame fusion on the firmware (the pair with its key frame; the host's
               fusion the same, digest for digest after every frame; with --within the SysTick limit 212 000)";

pub fn stream(args: &[String]) -> Result<(), String> {
    if args.is_empty() || args.iter().any(|a| a == "--help" || a == "-h") {
        println!("{STREAM_USAGE}");
        return if args.is_empty() {
            Err("stream needs a file".into())
        } else {
            Ok(())
        };
    }
    setup_emulator()?;
    let within = args.iter().any(|a| a == "--within");
    let fused = args.iter().any(|a| a == "--fused");
    let mut features = Vec::new();
    if within {
        features.push("link-deadline");
    }
    if fused {
        features.push("link-fused");
    }
    let elf = build_firmware_with("link", Board::Mps2, &features.join(" "))?;
    let cwd = std::env::current_dir().map_err(|e| e.to_string())?;
    // The file as the user named it, from where they ran cargo.
    let mut a: Vec<String> = Vec::new();
    for x in args {
        if !x.starts_with("--") && std::path::Path::new(x).exists() {
            a.push(cwd.join(x).to_string_lossy().to_string());
        } else {
            a.push(x.clone());
        }
    }
    let elf = elf.to_string_lossy().to_string();
    let mut all = vec![
        "run",
        "--quiet",
        "--release",
        "--bin",
        "stream",
        "--",
        "--elf",
        &elf,
    ];
    all.extend(a.iter().map(String::as_str));
    run(&root().join("host_tests"), "cargo", &all)
}
