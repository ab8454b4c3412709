//! The indexed crossing search gives exactly the results of the reference
//! matcher, which offers every frame-2 segment to every point's walk.
//!
//! The reference has no work budget, so the comparison runs with the
//! largest one; with the default budget the indexed search may only flag
//! points `over_budget` on top (checked separately).

use host_tests::{frame, scenarios, synth, B, N};
use roadstereo::{Config, PointResult, Processor, Status, Step, Structure};

/// The first point where two structures differ, for the message.
fn first_difference(
    a: &Structure<N, B>,
    b: &Structure<N, B>,
) -> Option<(usize, usize, PointResult, PointResult)> {
    for (k, (x, y)) in a.boundaries().iter().zip(b.boundaries()).enumerate() {
        for (i, (p, q)) in x.points().iter().zip(y.points()).enumerate() {
            if p != q {
                return Some((k, i, *p, *q));
            }
        }
        if x.points().len() != y.points().len() {
            return Some((
                k,
                x.points().len().min(y.points().len()),
                PointResult::default(),
                PointResult::default(),
            ));
        }
    }
    None
}

fn both(s: &synth::Scenario, quantised: bool) {
    let r = s.render();
    let cam = s.intrinsics.camera();
    let f1 = frame(cam, &synth::Rendered::pixels(&r.frame1, quantised));
    let f2 = frame(cam, &synth::Rendered::pixels(&r.frame2, quantised));
    let m = r.motion();
    let unlimited = Config::DEFAULT
        .with_work_budget(Config::MAX_WORK_PER_POINT)
        .expect("valid");
    let mut p = Box::new(Processor::<N, B>::new(unlimited));
    assert!(matches!(p.process(&f1, None), Ok(Step::First)));
    let fast = p.process_against_kept(&f2, &m).expect("structure").clone();
    let slow = p
        .reference_against_kept(&f2, &m)
        .expect("structure")
        .clone();
    if let Some((k, i, a, b)) = first_difference(&fast, &slow) {
        panic!(
            "{} (quantised: {quantised}): boundary {k} point {i}: indexed {a:?}, reference {b:?}",
            s.name
        );
    }
    // The default budget: the same, or over_budget.
    let mut d = Box::new(Processor::<N, B>::new(Config::DEFAULT));
    assert!(matches!(d.process(&f1, None), Ok(Step::First)));
    let budgeted = d.process_against_kept(&f2, &m).expect("structure");
    for (x, y) in budgeted.boundaries().iter().zip(slow.boundaries()) {
        for (p, q) in x.points().iter().zip(y.points()) {
            assert!(
                p == q || p.status() == Status::OverBudget,
                "{} (quantised: {quantised}): with the default budget {p:?}, reference {q:?}",
                s.name
            );
        }
    }
}

#[test]
fn indexed_search_equals_reference_on_named_scenarios() {
    let mut all = scenarios::named();
    all.push(scenarios::degenerate());
    for s in &all {
        both(s, false);
        both(s, true);
    }
}

#[test]
fn indexed_search_equals_reference_on_random_scenarios() {
    for seed in 0..300 {
        let s = scenarios::random(seed);
        both(&s, false);
        both(&s, true);
    }
}

/// The same on every frame pair of the firmware's embedded data
/// (`src/bin/data/`): the benchmark and stress pairs, the demo drive, and
/// the adversarial inputs (spurious points in either frame, folds, radial
/// stairs, zig-zags, a FOE on or near a boundary), whose frame-2 indexes
/// set segments aside or come out loose.
#[test]
fn indexed_search_equals_reference_on_embedded_data() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../src/bin/data");
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .expect("data dir")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "bin"))
        .collect();
    files.sort();
    let mut pairs = 0;
    for path in &files {
        let bytes = std::fs::read(path).expect("read");
        let Some((cam, frames)) = host_tests::drive::decode(&bytes) else {
            continue;
        };
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let mk = |f: &host_tests::drive::DriveFrame| {
            let mut fr = roadstereo::Frame::<N, B>::new(cam);
            for b in f.boundaries.iter().take(B) {
                let pts: Vec<_> = b
                    .iter()
                    .take(N)
                    .map(|q| roadstereo::Pixel::new(q[0], q[1]))
                    .collect();
                fr.push_boundary(&pts).expect("boundary");
            }
            fr
        };
        for w in frames.windows(2).take(6) {
            let (f1, f2) = (mk(&w[0]), mk(&w[1]));
            let m = roadstereo::Motion::new(w[1].translation, w[1].rotation).expect("motion");
            let unlimited = Config::DEFAULT
                .with_work_budget(Config::MAX_WORK_PER_POINT)
                .expect("valid");
            let mut p = Box::new(Processor::<N, B>::new(unlimited));
            let _ = p.process(&f1, None);
            let fast = p.process_against_kept(&f2, &m).expect("structure").clone();
            let slow = p
                .reference_against_kept(&f2, &m)
                .expect("structure")
                .clone();
            if let Some((k, i, a, b)) = first_difference(&fast, &slow) {
                panic!("{name:?}: boundary {k} point {i}: indexed {a:?}, reference {b:?}");
            }
            let mut d = Box::new(Processor::<N, B>::new(Config::DEFAULT));
            let _ = d.process(&f1, None);
            let budgeted = d.process_against_kept(&f2, &m).expect("structure");
            for (x, y) in budgeted.boundaries().iter().zip(slow.boundaries()) {
                for (p, q) in x.points().iter().zip(y.points()) {
                    assert!(
                        p == q || p.status() == Status::OverBudget,
                        "{name:?}: with the default budget {p:?}, reference {q:?}"
                    );
                }
            }
            pairs += 1;
        }
    }
    assert!(pairs >= 60, "{pairs}");
}
