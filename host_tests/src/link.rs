//! The host side of the camera front-end link (`roadstereo::wire`): a
//! recorded drive turned into the packets a front end and odometry would
//! send, seeded fault injection, and the host build of the controller's
//! receive loop (the reference the firmware is compared with, bit for bit).

use roadstereo::fusion::{Fusion, FusionConfig};
use roadstereo::wire::encode::{self, BoundaryHead, FrameHead, MotionFields, ResultHead, Sender};
use roadstereo::wire::{
    cobs_max, frame_packet_max, result_packet_max, DataIds, Event, FrameJob, PacketType, Receiver,
};
use roadstereo::{Camera, Config, Pixel, Processor, Step};

/// Capacity of the link firmware (`src/bin/link.rs`).
pub const N: usize = 256;
/// Boundaries per frame.
pub const B: usize = 2;

/// One recorded frame.
#[derive(Debug, Clone)]
pub struct LinkFrame {
    pub camera: Camera,
    /// Motion from the previous frame: translation, rotation.
    pub motion: Option<([f32; 3], [f32; 3])>,
    pub boundaries: Vec<Vec<[f32; 2]>>,
}

/// Read replay JSON Lines (blank lines skipped).
pub fn from_jsonl(text: &str) -> Result<Vec<LinkFrame>, String> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let f: crate::jsonl::FrameIn =
            serde_json::from_str(line).map_err(|e| format!("line {}: {e}", i + 1))?;
        let c = &f.camera;
        let camera = Camera::new(c.fx, c.fy, c.cx, c.cy, c.width, c.height)
            .map_err(|e| format!("line {}: camera: {e}", i + 1))?;
        out.push(LinkFrame {
            camera,
            motion: f.motion.map(|m| (m.translation, m.rotation)),
            boundaries: f.boundaries,
        });
    }
    Ok(out)
}

/// Read the firmware drive format (`src/bin/data/drive.bin`).
pub fn from_drive(bytes: &[u8]) -> Result<Vec<LinkFrame>, String> {
    let (camera, frames) = crate::drive::decode(bytes).ok_or("bad drive data")?;
    Ok(frames
        .into_iter()
        .enumerate()
        .map(|(i, f)| LinkFrame {
            camera,
            motion: (i > 0).then_some((f.translation, f.rotation)),
            boundaries: f.boundaries,
        })
        .collect())
}

/// What a packet on the link carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Camera,
    Motion,
    Frame,
    End,
}

/// One packet's link bytes (COBS frame with its delimiter).
#[derive(Debug, Clone)]
pub struct LinkPacket {
    pub kind: Kind,
    pub bytes: Vec<u8>,
}

/// COBS-frame a raw packet.
pub fn framed(raw: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8; cobs_max(raw.len())];
    let n = encode::cobs_frame(raw, &mut out).expect("buffer sized by cobs_max");
    out.truncate(n);
    out
}

/// The packets for `frames`: frame `i` has id `i` and timestamp `i` ×
/// 33 333 µs; a camera packet before the first frame, whenever the
/// camera changes and every 8 frames (a lost one is soon repeated); a
/// motion packet before each frame that has one; every boundary with the
/// localisation-error radius `radius` px; an end packet last.
pub fn packets(frames: &[LinkFrame], radius: f32) -> Result<Vec<LinkPacket>, String> {
    // (The sender numbers each data id's packets as the receiver checks.)
    let mut tx = Sender::new(DataIds::DEFAULT);
    let mut out = Vec::new();
    let mut raw = vec![0u8; frame_packet_max(N.max(4096), B.max(8))];
    let mut last_camera: Option<Camera> = None;
    for (i, f) in frames.iter().enumerate() {
        let id = i as u32;
        if last_camera != Some(f.camera) || i % 8 == 0 {
            let n = tx.camera(&mut raw, &f.camera).map_err(|e| e.to_string())?;
            out.push(LinkPacket {
                kind: Kind::Camera,
                bytes: framed(&raw[..n]),
            });
            last_camera = Some(f.camera);
        }
        if let (Some((t, r)), true) = (f.motion, i > 0) {
            let m = MotionFields {
                from: id - 1,
                to: id,
                translation: t,
                rotation: r,
                translation_error: None,
                rotation_error: None,
            };
            let n = tx.motion(&mut raw, &m).map_err(|e| e.to_string())?;
            out.push(LinkPacket {
                kind: Kind::Motion,
                bytes: framed(&raw[..n]),
            });
        }
        let head = FrameHead {
            timestamp_us: u64::from(id) * 33_333,
            frame_id: id,
            width: f.camera.width(),
            height: f.camera.height(),
        };
        let pts: Vec<Vec<Pixel>> = f
            .boundaries
            .iter()
            .map(|b| b.iter().map(|p| Pixel::new(p[0], p[1])).collect())
            .collect();
        let list: Vec<(BoundaryHead, &[Pixel])> = pts
            .iter()
            .map(|p| {
                (
                    BoundaryHead {
                        quality: 255,
                        radius_px: radius,
                    },
                    p.as_slice(),
                )
            })
            .collect();
        let n = tx
            .frame(&mut raw, &head, &list)
            .map_err(|e| format!("frame {i}: {e}"))?;
        out.push(LinkPacket {
            kind: Kind::Frame,
            bytes: framed(&raw[..n]),
        });
    }
    let n = tx.end(&mut raw).map_err(|e| e.to_string())?;
    out.push(LinkPacket {
        kind: Kind::End,
        bytes: framed(&raw[..n]),
    });
    Ok(out)
}

/// Fault rates (each a probability per packet).
#[derive(Debug, Clone, Copy, Default)]
pub struct Faults {
    pub corrupt: f64,
    pub drop: f64,
    pub duplicate: f64,
    pub seed: u64,
}

/// What was injected.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Injected {
    pub corrupted: u32,
    pub dropped: u32,
    pub duplicated: u32,
}

/// A small deterministic generator (splitmix64).
pub struct Rng(pub u64);
impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// The byte stream for `packets` with faults: a leading delimiter, then
/// each packet (never the end packet) dropped, sent twice, or sent with one
/// bit flipped, each with its probability. Several faults can hit one
/// packet (a duplicate of a corrupted one is corrupted twice over).
pub fn inject(packets: &[LinkPacket], f: &Faults) -> (Vec<u8>, Injected) {
    let mut rng = Rng(f.seed);
    let mut out = vec![0u8];
    let mut n = Injected::default();
    for p in packets {
        if p.kind == Kind::End {
            out.extend(&p.bytes);
            continue;
        }
        if rng.unit() < f.drop {
            n.dropped += 1;
            continue;
        }
        let copies = if rng.unit() < f.duplicate {
            n.duplicated += 1;
            2
        } else {
            1
        };
        for _ in 0..copies {
            let mut b = p.bytes.clone();
            if rng.unit() < f.corrupt {
                n.corrupted += 1;
                let i = rng.below(b.len());
                b[i] ^= 1 << rng.below(8);
            }
            out.extend(b);
        }
    }
    (out, n)
}

/// The controller's receive loop on the host, as `src/bin/link.rs` runs
/// it: every raw output packet (results with 0 instructions, reports, and
/// the summary at the end), in order.
pub fn host_outputs(stream: &[u8], chunk: usize) -> Vec<Vec<u8>> {
    let mut p = Box::new(Processor::<N, B>::new(Config::DEFAULT));
    receive_loop(stream, chunk, |job, raw, counter| {
        let step = job.run(&mut p).expect("a job always runs");
        let head: ResultHead = job.result_head(0);
        encode::result(
            raw,
            DataIds::DEFAULT.result,
            counter,
            &head,
            &step,
            &job.kept_quality,
        )
        .map(Some)
        .expect("result buffer sized by result_packet_max")
    })
}

/// Map points per boundary of the link firmware's fusion (feature
/// `link-fused`).
pub const M: usize = 512;

/// [`host_outputs`] as the link firmware runs it with the feature
/// `link-fused`: each frame through a key-frame fusion
/// (`FrameJob::run_fused`), its result the key frame's pair with it (the
/// head's `kept` id the key frame's; no structure when the frame was not
/// paired), a frame the fusion refuses no packet; and, per frame run, the
/// frame's id and the fusion's digest after it (the firmware logs them).
pub fn host_outputs_fused(stream: &[u8], chunk: usize) -> (Vec<Vec<u8>>, Vec<(u32, u32)>) {
    let mut f = Box::new(Fusion::<N, B, M>::new(
        Config::DEFAULT,
        FusionConfig::DEFAULT,
    ));
    let mut key_quality = [0u8; B];
    let mut digests = Vec::new();
    let out = receive_loop(stream, chunk, |job, raw, counter| {
        let key = f.key_id();
        let step = job.run_fused(&mut f).ok()?;
        let paired = step.paired.and(key);
        let quality = if paired.is_some() {
            key_quality
        } else {
            job.info.quality
        };
        if step.new_key.is_some() {
            key_quality = job.info.quality;
        }
        digests.push((job.info.frame_id, f.digest()));
        let mut head: ResultHead = job.result_head(0);
        head.kept_id = paired.unwrap_or(job.info.frame_id);
        let result = match paired {
            Some(_) => Step::Structure(f.structure()),
            None => Step::First,
        };
        encode::result(
            raw,
            DataIds::DEFAULT.result,
            counter,
            &head,
            &result,
            &quality,
        )
        .map(Some)
        .expect("result buffer sized by result_packet_max")
    });
    (out, digests)
}

/// The receive loop: each frame job to `on_frame`, which writes its
/// result packet into the buffer with the counter given and returns its
/// length (`None`: no packet); reports and the summary as the firmware
/// sends them.
fn receive_loop(
    stream: &[u8],
    chunk: usize,
    mut on_frame: impl FnMut(&FrameJob<'_, N, B>, &mut [u8], u16) -> Option<usize>,
) -> Vec<Vec<u8>> {
    let ids = DataIds::DEFAULT;
    let mut rx = Box::new(Receiver::<N, B>::new(ids, Config::DEFAULT));
    let mut raw = vec![0u8; result_packet_max(N, B)];
    let (mut results, mut reports) = (0u16, 0u16);
    let mut out = Vec::new();
    let mut end = false;
    for piece in stream.chunks(chunk.max(1)) {
        rx.feed(piece, |ev| match ev {
            Event::Frame(job) => {
                if let Some(n) = on_frame(&job, &mut raw, results) {
                    results = results.wrapping_add(1);
                    out.push(raw[..n].to_vec());
                }
            }
            Event::Error(e) => {
                let n = encode::report(&mut raw, ids.report, reports, &e).expect("report fits");
                reports = reports.wrapping_add(1);
                out.push(raw[..n].to_vec());
            }
            Event::End => end = true,
            Event::Motion(_) | Event::Camera(_) => {}
        });
        if end {
            let c = *rx.counters();
            let n = encode::summary(&mut raw, ids.summary, 0, &c.values()).expect("summary fits");
            out.push(raw[..n].to_vec());
            break;
        }
    }
    out
}

/// Split link bytes at the delimiters and COBS-decode each frame (with the
/// `cobs` crate); frames that do not decode are kept as `Err`.
pub fn split_link(bytes: &[u8]) -> Vec<Result<Vec<u8>, Vec<u8>>> {
    bytes
        .split(|&b| b == 0)
        .filter(|f| !f.is_empty())
        .map(|f| {
            let mut buf = f.to_vec();
            match cobs::decode_in_place(&mut buf) {
                Ok(n) => {
                    buf.truncate(n);
                    Ok(buf)
                }
                Err(_) => Err(f.to_vec()),
            }
        })
        .collect()
}

/// The packet type of a raw output packet.
pub fn type_of(raw: &[u8]) -> Option<PacketType> {
    raw.get(3).and_then(|&c| PacketType::from_code(c))
}
