//! The usual case of the matching stage: forward motion (`W' > 0`) and no
//! translation error, with a frame-2 boundary on one side of the FOE's
//! row (half-plane keys, [`crate::pencil`]) or near it (pseudo-angle keys,
//! [`Wedge::new_angular`]: the same wedge, its key interval found in the
//! index's unwrapped keys, [`crate::search::Lean::copy`]). Here the error
//! band of [`crate::depth`] is replaced by a slightly larger region whose
//! test is mostly a comparison of keys the index already holds: the
//! **wedge**.
//!
//! # The wedge holds the band
//! With the notation of [`crate::depth`] and no translation error, the band
//! of a compensated point `p₁'` at distance `ρ₁ = |p₁' − F|` from the FOE
//! `F` is `λ ≥ −(r₁ + e₂)`, `|μ| ≤ (r₁ + e₂)(1 + h) + h λ` with `h = r₁/(ρ₁
//! − r₁ − e₂)` (`a = W'(p₁' − F)`, so `|a| = W' ρ₁` and `W'/(|a| − W'(r₁ +
//! e₂)) = 1/(ρ₁ − r₁ − e₂)`). Seen from `F`, a band point at `λ` is at
//! distance `ρ₁ + λ` along the ray through `p₁'`, so its angle from that ray
//! has the tangent `|μ|/(ρ₁ + λ)`. At `λ = −(r₁ + e₂)` that is `(r₁ + e₂)/(ρ₁
//! − r₁ − e₂)`; as `λ` grows the ratio moves monotonically towards its limit
//! `h`, which is smaller (`r₁ ≤ r₁ + e₂`). So every band point lies in the
//! wedge of rays from `F` within the angle `θ`, `tan θ = T = (r₁ + e₂)/(ρ₁
//! − r₁ − e₂)`, of the ray through `p₁'`, at `λ ≥ −(r₁ + e₂)`: the region
//! this module searches. It is the band widened by at most `(r₁ + e₂)(λ +
//! r₁ + e₂)/(ρ₁ − r₁ − e₂)` on either side, a few hundredths of a pixel
//! for a point 100 px from the FOE with a disparity of 10 px.
//!
//! # Keys filter, the edges decide
//! The half-plane key is a strictly monotone function of a ray's angle
//! about `F` over the half-plane, and along a segment (which cannot pass
//! through `F`) the angle is monotone, so a segment's rays have the keys
//! between those of its end points. The wedge's rays, within `θ = atan T
//! ≤ T` of `d = p₁' − F`, have keys within `δ` of `d`'s own `k_d`: for a
//! unit direction at the angle `φ` from the row, `k = cos φ/(|cos φ| +
//! sin φ)` changes at the rate `|dk/dφ| = 1/(|cos φ| + sin φ)² = S(k) =
//! 1 − 2|k| + 2k²` (from `|k| (|cos φ| + sin φ) = |cos φ|` and `cos² +
//! sin² = 1`), and `S` changes by at most 2 per key unit, so over the
//! wedge the keys stay within `δ ≤ θ (S(k_d) + 2δ)`, `δ ≤ T S(k_d)/(1 −
//! 2T) ≤ T S(k_d) (1 + 2T + 6T²)` for `T ≤ 1/8` (past the FOE's row the
//! half-plane ends and the keys with it). Step 1 computed `k_d` (the
//! point's own key) to within its margin `m ≤ 2⁻²⁰ (S/ρ₁ + 1)` (its `D =
//! |d_u| + t ≥ ρ₁`), so `[k_d − m − δ, k_d + m + δ]` with `S(k_d) + 2m` for
//! the rate holds every key of the wedge: no division. A wider wedge (`T >
//! 1/8`, close to the FOE) or a point without a key takes the keys of the
//! wedge's two edges instead (the edge directions `d ± T d⊥`; an edge
//! outside the half-plane stands for the key limit `±1` on its side, as
//! the wedge leaves the half-plane through the FOE's row). With every key
//! widened by its rounding margin, a segment whose interval
//! ([`crate::search`]) misses the wedge's is outside it.
//!
//! Every other segment is decided by the geometry. For a frame-2 point
//! `q`, `w = q − F`, let `X = d·w` and `Y = d × w` (`ρ₁ |w|` times the
//! cosine and the sine of its angle from `d`): the wedge is `|Y| ≤ T X`,
//! that is both *edge values* `T X ∓ Y` at least 0 (each linear in `w`:
//! the edges' lines through `F`, with the normals `T d ∓ d⊥`). A segment
//! with both ends inside is taken whole; one with an end outside an edge
//! is clipped by that edge's line, exactly (one division per edge it
//! crosses); one with both ends outside the same edge has no part in the
//! wedge. `X` is linear along the segment, so the ends of the part give
//! its range `[X₀, X₁]`, and as `X = ρ₁ (ρ₁ + λ)` (`λ = â·(q − p₁')`, `â
//! = d/ρ₁`), `λ ≥ −(r₁ + e₂)` is `X ≥ X_min = R − ρ₁ (r₁ + e₂)` with `R =
//! |d|² = ρ₁²`: the walk works in `X` throughout and never needs `λ`.
//!
//! The walk over the segments (in order, with the rules of
//! [`crate::matching`]: one piece, not grazing, no end vertex inside,
//! the exact line's nearest crossing for the estimate, where the segment's
//! ends lie on the line's two sides (`Y` changes sign): a segment whose
//! keys miss the line's, widened by the margins, has both ends farther
//! from the line than the sides' rounding, so no key test is needed there)
//! gives the piece's range `[lo, hi]` and the crossing's `X`, and with
//! `|a| = W' ρ₁` and `λ = (X − R)/ρ₁` the depth and stick of
//! [`crate::depth`] become
//!
//! `s = W' (1 + R/(X − R))`,   `s_far = W' (1 + (R + ρ₁ r₁)/(lo − R − ρ₁ (r₁ + e₂)))`,
//! `s_near = W' (1 + (R − ρ₁ r₁)/(hi − R + ρ₁ (r₁ + e₂)))`
//!
//! (`s_far`'s numerator and `s_near`'s denominator are the larger ones,
//! `(lo − R) − ρ₁ (r₁ + e₂) ≤ X − R ≤ (hi − R) + ρ₁ (r₁ + e₂)`, each
//! computed in that order: IEEE operations keep the order, so the rounded
//! stick holds the rounded estimate). A piece is grazing when it is longer
//! than any piece a boundary crossing the line at `φ_min` or steeper could
//! leave in the wedge, the polyline's own error included: a straight
//! boundary at the angle `φ` crosses a strip of half-width `w` (the wedge's
//! at the piece's near end, `T (ρ₁ + λ)`) over `2 w cot φ` along the line,
//! and the points within `e₂` of it that lie in the strip span `2 w cot φ +
//! 2 e₂/sin φ`; for `φ ≥ φ_min` that is at most `2 w cot φ_min + 2
//! e₂/sin φ_min`. So the test is, in `λ`, `hi − lo > T (ρ₁ + lo) · 2 cot
//! φ_min + e₂ · 2/sin φ_min`, in `X` (times `ρ₁`) `hi − lo > T lo · 2 cot
//! φ_min + ρ₁ e₂ · 2/sin φ_min`: a point whose detected piece is flagged
//! cannot have its true crossing at `φ_min` or steeper (up to the curvature
//! of the boundary over the piece). The test is a cut for information, not
//! part of the guarantee: the stick comes from the piece's range whatever
//! its length. (Before the `e₂` term the test took the polyline's wobble
//! within `e₂` for flatness: a boundary rounded to the pixel grid lost 1.8
//! % of the two-view ideal points to it, at true angles of 10–15°.) It only
//! becomes true as the piece grows (`lo ≥ X_min > 0`), so the walk may stop
//! at the first segment that makes it true and get the outcome a walk to
//! the end would.
//!
//! # Rounding
//! `ρ₁` enters only through `X_min`, `T` and the stick's small terms
//! `ρ₁ r₁`, `ρ₁ (r₁ + e₂)`, and each of them is a bound in the right
//! direction for any `ρ₊ ≥ ρ₁`: `X_min` falls (more of the band's near
//! end), `T` grows (a wider wedge), `s_far` grows (its numerator grows and
//! its positive denominator shrinks) and `s_near` falls (`R − ρ₊ r₁ > 0`
//! shrinks, its denominator grows). So `ρ₊` is `R` times the division-free
//! reciprocal square root ([`crate::math::rsqrt_pos`], within `3.1 · 2⁻²⁴`)
//! times `1 + 2⁻²¹`, and `T = x/(1 − x)` with `x = (r₁ + e₂)/ρ₁ < 1/3`
//! (bounded above the same way) is bounded by `x (1 + x + x² + 2x³)` and
//! rounded up by `2⁻¹⁶` relative: no division and no square root. The
//! key interval's `δ` is rounded up by `2⁻¹⁶` too, and the margin of each
//! end is the key's own ([`crate::pencil`]). `R`,
//! `X`, `Y` and the edge values are computed from coordinates below the
//! frame's scale `S` and, as distances (divided by `ρ₁`), are off by a few
//! `2⁻²⁴ S` at most, which the slack of `2⁻²⁰ S` in `r₁` and `e₂` covers
//! (see [`crate::depth`]).
//!
//! # The stick from the piece's lines
//! The stick above bounds the two distances from the FOE apart: the true
//! frame-1 point by the disc (`d̂·P₁ ≤ R + ρ₁ r₁`, in the wedge's frame
//! `X = d·w`, `Y = d × w`, where `P₁' = (R, 0)`) and the true
//! correspondent by the piece's range (`d̂·P₂ ≥ lo − ρ₁ e₂`). Both can
//! hold only on different rays, which the truth is not: `P₁ = k P₂` on one
//! ray from the FOE, with `k = ρ(p₁)/ρ(p₂) < 1` and `s = W'/(1 − k)`
//! (the estimate's `k` is `R/X`). So the same bound holds with **any**
//! direction `u` in place of `d̂`: `u·P₁ = k u·P₂`, and where `u·P₂` is
//! positive over the true correspondent's region,
//!
//! `k ≤ max u·P₁ / min u·P₂`,   `k ≥ min u·P₁ / max u·P₂`,
//!
//! with `max u·P₁ = u·P₁' + ρ₁ r₁ |u|` over the disc and, for a
//! correspondent within `e₂` of segment `a → b`, `min u·P₂ = min(u·a,
//! u·b) − ρ₁ e₂ |u|` (the segment's `e₂`-neighbourhood is convex, a linear
//! function takes its extremes at the ends). In `t = k/(1 − k)` (`s = W'
//! (1 + t)`), `t ≤ max u·P₁ / (min u·P₂ − max u·P₁)`, whose denominator is
//! `min(u·(a − P₁'), u·(b − P₁')) − ρ₁ (r₁ + e₂) |u|`: computed from the
//! differences `a − P₁'`, without the cancellation of two large products.
//! The true correspondent lies within `e₂` of one of the piece's segments
//! (a polyline point within `e₂` of it lies in the wedge, and the piece
//! holds every segment with a part there), so `t_far = max` over the
//! segments of the smallest bound each of three directions gives: `d̂`
//! (the segment's own part `[lo_j, hi_j]`, the stick above segment by
//! segment), the segment's normal, and the normal of the piece's chord
//! (first to last vertex; a pixel staircase's steps point every way, its
//! chord does not); `t_near` likewise with `min` and `max` exchanged.
//!
//! For a straight boundary crossing the line at `φ` this is exact: the
//! normal gives `k ≤ (ρ₁ sin φ + r₁)/((ρ₁ + D) sin φ − e₂)`, so the far end
//! is bounded exactly when `D sin φ > r₁ + e₂`: when the polyline passes
//! farther than `r₁ + e₂` from `p₁'`, which is also necessary (otherwise a
//! true point and a correspondent both at `p₁'`'s nearest polyline point,
//! at infinite depth, fit the error model). The piece's range alone
//! needs `D > r₁ + e₂ + (r₁ + e₂) cot φ`: at 45° that is `2 (r₁ + e₂)`
//! against `1.41 (r₁ + e₂)`, at 20° `3.75` against `2.92`; the far end's
//! disparity error shrinks by `(r₁ + e₂)(1 + cot φ − 1/sin φ)`, up to
//! `0.9 (r₁ + e₂)`. It matters where the disparity is a few times the
//! error, so it is taken there only ([`Wedge::refines`]: the far end
//! unbounded, or its disparity under [`REFINE_GAP`] `(r₁ + e₂)` by the
//! piece's range), out of the walk's function: the walk keeps the usual
//! point's registers, and the refinement finds the piece again from its
//! end ([`Wedge::refined`]: back to the first segment without a part,
//! then the range, the crossing and the bounds in one pass, bit for bit
//! the walk's range and crossing). Its dear part, a segment's two
//! directions' bounds (two divisions each and a reciprocal square root),
//! is paid from the frame's work budget, [`REFINE_UNITS`] a segment; a
//! segment the credit left cannot pay for keeps only its `d̂` bound, the
//! stick from its range: `t_far` is still a maximum over the segments of
//! bounds each valid for its segment, so the stick still holds, only less
//! tight (with no credit it is the stick from the piece's range, bit for
//! bit; one left unbounded for want of credit is flagged
//! [`Status::OverBudget`]). The rest of the pass (the piece found again,
//! each segment's part and crossing, as the walk computed them) is bounded
//! by the segments the walk paid for. The band path keeps the stick from
//! the range alone. Rounding: `|u|` is bounded above (`rsqrt_pos` with
//! [`crate::math::RSQRT_UP`] twice), each `u·(v − P₁')` and `u_x R` is
//! widened by four times its rounding bound, and the ends are rounded
//! outwards by `2⁻²¹`; the vertices' own rounding is the slack in `r₁` and
//! `e₂`, as above (see [`STICK_UP`] for what carries which rounding).
//! `refined_stick_holds_every_consistent_depth` checks the bound against
//! `f64` configurations near the extremes of the model (the truth at
//! 0.999 of each error; it fails with any of the error terms 10 % short).

use crate::camera::Pixel;
use crate::matching::Outcome;
use crate::math::{dot, fmax, fmin, rsqrt_pos, sub, RSQRT_UP};
use crate::search::{Flow, Visitor, CLIP_UNITS};
use crate::structure::Status;

/// `2⁻²⁰`, the keys' rounding unit ([`crate::pencil`]).
const ULP20: f32 = 9.536_743e-7;

/// One point's wedge (see the module docs), in the index's oriented keys.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Wedge {
    foe: [f32; 2],
    /// `p₁'`, `d = p₁' − F`.
    p: [f32; 2],
    d: [f32; 2],
    /// `R = |d|² = ρ₁²`, and `1/R` (to rounding).
    r2: f32,
    inv_r2: f32,
    /// `ρ₊ ≥ ρ₁`, and `ρ₊ (r₁ + e₂)`.
    pub(crate) rho: f32,
    rho_re: f32,
    /// `T`, the tangent of the half-angle (rounded up).
    t: f32,
    /// The wedge's key interval (oriented, widened by the edges' margins):
    /// the index query. Ordered, `kl ≤ kh`: the lean walks test a
    /// segment's interval `[lo, hi]` against it as `lo ≤ kh` and `hi ≥ kl`
    /// (`r₁, e₂ ≥ 0`, so `T`, `δ` and the margins are not negative).
    pub(crate) kl: f32,
    pub(crate) kh: f32,
    /// `X_min = R − ρ₊ (r₁ + e₂)`: `λ ≥ −(r₁ + e₂)` is `X ≥ X_min`.
    pub(crate) x_min: f32,
    /// The grazing test's allowance for the polyline's own error, in `X`:
    /// `ρ₊ e₂ · 2/sin φ_min` (module docs).
    g0: f32,
}

/// A point without a wedge: it lies within `3 (r₁ + e₂)` of the FOE
/// ([`Status::AtFoe`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct AtFoe;

impl Wedge {
    /// The wedge of compensated point `p` for a FOE `foe`, the boundary on
    /// the `side` of its row (+1 below), errors `r1`, `e2` and the grazing
    /// test's `e2_csc = e₂ · 2/sin φ_min`, keys with
    /// `key_scale` (`crate::pencil::Keying`) oriented by `orient`; `key` is
    /// `p`'s own raw half-plane key (step 1's; [`crate::pencil::NO_KEY`]
    /// where it has none).
    #[inline(always)]
    pub(crate) fn new(
        p: [f32; 2],
        (foe, side): ([f32; 2], f32),
        (r1, e2, e2_csc): (f32, f32, f32),
        (key, key_scale, orient): (f32, f32, f32),
    ) -> Result<Self, AtFoe> {
        let (mut w, y_up) = Self::frame(p, foe, (r1, e2, e2_csc))?;
        let (d, t) = (w.d, w.t);
        let k = orient * key;
        // (A NaN fails.)
        (w.kl, w.kh) = if t <= 0.125 && k.is_finite() {
            // The keys of the rays within atan T of d's, from d's own
            // (module docs): `m` bounds its margin (D ≥ ρ₁), `S(k) + 2m`
            // the keys' rate of change at d, and `δ` the change over the
            // wedge.
            let m = key_scale * y_up + ULP20;
            let ka = k.abs();
            let rate = 1.0 + ka * (2.0 * ka - 2.0) + 2.0 * m;
            let delta = t * rate * (1.0 + t * (2.0 + 6.0 * t)) * (1.0 + 1.53e-5) + m;
            (k - delta, k + delta)
        } else {
            exact_keys(d, t, side, key_scale, orient)
        };
        Ok(w)
    }

    /// [`Self::new`] for pseudo-angle keys ([`crate::pencil`], `key` the
    /// point's raw one, in `[0, 4)`, or [`crate::pencil::NO_KEY`]): the
    /// interval `k ± δ` of the oriented key `k`, `δ = T + m` rounded up,
    /// with `m = 2⁻²⁰ (S/ρ₁ + 4)` bounding the key's margin (its `D =
    /// |d_u| + |d_v| ≥ ρ₁`) and `T ≥ θ` the wedge's half-angle: a
    /// pseudo-angle changes by at most one unit per radian. Not yet
    /// unwrapped: the index gives the copy to walk ([`crate::search::Lean::copy`]);
    /// a segment (less than half a turn about the FOE) has the rays whose
    /// keys lie between its ends' unwrapped keys, so the filter of the
    /// module docs holds on the unwrapped keys.
    /// A point without a key gets `(−∞, ∞)`: no copy of it is single (the
    /// caller takes the band path) unless the index has no keyed segment
    /// (then the empty copy, which meets only the unkeyed ones).
    #[inline(always)]
    pub(crate) fn new_angular(
        p: [f32; 2],
        foe: [f32; 2],
        (r1, e2, e2_csc): (f32, f32, f32),
        (key, key_scale, orient): (f32, f32, f32),
    ) -> Result<Self, AtFoe> {
        let (mut w, y_up) = Self::frame(p, foe, (r1, e2, e2_csc))?;
        let k = orient * key;
        // (A NaN fails.)
        (w.kl, w.kh) = if k.is_finite() {
            let m = key_scale * y_up + 4.0 * ULP20;
            let delta = (w.t + m) * (1.0 + 1.53e-5) + ULP20;
            (k - delta, k + delta)
        } else {
            (f32::NEG_INFINITY, f32::INFINITY)
        };
        Ok(w)
    }

    /// The wedge's geometry without its keys (`kl = kh = 0`), and `y₊ ≥
    /// 1/ρ₁`: [`Self::new`] and [`Self::new_angular`] add the keys.
    #[inline(always)]
    fn frame(
        p: [f32; 2],
        foe: [f32; 2],
        (r1, e2, e2_csc): (f32, f32, f32),
    ) -> Result<(Self, f32), AtFoe> {
        let d = sub(p, foe);
        let re = r1 + e2;
        let r2 = dot(d, d);
        // ρ₁ > 3 (r₁ + e₂), and R in `rsqrt_pos`'s range. (A NaN fails.)
        if !(r2 > 9.0 * (re * re) && r2 < 1.0e30) {
            return Err(AtFoe);
        }
        let y = rsqrt_pos(r2);
        let y_up = y * RSQRT_UP;
        let rho = (r2 * y) * RSQRT_UP;
        // T = x/(1 − x) with x = (r₁ + e₂)/ρ₁ < 1/3, bounded above by
        // x (1 + x + x² + 2x³) (the rest of the series, x⁴/(1 − x), is at
        // most 1.5 x⁴ there), x itself from above.
        let x = re * y_up;
        let t = x * (1.0 + x * (1.0 + x * (1.0 + 2.0 * x))) * (1.0 + 1.53e-5);
        let rho_re = rho * re;
        Ok((
            Self {
                foe,
                p,
                d,
                r2,
                inv_r2: y * y,
                rho,
                rho_re,
                t,
                kl: 0.0,
                kh: 0.0,
                x_min: r2 - rho_re,
                g0: rho * e2_csc,
            },
            y_up,
        ))
    }

    /// A vertex in the wedge's frame: `w = v − F`, `X = d·w`, `Y = d × w`
    /// and `T X` (the edge values are `T X ∓ Y`, both at least 0 inside
    /// the wedge: `|Y| ≤ T X`).
    #[inline(always)]
    pub(crate) fn vertex(&self, v: [f32; 2]) -> WVertex {
        let w = sub(v, self.foe);
        let x = dot(self.d, w);
        WVertex {
            x,
            y: self.d[0] * w[1] - self.d[1] * w[0],
            tx: self.t * x,
        }
    }

    /// The part of segment `a → b` in the wedge: clipped exactly by both
    /// edges' lines, its `X` range cut at `X ≥ X_min`; `None` when nothing
    /// is left.
    #[inline(always)]
    pub(crate) fn part(&self, a: &WVertex, b: &WVertex) -> Option<(f32, f32)> {
        let (mut l0, mut l1) = (a.x, b.x);
        if !(a.inside() && b.inside()) {
            let (t0, t1) = clip(a, b)?;
            let dl = b.x - a.x;
            if t0 != 0.0 {
                l0 = a.x + t0 * dl;
            }
            if t1 != 1.0 {
                l1 = a.x + t1 * dl;
            }
        }
        let (lo, hi) = if l0 <= l1 { (l0, l1) } else { (l1, l0) };
        // At X ≥ X_min only. (A NaN fails.)
        let lo = if lo > self.x_min {
            lo
        } else if hi >= self.x_min {
            self.x_min
        } else {
            return None;
        };
        Some((lo, hi))
    }

    /// Whether segment `a → b` certainly has no part ([`Self::part`] gives
    /// `None`): both ends' `X` below `X_min` by more than the clip's
    /// interpolation can round (`X_a + t (X_b − X_a)` is within `3.1 · 2⁻²⁴
    /// (|X_a| + |X_b|)` of the exact value, which is at most the larger
    /// `X`; the margin taken is `8 · 2⁻²⁴`).
    #[inline(always)]
    pub(crate) fn before(&self, a: &WVertex, b: &WVertex) -> bool {
        fmax(a.x, b.x) + (a.x.abs() + b.x.abs()) * 4.77e-7 < self.x_min
    }

    /// Whether a piece with the `X` range `[lo, hi]` is grazing (module
    /// docs); it stays so as the piece grows.
    #[inline(always)]
    pub(crate) fn grazing(&self, lo: f32, hi: f32, cot_twice: f32) -> bool {
        hi - lo > (self.t * cot_twice) * lo + self.g0
    }

    /// `best` lowered to the exact line's crossing of segment `a → b`, if
    /// it has one (its ends on the line's two sides) nearer than `best`
    /// and beyond `X_min`.
    #[inline(always)]
    pub(crate) fn crossing(&self, a: &WVertex, b: &WVertex, best: f32) -> f32 {
        let (sa, sb) = (a.y, b.y);
        if crate::depth::side_bit(sa) != crate::depth::side_bit(sb) {
            let x = a.x + sa / (sa - sb) * (b.x - a.x);
            if x < best && x > self.x_min {
                return x;
            }
        }
        best
    }

    /// The point of the exact line at `X` (for a crossing: the frame-2
    /// point, on the polyline up to rounding): `p₁' + d (X − R)/R`.
    #[inline(always)]
    pub(crate) fn point_at(&self, x: f32) -> [f32; 2] {
        let f = (x - self.r2) * self.inv_r2;
        [self.p[0] + f * self.d[0], self.p[1] + f * self.d[1]]
    }

    /// The depth estimate and the stick's ends in the compensated frame,
    /// `(s, s_near, s_far)` (module docs), for `w` = [`stick_w`]`(W')`, from
    /// the crossing's `X` and the piece's range; `None` when the far end is
    /// unbounded (the disparity is not larger than its error).
    #[inline(always)]
    pub(crate) fn depths(
        &self,
        [w, w_up, w_down]: [f32; 3],
        r1: f32,
        (x, lo, hi): (f32, f32, f32),
    ) -> Option<(f32, f32, f32)> {
        let r2 = self.r2;
        let den_far = (lo - r2) - self.rho_re;
        // (A NaN fails.)
        if !(den_far > 0.0) {
            return None;
        }
        let rr1 = self.rho * r1;
        let s = w + w * (r2 / (x - r2));
        let s_far = w_up + w_up * ((r2 + rr1) / den_far);
        let s_near = w_down + w_down * ((r2 - rr1) / ((hi - r2) + self.rho_re));
        Some((s, s_near, s_far))
    }

    /// Whether the stick of a walk's `outcome` is to be tightened by the
    /// lines of the piece's segments (module docs, "The stick from the
    /// piece's lines"): a match whose stick from the piece's range is
    /// unbounded, or whose far end's disparity is under [`REFINE_GAP`]
    /// times `r₁ + e₂`. Then the piece's end, one past its last segment.
    #[inline(always)]
    pub(crate) fn refines(&self, outcome: &Outcome) -> Option<usize> {
        match *outcome {
            // (A NaN refines.)
            Outcome::Match { lo, end, .. }
                if end != 0 && !((lo - self.r2) - self.rho_re > REFINE_GAP * self.rho_re) =>
            {
                Some(end)
            }
            _ => None,
        }
    }

    /// The first segment of the piece that ends at `end`: the walk took
    /// every segment with a part in the wedge, and found one piece, so
    /// the piece's segments are those before `end` back to the first
    /// without a part. At most the piece's segments, each of which the
    /// walk paid for, and one more (which it may not have looked at).
    fn piece_start(&self, b2: &[Pixel], end: usize) -> Option<usize> {
        let mut first = end.checked_sub(1)?;
        let mut vb = self.vertex(b2.get(first)?.arr());
        while let Some(v) = first.checked_sub(1).and_then(|i| b2.get(i)) {
            let va = self.vertex(v.arr());
            if self.part(&va, &vb).is_none() {
                break;
            }
            (first, vb) = (first - 1, va);
        }
        Some(first)
    }

    /// For a walk whose outcome [`Self::refines`]: the crossing's `X` and
    /// the stick, from the piece that ends at `end` alone (`W' = w`). The
    /// piece's range and nearest crossing come out as the walk computed
    /// them (the same operations in the same order: the same bits), so the
    /// walk's outcome need not be kept; the stick is tightened by the
    /// segments' lines (module docs, "The stick from the piece's lines"),
    /// or is [`Self::depths`]'s where they give no bounded one. `None`
    /// only when the piece is not found again (not reached: the walk found
    /// it with this wedge). Out of line: the usual point does not take it.
    /// Two passes over the piece's segments (and one more), each of which
    /// the walk paid for; the lines' bounds of a segment (its normal's and
    /// the chord's, the dear part) cost [`REFINE_UNITS`] more from
    /// `credit`, and a segment the credit cannot pay for keeps the bound
    /// from its range (the stick of [`Self::depths`] over that segment):
    /// valid, only less tight. The third value says whether a segment went
    /// unpaid (then an unbounded stick is the budget's doing, not the
    /// geometry's).
    #[inline(never)]
    pub(crate) fn refined(
        &self,
        b2: &[Pixel],
        end: usize,
        (w, r1): ([f32; 3], f32),
        credit: &mut u32,
    ) -> Option<(f32, Option<Depths>, bool)> {
        let first = self.piece_start(b2, end)?;
        let (v0, rest) = b2.get(first..=end)?.split_first()?;
        let last = rest.last()?;
        let r2 = self.r2;
        let pr1 = self.rho * r1;
        let p1 = (r2, pr1, self.rho_re);
        let mut va = self.vertex(v0.arr());
        // The segments the credit pays for, from the first.
        let segments = u32::try_from(rest.len()).unwrap_or(u32::MAX);
        let paid = (*credit / REFINE_UNITS).min(segments);
        *credit -= paid * REFINE_UNITS;
        // The normal of the piece's chord, one direction for every paid
        // segment (none: not needed).
        let chord = if paid > 0 {
            Direction::normal_of(&va, &self.vertex(last.arr()), p1)
        } else {
            None
        };
        let (mut lo, mut hi, mut best) = (0.0, 0.0, f32::INFINITY);
        // The largest and the smallest `t = k/(1 − k)` (`k = ρ(p₁)/ρ(p₂)`)
        // any segment allows: `s = W' (1 + t)`.
        let (mut t_far, mut t_near) = (0.0f32, f32::INFINITY);
        for (i, v) in rest.iter().enumerate() {
            let vb = self.vertex(v.arr());
            let (lo_j, hi_j) = self.part(&va, &vb)?;
            (lo, hi) = if i == 0 {
                (lo_j, hi_j)
            } else {
                (fmin(lo, lo_j), fmax(hi, hi_j))
            };
            best = self.crossing(&va, &vb, best);
            // The central ray, as [`Self::depths`] has it.
            let den = (lo_j - r2) - self.rho_re;
            let mut far = if den > 0.0 {
                (r2 + pr1) / den
            } else {
                f32::INFINITY
            };
            let mut near = (r2 - pr1) / ((hi_j - r2) + self.rho_re);
            // The segment's own normal, and the chord's, where the credit
            // pays for them.
            if (i as u64) < u64::from(paid) {
                for dir in [Direction::normal_of(&va, &vb, p1), chord].iter().flatten() {
                    let (f, n) = dir.bounds(&va, &vb, r2);
                    far = fmin(far, f);
                    near = fmax(near, n);
                }
            }
            t_far = fmax(t_far, far);
            t_near = fmin(t_near, near);
            va = vb;
        }
        if best == f32::INFINITY {
            return None;
        }
        let x = fmin(fmax(best, lo), hi);
        // (A NaN fails.)
        if !(t_far < f32::INFINITY) || !(t_near >= 0.0) {
            return Some((x, self.depths(w, r1, (x, lo, hi)), paid < segments));
        }
        let [w, w_up, w_down] = w;
        let s = w + w * (r2 / (x - r2));
        let s_far = w_up + w_up * t_far;
        let s_near = w_down + w_down * t_near;
        // (Rounding aside, the estimate's own ratio `R/X` lies between.)
        Some((
            x,
            Some((s, fmin(s_near, s), fmax(s_far, s))),
            paid < segments,
        ))
    }
}

/// [`Wedge::refines`] a stick whose far end's disparity (from the
/// piece's range) is under this many times `r₁ + e₂`: there the lines can
/// take up to about `0.9 (r₁ + e₂)` off it near the minimum angle
/// (module docs; `0.59 (r₁ + e₂)` at 45°, about `0.3` at 70°), a tenth or
/// more of such a disparity below about 70°. (At 10 the refinement would still shorten far ends by up to a
/// tenth, but the demo's costliest frame would refine 70 of its points,
/// +11 %; `docs/PERFORMANCE.md`.)
pub(crate) const REFINE_GAP: f32 = 4.0;

/// Work units [`Wedge::refined`] pays for a segment's lines (its normal
/// and the chord's bounds: two divisions each, a reciprocal square root),
/// on top of what the walk paid to clip it. A paid segment costs about 245
/// instructions more than an unpaid one (measured on the bench's `+e_3`
/// probes against a build that charges but skips the bounds), so at four
/// units a unit of it costs about 61, less than the band path's (`docs/VEHICLE.md`,
/// "Worst case": `C_U`, 120 today); at two it would cost about 122.
pub(crate) const REFINE_UNITS: u32 = 4;

/// A depth estimate and the stick's ends in the compensated frame, `(s,
/// s_near, s_far)` ([`Wedge::depths`]).
pub(crate) type Depths = (f32, f32, f32);

/// `1 + 2⁻²¹` and `1 − 2⁻²¹`: the stick's ends rounded outwards (from the
/// piece's range, [`Wedge::depths`], and from its lines), a margin on top
/// of what carries the rounding. They are folded into `W'` once a frame
/// ([`stick_w`]): an end `s = W'(1 + t)` is computed as `W'↑ + W'↑ t`
/// with `W'↑ = fl(W' · STICK_UP)`, at least `W'(1 + t)(1 + 2⁻²¹)(1 −
/// 2⁻²⁴)³ > W'(1 + t)(1 + 5 · 2⁻²⁴)`, the same margin as the factor
/// applied to the rounded end (and the reverse at the near end, where
/// `1 + t > 0` or the end is no bound). With `W' > 0` (the wedge path)
/// each operation stays monotone, so the ends still hold the estimate
/// `W' + W' R/(X − R)`. What carries the rounding is the slack `δ = 2⁻²⁰ S` in `r₁` and `e₂` ([`crate::depth`]):
/// besides the coordinates' rounding it moves each end outwards by at
/// least about `δ/D` relative (`D` the end's disparity, less its error),
/// which grows as the cancellations in the ends' denominators do. The
/// ends' own arithmetic (the inputs of the central ray's bound, `t`'s
/// quotient, `w + w t`) rounds by a few `2⁻²⁴` relative, which `δ/D`
/// covers unless `D` approaches the frame's whole scale `S`; this factor
/// covers it there too. (An independent review found that
/// `refined_stick_holds_every_consistent_depth`, its truth at 0.999 of
/// each error, passes with every widening of the refinement removed, and
/// fails at exactly the errors with them in place: the slack, not these
/// widenings, is what that test sees.)
const STICK_UP: f32 = 1.0 + 4.768_371_6e-7;
const STICK_DOWN: f32 = 1.0 - 4.768_371_6e-7;

/// `[W', W' · STICK_UP, W' · STICK_DOWN]`, what [`Wedge::depths`] and
/// [`Wedge::refined`] take for `W'` (the outward rounding folded in once a
/// frame, [`STICK_UP`]).
#[inline(always)]
pub(crate) fn stick_w(w: f32) -> [f32; 3] {
    [w, w * STICK_UP, w * STICK_DOWN]
}

/// A direction `u` in the wedge's frame (not unit: `|u| ≤ l`), oriented so
/// that the segment it was made from lies on its positive side, with what
/// its bounds on `t = k/(1 − k)` share (module docs, "The stick from the
/// piece's lines"): over the frame-1 error disc about `P₁' = (R, 0)`,
/// `u·P₁ ≤ n_far` and `u·P₁ ≥ n_near` (`u_x R ± ρ₊ r₁ l`, with the
/// rounding of `u_x R`), and `ρ₊ (r₁ + e₂) l`.
#[derive(Clone, Copy)]
struct Direction {
    u: [f32; 2],
    n_far: f32,
    n_near: f32,
    re_l: f32,
}

impl Direction {
    /// The normal of the line through `a` and `b`, on `a`'s positive side,
    /// for `p1 = (R, ρ₊ r₁, ρ₊ (r₁ + e₂))`; `None` when they are (nearly)
    /// one point.
    #[inline(always)]
    fn normal_of(a: &WVertex, b: &WVertex, (r2, pr1, pre): (f32, f32, f32)) -> Option<Self> {
        let (dx, dy) = (b.x - a.x, b.y - a.y);
        let l2 = dx * dx + dy * dy;
        // (A NaN fails.)
        if !(l2 > 1.0e-30 && l2 < 1.0e30) {
            return None;
        }
        let along_a = dy * a.x - dx * a.y;
        let u = if along_a < 0.0 { [-dy, dx] } else { [dy, -dx] };
        // `l ≥ |u|` (`rsqrt_pos`, no division; the sum within 2⁻²³).
        let l = ((l2 * rsqrt_pos(l2)) * RSQRT_UP) * RSQRT_UP;
        let ux_r = u[0] * r2;
        // `u_x R`'s rounding, 4 times over.
        let err = ux_r.abs() * 2.384_185_8e-7;
        Some(Self {
            u,
            n_far: ux_r + err + pr1 * l,
            n_near: ux_r - err - pr1 * l,
            re_l: pre * l,
        })
    }

    /// `u·(v − P₁')`, computed as `u_x (X − R) + u_y Y`, lowered (`−`) and
    /// raised (`+`) by its rounding, 4 times over (`X − R` is exact where
    /// `R/2 ≤ X ≤ 2R`, Sterbenz, and within `2⁻²⁴` of itself where not).
    #[inline(always)]
    fn beyond(&self, v: &WVertex, r2: f32) -> (f32, f32) {
        let (p, q) = (self.u[0] * (v.x - r2), self.u[1] * v.y);
        let err = (p.abs() + q.abs()) * 4.768_371_6e-7;
        let g = p + q;
        (g - err, g + err)
    }

    /// The bounds `(t_far, t_near)` on `t` if the true `P₂` is within
    /// `ρ₊ e₂` of segment `a → b` (`+∞` and `0` where this direction gives
    /// none).
    #[inline(always)]
    fn bounds(&self, a: &WVertex, b: &WVertex, r2: f32) -> (f32, f32) {
        let ((la, ha), (lb, hb)) = (self.beyond(a, r2), self.beyond(b, r2));
        // `min u·P₂ − max u·P₁` and `max u·P₂ − min u·P₁`.
        let gap_lo = fmin(la, lb) - self.re_l;
        let gap_hi = fmax(ha, hb) + self.re_l;
        // (A NaN fails.)
        let far = if self.n_far > 0.0 && gap_lo > 0.0 {
            self.n_far / gap_lo
        } else {
            f32::INFINITY
        };
        let near = if self.n_near > 0.0 && gap_hi > 0.0 {
            self.n_near / gap_hi
        } else {
            0.0
        };
        (far, near)
    }
}

/// The part of the segment `a → b` inside both edges' lines (the side of
/// `d` is inside), as its range `(t0, t1)` along the segment; `None` when
/// it has none.
#[inline(always)]
fn clip(a: &WVertex, b: &WVertex) -> Option<(f32, f32)> {
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    // The `−` edge (T X − Y), then the `+` edge (T X + Y).
    let (ca, cb) = (a.tx - a.y, b.tx - b.y);
    if ca < 0.0 {
        if cb < 0.0 {
            return None;
        }
        t0 = ca / (ca - cb);
    } else if cb < 0.0 {
        t1 = ca / (ca - cb);
    }
    let (ca, cb) = (a.tx + a.y, b.tx + b.y);
    if ca < 0.0 {
        if cb < 0.0 {
            return None;
        }
        t0 = fmax(t0, ca / (ca - cb));
    } else if cb < 0.0 {
        t1 = fmin(t1, ca / (ca - cb));
    }
    // (A NaN fails.)
    (t0 <= t1).then_some((t0, t1))
}

/// The wedge's key interval from its edges' own keys, each widened by its
/// margin (a wide wedge, `T > 1/8`, or a point without a key): for `d`,
/// `T`, and the keys as in [`Wedge::new`].
#[cold]
#[inline(never)]
fn exact_keys(d: [f32; 2], t: f32, side: f32, key_scale: f32, orient: f32) -> (f32, f32) {
    // The edge directions d ∓ s T d⊥ (d⊥ = (−d_v, d_u)), named so that
    // the first has the lower key: turning d by +90° moves its key by
    // −side, then the orientation (s = ±1, so the products are those of
    // d ± T d⊥ exactly).
    let s = if side * orient > 0.0 { -1.0 } else { 1.0 };
    let st = s * t;
    let el = [d[0] + st * d[1], d[1] - st * d[0]];
    let eh = [d[0] - st * d[1], d[1] + st * d[0]];
    edge_keys(d, (el, eh, s), side, key_scale, orient)
}

/// The wedge's key interval in general: the keys of the edge directions
/// `el`, `eh` (named as in [`Wedge::new`]), each widened by its margin; an
/// edge outside the half-plane stands for the key limit where the wedge
/// crosses the FOE's row, on the side of `d` (the wedge is narrower than
/// 53°); the lower key is the low end. When the whole wedge lies beyond
/// the row no keyed point is in it, and the interval is `(−∞, −∞)`: it
/// meets only the intervals of segments with an unkeyed end (frame 2's
/// `(−∞, ∞)`, [`crate::search`]), and a walk's tests of a segment's low
/// end against it (`lo ≤ kh`, `sm > kh`) reject every other
/// segment and end the run at the first one past them. (As the empty
/// `(∞, −∞)`, the same segments meet it, but those tests took every
/// finite low end for one below the query.)
#[inline(always)]
fn edge_keys(
    d: [f32; 2],
    (el, eh, s): ([f32; 2], [f32; 2], f32),
    side: f32,
    key_scale: f32,
    orient: f32,
) -> (f32, f32) {
    let limit = orient * if d[0] >= 0.0 { 1.0 } else { -1.0 };
    let key = |e: [f32; 2]| {
        let te = side * e[1];
        if te > 0.0 {
            let i = 1.0 / (e[0].abs() + te);
            (orient * (e[0] * i), key_scale * i + ULP20, true)
        } else {
            (limit, 0.0, false)
        }
    };
    let ((k0, m0, in0), (k1, m1, in1)) = (key(el), key(eh));
    // The first edge's is the lower key on a tie when it is d − T d⊥'s.
    let first_low = if s > 0.0 { k0 <= k1 } else { k0 < k1 };
    if !(side * d[1] > 0.0 || in0 || in1) {
        // The whole wedge lies beyond the FOE's row: no keyed point.
        return (f32::NEG_INFINITY, f32::NEG_INFINITY);
    }
    if first_low {
        (k0 - m0, k1 + m1)
    } else {
        (k1 - m1, k0 + m0)
    }
}

/// A frame-2 vertex in a wedge's frame ([`Wedge::vertex`]): `X`, `Y` and
/// `T X`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct WVertex {
    x: f32,
    y: f32,
    tx: f32,
}

impl WVertex {
    /// A placeholder, never read before it is overwritten.
    pub(crate) const NONE: WVertex = WVertex {
        x: 0.0,
        y: 0.0,
        tx: 0.0,
    };

    /// Whether both edge values are at least 0, `|Y| ≤ T X` (`T X − Y ≥ 0`
    /// exactly when `T X ≥ Y` in IEEE arithmetic, and `T X + Y ≥ 0` when
    /// `T X ≥ −Y`). (A NaN fails.)
    #[inline(always)]
    fn inside(&self) -> bool {
        self.y.abs() <= self.tx
    }
}

/// The walk over a polyline's segments through one wedge (the rules of
/// [`crate::matching`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct WedgeWalk {
    /// The segment that continues the piece (`usize::MAX`: none yet).
    next: usize,
    lo: f32,
    hi: f32,
    /// The nearest crossing's `X` (infinite: none).
    best: f32,
    open: bool,
}

impl WedgeWalk {
    pub(crate) const NEW: WedgeWalk = WedgeWalk {
        next: usize::MAX,
        lo: 0.0,
        hi: 0.0,
        best: f32::INFINITY,
        open: false,
    };

    /// Take segment `j` from vertex `a` to vertex `b`, whose key interval
    /// (oriented, [`crate::search`]) is `(klo, khi)`, of a polyline of
    /// `segments` segments; segments come in increasing index. `Err` when
    /// the outcome is decided ([`Status::Ambiguous`] or
    /// [`Status::Grazing`]).
    #[inline(always)]
    pub(crate) fn take(
        &mut self,
        wedge: &Wedge,
        j: usize,
        (a, b): (&WVertex, &WVertex),
        (klo, khi): (f32, f32),
        segments: usize,
        cot_twice: f32,
    ) -> Result<(), Status> {
        if klo > wedge.kh || khi < wedge.kl {
            return Ok(());
        }
        self.take_met(wedge, j, (a, b), segments, cot_twice)
    }

    /// [`Self::take`] for a segment whose interval meets the wedge's.
    #[inline(always)]
    pub(crate) fn take_met(
        &mut self,
        wedge: &Wedge,
        j: usize,
        (a, b): (&WVertex, &WVertex),
        segments: usize,
        cot_twice: f32,
    ) -> Result<(), Status> {
        let Some((lo, hi)) = wedge.part(a, b) else {
            return Ok(());
        };
        if self.next == j {
            self.lo = fmin(self.lo, lo);
            self.hi = fmax(self.hi, hi);
        } else {
            if self.next != usize::MAX {
                return Err(Status::Ambiguous);
            }
            self.lo = lo;
            self.hi = hi;
            if j == 0 {
                self.open |= end_inside((a.x, a.y, a.tx), wedge.x_min);
            }
        }
        if j + 1 == segments {
            self.open |= end_inside((b.x, b.y, b.tx), wedge.x_min);
        }
        self.next = j + 1;
        if wedge.grazing(self.lo, self.hi, cot_twice) {
            return Err(Status::Grazing);
        }
        self.best = wedge.crossing(a, b, self.best);
        Ok(())
    }

    /// The outcome once the segments are through (in `X`, [`Wedge::vertex`]).
    #[inline(always)]
    pub(crate) fn outcome(&self) -> Outcome {
        if self.open {
            return Outcome::Flag(Status::BoundaryEnd);
        }
        if self.next == usize::MAX || self.best == f32::INFINITY {
            return Outcome::Flag(Status::NoIntersection);
        }
        Outcome::Match {
            lam: fmin(fmax(self.best, self.lo), self.hi),
            lo: self.lo,
            hi: self.hi,
            end: self.next,
        }
    }
}

/// Whether an end vertex `a` of the polyline lies in the wedge
/// (both edge values at least 0, `X ≥ X_min`). (Out of line, its arguments by value: the walk's
/// usual segment is no end, and its values stay in registers.)
#[cold]
#[inline(never)]
fn end_inside((x, y, tx): (f32, f32, f32), x_min: f32) -> bool {
    y.abs() <= tx && x >= x_min
}

/// A wedge walk as an index [`Visitor`], for the reference matcher (the
/// indexed path walks the index's runs itself): the wedge, the polyline,
/// the last vertex (reused along a run) and the walk.
#[derive(Clone, Copy)]
pub(crate) struct WedgeWalker<'a> {
    wedge: Wedge,
    boundary: &'a [Pixel],
    cot_twice: f32,
    cache_i: usize,
    cache: WVertex,
    walk: WedgeWalk,
    decided: Option<Status>,
}

impl<'a> WedgeWalker<'a> {
    pub(crate) fn new(wedge: Wedge, boundary: &'a [Pixel], cot_twice: f32) -> Self {
        Self {
            wedge,
            boundary,
            cot_twice,
            cache_i: usize::MAX,
            cache: WVertex::NONE,
            walk: WedgeWalk::NEW,
            decided: None,
        }
    }

    #[inline(always)]
    fn vertex(&mut self, i: usize) -> Option<WVertex> {
        if self.cache_i == i {
            return Some(self.cache);
        }
        let v = self.boundary.get(i)?;
        self.cache = self.wedge.vertex(v.arr());
        self.cache_i = i;
        Some(self.cache)
    }

    /// The walk's outcome.
    pub(crate) fn outcome(&self) -> Outcome {
        match self.decided {
            Some(s) => Outcome::Flag(s),
            None => self.walk.outcome(),
        }
    }
}

impl Visitor<'_> for WedgeWalker<'_> {
    #[inline(always)]
    fn segment(&mut self, j: usize, interval: (f32, f32)) -> (Flow, u32) {
        let (Some(a), Some(b)) = (self.vertex(j), self.vertex(j + 1)) else {
            return (Flow::Continue, 0);
        };
        let segments = self.boundary.len().saturating_sub(1);
        let wedge = self.wedge;
        match self
            .walk
            .take(&wedge, j, (&a, &b), interval, segments, self.cot_twice)
        {
            Ok(()) => (Flow::Continue, CLIP_UNITS),
            Err(s) => {
                self.decided = Some(s);
                (Flow::Stop, CLIP_UNITS)
            }
        }
    }
}

#[cfg(test)]
mod tests;
