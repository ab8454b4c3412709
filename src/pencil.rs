//! How the epipolar lines of a frame pair, which all pass through the
//! focus of expansion, are told apart by one number: the *key* of the ray
//! from the FOE through a point.
//!
//! A key is a strictly monotone function of the ray's direction about the
//! FOE (or, for a FOE at infinity, of its offset), so a boundary segment can
//! only meet a ray whose key lies between the keys of the segment's end
//! points, and a region of the image spanning an angle `δ` about the FOE
//! maps to a key interval. Three forms, chosen per frame-2 boundary:
//!
//! * [`Pencil::Half`]: the FOE is near the image and the boundary lies
//!   wholly above or below its row (the usual road scene: the FOE near the
//!   horizon, the boundaries below it): `d_u / (|d_u| + t)` with
//!   `d = q − FOE`, `t = side · d_v > 0`. No quadrants, never wraps.
//! * [`Pencil::Angular`]: the FOE is near the image and the boundary comes
//!   close to its row: the pseudo-angle of `q − FOE` in `[0, 4)`, which
//!   wraps once a turn (keys along a boundary are unwrapped by multiples of
//!   4).
//! * [`Pencil::Projective`]: the FOE is at least two image reaches from the
//!   principal point, or at infinity (`W' = 0`): where the ray crosses the
//!   reference line through `c₂` perpendicular to `g = (f_x U', f_y V')`, in
//!   pixels along it. For `W' = 0` this is the lines' common offset.
//!
//! Both angular forms change by at most one key unit per radian of ray
//! direction (`d/dθ [sin θ/(|sin θ| + cos θ)] = 1/(|sin θ| + cos θ)² ≤ 1`,
//! the same for the pseudo-angle), which is how a band of angular half-width
//! `δ` becomes the key interval `[k − tan δ, k + tan δ]`.
//!
//! # Rounding margins
//! A key computed in `f32` differs from the exact key of the same input
//! point by at most its margin, which [`Keying::key`] returns with it. With
//! every coordinate below `S` in magnitude (the frame's
//! [`crate::epipolar::PairGeometry::coordinate_scale`]), `d = q − FOE` is
//! rounded by at most `2⁻²³ S` per component. The half-plane key
//! `d_u · (1/D)`, `D = |d_u| + t`, has a gradient of at most `1/D` per
//! component and three roundings of its own (`3 · 2⁻²⁴`), so its error is
//! below `2⁻²² (S/D + 1)`; its margin is four times that, `2⁻²⁰ (S/D + 1)`.
//! The pseudo-angle (`D = |d_u| + |d_v|`, one more rounding for its
//! quadrant offset) gets `2⁻²⁰ (S/D + 4)`. The projective key (a ratio
//! whose denominator stays above half its value over the image) moves by at
//! most `2⁻¹⁹ S (S / reach + 1)` anywhere; its margin is `2⁻¹⁸ S (S / reach
//! + 4)` for every point. So a key far from the FOE is known to about
//! `2⁻²⁰`, one next to it coarsely: the fold test and the index widen each
//! vertex's key by its own margin. The unit test `keys_are_within_their_margin`
//! checks the margins against keys computed in `f64`.

use crate::math::{dot, fmax, fmin, sub};

/// "No key": the point is too close to the FOE (or its row) to be keyed
/// reliably, or is not a finite point.
pub(crate) const NO_KEY: f32 = f32::INFINITY;

/// The smallest distance from the FOE's row of a point with a half-plane
/// key, at least this many pixels (more for large coordinates).
const HALF_MIN_T: f32 = 4.0;
/// A frame-2 boundary gets half-plane keys when it keeps at least this far
/// from the FOE's row (pixels; at least four times the keys' `t_min`).
const HALF_MARGIN: f32 = 16.0;
/// The smallest distance from the FOE of a point with a pseudo-angle key.
const ANGULAR_MIN_D: f32 = 1.0;

/// How lines through the FOE are keyed (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) enum Pencil {
    /// Half-plane key.
    Half {
        /// Focus of expansion, frame-2 pixels.
        foe: [f32; 2],
        /// +1 when the keyed points lie below the FOE (larger `v`), −1 above.
        side: f32,
        /// The smallest `t` with a key, pixels.
        min_t: f32,
    },
    /// Pseudo-angle key.
    Angular {
        /// Focus of expansion, frame-2 pixels.
        foe: [f32; 2],
    },
    /// Projective key.
    Projective {
        /// Principal point of frame 2.
        c: [f32; 2],
        /// Unit vector along `g`.
        g_hat: [f32; 2],
        /// `|g|`.
        g_norm: f32,
        /// `W'`.
        w: f32,
    },
}

/// The keying of one frame pair's lines for one frame-2 boundary: the form
/// and its rounding margin.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Keying {
    pub(crate) pencil: Pencil,
    /// The largest rounding margin of any key (see the module docs).
    pub(crate) eps: f32,
    /// `2⁻²⁰ S`: a direction key at distance `D` (its `D`) from the FOE has
    /// the margin `key_scale / D + 4 · 2⁻²⁰` at most.
    pub(crate) key_scale: f32,
    /// 4 for pseudo-angles (keys repeat every turn), 0 otherwise.
    pub(crate) period: f32,
}

/// `2⁻²⁰`.
const ULP20: f32 = 9.536_743e-7;

impl Keying {
    /// The keying for a frame pair whose FOE is `foe` (`None` at infinity),
    /// `c2` the frame-2 principal point, `g = (f_x U', f_y V')`, `w = W'`,
    /// `reach` the largest distance from `c2` to the frame-2 image (with
    /// its margin) and `scale` the coordinate scale `S`, for a frame-2
    /// boundary whose rows run between `rows.0` and `rows.1` (`None`: no
    /// such boundary).
    pub(crate) fn choose(
        foe: Option<[f32; 2]>,
        (c2, g, w): ([f32; 2], [f32; 2], f32),
        reach: f32,
        scale: f32,
        rows: Option<(f32, f32)>,
    ) -> Self {
        // Projective when the FOE is at least two reaches away (or at
        // infinity): `|g| ≥ 2 |W'| reach`, squared.
        let g2 = dot(g, g);
        let near = match foe {
            Some(f) if 4.0 * (w * w) * (reach * reach) > g2 => Some(f),
            _ => None,
        };
        let Some(foe) = near else {
            let g_norm = crate::math::sqrt(g2);
            // (g2 > 0 here: with g = 0 the FOE is the principal point, near.)
            let inv = if g_norm > 0.0 { 1.0 / g_norm } else { 0.0 };
            return Self {
                pencil: Pencil::Projective {
                    c: c2,
                    g_hat: [g[0] * inv, g[1] * inv],
                    g_norm,
                    w,
                },
                eps: 3.82e-6 * scale * (scale / fmax(reach, 1.0) + 4.0),
                key_scale: 0.0,
                period: 0.0,
            };
        };
        // The FOE is within two reaches of c2: |foe| ≤ |c2| + 2 reach ≤ 3 S.
        let scale = fmax(scale, fmax(foe[0].abs(), foe[1].abs()));
        let min_t = fmax(HALF_MIN_T, scale * (1.0 / 256.0));
        let need = fmax(HALF_MARGIN, 4.0 * min_t);
        let side = rows.and_then(|(a, b)| {
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            if lo - foe[1] >= need {
                Some(1.0)
            } else if foe[1] - hi >= need {
                Some(-1.0)
            } else {
                None
            }
        });
        match side {
            Some(side) => Self {
                pencil: Pencil::Half { foe, side, min_t },
                eps: ULP20 * (scale / min_t + 4.0),
                key_scale: ULP20 * scale,
                period: 0.0,
            },
            None => Self {
                pencil: Pencil::Angular { foe },
                eps: ULP20 * (scale / ANGULAR_MIN_D + 4.0),
                key_scale: ULP20 * scale,
                period: 4.0,
            },
        }
    }

    /// The key of the ray from the FOE through `q` and its rounding
    /// margin, or [`NO_KEY`] (and 0).
    #[inline(always)]
    pub(crate) fn key(&self, q: [f32; 2]) -> (f32, f32) {
        match self.pencil {
            Pencil::Half { foe, side, min_t } => half_key(q, (foe, side, min_t), self.key_scale),
            Pencil::Angular { foe } => {
                let d = sub(q, foe);
                // NaN fails the test too.
                if dot(d, d) >= ANGULAR_MIN_D * ANGULAR_MIN_D {
                    let (k, inv) = pseudo_angle_with_inverse(d);
                    (k, self.key_scale * inv + 4.0 * ULP20)
                } else {
                    (NO_KEY, 0.0)
                }
            }
            Pencil::Projective {
                c,
                g_hat,
                g_norm,
                w,
            } => {
                let d = sub(q, c);
                let den = g_norm - w * dot(g_hat, d);
                if den >= 0.5 * g_norm && g_norm > 0.0 {
                    (g_norm * (g_hat[0] * d[1] - g_hat[1] * d[0]) / den, self.eps)
                } else {
                    (NO_KEY, 0.0)
                }
            }
        }
    }

    /// Whether the keys are direction keys with the Lipschitz property of
    /// the module docs (half-plane or pseudo-angle).
    pub(crate) fn angular(&self) -> bool {
        !matches!(self.pencil, Pencil::Projective { .. })
    }

    /// The key interval of the rays from the FOE at an angle of at most
    /// `atan(t)` from the ray through `p` (whose key is `k`, possibly
    /// [`NO_KEY`]), widened by `margin` (the rounding of `k`); `None` when no
    /// keyed point can lie on those rays. For the direction keys only.
    pub(crate) fn around(&self, p: [f32; 2], k: f32, t: f32, margin: f32) -> Option<(f32, f32)> {
        let m = t + margin;
        if k.is_finite() {
            return Some((k - m, k + m));
        }
        // The ray through p has no key of its own: a half-plane key's
        // point is within t_min of the FOE's row or beyond it, a
        // pseudo-angle's within a pixel of the FOE.
        let (foe, side) = match self.pencil {
            Pencil::Half { foe, side, .. } => (foe, Some(side)),
            Pencil::Angular { foe } => (foe, None),
            Pencil::Projective { .. } => return None,
        };
        let d = sub(p, foe);
        let n2 = dot(d, d);
        // (A NaN fails.)
        if !(n2 > 0.0) {
            return Some((f32::NEG_INFINITY, f32::INFINITY));
        }
        let Some(side) = side else {
            // The pseudo-angle of d itself, with the margin `key` would
            // give it (valid at any distance from the FOE).
            let (k, inv) = pseudo_angle_with_inverse(d);
            let m = t + (self.key_scale * inv + 4.0 * ULP20);
            return Some((k - m, k + m));
        };
        // The rays within atan t of d (less than a half-turn in all) meet
        // the half-plane in one arc, whose ends are edge directions
        // d ± t·perp(d) inside the half-plane or the row's directions
        // (keys −1 and +1, left and right) inside the wedge: the key range
        // spans those ends.
        let perp = [-d[1], d[0]];
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for s in [-1.0f32, 1.0] {
            let e = [d[0] + s * t * perp[0], d[1] + s * t * perp[1]];
            let tt = side * e[1];
            if tt > 0.0 {
                let key = e[0] / (e[0].abs() + tt);
                (lo, hi) = (fmin(lo, key), fmax(hi, key));
            }
        }
        // The row's direction (±1, 0) is within atan t of d when its cosine
        // to d, ±d_u/|d|, is at least 1/√(1 + t²) (a little lower, for
        // rounding).
        let within = d[0] * d[0] * (1.0 + t * t) * (1.0 + 1.0e-5) >= n2;
        for (row, key) in [(d[0] > 0.0, 1.0f32), (d[0] < 0.0, -1.0)] {
            if within && row {
                (lo, hi) = (fmin(lo, key), fmax(hi, key));
            }
        }
        // (Empty: the rays miss the half-plane.)
        (lo <= hi).then_some((lo - self.eps, hi + self.eps))
    }
}

/// The half-plane key of `q` ([`Pencil::Half`] with these fields) and its
/// margin, or [`NO_KEY`] (and 0). For a finite `q − foe` (and `min_t >
/// 0`, as [`Keying::choose`] makes it) a key is `d_u / (|d_u| + t)` with
/// `t ≥ min_t`: finite and at most 1 in magnitude (and a rounding). The
/// callers' `q` is a validated pixel (within the image's margin) or step
/// 1's compensated point on a certified pair (within three image sizes,
/// `certifies_image`), and a half-plane keying's FOE is within two
/// reaches of the principal point ([`Keying::choose`]), so `q − foe` is
/// finite there; an infinite `q` would give a NaN key, not `NO_KEY`.
#[inline(always)]
pub(crate) fn half_key(q: [f32; 2], pencil: ([f32; 2], f32, f32), key_scale: f32) -> (f32, f32) {
    half_key_or_none(q, pencil, key_scale).unwrap_or((NO_KEY, 0.0))
}

/// [`half_key`], `None` where it gives [`NO_KEY`] (and 0): a caller that
/// leaves the unkeyed vertices to a path of their own asks where the key
/// is made, not of the key again.
#[inline(always)]
pub(crate) fn half_key_or_none(
    q: [f32; 2],
    (foe, side, min_t): ([f32; 2], f32, f32),
    key_scale: f32,
) -> Option<(f32, f32)> {
    let d = sub(q, foe);
    let t = side * d[1];
    // NaN fails the test too.
    if t >= min_t {
        let inv = 1.0 / (d[0].abs() + t);
        Some((d[0] * inv, key_scale * inv + ULP20))
    } else {
        None
    }
}

/// The pseudo-angle of a non-zero `d` (by a reciprocal: with `d` turned so
/// that "up" is the `+x` axis, `p = y/(|x| + |y|)`, placed by half-plane
/// as `p`, `4 + p` or `2 − p`, in `[0, 4)` up to rounding) and that
/// reciprocal, `1/(|d_u| + |d_v|)`.
#[inline(always)]
fn pseudo_angle_with_inverse(d: [f32; 2]) -> (f32, f32) {
    // Rotate so that "up" (0,-1) becomes the +x axis: (x, y) -> (-y, x).
    let (x, y) = (-d[1], d[0]);
    let inv = 1.0 / (x.abs() + y.abs());
    let p = y * inv; // in [-1, 1]
    let k = if x >= 0.0 {
        if y >= 0.0 {
            p
        } else {
            4.0 + p
        }
    } else {
        2.0 - p
    };
    (k, inv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;
    extern crate std;

    /// The exact key of the same `f32` input point, in `f64`.
    fn exact(k: &Keying, q: [f32; 2]) -> Option<f64> {
        let q = [f64::from(q[0]), f64::from(q[1])];
        match k.pencil {
            Pencil::Half { foe, side, min_t } => {
                let d = [q[0] - f64::from(foe[0]), q[1] - f64::from(foe[1])];
                let t = f64::from(side) * d[1];
                (t >= f64::from(min_t) * 1.001).then(|| d[0] / (d[0].abs() + t))
            }
            Pencil::Angular { foe } => {
                let d = [q[0] - f64::from(foe[0]), q[1] - f64::from(foe[1])];
                if d[0] * d[0] + d[1] * d[1] < 1.002 {
                    return None;
                }
                let (x, y) = (-d[1], d[0]);
                let p = y / (x.abs() + y.abs());
                Some(if x >= 0.0 {
                    if y >= 0.0 {
                        p
                    } else {
                        4.0 + p
                    }
                } else {
                    2.0 - p
                })
            }
            Pencil::Projective {
                c,
                g_hat,
                g_norm,
                w,
            } => {
                let d = [q[0] - f64::from(c[0]), q[1] - f64::from(c[1])];
                let (gh, gn, w) = (
                    [f64::from(g_hat[0]), f64::from(g_hat[1])],
                    f64::from(g_norm),
                    f64::from(w),
                );
                let den = gn - w * (gh[0] * d[0] + gh[1] * d[1]);
                (den >= 0.501 * gn).then(|| gn * (gh[0] * d[1] - gh[1] * d[0]) / den)
            }
        }
    }

    #[test]
    fn pseudo_angle_is_monotone_in_the_true_angle() {
        let mut last = -1.0;
        for i in 0..3600 {
            // True angle measured from "up", clockwise on screen.
            let t = (i as f32) * core::f32::consts::PI * 2.0 / 3600.0;
            let (p, _) = pseudo_angle_with_inverse([libm::sinf(t), -libm::cosf(t)]);
            assert!(p > last, "not increasing at step {i}: {p} <= {last}");
            assert!((0.0..4.0).contains(&p));
            last = p;
        }
        let card = |d| pseudo_angle_with_inverse(d).0;
        assert_eq!(card([0.0, -1.0]), 0.0);
        assert_eq!(card([1.0, 0.0]), 1.0);
        assert_eq!(card([0.0, 1.0]), 2.0);
        assert_eq!(card([-1.0, 0.0]), 3.0);
    }

    /// Keys computed in `f32` are within [`Keying::eps`] of the exact keys
    /// of the same points, for all three forms, FOEs near and far, points
    /// anywhere the processor accepts (the frame-2 image grown by its
    /// size) and images up to the largest accepted size.
    #[test]
    fn keys_are_within_their_margin() {
        let mut rng = Rng(0x6b65_7973);
        let mut checked = [0usize; 3];
        for case in 0..3000 {
            let (w2, h2) = if case % 3 == 0 {
                (16384.0f32, 16384.0f32)
            } else {
                (512.0, 480.0)
            };
            let c2 = [w2 * rng.next(), h2 * rng.next()];
            let reach = (w2 * w2 + h2 * h2).sqrt();
            let scale = 2.0 * w2.max(h2);
            let g = [(rng.next() - 0.5) * 2000.0, (rng.next() - 0.5) * 2000.0];
            let w = match case % 4 {
                0 => 0.0,
                1 => (rng.next() - 0.5) * 1e-3,
                _ => (rng.next() - 0.5) * 4.0,
            };
            let foe = (w != 0.0).then(|| [c2[0] + g[0] / w, c2[1] + g[1] / w]);
            let row = rng.next() * h2;
            let rows = Some((row, row + rng.next() * h2));
            let k = Keying::choose(foe, (c2, g, w), reach, scale, rows);
            let form = match k.pencil {
                Pencil::Half { .. } => 0,
                Pencil::Angular { .. } => 1,
                Pencil::Projective { .. } => 2,
            };
            for _ in 0..50 {
                let q = [-w2 + 3.0 * w2 * rng.next(), -h2 + 3.0 * h2 * rng.next()];
                let (got, margin) = k.key(q);
                let Some(want) = exact(&k, q) else { continue };
                if !got.is_finite() {
                    continue;
                }
                let mut err = (f64::from(got) - want).abs();
                if k.period > 0.0 {
                    err = err.min((err - 4.0).abs());
                }
                assert!(
                    err <= f64::from(margin) && margin <= k.eps,
                    "case {case} form {form}: key {got} vs {want}, err {err} > {margin}"
                );
                checked[form] += 1;
            }
        }
        assert!(checked.iter().all(|&c| c > 10_000), "{checked:?}");
    }

    /// `Keying::around` for a point without a key of its own (beyond or
    /// near the FOE's row for half-plane keys, within a pixel of the FOE
    /// for pseudo-angles) holds the exact key of every direction within
    /// `atan t` of the point's, for narrow and very wide wedges (`f64`).
    #[test]
    fn around_holds_every_direction_of_the_wedge() {
        let mut rng = Rng(0xa20d_0003);
        let mut checked = 0;
        for case in 0..20_000 {
            let foe = [512.0 * rng.next(), 480.0 * rng.next()];
            let half = case % 2 == 0;
            let side = if rng.next() < 0.5 { 1.0 } else { -1.0 };
            let keying = Keying {
                pencil: if half {
                    Pencil::Half {
                        foe,
                        side,
                        min_t: 4.0,
                    }
                } else {
                    Pencil::Angular { foe }
                },
                eps: ULP20 * (1024.0 / 4.0 + 4.0),
                key_scale: ULP20 * 1024.0,
                period: if half { 0.0 } else { 4.0 },
            };
            // A point with no key: for half-plane keys within t_min of the
            // row or beyond it; for pseudo-angles within a pixel of the FOE.
            let ang = rng.next() * core::f32::consts::TAU;
            let r = if half {
                3.0 + 60.0 * rng.next()
            } else {
                0.05 + 0.9 * rng.next()
            };
            let p = [foe[0] + r * libm::cosf(ang), foe[1] + r * libm::sinf(ang)];
            let (k, _) = keying.key(p);
            if k.is_finite() {
                continue;
            }
            let t = if rng.next() < 0.5 {
                0.01 * rng.next()
            } else {
                5.0 * rng.next()
            };
            let range = keying.around(p, k, t, 0.0);
            let d = [f64::from(p[0] - foe[0]), f64::from(p[1] - foe[1])];
            let a0 = d[1].atan2(d[0]);
            let half_angle = f64::from(t).atan() * 0.9999;
            for i in 0..=64 {
                let a = a0 + half_angle * (f64::from(i) / 32.0 - 1.0);
                let q = [
                    f64::from(foe[0]) + 100.0 * a.cos(),
                    f64::from(foe[1]) + 100.0 * a.sin(),
                ];
                let qf = [q[0] as f32, q[1] as f32];
                let Some(ke) = exact(&keying, qf) else {
                    continue;
                };
                assert!(
                    range.is_some(),
                    "case {case}: no range, but key {ke} of a direction in the wedge"
                );
                let (lo, hi) = range.unwrap_or((0.0, 0.0));
                let inside = (-2..=2).any(|m| {
                    let kk = ke + 4.0 * f64::from(m) * f64::from(u8::from(!half));
                    kk >= f64::from(lo) - 1e-6 && kk <= f64::from(hi) + 1e-6
                });
                assert!(
                    inside,
                    "case {case}: key {ke} outside [{lo}, {hi}] (t {t}, half {half})"
                );
                checked += 1;
            }
        }
        assert!(checked > 100_000, "{checked}");
    }
}
