//! The link's typed errors.

use core::fmt;

use crate::{BoundaryError, CameraError, ConfigError, MotionError};

/// Why a packet was not taken, or what the receiver noticed about one.
///
/// Every error but [`WireError::CounterJump`] discards the packet, and
/// none of them changes the decoder's camera or the processor's kept
/// state. Nor its counters, with one exception (`docs/wire.md`): a packet
/// intact up to its content (CRC, header and counter checked out, the
/// content then rejected) records its counter as received, so the next
/// good packet of its data id counts it neither missed nor repeated.
/// Otherwise the next good packet gives exactly what it would have given
/// had the bad one never come. (An adversarial review found this
/// paragraph claiming no exception.)
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum WireError {
    /// The frame delimiter came early: inside a COBS run, or before a
    /// whole header and CRC (`len` bytes decoded).
    Truncated {
        /// Bytes decoded before the delimiter.
        len: u32,
    },
    /// The CRC over the packet does not check out (corrupt bytes).
    BadCrc,
    /// The packet does not start with [`MAGIC`](super::MAGIC).
    BadMagic,
    /// A format version this decoder does not read.
    UnknownVersion {
        /// The version byte.
        version: u8,
    },
    /// A packet type this receiver does not take.
    UnknownType {
        /// The type byte.
        code: u8,
    },
    /// The payload length disagrees with the packet's size or content.
    BadLength {
        /// The length field.
        declared: u32,
        /// What the packet holds (or its content needs).
        actual: u32,
    },
    /// The data id is not the one configured for this packet type.
    WrongDataId {
        /// Configured.
        expected: u16,
        /// Received.
        got: u16,
    },
    /// The same counter as the last packet of this data id: a repeat,
    /// dropped.
    Repeated {
        /// The counter.
        counter: u16,
    },
    /// Packets of this data id were lost before this one (which is taken).
    CounterJump {
        /// How many counters were skipped.
        missed: u16,
    },
    /// A frame packet before any camera packet.
    NoCamera,
    /// The frame's image size is not the camera's.
    ImageSize {
        /// Width in the packet.
        width: u16,
        /// Height in the packet.
        height: u16,
    },
    /// More boundaries than the capacity `B`.
    TooManyBoundaries {
        /// Boundaries in the packet.
        count: u8,
        /// Capacity.
        capacity: u8,
    },
    /// More points on a boundary than the capacity `N`.
    TooManyPoints {
        /// Boundary (position in the packet).
        boundary: u8,
        /// Points in the packet.
        len: u16,
        /// Capacity.
        capacity: u16,
    },
    /// A boundary's index is not its position in the packet.
    BoundaryIndex {
        /// Its position.
        expected: u8,
        /// Its index field.
        got: u8,
    },
    /// A boundary's localisation-error radius is above
    /// [`MAX_RADIUS_PX`](super::MAX_RADIUS_PX).
    Radius {
        /// Boundary.
        boundary: u8,
    },
    /// A boundary's points are invalid (as [`crate::Frame::push_boundary`]
    /// says).
    Boundary {
        /// Boundary.
        boundary: u8,
        /// Why.
        error: BoundaryError,
    },
    /// The camera packet's intrinsics are invalid.
    Camera(CameraError),
    /// The motion packet's motion is invalid.
    Motion(MotionError),
    /// The motion packet's error bounds are invalid.
    MotionBounds(ConfigError),
    /// A frame's motion packet is for another frame pair (the frame is
    /// taken as a new first frame).
    MotionMismatch {
        /// The kept frame.
        kept: u32,
        /// This frame.
        frame: u32,
        /// The motion's from-frame.
        from: u32,
        /// The motion's to-frame.
        to: u32,
    },
    /// A frame came with no motion packet since the last frame (the frame
    /// is taken as a new first frame).
    MissingMotion {
        /// The kept frame.
        kept: u32,
        /// This frame.
        frame: u32,
    },
}

/// The kind of a [`WireError`], its code in a report packet and its name
/// in tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
#[allow(missing_docs)]
#[non_exhaustive]
pub enum ErrorKind {
    Truncated = 1,
    BadCrc,
    BadMagic,
    UnknownVersion,
    UnknownType,
    BadLength,
    WrongDataId,
    Repeated,
    CounterJump,
    NoCamera,
    ImageSize,
    TooManyBoundaries,
    TooManyPoints,
    BoundaryIndex,
    Radius,
    Boundary,
    Camera,
    Motion,
    MotionBounds,
    MotionMismatch,
    MissingMotion,
}

impl ErrorKind {
    /// Every kind, in code order (code = position + 1).
    pub const ALL: [ErrorKind; 21] = [
        Self::Truncated,
        Self::BadCrc,
        Self::BadMagic,
        Self::UnknownVersion,
        Self::UnknownType,
        Self::BadLength,
        Self::WrongDataId,
        Self::Repeated,
        Self::CounterJump,
        Self::NoCamera,
        Self::ImageSize,
        Self::TooManyBoundaries,
        Self::TooManyPoints,
        Self::BoundaryIndex,
        Self::Radius,
        Self::Boundary,
        Self::Camera,
        Self::Motion,
        Self::MotionBounds,
        Self::MotionMismatch,
        Self::MissingMotion,
    ];

    /// The kind with report code `c`.
    pub fn from_code(c: u8) -> Option<Self> {
        Self::ALL.get(usize::from(c).checked_sub(1)?).copied()
    }

    /// Short lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Truncated => "truncated",
            Self::BadCrc => "bad_crc",
            Self::BadMagic => "bad_magic",
            Self::UnknownVersion => "unknown_version",
            Self::UnknownType => "unknown_type",
            Self::BadLength => "bad_length",
            Self::WrongDataId => "wrong_data_id",
            Self::Repeated => "repeated",
            Self::CounterJump => "counter_jump",
            Self::NoCamera => "no_camera",
            Self::ImageSize => "image_size",
            Self::TooManyBoundaries => "too_many_boundaries",
            Self::TooManyPoints => "too_many_points",
            Self::BoundaryIndex => "boundary_index",
            Self::Radius => "radius",
            Self::Boundary => "invalid_boundary",
            Self::Camera => "invalid_camera",
            Self::Motion => "invalid_motion",
            Self::MotionBounds => "invalid_motion_bounds",
            Self::MotionMismatch => "motion_mismatch",
            Self::MissingMotion => "missing_motion",
        }
    }
}

impl fmt::Display for ErrorKind {
    /// [`ErrorKind::name`].
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl WireError {
    /// The kind.
    pub fn kind(&self) -> ErrorKind {
        match self {
            Self::Truncated { .. } => ErrorKind::Truncated,
            Self::BadCrc => ErrorKind::BadCrc,
            Self::BadMagic => ErrorKind::BadMagic,
            Self::UnknownVersion { .. } => ErrorKind::UnknownVersion,
            Self::UnknownType { .. } => ErrorKind::UnknownType,
            Self::BadLength { .. } => ErrorKind::BadLength,
            Self::WrongDataId { .. } => ErrorKind::WrongDataId,
            Self::Repeated { .. } => ErrorKind::Repeated,
            Self::CounterJump { .. } => ErrorKind::CounterJump,
            Self::NoCamera => ErrorKind::NoCamera,
            Self::ImageSize { .. } => ErrorKind::ImageSize,
            Self::TooManyBoundaries { .. } => ErrorKind::TooManyBoundaries,
            Self::TooManyPoints { .. } => ErrorKind::TooManyPoints,
            Self::BoundaryIndex { .. } => ErrorKind::BoundaryIndex,
            Self::Radius { .. } => ErrorKind::Radius,
            Self::Boundary { .. } => ErrorKind::Boundary,
            Self::Camera(_) => ErrorKind::Camera,
            Self::Motion(_) => ErrorKind::Motion,
            Self::MotionBounds(_) => ErrorKind::MotionBounds,
            Self::MotionMismatch { .. } => ErrorKind::MotionMismatch,
            Self::MissingMotion { .. } => ErrorKind::MissingMotion,
        }
    }

    /// The error's details as a report packet carries them: `(sub, a,
    /// [b, c, d, e])` (see `docs/wire.md`, "Report packet").
    pub fn details(&self) -> (u8, u16, [u32; 4]) {
        let z = [0; 4];
        match *self {
            Self::Truncated { len } => (0, 0, [len, 0, 0, 0]),
            Self::BadCrc | Self::BadMagic | Self::NoCamera => (0, 0, z),
            Self::UnknownVersion { version } => (version, 0, z),
            Self::UnknownType { code } => (code, 0, z),
            Self::BadLength { declared, actual } => (0, 0, [declared, actual, 0, 0]),
            Self::WrongDataId { expected, got } => (0, got, [u32::from(expected), 0, 0, 0]),
            Self::Repeated { counter } => (0, counter, z),
            Self::CounterJump { missed } => (0, missed, z),
            Self::ImageSize { width, height } => (0, width, [u32::from(height), 0, 0, 0]),
            Self::TooManyBoundaries { count, capacity } => {
                (count, 0, [u32::from(capacity), 0, 0, 0])
            }
            Self::TooManyPoints {
                boundary,
                len,
                capacity,
            } => (boundary, len, [u32::from(capacity), 0, 0, 0]),
            Self::BoundaryIndex { expected, got } => (expected, u16::from(got), z),
            Self::Radius { boundary } => (boundary, 0, z),
            Self::Boundary { boundary, error } => {
                let (code, index) = match error {
                    BoundaryError::TooFewPoints => (1, 0),
                    BoundaryError::TooManyPoints { len, .. } => (2, len),
                    BoundaryError::TooManyBoundaries => (3, 0),
                    BoundaryError::NotFinite { index } => (4, index),
                    BoundaryError::OutsideImage { index } => (5, index),
                    BoundaryError::Duplicate { index } => (6, index),
                    BoundaryError::Unordered { index } => (7, index),
                };
                let index = u32::try_from(index).unwrap_or(u32::MAX);
                (boundary, code, [index, 0, 0, 0])
            }
            Self::Camera(e) => (e as u8, 0, z),
            Self::Motion(e) => (e as u8, 0, z),
            Self::MotionBounds(e) => (e as u8, 0, z),
            Self::MotionMismatch {
                kept,
                frame,
                from,
                to,
            } => (0, 0, [kept, frame, from, to]),
            Self::MissingMotion { kept, frame } => (0, 0, [kept, frame, 0, 0]),
        }
    }
}

/// The library's own error behind a boundary, camera or motion packet's
/// refusal is part of the message (`Display`), so `source` gives none: a
/// reporter that walks the chain would print it twice.
impl core::error::Error for WireError {}

impl fmt::Display for WireError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Truncated { len } => write!(f, "packet cut short after {len} bytes"),
            Self::BadCrc => f.write_str("CRC mismatch"),
            Self::BadMagic => f.write_str("not a roadstereo packet (magic)"),
            Self::UnknownVersion { version } => write!(f, "unknown format version {version}"),
            Self::UnknownType { code } => write!(f, "unexpected packet type {code:#04x}"),
            Self::BadLength { declared, actual } => {
                write!(f, "payload length {declared}, packet has {actual}")
            }
            Self::WrongDataId { expected, got } => {
                write!(f, "data id {got:#06x}, expected {expected:#06x}")
            }
            Self::Repeated { counter } => write!(f, "repeated counter {counter}"),
            Self::CounterJump { missed } => write!(f, "{missed} packets lost"),
            Self::NoCamera => f.write_str("frame before any camera packet"),
            Self::ImageSize { width, height } => {
                write!(f, "image {width} x {height} is not the camera's")
            }
            Self::TooManyBoundaries { count, capacity } => {
                write!(f, "{count} boundaries, capacity {capacity}")
            }
            Self::TooManyPoints {
                boundary,
                len,
                capacity,
            } => write!(f, "boundary {boundary}: {len} points, capacity {capacity}"),
            Self::BoundaryIndex { expected, got } => {
                write!(f, "boundary {expected} has index {got}")
            }
            Self::Radius { boundary } => {
                write!(f, "boundary {boundary}: error radius above 100 px")
            }
            Self::Boundary { boundary, error } => write!(f, "boundary {boundary}: {error}"),
            Self::Camera(e) => write!(f, "camera packet: {e}"),
            Self::Motion(e) => write!(f, "motion packet: {e}"),
            Self::MotionBounds(e) => write!(f, "motion packet bounds: {e}"),
            Self::MotionMismatch {
                kept,
                frame,
                from,
                to,
            } => write!(
                f,
                "motion {from} -> {to} does not pair kept frame {kept} with frame {frame}"
            ),
            Self::MissingMotion { kept, frame } => {
                write!(f, "no motion from kept frame {kept} to frame {frame}")
            }
        }
    }
}
