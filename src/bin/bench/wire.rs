//! The link's decoder on the emulated controller (issue 12).

use core::hint::black_box;

use roadstereo::Frame;

use super::{fw, BENCH};

/// The link's decoder on the emulated controller (issue 12): the first
/// frame of the N = 256 bench pair as a frame packet, decoded whole and
/// in the UART driver's 64-byte chunks (COBS, CRC, parsing, the points
/// written into the frame and validated), and the CRC alone over the
/// packet with no table, one table (the library's choice) and 16 tables.
pub fn wire_cost() {
    use crc::{Crc, NoTable, Table, CRC_32_AUTOSAR};
    use roadstereo::wire::encode::{self, BoundaryHead, FrameHead};
    use roadstereo::wire::{cobs_max, frame_packet_max, DataIds, Decoder, Packet};

    static CRC0: Crc<u32, NoTable> = Crc::<u32, NoTable>::new(&CRC_32_AUTOSAR);
    static CRC1: Crc<u32, Table<1>> = Crc::<u32, Table<1>>::new(&CRC_32_AUTOSAR);
    static CRC16: Crc<u32, Table<16>> = Crc::<u32, Table<16>>::new(&CRC_32_AUTOSAR);
    const RAW: usize = frame_packet_max(256, 2);

    let Some((_, data)) = BENCH.iter().find(|(n, _)| *n == 256) else {
        return;
    };
    let Ok(mut drive) = fw::Drive::new(data) else {
        return;
    };
    let cam = drive.camera;
    let mut frame = Frame::<256, 2>::new(cam);
    if drive.next_frame(&mut frame).is_err() {
        return;
    }
    let ids = DataIds::DEFAULT;
    let mut raw = [0u8; RAW];
    let mut link = [0u8; cobs_max(RAW)];
    let mut cam_link = [0u8; 64];
    let Ok(n) = encode::camera(&mut raw, ids.camera, 0, &cam) else {
        return;
    };
    let Ok(cam_n) = encode::cobs_frame(raw.get(..n).unwrap_or(&[]), &mut cam_link) else {
        return;
    };
    let mut p = match encode::FramePacket::begin(
        &mut raw,
        ids.frame,
        0,
        &FrameHead {
            timestamp_us: 0,
            frame_id: 1,
            width: cam.width(),
            height: cam.height(),
        },
    ) {
        Ok(p) => p,
        Err(_) => return,
    };
    let head = BoundaryHead {
        quality: 255,
        radius_px: 0.5,
    };
    for b in frame.boundaries() {
        if p.boundary(&head, b.points()).is_err() {
            return;
        }
    }
    let Ok(raw_n) = p.finish() else { return };
    let packet = raw.get(..raw_n).unwrap_or(&[]);
    let Ok(link_n) = encode::cobs_frame(packet, &mut link) else {
        return;
    };
    let bytes = link.get(..link_n).unwrap_or(&[]);
    let points: usize = frame.boundaries().iter().map(|b| b.points().len()).sum();
    // A fresh decoder each time (the same counters again would be repeats).
    let mut decoder = Decoder::<256, 2>::new(ids);
    let mut decode = |chunk: usize| -> (bool, u32) {
        decoder = Decoder::new(ids);
        let d = &mut decoder;
        let _ = d.feed(cam_link.get(..cam_n).unwrap_or(&[]));
        fw::measure(|| {
            let mut ok = false;
            for piece in black_box(bytes).chunks(chunk) {
                let mut rest = piece;
                while !rest.is_empty() {
                    let (used, out) = d.feed(rest);
                    rest = rest.get(used..).unwrap_or(&[]);
                    if let Some(o) = out {
                        ok = matches!(o.packet, Ok(Packet::Frame(f, _))
                            if f.boundaries().len() == frame.boundaries().len());
                    }
                }
            }
            ok
        })
    };
    let (ok_whole, whole) = decode(bytes.len());
    let (ok_chunked, chunked) = decode(64);
    #[inline(never)]
    fn crc_none(b: &[u8]) -> u32 {
        CRC0.checksum(b)
    }
    #[inline(never)]
    fn crc_table1(b: &[u8]) -> u32 {
        CRC1.checksum(b)
    }
    #[inline(never)]
    fn crc_table16(b: &[u8]) -> u32 {
        CRC16.checksum(b)
    }
    let (_, crc0) = fw::measure(|| black_box(crc_none(black_box(packet))));
    let (_, crc1) = fw::measure(|| black_box(crc_table1(black_box(packet))));
    let (_, crc16) = fw::measure(|| black_box(crc_table16(black_box(packet))));
    defmt::info!(
        "wire points={=u32} packet_bytes={=u32} link_bytes={=u32} decode={=u32} decode_chunked={=u32} ok={=bool} crc_none={=u32} crc_table1={=u32} crc_table16={=u32} decoder_bytes={=u32}",
        points as u32,
        raw_n as u32,
        link_n as u32,
        whole,
        chunked,
        ok_whole && ok_chunked,
        crc0,
        crc1,
        crc16,
        core::mem::size_of::<Decoder<256, 2>>() as u32
    );
}
