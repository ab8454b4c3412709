//! Differential test: `roadstereo::wire::Decoder` against the reference of
//! `host_tests::wire_ref` (written from docs/wire.md) over random valid
//! packets in random chunks and over mutated packets.
//! `WIRE_DIFF_SECONDS` (default 10), `WIRE_DIFF_SEED` (default 1).

use std::time::{Duration, Instant};

use host_tests::link::Rng;
use host_tests::wire_ref::{compare, fix_crc, link, packet, Out, Reference};
use roadstereo::wire::{DataIds, WireError};
use std::collections::BTreeMap;

const BASE: u32 = 0x0101;
static STATS: std::sync::Mutex<BTreeMap<String, u64>> = std::sync::Mutex::new(BTreeMap::new());

struct Cam {
    w: u16,
    h: u16,
}

/// Raw positions where a COBS run starts (after a zero, after 254
/// non-zero bytes), and the 254-splits alone.
fn run_starts(raw: &[u8]) -> (Vec<usize>, Vec<usize>) {
    let (mut all, mut long) = (Vec::new(), Vec::new());
    let mut run = 0;
    for (i, &b) in raw.iter().enumerate() {
        if b == 0 {
            all.push(i + 1);
            run = 0;
        } else {
            run += 1;
            if run == 254 {
                all.push(i + 1);
                long.push(i + 1);
                run = 0;
            }
        }
    }
    (all, long)
}

fn link_pos(long: &[usize], raw_i: usize) -> usize {
    1 + raw_i + long.iter().filter(|&&s| s <= raw_i).count()
}

struct Gen {
    rng: Rng,
    n_cap: usize,
    b_cap: usize,
}

impl Gen {
    fn p(&mut self, x: f64) -> bool {
        self.rng.unit() < x
    }
    fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[self.rng.below(xs.len())]
    }

    fn camera_payload(&mut self, c: &Cam) -> Vec<u8> {
        let mut p = Vec::new();
        for x in [800.0f32, 790.0, c.w as f32 / 2.0, c.h as f32 / 2.0] {
            p.extend_from_slice(&x.to_le_bytes());
        }
        p.extend_from_slice(&c.w.to_le_bytes());
        p.extend_from_slice(&c.h.to_le_bytes());
        p
    }

    fn motion_payload(&mut self, from: u32, to: u32) -> Vec<u8> {
        let mut p = Vec::new();
        p.extend_from_slice(&from.to_le_bytes());
        p.extend_from_slice(&to.to_le_bytes());
        // Roll and yaw too, sometimes: where the angles' bounds and their
        // box about the axes differ most.
        let turn = if self.p(0.5) { 0.6 } else { 0.0 };
        let vals: [f32; 6] = [
            (self.rng.unit() as f32 - 0.5) * 0.2,
            0.0,
            0.1 + self.rng.unit() as f32,
            (self.rng.unit() as f32 - 0.5) * turn,
            (self.rng.unit() as f32 - 0.5) * 0.1,
            (self.rng.unit() as f32 - 0.5) * turn,
        ];
        for v in vals {
            p.extend_from_slice(&v.to_le_bytes());
        }
        let flags = self.rng.below(4) as u8;
        p.push(flags);
        p.extend_from_slice(&[0, 0, 0]);
        let te: f32 = if self.p(0.1) { -1.0 } else { 0.01 };
        p.extend_from_slice(&te.to_le_bytes());
        // Small bounds, bounds whose own sum is within 0.1 but whose box
        // about the axes is not (refused for the box), or a NaN.
        let rot = if self.p(0.3) {
            [0.04f32, 0.03, 0.029]
        } else {
            [0.001, 0.002, if self.p(0.1) { f32::NAN } else { 0.0 }]
        };
        for v in rot {
            p.extend_from_slice(&v.to_le_bytes());
        }
        p
    }

    /// One coordinate in range `[BASE, BASE + limit]`, by mode.
    fn coord(&mut self, limit: u32, zero_low: bool) -> u32 {
        let mut r = BASE + self.rng.below(limit as usize + 1) as u32;
        if zero_low {
            r &= !0xFF;
            if r < 0x200 {
                r = 0x200;
            }
            if r > BASE + limit {
                r = BASE + 8 * (self.rng.below((limit / 8) as usize + 1) as u32);
            }
        } else if self.p(0.5) {
            // Half-pixel grid: no zero byte.
            r = BASE + 8 * ((r - BASE) / 8);
        }
        r
    }

    /// Points (raw words) of one valid boundary of `n` points.
    fn points(&mut self, c: &Cam, n: usize) -> Vec<(u32, u32)> {
        let (lu, lv) = (16 * (u32::from(c.w) + 1), 16 * (u32::from(c.h) + 1));
        let up = self.p(0.5);
        let zero_p = self.pick(&[0.0, 0.0, 0.1, 0.3, 0.8]);
        let span = lv as usize;
        let max_step = (span / n.max(1)).max(1);
        let step_cap = self.pick(&[1usize, 2, 8, 16, 40, 256, max_step]);
        let step_cap = step_cap.min(max_step).max(1);
        let total: usize = n * step_cap;
        let mut v = if total >= span {
            0
        } else {
            self.rng.below(span - total + 1)
        } as u32;
        let mut pts = Vec::new();
        let mut u = self.coord(lu, false);
        for _ in 0..n {
            if self.p(0.7) {
                let zl = self.p(zero_p);
                u = self.coord(lu, zl);
            } else {
                u = (u as i64 + self.rng.below(33) as i64 - 16)
                    .clamp(BASE as i64, (BASE + lu) as i64) as u32;
            }
            pts.push((u, v));
            let mut s = 1 + self.rng.below(step_cap) as u32;
            if self.p(zero_p) {
                // Land on a zero low byte when possible.
                let vr = BASE + v + s;
                let next = (vr | 0xFF) + 1;
                if next - BASE - v <= step_cap as u32 {
                    s = next - BASE - v;
                }
            }
            v += s;
        }
        // v values: raw offsets from BASE; map to raw and direction.
        pts.iter()
            .map(|&(u, v)| {
                let vv = if up { v } else { v.min(lv) };
                let vraw = if up {
                    BASE + vv
                } else {
                    BASE + lv - vv.min(lv)
                };
                (u, vraw.min(BASE + lv))
            })
            .collect()
    }
}

struct FramePkt {
    raw: Vec<u8>,
    /// Raw offsets of interest (a mutated point's first byte).
    hot: Vec<usize>,
}

fn frame_packet(g: &mut Gen, c: &Cam, id: u32, counter: u16, mutate: bool) -> FramePkt {
    let nb = if g.p(0.03) {
        g.b_cap + 1
    } else {
        g.rng.below(g.b_cap + 1).max(if g.p(0.9) { 1 } else { 0 })
    };
    let mut bounds: Vec<Vec<(u32, u32)>> = Vec::new();
    for _ in 0..nb {
        let n = match g.rng.below(10) {
            0 => g.n_cap,
            1 => 2,
            2 => 3,
            3 => 2 + g.rng.below(8),
            _ => 2 + g.rng.below(g.n_cap - 1),
        };
        bounds.push(g.points(c, n));
    }
    let mut hot = Vec::new();
    let mut p = Vec::new();
    p.extend_from_slice(&(u64::from(id) * 33_333 + 7).to_le_bytes());
    p.extend_from_slice(&id.to_le_bytes());
    p.extend_from_slice(&c.w.to_le_bytes());
    p.extend_from_slice(&c.h.to_le_bytes());
    p.push(nb as u8);
    p.push(0);
    let mut offs = Vec::new();
    for (k, b) in bounds.iter().enumerate() {
        p.push(k as u8);
        p.push(g.rng.below(256) as u8);
        let rr = g.rng.below(25601) as u16;
        let r: u16 = g.pick(&[0, 1, 64, 256, 25600, rr]);
        p.extend_from_slice(&r.to_le_bytes());
        p.extend_from_slice(&(b.len() as u16).to_le_bytes());
        let mut o = Vec::new();
        for &(u, v) in b {
            o.push(10 + p.len());
            p.extend_from_slice(&(u as u16).to_le_bytes());
            p.extend_from_slice(&(v as u16).to_le_bytes());
        }
        offs.push((10 + p.len() - 6 - 4 * b.len(), o));
    }
    let mut raw = packet(0x01, 0x0F01, counter, &p);
    if !mutate {
        return FramePkt { raw, hot };
    }
    let (lu, lv) = (16 * (u32::from(c.w) + 1), 16 * (u32::from(c.h) + 1));
    let (starts, _) = run_starts(&raw);
    let times = 1 + g.rng.below(2);
    for _ in 0..times {
        let what = g.rng.below(20);
        if what < 13 && !offs.is_empty() {
            let k = g.rng.below(offs.len());
            let pts = offs[k].1.clone();
            if pts.is_empty() {
                continue;
            }
            let last = pts.len() - 1;
            let straddling: Vec<usize> = (0..pts.len())
                .filter(|&i| starts.iter().any(|&s| s > pts[i] && s < pts[i] + 4))
                .collect();
            let i = match g.rng.below(8) {
                0 => 0,
                1 => 1.min(last),
                2 => 2.min(last),
                3 => last,
                4 => last.saturating_sub(1),
                5 | 6 if !straddling.is_empty() => straddling[g.rng.below(straddling.len())],
                _ => g.rng.below(pts.len()),
            };
            let o = pts[i];
            if o + 4 > raw.len() {
                continue;
            }
            hot.push(o);
            let rd =
                |raw: &Vec<u8>, at: usize| u32::from(u16::from_le_bytes([raw[at], raw[at + 1]]));
            let set = |raw: &mut Vec<u8>, at: usize, x: u32| {
                raw[at..at + 2].copy_from_slice(&(x as u16).to_le_bytes())
            };
            match g.rng.below(12) {
                0 => {
                    let x = g.pick(&[
                        BASE + lu + 1,
                        BASE + lu,
                        0x100,
                        0xFF,
                        0,
                        0xFFFF,
                        BASE,
                        0x1FF,
                    ]);
                    set(&mut raw, o, x)
                }
                1 => {
                    let x = g.pick(&[
                        BASE + lv + 1,
                        BASE + lv,
                        0x100,
                        0xFF,
                        0,
                        0xFFFF,
                        BASE,
                        0x1FF,
                    ]);
                    set(&mut raw, o + 2, x)
                }
                2 if i > 0 => {
                    // Same row as the previous point.
                    let pv = rd(&raw, pts[i - 1] + 2);
                    set(&mut raw, o + 2, pv)
                }
                3 if i > 0 => {
                    // Duplicate of the previous point.
                    let (pu, pv) = (rd(&raw, pts[i - 1]), rd(&raw, pts[i - 1] + 2));
                    set(&mut raw, o, pu);
                    set(&mut raw, o + 2, pv)
                }
                4 if i > 0 => {
                    // Step the other way.
                    let pv = rd(&raw, pts[i - 1] + 2);
                    let v = rd(&raw, o + 2);
                    let back = 2 * pv as i64 - v as i64;
                    set(&mut raw, o + 2, back.clamp(0, 0xFFFF) as u32)
                }
                5..=7 => {
                    let j = g.rng.below(4);
                    raw[o + j] = 0;
                }
                8 => {
                    let j = g.rng.below(4);
                    raw[o + j] = g.rng.below(256) as u8;
                }
                9 => {
                    // u equal to the previous u but a valid row step: fine.
                    if i > 0 {
                        let pu = rd(&raw, pts[i - 1]);
                        set(&mut raw, o, pu)
                    }
                }
                _ => {
                    let j = g.rng.below(4);
                    raw[o + j] ^= 1 << g.rng.below(8);
                }
            }
        } else {
            // Header and field changes.
            if raw.len() < 10 + 18 + 4 || offs.iter().any(|(h, _)| h + 6 > raw.len()) {
                continue;
            }
            match g.rng.below(12) {
                0 => {
                    let l = u16::from_le_bytes([raw[8], raw[9]]);
                    let d = g.pick(&[1i32, -1, 4, -4, 6, -6, 100]);
                    raw[8..10].copy_from_slice(&((l as i32 + d) as u16).to_le_bytes());
                }
                1 => raw[10 + 16] = g.rng.below(5) as u8,
                2 if !offs.is_empty() => {
                    let (h, _) = offs[g.rng.below(offs.len())];
                    raw[h] = g.rng.below(4) as u8
                }
                3 if !offs.is_empty() => {
                    let (h, _) = offs[g.rng.below(offs.len())];
                    let r: u16 = g.pick(&[25600, 25601, 0xFFFF, 0]);
                    raw[h + 2..h + 4].copy_from_slice(&r.to_le_bytes())
                }
                4 if !offs.is_empty() => {
                    let (h, ref o) = offs[g.rng.below(offs.len())];
                    let n = o.len() as i32;
                    let x = g.pick(&[
                        0i32,
                        1,
                        2,
                        n - 1,
                        n + 1,
                        g.n_cap as i32,
                        g.n_cap as i32 + 1,
                        0xFFFF,
                    ]);
                    raw[h + 4..h + 6].copy_from_slice(&(x.clamp(0, 0xFFFF) as u16).to_le_bytes())
                }
                5 => raw[10 + 12] ^= 1,
                6 => raw[10 + 14] ^= 2,
                7 => raw[g.rng.below(4)] ^= 1 << g.rng.below(8),
                8 => raw[4] ^= 1,
                9 => {
                    let cut = 10 + g.rng.below(raw.len() - 10);
                    raw.truncate(cut);
                    raw.extend_from_slice(&[0; 4]);
                    let l = (raw.len() - 14) as u16;
                    if g.p(0.7) {
                        raw[8..10].copy_from_slice(&l.to_le_bytes());
                    }
                }
                10 => {
                    let at = raw.len() - 4;
                    let extra = 1 + g.rng.below(9);
                    for _ in 0..extra {
                        raw.insert(at, 1 + g.rng.below(255) as u8);
                    }
                    if g.p(0.7) {
                        let l = (raw.len() - 14) as u16;
                        raw[8..10].copy_from_slice(&l.to_le_bytes());
                    }
                }
                _ => {
                    let at = 10 + g.rng.below(raw.len() - 14);
                    raw[at] ^= 1 << g.rng.below(8);
                }
            }
        }
    }
    if g.p(0.9) {
        fix_crc(&mut raw);
    }
    FramePkt { raw, hot }
}

struct Case {
    /// The raw packets (for the libFuzzer seed corpus).
    raws: Vec<Vec<u8>>,
    stream: Vec<u8>,
    /// Stream offsets of interest (feed splits go there).
    hot: Vec<usize>,
}

fn case(g: &mut Gen) -> Case {
    let cams = [
        Cam { w: 512, h: 480 },
        Cam { w: 1024, h: 960 },
        Cam { w: 16, h: 12 },
        Cam { w: 4000, h: 4000 },
        Cam { w: 16384, h: 16384 },
        Cam { w: 300, h: 2 },
    ];
    let ci = g.rng.below(cams.len());
    let mut c = &cams[ci];
    let mut stream = Vec::new();
    if g.p(0.9) {
        stream.push(0);
    }
    let mut hot = Vec::new();
    let mutate_rate = g.pick(&[0.0, 0.2, 0.5, 1.0]);
    let link_rate = g.pick(&[0.0, 0.0, 0.1, 0.3]);
    let mut counters = [0u16; 4];
    let mut raws: Vec<(Vec<u8>, Vec<usize>)> = Vec::new();
    if g.p(0.97) {
        let p = g.camera_payload(c);
        raws.push((packet(0x03, 0x0F03, counters[2], &p), vec![]));
        counters[2] += 1;
    }
    let frames = 1 + g.rng.below(6);
    for id in 0..frames as u32 {
        if g.p(0.05) {
            let nc = g.rng.below(cams.len());
            c = &cams[nc];
            let p = g.camera_payload(c);
            raws.push((packet(0x03, 0x0F03, counters[2], &p), vec![]));
            counters[2] += 1;
        }
        if id > 0 && g.p(0.8) {
            let p = g.motion_payload(id - 1, id);
            let mut r = packet(0x02, 0x0F02, counters[1], &p);
            if g.p(mutate_rate * 0.3) {
                let at = 10 + g.rng.below(52);
                r[at] ^= 1 << g.rng.below(8);
                if g.p(0.3) {
                    r[8] = r[8].wrapping_add(1);
                }
                fix_crc(&mut r);
            }
            raws.push((r, vec![]));
            counters[1] += 1;
        }
        let mutate = g.p(mutate_rate);
        let f = frame_packet(g, c, id, counters[0], mutate);
        if !(g.p(0.05)) {
            counters[0] = counters[0].wrapping_add(1);
        }
        raws.push((f.raw, f.hot));
    }
    if g.p(0.5) {
        raws.push((packet(0x7F, 0x0F7F, counters[3], &[]), vec![]));
    }
    let raw_list: Vec<Vec<u8>> = raws.iter().map(|(r, _)| r.clone()).collect();
    for (raw, h) in raws {
        let (_, long) = run_starts(&raw);
        let start = stream.len();
        let mut l = link(&raw);
        for &o in &h {
            let lp = link_pos(&long, o);
            for j in 0..5 {
                hot.push(start + lp + j);
            }
        }
        // The end of the packet: the last point before the CRC.
        let end = start + l.len();
        for j in 1..10 {
            hot.push(end.saturating_sub(j));
        }
        if g.p(link_rate) {
            let k = g.rng.below(7);
            let at = g.rng.below(l.len());
            match k {
                0 => l[at] ^= 1 << g.rng.below(8),
                1 => {
                    l.truncate(at);
                    l.push(0)
                }
                2 => l.insert(at, 0),
                3 => {
                    let b = l[at];
                    l.insert(at, b)
                }
                4 => {
                    l.remove(at);
                }
                5 => {
                    let gb: Vec<u8> = (0..g.rng.below(20))
                        .map(|_| g.rng.below(256) as u8)
                        .collect();
                    stream.extend(gb)
                }
                _ => {
                    // Duplicate the whole packet.
                    stream.extend(l.clone())
                }
            }
        }
        stream.extend(l);
    }
    hot.retain(|&h| h > 0 && h < stream.len());
    hot.sort();
    hot.dedup();
    Case {
        raws: raw_list,
        stream,
        hot,
    }
}

fn chunks(g: &mut Gen, c: &Case) -> Vec<usize> {
    match g.rng.below(8) {
        0 => vec![1],
        1 => vec![g.pick(&[2, 3, 4, 5, 6, 7, 63, 64, 65, 253, 254, 255, 256, 257])],
        2 => vec![c.stream.len()],
        3 | 4 if !c.hot.is_empty() => {
            // Split at a random subset of the hot offsets.
            let mut cuts: Vec<usize> = c.hot.iter().copied().filter(|_| g.p(0.3)).collect();
            cuts.push(c.stream.len());
            let mut prev = 0;
            let mut v = Vec::new();
            for x in cuts {
                if x > prev {
                    v.push(x - prev);
                    prev = x;
                }
            }
            v
        }
        _ => (0..64).map(|_| 1 + g.rng.below(300)).collect(),
    }
}

fn check<const N: usize, const B: usize>(stream: &[u8], ch: &[usize]) -> bool {
    compare::<N, B>(stream, ch).is_ok()
}

/// Shrink a failing (stream, chunks): drop byte ranges, then simplify chunks.
fn shrink<const N: usize, const B: usize>(
    mut s: Vec<u8>,
    mut ch: Vec<usize>,
) -> (Vec<u8>, Vec<usize>) {
    // Chunks as explicit list covering the stream.
    let mut explicit = Vec::new();
    let mut at = 0;
    let mut i = 0;
    while at < s.len() {
        let t = ch[i % ch.len()].clamp(1, s.len() - at);
        explicit.push(t);
        at += t;
        i += 1;
    }
    ch = explicit;
    // Try whole-stream single chunk and all-ones first.
    for alt in [vec![s.len()], vec![1]] {
        if !check::<N, B>(&s, &alt) {
            ch = alt;
            break;
        }
    }
    let ones = ch == vec![1] || ch == vec![s.len()];
    let mut step = s.len() / 2;
    while step >= 1 {
        let mut i = 0;
        while i + step <= s.len() {
            let mut t = s.clone();
            t.drain(i..i + step);
            let tch = if ones {
                if ch.len() == 1 && ch[0] > 1 {
                    vec![t.len()]
                } else {
                    ch.clone()
                }
            } else {
                // Remove `step` bytes from the chunk list at position i.
                let mut v = Vec::new();
                let mut pos = 0;
                for &c in &ch {
                    let (a, b) = (pos, pos + c);
                    let keep = c - (b.min(i + step).saturating_sub(a.max(i)));
                    if keep > 0 {
                        v.push(keep);
                    }
                    pos = b;
                }
                v
            };
            if !t.is_empty() && !tch.is_empty() && !check::<N, B>(&t, &tch) {
                s = t;
                ch = tch;
            } else {
                i += step;
            }
        }
        step /= 2;
    }
    (s, ch)
}

fn hex(b: &[u8]) -> String {
    b.iter()
        .map(|x| format!("{x:02x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

fn run<const N: usize, const B: usize>(seed: u64, seconds: u64) -> (u64, u64, u64, Vec<String>) {
    let mut g = Gen {
        rng: Rng(seed),
        n_cap: N,
        b_cap: B,
    };
    let deadline = Instant::now() + Duration::from_secs(seconds);
    let (mut cases, mut outputs, mut bytes) = (0u64, 0u64, 0u64);
    let mut fails = Vec::new();
    while Instant::now() < deadline {
        let c = case(&mut g);
        for _ in 0..3 {
            let ch = chunks(&mut g, &c);
            bytes += c.stream.len() as u64;
            match compare::<N, B>(&c.stream, &ch) {
                Ok(n) => {
                    outputs += n as u64;
                    if std::env::var("WIRE_DIFF_STATS").is_ok() {
                        for o in Reference::<N, B>::new(DataIds::DEFAULT).run(&c.stream) {
                            let k = match o.out {
                                Out::Err(WireError::Boundary { error, .. }) => {
                                    format!(
                                        "boundary:{}",
                                        format!("{error:?}")
                                            .split(|c: char| !c.is_alphanumeric())
                                            .next()
                                            .unwrap()
                                    )
                                }
                                Out::Err(e) => format!("{:?}", e.kind()),
                                Out::Frame { .. } => "frame".into(),
                                Out::Motion(_) => "motion".into(),
                                Out::Camera(_) => "camera".into(),
                                Out::End => "end".into(),
                            };
                            *STATS.lock().unwrap().entry(k).or_insert(0) += 1;
                        }
                    }
                }
                Err((i, r, d)) => {
                    let (s, sch) = shrink::<N, B>(c.stream.clone(), ch.clone());
                    let e = compare::<N, B>(&s, &sch).err();
                    let msg = format!(
                        "N={N} B={B} seed {seed} case {cases}: output {i}: reference {r:?}, decoder {d:?}\n  shrunk: stream [{}] chunks {:?}\n  shrunk gives {:?}",
                        hex(&s),
                        sch,
                        e
                    );
                    eprintln!("{msg}");
                    fails.push(msg);
                    if fails.len() > 20 {
                        return (cases, outputs, bytes, fails);
                    }
                }
            }
        }
        cases += 1;
    }
    (cases, outputs, bytes, fails)
}

/// Seeds for the libFuzzer target `wire_diff` (fuzz/fuzz_targets/wire_diff.rs):
/// `WIRE_DIFF_DUMP=dir`.
#[test]
fn dump_seeds() {
    let Ok(dir) = std::env::var("WIRE_DIFF_DUMP") else {
        return;
    };
    std::fs::create_dir_all(&dir).unwrap();
    for (v, n_cap, b_cap) in [(0u8, 256usize, 2usize), (1, 8, 3)] {
        let mut g = Gen {
            rng: Rng(77 + u64::from(v)),
            n_cap,
            b_cap,
        };
        for i in 0..300 {
            let c = case(&mut g);
            let mut d = vec![v, g.rng.below(256) as u8];
            for r in &c.raws {
                if r.len() > 3000 {
                    continue;
                }
                d.push(if g.p(0.1) { 2 } else { 0 });
                d.extend_from_slice(&(r.len() as u16).to_le_bytes());
                d.extend_from_slice(r);
            }
            std::fs::write(format!("{dir}/seed_{v}_{i}"), d).unwrap();
        }
    }
}

#[test]
fn decoder_agrees_with_the_reference() {
    let seconds: u64 = std::env::var("WIRE_DIFF_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10);
    let seed: u64 = std::env::var("WIRE_DIFF_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let third = (seconds / 3).max(1);
    let mut all = Vec::new();
    let (c1, o1, b1, f1) = run::<256, 2>(seed, third);
    println!(
        "N=256 B=2: {c1} cases, {o1} outputs, {b1} bytes fed, {} disagreements",
        f1.len()
    );
    all.extend(f1);
    let (c2, o2, b2, f2) = run::<8, 3>(seed ^ 0xABCD, third);
    println!(
        "N=8 B=3: {c2} cases, {o2} outputs, {b2} bytes fed, {} disagreements",
        f2.len()
    );
    all.extend(f2);
    let (c3, o3, b3, f3) = run::<512, 1>(seed ^ 0x1234, third);
    println!(
        "N=512 B=1: {c3} cases, {o3} outputs, {b3} bytes fed, {} disagreements",
        f3.len()
    );
    all.extend(f3);
    for (k, v) in STATS.lock().unwrap().iter() {
        println!("  {k}: {v}");
    }
    assert!(
        all.is_empty(),
        "{} disagreements:\n{}",
        all.len(),
        all.join("\n")
    );
}

/// A systematic sweep: one boundary whose points cross a 254-byte COBS
/// run edge at every alignment (the boundary head's zero bytes move the
/// run's start), every mutation at the first points, the last ones and
/// those around the run edge, each fed whole, byte by byte, and split at
/// every byte of the mutated point.
#[test]
fn systematic_sweep_around_run_edges() {
    const N: usize = 512;
    let cam_p = {
        let mut p = Vec::new();
        for x in [800.0f32, 790.0, 512.0, 480.0] {
            p.extend_from_slice(&x.to_le_bytes());
        }
        p.extend_from_slice(&1024u16.to_le_bytes());
        p.extend_from_slice(&960u16.to_le_bytes());
        p
    };
    let cam = link(&packet(0x03, 0x0F03, 0, &cam_p));
    let (mut cases, mut fails) = (0u64, Vec::new());
    let lu = 16 * 1025;
    let lv = 16 * 961;
    for &n in &[70usize, 130, 255, 256, 300] {
        for &quality in &[0u8, 7] {
            for &radius in &[0u16, 1, 256, 257] {
                for &down in &[false, true] {
                    let pts: Vec<(u16, u16)> = (0..n)
                        .map(|k| {
                            let v = if down {
                                0x0111 + 16 * (n - 1 - k)
                            } else {
                                0x0111 + 16 * k
                            };
                            ((0x0111 + 8 * (k % 50)) as u16, v as u16)
                        })
                        .collect();
                    let mut p = Vec::new();
                    p.extend_from_slice(&5u64.to_le_bytes());
                    p.extend_from_slice(&9u32.to_le_bytes());
                    p.extend_from_slice(&1024u16.to_le_bytes());
                    p.extend_from_slice(&960u16.to_le_bytes());
                    p.extend_from_slice(&[1, 0, 0, quality]);
                    p.extend_from_slice(&radius.to_le_bytes());
                    p.extend_from_slice(&(n as u16).to_le_bytes());
                    for &(u, v) in &pts {
                        p.extend_from_slice(&u.to_le_bytes());
                        p.extend_from_slice(&v.to_le_bytes());
                    }
                    let good = packet(0x01, 0x0F01, 0, &p);
                    let (starts, _) = run_starts(&good);
                    let p0 = 34;
                    let edge: Vec<usize> = (0..n)
                        .filter(|&i| {
                            starts
                                .iter()
                                .any(|&s| s + 4 > p0 + 4 * i && s < p0 + 4 * i + 8)
                        })
                        .collect();
                    let mut idx: Vec<usize> = vec![0, 1, 2, n - 3, n - 2, n - 1];
                    idx.extend(edge);
                    idx.sort();
                    idx.dedup();
                    for &i in &idx {
                        let o = p0 + 4 * i;
                        let (u, v) = (u32::from(pts[i].0), u32::from(pts[i].1));
                        let prev = if i > 0 { Some(pts[i - 1]) } else { None };
                        let mut muts: Vec<(u32, u32)> = vec![
                            (BASE + lu + 1, v),
                            (BASE + lu, v),
                            (0x100, v),
                            (0xFF, v),
                            (0, v),
                            (0xFFFF, v),
                            (u, BASE + lv + 1),
                            (u, BASE + lv),
                            (u, 0x100),
                            (u, 0),
                            (u & !0xFF | 0x200, v), // zero low byte of u, valid
                            (u, v & !0xFF),         // zero low byte of v
                            (u & 0xFF, v),          // zero high byte of u
                            (u, v & 0xFF),          // zero high byte of v
                            (u, v),                 // unchanged
                        ];
                        if let Some((pu, pv)) = prev {
                            let (pu, pv) = (u32::from(pu), u32::from(pv));
                            muts.push((pu, pv)); // duplicate
                            muts.push((u, pv)); // same row
                            muts.push((u, (2 * pv).wrapping_sub(v) & 0xFFFF)); // turn back
                            muts.push((pu, v));
                        }
                        for (mu, mv) in muts {
                            for fix in [true, false] {
                                let mut raw = good.clone();
                                raw[o..o + 2].copy_from_slice(&(mu as u16).to_le_bytes());
                                raw[o + 2..o + 4].copy_from_slice(&(mv as u16).to_le_bytes());
                                if fix {
                                    fix_crc(&mut raw);
                                }
                                let mut stream = vec![0u8];
                                stream.extend(&cam);
                                let start = stream.len();
                                let l = link(&raw);
                                stream.extend(&l);
                                // A second good frame after it.
                                stream.extend(link(&packet(0x01, 0x0F01, 1, &p)));
                                let (_, long) = run_starts(&raw);
                                let lp = start + link_pos(&long, o);
                                let mut chs: Vec<Vec<usize>> =
                                    vec![vec![stream.len()], vec![1], vec![3], vec![64]];
                                for d in 0..7 {
                                    let cut = lp + d - 1;
                                    chs.push(vec![cut, stream.len() - cut]);
                                }
                                // Two cuts inside the point.
                                chs.push(vec![lp + 1, 2, stream.len()]);
                                for ch in chs {
                                    cases += 1;
                                    if let Err(e) = compare::<N, 2>(&stream, &ch) {
                                        let msg = format!(
                                            "n {n} q {quality} r {radius} down {down} point {i} -> ({mu:#x}, {mv:#x}) crc fixed {fix} chunks {ch:?}: {e:?}\n  stream [{}]",
                                            hex(&stream)
                                        );
                                        eprintln!("{msg}");
                                        fails.push(msg);
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    println!("sweep: {cases} cases, {} disagreements", fails.len());
    assert!(fails.is_empty(), "{}", fails.len());
}
