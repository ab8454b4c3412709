//! Seeded multi-frame drives with ground truth, for the fusion tests
//! (issue 13): a road from the scenario families, a vehicle driving along
//! it frame after frame with steering, lateral and pitch wobble, the
//! detector's boundaries in every frame (rounded to the pixel grid or moved
//! by disc noise), the per-frame motions, and per key-frame point the true
//! depth and, per later frame, whether its correspondent is in that frame's
//! data. All of it from the generator's own `f64` geometry
//! ([`crate::synth`]); the fusion is run through the library's public API
//! ([`run`]) and every record compared with that truth by the tests.

use roadstereo::fusion::{ChainedMotion, FusedPoint, Fusion, FusionConfig, FusionStep};
use roadstereo::{Config, Frame, Motion, Pixel, Status};

use crate::certify::deviation_bound;
use crate::synth::{self, add, mm, mv, sub, tr, Intrinsics, Pose, Rng, Road, TruePoint, M3, V3};
use crate::{B, N};

/// Map capacity per boundary in the host runs.
pub const M: usize = 1024;

/// The host's fusion.
pub type HostFusion = Fusion<N, B, M>;

/// A family of drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum DriveFamily {
    /// The paper's Fig. 6 set-up (camera h = 1, tilt 23°, f = 800, a right
    /// curve of radius 12–20, width 1.2–1.4) driven 0.3–0.5 per frame along
    /// the curve, steering wobble ±2°.
    Fig6,
    /// Right curves of radius 8–60.
    CurveRight,
    /// Left curves of radius 8–60.
    CurveLeft,
    /// S-bends: the curvature changes sign 3–10 ahead.
    SBend,
    /// Crests and dips.
    CrestDip,
    /// Steering wobble of 2–5° about the road's heading.
    Steering,
    /// Lateral wobble of 0.05–0.2 across the lane.
    Lateral,
    /// The paper's calibrated camera, any road.
    CalibratedCamera,
    /// Frames between the two frames of a two-view scenario
    /// ([`Drive::through_scenario`]); not a random family.
    Scenario,
}

impl DriveFamily {
    /// Every family, in report order.
    pub const ALL: [DriveFamily; 8] = [
        DriveFamily::Fig6,
        DriveFamily::CurveRight,
        DriveFamily::CurveLeft,
        DriveFamily::SBend,
        DriveFamily::CrestDip,
        DriveFamily::Steering,
        DriveFamily::Lateral,
        DriveFamily::CalibratedCamera,
    ];

    pub fn name(self) -> &'static str {
        match self {
            DriveFamily::Fig6 => "fig6",
            DriveFamily::CurveRight => "curve_right",
            DriveFamily::CurveLeft => "curve_left",
            DriveFamily::SBend => "s_bend",
            DriveFamily::CrestDip => "crest_dip",
            DriveFamily::Steering => "steering",
            DriveFamily::Lateral => "lateral",
            DriveFamily::CalibratedCamera => "calibrated_camera",
            DriveFamily::Scenario => "scenario",
        }
    }
}

/// A drive: road, camera mounting, and the vehicle's path.
#[derive(Debug, Clone)]
pub struct DriveSpec {
    pub name: String,
    pub family: DriveFamily,
    pub intrinsics: Intrinsics,
    pub road: Road,
    pub height: f64,
    pub tilt: f64,
    pub frames: usize,
    /// Arc length of the first frame and travel per frame.
    pub start: f64,
    pub step: f64,
    /// The heading's offset from the road's, into the curve (radians).
    pub yaw_bias: f64,
    /// Amplitudes of the wobble: heading (radians), lateral offset, pitch
    /// (radians), and their phase.
    pub yaw_wobble: f64,
    pub lateral_wobble: f64,
    pub pitch_wobble: f64,
    pub phase: f64,
    /// How far ahead the road is detected.
    pub range: f64,
}

fn deg(x: f64) -> f64 {
    x.to_radians()
}

fn sign(g: &mut Rng) -> f64 {
    if g.chance(0.5) {
        1.0
    } else {
        -1.0
    }
}

impl DriveSpec {
    /// Drive `seed` of `family` (`frames` frames).
    pub fn new(family: DriveFamily, seed: u64, frames: usize) -> DriveSpec {
        let id = DriveFamily::ALL
            .iter()
            .position(|&f| f == family)
            .unwrap_or(0) as u64;
        let mut g = Rng(seed
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add((id + 11).wrapping_mul(0xD1B5_4A32_D192_ED03)));
        g.next_u64();
        let base_road = |g: &mut Rng, ka: f64, kb: f64| Road {
            width: g.uniform(1.0, 1.8),
            curvature_a: ka,
            curvature_b: kb,
            centre_offset: g.uniform(-0.2, 0.2),
            heading: deg(g.uniform(-2.0, 2.0)),
            ..Road::straight(1.3)
        };
        let mut s = DriveSpec {
            name: format!("{}/{seed}", family.name()),
            family,
            intrinsics: Intrinsics::default(),
            road: Road::straight(1.3),
            height: 1.0,
            tilt: deg(23.0),
            frames,
            start: 0.0,
            step: 0.4,
            yaw_bias: 0.0,
            yaw_wobble: deg(1.0),
            lateral_wobble: 0.05,
            pitch_wobble: deg(0.3),
            phase: g.uniform(0.0, std::f64::consts::TAU),
            range: 60.0,
        };
        let mounting = |s: &mut DriveSpec, g: &mut Rng| {
            s.height = g.uniform(0.8, 1.4);
            s.tilt = deg(g.uniform(17.0, 28.0));
            s.step = g.uniform(0.2, 0.5);
        };
        match family {
            DriveFamily::Fig6 => {
                let k = 1.0 / g.uniform(12.0, 20.0);
                s.road = Road {
                    width: g.uniform(1.2, 1.4),
                    centre_offset: g.uniform(-0.1, 0.1),
                    curvature_a: k,
                    curvature_b: k,
                    ..Road::straight(1.3)
                };
                s.step = g.uniform(0.3, 0.5);
                s.yaw_wobble = deg(2.0);
                s.lateral_wobble = 0.03;
            }
            DriveFamily::CurveRight | DriveFamily::CurveLeft => {
                let sg = if family == DriveFamily::CurveRight {
                    1.0
                } else {
                    -1.0
                };
                let k = sg / g.uniform(8.0, 60.0);
                s.road = base_road(&mut g, k, k);
                mounting(&mut s, &mut g);
            }
            DriveFamily::SBend => {
                let k = sign(&mut g) * g.uniform(1.0 / 30.0, 1.0 / 10.0);
                s.road = base_road(&mut g, k, -k);
                s.road.switch_at = g.uniform(3.0, 10.0);
                mounting(&mut s, &mut g);
            }
            DriveFamily::CrestDip => {
                let k = g.uniform(-1.0 / 30.0, 1.0 / 30.0);
                s.road = base_road(&mut g, k, k);
                s.road.grade_from = g.uniform(1.0, 6.0);
                s.road.grade = g.uniform(-0.12, 0.12);
                s.road.vertical_curvature = sign(&mut g) * g.uniform(0.02, 0.05);
                mounting(&mut s, &mut g);
            }
            DriveFamily::Steering => {
                let k = g.uniform(-1.0 / 15.0, 1.0 / 15.0);
                s.road = base_road(&mut g, k, k);
                mounting(&mut s, &mut g);
                s.yaw_wobble = deg(g.uniform(2.0, 5.0));
            }
            DriveFamily::Lateral => {
                let k = g.uniform(-1.0 / 20.0, 1.0 / 20.0);
                s.road = base_road(&mut g, k, k);
                mounting(&mut s, &mut g);
                s.lateral_wobble = g.uniform(0.05, 0.2);
            }
            DriveFamily::Scenario => {}
            DriveFamily::CalibratedCamera => {
                let k1 = g.uniform(-1.0 / 10.0, 1.0 / 10.0);
                let k2 = if g.chance(0.3) { -k1 } else { k1 };
                s.road = base_road(&mut g, k1, k2);
                s.road.switch_at = g.uniform(3.0, 10.0);
                mounting(&mut s, &mut g);
                s.intrinsics = Intrinsics::paper_calibrated();
            }
        }
        // The driver looks into the curve: the heading leads the road's by
        // the turn over 1.5 units, which keeps both edges in view.
        s.yaw_bias = 1.5 * s.road.curvature_a;
        s
    }

    /// The camera pose of frame `i`.
    pub fn pose(&self, i: usize) -> Pose {
        let sarc = self.start + self.step * i as f64;
        let (c, psi, grade) = self.road.centre_at(sarc, 0.01);
        let t = i as f64 * 0.7 + self.phase;
        let lateral = self.lateral_wobble * (0.6 * t).sin();
        let pos = [c[0] + lateral * psi.cos(), c[1], c[2] - lateral * psi.sin()];
        let yaw = psi + self.yaw_bias + self.yaw_wobble * t.sin();
        let pitch = grade.atan() + self.pitch_wobble * (1.3 * t).cos();
        Pose::vehicle_camera_pitched(pos, yaw, pitch, self.height, self.tilt)
    }

    /// Render the drive; `None` when some frame does not see both
    /// boundaries (at least 2 points each).
    pub fn render(&self) -> Option<Drive> {
        let travel = self.step * self.frames as f64;
        let world = self.road.boundaries(2.0, self.range + travel + 2.0, 0.01);
        let k = self.intrinsics;
        let mut frames = Vec::new();
        for i in 0..self.frames {
            let pose = self.pose(i);
            let mut bs = Vec::new();
            for curve in &world {
                let b = synth::detect(curve, &pose, &k, self.range);
                if b.len() < 2 {
                    return None;
                }
                bs.push(b);
            }
            frames.push(DriveFrame {
                pose,
                boundaries: bs,
            });
        }
        let motions = (1..frames.len())
            .map(|i| frames[i - 1].pose.motion_to(&frames[i].pose))
            .collect();
        Some(Drive {
            spec: self.clone(),
            world: world.to_vec(),
            frames,
            motions,
        })
    }
}

/// The paper's Fig. 6 set-up as a drive of `frames` frames: the camera
/// of Sec. 3 (h = 1, tilt 23°, f = 800), the right curve of radius 15 and
/// width 1.3, 0.4 forward a frame along it, the heading leading the
/// road's by the turn over 1.5 and wobbling ±2°.
pub fn fig6_drive(frames: usize) -> Drive {
    let mut s = DriveSpec::new(DriveFamily::Fig6, 0, frames);
    s.name = "fig6 (r = 15, 0.4 a frame)".into();
    s.road = Road {
        curvature_a: 1.0 / 15.0,
        curvature_b: 1.0 / 15.0,
        ..Road::straight(1.3)
    };
    s.step = 0.4;
    s.yaw_bias = 1.5 / 15.0;
    s.render().expect("both edges in view")
}

/// One frame of a rendered drive.
#[derive(Debug, Clone)]
pub struct DriveFrame {
    pub pose: Pose,
    /// Per boundary (0 left, 1 right), the detector's true points.
    pub boundaries: Vec<Vec<TruePoint>>,
}

/// A rendered drive.
#[derive(Debug, Clone)]
pub struct Drive {
    pub spec: DriveSpec,
    /// The world curve of each boundary.
    pub world: Vec<Vec<V3>>,
    pub frames: Vec<DriveFrame>,
    /// `motions[i]`: (translation, angles) from frame `i` to frame `i + 1`.
    pub motions: Vec<(V3, V3)>,
}

/// How the detector reports the points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Noise {
    /// `u` rounded to the pixel grid.
    Rounded,
    /// Moved by a random vector shorter than 0.999 × 0.5 px.
    Disc,
}

impl Noise {
    pub fn name(self) -> &'static str {
        match self {
            Noise::Rounded => "rounded",
            Noise::Disc => "disc",
        }
    }
}

/// The motion errors given to the pipeline (none, or random within a box
/// that the configuration declares).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionNoise {
    /// Per component of each frame's translation, length units.
    pub delta: f64,
    /// Per axis of each frame's rotation (rotation vector about the new
    /// camera's axes), radians.
    pub eps: f64,
}

/// The rotation with rotation vector `w` (Rodrigues).
pub fn exp_rotation(w: V3) -> M3 {
    let th = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    let mut m = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if th == 0.0 {
        return m;
    }
    let k = [w[0] / th, w[1] / th, w[2] / th];
    let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    let kk = mm(&kx, &kx);
    let (s, c) = th.sin_cos();
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] += s * kx[i][j] + (1.0 - c) * kk[i][j];
        }
    }
    m
}

fn angles_of(r: &M3) -> V3 {
    [
        (-r[1][2]).clamp(-1.0, 1.0).asin(),
        r[0][2].atan2(r[2][2]),
        r[1][0].atan2(r[1][1]),
    ]
}

/// The detector output and motions given to the library for one variant.
#[derive(Debug, Clone)]
pub struct Input {
    pub noise: Noise,
    pub frames: Vec<Vec<Vec<Pixel>>>,
    /// The motions given (`given[i]`: frame `i` to `i + 1`), in `f32`.
    pub given: Vec<Motion>,
    /// The declared errors: `e₁ = 0.5`, `e₂ = 0.5` + the chord allowance.
    pub e1: f64,
    pub e2: f64,
    pub motion_noise: Option<MotionNoise>,
}

impl Input {
    /// The processor configuration declaring the errors.
    pub fn config(&self) -> Config {
        let mut c = Config::new(self.e1 as f32, self.e2 as f32, 10.0, 1000.0).expect("config");
        if let Some(m) = self.motion_noise {
            c = c
                .with_translation_error(m.delta as f32)
                .expect("translation bound")
                .with_rotation_error([m.eps as f32; 3])
                .expect("rotation bound")
                // With motion errors the bands are wide: the largest
                // budget, as the two-view motion-error tests use.
                .with_work_budget(Config::MAX_WORK_PER_POINT)
                .expect("work budget");
        }
        c
    }

    pub fn frame(&self, k: &Intrinsics, i: usize) -> Frame<N, B> {
        let mut f = Frame::new(k.camera());
        for b in &self.frames[i] {
            // (An empty polyline: the boundary marked absent.)
            if b.is_empty() {
                f.push_absent().expect("a free slot");
            } else {
                f.push_boundary(b).expect("valid boundary");
            }
        }
        f
    }
}

/// Grid of the chord allowance, pixels (as the certification's).
const ALLOWANCE_STEP: f64 = 0.005;

impl Drive {
    /// The two frames of a two-view scenario with frames between them: the
    /// camera moved by the fraction `t` of the scenario's motion (its
    /// translation and its angles scaled by `t`) for each `t` of
    /// `fractions` (0 and 1 are the scenario's own frames). The boundaries
    /// seen (2 points or more) in every frame are kept. `None` if none is.
    pub fn through_scenario(sc: &synth::Scenario, fractions: &[f64]) -> Option<Drive> {
        let r = sc.render();
        let k = sc.intrinsics;
        let rows = sc.rows();
        let poses: Vec<Pose> = fractions
            .iter()
            .map(|&t| {
                r.pose1
                    .moved(r.translation.map(|x| x * t), r.angles.map(|x| x * t))
            })
            .collect();
        let mut world = Vec::new();
        let mut per_frame: Vec<Vec<Vec<TruePoint>>> = vec![Vec::new(); poses.len()];
        for curve in r.world.iter() {
            let seen: Vec<Vec<TruePoint>> = poses
                .iter()
                .map(|p| synth::detect_rows(curve, p, &k, sc.range, &rows))
                .collect();
            if seen.iter().all(|b| b.len() >= 2) {
                world.push(curve.clone());
                for (f, b) in per_frame.iter_mut().zip(seen) {
                    f.push(b);
                }
            }
        }
        if world.is_empty() {
            return None;
        }
        let frames: Vec<DriveFrame> = poses
            .into_iter()
            .zip(per_frame)
            .map(|(pose, boundaries)| DriveFrame { pose, boundaries })
            .collect();
        let motions = (1..frames.len())
            .map(|i| frames[i - 1].pose.motion_to(&frames[i].pose))
            .collect();
        let spec = DriveSpec {
            name: sc.name.clone(),
            family: DriveFamily::Scenario,
            intrinsics: k,
            road: sc.road,
            height: sc.height,
            tilt: sc.tilt,
            frames: frames.len(),
            start: 0.0,
            step: 0.0,
            yaw_bias: 0.0,
            yaw_wobble: 0.0,
            lateral_wobble: 0.0,
            pitch_wobble: 0.0,
            phase: 0.0,
            range: sc.range,
        };
        Some(Drive {
            spec,
            world,
            frames,
            motions,
        })
    }

    /// Whether the 3-D point of key frame `key`'s point `i` on boundary `b`
    /// is within the stretch frame `j` detected (its correspondent is in
    /// frame `j`'s data).
    pub fn observed(&self, key: usize, b: usize, i: usize, j: usize) -> bool {
        let p = &self.frames[key].boundaries[b][i];
        let bj = &self.frames[j].boundaries[b];
        let (a, z) = (bj[0].arc, bj[bj.len() - 1].arc);
        let (lo, hi) = (a.min(z), a.max(z));
        (lo..=hi).contains(&p.arc)
    }

    /// Upper bound of the distance of the true image curve from the
    /// polyline of the exact detected points, over every frame after the
    /// first (the chords' sagitta: what `e₂` must add).
    pub fn sagitta(&self) -> f64 {
        let k = &self.spec.intrinsics;
        let mut worst = 0.0f64;
        for f in self.frames.iter().skip(1) {
            for (b, pts) in f.boundaries.iter().enumerate() {
                let curve = &self.world[b];
                let (a, z) = (pts[0].arc, pts[pts.len() - 1].arc);
                let (lo, hi) = (a.min(z), a.max(z));
                let mut c = vec![[pts[0].u, pts[0].v]];
                // The curve's vertices strictly inside the stretch, in the
                // order of the detected points.
                let mut inner: Vec<[f64; 2]> = curve
                    .iter()
                    .enumerate()
                    .filter(|(s, _)| (*s as f64) > lo && (*s as f64) < hi)
                    .filter_map(|(_, w)| k.project(f.pose.to_camera(*w)))
                    .collect();
                if a > z {
                    inner.reverse();
                }
                c.extend(inner);
                let last = pts[pts.len() - 1];
                c.push([last.u, last.v]);
                let exact: Vec<[f64; 2]> = pts.iter().map(|p| [p.u, p.v]).collect();
                worst = worst.max(deviation_bound(&c, &exact));
            }
        }
        worst
    }

    /// The detector output and the motions for `noise`, with motion errors
    /// if `motion_noise` is given.
    pub fn input(&self, noise: Noise, motion_noise: Option<MotionNoise>, seed: u64) -> Input {
        let mut g = Rng(seed ^ 0x5EED_F00D_u64.wrapping_mul(noise as u64 + 1));
        let k = self.spec.intrinsics;
        let rho = 0.999 * 0.5;
        let mut frames = Vec::new();
        for f in &self.frames {
            let mut bs = Vec::new();
            for pts in &f.boundaries {
                let b: Vec<Pixel> = match noise {
                    Noise::Rounded => pts
                        .iter()
                        .map(|p| Pixel::new(p.u.round() as f32, p.v as f32))
                        .collect(),
                    Noise::Disc => {
                        let moves: Vec<(f64, f64)> = pts
                            .iter()
                            .map(|_| {
                                (
                                    rho * g.uniform(0.0, 1.0).sqrt(),
                                    g.uniform(0.0, std::f64::consts::TAU),
                                )
                            })
                            .collect();
                        let out: Vec<Pixel> = pts
                            .iter()
                            .zip(&moves)
                            .map(|(p, (r, a))| {
                                Pixel::new((p.u + r * a.cos()) as f32, (p.v + r * a.sin()) as f32)
                            })
                            .collect();
                        let mut f = Frame::<N, B>::new(k.camera());
                        if f.push_boundary(&out).is_ok() {
                            out
                        } else {
                            // Along the row instead (keeps the row order).
                            pts.iter()
                                .zip(&moves)
                                .map(|(p, (r, a))| {
                                    Pixel::new((p.u + r * a.cos().signum()) as f32, p.v as f32)
                                })
                                .collect()
                        }
                    }
                };
                bs.push(b);
            }
            frames.push(bs);
        }
        let given = self
            .motions
            .iter()
            .map(|&(t, a)| {
                let (t, a) = match motion_noise {
                    None => (t, a),
                    Some(mn) => {
                        // The true motion is (t, R); the given one is off
                        // by d in t and by Ω in R (R = R_given Ω, Ω about
                        // the new camera's axes), each inside the box.
                        let d = [0, 1, 2].map(|_| mn.delta * g.uniform(-1.0, 1.0));
                        let w = [0, 1, 2].map(|_| mn.eps * g.uniform(-1.0, 1.0));
                        let r = synth::rotation(a);
                        let given_r = mm(&r, &tr(&exp_rotation(w)));
                        (add(t, d), angles_of(&given_r))
                    }
                };
                Motion::new(t.map(|x| x as f32), a.map(|x| x as f32)).expect("valid motion")
            })
            .collect();
        let allowance = (self.sagitta() / ALLOWANCE_STEP).ceil() * ALLOWANCE_STEP + ALLOWANCE_STEP;
        Input {
            noise,
            frames,
            given,
            e1: 0.5,
            e2: 0.5 + allowance,
            motion_noise,
        }
    }

    /// The true depth of key frame `key`'s point `i` on boundary `b`.
    pub fn z_true(&self, key: usize, b: usize, i: usize) -> f64 {
        self.frames[key].boundaries[b][i].camera[2]
    }

    /// World position of a key-frame point.
    pub fn world_point(&self, key: usize, b: usize, i: usize) -> V3 {
        let f = &self.frames[key];
        add(f.pose.centre, mv(&f.pose.rot, f.boundaries[b][i].camera))
    }

    /// A world point in frame `j`'s vehicle frame (camera frame turned by
    /// the tilt: `x` right, `y` down, `z` forward).
    pub fn in_vehicle(&self, j: usize, w: V3) -> V3 {
        let c = self.frames[j].pose.to_camera(w);
        let (s, co) = self.spec.tilt.sin_cos();
        [c[0], co * c[1] + s * c[2], -s * c[1] + co * c[2]]
    }

    /// Distance from `q` to the segment `a b` in 3-D.
    pub fn segment_distance(q: V3, a: V3, b: V3) -> f64 {
        let d = sub(b, a);
        let l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let w = sub(q, a);
        let t = if l2 > 0.0 {
            ((w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let e = sub(w, [t * d[0], t * d[1], t * d[2]]);
        (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt()
    }
}

/// One pair's result for one key-frame point.
#[derive(Debug, Clone, Copy)]
pub struct PairPoint {
    pub status: Status,
    pub z_near: f64,
    pub z_far: f64,
}

/// Everything one key frame went through.
#[derive(Debug, Clone)]
pub struct KeyRecord {
    /// Frame index of the key frame.
    pub key: usize,
    /// Frame index of each partner, in order.
    pub partners: Vec<usize>,
    /// After each partner: every point's fusion (`[partner][boundary][i]`).
    pub fused: Vec<Vec<Vec<FusedPoint>>>,
    /// Each partner's two-view results (`[partner][boundary][i]`).
    pub pairs: Vec<Vec<Vec<PairPoint>>>,
}

/// A whole run: the key frames, each step's report, and the map after
/// each frame (per boundary, the points in the vehicle frame).
#[derive(Debug, Clone)]
pub struct Run {
    pub keys: Vec<KeyRecord>,
    pub steps: Vec<FusionStep>,
}

/// Run the fusion over the input; `each` sees the fusion after every
/// frame (with the frame index and the step's report).
pub fn run(
    d: &Drive,
    input: &Input,
    policy: FusionConfig,
    each: impl FnMut(usize, &FusionStep, &HostFusion),
) -> Run {
    run_within(d, input, policy, None, each)
}

/// [`run`] with the counting rule for folded points on
/// (`Fusion::set_fold_counting`).
pub fn run_counted(
    d: &Drive,
    input: &Input,
    policy: FusionConfig,
    each: impl FnMut(usize, &FusionStep, &HostFusion),
) -> Run {
    run_with(d, input, (policy, true), None, each)
}

/// [`run`] with every frame's step within a deadline
/// (`Fusion::step_within`) whose clock says the time is up from its
/// `k`-th question on, when `cut` is `Some(k)`.
pub fn run_within(
    d: &Drive,
    input: &Input,
    policy: FusionConfig,
    cut: Option<usize>,
    each: impl FnMut(usize, &FusionStep, &HostFusion),
) -> Run {
    run_with(d, input, (policy, false), cut, each)
}

/// [`run_within`], the counting rule on or off.
fn run_with(
    d: &Drive,
    input: &Input,
    (policy, counting): (FusionConfig, bool),
    cut: Option<usize>,
    mut each: impl FnMut(usize, &FusionStep, &HostFusion),
) -> Run {
    let k = d.spec.intrinsics;
    let mut fusion = Box::new(HostFusion::new(input.config(), policy));
    fusion.set_fold_counting(counting);
    let mut keys: Vec<KeyRecord> = Vec::new();
    let mut steps = Vec::new();
    for j in 0..d.frames.len() {
        let frame = input.frame(&k, j);
        let motion = (j > 0).then(|| ChainedMotion {
            from: (j - 1) as u32,
            motion: input.given[j - 1],
        });
        let step = match cut {
            None => fusion.step(j as u32, &frame, motion.as_ref()),
            Some(k) => {
                let mut asked = 0usize;
                let mut clock = || {
                    asked += 1;
                    asked > k
                };
                fusion.step_within(j as u32, &frame, motion.as_ref(), &mut clock)
            }
        }
        .expect("frames chain");
        steps.push(step);
        if step.paired.is_some() {
            let key = fusion.key().expect("a key frame");
            let kid = key.id() as usize;
            if keys.last().map(|r| r.key) != Some(kid) {
                keys.push(KeyRecord {
                    key: kid,
                    partners: Vec::new(),
                    fused: Vec::new(),
                    pairs: Vec::new(),
                });
            }
            let rec = keys.last_mut().expect("record");
            rec.partners.push(j);
            rec.fused
                .push((0..B).map(|b| key.points(b).collect()).collect());
            rec.pairs.push(
                fusion
                    .structure()
                    .boundaries()
                    .iter()
                    .map(|bs| {
                        bs.points()
                            .iter()
                            .map(|r| {
                                let iv = r.interval();
                                PairPoint {
                                    status: r.status(),
                                    z_near: iv.map_or(f64::NAN, |i| f64::from(i.z_near)),
                                    z_far: iv.map_or(f64::NAN, |i| f64::from(i.z_far)),
                                }
                            })
                            .collect()
                    })
                    .collect(),
            );
        }
        each(j, &step, &fusion);
    }
    Run { keys, steps }
}

/// The relative width `(z_far − z_near) / z` of an interval.
pub fn relative_width(near: f64, far: f64, z: f64) -> f64 {
    (far - near) / z
}

/// A frame's camera pose after the motion `(t, angles)` (for checks).
pub fn moved(p: &Pose, t: V3, a: V3) -> Pose {
    p.moved(t, a)
}

/// `R` of a pose relative to another (for checks).
pub fn relative(a: &Pose, b: &Pose) -> M3 {
    mm(&tr(&a.rot), &b.rot)
}

/// Counts of one run (or many, added up) against the truth.
#[derive(Debug, Clone, Default)]
pub struct Tally {
    pub drives: usize,
    pub key_frames: usize,
    pub pairs: usize,
    /// Snapshots (after every partner) of points with two or more
    /// agreeing pairs, and of those the ones whose interval holds the truth.
    pub consistent: usize,
    pub consistent_contained: usize,
    /// The same for points with one pair (two-view sticks).
    pub single: usize,
    pub single_contained: usize,
    /// Points inconsistent when their key frame retired (or at the end).
    pub inconsistent: usize,
    /// Snapshots of points the sight check flagged (`PartlyUnseen`), and of
    /// those the ones whose interval holds the truth.
    pub unseen: usize,
    pub unseen_contained: usize,
    /// Snapshots of points the sight check widened (`Widened`: not
    /// flagged), and of those the ones whose interval holds the truth.
    pub widened: usize,
    pub widened_contained: usize,
    /// Two-view sticks (`Ok`) that miss the truth: all, and those whose
    /// correspondent was in the partner frame (a broken guarantee).
    pub wrong_pairs: usize,
    pub wrong_pairs_observed: usize,
    /// What became of the points of the wrong two-view sticks, at the key
    /// frame's end: flagged inconsistent; unflagged and still holding the
    /// truth; unflagged single (a two-view stick nothing checked); unflagged
    /// with two or more pairs and missing the truth (a wrong fused point).
    pub caught: usize,
    pub harmless: usize,
    pub wrong_single: usize,
    pub wrong_fused: usize,
}

impl Tally {
    pub fn add(&mut self, o: &Tally) {
        self.drives += o.drives;
        self.key_frames += o.key_frames;
        self.pairs += o.pairs;
        self.consistent += o.consistent;
        self.consistent_contained += o.consistent_contained;
        self.single += o.single;
        self.single_contained += o.single_contained;
        self.inconsistent += o.inconsistent;
        self.unseen += o.unseen;
        self.unseen_contained += o.unseen_contained;
        self.widened += o.widened;
        self.widened_contained += o.widened_contained;
        self.wrong_pairs += o.wrong_pairs;
        self.wrong_pairs_observed += o.wrong_pairs_observed;
        self.caught += o.caught;
        self.harmless += o.harmless;
        self.wrong_single += o.wrong_single;
        self.wrong_fused += o.wrong_fused;
    }
}

fn holds(iv: Option<roadstereo::DepthInterval>, z: f64) -> bool {
    iv.is_some_and(|iv| f64::from(iv.z_near) <= z && z <= f64::from(iv.z_far))
}

/// Compare a run with the drive's truth.
pub fn tally(d: &Drive, run: &Run) -> Tally {
    use roadstereo::fusion::FusedStatus;
    let mut t = Tally {
        drives: 1,
        key_frames: run.keys.len(),
        ..Tally::default()
    };
    for rec in &run.keys {
        t.pairs += rec.partners.len();
        for snap in &rec.fused {
            for (b, pts) in snap.iter().enumerate() {
                for (i, p) in pts.iter().enumerate() {
                    let z = d.z_true(rec.key, b, i);
                    match p.status {
                        FusedStatus::Consistent => {
                            t.consistent += 1;
                            t.consistent_contained += usize::from(holds(p.interval, z));
                        }
                        FusedStatus::Single => {
                            t.single += 1;
                            t.single_contained += usize::from(holds(p.interval, z));
                        }
                        FusedStatus::PartlyUnseen => {
                            t.unseen += 1;
                            t.unseen_contained += usize::from(holds(p.interval, z));
                        }
                        FusedStatus::Widened => {
                            t.widened += 1;
                            t.widened_contained += usize::from(holds(p.interval, z));
                        }
                        _ => {}
                    }
                }
            }
        }
        let Some(last) = rec.fused.last() else {
            continue;
        };
        t.inconsistent += last
            .iter()
            .flatten()
            .filter(|p| p.status == FusedStatus::Inconsistent)
            .count();
        for (pi, pair) in rec.pairs.iter().enumerate() {
            for (b, pts) in pair.iter().enumerate() {
                for (i, q) in pts.iter().enumerate() {
                    let z = d.z_true(rec.key, b, i);
                    if q.status != Status::Ok || (q.z_near <= z && z <= q.z_far) {
                        continue;
                    }
                    t.wrong_pairs += 1;
                    if d.observed(rec.key, b, i, rec.partners[pi]) {
                        t.wrong_pairs_observed += 1;
                    }
                    let f = last[b][i];
                    match f.status {
                        FusedStatus::Inconsistent | FusedStatus::PartlyUnseen => t.caught += 1,
                        _ if holds(f.interval, z) => t.harmless += 1,
                        FusedStatus::Single => t.wrong_single += 1,
                        _ => t.wrong_fused += 1,
                    }
                }
            }
        }
    }
    t
}
