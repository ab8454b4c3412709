//! The downstream check: a firmware crate that depends on the library as a
//! board's firmware would (`xtask/fixtures/downstream`: no `firmware`
//! feature, its own `memory.x` with flash at `0x0800_0000`, the processor
//! in a `static`) builds for the Cortex-M4F, its vector table lands at its
//! own flash origin, and the library's build script put nothing on its
//! link line (a link search path a build script prints reaches every
//! crate linked after it, so the emulator's map must stay out).

use std::fs;

use crate::firmware::vector_table;
use crate::util::{root, run};

/// Build the fixture and check its link.
pub fn downstream() -> Result<(), String> {
    let dir = root().join("xtask/fixtures/downstream");
    run(&dir, "cargo", &["build", "--release"])?;
    let release = dir.join("target/thumbv7em-none-eabihf/release");
    // The library's build script output: no link directive at all.
    let build = release.join("build");
    let entries = fs::read_dir(&build).map_err(|e| format!("{}: {e}", build.display()))?;
    let mut seen = false;
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        if !name.starts_with("roadstereo-") {
            continue;
        }
        let Ok(out) = fs::read_to_string(e.path().join("output")) else {
            continue;
        };
        seen = true;
        if let Some(l) = out.lines().find(|l| l.contains("rustc-link")) {
            return Err(format!(
                "downstream: the library's build script put `{l}` on a dependent's link"
            ));
        }
    }
    if !seen {
        return Err("downstream: no build script output of the library found".into());
    }
    // The linked ELF: the vector table at the fixture's own flash origin.
    let vma = vector_table(&release.join("downstream"))?;
    if vma != "08000000" {
        return Err(format!(
            "downstream: .vector_table at 0x{vma}, not at the crate's own flash origin 0x08000000"
        ));
    }
    println!(
        "xtask: downstream firmware crate (no `firmware` feature, its own memory.x): vector table at 0x{vma}, no link directive from the library, static processor builds"
    );
    Ok(())
}
