//! A boundary the detector lost in a frame, marked absent
//! (`Frame::push_absent`): the other boundary keeps its number and its
//! results, the absent one gives none (frame 1) or flags every point
//! (frame 2), the fast path still equals the reference, and the fusion
//! and its map keep the truth over drives where boundaries come and go.

use host_tests::drives::{run, tally, DriveFamily, DriveSpec, Noise, Tally};
use host_tests::{scenarios, synth, B, N};
use roadstereo::fusion::FusionConfig;
use roadstereo::{Camera, Config, Frame, Pixel, Processor, Status, Step, Structure};

/// A frame of `boundaries`, `None` marking one absent.
fn frame_with(cam: Camera, boundaries: &[Option<&Vec<Pixel>>]) -> Frame<N, B> {
    let mut f = Frame::new(cam);
    for b in boundaries {
        match b {
            Some(pts) => f.push_boundary(pts).expect("valid boundary"),
            None => f.push_absent().expect("a free slot"),
        }
    }
    f
}

/// The pair through a fresh processor with the largest work budget (so
/// one boundary's work cannot change the other's), and the reference's
/// results for the same pair.
fn pair(
    f1: &Frame<N, B>,
    f2: &Frame<N, B>,
    m: &roadstereo::Motion,
) -> (Structure<N, B>, Structure<N, B>) {
    let unlimited = Config::DEFAULT
        .with_work_budget(Config::MAX_WORK_PER_POINT)
        .expect("valid");
    let mut p = Box::new(Processor::<N, B>::new(unlimited));
    assert!(matches!(p.process(f1, None), Ok(Step::First)));
    let fast = p.process_against_kept(f2, m).expect("structure").clone();
    let slow = p.reference_against_kept(f2, m).expect("structure").clone();
    (fast, slow)
}

/// A two-view scenario with both edges seen in both frames: its camera,
/// the two frames' pixel polylines and the motion.
struct TwoEdges {
    cam: Camera,
    p1: Vec<Vec<Pixel>>,
    p2: Vec<Vec<Pixel>>,
    m: roadstereo::Motion,
}

fn two_edges(s: &synth::Scenario, quantised: bool) -> Option<TwoEdges> {
    let r = s.render();
    if r.frame1.len() < 2 || r.frame2.len() < 2 {
        return None;
    }
    Some(TwoEdges {
        cam: s.intrinsics.camera(),
        p1: synth::Rendered::pixels(&r.frame1, quantised),
        p2: synth::Rendered::pixels(&r.frame2, quantised),
        m: r.motion(),
    })
}

/// No result of an absent frame-2 boundary's points has a depth: each is
/// `no_intersection` or flagged before the search.
fn flagged_without_frame2(s: &Structure<N, B>, k: usize, len: usize) {
    let b = &s.boundaries()[k];
    assert_eq!(b.points().len(), len);
    for r in b.points() {
        assert!(
            matches!(
                r.status(),
                Status::NoIntersection
                    | Status::AtFoe
                    | Status::BehindCamera
                    | Status::OutOfView
                    | Status::Folded
            ),
            "{r:?}"
        );
        assert!(r.interval().is_none() && r.pixel2().is_none(), "{r:?}");
    }
}

#[test]
fn an_absent_boundary_keeps_the_numbering_and_the_other_boundarys_results() {
    let mut scs = scenarios::named();
    scs.extend((0..60).map(scenarios::random));
    let (mut pairs, mut searched) = (0usize, 0usize);
    for s in &scs {
        for quantised in [false, true] {
            let Some(TwoEdges { cam, p1, p2, m }) = two_edges(s, quantised) else {
                continue;
            };
            let full1 = frame_with(cam, &[Some(&p1[0]), Some(&p1[1])]);
            let full2 = frame_with(cam, &[Some(&p2[0]), Some(&p2[1])]);
            let (full, _) = pair(&full1, &full2, &m);
            for lost in 0..2 {
                let other = 1 - lost;
                let mut with = [Some(&p2[0]), Some(&p2[1])];
                with[lost] = None;
                // Frame 2 lost it: the other boundary's results unchanged,
                // the lost one's points without a depth.
                let (fast, slow) = pair(&full1, &frame_with(cam, &with), &m);
                assert_eq!(fast, slow, "{}: frame 2 without boundary {lost}", s.name);
                assert_eq!(fast.boundaries().len(), 2);
                assert_eq!(
                    fast.boundaries()[other],
                    full.boundaries()[other],
                    "{}: frame 2 without boundary {lost}",
                    s.name
                );
                flagged_without_frame2(&fast, lost, p1[lost].len());
                searched += p1[lost].len();
                // Frame 1 lost it: no results there, the other unchanged.
                let mut with1 = [Some(&p1[0]), Some(&p1[1])];
                with1[lost] = None;
                let (fast, slow) = pair(&frame_with(cam, &with1), &full2, &m);
                assert_eq!(fast, slow, "{}: frame 1 without boundary {lost}", s.name);
                assert!(fast.boundaries()[lost].points().is_empty());
                assert_eq!(fast.boundaries()[other], full.boundaries()[other]);
                // Both frames lost it.
                let (fast, _) = pair(&frame_with(cam, &with1), &frame_with(cam, &with), &m);
                assert!(fast.boundaries()[lost].points().is_empty());
                assert_eq!(fast.boundaries()[other], full.boundaries()[other]);
                pairs += 3;
            }
        }
    }
    println!("{pairs} pairs with a boundary absent; {searched} points of an absent frame-2 boundary, none with a depth");
    assert!(pairs > 300, "{pairs}");
}

#[test]
fn a_kept_frame_with_an_absent_boundary_pairs_on() {
    // The frame kept by `process` has boundary 0 absent: the next pair
    // gives boundary 0 no results and boundary 1 its own.
    let TwoEdges { cam, p1, p2, m } =
        two_edges(&scenarios::random(3), true).expect("both edges in view");
    let mut p = Box::new(Processor::<N, B>::new(Config::DEFAULT));
    let f1 = frame_with(cam, &[None, Some(&p1[1])]);
    assert!(matches!(p.process(&f1, None), Ok(Step::First)));
    let f2 = frame_with(cam, &[Some(&p2[0]), Some(&p2[1])]);
    let Ok(Step::Structure(s2)) = p.process(&f2, Some(&m)) else {
        panic!("a structure");
    };
    assert!(s2.boundaries()[0].points().is_empty());
    assert!(s2.boundaries()[1]
        .points()
        .iter()
        .any(|r| r.status() == Status::Ok));
    // A frame with every boundary absent is a frame without points.
    let empty = frame_with(cam, &[None, None]);
    let Ok(Step::Structure(s3)) = p.process(&empty, Some(&m)) else {
        panic!("a structure");
    };
    assert!(s3.boundaries()[1]
        .points()
        .iter()
        .all(|r| r.interval().is_none()));
}

#[test]
fn push_absent_takes_a_slot() {
    let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).expect("camera");
    let mut f = Frame::<8, 2>::new(cam);
    f.push_absent().expect("slot 0");
    assert!(f.boundaries()[0].is_absent());
    f.push_boundary(&[Pixel::new(10.0, 10.0), Pixel::new(11.0, 11.0)])
        .expect("slot 1");
    assert!(!f.boundaries()[1].is_absent());
    let before = f.clone();
    assert_eq!(
        f.push_absent(),
        Err(roadstereo::BoundaryError::TooManyBoundaries)
    );
    assert!(f == before);
    // An empty polyline is still an error: absence is said, not inferred.
    let mut g = Frame::<8, 2>::new(cam);
    assert_eq!(
        g.push_boundary(&[]),
        Err(roadstereo::BoundaryError::TooFewPoints)
    );
}

/// Drives whose detector loses a boundary now and then (boundary 0 in
/// every 5th frame from the 3rd, boundary 1 in every 7th from the 5th):
/// every fused interval with two or more agreeing pairs, and every
/// two-view stick with a correspondent, still holds the truth.
#[test]
fn fusion_over_drives_where_boundaries_come_and_go() {
    let mut all = Tally::default();
    let mut absent = 0usize;
    for family in DriveFamily::ALL {
        let mut seed = 0u64;
        let mut done = 0;
        while done < 6 {
            let Some(d) = DriveSpec::new(family, seed, 14).render() else {
                seed += 1;
                continue;
            };
            let mut input = d.input(Noise::Rounded, None, seed);
            for (j, f) in input.frames.iter_mut().enumerate() {
                if j % 5 == 3 {
                    f[0].clear();
                    absent += 1;
                }
                if j % 7 == 5 {
                    f[1].clear();
                    absent += 1;
                }
            }
            let policy = FusionConfig::DEFAULT
                .with_tilt(d.spec.tilt as f32)
                .expect("tilt");
            let r = run(&d, &input, policy, |_, _, f| {
                // The key frame counts a boundary absent before a seen one.
                if let Some(k) = f.key() {
                    let lens = input.frames[k.id() as usize]
                        .iter()
                        .map(Vec::len)
                        .collect::<Vec<_>>();
                    assert_eq!((k.len(0), k.len(1)), (lens[0], lens[1]));
                    let want = if lens[1] > 0 {
                        2
                    } else {
                        usize::from(lens[0] > 0)
                    };
                    assert_eq!(k.boundaries(), want, "key frame {}", k.id());
                }
            });
            all.add(&tally(&d, &r));
            done += 1;
            seed += 1;
        }
    }
    println!(
        "{} drives, {absent} boundaries absent: {} / {} fused snapshots hold the truth, {} wrong two-view sticks ({} with a correspondent), {} wrong fused",
        all.drives, all.consistent_contained, all.consistent, all.wrong_pairs, all.wrong_pairs_observed, all.wrong_fused
    );
    assert_eq!(all.consistent, all.consistent_contained);
    assert_eq!(all.wrong_pairs_observed, 0);
    assert_eq!(all.wrong_fused, 0);
    assert!(all.consistent > 5_000, "{all:?}");
}

/// With a work budget that binds (16 units a point), an absent boundary
/// changes what the budget leaves the other (its unused units carry from
/// one boundary to the next), never the match a point gets: each of the
/// other boundary's points is the unlimited run's result, `over_budget`,
/// or `ok` with the same match and a stick round the unlimited one (a
/// refinement left unpaid).
#[test]
fn with_a_budget_that_binds_the_other_boundary_only_moves_its_budget_line() {
    let small = Config::DEFAULT.with_work_budget(16).expect("valid");
    let run = |f1: &Frame<N, B>, f2: &Frame<N, B>, m: &roadstereo::Motion, c: Config| {
        let mut p = Box::new(Processor::<N, B>::new(c));
        assert!(matches!(p.process(f1, None), Ok(Step::First)));
        p.process_against_kept(f2, m).expect("structure").clone()
    };
    let (mut moved, mut compared) = (0usize, 0usize);
    for s in (0..40).map(scenarios::random) {
        let Some(TwoEdges { cam, p1, p2, m }) = two_edges(&s, true) else {
            continue;
        };
        let full1 = frame_with(cam, &[Some(&p1[0]), Some(&p1[1])]);
        let full2 = frame_with(cam, &[Some(&p2[0]), Some(&p2[1])]);
        let (unlimited, _) = pair(&full1, &full2, &m);
        let budgeted = run(&full1, &full2, &m, small);
        let variants = [
            (
                frame_with(cam, &[Some(&p1[0]), Some(&p1[1])]),
                frame_with(cam, &[None, Some(&p2[1])]),
            ),
            (
                frame_with(cam, &[None, Some(&p1[1])]),
                frame_with(cam, &[Some(&p2[0]), Some(&p2[1])]),
            ),
        ];
        for (f1, f2) in &variants {
            let got = run(f1, f2, &m, small);
            for ((g, u), b) in got.boundaries()[1]
                .points()
                .iter()
                .zip(unlimited.boundaries()[1].points())
                .zip(budgeted.boundaries()[1].points())
            {
                // (Or a looser stick round the same match: a refinement the
                // budget did not pay for, as any budget may leave.)
                let looser = g.status() == Status::Ok
                    && u.status() == Status::Ok
                    && g.pixel2() == u.pixel2()
                    && g.interval()
                        .zip(u.interval())
                        .is_some_and(|(a, b)| a.z_near <= b.z_near && b.z_far <= a.z_far);
                assert!(
                    g == u || looser || g.status() == Status::OverBudget,
                    "{}: {g:?} vs {u:?}",
                    s.name
                );
                moved += usize::from(g != b);
                compared += 1;
            }
        }
    }
    println!("budget 16: {moved} of {compared} points of the other boundary differ from the run with both boundaries, each the unlimited result, over_budget or a looser stick");
    assert!(compared > 10_000, "{compared}");
}
