//! The firmware on the emulated vehicle controller: build a binary, run it
//! on QEMU with its defmt log decoded, and read the log's `key=value`
//! records.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::util::{capture, root, run, tool, THUMB};

/// The board a firmware is built for (see `src/bin/fw/board.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Board {
    /// The emulated mps2-an386 (the default).
    Mps2,
    /// An STM32F405 (feature `board-f405`), on QEMU's netduinoplus2.
    F405,
}

impl Board {
    /// From `--board NAME`.
    pub fn from_name(name: &str) -> Option<Board> {
        match name {
            "mps2" | "mps2-an386" => Some(Board::Mps2),
            "f405" | "stm32f405" => Some(Board::F405),
            _ => None,
        }
    }

    /// The cargo features, the target directory (each board its own, so
    /// neither build replaces the other's) and the QEMU machine.
    fn features(self) -> &'static str {
        match self {
            Board::Mps2 => "firmware",
            Board::F405 => "firmware board-f405",
        }
    }

    fn target_dir(self) -> PathBuf {
        match self {
            Board::Mps2 => root().join("target"),
            Board::F405 => root().join("target").join("f405"),
        }
    }

    /// Where the board's flash starts (its vector table), as `llvm-objdump
    /// -h` prints it.
    pub fn flash_origin(self) -> &'static str {
        match self {
            Board::Mps2 => "00000000",
            Board::F405 => "08000000",
        }
    }

    fn machine(self) -> &'static str {
        match self {
            Board::Mps2 => "mps2-an386",
            Board::F405 => "netduinoplus2",
        }
    }
}

/// Build a firmware binary (release) for the mps2-an386 and return its
/// ELF path.
pub fn build_firmware(bin: &str) -> Result<PathBuf, String> {
    build_firmware_for(bin, Board::Mps2)
}

/// Build a firmware binary (release) for `board` and return its ELF path.
pub fn build_firmware_for(bin: &str, board: Board) -> Result<PathBuf, String> {
    build_firmware_with(bin, board, "")
}

/// [`build_firmware_for`] with `extra` cargo features beside the board's.
pub fn build_firmware_with(bin: &str, board: Board, extra: &str) -> Result<PathBuf, String> {
    let r = root();
    let dir = board.target_dir();
    let dir_s = dir.to_string_lossy().to_string();
    let features = format!("{} {extra}", board.features());
    run(
        &r,
        "cargo",
        &[
            "build",
            "--release",
            "--target",
            THUMB,
            "--target-dir",
            &dir_s,
            "--features",
            features.trim(),
            "--bin",
            bin,
        ],
    )?;
    Ok(dir.join(THUMB).join("release").join(bin))
}

/// Run a firmware ELF on QEMU mps2-an386 with the defmt log decoded; echo
/// and return it.
pub fn run_firmware(elf: &Path) -> Result<String, String> {
    run_firmware_on(elf, Board::Mps2)
}

/// Run a firmware ELF built for `board` on its QEMU machine with the defmt
/// log decoded; echo and return it.
pub fn run_firmware_on(elf: &Path, board: Board) -> Result<String, String> {
    let r = root();
    let elf_s = elf.to_string_lossy().to_string();
    println!(
        "xtask: running {} on QEMU {} (Cortex-M4F)",
        elf.display(),
        board.machine()
    );
    let out = Command::new("bash")
        .arg(r.join(".cargo").join("qemu-run.sh"))
        .arg(&elf_s)
        .env("QEMU_MACHINE", board.machine())
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

/// One log line's `key=value` pairs, in order.
pub type Record = Vec<(String, String)>;

/// The records of the log lines containing `marker`.
pub fn records(text: &str, marker: &str) -> Vec<Record> {
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

/// The value of `key` in a record.
pub fn field<'a>(rec: &'a [(String, String)], key: &str) -> Option<&'a str> {
    rec.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
}

/// The value of `key` as a number (0 when missing or not a number).
pub fn num(rec: &[(String, String)], key: &str) -> u64 {
    field(rec, key).and_then(|v| v.parse().ok()).unwrap_or(0)
}

/// The address of an ELF's `.vector_table` section (hex, as `llvm-objdump
/// -h` prints it).
pub fn vector_table(elf: &Path) -> Result<String, String> {
    let elf = elf.to_string_lossy().to_string();
    let headers = capture(&tool("llvm-objdump")?, &["-h", &elf])?;
    headers
        .lines()
        .find(|l| l.contains(".vector_table"))
        .and_then(|l| l.split_whitespace().nth(3))
        .map(str::to_string)
        .ok_or_else(|| format!("no .vector_table in {elf}"))
}
