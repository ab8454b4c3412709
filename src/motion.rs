//! Camera motion between frame 1 and frame 2.
//!
//! # Conventions
//! Everything is expressed in the **frame-1 camera coordinates**
//! (`x` right, `y` down, `z` forward; right-handed).
//!
//! * Translation `(U, V, W)`: the position of the frame-2 camera centre in
//!   frame-1 camera coordinates, in any length unit (depths come out in the
//!   same unit). `W > 0` is forward motion. This is the paper's `T` (Sec. 2).
//! * Rotation `(α, β, γ)`, radians: the orientation of the frame-2 camera in
//!   frame-1 coordinates is `R = R_y(β) · R_x(α) · R_z(γ)` (turn by `β` about
//!   `y`, then pitch by `α` about the new `x`, then roll by `γ` about the new
//!   `z`), each elementary rotation right-handed:
//!   `+β` turns the camera to the **right** (`z` towards `+x`),
//!   `+α` pitches it **up** (`z` towards `-y`),
//!   `+γ` rolls it **clockwise** as seen from behind (`x` towards `+y`).
//!   The paper's Fig. 6 "(0, −5°, 0), steering to the right" is
//!   `β = +5°` here: the paper gives the apparent rotation of the scene.
//! * A point with frame-1 coordinates `P` has frame-2 coordinates
//!   `P₂ = Rᵀ (P − T)`.
//!
//! Rotation compensation is exact: a frame-1 pixel `p` is mapped by the
//! homography `K₂ Rᵀ K₁⁻¹`, not by the small-angle flow approximation.

use core::fmt;

use crate::math::{mat3_mul, sin_cos, MAX_TRANSLATION};

/// Largest accepted rotation about any one axis between two frames, radians (60°).
pub const MAX_ROTATION_RAD: f32 = core::f32::consts::FRAC_PI_3;

/// Smallest accepted translation length, in the caller's length unit.
pub const MIN_TRANSLATION: f32 = 1.0e-6;

/// Why a motion was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MotionError {
    /// A component is NaN or infinite.
    NotFinite,
    /// `|(U, V, W)|` is below [`MIN_TRANSLATION`]: no baseline, no depth.
    ZeroTranslation,
    /// A translation component exceeds `1e6` units.
    TranslationTooLarge,
    /// A rotation angle exceeds [`MAX_ROTATION_RAD`].
    RotationTooLarge,
}

impl core::error::Error for MotionError {}

impl fmt::Display for MotionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NotFinite => "motion component is NaN or infinite",
            Self::ZeroTranslation => "translation is zero: no baseline for stereo",
            Self::TranslationTooLarge => "translation component above 1e6 units",
            Self::RotationTooLarge => "rotation angle above 60 degrees",
        })
    }
}

/// Validated motion from frame 1 to frame 2 (see the module docs for conventions).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Motion {
    translation: [f32; 3],
    angles: [f32; 3],
    rotation: [[f32; 3]; 3],
}

impl Motion {
    /// Checked constructor from translation `(U, V, W)` and rotation
    /// `(α, β, γ)` in radians.
    ///
    /// ```
    /// use roadstereo::{Motion, MotionError};
    /// // The paper's Fig. 6: forward 0.4, steering 5° to the right.
    /// let m = Motion::new([0.0, 0.0, 0.4], [0.0, 5f32.to_radians(), 0.0])?;
    /// assert_eq!(m.translation(), [0.0, 0.0, 0.4]);
    /// assert_eq!(Motion::new([0.0; 3], [0.0; 3]), Err(MotionError::ZeroTranslation));
    /// # Ok::<(), MotionError>(())
    /// ```
    pub fn new(translation: [f32; 3], rotation: [f32; 3]) -> Result<Self, MotionError> {
        if translation
            .iter()
            .chain(rotation.iter())
            .any(|x| !x.is_finite())
        {
            return Err(MotionError::NotFinite);
        }
        if translation.iter().any(|x| x.abs() > MAX_TRANSLATION) {
            return Err(MotionError::TranslationTooLarge);
        }
        if rotation.iter().any(|x| x.abs() > MAX_ROTATION_RAD) {
            return Err(MotionError::RotationTooLarge);
        }
        let [u, v, w] = translation;
        // Compare the squared length: no square root needed.
        if u * u + v * v + w * w < MIN_TRANSLATION * MIN_TRANSLATION {
            return Err(MotionError::ZeroTranslation);
        }
        let (sa, ca) = sin_cos(rotation[0]);
        let (sb, cb) = sin_cos(rotation[1]);
        let (sg, cg) = sin_cos(rotation[2]);
        let ry = [[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]];
        let rx = [[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]];
        let rz = [[cg, -sg, 0.0], [sg, cg, 0.0], [0.0, 0.0, 1.0]];
        Ok(Self {
            translation,
            angles: rotation,
            rotation: mat3_mul(&mat3_mul(&ry, &rx), &rz),
        })
    }

    /// Translation `(U, V, W)` in frame-1 camera coordinates.
    pub fn translation(&self) -> [f32; 3] {
        self.translation
    }

    /// Rotation angles `(α, β, γ)`, radians.
    pub fn angles(&self) -> [f32; 3] {
        self.angles
    }

    /// Rotation matrix `R` (frame-2 axes as columns, in frame-1 coordinates).
    pub fn rotation_matrix(&self) -> [[f32; 3]; 3] {
        self.rotation
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steering_right_turns_forward_axis_towards_plus_x() {
        let m = Motion::new([0.0, 0.0, 1.0], [0.0, 0.1, 0.0]).unwrap();
        let r = m.rotation_matrix();
        // Third column: frame-2 forward axis in frame-1 coordinates.
        assert!(r[0][2] > 0.09 && r[2][2] > 0.99);
    }

    #[test]
    fn pitch_up_turns_forward_axis_towards_minus_y() {
        let m = Motion::new([0.0, 0.0, 1.0], [0.1, 0.0, 0.0]).unwrap();
        assert!(m.rotation_matrix()[1][2] < -0.09);
    }

    #[test]
    fn rejects_bad_motion() {
        assert_eq!(
            Motion::new([f32::NAN, 0.0, 1.0], [0.0; 3]),
            Err(MotionError::NotFinite)
        );
        assert_eq!(
            Motion::new([0.0, 0.0, 1.0], [0.0, 2.0, 0.0]),
            Err(MotionError::RotationTooLarge)
        );
        assert_eq!(
            Motion::new([0.0, 0.0, 1e7], [0.0; 3]),
            Err(MotionError::TranslationTooLarge)
        );
    }
}
