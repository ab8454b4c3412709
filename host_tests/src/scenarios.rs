//! The named scenario set and the seeded random scenarios.

use crate::synth::{mv, tr, Drive, Intrinsics, Rng, Road, Scenario};

fn deg(x: f64) -> f64 {
    x.to_radians()
}

/// The named scenarios of the issue, each with the paper's camera (Sec. 3):
/// 512×480, f = 800 px, h = 1, tilt 23°, road width 1.3 h.
pub fn named() -> Vec<Scenario> {
    let w = 1.3;
    let curve = |k: f64| Road {
        curvature_a: k,
        curvature_b: k,
        ..Road::straight(w)
    };
    let follow = |k: f64, d: f64| Drive {
        forward: d,
        yaw: k * d,
        ..Drive::default()
    };
    let mut v = Vec::new();
    // The paper's Fig. 6: robot translation (0, 0, 0.4), steering 5° right,
    // on a road curving right.
    v.push(Scenario::new(
        "fig6",
        curve(1.0 / 15.0),
        Drive {
            forward: 0.4,
            yaw: deg(5.0),
            ..Drive::default()
        },
    ));
    for r in [8.0, 15.0, 30.0, 60.0] {
        v.push(Scenario::new(
            &format!("right_r{r}"),
            curve(1.0 / r),
            follow(1.0 / r, 0.4),
        ));
        v.push(Scenario::new(
            &format!("left_r{r}"),
            curve(-1.0 / r),
            follow(-1.0 / r, 0.4),
        ));
    }
    v.push(Scenario::new(
        "s_curve",
        Road {
            curvature_a: 1.0 / 12.0,
            curvature_b: -1.0 / 12.0,
            switch_at: 5.0,
            ..Road::straight(w)
        },
        follow(1.0 / 12.0, 0.4),
    ));
    v.push(Scenario::new(
        "crest",
        Road {
            curvature_a: 1.0 / 20.0,
            curvature_b: 1.0 / 20.0,
            grade_from: 2.0,
            grade: 0.15,
            vertical_curvature: -0.04,
            ..Road::straight(w)
        },
        follow(1.0 / 20.0, 0.4),
    ));
    v.push(Scenario::new(
        "dip",
        Road {
            curvature_a: -1.0 / 20.0,
            curvature_b: -1.0 / 20.0,
            grade_from: 2.0,
            grade: -0.1,
            vertical_curvature: 0.05,
            ..Road::straight(w)
        },
        follow(-1.0 / 20.0, 0.4),
    ));
    v.push(Scenario::new(
        "lateral_u",
        curve(1.0 / 20.0),
        Drive {
            forward: 0.3,
            lateral: 0.15,
            yaw: deg(1.0),
            ..Drive::default()
        },
    ));
    v.push(Scenario::new(
        "vertical_v",
        curve(-1.0 / 20.0),
        Drive {
            forward: 0.3,
            up: 0.08,
            ..Drive::default()
        },
    ));
    v.push(Scenario::new(
        "backward",
        curve(1.0 / 15.0),
        Drive {
            forward: -0.4,
            yaw: -0.4 / 15.0,
            ..Drive::default()
        },
    ));
    // Pure sideways camera translation: W = 0, FOE at infinity (eq. 3.3).
    let mut lateral = Scenario::new("pure_lateral_w0", curve(1.0 / 20.0), Drive::default());
    lateral.camera_motion = Some(([0.2, 0.0, 0.0], [0.0, 0.0, 0.0]));
    v.push(lateral);
    v
}

/// The degenerate scenario: a straight road driven straight along its axis.
pub fn degenerate() -> Scenario {
    Scenario::new(
        "straight_degenerate",
        Road::straight(1.3),
        Drive {
            forward: 0.4,
            ..Drive::default()
        },
    )
}

/// A seeded random scenario: curvature, S-bends, crests/dips, steering,
/// motion (occasionally backwards or purely sideways), road width, tilt and
/// camera height all drawn at random.
pub fn random(seed: u64) -> Scenario {
    let mut g = Rng(seed.wrapping_mul(0x2545_F491_4F6C_DD1D).wrapping_add(7));
    let k1 = g.uniform(-1.0 / 8.0, 1.0 / 8.0);
    let k2 = if g.chance(0.3) { -k1 } else { k1 };
    let crest = g.chance(0.4);
    let road = Road {
        width: g.uniform(1.0, 1.8),
        curvature_a: k1,
        curvature_b: k2,
        switch_at: g.uniform(3.0, 10.0),
        grade_from: g.uniform(1.0, 6.0),
        grade: if crest { g.uniform(-0.15, 0.15) } else { 0.0 },
        vertical_curvature: if crest { g.uniform(-0.06, 0.06) } else { 0.0 },
        centre_offset: g.uniform(-0.3, 0.3),
        heading: deg(g.uniform(-4.0, 4.0)),
    };
    let mut forward = g.uniform(0.1, 0.6);
    if g.chance(0.1) {
        forward = -forward;
    }
    let drive = Drive {
        forward,
        lateral: g.uniform(-0.1, 0.1),
        up: g.uniform(-0.04, 0.04),
        yaw: k1 * forward + deg(g.uniform(-3.0, 3.0)),
        pitch: deg(g.uniform(-1.0, 1.0)),
        roll: deg(g.uniform(-1.0, 1.0)),
    };
    let mut s = Scenario::new(&format!("random_{seed}"), road, drive);
    s.tilt = deg(g.uniform(15.0, 30.0));
    s.height = g.uniform(0.7, 1.5);
    if g.chance(0.05) {
        s.camera_motion = Some(([g.uniform(0.1, 0.3), 0.0, 0.0], [0.0, 0.0, 0.0]));
    }
    s
}

/// A named family of seeded random scenarios for the certification run
/// (`tests/certify.rs`): each family draws its own parameters from its own
/// generator, so a family's scenarios do not change when another family is
/// added or edited.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Family {
    /// The paper's Fig. 6 set-up: right curve of radius 12–20, forward
    /// 0.3–0.5, steering 4–6° right, h = 1, tilt 23°, width 1.3.
    Fig6,
    /// Right curves of radius 8–60, driven along the curve.
    CurveRight,
    /// Left curves of radius 8–60.
    CurveLeft,
    /// S-bends: the curvature changes sign 3–10 ahead.
    SBend,
    /// Crests and dips: grade ±0.15, vertical curvature ±0.02–0.06.
    CrestDip,
    /// Steering 2–5° either way beyond the road's own turn.
    Steering,
    /// Lateral motion 0.05–0.2 either way with forward motion.
    Lateral,
    /// Driving backwards 0.1–0.6.
    Backward,
    /// Purely sideways camera translation (`W = 0`, no rotation): the FOE
    /// at infinity, ordinary stereo (eq. 3.3).
    SidewaysW0,
    /// The FOE far away but finite: sideways motion with a tiny rotation,
    /// or a tiny forward component (`|W| ≤ 2 %` of the travel).
    FarFoe,
    /// The paper's calibrated camera (non-square pixels, off-centre
    /// principal point), general random roads and motion.
    CalibratedCamera,
    /// Rotations up to 5° about each axis.
    Rotation5,
    /// The translation points 10–15° below level towards a boundary: the
    /// FOE sits in the image near (on) a boundary.
    FoeNearBoundary,
    /// The detector reports every 2nd or 3rd row.
    SparseRows,
    /// Short travel (0.03–0.15), a camera tilted 4–10° seeing the road out
    /// to 150: far points with small disparity.
    FarSmallDisparity,
    /// Everything at once: either camera, rows every 1–3, rotations up to
    /// 5°, any road, any motion.
    Mixed,
}

impl Family {
    /// Every family, in report order.
    pub const ALL: [Family; 16] = [
        Family::Fig6,
        Family::CurveRight,
        Family::CurveLeft,
        Family::SBend,
        Family::CrestDip,
        Family::Steering,
        Family::Lateral,
        Family::Backward,
        Family::SidewaysW0,
        Family::FarFoe,
        Family::CalibratedCamera,
        Family::Rotation5,
        Family::FoeNearBoundary,
        Family::SparseRows,
        Family::FarSmallDisparity,
        Family::Mixed,
    ];

    /// Short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Family::Fig6 => "fig6",
            Family::CurveRight => "curve_right",
            Family::CurveLeft => "curve_left",
            Family::SBend => "s_bend",
            Family::CrestDip => "crest_dip",
            Family::Steering => "steering",
            Family::Lateral => "lateral",
            Family::Backward => "backward",
            Family::SidewaysW0 => "sideways_w0",
            Family::FarFoe => "far_foe",
            Family::CalibratedCamera => "calibrated_camera",
            Family::Rotation5 => "rotation_5deg",
            Family::FoeNearBoundary => "foe_near_boundary",
            Family::SparseRows => "sparse_rows",
            Family::FarSmallDisparity => "far_small_disparity",
            Family::Mixed => "mixed",
        }
    }

    /// The family with this name.
    pub fn from_name(name: &str) -> Option<Family> {
        Family::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The family's own generator for scenario `seed`.
    fn rng(self, seed: u64) -> Rng {
        let id = Family::ALL.iter().position(|&f| f == self).unwrap_or(0) as u64;
        let mut g = Rng(seed
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add((id + 1).wrapping_mul(0xD1B5_4A32_D192_ED03)));
        g.next_u64();
        g
    }

    /// Scenario `seed` of this family (named `family/seed`).
    pub fn scenario(self, seed: u64) -> Scenario {
        let mut g = self.rng(seed);
        let mut s = match self {
            Family::Fig6 => {
                let k = 1.0 / g.uniform(12.0, 20.0);
                let road = Road {
                    width: g.uniform(1.2, 1.4),
                    centre_offset: g.uniform(-0.1, 0.1),
                    heading: deg(g.uniform(-1.0, 1.0)),
                    ..curved(k, k)
                };
                let drive = Drive {
                    forward: g.uniform(0.3, 0.5),
                    yaw: deg(g.uniform(4.0, 6.0)),
                    ..Drive::default()
                };
                Scenario::new("", road, drive)
            }
            Family::CurveRight | Family::CurveLeft => {
                let sign = if self == Family::CurveRight {
                    1.0
                } else {
                    -1.0
                };
                let k = sign / g.uniform(8.0, 60.0);
                let road = base_road(&mut g, k, k);
                let drive = follow(&mut g, k, (0.2, 0.6), 1.0);
                base(&mut g, road, drive)
            }
            Family::SBend => {
                let k = sign(&mut g) * g.uniform(1.0 / 30.0, 1.0 / 8.0);
                let mut road = base_road(&mut g, k, -k);
                road.switch_at = g.uniform(3.0, 10.0);
                let drive = follow(&mut g, k, (0.2, 0.6), 1.0);
                base(&mut g, road, drive)
            }
            Family::CrestDip => {
                let k = g.uniform(-1.0 / 30.0, 1.0 / 30.0);
                let mut road = base_road(&mut g, k, k);
                road.grade_from = g.uniform(1.0, 6.0);
                road.grade = g.uniform(-0.15, 0.15);
                road.vertical_curvature = sign(&mut g) * g.uniform(0.02, 0.06);
                let drive = follow(&mut g, k, (0.2, 0.6), 1.0);
                base(&mut g, road, drive)
            }
            Family::Steering => {
                let k = g.uniform(-1.0 / 15.0, 1.0 / 15.0);
                let road = base_road(&mut g, k, k);
                let mut drive = follow(&mut g, k, (0.2, 0.6), 0.0);
                drive.yaw += deg(sign(&mut g) * g.uniform(2.0, 5.0));
                base(&mut g, road, drive)
            }
            Family::Lateral => {
                let k = g.uniform(-1.0 / 20.0, 1.0 / 20.0);
                let road = base_road(&mut g, k, k);
                let mut drive = follow(&mut g, k, (0.2, 0.5), 1.0);
                drive.lateral = sign(&mut g) * g.uniform(0.05, 0.2);
                drive.up = g.uniform(-0.04, 0.04);
                base(&mut g, road, drive)
            }
            Family::Backward => {
                let k = g.uniform(-1.0 / 10.0, 1.0 / 10.0);
                let road = base_road(&mut g, k, k);
                let drive = follow(&mut g, k, (-0.6, -0.1), 1.0);
                base(&mut g, road, drive)
            }
            Family::SidewaysW0 => {
                let k = g.uniform(-1.0 / 10.0, 1.0 / 10.0);
                let road = base_road(&mut g, k, k);
                let mut s = base(&mut g, road, Drive::default());
                let t = [
                    sign(&mut g) * g.uniform(0.1, 0.3),
                    g.uniform(-0.05, 0.05),
                    0.0,
                ];
                s.camera_motion = Some((t, [0.0; 3]));
                s
            }
            Family::FarFoe => {
                let k = g.uniform(-1.0 / 10.0, 1.0 / 10.0);
                let road = base_road(&mut g, k, k);
                let mut s = base(&mut g, road, Drive::default());
                let u = sign(&mut g) * g.uniform(0.1, 0.3);
                let v = g.uniform(-0.05, 0.05);
                let motion = if g.chance(0.5) {
                    // W = 0 and a tiny rotation (1e-6 to 1e-3 rad per axis).
                    let mut tiny = || sign(&mut g) * 10f64.powf(g.uniform(-6.0, -3.0));
                    ([u, v, 0.0], [tiny(), tiny(), tiny()])
                } else {
                    // No rotation and a tiny forward or backward component.
                    let w = u.abs() * g.uniform(-0.02, 0.02);
                    ([u, v, w], [0.0; 3])
                };
                s.camera_motion = Some(motion);
                s
            }
            Family::CalibratedCamera => {
                let mut s = general(&mut g);
                s.intrinsics = Intrinsics::paper_calibrated();
                s
            }
            Family::Rotation5 => {
                let mut s = general(&mut g);
                let k = s.road.curvature_a;
                s.drive.yaw = k * s.drive.forward + deg(g.uniform(-5.0, 5.0));
                s.drive.pitch = deg(g.uniform(-5.0, 5.0));
                s.drive.roll = deg(g.uniform(-5.0, 5.0));
                s
            }
            Family::FoeNearBoundary => foe_near_boundary(&mut g),
            Family::SparseRows => {
                let mut s = general(&mut g);
                s.row_step = if g.chance(0.5) { 2 } else { 3 };
                s.row_phase = (g.next_u64() % u64::from(s.row_step)) as u16;
                s
            }
            Family::FarSmallDisparity => {
                let k = g.uniform(-1.0 / 100.0, 1.0 / 100.0);
                let road = Road {
                    width: g.uniform(1.0, 1.8),
                    centre_offset: g.uniform(-0.3, 0.3),
                    heading: deg(g.uniform(-2.0, 2.0)),
                    ..curved(k, k)
                };
                let forward = g.uniform(0.03, 0.15);
                let drive = Drive {
                    forward,
                    lateral: g.uniform(-0.01, 0.01),
                    yaw: k * forward + deg(g.uniform(-0.3, 0.3)),
                    pitch: deg(g.uniform(-0.2, 0.2)),
                    roll: deg(g.uniform(-0.2, 0.2)),
                    ..Drive::default()
                };
                let mut s = Scenario::new("", road, drive);
                s.tilt = deg(g.uniform(4.0, 10.0));
                s.height = g.uniform(1.0, 1.5);
                s.range = 150.0;
                s
            }
            Family::Mixed => {
                let mut s = general(&mut g);
                if g.chance(0.5) {
                    s.intrinsics = Intrinsics::paper_calibrated();
                }
                s.row_step = 1 + (g.next_u64() % 3) as u16;
                s.row_phase = (g.next_u64() % u64::from(s.row_step)) as u16;
                if g.chance(0.5) {
                    s.drive.yaw += deg(g.uniform(-5.0, 5.0));
                    s.drive.pitch = deg(g.uniform(-5.0, 5.0));
                    s.drive.roll = deg(g.uniform(-5.0, 5.0));
                }
                s
            }
        };
        s.name = format!("{}/{seed}", self.name());
        s
    }
}

fn sign(g: &mut Rng) -> f64 {
    if g.chance(0.5) {
        1.0
    } else {
        -1.0
    }
}

fn curved(ka: f64, kb: f64) -> Road {
    Road {
        curvature_a: ka,
        curvature_b: kb,
        ..Road::straight(1.3)
    }
}

/// A road of random width, offset and heading with the given curvatures.
fn base_road(g: &mut Rng, ka: f64, kb: f64) -> Road {
    Road {
        width: g.uniform(1.0, 1.8),
        centre_offset: g.uniform(-0.3, 0.3),
        heading: deg(g.uniform(-4.0, 4.0)),
        ..curved(ka, kb)
    }
}

/// Driving `forward` along a road of curvature `k`, the heading off by up
/// to `yaw_noise_deg`, with suspension pitch and roll up to 1°.
fn follow_drive(g: &mut Rng, k: f64, forward: f64, yaw_noise_deg: f64) -> Drive {
    Drive {
        forward,
        yaw: k * forward + deg(g.uniform(-yaw_noise_deg, yaw_noise_deg)),
        pitch: deg(g.uniform(-1.0, 1.0)),
        roll: deg(g.uniform(-1.0, 1.0)),
        ..Drive::default()
    }
}

/// [`follow_drive`] with the distance drawn from `forward`'s range.
fn follow(g: &mut Rng, k: f64, forward: (f64, f64), yaw_noise_deg: f64) -> Drive {
    let d = g.uniform(forward.0, forward.1);
    follow_drive(g, k, d, yaw_noise_deg)
}

/// A scenario with a random camera mounting (height 0.7–1.5, tilt 15–30°).
fn base(g: &mut Rng, road: Road, drive: Drive) -> Scenario {
    let mut s = Scenario::new("", road, drive);
    s.tilt = deg(g.uniform(15.0, 30.0));
    s.height = g.uniform(0.7, 1.5);
    s
}

/// Any road (curves, S-bends, crests and dips) and any motion (steering,
/// lateral and vertical, backwards 10 %), like [`random`].
fn general(g: &mut Rng) -> Scenario {
    let k1 = g.uniform(-1.0 / 8.0, 1.0 / 8.0);
    let k2 = if g.chance(0.3) { -k1 } else { k1 };
    let mut road = base_road(g, k1, k2);
    road.switch_at = g.uniform(3.0, 10.0);
    if g.chance(0.4) {
        road.grade_from = g.uniform(1.0, 6.0);
        road.grade = g.uniform(-0.15, 0.15);
        road.vertical_curvature = g.uniform(-0.06, 0.06);
    }
    let mut forward = g.uniform(0.1, 0.6);
    if g.chance(0.1) {
        forward = -forward;
    }
    let mut drive = follow_drive(g, k1, forward, 3.0);
    drive.lateral = g.uniform(-0.1, 0.1);
    drive.up = g.uniform(-0.04, 0.04);
    base(g, road, drive)
}

/// The translation points `δ` = 10–15° below level, turned towards a point
/// of one boundary `h / tan δ` ahead (± 1.5°): the FOE is the image of that
/// ground point, on or near the boundary. Small rotations (±1°).
fn foe_near_boundary(g: &mut Rng) -> Scenario {
    let k = g.uniform(-1.0 / 15.0, 1.0 / 15.0);
    let road = base_road(g, k, k);
    let mut s = Scenario::new("", road, Drive::default());
    let delta = deg(g.uniform(10.0, 15.0));
    s.height = g.uniform(0.8, 1.5);
    // The FOE `tilt − δ` above the optical axis: 3–13°, inside the image.
    s.tilt = delta + deg(g.uniform(3.0, 13.0));
    let ahead = s.height / delta.tan();
    let side = (g.next_u64() % 2) as usize;
    let curve = &s.road.boundaries(0.0, ahead + 1.0, 0.01)[side];
    let target = curve
        .iter()
        .min_by(|a, b| (a[2] - ahead).abs().total_cmp(&(b[2] - ahead).abs()))
        .copied()
        .unwrap_or([0.0, 0.0, ahead]);
    let psi = target[0].atan2(target[2]) + deg(g.uniform(-1.5, 1.5));
    let travel = g.uniform(0.2, 0.5);
    let world_dir = [
        psi.sin() * delta.cos(),
        delta.sin(), // y down: below level
        psi.cos() * delta.cos(),
    ];
    let t = mv(&tr(&s.pose1().rot), world_dir).map(|x| x * travel);
    let angles = [0, 1, 2].map(|_| deg(g.uniform(-1.0, 1.0)));
    s.camera_motion = Some((t, angles));
    s
}
