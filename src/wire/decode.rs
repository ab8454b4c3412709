//! The byte-fed streaming decoder.
//!
//! COBS framing is the `cobs` crate's [`DecoderState`] state machine: it
//! reads every code byte and delimiter, and its run counter says how many
//! data bytes follow, which are then taken as one slice (the CRC and the
//! points are computed over whole runs, not byte by byte). The decoded
//! bytes go through the CRC register and a small parser; a frame's points
//! are written straight into the decoder's [`Frame`] and validated there.
//!
//! # Bounds
//! [`Decoder::feed`] does constant work per input byte and returns after
//! at most `input.len()` bytes; nothing is buffered but one packet's
//! fixed-size sections (at most [`MOTION_LEN`] bytes) and a partial point.

use cobs::{DecodeResult, DecoderState};
use crc::Digest;

use super::{
    raw_to_px, raw_to_radius, CrcTable, DataIds, PacketType, WireError, BOUNDARY_HEAD_LEN,
    CAMERA_LEN, CRC, CRC_LEN, FRAME_HEAD_LEN, HEADER_LEN, MAGIC, MOTION_LEN, POINT_LEN, RESIDUE,
    VERSION,
};
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
    /// Localisation-error radius of each boundary, pixels.
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
    /// Bound on each rotation angle's error (validated for
    /// [`Config::with_rotation_error`]).
    pub rotation_error: Option<[f32; 3]>,
    /// The packet's counter.
    pub counter: u16,
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

    /// Check and convert `chunks` into `dst` (same length); stops at the
    /// first bad point. The usual case, once the row direction is known,
    /// in a lean loop; a point it does not pass gets the careful check,
    /// which names the error.
    #[inline(never)]
    fn store(&mut self, chunks: &[[u8; 4]], dst: &mut [Pixel]) -> Result<(), crate::BoundaryError> {
        let mut pairs = dst.iter_mut().zip(chunks);
        while self.index < 2 {
            let Some((d, c)) = pairs.next() else {
                return Ok(());
            };
            let w = u32::from_le_bytes(*c);
            self.check(w)?;
            *d = Pixel::new(raw_to_px(w as u16), raw_to_px((w >> 16) as u16));
        }
        let base = u32::from(super::RAW_MINUS_ONE_PX);
        let (umax, vmax) = self.limits;
        let (mut prev, mut step) = (self.prev, self.step);
        let mut taken = 0usize;
        let mut failed = None;
        for (d, c) in pairs {
            let w = u32::from_le_bytes(*c);
            let (u, v) = (w & 0xFFFF, w >> 16);
            let dv = v as i32 - (prev >> 16) as i32;
            // (A duplicate has dv = 0 too: the careful check tells which.)
            if u.wrapping_sub(base) > umax
                || v.wrapping_sub(base) > vmax
                || dv == 0
                || (dv ^ step) < 0
            {
                failed = Some(w);
                break;
            }
            step = dv;
            prev = w;
            *d = Pixel::new(raw_to_px(u as u16), raw_to_px(v as u16));
            taken += 1;
        }
        self.index += taken;
        self.step = step;
        self.prev = prev;
        match failed {
            Some(w) => self.check(w),
            None => Ok(()),
        }
    }
}

/// The first zero byte of `s`: four bytes at a time (a word has a zero
/// byte iff `(w − 0x0101_0101) & !w & 0x8080_8080 ≠ 0`), then byte by byte.
#[inline(always)]
fn zero_at(s: &[u8]) -> Option<usize> {
    let (words, _) = s.as_chunks::<4>();
    let mut at = 0;
    for w in words {
        let x = u32::from_le_bytes(*w);
        if x.wrapping_sub(0x0101_0101) & !x & 0x8080_8080 != 0 {
            break;
        }
        at += 4;
    }
    s.get(at..)?.iter().position(|&b| b == 0).map(|i| at + i)
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
    crc: Digest<'static, u32, CrcTable>,
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

impl<const N: usize, const B: usize> Decoder<N, B> {
    /// A decoder that takes packets with the data ids `ids`, with no camera
    /// yet (frames need a camera packet first).
    pub const fn new(ids: DataIds) -> Self {
        Self {
            ids,
            cobs: DecoderState::Idle,
            crc: CRC.digest(),
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
                if let Some(z) = zero_at(chunk) {
                    // A delimiter inside a run: the packet was cut short.
                    used += z + 1;
                    self.cobs = DecoderState::Idle;
                    let len = self.pos.saturating_add(z as u32);
                    return (used, Some(self.fail(WireError::Truncated { len })));
                }
                self.data(chunk);
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
                Ok(DecodeResult::DataContinue(b)) => self.data(&[b]),
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
        self.crc = CRC.digest();
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

    /// Decoded bytes of the current packet.
    fn data(&mut self, bytes: &[u8]) {
        self.crc.update(bytes);
        let mut s = bytes;
        // Each pass consumes at least one byte.
        while !s.is_empty() {
            s = match self.state {
                State::Small(section) => self.small(section, s),
                State::Points => self.points(s),
                State::Trailer | State::Skip => {
                    self.advance(s.len());
                    &[]
                }
            };
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

    fn small<'s>(&mut self, section: Section, s: &'s [u8]) -> &'s [u8] {
        let need = section.len();
        let take = need.saturating_sub(self.small_len).min(s.len());
        let (head, tail) = s.split_at_checked(take).unwrap_or((s, &[]));
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
        tail
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

    /// Points of the current boundary: whole points straight into the
    /// frame's slot, a partial one carried to the next slice.
    fn points<'s>(&mut self, s: &'s [u8]) -> &'s [u8] {
        let mut s = s;
        if self.carry_len > 0 || s.len() < POINT_LEN {
            while self.carry_len < POINT_LEN {
                let Some((&b, rest)) = s.split_first() else {
                    return s;
                };
                if let Some(c) = self.carry.get_mut(self.carry_len) {
                    *c = b;
                }
                self.carry_len += 1;
                self.advance(1);
                s = rest;
            }
            self.carry_len = 0;
            let c = self.carry;
            self.store(&c);
        } else {
            let left = (self.points - self.done) * POINT_LEN;
            let whole = left.min(s.len() - s.len() % POINT_LEN);
            let (body, rest) = s.split_at_checked(whole).unwrap_or((&[], s));
            self.advance(whole);
            self.store(body);
            s = rest;
        }
        if self.state == State::Points && self.done >= self.points {
            self.boundary_done();
        }
        s
    }

    /// Validate whole points and convert them into the next slot's
    /// storage. The checks are [`crate::Frame::push_boundary`]'s, done on
    /// the raw values, in the same order, with the same errors: every
    /// point is finite by construction; `u` is inside `[−1, width]` iff
    /// `raw − 0x0101` is in `[0, 16 (width + 1)]` (the conversion is exact);
    /// equal raw points are equal pixels; a row step's sign is the raw
    /// step's.
    #[inline(always)]
    fn store(&mut self, body: &[u8]) {
        let (chunks, _) = body.as_chunks::<POINT_LEN>();
        let done = self.done;
        let mut run = PointRun {
            limits: self.limits,
            prev: self.prev,
            step: self.step,
            index: done,
        };
        let mut bad = None;
        if let Some(dst) = self
            .frame
            .next_storage()
            .and_then(|s| s.get_mut(done..done + chunks.len()))
        {
            bad = run.store(chunks, dst).err();
        }
        self.prev = run.prev;
        self.step = run.step;
        self.done = done + chunks.len();
        if let Some(error) = bad {
            self.fault(WireError::Boundary {
                boundary: u8::try_from(self.boundary).unwrap_or(u8::MAX),
                error,
            });
        }
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
        if let Some(r) = re {
            if let Err(e) = Config::DEFAULT.with_rotation_error(r) {
                return self.fault(WireError::MotionBounds(e));
            }
        }
        self.motion = Some(MotionPacket {
            from: le32(b, 0),
            to: le32(b, 4),
            motion,
            translation_error: te,
            rotation_error: re,
            counter: self.counter,
        });
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
        if self.crc.clone().finalize() != RESIDUE {
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
