//! Fusing the error ranges of many frames (paper, Sec. 5: "the final goal
//! ... is to obtain a more accurate 3-D road structure by fusing the error
//! ranges of depth information from many more frames and/or from range
//! sensors").
//!
//! [`Fusion`] drives a [`Processor`] over a stream of frames with a **key
//! frame**: every later frame is paired with the key frame
//! ([`Processor::process_against_kept`]), so each pair gives the key
//! frame's points guaranteed sticks on their own rays, and the fused
//! interval of a point is the intersection of its sticks ([`KeyFrame`]
//! explains the fusion and the consistency check that catches wrong
//! matches). When the key frame retires, its fused points move into the
//! [`RoadMap`], which carries them forward in the current vehicle frame.
//!
//! # At a glance
//! * **Per frame:** [`Fusion::step`] (or [`Fusion::step_within`] with
//!   your clock) with the frame's id, the frame, and the motion from the
//!   frame before it ([`ChainedMotion`]; `None` only for the first frame
//!   or after [`Fusion::reset`]). From the link: [`crate::wire::FrameJob::run_fused`].
//! * **On an error** ([`FusionError`]: a missing motion, a motion that
//!   does not chain from the last frame, a repeated id) nothing changes;
//!   the caller may [`Fusion::reset`] and go on. A motion or error bound
//!   the processor does not accept is no error: the frame starts a new
//!   key frame ([`KeyReason`]).
//! * **What holds:** every fused interval of a point that is not
//!   [`FusedStatus::Inconsistent`] contains the true depth when every pair
//!   was within the error model (README, "What holds and what does not,
//!   today"); an inconsistent
//!   point keeps the interval most of its pairs agree on, flagged. Each
//!   road-map point's truth lies within its radius of its near–far segment
//!   ([`crate::map`], "The radius: how far the true point may be from the
//!   stick").
//! * **Reading:** the key frame's points by [`Fusion::key`] (intervals,
//!   counts) and [`Fusion::key_point`] (with the pixel and the ray;
//!   `None` between a retirement and the next step), the map by
//!   [`RoadMap::points`] in the current vehicle frame; what a step did by
//!   [`FusionStep`].
//! * **A range sensor:** [`Fusion::constrain`] with [`Fusion::key_ref`].
//! * **Cost:** the matching of one pair a frame (the processor's), plus
//!   the fusion's own work, linear in the key frame's points (measured:
//!   README, "Within a deadline"). The sections below say how and why.
//!
//! # The motion from the key frame
//! Each frame comes with the motion from the frame before it, named by
//! frame ids ([`ChainedMotion`]); the motion from the key frame is their
//! composition ([`Motion::then`]). When the processor's configuration
//! bounds the per-frame motion errors, the composed motion's bounds are
//! composed too (`src/fusion/chain.rs` derives them) and the processor
//! pairs with them, so the fused interval stays guaranteed: the translation
//! bound grows with the travel since the key frame, the rotation bound with
//! the number of frames. The composed motion's `f32` rounding is carried
//! too, bounds or not: the chain bounds it (`src/fusion/chain.rs`,
//! "Rounding") and the processor adds it to the pair's errors
//! (`crate::processor`, "The composition's rounding"; until a review it
//! was left out, and a translation composed out and back left fused
//! intervals 0.7–2.4 % off the truth); the road map's radius carries its
//! own (`crate::map`, "The radius").
//!
//! # Longer baselines, informative pairs
//! Pairing with the key frame rather than with the previous frame makes the
//! baseline grow frame by frame: the disparity grows about in proportion
//! (the motion factor `F ≈ n` of eq. 3.4) and a stick's relative length
//! shrinks as `1/d` (Sec. 4.1.1), so the later pairs are the informative
//! ones and the intersection is set by them. The key frame is kept as long
//! as its points are still matched (the policy below) to let the baseline
//! grow; a pair that flags a point (grazing, at the FOE, out of view) gives
//! it nothing, and one that matches it is checked against its fused
//! interval even when it does not narrow it.
//!
//! # Key-frame policy
//! The first frame with boundary points becomes the key frame. After each
//! pair the next frame is made the key frame's **last partner** (paired
//! with it by [`Processor::process`], which then keeps that frame as the
//! new key frame) when
//!
//! * the key frame has had `max_partners − 1` partners
//!   ([`FusionConfig::new`], default 8 partners in all), or
//! * the pair matched fewer than `keep_permille` ‰ of the most points any
//!   pair of this key frame matched (default 500: half), or nothing at all
//!   after two partners.
//!
//! A new key frame also starts, without a last pair, when the composed
//! motion is not one the processor accepts (a turn beyond
//! [`crate::motion::MAX_ROTATION_RAD`], a translation beyond `1e6`, no
//! baseline) or its composed error bound is not (rotation errors summing
//! beyond 0.1 rad, see [`crate::Config::with_rotation_error`]). A frame
//! without boundary points never becomes a key frame: the switch waits for
//! the next frame that has some (the frame is still paired and the map
//! still carried). Every frame is matched exactly once, so the fusion adds
//! no matching work.
//!
//! # The retirement over two steps
//! A retiring key frame's admitted points are copied into the map (their
//! rays, their coded ends, the batch's bounds): the costliest part of the
//! fusion (about 65 instructions a point, 100 when this split was made),
//! and all of it in one frame. So
//! the retiring step looks at no more of them than 35.5 % of the key
//! frame's points, rounded up (entered, or left out as
//! [`crate::map::Retired::unbounded`]; boundary by boundary, in order; the
//! share is [`FusionConfig::with_retirement_share`]'s, 355 ‰ by default)
//! and makes room for all; the rest enter at the start of the **next**
//! step, before its pair: the retired key frame's cells and the
//! reconstruction of its pixels stay untouched until then (the next key
//! frame's fusion starts with that step, and the processor pairs after
//! it).
//!
//! Why a share of the key frame's points: the retiring step also fuses its
//! own pair (about 37 instructions a key-frame point) and makes the room,
//! so with 35.5 % of its points entered it stays near 80 a point whatever
//! share of them is admitted, and a key frame with fewer admitted points
//! (the demo drive's, about a third) retires in one step as before. The
//! next step pairs a fresh key frame, whose first pair has no interval to
//! intersect (about 13 a point), and enters the rest, at most 64.5 % of the
//! retired key frame's points: where the two key frames are about as large
//! the two steps come out even (the default evens them where a full key
//! frame retires into a full map: `docs/FUSION.md`). Where the next key
//! frame is much smaller, that step's work is the same, so its work a
//! point of its own key frame is larger (a review's key frame of 4 points
//! after one of 504: 34 670 instructions; the bench's `shrinking` drive,
//! key frames of 256 and 90 points a boundary by turns, 136 instructions
//! a key-frame point in the 90-point key frame's first step, issue 13; a
//! share from both key frames' sizes would move the entries into the
//! retiring step, whose matching is the larger key frame's: the dearer
//! frame for the deadline, `docs/FUSION.md`). (A share of the admitted points
//! split the demo drive's retirements too, and moved work into the step
//! after one, the demo's dearest matching, past the deadline; a share of
//! the capacity `B·N` left small key frames whole, a review's 90 points a
//! boundary at 159 a point.)
//!
//! A pass that conflicts: where the retiring step's pair gave `k` of its
//! points an interval missing their fused one (a road that moves, a wrong
//! detector or odometry), each cost the pass about 40 instructions more
//! than an agreeing point (the conflict's path), so the step looks at
//! `⌈k/2⌉` fewer points than its share (not below 0; a share of 1000 ‰
//! stays whole): an entry costs about 100. The next step enters no more
//! for it: each of the `k` points is inconsistent now, so not admitted,
//! and of the `n` points' admitted ones at most `n − k − (share − ⌈k/2⌉)
//! ≤ n − share` are left, what it enters without the cut (at most `n − k
//! ≤ n − share` where the cut leaves the retiring step none to look at:
//! then `⌈k/2⌉ ≥ share`, so `k ≥ share`).
//! (The bench's jumping road, 455 conflicts in a retiring step: 88.7
//! instructions a key-frame point without the cut, 74.9 with it;
//! `host_tests/tests/fusion/`,
//! `a_retiring_step_whose_pass_conflicts_enters_less_and_the_rest_next`.)
//!
//! Between the two steps the map holds the points entered so far (each
//! point whole: bounded, carried and swept as any other), [`Fusion::key`]
//! all of them; [`crate::map::Retired::pending`] counts the rest, and the
//! next step's [`FusionStep::finished`] what became of them (a
//! [`Fusion::constrain`] in between enters them first). The map's sweep
//! rests in the step after a retirement as in the retiring one, whether
//! the retirement was cut or not. A retirement at a motion or error limit
//! (a step without a pair) is cut at the same share: the processor keeps
//! the new frame at once, but its reconstruction of the retired key
//! frame's pixels stays until it pairs again (keeping a frame touches
//! only the kept frame and the flag of an expired deadline), so the rest
//! enters at the start of the next step as after a last pair. Such a
//! step has no pair to fuse, so it is the lighter of the two (retired
//! whole, a review measured 108 instructions a key-frame point). A share
//! of 1000 ‰ retires every key frame whole.
//! The map after the next step is the one a whole retirement leaves (the
//! same points, bounds and counts: `host_tests/tests/fusion/`,
//! `a_retirement_over_two_steps_leaves_the_whole_ones_map` and
//! `a_retirement_at_a_motion_limit_over_two_steps_leaves_the_whole_ones_map`).
//!
//! # The sweep after the pass
//! The map's sweep for points behind the vehicle (`crate::map`, "What leaves
//! the map") runs after the pair is fused, not with the carry before the
//! matching, so that a step can tell what its pass cost: it rests where the
//! pass had more conflicts than agreeing intervals (twice the conflicts above
//! the matched points), as it does where a key frame retires and in the next
//! step. Each conflict costs the pass about 40 instructions more than an
//! agreeing point, so a pass where most conflict has spent what the sweep's
//! tests would (up to [`crate::map::SWEEP_PER_FRAME`] a boundary, about 40
//! each); where at most half conflict, the pass is at most about 20 a point
//! dearer and the sweep fits. Resting loses nothing: a point behind the camera
//! is left out of every query whether swept or not, and one no sweep reaches
//! goes for room when its batch is the oldest (and a point whose interval
//! conflicted is never admitted, so a key frame whose passes mostly conflict
//! brings few points to make room for). The bench's `wobbling_forward` drive
//! (every matched point conflicting in steps whose map has batches the camera
//! is passing; a review's, simplified): 82 instructions a key-frame point with
//! the sweep after every pass, 76 with the rest. Since the sweep runs after the
//! matching, a caller's clock no longer sees its work before the matching's
//! last question (at most [`crate::map::SWEEP_PER_FRAME`] tests a boundary,
//! about 2 600 instructions for two): part of the fusion's own work after the
//! matching, which the deadline's margin must leave room for
//! ([`Fusion::step_within`]).
//!
//! # Range sensors
//! [`Fusion::constrain`] intersects a key-frame point's interval with a
//! range interval along its ray from another sensor (a lidar or radar
//! return), checked for consistency like a pair.
//!
//! # Memory and work
//! Beside the processor, `Fusion<N, B, M>` holds a [`KeyFrame`] (`20·B·N`
//! bytes), a [`RoadMap`] (`12·B·M` bytes and [`crate::map::MAP_BATCHES`]
//! batches) and a few words: 23 640 bytes for `N = 256`, `B = 2`,
//! `M = 512` on the Cortex-M4F, asserted at compile time there (at most
//! 24 KiB). Per frame the fusion costs one pass over the key frame's points
//! (`O(1)` each: an intersection, or the consistency check), `O(MAP_BATCHES)`
//! to carry the map and at most [`crate::map::SWEEP_PER_FRAME`] point tests
//! per boundary for points the vehicle has passed; a retiring key frame
//! one more pass to copy its points into the map (up to 35.5 % of its
//! points in that step, the rest at the start of the next, above). The
//! depths of the map are 16-bit codes relative
//! to a power of two at or above the configuration's maximum depth
//! (resolution `2⁻¹²` of the depth for depths within `2¹⁵` of it, rounded
//! outwards). `docs/FUSION.md` ("What the fusion tests show") gives the
//! instructions measured.

mod chain;
pub(crate) mod code;
mod key;
mod sight;

use core::fmt;

pub(crate) use chain::{norm1, Chain, StepBounds, STEP_ROUNDING};
pub(crate) use key::Cell;
pub use key::{FusedCounts, FusedPoint, FusedStatus, KeyFrame, KeyPoint, PairFused};

use crate::boundary::Frame;
use crate::config::Config;
use crate::deadline::{Deadline, NoDeadline};
use crate::map::{Retired, RoadMap};
use crate::math::{fmax, sin_cos, sqrt};
use crate::motion::Motion;
use crate::processor::{Processor, Rounding};
use crate::structure::Structure;
use code::DepthScale;
use key::Added;

/// Most partners a key frame may be given ([`FusionConfig::new`]).
pub const MAX_PARTNERS: u16 = 64;

/// The fusion's policy: the key-frame rule, the map's admission rule and
/// the camera's mounting tilt (for the map's vehicle frame).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FusionConfig {
    max_partners: u16,
    keep_permille: u16,
    map_min_pairs: u8,
    sight_check: bool,
    retire_permille: u16,
    tilt: f32,
    tilt_sc: (f32, f32),
}

/// Why a [`FusionConfig`] was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum FusionConfigError {
    /// `max_partners` is not in `1..=MAX_PARTNERS`.
    Partners,
    /// `keep_permille` is above 1000.
    KeepShare,
    /// The map's minimum of agreeing pairs is not in `1..=64`.
    MinPairs,
    /// The tilt is NaN or beyond ±90°.
    Tilt,
    /// The retirement's share is above 1000 permille.
    RetireShare,
}

impl core::error::Error for FusionConfigError {}

impl fmt::Display for FusionConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Partners => "partners per key frame must be in 1..=64",
            Self::KeepShare => "the share of matched points must be at most 1000 permille",
            Self::MinPairs => "the map's minimum of agreeing pairs must be in 1..=64",
            Self::Tilt => "the tilt must be finite and within 90 degrees",
            Self::RetireShare => "the retirement's share must be at most 1000 permille",
        })
    }
}

impl Default for FusionConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl FusionConfig {
    /// 8 partners per key frame, a new key frame when a pair matches less
    /// than half of the best pair's points, points with 2 or more agreeing
    /// pairs into the map, no tilt (the vehicle frame is the camera frame).
    pub const DEFAULT: FusionConfig = match FusionConfig::new(8, 500) {
        Ok(c) => c,
        Err(_) => panic!("the default fusion configuration is valid"),
    };

    /// A key frame's last partner (the frame that becomes the next key
    /// frame) is its `max_partners`-th (1 to [`MAX_PARTNERS`]), or the
    /// frame after a pair that matched fewer than `keep_permille` ‰ of the
    /// most points a pair of it matched (0 switches the share rule off),
    /// whichever comes first. The map then admits points with 2 agreeing
    /// pairs or more ([`FusionConfig::with_map_min_pairs`]: with
    /// `max_partners` 1, set it to 1 or add range constraints, or the map
    /// stays empty). A frame without points cannot become a key
    /// frame: while the last partner is due, such frames are paired too
    /// and the switch waits for the next frame with points (module docs,
    /// "Key-frame policy"), so a key frame has more than `max_partners`
    /// partners exactly when frames without points came while it was due.
    ///
    /// ```
    /// use roadstereo::fusion::FusionConfig;
    /// let c = FusionConfig::new(6, 400)?.with_tilt(23f32.to_radians())?;
    /// assert_eq!(c.max_partners(), 6);
    /// assert!(FusionConfig::new(0, 400).is_err());
    /// # Ok::<(), roadstereo::fusion::FusionConfigError>(())
    /// ```
    pub const fn new(max_partners: u16, keep_permille: u16) -> Result<Self, FusionConfigError> {
        if max_partners == 0 || max_partners > MAX_PARTNERS {
            return Err(FusionConfigError::Partners);
        }
        if keep_permille > 1000 {
            return Err(FusionConfigError::KeepShare);
        }
        Ok(Self {
            max_partners,
            keep_permille,
            map_min_pairs: 2,
            sight_check: false,
            retire_permille: 355,
            tilt: 0.0,
            tilt_sc: (0.0, 1.0),
        })
    }

    /// The same policy with the camera pitched down by `tilt` radians
    /// (`|tilt| ≤ π/2`): the map's vehicle frame is the camera frame turned
    /// by it ([`crate::analysis::camera_to_vehicle`]).
    pub const fn with_tilt(mut self, tilt: f32) -> Result<Self, FusionConfigError> {
        // (A NaN fails.)
        if !(tilt.abs() <= core::f32::consts::FRAC_PI_2) {
            return Err(FusionConfigError::Tilt);
        }
        self.tilt = tilt;
        self.tilt_sc = sin_cos(tilt);
        Ok(self)
    }

    /// The same policy with points entering the map only with at least
    /// `pairs` agreeing pairs, 1 to 64 (1 admits [`FusedStatus::Single`]
    /// points, which nothing has checked; 2 is [`FusionConfig::new`]'s).
    /// Partners and range constraints ([`Fusion::constrain`]) count, and a
    /// key frame has at most `max_partners` partners with points: with
    /// `pairs` above `max_partners` (`new(1, …)` keeps 2) only constraints
    /// can bring a point in, and without them the map stays empty (every
    /// retirement counts its points in [`crate::map::Retired::unverified`]).
    /// Not an error, as constraints may be part of the plan; check
    /// `map_min_pairs() <= max_partners()` if they are not.
    pub const fn with_map_min_pairs(mut self, pairs: u8) -> Result<Self, FusionConfigError> {
        if pairs == 0 || pairs > 64 {
            return Err(FusionConfigError::MinPairs);
        }
        self.map_min_pairs = pairs;
        Ok(self)
    }

    /// The same policy with the **sight check** on or off (off by
    /// default): where a point's pairs' sticks reach depths some
    /// contributing partner was not shown to see along its ray (it left
    /// that partner's image, or its boundary's rows), that partner's match
    /// may be of another stretch that happens to lie inside a wider right
    /// stick, and the point's interval is **widened** over those depths
    /// ([`FusedStatus::Widened`]: it then holds the truth whenever one of
    /// its pairs is right; `src/fusion/sight.rs`, "The rule";
    /// `docs/FUSION.md`, "The sight check"); a point where such a partner
    /// was shown to see none of the ray is flagged
    /// [`FusedStatus::PartlyUnseen`] and kept out of the map. It costs
    /// narrowing and the fusion's work (measured in `docs/FUSION.md`: not
    /// within the 80 instructions a key-frame point budgeted for the
    /// default). A range constraint ([`Fusion::constrain`]) counts as a
    /// pair whose partner sees everything: its near end lowers `H` like a
    /// stick's, so a constraint reaching below what a partner was shown to
    /// see (a return "nothing within 80 m", `near = 0`, say) widens the
    /// point down to it.
    pub const fn with_sight_check(mut self, on: bool) -> Self {
        self.sight_check = on;
        self
    }

    /// The same policy with no more admitted points than `permille` ‰ of a
    /// retiring key frame's points (rounded up), 0 to 1000, looked at in
    /// the step that retires it (entered into the map, or left out as
    /// unbounded), 355 by default (1000: all of them in that step); the
    /// rest enter at the start of the next step, before its pair: the
    /// retiring step's work bounded by the share, the map whole one step
    /// later ([`crate::map::Retired::pending`], [`FusionStep::finished`];
    /// module docs, "The retirement over two steps").
    pub const fn with_retirement_share(mut self, permille: u16) -> Result<Self, FusionConfigError> {
        if permille > 1000 {
            return Err(FusionConfigError::RetireShare);
        }
        self.retire_permille = permille;
        Ok(self)
    }

    /// The share of a retiring key frame's points, permille, up to which
    /// its admitted points enter the map in its retiring step.
    pub const fn retirement_share(&self) -> u16 {
        self.retire_permille
    }

    /// Whether the sight check is on.
    pub const fn sight_check(&self) -> bool {
        self.sight_check
    }

    /// Most partners per key frame.
    pub const fn max_partners(&self) -> u16 {
        self.max_partners
    }
    /// The share rule, permille.
    pub const fn keep_permille(&self) -> u16 {
        self.keep_permille
    }
    /// Fewest agreeing pairs of a map point.
    pub const fn map_min_pairs(&self) -> u8 {
        self.map_min_pairs
    }
    /// The mounting tilt, radians.
    pub const fn tilt(&self) -> f32 {
        self.tilt
    }
}

/// A frame's motion from the frame before it, named by that frame's id.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ChainedMotion {
    /// The id of the frame the motion starts from.
    pub from: u32,
    /// The motion (conventions of [`crate::motion`]).
    pub motion: Motion,
}

/// Why a frame or a constraint was rejected. Nothing changes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum FusionError {
    /// A previous frame exists but no motion was given.
    MissingMotion,
    /// The motion starts from another frame than the last one accepted.
    BrokenChain {
        /// The last accepted frame's id.
        expected: u32,
        /// The id the motion starts from.
        given: u32,
    },
    /// The frame has the id of the last accepted frame.
    RepeatedFrame(u32),
    /// There is no key frame (to constrain).
    NoKeyFrame,
    /// A constraint named another key frame than the one it would go to
    /// ([`Fusion::key_id`]): it was meant for a key frame that has
    /// retired, or not yet started.
    KeyMismatch {
        /// The key frame constraints go to now.
        expected: KeyRef,
        /// The key frame the constraint named.
        given: KeyRef,
    },
    /// The key frame has no such boundary point.
    NoSuchPoint,
    /// A range is not `0 ≤ near ≤ far` with both finite (or its far end
    /// converted to a depth overflows).
    InvalidRange,
    /// A frame from the link declared a localisation error or motion-error
    /// bounds larger than the fusion's configuration
    /// ([`crate::wire::FrameJob::run_fused`]): its sticks would not be
    /// guaranteed.
    ErrorsAboveConfig,
}

impl core::error::Error for FusionError {}

impl fmt::Display for FusionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::MissingMotion => f.write_str("a motion from the previous frame is required"),
            Self::BrokenChain { expected, given } => write!(
                f,
                "the motion starts from frame {given}, the last frame was {expected}"
            ),
            Self::RepeatedFrame(id) => write!(f, "frame {id} was the last frame already"),
            Self::NoKeyFrame => f.write_str("there is no key frame"),
            Self::KeyMismatch { expected, given } => write!(
                f,
                "the constraint is for key frame {} (key frame {} of the fusion), the key frame is {} ({})",
                given.id, given.serial, expected.id, expected.serial
            ),
            Self::NoSuchPoint => f.write_str("the key frame has no such point"),
            Self::InvalidRange => {
                f.write_str("a range must be finite with 0 <= near <= far, its far depth too")
            }
            Self::ErrorsAboveConfig => {
                f.write_str("the frame's declared errors exceed the fusion's configuration")
            }
        }
    }
}

/// Why a key frame started.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum KeyReason {
    /// There was no key frame (the first frame with points).
    First,
    /// The old one had its `max_partners`.
    Partners,
    /// The old one's points were no longer matched.
    FewMatched,
    /// The composed motion is not one the processor accepts.
    MotionLimit,
    /// The composed motion's error bound is not one the processor accepts.
    ErrorLimit,
}

impl KeyReason {
    /// Short lower-case name.
    pub const fn name(self) -> &'static str {
        match self {
            Self::First => "first",
            Self::Partners => "partners",
            Self::FewMatched => "few_matched",
            Self::MotionLimit => "motion_limit",
            Self::ErrorLimit => "error_limit",
        }
    }
}

impl fmt::Display for KeyReason {
    /// [`KeyReason::name`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What one frame did.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FusionStep {
    /// What the pair with the key frame fused (none when the frame was not
    /// paired: the first frame, or after a motion limit).
    pub paired: Option<PairFused>,
    /// The frame's place among the key frame's partners (1 = first).
    pub partner: u16,
    /// The key frame that retired into the map, if one did. A key frame
    /// with more admitted points than a step's share enters the rest at
    /// the start of the next step ([`Retired::pending`], module docs).
    pub retired: Option<Retired>,
    /// The rest of the last step's retirement, entered at the start of
    /// this step (before its pair), if it had one: its `entered`,
    /// `unbounded` and `unfit` counts, which add up to the last step's
    /// [`Retired::pending`] (a [`Fusion::constrain`] in between enters it
    /// then, and this step reports it; a [`Fusion::reset`] in between
    /// forgets it with the map, and no step reports it).
    pub finished: Option<Retired>,
    /// Why this frame became the key frame, if it did.
    pub new_key: Option<KeyReason>,
}

/// The key-frame fusion and its road map, around the per-frame processor
/// (module docs). `N`, `B` as for [`Processor`], and `N ≤ 65 535` (a key
/// frame's counts are 16-bit; checked at compile time); `M` points per
/// boundary in the map, `0 < M < 65535` (checked at compile time:
/// [`RoadMap`]).
///
/// The largest `N` compiles, the next does not (these two examples show
/// the check only: a value this large, 5.5 MB, is built on the stack
/// before `Box::new` moves it, which overflows a test thread's stack in
/// a debug build. Put a fusion in a `static`, as README's "In a
/// firmware: a static processor" does, or reuse one with
/// [`Fusion::reset_with`]):
///
/// ```no_run
/// # use roadstereo::{fusion::{Fusion, FusionConfig}, Config};
/// let f = Box::new(Fusion::<65_535, 1, 4>::new(Config::DEFAULT, FusionConfig::DEFAULT));
/// ```
///
/// ```compile_fail
/// # use roadstereo::{fusion::{Fusion, FusionConfig}, Config};
/// let f = Box::new(Fusion::<65_536, 1, 4>::new(Config::DEFAULT, FusionConfig::DEFAULT));
/// ```
#[derive(Debug, Clone)]
pub struct Fusion<const N: usize, const B: usize, const M: usize> {
    processor: Processor<N, B>,
    base: Config,
    config: FusionConfig,
    key: KeyFrame<N, B>,
    has_key: bool,
    /// No key frame, but `key` shows the one the last step retired (a
    /// frame without points could not start the next): [`Fusion::key`]
    /// until the next step.
    shows_retired: bool,
    /// The key frame's motion to the last accepted frame.
    chain: Chain,
    last: Option<u32>,
    /// Where the last accepted frame came from a link job
    /// ([`crate::wire::FrameJob::run_fused`]), the job's serial: a later
    /// job chains onto it only if its kept frame is that one (frame ids
    /// need not be unique). `None` after a step by the caller.
    pub(crate) link_serial: Option<u32>,
    /// The next frame is the key frame's last partner.
    due: bool,
    /// A key frame the processor keeps whose fusion has not started yet:
    /// `key` still shows the one that just retired (its id, its lengths).
    pending: Option<(u32, [u16; B])>,
    map: RoadMap<B, M>,
    /// The rest of a retirement, entered ([`Fusion::settle`]) and not
    /// reported yet ([`FusionStep::finished`]).
    finished: Option<Retired>,
    /// The last step retired a key frame: the map's sweep rests in the
    /// next too.
    rest_sweep: bool,
    /// The rounding of the last pair's composed motion (`Chain::config`).
    pair_rounding: Rounding,
    /// Key frames started over the fusion's life ([`KeyRef`]; a reset
    /// does not restart it).
    keys_started: u32,
}

/// One key frame of a fusion's life, as [`Fusion::constrain`] names it:
/// its frame id and the number of key frames the fusion had started when
/// it started, which [`Fusion::reset`] does not restart. Frame ids need
/// not be unique over a drive (a front end that restarts its ids, a fusion
/// reset after a broken chain): a range measured for one key frame is
/// never put on a later key frame with the same id.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct KeyRef {
    id: u32,
    serial: u32,
}

impl KeyRef {
    /// The key frame's id, as given to [`Fusion::step`].
    pub fn id(&self) -> u32 {
        self.id
    }

    /// The key frame's place among the key frames the fusion started, from
    /// 1 (wrapping after `u32::MAX`).
    pub fn serial(&self) -> u32 {
        self.serial
    }
}

impl<const N: usize, const B: usize, const M: usize> Fusion<N, B, M> {
    /// A fusion with no frame yet: the processor's configuration `base`
    /// (its error bounds are per frame) and the policy `config`.
    pub const fn new(base: Config, config: FusionConfig) -> Self {
        let scale = DepthScale::for_max_depth(base.max_depth());
        Self {
            processor: Processor::new(base),
            base,
            config,
            key: KeyFrame::new(scale, config.map_min_pairs),
            has_key: false,
            shows_retired: false,
            chain: Chain::IDENTITY,
            last: None,
            link_serial: None,
            due: false,
            pending: None,
            map: RoadMap::new(config.tilt_sc, scale),
            finished: None,
            rest_sweep: false,
            pair_rounding: Rounding::NONE,
            keys_started: 0,
        }
    }

    /// Forget every frame and the map (e.g. after a camera reset, when the
    /// motion chain is broken). The counters of the map start over.
    pub fn reset(&mut self) {
        self.processor.reset();
        self.processor.set_config(self.base);
        self.has_key = false;
        self.shows_retired = false;
        self.chain = Chain::IDENTITY;
        self.last = None;
        self.link_serial = None;
        self.due = false;
        self.pending = None;
        self.finished = None;
        self.rest_sweep = false;
        self.map.clear();
    }

    /// [`Fusion::reset`] with the policy `config` from now on (the map's
    /// tilt, its admission, the key-frame rule, the sight check).
    pub fn reset_with(&mut self, config: FusionConfig) {
        self.reset();
        self.config = config;
        self.key.reconfigure(config.map_min_pairs);
        self.map.clear_tilted(config.tilt_sc);
    }

    /// Process frame `id` with the motion from the last accepted frame
    /// (ignored for the first frame, or the first after
    /// [`Fusion::reset`]).
    ///
    /// The ids are what chains the motions: a motion "from `k`" is taken
    /// from the last accepted frame when that frame's id is `k`, whatever
    /// frame the caller meant by it. A front end that restarts its frame
    /// ids (or reuses one) resets the fusion first; a frame refused as
    /// [`FusionError::RepeatedFrame`] is not a new frame to chain from.
    /// (Range returns are safe either way: [`KeyRef`].)
    ///
    /// Errors (nothing changes): [`FusionError::MissingMotion`],
    /// [`FusionError::BrokenChain`] when the motion does not start at the
    /// last accepted frame, [`FusionError::RepeatedFrame`].
    ///
    /// Work: one [`Processor`] call (the matching), one pass over the key
    /// frame's points, carrying the map (module docs).
    ///
    /// ```
    /// use roadstereo::fusion::{ChainedMotion, FusedStatus, Fusion, FusionConfig};
    /// use roadstereo::{Camera, Config, Frame, Motion, Pixel};
    /// let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap();
    /// let mut fusion = Fusion::<64, 2, 128>::new(Config::DEFAULT, FusionConfig::DEFAULT);
    /// // A straight road edge on the ground 1 unit below the camera and 1
    /// // to the left, at depths 5 to 16, seen after `n` steps of 0.25
    /// // forward and 0.05 to the right.
    /// let edge = |n: f32| {
    ///     let mut f = Frame::new(cam);
    ///     let pts: Vec<Pixel> = (0..12)
    ///         .map(|i| {
    ///             let (x, z) = (-1.0 - 0.05 * n, 5.0 + i as f32 - 0.25 * n);
    ///             Pixel::new(255.5 + 800.0 * x / z, 239.5 + 800.0 / z)
    ///         })
    ///         .collect();
    ///     f.push_boundary(&pts).unwrap();
    ///     f
    /// };
    /// fusion.step(0, &edge(0.0), None).unwrap();
    /// let step = Motion::new([0.05, 0.0, 0.25], [0.0; 3]).unwrap();
    /// for id in 1..=3 {
    ///     let m = ChainedMotion { from: id - 1, motion: step };
    ///     fusion.step(id, &edge(id as f32), Some(&m)).unwrap();
    /// }
    /// // The key frame (frame 0) has three partners; its points' fused
    /// // intervals hold the true depths 5 + i.
    /// let key = fusion.key().unwrap();
    /// assert_eq!(key.partners(), 3);
    /// let p = key.point(0, 4).unwrap();
    /// assert_eq!(p.status, FusedStatus::Consistent);
    /// let iv = p.interval.unwrap();
    /// assert!(iv.z_near <= 9.0 && 9.0 <= iv.z_far);
    /// ```
    pub fn step(
        &mut self,
        id: u32,
        frame: &Frame<N, B>,
        motion: Option<&ChainedMotion>,
    ) -> Result<FusionStep, FusionError> {
        self.step_within(id, frame, motion, &mut NoDeadline)
    }

    /// [`Fusion::step`] with the pair's matching bounded by the caller's
    /// `deadline` ([`Processor::process_within`], [`crate::deadline`]):
    /// once it has expired the key-frame points not matched are
    /// [`crate::Status::OverBudget`] in this pair, which gives them no new
    /// interval (as any flag does), and [`Fusion::deadline_expired`] says
    /// so. A cut pair does not count towards the key-frame policy's "few
    /// matched" rule (a frame the clock cut short says nothing about how
    /// much of the key frame is still in view). The fusion's own work after
    /// the matching (one pass over the key frame's points, the map) is not
    /// cut: it is linear in the key frame's points plus a constant
    /// (`docs/FUSION.md`, "The fusion's own work"), so leave room for it in
    /// the limit. Its figures on the emulated Cortex-M4F (measured by
    /// `cargo xtask bench`, not a bound; more a point where key frames
    /// are small, shrink, or their pairs disagree): README, "Within a
    /// deadline".
    pub fn step_within<D: Deadline>(
        &mut self,
        id: u32,
        frame: &Frame<N, B>,
        motion: Option<&ChainedMotion>,
        deadline: &mut D,
    ) -> Result<FusionStep, FusionError> {
        let mut out = FusionStep {
            paired: None,
            partner: 0,
            retired: None,
            finished: None,
            new_key: None,
        };
        // 1. Validate (nothing changes on an error).
        let Some(last) = self.last else {
            self.last = Some(id);
            self.link_serial = None;
            out.new_key = self.start_key(id, frame, KeyReason::First, false);
            return Ok(out);
        };
        let m = chained_from(last, id, motion)?;
        self.last = Some(id);
        self.link_serial = None;
        let bounds = StepBounds::of(&self.base);
        self.settle();
        out.finished = self.finished.take();
        let after_retirement = core::mem::take(&mut self.rest_sweep);
        self.shows_retired = false;
        if !self.has_key {
            self.map.carry(&m.motion, &bounds);
            if !after_retirement {
                self.map.sweep();
            }
            out.new_key = self.start_key(id, frame, KeyReason::First, false);
            return Ok(out);
        }
        // 2. The motion from the key frame, and the pair. (The chain is
        // kept from here on: every path below either keeps it or starts it
        // anew after retiring the key frame with it.)
        self.chain = self.chain.then(&m.motion, &bounds);
        let motion = self.chain.motion();
        let cfg = self.chain.config(&self.base);
        let limit = match (&motion, &cfg) {
            (Err(_), _) => Some(KeyReason::MotionLimit),
            (Ok(_), Err(_)) => Some(KeyReason::ErrorLimit),
            (Ok(_), Ok(_)) => None,
        };
        let last_partner = self.due && has_points(frame);
        // 3. The map follows the vehicle; its sweep, after the pass, rests
        // in a frame where a key frame retires and in the next (they copy
        // points instead, the next the rest of a retirement cut at its
        // share; resting in it whether cut or not leaves a cut
        // retirement's map the whole one's), and where the pass had more
        // conflicts than agreeing intervals (below).
        self.map.carry(&m.motion, &bounds);
        let sweep = !(last_partner || limit.is_some() || after_retirement);
        let (Ok(motion), Ok(cfg), None) = (&motion, &cfg, limit) else {
            // No last pair: retire what the key frame has, at the same
            // share as after a last pair, and start anew. (The processor
            // keeps this frame at once, but its reconstruction of the
            // key frame's pixels stays until it pairs again, and `key`
            // the retired cells until `settle`: the rest enters then, as
            // after a last pair.)
            out.retired = self.retire(self.config.retire_permille, 0);
            let shown = out.retired.is_some();
            // (`limit` is `Some` here: `None` only with both `Ok`.)
            let reason = limit.unwrap_or(KeyReason::MotionLimit);
            out.new_key = self.start_key(id, frame, reason, shown);
            return Ok(out);
        };
        // (The composed bounds and the composition's rounding, for this
        // pair: `Chain::config`.)
        let (cfg, rounding) = *cfg;
        self.processor.set_config(cfg);
        let fused = self.fuse_pair(frame, motion, rounding, last_partner, deadline);
        let cut = self.processor.deadline_expired();
        // The sweep rests where more of the pass's intervals conflicted
        // than agreed: each conflict cost the pass about 40 instructions
        // more, about what the sweep's tests would (module docs, "The
        // sweep after the pass").
        if sweep && fused.conflicts.saturating_mul(2) <= fused.matched {
            self.map.sweep();
        }
        // 4. The pair fused; a last partner retires the key frame.
        out.paired = Some(fused);
        out.partner = self.key.partners();
        if last_partner {
            // (The processor keeps the reconstruction of the key frame's
            // pixels and `key` its cells until the next step: the rest of
            // a retirement past the share enters then, `settle`.)
            out.retired = self.retire(self.config.retire_permille, fused.conflicts);
            out.new_key = Some(if self.key.partners() >= self.config.max_partners {
                KeyReason::Partners
            } else {
                KeyReason::FewMatched
            });
            // The processor keeps this frame: the new key frame. Its fusion
            // starts with the next frame; until then `key` shows the
            // retired one's final state.
            self.begin_key(id, frame);
            self.chain = Chain::IDENTITY;
            self.due = self.config.max_partners <= 1;
            return Ok(out);
        }
        // 5. The policy: is the next frame the last partner?
        let p = self.key.partners();
        let best = self.key.best_matched();
        let few = !cut
            && (u64::from(fused.matched) * 1000
                < u64::from(self.config.keep_permille) * u64::from(best)
                || (best == 0 && p >= 2));
        self.due = p.saturating_add(1) >= self.config.max_partners || few;
        Ok(out)
    }

    /// The pair of the key frame and `frame` through the processor, fused
    /// into the key frame: a last partner is processed against the kept
    /// frame and replaces it (it becomes the next key frame), any other is
    /// processed against the kept frame, which stays.
    fn fuse_pair<D: Deadline>(
        &mut self,
        frame: &Frame<N, B>,
        motion: &Motion,
        rounding: Rounding,
        last_partner: bool,
        deadline: &mut D,
    ) -> PairFused {
        // (The composition's rounding, which the processor carries.)
        self.pair_rounding = rounding;
        // (The pair's configuration, for the sight check's margins.)
        let cfg = self.config.sight_check.then(|| *self.processor.config());
        match self.processor.process_composed_within(
            frame,
            motion,
            rounding,
            !last_partner,
            deadline,
        ) {
            Ok(s) => match cfg {
                None => self.key.fuse(s),
                Some(cfg) => fuse_sighted(&mut self.key, s, (frame, motion, &cfg)),
            },
            // (A kept frame exists: not reached.)
            Err(_) => PairFused::default(),
        }
    }

    /// The last step's pair again on `copy` (a copy of [`Fusion::processor`]
    /// from before the step), with its configuration and composed
    /// motion's rounding: for the project's bench firmware, which times
    /// the matching apart from the fusion's own work. Not part of the API.
    #[cfg(feature = "firmware")]
    #[doc(hidden)]
    pub fn replay_pair<'p>(
        &self,
        copy: &'p mut Processor<N, B>,
        frame: &Frame<N, B>,
        motion: &Motion,
        last_partner: bool,
    ) -> Result<&'p Structure<N, B>, crate::ProcessError> {
        copy.set_config(*self.processor.config());
        copy.process_composed_within(
            frame,
            motion,
            self.pair_rounding,
            !last_partner,
            &mut NoDeadline,
        )
    }

    /// Whether the deadline of the last [`Fusion::step_within`] cut its
    /// pair's matching short ([`Processor::deadline_expired`]); `false`
    /// after a step that did not pair. A step that returned an error
    /// changes nothing, this flag included. A pair cut short, even at
    /// its first question, still takes one of the key frame's
    /// `max_partners` places.
    pub fn deadline_expired(&self) -> bool {
        self.processor.deadline_expired()
    }

    /// Make frame `id` the key frame (if it has points): the processor
    /// keeps it, every point unmatched. With `show_retired` the fusion
    /// state keeps showing the key frame that just retired until the next
    /// frame ([`Fusion::key`]).
    fn start_key(
        &mut self,
        id: u32,
        frame: &Frame<N, B>,
        reason: KeyReason,
        show_retired: bool,
    ) -> Option<KeyReason> {
        self.processor.reset();
        self.processor.set_config(self.base);
        self.chain = Chain::IDENTITY;
        self.due = self.config.max_partners <= 1;
        self.pending = None;
        if !has_points(frame) {
            self.has_key = false;
            // (`key` keeps the retired key frame's state until the next
            // step, as with a frame that starts the next key frame.)
            self.shows_retired = show_retired;
            return None;
        }
        let _ = self.processor.process(frame, None);
        self.begin_key(id, frame);
        if !show_retired {
            self.settle();
        }
        self.has_key = true;
        Some(reason)
    }

    /// Frame `id`, which the processor keeps, is the new key frame; its
    /// fusion starts with the next step ([`Self::settle`]).
    fn begin_key(&mut self, id: u32, frame: &Frame<N, B>) {
        self.pending = Some((id, KeyFrame::lens_of(frame)));
        self.keys_started = self.keys_started.wrapping_add(1);
    }

    /// Start the fusion of a key frame the processor keeps; first, the rest
    /// of the last retirement enters the map, while the retired key frame's
    /// cells and the reconstruction of its pixels are still there (every
    /// caller settles before the processor pairs again or `key` starts).
    fn settle(&mut self) {
        if let Some(r) = self.map.finish(&self.key, self.processor.structure()) {
            self.finished = Some(r);
        }
        if let Some((id, lens)) = self.pending.take() {
            self.key.start(id, lens);
        }
    }

    /// Move the key frame's fused points into the map, posed by the chain
    /// (the key frame's motion to the current frame): admitted points up to
    /// `permille` ‰ of its points, less half the `conflicts` of the pair
    /// fused in this step, now, the rest at the next [`Self::settle`].
    fn retire(&mut self, permille: u16, conflicts: u32) -> Option<Retired> {
        if !self.has_key || self.key.partners() == 0 {
            return None;
        }
        self.rest_sweep = true;
        Some(self.map.retire(
            &self.key,
            self.processor.structure(),
            &self.chain,
            (self.base.e1(), permille, conflicts),
        ))
    }

    /// Intersect point `index` of key-frame boundary `boundary` with a
    /// range interval from another sensor: the point is between `near` and
    /// `far` along its ray, as **distances from the key-frame camera
    /// centre** (what a lidar or radar return gives), `0 ≤ near ≤ far`,
    /// both finite. It counts as one more pair: an interval missing the
    /// fused one flags the point; with the sight check on
    /// ([`FusionConfig::with_sight_check`]) one whose near end lies below
    /// what a partner was shown to see widens it down to that near end
    /// ([`FusedStatus::Widened`]). Returns the point after.
    ///
    /// The distance `r` along the ray through normalised `(x, y)` is the
    /// depth `Z = r / √(1 + x² + y²)`, on the **true** point's ray, whose
    /// pixel is within `e₁` of the detected one ([`Config::e1`]): the near
    /// end is divided by the largest `√(1 + x² + y²)` over those rays and
    /// the far end by the smallest, both rounded outwards (a `far` whose
    /// depth overflows `f32` is an [`FusionError::InvalidRange`]). (The
    /// detected pixel's ray alone missed the truth by about `|x| e₁/f`
    /// of the depth, found by an adversarial review.)
    ///
    /// `key` names the key frame the range belongs to ([`Fusion::key_ref`]
    /// when the range was asked for); it must be the one constraints go
    /// to now, the processor's kept frame, else
    /// [`FusionError::KeyMismatch`]: right after a step that retired a key
    /// frame that is the **new** one, whose fusion starts with it
    /// ([`Fusion::key`] shows the new key frame from then on, not the
    /// retired one's final state), so a range measured for the retired
    /// one's pixels is refused rather than put on another point, also when
    /// the new key frame has the same frame id ([`KeyRef`]). An error
    /// leaves everything as it was, [`Fusion::key`] included. The checks,
    /// in order: the range, a key frame, the key, the point.
    pub fn constrain(
        &mut self,
        key: KeyRef,
        boundary: usize,
        index: usize,
        near: f32,
        far: f32,
    ) -> Result<FusedPoint, FusionError> {
        if !(near.is_finite() && far.is_finite() && 0.0 <= near && near <= far) {
            return Err(FusionError::InvalidRange);
        }
        let current = self.key_ref().ok_or(FusionError::NoKeyFrame)?;
        if key != current {
            return Err(FusionError::KeyMismatch {
                expected: current,
                given: key,
            });
        }
        // Every check before the pending key frame's fusion starts
        // (`settle`): the kept frame is that key frame, and an error must
        // leave the state untouched.
        let kept = self
            .processor
            .previous()
            .filter(|_| self.has_key)
            .ok_or(FusionError::NoKeyFrame)?;
        let p = kept
            .boundaries()
            .get(boundary)
            .and_then(|b| b.points().get(index))
            .copied()
            .ok_or(FusionError::NoSuchPoint)?;
        // The true point is on the ray of a pixel within `e₁` of the
        // detected one: its `√(1 + x² + y²)` between those at the corners
        // of the box `|Δx| ≤ e₁/f_x`, `|Δy| ≤ e₁/f_y` nearest to and
        // farthest from the principal point (the disc is inside the box).
        let cam = kept.camera();
        let [x, y] = cam.normalise(p);
        let e1 = self.base.e1();
        let (dx, dy) = (e1 / cam.fx(), e1 / cam.fy());
        let (xa, ya) = (x.abs(), y.abs());
        let (xl, yl) = (fmax(xa - dx, 0.0), fmax(ya - dy, 0.0));
        let (xh, yh) = (xa + dx, ya + dy);
        let n_lo = sqrt(1.0 + xl * xl + yl * yl);
        let n_hi = sqrt(1.0 + xh * xh + yh * yh);
        // (sqrt is within 2e-7 of the truth; 1e-6 covers it, the squares
        // and the division. Where a quotient is subnormal its rounding is
        // absolute, up to half of `f32::from_bits(1)` an operation: two of
        // them more, found by an adversarial review at ranges below 10⁻⁴².)
        let tiny = f32::from_bits(2);
        let (zn, zf) = (
            fmax(near / n_hi * (1.0 - 1.0e-6) - tiny, 0.0),
            far / n_lo * (1.0 + 1.0e-6) + tiny,
        );
        // (A far end near `f32::MAX` overflows; `n ≥ 1`, so only the far one.)
        if !zf.is_finite() {
            return Err(FusionError::InvalidRange);
        }
        self.settle();
        match self
            .key
            .constrain(boundary, index, (zn, zf), self.config.sight_check)
        {
            Some(Added::Agreed | Added::Unseen { .. } | Added::Conflict { .. }) => {}
            None => return Err(FusionError::NoSuchPoint),
        }
        self.key
            .point(boundary, index)
            .ok_or(FusionError::NoSuchPoint)
    }

    /// The id of the key frame that [`Fusion::constrain`] addresses: the
    /// processor's kept frame, the newest key frame (right after a step
    /// that retired one, the new one, while [`Fusion::key`] still shows
    /// the retired one and [`Fusion::key_point`] gives `None` until the
    /// new one's fusion starts). `None` without a key frame.
    pub fn key_id(&self) -> Option<u32> {
        if !self.has_key || self.processor.previous().is_none() {
            return None;
        }
        Some(self.pending.map_or(self.key.id(), |(id, _)| id))
    }

    /// The key frame [`Fusion::constrain`] addresses, as it names it: its
    /// id ([`Fusion::key_id`]) and its place among the key frames the
    /// fusion started. Take it when asking another sensor for a range, and
    /// give it back with the range.
    pub fn key_ref(&self) -> Option<KeyRef> {
        Some(KeyRef {
            id: self.key_id()?,
            serial: self.keys_started,
        })
    }

    /// The current key frame's fusion, if there is a key frame. Right
    /// after a step that retired a key frame ([`FusionStep::retired`]) and
    /// until the next step, the retired key frame's final state (its
    /// [`KeyFrame::id`] tells): what went into the map, and what the pairs
    /// made of every point. That holds also when the retiring frame had no
    /// points and so started no key frame ([`Fusion::key_id`] is then
    /// `None`).
    pub fn key(&self) -> Option<&KeyFrame<N, B>> {
        (self.has_key || self.shows_retired).then_some(&self.key)
    }

    /// Point `index` of key-frame boundary `boundary` with its pixel and
    /// ray, so its fused interval can be put in 3-D ([`KeyPoint::stick`]:
    /// key-frame camera coordinates). The key frame's pixels are the
    /// processor's kept frame, so this is `None` right after a step that
    /// retired a key frame and until the next step or
    /// [`Fusion::constrain`]: [`Fusion::key`] then shows the retired key
    /// frame, whose frame the processor no longer keeps (its admitted
    /// points are in the map, in 3-D: [`RoadMap::points`]). `None` also
    /// without a key frame or such a point.
    ///
    /// ```
    /// use roadstereo::fusion::{ChainedMotion, Fusion, FusionConfig};
    /// use roadstereo::{Camera, Config, Frame, Motion, Pixel};
    /// let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap();
    /// let mut fusion = Fusion::<64, 1, 128>::new(Config::DEFAULT, FusionConfig::DEFAULT);
    /// // A straight edge 1 below and 1 left of the camera, depths 5 to 16,
    /// // after `n` steps of 0.25 forward and 0.05 right.
    /// let edge = |n: f32| {
    ///     let mut f = Frame::new(cam);
    ///     let mut pts = [Pixel::default(); 12];
    ///     for (i, p) in pts.iter_mut().enumerate() {
    ///         let (x, z) = (-1.0 - 0.05 * n, 5.0 + i as f32 - 0.25 * n);
    ///         *p = Pixel::new(255.5 + 800.0 * x / z, 239.5 + 800.0 / z);
    ///     }
    ///     f.push_boundary(&pts).unwrap();
    ///     f
    /// };
    /// fusion.step(0, &edge(0.0), None).unwrap();
    /// let step = Motion::new([0.05, 0.0, 0.25], [0.0; 3]).unwrap();
    /// for id in 1..=3 {
    ///     let m = ChainedMotion { from: id - 1, motion: step };
    ///     fusion.step(id, &edge(id as f32), Some(&m)).unwrap();
    /// }
    /// // Point 4 is at (-1, 1, 9) in the key frame's camera coordinates.
    /// let p = fusion.key_point(0, 4).unwrap();
    /// let (near, far) = p.stick().unwrap();
    /// assert!(near[2] <= 9.0 && 9.0 <= far[2]);
    /// assert!((near[0] / near[2] + 1.0 / 9.0).abs() < 1e-3);
    /// ```
    pub fn key_point(&self, boundary: usize, index: usize) -> Option<KeyPoint> {
        if !self.has_key || self.pending.is_some() {
            return None;
        }
        let frame = self.processor.previous()?;
        let pixel = *frame.boundaries().get(boundary)?.points().get(index)?;
        let fused = self.key.point(boundary, index)?;
        let [x, y] = frame.camera().normalise(pixel);
        Some(KeyPoint {
            pixel,
            ray: [x, y, 1.0],
            fused,
        })
    }

    /// The road map.
    pub fn map(&self) -> &RoadMap<B, M> {
        &self.map
    }

    /// The last pair's reconstruction (the key frame against the last
    /// paired frame, in key-frame camera coordinates).
    pub fn structure(&self) -> &Structure<N, B> {
        self.processor.structure()
    }

    /// The processor (its kept frame is the key frame).
    pub fn processor(&self) -> &Processor<N, B> {
        &self.processor
    }

    /// The counting rule for folded points in the pairs' search on or off
    /// from the next step on ([`Processor::set_fold_counting`]; off by
    /// default). A pair's points are then searched where the rule allows,
    /// and their sticks fuse as every other point's.
    pub fn set_fold_counting(&mut self, on: bool) {
        self.processor.set_fold_counting(on);
    }

    /// The id of the last frame a step accepted (`None` before the first
    /// and after [`Fusion::reset`]): the frame the next step's motion must
    /// start from ([`FusionError::BrokenChain`]).
    pub fn last_frame(&self) -> Option<u32> {
        self.last
    }

    /// The policy.
    pub fn config(&self) -> &FusionConfig {
        &self.config
    }

    /// The processor's configuration the fusion was made with
    /// ([`Fusion::new`]'s `base`): every pair's error model, before the
    /// composed motion's bounds are added.
    pub fn base_config(&self) -> &Config {
        &self.base
    }

    /// A 32-bit FNV-1a digest of the key frame's fusion and the map, bit
    /// for bit (to compare the firmware with the host build).
    pub fn digest(&self) -> u32 {
        let mut h: u32 = 0x811c_9dc5;
        let mut eat = |x: u32| {
            for b in x.to_le_bytes() {
                h = (h ^ u32::from(b)).wrapping_mul(0x0100_0193);
            }
        };
        eat(u32::from(self.has_key));
        if self.has_key {
            self.key.digest_into(&mut eat);
        }
        self.map.digest_into(&mut eat);
        h
    }
}

/// Step 1 of [`Fusion::step`] after the first frame: frame `id`'s motion
/// must be given and chain from the `last` frame, and `id` must be new.
fn chained_from(
    last: u32,
    id: u32,
    motion: Option<&ChainedMotion>,
) -> Result<&ChainedMotion, FusionError> {
    let m = motion.ok_or(FusionError::MissingMotion)?;
    if m.from != last {
        return Err(FusionError::BrokenChain {
            expected: last,
            given: m.from,
        });
    }
    if id == last {
        return Err(FusionError::RepeatedFrame(id));
    }
    Ok(m)
}

fn has_points<const N: usize, const B: usize>(frame: &Frame<N, B>) -> bool {
    frame.boundaries().iter().any(|b| !b.points().is_empty())
}

// The fusion state and the map beside the processor fit 24 KiB on the
// vehicle controller (issue 13): 2 × 256 key-frame points, 2 × 512 map
// points. A change that grows them past it fails the build.
#[cfg(target_pointer_width = "32")]
const _: () = assert!(
    core::mem::size_of::<Fusion<256, 2, 512>>() - core::mem::size_of::<Processor<256, 2>>()
        <= 24 * 1024
);

/// [`KeyFrame::fuse_sighted`] for a pair with `partner` under `motion`
/// and the pair's configuration: what the partner sees of each
/// boundary's rays first (`sight`). Out of line, so that a step without
/// the check keeps its stack.
#[inline(never)]
fn fuse_sighted<const N: usize, const B: usize>(
    key: &mut KeyFrame<N, B>,
    s: &Structure<N, B>,
    (partner, motion, cfg): (&Frame<N, B>, &Motion, &Config),
) -> PairFused {
    let sights: [Option<sight::Sight>; B] = core::array::from_fn(|k| {
        let points = partner.boundaries().get(k).map_or(&[][..], |b| b.points());
        sight::Sight::new(s.camera1(), partner.camera(), points, motion, cfg)
    });
    key.fuse_sighted(s, &sights)
}
