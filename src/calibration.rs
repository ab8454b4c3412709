//! Intrinsic calibration from foci of expansion (paper, Appendix II B).
//!
//! The camera is moved by known translations without rotation. Each
//! motion's focus of expansion (FOE) is found from the flow of feature
//! points ([`focus_of_expansion`]); the FOEs give the image origin, the
//! aspect ratio, the roll angle and the focal lengths.
//!
//! # Model
//! Translations are given in the robot (arm) frame, `x` right, `y` down,
//! `z` forward. The camera's axes are those of the robot rolled by `γ` about
//! the optical axis (`+γ` clockwise seen from behind, as in
//! [`crate::motion`]): a robot translation `T` is `T_c = R_z(γ)ᵀ T` in camera
//! coordinates, and its FOE is (eq. A.1, with two focal lengths)
//!
//! `FOE = (c_x + f_x T_cx / T_cz, c_y + f_y T_cy / T_cz)`.
//!
//! The aspect ratio is `r = f_x / f_y` (the paper's `f_x = r f_y`).
//!
//! # Step by step (the paper's procedure)
//! 1. `c` is the FOE of the straight translation `(0, 0, t)`.
//! 2. With `d_k = FOE_k − c` for the four diagonal translations
//!    `(±t, ±t, t)`, `D⁻¹ d_k = R_zᵀ (±1, ±1)` (`D = diag(f_x, f_y)`), so
//!    adjacent `D⁻¹ d_k` are perpendicular:
//!    `d_Px d_Qx + r² d_Py d_Qy = 0` (the paper's scalar product, with `y`
//!    down here); `r²` is the least-squares solution over the four adjacent
//!    pairs.
//! 3. `γ` is the mean angle between `(d_kx, r d_ky)` and `(±1, ±1)`.
//! 4. `|D⁻¹ d_k| = √2` gives `f_y` (mean over the four), `f_x = r f_y`.
//!
//! # Jointly (beyond the paper)
//! [`calibrate_jointly`] fits `c_x, c_y, γ, f_x, f_y` to every flow of every
//! motion at once: each flow must point away from (or towards) its motion's
//! predicted FOE. Gauss–Newton on the point-to-line distances (pixels), started from
//! the step-by-step result, a bounded number of iterations; it reports the
//! RMS residual and the standard deviation of each parameter.
//!
//! # Inputs and results
//! Pixel coordinates (flow ends, FOEs) must be finite and within
//! ±[`MAX_COORD_PX`], translation components within ±1e6 units, the roll
//! within ±[`crate::MAX_ANGLE_RAD`] (reduced correctly below that);
//! anything else is a typed error. Every `Ok` result is finite: a result
//! that would overflow `f32` from such inputs is
//! [`CalibrationError::Overflow`].

use core::fmt;

use crate::camera::{Camera, CameraError, Pixel};
use crate::math::{
    cross, dot, fmax, fmin, reduce_angle, sin_cos_reduced, sqrt, sub, AngleError, MAX_TRANSLATION,
};
use crate::motion::{Motion, MotionError};

/// One feature point's flow between two frames of a pure translation.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Flow {
    /// Position in the first frame, pixels.
    pub from: Pixel,
    /// Position in the second frame, pixels.
    pub to: Pixel,
}

/// Why an FOE or a calibration could not be computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum CalibrationError {
    /// A coordinate or an intrinsic parameter is NaN or infinite.
    NotFinite,
    /// A pixel coordinate is beyond ±[`MAX_COORD_PX`], or a translation
    /// component beyond ±1e6 units.
    OutOfRange,
    /// Too few usable (non-zero) flows: fewer than two for an FOE; for a
    /// joint calibration, fewer than six in all among the motions with at
    /// least two (a motion with one usable flow adds nothing).
    TooFewFlows,
    /// More flows than the estimator's capacity `N`.
    TooManyFlows,
    /// The flows are (nearly) parallel: the FOE is at infinity.
    Parallel,
    /// A translation is NaN or infinite, or has no forward component
    /// (`t_z ≤ 0`).
    BadTranslation,
    /// The FOEs are inconsistent with the model (e.g. `r² ≤ 0`), or the
    /// joint fit's equations are singular or too close to it (fewer than
    /// three motions, translations on one line: [`MIN_JOINT_SPREAD`],
    /// [`MIN_JOINT_CONDITION`]) or its iterations diverged.
    Degenerate,
    /// A result would not be finite in `f32` (finite but extreme inputs).
    Overflow,
    /// The roll angle is rejected.
    Angle(AngleError),
    /// The result is not a valid camera.
    Camera(CameraError),
    /// The converted motion is not a valid pipeline motion.
    Motion(MotionError),
}

impl core::error::Error for CalibrationError {}

impl fmt::Display for CalibrationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotFinite => f.write_str("a coordinate is NaN or infinite"),
            Self::OutOfRange => f.write_str("a coordinate or translation is out of range"),
            Self::TooFewFlows => f.write_str("too few usable flows"),
            Self::TooManyFlows => f.write_str("more flows than the capacity"),
            Self::Parallel => f.write_str("flows are parallel: FOE at infinity"),
            Self::BadTranslation => f.write_str("translation without forward component"),
            Self::Degenerate => f.write_str("FOEs inconsistent with the camera model"),
            Self::Overflow => f.write_str("a result would not be finite"),
            Self::Angle(e) => write!(f, "roll rejected: {e}"),
            Self::Camera(e) => write!(f, "calibrated camera invalid: {e}"),
            Self::Motion(e) => write!(f, "converted motion invalid: {e}"),
        }
    }
}

/// Largest accepted magnitude of a pixel coordinate (flow ends, FOEs),
/// pixels. The largest valid image is 16 384 px wide, and an FOE of a
/// calibration motion lies about `f ≤ 1e5` px from the centre; this bound
/// keeps every square and product of the estimators far below `f32`
/// overflow.
pub const MAX_COORD_PX: f32 = 1.0e6;

/// A pixel coordinate is finite and within ±[`MAX_COORD_PX`].
fn check_pixel(p: Pixel) -> Result<(), CalibrationError> {
    if !(p.u.is_finite() && p.v.is_finite()) {
        return Err(CalibrationError::NotFinite);
    }
    if p.u.abs() > MAX_COORD_PX || p.v.abs() > MAX_COORD_PX {
        return Err(CalibrationError::OutOfRange);
    }
    Ok(())
}

/// A calibration translation: finite, within ±1e6 units, `t_z > 0`.
fn check_translation(t: [f32; 3]) -> Result<(), CalibrationError> {
    if t.iter().any(|x| !x.is_finite()) || t[2] <= 0.0 {
        return Err(CalibrationError::BadTranslation);
    }
    if t.iter().any(|x| x.abs() > MAX_TRANSLATION) {
        return Err(CalibrationError::OutOfRange);
    }
    Ok(())
}

/// At most `N` flows, each end a valid pixel coordinate ([`check_pixel`]).
fn check_flows<const N: usize>(flows: &[Flow]) -> Result<(), CalibrationError> {
    if flows.len() > N {
        return Err(CalibrationError::TooManyFlows);
    }
    for f in flows {
        check_pixel(f.from)?;
        check_pixel(f.to)?;
    }
    Ok(())
}

/// A focus of expansion fitted to flows.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FoeFit {
    /// The FOE, pixels.
    pub foe: Pixel,
    /// RMS distance of the FOE from the inlier flow lines, pixels (the
    /// paper's "variance of the intersections", as a spread).
    pub rms: f32,
    /// Flows kept.
    pub inliers: usize,
    /// Flows rejected as outliers.
    pub outliers: usize,
}

/// Outlier-rejection rounds of [`focus_of_expansion`].
pub const FOE_ROUNDS: usize = 8;

/// A flow agrees with an FOE when its end point lies within this many
/// pixels of the line from the FOE through its start (quantisation of both
/// end points to the pixel grid moves it by up to about one pixel).
pub const FLOW_TOLERANCE_PX: f32 = 2.0;

/// How far (pixels) the end of flow `f` lies from the line through `foe`
/// and the start of `f`: the flow's own misalignment, whose noise does not
/// grow with the distance to the FOE (unlike the FOE's distance from the
/// flow line).
fn misalignment(f: &Flow, foe: [f32; 2]) -> f32 {
    let d = sub(f.to.arr(), f.from.arr());
    let e = sub(foe, f.from.arr());
    let le = sqrt(dot(e, e));
    if le <= 0.0 {
        return 0.0;
    }
    cross(d, e).abs() / le
}

/// Weighted least-squares FOE: minimises `Σ (d_i × (F − p_i))² / |F₀ − p_i|²`
/// over the kept flows (the misalignments at the current estimate `F₀`).
fn refine(flows: &[Flow], keep: &[bool], f0: [f32; 2]) -> Option<[f32; 2]> {
    let o = f0;
    let (mut a11, mut a12, mut a22, mut b1, mut b2, mut n) =
        (0.0f32, 0.0f32, 0.0f32, 0.0f32, 0.0f32, 0usize);
    for (f, &k) in flows.iter().zip(keep) {
        if !k {
            continue;
        }
        let d = sub(f.to.arr(), f.from.arr());
        let e = sub(o, f.from.arr());
        let w2 = dot(e, e);
        if w2 <= 0.0 || dot(d, d) <= 0.0 {
            continue;
        }
        // Residual cross(d, F − p) = nrm · (F − o) + cross(d, o − p), nrm = (−d_y, d_x).
        let w = 1.0 / w2;
        let nrm = [-d[1], d[0]];
        let r0 = cross(d, e);
        a11 += w * nrm[0] * nrm[0];
        a12 += w * nrm[0] * nrm[1];
        a22 += w * nrm[1] * nrm[1];
        b1 -= w * nrm[0] * r0;
        b2 -= w * nrm[1] * r0;
        n += 1;
    }
    let det = a11 * a22 - a12 * a12;
    let tr = a11 + a22;
    if n < 2 || det.is_nan() || det <= 1.0e-7 * tr * tr {
        return None;
    }
    let x = (a22 * b1 - a12 * b2) / det;
    let y = (a11 * b2 - a12 * b1) / det;
    let f = [o[0] + x, o[1] + y];
    (f[0].is_finite() && f[1].is_finite()).then_some(f)
}

/// Intersection of the lines of flows `a` and `b`, if not near-parallel.
fn pair(a: &Flow, b: &Flow) -> Option<[f32; 2]> {
    let (da, db) = (sub(a.to.arr(), a.from.arr()), sub(b.to.arr(), b.from.arr()));
    let den = cross(da, db);
    let scale = sqrt(dot(da, da) * dot(db, db));
    if den.abs() <= 1.0e-3 * scale {
        return None;
    }
    let t = cross(sub(b.from.arr(), a.from.arr()), db) / den;
    let p = [a.from.u + t * da[0], a.from.v + t * da[1]];
    (p[0].is_finite() && p[1].is_finite()).then_some(p)
}

/// The focus of expansion of one pure translation from the flows of its
/// feature points, robust to wrong matches:
///
/// 1. candidates: the intersections of flow `i` with flow `i + n/2` and
///    `i + n/3`; the candidate with which most flows agree (their end
///    lies within [`FLOW_TOLERANCE_PX`] of the line from the candidate
///    through their start) is the start;
/// 2. up to [`FOE_ROUNDS`] rounds: keep the flows whose misalignment is at
///    most `max(3 × median, FLOW_TOLERANCE_PX)`, and re-fit by weighted
///    least squares on the misalignments.
///
/// Zero-length flows are ignored. `N` is the capacity. Every flow end must
/// be finite and within ±[`MAX_COORD_PX`] (`NotFinite`, `OutOfRange`);
/// [`CalibrationError::Overflow`] if the FOE or its spread would not be
/// finite. Work `O(n²)` for `n ≤ N` flows (a calibration, not a per-frame
/// task).
///
/// ```
/// use roadstereo::calibration::{focus_of_expansion, Flow};
/// use roadstereo::Pixel;
/// // Points moving away from (300, 200).
/// let flows: Vec<Flow> = [(100.0, 100.0), (400.0, 50.0), (350.0, 400.0), (50.0, 300.0)]
///     .iter()
///     .map(|&(u, v)| Flow {
///         from: Pixel::new(u, v),
///         to: Pixel::new(300.0 + 1.2 * (u - 300.0), 200.0 + 1.2 * (v - 200.0)),
///     })
///     .collect();
/// let fit = focus_of_expansion::<64>(&flows).unwrap();
/// assert!((fit.foe.u - 300.0).abs() < 0.01 && (fit.foe.v - 200.0).abs() < 0.01);
/// ```
pub fn focus_of_expansion<const N: usize>(flows: &[Flow]) -> Result<FoeFit, CalibrationError> {
    // 1. Validate the flows.
    check_flows::<N>(flows)?;
    // 2. The usable flows: those that move.
    let (usable, count) = usable_flows::<N>(flows);
    if count < 2 {
        return Err(CalibrationError::TooFewFlows);
    }
    // 3. A robust start: the best-supported pairwise intersection.
    let start = best_supported_intersection(flows, &usable).ok_or(CalibrationError::Parallel)?;
    // 4. Reject the outliers and re-fit, in at most FOE_ROUNDS rounds.
    let (foe, keep) = reject_and_refit::<N>(flows, &usable, start)?;
    // 5. The spread of the inliers about the FOE.
    foe_fit(flows, &keep, foe, count)
}

/// Step 2 of [`focus_of_expansion`]: the mask of the flows that move, and
/// their count.
fn usable_flows<const N: usize>(flows: &[Flow]) -> ([bool; N], usize) {
    let mut usable = [false; N];
    let mut count = 0;
    for (k, f) in usable.iter_mut().zip(flows) {
        *k = f.from != f.to;
        count += usize::from(*k);
    }
    (usable, count)
}

/// Step 3 of [`focus_of_expansion`]: among the intersections of flow `i`
/// with flow `i + n/2` and with flow `i + n/3`, the one most usable flows
/// agree with (their end within [`FLOW_TOLERANCE_PX`] of the line from it
/// through their start). `None` if every pair is (nearly) parallel.
///
/// Work: `2n` candidates, each checked against the `n` flows.
fn best_supported_intersection(flows: &[Flow], usable: &[bool]) -> Option<[f32; 2]> {
    let n = flows.len();
    let mut best: Option<([f32; 2], usize)> = None;
    for step in [n / 2, n / 3] {
        for (i, a) in flows.iter().enumerate() {
            let Some(b) = flows.get((i + step.max(1)) % n) else {
                continue;
            };
            if a.from == a.to || b.from == b.to {
                continue;
            }
            let Some(p) = pair(a, b) else {
                continue;
            };
            let support = flows
                .iter()
                .zip(usable.iter())
                .filter(|(f, &k)| k && misalignment(f, p) <= FLOW_TOLERANCE_PX)
                .count();
            if best.is_none_or(|(_, s)| support > s) {
                best = Some((p, support));
            }
        }
    }
    best.map(|(p, _)| p)
}

/// Step 4 of [`focus_of_expansion`]: up to [`FOE_ROUNDS`] rounds of
/// keeping the usable flows whose misalignment is at most
/// `max(3 × median, FLOW_TOLERANCE_PX)` (the median over the flows within
/// `3 × FLOW_TOLERANCE_PX`, if any) and re-fitting by weighted least
/// squares; stops early when the FOE moves less than 1e-3 px. The FOE and
/// the flows kept.
fn reject_and_refit<const N: usize>(
    flows: &[Flow],
    usable: &[bool; N],
    start: [f32; 2],
) -> Result<([f32; 2], [bool; N]), CalibrationError> {
    let mut foe = start;
    let mut keep = *usable;
    let mut dist = [0.0f32; N];
    for _ in 0..FOE_ROUNDS {
        let mut m = 0usize;
        for (((d, k), f), &u) in dist
            .iter_mut()
            .zip(keep.iter_mut())
            .zip(flows)
            .zip(usable.iter())
        {
            *k = u;
            if u {
                *d = misalignment(f, foe);
                m += 1;
            }
        }
        // The median over the agreeing flows sets the scale of the noise.
        let mut agree = [false; N];
        for ((a, &d), &u) in agree.iter_mut().zip(dist.iter()).zip(usable.iter()) {
            *a = u && d <= 3.0 * FLOW_TOLERANCE_PX;
        }
        let ma = agree.iter().filter(|&&a| a).count();
        let median = if ma > 0 {
            median_of_kept(&dist, &agree, ma)
        } else {
            median_of_kept(&dist, &keep, m)
        };
        let limit = fmax(3.0 * median, FLOW_TOLERANCE_PX);
        for (k, &d) in keep.iter_mut().zip(dist.iter()) {
            if *k && d > limit {
                *k = false;
            }
        }
        let Some(next) = refine(flows, &keep, foe) else {
            return Err(CalibrationError::Parallel);
        };
        let moved = fmax((next[0] - foe[0]).abs(), (next[1] - foe[1]).abs());
        foe = next;
        if moved < 1.0e-3 {
            break;
        }
    }
    Ok((foe, keep))
}

/// Step 5 of [`focus_of_expansion`]: the RMS distance of the FOE from the
/// kept flows' lines, and the counts; [`CalibrationError::Overflow`] if
/// the FOE or the spread is not finite.
fn foe_fit(
    flows: &[Flow],
    keep: &[bool],
    foe: [f32; 2],
    usable: usize,
) -> Result<FoeFit, CalibrationError> {
    let mut ss = 0.0f32;
    let mut inliers = 0usize;
    for (f, &k) in flows.iter().zip(keep.iter()) {
        if k {
            let d = distance(f, foe);
            ss += d * d;
            inliers += 1;
        }
    }
    if inliers < 2 {
        return Err(CalibrationError::TooFewFlows);
    }
    // Checked before the square root, which maps NaN to 0.
    if !(foe[0].is_finite() && foe[1].is_finite() && ss.is_finite()) {
        return Err(CalibrationError::Overflow);
    }
    let rms = sqrt(ss / inliers as f32);
    Ok(FoeFit {
        foe: Pixel::new(foe[0], foe[1]),
        rms,
        inliers,
        outliers: usable - inliers,
    })
}

/// Distance of `p` from the line of flow `f`, pixels.
fn distance(f: &Flow, p: [f32; 2]) -> f32 {
    let d = sub(f.to.arr(), f.from.arr());
    let l2 = dot(d, d);
    if l2 <= 0.0 {
        return f32::INFINITY;
    }
    cross(d, sub(p, f.from.arr())).abs() / sqrt(l2)
}

/// The median of the kept entries (the lower one for an even count), by
/// counting: `O(n²)` for the `n ≤ N` flows of one calibration motion.
fn median_of_kept(v: &[f32], keep: &[bool], m: usize) -> f32 {
    let want = m.saturating_sub(1) / 2;
    for (x, &k) in v.iter().zip(keep) {
        if !k {
            continue;
        }
        let (mut below, mut equal) = (0usize, 0usize);
        for (y, &ky) in v.iter().zip(keep) {
            if ky {
                if y < x {
                    below += 1;
                } else if y == x {
                    equal += 1;
                }
            }
        }
        if below <= want && want < below + equal {
            return *x;
        }
    }
    0.0
}

/// Intrinsic parameters recovered by a calibration.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Intrinsics {
    /// Image origin (principal point), pixels.
    pub cx: f32,
    /// Image origin row, pixels.
    pub cy: f32,
    /// Roll of the camera axes about the optical axis relative to the robot
    /// axes, radians (`+` clockwise seen from behind).
    pub roll: f32,
    /// Horizontal focal length, pixels.
    pub fx: f32,
    /// Vertical focal length, pixels.
    pub fy: f32,
}

impl Intrinsics {
    /// Every parameter finite and the roll within ±[`crate::MAX_ANGLE_RAD`]:
    /// the sine and cosine of the roll.
    fn check(&self) -> Result<(f32, f32), CalibrationError> {
        if ![self.cx, self.cy, self.roll, self.fx, self.fy]
            .iter()
            .all(|x| x.is_finite())
        {
            return Err(CalibrationError::NotFinite);
        }
        sin_cos_reduced(self.roll).map_err(CalibrationError::Angle)
    }

    /// Aspect ratio `r = f_x / f_y`: [`CalibrationError::Degenerate`] unless
    /// both focal lengths are positive, [`CalibrationError::Overflow`] if
    /// the ratio is not finite and positive (it overflows, or underflows
    /// to 0).
    ///
    /// ```
    /// use roadstereo::calibration::{CalibrationError, Intrinsics};
    /// let k = Intrinsics { cx: 256.0, cy: 240.0, roll: 0.0, fx: 600.0, fy: 800.0 };
    /// assert_eq!(k.aspect(), Ok(0.75));
    /// assert_eq!(Intrinsics { fy: 0.0, ..k }.aspect(), Err(CalibrationError::Degenerate));
    /// ```
    pub fn aspect(&self) -> Result<f32, CalibrationError> {
        if !(self.fx.is_finite() && self.fy.is_finite()) {
            return Err(CalibrationError::NotFinite);
        }
        if !(self.fx > 0.0 && self.fy > 0.0) {
            return Err(CalibrationError::Degenerate);
        }
        let r = self.fx / self.fy;
        (r.is_finite() && r > 0.0)
            .then_some(r)
            .ok_or(CalibrationError::Overflow)
    }

    /// The FOE this camera predicts for robot translation `t` (finite,
    /// within ±1e6 units, `t_z > 0`). The roll may be any angle within
    /// ±[`crate::MAX_ANGLE_RAD`]; [`CalibrationError::Overflow`] if the FOE
    /// is not finite (`t_z` tiny against `t_x`, `t_y`).
    ///
    /// ```
    /// use roadstereo::calibration::{CalibrationError, Intrinsics};
    /// let k = Intrinsics { cx: 256.0, cy: 240.0, roll: 0.0, fx: 600.0, fy: 800.0 };
    /// let p = k.predicted_foe([1.0, 0.5, 2.0])?;
    /// assert_eq!((p.u, p.v), (556.0, 440.0));
    /// assert_eq!(k.predicted_foe([1.0, 0.0, 0.0]), Err(CalibrationError::BadTranslation));
    /// # Ok::<(), CalibrationError>(())
    /// ```
    pub fn predicted_foe(&self, t: [f32; 3]) -> Result<Pixel, CalibrationError> {
        let (s, c) = self.check()?;
        check_translation(t)?;
        // R_z(γ)ᵀ (x, y): rotate the robot translation into camera axes.
        let (x, y) = (c * t[0] + s * t[1], -s * t[0] + c * t[1]);
        let foe = Pixel::new(self.cx + self.fx * x / t[2], self.cy + self.fy * y / t[2]);
        if !(foe.u.is_finite() && foe.v.is_finite()) {
            return Err(CalibrationError::Overflow);
        }
        Ok(foe)
    }

    /// The camera model of the pipeline for an image of `width × height`
    /// (validated by [`Camera::new`]).
    pub fn camera(&self, width: u16, height: u16) -> Result<Camera, CalibrationError> {
        Camera::new(self.fx, self.fy, self.cx, self.cy, width, height)
            .map_err(CalibrationError::Camera)
    }

    /// A robot-frame motion (translation and rotation in the robot's axes,
    /// the conventions of [`crate::motion`]) expressed in the rolled camera
    /// axes, as the pipeline wants it: `T_c = R_zᵀ T`, `R_c = R_zᵀ R R_z`.
    /// The roll may be any angle within ±[`crate::MAX_ANGLE_RAD`]; the
    /// result is validated by [`Motion::new`] ([`CalibrationError::Motion`]).
    pub fn camera_motion(&self, robot: &Motion) -> Result<Motion, CalibrationError> {
        let (s, c) = self.check()?;
        let rz = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        let rzt = crate::math::mat3_transpose(&rz);
        let t = crate::math::mat3_vec(&rzt, robot.translation());
        let r = crate::math::mat3_mul(&rzt, &crate::math::mat3_mul(&robot.rotation_matrix(), &rz));
        // Angles of R = R_y(β) R_x(α) R_z(γ): α = asin(−r12), β = atan2(r02, r22),
        // γ = atan2(r10, r11).
        let [[_, _, r02], [r10, r11, r12], [_, _, r22]] = r;
        let alpha = crate::math::asin(-r12);
        let beta = crate::math::atan2(r02, r22);
        let gamma = crate::math::atan2(r10, r11);
        Motion::new(t, [alpha, beta, gamma]).map_err(CalibrationError::Motion)
    }
}

/// The paper's step-by-step procedure (Appendix II B (a), (b)).
///
/// `straight`: FOE of the translation `(0, 0, t)`; `diagonal`: FOEs of the
/// translations `(+t, +t, t)`, `(−t, +t, t)`, `(−t, −t, t)`, `(+t, −t, t)`
/// (in that order: round the image, so neighbours are adjacent). Each
/// within ±[`MAX_COORD_PX`]; [`CalibrationError::Overflow`] if a result
/// would not be finite; [`CalibrationError::Degenerate`] if no `r² > 0`
/// fits, if the rolls the four FOEs give disagree (their mean turn
/// shorter than half a unit: e.g. the four in mirrored order, which no
/// roll of the model gives), or if the fit is ill-conditioned: the roll
/// within about 2.9° of 45° + k·90° ([`MIN_STEPWISE_CONDITION`]), where
/// the diagonal FOEs lie near the image axes and the perpendicularity
/// test cannot tell the aspect ratio. Elsewhere FOE errors of `δ` px
/// along the diagonals move `r² = (f_x/f_y)²` by about `√2 δ (1/f_x +
/// 1/f_y)/|cos 2γ|` of itself (`d_x`'s error relative to `f_x`, `d_y`'s
/// to `f_y`; with square pixels `4 δ / (L |cos 2γ|)`, `L` the diagonal
/// FOEs' distance from the straight one: at the limit, `δ = 0.5` and `L =
/// 1 000`, 2 %), and errors of length `δ` in any direction by at most
/// `√2` times that, `2 δ (1/f_x + 1/f_y)/|cos 2γ|`. Measured for aspects
/// from 1/10 to 10 (host test `stepwise_sensitivity_for_any_aspect`):
/// every sign pattern along the diagonals within 1.002 times the first
/// form, errors in eight directions each within 0.92 times the second.
/// (A square-pixel form of these bounds falls 3.9 times short at `f =
/// (100, 1 000)`, an adversarial review found.)
pub fn calibrate_stepwise(
    straight: Pixel,
    diagonal: [Pixel; 4],
) -> Result<Intrinsics, CalibrationError> {
    check_pixel(straight)?;
    for p in diagonal {
        check_pixel(p)?;
    }
    let c = straight.arr();
    let d = diagonal.map(|p| sub(p.arr(), c));
    // r² from the four adjacent pairs: a + r² b = 0 in least squares.
    let (mut ab, mut bb) = (0.0f32, 0.0f32);
    for k in 0..4 {
        let (p, q) = (
            d.get(k).copied().unwrap_or_default(),
            d.get((k + 1) % 4).copied().unwrap_or_default(),
        );
        let (a, b) = (p[0] * q[0], p[1] * q[1]);
        ab += a * b;
        bb += b * b;
    }
    if bb.is_nan() || bb <= 0.0 {
        return Err(CalibrationError::Degenerate);
    }
    let r2 = -ab / bb;
    if !r2.is_finite() || r2 <= 0.0 {
        return Err(CalibrationError::Degenerate);
    }
    let r = sqrt(r2);
    // The fit's conditioning: in the corrected offsets `e = (d_x, r d_y)`
    // adjacent FOEs are perpendicular, `|b| r² = |e_p| |e_q| |cos 2γ| / 2`
    // at the roll `γ`, so the mean of `r² |b| / (|e_p| |e_q|)` is `|cos 2γ|
    // / 2`; an FOE error of `δ` px moves `r²` by about `4 δ / (L |cos
    // 2γ|)` of itself (`L` the offsets' length), unbounded towards rolls of
    // 45° + k·90°, where the diagonal FOEs lie on the image axes and every
    // product is near 0. Below [`MIN_STEPWISE_CONDITION`]: `Degenerate`.
    // (Until an adversarial review only the exact roll was, and 44.9° with
    // FOEs on the pixel grid gave f_x 545, f_y 890 for 600, 800.)
    let mut cond = 0.0f32;
    for k in 0..4 {
        let (p, q) = (
            d.get(k).copied().unwrap_or_default(),
            d.get((k + 1) % 4).copied().unwrap_or_default(),
        );
        let (ep, eq) = ([p[0], r * p[1]], [q[0], r * q[1]]);
        let den = sqrt(dot(ep, ep)) * sqrt(dot(eq, eq));
        // (A NaN fails.)
        if !(den > 0.0) {
            return Err(CalibrationError::Degenerate);
        }
        cond += (r2 * p[1] * q[1]).abs() / den;
    }
    if !(cond * 0.25 >= MIN_STEPWISE_CONDITION) {
        return Err(CalibrationError::Degenerate);
    }
    let signs = [[1.0f32, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]];
    // Roll: e_k = (d_x, r d_y) ∝ R_zᵀ s_k, i.e. e_k is s_k turned by −γ.
    let (mut sin_sum, mut cos_sum, mut fy_sum) = (0.0f32, 0.0f32, 0.0f32);
    for (dk, s) in d.iter().zip(signs.iter()) {
        let e = [dk[0], r * dk[1]];
        // angle(e) − angle(s) = −γ: accumulate the unit rotation s → e.
        let le = sqrt(dot(e, e));
        if le.is_nan() || le <= 0.0 {
            return Err(CalibrationError::Degenerate);
        }
        let ls = core::f32::consts::SQRT_2;
        cos_sum += dot(*s, e) / (le * ls);
        sin_sum += cross(*s, e) / (le * ls);
        // |D⁻¹ d| = √2 with D = f_y diag(r, 1): f_y = |(d_x / r, d_y)| / √2.
        fy_sum += sqrt(dk[0] * dk[0] / r2 + dk[1] * dk[1]) / ls;
    }
    // The four turns agree for FOEs the model can give (exactly, without
    // noise: their sum is 4 long). Four that cancel (the diagonal FOEs in
    // mirrored order, a reflection no roll gives) left the roll to
    // `atan2(0, 0)` until an adversarial review: their mean is required
    // to be at least half a unit long (each turn within 60° of it would
    // do).
    if !(sqrt(sin_sum * sin_sum + cos_sum * cos_sum) >= 2.0) {
        return Err(CalibrationError::Degenerate);
    }
    let roll = -crate::math::atan2(sin_sum, cos_sum);
    let fy = fy_sum / 4.0;
    let k = Intrinsics {
        cx: c[0],
        cy: c[1],
        roll,
        fx: r * fy,
        fy,
    };
    if ![roll, k.fx, fy].iter().all(|x| x.is_finite()) {
        return Err(CalibrationError::Overflow);
    }
    Ok(k)
}

/// The flows of one calibration motion and its robot translation.
#[derive(Debug, Clone, Copy)]
pub struct MotionFlows<'a> {
    /// Robot translation `(t_x, t_y, t_z)`, `t_z > 0`.
    pub translation: [f32; 3],
    /// The flows observed for it.
    pub flows: &'a [Flow],
}

/// Quality figures of a joint calibration.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct JointFit {
    /// The parameters.
    pub intrinsics: Intrinsics,
    /// RMS misalignment of the inlier flows, pixels.
    pub rms: f32,
    /// Standard deviations of `c_x, c_y` (px), `γ` (rad), `f_x, f_y` (px).
    pub sigma: [f32; 5],
    /// Flows used (inliers of the per-motion FOE fits).
    pub flows: usize,
    /// Gauss–Newton iterations run.
    pub iterations: usize,
}

/// The least conditioning [`calibrate_stepwise`] accepts: the mean, over
/// the four adjacent pairs of diagonal FOEs, of `|cos 2γ| / 2` at the roll
/// `γ` (exactly, for FOEs the model gives). 0.05: rolls at least 2.87°
/// from 45° + k·90°.
pub const MIN_STEPWISE_CONDITION: f32 = 0.05;

/// The least spread of the motions' translations [`calibrate_jointly`]
/// accepts: `4 det C / (tr C)²` of the covariance `C` of their points
/// `(t_x, t_y)/t_z`, about `4 λ_min/λ_max`, 0 where they lie on one line
/// (or are fewer than three), 1 where they spread alike in every
/// direction (the paper's five motions); unchanged by turning, shifting
/// or scaling the points. The
/// model's FOE `(c_x + f_x x', c_y + f_y y')`, `(x', y')` the point turned
/// by the roll, is affine in the point, so points on one line determine
/// four of the five parameters at most, and fewer than three motions
/// likewise (an adversary's find: two motions, or five on a line, gave
/// `Ok` results up to 109 px off). Measured with this measure: at most
/// 4.7·10⁻¹⁰ on such sets, at least 0.548 over 2 730 random cameras with
/// motions in four directions, 1.0 on the paper's;
/// `10⁻⁴` refuses too sets whose spread across their line is under about
/// half a per cent of the spread along it (`λ_min/λ_max < 2.5·10⁻⁵`: three
/// points whose triangle's height is under 0.43 % of its base, `q ≈ 5.3
/// (h/L)²`), where the fit is poorly determined anyway.
pub const MIN_JOINT_SPREAD: f32 = 1.0e-4;

/// The least conditioning of the joint fit's normal equations
/// [`calibrate_jointly`] accepts: their matrix's smallest Cholesky pivot
/// scaled to a unit diagonal, which is at least the matrix's smallest
/// eigenvalue: below it the flows leave a combination of the parameters
/// undetermined (a motion whose flows all lie on one line through its
/// FOE fixes that FOE in one direction only, which the translations'
/// spread cannot see) and the `f32` sums cannot tell it from singular.
/// (A pivot above it does not bound the condition number.) The sums are
/// compensated (Kahan), so their rounding does not grow with the flows:
/// measured at most 7.1·10⁻⁷ where the fit is singular with 50 flows a
/// motion and 0 with 12 000 (a review's case; 1.0·10⁻⁵ before the
/// compensation), at least 2.3·10⁻³ on the paper's set-up with 10 % wrong
/// matches and 6.6·10⁻⁵ over 2 730 random cameras (images up to 16 384
/// px, focal lengths to 10⁵ px, aspect ratios 0.1–10). A fit refused here
/// is [`CalibrationError::Degenerate`].
pub const MIN_JOINT_CONDITION: f32 = 1.0e-5;

/// Gauss–Newton iterations of [`calibrate_jointly`] at most.
pub const JOINT_ITERATIONS: usize = 10;

/// Joint calibration from every flow of every motion (see the module docs),
/// started from `start`: minimises the misalignments of all flows (the
/// distance of each flow's end from the line from its motion's predicted
/// FOE through its start). A flow is used when its misalignment is at most
/// `max(3 × median, FLOW_TOLERANCE_PX)` (the rule of
/// [`focus_of_expansion`]), re-decided at each iteration. `N`: capacity per
/// motion.
///
/// Input: translations as for [`Intrinsics::predicted_foe`], flows as for
/// [`focus_of_expansion`], `start` finite with its roll within
/// ±[`crate::MAX_ANGLE_RAD`]. The result's roll is in `[−π, π]` and its
/// focal lengths are positive (a fit with both negative is the same camera,
/// given with them positive and the roll turned by π; one not positive is
/// [`CalibrationError::Degenerate`]); every number of the result is finite
/// ([`CalibrationError::Overflow`] otherwise). A fit the motions cannot
/// determine is [`CalibrationError::Degenerate`] whatever its residuals:
/// fewer than three motions with two usable flows, their translations'
/// points `(t_x, t_y)/t_z` on one line or nearly (their spread across it
/// under about half a per cent of that along it)
/// ([`MIN_JOINT_SPREAD`]), or normal equations too close to singular for
/// `f32` to tell ([`MIN_JOINT_CONDITION`]; e.g. motions whose flows each
/// lie on one line through their FOE). The standard deviations are the linearised
/// ones at the result: with wrong matches among the flows they can
/// understate the error (module docs). Work: at most `JOINT_ITERATIONS + 1` passes over the flows,
/// each `O(n²)` per motion of `n ≤ N` flows (the median of the masks).
pub fn calibrate_jointly<const N: usize>(
    motions: &[MotionFlows<'_>],
    start: &Intrinsics,
) -> Result<JointFit, CalibrationError> {
    // 1. Validate the input.
    for m in motions {
        check_translation(m.translation)?;
        check_flows::<N>(m.flows)?;
    }
    start.check()?;
    // 2. Gauss–Newton steps from the start (its roll in [−π, π], where
    //    f32 resolves it finely), the inlier masks from the start model
    //    first and from the current one afterwards.
    let start = Intrinsics {
        roll: roll_in_half_turn(start.roll).map_err(CalibrationError::Angle)?,
        ..*start
    };
    let mut p = Params::of(&start);
    let mut masks = start;
    let mut iterations = 0;
    for _ in 0..JOINT_ITERATIONS {
        let eq = Normal::accumulate::<N>(motions, &p.intrinsics(), &masks)?;
        let step = solve5(eq.jtj, eq.jtr).ok_or(CalibrationError::Degenerate)?;
        let converged = p.apply(&step)?;
        iterations += 1;
        masks = p.intrinsics();
        if converged {
            break;
        }
    }
    // 3. The residuals and standard deviations at the result.
    let eq = Normal::accumulate::<N>(motions, &p.intrinsics(), &masks)?;
    joint_fit(&p, &eq, iterations)
}

/// `roll` as the equivalent angle in `[−π, π]` (itself, the same bits, if
/// it is there already).
fn roll_in_half_turn(roll: f32) -> Result<f32, AngleError> {
    if roll.abs() <= core::f32::consts::PI {
        return Ok(roll);
    }
    reduce_angle(roll)
}

/// The parameters of [`calibrate_jointly`], scaled to similar sizes:
/// `c` (px), roll (mrad), `f` (px).
struct Params([f32; 5]);

impl Params {
    fn of(k: &Intrinsics) -> Self {
        Self([k.cx, k.cy, k.roll * 1000.0, k.fx, k.fy])
    }

    fn intrinsics(&self) -> Intrinsics {
        let p = &self.0;
        Intrinsics {
            cx: p[0],
            cy: p[1],
            roll: p[2] * 0.001,
            fx: p[3],
            fy: p[4],
        }
    }

    /// `p ← p − step`: whether the step was small (converged);
    /// [`CalibrationError::Degenerate`] if a parameter is no longer finite.
    fn apply(&mut self, step: &[f32; 5]) -> Result<bool, CalibrationError> {
        let mut big = false;
        for (pi, si) in self.0.iter_mut().zip(step.iter()) {
            *pi -= si;
            big |= si.abs() > 1.0e-4 * fmax(pi.abs(), 1.0);
        }
        if self.0.iter().any(|x| !x.is_finite()) {
            return Err(CalibrationError::Degenerate);
        }
        Ok(!big)
    }
}

/// The Gauss–Newton normal equations of the flows' misalignments at one
/// model, with the sum of squares and the count of the flows used.
struct Normal {
    jtj: [[f32; 5]; 5],
    jtr: [f32; 5],
    ss: f32,
    n: usize,
    /// The running compensations of `jtj` and `jtr` (Kahan's summation:
    /// without them the sums' rounding grows with the flows, and with
    /// twelve thousand flows a motion a singular fit's scaled pivot
    /// reached [`MIN_JOINT_CONDITION`], a review's find).
    jtj_c: [[f32; 5]; 5],
    jtr_c: [f32; 5],
    /// The spread of the motions used: each one's point `(x, y)`, its
    /// translation `(t_x, t_y)/t_z` turned by the roll.
    spread: Spread,
}

/// The spread of points `(x, y)` (the motions' of a joint fit): their
/// count, and the mean and co-moments of the points less the first one by
/// Welford's update. Less the first point, the rounding does not grow with
/// the points' distance from the origin (Welford's mean alone rounds to
/// the coordinates' size: `q` 5·10⁻⁶ for five collinear points 3 from it
/// and 0.01 apart); by Welford's update, not with the first point's
/// distance from the others (plain shifted sums cancelled to `q` 4·10⁻⁴ on
/// a thousand collinear points with the first 1 000 from them, a
/// review's find).
#[derive(Debug, Clone, Copy, Default)]
struct Spread {
    n: u32,
    origin: Option<(f32, f32)>,
    mean: (f32, f32),
    /// `Σ (x − x̄)², Σ (x − x̄)(y − ȳ), Σ (y − ȳ)²`.
    m: (f32, f32, f32),
}

impl Spread {
    fn push(&mut self, x: f32, y: f32) {
        let (x0, y0) = *self.origin.get_or_insert((x, y));
        let (x, y) = (x - x0, y - y0);
        self.n = self.n.saturating_add(1);
        let n = self.n as f32;
        let (dx, dy) = (x - self.mean.0, y - self.mean.1);
        self.mean = (self.mean.0 + dx / n, self.mean.1 + dy / n);
        let (ex, ey) = (x - self.mean.0, y - self.mean.1);
        self.m = (self.m.0 + dx * ex, self.m.1 + dx * ey, self.m.2 + dy * ey);
    }

    /// `4 det C / (tr C)²` of the points' covariance `C`, the product of
    /// its eigenvalues over their squared mean: between 0 (the points on
    /// one line, or fewer than three) and 1 (spread alike in every
    /// direction, as the paper's five motions are), about `4 λ_min/λ_max`
    /// where small; unchanged by turning, shifting or scaling the points
    /// (each term taken over the trace before the product, so that
    /// neither over- nor underflows).
    fn q(&self) -> f32 {
        if self.n < 3 {
            return 0.0;
        }
        let (sxx, sxy, syy) = self.m;
        let tr = sxx + syy;
        let (a, b, c) = (sxx / tr, sxy / tr, syy / tr);
        let q = 4.0 * (a * c - b * b);
        // (A NaN, from a zero or non-finite trace, or a rounding below 0:
        // 0; above 1 only by rounding.)
        if q > 0.0 {
            fmin(q, 1.0)
        } else {
            0.0
        }
    }
}

impl Normal {
    /// The equations at `model`, over each motion's flows kept by the rule
    /// of [`focus_of_expansion`] at `masks`; [`CalibrationError::TooFewFlows`]
    /// if fewer than six flows are used in all.
    fn accumulate<const N: usize>(
        motions: &[MotionFlows<'_>],
        model: &Intrinsics,
        masks: &Intrinsics,
    ) -> Result<Self, CalibrationError> {
        // A roll the iterations pushed past the reduction's range: diverged.
        let (s, c) = sin_cos_reduced(model.roll).map_err(|_| CalibrationError::Degenerate)?;
        let mut eq = Normal {
            jtj: [[0.0f32; 5]; 5],
            jtr: [0.0f32; 5],
            ss: 0.0,
            n: 0,
            jtj_c: [[0.0f32; 5]; 5],
            jtr_c: [0.0f32; 5],
            spread: Spread::default(),
        };
        for m in motions {
            let mut keep = [false; N];
            if inlier_mask(m, masks, &mut keep)? < 2 {
                continue;
            }
            let t = m.translation;
            let (x, y) = ((c * t[0] + s * t[1]) / t[2], (-s * t[0] + c * t[1]) / t[2]);
            eq.spread.push(x, y);
            // d/dγ of R_zᵀ (t_x, t_y) / t_z.
            let (dx, dy) = ((-s * t[0] + c * t[1]) / t[2], (-c * t[0] - s * t[1]) / t[2]);
            let foe = [model.cx + model.fx * x, model.cy + model.fy * y];
            // dF/dp for p = (cx, cy, roll_mrad, fx, fy).
            let dfdp = [
                [1.0, 0.0],
                [0.0, 1.0],
                [model.fx * dx * 0.001, model.fy * dy * 0.001],
                [x, 0.0],
                [0.0, y],
            ];
            for (f, &kk) in m.flows.iter().zip(keep.iter()) {
                if kk {
                    eq.add_flow(f, foe, &dfdp);
                }
            }
        }
        if eq.n < 6 {
            return Err(CalibrationError::TooFewFlows);
        }
        Ok(eq)
    }

    /// One flow's misalignment from the line FOE → start,
    /// `res = (d × e) / |e|` with `e = FOE − start`, and its gradient.
    fn add_flow(&mut self, f: &Flow, foe: [f32; 2], dfdp: &[[f32; 2]; 5]) {
        let d = sub(f.to.arr(), f.from.arr());
        let e = sub(foe, f.from.arr());
        let le2 = dot(e, e);
        if le2.is_nan() || le2 <= 0.0 {
            return;
        }
        let le = sqrt(le2);
        let cr = cross(d, e);
        let res = cr / le;
        // ∂res/∂F = n/|e| − (d × e) e/|e|³, n = (−d_y, d_x).
        let g = [
            -d[1] / le - cr * e[0] / (le2 * le),
            d[0] / le - cr * e[1] / (le2 * le),
        ];
        let j = dfdp.map(|h| dot(g, h));
        for ((row, crow), &ja) in self.jtj.iter_mut().zip(self.jtj_c.iter_mut()).zip(j.iter()) {
            for ((cell, c), &jb) in row.iter_mut().zip(crow.iter_mut()).zip(j.iter()) {
                kahan(cell, c, ja * jb);
            }
        }
        for ((g, c), &ja) in self.jtr.iter_mut().zip(self.jtr_c.iter_mut()).zip(j.iter()) {
            kahan(g, c, ja * res);
        }
        self.ss += res * res;
        self.n += 1;
    }
}

/// `*sum += x` by Kahan's compensated summation, `c` the running
/// compensation (the low part lost so far, negated): the sum's error
/// stays about `2u` of the terms' absolute sum however many there are.
/// (`f32` additions are not reassociated: the compensation survives.)
fn kahan(sum: &mut f32, c: &mut f32, x: f32) {
    let y = x - *c;
    let t = *sum + y;
    *c = (t - *sum) - y;
    *sum = t;
}

/// The flows of motion `m` whose misalignment from the FOE `model`
/// predicts is at most `max(3 × median, FLOW_TOLERANCE_PX)`, in `keep`;
/// their count.
fn inlier_mask<const N: usize>(
    m: &MotionFlows<'_>,
    model: &Intrinsics,
    keep: &mut [bool; N],
) -> Result<usize, CalibrationError> {
    let foe = model.predicted_foe(m.translation)?;
    let mut dist = [0.0f32; N];
    let mut n = 0;
    for ((d, kk), f) in dist.iter_mut().zip(keep.iter_mut()).zip(m.flows) {
        *kk = f.from != f.to;
        if *kk {
            *d = misalignment(f, foe.arr());
            n += 1;
        }
    }
    let med = median_of_kept(&dist, keep, n);
    let limit = fmax(3.0 * med, FLOW_TOLERANCE_PX);
    let mut left = 0;
    for (kk, &d) in keep.iter_mut().zip(dist.iter()) {
        if *kk && d > limit {
            *kk = false;
        }
        left += usize::from(*kk);
    }
    Ok(left)
}

/// Step 3 of [`calibrate_jointly`]: the result, its RMS misalignment and
/// the standard deviations from the normal equations at the result;
/// [`CalibrationError::Degenerate`] if they are singular there,
/// [`CalibrationError::Overflow`] if a number is not finite.
fn joint_fit(p: &Params, eq: &Normal, iterations: usize) -> Result<JointFit, CalibrationError> {
    // Every square root's argument is checked first: `sqrt` maps NaN to 0.
    if !eq.ss.is_finite() {
        return Err(CalibrationError::Overflow);
    }
    let rms = sqrt(eq.ss / eq.n as f32);
    let dof = eq.n.saturating_sub(5).max(1) as f32;
    let var = rms * rms * eq.n as f32 / dof;
    // A fit the flows do not determine (an adversary's find: two motions,
    // or translations on one line, gave `Ok` up to 109 px off with σ of a
    // tenth of a pixel): refused, whatever the residuals.
    if eq.spread.q() < MIN_JOINT_SPREAD || joint_conditioning(&eq.jtj) < MIN_JOINT_CONDITION {
        return Err(CalibrationError::Degenerate);
    }
    let inv_diag = inverse_diagonal5(eq.jtj).ok_or(CalibrationError::Degenerate)?;
    let scale = [1.0, 1.0, 0.001, 1.0, 1.0];
    let mut sigma = [0.0f32; 5];
    for ((sg, id), sc) in sigma.iter_mut().zip(inv_diag.iter()).zip(scale.iter()) {
        let v = id * var;
        if !v.is_finite() {
            return Err(CalibrationError::Overflow);
        }
        *sg = sqrt(fmax(v, 0.0)) * sc;
    }
    let mut intrinsics = p.intrinsics();
    // (Within the reduction's range: the last pass took its sine.)
    intrinsics.roll =
        roll_in_half_turn(intrinsics.roll).map_err(|_| CalibrationError::Degenerate)?;
    // Both focal lengths negative is the same camera with the roll turned
    // by π (`diag(−f) R_z(γ + π)ᵀ = diag(f) R_z(γ)ᵀ`): given as that one.
    // One of them not positive is a mirror image no camera gives. (Until an
    // adversarial review a start with negative focal lengths returned `Ok`
    // with them.)
    if intrinsics.fx < 0.0 && intrinsics.fy < 0.0 {
        intrinsics.fx = -intrinsics.fx;
        intrinsics.fy = -intrinsics.fy;
        let pi = core::f32::consts::PI;
        intrinsics.roll += if intrinsics.roll > 0.0 { -pi } else { pi };
    }
    if !(intrinsics.fx > 0.0 && intrinsics.fy > 0.0) {
        return Err(CalibrationError::Degenerate);
    }
    let k = &intrinsics;
    let numbers = [k.cx, k.cy, k.roll, k.fx, k.fy, rms];
    if !numbers.iter().chain(sigma.iter()).all(|x| x.is_finite()) {
        return Err(CalibrationError::Overflow);
    }
    Ok(JointFit {
        intrinsics,
        rms,
        sigma,
        flows: eq.n,
        iterations,
    })
}

/// Solve the 5×5 symmetric positive definite system `a x = b` (Cholesky).
fn solve5(a: [[f32; 5]; 5], b: [f32; 5]) -> Option<[f32; 5]> {
    let l = cholesky5(a)?;
    // Forward: L y = b.
    let mut y = [0.0f32; 5];
    for i in 0..5 {
        let row = l.get(i)?;
        let mut s = *b.get(i)?;
        for (k, yk) in y.iter().enumerate().take(i) {
            s -= row.get(k)? * yk;
        }
        *y.get_mut(i)? = s / row.get(i)?;
    }
    // Backward: Lᵀ x = y.
    let mut x = [0.0f32; 5];
    for i in (0..5).rev() {
        let mut s = *y.get(i)?;
        for k in i + 1..5 {
            s -= l.get(k)?.get(i)? * x.get(k)?;
        }
        *x.get_mut(i)? = s / l.get(i)?.get(i)?;
    }
    Some(x)
}

fn cholesky5(a: [[f32; 5]; 5]) -> Option<[[f32; 5]; 5]> {
    let mut l = [[0.0f32; 5]; 5];
    for i in 0..5 {
        for j in 0..=i {
            let mut s = *a.get(i)?.get(j)?;
            for k in 0..j {
                s -= l.get(i)?.get(k)? * l.get(j)?.get(k)?;
            }
            if i == j {
                if s.is_nan() || s <= 0.0 {
                    return None;
                }
                *l.get_mut(i)?.get_mut(j)? = sqrt(s);
            } else {
                let d = *l.get(j)?.get(j)?;
                *l.get_mut(i)?.get_mut(j)? = s / d;
            }
        }
    }
    Some(l)
}

/// The conditioning of the joint fit's normal equations `a`: the smallest
/// Cholesky pivot of `a` scaled to a unit diagonal (`D^{-1/2} a D^{-1/2}`,
/// `D` its diagonal), between 0 (singular: some combination of the
/// parameters is not determined by the flows) and 1 (the parameters'
/// directions independent). At least the reciprocal of the scaled
/// matrix's condition number. 0 where a diagonal entry is not positive
/// or the factorisation fails.
fn joint_conditioning(a: &[[f32; 5]; 5]) -> f32 {
    let mut d = [0.0f32; 5];
    for (i, di) in d.iter_mut().enumerate() {
        let aii = a.get(i).and_then(|r| r.get(i)).copied().unwrap_or(0.0);
        if !(aii > 0.0 && aii.is_finite()) {
            return 0.0;
        }
        *di = 1.0 / sqrt(aii);
    }
    let mut scaled = [[0.0f32; 5]; 5];
    for (i, (row, &di)) in scaled.iter_mut().zip(d.iter()).enumerate() {
        for (j, (cell, &dj)) in row.iter_mut().zip(d.iter()).enumerate() {
            let aij = a.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0.0);
            *cell = aij * di * dj;
        }
    }
    let Some(l) = cholesky5(scaled) else {
        return 0.0;
    };
    let mut least = f32::INFINITY;
    for (i, row) in l.iter().enumerate() {
        let p = row.get(i).copied().unwrap_or(0.0);
        least = fmin(least, p * p);
    }
    if least.is_finite() {
        least
    } else {
        0.0
    }
}

/// Diagonal of the inverse of a 5×5 SPD matrix (for standard deviations).
fn inverse_diagonal5(a: [[f32; 5]; 5]) -> Option<[f32; 5]> {
    let mut out = [0.0f32; 5];
    for (i, o) in out.iter_mut().enumerate() {
        let mut e = [0.0f32; 5];
        *e.get_mut(i)? = 1.0;
        *o = *solve5(a, e)?.get(i)?;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    /// Kahan's summation keeps a million terms' sum within the last place
    /// of the `f64` sum, where the plain `f32` sum drifts by 30 times
    /// that (what made a singular joint fit's pivot grow with its flows).
    #[test]
    fn compensated_sums_do_not_drift_with_the_terms() {
        let (mut plain, mut sum, mut c, mut exact) = (0.0f32, 0.0f32, 0.0f32, 0.0f64);
        for k in 0..1_000_000u32 {
            let x = 0.1 + (k % 97) as f32 * 1.0e-3;
            plain += x;
            kahan(&mut sum, &mut c, x);
            exact += f64::from(x);
        }
        let rel = |v: f32| ((f64::from(v) - exact) / exact).abs();
        // (The `f32` result itself is within 2⁻²⁴ of the sum.)
        assert!(rel(sum) < 1.0e-7, "{}", rel(sum));
        assert!(rel(plain) > 1.0e-6, "{}", rel(plain));
    }

    /// The translations' spread is 0 on a line (and for fewer than three
    /// points), 1 for points spread alike, and unchanged by turning,
    /// shifting and scaling them (a review found the first measure, a
    /// moment matrix scaled to a unit diagonal, 0.8 or 10⁻⁷ for the same
    /// points as their line lay along an axis or not), also for many
    /// collinear points far from the first one or from the origin and at
    /// scales from 10⁻¹⁵ to 10¹⁵ (reviews found sums shifted by the first
    /// point cancelling to 4·10⁻⁴, and an unnormalised determinant
    /// underflowing to 0 for a unit square scaled by 10⁻¹²).
    #[test]
    fn the_spread_sees_a_line_in_any_direction() {
        let spread_of = |pts: &[(f32, f32)]| {
            let mut sp = Spread::default();
            for &(x, y) in pts {
                sp.push(x, y);
            }
            sp.q()
        };
        let square = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        assert!((spread_of(&square) - 1.0).abs() < 1e-6);
        assert_eq!(spread_of(&square[..2]), 0.0);
        for angle in [0.0f32, 0.3, 0.785, 1.2, 2.0] {
            let (s, c) = (angle.sin(), angle.cos());
            let turn = |(x, y): (f32, f32), k: f32, d: (f32, f32)| {
                (k * (c * x - s * y) + d.0, k * (s * x + c * y) + d.1)
            };
            for (k, d) in [(1.0, (0.0, 0.0)), (0.01, (3.0, -2.0)), (50.0, (-0.4, 0.7))] {
                let line: [(f32, f32); 5] =
                    core::array::from_fn(|i| turn((i as f32 - 2.0, 0.0), k, d));
                assert!(spread_of(&line) < 1e-6, "{angle} {k}");
                // The middle point 5 % of the extent off the line, and
                // 0.1 %: the same spread at every angle, scale and shift.
                for (off, lo, hi) in [(0.2f32, 0.01, 0.03), (0.004, 0.0, 1e-4)] {
                    let mut bent = line;
                    bent[2] = turn((0.0, off), k, d);
                    let q = spread_of(&bent);
                    assert!(lo <= q && q < hi, "{angle} {k} {off}: {q}");
                }
            }
        }
        // A first point far from a thousand collinear ones, far from the
        // origin, and the same points scaled.
        for (far, at) in [(10.0f32, 0.0f32), (1000.0, 0.0), (0.0, 1.0e4)] {
            let (s, c) = 0.785f32.sin_cos();
            let mut pts = std::vec![(at + far * c, at + far * s)];
            pts.extend((0..1000).map(|i| {
                let t = i as f32 / 1000.0;
                (at + t * c, at + t * s)
            }));
            assert!(spread_of(&pts) < 1e-5, "{far} {at}: {}", spread_of(&pts));
        }
        for k in [1.0e-15f32, 1.0e-12, 1.0e12, 1.0e15] {
            let scaled: std::vec::Vec<(f32, f32)> =
                square.iter().map(|&(x, y)| (x * k, y * k)).collect();
            assert!((spread_of(&scaled) - 1.0).abs() < 1e-5, "{k}");
        }
    }
}
