//! Epipolar geometry of a frame pair and the search for intersections of an
//! epipolar line with a frame-2 boundary (paper Sec. 2, steps 1–3).
//!
//! # Rotation compensation (step 1), exact
//! A frame-1 pixel `p₁` is mapped by the homography `H = K₂ Rᵀ K₁⁻¹` to
//! `p₁'`, where it would be seen from the frame-2 orientation without
//! translation. With `q = Rᵀ K₁⁻¹ p₁` (third component `q_z`), a point at
//! frame-1 depth `Z` on that ray has depth `s = Z · q_z` in the compensated
//! frame, and the remaining motion is the pure translation
//! `T' = Rᵀ T = (U', V', W')`.
//!
//! # Epipolar line (steps 2–3)
//! In pixels, with `c₂` the frame-2 principal point, define
//! `a = W'(p₁' − c₂) − (f_x U', f_y V')`. From eq. 2.2 (per axis, with the
//! focal lengths of frame 2) the frame-2 point is
//! `p₂ = p₁' + a / (s − W')`,
//! so the disparity `d = p₂ − p₁'` is parallel to `a`. Writing `p₂ = p₁' + τ a`,
//! a point in front of both cameras (`s > 0`, `s − W' > 0`) has
//! `τ > 0` and, when `W' < 0`, `τ < 1/|W'|`. For `W' ≠ 0`, `a = W'(p₁' − FOE)`
//! with `FOE = c₂ + (f_x U', f_y V')/W'` (eq. A.1): the search range is the
//! half-line from `p₁'` away from the FOE when `W' > 0` and the segment from
//! `p₁'` to the FOE when `W' < 0`, exactly as in the paper. When `W' = 0` the
//! FOE is at infinity and all epipolar lines are parallel to `−(U', V')`
//! (ordinary stereo, eq. 3.3); the same formulas hold unchanged.
//!
//! # Finding the intersections
//! Every epipolar line passes through the FOE (a point at infinity when
//! `W' = 0`), so each line is identified by one number, its *key*: the
//! pseudo-angle of its direction about the FOE, or, when the FOE is far
//! outside the image, where it crosses a fixed reference line. A segment of
//! the frame-2 boundary can only cross the line if the line's key lies
//! between the keys of the segment's end points. [`IndexedSearch`] keeps the
//! key range of every subtree of segments in an implicit binary tree built in
//! one linear pass per boundary, and descends only into subtrees whose range
//! holds the key. The key test is only a filter (widened by a margin that
//! covers rounding); the decision whether a segment crosses is always the
//! exact side test of [`EpipolarLine::crossing`], so any search that offers
//! every crossing segment gives identical results.

use crate::camera::{Camera, Pixel};
use crate::math::{cross, dot, mat3_mul, mat3_transpose, mat3_vec, pseudo_angle, sub};
use crate::motion::Motion;

/// At most this many intersections of one epipolar line with one boundary
/// are told apart; a line meeting the boundary more often is
/// [`crate::Status::Tangled`].
pub const MAX_CROSSINGS: usize = 8;

/// The intersections found for one epipolar line: up to
/// [`MAX_CROSSINGS`]` + 1` (one more than can be told apart, so "too many"
/// is visible).
pub type Crossings = heapless::Vec<Crossing, { MAX_CROSSINGS + 1 }>;

/// One intersection of an epipolar line with a boundary segment.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Crossing {
    /// Index `j` of the segment from point `j` to point `j + 1`.
    pub segment: usize,
    /// Position along the line: `p₂ = p₁' + τ a` (dimensionless, `1/(s − W')`).
    pub tau: f32,
}

/// How a line through the FOE is identified by one number.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PencilKey {
    /// FOE near or inside the image: pseudo-angle of `v − FOE`, in `[0, 4)`.
    Angular {
        /// Focus of expansion, frame-2 pixels.
        foe: [f32; 2],
        /// Sign of `W'`: +1 or −1.
        sign_w: f32,
    },
    /// FOE far outside the image (or at infinity): the position, in pixels,
    /// where the line through the FOE crosses the reference line through
    /// `c₂` perpendicular to `g = (f_x U', f_y V')`.
    Projective {
        /// Principal point of frame 2.
        c: [f32; 2],
        /// Unit vector along `g`.
        g_hat: [f32; 2],
        /// `|g|`.
        g_norm: f32,
        /// `W'`.
        w: f32,
    },
}

/// Key widening that covers rounding in the pseudo-angle (units of `[0, 4)`).
const ANGULAR_EPS: f32 = 1.0e-4;
/// Key widening in the projective mode, pixels (plus a relative part).
const PROJECTIVE_EPS: f32 = 1.0e-3;
/// Sentinel for "no usable key": the segment is always examined.
const NO_KEY: f32 = f32::INFINITY;

impl PencilKey {
    /// Key of a boundary vertex, or [`NO_KEY`] when it cannot be keyed
    /// reliably (at the FOE, or near the singular line of the projective key).
    fn vertex(&self, v: [f32; 2]) -> f32 {
        match *self {
            PencilKey::Angular { foe, .. } => {
                let d = sub(v, foe);
                if dot(d, d) < 1.0e-6 {
                    NO_KEY
                } else {
                    pseudo_angle(d)
                }
            }
            PencilKey::Projective { .. } => self.projective(v),
        }
    }

    fn projective(&self, v: [f32; 2]) -> f32 {
        match *self {
            PencilKey::Projective {
                c,
                g_hat,
                g_norm,
                w,
            } => {
                let d = sub(v, c);
                let n_hat = [-g_hat[1], g_hat[0]];
                let den = g_norm - w * dot(g_hat, d);
                if den < 0.25 * g_norm {
                    NO_KEY
                } else {
                    g_norm * dot(n_hat, d) / den
                }
            }
            PencilKey::Angular { .. } => NO_KEY,
        }
    }

    /// Key of an epipolar line, [`NO_KEY`] if it has none usable.
    pub(crate) fn line(&self, line: &EpipolarLine) -> f32 {
        match *self {
            PencilKey::Angular { sign_w, .. } => {
                pseudo_angle([sign_w * line.a[0], sign_w * line.a[1]])
            }
            PencilKey::Projective { .. } => self.projective(line.origin),
        }
    }

    /// Key interval of the segment between vertices with keys `k0`, `k1`.
    fn segment(&self, k0: f32, k1: f32) -> Interval {
        if !(k0.is_finite() && k1.is_finite()) {
            return Interval::ALL;
        }
        let (lo, hi) = if k0 <= k1 { (k0, k1) } else { (k1, k0) };
        match self {
            PencilKey::Angular { .. } => {
                let span = hi - lo;
                if (span - 2.0).abs() < 1.0e-3 {
                    // The segment passes (almost) through the FOE.
                    Interval::ALL
                } else if span > 2.0 {
                    // The shorter arc wraps through the cut at "up".
                    Interval {
                        lo: hi - ANGULAR_EPS,
                        hi: lo + 4.0 + ANGULAR_EPS,
                    }
                } else {
                    Interval {
                        lo: lo - ANGULAR_EPS,
                        hi: hi + ANGULAR_EPS,
                    }
                }
            }
            PencilKey::Projective { .. } => {
                let eps = PROJECTIVE_EPS + 1.0e-5 * lo.abs().max(hi.abs());
                Interval {
                    lo: lo - eps,
                    hi: hi + eps,
                }
            }
        }
    }

    /// Whether a line with key `q` may meet a segment with interval `i`.
    fn admits(&self, i: &Interval, q: f32) -> bool {
        if !q.is_finite() {
            return true;
        }
        match self {
            PencilKey::Angular { .. } => i.holds(q) || i.holds(q + 4.0),
            PencilKey::Projective { .. } => i.holds(q),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Interval {
    lo: f32,
    hi: f32,
}

impl Interval {
    const ALL: Interval = Interval {
        lo: f32::NEG_INFINITY,
        hi: f32::INFINITY,
    };
    const EMPTY: Interval = Interval {
        lo: f32::INFINITY,
        hi: f32::NEG_INFINITY,
    };
    fn holds(&self, q: f32) -> bool {
        self.lo <= q && q <= self.hi
    }
    fn union(&self, o: &Interval) -> Interval {
        Interval {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }
}

/// The epipolar geometry of one frame pair, computed once per frame.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PairGeometry {
    h: crate::math::Mat3,
    w: f32,
    g: [f32; 2],
    c2: [f32; 2],
    key: PencilKey,
}

/// A frame-1 pixel after exact rotation compensation.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Compensated {
    /// `p₁' = K₂ Rᵀ K₁⁻¹ p₁`, frame-2 pixels.
    pub pixel: [f32; 2],
    /// `q_z`: frame-1 depth `Z` and compensated depth `s` relate as `s = Z q_z`.
    pub depth_scale: f32,
    /// Upper bound on how much the homography stretches a small
    /// displacement at `p₁` (max of the 1- and ∞-norms of its Jacobian,
    /// both ≥ the spectral norm).
    pub stretch: f32,
}

/// The epipolar line of one compensated frame-1 point.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EpipolarLine {
    /// `p₁'`, frame-2 pixels.
    pub origin: [f32; 2],
    /// `a = W'(p₁' − c₂) − (f_x U', f_y V')`, pixels × length unit.
    pub a: [f32; 2],
    /// `|a|²`.
    pub a2: f32,
    /// Largest admissible `τ` (`1/|W'|` when `W' < 0`, else infinity).
    pub tau_max: f32,
}

impl EpipolarLine {
    /// The intersection of this line's search range with the segment
    /// `v0 → v1` (segment index `segment`), if any.
    ///
    /// The crossing test is the exact side test on the signs of
    /// `σ = a × (v − p₁')` (a vertex on the line counts as on the positive
    /// side), so two adjacent segments never both report a crossing through
    /// their shared vertex.
    pub fn crossing(&self, segment: usize, v0: Pixel, v1: Pixel) -> Option<Crossing> {
        let (v0, v1) = (v0.arr(), v1.arr());
        let s0 = cross(self.a, sub(v0, self.origin));
        let s1 = cross(self.a, sub(v1, self.origin));
        if (s0 >= 0.0) == (s1 >= 0.0) {
            return None;
        }
        // s0 and s1 have strictly different signs, so s0 - s1 != 0.
        let u = s0 / (s0 - s1);
        let p = [v0[0] + u * (v1[0] - v0[0]), v0[1] + u * (v1[1] - v0[1])];
        // a2 > 0 is guaranteed by the caller (the point is not at the FOE).
        let tau = dot(sub(p, self.origin), self.a) / self.a2;
        (tau > 0.0 && tau < self.tau_max).then_some(Crossing { segment, tau })
    }

    /// The frame-2 pixel at position `tau` on the line.
    pub fn at(&self, tau: f32) -> Pixel {
        Pixel::new(
            self.origin[0] + tau * self.a[0],
            self.origin[1] + tau * self.a[1],
        )
    }
}

impl PairGeometry {
    /// Geometry for frame 1 seen by `cam1`, frame 2 by `cam2`, and `motion`.
    pub fn new(cam1: &Camera, cam2: &Camera, motion: &Motion) -> Self {
        let rt = mat3_transpose(&motion.rotation_matrix());
        let tp = mat3_vec(&rt, motion.translation());
        // Camera::new guarantees fx, fy >= 1: the divisions are safe.
        let (ifx, ify) = (1.0 / cam1.fx(), 1.0 / cam1.fy());
        let kinv = [
            [ifx, 0.0, -cam1.cx() * ifx],
            [0.0, ify, -cam1.cy() * ify],
            [0.0, 0.0, 1.0],
        ];
        let k2 = [
            [cam2.fx(), 0.0, cam2.cx()],
            [0.0, cam2.fy(), cam2.cy()],
            [0.0, 0.0, 1.0],
        ];
        let h = mat3_mul(&k2, &mat3_mul(&rt, &kinv));
        let w = tp[2];
        let g = [cam2.fx() * tp[0], cam2.fy() * tp[1]];
        let c2 = [cam2.cx(), cam2.cy()];
        let g_norm = crate::math::sqrt(dot(g, g));
        // Projective keys are well conditioned when the FOE is at least two
        // image reaches away from the principal point (or at infinity).
        let key = if w.abs() * cam2.reach() <= 0.5 * g_norm && g_norm > 0.0 {
            PencilKey::Projective {
                c: c2,
                g_hat: [g[0] / g_norm, g[1] / g_norm],
                g_norm,
                w,
            }
        } else {
            // Here |w| * reach > 0.5 * g_norm >= 0, so w != 0.
            PencilKey::Angular {
                foe: [c2[0] + g[0] / w, c2[1] + g[1] / w],
                sign_w: if w > 0.0 { 1.0 } else { -1.0 },
            }
        };
        Self { h, w, g, c2, key }
    }

    /// `W'`, the forward component of the rotation-compensated translation.
    pub fn w(&self) -> f32 {
        self.w
    }

    /// How epipolar lines are keyed for this pair.
    pub fn key(&self) -> &PencilKey {
        &self.key
    }

    /// The focus of expansion in frame-2 pixels (eq. A.1 with the
    /// compensated translation), `None` when it is at infinity (`W' = 0`).
    pub fn focus_of_expansion(&self) -> Option<Pixel> {
        if self.w == 0.0 {
            return None;
        }
        let f = [
            self.c2[0] + self.g[0] / self.w,
            self.c2[1] + self.g[1] / self.w,
        ];
        (f[0].is_finite() && f[1].is_finite()).then_some(Pixel::new(f[0], f[1]))
    }

    /// Exact rotation compensation of a frame-1 pixel; `None` when the ray
    /// points behind the frame-2 camera orientation (`q_z ≤ 1e-6`).
    pub fn compensate(&self, p1: Pixel) -> Option<Compensated> {
        let [x, y, z] = mat3_vec(&self.h, [p1.u, p1.v, 1.0]);
        let [[h00, h01, _], [h10, h11, _], [h20, h21, _]] = self.h;
        if z <= 1.0e-6 {
            return None;
        }
        let iz = 1.0 / z;
        let (px, py) = (x * iz, y * iz);
        // Jacobian of (x/z, y/z) with respect to (u, v).
        let j00 = (h00 - px * h20) * iz;
        let j01 = (h01 - px * h21) * iz;
        let j10 = (h10 - py * h20) * iz;
        let j11 = (h11 - py * h21) * iz;
        let n1 = (j00.abs() + j10.abs()).max(j01.abs() + j11.abs());
        let ninf = (j00.abs() + j01.abs()).max(j10.abs() + j11.abs());
        Some(Compensated {
            pixel: [px, py],
            depth_scale: z,
            stretch: n1.max(ninf),
        })
    }

    /// The epipolar line of a compensated point (the vector `a`).
    pub fn line(&self, c: &Compensated) -> EpipolarLine {
        let a = [
            self.w * (c.pixel[0] - self.c2[0]) - self.g[0],
            self.w * (c.pixel[1] - self.c2[1]) - self.g[1],
        ];
        EpipolarLine {
            origin: c.pixel,
            a,
            a2: dot(a, a),
            tau_max: if self.w < 0.0 {
                -1.0 / self.w
            } else {
                f32::INFINITY
            },
        }
    }
}

/// A strategy for finding every crossing of an epipolar line with a frame-2
/// boundary. [`IndexedSearch`] is the one the processor uses; tests plug in
/// a brute-force one and check both give identical results.
pub trait CrossingSearch {
    /// Called once for each frame-2 boundary before its lines are searched.
    fn prepare(&mut self, boundary: &[Pixel], key: &PencilKey);
    /// Push the crossings of `line` with `boundary` (the one last prepared)
    /// into `out`, each found by [`EpipolarLine::crossing`], stopping when
    /// `out` is full. The order does not matter.
    fn search(&mut self, line: &EpipolarLine, boundary: &[Pixel], out: &mut Crossings);
}

/// The indexed search: a key-range tree over the segments of one boundary.
///
/// Memory: `12 N` bytes (one key per vertex, one interval per inner node).
/// Work: `O(M)` to prepare a boundary of `M` points; per line, the nodes
/// whose key range holds the line's key, i.e. `O(log M)` for each segment
/// the line can meet, and at most `O(M)` for a line that runs along the
/// boundary (a degenerate, grazing configuration).
#[derive(Debug, Clone)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct IndexedSearch<const N: usize> {
    keys: [f32; N],
    nodes: [Interval; N],
    segments: usize,
    key: PencilKey,
}

impl<const N: usize> Default for IndexedSearch<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> IndexedSearch<N> {
    /// An empty index.
    pub const fn new() -> Self {
        Self {
            keys: [0.0; N],
            nodes: [Interval::EMPTY; N],
            segments: 0,
            key: PencilKey::Angular {
                foe: [0.0, 0.0],
                sign_w: 1.0,
            },
        }
    }

    fn seg_interval(&self, j: usize) -> Interval {
        match (self.keys.get(j), self.keys.get(j + 1)) {
            (Some(&k0), Some(&k1)) => self.key.segment(k0, k1),
            _ => Interval::ALL,
        }
    }

    fn node_interval(&self, x: usize) -> Interval {
        if x >= self.segments {
            self.seg_interval(x - self.segments)
        } else {
            self.nodes.get(x).copied().unwrap_or(Interval::ALL)
        }
    }

    /// Build the tree over the vertex keys `keys` (at most `N` are used).
    fn build(&mut self, key: &PencilKey, keys: impl Iterator<Item = f32>) {
        self.key = *key;
        let mut n: usize = 0;
        for (slot, k) in self.keys.iter_mut().zip(keys) {
            *slot = k;
            n += 1;
        }
        self.segments = n.saturating_sub(1);
        // Inner nodes 1..S, children 2x and 2x+1; indices >= S are leaves.
        for x in (1..self.segments).rev() {
            let i = self
                .node_interval(2 * x)
                .union(&self.node_interval(2 * x + 1));
            if let Some(slot) = self.nodes.get_mut(x) {
                *slot = i;
            }
        }
    }

    /// Index the rotation-compensated frame-1 boundary (for the fold test).
    pub(crate) fn prepare_compensated(&mut self, boundary: &[Pixel], geom: &PairGeometry) {
        let key = geom.key;
        self.build(
            &key,
            boundary
                .iter()
                .map(|p| geom.compensate(*p).map_or(NO_KEY, |c| key.vertex(c.pixel))),
        );
    }

    /// Whether the indexed polyline meets the line with key `q` at a segment
    /// outside `skip` (inclusive segment range). Unkeyable lines answer yes.
    pub(crate) fn meets_outside(&self, q: f32, skip: (usize, usize)) -> bool {
        let s = self.segments;
        if s == 0 {
            return false;
        }
        if !q.is_finite() {
            return true;
        }
        let mut stack: heapless::Vec<usize, 64> = heapless::Vec::new();
        let _ = stack.push(1);
        while let Some(x) = stack.pop() {
            if !self.key.admits(&self.node_interval(x), q) {
                continue;
            }
            if x >= s {
                let j = x - s;
                if j < skip.0 || j > skip.1 {
                    return true;
                }
            } else if stack.push(2 * x).is_err() || stack.push(2 * x + 1).is_err() {
                return true;
            }
        }
        false
    }

    fn scan_all(line: &EpipolarLine, boundary: &[Pixel], out: &mut Crossings) {
        for (j, w) in boundary.windows(2).enumerate() {
            if let [v0, v1] = w {
                if let Some(c) = line.crossing(j, *v0, *v1) {
                    if out.push(c).is_err() {
                        return;
                    }
                }
            }
        }
    }
}

impl<const N: usize> CrossingSearch for IndexedSearch<N> {
    fn prepare(&mut self, boundary: &[Pixel], key: &PencilKey) {
        self.build(key, boundary.iter().map(|p| key.vertex(p.arr())));
    }

    fn search(&mut self, line: &EpipolarLine, boundary: &[Pixel], out: &mut Crossings) {
        let s = self.segments;
        let q = self.key.line(line);
        if s == 0 || !q.is_finite() || boundary.len() != s + 1 {
            Self::scan_all(line, boundary, out);
            return;
        }
        let mut stack: heapless::Vec<usize, 64> = heapless::Vec::new();
        // Cannot fail: the stack is empty.
        let _ = stack.push(1);
        while let Some(x) = stack.pop() {
            if !self.key.admits(&self.node_interval(x), q) {
                continue;
            }
            if x >= s {
                let j = x - s;
                if let (Some(v0), Some(v1)) = (boundary.get(j), boundary.get(j + 1)) {
                    if let Some(c) = line.crossing(j, *v0, *v1) {
                        if out.push(c).is_err() {
                            return;
                        }
                    }
                }
            } else if stack.push(2 * x).is_err() || stack.push(2 * x + 1).is_err() {
                // Unreachable for any N below 2^62 (the tree is shallower
                // than the stack), but never give a wrong answer: rescan.
                out.clear();
                Self::scan_all(line, boundary, out);
                return;
            }
        }
    }
}
