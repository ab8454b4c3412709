//! Profiling aid: the N = 256 benchmark frame pair processed once, so a
//! QEMU execution trace of this binary shows where one per-frame call's
//! instructions go (`cargo xtask profile`).

#![no_std]
#![no_main]

mod fw;

use core::hint::black_box;

use cortex_m_rt::entry;
use defmt_semihosting as _;
use roadstereo::{Config, Frame, Processor};

static DATA: &[u8] = include_bytes!("data/bench_256.bin");

#[inline(never)]
fn marker(tag: u32) -> u32 {
    black_box(tag)
}

#[entry]
fn main() -> ! {
    let mut processor = Processor::<512, 2>::new(Config::default());
    let Ok(mut d) = fw::Drive::new(DATA) else {
        fw::exit(false)
    };
    let mut f1 = Frame::<512, 2>::new(d.camera);
    let mut f2 = Frame::<512, 2>::new(d.camera);
    let (Ok(_), Ok(Some(m))) = (d.next_frame(&mut f1), d.next_frame(&mut f2)) else {
        fw::exit(false)
    };
    let _ = processor.process(&f1, None);
    marker(1);
    let ok = processor.process(black_box(&f2), Some(&m)).is_ok();
    marker(2);
    let points: usize = f2.boundaries().iter().map(|b| b.points().len()).sum();
    defmt::info!(
        "profile points={=usize} digest={=u32:08x}",
        points,
        processor.structure().digest()
    );
    fw::exit(ok)
}
