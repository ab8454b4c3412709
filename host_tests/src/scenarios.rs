//! The named scenario set and the seeded random scenarios.

use crate::synth::{Drive, Rng, Road, Scenario};

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
