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

/// Why no geometry could be estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GeometryError {
    /// Too few points on a boundary (at least 10 each are needed).
    TooFewPoints,
    /// No tilt in `[0°, 60°]` is consistent with the points.
    Inconsistent,
}

impl core::error::Error for GeometryError {}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::TooFewPoints => "too few reconstructed points on a boundary",
            Self::Inconsistent => "no ground plane is consistent with the sticks",
        })
    }
}

/// Tilt grid step, radians (0.05°).
const TILT_STEP: f32 = 0.000_872_664_6;
/// Tilt grid end, radians (60°).
const TILT_MAX: f32 = core::f32::consts::FRAC_PI_3;

/// Heights consistent with all but `m` of the points at tilt `(s, c)`:
/// the hull of the heights covered by at least `n − m` intervals.
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
    // Sweep: coverage rises at each lo, falls after each hi.
    let (mut i, mut j, mut cover) = (0usize, 0usize, 0usize);
    let (mut first, mut last) = (f32::INFINITY, f32::NEG_INFINITY);
    while i < n || j < n {
        let next_lo = lo.get(i).copied().unwrap_or(f32::INFINITY);
        let next_hi = hi.get(j).copied().unwrap_or(f32::INFINITY);
        if next_lo <= next_hi {
            cover += 1;
            if cover >= need && !first.is_finite() {
                first = next_lo;
            }
            i += 1;
        } else {
            if cover >= need {
                last = next_hi;
            }
            cover = cover.saturating_sub(1);
            j += 1;
        }
    }
    (first.is_finite() && last.is_finite() && first <= last).then_some(Range {
        lo: first,
        hi: last,
    })
}

/// Ground-plane position (lateral, forward) of a sample at tilt `(s, c)`
/// and height 1 (positions scale with the height).
fn ground(p: &Sample, s: f32, c: f32) -> Option<[f32; 2]> {
    let k = p.y * c + s;
    if k <= 0.0 {
        return None;
    }
    let z = 1.0 / k;
    // Camera (x z, y z, z) → vehicle: lateral x z, forward −s y z + c z.
    Some([p.x * z, (-s * p.y + c) * z])
}

/// Median distance, on the plane at height 1, from the points of `b` to the
/// polyline of `a` (both in order along their boundaries).
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

/// Most views (frame pairs) [`road_geometry`] combines.
pub const MAX_VIEWS: usize = 16;

/// Camera height, tilt and road width from one or more views — the samples
/// of the left and the right boundary of a reconstruction (each in order
/// along its boundary) — of the same road from the same camera mounting,
/// e.g. successive frame pairs. A `(θ, h)` must agree with the points of
/// all views (all but `outliers` of them, for wrong matches); the width is
/// the median over the views of each view's median boundary distance. `N`
/// is the capacity for all points together; more are left out (the
/// farther points of each view first).
///
/// Work: `O(G · M log M + G · V · m²)` for `M` points in all, `V` views of
/// `m` points and `G = 1200` tilts — a check of the reconstruction, not a
/// per-frame task.
pub fn road_geometry<const N: usize>(
    views: &[(&[Sample], &[Sample])],
    outliers: usize,
) -> Result<RoadGeometry, GeometryError> {
    if views.is_empty()
        || views.len() > MAX_VIEWS
        || views
            .iter()
            .any(|(l, r)| l.len() < 10 || r.len() < 10 || l.len() > N || r.len() > N)
    {
        return Err(GeometryError::TooFewPoints);
    }
    let mut all = [Sample::default(); N];
    let mut n = 0;
    // The plane fit uses every boundary of every view (the road is taken as
    // planar over the points given; pass the near part of a hilly road).
    let share = (N / (2 * views.len())).max(5);
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
    let pts = all.get(..n).ok_or(GeometryError::TooFewPoints)?;
    let (mut tilt, mut height, mut width) = (
        Range {
            lo: f32::INFINITY,
            hi: f32::NEG_INFINITY,
        },
        Range {
            lo: f32::INFINITY,
            hi: f32::NEG_INFINITY,
        },
        Range {
            lo: f32::INFINITY,
            hi: f32::NEG_INFINITY,
        },
    );
    let mut t = 0.0f32;
    while t <= TILT_MAX {
        let (s, c) = sin_cos(t);
        if let Some(h) = heights::<N>(pts, s, c, outliers) {
            tilt.lo = fmin(tilt.lo, t);
            tilt.hi = fmax(tilt.hi, t);
            height.lo = fmin(height.lo, h.lo);
            height.hi = fmax(height.hi, h.hi);
            let mut w = [0.0f32; MAX_VIEWS];
            let mut k = 0;
            for ((l, r), slot) in views.iter().zip(w.iter_mut()) {
                if let Some(w1) = width_at::<N>(l, r, s, c) {
                    *slot = w1;
                    k += 1;
                }
            }
            if let Some(ws) = w.get_mut(..k) {
                ws.sort_unstable_by(f32::total_cmp);
                if let Some(&w1) = ws.get(k / 2) {
                    width.lo = fmin(width.lo, w1 * h.lo);
                    width.hi = fmax(width.hi, w1 * h.hi);
                }
            }
        }
        t += TILT_STEP;
    }
    if !(tilt.lo.is_finite() && width.lo.is_finite()) {
        return Err(GeometryError::Inconsistent);
    }
    // The grid step: a tilt within half a step beyond the ends may also fit.
    tilt.lo = fmax(tilt.lo - TILT_STEP, 0.0);
    tilt.hi += TILT_STEP;
    Ok(RoadGeometry {
        height,
        tilt,
        width,
        outliers_allowed: outliers,
    })
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
                let (x, y) = cam.normalise(r.pixel1());
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
