//! Certification of the guarantee (issue 11, sections 2 and 4): seeded
//! scenario families run through the library with four detector variants,
//! each within the library's stated error model, and checked point by point
//! against ground truth computed from the generator's own geometry.
//!
//! **The model** (README's first section, `docs/METHOD.md`, `src/depth.rs`): the true frame-1 point is within
//! `e₁` of the detected one; the true frame-2 boundary curve is within `e₂`
//! of the frame-2 polyline (every point of the true curve, over the stretch
//! frame 2 observed, within `e₂` of some point of the polyline).
//!
//! **The variants** ([`Variant`]) move the detected points by less than a
//! nominal error `ê₁`, `ê₂`. The frame-2 polyline also deviates from the
//! curved truth by its chords' sagitta, more so when the detector reports
//! only every 2nd or 3rd row, so the declared `e₂` adds a chord allowance
//! measured per scenario: `e₂ = ê₂ + a`, `a` ≥ the largest distance of the
//! true curve from the polyline of the *exact* points. By the triangle
//! inequality the true curve is then within `ê₂ + a` of the moved polyline.
//! [`Input`] measures both (the frame-1 offsets exactly, the frame-2
//! deviation by a rigorous upper bound, [`deviation_bound`]) so the tests
//! can assert that every variant is inside the declared model.
//!
//! **The truth** per frame-1 point ([`PointTruth`]): the depth of the true
//! point it stands for; whether its correspondent is in the frame-2 data;
//! the two-view ideal (the correspondent exists, the true epipolar line
//! meets the true frame-2 curve at ≥ [`MIN_ANGLE_DEG`], the true disparity
//! exceeds `e₁ + e₂`); whether the true frame-1 curve folds there (its true
//! epipolar half-line from the FOE meets the true frame-1 curve again).
//! None of it uses the library's geometry: only the documented conventions.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use roadstereo::{Config, Frame, Pixel, Processor, Status, Step};

use crate::jsonl::{CameraIn, FrameIn, MotionIn};
use crate::scenarios::Family;
use crate::synth::{self, mv, tr, Intrinsics, Rendered, Rng, Scenario, TruePoint, V3};
use crate::{B, N};

/// The minimum crossing angle given to the library and used by the ideal.
pub const MIN_ANGLE_DEG: f64 = 10.0;
/// The maximum depth given to the library (beyond every modelled road).
pub const MAX_DEPTH: f32 = 1000.0;
/// Piece length (pixels) of the frame-2 deviation bound.
const PIECE_PX: f64 = 0.25;
/// A piece whose bound exceeds its end values by more than this is halved.
const BOUND_SLACK_PX: f64 = 2e-3;
/// Grid of the declared chord allowance, pixels.
const ALLOWANCE_STEP: f64 = 0.005;
/// Share of the nominal error the noise and the adversary use ("just under").
const JUST_UNDER: f64 = 0.999;

type P2 = [f64; 2];

/// A detector variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Variant {
    /// Sub-pixel points on the true curve (only the `f32` rounding).
    Exact,
    /// `u` rounded to the pixel grid on each (integer) row.
    Rounded,
    /// Every point moved by a random vector shorter than the nominal error
    /// (uniform in the disc of radius 0.999 ê).
    Disc,
    /// Frame-1 points moved 0.999 ê₁ along the true curve's normal to one
    /// side, frame-2 points 0.999 ê₂ to the other (the side drawn per
    /// boundary).
    Adversarial,
}

impl Variant {
    /// Every variant, in report order.
    pub const ALL: [Variant; 4] = [
        Variant::Exact,
        Variant::Rounded,
        Variant::Disc,
        Variant::Adversarial,
    ];

    /// Short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Exact => "exact",
            Variant::Rounded => "rounded",
            Variant::Disc => "disc",
            Variant::Adversarial => "adversarial",
        }
    }

    /// The variant with this name.
    pub fn from_name(name: &str) -> Option<Variant> {
        Variant::ALL.into_iter().find(|v| v.name() == name)
    }

    /// The nominal localisation errors `(ê₁, ê₂)`, pixels: the exact
    /// detector's cover the `f32` rounding of the pixels and of the
    /// library's own arithmetic; the others are the paper's `e = 1` px.
    pub fn nominal(self) -> (f64, f64) {
        match self {
            Variant::Exact => (0.01, 0.01),
            Variant::Rounded | Variant::Disc | Variant::Adversarial => (0.5, 0.5),
        }
    }
}

/// Ground truth of one frame-1 point, from the generator's geometry.
#[derive(Debug, Clone, Copy)]
pub struct PointTruth {
    /// Depth (frame-1 camera `z`) of the true point.
    pub z_true: f64,
    /// The true correspondent is in the frame-2 data (within the stretch of
    /// the curve frame 2 observed).
    pub observed: bool,
    /// The true point, rotation-compensated (frame-2 orientation), pixels.
    pub p1c: P2,
    /// The true correspondent in frame 2, pixels (`None` behind the camera).
    pub p2: Option<P2>,
    /// `|p₂ − p₁'|` of the true points, pixels.
    pub disparity: f64,
    /// Angle between the true epipolar line and the true frame-2 curve at
    /// the true correspondent, degrees in `[0, 90]` (NaN if undefined).
    pub angle_deg: f64,
    /// The true epipolar half-line from the FOE through this point meets
    /// the true frame-1 curve (the stretch frame 1 observed) again, away
    /// from the point (not in the two segments next to it).
    pub folds: bool,
}

impl PointTruth {
    /// The two-view ideal for total localisation error `e` (= e₁ + e₂):
    /// the correspondent exists, the crossing is at least
    /// [`MIN_ANGLE_DEG`] steep and the disparity exceeds `e`.
    pub fn ideal(&self, e: f64) -> bool {
        self.observed && self.p2.is_some() && self.disparity > e && self.angle_deg >= MIN_ANGLE_DEG
    }
}

/// Whether **any** method that guarantees its stick could bound the far
/// end of detected frame-1 point `p` against the detected frame-2
/// polyline `poly` with the declared errors `(e₁, e₂)`: the polyline
/// passes farther than `r₁ + e₂` from the compensated point, `r₁` the
/// smallest radius of the image of `p`'s `e₁` disc under the compensation
/// (24 directions, to first order; 0.1 % taken off). If it passes nearer,
/// a true frame-1 point within `e₁` of `p` and a true frame-2 curve within
/// `e₂` of the polyline can meet at one image point: zero disparity,
/// infinite depth, consistent with both detections, so no guaranteed
/// stick is bounded.
pub fn boundable(
    r: &Rendered,
    k: &Intrinsics,
    p: Pixel,
    poly: &[Pixel],
    (e1, e2): (f64, f64),
) -> bool {
    let (u, v) = (f64::from(p.u), f64::from(p.v));
    let c = r.compensate(k, u, v);
    let h = 1e-3;
    let r1 = (0..24)
        .map(|j| {
            let a = std::f64::consts::TAU * f64::from(j) / 24.0;
            let q = r.compensate(k, u + h * a.cos(), v + h * a.sin());
            norm2(sub2(q, c)) / h
        })
        .fold(f64::INFINITY, f64::min)
        * e1
        * 0.999;
    let dist = poly
        .windows(2)
        .map(|w| {
            let (a, b) = (
                [f64::from(w[0].u), f64::from(w[0].v)],
                [f64::from(w[1].u), f64::from(w[1].v)],
            );
            let (ab, ac) = (sub2(b, a), sub2(c, a));
            let l2 = dot2(ab, ab);
            let t = if l2 > 0.0 {
                (dot2(ac, ab) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            norm2(sub2(c, [a[0] + t * ab[0], a[1] + t * ab[1]]))
        })
        .fold(f64::INFINITY, f64::min);
    dist > r1 + e2 * 0.999
}

/// A rendered scenario with its ground truth.
#[derive(Debug, Clone)]
pub struct Case {
    pub family: Family,
    pub seed: u64,
    pub scenario: Scenario,
    pub rendered: Rendered,
    /// Per boundary, per frame-1 point.
    pub truth: Vec<Vec<PointTruth>>,
    /// Per boundary, the true frame-2 curve over the observed stretch (the
    /// projected world polyline), pixels.
    pub curve2: Vec<Vec<P2>>,
    /// Unit normals of the true image curves at the detected points
    /// (tangent along the world polyline turned by +90°), frames 1 and 2.
    pub normal1: Vec<Vec<P2>>,
    pub normal2: Vec<Vec<P2>>,
    /// Upper bound of the true frame-2 curve's distance from the polyline
    /// of the exact points (the chords' sagitta), over all boundaries.
    pub sagitta: f64,
}

fn sub2(a: P2, b: P2) -> P2 {
    [a[0] - b[0], a[1] - b[1]]
}
fn dot2(a: P2, b: P2) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}
fn cross2(a: P2, b: P2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}
fn norm2(a: P2) -> f64 {
    a[0].hypot(a[1])
}
fn cross3(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Distance from `q` to the segment `a b`.
pub fn point_segment_distance(q: P2, a: P2, b: P2) -> f64 {
    let d = sub2(b, a);
    let l2 = dot2(d, d);
    let t = if l2 > 0.0 {
        (dot2(sub2(q, a), d) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm2(sub2(q, [a[0] + t * d[0], a[1] + t * d[1]]))
}

/// A rigorous upper bound of the largest distance from a point of the
/// polyline `truth` to the polyline `poly` (`max over x ∈ truth of
/// min over y ∈ poly |x − y|`).
///
/// Each segment of `truth` is cut into pieces of at most [`PIECE_PX`];
/// on a piece `[a, b]` the distance to the polyline is bounded by the
/// smaller of two bounds, both valid: the distance to one fixed segment of
/// `poly` is convex along the piece, so at most the larger of its values
/// at `a` and `b` (take the best segment); and the distance to the
/// polyline is 1-Lipschitz, so at most `(d(a) + d(b) + |b − a|)/2`. A
/// piece where this is looser than `max(d(a), d(b))` by more than 2e-3 px
/// (the nearest segment changes inside it) is halved, up to 12 times. The
/// candidates are the segments of `poly` within 3 of the one nearest the
/// previous piece (both polylines run monotonically in `v`); a nearest
/// segment outside them only makes the bound larger, never smaller.
pub fn deviation_bound(truth: &[P2], poly: &[P2]) -> f64 {
    if poly.len() < 2 || truth.is_empty() {
        return f64::INFINITY;
    }
    let mut d = Deviation { poly, cur: 0 };
    d.cur = (0..poly.len() - 1)
        .min_by(|&i, &j| d.dist(truth[0], i).total_cmp(&d.dist(truth[0], j)))
        .unwrap_or(0);
    let mut worst = d.piece(truth[0], truth[0], 0);
    for w in truth.windows(2) {
        let (a, b) = (w[0], w[1]);
        let pieces = (norm2(sub2(b, a)) / PIECE_PX).ceil().max(1.0) as usize;
        let mut prev = a;
        for k in 1..=pieces {
            let t = k as f64 / pieces as f64;
            let next = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            worst = worst.max(d.piece(prev, next, 0));
            prev = next;
        }
    }
    worst
}

/// State of [`deviation_bound`]: the polyline and the segment nearest the
/// last piece.
struct Deviation<'a> {
    poly: &'a [P2],
    cur: usize,
}

impl Deviation<'_> {
    fn dist(&self, q: P2, j: usize) -> f64 {
        point_segment_distance(q, self.poly[j], self.poly[j + 1])
    }

    /// The bound on one piece, halved (up to 12 times) where the convex
    /// bound is loose, i.e. where the nearest segment changes inside it.
    fn piece(&mut self, a: P2, b: P2, depth: u32) -> f64 {
        let segs = self.poly.len() - 1;
        let (mut convex, mut da, mut db, mut best_b) =
            (f64::INFINITY, f64::INFINITY, f64::INFINITY, self.cur);
        for j in self.cur.saturating_sub(3)..(self.cur + 4).min(segs) {
            let (fa, fb) = (self.dist(a, j), self.dist(b, j));
            convex = convex.min(fa.max(fb));
            da = da.min(fa);
            if fb < db {
                db = fb;
                best_b = j;
            }
        }
        let lipschitz = 0.5 * (da + db + norm2(sub2(b, a)));
        let bound = convex.min(lipschitz);
        if depth < 12 && bound > da.max(db) + BOUND_SLACK_PX {
            let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
            let left = self.piece(a, m, depth + 1);
            return left.max(self.piece(m, b, depth + 1));
        }
        self.cur = best_b;
        bound
    }
}

/// Fold flags of a compensated curve `v` about the homogeneous FOE `foe`:
/// for each vertex `j`, whether the half-line from the FOE through `v[j]`
/// (the whole line when the FOE is at infinity) meets the curve again in a
/// segment not adjacent to `j`.
pub fn fold_flags(v: &[P2], foe: V3) -> Vec<bool> {
    let n = v.len();
    let fxy = [foe[0], foe[1]];
    let fz = foe[2];
    let mut out = vec![false; n];
    let mut side = vec![0.0; n];
    for j in 0..n {
        let p = v[j];
        let l = cross3([p[0], p[1], 1.0], foe);
        for (k, q) in v.iter().enumerate() {
            side[k] = l[0] * q[0] + l[1] * q[1] + l[2];
        }
        // Away from the FOE along the line, scaled by fz² (no division).
        let ray = sub2([p[0] * fz, p[1] * fz], fxy);
        out[j] = (0..n.saturating_sub(1)).any(|k| {
            if k + 1 == j || k == j {
                return false;
            }
            let (s0, s1) = (side[k], side[k + 1]);
            if !((s0 <= 0.0 && s1 >= 0.0) || (s0 >= 0.0 && s1 <= 0.0)) || (s0 == 0.0 && s1 == 0.0) {
                return false;
            }
            let t = s0 / (s0 - s1);
            let x = [
                v[k][0] + t * (v[k + 1][0] - v[k][0]),
                v[k][1] + t * (v[k + 1][1] - v[k][1]),
            ];
            dot2(sub2([x[0] * fz, x[1] * fz], fxy), ray) > 0.0
        });
    }
    out
}

/// Unit tangent (along increasing arc) of the image of `curve` at `arc`.
fn image_tangent(curve: &[V3], arc: f64, pose: &synth::Pose, k: &Intrinsics) -> Option<P2> {
    let s = (arc.floor().max(0.0) as usize).min(curve.len() - 2);
    let a = k.project(pose.to_camera(curve[s]))?;
    let b = k.project(pose.to_camera(curve[s + 1]))?;
    let d = sub2(b, a);
    let l = norm2(d);
    (l > 0.0).then(|| [d[0] / l, d[1] / l])
}

fn normal_of(t: Option<P2>) -> P2 {
    t.map_or([1.0, 0.0], |t| [-t[1], t[0]])
}

/// The FOE in the compensated (frame-2 oriented) image, homogeneous:
/// `K Rᵀ T`.
pub fn foe_h(r: &Rendered, k: &Intrinsics) -> V3 {
    let t = mv(&tr(&r.relative_rotation()), r.translation);
    [k.fx * t[0] + k.cx * t[2], k.fy * t[1] + k.cy * t[2], t[2]]
}

impl Case {
    /// Render scenario `seed` of `family` and compute its truth; `None`
    /// when no boundary is seen in both frames.
    pub fn new(family: Family, seed: u64) -> Option<Case> {
        Case::of(family, seed, family.scenario(seed))
    }

    /// [`Case::new`] for a given scenario.
    pub fn of(family: Family, seed: u64, scenario: Scenario) -> Option<Case> {
        let r = scenario.render();
        if r.frame1.is_empty() {
            return None;
        }
        let k = scenario.intrinsics;
        let foe = foe_h(&r, &k);
        let mut truth = Vec::new();
        let (mut curve2, mut normal1, mut normal2) = (Vec::new(), Vec::new(), Vec::new());
        let mut sagitta = 0.0f64;
        for (b, (b1, b2)) in r.frame1.iter().zip(&r.frame2).enumerate() {
            let curve = &r.world[r.world_index[b]];
            // The true frame-1 curve at every row over the observed stretch.
            let (lo1, hi1) = arc_range(b1);
            let dense: Vec<TruePoint> = if scenario.row_step <= 1 {
                b1.clone()
            } else {
                synth::detect(curve, &r.pose1, &k, scenario.range)
                    .into_iter()
                    .filter(|p| p.arc >= lo1 - 1e-9 && p.arc <= hi1 + 1e-9)
                    .collect()
            };
            let dense_c: Vec<P2> = dense.iter().map(|p| r.compensate(&k, p.u, p.v)).collect();
            let folds = fold_flags(&dense_c, foe);
            // The true frame-2 curve over the observed stretch.
            let (lo2, hi2) = arc_range(b2);
            let mut c2 = vec![[b2[0].u, b2[0].v]];
            let first_vertex = lo2.floor() as usize + 1;
            for w in curve.iter().take(hi2.ceil() as usize).skip(first_vertex) {
                if let Some(p) = k.project(r.pose2.to_camera(*w)) {
                    c2.push(p);
                }
            }
            let last = b2[b2.len() - 1];
            c2.push([last.u, last.v]);
            let exact: Vec<P2> = b2.iter().map(|p| [p.u, p.v]).collect();
            sagitta = sagitta.max(deviation_bound(&c2, &exact));
            let mut tb = Vec::new();
            for (i, p) in b1.iter().enumerate() {
                let world = synth::add(r.pose1.centre, mv(&r.pose1.rot, p.camera));
                let p2 = k.project(r.pose2.to_camera(world));
                let p1c = r.compensate(&k, p.u, p.v);
                let (mut disparity, mut angle_deg) = (f64::NAN, f64::NAN);
                if let Some(p2) = p2 {
                    let d = sub2(p2, p1c);
                    disparity = norm2(d);
                    if let Some(t) = image_tangent(curve, p.arc, &r.pose2, &k) {
                        if disparity > 0.0 {
                            angle_deg = cross2(d, t).abs().atan2(dot2(d, t).abs()).to_degrees();
                        }
                    }
                }
                let j = dense
                    .iter()
                    .position(|q| q.v == p.v && (q.arc - p.arc).abs() < 1e-6);
                tb.push(PointTruth {
                    z_true: p.camera[2],
                    observed: r.correspondent_observed(b, i),
                    p1c,
                    p2,
                    disparity,
                    angle_deg,
                    folds: j.is_some_and(|j| folds[j]),
                });
            }
            truth.push(tb);
            curve2.push(c2);
            normal1.push(
                b1.iter()
                    .map(|p| normal_of(image_tangent(curve, p.arc, &r.pose1, &k)))
                    .collect(),
            );
            normal2.push(
                b2.iter()
                    .map(|p| normal_of(image_tangent(curve, p.arc, &r.pose2, &k)))
                    .collect(),
            );
        }
        Some(Case {
            family,
            seed,
            scenario,
            rendered: r,
            truth,
            curve2,
            normal1,
            normal2,
            sagitta,
        })
    }

    /// The declared chord allowance: the sagitta bound rounded up to the
    /// allowance grid, plus one step of margin for the bound's own slack.
    pub fn allowance(&self) -> f64 {
        (self.sagitta / ALLOWANCE_STEP).ceil() * ALLOWANCE_STEP + ALLOWANCE_STEP
    }

    /// Points over all boundaries.
    pub fn points(&self) -> usize {
        self.truth.iter().map(Vec::len).sum()
    }
}

fn arc_range(b: &[TruePoint]) -> (f64, f64) {
    let (a, z) = (b[0].arc, b[b.len() - 1].arc);
    (a.min(z), a.max(z))
}

/// One variant's detector output for a case, with its declared errors and
/// the measured deviations from the truth.
#[derive(Debug, Clone)]
pub struct Input {
    pub variant: Variant,
    /// Declared errors given to the library.
    pub e1: f64,
    pub e2: f64,
    pub frame1: Vec<Vec<Pixel>>,
    pub frame2: Vec<Vec<Pixel>>,
    /// Largest `|detected − true|` over the frame-1 points (as `f32`).
    pub dev1: f64,
    /// Upper bound of the true frame-2 curve's distance from the polyline.
    pub dev2: f64,
    /// Boundaries whose points were moved along the row instead of the
    /// normal (the normal move broke the row order).
    pub fallbacks: usize,
}

impl Input {
    /// The library configuration for this input.
    pub fn config(&self) -> Config {
        Config::new(
            self.e1 as f32,
            self.e2 as f32,
            MIN_ANGLE_DEG as f32,
            MAX_DEPTH,
        )
        .expect("valid configuration")
    }

    /// Both frames as library frames.
    pub fn frames(&self, k: &Intrinsics) -> Result<(Frame<N, B>, Frame<N, B>), String> {
        Ok((make_frame(k, &self.frame1)?, make_frame(k, &self.frame2)?))
    }
}

fn make_frame(k: &Intrinsics, bs: &[Vec<Pixel>]) -> Result<Frame<N, B>, String> {
    let mut f = Frame::new(k.camera());
    for (i, b) in bs.iter().enumerate() {
        f.push_boundary(b)
            .map_err(|e| format!("boundary {i}: {e}"))?;
    }
    Ok(f)
}

fn valid_boundary(k: &Intrinsics, b: &[Pixel]) -> bool {
    let mut f = Frame::<N, B>::new(k.camera());
    f.push_boundary(b).is_ok()
}

fn px(p: P2) -> Pixel {
    Pixel::new(p[0] as f32, p[1] as f32)
}
fn of_px(p: Pixel) -> P2 {
    [f64::from(p.u), f64::from(p.v)]
}

/// The detector of one variant: its random numbers and how often it had
/// to fall back to moves along the row.
struct Mover<'a> {
    variant: Variant,
    g: Rng,
    k: &'a Intrinsics,
    fallbacks: usize,
}

impl Mover<'_> {
    /// Move the points of one boundary; `side` ±1 for the adversary,
    /// `radius` the nominal error.
    fn boundary(
        &mut self,
        pts: &[TruePoint],
        normals: &[P2],
        radius: f64,
        side: f64,
    ) -> Vec<Pixel> {
        let rho = JUST_UNDER * radius;
        let (g, k) = (&mut self.g, self.k);
        match self.variant {
            Variant::Exact => pts.iter().map(|p| px([p.u, p.v])).collect(),
            Variant::Rounded => pts.iter().map(|p| px([p.u.round(), p.v])).collect(),
            Variant::Disc => {
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
                    .map(|(p, &(r, a))| px([p.u + r * a.cos(), p.v + r * a.sin()]))
                    .collect();
                if valid_boundary(k, &out) {
                    return out;
                }
                self.fallbacks += 1;
                pts.iter()
                    .zip(&moves)
                    .map(|(p, &(r, a))| px([p.u + r * a.cos().signum(), p.v]))
                    .collect()
            }
            Variant::Adversarial => {
                let out: Vec<Pixel> = pts
                    .iter()
                    .zip(normals)
                    .map(|(p, n)| px([p.u + side * rho * n[0], p.v + side * rho * n[1]]))
                    .collect();
                if valid_boundary(k, &out) {
                    return out;
                }
                self.fallbacks += 1;
                pts.iter()
                    .zip(normals)
                    .map(|(p, n)| px([p.u + side * rho * n[0].signum(), p.v]))
                    .collect()
            }
        }
    }
}

impl Case {
    /// The detector output of `variant` for this case.
    pub fn input(&self, variant: Variant) -> Input {
        let (n1, n2) = variant.nominal();
        let e1 = n1;
        let e2 = n2 + self.allowance();
        let k = &self.scenario.intrinsics;
        let mut mover = Mover {
            variant,
            g: Rng(self
                .seed
                .wrapping_mul(0xA24B_AED4_963E_E407)
                .wrapping_add((self.family as u64) << 32 | variant as u64)),
            k,
            fallbacks: 0,
        };
        let (mut frame1, mut frame2) = (Vec::new(), Vec::new());
        let r = &self.rendered;
        for b in 0..r.frame1.len() {
            let side = if mover.g.chance(0.5) { 1.0 } else { -1.0 };
            frame1.push(mover.boundary(&r.frame1[b], &self.normal1[b], n1, side));
            frame2.push(mover.boundary(&r.frame2[b], &self.normal2[b], n2, -side));
        }
        let fallbacks = mover.fallbacks;
        let dev1 = frame1
            .iter()
            .zip(&r.frame1)
            .flat_map(|(d, t)| {
                d.iter()
                    .zip(t)
                    .map(|(d, t)| norm2(sub2(of_px(*d), [t.u, t.v])))
            })
            .fold(0.0, f64::max);
        let dev2 = frame2
            .iter()
            .zip(&self.curve2)
            .map(|(d, c)| deviation_bound(c, &d.iter().map(|p| of_px(*p)).collect::<Vec<_>>()))
            .fold(0.0, f64::max);
        Input {
            variant,
            e1,
            e2,
            frame1,
            frame2,
            dev1,
            dev2,
            fallbacks,
        }
    }
}

/// The library's result for one point.
#[derive(Debug, Clone, Copy)]
pub struct Outcome {
    pub status: Status,
    pub z: f64,
    pub z_near: f64,
    pub z_far: f64,
    pub p2: Option<P2>,
}

impl Outcome {
    pub fn contains(&self, z: f64) -> bool {
        self.z_near <= z && z <= self.z_far
    }
}

/// Run the library on an input (a fresh processor with the input's
/// configuration), as [`crate::reconstruct`] does.
pub fn run(
    k: &Intrinsics,
    motion: &roadstereo::Motion,
    input: &Input,
) -> Result<Vec<Vec<Outcome>>, String> {
    run_with(k, motion, input, Fold::Tested)
}

/// Whether the library runs its fold test (step 2) on a case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fold {
    /// As shipped.
    Tested,
    /// Switched off (`Processor::without_fold_test_against_kept`): every
    /// folded point searched, for the check that the search alone holds
    /// the containment guarantee.
    Untested,
    /// With the counting rule on (`Processor::set_fold_counting`): the
    /// points that fold searched where the rule allows.
    Counted,
    /// As shipped, within a deadline (`Processor::process_within`) whose
    /// clock says the time is up from its `k`-th question on: the points
    /// not done by then `over_budget`, the rest complete results.
    Within(usize),
}

/// [`run`] with or without the fold test.
pub fn run_with(
    k: &Intrinsics,
    motion: &roadstereo::Motion,
    input: &Input,
    fold: Fold,
) -> Result<Vec<Vec<Outcome>>, String> {
    let (f1, f2) = input.frames(k)?;
    run_frames(&f1, &f2, motion, input.config(), fold)
}

fn run_frames(
    f1: &Frame<N, B>,
    f2: &Frame<N, B>,
    motion: &roadstereo::Motion,
    config: Config,
    fold: Fold,
) -> Result<Vec<Vec<Outcome>>, String> {
    let mut p = Box::new(Processor::<N, B>::new(config));
    match p.process(f1, None) {
        Ok(Step::First) => {}
        other => return Err(format!("first frame: {other:?}")),
    }
    let s = match fold {
        Fold::Tested => match p.process(f2, Some(motion)) {
            Ok(Step::Structure(s)) => s,
            other => return Err(format!("second frame: {other:?}")),
        },
        Fold::Counted => {
            p.set_fold_counting(true);
            match p.process(f2, Some(motion)) {
                Ok(Step::Structure(s)) => s,
                other => return Err(format!("second frame: {other:?}")),
            }
        }
        Fold::Untested => match p.without_fold_test_against_kept(f2, motion, false) {
            Ok(s) => s,
            other => return Err(format!("second frame: {other:?}")),
        },
        Fold::Within(k) => {
            let mut asked = 0usize;
            let mut clock = || {
                asked += 1;
                asked > k
            };
            match p.process_within(f2, Some(motion), &mut clock) {
                Ok(Step::Structure(s)) => s,
                other => return Err(format!("second frame: {other:?}")),
            }
        }
    };
    Ok(s.boundaries()
        .iter()
        .map(|b| {
            b.points()
                .iter()
                .map(|r| {
                    let (z, zn, zf) = match (r.depth(), r.interval()) {
                        (Some(z), Some(iv)) => {
                            (f64::from(z), f64::from(iv.z_near), f64::from(iv.z_far))
                        }
                        _ => (f64::NAN, f64::NAN, f64::NAN),
                    };
                    Outcome {
                        status: r.status(),
                        z,
                        z_near: zn,
                        z_far: zf,
                        p2: r.pixel2().map(of_px),
                    }
                })
                .collect()
        })
        .collect())
}

/// Counts for one (family, variant) cell of the report.
#[derive(Debug, Clone, Default)]
pub struct Tally {
    pub scenarios: usize,
    pub points: usize,
    /// Points of the two-view ideal.
    pub ideal: usize,
    /// `Status::Ok` points (the actual yield).
    pub ok: usize,
    /// `Ok` points that are ideal.
    pub ok_ideal: usize,
    /// `Ok` points whose correspondent is in frame 2, and of those the ones
    /// whose stick contains the truth.
    pub ok_observed: usize,
    pub contained: usize,
    /// `Ok` points whose correspondent is not in frame 2, and of those the
    /// ones whose stick misses the truth (no two-view method can tell).
    pub ok_unobserved: usize,
    pub ok_unobserved_miss: usize,
    /// `Folded` flags, and those on ideal points of a curve that does not
    /// fold there.
    pub folded: usize,
    pub folded_spurious: usize,
    /// The ideal points by library status (indexed like `Status::ALL`).
    pub ideal_by_status: Vec<usize>,
    /// Ideal points where the true frame-1 curve folds.
    pub ideal_folds: usize,
    /// Relative stick widths `(z_far − z_near)/z_true` of the `Ok` points
    /// with a correspondent.
    pub widths: Vec<f32>,
    /// Ideal points whose far end any guaranteed stick could bound: the
    /// frame-2 polyline passes farther than `r₁ + e₂` from the detected
    /// compensated point ([`boundable`]).
    pub ideal_boundable: usize,
}

impl Tally {
    pub fn add(&mut self, o: &Tally) {
        self.scenarios += o.scenarios;
        self.points += o.points;
        self.ideal += o.ideal;
        self.ok += o.ok;
        self.ok_ideal += o.ok_ideal;
        self.ok_observed += o.ok_observed;
        self.contained += o.contained;
        self.ok_unobserved += o.ok_unobserved;
        self.ok_unobserved_miss += o.ok_unobserved_miss;
        self.folded += o.folded;
        self.folded_spurious += o.folded_spurious;
        self.ideal_folds += o.ideal_folds;
        self.widths.extend_from_slice(&o.widths);
        self.ideal_boundable += o.ideal_boundable;
        if self.ideal_by_status.len() < o.ideal_by_status.len() {
            self.ideal_by_status.resize(o.ideal_by_status.len(), 0);
        }
        for (a, b) in self.ideal_by_status.iter_mut().zip(&o.ideal_by_status) {
            *a += b;
        }
    }
    /// Ideal yield: ideal points / points.
    pub fn ideal_yield(&self) -> f64 {
        ratio(self.ideal, self.points)
    }
    /// Actual yield: `Ok` points / points.
    pub fn actual_yield(&self) -> f64 {
        ratio(self.ok, self.points)
    }
    /// Actual / ideal (`Ok` points / ideal points).
    pub fn actual_over_ideal(&self) -> f64 {
        ratio(self.ok, self.ideal)
    }
    /// Share of the ideal points that are `Ok`.
    pub fn ideal_recall(&self) -> f64 {
        ratio(self.ok_ideal, self.ideal)
    }
    /// Share of the `Ok` points with a correspondent whose stick holds the truth.
    pub fn containment(&self) -> f64 {
        ratio(self.contained, self.ok_observed)
    }
    /// The `q`-quantile (0..1) of the relative stick widths, NaN if none.
    pub fn width_quantile(&self, q: f64) -> f64 {
        let mut w = self.widths.clone();
        if w.is_empty() {
            return f64::NAN;
        }
        w.sort_by(f32::total_cmp);
        let i = ((w.len() - 1) as f64 * q).round() as usize;
        f64::from(w[i])
    }
    /// Share of the ideal points any guaranteed stick could bound.
    pub fn boundable_share(&self) -> f64 {
        ratio(self.ideal_boundable, self.ideal)
    }
    /// Spurious `Folded` flags as a share of the ideal points.
    pub fn folded_loss(&self) -> f64 {
        ratio(self.folded_spurious, self.ideal)
    }

    /// The share of the ideal points (true crossing at least
    /// [`MIN_ANGLE_DEG`] steep) flagged `grazing`.
    pub fn grazing_loss(&self) -> f64 {
        let i = Status::ALL.iter().position(|&x| x == Status::Grazing);
        ratio(
            i.and_then(|i| self.ideal_by_status.get(i).copied())
                .unwrap_or(0),
            self.ideal,
        )
    }
}

fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 {
        f64::NAN
    } else {
        a as f64 / b as f64
    }
}

/// A contained-truth failure.
#[derive(Debug, Clone)]
pub struct Miss {
    pub family: Family,
    pub seed: u64,
    pub variant: Variant,
    pub boundary: usize,
    pub index: usize,
    pub p1: P2,
    pub z_true: f64,
    pub outcome: Outcome,
    pub truth: PointTruth,
    /// How far outside the stick, relative to the true depth.
    pub severity: f64,
}

impl Miss {
    /// One line for the report.
    pub fn describe(&self) -> String {
        let o = &self.outcome;
        let off = match (o.p2, self.truth.p2) {
            (Some(a), Some(b)) => format!("{:.1}", norm2(sub2(a, b))),
            _ => "-".into(),
        };
        format!(
            "{}/{} {} b{} i{} p1 ({:.2}, {:.0}): z_true {:.4} outside [{:.4}, {:.4}] (z {:.4}, {}), \
             true disparity {:.2} px, angle {:.1}°, match {off} px from the true correspondent",
            self.family.name(),
            self.seed,
            self.variant.name(),
            self.boundary,
            self.index,
            self.p1[0],
            self.p1[1],
            self.z_true,
            o.z_near,
            o.z_far,
            o.z,
            o.status,
            self.truth.disparity,
            self.truth.angle_deg,
        )
    }
}

/// The checks of one case in one variant.
#[derive(Debug, Clone)]
pub struct Checked {
    pub variant: Variant,
    pub tally: Tally,
    pub misses: Vec<Miss>,
    /// Model violations of the input (a failure of the test itself).
    pub model_errors: Vec<String>,
    /// Boundaries moved along the row instead (see [`Input::fallbacks`]).
    pub fallbacks: usize,
}

/// Run one case in one variant and check every point.
pub fn check(case: &Case, variant: Variant) -> Checked {
    check_with(case, variant, Fold::Tested)
}

/// [`check`] with or without the library's fold test.
pub fn check_with(case: &Case, variant: Variant, fold: Fold) -> Checked {
    let input = case.input(variant);
    let mut model_errors = Vec::new();
    let name = format!("{}/{} {}", case.family.name(), case.seed, variant.name());
    if input.dev1 > input.e1 {
        model_errors.push(format!(
            "{name}: frame-1 offset {} > e1 {}",
            input.dev1, input.e1
        ));
    }
    if input.dev2 > input.e2 {
        model_errors.push(format!(
            "{name}: frame-2 deviation {} > e2 {}",
            input.dev2, input.e2
        ));
    }
    let k = &case.scenario.intrinsics;
    let out = match run_with(k, &case.rendered.motion(), &input, fold) {
        Ok(o) => o,
        Err(e) => {
            model_errors.push(format!("{name}: {e}"));
            Vec::new()
        }
    };
    let e = input.e1 + input.e2;
    let mut t = Tally {
        scenarios: 1,
        ideal_by_status: vec![0; Status::ALL.len()],
        ..Tally::default()
    };
    let mut misses = Vec::new();
    for (b, (ob, tb)) in out.iter().zip(&case.truth).enumerate() {
        for (i, (o, tr)) in ob.iter().zip(tb).enumerate() {
            t.points += 1;
            let ideal = tr.ideal(e);
            let ok = o.status == Status::Ok;
            if ideal {
                t.ideal += 1;
                t.ideal_folds += usize::from(tr.folds);
                let (d1, d2) = (&input.frame1, &input.frame2);
                if let (Some(p), Some(poly)) = (d1.get(b).and_then(|f| f.get(i)), d2.get(b)) {
                    t.ideal_boundable +=
                        usize::from(boundable(&case.rendered, k, *p, poly, (input.e1, input.e2)));
                }
                if let Some(s) = Status::ALL.iter().position(|&s| s == o.status) {
                    t.ideal_by_status[s] += 1;
                }
            }
            if o.status == Status::Folded {
                t.folded += 1;
                if ideal && !tr.folds {
                    t.folded_spurious += 1;
                }
            }
            if !ok {
                continue;
            }
            t.ok += 1;
            t.ok_ideal += usize::from(ideal);
            let inside = o.contains(tr.z_true);
            if !tr.observed {
                t.ok_unobserved += 1;
                t.ok_unobserved_miss += usize::from(!inside);
                continue;
            }
            t.ok_observed += 1;
            t.widths.push(((o.z_far - o.z_near) / tr.z_true) as f32);
            if inside {
                t.contained += 1;
            } else {
                let severity =
                    ((o.z_near - tr.z_true).max(tr.z_true - o.z_far) / tr.z_true).max(0.0);
                misses.push(Miss {
                    family: case.family,
                    seed: case.seed,
                    variant,
                    boundary: b,
                    index: i,
                    p1: of_px(input.frame1[b][i]),
                    z_true: tr.z_true,
                    outcome: *o,
                    truth: *tr,
                    severity: if severity.is_nan() {
                        f64::INFINITY
                    } else {
                        severity
                    },
                });
            }
        }
    }
    Checked {
        variant,
        tally: t,
        misses,
        model_errors,
        fallbacks: input.fallbacks,
    }
}

fn camera_in(k: &Intrinsics) -> CameraIn {
    CameraIn {
        fx: k.fx as f32,
        fy: k.fy as f32,
        cx: k.cx as f32,
        cy: k.cy as f32,
        width: k.width,
        height: k.height,
    }
}

fn replay_text(
    k: &Intrinsics,
    m: &roadstereo::Motion,
    f1: &[Vec<Pixel>],
    f2: &[Vec<Pixel>],
) -> String {
    let line = |bs: &[Vec<Pixel>], motion: Option<MotionIn>| {
        serde_json::to_string(&FrameIn {
            camera: camera_in(k),
            motion,
            boundaries: bs
                .iter()
                .map(|b| b.iter().map(|p| [p.u, p.v]).collect())
                .collect(),
        })
        .expect("serialisable")
    };
    format!(
        "{}\n{}",
        line(f1, None),
        line(
            f2,
            Some(MotionIn {
                translation: m.translation(),
                rotation: m.angles(),
            })
        )
    )
}

/// A replay (JSON Lines, README "Replay") that reproduces a miss, as
/// small as found cheaply: frame 1 cut to the point and its neighbour,
/// frame 2 shrunk from either end, each cut kept only if the point still
/// comes out `ok` with a stick that misses the truth; `None` if not even
/// the full frames reproduce it. The configuration is printed with it
/// (`e1`, `e2`).
pub fn replay_for(case: &Case, miss: &Miss) -> Option<String> {
    let input = case.input(miss.variant);
    let k = &case.scenario.intrinsics;
    let m = case.rendered.motion();
    let config = input.config();
    let misses = |f1: &[Vec<Pixel>], f2: &[Vec<Pixel>], b: usize, i: usize| -> bool {
        let (Ok(a), Ok(c)) = (make_frame(k, f1), make_frame(k, f2)) else {
            return false;
        };
        run_frames(&a, &c, &m, config, Fold::Tested).is_ok_and(|o| {
            o.get(b)
                .and_then(|ob| ob.get(i))
                .is_some_and(|o| o.status == Status::Ok && !o.contains(miss.z_true))
        })
    };
    let (b, i) = (miss.boundary, miss.index);
    if !misses(&input.frame1, &input.frame2, b, i) {
        return None;
    }
    let b1 = &input.frame1[b];
    let j = if i + 1 < b1.len() { i + 1 } else { i - 1 };
    let mut f1 = vec![vec![b1[i], b1[j]]];
    let mut f2 = vec![input.frame2[b].clone()];
    if !misses(&f1, &f2, 0, 0) {
        f1 = input.frame1.clone();
        f2 = input.frame2.clone();
        return Some(with_config(&input, replay_text(k, &m, &f1, &f2)));
    }
    // Shrink frame 2 from either end while the miss persists.
    let mut b2 = f2[0].clone();
    let mut chunk = b2.len() / 2;
    while chunk >= 1 {
        let mut shrunk = false;
        for from_start in [true, false] {
            if b2.len() < chunk + 2 {
                continue;
            }
            let cut = if from_start {
                b2[chunk..].to_vec()
            } else {
                b2[..b2.len() - chunk].to_vec()
            };
            if misses(&f1, std::slice::from_ref(&cut), 0, 0) {
                b2 = cut;
                shrunk = true;
            }
        }
        if !shrunk {
            chunk /= 2;
        }
    }
    f2 = vec![b2];
    Some(with_config(&input, replay_text(k, &m, &f1, &f2)))
}

fn with_config(input: &Input, text: String) -> String {
    format!(
        "# Config::new({}, {}, {MIN_ANGLE_DEG}, {MAX_DEPTH}); frame-1 point 0 of boundary 0 \
         (unless the full frames are given)\n{text}",
        input.e1 as f32, input.e2 as f32
    )
}

/// Results of a certification run.
#[derive(Debug, Default)]
pub struct Report {
    pub cells: BTreeMap<(Family, Variant), Tally>,
    pub misses: Vec<Miss>,
    pub model_errors: Vec<String>,
    pub skipped: usize,
    pub cases: usize,
    pub largest_allowance: f64,
    pub fallbacks: usize,
}

impl Report {
    /// The total over every family of one variant.
    pub fn variant_total(&self, v: Variant) -> Tally {
        let mut t = Tally::default();
        for ((_, cv), c) in &self.cells {
            if *cv == v {
                t.add(c);
            }
        }
        t
    }

    /// The report table: one row per family and variant, totals per variant.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "| family | variant | scen. | points | ideal | actual (ok) | actual/ideal | ok∩ideal/ideal | containment | misses | folded loss |"
        );
        let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
        let row = |s: &mut String, f: &str, v: &str, t: &Tally| {
            let _ = writeln!(
                s,
                "| {f} | {v} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                t.scenarios,
                t.points,
                pct(t.ideal_yield()),
                pct(t.actual_yield()),
                pct(t.actual_over_ideal()),
                pct(t.ideal_recall()),
                containment(t),
                t.ok_observed - t.contained,
                pct(t.folded_loss()),
            );
        };
        for ((f, v), t) in &self.cells {
            row(&mut s, f.name(), v.name(), t);
        }
        for v in Variant::ALL {
            row(&mut s, "**all**", v.name(), &self.variant_total(v));
        }
        s
    }

    /// Where the ideal points go, per family and variant: the share of
    /// them with each outcome (`folded` split by whether the true curve
    /// folds there), and the share on which the true curve folds.
    pub fn where_table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "| family | variant | ideal | true folds | ok | folded (true fold) | folded (no fold) | grazing | unbounded | ambiguous | no_intersection | other |"
        );
        let _ = writeln!(
            s,
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
        );
        let at = |t: &Tally, st: Status| {
            Status::ALL
                .iter()
                .position(|&x| x == st)
                .and_then(|i| t.ideal_by_status.get(i).copied())
                .unwrap_or(0)
        };
        let row = |s: &mut String, f: &str, v: &str, t: &Tally| {
            let named = [
                Status::Ok,
                Status::Folded,
                Status::Grazing,
                Status::Unbounded,
                Status::Ambiguous,
                Status::NoIntersection,
            ];
            let other = t.ideal - named.iter().map(|&st| at(t, st)).sum::<usize>();
            let folded = at(t, Status::Folded);
            let p = |n: usize| pct(ratio(n, t.ideal));
            let _ = writeln!(
                s,
                "| {f} | {v} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                t.ideal,
                p(t.ideal_folds),
                p(at(t, Status::Ok)),
                p(folded - t.folded_spurious),
                p(t.folded_spurious),
                p(at(t, Status::Grazing)),
                p(at(t, Status::Unbounded)),
                p(at(t, Status::Ambiguous)),
                p(at(t, Status::NoIntersection)),
                p(other),
            );
        };
        for ((f, v), t) in &self.cells {
            row(&mut s, f.name(), v.name(), t);
        }
        for v in Variant::ALL {
            row(&mut s, "**all**", v.name(), &self.variant_total(v));
        }
        s
    }

    /// Where the ideal points go: their library status, per variant.
    pub fn loss_table(&self) -> String {
        let mut s = String::new();
        let _ = write!(s, "| variant | ideal |");
        for st in Status::ALL {
            let _ = write!(s, " {st} |");
        }
        let _ = writeln!(s);
        let _ = writeln!(s, "|---|---:|{}", "---:|".repeat(Status::ALL.len()));
        for v in Variant::ALL {
            let t = self.variant_total(v);
            let _ = write!(s, "| {} | {} |", v.name(), t.ideal);
            for n in &t.ideal_by_status {
                let _ = write!(s, " {} |", pct(ratio(*n, t.ideal)));
            }
            let _ = writeln!(s);
        }
        s
    }
}

fn pct(x: f64) -> String {
    if x.is_nan() {
        "-".into()
    } else {
        format!("{:.1} %", 100.0 * x)
    }
}

fn containment(t: &Tally) -> String {
    if t.ok_observed == 0 {
        "-".into()
    } else if t.contained == t.ok_observed {
        "100 %".into()
    } else {
        format!("{:.3} %", 100.0 * t.contained as f64 / t.ok_observed as f64)
    }
}

/// Run `per_family` seeds of every family in every variant, on all cores.
pub fn certify(families: &[Family], seeds: std::ops::Range<u64>) -> Report {
    certify_with(families, seeds, Fold::Tested)
}

/// [`certify`] with or without the library's fold test.
pub fn certify_with(families: &[Family], seeds: std::ops::Range<u64>, fold: Fold) -> Report {
    let jobs: Vec<(Family, u64)> = families
        .iter()
        .flat_map(|&f| seeds.clone().map(move |s| (f, s)))
        .collect();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let threads = std::thread::available_parallelism()
        .map_or(4, |n| n.get())
        .min(32);
    type Out = (usize, Option<(Vec<Checked>, f64)>);
    let mut results: Vec<Out> = std::thread::scope(|sc| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                sc.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let j = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(&(f, seed)) = jobs.get(j) else {
                            break;
                        };
                        let r = Case::new(f, seed).map(|c| {
                            (
                                Variant::ALL
                                    .iter()
                                    .map(|&v| check_with(&c, v, fold))
                                    .collect(),
                                c.allowance(),
                            )
                        });
                        mine.push((j, r));
                    }
                    mine
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("worker"))
            .collect()
    });
    results.sort_by_key(|r| r.0);
    let mut rep = Report::default();
    for (j, r) in results {
        let Some((checked, allowance)) = r else {
            rep.skipped += 1;
            continue;
        };
        rep.cases += 1;
        rep.largest_allowance = rep.largest_allowance.max(allowance);
        let f = jobs[j].0;
        for c in checked {
            rep.cells.entry((f, c.variant)).or_default().add(&c.tally);
            rep.misses.extend(c.misses);
            rep.model_errors.extend(c.model_errors);
            rep.fallbacks += c.fallbacks;
        }
    }
    rep.misses.sort_by(|a, b| b.severity.total_cmp(&a.severity));
    rep
}

/// Distance from `q` to the polyline `poly`.
pub fn polyline_distance(q: P2, poly: &[P2]) -> f64 {
    poly.windows(2)
        .map(|w| point_segment_distance(q, w[0], w[1]))
        .fold(f64::INFINITY, f64::min)
}

/// Two-view geometry in `f64` from the README's conventions alone (for the
/// replay-format reproducers): camera `k` in both frames, the frame-2
/// camera at `t` with orientation `R(angles)` in frame-1 coordinates.
#[derive(Debug, Clone, Copy)]
pub struct Geometry {
    pub k: Intrinsics,
    pub r: synth::M3,
    pub t: V3,
}

impl Geometry {
    pub fn new(k: Intrinsics, t: V3, angles: V3) -> Self {
        Self {
            k,
            r: synth::rotation(angles),
            t,
        }
    }

    /// The frame-1 ray `(x, y, 1)` of a pixel.
    pub fn ray1(&self, p: P2) -> V3 {
        self.k.ray(p[0], p[1])
    }

    /// The frame-2 pixel of a point in frame-1 coordinates, `K Rᵀ (P − T)`.
    pub fn project2(&self, p: V3) -> Option<P2> {
        self.k.project(mv(&tr(&self.r), synth::sub(p, self.t)))
    }

    /// A frame-1 pixel rotation-compensated, `K Rᵀ K⁻¹ p`.
    pub fn compensate(&self, p: P2) -> Option<P2> {
        self.k.project(mv(&tr(&self.r), self.ray1(p)))
    }

    /// The FOE in the compensated image, homogeneous, `K Rᵀ T`.
    pub fn foe(&self) -> V3 {
        let t = mv(&tr(&self.r), self.t);
        [
            self.k.fx * t[0] + self.k.cx * t[2],
            self.k.fy * t[1] + self.k.cy * t[2],
            t[2],
        ]
    }

    /// The depth of the correspondence `p1 ↔ p2`: `Z` of the least-squares
    /// solution of `Z Rᵀ r₁ − λ r₂ = Rᵀ T`.
    pub fn depth(&self, p1: P2, p2: P2) -> f64 {
        let a = mv(&tr(&self.r), self.ray1(p1));
        let c = self.k.ray(p2[0], p2[1]);
        let b = mv(&tr(&self.r), self.t);
        let d = |x: V3, y: V3| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
        let (aa, ac, cc, ab, cb) = (d(a, a), d(a, c), d(c, c), d(a, b), d(c, b));
        // [aa −ac; −ac cc] [Z; λ] = [ab; −cb]
        let det = aa * cc - ac * ac;
        (ab * cc - ac * cb) / det
    }

    /// Where the exact epipolar line of `p1` (the whole line through the
    /// FOE) crosses the polyline `poly`.
    pub fn crossings(&self, p1: P2, poly: &[P2]) -> Vec<P2> {
        let Some(p) = self.compensate(p1) else {
            return Vec::new();
        };
        let l = cross3([p[0], p[1], 1.0], self.foe());
        let side = |q: P2| l[0] * q[0] + l[1] * q[1] + l[2];
        poly.windows(2)
            .filter_map(|w| {
                let (s0, s1) = (side(w[0]), side(w[1]));
                if s0 == s1 || s0 * s1 > 0.0 {
                    return None;
                }
                let t = s0 / (s0 - s1);
                Some([
                    w[0][0] + t * (w[1][0] - w[0][0]),
                    w[0][1] + t * (w[1][1] - w[0][1]),
                ])
            })
            .collect()
    }

    /// The smallest distance from the frame-2 polyline of the image of the
    /// point at depth `z` on the ray of some pixel within `e1` of `p1`
    /// (a polar grid over the disc): the depth is consistent with both
    /// images within the errors iff this is at most `e₂` (up to the grid).
    pub fn consistency(&self, p1: P2, e1: f64, z: f64, poly: &[P2]) -> f64 {
        let mut best = f64::INFINITY;
        for ri in 0..=20 {
            let r = e1 * f64::from(ri) / 20.0;
            let n = if ri == 0 { 1 } else { 8 * ri };
            for ai in 0..n {
                let a = std::f64::consts::TAU * f64::from(ai) / f64::from(n);
                let q = [p1[0] + r * a.cos(), p1[1] + r * a.sin()];
                let ray = self.ray1(q);
                if let Some(p2) = self.project2(ray.map(|x| x * z)) {
                    best = best.min(polyline_distance(p2, poly));
                }
            }
        }
        best
    }
}
