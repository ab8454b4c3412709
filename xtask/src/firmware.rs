//! The firmware on the emulated vehicle controller: build a binary, run it
//! on QEMU with its defmt log decoded, and read the log's `key=value`
//! records.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::util::{root, run, THUMB};

/// Build a firmware binary (release) and return its ELF path.
pub fn build_firmware(bin: &str) -> Result<PathBuf, String> {
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
pub fn run_firmware(elf: &Path) -> Result<String, String> {
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
