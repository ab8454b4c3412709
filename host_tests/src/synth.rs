//! Synthetic roads with ground truth, written independently of the
//! library's projection code: its own `f64` geometry, its own rotation
//! matrices, its own projection. Only the documented conventions are shared
//! (camera axes x right / y down / z forward; motion = frame-2 camera pose
//! in frame-1 camera coordinates, `R = R_y(β) R_x(α) R_z(γ)`).
//!
//! World frame: x right, y **down**, z forward; the ground at the vehicle is
//! `y = 0`; the camera sits `h` above it, pitched down by the tilt `θ`.

pub type V3 = [f64; 3];
pub type M3 = [[f64; 3]; 3];

/// Matrix product.
pub fn mm(a: &M3, b: &M3) -> M3 {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}
/// Matrix times vector.
pub fn mv(a: &M3, v: V3) -> V3 {
    [0, 1, 2].map(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}
/// Transpose.
pub fn tr(a: &M3) -> M3 {
    [0, 1, 2].map(|i| [a[0][i], a[1][i], a[2][i]])
}
fn rx(t: f64) -> M3 {
    let (s, c) = t.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}
fn ry(t: f64) -> M3 {
    let (s, c) = t.sin_cos();
    [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]
}
fn rz(t: f64) -> M3 {
    let (s, c) = t.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}
/// The rotation of the README's conventions, `R = R_y(β) R_x(α) R_z(γ)`
/// for angles `(α, β, γ)`.
pub fn rotation(angles: V3) -> M3 {
    mm(&mm(&ry(angles[1]), &rx(angles[0])), &rz(angles[2]))
}

/// Vector sum.
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// Vector difference.
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The camera intrinsics of the paper's simulation (Sec. 3) by default.
/// Pixels: `u = cx + fx x/z`, `v = cy + fy y/z` (README, "Conventions").
#[derive(Debug, Clone, Copy)]
pub struct Intrinsics {
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
    pub width: u16,
    pub height: u16,
}

impl Default for Intrinsics {
    fn default() -> Self {
        Self {
            fx: 800.0,
            fy: 800.0,
            cx: 255.5,
            cy: 239.5,
            width: 512,
            height: 480,
        }
    }
}

impl Intrinsics {
    /// The paper's calibrated camera (Appendix II B): non-square pixels
    /// (aspect 0.787) and an off-centre principal point, 512 × 480.
    pub fn paper_calibrated() -> Self {
        Self {
            fx: 614.5,
            fy: 780.7,
            cx: 273.59,
            cy: 233.96,
            width: 512,
            height: 480,
        }
    }

    /// Pixel of a point in camera coordinates (`None` behind or on the
    /// camera plane).
    pub fn project(&self, c: V3) -> Option<[f64; 2]> {
        (c[2] > 0.0).then(|| {
            [
                self.cx + self.fx * c[0] / c[2],
                self.cy + self.fy * c[1] / c[2],
            ]
        })
    }

    /// The normalised ray `(x, y, 1)` of a pixel.
    pub fn ray(&self, u: f64, v: f64) -> V3 {
        [(u - self.cx) / self.fx, (v - self.cy) / self.fy, 1.0]
    }

    pub fn camera(&self) -> roadstereo::Camera {
        roadstereo::Camera::new(
            self.fx as f32,
            self.fy as f32,
            self.cx as f32,
            self.cy as f32,
            self.width,
            self.height,
        )
        .expect("valid synthetic camera")
    }
}

/// The road: horizontal curvature in two pieces (an S-curve when they
/// differ in sign) and a vertical profile (crest or dip).
#[derive(Debug, Clone, Copy)]
pub struct Road {
    /// Road width (same unit as the camera height).
    pub width: f64,
    /// Curvature (1/radius, + turns right) before `switch_at`.
    pub curvature_a: f64,
    /// Curvature after `switch_at`.
    pub curvature_b: f64,
    /// Arc length where the curvature switches.
    pub switch_at: f64,
    /// Arc length where the vertical profile starts.
    pub grade_from: f64,
    /// Initial grade (rise per unit length, + up) from `grade_from`.
    pub grade: f64,
    /// Vertical curvature (+ bends up: a dip; − bends down: a crest).
    pub vertical_curvature: f64,
    /// Lateral offset of the road centreline from the vehicle at σ = 0 (+ right).
    pub centre_offset: f64,
    /// Heading of the road at σ = 0 relative to the vehicle (+ right), radians.
    pub heading: f64,
}

impl Road {
    pub fn straight(width: f64) -> Self {
        Self {
            width,
            curvature_a: 0.0,
            curvature_b: 0.0,
            switch_at: 1e9,
            grade_from: 1e9,
            grade: 0.0,
            vertical_curvature: 0.0,
            centre_offset: 0.0,
            heading: 0.0,
        }
    }

    fn curvature(&self, s: f64) -> f64 {
        if s < self.switch_at {
            self.curvature_a
        } else {
            self.curvature_b
        }
    }

    fn height(&self, s: f64) -> f64 {
        if s <= self.grade_from {
            0.0
        } else {
            let t = s - self.grade_from;
            self.grade * t + 0.5 * self.vertical_curvature * t * t
        }
    }

    /// Centreline at arc length `s` ≥ 0: `(position on the ground, heading,
    /// grade)` with the same integration as [`Road::boundaries`].
    pub fn centre_at(&self, s: f64, ds: f64) -> (V3, f64, f64) {
        let (mut t, mut p, mut psi) = (0.0, [self.centre_offset, 0.0, 0.0], self.heading);
        while t + 0.5 * ds < s {
            let k = self.curvature(t + 0.5 * ds);
            let pm = psi + 0.5 * k * ds;
            p = [p[0] + ds * pm.sin(), 0.0, p[2] + ds * pm.cos()];
            psi += k * ds;
            t += ds;
        }
        let grade = if t <= self.grade_from {
            0.0
        } else {
            self.grade + self.vertical_curvature * (t - self.grade_from)
        };
        ([p[0], -self.height(t), p[2]], psi, grade)
    }

    /// The two boundary curves (left, right) as fine 3-D polylines in the
    /// world frame, from arc length `-back` to `ahead`, step `ds`.
    pub fn boundaries(&self, back: f64, ahead: f64, ds: f64) -> [Vec<V3>; 2] {
        // Integrate the centreline (midpoint rule on the heading).
        let n_back = (back / ds).ceil() as usize;
        let n_ahead = (ahead / ds).ceil() as usize;
        let mut fwd = vec![(0.0f64, [self.centre_offset, 0.0, 0.0], self.heading)];
        let (mut s, mut p, mut psi) = (0.0, [self.centre_offset, 0.0, 0.0], self.heading);
        for _ in 0..n_ahead {
            let k = self.curvature(s + 0.5 * ds);
            let pm = psi + 0.5 * k * ds;
            p = [p[0] + ds * pm.sin(), 0.0, p[2] + ds * pm.cos()];
            psi += k * ds;
            s += ds;
            fwd.push((s, p, psi));
        }
        let (mut s, mut p, mut psi) = (0.0, [self.centre_offset, 0.0, 0.0], self.heading);
        let mut bwd = Vec::new();
        for _ in 0..n_back {
            let k = self.curvature(s - 0.5 * ds);
            let pm = psi - 0.5 * k * ds;
            p = [p[0] - ds * pm.sin(), 0.0, p[2] - ds * pm.cos()];
            psi -= k * ds;
            s -= ds;
            bwd.push((s, p, psi));
        }
        bwd.reverse();
        bwd.extend(fwd);
        let half = 0.5 * self.width;
        let mut out = [Vec::new(), Vec::new()];
        for (s, c, psi) in bwd {
            let y = -self.height(s);
            let n = [psi.cos(), 0.0, -psi.sin()]; // right normal
            out[0].push([c[0] - half * n[0], y, c[2] - half * n[2]]);
            out[1].push([c[0] + half * n[0], y, c[2] + half * n[2]]);
        }
        out
    }
}

/// A camera pose in the world: centre and orientation (columns = camera axes).
#[derive(Debug, Clone, Copy)]
pub struct Pose {
    pub centre: V3,
    pub rot: M3,
}

impl Pose {
    /// The camera on a vehicle at `position` (on the ground) with heading
    /// `yaw` (+ right), mounted `height` above the ground and pitched down
    /// by `tilt`.
    pub fn vehicle_camera(position: V3, yaw: f64, height: f64, tilt: f64) -> Self {
        Self {
            centre: add(position, [0.0, -height, 0.0]),
            rot: mm(&ry(yaw), &rx(-tilt)),
        }
    }

    /// A camera on a vehicle that is also pitched (nose up by `pitch`).
    pub fn vehicle_camera_pitched(
        position: V3,
        yaw: f64,
        pitch: f64,
        height: f64,
        tilt: f64,
    ) -> Self {
        // "Up" from the vehicle is along its own -y axis.
        let body = mm(&ry(yaw), &rx(pitch));
        Self {
            centre: add(position, mv(&body, [0.0, -height, 0.0])),
            rot: mm(&body, &rx(-tilt)),
        }
    }

    /// World point → camera coordinates.
    pub fn to_camera(&self, p: V3) -> V3 {
        mv(&tr(&self.rot), sub(p, self.centre))
    }

    /// The pose after the documented motion: translation `t` (in this
    /// camera's coordinates) and rotation angles (α, β, γ).
    pub fn moved(&self, t: V3, angles: V3) -> Self {
        let rel = rotation(angles);
        Self {
            centre: add(self.centre, mv(&self.rot, t)),
            rot: mm(&self.rot, &rel),
        }
    }

    /// The motion (translation, angles) from `self` to `other`, in the
    /// documented convention.
    pub fn motion_to(&self, other: &Pose) -> (V3, V3) {
        let t = mv(&tr(&self.rot), sub(other.centre, self.centre));
        let r = mm(&tr(&self.rot), &other.rot);
        let alpha = (-r[1][2]).clamp(-1.0, 1.0).asin();
        let beta = r[0][2].atan2(r[2][2]);
        let gamma = r[1][0].atan2(r[1][1]);
        (t, [alpha, beta, gamma])
    }
}

/// One detected boundary point with its ground truth.
#[derive(Debug, Clone, Copy)]
pub struct TruePoint {
    /// Exact (sub-pixel) column on this row.
    pub u: f64,
    /// Image row (an integer).
    pub v: f64,
    /// The 3-D point in this frame's camera coordinates.
    pub camera: V3,
    /// Position along the world polyline (fine-segment index + fraction):
    /// the same 3-D point has the same `arc` in every frame.
    pub arc: f64,
}

/// Project the world polyline and keep, for each integer image row, the
/// exact crossing — one boundary point per row, from the bottom of the image
/// upwards, stopping where the curve leaves the image, folds back in the
/// image (a crest hides the rest) or passes `max_depth`.
pub fn detect(curve: &[V3], pose: &Pose, k: &Intrinsics, max_depth: f64) -> Vec<TruePoint> {
    let rows: Vec<f64> = (0..k.height).rev().map(f64::from).collect();
    detect_rows(curve, pose, k, max_depth, &rows)
}

/// [`detect`] at the given rows (in decreasing order, may be fractional).
pub fn detect_rows(
    curve: &[V3],
    pose: &Pose,
    k: &Intrinsics,
    max_depth: f64,
    rows: &[f64],
) -> Vec<TruePoint> {
    let proj: Vec<(V3, f64)> = curve
        .iter()
        .map(|&p| {
            let c = pose.to_camera(p);
            let v = if c[2] > 1e-3 {
                k.cy + k.fy * c[1] / c[2]
            } else {
                f64::NAN
            };
            (c, v)
        })
        .collect();
    let mut out: Vec<TruePoint> = Vec::new();
    let mut started = false;
    let mut next = 0; // index into rows
    for (seg, w) in proj.windows(2).enumerate() {
        let ((c0, v0), (c1, v1)) = (w[0], w[1]);
        if !(v0.is_finite() && v1.is_finite()) || c0[2] < 0.05 {
            if started {
                break;
            }
            continue;
        }
        if v1 > v0 {
            // The curve turns back downwards in the image: occluded beyond.
            if started {
                break;
            }
            continue;
        }
        if c1[2] > max_depth {
            break;
        }
        // Skip rows below this segment (not reached yet by the curve).
        while next < rows.len() && rows[next] > v0 {
            next += 1;
        }
        while next < rows.len() && rows[next] > v1 {
            let r = rows[next];
            next += 1;
            let d = sub(c1, c0);
            let rr = r - k.cy;
            let den = k.fy * d[1] - rr * d[2];
            if den.abs() <= 1e-15 {
                continue;
            }
            let lam = ((rr * c0[2]) - k.fy * c0[1]) / den;
            let p = [c0[0] + lam * d[0], c0[1] + lam * d[1], c0[2] + lam * d[2]];
            let u = k.cx + k.fx * p[0] / p[2];
            if !(0.0..=f64::from(k.width) - 1.0).contains(&u) {
                if started {
                    return out;
                }
            } else {
                started = true;
                out.push(TruePoint {
                    u,
                    v: r,
                    camera: p,
                    arc: seg as f64 + lam,
                });
            }
        }
        if next >= rows.len() {
            break;
        }
    }
    out
}

/// The vehicle motion between two frames, in the vehicle (road) frame.
#[derive(Debug, Clone, Copy, Default)]
pub struct Drive {
    /// Forward distance along the vehicle heading (+ forward).
    pub forward: f64,
    /// Sideways distance (+ right).
    pub lateral: f64,
    /// Vertical distance (+ up).
    pub up: f64,
    /// Heading change (+ right), radians.
    pub yaw: f64,
    /// Extra camera pitch change (+ up), radians.
    pub pitch: f64,
    /// Extra camera roll change (+ clockwise), radians.
    pub roll: f64,
}

/// A complete two-frame scenario.
#[derive(Debug, Clone)]
pub struct Scenario {
    pub name: String,
    pub intrinsics: Intrinsics,
    pub road: Road,
    pub height: f64,
    pub tilt: f64,
    pub drive: Drive,
    /// Or: a pure camera-frame translation/rotation instead of `drive`.
    pub camera_motion: Option<(V3, V3)>,
    /// The detector reports every `row_step`-th image row (1: every row),
    /// the rows `v` with `v % row_step == row_phase`.
    pub row_step: u16,
    pub row_phase: u16,
    /// How far ahead the road is modelled and detected (length units).
    pub range: f64,
}

/// Frames of a scenario with ground truth.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// Boundaries seen (with at least 2 points) in both frames; index `k`
    /// of frame 1 corresponds to index `k` of frame 2.
    pub frame1: Vec<Vec<TruePoint>>,
    pub frame2: Vec<Vec<TruePoint>>,
    pub translation: V3,
    pub angles: V3,
    pub pose1: Pose,
    pub pose2: Pose,
    /// World boundary polylines (for plots).
    pub world: [Vec<V3>; 2],
    /// For each boundary `k` of `frame1`/`frame2`, its curve in `world`.
    pub world_index: Vec<usize>,
}

impl Scenario {
    pub fn new(name: &str, road: Road, drive: Drive) -> Self {
        Self {
            name: name.to_string(),
            intrinsics: Intrinsics::default(),
            road,
            height: 1.0,
            tilt: 23f64.to_radians(),
            drive,
            camera_motion: None,
            row_step: 1,
            row_phase: 0,
            range: 60.0,
        }
    }

    /// The frame-1 camera pose in the world (at the origin, heading 0).
    pub fn pose1(&self) -> Pose {
        Pose::vehicle_camera([0.0, 0.0, 0.0], 0.0, self.height, self.tilt)
    }

    /// The image rows the detector reports, bottom up.
    pub fn rows(&self) -> Vec<f64> {
        let step = self.row_step.max(1);
        (0..self.intrinsics.height)
            .rev()
            .filter(|r| r % step == self.row_phase % step)
            .map(f64::from)
            .collect()
    }

    pub fn render(&self) -> Rendered {
        let pose1 = self.pose1();
        let pose2 = match self.camera_motion {
            Some((t, a)) => pose1.moved(t, a),
            None => {
                let d = &self.drive;
                // Vehicle moves in its own frame, then turns; the camera may
                // pitch/roll on top (suspension).
                let pos = [d.lateral, -d.up, d.forward];
                let base = Pose::vehicle_camera(pos, d.yaw, self.height, self.tilt);
                Pose {
                    centre: base.centre,
                    rot: mm(&mm(&base.rot, &rx(d.pitch)), &rz(d.roll)),
                }
            }
        };
        // A given camera motion is the motion, exactly (`W = 0` stays 0, not
        // the 1e-17 the round trip through the poses would give).
        let (translation, angles) = self
            .camera_motion
            .unwrap_or_else(|| pose1.motion_to(&pose2));
        let world = self.road.boundaries(2.0, self.range, 0.01);
        let k = &self.intrinsics;
        let rows = self.rows();
        let mut frame1 = Vec::new();
        let mut frame2 = Vec::new();
        let mut world_index = Vec::new();
        for (wi, curve) in world.iter().enumerate() {
            let b1 = detect_rows(curve, &pose1, k, self.range, &rows);
            let b2 = detect_rows(curve, &pose2, k, self.range, &rows);
            if b1.len() >= 2 && b2.len() >= 2 {
                frame1.push(b1);
                frame2.push(b2);
                world_index.push(wi);
            }
        }
        Rendered {
            frame1,
            frame2,
            translation,
            angles,
            pose1,
            pose2,
            world,
            world_index,
        }
    }
}

impl Rendered {
    pub fn motion(&self) -> roadstereo::Motion {
        roadstereo::Motion::new(
            self.translation.map(|x| x as f32),
            self.angles.map(|x| x as f32),
        )
        .expect("valid synthetic motion")
    }

    /// Pixel polylines of one frame, exact or rounded to the pixel grid.
    pub fn pixels(frame: &[Vec<TruePoint>], quantised: bool) -> Vec<Vec<roadstereo::Pixel>> {
        frame
            .iter()
            .map(|b| {
                b.iter()
                    .map(|p| {
                        let u = if quantised { p.u.round() } else { p.u };
                        roadstereo::Pixel::new(u as f32, p.v as f32)
                    })
                    .collect()
            })
            .collect()
    }

    /// Whether the true frame-2 correspondent of frame-1 point `i` of
    /// boundary `b` is in the frame-2 data: its 3-D point lies within the
    /// stretch of the curve the frame-2 detector returned (the paper's
    /// assumption (1), Sec. 2: the correspondence exists).
    pub fn correspondent_observed(&self, b: usize, i: usize) -> bool {
        let (Some(b1), Some(b2)) = (self.frame1.get(b), self.frame2.get(b)) else {
            return false;
        };
        let (Some(p), Some(first), Some(last)) = (b1.get(i), b2.first(), b2.last()) else {
            return false;
        };
        let (lo, hi) = if first.arc <= last.arc {
            (first.arc, last.arc)
        } else {
            (last.arc, first.arc)
        };
        (lo..=hi).contains(&p.arc)
    }

    /// The orientation of the frame-2 camera in frame-1 camera coordinates
    /// (`R` of the README's conventions).
    pub fn relative_rotation(&self) -> M3 {
        mm(&tr(&self.pose1.rot), &self.pose2.rot)
    }

    /// The rotation-compensated position and the true frame-2 position of a
    /// frame-1 pixel, by this module's own geometry (for test statistics).
    pub fn compensate(&self, k: &Intrinsics, u: f64, v: f64) -> [f64; 2] {
        let ray = k.ray(u, v);
        let q = mv(&tr(&self.relative_rotation()), ray);
        [k.cx + k.fx * q[0] / q[2], k.cy + k.fy * q[1] / q[2]]
    }
}

/// A small deterministic generator (SplitMix64) for seeded scenarios.
#[derive(Debug, Clone)]
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
    pub fn chance(&mut self, p: f64) -> bool {
        self.uniform(0.0, 1.0) < p
    }
}
