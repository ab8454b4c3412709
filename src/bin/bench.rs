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
//! map's own cost.
//! `cargo xtask bench` runs it, prints the tables and checks the budgets.

#![no_std]
#![no_main]

mod fw;

use core::hint::black_box;

use cortex_m_rt::entry;
use defmt_semihosting as _;
use roadstereo::fusion::{Fusion, FusionConfig};
use roadstereo::{Config, Frame, Motion, Processor, Status, Structure};
use static_cell::ConstStaticCell;

static BENCH: [(u32, &[u8]); 5] = [
    (32, include_bytes!("data/bench_32.bin")),
    (64, include_bytes!("data/bench_64.bin")),
    (128, include_bytes!("data/bench_128.bin")),
    (256, include_bytes!("data/bench_256.bin")),
    (512, include_bytes!("data/bench_512.bin")),
];

/// Oversampled pairs, reported beside the budget table (not budgeted).
static STRESS: [(u32, &[u8]); 2] = [
    (256, include_bytes!("data/stress_256.bin")),
    (512, include_bytes!("data/stress_512.bin")),
];

// The adversarial family: `static ADVERSARIAL: &[(&str, u32, u8, &[u8])]` (name, N, error model, data), one
// (member, N, RSD1 frame pair) per line, written by the generator
// (`cd host_tests && cargo run --release --bin adversarial`).
include!("data/adversarial.rs");

/// Frame pairs a third adversarial review found by hill climbing on the
/// emulated controller (from `back_spiral`: the motion changed a little,
/// frame points jittered, zig-zagged or spurred; each under the
/// configuration its climb settled on, ids 10–15 of [`member_config`]):
/// over the worst-case envelope of the family and the probes before them
/// by up to 9 % (`rev_c1` at `w = 160`), and `rev_d2` 40 583 instructions
/// late within a deadline. Stored as found (the RSD1 files), not as
/// generator parameters: (name, N, data). Run as [`PROBES`].
static FOUND: &[(&str, u32, &[u8])] = &[
    ("rev_a1", 64, include_bytes!("data/rev_a1.bin")),
    ("rev_b1", 256, include_bytes!("data/rev_b1.bin")),
    ("rev_b2", 64, include_bytes!("data/rev_b2.bin")),
    ("rev_c1", 512, include_bytes!("data/rev_c1.bin")),
    ("rev_c2", 256, include_bytes!("data/rev_c2.bin")),
    ("rev_d2", 512, include_bytes!("data/rev_d2.bin")),
    // A fourth review's (a longer climb, cameras that differ between the
    // frames too): over the envelope above by 7.6 % (`rev_e2`, one camera)
    // and 13.6 % (`rev_e4`, frame 1's camera its own, [`CAMERA1`]) at
    // 2 × 64 and `w = 8`, in the fixed cost of a point.
    ("rev_e2", 64, include_bytes!("data/rev_e2.bin")),
    ("rev_e4", 64, include_bytes!("data/rev_e4.bin")),
    // A fifth review's (climbed from `rev_e4` and `rev_d2`, each frame its
    // own camera): `rev_f1` over the envelope by 0.41 % at `w = 9`, a
    // budget between the sweep's (a unit there cost about 133
    // instructions); `rev_g1` 35 024 instructions late within a deadline
    // (above the 34 570 measured before it, within the 40 000 allowed).
    ("rev_f1", 64, include_bytes!("data/rev_f1.bin")),
    ("rev_g1", 512, include_bytes!("data/rev_g1.bin")),
    // A sixth review's (climbed from `worst_found` with the counting rule
    // for folded points on, no translation error, so that the rule runs):
    // 73 943 late with the rule on while its passes still made each
    // point's ray after the clock's yes; 32 951 at worst since, cut at
    // every fifth question.
    ("rev_h1", 512, include_bytes!("data/rev_h1.bin")),
    // A seventh review's (thirteenth session; climbed from `rev_f1`
    // letting the climb drift sideways, frame 1's camera its own): over
    // the envelope above by 0.43 % at 2 × 64 and `w = 9` (386 898 against
    // 385 247), in the fixed cost of a point.
    ("rev_x3", 64, include_bytes!("data/rev_x3.bin")),
    // An eighth review (after the fifteenth session's aside-list run):
    // `rev8_a` and `rev8_b` (climbed from `back_spiral` at N = 128 with
    // `rev_x3`'s configuration, backward on the band path, frame 1 a
    // camera of its own) over the envelope of their time, by 0.16 % at 2 ×
    // 64 and 5.2 % at 2 × 128, `w` = 9, most units radial-level block
    // skips; `rev8_l` 30 909 late with the counting rule off, `rev8_s`
    // 49 282 with it on (a partners query's stretch at one unit a segment,
    // then the flags after the yes).
    ("rev8_a", 64, include_bytes!("data/rev8_a.bin")),
    ("rev8_b", 128, include_bytes!("data/rev8_b.bin")),
    ("rev8_l", 512, include_bytes!("data/rev8_l.bin")),
    ("rev8_s", 512, include_bytes!("data/rev8_s.bin")),
    // A ninth review's lateness climb from `rev8_s` (frame 2 turned 0.5 rad
    // about `y`: step 1 not certified, so a partners query compensates
    // point by point, dearer a segment): 39 725 late with the counting
    // rule on at `PARTNER_UNITS` = 3 (35 668 at 5).
    ("rev9_s", 512, include_bytes!("data/rev9_s.bin")),
];

/// [`FOUND`] pairs whose frame 1 has a camera of its own (the RSD1 file
/// holds one camera, frame 2's): `(f_x, f_y, c_x, c_y, width, height)`.
#[allow(clippy::type_complexity)]
static CAMERA1: &[(&str, (f32, f32, f32, f32, u16, u16))] = &[
    (
        "rev8_a",
        (798.001_04, 688.121_77, 258.982_36, 256.23584, 512, 480),
    ),
    (
        "rev8_b",
        (799.085_63, 690.7901, 254.676_97, 255.573_88, 512, 480),
    ),
    ("rev9_s", (3_177.910_3, 3_200.0, 1_023.5, 959.5, 2048, 1920)),
    (
        "rev8_l",
        (3_200.034, 3_190.077, 1_022.701_7, 955.088_2, 2048, 1920),
    ),
    (
        "rev_h1",
        (
            2_311.878_2,
            3_153.289_6,
            1_063.460_7,
            1_001.112_73,
            2048,
            1920,
        ),
    ),
    (
        "rev_e4",
        (796.521_55, 688.718_75, 258.442_23, 256.224_8, 512, 480),
    ),
    (
        "rev_f1",
        (794.812, 688.718_75, 258.686_92, 256.224_8, 512, 480),
    ),
    (
        "rev_x3",
        (797.166_7, 688.187_4, 258.933_62, 256.235_84, 512, 480),
    ),
    (
        "rev_g1",
        (
            3_209.982_7,
            3_049.837_2,
            1_060.383_2,
            992.867_06,
            2048,
            1920,
        ),
    ),
];

/// Frame 1 made again with pair `name`'s own frame-1 camera, if it has one
/// ([`CAMERA1`]); false when that camera or a boundary is not accepted.
fn camera1(name: &str, f1: &mut Frame<CAP, 2>) -> bool {
    let Some(&(_, (fx, fy, cx, cy, w, h))) = CAMERA1.iter().find(|c| c.0 == name) else {
        return true;
    };
    let Ok(cam) = roadstereo::Camera::new(fx, fy, cx, cy, w, h) else {
        return false;
    };
    let mut g = Frame::<CAP, 2>::new(cam);
    for b in f1.boundaries() {
        if g.push_boundary(b.points()).is_err() {
            return false;
        }
    }
    *f1 = g;
    true
}

/// The frame pair `name` at `n` points a boundary: a member of the
/// adversarial family, or a [`FOUND`] pair.
fn pair_data(name: &str, n: u32) -> Option<&'static [u8]> {
    ADVERSARIAL
        .iter()
        .find(|a| a.0 == name && a.1 == n)
        .map(|a| a.3)
        .or_else(|| FOUND.iter().find(|f| f.0 == name && f.1 == n).map(|f| f.2))
}

const CAP: usize = 512;

/// The demo drive (`cargo xtask demo`), for the fusion's cost.
static DRIVE: &[u8] = include_bytes!("data/drive.bin");

/// The fusion policy of the demo drive (its camera is tilted 23° down).
const POLICY: FusionConfig = fw::DEMO_POLICY;

/// The processor of the bench pairs and the fusion of the demo drive, in
/// statics (their constructors are `const`), as a firmware keeps them.
static PROCESSOR: ConstStaticCell<Processor<CAP, 2>> =
    ConstStaticCell::new(Processor::new(Config::DEFAULT));
static FUSION: ConstStaticCell<Fusion<256, 2, 512>> =
    ConstStaticCell::new(Fusion::new(Config::DEFAULT, POLICY));

/// The fusion over the demo drive: per frame the whole step, the processor
/// call inside it (replayed on a copy of the processor, with the motion
/// composed the same way, and checked to give the same structure), and
/// the difference: the fusion's and the map's own instructions.
fn fusion_bench() -> bool {
    let Ok(mut drive) = fw::Drive::new(DRIVE) else {
        return false;
    };
    let fusion: &'static mut Fusion<256, 2, 512> = FUSION.take();
    let mut frame = Frame::<256, 2>::new(drive.camera);
    // The motion from the key frame to the previous frame.
    let mut key_motion: Option<Motion> = None;
    for i in 0..drive.frames {
        let Ok(motion) = drive.next_frame(&mut frame) else {
            return false;
        };
        let chained = fw::chained(i, motion);
        let mut copy = fusion.processor().clone();
        // The stack of one step, on a copy (a retiring frame and the next).
        if i == 8 || i == 9 {
            let mut twin = fusion.clone();
            let bytes = stack::high_water(|| {
                let _ = black_box(twin.step(black_box(i), &frame, chained.as_ref()));
            });
            defmt::info!("fusion_stack frame={=u32} bytes={=u32}", i, bytes);
        }
        let (result, step_instr) =
            fw::measure(|| fusion.step(black_box(i), &frame, chained.as_ref()));
        let Ok(step) = result else {
            return false;
        };
        let composed = match (key_motion, motion) {
            (Some(k), Some(m)) => k.then(&m).ok(),
            (None, m) => m,
            _ => None,
        };
        let matching = match (step.new_key.is_some(), step.paired.is_some(), composed) {
            (true, false, _) => {
                copy.reset();
                fw::measure(|| copy.process(&frame, None).is_ok()).1
            }
            // (The pair with its configuration and composition's rounding,
            // as the fusion gave them.)
            (last, true, Some(m)) => {
                fw::measure(|| fusion.replay_pair(&mut copy, &frame, &m, last).is_ok()).1
            }
            _ => 0,
        };
        key_motion = if step.new_key.is_some() {
            None
        } else {
            composed
        };
        let points = fw::point_count(fusion.structure());
        let same =
            step.paired.is_none() || copy.structure().digest() == fusion.structure().digest();
        let own = step_instr.saturating_sub(matching);
        defmt::info!(
            "fusion frame={=u32} points={=u32} step_instr={=u32} matching_instr={=u32} fusion_instr={=u32} per_point={=u32} paired={=bool} retired={=bool} same_structure={=bool} map={=u32} ok={=u32} folded={=u32}",
            i,
            points as u32,
            step_instr,
            matching,
            own,
            own / (points as u32).max(1),
            step.paired.is_some(),
            step.retired.is_some(),
            same,
            (fusion.map().len(0) + fusion.map().len(1)) as u32,
            fusion.structure().status_counts().get(Status::Ok) as u32,
            fusion.structure().status_counts().get(Status::Folded) as u32
        );
    }
    fusion.reset();
    if !fusion_within(fusion) {
        return false;
    }
    fusion.reset();
    fusion.set_fold_counting(true);
    let counted = fusion_counted(fusion);
    fusion.set_fold_counting(false);
    fusion.reset_with(POLICY.with_sight_check(true));
    let sighted = fusion_sighted(fusion);
    fusion.reset_with(POLICY);
    counted && sighted
}

/// The demo drive again through `Fusion::step` with the sight check on
/// (`FusionConfig::with_sight_check`): per frame the step's instructions
/// (the matching is the same as [`fusion_bench`]'s), and the key frame's
/// consistent, widened and partly unseen points after it.
fn fusion_sighted(fusion: &mut Fusion<256, 2, 512>) -> bool {
    let Ok(mut drive) = fw::Drive::new(DRIVE) else {
        return false;
    };
    let mut frame = Frame::<256, 2>::new(drive.camera);
    for i in 0..drive.frames {
        let Ok(motion) = drive.next_frame(&mut frame) else {
            return false;
        };
        let chained = fw::chained(i, motion);
        // The stack of one step with the check on, on a copy (as
        // `fusion_bench`'s: a retiring frame and the next).
        if i == 8 || i == 9 {
            let mut twin = fusion.clone();
            let bytes = stack::high_water(|| {
                let _ = black_box(twin.step(black_box(i), &frame, chained.as_ref()));
            });
            defmt::info!("fusion_sighted_stack frame={=u32} bytes={=u32}", i, bytes);
        }
        let (result, instr) = fw::measure(|| fusion.step(black_box(i), &frame, chained.as_ref()));
        let Ok(step) = result else {
            return false;
        };
        let counts = fusion.key().map(|k| k.counts()).unwrap_or_default();
        defmt::info!(
            "fusion_sighted frame={=u32} step_instr={=u32} paired={=bool} consistent={=u32} widened={=u32} partly_unseen={=u32} map={=u32}",
            i,
            instr,
            step.paired.is_some(),
            counts.consistent,
            counts.widened,
            counts.partly_unseen,
            (fusion.map().len(0) + fusion.map().len(1)) as u32
        );
    }
    true
}

/// The demo drive again through `Fusion::step` with the counting rule for
/// folded points on (`Fusion::set_fold_counting`): per frame the step's
/// instructions and the pair's `ok` and `folded` points (against the
/// rows of [`fusion_bench`], where the rule is off).
fn fusion_counted(fusion: &mut Fusion<256, 2, 512>) -> bool {
    let Ok(mut drive) = fw::Drive::new(DRIVE) else {
        return false;
    };
    let mut frame = Frame::<256, 2>::new(drive.camera);
    for i in 0..drive.frames {
        let Ok(motion) = drive.next_frame(&mut frame) else {
            return false;
        };
        let chained = fw::chained(i, motion);
        let (result, instr) = fw::measure(|| fusion.step(black_box(i), &frame, chained.as_ref()));
        let Ok(step) = result else {
            return false;
        };
        let counts = fusion.structure().status_counts();
        defmt::info!(
            "fusion_counted frame={=u32} step_instr={=u32} paired={=bool} ok={=u32} folded={=u32} over_budget={=u32}",
            i,
            instr,
            step.paired.is_some(),
            counts.get(Status::Ok) as u32,
            counts.get(Status::Folded) as u32,
            counts.get(Status::OverBudget) as u32
        );
    }
    true
}

/// The limit of the demo drive's steps within a deadline, instructions:
/// the deadline (277 200) less the lateness README quotes (40 000, the
/// bench's hard budget for it: 34 570 measured where it is worst, at
/// 2 × 512) and the fusion's own work after the matching, which the
/// deadline does not cut (at most 24 516 on this drive, in a frame where
/// a key frame retires), rounded down.
const DRIVE_LIMIT: u32 = 212_000;

/// The demo drive again through `Fusion::step_within`, SysTick as the
/// clock at [`DRIVE_LIMIT`]: per frame the step's instructions, whether
/// the deadline cut it, and the pair's `ok` and `over_budget` points.
fn fusion_within(fusion: &mut Fusion<256, 2, 512>) -> bool {
    let Ok(mut drive) = fw::Drive::new(DRIVE) else {
        return false;
    };
    let mut frame = Frame::<256, 2>::new(drive.camera);
    let budget = fw::ticks_of(DRIVE_LIMIT);
    for i in 0..drive.frames {
        let Ok(motion) = drive.next_frame(&mut frame) else {
            return false;
        };
        let chained = fw::chained(i, motion);
        let t0 = fw::ticks();
        let mut clock = || fw::ticks().saturating_sub(t0) >= budget;
        let (result, instr) =
            fw::measure(|| fusion.step_within(black_box(i), &frame, chained.as_ref(), &mut clock));
        let Ok(step) = result else {
            return false;
        };
        let counts = fusion.structure().status_counts();
        defmt::info!(
            "fusion_within frame={=u32} limit={=u32} step_instr={=u32} cut={=bool} paired={=bool} ok={=u32} over_budget={=u32}",
            i,
            DRIVE_LIMIT,
            instr,
            fusion.deadline_expired(),
            step.paired.is_some(),
            counts.get(Status::Ok) as u32,
            counts.get(Status::OverBudget) as u32
        );
    }
    true
}

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

/// Stack painting: fill the free stack below the current stack pointer with
/// a pattern, run `f`, and find how deep it wrote. Reading and writing raw
/// stack memory needs `unsafe`; this is measurement code in the benchmark
/// binary only (the library forbids `unsafe`).
mod stack {
    const PATTERN: u32 = 0xDEAD_BEEF;
    extern "C" {
        static mut __sheap: u32;
    }

    #[inline(never)]
    pub fn high_water(f: impl FnOnce()) -> u32 {
        let sp = cortex_m::register::msp::read() as usize;
        let bottom = core::ptr::addr_of_mut!(__sheap) as usize;
        // Leave 256 bytes below the current frame for this function itself.
        let top = (sp - 256) & !3;
        let mut a = bottom;
        while a < top {
            // SAFETY: [bottom, top) is free stack memory below the live stack
            // (cortex-m-rt puts the stack at the top of RAM, growing down to
            // the end of .bss at __sheap); nothing else uses it.
            unsafe { core::ptr::write_volatile(a as *mut u32, PATTERN) };
            a += 4;
        }
        f();
        let mut a = bottom;
        // SAFETY: as above; reading back the painted region.
        while a < top && unsafe { core::ptr::read_volatile(a as *const u32) } == PATTERN {
            a += 4;
        }
        (sp - a) as u32
    }
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

/// Limits of the deadline sweep, instructions from the call's start.
const DEADLINE_LIMITS: [u32; 15] = [
    0, 20_000, 40_000, 60_000, 80_000, 100_000, 120_000, 140_000, 160_000, 180_000, 200_000,
    220_000, 240_000, 260_000, 280_000,
];

/// The per-frame call of frame pair `(f1, f2)` within a deadline of
/// `limit` instructions, by SysTick (what a firmware's cycle counter
/// would be): the measured call, and when the clock first said the time
/// was up (instructions from the call's start).
fn measure_within(
    processor: &mut Processor<CAP, 2>,
    pair: (&Frame<CAP, 2>, &Frame<CAP, 2>, &roadstereo::Motion),
    limit: u32,
) -> (Measured, Option<u32>) {
    let budget = fw::ticks_of(limit);
    let mut first = None;
    let r = call_within(processor, pair, &mut |dt| {
        let up = dt >= budget;
        if up && first.is_none() {
            first = Some(dt);
        }
        up
    });
    (r, first.map(fw::instructions))
}

/// The pair's per-frame call (the processor reset, frame 1 given) within
/// `clock`, which is handed the core-clock ticks since the call's start.
fn call_within(
    processor: &mut Processor<CAP, 2>,
    (f1, f2, m): (&Frame<CAP, 2>, &Frame<CAP, 2>, &roadstereo::Motion),
    clock: &mut impl FnMut(u64) -> bool,
) -> Measured {
    processor.reset();
    let _ = processor.process(f1, None);
    let t0 = fw::ticks();
    let mut ask = || clock(fw::ticks().saturating_sub(t0));
    let (processed, instr) = fw::measure(|| {
        processor
            .process_within(black_box(f2), Some(m), &mut ask)
            .is_ok()
    });
    Measured::of(processor, (processed, instr))
}

/// A pair of the deadline's measurements loaded into `(f1, f2)` with its
/// configuration set on `processor`: its motion, or `None` (logged).
fn load_member(
    processor: &mut Processor<CAP, 2>,
    (name, errors, data): (&str, u8, &'static [u8]),
    f1: &mut Frame<CAP, 2>,
    f2: &mut Frame<CAP, 2>,
) -> Option<roadstereo::Motion> {
    let (Some(m), Some(c)) = (
        load(data, f1, f2),
        member_config(errors, Config::DEFAULT_WORK_PER_POINT),
    ) else {
        defmt::error!("bad deadline data for {=str}", name);
        return None;
    };
    if !camera1(name, f1) {
        defmt::error!("bad frame-1 camera for {=str}", name);
        return None;
    }
    processor.set_config(c);
    Some(m)
}

/// The representative pair and every adversarial member at 2 × 256: name,
/// error model ([`member_config`]), data.
fn pairs_256() -> impl Iterator<Item = (&'static str, u8, &'static [u8])> {
    pairs_of(256)
}

/// [`pairs_256`] at 2 × `n`.
fn pairs_of(n: u32) -> impl Iterator<Item = (&'static str, u8, &'static [u8])> {
    let bench = BENCH
        .iter()
        .filter(move |b| b.0 == n)
        .map(|b| ("representative", 0u8, b.1));
    let members = ADVERSARIAL
        .iter()
        .filter(move |a| a.1 == n)
        .map(|a| (a.0, a.2, a.3));
    bench.chain(members)
}

/// The deadline sweep: the representative pair and every adversarial
/// member at 2 × 256, each within every limit of [`DEADLINE_LIMITS`]: the
/// call's instructions, when the clock said the time was up, and the
/// points still `ok`. (`xtask/src/bench.rs` reports the overrun, the
/// call's instructions past the clock's first yes.)
fn deadline_sweep(
    processor: &mut Processor<CAP, 2>,
    f1: &mut Frame<CAP, 2>,
    f2: &mut Frame<CAP, 2>,
) {
    for (name, errors, data) in pairs_256() {
        let Some(m) = load_member(processor, (name, errors, data), f1, f2) else {
            continue;
        };
        for limit in DEADLINE_LIMITS {
            let (r, at) = measure_within(processor, (f1, f2, &m), limit);
            defmt::info!(
                "deadline name={=str} limit={=u32} instr={=u32} expired={=bool} expired_at={=u32} reported={=bool} points={=u32} ok={=u32} processed={=bool}",
                name,
                limit,
                r.instr,
                at.is_some(),
                at.unwrap_or(0),
                processor.deadline_expired(),
                r.points,
                r.ok,
                r.processed
            );
        }
    }
    processor.set_config(Config::DEFAULT);
    deadline_gaps(processor, f1, f2, 256);
    deadline_gaps(processor, f1, f2, 512);
}

/// Questions a frame asks its clock, at most (one to three a point, one
/// before every 32 items of a boundary's passes and a few a boundary, 2 ×
/// 512 points: `host_tests/tests/deadline.rs`).
const MAX_QUESTIONS: usize = 4096;

/// The call's lateness where it is worst: each pair (the representative,
/// every member, every configuration probe, and `search_3` under
/// localisation errors of 100 px, an adversarial review's find) run once
/// with a clock that never says yes, recording when each question is
/// asked; then, for the questions after the four longest gaps, run with a
/// clock that says yes there (the same clock otherwise). A limit just
/// after the question before the gap makes the call that late: the gap,
/// then the overrun past the yes. Logged per cut: the gap, the overrun,
/// their sum (the lateness).
fn deadline_gaps(
    processor: &mut Processor<CAP, 2>,
    f1: &mut Frame<CAP, 2>,
    f2: &mut Frame<CAP, 2>,
    n: u32,
) {
    let probes = PROBES
        .iter()
        .filter(|p| p.4.is_none() && (p.2 == 256 || p.2 == n))
        .filter_map(move |p| pair_data(p.1, n).map(|data| (p.0, p.3, data)));
    let wide = ADVERSARIAL
        .iter()
        .filter(move |a| a.0 == "search_3" && a.1 == n)
        .map(|a| ("search_3+e_100", 9u8, a.3));
    // (Every pair with the counting rule for folded points on too: a fifth
    // review found its flags after the cut 42 786 late, over the margin,
    // until they were made where the cut fell; an eighth found the
    // unmodified `straight_exact` 41 250 late at 2 × 512 with the rule on,
    // which these runs then left out, and its own pair 49 282.)
    let runs = pairs_of(n)
        .chain(probes)
        .chain(wide)
        .flat_map(|(name, errors, data)| [(name, errors, data, false), (name, errors, data, true)]);
    for (name, errors, data, counting) in runs {
        let Some(m) = load_member(processor, (name, errors, data), f1, f2) else {
            continue;
        };
        processor.set_fold_counting(counting);
        // The questions' times, instructions from the call's start.
        let mut times = heapless::Vec::<u32, MAX_QUESTIONS>::new();
        let full = cut_at(processor, (f1, f2, &m), usize::MAX, &mut times);
        // The four longest gaps (gap, index of the question after it).
        let mut top = [(0u32, 0usize); 4];
        for (k, w) in times.windows(2).enumerate() {
            let (Some(&a), Some(&b)) = (w.first(), w.get(1)) else {
                continue;
            };
            let gap = b.saturating_sub(a);
            if let Some(slot) = top.iter_mut().min_by_key(|t| t.0) {
                if gap > slot.0 {
                    *slot = (gap, k + 1);
                }
            }
        }
        for (gap, k) in top {
            if gap == 0 {
                continue;
            }
            let mut t = heapless::Vec::<u32, MAX_QUESTIONS>::new();
            let end = cut_at(processor, (f1, f2, &m), k, &mut t);
            let at = t.get(k).copied().unwrap_or(end);
            let before = t.get(k.wrapping_sub(1)).copied().unwrap_or(0);
            defmt::info!(
                "deadline_gap n={=u32} name={=str} counting={=bool} questions={=usize} full={=u32} k={=usize} gap={=u32} overrun={=u32} lateness={=u32} reported={=bool}",
                n,
                name,
                counting,
                times.len(),
                full,
                k,
                gap,
                end.saturating_sub(at),
                end.saturating_sub(before),
                processor.deadline_expired()
            );
        }
    }
    processor.set_fold_counting(false);
    processor.set_config(Config::DEFAULT);
}

/// The pair's call within a clock that records each question's time in
/// `times` (instructions from the call's start) and says yes from
/// question `k` on; returns the call's instructions.
fn cut_at(
    processor: &mut Processor<CAP, 2>,
    pair: (&Frame<CAP, 2>, &Frame<CAP, 2>, &roadstereo::Motion),
    k: usize,
    times: &mut heapless::Vec<u32, MAX_QUESTIONS>,
) -> u32 {
    let r = call_within(processor, pair, &mut |dt| {
        let _ = times.push(fw::instructions(dt));
        times.len() > k
    });
    r.instr
}

/// An adversarial member's configuration: its error model (the id in
/// `data/adversarial.rs`, `Errors::id` in `host_tests/src/drive/adversarial.rs`)
/// with a work budget of `w` units per point.
fn member_config(errors: u8, w: u32) -> Option<Config> {
    let c = match errors {
        0 => Config::DEFAULT,
        1 => Config::DEFAULT.with_rotation_error([0.01; 3]).ok()?,
        2 => Config::DEFAULT
            .with_rotation_error([0.0, 0.0, 0.001])
            .ok()?,
        3 => Config::DEFAULT.with_translation_error(0.02).ok()?,
        // The configuration probes' ([`PROBES`]).
        4 => Config::DEFAULT.with_localisation_error(0.5, 10.0).ok()?,
        5 => Config::new(0.5, 0.5, 0.1, 1000.0)
            .ok()?
            .with_rotation_error([1.0e-6, 0.0, 0.0])
            .ok()?,
        6 => Config::new(0.5, 0.5, 0.1, 1000.0).ok()?,
        7 => Config::DEFAULT.with_localisation_error(0.5, 2.0).ok()?,
        8 => Config::DEFAULT.with_localisation_error(3.0, 3.0).ok()?,
        // The deadline's probe (`deadline_gaps`).
        9 => Config::DEFAULT.with_localisation_error(100.0, 100.0).ok()?,
        // The [`FOUND`] pairs' (reviews' hill climbing).
        id @ 10.. => {
            let &(e1, e2, angle, t, r, max_depth) = FOUND_CONFIGS.get(usize::from(id - 10))?;
            let mut c = Config::new(e1, e2, angle, max_depth).ok()?;
            if let Some(t) = t {
                c = c.with_translation_error(t).ok()?;
            }
            if let Some(r) = r {
                c = c.with_rotation_error(r).ok()?;
            }
            c
        }
    };
    c.with_work_budget(w).ok()
}

/// The configurations the [`FOUND`] pairs' climbs settled on, ids 10 …
/// of [`member_config`]: `e₁`, `e₂` (px), the minimum angle (°), the
/// translation and the rotation error bounds where configured, the
/// largest depth.
#[allow(clippy::type_complexity)]
const FOUND_CONFIGS: [(f32, f32, f32, Option<f32>, Option<[f32; 3]>, f32); 17] = [
    // 10: rev_a1
    (
        0.187_798_7,
        3.886_967_7,
        0.1,
        Some(0.000_036_500_76),
        Some([5.444_365e-9, 6.994_154_7e-7, 0.000_011_191_911]),
        1000.0,
    ),
    // 11: rev_b1
    (
        0.039_700_568,
        7.797_034_3,
        0.1,
        None,
        Some([2.330_313_3e-7, 0.000_001_234_004_8, 0.000_011_155_589]),
        1000.0,
    ),
    // 12: rev_b2
    (
        0.002_421_314_8,
        3.546_954_2,
        1.560_985_1,
        None,
        Some([0.000_001_897_681, 1.341_467_9e-7, 0.000_001_043_540_7]),
        1000.0,
    ),
    // 13: rev_c1
    (
        7.236_438_8,
        1.773_699_4,
        0.1,
        Some(0.000_329_890_38),
        Some([0.000_069_144_04, 0.000_004_483_309_6, 0.000_148_353_72]),
        1000.0,
    ),
    // 14: rev_c2
    (
        0.039_460_093,
        7.563_63,
        0.230_282_22,
        None,
        Some([0.000_001_031_347_8, 1.524_648_6e-7, 0.000_011_155_589]),
        1000.0,
    ),
    // 15: rev_d2
    (
        1.156_408_3,
        20.876_842,
        0.1,
        Some(0.000_057_453_27),
        None,
        1000.0,
    ),
    // 16: rev_e2
    (
        0.177_312_46,
        0.514_759_96,
        0.1,
        Some(0.000_036_500_76),
        Some([2.912_029_2e-7, 3.432_673_3e-9, 5.980_558_6e-8]),
        1000.0,
    ),
    // 17: rev_e4
    (
        0.057_810_06,
        0.091_832_56,
        89.0,
        None,
        Some([0.000_019_466_439, 0.000_011_047_276_5, 5.317_562_6e-7]),
        1000.0,
    ),
    // 18: rev_f1
    (
        0.057_047_132,
        0.124_408_76,
        89.0,
        None,
        Some([1.887_626_8e-5, 8.793_415e-6, 6.647_438e-7]),
        3_700.942_6,
    ),
    // 19: rev_g1
    (
        1.152_771_7,
        20.876_842,
        0.929_086_1,
        Some(2.034_227_7e-6),
        None,
        8_995.452,
    ),
    // 20: rev_h1
    (0.492_813_8, 4.110_903, 3.451_912_2, None, None, 1_268.646_1),
    // 21: rev_x3
    (
        0.071_628_03,
        0.150_381_34,
        89.0,
        Some(8.588_438e-6),
        Some([1.750_005_9e-5, 8.877_444e-6, 4.543_080_6e-7]),
        447.416_14,
    ),
    // 22: rev8_a
    (
        0.074_166_59,
        0.156_690_03,
        89.0,
        Some(9.357_789e-6),
        Some([1.5192426e-05, 1.27653275e-05, 1.953_062_6e-7]),
        1_319.43,
    ),
    // 23: rev8_b
    (
        0.15482147,
        0.003_454_848_2,
        83.893_92,
        Some(3.212_669_3e-5),
        Some([2.022_006_8e-6, 4.445_789_2e-7, 5.766_947_5e-8]),
        2.534_873_2,
    ),
    // 24: rev8_l
    (
        0.601_261_6,
        0.669_997_33,
        0.412_469_1,
        None,
        None,
        362.27478,
    ),
    // 25: rev8_s
    (0.489_574_25, 0.424_186_3, 39.153_034, None, None, 659.257_9),
    // 26: rev9_s
    (
        0.963_977_4,
        0.219_373_36,
        7.695_428_3,
        None,
        None,
        2_135.399_6,
    ),
];

/// Configuration probes of the worst-case sweep: a member's frame pair (its
/// name and N in the family) under another valid configuration (an id of
/// [`member_config`]), logged as its own sweep row. An adversarial review
/// found these over the envelope measured on the members' own
/// configurations: a wide frame-2 error (the band's segments pass
/// `Radial`'s cheap test and are clipped, about 100 instructions a unit), a
/// tiny rotation error with a small minimum angle (every point checked in
/// step 1), and a rotation error at small budgets (the fixed cost of a
/// point, `C_P`).
/// The `+e_3` probes (a review's ask) run forward members with shallow
/// crossings and dense vertices under `e₁ = e₂ = 3` px: most disparities
/// are then under `REFINE_GAP (r₁ + e₂)`, so most points take the stick
/// from the piece's lines, whose bounds the work budget charges
/// `REFINE_UNITS` a segment (before it did, these probes measured 134
/// instructions a unit: the pass was paid only by the walk's clips).
/// A probe with a window `(off, k)` takes points `off .. off + k` of each
/// boundary in both frames (a smaller frame of the same pair).
#[allow(clippy::type_complexity)]
const PROBES: &[(&str, &str, u32, u8, Option<(usize, usize)>)] = &[
    ("back_spiral+e2_10", "back_spiral", 256, 4, None),
    ("back_spiral+e2_2", "back_spiral", 256, 7, None),
    ("back_radial_stair+e2_10", "back_radial_stair", 256, 4, None),
    (
        "back_spiral+rot_1e-6+angle_0.1",
        "back_spiral",
        256,
        5,
        None,
    ),
    ("search_1+angle_0.1", "search_1", 256, 6, None),
    ("fwd_spiral_zz+rot_z", "fwd_spiral_zz", 64, 2, None),
    (
        "fwd_spiral_zz+rot_z[16..64]",
        "fwd_spiral_zz",
        64,
        2,
        Some((16, 48)),
    ),
    ("fwd_spiral+rot_1e-6+angle_0.1", "fwd_spiral", 64, 5, None),
    (
        "fwd_spiral+rot_1e-6+angle_0.1[12..60]",
        "fwd_spiral",
        64,
        5,
        Some((12, 48)),
    ),
    (
        "back_spiral+rot_1e-6[60..68]",
        "back_spiral",
        128,
        5,
        Some((60, 8)),
    ),
    ("zigzag_small+e_3", "zigzag_small", 256, 8, None),
    ("radial_stair+e_3", "radial_stair", 256, 8, None),
    ("near_foe+e_3", "near_foe", 256, 8, None),
    ("foe_row+e_3", "foe_row", 256, 8, None),
    ("rev_a1", "rev_a1", 64, 10, None),
    ("rev_b1", "rev_b1", 256, 11, None),
    ("rev_b2", "rev_b2", 64, 12, None),
    ("rev_c1", "rev_c1", 512, 13, None),
    ("rev_c2", "rev_c2", 256, 14, None),
    ("rev_d2", "rev_d2", 512, 15, None),
    ("rev_e2", "rev_e2", 64, 16, None),
    ("rev_e4", "rev_e4", 64, 17, None),
    ("rev_f1", "rev_f1", 64, 18, None),
    ("rev_g1", "rev_g1", 512, 19, None),
    ("rev_h1", "rev_h1", 512, 20, None),
    ("rev_x3", "rev_x3", 64, 21, None),
    ("rev8_a", "rev8_a", 64, 22, None),
    ("rev8_b", "rev8_b", 128, 23, None),
    ("rev8_l", "rev8_l", 512, 24, None),
    ("rev8_s", "rev8_s", 512, 25, None),
    ("rev9_s", "rev9_s", 512, 26, None),
];

/// Budgets of the configuration probes (the sweep's, up to twice the
/// default: the probes' frames are long), with the small budgets just
/// above the smallest (a fifth review found a pair over the envelope at
/// `w = 9`, none of the sweep's then, a unit there dearer than the
/// sweep's slopes).
const PROBE_SWEEP: [u32; 7] = [
    Config::MIN_WORK_PER_POINT,
    9,
    10,
    12,
    16,
    Config::DEFAULT_WORK_PER_POINT,
    160,
];

/// Budgets of the work sweep, units per point: the smallest accepted, two
/// between, the default and up to 8 times it.
const SWEEP: [u32; 6] = [
    Config::MIN_WORK_PER_POINT,
    16,
    40,
    Config::DEFAULT_WORK_PER_POINT,
    160,
    640,
];

/// The pair `f` cut to its first `boundaries` boundaries, each to its
/// points `from .. to` (fewer where a boundary is shorter), and whether
/// every cut boundary was accepted.
fn cut(
    (f1, f2): (&Frame<CAP, 2>, &Frame<CAP, 2>),
    boundaries: usize,
    (from, to): (usize, usize),
) -> (Frame<CAP, 2>, Frame<CAP, 2>, bool) {
    let (mut t1, mut t2) = (
        Frame::<CAP, 2>::new(*f1.camera()),
        Frame::<CAP, 2>::new(*f2.camera()),
    );
    let mut pushed = true;
    for (src, dst) in [(f1, &mut t1), (f2, &mut t2)] {
        for bd in src.boundaries().iter().take(boundaries) {
            let pts = bd.points();
            let part = pts.get(from..to.min(pts.len())).unwrap_or(&[]);
            pushed &= dst.push_boundary(part).is_ok();
        }
    }
    (t1, t2, pushed)
}

/// One row of the worst-case sweep: the pair under error model `errors`
/// ([`member_config`]) with budget `w`, measured and logged under `name`
/// (the family's `n`); false when the configuration is not valid.
fn sweep_row(
    processor: &mut Processor<CAP, 2>,
    (f1, f2, m): (&Frame<CAP, 2>, &Frame<CAP, 2>, &roadstereo::Motion),
    (name, n): (&str, u32),
    errors: u8,
    w: u32,
) -> bool {
    let Some(c) = member_config(errors, w) else {
        return false;
    };
    processor.set_config(c);
    let r = measure_pair(processor, f1, f2, m);
    let s = processor.structure();
    defmt::info!(
        "sweep name={=str} n={=u32} w={=u32} points={=u32} instr={=u32} processed={=bool} work_spent={=u32} over_budget={=usize}",
        name,
        n,
        w,
        r.points,
        r.instr,
        r.processed,
        s.work_units().0,
        s.status_counts().get(Status::OverBudget)
    );
    true
}

/// The measurements behind README's worst-case formula ("Worst case"):
/// the fixed cost of a frame (one and two boundaries of two points each,
/// from the N = 32 bench pair), and every 2 × 256 member of the adversarial
/// family under each budget of [`SWEEP`] (instructions against the work
/// units spent; the points flagged `over_budget`).
fn worst_case_sweep(
    processor: &mut Processor<CAP, 2>,
    f1: &mut Frame<CAP, 2>,
    f2: &mut Frame<CAP, 2>,
) {
    defmt::info!(
        "work default_per_point={=u32}",
        Config::DEFAULT_WORK_PER_POINT
    );
    if let Some((_, data)) = BENCH.first() {
        if let Some(m) = load(data, f1, f2) {
            for b in 1..=2usize {
                let (t1, t2, pushed) = cut((f1, f2), b, (0, 2));
                let r = measure_pair(processor, &t1, &t2, &m);
                defmt::info!(
                    "fixed boundaries={=usize} points={=u32} instr={=u32} processed={=bool} pushed={=bool}",
                    b,
                    r.points,
                    r.instr,
                    r.processed,
                    pushed
                );
            }
        }
    }
    for (name, n, errors, data) in ADVERSARIAL.iter().filter(|a| a.1 == 256) {
        let Some(m) = load(data, f1, f2) else {
            continue;
        };
        for w in SWEEP {
            sweep_row(processor, (f1, f2, &m), (name, *n), *errors, w);
        }
    }
    for (probe, member, n, errors, window) in PROBES {
        let Some(data) = pair_data(member, *n) else {
            defmt::error!(
                "no member {=str} n={=u32} for probe {=str}",
                member,
                n,
                probe
            );
            continue;
        };
        let Some(m) = load(data, f1, f2) else {
            continue;
        };
        if !camera1(member, f1) {
            defmt::error!("probe {=str}: its frame-1 camera does not push", probe);
            continue;
        }
        if let Some((off, k)) = *window {
            let (t1, t2, pushed) = cut((f1, f2), 2, (off, off + k));
            if !pushed {
                defmt::error!("probe {=str}: its window does not push", probe);
                continue;
            }
            (*f1, *f2) = (t1, t2);
        }
        for w in PROBE_SWEEP {
            if !sweep_row(processor, (f1, f2, &m), (probe, *n), *errors, w) {
                defmt::error!("bad probe configuration for {=str}", probe);
            }
        }
    }
    processor.set_config(Config::DEFAULT);
}

/// The link's decoder on the emulated controller (issue 12): the first
/// frame of the N = 256 bench pair as a frame packet, decoded whole and
/// in the UART driver's 64-byte chunks (COBS, CRC, parsing, the points
/// written into the frame and validated), and the CRC alone over the
/// packet with no table, one table (the library's choice) and 16 tables.
fn wire_cost() {
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
