//! Firmware link set-up (only when building for a Cortex-M target): put
//! `memory.x` on the linker search path and link the binaries with
//! cortex-m-rt's `link.x` (and defmt's `defmt.x` where defmt logs).

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    let target = env::var("TARGET").unwrap_or_default();
    if !target.starts_with("thumbv") {
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
