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
//! # Motion errors
//! When the configuration bounds the per-frame motion errors, a carried
//! point may be off its computed position by at most `ρ + φ |P_K|`, `|P_K|`
//! its distance from the key-frame camera: the batch starts with the bound
//! of its key frame's composed motion ([`crate::fusion`]) and each frame
//! adds `√3 δ + ω |b'|` to `ρ` and `ω` to `φ` (`δ` the translation error
//! per component, `ω` the rotation error angle, `b'` the key-frame camera's
//! new position): the true point `Ωᵀ Rᵀ (P_t − T − d)` is off by at most
//! the old error plus `|d| + ω |P'|`, and `|P'| ≤ |P_K| + |b'|`. A
//! [`MapPoint`] carries that bound as its `radius`: the true point is within
//! `radius` of the stick.
//!
//! # What leaves the map, all counted ([`MapDrops`])
//! * **Behind**: a point whose whole stick, widened by its radius, is
//!   behind the camera (negative forward coordinate in the vehicle frame)
//!   is dropped when the map is carried. A batch wholly ahead of or behind
//!   the camera (by a bounding sphere) is decided at once; only a batch
//!   straddling the camera is looked at point by point.
//! * **Capacity**: a boundary holds at most `M` points and the map at most
//!   [`MAP_BATCHES`] batches; a retiring key frame makes room by dropping
//!   the oldest points first (the oldest batch's, in the order they
//!   entered).
//!
//! Size: `12·B·M` bytes of points and [`MAP_BATCHES`] batches of
//! `96 + 8·B` bytes (`12 KiB + 0.9 KiB` for `B = 2`, `M = 512`).

use crate::depth::DepthInterval;
use crate::fusion::code::DepthScale;
use crate::fusion::Chain;
use crate::fusion::{FusedStatus, KeyFrame, StepBounds};
use crate::geometry::Sample;
use crate::math::{fmax, fmin, mat3_transpose, mat3_vec, sqrt, Mat3};
use crate::motion::Motion;
use crate::structure::Structure;

/// The most batches (retired key frames) the map holds at once.
pub const MAP_BATCHES: usize = 8;

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
    /// The key frame's id.
    key: u32,
    /// Slots of each boundary's ring the batch occupies (live or not).
    len: [u16; B],
    /// Of those, the live ones.
    live: [u16; B],
    /// A sphere (key-frame coordinates) holding every stick end, and the
    /// largest `|P_K|` of a stick end.
    centre: [f32; 3],
    spread: f32,
    reach: f32,
}

impl<const B: usize> Batch<B> {
    const EMPTY: Self = Self {
        a: [[0.0; 3]; 3],
        b: [0.0; 3],
        rho: 0.0,
        phi: 0.0,
        key: 0,
        len: [0; B],
        live: [0; B],
        centre: [0.0; 3],
        spread: 0.0,
        reach: 0.0,
    };

    fn live_total(&self) -> u32 {
        self.live.iter().map(|&l| u32::from(l)).sum()
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
    /// The true point is within this distance of the stick (0 without
    /// motion-error bounds).
    pub radius: f32,
    /// The id of the key frame the point was fused in.
    pub key: u32,
    /// The point's ray in that key frame: normalised `(x, y)` of its pixel
    /// ([`crate::Camera::normalise`]).
    pub ray: (f32, f32),
}

/// Points that left the map, by reason, since it was made or cleared.
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
    /// (unmatched or single).
    pub unverified: u32,
    /// Points left out: inconsistent.
    pub inconsistent: u32,
    /// Older points dropped to make room (also in [`MapDrops::capacity`]).
    pub dropped: u32,
    /// This key frame's own points beyond a boundary's capacity `M` (the
    /// farthest along the boundary), left out.
    pub unfit: u32,
}

/// The fixed-capacity road map: up to `M` points on each of `B`
/// boundaries (module docs).
#[derive(Debug, Clone)]
pub struct RoadMap<const B: usize, const M: usize> {
    entries: [[Entry; M]; B],
    /// Per boundary, the ring's oldest slot and the slots in use.
    tail: [u16; B],
    used: [u16; B],
    batches: [Batch<B>; MAP_BATCHES],
    first: u8,
    count: u8,
    /// Sine and cosine of the mounting tilt.
    tilt: (f32, f32),
    scale: DepthScale,
    drops: MapDrops,
}

/// The forward axis of the vehicle frame in camera coordinates.
fn forward_axis(tilt: (f32, f32)) -> [f32; 3] {
    [0.0, -tilt.0, tilt.1]
}

fn dot3(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
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
            tilt,
            scale,
            drops: MapDrops {
                behind: 0,
                capacity: 0,
            },
        }
    }

    /// Forget every point (the counters too).
    pub(crate) fn clear(&mut self) {
        self.tail = [0; B];
        self.used = [0; B];
        self.first = 0;
        self.count = 0;
        self.drops = MapDrops::default();
    }

    /// Points on `boundary` now.
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

    /// The points that left the map so far.
    pub fn drops(&self) -> MapDrops {
        self.drops
    }

    fn batch_iter(&self) -> impl Iterator<Item = &Batch<B>> {
        (0..usize::from(self.count)).filter_map(move |i| {
            self.batches
                .get((usize::from(self.first) + i) % MAP_BATCHES)
        })
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

    /// Each live point of `boundary`, oldest first, in the current vehicle
    /// frame.
    ///
    /// Work: 2 matrix-vector products per point.
    pub fn points(&self, boundary: usize) -> impl Iterator<Item = MapPoint> + '_ {
        (0..usize::from(self.count)).flat_map(move |i| {
            let batch = self
                .batches
                .get((usize::from(self.first) + i) % MAP_BATCHES)
                .copied()
                .unwrap_or(Batch::EMPTY);
            let (start, len) = self.range(i, boundary);
            let ring = self.entries.get(boundary).map_or(&[][..], |e| &e[..]);
            (0..len).filter_map(move |j| {
                let e = ring.get((start + j) % M)?;
                e.live().then(|| self.map_point(&batch, e))
            })
        })
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
            radius: b.rho + b.phi * zf * (1.0 + 0.5 * (e.x * e.x + e.y * e.y)),
            key: b.key,
            ray: (e.x, e.y),
        }
    }

    /// The points of `boundary` in batch `batch` (0 = oldest) as samples
    /// of [`crate::geometry::road_geometry`]: each point's ray and fused
    /// interval in its key frame's camera coordinates (one view per key
    /// frame; the intervals are those of the key frame, not widened by the
    /// carrying). Fewer if `out` fills up.
    pub fn samples<const N: usize>(
        &self,
        batch: usize,
        boundary: usize,
        out: &mut heapless::Vec<Sample, N>,
    ) {
        out.clear();
        if batch >= usize::from(self.count) {
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
            if e.live() {
                let _ = out.push(Sample {
                    x: e.x,
                    y: e.y,
                    z_near: self.scale.depth(e.near),
                    z_far: self.scale.depth(e.far),
                });
            }
        }
    }

    /// The id of batch `batch`'s key frame (0 = oldest).
    pub fn batch_key(&self, batch: usize) -> Option<u32> {
        self.batch_iter().nth(batch).map(|b| b.key)
    }

    /// Carry every batch into the next frame by the motion `m` (from the
    /// current frame to the next) with per-frame error bounds `bounds`, and
    /// drop the points now behind the vehicle.
    ///
    /// Work: `O(MAP_BATCHES)` plus one test per point of a batch that
    /// straddles the camera.
    pub(crate) fn carry(&mut self, m: &Motion, bounds: &StepBounds) {
        let rt = mat3_transpose(&m.rotation_matrix());
        let t = m.translation();
        let w = forward_axis(self.tilt);
        let widen = bounds.any();
        for i in 0..usize::from(self.count) {
            let slot = (usize::from(self.first) + i) % MAP_BATCHES;
            let Some(b) = self.batches.get_mut(slot) else {
                continue;
            };
            let a = b.a;
            // A ← Rᵀ A column by column is Rᵀ times each column: (Rᵀ A).
            b.a = crate::math::mat3_mul(&rt, &a);
            let d = [b.b[0] - t[0], b.b[1] - t[1], b.b[2] - t[2]];
            b.b = mat3_vec(&rt, d);
            if widen {
                let nb = sqrt(dot3(b.b, b.b));
                b.rho =
                    (b.rho + 1.732_051 * bounds.delta + bounds.omega * nb) * (1.0 + 1.0 / 65_536.0);
                b.phi = (b.phi + bounds.omega) * (1.0 + 1.0 / 65_536.0);
            }
            let b = *b;
            self.drop_behind(i, &b, w);
        }
        self.pop_dead();
    }

    /// Drop batch `i`'s points that are behind the camera.
    fn drop_behind(&mut self, i: usize, b: &Batch<B>, w: [f32; 3]) {
        // Forward coordinate of a key-frame point P: g·P + g0.
        let g = mat3_vec(&mat3_transpose(&b.a), w);
        let g0 = dot3(w, b.b);
        let margin = b.spread + b.rho + b.phi * b.reach;
        let fc = dot3(g, b.centre) + g0;
        if fc - margin >= 0.0 {
            return;
        }
        let all = fc + margin < 0.0;
        let scale = self.scale;
        let mut dropped = [0u16; B];
        for (k, dk) in dropped.iter_mut().enumerate() {
            let (start, len) = self.range(i, k);
            let Some(ring) = self.entries.get_mut(k) else {
                continue;
            };
            for j in 0..len {
                let Some(e) = ring.get_mut((start + j) % M) else {
                    continue;
                };
                if !e.live() {
                    continue;
                }
                let behind = all || {
                    let dir = g[0] * e.x + g[1] * e.y + g[2];
                    let (zn, zf) = (scale.depth(e.near), scale.depth(e.far));
                    let ahead = fmax(dir * zn, dir * zf) + g0;
                    let r = b.rho + b.phi * zf * (1.0 + 0.5 * (e.x * e.x + e.y * e.y));
                    ahead + r < 0.0
                };
                if behind {
                    *e = Entry::DEAD;
                    *dk += 1;
                }
            }
        }
        let slot = (usize::from(self.first) + i) % MAP_BATCHES;
        if let Some(bm) = self.batches.get_mut(slot) {
            for (l, d) in bm.live.iter_mut().zip(dropped) {
                *l = l.saturating_sub(d);
                self.drops.behind = self.drops.behind.saturating_add(u32::from(d));
            }
        }
    }

    /// Remove the oldest batches that have no live point left.
    fn pop_dead(&mut self) {
        while self.count > 0 {
            let slot = usize::from(self.first);
            let Some(b) = self.batches.get(slot) else {
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
        for ((t, u), &l) in self.tail.iter_mut().zip(self.used.iter_mut()).zip(lens) {
            *t = ((usize::from(*t) + usize::from(l)) % M) as u16;
            *u = u.saturating_sub(l);
        }
        self.first = ((usize::from(self.first) + 1) % MAP_BATCHES) as u8;
        self.count -= 1;
    }

    /// Free `need` slots on `boundary` by dropping its oldest points;
    /// returns the live points dropped.
    fn free_slots(&mut self, boundary: usize, need: usize) -> u32 {
        let mut dropped = 0u32;
        let mut need = need;
        // Slots are taken from the oldest batches that hold any on this
        // boundary (at most MAP_BATCHES of them).
        for i in 0..usize::from(self.count) {
            if need == 0 {
                break;
            }
            let slot = (usize::from(self.first) + i) % MAP_BATCHES;
            let (start, len) = self.range(i, boundary);
            let take = len.min(need);
            let Some(ring) = self.entries.get_mut(boundary) else {
                break;
            };
            let mut live = 0u16;
            for j in 0..take {
                if let Some(e) = ring.get_mut((start + j) % M) {
                    if e.live() {
                        live += 1;
                    }
                    *e = Entry::DEAD;
                }
            }
            if let (Some(b), Some(t), Some(u)) = (
                self.batches.get_mut(slot),
                self.tail.get_mut(boundary),
                self.used.get_mut(boundary),
            ) {
                if let (Some(l), Some(lv)) = (b.len.get_mut(boundary), b.live.get_mut(boundary)) {
                    *l = l.saturating_sub(take as u16);
                    *lv = lv.saturating_sub(live);
                }
                // This batch's slots start at the ring's tail: every older
                // batch has none left on this boundary.
                *t = ((usize::from(*t) + take) % M) as u16;
                *u = u.saturating_sub(take as u16);
            }
            dropped += u32::from(live);
            need -= take;
        }
        dropped
    }

    /// Put a retiring key frame's fused points into the map: the points
    /// [`FusedStatus::Consistent`] (or [`FusedStatus::Single`] if
    /// `min_pairs ≤ 1`) with at least `min_pairs` agreeing pairs and a
    /// bounded interval, as one batch posed by `chain` (the key frame's
    /// motion to the current frame). The oldest points make room.
    ///
    /// Work: two passes over the key frame's points (`B·N`), plus the
    /// points dropped for room.
    pub(crate) fn retire<const N: usize>(
        &mut self,
        key: &KeyFrame<N, B>,
        s: &Structure<N, B>,
        chain: &Chain,
        min_pairs: u8,
    ) -> Retired {
        let mut out = Retired {
            key: key.id(),
            ..Retired::default()
        };
        let eligible = |k: usize, i: usize| -> bool {
            key.cell(k, i).is_some_and(|c| {
                let st = c.status();
                let ok =
                    st == FusedStatus::Consistent || (st == FusedStatus::Single && min_pairs <= 1);
                ok && c.support() >= min_pairs
                    && c.interval().is_some_and(|iv| iv.z_far.is_finite())
            })
        };
        // 1. Count, per boundary.
        let mut want = [0usize; B];
        for (k, w) in want.iter_mut().enumerate() {
            for i in 0..key.len(k) {
                if eligible(k, i) {
                    *w += 1;
                } else {
                    match key.cell(k, i).map(|c| c.status()) {
                        Some(FusedStatus::Inconsistent) => out.inconsistent += 1,
                        _ => out.unverified += 1,
                    }
                }
            }
        }
        if want.iter().all(|&w| w == 0) {
            return out;
        }
        // 2. Room: a batch slot, then ring slots, oldest first.
        if usize::from(self.count) >= MAP_BATCHES {
            if let Some(b) = self.batches.get(usize::from(self.first)).copied() {
                out.dropped += b.live_total();
                self.pop_oldest(&b.len);
            }
        }
        for (k, w) in want.iter_mut().enumerate() {
            if *w > M {
                out.unfit += (*w - M) as u32;
                *w = M;
            }
            let used = self.used.get(k).map_or(0, |&u| usize::from(u));
            let free = M - used.min(M);
            if free < *w {
                out.dropped += self.free_slots(k, *w - free);
            }
        }
        self.pop_dead();
        self.drops.capacity = self.drops.capacity.saturating_add(out.dropped);
        // 3. The batch.
        let (a, b, rho, phi) = chain.pose();
        let mut batch = Batch::<B> {
            a,
            b,
            rho,
            phi,
            key: key.id(),
            ..Batch::EMPTY
        };
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        let mut reach = 0.0f32;
        let cam = s.camera1();
        for (k, &w) in want.iter().enumerate() {
            let start = self.tail.get(k).map_or(0, |&t| usize::from(t))
                + self.used.get(k).map_or(0, |&u| usize::from(u));
            let (Some(ring), Some(results)) = (self.entries.get_mut(k), s.boundaries().get(k))
            else {
                continue;
            };
            let mut n = 0usize;
            for i in 0..key.len(k) {
                if n >= w {
                    break;
                }
                if !eligible(k, i) {
                    continue;
                }
                let (Some(iv), Some(r)) = (
                    key.cell(k, i).and_then(|c| c.interval()),
                    results.points().get(i),
                ) else {
                    continue;
                };
                let (x, y) = cam.normalise(r.pixel1());
                let DepthInterval { z_near, z_far } = iv;
                let e = Entry {
                    x,
                    y,
                    near: self.scale.down(z_near),
                    far: self.scale.up(z_far).max(1),
                };
                let zf = self.scale.depth(e.far);
                let zn = self.scale.depth(e.near);
                for p in [[x * zn, y * zn, zn], [x * zf, y * zf, zf]] {
                    for ((l, h), v) in lo.iter_mut().zip(hi.iter_mut()).zip(p) {
                        *l = fmin(*l, v);
                        *h = fmax(*h, v);
                    }
                }
                reach = fmax(reach, zf * (1.0 + 0.5 * (x * x + y * y)));
                if let Some(slot) = ring.get_mut((start + n) % M) {
                    *slot = e;
                }
                n += 1;
            }
            let n16 = n as u16;
            if let (Some(l), Some(lv), Some(u)) = (
                batch.len.get_mut(k),
                batch.live.get_mut(k),
                self.used.get_mut(k),
            ) {
                *l = n16;
                *lv = n16;
                *u = u.saturating_add(n16);
            }
            out.entered += n as u32;
        }
        let [l0, l1, l2] = lo;
        let [h0, h1, h2] = hi;
        let half = [0.5 * (h0 - l0), 0.5 * (h1 - l1), 0.5 * (h2 - l2)];
        batch.centre = [0.5 * (h0 + l0), 0.5 * (h1 + l1), 0.5 * (h2 + l2)];
        // Half the box's diagonal, rounded up a little.
        batch.spread = sqrt(dot3(half, half)) * 1.0001 + 1e-6;
        batch.reach = reach;
        let slot = (usize::from(self.first) + usize::from(self.count)) % MAP_BATCHES;
        if let Some(b) = self.batches.get_mut(slot) {
            *b = batch;
            self.count += 1;
            // Points the camera has passed already leave at once.
            let w = forward_axis(self.tilt);
            self.drop_behind(usize::from(self.count) - 1, &batch, w);
            self.pop_dead();
        }
        out
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
