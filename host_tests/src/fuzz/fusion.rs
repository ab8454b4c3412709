//! The key-frame fusion and its road map ([`roadstereo::fusion`]):
//! sequences of [`Fusion::step`], [`Fusion::step_within`],
//! [`Fusion::constrain`] and [`Fusion::reset`] calls.
//!
//! Inputs: the frame target's road scenes, cameras, configurations,
//! motions and boundaries ([`super::frame`]), driven frame after frame
//! with frame ids, so most steps pair with a key frame and key frames
//! retire into a small map; mixed with missing motions, motions from
//! another frame, repeated and arbitrary ids, frames without points,
//! clocks that cut the pair at any question, range constraints on any
//! point (out of range, inverted, special values, many on one point) and
//! every [`FusionConfig`] option at and beyond its limits.
//!
//! Oracles, on every call:
//! * no panic (the host tests' profile has overflow checks on) and no
//!   hang;
//! * errors exactly when the API says (the frame chain's rules and the
//!   range's, decided here from the calls), and then the state untouched:
//!   its digest as before the call, and on one call in eight its whole
//!   `Debug` (the processor, the chain, the policy's counters); and a
//!   shadow fusion gets only the calls
//!   that succeeded, with the same clocks, and both agree after every call
//!   (their digests, steps and constrained points), which also checks
//!   determinism;
//! * a clock is not asked after it said yes, and the expiry flag is set
//!   exactly when it did in a step that paired;
//! * every key-frame point well formed: its status as its counts say
//!   (unmatched without an interval, single with one pair, consistent
//!   with two or more and none disagreeing, inconsistent with some), its
//!   interval finite with `0 ≤ z_near ≤ z_far`, the per-status counts
//!   their sums, the partners within the policy;
//! * a retired key frame's points all accounted for (entered, unverified,
//!   inconsistent, unbounded or unfit), and the map's: every point that
//!   entered since the last reset is stored, dropped behind the vehicle
//!   or dropped for room; at most `M` a boundary and [`MAP_BATCHES`]
//!   batches; every map point finite with a finite radius `≥ 0`.

use roadstereo::fusion::{
    ChainedMotion, FusedStatus, Fusion, FusionConfig, FusionConfigError, FusionError, FusionStep,
    KeyRef, MAX_PARTNERS,
};
use roadstereo::map::MAP_BATCHES;
use roadstereo::{Camera, Config, Frame, Pixel};

use super::frame::{self, ConfigIn, FrameIn, MotionIn, Pose, Scene, IDENTITY};
use super::{Outcome, Source};

/// The usual capacity: key frames of up to 3 boundaries of 64 points, a
/// map of 40 points a boundary (small, so that it fills).
pub const SMALL: (usize, usize, usize) = (64, 3, 40);
/// One case in 16: the firmware's sizes (2 × 256 points, 512 a boundary
/// in the map).
pub const LARGE: (usize, usize, usize) = (256, 2, 512);

/// One case: the capacity, the configurations, the calls.
#[derive(Debug, Clone)]
pub struct Case {
    /// [`LARGE`] instead of [`SMALL`].
    pub large: bool,
    /// The processor's configuration.
    pub config: ConfigIn,
    /// The fusion's policy.
    pub policy: PolicyIn,
    /// The calls, in order.
    pub calls: Vec<Call>,
}

/// Arguments of [`FusionConfig::new`] and its `with_` methods (`None`: not
/// called). A rejected step leaves the policy of the steps before.
#[derive(Debug, Clone, Copy)]
pub struct PolicyIn {
    /// `max_partners`, `keep_permille`.
    pub new: (u16, u16),
    /// [`FusionConfig::with_map_min_pairs`].
    pub min_pairs: Option<u8>,
    /// [`FusionConfig::with_tilt`].
    pub tilt: Option<f32>,
    /// [`FusionConfig::with_sight_check`] (drawn after everything else: a
    /// case saved before it reads what follows its draws, or 0, the check
    /// off).
    pub sight: bool,
    /// [`FusionConfig::with_retirement_share`] (drawn after the sight
    /// check, for the same reason).
    pub share: Option<u16>,
}

/// One call.
#[derive(Debug, Clone)]
pub enum Call {
    /// [`Fusion::step`], or [`Fusion::step_within`] with a clock that says
    /// the time is up from its `clock`-th question on.
    Step {
        /// The frame's id.
        id: u32,
        /// The frame.
        frame: FrameIn,
        /// The motion and the id it starts from.
        motion: Option<(u32, MotionIn)>,
        /// The clock, if any.
        clock: Option<usize>,
    },
    /// [`Fusion::constrain`], `times` times over.
    Constrain {
        /// The key-frame boundary.
        boundary: usize,
        /// The point.
        index: usize,
        /// Distances along the ray.
        near: f32,
        /// Distances along the ray.
        far: f32,
        /// How many times.
        times: u16,
    },
    /// [`Fusion::reset`].
    Reset,
}

// ---------------------------------------------------------------------
// Generation.

fn policy(src: &mut Source) -> PolicyIn {
    let partners = match src.below(16) {
        0 => src.pick(&[0, MAX_PARTNERS, MAX_PARTNERS + 1, u16::MAX]),
        1..=3 => 1,
        4 => 1 + src.below(u32::from(MAX_PARTNERS)) as u16,
        _ => 2 + src.below(7) as u16,
    };
    let keep = match src.below(8) {
        0 => src.pick(&[0, 1000, 1001, u16::MAX]),
        1 => src.below(1001) as u16,
        _ => 500,
    };
    let min_pairs = src.chance(1, 3).then(|| match src.below(4) {
        0 => src.pick(&[0, 64, 65, u8::MAX]),
        _ => 1 + src.below(4) as u8,
    });
    let tilt = src.chance(1, 2).then(|| {
        src.mixed(|s| match s.below(8) {
            0 => s.pick(&[
                core::f32::consts::FRAC_PI_2,
                -core::f32::consts::FRAC_PI_2,
                core::f32::consts::FRAC_PI_2.next_up(),
            ]),
            _ => s.f32_in(-0.1, 0.5),
        })
    });
    PolicyIn {
        new: (partners, keep),
        min_pairs,
        tilt,
        sight: false,
        share: None,
    }
}

/// A range along a ray: mostly plausible, else inverted, negative, special
/// or huge.
fn range(src: &mut Source) -> (f32, f32) {
    match src.below(16) {
        0 => (src.special(), src.special()),
        1 => {
            let a = src.f32_in(0.0, 50.0);
            (a + 1.0, a)
        }
        2 => (-src.f32_in(0.0, 5.0), src.f32_in(0.0, 5.0)),
        3 => (0.0, src.pick(&[f32::MAX, 3.0e38, 1.0e30, 0.0])),
        _ => {
            let a = src.f32_in(0.5, 80.0);
            (a, a * src.f32_in(1.0, 2.0))
        }
    }
}

/// Draw a case.
pub fn generate(src: &mut Source) -> Case {
    let large = src.chance(1, 16);
    let (cap, cap_b, _) = if large { LARGE } else { SMALL };
    let cap_points = if large || src.chance(1, 4) { cap } else { 24 };
    // One case in three is a clean drive: the paper's camera, forward
    // motions along the road, an unbroken chain, the default processor
    // configuration mostly, so that pairs match and key frames fill the
    // map; the rest mix in every kind of bad input.
    let clean = src.chance(1, 3);
    let config = if clean && src.chance(3, 4) {
        ConfigIn {
            new: [0.5, 0.5, 10.0, 1000.0],
            translation_error: None,
            rotation_error: None,
            work_budget: None,
        }
    } else {
        frame::config(src)
    };
    let mut policy = policy(src);
    if clean {
        policy.new = (2 + src.below(7) as u16, 500);
        policy.min_pairs = Some(1 + src.below(2) as u8);
    }
    let scene = Scene::new(src);
    let (k0, size0) = if clean {
        ([800.0, 800.0, 255.5, 239.5], (512, 480))
    } else {
        frame::camera(src)
    };
    // Mostly short sequences; one in eight a drive long enough to fill
    // the map's batches.
    let calls_n = match (large, src.chance(1, 8)) {
        (true, _) => 3 + src.index(8),
        (false, false) => 3 + src.index(18),
        (false, true) => 24 + src.index(40),
    };
    let mut calls = Vec::with_capacity(calls_n);
    // The generator's model: the last frame's pose and id.
    let mut pose: Pose = IDENTITY;
    let mut last: Option<u32> = None;
    let mut last_boundaries: Vec<Vec<[f32; 2]>> = Vec::new();
    for _ in 0..calls_n {
        match src.below(if clean { 96 } else { 24 }) {
            0 => {
                calls.push(Call::Reset);
                last = None;
                continue;
            }
            1..=3 => {
                let (near, far) = range(src);
                let times = if src.chance(1, 8) {
                    1 + src.below(300) as u16
                } else {
                    1
                };
                calls.push(Call::Constrain {
                    boundary: src.index(cap_b + 1),
                    index: if src.chance(1, 8) {
                        src.pick(&[cap, cap + 1, usize::MAX])
                    } else {
                        src.index(cap_points)
                    },
                    near,
                    far,
                    times,
                });
                continue;
            }
            _ => {}
        }
        let m = if clean {
            let (st, ct) = (scene.tilt.sin() as f32, scene.tilt.cos() as f32);
            let w = src.f32_in(0.1, 0.6);
            MotionIn {
                t: [src.f32_in(-0.05, 0.05), -w * st, w * ct],
                r: [0.0, src.f32_in(-0.01, 0.01), 0.0],
            }
        } else {
            frame::motion(src, scene.tilt)
        };
        let id = match (last, if clean { 2 } else { src.below(32) }) {
            (Some(l), 0) => l,
            (_, 1) => src.u32(),
            (Some(l), _) => l.wrapping_add(1),
            (None, _) => src.below(4),
        };
        let from = match (last, if clean { 2 } else { src.below(32) }) {
            (_, 0) => None,
            (Some(l), 1) => Some(l.wrapping_sub(1)),
            (Some(l), _) => Some(l),
            (None, _) => Some(src.u32()),
        };
        let valid = roadstereo::Motion::new(m.t, m.r).is_ok();
        // The true pose follows the motion whenever it is a valid one.
        if valid && last.is_some() {
            pose = pose.then(&m);
        }
        let (k, size) = if !clean && src.chance(1, 16) {
            frame::camera(src)
        } else {
            (k0, size0)
        };
        let nb = match src.below(16) {
            0 => 0,
            _ if !last_boundaries.is_empty() && src.chance(3, 4) => last_boundaries.len(),
            1 => cap_b + 1,
            _ => 1 + src.index(cap_b.min(scene.edges.len())),
        };
        let boundaries = frame::boundaries(
            src,
            (&scene, &pose),
            nb,
            (k, size),
            cap_points,
            &mut last_boundaries,
        );
        let clock = src.chance(1, 4).then(|| match src.below(4) {
            0 => 0,
            1 => 1 + src.index(8),
            _ => src.index(2000),
        });
        calls.push(Call::Step {
            id,
            frame: FrameIn {
                k,
                size,
                boundaries,
            },
            motion: from.map(|f| (f, m)),
            clock,
        });
        // The model does not know whether the camera is accepted; a step
        // with a rejected camera is skipped by the runner, and the next
        // step's chain is then broken, which is one more error to check.
        let chained = matches!(from, Some(f) if Some(f) == last);
        if last.is_none() || (chained && valid && Some(id) != last) {
            last = Some(id);
        }
    }
    policy.sight = !src.chance(1, 2);
    policy.share = src.chance(1, 2).then(|| match src.below(4) {
        0 => src.pick(&[0, 1000, 1001, u16::MAX]),
        _ => src.below(1001) as u16,
    });
    Case {
        large,
        config,
        policy,
        calls,
    }
}

// ---------------------------------------------------------------------
// Running and the oracles.

/// Feature bits (see [`Outcome::features`]): the fusion's own from 64 on,
/// above the frame target's (which its frames, motions and configurations
/// set too).
pub mod bit {
    pub const FUSION_ERR: u32 = 64; // 6
    pub const POLICY_ERR: u32 = 70; // 4
    pub const STATUS: u32 = 74; // 4: a fused status seen
    pub const NEW_KEY: u32 = 78; // 5: a key reason
    pub const RETIRED: u32 = 83;
    pub const DROPPED_ROOM: u32 = 84;
    pub const DROPPED_BEHIND: u32 = 85;
    pub const UNFIT: u32 = 86;
    pub const UNBOUNDED: u32 = 87;
    pub const CUT: u32 = 88;
    pub const CONFLICT: u32 = 89;
    pub const CONSTRAINED: u32 = 90;
    pub const SATURATED: u32 = 91;
    pub const LARGE: u32 = 92;
    pub const MAP_POINTS: u32 = 93;
    pub const FULL_BATCHES: u32 = 94;
    pub const BLANK_PAIRED: u32 = 95;
    /// The sight check's flag seen (`FusedStatus::PartlyUnseen`, apart
    /// from `STATUS`'s four, added before it).
    pub const PARTLY_UNSEEN: u32 = 96;
    /// The sight check's widening seen (`FusedStatus::Widened`).
    pub const WIDENED: u32 = 97;
    /// A constraint for another key frame refused
    /// (`FusionError::KeyMismatch`).
    pub const KEY_MISMATCH: u32 = 98;
    /// A retirement cut at its share, the rest entered the next step (or
    /// by a constraint before it: `Fusion::settle`).
    pub const FINISHED: u32 = 99;
    /// A retirement share above 1000 ‰ refused.
    pub const SHARE_ERR: u32 = 100;
    /// One past the last.
    pub const END: u32 = 101;
}

use frame::set;

/// Generate a case from `src` and check it.
pub fn run(src: &mut Source) -> Outcome {
    check(&generate(src))
}

/// Check a case against every oracle (panics on a finding).
pub fn check(case: &Case) -> Outcome {
    if case.large {
        run_case::<{ LARGE.0 }, { LARGE.1 }, { LARGE.2 }>(case)
    } else {
        run_case::<{ SMALL.0 }, { SMALL.1 }, { SMALL.2 }>(case)
    }
}

/// The policy of `p`, each rejected step checked against the documented
/// rule and skipped.
fn build_policy(p: &PolicyIn, features: &mut u128) -> FusionConfig {
    let (partners, keep) = p.new;
    let mut c = match FusionConfig::new(partners, keep) {
        Ok(c) => c,
        Err(e) => {
            let want = if partners == 0 || partners > MAX_PARTNERS {
                FusionConfigError::Partners
            } else {
                FusionConfigError::KeepShare
            };
            assert_eq!(e, want, "FusionConfig::new{:?}", p.new);
            set(features, bit::POLICY_ERR + e as u32);
            FusionConfig::DEFAULT
        }
    };
    if let Some(n) = p.min_pairs {
        match c.with_map_min_pairs(n) {
            Ok(x) => {
                assert!((1..=64).contains(&n), "min pairs {n} accepted");
                c = x;
            }
            Err(e) => {
                assert_eq!(e, FusionConfigError::MinPairs, "min pairs {n}");
                assert!(!(1..=64).contains(&n), "min pairs {n} rejected");
                set(features, bit::POLICY_ERR + e as u32);
            }
        }
    }
    c = c.with_sight_check(p.sight);
    if let Some(n) = p.share {
        match c.with_retirement_share(n) {
            Ok(x) => {
                assert!(n <= 1000, "share {n} accepted");
                c = x;
            }
            Err(e) => {
                assert_eq!(e, FusionConfigError::RetireShare, "share {n}");
                assert!(n > 1000, "share {n} rejected");
                set(features, bit::SHARE_ERR);
            }
        }
    }
    if let Some(t) = p.tilt {
        let ok = t.abs() <= core::f32::consts::FRAC_PI_2;
        match c.with_tilt(t) {
            Ok(x) => {
                assert!(ok, "tilt {t} accepted");
                c = x;
            }
            Err(e) => {
                assert_eq!(e, FusionConfigError::Tilt, "tilt {t}");
                assert!(!ok, "tilt {t} rejected");
                set(features, bit::POLICY_ERR + e as u32);
            }
        }
    }
    c
}

fn error_bit(e: &FusionError) -> u32 {
    match e {
        FusionError::MissingMotion => 0,
        FusionError::BrokenChain { .. } => 1,
        FusionError::RepeatedFrame(_) => 2,
        FusionError::NoKeyFrame => 3,
        FusionError::NoSuchPoint => 4,
        FusionError::KeyMismatch { .. } => bit::KEY_MISMATCH - bit::FUSION_ERR,
        // (Non-exhaustive: a later variant counts with `InvalidRange`.)
        _ => 5,
    }
}

/// The error [`Fusion::step`] must give for frame `id` with `motion`
/// after the last accepted frame `last`.
fn expected_step_error(
    last: Option<u32>,
    id: u32,
    motion: Option<&ChainedMotion>,
) -> Option<FusionError> {
    let last = last?;
    match motion {
        None => Some(FusionError::MissingMotion),
        Some(m) if m.from != last => Some(FusionError::BrokenChain {
            expected: last,
            given: m.from,
        }),
        Some(_) if id == last => Some(FusionError::RepeatedFrame(id)),
        Some(_) => None,
    }
}

/// One step on `f`: the result, and the clock's questions.
fn step<const N: usize, const B: usize, const M: usize>(
    f: &mut Fusion<N, B, M>,
    id: u32,
    frame: &Frame<N, B>,
    motion: Option<&ChainedMotion>,
    clock: Option<usize>,
) -> (Result<FusionStep, FusionError>, usize) {
    match clock {
        None => (f.step(id, frame, motion), 0),
        Some(k) => {
            let mut asked = 0usize;
            let mut c = || {
                asked += 1;
                asked > k
            };
            let r = f.step_within(id, frame, motion, &mut c);
            (r, asked)
        }
    }
}

fn run_case<const N: usize, const B: usize, const M: usize>(case: &Case) -> Outcome {
    let mut out = Outcome::default();
    let mut features = 0u128;
    if case.large {
        set(&mut features, bit::LARGE);
    }
    let base = frame::build_config(&case.config, &mut features);
    let policy = build_policy(&case.policy, &mut features);
    let mut f = Box::new(Fusion::<N, B, M>::new(base, policy));
    let mut shadow = f.clone();
    // The model: the last accepted frame, the points that entered the map.
    let mut last: Option<u32> = None;
    // (The model's key frame: its id and serial, the key frames started
    // so far, which a reset does not restart; and the last key frame's
    // reference before it, a stale one to offer.)
    let mut model_key: Option<(u32, u32)> = None;
    let mut started = 0u32;
    let (mut last_seen, mut stale): (Option<KeyRef>, Option<KeyRef>) = (None, None);
    let foreign = foreign_key();
    let mut entered: u64 = 0;
    // The last retirement's rest (`Retired::pending`), until a step reports
    // it (`FusionStep::finished`): a constraint between the two steps
    // enters it into the map before the count says so.
    let mut unreported: u64 = 0;
    // Frames without points paired with the key frame: each may take a
    // partner's place beyond `max_partners` (it cannot be the last
    // partner, `FusionConfig::new`); the partners allowed the key frame
    // shown.
    let mut blank_paired = 0u32;
    let mut allowed = u32::from(policy.max_partners());
    for (n, call) in case.calls.iter().enumerate() {
        let at = |what: &str| format!("call {n} ({what})");
        out.calls += 1;
        match call {
            Call::Reset => {
                f.reset();
                shadow.reset();
                last = None;
                model_key = None;
                entered = 0;
                unreported = 0;
                blank_paired = 0;
                allowed = u32::from(policy.max_partners());
            }
            Call::Step {
                id,
                frame: frame_in,
                motion,
                clock,
            } => {
                let Some(frame) = frame::build_frame::<N, B>(frame_in, &mut features) else {
                    continue;
                };
                let motion = motion.and_then(|(from, m)| {
                    frame::build_motion(&m, &mut features)
                        .map(|motion| ChainedMotion { from, motion })
                });
                let want = expected_step_error(last, *id, motion.as_ref());
                let before = f.digest();
                // The whole state, where an error is due (its `Debug`: the
                // processor, the chain, the policy's counters too), on one
                // call in eight (formatting it makes a case many times
                // slower).
                let whole = (want.is_some() && n % 8 == 0).then(|| format!("{f:?}"));
                let (got, asked) = step(&mut f, *id, &frame, motion.as_ref(), *clock);
                if let Some(k) = clock {
                    assert!(
                        asked <= k + 1,
                        "{}: the clock was asked {asked} times after it said yes at {k}",
                        at("step")
                    );
                }
                match got {
                    Err(e) => {
                        assert_eq!(Some(e), want, "{}: error", at("step"));
                        if let Some(w) = &whole {
                            assert!(
                                format!("{f:?}") == *w,
                                "{}: an error changed the state",
                                at("step")
                            );
                        }
                        assert_eq!(
                            f.digest(),
                            before,
                            "{}: an error changed the state",
                            at("step")
                        );
                        set(&mut features, bit::FUSION_ERR + error_bit(&e));
                    }
                    Ok(s) => {
                        assert_eq!(want, None, "{}: accepted", at("step"));
                        last = Some(*id);
                        let (twin, _) = step(&mut shadow, *id, &frame, motion.as_ref(), *clock);
                        assert_eq!(
                            twin,
                            Ok(s),
                            "{}: the shadow (which saw only the calls that succeeded) differs",
                            at("step")
                        );
                        let cut = clock.is_some_and(|k| asked > k);
                        if s.paired.is_some() {
                            out.reconstructions += 1;
                            assert_eq!(
                                f.deadline_expired(),
                                cut,
                                "{}: the expiry flag",
                                at("step")
                            );
                        } else {
                            assert!(!f.deadline_expired(), "{}: expired, not paired", at("step"));
                        }
                        if cut {
                            set(&mut features, bit::CUT);
                        }
                        let blank = frame.boundaries().iter().all(|b| b.points().is_empty());
                        if s.paired.is_some() && blank {
                            blank_paired += 1;
                            set(&mut features, bit::BLANK_PAIRED);
                        }
                        allowed = u32::from(policy.max_partners()) + blank_paired;
                        entered +=
                            check_step(&f, &s, allowed, &mut out, &mut features, &at("step"));
                        // (A successful step finished the last rest first.)
                        unreported = s.retired.map_or(0, |r| u64::from(r.pending));
                        if s.new_key.is_some() || f.key().is_none() {
                            blank_paired = 0;
                        }
                        if s.new_key.is_some() {
                            started = started.wrapping_add(1);
                            model_key = Some((*id, started));
                        } else if f.key().is_none() {
                            model_key = None;
                        }
                        let now = f.key_ref();
                        if now.is_some() && now != last_seen {
                            stale = last_seen.or(stale);
                            last_seen = now;
                        }
                    }
                }
            }
            Call::Constrain {
                boundary,
                index,
                near,
                far,
                times,
            } => {
                // The reference the caller holds: the key frame's now, or
                // on one call in five the one before (a return for a key
                // frame that has retired, maybe with the same id after a
                // reset), or without either another fusion's.
                let key = match (n % 5 == 4, f.key_ref(), stale) {
                    (true, _, Some(old)) => old,
                    (_, Some(now), _) => now,
                    (_, None, old) => old.unwrap_or(foreign),
                };
                for rep in 0..*times {
                    constrain(
                        &mut f,
                        &mut shadow,
                        (model_key, key),
                        (*boundary, *index, *near, *far),
                        // (The whole state as for a step, on the first.)
                        rep == 0 && n % 8 == 0,
                        &mut features,
                        &at("constrain"),
                    );
                }
            }
        }
        check_state(
            &f,
            allowed,
            (entered, unreported),
            &mut features,
            &at("after"),
        );
        assert_eq!(
            f.digest(),
            shadow.digest(),
            "{}: the shadow's digest differs",
            at("after")
        );
    }
    out.features = features;
    out
}

/// A key frame's reference from another fusion (frame 0, the first key
/// frame it started): what a caller holding none of this fusion's could
/// give.
fn foreign_key() -> KeyRef {
    let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).expect("camera");
    let mut frame = Frame::<4, 1>::new(cam);
    frame
        .push_boundary(&[Pixel::new(100.0, 400.0), Pixel::new(120.0, 380.0)])
        .expect("boundary");
    let mut other = Box::new(Fusion::<4, 1, 4>::new(
        Config::DEFAULT,
        FusionConfig::DEFAULT,
    ));
    other.step(0, &frame, None).expect("key frame");
    other.key_ref().expect("key frame")
}

/// One [`Fusion::constrain`] on `f` and, when it succeeds, on the shadow.
fn constrain<const N: usize, const B: usize, const M: usize>(
    f: &mut Fusion<N, B, M>,
    shadow: &mut Fusion<N, B, M>,
    (model_key, key): (Option<(u32, u32)>, KeyRef),
    (boundary, index, near, far): (usize, usize, f32, f32),
    check_whole: bool,
    features: &mut u128,
    at: &str,
) {
    let valid = near.is_finite() && far.is_finite() && 0.0 <= near && near <= far;
    let kept = f.processor().previous().filter(|_| f.key().is_some());
    // (The model's key frame: the last step that started one.)
    let current = f.key_ref();
    assert_eq!(
        current.map(|k| (k.id(), k.serial())),
        model_key.filter(|_| kept.is_some()),
        "{at}: key_ref"
    );
    assert_eq!(f.key_id(), current.map(|k| k.id()), "{at}: key_id");
    let want = if !valid {
        Some(FusionError::InvalidRange)
    } else {
        match (kept, current) {
            (None, _) | (_, None) => Some(FusionError::NoKeyFrame),
            (Some(_), Some(current)) if current != key => Some(FusionError::KeyMismatch {
                expected: current,
                given: key,
            }),
            (Some(k), Some(_)) => k
                .boundaries()
                .get(boundary)
                .and_then(|b| b.points().get(index))
                .map_or(Some(FusionError::NoSuchPoint), |_| None),
        }
    };
    let before = f.digest();
    let whole = (want.is_some() && check_whole).then(|| format!("{f:?}"));
    match f.constrain(key, boundary, index, near, far) {
        Err(e) => {
            // A far end whose depth overflows is an invalid range too (its
            // depth is `far` over at least 1, rounded up by 10⁻⁶).
            let overflow =
                e == FusionError::InvalidRange && want.is_none() && far > f32::MAX / (1.0 + 1.0e-6);
            assert!(
                Some(e) == want || overflow,
                "{at}: constrain({boundary}, {index}, {near}, {far}): {e:?}, expected {want:?}"
            );
            assert_eq!(f.digest(), before, "{at}: an error changed the state");
            if let Some(w) = &whole {
                assert!(format!("{f:?}") == *w, "{at}: an error changed the state");
            }
            set(features, bit::FUSION_ERR + error_bit(&e));
        }
        Ok(p) => {
            assert_eq!(
                want, None,
                "{at}: constrain({boundary}, {index}, {near}, {far}) accepted"
            );
            set(features, bit::CONSTRAINED);
            assert_eq!(
                f.key().and_then(|k| k.point(boundary, index)),
                Some(p),
                "{at}: the point returned is not the key frame's"
            );
            check_point(&p, at);
            if p.pairs == u8::MAX {
                set(features, bit::SATURATED);
            }
            assert_eq!(
                shadow.constrain(key, boundary, index, near, far),
                Ok(p),
                "{at}: the shadow differs"
            );
        }
    }
}

/// A fused point is well formed: its status as its counts say, its
/// interval finite and ordered.
fn check_point(p: &roadstereo::fusion::FusedPoint, at: &str) {
    assert!(
        p.disagreeing <= p.pairs,
        "{at}: {p:?}: more disagreeing than pairs"
    );
    match p.status {
        FusedStatus::Unmatched => {
            assert!(p.interval.is_none() && p.pairs == 0, "{at}: {p:?}");
        }
        FusedStatus::Single => {
            assert!(
                p.interval.is_some() && p.pairs == 1 && p.disagreeing == 0,
                "{at}: {p:?}"
            );
        }
        FusedStatus::Consistent => {
            assert!(
                p.interval.is_some() && p.pairs >= 2 && p.disagreeing == 0,
                "{at}: {p:?}"
            );
        }
        FusedStatus::Inconsistent => {
            assert!(p.interval.is_some() && p.disagreeing >= 1, "{at}: {p:?}");
        }
        FusedStatus::PartlyUnseen | FusedStatus::Widened => {
            assert!(
                p.interval.is_some() && p.pairs >= 2 && p.disagreeing == 0,
                "{at}: {p:?}"
            );
        }
        // (`FusedStatus` is `#[non_exhaustive]`: a status added later must
        // be given its check here.)
        other => panic!("{at}: a status this check does not know: {other:?}"),
    }
    if let Some(iv) = p.interval {
        // (Finite for every status since the twenty-fourth session's
        // exact rival intervals; an inconsistent point's majority could be
        // a coded interval with an unbounded far end before.)
        assert!(
            iv.z_near.is_finite()
                && iv.z_far.is_finite()
                && 0.0 <= iv.z_near
                && iv.z_near <= iv.z_far,
            "{at}: {p:?}: interval"
        );
    }
}

/// What a successful step says, against the state after it; returns the
/// points that entered the map.
fn check_step<const N: usize, const B: usize, const M: usize>(
    f: &Fusion<N, B, M>,
    s: &FusionStep,
    allowed: u32,
    out: &mut Outcome,
    features: &mut u128,
    at: &str,
) -> u64 {
    assert!(u32::from(s.partner) <= allowed, "{at}: {s:?}: partner");
    if let Some(p) = s.paired {
        assert!(p.conflicts <= p.matched, "{at}: {s:?}: conflicts");
        assert!(p.matched as usize <= N * B, "{at}: {s:?}: matched");
        // (The pair's reconstruction: the key frame's points, each with a
        // result.)
        let paired: usize = f
            .structure()
            .boundaries()
            .iter()
            .map(|b| b.points().len())
            .sum();
        assert!(
            p.matched as usize <= paired,
            "{at}: {s:?}: matched of {paired}"
        );
        out.points[0] += paired as u64;
        out.points[1] += u64::from(p.matched);
        if p.conflicts > 0 {
            set(features, bit::CONFLICT);
        }
    }
    if let Some(r) = s.new_key {
        set(features, bit::NEW_KEY + r as u32);
    }
    // The rest of the last step's retirement (the points it entered are
    // the map's from then on).
    let finished = s.finished.map_or(0, |r| {
        set(features, bit::FINISHED);
        // (A cut retirement counts its unfit points with its rest.)
        if r.unfit > 0 {
            set(features, bit::UNFIT);
        }
        assert!(
            r.unverified == 0 && r.inconsistent == 0 && r.dropped == 0 && r.pending == 0,
            "{at}: {r:?}"
        );
        u64::from(r.entered)
    });
    let Some(r) = s.retired else {
        return finished;
    };
    set(features, bit::RETIRED);
    if r.dropped > 0 {
        set(features, bit::DROPPED_ROOM);
    }
    if r.unfit > 0 {
        set(features, bit::UNFIT);
    }
    if r.unbounded > 0 {
        set(features, bit::UNBOUNDED);
    }
    // The retired key frame's final state is shown until the next step
    // (unless the step's frame had no points to start a new one).
    if let Some(k) = f.key().filter(|k| k.id() == r.key) {
        let total: usize = (0..k.boundaries()).map(|b| k.len(b)).sum();
        let counted = r.entered + r.unverified + r.inconsistent + r.unbounded + r.unfit + r.pending;
        assert_eq!(
            counted as usize, total,
            "{at}: {r:?}: the retired key frame's {total} points not all accounted for"
        );
    }
    finished + u64::from(r.entered)
}

/// The state's invariants.
fn check_state<const N: usize, const B: usize, const M: usize>(
    f: &Fusion<N, B, M>,
    allowed: u32,
    entered: (u64, u64),
    features: &mut u128,
    at: &str,
) {
    if let Some(k) = f.key() {
        assert!(u32::from(k.partners()) <= allowed, "{at}: partners");
        assert!(k.boundaries() <= B, "{at}: boundaries");
        let mut tally = [0u32; 6];
        for b in 0..k.boundaries() {
            assert!(k.len(b) <= N, "{at}: boundary {b} length");
            let mut n = 0;
            for (i, p) in k.points(b).enumerate() {
                check_point(&p, &format!("{at}: key point {b}/{i}"));
                // `key_point`: the same fusion, a ray through the pixel, a
                // finite stick when the interval is bounded.
                if let Some(kp) = f.key_point(b, i) {
                    assert_eq!(kp.fused, p, "{at}: key_point({b}, {i})");
                    assert!(kp.ray[2] == 1.0 && kp.ray[0].is_finite() && kp.ray[1].is_finite());
                    // (Bounded: the far end a finite point, `KeyPoint::stick`.)
                    let bounded = p.interval.is_some_and(|iv| {
                        [kp.ray[0] * iv.z_far, kp.ray[1] * iv.z_far, iv.z_far]
                            .iter()
                            .all(|x| x.is_finite())
                    });
                    match kp.stick() {
                        Some((n, fa)) => assert!(
                            bounded && n.iter().chain(&fa).all(|x| x.is_finite()),
                            "{at}: key_point({b}, {i}) stick {n:?} {fa:?}"
                        ),
                        None => assert!(!bounded, "{at}: key_point({b}, {i}) without a stick"),
                    }
                }
                assert_eq!(k.point(b, i), Some(p), "{at}: point({b}, {i})");
                tally[p.status as usize] += 1;
                set(
                    features,
                    match p.status {
                        FusedStatus::PartlyUnseen => bit::PARTLY_UNSEEN,
                        FusedStatus::Widened => bit::WIDENED,
                        s => bit::STATUS + s as u32,
                    },
                );
                n += 1;
            }
            assert_eq!(n, k.len(b), "{at}: boundary {b}: one point each");
            assert_eq!(k.point(b, n), None, "{at}: a point past the end");
        }
        let c = k.counts();
        assert_eq!(
            [
                c.unmatched,
                c.single,
                c.consistent,
                c.inconsistent,
                c.partly_unseen,
                c.widened
            ],
            tally,
            "{at}: counts"
        );
    }
    let map = f.map();
    assert!(map.batches() <= MAP_BATCHES, "{at}: batches");
    if map.batches() == MAP_BATCHES {
        set(features, bit::FULL_BATCHES);
    }
    for i in 0..map.batches() {
        assert!(map.batch_key(i).is_some(), "{at}: batch {i}");
    }
    assert_eq!(
        map.batch_key(map.batches()),
        None,
        "{at}: a batch past the end"
    );
    let mut stored = 0u64;
    for b in 0..B {
        let len = map.len(b);
        assert!(len <= M, "{at}: map boundary {b} holds {len} > {M}");
        stored += len as u64;
        let mut shown = 0;
        for p in map.points(b) {
            assert!(
                p.near
                    .iter()
                    .chain(&p.far)
                    .chain(&p.ray)
                    .all(|x| x.is_finite())
                    && p.radius.is_finite()
                    && p.radius >= 0.0,
                "{at}: map point {p:?}"
            );
            shown += 1;
        }
        assert!(
            shown <= len,
            "{at}: map boundary {b}: {shown} shown of {len}"
        );
        if shown > 0 {
            set(features, bit::MAP_POINTS);
        }
    }
    let d = map.drops();
    if d.behind > 0 {
        set(features, bit::DROPPED_BEHIND);
    }
    // Exactly what entered, or up to the rest a constraint entered before
    // a step reports it.
    let (entered, unreported) = entered;
    let held = stored + u64::from(d.behind) + u64::from(d.capacity);
    assert!(
        entered <= held && held <= entered + unreported,
        "{at}: the map's points not accounted for ({stored} stored, {d:?}; {entered} entered, {unreported} not reported yet)"
    );
}
