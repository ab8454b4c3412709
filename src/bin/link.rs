//! The camera front-end link on the emulated vehicle controller: packets
//! come in on UART0 (camera, motion and frame packets, `roadstereo::wire`),
//! each frame goes through the per-frame processor with its pair's
//! configuration, and a result packet (or a report packet for each typed
//! error) goes back out on UART0. An end packet makes it answer with a
//! summary packet (its counters) and exit with success.
//!
//! The per-frame call is timed alone (the UART polling's instruction count
//! varies from run to run); the instructions go into the result packet and
//! the defmt log. `cargo xtask stream FILE.jsonl` drives it.
//!
//! With the feature `link-fused` each frame goes into a key-frame fusion
//! instead ([`roadstereo::wire::FrameJob::run_fused`]): the result packet
//! is the pair of the key frame with this frame (its `kept` id the key
//! frame's), and the log line of each frame carries the fusion's digest,
//! which the stream tool compares with the host's.

#![no_std]
#![no_main]

mod fw;

use cortex_m_rt::entry;
use defmt_semihosting as _;
#[cfg(feature = "link-fused")]
use roadstereo::fusion::{Fusion, FusionConfig};
use roadstereo::link::{write_packet, write_result, UartLink};
use roadstereo::wire::encode::{ResultHead, Sender};
use roadstereo::wire::{self, DataIds, Event, FrameJob, PacketType, Receiver};
#[cfg(not(feature = "link-fused"))]
use roadstereo::Processor;
use roadstereo::{Config, Status, Step};
use static_cell::ConstStaticCell;

/// Capacity: two boundaries of up to 256 points.
const N: usize = 256;
const B: usize = 2;

/// Default frame budget: 5 % of a 33 ms frame at 168 MHz, one instruction
/// counted as one cycle (as the demo).
const BUDGET_INSTRUCTIONS: u32 = 33 * 168_000 / 20;

/// With the feature `link-deadline`, each frame runs within SysTick as the
/// deadline's clock ([`roadstereo::wire::FrameJob::run_within`]), the
/// clock saying yes at [`LIMIT_INSTRUCTIONS`]: every frame then ends within
/// [`BUDGET_INSTRUCTIONS`], the points the time did not reach flagged
/// `over_budget` (`cargo xtask stream FILE --within` checks both). Without
/// it the call is not bounded by a clock, and the host reproduces every
/// result bit for bit.
const WITHIN: bool = cfg!(feature = "link-deadline");

/// Whether each frame goes into a key-frame fusion (feature `link-fused`).
const FUSED: bool = cfg!(feature = "link-fused");

/// The clock's limit within a deadline: the frame budget less the lateness
/// README tells a firmware to allow for (40 000 instructions), and with the
/// fusion also less the fusion's own work after the matching, which the
/// deadline does not cut: the demo's limit for its fusion steps (212 000,
/// `src/bin/bench/fusion.rs`, `DRIVE_LIMIT`; at most 64 instructions a key-frame
/// point on the demo drive, whose map never fills; 165, and up to 209 in
/// reviews' runs, where a key frame retires into a full map, README).
const LIMIT_INSTRUCTIONS: u32 = if FUSED {
    212_000
} else {
    BUDGET_INSTRUCTIONS - 40_000
};

/// Points per boundary in the fusion's road map.
#[cfg(feature = "link-fused")]
const M: usize = 512;

/// UART0 of the mps2-an386 (CMSDK APB UART), register level. The library
/// stays free of `unsafe`: the volatile register accesses live here.
mod uart0 {
    use core::convert::Infallible;
    use core::ptr::{read_volatile, write_volatile};

    const BASE: usize = 0x4000_4000;
    const DATA: *mut u32 = BASE as *mut u32;
    const STATE: *mut u32 = (BASE + 0x04) as *mut u32;
    const CTRL: *mut u32 = (BASE + 0x08) as *mut u32;
    const BAUDDIV: *mut u32 = (BASE + 0x10) as *mut u32;
    const TX_FULL: u32 = 1 << 0;
    const RX_FULL: u32 = 1 << 1;

    /// A handle on UART0 (all handles drive the same registers).
    pub struct Uart0;

    impl Uart0 {
        /// Enable transmit and receive.
        pub fn init() -> Self {
            // SAFETY: the UART0 registers of this machine; nothing else in
            // the firmware touches them.
            unsafe {
                write_volatile(BAUDDIV, 16);
                write_volatile(CTRL, 0b11);
            }
            Uart0
        }
        fn state() -> u32 {
            // SAFETY: see `init`.
            unsafe { read_volatile(STATE) }
        }
    }

    impl embedded_io::ErrorType for Uart0 {
        type Error = Infallible;
    }

    impl embedded_io::Read for Uart0 {
        /// Blocks until a byte came, then takes what is there.
        fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
            let mut n = 0;
            if buf.is_empty() {
                return Ok(0);
            }
            while Self::state() & RX_FULL == 0 {}
            for b in buf.iter_mut() {
                if Self::state() & RX_FULL == 0 {
                    break;
                }
                // SAFETY: see `init`.
                *b = unsafe { read_volatile(DATA) } as u8;
                n += 1;
            }
            Ok(n)
        }
    }

    impl embedded_io::Write for Uart0 {
        fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
            for &b in buf {
                while Self::state() & TX_FULL != 0 {}
                // SAFETY: see `init`.
                unsafe { write_volatile(DATA, u32::from(b)) };
            }
            Ok(buf.len())
        }
        fn flush(&mut self) -> Result<(), Infallible> {
            Ok(())
        }
    }
}

use uart0::Uart0;

/// The buffer for the report and summary packets (a summary: header 10,
/// four counters and one a kind, CRC 4); results go out through
/// `write_result`, with no buffer for the packet.
const RAW: usize = 14 + 4 * (4 + wire::ErrorKind::ALL.len());

/// The receiver (its frame under assembly) and the processor in statics,
/// laid out at build time: their constructors are `const`.
static RECEIVER: ConstStaticCell<Receiver<N, B>> =
    ConstStaticCell::new(Receiver::new(DataIds::DEFAULT, Config::DEFAULT));
#[cfg(not(feature = "link-fused"))]
static PROCESSOR: ConstStaticCell<Processor<N, B>> =
    ConstStaticCell::new(Processor::new(Config::DEFAULT));
/// With `link-fused`: the fusion (its processor, key frame and map), its
/// error model the receiver's base configuration (a frame sent with a
/// larger radius or motion bounds is refused,
/// [`roadstereo::fusion::FusionError::ErrorsAboveConfig`]) and the default
/// policy.
#[cfg(feature = "link-fused")]
static FUSION: ConstStaticCell<Fusion<N, B, M>> =
    ConstStaticCell::new(Fusion::new(Config::DEFAULT, FusionConfig::DEFAULT));

/// What runs the frames: the processor, pairing each frame with the last,
/// or the fusion, pairing it with its key frame.
struct Runner {
    #[cfg(not(feature = "link-fused"))]
    processor: &'static mut Processor<N, B>,
    #[cfg(feature = "link-fused")]
    fusion: &'static mut Fusion<N, B, M>,
    /// The key frame's boundary qualities (what its pairs' results report).
    #[cfg(feature = "link-fused")]
    key_quality: [u8; B],
}

impl Runner {
    fn new() -> Self {
        Runner {
            #[cfg(not(feature = "link-fused"))]
            processor: PROCESSOR.take(),
            #[cfg(feature = "link-fused")]
            fusion: FUSION.take(),
            #[cfg(feature = "link-fused")]
            key_quality: [0; B],
        }
    }

    /// The job run (within the clock's limit with `link-deadline`): the
    /// result packet's head (its instructions the call's, timed alone),
    /// the step and the kept frame's qualities; `None` when the frame was
    /// refused.
    #[cfg(not(feature = "link-fused"))]
    fn run(&mut self, job: &FrameJob<'_, N, B>) -> Option<(ResultHead, Step<'_, N, B>, [u8; B])> {
        let (step, instr) = if WITHIN {
            let (t0, limit) = (fw::ticks(), fw::ticks_of(LIMIT_INSTRUCTIONS));
            let mut clock = || fw::ticks().saturating_sub(t0) >= limit;
            fw::measure(|| job.run_within(self.processor, &mut clock))
        } else {
            fw::measure(|| job.run(self.processor))
        };
        let Ok(step) = step else {
            defmt::error!("frame {=u32}: processor refused", job.info.frame_id);
            return None;
        };
        Some((job.result_head(instr), step, job.kept_quality))
    }

    /// [`Self::run`] through the fusion: the head names the key frame the
    /// frame was paired with (the frame itself, and no structure, when it
    /// was not paired); the log line gives the fusion's digest after it.
    #[cfg(feature = "link-fused")]
    fn run(&mut self, job: &FrameJob<'_, N, B>) -> Option<(ResultHead, Step<'_, N, B>, [u8; B])> {
        let key = self.fusion.key_id();
        let (step, instr) = if WITHIN {
            let (t0, limit) = (fw::ticks(), fw::ticks_of(LIMIT_INSTRUCTIONS));
            let mut clock = || fw::ticks().saturating_sub(t0) >= limit;
            fw::measure(|| job.run_fused_within(self.fusion, &mut clock))
        } else {
            fw::measure(|| job.run_fused(self.fusion))
        };
        let step = match step {
            Ok(s) => s,
            Err(e) => {
                defmt::error!("frame {=u32}: fusion refused: {}", job.info.frame_id, e);
                return None;
            }
        };
        let paired = step.paired.and(key);
        let quality = if paired.is_some() {
            self.key_quality
        } else {
            job.info.quality
        };
        if step.new_key.is_some() {
            self.key_quality = job.info.quality;
        }
        let c = self.fusion.key().map(|k| k.counts()).unwrap_or_default();
        defmt::info!(
            "fused frame={=u32} key={=u32} paired={=bool} consistent={=u32} inconsistent={=u32} fusion_digest={=u32:08x}",
            job.info.frame_id,
            paired.unwrap_or(job.info.frame_id),
            paired.is_some(),
            c.consistent,
            c.inconsistent,
            self.fusion.digest()
        );
        let mut head = job.result_head(instr);
        head.kept_id = paired.unwrap_or(job.info.frame_id);
        let result = match paired {
            Some(_) => Step::Structure(self.fusion.structure()),
            None => Step::First,
        };
        Some((head, result, quality))
    }
}

#[entry]
fn main() -> ! {
    let Some(mut core) = cortex_m::Peripherals::take() else {
        fw::exit(false)
    };
    fw::start_counter(&mut core.SYST);
    let mut link = UartLink::new(Uart0::init());
    let mut tx = Uart0;
    let ids = DataIds::DEFAULT;
    let rx: &'static mut Receiver<N, B> = RECEIVER.take();
    let mut runner = Runner::new();
    let mut raw = [0u8; RAW];
    // (Numbers each output data id's packets.)
    let mut sender = Sender::new(ids);
    defmt::info!(
        "roadstereo link: UART0, capacity {=usize} x {=usize}, budget {=u32} instructions/frame, within a deadline {=bool} (limit {=u32}), fused {=bool}",
        B,
        N,
        BUDGET_INSTRUCTIONS,
        WITHIN,
        LIMIT_INSTRUCTIONS,
        FUSED
    );
    defmt::info!(
        "sizes receiver={=usize} uart_link={=usize} result_buffers={=usize}",
        core::mem::size_of::<Receiver<N, B>>(),
        core::mem::size_of::<UartLink<Uart0>>(),
        RAW
    );
    loop {
        let mut end = false;
        let polled = link.poll(rx, |ev| match ev {
            Event::Frame(job) => {
                let Some((head, step, quality)) = runner.run(&job) else {
                    return;
                };
                let instr = head.instructions;
                if let Step::Structure(s) = &step {
                    let c = s.status_counts();
                    defmt::info!(
                        "frame={=u32} kept={=u32} points={=u32} ok={=u32} instr={=u32} budget_permille={=u32} digest={=u32:08x}",
                        job.info.frame_id,
                        head.kept_id,
                        c.total() as u32,
                        c.get(Status::Ok) as u32,
                        instr,
                        (u64::from(instr) * 1000 / u64::from(BUDGET_INSTRUCTIONS)) as u32,
                        s.digest()
                    );
                }
                let counter = sender.next_counter(PacketType::Result);
                match write_result(&mut tx, ids.result, counter, &head, &step, &quality) {
                    Ok(()) => sender.skip(PacketType::Result),
                    Err(e) => defmt::error!("result packet: {}", e),
                }
            }
            Event::Error(e) => {
                defmt::warn!("link error: {}", e);
                if let Ok(n) = sender.report(&mut raw, &e) {
                    let _ = write_packet(&mut tx, raw.get(..n).unwrap_or(&[]));
                }
            }
            Event::End => end = true,
            Event::Motion(_) | Event::Camera(_) => {}
        });
        if polled.is_err() {
            defmt::error!("UART read error");
        }
        if end {
            let c = *rx.counters();
            if let Ok(n) = sender.summary(&mut raw, &c.values()) {
                let _ = write_packet(&mut tx, raw.get(..n).unwrap_or(&[]));
            }
            defmt::info!(
                "done bytes={=u32} frames={=u32} motions={=u32} cameras={=u32} errors={=u32}",
                c.bytes,
                c.frames,
                c.motions,
                c.cameras,
                c.total_errors()
            );
            fw::exit(true)
        }
    }
}
