//! The fuzz harness on stable (issue 15): the saved corpus of
//! interesting cases (`fuzz_corpus/<target>/`, the draws of each case)
//! replayed against every oracle with a per-case time limit, a short
//! seeded pass of each target, and the guard that this profile checks
//! overflows. The long pass is `cargo xtask fuzz` (src/bin/fuzz.rs).

use std::path::Path;
use std::time::Duration;

use host_tests::fuzz::{corpus_files, within, Source, Target};

/// Per-case time limit (the slowest cases take milliseconds).
const LIMIT: Duration = Duration::from_secs(20);

/// The profile the host tests run in has overflow checks and debug
/// assertions on, for this crate and for roadstereo alike (profiles
/// apply to every crate of the build).
#[test]
fn overflow_checks_and_debug_assertions_are_on() {
    assert!(
        std::hint::black_box(cfg!(debug_assertions)),
        "debug assertions are off (run the host tests with `--profile checked`)"
    );
    let r = std::panic::catch_unwind(|| std::hint::black_box(u32::MAX) + std::hint::black_box(1));
    assert!(
        r.is_err(),
        "an overflowing add did not panic: overflow checks are off (run the host tests in the \
         `checked` profile, as `cargo xtask test` does: `cargo test --profile checked`)"
    );
}

fn replay_corpus(target: Target) -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz_corpus")
        .join(target.name());
    let files = corpus_files(&dir);
    for f in &files {
        let bytes = std::fs::read(f).expect("corpus file");
        let name = f.display().to_string();
        within(LIMIT, move || {
            let r = std::panic::catch_unwind(|| target.run(&mut Source::bytes(&bytes)));
            if let Err(e) = r {
                panic!("{name}: {}", host_tests::fuzz::panic_message(&*e));
            }
        });
    }
    files.len()
}

#[test]
fn saved_frame_cases() {
    assert!(replay_corpus(Target::Frame) >= 20);
}

#[test]
fn saved_calibration_cases() {
    assert!(replay_corpus(Target::Calibration) >= 5);
}

#[test]
fn saved_geometry_cases() {
    assert!(replay_corpus(Target::Geometry) >= 3);
}

#[test]
fn saved_replay_cases() {
    assert!(replay_corpus(Target::Replay) >= 2);
}

#[test]
fn saved_fusion_cases() {
    assert!(replay_corpus(Target::Fusion) >= 20);
}

/// A recorded case replays as the same case: the corpus format is the
/// generator's draws.
#[test]
fn recorded_draws_give_the_same_case() {
    for target in Target::ALL {
        for seed in 0..50 {
            let mut src = Source::seeded(seed).recording();
            let a = target.describe(&mut src);
            let b = target.describe(&mut Source::bytes(src.recorded()));
            assert_eq!(a, b, "{} seed {seed}", target.name());
        }
    }
}

/// A few thousand seeded cases of each target (the CI pass runs far more).
#[test]
fn seeded_smoke_pass() {
    for (target, n) in [
        (Target::Frame, 3000),
        (Target::Calibration, 3000),
        (Target::Geometry, 300),
        (Target::Replay, 1000),
        (Target::Fusion, 3000),
    ] {
        for seed in 0..n {
            let r = std::panic::catch_unwind(|| target.run(&mut Source::seeded(seed)));
            if let Err(e) = r {
                panic!(
                    "{} seed {seed}: {}",
                    target.name(),
                    host_tests::fuzz::panic_message(&*e)
                );
            }
        }
    }
}

/// The per-case time limit catches a case that does not return.
#[test]
fn a_case_past_the_time_limit_is_a_failure() {
    let r = std::panic::catch_unwind(|| {
        within(Duration::from_millis(50), || {
            std::thread::sleep(Duration::from_secs(2));
        })
    });
    let msg = host_tests::fuzz::panic_message(&*r.expect_err("must time out"));
    assert!(msg.contains("hang"), "{msg}");
}

/// The fusion target's generator reaches every path its feature bits
/// name (errors, key-frame reasons, retirements, the map's drops, cut
/// pairs, conflicts, saturated counts, ...): a change of the generator or
/// of the fusion that leaves one unreached fails here.
#[test]
fn fusion_cases_reach_every_path() {
    use host_tests::fuzz::fusion::bit;
    let mut seen = 0u128;
    for seed in 0..6000 {
        seen |= Target::Fusion.run(&mut Source::seeded(seed)).features;
    }
    let missing: Vec<u32> = (bit::FUSION_ERR..bit::END)
        .filter(|b| seen & (1u128 << b) == 0)
        .collect();
    assert!(
        missing.is_empty(),
        "fusion feature bits never set: {missing:?}"
    );
}
