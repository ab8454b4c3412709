//! Road-boundary polylines and frames, validated on construction.
//! A boundary the detector lost in a frame is pushed absent
//! ([`Frame::push_absent`]): no points, its slot kept.
//!
//! A raw polyline from the camera front end is a `&[Pixel]`. A [`Boundary`]
//! is known to be finite, inside the image, ordered and within capacity; the
//! only way to make one is [`Frame::push_boundary`], which checks all that.
//!
//! **Ordered** means strictly monotone in the image row `v` (all increasing
//! or all decreasing), as a row-scanning boundary detector produces: one
//! point per row. A polyline that turns back in `v` (a zig-zag), repeats a
//! point or repeats a row is rejected.

use core::fmt;

use crate::buffer::Buffer;
use crate::camera::{Camera, Pixel};

/// Why a boundary was rejected. Indices refer to the offending point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum BoundaryError {
    /// Fewer than two points.
    TooFewPoints,
    /// More points than the capacity `N`; nothing is truncated.
    TooManyPoints {
        /// Points offered.
        len: usize,
        /// Capacity `N`.
        capacity: usize,
    },
    /// The frame already holds `B` boundaries.
    TooManyBoundaries,
    /// Point is NaN or infinite.
    NotFinite {
        /// Index of the point.
        index: usize,
    },
    /// Point lies outside the image plus [`crate::IMAGE_MARGIN_PX`].
    OutsideImage {
        /// Index of the point.
        index: usize,
    },
    /// Point equals its predecessor.
    Duplicate {
        /// Index of the point.
        index: usize,
    },
    /// Row `v` does not keep strictly increasing (or strictly decreasing).
    Unordered {
        /// Index of the point.
        index: usize,
    },
}

impl core::error::Error for BoundaryError {}

impl fmt::Display for BoundaryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooFewPoints => f.write_str("boundary has fewer than 2 points"),
            Self::TooManyPoints { len, capacity } => {
                write!(f, "boundary has {len} points, capacity is {capacity}")
            }
            Self::TooManyBoundaries => f.write_str("frame boundary capacity exhausted"),
            Self::NotFinite { index } => write!(f, "point {index} is NaN or infinite"),
            Self::OutsideImage { index } => write!(f, "point {index} is outside the image"),
            Self::Duplicate { index } => write!(f, "point {index} repeats its predecessor"),
            Self::Unordered { index } => {
                write!(f, "point {index} breaks the strict row order")
            }
        }
    }
}

/// A validated road-boundary polyline of at most `N` pixel points.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Boundary<const N: usize> {
    points: Buffer<Pixel, N>,
}

impl<const N: usize> Boundary<N> {
    /// No points (a frame's unused boundary slot).
    const EMPTY: Self = Self {
        points: Buffer::new(Pixel::new(0.0, 0.0)),
    };

    /// Check that `points` make a valid boundary (see the module docs).
    fn check(points: &[Pixel], camera: &Camera) -> Result<(), BoundaryError> {
        if points.len() < 2 {
            return Err(BoundaryError::TooFewPoints);
        }
        if points.len() > N {
            return Err(BoundaryError::TooManyPoints {
                len: points.len(),
                capacity: N,
            });
        }
        let mut direction = 0.0f32;
        let mut prev: Option<Pixel> = None;
        for (index, &p) in points.iter().enumerate() {
            if !(p.u.is_finite() && p.v.is_finite()) {
                return Err(BoundaryError::NotFinite { index });
            }
            if !camera.contains(p) {
                return Err(BoundaryError::OutsideImage { index });
            }
            if let Some(q) = prev {
                if p == q {
                    return Err(BoundaryError::Duplicate { index });
                }
                let dv = p.v - q.v;
                // Compare signs, not the product: two tiny steps (near
                // v = 0) multiply to -0.0 and would let a turn through.
                if dv == 0.0 || (direction != 0.0 && (dv > 0.0) != (direction > 0.0)) {
                    return Err(BoundaryError::Unordered { index });
                }
                direction = dv;
            }
            prev = Some(p);
        }
        Ok(())
    }

    /// The points, in the order given.
    pub fn points(&self) -> &[Pixel] {
        self.points.as_slice()
    }

    /// Whether the boundary was pushed as absent ([`Frame::push_absent`]):
    /// no points (a pushed polyline has at least two).
    pub fn is_absent(&self) -> bool {
        self.points.as_slice().is_empty()
    }
}

/// One camera frame: its intrinsics and up to `B` validated boundaries of up
/// to `N` points each (index 0 = left road edge, 1 = right, by convention;
/// boundary `k` of one frame corresponds to boundary `k` of the next; a
/// boundary not detected in a frame is pushed absent,
/// [`Frame::push_absent`], so that the others keep their numbers).
///
/// Its storage is `B` boundary slots of `N` points, filled once when the
/// frame is made: adding a boundary copies its points into the next slot,
/// and nothing larger than a point is ever moved or built on the stack.
#[derive(Clone)]
pub struct Frame<const N: usize, const B: usize> {
    camera: Camera,
    slots: [Boundary<N>; B],
    count: usize,
}

impl<const N: usize, const B: usize> PartialEq for Frame<N, B> {
    fn eq(&self, other: &Self) -> bool {
        self.camera == other.camera && self.boundaries() == other.boundaries()
    }
}

impl<const N: usize, const B: usize> fmt::Debug for Frame<N, B> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Frame")
            .field("camera", &self.camera)
            .field("boundaries", &self.boundaries())
            .finish()
    }
}

#[cfg(feature = "defmt")]
impl<const N: usize, const B: usize> defmt::Format for Frame<N, B> {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "Frame {{ camera: {}, boundaries: {} }}",
            self.camera,
            self.boundaries()
        )
    }
}

impl<const N: usize, const B: usize> Frame<N, B> {
    /// An empty frame seen by `camera`.
    pub const fn new(camera: Camera) -> Self {
        Self {
            camera,
            slots: [Boundary::EMPTY; B],
            count: 0,
        }
    }

    /// Validate a raw polyline and append it as the next boundary.
    /// On error the frame is unchanged.
    ///
    /// ```
    /// use roadstereo::{BoundaryError, Camera, Frame, Pixel};
    /// let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap();
    /// let mut frame = Frame::<64, 2>::new(cam);
    /// frame.push_boundary(&[Pixel::new(100.0, 470.0), Pixel::new(101.5, 469.0)])?;
    /// assert_eq!(
    ///     frame.push_boundary(&[Pixel::new(1.0, 1.0), Pixel::new(2.0, 5.0), Pixel::new(3.0, 2.0)]),
    ///     Err(BoundaryError::Unordered { index: 2 })
    /// );
    /// assert_eq!(frame.boundaries().len(), 1);
    /// # Ok::<(), BoundaryError>(())
    /// ```
    pub fn push_boundary(&mut self, points: &[Pixel]) -> Result<(), BoundaryError> {
        let Some(slot) = self.slots.get_mut(self.count) else {
            return Err(BoundaryError::TooManyBoundaries);
        };
        Boundary::<N>::check(points, &self.camera)?;
        slot.points.copy_from(points);
        self.count += 1;
        Ok(())
    }

    /// Append the next boundary as **absent**: the detector did not find
    /// it in this frame. The slot keeps the boundaries' numbering (boundary
    /// `k` of one frame is boundary `k` of the next), so a lost left edge
    /// does not turn the right edge into boundary 0. An absent boundary has
    /// no points: as frame 1 of a pair it gives no results, as frame 2
    /// every point of the other frame's boundary `k` is `no_intersection`
    /// (or flagged earlier, as any point is). The other boundaries' results
    /// are what they would be with it present while the frame's work
    /// budget ([`crate::Config::with_work_budget`], whose unused units carry
    /// from one boundary to the next) and the caller's deadline do not run
    /// out. A polyline of fewer than two
    /// points stays an error of [`Frame::push_boundary`]: absence is said,
    /// not inferred. `Err(TooManyBoundaries)` when the frame holds `B`
    /// boundaries (the frame unchanged).
    ///
    /// ```
    /// use roadstereo::{Camera, Frame, Pixel};
    /// let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap();
    /// let mut frame = Frame::<64, 2>::new(cam);
    /// frame.push_absent()?; // the left edge was not detected
    /// frame.push_boundary(&[Pixel::new(400.0, 470.0), Pixel::new(398.5, 469.0)])?;
    /// assert!(frame.boundaries()[0].is_absent());
    /// assert_eq!(frame.boundaries()[1].points().len(), 2);
    /// # Ok::<(), roadstereo::BoundaryError>(())
    /// ```
    pub fn push_absent(&mut self) -> Result<(), BoundaryError> {
        let Some(slot) = self.slots.get_mut(self.count) else {
            return Err(BoundaryError::TooManyBoundaries);
        };
        slot.points.set_len(0);
        self.count += 1;
        Ok(())
    }

    /// Make this frame a copy of `other` in place: one slice copy per
    /// boundary.
    pub(crate) fn assign(&mut self, other: &Self) {
        self.camera = other.camera;
        self.count = other.count;
        for (dst, src) in self.slots.iter_mut().zip(other.boundaries()) {
            dst.points.copy_from(src.points());
        }
    }

    /// Boundary `k` overwritten with the boundary `src` thinned with the
    /// tolerance `eps` ([`crate::thin`]: a subsequence of `src`, so again
    /// a boundary), and the thinned points; `None` when the frame has no
    /// boundary `k` (nothing changed) or `src` is not thinned
    /// ([`crate::thin`]'s reasons: too short, `eps` not positive, a row
    /// span that overflows, a first part that does not thin; more than `N`
    /// points). Under a caller's deadline `tick` is asked between parts of
    /// the pass; `None` when it says the time is up. After a `None` past
    /// the pass's start, boundary `k` may hold a partial write: the caller
    /// makes this frame another anyway.
    #[inline(never)]
    pub(crate) fn thin_into(
        &mut self,
        k: usize,
        src: &[Pixel],
        eps: f32,
        tick: &mut crate::search::Tick<'_>,
    ) -> Option<&[Pixel]> {
        if k >= self.count {
            return None;
        }
        let slot = self.slots.get_mut(k)?;
        let m = crate::thin::thin(src, eps, slot.points.storage_mut(), tick)?;
        slot.points.set_len(m);
        Some(slot.points.as_slice())
    }

    /// Start filling this frame in place for `camera`: no boundaries yet.
    /// (The wire decoder writes points straight into the slots.)
    pub(crate) fn restart(&mut self, camera: Camera) {
        self.camera = camera;
        self.count = 0;
    }

    /// The storage of the next boundary slot (all `N` points), to be
    /// written before [`Frame::commit_next_validated`]; `None` when the frame holds
    /// `B` boundaries.
    pub(crate) fn next_storage(&mut self) -> Option<&mut [Pixel; N]> {
        self.slots
            .get_mut(self.count)
            .map(|s| s.points.storage_mut())
    }

    /// Append the first `len` points written into the next slot as the
    /// next boundary, **already validated** by the caller with checks
    /// equivalent to [`Frame::push_boundary`]'s (the wire decoder checks
    /// its fixed-point points as integers, in the same order with the same
    /// errors; `wire`'s tests and the host fuzz test compare the two on
    /// every decoded frame). `false` when the frame holds `B` boundaries or
    /// `len > N` (nothing changes then).
    pub(crate) fn commit_next_validated(&mut self, len: usize) -> bool {
        if len > N {
            return false;
        }
        let Some(slot) = self.slots.get_mut(self.count) else {
            return false;
        };
        slot.points.set_len(len);
        self.count += 1;
        true
    }

    /// Remove all boundaries (keeps the camera).
    pub fn clear(&mut self) {
        self.count = 0;
    }

    /// The camera of this frame.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The validated boundaries.
    pub fn boundaries(&self) -> &[Boundary<N>] {
        self.slots.get(..self.count).unwrap_or(&[])
    }
}
