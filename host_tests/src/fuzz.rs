//! The project's own fuzzing (issue 15): structured cases for the frame
//! path ([`frame`]), the calibration entry points ([`calibration`]),
//! [`roadstereo::geometry::road_geometry`] ([`geometry`]), the replay
//! parser ([`replay`]) and the key-frame fusion with its road map
//! ([`fusion`]), each run against its oracles.
//!
//! A case is a pure function of a [`Source`] of 32-bit draws: a seeded
//! generator for the stable pass (`src/bin/fuzz.rs`, `cargo xtask fuzz`)
//! or a byte string for cargo-fuzz (`fuzz/`) and for the saved corpus
//! (`fuzz_corpus/`, replayed by `tests/fuzz_corpus.rs`). A seeded case can
//! be recorded as the bytes of its draws, so one corpus format serves
//! both. Every oracle failure is a panic with a message naming what broke;
//! the runners catch it and report the case.

pub mod calibration;
pub mod frame;
pub mod fusion;
pub mod geometry;
pub mod replay;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Where a case's decisions come from.
pub struct Source<'a> {
    kind: Kind<'a>,
    /// The draws so far, as bytes, when recording (see [`Source::recorded`]).
    record: Option<Vec<u8>>,
}

enum Kind<'a> {
    /// splitmix64.
    Rng(u64),
    /// Four bytes a draw, little endian; zeros after the end.
    Bytes(&'a [u8], usize),
}

impl<'a> Source<'a> {
    /// The seeded generator.
    pub fn seeded(seed: u64) -> Source<'static> {
        Source {
            kind: Kind::Rng(seed ^ 0x005E_ED0F_F022_u64.rotate_left(17)),
            record: None,
        }
    }

    /// Draws read from bytes (cargo-fuzz inputs, corpus files).
    pub fn bytes(b: &'a [u8]) -> Source<'a> {
        Source {
            kind: Kind::Bytes(b, 0),
            record: None,
        }
    }

    /// The same source, recording its draws.
    pub fn recording(mut self) -> Self {
        self.record = Some(Vec::new());
        self
    }

    /// The bytes of the draws so far (empty unless recording): feeding them
    /// to [`Source::bytes`] gives the same case.
    pub fn recorded(&self) -> &[u8] {
        self.record.as_deref().unwrap_or(&[])
    }

    /// The next draw.
    pub fn u32(&mut self) -> u32 {
        let x = match &mut self.kind {
            Kind::Rng(s) => {
                *s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
                let mut z = *s;
                z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
                ((z ^ (z >> 31)) >> 32) as u32
            }
            Kind::Bytes(b, at) => {
                let mut w = [0u8; 4];
                for (k, slot) in w.iter_mut().enumerate() {
                    *slot = b.get(*at + k).copied().unwrap_or(0);
                }
                *at += 4;
                u32::from_le_bytes(w)
            }
        };
        if let Some(r) = &mut self.record {
            r.extend_from_slice(&x.to_le_bytes());
        }
        x
    }

    /// Uniform in `0..n` (`0` for `n = 0`).
    pub fn below(&mut self, n: u32) -> u32 {
        if n == 0 {
            return 0;
        }
        ((u64::from(self.u32()) * u64::from(n)) >> 32) as u32
    }

    /// Uniform in `0..n` as a `usize`.
    pub fn index(&mut self, n: usize) -> usize {
        self.below(u32::try_from(n).unwrap_or(u32::MAX)) as usize
    }

    /// True with probability `num / den`.
    pub fn chance(&mut self, num: u32, den: u32) -> bool {
        self.below(den) < num
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        f64::from(self.u32()) / 4_294_967_296.0
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform in `[lo, hi)` as an `f32`.
    pub fn f32_in(&mut self, lo: f64, hi: f64) -> f32 {
        self.range(lo, hi) as f32
    }

    /// One of `items` (the first for an empty draw).
    pub fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[self.index(items.len())]
    }

    /// A value from [`SPECIALS`], or any bit pattern.
    pub fn special(&mut self) -> f32 {
        if self.chance(1, 8) {
            f32::from_bits(self.u32())
        } else {
            self.pick(&SPECIALS)
        }
    }

    /// A number of the kind the brief lists: mostly `plausible` (drawn by
    /// the caller's closure), else an exact integer near it, a special
    /// value or a ±1e30.
    pub fn mixed(&mut self, plausible: impl FnOnce(&mut Self) -> f32) -> f32 {
        match self.below(32) {
            0 => self.special(),
            1 => {
                let x = plausible(self);
                x.round()
            }
            2 => {
                let x = plausible(self);
                if self.chance(1, 2) {
                    x.next_up()
                } else {
                    x.next_down()
                }
            }
            _ => plausible(self),
        }
    }
}

/// NaN, ±inf, ±0, subnormals, ±1e30, the extremes of `f32` and the
/// crate's range limits and their neighbours.
pub const SPECIALS: [f32; 28] = [
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    0.0,
    -0.0,
    1.0e-45,
    -1.0e-45,
    1.175_494_2e-38, // largest subnormal
    f32::MIN_POSITIVE,
    -f32::MIN_POSITIVE,
    1.0e30,
    -1.0e30,
    f32::MAX,
    f32::MIN,
    3.0e38,
    1.0e6,
    -1.0e6,
    1_000_000.06,
    1.0e5,
    100.0,
    0.1,
    1.0,
    -1.0,
    0.5,
    f32::EPSILON,
    1.0e-6,
    core::f32::consts::PI,
    -core::f32::consts::PI,
];

/// What a target's run of one case gives the runner.
#[derive(Debug, Default, Clone, Copy)]
pub struct Outcome {
    /// Calls of the frame path made (`process`, `process_against_kept`,
    /// `reset`), or entry-point calls for the other targets.
    pub calls: u64,
    /// Frame-path calls that gave a structure (0 for the other targets).
    pub reconstructions: u64,
    /// Kept points matched in those reconstructions, and how many got a
    /// depth.
    pub points: [u64; 2],
    /// Feature bits of the case (statuses seen, error kinds, paths): a
    /// case with a bit no earlier case had is kept as interesting.
    pub features: u128,
}

/// The targets of the pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// [`frame`].
    Frame,
    /// [`calibration`].
    Calibration,
    /// [`geometry`].
    Geometry,
    /// [`replay`].
    Replay,
    /// [`fusion`].
    Fusion,
}

impl Target {
    /// Every target.
    pub const ALL: [Target; 5] = [
        Target::Frame,
        Target::Calibration,
        Target::Geometry,
        Target::Replay,
        Target::Fusion,
    ];

    /// Its name (also the corpus folder's and the cargo-fuzz target's).
    pub fn name(self) -> &'static str {
        match self {
            Target::Frame => "frame",
            Target::Calibration => "calibration",
            Target::Geometry => "geometry",
            Target::Replay => "replay",
            Target::Fusion => "fusion",
        }
    }

    /// The target of a name.
    pub fn from_name(s: &str) -> Option<Target> {
        Target::ALL.into_iter().find(|t| t.name() == s)
    }

    /// Generate a case from `src` and check it (panics on a finding).
    pub fn run(self, src: &mut Source) -> Outcome {
        match self {
            Target::Frame => frame::run(src),
            Target::Calibration => calibration::run(src),
            Target::Geometry => geometry::run(src),
            Target::Replay => replay::run(src),
            Target::Fusion => fusion::run(src),
        }
    }

    /// The case of `src`, described (for a report).
    pub fn describe(self, src: &mut Source) -> String {
        match self {
            Target::Frame => format!("{:#?}", frame::generate(src)),
            Target::Calibration => format!("{:#?}", calibration::generate(src)),
            Target::Geometry => format!("{:#?}", geometry::generate(src)),
            Target::Replay => replay::describe(src),
            Target::Fusion => format!("{:#?}", fusion::generate(src)),
        }
    }
}

/// The message of a caught panic.
pub fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "(panic with a non-string payload)".to_string()
    }
}

/// Run `f` on another thread and fail if it takes longer than `limit`
/// (for tests: the per-case time limit without the pass's watchdog).
pub fn within<T: Send + 'static>(limit: Duration, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    let h = std::thread::spawn(move || {
        let r = catch_unwind(AssertUnwindSafe(f));
        let _ = tx.send(());
        r
    });
    match rx.recv_timeout(limit) {
        Ok(()) => match h.join() {
            Ok(Ok(v)) => v,
            Ok(Err(p)) | Err(p) => std::panic::resume_unwind(p),
        },
        Err(_) => panic!("case still running after {limit:?}: a hang"),
    }
}

/// A panic hook for the passes: one line per panic (where and what), no
/// backtrace: the case's seed is the way back to it.
pub fn quiet_panics() {
    std::panic::set_hook(Box::new(|info| {
        let at = info
            .location()
            .map(|l| format!("{}:{}", l.file(), l.line()))
            .unwrap_or_default();
        eprintln!("fuzz: panic at {at}: {}", panic_message(info.payload()));
    }));
}

/// Settings of a pass of the seeded generator.
#[derive(Debug, Clone)]
pub struct Pass {
    /// The targets and the share of the time each gets (weights).
    pub targets: Vec<(Target, u32)>,
    /// First seed; worker `w` of `T` takes `seed + w`, `seed + w + T`, ...
    pub seed: u64,
    /// Wall-clock time for the whole pass.
    pub time: Duration,
    /// At most this many cases per target (`u64::MAX`: no limit).
    pub max_cases: u64,
    /// Worker threads.
    pub threads: usize,
    /// Per-case time limit (a hang beyond it stops the pass).
    pub case_limit: Duration,
    /// Where to write interesting cases (new feature bits) and findings.
    pub save: Option<std::path::PathBuf>,
}

/// What a pass found and did, per target.
#[derive(Debug, Clone, Default)]
pub struct Tally {
    /// Cases run.
    pub cases: u64,
    /// Calls made.
    pub calls: u64,
    /// Reconstructions (frame path).
    pub reconstructions: u64,
    /// Points matched and depths given in them.
    pub points: [u64; 2],
    /// Cases that broke an oracle: seed and message.
    pub findings: Vec<(u64, String)>,
    /// Seconds spent.
    pub seconds: f64,
    /// Slowest case, seconds, and its seed.
    pub slowest: (f64, u64),
    /// Feature bits seen.
    pub features: u128,
}

/// Most findings a target reports before its worker stops.
const MAX_FINDINGS: usize = 200;

/// Run a pass: each target in turn for its share of the time, on
/// `threads` workers, under a watchdog that ends the process (exit 3,
/// naming the case) when a case runs past the limit.
pub fn pass(p: &Pass) -> Vec<(Target, Tally)> {
    let total: u32 = p.targets.iter().map(|t| t.1).sum::<u32>().max(1);
    let mut out = Vec::new();
    for &(target, weight) in &p.targets {
        let time = p.time.mul_f64(f64::from(weight) / f64::from(total));
        out.push((target, pass_target(p, target, time)));
    }
    out
}

/// The watchdog's view of a worker: the seed it runs and since when
/// (milliseconds since the pass started; `u64::MAX` when idle).
struct Running {
    seed: AtomicU64,
    since_ms: AtomicU64,
}

fn pass_target(p: &Pass, target: Target, time: Duration) -> Tally {
    let start = Instant::now();
    let threads = p.threads.max(1);
    let running: Arc<Vec<Running>> = Arc::new(
        (0..threads)
            .map(|_| Running {
                seed: AtomicU64::new(0),
                since_ms: AtomicU64::new(u64::MAX),
            })
            .collect(),
    );
    let done = Arc::new(AtomicBool::new(false));
    let watchdog = {
        let (running, done, limit) = (running.clone(), done.clone(), p.case_limit);
        std::thread::spawn(move || {
            while !done.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(50));
                let now = start.elapsed().as_millis() as u64;
                for r in running.iter() {
                    let since = r.since_ms.load(Ordering::Relaxed);
                    if since != u64::MAX && now.saturating_sub(since) > limit.as_millis() as u64 {
                        let seed = r.seed.load(Ordering::Relaxed);
                        eprintln!(
                            "fuzz: HANG: target {} seed {seed} still running after {limit:?}; the case:\n{}",
                            target.name(),
                            target.describe(&mut Source::seeded(seed))
                        );
                        std::process::exit(3);
                    }
                }
            }
        })
    };
    let workers: Vec<_> = (0..threads)
        .map(|w| {
            let running = running.clone();
            let save = p.save.clone();
            let (base, max_cases) = (p.seed, p.max_cases);
            std::thread::spawn(move || {
                let mut t = Tally::default();
                let mut k = 0u64;
                let me = &running[w];
                while start.elapsed() < time && k * (threads as u64) < max_cases {
                    let seed = base.wrapping_add(w as u64).wrapping_add(k * threads as u64);
                    k += 1;
                    me.seed.store(seed, Ordering::Relaxed);
                    me.since_ms
                        .store(start.elapsed().as_millis() as u64, Ordering::Relaxed);
                    let t0 = Instant::now();
                    let r =
                        catch_unwind(AssertUnwindSafe(|| target.run(&mut Source::seeded(seed))));
                    me.since_ms.store(u64::MAX, Ordering::Relaxed);
                    let dt = t0.elapsed().as_secs_f64();
                    if dt > t.slowest.0 {
                        t.slowest = (dt, seed);
                    }
                    t.cases += 1;
                    match r {
                        Ok(o) => {
                            t.calls += o.calls;
                            t.reconstructions += o.reconstructions;
                            t.points[0] += o.points[0];
                            t.points[1] += o.points[1];
                            if o.features & !t.features != 0 {
                                t.features |= o.features;
                                if let Some(dir) = &save {
                                    save_case(dir, target, seed, "case");
                                }
                            }
                        }
                        Err(e) => {
                            let msg = panic_message(&*e);
                            eprintln!("fuzz: FINDING: target {} seed {seed}: {msg}", target.name());
                            if let Some(dir) = &save {
                                save_case(dir, target, seed, "finding");
                            }
                            t.findings.push((seed, msg));
                            if t.findings.len() >= MAX_FINDINGS {
                                break;
                            }
                        }
                    }
                }
                t
            })
        })
        .collect();
    let mut all = Tally::default();
    for h in workers {
        let t = h.join().unwrap_or_default();
        all.cases += t.cases;
        all.calls += t.calls;
        all.reconstructions += t.reconstructions;
        all.points[0] += t.points[0];
        all.points[1] += t.points[1];
        all.findings.extend(t.findings);
        all.features |= t.features;
        if t.slowest.0 > all.slowest.0 {
            all.slowest = t.slowest;
        }
    }
    done.store(true, Ordering::Relaxed);
    let _ = watchdog.join();
    all.seconds = start.elapsed().as_secs_f64();
    all
}

/// Write the recorded draws of seed `seed`'s case to
/// `dir/<target>/<kind>-<seed>`.
fn save_case(dir: &Path, target: Target, seed: u64, kind: &str) {
    let mut src = Source::seeded(seed).recording();
    // Generate only (a finding's run would panic again).
    let _ = target.describe(&mut src);
    let d = dir.join(target.name());
    let _ = std::fs::create_dir_all(&d);
    let _ = std::fs::write(d.join(format!("{kind}-{seed}")), src.recorded());
}

/// The files of a saved corpus folder, sorted by name.
pub fn corpus_files(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    v.retain(|p| p.is_file());
    v.sort();
    v
}
