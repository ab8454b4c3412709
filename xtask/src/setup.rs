//! Installing what the tasks need: the pinned toolchain's thumb target and
//! components, the emulator and the defmt decoder.

use std::process::Command;

use crate::util::{have, root, run, THUMB, TOOLCHAIN};

/// Install the thumb target and components of the pinned toolchain
/// (idempotent; `RUSTUP_AUTO_INSTALL=0` means nobody else will).
pub fn setup_toolchain() -> Result<(), String> {
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

/// Install what the emulated controller needs, if missing: the toolchain's
/// parts, `qemu-system-arm` (apt) and `defmt-print` (cargo).
pub fn setup_emulator() -> Result<(), String> {
    setup_toolchain()?;
    if !have("qemu-system-arm", "--version") {
        install_qemu()?;
    }
    if !have("defmt-print", "--version") {
        run(
            &root(),
            "cargo",
            &["install", "defmt-print", "--version", "1.2.0", "--locked"],
        )?;
    }
    Ok(())
}

/// `apt-get install qemu-system-arm`, through `sudo` unless running as root.
fn install_qemu() -> Result<(), String> {
    let r = root();
    let sudo: &[&str] = if running_as_root() { &[] } else { &["sudo"] };
    let apt = |args: &[&str]| -> Result<(), String> {
        let mut all: Vec<&str> = sudo.to_vec();
        all.push("apt-get");
        all.extend_from_slice(args);
        let (p, rest) = all.split_first().ok_or("empty command")?;
        run(&r, p, rest)
    };
    apt(&["update", "-qq"])?;
    apt(&["install", "-y", "-qq", "qemu-system-arm"])
}

/// Whether `id -u` says 0 (or cannot tell: then no `sudo` either).
fn running_as_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .map(|o| !o.status.success() || String::from_utf8_lossy(&o.stdout).trim() == "0")
        .unwrap_or(true)
}
