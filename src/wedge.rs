//! The usual case of the matching stage: forward motion (`W' > 0`), no
//! translation error, and a frame-2 boundary on one side of the FOE's row
//! (half-plane keys, [`crate::pencil`]). Here the error band of
//! [`crate::depth`] is replaced by a slightly larger region whose test is
//! mostly a comparison of keys the index already holds: the **wedge**.
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
//! # Keys decide most segments
//! The half-plane key is a strictly monotone function of a ray's angle
//! about `F` over the half-plane, and along a segment (which cannot pass
//! through `F`) the angle is monotone, so a segment's rays have the keys
//! between those of its end points. The wedge's rays have the keys between
//! those of its two edges (the edge directions `d ± T d⊥`, `d = p₁' − F`;
//! an edge outside the half-plane stands for the key limit `±1` on its
//! side, as the wedge leaves the half-plane through the FOE's row). With
//! every key widened by its rounding margin, a segment whose interval
//! ([`crate::search`]) misses the wedge's is outside it; one whose interval
//! lies inside the wedge's is taken whole (it reaches at most its keys'
//! margins past an edge, which only lengthens the piece: the stick stays a
//! bound); only a segment whose interval straddles an edge's key is
//! clipped by that edge's line, exactly (one division per edge it
//! crosses). The segment's part in the wedge then has the range `[λ₀, λ₁]`
//! of `λ = â·(q − p₁')` (`â = d/ρ₁`; `λ` is linear along the segment, so
//! the ends of the part give it), cut at `λ ≥ −(r₁ + e₂)`.
//!
//! The walk over the segments (in order, with the rules of
//! [`crate::matching`]: one piece, not grazing, no end vertex inside,
//! the exact line's nearest crossing for the estimate, where the segment's
//! ends lie on the line's two sides: a segment whose keys miss the line's,
//! widened by the margins, has both ends farther from the line than the
//! sides' rounding, so no key test is needed there) gives the piece's
//! range `[lo, hi]` and the crossing's `λ`, and with `|a| = W' ρ₁`
//! the depth and stick of [`crate::depth`] become
//!
//! `s = W' (1 + ρ₁/λ)`,   `s_far = W' (1 + (ρ₁ + r₁)/(lo − r₁ − e₂))`,
//! `s_near = W' (1 + (ρ₁ − r₁)/(hi + r₁ + e₂))`
//!
//! (numerators and denominators ordered as the IEEE operations keep them,
//! so the rounded stick holds the rounded estimate). A piece is grazing
//! when it is longer than the wedge's width at its near end over
//! `tan φ_min`, `hi − lo > T (ρ₁ + lo) · 2 cot φ_min`: a test that only
//! becomes true as the piece grows, so the walk may stop at the first
//! segment that makes it true and get the outcome a walk to the end would.
//!
//! # Rounding
//! `T` is rounded up by `2⁻¹⁶` relative; the edge directions, the keys and
//! the `λ`s are computed from coordinates below the frame's scale `S` and
//! are off by a few `2⁻²⁴ S` at most, which the slack of `2⁻²⁰ S` in `r₁`
//! and `e₂` covers (see [`crate::depth`]).

use crate::camera::Pixel;
use crate::matching::Outcome;
use crate::math::{dot, fmax, fmin, sqrt_pos, sub};
use crate::search::{Flow, Visitor, CLIP_UNITS};
use crate::structure::Status;

/// `2⁻²⁰`, the keys' rounding unit ([`crate::pencil`]).
const ULP20: f32 = 9.536_743e-7;

/// One point's wedge (see the module docs), in the index's oriented keys.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Wedge {
    foe: [f32; 2],
    /// `p₁'`, `d = p₁' − F`, `â = d/ρ₁`, `ρ₁`.
    p: [f32; 2],
    d: [f32; 2],
    u: [f32; 2],
    pub(crate) rho: f32,
    /// `T`, the tangent of the half-angle.
    t: f32,
    /// The wedge's key interval (oriented, widened by the edges' margins):
    /// the index query.
    pub(crate) kl: f32,
    pub(crate) kh: f32,
    /// Inward normals of the edges whose keys are `kl` and `kh`.
    nl: [f32; 2],
    nh: [f32; 2],
    /// `−(r₁ + e₂)`.
    pub(crate) lam_lo: f32,
}

/// A point without a wedge: it lies within `3 (r₁ + e₂)` of the FOE
/// ([`Status::AtFoe`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct AtFoe;

impl Wedge {
    /// The wedge of compensated point `p` for a FOE `foe`, the boundary on
    /// the `side` of its row (+1 below), errors `r1`, `e2`, keys with
    /// `key_scale` (`crate::pencil::Keying`) oriented by `orient`.
    #[inline(always)]
    pub(crate) fn new(
        p: [f32; 2],
        (foe, side): ([f32; 2], f32),
        (r1, e2): (f32, f32),
        key_scale: f32,
        orient: f32,
    ) -> Result<Self, AtFoe> {
        let d = sub(p, foe);
        let re = r1 + e2;
        let rho = sqrt_pos(dot(d, d));
        // (A NaN fails.)
        if !(rho > 3.0 * re) {
            return Err(AtFoe);
        }
        let inv = 1.0 / rho;
        let t = re / (rho - re) * (1.0 + 1.53e-5);
        // The edge directions d ∓ s T d⊥ (d⊥ = (−d_v, d_u)), named so that
        // the first has the lower key: turning d by +90° moves its key by
        // −side, then the orientation (s = ±1, so the products are those
        // of d ± T d⊥ exactly).
        let s = if side * orient > 0.0 { -1.0 } else { 1.0 };
        let st = s * t;
        let el = [d[0] + st * d[1], d[1] - st * d[0]];
        let eh = [d[0] - st * d[1], d[1] + st * d[0]];
        let (tl, th) = (side * el[1], side * eh[1]);
        let (kl, kh, nl, nh) = if tl > 0.0 && th > 0.0 {
            // Both edges in the half-plane (the usual wedge).
            let (il, ih) = (1.0 / (el[0].abs() + tl), 1.0 / (eh[0].abs() + th));
            let (k0, k1) = (orient * (el[0] * il), orient * (eh[0] * ih));
            if k0 < k1 {
                // Inward normals: s perp(e_l) and −s perp(e_h) point
                // towards d.
                (
                    k0 - (key_scale * il + ULP20),
                    k1 + (key_scale * ih + ULP20),
                    [-s * el[1], s * el[0]],
                    [s * eh[1], -s * eh[0]],
                )
            } else {
                edge_keys(d, (el, eh, s), side, key_scale, orient)
            }
        } else {
            edge_keys(d, (el, eh, s), side, key_scale, orient)
        };
        Ok(Self {
            foe,
            p,
            d,
            u: [d[0] * inv, d[1] * inv],
            rho,
            t,
            kl,
            kh,
            nl,
            nh,
            lam_lo: -re,
        })
    }

    /// A vertex in the wedge's frame: `w = v − F`, its `λ` and its side of
    /// the exact line.
    #[inline(always)]
    pub(crate) fn vertex(&self, v: [f32; 2]) -> WVertex {
        let w = sub(v, self.foe);
        WVertex {
            w,
            lam: dot(self.u, w) - self.rho,
            side: self.d[0] * w[1] - self.d[1] * w[0],
        }
    }

    /// The part of segment `a → b` in the wedge, as [`WedgeWalk::take`]
    /// takes a segment whose key interval meets the wedge's (`cut`: it
    /// reaches past the low edge's key, the high edge's): clipped by those
    /// edges, its `λ` range cut at `λ ≥ −(r₁ + e₂)`; `None` when nothing is
    /// left.
    #[inline(always)]
    pub(crate) fn part(&self, a: &WVertex, b: &WVertex, cut: (bool, bool)) -> Option<Part> {
        let dl = b.lam - a.lam;
        // The part's ends, and whether each is the segment's own end.
        let (mut l0, mut l1, mut whole) = (a.lam, b.lam, (true, true));
        if cut.0 || cut.1 {
            let (t0, t1) = self.clip(a, b, cut)?;
            if t0 != 0.0 {
                (l0, whole.0) = (a.lam + t0 * dl, false);
            }
            if t1 != 1.0 {
                (l1, whole.1) = (a.lam + t1 * dl, false);
            }
        }
        let (lo, hi) = if l0 <= l1 { (l0, l1) } else { (l1, l0) };
        // At λ ≥ −(r₁ + e₂) only. (A NaN fails.)
        let lo = if lo > self.lam_lo {
            lo
        } else if hi >= self.lam_lo {
            self.lam_lo
        } else {
            return None;
        };
        Some(Part { lo, hi, whole })
    }

    /// Whether a piece with the `λ` range `[lo, hi]` is grazing (module
    /// docs); it stays so as the piece grows.
    #[inline(always)]
    pub(crate) fn grazing(&self, lo: f32, hi: f32, cot_twice: f32) -> bool {
        hi - lo > self.t * (self.rho + lo) * cot_twice
    }

    /// `best` lowered to the exact line's crossing of segment `a → b`, if
    /// it has one (its ends on the line's two sides) nearer than `best`
    /// and beyond `λ = −(r₁ + e₂)`.
    #[inline(always)]
    pub(crate) fn crossing(&self, a: &WVertex, b: &WVertex, best: f32) -> f32 {
        let (sa, sb) = (a.side, b.side);
        if crate::depth::side_bit(sa) != crate::depth::side_bit(sb) {
            let lam = a.lam + sa / (sa - sb) * (b.lam - a.lam);
            if lam < best && lam > self.lam_lo {
                return lam;
            }
        }
        best
    }

    /// The part of the segment `a → b` inside the edges' lines where `cut`
    /// says (low edge, high edge; the side towards `d` is inside), as its
    /// range `(t0, t1)` along the segment; `None` when it has none.
    #[inline(always)]
    fn clip(&self, a: &WVertex, b: &WVertex, cut: (bool, bool)) -> Option<(f32, f32)> {
        let (mut t0, mut t1) = (0.0f32, 1.0f32);
        for (cut, n) in [(cut.0, self.nl), (cut.1, self.nh)] {
            if cut {
                let (ca, cb) = (dot(n, a.w), dot(n, b.w));
                if ca < 0.0 {
                    if cb < 0.0 {
                        return None;
                    }
                    t0 = fmax(t0, ca / (ca - cb));
                } else if cb < 0.0 {
                    t1 = fmin(t1, ca / (ca - cb));
                }
            }
        }
        // (A NaN fails.)
        (t0 <= t1).then_some((t0, t1))
    }

    /// The point of the exact line at `λ` (for a crossing: the frame-2
    /// point, on the polyline up to rounding).
    #[inline(always)]
    pub(crate) fn point_at(&self, lam: f32) -> [f32; 2] {
        [self.p[0] + lam * self.u[0], self.p[1] + lam * self.u[1]]
    }

    /// The depth estimate and the stick's ends in the compensated frame,
    /// `(s, s_near, s_far)` (module docs), for `w = W'`; `None` when the
    /// far end is unbounded (the disparity is not larger than its error).
    #[inline(always)]
    pub(crate) fn depths(
        &self,
        w: f32,
        r1: f32,
        (lam, lo, hi): (f32, f32, f32),
    ) -> Option<(f32, f32, f32)> {
        let den_far = lo + self.lam_lo;
        // (A NaN fails.)
        if !(den_far > 0.0) {
            return None;
        }
        let s = w + w * (self.rho / lam);
        let s_far = w + w * ((self.rho + r1) / den_far);
        let s_near = w + w * ((self.rho - r1) / (hi - self.lam_lo));
        Some((s, s_near, s_far))
    }
}

/// The wedge's key interval and the inward normals of the edges whose
/// keys bound it, in general: the keys of the edge directions `el`, `eh`
/// (named as in [`Wedge::new`]), each widened by its margin; an edge
/// outside the half-plane stands for the key limit where the wedge crosses
/// the FOE's row, on the side of `d` (the wedge is narrower than 53°); the
/// lower key is the low end (the first edge's on a tie), and the interval
/// is empty when the whole wedge lies beyond the row.
#[cold]
#[inline(never)]
fn edge_keys(
    d: [f32; 2],
    (el, eh, s): ([f32; 2], [f32; 2], f32),
    side: f32,
    key_scale: f32,
    orient: f32,
) -> (f32, f32, [f32; 2], [f32; 2]) {
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
    // Inward normals: s perp(e_l) and −s perp(e_h) point towards d.
    let (n0, n1) = ([-s * el[1], s * el[0]], [s * eh[1], -s * eh[0]]);
    // The first edge's is the lower key on a tie when it is d − T d⊥'s.
    let first_low = if s > 0.0 { k0 <= k1 } else { k0 < k1 };
    let (kl, nl, kh, nh) = if first_low {
        (k0 - m0, n0, k1 + m1, n1)
    } else {
        (k1 - m1, n1, k0 + m0, n0)
    };
    if !(side * d[1] > 0.0 || in0 || in1) {
        // The whole wedge lies beyond the FOE's row: no keyed point.
        return (f32::INFINITY, f32::NEG_INFINITY, nl, nh);
    }
    (kl, kh, nl, nh)
}

/// A frame-2 vertex in a wedge's frame ([`Wedge::vertex`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct WVertex {
    w: [f32; 2],
    lam: f32,
    side: f32,
}

impl WVertex {
    /// A placeholder, never read before it is overwritten.
    pub(crate) const NONE: WVertex = WVertex {
        w: [0.0; 2],
        lam: 0.0,
        side: 0.0,
    };
}

/// A segment's part in a wedge ([`Wedge::part`]): its `λ` range, and
/// whether each end is the segment's own (no edge cut it off).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Part {
    pub(crate) lo: f32,
    pub(crate) hi: f32,
    whole: (bool, bool),
}

/// The walk over a polyline's segments through one wedge (the rules of
/// [`crate::matching`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct WedgeWalk {
    /// The segment that continues the piece (`usize::MAX`: none yet).
    next: usize,
    lo: f32,
    hi: f32,
    /// The nearest crossing's `λ` (infinite: none).
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
        let cut = (klo < wedge.kl, khi > wedge.kh);
        self.take_met(wedge, j, (a, b), cut, segments, cot_twice)
    }

    /// [`Self::take`] for a segment whose interval meets the wedge's;
    /// `cut`: whether it reaches past the low edge's key, and past the
    /// high edge's.
    #[inline(always)]
    pub(crate) fn take_met(
        &mut self,
        wedge: &Wedge,
        j: usize,
        (a, b): (&WVertex, &WVertex),
        cut: (bool, bool),
        segments: usize,
        cot_twice: f32,
    ) -> Result<(), Status> {
        let Some(part) = wedge.part(a, b, cut) else {
            return Ok(());
        };
        let (lo, hi) = (part.lo, part.hi);
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
                // The first vertex is in the wedge when no edge cut it off.
                self.open |= end_inside(part.whole.0, a.lam, wedge.lam_lo);
            }
        }
        if j + 1 == segments {
            self.open |= end_inside(part.whole.1, b.lam, wedge.lam_lo);
        }
        self.next = j + 1;
        if wedge.grazing(self.lo, self.hi, cot_twice) {
            return Err(Status::Grazing);
        }
        self.best = wedge.crossing(a, b, self.best);
        Ok(())
    }

    /// The outcome once the segments are through (`λ` in pixels).
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
        }
    }
}

/// Whether an end vertex of the polyline lies in the wedge: no edge cut
/// it off (`whole`) and its `λ` is at least `lam_lo`. (Out of line: the
/// walk's usual segment is no end.)
#[cold]
#[inline(never)]
fn end_inside(whole: bool, lam: f32, lam_lo: f32) -> bool {
    whole && lam >= lam_lo
}

/// A wedge walk as an index [`Visitor`] (the loose index, and the
/// reference): the wedge, the polyline, the last vertex (reused along a
/// run) and the walk.
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

impl Visitor for WedgeWalker<'_> {
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
mod tests {
    use super::*;
    use crate::depth::{Band, PointErrors};
    use crate::test_rng::Rng;

    /// Every point the band holds (a true frame-1 point within `r₁`, any
    /// depth, a polyline point within `e₂` of its correspondent, computed in
    /// `f64`) lies in the wedge: its key interval meets the wedge's, and
    /// the wedge walk takes it as a piece (`W' > 0`, no translation error;
    /// keys on either side of the FOE's row).
    #[test]
    fn wedge_holds_every_band_point() {
        let mut rng = Rng(0x3ed9_e001);
        let mut inside = 0;
        let key_scale = 9.536_743e-7 * 1024.0;
        for case in 0..40_000 {
            let w = 0.05 + rng.next();
            let g = [(rng.next() - 0.5) * 300.0, (rng.next() - 0.5) * 300.0];
            let c2 = [255.5f32, 239.5];
            let foe = [c2[0] + g[0] / w, c2[1] + g[1] / w];
            let p = [512.0 * rng.next(), 480.0 * rng.next()];
            let (r1, e2) = (0.05 + rng.next(), 0.05 + rng.next());
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
            let s = wf + 0.01 + 60.0 * f64::from(rng.next()) * f64::from(rng.next());
            let tau = 1.0 / (s - wf);
            let p2 = [pt[0] + tau * at[0], pt[1] + tau * at[1]];
            let ang2 = rng.next() * core::f32::consts::TAU;
            let rad2 = f64::from(e2) * f64::from(rng.next());
            let q = [
                (p2[0] + rad2 * f64::from(libm::cosf(ang2))) as f32,
                (p2[1] + rad2 * f64::from(libm::sinf(ang2))) as f32,
            ];
            // The boundary's side of the FOE's row: q's, and q keyed.
            let dq = [q[0] - foe[0], q[1] - foe[1]];
            let side = if dq[1] >= 0.0 { 1.0 } else { -1.0 };
            let t = side * dq[1];
            if !(t >= 4.0 && q[0].abs() < 3000.0 && q[1].abs() < 3000.0) {
                continue;
            }
            let orient = if rng.next() < 0.5 { 1.0 } else { -1.0 };
            let Ok(wedge) = Wedge::new(p, (foe, side), (r1, e2), key_scale, orient) else {
                continue;
            };
            let i = 1.0 / (dq[0].abs() + t);
            let (k, m) = (orient * (dq[0] * i), key_scale * i + ULP20);
            assert!(
                k + m >= wedge.kl && k - m <= wedge.kh,
                "case {case}: key {k} ± {m} outside [{}, {}]",
                wedge.kl,
                wedge.kh
            );
            let v = wedge.vertex(q);
            let mut walk = WedgeWalk::NEW;
            let r = walk.take(&wedge, 5, (&v, &v), (k - m, k + m), 10, 11.34);
            assert!(
                walk.next == 6 || r == Err(Status::Grazing),
                "case {case}: q {q:?} not in the wedge of {p:?} (foe {foe:?})"
            );
            // And the band itself holds it (the wedge is the larger).
            let band = Band::new(
                p,
                [w * (p[0] - c2[0]) - g[0], w * (p[1] - c2[1]) - g[1]],
                w,
                &PointErrors {
                    r1,
                    e2,
                    spread_a: 0.0,
                    spread_w: 0.0,
                },
                0.0,
            );
            if let Ok(b) = band {
                let c = b.vertex(q);
                assert!(Band::contains(&c), "case {case}: q outside the band");
            }
            inside += 1;
        }
        assert!(inside > 5_000, "{inside}");
    }
}
