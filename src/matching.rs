//! Matching one frame-1 point: walk the frame-2 segments that meet its
//! error band ([`crate::depth`]) in polyline order and stop as soon as the
//! outcome is decided.
//!
//! The walk is defined as a scan of **every** segment in increasing index
//! (the reference, `Processor::reference_against_kept`); the processor feeds it only the
//! segments the index offers ([`crate::search`]), a superset of those that
//! meet the band, in the same order. A segment outside the band changes
//! nothing, so both give the same outcome; the host tests compare them on
//! every scenario. The rules, in order of the segments:
//!
//! * the segments in the band must follow each other directly: they form
//!   one *piece*. A second piece (the band meets the boundary in two
//!   separate places) is [`Status::Ambiguous`]: either could hold the
//!   correspondent, and no depth is given;
//! * a piece longer than the band's width over `tan(φ_min)`, twice (both
//!   edges of the band), plus `e₂ · 2/sin φ_min` (the polyline's own
//!   error, [`crate::wedge`]) is [`Status::Grazing`];
//! * an end vertex of the polyline inside the band is
//!   [`Status::BoundaryEnd`]: the boundary may go on, undetected, inside
//!   the band;
//! * otherwise the exact epipolar line's crossing nearest the point
//!   (smallest `λ'`) gives the depth estimate and the piece's `λ'` range
//!   the stick; a piece the exact line does not cross is
//!   [`Status::NoIntersection`].

use crate::camera::Pixel;
use crate::depth::{Band, Vertex};
use crate::math::{fmax, fmin};
use crate::search::{Flow, Visitor, CLIP_UNITS};
use crate::structure::Status;

/// What a walk concluded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Outcome {
    /// A crossing: its `λ'` and the piece's range `[lo, hi]`; on the
    /// wedge path also where the piece ends, one past its last segment
    /// (its segments' lines tighten the stick,
    /// [`crate::wedge::Wedge::refined`]; the band path gives 0).
    Match {
        lam: f32,
        lo: f32,
        hi: f32,
        end: usize,
    },
    /// No depth, and why.
    Flag(Status),
}

/// The state of one point's walk: a few plain values, so that it lives in
/// registers.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Walk {
    /// The segment that continues the piece (`usize::MAX`: no piece yet).
    next: usize,
    /// The piece's `λ'` range.
    lo: f32,
    hi: f32,
    /// The nearest exact crossing's `λ'` (infinite: none).
    best: f32,
    /// An end vertex of the polyline lies in the band.
    open: bool,
}

impl Walk {
    /// A walk before any segment.
    pub(crate) const NEW: Walk = Walk {
        next: usize::MAX,
        lo: 0.0,
        hi: 0.0,
        best: f32::INFINITY,
        open: false,
    };

    /// Take segment `j` from vertex `c0` to vertex `c1` (both in `band`'s
    /// frame, [`Band::vertex`]) of a polyline of `segments` segments;
    /// segments come in increasing index. `Err` when the outcome is decided
    /// ([`Status::Ambiguous`] or [`Status::Grazing`]): the walk stops.
    #[inline(always)]
    pub(crate) fn take(
        &mut self,
        band: &Band,
        j: usize,
        (c0, c1): (&Vertex, &Vertex),
        segments: usize,
        cot_twice: f32,
    ) -> Result<(), Status> {
        let Some(c) = band.segment(c0, c1) else {
            return Ok(());
        };
        if self.next == j {
            self.lo = fmin(self.lo, c.lo);
            self.hi = fmax(self.hi, c.hi);
        } else {
            if self.next != usize::MAX {
                return Err(Status::Ambiguous);
            }
            self.lo = c.lo;
            self.hi = c.hi;
            // The polyline's first vertex can only begin a piece.
            self.open |= j == 0 && Band::contains(c0);
        }
        self.open |= j + 1 == segments && Band::contains(c1);
        self.next = j + 1;
        if band.grazing(self.lo, self.hi, cot_twice) {
            return Err(Status::Grazing);
        }
        if let Some(lam) = c.crossing {
            // Only a crossing within the band's λ' range counts.
            if lam < self.best && lam > band.lam_lo && lam < band.lam_hi {
                self.best = lam;
            }
        }
        Ok(())
    }

    /// The outcome once the segments are through.
    #[inline(always)]
    pub(crate) fn outcome(&self) -> Outcome {
        if self.open {
            return Outcome::Flag(Status::BoundaryEnd);
        }
        if self.next == usize::MAX || self.best == f32::INFINITY {
            return Outcome::Flag(Status::NoIntersection);
        }
        Outcome::Match {
            // Within the piece, as it is up to rounding.
            lam: fmin(fmax(self.best, self.lo), self.hi),
            lo: self.lo,
            hi: self.hi,
            end: 0,
        }
    }
}

/// A cheap test that a segment misses a band which narrows towards the FOE
/// (`W' < 0`, slope `h ≤ 0`), from the segment's key interval and its
/// distance from the FOE, so that the wide key interval such a band needs
/// (its part near the FOE is wide in angle, [`Band::key_half_width`])
/// costs two units per segment instead of three.
///
/// A band point `q` at distance `r` from the FOE `F` and at the angle `φ`
/// from the ray through `p₁'` has `λ = ρ₁ − r cos φ` and `|μ| = r |sin φ|`,
/// so the band's `|μ| ≤ K₀ + h λ` gives `r |sin φ| ≤ c₀ + |h| r cos φ ≤ c₀ +
/// |h| r` with `c₀ = K₀ − |h| ρ₁` (`> e₂ > 0`): `|sin φ| ≤ c₀/r + |h|`.
/// Half-plane keys change by at most one unit per radian, so every point
/// of a segment whose key interval lies `δ` from the point's own (both
/// widened by their margins) is at `|φ| ≥ δ`, and `|sin φ| ≥ sin min(δ, 1)
/// ≥ δ′ (1 − δ′²/6)` with `δ′ = min(δ, 1)` (`|φ| ≤ π/2 + (r₁ + e₂)/m` in the
/// band beyond the FOE-near radius `m`). So a segment at least `m` from the
/// FOE whose `δ′ (1 − δ′²/6) − |h|` exceeds `c₀/r_min` (`r_min` its
/// distance from `F`) misses the band; `c₀` and `|h|` are taken 0.1 %
/// larger and the left side 0.1 % smaller for rounding, far more than the
/// band's own arithmetic is off, so a rejected segment is one the band's
/// clip rejects too. The distance is tried first from below by the
/// segment's smaller distance from the FOE's row, `min(t_a, t_b)` with `t
/// = side · (v − F_v)` (every point of the segment is at least that far
/// from `F`, as `t` is linear along it): no division, and on a boundary
/// that keeps well below or above the FOE it decides most segments; the
/// exact distance only when that bound does not.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Radial {
    foe: [f32; 2],
    /// The side of the FOE's row the boundary keeps to (+1 below).
    side: f32,
    /// The point's own key interval (oriented as the intervals offered).
    own: (f32, f32),
    /// `(1.001 c₀)²`, `1.001 |h|`, `m²`.
    c0sq: f32,
    h: f32,
    m2: f32,
}

impl Radial {
    /// A test that is never made (a place holder where there is none).
    pub(crate) const NONE: Radial = Radial {
        foe: [0.0; 2],
        side: 0.0,
        own: (0.0, 0.0),
        c0sq: 0.0,
        h: 0.0,
        m2: 0.0,
    };

    /// The test for `band` (`None` unless it narrows towards the FOE),
    /// with the FOE, the point's own key interval and the FOE-near radius.
    pub(crate) fn new(
        band: &Band,
        (foe, side): ([f32; 2], f32),
        own: (f32, f32),
        near_foe: f32,
    ) -> Option<Self> {
        let w = band.w();
        if !(w < 0.0 && band.h <= 0.0) {
            return None;
        }
        // ρ₁ = |a|/|W'| (a = W'(p₁' − F)).
        let h = -band.h;
        let c0 = band.k0 / band.a_len - h * (band.a_len / -w);
        if !(c0 > 0.0) {
            return None;
        }
        let c0 = c0 * 1.001;
        Some(Self {
            foe,
            side,
            own,
            c0sq: c0 * c0,
            h: h * 1.001,
            m2: near_foe * near_foe,
        })
    }

    /// Whether the segment `a → b` with key interval `(lo, hi)` misses the
    /// band for certain.
    #[inline(always)]
    pub(crate) fn rejects(&self, a: [f32; 2], b: [f32; 2], (lo, hi): (f32, f32)) -> bool {
        match self.by_row(a[1], b[1], (lo, hi)) {
            Row::Rejects => true,
            Row::Keeps => false,
            Row::Undecided(d) => self.rejects_exact(a, b, d),
        }
    }

    /// The second part of [`Self::rejects`], where [`Self::by_row`] said
    /// [`Row::Undecided`] with the key distance `d`: the exact distance
    /// from the FOE to the segment `a → b` decides.
    #[inline(always)]
    fn rejects_exact(&self, a: [f32; 2], b: [f32; 2], d: f32) -> bool {
        // The squared distance from the FOE to the segment.
        let ua = [a[0] - self.foe[0], a[1] - self.foe[1]];
        let ab = [b[0] - a[0], b[1] - a[1]];
        let l2 = ab[0] * ab[0] + ab[1] * ab[1];
        let t = if l2 > 0.0 {
            fmin(fmax(-(ua[0] * ab[0] + ua[1] * ab[1]) / l2, 0.0), 1.0)
        } else {
            0.0
        };
        let v = [ua[0] + t * ab[0], ua[1] + t * ab[1]];
        let r2 = v[0] * v[0] + v[1] * v[1];
        r2 >= self.m2 && d * d * r2 > self.c0sq
    }

    /// The first part of [`Self::rejects`], from the key interval and the
    /// rows `va`, `vb` of the segment's ends only: the key distance `d`
    /// (`δ′ (1 − δ′²/6)` less `|h|`, rounded down) and the distance from
    /// the FOE's row as the lower bound of the distance. The general visit
    /// makes this test itself before it offers a segment
    /// ([`crate::search::Visitor::radial`]), so that the segments it
    /// rejects cost no call.
    #[inline(always)]
    pub(crate) fn by_row(&self, va: f32, vb: f32, (lo, hi): (f32, f32)) -> Row {
        let Some(d) = self.key_distance((lo, hi)) else {
            return Row::Keeps;
        };
        // A lower bound of the distance first: the distance from the row.
        let t = fmin(
            self.side * (va - self.foe[1]),
            self.side * (vb - self.foe[1]),
        );
        if t > 0.0 {
            let t2 = t * t;
            if t2 >= self.m2 && d * d * t2 > self.c0sq {
                return Row::Rejects;
            }
        }
        Row::Undecided(d)
    }

    /// The key distance `d` of [`Self::by_row`] for the key interval `(lo,
    /// hi)`: `δ′ (1 − δ′²/6)` less `|h|` (rounded down by 0.1 %), `None`
    /// where it is not positive (no rejection). (A NaN gives `None`.)
    #[inline(always)]
    fn key_distance(&self, (lo, hi): (f32, f32)) -> Option<f32> {
        let delta = fmax(lo - self.own.1, self.own.0 - hi);
        if !(delta > self.h) {
            return None;
        }
        let dc = fmin(delta, 1.0);
        let d = dc * (1.0 - dc * dc * (1.0 / 6.0)) * 0.999 - self.h;
        (d > 0.0).then_some(d)
    }

    /// Whether [`Self::by_row`] rejects **every** segment of a block whose
    /// key intervals lie in the hull `(lo, hi)` and whose end vertices'
    /// rows lie in `[v_min, v_max]` (the block tree's radial levels,
    /// [`crate::search`]), so that the block can be passed over whole.
    ///
    /// Each segment's key distance `δ_s = max(l_s − k₊, k₋ − h_s)` is at
    /// least the hull's `δ_B` (`l_s ≥ lo`, `h_s ≤ hi`, and IEEE subtraction
    /// and `max` are monotone, so this holds as computed), and its row
    /// bound `t_s = min side · (v − F_v)` over its two ends is at least the
    /// block's `t_B`, the same expression at `v_min` (below the FOE's row,
    /// `side` +1) or at `v_max` (`side` −1), exactly. The function `d(δ)` of
    /// [`Self::key_distance`] rises with `δ` (`x (1 − x²/6)` has the
    /// derivative `1 − x²/2 > 0` on `[0, 1]`), but as computed it may fall
    /// by its rounding: each value is within `5.2 · 2⁻²⁴` of the exact one
    /// (four roundings and `1 − x²/6 ≥ 5/6`; the terms are at most 1), and
    /// the subtraction of `|h|` adds two more, so `d_s ≥ d_B − 14 · 2⁻²⁴ >
    /// d_B − 10⁻⁶`. The block is tested with `d_B − 2 · 10⁻⁶`. The rounded
    /// products `d · d · t²` are monotone in each (non-negative) factor, so
    /// the block's is at most each segment's, and it is compared with
    /// `c₀²` taken `10⁻⁵` larger besides. So `δ_s > |h|`, `d_s > 0`, `t_s² ≥
    /// m²` and `d_s² t_s² > c₀²` as computed for every segment of the
    /// block: each is [`Row::Rejects`] (unit test
    /// `a_rejected_block_holds_only_rejected_segments`). Precondition: no
    /// interval end is NaN (the hull's `min`/`max` by comparison would drop
    /// it while the segment's own test would not). The index's intervals
    /// are finite, infinite for an unkeyed end, or empty: keys come from
    /// validated, finite pixels, and an unkeyable one is [`crate::pencil`]'s
    /// infinite `NO_KEY`. (An independent review found no counterexample
    /// with finite or infinite ends: 3 M random tests with coordinates up to
    /// 10³⁰, `c₀` from 10⁻³⁰ to 10³⁰, key distances about `|h|` and 1.)
    /// `c0sq` is [`Self::block_c0sq`], passed in so that a walk over
    /// several levels makes it once.
    #[inline(always)]
    pub(crate) fn rejects_block(
        &self,
        hull: (f32, f32),
        (v_min, v_max): (f32, f32),
        c0sq: f32,
    ) -> bool {
        let Some(d) = self.key_distance(hull) else {
            return false;
        };
        let d = d - 2.0e-6;
        let v = if self.side > 0.0 { v_min } else { v_max };
        let t = self.side * (v - self.foe[1]);
        // (A NaN fails.)
        if !(d > 0.0 && t > 0.0) {
            return false;
        }
        let t2 = t * t;
        t2 >= self.m2 && d * d * t2 > c0sq
    }

    /// The `c₀²` that [`Self::rejects_block`] compares with: `10⁻⁵`
    /// larger than the segments' test's.
    #[inline(always)]
    pub(crate) fn block_c0sq(&self) -> f32 {
        self.c0sq * 1.000_01
    }
}

/// What [`Radial::by_row`] decides.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Row {
    /// The segment misses the band.
    Rejects,
    /// The test cannot reject it.
    Keeps,
    /// The exact distance decides, with this key distance `d`.
    Undecided(f32),
}

/// Work units a [`Radial`] rejection costs on top of the look (it is about
/// as long as the look itself).
pub(crate) const RADIAL_UNITS: u32 = 1;

/// A walk as an index [`Visitor`]: the band, the polyline, the last vertex
/// computed (reused along a run), the walk, and the band's [`Radial`] test
/// if it has one.
#[derive(Clone, Copy)]
pub(crate) struct Walker<'a> {
    pub(crate) band: Band,
    boundary: &'a [Pixel],
    cot_twice: f32,
    cache_i: usize,
    cache: Vertex,
    pub(crate) walk: Walk,
    /// Why the walk stopped early, if it did.
    pub(crate) decided: Option<Status>,
    radial: Option<Radial>,
}

impl<'a> Walker<'a> {
    pub(crate) fn new(
        band: Band,
        boundary: &'a [Pixel],
        cot_twice: f32,
        radial: Option<Radial>,
    ) -> Self {
        Self {
            band,
            boundary,
            cot_twice,
            cache_i: usize::MAX,
            cache: Vertex::NONE,
            walk: Walk::NEW,
            decided: None,
            radial,
        }
    }

    /// Vertex `i` in the band's frame (the previous segment's end is
    /// reused along a run).
    #[inline(always)]
    fn vertex(&mut self, i: usize) -> Option<Vertex> {
        if self.cache_i == i {
            return Some(self.cache);
        }
        let v = self.boundary.get(i)?;
        self.cache = self.band.vertex(v.arr());
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

impl<'a> Visitor<'a> for Walker<'a> {
    #[inline(always)]
    fn radial(&self) -> Option<(Radial, &'a [Pixel])> {
        self.radial.map(|r| (r, self.boundary))
    }

    #[inline(always)]
    fn segment(&mut self, j: usize, interval: (f32, f32)) -> (Flow, u32) {
        if let (Some(rad), Some(a), Some(b)) =
            (self.radial, self.boundary.get(j), self.boundary.get(j + 1))
        {
            if rad.rejects(a.arr(), b.arr(), interval) {
                return (Flow::Continue, RADIAL_UNITS);
            }
        }
        self.take(j)
    }

    /// (The general visit made [`Radial::rejects`] with this walker's test
    /// and segment `j`'s ends, and it kept the segment: the clip alone.)
    #[inline(always)]
    fn segment_kept(&mut self, j: usize, _: (f32, f32)) -> (Flow, u32) {
        self.take(j)
    }
}

impl Walker<'_> {
    /// Segment `j` taken by the walk (past the radial test): its clip.
    #[inline(always)]
    fn take(&mut self, j: usize) -> (Flow, u32) {
        let (Some(c0), Some(c1)) = (self.vertex(j), self.vertex(j + 1)) else {
            return (Flow::Continue, 0);
        };
        let segments = self.boundary.len().saturating_sub(1);
        match self
            .walk
            .take(&self.band, j, (&c0, &c1), segments, self.cot_twice)
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
    use crate::depth::tests::band_point;
    use crate::depth::PointErrors;
    use crate::test_rng::Rng;

    /// [`Radial::rejects`] is only a shortcut of the band's clip: moving
    /// backwards (`W' < 0`, no translation error, half-plane keys), a
    /// segment through a band point (a true frame-1 point within `r₁`, any
    /// depth, a polyline point within `e₂` of its correspondent, in `f64`)
    /// is never rejected, and every segment it rejects (random ones about
    /// the band point, most of them outside the band) has no part in the
    /// band. Both bounds of the distance are exercised (the boundary well
    /// below the FOE, and beside its row).
    #[test]
    fn radial_rejects_only_what_the_band_clips_away() {
        let mut rng = Rng(0x7ad1_a150);
        let (mut through, mut rejected) = (0, 0);
        let key_scale = 9.536_743e-7 * 1024.0;
        for case in 0..60_000 {
            let w = -(0.05 + rng.next());
            let c2 = [255.5f32, 239.5];
            let foe = [512.0 * rng.next(), 480.0 * rng.next() - 120.0];
            let g = [w * (foe[0] - c2[0]), w * (foe[1] - c2[1])];
            let p = [512.0 * rng.next(), 480.0 * rng.next()];
            let (r1, e2) = (0.05 + rng.next(), 0.05 + rng.next());
            let backward = |rng: &mut Rng, _: f64| Some(0.01 + 30.0 * f64::from(rng.next()));
            let Some(q) = band_point(&mut rng, (w, g, c2), p, (r1, e2), backward) else {
                continue;
            };
            let side = if q[1] >= foe[1] { 1.0 } else { -1.0 };
            let near_foe = 48.0 * (r1 + e2) + 8.0;
            let errors = PointErrors {
                r1,
                e2,
                e2_csc: e2 * 11.52,
                spread_a: 0.0,
                spread_w: 0.0,
            };
            let a = [w * (p[0] - c2[0]) - g[0], w * (p[1] - c2[1]) - g[1]];
            let Ok(band) = Band::new(p, a, w, &errors, near_foe) else {
                continue;
            };
            let key = |v: [f32; 2]| crate::pencil::half_key(v, (foe, side, 4.0), key_scale);
            let (kp, mp) = key(p);
            if !kp.is_finite() {
                continue;
            }
            let Some(rad) = Radial::new(&band, (foe, side), (kp - mp, kp + mp), near_foe) else {
                continue;
            };
            let interval = |u: [f32; 2], v: [f32; 2]| {
                let ((ku, mu), (kv, mv)) = (key(u), key(v));
                if (ku + kv).is_finite() {
                    (fmin(ku - mu, kv - mv), fmax(ku + mu, kv + mv))
                } else {
                    (f32::NEG_INFINITY, f32::INFINITY)
                }
            };
            // A segment through q, in any direction.
            let ang = rng.next() * core::f32::consts::TAU;
            let (l0, l1) = (8.0 * rng.next(), 8.0 * rng.next());
            let u = [libm::cosf(ang), libm::sinf(ang)];
            let s0 = [q[0] + l0 * u[0], q[1] + l0 * u[1]];
            let s1 = [q[0] - l1 * u[0], q[1] - l1 * u[1]];
            if !(interval(s0, s1).0.is_finite()) {
                continue;
            }
            assert!(
                !rad.rejects(s0, s1, interval(s0, s1)),
                "case {case}: a segment through band point {q:?} rejected (p {p:?}, foe {foe:?})"
            );
            through += 1;
            // A segment about q, shifted off it by up to 40 px.
            let off = [80.0 * (rng.next() - 0.5), 80.0 * (rng.next() - 0.5)];
            let (t0, t1) = (
                [s0[0] + off[0], s0[1] + off[1]],
                [s1[0] + off[0], s1[1] + off[1]],
            );
            let iv = interval(t0, t1);
            if iv.0.is_finite() && rad.rejects(t0, t1, iv) {
                assert!(
                    band.segment(&band.vertex(t0), &band.vertex(t1)).is_none(),
                    "case {case}: segment {t0:?} → {t1:?} rejected but in the band of {p:?}"
                );
                rejected += 1;
            }
        }
        assert!(through > 10_000 && rejected > 2_000, "{through} {rejected}");
    }

    /// [`Radial::rejects_block`] passes over a block only when
    /// [`Radial::by_row`] rejects every segment in it: random tests and
    /// blocks of 1–64 segments, each block built about the test's
    /// threshold (key distances and rows that put `d t` within 10⁻³ of
    /// `c₀`, either side, and key distances about `|h|` and past 1), so
    /// that many blocks are decided within the margins.
    #[test]
    fn a_rejected_block_holds_only_rejected_segments() {
        let mut rng = Rng(0x0b10_c4ed);
        let (mut blocks, mut passed, mut close) = (0u32, 0u32, 0u32);
        for _ in 0..200_000 {
            let side = if rng.next() < 0.5 { 1.0 } else { -1.0 };
            let foe = [512.0 * rng.next(), 480.0 * rng.next() - 120.0];
            let k = 2.0 * rng.next() - 1.0;
            let m = 1.0e-6 * (1.0 + 4.0 * rng.next());
            let (h, c0, near) = (
                0.3 * rng.next(),
                0.01 + 5.0 * rng.next(),
                1.0 + 49.0 * rng.next(),
            );
            let rad = Radial {
                foe,
                side,
                own: (k - m, k + m),
                c0sq: c0 * c0,
                h,
                m2: near * near,
            };
            // The block's smallest key distance and row distance, about the
            // threshold `d(δ) t = c₀` (the scale of one of them random).
            let delta = match rng.next() {
                x if x < 0.2 => h * (1.0 + 1.0e-3 * (rng.next() - 0.5)),
                x if x < 0.3 => 1.0 + rng.next(),
                _ => h + (1.5 - h) * rng.next(),
            };
            let Some(d) = rad.key_distance((k + m + delta, k + m + delta + 0.01)) else {
                continue;
            };
            let t_min = c0 / d * (1.0 + 2.0e-3 * (rng.next() - 0.5));
            let t_min = if rng.next() < 0.1 {
                near * (1.0 + 1.0e-4 * (rng.next() - 0.5))
            } else {
                t_min
            };
            let len = 1 + (64.0 * rng.next()) as usize;
            // Segments: key intervals at least `delta` from the own one
            // (either side), end rows at least `t_min` from the FOE's row.
            let mut segs = [((0.0f32, 0.0f32), (0.0f32, 0.0f32)); 64];
            let binding = (64.0 * rng.next()) as usize % len;
            // One side of the own key (a block with keys on both sides has
            // no key distance), now and then both.
            let (above, mixed) = (rng.next() < 0.5, rng.next() < 0.05);
            for (i, sg) in segs.iter_mut().take(len).enumerate() {
                let grow = if i == binding {
                    0.0
                } else {
                    rng.next() * rng.next()
                };
                let dk = delta * (1.0 + grow);
                let w = 0.05 * rng.next();
                let iv = if above != (mixed && rng.next() < 0.5) {
                    (k + m + dk, k + m + dk + w)
                } else {
                    (k - m - dk - w, k - m - dk)
                };
                let row = |rng: &mut Rng, g: f32| foe[1] + side * t_min * (1.0 + g * rng.next());
                let va = row(&mut rng, if i == binding { 0.0 } else { 0.5 });
                let vb = row(&mut rng, 0.5);
                *sg = (iv, (va, vb));
            }
            let segs = segs.get(..len).unwrap_or(&[]);
            let mut hull = (f32::INFINITY, f32::NEG_INFINITY);
            let mut rows = (f32::INFINITY, f32::NEG_INFINITY);
            for &((lo, hi), (va, vb)) in segs {
                hull = (fmin(hull.0, lo), fmax(hull.1, hi));
                rows = (fmin(rows.0, fmin(va, vb)), fmax(rows.1, fmax(va, vb)));
            }
            blocks += 1;
            if !rad.rejects_block(hull, rows, rad.block_c0sq()) {
                continue;
            }
            passed += 1;
            let dk = fmax(hull.0 - rad.own.1, rad.own.0 - hull.1);
            let db = rad.key_distance(hull).unwrap_or(0.0);
            let tb = side * (if side > 0.0 { rows.0 } else { rows.1 } - foe[1]);
            if (db * tb) * (db * tb) < c0 * c0 * 1.001 || dk < h * 1.001 {
                close += 1;
            }
            for (i, &(iv, (va, vb))) in segs.iter().enumerate() {
                assert_eq!(
                    rad.by_row(va, vb, iv),
                    Row::Rejects,
                    "segment {i} of a rejected block: {iv:?} rows {va} {vb} ({rad:?}, hull {hull:?}, rows {rows:?})"
                );
            }
        }
        assert!(
            blocks > 150_000 && passed > 15_000 && close > 4_000,
            "{blocks} blocks, {passed} rejected, {close} within 0.1 % of the threshold"
        );
    }
}
