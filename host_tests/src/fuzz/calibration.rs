//! The calibration entry points ([`roadstereo::calibration`]):
//! [`focus_of_expansion`], [`calibrate_stepwise`], [`calibrate_jointly`]
//! and the methods of [`Intrinsics`], on flows of a drawn camera (with
//! noise, outliers, zero and parallel flows) mixed with special values.
//!
//! Oracles: no panic; every `Ok` is finite (issue 15, item 2: "a result is
//! finite or it is an error"), within its documented ranges (the joint
//! fit's roll in `[−π, π]`, counts no more than the flows); input errors
//! as documented (`TooManyFlows` over the capacity, `NotFinite` for a NaN
//! or infinite coordinate); same input, same output.

use roadstereo::calibration::{
    calibrate_jointly, calibrate_stepwise, focus_of_expansion, CalibrationError, Flow, Intrinsics,
    MotionFlows, MAX_COORD_PX,
};
use roadstereo::{Motion, Pixel};

use super::{Outcome, Source};

/// A flow as drawn: `[from, to]`, each `[u, v]`.
pub type FlowIn = [[f32; 2]; 2];

/// Capacity of the flows of one motion.
pub const CAP: usize = 48;

/// One case.
#[derive(Debug, Clone)]
pub enum Case {
    /// [`focus_of_expansion`] on `(from, to)` flows.
    Foe(Vec<[[f32; 2]; 2]>),
    /// [`calibrate_stepwise`]: the straight FOE and the four diagonal ones.
    Stepwise([f32; 2], [[f32; 2]; 4]),
    /// [`calibrate_jointly`]: motions (translation, flows) and the start
    /// (`cx, cy, roll, fx, fy`).
    Joint(Vec<([f32; 3], Vec<FlowIn>)>, [f32; 5]),
    /// The methods of [`Intrinsics`] (`cx, cy, roll, fx, fy`): `aspect`,
    /// `predicted_foe(t)`, `camera(w, h)`, `camera_motion(robot)`.
    Methods([f32; 5], [f32; 3], (u16, u16), ([f32; 3], [f32; 3])),
}

/// A camera to draw flows from: `cx, cy, roll, fx, fy`.
fn intrinsics(src: &mut Source) -> [f32; 5] {
    let f = src.mixed(|s| s.f32_in(100.0, 2000.0));
    [
        src.mixed(|s| s.f32_in(0.0, 640.0)),
        src.mixed(|s| s.f32_in(0.0, 480.0)),
        src.mixed(|s| match s.below(8) {
            0 => s.f32_in(-8192.0, 8192.0),
            1 => s.pick(&[8192.0, 8192.0f32.next_up(), -8192.0, core::f32::consts::PI]),
            _ => s.f32_in(-0.2, 0.2),
        }),
        f,
        src.mixed(|s| f * s.f32_in(0.8, 1.25)),
    ]
}

/// The FOE of translation `t` for `k` (as [`Intrinsics::predicted_foe`]).
fn foe(k: &[f32; 5], t: [f32; 3]) -> [f64; 2] {
    let [cx, cy, roll, fx, fy] = k.map(f64::from);
    let (s, c) = roll.sin_cos();
    let t = t.map(f64::from);
    let (x, y) = (c * t[0] + s * t[1], -s * t[0] + c * t[1]);
    [cx + fx * x / t[2], cy + fy * y / t[2]]
}

/// A translation: forward mostly, else special.
fn translation(src: &mut Source) -> [f32; 3] {
    match src.below(12) {
        0 => [src.special(), src.special(), src.special()],
        1 => [
            0.0,
            0.0,
            src.pick(&[0.0, -1.0, 1.0e-30, 1.0e6, 1.000_001e6]),
        ],
        _ => {
            let tz = src.mixed(|s| s.f32_in(0.2, 2.0));
            [
                src.mixed(|s| s.f32_in(-1.0, 1.0) * tz),
                src.mixed(|s| s.f32_in(-1.0, 1.0) * tz),
                tz,
            ]
        }
    }
}

/// Flows of a translation with FOE `e`: noise, outliers, zero flows,
/// duplicates, parallel flows and special values.
fn flows(src: &mut Source, e: [f64; 2]) -> Vec<[[f32; 2]; 2]> {
    let n = match src.below(16) {
        0 => src.index(3),
        1 => CAP + src.index(3),
        _ => 2 + src.index(30),
    };
    let noise = src.pick(&[0.0, 0.0, 0.3, 1.0, 5.0]);
    let parallel = src.chance(1, 16);
    let mut v = Vec::with_capacity(n);
    for _ in 0..n {
        let from = [src.range(0.0, 640.0), src.range(0.0, 480.0)];
        let to = if parallel {
            [from[0] + 5.0, from[1] + 1.0]
        } else if src.chance(1, 10) {
            [src.range(0.0, 640.0), src.range(0.0, 480.0)]
        } else {
            let g = src.range(0.02, 0.5);
            [
                from[0] + g * (from[0] - e[0]) + src.range(-noise, noise),
                from[1] + g * (from[1] - e[1]) + src.range(-noise, noise),
            ]
        };
        v.push([from.map(|x| x as f32), to.map(|x| x as f32)]);
    }
    let mutations = if src.chance(1, 2) {
        0
    } else {
        1 + src.below(3)
    };
    for _ in 0..mutations {
        if v.is_empty() {
            break;
        }
        let i = src.index(v.len());
        match src.below(6) {
            0 => v[i][src.index(2)][src.index(2)] = src.special(),
            1 => v[i][1] = v[i][0],
            2 => {
                let f = v[i];
                v.push(f);
            }
            3 => {
                v[i][src.index(2)][src.index(2)] = src.pick(&[
                    MAX_COORD_PX,
                    -MAX_COORD_PX,
                    MAX_COORD_PX.next_up(),
                    1.0e30,
                    -1.0e30,
                ])
            }
            4 => v[i] = v[i].map(|p| p.map(f32::round)),
            _ => v[i][1][0] = src.mixed(|s| s.f32_in(-1.0e6, 1.0e6)),
        }
    }
    v
}

/// Draw a case.
pub fn generate(src: &mut Source) -> Case {
    let k = intrinsics(src);
    match src.below(4) {
        0 => {
            let t = translation(src);
            let e = foe(&k, t);
            Case::Foe(flows(src, e))
        }
        1 => {
            let t = src.mixed(|s| s.f32_in(0.2, 2.0));
            let pt = |src: &mut Source, tx: f32, ty: f32| {
                let e = foe(&k, [tx, ty, t]);
                let p = [e[0] as f32, e[1] as f32];
                if src.chance(1, 10) {
                    [src.special(), p[1]]
                } else if src.chance(1, 10) {
                    p.map(|x| src.mixed(|s| x + s.f32_in(-1.0e3, 1.0e3)))
                } else {
                    p.map(|x| x + src.f32_in(-0.5, 0.5))
                }
            };
            let straight = pt(src, 0.0, 0.0);
            let d = [
                pt(src, t, t),
                pt(src, -t, t),
                pt(src, -t, -t),
                pt(src, t, -t),
            ];
            Case::Stepwise(straight, d)
        }
        2 => {
            let m = 1 + src.index(4);
            let motions = (0..m)
                .map(|_| {
                    let t = translation(src);
                    let e = foe(&k, t);
                    (t, flows(src, e))
                })
                .collect();
            let start = if src.chance(1, 4) {
                intrinsics(src)
            } else {
                k.map(|x| x * src.f32_in(0.95, 1.05))
            };
            Case::Joint(motions, start)
        }
        _ => {
            let size = if src.chance(1, 2) {
                (640, 480)
            } else {
                (src.below(20000) as u16, src.below(20000) as u16)
            };
            let robot_t = translation(src);
            let robot_r = [0, 1, 2].map(|_| src.mixed(|s| s.f32_in(-1.1, 1.1)));
            Case::Methods(k, translation(src), size, (robot_t, robot_r))
        }
    }
}

fn to_flows(v: &[[[f32; 2]; 2]]) -> Vec<Flow> {
    v.iter()
        .map(|[a, b]| Flow {
            from: Pixel::new(a[0], a[1]),
            to: Pixel::new(b[0], b[1]),
        })
        .collect()
}

fn finite(xs: &[f32]) -> bool {
    xs.iter().all(|x| x.is_finite())
}

fn intr(k: &[f32; 5]) -> Intrinsics {
    Intrinsics {
        cx: k[0],
        cy: k[1],
        roll: k[2],
        fx: k[3],
        fy: k[4],
    }
}

fn check_intrinsics(k: &Intrinsics, what: &str) {
    assert!(
        finite(&[k.cx, k.cy, k.roll, k.fx, k.fy]),
        "{what}: Ok with a non-finite result {k:?}"
    );
}

/// The documented input errors of a set of flows, if any.
fn flow_input_error(v: &[[[f32; 2]; 2]]) -> Option<CalibrationError> {
    if v.len() > CAP {
        return Some(CalibrationError::TooManyFlows);
    }
    for f in v {
        for p in f {
            if !finite(p) {
                return Some(CalibrationError::NotFinite);
            }
            if p[0].abs() > MAX_COORD_PX || p[1].abs() > MAX_COORD_PX {
                return Some(CalibrationError::OutOfRange);
            }
        }
    }
    None
}

/// Generate a case from `src` and check it.
pub fn run(src: &mut Source) -> Outcome {
    check(&generate(src))
}

/// Check a case (panics on a finding).
pub fn check(case: &Case) -> Outcome {
    let mut features = 0u128;
    let mut feature = |b: u32| features |= 1u128 << b;
    let err_bit = |e: &CalibrationError| -> u32 {
        match e {
            CalibrationError::NotFinite => 0,
            CalibrationError::OutOfRange => 1,
            CalibrationError::TooFewFlows => 2,
            CalibrationError::TooManyFlows => 3,
            CalibrationError::Parallel => 4,
            CalibrationError::BadTranslation => 5,
            CalibrationError::Degenerate => 6,
            CalibrationError::Overflow => 7,
            CalibrationError::Angle(_) => 8,
            CalibrationError::Camera(_) => 9,
            CalibrationError::Motion(_) => 10,
            // (The enum is non-exhaustive: a variant added later counts with
            // the last one, so no other feature's bit is taken.)
            _ => 10,
        }
    };
    let mut calls = 1;
    match case {
        Case::Foe(v) => {
            let flows = to_flows(v);
            let r = focus_of_expansion::<CAP>(&flows);
            assert_eq!(
                r,
                focus_of_expansion::<CAP>(&flows),
                "focus_of_expansion: not deterministic"
            );
            match (&r, flow_input_error(v)) {
                (Ok(fit), None) => {
                    feature(16);
                    assert!(
                        finite(&[fit.foe.u, fit.foe.v, fit.rms]) && fit.rms >= 0.0,
                        "focus_of_expansion: Ok with {fit:?}"
                    );
                    assert!(
                        fit.inliers + fit.outliers <= v.len(),
                        "focus_of_expansion: counts {fit:?}"
                    );
                }
                (Ok(fit), Some(e)) => panic!("focus_of_expansion: Ok {fit:?}, expected {e:?}"),
                (Err(e), want) => {
                    feature(err_bit(e));
                    if let Some(w) = want {
                        assert_eq!(*e, w, "focus_of_expansion: input error");
                    }
                }
            }
        }
        Case::Stepwise(s, d) => {
            let (s, d) = (Pixel::new(s[0], s[1]), d.map(|p| Pixel::new(p[0], p[1])));
            let r = calibrate_stepwise(s, d);
            assert_eq!(
                r,
                calibrate_stepwise(s, d),
                "calibrate_stepwise: not deterministic"
            );
            match &r {
                Ok(k) => {
                    feature(17);
                    check_intrinsics(k, "calibrate_stepwise");
                }
                Err(e) => feature(err_bit(e)),
            }
            // The first bad pixel, in order, decides the error.
            let first_bad = [s].into_iter().chain(d).find_map(|p| {
                if !finite(&[p.u, p.v]) {
                    Some(CalibrationError::NotFinite)
                } else if p.u.abs() > MAX_COORD_PX || p.v.abs() > MAX_COORD_PX {
                    Some(CalibrationError::OutOfRange)
                } else {
                    None
                }
            });
            if let Some(e) = first_bad {
                assert_eq!(r, Err(e), "calibrate_stepwise: input error");
            }
        }
        Case::Joint(motions, start) => {
            let flows: Vec<Vec<Flow>> = motions.iter().map(|m| to_flows(&m.1)).collect();
            let ms: Vec<MotionFlows> = motions
                .iter()
                .zip(&flows)
                .map(|(m, f)| MotionFlows {
                    translation: m.0,
                    flows: f,
                })
                .collect();
            let k = intr(start);
            let r = calibrate_jointly::<CAP>(&ms, &k);
            assert_eq!(
                r,
                calibrate_jointly::<CAP>(&ms, &k),
                "calibrate_jointly: not deterministic"
            );
            match &r {
                Ok(fit) => {
                    feature(18);
                    check_intrinsics(&fit.intrinsics, "calibrate_jointly");
                    let pi = core::f32::consts::PI;
                    assert!(
                        fit.intrinsics.roll.abs() <= pi,
                        "calibrate_jointly: roll {} outside [-pi, pi]",
                        fit.intrinsics.roll
                    );
                    assert!(
                        fit.rms.is_finite() && finite(&fit.sigma),
                        "calibrate_jointly: Ok with {fit:?}"
                    );
                    let total: usize = motions.iter().map(|m| m.1.len()).sum();
                    assert!(
                        fit.flows <= total,
                        "calibrate_jointly: {} flows used of {total}",
                        fit.flows
                    );
                    assert!(fit.iterations <= roadstereo::calibration::JOINT_ITERATIONS);
                }
                Err(e) => feature(err_bit(e)),
            }
            if let Some(e) = motions.iter().find_map(|m| flow_input_error(&m.1)) {
                if motions
                    .iter()
                    .all(|m| finite(&m.0) && m.0[2] > 0.0 && m.0.iter().all(|x| x.abs() <= 1.0e6))
                {
                    assert!(r.is_err(), "calibrate_jointly: Ok despite {e:?}");
                }
            }
        }
        Case::Methods(k, t, size, robot) => {
            calls = 4;
            let i = intr(k);
            match i.aspect() {
                Ok(a) => {
                    feature(19);
                    assert!(a.is_finite() && a > 0.0, "aspect: Ok({a})");
                }
                Err(e) => feature(err_bit(&e)),
            }
            match i.predicted_foe(*t) {
                Ok(p) => {
                    feature(20);
                    assert!(finite(&[p.u, p.v]), "predicted_foe: Ok({p:?})");
                    assert_eq!(
                        i.predicted_foe(*t),
                        Ok(p),
                        "predicted_foe: not deterministic"
                    );
                }
                Err(e) => feature(err_bit(&e)),
            }
            match i.camera(size.0, size.1) {
                Ok(c) => {
                    feature(21);
                    assert_eq!((c.fx(), c.fy(), c.cx(), c.cy()), (i.fx, i.fy, i.cx, i.cy));
                }
                Err(e) => feature(err_bit(&e)),
            }
            if let Ok(m) = Motion::new(robot.0, robot.1) {
                match i.camera_motion(&m) {
                    Ok(c) => {
                        feature(22);
                        assert!(
                            finite(&c.translation()) && finite(&c.angles()),
                            "camera_motion: Ok({c:?})"
                        );
                        assert_eq!(
                            i.camera_motion(&m),
                            Ok(c),
                            "camera_motion: not deterministic"
                        );
                    }
                    Err(e) => feature(err_bit(&e)),
                }
            }
        }
    }
    Outcome {
        calls,
        features,
        ..Outcome::default()
    }
}
