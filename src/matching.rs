//! Matching one frame-1 point: walk the frame-2 segments that meet its
//! error band ([`crate::depth`]) in polyline order and stop as soon as the
//! outcome is decided.
//!
//! The walk is defined as a scan of **every** segment in increasing index
//! (the reference, [`reference_walk`]); the processor feeds it only the
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
//!   edges of the band), is [`Status::Grazing`];
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
use crate::search::{Flow, Visitor};
use crate::structure::Status;

/// What a walk concluded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Outcome {
    /// A crossing: its `λ'` and the piece's range `[lo, hi]`.
    Match { lam: f32, lo: f32, hi: f32 },
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
        }
    }
}

/// A walk as an index [`Visitor`]: the band, the polyline, the last vertex
/// computed (reused along a run) and the walk.
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
}

impl<'a> Walker<'a> {
    pub(crate) fn new(band: Band, boundary: &'a [Pixel], cot_twice: f32) -> Self {
        Self {
            band,
            boundary,
            cot_twice,
            cache_i: usize::MAX,
            cache: Vertex::NONE,
            walk: Walk::NEW,
            decided: None,
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

impl Visitor for Walker<'_> {
    #[inline(always)]
    fn segment(&mut self, j: usize, _: (f32, f32)) -> Flow {
        let (Some(c0), Some(c1)) = (self.vertex(j), self.vertex(j + 1)) else {
            return Flow::Continue;
        };
        let segments = self.boundary.len().saturating_sub(1);
        match self
            .walk
            .take(&self.band, j, (&c0, &c1), segments, self.cot_twice)
        {
            Ok(()) => Flow::Continue,
            Err(s) => {
                self.decided = Some(s);
                Flow::Stop
            }
        }
    }
}

/// The reference: the walk over every segment of `boundary`, in order.
pub(crate) fn reference_walk(band: Band, boundary: &[Pixel], cot_twice: f32) -> Outcome {
    let mut walker = Walker::new(band, boundary, cot_twice);
    for j in 0..boundary.len().saturating_sub(1) {
        if walker.segment(j, (f32::NEG_INFINITY, f32::INFINITY)) == Flow::Stop {
            break;
        }
    }
    walker.outcome()
}
