//! Synthetic calibration runs (Appendix II B) with their own `f64`
//! geometry: a camera with the paper's calibrated values, random 3-D feature
//! points in front of it, known robot translations, flows quantised to the
//! pixel grid, optional wrong matches.

use crate::synth::Rng;
use roadstereo::calibration::{
    calibrate_jointly, calibrate_stepwise, focus_of_expansion, CalibrationError, Flow, Intrinsics,
    JointFit, MotionFlows,
};
use roadstereo::Pixel;

/// Capacity (flows per motion) of the calibration runs.
pub const CAP: usize = 512;

/// One synthetic calibration run: the flows of each motion (the first five
/// must be the paper's straight and diagonal ones), the step-by-step
/// result, and the joint fit started from it.
pub fn calibrate_run(
    cam: &TrueCamera,
    motions: &[[f64; 3]],
    n: usize,
    outliers: f64,
    seed: u64,
) -> Result<(Vec<Vec<Flow>>, Intrinsics, JointFit), CalibrationError> {
    let mut rng = Rng(seed);
    let sets: Vec<Vec<Flow>> = motions
        .iter()
        .map(|&t| flows(cam, t, n, outliers, &mut rng))
        .collect();
    let foes: Vec<Pixel> = sets
        .iter()
        .take(5)
        .map(|f| focus_of_expansion::<CAP>(f).map(|x| x.foe))
        .collect::<Result<_, _>>()?;
    let [straight, p, q, r, s] = foes[..] else {
        return Err(CalibrationError::TooFewFlows);
    };
    let stepwise = calibrate_stepwise(straight, [p, q, r, s])?;
    let joint = calibrate_jointly::<CAP>(&motion_flows(motions, &sets), &stepwise)?;
    Ok((sets, stepwise, joint))
}

/// Each motion's translation with its flows, as the joint fit takes them.
pub fn motion_flows<'a>(motions: &[[f64; 3]], sets: &'a [Vec<Flow>]) -> Vec<MotionFlows<'a>> {
    motions
        .iter()
        .zip(sets)
        .map(|(t, f)| MotionFlows {
            translation: t.map(|x| x as f32),
            flows: f,
        })
        .collect()
}

/// The true camera (the paper's values: c = (273.59, 233.96), r = 0.787,
/// γ = −1.26°, f_x = 614.5, f_y = 780.7, 512 × 480).
#[derive(Debug, Clone, Copy)]
pub struct TrueCamera {
    pub cx: f64,
    pub cy: f64,
    pub roll: f64,
    pub fx: f64,
    pub fy: f64,
    pub width: f64,
    pub height: f64,
}

impl Default for TrueCamera {
    fn default() -> Self {
        Self {
            cx: 273.59,
            cy: 233.96,
            roll: (-1.26f64).to_radians(),
            fx: 614.5,
            fy: 780.7,
            width: 512.0,
            height: 480.0,
        }
    }
}

impl TrueCamera {
    /// Robot-frame point → pixel (camera axes rolled by γ: P_c = R_zᵀ P).
    pub fn project(&self, p: [f64; 3]) -> Option<[f64; 2]> {
        let (s, c) = self.roll.sin_cos();
        let (x, y) = (c * p[0] + s * p[1], -s * p[0] + c * p[1]);
        if p[2] <= 0.1 {
            return None;
        }
        let uv = [self.cx + self.fx * x / p[2], self.cy + self.fy * y / p[2]];
        let inside =
            (0.0..=self.width - 1.0).contains(&uv[0]) && (0.0..=self.height - 1.0).contains(&uv[1]);
        inside.then_some(uv)
    }

    /// Pixel + depth → robot-frame point.
    pub fn unproject(&self, uv: [f64; 2], z: f64) -> [f64; 3] {
        let (x, y) = (
            (uv[0] - self.cx) / self.fx * z,
            (uv[1] - self.cy) / self.fy * z,
        );
        let (s, c) = self.roll.sin_cos();
        // P = R_z (x, y): inverse of the projection's rotation.
        [c * x - s * y, s * x + c * y, z]
    }

    /// The true FOE of a robot translation.
    pub fn foe(&self, t: [f64; 3]) -> [f64; 2] {
        let (s, c) = self.roll.sin_cos();
        let (x, y) = (c * t[0] + s * t[1], -s * t[0] + c * t[1]);
        [self.cx + self.fx * x / t[2], self.cy + self.fy * y / t[2]]
    }
}

/// The paper's motions: straight 4.0 units, then the diagonals
/// (+,+), (−,+), (−,−), (+,−) of 2.5 units (round the image).
pub fn paper_motions() -> Vec<[f64; 3]> {
    vec![
        [0.0, 0.0, 4.0],
        [2.5, 2.5, 2.5],
        [-2.5, 2.5, 2.5],
        [-2.5, -2.5, 2.5],
        [2.5, -2.5, 2.5],
    ]
}

/// `n` flows for robot translation `t`: feature points at depths 8–40
/// units seen in both frames, positions rounded to the pixel grid;
/// a fraction `outliers` of them replaced by random wrong matches.
pub fn flows(cam: &TrueCamera, t: [f64; 3], n: usize, outliers: f64, rng: &mut Rng) -> Vec<Flow> {
    let mut out = Vec::new();
    let mut tries = 0;
    while out.len() < n && tries < 100_000 {
        tries += 1;
        let uv = [
            rng.uniform(0.0, cam.width - 1.0),
            rng.uniform(0.0, cam.height - 1.0),
        ];
        let z = rng.uniform(8.0, 40.0);
        let p = cam.unproject(uv, z);
        let moved = [p[0] - t[0], p[1] - t[1], p[2] - t[2]];
        let Some(q) = cam.project(moved) else {
            continue;
        };
        let from = Pixel::new(uv[0].round() as f32, uv[1].round() as f32);
        let mut to = Pixel::new(q[0].round() as f32, q[1].round() as f32);
        if rng.chance(outliers) {
            to = Pixel::new(
                rng.uniform(0.0, cam.width - 1.0).round() as f32,
                rng.uniform(0.0, cam.height - 1.0).round() as f32,
            );
        }
        if from != to {
            out.push(Flow { from, to });
        }
    }
    out
}
