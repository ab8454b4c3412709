//! Link set-up for this package's own firmware binaries (feature
//! `firmware`, Cortex-M targets only): put `memory.x` (the emulated
//! controller's map) on the linker search path and link the binaries with
//! cortex-m-rt's `link.x` (and defmt's `defmt.x` where defmt logs).
//!
//! Without the `firmware` feature nothing is emitted, so a firmware crate
//! that depends on this library links with its own `memory.x`: a link
//! search path a build script prints reaches every crate linked after it,
//! and this one must not put the emulator's map in front of a board's
//! (`cargo xtask ci` checks it with a downstream crate whose map differs).

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    let target = env::var("TARGET").unwrap_or_default();
    let firmware = env::var_os("CARGO_FEATURE_FIRMWARE").is_some();
    if !target.starts_with("thumbv") || !firmware {
        return;
    }
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    fs::write(out.join("memory.x"), include_bytes!("memory.x")).expect("write memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    for bin in ["demo", "bench", "profile", "link"] {
        println!("cargo:rustc-link-arg-bin={bin}=-Tdefmt.x");
    }
}
