//! The UART link: embedded-io [`Read`] for the packets coming in,
//! [`Write`] for the results going out.

use embedded_io::{Read, Write};

use super::{cut, Error};
use crate::wire::encode::{cobs_frame, EncodeError};
use crate::wire::{Event, Receiver};

/// Bytes asked of the UART per read.
pub const UART_CHUNK: usize = 64;

/// The UART link driver.
#[derive(Debug)]
pub struct UartLink<IO> {
    io: IO,
    chunk: [u8; UART_CHUNK],
}

impl<IO: Read + Write> UartLink<IO> {
    /// A driver over `io`.
    pub fn new(io: IO) -> Self {
        Self {
            io,
            chunk: [0; UART_CHUNK],
        }
    }

    /// Give back the UART.
    pub fn release(self) -> IO {
        self.io
    }

    /// The UART, to write on it.
    pub fn io(&mut self) -> &mut IO {
        &mut self.io
    }

    /// One read (blocking until at least one byte came, as
    /// [`Read::read`] does) fed to `rx`; the bytes read. A read error ends
    /// the packet in progress where it stands ([`Error::Bus`] says what
    /// the receiver makes of it).
    pub fn poll<const N: usize, const B: usize>(
        &mut self,
        rx: &mut Receiver<N, B>,
        mut on: impl FnMut(Event<'_, N, B>),
    ) -> Result<usize, Error<IO::Error>> {
        match self.io.read(&mut self.chunk) {
            Ok(n) => {
                rx.feed(self.chunk.get(..n).unwrap_or(&[]), &mut on);
                Ok(n)
            }
            Err(e) => {
                cut(rx, &mut on);
                Err(Error::Bus(e))
            }
        }
    }
}

/// COBS-frame the packet `raw` into `scratch` and write it all to `w`,
/// then flush. At most one `write` a byte: each must take at least one
/// ([`Error::WriteZero`] if one takes none; embedded-io's `write_all`
/// panics there).
pub fn write_packet<W: Write>(
    w: &mut W,
    raw: &[u8],
    scratch: &mut [u8],
) -> Result<(), Error<W::Error>> {
    let n = cobs_frame(raw, scratch).map_err(Error::Encode)?;
    let mut rest = scratch
        .get(..n)
        .ok_or(Error::Encode(EncodeError::BufferTooSmall))?;
    for _ in 0..n {
        if rest.is_empty() {
            break;
        }
        match w.write(rest).map_err(Error::Bus)? {
            0 => return Err(Error::WriteZero),
            // (A writer that claims more than it was given has taken it all.)
            k => rest = rest.get(k..).unwrap_or(&[]),
        }
    }
    w.flush().map_err(Error::Bus)
}
