//! Issue 15, item 3: every public function taking an angle reduces it
//! correctly or returns a typed error. A table of angles at and beyond each
//! function's range, each result compared with the same formula evaluated
//! in `f64` with `libm`'s `sin`/`cos` (so a reduction error in the library
//! cannot cancel out).

use roadstereo::analysis::{
    camera_to_vehicle, common_rows_motion, disparity_tilted, ground_interval, misaligned_disparity,
    misaligned_row, misalignment_depth_error, motion_factor, vehicle_to_camera,
};
use roadstereo::{AngleError, MAX_ANGLE_RAD};

fn sin(x: f32) -> f64 {
    libm::sin(f64::from(x))
}
fn cos(x: f32) -> f64 {
    libm::cos(f64::from(x))
}

/// The smallest `f32` above `x > 0`.
fn up(x: f32) -> f32 {
    f32::from_bits(x.to_bits() + 1)
}

/// Angles every function accepts: small, at the quarter turn, several
/// turns (the 6 and 7 rad), and the ends of the range.
fn accepted() -> Vec<f32> {
    use std::f32::consts::{FRAC_PI_2, PI};
    vec![
        0.0,
        -0.0,
        f32::from_bits(1),
        0.4,
        -0.4,
        FRAC_PI_2,
        -FRAC_PI_2,
        2.5,
        -2.5,
        PI,
        6.0,
        7.0,
        -7.0,
        100.0,
        -1000.0,
        4321.5,
        MAX_ANGLE_RAD,
        -MAX_ANGLE_RAD,
    ]
}

/// Angles every function rejects, with the error.
fn rejected() -> Vec<(f32, AngleError)> {
    vec![
        (up(MAX_ANGLE_RAD), AngleError::TooLarge),
        (-up(MAX_ANGLE_RAD), AngleError::TooLarge),
        (1.0e5, AngleError::TooLarge),
        (-1.0e30, AngleError::TooLarge),
        (f32::MAX, AngleError::TooLarge),
        (f32::INFINITY, AngleError::NotFinite),
        (f32::NEG_INFINITY, AngleError::NotFinite),
        (f32::NAN, AngleError::NotFinite),
    ]
}

/// `|got − want| ≤ abs + rel · |want|`, or both infinite (the functions'
/// "not in front of the camera" value).
fn close(got: f32, want: f64, abs: f64, rel: f64) -> bool {
    if want.is_infinite() || got.is_infinite() {
        return got.is_infinite() && want.is_infinite();
    }
    (f64::from(got) - want).abs() <= abs + rel * want.abs()
}

/// The reproducer and the transform in both directions: `(0, 0, 1)`
/// turns into `(0, −sin θ, cos θ)` and `(0, sin θ, cos θ)` with no rounding
/// but the sine's and cosine's own, so these bound the reduction's error
/// directly (1.2e-7: two ulps of 1).
#[test]
fn tilt_transform_reduces_every_angle() {
    let [u, v, w] = vehicle_to_camera([0.0, 0.0, 1.0], 6.0).unwrap();
    assert!(u == 0.0 && (v - 0.279_415_5).abs() < 1e-6 && (w - 0.960_170_3).abs() < 1e-6);
    for x in accepted() {
        let a = vehicle_to_camera([0.0, 0.0, 1.0], x).unwrap();
        let b = camera_to_vehicle([0.0, 0.0, 1.0], x).unwrap();
        let (s, c) = (sin(x), cos(x));
        for (got, want) in a.iter().zip([0.0, -s, c]).chain(b.iter().zip([0.0, s, c])) {
            assert!(close(*got, want, 1.2e-7, 0.0), "θ = {x}: {got} vs {want}");
        }
        // A general vector: the products add an ulp or two of |t| ≤ 1.8.
        let t = [0.3f32, -0.2, 1.7];
        let g = vehicle_to_camera(t, x).unwrap();
        let want = [0.3, c * -0.2 - s * 1.7, s * -0.2 + c * 1.7];
        for (got, want) in g.iter().zip(want) {
            assert!(close(*got, want, 1.0e-6, 0.0), "θ = {x}: {got} vs {want}");
        }
    }
    for (x, e) in rejected() {
        assert_eq!(vehicle_to_camera([0.0, 0.0, 1.0], x), Err(e), "θ = {x}");
        assert_eq!(camera_to_vehicle([0.0, 0.0, 1.0], x), Err(e), "θ = {x}");
    }
}

/// Eqs. 3.2 and 3.4 at every tilt of the table (f = 800, h = 1, w = 0.1,
/// z = 4): relative error 1e-5 (the `f32` formula's own rounding is a few
/// ulps; the denominators stay away from zero for these tilts).
#[test]
fn disparity_and_motion_factor_reduce_every_tilt() {
    for x in accepted() {
        let (s, c) = (sin(x), cos(x));
        let zp = s + 4.0 * c;
        let den = zp * (zp - 0.1 * c);
        let want = if zp > 0.0 && den > 0.0 {
            800.0 * 0.1 / den
        } else {
            f64::INFINITY
        };
        let got = disparity_tilted(800.0, 1.0, 0.1, 4.0, x).unwrap();
        assert!(close(got, want, 0.0, 1e-5), "θ = {x}: {got} vs {want}");
        // F for n = 2, w = 0.1, Z' = 5: 2 + 2 w cos θ / (5 − 2 w cos θ).
        let want = 2.0 + 2.0 * 0.1 * c / (5.0 - 0.2 * c);
        let got = motion_factor(2.0, 0.1, 5.0, x).unwrap();
        assert!(close(got, want, 0.0, 1e-6), "θ = {x}: {got} vs {want}");
    }
    for (x, e) in rejected() {
        assert_eq!(disparity_tilted(800.0, 1.0, 0.1, 4.0, x), Err(e), "θ = {x}");
        assert_eq!(motion_factor(2.0, 0.1, 5.0, x), Err(e), "θ = {x}");
    }
}

/// Appendix II A at every axis error of the table (row 120 and 130, f =
/// 800): relative error 1e-5 where the turned axis does not come near the
/// row (it does at `tan θ = f/y`, about 1.42 rad, not in the table).
#[test]
fn misalignment_reduces_every_angle() {
    let (y, f) = (120.0f64, 800.0f64);
    for x in accepted() {
        let (s, c) = (sin(x), cos(x));
        let want = y * f / (f * c - y * s);
        let got = misaligned_row(y as f32, f as f32, x).unwrap();
        assert!(close(got, want, 0.0, 1e-5), "θ = {x}: {got} vs {want}");
        let want = 10.0 * f * f * c / ((f * c - y * s) * (f * c - (y + 10.0) * s));
        let got = misaligned_disparity(y as f32, y as f32 + 10.0, f as f32, x).unwrap();
        assert!(close(got, want, 0.0, 1e-5), "θ = {x}: {got} vs {want}");
    }
    for (x, e) in rejected() {
        assert_eq!(misaligned_row(120.0, 800.0, x), Err(e), "θ = {x}");
        assert_eq!(
            misaligned_disparity(120.0, 130.0, 800.0, x),
            Err(e),
            "θ = {x}"
        );
    }
}

/// `misalignment_depth_error` in `f64` (its docs' definition), for a ground
/// point at `z`, camera height 1, forward motion 0.25, f = 800.
fn depth_error_f64(tilt: f32, z: f64, angle: f32) -> Option<f64> {
    let (f, h, w) = (800.0f64, 1.0f64, 0.25f64);
    let (s, c) = (sin(tilt), cos(tilt));
    let t = [0.0, -s * w, c * w];
    let p1 = [0.0, c * h - s * z, s * h + c * z];
    let p2 = [0.0, p1[1] - t[1], p1[2] - t[2]];
    if p1[2] <= 0.0 || p2[2] <= 0.0 {
        return None;
    }
    let (y1, y2) = (f * p1[1] / p1[2], f * p2[1] / p2[2]);
    let (sa, ca) = (sin(angle), cos(angle));
    let row = |y: f64| y * f / (f * ca - y * sa);
    let disparity = (y2 - y1) * f * f * ca / ((f * ca - y1 * sa) * (f * ca - y2 * sa));
    let depth = |y2: f64, dy: f64| (-f * t[1] + t[2] * y2) / dy;
    Some((depth(row(y2), disparity) / depth(y2, y2 - y1) - 1.0).abs())
}

/// The depth error from an axis error, with the tilt and then the axis
/// error taken from the table: absolute error 1e-4 plus 1e-4 relative (the
/// result is a ratio of two depths minus one; each depth has `f32`
/// rounding of a few ulps).
#[test]
fn misalignment_depth_error_reduces_both_angles() {
    let z = 4.0f32;
    for x in accepted() {
        for (tilt, angle) in [(x, 0.02f32), (0.4, x)] {
            let got = misalignment_depth_error(800.0, 1.0, tilt, 0.25, z, angle).unwrap();
            let want = depth_error_f64(tilt, f64::from(z), angle);
            match (got, want) {
                (None, None) => {}
                (Some(g), Some(w)) => {
                    assert!(
                        close(g, w, 1e-4, 1e-4),
                        "tilt {tilt}, angle {angle}: {g} vs {w}"
                    )
                }
                _ => panic!("tilt {tilt}, angle {angle}: {got:?} vs {want:?}"),
            }
        }
    }
    for (x, e) in rejected() {
        assert_eq!(
            misalignment_depth_error(800.0, 1.0, x, 0.25, z, 0.02),
            Err(e)
        );
        assert_eq!(
            misalignment_depth_error(800.0, 1.0, 0.4, 0.25, z, x),
            Err(e)
        );
    }
}

/// The tilt as the equivalent angle in `[−π, π]`, in `f64`.
fn reduced_f64(x: f32) -> f64 {
    let x = f64::from(x);
    let turn = 2.0 * std::f64::consts::PI;
    x - turn * (x / turn).round()
}

/// The ground seen, in `f64`: `h cot α` over the part of the view's rays
/// `[t − half, t + half]` (below the horizontal ahead; shifted by a turn
/// for a tilt near −π) in `(0, π)`, with the part's ends `(a, b)`; near
/// end `−∞` when the view reaches the horizon behind, far end `+∞` when it
/// reaches the horizon ahead.
fn ground_f64(h: f64, t: f64, half: f64) -> Option<(f64, f64, f64, f64)> {
    use std::f64::consts::{PI, TAU};
    [0.0, TAU].into_iter().find_map(|shift| {
        let (upper, lower) = (t - half + shift, t + half + shift);
        let (a, b) = (upper.max(0.0), lower.min(PI));
        (a < b).then(|| {
            let near = if lower >= PI {
                f64::NEG_INFINITY
            } else {
                h / b.tan()
            };
            let far = if upper <= 0.0 {
                f64::INFINITY
            } else {
                h / a.tan()
            };
            (near, far, a, b)
        })
    })
}

/// `ground_interval`'s ends `got` against [`ground_f64`]'s `want` for a
/// camera at height `h`: within 3e-7 rad of the reduced tilt's error times
/// `h / sin² α` (how fast `h cot α` moves) at each end's ray, plus 1e-5
/// relative for the `f32` formula.
fn assert_ground_close(got: (f32, f32), want: (f64, f64, f64, f64), h: f64, what: &str) {
    let ((gn, gf), (wn, wf, a, b)) = (got, want);
    let slope = |x: f64| h / (x.sin() * x.sin());
    assert!(close(gn, wn, 3e-7 * slope(b), 1e-5), "{what}: {gn} vs {wn}");
    assert!(close(gf, wf, 3e-7 * slope(a), 1e-5), "{what}: {gf} vs {wf}");
}

/// A camera looking steeply down or back sees the ground behind it too
/// (an adversarial review: 80° down with a half field of view of 20°, and
/// 23° down with 70°, were "no ground"), and one upside down sees the
/// ground behind it; every tilt from −π to π with half fields of view
/// from 0.01 to 1.5 rad against `f64`, away from the view's edges at the
/// horizons (where `f32` and `f64` may fall on either side).
#[test]
fn ground_seen_at_every_tilt() {
    let r = ground_interval(1.0, 80f32.to_radians(), 20f32.to_radians())
        .unwrap()
        .expect("ground seen");
    assert!(
        (r.lo - (-0.176_327)).abs() < 1e-4 && (r.hi - 0.577_350).abs() < 1e-4,
        "{r:?}"
    );
    let r = ground_interval(1.0, 23f32.to_radians(), 70f32.to_radians())
        .unwrap()
        .expect("ground seen");
    assert!(
        r.hi.is_infinite() && (r.lo - (-0.052_408)).abs() < 1e-4,
        "{r:?}"
    );
    let (mut seen, mut compared) = (0, 0);
    for i in 0..=4000 {
        let t = -std::f64::consts::PI + std::f64::consts::TAU * f64::from(i) / 4000.0;
        for half in [0.01f64, 0.2, 0.7, 1.2, 1.5] {
            let (tf, hf) = (t as f32, half as f32);
            let (t64, h64) = (f64::from(tf), f64::from(hf));
            // Away from the horizons' edges by 1e-5 rad.
            let edge = [
                0.0,
                std::f64::consts::PI,
                -std::f64::consts::PI,
                std::f64::consts::TAU,
            ]
            .iter()
            .any(|e| (t64 - h64 - e).abs() < 1e-5 || (t64 + h64 - e).abs() < 1e-5);
            if edge {
                continue;
            }
            compared += 1;
            let got = ground_interval(2.0, tf, hf).unwrap().map(|r| (r.lo, r.hi));
            let want = ground_f64(2.0, t64, h64);
            match (got, want) {
                (None, None) => {}
                (Some(g), Some(w)) => {
                    seen += 1;
                    assert_ground_close(g, w, 2.0, &format!("tilt {t}, half {half}"));
                }
                _ => panic!("tilt {t}, half {half}: {got:?} vs {want:?}"),
            }
        }
    }
    println!("{compared} views, {seen} see the ground");
    assert!(
        seen > compared / 3 && seen < compared,
        "{seen} of {compared}"
    );
}

/// The ground in view and the common rows, at every tilt of the table and
/// with the half field of view of 480 rows at f = 800: the tilt is reduced
/// (6 rad sees the ground that `6 − 2π` does not: it looks up), a half
/// field of view outside `(0, π/2)` is `OutOfDomain`. The reduced tilt is
/// within 3e-7 rad of the exact one (the library's bound for its `f32`
/// angle in `[−π, π]`), and a distance `h / tan θ` moves by `h / sin² θ`
/// per radian: that, plus 1e-5 relative for the `f32` formula; 1e-4
/// relative for the row fraction (an arctangent and two tangents).
#[test]
fn ground_in_view_reduces_the_tilt() {
    let (h, f, rows, w) = (1.0f64, 800.0f64, 480.0f64, 0.1f64);
    let half_fov = (rows / 2.0 / f).atan();
    let mut seen = 0;
    for x in accepted()
        .into_iter()
        .chain([0.4 + 2.0 * std::f32::consts::TAU])
    {
        let t = reduced_f64(x);
        let lower = t + half_fov;
        let want = ground_f64(h, t, half_fov);
        let got = ground_interval(h as f32, x, half_fov as f32)
            .unwrap()
            .map(|r| (r.lo, r.hi));
        // `common_rows_motion`'s model: the ground ahead, the view's lower
        // edge short of the vertical.
        let ahead = lower > 0.0 && lower < std::f64::consts::FRAC_PI_2;
        if !ahead {
            assert_eq!(
                common_rows_motion(h as f32, x, f as f32, rows as f32, w as f32),
                Ok(None),
                "θ = {x}"
            );
        }
        match (got, want) {
            (None, None) => {}
            (Some(g), Some(exact)) => {
                seen += 1;
                let (wn, wf, _, _) = exact;
                assert_ground_close(g, exact, h, &format!("θ = {x}"));
                if !ahead {
                    continue;
                }
                // Common rows (the docs' formula, in f64).
                let row = |d: f64| f * ((h / d).atan() - t).tan();
                let top = if wf.is_finite() {
                    -rows / 2.0
                } else {
                    (-rows / 2.0).max(-f * t.tan())
                };
                let seen_rows = rows / 2.0 - top;
                let want = (1.0 - (rows / 2.0 - row(wn + w)) / seen_rows).max(0.0);
                let got = common_rows_motion(h as f32, x, f as f32, rows as f32, w as f32)
                    .unwrap()
                    .expect("ground in view");
                assert!(close(got, want, 0.0, 1e-4), "θ = {x}: {got} vs {want}");
            }
            _ => panic!("θ = {x}: {got:?} vs {want:?}"),
        }
    }
    // The table's tilts of 0.4, 6, 7, 0.4 + 4π and others see the ground.
    assert!(seen >= 4, "{seen}");
    for (x, e) in rejected() {
        assert_eq!(ground_interval(1.0, x, 0.3), Err(e), "θ = {x}");
        assert_eq!(common_rows_motion(1.0, x, 800.0, 480.0, 0.1), Err(e));
    }
    for (fov, e) in [
        (0.0, AngleError::OutOfDomain),
        (-0.1, AngleError::OutOfDomain),
        (std::f32::consts::FRAC_PI_2, AngleError::OutOfDomain),
        (2.0, AngleError::OutOfDomain),
        (f32::NAN, AngleError::NotFinite),
        (f32::INFINITY, AngleError::NotFinite),
    ] {
        assert_eq!(ground_interval(1.0, 0.4, fov), Err(e), "half fov {fov}");
    }
}

/// `Intrinsics::predicted_foe` and `camera_motion` at every roll of the
/// table, against `f64` (the issue: a roll of 7 rad gave a wrong FOE). An
/// FOE `f · t / t_z` away moves by about `f |t| / t_z · δ` for a rotation
/// error `δ` (1.2e-7 here): 2e-4 px for this camera and translation.
#[test]
fn calibration_reduces_every_roll() {
    use roadstereo::calibration::{CalibrationError, Intrinsics};
    let base = Intrinsics {
        cx: 273.59,
        cy: 233.96,
        roll: 0.0,
        fx: 614.5,
        fy: 780.7,
    };
    let t = [2.5f32, -1.5, 2.5];
    let robot = roadstereo::Motion::new([0.3, 0.1, 1.0], [0.0, 0.1, 0.0]).unwrap();
    for x in accepted() {
        let k = Intrinsics { roll: x, ..base };
        let (s, c) = (sin(x), cos(x));
        let (tx, ty, tz) = (f64::from(t[0]), f64::from(t[1]), f64::from(t[2]));
        let want = [
            f64::from(k.cx) + f64::from(k.fx) * (c * tx + s * ty) / tz,
            f64::from(k.cy) + f64::from(k.fy) * (-s * tx + c * ty) / tz,
        ];
        let got = k.predicted_foe(t).unwrap();
        assert!(
            close(got.u, want[0], 2e-4, 1e-6) && close(got.v, want[1], 2e-4, 1e-6),
            "roll {x}: {got:?} vs {want:?}"
        );
        // T_c = R_zᵀ T and R_c = R_zᵀ R_y(0.1) R_z, in f64.
        let m = k.camera_motion(&robot).unwrap();
        let tc = [0.3 * c + 0.1 * s, -0.3 * s + 0.1 * c, 1.0];
        for (g, w) in m.translation().iter().zip(tc) {
            assert!(close(*g, w, 1e-6, 0.0), "roll {x}: {g} vs {w}");
        }
        let (sb, cb) = (libm::sin(0.1), libm::cos(0.1));
        let ry = [[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]];
        let rz = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        let mul = |a: [[f64; 3]; 3], b: [[f64; 3]; 3]| {
            let mut o = [[0.0; 3]; 3];
            for (i, row) in o.iter_mut().enumerate() {
                for (j, cell) in row.iter_mut().enumerate() {
                    *cell = (0..3).map(|k| a[i][k] * b[k][j]).sum();
                }
            }
            o
        };
        let rzt = [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]];
        let want = mul(rzt, mul(ry, rz));
        let got = m.rotation_matrix();
        for i in 0..3 {
            for j in 0..3 {
                // Through asin/atan2 and back: a few ulps of 1.
                assert!(
                    close(got[i][j], want[i][j], 1e-6, 0.0),
                    "roll {x}: R[{i}][{j}]"
                );
            }
        }
    }
    for (x, e) in rejected() {
        let k = Intrinsics { roll: x, ..base };
        // NaN and infinite parameters are NotFinite, as for every field.
        let want = if e == AngleError::NotFinite {
            CalibrationError::NotFinite
        } else {
            CalibrationError::Angle(e)
        };
        assert_eq!(k.predicted_foe(t), Err(want), "roll {x}");
        assert_eq!(k.camera_motion(&robot), Err(want), "roll {x}");
    }
}

/// `calibrate_jointly` started from a roll whole turns away from the
/// step-by-step one converges to the same camera (within the joint fit's
/// tolerances of the truth: c ± 1.5 px, γ ± 0.5°, f ± 2 %), with its roll
/// reported in `[−π, π]`; a start roll beyond the range is a typed error.
#[test]
fn joint_calibration_reduces_the_start_roll() {
    use host_tests::calib::{calibrate_run, paper_motions, TrueCamera};
    use roadstereo::calibration::{calibrate_jointly, CalibrationError, Intrinsics, MotionFlows};
    let cam = TrueCamera::default();
    let (sets, stepwise, joint) = calibrate_run(&cam, &paper_motions(), 50, 0.0, 11).unwrap();
    let motions: Vec<MotionFlows<'_>> = paper_motions()
        .iter()
        .zip(&sets)
        .map(|(t, f)| MotionFlows {
            translation: t.map(|x| x as f32),
            flows: f,
        })
        .collect();
    let tau = std::f32::consts::TAU;
    for turns in [-3.0f32, -1.0, 1.0, 2.0, 1000.0] {
        let start = Intrinsics {
            roll: stepwise.roll + turns * tau,
            ..stepwise
        };
        let j = calibrate_jointly::<512>(&motions, &start).unwrap();
        let k = j.intrinsics;
        assert!(
            (-std::f32::consts::PI..=std::f32::consts::PI).contains(&k.roll),
            "{k:?}"
        );
        assert!(
            (f64::from(k.roll) - cam.roll).to_degrees().abs() <= 0.5,
            "{turns}: {k:?}"
        );
        assert!((f64::from(k.cx) - cam.cx).hypot(f64::from(k.cy) - cam.cy) <= 1.5);
        assert!((f64::from(k.fx) / cam.fx - 1.0).abs() <= 0.02);
        assert!((f64::from(k.fy) / cam.fy - 1.0).abs() <= 0.02);
        // The same minimum as from the step-by-step start.
        assert!(
            (k.roll - joint.intrinsics.roll).abs() < 1e-4,
            "{turns}: {k:?}"
        );
    }
    for (x, e) in rejected() {
        let start = Intrinsics {
            roll: x,
            ..stepwise
        };
        let want = if e == AngleError::NotFinite {
            CalibrationError::NotFinite
        } else {
            CalibrationError::Angle(e)
        };
        assert_eq!(calibrate_jointly::<512>(&motions, &start), Err(want));
    }
}

/// The two functions that validate their angles into the unreduced
/// kernel's range instead: `Motion::new` (±60° per axis, the rotation
/// matrix against `f64`) and `Config::new` (a minimum angle of 0.1°–89°).
#[test]
fn validated_angle_ranges_hold_at_their_ends() {
    use roadstereo::motion::MAX_ROTATION_RAD;
    use roadstereo::{Config, ConfigError, Motion, MotionError};
    for a in [0.0f32, -0.0, 0.4, MAX_ROTATION_RAD, -MAX_ROTATION_RAD] {
        let m = Motion::new([0.0, 0.0, 1.0], [0.0, a, 0.0]).unwrap();
        let r = m.rotation_matrix();
        // R_y(β): r00 = cos β, r02 = sin β.
        assert!(close(r[0][0], cos(a), 1.2e-7, 0.0) && close(r[0][2], sin(a), 1.2e-7, 0.0));
    }
    for (a, e) in [
        (up(MAX_ROTATION_RAD), MotionError::RotationTooLarge),
        (6.0, MotionError::RotationTooLarge),
        (f32::MAX, MotionError::RotationTooLarge),
        (f32::NAN, MotionError::NotFinite),
        (f32::INFINITY, MotionError::NotFinite),
    ] {
        for axis in 0..3 {
            let mut rot = [0.0; 3];
            rot[axis] = a;
            assert_eq!(Motion::new([0.0, 0.0, 1.0], rot), Err(e), "{a}");
        }
    }
    for deg in [0.1f32, 10.0, 89.0] {
        assert!(Config::new(0.5, 0.5, deg, 100.0).is_ok(), "{deg}");
    }
    for deg in [0.09f32, 89.01, 400.0, f32::NAN, f32::INFINITY] {
        assert_eq!(
            Config::new(0.5, 0.5, deg, 100.0),
            Err(ConfigError::MinAngle),
            "{deg}"
        );
    }
}
