//! Unit tests of the wire format: round trips at every chunking, each
//! typed error, resynchronisation, and the decoder against `cobs`.

#![allow(clippy::panic, clippy::large_enum_variant)]

extern crate std;
use std::vec;
use std::vec::Vec;

use super::encode::{self, BoundaryHead, FrameHead, MotionFields};
use super::*;
use crate::test_rng::Rng;
use crate::{BoundaryError, Camera, Frame, Pixel};

const IDS: DataIds = DataIds::DEFAULT;

fn cam() -> Camera {
    Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap()
}

fn link(raw: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8; cobs_max(raw.len())];
    let n = encode::cobs_frame(raw, &mut out).unwrap();
    out.truncate(n);
    out
}

fn camera_packet(counter: u16) -> Vec<u8> {
    let mut raw = [0u8; 64];
    let n = encode::camera(&mut raw, IDS.camera, counter, &cam()).unwrap();
    link(&raw[..n])
}

fn line(n: usize, u0: f32) -> Vec<Pixel> {
    (0..n)
        .map(|i| Pixel::new(u0 + 0.0625 * i as f32, 470.0 - i as f32))
        .collect()
}

fn frame_raw(counter: u16, id: u32, bs: &[(f32, Vec<Pixel>)]) -> Vec<u8> {
    let mut raw = vec![0u8; frame_packet_max(64, 4)];
    let head = FrameHead {
        timestamp_us: 1_000_000 + u64::from(id),
        frame_id: id,
        width: 512,
        height: 480,
    };
    let list: Vec<(BoundaryHead, &[Pixel])> = bs
        .iter()
        .enumerate()
        .map(|(k, (r, p))| {
            (
                BoundaryHead {
                    quality: k as u8 + 7,
                    radius_px: *r,
                },
                p.as_slice(),
            )
        })
        .collect();
    let n = encode::frame(&mut raw, IDS.frame, counter, &head, &list).unwrap();
    raw.truncate(n);
    raw
}

fn frame_packet(counter: u16, id: u32, bs: &[(f32, Vec<Pixel>)]) -> Vec<u8> {
    link(&frame_raw(counter, id, bs))
}

fn motion_packet(counter: u16, from: u32, to: u32) -> Vec<u8> {
    motion_link(
        counter,
        &MotionFields {
            from,
            to,
            translation: [0.0, 0.0, 0.4],
            rotation: [0.0, 0.01, 0.0],
            translation_error: Some(0.01),
            rotation_error: None,
        },
    )
}

/// The motion packet `m`, numbered `counter`, as the link carries it.
fn motion_link(counter: u16, m: &MotionFields) -> Vec<u8> {
    let mut raw = [0u8; 80];
    let n = encode::motion(&mut raw, IDS.motion, counter, m).unwrap();
    link(&raw[..n])
}

/// What a decoder made of a stream: per packet, `Ok(kind)` or the error.
#[derive(Debug, PartialEq)]
enum Out {
    Frame(Frame<64, 2>, FrameInfo<2>, u16),
    Motion(MotionPacket, u16),
    Camera(u16),
    End,
    Err(WireError),
}

fn run(d: &mut Decoder<64, 2>, stream: &[u8], chunk: usize) -> Vec<Out> {
    let mut out = Vec::new();
    for piece in stream.chunks(chunk.max(1)) {
        let mut rest = piece;
        while !rest.is_empty() {
            let (used, got) = d.feed(rest);
            assert!(used > 0 && used <= rest.len());
            rest = &rest[used..];
            if let Some(g) = got {
                out.push(match g.packet {
                    Ok(Packet::Frame(f, i)) => Out::Frame(f.clone(), *i, g.missed),
                    Ok(Packet::Motion(m)) => Out::Motion(m, g.missed),
                    Ok(Packet::Camera(_)) => Out::Camera(g.missed),
                    Ok(Packet::End) => Out::End,
                    Err(e) => Out::Err(e),
                });
            }
        }
    }
    out
}

#[test]
fn residue_checks_any_intact_packet() {
    let mut rng = Rng(7);
    for len in 0..200 {
        let mut m: Vec<u8> = (0..len).map(|_| (rng.next() * 256.0) as u8).collect();
        let c = CRC.checksum(&m);
        m.extend_from_slice(&c.to_le_bytes());
        let mut d = CRC.digest();
        d.update(&m);
        assert_eq!(d.finalize(), RESIDUE, "len {len}");
    }
}

#[test]
fn fixed_point_conversions_are_exact() {
    for raw in [257u16, 258, 272, 273, 8000, 65535] {
        assert_eq!(px_to_raw(raw_to_px(raw)), Some(raw));
    }
    // Bit for bit the plain formula, at every raw value.
    for raw in 0..=u16::MAX {
        let plain = f32::from(raw) * 0.0625 - 17.0625;
        assert_eq!(raw_to_px(raw).to_bits(), plain.to_bits(), "{raw}");
    }
    assert_eq!(raw_to_px(RAW_MINUS_ONE_PX), -1.0);
    assert_eq!(raw_to_px(65535), 4078.875);
    assert_eq!(px_to_raw(-1.04), None);
    assert_eq!(px_to_raw(f32::NAN), None);
    assert_eq!(px_to_raw(4079.0), None);
    // Integer and half-pixel coordinates have no zero byte.
    for k in 0..8000 {
        let raw = px_to_raw(-1.0 + 0.5 * k as f32).unwrap();
        assert!(raw.to_le_bytes().iter().all(|&b| b != 0), "{k}");
    }
    assert_eq!(radius_to_raw(0.5), Some(128));
    assert!(raw_to_radius(radius_to_raw(0.3).unwrap()) >= 0.3);
    assert_eq!(radius_to_raw(100.5), None);
}

#[test]
fn round_trip_at_every_chunking() {
    let b0 = line(40, 100.0);
    let b1 = line(64, 400.0);
    let mut stream = vec![0u8];
    stream.extend(camera_packet(0));
    stream.extend(motion_packet(0, 4, 5));
    stream.extend(frame_packet(0, 5, &[(0.5, b0.clone()), (1.25, b1.clone())]));
    let mut raw = [0u8; 20];
    let n = encode::end(&mut raw, IDS.end, 0).unwrap();
    stream.extend(link(&raw[..n]));
    let mut expect = Frame::<64, 2>::new(cam());
    expect.push_boundary(&b0).unwrap();
    expect.push_boundary(&b1).unwrap();
    for chunk in [1, 2, 3, 4, 5, 7, 13, 64, 255, 256, 10_000] {
        let mut d = Decoder::<64, 2>::new(IDS);
        let out = run(&mut d, &stream, chunk);
        assert_eq!(out.len(), 4, "chunk {chunk}: {out:?}");
        assert_eq!(out[0], Out::Camera(0));
        let Out::Motion(m, 0) = &out[1] else {
            panic!("{:?}", out[1])
        };
        assert_eq!(
            (m.from, m.to, m.translation_error, m.rotation_error),
            (4, 5, Some(0.01), None)
        );
        let Out::Frame(f, info, 0) = &out[2] else {
            panic!("{:?}", out[2])
        };
        assert_eq!(f, &expect, "chunk {chunk}");
        assert_eq!(info.frame_id, 5);
        assert_eq!(info.timestamp_us, 1_000_005);
        assert_eq!(info.quality, [7, 8]);
        assert_eq!(info.radius_px, [0.5, 1.25]);
        assert_eq!(out[3], Out::End);
    }
}

#[test]
fn an_absent_boundary_round_trips_and_one_point_is_an_error() {
    let b1 = line(20, 400.0);
    let mut stream = vec![0u8];
    stream.extend(camera_packet(0));
    // Boundary 0 absent (no points, its radius ignored), boundary 1 seen.
    stream.extend(frame_packet(0, 5, &[(3.0, Vec::new()), (1.25, b1.clone())]));
    let mut expect = Frame::<64, 2>::new(cam());
    expect.push_absent().unwrap();
    expect.push_boundary(&b1).unwrap();
    for chunk in [1, 3, 7, 64, 10_000] {
        let mut d = Decoder::<64, 2>::new(IDS);
        let out = run(&mut d, &stream, chunk);
        assert_eq!(out.len(), 2, "chunk {chunk}: {out:?}");
        let Out::Frame(f, info, 0) = &out[1] else {
            panic!("{:?}", out[1])
        };
        assert_eq!(f, &expect, "chunk {chunk}");
        assert!(f.boundaries()[0].is_absent());
        assert_eq!(info.quality, [7, 8]);
        assert_eq!(info.radius_px, [0.0, 1.25]);
        assert_eq!(info.max_radius(2), 1.25);
    }
    // An absent boundary's radius is not checked: one past the 100 px
    // limit (raw 0xFFFF, which the encoder would refuse) still decodes.
    let mut raw = frame_raw(2, 7, &[(3.0, Vec::new()), (1.25, b1.clone())]);
    let at = HEADER_LEN + 18 + 2;
    raw[at..at + 2].copy_from_slice(&0xFFFFu16.to_le_bytes());
    let body = raw.len() - 4;
    let crc = CRC.checksum(&raw[..body]);
    raw[body..].copy_from_slice(&crc.to_le_bytes());
    let mut d = Decoder::<64, 2>::new(IDS);
    run(&mut d, &[vec![0u8], camera_packet(0)].concat(), 9);
    let out = run(&mut d, &link(&raw), 9);
    let [Out::Frame(f, info, 0)] = &out[..] else {
        panic!("{out:?}")
    };
    assert!(f.boundaries()[0].is_absent());
    assert_eq!(info.radius_px, [0.0, 1.25]);
    // One point is not a boundary: the error it always was.
    let mut d = Decoder::<64, 2>::new(IDS);
    run(&mut d, &camera_packet(0), 9);
    let out = run(&mut d, &frame_packet(1, 6, &[(0.5, line(1, 50.0))]), 9);
    assert_eq!(
        out,
        [Out::Err(WireError::Boundary {
            boundary: 0,
            error: crate::BoundaryError::TooFewPoints
        })]
    );
}

#[test]
fn typed_errors_and_resync() {
    let good = frame_packet(1, 1, &[(0.5, line(10, 50.0))]);
    let mut d = Decoder::<64, 2>::new(IDS);
    // A frame before any camera.
    let out = run(&mut d, &frame_packet(0, 0, &[(0.5, line(10, 50.0))]), 9);
    assert_eq!(out, [Out::Err(WireError::NoCamera)]);
    run(&mut d, &camera_packet(0), 9);

    // Garbage without a delimiter, then a packet: one error, then the packet.
    let mut s: Vec<u8> = (1..=40u8).collect();
    s.push(0);
    s.extend(&good);
    let out = run(&mut d, &s, 5);
    assert_eq!(out.len(), 2, "{out:?}");
    assert!(matches!(out[0], Out::Err(_)));
    // (The NoCamera packet was intact: its counter 0 counted.)
    assert!(matches!(out[1], Out::Frame(_, _, 0)), "{:?}", out[1]);

    // Repeated counter: dropped.
    assert_eq!(
        run(&mut d, &good, 3),
        [Out::Err(WireError::Repeated { counter: 1 })]
    );

    // A flipped bit: bad CRC (or a cut when it makes a zero), and the
    // counter is not advanced by it.
    let mut bad = frame_packet(2, 2, &[(0.5, line(10, 50.0))]);
    bad[30] ^= 0x10;
    let out = run(&mut d, &bad, 4);
    assert!(
        matches!(out.as_slice(), [Out::Err(WireError::BadCrc)]),
        "{out:?}"
    );
    let out = run(&mut d, &frame_packet(2, 2, &[(0.5, line(10, 50.0))]), 4);
    assert!(matches!(out.as_slice(), [Out::Frame(_, _, 0)]), "{out:?}");

    // A packet cut short: the next packet's delimiter ends it early.
    let p = frame_packet(3, 3, &[(0.5, line(10, 50.0))]);
    let mut s = p[..p.len() / 2].to_vec();
    s.push(0);
    let out = run(&mut d, &s, 4);
    assert!(
        matches!(out.as_slice(), [Out::Err(WireError::Truncated { .. })]),
        "{out:?}"
    );

    // Counter jump: taken, with the count.
    let out = run(&mut d, &frame_packet(6, 6, &[(0.5, line(10, 50.0))]), 4);
    assert!(matches!(out.as_slice(), [Out::Frame(_, _, 3)]), "{out:?}");

    // Invalid content, intact packets.
    let unordered = vec![
        Pixel::new(1.0, 1.0),
        Pixel::new(2.0, 5.0),
        Pixel::new(3.0, 2.0),
    ];
    let out = run(&mut d, &frame_packet(7, 7, &[(0.5, unordered)]), 4);
    assert_eq!(
        out,
        [Out::Err(WireError::Boundary {
            boundary: 0,
            error: BoundaryError::Unordered { index: 2 }
        })]
    );
    let outside = vec![Pixel::new(1.0, 1.0), Pixel::new(600.0, 5.0)];
    let out = run(&mut d, &frame_packet(8, 8, &[(0.5, outside)]), 4);
    assert_eq!(
        out,
        [Out::Err(WireError::Boundary {
            boundary: 0,
            error: BoundaryError::OutsideImage { index: 1 }
        })]
    );
    let three = [
        (0.5, line(3, 9.0)),
        (0.5, line(3, 19.0)),
        (0.5, line(3, 29.0)),
    ];
    let out = run(&mut d, &frame_packet(9, 9, &three), 4);
    assert_eq!(
        out,
        [Out::Err(WireError::TooManyBoundaries {
            count: 3,
            capacity: 2
        })]
    );
    let out = run(&mut d, &frame_packet(10, 10, &[(0.5, line(65, 9.0))]), 4);
    assert_eq!(
        out,
        [Out::Err(WireError::TooManyPoints {
            boundary: 0,
            len: 65,
            capacity: 64
        })]
    );

    // Version, magic, type and data id.
    let mut raw = frame_raw(11, 11, &[(0.5, line(4, 9.0))]);
    raw[2] = 9;
    let n = raw.len() - 4;
    let c = CRC.checksum(&raw[..n]);
    raw[n..].copy_from_slice(&c.to_le_bytes());
    assert_eq!(
        run(&mut d, &link(&raw), 4),
        [Out::Err(WireError::UnknownVersion { version: 9 })]
    );
    raw[2] = VERSION;
    raw[4] = 0x55;
    let c = CRC.checksum(&raw[..n]);
    raw[n..].copy_from_slice(&c.to_le_bytes());
    assert_eq!(
        run(&mut d, &link(&raw), 4),
        [Out::Err(WireError::WrongDataId {
            expected: IDS.frame,
            got: 0x0F55
        })]
    );
    // And still in step.
    let out = run(&mut d, &frame_packet(11, 11, &[(0.5, line(10, 50.0))]), 4);
    assert!(matches!(out.as_slice(), [Out::Frame(_, _, 0)]), "{out:?}");
}

/// The run-at-a-time COBS path agrees with the `cobs` crate's decoder on
/// random streams (with zeros and long runs).
#[test]
fn cobs_paths_agree_with_the_crate() {
    let mut rng = Rng(99);
    for case in 0..300 {
        let len = (rng.next() * 1200.0) as usize;
        let zero_rate = rng.next() * 0.3;
        let body: Vec<u8> = (0..len)
            .map(|_| {
                if rng.next() < zero_rate {
                    0
                } else {
                    1 + (rng.next() * 255.0) as u8
                }
            })
            .collect();
        let enc = link(&body);
        let mut reference = vec![0u8; len + 8];
        let n = cobs::decode(&enc[..enc.len() - 1], &mut reference)
            .unwrap()
            .frame_size();
        assert_eq!(&reference[..n], &body[..], "case {case}");
        // The decoder sees the same bytes: its CRC says so (the body is no
        // packet, so the verdict must be a length or CRC error, never a
        // COBS cut).
        let mut d = Decoder::<64, 2>::new(IDS);
        let out = run(&mut d, &enc, 1 + case % 17);
        if len >= 14 {
            assert_eq!(out.len(), 1, "case {case}");
            assert!(
                !matches!(out[0], Out::Err(WireError::Truncated { .. })),
                "case {case}: {out:?}"
            );
        }
    }
}

/// A camera packet's event carries the intrinsics the next frames are
/// seen with (an integrator's note: it carried nothing, though the
/// decoder's packet had them), and a changed camera's event the new ones.
#[test]
fn a_camera_event_carries_its_camera() {
    let mut rx = Receiver::<64, 2>::new(IDS, crate::Config::DEFAULT);
    let other = Camera::new(700.0, 710.0, 300.25, 200.5, 640, 400).unwrap();
    let mut raw = [0u8; 64];
    let n = encode::camera(&mut raw, IDS.camera, 1, &other).unwrap();
    let mut seen = Vec::new();
    for bytes in [vec![0], camera_packet(0), link(&raw[..n])] {
        rx.feed(&bytes, |e| {
            if let Event::Camera(c) = e {
                seen.push(c);
            }
        });
    }
    assert_eq!(seen, [cam(), other]);
}

/// A `Sender` numbers each data id's packets on its own, as the receiver
/// checks them: interleaved camera, motion and frame packets (one frame
/// packet failing for a short buffer, which takes no number) reach a
/// receiver with no counter error, every frame paired with its motion;
/// the same stream with one frame's counter skipped is a `counter_jump`.
#[test]
fn a_sender_numbers_each_streams_packets() {
    let run = |skip_one: bool| {
        let mut tx = encode::Sender::new(IDS);
        let mut rx = Receiver::<64, 2>::new(IDS, crate::Config::DEFAULT);
        let mut raw = vec![0u8; frame_packet_max(64, 2)];
        let (mut frames, mut paired, mut errors) = (0, 0, Vec::new());
        let mut feed = |rx: &mut Receiver<64, 2>, bytes: &[u8]| {
            rx.feed(&link(bytes), |e| match e {
                Event::Frame(job) => {
                    frames += 1;
                    paired += usize::from(job.motion.is_some());
                }
                Event::Error(e) => errors.push(e.kind()),
                _ => {}
            });
        };
        rx.feed(&[0], |_| {});
        for id in 0..6u32 {
            if id % 3 == 0 {
                let n = tx.camera(&mut raw, &cam()).unwrap();
                feed(&mut rx, &raw[..n]);
            }
            if id > 0 {
                let m = encode::MotionFields::of(id - 1, id, &drive_step());
                let n = tx.motion(&mut raw, &m).unwrap();
                feed(&mut rx, &raw[..n]);
            }
            let head = encode::FrameHead {
                timestamp_us: u64::from(id),
                frame_id: id,
                width: 512,
                height: 480,
            };
            let pts = drive_edge(id as f32, -1.0);
            let bh = encode::BoundaryHead {
                quality: 1,
                radius_px: 0.5,
            };
            let list = [(bh, pts.as_slice())];
            // A buffer too short: an error, and no number taken.
            let before = tx.next_counter(PacketType::Frame);
            assert!(tx.frame(&mut raw[..20], &head, &list).is_err());
            assert_eq!(tx.next_counter(PacketType::Frame), before);
            if skip_one && id == 4 {
                tx.skip(PacketType::Frame);
            }
            let n = tx.frame(&mut raw, &head, &list).unwrap();
            feed(&mut rx, &raw[..n]);
        }
        (frames, paired, errors)
    };
    assert_eq!(run(false), (6, 5, vec![]));
    let (frames, _, errors) = run(true);
    assert_eq!((frames, errors), (6, vec![ErrorKind::CounterJump]));
}

/// A summary packet round-trips: the counters a receiver keeps, encoded
/// as the link firmware answers an end packet, parse back to themselves
/// (every field distinct, so a shifted or swapped field shows); any
/// other payload length is not a summary.
#[test]
fn a_summary_parses_back_to_its_counters() {
    let mut c = Counters {
        bytes: 0xdead_beef,
        frames: 2,
        motions: 3,
        cameras: 4,
        ..Counters::default()
    };
    for (k, e) in c.errors.iter_mut().enumerate() {
        *e = 100 + k as u32;
    }
    let mut raw = [0u8; 256];
    let n = encode::summary(&mut raw, IDS.result, 9, &c.values()).unwrap();
    let checked = result::check(&raw[..n]).unwrap();
    assert_eq!(checked.ptype, PacketType::Summary);
    assert_eq!(result::summary(checked.payload), Some(c));
    assert_eq!(c.errors_of(ErrorKind::MissingMotion), 120);
    let p = checked.payload;
    assert_eq!(result::summary(&p[..p.len() - 4]), None);
}

/// The result packet's flags byte carries `Structure::deadline_expired`:
/// set when the caller's clock cut the frame short (every point then
/// `over_budget`, for a clock that says yes at once), clear without a
/// deadline and for a first frame.
#[test]
fn result_packet_carries_the_deadline_flag() {
    use crate::{Config, Motion, Processor, Status};
    let frame = |u0: f32| {
        let mut f = Frame::<64, 2>::new(cam());
        f.push_boundary(&line(40, u0)).unwrap();
        f
    };
    let (f1, f2) = (frame(100.0), frame(96.0));
    let motion = Motion::new([0.0, 0.0, 0.4], [0.0, 0.0, 0.0]).unwrap();
    let head = encode::ResultHead {
        frame_id: 2,
        kept_id: 1,
        timestamp_us: 7,
        instructions: 0,
    };
    let parse = |raw: &[u8]| -> (bool, bool, u16, u16) {
        let c = result::check(raw).unwrap();
        let v = ResultView::parse(c.payload).unwrap();
        let ok = v.count(Status::Ok);
        (
            v.structure,
            v.deadline_expired,
            ok,
            v.count(Status::OverBudget),
        )
    };
    let mut p = Processor::<64, 2>::new(Config::default());
    let mut raw = vec![0u8; 4096];
    let first = p.process_within(&f1, None, &mut || true).unwrap();
    let n = encode::result(&mut raw, IDS.result, 0, &head, &first, &[0]).unwrap();
    assert_eq!(parse(&raw[..n]), (false, false, 0, 0));
    // Cut at once: every point flagged, the flag set.
    let cut = p
        .process_against_kept_within(&f2, &motion, &mut || true)
        .unwrap();
    assert!(cut.deadline_expired());
    let step = crate::Step::Structure(cut);
    let n = encode::result(&mut raw, IDS.result, 1, &head, &step, &[0]).unwrap();
    assert_eq!(parse(&raw[..n]), (true, true, 0, 40));
    // The same pair without a deadline: points matched, the flag clear.
    let whole = p.process_against_kept(&f2, &motion).unwrap();
    assert!(!whole.deadline_expired());
    let step = crate::Step::Structure(whole);
    let n = encode::result(&mut raw, IDS.result, 2, &head, &step, &[0]).unwrap();
    let (structure, expired, ok, over) = parse(&raw[..n]);
    assert!(structure && !expired && over == 0 && ok > 0, "{ok} ok");
}

/// `px_to_raw` rounds to the nearest sixteenth exactly (a tie upwards),
/// and says `None` exactly where the rounded value is below −1 px or above
/// 4078.875 px: against `f64` at the 64 `f32` on either side of every
/// sixteenth's midpoint (where a double rounding would show; the review's
/// 0.031248987 and −1.0312504 among them) and at ends of the range.
#[test]
fn px_to_raw_rounds_exactly() {
    let want = |px: f32| -> Option<u16> {
        let y = f64::from(px) * 16.0;
        let n = (y + 0.5).floor();
        let raw = n + 273.0;
        (px.is_finite() && (257.0..=65535.0).contains(&raw)).then_some(raw as u16)
    };
    assert_eq!(px_to_raw(0.031_248_987), Some(273));
    assert_eq!(px_to_raw(-1.031_250_4), None);
    assert_eq!(px_to_raw(-1.0), Some(RAW_MINUS_ONE_PX));
    assert_eq!(px_to_raw(4078.875), Some(u16::MAX));
    assert_eq!(px_to_raw(4078.91), None);
    for v in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1.0e9, -1.0e9] {
        assert_eq!(px_to_raw(v), None, "{v}");
    }
    let mut checked = 0u32;
    // Every midpoint `(k + 1/2)/16` px from −2 px to 4100 px, every 7th.
    let mut k = -33i32;
    while k < 65_600 {
        let mid = (k as f32 + 0.5) / 16.0;
        let bits = mid.to_bits();
        for d in 0..=128u32 {
            let b = (bits + d).wrapping_sub(64);
            let px = f32::from_bits(b);
            assert_eq!(px_to_raw(px), want(px), "{px:e} ({b:#x})");
            checked += 1;
        }
        k += 7;
    }
    assert!(checked > 1_000_000, "{checked}");
}

/// A boundary the encoder refuses leaves nothing behind: a packet with
/// refused boundaries between the good ones is, byte for byte, the packet
/// of the good ones alone (until a review, the refused boundary's head and
/// points before the bad one stayed in the packet, with a valid CRC, and
/// decoded as another boundary than any the caller wrote).
#[test]
fn a_refused_boundary_leaves_the_packet_as_it_was() {
    use encode::EncodeError;
    let head = FrameHead {
        timestamp_us: 7,
        frame_id: 3,
        width: 512,
        height: 480,
    };
    let bh = |k: u8, r: f32| BoundaryHead {
        quality: k,
        radius_px: r,
    };
    let (p1, p2) = (line(40, 100.0), line(30, 140.0));
    let mut want = vec![0u8; 1024];
    let goods = [(bh(1, 0.25), &p1[..]), (bh(2, 0.5), &p2[..])];
    let n = encode::frame(&mut want, IDS.frame, 4, &head, &goods).unwrap();
    want.truncate(n);
    let mut bad_late = line(25, 300.0);
    bad_late[17] = Pixel::new(5000.0, 200.0);
    let mut bad_first = line(12, 300.0);
    bad_first[0] = Pixel::new(-3.0, 200.0);
    let big = line(60, 300.0);
    // Rows 0.03 px apart, valid for `Frame`, round to one row, and a point
    // 0.01 px from the one before rounds onto it: both refused, as the
    // receiver would refuse them, at the point that breaks the order.
    let mut merged = line(25, 300.0);
    merged[10] = Pixel::new(merged[10].u, merged[9].v - 0.03);
    let mut same = line(25, 300.0);
    same[4] = Pixel::new(same[3].u + 0.01, same[3].v - 0.01);
    for pts in [&merged, &same] {
        let mut f = Frame::<64, 1>::new(cam());
        f.push_boundary(pts).unwrap();
    }
    // (A roomy buffer: refused for a point or the radius; a buffer of the
    // good packet's size: refused for want of room part way through.)
    type Refused<'a> = &'a [(BoundaryHead, &'a [Pixel], EncodeError)];
    let cases: [(usize, Refused); 2] = [
        (
            1024,
            &[
                (bh(5, 1.0), &bad_late, EncodeError::PointRange),
                (bh(6, 1.0), &bad_first, EncodeError::PointRange),
                (bh(7, 1000.0), &p2, EncodeError::Radius),
                (bh(9, 1.0), &merged, EncodeError::Unordered { index: 10 }),
                (bh(10, 1.0), &same, EncodeError::Unordered { index: 4 }),
            ],
        ),
        (n, &[(bh(8, 1.0), &big, EncodeError::BufferTooSmall)]),
    ];
    for (room, refused) in cases {
        let mut got = vec![0u8; room];
        let mut p = encode::FramePacket::begin(&mut got, IDS.frame, 4, &head).unwrap();
        p.boundary(&goods[0].0, goods[0].1).unwrap();
        for (h, pts, e) in refused {
            assert_eq!(p.boundary(h, pts), Err(*e), "{e:?}");
        }
        p.boundary(&goods[1].0, goods[1].1).unwrap();
        let len = p.finish().unwrap();
        assert_eq!(&got[..len], &want[..], "room {room}");
    }
}

/// A straight edge on the ground 1 below the camera at `x0` across,
/// depths 10 to 21, after `n` steps of [`drive_step`]; pixels on the
/// link's 1/16 px grid, so the link carries them exactly.
fn drive_edge(n: f32, x0: f32) -> Vec<Pixel> {
    (0..12)
        .map(|i| {
            let (x, z) = (x0 - 0.02 * n, 10.0 + i as f32 - 0.25 * n);
            let g = |c: f32| (c * 16.0).round() / 16.0;
            Pixel::new(g(255.5 + 800.0 * x / z), g(239.5 + 800.0 / z))
        })
        .collect()
}

/// The drive's motion a frame: 0.25 forward, 0.02 right.
fn drive_step() -> crate::Motion {
    crate::Motion::new([0.02, 0.0, 0.25], [0.0; 3]).unwrap()
}

/// The motion packet from frame `to − 1` to `to` of [`drive_step`], with
/// the error bounds given.
fn drive_motion_packet(counter: u16, to: u32, te: Option<f32>, re: Option<[f32; 3]>) -> Vec<u8> {
    drive_motion(counter, (to - 1, to), (te, re))
}

/// The motion packet of [`drive_step`] from frame `from` to `to`, with the
/// error bounds given.
fn drive_motion(
    counter: u16,
    (from, to): (u32, u32),
    (te, re): (Option<f32>, Option<[f32; 3]>),
) -> Vec<u8> {
    let step = drive_step();
    motion_link(
        counter,
        &MotionFields {
            from,
            to,
            translation: step.translation(),
            rotation: step.angles(),
            translation_error: te,
            rotation_error: re,
        },
    )
}

/// A drive through the link into a key-frame fusion (`FrameJob::run_fused`)
/// fuses what the same frames and motions given to `Fusion::step` fuse,
/// bit for bit; a frame declaring a larger error than the fusion's is
/// refused with the state unchanged; a lost motion packet, or a motion from
/// the refused frame, resets the fusion (the chain is broken) and the frame
/// starts a new key frame.
#[test]
fn frames_from_the_link_fuse_as_the_same_frames_stepped() {
    use crate::fusion::{ChainedMotion, Fusion, FusionConfig, FusionError, KeyReason};
    use crate::Config;
    let step = drive_step();
    let policy = FusionConfig::new(4, 500).unwrap();
    let mut via_link = Fusion::<64, 2, 128>::new(Config::DEFAULT, policy);
    let mut direct = Fusion::<64, 2, 128>::new(Config::DEFAULT, policy);
    let mut rx = super::Receiver::<64, 2>::new(IDS, Config::DEFAULT);
    rx.feed(&[0], |_| {});
    rx.feed(&camera_packet(0), |_| {});
    let mut retired = 0;
    for id in 0..20u32 {
        let pts = drive_edge(id as f32, -1.0);
        // Frame 8's motion packet is lost.
        if id > 0 && id != 8 {
            rx.feed(&drive_motion_packet(id as u16, id, None, None), |_| {});
        }
        // Frame 3 declares 0.75 px, above the fusion's 0.5.
        let r = if id == 3 { 0.75 } else { 0.5 };
        let packet = frame_packet(id as u16, id, &[(r, pts.clone()), (r, pts.clone())]);
        let mut got = None;
        let before = via_link.digest();
        rx.feed(&packet, |e| {
            if let super::Event::Frame(job) = e {
                got = Some(job.run_fused(&mut via_link));
            }
        });
        let got = got.expect("a frame job");
        if id == 3 {
            assert_eq!(got, Err(FusionError::ErrorsAboveConfig));
            assert_eq!(
                via_link.digest(),
                before,
                "a refused frame changed the state"
            );
            assert_eq!(via_link.last_frame(), Some(2));
            continue;
        }
        let mut frame = Frame::<64, 2>::new(cam());
        frame.push_boundary(&pts).unwrap();
        frame.push_boundary(&pts).unwrap();
        // After the refused frame 3 (frame 4's motion starts from it) and
        // the lost motion of frame 8, the chain starts anew.
        let anew = id == 0 || id == 4 || id == 8;
        if anew {
            direct.reset();
        }
        let chained = (!anew).then(|| ChainedMotion {
            from: id - 1,
            motion: step,
        });
        let want = direct.step(id, &frame, chained.as_ref()).unwrap();
        let s = got.unwrap();
        assert_eq!(s, want, "frame {id}");
        assert_eq!(via_link.digest(), direct.digest(), "frame {id}");
        if anew {
            assert_eq!(s.new_key, Some(KeyReason::First), "frame {id}");
            assert_eq!(via_link.map().batches(), 0);
        }
        retired += usize::from(s.retired.is_some());
    }
    // Key frames retired into the map after the resets.
    assert!(retired >= 2, "{retired}");
    assert!(via_link.map().points(0).count() > 0);
}

/// `run_fused` refuses a motion whose error bounds exceed the fusion's
/// where the motion chains on (translation, then rotation), with nothing
/// changed; the next frame, whose motion starts from the refused one,
/// starts the fusion anew without its bounds being judged; an absent
/// boundary (0 points, its radius ignored even at 99 px) pairs on.
#[test]
fn run_fused_judges_the_motion_bounds_it_uses() {
    use crate::fusion::{Fusion, FusionConfig, FusionError, KeyReason};
    use crate::Config;
    let base = Config::DEFAULT.with_translation_error(0.01).unwrap();
    let mut f = Fusion::<64, 2, 128>::new(base, FusionConfig::new(4, 500).unwrap());
    let mut rx = super::Receiver::<64, 2>::new(IDS, Config::DEFAULT);
    rx.feed(&[0], |_| {});
    rx.feed(&camera_packet(0), |_| {});
    let mut paired_absent = 0;
    for id in 0..12u32 {
        let (te, re) = match id {
            4 | 5 => (Some(0.02), None),
            7 => (Some(0.01), Some([0.0, 0.001, 0.0])),
            _ => (Some(0.01), None),
        };
        if id > 0 {
            rx.feed(&drive_motion_packet(id as u16, id, te, re), |_| {});
        }
        let absent = [2, 3, 9].contains(&id);
        let b0 = if absent {
            (99.0, Vec::new())
        } else {
            (0.5, drive_edge(id as f32, -1.0))
        };
        let packet = frame_packet(
            100 + id as u16,
            id,
            &[b0, (0.5, drive_edge(id as f32, 1.0))],
        );
        let before = (f.digest(), f.last_frame(), f.key_id());
        let mut got = None;
        rx.feed(&packet, |e| {
            if let super::Event::Frame(job) = e {
                got = Some(job.run_fused(&mut f));
            }
        });
        let got = got.expect("a frame job");
        match id {
            // The translation bound (4), the rotation bound (7): refused.
            4 | 7 => {
                assert_eq!(got, Err(FusionError::ErrorsAboveConfig), "frame {id}");
                assert_eq!((f.digest(), f.last_frame(), f.key_id()), before);
            }
            // Their motions start from the refused frame: anew, frame 5's
            // bound (above the fusion's) thrown away with its motion.
            5 | 8 => {
                let s = got.unwrap();
                assert_eq!(s.new_key, Some(KeyReason::First), "frame {id}");
                assert_eq!((f.key_id(), f.last_frame()), (Some(id), Some(id)));
            }
            _ => {
                let s = got.unwrap();
                assert_eq!(f.last_frame(), Some(id));
                if absent && s.paired.is_some() {
                    paired_absent += 1;
                }
            }
        }
    }
    assert!(paired_absent >= 2, "{paired_absent}");
}

/// A motion packet's rotation error bounds are the Euler angles' (as the
/// packet's rotation is), and the pair is configured with their box about
/// the camera's axes (an integrator's find: the receiver put the angles'
/// bounds into the configuration as they were, so with `γ = 0.5` an error
/// of `ε` in `α`, which turns the camera by about `ε (cos γ, −sin γ, 0)`
/// about its axes, was bounded by `(ε, 0, 0)`: nothing about `y`). Bounds
/// whose box is past what a configuration takes (0.1 rad in all) are a
/// typed error, although the angles' own sum is 0.1.
#[test]
fn a_motions_angle_error_bounds_reach_every_axis_they_turn() {
    let (eps, gamma) = (0.001f32, 0.5f32);
    let fields = |re| MotionFields {
        from: 0,
        to: 1,
        translation: [0.0, 0.0, 0.4],
        rotation: [0.0, 0.0, gamma],
        translation_error: None,
        rotation_error: Some(re),
    };
    let mut rx = Receiver::<64, 2>::new(IDS, crate::Config::DEFAULT);
    let mut seen = Vec::new();
    let mut feed = |bytes: &[u8], seen: &mut Vec<Result<[f32; 3], WireError>>| {
        rx.feed(bytes, |e| match e {
            Event::Frame(job) => seen.push(Ok(job.config.rotation_error())),
            Event::Error(err) => seen.push(Err(err)),
            _ => {}
        });
    };
    feed(&[0], &mut seen);
    feed(&camera_packet(0), &mut seen);
    feed(&frame_packet(1, 0, &[(0.5, line(8, 100.0))]), &mut seen);
    feed(&motion_link(2, &fields([eps, 0.0, 0.0])), &mut seen);
    feed(&frame_packet(3, 1, &[(0.5, line(8, 101.0))]), &mut seen);
    // The turn an error of `ε` in `α` makes about each axis, to first order.
    let turn = [eps * libm::cosf(gamma), eps * libm::sinf(gamma), 0.0];
    let got = seen.last().copied().expect("two frame jobs");
    let Ok(axes) = got else { panic!("{got:?}") };
    for k in 0..3 {
        assert!(axes[k] >= turn[k], "axis {k}: {axes:?} against {turn:?}");
    }
    assert!(axes[1] > 0.47 * eps, "{axes:?}");
    // Angles' bounds of 0.1 in all, whose box about the axes is more.
    let before = seen.len();
    feed(&motion_link(3, &fields([0.05, 0.0, 0.05])), &mut seen);
    assert_eq!(
        seen.get(before).copied(),
        Some(Err(WireError::MotionBounds(
            crate::ConfigError::RotationError
        )))
    );
}

/// A fusion fed by the link, made as `run_fused` says (the rotation's
/// bound as `euler_error_box_any_angles` of the odometry's angle bounds),
/// takes every frame whose packet declares those angle bounds and fuses
/// them; made with the angle bounds themselves it refuses the frames
/// whose motion chains on (their box about the axes is larger: a review's
/// find, when the docs still said to make it with the declared bounds).
#[test]
fn a_link_fed_fusion_made_with_the_any_angle_box_takes_every_frame() {
    use crate::fusion::{Fusion, FusionConfig, FusionError};
    use crate::motion_error::euler_error_box_any_angles;
    use crate::Config;
    let eps = [0.001f32; 3];
    let made = |rot| Config::DEFAULT.with_rotation_error(rot).unwrap();
    for (base, refused) in [
        (made(euler_error_box_any_angles(eps)), false),
        (made(eps), true),
    ] {
        let mut f = Fusion::<64, 2, 128>::new(base, FusionConfig::new(4, 500).unwrap());
        let mut rx = super::Receiver::<64, 2>::new(IDS, Config::DEFAULT);
        rx.feed(&[0], |_| {});
        rx.feed(&camera_packet(0), |_| {});
        let (mut taken, mut paired) = (0, 0);
        for id in 0..10u32 {
            if id > 0 {
                rx.feed(&drive_motion_packet(id as u16, id, None, Some(eps)), |_| {});
            }
            let packet = frame_packet(
                100 + id as u16,
                id,
                &[
                    (0.5, drive_edge(id as f32, -1.0)),
                    (0.5, drive_edge(id as f32, 1.0)),
                ],
            );
            rx.feed(&packet, |e| {
                if let super::Event::Frame(job) = e {
                    match job.run_fused(&mut f) {
                        Ok(s) => {
                            taken += 1;
                            paired += usize::from(s.paired.is_some());
                        }
                        Err(e) => assert_eq!(e, FusionError::ErrorsAboveConfig),
                    }
                }
            });
        }
        if refused {
            assert!(taken < 10 && paired == 0, "{taken} taken, {paired} paired");
        } else {
            assert_eq!((taken, paired), (10, 9));
        }
    }
}

/// The chain `run_fused` goes on is the previous job's frame, not a frame
/// id: a frame refused with the fusion's last id (an adversary's find:
/// frame 9 of a drive sent as id 4, after frame 4, with a radius above
/// the fusion's), then a motion from "4" and frame 5: the fusion starts
/// anew, where it paired frame 5 with frame 4 under frame 9's motion
/// before (14 of 16 intervals in conflict). The same after the fusion's
/// own refusal of a frame with its kept frame's id (a motion packet from
/// 3 to 3, `RepeatedFrame`).
#[test]
fn run_fused_chains_onto_the_previous_jobs_frame_not_its_id() {
    use crate::fusion::{Fusion, FusionConfig, FusionError, KeyReason};
    use crate::Config;
    let mut f = Fusion::<64, 2, 128>::new(Config::DEFAULT, FusionConfig::new(8, 500).unwrap());
    let mut rx = super::Receiver::<64, 2>::new(IDS, Config::DEFAULT);
    rx.feed(&[0], |_| {});
    rx.feed(&camera_packet(0), |_| {});
    let mut counter = 1u16;
    let mut send = |rx: &mut super::Receiver<64, 2>,
                    f: &mut Fusion<64, 2, 128>,
                    motion: Option<(u32, u32)>,
                    id: u32,
                    at: f32,
                    r: f32| {
        let mut got = None;
        send_job(rx, &mut counter, (motion, id, at, r), |j| {
            got = Some(j.run_fused(f));
        });
        got.expect("a frame job")
    };
    for id in 0..5u32 {
        let m = (id > 0).then(|| (id - 1, id));
        let s = send(&mut rx, &mut f, m, id, id as f32, 0.5).unwrap();
        assert_eq!(s.new_key.is_some(), id == 0, "frame {id}");
    }
    // Drive frame 9 as id 4, no motion, 0.75 px: refused, nothing changes.
    let before = (f.digest(), f.last_frame(), f.key_id());
    let got = send(&mut rx, &mut f, None, 4, 9.0, 0.75);
    assert_eq!(got, Err(FusionError::ErrorsAboveConfig));
    assert_eq!((f.digest(), f.last_frame(), f.key_id()), before);
    // Its motion to frame 10, sent as id 5: anew.
    let s = send(&mut rx, &mut f, Some((4, 5)), 5, 10.0, 0.5).unwrap();
    assert_eq!((s.paired, s.new_key), (None, Some(KeyReason::First)));
    assert_eq!((f.key_id(), f.last_frame()), (Some(5), Some(5)));
    // Frames 6 and 7 pair on.
    for id in 6..8u32 {
        let s = send(
            &mut rx,
            &mut f,
            Some((id - 1, id)),
            id,
            id as f32 + 5.0,
            0.5,
        )
        .unwrap();
        assert!(s.paired.is_some() && s.new_key.is_none(), "frame {id}");
    }
    // A motion from 7 to 7 and a frame 7: the receiver pairs them, the
    // fusion refuses the repeated id, nothing changes.
    let before = (f.digest(), f.last_frame(), f.key_id());
    let got = send(&mut rx, &mut f, Some((7, 7)), 7, 13.0, 0.5);
    assert_eq!(got, Err(FusionError::RepeatedFrame(7)));
    assert_eq!((f.digest(), f.last_frame(), f.key_id()), before);
    // The next motion starts from the refused frame 7: anew.
    let s = send(&mut rx, &mut f, Some((7, 8)), 8, 14.0, 0.5).unwrap();
    assert_eq!((s.paired, s.new_key), (None, Some(KeyReason::First)));
    // And the caller's own steps between two jobs: a reset and a frame
    // stepped as id 9, the receiver's kept frame's id (a different frame,
    // drive frame 16); the next job's motion from 9 chains onto the
    // receiver's frame 9, not the fusion's: anew.
    let s = send(&mut rx, &mut f, Some((8, 9)), 9, 15.0, 0.5).unwrap();
    assert!(s.paired.is_some());
    let mut frame = Frame::<64, 2>::new(cam());
    let pts = drive_edge(16.0, -1.0);
    frame.push_boundary(&pts).unwrap();
    frame.push_boundary(&pts).unwrap();
    f.reset();
    let direct = f.step(9, &frame, None).unwrap();
    assert_eq!(direct.new_key, Some(KeyReason::First));
    let s = send(&mut rx, &mut f, Some((9, 10)), 10, 17.0, 0.5).unwrap();
    assert_eq!((s.paired, s.new_key), (None, Some(KeyReason::First)));
    assert_eq!((f.key_id(), f.last_frame()), (Some(10), Some(10)));
}

/// A frame job sent through `rx`: its motion packet (from, to) if any,
/// then frame `id` showing the drive at `at` with radius `r`, each job
/// handed to `on`.
fn send_job(
    rx: &mut super::Receiver<64, 2>,
    counter: &mut u16,
    (motion, id, at, r): (Option<(u32, u32)>, u32, f32, f32),
    mut on: impl FnMut(&super::FrameJob<'_, 64, 2>),
) {
    if let Some((from, to)) = motion {
        rx.feed(&drive_motion(*counter, (from, to), (None, None)), |_| {});
        *counter += 1;
    }
    let pts = drive_edge(at, -1.0);
    let packet = frame_packet(*counter, id, &[(r, pts.clone()), (r, pts)]);
    *counter += 1;
    rx.feed(&packet, |e| {
        if let super::Event::Frame(job) = e {
            on(&job);
        }
    });
}

/// `run_fused` chains no job onto a frame another receiver put into the
/// fusion, nor onto the caller's own steps, whatever the ids (a review's
/// finds: each receiver counted its jobs from 1, so a new receiver after
/// a link restart, its first frame refused, chained its second onto the
/// old receiver's frame of the same id, the key point of true depth 14
/// given `[1.20, 1.68]`; and no test caught the caller's own steps
/// without a reset).
#[test]
fn run_fused_chains_onto_no_other_receivers_frame_nor_the_callers() {
    use crate::fusion::{ChainedMotion, Fusion, FusionConfig, FusionError, KeyReason};
    use crate::Config;
    let fusion = || Fusion::<64, 2, 128>::new(Config::DEFAULT, FusionConfig::new(8, 500).unwrap());
    let receiver = || {
        let mut rx = super::Receiver::<64, 2>::new(IDS, Config::DEFAULT);
        rx.feed(&[0], |_| {});
        rx.feed(&camera_packet(0), |_| {});
        rx
    };
    let anew = |got: Option<Result<crate::fusion::FusionStep, FusionError>>| {
        let s = got.expect("a job").expect("taken");
        assert_eq!((s.paired, s.new_key), (None, Some(KeyReason::First)));
    };
    // A new receiver after a restart (the sender's ids restarted too).
    let mut f = fusion();
    let (mut rx1, mut c1) = (receiver(), 1u16);
    send_job(&mut rx1, &mut c1, (None, 0, 0.0, 0.5), |j| {
        j.run_fused(&mut f).unwrap();
    });
    let (mut rx2, mut c2) = (receiver(), 1u16);
    send_job(&mut rx2, &mut c2, (None, 0, 9.0, 0.75), |j| {
        assert_eq!(j.run_fused(&mut f), Err(FusionError::ErrorsAboveConfig));
    });
    let mut got = None;
    send_job(&mut rx2, &mut c2, (Some((0, 1)), 1, 10.0, 0.5), |j| {
        got = Some(j.run_fused(&mut f));
    });
    anew(got);
    // Two receivers into one fusion: b's second frame does not chain onto
    // a's first, which has its first's id.
    let mut f = fusion();
    let (mut a, mut ca, mut b, mut cb) = (receiver(), 1u16, receiver(), 1u16);
    send_job(&mut a, &mut ca, (None, 0, 0.0, 0.5), |j| {
        j.run_fused(&mut f).unwrap();
    });
    send_job(&mut b, &mut cb, (None, 0, 20.0, 0.5), |_| {});
    let mut got = None;
    send_job(&mut b, &mut cb, (Some((0, 1)), 1, 21.0, 0.5), |j| {
        got = Some(j.run_fused(&mut f));
    });
    anew(got);
    // The caller's own steps, no reset, back to the id of the receiver's
    // kept frame: the next job starts anew.
    let mut f = fusion();
    let (mut rx, mut c) = (receiver(), 1u16);
    send_job(&mut rx, &mut c, (None, 0, 0.0, 0.5), |j| {
        j.run_fused(&mut f).unwrap();
    });
    let frame = |n: f32| {
        let mut fr = Frame::<64, 2>::new(cam());
        let pts = drive_edge(n, -1.0);
        fr.push_boundary(&pts).unwrap();
        fr.push_boundary(&pts).unwrap();
        fr
    };
    let m = drive_step();
    f.step(
        100,
        &frame(1.0),
        Some(&ChainedMotion { from: 0, motion: m }),
    )
    .unwrap();
    f.step(
        0,
        &frame(2.0),
        Some(&ChainedMotion {
            from: 100,
            motion: m,
        }),
    )
    .unwrap();
    let mut got = None;
    send_job(&mut rx, &mut c, (Some((0, 1)), 1, 1.0, 0.5), |j| {
        got = Some(j.run_fused(&mut f));
    });
    anew(got);
}

/// A motion packet that came before the kept frame is not used to pair
/// the next one (an adversary's find: one sent before the first frame
/// paired the second): the second frame is `missing_motion` and starts
/// the pairing anew.
#[test]
fn a_motion_before_the_kept_frame_pairs_nothing() {
    use crate::Config;
    let mut rx = super::Receiver::<64, 2>::new(IDS, Config::DEFAULT);
    rx.feed(&[0], |_| {});
    rx.feed(&camera_packet(0), |_| {});
    rx.feed(&drive_motion(1, (0, 1), (None, None)), |_| {});
    let pts = |n: f32| drive_edge(n, -1.0);
    let mut log = Vec::new();
    for (c, id) in [(2u16, 0u32), (3, 1)] {
        let packet = frame_packet(c, id, &[(0.5, pts(id as f32)), (0.5, pts(id as f32))]);
        rx.feed(&packet, |e| match e {
            super::Event::Frame(job) => log.push(std::format!(
                "frame {} kept {} paired {}",
                job.info.frame_id,
                job.kept_id,
                job.motion.is_some()
            )),
            super::Event::Error(e) => log.push(std::format!("error {}", e.kind().name())),
            _ => {}
        });
    }
    assert_eq!(
        log,
        [
            "frame 0 kept 0 paired false",
            "error missing_motion",
            "frame 1 kept 1 paired false"
        ]
    );
}

/// One boundary of `pts` with radius `r` encoded in a 512 × 480 frame
/// packet and decoded after a camera packet: the boundary's points as
/// sent and the radius the packet carries; the encoder's error, if any.
fn sent_boundary(pts: &[Pixel], r: f32) -> Result<(Vec<Pixel>, f32), encode::EncodeError> {
    let mut raw = vec![0u8; frame_packet_max(64, 4)];
    let head = FrameHead {
        timestamp_us: 1,
        frame_id: 1,
        width: 512,
        height: 480,
    };
    let bh = BoundaryHead {
        quality: 0,
        radius_px: r,
    };
    let n = encode::frame(&mut raw, IDS.frame, 0, &head, &[(bh, pts)])?;
    let mut d = Decoder::<64, 2>::new(IDS);
    run(&mut d, &[vec![0u8], camera_packet(0)].concat(), 9);
    let out = run(&mut d, &link(&raw[..n]), 9);
    let [Out::Frame(f, info, 0)] = &out[..] else {
        panic!("{out:?}")
    };
    Ok((f.boundaries()[0].points().to_vec(), info.radius_px[0]))
}

/// A point off the 1/16 px grid by less than about 2⁻⁷⁵ px moves when it
/// is sent, though both squares of its move underflow to 0: the radius
/// sent still covers it (an adversarial review, thirtieth session: `u =
/// 10⁻³⁰`, radius 0, sent with radius 0), for offsets of either sign in
/// either coordinate from the grid point (0, 0) and radii on the 1/256 px
/// grid.
#[test]
fn the_radius_sent_covers_a_move_whose_square_underflows() {
    for (du, dv) in [
        (1.0e-30f32, 0.0f32),
        (0.0, 1.0e-30),
        (-1.0e-38, 0.0),
        (f32::from_bits(1), 0.0),
    ] {
        for r in [0.0f32, 0.5, 1.0] {
            // (Off the grid point (0, 0) by `(du, dv)`: near zero, where
            // such offsets are not absorbed.)
            let pts = [Pixel::new(du, dv), Pixel::new(5.0, 20.0)];
            let (q, sent) = sent_boundary(&pts, r).expect("encodes");
            assert_eq!((q[0].u, q[0].v), (0.0, 0.0));
            assert!(sent > r, "{du:e} {dv:e}, radius {r}: sent {sent}");
        }
    }
}

/// The radius a frame packet carries bounds the true point's distance from
/// the point as sent: the declared radius plus what the rounding to
/// 1/16 px moved each point (exactly, in `f64`), for points anywhere on
/// the pixel grid or off it; points on the 1/16 px grid keep the radius
/// as declared.
#[test]
fn the_radius_sent_covers_the_rounding_of_the_points() {
    let mut rng = Rng(11);
    let mut widened = 0;
    for case in 0..2000 {
        let r = [0.0f32, 0.25, 0.5, 1.0, 99.9][case % 5];
        let on_grid = case % 7 == 0;
        let pts: Vec<Pixel> = (0..20)
            .map(|i| {
                let u = rng.next() * 510.0;
                let u = if on_grid {
                    (u * 16.0).round() / 16.0
                } else {
                    u
                };
                Pixel::new(
                    u,
                    470.0 - i as f32 - if on_grid { 0.0 } else { rng.next() * 0.9 },
                )
            })
            .collect();
        let (points, radius) = match sent_boundary(&pts, r) {
            Ok(sent) => sent,
            // (99.9 px plus the rounding can pass the 100 px limit.)
            Err(encode::EncodeError::Radius) if r > 99.0 => continue,
            Err(e) => panic!("{e:?}"),
        };
        let sent = f64::from(radius);
        for (p, q) in pts.iter().zip(&points) {
            let moved = (f64::from(q.u) - f64::from(p.u)).hypot(f64::from(q.v) - f64::from(p.v));
            assert!(
                moved + f64::from(r) <= sent,
                "case {case}: {p:?} sent as {q:?}, radius {r} sent as {sent}"
            );
        }
        if on_grid {
            assert_eq!(radius, raw_to_radius(radius_to_raw(r).unwrap()));
        } else {
            widened += usize::from(sent > f64::from(r) + 1.0 / 256.0);
        }
    }
    assert!(widened > 1000, "{widened}");
}
