//! The UART link: embedded-io [`Read`] for the packets coming in,
//! [`Write`] for the results going out.

use embedded_io::{Read, Write};

use super::{cut, Error};
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

/// COBS-frame the packet `raw` as it is written to `w`, then the `0x00`
/// delimiter, then flush: the same bytes as
/// [`crate::wire::encode::cobs_frame`] gives, without a buffer for them
/// (each block's code byte, then its bytes straight from `raw`; a result
/// packet of 2 × 256 points is about 10.8 KB, which a framing buffer
/// would double). Each `write` must take at least one byte
/// ([`Error::WriteZero`] if one takes none; embedded-io's `write_all`
/// panics there); at most one `write` a byte.
pub fn write_packet<W: Write>(w: &mut W, raw: &[u8]) -> Result<(), Error<W::Error>> {
    let mut rest = raw;
    // Each block takes at least one byte of `raw` but the last: at most
    // `raw.len() + 1` blocks.
    for _ in 0..=raw.len() {
        // A block: up to 254 bytes without a zero, then the zero it ends
        // at (taken, not written), the code byte their count plus one.
        let run = rest.iter().take(COBS_RUN).position(|&b| b == 0);
        let len = run.unwrap_or(rest.len().min(COBS_RUN));
        let (block, after) = rest.split_at_checked(len).unwrap_or((rest, &[]));
        write_all(w, &[u8::try_from(len + 1).unwrap_or(u8::MAX)])?;
        write_all(w, block)?;
        match run {
            // The zero taken: a block follows, empty if `raw` ends here.
            Some(_) => rest = after.get(1..).unwrap_or(&[]),
            None if after.is_empty() => break,
            None => rest = after,
        }
    }
    write_all(w, &[0])?;
    w.flush().map_err(Error::Bus)
}

/// The most bytes of a COBS block without its code byte.
const COBS_RUN: usize = 254;

/// All of `bytes` to `w`, one `write` a byte at most.
fn write_all<W: Write>(w: &mut W, bytes: &[u8]) -> Result<(), Error<W::Error>> {
    let mut rest = bytes;
    for _ in 0..bytes.len() {
        if rest.is_empty() {
            break;
        }
        match w.write(rest).map_err(Error::Bus)? {
            0 => return Err(Error::WriteZero),
            // (A writer that claims more than it was given has taken it all.)
            k => rest = rest.get(k..).unwrap_or(&[]),
        }
    }
    Ok(())
}
