//! The camera front-end link's wire format (version 1): frame, motion and
//! camera packets in, result and report packets out, each one COBS frame
//! protected by a data id, a counter and a CRC-32 in the spirit of AUTOSAR
//! E2E. `docs/wire.md` gives the format byte by byte.
//!
//! * [`encode`]: writers for every packet (the front end's side, and the
//!   controller's results), into caller-provided buffers.
//! * [`Decoder`]: the byte-fed streaming decoder. Feed it whatever chunk
//!   arrived; it yields each complete packet or a typed [`WireError`],
//!   resynchronises at the next frame delimiter, and writes a frame's
//!   points straight into its [`Frame`](crate::Frame) (no copy of the
//!   points in between).
//! * [`Receiver`]: the decoder plus the pairing of frames with motions: a
//!   frame job carries the [`Config`](crate::Config) for its pair, with the
//!   boundaries' localisation-error radii and the motion's error bounds.
//! * [`ResultView`]: a parsed result packet (the vehicle's side).
//!
//! Every packet, before COBS (little endian throughout):
//!
//! | offset | size | field |
//! |---:|---:|---|
//! | 0 | 2 | magic `"RS"` (`0x52 0x53`) |
//! | 2 | 1 | format version, [`VERSION`] |
//! | 3 | 1 | packet type ([`PacketType`]) |
//! | 4 | 2 | data id (which stream: [`DataIds`]) |
//! | 6 | 2 | counter, +1 per packet of that data id, wrapping |
//! | 8 | 2 | payload length `L` |
//! | 10 | `L` | payload |
//! | 10 + `L` | 4 | CRC-32/AUTOSAR of bytes `0 .. 10 + L` |
//!
//! On the link each packet is COBS-encoded and ends with one `0x00`
//! (the frame delimiter), the only zero byte on the link.

mod decode;
pub mod encode;
mod error;
mod receiver;
pub mod result;

pub use decode::{Decoded, Decoder, FrameInfo, MotionPacket, Packet};
pub use error::{ErrorKind, WireError};
pub use receiver::{Counters, Event, FrameJob, Receiver};
pub use result::{PointView, ResultBoundary, ResultView};

use crc::{Crc, Table};

/// The format version this module writes and reads.
pub const VERSION: u8 = 1;
/// The first two bytes of every packet.
pub const MAGIC: [u8; 2] = *b"RS";
/// Bytes before the payload. (The layout lengths are the format's,
/// `docs/wire.md`; a caller sizes its buffers with [`frame_packet_max`],
/// [`input_packet_max`] (what a receiver takes, every packet type: at a
/// small capacity a motion packet is larger than a frame packet),
/// [`result_packet_max`] and [`cobs_max`].)
pub(crate) const HEADER_LEN: usize = 10;
/// Bytes of the CRC after the payload.
pub(crate) const CRC_LEN: usize = 4;
/// A frame payload's fixed part: timestamp, frame id, image size,
/// boundary count and a reserved byte.
pub(crate) const FRAME_HEAD_LEN: usize = 18;
/// A boundary's fixed part: index, quality, error radius, point count.
pub(crate) const BOUNDARY_HEAD_LEN: usize = 6;
/// One point: `u`, `v` as `u16` in 1/16 px ([`raw_to_px`]).
pub(crate) const POINT_LEN: usize = 4;
/// A motion payload (fixed size).
pub(crate) const MOTION_LEN: usize = 52;
/// A camera payload (fixed size).
pub(crate) const CAMERA_LEN: usize = 20;
/// A report payload (fixed size).
pub(crate) const REPORT_LEN: usize = 20;
/// A result payload's fixed part.
pub(crate) const RESULT_HEAD_LEN: usize = 56;
// The result head holds one u16 count per status (offset 28, then a u16
// of padding): a new status is a new format version.
const _: () = assert!(RESULT_HEAD_LEN == 28 + 2 * crate::structure::STATUS_COUNT + 2);
/// A result boundary's fixed part.
pub(crate) const RESULT_BOUNDARY_LEN: usize = 4;
/// A result point with a depth: status and five `f32`.
pub(crate) const RESULT_POINT_MAX: usize = 21;
/// The largest localisation-error radius a boundary may carry, pixels
/// (the limit of [`crate::Config`]).
pub const MAX_RADIUS_PX: f32 = 100.0;

/// Largest frame payload for `B` boundaries of up to `N` points.
///
/// The header's length field is 16 bits: a frame whose payload would pass
/// 65 535 bytes cannot be sent ([`encode::EncodeError::TooLarge`]). A
/// capacity whose full frame passes it (`18 + B·(6 + 4 N) > 65 535`, e.g.
/// `N = 16 383, B = 1` or `N = 1 024, B = 16`) can be declared, but only
/// frames that leave enough of it unused go over the link.
pub const fn frame_payload_max(n: usize, b: usize) -> usize {
    FRAME_HEAD_LEN + b * (BOUNDARY_HEAD_LEN + POINT_LEN * n)
}
/// Largest frame packet (header, payload, CRC) before COBS.
pub const fn frame_packet_max(n: usize, b: usize) -> usize {
    HEADER_LEN + frame_payload_max(n, b) + CRC_LEN
}
/// Largest packet (header, payload, CRC) before COBS that a receiver of
/// `B` boundaries of up to `N` points takes in: its largest frame packet,
/// or a motion or camera packet where that is larger (a small capacity).
pub const fn input_packet_max(n: usize, b: usize) -> usize {
    let frame = frame_packet_max(n, b);
    let fixed = HEADER_LEN
        + CRC_LEN
        + if MOTION_LEN > CAMERA_LEN {
            MOTION_LEN
        } else {
            CAMERA_LEN
        };
    if frame > fixed {
        frame
    } else {
        fixed
    }
}
/// Largest result packet before COBS.
pub const fn result_packet_max(n: usize, b: usize) -> usize {
    HEADER_LEN + RESULT_HEAD_LEN + b * (RESULT_BOUNDARY_LEN + RESULT_POINT_MAX * n) + CRC_LEN
}
/// Largest COBS encoding of a `raw_len`-byte packet, with its delimiter.
pub const fn cobs_max(raw_len: usize) -> usize {
    raw_len + raw_len / 254 + 2
}

/// The packet types of version 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum PacketType {
    /// Front end → controller: one camera frame's boundaries.
    Frame = 0x01,
    /// Odometry → controller: the motion between two frames.
    Motion = 0x02,
    /// Front end → controller: the camera intrinsics (sent at start and
    /// whenever they change; repeated freely).
    Camera = 0x03,
    /// Test harness → controller: end of the stream (no payload).
    End = 0x7F,
    /// Controller → vehicle: one frame's results.
    Result = 0x81,
    /// Controller → vehicle: one typed error the receiver saw.
    Report = 0x82,
    /// Controller → vehicle: the receiver's counters (answer to `End`).
    Summary = 0x83,
}

impl PacketType {
    /// The type with code `b`.
    pub fn from_code(b: u8) -> Option<Self> {
        Some(match b {
            0x01 => Self::Frame,
            0x02 => Self::Motion,
            0x03 => Self::Camera,
            0x7F => Self::End,
            0x81 => Self::Result,
            0x82 => Self::Report,
            0x83 => Self::Summary,
            _ => return None,
        })
    }
}

/// The data id of each stream (AUTOSAR E2E's data id: a receiver only
/// takes a packet type from its configured sender). Each data id has its
/// own counter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DataIds {
    /// Frame packets.
    pub frame: u16,
    /// Motion packets.
    pub motion: u16,
    /// Camera packets.
    pub camera: u16,
    /// End packets.
    pub end: u16,
    /// Result packets.
    pub result: u16,
    /// Report packets.
    pub report: u16,
    /// Summary packets.
    pub summary: u16,
}

impl DataIds {
    /// The ids this project uses: `0x0F01` frame, `0x0F02` motion,
    /// `0x0F03` camera, `0x0F7F` end, `0x0F81` result, `0x0F82` report,
    /// `0x0F83` summary.
    pub const DEFAULT: DataIds = DataIds {
        frame: 0x0F01,
        motion: 0x0F02,
        camera: 0x0F03,
        end: 0x0F7F,
        result: 0x0F81,
        report: 0x0F82,
        summary: 0x0F83,
    };

    /// The id expected for packets of type `t`.
    pub fn of(&self, t: PacketType) -> u16 {
        match t {
            PacketType::Frame => self.frame,
            PacketType::Motion => self.motion,
            PacketType::Camera => self.camera,
            PacketType::End => self.end,
            PacketType::Result => self.result,
            PacketType::Report => self.report,
            PacketType::Summary => self.summary,
        }
    }
}

impl Default for DataIds {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The CRC's implementation: one 256-entry table (1 KiB of flash), about
/// five instructions a byte on the Cortex-M4F; `docs/VEHICLE.md` ("The link") gives
/// the measured trade-off against no table and 16 tables. (The decoder
/// runs its own register over this table, a word at a time, inside its
/// pass over the points: see `decode`.)
pub(crate) type CrcTable = Table<1>;

/// CRC-32/AUTOSAR (polynomial `0xF4ACFB13`, reflected, init and xorout
/// `0xFFFFFFFF`).
pub(crate) static CRC: Crc<u32, CrcTable> = Crc::<u32, CrcTable>::new(&crc::CRC_32_AUTOSAR);

/// What the CRC register gives over a packet *including* its CRC (low
/// byte first) when the packet is intact: the decoder checks that instead
/// of locating the last four bytes first.
pub(crate) const RESIDUE: u32 = {
    let c = CRC.checksum(&[]);
    CRC.checksum(&c.to_le_bytes())
};

/// The raw value of a point coordinate of −1 px (the image's margin).
///
/// A coordinate `px` is sent as `raw = 16 (px + 1) + 0x0101`: 1/16 px
/// steps, from −1 px (the margin) up to 4078.875 px. The offset `0x0101`
/// keeps every byte of an integer or half-pixel coordinate non-zero (the
/// high byte is at least 1; the low byte of `16 k + 1` never 0), and those
/// are what row-scanning detectors report: in COBS a zero byte ends a run,
/// and each run costs the decoder a fixed overhead, so point data without
/// zeros is decoded in long runs.
pub(crate) const RAW_MINUS_ONE_PX: u16 = 0x0101;

/// A point coordinate on the wire → pixels: `raw / 16 − 17.0625`, i.e.
/// `(raw − 0x0101) / 16 − 1` (exact in `f32`).
///
/// Computed without a conversion instruction: the `f32` with the bits
/// `0x4900_0000 | raw` is `2^19 + raw / 16` (the numbers of `[2^19, 2^20)`
/// step by 1/16 and `raw` fills the low 16 of the 23 fraction bits), and
/// subtracting `2^19 + 17.0625` is exact (the operands are within a factor
/// of two of each other), so the result is the same as
/// `f32::from(raw) * 0.0625 - 17.0625`, bit for bit.
#[inline(always)]
pub fn raw_to_px(raw: u16) -> f32 {
    // 2^19 + 17.0625 (exact in `f32`).
    const BIAS: f32 = 524_288.0 + 17.0625;
    f32::from_bits(0x4900_0000 | u32::from(raw)) - BIAS
}

/// Pixels → a point coordinate on the wire, rounded to the nearest
/// 1/16 px (a tie upwards); `None` below −1 px or above 4078.875 px (after
/// rounding) or not finite.
///
/// Exact: `16 px` is exact in `f32`, and so are its whole part and the
/// remainder (both within `2^17`); the rounding is decided on those. (An
/// adversarial review found the sum `(px + 1) · 16 + 257 + 0.5` rounded
/// twice: 1 448 of the 744 million `f32` in range went to the other
/// sixteenth, `−1.0312504` px to −1 px instead of `None`.)
pub fn px_to_raw(px: f32) -> Option<u16> {
    // (NaN fails; the bounds keep `16 px` within `i32` exactly.)
    if !(-2.0..=4100.0).contains(&px) {
        return None;
    }
    let y = px * 16.0;
    // `y as i32` truncates towards 0; one less below a negative `y`'s.
    let t = y as i32;
    let whole = if (t as f32) > y { t - 1 } else { t };
    let n = whole + i32::from(y - whole as f32 >= 0.5);
    // raw = 16 (px + 1) + 257 at the rounded `px`.
    let raw = n + 16 + i32::from(RAW_MINUS_ONE_PX);
    u16::try_from(raw).ok().filter(|&r| r >= RAW_MINUS_ONE_PX)
}

/// A localisation-error radius on the wire (1/256 px) → pixels.
#[inline(always)]
pub fn raw_to_radius(raw: u16) -> f32 {
    f32::from(raw) / 256.0
}

/// Pixels → a radius on the wire, rounded up to the next 1/256 px (so
/// the bound is never lowered); `None` above [`MAX_RADIUS_PX`], negative
/// or NaN.
pub fn radius_to_raw(px: f32) -> Option<u16> {
    if !(0.0..=MAX_RADIUS_PX).contains(&px) {
        return None;
    }
    let t = px * 256.0;
    let r = t as u16;
    Some(if f32::from(r) < t { r + 1 } else { r })
}

#[cfg(test)]
mod tests;
