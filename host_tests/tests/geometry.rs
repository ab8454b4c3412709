//! Road geometry from the reconstruction (Sec. 4.2.1) on an ALV-like set-up:
//! camera height 2, tilt 23°, road width 2.6, 1 unit of travel between
//! frames, 512 × 480, f = 800, quantised boundaries.

use host_tests::{frame, reconstruct, synth};
use roadstereo::geometry::{road_geometry, samples, Range, RoadGeometry, Sample};
use roadstereo::{Config, Processor, Step};

const N: usize = host_tests::N;

fn alv(curvature: f64, heading_deg: f64) -> synth::Scenario {
    let road = synth::Road {
        width: 2.6,
        curvature_a: curvature,
        curvature_b: curvature,
        heading: heading_deg.to_radians(),
        ..synth::Road::straight(2.6)
    };
    let mut s = synth::Scenario::new(
        "alv",
        road,
        synth::Drive {
            forward: 1.0,
            yaw: curvature * 1.0,
            ..Default::default()
        },
    );
    s.height = 2.0;
    s.tilt = 23f64.to_radians();
    s
}

/// The three ranges as "lo–hi (width)", tilt in degrees.
fn cells(g: &RoadGeometry) -> [String; 3] {
    let cell = |r: &Range, scale: f32, digits: usize| {
        let (lo, hi) = (r.lo * scale, r.hi * scale);
        format!("{lo:.digits$}–{hi:.digits$} ({:.digits$})", hi - lo)
    };
    [
        cell(&g.height, 1.0, 2),
        cell(&g.tilt, 1f32.to_degrees(), 1),
        cell(&g.width, 1.0, 2),
    ]
}

fn boundary_samples(s: &synth::Scenario) -> (Vec<Sample>, Vec<Sample>) {
    let k = s.intrinsics;
    let r = s.render();
    let p = reconstruct(&r, &k, true, Config::default());
    let mut v = heapless::Vec::<Sample, N>::new();
    samples(p.structure(), 0, &mut v);
    let left = v.to_vec();
    samples(p.structure(), 1, &mut v);
    (left, v.to_vec())
}

#[test]
fn alv_geometry_ranges_contain_the_truth() {
    println!("| road | height | tilt (°) | width |");
    println!("|---|---|---|---|");
    println!("| paper (ALV board) | 1.9–2.3 (0.40) | 20–24 (4) | 2.4–3.0 (0.60) |");
    // (A straight road driven straight is degenerate: no depths at all.)
    for (name, k, h) in [
        ("straight, heading 8°", 0.0, 8.0),
        ("curve r = 40", 1.0 / 40.0, 0.0),
        ("curve r = −60", -1.0 / 60.0, 0.0),
    ] {
        let s = alv(k, h);
        let (left, right) = boundary_samples(&s);
        let g0 = road_geometry::<N>(&[(&left, &right)], 0).expect("geometry");
        println!("  (no outlier allowance: height {:.2}–{:.2}, tilt {:.1}–{:.1}, width {:.2}–{:.2}; {} + {} points)", g0.height.lo, g0.height.hi, g0.tilt.lo.to_degrees(), g0.tilt.hi.to_degrees(), g0.width.lo, g0.width.hi, left.len(), right.len());
        let g = road_geometry::<N>(&[(&left, &right)], 3).expect("geometry");
        let tilt_deg = (g.tilt.lo.to_degrees(), g.tilt.hi.to_degrees());
        let [h, t, w] = cells(&g);
        println!("| {name} | {h} | {t} | {w} |");
        assert!(g.height.contains(2.0), "{name}: height {:?}", g.height);
        assert!(
            g.tilt.contains(23f32.to_radians()),
            "{name}: tilt {tilt_deg:?}"
        );
        assert!(g.width.contains(2.6), "{name}: width {:?}", g.width);
        // Not vacuous: a tenth of the value or tighter (the widths are
        // printed next to the paper's above).
        assert!(
            g.height.width() <= 1.0 && g.width.width() <= 0.8,
            "{name}: {g:?}"
        );
        assert!(tilt_deg.1 - tilt_deg.0 <= 8.0, "{name}: tilt range");
    }
}

/// A few wrong matches (points with a wrong, tight stick) do not move the
/// ranges off the truth.
#[test]
fn wrong_matches_are_tolerated() {
    let s = alv(1.0 / 40.0, 0.0);
    let (mut left, right) = boundary_samples(&s);
    for (i, p) in left.iter_mut().enumerate().take(3) {
        p.z_near = 0.5 + i as f32 * 0.1;
        p.z_far = p.z_near * 1.01;
    }
    let g = road_geometry::<N>(&[(&left, &right)], 3).expect("geometry");
    assert!(
        g.height.contains(2.0) && g.tilt.contains(23f32.to_radians()) && g.width.contains(2.6),
        "{g:?}"
    );
    // Without the allowance the same data has no consistent plane near the truth.
    let strict = road_geometry::<N>(&[(&left, &right)], 0);
    assert!(
        strict.map_or(true, |g| !g.height.contains(2.0)),
        "{strict:?}"
    );
}

/// Key frames of a drive on the r = 40 curve, frames 1 unit of travel
/// apart. Each key frame (the vehicle at a different offset and heading on
/// the road, as with steering wobble) is reconstructed against the next 1, 2
/// and 3 frames with [`Processor::process_against_kept`]: longer baselines
/// give larger disparities and tighter sticks. The constraints of all these
/// views together narrow the ranges, which still contain the truth. Without
/// an allowance for wrong matches every range is at most half as wide as
/// the paper's (0.40, 4°, 0.60).
#[test]
fn key_frames_narrow_the_ranges() {
    const CAP: usize = 4096;
    let curvature = 1.0 / 40.0;
    let mut sets = Vec::new();
    for (offset, heading) in [(0.0, 0.0), (-0.3, -2.0), (0.15, -1.0), (-0.15, 1.0)] {
        let cam = synth::Intrinsics::default().camera();
        let mut p = Box::new(Processor::<N, { host_tests::B }>::new(Config::default()));
        let mut key_boundaries = None;
        for travel in [1.0, 2.0, 3.0] {
            let mut s = alv(curvature, heading);
            s.road.centre_offset = offset;
            s.drive.forward = travel;
            s.drive.yaw = curvature * travel;
            let r = s.render();
            let f1 = frame(cam, &synth::Rendered::pixels(&r.frame1, true));
            let f2 = frame(cam, &synth::Rendered::pixels(&r.frame2, true));
            // The key frame is the same image for every travel.
            match &key_boundaries {
                None => {
                    assert!(matches!(p.process(&f1, None), Ok(Step::First)));
                    key_boundaries = Some(f1.boundaries().len());
                }
                Some(n) => assert_eq!(*n, f1.boundaries().len()),
            }
            let st = p
                .process_against_kept(&f2, &r.motion())
                .expect("processing succeeds");
            let mut v = heapless::Vec::<Sample, N>::new();
            samples(st, 0, &mut v);
            let left = v.to_vec();
            samples(st, 1, &mut v);
            sets.push((left, v.to_vec()));
        }
        assert!(p.previous().is_some(), "the key frame is still kept");
    }
    let views: Vec<(&[Sample], &[Sample])> = sets
        .iter()
        .map(|(l, r)| (l.as_slice(), r.as_slice()))
        .collect();
    for outliers in [0usize, 6] {
        let g = road_geometry::<CAP>(&views, outliers).expect("geometry");
        let tilt = (g.tilt.lo.to_degrees(), g.tilt.hi.to_degrees());
        let [h, t, w] = cells(&g);
        println!(
            "{} views (4 key frames × travel 1, 2, 3), {outliers} outliers allowed: height {h}, tilt (°) {t}, width {w}; paper 0.40, 4°, 0.60",
            views.len()
        );
        assert!(
            g.height.contains(2.0) && g.tilt.contains(23f32.to_radians()) && g.width.contains(2.6),
            "{g:?}"
        );
        if outliers == 0 {
            assert!(
                g.height.width() <= 0.20,
                "height range {}",
                g.height.width()
            );
            assert!(tilt.1 - tilt.0 <= 2.0, "tilt range {}", tilt.1 - tilt.0);
            assert!(g.width.width() <= 0.30, "width range {}", g.width.width());
        }
    }
}
