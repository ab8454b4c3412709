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

use crate::math::{asin, atan2, mat3_mul, mat3_vec, sin_cos, MAX_TRANSLATION};

/// Largest accepted rotation about any one axis between two frames, radians (60°).
pub const MAX_ROTATION_RAD: f32 = core::f32::consts::FRAC_PI_3;

/// Smallest accepted translation length, in the caller's length unit.
pub const MIN_TRANSLATION: f32 = 1.0e-6;

/// Why a motion was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
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
///
/// A motion made from a matrix ([`Motion::then`]) recovers its angles
/// only when asked ([`Motion::angles`]): its `angles` field holds NaN
/// (never a valid angle) until then, and equality, `Debug` and `defmt`
/// use [`Motion::angles`], so the motion behaves as if they were stored.
#[derive(Clone, Copy)]
pub struct Motion {
    translation: [f32; 3],
    /// The angles given to [`Motion::new`]; all NaN for a motion made
    /// from its matrix (recovered by [`Motion::angles`]).
    angles: [f32; 3],
    rotation: [[f32; 3]; 3],
}

impl PartialEq for Motion {
    fn eq(&self, other: &Self) -> bool {
        self.translation == other.translation
            && self.angles() == other.angles()
            && self.rotation == other.rotation
    }
}

impl fmt::Debug for Motion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Motion")
            .field("translation", &self.translation)
            .field("angles", &self.angles())
            .field("rotation", &self.rotation)
            .finish()
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Motion {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "Motion {{ translation: {}, angles: {}, rotation: {} }}",
            self.translation,
            self.angles(),
            self.rotation
        )
    }
}

/// The angles `(α, β, γ)` of the rotation matrix `r`
/// (`R = R_y(β) R_x(α) R_z(γ)`: `α = asin(−R₁₂)`, `β = atan2(R₀₂, R₂₂)`,
/// `γ = atan2(R₁₀, R₁₁)`).
fn angles_of(r: &[[f32; 3]; 3]) -> [f32; 3] {
    let [[_, _, r02], [r10, r11, r12], [_, _, r22]] = *r;
    [asin(-r12), atan2(r02, r22), atan2(r10, r11)]
}

/// Whether the angles [`angles_of`] recovers from `r` are certainly all
/// within [`MAX_ROTATION_RAD`], from the matrix alone: `|R₁₂| ≤ 0.85`
/// (`asin 0.85 = 1.0160`), and for each `atan2(y, x)` a positive `x`
/// with `|y| ≤ 1.7 x` (`atan 1.7 = 1.0391`), against the limit `1.0472`.
/// The margins (at least `0.008` rad) dwarf the recovery's rounding
/// (`asin`, `atan2` within `1e-6` here, the quotient's rounding `1e-7`
/// relative), so a `true` here never changes the check's decision; a
/// `false` sends the check to the angles themselves.
fn surely_within_limit(r: &[[f32; 3]; 3]) -> bool {
    let [[_, _, r02], [r10, r11, r12], [_, _, r22]] = *r;
    r12.abs() <= 0.85 && r22 > 0.0 && r02.abs() <= 1.7 * r22 && r11 > 0.0 && r10.abs() <= 1.7 * r11
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

    /// The motion from frame 1 to frame 3 when `self` goes from frame 1 to
    /// frame 2 and `next` from frame 2 to frame 3: the translation
    /// `T = T₁ + R₁ T₂` (frame-1 coordinates) and the rotation `R = R₁ R₂`,
    /// composed as matrices (no round trip through the angles, which
    /// [`Motion::angles`] gives recovered from `R`). The same checks as
    /// [`Motion::new`]: a composition that comes back to its start is
    /// [`MotionError::ZeroTranslation`], one that turns more than
    /// [`MAX_ROTATION_RAD`] about an axis [`MotionError::RotationTooLarge`].
    ///
    /// Each composition rounds like one matrix product in `f32`, about
    /// `1e-7` of the rotation's entries: composing `n` motions moves the
    /// rotation-compensated points by about `n · 1e-7 · f` pixels (`8e-4`
    /// px for 10 motions at `f = 800`). The translation rounds by about
    /// `1e-7` of the translations composed, not of their sum: where they
    /// cancel (out and back) the result can be far off relative to
    /// itself, and its focus of expansion with it (an adversarial review:
    /// out by 10⁵ and back to 4, the composed translation off by 0.2 %,
    /// the focus by 170 px at `f = 10⁵`). The processor takes a motion it
    /// is given as exact: configure motion errors that cover the rounding
    /// of one you compose ([`crate::Config::with_translation_error`]); the
    /// fusion carries its own composition's rounding ([`crate::fusion`]).
    ///
    /// ```
    /// use roadstereo::Motion;
    /// let step = Motion::new([0.0, 0.0, 0.4], [0.0, 0.05, 0.0])?;
    /// let two = step.then(&step)?;
    /// // Two turns of 0.05 rad are one of 0.1 rad.
    /// assert!((two.angles()[1] - 0.1).abs() < 1e-6);
    /// // The second step goes forward along the turned axis.
    /// let [u, _, w] = two.translation();
    /// assert!((u - 0.4 * 0.05f32.sin()).abs() < 1e-6 && (w - 0.4 - 0.4 * 0.05f32.cos()).abs() < 1e-6);
    /// # Ok::<(), roadstereo::MotionError>(())
    /// ```
    pub fn then(&self, next: &Motion) -> Result<Motion, MotionError> {
        let r = self.rotation;
        let t = mat3_vec(&r, next.translation);
        let translation = [
            self.translation[0] + t[0],
            self.translation[1] + t[1],
            self.translation[2] + t[2],
        ];
        Self::from_matrix(translation, mat3_mul(&r, &next.rotation))
    }

    /// A motion from its translation and rotation matrix, checked as
    /// [`Motion::new`] checks its arguments; the angles are recovered from
    /// the matrix (`R = R_y(β) R_x(α) R_z(γ)`: `α = asin(−R₁₂)`,
    /// `β = atan2(R₀₂, R₂₂)`, `γ = atan2(R₁₀, R₁₁)`). The caller makes
    /// `rotation` a rotation (a product of rotations).
    pub(crate) fn from_matrix(
        translation: [f32; 3],
        rotation: [[f32; 3]; 3],
    ) -> Result<Self, MotionError> {
        if translation
            .iter()
            .chain(rotation.iter().flatten())
            .any(|x| !x.is_finite())
        {
            return Err(MotionError::NotFinite);
        }
        if translation.iter().any(|x| x.abs() > MAX_TRANSLATION) {
            return Err(MotionError::TranslationTooLarge);
        }
        let [u, v, w] = translation;
        if u * u + v * v + w * w < MIN_TRANSLATION * MIN_TRANSLATION {
            return Err(MotionError::ZeroTranslation);
        }
        // The angles are recovered only where the matrix alone cannot
        // show them within the limit (the same decision either way), and
        // otherwise only when asked for.
        if !surely_within_limit(&rotation)
            && angles_of(&rotation)
                .iter()
                .any(|x| x.abs() > MAX_ROTATION_RAD)
        {
            return Err(MotionError::RotationTooLarge);
        }
        Ok(Self {
            translation,
            angles: [f32::NAN; 3],
            rotation,
        })
    }

    /// Translation `(U, V, W)` in frame-1 camera coordinates.
    pub fn translation(&self) -> [f32; 3] {
        self.translation
    }

    /// Rotation angles `(α, β, γ)`, radians (for a motion made from its
    /// matrix, recovered from it here, the same each time).
    pub fn angles(&self) -> [f32; 3] {
        if self.angles[0].is_nan() {
            angles_of(&self.rotation)
        } else {
            self.angles
        }
    }

    /// Rotation matrix `R` (frame-2 axes as columns, in frame-1 coordinates).
    ///
    /// For a motion from [`Motion::new`] every entry is within `3·10⁻⁷` of
    /// the exact rotation of the angles given, as far as searched against
    /// `f64` to the 60° limit (measured, not derived: the test
    /// `the_matrix_is_within_3e_7_of_its_angles_rotation`). The sticks are
    /// guaranteed for this matrix as the motion
    /// given: where the angles are the truth and `f · 3·10⁻⁷` pixels
    /// matter (focal lengths of thousands of pixels), that difference is
    /// part of the motion's error, for a configured rotation error
    /// ([`crate::Config::with_rotation_error`]) to hold with margin.
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
    fn composition_matches_the_product_of_the_motions() {
        // A point's frame-3 coordinates through two motions, step by step
        // and through the composition: P₂ = R₁ᵀ (P₁ − T₁), P₃ = R₂ᵀ (P₂ − T₂).
        let a = Motion::new([0.1, -0.05, 0.4], [0.02, 0.08, -0.01]).unwrap();
        let b = Motion::new([-0.03, 0.02, 0.35], [-0.01, -0.04, 0.03]).unwrap();
        let ab = a.then(&b).unwrap();
        let to_next = |m: &Motion, p: [f32; 3]| {
            let t = m.translation();
            let d = [p[0] - t[0], p[1] - t[1], p[2] - t[2]];
            mat3_vec(&crate::math::mat3_transpose(&m.rotation_matrix()), d)
        };
        for p in [[1.0, 2.0, 5.0], [-3.0, 0.5, 12.0], [0.0, 0.0, 1.0]] {
            let step = to_next(&b, to_next(&a, p));
            let once = to_next(&ab, p);
            for (x, y) in step.iter().zip(once) {
                assert!((x - y).abs() < 2e-6, "{step:?} {once:?}");
            }
        }
        // The recovered angles give back the matrix.
        let again = Motion::new(ab.translation(), ab.angles()).unwrap();
        for (r, q) in again.rotation_matrix().iter().zip(ab.rotation_matrix()) {
            for (x, y) in r.iter().zip(q) {
                assert!((x - y).abs() < 2e-6);
            }
        }
        // Out and back is no baseline; too many turns are too large.
        let back = Motion::new([0.0, 0.0, -0.4], [0.0; 3]).unwrap();
        let fwd = Motion::new([0.0, 0.0, 0.4], [0.0; 3]).unwrap();
        assert_eq!(fwd.then(&back), Err(MotionError::ZeroTranslation));
        let turn = Motion::new([0.0, 0.0, 0.4], [0.0, 0.6, 0.0]).unwrap();
        assert_eq!(turn.then(&turn), Err(MotionError::RotationTooLarge));
    }

    /// The matrix [`Motion::new`] builds is within `3·10⁻⁷` of the exact
    /// rotation its angles name, entry by entry (`f64`, `R = R_y(β) R_x(α)
    /// R_z(γ)`), for angles to the 60° limit, as far as searched: 200 000
    /// random triples, then a hill climb from the 64 worst of them,
    /// nudging each angle by up to 2¹⁶ units in the last place. Measured,
    /// not derived (the sines and cosines themselves are pinned within
    /// `3·10⁻⁷` of `libm`'s at 2 001 points, `math`). The docs said
    /// 1.7·10⁻⁷ until an adversarial review (thirtieth session) found
    /// 1.91·10⁻⁷, then 2·10⁻⁷ until a reviewer's climb found 2.74·10⁻⁷ at
    /// the angles checked first here.
    #[test]
    fn the_matrix_is_within_3e_7_of_its_angles_rotation() {
        extern crate std;
        let exact = |a: [f32; 3]| -> [[f64; 3]; 3] {
            let [al, be, ga] = a.map(f64::from);
            let rx = [
                [1.0, 0.0, 0.0],
                [0.0, al.cos(), -al.sin()],
                [0.0, al.sin(), al.cos()],
            ];
            let ry = [
                [be.cos(), 0.0, be.sin()],
                [0.0, 1.0, 0.0],
                [-be.sin(), 0.0, be.cos()],
            ];
            let rz = [
                [ga.cos(), -ga.sin(), 0.0],
                [ga.sin(), ga.cos(), 0.0],
                [0.0, 0.0, 1.0],
            ];
            let mul = |x: [[f64; 3]; 3], y: [[f64; 3]; 3]| {
                [0, 1, 2].map(|i| [0, 1, 2].map(|j| (0..3).map(|k| x[i][k] * y[k][j]).sum::<f64>()))
            };
            mul(mul(ry, rx), rz)
        };
        let off = |a: [f32; 3]| {
            let m = Motion::new([0.0, 0.0, 1.0], a)
                .expect("motion")
                .rotation_matrix();
            let r = exact(a);
            (0..9)
                .map(|k| (f64::from(m[k / 3][k % 3]) - r[k / 3][k % 3]).abs())
                .fold(0.0, f64::max)
        };
        let found = off([-0.921_213_4, -1.027_005_3, 0.859_918_5]);
        assert!((2.7e-7..=3.0e-7).contains(&found), "{found:e}");
        let mut g = crate::test_rng::Rng(0x0a11_5e7e);
        let mut starts = std::vec::Vec::new();
        for _ in 0..200_000 {
            let a = [0.0; 3].map(|_: f32| (g.next() * 2.0 - 1.0) * MAX_ROTATION_RAD);
            starts.push((off(a), a));
        }
        starts.sort_by(|x, y| y.0.total_cmp(&x.0));
        let mut worst = starts.first().map_or(0.0, |s| s.0);
        // A hill climb from the 64 worst: nudge one angle by ±2^j units
        // in the last place (j up to 16), keep what is worse.
        for &(mut best, mut a) in starts.iter().take(64) {
            for _ in 0..600 {
                let i = (g.next() * 3.0) as usize % 3;
                let step = 1i32 << ((g.next() * 17.0) as i32).clamp(0, 16);
                let step = if g.next() < 0.5 { step } else { -step };
                let mut b = a;
                b[i] = f32::from_bits(b[i].to_bits().wrapping_add_signed(step));
                if !(b[i].abs() <= MAX_ROTATION_RAD) {
                    continue;
                }
                let e = off(b);
                if e > best {
                    (best, a) = (e, b);
                }
            }
            worst = worst.max(best);
        }
        assert!(worst <= 3.0e-7, "{worst:e}");
        assert!(
            worst > 2.0e-7,
            "the climb reaches near the bound: {worst:e}"
        );
    }

    #[test]
    fn the_matrix_shortcut_never_overrides_the_angles() {
        // Rotations from composed random turns, many near and past the
        // limit: wherever the shortcut says "within", the recovered
        // angles are within; and a composed motion's lazily recovered
        // angles are the angles `from_matrix` used to store.
        let mut g = crate::test_rng::Rng(0x2468_ace1);
        let mut shortcut = 0;
        for i in 0..20_000 {
            let reach = if i % 2 == 0 { 1.2 } else { 0.7 };
            let mut ang = || (g.next() * 2.0 - 1.0) * reach;
            let (Ok(a), Ok(b)) = (
                Motion::new([0.0, 0.0, 1.0], [ang(), ang(), ang()]),
                Motion::new([0.1, 0.0, 1.0], [ang(), ang(), ang()]),
            ) else {
                continue;
            };
            let r = mat3_mul(&a.rotation_matrix(), &b.rotation_matrix());
            let angles = angles_of(&r);
            let within = !angles.iter().any(|x| x.abs() > MAX_ROTATION_RAD);
            if surely_within_limit(&r) {
                shortcut += 1;
                assert!(within, "{r:?} {angles:?}");
            }
            match a.then(&b) {
                Ok(m) => {
                    assert!(within);
                    assert_eq!(m.angles(), angles);
                    assert_eq!(m, m);
                }
                Err(e) => {
                    assert_eq!(e, MotionError::RotationTooLarge);
                    assert!(!within);
                }
            }
        }
        assert!(shortcut > 1_000, "{shortcut}");
        // At the shortcut's own edges the angles keep their margin.
        for x in [0.85f32, -0.85] {
            assert!(asin(x).abs() < MAX_ROTATION_RAD - 0.03);
        }
        assert!(atan2(1.7, 1.0) < MAX_ROTATION_RAD - 0.008);
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
