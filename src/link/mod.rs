//! Thin drivers that move the [`crate::wire`] bytes: an SPI front end with
//! a data-ready pin ([`SpiLink`], embedded-hal 1.0) and a UART
//! ([`UartLink`], embedded-io). Both feed a [`Receiver`] and hand its
//! events to the caller; neither buffers more than one fixed-size chunk.
//!
//! Errors wrap the HAL's own error type ([`Error::Bus`]).

mod spi;
mod uart;

pub use spi::{SpiLink, SPI_CHUNK, SPI_HEADER_LEN};
pub use uart::{write_packet, write_result, UartLink, UART_CHUNK};

use core::fmt;

/// A driver's error: the bus's or pin's own error, what the link's
/// framing found before any byte reached the decoder, or, writing, a bus
/// that takes nothing ([`Error::WriteZero`]) or a buffer too small.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error<E, P = core::convert::Infallible> {
    /// The bus (SPI or UART) failed. Reading, the packet in progress ends
    /// where it stands, as at a delimiter: a cut packet is refused
    /// (`truncated`, or `bad_crc` where the bytes before the cut end one
    /// of its COBS runs and decode to 14 bytes or more), one that lacked
    /// only its delimiter is taken, a cut before any of its bytes reports
    /// nothing, and the bytes after the error start a new packet (the rest
    /// of a cut one refused in turn). Writing, what was written of the
    /// packet stays written.
    Bus(E),
    /// Writing, the bus accepted no byte of a non-empty buffer (`Ok(0)`,
    /// which embedded-io's `Write::write` contract rules out: a driver
    /// that breaks it gets this error, where `write_all` would panic); what
    /// was written of the packet stays written.
    WriteZero,
    /// The data-ready pin could not be read.
    Pin(P),
    /// The SPI length header is not valid (its check bytes disagree, or
    /// the length is 0): nothing was read after it.
    BadHeader {
        /// The header's four bytes.
        raw: [u8; SPI_HEADER_LEN],
    },
    /// The SPI length header announces more bytes than the largest packet
    /// of this capacity: the bytes were read and dropped.
    TooLarge {
        /// Announced length.
        len: u16,
        /// The largest accepted.
        max: u16,
    },
    /// Writing a result, the structure is too large for the format (more
    /// than 255 boundaries, or 65 535 points or bytes): nothing was
    /// written.
    Encode(crate::wire::encode::EncodeError),
}

impl<E: fmt::Debug, P: fmt::Debug> fmt::Display for Error<E, P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Bus(e) => write!(f, "bus error: {e:?}"),
            Self::WriteZero => f.write_str("the bus accepted no byte of a write"),
            Self::Pin(e) => write!(f, "data-ready pin error: {e:?}"),
            Self::BadHeader { raw } => write!(f, "bad SPI length header {raw:02x?}"),
            Self::TooLarge { len, max } => {
                write!(f, "packet of {len} bytes announced, at most {max}")
            }
            Self::Encode(e) => write!(f, "{e}"),
        }
    }
}

impl<E: fmt::Debug, P: fmt::Debug> core::error::Error for Error<E, P> {}

impl<E, P> From<crate::wire::encode::EncodeError> for Error<E, P> {
    fn from(e: crate::wire::encode::EncodeError) -> Self {
        Self::Encode(e)
    }
}

use crate::wire::Receiver;

/// End the packet in progress (after a bus error): the receiver sees a
/// delimiter, reports the cut packet and starts afresh. The delimiter is
/// not a byte the bus delivered: [`crate::wire::Counters::bytes`] does not
/// count it (an adversary found every bus error counted a byte).
fn cut<const N: usize, const B: usize>(
    rx: &mut Receiver<N, B>,
    on: &mut impl FnMut(crate::wire::Event<'_, N, B>),
) {
    rx.feed_uncounted(&[0], on);
}

#[cfg(test)]
mod tests;
