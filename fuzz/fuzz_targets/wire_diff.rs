//! libFuzzer target: the link decoder against the reference of
//! `host_tests::wire_ref`. Input: a control byte (bit 0: N = 8, B = 3
//! instead of N = 256, B = 2), a chunk byte, then records `flags, len u16,
//! raw packet`: flags bit 0 sets the length field from the size, bit 1
//! keeps the CRC as given (else it is recomputed), bit 2 inserts a zero
//! byte into the link bytes at (flags >> 3) mod len. A valid 512 x 480
//! camera packet comes first.
#![no_main]

use host_tests::link::Rng;
use host_tests::wire_ref::{compare, fix_crc, link, packet};
use libfuzzer_sys::fuzz_target;

fn camera() -> Vec<u8> {
    let mut p = Vec::new();
    for x in [800.0f32, 790.0, 256.0, 240.0] {
        p.extend_from_slice(&x.to_le_bytes());
    }
    p.extend_from_slice(&512u16.to_le_bytes());
    p.extend_from_slice(&480u16.to_le_bytes());
    packet(0x03, 0x0F03, 0xFFFF, &p)
}

fuzz_target!(|data: &[u8]| {
    if data.len() < 2 {
        return;
    }
    let (ctl, cb) = (data[0], data[1]);
    let mut stream = vec![0u8];
    stream.extend(link(&camera()));
    let mut rest = &data[2..];
    while rest.len() >= 3 {
        let f = rest[0];
        let l = usize::from(u16::from_le_bytes([rest[1], rest[2]]));
        rest = &rest[3..];
        let l = l.min(rest.len());
        let mut raw = rest[..l].to_vec();
        rest = &rest[l..];
        if f & 1 != 0 && raw.len() >= 14 {
            let n = (raw.len() - 14) as u16;
            raw[8..10].copy_from_slice(&n.to_le_bytes());
        }
        if f & 2 == 0 {
            fix_crc(&mut raw);
        }
        let mut lk = link(&raw);
        if f & 4 != 0 {
            let at = usize::from(f >> 3) % lk.len();
            lk.insert(at, 0);
        }
        stream.extend(lk);
    }
    let chunks: Vec<usize> = if cb < 16 {
        vec![usize::from(cb) + 1]
    } else if cb < 24 {
        vec![[63, 64, 65, 253, 254, 255, 256, 100_000][usize::from(cb - 16)]]
    } else {
        let mut r = Rng(u64::from(cb));
        (0..64).map(|_| 1 + r.below(300)).collect()
    };
    let res = if ctl & 1 == 0 {
        compare::<256, 2>(&stream, &chunks)
    } else {
        compare::<8, 3>(&stream, &chunks)
    };
    if let Err((i, r, d)) = res {
        panic!("output {i}: reference {r:?}, decoder {d:?}; chunks {chunks:?}");
    }
});
