//! The per-frame processor: keeps the previous frame and turns each new
//! frame plus its motion into the 3-D road structure.
//!
//! Memory is fixed at compile time: a `Processor<N, B>` holds the previous
//! frame (`B` boundaries of up to `N` points), the search index of one
//! boundary and the output (`B × N` [`PointResult`]s), nothing else; see
//! [`Processor`] for the byte counts. Work per frame is one pass over the
//! points of each boundary (see [`crate::epipolar::IndexedSearch`]).

use core::fmt;

use crate::boundary::Frame;
use crate::buffer::Buffer;
use crate::camera::{Camera, Pixel};
use crate::depth::{chord, crossing_angle, stick, stick_exact, DepthInterval, CHORD_HALF_WINDOW};
use crate::epipolar::half_key;
use crate::epipolar::{
    Compensated, CrossingSearch, Crossings, EpipolarLine, IndexedSearch, PairGeometry, PencilKey,
    SingleRun, Unwrap, ANGULAR_EPS, MAX_CROSSINGS, MAX_RAY_CROSSINGS,
};
use crate::math::{fmax, fmin};
use crate::motion::Motion;

/// Tuning of the reconstruction. All values are validated by [`Config::new`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    e1: f32,
    e2: f32,
    sin_min_angle: f32,
    max_depth: f32,
    translation_error: f32,
    rotation_error: [f32; 3],
}

/// Why a configuration was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigError {
    /// A localisation error is negative, NaN or above 100 px.
    LocalisationError,
    /// The minimum crossing angle is not in `[0.1°, 89°]`.
    MinAngle,
    /// The maximum depth is not finite and positive.
    MaxDepth,
    /// The translation error bound is negative, NaN or too large.
    TranslationError,
    /// A rotation error bound is negative, NaN, or they sum above 0.1 rad.
    RotationError,
}

impl core::error::Error for ConfigError {}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::LocalisationError => "localisation error must be in [0, 100] px",
            Self::MinAngle => "minimum crossing angle must be in [0.1, 89] degrees",
            Self::MaxDepth => "maximum depth must be finite and positive",
            Self::TranslationError => "translation error bound must be in [0, 1e6]",
            Self::RotationError => "rotation error bounds must be >= 0 and sum to at most 0.1 rad",
        })
    }
}

impl Default for Config {
    /// `e₁ = e₂ = 0.5` px (the paper's `e = 1` px), minimum crossing angle
    /// 10°, maximum depth 1000 length units.
    fn default() -> Self {
        Self {
            e1: 0.5,
            e2: 0.5,
            sin_min_angle: 0.173_648_18,
            max_depth: 1000.0,
            translation_error: 0.0,
            rotation_error: [0.0; 3],
        }
    }
}

impl Config {
    /// Checked constructor.
    ///
    /// * `e1`, `e2`: largest localisation error of a boundary point in frame 1
    ///   and of the boundary in frame 2, pixels (the paper's `e = e₁ + e₂`).
    /// * `min_angle_deg`: intersections flatter than this are [`Status::Grazing`].
    /// * `max_depth`: depths beyond it are [`Status::BeyondMaxDepth`].
    ///
    /// ```
    /// use roadstereo::Config;
    /// let c = Config::new(0.5, 0.5, 10.0, 200.0)?;
    /// assert_eq!(c.total_error(), 1.0);
    /// assert!(Config::new(-1.0, 0.5, 10.0, 200.0).is_err());
    /// # Ok::<(), roadstereo::ConfigError>(())
    /// ```
    pub fn new(e1: f32, e2: f32, min_angle_deg: f32, max_depth: f32) -> Result<Self, ConfigError> {
        let ok_e = |e: f32| (0.0..=100.0).contains(&e);
        if !(ok_e(e1) && ok_e(e2)) {
            return Err(ConfigError::LocalisationError);
        }
        if !(0.1..=89.0).contains(&min_angle_deg) {
            return Err(ConfigError::MinAngle);
        }
        if !(max_depth.is_finite() && max_depth > 0.0) {
            return Err(ConfigError::MaxDepth);
        }
        Ok(Self {
            e1,
            e2,
            sin_min_angle: crate::math::sin_cos(min_angle_deg.to_radians()).0,
            max_depth,
            translation_error: 0.0,
            rotation_error: [0.0; 3],
        })
    }

    /// The same configuration with sticks that also hold when each
    /// component `(U, V, W)` of the translation given to
    /// [`Processor::process`] may be off by up to `delta` (length units,
    /// frame-1 camera axes): the combined interval of quantisation and
    /// translation error (Sec. 4.2), guaranteed for every translation in that
    /// box. See [`crate::depth`] for the bound.
    ///
    /// ```
    /// use roadstereo::Config;
    /// let c = Config::default().with_translation_error(0.02)?;
    /// assert_eq!(c.translation_error(), 0.02);
    /// assert!(Config::default().with_translation_error(-1.0).is_err());
    /// # Ok::<(), roadstereo::ConfigError>(())
    /// ```
    pub fn with_translation_error(mut self, delta: f32) -> Result<Self, ConfigError> {
        if !(0.0..=crate::math::MAX_TRANSLATION).contains(&delta) {
            return Err(ConfigError::TranslationError);
        }
        self.translation_error = delta;
        Ok(self)
    }

    /// The same configuration with sticks that also hold when the rotation
    /// given to [`Processor::process`] may be off by up to `eps` radians
    /// about each axis (`x`, `y`, `z`; at most 0.1 rad in all): every
    /// point's frame-1 localisation error grows by
    /// [`crate::motion_error::rotation_shift_bound`].
    ///
    /// ```
    /// use roadstereo::Config;
    /// let c = Config::default().with_rotation_error([0.01, 0.01, 0.005])?;
    /// assert!(Config::default().with_rotation_error([0.1, 0.1, 0.0]).is_err());
    /// # Ok::<(), roadstereo::ConfigError>(())
    /// ```
    pub fn with_rotation_error(mut self, eps: [f32; 3]) -> Result<Self, ConfigError> {
        let total = eps[0] + eps[1] + eps[2];
        if eps.iter().any(|e| !(0.0..=0.1).contains(e)) || total > 0.1 {
            return Err(ConfigError::RotationError);
        }
        self.rotation_error = eps;
        Ok(self)
    }

    /// Bound on the rotation error about each axis, radians.
    pub fn rotation_error(&self) -> [f32; 3] {
        self.rotation_error
    }

    /// Bound on each translation component's error, length units.
    pub fn translation_error(&self) -> f32 {
        self.translation_error
    }

    /// `e = e₁ + e₂`, pixels.
    pub fn total_error(&self) -> f32 {
        self.e1 + self.e2
    }
    /// Frame-1 localisation error `e₁`, pixels.
    pub fn e1(&self) -> f32 {
        self.e1
    }
    /// Frame-2 localisation error `e₂`, pixels.
    pub fn e2(&self) -> f32 {
        self.e2
    }
    /// Maximum depth, length units.
    pub fn max_depth(&self) -> f32 {
        self.max_depth
    }
}

/// Outcome for one frame-1 boundary point. Only [`Status::Ok`] is unflagged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum Status {
    /// Matched; depth and stick given.
    Ok,
    /// Several intersections (2 to [`MAX_CROSSINGS`]); the one nearest to the
    /// rotated point along the epipolar line (smallest disparity, ties to the
    /// lower segment index) was taken. Depth and stick given, but flagged.
    Ambiguous,
    /// The point's error disc contains the focus of expansion: no disparity.
    AtFoe,
    /// After rotation compensation the ray points behind the frame-2 camera.
    BehindCamera,
    /// The epipolar search range does not meet the corresponding frame-2
    /// boundary (or frame 2 has no boundary with this index).
    #[default]
    NoIntersection,
    /// More than [`MAX_CROSSINGS`] intersections with the search range, or
    /// more than [`crate::epipolar::MAX_RAY_CROSSINGS`] with the whole ray
    /// from the FOE through the point: the boundary runs along the
    /// epipolar line.
    Tangled,
    /// The epipolar line meets the boundary flatter than the minimum angle.
    Grazing,
    /// The triangulated depth is not positive (numerically degenerate).
    NonPositiveDepth,
    /// The depth exceeds [`Config::max_depth`].
    BeyondMaxDepth,
    /// The disparity is not larger than its error: the stick's far end is
    /// unbounded.
    Unbounded,
    /// The point would have a depth, but its epipolar line meets the
    /// frame-1 boundary again, more than [`crate::depth::CHORD_HALF_WINDOW`]
    /// points away: the boundary folds across the epipolar lines, so the
    /// frame-2 intersection may be the image of another part of the curve
    /// (one possibly not visible in frame 2). The correspondence is not
    /// unique; no depth is given.
    Folded,
}

impl Status {
    /// Whether a depth, 3-D point and stick are given.
    pub fn has_depth(self) -> bool {
        matches!(self, Status::Ok | Status::Ambiguous)
    }
    /// Whether a frame-2 intersection was chosen.
    pub fn has_match(self) -> bool {
        matches!(
            self,
            Status::Ok
                | Status::Ambiguous
                | Status::Grazing
                | Status::NonPositiveDepth
                | Status::BeyondMaxDepth
                | Status::Unbounded
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
            Status::Tangled => "tangled",
            Status::Grazing => "grazing",
            Status::NonPositiveDepth => "non_positive_depth",
            Status::BeyondMaxDepth => "beyond_max_depth",
            Status::Unbounded => "unbounded",
            Status::Folded => "folded",
        }
    }
    /// Every status, in declaration order.
    pub const ALL: [Status; 11] = [
        Status::Ok,
        Status::Ambiguous,
        Status::AtFoe,
        Status::BehindCamera,
        Status::NoIntersection,
        Status::Tangled,
        Status::Grazing,
        Status::NonPositiveDepth,
        Status::BeyondMaxDepth,
        Status::Unbounded,
        Status::Folded,
    ];
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Result for one frame-1 boundary point (32 bytes).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PointResult {
    pixel1: Pixel,
    pixel2: Pixel,
    z: f32,
    z_near: f32,
    z_far: f32,
    status: Status,
}

impl PointResult {
    /// No result (what unused output entries hold).
    const EMPTY: Self = Self {
        pixel1: Pixel::new(0.0, 0.0),
        pixel2: Pixel::new(0.0, 0.0),
        z: 0.0,
        z_near: 0.0,
        z_far: 0.0,
        status: Status::NoIntersection,
    };

    /// The outcome.
    pub fn status(&self) -> Status {
        self.status
    }
    /// The frame-1 pixel (as given, before rotation compensation).
    pub fn pixel1(&self) -> Pixel {
        self.pixel1
    }
    /// The matched frame-2 pixel, if an intersection was chosen.
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
}

/// Per-point results of one boundary, in the order of its frame-1 points.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BoundaryStructure<const N: usize> {
    points: Buffer<PointResult, N>,
}

impl<const N: usize> BoundaryStructure<N> {
    const EMPTY: Self = Self {
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
    camera1: Camera,
    slots: [BoundaryStructure<N>; B],
    count: usize,
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
    /// Per-boundary results (index as in frame 1).
    pub fn boundaries(&self) -> &[BoundaryStructure<N>] {
        self.slots.get(..self.count).unwrap_or(&[])
    }

    /// The camera of frame 1, in whose coordinates the points are given.
    pub fn camera1(&self) -> &Camera {
        &self.camera1
    }

    /// 3-D point `(X, Y, Z)` of a result: `X = x₁ Z`, `Y = y₁ Z` (eq. 2.3).
    pub fn point(&self, r: &PointResult) -> Option<[f32; 3]> {
        let z = r.depth()?;
        let (x, y) = self.camera1.normalise(r.pixel1);
        Some([x * z, y * z, z])
    }

    /// The stick's two 3-D end points (near, far) on the frame-1 ray.
    pub fn stick(&self, r: &PointResult) -> Option<([f32; 3], [f32; 3])> {
        let i = r.interval()?;
        let (x, y) = self.camera1.normalise(r.pixel1);
        Some((
            [x * i.z_near, y * i.z_near, i.z_near],
            [x * i.z_far, y * i.z_far, i.z_far],
        ))
    }

    /// A 32-bit FNV-1a digest of every result, bit for bit (status, both
    /// pixels, depth and stick of every point, boundary by boundary): two
    /// runs agree exactly iff their digests agree (up to hash collisions).
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
                eat(r.status as u32);
                for x in [
                    r.pixel1.u, r.pixel1.v, r.pixel2.u, r.pixel2.v, r.z, r.z_near, r.z_far,
                ] {
                    eat(x.to_bits());
                }
            }
        }
        h
    }

    /// How many points have each status, indexed like [`Status::ALL`].
    pub fn status_counts(&self) -> [usize; 11] {
        let mut c = [0usize; 11];
        for r in self.boundaries().iter().flat_map(|b| b.points()) {
            if let Some(slot) = c.get_mut(r.status as usize) {
                *slot += 1;
            }
        }
        c
    }
}

/// What [`Processor::process`] produced.
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
pub enum ProcessError {
    /// A previous frame exists but no motion was given.
    MissingMotion,
    /// [`Processor::process_against_kept`] was called with no kept frame.
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

/// The per-frame motion-stereo processor for up to `B` boundaries of up to
/// `N` points. No heap: everything lives inside this value, so it can be a
/// `static`.
///
/// Size (bytes, 32-bit target): about `8·B·N` (previous frame) + `12·N`
/// (search index) + `32·B·N` (output) + ~100; for `N = 256, B = 2` about
/// 23.2 KiB (23 740 B on the Cortex-M4F), checked by a test.
///
/// ```
/// use roadstereo::{Camera, Config, Frame, Motion, Pixel, Processor, Step};
/// let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap();
/// let mut p = Processor::<64, 2>::new(Config::default());
///
/// // Frame 1: one boundary, a line on the ground to the left.
/// let mut f1 = Frame::new(cam);
/// f1.push_boundary(&[Pixel::new(100.0, 400.0), Pixel::new(150.0, 300.0)]).unwrap();
/// assert!(matches!(p.process(&f1, None), Ok(Step::First)));
///
/// // Frame 2 after moving forward: the boundary moved outwards.
/// let mut f2 = Frame::new(cam);
/// f2.push_boundary(&[Pixel::new(40.0, 470.0), Pixel::new(130.0, 300.0)]).unwrap();
/// let m = Motion::new([0.0, 0.0, 0.4], [0.0, 0.0, 0.0]).unwrap();
/// if let Ok(Step::Structure(s)) = p.process(&f2, Some(&m)) {
///     let r = &s.boundaries()[0].points()[1];
///     assert!(r.depth().is_some());
/// } else {
///     panic!("expected a structure");
/// }
/// ```
#[derive(Debug, Clone)]
pub struct Processor<const N: usize, const B: usize> {
    config: Config,
    previous: Frame<N, B>,
    has_previous: bool,
    search: IndexedSearch<N>,
    output: Structure<N, B>,
}

impl<const N: usize, const B: usize> Processor<N, B> {
    /// A processor with no previous frame.
    pub const fn new(config: Config) -> Self {
        Self {
            config,
            previous: Frame::new(Camera::PLACEHOLDER),
            has_previous: false,
            search: IndexedSearch::new(),
            output: Structure {
                camera1: Camera::PLACEHOLDER,
                slots: [BoundaryStructure::EMPTY; B],
                count: 0,
            },
        }
    }

    /// The configuration.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The kept previous frame, if any.
    pub fn previous(&self) -> Option<&Frame<N, B>> {
        self.has_previous.then_some(&self.previous)
    }

    /// Forget the previous frame (e.g. after a camera reset).
    pub fn reset(&mut self) {
        self.has_previous = false;
    }

    /// Process the next frame with the motion from the previous one.
    ///
    /// The first frame (or the first after [`Processor::reset`]) is kept and
    /// [`Step::First`] returned; `motion` is then ignored. On error nothing
    /// changes. On success the new frame becomes the previous one.
    pub fn process(
        &mut self,
        frame: &Frame<N, B>,
        motion: Option<&Motion>,
    ) -> Result<Step<'_, N, B>, ProcessError> {
        let first = self.run_own(frame, motion, true)?;
        Ok(if first {
            Step::First
        } else {
            Step::Structure(&self.output)
        })
    }

    /// [`Processor::process`] with a caller-chosen crossing search (tests use
    /// a brute-force one); the fold test still uses the built-in index.
    /// Returns `Ok(true)` for a first frame.
    pub fn process_with<S: CrossingSearch>(
        &mut self,
        frame: &Frame<N, B>,
        motion: Option<&Motion>,
        search: &mut S,
    ) -> Result<bool, ProcessError> {
        self.run_using(frame, motion, true, |index| WithSearch(index, search))
    }

    /// Reconstruct `frame` against the kept frame *without replacing it*,
    /// which makes the kept frame a key frame; `motion` is from the kept
    /// frame to `frame`. Pairing one key frame with several later frames
    /// gives views of the same boundary points with longer baselines: the
    /// disparity grows with the travel (eq. 2.3; the motion factor `F` of
    /// eq. 3.4) and the sticks shrink with it, which is how
    /// [`crate::geometry::road_geometry`] fuses frames. Errors leave the kept
    /// state unchanged; with no kept frame this is
    /// [`ProcessError::NoKeptFrame`].
    pub fn process_against_kept(
        &mut self,
        frame: &Frame<N, B>,
        motion: &Motion,
    ) -> Result<&Structure<N, B>, ProcessError> {
        if !self.has_previous {
            return Err(ProcessError::NoKeptFrame);
        }
        self.run_own(frame, Some(motion), false)?;
        Ok(&self.output)
    }

    /// [`run`] with the built-in index; `replace`: keep `frame` afterwards.
    fn run_own(
        &mut self,
        frame: &Frame<N, B>,
        motion: Option<&Motion>,
        replace: bool,
    ) -> Result<bool, ProcessError> {
        self.run_using(frame, motion, replace, OwnIndex)
    }

    /// [`run`] with the searches `searches` makes of the built-in index.
    fn run_using<'a, T: Searches<N>>(
        &'a mut self,
        frame: &Frame<N, B>,
        motion: Option<&Motion>,
        replace: bool,
        searches: impl FnOnce(&'a mut IndexedSearch<N>) -> T,
    ) -> Result<bool, ProcessError> {
        let Self {
            config,
            previous,
            has_previous,
            search,
            output,
        } = self;
        run(
            config,
            previous,
            has_previous,
            output,
            frame,
            motion,
            replace,
            &mut searches(search),
        )
    }

    /// The output of the last successful reconstruction (empty before one).
    pub fn structure(&self) -> &Structure<N, B> {
        &self.output
    }
}

/// The two uses of search scratch in one frame, one after the other: the
/// fold test over frame 1, then the crossing search over frame 2. With the
/// built-in index both share one index (no extra memory).
trait Searches<const N: usize> {
    type Crossing: CrossingSearch;
    fn index(&mut self) -> &mut IndexedSearch<N>;
    fn crossing(&mut self) -> &mut Self::Crossing;
    /// The built-in index as the crossing search, if it is the one used.
    fn lean(&mut self) -> Option<&mut IndexedSearch<N>>;
}

struct OwnIndex<'a, const N: usize>(&'a mut IndexedSearch<N>);

impl<const N: usize> Searches<N> for OwnIndex<'_, N> {
    type Crossing = IndexedSearch<N>;
    fn index(&mut self) -> &mut IndexedSearch<N> {
        self.0
    }
    fn crossing(&mut self) -> &mut IndexedSearch<N> {
        self.0
    }
    fn lean(&mut self) -> Option<&mut IndexedSearch<N>> {
        Some(self.0)
    }
}

struct WithSearch<'a, const N: usize, S>(&'a mut IndexedSearch<N>, &'a mut S);

impl<const N: usize, S: CrossingSearch> Searches<N> for WithSearch<'_, N, S> {
    type Crossing = S;
    fn index(&mut self) -> &mut IndexedSearch<N> {
        self.0
    }
    fn crossing(&mut self) -> &mut S {
        self.1
    }
    fn lean(&mut self) -> Option<&mut IndexedSearch<N>> {
        None
    }
}

#[allow(clippy::too_many_arguments)]
fn run<const N: usize, const B: usize, S: Searches<N>>(
    config: &Config,
    previous: &mut Frame<N, B>,
    has_previous: &mut bool,
    out: &mut Structure<N, B>,
    frame: &Frame<N, B>,
    motion: Option<&Motion>,
    replace: bool,
    searches: &mut S,
) -> Result<bool, ProcessError> {
    if !*has_previous {
        previous.assign(frame);
        *has_previous = true;
        return Ok(true);
    }
    let Some(motion) = motion else {
        return Err(ProcessError::MissingMotion);
    };
    let geom = PairGeometry::new(previous.camera(), frame.camera(), motion);
    let errors = MotionErrors::new(config, &geom);
    out.camera1 = *previous.camera();
    // The output's slots are sized, not filled: pass 1 writes every entry.
    out.count = previous.boundaries().len();
    for (k, (b1, bs)) in previous
        .boundaries()
        .iter()
        .zip(out.slots.iter_mut())
        .enumerate()
    {
        // How epipolar lines are keyed for this boundary pair: by the
        // half-plane pseudo-angle when the frame-2 boundary lies wholly
        // above or below the FOE (the usual road scene), else as the pair
        // geometry says.
        let b2 = frame.boundaries().get(k).map(|b| b.points());
        let b2_ends = b2.and_then(|b| Some((*b.first()?, *b.last()?)));
        let key = b2_ends
            .and_then(|(f, l)| geom.half_key(f.v, l.v))
            .unwrap_or(*geom.key());
        // The keys of the frame-2 boundary's end vertices: the orientation
        // of its keys, and a guess for frame 1's (the fold test).
        let ends = b2_ends.map(|(f, l)| (key.vertex_key(f.arr()), key.vertex_key(l.arr())));
        let n = b1.points().len();
        bs.points.set_len(n);
        // Pass 1: compensate every frame-1 point once. The output entry
        // holds the compensated point until pass 2 overwrites it: p₁' in
        // `pixel2`, q_z in `z`, the stretch in `z_near`, the raw key of
        // its epipolar line in `z_far` (no extra memory); the unwrapped
        // keys go to the index's key array.
        //
        // The fold test (frame 1 only): does a point's epipolar line meet
        // the frame-1 boundary again, away from the point itself? The line
        // through the FOE and p₁' has p₁''s own key. Pass 1 and
        // `fold_suffix` do it in two sweeps when the key margin is a
        // constant (pseudo-angles, whole or half-plane).
        let index = searches.index();
        let (prefix, periodic) = match key {
            PencilKey::Angular { .. } => (true, true),
            PencilKey::Half { .. } => (true, false),
            PencilKey::Projective { .. } => (false, false),
        };
        let b1 = b1.points();
        let (o, pass) = if prefix {
            let o = fold_orientation(&geom, &key, b1, ends);
            let pass = match key {
                PencilKey::Half { foe, side, min_t } => pass1::<N, true, false>(
                    &geom,
                    &key,
                    move |v| half_key(foe, side, min_t, v),
                    b1,
                    bs.points.as_mut_slice(),
                    index.keys_mut(),
                    (o, periodic),
                ),
                _ => pass1::<N, true, true>(
                    &geom,
                    &key,
                    move |v| key.vertex_key(v),
                    b1,
                    bs.points.as_mut_slice(),
                    index.keys_mut(),
                    (o, periodic),
                ),
            };
            (o, pass)
        } else {
            let pass = pass1::<N, false, false>(
                &geom,
                &key,
                move |v| key.vertex_key(v),
                b1,
                bs.points.as_mut_slice(),
                index.keys_mut(),
                (1.0, false),
            );
            (1.0, pass)
        };
        let (all_keyed, fast) = pass;
        if !fast {
            if prefix {
                // Undo pass 1's tentative flags.
                for r in bs.points.as_mut_slice().iter_mut() {
                    if r.status == Status::Folded {
                        r.status = Status::NoIntersection;
                    }
                }
            }
            index.index_keys(&key, false, n, all_keyed);
            if index.fold_fast() {
                index.fold_each(|i| {
                    if let Some(r) = bs.points.as_mut_slice().get_mut(i) {
                        r.status = Status::Folded;
                    }
                });
            } else {
                for (i, r) in bs.points.as_mut_slice().iter_mut().enumerate() {
                    if r.status != Status::BehindCamera
                        && index.meets_outside(
                            o * r.z_far,
                            (
                                i.saturating_sub(CHORD_HALF_WINDOW),
                                i + CHORD_HALF_WINDOW - 1,
                            ),
                        )
                    {
                        r.status = Status::Folded;
                    }
                }
            }
        }
        // Pass 2: intersect, triangulate, bound.
        if let Some(b2) = b2 {
            match (searches.lean(), ends) {
                (Some(index), Some(ends)) => index.prepare_with_ends(b2, &key, ends),
                _ => searches.crossing().prepare(b2, &key),
            }
        }
        let lean = match (searches.lean(), b2, errors.frame_disc) {
            (Some(index), Some(b2), Some(disc)) if errors.translation <= 0.0 => {
                index.single_run(b2).map(|run| (run, disc))
            }
            _ => None,
        };
        match lean {
            Some((run, disc)) if run.periodic() => {
                pass2_lean::<N, true>(config, &geom, disc, bs.points.as_mut_slice(), run)
            }
            Some((run, disc)) => {
                pass2_lean::<N, false>(config, &geom, disc, bs.points.as_mut_slice(), run)
            }
            None => pass2(
                config,
                &geom,
                &errors,
                bs.points.as_mut_slice(),
                b2,
                searches.crossing(),
            ),
        }
    }
    if replace {
        previous.assign(frame);
    }
    Ok(false)
}

/// Pass 1 over one frame-1 boundary: compensate every point exactly
/// ([`PairGeometry::compensate_in_frame`]), key its epipolar line, and
/// write the slot (see [`run`]) and the unwrapped key. With `PREFIX`
/// (pseudo-angle keys, whose key margin is a constant) it also does the
/// first half of the fold test in the same sweep: the slot of point `i`
/// is marked [`Status::Folded`] when its key lies in the widened range of
/// the keys of points `0 ..= i − 4`, the path of segments `0 ..= i − 5`
/// (see [`IndexedSearch::fold_each`]); these marks hold only if the
/// keys turn out all usable and span less than a turn (the caller checks).
/// With `PREFIX` it then does the second half ([`fold_suffix`]).
///
/// Returns whether every key is usable ([`crate::epipolar::Unwrap`]), and
/// whether the fold test was done here (`PREFIX`, all keys usable, and
/// for whole-turn keys a span under a turn); `(o, periodic)` are the keys'
/// orientation ([`fold_orientation`]) and whether they are whole-turn
/// pseudo-angles.
#[inline(never)]
fn pass1<const N: usize, const PREFIX: bool, const WRAPS: bool>(
    geom: &PairGeometry,
    key: &PencilKey,
    key_of: impl Fn([f32; 2]) -> f32,
    b1: &[Pixel],
    slots: &mut [PointResult],
    keys: &mut [f32; N],
    (o, periodic): (f32, bool),
) -> (bool, bool) {
    let mut unwrap = Unwrap::new(key);
    // Without wrapping (`!WRAPS`: keys that are not periodic) the keys are
    // used as they come; they are all usable iff their sum is finite.
    let mut sum = 0.0f32;
    let mut prefix = PrefixFold::new();
    // The frame-wide stretch bound, decided once (else each point's own).
    let frame_stretch = geom.frame_stretch();
    for (i, (slot, &p1)) in slots.iter_mut().zip(b1).enumerate() {
        // The branch per point, with each arm inlined whole (one `Option`
        // passed through costs two instructions a point).
        let c = match frame_stretch {
            Some(st) => geom.compensate_with(p1, Some(st)),
            None => geom.compensate(p1),
        };
        let k = match c {
            Some(c) => {
                let raw = key_of(c.pixel);
                let k = if WRAPS {
                    unwrap.next(raw)
                } else {
                    sum += raw;
                    raw
                };
                let mut status = Status::NoIntersection;
                if PREFIX && prefix.met(keys, i, o * k) {
                    status = Status::Folded;
                }
                *slot = PointResult {
                    pixel1: p1,
                    pixel2: Pixel::new(c.pixel[0], c.pixel[1]),
                    z: c.depth_scale,
                    z_near: c.stretch,
                    z_far: raw,
                    status,
                };
                k
            }
            None => {
                *slot = flagged(p1, Status::BehindCamera);
                sum = f32::INFINITY;
                unwrap.next(f32::INFINITY)
            }
        };
        if let Some(s) = keys.get_mut(i) {
            *s = o * k;
        }
    }
    let all_keyed = if WRAPS {
        unwrap.all_keyed()
    } else {
        sum.is_finite()
    };
    let n = slots.len().min(b1.len());
    let fast = PREFIX
        && all_keyed
        && fold_suffix(keys.get(..n).unwrap_or(&[]), slots, prefix.pmax, periodic);
    (all_keyed, fast)
}

/// The prefix half of the fold test, one point at a time along the
/// boundary (see [`pass1`]), on keys oriented by [`fold_orientation`]'s
/// sign (the query does not change when every key changes sign): the
/// maximum of the keys of the points before is kept as the sweep goes,
/// the minimum over `keys[..pmin_upto]` is brought up to date only when a
/// test needs it (each key joins it at most once). The orientation only
/// decides which extreme is kept eagerly.
struct PrefixFold {
    pmin: f32,
    pmax: f32,
    pmin_upto: usize,
}

impl PrefixFold {
    fn new() -> Self {
        Self {
            pmin: f32::INFINITY,
            pmax: f32::NEG_INFINITY,
            pmin_upto: 0,
        }
    }

    /// Whether point `i` with (oriented, unwrapped) key `k` meets the
    /// segments `0 ..= i − 5`: its key lies in the widened range of
    /// `keys[..= i − 4]` (which must already hold the keys of the points
    /// before `i`). Called for `i = 0, 1, 2, …` in turn.
    #[inline(always)]
    fn met(&mut self, keys: &[f32], i: usize, k: f32) -> bool {
        let eps = ANGULAR_EPS;
        let Some(&v) = keys.get(i.wrapping_sub(4)) else {
            return false;
        };
        self.pmax = fmax(self.pmax, v);
        if i >= 5 && k <= self.pmax + eps {
            for &w in keys.get(self.pmin_upto..i - 3).unwrap_or(&[]) {
                self.pmin = fmin(self.pmin, w);
            }
            self.pmin_upto = i - 3;
            return self.pmin - eps <= k;
        }
        false
    }
}

/// The second half of the fold test for pseudo-angle keys, after
/// [`pass1`]: marks point `i` [`Status::Folded`] when its key lies in the
/// widened range of the keys of points `i + 4 ..`, the path of segments
/// `i + 4 ..` (present while `i + 4 ≤ n − 2`), on [`pass1`]'s oriented
/// keys; `pmax` is [`pass1`]'s.
/// Returns whether the keys
/// span less than a turn (less 0.1), the condition under which these
/// tests, and pass 1's, equal the general query
/// ([`IndexedSearch::meets_outside`]); otherwise the caller discards them.
#[inline(always)]
fn fold_suffix(keys: &[f32], slots: &mut [PointResult], pmax: f32, periodic: bool) -> bool {
    let eps = ANGULAR_EPS;
    let n = keys.len().min(slots.len());
    let (Some(keys), Some(slots)) = (keys.get(..n), slots.get_mut(..n)) else {
        return false;
    };
    let Some(&last) = keys.last() else {
        return false;
    };
    // Extremes of the keys of points `.. n`: the minimum kept as the sweep
    // goes, the maximum over `keys[smax_from..]` brought up to date only
    // when a test needs it.
    let (mut smin, mut smax) = (last, last);
    let mut smax_from = n - 1;
    // i = n − 6 down to 0, with key i + 4 joining the suffix first.
    let joins = keys.get(..n.saturating_sub(1)).unwrap_or(&[]);
    for (i, w) in joins.windows(5).enumerate().rev() {
        let [k, .., v] = *w else { continue };
        smin = fmin(smin, v);
        if smin - eps <= k {
            for &x in keys.get(i + 4..smax_from).unwrap_or(&[]) {
                smax = fmax(smax, x);
            }
            smax_from = i + 4;
            if k <= smax + eps {
                if let Some(r) = slots.get_mut(i) {
                    r.status = Status::Folded;
                }
            }
        }
    }
    if !periodic {
        return true;
    }
    // The span of all keys: `pmax` covers points `0 ..= n − 5`, `smin`
    // points `4 ..`.
    smax = fmax(smax, pmax);
    for &w in keys.get(n.saturating_sub(4)..).unwrap_or(&[]) {
        smax = fmax(smax, w);
    }
    for &w in keys.iter().take(4.min(n)) {
        smin = fmin(smin, w);
    }
    smax - smin < 4.0 - 0.1
}

/// The likely direction of the keys along a frame-1 boundary (+1 rising,
/// −1 falling), for the fold test's order of work (any value gives the
/// same results): that of its frame-2 counterpart, from the keys of its
/// end vertices `b2_ends` (the same boundary seen from nearly the same
/// place), or of `b1`'s compensated end points when there is none.
fn fold_orientation(
    geom: &PairGeometry,
    key: &PencilKey,
    b1: &[Pixel],
    b2_ends: Option<(f32, f32)>,
) -> f32 {
    let mut d = match b2_ends {
        Some((first, last)) => last - first,
        None => {
            let raw = |p: Option<&Pixel>| {
                p.and_then(|&p| geom.compensate_in_frame(p))
                    .map_or(f32::NAN, |c| key.vertex_key(c.pixel))
            };
            raw(b1.last()) - raw(b1.first())
        }
    };
    // Pseudo-angles: the shorter way round.
    if d > 2.0 {
        d -= 4.0;
    } else if d < -2.0 {
        d += 4.0;
    }
    if d < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// The compensated point pass 1 left in an output entry (see [`run`]):
/// `p₁'` in `pixel2`, `q_z` in `z`, the stretch in `z_near`; `None` for a
/// point behind the camera.
#[inline(always)]
fn stashed(r: &PointResult) -> Option<Compensated> {
    (r.status != Status::BehindCamera).then_some(Compensated {
        pixel: [r.pixel2.u, r.pixel2.v],
        depth_scale: r.z,
        stretch: r.z_near,
    })
}

/// Pass 2 over one boundary: intersect, triangulate, bound.
#[inline(never)]
fn pass2<S: CrossingSearch>(
    config: &Config,
    geom: &PairGeometry,
    errors: &MotionErrors,
    points: &mut [PointResult],
    b2: Option<&[Pixel]>,
    search: &mut S,
) {
    for r in points.iter_mut() {
        let Some(c) = stashed(r) else {
            continue;
        };
        *r = evaluate(
            config,
            geom,
            r.pixel1,
            &c,
            r.z_far,
            errors,
            r.status == Status::Folded,
            b2,
            search,
        );
    }
}

/// The motion-error model of one frame, worked out once per frame.
struct MotionErrors {
    /// Translation error bound per component, including the turn of the
    /// compensated translation by a rotation error: `|T| Σε` (5 % added for
    /// the second order).
    translation: f32,
    /// Whether a rotation error is configured (points then get the shift
    /// bound added to their frame-1 error).
    rotation: bool,
    /// When every point has the same frame-1 error disc (a frame-wide
    /// stretch and no rotation error): its radius `r₁` and the bound on
    /// `|a|²` below which the disc holds the FOE, `max((|W'| max(r₁,
    /// 10⁻³))², 10⁻¹²)`, as [`evaluate`] would compute them per point.
    frame_disc: Option<(f32, f32)>,
}

impl MotionErrors {
    fn new(config: &Config, geom: &PairGeometry) -> Self {
        let [ex, ey, ez] = config.rotation_error;
        let rotation = ex + ey + ez > 0.0;
        // |T| only when a rotation error turns it (else the term is 0).
        let turn = if rotation {
            1.05 * geom.translation_norm() * (ex + ey + ez)
        } else {
            0.0
        };
        Self {
            translation: config.translation_error + turn,
            rotation,
            frame_disc: match geom.frame_stretch() {
                Some(stretch) if !rotation => {
                    let r1 = config.e1 * stretch;
                    Some((r1, foe_guard2(geom.w(), r1)))
                }
                _ => None,
            },
        }
    }
}

/// `|a| = |W'| ρ₁` (ρ₁ the distance to the FOE): `|a|²` at or below this
/// means the frame-1 error disc of radius `r₁` holds the FOE (and `|a|` is
/// not usable below 10⁻⁶ in any case).
fn foe_guard2(w: f32, r1: f32) -> f32 {
    let g = w.abs() * crate::math::fmax(r1, 1.0e-3);
    crate::math::fmax(g * g, 1.0e-12)
}

fn flagged(pixel1: Pixel, status: Status) -> PointResult {
    PointResult {
        pixel1,
        status,
        ..PointResult::default()
    }
}

/// What the crossing search found on one epipolar ray: every crossing of
/// the ray is visited (up to one more than [`MAX_RAY_CROSSINGS`]); those in
/// the search range are counted and the one nearest `p₁'` is kept.
struct Hits {
    on_ray: usize,
    valid: usize,
    /// The crossing nearest `p₁'` (smallest `τ`, then lowest segment), if
    /// `valid > 0`.
    best_tau: f32,
    best_segment: usize,
}

impl Hits {
    fn new() -> Self {
        Self {
            on_ray: 0,
            valid: 0,
            best_tau: f32::INFINITY,
            best_segment: 0,
        }
    }

    /// Take one crossing (any order); `false` once there are too many to
    /// tell apart.
    #[inline(always)]
    fn visit(&mut self, line: &EpipolarLine, x: crate::epipolar::Crossing) -> bool {
        self.on_ray += 1;
        if self.on_ray > MAX_RAY_CROSSINGS {
            return false;
        }
        if line.in_search_range(&x) {
            self.valid += 1;
            if (x.tau, x.segment) < (self.best_tau, self.best_segment) {
                self.best_tau = x.tau;
                self.best_segment = x.segment;
            }
        }
        true
    }

    /// [`Self::visit`] for crossings that come in increasing segment order
    /// with whether they lie in the search range ([`SingleRun::search`]):
    /// of two with the same `τ` the earlier has the lower segment.
    #[inline(always)]
    fn visit_in_order(&mut self, x: crate::epipolar::Crossing, in_range: bool) -> bool {
        self.on_ray += 1;
        if self.on_ray > MAX_RAY_CROSSINGS {
            return false;
        }
        if in_range {
            self.valid += 1;
            if x.tau < self.best_tau {
                self.best_tau = x.tau;
                self.best_segment = x.segment;
            }
        }
        true
    }
}

/// The whole per-point pipeline: compensate, draw the line, intersect,
/// triangulate, bound.
#[allow(clippy::too_many_arguments)]
fn evaluate<S: CrossingSearch>(
    config: &Config,
    geom: &PairGeometry,
    p1: Pixel,
    c: &Compensated,
    key: f32,
    errors: &MotionErrors,
    folded: bool,
    b2: Option<&[Pixel]>,
    search: &mut S,
) -> PointResult {
    let mut line: EpipolarLine = geom.line(c);
    // The key of p₁' (computed in pass 1) is the key of its epipolar line.
    line.key = key;
    let w = geom.w();
    let (r1, guard2) = match errors.frame_disc {
        Some(disc) => disc,
        None => {
            let mut r1 = config.e1 * c.stretch;
            if errors.rotation {
                r1 += crate::motion_error::rotation_shift_bound(
                    c.pixel,
                    geom.camera2_intrinsics(),
                    config.rotation_error,
                );
            }
            (r1, foe_guard2(w, r1))
        }
    };
    if line.a2 <= guard2 {
        return flagged(p1, Status::AtFoe);
    }
    let Some(b2) = b2 else {
        return flagged(p1, Status::NoIntersection);
    };
    let mut hits = Hits::new();
    search.search(&line, b2, |x| hits.visit(&line, x));
    conclude(config, geom, p1, c, &line, &hits, r1, errors, folded, b2)
}

/// Pass 2 for the usual case: a one-run index over the frame-2 boundary,
/// a frame-wide frame-1 error disc `(r₁, guard)` and no translation error.
/// The same results as [`evaluate`] for every point; the crossing search is
/// inlined, and lines it declines go through the index's general search
/// out of line.
#[inline(never)]
fn pass2_lean<const N: usize, const PERIODIC: bool>(
    config: &Config,
    geom: &PairGeometry,
    (r1, guard2): (f32, f32),
    points: &mut [PointResult],
    mut run: SingleRun<'_, N>,
) {
    let errors = MotionErrors {
        translation: 0.0,
        rotation: false,
        frame_disc: Some((r1, guard2)),
    };
    let b2 = run.boundary();
    for r in points.iter_mut() {
        let Some(c) = stashed(r) else {
            continue;
        };
        let mut line: EpipolarLine = geom.line(&c);
        line.key = r.z_far;
        if line.a2 <= guard2 {
            *r = flagged(r.pixel1, Status::AtFoe);
            continue;
        }
        let mut hits = Hits::new();
        if !run.search::<PERIODIC, _>(&line, |x, in_range| hits.visit_in_order(x, in_range)) {
            let mut found = Crossings::new();
            run.collect_general(line, &mut found);
            for &x in found.iter() {
                if !hits.visit(&line, x) {
                    break;
                }
            }
        }
        *r = conclude(
            config,
            geom,
            r.pixel1,
            &c,
            &line,
            &hits,
            r1,
            &errors,
            r.status == Status::Folded,
            b2,
        );
    }
}

/// The rest of the per-point pipeline once the crossings are known:
/// choose, triangulate (eq. 2.3), bound (the stick).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn conclude(
    config: &Config,
    geom: &PairGeometry,
    p1: Pixel,
    c: &Compensated,
    line: &EpipolarLine,
    hits: &Hits,
    r1: f32,
    errors: &MotionErrors,
    folded: bool,
    b2: &[Pixel],
) -> PointResult {
    let status = match_status(hits, folded);
    if !is_match(status) {
        return flagged(p1, status);
    }
    triangulate(
        config,
        geom,
        p1,
        c,
        line,
        (hits.best_tau, hits.best_segment),
        status,
        r1,
        errors,
        b2,
    )
}

/// The outcome of the search: [`Status::Tangled`] or
/// [`Status::NoIntersection`] (final), or for a match its provisional
/// status: [`Status::Folded`] when the fold test marked the point (it
/// applies if a depth is given), else [`Status::Ambiguous`] or
/// [`Status::Ok`].
#[inline(always)]
fn match_status(hits: &Hits, folded: bool) -> Status {
    if hits.on_ray > MAX_RAY_CROSSINGS || hits.valid > MAX_CROSSINGS {
        // Too many to tell apart: the boundary runs along the ray.
        Status::Tangled
    } else if hits.valid == 0 {
        Status::NoIntersection
    } else if folded {
        Status::Folded
    } else if hits.valid > 1 {
        Status::Ambiguous
    } else {
        Status::Ok
    }
}

/// Whether [`match_status`] found a match.
#[inline(always)]
fn is_match(status: Status) -> bool {
    matches!(status, Status::Ok | Status::Ambiguous | Status::Folded)
}

/// Triangulate the match `(τ, segment)` of a point (eq. 2.3) and bound it
/// (the stick); `status` is the match's provisional one ([`match_status`]),
/// kept when a depth is given.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn triangulate(
    config: &Config,
    geom: &PairGeometry,
    p1: Pixel,
    c: &Compensated,
    line: &EpipolarLine,
    (best_tau, best_segment): (f32, usize),
    status: Status,
    r1: f32,
    errors: &MotionErrors,
    b2: &[Pixel],
) -> PointResult {
    let w = geom.w();
    let mut r = PointResult {
        pixel1: p1,
        pixel2: line.at(best_tau),
        status,
        ..PointResult::default()
    };
    // a2 > 1e-12 (checked above); infinite only for absurd motions, and
    // then `a_len` is NaN, which the grazing test below flags.
    let a_len = crate::math::sqrt_pos(line.a2);
    let (sin_low, cos) = crossing_angle(line.a, a_len, chord(b2, best_segment), config.e2);
    // A NaN angle (impossible for validated input) is grazing too: one
    // negated comparison says both.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    let grazing = !(sin_low >= config.sin_min_angle);
    if grazing {
        r.status = Status::Grazing;
        return r;
    }
    // Eq. 2.3 along the disparity: s = W' + |a|/d with the disparity
    // d = τ|a| (τ > 0 by construction), written as the stick writes its
    // ends (see below).
    let d = best_tau * a_len;
    let s = w + a_len / d;
    let z = s / c.depth_scale;
    if z.is_nan() || z <= 0.0 {
        r.status = Status::NonPositiveDepth;
        return r;
    }
    if z > config.max_depth {
        r.status = Status::BeyondMaxDepth;
        return r;
    }
    // The stick holds `z`. For `stick_exact` that needs no clamp: its ends
    // are `(W' + (|a| ± |W'|r₁)/(d ∓ ε…))/q_z` with `ε > 0`, `d − ε > 0`,
    // `q_z > 0` (pass 1 flags the rest), and correctly rounded `+ − × ÷`
    // are monotone in each argument, so the rounded far end is at least
    // the rounded `z` and the near end at most (test
    // `every_depth_lies_in_its_stick`). `stick`'s spreads move its ends by
    // other expressions, so there the stick is widened to `z` if need be.
    let interval = if errors.translation > 0.0 {
        let (spread_a, spread_w) = crate::motion_error::spread(
            geom.rotation(),
            geom.camera2_intrinsics(),
            c.pixel,
            errors.translation,
        );
        stick(
            w,
            best_tau,
            a_len,
            r1,
            config.e2,
            sin_low,
            cos,
            c.depth_scale,
            spread_a,
            spread_w,
        )
        .map(|i| DepthInterval {
            z_near: crate::math::fmin(i.z_near, z),
            z_far: crate::math::fmax(i.z_far, z),
        })
    } else {
        stick_exact(
            w,
            best_tau,
            a_len,
            r1,
            config.e2,
            sin_low,
            cos,
            c.depth_scale,
        )
    };
    match interval {
        // The status stays: `Ok`, `Ambiguous`, or `Folded` (the fold test
        // only matters where a depth would otherwise be given).
        Some(i) => {
            r.z = z;
            r.z_near = i.z_near;
            r.z_far = i.z_far;
        }
        None => r.status = Status::Unbounded,
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::epipolar::Unwrap;
    use crate::test_rng::Rng;

    /// The fold test in two sweeps (pass 1's prefix half, [`PrefixFold`],
    /// and [`fold_suffix`]) answers exactly as the general index query,
    /// whichever orientation it guesses, on key sequences that jitter
    /// around the key margin, fold back and (pseudo-angles) wrap round at
    /// 4, for whole-turn and half-plane keys; and it declines exactly when
    /// whole-turn keys span a turn or more.
    #[test]
    fn two_sweep_fold_test_equals_the_general_query() {
        const M: usize = 64;
        let mut rng = Rng(0x5eed_f01d);
        let (mut compared, mut folds, mut declined) = (0, 0, 0);
        for case in 0..6000 {
            let half = case % 2 == 0;
            let key = if half {
                PencilKey::Half {
                    foe: [0.0, 0.0],
                    side: 1.0,
                    min_t: crate::epipolar::HALF_MIN_DV,
                }
            } else {
                PencilKey::Angular {
                    foe: [0.0, 0.0],
                    sign_w: 1.0,
                }
            };
            let n = 2 + (rng.next() * (M - 2) as f32) as usize;
            // Steps well below the margin up to steps that wind the
            // pseudo-angle round more than a turn.
            let scale = [3.0e-5, 1.0e-4, 1.0e-3, 0.05, 0.3][case / 2 % 5];
            let drift = (rng.next() - 0.5) * scale;
            let mut raw = [0.0f32; M];
            let mut k = if half {
                rng.next() - 0.5
            } else {
                rng.next() * 4.0
            };
            for slot in raw.iter_mut().take(n) {
                *slot = if half {
                    k.clamp(-0.999, 0.999)
                } else {
                    k.rem_euclid(4.0)
                };
                let back = if rng.next() < 0.03 {
                    -30.0 * drift
                } else {
                    0.0
                };
                k += drift + (rng.next() - 0.5) * scale + back;
            }
            // The keys as pass 1 leaves them.
            let mut keys = [0.0f32; M];
            let mut unwrap = Unwrap::new(&key);
            for (u, &r) in keys.iter_mut().zip(&raw).take(n) {
                *u = if half { r } else { unwrap.next(r) };
            }
            let keys = &keys[..n];
            // Pass 1 stores the keys oriented by its guess.
            let o = if rng.next() < 0.5 { 1.0 } else { -1.0 };
            let mut oriented = [0.0f32; M];
            for (d, &k) in oriented.iter_mut().zip(keys) {
                *d = o * k;
            }
            let oriented = &oriented[..n];
            let mut prefix = PrefixFold::new();
            let mut got = [false; M];
            for (i, &k) in oriented.iter().enumerate() {
                got[i] = prefix.met(oriented, i, k);
            }
            let mut slots = [PointResult::default(); M];
            let fast = fold_suffix(oriented, &mut slots[..n], prefix.pmax, !half);
            let (lo, hi) = keys
                .iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &k| {
                    (a.min(k), b.max(k))
                });
            assert_eq!(fast, half || hi - lo < 3.9, "case {case}");
            if !fast {
                declined += 1;
                continue;
            }
            let mut want = [false; M];
            IndexedSearch::<M>::general_fold_flags(&key, keys, &mut want);
            for i in 0..n {
                let g = got[i] || slots[i].status == Status::Folded;
                assert_eq!(g, want[i], "case {case}, point {i} of {n}, o = {o}");
                folds += usize::from(g);
            }
            compared += 1;
        }
        assert!(
            compared > 5000 && folds > 2000 && declined > 50,
            "{compared} {folds} {declined}"
        );
    }
}
