//! The host-side tasks: `test`, `figures` and `ci` (everything `.ci/run`
//! runs).

use std::path::Path;

use crate::bench::{bench, bench_args};
use crate::demo::demo;
use crate::profile::profile;
use crate::setup::setup_toolchain;
use crate::util::{root, run, THUMB};

pub fn test() -> Result<(), String> {
    let r = root();
    run(&r, "cargo", &["test", "--target", "host-tuple", "--lib"])?;
    run(&r, "cargo", &["test", "--target", "host-tuple", "--doc"])?;
    run(&r.join("host_tests"), "cargo", &["test"])
}

pub fn figures() -> Result<(), String> {
    run(
        &root().join("host_tests"),
        "cargo",
        &["run", "--release", "--bin", "figures", "--", "../docs"],
    )
}

pub fn ci() -> Result<(), String> {
    let r = root();
    let h = r.join("host_tests");
    setup_toolchain()?;
    let cargo = |dir: &Path, args: &[&str]| run(dir, "cargo", args);
    cargo(&r, &["fmt", "--check"])?;
    cargo(&h, &["fmt", "--check"])?;
    cargo(&r.join("xtask"), &["fmt", "--check"])?;
    // The library for the vehicle controller, without and with defmt.
    cargo(&r, &["build", "--release", "--target", THUMB])?;
    cargo(
        &r,
        &[
            "build",
            "--release",
            "--target",
            THUMB,
            "--features",
            "defmt",
        ],
    )?;
    cargo(&r, &["clippy", "--target", THUMB, "--", "-D", "warnings"])?;
    cargo(
        &r,
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
    cargo(
        &r,
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
    cargo(&h, &["clippy", "--all-targets", "--", "-D", "warnings"])?;
    cargo(
        &r,
        &[
            "clippy",
            "--release",
            "--target",
            THUMB,
            "--features",
            "firmware",
            "--bins",
            "--",
            "-D",
            "warnings",
        ],
    )?;
    // The README's test command.
    test()?;
    // The firmware on the emulated controller: the demo, compared frame by
    // frame with the host build, then the benchmark, budgets and proofs.
    demo(true)?;
    bench(&bench_args(&[])?)?;
    // The profiler too, so it cannot rot (about ten seconds).
    profile()
}
