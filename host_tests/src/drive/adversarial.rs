//! The adversarial benchmark family of issue 11: frame pairs that pass
//! [`roadstereo::Frame::push_boundary`] but cost the matching stage far more
//! than the representative pair, at N = 64, 128, 256 and 512 points per
//! boundary (two boundaries), written as RSD1 files
//! (`src/bin/data/adv_<member>_<N>.bin`, format: [`super::encode`]) with a
//! generated table for the bench firmware (`src/bin/data/adversarial.rs`).
//!
//! Every member is one [`Params`] value rendered by [`render`] at each N,
//! in the bench's camera scheme (one detector point per image row: N ≤ 128
//! the paper's 512 × 480 camera, f = 800; N = 256 the same field of view at
//! 1024 × 960, N = 512 at 2048 × 1920; [`camera_for`]). Every length in a
//! [`Params`] is in *paper pixels* (the 512 × 480 camera) and is scaled
//! with the camera, and every vertex position is counted from an end of the
//! boundary, so one [`Params`] is the same scene at every N: that is what
//! makes the N = 512 / N = 64 per-point budget meaningful for the searched
//! members too.
//!
//! The base is the representative pair ([`super::bench_pair_one_per_row`]:
//! the Fig. 6 set-up, a right curve of radius 15 driven forward 0.4 with 5°
//! of steering; [`Params::fig6`] renders it bit for bit, a test checks it);
//! the members change one or a few things (the list: [`hand_members`]):
//!
//! * spurious detector points ([`Spur`]): a vertex near an end of a
//!   boundary moved to the image edge (in frame 2, frame 1 or both);
//! * the scene: a straight road driven straight ([`Scene::Straight`]: every
//!   boundary runs through the FOE, along the epipolar lines), or a
//!   quantised edge at a constant small angle to the direction of the FOE
//!   ([`Scene::Spiral`]);
//! * the motion ([`Foe`], [`Params::turn`]): the translation turned so the
//!   focus of expansion sits at a chosen pixel (inside the image, on or near
//!   a boundary), an extra camera rotation;
//! * the detector: u rounded to the pixel grid or exact, rows spread evenly
//!   (sub-pixel, the bench's) or on integer rows ([`Rows`]), zig-zags
//!   ([`Params::zigzag`]), one frame-1 vertex lifted above the FOE's row
//!   ([`Lift`]).
//!
//! [`mutate`] changes any of these at random; `cargo run --release --bin
//! adversarial -- --search --seed S` (host_tests/src/bin/adversarial.rs)
//! runs a seeded search with it and keeps the costliest pairs it finds,
//! stored as [`Params`] in `adversarial_found.json` beside this file, so
//! rendering them stays deterministic ([`found_members`]).

use serde::{Deserialize, Serialize};

use super::DriveFrame;
use crate::synth::{self, Intrinsics, Pose, Road, V3};

/// The sizes every member is rendered at (points per boundary).
pub const SIZES: [usize; 4] = [64, 128, 256, 512];

/// Where the searched members are kept (relative to this file).
pub const FOUND_JSON: &str = include_str!("adversarial_found.json");

/// The file name of member `name` at `n` points per boundary.
pub fn file_name(name: &str, n: usize) -> String {
    format!("adv_{name}_{n}.bin")
}

/// The camera scale for `n` points per boundary: the smallest power of two
/// that gives the representative pair's shorter boundary (152 rows at the
/// paper's resolution) at least `n` rows, as [`super::bench_pair_one_per_row`].
pub fn scale_for(n: usize) -> u16 {
    let mut s = 1u16;
    while 152 * usize::from(s) < n {
        s *= 2;
    }
    s
}

/// The bench's camera for `n` points per boundary (the paper's, scaled).
pub fn camera_for(n: usize) -> Intrinsics {
    let s = scale_for(n);
    let base = Intrinsics::default();
    let sf = f64::from(s);
    Intrinsics {
        fx: base.fx * sf,
        fy: base.fy * sf,
        cx: (base.cx + 0.5) * sf - 0.5,
        cy: (base.cy + 0.5) * sf - 0.5,
        width: base.width * s,
        height: base.height * s,
    }
}

/// A paper pixel coordinate in the camera of scale `s`.
fn scaled(x: f64, s: f64) -> f64 {
    (x + 0.5) * s - 0.5
}

/// The world and the motion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Scene {
    /// The representative pair's road and motion: a right curve of radius
    /// 15, road width 1.3, camera 1 above the road tilted 23°, driven
    /// forward 0.4 with 5° of steering to the right.
    Fig6,
    /// A straight road driven straight along it (forward 0.4): both
    /// boundaries are straight lines through the focus of expansion, so
    /// every epipolar line runs along a boundary.
    Straight,
    /// The Fig. 6 motion, but each boundary a logarithmic spiral about the
    /// FOE that meets every radial line at `deg` degrees (a straight edge
    /// nearly along the epipolar lines, with the angle constant along it),
    /// starting at the bottom end of the Fig. 6 frame-2 boundary and running
    /// up to the top of the image; frame 1 is the same curve contracted
    /// towards the FOE by 0.9 in the rotation-compensated image (a positive
    /// disparity for every point), mapped back through the rotation.
    Spiral {
        /// Angle to the radial direction, degrees (boundary 1 leans the
        /// other way).
        deg: f64,
    },
}

/// Which rows the detector reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Rows {
    /// N rows spread evenly over each boundary's visible extent (sub-pixel
    /// rows, the bench's scheme).
    Even,
    /// The same rows rounded to integers (the pixel grid).
    Integer,
}

/// Where the focus of expansion is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Foe {
    /// Where the scene's motion puts it (Fig. 6: about (185, −100), above
    /// the image).
    Natural,
    /// The translation turned (length and rotation kept) so the FOE is at
    /// `(u, v)` in frame 2's image, paper pixels.
    At {
        /// Column, paper pixels.
        u: f64,
        /// Row, paper pixels.
        v: f64,
    },
}

/// A spurious detector point: vertex `k` from the start (`from_end`:
/// from the end) of boundary `boundary` moved to column `u` (a fraction of
/// the image width: 0 the left edge, 1 the right edge), row kept.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Spur {
    /// 1: frame 1, 2: frame 2, 3: both.
    pub frames: u8,
    /// Boundary index (0 left, 1 right).
    pub boundary: usize,
    /// Count from the end instead of the start.
    pub from_end: bool,
    /// Vertex index from that end.
    pub k: usize,
    /// New column as a fraction of `width − 1`.
    pub u: f64,
}

/// One frame-1 vertex lifted above the FOE's row: the last (topmost)
/// vertex of `boundary`, moved so its rotation-compensated position is
/// `above` paper pixels above the FOE's row (compensated column kept).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Lift {
    /// Boundary index.
    pub boundary: usize,
    /// Paper pixels above the FOE's row.
    pub above: f64,
}

/// One adversarial pair, independent of N (lengths in paper pixels).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Params {
    /// World and motion.
    pub scene: Scene,
    /// Columns rounded to the pixel grid (else exact, sub-pixel).
    pub quantise: bool,
    /// Rows reported.
    pub rows: Rows,
    /// Focus of expansion.
    pub foe: Foe,
    /// Extra rotation of camera 2 about its own axes (α, β, γ as in
    /// `Motion`), degrees.
    pub turn: [f64; 3],
    /// Zig-zag amplitude per frame, paper pixels: vertex `i`'s column moves
    /// by `+a` for even `i`, `−a` for odd `i` (clamped to the image).
    pub zigzag: [f64; 2],
    /// Spurious points, applied after the zig-zag.
    pub spurious: Vec<Spur>,
    /// A frame-1 vertex above the FOE's row, applied last.
    pub lift: Option<Lift>,
    /// The detector's topmost row, paper pixels (a region of interest
    /// below the horizon; 0: the whole image).
    #[serde(default)]
    pub top: f64,
    /// The camera moves backwards: the two frames swapped (frame 2's view
    /// first) and the motion inverted. The per-frame settings above
    /// (`zigzag`, `spurious`, `lift`) name the frames before the swap.
    #[serde(default)]
    pub reverse: bool,
}

impl Params {
    /// The representative pair (the bench's `bench_N.bin`).
    pub fn fig6() -> Self {
        Params {
            scene: Scene::Fig6,
            quantise: true,
            rows: Rows::Even,
            foe: Foe::Natural,
            turn: [0.0; 3],
            zigzag: [0.0; 2],
            spurious: Vec::new(),
            lift: None,
            top: 0.0,
            reverse: false,
        }
    }
}

/// The error model a member's processor is configured with (`Config`
/// builders; the bench firmware's `member_config` maps the same ids).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Errors {
    /// `Config::DEFAULT`: localisation errors only.
    #[default]
    Default,
    /// A rotation error of 0.01 rad about each axis
    /// (`with_rotation_error([0.01; 3])`): step 1 certifies no image, the
    /// points are checked one by one.
    Rotation,
    /// A rotation error of 0.001 rad about the optical axis only.
    RotationZ,
    /// A translation error of 0.02 (`with_translation_error(0.02)`): the
    /// wedge does not hold the band, every point takes the band path.
    Translation,
}

impl Errors {
    /// The processor's configuration (the bench firmware's `member_config`
    /// at the default work budget).
    pub fn config(self) -> roadstereo::Config {
        let c = roadstereo::Config::DEFAULT;
        match self {
            Errors::Default => Ok(c),
            Errors::Rotation => c.with_rotation_error([0.01; 3]),
            Errors::RotationZ => c.with_rotation_error([0.0, 0.0, 0.001]),
            Errors::Translation => c.with_translation_error(0.02),
        }
        .expect("valid error bounds")
    }

    /// The id in the firmware's table.
    pub fn id(self) -> u8 {
        match self {
            Errors::Default => 0,
            Errors::Rotation => 1,
            Errors::RotationZ => 2,
            Errors::Translation => 3,
        }
    }
}

/// A member of the family: a name (letters, digits, `_`), what it is and
/// why it is hard, and its parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Member {
    /// File and log name.
    pub name: String,
    /// What it is and why it is hard.
    pub what: String,
    /// The pair.
    pub params: Params,
    /// The processor's error model.
    #[serde(default)]
    pub errors: Errors,
}

/// Vertex 1 and vertex N − 2 of both boundaries moved to the left image
/// edge (column 0; of the four choices of edge the costliest for today's
/// index on the host), in `frames` (1, 2 or 3 for both).
pub fn end_spurs(frames: u8) -> Vec<Spur> {
    let mut v = Vec::new();
    for boundary in 0..2 {
        let u = 0.0;
        for from_end in [false, true] {
            v.push(Spur {
                frames,
                boundary,
                from_end,
                k: 1,
                u,
            });
        }
    }
    v
}

/// The hand-made members, in the order the bench reports them.
pub fn hand_members() -> Vec<Member> {
    let m = |name: &str, what: &str, params: Params| Member {
        name: name.into(),
        what: what.into(),
        params,
        errors: Errors::Default,
    };
    let with = |errors: Errors, member: Member| Member { errors, ..member };
    let fig6 = Params::fig6();
    let straight = Params {
        scene: Scene::Straight,
        rows: Rows::Integer,
        ..Params::fig6()
    };
    let mut v = vec![
        m(
            "spur_f2",
            "the representative pair, vertex 1 and N-2 of each frame-2 boundary moved to the left image edge (column 0): one early and one late outlying key in the frame-2 index",
            Params {
                spurious: end_spurs(2),
                ..fig6.clone()
            },
        ),
        m(
            "spur_f1",
            "the same spurious points in frame 1 only: the fold test's keys jump at both ends",
            Params {
                spurious: end_spurs(1),
                ..fig6.clone()
            },
        ),
        m(
            "spur_both",
            "the same spurious points in both frames",
            Params {
                spurious: end_spurs(3),
                ..fig6.clone()
            },
        ),
        m(
            "straight_round",
            "a straight road driven straight, integer rows, columns rounded: both boundaries lie along epipolar lines (radial from the FOE), the keys a staircase about one value",
            Params {
                quantise: true,
                ..straight.clone()
            },
        ),
        m(
            "straight_exact",
            "the same with exact sub-pixel columns: every key nearly the same",
            Params {
                quantise: false,
                ..straight.clone()
            },
        ),
        m(
            "radial_stair",
            "a quantised edge 3 degrees from the FOE direction all along it (log spiral about the FOE), integer rows: near-constant keys with rounding jitter",
            Params {
                scene: Scene::Spiral { deg: 3.0 },
                rows: Rows::Integer,
                ..fig6.clone()
            },
        ),
        m(
            "radial_stair_flat",
            "the same staircase 0.5 degrees from the FOE direction: the rounding jitter of the keys outweighs their trend over tens of segments",
            Params {
                scene: Scene::Spiral { deg: 0.5 },
                rows: Rows::Integer,
                ..fig6.clone()
            },
        ),
        m(
            "zigzag_small",
            "the representative pair with every column alternating by +-2 px in both frames (v-monotone): the key order jitters at every vertex",
            Params {
                zigzag: [2.0, 2.0],
                ..fig6.clone()
            },
        ),
        m(
            "zigzag_large",
            "the same alternating by +-60 px: every segment nearly horizontal, long runs of overlapping key ranges",
            Params {
                zigzag: [60.0, 60.0],
                ..fig6.clone()
            },
        ),
        m(
            "foe_row",
            "the Fig. 6 road with the translation pointing 12 degrees below level (FOE at row 139, inside the image): both frame-1 boundaries cross the FOE's row",
            Params {
                foe: Foe::At { u: 185.0, v: 139.0 },
                ..fig6.clone()
            },
        ),
        m(
            "near_foe",
            "the Fig. 6 road with the FOE on the right boundary (frame 2, at row 300): the points next to it see epipolar lines in every direction",
            Params {
                foe: Foe::At { u: 355.0, v: 300.0 },
                ..fig6.clone()
            },
        ),
        m(
            "worst_found",
            "the issue's worst case: spurious points in both frames, the detector's rows from 40 down, the FOE at row 16 (every frame-2 point more than 16 px below it: half-plane keys) and the top frame-1 point of the left boundary 10 px above the FOE's row (a point without a half-plane key)",
            Params {
                spurious: end_spurs(3),
                foe: Foe::At { u: 185.0, v: 16.0 },
                lift: Some(Lift {
                    boundary: 0,
                    above: 10.0,
                }),
                top: 40.0,
                ..fig6.clone()
            },
        ),
    ];
    // Found by an adversarial review (issue 11): backward motion (every
    // point on the band path), forward log spirals about an FOE inside the
    // image, and configured motion errors; the formula of README's "Worst
    // case" (`docs/VEHICLE.md`) did not hold on them until they joined the family.
    let get = |name: &str| {
        v.iter()
            .find(|x| x.name == name)
            .map(|x| x.params.clone())
            .unwrap_or_else(Params::fig6)
    };
    let spur = |frames: u8, boundary: usize, from_end: bool, k: usize, u: f64| Spur {
        frames,
        boundary,
        from_end,
        k,
        u,
    };
    let (foe_row, near_foe, radial_stair) = (get("foe_row"), get("near_foe"), get("radial_stair"));
    let extra = vec![
        m(
            "back_spiral",
            "moving backwards past log spirals 1.9 degrees off the radial direction, exact columns, the FOE just above the image (row -22), the camera turned 1.5 degrees, spurious points in both frames: every point takes the band path, whose runs reach to the FOE",
            Params {
                scene: Scene::Spiral { deg: 1.9 },
                quantise: false,
                foe: Foe::At {
                    u: 243.064,
                    v: -22.152,
                },
                turn: [0.0, 1.475, 0.0],
                spurious: vec![
                    spur(3, 1, true, 4, 0.864),
                    spur(1, 0, true, 7, 0.0),
                    spur(3, 0, false, 4, 0.264),
                    spur(3, 1, true, 1, 1.0),
                ],
                reverse: true,
                ..fig6.clone()
            },
        ),
        m(
            "back_radial_stair",
            "radial_stair driven backwards: the band path along a near-radial staircase",
            Params {
                reverse: true,
                ..radial_stair
            },
        ),
        m(
            "back_foe_row",
            "foe_row driven backwards: pseudo-angle keys on the band path",
            Params {
                reverse: true,
                ..foe_row.clone()
            },
        ),
        m(
            "fwd_spiral",
            "log spirals 10.7 degrees off radial about an FOE inside the image (row 170), exact columns, a 2 px zig-zag in frame 2, the camera turned 1 degree, spurious points: pseudo-angle keys, the fold test's queries and long angular walks",
            Params {
                scene: Scene::Spiral { deg: 10.69 },
                quantise: false,
                foe: Foe::At {
                    u: 207.844,
                    v: 169.838,
                },
                turn: [0.558, 0.0, -0.929],
                zigzag: [0.0, 2.0],
                spurious: vec![
                    spur(3, 0, true, 8, 0.0),
                    spur(2, 0, true, 0, 0.0),
                    spur(1, 0, true, 2, 1.0),
                ],
                ..fig6.clone()
            },
        ),
        m(
            "fwd_spiral_zz",
            "log spirals 1.9 degrees off radial about an FOE at row 143, columns rounded, a 10 px zig-zag in frame 2, spurious points in both frames",
            Params {
                scene: Scene::Spiral { deg: 1.87 },
                foe: Foe::At {
                    u: 197.826,
                    v: 142.712,
                },
                turn: [1.054, -0.026, 0.0],
                zigzag: [0.0, 10.0],
                spurious: vec![
                    spur(2, 1, true, 4, 0.0),
                    spur(2, 0, true, 10, 1.0),
                    spur(2, 0, false, 0, 0.0),
                    spur(1, 1, false, 5, 0.551),
                    spur(3, 1, false, 9, 0.0),
                    spur(3, 1, true, 5, 1.0),
                ],
                ..fig6.clone()
            },
        ),
        with(
            Errors::Rotation,
            m(
                "foe_row_rot_err",
                "foe_row with a rotation error of 0.01 rad about each axis configured: no certified image, the band widened by the rotation's uncertainty",
                foe_row.clone(),
            ),
        ),
        with(
            Errors::RotationZ,
            m(
                "foe_row_rot_z",
                "foe_row with a rotation error of 0.001 rad about the optical axis",
                foe_row,
            ),
        ),
        with(
            Errors::Rotation,
            m(
                "near_foe_rot_err",
                "near_foe with a rotation error of 0.01 rad about each axis",
                near_foe.clone(),
            ),
        ),
        with(
            Errors::Translation,
            m(
                "near_foe_trans_err",
                "near_foe with a translation error of 0.02: every point on the band path",
                near_foe,
            ),
        ),
    ];
    v.extend(extra);
    v
}

/// The members the seeded search kept (`adversarial_found.json`).
pub fn found_members() -> Vec<Member> {
    serde_json::from_str(FOUND_JSON).expect("adversarial_found.json parses")
}

/// The whole family: the hand-made members, then the searched ones.
pub fn family() -> Vec<Member> {
    let mut v = hand_members();
    v.extend(found_members());
    v
}

// ---- small f64 geometry (row-major 3 × 3) ----

type M3 = [[f64; 3]; 3];

fn mv(a: &M3, v: V3) -> V3 {
    [0, 1, 2].map(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}
fn mm(a: &M3, b: &M3) -> M3 {
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}
fn tr(a: &M3) -> M3 {
    [0, 1, 2].map(|i| [a[0][i], a[1][i], a[2][i]])
}
fn norm(v: V3) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// The two poses of a pair and what follows from them: the rotation of
/// camera 2 in camera-1 coordinates and the FOE in frame 2's image.
struct Motion2 {
    p1: Pose,
    p2: Pose,
    rel: M3,
    foe: [f64; 2],
}

impl Motion2 {
    fn new(p1: Pose, p2: Pose, k: &Intrinsics) -> Self {
        let rel = mm(&tr(&p1.rot), &p2.rot);
        let t1 = mv(&tr(&p1.rot), sub(p2.centre, p1.centre));
        let d2 = mv(&tr(&rel), t1);
        let foe = [k.cx + k.fx * d2[0] / d2[2], k.cy + k.fy * d2[1] / d2[2]];
        Motion2 { p1, p2, rel, foe }
    }
    /// Frame-1 pixel → rotation-compensated pixel (`K Rᵀ K⁻¹`).
    fn compensate(&self, k: &Intrinsics, p: [f64; 2]) -> [f64; 2] {
        let q = mv(
            &tr(&self.rel),
            [(p[0] - k.cx) / k.fx, (p[1] - k.cy) / k.fy, 1.0],
        );
        [k.cx + k.fx * q[0] / q[2], k.cy + k.fy * q[1] / q[2]]
    }
    /// The inverse of [`Motion2::compensate`].
    fn uncompensate(&self, k: &Intrinsics, p: [f64; 2]) -> [f64; 2] {
        let q = mv(&self.rel, [(p[0] - k.cx) / k.fx, (p[1] - k.cy) / k.fy, 1.0]);
        [k.cx + k.fx * q[0] / q[2], k.cy + k.fy * q[1] / q[2]]
    }
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn deg(x: f64) -> f64 {
    x.to_radians()
}

/// The poses of `p` in camera `k`.
fn motion(p: &Params, k: &Intrinsics) -> Motion2 {
    let tilt = deg(23.0);
    let p1 = Pose::vehicle_camera([0.0; 3], 0.0, 1.0, tilt);
    let mut p2 = match p.scene {
        Scene::Fig6 | Scene::Spiral { .. } => {
            Pose::vehicle_camera([0.0, 0.0, 0.4], deg(5.0), 1.0, tilt)
        }
        Scene::Straight => Pose::vehicle_camera([0.0, 0.0, 0.4], 0.0, 1.0, tilt),
    };
    if p.turn != [0.0; 3] {
        p2 = p2.moved([0.0; 3], p.turn.map(deg));
    }
    let m = Motion2::new(p1, p2, k);
    match p.foe {
        Foe::Natural => m,
        Foe::At { u, v } => {
            // Keep the rotation and |T|; point T (frame-2 coordinates) at
            // the pixel.
            let s = f64::from(k.width) / f64::from(Intrinsics::default().width);
            let len = norm(mv(&tr(&p1.rot), sub(p2.centre, p1.centre)));
            let d2 = [
                (scaled(u, s) - k.cx) / k.fx,
                (scaled(v, s) - k.cy) / k.fy,
                1.0,
            ];
            let n2 = norm(d2);
            let t1 = mv(&m.rel, d2.map(|x| x * len / n2));
            let c = mv(&p1.rot, t1);
            let p2 = Pose {
                centre: [
                    p1.centre[0] + c[0],
                    p1.centre[1] + c[1],
                    p1.centre[2] + c[2],
                ],
                rot: p2.rot,
            };
            Motion2::new(p1, p2, k)
        }
    }
}

/// `n` rows over `[lo, hi]` (hi first, decreasing), evenly spread, as the
/// bench; rounded for [`Rows::Integer`].
fn rows_over(lo: f64, hi: f64, n: usize, rows: Rows) -> Vec<f64> {
    (0..n)
        .map(|j| {
            let r = hi - (hi - lo) * j as f64 / (n as f64 - 1.0);
            match rows {
                Rows::Even => r,
                Rows::Integer => r.round(),
            }
        })
        .collect()
}

/// A road scene's boundaries in one frame: exact `(u, v)`, bottom first.
fn road_boundaries(
    world: &[Vec<V3>],
    pose: &Pose,
    k: &Intrinsics,
    n: usize,
    rows: Rows,
    top: f64,
) -> Result<Vec<Vec<[f64; 2]>>, String> {
    let mut out = Vec::new();
    for curve in world {
        let all = synth::detect(curve, pose, k, 60.0);
        let (lo, hi) = (
            all.last().map_or(0.0, |p| p.v).max(top),
            all.first().map_or(0.0, |p| p.v),
        );
        if hi <= lo {
            return Err("a boundary lies above the detector's top row".into());
        }
        let pts = synth::detect_rows(curve, pose, k, 60.0, &rows_over(lo, hi, n, rows));
        if pts.len() != n {
            return Err(format!("a boundary gives {} of {n} points", pts.len()));
        }
        out.push(pts.iter().map(|p| [p.u, p.v]).collect());
    }
    Ok(out)
}

/// Resample a dense curve (v decreasing along it) at `n` rows spread over
/// its extent inside the image (u interpolated linearly).
fn resample(
    curve: &[[f64; 2]],
    k: &Intrinsics,
    n: usize,
    rows: Rows,
    top: f64,
) -> Result<Vec<[f64; 2]>, String> {
    let bottom = f64::from(k.height) - 1.0;
    let seen = |p: &[f64; 2]| {
        (top..=bottom).contains(&p[1]) && (0.0..=f64::from(k.width) - 1.0).contains(&p[0])
    };
    // One stretch of the curve inside the image: a curve that leaves it and
    // comes back would be bridged by a chord far from the true curve (a
    // pair outside the error model).
    let first = curve.iter().position(seen).unwrap_or(curve.len());
    let last = curve.iter().rposition(seen).unwrap_or(0);
    if first <= last && !curve[first..=last].iter().all(seen) {
        return Err("curve leaves the image and comes back".into());
    }
    let inside: Vec<[f64; 2]> = curve.iter().copied().filter(seen).collect();
    if inside.len() < 2 || inside.windows(2).any(|w| w[1][1] >= w[0][1]) {
        return Err("curve not v-monotone inside the image".into());
    }
    let (hi, lo) = (inside[0][1], inside[inside.len() - 1][1]);
    let mut out = Vec::new();
    let mut j = 0;
    for r in rows_over(lo, hi, n, rows) {
        while j + 2 < inside.len() && inside[j + 1][1] > r {
            j += 1;
        }
        let (a, b) = (inside[j], inside[j + 1]);
        let t = ((a[1] - r) / (a[1] - b[1])).clamp(0.0, 1.0);
        out.push([a[0] + t * (b[0] - a[0]), r]);
    }
    Ok(out)
}

/// The spiral scene's boundaries (frame 1 raw pixels, frame 2), exact.
fn spiral_boundaries(
    deg_off: f64,
    m: &Motion2,
    k: &Intrinsics,
    n: usize,
    rows: Rows,
    top: f64,
) -> Result<[Vec<Vec<[f64; 2]>>; 2], String> {
    let road = Road {
        curvature_a: 1.0 / 15.0,
        curvature_b: 1.0 / 15.0,
        ..Road::straight(1.3)
    };
    let world = road.boundaries(2.0, 60.0, 0.01);
    let f = m.foe;
    let mut f1 = Vec::new();
    let mut f2 = Vec::new();
    for (bi, curve) in world.iter().enumerate() {
        let a = synth::detect(curve, &m.p2, k, 60.0)
            .first()
            .map(|p| [p.u, p.v])
            .ok_or("no Fig. 6 anchor")?;
        let r0 = (a[0] - f[0]).hypot(a[1] - f[1]);
        let th0 = (a[1] - f[1]).atan2(a[0] - f[0]);
        let sign = if bi == 0 { 1.0 } else { -1.0 };
        let tan = deg(deg_off).tan() * sign;
        // t = ln(r0 / r): from 0.3 below the anchor (outside the image) in.
        let dense: Vec<[f64; 2]> = (0..6000)
            .map(|i| -0.3 + i as f64 * 0.0005)
            .map(|t| {
                let r = r0 * (-t).exp();
                let th = th0 + tan * t;
                [f[0] + r * th.cos(), f[1] + r * th.sin()]
            })
            .take_while(|p| p[1] > -2.0)
            .collect();
        let frame1: Vec<[f64; 2]> = dense
            .iter()
            .map(|p| m.uncompensate(k, [f[0] + 0.9 * (p[0] - f[0]), f[1] + 0.9 * (p[1] - f[1])]))
            .collect();
        f2.push(resample(&dense, k, n, rows, top)?);
        f1.push(resample(&frame1, k, n, rows, top)?);
    }
    Ok([f1, f2])
}

/// Render member parameters at `n` points per boundary: the camera and the
/// two frames (the second with its motion), or why they are invalid.
pub fn render(p: &Params, n: usize) -> Result<(Intrinsics, Vec<DriveFrame>), String> {
    let k = camera_for(n);
    let s = f64::from(scale_for(n));
    let m = motion(p, &k);
    let top = if p.top > 0.0 { scaled(p.top, s) } else { 0.0 };
    let mut frames: [Vec<Vec<[f64; 2]>>; 2] = match p.scene {
        Scene::Fig6 | Scene::Straight => {
            let road = match p.scene {
                Scene::Straight => Road::straight(1.3),
                _ => Road {
                    curvature_a: 1.0 / 15.0,
                    curvature_b: 1.0 / 15.0,
                    ..Road::straight(1.3)
                },
            };
            let world = road.boundaries(2.0, 60.0, 0.01);
            [
                road_boundaries(&world, &m.p1, &k, n, p.rows, top)?,
                road_boundaries(&world, &m.p2, &k, n, p.rows, top)?,
            ]
        }
        Scene::Spiral { deg } => spiral_boundaries(deg, &m, &k, n, p.rows, top)?,
    };
    let wmax = f64::from(k.width) - 1.0;
    let round = |x: f64| if p.quantise { x.round() } else { x };
    for (fi, frame) in frames.iter_mut().enumerate() {
        for b in frame.iter_mut() {
            for (i, q) in b.iter_mut().enumerate() {
                q[0] = round(q[0]);
                let a = p.zigzag[fi] * s;
                if a != 0.0 {
                    let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
                    q[0] = round((q[0] + sign * a).clamp(0.0, wmax));
                }
            }
        }
        for sp in &p.spurious {
            if sp.frames & (1 << fi) == 0 {
                continue;
            }
            let b = frame.get_mut(sp.boundary).ok_or("no such boundary")?;
            let len = b.len();
            let i = if sp.from_end {
                len.checked_sub(1 + sp.k)
            } else {
                Some(sp.k)
            }
            .filter(|&i| i < len)
            .ok_or("spurious vertex out of range")?;
            b[i][0] = round(sp.u.clamp(0.0, 1.0) * wmax);
        }
    }
    if let Some(l) = p.lift {
        let b = frames[0].get_mut(l.boundary).ok_or("no such boundary")?;
        let len = b.len();
        let c = m.compensate(&k, b[len - 1]);
        let mut q = m.uncompensate(&k, [c[0], m.foe[1] - l.above * s]);
        q[0] = round(q[0]);
        let hmax = f64::from(k.height);
        if !(q[1] < b[len - 2][1]
            && q[1] >= -1.0
            && q[1] <= hmax
            && (-1.0..=wmax + 1.0).contains(&q[0]))
        {
            return Err(format!(
                "lifted vertex {q:?} leaves the image or the row order"
            ));
        }
        b[len - 1] = q;
    }
    let (t, a) = if p.reverse {
        frames.swap(0, 1);
        m.p2.motion_to(&m.p1)
    } else {
        m.p1.motion_to(&m.p2)
    };
    let out = frames
        .iter()
        .enumerate()
        .map(|(i, bs)| DriveFrame {
            translation: if i == 0 {
                [0.0; 3]
            } else {
                t.map(|x| x as f32)
            },
            rotation: if i == 0 {
                [0.0; 3]
            } else {
                a.map(|x| x as f32)
            },
            boundaries: bs
                .iter()
                .map(|b| b.iter().map(|q| [q[0] as f32, q[1] as f32]).collect())
                .collect(),
            depths: Vec::new(),
        })
        .collect::<Vec<_>>();
    validate(&k, &out)?;
    Ok((k, out))
}

/// Whether a rendered pair passes the library's validation: every boundary
/// through `Frame::push_boundary`, exactly two of the same length per
/// frame, the motion through `Motion::new`.
pub fn validate(k: &Intrinsics, frames: &[DriveFrame]) -> Result<(), String> {
    let cam = k.camera();
    if frames.len() != 2 {
        return Err("not a pair".into());
    }
    for (i, f) in frames.iter().enumerate() {
        let mut fr = roadstereo::Frame::<512, 2>::new(cam);
        if f.boundaries.len() != 2 {
            return Err(format!("frame {i}: {} boundaries", f.boundaries.len()));
        }
        for b in &f.boundaries {
            let pts: Vec<roadstereo::Pixel> = b
                .iter()
                .map(|q| roadstereo::Pixel::new(q[0], q[1]))
                .collect();
            fr.push_boundary(&pts)
                .map_err(|e| format!("frame {i}: {e}"))?;
        }
    }
    roadstereo::Motion::new(frames[1].translation, frames[1].rotation)
        .map_err(|e| format!("motion: {e:?}"))?;
    Ok(())
}

/// The frames of a rendered pair as the library's types, and its motion.
pub fn library_pair(
    k: &Intrinsics,
    frames: &[DriveFrame],
) -> (
    roadstereo::Frame<512, 2>,
    roadstereo::Frame<512, 2>,
    roadstereo::Motion,
) {
    let cam = k.camera();
    let make = |f: &DriveFrame| {
        let mut fr = roadstereo::Frame::<512, 2>::new(cam);
        for b in &f.boundaries {
            let pts: Vec<roadstereo::Pixel> = b
                .iter()
                .map(|q| roadstereo::Pixel::new(q[0], q[1]))
                .collect();
            fr.push_boundary(&pts).expect("validated");
        }
        fr
    };
    let m = roadstereo::Motion::new(frames[1].translation, frames[1].rotation).expect("validated");
    (make(&frames[0]), make(&frames[1]), m)
}

/// Host cost of a pair: the best of `reps` timings of the release build's
/// `Processor::process` for frame 2 (the processor reset and given frame 1
/// before each), in nanoseconds, with the status counts.
pub fn host_cost(
    k: &Intrinsics,
    frames: &[DriveFrame],
    reps: usize,
    errors: Errors,
) -> (f64, Vec<(String, usize)>) {
    use roadstereo::{Processor, Status};
    let (f1, f2, m) = library_pair(k, frames);
    let mut p = Box::new(Processor::<512, 2>::new(errors.config()));
    let mut best = f64::INFINITY;
    for _ in 0..reps.max(1) {
        p.reset();
        let _ = p.process(&f1, None);
        let t0 = std::time::Instant::now();
        let r = p.process(std::hint::black_box(&f2), Some(&m)).is_ok();
        let dt = t0.elapsed().as_secs_f64() * 1e9;
        std::hint::black_box(r);
        best = best.min(dt);
    }
    let counts = p.structure().status_counts();
    let named = counts
        .iter()
        .filter(|&(s, c)| c > 0 || s == Status::Ok)
        .map(|(s, c)| (s.name().to_string(), c))
        .collect();
    (best, named)
}

/// The bench firmware's table of the family: one `include_bytes!` line per
/// member and N (the file `src/bin/data/adversarial.rs`).
pub fn firmware_table(members: &[Member]) -> String {
    let mut s = String::from(
        "// Generated by `cd host_tests && cargo run --release --bin adversarial` (see\n\
         // host_tests/src/drive/adversarial.rs): the adversarial family, one RSD1 frame\n\
         // pair per member and N. Do not edit.\n\
         // The third field is the member's error model (`Errors::id`).\n\
         static ADVERSARIAL: &[(&str, u32, u8, &[u8])] = &[\n",
    );
    for m in members {
        for n in SIZES {
            s.push_str(&format!(
                "    (\"{}\", {n}, {}, include_bytes!(\"{}\")),\n",
                m.name,
                m.errors.id(),
                file_name(&m.name, n)
            ));
        }
    }
    s.push_str("];\n");
    s
}

/// Write every member at every N and the firmware's table into `dir`;
/// returns the bytes written (data files only).
pub fn write_all(dir: &std::path::Path, members: &[Member]) -> Result<usize, String> {
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    let mut total = 0;
    for m in members {
        for n in SIZES {
            let (k, frames) =
                render(&m.params, n).map_err(|e| format!("{} at {n}: {e}", m.name))?;
            let bytes = super::encode(&k, &frames);
            total += bytes.len();
            std::fs::write(dir.join(file_name(&m.name, n)), bytes).map_err(|e| e.to_string())?;
        }
    }
    std::fs::write(dir.join("adversarial.rs"), firmware_table(members))
        .map_err(|e| e.to_string())?;
    Ok(total)
}

// ---- the seeded search ----

/// A random change to a pair (one of: rounding or the direction of
/// travel, rows, scene, FOE, camera turn, zig-zag, a spurious point added,
/// moved or removed, the lift).
/// Every change is in paper pixels or counted from a boundary's end, so a
/// mutant is the same scene at every N.
pub fn mutate(p: &Params, g: &mut synth::Rng) -> Params {
    let mut q = mutate_raw(p, g);
    // Short decimals in the stored parameters.
    let r = |x: &mut f64| *x = (*x * 1000.0).round() / 1000.0;
    if let Scene::Spiral { deg } = &mut q.scene {
        r(deg);
    }
    if let Foe::At { u, v } = &mut q.foe {
        r(u);
        r(v);
    }
    q.turn.iter_mut().for_each(r);
    q.spurious.iter_mut().for_each(|s| r(&mut s.u));
    if let Some(l) = &mut q.lift {
        r(&mut l.above);
    }
    r(&mut q.top);
    q
}

fn mutate_raw(p: &Params, g: &mut synth::Rng) -> Params {
    let mut q = p.clone();
    let pick = |g: &mut synth::Rng, n: usize| (g.next_u64() % n as u64) as usize;
    match pick(g, 10) {
        0 if g.chance(0.25) => q.reverse = !q.reverse,
        0 => q.quantise = !q.quantise,
        1 => {
            q.rows = match q.rows {
                Rows::Even => Rows::Integer,
                Rows::Integer => Rows::Even,
            }
        }
        2 => {
            q.scene = match pick(g, 3) {
                0 => Scene::Fig6,
                1 => Scene::Straight,
                _ => Scene::Spiral {
                    deg: g.uniform(0.2, 12.0),
                },
            }
        }
        3 => {
            q.foe = match (q.foe, g.chance(0.2)) {
                (_, true) => Foe::Natural,
                (Foe::At { u, v }, false) if g.chance(0.6) => Foe::At {
                    u: u + g.uniform(-30.0, 30.0),
                    v: v + g.uniform(-30.0, 30.0),
                },
                _ => Foe::At {
                    u: g.uniform(-50.0, 560.0),
                    v: g.uniform(-120.0, 480.0),
                },
            }
        }
        4 => {
            let a = pick(g, 3);
            q.turn[a] = (q.turn[a] + g.uniform(-1.5, 1.5)).clamp(-5.0, 5.0);
        }
        5 => {
            let f = pick(g, 2);
            q.zigzag[f] = if g.chance(0.3) {
                0.0
            } else {
                *[0.5, 1.0, 2.0, 3.0, 5.0, 10.0, 30.0, 60.0, 120.0]
                    .get(pick(g, 9))
                    .unwrap_or(&2.0)
            };
        }
        6 | 7 => {
            if !q.spurious.is_empty() && g.chance(0.3) {
                let i = pick(g, q.spurious.len());
                q.spurious.remove(i);
            } else if !q.spurious.is_empty() && g.chance(0.5) {
                let i = pick(g, q.spurious.len());
                let s = &mut q.spurious[i];
                match pick(g, 4) {
                    0 => s.k = pick(g, 12),
                    1 => s.u = g.uniform(0.0, 1.0),
                    2 => s.frames = 1 + pick(g, 3) as u8,
                    _ => s.from_end = !s.from_end,
                }
            } else if q.spurious.len() < 8 {
                q.spurious.push(Spur {
                    frames: 1 + pick(g, 3) as u8,
                    boundary: pick(g, 2),
                    from_end: g.chance(0.5),
                    k: pick(g, 12),
                    u: if g.chance(0.6) {
                        (pick(g, 2)) as f64
                    } else {
                        g.uniform(0.0, 1.0)
                    },
                });
            }
        }
        8 if g.chance(0.3) => {
            q.top = if g.chance(0.3) {
                0.0
            } else {
                g.uniform(0.0, 200.0)
            };
        }
        8 => {
            q.lift = if q.lift.is_some() && g.chance(0.3) {
                None
            } else {
                Some(Lift {
                    boundary: pick(g, 2),
                    above: g.uniform(0.5, 40.0),
                })
            }
        }
        _ => {
            // A FOE just above the boundaries' top (the worst case).
            q.foe = Foe::At {
                u: g.uniform(100.0, 400.0),
                v: g.uniform(100.0, 160.0),
            };
        }
    }
    q
}

/// Whether `p` renders validly at every N.
pub fn valid_everywhere(p: &Params) -> bool {
    SIZES.iter().all(|&n| render(p, n).is_ok())
}
