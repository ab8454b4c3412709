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
//! running maximum and minimum of the keys along the boundary, built in one
//! linear pass, so the segments that can hold a key form one run, found by
//! probing from the previous point's run (a sweep along the boundary). The
//! key test is only a filter (widened by a margin that covers rounding); the
//! decision whether a segment crosses is always the exact side test of
//! [`EpipolarLine::crossing`], so any search that offers every crossing
//! segment gives identical results.

use crate::camera::{Camera, Pixel};
use crate::math::{
    ceil_i32, cross, dot, fmax, fmin, mat3_transpose, mat3_vec, next_up, pseudo_angle,
    pseudo_angle_nonzero, sub,
};
use crate::motion::Motion;

/// At most this many intersections of one epipolar search range with one
/// boundary are told apart; more is [`crate::Status::Tangled`].
pub const MAX_CROSSINGS: usize = 8;

/// At most this many intersections of the whole ray from the FOE through a
/// point are collected; a boundary meeting the ray more often runs along
/// it, and the point is [`crate::Status::Tangled`] without further search.
pub const MAX_RAY_CROSSINGS: usize = 16;

/// The intersections found for one epipolar ray: up to
/// [`MAX_RAY_CROSSINGS`]` + 1` (one more than can be told apart, so "too
/// many" is visible).
pub type Crossings = heapless::Vec<Crossing, { MAX_RAY_CROSSINGS + 1 }>;

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
    /// FOE off to one side of everything keyed (above or below it in the
    /// image): the pseudo-angle of `v − FOE` within that half-plane,
    /// `d_u / (|d_u| + t)` with `t = side · d_v`, in `(−1, 1)`. It needs no
    /// quadrants and never wraps; a point with `t < min_t` has no key.
    Half {
        /// Focus of expansion, frame-2 pixels.
        foe: [f32; 2],
        /// +1 when the keyed points lie below the FOE (larger `v`), −1 above.
        side: f32,
        /// The smallest `t` with a key, pixels (at least [`HALF_MIN_DV`]).
        min_t: f32,
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

/// Key widening that covers rounding in the pseudo-angle (units of `[0, 4)`;
/// also for [`PencilKey::Half`]).
pub(crate) const ANGULAR_EPS: f32 = 1.0e-4;
/// The smallest distance `t` from the FOE's row, pixels, of a point with a
/// [`PencilKey::Half`] key, for coordinates (FOE, points, principal point)
/// within 1 000 px; beyond that it grows in proportion. The key
/// `d_u/(|d_u| + t)` moves by at most (rounding of `d`) / (|d_u| + t); `d`
/// is rounded by at most 2⁻²⁴ of the larger coordinate, about 6e-5 px at
/// 1 000 px, and the direction of the epipolar vector `a` differs from that
/// of `p₁' − FOE` by a like amount: under the key margin, 1e-4, in all.
pub const HALF_MIN_DV: f32 = 4.0;
/// [`PairGeometry::half_key`] is offered only for a boundary at least this
/// far from the FOE's row (pixels), so that its frame-1 counterpart, after
/// rotation compensation, is all keyed too.
const HALF_MARGIN: f32 = 16.0;
/// Key widening in the projective mode, pixels (plus a relative part).
const PROJECTIVE_EPS: f32 = 1.0e-3;
/// Sentinel for "no usable key": the segment is always examined.
const NO_KEY: f32 = f32::INFINITY;

/// [`PencilKey::Half`]'s key of a point `v`, or [`NO_KEY`].
#[inline(always)]
pub(crate) fn half_key(foe: [f32; 2], side: f32, min_t: f32, v: [f32; 2]) -> f32 {
    let d = sub(v, foe);
    let t = side * d[1];
    // NaN fails the test too.
    if t >= min_t {
        d[0] / (d[0].abs() + t)
    } else {
        NO_KEY
    }
}

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
                    // |d|² ≥ 1e-6 (or NaN, which gives NaN either way).
                    pseudo_angle_nonzero(d)
                }
            }
            PencilKey::Half { foe, side, min_t } => half_key(foe, side, min_t, v),
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
            PencilKey::Angular { .. } | PencilKey::Half { .. } => NO_KEY,
        }
    }

    /// Key of an epipolar line, [`NO_KEY`] if it has none usable.
    pub(crate) fn line(&self, line: &EpipolarLine) -> f32 {
        match *self {
            PencilKey::Angular { sign_w, .. } => {
                pseudo_angle([sign_w * line.a[0], sign_w * line.a[1]])
            }
            PencilKey::Half { foe, side, min_t } => half_key(foe, side, min_t, line.origin),
            PencilKey::Projective { .. } => self.projective(line.origin),
        }
    }

    /// Key of a boundary vertex (public within the crate for the fold test).
    pub(crate) fn vertex_key(&self, v: [f32; 2]) -> f32 {
        self.vertex(v)
    }
}

/// The epipolar geometry of one frame pair, computed once per frame.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PairGeometry {
    h: crate::math::Mat3,
    r: crate::math::Mat3,
    k2: (f32, f32, f32, f32),
    /// `T' = Rᵀ T`, the compensated translation.
    tp: [f32; 3],
    w: f32,
    g: [f32; 2],
    c2: [f32; 2],
    key: PencilKey,
    /// An upper bound on [`Compensated::stretch`] over the whole frame-1
    /// image with its margin (infinity when none is known).
    stretch_bound: f32,
    /// [`EpipolarLine::tau_max`] (also `ray_max`) and `ray_min`: the same
    /// for every line of the pair.
    tau_range: (f32, f32),
    /// For [`Self::half_key`]: the FOE, the keys' `min_t` and the distance
    /// a boundary must keep from the FOE's row (none without a FOE).
    half: Option<([f32; 2], f32, f32)>,
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
    /// Largest admissible `τ` of the search range (`1/|W'|` when `W' < 0`,
    /// else infinity); the smallest is 0 (exclusive).
    pub tau_max: f32,
    /// The ray from the FOE through `p₁'` is `ray_min < τ < ray_max`
    /// (`τ > −1/W'` when `W' > 0`, `τ < 1/|W'|` when `W' < 0`, the whole
    /// line when `W' = 0`); the search range is the part with `τ > 0`.
    pub ray_min: f32,
    /// See `ray_min`.
    pub ray_max: f32,
    /// The line's key if the caller already knows it (any value congruent
    /// modulo the key's period will do), else infinity: the search then
    /// computes it. Only the search's speed depends on it.
    pub key: f32,
}

/// The side of a vertex from its `σ` ([`EpipolarLine::side`]): 0 for
/// `σ ≥ 0`, 1 for `σ < 0`. The sign bit once −0 is made +0 (`+ 0.0`), so a
/// vertex on the line counts as on the positive side.
#[inline(always)]
pub(crate) fn side_bit(sigma: f32) -> u32 {
    (sigma + 0.0).to_bits() >> 31
}

/// Whether two vertices with sides `s0`, `s1` ([`EpipolarLine::side`]) lie
/// on opposite sides of the line: `side_bit(s0) != side_bit(s1)`, decided
/// by the sign of `s0 s1` (one compare) except for an exact zero (a vertex
/// on the line, or underflow) or NaN, which take the sign-bit rule.
#[inline(always)]
pub(crate) fn opposite_sides(s0: f32, s1: f32) -> bool {
    let p = s0 * s1;
    if p < 0.0 {
        true
    } else if p > 0.0 {
        false
    } else {
        side_bit(s0) != side_bit(s1)
    }
}

impl EpipolarLine {
    /// The intersection of the ray from the FOE through `p₁'` with the
    /// segment `v0 → v1` (segment index `segment`), if any.
    ///
    /// The crossing test is the exact side test on the signs of
    /// `σ = a × (v − p₁')` (a vertex on the line counts as on the positive
    /// side), so two adjacent segments never both report a crossing through
    /// their shared vertex.
    pub fn crossing(&self, segment: usize, v0: Pixel, v1: Pixel) -> Option<Crossing> {
        let (s0, s1) = (self.side(v0), self.side(v1));
        if side_bit(s0) == side_bit(s1) {
            return None;
        }
        self.crossing_between(segment, v0, v1, s0, s1)
    }

    /// `σ = a × (v − p₁')` of a vertex: its side of the line.
    #[inline(always)]
    pub(crate) fn side(&self, v: Pixel) -> f32 {
        cross(self.a, sub(v.arr(), self.origin))
    }

    /// [`Self::crossing`] of a segment whose end points' sides `s0`, `s1`
    /// ([`Self::side`]) have different [`side_bit`]s.
    #[inline(always)]
    pub(crate) fn crossing_between(
        &self,
        segment: usize,
        v0: Pixel,
        v1: Pixel,
        s0: f32,
        s1: f32,
    ) -> Option<Crossing> {
        let tau = self.tau_between(v0, v1, s0, s1);
        (tau > self.ray_min && tau < self.ray_max).then_some(Crossing { segment, tau })
    }

    /// The position `τ` where the line meets the segment `v0 → v1` whose
    /// end points' sides `s0`, `s1` have different [`side_bit`]s: from
    /// `p₁' + τ a = v0 + u (v1 − v0)`, crossing both sides with
    /// `e = v1 − v0`, `τ = ((v0 − p₁') × e) / (a × e)`, and
    /// `a × e = σ₁ − σ₀`, which is not zero since the signs differ (a NaN
    /// σ, not from finite input, gives a NaN τ: no crossing).
    #[inline(always)]
    pub(crate) fn tau_between(&self, v0: Pixel, v1: Pixel, s0: f32, s1: f32) -> f32 {
        let (v0, v1) = (v0.arr(), v1.arr());
        cross(sub(v0, self.origin), sub(v1, v0)) / (s1 - s0)
    }

    /// Whether a crossing lies in the search range: the half-line away from
    /// the FOE (`W' ≥ 0`) or the segment towards it (`W' < 0`), Sec. 2 (3).
    pub fn in_search_range(&self, c: &Crossing) -> bool {
        c.tau > 0.0 && c.tau < self.tau_max
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
        let (kx, ky) = (-cam1.cx() * ifx, -cam1.cy() * ify);
        // H = K₂ Rᵀ K₁⁻¹ with the zeros of the intrinsic matrices skipped
        // (each sum keeps the dense product's order: the same value).
        let m = rt.map(|[r0, r1, r2]| [r0 * ifx, r1 * ify, r0 * kx + r1 * ky + r2]);
        let [[a0, a1, a2], [b0, b1, b2], m2] = m;
        let [c0, c1, c2] = m2;
        let (fx2, fy2, cx2, cy2) = (cam2.fx(), cam2.fy(), cam2.cx(), cam2.cy());
        let h = [
            [
                fx2 * a0 + cx2 * c0,
                fx2 * a1 + cx2 * c1,
                fx2 * a2 + cx2 * c2,
            ],
            [
                fy2 * b0 + cy2 * c0,
                fy2 * b1 + cy2 * c1,
                fy2 * b2 + cy2 * c2,
            ],
            m2,
        ];
        let w = tp[2];
        let g = [cam2.fx() * tp[0], cam2.fy() * tp[1]];
        let c2 = [cam2.cx(), cam2.cy()];
        // Projective keys are well conditioned when the FOE is at least two
        // image reaches away from the principal point (or at infinity):
        // `|w| reach ≤ |g| / 2`, squared.
        let (wr2, g2) = ((w * w) * cam2.reach2(), dot(g, g));
        // Eq. A.1 (infinite or NaN when W' = 0).
        let foe = [c2[0] + g[0] / w, c2[1] + g[1] / w];
        let key = if 4.0 * wr2 <= g2 && g2 > 0.0 {
            let g_norm = crate::math::sqrt(g2);
            PencilKey::Projective {
                c: c2,
                g_hat: [g[0] / g_norm, g[1] / g_norm],
                g_norm,
                w,
            }
        } else {
            // Here (w reach)² > |g|²/4 ≥ 0, so w != 0.
            PencilKey::Angular {
                foe,
                sign_w: if w > 0.0 { 1.0 } else { -1.0 },
            }
        };
        Self {
            h,
            r: motion.rotation_matrix(),
            k2: (cam2.fx(), cam2.fy(), cam2.cx(), cam2.cy()),
            tp,
            w,
            g,
            c2,
            key,
            stretch_bound: stretch_bound(&h, cam1),
            half: (w != 0.0 && foe[0].is_finite() && foe[1].is_finite()).then(|| {
                // Coordinates beyond 1 000 px scale the rounding (see
                // HALF_MIN_DV).
                let scale = fmax(foe[0].abs(), foe[1].abs()) + fmax(c2[0].abs(), c2[1].abs());
                let min_t = HALF_MIN_DV * fmax(1.0, scale * 1.0e-3);
                (foe, min_t, fmax(HALF_MARGIN, 4.0 * min_t))
            }),
            tau_range: (
                if w < 0.0 { -1.0 / w } else { f32::INFINITY },
                if w > 0.0 { -1.0 / w } else { f32::NEG_INFINITY },
            ),
        }
    }

    /// The rotation `R` of the motion.
    pub(crate) fn rotation(&self) -> &crate::math::Mat3 {
        &self.r
    }

    /// `|T|`, the length of the translation.
    pub(crate) fn translation_norm(&self) -> f32 {
        let [tx, ty, tz] = self.tp;
        crate::math::sqrt(tx * tx + ty * ty + tz * tz)
    }

    /// Frame-2 intrinsics `(f_x, f_y, c_x, c_y)`.
    pub(crate) fn camera2_intrinsics(&self) -> (f32, f32, f32, f32) {
        self.k2
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

    /// [`PencilKey::Half`] for a frame-2 boundary whose rows run from
    /// `v_first` to `v_last` (boundaries are monotone in the row, so these
    /// bound all of it), when it lies wholly above or below the FOE's row
    /// with some margin; `None` otherwise (no FOE, or too close to it).
    pub fn half_key(&self, v_first: f32, v_last: f32) -> Option<PencilKey> {
        let (foe, min_t, need) = self.half?;
        let (lo, hi) = (fmin(v_first, v_last), fmax(v_first, v_last));
        let side = if lo - foe[1] >= need {
            1.0
        } else if foe[1] - hi >= need {
            -1.0
        } else {
            // Too close to the FOE's row, or NaN.
            return None;
        };
        Some(PencilKey::Half { foe, side, min_t })
    }

    /// Exact rotation compensation of a frame-1 pixel; `None` when the ray
    /// points behind the frame-2 camera orientation (`q_z ≤ 1e-6`).
    pub fn compensate(&self, p1: Pixel) -> Option<Compensated> {
        self.compensate_with(p1, None)
    }

    /// [`Self::compensate`] with the frame-wide stretch bound in place of
    /// the point's own (when there is one): what the processor uses.
    #[inline]
    pub(crate) fn compensate_in_frame(&self, p1: Pixel) -> Option<Compensated> {
        self.compensate_with(p1, self.frame_stretch())
    }

    /// [`Self::compensate`] with `stretch` as the stretch bound (the
    /// frame-wide one, [`Self::frame_stretch`]), or the point's own when
    /// `None`.
    #[inline(always)]
    pub(crate) fn compensate_with(&self, p1: Pixel, stretch: Option<f32>) -> Option<Compensated> {
        let [x, y, z] = mat3_vec(&self.h, [p1.u, p1.v, 1.0]);
        if z <= 1.0e-6 {
            return None;
        }
        let iz = 1.0 / z;
        let (px, py) = (x * iz, y * iz);
        let stretch = stretch.unwrap_or_else(|| {
            // Jacobian of (x/z, y/z) with respect to (u, v).
            let [[h00, h01, _], [h10, h11, _], [h20, h21, _]] = self.h;
            let j00 = (h00 - px * h20) * iz;
            let j01 = (h01 - px * h21) * iz;
            let j10 = (h10 - py * h20) * iz;
            let j11 = (h11 - py * h21) * iz;
            let n1 = fmax(j00.abs() + j10.abs(), j01.abs() + j11.abs());
            let ninf = fmax(j00.abs() + j01.abs(), j10.abs() + j11.abs());
            fmax(n1, ninf)
        });
        Some(Compensated {
            pixel: [px, py],
            depth_scale: z,
            stretch,
        })
    }

    /// The frame-wide stretch bound that [`Self::compensate_in_frame`]
    /// gives every point, if there is one.
    pub(crate) fn frame_stretch(&self) -> Option<f32> {
        self.stretch_bound.is_finite().then_some(self.stretch_bound)
    }

    /// The epipolar line of a compensated point (the vector `a`).
    pub fn line(&self, c: &Compensated) -> EpipolarLine {
        let a = [
            self.w * (c.pixel[0] - self.c2[0]) - self.g[0],
            self.w * (c.pixel[1] - self.c2[1]) - self.g[1],
        ];
        let (tau_max, ray_min) = self.tau_range;
        EpipolarLine {
            origin: c.pixel,
            a,
            a2: dot(a, a),
            tau_max,
            ray_min,
            ray_max: tau_max,
            key: NO_KEY,
        }
    }
}

/// An upper bound on the stretch of `h` (see [`Compensated::stretch`]) over
/// the image of `cam` with its margin, or infinity.
///
/// On the image rectangle `z = h₂₀u + h₂₁v + h₂₂` is linear and the
/// compensated coordinates `x/z`, `y/z` are linear-fractional, so with
/// `z > 0` all three take their extremes at the corners. Each entry of the
/// Jacobian, e.g. `(h₀₀ − p_x h₂₀)/z`, is then bounded by the larger of its
/// numerator's values at the extremes of `p_x` over the smallest `z`; the
/// 1- and ∞-norms of those bounds bound the stretch everywhere. It exceeds
/// the largest point's own value by under 1 % for rotations up to 1° about
/// each axis and under 5 % up to 5° (test `frame_stretch_bound_holds_and_is_tight`),
/// and saves the computation per point.
fn stretch_bound(h: &crate::math::Mat3, cam: &Camera) -> f32 {
    let m = crate::camera::IMAGE_MARGIN_PX;
    let (u1, v1) = (
        f32::from(cam.width()) - 1.0 + m,
        f32::from(cam.height()) - 1.0 + m,
    );
    let [[h00, h01, h02], [h10, h11, h12], [h20, h21, h22]] = *h;
    // A row of H at the corners: (h_0 u + h_1 v) + h_2, as `mat3_vec` sums.
    let row = |a: f32, b: f32, c: f32| {
        let (au0, au1, bv0, bv1) = (a * -m, a * u1, b * -m, b * v1);
        [au0 + bv0 + c, au1 + bv0 + c, au0 + bv1 + c, au1 + bv1 + c]
    };
    let (xs, ys, zs) = (row(h00, h01, h02), row(h10, h11, h12), row(h20, h21, h22));
    let [z0, z1, z2, z3] = zs;
    let zmin = fmin(fmin(z0, z1), fmin(z2, z3));
    // (A NaN corner gives a NaN bound below, which is refused too.)
    if zmin.is_nan() || zmin <= 1.0e-3 {
        return f32::INFINITY;
    }
    let extremes = |ps: [f32; 4]| {
        let [p0, p1, p2, p3] = ps;
        let (lo01, hi01) = if p0 < p1 { (p0, p1) } else { (p1, p0) };
        let (lo23, hi23) = if p2 < p3 { (p2, p3) } else { (p3, p2) };
        (fmin(lo01, lo23), fmax(hi01, hi23))
    };
    let (xmin, xmax) = extremes([xs[0] / z0, xs[1] / z1, xs[2] / z2, xs[3] / z3]);
    let (ymin, ymax) = extremes([ys[0] / z0, ys[1] / z1, ys[2] / z2, ys[3] / z3]);
    let bound =
        |c: f32, p0: f32, p1: f32, k: f32| fmax((c - p0 * k).abs(), (c - p1 * k).abs()) / zmin;
    let j00 = bound(h00, xmin, xmax, h20);
    let j01 = bound(h01, xmin, xmax, h21);
    let j10 = bound(h10, ymin, ymax, h20);
    let j11 = bound(h11, ymin, ymax, h21);
    let n1 = fmax(j00 + j10, j01 + j11);
    let ninf = fmax(j00 + j01, j10 + j11);
    // A relative 1e-5 covers the rounding of this computation.
    let b = fmax(n1, ninf) * (1.0 + 1.0e-5);
    if b.is_finite() {
        b
    } else {
        f32::INFINITY
    }
}

/// A strategy for finding every crossing of an epipolar line with a frame-2
/// boundary. [`IndexedSearch`] is the one the processor uses; tests plug in
/// a brute-force one and check both give identical results.
pub trait CrossingSearch {
    /// Called once for each frame-2 boundary before its lines are searched.
    fn prepare(&mut self, boundary: &[Pixel], key: &PencilKey);
    /// Call `visit` with every crossing of `line`'s ray with `boundary`
    /// (the one last prepared), each found by [`EpipolarLine::crossing`],
    /// until `visit` returns `false`. The order does not matter.
    fn search<F: FnMut(Crossing) -> bool>(
        &mut self,
        line: &EpipolarLine,
        boundary: &[Pixel],
        visit: F,
    );

    /// [`CrossingSearch::search`] into `out`, stopping when it is full.
    fn collect(&mut self, line: &EpipolarLine, boundary: &[Pixel], out: &mut Crossings) {
        self.search(line, boundary, |c| out.push(c).is_ok());
    }
}

/// Every crossing of `line` with `boundary`, segment by segment, until
/// `visit` returns `false`.
fn scan_all<F: FnMut(Crossing) -> bool>(line: &EpipolarLine, boundary: &[Pixel], mut visit: F) {
    for (j, w) in boundary.windows(2).enumerate() {
        if let [v0, v1] = w {
            if let Some(c) = line.crossing(j, *v0, *v1) {
                if !visit(c) {
                    return;
                }
            }
        }
    }
}

/// Unwraps a sequence of vertex keys along a boundary: pseudo-angles
/// (in `[0, 4)`) get the multiple of 4 that keeps consecutive keys less
/// than half a turn apart; projective keys pass unchanged. Unkeyable
/// vertices ([`NO_KEY`]) pass unchanged and break the sequence.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Unwrap {
    period: f32,
    offset: f32,
    prev: f32,
    prev_raw: f32,
    /// Raw steps below this take the short path (none once the offset is
    /// so large that its rounding could reach 1e-3).
    short_step: f32,
    /// Every key so far finite and no step half a turn (a segment through
    /// the FOE).
    all_keyed: bool,
}

impl Unwrap {
    /// Every key so far finite, and no segment through the FOE.
    pub(crate) fn all_keyed(&self) -> bool {
        self.all_keyed
    }

    pub(crate) fn new(key: &PencilKey) -> Self {
        Self {
            period: match key {
                PencilKey::Angular { .. } => 4.0,
                PencilKey::Half { .. } | PencilKey::Projective { .. } => 0.0,
            },
            offset: 0.0,
            prev: NO_KEY,
            prev_raw: NO_KEY,
            short_step: 1.998,
            all_keyed: true,
        }
    }

    /// The unwrapped key of the next vertex, whose raw key is `raw`.
    #[inline(always)]
    pub(crate) fn next(&mut self, raw: f32) -> f32 {
        // The usual step: both keys finite and less than 1.998 apart (NaN
        // and infinities fail the test), so no unwrapping, and the
        // unwrapped step (the same up to the rounding of `+ offset`, below
        // 2e-4 while |offset| < 1024) is not half a turn. The general code
        // below gives the same bits.
        if (raw - self.prev_raw).abs() < self.short_step {
            let k = raw + self.offset;
            self.prev = k;
            self.prev_raw = raw;
            return k;
        }
        self.step(raw)
    }

    fn step(&mut self, raw: f32) -> f32 {
        self.prev_raw = raw;
        let mut k = raw;
        if k.is_finite() {
            k += self.offset;
            if self.period > 0.0 && self.prev.is_finite() {
                // Raw keys are in [0, 4) and consecutive keys differ by
                // less than half a turn, so one correction of the running
                // offset (a multiple of 4) suffices.
                let d = k - self.prev;
                if d > 2.0 {
                    self.offset -= 4.0;
                    k -= 4.0;
                } else if d < -2.0 {
                    self.offset += 4.0;
                    k += 4.0;
                }
                if self.offset.abs() >= 1024.0 {
                    self.short_step = -1.0;
                }
                self.all_keyed &= ((k - self.prev).abs() - 2.0).abs() >= 1.0e-3;
            }
        } else {
            self.all_keyed = false;
        }
        self.prev = k;
        k
    }
}

/// Segments with an unkeyable end (at the FOE) an index keeps aside; with
/// more, every search scans the whole boundary.
const MAX_UNKEYED: usize = 4;
/// Linear probes before a search for the candidate run falls back to bisection.
const PROBES: usize = 8;

/// The sweep index of one boundary: the crossing search of the processor.
///
/// Every line through the FOE has a key (see the module docs); a segment
/// can only cross the line whose key lies between its end points' keys.
/// Along a road boundary the keys move mostly one way (oriented here so
/// that they increase), with quantisation jitter and, where the boundary
/// folds across the epipolar lines, reversals. The index keeps for every
/// segment `j` the running maximum `hi[j]` of the (oriented) keys from the
/// start and the running minimum `lo[j]` to the end. Both are
/// non-decreasing whatever the keys do, so the segments whose key range can
/// hold a key `q` lie in the one run `a ≤ j < b` with `hi[j] ≥ q` and
/// `lo[j] ≤ q`. The run is found by probing from where the previous search
/// found it (consecutive boundary points have nearby keys: `O(1)` per
/// point along a sweep), falling back to bisection (`O(log M)`).
/// Every candidate is confirmed by the exact side test of
/// [`EpipolarLine::crossing`], so the result is that of a brute-force
/// search; only the work depends on the shape: `O(M)` to build, and per
/// point `O(1)` plus the candidates, which are few unless the boundary runs
/// along the epipolar lines (grazing, degenerate) or folds across them
/// between two intersections.
///
/// Memory: `12 N` bytes plus a few words.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct IndexedSearch<const N: usize> {
    /// Unwrapped vertex keys ([`NO_KEY`] where unkeyable).
    keys: [f32; N],
    /// Per segment: running max of the oriented keys from the start.
    hi: [f32; N],
    /// Per segment: running min of the oriented keys to the end.
    lo: [f32; N],
    /// +1 if the keys increase along the boundary overall, −1 if not.
    orient: f32,
    /// Where the last search found its candidates.
    hint: usize,
    /// Segments touching an unkeyable vertex or passing through the FOE
    /// (always examined in the crossing search).
    unkeyed: heapless::Vec<usize, MAX_UNKEYED>,
    /// Too many unkeyed segments: every search scans the whole boundary.
    scan: bool,
    /// Built for the fold test with every segment keyed and the keys
    /// spanning less than a turn: `hi`/`lo` then hold the suffix maximum
    /// and minimum of the keys and [`Self::fold_each`] answers in `O(1)`.
    fold_fast: bool,
    /// Every vertex has a key and no segment passes through the FOE.
    all_keyed: bool,
    /// Built for the crossing search with every segment keyed and the
    /// widened keys spanning less than a turn: one key in `[0, 4)` has one
    /// representative to look for, `q + base` or `q + base + 4`
    /// ([`Self::single_key`]), and the search is one run.
    single: bool,
    /// A multiple of 4 with `base ≤ kmin − eps < base + 4`.
    base: f32,
    /// When ±1: `hi` already holds the prefix maximum of the keys oriented
    /// by this sign (written while the keys were made); 0 otherwise.
    prefix_orient: f32,
    segments: usize,
    /// Range of the unwrapped keys.
    kmin: f32,
    kmax: f32,
    /// Widening of key comparisons (covers rounding).
    eps: f32,
    /// 4 for pseudo-angles (keys repeat every turn), 0 for projective keys.
    period: f32,
    key: PencilKey,
}

impl<const N: usize> Default for IndexedSearch<N> {
    fn default() -> Self {
        Self::new()
    }
}

/// A [`IndexedSearch`] whose keys span less than a turn and whose segments
/// all have keys, borrowed for one boundary's matching pass: the crossing
/// search of [`IndexedSearch::search`] for that case, with the run located
/// and scanned in one place and the state in registers.
pub(crate) struct SingleRun<'a, const N: usize> {
    index: &'a IndexedSearch<N>,
    hi: &'a [f32],
    lo: &'a [f32],
    boundary: &'a [Pixel],
    /// Pseudo-angles over the whole turn (a usable raw key is in `[+0,
    /// 4)`; other keys are usable when finite).
    periodic: bool,
    orient: f32,
    eps: f32,
    /// The smallest usable unwrapped key, `kmin − eps` (pseudo-angles;
    /// −∞ for projective keys, which are not unwrapped).
    lim: f32,
    /// A usable raw key `q` stands for `q + base`, or `q + base4` when
    /// that is below `lim` ([`IndexedSearch::single_key`]).
    base: f32,
    base4: f32,
    hint: usize,
}

impl<'a, const N: usize> SingleRun<'a, N> {
    /// Whether the keys are pseudo-angles over the whole turn (see
    /// [`Self::search`]).
    pub(crate) fn periodic(&self) -> bool {
        self.periodic
    }

    /// The frame-2 boundary.
    pub(crate) fn boundary(&self) -> &'a [Pixel] {
        self.boundary
    }

    /// Every crossing of `line`'s ray, up to [`MAX_RAY_CROSSINGS`]` + 1`,
    /// by the general search of the index (for a line [`Self::search`]
    /// declined). The work is out of line (rare) and only copies go there
    /// (`line`, the hint), so that the caller keeps its line and this view
    /// in registers.
    #[inline(always)]
    pub(crate) fn collect_general(&mut self, line: EpipolarLine, out: &mut Crossings) {
        let mut hint = self.hint;
        collect_general(self.index, &mut hint, line, self.boundary, out);
        self.hint = hint;
    }

    /// Visit the crossings of `line`'s ray with the boundary, as
    /// [`IndexedSearch::search`] does (the same crossings, in increasing
    /// segment order), until `visit` returns `false`. Returns `false`
    /// without visiting anything when the line's key is not usable (the
    /// caller then uses [`Self::collect_general`]).
    ///
    /// `PERIODIC` must say whether the keys are pseudo-angles over the whole
    /// turn ([`Self::periodic`]); without it a key needs no turn chosen.
    /// `visit` gets each crossing and whether it lies in the search range
    /// ([`EpipolarLine::in_search_range`], for a line whose `ray_max` is its
    /// `tau_max`, as [`PairGeometry::line`] makes them).
    #[inline(always)]
    pub(crate) fn search<const PERIODIC: bool, F: FnMut(Crossing, bool) -> bool>(
        &mut self,
        line: &EpipolarLine,
        mut visit: F,
    ) -> bool {
        let q = line.key;
        let usable = if PERIODIC {
            q.to_bits() < 4.0f32.to_bits()
        } else {
            q.is_finite()
        };
        if !usable {
            return false;
        }
        let qq = if PERIODIC {
            let qq = q + self.base;
            if qq < self.lim {
                q + self.base4
            } else {
                qq
            }
        } else {
            q
        };
        let oq = self.orient * qq;
        let a = first_at_least(self.hi, oq - self.eps, self.hint);
        self.hint = a;
        let t_hi = oq + self.eps;
        // The candidates: from `a` while the suffix minimum allows, each
        // vertex's side computed once for the two segments that share it.
        let mut j = a;
        let Some(&first) = self.boundary.get(j) else {
            return true;
        };
        let (mut v0, mut s0) = (first, line.side(first));
        while let Some(&l) = self.lo.get(j) {
            if l > t_hi {
                break;
            }
            let Some(&v1) = self.boundary.get(j + 1) else {
                break;
            };
            let s1 = line.side(v1);
            if opposite_sides(s0, s1) {
                // On the ray: ray_min < τ < ray_max; in the search range
                // also τ > 0 (and τ < tau_max = ray_max).
                let tau = line.tau_between(v0, v1, s0, s1);
                let c = Crossing { segment: j, tau };
                // (A NaN τ fails both `>`: no crossing, as in `crossing`.)
                let more = if tau > 0.0 {
                    tau >= line.ray_max || visit(c, true)
                } else if tau > line.ray_min {
                    visit(c, false)
                } else {
                    true
                };
                if !more {
                    break;
                }
            }
            (v0, s0) = (v1, s1);
            j += 1;
        }
        true
    }
}

/// [`SingleRun::collect_general`], out of line.
#[inline(never)]
fn collect_general<const N: usize>(
    index: &IndexedSearch<N>,
    hint: &mut usize,
    line: EpipolarLine,
    boundary: &[Pixel],
    out: &mut Crossings,
) {
    index.search_at(hint, &line, boundary, |c| out.push(c).is_ok());
}

/// First index `j` in `[0, v.len())` with `v[j] ≥ t` in a non-decreasing
/// slice (or `v.len()`): linear probes from `hint`, then bisection.
#[inline(always)]
fn first_at_least(v: &[f32], t: f32, hint: usize) -> usize {
    let n = v.len();
    let at = |j: usize| v.get(j).copied().unwrap_or(f32::INFINITY);
    if n == 0 {
        return 0;
    }
    let mut j = if hint < n { hint } else { n - 1 };
    if at(j) >= t {
        for _ in 0..PROBES {
            if j == 0 || at(j - 1) < t {
                return j;
            }
            j -= 1;
        }
        bisect(v, 0, j, t)
    } else {
        for _ in 0..PROBES {
            j += 1;
            if j >= n || at(j) >= t {
                return j;
            }
        }
        bisect(v, j + 1, n, t)
    }
}

/// First index in `[lo, hi)` with `v[j] ≥ t` (non-decreasing `v`), or `hi`.
fn bisect(v: &[f32], mut lo: usize, mut hi: usize, t: f32) -> usize {
    while lo < hi {
        let m = lo + (hi - lo) / 2;
        if v.get(m).copied().unwrap_or(f32::INFINITY) >= t {
            hi = m;
        } else {
            lo = m + 1;
        }
    }
    hi
}

impl<const N: usize> IndexedSearch<N> {
    /// An empty index.
    pub const fn new() -> Self {
        Self {
            keys: [0.0; N],
            hi: [0.0; N],
            lo: [0.0; N],
            orient: 1.0,
            hint: 0,
            unkeyed: heapless::Vec::new(),
            scan: false,
            fold_fast: false,
            all_keyed: false,
            single: false,
            base: 0.0,
            prefix_orient: 0.0,
            segments: 0,
            kmin: 0.0,
            kmax: 0.0,
            eps: ANGULAR_EPS,
            period: 4.0,
            key: PencilKey::Angular {
                foe: [0.0, 0.0],
                sign_w: 1.0,
            },
        }
    }

    /// Whether segment `(k0, k1)` has usable keys and does not pass
    /// through the FOE (half a turn between its ends).
    #[inline(always)]
    fn keyed(&self, k0: f32, k1: f32) -> bool {
        k0.is_finite()
            && k1.is_finite()
            && !(self.period > 0.0 && ((k1 - k0).abs() - 2.0).abs() < 1.0e-3)
    }

    /// Build the index over the vertex keys `keys` (at most `N` are used).
    /// `unkeyed_meets_all`: whether a segment with an unkeyable end may meet
    /// every line (the crossing search) or none (the fold test, where such
    /// a vertex is at the FOE or behind the camera).
    fn build(&mut self, key: &PencilKey, unkeyed_meets_all: bool, keys: impl Iterator<Item = f32>) {
        let mut unwrap = Unwrap::new(key);
        let mut n: usize = 0;
        for (slot, raw) in self.keys.iter_mut().zip(keys) {
            *slot = unwrap.next(raw);
            n += 1;
        }
        self.index_keys(key, unkeyed_meets_all, n, unwrap.all_keyed());
    }

    /// The key array, for a caller that unwraps the keys itself (with an
    /// [`Unwrap`]) before [`Self::index_keys`].
    pub(crate) fn keys_mut(&mut self) -> &mut [f32; N] {
        &mut self.keys
    }

    /// Index the first `n` unwrapped keys already in the key array;
    /// `all_keyed` as the [`Unwrap`] that made them says.
    pub(crate) fn index_keys(
        &mut self,
        key: &PencilKey,
        unkeyed_meets_all: bool,
        n: usize,
        all_keyed: bool,
    ) {
        // Consumed here whatever path follows: a mark left by a build that
        // did not reach `envelopes` must not reach a later one.
        let prefix_orient = core::mem::replace(&mut self.prefix_orient, 0.0);
        self.key = *key;
        self.unkeyed.clear();
        self.scan = false;
        self.fold_fast = false;
        self.single = false;
        self.hint = 0;
        self.period = match key {
            PencilKey::Angular { .. } => 4.0,
            PencilKey::Half { .. } | PencilKey::Projective { .. } => 0.0,
        };
        let n = n.min(N);
        self.segments = n.saturating_sub(1);
        self.all_keyed = all_keyed;
        let keys = self.keys.get(..n).unwrap_or(&[]);
        // Orientation from the first and the last usable key.
        let (first, last) = if all_keyed {
            (keys.first(), keys.last())
        } else {
            (
                keys.iter().find(|k| k.is_finite()),
                keys.iter().rev().find(|k| k.is_finite()),
            )
        };
        let (first, last) = (
            first.copied().unwrap_or(NO_KEY),
            last.copied().unwrap_or(NO_KEY),
        );
        let o = if last >= first { 1.0 } else { -1.0 };
        self.orient = o;
        if !unkeyed_meets_all && all_keyed {
            // The fold test's fast form: suffix extremes of the keys
            // (whose first entries are the extremes of all keys).
            if let (Some(smax), Some(smin)) = (self.hi.get_mut(..n), self.lo.get_mut(..n)) {
                let (mut mx, mut mn) = (f32::NEG_INFINITY, f32::INFINITY);
                for ((&k, h), l) in keys.iter().zip(smax.iter_mut()).zip(smin.iter_mut()).rev() {
                    mx = fmax(mx, k);
                    mn = fmin(mn, k);
                    *h = mx;
                    *l = mn;
                }
                if self.period <= 0.0 || mx - mn < self.period - 0.1 {
                    self.set_range(mn, mx);
                    self.fold_fast = true;
                    return;
                }
            }
        }
        self.envelopes(unkeyed_meets_all, prefix_orient == o);
        let s = self.segments;
        let ends = (self.hi.get(s.wrapping_sub(1)), self.lo.first());
        match ends {
            (Some(&top), Some(&bottom))
                if unkeyed_meets_all && self.unkeyed.is_empty() && !self.scan =>
            {
                // Every vertex is on a keyed segment: the envelopes' ends
                // are the extremes of the (oriented) keys.
                if o > 0.0 {
                    self.set_range(bottom, top);
                } else {
                    self.set_range(-top, -bottom);
                }
                self.single = self.all_keyed && self.single_turn();
            }
            _ => {
                let (mut mn, mut mx) = (f32::INFINITY, f32::NEG_INFINITY);
                for &k in self.keys.get(..n).unwrap_or(&[]) {
                    if k.is_finite() {
                        mn = fmin(mn, k);
                        mx = fmax(mx, k);
                    }
                }
                self.set_range(mn, mx);
            }
        }
    }

    /// [`Self::index_keys`] for the crossing search over `n ≥ 2` half-plane
    /// keys, all usable, whose prefix maximum (oriented by `o`, which is
    /// what `index_keys` finds from the end keys) is already in `hi`: the
    /// same index, without the general case's branches.
    fn finish_half(&mut self, key: &PencilKey, n: usize, o: f32) {
        self.prefix_orient = 0.0;
        self.key = *key;
        self.unkeyed.clear();
        self.scan = false;
        self.fold_fast = false;
        self.hint = 0;
        self.period = 0.0;
        let n = n.min(N);
        // (The caller ensures n ≥ 2; anything less falls to the scan.)
        let s = n.saturating_sub(1);
        self.segments = s;
        self.all_keyed = true;
        self.orient = o;
        let (Some(keys), Some(lo), Some(&top)) = (
            self.keys.get(..n),
            self.lo.get_mut(..s),
            s.checked_sub(1).and_then(|i| self.hi.get(i)),
        ) else {
            self.scan = true;
            self.single = false;
            return;
        };
        let mut run = keys.last().map_or(f32::INFINITY, |&k| o * k);
        for (&k, l) in keys.iter().zip(lo.iter_mut()).rev() {
            run = fmin(run, o * k);
            *l = run;
        }
        let bottom = lo.first().copied().unwrap_or(run);
        if o > 0.0 {
            self.set_range(bottom, top);
        } else {
            self.set_range(-top, -bottom);
        }
        // Half-plane keys are not periodic: one run always.
        self.single = true;
    }

    /// The range of the unwrapped keys and the key margin that follows.
    fn set_range(&mut self, kmin: f32, kmax: f32) {
        self.kmin = kmin;
        self.kmax = kmax;
        self.eps = match self.key {
            PencilKey::Angular { .. } | PencilKey::Half { .. } => ANGULAR_EPS,
            PencilKey::Projective { .. } => PROJECTIVE_EPS + 1.0e-5 * fmax(kmin.abs(), kmax.abs()),
        };
    }

    /// Whether the widened key range spans less than a turn (always for
    /// projective keys), and if so `base` for [`Self::single_key`].
    fn single_turn(&mut self) -> bool {
        if self.period <= 0.0 {
            return true;
        }
        let (lo, hi) = (self.kmin - self.eps, self.kmax + self.eps);
        if !(hi - lo < self.period && lo.abs() < 1.0e6) {
            return false;
        }
        // |lo| < 1e6: the quotient and the multiple of 4 are exact enough
        // (the comparison in `single_key` decides, not this value).
        let m = ceil_i32(lo * 0.25) - 1;
        self.base = 4.0 * m as f32;
        if self.base > lo || self.base + 4.0 <= lo {
            // Rounding put lo outside [base, base + 4): no shortcut.
            return false;
        }
        true
    }

    /// For a [`Self::single`] index: the one unwrapped key equal to `q`
    /// modulo the period that can lie in the widened key range (the
    /// smallest one `≥ kmin − eps`), for `q` in `[+0, 4)`; `None` otherwise.
    #[inline(always)]
    fn single_key(&self, q: f32) -> Option<f32> {
        if self.period <= 0.0 {
            return q.is_finite().then_some(q);
        }
        // q in [+0, 4) (not NaN, not −0): as bits, a u32 below that of 4
        // (the order of non-negative floats is that of their bits).
        if q.to_bits() >= 4.0f32.to_bits() {
            return None;
        }
        let qq = q + self.base;
        Some(if qq < self.kmin - self.eps {
            q + (self.base + 4.0)
        } else {
            qq
        })
    }

    /// The one-run view of a [`Self::single`] index built for `boundary`
    /// (`None` for any other index): what the processor's lean matching
    /// pass needs, borrowed once per boundary.
    #[inline(always)]
    pub(crate) fn single_run<'a>(&'a self, boundary: &'a [Pixel]) -> Option<SingleRun<'a, N>> {
        let s = self.segments;
        if !self.single || boundary.len() != s + 1 {
            return None;
        }
        let angular = self.period > 0.0;
        Some(SingleRun {
            index: self,
            hi: self.hi.get(..s)?,
            lo: self.lo.get(..s)?,
            boundary,
            periodic: angular,
            orient: self.orient,
            eps: self.eps,
            lim: if angular {
                self.kmin - self.eps
            } else {
                f32::NEG_INFINITY
            },
            base: if angular { self.base } else { 0.0 },
            base4: self.base + 4.0,
            hint: self.hint,
        })
    }

    /// Visit the crossings on the candidate run of the unwrapped key `qq`
    /// for an index whose segments are all keyed; `false` when `visit`
    /// stopped the search.
    ///
    /// The run `[a, b)` holds hardly any segment besides those whose own
    /// keys bracket the line's (the key test rejects about 1 in 500 on the
    /// bench), so the exact side test is tried on all of it.
    #[inline(always)]
    fn keyed_run<F: FnMut(Crossing) -> bool>(
        &self,
        hint: &mut usize,
        qq: f32,
        line: &EpipolarLine,
        boundary: &[Pixel],
        visit: &mut F,
    ) -> bool {
        let s = self.segments;
        let (Some(hi), Some(lo)) = (self.hi.get(..s), self.lo.get(..s)) else {
            return true;
        };
        let oq = self.orient * qq;
        let a = first_at_least(hi, oq - self.eps, *hint);
        *hint = a;
        let t_hi = oq + self.eps;
        let (Some(run), Some(pts)) = (lo.get(a..), boundary.get(a..)) else {
            return true;
        };
        for ((&l, w), j) in run.iter().zip(pts.windows(2)).zip(a..) {
            if l > t_hi {
                break;
            }
            if let [v0, v1] = *w {
                if let Some(c) = line.crossing(j, v0, v1) {
                    if !visit(c) {
                        return false;
                    }
                }
            }
        }
        true
    }

    /// The running envelopes `hi`, `lo` of the oriented keys (and the list
    /// of unkeyed segments) for the general search.
    /// `prefix_ready`: `hi` already holds the prefix maximum (of the keys
    /// oriented as `orient`).
    fn envelopes(&mut self, unkeyed_meets_all: bool, prefix_ready: bool) {
        let (s, o, period) = (self.segments, self.orient, self.period);
        let (Some(keys), Some(hi), Some(lo)) = (
            self.keys.get(..s + 1),
            self.hi.get_mut(..s),
            self.lo.get_mut(..s),
        ) else {
            self.scan = true;
            return;
        };
        if self.all_keyed {
            // Every segment counts: prefix maximum and suffix minimum of
            // the oriented vertex keys.
            if !prefix_ready {
                let mut run = keys.first().map_or(f32::NEG_INFINITY, |&k| o * k);
                for (&k, h) in keys.iter().skip(1).zip(hi.iter_mut()) {
                    run = fmax(run, o * k);
                    *h = run;
                }
            }
            let mut run = keys.last().map_or(f32::INFINITY, |&k| o * k);
            for (&k, l) in keys.iter().zip(lo.iter_mut()).rev() {
                run = fmin(run, o * k);
                *l = run;
            }
            return;
        }
        let keyed = |k0: f32, k1: f32| {
            k0.is_finite()
                && k1.is_finite()
                && !(period > 0.0 && ((k1 - k0).abs() - 2.0).abs() < 1.0e-3)
        };
        // Running maximum over the vertices of keyed segments: a segment's
        // first vertex is already in when the one before was keyed.
        let mut run = f32::NEG_INFINITY;
        let mut joined = false;
        for (j, (w, h)) in keys.windows(2).zip(hi.iter_mut()).enumerate() {
            if let [k0, k1] = *w {
                if keyed(k0, k1) {
                    if !joined {
                        run = fmax(run, o * k0);
                    }
                    run = fmax(run, o * k1);
                    joined = true;
                } else {
                    joined = false;
                    if unkeyed_meets_all && self.unkeyed.push(j).is_err() {
                        self.scan = true;
                    }
                }
            }
            *h = run;
        }
        let mut run = f32::INFINITY;
        let mut joined = false;
        for (w, l) in keys.windows(2).rev().zip(lo.iter_mut().rev()) {
            if let [k0, k1] = *w {
                if keyed(k0, k1) {
                    if !joined {
                        run = fmin(run, o * k1);
                    }
                    run = fmin(run, o * k0);
                    joined = true;
                } else {
                    joined = false;
                }
            }
            *l = run;
        }
    }

    /// The run of candidate segments `[a, b)` for the (unwrapped) key `qq`.
    #[inline]
    fn run_for(&mut self, qq: f32) -> (usize, usize) {
        let s = self.segments;
        let (Some(hi), Some(lo)) = (self.hi.get(..s), self.lo.get(..s)) else {
            return (0, 0);
        };
        let oq = self.orient * qq;
        let (t_lo, t_hi) = (oq - self.eps, oq + self.eps);
        match (hi.last(), lo.first()) {
            (Some(&top), Some(&bottom)) if top >= t_lo && bottom <= t_hi => {}
            _ => return (0, 0),
        }
        let a = first_at_least(hi, t_lo, self.hint);
        self.hint = a;
        // lo[j] > t_hi for the first time at b (usually a step or two on).
        let rest = lo.get(a..).unwrap_or(&[]);
        let mut b = rest.len();
        for (i, &l) in rest.iter().take(PROBES).enumerate() {
            if l > t_hi {
                b = i;
                break;
            }
        }
        if b == rest.len() && rest.len() > PROBES {
            // Bisection for "l > t_hi" = "l ≥ next float after t_hi".
            b = bisect(rest, PROBES, rest.len(), next_up(t_hi));
        }
        (a, a + b)
    }

    /// The first unwrapped key equal to `q` modulo the period that can
    /// occur, and how many (one period apart) follow it; `None` when the
    /// boundary winds round the FOE more than once (scan it all).
    #[inline]
    fn turns(&self, q: f32) -> Option<(f32, u32)> {
        let p = self.period;
        let (lo, hi) = (self.kmin - self.eps, self.kmax + self.eps);
        if p <= 0.0 {
            return Some((q, u32::from(lo <= q && q <= hi)));
        }
        if hi - lo >= 2.0 * p {
            return None;
        }
        // Smallest q + 4m ≥ lo (the division by 4 is exact).
        let first = q + p * ceil_i32((lo - q) * 0.25) as f32;
        let count = if first > hi {
            0
        } else if first + p > hi {
            1
        } else {
            2
        };
        Some((first, count))
    }

    /// The candidate segments for the key `q`, with the visiting order.
    #[inline]
    fn candidates(
        &self,
        j0: usize,
        j1: usize,
        qq: f32,
        mut visit: impl FnMut(usize) -> bool,
    ) -> bool {
        let eps = self.eps;
        let Some(keys) = self.keys.get(j0..(j1 + 1).min(self.segments + 1)) else {
            return true;
        };
        for (i, w) in keys.windows(2).enumerate() {
            if let [k0, k1] = *w {
                let (mn, mx) = if k0 <= k1 { (k0, k1) } else { (k1, k0) };
                if mn - eps <= qq && qq <= mx + eps && self.keyed(k0, k1) && !visit(j0 + i) {
                    return false;
                }
            }
        }
        true
    }

    #[cfg(test)]
    /// Index the rotation-compensated frame-1 boundary (for the fold test)
    /// from the keys of its compensated points.
    pub(crate) fn prepare_keys(&mut self, key: &PencilKey, keys: impl Iterator<Item = f32>) {
        self.build(key, false, keys);
    }

    /// Whether [`Self::fold_each`] applies (built by [`Self::prepare_keys`]
    /// with every segment keyed and less than a turn of keys).
    pub(crate) fn fold_fast(&self) -> bool {
        self.fold_fast
    }

    /// The fold test of every vertex in `O(1)` each (when
    /// [`Self::fold_fast`]): calls `folded(i)` for each vertex `i` that
    /// [`Self::meets_outside`] would find met by its own key outside the
    /// segments `i−4 ..= i+3`. The segments `j ≤ i−5` form a connected
    /// path over the vertices `0..=i−4`, so the union of their widened key
    /// ranges is the one interval `[min − ε, max + ε]` of those keys (a
    /// running prefix); the same holds for the segments `j ≥ i+4` and the
    /// suffix extremes from vertex `i+4`, which the build kept.
    pub(crate) fn fold_each(&self, folded: impl FnMut(usize)) {
        if self.orient > 0.0 {
            self.fold_each_in::<true>(folded);
        } else {
            self.fold_each_in::<false>(folded);
        }
    }

    /// [`Self::fold_each`] for keys that rise (`RISING`) or fall overall:
    /// the same two comparisons for each range, the one that usually
    /// fails first (the prefix lies behind the key, the suffix ahead).
    #[inline(always)]
    // The branches differ in the order of the two comparisons, which is
    // the point (clippy sees them as the same).
    #[allow(clippy::if_same_then_else)]
    fn fold_each_in<const RISING: bool>(&self, mut folded: impl FnMut(usize)) {
        let n = self.segments + 1;
        let (Some(keys), Some(smin), Some(smax)) =
            (self.keys.get(..n), self.lo.get(..n), self.hi.get(..n))
        else {
            return;
        };
        let eps = self.eps;
        let within = |lo: f32, hi: f32, k: f32| {
            if RISING {
                k <= hi + eps && lo - eps <= k
            } else {
                lo - eps <= k && k <= hi + eps
            }
        };
        let ahead = |lo: f32, hi: f32, k: f32| {
            if RISING {
                lo - eps <= k && k <= hi + eps
            } else {
                k <= hi + eps && lo - eps <= k
            }
        };
        // Vertex i − 4 (from i = 4 on) and the suffix extremes from vertex
        // i + 4 (while i + 5 < n), walked along with i: no indexing.
        let mut lagged = keys.iter();
        let last = n.saturating_sub(1);
        let mut suffix = smin
            .get(4..last)
            .unwrap_or(&[])
            .iter()
            .zip(smax.get(4..last).unwrap_or(&[]));
        let (mut pmin, mut pmax) = (f32::INFINITY, f32::NEG_INFINITY);
        // Vertices 0 ..= 4: no segment behind them yet (vertex 4 starts
        // the prefix with vertex 0).
        for (i, &k) in keys.iter().enumerate().take(5) {
            if i == 4 {
                if let Some(&v) = lagged.next() {
                    pmin = fmin(pmin, v);
                    pmax = fmax(pmax, v);
                }
            }
            if let Some((&mn, &mx)) = suffix.next() {
                if ahead(mn, mx, k) {
                    folded(i);
                }
            }
        }
        for ((i, &k), &v) in keys.iter().enumerate().skip(5).zip(lagged) {
            pmin = fmin(pmin, v);
            pmax = fmax(pmax, v);
            let mut met = within(pmin, pmax, k);
            if let Some((&mn, &mx)) = suffix.next() {
                met = met || ahead(mn, mx, k);
            }
            if met {
                folded(i);
            }
        }
    }

    /// Whether the indexed polyline meets the line with key `q` at a segment
    /// outside `skip` (inclusive segment range). Unkeyable lines answer yes.
    pub(crate) fn meets_outside(&mut self, q: f32, skip: (usize, usize)) -> bool {
        if self.segments == 0 {
            return false;
        }
        if !q.is_finite() {
            return true;
        }
        let Some((first, count)) = self.turns(q) else {
            return self.segments > skip.1.saturating_sub(skip.0) + 1;
        };
        let mut qq = first;
        for _ in 0..count {
            let (a, b) = self.run_for(qq);
            // Only the candidates outside the skipped window matter.
            let (l0, l1) = (a, b.min(skip.0));
            let (r0, r1) = (a.max(skip.1.saturating_add(1)), b);
            let met = |_| false;
            if (l0 < l1 && !self.candidates(l0, l1, qq, met))
                || (r0 < r1 && !self.candidates(r0, r1, qq, met))
            {
                return true;
            }
            qq += self.period;
        }
        false
    }
}

impl<const N: usize> IndexedSearch<N> {
    /// [`CrossingSearch::prepare`] given the keys of the boundary's first
    /// and last vertices (`key.vertex_key` of each), which the caller may
    /// already have.
    pub(crate) fn prepare_with_ends(
        &mut self,
        boundary: &[Pixel],
        key: &PencilKey,
        (k_first, k_last): (f32, f32),
    ) {
        match *key {
            // Half-plane keys never wrap: no unwrapping.
            PencilKey::Half { foe, side, min_t } => {
                // The orientation `index_keys` will find (from the first and
                // the last key, when all are usable), known in advance: the
                // prefix maximum `hi` is made with the keys.
                let o = if k_last >= k_first { 1.0 } else { -1.0 };
                let (Some(k0), Some(first)) = (self.keys.first_mut(), boundary.first()) else {
                    self.index_keys(key, true, 0, true);
                    return;
                };
                *k0 = half_key(foe, side, min_t, first.arr());
                let (mut sum, mut run) = (*k0, o * *k0);
                let mut n = 1;
                let rest = self.keys.iter_mut().skip(1).zip(self.hi.iter_mut());
                for ((slot, h), p) in rest.zip(boundary.iter().skip(1)) {
                    let k = half_key(foe, side, min_t, p.arr());
                    *slot = k;
                    sum += k;
                    run = fmax(run, o * k);
                    *h = run;
                    n += 1;
                }
                if sum.is_finite() && n >= 2 {
                    self.finish_half(key, n, o);
                } else {
                    self.prefix_orient = o;
                    self.index_keys(key, true, n, sum.is_finite());
                }
            }
            _ => self.build(key, true, boundary.iter().map(|p| key.vertex(p.arr()))),
        }
    }
}

impl<const N: usize> CrossingSearch for IndexedSearch<N> {
    fn prepare(&mut self, boundary: &[Pixel], key: &PencilKey) {
        let key_of = |p: Option<&Pixel>| p.map_or(NO_KEY, |p| key.vertex(p.arr()));
        let ends = (key_of(boundary.first()), key_of(boundary.last()));
        self.prepare_with_ends(boundary, key, ends);
    }

    /// The sweep of [`IndexedSearch`] written out for the crossing search:
    /// the run start from the hint (probes, then bisection), then the
    /// candidates while the suffix minimum `lo` allows, each confirmed by
    /// the exact side test.
    fn search<F: FnMut(Crossing) -> bool>(
        &mut self,
        line: &EpipolarLine,
        boundary: &[Pixel],
        visit: F,
    ) {
        let mut hint = self.hint;
        self.search_at(&mut hint, line, boundary, visit);
        self.hint = hint;
    }
}

impl<const N: usize> IndexedSearch<N> {
    /// [`CrossingSearch::search`] from the run start `hint` (updated).
    fn search_at<F: FnMut(Crossing) -> bool>(
        &self,
        hint: &mut usize,
        line: &EpipolarLine,
        boundary: &[Pixel],
        mut visit: F,
    ) {
        let s = self.segments;
        if self.single && boundary.len() == s + 1 {
            if let Some(qq) = self.single_key(line.key) {
                self.keyed_run(hint, qq, line, boundary, &mut visit);
                return;
            }
        }
        let q = if line.key.is_finite() {
            line.key
        } else {
            self.key.line(line)
        };
        let turns = if boundary.len() != s + 1 || self.scan || !q.is_finite() {
            // Not the boundary this index was prepared for, or no key.
            None
        } else {
            self.turns(q)
        };
        let Some((first, count)) = turns else {
            scan_all(line, boundary, visit);
            return;
        };
        for &j in self.unkeyed.iter() {
            if let (Some(v0), Some(v1)) = (boundary.get(j), boundary.get(j + 1)) {
                if let Some(c) = line.crossing(j, *v0, *v1) {
                    if !visit(c) {
                        return;
                    }
                }
            }
        }
        let mut qq = first;
        for _ in 0..count {
            if self.all_keyed {
                if !self.keyed_run(hint, qq, line, boundary, &mut visit) {
                    return;
                }
                qq += self.period;
                continue;
            }
            let (o, eps) = (self.orient, self.eps);
            let (Some(keys), Some(hi), Some(lo)) =
                (self.keys.get(..s + 1), self.hi.get(..s), self.lo.get(..s))
            else {
                return;
            };
            let oq = o * qq;
            let a = first_at_least(hi, oq - eps, *hint);
            *hint = a;
            let t_hi = oq + eps;
            // Bounded by the slice `lo` (one entry per segment).
            let mut j = a;
            while let (Some(&l), Some(&k0), Some(&k1)) = (lo.get(j), keys.get(j), keys.get(j + 1)) {
                if l > t_hi {
                    break;
                }
                // Unkeyed segments were examined above.
                let (mn, mx) = if k0 <= k1 { (k0, k1) } else { (k1, k0) };
                if mn - eps <= qq && qq <= mx + eps && self.keyed(k0, k1) {
                    if let (Some(&v0), Some(&v1)) = (boundary.get(j), boundary.get(j + 1)) {
                        if let Some(c) = line.crossing(j, v0, v1) {
                            if !visit(c) {
                                return;
                            }
                        }
                    }
                }
                j += 1;
            }
            qq += self.period;
        }
    }
}

#[cfg(test)]
impl<const N: usize> IndexedSearch<N> {
    /// For tests of other fold-test implementations: the general index
    /// query ([`Self::meets_outside`] over envelopes, never the fast form)
    /// for every point of the unwrapped, all usable `keys`, into `out`.
    pub(crate) fn general_fold_flags(key: &PencilKey, keys: &[f32], out: &mut [bool]) {
        let mut ix = Self::new();
        let n = keys.len().min(N);
        ix.keys[..n].copy_from_slice(&keys[..n]);
        ix.index_keys(key, false, n, true);
        ix.fold_fast = false;
        ix.envelopes(false, false);
        for (i, o) in out.iter_mut().enumerate().take(n) {
            *o = ix.meets_outside(keys[i], (i.saturating_sub(4), i + 3));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;

    /// The `O(1)` fold test answers exactly as the general index query, on
    /// key sequences that jitter (steps around the key margin), fold back,
    /// wrap round at 4, for both kinds of key.
    #[test]
    fn fast_fold_test_equals_the_general_query() {
        const M: usize = 64;
        let mut rng = Rng(0x9e37_79b9);
        let (mut fast_cases, mut folds) = (0, 0);
        for case in 0..4000 {
            let projective = case % 3 == 0;
            let key = if projective {
                PencilKey::Projective {
                    c: [0.0, 0.0],
                    g_hat: [1.0, 0.0],
                    g_norm: 1.0,
                    w: 0.0,
                }
            } else {
                PencilKey::Angular {
                    foe: [0.0, 0.0],
                    sign_w: 1.0,
                }
            };
            let n = 2 + (rng.next() * (M - 2) as f32) as usize;
            let scale = [3.0e-5, 1.0e-4, 1.0e-3, 0.05][case % 4];
            let drift = (rng.next() - 0.5) * scale;
            let mut keys = [0.0f32; M];
            let mut k = rng.next() * 4.0;
            for slot in keys.iter_mut().take(n) {
                *slot = if projective {
                    k * 100.0
                } else {
                    k.rem_euclid(4.0)
                };
                // Drift plus jitter; now and then a turn back.
                let back = if rng.next() < 0.03 {
                    -30.0 * drift
                } else {
                    0.0
                };
                k += drift + (rng.next() - 0.5) * scale + back;
            }
            let mut fast = IndexedSearch::<M>::new();
            fast.prepare_keys(&key, keys.iter().take(n).copied());
            if !fast.fold_fast() {
                continue;
            }
            fast_cases += 1;
            let mut slow = fast.clone();
            slow.fold_fast = false;
            slow.envelopes(false, false);
            let mut got = [false; M];
            fast.fold_each(|i| got[i] = true);
            for (i, &g) in got.iter().enumerate().take(n) {
                let want = slow.meets_outside(fast.keys[i], (i.saturating_sub(4), i + 3));
                assert_eq!(g, want, "case {case}, vertex {i} of {n}");
                folds += usize::from(g);
            }
        }
        assert!(fast_cases > 3000 && folds > 1000, "{fast_cases} {folds}");
    }

    /// A vertex on the line counts as on the positive side, also when its
    /// σ comes out as −0: of the two segments through it, exactly the one
    /// from the negative side reports the crossing.
    #[test]
    fn vertex_on_the_line_is_on_the_positive_side() {
        // a = (−1, 0): σ of the vertex (5, 0) is (−1)(0) − (0)(5) = −0.
        let line = EpipolarLine {
            origin: [0.0, 0.0],
            a: [-1.0, 0.0],
            a2: 1.0,
            tau_max: f32::INFINITY,
            ray_min: f32::NEG_INFINITY,
            ray_max: f32::INFINITY,
            key: NO_KEY,
        };
        let on = Pixel::new(5.0, 0.0);
        let sigma = cross(line.a, sub(on.arr(), line.origin));
        assert!(sigma == 0.0 && sigma.is_sign_negative());
        let (neg, pos) = (Pixel::new(5.0, 1.0), Pixel::new(5.0, -1.0));
        let into = line.crossing(0, neg, on).expect("from the negative side");
        assert_eq!(into.tau, -5.0);
        assert_eq!(line.crossing(1, on, pos), None);
        assert_eq!(line.crossing(2, pos, on), None);
        assert!(line.crossing(3, on, neg).is_some());
    }

    /// The one-compare side test gives the sign-bit rule's answer for
    /// every pair of special and ordinary values.
    #[test]
    fn opposite_sides_is_the_sign_bit_rule() {
        let values = [
            0.0f32,
            -0.0,
            f32::from_bits(1),
            -f32::from_bits(1),
            1.0e-30,
            -1.0e-30,
            1.0e-20,
            -1.0e-20,
            0.5,
            -0.5,
            3.0e20,
            -3.0e20,
            f32::MAX,
            -f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
        ];
        for &a in &values {
            for &b in &values {
                assert_eq!(opposite_sides(a, b), side_bit(a) != side_bit(b), "{a} {b}");
            }
        }
    }

    /// The index finds exactly the crossings a scan of every segment finds,
    /// on random polylines about the FOE (arcs that wrap past the cut of
    /// the pseudo-angle, zigzags, boundaries through the FOE) and for both
    /// kinds of key and both signs of `W'`; both the one-run path and the
    /// general path are exercised.
    #[test]
    fn index_finds_what_a_scan_finds() {
        const M: usize = 48;
        let mut rng = Rng(0x0bad_cafe);
        let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).expect("camera");
        let (mut single, mut general, mut found) = (0, 0, 0);
        for case in 0..3000 {
            // W' > 0, W' < 0, and a sideways motion (projective keys).
            let t = match case % 3 {
                0 => [0.1 * (rng.next() - 0.5), 0.05 * (rng.next() - 0.5), 1.0],
                1 => [0.1 * (rng.next() - 0.5), 0.05 * (rng.next() - 0.5), -1.0],
                _ => [1.0, 0.2 * (rng.next() - 0.5), 0.05 * (rng.next() - 0.5)],
            };
            let m = Motion::new(t, [0.0; 3]).expect("motion");
            let g = PairGeometry::new(&cam, &cam, &m);
            let centre = g
                .focus_of_expansion()
                .map_or([255.5, 239.5], |f| [f.u, f.v]);
            let n = 2 + (rng.next() * (M - 2) as f32) as usize;
            let r0 = 20.0 + 200.0 * rng.next();
            let a0 = 6.3 * rng.next();
            let sweep = (rng.next() - 0.3) * 14.0;
            let wobble = [0.0, 2.0, 40.0][case % 5 % 3];
            let mut pts = [Pixel::new(0.0, 0.0); M];
            for (i, p) in pts.iter_mut().enumerate().take(n) {
                let a = a0 + sweep * i as f32 / n as f32;
                let r = r0 + wobble * (rng.next() - 0.5) + 3.0 * i as f32;
                *p = Pixel::new(centre[0] + r * libm::cosf(a), centre[1] + r * libm::sinf(a));
            }
            if case % 17 == 0 {
                pts[n / 2] = Pixel::new(centre[0], centre[1]);
            }
            let boundary = &pts[..n];
            let mut index = IndexedSearch::<M>::new();
            index.prepare(boundary, g.key());
            if index.single {
                single += 1;
            } else {
                general += 1;
            }
            for _ in 0..20 {
                let p = Pixel::new(512.0 * rng.next(), 480.0 * rng.next());
                let Some(c) = g.compensate(p) else { continue };
                let mut line = g.line(&c);
                if line.a2 <= 1.0e-6 {
                    continue;
                }
                if rng.next() < 0.5 {
                    line.key = g.key().vertex_key(c.pixel);
                }
                let mut got = heapless::Vec::<Crossing, M>::new();
                let mut want = heapless::Vec::<Crossing, M>::new();
                index.search(&line, boundary, |x| got.push(x).is_ok());
                scan_all(&line, boundary, |x| want.push(x).is_ok());
                got.sort_unstable_by_key(|x| x.segment);
                assert_eq!(got, want, "case {case}");
                found += got.len();
            }
        }
        assert!(
            single > 1000 && general > 300 && found > 10_000,
            "{single} {general} {found}"
        );
    }

    /// With half-plane keys the index finds exactly the crossings a scan of
    /// every segment finds: random motions whose FOE lies above or below
    /// the boundary (in the image or far outside it, `W' > 0` and `< 0`),
    /// boundaries monotone in the row that zigzag sideways, run steeply or
    /// nearly along the rows, and lines from anywhere in the image,
    /// including points too close to the FOE's row to have a key (the
    /// general search takes those). Both the one-run path and the fallback
    /// are exercised.
    #[test]
    fn half_key_index_finds_what_a_scan_finds() {
        const M: usize = 48;
        let mut rng = Rng(0x4a1f_2b3c);
        let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).expect("camera");
        let (mut keyed, mut unkeyed, mut found, mut boundaries) = (0, 0, 0, 0);
        for case in 0..3000 {
            let w = if case % 4 == 3 { -1.0 } else { 1.0 };
            // FOE rows from well above the image to well below it.
            let t = [0.6 * (rng.next() - 0.5), 0.9 * (rng.next() - 0.5) * 2.0, w];
            let m = Motion::new(t, [0.0; 3]).expect("motion");
            let g = PairGeometry::new(&cam, &cam, &m);
            let Some(foe) = g.focus_of_expansion() else {
                continue;
            };
            let n = 2 + (rng.next() * (M - 2) as f32) as usize;
            // A run of rows on one side of the FOE, in the image.
            let below = rng.next() < 0.5;
            let (v0, v1) = if below {
                (fmax(foe.v + 20.0, -1.0), 480.0)
            } else {
                (-1.0, fmin(foe.v - 20.0, 480.0))
            };
            if v1 - v0 < n as f32 * 0.01 {
                continue;
            }
            let u0 = 512.0 * rng.next();
            let slope = 4.0 * (rng.next() - 0.5) * [0.1, 1.0, 20.0][case % 3];
            let zig = [0.0, 1.0, 30.0][case % 5 % 3];
            let mut pts = [Pixel::new(0.0, 0.0); M];
            for (i, p) in pts.iter_mut().enumerate().take(n) {
                let v = v0 + (v1 - v0) * (i as f32 + 0.5) / n as f32;
                let u = u0 + slope * (v - v0) + zig * (rng.next() - 0.5);
                *p = Pixel::new(u.clamp(-1.0, 512.0), v);
            }
            let boundary = &pts[..n];
            let Some(key) = g.half_key(boundary[0].v, boundary[n - 1].v) else {
                continue;
            };
            boundaries += 1;
            let mut index = IndexedSearch::<M>::new();
            index.prepare(boundary, &key);
            assert!(index.single, "case {case}: a half-plane index is one run");
            for _ in 0..20 {
                let p = Pixel::new(512.0 * rng.next(), 480.0 * rng.next());
                let Some(c) = g.compensate(p) else { continue };
                let mut line = g.line(&c);
                if line.a2 <= 1.0e-6 {
                    continue;
                }
                line.key = key.vertex_key(c.pixel);
                if line.key.is_finite() {
                    keyed += 1;
                } else {
                    unkeyed += 1;
                }
                let mut got = heapless::Vec::<Crossing, M>::new();
                let mut want = heapless::Vec::<Crossing, M>::new();
                if let Some(mut run) = index.single_run(boundary) {
                    if !run.search::<false, _>(&line, |x, _| got.push(x).is_ok()) {
                        let mut c = Crossings::new();
                        run.collect_general(line, &mut c);
                        got.extend(c.iter().copied());
                    }
                }
                scan_all(&line, boundary, |x| want.push(x).is_ok());
                got.sort_unstable_by_key(|x| x.segment);
                assert_eq!(got, want, "case {case}");
                found += got.len();
            }
        }
        assert!(
            boundaries > 1500 && keyed > 20_000 && unkeyed > 1_000 && found > 10_000,
            "{boundaries} {keyed} {unkeyed} {found}"
        );
    }

    /// The frame-wide stretch bound is never below a point's own stretch,
    /// anywhere in the image with its margin, and exceeds the largest one
    /// by at most 1 % for rotations up to 1° about each axis (measured:
    /// 0.8 %) and 5 % up to 5° (4.1 %).
    #[test]
    fn frame_stretch_bound_holds_and_is_tight() {
        let mut rng = Rng(0x1234_5678);
        let (mut worst1, mut worst5) = (0.0f32, 0.0f32);
        for case in 0..400 {
            let cam = Camera::new(
                600.0 + 400.0 * rng.next(),
                600.0 + 400.0 * rng.next(),
                200.0 + 100.0 * rng.next(),
                200.0 + 80.0 * rng.next(),
                512,
                480,
            )
            .expect("camera");
            let deg = if case % 2 == 0 { 5.0f32 } else { 1.0 };
            let a = [0.0; 3].map(|_: f32| (rng.next() - 0.5) * 2.0 * deg.to_radians());
            let m = Motion::new([0.1, 0.0, 1.0], a).expect("motion");
            let g = PairGeometry::new(&cam, &cam, &m);
            assert!(g.stretch_bound.is_finite(), "case {case}");
            let mut largest = 0.0f32;
            for i in 0..=32 {
                for j in 0..=32 {
                    let p = Pixel::new(
                        -1.0 + 512.0 * i as f32 / 32.0,
                        -1.0 + 480.0 * j as f32 / 32.0,
                    );
                    let c = g.compensate(p).expect("in front");
                    assert!(
                        c.stretch <= g.stretch_bound,
                        "case {case}: {} > {}",
                        c.stretch,
                        g.stretch_bound
                    );
                    largest = fmax(largest, c.stretch);
                    let f = g.compensate_in_frame(p).expect("in front");
                    assert_eq!((f.pixel, f.depth_scale), (c.pixel, c.depth_scale));
                }
            }

            let ratio = g.stretch_bound / largest;
            let worst = if case % 2 == 0 {
                &mut worst5
            } else {
                &mut worst1
            };
            *worst = fmax(*worst, ratio);
        }
        assert!(worst1 <= 1.01 && worst5 <= 1.05, "{worst1} {worst5}");
    }
}
