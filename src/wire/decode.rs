//! The byte-fed streaming decoder.
//!
//! COBS framing is the `cobs` crate's [`DecoderState`] state machine: it
//! reads every code byte and delimiter, and its run counter says how many
//! data bytes follow, which are then taken as one slice. A run's bytes
//! are the decoded bytes, and none may be zero (a zero is the delimiter):
//! one pass over the run tests for a zero, updates the CRC register (the
//! `crc` crate's CRC-32/AUTOSAR table, a word at a time) and parses. A
//! frame's points are checked in that same pass, a word each, and written
//! straight into the decoder's [`Frame`]; nothing is copied in between.
//!
//! # Bounds
//! [`Decoder::feed`] does constant work per input byte and returns after
//! at most `input.len()` bytes; nothing is buffered but one packet's
//! fixed-size sections (at most [`MOTION_LEN`] bytes) and a partial point.

use cobs::{DecodeResult, DecoderState};

use super::{
    raw_to_px, raw_to_radius, DataIds, PacketType, WireError, BOUNDARY_HEAD_LEN, CAMERA_LEN, CRC,
    CRC_LEN, FRAME_HEAD_LEN, HEADER_LEN, MAGIC, MOTION_LEN, POINT_LEN, RESIDUE, VERSION,
};
use crate::motion_error::euler_error_box;
use crate::{Camera, Config, Frame, Motion, Pixel};

/// A frame packet's fields other than the points.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameInfo<const B: usize> {
    /// Exposure timestamp, microseconds.
    pub timestamp_us: u64,
    /// Frame id.
    pub frame_id: u32,
    /// The packet's counter.
    pub counter: u16,
    /// Quality of each boundary (index as in the frame).
    pub quality: [u8; B],
    /// Localisation-error radius of each boundary, pixels (0 for an
    /// absent one, whatever the packet said).
    pub radius_px: [f32; B],
}

impl<const B: usize> FrameInfo<B> {
    const EMPTY: Self = Self {
        timestamp_us: 0,
        frame_id: 0,
        counter: 0,
        quality: [0; B],
        radius_px: [0.0; B],
    };

    /// The largest radius over the first `count` boundaries (0 for none).
    pub fn max_radius(&self, count: usize) -> f32 {
        self.radius_px
            .iter()
            .take(count)
            .fold(0.0, |m, &r| crate::math::fmax(m, r))
    }
}

/// A decoded motion packet.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MotionPacket {
    /// Frame id of the first frame.
    pub from: u32,
    /// Frame id of the second frame.
    pub to: u32,
    /// The validated motion.
    pub motion: Motion,
    /// Bound on each translation component's error (validated for
    /// [`Config::with_translation_error`]).
    pub translation_error: Option<f32>,
    /// Bounds on the errors of the rotation angles `(α, β, γ)` as sent
    /// (radians, the angles of [`Motion::new`]). The pair's configuration
    /// takes their box about the camera's axes,
    /// [`MotionPacket::axis_rotation_error`], which the decoder checks
    /// with [`Config::with_rotation_error`].
    pub rotation_error: Option<[f32; 3]>,
    /// The packet's counter.
    pub counter: u16,
}

impl MotionPacket {
    /// The rotation error bounds about the frame-2 camera's axes, as
    /// [`Config::with_rotation_error`] takes them: the box
    /// [`crate::motion_error::euler_error_box`] gives for
    /// [`Self::rotation_error`] at the packet's angles (an error in `α`
    /// alone reaches the `y` axis when `γ ≠ 0`, so the angles' bounds
    /// cannot be used as they are). `None` when the packet gives none.
    pub fn axis_rotation_error(&self) -> Option<[f32; 3]> {
        // The motion's angles were validated by `Motion::new`, so the box
        // exists; `None` otherwise, which the decoder refuses.
        self.rotation_error
            .and_then(|r| euler_error_box(self.motion.angles(), r).ok())
    }
}

/// One complete packet.
#[derive(Debug)]
pub enum Packet<'a, const N: usize, const B: usize> {
    /// A frame: validated boundaries in the decoder's frame (valid until
    /// the next [`Decoder::feed`]).
    Frame(&'a Frame<N, B>, &'a FrameInfo<B>),
    /// A motion.
    Motion(MotionPacket),
    /// Camera intrinsics (already made the decoder's camera).
    Camera(Camera),
    /// End of the stream.
    End,
}

/// What one packet gave: the packet or why it was not taken, and how
/// many packets of its data id were lost before it (for an intact packet
/// with the right data id; 0 otherwise).
#[derive(Debug)]
pub struct Decoded<'a, const N: usize, const B: usize> {
    /// Counters skipped before this packet.
    pub missed: u16,
    /// The packet, or the error.
    pub packet: Result<Packet<'a, N, B>, WireError>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Section {
    Header,
    FrameHead,
    BoundaryHead,
    Motion,
    Camera,
}

impl Section {
    const fn len(self) -> usize {
        match self {
            Self::Header => HEADER_LEN,
            Self::FrameHead => FRAME_HEAD_LEN,
            Self::BoundaryHead => BOUNDARY_HEAD_LEN,
            Self::Motion => MOTION_LEN,
            Self::Camera => CAMERA_LEN,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Collecting a fixed-size section.
    Small(Section),
    /// A boundary's points.
    Points,
    /// The payload is complete: the CRC (and anything after it).
    Trailer,
    /// The packet is bad: count and CRC the rest.
    Skip,
}

/// Input packet types, for the counters.
const INPUTS: usize = 4;

fn input_slot(t: PacketType) -> Option<usize> {
    match t {
        PacketType::Frame => Some(0),
        PacketType::Motion => Some(1),
        PacketType::Camera => Some(2),
        PacketType::End => Some(3),
        _ => None,
    }
}

/// The order and range checks' state along one boundary's points.
struct PointRun {
    /// Largest `raw − 0x0101` for `u` and `v`.
    limits: (u32, u32),
    /// The previous point, raw (`u` in the low half, `v` in the high).
    prev: u32,
    /// The last row step (0 before the second point).
    step: i32,
    /// Index of the next point.
    index: usize,
}

impl PointRun {
    /// One point with every check (the first two of a boundary, where the
    /// row direction is not known yet).
    #[inline(always)]
    fn check(&mut self, w: u32) -> Result<(), crate::BoundaryError> {
        use crate::BoundaryError as E;
        let index = self.index;
        let base = u32::from(super::RAW_MINUS_ONE_PX);
        let (u, v) = (w & 0xFFFF, w >> 16);
        if u.wrapping_sub(base) > self.limits.0 || v.wrapping_sub(base) > self.limits.1 {
            return Err(E::OutsideImage { index });
        }
        if index > 0 {
            if w == self.prev {
                return Err(E::Duplicate { index });
            }
            let dv = v as i32 - (self.prev >> 16) as i32;
            if dv == 0 || (self.step != 0 && (dv ^ self.step) < 0) {
                return Err(E::Unordered { index });
            }
            self.step = dv;
        }
        self.prev = w;
        self.index = index + 1;
        Ok(())
    }
}

/// The CRC register's value at the start of a packet. CRC-32/AUTOSAR is
/// reflected: the register holds the reflected remainder, shifts right,
/// and takes each byte at its low end (the `crc` crate's table).
const CRC_INIT: u32 = crc::CRC_32_AUTOSAR.init.reverse_bits();
const _: () = assert!(
    crc::CRC_32_AUTOSAR.refin && crc::CRC_32_AUTOSAR.refout && crc::CRC_32_AUTOSAR.width == 32
);

/// The `crc` crate's table for [`CRC`] (one 256-entry lane).
#[inline(always)]
fn crc_table() -> &'static [u32; 256] {
    let [t] = CRC.table();
    t
}

/// The register after one more byte entered its low end.
#[inline(always)]
fn crc_shift(t: &[u32; 256], c: u32) -> u32 {
    t.get((c & 0xFF) as usize).copied().unwrap_or(0) ^ (c >> 8)
}

/// The register after byte `b`.
#[inline(always)]
fn crc_byte(t: &[u32; 256], c: u32, b: u8) -> u32 {
    crc_shift(t, c ^ u32::from(b))
}

/// The register after the four bytes of `w` (little endian).
#[inline(always)]
fn crc_word(t: &[u32; 256], c: u32, w: u32) -> u32 {
    crc_shift(t, crc_shift(t, crc_shift(t, crc_shift(t, c ^ w))))
}

/// Non-zero iff one of the four bytes of `w` is zero; then its lowest set
/// bit is bit 7 of the first zero byte (the bits above it may be wrong).
#[inline(always)]
fn zero_bytes(w: u32) -> u32 {
    w.wrapping_sub(0x0101_0101) & !w & 0x8080_8080
}

/// The register after `s`, bytes of a COBS run; `Err(z)`: a zero byte (a
/// delimiter) at `z`, where the run ends.
#[inline(always)]
fn crc_run(mut c: u32, s: &[u8]) -> Result<u32, usize> {
    let t = crc_table();
    let (words, tail) = s.as_chunks::<4>();
    for (i, w) in words.iter().enumerate() {
        let w = u32::from_le_bytes(*w);
        let z = zero_bytes(w);
        if z != 0 {
            return Err(4 * i + (z.trailing_zeros() / 8) as usize);
        }
        c = crc_word(t, c, w);
    }
    for (i, &b) in tail.iter().enumerate() {
        if b == 0 {
            return Err(4 * words.len() + i);
        }
        c = crc_byte(t, c, b);
    }
    Ok(c)
}

/// A point's pixel from its raw word (`u` low, `v` high).
#[inline(always)]
fn pixel(w: u32) -> Pixel {
    Pixel::new(raw_to_px(w as u16), raw_to_px((w >> 16) as u16))
}

/// The lean loop over whole points once the row direction is known
/// (`UP`: `v` grows): every check of [`PointRun::check`] on the raw word
/// (inside the image with its margin, a row step of the boundary's sign,
/// which excludes duplicates), no zero byte (a delimiter) and the CRC,
/// each point stored as its pixel. `pv` is the previous point's raw `v`.
/// Stops before the first point that fails any test; gives how many it
/// took and the register. (Not inlined: inside the decoder's dispatch
/// its loop lacked registers, rematerialising the table's address and
/// reloading the limits each point.)
#[inline(never)]
fn lean<const UP: bool>(
    words: &[[u8; POINT_LEN]],
    dst: &mut [Pixel],
    limits: (u32, u32),
    mut crc: u32,
    mut pv: u32,
) -> (usize, u32) {
    let t = crc_table();
    let base = u32::from(super::RAW_MINUS_ONE_PX);
    let (umax, vmax) = limits;
    let mut taken = 0usize;
    for (d, c) in dst.iter_mut().zip(words) {
        let w = u32::from_le_bytes(*c);
        let (u, v) = (w & 0xFFFF, w >> 16);
        // (|v − pv| < 2^16: the difference as i32 is exact.)
        let step = if UP {
            v.wrapping_sub(pv)
        } else {
            pv.wrapping_sub(v)
        } as i32;
        // A zero high byte puts `u` or `v` below 0x0101, outside: only
        // the low bytes need the zero test here.
        if u.wrapping_sub(base) > umax
            || v.wrapping_sub(base) > vmax
            || step <= 0
            || w & 0xFF == 0
            || w & 0xFF_0000 == 0
        {
            break;
        }
        crc = crc_word(t, crc, w);
        *d = pixel(w);
        pv = v;
        taken += 1;
    }
    (taken, crc)
}

fn le16(b: &[u8], at: usize) -> u16 {
    match b.get(at..at + 2) {
        Some(&[x, y]) => u16::from_le_bytes([x, y]),
        _ => 0,
    }
}
fn le32(b: &[u8], at: usize) -> u32 {
    match b.get(at..at + 4) {
        Some(&[a, c, d, e]) => u32::from_le_bytes([a, c, d, e]),
        _ => 0,
    }
}
fn lef32(b: &[u8], at: usize) -> f32 {
    f32::from_bits(le32(b, at))
}

/// The streaming decoder for frames of up to `B` boundaries of `N` points
/// (see the module docs of [`crate::wire`] for the format).
///
/// ```
/// use roadstereo::wire::{encode, DataIds, Decoder, Packet};
/// use roadstereo::Camera;
/// let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap();
/// let (mut raw, mut link) = ([0u8; 64], [0u8; 80]);
/// let n = encode::camera(&mut raw, DataIds::DEFAULT.camera, 0, &cam).unwrap();
/// let n = encode::cobs_frame(&raw[..n], &mut link).unwrap();
/// let mut d = Decoder::<16, 2>::new(DataIds::DEFAULT);
/// // Any chunking: here the first 5 bytes, then the rest.
/// assert!(d.feed(&link[..5]).1.is_none());
/// let (used, out) = d.feed(&link[5..n]);
/// assert_eq!(used, n - 5);
/// assert!(matches!(out.unwrap().packet, Ok(Packet::Camera(c)) if c == cam));
/// ```
pub struct Decoder<const N: usize, const B: usize> {
    ids: DataIds,
    cobs: DecoderState,
    /// The CRC register ([`CRC_INIT`] at a packet's start).
    crc: u32,
    /// Bytes decoded in the current packet (saturating).
    pos: u32,
    state: State,
    /// The header's fields.
    ptype: Option<PacketType>,
    data_id: u16,
    counter: u16,
    declared: u32,
    /// Magic, version or type wrong (reported after the CRC).
    header_fault: Option<WireError>,
    /// The first content fault (reported after the CRC).
    fault: Option<WireError>,
    small: [u8; MOTION_LEN],
    small_len: usize,
    /// Last accepted counter per input type.
    last: [Option<u16>; INPUTS],
    camera: Option<Camera>,
    new_camera: Option<Camera>,
    motion: Option<MotionPacket>,
    frame: Frame<N, B>,
    info: FrameInfo<B>,
    boundaries: usize,
    boundary: usize,
    points: usize,
    done: usize,
    carry: [u8; POINT_LEN],
    carry_len: usize,
    /// Largest raw `u` and `v` inside the image with its margin.
    limits: (u32, u32),
    /// The previous point (raw, `v` high) and the last row step, for the
    /// order checks.
    prev: u32,
    step: i32,
}

/// A summary (the frame buffer being filled is kilobytes): the data ids,
/// where the decoder is in a packet, the camera and the motion it holds.
impl<const N: usize, const B: usize> core::fmt::Debug for Decoder<N, B> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Decoder")
            .field("ids", &self.ids)
            .field("state", &self.state)
            .field("packet_type", &self.ptype)
            .field("bytes_in_packet", &self.pos)
            .field("camera", &self.camera)
            .field("motion", &self.motion)
            .field("boundaries_done", &self.boundary)
            .finish_non_exhaustive()
    }
}

impl<const N: usize, const B: usize> Decoder<N, B> {
    /// A decoder that takes packets with the data ids `ids`, with no camera
    /// yet (frames need a camera packet first).
    pub const fn new(ids: DataIds) -> Self {
        Self {
            ids,
            cobs: DecoderState::Idle,
            crc: CRC_INIT,
            pos: 0,
            state: State::Skip,
            ptype: None,
            data_id: 0,
            counter: 0,
            declared: 0,
            header_fault: None,
            fault: None,
            small: [0; MOTION_LEN],
            small_len: 0,
            last: [None; INPUTS],
            camera: None,
            new_camera: None,
            motion: None,
            frame: Frame::new(Camera::PLACEHOLDER),
            info: FrameInfo::EMPTY,
            boundaries: 0,
            boundary: 0,
            points: 0,
            done: 0,
            carry: [0; POINT_LEN],
            carry_len: 0,
            limits: (0, 0),
            prev: 0,
            step: 0,
        }
    }

    /// The camera frames are checked against (from the last camera packet).
    pub fn camera(&self) -> Option<&Camera> {
        self.camera.as_ref()
    }

    /// Feed the next bytes from the link. Returns how many were used and,
    /// when a packet ended among them, what it gave; call again with the
    /// rest. Garbage before a packet is reported as one error at the next
    /// delimiter, after which decoding resumes in step.
    pub fn feed(&mut self, input: &[u8]) -> (usize, Option<Decoded<'_, N, B>>) {
        let mut used = 0usize;
        let mut rest = input;
        while let Some((&byte, after)) = rest.split_first() {
            // A run of data bytes: take as many as arrived, in one slice.
            let run = match self.cobs {
                DecoderState::Grab(k) | DecoderState::GrabChain(k) => k,
                DecoderState::Idle => 0,
            };
            if run > 0 {
                let take = usize::from(run).min(rest.len());
                let Some((chunk, after_chunk)) = rest.split_at_checked(take) else {
                    break;
                };
                let at = self.pos;
                if let Some(z) = self.run(chunk) {
                    // A delimiter inside a run: the packet was cut short.
                    used += z + 1;
                    self.cobs = DecoderState::Idle;
                    let len = at.saturating_add(z as u32);
                    return (used, Some(self.fail(WireError::Truncated { len })));
                }
                let left = run - take as u8;
                self.cobs = match self.cobs {
                    DecoderState::GrabChain(_) => DecoderState::GrabChain(left),
                    _ => DecoderState::Grab(left),
                };
                used += take;
                rest = after_chunk;
                continue;
            }
            used += 1;
            rest = after;
            match self.cobs.feed(byte) {
                Ok(DecodeResult::NoData) => {}
                Ok(DecodeResult::DataStart) => self.start(),
                Ok(DecodeResult::DataContinue(b)) => self.decoded(b),
                Ok(DecodeResult::DataComplete) => return (used, Some(self.finish())),
                Err(_) => {
                    let len = self.pos;
                    return (used, Some(self.fail(WireError::Truncated { len })));
                }
            }
        }
        (used, None)
    }

    fn fail(&mut self, e: WireError) -> Decoded<'_, N, B> {
        self.state = State::Skip;
        Decoded {
            missed: 0,
            packet: Err(e),
        }
    }

    /// A packet begins.
    fn start(&mut self) {
        self.crc = CRC_INIT;
        self.pos = 0;
        self.state = State::Small(Section::Header);
        self.small_len = 0;
        self.ptype = None;
        self.header_fault = None;
        self.fault = None;
        self.new_camera = None;
        self.motion = None;
        self.carry_len = 0;
    }

    /// The bytes of a COBS run (as sent: they are the decoded bytes, and a
    /// zero among them is a delimiter) through the zero test, the CRC
    /// register and the parser, each state taking what it can in one
    /// pass. `Some(z)`: a zero at `z` (the run, and the packet, end there;
    /// the bytes before it were taken).
    fn run(&mut self, chunk: &[u8]) -> Option<usize> {
        let mut s = chunk;
        while !s.is_empty() {
            let at = chunk.len() - s.len();
            let taken = match self.state {
                State::Small(section) => self.small(section, s),
                State::Points => self.points(s),
                State::Trailer | State::Skip => match crc_run(self.crc, s) {
                    Ok(c) => {
                        self.crc = c;
                        self.advance(s.len());
                        Ok(&[][..])
                    }
                    Err(z) => Err(z),
                },
            };
            let rest = match taken {
                Ok(rest) => rest,
                Err(z) => return Some(at + z),
            };
            // (Every pass takes at least one byte.)
            if rest.len() >= s.len() {
                break;
            }
            s = rest;
        }
        None
    }

    /// The zero byte COBS decodes at the end of a run (a code byte).
    fn decoded(&mut self, b: u8) {
        self.crc = crc_byte(crc_table(), self.crc, b);
        match self.state {
            State::Small(section) => {
                if let Some(d) = self.small.get_mut(self.small_len) {
                    *d = b;
                }
                self.small_len += 1;
                self.advance(1);
                if self.small_len >= section.len() {
                    self.section_done(section);
                }
            }
            State::Points => {
                self.carry(b);
            }
            State::Trailer | State::Skip => self.advance(1),
        }
    }

    fn advance(&mut self, n: usize) {
        self.pos = self
            .pos
            .saturating_add(u32::try_from(n).unwrap_or(u32::MAX));
    }

    fn payload_end(&self) -> u32 {
        HEADER_LEN as u32 + self.declared
    }

    /// Record a content fault and skip the rest.
    fn fault(&mut self, e: WireError) {
        if self.fault.is_none() {
            self.fault = Some(e);
        }
        self.state = State::Skip;
    }

    /// Go on with a fixed-size section, if the payload holds it.
    fn expect(&mut self, section: Section) {
        let end = self.pos.saturating_add(section.len() as u32);
        if end > self.payload_end() {
            let actual = end - HEADER_LEN as u32;
            self.fault(WireError::BadLength {
                declared: self.declared,
                actual,
            });
        } else {
            self.small_len = 0;
            self.state = State::Small(section);
        }
    }

    /// The payload's content is complete: it must fill the payload.
    fn content_done(&mut self) {
        if self.pos != self.payload_end() {
            let actual = self.pos.saturating_sub(HEADER_LEN as u32);
            self.fault(WireError::BadLength {
                declared: self.declared,
                actual,
            });
        } else {
            self.state = State::Trailer;
        }
    }

    /// Bytes of a run into a fixed-size section.
    fn small<'s>(&mut self, section: Section, s: &'s [u8]) -> Result<&'s [u8], usize> {
        let need = section.len();
        let take = need.saturating_sub(self.small_len).min(s.len());
        let (head, tail) = s.split_at_checked(take).unwrap_or((s, &[]));
        self.crc = crc_run(self.crc, head)?;
        if let Some(dst) = self.small.get_mut(self.small_len..self.small_len + take) {
            for (d, b) in dst.iter_mut().zip(head) {
                *d = *b;
            }
        }
        self.small_len += take;
        self.advance(take);
        if self.small_len >= need {
            self.section_done(section);
        }
        Ok(tail)
    }

    fn section_done(&mut self, section: Section) {
        let b = self.small;
        match section {
            Section::Header => self.header(&b),
            Section::FrameHead => self.frame_head(&b),
            Section::BoundaryHead => self.boundary_head(&b),
            Section::Motion => self.motion_body(&b),
            Section::Camera => self.camera_body(&b),
        }
    }

    fn header(&mut self, b: &[u8]) {
        self.data_id = le16(b, 4);
        self.counter = le16(b, 6);
        self.declared = u32::from(le16(b, 8));
        let (magic, version, code) = (b.get(..2), b.get(2).copied(), b.get(3).copied());
        let header_fault = if magic != Some(&MAGIC[..]) {
            Some(WireError::BadMagic)
        } else if version != Some(VERSION) {
            Some(WireError::UnknownVersion {
                version: version.unwrap_or(0),
            })
        } else {
            let code = code.unwrap_or(0);
            match PacketType::from_code(code).filter(|t| input_slot(*t).is_some()) {
                None => Some(WireError::UnknownType { code }),
                Some(t) => {
                    self.ptype = Some(t);
                    None
                }
            }
        };
        if header_fault.is_some() {
            self.header_fault = header_fault;
            self.state = State::Skip;
            return;
        }
        match self.ptype {
            Some(PacketType::Frame) => self.expect(Section::FrameHead),
            Some(PacketType::Motion) => self.expect(Section::Motion),
            Some(PacketType::Camera) => self.expect(Section::Camera),
            _ => self.content_done(),
        }
    }

    fn frame_head(&mut self, b: &[u8]) {
        let ts = u64::from(le32(b, 0)) | (u64::from(le32(b, 4)) << 32);
        let (id, w, h) = (le32(b, 8), le16(b, 12), le16(b, 14));
        let nb = b.get(16).copied().unwrap_or(0);
        let Some(camera) = self.camera else {
            return self.fault(WireError::NoCamera);
        };
        if (w, h) != (camera.width(), camera.height()) {
            return self.fault(WireError::ImageSize {
                width: w,
                height: h,
            });
        }
        if usize::from(nb) > B {
            return self.fault(WireError::TooManyBoundaries {
                count: nb,
                capacity: u8::try_from(B).unwrap_or(u8::MAX),
            });
        }
        self.frame.restart(camera);
        // −1 ≤ u = (raw − 0x0101) / 16 − 1 ≤ width ⇔
        // 0 ≤ raw − 0x0101 ≤ 16 (width + 1) (exact; below 0 it wraps).
        self.limits = (
            16 * (u32::from(camera.width()) + 1),
            16 * (u32::from(camera.height()) + 1),
        );
        self.info = FrameInfo {
            timestamp_us: ts,
            frame_id: id,
            counter: self.counter,
            ..FrameInfo::EMPTY
        };
        self.boundaries = usize::from(nb);
        self.boundary = 0;
        if nb == 0 {
            self.content_done();
        } else {
            self.expect(Section::BoundaryHead);
        }
    }

    fn boundary_head(&mut self, b: &[u8]) {
        let k = self.boundary;
        let kb = u8::try_from(k).unwrap_or(u8::MAX);
        let (index, quality, radius, n) = (
            b.first().copied().unwrap_or(0),
            b.get(1).copied().unwrap_or(0),
            le16(b, 2),
            le16(b, 4),
        );
        if usize::from(index) != k {
            return self.fault(WireError::BoundaryIndex {
                expected: kb,
                got: index,
            });
        }
        if n == 0 {
            // An absent boundary (`Frame::push_absent`): its quality kept,
            // its radius ignored, unchecked (0, so that it widens no pair's
            // error).
            if let Some(q) = self.info.quality.get_mut(k) {
                *q = quality;
            }
            if let Some(r) = self.info.radius_px.get_mut(k) {
                *r = 0.0;
            }
            self.points = 0;
            return self.boundary_done();
        }
        let radius = raw_to_radius(radius);
        if radius > super::MAX_RADIUS_PX {
            return self.fault(WireError::Radius { boundary: kb });
        }
        if usize::from(n) > N {
            return self.fault(WireError::TooManyPoints {
                boundary: kb,
                len: n,
                capacity: u16::try_from(N).unwrap_or(u16::MAX),
            });
        }
        if n < 2 {
            return self.fault(WireError::Boundary {
                boundary: kb,
                error: crate::BoundaryError::TooFewPoints,
            });
        }
        let end = self.pos.saturating_add(u32::from(n) * POINT_LEN as u32);
        if end > self.payload_end() {
            return self.fault(WireError::BadLength {
                declared: self.declared,
                actual: end - HEADER_LEN as u32,
            });
        }
        if let Some(q) = self.info.quality.get_mut(k) {
            *q = quality;
        }
        if let Some(r) = self.info.radius_px.get_mut(k) {
            *r = radius;
        }
        self.points = usize::from(n);
        self.done = 0;
        self.carry_len = 0;
        self.step = 0;
        self.state = State::Points;
    }

    /// Points of the current boundary from a run: whole points straight
    /// into the frame's slot (once the row direction is known, in the lean
    /// loop), the first two of a boundary and a point split between runs
    /// or feeds byte by byte through the carry.
    fn points<'s>(&mut self, s: &'s [u8]) -> Result<&'s [u8], usize> {
        if self.carry_len == 0 && self.done >= 2 && s.len() >= POINT_LEN {
            return self.whole_points(s);
        }
        // At most one point's bytes.
        let mut s = s;
        let mut at = 0;
        while let Some((&b, rest)) = s.split_first() {
            if b == 0 {
                return Err(at);
            }
            self.crc = crc_byte(crc_table(), self.crc, b);
            s = rest;
            at += 1;
            if self.carry(b) {
                break;
            }
        }
        Ok(s)
    }

    /// One byte of a point (already through the CRC); `true` when it
    /// completed the point.
    fn carry(&mut self, b: u8) -> bool {
        if let Some(c) = self.carry.get_mut(self.carry_len) {
            *c = b;
        }
        self.carry_len += 1;
        self.advance(1);
        if self.carry_len < POINT_LEN {
            return false;
        }
        self.carry_len = 0;
        self.point(u32::from_le_bytes(self.carry));
        true
    }

    /// One point (already through the CRC) with the careful check, which
    /// names the error.
    fn point(&mut self, w: u32) {
        let done = self.done;
        let mut run = PointRun {
            limits: self.limits,
            prev: self.prev,
            step: self.step,
            index: done,
        };
        let checked = run.check(w);
        self.prev = run.prev;
        self.step = run.step;
        self.done = done + 1;
        match checked {
            Ok(()) => {
                if let Some(d) = self.frame.next_storage().and_then(|p| p.get_mut(done)) {
                    *d = pixel(w);
                }
                if self.done >= self.points {
                    self.boundary_done();
                }
            }
            Err(error) => self.fault(WireError::Boundary {
                boundary: u8::try_from(self.boundary).unwrap_or(u8::MAX),
                error,
            }),
        }
    }

    /// Whole points of a run (at least one; the row direction known):
    /// the lean loop, then the careful check of a point it did not take.
    /// The checks are [`crate::Frame::push_boundary`]'s, done on the raw
    /// values, in the same order, with the same errors: every point is
    /// finite by construction; `u` is inside `[−1, width]` iff
    /// `raw − 0x0101` is in `[0, 16 (width + 1)]` (the conversion is
    /// exact); equal raw points are equal pixels; a row step's sign is the
    /// raw step's.
    fn whole_points<'s>(&mut self, s: &'s [u8]) -> Result<&'s [u8], usize> {
        let done = self.done;
        let n = self.points.saturating_sub(done).min(s.len() / POINT_LEN);
        let (words, _) = s.as_chunks::<POINT_LEN>();
        let words = words.get(..n).unwrap_or(&[]);
        let Some(dst) = self
            .frame
            .next_storage()
            .and_then(|p| p.get_mut(done..done + words.len()))
        else {
            // (Not reached: the frame head admits at most `B` boundaries.)
            // Taken unstored; `boundary_done` reports the full frame.
            let len = words.len() * POINT_LEN;
            let (body, rest) = s.split_at_checked(len).unwrap_or((s, &[]));
            self.crc = crc_run(self.crc, body)?;
            self.advance(len);
            self.done = done + words.len();
            if self.done >= self.points {
                self.boundary_done();
            }
            return Ok(rest);
        };
        let pv = self.prev >> 16;
        let (taken, crc) = if self.step > 0 {
            lean::<true>(words, dst, self.limits, self.crc, pv)
        } else {
            lean::<false>(words, dst, self.limits, self.crc, pv)
        };
        self.crc = crc;
        if let Some(c) = taken.checked_sub(1).and_then(|i| words.get(i)) {
            self.prev = u32::from_le_bytes(*c);
        }
        self.done = done + taken;
        self.advance(taken * POINT_LEN);
        let mut end = taken;
        if let Some(c) = words.get(taken) {
            let w = u32::from_le_bytes(*c);
            let z = zero_bytes(w);
            if z != 0 {
                return Err(taken * POINT_LEN + (z.trailing_zeros() / 8) as usize);
            }
            self.crc = crc_word(crc_table(), self.crc, w);
            self.advance(POINT_LEN);
            self.point(w);
            end += 1;
        } else if self.done >= self.points {
            self.boundary_done();
        }
        Ok(s.get(end * POINT_LEN..).unwrap_or(&[]))
    }

    fn boundary_done(&mut self) {
        let k = self.boundary;
        if !self.frame.commit_next_validated(self.points) {
            return self.fault(WireError::TooManyBoundaries {
                count: u8::try_from(k + 1).unwrap_or(u8::MAX),
                capacity: u8::try_from(B).unwrap_or(u8::MAX),
            });
        }
        self.boundary = k + 1;
        if self.boundary < self.boundaries {
            self.expect(Section::BoundaryHead);
        } else {
            self.content_done();
        }
    }

    fn motion_body(&mut self, b: &[u8]) {
        let f = |i: usize| lef32(b, 8 + 4 * i);
        let motion = match Motion::new([f(0), f(1), f(2)], [f(3), f(4), f(5)]) {
            Ok(m) => m,
            Err(e) => return self.fault(WireError::Motion(e)),
        };
        let flags = b.get(32).copied().unwrap_or(0);
        let te = (flags & 1 != 0).then(|| lef32(b, 36));
        let re = (flags & 2 != 0).then(|| [lef32(b, 40), lef32(b, 44), lef32(b, 48)]);
        if let Some(t) = te {
            if let Err(e) = Config::DEFAULT.with_translation_error(t) {
                return self.fault(WireError::MotionBounds(e));
            }
        }
        let packet = MotionPacket {
            from: le32(b, 0),
            to: le32(b, 4),
            motion,
            translation_error: te,
            rotation_error: re,
            counter: self.counter,
        };
        if let Some(r) = re {
            // The angles' bounds as sent, and their box about the axes
            // (what the pair's configuration takes).
            let axes = packet.axis_rotation_error().unwrap_or([f32::INFINITY; 3]);
            for v in [r, axes] {
                if let Err(e) = Config::DEFAULT.with_rotation_error(v) {
                    return self.fault(WireError::MotionBounds(e));
                }
            }
        }
        self.motion = Some(packet);
        self.content_done();
    }

    fn camera_body(&mut self, b: &[u8]) {
        let f = |i: usize| lef32(b, 4 * i);
        match Camera::new(f(0), f(1), f(2), f(3), le16(b, 16), le16(b, 18)) {
            Ok(c) => {
                self.new_camera = Some(c);
                self.content_done();
            }
            Err(e) => self.fault(WireError::Camera(e)),
        }
    }

    /// The delimiter: check the packet and give it out.
    fn finish(&mut self) -> Decoded<'_, N, B> {
        let len = self.pos;
        let state = self.state;
        self.state = State::Skip;
        let err = |e| Decoded {
            missed: 0,
            packet: Err(e),
        };
        if len < (HEADER_LEN + CRC_LEN) as u32 {
            return err(WireError::Truncated { len });
        }
        if self.crc ^ crc::CRC_32_AUTOSAR.xorout != RESIDUE {
            return err(WireError::BadCrc);
        }
        if let Some(e) = self.header_fault {
            return err(e);
        }
        let actual = len - (HEADER_LEN + CRC_LEN) as u32;
        if actual != self.declared {
            return err(WireError::BadLength {
                declared: self.declared,
                actual,
            });
        }
        let Some(t) = self.ptype else {
            return err(WireError::Truncated { len });
        };
        let expected = self.ids.of(t);
        if self.data_id != expected {
            return err(WireError::WrongDataId {
                expected,
                got: self.data_id,
            });
        }
        // An intact packet of this stream: its counter counts, whatever
        // its content.
        let slot = input_slot(t).and_then(|i| self.last.get_mut(i));
        let mut missed = 0;
        if let Some(last) = slot {
            if let Some(prev) = *last {
                let delta = self.counter.wrapping_sub(prev);
                if delta == 0 {
                    return err(WireError::Repeated {
                        counter: self.counter,
                    });
                }
                missed = delta - 1;
            }
            *last = Some(self.counter);
        }
        let packet = match (self.fault, state) {
            (Some(e), _) => Err(e),
            (None, State::Trailer) => match t {
                PacketType::Frame => Ok(Packet::Frame(&self.frame, &self.info)),
                PacketType::Motion => match self.motion {
                    Some(m) => Ok(Packet::Motion(m)),
                    None => Err(WireError::Truncated { len }),
                },
                PacketType::Camera => match self.new_camera {
                    Some(c) => {
                        self.camera = Some(c);
                        Ok(Packet::Camera(c))
                    }
                    None => Err(WireError::Truncated { len }),
                },
                _ => Ok(Packet::End),
            },
            (None, _) => Err(WireError::Truncated { len }),
        };
        Decoded { missed, packet }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decoder's register over the crate's table is the crate's
    /// CRC-32/AUTOSAR, at every length and split; a zero stops it at its
    /// index.
    #[test]
    fn crc_register_is_the_crates() {
        let mut rng = crate::test_rng::Rng(0x2026_0012);
        let bytes: [u8; 300] = core::array::from_fn(|_| 1 + (rng.next() * 255.0) as u8);
        for len in 0..bytes.len() {
            let b = &bytes[..len];
            for cut in [0, len / 3, len / 2, len] {
                let c = crc_run(CRC_INIT, &b[..cut]).unwrap();
                let c = crc_run(c, &b[cut..]).unwrap();
                assert_eq!(
                    c ^ crc::CRC_32_AUTOSAR.xorout,
                    CRC.checksum(b),
                    "{len} {cut}"
                );
            }
            let mut c = CRC_INIT;
            for (i, &x) in b.iter().enumerate() {
                c = if i % 3 == 0 {
                    crc_byte(crc_table(), c, x)
                } else {
                    crc_run(c, &[x]).unwrap()
                };
            }
            assert_eq!(c ^ crc::CRC_32_AUTOSAR.xorout, CRC.checksum(b));
            for z in 0..len {
                let mut with_zero = b.to_vec();
                with_zero[z] = 0;
                assert_eq!(crc_run(CRC_INIT, &with_zero), Err(z));
            }
        }
    }
}
