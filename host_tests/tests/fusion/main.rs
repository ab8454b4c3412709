//! The key-frame fusion and the road map (issue 13) against ground truth
//! from the independent `f64` generator (`src/drives.rs`): containment over
//! seeded random drives, the narrowing with the number of partner frames,
//! wrong two-view matches caught, the map in the vehicle frame, and bad
//! inputs. One module a subject:
//!
//! * `containment`: containment over the seeded random drives (every detector variant, motion errors, the counting rule, a deadline's cut), and the wrong two-view matches caught.
//! * `narrowing`: the narrowing of the fused intervals with the number of partner frames.
//! * `retirement`: a retiring key frame's points entering the map over two steps: the same map as a whole retirement, the share, conflicts and rests.
//! * `map`: the road map against the truth in the vehicle frame: its points, samples, radius, capacity and depth codes; key-frame points in 3-D.
//! * `inputs`: bad inputs are typed errors that change nothing; range constraints from another sensor.
//! * `sight`: the sight check, and the limits of interval logic it is built for.
//! * `geometry`: road geometry (camera height, tilt, road width) from the fused map.

mod containment;
mod geometry;
mod inputs;
mod map;
mod narrowing;
mod retirement;
mod sight;

use host_tests::drives::{
    fig6_drive, run, tally, Drive, DriveFamily, DriveSpec, HostFusion, MotionNoise, Noise, Run,
    Tally,
};
use host_tests::synth::{self, Road, Scenario};
use host_tests::{scenarios, B, N};
use roadstereo::fusion::{
    ChainedMotion, FusedStatus, Fusion, FusionConfig, FusionError, KeyReason,
};
use roadstereo::{Config, Frame, Motion, Pixel, Status};

/// Frames per drive (the issue asks for at least 12).
const FRAMES: usize = 14;

/// Drives per family in the containment runs (8 families: 304 drives).
const PER_FAMILY: usize = 38;

/// The first `count` seeds of `family` whose drive sees both boundaries
/// in every frame, rendered; and the seeds skipped.
fn drives(family: DriveFamily, count: usize, frames: usize) -> (Vec<(u64, Drive)>, usize) {
    let (mut out, mut skipped) = (Vec::new(), 0);
    let mut seed = 0u64;
    while out.len() < count {
        match DriveSpec::new(family, seed, frames).render() {
            Some(d) => out.push((seed, d)),
            None => skipped += 1,
        }
        seed += 1;
    }
    (out, skipped)
}

fn pct(a: usize, b: usize) -> String {
    if b == 0 {
        "–".into()
    } else {
        format!("{:.2} %", 100.0 * a as f64 / b as f64)
    }
}

/// The motion into frame `j` of a drive whose motions from each frame to
/// the next are `motions` (none into the first).
fn given_into(motions: &[Motion], j: usize) -> Option<ChainedMotion> {
    let motion = *motions.get(j.checked_sub(1)?)?;
    Some(ChainedMotion {
        from: j as u32 - 1,
        motion,
    })
}
