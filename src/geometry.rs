//! Road geometry from the reconstruction (paper, Sec. 4.2.1): camera height
//! above the road and camera tilt, each as a range that holds every value
//! consistent with the sticks, and the road width estimated from them,
//! without prior knowledge of any of them.
//!
//! The near road is taken as a plane. With zero roll, a plane at height `h`
//! below a camera tilted down by `θ` is `Y cos θ + Z sin θ = h` in camera
//! coordinates (see [`crate::analysis`]); the ray of a point with normalised
//! coordinates `(x, y)` meets it at depth `Z = h / (y cos θ + sin θ)`. A
//! pair `(θ, h)` is consistent with a point when that depth lies in the
//! point's stick `[Z_near, Z_far]`, i.e. when
//! `h ∈ [Z_near g(θ), Z_far g(θ)]` with `g(θ) = y cos θ + sin θ`.
//!
//! **Exact up to a superset.** The tilts from 0° to 60° are cut into
//! cells of 0.05°, and a cell with any consistent height into 16 parts;
//! in each cell (and part) every point's interval is widened to what any
//! tilt of it allows: `[Z_near g₋, Z_far g₊]` with `g₋` and `g₊`
//! the least and the largest `g` over the cell (`g = √(1 + y²) sin(θ + φ)`,
//! `tan φ = y`, rises to one maximum and falls, so `g₋` is at an end of the
//! cell and `g₊` at an end or, where `g′ = cos θ − y sin θ` changes sign in
//! the cell, `√(1 + y²)`), each widened by the rounding of `g` (the sine
//! and cosine within `3·10⁻⁷`, the sum within two units: `10⁻⁶ (|y| +
//! 1)` taken) and of the products (`2⁻²²` relative, and `4 · 2⁻¹⁴⁹`
//! absolute for subnormal ones: sticks below `10⁻³⁸`). The heights covered by
//! all but a few (`outliers`, wrong matches) of those intervals are found
//! by a sweep over their ends. A `(θ, h)` that agrees with the sticks has
//! `h` in every widened interval of `θ`'s cell and part, so the parts with
//! any such height give a tilt range, and their heights a height range,
//! that hold every `(θ, h)` consistent with the sticks (with all but
//! `outliers` of them). Until an adversarial review, the heights were
//! those of the grid tilts alone: with sticks of ±0.1 % a true tilt
//! between two grid tilts was reported with a height range that missed
//! the truth, or as inconsistent.
//!
//! The road width for a `(θ, h)` is the median distance, on the plane,
//! from the points of one boundary to the polyline of the other; it scales
//! with `h`. It is an estimate (the median of the distances, not a bound):
//! its range is the hull, over the cells with a height, of the widths at
//! the cell's two ends times the cell's heights.

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

/// Camera height and tilt (radians) consistent with the sticks, and the
/// road width estimated from them.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RoadGeometry {
    /// Camera height above the road, length units.
    pub height: Range,
    /// Camera tilt below the horizontal, radians.
    pub tilt: Range,
    /// Road width, length units: an estimate (module docs); `None` when
    /// no view gives one (every point of a boundary at or beyond the
    /// horizon of every consistent tilt, where its ground position is not
    /// finite). The height and tilt ranges do not depend on it.
    pub width: Option<Range>,
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
    /// More than [`MAX_VIEWS`] views, or more boundaries (two a view)
    /// than the capacity `N` can take a point of each.
    TooManyViews,
    /// `outliers` is not below the number of points of the plane fit:
    /// every `(θ, h)` would agree with all but `outliers` of them.
    TooManyOutliers,
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
            Self::TooManyViews => {
                f.write_str("more views than MAX_VIEWS, or than the capacity takes")
            }
            Self::TooManyOutliers => {
                f.write_str("outliers allowed not below the points of the plane fit")
            }
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

/// Tilt cell width, radians (0.05°).
const TILT_STEP: f32 = 0.000_872_664_6;
/// Tilt cells: `TILT_STEPS · TILT_STEP` is 60°, the largest tilt tried.
const TILT_STEPS: u16 = 1200;
/// Parts of a tilt cell with any consistent height, each tested again:
/// the widening of a point's interval over a cell is then a sixteenth.
const SUB_CELLS: u16 = 16;

/// The rounding allowance of `g = y cos θ + sin θ` per unit of `|y| + 1`
/// (module docs).
const G_ROUNDING: f32 = 1.0e-6;
/// The relative rounding allowance of a product `Z g` (module docs).
const PRODUCT_ROUNDING: f32 = 2.384_185_8e-7;
/// The absolute allowance for the same products where they are
/// subnormal: `4 · 2⁻¹⁴⁹`, more than three roundings of half of `2⁻¹⁴⁹`.
const SUBNORMAL_ROUNDING: f32 = f32::from_bits(4);

/// The tilt cell `[θ_a, θ_b]` with the sines and cosines of its ends.
#[derive(Clone, Copy)]
struct Cell {
    a: (f32, f32),
    b: (f32, f32),
}

impl Cell {
    /// The heights a point allows at some tilt of the cell, widened by the
    /// rounding (module docs); `None` where no tilt of the cell has its ray
    /// meet the plane ahead (the point disagrees).
    fn interval(&self, p: &Sample) -> Option<(f32, f32)> {
        let ((sa, ca), (sb, cb)) = (self.a, self.b);
        let (ga, gb) = (p.y * ca + sa, p.y * cb + sb);
        let tol = G_ROUNDING * (p.y.abs() + 1.0);
        let mut g_hi = fmax(ga, gb);
        // `g′` from positive (or nearly) at `θ_a` to negative (or nearly)
        // at `θ_b`: the maximum `√(1 + y²)` may lie inside.
        if ca - p.y * sa >= -tol && cb - p.y * sb <= tol {
            g_hi = fmax(g_hi, sqrt(1.0 + p.y * p.y) * (1.0 + PRODUCT_ROUNDING));
        }
        let g_hi = g_hi + tol;
        if g_hi <= 0.0 {
            return None;
        }
        let g_lo = fmax(fmin(ga, gb) - tol, 0.0);
        // (Relative allowances hold for normal products; a subnormal one
        // rounds by up to half of `2⁻¹⁴⁹`, absolutely, each of two
        // roundings and the allowance's own: `SUBNORMAL_ROUNDING` more.
        // An adversarial review, thirtieth session, found sticks at
        // `5 · 2⁻¹⁴⁹` whose consistent height lay outside the range.)
        Some((
            fmax(
                p.z_near * g_lo * (1.0 - PRODUCT_ROUNDING) - SUBNORMAL_ROUNDING,
                0.0,
            ),
            p.z_far * g_hi * (1.0 + PRODUCT_ROUNDING) + SUBNORMAL_ROUNDING,
        ))
    }
}

/// Heights consistent with all but `m` of the points in tilt cell `cell`
/// ([`Cell::interval`]): the hull of the heights covered by at least `n −
/// m` intervals.
///
/// Work: one pass over `points` (at most `N` are used), two sorts, and a
/// sweep of exactly one step per interval end (`2n` steps).
fn heights<const N: usize>(points: &[Sample], cell: &Cell, m: usize) -> Option<Range> {
    let mut lo = [0.0f32; N];
    let mut hi = [0.0f32; N];
    let mut n = 0;
    for p in points {
        let Some((a, b)) = cell.interval(p) else {
            // No ray of the cell meets the plane ahead: this point
            // disagrees. (Until a review this skipped the point's slot
            // too, and the sweep took the first `n` slots: a left-out
            // point's empty `[0, 0]` in, the last point's interval out.)
            continue;
        };
        if let (Some(l), Some(h)) = (lo.get_mut(n), hi.get_mut(n)) {
            (*l, *h) = (a, b);
            n += 1;
        }
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
/// the points given; pass the near part of a hilly road). When they do not
/// all fit in `N`, each boundary keeps its `q` nearest (by the stick's
/// middle, whatever their order), `q` the largest share with which the
/// boundaries' points fit: every view keeps points, the farther ones of
/// the longest boundaries are left out first. (Until an adversarial review
/// each boundary gave its first `max(N / (2 · views), 5)` points in the
/// order given, and views past the capacity none: 16 views of which the
/// last 9 disagreed with the first 7 came out consistent at `N = 64`.)
/// [`GeometryError::TooManyViews`] when `N` cannot take one point of every
/// boundary.
///
/// Work: `O(N)` per share tried (at most `N`), and a sort of each
/// boundary's depths that does not fit.
fn plane_points<'a, const N: usize>(
    views: &[(&[Sample], &[Sample])],
    all: &'a mut [Sample; N],
) -> Result<&'a [Sample], GeometryError> {
    let sides = || views.iter().flat_map(|(l, r)| [*l, *r]);
    let taken = |q: usize| {
        sides()
            .map(|side| side.len().min(q))
            .fold(0usize, usize::saturating_add)
    };
    // The largest share that fits (the sides are at most `N` long, so a
    // share of `N` takes every point).
    let mut q = 0;
    while q < N && taken(q + 1) <= N {
        q += 1;
    }
    if q == 0 {
        return Err(GeometryError::TooManyViews);
    }
    let mut n = 0;
    let mut keys = [0.0f32; N];
    for side in sides() {
        // The `q`-th least middle of the side's sticks (all of them when
        // the side fits): the points below it, then those at it, up to `q`.
        let cut = if side.len() > q {
            let k = keys.get_mut(..side.len()).unwrap_or_default();
            for (key, p) in k.iter_mut().zip(side) {
                *key = middle(p);
            }
            k.sort_unstable_by(f32::total_cmp);
            k.get(q - 1).copied().unwrap_or(f32::INFINITY)
        } else {
            f32::INFINITY
        };
        let below = side.iter().filter(|p| middle(p) < cut);
        let at = side.iter().filter(|p| middle(p) == cut);
        for p in below.chain(at).take(q) {
            if let Some(slot) = all.get_mut(n) {
                *slot = *p;
                n += 1;
            }
        }
    }
    Ok(all.get(..n).unwrap_or_default())
}

/// The middle of a sample's stick (finite: the sticks are validated).
fn middle(p: &Sample) -> f32 {
    0.5 * p.z_near + 0.5 * p.z_far
}

/// The ranges [`road_geometry`] accumulates over the tilt cells.
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

    /// Step 3 of [`road_geometry`], in one tilt cell `[θ_a, θ_b]`: the
    /// heights consistent there, and the widths at unit height at its
    /// ends (the width scales with the height).
    fn add(&mut self, (ta, tb): (f32, f32), height: Range, widths: [Option<f32>; 2]) {
        self.tilt.lo = fmin(self.tilt.lo, ta);
        self.tilt.hi = fmax(self.tilt.hi, tb);
        self.height.lo = fmin(self.height.lo, height.lo);
        self.height.hi = fmax(self.height.hi, height.hi);
        for w in widths.into_iter().flatten() {
            self.width.lo = fmin(self.width.lo, w * height.lo);
            self.width.hi = fmax(self.width.hi, w * height.hi);
        }
    }

    /// Step 4 of [`road_geometry`]: a result if any tilt cell fitted (the
    /// width if any of them gave one). (Until an adversarial review a
    /// result needed a width too: sticks consistent with a tilt and a
    /// height, but whose points of one boundary were all near the horizon,
    /// came out [`GeometryError::Inconsistent`].)
    fn finish(self, outliers: usize) -> Result<RoadGeometry, GeometryError> {
        let Hull {
            tilt,
            height,
            width,
        } = self;
        if !tilt.lo.is_finite() {
            return Err(GeometryError::Inconsistent);
        }
        Ok(RoadGeometry {
            height,
            tilt,
            width: width.lo.is_finite().then_some(width),
            outliers_allowed: outliers,
        })
    }
}

/// Camera height, tilt and road width from one or more views — the samples
/// of the left and the right boundary of a reconstruction (each in order
/// along its boundary) — of the same road from the same camera mounting,
/// e.g. successive frame pairs. A `(θ, h)` must agree with the points of
/// all views (all but `outliers` of them, for wrong matches); the width is
/// the median over the views of each view's median boundary distance. `P`
/// is the capacity for the plane fit's points together (the caller names
/// it, as in `road_geometry::<512>(&views, 0)`; not the processor's `N`); when there are
/// more, every boundary of every view keeps the same number of its
/// nearest points (by the stick's middle, in any order given), as many as
/// fit, and the farther ones are left out.
///
/// Input: 1 to [`MAX_VIEWS`] views, no more boundaries (`2 · views`) than
/// `P`, [`MIN_POINTS`] to `P` samples on each boundary, every sample
/// finite with `|x|, |y| ≤` [`MAX_NORMALISED`] and `0 ≤ z_near ≤ z_far ≤`
/// [`MAX_SAMPLE_DEPTH`], `outliers` below the plane fit's points; anything
/// else is a typed error (naming the first bad sample).
///
/// The height and tilt ranges hold every `(θ, h)` with `θ` in `[0°, 60°]`
/// that agrees with the sticks of all but `outliers` of the plane-fit
/// points (module docs: a superset, by the widening over a 0.003°
/// part of a cell), and [`GeometryError::Inconsistent`] means no such
/// `(θ, h)` exists; the width range is an estimate, `None` when no view
/// gives one.
///
/// Work: `G = 1200` tilt cells (a constant), each with `O(M log M)` for
/// the heights of the `M ≤ P` plane-fit points (16 times more in a cell
/// with any), and at most `G + 1` grid tilts with `O(V · m²)` for the
/// widths of `V ≤ 16` views of `m ≤ P` points per boundary — a check of
/// the reconstruction, not a per-frame task.
pub fn road_geometry<const P: usize>(
    views: &[(&[Sample], &[Sample])],
    outliers: usize,
) -> Result<RoadGeometry, GeometryError> {
    // 1. Validate the input.
    check_views::<P>(views)?;
    // 2. Gather the points of the plane fit.
    let mut all = [Sample::default(); P];
    let points = plane_points(views, &mut all)?;
    if outliers >= points.len() {
        return Err(GeometryError::TooManyOutliers);
    }
    // 3. Sweep the tilt cells: heights consistent in each, and widths at
    // its ends (each grid tilt's width made once, when a cell needs it).
    let mut hull = Hull {
        tilt: Hull::EMPTY,
        height: Hull::EMPTY,
        width: Hull::EMPTY,
    };
    // `sin_cos` is valid here: the tilts are in [0, 60°].
    let mut a = (0.0f32, sin_cos(0.0));
    let mut width_a: Option<Option<f32>> = None;
    for step in 1..=TILT_STEPS {
        let tb = f32::from(step) * TILT_STEP;
        let b = (tb, sin_cos(tb));
        let cell = Cell { a: a.1, b: b.1 };
        let mut width_b = None;
        if heights::<P>(points, &cell, outliers).is_some() {
            let wa = *width_a.get_or_insert_with(|| median_width::<P>(views, a.1 .0, a.1 .1));
            let wb = median_width::<P>(views, b.1 .0, b.1 .1);
            width_b = Some(wb);
            // The cell's heights from its `SUB_CELLS` parts (each a
            // superset of its own, and the parts cover the cell).
            let mut sa = a;
            for part in 1..=SUB_CELLS {
                let t = if part == SUB_CELLS {
                    tb
                } else {
                    a.0 + TILT_STEP * (f32::from(part) / f32::from(SUB_CELLS))
                };
                let sb = (t, sin_cos(t));
                let sub = Cell { a: sa.1, b: sb.1 };
                if let Some(h) = heights::<P>(points, &sub, outliers) {
                    hull.add((sa.0, sb.0), h, [wa, wb]);
                }
                sa = sb;
            }
        }
        (a, width_a) = (b, width_b);
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
