//! The vehicle's side: parsing the controller's output packets (result,
//! report, summary) once a COBS frame has been decoded into a buffer (for
//! instance with `cobs::decode_in_place`).

use super::{
    ErrorKind, PacketType, WireError, CRC, CRC_LEN, HEADER_LEN, MAGIC, REPORT_LEN,
    RESULT_BOUNDARY_LEN, RESULT_HEAD_LEN, VERSION,
};
use crate::structure::STATUS_COUNT;
use crate::Status;

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

/// A checked packet: its type, data id, counter and payload.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Checked<'a> {
    /// Type.
    pub ptype: PacketType,
    /// Data id.
    pub data_id: u16,
    /// Counter.
    pub counter: u16,
    /// Payload.
    pub payload: &'a [u8],
}

/// Check a whole decoded packet (header, length, CRC).
pub fn check(raw: &[u8]) -> Result<Checked<'_>, WireError> {
    let len = u32::try_from(raw.len()).unwrap_or(u32::MAX);
    if raw.len() < HEADER_LEN + CRC_LEN {
        return Err(WireError::Truncated { len });
    }
    let body = raw.get(..raw.len() - CRC_LEN).unwrap_or(&[]);
    if CRC.checksum(body) != le32(raw, raw.len() - CRC_LEN) {
        return Err(WireError::BadCrc);
    }
    if raw.get(..2) != Some(&MAGIC[..]) {
        return Err(WireError::BadMagic);
    }
    let version = raw.get(2).copied().unwrap_or(0);
    if version != VERSION {
        return Err(WireError::UnknownVersion { version });
    }
    let code = raw.get(3).copied().unwrap_or(0);
    let ptype = PacketType::from_code(code).ok_or(WireError::UnknownType { code })?;
    let declared = u32::from(le16(raw, 8));
    let actual = len - (HEADER_LEN + CRC_LEN) as u32;
    if declared != actual {
        return Err(WireError::BadLength { declared, actual });
    }
    Ok(Checked {
        ptype,
        data_id: le16(raw, 4),
        counter: le16(raw, 6),
        payload: body.get(HEADER_LEN..).unwrap_or(&[]),
    })
}

/// A report packet's content.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Report {
    /// The error's kind.
    pub kind: ErrorKind,
    /// Its details (see [`WireError::details`]).
    pub details: (u8, u16, [u32; 4]),
}

/// Parse a summary payload (the controller's answer to an end packet:
/// the receiver's [`super::Counters`], as [`super::Counters::values`]
/// orders them), or `None` if its length is not a summary's.
pub fn summary(payload: &[u8]) -> Option<super::Counters> {
    let mut v = [0u32; 4 + ErrorKind::ALL.len()];
    if payload.len() != 4 * v.len() {
        return None;
    }
    for (k, d) in v.iter_mut().enumerate() {
        *d = le32(payload, 4 * k);
    }
    let [bytes, frames, motions, cameras, ..] = v;
    let mut errors = [0u32; ErrorKind::ALL.len()];
    for (d, s) in errors.iter_mut().zip(v.iter().skip(4)) {
        *d = *s;
    }
    Some(super::Counters {
        bytes,
        frames,
        motions,
        cameras,
        errors,
    })
}

/// Parse a report payload.
pub fn report(payload: &[u8]) -> Option<Report> {
    if payload.len() != REPORT_LEN {
        return None;
    }
    Some(Report {
        kind: ErrorKind::from_code(*payload.first()?)?,
        details: (
            *payload.get(1)?,
            le16(payload, 2),
            [
                le32(payload, 4),
                le32(payload, 8),
                le32(payload, 12),
                le32(payload, 16),
            ],
        ),
    })
}

/// One point of a result.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PointView {
    /// Its status.
    pub status: Status,
    /// `(X, Y, Z, z_near, z_far)` when the status has a depth.
    pub values: Option<[f32; 5]>,
}

/// One boundary of a result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResultBoundary<'a> {
    /// Points.
    pub len: u16,
    /// The kept frame's quality value for it.
    pub quality: u8,
    bytes: &'a [u8],
}

impl ResultBoundary<'_> {
    /// The points, in frame-1 order.
    pub fn points(&self) -> impl Iterator<Item = PointView> + '_ {
        let mut at = 0usize;
        (0..self.len).map_while(move |_| {
            let code = *self.bytes.get(at)?;
            let status = *Status::ALL.get(usize::from(code))?;
            at += 1;
            let values = if status.has_depth() {
                let v = |i: usize| f32::from_bits(le32(self.bytes, at + 4 * i));
                let vals = [v(0), v(1), v(2), v(3), v(4)];
                at += 20;
                Some(vals)
            } else {
                None
            };
            Some(PointView { status, values })
        })
    }
}

/// A parsed result packet.
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResultView<'a> {
    /// The frame (frame 2 of the pair).
    pub frame_id: u32,
    /// The kept frame (frame 1; the frame itself for a first frame).
    pub kept_id: u32,
    /// The frame's exposure timestamp, microseconds.
    pub timestamp_us: u64,
    /// Whether a structure was computed (`false`: the frame was kept as
    /// the first of a new pairing).
    pub structure: bool,
    /// Whether the caller's deadline cut the frame's reconstruction short
    /// (flags bit 0, [`crate::Structure::deadline_expired`]): its
    /// `over_budget` points are then (also) the clock's.
    pub deadline_expired: bool,
    /// Instructions of the per-frame call (0 where not measured).
    pub instructions: u32,
    /// [`crate::Structure::digest`].
    pub digest: u32,
    /// Points per status, indexed like [`Status::ALL`] ([`Self::count`]).
    counts: [u16; STATUS_COUNT],
    boundaries: u8,
    body: &'a [u8],
}

/// Why a result payload could not be parsed: it is shorter than its
/// header, a point's status code is unknown, or the boundaries and points
/// it announces do not fill it exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BadResult;

impl core::fmt::Display for BadResult {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("result payload malformed")
    }
}

impl core::error::Error for BadResult {}

impl<'a> ResultView<'a> {
    /// Parse a result payload (from [`check`]); every boundary and point
    /// is checked to be in the payload.
    pub fn parse(payload: &'a [u8]) -> Result<Self, BadResult> {
        let head = payload.get(..RESULT_HEAD_LEN).ok_or(BadResult)?;
        let mut counts = [0u16; STATUS_COUNT];
        for (i, c) in counts.iter_mut().enumerate() {
            *c = le16(head, 28 + 2 * i);
        }
        let v = ResultView {
            frame_id: le32(head, 0),
            kept_id: le32(head, 4),
            timestamp_us: u64::from(le32(head, 8)) | (u64::from(le32(head, 12)) << 32),
            structure: head.get(16) == Some(&1),
            boundaries: head.get(17).copied().unwrap_or(0),
            deadline_expired: head.get(18).is_some_and(|f| f & 1 != 0),
            instructions: le32(head, 20),
            digest: le32(head, 24),
            counts,
            body: payload.get(RESULT_HEAD_LEN..).unwrap_or(&[]),
        };
        // Walk everything once so the accessors cannot run short.
        let mut at = 0usize;
        for _ in 0..v.boundaries {
            let n = le16(v.body, at);
            at += RESULT_BOUNDARY_LEN;
            for _ in 0..n {
                let code = *v.body.get(at).ok_or(BadResult)?;
                let st = Status::ALL.get(usize::from(code)).ok_or(BadResult)?;
                at += if st.has_depth() { 21 } else { 1 };
            }
        }
        if at != v.body.len() {
            return Err(BadResult);
        }
        Ok(v)
    }

    /// The points with status `s`, as the packet gives it (saturated at
    /// `u16::MAX`).
    pub fn count(&self, s: Status) -> u16 {
        self.counts.get(s as usize).copied().unwrap_or(0)
    }

    /// All points the packet counts.
    pub fn total(&self) -> u64 {
        self.counts.iter().map(|&c| u64::from(c)).sum()
    }

    /// The boundaries.
    pub fn boundaries(&self) -> impl Iterator<Item = ResultBoundary<'a>> + '_ {
        let mut at = 0usize;
        let body = self.body;
        (0..self.boundaries).map_while(move |_| {
            let len = le16(body, at);
            let quality = *body.get(at + 2)?;
            at += RESULT_BOUNDARY_LEN;
            let start = at;
            for _ in 0..len {
                let code = *body.get(at)?;
                at += if Status::ALL.get(usize::from(code))?.has_depth() {
                    21
                } else {
                    1
                };
            }
            Some(ResultBoundary {
                len,
                quality,
                bytes: body.get(start..at)?,
            })
        })
    }

    /// The instructions field set to zero: what a host build, which counts
    /// none, writes for the same frame.
    pub fn zero_instructions(raw: &mut [u8]) {
        let at = HEADER_LEN + 20;
        if let Some(b) = raw.get_mut(at..at + 4) {
            b.fill(0);
        }
        let n = raw.len().saturating_sub(CRC_LEN);
        let crc = CRC.checksum(raw.get(..n).unwrap_or(&[]));
        if let Some(b) = raw.get_mut(n..) {
            for (d, s) in b.iter_mut().zip(crc.to_le_bytes()) {
                *d = s;
            }
        }
    }
}
