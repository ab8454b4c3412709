//! Link set-up for this package's own firmware binaries (feature
//! `firmware`, Cortex-M targets only): put `memory.x` and the board's
//! memory map, as `board.x`, on the linker search path (the emulated
//! controller's, `src/bin/fw/boards/mps2-an386.x`, or with `board-f405` an
//! STM32F405's, `src/bin/fw/boards/stm32f405.x`; `memory.x` includes
//! `board.x`) and link the binaries with cortex-m-rt's `link.x` (and
//! defmt's `defmt.x` where defmt logs).
//!
//! The indirection is needed because the linker looks for `memory.x` in
//! the package root before the search path: a map written there would
//! always win over the board's.
//!
//! Without the `firmware` feature nothing is emitted, so a firmware crate
//! that depends on this library links with its own `memory.x`: a link
//! directive here would leak into every downstream binary.

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=src/bin/fw/boards");
    println!("cargo:rerun-if-changed=build.rs");
    let target = env::var("TARGET").unwrap_or_default();
    let firmware = env::var_os("CARGO_FEATURE_FIRMWARE").is_some();
    if !target.starts_with("thumbv") || !firmware {
        return;
    }
    // The board's memory map (see src/bin/fw/board.rs): the emulator's by
    // default.
    let board: &[u8] = if env::var_os("CARGO_FEATURE_BOARD_F405").is_some() {
        include_bytes!("src/bin/fw/boards/stm32f405.x")
    } else {
        include_bytes!("src/bin/fw/boards/mps2-an386.x")
    };
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::write(out.join("memory.x"), include_bytes!("memory.x")).expect("write memory.x");
    fs::write(out.join("board.x"), board).expect("write board.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    for bin in ["demo", "bench", "profile", "link"] {
        println!("cargo:rustc-link-arg-bin={bin}=-Tdefmt.x");
    }
}
