//! Frame 2's boundaries thinned (`roadstereo::thin`) against the truth,
//! on an input an adversarial review built to break it: a boundary whose
//! rows at the image's top are subnormals apart, a spike along row 0;
//! moving forwards (the wedge path), backwards (the band path), and
//! forwards under a translation error (the band path).

use roadstereo::{Camera, Config, Frame, Motion, Pixel, Processor, Status, Step};

#[test]
fn a_spike_at_subnormal_row_gaps_survives_the_thinning() {
    // Moving forwards 0.5 (the FOE at the principal point), frame 1's
    // point (260, 120) at depth 1 is (−0.12, −0.24, 1); after moving it
    // projects to (320 − 60/0.5, 240 − 120/0.5) = (200, 0).
    spike_survives(
        [0.0, 0.0, 0.5],
        [Pixel::new(260.0, 120.0), Pixel::new(262.0, 124.0)],
        1.0,
    );
}

/// [`a_spike_at_subnormal_row_gaps_survives_the_thinning`] moving
/// backwards, where every point takes the band path (thinned since the
/// twenty-sixth session): the motion `(0.15, 0.35, −0.5)`, the FOE at
/// (170, −110) above the image, frame 1's point (230, 110) at depth 0.5
/// is `(−0.09, −0.13, 0.5)`, after moving `(−0.24, −0.48, 1)`, seen at
/// (200, 0) on the spike.
#[test]
fn a_spike_at_subnormal_row_gaps_survives_the_thinning_backwards() {
    spike_survives(
        [0.15, 0.35, -0.5],
        [Pixel::new(230.0, 110.0), Pixel::new(232.0, 114.0)],
        0.5,
    );
}

/// [`a_spike_at_subnormal_row_gaps_survives_the_thinning`] with a
/// translation error of 10⁻³ configured, which sends every point to the
/// band path (thinned since the twenty-sixth session): the motion given is
/// the true one, so the truth is the same.
#[test]
fn a_spike_at_subnormal_row_gaps_survives_the_thinning_under_a_translation_error() {
    let config = Config::DEFAULT
        .with_translation_error(1e-3)
        .expect("config");
    spike_survives_with(
        config,
        [0.0, 0.0, 0.5],
        [Pixel::new(260.0, 120.0), Pixel::new(262.0, 124.0)],
        1.0,
    );
}

/// Frame 1's first point, at depth `truth`, is seen after the motion `t`
/// at (200, 0), on the spike the frame-2 boundary makes along row 0 (the
/// rows of its first three vertices a subnormal apart). `process` thins
/// frame 2's boundary; the spike must survive it: the point is flagged,
/// or `ok` with its stick holding `truth` (a review found it `ok` at
/// [1.197, 1.237] for the truth 1 while the thinning's test took `+∞ ≥
/// +∞` and dropped the spike). The same for the kept-frame call, which
/// does not thin.
fn spike_survives(t: [f32; 3], p1: [Pixel; 2], truth: f32) {
    spike_survives_with(Config::DEFAULT, t, p1, truth);
}

/// [`spike_survives`] with `config`.
fn spike_survives_with(config: Config, t: [f32; 3], p1: [Pixel; 2], truth: f32) {
    let sub = f32::from_bits;
    let cam = Camera::new(500.0, 500.0, 320.0, 240.0, 640, 480).expect("camera");
    let m = Motion::new(t, [0.0; 3]).expect("motion");
    let p2 = [
        Pixel::new(0.0, 0.0),
        Pixel::new(400.0, sub(1)),
        Pixel::new(1.0, sub(2)),
        Pixel::new(600.0, 100.0),
    ];
    let mut f1 = Frame::<8, 1>::new(cam);
    f1.push_boundary(&p1).expect("frame 1");
    let mut f2 = Frame::<8, 1>::new(cam);
    f2.push_boundary(&p2).expect("frame 2");
    for kept in [false, true] {
        let mut p = Box::new(Processor::<8, 1>::new(config));
        assert!(matches!(p.process(&f1, None), Ok(Step::First)));
        let s = if kept {
            p.process_against_kept(&f2, &m).expect("kept").clone()
        } else {
            let Ok(Step::Structure(s)) = p.process(&f2, Some(&m)) else {
                panic!("no structure");
            };
            s.clone()
        };
        let r = s.boundaries()[0].points()[0];
        if r.status() == Status::Ok {
            let i = r.interval().expect("a stick");
            assert!(
                i.z_near <= truth * 1.0001 && truth * 0.9999 <= i.z_far,
                "kept {kept}: {r:?}"
            );
        }
        println!("kept {kept}: {r:?}");
    }
}
