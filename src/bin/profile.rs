//! Profiling aid: a list of named windows, each one per-frame call on a
//! frame pair from an embedded data file, processed between two marker
//! calls, so a QEMU execution trace of this binary shows where each call's
//! instructions go (`cargo xtask profile`).
//!
//! Window `k` (from 0) is the code between the entries into `marker(2k + 1)`
//! and `marker(2k + 2)`; after it the firmware logs
//! `profile window=k name=… points=… digest=…`, outside the window. With
//! feature `profile-fusion` (`cargo xtask profile --fusion`) one window
//! more: a whole step of the demo drive's fusion ([`fusion`]).

#![no_std]
#![no_main]

mod fw;

use core::hint::black_box;

use cortex_m_rt::entry;
use defmt_semihosting as _;
use roadstereo::{Config, Frame, Processor};
use static_cell::ConstStaticCell;

/// The traced windows, in order: a name (no spaces) and a frame pair in the
/// format of `host_tests/src/drive.rs` (the first two frames are used). To
/// add a window, add one line here, e.g.
/// `("worst", include_bytes!("data/worst_256.bin")),`; `cargo xtask profile`
/// reports every window the firmware logs.
static WINDOWS: &[(&str, &[u8])] = &[
    // The bench's representative N = 256 pair (one detector point per row).
    ("representative", include_bytes!("data/bench_256.bin")),
    // The bench's N = 256 stress pair (up to 3.4 points per row).
    ("stress", include_bytes!("data/stress_256.bin")),
    // The demo drive's frames 14 and 15 as one consecutive pair (the
    // costliest such pair when the demo matched consecutive frames; the
    // fusion demo pairs frame 15 with key frame 12).
    ("demo_15", include_bytes!("data/demo_15.bin")),
    // The fusion demo's two costliest pairs, frames 8 and 9 and frames 12
    // and 13 (each the first partner of a new key frame, so a consecutive
    // pair: the demo's matching of those frames, its digests the demo's;
    // `cargo run --release --example pair_of -- ../src/bin/data/drive.bin
    // 9 ../src/bin/data/demo_9.bin` in host_tests writes them).
    ("demo_9", include_bytes!("data/demo_9.bin")),
    ("demo_13", include_bytes!("data/demo_13.bin")),
    // Spurious frame-2 detector points (N = 256): the wedge path's lean walk
    // with the index's aside entries merged in.
    ("spur_f2", include_bytes!("data/adv_spur_f2_256.bin")),
    // The adversarial family's costliest member at 2 × 256 (a frame-1
    // boundary across the FOE's row): the general band path.
    ("foe_row", include_bytes!("data/adv_foe_row_256.bin")),
    // Backward motion on log spirals about an FOE just above the image
    // (N = 256), the family's costliest hand-made member at 2 × 256 (the
    // seeded search's backward spirals cost up to 9 % more): the band
    // path's general visit, with the aside and FOE-near lists merged in
    // and the work budget binding.
    (
        "back_spiral",
        include_bytes!("data/adv_back_spiral_256.bin"),
    ),
    // The same member at 2 × 512, where its points' runs mostly merge the
    // aside list in (`Index::visit_run_aside`), not the general visit.
    (
        "back_spiral_512",
        include_bytes!("data/adv_back_spiral_512.bin"),
    ),
];

/// Capacity: the bench's, so the per-frame code is the bench's too.
const CAP: usize = 512;

/// The processor, in a static as a firmware keeps it (its constructor is
/// `const`).
static PROCESSOR: ConstStaticCell<Processor<CAP, 2>> =
    ConstStaticCell::new(Processor::new(Config::DEFAULT));

#[inline(never)]
fn marker(tag: u32) -> u32 {
    black_box(tag)
}

#[entry]
fn main() -> ! {
    let processor: &'static mut Processor<CAP, 2> = PROCESSOR.take();
    let mut ok = true;
    for (k, (name, data)) in WINDOWS.iter().enumerate() {
        ok &= window(processor, k, name, data);
    }
    ok &= wire_window(WINDOWS.len());
    // (Only with `profile-fusion`: a second monomorphisation moves the
    // other windows' code, `cargo xtask profile --help`.)
    #[cfg(feature = "profile-fusion")]
    {
        ok &= fusion::window(WINDOWS.len() + 1);
    }
    fw::exit(ok)
}

/// Window `k`: the processor, reset, takes the pair's first frame, then its
/// second between `marker(2k + 1)` and `marker(2k + 2)`; log the result.
/// Whether the data was read and the call succeeded.
fn window(processor: &mut Processor<CAP, 2>, k: usize, name: &str, data: &'static [u8]) -> bool {
    processor.reset();
    let Ok(mut d) = fw::Drive::new(data) else {
        return false;
    };
    let mut f1 = Frame::<CAP, 2>::new(d.camera);
    let mut f2 = Frame::<CAP, 2>::new(d.camera);
    let (Ok(_), Ok(Some(m))) = (d.next_frame(&mut f1), d.next_frame(&mut f2)) else {
        return false;
    };
    let _ = processor.process(&f1, None);
    let tag = 2 * k as u32 + 1;
    marker(tag);
    let ok = processor.process(black_box(&f2), Some(&m)).is_ok();
    marker(tag + 1);
    let points: usize = f2.boundaries().iter().map(|b| b.points().len()).sum();
    defmt::info!(
        "profile window={=usize} name={=str} points={=usize} digest={=u32:08x} ok={=bool}",
        k,
        name,
        points,
        processor.structure().digest(),
        ok
    );
    ok
}

/// The link's decoder on the representative pair's first frame (a
/// 2 × 256 frame packet): COBS, CRC, parsing, the points validated and
/// written into the decoder's frame (`roadstereo::wire`).
fn wire_window(k: usize) -> bool {
    use roadstereo::wire::{cobs_max, frame_packet_max, DataIds, Decoder, Packet};
    const RAW: usize = frame_packet_max(256, 2);
    let mut raw = [0u8; RAW];
    let mut cam = [0u8; 64];
    let mut link = [0u8; cobs_max(RAW)];
    let Some((cam_n, link_n, points)) =
        fw::wire_sample::<256, 2>(WINDOWS[0].1, &mut raw, &mut cam, &mut link)
    else {
        return false;
    };
    let mut d = Decoder::<256, 2>::new(DataIds::DEFAULT);
    let _ = d.feed(cam.get(..cam_n).unwrap_or(&[]));
    let bytes = link.get(..link_n).unwrap_or(&[]);
    let tag = 2 * k as u32 + 1;
    marker(tag);
    let (used, out) = d.feed(black_box(bytes));
    let ok = used == bytes.len() && matches!(out.map(|o| o.packet), Some(Ok(Packet::Frame(..))));
    marker(tag + 1);
    defmt::info!(
        "profile window={=usize} name={=str} points={=usize} digest={=u32:08x} ok={=bool}",
        k,
        "wire decode",
        points,
        0u32,
        ok
    );
    ok
}

/// The window over a step of the demo's fusion (feature `profile-fusion`,
/// `cargo xtask profile --fusion`).
#[cfg(feature = "profile-fusion")]
mod fusion {
    use super::{black_box, fw, marker, ConstStaticCell};
    use roadstereo::fusion::Fusion;
    use roadstereo::{Config, Frame};

    /// The demo drive (the bench's fusion demo).
    static DRIVE: &[u8] = include_bytes!("data/drive.bin");
    /// The step of the demo's fusion traced: frame 13, the bench's costliest
    /// step with the fusion (the first partner of key frame 12).
    const FUSION_FRAME: u32 = 13;
    static FUSION: ConstStaticCell<Fusion<256, 2, 512>> =
        ConstStaticCell::new(Fusion::new(Config::DEFAULT, fw::DEMO_POLICY));

    /// The bench's fusion over the demo drive (`Fusion<256, 2, 512>`), frames
    /// before [`FUSION_FRAME`] outside the window, that frame's whole step
    /// (the matching, the fusion and the map) inside it; the digest is the
    /// fusion's.
    pub fn window(k: usize) -> bool {
        let fusion: &'static mut Fusion<256, 2, 512> = FUSION.take();
        let Ok(mut drive) = fw::Drive::new(DRIVE) else {
            return false;
        };
        let mut frame = Frame::<256, 2>::new(drive.camera);
        let mut ok = true;
        for i in 0..=FUSION_FRAME.min(drive.frames.saturating_sub(1)) {
            let Ok(motion) = drive.next_frame(&mut frame) else {
                return false;
            };
            let chained = fw::chained(i, motion);
            if i == FUSION_FRAME {
                let tag = 2 * k as u32 + 1;
                marker(tag);
                ok = fusion
                    .step(black_box(i), black_box(&frame), chained.as_ref())
                    .is_ok();
                marker(tag + 1);
            } else if fusion.step(i, &frame, chained.as_ref()).is_err() {
                return false;
            }
        }
        let points = fw::point_count(fusion.structure());
        defmt::info!(
            "profile window={=usize} name={=str} points={=usize} digest={=u32:08x} ok={=bool}",
            k,
            "fusion_13",
            points,
            fusion.digest(),
            ok
        );
        ok
    }
}
