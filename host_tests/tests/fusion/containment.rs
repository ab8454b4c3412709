//! Containment over the seeded random drives (every detector variant, motion errors, the counting rule, a deadline's cut), and the wrong two-view matches caught.

use super::*;

/// Every family's drives through the fusion (default policy) with one
/// detector variant and optional motion errors: per family the tally
/// against the truth, printed as a table; every fused point (two or more
/// agreeing pairs) holds the truth, every wrong two-view stick is caught
/// or harmless, and no two-view stick whose correspondent exists misses.
fn containment(noise: Noise, motion: Option<MotionNoise>, per_family: usize) -> Tally {
    containment_with(noise, motion, per_family, false)
}

/// [`containment`] with the counting rule for folded points on or off.
fn containment_with(
    noise: Noise,
    motion: Option<MotionNoise>,
    per_family: usize,
    counting: bool,
) -> Tally {
    use std::fmt::Write as _;
    let policy = FusionConfig::DEFAULT;
    let mut all = Tally::default();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "\n{} boundaries{}, {FRAMES} frames a drive, default policy (8 partners, 500 ‰):",
        noise.name(),
        motion.map_or(String::new(), |m| format!(
            ", motion off by up to {} per translation component and {:.2}° per axis, bounds configured",
            m.delta,
            m.eps.to_degrees()
        ))
    );
    let _ = writeln!(out, "| family | drives (skipped) | key frames | fused points (≥ 2 pairs) holding the truth | single-pair points holding it | inconsistent | wrong two-view sticks | caught | harmless | wrong single | wrong fused |");
    let _ = writeln!(
        out,
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for family in DriveFamily::ALL {
        let (ds, skipped) = drives(family, per_family, FRAMES);
        let mut t = Tally::default();
        for (seed, d) in &ds {
            let input = d.input(noise, motion, *seed);
            let r = if counting {
                host_tests::drives::run_counted(d, &input, policy, |_, _, _| {})
            } else {
                run(d, &input, policy, |_, _, _| {})
            };
            t.add(&tally(d, &r));
        }
        let _ = writeln!(
            out,
            "| {} | {} ({skipped}) | {} | {} / {} ({}) | {} / {} ({}) | {} | {} | {} | {} | {} | {} |",
            family.name(),
            t.drives,
            t.key_frames,
            t.consistent_contained,
            t.consistent,
            pct(t.consistent_contained, t.consistent),
            t.single_contained,
            t.single,
            pct(t.single_contained, t.single),
            t.inconsistent,
            t.wrong_pairs,
            t.caught,
            t.harmless,
            t.wrong_single,
            t.wrong_fused
        );
        all.add(&t);
    }
    let _ = writeln!(
        out,
        "all: {} drives, {} of {} fused point snapshots hold the truth; {} wrong two-view sticks ({} with a correspondent): {} caught, {} harmless, {} single, {} wrong fused",
        all.drives,
        all.consistent_contained,
        all.consistent,
        all.wrong_pairs,
        all.wrong_pairs_observed,
        all.caught,
        all.harmless,
        all.wrong_single,
        all.wrong_fused
    );
    print!("{out}");
    assert!(all.drives >= 300 || per_family < PER_FAMILY);
    assert_eq!(
        all.consistent_contained, all.consistent,
        "a fused interval misses the truth"
    );
    assert_eq!(all.wrong_fused, 0);
    assert_eq!(
        all.wrong_pairs_observed, 0,
        "a two-view stick with a correspondent misses"
    );
    assert!(all.consistent > 100_000 / if motion.is_some() { 10 } else { 1 });
    all
}

/// What the work budget and the cap of a deadline cost on the fusion's
/// drives, whose pairs reach across up to eight frames (`docs/VEHICLE.md`, "Within a
/// deadline" and "Worst case"):
///
/// * **The default budget, no clock.** A point the budget flags
///   `over_budget` would never be `ok` with the largest budget (the pair
///   run again with it): the budget costs no depth here. (Mostly fold
///   queries, each paid from the allowances of the points before it,
///   `fold::step`: on a crest the first points' queries are the dear
///   ones.)
/// * **The cap** (`Deadline::carry`, 2 by default), a clock that never
///   says yes against no clock: a point whose search needs more than
///   `CARRY` allowances at once comes out `over_budget` (or `ok` with a
///   looser stick), and one the frame's credit ran out on without a clock
///   may be done, never anything else. Compared step by step up to a
///   drive's first changed point (after it the key frames may differ). An
///   adversarial review found such a drive of its own.
///
/// The figures printed are `docs/FUSION.md`'s.
#[test]
fn the_deadline_cap_on_the_drives() {
    let policy = FusionConfig::DEFAULT;
    let (mut compared, mut changed_drives, mut pairs, mut points) =
        (0usize, 0usize, 0usize, 0usize);
    let mut over_budget = std::collections::BTreeMap::new();
    let (mut looser, mut done_within) = (0usize, 0usize);
    // Points `over_budget` without a clock, in every paired step.
    let mut budget_flagged = std::collections::BTreeMap::new();
    let mut all_points = 0usize;
    for family in DriveFamily::ALL {
        let (ds, _) = drives(family, PER_FAMILY, FRAMES);
        for (seed, d) in &ds {
            let input = d.input(Noise::Rounded, None, *seed);
            fn record(
                steps: &mut Vec<Option<roadstereo::Structure<N, B>>>,
            ) -> impl FnMut(usize, &roadstereo::fusion::FusionStep, &HostFusion) + '_ {
                move |_, step, f| steps.push(step.paired.map(|_| f.structure().clone()))
            }
            let mut full = Vec::new();
            let mut keys = Vec::new();
            run(d, &input, policy, |j, step, f| {
                record(&mut full)(j, step, f);
                keys.push(f.key().map_or(0, |k| k.id() as usize));
            });
            let mut capped = Vec::new();
            // (A clock asked at most `usize::MAX` times never says yes.)
            host_tests::drives::run_within(
                d,
                &input,
                policy,
                Some(usize::MAX),
                record(&mut capped),
            );
            compared += 1;
            // Every `over_budget` point without a clock, and what the pair
            // gives it with the largest budget (the key frame and partner
            // again, the motion composed as the fusion composes it).
            let cfg = input.config();
            let largest = cfg
                .with_work_budget(Config::MAX_WORK_PER_POINT)
                .expect("the largest budget");
            for (j, (b, key)) in full.iter().zip(&keys).enumerate() {
                let Some(b) = b else { continue };
                all_points += b
                    .boundaries()
                    .iter()
                    .map(|x| x.points().len())
                    .sum::<usize>();
                if b.status_counts().get(Status::OverBudget) == 0 {
                    continue;
                }
                let mut p = Box::new(roadstereo::Processor::<N, B>::new(largest));
                let k = d.spec.intrinsics;
                p.process(&input.frame(&k, *key), None).expect("key frame");
                let mut m = input.given[*key];
                for g in &input.given[*key + 1..j] {
                    m = m.then(g).expect("composed");
                }
                let big = p
                    .process_against_kept(&input.frame(&k, j), &m)
                    .expect("pair");
                for (x, y) in b.boundaries().iter().zip(big.boundaries()) {
                    for (q, r) in x.points().iter().zip(y.points()) {
                        if q.status() == Status::OverBudget {
                            *budget_flagged.entry(r.status().name()).or_insert(0usize) += 1;
                        }
                    }
                }
            }
            'steps: for (j, (a, b)) in capped.iter().zip(&full).enumerate() {
                let (a, b) = match (a, b) {
                    (Some(a), Some(b)) => (a, b),
                    (None, None) => continue,
                    _ => panic!("{}: step {j} paired in one run only", d.spec.name),
                };
                pairs += 1;
                let mut changed = false;
                for (x, y) in a.boundaries().iter().zip(b.boundaries()) {
                    assert_eq!(x.points().len(), y.points().len());
                    for (p, q) in x.points().iter().zip(y.points()) {
                        points += 1;
                        if p == q {
                            continue;
                        }
                        changed = true;
                        if q.status() == Status::OverBudget {
                            // (The frame's credit ran out without a clock;
                            // under the cap it went round otherwise.)
                            done_within += 1;
                        } else if p.status() == Status::OverBudget {
                            assert!(p.interval().is_none(), "{}: step {j}: {p:?}", d.spec.name);
                            *over_budget.entry(q.status().name()).or_insert(0usize) += 1;
                        } else if host_tests::fuzz::frame::looser_stick(p, q) {
                            looser += 1;
                        } else if host_tests::fuzz::frame::looser_stick(q, p) {
                            // (Without a clock the frame's credit ran out
                            // on the stick's refinement.)
                            done_within += 1;
                        } else {
                            panic!(
                                "{}: step {j}: within the clock {p:?}, without {q:?}",
                                d.spec.name
                            );
                        }
                    }
                }
                if changed {
                    changed_drives += 1;
                    break 'steps;
                }
            }
        }
    }
    println!(
        "the default cap on {compared} drives (rounded, {FRAMES} frames): {changed_drives} drives with a changed point; up to the first, {pairs} pairs, {points} points, over_budget where no clock gives {over_budget:?}, {looser} looser sticks, {done_within} done where no clock ran out of the budget; without a clock, of {all_points} points, over_budget: {budget_flagged:?} (as the largest budget gives them)"
    );
    assert!(pairs > compared * (FRAMES / 2), "{pairs} pairs compared");
    assert!(
        all_points > 2_000_000 && !budget_flagged.is_empty(),
        "the budget binds nowhere: {budget_flagged:?} (docs/FUSION.md's figure to update)"
    );
    assert_eq!(
        budget_flagged.get("ok"),
        None,
        "the default budget cost depths on the drives"
    );
}

/// The fusion with every frame's matching cut short by a deadline
/// (`Fusion::step_within`, a clock that says the time is up from its
/// 300th question on: about the first boundary of a 2 × 256 frame): the
/// cut points get no new interval, so every fused interval still holds
/// the truth and no wrong match is fused; the cut does not end key frames
/// early (the "few matched" rule skips a cut pair), and the yield shows
/// what the cut cost.
#[test]
fn containment_within_a_deadline() {
    let policy = FusionConfig::DEFAULT;
    let (mut cut_tally, mut full_tally) = (Tally::default(), Tally::default());
    let mut cut_steps = 0usize;
    for family in DriveFamily::ALL {
        let (ds, _) = drives(family, 6, FRAMES);
        for (seed, d) in &ds {
            let input = d.input(Noise::Rounded, None, *seed);
            let r = host_tests::drives::run_within(d, &input, policy, Some(300), |_, _, f| {
                if f.deadline_expired() {
                    cut_steps += 1;
                }
            });
            cut_tally.add(&tally(d, &r));
            full_tally.add(&tally(d, &run(d, &input, policy, |_, _, _| {})));
        }
    }
    println!(
        "within a deadline (300 questions a frame): {} drives, {cut_steps} steps cut; {} key frames ({} without the deadline); {} of {} fused point snapshots hold the truth ({} without); {} wrong two-view sticks, {} wrong fused",
        cut_tally.drives,
        cut_tally.key_frames,
        full_tally.key_frames,
        cut_tally.consistent_contained,
        cut_tally.consistent,
        full_tally.consistent,
        cut_tally.wrong_pairs,
        cut_tally.wrong_fused
    );
    assert!(cut_steps > cut_tally.drives * 4, "{cut_steps} steps cut");
    assert_eq!(
        cut_tally.consistent_contained, cut_tally.consistent,
        "a fused interval misses the truth within a deadline"
    );
    assert_eq!(cut_tally.wrong_fused, 0);
    assert_eq!(cut_tally.wrong_pairs_observed, 0);
    assert!(cut_tally.consistent > 0 && cut_tally.consistent < full_tally.consistent);
    assert!(
        cut_tally.key_frames <= full_tally.key_frames,
        "the cut ended key frames early: {} against {}",
        cut_tally.key_frames,
        full_tally.key_frames
    );
}

#[test]
fn containment_rounded() {
    containment(Noise::Rounded, None, PER_FAMILY);
}

#[test]
fn containment_disc_noise() {
    containment(Noise::Disc, None, PER_FAMILY);
}

/// The same with the counting rule for folded points on
/// (`Fusion::set_fold_counting`): the pairs' points it gives back fuse as
/// every other, and the fused intervals still hold the truth, no wrong
/// match unflagged (rounded boundaries).
#[test]
fn containment_with_the_counting_rule() {
    let t = containment_with(Noise::Rounded, None, PER_FAMILY, true);
    assert!(t.consistent > 0);
    // The drive built for wrong matches on disjoint stretches: every
    // wrong two-view stick still flagged or harmless.
    let d = disjoint_stretch_drive();
    let policy = FusionConfig::new(8, 0).expect("policy");
    let mut all = Tally::default();
    for (v, noise) in [Noise::Rounded, Noise::Disc].into_iter().enumerate() {
        let input = d.input(noise, None, v as u64);
        let r = host_tests::drives::run_counted(&d, &input, policy, |_, _, _| {});
        all.add(&tally(&d, &r));
    }
    wrong_match_report("built on purpose, with the counting rule", &all);
    assert!(all.wrong_pairs >= 10, "{all:?}");
    assert_eq!(all.wrong_pairs, all.caught + all.harmless, "{all:?}");
    assert_eq!(all.consistent, all.consistent_contained);
}

#[test]
fn containment_with_motion_errors() {
    // About 2.5 % of a frame's travel per translation component, 0.1° per
    // axis: the composed bounds keep every fused interval guaranteed.
    let m = MotionNoise {
        delta: 0.01,
        eps: 0.1f64.to_radians(),
    };
    containment(Noise::Rounded, Some(m), PER_FAMILY);
}

/// The S-bend built to make frames see disjoint stretches of a boundary:
/// the left edge bends out of view on the left (curvature −1/10.5) and back
/// in far ahead (+1/10.5 from 4.7 on), seen by a high camera (h = 1.5, tilt
/// 19°); the vehicle moves 0.34 forward and 0.05 to the left while turning
/// 2.9° left, in nine frames a quarter of that apart. The key frame sees
/// only the edge's far stretch, beyond the bend; frames 5 and 6 only its
/// near stretch, entering at the bottom; frames 7 and 8 both again. The key
/// frame's epipolar lines meet the near stretch at points consistent with
/// both images: wrong two-view matches, which the earlier partners'
/// intervals contradict.
fn disjoint_stretch_drive() -> Drive {
    let k = 0.095;
    let road = Road {
        width: 1.4,
        curvature_a: -k,
        curvature_b: k,
        switch_at: 4.7,
        ..Road::straight(1.4)
    };
    let mut s = Scenario::new(
        "disjoint_stretches",
        road,
        synth::Drive {
            forward: 0.34,
            lateral: -0.05,
            yaw: (-2.9f64).to_radians(),
            ..Default::default()
        },
    );
    s.height = 1.5;
    s.tilt = 19f64.to_radians();
    let fractions: Vec<f64> = (0..=8).map(|i| f64::from(i) * 0.25).collect();
    Drive::through_scenario(&s, &fractions).expect("both edges in view")
}

pub(super) fn wrong_match_report(name: &str, t: &Tally) {
    println!(
        "{name}: {} wrong two-view sticks ({} with a correspondent in the partner frame): {} flagged inconsistent, {} harmless (the fused interval still holds the truth), {} single, {} wrong fused; {} fused snapshots hold the truth of {}",
        t.wrong_pairs,
        t.wrong_pairs_observed,
        t.caught,
        t.harmless,
        t.wrong_single,
        t.wrong_fused,
        t.consistent_contained,
        t.consistent
    );
}

#[test]
fn wrong_matches_on_disjoint_stretches_are_flagged() {
    let d = disjoint_stretch_drive();
    let policy = FusionConfig::new(8, 0).expect("policy");
    let mut all = Tally::default();
    for (v, noise) in [Noise::Rounded, Noise::Disc].into_iter().enumerate() {
        let input = d.input(noise, None, v as u64);
        let r = run(&d, &input, policy, |_, _, _| {});
        let t = tally(&d, &r);
        wrong_match_report(&format!("built on purpose, {}", noise.name()), &t);
        all.add(&t);
    }
    // The scenario does what it is built for.
    assert!(all.wrong_pairs >= 10, "{all:?}");
    assert_eq!(all.wrong_pairs, all.caught + all.harmless, "{all:?}");
    assert_eq!(all.consistent, all.consistent_contained);
}

/// Today's wrong two-view points of the 1000 random scenarios (points
/// `ok` whose correspondent is not in frame 2 and whose stick misses the
/// truth), each scenario driven through with three frames between its
/// two (a quarter of the motion apart), the first frame the key frame:
/// every one is flagged.
#[test]
fn wrong_matches_of_the_random_scenarios_are_flagged() {
    let mut seeds = Vec::new();
    let mut two_view_wrong = 0;
    for seed in 0..1000 {
        let s = scenarios::random(seed);
        let r = s.render();
        if r.frame1.is_empty() {
            continue;
        }
        let p = host_tests::reconstruct(&r, &s.intrinsics, true, Config::default());
        let wrong = host_tests::point_stats(&r, &s.intrinsics, &p)
            .iter()
            .filter(|st| st.status == Status::Ok && !st.observed && !st.contained())
            .count();
        if wrong > 0 {
            seeds.push(seed);
            two_view_wrong += wrong;
        }
    }
    println!(
        "the 1000 random scenarios: {two_view_wrong} wrong two-view points in scenarios {seeds:?}"
    );
    assert!(two_view_wrong > 0);
    let policy = FusionConfig::new(8, 0).expect("policy");
    let mut all = Tally::default();
    for seed in seeds {
        let s = scenarios::random(seed);
        let d = Drive::through_scenario(&s, &[0.0, 0.25, 0.5, 0.75, 1.0]).expect("drive");
        let input = d.input(Noise::Rounded, None, seed);
        let r = run(&d, &input, policy, |_, _, _| {});
        all.add(&tally(&d, &r));
    }
    wrong_match_report("random scenarios, driven through", &all);
    assert!(all.wrong_pairs >= two_view_wrong);
    assert_eq!(all.wrong_pairs, all.caught, "{all:?}");
    assert_eq!(all.consistent, all.consistent_contained);
}
