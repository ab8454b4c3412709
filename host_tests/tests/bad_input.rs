//! Every kind of bad input gets a typed error or a flag, and the kept state
//! is untouched: the next good frame gives exactly the result it would have
//! given had the bad input never come.

use host_tests::{frame, scenarios, synth, B, N};
use roadstereo::{
    BoundaryError, Camera, CameraError, Config, Frame, Motion, MotionError, Pixel, ProcessError,
    Processor, Status, Step,
};

struct Good {
    cam: Camera,
    f1: Frame<N, B>,
    f2: Frame<N, B>,
    m: Motion,
}

fn good() -> Good {
    let s = scenarios::named().remove(0);
    let r = s.render();
    let cam = s.intrinsics.camera();
    Good {
        cam,
        f1: frame(cam, &synth::Rendered::pixels(&r.frame1, true)),
        f2: frame(cam, &synth::Rendered::pixels(&r.frame2, true)),
        m: r.motion(),
    }
}

fn line(n: usize) -> Vec<Pixel> {
    (0..n)
        .map(|i| Pixel::new(100.0 + i as f32 * 0.3, 470.0 - i as f32))
        .collect()
}

/// What a bad input does: the error it gets. It may touch the processor
/// (only through its public API) and a frame under construction.
type Case = (&'static str, fn(&Good, &mut Processor<N, B>) -> String);

fn boundary_err(points: Vec<Pixel>, cam: Camera) -> String {
    let mut f = Frame::<N, B>::new(cam);
    let before = f.clone();
    let e = f.push_boundary(&points).expect_err("must be rejected");
    assert_eq!(f, before, "a rejected boundary leaves the frame as it was");
    format!("{e:?}")
}

fn cases() -> Vec<Case> {
    vec![
        ("NaN in a point", |g, _| {
            let mut p = line(10);
            p[3].u = f32::NAN;
            let e = boundary_err(p, g.cam);
            assert_eq!(e, format!("{:?}", BoundaryError::NotFinite { index: 3 }));
            e
        }),
        ("infinity in a point", |g, _| {
            let mut p = line(10);
            p[5].v = f32::INFINITY;
            let e = boundary_err(p, g.cam);
            assert_eq!(e, format!("{:?}", BoundaryError::NotFinite { index: 5 }));
            e
        }),
        ("point outside the image", |g, _| {
            let mut p = line(10);
            p[2].u = -5.0;
            let e = boundary_err(p, g.cam);
            assert_eq!(e, format!("{:?}", BoundaryError::OutsideImage { index: 2 }));
            e
        }),
        ("more points than the capacity", |g, _| {
            let p: Vec<Pixel> = (0..N + 1)
                .map(|i| Pixel::new(10.0 + i as f32 * 0.5, 479.0 - i as f32 * 0.5))
                .collect();
            let e = boundary_err(p, g.cam);
            assert_eq!(
                e,
                format!(
                    "{:?}",
                    BoundaryError::TooManyPoints {
                        len: N + 1,
                        capacity: N
                    }
                )
            );
            e
        }),
        ("fewer than two points", |g, _| {
            let e = boundary_err(line(1), g.cam);
            assert_eq!(e, format!("{:?}", BoundaryError::TooFewPoints));
            e
        }),
        ("unordered polyline", |g, _| {
            let mut p = line(10);
            p.swap(4, 6);
            let e = boundary_err(p, g.cam);
            assert_eq!(e, format!("{:?}", BoundaryError::Unordered { index: 5 }));
            e
        }),
        ("zig-zag polyline", |g, _| {
            let p = vec![
                Pixel::new(10.0, 400.0),
                Pixel::new(12.0, 390.0),
                Pixel::new(14.0, 395.0),
            ];
            let e = boundary_err(p, g.cam);
            assert_eq!(e, format!("{:?}", BoundaryError::Unordered { index: 2 }));
            e
        }),
        ("repeated row", |g, _| {
            let p = vec![Pixel::new(10.0, 400.0), Pixel::new(12.0, 400.0)];
            let e = boundary_err(p, g.cam);
            assert_eq!(e, format!("{:?}", BoundaryError::Unordered { index: 1 }));
            e
        }),
        ("duplicate points", |g, _| {
            let mut p = line(10);
            p[7] = p[6];
            let e = boundary_err(p, g.cam);
            assert_eq!(e, format!("{:?}", BoundaryError::Duplicate { index: 7 }));
            e
        }),
        ("too many boundaries", |g, _| {
            let mut f = g.f2.clone();
            let before = f.clone();
            let e = f.push_boundary(&line(5)).expect_err("frame is full");
            assert_eq!(f, before);
            assert_eq!(e, BoundaryError::TooManyBoundaries);
            format!("{e:?}")
        }),
        ("NaN in the motion", |_, _| {
            let e = Motion::new([0.0, f32::NAN, 0.4], [0.0; 3]).expect_err("rejected");
            assert_eq!(e, MotionError::NotFinite);
            format!("{e:?}")
        }),
        ("infinity in the rotation", |_, _| {
            let e = Motion::new([0.0, 0.0, 0.4], [0.0, f32::NEG_INFINITY, 0.0]).expect_err("x");
            assert_eq!(e, MotionError::NotFinite);
            format!("{e:?}")
        }),
        ("U = V = W = 0", |_, _| {
            let e = Motion::new([0.0; 3], [0.0, 0.1, 0.0]).expect_err("rejected");
            assert_eq!(e, MotionError::ZeroTranslation);
            format!("{e:?}")
        }),
        ("NaN in the camera", |_, _| {
            let e = Camera::new(800.0, f32::NAN, 255.5, 239.5, 512, 480).expect_err("x");
            assert_eq!(e, CameraError::NotFinite);
            format!("{e:?}")
        }),
        ("zero focal length", |_, _| {
            let e = Camera::new(0.0, 800.0, 255.5, 239.5, 512, 480).expect_err("x");
            assert_eq!(e, CameraError::FocalLength);
            format!("{e:?}")
        }),
        ("frame without motion", |g, p| {
            let e = p.process(&g.f1, None).expect_err("motion is required");
            assert_eq!(e, ProcessError::MissingMotion);
            format!("{e:?}")
        }),
    ]
}

/// Reference: frames 1 and 2 with nothing in between.
fn reference(g: &Good) -> Box<Processor<N, B>> {
    let mut p = Box::new(Processor::new(Config::default()));
    assert!(matches!(p.process(&g.f1, None), Ok(Step::First)));
    assert!(matches!(
        p.process(&g.f2, Some(&g.m)),
        Ok(Step::Structure(_))
    ));
    p
}

#[test]
fn each_bad_input_gets_a_typed_error_and_leaves_the_state_untouched() {
    let g = good();
    let want = reference(&g);
    for (name, case) in cases() {
        let mut p = Box::new(Processor::<N, B>::new(Config::default()));
        assert!(matches!(p.process(&g.f1, None), Ok(Step::First)));
        let kept = p.previous().cloned();
        let err = case(&g, &mut p);
        println!("{name:32} -> {err}");
        assert_eq!(p.previous().cloned(), kept, "{name}: kept frame changed");
        assert!(matches!(
            p.process(&g.f2, Some(&g.m)),
            Ok(Step::Structure(_))
        ));
        assert_eq!(p.structure(), want.structure(), "{name}: result differs");
    }
}

#[test]
fn no_previous_frame_is_reported() {
    let g = good();
    let mut p = Box::new(Processor::<N, B>::new(Config::default()));
    // Even with a motion, the first frame only starts the sequence.
    assert!(matches!(p.process(&g.f2, Some(&g.m)), Ok(Step::First)));
    assert_eq!(p.previous(), Some(&g.f2));
    p.reset();
    assert_eq!(p.previous(), None);
    // A key-frame reconstruction needs a kept frame.
    let e = p
        .process_against_kept(&g.f2, &g.m)
        .expect_err("no kept frame");
    assert_eq!(e, ProcessError::NoKeptFrame);
    assert_eq!(p.previous(), None);
}

/// A key-frame reconstruction keeps the key frame (the next frame is
/// paired with it again) and gives the same structure each time: the
/// reference matcher's on frame 2's boundaries as given (the ordinary call
/// thins them, `roadstereo::thin`, and so may differ from it by a little
/// more than the thinning's `ε` in its sticks). Every point with a stick
/// in both has overlapping sticks, and most points have one.
#[test]
fn key_frame_is_kept() {
    let g = good();
    let ordinary = reference(&g);
    let mut want = Box::new(Processor::<N, B>::new(Config::default()));
    assert!(matches!(want.process(&g.f1, None), Ok(Step::First)));
    let want = want
        .reference_against_kept(&g.f2, &g.m)
        .expect("kept")
        .clone();
    let mut p = Box::new(Processor::<N, B>::new(Config::default()));
    assert!(matches!(p.process(&g.f1, None), Ok(Step::First)));
    for _ in 0..2 {
        let s = p.process_against_kept(&g.f2, &g.m).expect("structure");
        assert_eq!(s, &want);
        assert_eq!(p.previous(), Some(&g.f1));
    }
    let (mut both, mut points) = (0, 0);
    for (x, y) in want
        .boundaries()
        .iter()
        .zip(ordinary.structure().boundaries())
    {
        for (a, b) in x.points().iter().zip(y.points()) {
            points += 1;
            if let (Some(da), Some(db)) = (a.interval(), b.interval()) {
                both += 1;
                assert!(
                    da.z_near <= db.z_far && db.z_near <= da.z_far,
                    "{a:?} {b:?}"
                );
            }
        }
    }
    assert!(both * 10 >= points * 3, "{both} of {points}");
}

/// A point at the focus of expansion has no disparity: flagged, and the
/// other points of the frame are processed normally.
#[test]
fn point_at_the_focus_of_expansion_is_flagged() {
    let cam = Camera::new(800.0, 800.0, 256.0, 240.0, 512, 480).expect("camera");
    let m = Motion::new([0.0, 0.0, 0.5], [0.0; 3]).expect("motion");
    // Frame 1: a boundary through the principal point = the FOE.
    let b1 = [
        Pixel::new(256.0, 240.0),
        Pixel::new(240.0, 300.0),
        Pixel::new(220.0, 380.0),
    ];
    // Frame 2: the same ground line after moving forward, crossing it.
    let b2 = [Pixel::new(300.0, 230.0), Pixel::new(150.0, 470.0)];
    let mut p = Box::new(Processor::<N, B>::new(Config::default()));
    let mut f1 = Frame::new(cam);
    f1.push_boundary(&b1).expect("valid");
    let mut f2 = Frame::new(cam);
    f2.push_boundary(&b2).expect("valid");
    assert!(matches!(p.process(&f1, None), Ok(Step::First)));
    let Ok(Step::Structure(s)) = p.process(&f2, Some(&m)) else {
        panic!("expected a structure")
    };
    let pts = s.boundaries()[0].points();
    assert_eq!(pts[0].status(), Status::AtFoe);
    assert_eq!(pts[0].depth(), None);
    assert!(pts[1..].iter().all(|r| r.status() != Status::AtFoe));
}

/// The epipolar segment toward the FOE (W < 0) and the half-line away from
/// it (W > 0): a frame-2 boundary on the wrong side gives no intersection.
#[test]
fn search_range_follows_the_sign_of_w() {
    let cam = Camera::new(800.0, 800.0, 256.0, 240.0, 512, 480).expect("camera");
    // A line the rays from the FOE (the principal point) cross at 60-80°.
    let b1 = [Pixel::new(150.0, 400.0), Pixel::new(250.0, 380.0)];
    // Frame 1's line scaled by 1.3 away from the FOE, extended by a fifth
    // of its length at either end: outward of frame 1, where forward
    // motion moves it.
    let outward = [Pixel::new(92.2, 453.2), Pixel::new(274.2, 416.8)];
    for (w, want_match) in [(0.5f32, true), (-0.5, false)] {
        let m = Motion::new([0.0, 0.0, w], [0.0; 3]).expect("motion");
        let mut p = Box::new(Processor::<N, B>::new(Config::default()));
        let mut f1 = Frame::new(cam);
        f1.push_boundary(&b1).expect("valid");
        let mut f2 = Frame::new(cam);
        f2.push_boundary(&outward).expect("valid");
        assert!(matches!(p.process(&f1, None), Ok(Step::First)));
        let Ok(Step::Structure(s)) = p.process(&f2, Some(&m)) else {
            panic!("expected a structure")
        };
        for r in s.boundaries()[0].points() {
            assert_eq!(r.pixel2().is_some(), want_match, "W = {w}: {r:?}");
        }
    }
}
