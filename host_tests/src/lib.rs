//! Host-side support for testing roadstereo: the synthetic road generator
//! (independent `f64` geometry), scenario sets, and helpers shared by the
//! tests and the host tools.

pub mod calib;
pub mod certify;
pub mod drive;
pub mod drives;
pub mod fuzz;
pub mod jsonl;
pub mod link;
pub mod scenarios;
pub mod synth;
pub mod wire_ref;

use roadstereo::{Frame, Pixel, Processor};

/// Capacity used by the host tests: one point per row of a 480-row image fits.
pub const N: usize = 512;
/// Boundaries per frame (left, right).
pub const B: usize = 2;

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

/// Everything the tests need to know about one reconstructed point, with
/// the ground truth computed by the synthetic road (not by the library).
#[derive(Debug, Clone, Copy)]
pub struct PointStat {
    pub boundary: usize,
    pub index: usize,
    pub status: roadstereo::Status,
    pub z: f64,
    pub z_near: f64,
    pub z_far: f64,
    /// True depth of the 3-D boundary point on this frame-1 row.
    pub z_true: f64,
    /// Disparity length, pixels: |p₂ − p₁'| with p₁' from the test's own
    /// rotation compensation.
    pub disparity: f64,
    /// Angle between the epipolar line and the true frame-2 boundary at
    /// the match, degrees.
    pub angle_deg: f64,
    /// The true correspondent is in the frame-2 data (Sec. 2, assumption 1).
    pub observed: bool,
}

impl PointStat {
    pub fn contained(&self) -> bool {
        self.z_near <= self.z_true && self.z_true <= self.z_far
    }
    pub fn rel_error(&self) -> f64 {
        ((self.z - self.z_true) / self.z_true).abs()
    }
}

/// Per-point statistics of a processed scenario.
pub fn point_stats(
    r: &synth::Rendered,
    k: &synth::Intrinsics,
    p: &Processor<N, B>,
) -> Vec<PointStat> {
    let mut out = Vec::new();
    for (bi, b) in p.structure().boundaries().iter().enumerate() {
        for (i, pr) in b.points().iter().enumerate() {
            let truth = r.frame1[bi][i];
            let (mut z, mut zn, mut zf) = (f64::NAN, f64::NAN, f64::NAN);
            if let (Some(d), Some(iv)) = (pr.depth(), pr.interval()) {
                z = f64::from(d);
                zn = f64::from(iv.z_near);
                zf = f64::from(iv.z_far);
            }
            let (mut disparity, mut angle_deg) = (f64::NAN, f64::NAN);
            if let Some(p2) = pr.pixel2() {
                let p1c = r.compensate(k, f64::from(pr.pixel1().u), f64::from(pr.pixel1().v));
                let d = [f64::from(p2.u) - p1c[0], f64::from(p2.v) - p1c[1]];
                disparity = d[0].hypot(d[1]);
                // True boundary tangent in frame 2 near the match row.
                let b2 = &r.frame2[bi];
                let kk = b2
                    .iter()
                    .enumerate()
                    .min_by(|a, b| {
                        (a.1.v - f64::from(p2.v))
                            .abs()
                            .total_cmp(&(b.1.v - f64::from(p2.v)).abs())
                    })
                    .map(|x| x.0)
                    .unwrap_or(0);
                let (a, c) = (kk.saturating_sub(1), (kk + 1).min(b2.len() - 1));
                let t = [b2[c].u - b2[a].u, b2[c].v - b2[a].v];
                let cr = (d[0] * t[1] - d[1] * t[0]).abs();
                let dt = (d[0] * t[0] + d[1] * t[1]).abs();
                angle_deg = cr.atan2(dt).to_degrees();
            }
            out.push(PointStat {
                boundary: bi,
                index: i,
                status: pr.status(),
                z,
                z_near: zn,
                z_far: zf,
                z_true: truth.camera[2],
                disparity,
                angle_deg,
                observed: r.correspondent_observed(bi, i),
            });
        }
    }
    out
}

/// Median of a slice (NaN-free).
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    v[v.len() / 2]
}

/// Least-squares slope of y on x.
pub fn slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}
