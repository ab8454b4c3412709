//! The drivers against scripted buses (embedded-hal-mock): a good frame,
//! a bus error mid-frame, a short read, a CRC fault, a frame larger than
//! the capacity, data-ready stuck high. Each gives its typed error and the
//! next good frame decodes.

#![allow(clippy::panic)]

extern crate std;
use std::vec;
use std::vec::Vec;

use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};
use embedded_hal_mock::eh1::digital::{Mock as Pin, State, Transaction as PinT};
use embedded_hal_mock::eh1::spi::{Mock as Spi, Transaction as SpiT};

use super::{Error, SpiLink, UartLink, SPI_CHUNK};
use crate::wire::encode::{self, BoundaryHead, FrameHead};
use crate::wire::{cobs_max, DataIds, Event, Receiver, WireError};
use crate::{Camera, Config, Pixel};

const IDS: DataIds = DataIds::DEFAULT;

fn cam() -> Camera {
    Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap()
}

fn framed(raw: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8; cobs_max(raw.len())];
    let n = encode::cobs_frame(raw, &mut out).unwrap();
    out.truncate(n);
    out
}

fn camera_bytes(counter: u16) -> Vec<u8> {
    let mut raw = [0u8; 64];
    let n = encode::camera(&mut raw, IDS.camera, counter, &cam()).unwrap();
    framed(&raw[..n])
}

fn frame_bytes(counter: u16, id: u32, points: usize) -> Vec<u8> {
    let pts: Vec<Pixel> = (0..points)
        .map(|i| Pixel::new(100.0 + 0.5 * i as f32, 470.0 - i as f32))
        .collect();
    let mut raw = vec![0u8; 8 + crate::wire::frame_packet_max(points, 1)];
    let head = FrameHead {
        timestamp_us: 5,
        frame_id: id,
        width: 512,
        height: 480,
    };
    let b = BoundaryHead {
        quality: 1,
        radius_px: 0.5,
    };
    let n = encode::frame(&mut raw, IDS.frame, counter, &head, &[(b, &pts)]).unwrap();
    framed(&raw[..n])
}

/// SPI transactions for one packet: header, then chunks.
fn spi_script(bytes: &[u8]) -> Vec<SpiT<u8>> {
    let n = bytes.len() as u16;
    let mut head = n.to_le_bytes().to_vec();
    head.extend((!n).to_le_bytes());
    let mut t = vec![
        SpiT::transaction_start(),
        SpiT::read_vec(head),
        SpiT::transaction_end(),
    ];
    for c in bytes.chunks(SPI_CHUNK) {
        t.push(SpiT::transaction_start());
        t.push(SpiT::read_vec(c.to_vec()));
        t.push(SpiT::transaction_end());
    }
    t
}

/// Events seen, as short strings.
fn record(log: &mut Vec<std::string::String>) -> impl FnMut(Event<'_, 32, 2>) + '_ {
    move |e| {
        log.push(match e {
            Event::Frame(j) => std::format!("frame {}", j.info.frame_id),
            Event::Camera(_) => "camera".into(),
            Event::Motion(_) => "motion".into(),
            Event::End => "end".into(),
            Event::Error(e) => std::format!("error {}", e.kind().name()),
        })
    }
}

/// A bus that fails its `fail_at`-th transaction (without touching the
/// mock) and passes the others on.
struct Faulty {
    inner: Spi<u8>,
    n: usize,
    fail_at: usize,
}
impl ErrorType for Faulty {
    type Error = ErrorKind;
}
impl SpiDevice for Faulty {
    fn transaction(&mut self, ops: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        self.n += 1;
        if self.n == self.fail_at {
            return Err(ErrorKind::Other);
        }
        self.inner.transaction(ops)
    }
}

#[test]
fn spi_good_frame_then_faults_each_typed_and_nothing_lost() {
    let cam_b = camera_bytes(0);
    let good = frame_bytes(0, 1, 32);
    let mut crc_bad = frame_bytes(1, 2, 32);
    crc_bad[40] ^= 0x01;
    if crc_bad[40] == 0 {
        crc_bad[40] = 0x02;
    }
    let after_crc = frame_bytes(2, 3, 32);
    // Short read: the front end gives up half way, the rest reads as zeros.
    let short_src = frame_bytes(3, 4, 32);
    let mut short = short_src[..short_src.len() / 2].to_vec();
    short.resize(short_src.len(), 0);
    let after_short = frame_bytes(4, 5, 32);
    // Larger than a Receiver<32, 2> can take: 200 points.
    let huge = frame_bytes(5, 6, 200);
    let after_huge = frame_bytes(6, 7, 32);

    let mut spi_t = Vec::new();
    let mut pin_t = Vec::new();
    for p in [
        &cam_b,
        &good,
        &crc_bad,
        &after_crc,
        &short,
        &after_short,
        &huge,
        &after_huge,
    ] {
        spi_t.extend(spi_script(p));
        pin_t.push(PinT::get(State::High));
    }
    pin_t.push(PinT::get(State::Low));
    let spi = Spi::new(&spi_t);
    let pin = Pin::new(&pin_t);
    let mut link = SpiLink::new(spi, pin);
    let mut rx = Receiver::<32, 2>::new(IDS, Config::DEFAULT);
    let mut log = Vec::new();
    let mut results = Vec::new();
    for _ in 0..9 {
        results.push(link.poll(&mut rx, record(&mut log)));
    }
    assert_eq!(
        results[..6],
        [Ok(true), Ok(true), Ok(true), Ok(true), Ok(true), Ok(true)]
    );
    assert!(
        matches!(results[6], Err(Error::TooLarge { .. })),
        "{:?}",
        results[6]
    );
    assert_eq!(results[7..], [Ok(true), Ok(false)]);
    assert_eq!(
        log,
        [
            "camera",
            "frame 1",
            // The lost packet shows as a counter jump; no motion packets
            // are sent here, so each later frame starts a new pairing.
            "error bad_crc",
            "error counter_jump",
            "error missing_motion",
            "frame 3",
            "error truncated",
            "error counter_jump",
            "error missing_motion",
            "frame 5",
            "error counter_jump",
            "error missing_motion",
            "frame 7"
        ]
    );
    let (mut spi, mut pin) = link.release();
    spi.done();
    pin.done();
}

#[test]
fn spi_bus_error_mid_frame_ends_the_packet_and_the_next_decodes() {
    let cam_b = camera_bytes(0);
    let f1 = frame_bytes(0, 1, 32);
    let f2 = frame_bytes(1, 2, 32);
    let mut spi_t = spi_script(&cam_b);
    // f1: header and its first chunk, then the bus fails on the second
    // chunk (the faulty wrapper answers it: the mock never sees it).
    let s1 = spi_script(&f1);
    spi_t.extend_from_slice(&s1[..6]);
    spi_t.extend(spi_script(&f2));
    let cam_transactions = spi_script(&cam_b).len() / 3;
    let faulty = Faulty {
        inner: Spi::new(&spi_t),
        n: 0,
        fail_at: cam_transactions + 3,
    };
    let pin = Pin::new(&[
        PinT::get(State::High),
        PinT::get(State::High),
        PinT::get(State::High),
    ]);
    let mut link = SpiLink::new(faulty, pin);
    let mut rx = Receiver::<32, 2>::new(IDS, Config::DEFAULT);
    let mut log = Vec::new();
    assert_eq!(link.poll(&mut rx, record(&mut log)), Ok(true));
    assert_eq!(
        link.poll(&mut rx, record(&mut log)),
        Err(Error::Bus(ErrorKind::Other))
    );
    assert_eq!(link.poll(&mut rx, record(&mut log)), Ok(true));
    assert_eq!(log, ["camera", "error truncated", "frame 2"]);
    // The bytes the bus delivered: the cut's delimiter is not one of them.
    let delivered = cam_b.len() + SPI_CHUNK.min(f1.len()) + f2.len();
    assert_eq!(rx.counters().bytes as usize, delivered);
    let (mut spi, mut pin) = link.release();
    spi.inner.done();
    pin.done();
}

/// At a small capacity a motion packet (68 bytes on the link) is larger
/// than the largest frame packet: the SPI driver still takes it, and a
/// camera packet (until a review, it read and dropped a motion packet as
/// `TooLarge` at `B` = 2, `N` = 2).
#[test]
fn spi_small_capacity_takes_motion_and_camera_packets() {
    let cam_b = camera_bytes(0);
    let mut raw = [0u8; 80];
    let m = encode::MotionFields {
        from: 1,
        to: 2,
        translation: [0.0, 0.0, 0.4],
        rotation: [0.0; 3],
        translation_error: None,
        rotation_error: None,
    };
    let n = encode::motion(&mut raw, IDS.motion, 0, &m).unwrap();
    let mot = framed(&raw[..n]);
    assert!(mot.len() > cobs_max(crate::wire::frame_packet_max(2, 2)));
    let mut spi_t = spi_script(&cam_b);
    spi_t.extend(spi_script(&mot));
    let pin = Pin::new(&[PinT::get(State::High), PinT::get(State::High)]);
    let mut link = SpiLink::new(Spi::new(&spi_t), pin);
    let mut rx = Receiver::<2, 2>::new(IDS, Config::DEFAULT);
    let mut log = Vec::new();
    for _ in 0..2 {
        let polled = link.poll(&mut rx, |e| {
            log.push(match e {
                Event::Camera(_) => "camera",
                Event::Motion(_) => "motion",
                _ => "other",
            })
        });
        assert_eq!(polled, Ok(true));
    }
    assert_eq!(log, ["camera", "motion"]);
    let (mut spi, mut pin) = link.release();
    spi.done();
    pin.done();
}

#[test]
fn spi_data_ready_stuck_high_gives_bad_headers_and_returns() {
    // A floating bus reads all ones: the header's check fails every time.
    let mut spi_t = Vec::new();
    for _ in 0..3 {
        spi_t.push(SpiT::transaction_start());
        spi_t.push(SpiT::read_vec(vec![0xFF; 4]));
        spi_t.push(SpiT::transaction_end());
    }
    let mut link = SpiLink::new(
        Spi::new(&spi_t),
        Pin::new(&[
            PinT::get(State::High),
            PinT::get(State::High),
            PinT::get(State::High),
        ]),
    );
    let mut rx = Receiver::<32, 2>::new(IDS, Config::DEFAULT);
    let mut log = Vec::new();
    for _ in 0..3 {
        assert_eq!(
            link.poll(&mut rx, record(&mut log)),
            Err(Error::BadHeader { raw: [0xFF; 4] })
        );
    }
    assert!(log.is_empty());
    let (mut spi, mut pin) = link.release();
    spi.done();
    pin.done();
}

/// An in-memory UART: reads come from a script of chunks (an `Err` entry
/// is a read error), writes are collected.
struct Uart {
    reads: Vec<Result<Vec<u8>, ()>>,
    written: Vec<u8>,
    /// How many bytes each write takes, in turn (`None`: all it is given;
    /// after the script, all).
    writes: Vec<Option<usize>>,
}
impl Uart {
    /// A UART for writing about `len` bytes whose writes each take a
    /// random amount (1 to 300 bytes, or all they are given), from
    /// `below(k)`, a whole number under `k`.
    fn taking_at_random(len: usize, below: &mut impl FnMut(u32) -> u32) -> Self {
        let writes = (0..4 * len + 4)
            .map(|_| (below(3) != 0).then(|| 1 + below(300) as usize))
            .collect();
        Self {
            reads: Vec::new(),
            written: Vec::new(),
            writes,
        }
    }
}

#[derive(Debug, PartialEq)]
struct UartError;
impl core::fmt::Display for UartError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("uart error")
    }
}
impl core::error::Error for UartError {}
impl embedded_io::Error for UartError {
    fn kind(&self) -> embedded_io::ErrorKind {
        embedded_io::ErrorKind::Other
    }
}
impl embedded_io::ErrorType for Uart {
    type Error = UartError;
}
impl embedded_io::Read for Uart {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, UartError> {
        match self.reads.first_mut() {
            None => Ok(0),
            Some(Err(())) => {
                let _ = self.reads.remove(0);
                Err(UartError)
            }
            Some(Ok(v)) => {
                let n = v.len().min(buf.len());
                buf[..n].copy_from_slice(&v[..n]);
                v.drain(..n);
                if v.is_empty() {
                    let _ = self.reads.remove(0);
                }
                Ok(n)
            }
        }
    }
}
impl embedded_io::Write for Uart {
    fn write(&mut self, buf: &[u8]) -> Result<usize, UartError> {
        let n = match self.writes.first().copied() {
            Some(n) => {
                let _ = self.writes.remove(0);
                n.unwrap_or(buf.len()).min(buf.len())
            }
            None => buf.len(),
        };
        self.written.extend_from_slice(&buf[..n]);
        Ok(n)
    }
    fn flush(&mut self) -> Result<(), UartError> {
        Ok(())
    }
}

#[test]
fn uart_chunks_read_error_and_write() {
    let mut s = camera_bytes(0);
    s.extend(frame_bytes(0, 1, 32));
    let f2 = frame_bytes(1, 2, 32);
    let f3 = frame_bytes(2, 3, 32);
    let reads = vec![
        Ok(s[..7].to_vec()),
        Ok(s[7..].to_vec()),
        Ok(f2[..50].to_vec()),
        Err(()),
        Ok(f3.clone()),
    ];
    let delivered = s.len() + 50 + f3.len();
    let mut link = UartLink::new(Uart {
        reads,
        written: Vec::new(),
        writes: Vec::new(),
    });
    let mut rx = Receiver::<32, 2>::new(IDS, Config::DEFAULT);
    let mut log = Vec::new();
    for _ in 0..12 {
        let _ = link.poll(&mut rx, record(&mut log));
    }
    // The delimiter the read error put in is not a byte the UART gave (an
    // adversary found each bus error counted one).
    assert_eq!(rx.counters().bytes as usize, delivered);
    assert_eq!(
        log,
        [
            "camera",
            "frame 1",
            "error truncated",
            "error counter_jump",
            "error missing_motion",
            "frame 3"
        ]
    );
    let mut raw = [0u8; 64];
    let n = encode::report(&mut raw, IDS.report, 0, &WireError::BadCrc).unwrap();
    super::write_packet(link.io(), &raw[..n]).unwrap();
    let w = &link.release().written;
    assert_eq!(w.last(), Some(&0));
    let mut dec = w.clone();
    let m = cobs::decode_in_place(&mut dec[..w.len() - 1]).unwrap();
    assert_eq!(&dec[..m], &raw[..n]);
}

/// `write_packet` on a UART that takes a byte a write writes the packet
/// whole; one whose `write` takes nothing of a non-empty buffer (which
/// embedded-io's contract rules out) gets `WriteZero`, not a panic (an
/// adversary's find: `write_all` panics there), with what was taken
/// before it kept.
#[test]
fn uart_write_packet_one_byte_at_a_time_and_a_write_of_nothing() {
    let mut raw = [0u8; 64];
    let n = encode::report(&mut raw, IDS.report, 3, &WireError::BadCrc).unwrap();
    let framed = framed(&raw[..n]);
    let mut one = Uart {
        reads: Vec::new(),
        written: Vec::new(),
        writes: vec![Some(1); 200],
    };
    super::write_packet(&mut one, &raw[..n]).unwrap();
    assert_eq!(one.written, framed);
    // The first block taken, then nothing of the second.
    let mut zero = Uart {
        reads: Vec::new(),
        written: Vec::new(),
        writes: vec![None, Some(0)],
    };
    assert_eq!(
        super::write_packet(&mut zero, &raw[..n]),
        Err(Error::WriteZero)
    );
    // (The first block whole: its code byte says how long it is.)
    assert_eq!(zero.written, framed[..usize::from(framed[0])]);
}

/// `write_packet` frames as it writes, with no buffer: the bytes are the
/// `cobs` crate's encoding and the delimiter (`encode::cobs_frame`), for
/// packets of every shape a COBS block has an edge at (empty, all zeros,
/// runs of 253 to 255 and 508 to 510 bytes without a zero, a zero first
/// or last) and random ones, under writes that take random amounts.
#[test]
fn write_packet_frames_as_the_cobs_crate_does() {
    let mut rng = crate::test_rng::Rng(11);
    let mut cases: Vec<Vec<u8>> = vec![Vec::new(), vec![0], vec![0; 3], vec![7]];
    for run in [1, 253, 254, 255, 508, 509, 510] {
        let body: Vec<u8> = (0..run).map(|i| (i % 255 + 1) as u8).collect();
        cases.push(body.clone());
        cases.push([&[0u8][..], &body].concat());
        cases.push([&body[..], &[0u8]].concat());
        cases.push([&body[..], &[0u8], &body].concat());
    }
    // A whole number below `k`.
    let mut below = |k: u32| (rng.next() * k as f32) as u32;
    for _ in 0..300 {
        let len = below(1200) as usize;
        let zeros = 1 + below(400);
        cases.push(
            (0..len)
                .map(|_| {
                    if below(zeros) == 0 {
                        0
                    } else {
                        below(256) as u8
                    }
                })
                .collect(),
        );
    }
    for (case, raw) in cases.iter().enumerate() {
        let want = framed(raw);
        let mut uart = Uart::taking_at_random(want.len(), &mut below);
        super::write_packet(&mut uart, raw).unwrap();
        assert_eq!(uart.written, want, "case {case}, {} bytes", raw.len());
    }
}

/// `write_result` writes what `encode::result` and `write_packet` write,
/// byte for byte, without a buffer for the packet: a first frame, a frame
/// the clock cut (every point flagged), and whole pairs of two boundaries
/// whose results run past several COBS blocks (points with depths, each
/// 21 bytes, and flagged ones, 1), under writes that take random amounts.
#[test]
fn write_result_writes_what_the_buffered_path_writes() {
    use crate::{Frame, Motion, Processor, Step};
    let mut rng = crate::test_rng::Rng(5);
    let mut below = |k: u32| (rng.next() * k as f32) as u32;
    let frame = |u0: f32, n: usize, m: usize| {
        let mut f = Frame::<64, 2>::new(cam());
        let a: Vec<Pixel> = (0..n)
            .map(|i| Pixel::new(u0 + 0.5 * i as f32, 470.0 - 3.0 * i as f32))
            .collect();
        let b: Vec<Pixel> = (0..m)
            .map(|i| Pixel::new(u0 + 200.0 - 0.5 * i as f32, 470.0 - 3.0 * i as f32))
            .collect();
        f.push_boundary(&a).unwrap();
        f.push_boundary(&b).unwrap();
        f
    };
    let head = encode::ResultHead {
        frame_id: 0x0100_0002,
        kept_id: 1,
        timestamp_us: 0x00ff_0000_0000_0007,
        instructions: 12345,
    };
    let motion = Motion::new([0.0, 0.0, 0.4], [0.0, 0.0, 0.0]).unwrap();
    let mut p = Processor::<64, 2>::new(Config::DEFAULT);
    let (mut cases, mut longest) = (0, 0);
    for (n, m) in [(2, 2), (40, 64), (64, 12), (13, 64)] {
        let (f1, f2) = (frame(100.0, n, m), frame(96.0, n, m));
        p.reset();
        for kind in 0..3 {
            let mut raw = vec![0u8; crate::wire::result_packet_max(64, 2)];
            let nbytes = match kind {
                0 => {
                    p.reset();
                    let s = p.process(&f1, None).unwrap();
                    encode::result(&mut raw, IDS.result, 7, &head, &s, &[3, 4]).unwrap()
                }
                1 => {
                    let s = p
                        .process_against_kept_within(&f2, &motion, &mut || true)
                        .unwrap();
                    let s = Step::Structure(s);
                    encode::result(&mut raw, IDS.result, 8, &head, &s, &[3, 4]).unwrap()
                }
                _ => {
                    let s = Step::Structure(p.process_against_kept(&f2, &motion).unwrap());
                    encode::result(&mut raw, IDS.result, 9, &head, &s, &[3, 4]).unwrap()
                }
            };
            let want = framed(&raw[..nbytes]);
            let mut uart = Uart::taking_at_random(want.len(), &mut below);
            match kind {
                0 => {
                    p.reset();
                    let s = p.process(&f1, None).unwrap();
                    super::write_result(&mut uart, IDS.result, 7, &head, &s, &[3, 4]).unwrap();
                }
                1 => {
                    let s = p
                        .process_against_kept_within(&f2, &motion, &mut || true)
                        .unwrap();
                    let s = Step::Structure(s);
                    super::write_result(&mut uart, IDS.result, 8, &head, &s, &[3, 4]).unwrap();
                }
                _ => {
                    let s = Step::Structure(p.process_against_kept(&f2, &motion).unwrap());
                    super::write_result(&mut uart, IDS.result, 9, &head, &s, &[3, 4]).unwrap();
                }
            }
            assert_eq!(uart.written, want, "boundaries of {n} and {m}, kind {kind}");
            longest = longest.max(want.len());
            cases += 1;
        }
    }
    assert_eq!(cases, 12);
    // Several blocks of 254 (and the depths of matched points) in the
    // longest.
    assert!(longest > 3 * 255, "{longest}");
}
