//! Benchmark on the emulated vehicle controller: instructions for the whole
//! per-frame call at N = 32 … 512 points per boundary (two boundaries; the
//! Fig. 6 set-up on a curve of radius 15, one detector point per image row:
//! the camera's resolution grows with N), and on the stress pairs (the
//! paper's 512 × 480 camera sampled at up to 3.4 points per row, N = 256
//! and 512); the worst-case stack of one
//! per-frame call (stack painting), and the library's state and output
//! sizes on the target; then every member of the adversarial family
//! (issue 11: `host_tests/src/drive/adversarial.rs`, the table
//! `data/adversarial.rs` it generates) at every N, measured like the
//! representative rows, with the count of every status by name.
//! Then the key-frame fusion over the demo drive (24 frames, two boundaries
//! of up to 256 points): per frame the instructions of the whole fusion
//! step and of the processor call inside it (the same call replayed on a
//! copy of the processor), whose difference is the fusion and the road
//! map's own cost; the same over a sideways drive whose road map fills
//! (every retiring key frame then drops the oldest points for room).
//! `cargo xtask bench` runs it, prints the tables and checks the budgets.

#![no_std]
#![no_main]

#[path = "../fw/mod.rs"]
mod fw;

mod deadline;
mod fusion;
mod pairs;
mod stack;
mod wire;
mod worst;

use core::hint::black_box;

use cortex_m_rt::entry;
use defmt_semihosting as _;
use roadstereo::fusion::Fusion;
use roadstereo::{Config, Frame, Processor, Status, Structure};
use static_cell::ConstStaticCell;

use deadline::deadline_sweep;
use fusion::fusion_bench;
use pairs::member_config;
use wire::wire_cost;
use worst::worst_case_sweep;

static BENCH: [(u32, &[u8]); 5] = [
    (32, include_bytes!("../data/bench_32.bin")),
    (64, include_bytes!("../data/bench_64.bin")),
    (128, include_bytes!("../data/bench_128.bin")),
    (256, include_bytes!("../data/bench_256.bin")),
    (512, include_bytes!("../data/bench_512.bin")),
];

/// Oversampled pairs, reported beside the budget table (not budgeted).
static STRESS: [(u32, &[u8]); 2] = [
    (256, include_bytes!("../data/stress_256.bin")),
    (512, include_bytes!("../data/stress_512.bin")),
];

// The adversarial family: `static ADVERSARIAL: &[(&str, u32, u8, &[u8])]` (name, N, error model, data), one
// (member, N, RSD1 frame pair) per line, written by the generator
// (`cd host_tests && cargo run --release --bin adversarial`).
include!("../data/adversarial.rs");

/// The capacity of the bench's frames, points a boundary.
const CAP: usize = 512;

/// The processor of the bench pairs, in a static (its constructor is
/// `const`), as a firmware keeps it.
static PROCESSOR: ConstStaticCell<Processor<CAP, 2>> =
    ConstStaticCell::new(Processor::new(Config::DEFAULT));

/// The count of every status present (and of `ok` always) as
/// `status.<name>=<count>` fields, by [`Status::name`] over [`Status::ALL`],
/// so a status added to the library is logged without a change here.
fn status_fields(s: &Structure<CAP, 2>) -> heapless::String<400> {
    let mut out = heapless::String::new();
    let counts = s.status_counts();
    for (st, c) in counts.iter() {
        if c == 0 && st != Status::Ok {
            continue;
        }
        // Decimal digits of c, most significant first.
        let mut digits = [0u8; 20];
        let mut k = digits.len();
        let mut x = c;
        loop {
            k -= 1;
            digits[k] = b'0' + (x % 10) as u8;
            x /= 10;
            if x == 0 {
                break;
            }
        }
        let parts = [
            "status.",
            st.name(),
            "=",
            core::str::from_utf8(&digits[k..]).unwrap_or("?"),
            " ",
        ];
        for p in parts {
            // A full line drops the rest (400 bytes hold every status).
            let _ = out.push_str(p);
        }
    }
    out
}

fn load(
    data: &'static [u8],
    f1: &mut Frame<CAP, 2>,
    f2: &mut Frame<CAP, 2>,
) -> Option<roadstereo::Motion> {
    let mut d = fw::Drive::new(data).ok()?;
    *f1 = Frame::new(d.camera);
    *f2 = Frame::new(d.camera);
    d.next_frame(f1).ok()?;
    d.next_frame(f2).ok()?
}

/// One measured frame pair: the processor reset, frame 1 given, then the
/// instructions of the per-frame call for frame 2.
struct Measured {
    processed: bool,
    instr: u32,
    points: u32,
    ok: u32,
}

impl Measured {
    /// The call's outcome and instructions with the processor's output
    /// counted.
    fn of(processor: &Processor<CAP, 2>, (processed, instr): (bool, u32)) -> Self {
        let points = fw::point_count(processor.structure());
        let ok = processor.structure().status_counts().get(Status::Ok);
        Measured {
            processed,
            instr,
            points: points as u32,
            ok: ok as u32,
        }
    }
}

fn measure_pair(
    processor: &mut Processor<CAP, 2>,
    f1: &Frame<CAP, 2>,
    f2: &Frame<CAP, 2>,
    m: &roadstereo::Motion,
) -> Measured {
    processor.reset();
    let _ = processor.process(f1, None);
    let (processed, instr) = fw::measure(|| processor.process(black_box(f2), Some(m)).is_ok());
    Measured::of(processor, (processed, instr))
}

#[entry]
fn main() -> ! {
    let Some(mut core) = cortex_m::Peripherals::take() else {
        fw::exit(false)
    };
    fw::start_counter(&mut core.SYST);
    let processor: &'static mut Processor<CAP, 2> = PROCESSOR.take();
    let cam = match roadstereo::Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480) {
        Ok(c) => c,
        Err(_) => fw::exit(false),
    };
    let mut f1 = Frame::<CAP, 2>::new(cam);
    let mut f2 = Frame::<CAP, 2>::new(cam);
    for (n, data) in BENCH.iter() {
        let Some(m) = load(data, &mut f1, &mut f2) else {
            defmt::error!("bad bench data for n={=u32}", n);
            fw::exit(false)
        };
        let r = measure_pair(processor, &f1, &f2, &m);
        defmt::info!(
            "bench n={=u32} points={=u32} instr={=u32} per_point={=u32} ok={=u32} digest={=u32:08x} processed={=bool} work_spent={=u32} work_granted={=u32}",
            n,
            r.points,
            r.instr,
            r.instr / r.points.max(1),
            r.ok,
            processor.structure().digest(),
            r.processed,
            processor.structure().work_units().0,
            processor.structure().work_units().1
        );
        if *n == 256 {
            processor.reset();
            let _ = processor.process(&f1, None);
            let bytes = stack::high_water(|| {
                let _ = black_box(processor.process(black_box(&f2), Some(&m)));
            });
            defmt::info!("stack per_frame_call={=u32} pair=representative", bytes);
        }
    }
    for (n, data) in STRESS.iter() {
        let Some(m) = load(data, &mut f1, &mut f2) else {
            defmt::error!("bad stress data for n={=u32}", n);
            fw::exit(false)
        };
        let r = measure_pair(processor, &f1, &f2, &m);
        defmt::info!(
            "stress n={=u32} points={=u32} instr={=u32} per_point={=u32} ok={=u32} processed={=bool}",
            n,
            r.points,
            r.instr,
            r.instr / r.points.max(1),
            r.ok,
            r.processed
        );
    }
    for (name, n, errors, data) in ADVERSARIAL.iter() {
        let Some(m) = load(data, &mut f1, &mut f2) else {
            defmt::error!("bad adversarial data for {=str} n={=u32}", name, n);
            fw::exit(false)
        };
        let Some(c) = member_config(*errors, Config::DEFAULT_WORK_PER_POINT) else {
            defmt::error!("bad error model for {=str}", name);
            fw::exit(false)
        };
        processor.set_config(c);
        let r = measure_pair(processor, &f1, &f2, &m);
        if *n == 256 {
            // The stack on every path the family takes (the band path, the
            // pseudo-angle path, a block tree built inside a walk), not
            // only the representative pair's.
            processor.reset();
            let _ = processor.process(&f1, None);
            let bytes = stack::high_water(|| {
                let _ = black_box(processor.process(black_box(&f2), Some(&m)));
            });
            defmt::info!("stack per_frame_call={=u32} pair={=str}", bytes, name);
        }
        processor.set_config(Config::DEFAULT);
        defmt::info!(
            "adversarial name={=str} n={=u32} points={=u32} instr={=u32} per_point={=u32} digest={=u32:08x} processed={=bool} work_spent={=u32} work_granted={=u32} {=str}",
            name,
            n,
            r.points,
            r.instr,
            r.instr / r.points.max(1),
            processor.structure().digest(),
            r.processed,
            processor.structure().work_units().0,
            processor.structure().work_units().1,
            status_fields(processor.structure()).as_str()
        );
    }
    worst_case_sweep(processor, &mut f1, &mut f2);
    deadline_sweep(processor, &mut f1, &mut f2);
    wire_cost();
    if !fusion_bench() {
        defmt::error!("fusion bench failed");
        fw::exit(false)
    }
    defmt::info!(
        "fusion_memory fusion_256_2_512={=u32} processor_256_2={=u32} key_frame_256_2={=u32} map_2_512={=u32}",
        core::mem::size_of::<Fusion<256, 2, 512>>() as u32,
        core::mem::size_of::<Processor<256, 2>>() as u32,
        core::mem::size_of::<roadstereo::fusion::KeyFrame<256, 2>>() as u32,
        core::mem::size_of::<roadstereo::map::RoadMap<2, 512>>() as u32
    );
    let (p, f, s) = (
        core::mem::size_of::<Processor<256, 2>>() as u32,
        core::mem::size_of::<Frame<256, 2>>() as u32,
        core::mem::size_of::<Structure<256, 2>>() as u32,
    );
    defmt::info!(
        "sizes processor_256_2={=u32} frame_256_2={=u32} structure_256_2={=u32} search_256={=u32}",
        p,
        f,
        s,
        p - f - s
    );
    fw::exit(true)
}
