//! Matching one frame-1 point: walk the frame-2 segments that meet its
//! error band ([`crate::depth`]) in polyline order, group them into pieces,
//! and stop as soon as the outcome is decided.
//!
//! The walk is defined as a scan of **every** segment in increasing index
//! (the reference, [`reference_walk`]); the processor feeds it only the
//! segments the index offers ([`crate::search`]), a superset of those that
//! meet the band, in the same order. A segment outside the band changes
//! nothing, so both give the same outcome; a unit test and the host tests
//! compare them. The rules, in order of the segments:
//!
//! * a segment in the band continues the current piece when it follows the
//!   previous segment in the band directly, and starts a new piece
//!   otherwise; more than [`MAX_PIECES`] pieces is [`Status::Tangled`];
//! * a piece longer than the band's width over `tan(φ_min)` (both ends of
//!   the band's `λ` range) is [`Status::Grazing`];
//! * the exact epipolar line's crossings in the band are kept, the one
//!   nearest the point (smallest `λ`) for the depth estimate; the hull of
//!   every piece's `λ` range gives the stick;
//! * an end vertex of the polyline inside the band makes the outcome
//!   [`Status::BoundaryEnd`]: the boundary may go on, undetected, inside
//!   the band.

use crate::depth::{Band, Clipped, Coords};
use crate::search::Flow;
use crate::structure::{Status, MAX_PIECES};

/// What a walk concluded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Outcome {
    /// A crossing: the frame-2 point, its `λ'`, the hull `[lo, hi]` of the
    /// pieces, and how many pieces there were.
    Match {
        p2: [f32; 2],
        lam: f32,
        lo: f32,
        hi: f32,
        pieces: usize,
    },
    /// No depth: [`Status::NoIntersection`], [`Status::Tangled`] or
    /// [`Status::Grazing`].
    Flag(Status),
}

/// The state of one point's walk.
pub(crate) struct Walk<'a> {
    band: &'a Band,
    boundary: &'a [crate::camera::Pixel],
    cot_twice: f32,
    pieces: usize,
    /// Index of the last segment in the band (for adjacency).
    last: usize,
    piece: (f32, f32),
    hull: (f32, f32),
    /// The nearest exact crossing: `λ'`, segment, position on it.
    best: Option<(f32, usize, f32)>,
    /// The vertex whose coordinates were computed last, and them.
    cached: Option<(usize, Coords)>,
    decided: Option<Status>,
    /// An end vertex of the polyline lies in the band.
    open: bool,
}

impl<'a> Walk<'a> {
    pub(crate) fn new(
        band: &'a Band,
        boundary: &'a [crate::camera::Pixel],
        cot_twice: f32,
    ) -> Self {
        Self {
            band,
            boundary,
            cot_twice,
            pieces: 0,
            last: usize::MAX,
            piece: (0.0, 0.0),
            hull: (f32::INFINITY, f32::NEG_INFINITY),
            best: None,
            cached: None,
            decided: None,
            open: false,
        }
    }

    /// The coordinates of vertex `i` (the previous segment's end is
    /// reused along a run).
    #[inline(always)]
    fn coords(&mut self, i: usize) -> Option<Coords> {
        if let Some((k, c)) = self.cached {
            if k == i {
                return Some(c);
            }
        }
        let v = self.boundary.get(i)?;
        let c = self.band.coords(v.arr());
        self.cached = Some((i, c));
        Some(c)
    }

    /// Take segment `j` (segments come in increasing index).
    #[inline(always)]
    pub(crate) fn segment(&mut self, j: usize) -> Flow {
        let (Some(c0), Some(c1)) = (self.coords(j), self.coords(j + 1)) else {
            return Flow::Continue;
        };
        match self.band.clip(c0, c1) {
            Some(clipped) => {
                let last = j + 2 >= self.boundary.len();
                self.open |= (j == 0 && self.band.contains(c0)) || (last && self.band.contains(c1));
                self.in_band(j, clipped)
            }
            None => Flow::Continue,
        }
    }

    #[inline(always)]
    fn in_band(&mut self, j: usize, c: Clipped) -> Flow {
        if self.pieces > 0 && self.last.wrapping_add(1) == j {
            self.piece = (
                crate::math::fmin(self.piece.0, c.lo),
                crate::math::fmax(self.piece.1, c.hi),
            );
        } else {
            self.pieces += 1;
            if self.pieces > MAX_PIECES {
                self.decided = Some(Status::Tangled);
                return Flow::Stop;
            }
            self.piece = (c.lo, c.hi);
        }
        self.last = j;
        if self
            .band
            .grazing(self.piece.0, self.piece.1, self.cot_twice)
        {
            self.decided = Some(Status::Grazing);
            return Flow::Stop;
        }
        self.hull = (
            crate::math::fmin(self.hull.0, c.lo),
            crate::math::fmax(self.hull.1, c.hi),
        );
        if let Some((t, lam)) = c.crossing {
            if self.best.is_none_or(|(b, _, _)| lam < b) {
                self.best = Some((lam, j, t));
            }
        }
        Flow::Continue
    }

    /// The outcome once the segments are through (or the walk stopped).
    pub(crate) fn outcome(&self) -> Outcome {
        if let Some(s) = self.decided {
            return Outcome::Flag(s);
        }
        if self.open {
            return Outcome::Flag(Status::BoundaryEnd);
        }
        let Some((lam, j, t)) = self.best else {
            return Outcome::Flag(Status::NoIntersection);
        };
        let (Some(v0), Some(v1)) = (self.boundary.get(j), self.boundary.get(j + 1)) else {
            return Outcome::Flag(Status::NoIntersection);
        };
        Outcome::Match {
            p2: Band::point_on(v0.arr(), v1.arr(), t),
            lam: crate::math::fmin(crate::math::fmax(lam, self.hull.0), self.hull.1),
            lo: self.hull.0,
            hi: self.hull.1,
            pieces: self.pieces,
        }
    }
}

/// The reference: the walk over every segment of `boundary`, in order.
pub(crate) fn reference_walk(
    band: &Band,
    boundary: &[crate::camera::Pixel],
    cot_twice: f32,
) -> Outcome {
    let mut walk = Walk::new(band, boundary, cot_twice);
    for j in 0..boundary.len().saturating_sub(1) {
        if walk.segment(j) == Flow::Stop {
            break;
        }
    }
    walk.outcome()
}
