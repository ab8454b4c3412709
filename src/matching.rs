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

use crate::camera::Pixel;
use crate::depth::{Band, Vertex};
use crate::math::{fmax, fmin};
use crate::search::{Flow, Visitor};
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

/// The state of one point's walk (plain values: it lives in registers).
#[derive(Clone, Copy)]
pub(crate) struct Walk<'a> {
    band: Band,
    boundary: &'a [Pixel],
    cot_twice: f32,
    pieces: usize,
    /// The index a segment must have to continue the current piece.
    next: usize,
    piece_lo: f32,
    piece_hi: f32,
    hull_lo: f32,
    hull_hi: f32,
    /// The nearest exact crossing: `λ'` (infinite: none), segment, position.
    best_lam: f32,
    best_j: usize,
    best_t: f32,
    /// The vertex computed last, and it.
    cache_i: usize,
    cache: Vertex,
    /// `Grazing` or `Tangled` once decided, else `Ok`.
    decided: Status,
    /// An end vertex of the polyline lies in the band.
    open: bool,
}

impl<'a> Walk<'a> {
    #[inline(always)]
    pub(crate) fn new(band: Band, boundary: &'a [Pixel], cot_twice: f32) -> Self {
        Self {
            band,
            boundary,
            cot_twice,
            pieces: 0,
            next: usize::MAX,
            piece_lo: 0.0,
            piece_hi: 0.0,
            hull_lo: f32::INFINITY,
            hull_hi: f32::NEG_INFINITY,
            best_lam: f32::INFINITY,
            best_j: 0,
            best_t: 0.0,
            cache_i: usize::MAX,
            cache: Vertex::NONE,
            decided: Status::Ok,
            open: false,
        }
    }

    /// The coordinates of vertex `i` (the previous segment's end is
    /// reused along a run).
    #[inline(always)]
    fn coords(&mut self, i: usize) -> Option<Vertex> {
        if self.cache_i == i {
            return Some(self.cache);
        }
        let v = self.boundary.get(i)?;
        self.cache = self.band.vertex(v.arr());
        self.cache_i = i;
        Some(self.cache)
    }

    /// Take segment `j` (segments come in increasing index).
    #[inline(always)]
    pub(crate) fn take(&mut self, j: usize) -> Flow {
        let Some(c0) = self.coords(j) else {
            return Flow::Continue;
        };
        let Some(c1) = self.coords(j + 1) else {
            return Flow::Continue;
        };
        let Some(c) = self.band.segment(&c0, &c1) else {
            return Flow::Continue;
        };
        if j == 0 || j + 2 >= self.boundary.len() {
            self.open |= (j == 0 && Band::contains(&c0))
                || (j + 2 >= self.boundary.len() && Band::contains(&c1));
        }
        if self.next == j {
            self.piece_lo = fmin(self.piece_lo, c.lo);
            self.piece_hi = fmax(self.piece_hi, c.hi);
        } else {
            // A new piece: the last one joins the hull.
            self.close_piece();
            self.pieces += 1;
            if self.pieces > MAX_PIECES {
                self.decided = Status::Tangled;
                return Flow::Stop;
            }
            self.piece_lo = c.lo;
            self.piece_hi = c.hi;
        }
        self.next = j + 1;
        if self
            .band
            .grazing(self.piece_lo, self.piece_hi, self.cot_twice)
        {
            self.decided = Status::Grazing;
            return Flow::Stop;
        }
        if let Some((t, lam)) = c.crossing {
            // Only a crossing within the band's λ' range counts.
            if lam < self.best_lam && lam > self.band.lam_lo && lam < self.band.lam_hi {
                self.best_lam = lam;
                self.best_j = j;
                self.best_t = t;
            }
        }
        Flow::Continue
    }

    /// Bring the current piece into the hull.
    #[inline(always)]
    fn close_piece(&mut self) {
        if self.pieces > 0 {
            self.hull_lo = fmin(self.hull_lo, self.piece_lo);
            self.hull_hi = fmax(self.hull_hi, self.piece_hi);
        }
    }

    /// The outcome once the segments are through (or the walk stopped).
    #[inline(always)]
    pub(crate) fn outcome(&mut self) -> Outcome {
        self.close_piece();
        if self.decided != Status::Ok {
            return Outcome::Flag(self.decided);
        }
        if self.open {
            return Outcome::Flag(Status::BoundaryEnd);
        }
        let (Some(v0), Some(v1)) = (
            self.boundary.get(self.best_j),
            self.boundary.get(self.best_j + 1),
        ) else {
            return Outcome::Flag(Status::NoIntersection);
        };
        if self.best_lam == f32::INFINITY {
            return Outcome::Flag(Status::NoIntersection);
        }
        Outcome::Match {
            p2: Band::point_on(v0.arr(), v1.arr(), self.best_t),
            // Within the hull, as it is up to rounding.
            lam: fmin(fmax(self.best_lam, self.hull_lo), self.hull_hi),
            lo: self.hull_lo,
            hi: self.hull_hi,
            pieces: self.pieces,
        }
    }
}

impl Visitor for Walk<'_> {
    #[inline(always)]
    fn segment(&mut self, j: usize) -> Flow {
        self.take(j)
    }
}

/// The reference: the walk over every segment of `boundary`, in order.
pub(crate) fn reference_walk(band: Band, boundary: &[Pixel], cot_twice: f32) -> Outcome {
    let mut walk = Walk::new(band, boundary, cot_twice);
    for j in 0..boundary.len().saturating_sub(1) {
        if walk.take(j) == Flow::Stop {
            break;
        }
    }
    walk.outcome()
}
