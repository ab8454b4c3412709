//! The caller's deadline (`Processor::process_within`,
//! `roadstereo::deadline`): once the clock says the time is up, every point
//! not done is `over_budget` and the call returns; the points done before
//! are complete results. Here the clock is a count of the questions it is
//! asked, so every cut is reproducible; the firmware bench measures the
//! same with SysTick as the clock (`docs/VEHICLE.md`, "Within a deadline").
//!
//! The results are compared with the same configuration's with the
//! largest work budget and no deadline (whose sticks the certification
//! holds to the `f64` truth, `tests/certify.rs`, which also runs the
//! certification within a deadline), as the fuzzer's budget oracle does:
//! every point is equal to that result, `over_budget`, or `ok` with the
//! same match and a looser stick (its refinement paid less), never
//! anything else. (Under a deadline a point's search may spend at most
//! `CARRY` allowances between two questions, so the credit goes round
//! differently: a point may
//! come out `over_budget` before the time is up, and one that was
//! `over_budget` without a deadline may be done.)

use host_tests::drive::adversarial::{family, library_pair, render};
use host_tests::fuzz::frame::looser_stick;
use host_tests::{frame, scenarios, synth, B, N};
use roadstereo::{Config, Frame, Motion, Processor, Status, Step, Structure};

/// A clock that says the time is up from its `k`-th question on, and
/// counts the questions.
struct Clock {
    k: usize,
    asked: usize,
}

impl roadstereo::Deadline for Clock {
    fn expired(&mut self) -> bool {
        self.asked += 1;
        self.asked > self.k
    }
}

/// A clock that never says yes and caps nothing (`Deadline::carry`).
struct Uncapped;

impl roadstereo::Deadline for Uncapped {
    fn expired(&mut self) -> bool {
        false
    }
    fn carry(&self) -> u32 {
        u32::MAX
    }
}

#[derive(Default, Debug)]
struct Counts {
    equal: usize,
    over_budget: usize,
    looser: usize,
    cut_frames: usize,
    /// Points where a clock that never says yes gives another result than
    /// `process` (the cap, `CARRY`).
    capped: usize,
}

impl Counts {
    fn add(&mut self, o: &Counts) {
        self.equal += o.equal;
        self.over_budget += o.over_budget;
        self.looser += o.looser;
        self.cut_frames += o.cut_frames;
        self.capped += o.capped;
    }
}

/// `f2` against `p`'s kept frame within a clock that never says yes and
/// caps nothing ([`Uncapped`]) gives `plain`, `process`'s result
/// (`Deadline::carry`): every point, and the work units spent and granted
/// (which `Structure`'s equality leaves out).
fn assert_uncapped_is(
    p: &mut Processor<N, B>,
    (f2, m): (&Frame<N, B>, &Motion),
    plain: &Structure<N, B>,
    what: &str,
) {
    let free = Box::new(
        p.process_against_kept_within(f2, m, &mut Uncapped)
            .expect("kept")
            .clone(),
    );
    assert!(
        *free == *plain,
        "{what}: an uncapped clock that never says yes differs from process"
    );
    assert_eq!(
        free.work_units(),
        plain.work_units(),
        "{what}: an uncapped clock spent other work units than process"
    );
}

/// Every point of `got` (within a deadline) against `full` (the largest
/// budget, no deadline).
fn compare(got: &Structure<N, B>, full: &Structure<N, B>, what: &str, c: &mut Counts) {
    assert_eq!(got.boundaries().len(), full.boundaries().len(), "{what}");
    for (x, y) in got.boundaries().iter().zip(full.boundaries()) {
        assert_eq!(
            x.points().len(),
            y.points().len(),
            "{what}: one result per point"
        );
        for (a, b) in x.points().iter().zip(y.points()) {
            // (A cut point's slot is flagged with a pixel and a status,
            // its other bytes left: its pixel must still be its own.)
            assert_eq!(a.pixel1(), b.pixel1(), "{what}: another point's pixel");
            if a == b {
                c.equal += 1;
            } else if a.status() == Status::OverBudget {
                assert!(
                    a.depth().is_none() && a.interval().is_none() && a.pixel2().is_none(),
                    "{what}: an over_budget point with a result: {a:?}"
                );
                c.over_budget += 1;
            } else if looser_stick(a, b) {
                c.looser += 1;
            } else {
                panic!("{what}: within the deadline {a:?}, without {b:?}");
            }
        }
    }
}

/// The pair `(f1, f2)` within clocks that say yes from their `k`-th
/// question on, for every `k` from 0 to past the frame's last question.
fn sweep(config: Config, (f1, f2, m): (&Frame<N, B>, &Frame<N, B>, &Motion), what: &str) -> Counts {
    sweep_with(config, (f1, f2, m), what, false)
}

/// [`sweep`] with the counting rule for folded points on or off
/// (`Processor::set_fold_counting`).
fn sweep_with(
    config: Config,
    (f1, f2, m): (&Frame<N, B>, &Frame<N, B>, &Motion),
    what: &str,
    counting: bool,
) -> Counts {
    let largest = config
        .with_work_budget(Config::MAX_WORK_PER_POINT)
        .expect("the largest budget");
    let mut p = Box::new(Processor::<N, B>::new(largest));
    p.set_fold_counting(counting);
    assert!(matches!(p.process(f1, None), Ok(Step::First)));
    let Ok(full) = p.process_against_kept(f2, m) else {
        panic!("{what}: no structure");
    };
    let full = Box::new(full.clone());
    p.set_config(config);
    let default = Box::new(p.process_against_kept(f2, m).expect("kept").clone());
    assert!(!p.deadline_expired());
    let points: usize = full.boundaries().iter().map(|b| b.points().len()).sum();
    // The questions a frame asks without expiring: at most one a point
    // in step 1, the fold queries and step 4, a few a boundary, and one
    // before every 32 items of each pass of a boundary's steps (fewer
    // than 24 passes: step 1, the fold test, the two index builds); with
    // the counting rule two more a point that folds (its partners, its
    // images), one more for its search, and three more passes.
    let mut never = Clock {
        k: usize::MAX,
        asked: 0,
    };
    let uncut = Box::new(
        p.process_against_kept_within(f2, m, &mut never)
            .expect("kept")
            .clone(),
    );
    assert!(!p.deadline_expired(), "{what}: a clock that never says yes");
    let asked = never.asked;
    let (per_point, passes) = if counting { (6, 30) } else { (3, 24) };
    assert!(
        asked <= per_point * points + passes * points.div_ceil(32) + 32 * B,
        "{what}: {asked} questions for {points} points"
    );
    // With no cap and a clock that never says yes: `process` exactly.
    assert_uncapped_is(&mut p, (f2, m), &default, what);
    let mut c = Counts::default();
    compare(&uncut, &full, what, &mut c);
    c.capped = uncut
        .boundaries()
        .iter()
        .zip(default.boundaries())
        .map(|(x, y)| {
            x.points()
                .iter()
                .zip(y.points())
                .filter(|(a, b)| a != b)
                .count()
        })
        .sum();
    let mut ks: Vec<usize> = (0..8).collect();
    ks.extend((1..=16).map(|i| i * asked / 16));
    ks.push(asked + 1);
    for k in ks {
        let mut clock = Clock { k, asked: 0 };
        let got = Box::new(
            p.process_against_kept_within(f2, m, &mut clock)
                .expect("kept")
                .clone(),
        );
        let expired = clock.asked > k;
        assert_eq!(p.deadline_expired(), expired, "{what}, k = {k}");
        // Once it has said yes the clock is not asked again.
        assert!(
            clock.asked <= k + 1,
            "{what}, k = {k}: asked {}",
            clock.asked
        );
        compare(&got, &full, &format!("{what}, k = {k}"), &mut c);
        // The frame up to the cut is the uncut one's: every point that
        // one's, or flagged.
        for (x, y) in got.boundaries().iter().zip(uncut.boundaries()) {
            for (a, b) in x.points().iter().zip(y.points()) {
                assert!(
                    a == b || a.status() == Status::OverBudget,
                    "{what}, k = {k}: cut {a:?}, uncut {b:?}"
                );
            }
        }
        if expired {
            c.cut_frames += 1;
        }
        if k == 0 {
            // A deadline already passed: nothing is done.
            for b in got.boundaries() {
                assert!(
                    b.points().iter().all(|r| r.status() == Status::OverBudget),
                    "{what}: a passed deadline left a point done"
                );
            }
            assert_eq!(
                got.work_units().0,
                0,
                "{what}: a passed deadline spent work"
            );
        }
    }
    // The processor without a deadline afterwards: as before.
    assert!(p.process_against_kept(f2, m).expect("kept") == &*default);
    assert!(!p.deadline_expired());
    c
}

/// The adversarial family (the bench's pairs, each member's own
/// configuration) at 64 and 256 points a boundary.
#[test]
fn every_cut_of_the_adversarial_family_is_complete_or_flagged() {
    let mut total = Counts::default();
    let mut pairs = 0;
    for m in family() {
        for n in [64usize, 256] {
            let Ok((k, frames)) = render(&m.params, n) else {
                continue;
            };
            let (f1, f2, motion) = library_pair(&k, &frames);
            let c = sweep(
                m.errors.config(),
                (&f1, &f2, &motion),
                &format!("{} N = {n}", m.name),
            );
            total.add(&c);
            pairs += 1;
        }
    }
    // What the cap costs here is reported (`docs/VEHICLE.md`, "Within a deadline").
    eprintln!("{pairs} pairs: {total:?}");
    assert!(pairs >= 40, "{pairs} pairs");
    assert!(
        total.cut_frames > 10 * pairs,
        "the clocks cut {} frames",
        total.cut_frames
    );
    assert!(total.over_budget > 0 && total.equal > 0);
}

/// The same with the counting rule for folded points on
/// (`Processor::set_fold_counting`), on the pairs where it acts: the
/// certification's S-bends, rounded to the pixel grid and with disc
/// noise, each at its own errors. Every cut is complete or flagged, a
/// clock that never says yes and caps nothing is `process` exactly, and
/// the rule gives points back on these pairs (fewer `folded` than without
/// it).
#[test]
fn every_cut_with_the_counting_rule_is_complete_or_flagged() {
    use host_tests::certify::{Case, Variant};
    use host_tests::scenarios::Family;
    let mut total = Counts::default();
    let (mut folded_off, mut folded_on) = (0usize, 0usize);
    for seed in 0..8 {
        let Some(case) = Case::new(Family::SBend, seed) else {
            continue;
        };
        let k = &case.scenario.intrinsics;
        let m = case.rendered.motion();
        for v in [Variant::Rounded, Variant::Disc] {
            let input = case.input(v);
            let (f1, f2) = input.frames(k).expect("frames");
            let what = format!("s_bend {seed} {}", v.name());
            let c = sweep_with(input.config(), (&f1, &f2, &m), &what, true);
            total.add(&c);
            let count = |on: bool| {
                let mut p = Box::new(Processor::<N, B>::new(input.config()));
                p.set_fold_counting(on);
                assert!(matches!(p.process(&f1, None), Ok(Step::First)));
                let s = p.process_against_kept(&f2, &m).expect("kept");
                s.boundaries()
                    .iter()
                    .flat_map(|b| b.points())
                    .filter(|r| r.status() == Status::Folded)
                    .count()
            };
            folded_off += count(false);
            folded_on += count(true);
        }
    }
    eprintln!("{total:?}; folded {folded_off} without the rule, {folded_on} with it");
    assert!(total.equal > 0 && total.over_budget > 0 && total.cut_frames > 0);
    assert!(
        folded_on * 2 < folded_off,
        "the rule gave back too few: folded {folded_off} without it, {folded_on} with it"
    );
}

/// The named synthetic scenarios and 20 random ones, exact and rounded to
/// the pixel grid.
#[test]
fn every_cut_of_the_synthetic_scenarios_is_complete_or_flagged() {
    let mut total = Counts::default();
    let mut all = scenarios::named();
    all.extend((0..20).map(scenarios::random));
    for s in all {
        let r = s.render();
        let cam = s.intrinsics.camera();
        for quantised in [false, true] {
            let f1 = frame(cam, &synth::Rendered::pixels(&r.frame1, quantised));
            let f2 = frame(cam, &synth::Rendered::pixels(&r.frame2, quantised));
            let c = sweep(
                Config::DEFAULT,
                (&f1, &f2, &r.motion()),
                &format!("{} q={quantised}", s.name),
            );
            total.add(&c);
        }
    }
    eprintln!("{total:?}");
    assert!(total.equal > 0 && total.over_budget > 0);
    assert!(total.cut_frames > 0, "no frame was cut");
    // At the default budget the cap changes no point of these scenarios
    // (`roadstereo::deadline`, "What the cap costs").
    assert_eq!(
        total.capped, 0,
        "the cap changed points of the synthetic scenarios"
    );
}

/// `process_within` keeps the frame as `process` does, cut short or not,
/// and the first frame needs no clock.
#[test]
fn a_cut_frame_still_becomes_the_previous_one() {
    let s = scenarios::named().into_iter().next().expect("a scenario");
    let r = s.render();
    let cam = s.intrinsics.camera();
    let f1 = frame(cam, &synth::Rendered::pixels(&r.frame1, false));
    let f2 = frame(cam, &synth::Rendered::pixels(&r.frame2, false));
    let mut p = Box::new(Processor::<N, B>::new(Config::DEFAULT));
    let mut clock = Clock { k: 0, asked: 0 };
    assert!(matches!(
        p.process_within(&f1, None, &mut clock),
        Ok(Step::First)
    ));
    assert_eq!(clock.asked, 0, "the first frame asks nothing");
    assert!(!p.deadline_expired());
    let mut clock = Clock { k: 3, asked: 0 };
    let Ok(Step::Structure(st)) = p.process_within(&f2, Some(&r.motion()), &mut clock) else {
        panic!("no structure");
    };
    let flagged = st
        .boundaries()
        .iter()
        .flat_map(|b| b.points())
        .filter(|r| r.status() == Status::OverBudget)
        .count();
    assert!(flagged > 0);
    assert!(p.deadline_expired());
    assert!(
        p.previous() == Some(&f2),
        "the cut frame is the previous one"
    );
    // A missing motion is an error, and changes nothing.
    let mut clock = Clock {
        k: usize::MAX,
        asked: 0,
    };
    assert!(p.process_within(&f1, None, &mut clock).is_err());
    assert!(p.previous() == Some(&f2));
    assert!(p.deadline_expired(), "an error leaves the last flag");
}

/// A clock that never says yes and caps nothing gives `process`'s results
/// exactly (`Deadline::carry`), at every work budget: also where the
/// budget binds (8 and 16 allowances a point), where a search structure
/// built differently with a clock than without one would show. (Without
/// a clock a loose frame-2 index leaves its block tree until a lean walk
/// reads it, with one the build makes it; a first form of that deferral
/// changed the units, `docs/PERFORMANCE.md`, "The demo's matching within
/// the deadline".) The named synthetic scenarios and 20 random ones,
/// exact and rounded, frame 2 as rendered, with spurious detector points
/// (every 9th vertex moved 150 px along its row) and bent back on itself
/// (its last 30 % of vertices mirrored along their rows about the first
/// of them: the keys fold, and the index is loose), and the adversarial
/// family at N = 64 in its own configuration.
#[test]
fn an_uncapped_clock_is_process_at_every_budget() {
    let mut pairs = 0usize;
    let mut check =
        |config: Config, (f1, f2, m): (&Frame<N, B>, &Frame<N, B>, &Motion), what: &str| {
            let mut p = Box::new(Processor::<N, B>::new(config));
            assert!(matches!(p.process(f1, None), Ok(Step::First)), "{what}");
            let plain = Box::new(p.process_against_kept(f2, m).expect("kept").clone());
            assert_uncapped_is(&mut p, (f2, m), &plain, what);
            pairs += 1;
        };
    let mut all = scenarios::named();
    all.extend((0..20).map(scenarios::random));
    for s in all {
        let r = s.render();
        let cam = s.intrinsics.camera();
        let width = cam.width() as f32;
        for quantised in [false, true] {
            let f1 = frame(cam, &synth::Rendered::pixels(&r.frame1, quantised));
            let clean = synth::Rendered::pixels(&r.frame2, quantised);
            let mut spiky = clean.clone();
            for b in &mut spiky {
                for (i, p) in b.iter_mut().enumerate().skip(4) {
                    if i % 9 == 0 {
                        let u = if p.u > width / 2.0 {
                            p.u - 150.0
                        } else {
                            p.u + 150.0
                        };
                        *p = roadstereo::Pixel::new(u.clamp(0.0, width - 1.0), p.v);
                    }
                }
            }
            let mut folded = clean.clone();
            for b in &mut folded {
                let k = b.len() * 7 / 10;
                let Some(u0) = b.get(k).map(|p| p.u) else {
                    continue;
                };
                for p in b.iter_mut().skip(k + 1) {
                    let u = 2.0 * u0 - p.u;
                    *p = roadstereo::Pixel::new(u.clamp(0.0, width - 1.0), p.v);
                }
            }
            for (f2, tag) in [
                (frame(cam, &clean), ""),
                (frame(cam, &spiky), " spikes"),
                (frame(cam, &folded), " folded"),
            ] {
                for w in [8, 16, 80] {
                    let config = Config::DEFAULT.with_work_budget(w).expect("budget");
                    check(
                        config,
                        (&f1, &f2, &r.motion()),
                        &format!("{} q={quantised}{tag} w={w}", s.name),
                    );
                }
            }
        }
    }
    for m in family() {
        let Ok((k, frames)) = render(&m.params, 64) else {
            continue;
        };
        let (f1, f2, motion) = library_pair(&k, &frames);
        for w in [8, 16] {
            let config = m.errors.config().with_work_budget(w).expect("budget");
            check(config, (&f1, &f2, &motion), &format!("{} w={w}", m.name));
        }
    }
    assert!(pairs > 300, "{pairs} pairs");
}

/// The work units a frame reports count every unit even where the
/// frame's grants would pass 32 bits (`B N` points at the largest
/// budget): until a review, a `Processor<512, 9>` at
/// `Config::MAX_WORK_PER_POINT` reported 143 025 units spent with 8
/// boundaries and 8 675 with 9, the saturated grant having wiped the
/// count. Now a point's allowance is at most `⌊(2³² − 1)/(B N)⌋`: the
/// units granted never saturate and the spent ones never fall as
/// boundaries are added.
#[test]
fn the_work_units_never_saturate_at_the_largest_budget() {
    use roadstereo::{Camera, Pixel};
    const BN: usize = 512;
    const BB: usize = 9;
    let cam = Camera::new(800.0, 800.0, 1023.5, 1023.5, 2048, 2048).expect("camera");
    let config = Config::DEFAULT
        .with_work_budget(Config::MAX_WORK_PER_POINT)
        .expect("budget");
    let boundary = |k: usize, scale: f32| -> Vec<Pixel> {
        (0..480)
            .map(|i| {
                let (u, v) = (
                    1100.0 + 90.0 * k as f32 + 0.4 * i as f32,
                    1040.0 + 2.0 * i as f32,
                );
                Pixel::new(1023.5 + (u - 1023.5) * scale, 1023.5 + (v - 1023.5) * scale)
            })
            .collect()
    };
    let motion = Motion::new([0.0, 0.0, 0.3], [0.0; 3]).expect("motion");
    let mut last = (0u32, 0u32);
    for boundaries in 1..=BB {
        let mut p = Box::new(Processor::<BN, BB>::new(config));
        let (mut f1, mut f2) = (Frame::<BN, BB>::new(cam), Frame::<BN, BB>::new(cam));
        for k in 0..boundaries {
            f1.push_boundary(&boundary(k, 1.0)).expect("frame 1");
            f2.push_boundary(&boundary(k, 1.03)).expect("frame 2");
        }
        assert!(matches!(p.process(&f1, None), Ok(Step::First)));
        let Ok(Step::Structure(s)) = p.process(&f2, Some(&motion)) else {
            panic!("a structure");
        };
        let (spent, granted) = s.work_units();
        let points = (480 * boundaries) as u64;
        assert!(
            granted < u32::MAX && spent <= granted,
            "{boundaries}: {spent} of {granted}"
        );
        assert!(u64::from(granted) <= points * u64::from(u32::MAX / (BN * BB) as u32));
        assert!(
            spent >= last.0 && granted > last.1,
            "{boundaries}: {spent} of {granted} after {last:?}"
        );
        last = (spent, granted);
    }
    assert!(last.0 > 0);
}
