//! Where the localisation errors can put a point's true correspondent (its
//! *error band*), the depth that a frame-2 crossing gives (eq. 2.3) and the
//! interval of depths the band allows (the "stick" of Sec. 4.1, made a
//! guaranteed bound).
//!
//! # Depth from the disparity (eq. 2.3, general `(U, V, W)`)
//! With the notation of [`crate::epipolar`], the frame-2 point is
//! `p₂ = p₁' + τ a` and `τ = 1/(s − W')`, hence
//!
//! `s = W' + 1/τ`,   `Z = s / q_z`,   `X = x₁ Z`, `Y = y₁ Z`
//!
//! where `(x₁, y₁)` are the normalised frame-1 coordinates. This is eq. 2.3
//! solved along the disparity: `τ` is the position of the crossing on the
//! epipolar line, so both components `d_x`, `d_y` contribute, each in
//! proportion to its share of the line's direction, instead of picking the
//! `x` or `y` form of eq. 2.3 (either of which is ill-conditioned when its
//! component is small). Without rotation and with `f_x = f_y = f` it
//! reduces to eq. 2.3 exactly. The processor evaluates it with
//! `λ = τ |a|²` (the crossing's coordinate along `a`, see below) as
//! `s = W' + |a|²/λ`, the form the stick's ends share.
//!
//! # The error band
//! The paper bounds the depth by a disparity error `e = e₁ + e₂` along `y`
//! at the crossing it found. Here the model is: the true frame-1 point is
//! within `e₁` pixels of the detected one (any direction), so after the
//! rotation compensation within `r₁` of the computed `p₁'` (`e₁` times the
//! homography's stretch, times the change of `q_z` across the disc, plus
//! the compensation's rounding: [`crate::epipolar`], "The error disc after
//! compensation"; plus the shift a rotation error can cause,
//! [`crate::Config::with_rotation_error`]); the
//! true frame-2 boundary is within `e₂` of the polyline; each translation
//! component may be off by `δ` ([`crate::Config::with_translation_error`]).
//! Write the true point as `p₁' + δ₁` (`|δ₁| ≤ r₁`), the true `W'` as
//! `W'_t` (`|W'_t − W'| ≤ σ_w`), and the true epipolar vector as
//! `a_t = a + δa + W'_t δ₁` (exact: `a` is affine in the point and linear in
//! the translation; `|δa| ≤ σ_a` over the error box, [`crate::motion_error`]).
//! The true correspondent is `p₂ = p₁' + δ₁ + τ a_t` with `τ > 0`. In the
//! frame of the line, `λ = â·(p₂ − p₁')`, `μ = n̂·(p₂ − p₁')` (`â = a/|a|`,
//! `n̂` its normal, pixels):
//!
//! `λ = (1 + τW'_t) ξ + τ(|a| + â·δa)`,   `μ = (1 + τW'_t) η + τ n̂·δa`
//!
//! with `ξ = â·δ₁`, `η = n̂·δ₁`, `ξ² + η² ≤ r₁²`, and `1 + τW'_t > 0` (it is
//! the ratio of the frame-2 to the frame-1 distance from the true FOE).
//! Let `A₋ = |a| − σ_a − (|W'| + σ_w) r₁` (positive, else the point's error
//! disc holds the FOE) and `A₊ = |a| + σ_a + (|W'| + σ_w) r₁`. Then
//!
//! * `τ = (λ − ξ)/(|a| + â·δa + W'_t ξ)`, the denominator in `[A₋, A₊]`, so
//!   `λ > −r₁` and `τ ≤ (λ + r₁)/A₋`;
//! * `|μ| ≤ r₁ + τ c` with `c = (W' + σ_w) r₁ + σ_a`, hence
//!   `|μ| ≤ r₁ + |h| r₁ + h λ` with the slope `h = c/A₋` when `c > 0`
//!   (`τ ≤ (λ + r₁)/A₋`) and `h = c/A₊` when `c < 0` (`τ ≥ (λ − r₁)/A₊`):
//!   the band is a thin wedge from `p₁'` outwards, widening away from the
//!   FOE when `W' > 0` and narrowing towards it when `W' < 0`;
//! * for `W'_t < 0` also `τ < 1/|W'_t|`: `λ < r₁ + A₊/(|W'| − σ_w)`, the
//!   FOE end of the paper's segment.
//!
//! A polyline point `q` within `e₂` of `p₂` lies in the band widened by `e₂`:
//! `λ_q > −(r₁ + e₂)` and `|μ_q| ≤ (r₁ + e₂)(1 + |h|) + h λ_q` (the bound on
//! `|μ|` changes with `λ` at slope `h`, and `|λ_q − λ| ≤ e₂`). So the search looks for every
//! polyline segment meeting that region, the **whole** band and not only
//! the exact line, including the part behind `p₁'` down to `r₁ + e₂`. Each
//! segment is clipped to the region (a convex set: four half-planes), which
//! gives the range `[λ_lo, λ_hi]` of its points in the band. Consecutive
//! segments in the band form one *piece*; if the band meets the boundary in
//! more than one piece the point is [`crate::Status::Ambiguous`] and gets no
//! depth (either piece could hold the correspondent).
//!
//! # The stick
//! With `L₋ = λ_lo − e₂` and `L₊ = λ_hi + e₂` over the piece (the true
//! `p₂` is within `e₂` of some band point of the polyline), `1/τ` lies in
//! `[A₋/(L₊ + r₁), A₊/(L₋ − r₁)]`, so
//!
//! `s_far = W' + σ_w + A₊/(L₋ − r₁)`,   `s_near = W' − σ_w + A₋/(L₊ + r₁)`
//!
//! and `Z = s/q_z` with `q_z` itself within `Δ` of ours when the point
//! moves by `e₁` (`PairGeometry::depth_scale_error`).
//! When `L₋ ≤ r₁` the disparity is not larger than its error and the far
//! end is unbounded ([`crate::Status::Unbounded`], also when the near end
//! reaches 0). This is the paper's interval with both errors as discs: for
//! a crossing at right angles the band's piece is a point and the relative
//! half-length is `≈ (r₁ + e₂)/D`, the paper's `|ΔZ/Z| ≈ e/d`
//! (Sec. 4.1.1). A crossing at an angle `φ` gives a piece of length about
//! `w/tan φ` (`w` the band's width): flatter than the configured minimum
//! angle it is [`crate::Status::Grazing`], which keeps the sticks useful;
//! the bound holds at every angle.
//! The two ends bound the two distances from the FOE separately, on
//! different rays; on the wedge path (forward motion, no translation
//! error) the stick of a point whose disparity is a few times its error
//! is tightened by the lines of the piece's segments, which is exact for
//! a straight boundary (the far end is bounded exactly when the polyline
//! passes farther than `r₁ + e₂` from `p₁'`; `src/wedge.rs`, "The stick
//! from the piece's lines").
//!
//! All of this is computed in `f32`. The band is widened by the rounding of
//! the coordinates involved, `2⁻²⁰ S` pixels for coordinates below `S`
//! (`PairGeometry::coordinate_scale`, about 10⁻³ px for
//! the paper's camera), and the estimate `s = W' + |a|²/λ` shares the form
//! of the stick's ends with smaller numerators and larger denominators at
//! `s_far` (the reverse at `s_near`): IEEE `+ − × ÷` are monotone in each
//! argument, so the rounded stick holds the rounded depth with no clamp.

use crate::math::{cross, dot, fmax, fmin, sqrt_pos};

/// Depth interval along the frame-1 ray: every depth consistent with the
/// localisation errors lies in `[z_near, z_far]` (length unit of the motion).
///
/// The interval is what the errors allow, however wide: `Config::max_depth`
/// bounds the depth estimate (a point past it is `beyond_max_depth`), not
/// `z_far`, which can lie far beyond it where the disparity is only a few
/// times its error. A consumer that wants only informative points filters
/// on [`DepthInterval::relative_width`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DepthInterval {
    /// Nearest consistent depth `Z_near`: above 0 on a pair's stick
    /// ([`crate::PointResult::interval`]); a fused interval's
    /// ([`crate::fusion`]) can have 0 here, its ends being kept in 16 bits
    /// each and a near end below `2⁻¹⁵` of the configured maximum depth
    /// rounded down to 0 (still holding the truth; a tenth review's find
    /// against the "> 0" this said before).
    pub z_near: f32,
    /// Farthest consistent depth `Z_far`.
    pub z_far: f32,
}

impl DepthInterval {
    /// `(z_far − z_near) / z`: the interval's length relative to the depth
    /// estimate `z` (`PointResult`'s point's `Z`), what Sec. 4.1 calls the
    /// relative error range (an `ok` point's `z` is above 0; for any other
    /// `z` the quotient is whatever `f32` division gives).
    ///
    /// ```
    /// use roadstereo::DepthInterval;
    /// let stick = DepthInterval { z_near: 9.5, z_far: 10.6 };
    /// assert!((stick.relative_width(10.0) - 0.11).abs() < 1e-6);
    /// ```
    pub fn relative_width(&self, z: f32) -> f32 {
        (self.z_far - self.z_near) / z
    }
}

/// The error terms of one point (pixels, and the translation spreads).
#[derive(Debug, Clone, Copy)]
pub(crate) struct PointErrors {
    /// `r₁`: radius of the compensated frame-1 error disc, with slack.
    pub(crate) r1: f32,
    /// `e₂`, with slack.
    pub(crate) e2: f32,
    /// `e₂ · 2/sin φ_min`, the grazing test's allowance for the polyline's
    /// own error ([`Band::grazing`]).
    pub(crate) e2_csc: f32,
    /// `σ_a`: how far a translation error can move `a` at this point.
    pub(crate) spread_a: f32,
    /// `σ_w`: how far a translation error can move `W'`.
    pub(crate) spread_w: f32,
}

/// Why a point has no band.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum NoBand {
    /// The error disc holds the FOE, or the point is too close to it for
    /// its band to be told from the FOE's (see [`Band::new`]).
    AtFoe,
}

/// One point's error band, in the coordinates of its epipolar line scaled
/// by `|a|` (`λ' = a·(q − p₁') = |a| λ`, `μ' = a × (q − p₁') = |a| μ`): the
/// region `|μ'| ≤ k0 + h λ'`, `lam_lo ≤ λ' ≤ lam_hi`. The stick's terms are
/// worked out only for a point that gets a match ([`Band::depths`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Band {
    /// `p₁'`.
    pub(crate) p: [f32; 2],
    /// The epipolar vector `a`.
    pub(crate) a: [f32; 2],
    /// `|a|²`, `|a|`.
    pub(crate) a2: f32,
    pub(crate) a_len: f32,
    pub(crate) k0: f32,
    pub(crate) h: f32,
    pub(crate) lam_lo: f32,
    pub(crate) lam_hi: f32,
    w: f32,
    /// The tangent of the band's angular half-width as seen from the FOE,
    /// and `1/(ρ₁ − r₁ − e₂)` (for `W' > 0`; see [`Band::key_half_width`]).
    half_angle: f32,
    foe_inv: f32,
    /// `e₂ · 2/sin φ_min`, scaled by `|a|` ([`Band::grazing`]).
    g0: f32,
}

/// How the band stands to the FOE, for the key interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Reach {
    /// The band's rays from the FOE are within `atan(t)` of the point's
    /// own, whose key is known to the second value.
    Within(f32, f32),
    /// Every key (the search is exhaustive).
    Everything,
}

impl Band {
    /// The band of a compensated point `p` with epipolar vector `a` (see
    /// the module docs); `w` is `W'`.
    ///
    /// `near_foe` is the radius `m` about the FOE left to the FOE-near list
    /// when `W' < 0` (see `crate::search`); the band's key interval then
    /// covers the part at least `m` from the FOE. A point whose error disc
    /// holds the FOE (`A₋ ≤ 0`), or with `W' > 0` closer to it than
    /// `3(r₁ + e₂)`, or with `W' < 0` closer than `m + r₁ + e₂`, has no band:
    /// its disparity could not exceed its error in any case worth a stick.
    #[inline(always)]
    pub(crate) fn new(
        p: [f32; 2],
        a: [f32; 2],
        w: f32,
        err: &PointErrors,
        near_foe: f32,
    ) -> Result<Self, NoBand> {
        if w > 0.0 && err.spread_a == 0.0 && err.spread_w == 0.0 {
            return Self::forward(p, a, w, err);
        }
        let a2 = dot(a, a);
        // `a2 > 1e-30` keeps the square root's input in its range (and
        // refuses NaN).
        if !(a2 > 1.0e-30) {
            return Err(NoBand::AtFoe);
        }
        let a_len = sqrt_pos(a2);
        let PointErrors {
            r1,
            e2,
            e2_csc,
            spread_a,
            spread_w,
        } = *err;
        let wa = w.abs();
        let re = r1 + e2;
        let mv = spread_a + (wa + spread_w) * r1;
        let a_minus = a_len - mv;
        let (h, foe_inv, lam_hi) = {
            let guard = if w < 0.0 { wa * (near_foe + re) } else { 0.0 };
            // (A NaN fails both.)
            if !(a_minus > 0.0 && a_len > guard) {
                return Err(NoBand::AtFoe);
            }
            // The slope: |μ| ≤ r₁ + τ c with τ ≤ (λ + r₁)/A₋ when c > 0,
            // and τ ≥ (λ − r₁)/A₊ when c < 0 (the band narrows towards the
            // FOE).
            let c = (w + spread_w) * r1 + spread_a;
            let h = if c > 0.0 {
                c / a_minus
            } else {
                c / (a_len + mv)
            };
            let foe_inv = if w > 0.0 { wa / (a_len - wa * re) } else { 0.0 };
            let lam_hi = if w + spread_w < 0.0 {
                // r₁ + A₊/(|W'| − σ_w) + e₂, scaled by |a|.
                (re + (a_len + mv) / (wa - spread_w)) * a_len
            } else {
                f32::INFINITY
            };
            (h, foe_inv, lam_hi)
        };
        Ok(Self {
            p,
            a,
            a2,
            a_len,
            k0: re * (1.0 + h.abs()) * a_len,
            h,
            lam_lo: -re * a_len,
            lam_hi,
            w,
            // The maximum over the band of |μ|/(ρ₁ + λ): at its near end
            // (r₁ + e₂)/(ρ₁ − r₁ − e₂), or its slope h far out.
            half_angle: fmax(re * foe_inv, h),
            foe_inv,
            g0: e2_csc * a_len,
        })
    }

    /// [`Band::new`] in the usual case, `W' > 0` and no translation error:
    /// `1/(ρ₁ − r₁ − e₂) = W'/(|a| − W'(r₁ + e₂))` and `h = W' r₁ / A₋ ≤ r₁
    /// W'/(|a| − W'(r₁ + e₂))`, one division; no far limit.
    #[inline(always)]
    pub(crate) fn forward(
        p: [f32; 2],
        a: [f32; 2],
        w: f32,
        err: &PointErrors,
    ) -> Result<Self, NoBand> {
        let (r1, e2) = (err.r1, err.e2);
        let a2 = dot(a, a);
        // `a2 > 1e-30` keeps the square root's input in its range (and
        // refuses NaN).
        if !(a2 > 1.0e-30) {
            return Err(NoBand::AtFoe);
        }
        let a_len = sqrt_pos(a2);
        let re = r1 + e2;
        // (A NaN fails.)
        if !(a_len - 3.0 * w * re > 0.0) {
            return Err(NoBand::AtFoe);
        }
        let foe_inv = w / (a_len - w * re);
        let h = r1 * foe_inv;
        Ok(Self {
            p,
            a,
            a2,
            a_len,
            k0: re * (1.0 + h) * a_len,
            h,
            lam_lo: -re * a_len,
            lam_hi: f32::INFINITY,
            w,
            half_angle: re * foe_inv,
            foe_inv,
            g0: err.e2_csc * a_len,
        })
    }

    /// `W'`.
    pub(crate) fn w(&self) -> f32 {
        self.w
    }

    /// How wide the band's key interval is (for direction keys): its rays
    /// lie within `atan(t)` of the point's own, and `m` is the rounding
    /// margin of the point's own key (whose distance from the FOE is at
    /// least `ρ₁ − r₁ − e₂`; `key_scale` as in `crate::pencil::Keying`):
    /// `Within(t, m)`. `near_foe` as in [`Band::new`]; `exhaustive` when the
    /// FOE's position is uncertain and `W' < 0` (a translation error with
    /// backward motion: the band runs into an uncertain FOE, and every key
    /// is searched).
    #[inline(always)]
    pub(crate) fn key_half_width(&self, near_foe: f32, exhaustive: bool, key_scale: f32) -> Reach {
        const FLOOR: f32 = 4.0 * 9.536_743e-7;
        // (The band reaches behind the FOE when ρ₁ ≤ r₁ + e₂, where
        // `foe_inv` is not positive: every key. A NaN fails.)
        if self.w > 0.0 && self.foe_inv > 0.0 && self.foe_inv < f32::INFINITY {
            Reach::Within(
                self.half_angle * (1.0 + 1.0e-5),
                key_scale * self.foe_inv * (1.0 + 1.0e-5) + FLOOR,
            )
        } else if self.w < 0.0 && !exhaustive {
            // The part at least `near_foe` from the FOE: |μ| ≤ K₀ + h λ
            // (h ≤ 0 here) is largest against the axis distance ρ₁ − λ at
            // λ = ρ₁ − near_foe (the derivative of the ratio has the sign
            // of K₀ + h ρ₁ ≥ e₂ > 0); the point itself is farther.
            let rho1 = self.a_len / self.w.abs();
            let k0 = self.k0 / self.a_len;
            Reach::Within(
                (k0 + self.h * (rho1 - near_foe)) / near_foe * (1.0 + 1.0e-5),
                key_scale / near_foe + FLOOR,
            )
        } else {
            Reach::Everything
        }
    }

    /// The four corners of the band's region (pixels), its near end at
    /// `λ = −(r₁ + e₂)` and its far end at `λ = far` (`far` bounded by the
    /// image's reach when the band is unbounded): for keys that are not
    /// direction keys, whose interval is the hull of the corners' keys.
    pub(crate) fn corners(&self, reach_from_p: f32) -> [[f32; 2]; 4] {
        let inv = 1.0 / self.a_len;
        let u = [self.a[0] * inv, self.a[1] * inv];
        let n = [-u[1], u[0]];
        let near = self.lam_lo * inv;
        let far = fmin(self.lam_hi * inv, reach_from_p);
        let at = |l: f32, s: f32| {
            let half = (self.k0 + self.h * l * self.a_len) * inv;
            [
                self.p[0] + l * u[0] + s * half * n[0],
                self.p[1] + l * u[1] + s * half * n[1],
            ]
        };
        [at(near, 1.0), at(near, -1.0), at(far, 1.0), at(far, -1.0)]
    }

    /// A frame-2 vertex in the band's frame: `(λ', μ')`, the values of the
    /// two edge functions `g± = k0 + h λ' ∓ μ'` (inside the wedge when both
    /// are ≥ 0) and its outcode: bit 0 beyond the `+` edge, bit 1 beyond
    /// the `−` edge, bit 2 before `lam_lo`, bit 3 after `lam_hi`.
    #[inline(always)]
    pub(crate) fn vertex(&self, v: [f32; 2]) -> Vertex {
        let d = [v[0] - self.p[0], v[1] - self.p[1]];
        let lam = dot(self.a, d);
        let mu = cross(self.a, d);
        let base = self.k0 + self.h * lam;
        let (gp, gm) = (base - mu, base + mu);
        // Sign bits (−0 made +0: a vertex on an edge is inside).
        let out = ((gp + 0.0).to_bits() >> 31)
            | (((gm + 0.0).to_bits() >> 31) << 1)
            | (u32::from(lam < self.lam_lo) << 2)
            | (u32::from(lam > self.lam_hi) << 3);
        Vertex {
            lam,
            mu,
            gp,
            gm,
            out,
        }
    }

    /// The part of the segment `a → b` (two [`Band::vertex`]es) in the
    /// band's region, as its range of `λ'`, and the exact line's crossing
    /// of the segment, `(t along it, λ')`; `None` when the segment misses
    /// the region. Cohen–Sutherland by the outcodes: both ends beyond one
    /// edge is a miss at once; a segment wholly inside needs no division;
    /// each edge one end crosses costs one (where the segment meets it).
    #[inline(always)]
    pub(crate) fn segment(&self, a: &Vertex, b: &Vertex) -> Option<Clipped> {
        if a.out & b.out != 0 {
            return None;
        }
        let dl = b.lam - a.lam;
        let (mut t0, mut t1) = (0.0f32, 1.0f32);
        let crossed = (a.out | b.out) & 3;
        if crossed != 0 {
            // The wedge's edges, each a line: where the segment crosses one
            // that an end lies beyond, it enters or leaves the region.
            for (bit, ga, gb) in [(1u32, a.gp, b.gp), (2u32, a.gm, b.gm)] {
                if crossed & bit != 0 {
                    let t = ga / (ga - gb);
                    if ga < 0.0 {
                        t0 = fmax(t0, t);
                    } else {
                        t1 = fmin(t1, t);
                    }
                }
            }
            // (A NaN fails.)
            if !(t0 <= t1) {
                return None;
            }
        }
        let (la, lb) = (a.lam + t0 * dl, a.lam + t1 * dl);
        let (mut lo, mut hi) = if dl >= 0.0 { (la, lb) } else { (lb, la) };
        if (a.out | b.out) & 12 != 0 {
            (lo, hi) = (fmax(lo, self.lam_lo), fmin(hi, self.lam_hi));
            if !(lo <= hi) {
                return None;
            }
        }
        let crossing =
            (side_bit(a.mu) != side_bit(b.mu)).then(|| a.lam + a.mu / (a.mu - b.mu) * dl);
        Some(Clipped { lo, hi, crossing })
    }

    /// Whether a vertex lies in the band's region.
    #[inline(always)]
    pub(crate) fn contains(v: &Vertex) -> bool {
        v.out == 0
    }

    /// Whether a piece of the band from `lo` to `hi` (`λ'`) is longer than
    /// the band's width there times `cot_twice = 2 cot(φ_min)` plus `e₂ ·
    /// 2/sin φ_min`: no boundary within `e₂` of the polyline crosses the
    /// line at the minimum angle or steeper (the derivation is
    /// [`crate::wedge`]'s, with the band's half-width for the wedge's).
    #[inline(always)]
    pub(crate) fn grazing(&self, lo: f32, hi: f32, cot_twice: f32) -> bool {
        hi - lo > (self.k0 + self.h * hi) * cot_twice + self.g0
    }

    /// The depth estimate and the stick in the compensated frame, `(s,
    /// s_near, s_far)`, for the exact crossing at `lam` (`λ'`, within
    /// `[lo, hi]`) and the piece's range `[lo, hi]` (`λ'`); `None` when
    /// the far end is unbounded. `err` as for [`Band::new`].
    #[inline(always)]
    pub(crate) fn depths(
        &self,
        err: &PointErrors,
        lam: f32,
        lo: f32,
        hi: f32,
    ) -> Option<(f32, f32, f32)> {
        let (r1a, e2a) = (err.r1 * self.a_len, err.e2 * self.a_len);
        let den_far = (lo - e2a) - r1a;
        // (A NaN fails.)
        if !(den_far > 0.0) {
            return None;
        }
        // |a| (σ_a + (|W'| + σ_w) r₁): the stick's numerators are
        // |a| A₊ and |a| A₋ (module docs), scaled by |a|.
        let mv = self.a_len * (err.spread_a + (self.w.abs() + err.spread_w) * err.r1);
        let s = self.w + self.a2 / lam;
        let s_far = (self.w + err.spread_w) + (self.a2 + mv) / den_far;
        let s_near = (self.w - err.spread_w) + (self.a2 - mv) / ((hi + e2a) + r1a);
        Some((s, s_near, s_far))
    }

    /// The point of the exact epipolar line at `λ'`: `p₁' + (λ'/|a|²) a`
    /// (for a crossing: the frame-2 point, on the polyline up to rounding).
    #[inline(always)]
    pub(crate) fn point_at(&self, lam: f32) -> [f32; 2] {
        let t = lam / self.a2;
        [self.p[0] + t * self.a[0], self.p[1] + t * self.a[1]]
    }
}

/// A vertex in a band's frame (see [`Band::vertex`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Vertex {
    pub(crate) lam: f32,
    pub(crate) mu: f32,
    gp: f32,
    gm: f32,
    out: u32,
}

impl Vertex {
    /// A placeholder (outside everything).
    pub(crate) const NONE: Vertex = Vertex {
        lam: 0.0,
        mu: 0.0,
        gp: -1.0,
        gm: -1.0,
        out: 15,
    };
}

/// What [`Band::segment`] found: the `λ'` range of the segment's part in the
/// band, and the `λ'` of the exact line's crossing of the segment (which
/// the walk keeps only within the band's `λ'` range, and brings into the
/// piece's range against rounding).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Clipped {
    pub(crate) lo: f32,
    pub(crate) hi: f32,
    pub(crate) crossing: Option<f32>,
}

/// The side of a vertex from its `μ'`: 0 for `μ' ≥ 0`, 1 for `μ' < 0`. The
/// sign bit once −0 is made +0 (`+ 0.0`), so a vertex on the line counts as
/// on the positive side and two adjacent segments never both report a
/// crossing through their shared vertex.
#[inline(always)]
pub(crate) fn side_bit(mu: f32) -> u32 {
    (mu + 0.0).to_bits() >> 31
}

/// The depth interval of `(s_near, s_far)` for a point whose `1/q_z` is
/// `iz`, known to a relative `kappa` (`κ = 2Δ/q_z`, see
/// [`crate::epipolar::PairGeometry::depth_scale_error`]); `None` when the
/// far end is not finite or the near end not above 0.
#[inline(always)]
pub(crate) fn interval(s_near: f32, s_far: f32, iz: f32, kappa: f32) -> Option<DepthInterval> {
    let z_far = s_far * (iz * (1.0 + kappa));
    let z_near = s_near * (iz * (1.0 - kappa));
    (z_far.is_finite() && z_near > 0.0).then_some(DepthInterval { z_near, z_far })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::test_rng::Rng;

    /// A frame-2 point the band of `p` holds, for the pair `W' = w`, `g`
    /// and the principal point `c2`: a true frame-1 point within `r₁` of
    /// `p`, its depth `s` drawn by `depth` (`None`: no point), a polyline
    /// point within `e₂` of its correspondent, computed in `f64`.
    pub(crate) fn band_point(
        rng: &mut Rng,
        (w, g, c2): (f32, [f32; 2], [f32; 2]),
        p: [f32; 2],
        (r1, e2): (f32, f32),
        depth: impl FnOnce(&mut Rng, f64) -> Option<f64>,
    ) -> Option<[f32; 2]> {
        let ang = rng.next() * core::f32::consts::TAU;
        let rad = f64::from(r1) * f64::from(rng.next());
        let pt = [
            f64::from(p[0]) + rad * f64::from(libm::cosf(ang)),
            f64::from(p[1]) + rad * f64::from(libm::sinf(ang)),
        ];
        let wf = f64::from(w);
        let at = [
            wf * (pt[0] - f64::from(c2[0])) - f64::from(g[0]),
            wf * (pt[1] - f64::from(c2[1])) - f64::from(g[1]),
        ];
        let s = depth(rng, wf)?;
        let tau = 1.0 / (s - wf);
        let p2 = [pt[0] + tau * at[0], pt[1] + tau * at[1]];
        let ang2 = rng.next() * core::f32::consts::TAU;
        let rad2 = f64::from(e2) * f64::from(rng.next());
        Some([
            (p2[0] + rad2 * f64::from(libm::cosf(ang2))) as f32,
            (p2[1] + rad2 * f64::from(libm::sinf(ang2))) as f32,
        ])
    }

    /// The band's region holds every frame-2 point the error model allows:
    /// random true frame-1 points within `r₁`, translation errors within
    /// the spreads, depths anywhere along the ray, and polyline points
    /// within `e₂` of the true correspondent (computed in `f64`).
    #[test]
    fn band_holds_every_consistent_point() {
        let mut rng = Rng(0xba4d_0001);
        let mut inside = 0;
        for case in 0..20_000 {
            let w = match case % 3 {
                0 => 0.3 + rng.next(),
                1 => -(0.3 + rng.next()),
                _ => 0.0,
            };
            let g = [(rng.next() - 0.5) * 300.0, (rng.next() - 0.5) * 300.0];
            let c2 = [255.5f32, 239.5];
            let p = [512.0 * rng.next(), 480.0 * rng.next()];
            let a = [w * (p[0] - c2[0]) - g[0], w * (p[1] - c2[1]) - g[1]];
            let err = PointErrors {
                r1: 0.1 + rng.next(),
                e2: 0.1 + rng.next(),
                e2_csc: 0.0,
                spread_a: 0.0,
                spread_w: 0.0,
            };
            let Ok(band) = Band::new(p, a, w, &err, 20.0) else {
                continue;
            };
            // A true point and depth, a polyline point within e2 of it.
            let depth = |rng: &mut Rng, wf: f64| {
                let s = 0.5 + 40.0 * f64::from(rng.next());
                (s - wf > 0.0).then_some(s)
            };
            let Some(q) = band_point(&mut rng, (w, g, c2), p, (err.r1, err.e2), depth) else {
                continue;
            };
            let c = band.vertex(q);
            assert!(
                band.segment(&c, &c).is_some() && Band::contains(&c),
                "case {case}: q {q:?} outside the band of {p:?} (w {w})"
            );
            inside += 1;
        }
        assert!(inside > 10_000, "{inside}");
    }
}
