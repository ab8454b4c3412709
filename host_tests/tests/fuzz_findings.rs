//! Findings of the fuzz pass (issue 15), each as a small regression test.

use roadstereo::{Camera, Config, Frame, Motion, Pixel, Processor, Step};

fn frame<const N: usize>(cam: Camera, bs: &[&[[f32; 2]]]) -> Frame<N, 2> {
    let mut f = Frame::new(cam);
    for b in bs {
        let p: Vec<Pixel> = b.iter().map(|p| Pixel::new(p[0], p[1])).collect();
        f.push_boundary(&p).expect("valid boundary");
    }
    f
}

/// F1 (fixed in `Keying::around`, src/pencil.rs): with a rotation error
/// configured, the indexed search missed a frame-2 segment that the band
/// meets at the end of the boundary (indexed `no_intersection`, reference
/// `boundary_end`). The point lies beyond the FOE's row, and its band is
/// 126° wide: the key range took the wrong side's limit, which holds only
/// for wedges narrower than a right angle to the row. The range now spans
/// the ends of the band's arc in the half-plane: edge directions inside it
/// and the row's directions inside the band.
#[test]
fn f1_indexed_search_misses_a_boundary_end_with_a_rotation_error() {
    let cam = Camera::new(798.17523, 798.17523, 313.77997, 240.62936, 640, 480).unwrap();
    let config = Config::DEFAULT
        .with_rotation_error([0.06487539, 0.0058093923, 0.0052432027])
        .unwrap()
        .with_work_budget(Config::MAX_WORK_PER_POINT)
        .unwrap();
    let f1 = frame::<16>(cam, &[&[[31.0, 121.0], [65.0, 111.0]]]);
    let f2 = frame::<16>(
        cam,
        &[&[
            [627.5, 449.0],
            [628.5, 445.0],
            [627.0, 438.0],
            [627.5, 431.0],
            [627.0, 425.5],
        ]],
    );
    let m = Motion::new([-0.26783878, 0.0361033, 0.34049422], [0.0; 3]).unwrap();
    let mut p = Processor::<16, 2>::new(config);
    assert!(matches!(p.process(&f1, None), Ok(Step::First)));
    let fast = p.process_against_kept(&f2, &m).unwrap().clone();
    let slow = p.reference_against_kept(&f2, &m).unwrap().clone();
    let (a, b) = (fast.boundaries()[0].points(), slow.boundaries()[0].points());
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        println!(
            "point {i}: indexed {}, reference {}",
            x.status(),
            y.status()
        );
    }
    assert_eq!(fast, slow);
}

/// F2 (fixed, src/boundary.rs): a polyline turning back in `v` by steps
/// so small (near `v = 0`) that their product underflows to `-0.0` was
/// accepted: the order check multiplied the steps. It compares signs now.
/// Fuzz seed 428754 (frame): `[.., (4.86, 1e-45), (5, 0), (4.86, 1e-45)]`.
#[test]
fn f2_a_zig_zag_by_tiny_steps_near_row_0_is_rejected() {
    use roadstereo::BoundaryError;
    let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap();
    for (a, b) in [
        (1.0e-45f32, 0.0f32),
        (1.0e-30, -1.0e-30),
        (1.0e-25, -1.0e-25),
    ] {
        let mut f = Frame::<16, 2>::new(cam);
        let before = f.clone();
        let zig = [
            Pixel::new(100.0, 50.0),
            Pixel::new(101.0, a),
            Pixel::new(102.0, b),
            Pixel::new(103.0, a),
        ];
        assert_eq!(
            f.push_boundary(&zig),
            Err(BoundaryError::Unordered { index: 3 }),
            "{a} {b}"
        );
        assert!(f == before);
    }
    // Tiny steps in one direction stay valid.
    let mut f = Frame::<16, 2>::new(cam);
    let ok = [
        Pixel::new(100.0, 1.0e-30),
        Pixel::new(101.0, 1.0e-45),
        Pixel::new(102.0, 0.0),
    ];
    assert_eq!(f.push_boundary(&ok), Ok(()));
}

/// F3 (fixed, src/calibration.rs): `Intrinsics::aspect` of two positive
/// focal lengths returned `Ok(0.0)` when the ratio underflowed (fuzz seed
/// 60327, calibration); it is `Overflow` now, as a ratio that is not
/// finite is.
#[test]
fn f3_an_aspect_ratio_that_underflows_is_an_error() {
    use roadstereo::calibration::{CalibrationError, Intrinsics};
    let k = Intrinsics {
        cx: 256.0,
        cy: 240.0,
        roll: 0.0,
        fx: 1.0e-45,
        fy: 100.0,
    };
    assert_eq!(k.aspect(), Err(CalibrationError::Overflow));
    assert_eq!(
        Intrinsics {
            fx: 1.0e30,
            fy: 1.0e-30,
            ..k
        }
        .aspect(),
        Err(CalibrationError::Overflow)
    );
    assert_eq!(
        Intrinsics {
            fx: 600.0,
            fy: 800.0,
            ..k
        }
        .aspect(),
        Ok(0.75)
    );
}

/// The indexed (largest budget) and reference statuses of a kept boundary
/// `b1` (camera `c1`) against `b2` (camera `c2`) after motion `(t, r)`.
fn pair(
    config: Config,
    c1: Camera,
    c2: Camera,
    b1: &[[f32; 2]],
    b2: &[[f32; 2]],
    (t, r): ([f32; 3], [f32; 3]),
) -> (Vec<roadstereo::PointResult>, Vec<roadstereo::PointResult>) {
    let config = config.with_work_budget(Config::MAX_WORK_PER_POINT).unwrap();
    let f1 = frame::<16>(c1, &[b1]);
    let f2 = frame::<16>(c2, &[b2]);
    let m = Motion::new(t, r).unwrap();
    let mut p = Processor::<16, 2>::new(config);
    assert!(matches!(p.process(&f1, None), Ok(Step::First)));
    let fast = p.process_against_kept(&f2, &m).unwrap().boundaries()[0]
        .points()
        .to_vec();
    let slow = p.reference_against_kept(&f2, &m).unwrap().boundaries()[0]
        .points()
        .to_vec();
    (fast, slow)
}

/// F4a (fixed in `Keying::around`, src/pencil.rs): no motion error, two
/// different cameras: the indexed search missed a depth the reference
/// finds (indexed `no_intersection`; reference `ok`, z = 1.488 at (265.6,
/// 240.6)). The point is 0.9 px from the FOE, where pseudo-angle keys are
/// not given, and its band is still valid (its errors are small): its key
/// range was taken as empty. It is now its own direction's pseudo-angle
/// with the margin `Keying::key` would give it. Fuzz seed 55662, reduced
/// with `fuzz --pair 55662`.
#[test]
fn f4a_indexed_search_misses_a_depth() {
    let c1 = Camera::new(250.94536, 250.94536, -0.0, 136.09424, 256, 256).unwrap();
    let c2 = Camera::new(11.33587, 11.33587, 262.34665, 240.22495, 512, 480).unwrap();
    let config = Config::new(0.25, 0.25, 10.0, 1000.0).unwrap();
    let (fast, slow) = pair(
        config,
        c1,
        c2,
        &[[15.0, 135.0], [96.0, 119.0]],
        &[[266.0, 241.0], [265.0, 240.0]],
        (
            [-0.021163397, -0.0045407945, 1.0596383],
            [0.047869693, -0.029776195, 0.024633728],
        ),
    );
    assert_eq!(fast, slow);
}

/// F4b (fixed with F4a): no motion error, a 1 px focal length: indexed
/// `no_intersection`, reference `grazing` (a point within a pixel of the
/// FOE). Fuzz seed 65892.
#[test]
fn f4b_indexed_search_misses_a_grazing_piece() {
    let c = Camera::new(1.0000001, 1.0000001, 227.42157, 116.37078, 320, 240).unwrap();
    let config = Config::new(0.0, 0.0, 10.0, 1000.0).unwrap();
    let (fast, slow) = pair(
        config,
        c,
        c,
        &[[226.8127, 116.39096], [227.43799, 116.298584]],
        &[[222.0, 117.0], [225.0, 116.5]],
        (
            [-0.14864816, 0.028736841, 1.7132457],
            [0.04524284, 0.04913117, 0.04435491],
        ),
    );
    assert_eq!(fast, slow);
}

/// Issue 11's overflow: a frame-2 boundary that starts exactly at the FOE
/// made `process` add with overflow (`ceil_i32(+inf)`) in a build with
/// overflow checks. This file runs in the `checked` profile, so the test
/// fails on any overflow on that path; the matchers agree there too.
#[test]
fn the_issue_11_overflow_case_runs_with_overflow_checks() {
    let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap();
    let (fast, slow) = pair(
        Config::DEFAULT,
        cam,
        cam,
        &[[100.0, 400.0], [150.0, 300.0]],
        &[[255.5, 239.5], [255.50043, 239.4991]],
        ([0.0, 0.0, 0.4], [0.0; 3]),
    );
    assert_eq!(fast, slow);
    let mut p = Processor::<16, 2>::new(Config::DEFAULT);
    let f1 = frame::<16>(cam, &[&[[100.0, 400.0], [150.0, 300.0]]]);
    let f2 = frame::<16>(cam, &[&[[255.5, 239.5], [255.50043, 239.4991]]]);
    let m = Motion::new([0.0, 0.0, 0.4], [0.0; 3]).unwrap();
    assert!(matches!(p.process(&f1, None), Ok(Step::First)));
    assert!(matches!(p.process(&f2, Some(&m)), Ok(Step::Structure(_))));
}

/// F5 (fixed in `Band::key_half_width`, src/depth.rs): a translation error
/// and a localisation error of 100 px: the band reaches behind the FOE
/// (`ρ₁ ≤ r₁ + e₂`), where the key half-width's `1/(ρ₁ − r₁ − e₂)` turned
/// negative and the query missed the segments (indexed `no_intersection`,
/// reference `boundary_end`). Such a band now searches every key. Fuzz seed
/// 1214507, reduced with `fuzz --pair 1214507`.
#[test]
fn f5_a_band_behind_the_foe_searches_every_key() {
    let c1 = Camera::new(595.0, 609.955, 259.2145, 235.27821, 512, 480).unwrap();
    let c2 = Camera::new(95.70208, 95.70208, 132.48987, 244.57388, 256, 256).unwrap();
    let config = Config::new(100.0, 100.0, 10.0, 1000.0)
        .unwrap()
        .with_translation_error(1.0)
        .unwrap();
    let (fast, slow) = pair(
        config,
        c1,
        c2,
        &[[49.0, 103.0], [15.0, 97.0]],
        &[[150.0, 255.0], [151.0, 256.0]],
        (
            [46769.465, 0.0, 100000.0],
            [-0.0018343587, -0.034090184, 0.010205298],
        ),
    );
    assert_eq!(fast, slow);
}
