//! The frame path: sequences of [`Processor::process`],
//! [`Processor::process_against_kept`] and [`Processor::reset`] calls with
//! drawn configurations, cameras, motions and boundaries.
//!
//! Inputs: a road scene (a ground plane below a tilted camera, two to
//! three curved edges) seen from poses that follow the drawn motions, so
//! most frame pairs have real correspondences; mixed with random monotone
//! polylines, zig-zags in `u`, radial lines through the principal point,
//! copies of the previous frame, exact integers, the image edges and
//! margins and one past them, NaN, ±inf, ±0, subnormals, ±1e30,
//! duplicates, repeated rows, rows out of order, too few and too many
//! points and boundaries; motions forward, backward, sideways, tiny and
//! huge, with rotations up to ±π; every configuration option at and
//! beyond its limits.
//!
//! Oracles, on every call:
//! * no panic (the host tests' profile has overflow checks on);
//! * a rejected boundary leaves the frame as it was, and is rejected for
//!   exactly the first rule it breaks (an independent check of the rules
//!   of [`roadstereo::boundary`]);
//! * every depth finite with `0 < z <= max_depth` and
//!   `z_near <= z <= z_far`, every match and 3-D point finite, one result
//!   per kept point naming that point;
//! * errors exactly when the API says, and then the state untouched: a
//!   shadow processor gets only the calls that succeeded, and both agree
//!   bit for bit after every call (which also checks determinism, and,
//!   the shadow taking the checking forms of the loops that have a bounded
//!   one, `Processor::set_checking_forms`, that the bounded forms give
//!   the same results);
//! * the indexed matcher with [`Config::MAX_WORK_PER_POINT`] equals the
//!   reference matcher bit for bit (but for the known findings of the
//!   matching stage, counted: see `known`), and with the case's own
//!   budget every point equals that result or is [`Status::OverBudget`].

use roadstereo::geometry::{samples, Sample};
use roadstereo::{
    BoundaryError, Camera, CameraError, Config, ConfigError, Frame, Motion, MotionError, Pixel,
    PointResult, ProcessError, Processor, Status, Step, Structure, IMAGE_MARGIN_PX,
};

use super::{Outcome, Source};

/// The usual capacity: boundaries of up to 64 points, 3 a frame.
pub const SMALL: (usize, usize) = (64, 3);
/// One case in 16: up to 512 points (one a row), 2 a frame.
pub const LARGE: (usize, usize) = (512, 2);

/// One case: the capacity, the configuration, the calls.
#[derive(Debug, Clone)]
pub struct Case {
    /// [`LARGE`] instead of [`SMALL`].
    pub large: bool,
    /// The configuration's constructor arguments.
    pub config: ConfigIn,
    /// The calls, in order.
    pub calls: Vec<Call>,
}

/// Arguments of [`Config::new`] and its `with_` methods (`None`: not
/// called). A rejected step leaves the configuration of the steps before.
#[derive(Debug, Clone, Copy)]
pub struct ConfigIn {
    /// `e1, e2, min_angle_deg, max_depth`.
    pub new: [f32; 4],
    /// [`Config::with_translation_error`].
    pub translation_error: Option<f32>,
    /// [`Config::with_rotation_error`].
    pub rotation_error: Option<[f32; 3]>,
    /// [`Config::with_work_budget`].
    pub work_budget: Option<u32>,
}

impl ConfigIn {
    /// Whether the case's processors take the counting rule for folded
    /// points (`Processor::set_fold_counting`): the parity of the set bits
    /// of the configuration's first four arguments, so about half the
    /// cases, without a draw of its own (the corpus's cases stay what
    /// they were).
    pub fn fold_counting(&self) -> bool {
        self.new
            .iter()
            .map(|x| x.to_bits().count_ones())
            .sum::<u32>()
            % 2
            == 1
    }
}

/// One call of the frame path.
#[derive(Debug, Clone)]
pub enum Call {
    /// [`Processor::process`].
    Process(FrameIn, Option<MotionIn>),
    /// [`Processor::process_against_kept`].
    AgainstKept(FrameIn, MotionIn),
    /// [`Processor::reset`].
    Reset,
}

/// A frame's camera (`fx, fy, cx, cy`, width, height) and boundaries.
#[derive(Debug, Clone)]
pub struct FrameIn {
    /// `fx, fy, cx, cy`.
    pub k: [f32; 4],
    /// Width and height.
    pub size: (u16, u16),
    /// Raw polylines, `(u, v)`.
    pub boundaries: Vec<Vec<[f32; 2]>>,
}

/// A motion's translation and rotation.
#[derive(Debug, Clone, Copy)]
pub struct MotionIn {
    /// `(U, V, W)`.
    pub t: [f32; 3],
    /// `(α, β, γ)`, radians.
    pub r: [f32; 3],
}

// ---------------------------------------------------------------------
// Generation.

/// A camera pose in the scene: orientation (camera → world) and centre.
#[derive(Debug, Clone, Copy)]
pub(super) struct Pose {
    r: [[f64; 3]; 3],
    t: [f64; 3],
}

pub(super) const IDENTITY: Pose = Pose {
    r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    t: [0.0; 3],
};

fn mat_mul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn mat_vec(a: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

/// `R = R_y(β) R_x(α) R_z(γ)` (the crate's convention, see
/// [`roadstereo::motion`]).
fn rotation(a: [f32; 3]) -> [[f64; 3]; 3] {
    let (sa, ca) = f64::from(a[0]).sin_cos();
    let (sb, cb) = f64::from(a[1]).sin_cos();
    let (sg, cg) = f64::from(a[2]).sin_cos();
    let ry = [[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]];
    let rx = [[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]];
    let rz = [[cg, -sg, 0.0], [sg, cg, 0.0], [0.0, 0.0, 1.0]];
    mat_mul(&mat_mul(&ry, &rx), &rz)
}

impl Pose {
    /// The pose after `m` (given in this pose's camera axes).
    pub(super) fn then(&self, m: &MotionIn) -> Pose {
        let d = mat_vec(&self.r, m.t.map(f64::from));
        Pose {
            r: mat_mul(&self.r, &rotation(m.r)),
            t: [0, 1, 2].map(|i| self.t[i] + d[i]),
        }
    }

    /// A world point in this camera's axes.
    fn camera_point(&self, p: [f64; 3]) -> [f64; 3] {
        let d = [p[0] - self.t[0], p[1] - self.t[1], p[2] - self.t[2]];
        [0, 1, 2].map(|j| (0..3).map(|i| self.r[i][j] * d[i]).sum())
    }
}

/// The road: world axes are those of the first camera; the ground is
/// `Y cos θ + Z sin θ = h`; each edge is at lateral offset
/// `a + b s + c s²` at distance `s` along the road.
#[derive(Debug, Clone)]
pub(super) struct Scene {
    h: f64,
    pub(super) tilt: f64,
    pub(super) edges: Vec<[f64; 3]>,
    near: f64,
    far: f64,
}

impl Scene {
    pub(super) fn new(src: &mut Source) -> Scene {
        let n = 2 + src.index(2);
        let edges = (0..n)
            .map(|k| {
                let side = if k % 2 == 0 { -1.0 } else { 1.0 };
                [
                    side * src.range(0.5, 8.0),
                    src.range(-0.1, 0.1),
                    src.range(-0.004, 0.004),
                ]
            })
            .collect();
        Scene {
            h: src.range(0.3, 3.0),
            tilt: src.range(-0.05, 0.4),
            edges,
            near: src.range(1.0, 6.0),
            far: src.range(15.0, 300.0),
        }
    }

    /// The point of edge `e` at distance `s`.
    fn point(&self, e: [f64; 3], s: f64) -> [f64; 3] {
        let (st, ct) = self.tilt.sin_cos();
        let lateral = e[0] + e[1] * s + e[2] * s * s;
        // Below the camera on the plane, then `s` forward along it.
        [lateral, self.h * ct - s * st, self.h * st + s * ct]
    }
}

/// A plausible camera, or one at the limits, or (rarely) an invalid one.
pub(super) fn camera(src: &mut Source) -> ([f32; 4], (u16, u16)) {
    let (w, h): (u16, u16) = match src.below(16) {
        0 => (2, 2),
        1 => (16384, src.pick(&[2, 480, 16384])),
        2 => (src.pick(&[0, 1, 16385, u16::MAX]), 480),
        3 => (1 + src.below(4000) as u16, 1 + src.below(4000) as u16),
        _ => src.pick(&[(512, 480), (640, 480), (320, 240), (1280, 720), (256, 256)]),
    };
    let f = src.mixed(|s| match s.below(8) {
        0 => s.pick(&[1.0, 1.0e5, 0.999_999_9, 100_000.01]),
        1 => s.f32_in(1.0, 100.0),
        _ => s.f32_in(200.0, 2000.0),
    });
    let fy = if src.chance(3, 4) {
        f
    } else {
        src.mixed(|s| f * s.f32_in(0.8, 1.25))
    };
    let (wf, hf) = (f32::from(w), f32::from(h));
    let centre = |src: &mut Source, side: f32| {
        src.mixed(|s| match s.below(8) {
            0 => s.pick(&[0.0, side - 1.0, -0.0]),
            1 => s.f32_in(0.0, f64::from(side - 1.0)),
            _ => (side - 1.0) / 2.0 + s.f32_in(-10.0, 10.0),
        })
    };
    let cx = centre(src, wf);
    let cy = centre(src, hf);
    ([f, fy, cx, cy], (w, h))
}

pub(super) fn config(src: &mut Source) -> ConfigIn {
    let e = |src: &mut Source| {
        src.mixed(|s| match s.below(8) {
            0 => s.pick(&[0.0, 100.0, 3.0, 0.25]),
            1 => s.f32_in(0.0, 5.0),
            _ => 0.5,
        })
    };
    let e1 = e(src);
    let e2 = if src.chance(1, 2) { e1 } else { e(src) };
    let angle = src.mixed(|s| match s.below(8) {
        0 => s.pick(&[0.1, 89.0, 1.0, 45.0]),
        1 => s.f32_in(0.1, 89.0),
        _ => 10.0,
    });
    let max_depth = src.mixed(|s| match s.below(8) {
        0 => s.pick(&[1.0e-3, 1.0e6, 1.0e30, 3.0e38, 5.0]),
        1 => s.f32_in(1.0, 1.0e4),
        _ => 1000.0,
    });
    let translation_error = src.chance(1, 4).then(|| {
        src.mixed(|s| match s.below(6) {
            0 => s.pick(&[0.0, 1.0e6, 1.0]),
            _ => s.f32_in(0.0, 0.1),
        })
    });
    let rotation_error = src.chance(1, 4).then(|| {
        if src.chance(1, 6) {
            [src.special(), src.f32_in(0.0, 0.05), 0.0]
        } else {
            let total = src.f32_in(0.0, 0.1);
            let a = src.unit() as f32;
            let b = (1.0 - a) * src.unit() as f32;
            [total * a, total * b, total * (1.0 - a - b)]
        }
    });
    let work_budget = src.chance(1, 3).then(|| match src.below(6) {
        0 => Config::MIN_WORK_PER_POINT,
        1 => Config::MAX_WORK_PER_POINT,
        2 => src.pick(&[0, 7, Config::MAX_WORK_PER_POINT + 1, u32::MAX]),
        _ => Config::MIN_WORK_PER_POINT + src.below(200),
    });
    ConfigIn {
        new: [e1, e2, angle, max_depth],
        translation_error,
        rotation_error,
        work_budget,
    }
}

/// A motion: mostly forward driving, else backward, sideways, tiny, huge,
/// with large rotations, or with special values.
///
/// Driving is along the road: the camera is tilted down by `tilt`, so
/// forward on the road is `(0, −sin θ, cos θ)` in its axes.
pub(super) fn motion(src: &mut Source, tilt: f64) -> MotionIn {
    let (st, ct) = (tilt.sin() as f32, tilt.cos() as f32);
    let small = |s: &mut Source, a: f64| s.mixed(|s| s.f32_in(-a, a));
    let kind = src.below(16);
    let t = match kind {
        0 => [small(src, 0.5), small(src, 0.5), src.f32_in(-2.0, -0.05)],
        1 => [src.f32_in(-1.0, 1.0), small(src, 0.2), 0.0],
        2 => {
            let s = src.pick(&[1.0e-6, 2.0e-6, 1.0e-5, 1.0e-3]);
            [0.0, 0.0, s * src.pick(&[1.0f32, -1.0, 0.7])]
        }
        3 => [
            small(src, 1.0e5),
            0.0,
            src.pick(&[1.0e6, 999_999.94, 1.0e5]),
        ],
        4 => [src.special(), src.special(), src.special()],
        5 => [0.0, 0.0, src.mixed(|s| s.f32_in(0.05, 3.0))],
        _ => {
            let w = src.mixed(|s| s.f32_in(0.05, 3.0));
            [small(src, 0.3), small(src, 0.05) - w * st, w * ct]
        }
    };
    let r = match src.below(16) {
        0 => [0, 1, 2].map(|_| src.f32_in(-3.2, 3.2)),
        1 => [0, 1, 2].map(|_| src.f32_in(-1.05, 1.05)),
        2 => {
            let mut r = [0.0; 3];
            r[src.index(3)] = src.pick(&[
                core::f32::consts::FRAC_PI_3,
                -core::f32::consts::FRAC_PI_3,
                core::f32::consts::FRAC_PI_3.next_up(),
                core::f32::consts::PI,
                -core::f32::consts::PI,
            ]);
            r
        }
        3 => [src.special(), 0.0, 0.0],
        4..=7 => [0.0; 3],
        _ => [0, 1, 2].map(|_| small(src, 0.05)),
    };
    MotionIn { t, r }
}

/// The points of one boundary: a road edge seen from `pose`, a random
/// polyline, a radial line or a mutated copy, at most `cap + 2` points.
#[allow(clippy::too_many_arguments)]
fn boundary(
    src: &mut Source,
    scene: &Scene,
    edge: usize,
    pose: &Pose,
    k: [f32; 4],
    size: (u16, u16),
    cap: usize,
    previous: Option<&Vec<[f32; 2]>>,
) -> Vec<[f32; 2]> {
    let (w, h) = (f64::from(size.0), f64::from(size.1));
    let m = f64::from(IMAGE_MARGIN_PX);
    let inside =
        |p: [f64; 2]| p[0] >= -m && p[0] <= w - 1.0 + m && p[1] >= -m && p[1] <= h - 1.0 + m;
    let kind = src.below(32);
    let mut pts: Vec<[f64; 2]> = match kind {
        // A random polyline, strictly monotone in v, zig-zagging in u.
        0..=3 => {
            let n = 2 + src.index(cap);
            let mut v = src.range(-m, h - 1.0 + m);
            let dir = if src.chance(1, 2) { 1.0 } else { -1.0 };
            let mut u = src.range(-m, w - 1.0 + m);
            let amp = src.pick(&[0.0, 1.0, 2.0, 60.0, 500.0]);
            let step = src.pick(&[0.5, 1.0, 3.0, 20.0]);
            (0..n)
                .map(|i| {
                    v += dir * step * src.range(0.01, 2.0);
                    u += if i % 2 == 0 { amp } else { -amp } + src.range(-2.0, 2.0);
                    [u, v]
                })
                .collect()
        }
        // A radial line through the principal point.
        4 | 5 => {
            let n = 2 + src.index(cap);
            let ang = src.range(-3.2, 3.2);
            let (c, s) = (ang.cos(), ang.sin());
            let start = src.range(0.0, 30.0);
            let step = src.range(0.5, 5.0);
            (0..n)
                .map(|i| {
                    let r = start + step * i as f64;
                    [f64::from(k[2]) + r * c, f64::from(k[3]) + r * s]
                })
                .collect()
        }
        // A far vertex at the image's side, then points close to the
        // principal point: a long segment ending where a straight-ahead
        // motion's FOE is (a review's shape: the crossing there carried
        // the far end's rounding, `check_on_polyline`).
        7 => {
            let n = 2 + src.index(cap);
            let (cx, cy) = (f64::from(k[2]), f64::from(k[3]));
            let dir = if src.chance(1, 2) { 1.0 } else { -1.0 };
            let mut v = cy + src.range(-3.0, 3.0);
            let mut out = vec![[src.pick(&[-m, w - 1.0 + m]), v]];
            for _ in 1..n {
                v += dir * src.range(0.05, 1.0);
                out.push([cx + src.range(-2.0, 2.0), v]);
            }
            out
        }
        // The same boundary of the previous frame (no disparity).
        6 if previous.is_some() => previous
            .map(|p| p.iter().map(|q| q.map(f64::from)).collect())
            .unwrap_or_default(),
        // A road edge.
        _ => {
            let e = scene.edges[edge % scene.edges.len()];
            let n = 2 + src.index(cap + 2);
            let (near, far) = (scene.near, scene.far);
            let mut out = Vec::with_capacity(n);
            for i in 0..n {
                let s = near * (far / near).powf(i as f64 / (n - 1).max(1) as f64);
                let q = pose.camera_point(scene.point(e, s));
                if q[2] <= 1.0e-3 {
                    continue;
                }
                let (fx, fy, cx, cy) = (
                    f64::from(k[0]),
                    f64::from(k[1]),
                    f64::from(k[2]),
                    f64::from(k[3]),
                );
                out.push([cx + fx * q[0] / q[2], cy + fy * q[1] / q[2]]);
            }
            out
        }
    };
    // Quantise (exact integers, half pixels) or add noise.
    match src.below(8) {
        0 | 1 => pts.iter_mut().for_each(|p| *p = p.map(f64::round)),
        2 => pts
            .iter_mut()
            .for_each(|p| *p = p.map(|x| (2.0 * x).round() / 2.0)),
        3 => {
            for p in pts.iter_mut() {
                p[0] += src.range(-0.5, 0.5);
                p[1] += src.range(-0.5, 0.5);
            }
        }
        _ => {}
    }
    // Keep what a boundary detector would report (mostly).
    if src.chance(7, 8) {
        pts.retain(|&p| inside(p));
        let mut kept: Vec<[f64; 2]> = Vec::with_capacity(pts.len());
        for p in pts {
            let ok = match kept.as_slice() {
                [] => true,
                [a] => p[1] != a[1],
                [a, b, ..] => (p[1] - kept[kept.len() - 1][1]) * (b[1] - a[1]) > 0.0,
            };
            if ok {
                kept.push(p);
            }
        }
        pts = kept;
    }
    let mut pts: Vec<[f32; 2]> = pts.iter().map(|p| p.map(|x| x as f32)).collect();
    // Mutations: special values, edges and margins, duplicates, repeated
    // rows, rows out of order, too many points.
    // (Most mutations get the boundary rejected, which shifts the later
    // boundaries against those of the other frame: not too many.)
    let mutations = match src.below(16) {
        0..=12 => 0,
        13 | 14 => 1,
        _ => 1 + src.below(4),
    };
    for _ in 0..mutations {
        if pts.is_empty() {
            break;
        }
        let i = src.index(pts.len());
        let (wf, hf) = (f32::from(size.0), f32::from(size.1));
        match src.below(10) {
            0 => pts[i][src.index(2)] = src.special(),
            1 => {
                let edges_u = [
                    -1.0,
                    (-1.0f32).next_down(),
                    0.0,
                    wf - 1.0,
                    wf,
                    wf.next_up(),
                    -0.0,
                ];
                pts[i][0] = src.pick(&edges_u);
            }
            2 => {
                let edges_v = [-1.0, (-1.0f32).next_down(), 0.0, hf - 1.0, hf, hf.next_up()];
                pts[i][1] = src.pick(&edges_v);
            }
            3 => {
                let p = pts[i];
                pts.insert(i, p);
            }
            4 if i > 0 => pts[i][1] = pts[i - 1][1],
            5 if i + 1 < pts.len() => pts.swap(i, i + 1),
            6 => pts.truncate(src.index(3)),
            7 => {
                let p = *pts.last().unwrap_or(&[0.0, 0.0]);
                while pts.len() <= cap {
                    pts.push(p);
                }
            }
            8 => pts[i] = pts[i].map(f32::round),
            _ => pts[i][0] = src.mixed(|s| s.f32_in(-1.0, f64::from(wf))),
        }
    }
    pts
}

/// A frame's `nb` boundaries ([`boundary`], the `b`-th after the last
/// frame's `b`-th), kept as the last frame's.
pub(super) fn boundaries(
    src: &mut Source,
    (scene, pose): (&Scene, &Pose),
    nb: usize,
    (k, size): ([f32; 4], (u16, u16)),
    cap: usize,
    last: &mut Vec<Vec<[f32; 2]>>,
) -> Vec<Vec<[f32; 2]>> {
    // (Now and then a boundary the detector lost: empty, pushed absent.)
    let out: Vec<_> = (0..nb)
        .map(|b| {
            if src.chance(1, 20) {
                Vec::new()
            } else {
                boundary(src, scene, b, pose, k, size, cap, last.get(b))
            }
        })
        .collect();
    last.clone_from(&out);
    out
}

/// Draw a case.
pub fn generate(src: &mut Source) -> Case {
    let large = src.chance(1, 16);
    let (cap, cap_b) = if large { LARGE } else { SMALL };
    // Mostly short boundaries: the small capacity's cases are the bulk.
    let cap_points = if large || src.chance(1, 4) { cap } else { 24 };
    let config = config(src);
    let scene = Scene::new(src);
    let (k0, size0) = camera(src);
    let calls_n = 2 + src.index(5);
    let mut calls = Vec::with_capacity(calls_n);
    // The generator's model of the processor: the kept frame's pose.
    let mut kept: Option<Pose> = None;
    let mut last_boundaries: Vec<Vec<[f32; 2]>> = Vec::new();
    for i in 0..calls_n {
        let kind = if i == 0 { 0 } else { src.below(16) };
        if kind == 15 {
            calls.push(Call::Reset);
            kept = None;
            continue;
        }
        let m = motion(src, scene.tilt);
        let valid = Motion::new(m.t, m.r).is_ok();
        let from = kept.unwrap_or(IDENTITY);
        // The first frame (no kept frame) is seen from where the scene starts:
        // its motion is ignored.
        let pose = if valid && kept.is_some() {
            from.then(&m)
        } else {
            from
        };
        let (k, size) = if src.chance(1, 12) {
            camera(src)
        } else {
            (k0, size0)
        };
        // Mostly as many boundaries as the frame before (a boundary
        // missing in frame 2 leaves its kept points unmatched).
        let nb = match src.below(16) {
            _ if !last_boundaries.is_empty() && src.chance(3, 4) => last_boundaries.len(),
            0 => 0,
            1 => cap_b + 1,
            _ => 1 + src.index(cap_b),
        };
        let boundaries = boundaries(
            src,
            (&scene, &pose),
            nb,
            (k, size),
            cap_points,
            &mut last_boundaries,
        );
        let frame = FrameIn {
            k,
            size,
            boundaries,
        };
        if kind < 11 {
            let motion = (!src.chance(1, 12)).then_some(m);
            let accepted = kept.is_none() || motion.is_some_and(|m| Motion::new(m.t, m.r).is_ok());
            if accepted && Camera::new(k[0], k[1], k[2], k[3], size.0, size.1).is_ok() {
                kept = Some(if kept.is_none() { from } else { pose });
            }
            calls.push(Call::Process(frame, motion));
        } else {
            calls.push(Call::AgainstKept(frame, m));
        }
    }
    Case {
        large,
        config,
        calls,
    }
}

// ---------------------------------------------------------------------
// Running and the oracles.

/// Feature bits (see [`Outcome::features`]).
mod bit {
    pub const STATUS: u32 = 0; // 13 bits: a status seen
    pub const STATUS_MANY: u32 = 13; // 13 bits: a status on 4+ points of a call
    pub const PROCESS_ERR: u32 = 26; // 2
    pub const BOUNDARY_ERR: u32 = 28; // 7
    pub const CAMERA_ERR: u32 = 35; // 4
    pub const MOTION_ERR: u32 = 39; // 4
    pub const CONFIG_ERR: u32 = 43; // 6
    pub const LARGE: u32 = 49;
    pub const OVER_BUDGET_ONLY: u32 = 50;
    pub const TRANSLATION_ERR: u32 = 51;
    pub const ROTATION_ERR: u32 = 52;
    pub const BUDGET: u32 = 53;
    pub const BACKWARD: u32 = 54;
    pub const SIDEWAYS: u32 = 55;
    pub const TURN: u32 = 56;
    pub const FIRST: u32 = 57;
    pub const STRUCTURE: u32 = 58;
    pub const KEPT: u32 = 59;
    pub const RESET: u32 = 60;
    pub const SAMPLES: u32 = 61;
    pub const CAMERA_CHANGE: u32 = 62;
    pub const LOOSER_STICK: u32 = 63;
    // (64 up to `fuzz::fusion::bit::END`: the fusion target's, whose
    // frames are built here too.)
    pub const ABSENT: u32 = 120; // a boundary pushed as absent
}

pub(super) fn set(f: &mut u128, b: u32) {
    *f |= 1u128 << b;
}

/// Generate a case from `src` and check it.
pub fn run(src: &mut Source) -> Outcome {
    check(&generate(src))
}

/// Check a case against every oracle (panics on a finding).
pub fn check(case: &Case) -> Outcome {
    if case.large {
        run_case::<{ LARGE.0 }, { LARGE.1 }>(case)
    } else {
        run_case::<{ SMALL.0 }, { SMALL.1 }>(case)
    }
}

/// The configuration of `c`, each rejected step checked against the
/// documented rule and skipped.
pub(super) fn build_config(c: &ConfigIn, features: &mut u128) -> Config {
    let [e1, e2, angle, depth] = c.new;
    let mut config = match Config::new(e1, e2, angle, depth) {
        Ok(c) => c,
        Err(e) => {
            let want = if !((0.0..=100.0).contains(&e1) && (0.0..=100.0).contains(&e2)) {
                ConfigError::LocalisationError
            } else if !(0.1..=89.0).contains(&angle) {
                ConfigError::MinAngle
            } else {
                ConfigError::MaxDepth
            };
            assert_eq!(e, want, "Config::new{:?}", c.new);
            set(features, bit::CONFIG_ERR + e as u32);
            Config::DEFAULT
        }
    };
    if let Some(d) = c.translation_error {
        match config.with_translation_error(d) {
            Ok(x) => {
                config = x;
                if d > 0.0 {
                    set(features, bit::TRANSLATION_ERR);
                }
            }
            Err(e) => set(features, bit::CONFIG_ERR + e as u32),
        }
    }
    if let Some(r) = c.rotation_error {
        match config.with_rotation_error(r) {
            Ok(x) => {
                config = x;
                if r.iter().any(|&e| e > 0.0) {
                    set(features, bit::ROTATION_ERR);
                }
            }
            Err(e) => set(features, bit::CONFIG_ERR + e as u32),
        }
    }
    if let Some(u) = c.work_budget {
        let ok = (Config::MIN_WORK_PER_POINT..=Config::MAX_WORK_PER_POINT).contains(&u);
        match config.with_work_budget(u) {
            Ok(x) => {
                assert!(ok, "work budget {u} accepted");
                config = x;
                set(features, bit::BUDGET);
            }
            Err(e) => {
                assert!(!ok, "work budget {u} rejected");
                set(features, bit::CONFIG_ERR + e as u32);
            }
        }
    }
    config
}

/// The first rule of [`roadstereo::boundary`] that `pts` breaks, decided
/// independently of the library.
fn expected_boundary_error(pts: &[[f32; 2]], cam: &Camera, cap: usize) -> Option<BoundaryError> {
    if pts.len() < 2 {
        return Some(BoundaryError::TooFewPoints);
    }
    if pts.len() > cap {
        return Some(BoundaryError::TooManyPoints {
            len: pts.len(),
            capacity: cap,
        });
    }
    let m = IMAGE_MARGIN_PX;
    let (w, h) = (f32::from(cam.width()), f32::from(cam.height()));
    let mut dir = 0.0f32;
    for (index, p) in pts.iter().enumerate() {
        if !(p[0].is_finite() && p[1].is_finite()) {
            return Some(BoundaryError::NotFinite { index });
        }
        if !(p[0] >= -m && p[0] <= w - 1.0 + m && p[1] >= -m && p[1] <= h - 1.0 + m) {
            return Some(BoundaryError::OutsideImage { index });
        }
        if index > 0 {
            let q = pts[index - 1];
            if p[0] == q[0] && p[1] == q[1] {
                return Some(BoundaryError::Duplicate { index });
            }
            let dv = p[1] - q[1];
            if dv == 0.0 || (dir != 0.0 && (dv > 0.0) != (dir > 0.0)) {
                return Some(BoundaryError::Unordered { index });
            }
            dir = dv;
        }
    }
    None
}

fn boundary_error_bit(e: &BoundaryError) -> u32 {
    match e {
        BoundaryError::TooFewPoints => 0,
        BoundaryError::TooManyPoints { .. } => 1,
        BoundaryError::TooManyBoundaries => 2,
        BoundaryError::NotFinite { .. } => 3,
        BoundaryError::OutsideImage { .. } => 4,
        BoundaryError::Duplicate { .. } => 5,
        BoundaryError::Unordered { .. } => 6,
        // (The enum is non-exhaustive: a variant added later counts with
        // the last one, so no other feature's bit is taken.)
        _ => 6,
    }
}

/// The frame of `f`, or `None` when its camera is rejected. Every rejected
/// boundary is checked: the right error, the frame unchanged.
pub(super) fn build_frame<const N: usize, const B: usize>(
    f: &FrameIn,
    features: &mut u128,
) -> Option<Frame<N, B>> {
    let [fx, fy, cx, cy] = f.k;
    let cam = match Camera::new(fx, fy, cx, cy, f.size.0, f.size.1) {
        Ok(c) => c,
        Err(e) => {
            set(features, bit::CAMERA_ERR + e as u32);
            let finite = f.k.iter().all(|x| x.is_finite());
            if !finite {
                assert_eq!(e, CameraError::NotFinite, "camera {f:?}");
            }
            return None;
        }
    };
    let mut frame = Frame::<N, B>::new(cam);
    for (i, b) in f.boundaries.iter().enumerate() {
        let pts: Vec<Pixel> = b.iter().map(|p| Pixel::new(p[0], p[1])).collect();
        let before = frame.clone();
        let want = if frame.boundaries().len() >= B {
            Some(BoundaryError::TooManyBoundaries)
        } else if b.is_empty() {
            // (An empty polyline is pushed as an absent boundary.)
            None
        } else {
            expected_boundary_error(b, &cam, N)
        };
        let pushed = if b.is_empty() {
            set(features, bit::ABSENT);
            frame.push_absent()
        } else {
            frame.push_boundary(&pts)
        };
        match pushed {
            Ok(()) => {
                assert_eq!(want, None, "boundary {i} accepted: {b:?}");
                assert_eq!(frame.boundaries().len(), before.boundaries().len() + 1);
                assert_eq!(
                    frame.boundaries().last().map(|b| b.points()),
                    Some(&pts[..])
                );
            }
            Err(e) => {
                assert_eq!(Some(e), want, "boundary {i} rejected: {b:?}");
                assert!(frame == before, "a rejected boundary changed the frame");
                set(features, bit::BOUNDARY_ERR + boundary_error_bit(&e));
            }
        }
    }
    Some(frame)
}

pub(super) fn build_motion(m: &MotionIn, features: &mut u128) -> Option<Motion> {
    match Motion::new(m.t, m.r) {
        Ok(x) => {
            if m.t[2] < 0.0 {
                set(features, bit::BACKWARD);
            }
            if m.t[2] == 0.0 {
                set(features, bit::SIDEWAYS);
            }
            if m.r.iter().any(|a| a.abs() > 0.1) {
                set(features, bit::TURN);
            }
            Some(x)
        }
        Err(e) => {
            set(features, bit::MOTION_ERR + e as u32);
            if m.t.iter().chain(&m.r).any(|x| !x.is_finite()) {
                assert_eq!(e, MotionError::NotFinite, "motion {m:?}");
            }
            None
        }
    }
}

/// Same bits (PartialEq on the raw results, and the digest, which also
/// tells NaN payloads apart).
fn same<const N: usize, const B: usize>(a: &Structure<N, B>, b: &Structure<N, B>) -> bool {
    a.digest() == b.digest()
        && a.camera1() == b.camera1()
        && a.boundaries().len() == b.boundaries().len()
        && a.boundaries()
            .iter()
            .zip(b.boundaries())
            .all(|(x, y)| x.points().len() == y.points().len())
}

/// The distance, in `f64`, from `q` to the segment `a → b`.
pub fn on_segment_distance(q: Pixel, (a, b): (Pixel, Pixel)) -> f64 {
    let (qu, qv) = (f64::from(q.u), f64::from(q.v));
    let (au, av) = (f64::from(a.u), f64::from(a.v));
    let (du, dv) = (f64::from(b.u) - au, f64::from(b.v) - av);
    let l2 = du * du + dv * dv;
    let t = if l2 > 0.0 {
        (((qu - au) * du + (qv - av) * dv) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (qu - au - t * du).hypot(qv - av - t * dv)
}

/// Every reported frame-2 match of `s` lies on its boundary's frame-2
/// polyline within the documented tolerance, `2⁻¹⁶ S` with `S` the largest
/// coordinate magnitude of the match, the ends of a segment it lies that
/// close to, the compensated frame-1 point and the FOE (`docs/METHOD.md`,
/// "A match's pixel lies on the polyline"; the largest ratio seen in a minute of this pass was
/// `8.3·10⁻⁷` before the segment's ends counted, about a twentieth of it).
///
/// `thin` is the thinning's `ε` when `s` came from `Processor::process`,
/// which may thin frame 2's boundaries (`roadstereo::thin`; 0 otherwise):
/// the match then lies on a chord of the boundary, whose vertices it
/// skipped lie within `0.575 ε` of it, so the tolerance adds `ε` and takes
/// the boundary's largest coordinate into `S` (the chord's ends are
/// vertices of it).
fn check_on_polyline<const N: usize, const B: usize>(
    s: &Structure<N, B>,
    kept: &Frame<N, B>,
    (frame, m): (&Frame<N, B>, &Motion),
    thin: f64,
) {
    let g = roadstereo::PairGeometry::new(kept.camera(), frame.camera(), m);
    let foe = g
        .focus_of_expansion()
        .map_or(0.0, |f| f64::from(f.u.abs().max(f.v.abs())));
    for (k, b) in s.boundaries().iter().enumerate() {
        let poly = frame.boundaries().get(k).map(|b| b.points());
        for r in b.points() {
            let Some(q) = r.pixel2() else { continue };
            let Some(poly) = poly else {
                panic!("boundary {k}: a match without a frame-2 boundary: {r:?}");
            };
            let p1 = g
                .compensate(r.pixel1())
                .map_or(0.0, |c| f64::from(c.pixel().u.abs().max(c.pixel().v.abs())));
            let base = 1.0f64
                .max(f64::from(q.u.abs()))
                .max(f64::from(q.v.abs()))
                .max(p1)
                .max(foe);
            let base = if thin > 0.0 {
                poly.iter().fold(base, |s, p| {
                    s.max(f64::from(p.u.abs())).max(f64::from(p.v.abs()))
                })
            } else {
                base
            };
            // The least ratio of distance to tolerance over the segments.
            let ratio = poly
                .windows(2)
                .map(|w| {
                    let ends = [w[0].u, w[0].v, w[1].u, w[1].v];
                    let scale = ends.iter().fold(base, |s, x| s.max(f64::from(x.abs())));
                    on_segment_distance(q, (w[0], w[1])) / (scale / 65_536.0 + thin)
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                ratio <= 1.0,
                "boundary {k}: the match {q:?} is {ratio} tolerances off the frame-2 polyline: {r:?}"
            );
        }
    }
}

/// Every result of `s` is well formed, against the kept frame it came from.
fn check_structure<const N: usize, const B: usize>(
    s: &Structure<N, B>,
    kept: &Frame<N, B>,
    config: &Config,
    features: &mut u128,
) {
    assert!(
        s.camera1() == kept.camera(),
        "camera1 is not the kept camera"
    );
    assert_eq!(
        s.boundaries().len(),
        kept.boundaries().len(),
        "one boundary of results per kept boundary"
    );
    for (k, (b, kb)) in s.boundaries().iter().zip(kept.boundaries()).enumerate() {
        assert_eq!(
            b.points().len(),
            kb.points().len(),
            "boundary {k}: one result per point"
        );
        let mut counts = vec![0usize; Status::ALL.len()];
        let mut ok = 0;
        for (i, (r, p)) in b.points().iter().zip(kb.points()).enumerate() {
            let at = || format!("boundary {k} point {i}: {r:?}");
            assert!(
                r.pixel1().u.to_bits() == p.u.to_bits() && r.pixel1().v.to_bits() == p.v.to_bits(),
                "{}: pixel1 is not the kept point {p:?}",
                at()
            );
            counts[r.status() as usize] += 1;
            if let Some(q) = r.pixel2() {
                assert!(r.status().has_match(), "{}", at());
                assert!(
                    q.u.is_finite() && q.v.is_finite(),
                    "{}: match not finite",
                    at()
                );
            }
            match (r.depth(), r.interval()) {
                (Some(z), Some(iv)) => {
                    ok += 1;
                    assert_eq!(r.status(), Status::Ok, "{}", at());
                    assert!(
                        z.is_finite() && iv.z_near.is_finite() && iv.z_far.is_finite(),
                        "{}: depth not finite",
                        at()
                    );
                    assert!(
                        iv.z_near <= z && z <= iv.z_far,
                        "{}: depth outside its stick",
                        at()
                    );
                    assert!(
                        z > 0.0 && z <= config.max_depth(),
                        "{}: depth out of (0, max]",
                        at()
                    );
                    let xyz = s.point(r).expect("a point with a depth has a 3-D point");
                    let (a, c) = s.stick(r).expect("a point with a depth has a stick");
                    assert!(
                        xyz.iter().chain(&a).chain(&c).all(|x| x.is_finite()),
                        "{}: 3-D point or stick not finite",
                        at()
                    );
                }
                (None, None) => {
                    assert_ne!(r.status(), Status::Ok, "{}", at());
                    assert!(s.point(r).is_none() && s.stick(r).is_none(), "{}", at());
                }
                _ => panic!("{}: depth and interval disagree", at()),
            }
        }
        for (j, &c) in counts.iter().enumerate() {
            if c > 0 {
                set(features, bit::STATUS + j as u32);
            }
            if c >= 4 {
                set(features, bit::STATUS_MANY + j as u32);
            }
        }
        // The samples road_geometry takes: one per point with a depth.
        let mut v = heapless::Vec::<Sample, N>::new();
        samples(s, k, &mut v);
        assert_eq!(v.len(), ok, "boundary {k}: one sample per depth");
        assert!(
            v.iter()
                .all(|p| [p.x, p.y, p.z_near, p.z_far].iter().all(|x| x.is_finite())),
            "boundary {k}: a sample is not finite"
        );
        if ok > 0 {
            set(features, bit::SAMPLES);
        }
    }
}

/// The indexed matcher with the largest budget and the reference, on a
/// fresh processor keeping `kept`: they must agree bit for bit; the
/// indexed structure is returned (equal to the reference's but for the
/// known findings, see [`known`]).
fn matchers<const N: usize, const B: usize>(
    kept: &Frame<N, B>,
    frame: &Frame<N, B>,
    m: &Motion,
    (config, counting): (&Config, bool),
    thinned: bool,
) -> Box<Structure<N, B>> {
    let unlimited = config
        .with_work_budget(Config::MAX_WORK_PER_POINT)
        .expect("the largest budget is valid");
    if thinned {
        return thinned_matchers(kept, frame, m, (&unlimited, counting));
    }
    let mut r = Box::new(Processor::<N, B>::new(unlimited));
    r.set_fold_counting(counting);
    assert!(matches!(r.process(kept, None), Ok(Step::First)));
    let fast = Box::new(r.process_against_kept(frame, m).expect("kept").clone());
    let slow = Box::new(r.reference_against_kept(frame, m).expect("kept").clone());
    if !same(&fast, &slow) {
        point_for_point(&fast, &slow, "matcher");
        panic!("matcher: the indexed and reference structures differ");
    }
    // The same with the fold test switched off, where every point on a
    // fold reaches the search too.
    let fast_all = Box::new(
        r.without_fold_test_against_kept(frame, m, false)
            .expect("kept")
            .clone(),
    );
    let slow_all = r
        .without_fold_test_against_kept(frame, m, true)
        .expect("kept");
    point_for_point(&fast_all, slow_all, "matcher without the fold test");
    assert_eq!(
        r.previous(),
        Some(kept),
        "process_against_kept replaced the kept frame"
    );
    fast
}

/// [`matchers`] for `Processor::process`, which thins frame 2's
/// boundaries (`roadstereo::thin`): the indexed and reference matchers,
/// with the fold test and without, each on a processor that kept `kept`
/// first, equal point for point; the indexed one with the fold test is
/// returned.
fn thinned_matchers<const N: usize, const B: usize>(
    kept: &Frame<N, B>,
    frame: &Frame<N, B>,
    m: &Motion,
    (unlimited, counting): (&Config, bool),
) -> Box<Structure<N, B>> {
    let run = |reference: bool, fold_test: bool| {
        let mut r = Box::new(Processor::<N, B>::new(*unlimited));
        r.set_fold_counting(counting);
        assert!(matches!(r.process(kept, None), Ok(Step::First)));
        let s = Box::new(
            r.process_checked(frame, m, (reference, fold_test))
                .expect("kept")
                .clone(),
        );
        assert!(r.previous() == Some(frame), "the new frame was not kept");
        s
    };
    let fast = run(false, true);
    for fold_test in [true, false] {
        let fast_here = if fold_test {
            fast.clone()
        } else {
            run(false, false)
        };
        let slow = run(true, fold_test);
        let what = format!("thinned matcher (fold test {fold_test})");
        point_for_point(&fast_here, &slow, &what);
    }
    fast
}

/// Every point of the indexed structure `fast` equal to the reference's
/// `slow` (both with the largest budget); `what` names the matchers.
fn point_for_point<const N: usize, const B: usize>(
    fast: &Structure<N, B>,
    slow: &Structure<N, B>,
    what: &str,
) {
    for (k, (x, y)) in fast.boundaries().iter().zip(slow.boundaries()).enumerate() {
        for (i, (p, q)) in x.points().iter().zip(y.points()).enumerate() {
            assert!(
                p == q,
                "{what}: boundary {k} point {i}: indexed {p:?}, reference {q:?} (largest budget)"
            );
        }
    }
}

/// A call that gave a structure (a reconstruction).
pub const RECONSTRUCTED: u32 = 124;

/// `got` (the case's budget) against the indexed matcher with the largest
/// budget (which equals the reference, see [`matchers`]): each point
/// equal, over budget, or `ok` with the same match and a stick holding the
/// largest budget's (a stick the budget could not tighten by the piece's
/// lines keeps the bound from its range); with the largest budget, equal.
fn against_reference<const N: usize, const B: usize>(
    got: &Structure<N, B>,
    reference: &Structure<N, B>,
    config: &Config,
    features: &mut u128,
) {
    let largest = config.work_per_point() == Config::MAX_WORK_PER_POINT;
    for (k, (x, y)) in got
        .boundaries()
        .iter()
        .zip(reference.boundaries())
        .enumerate()
    {
        for (i, (p, q)) in x.points().iter().zip(y.points()).enumerate() {
            if p != q && looser_stick(p, q) {
                assert!(
                    !largest,
                    "largest budget: boundary {k} point {i}: {p:?}, reference {q:?}"
                );
                set(features, bit::LOOSER_STICK);
            } else if p != q {
                assert_eq!(
                    p.status(),
                    Status::OverBudget,
                    "budget {} (motion errors {:?} {:?}): boundary {k} point {i}: {p:?}, largest budget {q:?}",
                    config.work_per_point(),
                    config.translation_error(),
                    config.rotation_error()
                );
                assert!(
                    !largest,
                    "largest budget: boundary {k} point {i}: {p:?}, reference {q:?}"
                );
                set(features, bit::OVER_BUDGET_ONLY);
            }
        }
    }
}

/// The pair `(kept, frame)` on a fresh processor within clocks that say
/// the time is up from their `k`-th question on (`Processor::
/// process_against_kept_within`), for a few `k` from 0 to past the last
/// question: the expiry flag exactly when the clock said yes, the clock
/// not asked after, the structure's own checks, and every point equal to
/// the largest budget's (`reference`), `over_budget`, or `ok` with the
/// same match and a stick holding that one's.
fn within_deadlines<const N: usize, const B: usize>(
    kept: &Frame<N, B>,
    (frame, m): (&Frame<N, B>, &Motion),
    (config, counting): (&Config, bool),
    reference: &Structure<N, B>,
    features: &mut u128,
) {
    let mut p = Box::new(Processor::<N, B>::new(*config));
    p.set_fold_counting(counting);
    assert!(matches!(p.process(kept, None), Ok(Step::First)));
    let mut questions = 0usize;
    let mut count = || {
        questions += 1;
        false
    };
    let uncut = Box::new(
        p.process_against_kept_within(frame, m, &mut count)
            .expect("kept")
            .clone(),
    );
    assert!(!p.deadline_expired(), "a clock that never says yes");
    for k in [
        0,
        1,
        questions / 3,
        questions / 2,
        questions.saturating_sub(1),
        questions,
    ] {
        let mut asked = 0usize;
        let mut clock = || {
            asked += 1;
            asked > k
        };
        let got = Box::new(
            p.process_against_kept_within(frame, m, &mut clock)
                .expect("kept")
                .clone(),
        );
        assert_eq!(
            p.deadline_expired(),
            asked > k,
            "deadline at question {k}: the flag"
        );
        assert!(
            asked <= k + 1,
            "deadline at question {k}: asked {asked} times"
        );
        check_structure(&got, kept, config, features);
        // Up to the cut, the uncut frame: each point its result or flagged.
        for (x, y) in got.boundaries().iter().zip(uncut.boundaries()) {
            for (a, b) in x.points().iter().zip(y.points()) {
                assert!(
                    a == b || a.status() == Status::OverBudget,
                    "deadline at question {k}: {a:?}, uncut {b:?}"
                );
            }
        }
        for (x, y) in got.boundaries().iter().zip(reference.boundaries()) {
            for (a, b) in x.points().iter().zip(y.points()) {
                assert!(
                    a == b || a.status() == Status::OverBudget || looser_stick(a, b),
                    "deadline at question {k}: {a:?}, largest budget {b:?}"
                );
            }
        }
    }
    assert_eq!(p.previous(), Some(kept), "the kept frame was replaced");
}

/// Whether `p` is `q` with a stick that holds `q`'s: both `ok`, the same
/// pixels and depth, `p`'s ends at or beyond `q`'s (what a budget too small
/// to tighten a stick by the piece's lines gives).
pub fn looser_stick(p: &PointResult, q: &PointResult) -> bool {
    let bits = |r: &PointResult| r.depth().map(f32::to_bits);
    match (p.interval(), q.interval()) {
        (Some(a), Some(b)) => {
            p.status() == Status::Ok
                && q.status() == Status::Ok
                && p.pixel1() == q.pixel1()
                && p.pixel2() == q.pixel2()
                && bits(p) == bits(q)
                && a.z_near <= b.z_near
                && a.z_far >= b.z_far
        }
        _ => false,
    }
}

/// The observable state of a processor (kept frame and last structure)
/// equals that of another.
fn assert_same_state<const N: usize, const B: usize>(
    a: &Processor<N, B>,
    b: &Processor<N, B>,
    what: &str,
) {
    assert!(
        a.previous() == b.previous(),
        "{what}: the kept frame differs from the shadow's"
    );
    assert!(
        same(a.structure(), b.structure()),
        "{what}: the structure differs from the shadow's"
    );
}

fn run_case<const N: usize, const B: usize>(case: &Case) -> Outcome {
    let mut features = 0u128;
    if case.large {
        set(&mut features, bit::LARGE);
    }
    let config = build_config(&case.config, &mut features);
    // `a` gets every call; `shadow` only those that succeed.
    let counting = case.config.fold_counting();
    let mut a = Box::new(Processor::<N, B>::new(config));
    let mut shadow = Box::new(Processor::<N, B>::new(config));
    a.set_fold_counting(counting);
    shadow.set_fold_counting(counting);
    // (The shadow takes the checking forms of the loops that have a
    // bounded one: every call compares the two bit for bit.)
    shadow.set_checking_forms(true);
    let mut calls = 0;
    let mut reconstructions = 0;
    let mut points = [0u64; 2];
    let count = |s: &Structure<N, B>| {
        let all = s.boundaries().iter().flat_map(|b| b.points());
        [
            all.clone().count() as u64,
            all.filter(|r| r.status() == Status::Ok).count() as u64,
        ]
    };
    let mut last_camera = None;
    for (n, call) in case.calls.iter().enumerate() {
        calls += 1;
        let what = format!("call {n}");
        match call {
            Call::Reset => {
                a.reset();
                shadow.reset();
                assert!(a.previous().is_none(), "{what}: reset kept a frame");
                set(&mut features, bit::RESET);
            }
            Call::Process(f, m) => {
                let Some(frame) = build_frame::<N, B>(f, &mut features) else {
                    continue;
                };
                if last_camera.is_some_and(|c| c != *frame.camera()) {
                    set(&mut features, bit::CAMERA_CHANGE);
                }
                last_camera = Some(*frame.camera());
                let motion = m.as_ref().and_then(|m| build_motion(m, &mut features));
                let kept = a.previous().cloned().map(Box::new);
                let reference = match (&kept, &motion) {
                    (Some(k), Some(m)) => Some(matchers(k, &frame, m, (&config, counting), true)),
                    _ => None,
                };
                let got = match a.process(&frame, motion.as_ref()) {
                    Ok(Step::First) => Ok(None),
                    Ok(Step::Structure(s)) => Ok(Some(Box::new(s.clone()))),
                    Err(e) => Err(e),
                };
                match got {
                    Ok(None) => {
                        assert!(kept.is_none(), "{what}: First with a kept frame");
                        set(&mut features, bit::FIRST);
                        assert!(
                            a.previous() == Some(&frame),
                            "{what}: the first frame was not kept"
                        );
                        let s = shadow.process(&frame, motion.as_ref());
                        assert!(matches!(s, Ok(Step::First)), "{what}: shadow {s:?}");
                    }
                    Ok(Some(s)) => {
                        let (Some(k), Some(r)) = (&kept, &reference) else {
                            panic!("{what}: a structure without a kept frame and a motion");
                        };
                        set(&mut features, bit::STRUCTURE);
                        reconstructions += 1;
                        let c = count(&s);
                        points[0] += c[0];
                        points[1] += c[1];
                        assert!(
                            a.previous() == Some(&frame),
                            "{what}: the new frame was not kept"
                        );
                        check_structure(&s, k, &config, &mut features);
                        if let Some(m) = &motion {
                            // (The thinning's `ε`, `e₂/256`, where `process`
                            // thins: `roadstereo::thin`.)
                            let thin = f64::from(config.e2()) / 256.0;
                            check_on_polyline(&s, k, (&frame, m), thin);
                        }
                        against_reference(&s, r, &config, &mut features);
                        let t = shadow.process(&frame, motion.as_ref());
                        let Ok(Step::Structure(t)) = t else {
                            panic!("{what}: the shadow got {t:?}");
                        };
                        assert!(same(&s, t), "{what}: not deterministic");
                    }
                    Err(e) => {
                        assert_eq!(e, ProcessError::MissingMotion, "{what}");
                        assert!(kept.is_some() && motion.is_none(), "{what}: {e:?}");
                        set(&mut features, bit::PROCESS_ERR);
                    }
                }
            }
            Call::AgainstKept(f, m) => {
                let Some(frame) = build_frame::<N, B>(f, &mut features) else {
                    continue;
                };
                let Some(motion) = build_motion(m, &mut features) else {
                    continue;
                };
                let kept = a.previous().cloned().map(Box::new);
                let reference = kept
                    .as_ref()
                    .map(|k| matchers(k, &frame, &motion, (&config, counting), false));
                let got = a
                    .process_against_kept(&frame, &motion)
                    .map(|s| Box::new(s.clone()));
                match got {
                    Ok(s) => {
                        let (Some(k), Some(r)) = (&kept, &reference) else {
                            panic!("{what}: a structure without a kept frame");
                        };
                        set(&mut features, bit::KEPT);
                        reconstructions += 1;
                        let c = count(&s);
                        points[0] += c[0];
                        points[1] += c[1];
                        check_structure(&s, k, &config, &mut features);
                        check_on_polyline(&s, k, (&frame, &motion), 0.0);
                        against_reference(&s, r, &config, &mut features);
                        within_deadlines(
                            k,
                            (&frame, &motion),
                            (&config, counting),
                            r,
                            &mut features,
                        );
                        assert!(
                            a.previous() == Some(&**k),
                            "{what}: the kept frame was replaced"
                        );
                        let t = shadow.process_against_kept(&frame, &motion);
                        let Ok(t) = t else {
                            panic!("{what}: the shadow got {t:?}");
                        };
                        assert!(same(&s, t), "{what}: not deterministic");
                    }
                    Err(e) => {
                        assert_eq!(e, ProcessError::NoKeptFrame, "{what}");
                        assert!(kept.is_none(), "{what}: {e:?} with a kept frame");
                        let r = a.reference_against_kept(&frame, &motion).map(|_| ());
                        assert_eq!(r, Err(ProcessError::NoKeptFrame), "{what}: reference");
                        set(&mut features, bit::PROCESS_ERR + 1);
                    }
                }
            }
        }
        assert_same_state(&a, &shadow, &what);
    }
    Outcome {
        calls,
        reconstructions,
        points,
        features,
    }
}

/// A frame's raw polylines.
type Polylines = Vec<Vec<[f32; 2]>>;

/// Shrink a failing case: drop calls, boundaries, points and
/// configuration options, and round coordinates, while `fails` still
/// holds. For reports of findings.
pub fn shrink(case: &Case, fails: &dyn Fn(&Case) -> bool) -> Case {
    let mut best = case.clone();
    for _ in 0..2000 {
        let mut changed = false;
        let mut tries: Vec<Case> = Vec::new();
        for i in 0..best.calls.len() {
            let mut c = best.clone();
            c.calls.remove(i);
            tries.push(c);
        }
        let mut c = best.clone();
        c.config.translation_error = None;
        tries.push(c);
        let mut c = best.clone();
        c.config.rotation_error = None;
        tries.push(c);
        let mut c = best.clone();
        c.config.work_budget = None;
        tries.push(c);
        for i in 0..best.calls.len() {
            let n = match &best.calls[i] {
                Call::Process(f, _) | Call::AgainstKept(f, _) => f.boundaries.clone(),
                Call::Reset => continue,
            };
            for (b, pts) in n.iter().enumerate() {
                let edit = |c: &mut Case, g: &dyn Fn(&mut Polylines)| {
                    if let Call::Process(f, _) | Call::AgainstKept(f, _) = &mut c.calls[i] {
                        g(&mut f.boundaries);
                    }
                };
                let mut c = best.clone();
                edit(&mut c, &|bs| {
                    bs.remove(b);
                });
                tries.push(c);
                for p in 0..pts.len() {
                    let mut c = best.clone();
                    edit(&mut c, &|bs| {
                        bs[b].remove(p);
                    });
                    tries.push(c);
                    if pts[p].iter().any(|x| x.is_finite() && x.fract() != 0.0) {
                        let mut c = best.clone();
                        edit(&mut c, &|bs| bs[b][p] = bs[b][p].map(f32::round));
                        tries.push(c);
                    }
                }
            }
            for m in 0..6 {
                let mut c = best.clone();
                let mo = match &mut c.calls[i] {
                    Call::Process(_, Some(m)) | Call::AgainstKept(_, m) => m,
                    _ => continue,
                };
                let x = if m < 3 {
                    &mut mo.t[m]
                } else {
                    &mut mo.r[m - 3]
                };
                if *x == 0.0 || !x.is_finite() || x.fract() == 0.0 {
                    continue;
                }
                let y = if m < 3 {
                    (*x * 100.0).round() / 100.0
                } else {
                    0.0
                };
                if y != *x {
                    *x = y;
                    tries.push(c);
                }
            }
        }
        for c in tries {
            if fails(&c) {
                best = c;
                changed = true;
                break;
            }
        }
        if !changed {
            break;
        }
    }
    best
}

/// One reconstruction where the indexed matcher (largest budget) and the
/// reference differ, reduced: the kept boundary, the frame-2 boundary,
/// the cameras, the motion and the configuration's arguments.
#[derive(Debug, Clone)]
pub struct Pair {
    /// The configuration's arguments (budget: the largest).
    pub config: ConfigIn,
    /// Kept camera (`fx, fy, cx, cy`, size).
    pub cam1: ([f32; 4], (u16, u16)),
    /// Frame-2 camera.
    pub cam2: ([f32; 4], (u16, u16)),
    /// The kept boundary.
    pub b1: Vec<[f32; 2]>,
    /// The frame-2 boundary (none: the frame has fewer boundaries).
    pub b2: Option<Vec<[f32; 2]>>,
    /// The motion.
    pub motion: MotionIn,
}

impl Pair {
    /// The indexed and the reference statuses of every kept point, or
    /// `None` when an input is rejected.
    pub fn statuses(&self) -> Option<(Vec<PointResultBits>, Vec<PointResultBits>)> {
        let mut f = 0u128;
        let mut c = self.config;
        c.work_budget = Some(Config::MAX_WORK_PER_POINT);
        let config = build_config(&c, &mut f);
        let cam = |k: &([f32; 4], (u16, u16))| {
            Camera::new(k.0[0], k.0[1], k.0[2], k.0[3], k.1 .0, k.1 .1).ok()
        };
        let (c1, c2) = (cam(&self.cam1)?, cam(&self.cam2)?);
        let px = |b: &[[f32; 2]]| b.iter().map(|p| Pixel::new(p[0], p[1])).collect::<Vec<_>>();
        let mut f1 = Frame::<{ SMALL.0 }, 1>::new(c1);
        f1.push_boundary(&px(&self.b1)).ok()?;
        let mut f2 = Frame::<{ SMALL.0 }, 1>::new(c2);
        if let Some(b2) = &self.b2 {
            f2.push_boundary(&px(b2)).ok()?;
        }
        let m = Motion::new(self.motion.t, self.motion.r).ok()?;
        let mut p = Box::new(Processor::<{ SMALL.0 }, 1>::new(config));
        let _ = p.process(&f1, None);
        let bits = |s: &Structure<{ SMALL.0 }, 1>| {
            s.boundaries()[0]
                .points()
                .iter()
                .map(|r| PointResultBits(r.status(), r.pixel2(), r.depth()))
                .collect::<Vec<_>>()
        };
        let a = bits(p.process_against_kept(&f2, &m).ok()?);
        let b = bits(p.reference_against_kept(&f2, &m).ok()?);
        Some((a, b))
    }

    /// Whether the matchers differ.
    pub fn differs(&self) -> bool {
        self.statuses().is_some_and(|(a, b)| a != b)
    }

    /// Drop points of either boundary while the matchers still differ.
    pub fn shrink(mut self) -> Pair {
        loop {
            let mut changed = false;
            for i in 0..self.b1.len() {
                let mut t = self.clone();
                t.b1.remove(i);
                if t.differs() {
                    self = t;
                    changed = true;
                    break;
                }
            }
            if let Some(b2) = self.b2.clone() {
                for i in 0..b2.len() {
                    let mut t = self.clone();
                    if let Some(b) = &mut t.b2 {
                        b.remove(i);
                    }
                    if t.differs() {
                        self = t;
                        changed = true;
                        break;
                    }
                }
            }
            for opt in 0..2 {
                let mut t = self.clone();
                if opt == 0 && t.config.translation_error.is_some() {
                    t.config.translation_error = None;
                } else if opt == 1 && t.config.rotation_error.is_some() {
                    t.config.rotation_error = None;
                } else {
                    continue;
                }
                if t.differs() {
                    self = t;
                    changed = true;
                }
            }
            if !changed {
                return self;
            }
        }
    }
}

/// A point's status, match and depth (for comparing the matchers).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointResultBits(pub Status, pub Option<Pixel>, pub Option<f32>);

/// The first reconstruction of `case` where the indexed matcher with the
/// largest budget differs from the reference, as a [`Pair`].
pub fn first_differing_pair(case: &Case) -> Option<Pair> {
    let mut kept: Option<(&FrameIn, Frame<{ SMALL.0 }, { SMALL.1 }>)> = None;
    let mut f = 0u128;
    let config = build_config(&case.config, &mut f);
    let keep = |fi: &FrameIn| -> Option<Frame<{ SMALL.0 }, { SMALL.1 }>> {
        let mut f = 0u128;
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            build_frame::<{ SMALL.0 }, { SMALL.1 }>(fi, &mut f)
        }))
        .ok()?
    };
    for call in &case.calls {
        let (fi, m, replaces) = match call {
            Call::Reset => {
                kept = None;
                continue;
            }
            Call::Process(fi, m) => (fi, *m, true),
            Call::AgainstKept(fi, m) => (fi, Some(*m), false),
        };
        let Some(frame) = keep(fi) else { continue };
        let motion = m.and_then(|m| Motion::new(m.t, m.r).ok().map(|x| (m, x)));
        if let (Some((kfi, kf)), Some((mi, mo))) = (&kept, motion) {
            let mut r = Box::new(Processor::<{ SMALL.0 }, { SMALL.1 }>::new(
                config.with_work_budget(Config::MAX_WORK_PER_POINT).ok()?,
            ));
            let _ = r.process(kf, None);
            let a = r.process_against_kept(&frame, &mo).ok()?.clone();
            let b = r.reference_against_kept(&frame, &mo).ok()?.clone();
            for (k, (x, y)) in a.boundaries().iter().zip(b.boundaries()).enumerate() {
                if x != y {
                    let pts = |fr: &Frame<{ SMALL.0 }, { SMALL.1 }>, k: usize| {
                        fr.boundaries()
                            .get(k)
                            .map(|b| b.points().iter().map(|p| [p.u, p.v]).collect::<Vec<_>>())
                    };
                    return Some(Pair {
                        config: case.config,
                        cam1: (kfi.k, kfi.size),
                        cam2: (fi.k, fi.size),
                        b1: pts(kf, k)?,
                        b2: pts(&frame, k),
                        motion: mi,
                    });
                }
            }
        }
        if replaces && (kept.is_none() || motion.is_some()) {
            kept = Some((fi, frame));
        }
    }
    None
}
