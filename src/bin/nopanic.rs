//! Link-time proof that the per-frame code (the processor and the fusion
//! with its road map, and the calibration) has no
//! panic path: this binary calls every public per-frame entry point and the
//! calibration functions with inputs the optimiser
//! cannot see (`black_box`), and uses `panic-never`, whose panic handler
//! does not link. `cargo build --release --features firmware --bin nopanic`
//! succeeds only if no panicking branch survives in that code.

#![no_std]
#![no_main]

use core::hint::black_box;

use cortex_m_rt::entry;
use panic_never as _;
use roadstereo::calibration::{
    calibrate_jointly, calibrate_stepwise, focus_of_expansion, Flow, MotionFlows,
};
use roadstereo::fusion::{ChainedMotion, Fusion, FusionConfig};
use roadstereo::geometry::Sample;
use roadstereo::link::{write_packet, write_result, SpiLink, UartLink};
use roadstereo::wire::{encode, result, DataIds, Event, Receiver, ResultView};
use roadstereo::{Camera, Config, Frame, Motion, Pixel, Processor, Step};

/// A UART whose bytes the optimiser cannot see.
struct Opaque;
impl embedded_io::ErrorType for Opaque {
    type Error = core::convert::Infallible;
}
impl embedded_io::Read for Opaque {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        for b in buf.iter_mut() {
            *b = black_box(0x5A);
        }
        Ok(black_box(buf.len()))
    }
}
impl embedded_io::Write for Opaque {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        black_box(buf);
        // (Any count, 0 and more than it was given included: the driver
        // must not panic on a writer that breaks the contract.)
        Ok(black_box(buf.len()))
    }
    fn flush(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// An SPI bus and a data-ready pin the optimiser cannot see through.
struct OpaqueSpi;
impl embedded_hal::spi::ErrorType for OpaqueSpi {
    type Error = embedded_hal::spi::ErrorKind;
}
impl embedded_hal::spi::SpiDevice for OpaqueSpi {
    fn transaction(
        &mut self,
        ops: &mut [embedded_hal::spi::Operation<'_, u8>],
    ) -> Result<(), Self::Error> {
        for op in ops.iter_mut() {
            if let embedded_hal::spi::Operation::Read(buf) = op {
                for b in buf.iter_mut() {
                    *b = black_box(0x5A);
                }
            }
        }
        if black_box(false) {
            return Err(embedded_hal::spi::ErrorKind::Other);
        }
        Ok(())
    }
}
impl embedded_hal::digital::ErrorType for OpaqueSpi {
    type Error = core::convert::Infallible;
}
impl embedded_hal::digital::InputPin for OpaqueSpi {
    fn is_high(&mut self) -> Result<bool, Self::Error> {
        Ok(black_box(true))
    }
    fn is_low(&mut self) -> Result<bool, Self::Error> {
        Ok(black_box(false))
    }
}

const N: usize = 256;

#[entry]
fn main() -> ! {
    let mut processor = Processor::<N, 2>::new(
        Config::new(
            black_box(0.5),
            black_box(0.5),
            black_box(10.0),
            black_box(200.0),
        )
        .unwrap_or_default(),
    );
    let mut fusion = Fusion::<N, 2, 512>::new(
        *processor.config(),
        FusionConfig::new(black_box(8), black_box(500))
            .and_then(|c| c.with_tilt(black_box(0.4)))
            .and_then(|c| c.with_map_min_pairs(black_box(2)))
            .and_then(|c| c.with_retirement_share(black_box(375)))
            .unwrap_or_default()
            .with_sight_check(black_box(true)),
    );
    let mut id = 0u32;
    let mut points = [Pixel::default(); N];
    loop {
        let Ok(camera) = Camera::new(
            black_box(800.0),
            black_box(800.0),
            black_box(255.5),
            black_box(239.5),
            black_box(512),
            black_box(480),
        ) else {
            continue;
        };
        let mut frame = Frame::<N, 2>::new(camera);
        for _ in 0..2 {
            for p in points.iter_mut() {
                *p = black_box(Pixel::new(black_box(1.0), black_box(2.0)));
            }
            let len = black_box(N);
            // (A boundary pushed absent, as the optimiser cannot tell.)
            let _ = if black_box(false) {
                frame.push_absent()
            } else {
                frame.push_boundary(points.get(..len).unwrap_or(&[]))
            };
        }
        let motion = Motion::new(black_box([0.0, 0.0, 0.4]), black_box([0.0, 0.1, 0.0])).ok();
        // (The counting rule on or off as the optimiser cannot tell: its
        // code in the proof too.)
        processor.set_fold_counting(black_box(false));
        fusion.set_fold_counting(black_box(false));
        match processor.process(black_box(&frame), motion.as_ref()) {
            Ok(Step::Structure(s)) => {
                black_box(s.digest());
                black_box(s.status_counts());
                for b in s.boundaries() {
                    for r in b.points() {
                        black_box((s.point(r), s.stick(r), r.depth(), r.interval(), r.pixel2()));
                    }
                }
            }
            Ok(Step::First) => {}
            Err(e) => {
                black_box(e);
            }
        }
        if let Some(m) = motion.as_ref().filter(|_| black_box(true)) {
            match processor.process_against_kept(black_box(&frame), m) {
                Ok(s) => {
                    black_box(s.digest());
                }
                Err(e) => {
                    black_box(e);
                }
            }
        }
        // Within a deadline: a clock whose answers the linker cannot know.
        let mut asked = 0u32;
        let mut clock = || {
            asked = asked.wrapping_add(1);
            black_box(asked) > black_box(100)
        };
        if let Some(m) = motion.as_ref().filter(|_| black_box(true)) {
            match processor.process_against_kept_within(black_box(&frame), m, &mut clock) {
                Ok(s) => {
                    black_box(s.digest());
                }
                Err(e) => {
                    black_box(e);
                }
            }
        }
        match processor.process_within(black_box(&frame), motion.as_ref(), &mut clock) {
            Ok(Step::Structure(s)) => {
                black_box(s.digest());
            }
            Ok(Step::First) => {}
            Err(e) => {
                black_box(e);
            }
        }
        black_box(processor.deadline_expired());
        if black_box(false) {
            processor.reset();
        }
        // The fusion and its road map: every public entry point.
        let chained = motion.map(|m| ChainedMotion {
            from: black_box(id),
            motion: m,
        });
        id = id.wrapping_add(black_box(1));
        match fusion.step(black_box(id), black_box(&frame), chained.as_ref()) {
            Ok(s) => {
                black_box(s);
            }
            Err(e) => {
                black_box(e);
            }
        }
        if let Some(key) = fusion.key_ref() {
            black_box(
                fusion
                    .constrain(
                        black_box(key),
                        black_box(0),
                        black_box(3),
                        black_box(1.0),
                        black_box(2.0),
                    )
                    .ok(),
            );
        }
        if let Some(k) = fusion.key() {
            black_box((k.counts(), k.point(black_box(0), black_box(1)), k.len(0)));
            for p in k.points(black_box(1)) {
                black_box(p);
            }
        }
        if black_box(false) {
            fusion.reset_with(FusionConfig::DEFAULT.with_sight_check(black_box(false)));
        }
        let kp = fusion.key_point(black_box(1), black_box(7));
        black_box((kp, kp.and_then(|p| p.stick())));
        let map = fusion.map();
        for p in map.points(black_box(0)) {
            black_box(p);
        }
        let mut samples = heapless::Vec::<Sample, N>::new();
        map.samples(black_box(0), black_box(1), &mut samples);
        black_box((
            samples.len(),
            map.len(1),
            map.drops(),
            map.batch_key(0),
            map.batches(),
        ));
        black_box((fusion.digest(), fusion.structure().digest()));
        if black_box(false) {
            fusion.reset();
        }
        // The motion-error bounds an integrator configures with.
        let angles = black_box([0.1f32, -0.2, 0.3]);
        if let Ok(b) = roadstereo::motion_error::euler_error_box(angles, black_box([1e-3; 3])) {
            black_box(roadstereo::motion_error::rotation_shift_bound(
                roadstereo::Pixel::new(black_box(10.0), black_box(20.0)),
                &camera,
                b,
            ));
        }
        // The link: bytes from outside through the receiver (decoder,
        // pairing, per-pair config), the per-frame call, the result and
        // report packets, the UART driver, and the vehicle-side parsers.
        let mut rx = Receiver::<N, 2>::new(DataIds::DEFAULT, Config::DEFAULT);
        let mut link = UartLink::new(Opaque);
        let mut raw = [0u8; roadstereo::wire::result_packet_max(N, 2)];
        let mut out = Opaque;
        for _ in 0..black_box(3) {
            let _ = link.poll(&mut rx, |ev| match ev {
                Event::Frame(job) => {
                    // (Into the fusion too, as the optimiser cannot tell.)
                    if black_box(false) {
                        black_box(job.run_fused(&mut fusion).ok());
                    }
                    if let Ok(step) = job.run(&mut processor) {
                        let head = job.result_head(black_box(7));
                        if let Ok(n) =
                            encode::result(&mut raw, 1, 2, &head, &step, &job.kept_quality)
                        {
                            let _ = write_packet(&mut out, raw.get(..n).unwrap_or(&[]));
                        }
                        let _ = write_result(&mut out, 1, 2, &head, &step, &job.kept_quality);
                    }
                }
                Event::Error(e) => {
                    if let Ok(n) = encode::report(&mut raw, 1, 2, &e) {
                        let _ = write_packet(&mut out, raw.get(..n).unwrap_or(&[]));
                    }
                }
                _ => {}
            });
        }
        // The SPI driver into the same receiver.
        let mut spi = SpiLink::new(OpaqueSpi, OpaqueSpi);
        for _ in 0..black_box(3) {
            let _ = spi.poll(&mut rx, |ev| {
                black_box(matches!(ev, Event::Frame(_)));
            });
        }
        let bytes = black_box(&raw[..]);
        if let Ok(c) = result::check(bytes) {
            if let Ok(v) = ResultView::parse(c.payload) {
                for b in v.boundaries() {
                    for p in b.points() {
                        black_box(p);
                    }
                }
            }
            black_box(result::report(c.payload));
        }
        // The calibration entry points too.
        let flows = black_box(
            [Flow {
                from: black_box(Pixel::new(1.0, 2.0)),
                to: black_box(Pixel::new(3.0, 4.0)),
            }; 64],
        );
        let fit = focus_of_expansion::<64>(black_box(&flows));
        let p = fit.map(|f| f.foe).unwrap_or_default();
        if let Ok(k) = calibrate_stepwise(black_box(p), black_box([p; 4])) {
            let m = [MotionFlows {
                translation: black_box([0.0, 0.0, 1.0]),
                flows: &flows,
            }];
            black_box(calibrate_jointly::<64>(black_box(&m), &k).ok());
            black_box(k.camera(black_box(512), black_box(480)).ok());
            if let Some(m) = motion.as_ref() {
                black_box(k.camera_motion(m).ok());
            }
            black_box(k.predicted_foe(black_box([0.0, 0.0, 1.0])).ok());
            black_box(k.aspect().ok());
        }
    }
}
