//! The per-frame processor: keeps the previous frame and turns each new
//! frame plus its motion into the 3-D road structure.
//!
//! Per frame and boundary, top to bottom ([`Processor::process`]):
//!
//! 1. **Compensate** every frame-1 point ([`crate::epipolar`]): `p₁'`, `1/q_z`,
//!    its error radius `r₁`, and the key of its epipolar line
//!    (`crate::pencil`); points behind the frame-2 camera or far out of
//!    its view are flagged (checks a frame skips when its whole image
//!    passes them, `PairGeometry::certifies_image`).
//! 2. **Fold test**: flag the points whose own epipolar line meets the
//!    compensated frame-1 polyline again away from them
//!    ([`Status::Folded`]). When the keys are strictly ordered along the
//!    polyline nothing folds; when every point has a key without a period
//!    the test is decided from the keys in `O(1)` per point
//!    (`fold::folds_by_hulls`); only otherwise (a point without a key, or
//!    pseudo-angle keys) is the polyline indexed and queried.
//! 3. **Thin** the corresponding frame-2 polyline where the call may
//!    (`crate::thin`: [`Processor::process`] and
//!    [`Processor::process_within`], over the previous frame's boundary,
//!    which step 1 has read; the pair's `e₂` then holds the thinning's
//!    `ε = e₂/256`), and **index** it (`crate::search`).
//! 4. **Match** every remaining point: its error band ([`crate::depth`]),
//!    or, moving forwards without a translation error, the wedge that
//!    holds it (`crate::wedge`; half-plane keys, or pseudo-angle keys
//!    when the wedge's interval has a single copy in the index's
//!    unwrapped keys), the segments the index offers for its key interval
//!    (the wedge path walks the index's runs itself, skipping blocks on a
//!    loose index), the walk over them (`crate::matching`), and the depth
//!    and stick (the submodule `step4`).
//!
//! Memory is fixed at compile time: a `Processor<N, B>` holds the previous
//! frame (`B` boundaries of up to `N` points), one search index and the
//! output (`B × N` [`PointResult`]s), nothing else; see [`Processor`] for
//! the byte counts.
//!
//! # Worst case
//! Every loop of the per-frame call is bounded by a slice length (the
//! points of a boundary, its segments), a capacity or a constant, except
//! the searches' walks and bisections and the refinement of a stick by the
//! piece's lines (`src/wedge.rs`), which are paid from the frame's
//! work budget: each point brings [`Config::work_per_point`] units, unused
//! units carry over, and a point that would need more than there are is
//! flagged [`Status::OverBudget`]. So the cost of a frame is at most a
//! constant per frame, plus one per boundary, plus one per frame-1 and per
//! frame-2 point, plus one per unit of budget: README ("Worst case") gives
//! the measured constants.
//!
//! # The composition's rounding
//! The motion the fusion pairs with is composed from the per-frame ones
//! (`crate::fusion`, its chain), in `f32`: its translation may be off the
//! exact composition by `m_t` and its matrix by `m_r` (`|R_t v − R v| ≤
//! m_r |v|`), bounds the chain keeps (`Processor::process_composed_within`).
//! The translation's rounding is about `2⁻²⁴` of the per-frame
//! translations, not of their sum, so where they cancel (out by 10⁵ and
//! back to 4) it is large against the composed one: an adversarial review
//! found every fused interval missing the truth by 0.7–2.4 % there, until
//! the pairs carried it. Now `Pair::new` carries it three ways:
//! `T' = Rᵀ T` is off by at most `dt = m_r (|T| + m_t) + (1 + m_r) m_t`
//! (`PairGeometry::composition_error`), which moves the focus by at most
//! `√(f² + |d|²) dt/(|W'| − dt)`, added to its rounding (a shift of the
//! frame-1 point moving forwards, of the correspondent backwards, as the
//! focus's own rounding is), and scales `W'`, so every depth, by at most a
//! relative `s = dt/(|W'| − dt)` (the wedge paths' `W'↑`/`W'↓` widened by
//! `1 ± s`, the band path's stick ends likewise); the matrix's error
//! moves every compensated point by at most `f m_r (1 + ρ'²)/(1 − m_r
//! √(1 + ρ'²))` (`PairGeometry::composition_shift`), added to `r₁`, and
//! `q_z` by `m_r |q|`, added to its error. With `dt ≥ |W'|/2` nothing is
//! certified (every point flagged `out_of_view`, `r₁` infinite). The
//! focus's bound is loose by `|T'|/|W'|` (it turns the lines by
//! `dt/|T'|`), so where `dt ≥ |W'|/4` or `|W'| < |T|/2` (nearly
//! sideways motion) the chain puts `dt` into the configuration's
//! translation error instead (`Rounding::in_config`), which the band path
//! carries for any `W'`, zero included; only the matrix's shift is then
//! added here. (A review found sideways drives no longer fusing while
//! the chain refused such pairs.) A motion given to [`Processor::process`]
//! or [`Processor::process_against_kept`] is taken as exact: one a caller
//! composes ([`Motion::then`]) brings its rounding for the configured
//! motion errors to cover.

use crate::boundary::Frame;
use crate::camera::{Camera, Pixel};
use crate::config::Config;
use crate::deadline::{Deadline, Guard, NoDeadline};
use crate::depth::{interval, Band, PointErrors};
use crate::epipolar::PairGeometry;
use crate::matching::{Outcome, Radial, Walker};
use crate::motion::Motion;
use crate::pencil::{half_key, half_key_or_none, Keying, Pencil, NO_KEY};
use crate::search::{
    expired, run_start_in, BlockSkip, Blocks, Builder, Flow, Index, KeyOrder, LazyBlocks, Lean,
    OutOfWork, Query, Tick, Unkeyed, Visitor, Work, CHUNK, CLIP_UNITS,
};
use crate::structure::{PointResult, ProcessError, Status, Step, Structure};
use crate::wedge::{WVertex, Wedge, WedgeWalk, WedgeWalker};

mod counted;
mod pair;
mod step4;

pub(crate) use pair::Rounding;
use pair::{composition_box, Pair};
use step4::{flag_pending, match_boundary, unmatched};

/// The per-frame motion-stereo processor for up to `B` boundaries of up to
/// `N` points. No heap: everything lives inside this value, so it can be a
/// `static`.
///
/// Size (bytes, 32-bit target): `8·B·N` (previous frame) + about
/// `24.75·N` (search index) + `32·B·N` (output) + a few dozen; for `N =
/// 256, B = 2` exactly 26 892 B, asserted at compile time below (issue 11
/// allows up to 28 KiB; `docs/VEHICLE.md`, "Memory", says what the index's bytes buy).
///
/// ```
/// use roadstereo::{Camera, Config, Frame, Motion, Pixel, Processor, Step};
/// let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap();
/// let mut p = Processor::<64, 2>::new(Config::DEFAULT);
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
#[derive(Clone)]
pub struct Processor<const N: usize, const B: usize> {
    config: Config,
    previous: Frame<N, B>,
    has_previous: bool,
    /// Whether step 2's fold test runs: always, but in the tests of
    /// [`Self::without_fold_test_against_kept`] (no room taken: it sits in
    /// `has_previous`'s padding).
    #[cfg(any(test, feature = "_reference"))]
    fold_test: bool,
    /// Whether steps 1–3 take the checking forms of the loops that have a
    /// bounded form on certified half-plane keys: only in the tests of
    /// [`Self::set_checking_forms`] (padding too).
    #[cfg(any(test, feature = "_reference"))]
    checking: bool,
    /// Whether the counting rule for folded points is on
    /// ([`Self::set_fold_counting`]; padding too).
    fold_counting: bool,
    index: Index<N>,
    output: Structure<N, B>,
}

/// The configuration, the kept frame (its live points), the rule's switch
/// and the last structure; not the search index (internal, and `N`
/// entries of it whatever the frame).
impl<const N: usize, const B: usize> core::fmt::Debug for Processor<N, B> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Processor")
            .field("config", &self.config)
            .field("kept", &self.has_previous.then_some(&self.previous))
            .field("fold_counting", &self.fold_counting)
            .field("output", &self.output)
            .finish_non_exhaustive()
    }
}

impl<const N: usize, const B: usize> Processor<N, B> {
    /// A processor with no previous frame. (Its work budget is at most
    /// `⌊(2³² − 1)/(B N)⌋` units a point, below
    /// [`Config::MAX_WORK_PER_POINT`] only where `B N ≥ 4 096`: see
    /// [`Config::with_work_budget`]; [`Self::config`] gives it.)
    pub const fn new(config: Config) -> Self {
        Self {
            config: capped::<N, B>(config),
            previous: Frame::new(Camera::PLACEHOLDER),
            has_previous: false,
            #[cfg(any(test, feature = "_reference"))]
            fold_test: true,
            #[cfg(any(test, feature = "_reference"))]
            checking: false,
            fold_counting: false,
            index: Index::new(),
            output: Structure::EMPTY,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// Use `config` from the next call on (e.g. the error bounds that came
    /// with a frame pair over the link, [`crate::wire`], or those of the
    /// motion [`crate::fusion`] composes from its key frame). The kept frame
    /// and the last output are untouched; a [`Config`] is valid by
    /// construction. (Its work budget capped as in [`Self::new`].)
    ///
    /// ```
    /// use roadstereo::{Config, Processor};
    /// let mut p = Processor::<16, 2>::new(Config::DEFAULT);
    /// p.set_config(Config::DEFAULT.with_translation_error(0.01)?);
    /// assert_eq!(p.config().translation_error(), 0.01);
    /// # Ok::<(), roadstereo::ConfigError>(())
    /// ```
    pub fn set_config(&mut self, config: Config) {
        self.config = capped::<N, B>(config);
    }

    /// The **counting rule** for folded points on (`true`) or off
    /// (`false`, the default), from the next call on. Off, a point whose
    /// epipolar ray meets the frame-1 boundary again is
    /// [`Status::Folded`]: a frame-2 crossing on that ray may be the other
    /// place's image, which two views cannot tell. On, moving forwards
    /// without a translation error (half-plane keys, the usual case), such
    /// a point is searched after all when the boundary meets its ray
    /// exactly once more, nearer the FOE than the point's band, and the
    /// frame-2 boundary crosses the ray between that place and the band:
    /// the other place's image is then there, so what the point's band
    /// holds is its own (`src/fold/count.rs`). It gives back most of the
    /// points on curves that fold across the rays (the certification's
    /// S-bends: about 30 % of their two-view ideal points, none wrong), at
    /// a cost in time where points fold (README, "What the tests show";
    /// `docs/TESTS.md`, "The counting rule"). The stick's guarantee is the
    /// same either way: the rule decides only which points are searched,
    /// and what it assumes is the fold test's own assumption (a frame-2
    /// crossing has a frame-1 source the detector saw).
    ///
    /// ```
    /// use roadstereo::{Config, Processor};
    /// let mut p = Processor::<16, 2>::new(Config::DEFAULT);
    /// assert!(!p.fold_counting());
    /// p.set_fold_counting(true);
    /// assert!(p.fold_counting());
    /// ```
    pub fn set_fold_counting(&mut self, on: bool) {
        self.fold_counting = on;
    }

    /// Whether the counting rule for folded points is on
    /// ([`Self::set_fold_counting`]).
    pub fn fold_counting(&self) -> bool {
        self.fold_counting
    }

    /// The kept previous frame, if any.
    pub fn previous(&self) -> Option<&Frame<N, B>> {
        self.has_previous.then_some(&self.previous)
    }

    /// Forget the previous frame (e.g. after a camera reset).
    pub fn reset(&mut self) {
        self.has_previous = false;
        self.output.cut = false;
    }

    /// Process the next frame with the motion from the previous one.
    ///
    /// The first frame (or the first after [`Processor::reset`]) is kept and
    /// [`Step::First`] returned; `motion` is then ignored. On error nothing
    /// changes. On success the new frame becomes the previous one.
    ///
    /// Each frame is projected with its own [`crate::Camera`]: the two
    /// frames of a pair may have different intrinsics and image sizes (a
    /// zoom, a recalibration), and the guarantees hold for each as given.
    /// After a change of camera *mounting* the motion between the frames
    /// must say so, or [`Self::reset`] first.
    ///
    /// Each boundary of `frame` is **thinned** before it is searched
    /// ([`crate::thin`]): the vertices within `ε = e₂/256` of the chord
    /// between their neighbours dropped (on a detector's rounded straight
    /// stretches, most of them), and the search's `e₂` widened by `ε`, so
    /// every guarantee holds as before, each stick is a few tenths of a per
    /// cent wider, and a match lies within `ε` of the polyline given. The
    /// thinned boundary is written over the previous frame's, which the
    /// call replaces anyway; [`Self::process_against_kept`] keeps its
    /// frame and so searches `frame`'s boundaries as given (its results
    /// may differ from this call's by that much).
    pub fn process(
        &mut self,
        frame: &Frame<N, B>,
        motion: Option<&Motion>,
    ) -> Result<Step<'_, N, B>, ProcessError> {
        self.process_within(frame, motion, &mut NoDeadline)
    }

    /// [`Self::process`] within the caller's `deadline`
    /// ([`crate::deadline`]): asked between stretches of bounded work, one
    /// to three times a point (step 1 where the pair is not certified, the
    /// fold queries, each point's search) and between chunks of each pass
    /// over a boundary, from the first step on; once it has said yes every
    /// point not yet matched is flagged
    /// [`Status::OverBudget`] and the call returns
    /// ([`Self::deadline_expired`] then says so). The frame becomes the
    /// previous one either way, as with [`Self::process`]; the points done
    /// before the deadline are complete results. Under a deadline a point's
    /// search may spend at most [`crate::deadline::CARRY`] times its
    /// allowance between two questions (what it leaves still carries
    /// over), so the point in progress when the time is up ends within a
    /// bounded cost; so a point may also come out with a looser stick
    /// (still holding the truth) than [`Self::process`] gives it, or
    /// another result where that call ran out of budget (`Ok`, or `Folded`
    /// where the fold test's pass the clock stopped had found the point
    /// folding before an unkeyed point sent that call to the index, which
    /// ran out: a review's find). How late the call returns after the
    /// clock's yes, as measured, and the margin to leave for it: README,
    /// "Within a deadline".
    pub fn process_within<D: Deadline>(
        &mut self,
        frame: &Frame<N, B>,
        motion: Option<&Motion>,
        deadline: &mut D,
    ) -> Result<Step<'_, N, B>, ProcessError> {
        if !self.has_previous {
            self.previous.assign(frame);
            self.has_previous = true;
            self.output.cut = false;
            return Ok(Step::First);
        }
        let motion = motion.ok_or(ProcessError::MissingMotion)?;
        self.reconstruct(
            frame,
            motion,
            (Matcher::Indexed, true),
            Rounding::NONE,
            deadline,
        );
        self.previous.assign(frame);
        Ok(Step::Structure(&self.output))
    }

    /// Whether the deadline given to the last reconstruction
    /// ([`Self::process_within`], [`Self::process_against_kept_within`])
    /// expired before it finished: its points not matched by then are
    /// [`Status::OverBudget`]. Always `false` after [`Self::process`] and
    /// [`Self::process_against_kept`].
    pub fn deadline_expired(&self) -> bool {
        self.output.cut
    }

    /// Reconstruct `frame` against the kept frame *without replacing it*,
    /// which makes the kept frame a key frame; `motion` is from the kept
    /// frame to `frame`. Pairing one key frame with several later frames
    /// gives views of the same boundary points with longer baselines: the
    /// disparity grows with the travel (eq. 2.3; the motion factor `F` of
    /// eq. 3.4) and the sticks shrink with it, which is how
    /// [`crate::geometry::road_geometry`] fuses frames. Errors leave the kept
    /// state unchanged; with no kept frame this is
    /// [`ProcessError::NoKeptFrame`]. `frame`'s boundaries are searched as
    /// given: the thinning of [`Self::process`] needs the room of a frame
    /// the call replaces, and this call replaces none.
    pub fn process_against_kept(
        &mut self,
        frame: &Frame<N, B>,
        motion: &Motion,
    ) -> Result<&Structure<N, B>, ProcessError> {
        self.process_against_kept_within(frame, motion, &mut NoDeadline)
    }

    /// [`Self::process_against_kept`] within the caller's `deadline`, as
    /// [`Self::process_within`].
    pub fn process_against_kept_within<D: Deadline>(
        &mut self,
        frame: &Frame<N, B>,
        motion: &Motion,
        deadline: &mut D,
    ) -> Result<&Structure<N, B>, ProcessError> {
        self.process_composed_within(frame, motion, Rounding::NONE, true, deadline)
    }

    /// The fusion's pair ([`crate::fusion`]): `frame` against the kept
    /// frame (kept with `keep`, else replaced by `frame` as
    /// [`Self::process_within`] does) with a motion composed from the
    /// kept frame's, which may be off the per-frame motions' exact
    /// composition by its `f32` rounding, `rounding`. The pair carries
    /// it: module docs, "The composition's rounding".
    pub(crate) fn process_composed_within<D: Deadline>(
        &mut self,
        frame: &Frame<N, B>,
        motion: &Motion,
        rounding: Rounding,
        keep: bool,
        deadline: &mut D,
    ) -> Result<&Structure<N, B>, ProcessError> {
        if !self.has_previous {
            return Err(ProcessError::NoKeptFrame);
        }
        self.reconstruct(frame, motion, (Matcher::Indexed, false), rounding, deadline);
        if !keep {
            self.previous.assign(frame);
        }
        Ok(&self.output)
    }

    /// The output of the last successful reconstruction (empty before one).
    pub fn structure(&self) -> &Structure<N, B> {
        &self.output
    }

    /// [`Processor::process_against_kept`] with the reference matcher: every
    /// frame-2 segment offered to every point's walk in order, no index
    /// (the fold test keeps its index, and on a boundary of pseudo-angle
    /// keys the index still says which points take the band path, those
    /// whose wedge has no single copy: [`crate::search::Lean::copy`]). For
    /// the tests that the indexed search changes nothing; behind the
    /// private `_reference` feature.
    #[cfg(any(test, feature = "_reference"))]
    #[doc(hidden)]
    pub fn reference_against_kept(
        &mut self,
        frame: &Frame<N, B>,
        motion: &Motion,
    ) -> Result<&Structure<N, B>, ProcessError> {
        if !self.has_previous {
            return Err(ProcessError::NoKeptFrame);
        }
        self.reconstruct(
            frame,
            motion,
            (Matcher::Reference, false),
            Rounding::NONE,
            &mut NoDeadline,
        );
        Ok(&self.output)
    }

    /// [`Processor::process`] (frame 2's boundaries thinned as it thins
    /// them, [`crate::thin`]; the frame kept as the previous one after)
    /// with the reference matcher of [`Self::reference_against_kept`] when
    /// `reference`, and step 2's fold test switched off unless `fold_test`:
    /// for the tests that the indexed search changes nothing on thinned
    /// boundaries either; behind the private `_reference` feature. Needs a
    /// previous frame ([`ProcessError::NoKeptFrame`] without one).
    #[cfg(any(test, feature = "_reference"))]
    #[doc(hidden)]
    pub fn process_checked(
        &mut self,
        frame: &Frame<N, B>,
        motion: &Motion,
        (reference, fold_test): (bool, bool),
    ) -> Result<&Structure<N, B>, ProcessError> {
        self.test_reconstruct(frame, motion, (reference, fold_test, true))?;
        self.previous.assign(frame);
        Ok(&self.output)
    }

    /// The tests' reconstruction of `frame` against the previous frame:
    /// the reference matcher when `reference`, step 2's fold test on only
    /// with `fold_test`, frame 2's boundaries thinned with `thin` (over the
    /// previous frame's, which the caller then replaces).
    #[cfg(any(test, feature = "_reference"))]
    fn test_reconstruct(
        &mut self,
        frame: &Frame<N, B>,
        motion: &Motion,
        (reference, fold_test, thin): (bool, bool, bool),
    ) -> Result<(), ProcessError> {
        if !self.has_previous {
            return Err(ProcessError::NoKeptFrame);
        }
        let matcher = if reference {
            Matcher::Reference
        } else {
            Matcher::Indexed
        };
        self.fold_test = fold_test;
        self.reconstruct(
            frame,
            motion,
            (matcher, thin),
            Rounding::NONE,
            &mut NoDeadline,
        );
        self.fold_test = true;
        Ok(())
    }

    /// [`Processor::process_against_kept`] with step 2's fold test switched
    /// off (with the reference matcher of [`Self::reference_against_kept`]
    /// when `reference`): no point is flagged [`Status::Folded`], every
    /// point goes to the search. For the tests only, behind the private
    /// `_reference` feature: the containment guarantee does not rest on
    /// the fold test (a point whose correspondent exists has its true
    /// crossing in the band, where one piece is that crossing's and two
    /// separate ones make the point ambiguous), and without it the search
    /// meets every fold. The fold test protects the points whose
    /// correspondent is *not* in frame 2 (`docs/TESTS.md`, "What the fold test
    /// buys").
    #[cfg(any(test, feature = "_reference"))]
    #[doc(hidden)]
    pub fn without_fold_test_against_kept(
        &mut self,
        frame: &Frame<N, B>,
        motion: &Motion,
        reference: bool,
    ) -> Result<&Structure<N, B>, ProcessError> {
        self.test_reconstruct(frame, motion, (reference, false, false))?;
        Ok(&self.output)
    }

    /// Steps 1–3 with the checking forms (`on`) of the loops that have a
    /// bounded one, for the tests only, behind the private `_reference`
    /// feature. On a certified pair with half-plane keys step 1's key
    /// order, the fold test's forward pass and frame 2's lean key loop
    /// leave out their finiteness checks (`BOUNDED`: every key there is
    /// `NO_KEY` or finite and at most 1 in magnitude, `half_key`, with the
    /// arguments where they are used); the fuzz target's shadow processor
    /// runs the checking forms, so every call compares the two bit for bit.
    #[cfg(any(test, feature = "_reference"))]
    #[doc(hidden)]
    pub fn set_checking_forms(&mut self, on: bool) {
        self.checking = on;
    }

    /// Steps 1–4 of the module docs for every boundary of the kept frame,
    /// the motion within `rounding` of the true one
    /// ([`Self::process_composed_within`]; [`Rounding::NONE`]: exact); whether
    /// `deadline` expired before they were done goes into the output
    /// ([`Structure::deadline_expired`]).
    fn reconstruct<D: Deadline>(
        &mut self,
        frame: &Frame<N, B>,
        motion: &Motion,
        (matcher, thin): (Matcher, bool),
        rounding: Rounding,
        deadline: &mut D,
    ) {
        #[cfg(any(test, feature = "_reference"))]
        let fold_test = self.fold_test;
        #[cfg(any(test, feature = "_reference"))]
        let checking = self.checking;
        #[cfg(not(any(test, feature = "_reference")))]
        let checking = false;
        let Self {
            config,
            previous,
            index,
            output,
            fold_counting,
            ..
        } = self;
        // A composed motion: the points' rotation box holds the matrix's
        // error ([`composition_box`]; the flags of the configured box stay
        // the configured one's).
        let boxed;
        let point_config: &Config = if rounding.matrix > 0.0 {
            boxed = composition_box(config, frame.camera(), rounding.matrix);
            &boxed
        } else {
            config
        };
        let mut pair = Pair::new(
            point_config,
            config.rotation_error,
            previous.camera(),
            frame.camera(),
            motion,
            rounding,
        );
        // Thinned on every path: the band's searches, backwards, sideways
        // or under motion errors, take `e₂` from the pair as the wedge's do
        // (docs/PERFORMANCE.md, "Frame 2's boundary thinned on every
        // path").
        if thin {
            pair.thin = crate::thin::epsilon(config.e2);
        }
        let pair = pair;
        output.camera1 = *previous.camera();
        // (At most `B`, below 2¹⁶: `Structure::EMPTY`.)
        output.count = u16::try_from(previous.boundaries().len()).unwrap_or(u16::MAX);
        let mut work = Work::new();
        let mut guard = Guard::new(deadline, config.work_per_point);
        let boundaries = previous.boundaries().len();
        for (k, out) in output.slots.iter_mut().enumerate().take(boundaries) {
            let Some(b1) = previous.boundaries().get(k).map(|b| b.points()) else {
                break;
            };
            let b2 = frame.boundaries().get(k).map(|b| b.points());
            let keying = pair.keying(b2);
            out.points.set_len(b1.len());
            let slots = out.points.as_mut_slice();
            if guard.check() {
                // The time is up: the boundary's points flagged, its steps
                // skipped.
                cut_off(slots, b1);
                continue;
            }
            let mut r1_max = 0.0f32;
            // The keys' orientation along frame 2's boundary, a good guess
            // for frame 1's too (the same curve seen from nearby).
            let orient = orientation(
                &keying,
                b2.and_then(|b| b.first()),
                b2.and_then(|b| b.last()),
            );
            // Step 1, with each point's key margin where the fold index
            // wants it, and whether the keys are strictly ordered.
            let mut order = KeyOrder::NEW;
            // (How many points step 1's key order took: the fold test's
            // lead, [`crate::fold::step`].)
            let mut pushed = 0usize;
            let margins = index.margins_mut();
            match (pair.certified_r1, keying.pencil) {
                (Some(r1), Pencil::Half { foe, side, min_t }) => {
                    let ks = keying.key_scale;
                    let key = |p| half_key(p, (foe, side, min_t), ks);
                    let points = (&mut *slots, b1, &mut margins[..]);
                    let order = (&mut order, &mut pushed);
                    if checking {
                        step1_certified::<D, false>(&pair, r1, points, order, key, &mut guard);
                    } else {
                        step1_certified::<D, true>(&pair, r1, points, order, key, &mut guard);
                    }
                    r1_max = if slots.is_empty() { 0.0 } else { r1 };
                }
                (Some(r1), _) => {
                    let key = |p| keying.key(p);
                    let points = (&mut *slots, b1, &mut margins[..]);
                    let order = (&mut order, &mut pushed);
                    step1_certified::<D, false>(&pair, r1, points, order, key, &mut guard);
                    r1_max = if slots.is_empty() { 0.0 } else { r1 };
                }
                (None, _) => {
                    for ((slot, &p1), m) in slots.iter_mut().zip(b1).zip(margins.iter_mut()) {
                        // (The point-by-point path is the dear one: the
                        // caller's deadline is asked at each point.)
                        if guard.check() {
                            slot.flag_at(p1, Status::OverBudget);
                            *m = 0.0;
                            order.push(NO_KEY, 0.0);
                            continue;
                        }
                        let (k, e) = match compensate_point(&pair, &keying, p1, &mut r1_max) {
                            Ok((r, key)) => {
                                *slot = r;
                                key
                            }
                            Err(status) => {
                                *slot = PointResult::flagged(p1, status);
                                (NO_KEY, 0.0)
                            }
                        };
                        *m = e;
                        order.push(k, e);
                    }
                }
            }
            if guard.check() {
                // The time ran out in step 1: no fold test, no search.
                flag_pending(slots);
                continue;
            }
            // (Step 1's half-plane keys on a certified pair: every point
            // still to be matched, each key NO_KEY (margin 0) or at most 1
            // in magnitude with a finite margin > 0, `half_key`.)
            let bounded = !checking
                && pair.certified_r1.is_some()
                && matches!(keying.pencil, Pencil::Half { .. });
            #[cfg(not(any(test, feature = "_reference")))]
            crate::fold::step(
                index,
                slots,
                (&order, pushed, keying.period, orient, bounded),
                config.work_per_point,
                &mut work,
                &mut guard,
            );
            // (The tests' switch, `without_fold_test_against_kept`: without
            // the test, the points' allowances as its shortcuts grant them.)
            #[cfg(any(test, feature = "_reference"))]
            if fold_test {
                crate::fold::step(
                    index,
                    slots,
                    (&order, pushed, keying.period, orient, bounded),
                    config.work_per_point,
                    &mut work,
                    &mut guard,
                );
            } else {
                let n = u32::try_from(slots.len()).unwrap_or(u32::MAX);
                work.grant(config.work_per_point.saturating_mul(n));
            }
            if guard.check() {
                // The time ran out in the fold test: no index, no search
                // (and with the counting rule, no search of its points that
                // fold either, [`crate::fold::cut_short`]).
                crate::fold::cut_short(slots, *fold_counting);
                continue;
            }
            let Some(b2) = b2 else {
                unmatched(slots);
                continue;
            };
            let near_foe = pair.near_foe(r1_max);
            // Under a deadline the clock is asked before every `CHUNK`
            // vertices or segments of each pass of the build.
            let mut ask = || guard.check();
            let mut tick: Tick = if crate::deadline::never::<D>() {
                None
            } else {
                Some(&mut ask)
            };
            // Frame 2's boundary thinned ([`crate::thin`]) over frame 1's,
            // whose points step 1 took (the call makes this frame the
            // previous one at its end); the pair's `e₂` holds the `ε`. (A
            // pass the clock stopped leaves `b2` as it is: the build's
            // first question stops it too.)
            let thinned = if pair.thin > 0.0 {
                previous.thin_into(k, b2, pair.thin, &mut tick)
            } else {
                None
            };
            let b2 = thinned.unwrap_or(b2);
            let thinned = thinned.is_some();
            let built = frame2_keys(index, &keying, b2, (orient, checking, thinned), &mut tick)
                .is_some_and(|builder| {
                    let radius = near_foe + 2.0 * (r1_max + pair.e2());
                    frame2_index(builder, &pair, &keying, b2, radius, &mut tick)
                });
            if !built {
                // The time ran out in the build: the index unfit, unused
                // (as above with the counting rule).
                crate::fold::cut_short(slots, *fold_counting);
                continue;
            }
            match_boundary(
                &pair,
                &keying,
                near_foe,
                (slots, b2),
                index,
                (&mut work, &mut guard),
                matcher,
                (*fold_counting, checking, thinned),
            );
        }
        // (With the counting rule, a boundary the clock cut has its points
        // that fold flagged where the cut fell: in the rule's own part
        // ([`crate::fold::settle`]) or before it, above. A boundary done
        // before the cut keeps its results, the rule's included. Until a
        // review the frame's every folded point was flagged here after the
        // cut, one pass over every slot: 6 200 instructions late at 2 × 512,
        // 42 786 in all past the clock's yes, over the 40 000 README
        // allows.)
        guard.settle(&mut work);
        output.work = work.usage();
        output.cut = guard.has_expired();
    }
}

/// `config` with its work budget at most `⌊(2³² − 1)/(B N)⌋` units a
/// point, so that a frame's grants fit the `u32` credit and
/// [`crate::Structure::work_units`] counts every unit (until a review, a
/// `Processor<512, 9>` at [`Config::MAX_WORK_PER_POINT`] saturated the
/// count, and the units spent it gave fell with a boundary more). Only
/// where `B N ≥ 4 096` is this below [`Config::MAX_WORK_PER_POINT`].
/// (Applied where the processor takes its configuration, not per frame:
/// a cap in the per-frame call measured 2.5 instructions a point on the
/// representative pair, its inlining changed.)
const fn capped<const N: usize, const B: usize>(mut config: Config) -> Config {
    let points = (N as u64).saturating_mul(B as u64);
    if let Some(cap) = (u32::MAX as u64).checked_div(points) {
        // (At most `u32::MAX`: the cast keeps the value.)
        let cap = cap as u32;
        if config.work_per_point > cap {
            config.work_per_point = cap;
        }
    }
    config
}

/// Which matcher pass 2 uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Matcher {
    Indexed,
    #[cfg_attr(not(any(test, feature = "_reference")), allow(dead_code))]
    Reference,
}

/// Step 1 for one frame-1 point: compensate it and make its output slot
/// hold it until step 4 overwrites it: `p₁'` in `pixel2`, `1/q_z` in `z`,
/// `r₁` in `z_near`, the key of its epipolar line in `z_far`, and the
/// status [`Status::NoIntersection`] for a point still to be matched (no
/// extra memory). Returns the slot and the key with its margin, or why the
/// point is flagged, and keeps the largest `r₁` in `r1_max`.
#[inline(always)]
fn compensate_point(
    pair: &Pair,
    keying: &Keying,
    p1: Pixel,
    r1_max: &mut f32,
) -> Result<(PointResult, (f32, f32)), Status> {
    let config = pair.config;
    {
        let c = match pair.frame_r1 {
            Some(_) => pair.geom.compensate_with(p1, pair.geom.frame_stretch()),
            None => pair.geom.compensate(p1),
        };
        let Some(c) = c else {
            return Err(Status::BehindCamera);
        };
        if !pair.geom.in_view(c.pixel) {
            return Err(Status::OutOfView);
        }
        // q_z must be known to better than half its value (κ below, which
        // must stay below 1: `epipolar::HALF_KAPPA_MAX`). (A NaN fails.)
        if !(pair.depth_scale_error * c.inv_depth_scale <= crate::epipolar::HALF_KAPPA_MAX) {
            return Err(Status::BehindCamera);
        }
        let r1 = match pair.frame_r1 {
            Some(r1) => r1,
            None => {
                // The rotation error's shift is bounded at the point of the
                // disc farthest from the principal point along each axis
                // (`shift_bound` grows with both distances).
                let disc = pair.geom.point_disc_radius(&c, config.e1);
                let k2 = pair.geom.camera2_intrinsics();
                let far = [
                    k2.2 + ((c.pixel[0] - k2.2).abs() + disc),
                    k2.3 + ((c.pixel[1] - k2.3).abs() + disc),
                ];
                let r1 = disc
                    + crate::motion_error::shift_bound(far, k2, config.rotation_error)
                    + pair.slack_r1;
                // Far off the camera's axis the rotation error's shift has
                // no bound (`rotation_shift_bound`): such a point is out of
                // the view the stick can be certified in, and must not set
                // the frame's largest error. So is one whose error disc
                // reaches past the view's reach with `e₂`
                // (`PairGeometry::r1_cap`, for the focus's shift). (A NaN
                // fails.)
                if !(r1 <= pair.r1_cap) {
                    return Err(Status::OutOfView);
                }
                r1
            }
        };
        *r1_max = crate::math::fmax(*r1_max, r1);
        let key = keying.key(c.pixel);
        Ok((
            PointResult {
                pixel1: p1,
                pixel2: Pixel::new(c.pixel[0], c.pixel[1]),
                z: c.inv_depth_scale,
                z_near: r1,
                z_far: key.0,
                status: Status::NoIntersection,
            },
            key,
        ))
    }
}

/// Step 1 on a certified pair ([`compensate_all_certified`]); under a
/// deadline in parts of [`CHUNK`] points with the clock asked between them
/// (the key order followed on from part to part): once it says yes, the
/// points not reached are `over_budget`.
#[inline(always)]
fn step1_certified<D: Deadline, const BOUNDED: bool>(
    pair: &Pair,
    r1: f32,
    (slots, b1, margins): (&mut [PointResult], &[Pixel], &mut [f32]),
    (order, pushed): (&mut KeyOrder, &mut usize),
    key: impl Fn([f32; 2]) -> (f32, f32),
    guard: &mut Guard<'_, D>,
) {
    if crate::deadline::never::<D>() {
        *pushed += compensate_all_certified::<BOUNDED>(pair, r1, (slots, b1, margins), order, key);
        return;
    }
    let mut parts = slots
        .chunks_mut(CHUNK)
        .zip(b1.chunks(CHUNK))
        .zip(margins.chunks_mut(CHUNK));
    // (The clock was asked just before the first part.)
    let mut first = true;
    while let Some(((s, b), m)) = parts.next() {
        if !first && guard.check() {
            let rest = core::iter::once((s, b)).chain(parts.by_ref().map(|(p, _)| p));
            for (s, b) in rest {
                cut_off(s, b);
            }
            return;
        }
        *pushed += compensate_all_certified::<BOUNDED>(pair, r1, (s, b, m), order, &key);
        first = false;
    }
}

/// The slots of points `b1` the caller's deadline cut off before step 1
/// reached them, flagged [`Status::OverBudget`]: a pixel and a status a
/// point, the slot's other bytes (an earlier frame's) not what the result
/// says ([`PointResult`]). (Out of line: the loop on its own, after the
/// clock's yes, is a few instructions a point.)
#[cold]
#[inline(never)]
fn cut_off(slots: &mut [PointResult], b1: &[Pixel]) {
    for (slot, &p1) in slots.iter_mut().zip(b1) {
        slot.flag_at(p1, Status::OverBudget);
    }
}

/// Step 1 for every point of `b1` when the pair certifies the whole image
/// ([`Pair::certified_r1`]): [`compensate_point`] without its checks (they
/// pass), `r₁` the frame's, the keys from `key`; each point's key margin in
/// `margins`, the key order in `order` (followed only until it cannot be
/// strict any more, [`KeyOrder::settled`]: the rest of the points leave
/// [`KeyOrder::strict`] as it is), in a pass over the written keys after
/// the compensation's. `BOUNDED`: `key` gives [`NO_KEY`] or a key at most
/// 1 in magnitude ([`half_key`]; [`KeyOrder::push_until_settled`]).
/// Returns how many points the key order took.
#[inline(always)]
fn compensate_all_certified<const BOUNDED: bool>(
    pair: &Pair,
    r1: f32,
    (slots, b1, margins): (&mut [PointResult], &[Pixel], &mut [f32]),
    order: &mut KeyOrder,
    key: impl Fn([f32; 2]) -> (f32, f32),
) -> usize {
    let stretch = pair.geom.frame_stretch().unwrap_or(0.0);
    let one = |((slot, &p1), m): ((&mut PointResult, &Pixel), &mut f32)| {
        let c = pair.geom.compensate_certified(p1, stretch);
        let (k, e) = key(c.pixel);
        *slot = PointResult {
            pixel1: p1,
            pixel2: Pixel::new(c.pixel[0], c.pixel[1]),
            z: c.inv_depth_scale,
            z_near: r1,
            z_far: k,
            status: Status::NoIntersection,
        };
        *m = e;
    };
    let n = slots.len().min(b1.len()).min(margins.len());
    for p in slots.iter_mut().zip(b1).zip(margins.iter_mut()) {
        one(p);
    }
    // The key order from the keys and margins just written (`z_far` holds
    // the key), in a pass of its own: the same pushes in the same order,
    // and the compensation's loop stays lean. (In that loop until settled,
    // as before, the representative window measured 675.9 instructions a
    // point against 673.7, every other window dearer too.)
    // (Both cut to `n`, rather than the pairs taken to `n`: one count
    // for the loop, not the zip's and the take's.)
    let (slots, margins) = (
        slots.get(..n).unwrap_or_default(),
        margins.get(..n).unwrap_or_default(),
    );
    let keys = slots.iter().zip(margins);
    order.push_until_settled::<BOUNDED>(keys.map(|(slot, &e)| (slot.z_far, e)))
}

/// Step 3: index the frame-2 polyline; with `W' < 0` and the FOE near, the
/// segments within `radius` of the FOE are listed. With `radius = m +
/// 2 max(r₁ + e₂)` the list holds every segment the part of a band closer
/// to the FOE than `m` can meet: that part spans at most `r₁ + e₂` beyond
/// the FOE along the line and `2 (r₁ + e₂)` across it ([`crate::depth`]).
/// In two parts, the keys ([`frame2_keys`]) and the index from them
/// ([`frame2_index`]), so that a deadline can be asked in between.
/// `None` when `tick`'s clock stopped the keys (asked between parts of
/// [`CHUNK`] vertices; the builder takes each part where the last one
/// ended). Half-plane keys go through the lean loop's bounded form
/// ([`Builder::push_all_bounded`]) but with `checking`, the tests' switch
/// (`Processor::set_checking_forms`, tests and the fuzz target only).
fn frame2_keys<'a, const N: usize>(
    index: &'a mut Index<N>,
    keying: &Keying,
    b2: &[Pixel],
    (orient, checking, thinned): (f32, bool, bool),
    tick: &mut Tick<'_>,
) -> Option<Builder<'a, N>> {
    let mut builder = index
        .builder((keying.period, orient), Unkeyed::MeetAll)
        .uneven(thinned);
    // (Without a clock one part: the whole polyline.)
    let part = if tick.is_some() {
        CHUNK
    } else {
        b2.len().max(1)
    };
    // (The clock was asked before the thinning's last part, or before
    // this pass where nothing was thinned: at most a part of the thinning
    // and one of the keys between two questions.)
    for (c, b2) in b2.chunks(part).enumerate() {
        if c > 0 && expired(tick) {
            return None;
        }
        match keying.pencil {
            Pencil::Half { foe, side, min_t } => {
                let ks = keying.key_scale;
                let pencil = (foe, side, min_t);
                if checking {
                    builder.push_all(b2.iter().map(move |p| half_key(p.arr(), pencil, ks)));
                } else {
                    builder.push_all_bounded(b2, move |p| half_key_or_none(p.arr(), pencil, ks));
                }
            }
            _ => builder.push_all(b2.iter().map(|p| keying.key(p.arr()))),
        }
    }
    Some(builder)
}

/// The second part of step 3 ([`frame2_keys`]); `false` when `tick`'s
/// clock stopped the build ([`Builder::finish`]).
fn frame2_index<const N: usize>(
    builder: Builder<'_, N>,
    pair: &Pair,
    keying: &Keying,
    b2: &[Pixel],
    radius: f32,
    tick: &mut Tick<'_>,
) -> bool {
    let foe = pair.foe.filter(|_| pair.geom.w() < 0.0 && keying.angular());
    match foe {
        Some(f) => {
            let is_near = |j: usize| match (b2.get(j), b2.get(j + 1)) {
                (Some(a), Some(b)) => segment_distance2(f, a.arr(), b.arr()) <= radius * radius,
                _ => false,
            };
            builder.finish(Some(&is_near), tick)
        }
        // Searched only by the lean wedge walks (the predicate
        // `match_boundary` takes them by), without a clock: a loose
        // index's block tree left until a walk reads it (the same tree,
        // units and results; [`Builder::finish_deferring_tree`]).
        None if tick.is_none()
            && step4::wedge_path(pair)
            && matches!(keying.pencil, Pencil::Half { .. }) =>
        {
            builder.finish_deferring_tree(None)
        }
        None => builder.finish(None, tick),
    }
}

/// The likely orientation of the keys along a polyline from its end
/// points' (+1 rising, −1 falling; pseudo-angles the shorter way round).
fn orientation(keying: &Keying, first: Option<&Pixel>, last: Option<&Pixel>) -> f32 {
    let key = |p: Option<&Pixel>| p.map_or(NO_KEY, |p| keying.key(p.arr()).0);
    let mut d = key(last) - key(first);
    if keying.period > 0.0 {
        if d > 2.0 {
            d -= 4.0;
        } else if d < -2.0 {
            d += 4.0;
        }
    }
    if d < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// The squared distance from `p` to the segment `a → b`.
fn segment_distance2(p: [f32; 2], a: [f32; 2], b: [f32; 2]) -> f32 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let ap = [p[0] - a[0], p[1] - a[1]];
    let l2 = crate::math::dot(ab, ab);
    let t = if l2 > 0.0 {
        crate::math::fmin(crate::math::fmax(crate::math::dot(ap, ab) / l2, 0.0), 1.0)
    } else {
        0.0
    };
    let d = [ap[0] - t * ab[0], ap[1] - t * ab[1]];
    crate::math::dot(d, d)
}

// `Processor<256, 2>` is 26 892 B on the vehicle controller (README,
// "Memory"; every figure in `docs/VEHICLE.md`): a change that grows it fails the build, one that shrinks it
// lowers this figure.
#[cfg(target_pointer_width = "32")]
const _: () = assert!(core::mem::size_of::<Processor<256, 2>>() <= 26_892);

#[cfg(test)]
mod tests {
    /// The translation box `Pair::new` widens for a rotation error holds
    /// the true compensated translation `R_tᵀ T_t` mapped back by `R`, for
    /// every corner of the rotation and translation error boxes (`f64`,
    /// `R_t = R Exp(ω)`), including the case an adversary found short when
    /// the turn of the translation error was left out.
    #[test]
    fn translation_box_holds_the_turned_true_translation() {
        use crate::test_rng::Rng;
        let exp = |w: [f64; 3]| -> [[f64; 3]; 3] {
            let t = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            let k = if t > 0.0 { w.map(|x| x / t) } else { [0.0; 3] };
            let (s, c) = (t.sin(), 1.0 - t.cos());
            let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
            let mut m = [[0.0; 3]; 3];
            for i in 0..3 {
                for j in 0..3 {
                    let kk: f64 = (0..3).map(|l| kx[i][l] * kx[l][j]).sum();
                    m[i][j] = f64::from(u8::from(i == j)) + s * kx[i][j] + c * kk;
                }
            }
            m
        };
        let mv = |m: &[[f64; 3]; 3], v: [f64; 3]| {
            [0, 1, 2].map(|i| (0..3).map(|j| m[i][j] * v[j]).sum::<f64>())
        };
        let mtv = |m: &[[f64; 3]; 3], v: [f64; 3]| {
            [0, 1, 2].map(|i| (0..3).map(|j| m[j][i] * v[j]).sum::<f64>())
        };
        let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).expect("camera");
        let mut rng = Rng(0x7ea5_0001);
        let mut worst = 0.0f64;
        for case in 0..400 {
            let (t, a, eps, delta) = if case == 0 {
                ([1.0f32, 0.0, 0.0], [0.0f32; 3], [0.0f32, 0.1, 0.0], 0.3f32)
            } else {
                let t = [0.0; 3].map(|_: f32| rng.next() * 2.0 - 1.0);
                let a = [0.0; 3].map(|_: f32| (rng.next() - 0.5) * 0.6);
                let eps = [0.0; 3].map(|_: f32| rng.next() * 0.033);
                (t, a, eps, rng.next() * 0.5)
            };
            let Ok(m) = Motion::new(t, a) else { continue };
            let config = Config::DEFAULT
                .with_translation_error(delta)
                .and_then(|c| c.with_rotation_error(eps))
                .expect("config");
            let pair = Pair::new(
                &config,
                config.rotation_error,
                &cam,
                &cam,
                &m,
                Rounding::NONE,
            );
            let r = m.rotation_matrix().map(|row| row.map(f64::from));
            let t = m.translation().map(f64::from);
            for k in 0..64 {
                let s = |b: usize| if k >> b & 1 == 1 { 1.0 } else { -1.0 };
                let w = [0, 1, 2].map(|i| s(i) * f64::from(eps[i]));
                let d = [3, 4, 5].map(|i| s(i) * f64::from(delta));
                let tt = [t[0] + d[0], t[1] + d[1], t[2] + d[2]];
                let e = exp(w);
                // R_t = R Exp(ω); R (R_tᵀ T_t) against T.
                let rt_t = mtv(&e, mtv(&r, tt));
                let back = mv(&r, rt_t);
                let off = (0..3).map(|i| (back[i] - t[i]).abs()).fold(0.0, f64::max);
                assert!(
                    off <= f64::from(pair.translation),
                    "case {case}: {off} > {}",
                    pair.translation
                );
                worst = worst.max(off / f64::from(pair.translation));
            }
        }
        assert!(worst > 0.8, "the corners come near the bound: {worst}");
    }

    use super::step4::wedge_run_aside;
    use super::*;
    extern crate std;
    use std::vec::Vec;

    std::thread_local! {
        /// Points of this thread's tests that `match_wedge_angular` walked
        /// through a wedge, and that it sent to the band path.
        pub(super) static ANGULAR: core::cell::Cell<(usize, usize)> =
            const { core::cell::Cell::new((0, 0)) };
    }

    /// The wedge path for pseudo-angle keys is taken, and its band-path
    /// fallback too, where they should be: a steep line across the FOE's
    /// row (every point walked through a wedge, none to the band path),
    /// and a hairpin round the FOE within 1.6 px of its row, whose keys
    /// span nearly a turn (some points to the band path); and every
    /// result equals the reference's. (The host test
    /// `angular_wedge_equals_reference_near_and_round_the_foe` runs more
    /// shapes without the counts.)
    #[test]
    fn angular_wedge_and_its_band_fallback_are_taken() {
        use crate::{Camera, Motion};
        let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).expect("camera");
        let m = Motion::new([0.0, 0.0, 0.4], [0.0, 0.0, 0.0]).expect("motion");
        let foe = [255.5f32, 239.5f32];
        let s = 6.0f32 / 5.6;
        let scale =
            |q: [f32; 2]| Pixel::new(foe[0] + s * (q[0] - foe[0]), foe[1] + s * (q[1] - foe[1]));
        let line: Vec<[f32; 2]> = (0..360)
            .map(|i| [100.0 + 0.3 * (i as f32 - 180.0), 60.0 + i as f32])
            .collect();
        let mut hairpin: Vec<[f32; 2]> = (0..120)
            .map(|i| [470.0 - 3.9 * i as f32, foe[1] - 1.6 + 0.003 * i as f32])
            .collect();
        hairpin.extend((1..60).map(|i| [6.0 + 0.1 * i as f32, foe[1] - 1.24 + 0.04 * i as f32]));
        hairpin.extend((0..120).map(|i| [12.0 + 3.9 * i as f32, foe[1] + 1.24 + 0.003 * i as f32]));
        let inside = |p: &Pixel| p.u >= 0.0 && p.u <= 511.0 && p.v >= 0.0 && p.v <= 479.0;
        for (name, b, band) in [("line", &line, false), ("hairpin", &hairpin, true)] {
            let b1: Vec<Pixel> = b
                .iter()
                .map(|q| Pixel::new(q[0], q[1]))
                .filter(inside)
                .collect();
            let b2: Vec<Pixel> = b.iter().map(|&q| scale(q)).filter(inside).collect();
            let mut f1 = Frame::<512, 1>::new(cam);
            let mut f2 = Frame::<512, 1>::new(cam);
            f1.push_boundary(&b1).expect("frame 1");
            f2.push_boundary(&b2).expect("frame 2");
            let unlimited = Config::DEFAULT
                .with_work_budget(Config::MAX_WORK_PER_POINT)
                .expect("budget");
            let mut p = std::boxed::Box::new(Processor::<512, 1>::new(unlimited));
            assert!(p.process(&f1, None).is_ok());
            ANGULAR.with(|c| c.set((0, 0)));
            let fast = p.process_against_kept(&f2, &m).expect("fast").clone();
            let (walked, to_band) = ANGULAR.with(|c| c.get());
            let slow = p
                .reference_against_kept(&f2, &m)
                .expect("reference")
                .clone();
            assert_eq!(
                fast.boundaries()[0].points(),
                slow.boundaries()[0].points(),
                "{name}"
            );
            let ok = fast.boundaries()[0]
                .points()
                .iter()
                .filter(|r| r.status == Status::Ok)
                .count();
            assert!(walked > 100, "{name}: {walked} points walked a wedge");
            if band {
                assert!(to_band > 0, "{name}: no point took the band path");
            } else {
                assert_eq!(to_band, 0, "{name}: {to_band} points took the band path");
                assert!(ok > 300, "{name}: {ok} ok");
            }
        }
    }

    /// A wedge wholly beyond the FOE's row (no keyed point in it) walked
    /// through a loose index whose aside list is full, so that segments
    /// with an unkeyed end (meeting every key) stay in the run: the walk
    /// gives the reference's outcome, and clips only the segments that can
    /// meet the empty query, not every finite one (found by review: 158
    /// units before; now 44 without the tree's skips and 37 with them,
    /// where the reference meets 12 segments).
    #[test]
    fn empty_wedge_through_a_full_aside_list() {
        let (foe, side, min_t, ks) = ([100.0f32, 100.0f32], 1.0f32, 4.0f32, 1.0e-3f32);
        // 12 vertices above the FOE's row (unkeyed), then 40 keyed below,
        // folding in u.
        let mut b2: Vec<Pixel> = Vec::new();
        for i in 0..12 {
            b2.push(Pixel::new(400.0 + i as f32 * 0.5, 40.0 + i as f32 * 4.0));
        }
        for i in 0..40 {
            let step = if (i / 5) % 2 == 0 { i % 5 } else { 5 - i % 5 };
            b2.push(Pixel::new(
                100.0 + step as f32 * 30.0,
                110.0 + i as f32 * 5.0,
            ));
        }
        let key = |p: &Pixel| half_key(p.arr(), (foe, side, min_t), ks);
        let mut index = Index::<64>::new();
        let mut builder = index.builder((0.0, 1.0), Unkeyed::MeetAll);
        builder.push_all(b2.iter().map(key));
        builder.finish(None, &mut None);
        let lean = index.lean();
        assert_eq!(
            lean.aside.len(),
            crate::search::MAX_ASIDE,
            "the aside list is full"
        );
        assert!(lean.blocks.any(), "a loose index, with its block tree");
        // A point above the row, near the FOE: its wedge lies beyond the row.
        let wedge = Wedge::new(
            [100.0, 90.0],
            (foe, side),
            (1.5, 0.5, 1.0),
            (NO_KEY, ks, lean.orient),
        );
        let Ok(wedge) = wedge else {
            unreachable!("the point is 10 px from the FOE");
        };
        assert_eq!(
            (wedge.kl, wedge.kh),
            (f32::NEG_INFINITY, f32::NEG_INFINITY),
            "no keyed point"
        );
        let segments = b2.len() - 1;
        // The reference: every segment with its raw interval.
        let mut walker = WedgeWalker::new(wedge, &b2, 2.0);
        let keying_ivs = |j: usize| {
            let ((ka, ea), (kb, eb)) = (key(&b2[j]), key(&b2[j + 1]));
            if (ka + kb).is_finite() {
                (
                    crate::math::fmin(ka - ea, kb - eb),
                    crate::math::fmax(ka + ea, kb + eb),
                )
            } else {
                (f32::NEG_INFINITY, f32::INFINITY)
            }
        };
        let mut met = 0u32;
        for j in 0..segments {
            let iv = keying_ivs(j);
            met += u32::from(iv.0 <= wedge.kh && iv.1 >= wedge.kl);
            if Visitor::segment(&mut walker, j, iv).0 == Flow::Stop {
                break;
            }
        }
        let reference = walker.outcome();
        // The walk's units: a look and a clip for each segment that meets
        // the query, a look at each of the 12 keyed ones before the last of
        // them, and at most the run start's probes and bisection.
        let bound = (1 + CLIP_UNITS) * met + 12 + 12;
        let granted = 1_000_000;
        for skip in [false, true] {
            let mut work = Work::new();
            work.grant(granted);
            let run = (lean.segs, b2.as_slice(), lean.aside);
            let (outcome, _) = if skip {
                wedge_run_aside::<true>(&wedge, run, (0, lean.blocks), (segments, 2.0), &mut work)
            } else {
                wedge_run_aside::<false>(&wedge, run, (0, lean.blocks), (segments, 2.0), &mut work)
            };
            assert_eq!(outcome, reference, "skip {skip}");
            let spent = granted - work.credit();
            assert!(
                spent <= bound,
                "skip {skip}: {spent} units > {bound} for an empty query"
            );
        }
    }

    /// A boundary frame 2 lacks: its points still to be matched get clean
    /// `no_intersection` results (`step4::unmatched`), not step 1's values
    /// (a `no_intersection` slot with `r₁` in `z_near` is what a pass over
    /// a boundary takes for a point still to be matched; a review's find
    /// when the flags after a deadline became a status).
    #[test]
    fn a_boundary_frame_2_lacks_is_left_clean() {
        let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).expect("camera");
        let mut p = std::boxed::Box::new(Processor::<64, 2>::new(Config::DEFAULT));
        let mut f1 = Frame::<64, 2>::new(cam);
        for b in [
            [(100.0, 400.0), (150.0, 300.0)],
            [(400.0, 400.0), (350.0, 300.0)],
        ] {
            let b = b.map(|(u, v)| Pixel::new(u, v));
            assert!(f1.push_boundary(&b).is_ok());
        }
        assert!(p.process(&f1, None).is_ok());
        let mut f2 = Frame::<64, 2>::new(cam);
        assert!(f2
            .push_boundary(&[Pixel::new(40.0, 470.0), Pixel::new(130.0, 300.0)])
            .is_ok());
        let m = Motion::new([0.0, 0.0, 0.4], [0.0, 0.0, 0.0]).expect("motion");
        let s = p.process_against_kept(&f2, &m).expect("kept");
        let points = s.boundaries().get(1).map_or(&[][..], |b| b.points());
        assert_eq!(points.len(), 2);
        for r in points {
            assert_eq!(r.status, Status::NoIntersection);
            assert_eq!(
                (r.pixel2, r.z, r.z_near, r.z_far),
                (Pixel::new(0.0, 0.0), 0.0, 0.0, 0.0),
                "step 1's values left in {r:?}"
            );
        }
    }

    /// A composed motion's scale error `s` (the fusion's pairs,
    /// `Pair::scale_motion`) near 1: the stick's near ends are multiplied
    /// by `1 − s` (the band path: `1 − s − 2.4·10⁻⁷`), so from there on
    /// nothing bounds a depth from below and no point may be `Ok`. An
    /// adversarial review (twenty-ninth session) found
    /// `composition_error`'s test letting `s` reach about `1 + 2·10⁻⁵`
    /// (then `1.0001` times that); a near end behind the camera (`s_near <
    /// 0`) then turned positive, as the same review found for `κ`
    /// (`epipolar::HALF_KAPPA_MAX`). Pure translation backwards (`W' =
    /// −0.5`: the band path), so the composition's translation error `m_t`
    /// sets `s = d_t/((|W'| − d_t)(1 − 10⁻⁵))(1 + 10⁻⁵)` with
    /// `d_t = m_t(1 + 10⁻⁵)`: every `f32` `m_t` from 0.24996 to 0.25 (about 2 700), `s`
    /// from about 0.9997 through the band path's last positive factor to
    /// past `|W'|/2`, where `composition_error` gives up. The frames are
    /// those of the adversarial test (`host_tests/tests/
    /// adversarial_containment.rs`, `no_ok_stick_where_q_z_is_known_to_half_its_value`)
    /// ten times as far from the focus, whose 40 points' sticks reach
    /// behind the camera without a composition (every one `Unbounded`);
    /// before the fix 18 of them came out `Ok` from `m_t = 0.24999` on, and
    /// with the threshold at `s < 1` at `m_t` just below 0.25 (a second
    /// review: `s` from `1 − 2.4·10⁻⁷` to 1).
    #[test]
    fn no_ok_stick_where_the_composition_scale_reaches_one() {
        use crate::camera::{Camera, Pixel};
        use crate::deadline::NoDeadline;
        use crate::epipolar::{PairGeometry, SCALE_ERROR_MAX};
        let cam = Camera::new(1.0, 1.0, 8191.5, 8191.5, 16384, 16384).expect("camera");
        let c = 8191.5f32;
        let mut f1 = Frame::<64, 1>::new(cam);
        let p1: [Pixel; 40] = core::array::from_fn(|i| {
            Pixel::new(c + 300.0 + 0.001 * i as f32, c + 150.0 - 7.5 * i as f32)
        });
        f1.push_boundary(&p1).expect("frame 1");
        let mut f2 = Frame::<64, 1>::new(cam);
        let p2: [Pixel; 60] = core::array::from_fn(|i| {
            Pixel::new(c + 0.1 + 0.0001 * i as f32, c + 500.0 - 16.5 * i as f32)
        });
        f2.push_boundary(&p2).expect("frame 2");
        let motion = Motion::new([0.0, 0.0, -0.5], [0.0; 3]).expect("motion");
        let config = Config::new(0.0, 0.0, 10.0, 1000.0).expect("config");
        let geom = PairGeometry::new(&cam, &cam, &motion);
        // (Runs whose points reached the stick, and runs whose `s` lies in
        // the band path's window `[1 − 2.4·10⁻⁷, 1)` or at or past 1.)
        let (mut matched, mut window, mut past) = (0u32, 0u32, 0u32);
        let mut mt = 0.249_96f32;
        while mt <= 0.25 {
            let s = geom.composition_error(mt, 0.0).1 * 1.0001;
            window += u32::from((1.0 - 2.4e-7..1.0).contains(&s));
            past += u32::from(s >= 1.0 && s.is_finite());
            let mut p = Processor::<64, 1>::new(config);
            p.process(&f1, None).expect("frame 1");
            let rounding = Rounding {
                translation: mt,
                matrix: 0.0,
                in_config: false,
            };
            let out = p
                .process_composed_within(&f2, &motion, rounding, true, &mut NoDeadline)
                .expect("pair");
            for r in out.boundaries()[0].points() {
                assert_ne!(r.status(), Status::Ok, "m_t {mt:e} (s {s:e}): {r:?}");
            }
            let unbounded = out.boundaries()[0].points().iter();
            matched += u32::from(
                unbounded
                    .filter(|r| r.status() == Status::Unbounded)
                    .count()
                    > 0,
            );
            mt = f32::from_bits(mt.to_bits() + 1);
        }
        // (The sweep met both: the points reached the stick, and `s`
        // crossed the band path's window and 1, below `SCALE_ERROR_MAX`
        // too.)
        assert!(
            matched > 1000 && window > 0 && past > 100 && SCALE_ERROR_MAX < 1.0 - 2.4e-7,
            "{matched} {window} {past}"
        );
    }

    /// A point whose error disc, with `e₂`, reaches past the view's reach
    /// `L` from the principal point (`PairGeometry::r1_cap`) is refused,
    /// `OutOfView`: the focus's rounding is added as a shift bounded for
    /// true points within `2L` of `c₂` (`PairGeometry::foe_shift`), and
    /// the true points of such a disc need not be. A review (thirtieth
    /// session) found that bound argued for points in view while the
    /// true ones lie up to `r₁` and `e₂` beyond it. Frame 2 is a 16 × 16
    /// image (`L` = 33.2 px), the focus far down the diagonal (`D` ≈
    /// 1 400 px), frame 1's camera centred 23 px further out so that its
    /// points compensate to near the view's corner. Below the cap (`e₂` =
    /// 30 px, and `L − 0.6` with `r₁` about 0.5) the points are searched
    /// (their band, wider than the image, holds the boundary's ends:
    /// `BoundaryEnd`); past it (`L − 0.45`, 34 px) every one is
    /// `OutOfView`, where before the cap they were searched too. (A
    /// reviewer asked for both sides of the cap: a cap 1 px off fails.)
    #[test]
    fn points_whose_disc_with_e2_passes_the_views_reach_are_refused() {
        use crate::camera::{Camera, Pixel};
        let cam1 = Camera::new(16.0, 16.0, 30.5, 30.5, 64, 64).expect("camera 1");
        let cam2 = Camera::new(16.0, 16.0, 7.5, 7.5, 16, 16).expect("camera 2");
        let mut f1 = Frame::<16, 1>::new(cam1);
        let p1: [Pixel; 5] = core::array::from_fn(|i| {
            let t = i as f32 * 0.5 - 1.0;
            Pixel::new(8.0 + t, 8.0 - t)
        });
        f1.push_boundary(&p1).expect("frame 1");
        let mut f2 = Frame::<16, 1>::new(cam2);
        let p2: [Pixel; 5] = core::array::from_fn(|i| {
            let t = i as f32 * 0.5 - 1.0;
            Pixel::new(14.0 + t, 14.0 - t)
        });
        f2.push_boundary(&p2).expect("frame 2");
        // The focus `c₂ + 16 (U/W, V/W)` at about (−1 000, −1 000).
        let motion = Motion::new([-0.063, -0.063, 0.001], [0.0; 3]).expect("motion");
        let geom = crate::epipolar::PairGeometry::new(&cam1, &cam2, &motion);
        let l = geom.view_reach();
        assert!((33.0..33.5).contains(&l), "{l}");
        // Either side of the cap itself: `r₁` is about `e₁` = 0.5 px here
        // (a pure translation between two cameras of one focal length),
        // so `e₂ = L − 0.6` leaves it under the cap and `L − 0.45` over.
        let mut refused = [0usize; 4];
        for (n, e2) in refused.iter_mut().zip([30.0f32, l - 0.6, l - 0.45, 34.0]) {
            let config = Config::new(0.5, e2, 10.0, 1.0e6).expect("config");
            let mut p = Processor::<16, 1>::new(config);
            p.process(&f1, None).expect("frame 1");
            let Ok(Step::Structure(out)) = p.process(&f2, Some(&motion)) else {
                unreachable!("frame 2 makes a pair");
            };
            let points = out.boundaries()[0].points();
            assert_eq!(points.len(), 5);
            *n = points
                .iter()
                .filter(|r| r.status() == Status::OutOfView)
                .count();
        }
        assert_eq!(refused, [0, 0, 5, 5]);
    }
}
