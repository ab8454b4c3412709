//! Certification of the guarantee and of the yield (issue 11, sections 2
//! and 4), with the harness in `host_tests/src/certify.rs`.
//!
//! [`certify_containment`] runs the certification (every family, every
//! variant; about 5 s on two cores) and asserts the guarantee; print its
//! tables with
//!
//! ```text
//! cd host_tests && cargo test --profile checked --test certify certify_containment -- --nocapture
//! ```
//!
//! and check the yield targets too with `-- --ignored`.
//! `CERTIFY_FAMILIES=far_foe,backward` and `CERTIFY_PER_FAMILY=10` run a
//! subset (the figures are then asserted on it; the scenario count only on
//! the full run). The other tests check the harness itself: the variants
//! stay inside the declared error model, the truth agrees with the library
//! where the library is known to be right, the deviation bound and the
//! fold truth are right, the reproducers' truths follow from their
//! geometry, and the issue's two reproducers.

use host_tests::certify::{
    certify, certify_with, deviation_bound, fold_flags, point_segment_distance, replay_for, run,
    Case, Fold, Geometry, Report, Variant,
};
use host_tests::scenarios::Family;
use host_tests::synth::Intrinsics;
use roadstereo::{Config, Frame, Motion, Pixel, Processor, Status, Step};

/// Scenarios per family: 16 families × 66 = 1056 scenarios, each in the
/// four variants.
const PER_FAMILY: u64 = 66;

/// The issue's required figures.
const CONTAINMENT: f64 = 1.0;
const ACTUAL_OVER_IDEAL_ALL: f64 = 0.90;
const ACTUAL_OVER_IDEAL_FAMILY: f64 = 0.80;
const FOLDED_LOSS_MAX: f64 = 0.05;
/// The grazing test allows for the polyline's own error, so it should not
/// flag a point whose true crossing is at the minimum angle or steeper; the
/// allowance is for the boundary's curvature over the piece, which the test
/// leaves out (measured: at most 0.0 % in every variant; 1.8 % of the
/// rounded variant's ideal points before the allowance).
const GRAZING_LOSS_MAX: f64 = 0.002;

fn families_from_env() -> (Vec<Family>, u64, bool) {
    let fams = std::env::var("CERTIFY_FAMILIES").ok().map(|s| {
        s.split(',')
            .map(|n| Family::from_name(n.trim()).unwrap_or_else(|| panic!("no family {n}")))
            .collect::<Vec<_>>()
    });
    let per = std::env::var("CERTIFY_PER_FAMILY")
        .ok()
        .map(|s| s.parse().expect("CERTIFY_PER_FAMILY is a number"));
    let full = fams.is_none() && per.is_none();
    (
        fams.unwrap_or_else(|| Family::ALL.to_vec()),
        per.unwrap_or(PER_FAMILY),
        full,
    )
}

fn print_report(rep: &Report, seconds: f64) {
    println!(
        "{} scenarios ({} without a boundary in both frames skipped) × {} variants in {seconds:.1} s; \
         largest chord allowance {:.3} px; {} boundaries moved along the row instead of the normal",
        rep.cases,
        rep.skipped,
        Variant::ALL.len(),
        rep.largest_allowance,
        rep.fallbacks
    );
    println!("\nContainment and yield (ideal: the two-view ideal; actual: `ok`; folded loss: `folded` on ideal points of curves that do not fold there, share of the ideal points):\n");
    println!("{}", rep.table());
    println!("Where the ideal points go (share of the ideal points):\n");
    println!("{}", rep.where_table());
    println!("The ideal points by status:\n");
    println!("{}", rep.loss_table());
    for v in Variant::ALL {
        let t = rep.variant_total(v);
        println!(
            "{}: {} ok points with a correspondent, {} outside their stick; {} ok points without one, {} of them wrong",
            v.name(),
            t.ok_observed,
            t.ok_observed - t.contained,
            t.ok_unobserved,
            t.ok_unobserved_miss
        );
    }
    // How wide the sticks are: (z_far − z_near)/z_true of the ok points
    // with a correspondent, all families and the far, small-disparity one.
    println!("\nRelative stick widths of the `ok` points with a correspondent (median / 90th percentile):\n");
    println!("| variant | all families | far_small_disparity |");
    println!("|---|---:|---:|");
    for v in Variant::ALL {
        let t = rep.variant_total(v);
        let far = rep
            .cells
            .iter()
            .find(|((f, cv), _)| *cv == v && f.name() == "far_small_disparity")
            .map(|(_, c)| c.clone())
            .unwrap_or_default();
        println!(
            "| {} | {:.4} / {:.4} | {:.4} / {:.4} |",
            v.name(),
            t.width_quantile(0.5),
            t.width_quantile(0.9),
            far.width_quantile(0.5),
            far.width_quantile(0.9)
        );
    }
    // Where the ideal itself is out of reach of a guaranteed stick.
    println!("\nIdeal points any guaranteed stick could bound at all (the polyline farther than r₁ + e₂ from the point; `host_tests::certify::boundable`), against those `ok`:\n");
    println!("| family | variant | boundable / ideal | ok∩ideal / ideal |");
    println!("|---|---|---:|---:|");
    for ((f, v), c) in &rep.cells {
        if c.boundable_share() < 0.97 {
            println!(
                "| {} | {} | {:.1} % | {:.1} % |",
                f.name(),
                v.name(),
                100.0 * c.boundable_share(),
                100.0 * c.ideal_recall()
            );
        }
    }
    // The worst miss of each scenario and variant, the worst 10 of those.
    let mut groups: Vec<(&host_tests::certify::Miss, usize)> = Vec::new();
    for m in &rep.misses {
        match groups
            .iter_mut()
            .find(|(w, _)| (w.family, w.seed, w.variant) == (m.family, m.seed, m.variant))
        {
            Some(g) => g.1 += 1,
            None => groups.push((m, 1)),
        }
    }
    println!(
        "\n{} misses in {} scenario variants; the worst of each, worst first:",
        rep.misses.len(),
        groups.len()
    );
    for (m, n) in &groups {
        println!("  {n:4} × {}", m.describe());
    }
    println!("\nReplays of the worst 10:");
    for (m, _) in groups.iter().take(10) {
        println!("* {}", m.describe());
        let replay = Case::new(m.family, m.seed).and_then(|c| replay_for(&c, m));
        match replay {
            Some(r) => println!("{r}"),
            None => println!("  (not reproduced by a replay)"),
        }
    }
}

/// The certification's findings against the issue's requirements: the
/// guarantee (containment, the declared model, the scenario count, the
/// folded loss) and the yield targets, as lists of what is not met.
fn requirements(rep: &Report, full: bool) -> (Vec<String>, Vec<String>) {
    let (mut guarantee, mut yields) = (Vec::new(), Vec::new());
    if !rep.model_errors.is_empty() {
        guarantee.push(format!(
            "inputs outside the declared model (a bug of the harness): {:#?}",
            &rep.model_errors[..rep.model_errors.len().min(20)]
        ));
    }
    if full && rep.cases < 1000 {
        guarantee.push(format!("{} scenarios < 1000", rep.cases));
    }
    for v in Variant::ALL {
        let t = rep.variant_total(v);
        if t.containment() < CONTAINMENT {
            guarantee.push(format!(
                "{}: containment {}/{} ({} misses)",
                v.name(),
                t.contained,
                t.ok_observed,
                t.ok_observed - t.contained
            ));
        }
        if t.grazing_loss() > GRAZING_LOSS_MAX {
            guarantee.push(format!(
                "{}: {:.2} % of the ideal points grazing > {:.1} %",
                v.name(),
                100.0 * t.grazing_loss(),
                100.0 * GRAZING_LOSS_MAX
            ));
        }
        if t.ideal == 0 || t.actual_over_ideal() < ACTUAL_OVER_IDEAL_ALL {
            yields.push(format!(
                "{}: actual/ideal over all families {:.1} % < {:.0} %",
                v.name(),
                100.0 * t.actual_over_ideal(),
                100.0 * ACTUAL_OVER_IDEAL_ALL
            ));
        }
    }
    for ((f, v), t) in &rep.cells {
        if t.ideal == 0 {
            continue;
        }
        if t.actual_over_ideal() < ACTUAL_OVER_IDEAL_FAMILY {
            yields.push(format!(
                "{} {}: actual/ideal {:.1} % < {:.0} %",
                f.name(),
                v.name(),
                100.0 * t.actual_over_ideal(),
                100.0 * ACTUAL_OVER_IDEAL_FAMILY
            ));
        }
        if t.folded_loss() > FOLDED_LOSS_MAX {
            guarantee.push(format!(
                "{} {}: folded loss {:.1} % > {:.0} %",
                f.name(),
                v.name(),
                100.0 * t.folded_loss(),
                100.0 * FOLDED_LOSS_MAX
            ));
        }
    }
    (guarantee, yields)
}

/// The certification: >= 1000 seeded scenarios over the families, each in
/// the four variants; the truth inside the stick of 100 % of the `ok`
/// points whose correspondent exists (in every variant), every input
/// inside the declared model, folded loss <= 5 % per family. The report
/// (yield against the two-view ideal per family and variant, where the
/// ideal points go) is printed; the yield targets are checked by
/// [`certify_yield_targets`].
#[test]
fn certify_containment() {
    let (families, per, full) = families_from_env();
    let t0 = std::time::Instant::now();
    let rep = certify(&families, 0..per);
    print_report(&rep, t0.elapsed().as_secs_f64());
    let (guarantee, _) = requirements(&rep, full);
    assert!(
        guarantee.is_empty(),
        "{} requirements not met:\n{}",
        guarantee.len(),
        guarantee.join("\n")
    );
}

/// The search alone holds the guarantee (`docs/TESTS.md`, "What the fold test
/// buys"): with the library's fold test switched off, so that every point
/// on a fold is searched as well, the truth lies inside the stick of
/// 100 % of the `ok` points with a correspondent, in every variant of the
/// same scenarios. (The fold test protects the points *without* a
/// correspondent, which the guarantee does not cover; the report's
/// "without one" lines show what it saves.) The switch must reach the
/// folds: nothing is flagged `folded`, and the S-bend family, a third of
/// whose ideal points fold, keeps more than 90 % of them.
#[test]
fn containment_without_the_fold_test() {
    let (families, per, full) = families_from_env();
    let t0 = std::time::Instant::now();
    let rep = certify_with(&families, 0..per, Fold::Untested);
    print_report(&rep, t0.elapsed().as_secs_f64());
    let (guarantee, _) = requirements(&rep, full);
    assert!(
        guarantee.is_empty(),
        "{} requirements not met without the fold test:\n{}",
        guarantee.len(),
        guarantee.join("\n")
    );
    for ((f, v), t) in &rep.cells {
        assert_eq!(t.folded, 0, "{} {}: folded points", f.name(), v.name());
    }
    for v in Variant::ALL {
        if let Some(t) = rep.cells.get(&(Family::SBend, v)) {
            assert!(
                t.ideal_recall() > 0.9,
                "s_bend {}: {:.1} % of the ideal points ok",
                v.name(),
                100.0 * t.ideal_recall()
            );
        }
    }
}

/// The counting rule for folded points (`Processor::set_fold_counting`,
/// `docs/TESTS.md`, "The counting rule"): with it on, the truth inside the
/// stick of 100 % of the `ok` points with a correspondent in every variant
/// (the guarantee does not depend on which points are searched); no more
/// `ok` points without a correspondent (wrong matches) than without the
/// rule, in every variant; and the S-bend family, whose ideal points fold
/// across the rays a third of the time, at issue 11's per-family target
/// (actual >= 80 % of the ideal yield) in every variant, where without the
/// rule it is at about 66 %.
#[test]
fn containment_with_the_counting_rule() {
    let (families, per, full) = families_from_env();
    let t0 = std::time::Instant::now();
    let rep = certify_with(&families, 0..per, Fold::Counted);
    print_report(&rep, t0.elapsed().as_secs_f64());
    let (guarantee, _) = requirements(&rep, full);
    assert!(
        guarantee.is_empty(),
        "{} requirements not met with the counting rule:\n{}",
        guarantee.len(),
        guarantee.join("\n")
    );
    let shipped = certify(&families, 0..per);
    for v in Variant::ALL {
        let wrong = |r: &host_tests::certify::Report| {
            r.cells
                .iter()
                .filter(|((_, w), _)| *w == v)
                .map(|(_, t)| t.ok_unobserved)
                .sum::<usize>()
        };
        let (with, without) = (wrong(&rep), wrong(&shipped));
        println!(
            "{}: ok without a correspondent {with} with the rule, {without} without",
            v.name()
        );
        assert!(
            with <= without,
            "{}: {with} ok points without a correspondent, {without} without the rule",
            v.name()
        );
        if let Some(t) = rep.cells.get(&(Family::SBend, v)) {
            assert!(
                t.actual_over_ideal() >= 0.8,
                "s_bend {}: actual {:.1} % of the ideal yield",
                v.name(),
                100.0 * t.actual_over_ideal()
            );
        }
    }
}

/// The guarantee holds for a frame a deadline cuts short
/// (`Processor::process_within`): each point done before the clock said
/// the time was up is a complete result, the rest `over_budget`. The
/// certification with a clock that says so from its 200th question on
/// (a frame asks one to three a point: step 1 point by point where the
/// pair is not certified, the fold queries, step 4; about a quarter of
/// the ideal points are then done),
/// 100 % containment required; the deadline must cut (ideal points lost
/// to `over_budget` in every variant), and the report shows the yield
/// that is left.
#[test]
fn containment_within_a_deadline() {
    let (families, per, full) = families_from_env();
    let t0 = std::time::Instant::now();
    let rep = certify_with(&families, 0..per, Fold::Within(200));
    print_report(&rep, t0.elapsed().as_secs_f64());
    let (guarantee, _) = requirements(&rep, full);
    assert!(
        guarantee.is_empty(),
        "{} requirements not met within a deadline:\n{}",
        guarantee.len(),
        guarantee.join("\n")
    );
    let over = Status::ALL
        .iter()
        .position(|&s| s == Status::OverBudget)
        .expect("a status");
    for v in Variant::ALL {
        let t = rep.variant_total(v);
        let cut = t.ideal_by_status.get(over).copied().unwrap_or(0);
        println!(
            "{}: {} of {} ideal points over_budget, {:.1} % of the ideal points ok",
            v.name(),
            cut,
            t.ideal,
            100.0 * t.ideal_recall()
        );
        assert!(
            cut * 10 > t.ideal,
            "{}: the deadline cut only {cut} of {} ideal points",
            v.name(),
            t.ideal
        );
    }
}

/// Every family, 12 seeds each, every variant: `each` gets a processor
/// with the largest budget (a budget that never binds) that has kept the
/// pair's first frame, the second frame, the motion and the case's name.
fn each_pair(
    mut each: impl FnMut(
        &mut Processor<{ host_tests::N }, { host_tests::B }>,
        &Frame<{ host_tests::N }, { host_tests::B }>,
        &Motion,
        &str,
    ),
) {
    for f in Family::ALL {
        for seed in 0..12 {
            let Some(case) = Case::new(f, seed) else {
                continue;
            };
            let k = &case.scenario.intrinsics;
            let m = case.rendered.motion();
            for v in Variant::ALL {
                let input = case.input(v);
                let (f1, f2) = input.frames(k).expect("frames");
                let config = input
                    .config()
                    .with_work_budget(Config::MAX_WORK_PER_POINT)
                    .expect("budget");
                let mut p = Box::new(Processor::new(config));
                let _ = p.process(&f1, None);
                each(
                    &mut p,
                    &f2,
                    &m,
                    &format!("{} {seed} {}", f.name(), v.name()),
                );
            }
        }
    }
}

/// Every point of the indexed structure `fast` equals the reference's
/// `slow`; returns the points compared and the `ok` ones among them.
fn assert_indexed_is_reference(
    fast: &roadstereo::Structure<{ host_tests::N }, { host_tests::B }>,
    slow: &roadstereo::Structure<{ host_tests::N }, { host_tests::B }>,
    what: &str,
) -> (usize, usize) {
    let (mut points, mut ok) = (0usize, 0usize);
    for (bk, (x, y)) in fast.boundaries().iter().zip(slow.boundaries()).enumerate() {
        assert_eq!(x.points().len(), y.points().len());
        for (i, (a, b)) in x.points().iter().zip(y.points()).enumerate() {
            assert!(
                a == b,
                "{what}: boundary {bk} point {i}: indexed {a:?}, reference {b:?}"
            );
            points += 1;
            ok += usize::from(a.status() == Status::Ok);
        }
    }
    (points, ok)
}

/// The indexed search equals its reference with the counting rule for
/// folded points on (`Processor::set_fold_counting`): the points the rule
/// gives back are searched by each matcher, and every result is the same.
/// Every family, 12 seeds each, every variant, with a budget that never
/// binds; the rule must act (fewer points `folded` than without it).
#[test]
fn indexed_equals_reference_with_the_counting_rule() {
    let (mut points, mut given_back) = (0usize, 0usize);
    let folded = |s: &roadstereo::Structure<{ host_tests::N }, { host_tests::B }>| {
        s.boundaries()
            .iter()
            .flat_map(|b| b.points())
            .filter(|r| r.status() == Status::Folded)
            .count()
    };
    each_pair(|p, f2, m, what| {
        let without = folded(p.process_against_kept(f2, m).expect("indexed"));
        p.set_fold_counting(true);
        let fast = Box::new(p.process_against_kept(f2, m).expect("indexed").clone());
        let slow = p.reference_against_kept(f2, m).expect("reference");
        given_back += without - folded(&fast);
        points += assert_indexed_is_reference(&fast, slow, what).0;
    });
    eprintln!("{points} points, {given_back} given back by the counting rule");
    assert!(given_back > 1_000, "{given_back} points given back");
}

/// The indexed search equals its reference with the fold test switched
/// off as well, where every point on a fold reaches the search (issue 11:
/// the reference follows the rule and equals the fast path on every
/// scenario): every family, 12 seeds each, every variant, with a budget
/// that never binds.
#[test]
fn indexed_equals_reference_without_the_fold_test() {
    let (mut points, mut ok) = (0usize, 0usize);
    each_pair(|p, f2, m, what| {
        let fast = Box::new(
            p.without_fold_test_against_kept(f2, m, false)
                .expect("indexed")
                .clone(),
        );
        let slow = p
            .without_fold_test_against_kept(f2, m, true)
            .expect("reference");
        let (n, k) = assert_indexed_is_reference(&fast, slow, what);
        points += n;
        ok += k;
    });
    println!("{points} points equal, {ok} of them ok");
    assert!(
        points > 100_000 && ok > points / 3,
        "{points} points, {ok} ok"
    );
}

/// Issue 11's yield targets: actual >= 90 % of the ideal yield over all
/// families and >= 80 % in each, in every variant, with the library at its
/// best (the counting rule for folded points on, `Processor::set_fold_counting`;
/// without it the S-bend misses too). Not met: the far-small-disparity
/// family in the three inexact variants, whose ideal points no guaranteed
/// stick can mostly bound (`docs/TESTS.md` gives the figures and where the
/// points go): `cargo test --profile checked --test certify -- --ignored`
/// checks them.
#[test]
#[ignore = "issue 11's yield targets are not met yet (docs/TESTS.md gives the figures)"]
fn certify_yield_targets() {
    let (families, per, full) = families_from_env();
    let rep = certify_with(&families, 0..per, Fold::Counted);
    let (guarantee, yields) = requirements(&rep, full);
    let all: Vec<String> = guarantee.into_iter().chain(yields).collect();
    assert!(
        all.is_empty(),
        "{} requirements not met:\n{}",
        all.len(),
        all.join("\n")
    );
}

/// The harness on a few scenarios of every family: every variant inside
/// the declared model (the frame-1 offsets within e1, the true frame-2
/// curve within e2 of the polyline), the noise and the adversary close to
/// the edge of it, every input valid, and the report complete.
#[test]
fn variants_stay_inside_the_declared_model() {
    let rep = certify(&Family::ALL, 0..3);
    assert!(rep.model_errors.is_empty(), "{:#?}", rep.model_errors);
    assert_eq!(rep.skipped, 0);
    assert_eq!(rep.cells.len(), Family::ALL.len() * Variant::ALL.len());
    for f in Family::ALL {
        for seed in 0..3 {
            let c = Case::new(f, seed).expect("boundaries in both frames");
            for v in Variant::ALL {
                let i = c.input(v);
                assert!(i.dev1 <= i.e1 && i.dev2 <= i.e2, "{f:?}/{seed} {v:?}");
                let (n1, n2) = v.nominal();
                match v {
                    Variant::Exact => assert!(i.dev1 < 1e-4, "{}", i.dev1),
                    Variant::Rounded => assert!(i.dev1 > 0.45 && i.dev1 <= 0.5, "{}", i.dev1),
                    // Uniform in the disc: the largest of hundreds of moves is
                    // near the edge; the adversary is at it.
                    Variant::Disc => assert!(i.dev1 > 0.9 * n1, "{}", i.dev1),
                    Variant::Adversarial => {
                        assert!(i.dev1 > 0.998 * n1, "{}", i.dev1);
                        assert!(i.dev2 > 0.99 * n2, "{}", i.dev2);
                    }
                }
            }
        }
    }
    assert!(rep.table().lines().count() > Family::ALL.len() * Variant::ALL.len());
}

/// The truth agrees with the library where the library is right: exact
/// input, `ok` points with a correspondent, every family (the calibrated
/// camera, large rotations and sparse rows included): the reported match
/// is the true correspondent to a median 0.005 px and the depth the true
/// one to a median 1e-3 (the far, small-disparity family needs that much).
#[test]
fn truth_agrees_with_the_library_on_exact_input() {
    for f in Family::ALL {
        let (mut p2e, mut ze) = (Vec::new(), Vec::new());
        for seed in 0..3 {
            let c = Case::new(f, seed).expect("boundaries");
            let i = c.input(Variant::Exact);
            let out = run(&c.scenario.intrinsics, &c.rendered.motion(), &i).expect("runs");
            for (ob, tb) in out.iter().zip(&c.truth) {
                for (o, t) in ob.iter().zip(tb) {
                    if o.status == Status::Ok && t.observed {
                        if let (Some(a), Some(b)) = (o.p2, t.p2) {
                            p2e.push((a[0] - b[0]).hypot(a[1] - b[1]));
                        }
                        ze.push(((o.z - t.z_true) / t.z_true).abs());
                    }
                }
            }
        }
        if ze.is_empty() {
            // The far-FOE family: every point is flagged by today's library.
            assert_eq!(f, Family::FarFoe);
            continue;
        }
        let med = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let (m2, mz) = (med(&mut p2e), med(&mut ze));
        assert!(
            m2 < 0.005 && mz < 1e-3,
            "{f:?}: median p2 error {m2}, depth error {mz}"
        );
    }
}

/// The largest distance of `truth` from `poly`, sampled every `step` px
/// against every segment of `poly` that comes within 3 rows (the
/// polylines run monotonically in `v`, and every distance here is < 2 px).
fn brute_deviation(truth: &[[f64; 2]], poly: &[[f64; 2]], step: f64) -> f64 {
    let mut worst = 0.0f64;
    for w in truth.windows(2) {
        let n = ((w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) / step)
            .ceil()
            .max(1.0) as usize;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            let q = [
                w[0][0] + t * (w[1][0] - w[0][0]),
                w[0][1] + t * (w[1][1] - w[0][1]),
            ];
            let d = poly
                .windows(2)
                .filter(|s| {
                    s[0][1].min(s[1][1]) <= q[1] + 3.0 && s[0][1].max(s[1][1]) >= q[1] - 3.0
                })
                .map(|s| point_segment_distance(q, s[0], s[1]))
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d);
        }
    }
    worst
}

/// The frame-2 deviation bound is never below a dense brute-force sampling
/// of the true curve (every 0.005 px against every segment) and at most
/// 3e-3 px above it, on sparse-row, rotated and mixed scenarios in all
/// variants.
#[test]
fn deviation_bound_is_safe_and_tight() {
    for (f, seed) in [
        (Family::SparseRows, 0),
        (Family::Rotation5, 1),
        (Family::Mixed, 2),
        (Family::CrestDip, 0),
    ] {
        let c = Case::new(f, seed).expect("boundaries");
        for v in Variant::ALL {
            let i = c.input(v);
            for (b, curve) in c.curve2.iter().enumerate() {
                let poly: Vec<[f64; 2]> = i.frame2[b]
                    .iter()
                    .map(|p| [f64::from(p.u), f64::from(p.v)])
                    .collect();
                let bound = deviation_bound(curve, &poly);
                let brute = brute_deviation(curve, &poly, 0.005);
                // The sampling itself may miss up to half a step.
                assert!(bound >= brute - 1e-9, "{f:?} {v:?} b{b}: {bound} < {brute}");
                assert!(
                    bound <= brute + 0.0025 + 3e-3,
                    "{f:?} {v:?} b{b}: {bound} vs {brute}"
                );
            }
        }
    }
}

/// The fold truth on hand-made curves: a circle off the FOE folds (every
/// ray through it meets it twice), a line does not, a second piece on the
/// opposite half-line from the FOE is no fold, and with the FOE at
/// infinity the whole line counts.
#[test]
fn fold_truth_on_hand_made_curves() {
    let foe = [0.0, 0.0, 1.0];
    let circle: Vec<[f64; 2]> = (0..=300)
        .map(|i| {
            let a = f64::from(i).to_radians();
            [40.0 + 10.0 * a.cos(), 10.0 * a.sin()]
        })
        .collect();
    let flags = fold_flags(&circle, foe);
    // Away from the two tangent rays (at ±14.5° seen from the FOE) every
    // point of the 300° arc folds.
    let folds = flags.iter().filter(|&&f| f).count();
    assert!(folds > 250, "{folds} of {}", flags.len());
    let line: Vec<[f64; 2]> = (0..50).map(|i| [f64::from(i) - 25.0, 10.0]).collect();
    assert!(fold_flags(&line, foe).iter().all(|&f| !f));
    // Two horizontal pieces on either side of the FOE joined far away: a
    // ray from the FOE through the upper piece meets the lower one only on
    // its opposite half-line.
    let mut u: Vec<[f64; 2]> = (-10..=10).map(|i| [f64::from(i), 5.0]).collect();
    u.extend([[200.0, 5.0], [200.0, -5.0]]);
    u.extend((-10..=10).rev().map(|i| [f64::from(i), -5.0]));
    let flags = fold_flags(&u, foe);
    assert!(flags[..21].iter().all(|&f| !f), "{flags:?}");
    // The FOE at infinity along x: every line is horizontal and the pieces
    // never meet it again (each lies on its own horizontal line), but a
    // vertical zig-zag does.
    assert!(fold_flags(&u[..21], [1.0, 0.0, 0.0]).iter().all(|&f| !f));
    let zig: Vec<[f64; 2]> = vec![[0.0, 0.0], [0.0, 10.0], [5.0, 0.0], [5.0, 10.0]];
    let flags = fold_flags(&zig, [1.0, 0.0, 0.0]);
    assert!(flags[0] && flags[3], "{flags:?}");
}

// ---------------------------------------------------------------------
// The reproducers of issue 11, in the replay format's geometry.

fn paper_camera() -> Intrinsics {
    Intrinsics::default()
}

fn run_pair(
    k: &Intrinsics,
    f1: &[[f64; 2]],
    f2: &[[f64; 2]],
    t: [f64; 3],
    r: [f64; 3],
) -> Vec<roadstereo::PointResult> {
    let mk = |b: &[[f64; 2]]| {
        let mut f = Frame::<64, 1>::new(k.camera());
        let pts: Vec<Pixel> = b
            .iter()
            .map(|q| Pixel::new(q[0] as f32, q[1] as f32))
            .collect();
        f.push_boundary(&pts).expect("valid boundary");
        f
    };
    let mut p = Box::new(Processor::<64, 1>::new(Config::default()));
    assert!(matches!(p.process(&mk(f1), None), Ok(Step::First)));
    let m = Motion::new(t.map(|x| x as f32), r.map(|x| x as f32)).expect("valid motion");
    let Ok(Step::Structure(s)) = p.process(&mk(f2), Some(&m)) else {
        panic!("second frame not processed")
    };
    s.boundaries()[0].points().to_vec()
}

/// Issue 11, section 2: the true crossing lies just behind p1', within the
/// error band.
mod behind_p1 {
    pub const T: [f64; 3] = [
        -0.07818124974848233,
        -0.09419702412404288,
        0.3946595640497631,
    ];
    pub const R: [f64; 3] = [
        0.011889156262433606,
        0.010067072784074895,
        0.031182122704678943,
    ];
    pub const F1: [[f64; 2]; 2] = [[85.0, 21.0], [84.0, 20.0]];
    pub const P1: [f64; 2] = [84.0, 20.0];
    #[rustfmt::skip]
    pub const F2: [[f64; 2]; 46] = [
        [71.0, 45.0], [71.0, 44.0], [71.0, 43.0], [71.0, 42.0], [71.0, 41.0], [70.0, 40.0],
        [70.0, 39.0], [70.0, 38.0], [70.0, 37.0], [70.0, 36.0], [70.0, 35.0], [69.0, 34.0],
        [69.0, 33.0], [69.0, 32.0], [69.0, 31.0], [68.0, 30.0], [68.0, 29.0], [68.0, 28.0],
        [67.0, 27.0], [67.0, 26.0], [67.0, 25.0], [66.0, 24.0], [66.0, 23.0], [65.0, 22.0],
        [65.0, 21.0], [64.0, 20.0], [64.0, 19.0], [63.0, 18.0], [63.0, 17.0], [62.0, 16.0],
        [61.0, 15.0], [61.0, 14.0], [60.0, 13.0], [59.0, 12.0], [58.0, 11.0], [58.0, 10.0],
        [57.0, 9.0], [56.0, 8.0], [55.0, 7.0], [54.0, 6.0], [53.0, 5.0], [52.0, 4.0],
        [51.0, 3.0], [49.0, 2.0], [48.0, 1.0], [47.0, 0.0],
    ];
    /// The issue's true depth, and depths on both separated parts of the
    /// band (near the reported crossing at about 0.80 and from the crossing
    /// just behind p1' out to the maximum depth).
    pub const CONSISTENT: [f64; 6] = [0.76, 0.8032, 2.5, 7.24, 100.0, 900.0];
    /// Localisation errors of the replay (the default configuration).
    pub const E: f64 = 0.5;
}

/// The truth of the first reproducer follows from its geometry alone: with
/// the true frame-1 point within 0.5 px of (84, 20) and the true frame-2
/// curve within 0.5 px of the polyline, the issue's true depth 7.24 is
/// consistent (a point within the disc whose ray at depth 7.24 projects
/// within 0.5 px of the polyline), and so is the whole stretch from the
/// crossing just behind p1' out to the maximum depth (its disparity is
/// below the error) as well as the crossing at about 0.80 the exact
/// half-line finds: the band meets the boundary in separated places.
#[test]
fn reproducer_behind_p1_truth_follows_from_the_geometry() {
    use behind_p1::*;
    let g = Geometry::new(paper_camera(), T, R);
    let f2 = F2.to_vec();
    for z in CONSISTENT {
        let d = g.consistency(P1, E, z, &f2);
        assert!(d <= E, "depth {z}: {d} px from the polyline");
    }
    // The exact line meets the polyline just behind p1' (the wrong way
    // for forward motion: a negative depth) and at the far part (z 0.80).
    let z: Vec<f64> = g
        .crossings(P1, &f2)
        .iter()
        .map(|&c| g.depth(P1, c))
        .collect();
    assert_eq!(z.len(), 2, "{z:?}");
    assert!(z[0] < 0.0 && (z[1] - 0.8032).abs() < 1e-3, "{z:?}");
    // In between (1.2 to 2.2) the band misses the boundary.
    for z in [1.2, 1.6, 2.0] {
        assert!(g.consistency(P1, E, z, &f2) > E, "{z}");
    }
}

/// Issue 11, section 2, reproducer 1: frame-1 point (84, 20) must not come
/// out `ok` with a stick excluding the true depth (about 7.24); any depth
/// it keeps must have a stick covering every consistent depth.
#[test]
fn issue11_true_crossing_just_behind_p1() {
    use behind_p1::*;
    let out = run_pair(&paper_camera(), &F1, &F2, T, R);
    let r = out[1];
    assert_eq!((r.pixel1().u, r.pixel1().v), (84.0, 20.0));
    println!(
        "(84, 20): {} {:?} {:?}",
        r.status(),
        r.depth(),
        r.interval()
    );
    if let Some(iv) = r.interval() {
        assert!(
            r.status() != Status::Ok || (iv.z_near <= 7.24 && 7.24 <= iv.z_far),
            "ok with a stick [{}, {}] that excludes the true depth 7.24",
            iv.z_near,
            iv.z_far
        );
        for z in CONSISTENT {
            assert!(
                f64::from(iv.z_near) <= z && z <= f64::from(iv.z_far),
                "{}: the stick [{}, {}] excludes the consistent depth {z}",
                r.status(),
                iv.z_near,
                iv.z_far
            );
        }
    }
}

/// Issue 11, section 4: the FOE far away but finite (sideways motion with a
/// rotation of 1e-6 rad).
mod far_foe {
    pub const T: [f64; 3] = [0.295781, 0.043219, 0.0];
    pub const R: [f64; 3] = [1e-6, 0.0, 0.0];
    #[rustfmt::skip]
    pub const F1: [[f64; 2]; 12] = [
        [504.057, 479.0], [489.926, 439.0], [475.794, 399.0], [461.663, 359.0],
        [447.531, 319.0], [433.4, 279.0], [419.269, 239.0], [405.137, 199.0],
        [391.006, 159.0], [376.874, 119.0], [362.743, 79.0], [348.611, 39.0],
    ];
    #[rustfmt::skip]
    pub const F2: [[f64; 2]; 24] = [
        [348.336, 479.0], [346.649, 459.0], [344.961, 439.0], [343.274, 419.0],
        [341.586, 399.0], [339.899, 379.0], [338.211, 359.0], [336.524, 339.0],
        [334.836, 319.0], [333.149, 299.0], [331.461, 279.0], [329.774, 259.0],
        [328.086, 239.0], [326.399, 219.0], [324.711, 199.0], [323.024, 179.0],
        [321.336, 159.0], [319.649, 139.0], [317.961, 119.0], [316.274, 99.0],
        [314.586, 79.0], [312.899, 59.0], [311.211, 39.0], [309.524, 19.0],
    ];
}

/// The truth of the second reproducer: each frame-1 point's exact epipolar
/// line meets the (straight) frame-2 polyline once, triangulated in `f64`.
fn far_foe_truth(rotation: [f64; 3]) -> Vec<f64> {
    use far_foe::*;
    let g = Geometry::new(paper_camera(), T, rotation);
    F1.iter()
        .map(|&p| {
            let c = g.crossings(p, &F2);
            assert_eq!(c.len(), 1, "{p:?}: {c:?}");
            g.depth(p, c[0])
        })
        .collect()
}

/// The second reproducer's truth: the same within 1e-5 with and without the
/// 1e-6 rad rotation, and with the rotation exactly 0 the library gives all
/// 12 points `ok` within 0.01 % of it (as the issue says).
#[test]
fn reproducer_far_foe_truth_follows_from_the_geometry() {
    use far_foe::*;
    let (with, without) = (far_foe_truth(R), far_foe_truth([0.0; 3]));
    for (a, b) in with.iter().zip(&without) {
        assert!(((a - b) / b).abs() < 1e-5, "{a} vs {b}");
    }
    let out = run_pair(&paper_camera(), &F1, &F2, T, [0.0; 3]);
    for (r, z) in out.iter().zip(&without) {
        assert_eq!(r.status(), Status::Ok);
        let d = f64::from(r.depth().expect("depth"));
        assert!(((d - z) / z).abs() < 1e-4, "{d} vs {z}");
    }
}

/// Issue 11, section 4, reproducer 2: with the FOE far away but finite the
/// 12 points do not fold: all `ok`, within 0.01 % of the truth (as with the
/// rotation exactly 0).
#[test]
fn issue11_far_foe_is_not_folded() {
    use far_foe::*;
    let truth = far_foe_truth(R);
    let out = run_pair(&paper_camera(), &F1, &F2, T, R);
    assert_eq!(out.len(), 12);
    let statuses: Vec<Status> = out.iter().map(|r| r.status()).collect();
    println!("{statuses:?}");
    for (i, (r, z)) in out.iter().zip(&truth).enumerate() {
        assert_eq!(r.status(), Status::Ok, "point {i}: {statuses:?}");
        let d = f64::from(r.depth().expect("depth"));
        assert!(((d - z) / z).abs() < 1e-4, "point {i}: {d} vs true {z}");
    }
}
