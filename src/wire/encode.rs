//! Writing packets into caller-provided buffers: the raw packet (header,
//! payload, CRC) first, then [`cobs_frame`] for the link.

use core::fmt;

use super::{
    px_to_raw, radius_to_raw, raw_to_px, PacketType, BOUNDARY_HEAD_LEN, CRC, CRC_LEN,
    FRAME_HEAD_LEN, HEADER_LEN, MAGIC, VERSION,
};
use crate::{Camera, Motion, Pixel, Status, Step, Structure};

use super::{DataIds, WireError};

/// Why a packet could not be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum EncodeError {
    /// The output buffer is too small.
    BufferTooSmall,
    /// A point is outside what the format holds (`[−1, 4078.875]` px,
    /// after rounding to the sixteenth) or not finite.
    PointRange,
    /// A radius is negative, NaN or above [`MAX_RADIUS_PX`](super::MAX_RADIUS_PX).
    Radius,
    /// More than 255 boundaries, or more than 65 535 points or bytes.
    TooLarge,
    /// Point `index` of a boundary whose rows are in order (strictly
    /// monotone, as [`crate::Frame::push_boundary`] asks) rounds, to the
    /// sixteenth of a pixel, onto the row of the point before it (rows
    /// 1/32 px apart can): the receiver would refuse the boundary
    /// ([`crate::BoundaryError::Unordered`] or `Duplicate`), so it is not
    /// sent. Send rows at least 1/16 px apart. (Rounding cannot reverse
    /// the order, only merge rows; points out of order as given are sent
    /// as they are, for the receiver to name.)
    Unordered {
        /// The point's index in its boundary.
        index: u16,
    },
}

impl core::error::Error for EncodeError {}

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::BufferTooSmall => "output buffer too small",
            Self::PointRange => "point outside [-1, 4078.875] px or not finite",
            Self::Radius => "error radius outside [0, 100] px",
            Self::TooLarge => "too many boundaries, points or bytes for the format",
            Self::Unordered { index } => {
                return write!(
                    f,
                    "point {index}, rounded to 1/16 px, lands on the row of the point before"
                );
            }
        })
    }
}

/// A bounds-checked little-endian writer.
struct Writer<'a> {
    buf: &'a mut [u8],
    at: usize,
}

/// Where a packet's bytes go, in order: a buffer ([`Writer`]), a count of
/// them, or a link that frames them as they come
/// (`crate::link::write_result`).
pub(crate) trait Sink {
    type Error: From<EncodeError>;
    /// Take `b`, after what came before.
    fn put(&mut self, b: &[u8]) -> Result<(), Self::Error>;
}

/// A sink that only counts.
pub(crate) struct Count(pub(crate) usize);

impl Sink for Count {
    type Error = EncodeError;
    fn put(&mut self, b: &[u8]) -> Result<(), EncodeError> {
        self.0 = self.0.checked_add(b.len()).ok_or(EncodeError::TooLarge)?;
        Ok(())
    }
}

impl Sink for Writer<'_> {
    type Error = EncodeError;
    fn put(&mut self, b: &[u8]) -> Result<(), EncodeError> {
        self.bytes(b)
    }
}

/// A packet's header, its payload `len` bytes long.
pub(crate) fn header(t: PacketType, data_id: u16, counter: u16, len: u16) -> [u8; HEADER_LEN] {
    let [d0, d1] = data_id.to_le_bytes();
    let [c0, c1] = counter.to_le_bytes();
    let [l0, l1] = len.to_le_bytes();
    let [m0, m1] = MAGIC;
    [m0, m1, VERSION, t as u8, d0, d1, c0, c1, l0, l1]
}

impl Writer<'_> {
    fn bytes(&mut self, b: &[u8]) -> Result<(), EncodeError> {
        let end = self.at.checked_add(b.len()).ok_or(EncodeError::TooLarge)?;
        let dst = self
            .buf
            .get_mut(self.at..end)
            .ok_or(EncodeError::BufferTooSmall)?;
        for (d, s) in dst.iter_mut().zip(b) {
            *d = *s;
        }
        self.at = end;
        Ok(())
    }
    fn u8(&mut self, x: u8) -> Result<(), EncodeError> {
        self.bytes(&[x])
    }
    fn u16(&mut self, x: u16) -> Result<(), EncodeError> {
        self.bytes(&x.to_le_bytes())
    }
    fn u32(&mut self, x: u32) -> Result<(), EncodeError> {
        self.bytes(&x.to_le_bytes())
    }
    fn f32(&mut self, x: f32) -> Result<(), EncodeError> {
        self.u32(x.to_bits())
    }
    fn patch(&mut self, at: usize, b: &[u8]) {
        if let Some(dst) = self.buf.get_mut(at..at.saturating_add(b.len())) {
            for (d, s) in dst.iter_mut().zip(b) {
                *d = *s;
            }
        }
    }
    /// Write the header with a zero length (patched by [`Writer::finish`]).
    fn header(&mut self, t: PacketType, data_id: u16, counter: u16) -> Result<(), EncodeError> {
        self.bytes(&header(t, data_id, counter, 0))
    }
    /// Patch the payload length, append the CRC; the packet's length.
    fn finish(mut self) -> Result<usize, EncodeError> {
        let payload = self
            .at
            .checked_sub(HEADER_LEN)
            .ok_or(EncodeError::TooLarge)?;
        let len = u16::try_from(payload).map_err(|_| EncodeError::TooLarge)?;
        self.patch(8, &len.to_le_bytes());
        let crc = CRC.checksum(self.buf.get(..self.at).unwrap_or(&[]));
        self.u32(crc)?;
        Ok(self.at)
    }
}

/// The fixed part of a frame packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameHead {
    /// Exposure timestamp, microseconds (the front end's clock).
    pub timestamp_us: u64,
    /// Frame id (the motion packets name frames by it).
    pub frame_id: u32,
    /// Image width, pixels.
    pub width: u16,
    /// Image height, pixels.
    pub height: u16,
}

/// A boundary's fixed part in a frame packet.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BoundaryHead {
    /// Quality from the detector (0–255, carried to the result).
    pub quality: u8,
    /// Localisation-error radius of every point as given to the encoder
    /// (the detector's), pixels (`[0, 100]`). The packet carries it plus
    /// the most that rounding the boundary's points to 1/16 px moves one
    /// (nothing where every point is on that grid, as integer and
    /// half-pixel ones are), rounded up to 1/256 px: the radius on the wire
    /// bounds the true point's distance from the point as sent.
    /// [`EncodeError::Radius`] if that sum exceeds 100.
    pub radius_px: f32,
}

/// A frame packet being written: [`FramePacket::boundary`] per boundary,
/// then [`FramePacket::finish`].
pub struct FramePacket<'a> {
    w: Writer<'a>,
    count: u8,
}

impl core::fmt::Debug for FramePacket<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("FramePacket")
            .field("written", &self.w.at)
            .field("capacity", &self.w.buf.len())
            .field("boundaries", &self.count)
            .finish()
    }
}

impl<'a> FramePacket<'a> {
    /// Start a frame packet in `out`.
    pub fn begin(
        out: &'a mut [u8],
        data_id: u16,
        counter: u16,
        head: &FrameHead,
    ) -> Result<Self, EncodeError> {
        let mut w = Writer { buf: out, at: 0 };
        w.header(PacketType::Frame, data_id, counter)?;
        w.bytes(&head.timestamp_us.to_le_bytes())?;
        w.u32(head.frame_id)?;
        w.u16(head.width)?;
        w.u16(head.height)?;
        w.u8(0)?;
        w.u8(0)?;
        Ok(Self { w, count: 0 })
    }

    /// Append the next boundary (points rounded to 1/16 px). On an error
    /// nothing of the boundary is kept: the packet is as it was before the
    /// call, so a caller may skip the boundary and go on, and
    /// [`FramePacket::finish`] gives the boundaries that were appended.
    pub fn boundary(&mut self, head: &BoundaryHead, points: &[Pixel]) -> Result<(), EncodeError> {
        // (Every check before the count moves; the bytes written before a
        // failing one are taken back, so no partial boundary reaches
        // `finish`.)
        let index = self.count;
        let count = index.checked_add(1).ok_or(EncodeError::TooLarge)?;
        let start = self.w.at;
        match self.write_boundary(index, head, points) {
            Ok(()) => {
                self.count = count;
                Ok(())
            }
            Err(e) => {
                self.w.at = start;
                Err(e)
            }
        }
    }

    /// The bytes of boundary `index`; on an error some may be written.
    fn write_boundary(
        &mut self,
        index: u8,
        head: &BoundaryHead,
        points: &[Pixel],
    ) -> Result<(), EncodeError> {
        let n = u16::try_from(points.len()).map_err(|_| EncodeError::TooLarge)?;
        radius_to_raw(head.radius_px).ok_or(EncodeError::Radius)?;
        self.w.u8(index)?;
        self.w.u8(head.quality)?;
        let radius_at = self.w.at;
        self.w.u16(0)?;
        self.w.u16(n)?;
        // The points, and what rounding them to 1/16 px moves one at most:
        // the radius sent covers it, so that it bounds the true point's
        // distance from the point as sent. (Each difference is exact or
        // within 2⁻³⁰ px, the two values being within 1/32 px; the bound is
        // taken 10⁻⁵ larger, relative and absolute, for the square root and
        // the sum's rounding; `radius_to_raw` rounds up.)
        let mut moved = 0.0f32;
        // Whether any point moved at all: below about 2⁻⁷⁵ px both squares
        // underflow to 0, and such a point still moved (an adversarial
        // review, thirtieth session: `u = 10⁻³⁰` sent as 0 with the radius
        // 0); the absolute 10⁻⁵ covers it.
        let mut any = false;
        // The row order the receiver checks (`Boundary`'s): rows strictly
        // monotone. Where the points as given keep it, the rounded rows
        // must too (rounding is monotone, but rows 1/32 px apart can round
        // together); points out of order as given are sent as they are,
        // for the receiver to name. The rows before, given and rounded, and
        // the direction of the given ones (`None`: not yet known, or no
        // longer checked once the given rows break the order).
        let mut last: Option<(f32, u16)> = None;
        let mut rising: Option<Option<bool>> = Some(None);
        for (index, p) in points.iter().enumerate() {
            let u = px_to_raw(p.u).ok_or(EncodeError::PointRange)?;
            let v = px_to_raw(p.v).ok_or(EncodeError::PointRange)?;
            if let (Some((pv, prev)), Some(dir)) = (last, rising) {
                let up = p.v > pv;
                rising = (p.v != pv && dir.is_none_or(|d| d == up)).then_some(Some(up));
                if rising.is_some() && v == prev {
                    // (`n` fits 16 bits, so does the index.)
                    let index = u16::try_from(index).unwrap_or(u16::MAX);
                    return Err(EncodeError::Unordered { index });
                }
            }
            last = Some((p.v, v));
            let (du, dv) = (raw_to_px(u) - p.u, raw_to_px(v) - p.v);
            moved = crate::math::fmax(moved, du * du + dv * dv);
            any |= du != 0.0 || dv != 0.0;
            self.w.u16(u)?;
            self.w.u16(v)?;
        }
        let shift = if any {
            crate::math::sqrt(moved) * (1.0 + 1.0e-5) + 1.0e-5
        } else {
            0.0
        };
        let r = radius_to_raw(head.radius_px + shift).ok_or(EncodeError::Radius)?;
        self.w.patch(radius_at, &r.to_le_bytes());
        Ok(())
    }

    /// Patch the boundary count and length, append the CRC: the packet's
    /// length in `out`.
    pub fn finish(mut self) -> Result<usize, EncodeError> {
        self.w.patch(HEADER_LEN + FRAME_HEAD_LEN - 2, &[self.count]);
        self.w.finish()
    }
}

/// Write a whole frame packet for `boundaries` (points and head each).
pub fn frame(
    out: &mut [u8],
    data_id: u16,
    counter: u16,
    head: &FrameHead,
    boundaries: &[(BoundaryHead, &[Pixel])],
) -> Result<usize, EncodeError> {
    let mut p = FramePacket::begin(out, data_id, counter, head)?;
    for (h, pts) in boundaries {
        p.boundary(h, pts)?;
    }
    p.finish()
}

/// The content of a motion packet.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MotionFields {
    /// Frame id of the first frame.
    pub from: u32,
    /// Frame id of the second frame.
    pub to: u32,
    /// Translation `(U, V, W)` (README's conventions).
    pub translation: [f32; 3],
    /// Rotation `(α, β, γ)`, radians.
    pub rotation: [f32; 3],
    /// Bound on each translation component's error, if known.
    pub translation_error: Option<f32>,
    /// Bound on each rotation angle's error (`α`, `β`, `γ` of
    /// [`Self::rotation`]), radians, if known. The controller widens them
    /// to a box about the camera's axes at these angles
    /// ([`crate::wire::MotionPacket::axis_rotation_error`]); that box must
    /// pass [`crate::Config::with_rotation_error`] (at most 0.1 rad in
    /// all), or the packet is refused.
    pub rotation_error: Option<[f32; 3]>,
}

impl MotionFields {
    /// The fields of a validated motion, without error bounds.
    pub fn of(from: u32, to: u32, m: &Motion) -> Self {
        Self {
            from,
            to,
            translation: m.translation(),
            rotation: m.angles(),
            translation_error: None,
            rotation_error: None,
        }
    }
}

/// Write a motion packet.
pub fn motion(
    out: &mut [u8],
    data_id: u16,
    counter: u16,
    m: &MotionFields,
) -> Result<usize, EncodeError> {
    let mut w = Writer { buf: out, at: 0 };
    w.header(PacketType::Motion, data_id, counter)?;
    w.u32(m.from)?;
    w.u32(m.to)?;
    for x in m.translation.iter().chain(m.rotation.iter()) {
        w.f32(*x)?;
    }
    let flags =
        u8::from(m.translation_error.is_some()) | (u8::from(m.rotation_error.is_some()) << 1);
    w.bytes(&[flags, 0, 0, 0])?;
    w.f32(m.translation_error.unwrap_or(0.0))?;
    for x in m.rotation_error.unwrap_or([0.0; 3]) {
        w.f32(x)?;
    }
    w.finish()
}

/// Write a camera packet.
pub fn camera(
    out: &mut [u8],
    data_id: u16,
    counter: u16,
    c: &Camera,
) -> Result<usize, EncodeError> {
    let mut w = Writer { buf: out, at: 0 };
    w.header(PacketType::Camera, data_id, counter)?;
    for x in [c.fx(), c.fy(), c.cx(), c.cy()] {
        w.f32(x)?;
    }
    w.u16(c.width())?;
    w.u16(c.height())?;
    w.finish()
}

/// Write an end packet (no payload).
pub fn end(out: &mut [u8], data_id: u16, counter: u16) -> Result<usize, EncodeError> {
    let mut w = Writer { buf: out, at: 0 };
    w.header(PacketType::End, data_id, counter)?;
    w.finish()
}

/// Write a report packet for `e`.
pub fn report(
    out: &mut [u8],
    data_id: u16,
    counter: u16,
    e: &WireError,
) -> Result<usize, EncodeError> {
    let mut w = Writer { buf: out, at: 0 };
    w.header(PacketType::Report, data_id, counter)?;
    let (sub, a, rest) = e.details();
    w.u8(e.kind() as u8)?;
    w.u8(sub)?;
    w.u16(a)?;
    for x in rest {
        w.u32(x)?;
    }
    w.finish()
}

/// Write a summary packet: the receiver's counters, `u32` each.
pub fn summary(
    out: &mut [u8],
    data_id: u16,
    counter: u16,
    values: &[u32],
) -> Result<usize, EncodeError> {
    let mut w = Writer { buf: out, at: 0 };
    w.header(PacketType::Summary, data_id, counter)?;
    for x in values {
        w.u32(*x)?;
    }
    w.finish()
}

/// What a result packet says about its frame besides the structure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResultHead {
    /// The frame (frame 2 of the pair).
    pub frame_id: u32,
    /// The kept frame it was paired with (itself for a first frame).
    pub kept_id: u32,
    /// The frame's exposure timestamp, microseconds.
    pub timestamp_us: u64,
    /// Instructions of the per-frame call, where the firmware counts them
    /// (0 otherwise).
    pub instructions: u32,
}

/// Write a result packet: `step` of the frame, `quality` per boundary
/// (from the frame-1 packet; 0 where unknown).
pub fn result<const N: usize, const B: usize>(
    out: &mut [u8],
    data_id: u16,
    counter: u16,
    head: &ResultHead,
    step: &Step<'_, N, B>,
    quality: &[u8],
) -> Result<usize, EncodeError> {
    let mut w = Writer { buf: out, at: 0 };
    w.header(PacketType::Result, data_id, counter)?;
    result_payload(&mut w, head, step, quality)?;
    w.finish()
}

/// A result packet's payload (README's layout, `docs/wire.md`), into any
/// sink: [`result`]'s buffer, or a link that frames it as it goes
/// (`crate::link::write_result`).
pub(crate) fn result_payload<S: Sink, const N: usize, const B: usize>(
    w: &mut S,
    head: &ResultHead,
    step: &Step<'_, N, B>,
    quality: &[u8],
) -> Result<(), S::Error> {
    w.put(&head.frame_id.to_le_bytes())?;
    w.put(&head.kept_id.to_le_bytes())?;
    w.put(&head.timestamp_us.to_le_bytes())?;
    let s: Option<&Structure<N, B>> = match step {
        Step::First => None,
        Step::Structure(s) => Some(s),
    };
    let nb = s.map_or(0, |s| s.boundaries().len());
    // Flags: bit 0, the caller's deadline cut the frame short.
    w.put(&[
        u8::from(s.is_some()),
        u8::try_from(nb).map_err(|_| EncodeError::TooLarge)?,
        u8::from(s.is_some_and(|s| s.deadline_expired())),
        0,
    ])?;
    w.put(&head.instructions.to_le_bytes())?;
    w.put(&s.map_or(0, |s| s.digest()).to_le_bytes())?;
    let counts = s.map(|s| s.status_counts()).unwrap_or_default();
    for &st in Status::ALL {
        w.put(
            &u16::try_from(counts.get(st))
                .unwrap_or(u16::MAX)
                .to_le_bytes(),
        )?;
    }
    w.put(&[0, 0])?;
    if let Some(s) = s {
        for (k, b) in s.boundaries().iter().enumerate() {
            let pts = b.points();
            let [n0, n1] = u16::try_from(pts.len())
                .map_err(|_| EncodeError::TooLarge)?
                .to_le_bytes();
            w.put(&[n0, n1, quality.get(k).copied().unwrap_or(0), 0])?;
            for r in pts {
                w.put(&[r.status() as u8])?;
                if let (Some([x, y, z]), Some(i)) = (s.point(r), r.interval()) {
                    let mut v = [0u8; 20];
                    let bytes = [x, y, z, i.z_near, i.z_far].map(|x| x.to_bits().to_le_bytes());
                    for (d, s) in v.iter_mut().zip(bytes.iter().flatten()) {
                        *d = *s;
                    }
                    w.put(&v)?;
                }
            }
        }
    }
    Ok(())
}

/// The sending side of a stream: its data ids and each one's next
/// counter (`+1` a packet of that data id, wrapping, as the receiver
/// checks it: `docs/wire.md`), so the packets it writes number
/// themselves. A packet that could not be written takes no number.
/// Each method writes the raw packet into `out` as the free function of
/// its name does ([`frame`], [`motion`], ...); frame it for the link
/// with [`cobs_frame`] or `link::write_packet`.
///
/// ```
/// use roadstereo::wire::encode::{cobs_frame, Sender};
/// use roadstereo::wire::{DataIds, Event, Receiver};
/// use roadstereo::{Camera, Config};
/// let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480)?;
/// let mut tx = Sender::new(DataIds::DEFAULT);
/// let mut rx = Receiver::<64, 2>::new(DataIds::DEFAULT, Config::DEFAULT);
/// let (mut raw, mut link) = ([0u8; 64], [0u8; 80]);
/// let mut cameras = 0;
/// for _ in 0..3 {
///     let n = tx.camera(&mut raw, &cam)?;
///     let m = cobs_frame(&raw[..n], &mut link)?;
///     rx.feed(&link[..m], |e| cameras += usize::from(matches!(e, Event::Camera(_))));
/// }
/// // Numbered 0, 1, 2: no counter jump, no repeat.
/// assert_eq!((cameras, rx.counters().total_errors()), (3, 0));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sender {
    ids: DataIds,
    /// The next counter of frame, motion, camera, end, result, report and
    /// summary packets.
    next: [u16; 7],
}

impl Sender {
    /// A stream with the data ids `ids`, every counter at 0.
    pub const fn new(ids: DataIds) -> Self {
        Self { ids, next: [0; 7] }
    }

    /// The data ids.
    pub const fn ids(&self) -> DataIds {
        self.ids
    }

    /// The counter the next packet of `t` will carry.
    pub fn next_counter(&self, t: PacketType) -> u16 {
        self.next.get(Self::slot(t)).copied().unwrap_or(0)
    }

    fn slot(t: PacketType) -> usize {
        match t {
            PacketType::Frame => 0,
            PacketType::Motion => 1,
            PacketType::Camera => 2,
            PacketType::End => 3,
            PacketType::Result => 4,
            PacketType::Report => 5,
            PacketType::Summary => 6,
        }
    }

    /// The data id and counter for a packet of `t`; `write` makes it, and
    /// the counter moves on only if it did.
    fn numbered(
        &mut self,
        t: PacketType,
        write: impl FnOnce(u16, u16) -> Result<usize, EncodeError>,
    ) -> Result<usize, EncodeError> {
        let id = match t {
            PacketType::Frame => self.ids.frame,
            PacketType::Motion => self.ids.motion,
            PacketType::Camera => self.ids.camera,
            PacketType::End => self.ids.end,
            PacketType::Result => self.ids.result,
            PacketType::Report => self.ids.report,
            PacketType::Summary => self.ids.summary,
        };
        let n = write(id, self.next_counter(t))?;
        if let Some(c) = self.next.get_mut(Self::slot(t)) {
            *c = c.wrapping_add(1);
        }
        Ok(n)
    }

    /// A frame packet ([`frame`]).
    pub fn frame(
        &mut self,
        out: &mut [u8],
        head: &FrameHead,
        boundaries: &[(BoundaryHead, &[Pixel])],
    ) -> Result<usize, EncodeError> {
        self.numbered(PacketType::Frame, |id, c| {
            frame(out, id, c, head, boundaries)
        })
    }

    /// A motion packet ([`motion`]).
    pub fn motion(&mut self, out: &mut [u8], m: &MotionFields) -> Result<usize, EncodeError> {
        self.numbered(PacketType::Motion, |id, c| motion(out, id, c, m))
    }

    /// A camera packet ([`camera`]).
    pub fn camera(&mut self, out: &mut [u8], cam: &Camera) -> Result<usize, EncodeError> {
        self.numbered(PacketType::Camera, |id, c| camera(out, id, c, cam))
    }

    /// An end packet ([`end`]).
    pub fn end(&mut self, out: &mut [u8]) -> Result<usize, EncodeError> {
        self.numbered(PacketType::End, |id, c| end(out, id, c))
    }

    /// A result packet ([`result`]; `link::write_result` writes one without
    /// a buffer, with [`Self::next_counter`] and a [`Self::skip`] after).
    pub fn result<const N: usize, const B: usize>(
        &mut self,
        out: &mut [u8],
        head: &ResultHead,
        step: &Step<'_, N, B>,
        quality: &[u8],
    ) -> Result<usize, EncodeError> {
        self.numbered(PacketType::Result, |id, c| {
            result(out, id, c, head, step, quality)
        })
    }

    /// A report packet ([`report`]).
    pub fn report(&mut self, out: &mut [u8], e: &WireError) -> Result<usize, EncodeError> {
        self.numbered(PacketType::Report, |id, c| report(out, id, c, e))
    }

    /// A summary packet ([`summary`]).
    pub fn summary(&mut self, out: &mut [u8], values: &[u32]) -> Result<usize, EncodeError> {
        self.numbered(PacketType::Summary, |id, c| summary(out, id, c, values))
    }

    /// Move the counter of `t` on by one: a packet of it was written
    /// elsewhere (e.g. by `link::write_result`) with [`Self::next_counter`].
    pub fn skip(&mut self, t: PacketType) {
        if let Some(c) = self.next.get_mut(Self::slot(t)) {
            *c = c.wrapping_add(1);
        }
    }
}

/// COBS-encode the packet `raw` into `out` (with the `cobs` crate) and
/// append the frame delimiter: the bytes to send.
pub fn cobs_frame(raw: &[u8], out: &mut [u8]) -> Result<usize, EncodeError> {
    let n = cobs::try_encode(raw, out).map_err(|_| EncodeError::BufferTooSmall)?;
    let d = out.get_mut(n).ok_or(EncodeError::BufferTooSmall)?;
    *d = 0;
    Ok(n + 1)
}

// Used by the decoder's length checks.
const _: () = assert!(BOUNDARY_HEAD_LEN == 6 && CRC_LEN == 4);
