//! A straightforward reference decoder written from `docs/wire.md`, for a
//! differential test of `roadstereo::wire::Decoder`: the stream is split at
//! every zero byte, each frame decoded with the `cobs` crate, the CRC
//! checked with `crc::Crc::<u32>::new(&crc::CRC_32_AUTOSAR).checksum`, and
//! the fields parsed one by one; boundaries go through
//! `Frame::push_boundary`.

use roadstereo::wire::{DataIds, Decoder, Packet, PacketType, WireError};
use roadstereo::{BoundaryError, Camera, Config, Frame, Motion, Pixel};

pub const CRC: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_AUTOSAR);

/// One output of either decoder, comparable bit for bit.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Out {
    Frame {
        camera: String,
        /// Points' `(u, v)` bits per boundary.
        boundaries: Vec<Vec<(u32, u32)>>,
        timestamp_us: u64,
        frame_id: u32,
        counter: u16,
        quality: Vec<u8>,
        radius_bits: Vec<u32>,
    },
    Motion(String),
    Camera(String),
    End,
    Err(WireError),
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Got {
    pub missed: u16,
    pub out: Out,
}

/// docs/wire.md: `raw = 16 (px + 1) + 0x0101` (exact in `f32`).
fn raw_to_px(raw: u16) -> f32 {
    ((f64::from(raw) - 257.0) / 16.0 - 1.0) as f32
}
/// docs/wire.md: 1/256 px.
fn raw_to_radius(raw: u16) -> f32 {
    (f64::from(raw) / 256.0) as f32
}

fn le16(b: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([b[at], b[at + 1]])
}
fn le32(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}
fn lef32(b: &[u8], at: usize) -> f32 {
    f32::from_bits(le32(b, at))
}

fn frame_out<const N: usize, const B: usize>(
    f: &Frame<N, B>,
    ts: u64,
    id: u32,
    counter: u16,
    quality: &[u8],
    radius: &[f32],
) -> Out {
    Out::Frame {
        camera: format!("{:?}", f.camera()),
        boundaries: f
            .boundaries()
            .iter()
            .map(|b| {
                b.points()
                    .iter()
                    .map(|p| (p.u.to_bits(), p.v.to_bits()))
                    .collect()
            })
            .collect(),
        timestamp_us: ts,
        frame_id: id,
        counter,
        quality: quality.to_vec(),
        radius_bits: radius.iter().map(|r| r.to_bits()).collect(),
    }
}

/// The reference decoder's state.
pub struct Reference<const N: usize, const B: usize> {
    ids: DataIds,
    camera: Option<Camera>,
    last: [Option<u16>; 4],
}

impl<const N: usize, const B: usize> Reference<N, B> {
    pub fn new(ids: DataIds) -> Self {
        Self {
            ids,
            camera: None,
            last: [None; 4],
        }
    }

    /// Every output for `stream` (in order).
    pub fn run(&mut self, stream: &[u8]) -> Vec<Got> {
        let mut out = Vec::new();
        let mut parts: Vec<&[u8]> = stream.split(|&b| b == 0).collect();
        // The last part has no delimiter after it: no output.
        parts.pop();
        for p in parts {
            if p.is_empty() {
                continue;
            }
            out.push(self.frame(p));
        }
        out
    }

    fn frame(&mut self, src: &[u8]) -> Got {
        let err = |e| Got {
            missed: 0,
            out: Out::Err(e),
        };
        let mut dest = vec![0u8; src.len() + 1];
        let mut input = src.to_vec();
        input.push(0);
        let mut dec = cobs::CobsDecoder::new(&mut dest);
        let bytes = match dec.push(&input) {
            Ok(Some(r)) => {
                let n = r.frame_size();
                dest[..n].to_vec()
            }
            Ok(None) => unreachable!("the delimiter ends the frame"),
            Err(cobs::DecodeError::InvalidFrame { decoded_bytes }) => {
                return err(WireError::Truncated {
                    len: decoded_bytes as u32,
                })
            }
            Err(e) => panic!("cobs: {e:?}"),
        };
        let len = bytes.len();
        if len < 14 {
            return err(WireError::Truncated { len: len as u32 });
        }
        if CRC.checksum(&bytes[..len - 4]) != le32(&bytes, len - 4) {
            return err(WireError::BadCrc);
        }
        if bytes[..2] != *b"RS" {
            return err(WireError::BadMagic);
        }
        if bytes[2] != 1 {
            return err(WireError::UnknownVersion { version: bytes[2] });
        }
        let code = bytes[3];
        let (t, slot) = match code {
            0x01 => (PacketType::Frame, 0),
            0x02 => (PacketType::Motion, 1),
            0x03 => (PacketType::Camera, 2),
            0x7F => (PacketType::End, 3),
            _ => return err(WireError::UnknownType { code }),
        };
        let declared = u32::from(le16(&bytes, 8));
        let actual = (len - 14) as u32;
        if declared != actual {
            return err(WireError::BadLength { declared, actual });
        }
        let data_id = le16(&bytes, 4);
        let expected = self.ids.of(t);
        if data_id != expected {
            return err(WireError::WrongDataId {
                expected,
                got: data_id,
            });
        }
        let counter = le16(&bytes, 6);
        let mut missed = 0;
        if let Some(prev) = self.last[slot] {
            if prev == counter {
                return err(WireError::Repeated { counter });
            }
            missed = counter.wrapping_sub(prev).wrapping_sub(1);
        }
        self.last[slot] = Some(counter);
        let payload = &bytes[10..len - 4];
        let out = match t {
            PacketType::Frame => self.frame_payload(payload, counter),
            PacketType::Motion => motion_payload(payload),
            PacketType::Camera => self.camera_payload(payload),
            _ => {
                if payload.is_empty() {
                    Out::End
                } else {
                    Out::Err(WireError::BadLength {
                        declared,
                        actual: 0,
                    })
                }
            }
        };
        Got { missed, out }
    }

    fn frame_payload(&mut self, p: &[u8], counter: u16) -> Out {
        let l = p.len() as u32;
        let bad_len = |need: usize| {
            Out::Err(WireError::BadLength {
                declared: l,
                actual: need as u32,
            })
        };
        if p.len() < 18 {
            return bad_len(18);
        }
        let ts = u64::from(le32(p, 0)) | (u64::from(le32(p, 4)) << 32);
        let id = le32(p, 8);
        let (w, h) = (le16(p, 12), le16(p, 14));
        let nb = p[16];
        let Some(cam) = self.camera else {
            return Out::Err(WireError::NoCamera);
        };
        if w != cam.width() || h != cam.height() {
            return Out::Err(WireError::ImageSize {
                width: w,
                height: h,
            });
        }
        if usize::from(nb) > B {
            return Out::Err(WireError::TooManyBoundaries {
                count: nb,
                capacity: B as u8,
            });
        }
        let mut frame = Frame::<N, B>::new(cam);
        let mut quality = vec![0u8; B];
        let mut radius = vec![0f32; B];
        let mut off = 18usize;
        for k in 0..usize::from(nb) {
            if off + 6 > p.len() {
                return bad_len(off + 6);
            }
            let index = p[off];
            if usize::from(index) != k {
                return Out::Err(WireError::BoundaryIndex {
                    expected: k as u8,
                    got: index,
                });
            }
            let n = le16(p, off + 4);
            if n == 0 {
                // An absent boundary: its radius ignored, unchecked.
                frame.push_absent().expect("a slot: the count is at most B");
                quality[k] = p[off + 1];
                radius[k] = 0.0;
                off += 6;
                continue;
            }
            let r = raw_to_radius(le16(p, off + 2));
            if r > 100.0 {
                return Out::Err(WireError::Radius { boundary: k as u8 });
            }
            if usize::from(n) > N {
                return Out::Err(WireError::TooManyPoints {
                    boundary: k as u8,
                    len: n,
                    capacity: N as u16,
                });
            }
            if n < 2 {
                return Out::Err(WireError::Boundary {
                    boundary: k as u8,
                    error: BoundaryError::TooFewPoints,
                });
            }
            let end = off + 6 + 4 * usize::from(n);
            if end > p.len() {
                return bad_len(end);
            }
            let pts: Vec<Pixel> = (0..usize::from(n))
                .map(|i| {
                    let at = off + 6 + 4 * i;
                    Pixel::new(raw_to_px(le16(p, at)), raw_to_px(le16(p, at + 2)))
                })
                .collect();
            if let Err(error) = frame.push_boundary(&pts) {
                return Out::Err(WireError::Boundary {
                    boundary: k as u8,
                    error,
                });
            }
            quality[k] = p[off + 1];
            radius[k] = r;
            off = end;
        }
        if off != p.len() {
            return bad_len(off);
        }
        frame_out(&frame, ts, id, counter, &quality, &radius)
    }

    fn camera_payload(&mut self, p: &[u8]) -> Out {
        if p.len() < 20 {
            return Out::Err(WireError::BadLength {
                declared: p.len() as u32,
                actual: 20,
            });
        }
        let f = |i: usize| lef32(p, 4 * i);
        match Camera::new(f(0), f(1), f(2), f(3), le16(p, 16), le16(p, 18)) {
            Err(e) => Out::Err(WireError::Camera(e)),
            Ok(_) if p.len() != 20 => Out::Err(WireError::BadLength {
                declared: p.len() as u32,
                actual: 20,
            }),
            Ok(c) => {
                self.camera = Some(c);
                Out::Camera(format!("{c:?}"))
            }
        }
    }
}

fn motion_payload(p: &[u8]) -> Out {
    if p.len() < 52 {
        return Out::Err(WireError::BadLength {
            declared: p.len() as u32,
            actual: 52,
        });
    }
    let f = |i: usize| lef32(p, 8 + 4 * i);
    let motion = match Motion::new([f(0), f(1), f(2)], [f(3), f(4), f(5)]) {
        Ok(m) => m,
        Err(e) => return Out::Err(WireError::Motion(e)),
    };
    let flags = p[32];
    let te = (flags & 1 != 0).then(|| lef32(p, 36));
    let re = (flags & 2 != 0).then(|| [lef32(p, 40), lef32(p, 44), lef32(p, 48)]);
    if let Some(t) = te {
        if let Err(e) = Config::DEFAULT.with_translation_error(t) {
            return Out::Err(WireError::MotionBounds(e));
        }
    }
    if let Some(r) = re {
        // The bounds as sent, then their box about the camera's axes (the
        // library's `euler_error_box`, not a second form of it: a box a
        // rounding apart would split the verdicts at the limit; the box
        // itself is held to `f64` rotations in `tests/motion_error.rs`).
        let axes = roadstereo::motion_error::euler_error_box(motion.angles(), r)
            .unwrap_or([f32::INFINITY; 3]);
        for v in [r, axes] {
            if let Err(e) = Config::DEFAULT.with_rotation_error(v) {
                return Out::Err(WireError::MotionBounds(e));
            }
        }
    }
    if p.len() != 52 {
        return Out::Err(WireError::BadLength {
            declared: p.len() as u32,
            actual: 52,
        });
    }
    Out::Motion(format!(
        "{:?}",
        (
            le32(p, 0),
            le32(p, 4),
            motion,
            te.map(f32::to_bits),
            re.map(|r| r.map(f32::to_bits))
        )
    ))
}

/// The decoder under test over `stream`, fed in chunks of the sizes
/// `chunks` gives (cycled).
pub fn decoder_run<const N: usize, const B: usize>(stream: &[u8], chunks: &[usize]) -> Vec<Got> {
    let mut d = Box::new(Decoder::<N, B>::new(DataIds::DEFAULT));
    let mut out = Vec::new();
    let mut rest = stream;
    let mut ci = 0;
    while !rest.is_empty() {
        let take = chunks[ci % chunks.len()].clamp(1, rest.len());
        ci += 1;
        let (mut piece, after) = rest.split_at(take);
        rest = after;
        while !piece.is_empty() {
            let (used, got) = d.feed(piece);
            assert!(
                used >= 1 && used <= piece.len(),
                "feed used {used} of {}",
                piece.len()
            );
            piece = &piece[used..];
            if let Some(g) = got {
                let o = match g.packet {
                    Ok(Packet::Frame(f, info)) => frame_out(
                        f,
                        info.timestamp_us,
                        info.frame_id,
                        info.counter,
                        &info.quality,
                        &info.radius_px,
                    ),
                    Ok(Packet::Motion(m)) => Out::Motion(format!(
                        "{:?}",
                        (
                            m.from,
                            m.to,
                            m.motion,
                            m.translation_error.map(f32::to_bits),
                            m.rotation_error.map(|r| r.map(f32::to_bits)),
                        )
                    )),
                    Ok(Packet::Camera(c)) => Out::Camera(format!("{c:?}")),
                    Ok(Packet::End) => Out::End,
                    Err(e) => Out::Err(e),
                };
                out.push(Got {
                    missed: g.missed,
                    out: o,
                });
            }
        }
    }
    out
}

/// Both over `stream`: the index of the first disagreement and the two
/// outputs there, if any. (A test's error value: its size does not matter.)
#[allow(clippy::result_large_err)]
pub fn compare<const N: usize, const B: usize>(
    stream: &[u8],
    chunks: &[usize],
) -> Result<usize, (usize, Option<Got>, Option<Got>)> {
    let r = Reference::<N, B>::new(DataIds::DEFAULT).run(stream);
    let d = decoder_run::<N, B>(stream, chunks);
    for i in 0..r.len().max(d.len()) {
        if r.get(i) != d.get(i) {
            return Err((i, r.get(i).cloned(), d.get(i).cloned()));
        }
    }
    Ok(r.len())
}

/// A raw packet (before COBS) with its CRC.
pub fn packet(ptype: u8, data_id: u16, counter: u16, payload: &[u8]) -> Vec<u8> {
    let mut b = Vec::with_capacity(payload.len() + 14);
    b.extend_from_slice(b"RS");
    b.push(1);
    b.push(ptype);
    b.extend_from_slice(&data_id.to_le_bytes());
    b.extend_from_slice(&counter.to_le_bytes());
    b.extend_from_slice(&(payload.len() as u16).to_le_bytes());
    b.extend_from_slice(payload);
    let c = CRC.checksum(&b);
    b.extend_from_slice(&c.to_le_bytes());
    b
}

/// Recompute the CRC of a raw packet (its last four bytes).
pub fn fix_crc(b: &mut [u8]) {
    if b.len() >= 4 {
        let n = b.len() - 4;
        let c = CRC.checksum(&b[..n]);
        b[n..].copy_from_slice(&c.to_le_bytes());
    }
}

/// COBS with its delimiter.
pub fn link(raw: &[u8]) -> Vec<u8> {
    let mut v = cobs::encode_vec(raw);
    v.push(0);
    v
}
