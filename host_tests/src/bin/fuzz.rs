//! The seeded fuzz pass (issue 15): `fuzz [--seconds S] [--threads T]
//! [--seed X] [--targets frame:6,calibration:1,...,fusion:2] [--cases N]
//! [--case-limit S] [--save DIR]`.
//!
//! Runs each target's structured generator (see `host_tests::fuzz`) on
//! seeds `X, X+1, ...` for its share of `S` seconds on `T` threads, every
//! case against its oracles, with a per-case time limit (a hang ends the
//! run, exit 3, naming the seed and printing the case). Prints the cases,
//! calls and rates per target; exit 1 if any case broke an oracle (each
//! is printed with its seed: `--seed X --cases 1 --threads 1` repeats it).
//! `--save DIR` writes the draws of every case that showed a new feature
//! (and of every finding) to `DIR/<target>/`, for the saved corpus.
//! Build it with the `checked` profile (overflow checks on):
//! `cargo run --profile checked --bin fuzz -- ...` (`cargo xtask fuzz`).

use std::time::Duration;

/// The usage `--help` prints (the module docs say more).
const USAGE: &str = "usage: fuzz [--seconds S] [--threads T] [--seed X] \
[--targets frame:6,calibration:1,geometry:1,replay:1,fusion:2] [--cases N] \
[--case-limit S] [--save DIR]; fuzz --describe TARGET SEED prints a case \
(cargo xtask fuzz passes these on; the libFuzzer targets are in fuzz/, on nightly)";

use host_tests::fuzz::{pass, Pass, Target};

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut p = Pass {
        targets: vec![
            (Target::Frame, 6),
            (Target::Calibration, 1),
            (Target::Geometry, 1),
            (Target::Replay, 1),
            (Target::Fusion, 2),
        ],
        seed: 0,
        time: Duration::from_secs(60),
        max_cases: u64::MAX,
        threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        case_limit: Duration::from_secs(10),
        save: None,
    };
    // `fuzz --describe TARGET SEED`: print the case of a seed.
    if let [flag, target, seed] = args.as_slice() {
        if flag == "--describe" {
            let (Some(t), Ok(seed)) = (Target::from_name(target), seed.parse()) else {
                eprintln!("fuzz: usage: --describe TARGET SEED");
                return std::process::ExitCode::from(2);
            };
            println!(
                "{}",
                t.describe(&mut host_tests::fuzz::Source::seeded(seed))
            );
            return std::process::ExitCode::SUCCESS;
        }
    }
    // `fuzz --pair SEED`: the first frame pair of a (small) frame case
    // where the indexed matcher and the reference differ, reduced.
    if let [flag, seed] = args.as_slice() {
        if flag == "--pair" {
            use host_tests::fuzz::frame;
            let Ok(seed) = seed.parse() else {
                return std::process::ExitCode::from(2);
            };
            let case = frame::generate(&mut host_tests::fuzz::Source::seeded(seed));
            match frame::first_differing_pair(&case) {
                None => println!("fuzz: seed {seed}: the matchers agree (or a large case)"),
                Some(p) => {
                    let p = p.shrink();
                    println!("{p:?}");
                    if let Some((a, b)) = p.statuses() {
                        for (i, (x, y)) in a.iter().zip(&b).enumerate() {
                            if x != y {
                                println!("point {i}: indexed {x:?}, reference {y:?}");
                            }
                        }
                    }
                }
            }
            return std::process::ExitCode::SUCCESS;
        }
    }
    // `fuzz --shrink SEED`: shrink a failing frame case.
    if let [flag, seed] = args.as_slice() {
        if flag == "--shrink" {
            let Ok(seed) = seed.parse() else {
                return std::process::ExitCode::from(2);
            };
            use host_tests::fuzz::frame;
            let case = frame::generate(&mut host_tests::fuzz::Source::seeded(seed));
            std::panic::set_hook(Box::new(|_| {}));
            let message = |c: &frame::Case| {
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| frame::check(c)))
                    .err()
                    .map(|e| host_tests::fuzz::panic_message(&*e))
            };
            let Some(first) = message(&case) else {
                println!("fuzz: seed {seed}: no finding");
                return std::process::ExitCode::SUCCESS;
            };
            let key = first.split(':').next().unwrap_or("").to_string();
            let small = frame::shrink(&case, &|c| message(c).is_some_and(|m| m.starts_with(&key)));
            println!("{small:#?}\n{}", message(&small).unwrap_or_default());
            return std::process::ExitCode::SUCCESS;
        }
    }
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || it.next().cloned().unwrap_or_default();
        let bad = |what: &str| {
            eprintln!("fuzz: bad {what}");
            std::process::ExitCode::from(2)
        };
        match a.as_str() {
            "--seconds" => match value().parse::<f64>() {
                Ok(s) if s >= 0.0 => p.time = Duration::from_secs_f64(s),
                _ => return bad("--seconds"),
            },
            "--threads" => match value().parse() {
                Ok(t) => p.threads = t,
                _ => return bad("--threads"),
            },
            "--seed" => match value().parse() {
                Ok(s) => p.seed = s,
                _ => return bad("--seed"),
            },
            "--cases" => match value().parse() {
                Ok(n) => p.max_cases = n,
                _ => return bad("--cases"),
            },
            "--case-limit" => match value().parse::<f64>() {
                Ok(s) if s > 0.0 => p.case_limit = Duration::from_secs_f64(s),
                _ => return bad("--case-limit"),
            },
            "--help" | "-h" => {
                println!("{USAGE}");
                return std::process::ExitCode::SUCCESS;
            }
            "--save" => p.save = Some(value().into()),
            "--targets" => {
                let mut t = Vec::new();
                for item in value().split(',') {
                    let (name, w) = item.split_once(':').unwrap_or((item, "1"));
                    match (Target::from_name(name), w.parse()) {
                        (Some(x), Ok(w)) => t.push((x, w)),
                        _ => return bad("--targets"),
                    }
                }
                p.targets = t;
            }
            _ => {
                eprintln!("fuzz: unknown argument {a}\n{USAGE}");
                return std::process::ExitCode::from(2);
            }
        }
    }
    println!(
        "fuzz: seed {}, {:.0} s on {} thread(s), case limit {:?}, overflow checks {}",
        p.seed,
        p.time.as_secs_f64(),
        p.threads,
        p.case_limit,
        if cfg!(debug_assertions) { "on" } else { "OFF" }
    );
    host_tests::fuzz::quiet_panics();
    let results = pass(&p);
    let mut findings = 0;
    println!("fuzz: target       cases      calls    seconds   cases/s  features  slowest case");
    for (t, r) in &results {
        println!(
            "fuzz: {:<11} {:>9} {:>10} {:>10.1} {:>9.0} {:>9}  {:.3} s (seed {})",
            t.name(),
            r.cases,
            r.calls,
            r.seconds,
            r.cases as f64 / r.seconds.max(1e-9),
            r.features.count_ones(),
            r.slowest.0,
            r.slowest.1
        );
        if r.reconstructions > 0 {
            println!(
                "fuzz: {:<11} {} reconstructions ({:.0}/s) of {} points, {} with a depth",
                t.name(),
                r.reconstructions,
                r.reconstructions as f64 / r.seconds.max(1e-9),
                r.points[0],
                r.points[1]
            );
        }
        for (seed, msg) in &r.findings {
            println!("fuzz: FINDING {} seed {seed}: {msg}", t.name());
        }
        findings += r.findings.len();
    }
    let cases: u64 = results.iter().map(|r| r.1.cases).sum();
    println!("fuzz: {cases} cases, {findings} finding(s)");
    if findings > 0 {
        std::process::ExitCode::FAILURE
    } else {
        std::process::ExitCode::SUCCESS
    }
}
