//! A reported frame-2 match lies on the frame-2 polyline within `2⁻¹⁶ S`
//! pixels, `S` the largest coordinate magnitude among the match, the
//! compensated frame-1 point and the FOE (README, "Using the library"):
//! the match is the exact epipolar line's point at its crossing, computed
//! in `f32` from those points. The fuzz target checks every match of every
//! case (`host_tests/src/fuzz/frame.rs`, `check_on_polyline`); this is the
//! case an adversarial review found farthest off, on a 957 × 12 174 image.

use roadstereo::{Camera, Config, Frame, Motion, PairGeometry, Pixel, Processor, Step};

fn distance(q: Pixel, poly: &[Pixel]) -> f64 {
    let (qu, qv) = (f64::from(q.u), f64::from(q.v));
    poly.windows(2)
        .map(|w| {
            let (au, av) = (f64::from(w[0].u), f64::from(w[0].v));
            let (du, dv) = (f64::from(w[1].u) - au, f64::from(w[1].v) - av);
            let t = (((qu - au) * du + (qv - av) * dv) / (du * du + dv * dv)).clamp(0.0, 1.0);
            (qu - au - t * du).hypot(qv - av - t * dv)
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn a_match_on_a_tall_image_is_on_the_polyline_within_the_tolerance() {
    let cam = Camera::new(3401.9893, 2740.811, 358.85785, 0.0, 957, 12174).expect("camera");
    let config = Config::new(0.0, 0.0, 0.5494494, 85656.1).expect("config");
    let m = Motion::new(
        [-0.5699535, 0.13673073, 0.114157714],
        [0.00020717262, 0.000261925, 0.0003370098],
    )
    .expect("motion");
    let p1 = [
        Pixel::new(735.4471, 2020.6742),
        Pixel::new(740.31415, 2046.5731),
    ];
    let p2 = [
        Pixel::new(734.63385, 2001.6735),
        Pixel::new(739.46594, 2027.3148),
        Pixel::new(744.02155, 2051.976),
    ];
    let mut f1 = Frame::<8, 1>::new(cam);
    f1.push_boundary(&p1).expect("frame 1");
    let mut f2 = Frame::<8, 1>::new(cam);
    f2.push_boundary(&p2).expect("frame 2");
    let mut p = Processor::<8, 1>::new(config);
    assert!(matches!(p.process(&f1, None), Ok(Step::First)));
    let Ok(Step::Structure(s)) = p.process(&f2, Some(&m)) else {
        panic!("no structure");
    };
    let g = PairGeometry::new(&cam, &cam, &m);
    let foe = g.focus_of_expansion().expect("a finite FOE");
    let mut matched = 0;
    for r in s.boundaries()[0].points() {
        let Some(q) = r.pixel2() else { continue };
        matched += 1;
        let c = g.compensate(r.pixel1()).expect("compensated").pixel();
        let scale = [q.u, q.v, c.u, c.v, foe.u, foe.v]
            .iter()
            .fold(1.0f64, |s, x| s.max(f64::from(x.abs())));
        let d = distance(q, &p2);
        println!(
            "match {q:?}: {d:e} px off the polyline, S = {scale}, d/S = {:e}",
            d / scale
        );
        assert!(d <= scale / 65_536.0, "{d} px off, S = {scale}");
    }
    assert_eq!(matched, 2);
}
