//! What the processor gives back: per point a status, the matched frame-2
//! pixel, the depth and its stick; per frame the structure of every
//! boundary, in frame-1 camera coordinates.

use core::fmt;

use crate::buffer::Buffer;
use crate::camera::{Camera, Pixel};
use crate::depth::DepthInterval;

/// Outcome for one frame-1 boundary point. Only [`Status::Ok`] is unflagged.
///
/// Its `Default` is [`Status::NoIntersection`] (what a result slot holds
/// before its point is matched: no depth).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
#[non_exhaustive]
pub enum Status {
    /// Matched; depth and stick given. The band of the point's error
    /// meets the corresponding frame-2 boundary in one piece, the exact
    /// epipolar line crosses it there, and the stick is bounded.
    Ok,
    /// The band meets the boundary in two (or more) separate pieces: the
    /// correspondence is not unique, and no depth is given.
    Ambiguous,
    /// The point lies within `3 (r₁ + e₂)` of the focus of expansion
    /// (moving forwards without a translation error), its error disc
    /// widened by the motion's error bounds holds the FOE, or (moving
    /// backwards) it is too close to the FOE for its band to be told from
    /// the FOE's: no usable disparity.
    AtFoe,
    /// After rotation compensation the ray points behind the frame-2 camera,
    /// or the depth scale `q_z` is not known to better than half its value.
    BehindCamera,
    /// The band does not meet the corresponding frame-2 boundary, or the
    /// exact epipolar line does not cross it within the band (or frame 2
    /// has no boundary with this index).
    #[default]
    NoIntersection,
    /// A piece of the boundary in the band is longer than the band's width
    /// over the tangent of the minimum angle plus `e₂ · 2/sin φ_min`: no
    /// boundary within `e₂` of the polyline crosses the epipolar line at the
    /// minimum angle or steeper (it runs flatter, or along it).
    Grazing,
    /// The triangulated depth is not positive (numerically degenerate).
    NonPositiveDepth,
    /// The depth exceeds [`crate::Config::max_depth`].
    BeyondMaxDepth,
    /// The stick says nothing: the disparity is not larger than its error
    /// (no far end), or the near end is not above zero.
    Unbounded,
    /// The point's epipolar line meets the frame-1 boundary again, more
    /// than 4 points away: the boundary folds across the
    /// epipolar lines, so a frame-2 crossing may be the image of another
    /// part of the curve (one possibly not visible in frame 2). Not
    /// searched; no depth.
    Folded,
    /// After rotation compensation the point lies far outside the frame-2
    /// image (beyond one image size from its edges): no plausible
    /// correspondence (see [`crate::epipolar::PairGeometry`]); or, with a
    /// rotation error configured, so far off the camera's axis that the
    /// error's shift has no bound
    /// ([`crate::motion_error::rotation_shift_bound`] infinite); or its
    /// error disc `r₁` with `e₂` reaches past the farthest point of that
    /// view from the principal point (only on images not much larger than
    /// the errors; the bound on the focus's rounding needs the true
    /// points within it).
    OutOfView,
    /// The band reaches past an end of the frame-2 boundary (its first or
    /// last point lies in the band): the true crossing may lie beyond what
    /// frame 2 detected, so no stick can be guaranteed.
    BoundaryEnd,
    /// The frame's work budget ([`crate::Config::with_work_budget`]) was
    /// spent before this point's search could finish, or before the
    /// piece's lines could bound a stick that its range leaves unbounded,
    /// or the caller's deadline ([`crate::Processor::process_within`])
    /// expired before the point was done: no depth, and the frame did not
    /// run late.
    OverBudget,
}

/// Points on either side of a point whose segments the fold test skips.
pub(crate) const FOLD_WINDOW: usize = 4;

impl Status {
    /// Whether a depth, 3-D point and stick are given.
    pub fn has_depth(self) -> bool {
        matches!(self, Status::Ok)
    }
    /// Whether a frame-2 crossing was chosen.
    pub fn has_match(self) -> bool {
        matches!(
            self,
            Status::Ok | Status::NonPositiveDepth | Status::BeyondMaxDepth | Status::Unbounded
        )
    }
    /// Whether the point is flagged (anything but [`Status::Ok`]).
    pub fn is_flagged(self) -> bool {
        self != Status::Ok
    }
    /// Short lower-case name, as used in the replay output.
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Ambiguous => "ambiguous",
            Status::AtFoe => "at_foe",
            Status::BehindCamera => "behind_camera",
            Status::NoIntersection => "no_intersection",
            Status::Grazing => "grazing",
            Status::NonPositiveDepth => "non_positive_depth",
            Status::BeyondMaxDepth => "beyond_max_depth",
            Status::Unbounded => "unbounded",
            Status::Folded => "folded",
            Status::OutOfView => "out_of_view",
            Status::BoundaryEnd => "boundary_end",
            Status::OverBudget => "over_budget",
        }
    }
    /// Every status, in declaration order (the wire format's status codes,
    /// `crate::wire`). A slice: a status added in a minor release makes it
    /// longer without changing a public type.
    pub const ALL: &'static [Status] = &[
        Status::Ok,
        Status::Ambiguous,
        Status::AtFoe,
        Status::BehindCamera,
        Status::NoIntersection,
        Status::Grazing,
        Status::NonPositiveDepth,
        Status::BeyondMaxDepth,
        Status::Unbounded,
        Status::Folded,
        Status::OutOfView,
        Status::BoundaryEnd,
        Status::OverBudget,
    ];
}

/// How many statuses there are (the length of [`Status::ALL`]).
pub(crate) const STATUS_COUNT: usize = Status::ALL.len();

/// How many points of a [`Structure`] have each status
/// ([`Structure::status_counts`]).
///
/// ```
/// # use roadstereo::{Status, Structure};
/// fn report<const N: usize, const B: usize>(s: &Structure<N, B>) {
///     let c = s.status_counts();
///     let share = c.get(Status::Ok) as f32 / c.total().max(1) as f32;
///     for (status, n) in c.iter().filter(|&(_, n)| n > 0) {
///         // log `status` and `n`
///     }
/// }
/// ```
#[derive(Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StatusCounts {
    counts: [usize; STATUS_COUNT],
}

/// The statuses by name with their counts, those with none left out:
/// `{"ok": 426, "grazing": 3, ...}`.
impl fmt::Debug for StatusCounts {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_map()
            .entries(
                self.iter()
                    .filter(|&(_, n)| n > 0)
                    .map(|(s, n)| (s.name(), n)),
            )
            .finish()
    }
}

impl StatusCounts {
    /// The points with status `s`.
    pub fn get(&self, s: Status) -> usize {
        self.counts.get(s as usize).copied().unwrap_or(0)
    }
    /// Every status with its count, in the order of [`Status::ALL`].
    pub fn iter(&self) -> impl Iterator<Item = (Status, usize)> + '_ {
        Status::ALL.iter().copied().zip(self.counts.iter().copied())
    }
    /// All points.
    pub fn total(&self) -> usize {
        self.counts.iter().sum()
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Result for one frame-1 boundary point (32 bytes).
///
/// What a result says is its status, its frame-1 pixel, and what the
/// status gives: the frame-2 pixel where [`Status::has_match`], the depth
/// and stick where [`Status::has_depth`]. That is all the accessors show,
/// and all that equality (`==`), `Debug`, `defmt` and
/// [`Structure::digest`] look at: the bytes a flagged result keeps for
/// what its status does not give are unspecified, with or without a
/// deadline (a point the caller's deadline cut off gets its status, not a
/// clean slot, so that the flags written after the clock's yes are one
/// byte a point, [`crate::Processor::process_within`]; a point the
/// counting rule leaves `folded` keeps what the rule kept in its slot).
#[derive(Clone, Copy, Default)]
pub struct PointResult {
    pub(crate) pixel1: Pixel,
    pub(crate) pixel2: Pixel,
    pub(crate) z: f32,
    pub(crate) z_near: f32,
    pub(crate) z_far: f32,
    pub(crate) status: Status,
}

impl PointResult {
    /// No result (what unused output entries hold).
    pub(crate) const EMPTY: Self = Self {
        pixel1: Pixel::new(0.0, 0.0),
        pixel2: Pixel::new(0.0, 0.0),
        z: 0.0,
        z_near: 0.0,
        z_far: 0.0,
        status: Status::NoIntersection,
    };

    /// A flagged result for `pixel1`.
    #[inline(always)]
    pub(crate) fn flagged(pixel1: Pixel, status: Status) -> Self {
        Self {
            pixel1,
            status,
            ..Self::EMPTY
        }
    }

    /// This result flagged `status` (not [`Status::Ok`], nor a status with
    /// a match), its pixel kept and the rest left as it is: what the
    /// result says is [`Self::flagged`]'s (the type's docs). One store,
    /// where [`Self::flagged`] writes the whole slot: the flags a cut
    /// frame writes after the clock's yes, and the counting rule's. Not
    /// for [`Status::NoIntersection`] (a `no_intersection` slot with step
    /// 1's values is a point still to be matched to the passes over a
    /// boundary).
    #[inline(always)]
    pub(crate) fn flag(&mut self, status: Status) {
        self.status = status;
    }

    /// [`Self::flag`] for a slot that holds another point's result (an
    /// earlier frame's): `pixel1` written too. Two stores.
    #[inline(always)]
    pub(crate) fn flag_at(&mut self, pixel1: Pixel, status: Status) {
        self.pixel1 = pixel1;
        self.status = status;
    }

    /// What the result says (the type's docs): status, `pixel1`, and
    /// `pixel2`, `z`, `z_near`, `z_far` where the status gives them, 0
    /// where it does not (what [`Self::flagged`] holds there).
    #[inline]
    fn view(&self) -> (Status, Pixel, Pixel, [f32; 3]) {
        let s = self.status;
        let pixel2 = if s.has_match() {
            self.pixel2
        } else {
            Pixel::new(0.0, 0.0)
        };
        let depth = if s.has_depth() {
            [self.z, self.z_near, self.z_far]
        } else {
            [0.0; 3]
        };
        (s, self.pixel1, pixel2, depth)
    }

    /// The outcome.
    pub fn status(&self) -> Status {
        self.status
    }
    /// The frame-1 pixel (as given, before rotation compensation).
    pub fn pixel1(&self) -> Pixel {
        self.pixel1
    }
    /// The matched frame-2 pixel, if a crossing was chosen: the exact
    /// epipolar line's point there, on the frame-2 polyline up to `f32`
    /// rounding. Measured, not derived: within `2⁻¹⁶ S` px, `S` the largest
    /// coordinate magnitude of the match, the ends of the frame-2 segment
    /// it lies on, the compensated frame-1 point and the FOE, at least 1
    /// (the fuzz pass checks it on every match; with a FOE far outside the
    /// image, nearly sideways motion, or a long segment, the tolerance is
    /// as loose as `S` is large: `docs/METHOD.md`, "A match's pixel lies on the polyline").
    pub fn pixel2(&self) -> Option<Pixel> {
        self.status.has_match().then_some(self.pixel2)
    }
    /// Depth `Z` in frame-1 camera coordinates, if given.
    pub fn depth(&self) -> Option<f32> {
        self.status.has_depth().then_some(self.z)
    }
    /// The stick `[Z_near, Z_far]`, if given.
    pub fn interval(&self) -> Option<DepthInterval> {
        self.status.has_depth().then_some(DepthInterval {
            z_near: self.z_near,
            z_far: self.z_far,
        })
    }
    /// The stick's length relative to the depth
    /// ([`DepthInterval::relative_width`] at [`Self::depth`]), if given:
    /// what to filter uninformative sticks by.
    pub fn relative_width(&self) -> Option<f32> {
        let (stick, z) = (self.interval()?, self.depth()?);
        Some(stick.relative_width(z))
    }
}

/// Equal when they say the same (the type's docs): the fields a status
/// does not give are not compared.
impl PartialEq for PointResult {
    fn eq(&self, other: &Self) -> bool {
        self.view() == other.view()
    }
}

impl fmt::Debug for PointResult {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (status, pixel1, pixel2, [z, z_near, z_far]) = self.view();
        f.debug_struct("PointResult")
            .field("pixel1", &pixel1)
            .field("pixel2", &pixel2)
            .field("z", &z)
            .field("z_near", &z_near)
            .field("z_far", &z_far)
            .field("status", &status)
            .finish()
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for PointResult {
    fn format(&self, f: defmt::Formatter<'_>) {
        let (status, pixel1, pixel2, [z, z_near, z_far]) = self.view();
        defmt::write!(
            f,
            "PointResult {{ pixel1: {}, pixel2: {}, z: {}, z_near: {}, z_far: {}, status: {} }}",
            pixel1,
            pixel2,
            z,
            z_near,
            z_far,
            status
        );
    }
}

/// Per-point results of one boundary, in the order of its frame-1 points.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BoundaryStructure<const N: usize> {
    pub(crate) points: Buffer<PointResult, N>,
}

impl<const N: usize> BoundaryStructure<N> {
    pub(crate) const EMPTY: Self = Self {
        points: Buffer::new(PointResult::EMPTY),
    };

    /// The per-point results.
    pub fn points(&self) -> &[PointResult] {
        self.points.as_slice()
    }
}

/// The 3-D road structure recovered from one frame pair, in frame-1 camera
/// coordinates.
///
/// Its storage is `B` slots of `N` results, filled once when the processor
/// is made; each frame only sets how many are live.
#[derive(Clone)]
pub struct Structure<const N: usize, const B: usize> {
    pub(crate) camera1: Camera,
    pub(crate) slots: [BoundaryStructure<N>; B],
    /// Live boundaries (at most `B`, below 2¹⁶: [`Self::EMPTY`]'s check),
    /// and beside it in the same word whether the caller's deadline cut
    /// the reconstruction short ([`Structure::deadline_expired`]): the
    /// flag costs no byte.
    pub(crate) count: u16,
    pub(crate) cut: bool,
    /// Work units spent and granted ([`Structure::work_units`]).
    pub(crate) work: (u32, u32),
}

impl<const N: usize, const B: usize> PartialEq for Structure<N, B> {
    fn eq(&self, other: &Self) -> bool {
        self.camera1 == other.camera1 && self.boundaries() == other.boundaries()
    }
}

impl<const N: usize, const B: usize> fmt::Debug for Structure<N, B> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Structure")
            .field("camera1", &self.camera1)
            .field("boundaries", &self.boundaries())
            .finish()
    }
}

#[cfg(feature = "defmt")]
impl<const N: usize, const B: usize> defmt::Format for Structure<N, B> {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "Structure {{ camera1: {}, boundaries: {} }}",
            self.camera1,
            self.boundaries()
        )
    }
}

impl<const N: usize, const B: usize> Structure<N, B> {
    pub(crate) const EMPTY: Self = {
        assert!(B <= u16::MAX as usize, "at most 65 535 boundaries");
        Self {
            camera1: Camera::PLACEHOLDER,
            slots: [BoundaryStructure::EMPTY; B],
            count: 0,
            cut: false,
            work: (0, 0),
        }
    };

    /// Per-boundary results (index as in frame 1).
    pub fn boundaries(&self) -> &[BoundaryStructure<N>] {
        self.slots.get(..usize::from(self.count)).unwrap_or(&[])
    }

    /// The frame's work budget ([`crate::Config::with_work_budget`]): the
    /// units the search spent and the units the frame's points brought,
    /// `(spent, granted)`. A frame whose points came out
    /// [`Status::OverBudget`] spent all of it (without a deadline: within
    /// one, [`crate::Processor::process_within`], a point may also be cut
    /// by the cap or the clock, and the points after a cut grant
    /// nothing); the share spent says how close to its budget a frame
    /// came.
    pub fn work_units(&self) -> (u32, u32) {
        self.work
    }

    /// Whether the caller's deadline expired before this structure was
    /// done ([`crate::Processor::process_within`]): its points not matched
    /// by then are [`Status::OverBudget`] (so a consumer can tell the
    /// clock's flags from the work budget's). Always `false` for a
    /// structure from [`crate::Processor::process`]. The result packet
    /// carries it ([`crate::wire::ResultView::deadline_expired`]). Not part
    /// of the structure's equality or [`Self::digest`], which compare the
    /// results.
    pub fn deadline_expired(&self) -> bool {
        self.cut
    }

    /// The camera of frame 1, in whose coordinates the points are given.
    pub fn camera1(&self) -> &Camera {
        &self.camera1
    }

    /// 3-D point `(X, Y, Z)` of a result: `X = x₁ Z`, `Y = y₁ Z` (eq. 2.3).
    pub fn point(&self, r: &PointResult) -> Option<[f32; 3]> {
        let z = r.depth()?;
        let [x, y] = self.camera1.normalise(r.pixel1);
        Some([x * z, y * z, z])
    }

    /// The stick's two 3-D end points (near, far) on the frame-1 ray.
    pub fn stick(&self, r: &PointResult) -> Option<([f32; 3], [f32; 3])> {
        let i = r.interval()?;
        let [x, y] = self.camera1.normalise(r.pixel1);
        Some((
            [x * i.z_near, y * i.z_near, i.z_near],
            [x * i.z_far, y * i.z_far, i.z_far],
        ))
    }

    /// A 32-bit FNV-1a digest of every result, bit for bit (status, both
    /// pixels, depth and stick of every point, boundary by boundary; a
    /// field the point's status does not give counts as 0, as
    /// [`PointResult`]'s equality ignores it): two runs agree exactly iff
    /// their digests agree (up to hash collisions).
    /// Used to check that the firmware computes what the host computes.
    pub fn digest(&self) -> u32 {
        let mut h: u32 = 0x811c_9dc5;
        let mut eat = |x: u32| {
            for b in x.to_le_bytes() {
                h = (h ^ u32::from(b)).wrapping_mul(0x0100_0193);
            }
        };
        for b in self.boundaries() {
            eat(0xB0B0_B0B0);
            for r in b.points() {
                // (What the result says: [`PointResult`]'s docs.)
                let (status, p1, p2, [z, z_near, z_far]) = r.view();
                eat(status as u32);
                for x in [p1.u, p1.v, p2.u, p2.v, z, z_near, z_far] {
                    eat(x.to_bits());
                }
            }
        }
        h
    }

    /// How many points have each status.
    pub fn status_counts(&self) -> StatusCounts {
        let mut c = StatusCounts::default();
        for r in self.boundaries().iter().flat_map(|b| b.points()) {
            if let Some(slot) = c.counts.get_mut(r.status as usize) {
                *slot += 1;
            }
        }
        c
    }
}

/// What [`crate::Processor::process`] produced.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Step<'a, const N: usize, const B: usize> {
    /// There was no previous frame: this one is kept, nothing reconstructed.
    First,
    /// The structure recovered from the previous frame and this one.
    Structure(&'a Structure<N, B>),
}

/// Why a frame was rejected. The kept state is unchanged.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum ProcessError {
    /// A previous frame exists but no motion was given.
    MissingMotion,
    /// [`crate::Processor::process_against_kept`] was called with no kept frame.
    NoKeptFrame,
}

impl core::error::Error for ProcessError {}

impl fmt::Display for ProcessError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::MissingMotion => "a motion from the previous frame is required",
            Self::NoKeptFrame => "there is no kept frame to reconstruct against",
        })
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::format;

    /// `StatusCounts`' `Debug` names the statuses it has (an integrator's
    /// review: a bare array of 13 counts said nothing).
    #[test]
    fn status_counts_debug_names_the_statuses() {
        let mut c = StatusCounts::default();
        assert_eq!(format!("{c:?}"), "{}");
        c.counts[Status::Ok as usize] = 426;
        c.counts[Status::Grazing as usize] = 3;
        assert_eq!(format!("{c:?}"), "{\"ok\": 426, \"grazing\": 3}");
    }

    /// A result is what its status gives (`PointResult`'s docs): a flag
    /// written over another result's bytes (`flag`, `flag_at`) equals the
    /// clean flagged result, prints as it, and digests as it; a field the
    /// status gives still counts.
    #[test]
    fn a_result_is_what_its_status_gives() {
        let p = Pixel::new(3.0, 4.0);
        let ok = PointResult {
            pixel1: Pixel::new(9.0, 9.0),
            pixel2: Pixel::new(5.0, 6.0),
            z: 7.0,
            z_near: 6.5,
            z_far: f32::NAN,
            status: Status::Ok,
        };
        for status in [Status::OverBudget, Status::Folded, Status::NoIntersection] {
            let clean = PointResult::flagged(p, status);
            let mut left = ok;
            left.flag_at(p, status);
            assert_eq!(left, clean);
            assert_eq!(format!("{left:?}"), format!("{clean:?}"));
            let mut over = ok;
            over.pixel1 = p;
            over.flag(status);
            assert_eq!(over, clean);
            let digest = |r: PointResult| {
                let mut s = Structure::<1, 1>::EMPTY;
                s.count = 1;
                if let Some(b) = s.slots.first_mut() {
                    b.points.set_len(1);
                    if let Some(slot) = b.points.as_mut_slice().first_mut() {
                        *slot = r;
                    }
                }
                s.digest()
            };
            assert_eq!(digest(left), digest(clean), "{status:?}");
            assert_ne!(digest(ok), digest(clean));
        }
        // A status with a match compares its frame-2 pixel, and `ok` its
        // depth and stick (a NaN there is unequal, as any float's `==`).
        let mut unbounded = PointResult::flagged(p, Status::Unbounded);
        unbounded.pixel2 = Pixel::new(1.0, 2.0);
        assert_ne!(unbounded, PointResult::flagged(p, Status::Unbounded));
        unbounded.z = 8.0;
        let mut other = unbounded;
        other.z = 0.0;
        assert_eq!(unbounded, other);
        assert_ne!(ok, ok);
        let mut ok2 = ok;
        ok2.z_far = 7.5;
        assert_eq!(ok2, ok2);
        let mut ok3 = ok2;
        ok3.z_near = 6.0;
        assert_ne!(ok2, ok3);
    }
}
