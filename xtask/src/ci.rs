//! The host-side tasks: `test`, `fuzz`, `figures` and `ci` (everything `.ci/run`
//! runs).

use crate::bench::{bench, bench_args};
use crate::demo::demo_on_both_boards;
use crate::profile::{profile, ProfileArgs};
use crate::setup::setup_toolchain;
use crate::stream::stream;
use crate::util::{root, run, THUMB};

/// The README's test command: the library's unit and doc tests on the host,
/// then `host_tests` in its `checked` profile (optimised, with overflow
/// checks and debug assertions on in every crate: an overflow anywhere is
/// a failing test, issue 15 item 5; the library's own unit tests run in
/// the dev profile, which has them on too).
pub fn test() -> Result<(), String> {
    let r = root();
    run(&r, "cargo", &["test", "--target", "host-tuple", "--lib"])?;
    run(&r, "cargo", &["test", "--target", "host-tuple", "--doc"])?;
    run(
        &r.join("host_tests"),
        "cargo",
        &["test", "--profile", "checked"],
    )
}

/// Seconds of the fuzz pass in CI, on every core (two on the CI machine):
/// with its build, about two minutes. The pass is the stable seeded
/// generator; cargo-fuzz (`fuzz/`, nightly) is for long local runs.
pub const CI_FUZZ_SECONDS: &str = "110";

/// The seeded fuzz pass (`host_tests/src/bin/fuzz.rs`, stable, the
/// `checked` profile): `args` go to the pass (`--seconds`, `--threads`,
/// `--seed`, `--targets`, `--save`, ...); fails on any finding.
pub fn fuzz(args: &[String]) -> Result<(), String> {
    let mut all = vec!["run", "--profile", "checked", "--bin", "fuzz", "--"];
    all.extend(args.iter().map(String::as_str));
    run(&root().join("host_tests"), "cargo", &all)
}

/// Re-render `docs/` (figures and the replay example).
pub fn figures() -> Result<(), String> {
    run(
        &root().join("host_tests"),
        "cargo",
        &["run", "--release", "--bin", "figures", "--", "../docs"],
    )
}

/// What `ci` runs before the tests, in order: (folder under the repository
/// root, `""` for the root itself; cargo's arguments).
#[rustfmt::skip]
const CARGO_CHECKS: &[(&str, &[&str])] = &[
    ("", &["fmt", "--check"]),
    ("host_tests", &["fmt", "--check"]),
    ("xtask", &["fmt", "--check"]),
    // The library for the vehicle controller, without and with defmt.
    ("", &["build", "--release", "--target", THUMB]),
    ("", &["build", "--release", "--target", THUMB, "--features", "defmt"]),
    ("", &["clippy", "--target", THUMB, "--", "-D", "warnings"]),
    ("", &["clippy", "--target", THUMB, "--features", "defmt", "--", "-D", "warnings"]),
    // The API docs, without a broken or private link; and the crate's
    // internal docs (the maintainers' reading), without a broken link.
    ("", &["rustdoc", "--lib", "--target", "host-tuple", "--", "-D", "warnings"]),
    ("", &["rustdoc", "--lib", "--target", "host-tuple", "--", "-D", "warnings", "--document-private-items"]),
    // The library's tests and the host tests.
    ("", &["clippy", "--target", "host-tuple", "--all-targets", "--", "-D", "warnings"]),
    ("host_tests", &["clippy", "--all-targets", "--", "-D", "warnings"]),
    // The firmware binaries.
    ("", &["clippy", "--release", "--target", THUMB, "--features", "firmware", "--bins", "--", "-D", "warnings"]),
    // ... the link firmware's fused and deadline modes (`cargo xtask stream
    // --fused --within` builds the same),
    ("", &["clippy", "--release", "--target", THUMB, "--features", "firmware link-deadline link-fused", "--bin", "link", "--", "-D", "warnings"]),
    // ... the profile firmware's fusion window (`cargo xtask profile --fusion`),
    ("", &["clippy", "--release", "--target", THUMB, "--features", "profile-fusion", "--bin", "profile", "--", "-D", "warnings"]),
    // ... and for the second board (its own target dir, as `Board` builds it).
    ("", &["clippy", "--release", "--target", THUMB, "--features", "board-f405", "--bins", "--target-dir", "target/f405", "--", "-D", "warnings"]),
];

/// Everything CI runs: toolchain setup, the cargo checks above, the tests,
/// then the firmware on the emulated controller.
pub fn ci() -> Result<(), String> {
    let r = root();
    setup_toolchain()?;
    for (dir, args) in CARGO_CHECKS {
        let dir = if dir.is_empty() {
            r.clone()
        } else {
            r.join(dir)
        };
        run(&dir, "cargo", args)?;
    }
    // The README's test command.
    test()?;
    // A board's firmware crate links with its own memory map.
    crate::downstream::downstream()?;
    // The fuzz pass, bounded (see `CI_FUZZ_SECONDS`).
    fuzz(&["--seconds".to_string(), CI_FUZZ_SECONDS.to_string()])?;
    // The firmware on the emulated controller: the demo, compared frame by
    // frame with the host build, then the benchmark, budgets and proofs.
    // The same on the STM32F405 build (its memory map and clock), on QEMU's
    // netduinoplus2: the same results, the same instruction counts.
    demo_on_both_boards()?;
    // The link: the README's example drive streamed over UART0, then the
    // demo drive with faults injected, without and within a deadline; any
    // divergence fails.
    stream(&["docs/example.jsonl".into()])?;
    // (The same faults both times; the second within a deadline on the
    // firmware, feature `link-deadline`: every frame within the budget,
    // each result the host's point for point or `over_budget`.)
    let faulty = [
        "--drive",
        "src/bin/data/drive.bin",
        "--corrupt",
        "0.1",
        "--drop",
        "0.05",
        "--duplicate",
        "0.05",
        "--seed",
        "1",
    ];
    // Then the same through the key-frame fusion (feature `link-fused`):
    // every packet and the fusion's digest after every frame the host's,
    // and within a deadline every frame within the budget.
    for (within, fused) in [(false, false), (true, false), (false, true), (true, true)] {
        let mut args: Vec<String> = faulty.iter().map(|a| a.to_string()).collect();
        if within {
            args.push("--within".into());
        }
        if fused {
            args.push("--fused".into());
        }
        stream(&args)?;
    }
    let bench = bench(&bench_args(&[])?);
    // The profiler too, so it cannot rot (about ten seconds), with its
    // cycles budget; it runs even when a bench budget is missed, so both
    // verdicts are printed.
    let profile = profile(ProfileArgs::DEFAULT);
    bench.and(profile)
}
