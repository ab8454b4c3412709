//! # roadstereo
//!
//! 3-D structure of road boundaries from motion stereo, with a guaranteed
//! error interval ("stick") on every point, after M. Asada, *3-D Road
//! Structure from Motion Stereo*, Center for Automation Research, 1987.
//!
//! `#![no_std]`, no allocator, no `unsafe`, single precision only; every
//! buffer has a compile-time capacity and nothing panics on any input.
//!
//! ```
//! use roadstereo::{Camera, Config, Frame, Motion, Pixel, Processor, Status, Step};
//!
//! // The paper's simulated camera: 512 x 480, f = 800 px.
//! let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480)?;
//! // 2 boundaries of up to 256 points (in a firmware: a `static`).
//! let mut processor = Processor::<256, 2>::new(Config::DEFAULT);
//!
//! // Frame 1: a road edge on the ground, to the left; no motion yet.
//! let mut f1 = Frame::new(cam);
//! f1.push_boundary(&[Pixel::new(100.0, 400.0), Pixel::new(150.0, 300.0)])?;
//! assert!(matches!(processor.process(&f1, None)?, Step::First));
//!
//! // Frame 2, after 0.4 units forward: a depth and a guaranteed stick.
//! let mut f2 = Frame::new(cam);
//! f2.push_boundary(&[Pixel::new(40.0, 470.0), Pixel::new(130.0, 300.0)])?;
//! let motion = Motion::new([0.0, 0.0, 0.4], [0.0; 3])?;
//! if let Step::Structure(s) = processor.process(&f2, Some(&motion))? {
//!     for r in s.boundaries()[0].points() {
//!         if let (Status::Ok, Some(stick)) = (r.status(), r.interval()) {
//!             assert!(stick.z_near <= stick.z_far);
//!         }
//!     }
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The README (in the repository) has the conventions, the guarantees and
//! their limits, running within a deadline (`Processor::process_within`),
//! the fusion of many frames and the figures behind every budget.
//!
//! The pipeline, one module per concept of the paper:
//! [`camera`] (intrinsics), [`motion`] (frame-to-frame motion and its
//! conventions), [`boundary`] (validated polylines and frames),
//! [`epipolar`] (rotation compensation and the FOE of a pair, Sec. 2),
//! [`depth`] (triangulation, eq. 2.3, and the stick, Sec. 4.1), and
//! [`processor`] (the per-frame driver and its output), and
//! [`calibration`] (intrinsics from foci of expansion, Appendix II B), and
//! [`analysis`] (the disparity analysis of Sec. 3, the tilt transform of
//! Appendix I), [`motion_error`] (Sec. 4.2 and 5) and [`geometry`] (camera
//! height, tilt and road width from the reconstruction, Sec. 4.2.1), and
//! [`fusion`] (the error ranges of many frames fused on a key frame's rays,
//! Sec. 5) with its [`map`] (the fused road in the current vehicle frame).
//!
//! [`wire`] is the camera front-end link's format and streaming decoder,
//! [`link`] its embedded-hal / embedded-io drivers.
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]
#![warn(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]
#![cfg_attr(
    test,
    allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)
)]
// `if !(x > 0.0)` is this crate's way of writing "unless x is a number
// above 0": a NaN fails the comparison and takes the error branch, which
// `x <= 0.0` would not. Each such test says so in a comment.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
pub mod analysis;
pub mod boundary;
mod buffer;
pub mod calibration;
pub mod camera;
mod config;
pub mod deadline;
pub mod depth;
pub mod epipolar;
mod fold;
pub mod fusion;
pub mod geometry;
pub mod link;
pub mod map;
mod matching;
mod math;
pub mod motion;
pub mod motion_error;
mod pencil;
pub mod processor;
mod search;
mod structure;
pub mod thin;
mod wedge;
pub mod wire;

/// The `heapless` crate this one's API takes (`RoadMap::samples` and
/// `geometry::samples` fill a `heapless::Vec`), so that a user need not
/// depend on the same version by hand.
pub use heapless;

pub use boundary::{Boundary, BoundaryError, Frame};
pub use camera::{Camera, CameraError, Pixel, IMAGE_MARGIN_PX};
pub use config::{Config, ConfigError};
pub use deadline::{Deadline, NoDeadline};
pub use depth::DepthInterval;
pub use epipolar::PairGeometry;
pub use math::{AngleError, MAX_ANGLE_RAD};
pub use motion::{Motion, MotionError};
pub use processor::Processor;
pub use structure::{
    BoundaryStructure, PointResult, ProcessError, Status, StatusCounts, Step, Structure,
};

// The README's Rust examples are compiled and run as doc tests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;

/// Unit tests' random numbers.
#[cfg(test)]
mod test_rng {
    /// A small deterministic generator (xorshift), values in `[0, 1)`.
    pub(crate) struct Rng(pub(crate) u32);
    impl Rng {
        pub(crate) fn next(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 17;
            self.0 ^= self.0 << 5;
            (self.0 >> 8) as f32 / (1u32 << 24) as f32
        }
    }
}
