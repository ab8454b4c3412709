//! Firmware support shared by the binaries: the embedded frame data, the
//! instruction counter and the semihosting exit.
//!
//! Instruction counting: QEMU does not emulate the DWT cycle counter, but
//! SysTick on the core clock (the board's, [`board::CORE_HZ`]: 25 MHz on
//! mps2-an386, 40 ns a tick; 168 MHz on the STM32F405) counts virtual time,
//! and with `-icount shift=5` every instruction takes 32 ns: instructions =
//! ticks × (10⁹ / CORE_HZ) / 32, the same on every run.

#![allow(dead_code)]

pub mod board;

use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::{exception, ExceptionFrame};
use cortex_m_semihosting::debug;
use roadstereo::fusion::{ChainedMotion, FusionConfig};
use roadstereo::{Camera, Frame, Motion, Pixel, Structure};

/// Exit QEMU with success or failure (the process exit code is the verdict).
pub fn exit(ok: bool) -> ! {
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    #[allow(clippy::empty_loop)]
    loop {}
}

static WRAPS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    WRAPS.fetch_add(1, Ordering::Relaxed);
}

/// Start SysTick on the core clock, full 24-bit period, counting wraps.
pub fn start_counter(syst: &mut SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
}

/// Core-clock ticks since [`start_counter`].
#[inline(never)]
pub fn ticks() -> u64 {
    loop {
        let w1 = WRAPS.load(Ordering::Relaxed);
        let current = SYST::get_current();
        let w2 = WRAPS.load(Ordering::Relaxed);
        if w1 == w2 {
            return u64::from(w1) * 0x0100_0000 + u64::from(0x00FF_FFFF - current);
        }
    }
}

/// Instructions executed in `ticks` core-clock ticks under `-icount shift=5`
/// (32 ns each).
pub fn instructions(ticks: u64) -> u32 {
    // In u128: ticks × 10⁹ passes u64 after 110 s at 168 MHz.
    let ns = u128::from(ticks) * 1_000_000_000 / u128::from(board::CORE_HZ);
    u32::try_from(ns / 32).unwrap_or(u32::MAX)
}

/// Core-clock ticks in which `instructions` run under `-icount shift=5`
/// (the inverse of [`instructions`]).
pub fn ticks_of(instructions: u32) -> u64 {
    let ns = u128::from(instructions) * 32;
    u64::try_from(ns * u128::from(board::CORE_HZ) / 1_000_000_000).unwrap_or(u64::MAX)
}

/// Run `f` and return its result with the instructions it took (the
/// measurement's own overhead, measured once, subtracted).
#[inline(never)]
pub fn measure<T>(f: impl FnOnce() -> T) -> (T, u32) {
    let t0 = ticks();
    let r = f();
    let t1 = ticks();
    let t2 = ticks();
    // t2 - t1 is the cost of one ticks() call: the part of t1 - t0 that is
    // not `f`.
    (r, instructions((t1 - t0).saturating_sub(t2 - t1)))
}

/// Why the embedded frame data could not be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum DataError {
    /// The data ends early or has a bad header.
    Truncated,
    /// The camera, a motion or a boundary is invalid.
    Invalid,
}

/// A reader over the embedded frame data (format: `host_tests/src/drive.rs`).
pub struct Drive {
    data: &'static [u8],
    at: usize,
    /// The camera of every frame.
    pub camera: Camera,
    /// Number of frames.
    pub frames: u32,
}

impl Drive {
    /// Parse the header.
    pub fn new(data: &'static [u8]) -> Result<Self, DataError> {
        let mut d = Drive {
            data,
            at: 0,
            camera: Camera::new(1.0, 1.0, 0.0, 0.0, 2, 2).map_err(|_| DataError::Invalid)?,
            frames: 0,
        };
        if d.take(4)? != b"RSD1" {
            return Err(DataError::Truncated);
        }
        let (fx, fy, cx, cy) = (d.f32()?, d.f32()?, d.f32()?, d.f32()?);
        let (w, h) = (d.u16()?, d.u16()?);
        d.camera = Camera::new(fx, fy, cx, cy, w, h).map_err(|_| DataError::Invalid)?;
        d.frames = d.u32()?;
        Ok(d)
    }

    fn take(&mut self, n: usize) -> Result<&'static [u8], DataError> {
        let end = self.at.checked_add(n).ok_or(DataError::Truncated)?;
        let s = self.data.get(self.at..end).ok_or(DataError::Truncated)?;
        self.at = end;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32, DataError> {
        let b = self.take(4)?.try_into().map_err(|_| DataError::Truncated)?;
        Ok(u32::from_le_bytes(b))
    }
    fn u16(&mut self) -> Result<u16, DataError> {
        let b = self.take(2)?.try_into().map_err(|_| DataError::Truncated)?;
        Ok(u16::from_le_bytes(b))
    }
    fn f32(&mut self) -> Result<f32, DataError> {
        Ok(f32::from_bits(self.u32()?))
    }

    /// Read the next frame into `frame` (made with this drive's camera;
    /// cleared first); returns the motion from the previous frame (`None`
    /// for an all-zero motion).
    pub fn next_frame<const N: usize, const B: usize>(
        &mut self,
        frame: &mut Frame<N, B>,
    ) -> Result<Option<Motion>, DataError> {
        let t = [self.f32()?, self.f32()?, self.f32()?];
        let r = [self.f32()?, self.f32()?, self.f32()?];
        let motion = if t == [0.0; 3] {
            None
        } else {
            Some(Motion::new(t, r).map_err(|_| DataError::Invalid)?)
        };
        frame.clear();
        let nb = self.u32()?;
        for _ in 0..nb {
            let np = self.u32()? as usize;
            let mut pts: heapless::Vec<Pixel, N> = heapless::Vec::new();
            for _ in 0..np {
                let p = Pixel::new(self.f32()?, self.f32()?);
                pts.push(p).map_err(|_| DataError::Invalid)?;
            }
            frame.push_boundary(&pts).map_err(|_| DataError::Invalid)?;
        }
        Ok(motion)
    }
}

/// The first frame of `data` (an RSD1 drive) as the link sends it: the
/// camera packet into `cam`, the frame packet (radius 0.5 px, quality 255)
/// into `frame`, both COBS-framed. Returns the two lengths and the frame's
/// point count.
pub fn wire_sample<const N: usize, const B: usize>(
    data: &'static [u8],
    raw: &mut [u8],
    cam: &mut [u8],
    frame: &mut [u8],
) -> Option<(usize, usize, usize)> {
    use roadstereo::wire::encode::{self, BoundaryHead, FrameHead, FramePacket};
    use roadstereo::wire::DataIds;
    let mut drive = Drive::new(data).ok()?;
    let camera = drive.camera;
    let mut f = Frame::<N, B>::new(camera);
    drive.next_frame(&mut f).ok()?;
    let ids = DataIds::DEFAULT;
    let n = encode::camera(raw, ids.camera, 0, &camera).ok()?;
    let cam_n = encode::cobs_frame(raw.get(..n)?, cam).ok()?;
    let head = FrameHead {
        timestamp_us: 0,
        frame_id: 1,
        width: camera.width(),
        height: camera.height(),
    };
    let mut p = FramePacket::begin(raw, ids.frame, 0, &head).ok()?;
    let bh = BoundaryHead {
        quality: 255,
        radius_px: 0.5,
    };
    for b in f.boundaries() {
        p.boundary(&bh, b.points()).ok()?;
    }
    let n = p.finish().ok()?;
    let frame_n = encode::cobs_frame(raw.get(..n)?, frame).ok()?;
    let points = f.boundaries().iter().map(|b| b.points().len()).sum();
    Some((cam_n, frame_n, points))
}

/// A HardFault ends the run with failure (QEMU's exit code says so).
#[exception]
unsafe fn HardFault(_frame: &ExceptionFrame) -> ! {
    exit(false)
}

/// So does a panic (none can happen in the library: see the `nopanic` proof).
#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic");
    exit(false)
}

/// The demo drive's fusion policy (the demo, the bench and the profile's
/// fusion window): the drive's camera is tilted 23° down (the map's
/// vehicle frame). Checked at build time.
pub const DEMO_POLICY: FusionConfig = match FusionConfig::DEFAULT.with_tilt(23f32.to_radians()) {
    Ok(p) => p,
    Err(_) => panic!("the demo's tilt is within 90 degrees"),
};

/// Frame `i`'s motion from the drive data as the fusion takes it: from
/// frame `i − 1`.
pub fn chained(i: u32, motion: Option<Motion>) -> Option<ChainedMotion> {
    motion.map(|m| ChainedMotion {
        from: i.wrapping_sub(1),
        motion: m,
    })
}

/// The points of a structure, over its boundaries.
pub fn point_count<const N: usize, const B: usize>(s: &Structure<N, B>) -> usize {
    s.boundaries().iter().map(|b| b.points().len()).sum()
}
