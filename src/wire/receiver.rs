//! The receiver: the decoder plus the pairing of frames with motions and
//! the per-pair configuration.
//!
//! # Pairing
//! A frame is paired with the kept frame (the last frame handed out) when
//! the last motion packet since then goes from the kept frame's id to this
//! frame's id. Otherwise (the motion was lost, or a frame was) the error
//! is reported ([`WireError::MotionMismatch`], [`WireError::MissingMotion`])
//! and the frame starts the pairing anew: its job resets the processor
//! and keeps the frame ([`crate::Step::First`]). A motion packet is used
//! once.
//!
//! # Per-pair configuration
//! The job's [`Config`] is the receiver's base configuration with
//! * `e₁` = the largest localisation-error radius of the kept frame's
//!   boundaries and `e₂` = the largest of this frame's
//!   ([`Config::with_localisation_error`]). The processor's error model is
//!   frame-wide, so a boundary with a smaller radius than another gets the
//!   larger one: its sticks are longer than they need be, never too short.
//! * the motion packet's error bounds, when it has them
//!   ([`Config::with_translation_error`]; [`Config::with_rotation_error`]
//!   with the angles' bounds as their box about the camera's axes,
//!   [`MotionPacket::axis_rotation_error`]); the base configuration's
//!   otherwise.

use super::decode::{FrameInfo, MotionPacket, Packet};
use super::encode::ResultHead;
use super::{DataIds, Decoder, ErrorKind, WireError};
use crate::fusion::{ChainedMotion, Fusion, FusionError, FusionStep};
use crate::math::fmin;
use crate::{Camera, Config, Frame, Motion, ProcessError, Processor, Step};

/// What the receiver counted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Counters {
    /// Bytes fed.
    pub bytes: u32,
    /// Frame jobs handed out.
    pub frames: u32,
    /// Motion packets taken.
    pub motions: u32,
    /// Camera packets taken.
    pub cameras: u32,
    /// Errors reported, indexed like [`ErrorKind::ALL`].
    pub errors: [u32; ErrorKind::ALL.len()],
}

impl Counters {
    /// Errors of `kind`.
    pub fn errors_of(&self, kind: ErrorKind) -> u32 {
        self.errors
            .get(usize::from(kind as u8).saturating_sub(1))
            .copied()
            .unwrap_or(0)
    }
    /// All errors.
    pub fn total_errors(&self) -> u32 {
        self.errors.iter().fold(0u32, |a, &e| a.saturating_add(e))
    }
    /// The counters as a summary packet carries them: bytes, frames,
    /// motions, cameras, then the errors by kind.
    pub fn values(&self) -> [u32; 4 + ErrorKind::ALL.len()] {
        let mut v = [0u32; 4 + ErrorKind::ALL.len()];
        let head = [self.bytes, self.frames, self.motions, self.cameras];
        for (d, s) in v.iter_mut().zip(head.iter().chain(self.errors.iter())) {
            *d = *s;
        }
        v
    }
}

/// A frame ready for the processor: [`FrameJob::run`] it.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameJob<'a, const N: usize, const B: usize> {
    /// The validated frame (in the decoder).
    pub frame: &'a Frame<N, B>,
    /// Its packet's other fields.
    pub info: &'a FrameInfo<B>,
    /// The motion from the kept frame, or `None` when this frame starts the
    /// pairing (the processor is reset).
    pub motion: Option<Motion>,
    /// The configuration for this pair.
    pub config: Config,
    /// The kept frame's id (this frame's own when it starts the pairing).
    pub kept_id: u32,
    /// The kept frame's boundary qualities (what the result reports).
    pub kept_quality: [u8; B],
    /// This frame job's serial, unique among the jobs every receiver of
    /// the program handed out (`next_serial`), and the kept frame's: what
    /// [`Self::run_fused`] chains by, as frame ids need not be unique.
    serial: u32,
    kept_serial: u32,
}

impl<const N: usize, const B: usize> FrameJob<'_, N, B> {
    /// Run the per-frame call on `processor`: set the pair's configuration,
    /// reset first when the pairing starts anew, then
    /// [`Processor::process`].
    ///
    /// Run every job the receiver hands out, in order, on one processor:
    /// the processor pairs the frame with the frame it kept, which is the
    /// job's kept frame only if the previous job ran on it. A job skipped
    /// (or run on another processor) makes the next one pair across the
    /// gap, under a motion that is not theirs, and its sticks are not
    /// guaranteed; after skipping one, [`Processor::reset`] first. (The
    /// processor keeps no frame ids to check it by; [`Self::run_fused`]
    /// checks it.) `run` never refuses a frame: with a motion the
    /// processor has a frame to pair with, without one it was reset.
    pub fn run<'p>(
        &self,
        processor: &'p mut Processor<N, B>,
    ) -> Result<Step<'p, N, B>, ProcessError> {
        self.run_within(processor, &mut crate::deadline::NoDeadline)
    }

    /// [`Self::run`] within the caller's `deadline`
    /// ([`Processor::process_within`]; [`Processor::deadline_expired`]
    /// says afterwards whether it cut the frame short).
    pub fn run_within<'p, D: crate::deadline::Deadline>(
        &self,
        processor: &'p mut Processor<N, B>,
        deadline: &mut D,
    ) -> Result<Step<'p, N, B>, ProcessError> {
        processor.set_config(self.config);
        if self.motion.is_none() {
            processor.reset();
        }
        processor.process_within(self.frame, self.motion.as_ref(), deadline)
    }

    /// Run the frame through a key-frame fusion ([`Fusion::step`]) rather
    /// than pairing it with the last frame: the per-frame motion from the
    /// kept frame chains as [`ChainedMotion`] from [`Self::kept_id`], and
    /// the fusion pairs the frame with its key frame.
    ///
    /// The fusion's error model is fixed when it is made
    /// ([`Fusion::base_config`]), so the job's must fit in it: this frame's
    /// localisation-error radius (the largest of its boundaries) at most
    /// both its `e₁` (the frame may become the key frame) and its `e₂`, and,
    /// where the motion chains on, the motion's error bounds (the packet's,
    /// else the receiver's base configuration's) at most its bounds, per
    /// component. Otherwise
    /// [`FusionError::ErrorsAboveConfig`] and nothing changes: the sticks
    /// would not be guaranteed. Make the fusion with the largest errors the
    /// front end and the odometry declare, the rotation's as the box any
    /// angles give them
    /// ([`crate::motion_error::euler_error_box_any_angles`]: each packet's
    /// angle bounds are compared as their box about the axes, which is
    /// larger than the bounds themselves). A frame whose motion does not
    /// start from the frame the fusion took last, the previous job's of
    /// this receiver (the motion packet was lost, [`Self::motion`] `None`;
    /// the frame before was refused or not run into this fusion, also when
    /// it had the same frame id as the fusion's last frame; the fusion's
    /// last frame came from another receiver; or the fusion's last step
    /// was the caller's own [`Fusion::step`]), resets the fusion first
    /// ([`Fusion::reset`]) and starts it anew: the chain of motions is
    /// broken and the map cannot be carried to this frame. (Frame ids
    /// alone cannot decide: a refused frame with the fusion's last id
    /// would let the next motion chain onto the older frame.) Jobs are
    /// told apart by a serial unique over every receiver
    /// of the program where the target has 32-bit atomics (`thumbv7em`
    /// has); on a target without them, within one receiver only: reset
    /// the fusion before feeding it from a new receiver. Where the chain
    /// holds, the other refusal is the fusion's own
    /// [`FusionError::RepeatedFrame`], a frame with the same id as the one
    /// its motion starts from (the receiver pairs a motion packet from `k`
    /// to `k`); nothing changes, and the next job starts anew. (Where the
    /// chain is broken, such a frame starts the fusion anew as any other.)
    pub fn run_fused<const M: usize>(
        &self,
        fusion: &mut Fusion<N, B, M>,
    ) -> Result<FusionStep, FusionError> {
        self.run_fused_within(fusion, &mut crate::deadline::NoDeadline)
    }

    /// [`Self::run_fused`] within the caller's `deadline`
    /// ([`Fusion::step_within`]).
    pub fn run_fused_within<const M: usize, D: crate::deadline::Deadline>(
        &self,
        fusion: &mut Fusion<N, B, M>,
        deadline: &mut D,
    ) -> Result<FusionStep, FusionError> {
        let chained = self
            .motion
            .map(|motion| ChainedMotion {
                from: self.kept_id,
                motion,
            })
            .filter(|c| {
                fusion.last_frame() == Some(c.from) && fusion.link_serial == Some(self.kept_serial)
            });
        let base = fusion.base_config();
        let radius = self.info.max_radius(self.frame.boundaries().len());
        let mut within = radius <= fmin(base.e1(), base.e2());
        // (A motion the broken chain throws away bounds nothing.)
        if chained.is_some() {
            let (have, allow) = (self.config.rotation_error(), base.rotation_error());
            within &= self.config.translation_error() <= base.translation_error()
                && have.iter().zip(&allow).all(|(h, a)| h <= a);
        }
        if !within {
            return Err(FusionError::ErrorsAboveConfig);
        }
        if chained.is_none() {
            fusion.reset();
        }
        let step =
            fusion.step_within(self.info.frame_id, self.frame, chained.as_ref(), deadline)?;
        fusion.link_serial = Some(self.serial);
        Ok(step)
    }

    /// The result packet's head for this job.
    pub fn result_head(&self, instructions: u32) -> ResultHead {
        ResultHead {
            frame_id: self.info.frame_id,
            kept_id: self.kept_id,
            timestamp_us: self.info.timestamp_us,
            instructions,
        }
    }
}

/// What the receiver hands out, in order.
#[derive(Debug)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event<'a, const N: usize, const B: usize> {
    /// A frame to process.
    Frame(FrameJob<'a, N, B>),
    /// A motion packet was taken.
    Motion(MotionPacket),
    /// A camera packet was taken: the intrinsics the next frames are
    /// seen with (already the decoder's camera).
    Camera(Camera),
    /// A typed error (see [`WireError`]). A damaged stream can give one
    /// for every two bytes (`01 00` repeated is a truncated packet each
    /// time): a firmware that answers each with a packet of its own, as
    /// the `link` firmware's report does, sends more than it receives and
    /// should limit the rate (the receiver's [`Counters`] count them all).
    Error(WireError),
    /// The end of the stream.
    End,
}

#[derive(Debug, Clone, Copy)]
struct Kept<const B: usize> {
    id: u32,
    /// Its place among the frames handed out ([`FrameJob::serial`]).
    serial: u32,
    radius: f32,
    quality: [u8; B],
}

/// The link's receiving end for frames of up to `B` boundaries of `N`
/// points.
pub struct Receiver<const N: usize, const B: usize> {
    decoder: Decoder<N, B>,
    base: Config,
    motion: Option<MotionPacket>,
    kept: Option<Kept<B>>,
    /// The last frame job's serial ([`FrameJob::serial`]).
    serial: u32,
    counters: Counters,
}

/// A summary (the decoder's frame buffer is kilobytes): the decoder's,
/// the configuration, whether a motion and a frame are kept, the counters.
impl<const N: usize, const B: usize> core::fmt::Debug for Receiver<N, B> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Receiver")
            .field("decoder", &self.decoder)
            .field("base", &self.base)
            .field("motion", &self.motion)
            .field("kept_frame", &self.kept.is_some())
            .field("counters", &self.counters)
            .finish()
    }
}

impl<const N: usize, const B: usize> Receiver<N, B> {
    /// A receiver for packets with the data ids `ids`, building each
    /// pair's configuration from `base`.
    pub const fn new(ids: DataIds, base: Config) -> Self {
        Self {
            decoder: Decoder::new(ids),
            base,
            motion: None,
            kept: None,
            serial: 0,
            counters: Counters {
                bytes: 0,
                frames: 0,
                motions: 0,
                cameras: 0,
                errors: [0; ErrorKind::ALL.len()],
            },
        }
    }

    /// What has been counted so far.
    pub fn counters(&self) -> &Counters {
        &self.counters
    }

    /// Feed the next bytes from the link; `on` is called for every event,
    /// in order (a frame job's borrow ends with the call). At most
    /// `input.len()` decoder steps.
    pub fn feed(&mut self, input: &[u8], on: impl FnMut(Event<'_, N, B>)) {
        self.counters.bytes = self
            .counters
            .bytes
            .saturating_add(u32::try_from(input.len()).unwrap_or(u32::MAX));
        self.feed_uncounted(input, on);
    }

    /// [`Self::feed`] without counting the bytes ([`Counters::bytes`]): a
    /// delimiter the link drivers make up after a bus error
    /// (`crate::link`).
    pub(crate) fn feed_uncounted(&mut self, input: &[u8], mut on: impl FnMut(Event<'_, N, B>)) {
        let Self {
            decoder,
            base,
            motion,
            kept,
            serial,
            counters,
        } = self;
        let mut rest = input;
        for _ in 0..input.len() {
            if rest.is_empty() {
                break;
            }
            let (used, out) = decoder.feed(rest);
            rest = rest.get(used..).unwrap_or(&[]);
            let Some(d) = out else { continue };
            if d.missed > 0 {
                report(
                    counters,
                    WireError::CounterJump { missed: d.missed },
                    &mut on,
                );
            }
            match d.packet {
                Err(e) => report(counters, e, &mut on),
                Ok(Packet::Camera(c)) => {
                    counters.cameras = counters.cameras.saturating_add(1);
                    on(Event::Camera(c));
                }
                Ok(Packet::Motion(m)) => {
                    counters.motions = counters.motions.saturating_add(1);
                    *motion = Some(m);
                    on(Event::Motion(m));
                }
                Ok(Packet::End) => on(Event::End),
                Ok(Packet::Frame(frame, info)) => {
                    let count = frame.boundaries().len();
                    let radius = info.max_radius(count);
                    *serial = next_serial(*serial);
                    let mut job = FrameJob {
                        frame,
                        info,
                        motion: None,
                        config: *base,
                        kept_id: info.frame_id,
                        kept_quality: info.quality,
                        serial: *serial,
                        kept_serial: *serial,
                    };
                    // The motion packet since the kept frame, if any: one
                    // that came before it (before the first frame, or
                    // before a frame that started the pairing anew) is
                    // dropped here too. (An adversary's find: a motion
                    // packet sent before the first frame paired the
                    // second.)
                    let since = motion.take();
                    if let Some(k) = *kept {
                        match since {
                            Some(m) if m.from == k.id && m.to == info.frame_id => {
                                match pair_config(base, k.radius, radius, &m) {
                                    Ok(c) => {
                                        job.motion = Some(m.motion);
                                        job.config = c;
                                        job.kept_id = k.id;
                                        job.kept_quality = k.quality;
                                        job.kept_serial = k.serial;
                                    }
                                    Err(e) => report(counters, e, &mut on),
                                }
                            }
                            Some(m) => report(
                                counters,
                                WireError::MotionMismatch {
                                    kept: k.id,
                                    frame: info.frame_id,
                                    from: m.from,
                                    to: m.to,
                                },
                                &mut on,
                            ),
                            None => report(
                                counters,
                                WireError::MissingMotion {
                                    kept: k.id,
                                    frame: info.frame_id,
                                },
                                &mut on,
                            ),
                        }
                    }
                    *kept = Some(Kept {
                        id: info.frame_id,
                        serial: *serial,
                        radius,
                        quality: info.quality,
                    });
                    counters.frames = counters.frames.saturating_add(1);
                    on(Event::Frame(job));
                }
            }
        }
    }
}

/// The frame jobs handed out by every receiver of the program, where the
/// target has 32-bit atomics: a job's serial is unique among them, so a
/// fusion fed by two receivers, or by a new one after a link restart,
/// chains no job onto another receiver's frame (a review's find, when
/// each receiver counted from 1). (Wrapping: two jobs 2³² apart share a
/// serial; chaining also needs their frame ids to match.)
#[cfg(target_has_atomic = "32")]
static JOB_SERIALS: core::sync::atomic::AtomicU32 = core::sync::atomic::AtomicU32::new(0);

/// The next frame job's serial ([`FrameJob::serial`]) after `last`, this
/// receiver's last: from [`JOB_SERIALS`] where the target has 32-bit
/// atomics, else `last + 1` (then unique within one receiver only: a
/// fusion fed by a new receiver must be reset first, [`FrameJob::run_fused`]).
fn next_serial(last: u32) -> u32 {
    #[cfg(target_has_atomic = "32")]
    {
        let _ = last;
        JOB_SERIALS
            .fetch_add(1, core::sync::atomic::Ordering::Relaxed)
            .wrapping_add(1)
    }
    #[cfg(not(target_has_atomic = "32"))]
    {
        last.wrapping_add(1)
    }
}

/// Count `e` and hand it out.
fn report<const N: usize, const B: usize>(
    counters: &mut Counters,
    e: WireError,
    on: &mut impl FnMut(Event<'_, N, B>),
) {
    let i = usize::from(e.kind() as u8).saturating_sub(1);
    if let Some(c) = counters.errors.get_mut(i) {
        *c = c.saturating_add(1);
    }
    on(Event::Error(e));
}

/// The configuration for a pair: `base` with the two frames' radii and the
/// motion's error bounds.
fn pair_config(base: &Config, e1: f32, e2: f32, m: &MotionPacket) -> Result<Config, WireError> {
    let mut c = base
        .with_localisation_error(e1, e2)
        .map_err(|_| WireError::Radius { boundary: 0 })?;
    if let Some(t) = m.translation_error {
        c = c
            .with_translation_error(t)
            .map_err(WireError::MotionBounds)?;
    }
    if m.rotation_error.is_some() {
        // The angles' bounds as a box about the camera's axes (the decoder
        // has checked it; an infinite box is refused here too).
        let r = m.axis_rotation_error().unwrap_or([f32::INFINITY; 3]);
        c = c.with_rotation_error(r).map_err(WireError::MotionBounds)?;
    }
    Ok(c)
}
