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
    /// the packet in progress (the receiver reports it truncated).
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

/// COBS-frame the packet `raw` into `scratch` and write it all to `w`.
pub fn write_packet<W: Write>(
    w: &mut W,
    raw: &[u8],
    scratch: &mut [u8],
) -> Result<(), Error<W::Error>> {
    let n = cobs_frame(raw, scratch).map_err(Error::Encode)?;
    let bytes = scratch
        .get(..n)
        .ok_or(Error::Encode(EncodeError::BufferTooSmall))?;
    w.write_all(bytes).map_err(Error::Bus)?;
    w.flush().map_err(Error::Bus)
}
