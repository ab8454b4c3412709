//! Render the documentation figures and the replay example:
//! `figures [OUT_DIR]` (default `../docs`) writes
//! * `fig7_sticks.svg`: the paper's Fig. 7 from our code — top and side view
//!   of the reconstructed boundary points of the Fig. 6 set-up (quantised
//!   boundaries), each with its stick, and the true boundary;
//! * `fig_fusion.svg`: the key-frame fusion over a drive of the Fig. 6
//!   set-up — top and side view of the fused intervals every key frame
//!   retired with, the first key frame's single-pair sticks, the road map
//!   at the end and the true boundaries; and the median relative width
//!   against the number of partner frames;
//! * `example.jsonl` / `example_out.jsonl`: a two-frame replay example.

use host_tests::{jsonl, point_stats, reconstruct, scenarios, synth};
use plotters::prelude::*;
use roadstereo::{Config, Processor, Status};

type V3 = [f64; 3];

fn world(pose: &synth::Pose, p: [f32; 3]) -> V3 {
    let c = pose.centre;
    let r = pose.rot;
    let p = p.map(f64::from);
    [0, 1, 2].map(|i| c[i] + r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2])
}

/// The parts of a polyline inside the rectangle `x × y`, each a run of
/// points, the ends where it leaves or enters cut exactly at the edge
/// (Liang–Barsky on each segment), so no line is drawn along an edge.
fn clipped_runs(
    pts: impl IntoIterator<Item = (f64, f64)>,
    x: (f64, f64),
    y: (f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let clip = |a: (f64, f64), b: (f64, f64)| -> Option<((f64, f64), (f64, f64))> {
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        let d = (b.0 - a.0, b.1 - a.1);
        for (p, q) in [
            (-d.0, a.0 - x.0),
            (d.0, x.1 - a.0),
            (-d.1, a.1 - y.0),
            (d.1, y.1 - a.1),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    t0 = t0.max(t);
                } else {
                    t1 = t1.min(t);
                }
            }
        }
        (t0 <= t1).then_some((
            (a.0 + t0 * d.0, a.1 + t0 * d.1),
            (a.0 + t1 * d.0, a.1 + t1 * d.1),
        ))
    };
    let pts: Vec<(f64, f64)> = pts.into_iter().collect();
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for w in pts.windows(2) {
        match clip(w[0], w[1]) {
            Some((a, b)) => {
                if cur.last() != Some(&a) {
                    if cur.len() > 1 {
                        runs.push(std::mem::take(&mut cur));
                    }
                    cur.clear();
                    cur.push(a);
                }
                cur.push(b);
            }
            None => {
                if cur.len() > 1 {
                    runs.push(std::mem::take(&mut cur));
                }
                cur.clear();
            }
        }
    }
    if cur.len() > 1 {
        runs.push(cur);
    }
    runs
}

fn fig7(dir: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    let s = scenarios::named().remove(0); // fig6
    let k = s.intrinsics;
    let r = s.render();
    let p = reconstruct(&r, &k, true, Config::default());
    let st = p.structure();
    let stats = point_stats(&r, &k, &p);
    let path = dir.join("fig7_sticks.svg");
    let root = SVGBackend::new(&path, (1100, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(440);
    let zmax = 12.0;
    // Sticks and points in world coordinates (x right, y down, z forward).
    let mut sticks = Vec::new();
    let mut points = Vec::new();
    for b in st.boundaries() {
        for pr in b.points() {
            if pr.status() != Status::Ok {
                continue;
            }
            if let (Some(pt), Some((n, f))) = (st.point(pr), st.stick(pr)) {
                let (pw, nw, fw) = (world(&r.pose1, pt), world(&r.pose1, n), world(&r.pose1, f));
                if pw[2] < zmax {
                    sticks.push((nw, fw));
                    points.push(pw);
                }
            }
        }
    }
    let truth: Vec<Vec<V3>> = r
        .world
        .iter()
        .map(|c| c.iter().copied().filter(|p| p[2] > 0.0).collect())
        .collect();
    // Top view.
    let mut top = ChartBuilder::on(&left)
        .caption("Top view (Fig. 7): sticks for e = 1 px", ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(-3.0f64..3.0, 0.0f64..zmax)?;
    top.configure_mesh()
        .x_desc("x (right), camera heights")
        .y_desc("forward, camera heights")
        .draw()?;
    let mut labelled = false;
    for c in &truth {
        for run in clipped_runs(c.iter().map(|p| (p[0], p[2])), (-3.0, 3.0), (0.0, zmax)) {
            let s = top.draw_series(LineSeries::new(run, BLUE.mix(0.5)))?;
            if !labelled {
                s.label("true boundaries")
                    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLUE.mix(0.5)));
                labelled = true;
            }
        }
    }
    top.draw_series(
        sticks
            .iter()
            .map(|(n, f)| PathElement::new(vec![(n[0], n[2]), (f[0], f[2])], RED)),
    )?
    .label("sticks (e = 1 px)")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], RED));
    top.draw_series(
        points
            .iter()
            .map(|p| Circle::new((p[0], p[2]), 1, BLACK.filled())),
    )?
    .label("reconstructed points")
    .legend(|(x, y)| Circle::new((x + 9, y), 2, BLACK.filled()));
    top.draw_series(std::iter::once(Circle::new((0.0, 0.0), 6, BLACK)))?
        .label("camera")
        .legend(|(x, y)| Circle::new((x + 9, y), 5, BLACK));
    top.configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    // Side view.
    let mut side = ChartBuilder::on(&right)
        .caption(
            "Side view: height above the start ground vs forward distance",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(0.0f64..zmax, -0.6f64..1.4)?;
    side.configure_mesh()
        .x_desc("forward, camera heights")
        .y_desc("height")
        .draw()?;
    let mut labelled = false;
    for c in &truth {
        for run in clipped_runs(c.iter().map(|p| (p[2], -p[1])), (0.0, zmax), (-0.6, 1.4)) {
            let s = side.draw_series(LineSeries::new(run, BLUE.mix(0.5)))?;
            if !labelled {
                s.label("true boundaries")
                    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLUE.mix(0.5)));
                labelled = true;
            }
        }
    }
    side.draw_series(
        sticks
            .iter()
            .map(|(n, f)| PathElement::new(vec![(n[2], -n[1]), (f[2], -f[1])], RED)),
    )?
    .label("sticks (e = 1 px)")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], RED));
    side.draw_series(
        points
            .iter()
            .map(|p| Circle::new((p[2], -p[1]), 1, BLACK.filled())),
    )?
    .label("reconstructed points")
    .legend(|(x, y)| Circle::new((x + 9, y), 2, BLACK.filled()));
    side.draw_series(std::iter::once(Circle::new(
        (r.pose1.centre[2], -r.pose1.centre[1]),
        6,
        BLACK,
    )))?
    .label("camera")
    .legend(|(x, y)| Circle::new((x + 9, y), 5, BLACK));
    side.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    let ok = stats.iter().filter(|p| p.status == Status::Ok).count();
    let inside = stats
        .iter()
        .filter(|p| p.status == Status::Ok && p.contained())
        .count();
    println!(
        "wrote {} ({ok} points with sticks, {inside} contain the truth)",
        path.display()
    );
    Ok(())
}

fn example(dir: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    // The Fig. 6 set-up, boundaries thinned to every 24th row for reading.
    let s = scenarios::named().remove(0);
    let r = s.render();
    let k = s.intrinsics;
    let thin = |f: &[Vec<synth::TruePoint>]| -> Vec<Vec<[f32; 2]>> {
        f.iter()
            .map(|b| {
                b.iter()
                    .filter(|p| (p.v as i64) % 24 == 0)
                    .map(|p| [p.u.round() as f32, p.v as f32])
                    .collect()
            })
            .collect()
    };
    let camera = jsonl::CameraIn {
        fx: k.fx as f32,
        fy: k.fy as f32,
        cx: k.cx as f32,
        cy: k.cy as f32,
        width: k.width,
        height: k.height,
    };
    let m = r.motion();
    let lines = [
        jsonl::FrameIn {
            camera: camera.clone(),
            motion: None,
            boundaries: thin(&r.frame1),
        },
        jsonl::FrameIn {
            camera,
            motion: Some(jsonl::MotionIn {
                translation: m.translation(),
                rotation: m.angles(),
            }),
            boundaries: thin(&r.frame2),
        },
    ];
    let mut input = String::new();
    let mut output = String::new();
    let mut p = Box::new(Processor::<64, 2>::new(Config::default()));
    for (i, l) in lines.iter().enumerate() {
        let text = serde_json::to_string(l)?;
        let out = jsonl::process_line(&mut p, i + 1, &text);
        input.push_str(&text);
        input.push('\n');
        output.push_str(&serde_json::to_string(&out)?);
        output.push('\n');
    }
    std::fs::write(dir.join("example.jsonl"), input)?;
    std::fs::write(dir.join("example_out.jsonl"), output)?;
    println!("wrote example.jsonl and example_out.jsonl");
    Ok(())
}

/// Fig. 3: disparity vs distance for several tilts (W = 0.1, h = 1,
/// f = 800), with the ground in view of each tilt as a bar below.
fn fig3(dir: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    use roadstereo::analysis::{disparity_tilted, ground_interval};
    let path = dir.join("fig3_disparity_tilt.svg");
    let root = SVGBackend::new(&path, (720, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Fig. 3: disparity d_y vs distance, W = 0.1, h = 1",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0f64..12.0, -8.0f64..60.0)?;
    chart
        .configure_mesh()
        .x_desc("distance along the ground (camera heights)")
        .y_desc("d_y (pixels)")
        .draw()?;
    let half_fov = (240.0f32 / 800.0).atan();
    for (k, (deg, col)) in [(0.0f32, BLACK), (10.0, BLUE), (23.0, RED), (35.0, GREEN)]
        .into_iter()
        .enumerate()
    {
        let t = deg.to_radians();
        let curve = (5..120)
            .map(|i| {
                let z = i as f32 * 0.1;
                disparity_tilted(800.0, 1.0, 0.1, z, t).map(|d| (f64::from(z), f64::from(d)))
            })
            .collect::<Result<Vec<_>, _>>()?;
        chart
            .draw_series(LineSeries::new(curve, col.stroke_width(2)))?
            .label(format!("tilt {deg}°"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col));
        if let Some(roadstereo::geometry::Range { lo: near, hi: far }) =
            ground_interval(1.0, t, half_fov)?
        {
            let y = -1.5 - 1.5 * k as f64;
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(f64::from(near), y), (f64::from(far.min(12.0)), y)],
                col.stroke_width(5),
            )))?;
        }
    }
    chart.configure_series_labels().border_style(BLACK).draw()?;
    root.present()?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Fig. 4: the motion factor F vs n (w = 0.1, tilt 23°) for several Z'.
fn fig4(dir: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    use roadstereo::analysis::motion_factor;
    let path = dir.join("fig4_motion_factor.svg");
    let root = SVGBackend::new(&path, (720, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Fig. 4: F (disparity ratio for motion n·w) vs n, w = 0.1",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(50)
        .build_cartesian_2d(1.0f64..10.0, 0.0f64..25.0)?;
    chart.configure_mesh().x_desc("n").y_desc("F").draw()?;
    let t = 23f32.to_radians();
    for (zp, col) in [(1.5f32, RED), (3.0, BLUE), (6.0, GREEN), (12.0, BLACK)] {
        let curve = (10..=100)
            .map(|i| {
                let n = i as f32 * 0.1;
                motion_factor(n, 0.1, zp, t).map(|f| (f64::from(n), f64::from(f.min(25.0))))
            })
            .collect::<Result<Vec<_>, _>>()?;
        chart
            .draw_series(LineSeries::new(curve, col.stroke_width(2)))?
            .label(format!("Z' = {zp}"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col));
    }
    chart
        .draw_series(LineSeries::new(
            (1..=10).map(|n| (n as f64, n as f64)),
            BLACK.mix(0.3),
        ))?
        .label("F = n")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.3)));
    chart.configure_series_labels().border_style(BLACK).draw()?;
    root.present()?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Fig. A-2: relative depth error from a camera-axis error (1°, 2°, 3°)
/// vs distance, W = 0.25 and 0.5, with the quantisation error (e = 1 px).
fn fig_a2(dir: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    use roadstereo::analysis::{
        disparity_tilted, misalignment_depth_error, quantisation_depth_error,
    };
    let path = dir.join("fig_a2_axis_error.svg");
    let root = SVGBackend::new(&path, (1000, 420)).into_drawing_area();
    root.fill(&WHITE)?;
    let panels = root.split_evenly((1, 2));
    let t = 23f32.to_radians();
    for (area, w) in panels.iter().zip([0.25f32, 0.5]) {
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!("Fig. A-2: relative depth error, W = {w}"),
                ("sans-serif", 16),
            )
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(50)
            .build_cartesian_2d(1.0f64..9.0, 0.0f64..0.12)?;
        chart
            .configure_mesh()
            .x_desc("distance along the ground")
            .y_desc("|ΔZ / Z|")
            .draw()?;
        let zs: Vec<f32> = (0..=80)
            .map(|i| 1.2 + w + i as f32 * 0.1)
            .filter(|z| *z <= 9.0)
            .collect();
        let quantisation = zs
            .iter()
            .map(|&z| {
                let q = quantisation_depth_error(disparity_tilted(800.0, 1.0, w, z, t)?, 1.0);
                Ok((f64::from(z), f64::from(q.min(0.12))))
            })
            .collect::<Result<Vec<_>, roadstereo::AngleError>>()?;
        chart
            .draw_series(AreaSeries::new(quantisation, 0.0, BLACK.mix(0.15)))?
            .label("quantisation, e = 1 px")
            .legend(|(x, y)| {
                Rectangle::new([(x, y - 4), (x + 20, y + 4)], BLACK.mix(0.15).filled())
            });
        for (deg, col) in [(1.0f32, BLUE), (2.0, RED), (3.0, GREEN)] {
            let curve = zs
                .iter()
                .filter_map(|&z| {
                    misalignment_depth_error(800.0, 1.0, t, w, z, deg.to_radians())
                        .map(|e| e.map(|e| (f64::from(z), f64::from(e.min(0.12)))))
                        .transpose()
                })
                .collect::<Result<Vec<_>, _>>()?;
            chart
                .draw_series(LineSeries::new(curve, col.stroke_width(2)))?
                .label(format!("axis error {deg}°"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col));
        }
        chart.configure_series_labels().border_style(BLACK).draw()?;
    }
    root.present()?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Fig. 10: top views of the Fig. 6 reconstruction (vehicle frame) when
/// the robot's translation has an error of ±5 % of the travel in U, V or W
/// (the travel held constant for U and V), the whole pipeline re-run.
fn fig10(dir: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    use roadstereo::analysis::{camera_to_vehicle, vehicle_to_camera};
    use roadstereo::Motion;
    let s = scenarios::named().remove(0);
    let k = s.intrinsics;
    let r = s.render();
    let m = r.motion();
    let tilt = s.tilt as f32;
    let robot = camera_to_vehicle(m.translation(), tilt)?;
    let travel = robot.iter().map(|x| x * x).sum::<f32>().sqrt();
    let top = |mm: &Motion| -> Vec<(f64, f64)> {
        let cam = k.camera();
        let f1 = host_tests::frame(cam, &synth::Rendered::pixels(&r.frame1, true));
        let f2 = host_tests::frame(cam, &synth::Rendered::pixels(&r.frame2, true));
        let mut p = Box::new(Processor::<{ host_tests::N }, { host_tests::B }>::new(
            Config::default(),
        ));
        let _ = p.process(&f1, None);
        let _ = p.process(&f2, Some(mm));
        let st = p.structure();
        st.boundaries()
            .iter()
            .flat_map(|b| b.points().iter())
            .filter(|q| q.status() == Status::Ok)
            .filter_map(|q| st.point(q))
            // The tilt was accepted above, so every call succeeds.
            .filter_map(|pt| camera_to_vehicle(pt, tilt).ok())
            .map(|v| (f64::from(v[0]), f64::from(v[2])))
            .collect()
    };
    let path = dir.join("fig10_translation_error.svg");
    let root = SVGBackend::new(&path, (1200, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let panels = root.split_evenly((1, 3));
    let base = top(&m);
    for (area, (comp, name)) in panels.iter().zip([(0usize, "ΔU"), (1, "ΔV"), (2, "ΔW")]) {
        let mut chart = ChartBuilder::on(area)
            .caption(
                format!("Effect of {name} = ±5 % of the travel"),
                ("sans-serif", 16),
            )
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(40)
            .build_cartesian_2d(-2.0f64..3.0, 0.0f64..12.0)?;
        chart
            .configure_mesh()
            .x_desc("x (right)")
            .y_desc("forward")
            .draw()?;
        for (sign, col, what) in [(1.0f32, RED, "+5 %"), (-1.0, GREEN, "−5 %")] {
            let mut tr = robot;
            tr[comp] += sign * 0.05 * travel;
            if comp < 2 {
                let len = tr.iter().map(|x| x * x).sum::<f32>().sqrt();
                tr = tr.map(|x| x * travel / len);
            }
            let mm = Motion::new(vehicle_to_camera(tr, tilt)?, m.angles())?;
            chart
                .draw_series(top(&mm).into_iter().map(|p| Circle::new(p, 2, col)))?
                .label(format!("{name} {what}"))
                .legend(move |(x, y)| Circle::new((x + 9, y), 3, col));
        }
        chart
            .draw_series(base.iter().map(|&p| Circle::new(p, 1, BLACK.filled())))?
            .label("true motion")
            .legend(|(x, y)| Circle::new((x + 9, y), 2, BLACK.filled()));
        let c0 = r.pose1.centre;
        let mut labelled = false;
        for curve in &r.world {
            let pts = curve.iter().map(|p| (p[0] - c0[0], p[2] - c0[2]));
            for run in clipped_runs(pts, (-2.0, 3.0), (0.0, 12.0)) {
                let s = chart.draw_series(LineSeries::new(run, BLUE.mix(0.5)))?;
                if !labelled {
                    s.label("true boundaries").legend(|(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], BLUE.mix(0.5))
                    });
                    labelled = true;
                }
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
    }
    root.present()?;
    println!("wrote {}", path.display());
    Ok(())
}

/// A vehicle-frame point of frame `pose` (camera tilted by `tilt`) in
/// world coordinates.
fn vehicle_to_world(pose: &synth::Pose, tilt: f64, v: [f32; 3]) -> V3 {
    let v = v.map(f64::from);
    let (s, c) = tilt.sin_cos();
    let cam = [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]];
    let r = pose.rot;
    [0, 1, 2].map(|i| pose.centre[i] + r[i][0] * cam[0] + r[i][1] * cam[1] + r[i][2] * cam[2])
}

fn fig_fusion(dir: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    use host_tests::drives::{self, fig6_drive, DriveFamily, Noise};
    use roadstereo::fusion::{FusedStatus, FusionConfig};
    let path = dir.join("fig_fusion.svg");
    let d = fig6_drive(20);
    let input = d.input(Noise::Rounded, None, 1);
    let tilt = d.spec.tilt;
    let cam = d.spec.intrinsics.camera();
    let policy = FusionConfig::DEFAULT.with_tilt(tilt as f32)?;
    // Stick (or fused interval) of key-frame point i as world segment.
    let seg = |key: usize, b: usize, i: usize, near: f32, far: f32| -> (V3, V3) {
        let [x, y] = cam.normalise(input.frames[key][b][i]);
        let pose = &d.frames[key].pose;
        (
            world(pose, [x * near, y * near, near]),
            world(pose, [x * far, y * far, far]),
        )
    };
    let (mut single, mut fused, mut map) = (Vec::new(), Vec::new(), Vec::new());
    let last = d.frames.len() - 1;
    let run = drives::run(&d, &input, policy, |j, step, f| {
        let Some(key) = f.key() else { return };
        let kid = key.id() as usize;
        // A key frame that just retired (or the last one at the end): its
        // fused intervals.
        {
            if step.retired.is_some() || j == last {
                for b in 0..2 {
                    for (i, p) in key.points(b).enumerate() {
                        if let (FusedStatus::Consistent, Some(iv)) = (p.status, p.interval) {
                            fused.push(seg(kid, b, i, iv.z_near, iv.z_far));
                        }
                    }
                }
            }
        }
        if j == last {
            for b in 0..2 {
                for p in f.map().points(b) {
                    map.push((
                        vehicle_to_world(&d.frames[j].pose, tilt, p.near),
                        vehicle_to_world(&d.frames[j].pose, tilt, p.far),
                    ));
                }
            }
        }
    });
    // The first key frame's first pair: the single-pair sticks.
    if let Some(rec) = run.keys.first() {
        for (b, pts) in rec.pairs[0].iter().enumerate() {
            for (i, q) in pts.iter().enumerate() {
                if q.status == Status::Ok {
                    single.push(seg(rec.key, b, i, q.z_near as f32, q.z_far as f32));
                }
            }
        }
    }
    // The median width against the partners: the first key frame of each
    // family's drives, the points with an interval after the first partner.
    let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    let strict = FusionConfig::new(8, 0)?;
    let mut families: Vec<(String, Vec<drives::Drive>)> =
        vec![("Fig. 6 set-up".into(), vec![fig6_drive(14)])];
    for f in DriveFamily::ALL {
        let ds: Vec<drives::Drive> = (0..40)
            .filter_map(|seed| drives::DriveSpec::new(f, seed, 14).render())
            .take(10)
            .collect();
        families.push((f.name().into(), ds));
    }
    for (name, ds) in &families {
        let mut widths: Vec<Vec<f64>> = vec![Vec::new(); 8];
        for (seed, dd) in ds.iter().enumerate() {
            let input = dd.input(Noise::Rounded, None, seed as u64);
            let r = drives::run(dd, &input, strict, |_, _, _| {});
            let Some(rec) = r.keys.first() else { continue };
            for (b, pts) in rec.fused[0].iter().enumerate() {
                for (i, p0) in pts.iter().enumerate() {
                    if p0.interval.is_none() || p0.status.is_flagged() {
                        continue;
                    }
                    let z = dd.z_true(rec.key, b, i);
                    for (n, snap) in rec.fused.iter().enumerate().take(8) {
                        if let Some(iv) = snap[b][i]
                            .interval
                            .filter(|_| !snap[b][i].status.is_flagged())
                        {
                            widths[n].push(f64::from(iv.z_far - iv.z_near) / z);
                        }
                    }
                }
            }
        }
        let pts = widths
            .iter_mut()
            .enumerate()
            .filter(|(_, w)| !w.is_empty())
            .map(|(n, w)| {
                w.sort_by(f64::total_cmp);
                ((n + 1) as f64, w[w.len() / 2])
            })
            .collect();
        curves.push((name.clone(), pts));
    }
    let root = SVGBackend::new(&path, (1500, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let (left, rest) = root.split_horizontally(470);
    let (middle, right) = rest.split_horizontally(560);
    // Only what is inside both views (plotters draws a segment that
    // leaves the chart along its edge).
    let inside = |p: &V3| p[0] > -1.9 && p[0] < 5.9 && p[2] > -0.9 && p[2] < 13.9;
    let truth: Vec<Vec<V3>> = d
        .world
        .iter()
        .map(|c| {
            c.iter()
                .copied()
                .skip_while(|p| !inside(p))
                .take_while(inside)
                .collect()
        })
        .collect();
    let keep = |v: &[(V3, V3)]| -> Vec<(V3, V3)> {
        v.iter()
            .copied()
            .filter(|(n, f)| inside(n) && inside(f))
            .collect()
    };
    let (single, fused, map) = (keep(&single), keep(&fused), keep(&map));
    let poses: Vec<V3> = d.frames.iter().map(|f| f.pose.centre).collect();
    let pale = RGBColor(240, 150, 150);
    let green = RGBColor(0, 150, 60);
    let layers = [
        (
            &single,
            pale.stroke_width(1),
            "single pair (first key frame, 1st partner)",
        ),
        (
            &fused,
            BLACK.stroke_width(2),
            "fused, as each key frame retired",
        ),
        (&map, green.stroke_width(2), "road map after the last frame"),
    ];
    let mut top = ChartBuilder::on(&left)
        .caption(
            "Top view: fused intervals over 20 frames",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(-2.0f64..6.0, -1.0f64..14.0)?;
    top.configure_mesh()
        .x_desc("x (right), camera heights")
        .y_desc("forward, camera heights")
        .draw()?;
    for (k, c) in truth.iter().enumerate() {
        let s = top.draw_series(LineSeries::new(
            c.iter().map(|p| (p[0], p[2])),
            BLUE.mix(0.5),
        ))?;
        if k == 0 {
            s.label("true boundaries")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLUE.mix(0.5)));
        }
    }
    for (segs, style, name) in layers {
        top.draw_series(
            segs.iter()
                .map(move |(n, f)| PathElement::new(vec![(n[0], n[2]), (f[0], f[2])], style)),
        )?
        .label(name)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
    }
    top.draw_series(poses.iter().map(|p| Circle::new((p[0], p[2]), 3, BLACK)))?;
    top.configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    let mut side = ChartBuilder::on(&middle)
        .caption("Side view: height vs forward distance", ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(-1.0f64..14.0, -0.6f64..1.4)?;
    side.configure_mesh()
        .x_desc("forward, camera heights")
        .y_desc("height above the start ground")
        .draw()?;
    for c in &truth {
        side.draw_series(LineSeries::new(
            c.iter().map(|p| (p[2], -p[1])),
            BLUE.mix(0.5),
        ))?;
    }
    for (segs, style, _) in layers {
        side.draw_series(
            segs.iter()
                .map(move |(n, f)| PathElement::new(vec![(n[2], -n[1]), (f[2], -f[1])], style)),
        )?;
    }
    side.draw_series(poses.iter().map(|p| Circle::new((p[2], -p[1]), 3, BLACK)))?;
    let mut widths = ChartBuilder::on(&right)
        .caption(
            "Median relative width vs partner frames",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(55)
        .build_cartesian_2d(0.5f64..8.5, (0.02f64..0.8).log_scale())?;
    widths
        .configure_mesh()
        .y_label_formatter(&|v| format!("{v:.2}"))
        .x_desc("partner frames fused")
        .y_desc("median (z_far − z_near) / z")
        .draw()?;
    for (k, (name, pts)) in curves.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        let style = if k == 0 {
            BLACK.stroke_width(3)
        } else {
            color.stroke_width(1)
        };
        widths
            .draw_series(LineSeries::new(pts.iter().copied(), style))?
            .label(name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], style));
    }
    widths
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    println!(
        "wrote {} ({} single-pair sticks, {} fused intervals of retiring key frames, {} map points at the end)",
        path.display(),
        single.len(),
        fused.len(),
        map.len()
    );
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "../docs".into()));
    std::fs::create_dir_all(&dir)?;
    fig7(&dir)?;
    fig_fusion(&dir)?;
    fig3(&dir)?;
    fig4(&dir)?;
    fig_a2(&dir)?;
    fig10(&dir)?;
    example(&dir)?;
    Ok(())
}
