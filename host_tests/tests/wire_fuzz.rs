//! A seeded structured fuzzer for the link decoder, with the processor
//! behind it (issue 12). Each case generates frames (valid, and with
//! invalid boundaries: unordered, repeated, outside the image, too many
//! points or boundaries), motions and cameras, encodes them, damages the
//! stream (bit flips, cuts, garbage, drops, duplicates, random chunking)
//! and checks:
//! * nothing panics;
//! * every frame the decoder hands out equals the frame
//!   `Frame::push_boundary` builds from the same (quantised) points, and an
//!   invalid boundary in an intact packet gives push_boundary's own error;
//! * errors leave no trace: every pair the damaged run reconstructs gives
//!   bit for bit what the undamaged run gives for that pair.
//!
//! `WIRE_FUZZ_SECONDS` (default 20) bounds the run; it prints the cases run.

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use host_tests::link::{framed, host_outputs, Rng};
use roadstereo::wire::encode::{self, BoundaryHead, FrameHead, MotionFields};
use roadstereo::wire::result::check;
use roadstereo::wire::{px_to_raw, raw_to_px, DataIds, Decoder, Packet, PacketType, ResultView};
use roadstereo::{Camera, Frame, Pixel};

const N: usize = 256;
const B: usize = 2;

struct Case {
    /// Link bytes of every packet, in order.
    packets: Vec<Vec<u8>>,
    /// For each frame packet (by frame id): what push_boundary says.
    expect: BTreeMap<u32, Result<Frame<N, B>, ()>>,
}

fn boundary(rng: &mut Rng, cam: &Camera) -> Vec<Pixel> {
    let cap = if rng.unit() < 0.05 { 300 } else { 120 };
    let n = 2 + rng.below(cap);
    let (w, h) = (f32::from(cam.width()), f32::from(cam.height()));
    let mut v = -1.0 + rng.unit() as f32 * 20.0;
    let mut u = rng.unit() as f32 * w;
    let mut pts = Vec::new();
    for _ in 0..n {
        pts.push(Pixel::new(u, v));
        v += 0.0625 * (1 + rng.below(40)) as f32;
        u += (rng.unit() as f32 - 0.5) * 6.0;
        u = u.clamp(-1.0, w);
        if v > h {
            break;
        }
    }
    // Damage some boundaries in ways the decoder must name.
    match rng.below(12) {
        0 if pts.len() > 3 => {
            let i = 1 + rng.below(pts.len() - 2);
            pts[i] = pts[i - 1]; // repeated point
        }
        1 if pts.len() > 3 => {
            let i = 1 + rng.below(pts.len() - 2);
            pts.swap(i, i + 1); // unordered
        }
        2 => {
            let i = rng.below(pts.len());
            pts[i].u = w + 3.0; // outside the image
        }
        _ => {}
    }
    // Quantise as the wire does, so the expectation is exact.
    pts.iter()
        .map(|p| {
            let q = |x: f32| raw_to_px(px_to_raw(x).unwrap_or(257));
            Pixel::new(q(p.u), q(p.v))
        })
        .collect()
}

fn case(rng: &mut Rng) -> Case {
    let ids = DataIds::DEFAULT;
    let cam = Camera::new(
        400.0 + rng.unit() as f32 * 600.0,
        400.0 + rng.unit() as f32 * 600.0,
        255.5,
        239.5,
        512,
        480,
    )
    .expect("valid camera");
    let mut raw = vec![0u8; 16 * 1024];
    let mut packets = Vec::new();
    let mut expect = BTreeMap::new();
    let n = encode::camera(&mut raw, ids.camera, 0, &cam).expect("fits");
    packets.push(framed(&raw[..n]));
    let frames = 2 + rng.below(5);
    for id in 0..frames as u32 {
        if id > 0 && rng.unit() < 0.9 {
            let m = MotionFields {
                from: id - 1,
                to: id,
                translation: [
                    (rng.unit() as f32 - 0.5) * 0.2,
                    (rng.unit() as f32 - 0.5) * 0.1,
                    0.1 + rng.unit() as f32 * 0.5,
                ],
                rotation: [0.0, (rng.unit() as f32 - 0.5) * 0.1, 0.0],
                translation_error: (rng.unit() < 0.3).then_some(0.01),
                rotation_error: (rng.unit() < 0.3).then_some([0.001, 0.002, 0.0]),
            };
            let n = encode::motion(&mut raw, ids.motion, (id - 1) as u16, &m).expect("fits");
            packets.push(framed(&raw[..n]));
        }
        let nb = if rng.unit() < 0.05 {
            3
        } else {
            1 + rng.below(2)
        };
        let bs: Vec<Vec<Pixel>> = (0..nb).map(|_| boundary(rng, &cam)).collect();
        let heads: Vec<(BoundaryHead, &[Pixel])> = bs
            .iter()
            .map(|b| {
                (
                    BoundaryHead {
                        quality: rng.below(256) as u8,
                        radius_px: 0.25 + rng.unit() as f32 * 2.0,
                    },
                    b.as_slice(),
                )
            })
            .collect();
        let head = FrameHead {
            timestamp_us: u64::from(id) * 1000,
            frame_id: id,
            width: 512,
            height: 480,
        };
        let n = encode::frame(&mut raw, ids.frame, id as u16, &head, &heads).expect("fits");
        packets.push(framed(&raw[..n]));
        let mut f = Frame::<N, B>::new(cam);
        let ok = nb <= B && bs.iter().all(|b| f.push_boundary(b).is_ok());
        expect.insert(id, if ok { Ok(f) } else { Err(()) });
    }
    let n = encode::end(&mut raw, ids.end, 0).expect("fits");
    packets.push(framed(&raw[..n]));
    Case { packets, expect }
}

/// Damage: per packet drop, duplicate, flip bits, cut, or garbage before.
fn damage(rng: &mut Rng, packets: &[Vec<u8>]) -> Vec<u8> {
    let mut out = vec![0u8];
    let last = packets.len() - 1;
    for (i, p) in packets.iter().enumerate() {
        if i == last {
            out.extend(p);
            break;
        }
        let r = rng.unit();
        if r < 0.1 {
            continue;
        }
        let mut b = p.clone();
        if r < 0.3 {
            for _ in 0..1 + rng.below(3) {
                let k = rng.below(b.len());
                b[k] ^= 1 << rng.below(8);
            }
        } else if r < 0.4 {
            b.truncate(rng.below(b.len()));
            b.push(0);
        } else if r < 0.5 {
            let g: Vec<u8> = (0..rng.below(40)).map(|_| rng.below(256) as u8).collect();
            out.extend(g);
        }
        out.extend(&b);
        if rng.unit() < 0.1 {
            out.extend(&b);
        }
    }
    out
}

/// Every frame the decoder hands out (by id), fed in random chunks.
fn decoded_frames(rng: &mut Rng, stream: &[u8]) -> Vec<(u32, Frame<N, B>)> {
    let mut d = Box::new(Decoder::<N, B>::new(DataIds::DEFAULT));
    let mut out = Vec::new();
    let mut rest = stream;
    while !rest.is_empty() {
        let take = (1 + rng.below(300)).min(rest.len());
        let (mut piece, after) = rest.split_at(take);
        rest = after;
        while !piece.is_empty() {
            let (used, got) = d.feed(piece);
            assert!(used >= 1 && used <= piece.len());
            piece = &piece[used..];
            if let Some(Ok(Packet::Frame(f, info))) = got.map(|g| g.packet) {
                out.push((info.frame_id, f.clone()));
            }
        }
    }
    out
}

fn pairs(outputs: &[Vec<u8>]) -> BTreeMap<(u32, u32), Vec<u8>> {
    outputs
        .iter()
        .filter_map(|raw| {
            let c = check(raw).ok()?;
            (c.ptype == PacketType::Result).then_some(())?;
            let v = ResultView::parse(c.payload).ok()?;
            v.structure
                .then(|| ((v.kept_id, v.frame_id), c.payload.to_vec()))
        })
        .collect()
}

#[test]
fn structured_fuzz_of_the_decoder_with_the_processor() {
    let seconds: u64 = std::env::var("WIRE_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let seed: u64 = std::env::var("WIRE_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(12);
    let deadline = Instant::now() + Duration::from_secs(seconds);
    let mut rng = Rng(seed);
    let (mut cases, mut frames_checked, mut pairs_checked, mut bytes) = (0u64, 0u64, 0u64, 0u64);
    while Instant::now() < deadline {
        let c = case(&mut rng);
        let clean: Vec<u8> = std::iter::once(0u8)
            .chain(c.packets.iter().flatten().copied())
            .collect();
        let stream = damage(&mut rng, &c.packets);
        bytes += stream.len() as u64;
        // Decoded frames equal the encoded ones; invalid ones never come out.
        for (id, f) in decoded_frames(&mut rng, &stream) {
            match c.expect.get(&id) {
                Some(Ok(e)) => assert_eq!(&f, e, "case {cases}: frame {id}"),
                other => panic!("case {cases}: frame {id} decoded, expected {other:?}"),
            }
            frames_checked += 1;
        }
        // The clean stream gives every valid frame.
        let valid = c.expect.values().filter(|e| e.is_ok()).count();
        assert_eq!(
            decoded_frames(&mut rng, &clean).len(),
            valid,
            "case {cases}"
        );
        // Errors leave no trace in what the processor gives.
        let chunk = 1 + rng.below(200);
        let good = pairs(&host_outputs(&clean, chunk));
        for (k, payload) in pairs(&host_outputs(&stream, chunk)) {
            if let Some(g) = good.get(&k) {
                assert_eq!(&payload, g, "case {cases}: pair {k:?}");
                pairs_checked += 1;
            }
        }
        cases += 1;
    }
    println!(
        "wire fuzz: {cases} cases (seed {seed}, {seconds} s), {bytes} bytes, {frames_checked} decoded frames equal to the encoded ones, {pairs_checked} pairs identical to the undamaged run"
    );
    assert!(cases > 0);
}

/// An invalid boundary in an intact packet gives push_boundary's error.
#[test]
fn decoder_errors_are_push_boundary_errors() {
    let mut rng = Rng(5);
    let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).expect("valid");
    let mut raw = vec![0u8; 8 * 1024];
    let n = encode::camera(&mut raw, DataIds::DEFAULT.camera, 0, &cam).expect("fits");
    let mut stream = framed(&raw[..n]);
    let mut expected = Vec::new();
    for id in 0..2000u32 {
        let b = boundary(&mut rng, &cam);
        if b.len() > N {
            continue;
        }
        let head = FrameHead {
            timestamp_us: 0,
            frame_id: id,
            width: 512,
            height: 480,
        };
        let bh = BoundaryHead {
            quality: 0,
            radius_px: 0.5,
        };
        let n = encode::frame(
            &mut raw,
            DataIds::DEFAULT.frame,
            id as u16,
            &head,
            &[(bh, &b)],
        )
        .expect("fits");
        stream.extend(framed(&raw[..n]));
        let mut f = Frame::<N, B>::new(cam);
        expected.push(f.push_boundary(&b).err());
    }
    let mut d = Box::new(Decoder::<N, B>::new(DataIds::DEFAULT));
    let mut got = Vec::new();
    let mut rest = &stream[..];
    while !rest.is_empty() {
        let (used, out) = d.feed(rest);
        rest = &rest[used..];
        match out.map(|o| o.packet) {
            Some(Ok(Packet::Frame(..))) => got.push(None),
            Some(Err(roadstereo::wire::WireError::Boundary { error, .. })) => got.push(Some(error)),
            Some(Err(e)) => panic!("unexpected {e}"),
            _ => {}
        }
    }
    assert_eq!(got, expected);
    let bad = expected.iter().filter(|e| e.is_some()).count();
    assert!(bad > 100, "only {bad} invalid boundaries generated");
}
