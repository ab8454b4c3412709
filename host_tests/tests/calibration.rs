//! Intrinsic calibration from foci of expansion (Appendix II B) against a
//! synthetic camera with the paper's calibrated values.

use host_tests::calib::{calibrate_run, paper_motions, TrueCamera};
use roadstereo::calibration::{
    calibrate_jointly, calibrate_stepwise, focus_of_expansion, CalibrationError, Flow, Intrinsics,
    MotionFlows,
};
use roadstereo::Pixel;

struct Errors {
    c: f64,
    roll_deg: f64,
    r: f64,
    fx: f64,
    fy: f64,
}

impl Errors {
    fn of(k: &Intrinsics, t: &TrueCamera) -> Self {
        let r_true = t.fx / t.fy;
        Errors {
            c: (f64::from(k.cx) - t.cx).hypot(f64::from(k.cy) - t.cy),
            roll_deg: (f64::from(k.roll) - t.roll).to_degrees().abs(),
            r: (f64::from(k.aspect().expect("positive focal lengths")) / r_true - 1.0).abs(),
            fx: (f64::from(k.fx) / t.fx - 1.0).abs(),
            fy: (f64::from(k.fy) / t.fy - 1.0).abs(),
        }
    }
    fn within_issue_tolerances(&self) -> bool {
        self.c <= 1.5
            && self.roll_deg <= 0.5
            && self.r <= 0.02
            && self.fx <= 0.02
            && self.fy <= 0.02
    }
    /// One number: each error divided by its tolerance, summed.
    fn score(&self) -> f64 {
        self.c / 1.5 + self.roll_deg / 0.5 + (self.r + self.fx + self.fy) / 0.02
    }
}

/// Step-by-step and joint calibration of one synthetic run.
fn run(
    cam: &TrueCamera,
    motions: &[[f64; 3]],
    n: usize,
    outliers: f64,
    seed: u64,
) -> Result<(Intrinsics, Intrinsics), CalibrationError> {
    calibrate_run(cam, motions, n, outliers, seed).map(|(_, s, j)| (s, j.intrinsics))
}

#[test]
fn fifty_points_per_motion_recover_the_paper_camera() {
    let cam = TrueCamera::default();
    let (mut worst_s, mut worst_j) = (0.0f64, 0.0f64);
    let (mut sum_s, mut sum_j) = (0.0, 0.0);
    for seed in 0..20 {
        let (s, j) = run(&cam, &paper_motions(), 50, 0.0, seed).expect("calibrates");
        let (es, ej) = (Errors::of(&s, &cam), Errors::of(&j, &cam));
        assert!(
            ej.within_issue_tolerances(),
            "joint, seed {seed}: c {:.2} px, roll {:.3}°, r {:.4}, fx {:.4}, fy {:.4}",
            ej.c,
            ej.roll_deg,
            ej.r,
            ej.fx,
            ej.fy
        );
        assert!(
            es.within_issue_tolerances(),
            "stepwise, seed {seed}: c {:.2} px, roll {:.3}°, r {:.4}, fx {:.4}, fy {:.4}",
            es.c,
            es.roll_deg,
            es.r,
            es.fx,
            es.fy
        );
        worst_s = worst_s.max(es.score());
        worst_j = worst_j.max(ej.score());
        sum_s += es.score();
        sum_j += ej.score();
    }
    println!("error score (sum of error/tolerance), 20 runs: stepwise mean {:.3} worst {:.3}; joint mean {:.3} worst {:.3}", sum_s / 20.0, worst_s, sum_j / 20.0, worst_j);
    assert!(
        sum_j <= sum_s,
        "joint ({sum_j}) less accurate than stepwise ({sum_s})"
    );
}

/// With 10 % of the flows replaced by random wrong matches, the joint
/// calibration (the result the library offers) still meets every
/// tolerance; the step-by-step one is reported.
#[test]
fn ten_percent_wrong_matches_are_rejected() {
    let cam = TrueCamera::default();
    let (mut stepwise_ok, mut sum_s, mut sum_j) = (0, 0.0, 0.0);
    for seed in 0..20 {
        let (s, j) = run(&cam, &paper_motions(), 50, 0.10, 100 + seed).expect("calibrates");
        let (es, ej) = (Errors::of(&s, &cam), Errors::of(&j, &cam));
        assert!(
            ej.within_issue_tolerances(),
            "joint, seed {seed}: c {:.2} px, roll {:.3}°, r {:.4}, fx {:.4}, fy {:.4}",
            ej.c,
            ej.roll_deg,
            ej.r,
            ej.fx,
            ej.fy
        );
        stepwise_ok += usize::from(es.within_issue_tolerances());
        sum_s += es.score();
        sum_j += ej.score();
    }
    println!("10 % wrong matches, 20 runs: joint within tolerance 20/20 (mean score {:.3}), stepwise {stepwise_ok}/20 (mean score {:.3})", sum_j / 20.0, sum_s / 20.0);
    assert!(sum_j <= sum_s);
}

#[test]
fn errors_shrink_with_more_points_and_more_motions() {
    let cam = TrueCamera::default();
    let mean = |n: usize, motions: &[[f64; 3]]| -> (f64, f64) {
        let (mut s, mut j) = (0.0, 0.0);
        for seed in 0..20 {
            let (a, b) = run(&cam, motions, n, 0.0, 1000 + seed).expect("calibrates");
            s += Errors::of(&a, &cam).score();
            j += Errors::of(&b, &cam).score();
        }
        (s / 20.0, j / 20.0)
    };
    let mut rows = Vec::new();
    for n in [15, 50, 150] {
        let (s, j) = mean(n, &paper_motions());
        println!("points/motion {n:4}: stepwise {s:.3}  joint {j:.3}");
        rows.push((s, j));
    }
    assert!(rows[2].0 < rows[0].0 && rows[2].1 < rows[0].1, "{rows:?}");
    // More motions: the paper's five plus sideways-forward ones.
    let mut more = paper_motions();
    more.extend([
        [2.5, 0.0, 2.5],
        [-2.5, 0.0, 2.5],
        [0.0, 2.5, 2.5],
        [0.0, -2.5, 2.5],
    ]);
    let (_, j5) = mean(50, &paper_motions());
    let (_, j9) = mean(50, &more);
    println!("joint, 50 points/motion: 5 motions {j5:.3}, 9 motions {j9:.3}");
    assert!(j9 < j5);
}

#[test]
fn degenerate_inputs_give_typed_errors() {
    let f = |a: (f32, f32), b: (f32, f32)| Flow {
        from: Pixel::new(a.0, a.1),
        to: Pixel::new(b.0, b.1),
    };
    assert_eq!(
        focus_of_expansion::<8>(&[]),
        Err(CalibrationError::TooFewFlows)
    );
    assert_eq!(
        focus_of_expansion::<8>(&[f((1.0, 1.0), (2.0, 2.0))]),
        Err(CalibrationError::TooFewFlows)
    );
    // Zero-length flows are unusable.
    assert_eq!(
        focus_of_expansion::<8>(&[f((1.0, 1.0), (1.0, 1.0)), f((5.0, 1.0), (5.0, 1.0))]),
        Err(CalibrationError::TooFewFlows)
    );
    // Parallel flows: sideways motion, FOE at infinity.
    let parallel: Vec<Flow> = (0..10)
        .map(|i| {
            f(
                (10.0 * i as f32, 5.0 * i as f32),
                (10.0 * i as f32 + 7.0, 5.0 * i as f32),
            )
        })
        .collect();
    assert_eq!(
        focus_of_expansion::<16>(&parallel),
        Err(CalibrationError::Parallel)
    );
    assert_eq!(
        focus_of_expansion::<8>(&[f((f32::NAN, 1.0), (2.0, 2.0)), f((3.0, 1.0), (4.0, 5.0))]),
        Err(CalibrationError::NotFinite)
    );
    assert_eq!(
        focus_of_expansion::<1>(&[f((1.0, 1.0), (2.0, 2.0)), f((3.0, 1.0), (4.0, 5.0))]),
        Err(CalibrationError::TooManyFlows)
    );
    // Diagonal FOEs that are not consistent with any camera.
    let c = Pixel::new(256.0, 240.0);
    assert_eq!(
        calibrate_stepwise(c, [c, c, c, c]),
        Err(CalibrationError::Degenerate)
    );
    assert_eq!(
        calibrate_stepwise(Pixel::new(f32::INFINITY, 0.0), [c, c, c, c]),
        Err(CalibrationError::NotFinite)
    );
    let start = Intrinsics {
        cx: 256.0,
        cy: 240.0,
        roll: 0.0,
        fx: 600.0,
        fy: 600.0,
    };
    let flows = [f((1.0, 1.0), (2.0, 2.0))];
    assert_eq!(
        calibrate_jointly::<8>(
            &[MotionFlows {
                translation: [1.0, 0.0, 0.0],
                flows: &flows
            }],
            &start
        ),
        Err(CalibrationError::BadTranslation)
    );
    assert_eq!(
        calibrate_jointly::<8>(
            &[MotionFlows {
                translation: [0.0, 0.0, 1.0],
                flows: &flows
            }],
            &start
        ),
        Err(CalibrationError::TooFewFlows)
    );
}

/// The calibrated camera feeds the pipeline: a camera model plus the roll
/// that turns robot-frame motions into camera-frame ones.
#[test]
fn calibration_converts_into_the_pipeline_camera() {
    let cam = TrueCamera::default();
    let (_, j) = run(&cam, &paper_motions(), 50, 0.0, 7).expect("calibrates");
    let c = j.camera(512, 480).expect("valid camera");
    assert!((f64::from(c.fx()) / cam.fx - 1.0).abs() < 0.02);
    // A robot motion straight ahead is, in the rolled camera axes, still
    // straight ahead; a sideways one picks up a vertical part of sin(γ).
    let m = roadstereo::Motion::new([1.0, 0.0, 0.0], [0.0, 0.0, 0.0]).unwrap();
    let mc = j.camera_motion(&m).unwrap();
    let t = mc.translation();
    assert!((f64::from(t[1]) - (-cam.roll.sin())).abs() < 0.01, "{t:?}");
    // The predicted FOE of the calibrated camera matches the true one.
    for tr in paper_motions() {
        let p = j.predicted_foe(tr.map(|x| x as f32)).unwrap();
        let q = cam.foe(tr);
        assert!(
            (f64::from(p.u) - q[0]).hypot(f64::from(p.v) - q[1])
                < 0.02 * (q[0] - cam.cx).hypot(q[1] - cam.cy) + 1.5
        );
    }
}

/// End to end: a camera with the paper's roll and aspect ratio watches a
/// curved ground line while the robot drives forward; the pipeline, fed
/// with the *calibrated* camera and the robot motion converted to camera
/// axes, recovers the depths.
#[test]
fn calibrated_camera_feeds_the_pipeline() {
    use roadstereo::{Config, Frame, Motion, Processor, Status, Step};
    let cam = TrueCamera::default();
    let (_, k) = run(&cam, &paper_motions(), 50, 0.0, 3).expect("calibrates");
    let camera = k.camera(512, 480).expect("camera");
    // A ground line curving right, 1 unit below the camera, robot frame.
    let curve: Vec<[f64; 3]> = (0..4000)
        .map(|i| {
            let s = i as f64 * 0.005;
            [-0.8 + 0.02 * s * s, 1.0, 2.0 + s]
        })
        .collect();
    let robot_t = [-0.1, 0.0, 0.5];
    // One point per image row, sub-pixel, with the true 3-D point's depth.
    let detect = |shift: [f64; 3]| -> Vec<(Pixel, f64)> {
        let proj: Vec<Option<[f64; 2]>> = curve
            .iter()
            .map(|p| cam.project([p[0] - shift[0], p[1] - shift[1], p[2] - shift[2]]))
            .collect();
        let mut out: Vec<(Pixel, f64)> = Vec::new();
        for (i, w) in proj.windows(2).enumerate() {
            let (Some(a), Some(b)) = (w[0], w[1]) else {
                continue;
            };
            let mut r = a[1].floor();
            while r > b[1] {
                let t = (a[1] - r) / (a[1] - b[1]);
                let u = a[0] + t * (b[0] - a[0]);
                let z = curve[i][2] + t * (curve[i + 1][2] - curve[i][2]) - shift[2];
                if out.last().is_none_or(|(p, _)| f64::from(p.v) > r) {
                    out.push((Pixel::new(u as f32, r as f32), z));
                }
                r -= 1.0;
            }
        }
        out
    };
    let (b1, b2) = (detect([0.0; 3]), detect(robot_t));
    assert!(b1.len() > 100 && b2.len() > 100);
    let mut f1 = Frame::<512, 2>::new(camera);
    f1.push_boundary(&b1.iter().map(|x| x.0).collect::<Vec<_>>())
        .unwrap();
    let mut f2 = Frame::<512, 2>::new(camera);
    f2.push_boundary(&b2.iter().map(|x| x.0).collect::<Vec<_>>())
        .unwrap();
    let robot = Motion::new(robot_t.map(|x| x as f32), [0.0; 3]).unwrap();
    let motion = k.camera_motion(&robot).unwrap();
    let mut p = Box::new(Processor::<512, 2>::new(Config::default()));
    assert!(matches!(p.process(&f1, None), Ok(Step::First)));
    let Ok(Step::Structure(s)) = p.process(&f2, Some(&motion)) else {
        panic!("no structure")
    };
    let mut n = 0;
    let mut worst: f64 = 0.0;
    for (r, (_, z)) in s.boundaries()[0].points().iter().zip(&b1) {
        if r.status() == Status::Ok {
            let e = (f64::from(r.depth().unwrap()) / z - 1.0).abs();
            worst = worst.max(e);
            n += 1;
        }
    }
    println!(
        "calibrated pipeline: {n} depths, worst relative error {:.3} %, statuses {:?}",
        worst * 100.0,
        s.status_counts()
    );
    assert!(n >= 100, "{n} depths");
    assert!(worst < 0.02, "worst relative depth error {worst}");
}

/// Issue 15, item 2: finite inputs used to give `Ok` with infinite
/// results. The issue's two reproducers are now typed errors (a coordinate
/// beyond `MAX_COORD_PX`).
#[test]
fn issue_15_reproducers_are_typed_errors() {
    let p = |u: f32, v: f32| Pixel::new(u, v);
    assert_eq!(
        calibrate_stepwise(
            p(256.0, 240.0),
            [
                p(1000.0, 1000.0),
                p(-1e20, 1000.0),
                p(-500.0, -500.0),
                p(1000.0, -500.0)
            ]
        ),
        Err(CalibrationError::OutOfRange)
    );
    let flows = [
        Flow {
            from: p(100.0, 100.0),
            to: p(90.0, 95.0),
        },
        Flow {
            from: p(400.0, 300.0),
            to: p(420.0, 310.0),
        },
        Flow {
            from: p(377.5, -1e30),
            to: p(-9597.0, -1e30),
        },
    ];
    assert_eq!(
        focus_of_expansion::<8>(&flows),
        Err(CalibrationError::OutOfRange)
    );
}

/// Values to put into every input slot: zeros of both signs, subnormals,
/// ordinary values, the accepted limit `±MAX_COORD_PX`, just beyond it,
/// ±1e30, ±f32::MAX, ±inf, NaN.
fn extremes() -> Vec<f32> {
    use roadstereo::calibration::MAX_COORD_PX;
    vec![
        0.0,
        -0.0,
        f32::from_bits(1),
        -f32::from_bits(1),
        1.0e-30,
        1.0,
        -3.0,
        300.0,
        1.0e5,
        MAX_COORD_PX,
        -MAX_COORD_PX,
        MAX_COORD_PX * 1.000_001,
        1.0e30,
        -1.0e30,
        f32::MAX,
        -f32::MAX,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
    ]
}

fn finite_foe(f: &roadstereo::calibration::FoeFit) -> bool {
    f.foe.u.is_finite() && f.foe.v.is_finite() && f.rms.is_finite()
}

fn finite_intrinsics(k: &Intrinsics) -> bool {
    [k.cx, k.cy, k.roll, k.fx, k.fy]
        .iter()
        .all(|x| x.is_finite())
}

/// The rule: every result is finite or it is a typed error. Each input
/// coordinate of `focus_of_expansion`, `calibrate_stepwise` and
/// `calibrate_jointly` in turn takes every extreme value; a finite value
/// beyond `±MAX_COORD_PX` is `OutOfRange`, a NaN or infinite one
/// `NotFinite` (`BadTranslation` in a translation), and every `Ok` has only
/// finite numbers.
#[test]
fn extreme_inputs_give_finite_results_or_typed_errors() {
    use roadstereo::calibration::MAX_COORD_PX;
    let cam = TrueCamera::default();
    let (sets, stepwise, _) = calibrate_run(&cam, &paper_motions(), 15, 0.0, 5).expect("run");
    let in_range = |x: f32| x.abs() <= MAX_COORD_PX;
    // The error a bad coordinate must give.
    let want = |x: f32| {
        if !x.is_finite() {
            CalibrationError::NotFinite
        } else {
            CalibrationError::OutOfRange
        }
    };
    let (mut ok, mut err) = (0, 0);
    // focus_of_expansion: every coordinate of the first four flows.
    let base: Vec<Flow> = sets[1].clone();
    for slot in 0..16 {
        for x in extremes() {
            let mut flows = base.clone();
            let f = &mut flows[slot / 4];
            match slot % 4 {
                0 => f.from.u = x,
                1 => f.from.v = x,
                2 => f.to.u = x,
                _ => f.to.v = x,
            }
            match focus_of_expansion::<64>(&flows) {
                Ok(fit) => {
                    assert!(in_range(x) && finite_foe(&fit), "slot {slot}, {x}: {fit:?}");
                    ok += 1;
                }
                Err(e) => {
                    if !in_range(x) {
                        assert_eq!(e, want(x), "slot {slot}, {x}");
                    }
                    err += 1;
                }
            }
        }
    }
    // calibrate_stepwise: every coordinate of the five FOEs.
    let foes: Vec<Pixel> = (0..5)
        .map(|m| {
            let f = cam.foe(paper_motions()[m]);
            Pixel::new(f[0] as f32, f[1] as f32)
        })
        .collect();
    for slot in 0..10 {
        for x in extremes() {
            let mut p = foes.clone();
            if slot % 2 == 0 {
                p[slot / 2].u = x;
            } else {
                p[slot / 2].v = x;
            }
            match calibrate_stepwise(p[0], [p[1], p[2], p[3], p[4]]) {
                Ok(k) => {
                    assert!(
                        in_range(x) && finite_intrinsics(&k),
                        "slot {slot}, {x}: {k:?}"
                    );
                    ok += 1;
                }
                Err(e) => {
                    if !in_range(x) {
                        assert_eq!(e, want(x), "slot {slot}, {x}");
                    }
                    err += 1;
                }
            }
        }
    }
    // calibrate_jointly: a flow coordinate, a translation component and
    // every start parameter.
    let run_joint = |sets: &[Vec<Flow>], t: &[[f32; 3]], start: &Intrinsics| {
        let mf: Vec<MotionFlows<'_>> = sets
            .iter()
            .zip(t)
            .map(|(f, &translation)| MotionFlows {
                translation,
                flows: f,
            })
            .collect();
        calibrate_jointly::<64>(&mf, start)
    };
    let translations: Vec<[f32; 3]> = paper_motions()
        .iter()
        .map(|t| t.map(|x| x as f32))
        .collect();
    let check = |r: Result<roadstereo::calibration::JointFit, CalibrationError>,
                 what: &str,
                 ok: &mut usize,
                 err: &mut usize| match r {
        Ok(j) => {
            let finite = finite_intrinsics(&j.intrinsics)
                && j.rms.is_finite()
                && j.sigma.iter().all(|s| s.is_finite());
            assert!(finite, "{what}: {j:?}");
            *ok += 1;
        }
        Err(_) => *err += 1,
    };
    for x in extremes() {
        let mut s = sets.clone();
        s[2][0].to.v = x;
        let r = run_joint(&s, &translations, &stepwise);
        if !in_range(x) {
            assert_eq!(r, Err(want(x)), "flow {x}");
        }
        check(r, &format!("flow {x}"), &mut ok, &mut err);
        for c in 0..3 {
            let mut t = translations.clone();
            t[3][c] = x;
            let r = run_joint(&sets, &t, &stepwise);
            if !x.is_finite() || (c == 2 && x <= 0.0) {
                assert_eq!(r, Err(CalibrationError::BadTranslation), "t[{c}] = {x}");
            } else if x.abs() > 1.0e6 {
                assert_eq!(r, Err(CalibrationError::OutOfRange), "t[{c}] = {x}");
            }
            check(r, &format!("t[{c}] = {x}"), &mut ok, &mut err);
        }
        for field in 0..5 {
            let mut k = stepwise;
            *[&mut k.cx, &mut k.cy, &mut k.roll, &mut k.fx, &mut k.fy][field] = x;
            let r = run_joint(&sets, &translations, &k);
            if !x.is_finite() {
                assert_eq!(r, Err(CalibrationError::NotFinite), "start {field} = {x}");
            }
            check(r, &format!("start {field} = {x}"), &mut ok, &mut err);
        }
    }
    println!("extreme inputs: {ok} finite results, {err} typed errors");
    assert!(ok > 100 && err > 100);
}

/// Extreme but valid cameras: focal lengths at the pipeline's limit
/// (1e5 px, FOEs 1e5 px from the centre), a principal point at `(0, 0)`
/// (zeros of both signs in the FOEs), and a tiny one: step by step from
/// the exact FOEs (computed in `f64`) recovers the camera to 1e-4 relative
/// (the FOEs are rounded to `f32`).
#[test]
fn exact_foes_of_extreme_cameras_give_the_camera() {
    for cam in [
        TrueCamera {
            fx: 1.0e5,
            fy: 0.8e5,
            ..TrueCamera::default()
        },
        TrueCamera {
            cx: 0.0,
            cy: 0.0,
            roll: 0.0,
            ..TrueCamera::default()
        },
        TrueCamera {
            fx: 2.0,
            fy: 3.0,
            ..TrueCamera::default()
        },
    ] {
        let p: Vec<Pixel> = paper_motions()
            .iter()
            .map(|&t| {
                let f = cam.foe(t);
                Pixel::new(f[0] as f32, f[1] as f32)
            })
            .collect();
        let k = calibrate_stepwise(p[0], [p[1], p[2], p[3], p[4]]).expect("calibrates");
        let rel = |a: f32, b: f64| (f64::from(a) - b).abs() / b.abs().max(1.0);
        assert!(
            rel(k.cx, cam.cx) < 1e-4 && rel(k.cy, cam.cy) < 1e-4,
            "{k:?}"
        );
        assert!(
            rel(k.fx, cam.fx) < 1e-4 && rel(k.fy, cam.fy) < 1e-4,
            "{k:?}"
        );
        assert!((f64::from(k.roll) - cam.roll).abs() < 1e-4, "{k:?}");
        // The prediction of the recovered camera gives the FOEs back.
        for (&t, q) in paper_motions().iter().zip(&p) {
            let r = k.predicted_foe(t.map(|x| x as f32)).expect("finite");
            let scale = f64::from(q.u - k.cx).hypot(f64::from(q.v - k.cy));
            assert!(f64::from(r.u - q.u).hypot(f64::from(r.v - q.v)) < 1e-4 * scale + 1e-3);
        }
    }
}

/// The intrinsics' own methods: a result is finite or a typed error.
#[test]
fn intrinsics_methods_are_finite_or_typed_errors() {
    let k = Intrinsics {
        cx: 256.0,
        cy: 240.0,
        roll: 0.0,
        fx: 600.0,
        fy: 800.0,
    };
    assert_eq!(k.aspect(), Ok(0.75));
    let with = |fx: f32, fy: f32| Intrinsics { fx, fy, ..k };
    assert_eq!(
        with(f32::MAX, 1.0e-30).aspect(),
        Err(CalibrationError::Overflow)
    );
    assert_eq!(with(0.0, 800.0).aspect(), Err(CalibrationError::Degenerate));
    assert_eq!(
        with(600.0, -0.0).aspect(),
        Err(CalibrationError::Degenerate)
    );
    assert_eq!(
        with(f32::NAN, 800.0).aspect(),
        Err(CalibrationError::NotFinite)
    );
    assert_eq!(with(1.0e-45, 1.0).aspect(), Ok(1.0e-45));
    // predicted_foe: finite or typed.
    assert_eq!(
        with(f32::MAX, 800.0).predicted_foe([2.0, 0.0, 1.0]),
        Err(CalibrationError::Overflow)
    );
    assert_eq!(
        k.predicted_foe([1.0e6, 0.0, 1.0e-45]),
        Err(CalibrationError::Overflow)
    );
    assert_eq!(
        k.predicted_foe([2.0e6, 0.0, 1.0]),
        Err(CalibrationError::OutOfRange)
    );
    assert_eq!(
        k.predicted_foe([0.0, f32::NAN, 1.0]),
        Err(CalibrationError::BadTranslation)
    );
    assert_eq!(
        k.predicted_foe([0.0, 0.0, -0.0]),
        Err(CalibrationError::BadTranslation)
    );
    let p = k
        .predicted_foe([0.0, 0.0, 1.0e-45])
        .expect("straight ahead");
    assert_eq!((p.u, p.v), (256.0, 240.0));
    assert_eq!(
        Intrinsics {
            cy: f32::INFINITY,
            ..k
        }
        .predicted_foe([0.0, 0.0, 1.0]),
        Err(CalibrationError::NotFinite)
    );
    // camera: validated by Camera::new.
    assert!(matches!(
        with(f32::MAX, 800.0).camera(512, 480),
        Err(CalibrationError::Camera(_))
    ));
    // camera_motion: a result Motion::new rejects is a typed error.
    let robot = roadstereo::Motion::new([1.0e6, 1.0e6, 0.0], [0.0; 3]).expect("valid");
    let rolled = Intrinsics { roll: 0.5, ..k };
    assert_eq!(
        rolled.camera_motion(&robot),
        Err(CalibrationError::Motion(
            roadstereo::MotionError::TranslationTooLarge
        ))
    );
}

/// Diagonal FOEs no camera of the model gives are `Degenerate`, not a
/// roll from `atan2(0, 0)` (an adversarial review: the four of a square
/// in mirrored order gave `Ok` with roll 0, `f_x = f_y = 100`). The same
/// four in the documented order still calibrate, at every roll.
#[test]
fn mirrored_diagonal_foes_are_degenerate() {
    let p = Pixel::new;
    let c = p(300.0, 200.0);
    // Round the image in the documented order: (+,+), (−,+), (−,−), (+,−).
    let ok = calibrate_stepwise(
        c,
        [
            p(400.0, 300.0),
            p(200.0, 300.0),
            p(200.0, 100.0),
            p(400.0, 100.0),
        ],
    )
    .expect("the documented order");
    assert!(
        (ok.fx - 100.0).abs() < 1e-3 && (ok.fy - 100.0).abs() < 1e-3 && ok.roll.abs() < 1e-6,
        "{ok:?}"
    );
    let mirrored = [
        p(400.0, 300.0),
        p(400.0, 100.0),
        p(200.0, 100.0),
        p(200.0, 300.0),
    ];
    assert_eq!(
        calibrate_stepwise(c, mirrored),
        Err(CalibrationError::Degenerate)
    );
    // Every roll of the documented order, and its mirror image. (Near
    // rolls of ±45° and ±135° the fit of `r²` is ill-conditioned: those
    // are `Degenerate` too.)
    let mut calibrated = 0;
    for k in 0..360 {
        let g = (k as f32).to_radians();
        let (s, co) = (g.sin(), g.cos());
        let turn = |x: f32, y: f32| p(300.0 + co * x - s * y, 200.0 + s * x + co * y);
        let square = [
            turn(100.0, 100.0),
            turn(-100.0, 100.0),
            turn(-100.0, -100.0),
            turn(100.0, -100.0),
        ];
        if let Ok(k) = calibrate_stepwise(c, square) {
            assert!(
                (k.fx - 100.0).abs() < 0.1 && (k.fy - 100.0).abs() < 0.1,
                "{g}: {k:?}"
            );
            calibrated += 1;
        }
        let [a, b, cc, d] = square;
        assert_eq!(
            calibrate_stepwise(c, [a, d, cc, b]),
            Err(CalibrationError::Degenerate),
            "roll {k}° mirrored"
        );
    }
    // (Within 2.87° of ±45° and ±135° the fit is ill-conditioned and
    // `Degenerate`, below: 5 whole degrees each side of each.)
    assert!(calibrated >= 340, "{calibrated} of 360 rolls calibrated");
}

/// An adversarial review: near rolls of 45° + k·90° the diagonal FOEs lie
/// near the image axes and the perpendicularity test cannot tell the
/// aspect ratio: at 44.9° with FOEs on the pixel grid `calibrate_stepwise`
/// gave `Ok` with f_x 545, f_y 890 for 600, 800. Now it is `Degenerate`
/// within 2.87° of those rolls (`MIN_STEPWISE_CONDITION`) and elsewhere
/// within the documented sensitivity `4 δ / (L |cos 2γ|)` (here with
/// twice that allowed): every 0.05° of roll, FOEs of the paper-like camera
/// computed in `f64` and rounded to the pixel grid.
#[test]
fn stepwise_is_degenerate_only_near_the_axes_and_accurate_elsewhere() {
    let (cx, cy, fx, fy) = (256.0f64, 240.0f64, 600.0f64, 800.0f64);
    let foe = |g: f64, tx: f64, ty: f64| {
        let (s, c) = g.sin_cos();
        let (x, y) = (c * tx + s * ty, -s * tx + c * ty);
        Pixel::new((cx + fx * x).round() as f32, (cy + fy * y).round() as f32)
    };
    let (mut ok, mut degenerate, mut worst) = (0, 0, 0.0f64);
    for k in 0..7200 {
        let g = (k as f64 * 0.05).to_radians();
        let straight = foe(g, 0.0, 0.0);
        let diagonal = [
            foe(g, 1.0, 1.0),
            foe(g, -1.0, 1.0),
            foe(g, -1.0, -1.0),
            foe(g, 1.0, -1.0),
        ];
        // Off the nearest 45° + k·90°, in degrees.
        let d = (k as f64 * 0.05 - 45.0).rem_euclid(90.0);
        let off = d.min(90.0 - d);
        let cos2 = (2.0 * g).cos().abs();
        match calibrate_stepwise(straight, diagonal) {
            Ok(c) => {
                ok += 1;
                assert!(off > 2.8, "{:.2}°: {c:?}", k as f64 * 0.05);
                // L: the shortest offset of a diagonal FOE; δ: the grid's
                // rounding, half a pixel each way.
                let l = diagonal
                    .iter()
                    .map(|p| (f64::from(p.u) - cx).hypot(f64::from(p.v) - cy))
                    .fold(f64::INFINITY, f64::min);
                let allowed = 2.0 * 4.0 * 0.5f64.hypot(0.5) / (l * cos2);
                let e = ((f64::from(c.fx) - fx) / fx)
                    .abs()
                    .max(((f64::from(c.fy) - fy) / fy).abs());
                assert!(
                    e <= allowed,
                    "{:.2}°: {c:?}, {e} > {allowed}",
                    k as f64 * 0.05
                );
                worst = worst.max(e / allowed);
            }
            Err(e) => {
                assert_eq!(e, CalibrationError::Degenerate);
                assert!(off < 2.9, "{:.2}°: Degenerate", k as f64 * 0.05);
                degenerate += 1;
            }
        }
    }
    println!("stepwise over 7 200 rolls: {ok} Ok, {degenerate} Degenerate; largest error {worst:.2} of the allowed");
    assert!(ok > 6000, "{ok}");
}

/// An adversarial review: `calibrate_jointly` started from negative focal
/// lengths returned them (the same camera with the roll turned by π); now
/// the result has them positive and the roll turned.
#[test]
fn joint_calibration_gives_positive_focal_lengths() {
    let cam = TrueCamera::default();
    let mut rng = host_tests::synth::Rng(7);
    let sets: Vec<Vec<Flow>> = paper_motions()
        .iter()
        .map(|&t| host_tests::calib::flows(&cam, t, 50, 0.0, &mut rng))
        .collect();
    let views = host_tests::calib::motion_flows(&paper_motions(), &sets);
    let positive = Intrinsics {
        cx: cam.cx as f32,
        cy: cam.cy as f32,
        roll: cam.roll as f32,
        fx: cam.fx as f32,
        fy: cam.fy as f32,
    };
    let mirrored = Intrinsics {
        roll: positive.roll + std::f32::consts::PI,
        fx: -positive.fx,
        fy: -positive.fy,
        ..positive
    };
    let a = calibrate_jointly::<512>(&views, &positive).expect("converges");
    let b = calibrate_jointly::<512>(&views, &mirrored).expect("converges");
    for k in [a.intrinsics, b.intrinsics] {
        assert!(k.fx > 0.0 && k.fy > 0.0, "{k:?}");
        let e = Errors::of(&k, &cam);
        assert!(e.within_issue_tolerances(), "{k:?}");
    }
}

/// The step-by-step fit's sensitivity for cameras whose pixels are far
/// from square: an FOE error of `δ` along the diagonals moves `r² =
/// (f_x/f_y)²` by about `√2 δ (1/f_x + 1/f_y)/|cos 2γ|` of itself, and
/// an error of length `δ` in any direction by at most `√2` times that
/// (`calibrate_stepwise`'s docs; at `f_x = f_y` the diagonal form is the
/// paper-like `4δ/(L |cos 2γ|)`). An adversarial review (thirtieth
/// session) found the older `4δ/(L |cos 2γ|)` 3.9 times short at `f =
/// (100, 1 000)`, roll 0, with `δ = 0.5` px: the error of `d_x` scales
/// with `f_x`, not with `L`; a reviewer then found errors along the axes
/// 1.29 times past the diagonal form. For aspects from 1/10 to 10 and
/// rolls away from 45° + k·90°: every sign pattern of `±δ/√2` on the ten
/// coordinates of the five FOEs (exact in `f64`, then `f32`) within 1.02
/// times the diagonal form, and every choice of eight directions of
/// length `δ` for each FOE within 1.02 times the general one; both forms
/// reached to within 0.9 somewhere.
#[test]
fn stepwise_sensitivity_for_any_aspect() {
    let (cx, cy, delta) = (500.0f64, 500.0f64, 0.5f64);
    let (mut worst_diag, mut worst_any, mut old_short) = (0.0f64, 0.0f64, 0.0f64);
    for (fx, fy) in [
        (100.0, 1000.0),
        (1000.0, 100.0),
        (300.0, 1200.0),
        (800.0, 800.0),
        (400.0, 200.0),
    ] {
        for deg in [0.0f64, 20.0, 93.0, 130.0, 200.0] {
            let g = deg.to_radians();
            let foe = |tx: f64, ty: f64| {
                let (s, c) = g.sin_cos();
                let (x, y) = (c * tx + s * ty, -s * tx + c * ty);
                [cx + fx * x, cy + fy * y]
            };
            let exact = [
                foe(0.0, 0.0),
                foe(1.0, 1.0),
                foe(-1.0, 1.0),
                foe(-1.0, -1.0),
                foe(1.0, -1.0),
            ];
            let diag = 2f64.sqrt() * delta * (1.0 / fx + 1.0 / fy) / (2.0 * g).cos().abs();
            let any = 2f64.sqrt() * diag;
            let old = 4.0 * delta / (fx.hypot(fy) * (2.0 * g).cos().abs());
            let error = |p: [[f64; 2]; 5]| {
                let px = p.map(|q| Pixel::new(q[0] as f32, q[1] as f32));
                let k =
                    calibrate_stepwise(px[0], [px[1], px[2], px[3], px[4]]).expect("calibrates");
                let r2 = (f64::from(k.fx) / f64::from(k.fy)).powi(2);
                (r2 / (fx / fy).powi(2) - 1.0).abs()
            };
            let (mut d, mut a) = (0.0f64, 0.0f64);
            for pattern in 0u32..1024 {
                let mut p = exact;
                for k in 0..10 {
                    let s = if pattern >> k & 1 == 1 { 1.0 } else { -1.0 };
                    p[k / 2][k % 2] += s * delta / 2f64.sqrt();
                }
                d = d.max(error(p));
            }
            for pattern in 0u32..32_768 {
                let mut p = exact;
                for (j, q) in p.iter_mut().enumerate() {
                    let t = f64::from(pattern >> (3 * j) & 7) * core::f64::consts::FRAC_PI_4;
                    q[0] += delta * t.cos();
                    q[1] += delta * t.sin();
                }
                a = a.max(error(p));
            }
            assert!(
                d <= 1.02 * diag,
                "f ({fx}, {fy}), {deg}°: {d:e} against {diag:e}"
            );
            assert!(
                a <= 1.02 * any,
                "f ({fx}, {fy}), {deg}°: {a:e} against {any:e}"
            );
            worst_diag = worst_diag.max(d / diag);
            worst_any = worst_any.max(a / any);
            old_short = old_short.max(d / old);
        }
    }
    println!(
        "stepwise sensitivity: diagonal errors {worst_diag:.3} of their form, any direction {worst_any:.3} of theirs; {old_short:.2} of the old form"
    );
    assert!(
        worst_diag > 0.9 && worst_any > 0.9,
        "{worst_diag} {worst_any}"
    );
    assert!(old_short > 3.0, "{old_short}");
}

/// Exact flows (rounded to `f32` only) of `n` feature points at depths
/// 8–40 for the translation `t`: anywhere in the image, or with `line`
/// on the image line from the motion's FOE towards that pixel (from the
/// FOE to 1.5 times as far), which fixes the FOE in one direction only.
fn exact_flows(
    cam: &TrueCamera,
    t: [f64; 3],
    n: usize,
    line: Option<[f64; 2]>,
    rng: &mut host_tests::synth::Rng,
) -> Vec<Flow> {
    let foe = cam.foe(t);
    let mut out = Vec::new();
    for _ in 0..1000 * n {
        if out.len() == n {
            break;
        }
        let uv = match line {
            None => [
                rng.uniform(0.0, cam.width - 1.0),
                rng.uniform(0.0, cam.height - 1.0),
            ],
            Some(d) => {
                let s = rng.uniform(0.0, 1.5);
                [foe[0] + s * (d[0] - foe[0]), foe[1] + s * (d[1] - foe[1])]
            }
        };
        if !(0.0..cam.width).contains(&uv[0]) || !(0.0..cam.height).contains(&uv[1]) {
            continue;
        }
        let p = cam.unproject(uv, rng.uniform(8.0, 40.0));
        let Some(q) = cam.project([p[0] - t[0], p[1] - t[1], p[2] - t[2]]) else {
            continue;
        };
        let (from, to) = (
            Pixel::new(uv[0] as f32, uv[1] as f32),
            Pixel::new(q[0] as f32, q[1] as f32),
        );
        if from != to {
            out.push(Flow { from, to });
        }
    }
    out
}

/// Motions that cannot determine the five parameters are `Degenerate`,
/// not `Ok` (an adversary's find: two motions, or translations whose
/// points `(t_x, t_y)/t_z` lie on one line, gave `Ok` up to 109 px off
/// with standard deviations of a tenth of a pixel, with exact flows;
/// the model's FOE is affine in that point, so points on a line fix four
/// numbers at most). Its reproducer, then 100 seeds of each such set with
/// exact and with pixel-grid flows, starts up to 5 px and 5 % off: never
/// `Ok`. The paper's five motions, and its four diagonals alone, still
/// calibrate on every seed.
#[test]
fn joint_fits_the_motions_cannot_determine_are_degenerate() {
    let f = |a: (f32, f32), b: (f32, f32)| Flow {
        from: Pixel::new(a.0, a.1),
        to: Pixel::new(b.0, b.1),
    };
    let a = [
        f((215.84883, 472.69995), (246.24307, 468.56583)),
        f((381.42697, 129.18909), (439.3894, 90.53855)),
        f((167.97089, 400.01654), (252.01611, 371.57358)),
    ];
    let b = [
        f((413.6136, 358.26776), (405.017, 402.50632)),
        f((166.27502, 49.4977), (138.36786, 70.89983)),
        f((371.61914, 254.50679), (357.18472, 299.15607)),
    ];
    let motions = [
        MotionFlows {
            translation: [-2.0, 1.0, 2.5],
            flows: &a,
        },
        MotionFlows {
            translation: [1.0, -1.5, 2.5],
            flows: &b,
        },
    ];
    let start = Intrinsics {
        cx: 273.59,
        cy: 233.96,
        roll: 0.0,
        fx: 614.5,
        fy: 780.7,
    };
    assert_eq!(
        calibrate_jointly::<8>(&motions, &start),
        Err(CalibrationError::Degenerate)
    );
    let cam = TrueCamera::default();
    let sets: [(&str, Vec<[f64; 3]>, bool); 6] = [
        (
            "two motions",
            vec![[-2.0, 1.0, 2.5], [1.0, -1.5, 2.5]],
            false,
        ),
        (
            "straight and one diagonal",
            vec![[0.0, 0.0, 4.0], [2.5, 2.5, 2.5]],
            false,
        ),
        (
            "five along x",
            (0..5).map(|i| [f64::from(i) - 2.0, 0.0, 2.5]).collect(),
            false,
        ),
        (
            "five on a line not through c",
            (0..5).map(|i| [f64::from(i) - 2.0, 1.0, 2.5]).collect(),
            false,
        ),
        ("the paper's five", paper_motions(), true),
        ("the paper's diagonals", paper_motions()[1..].to_vec(), true),
    ];
    let mut refused = 0;
    for (name, ts, determined) in &sets {
        for grid in [false, true] {
            for seed in 0..100u64 {
                let mut rng = host_tests::synth::Rng(seed);
                let flow_sets: Vec<Vec<Flow>> = ts
                    .iter()
                    .map(|&t| {
                        if grid {
                            host_tests::calib::flows(&cam, t, 50, 0.0, &mut rng)
                        } else {
                            exact_flows(&cam, t, 50, None, &mut rng)
                        }
                    })
                    .collect();
                let mf = host_tests::calib::motion_flows(ts, &flow_sets);
                let s = |lo: f64, hi: f64, rng: &mut host_tests::synth::Rng| rng.uniform(lo, hi);
                let start = Intrinsics {
                    cx: (cam.cx + s(-5.0, 5.0, &mut rng)) as f32,
                    cy: (cam.cy + s(-5.0, 5.0, &mut rng)) as f32,
                    roll: (cam.roll + s(-0.02, 0.02, &mut rng)) as f32,
                    fx: (cam.fx * s(0.95, 1.05, &mut rng)) as f32,
                    fy: (cam.fy * s(0.95, 1.05, &mut rng)) as f32,
                };
                let r = calibrate_jointly::<64>(&mf, &start);
                if *determined {
                    let j = r.unwrap_or_else(|e| panic!("{name}, grid {grid}, seed {seed}: {e:?}"));
                    let e = Errors::of(&j.intrinsics, &cam);
                    assert!(e.c < 1.5, "{name}, grid {grid}, seed {seed}: c off {}", e.c);
                } else {
                    assert_eq!(
                        r.map(|j| j.intrinsics),
                        Err(CalibrationError::Degenerate),
                        "{name}, grid {grid}, seed {seed}"
                    );
                    refused += 1;
                }
            }
        }
    }
    assert_eq!(refused, 800);
}

/// Motions whose translations spread well but whose flows do not fix
/// their FOEs: in two of three motions every feature point lies on one
/// image line through the motion's FOE, which then fixes that FOE in one
/// direction only (2 + 1 + 1 numbers for 5 parameters). The translations'
/// spread cannot see it; the normal equations' conditioning refuses it
/// (`Degenerate`) on every seed and start (a review's case; with twelve
/// thousand flows a motion, measured and not kept here for its time, its
/// pivot reached the threshold until the sums were compensated).
#[test]
fn joint_fits_whose_flows_fix_foes_in_one_direction_are_degenerate() {
    let cam = TrueCamera::default();
    let ts = [[0.0, 0.0, 2.5], [2.5, 2.5, 2.5], [-2.5, 2.5, 2.5]];
    let toward = [None, Some([200.0, 250.0]), Some([300.0, 200.0])];
    for seed in 0..20u64 {
        let mut rng = host_tests::synth::Rng(seed);
        let sets: Vec<Vec<Flow>> = ts
            .iter()
            .zip(&toward)
            .map(|(&t, &line)| exact_flows(&cam, t, 200, line, &mut rng))
            .collect();
        assert!(sets.iter().all(|s| s.len() == 200), "seed {seed}");
        let mf = host_tests::calib::motion_flows(&ts, &sets);
        for k in [0.9f32, 1.0, 1.1] {
            let start = Intrinsics {
                cx: cam.cx as f32 + 3.0,
                cy: cam.cy as f32 - 2.0,
                roll: cam.roll as f32,
                fx: cam.fx as f32 * k,
                fy: cam.fy as f32 * k,
            };
            assert_eq!(
                calibrate_jointly::<256>(&mf, &start).map(|j| j.intrinsics),
                Err(CalibrationError::Degenerate),
                "seed {seed}, start f × {k}"
            );
        }
    }
}
