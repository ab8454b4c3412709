//! The UART link: embedded-io [`Read`] for the packets coming in,
//! [`Write`] for the results going out.

use embedded_io::{Read, Write};

use super::{cut, Error};
use crate::wire::encode::{self, Count, EncodeError, ResultHead, Sink};
use crate::wire::{CrcTable, PacketType, CRC};
use crate::wire::{Event, Receiver};
use crate::Step;

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
/// [`crate::wire::encode::cobs_frame`] gives, with a buffer of one COBS
/// block (255 bytes) in place of one for the whole framed packet. Each
/// `write` must take at least one byte ([`Error::WriteZero`] if one takes
/// none; embedded-io's `write_all` panics there); at most one `write` a
/// byte. After an error the packet is cut where it stands, without its
/// delimiter: write a `0x00` before the next packet, so that the
/// receiver drops only the cut one (its bytes and the next packet's would
/// otherwise decode as one, both refused).
pub fn write_packet<W: Write>(w: &mut W, raw: &[u8]) -> Result<(), Error<W::Error>> {
    let mut f = Framer::new(w);
    f.put_raw(raw)?;
    f.finish()
}

/// Encode a result packet ([`crate::wire::encode::result`]: the same
/// bytes, framed as [`write_packet`] frames them) straight to `w`, with no
/// buffer for the packet: a 2 × 256-point result is about 10.8 KB, which
/// `encode::result` and `write_packet` need in RAM. The structure is read
/// twice (its length goes in the header, before it), the CRC taken as
/// the bytes go. [`Error::Encode`] (nothing written) for a structure the
/// format cannot hold; otherwise as [`write_packet`].
pub fn write_result<W: Write, const N: usize, const B: usize>(
    w: &mut W,
    data_id: u16,
    counter: u16,
    head: &ResultHead,
    step: &Step<'_, N, B>,
    quality: &[u8],
) -> Result<(), Error<W::Error>> {
    let mut count = Count(0);
    encode::result_payload(&mut count, head, step, quality)?;
    let len = u16::try_from(count.0).map_err(|_| EncodeError::TooLarge)?;
    let mut out = Packet {
        framer: Framer::new(w),
        crc: CRC.digest(),
    };
    out.put(&encode::header(PacketType::Result, data_id, counter, len))?;
    encode::result_payload(&mut out, head, step, quality)?;
    let crc = out.crc.finalize();
    out.framer.put_raw(&crc.to_le_bytes())?;
    out.framer.finish()
}

/// The most bytes of a COBS block without its code byte.
const COBS_RUN: usize = 254;

/// COBS framing as the bytes come: a block is written when it is
/// complete (a zero ends it, or its 254th byte), its code byte first.
struct Framer<'w, W> {
    w: &'w mut W,
    /// The block: its code byte's place, then its bytes.
    block: [u8; COBS_RUN + 1],
    len: usize,
    /// The last block written was a full one (254 bytes, no zero taken).
    full: bool,
}

impl<'w, W: Write> Framer<'w, W> {
    fn new(w: &'w mut W) -> Self {
        Self {
            w,
            block: [0; COBS_RUN + 1],
            len: 0,
            full: false,
        }
    }

    fn put_raw(&mut self, bytes: &[u8]) -> Result<(), Error<W::Error>> {
        for &b in bytes {
            if b == 0 {
                // The zero ends the block (taken, not written).
                self.emit()?;
                self.full = false;
            } else {
                if let Some(d) = self.block.get_mut(self.len + 1) {
                    *d = b;
                }
                self.len += 1;
                if self.len >= COBS_RUN {
                    self.emit()?;
                    self.full = true;
                }
            }
        }
        Ok(())
    }

    /// Write the block, its code byte its length plus one.
    fn emit(&mut self) -> Result<(), Error<W::Error>> {
        let len = self.len.min(COBS_RUN);
        self.block[0] = u8::try_from(len + 1).unwrap_or(u8::MAX);
        self.len = 0;
        write_all(self.w, self.block.get(..=len).unwrap_or(&[]))
    }

    /// The last block (none after a full one: no zero follows it), the
    /// delimiter, and a flush.
    fn finish(mut self) -> Result<(), Error<W::Error>> {
        if self.len > 0 || !self.full {
            self.emit()?;
        }
        write_all(self.w, &[0])?;
        self.w.flush().map_err(Error::Bus)
    }
}

/// A result packet's bytes into the framer, their CRC taken.
struct Packet<'w, W> {
    framer: Framer<'w, W>,
    crc: crc::Digest<'static, u32, CrcTable>,
}

impl<W: Write> Sink for Packet<'_, W> {
    type Error = Error<W::Error>;
    fn put(&mut self, b: &[u8]) -> Result<(), Self::Error> {
        self.crc.update(b);
        self.framer.put_raw(b)
    }
}

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
