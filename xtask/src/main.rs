//! `cargo xtask <task>`: the project's automation, in plain Rust.
//!
//! * `test`    — every host test: the library's unit and doc tests, and the
//!   `host_tests` crate (synthetic roads with ground truth).
//! * `figures` — re-render `docs/` (figures and the replay example).
//! * `ci`      — what `.ci/run` runs: toolchain setup, formatting, clippy,
//!   thumb builds with and without `defmt`, then `test`.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

const TOOLCHAIN: &str = "1.95.0";
const THUMB: &str = "thumbv7em-none-eabihf";

fn root() -> PathBuf {
    // xtask/ lives directly under the repository root.
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

fn run(dir: &Path, program: &str, args: &[&str]) -> Result<(), String> {
    println!("xtask: ({}) {} {}", dir.display(), program, args.join(" "));
    let status = Command::new(program)
        .args(args)
        .current_dir(dir)
        .status()
        .map_err(|e| format!("cannot start {program}: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("`{program} {}` failed ({status})", args.join(" ")))
    }
}

/// Install the thumb target and components of the pinned toolchain
/// (idempotent; `RUSTUP_AUTO_INSTALL=0` means nobody else will).
fn setup_toolchain() -> Result<(), String> {
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

fn test() -> Result<(), String> {
    let r = root();
    run(&r, "cargo", &["test", "--target", "host-tuple", "--lib"])?;
    run(&r, "cargo", &["test", "--target", "host-tuple", "--doc"])?;
    run(&r.join("host_tests"), "cargo", &["test"])
}

fn figures() -> Result<(), String> {
    run(
        &root().join("host_tests"),
        "cargo",
        &["run", "--release", "--bin", "figures", "--", "../docs"],
    )
}

fn ci() -> Result<(), String> {
    let r = root();
    let h = r.join("host_tests");
    setup_toolchain()?;
    run(&r, "cargo", &["fmt", "--check"])?;
    run(&h, "cargo", &["fmt", "--check"])?;
    run(&r.join("xtask"), "cargo", &["fmt", "--check"])?;
    // The library for the vehicle controller, without and with defmt.
    run(&r, "cargo", &["build", "--release", "--target", THUMB])?;
    run(
        &r,
        "cargo",
        &[
            "build",
            "--release",
            "--target",
            THUMB,
            "--features",
            "defmt",
        ],
    )?;
    run(
        &r,
        "cargo",
        &["clippy", "--target", THUMB, "--", "-D", "warnings"],
    )?;
    run(
        &r,
        "cargo",
        &[
            "clippy",
            "--target",
            THUMB,
            "--features",
            "defmt",
            "--",
            "-D",
            "warnings",
        ],
    )?;
    run(
        &r,
        "cargo",
        &[
            "clippy",
            "--target",
            "host-tuple",
            "--all-targets",
            "--",
            "-D",
            "warnings",
        ],
    )?;
    run(
        &h,
        "cargo",
        &["clippy", "--all-targets", "--", "-D", "warnings"],
    )?;
    test()
}

fn main() -> ExitCode {
    let task = std::env::args().nth(1).unwrap_or_default();
    let result = match task.as_str() {
        "test" => test(),
        "figures" => figures(),
        "ci" => ci(),
        "setup" => setup_toolchain(),
        _ => {
            eprintln!("usage: cargo xtask <test|figures|ci|setup>");
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}
