//! Host-side support for testing roadstereo: the synthetic road generator
//! (independent `f64` geometry), scenario sets, a brute-force crossing
//! search, and helpers shared by the tests and the host tools.

pub mod scenarios;
pub mod synth;

use roadstereo::{CrossingSearch, Crossings, EpipolarLine, Frame, Pixel, Processor};

/// Capacity used by the host tests: one point per row of a 480-row image fits.
pub const N: usize = 512;
/// Boundaries per frame (left, right).
pub const B: usize = 2;

/// The reference matcher: every segment against the line.
#[derive(Debug, Default)]
pub struct BruteForce;

impl CrossingSearch for BruteForce {
    fn prepare(&mut self, _boundary: &[Pixel], _key: &roadstereo::epipolar::PencilKey) {}
    fn search(&mut self, line: &EpipolarLine, boundary: &[Pixel], out: &mut Crossings) {
        for j in 0..boundary.len().saturating_sub(1) {
            if let Some(c) = line.crossing(j, boundary[j], boundary[j + 1]) {
                if out.push(c).is_err() {
                    return;
                }
            }
        }
    }
}

/// Build a frame from pixel polylines (panics on invalid input: test helper).
pub fn frame(camera: roadstereo::Camera, boundaries: &[Vec<Pixel>]) -> Frame<N, B> {
    let mut f = Frame::new(camera);
    for b in boundaries {
        f.push_boundary(b).expect("valid synthetic boundary");
    }
    f
}

/// Run the two frames of a rendered scenario through a fresh processor.
pub fn reconstruct(
    r: &synth::Rendered,
    k: &synth::Intrinsics,
    quantised: bool,
    config: roadstereo::Config,
) -> Box<Processor<N, B>> {
    let cam = k.camera();
    let mut p = Box::new(Processor::<N, B>::new(config));
    let f1 = frame(cam, &synth::Rendered::pixels(&r.frame1, quantised));
    let f2 = frame(cam, &synth::Rendered::pixels(&r.frame2, quantised));
    let m = r.motion();
    assert!(matches!(p.process(&f1, None), Ok(roadstereo::Step::First)));
    p.process(&f2, Some(&m)).expect("processing succeeds");
    p
}
