//! The motion from the key frame to the current frame, composed from the
//! per-frame motions, with a bound of its error when the configuration
//! bounds the error of each per-frame motion.
//!
//! # The error model
//! As in [`crate::Config::with_translation_error`] and
//! [`crate::Config::with_rotation_error`]: the true motion of a frame is
//! `T + d`, `R Ω` with `|d_k| ≤ δ` on each component (the previous frame's
//! axes) and `Ω` a rotation whose rotation vector `ω` has `|ω_k| ≤ ε_k`
//! about the axes of the frame it arrives at; its angle is `|ω| ≤ |ε|`.
//!
//! # Composing the bound
//! With the key frame's motion to frame `j − 1` (`T₁`, `R₁`, bounds `δ₁`,
//! `ε₁`, angle `ω₁`) and the motion to frame `j` (`T₂`, `R₂`, `δ`, `ε`,
//! angle `ω₂ = |ε|`):
//!
//! * `T = T₁ + R₁ T₂`. The truth is `T₁ + d₁ + R₁ Ω₁ (T₂ + d₂)`, off by
//!   `d₁ + R₁ u` with `u = (Ω₁ − I)(T₂ + d₂) + d₂`. A rotation by at most
//!   `ω₁` moves a vector `v` by at most `ω₁ |v|`, so every component of `u`
//!   is at most `a = ω₁ (|T₂| + √3 δ) + δ`, and component `k` of `R₁ u` at
//!   most `a Σ_l |R₁[k][l]|`: `δ_j = δ₁ + a · max_k Σ_l |R₁[k][l]|`.
//! * `R = R₁ R₂`. The truth `R₁ Ω₁ R₂ Ω₂ = R (R₂ᵀ Ω₁ R₂) Ω₂` is off by the
//!   product of the rotations with vectors `R₂ᵀ ω₁` and `ω₂`, both about
//!   frame `j`'s axes. Their sum bounds the product's vector to first
//!   order, component by component (`Σ_l |R₂[l][k]| ε₁_l + ε_k`); the
//!   second order (the commutator, `½ |ω₁| |ω₂|` and smaller terms) is
//!   covered by adding `ω₁ ω₂`. The angle of the product is at most
//!   `ω₁ + ω₂` (the triangle inequality on rotations).
//!
//! Each bound is rounded up by `2⁻¹⁶` of itself against the `f32` rounding
//! of its own arithmetic, except on the first step from the key frame,
//! whose composition with the identity is exact: the first partner's
//! bounds are the step's own (a step's bounds at the configuration's
//! limit would otherwise be rounded past it). The translation bound grows with the travel, the
//! rotation bound with the number of frames: a key frame's last partner is
//! the last one whose bounds [`crate::Config`] still accepts (rotation
//! errors summing to at most 0.1 rad), see [`crate::fusion`].
//!
//! Without configured error bounds every bound stays exactly 0 and the
//! composed motion is what the per-frame motions compose to in `f32` (see
//! [`Motion::then`] for its rounding).
//!
//! # Rounding
//! The composition's own `f32` rounding is kept apart, always (configured
//! bounds or not), for the road map's radius ([`crate::map`], "The
//! radius", which derives the step): each frame adds [`STEP_ROUNDING`]
//! (`2⁻¹⁹`) to the orientation's angle error `r`, and `2⁻¹⁸ (|T₁|₁ +
//! |T₂|₁) + r |T₂|₁` to the translation's (the step's own rounding, and
//! the orientation's error so far turning `T₂`); the sums are rounded up.
//! The step assumes each frame's motion as [`Motion::new`] makes it (a
//! caller that composes motions itself brings their rounding, for
//! [`crate::Config::with_rotation_error`] to cover).
//!
//! For the pairs the chain keeps a second, tighter pair of bounds
//! (`pair_t`, `pair_r`): against the per-frame matrices as given, which
//! are what the processor takes for a pair's truth, with no angle to
//! matrix error, so `2⁻²⁰` a step for the product and `2⁻²¹ (|T₁|₁ +
//! |T₂|₁)` for the translation ([`PAIR_R_ROUNDING`], [`PAIR_T_ROUNDING`]),
//! and none for the first step from the key frame (exact). The processor
//! carries them (`crate::processor`, "The composition's rounding"; until
//! an adversarial review it took the composed motion as exact, and a
//! translation composed out by 10⁵ and back to 4 left every fused
//! interval 0.7–2.4 % off the truth); where the focus's error they give
//! would bound little, [`Chain::config`] puts them into the pair's
//! translation error instead.

use crate::config::{Config, ConfigError};
use crate::math::{mat3_mul, mat3_transpose, mat3_vec, sqrt, Mat3};
use crate::motion::{Motion, MotionError};
use crate::processor::Rounding;

/// `√3`, rounded up: the length of a vector whose components are at most 1.
const SQRT3: f32 = 1.732_051;
/// Rounding allowance of a bound's arithmetic.
const ROUND_UP: f32 = 1.0 + 1.0 / 65_536.0;

/// The `f32` rounding of composing one frame's rotation, as an angle
/// (`2⁻¹⁹ = 32 u`, [`crate::map`], "The radius"); a translation's is
/// twice this times the 1-norms involved.
pub(crate) const STEP_ROUNDING: f32 = 1.0 / 524_288.0;

/// The `f32` rounding of one composition step against the per-frame
/// matrices as given (module docs, "Rounding"): the product `R₁ R₂`, at
/// most `3 u` an entry (unit rows and columns), `9 u` as an operator,
/// below `2⁻²⁰ = 16 u`; and the translation `T₁ + R₁ T₂`, at most `u (3
/// |T₂|₁ + |T₁ + R₁ T₂|) ≤ u (4 |T₂|₁ + |T₁|₁)` a component, `√3` times
/// that as a length, below `2⁻²¹ (|T₁|₁ + |T₂|₁) = 8 u (…)`.
const PAIR_R_ROUNDING: f32 = 1.0 / 1_048_576.0;
const PAIR_T_ROUNDING: f32 = 1.0 / 2_097_152.0;

/// `|v|₁`.
pub(crate) fn norm1(v: [f32; 3]) -> f32 {
    v[0].abs() + v[1].abs() + v[2].abs()
}

/// The per-frame error bounds of the configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct StepBounds {
    /// Translation error per component, length units.
    pub(crate) delta: f32,
    /// Rotation error per axis, radians.
    pub(crate) eps: [f32; 3],
    /// The angle of the rotation error, `|ε|` rounded up.
    pub(crate) omega: f32,
}

impl StepBounds {
    pub(crate) fn of(config: &Config) -> Self {
        let eps = config.rotation_error();
        let [a, b, c] = eps;
        Self {
            delta: config.translation_error(),
            eps,
            omega: sqrt(a * a + b * b + c * c) * ROUND_UP,
        }
    }

    /// Whether any bound is configured.
    pub(crate) fn any(&self) -> bool {
        self.delta > 0.0 || self.omega > 0.0
    }
}

/// The key frame's motion to the current frame and its error bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Chain {
    /// Translation, key-frame camera coordinates.
    pub(crate) t: [f32; 3],
    /// Orientation of the current camera in key-frame coordinates.
    pub(crate) r: Mat3,
    /// Translation error bound per component (key-frame axes).
    pub(crate) delta: f32,
    /// Rotation error bound per axis (current frame's axes).
    pub(crate) eps: [f32; 3],
    /// Rotation error angle bound.
    pub(crate) omega: f32,
    /// The composition's own rounding (module docs): of the translation,
    /// and of the orientation as an angle.
    pub(crate) round_t: f32,
    pub(crate) round_r: f32,
    /// The same against the per-frame motions' matrices as given (what
    /// the processor takes for the truth of a pair, module docs), for the
    /// pair's configuration ([`Chain::config`]).
    pub(crate) pair_t: f32,
    pub(crate) pair_r: f32,
}

fn norm(v: [f32; 3]) -> f32 {
    sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) * ROUND_UP
}

impl Chain {
    /// The key frame itself: no motion, no error.
    pub(crate) const IDENTITY: Chain = Chain {
        t: [0.0; 3],
        r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        delta: 0.0,
        eps: [0.0; 3],
        omega: 0.0,
        round_t: 0.0,
        round_r: 0.0,
        pair_t: 0.0,
        pair_r: 0.0,
    };

    /// The chain continued by one frame's motion `m` with error bounds `b`
    /// (module docs).
    pub(crate) fn then(&self, m: &Motion, b: &StepBounds) -> Chain {
        let t2 = m.translation();
        let r2 = m.rotation_matrix();
        let rt2 = mat3_vec(&self.r, t2);
        let t = [self.t[0] + rt2[0], self.t[1] + rt2[1], self.t[2] + rt2[2]];
        let r = mat3_mul(&self.r, &r2);
        // This step's rounding, and the orientation's so far turning `T₂`.
        let round_t = (self.round_t
            + 2.0 * STEP_ROUNDING * (norm1(self.t) + norm1(t2))
            + self.round_r * norm1(t2))
            * ROUND_UP;
        let round_r = (self.round_r + STEP_ROUNDING) * ROUND_UP;
        // The same against the per-frame matrices as given (the pair's
        // truth, module docs): none on the first step, which composes
        // with the identity exactly (`1 x + 0 y + 0 z = x` in `f32`).
        let (pair_t, pair_r) =
            if self.pair_r == 0.0 && self.r == Chain::IDENTITY.r && self.t == [0.0; 3] {
                (0.0, 0.0)
            } else {
                (
                    (self.pair_t
                        + PAIR_T_ROUNDING * (norm1(self.t) + norm1(t2))
                        + self.pair_r * norm1(t2))
                        * ROUND_UP,
                    (self.pair_r + PAIR_R_ROUNDING) * ROUND_UP,
                )
            };
        if !(b.any() || self.delta > 0.0 || self.omega > 0.0) {
            return Chain {
                t,
                r,
                round_t,
                round_r,
                pair_t,
                pair_r,
                ..*self
            };
        }
        // The first step from the key frame (no error so far, the
        // identity's orientation): the composed motion is the step's own
        // (`1 x + 0 y + 0 z = x`), and so are its bounds, exactly. (The
        // sums below, rounded up, gave the first partner bounds above the
        // step's own, and a step's bounds at a configuration's limit,
        // rotation errors summing to 0.1 rad, started a new key frame
        // every frame: an adversary's find.)
        if self.delta == 0.0
            && self.omega == 0.0
            && self.eps == [0.0; 3]
            && self.r == Chain::IDENTITY.r
        {
            return Chain {
                t,
                r,
                delta: b.delta,
                eps: b.eps,
                omega: b.omega,
                round_t,
                round_r,
                pair_t,
                pair_r,
            };
        }
        let a = self.omega * (norm(t2) + SQRT3 * b.delta) + b.delta;
        let row = self
            .r
            .iter()
            .map(|[x, y, z]| x.abs() + y.abs() + z.abs())
            .fold(0.0f32, |m, s| if s > m { s } else { m });
        let delta = (self.delta + a * row) * ROUND_UP;
        let mut eps = [0.0f32; 3];
        for (k, e) in eps.iter_mut().enumerate() {
            let mut s = b.eps.get(k).copied().unwrap_or(0.0) + self.omega * b.omega;
            for (l, row) in r2.iter().enumerate() {
                let rlk = row.get(k).copied().unwrap_or(0.0);
                s += rlk.abs() * self.eps.get(l).copied().unwrap_or(0.0);
            }
            *e = s * ROUND_UP;
        }
        Chain {
            t,
            r,
            delta,
            eps,
            omega: (self.omega + b.omega) * ROUND_UP,
            round_t,
            round_r,
            pair_t,
            pair_r,
        }
    }

    /// How far the composed motion may be from the per-frame matrices'
    /// exact composition by its `f32` rounding, for the processor
    /// (`Processor::process_composed_within`), not yet in any
    /// configuration ([`Chain::config`] decides where it goes).
    pub(crate) fn rounding(&self) -> Rounding {
        Rounding {
            translation: self.pair_t,
            matrix: self.pair_r,
            in_config: false,
        }
    }

    /// The composed motion, for the processor.
    pub(crate) fn motion(&self) -> Result<Motion, MotionError> {
        Motion::from_matrix(self.t, self.r)
    }

    /// `base` with the composed error bounds in place of the per-frame
    /// ones (`base` itself when there are none), and the composition's
    /// rounding as the processor is to carry it ([`Chain::rounding`]).
    /// Where it could move `W'` by a quarter of itself or more
    /// (translations that cancel), or `W'` is under half of `|T|` (the
    /// focus more than about `1.7 f` out: a nearly sideways motion, where
    /// the focus's error, `|d|/|W'|` times `T'`'s, is looser than the
    /// turn of the lines, `T'`'s over `|T'|`), the error of `T'` goes
    /// into the configuration's translation error instead (on each
    /// component, the box holding every vector that long), and the band
    /// path carries it. (Until a review found sideways drives no longer fused, such a
    /// pair was refused and a new key frame started.) A bound the
    /// configuration does not accept is an error (a new key frame).
    pub(crate) fn config(&self, base: &Config) -> Result<(Config, Rounding), ConfigError> {
        let with_bounds = if self.delta > 0.0 || self.omega > 0.0 {
            base.with_translation_error(self.delta)?
                .with_rotation_error(self.eps)?
        } else {
            *base
        };
        let rounding = self.rounding();
        if rounding == Rounding::NONE {
            return Ok((with_bounds, rounding));
        }
        // `W' = (Rᵀ T)_z`, against `T'`'s error from the rounding.
        let w = self.r[0][2] * self.t[0] + self.r[1][2] * self.t[1] + self.r[2][2] * self.t[2];
        let dt = crate::epipolar::composition_dt(norm(self.t), self.pair_t, self.pair_r);
        // (A NaN fails.)
        if dt < 0.25 * w.abs() && w.abs() >= 0.5 * norm(self.t) {
            return Ok((with_bounds, rounding));
        }
        let config = with_bounds.with_translation_error(self.delta + dt * 1.01)?;
        Ok((
            config,
            Rounding {
                in_config: true,
                ..rounding
            },
        ))
    }

    /// The current frame's pose of key-frame points, `P = A P_K + b`
    /// (`A = Rᵀ`, `b = −Rᵀ T`), and the error bound of a carried point,
    /// `ρ + φ |P_K|`: `ρ = √3 δ + ω |T|`, `φ = ω` (the true point is
    /// `Ωᵀ Rᵀ (P_K − T − d)`, off by at most `ω |P_K − T| + |d|`), plus the
    /// composition's rounding (module docs) and that of `b` itself: `T`'s
    /// own error `round_t`, `R`'s error `round_r` turning `T`, and the
    /// product's rounding, `2⁻¹⁸ |T|₁`.
    pub(crate) fn pose(&self) -> (Mat3, [f32; 3], f32, f32) {
        let a = mat3_transpose(&self.r);
        let at = mat3_vec(&a, self.t);
        let bounds = if self.delta > 0.0 || self.omega > 0.0 {
            (SQRT3 * self.delta + self.omega * norm(self.t)) * ROUND_UP
        } else {
            0.0
        };
        let rho = bounds
            + (self.round_t + (2.0 * STEP_ROUNDING + self.round_r) * norm1(self.t)) * ROUND_UP;
        (a, [-at[0], -at[1], -at[2]], rho, self.omega + self.round_r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;

    fn rot(axis: usize, a: f32) -> Mat3 {
        let (s, c) = (libm::sinf(a), libm::cosf(a));
        match axis {
            0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
            1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
            _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    /// The rotation with vector `w` (Rodrigues), in `f32`.
    #[allow(clippy::needless_range_loop)]
    fn exp(w: [f32; 3]) -> Mat3 {
        let th = libm::sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        if th == 0.0 {
            return Chain::IDENTITY.r;
        }
        let k = [w[0] / th, w[1] / th, w[2] / th];
        let (s, c) = (libm::sinf(th), libm::cosf(th));
        let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
        let mut m = Chain::IDENTITY.r;
        let kk = mat3_mul(&kx, &kx);
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += s * kx[i][j] + (1.0 - c) * kk[i][j];
            }
        }
        m
    }

    /// The rotation vector of a rotation matrix (log map, small angles).
    fn log(m: &Mat3) -> [f32; 3] {
        let tr = m[0][0] + m[1][1] + m[2][2];
        let th = libm::acosf(((tr - 1.0) / 2.0).clamp(-1.0, 1.0));
        let f = if th < 1e-6 {
            0.5
        } else {
            th / (2.0 * libm::sinf(th))
        };
        [
            f * (m[2][1] - m[1][2]),
            f * (m[0][2] - m[2][0]),
            f * (m[1][0] - m[0][1]),
        ]
    }

    /// Random motions, each perturbed inside its error box: the composed
    /// truth stays inside the composed bounds.
    #[test]
    #[allow(clippy::needless_range_loop)]
    fn composed_bounds_hold_for_perturbed_chains() {
        let mut g = Rng(0xC0FF_EE11);
        let base = Config::DEFAULT
            .with_translation_error(0.02)
            .unwrap()
            .with_rotation_error([0.002, 0.003, 0.001])
            .unwrap();
        let b = StepBounds::of(&base);
        let mut worst = [0.0f32; 2];
        for _ in 0..300 {
            let mut chain = Chain::IDENTITY;
            let (mut tt, mut rt) = ([0.0f32; 3], Chain::IDENTITY.r);
            for _ in 0..8 {
                let mut u = || 2.0 * g.next() - 1.0;
                let m = Motion::new(
                    [0.1 * u(), 0.1 * u(), 0.4 + 0.1 * u()],
                    [0.02 * u(), 0.08 * u(), 0.02 * u()],
                )
                .unwrap();
                chain = chain.then(&m, &b);
                // The truth: the translation off by up to δ per component,
                // the rotation by a vector inside the ε box (about the new axes).
                let d = [b.delta * u(), b.delta * u(), b.delta * u()];
                let w = [b.eps[0] * u(), b.eps[1] * u(), b.eps[2] * u()];
                let t2 = m.translation();
                let t2 = [t2[0] + d[0], t2[1] + d[1], t2[2] + d[2]];
                let r2 = mat3_mul(&m.rotation_matrix(), &exp(w));
                let add = mat3_vec(&rt, t2);
                tt = [tt[0] + add[0], tt[1] + add[1], tt[2] + add[2]];
                rt = mat3_mul(&rt, &r2);
                for (x, y) in tt.iter().zip(chain.t) {
                    let off = (x - y).abs();
                    worst[0] = worst[0].max(off / chain.delta);
                    assert!(off <= chain.delta, "translation {off} > {}", chain.delta);
                }
                let err = log(&mat3_mul(&mat3_transpose(&chain.r), &rt));
                for k in 0..3 {
                    // (f32 rounding of the test's own products: 2e-6.)
                    worst[1] = worst[1].max(err[k].abs() / chain.eps[k]);
                    assert!(
                        err[k].abs() <= chain.eps[k] + 2e-6,
                        "{err:?} {:?}",
                        chain.eps
                    );
                }
            }
        }
        // Not vacuous: the truth comes within a factor of the bounds.
        assert!(worst[0] > 0.3 && worst[1] > 0.3, "{worst:?}");
        let _ = rot(0, 0.0);
    }

    #[test]
    fn no_bounds_stay_zero_and_the_config_is_the_base() {
        let b = StepBounds::of(&Config::DEFAULT);
        assert!(!b.any());
        let m = Motion::new([0.0, 0.0, 0.4], [0.0, 0.05, 0.0]).unwrap();
        let c = Chain::IDENTITY.then(&m, &b).then(&m, &b);
        assert_eq!((c.delta, c.eps, c.omega), (0.0, [0.0; 3], 0.0));
        // (The base configuration, and the rounding the processor carries:
        // forward, so not in the configuration.)
        let (cfg, rounding) = c.config(&Config::DEFAULT).unwrap();
        assert_eq!(cfg, Config::DEFAULT);
        assert!(!rounding.in_config && rounding.translation > 0.0 && rounding.matrix > 0.0);
        // Only the composition's rounding (module docs): two steps' worth,
        // `2⁻¹⁸ (0 + 0.4) + 2⁻¹⁸ (0.4 + 0.4) + 2⁻¹⁹ · 0.4` in `T` (`S =
        // 2⁻¹⁹`: `2 S · 1.4`), and `(2⁻¹⁸ + 2 · 2⁻¹⁹) |T|₁ = 4 S |T|₁` more
        // in `b`, each rounded up by at most `2⁻¹⁶`.
        let (_, _, rho, phi) = c.pose();
        assert!(
            (2.0 * STEP_ROUNDING..2.001 * STEP_ROUNDING).contains(&phi),
            "{phi}"
        );
        let want = STEP_ROUNDING * (2.0 * 1.4 + 4.0 * norm1(c.t));
        assert!(
            (want * 0.999..=want * 1.01).contains(&rho),
            "{rho} against {want}"
        );
        // The composed motion is the motions' composition.
        let two = m.then(&m).unwrap();
        assert_eq!(c.motion().unwrap().translation(), two.translation());
        assert_eq!(c.motion().unwrap().rotation_matrix(), two.rotation_matrix());
        let r = rot(1, 0.1);
        for (x, y) in r.iter().flatten().zip(c.r.iter().flatten()) {
            assert!((x - y).abs() < 1e-6);
        }
    }

    /// Bounds at a configuration's limit (rotation errors summing to 0.1
    /// rad, the largest translation error) still pair the key frame's
    /// first partner: its bounds are the step's own, not rounded past
    /// the limit (an adversary's find: every frame a new key frame,
    /// `ErrorLimit`, nothing fused). The second partner's composed
    /// rotation bound is past the limit, as it must be.
    #[test]
    fn bounds_at_the_limit_pair_the_first_partner() {
        let m = Motion::new([0.1, 0.0, 0.4], [0.01, 0.02, 0.03]).unwrap();
        let limit = crate::math::MAX_TRANSLATION;
        for eps in [[0.0, 0.1, 0.0], [0.05, 0.03, 0.02], [0.1, 0.0, 0.0]] {
            let base = Config::DEFAULT
                .with_translation_error(limit)
                .unwrap()
                .with_rotation_error(eps)
                .unwrap();
            let b = StepBounds::of(&base);
            let c = Chain::IDENTITY.then(&m, &b);
            let (cfg, _) = c.config(&base).unwrap();
            assert_eq!(cfg.rotation_error(), eps);
            assert!(c.then(&m, &b).config(&base).is_err());
        }
        // After steps without bounds (the orientation no longer the
        // identity) the sums are rounded up as any: the translation bound
        // holds the step's turned by the orientation.
        let none = StepBounds::of(&Config::DEFAULT);
        let base = Config::DEFAULT
            .with_translation_error(0.01)
            .unwrap()
            .with_rotation_error([0.0, 0.05, 0.0])
            .unwrap();
        let b = StepBounds::of(&base);
        let c = Chain::IDENTITY.then(&m, &none).then(&m, &b);
        assert!(c.eps[1] > b.eps[1], "{:?}", c.eps);
        assert!(c.delta > 0.01, "{}", c.delta);
        // A turn too small for a row's `f32` sum to leave 1 (3·10⁻⁸ rad
        // about `z`) still turns the translation error into more than
        // itself: rounded up (a review's find).
        let tiny = Motion::new([0.0, 0.0, 0.4], [0.0, 0.0, 3.0e-8]).unwrap();
        let c = Chain::IDENTITY.then(&tiny, &none).then(&m, &b);
        assert!(c.delta > 0.01, "{}", c.delta);
    }

    #[test]
    fn first_partner_has_the_per_frame_bounds_and_they_grow() {
        let base = Config::DEFAULT
            .with_translation_error(0.02)
            .unwrap()
            .with_rotation_error([0.004, 0.004, 0.004])
            .unwrap();
        let b = StepBounds::of(&base);
        let m = Motion::new([0.0, 0.0, 0.4], [0.0, 0.02, 0.0]).unwrap();
        let mut c = Chain::IDENTITY.then(&m, &b);
        // Exactly the step's own (the composition with the key frame's
        // identity is exact).
        assert_eq!((c.delta, c.eps, c.omega), (b.delta, b.eps, b.omega));
        let (cfg, _) = c.config(&base).unwrap();
        assert!(cfg.translation_error() >= 0.02);
        let mut frames = 1;
        // The rotation bounds sum past what a Config accepts (0.1 rad)
        // after about 8 frames here: that ends a key frame.
        while c.config(&base).is_ok() {
            c = c.then(&m, &b);
            frames += 1;
            assert!(frames < 20);
        }
        assert!((7..=10).contains(&frames), "{frames}");
    }
}
