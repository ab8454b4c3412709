//! The road map a vehicle controller consumes: fused boundary points with
//! their intervals, per boundary, in the **current vehicle frame**, with a
//! fixed capacity.
//!
//! # Representation
//! A retired key frame's fused points enter the map together, as a
//! **batch**: each point is stored as its key-frame ray and fused interval
//! (normalised `x`, `y` and the interval `[Z_near, Z_far]` in 16-bit
//! outward-rounded codes, 12 bytes), and the batch holds the key frame's
//! pose in the current camera frame, `P = A P_K + b`. Carrying the map
//! forward by a frame's motion (`P' = Rᵀ (P − T)`) updates each batch's
//! pose (`A ← Rᵀ A`, `b ← Rᵀ (b − T)`): `O(batches)` arithmetic, exact up to
//! the `f32` rounding of one matrix product per frame, and no point is
//! re-rounded frame after frame. [`RoadMap::points`] gives each point's
//! stick in the current **vehicle frame** (the camera frame turned by the
//! mounting tilt, Appendix I, [`crate::analysis::camera_to_vehicle`]).
//!
//! # The radius: how far the true point may be from the stick
//! The fused interval bounds the true point's depth `Z`, but on the ray
//! of the **detected** key-frame pixel; the true point lies on the ray of
//! the true pixel, within `e₁` of it ([`crate::Config::e1`]), so in the
//! key frame it is within `Z |Δ(x, y)| ≤ Z_far λ` of the stick's point at
//! its own depth, `λ = e₁/min(f_x, f_y)` (a pixel step `(du, dv)` is
//! `(du/f_x, dv/f_y)` in normalised coordinates). Its distance from the
//! key-frame camera is `|P_K| = Z √(1 + x² + y²)` on the true ray, at most
//! `Z_far (1 + ½((|x| + λ)² + (|y| + λ)²))` with the detected `(x, y)`.
//!
//! When the configuration bounds the per-frame motion errors, a carried
//! point may be off its computed position by at most `ρ + φ |P_K|` more:
//! the batch starts with the bound of its key frame's composed motion
//! ([`crate::fusion`]) and each frame adds `√3 δ + ω |b'|` to `ρ` and `ω`
//! to `φ` (`δ` the translation error per component, `ω` the rotation error
//! angle, `b'` the key-frame camera's new position): the true point `Ωᵀ Rᵀ
//! (P_t − T − d)` is off by at most the old error plus `|d| + ω |P'|`, and
//! `|P'| ≤ |P_K| + |b'|`. The carrying is a rotation and a translation, so
//! it keeps the key frame's lateral distance. A [`MapPoint`] carries the
//! sum, `Z_far λ + ρ + φ |P_K|`, as its `radius`: the true point is within
//! `radius` of the stick. (The radius left out `Z_far λ` until an
//! adversarial review found it: about `0.49 Z/800` missing with the
//! key-frame pixels 0.49 px off, `host_tests/tests/fusion/`.)
//!
//! The `f32` arithmetic is bounded the same way, as a motion error that
//! is always there, configured bounds or not (a second review found map
//! points up to `1.8·10⁻⁶` outside a radius of 0 with `e₁ = 0` and exact
//! motions). With `u = 2⁻²⁴`: a frame's rotation matrix from its `f32`
//! angles is within about `18 u` of the rotation those angles name (as an
//! operator; a review measured at most `4.3 u` over 2 million angle
//! triples up to the 60° limit), and the product `Rᵀ A` adds at most `3 u`
//! per entry (rows and columns of unit length), `9 u` as an operator:
//! below `2⁻¹⁹ = 32 u` per carried frame, added to `φ` (the review: at most
//! `4.9 u` for the whole step). The position `Rᵀ (b − T)` is off by at
//! most `(1 + 3 + 18) u √3 |b − T| < 2⁻¹⁸ (|b|₁ + |T|₁)`, added to `ρ`.
//! Both sums are rounded up by `2⁻¹⁶` (in `f32` a sum of many small terms
//! would otherwise lose them). The step assumes each frame's motion as
//! [`Motion::new`] makes it; a caller that composes motions itself brings
//! their rounding, for the configured rotation error to cover. A retiring
//! key frame's pose comes from its composed motion, one such step per frame
//! since the key frame, whose rounding the composition keeps the same way
//! ([`crate::fusion`]'s chain, with the orientation's error turning each
//! step's translation): the batch starts with it. A point's own evaluation
//! (its ray times the decoded depth, the pose, then the tilt's `f32` sine
//! and cosine) is within about `11 u (|P_K| + |b|)`, covered by `2⁻²⁰ |P_K|
//! = 16 u |P_K|` in the radius (`EVAL_ROUNDING`) and by the `ρ` above (at
//! least `2⁻¹⁸ |b|₁ = 64 u |b|₁` from the first step on). (A review ran
//! 14.5 million map-point checks over drives of 20 000 frames with turns
//! up to 60° a frame and steps up to `10⁵`, `e₁ = 0`: the largest distance
//! from the stick was 0.015 of the radius.)

//! # What leaves the map, all counted ([`MapDrops`])
//! * **Behind**: a point whose whole stick, widened by its radius, is
//!   behind the camera (negative forward coordinate in the vehicle frame)
//!   is left out of every query ([`RoadMap::points`], [`RoadMap::samples`])
//!   from the frame it gets there. Its slot is reclaimed, and the drop
//!   counted, by a sweep: a batch wholly behind the camera goes at once (a
//!   bound on its points' forward coordinates), one wholly ahead is
//!   skipped, and of the batches the camera is passing at most
//!   [`SWEEP_PER_FRAME`] points per boundary are tested each frame, from
//!   the oldest on (`RoadMap::sweep`, after `RoadMap::carry`; the
//!   fusion sweeps after its pass, and not in a frame where a key frame
//!   retires or the next, which copy points instead, nor in one whose
//!   pass had more conflicts than agreeing intervals, [`crate::fusion`],
//!   "The sweep after the pass"): a bounded cost per frame whatever `M`
//!   is. A point behind the camera that no sweep has reached is still
//!   left out of every query, and goes for room when its batch is the
//!   oldest.
//! * **Capacity**: a boundary holds at most `M` points and the map at most
//!   [`MAP_BATCHES`] batches; a retiring key frame makes room by dropping
//!   the oldest points first (the oldest batch's, in the order they
//!   entered), and leaves out its own farthest points beyond `M`. Every
//!   live point it drops counts as dropped for room, one behind the
//!   camera that the sweep has not reached yet too: the drop is not
//!   tested. (A batch the whole-batch bound finds behind is gone before:
//!   the carry, which precedes a retirement in its step, drops it; one
//!   whose points are all behind but that the bound does not find so is
//!   taken like any other. Testing each point dropped from a batch the
//!   camera is passing, to count it behind when it was, cost about 38
//!   instructions a drop, 13 660 in a retirement of the bench's forward
//!   drive, for a count 30 of its 357 drops moved: `docs/PERFORMANCE.md`.)
//!
//! A retiring key frame may enter over two steps ([`Retired::pending`];
//! [`crate::fusion`], "The retirement over two steps"): its batch holds
//! the points entered so far, bounded over them, and is bounded again
//! over all of them when the rest enter.
//!
//! Size: `12·B·M` bytes of points, [`MAP_BATCHES`] batches of `88 + 4·B`
//! bytes, a retirement's rest and the batches the camera is passing
//! (13 144 bytes in all for `B = 2`, `M = 512`).

use crate::camera::Camera;
use crate::fusion::code::DepthScale;
use crate::fusion::{norm1, Cell, Chain, KeyFrame, StepBounds, STEP_ROUNDING};
use crate::geometry::Sample;
use crate::math::{fmax, fmin, mat3_mul, mat3_transpose, mat3_vec, sqrt, Mat3};
use crate::motion::Motion;
use crate::structure::{PointResult, Structure};

mod retire;
mod sweep;
#[cfg(test)]
mod tests;

use retire::Rest;
use sweep::{View, Whole};

/// The most batches (retired key frames) the map holds at once.
pub const MAP_BATCHES: usize = 8;

/// Points per boundary the sweep for points behind the camera tests each
/// frame (module docs).
pub const SWEEP_PER_FRAME: usize = 32;

/// Rounding allowance of a bound's arithmetic.
const ROUND_UP: f32 = 1.0 + 1.0 / 65_536.0;

/// The largest `|P_K|` bound a map point may have, its far end times its
/// camera's ray bound ([`ray_bound`](retire::ray_bound)): its coordinates, the radius and the
/// sweep's bounds then stay finite ([`Retired::unbounded`]).
const MAX_REACH: f32 = 1.0e30;

/// The `f32` rounding of a map point's evaluation, relative to `|P_K|`
/// (`2⁻²⁰`, module docs).
const EVAL_ROUNDING: f32 = 1.0 / 1_048_576.0;

/// `2⁻²⁰`, the whole-batch bound's rounding unit ([`View`]).
const ULP20: f32 = 1.0 / 1_048_576.0;

/// One stored point: its key-frame ray and coded interval (12 bytes).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Entry {
    x: f32,
    y: f32,
    near: u16,
    /// 0: dropped (a live far end is at least code 1).
    far: u16,
}

impl Entry {
    const DEAD: Entry = Entry {
        x: 0.0,
        y: 0.0,
        near: 0,
        far: 0,
    };
    fn live(&self) -> bool {
        self.far != 0
    }
}

/// A retired key frame in the map.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Batch<const B: usize> {
    /// Key-frame camera coordinates → current camera coordinates.
    a: Mat3,
    b: [f32; 3],
    /// The carried error bound `ρ + φ |P_K|`.
    rho: f32,
    phi: f32,
    /// `λ = e₁/min(f_x, f_y)`, rounded up: the key frame's localisation
    /// error across the ray, per unit of depth (module docs).
    lat: f32,
    /// The key frame's id.
    key: u32,
    /// Slots of each boundary's ring the batch occupies (live or not).
    len: [u16; B],
    /// Of those, the live ones (all 0: the whole batch is gone).
    live: [u16; B],
    /// Over the batch's stick ends `P = z (x, y, 1)` (key-frame camera,
    /// the ends as the map decodes them): the smallest and largest forward
    /// rate of a ray, `w · (x, y, 1)` with `w` the key frame's forward
    /// axis; an upper bound `c` of `|(x, y, 1)|`; the smallest and largest
    /// depth; an upper bound of `|P_K|` ([`Extent`](retire::Extent), [`View::whole`]).
    dir: (f32, f32),
    ray: f32,
    depth: (f32, f32),
    reach: f32,
}

impl<const B: usize> Batch<B> {
    const EMPTY: Self = Self {
        a: [[0.0; 3]; 3],
        b: [0.0; 3],
        rho: 0.0,
        phi: 0.0,
        lat: 0.0,
        key: 0,
        len: [0; B],
        live: [0; B],
        dir: (0.0, 0.0),
        ray: 0.0,
        depth: (0.0, 0.0),
        reach: 0.0,
    };

    fn live_total(&self) -> u32 {
        self.live.iter().map(|&l| u32::from(l)).sum()
    }

    fn live_on(&self, boundary: usize) -> bool {
        self.live.get(boundary).is_some_and(|&l| l > 0)
    }
}

/// One map point in the current vehicle frame.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MapPoint {
    /// The near end of the fused stick, vehicle frame (`x` right, `y` down
    /// perpendicular to the ground, `z` forward; origin at the camera).
    pub near: [f32; 3],
    /// The far end.
    pub far: [f32; 3],
    /// The true point is within this distance of the stick: the key
    /// frame's localisation error `e₁` across the ray (`Z_far e₁/min(f_x,
    /// f_y)`) and, with motion-error bounds, the carried motion's error
    /// (module docs).
    pub radius: f32,
    /// The id of the key frame the point was fused in.
    pub key: u32,
    /// The point's ray in that key frame: normalised `[x, y]` of its pixel
    /// ([`crate::Camera::normalise`]).
    pub ray: [f32; 2],
}

/// Points that left the map, by reason, since it was made or cleared.
///
/// Each count **wraps** at `2³²` (a statistics counter: take the points
/// dropped between two readings as `now.wrapping_sub(then)`). At the
/// bench's sideways drive, 504 points dropped for room every 8 frames,
/// and 30 frames a second, that is after about 26 days without a
/// [`crate::fusion::Fusion::reset`]; a saturating count would then stop,
/// and every difference with it, without a sign.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MapDrops {
    /// Behind the vehicle.
    pub behind: u32,
    /// Dropped for room (oldest first) when a key frame retired.
    pub capacity: u32,
}

/// What one retiring key frame brought to the map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Retired {
    /// The key frame's id.
    pub key: u32,
    /// Points that entered the map.
    pub entered: u32,
    /// Points left out: fewer agreeing pairs than the configured minimum
    /// (unmatched, single, consistent or widened with too few pairs), or
    /// flagged `PartlyUnseen` by the sight check
    /// ([`crate::fusion::FusionConfig::with_sight_check`]).
    pub unverified: u32,
    /// Points left out: inconsistent.
    pub inconsistent: u32,
    /// Points left out: admitted, but with a far end beyond what the map's
    /// depth codes hold (about twice `Config::max_depth`: a range
    /// constraint or a stick reaching that far), which would be an
    /// unbounded stick in the map, or so far (a distance bound past `10³⁰`
    /// along the camera's steepest ray, with a huge `max_depth`) that the
    /// map's `f32` arithmetic could overflow.
    pub unbounded: u32,
    /// Older points dropped to make room (also in [`MapDrops::capacity`]).
    pub dropped: u32,
    /// This key frame's own points beyond a boundary's capacity `M` (the
    /// farthest along the boundary), left out.
    pub unfit: u32,
    /// Admitted points not looked at yet: a retirement that enters more
    /// points than its step's share enters the rest at the start of the
    /// next step, which reports them as
    /// [`crate::fusion::FusionStep::finished`] (`entered + unbounded +
    /// unfit` there is this count; [`crate::fusion`], "The retirement over
    /// two steps"). 0 when the retirement is whole. A
    /// [`crate::fusion::Fusion::reset`] before the next step forgets them
    /// with the map: no step reports them then.
    pub pending: u32,
}

/// The forward axis of the vehicle frame in camera coordinates.
fn forward_axis(tilt: (f32, f32)) -> [f32; 3] {
    [0.0, -tilt.0, tilt.1]
}

fn dot3(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The radius of an entry `e` whose far end is `zf` in a batch with the
/// bounds `rho`, `phi`, `lat` (module docs): `zf λ + ρ + φ |P_K|` and the
/// evaluation's rounding, `|P_K|` bounded on the true ray.
#[inline]
fn radius(rho: f32, phi: f32, lat: f32, e: &Entry, zf: f32) -> f32 {
    let (x, y) = (e.x.abs() + lat, e.y.abs() + lat);
    let reach = zf * (1.0 + 0.5 * (x * x + y * y));
    (zf * lat + rho + (phi + EVAL_ROUNDING) * reach) * ROUND_UP
}

/// The fixed-capacity road map: up to `M` points on each of `B`
/// boundaries (module docs). `0 < M < 65535` (16-bit slots): another `M`
/// fails to compile (`evaluation panicked: 0 < M < 65535`).
#[derive(Debug, Clone)]
pub struct RoadMap<const B: usize, const M: usize> {
    entries: [[Entry; M]; B],
    /// Per boundary, the ring's oldest slot and the slots in use.
    tail: [u16; B],
    used: [u16; B],
    batches: [Batch<B>; MAP_BATCHES],
    first: u8,
    count: u8,
    /// Per boundary, the sweep's next slot (counted from the ring's tail).
    sweep: [u16; B],
    /// Sine and cosine of the mounting tilt.
    tilt: (f32, f32),
    scale: DepthScale,
    drops: MapDrops,
    /// A retirement cut at its share, to finish ([`RoadMap::finish`]).
    rest: Option<Rest<B>>,
    /// By batch slot, the batches the last [`RoadMap::carry`] found the
    /// camera passing, for the [`RoadMap::sweep`] after it (taken by it).
    passing: [bool; MAP_BATCHES],
}

impl<const B: usize, const M: usize> RoadMap<B, M> {
    const CHECK: () = assert!(M > 0 && M < u16::MAX as usize, "0 < M < 65535");

    /// An empty map for a camera tilted down by the angle whose sine and
    /// cosine are `tilt`; depths coded with `scale`.
    pub(crate) const fn new(tilt: (f32, f32), scale: DepthScale) -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::CHECK;
        Self {
            entries: [[Entry::DEAD; M]; B],
            tail: [0; B],
            used: [0; B],
            batches: [Batch::EMPTY; MAP_BATCHES],
            first: 0,
            count: 0,
            sweep: [0; B],
            tilt,
            scale,
            drops: MapDrops {
                behind: 0,
                capacity: 0,
            },
            rest: None,
            passing: [false; MAP_BATCHES],
        }
    }

    /// [`Self::clear`] for a camera tilted by the angle whose sine and
    /// cosine are `tilt`.
    pub(crate) fn clear_tilted(&mut self, tilt: (f32, f32)) {
        self.clear();
        self.tilt = tilt;
    }

    /// Forget every point (the counters too).
    pub(crate) fn clear(&mut self) {
        self.tail = [0; B];
        self.used = [0; B];
        self.first = 0;
        self.count = 0;
        self.sweep = [0; B];
        self.drops = MapDrops::default();
        self.rest = None;
        self.passing = [false; MAP_BATCHES];
    }

    /// Points stored on `boundary` now: those [`RoadMap::points`] gives and
    /// those behind the vehicle the sweep has not reclaimed yet.
    pub fn len(&self, boundary: usize) -> usize {
        self.batch_iter()
            .map(|b| b.live.get(boundary).map_or(0, |&l| usize::from(l)))
            .sum()
    }

    /// Whether the map holds no point.
    pub fn is_empty(&self) -> bool {
        self.batch_iter().all(|b| b.live_total() == 0)
    }

    /// Batches (retired key frames) in the map, oldest first.
    pub fn batches(&self) -> usize {
        usize::from(self.count)
    }

    /// The id of batch `batch`'s key frame (0 = oldest).
    pub fn batch_key(&self, batch: usize) -> Option<u32> {
        self.batch_iter().nth(batch).map(|b| b.key)
    }

    /// The points that left the map so far.
    pub fn drops(&self) -> MapDrops {
        self.drops
    }

    fn slot(&self, i: usize) -> usize {
        (usize::from(self.first) + i) % MAP_BATCHES
    }

    fn batch_iter(&self) -> impl Iterator<Item = &Batch<B>> {
        (0..usize::from(self.count)).filter_map(move |i| self.batches.get(self.slot(i)))
    }

    /// The ring slots of batch `i` (0 = oldest) on `boundary`: start and
    /// length.
    fn range(&self, i: usize, boundary: usize) -> (usize, usize) {
        let mut start = self.tail.get(boundary).map_or(0, |&t| usize::from(t));
        let mut len = 0;
        for (j, b) in self.batch_iter().enumerate() {
            let l = b.len.get(boundary).map_or(0, |&l| usize::from(l));
            if j == i {
                len = l;
                break;
            }
            start += l;
        }
        (start % M, len)
    }

    /// Each point of `boundary` not behind the vehicle, oldest first, in
    /// the current vehicle frame.
    ///
    /// Work: 2 matrix-vector products per stored point.
    pub fn points(&self, boundary: usize) -> impl Iterator<Item = MapPoint> + '_ {
        (0..usize::from(self.count)).flat_map(move |i| {
            let batch = self
                .batches
                .get(self.slot(i))
                .copied()
                .filter(|b| b.live_on(boundary))
                .unwrap_or(Batch::EMPTY);
            let (start, len) = self.range(i, boundary);
            let len = if batch.live_on(boundary) { len } else { 0 };
            let ring = self.entries.get(boundary).map_or(&[][..], |e| &e[..]);
            (0..len).filter_map(move |j| self.shown(&batch, ring.get((start + j) % M)?))
        })
    }

    /// Entry `e` of batch `b` as the queries show it: its map point, or
    /// `None` when it is dropped or its whole stick, widened by its own
    /// radius, is behind the vehicle. [`Self::points`] and
    /// [`Self::samples`] both ask this, so they show the same points.
    /// (Until the twenty-third session `samples` asked the sweep's
    /// [`View::behind`], whose radius is the batch's bound, at least each
    /// point's own: a review found it showing points `points` hid, 13 386
    /// times over its drives, with and without motion errors.)
    fn shown(&self, b: &Batch<B>, e: &Entry) -> Option<MapPoint> {
        if !e.live() {
            return None;
        }
        let p = self.map_point(b, e);
        (fmax(p.near[2], p.far[2]) + p.radius >= 0.0).then_some(p)
    }

    fn map_point(&self, b: &Batch<B>, e: &Entry) -> MapPoint {
        let (zn, zf) = (self.scale.depth(e.near), self.scale.depth(e.far));
        let (s, c) = self.tilt;
        let at = |z: f32| {
            let p = mat3_vec(&b.a, [e.x * z, e.y * z, z]);
            let p = [p[0] + b.b[0], p[1] + b.b[1], p[2] + b.b[2]];
            [p[0], c * p[1] + s * p[2], -s * p[1] + c * p[2]]
        };
        MapPoint {
            near: at(zn),
            far: at(zf),
            radius: radius(b.rho, b.phi, b.lat, e, zf),
            key: b.key,
            ray: [e.x, e.y],
        }
    }

    /// The points of `boundary` in batch `batch` (0 = oldest) not behind
    /// the vehicle (those [`Self::points`] shows), as samples of
    /// [`crate::geometry::road_geometry`]: each point's ray and fused
    /// interval in its key frame's camera coordinates (one view per key
    /// frame; the intervals are those of the key frame, not widened by the
    /// carrying). Fewer if `out` fills up.
    ///
    /// Work: 2 matrix-vector products per stored point of the batch.
    pub fn samples<const N: usize>(
        &self,
        batch: usize,
        boundary: usize,
        out: &mut heapless::Vec<Sample, N>,
    ) {
        out.clear();
        let Some(b) = self.batch_iter().nth(batch).copied() else {
            return;
        };
        if !b.live_on(boundary) {
            return;
        }
        let (start, len) = self.range(batch, boundary);
        let Some(ring) = self.entries.get(boundary) else {
            return;
        };
        for j in 0..len {
            let Some(e) = ring.get((start + j) % M) else {
                continue;
            };
            if self.shown(&b, e).is_some() {
                let _ = out.push(Sample {
                    x: e.x,
                    y: e.y,
                    z_near: self.scale.depth(e.near),
                    z_far: self.scale.depth(e.far),
                });
            }
        }
    }

    /// Carry every batch into the next frame by the motion `m` (from the
    /// current frame to the next) with per-frame error bounds `bounds`,
    /// and reclaim the batches wholly behind the vehicle (module docs);
    /// the batches the camera is passing are kept for a [`Self::sweep`]
    /// of this frame.
    ///
    /// Work: `O(MAP_BATCHES)`.
    pub(crate) fn carry(&mut self, m: &Motion, bounds: &StepBounds) {
        let rt = mat3_transpose(&m.rotation_matrix());
        let t = m.translation();
        let widen = bounds.any();
        // By batch slot: whether the camera is passing the batch.
        let mut passing = [false; MAP_BATCHES];
        for i in 0..usize::from(self.count) {
            let slot = self.slot(i);
            let (Some(b), Some(pass)) = (self.batches.get_mut(slot), passing.get_mut(slot)) else {
                continue;
            };
            // P' = Rᵀ (A P_K + b − T): A ← Rᵀ A, b ← Rᵀ (b − T).
            b.a = mat3_mul(&rt, &b.a);
            let d = [b.b[0] - t[0], b.b[1] - t[1], b.b[2] - t[2]];
            b.b = mat3_vec(&rt, d);
            // This frame's rounding (module docs), bounds or not.
            b.rho = (b.rho + 2.0 * STEP_ROUNDING * (norm1(b.b) + norm1(t))) * ROUND_UP;
            b.phi = (b.phi + STEP_ROUNDING) * ROUND_UP;
            if widen {
                let nb = sqrt(dot3(b.b, b.b));
                b.rho = (b.rho + 1.732_051 * bounds.delta + bounds.omega * nb) * ROUND_UP;
                b.phi = (b.phi + bounds.omega) * ROUND_UP;
            }
            if b.live_total() == 0 {
                continue;
            }
            match View::of(b, self.tilt).whole(b) {
                Whole::Ahead => {}
                Whole::Behind => {
                    self.drops.behind = self.drops.behind.wrapping_add(b.live_total());
                    b.live = [0; B];
                }
                Whole::Passing => *pass = true,
            }
        }
        self.pop_dead();
        self.passing = passing;
    }

    /// Remove the oldest batches that have no live point left.
    fn pop_dead(&mut self) {
        while self.count > 0 {
            let Some(b) = self.batches.get(usize::from(self.first)) else {
                return;
            };
            if b.live_total() > 0 {
                return;
            }
            let lens = b.len;
            self.pop_oldest(&lens);
        }
    }

    /// Remove the oldest batch whose ring lengths are `lens` (its live
    /// points are counted by the caller).
    fn pop_oldest(&mut self, lens: &[u16; B]) {
        for (((t, u), c), &l) in self
            .tail
            .iter_mut()
            .zip(self.used.iter_mut())
            .zip(self.sweep.iter_mut())
            .zip(lens)
        {
            *t = ((usize::from(*t) + usize::from(l)) % M) as u16;
            *u = u.saturating_sub(l);
            *c = c.saturating_sub(l);
        }
        self.first = ((usize::from(self.first) + 1) % MAP_BATCHES) as u8;
        self.count -= 1;
    }

    pub(crate) fn digest_into(&self, eat: &mut impl FnMut(u32)) {
        for (i, b) in self.batch_iter().enumerate() {
            eat(0xBA7C_0000 | i as u32);
            eat(b.key);
            for v in b.a.iter().flatten().chain(b.b.iter()) {
                eat(v.to_bits());
            }
            eat(b.rho.to_bits());
            eat(b.phi.to_bits());
            eat(b.lat.to_bits());
            for k in 0..B {
                let (start, len) = self.range(i, k);
                if let Some(ring) = self.entries.get(k) {
                    for j in 0..len {
                        if let Some(e) = ring.get((start + j) % M) {
                            eat(e.x.to_bits());
                            eat(e.y.to_bits());
                            eat(u32::from(e.near) | u32::from(e.far) << 16);
                        }
                    }
                }
            }
        }
        eat(self.drops.behind);
        eat(self.drops.capacity);
    }
}
