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

/// The wedge path for pseudo-angle keys (a frame-2 boundary near or across
/// the FOE's row) against its reference, on boundaries built for it: a
/// steep line across the FOE's row, a curve round the FOE's left side, and
/// a hairpin round it (in along the row above it, down, and out below it:
/// its keys span nearly a turn, so wedges near the row have two copies in
/// the unwrapped keys and take the band path), each exact and rounded to
/// the pixel grid, frame 2 the frame-1 boundary seen from 0.4 closer (a
/// constant depth, so every point has its correspondent). (Counted when
/// written: every point of the line and the curve walked a wedge, and one
/// of the exact hairpin's took the band path.)
#[test]
fn angular_wedge_equals_reference_near_and_round_the_foe() {
    use roadstereo::{Camera, Motion, Pixel};
    let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).expect("camera");
    let m = Motion::new([0.0, 0.0, 0.4], [0.0, 0.0, 0.0]).expect("motion");
    let foe = [255.5f64, 239.5f64];
    // Depth 6: frame 2 sees every point 6/5.6 times as far from the FOE.
    let s = 6.0 / 5.6;
    let line: Vec<[f64; 2]> = (0..360)
        .map(|i| [100.0 + 0.3 * (i as f64 - 180.0), 60.0 + i as f64])
        .collect();
    let curve: Vec<[f64; 2]> = (0..300)
        .map(|i| {
            let a = -1.4 + 2.8 * i as f64 / 299.0;
            [foe[0] - 150.0 * a.cos(), foe[1] + 150.0 * a.sin()]
        })
        .collect();
    // (Within 1.6 px of the FOE's row over the legs, as a v-monotone
    // curve must be to turn nearly once round the FOE.)
    let mut hairpin: Vec<[f64; 2]> = (0..120)
        .map(|i| [470.0 - 3.9 * i as f64, foe[1] - 1.6 + 0.003 * i as f64])
        .collect();
    hairpin.extend((1..60).map(|i| [6.0 + 0.1 * i as f64, foe[1] - 1.24 + 0.04 * i as f64]));
    hairpin.extend((0..120).map(|i| [12.0 + 3.9 * i as f64, foe[1] + 1.24 + 0.003 * i as f64]));
    let inside = |p: &Pixel| p.u >= 0.0 && p.u <= 511.0 && p.v >= 0.0 && p.v <= 479.0;
    let mut oks = 0;
    for (name, b) in [("line", &line), ("curve", &curve), ("hairpin", &hairpin)] {
        for quantised in [false, true] {
            let px = |q: [f64; 2]| {
                let q = if quantised {
                    [q[0].round(), q[1].round()]
                } else {
                    q
                };
                Pixel::new(q[0] as f32, q[1] as f32)
            };
            let mut b1: Vec<Pixel> = b.iter().map(|&q| px(q)).filter(inside).collect();
            let mut b2: Vec<Pixel> = b
                .iter()
                .map(|&q| px([foe[0] + s * (q[0] - foe[0]), foe[1] + s * (q[1] - foe[1])]))
                .filter(inside)
                .collect();
            // Rounding may repeat a row: keep the first point of each.
            b1.dedup_by(|a, b| a.v <= b.v);
            b2.dedup_by(|a, b| a.v <= b.v);
            let (f1, f2) = (frame(cam, &[b1]), frame(cam, &[b2]));
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
                panic!("{name} (quantised: {quantised}): boundary {k} point {i}: indexed {a:?}, reference {b:?}");
            }
            let pts = fast.boundaries()[0].points();
            let ok = pts.iter().filter(|r| r.status() == Status::Ok).count();
            println!("{name} (quantised: {quantised}): {ok} of {} ok", pts.len());
            oks += ok;
        }
    }
    assert!(oks > 100, "the wedges matched {oks} points");
}

/// The adversarial family's pairs under localisation errors of 1.5–10 px,
/// where most sticks are refined by the piece's lines (from a review of
/// the refinement's charge): with the largest budget the indexed search
/// equals the reference, and at 16 budgets from 8 to 160 every point is
/// equal, `over_budget`, or `ok` with the same match and a looser stick.
#[test]
fn refinement_under_every_budget_on_the_adversarial_family() {
    use host_tests::drive::adversarial::{family, library_pair, render};
    use host_tests::fuzz::frame::looser_stick;
    let (mut equal, mut over, mut looser, mut bad) = (0usize, 0usize, 0usize, 0usize);
    for m in family() {
        for n in [64usize, 256] {
            let Ok((k, frames)) = render(&m.params, n) else {
                continue;
            };
            let (f1, f2, motion) = library_pair(&k, &frames);
            for e in [1.5f32, 3.0, 6.0, 10.0] {
                let base = m.errors.config().with_localisation_error(e, e).unwrap();
                let largest = base.with_work_budget(Config::MAX_WORK_PER_POINT).unwrap();
                let mut p = Box::new(Processor::<512, 2>::new(largest));
                let _ = p.process(&f1, None);
                let Ok(fast) = p.process_against_kept(&f2, &motion) else {
                    continue;
                };
                let fast = Box::new(fast.clone());
                let reference = Box::new(p.reference_against_kept(&f2, &motion).unwrap().clone());
                assert!(
                    fast == reference,
                    "{} at N = {n}, e = {e}: the indexed search differs from the reference",
                    m.name
                );
                for w in [
                    8u32, 9, 10, 11, 12, 14, 16, 20, 24, 32, 40, 48, 64, 80, 120, 160,
                ] {
                    p.set_config(base.with_work_budget(w).unwrap());
                    let got = p.process_against_kept(&f2, &motion).unwrap();
                    for (x, y) in got.boundaries().iter().zip(fast.boundaries()) {
                        for (a, b) in x.points().iter().zip(y.points()) {
                            if a == b {
                                equal += 1;
                            } else if looser_stick(a, b) {
                                looser += 1;
                            } else if a.status() == Status::OverBudget {
                                over += 1;
                            } else {
                                bad += 1;
                                eprintln!(
                                    "{} N = {n} e = {e} w = {w}: {a:?}, largest {b:?}",
                                    m.name
                                );
                            }
                        }
                    }
                }
            }
        }
    }
    eprintln!("equal {equal}, over_budget {over}, ok with a looser stick {looser}, other {bad}");
    assert_eq!(bad, 0);
    assert!(
        looser > 0,
        "no budget loosened a stick: the test does not reach the refinement"
    );
}
