//! Road geometry (camera height, tilt, road width) from the fused map.

use super::*;

/// The ALV-like set-up of `tests/geometry.rs` (camera height 2, tilt 23°,
/// road width 2.6, the r = 40 curve, 1 unit of travel a frame, quantised)
/// as a drive with lateral and heading wobble, no pitch.
fn alv_drive(frames: usize, seed: u64) -> Drive {
    let mut s = DriveSpec::new(DriveFamily::Fig6, seed, frames);
    s.name = format!("alv/{seed}");
    s.road = Road {
        curvature_a: 1.0 / 40.0,
        curvature_b: 1.0 / 40.0,
        ..Road::straight(2.6)
    };
    s.height = 2.0;
    s.tilt = 23f64.to_radians();
    s.step = 1.0;
    s.yaw_bias = 1.5 / 40.0;
    s.yaw_wobble = 1.5f64.to_radians();
    s.lateral_wobble = 0.2;
    // The same mounting in every view (road_geometry's model): no pitch.
    s.pitch_wobble = 0.0;
    s.render().expect("both edges in view")
}

/// Camera height, tilt and road width (`geometry::road_geometry`) from the
/// fused map: one view per retired key frame in the map (its fused
/// intervals on its own rays). Next to the figures of the 12 two-view
/// pairs of `tests/geometry.rs` (0.15, 0.7°, 0.08) and the paper's (0.40,
/// 4°, 0.60).
#[test]
fn road_geometry_from_the_fused_map() {
    use roadstereo::geometry::{road_geometry, Sample};
    const CAP: usize = 4096;
    let mut lines = vec![
        "| views | height | tilt | width |".to_string(),
        "|---|---|---|---|".to_string(),
        "| paper (ALV board) | 1.9–2.3 (0.40) | 20–24° (4°) | 2.4–3.0 (0.60) |".to_string(),
        "| 12 two-view pairs (`tests/geometry.rs`) | 1.93–2.08 (0.15) | 22.6–23.4° (0.7°) | 2.56–2.64 (0.08) |".to_string(),
    ];
    for (partners, frames) in [(4u16, 25usize), (8, 25)] {
        let d = alv_drive(frames, 1);
        let input = d.input(Noise::Rounded, None, 1);
        let cam = d.spec.intrinsics.camera();
        let policy = FusionConfig::new(partners, 500)
            .and_then(|p| p.with_tilt(23f32.to_radians()))
            .expect("policy");
        // (a) The map at the end of the drive: what is still ahead.
        let mut map_sets: Vec<(Vec<Sample>, Vec<Sample>)> = Vec::new();
        // (b) Each key frame's fused points as it retires (also those the
        // vehicle has passed since, which the map drops).
        let mut key_sets: Vec<(Vec<Sample>, Vec<Sample>)> = Vec::new();
        let r = run(&d, &input, policy, |j, _, f| {
            if let Some(key) = f.key() {
                let kid = key.id() as usize;
                if key.partners() >= partners {
                    let side = |b: usize| -> Vec<Sample> {
                        key.points(b)
                            .enumerate()
                            .filter(|(_, p)| p.status == FusedStatus::Consistent)
                            .filter_map(|(i, p)| {
                                let iv = p.interval?;
                                let [x, y] = cam.normalise(input.frames[kid][b][i]);
                                Some(Sample {
                                    x,
                                    y,
                                    z_near: iv.z_near,
                                    z_far: iv.z_far,
                                })
                            })
                            .collect()
                    };
                    let (l, r) = (side(0), side(1));
                    if l.len() >= 10 && r.len() >= 10 && key_sets.len() < 16 {
                        key_sets.push((l, r));
                    }
                }
            }
            if j + 1 < d.frames.len() {
                return;
            }
            let map = f.map();
            for batch in 0..map.batches() {
                let mut v = heapless::Vec::<Sample, N>::new();
                map.samples(batch, 0, &mut v);
                let left = v.to_vec();
                map.samples(batch, 1, &mut v);
                if left.len() >= 10 && v.len() >= 10 {
                    map_sets.push((left, v.to_vec()));
                }
            }
        });
        let _ = r;
        for (what, sets) in [
            ("fused map at the end", &map_sets),
            ("retiring key frames", &key_sets),
        ] {
            let views: Vec<(&[Sample], &[Sample])> = sets
                .iter()
                .map(|(l, r)| (l.as_slice(), r.as_slice()))
                .collect();
            let points: usize = sets.iter().map(|(l, r)| l.len() + r.len()).sum();
            assert!(!views.is_empty(), "{what}");
            let g = road_geometry::<CAP>(&views, 0).expect("geometry");
            let width = g.width.expect("a width");
            let (tl, th) = (g.tilt.lo.to_degrees(), g.tilt.hi.to_degrees());
            lines.push(format!(
                "| {what}: {} key frames of {partners} partners ({points} points) | {:.2}–{:.2} ({:.2}) | {tl:.1}–{th:.1}° ({:.1}°) | {:.2}–{:.2} ({:.2}) |",
                views.len(),
                g.height.lo,
                g.height.hi,
                g.height.width(),
                th - tl,
                width.lo,
                width.hi,
                width.width()
            ));
            assert!(
                g.height.contains(2.0)
                    && g.tilt.contains(23f32.to_radians())
                    && width.contains(2.6),
                "{what}: {g:?}"
            );
            // Under half the paper's ranges.
            assert!(
                g.height.width() <= 0.20 && th - tl <= 2.0 && width.width() <= 0.30,
                "{what}: {g:?}"
            );
        }
    }
    println!("{}", lines.join("\n"));
}
