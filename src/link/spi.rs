//! The SPI front end: embedded-hal 1.0 [`SpiDevice`] plus a data-ready
//! [`InputPin`].
//!
//! # Protocol
//! The front end raises data-ready while it holds a packet. The controller
//! then reads, in separate transactions (a transaction's operations are
//! fixed before chip select goes down, so the length cannot steer the one
//! it is read in):
//! 1. a 4-byte header: the length `n` of the packet's link bytes (COBS
//!    frame with its delimiter), `u16` little endian, then `!n` (its
//!    complement, so a floating or stuck bus is told from a length);
//! 2. the `n` bytes, in transactions of up to [`SPI_CHUNK`] bytes, each
//!    going on where the last stopped.
//!
//! Each transaction is one [`SpiDevice::transaction`] of a single
//! [`Operation::Read`] (the controller clocks out whatever the device
//! sends back on MOSI; a mock expects exactly these reads: 4 bytes, then
//! chunks of `min(SPI_CHUNK, what is left)`).
//!
//! Each chunk goes to the [`Receiver`] as it arrives, so no packet buffer
//! is needed and a short read or a corrupt byte is the decoder's typed
//! error. A bus error ends the packet in progress where it stands and the
//! next packet decodes as usual ([`Error::Bus`] says what the receiver
//! makes of the cut one).

use embedded_hal::digital::InputPin;
use embedded_hal::spi::{Operation, SpiDevice};

use super::{cut, Error};
use crate::wire::{cobs_max, input_packet_max, Event, Receiver};

/// Bytes of the length header.
pub const SPI_HEADER_LEN: usize = 4;
/// Bytes read per body transaction.
pub const SPI_CHUNK: usize = 64;

/// The SPI link driver.
#[derive(Debug)]
pub struct SpiLink<SPI, DR> {
    spi: SPI,
    ready: DR,
    chunk: [u8; SPI_CHUNK],
}

impl<SPI: SpiDevice, DR: InputPin> SpiLink<SPI, DR> {
    /// A driver over `spi` with the data-ready pin `ready`.
    pub fn new(spi: SPI, ready: DR) -> Self {
        Self {
            spi,
            ready,
            chunk: [0; SPI_CHUNK],
        }
    }

    /// Give back the bus and the pin.
    pub fn release(self) -> (SPI, DR) {
        (self.spi, self.ready)
    }

    /// If data-ready is high, read one packet and feed it to `rx`, whose
    /// events go to `on`; `Ok(false)` when no data was ready. Bounded: one
    /// header and at most `len / SPI_CHUNK + 1` body transactions, `len`
    /// limited by the header's `u16`.
    pub fn poll<const N: usize, const B: usize>(
        &mut self,
        rx: &mut Receiver<N, B>,
        mut on: impl FnMut(Event<'_, N, B>),
    ) -> Result<bool, Error<SPI::Error, DR::Error>> {
        if !self.ready.is_high().map_err(Error::Pin)? {
            return Ok(false);
        }
        let mut head = [0u8; SPI_HEADER_LEN];
        self.spi
            .transaction(&mut [Operation::Read(&mut head)])
            .map_err(Error::Bus)?;
        let [a, b, c, d] = head;
        let len = u16::from_le_bytes([a, b]);
        if len == 0 || u16::from_le_bytes([c, d]) != !len {
            return Err(Error::BadHeader { raw: head });
        }
        // (Any packet the receiver takes: at a small capacity a motion
        // packet is larger than the largest frame packet.)
        let max = u16::try_from(cobs_max(input_packet_max(N, B))).unwrap_or(u16::MAX);
        let too_large = len > max;
        let mut left = usize::from(len);
        while left > 0 {
            let n = left.min(SPI_CHUNK);
            let Some(buf) = self.chunk.get_mut(..n) else {
                break;
            };
            if let Err(e) = self.spi.transaction(&mut [Operation::Read(buf)]) {
                if !too_large {
                    cut(rx, &mut on);
                }
                return Err(Error::Bus(e));
            }
            if !too_large {
                rx.feed(buf, &mut on);
            }
            left -= n;
        }
        if too_large {
            return Err(Error::TooLarge { len, max });
        }
        Ok(true)
    }
}
