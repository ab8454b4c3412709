//! Road geometry from the reconstruction (paper, Sec. 4.2.1): camera height
//! above the road, camera tilt and road width, each as the range consistent
//! with the sticks, without prior knowledge of any of them.
//!
//! The near road is taken as a plane. With zero roll, a plane at height `h`
//! below a camera tilted down by `θ` is `Y cos θ + Z sin θ = h` in camera
//! coordinates (see [`crate::analysis`]); the ray of a point with normalised
//! coordinates `(x, y)` meets it at depth `Z = h / (y cos θ + sin θ)`. A
//! pair `(θ, h)` is consistent with a point when that depth lies in the
//! point's stick `[Z_near, Z_far]`, i.e. when
//! `h ∈ [Z_near (y cos θ + sin θ), Z_far (y cos θ + sin θ)]`. For each tilt
//! on a grid the heights consistent with all but a few points (wrong
//! matches) are found by a sweep over the interval ends; the tilts with any
//! such height, and the heights, give the ranges. The road width for a
//! `(θ, h)` is the median distance, on the plane, from the points of one
//! boundary to the polyline of the other; it scales with `h`, so its range
//! follows from the extreme heights at each consistent tilt.

use core::fmt;

use crate::math::{fmax, fmin, sin_cos, sqrt};

/// One reconstructed point: normalised coordinates and stick.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// `x = (u − c_x)/f_x` of the frame-1 pixel.
    pub x: f32,
    /// `y = (v − c_y)/f_y`.
    pub y: f32,
    /// Stick near end.
    pub z_near: f32,
    /// Stick far end.
    pub z_far: f32,
}

/// A closed range `[lo, hi]`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Range {
    /// Lower end.
    pub lo: f32,
    /// Upper end.
    pub hi: f32,
}

impl Range {
    /// Whether `v` is inside.
    pub fn contains(&self, v: f32) -> bool {
        self.lo <= v && v <= self.hi
    }
    /// `hi − lo`.
    pub fn width(&self) -> f32 {
        self.hi - self.lo
    }
}

/// Camera height, tilt (radians) and road width consistent with the sticks.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RoadGeometry {
    /// Camera height above the road, length units.
    pub height: Range,
    /// Camera tilt below the horizontal, radians.
    pub tilt: Range,
    /// Road width, length units.
    pub width: Range,
    /// Points that may disagree (wrong matches) at each tilt.
    pub outliers_allowed: usize,
}

/// Where a rejected [`Sample`] is in the input of [`road_geometry`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SampleIndex {
    /// Index of the view in `views`.
    pub view: usize,
    /// 0 for the left boundary of the view, 1 for the right one.
    pub boundary: usize,
    /// Index of the sample in that boundary.
    pub index: usize,
}

/// Why no geometry could be estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum GeometryError {
    /// No views, or fewer than [`MIN_POINTS`] points on a boundary.
    TooFewPoints,
    /// More points on a boundary than the capacity `N`.
    TooManyPoints,
    /// More than [`MAX_VIEWS`] views.
    TooManyViews,
    /// A coordinate or stick end of this sample is NaN or infinite.
    NotFinite(SampleIndex),
    /// This sample is finite but outside the accepted ranges: `|x|` or
    /// `|y|` above [`MAX_NORMALISED`], or not
    /// `0 ≤ z_near ≤ z_far ≤` [`MAX_SAMPLE_DEPTH`].
    OutOfRange(SampleIndex),
    /// No tilt in `[0°, 60°]` is consistent with the points.
    Inconsistent,
}

impl core::error::Error for GeometryError {}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let at = |f: &mut fmt::Formatter<'_>, i: &SampleIndex, what: &str| {
            write!(
                f,
                "sample {} of boundary {} in view {} {what}",
                i.index, i.boundary, i.view
            )
        };
        match self {
            Self::TooFewPoints => f.write_str("too few reconstructed points on a boundary"),
            Self::TooManyPoints => f.write_str("more points on a boundary than the capacity"),
            Self::TooManyViews => f.write_str("more views than MAX_VIEWS"),
            Self::NotFinite(i) => at(f, i, "is NaN or infinite"),
            Self::OutOfRange(i) => at(f, i, "is out of range"),
            Self::Inconsistent => f.write_str("no ground plane is consistent with the sticks"),
        }
    }
}

/// Fewest points [`road_geometry`] needs on each boundary of each view.
pub const MIN_POINTS: usize = 10;

/// Largest accepted `|x|`, `|y|` of a [`Sample`] (normalised coordinates).
/// A pixel of any valid [`crate::Camera`] is within 16 385 of the
/// principal point at `f ≥ 1` px.
pub const MAX_NORMALISED: f32 = 1.0e5;

/// Largest accepted stick end of a [`Sample`], length units (the crate's
/// bound on translations). With [`MAX_NORMALISED`] it keeps every product
/// of the estimate below `1e22`, far from `f32` overflow.
pub const MAX_SAMPLE_DEPTH: f32 = 1.0e6;

/// Tilt grid step, radians (0.05°).
const TILT_STEP: f32 = 0.000_872_664_6;
/// Tilts on the grid after 0: `TILT_STEPS · TILT_STEP` is 60°, the
/// largest tilt tried.
const TILT_STEPS: u16 = 1200;

/// Heights consistent with all but `m` of the points at tilt `(s, c)`:
/// the hull of the heights covered by at least `n − m` intervals.
///
/// Work: one pass over `points` (at most `N` are used), two sorts, and a
/// sweep of exactly one step per interval end (`2n` steps).
fn heights<const N: usize>(points: &[Sample], s: f32, c: f32, m: usize) -> Option<Range> {
    let mut lo = [0.0f32; N];
    let mut hi = [0.0f32; N];
    let mut n = 0;
    for ((l, h), p) in lo.iter_mut().zip(hi.iter_mut()).zip(points) {
        let k = p.y * c + s;
        if k <= 0.0 {
            // The ray does not meet the plane ahead: this point disagrees.
            continue;
        }
        *l = p.z_near * k;
        *h = p.z_far * k;
        n += 1;
    }
    let need = points.len().saturating_sub(m);
    if n < need || need == 0 {
        return None;
    }
    let (lo, hi) = (lo.get_mut(..n)?, hi.get_mut(..n)?);
    lo.sort_unstable_by(f32::total_cmp);
    hi.sort_unstable_by(f32::total_cmp);
    // Sweep: coverage rises at each lo, falls after each hi. Every step
    // consumes one end, so `2n` steps consume them all.
    let (mut i, mut j, mut cover) = (0usize, 0usize, 0usize);
    let (mut first, mut last) = (None, None);
    for _ in 0..lo.len().saturating_add(hi.len()) {
        match (lo.get(i), hi.get(j)) {
            (Some(&l), Some(&h)) if l <= h => {
                cover += 1;
                if cover >= need && first.is_none() {
                    first = Some(l);
                }
                i += 1;
            }
            (_, Some(&h)) => {
                if cover >= need {
                    last = Some(h);
                }
                cover = cover.saturating_sub(1);
                j += 1;
            }
            // Every interval has `lo ≤ hi`, so the sorted lo ends run out
            // no later than the hi ends: this arm only ends the sweep.
            (Some(_), None) | (None, None) => break,
        }
    }
    let (first, last) = (first?, last?);
    (first <= last).then_some(Range {
        lo: first,
        hi: last,
    })
}

/// Inverse of the farthest ground distance [`ground`] accepts, in camera
/// heights: farther points (closer to the horizon) are left out of the
/// width, which keeps their positions below `1e11`.
const MIN_GROUND_SLOPE: f32 = 1.0e-6;

/// Ground-plane position (lateral, forward) of a sample at tilt `(s, c)`
/// and height 1 (positions scale with the height); `None` if its ray does
/// not meet the plane ahead within `1 / MIN_GROUND_SLOPE` heights.
fn ground(p: &Sample, s: f32, c: f32) -> Option<[f32; 2]> {
    let k = p.y * c + s;
    if k < MIN_GROUND_SLOPE {
        return None;
    }
    let z = 1.0 / k;
    // Camera (x z, y z, z) → vehicle: lateral x z, forward −s y z + c z.
    Some([p.x * z, (-s * p.y + c) * z])
}

/// Median distance, on the plane at height 1, from the points of `b` to the
/// polyline of `a` (both in order along their boundaries).
///
/// Work: `|b| · |a|` point-to-segment distances (each at most `N`).
fn width_at<const N: usize>(a: &[Sample], b: &[Sample], s: f32, c: f32) -> Option<f32> {
    let mut d = [0.0f32; N];
    let mut n = 0;
    for (slot, p) in d.iter_mut().zip(b) {
        let Some(q) = ground(p, s, c) else { continue };
        let mut best = f32::INFINITY;
        let mut prev: Option<[f32; 2]> = None;
        for r in a {
            let Some(v) = ground(r, s, c) else { continue };
            if let Some(u) = prev {
                // Distance from q to the segment u → v.
                let e = [v[0] - u[0], v[1] - u[1]];
                let w = [q[0] - u[0], q[1] - u[1]];
                let ee = e[0] * e[0] + e[1] * e[1];
                let t = if ee > 0.0 {
                    fmin(fmax((w[0] * e[0] + w[1] * e[1]) / ee, 0.0), 1.0)
                } else {
                    0.0
                };
                let dx = [w[0] - t * e[0], w[1] - t * e[1]];
                best = fmin(best, sqrt(dx[0] * dx[0] + dx[1] * dx[1]));
            }
            prev = Some(v);
        }
        if best.is_finite() {
            *slot = best;
            n += 1;
        }
    }
    let d = d.get_mut(..n)?;
    if d.is_empty() {
        return None;
    }
    d.sort_unstable_by(f32::total_cmp);
    d.get(n / 2).copied()
}

/// The median over the views of each view's median boundary distance at
/// tilt `(s, c)` and height 1 (at most [`MAX_VIEWS`] views).
fn median_width<const N: usize>(views: &[(&[Sample], &[Sample])], s: f32, c: f32) -> Option<f32> {
    let mut w = [0.0f32; MAX_VIEWS];
    let mut k = 0;
    for ((l, r), slot) in views.iter().zip(w.iter_mut()) {
        if let Some(w1) = width_at::<N>(l, r, s, c) {
            *slot = w1;
            k += 1;
        }
    }
    let ws = w.get_mut(..k)?;
    ws.sort_unstable_by(f32::total_cmp);
    ws.get(k / 2).copied()
}

/// Most views (frame pairs) [`road_geometry`] combines.
pub const MAX_VIEWS: usize = 16;

/// Step 1 of [`road_geometry`]: the views' counts and every sample's
/// values are within the accepted ranges.
fn check_views<const N: usize>(views: &[(&[Sample], &[Sample])]) -> Result<(), GeometryError> {
    if views.is_empty() {
        return Err(GeometryError::TooFewPoints);
    }
    if views.len() > MAX_VIEWS {
        return Err(GeometryError::TooManyViews);
    }
    for (l, r) in views {
        if l.len() < MIN_POINTS || r.len() < MIN_POINTS {
            return Err(GeometryError::TooFewPoints);
        }
        if l.len() > N || r.len() > N {
            return Err(GeometryError::TooManyPoints);
        }
    }
    for (view, (l, r)) in views.iter().enumerate() {
        for (boundary, side) in [*l, *r].into_iter().enumerate() {
            for (index, p) in side.iter().enumerate() {
                let at = SampleIndex {
                    view,
                    boundary,
                    index,
                };
                if ![p.x, p.y, p.z_near, p.z_far].iter().all(|v| v.is_finite()) {
                    return Err(GeometryError::NotFinite(at));
                }
                let in_image = p.x.abs() <= MAX_NORMALISED && p.y.abs() <= MAX_NORMALISED;
                let stick = 0.0 <= p.z_near && p.z_near <= p.z_far && p.z_far <= MAX_SAMPLE_DEPTH;
                if !(in_image && stick) {
                    return Err(GeometryError::OutOfRange(at));
                }
            }
        }
    }
    Ok(())
}

/// Step 2 of [`road_geometry`]: the points of the plane fit, copied into
/// `all` — every boundary of every view (the road is taken as planar over
/// the points given; pass the near part of a hilly road), up to
/// `max(N / (2 · views), 5)` of each, nearest first, and no more than `N`.
fn plane_points<'a, const N: usize>(
    views: &[(&[Sample], &[Sample])],
    all: &'a mut [Sample; N],
) -> &'a [Sample] {
    let share = (N / (2 * views.len().max(1))).max(5);
    let mut n = 0;
    for (l, r) in views {
        for side in [*l, *r] {
            for p in side.iter().take(share) {
                if let Some(slot) = all.get_mut(n) {
                    *slot = *p;
                    n += 1;
                }
            }
        }
    }
    all.get(..n).unwrap_or_default()
}

/// The ranges [`road_geometry`] accumulates over the tilt grid.
struct Hull {
    tilt: Range,
    height: Range,
    width: Range,
}

impl Hull {
    const EMPTY: Range = Range {
        lo: f32::INFINITY,
        hi: f32::NEG_INFINITY,
    };

    /// Step 3 of [`road_geometry`], at one tilt: the heights consistent
    /// there, and the width they give (the width scales with the height).
    fn add(&mut self, tilt: f32, height: Range, width_at_unit_height: Option<f32>) {
        self.tilt.lo = fmin(self.tilt.lo, tilt);
        self.tilt.hi = fmax(self.tilt.hi, tilt);
        self.height.lo = fmin(self.height.lo, height.lo);
        self.height.hi = fmax(self.height.hi, height.hi);
        if let Some(w) = width_at_unit_height {
            self.width.lo = fmin(self.width.lo, w * height.lo);
            self.width.hi = fmax(self.width.hi, w * height.hi);
        }
    }

    /// Step 4 of [`road_geometry`]: a result if any tilt fitted and gave
    /// a width, the tilt range widened by the grid step (a tilt within
    /// half a step beyond the ends may also fit).
    fn finish(self, outliers: usize) -> Result<RoadGeometry, GeometryError> {
        let Hull {
            mut tilt,
            height,
            width,
        } = self;
        if !(tilt.lo.is_finite() && width.lo.is_finite()) {
            return Err(GeometryError::Inconsistent);
        }
        tilt.lo = fmax(tilt.lo - TILT_STEP, 0.0);
        tilt.hi += TILT_STEP;
        Ok(RoadGeometry {
            height,
            tilt,
            width,
            outliers_allowed: outliers,
        })
    }
}

/// Camera height, tilt and road width from one or more views — the samples
/// of the left and the right boundary of a reconstruction (each in order
/// along its boundary) — of the same road from the same camera mounting,
/// e.g. successive frame pairs. A `(θ, h)` must agree with the points of
/// all views (all but `outliers` of them, for wrong matches); the width is
/// the median over the views of each view's median boundary distance. `N`
/// is the capacity for all points together; more are left out (the
/// farther points of each view first).
///
/// Input: 1 to [`MAX_VIEWS`] views, [`MIN_POINTS`] to `N` samples on each
/// boundary, every sample finite with `|x|, |y| ≤` [`MAX_NORMALISED`] and
/// `0 ≤ z_near ≤ z_far ≤` [`MAX_SAMPLE_DEPTH`]; anything else is a typed
/// error naming the first bad sample.
///
/// Work: `G = 1201` tilts (a constant), each with `O(M log M)` for the
/// heights of the `M ≤ N` plane-fit points and `O(V · m²)` for the widths
/// of `V ≤ 16` views of `m ≤ N` points per boundary — a check of the
/// reconstruction, not a per-frame task.
pub fn road_geometry<const N: usize>(
    views: &[(&[Sample], &[Sample])],
    outliers: usize,
) -> Result<RoadGeometry, GeometryError> {
    // 1. Validate the input.
    check_views::<N>(views)?;
    // 2. Gather the points of the plane fit.
    let mut all = [Sample::default(); N];
    let points = plane_points(views, &mut all);
    // 3. Sweep the tilt grid: heights consistent at each tilt, and widths.
    let mut hull = Hull {
        tilt: Hull::EMPTY,
        height: Hull::EMPTY,
        width: Hull::EMPTY,
    };
    for step in 0..=TILT_STEPS {
        let tilt = f32::from(step) * TILT_STEP;
        // `sin_cos` is valid here: the tilt is in [0, 60°].
        let (s, c) = sin_cos(tilt);
        if let Some(h) = heights::<N>(points, s, c, outliers) {
            hull.add(tilt, h, median_width::<N>(views, s, c));
        }
    }
    // 4. The ranges.
    hull.finish(outliers)
}

/// The samples of one boundary of a reconstruction: its points with a depth
/// (status `Ok`), in order, as normalised coordinates and sticks.
pub fn samples<const N: usize, const B: usize>(
    s: &crate::Structure<N, B>,
    boundary: usize,
    out: &mut heapless::Vec<Sample, N>,
) {
    out.clear();
    let cam = s.camera1();
    if let Some(b) = s.boundaries().get(boundary) {
        for r in b.points() {
            if r.status() != crate::Status::Ok {
                continue;
            }
            if let Some(i) = r.interval() {
                let [x, y] = cam.normalise(r.pixel1());
                let _ = out.push(Sample {
                    x,
                    y,
                    z_near: i.z_near,
                    z_far: i.z_far,
                });
            }
        }
    }
}
