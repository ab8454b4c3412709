//! Triangulation (eqs. 2.1–2.3) and the error interval, the "stick" of
//! Sec. 4.1, extended to a guaranteed bound.
//!
//! # Depth from the disparity (eq. 2.3, general `(U, V, W)`)
//! With the notation of [`crate::epipolar`], the frame-2 point is
//! `p₂ = p₁' + τ a` and `τ = 1/(s − W')`, hence
//!
//! `s = W' + 1/τ`,   `Z = s / q_z`,   `X = x₁ Z`, `Y = y₁ Z`
//!
//! where `(x₁, y₁)` are the normalised frame-1 coordinates. This is eq. 2.3
//! solved in the least-squares sense along the disparity: `τ` is the
//! projection `(d · a)/|a|²` of the full 2-D disparity `d` on the epipolar
//! direction, so both components `d_x`, `d_y` contribute, each in proportion
//! to its share of the line's direction, instead of picking the `x` or `y`
//! form of eq. 2.3 (either of which is ill-conditioned when its component
//! is small). Without rotation and with `f_x = f_y = f` it reduces to eq. 2.3
//! exactly.
//!
//! The processor evaluates it as `s = W' + |a|/D` with the disparity
//! length `D = τ|a|` (the same value, one rounding more), because the
//! stick's ends below are that expression with `|a| ± |W'|r₁` and `D ∓ …`:
//! IEEE `+ − × ÷` are monotone in each argument, so the rounded stick
//! holds the rounded depth with no clamp.
//!
//! # The stick, guaranteed
//! The paper bounds the depth by a disparity error `e = e₁ + e₂` along `y`.
//! Here both localisation errors are discs (any direction):
//!
//! * frame 1: the true point is within `e₁` pixels of `p₁`; after rotation
//!   compensation within `r₁ = e₁ · stretch` of `p₁'` (the homography's
//!   local stretch bound);
//! * frame 2: the true boundary is within `e₂` pixels of the polyline.
//!
//! Let `D = τ|a|` be the disparity length, `φ` the angle between the
//! epipolar line and the boundary at the intersection. Moving `p₁'` by at
//! most `r₁` moves the start of the disparity along the line by at most
//! `r₁`, changes `|a|` by at most `|W'| r₁`, and tilts the line about the FOE
//! so that at `p₂` it is displaced sideways by at most
//! `h₁ = r₁ (1 + W' τ)` (the ratio of the distances of `p₂` and `p₁'` from
//! the FOE; `r₁` when `W' = 0`). The true intersection lies where a line
//! within `h₁` of ours meets a curve within `e₂` of the polyline: a
//! parallelogram whose extent along the line is
//!
//! `δ₂ = (e₂ + h₁ |cos φ|) / sin φ`.
//!
//! This is the `1/sin φ` growth of the frame-2 error: a boundary crossed at
//! a flat angle localises the intersection poorly. The disparity thus lies
//! in `D ± ε` with `ε = r₁ + δ₂`, and since
//! `s = W' + (|a| ± |W'| r₁)/(D ∓ ε)` is monotone in both (for the sign of
//! `W'` at hand the extremes fall on the corners, which coincide with the
//! exact extremes of `s = W' ρ₂/(ρ₂ − ρ₁)` over the box of radial distances
//! from the FOE):
//!
//! `s_far = W' + (1 + |W'| r₁/|a|) / (τ − ε/|a|)`,
//! `s_near = W' + (1 − |W'| r₁/|a|) / (τ + ε/|a|)`.
//!
//! A sideways offset `h` of the true line also lengthens the true disparity,
//! by at most `h²/2(D − ε)`, which the near end allows for. When
//! `τ ≤ ε/|a|` the disparity is not larger than its error and the far end is
//! unbounded ([`crate::Status::Unbounded`]). The boundary direction
//! is measured over a chord of up to `2·CHORD_HALF_WINDOW + 1` points; the
//! error of that chord's direction (at most `2 e₂ / L` for a chord of length
//! `L`) is taken off `sin φ` before it is used, so the stick stays a bound;
//! an intersection with `sin φ` below the configured minimum is
//! [`crate::Status::Grazing`] and gets no depth. Without errors
//! (`e₁ = e₂ = 0`) the stick collapses to the point. For `e₂ ≪ D` and
//! `φ = 90°` the relative half-length is `≈ (e₁ + e₂)/D`: the paper's
//! `|ΔZ/Z| ≈ e/d` (Sec. 4.1.1).

use crate::camera::Pixel;
use crate::math::{cross, dot, fmax, sqrt_pos, sub};

/// Half-width, in points, of the chord used to measure the boundary direction.
pub const CHORD_HALF_WINDOW: usize = 4;

/// Depth interval along the frame-1 ray: every depth consistent with the
/// localisation errors lies in `[z_near, z_far]` (length unit of the motion).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DepthInterval {
    /// Nearest consistent depth `Z_near` (≥ 0).
    pub z_near: f32,
    /// Farthest consistent depth `Z_far`.
    pub z_far: f32,
}

/// Direction of the boundary around segment `j`: the chord between the
/// points `CHORD_HALF_WINDOW` before `j` and after `j + 1` (clamped).
#[inline(always)]
pub(crate) fn chord(boundary: &[Pixel], j: usize) -> [f32; 2] {
    // Away from the ends (the usual case): one bounds check for the window.
    if let Some(&[a, .., b]) = j
        .checked_sub(CHORD_HALF_WINDOW)
        .and_then(|i0| boundary.get(i0..i0 + 2 * CHORD_HALF_WINDOW + 2))
    {
        return sub(b.arr(), a.arr());
    }
    let last = boundary.len().saturating_sub(1);
    let i0 = j.saturating_sub(CHORD_HALF_WINDOW);
    let i1 = (j + 1 + CHORD_HALF_WINDOW).min(last);
    match (boundary.get(i0), boundary.get(i1)) {
        (Some(a), Some(b)) => sub(b.arr(), a.arr()),
        _ => [0.0, 0.0],
    }
}

/// Angle terms of an intersection: `(sin φ_low, |cos φ|)`, where `φ_low`
/// is the smallest angle consistent with the chord's own error.
///
/// `|cos φ|` may round above 1 only when `sin φ` is below 1.001e-3 (the
/// two are computed from the same `1/(|a| l)` with a few roundings each),
/// which is under the sine of the smallest minimum angle a [`crate::Config`]
/// accepts (0.1°, 1.745e-3): such a crossing is grazing, and its `cos` is
/// never used.
pub(crate) fn crossing_angle(a: [f32; 2], a_len: f32, chord: [f32; 2], e2: f32) -> (f32, f32) {
    let l2 = dot(chord, chord);
    // The chord of a validated boundary has l2 > 0 and a point away from
    // the FOE has a_len > 0. Anything else (l2 or a_len zero or not
    // finite) cannot pass the grazing test below: 0 · ∞ and ∞ − ∞ give a
    // NaN sin, and a zero chord gives `sin_low` ≤ 0; the processor flags
    // both `Grazing` (a NaN by its negated comparison).
    let l = sqrt_pos(l2);
    let inv = 1.0 / (a_len * l);
    let sin = cross(a, chord).abs() * inv;
    let cos = dot(a, chord).abs() * inv;
    (sin - 2.0 * e2 / l, cos)
}

/// The stick for a match at `tau` (see the module docs), also when each
/// component of the translation used may be off by up to `delta` (see
/// [`crate::Config::with_translation_error`]; `spread_a = spread_w = 0`
/// without translation error).
///
/// With the true translation anywhere in that box, `|a|` may differ from
/// ours by `spread_a` and `W'` by `spread_w`
/// ([`crate::motion_error`]); the true epipolar line is turned from ours by
/// an angle with `sin Δθ ≤ spread_a / |a|`, which at the intersection
/// displaces it sideways by up to `D_true sin Δθ`. With
/// `h = h₁ + (D + ε) sin Δθ` the along-line error is
/// `ε = r₁ + (e₂ + h |cos φ|)/sin φ`, solved for `ε` in closed form, and
///
/// `s_far = W'₊ + (|a| + |W'|₊ r₁ + spread_a) / (D − ε)`,
/// `s_near = W'₋ + (|a| − |W'|₊ r₁ − spread_a) / (D + ε + h²/2(D − ε))`
///
/// (the last term: a sideways offset lengthens the true disparity at most by
/// that much). `None` when the far end is unbounded.
#[allow(clippy::too_many_arguments)]
pub(crate) fn stick(
    w: f32,
    tau: f32,
    a_len: f32,
    r1: f32,
    e2: f32,
    sin_low: f32,
    cos: f32,
    depth_scale: f32,
    spread_a: f32,
    spread_w: f32,
) -> Option<DepthInterval> {
    if spread_a == 0.0 && spread_w == 0.0 {
        return stick_exact(w, tau, a_len, r1, e2, sin_low, cos, depth_scale);
    }
    let d = tau * a_len;
    let turn = spread_a / a_len; // ≥ sin of the angle between the lines
    if turn.is_nan() || turn >= 1.0 || turn * cos >= sin_low {
        return None;
    }
    let h1 = r1 * fmax(1.0 + (w + spread_w) * tau, 1.0 + (w - spread_w) * tau);
    let h1 = fmax(h1, 0.0);
    let eps = (r1 + (e2 + (h1 + d * turn) * cos) / sin_low) / (1.0 - turn * cos / sin_low);
    if d - eps <= 0.0 {
        return None;
    }
    let h = h1 + (d + eps) * turn;
    let w_abs = w.abs() + spread_w;
    let a_hi = a_len + w_abs * r1 + spread_a;
    let a_lo = fmax(a_len - w_abs * r1 - spread_a, 0.0);
    let s_far = (w + spread_w) + a_hi / (d - eps);
    let s_near = (w - spread_w) + a_lo / (d + eps + h * h / (2.0 * (d - eps)));
    interval(s_near, s_far, depth_scale)
}

/// [`stick`] without translation error: the same formulas with the
/// spreads at zero (the same bits), without the terms that vanish.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn stick_exact(
    w: f32,
    tau: f32,
    a_len: f32,
    r1: f32,
    e2: f32,
    sin_low: f32,
    cos: f32,
    depth_scale: f32,
) -> Option<DepthInterval> {
    let d = tau * a_len;
    let h1 = fmax(r1 * (1.0 + w * tau), 0.0);
    let eps = r1 + (e2 + h1 * cos) / sin_low;
    if d - eps <= 0.0 {
        return None;
    }
    let wr = w.abs() * r1;
    let s_far = w + (a_len + wr) / (d - eps);
    // `|a| > |W'| r₁` here: the processor flags a point whose disc holds the
    // FOE (`|a|² ≤ (|W'| max(r₁, 10⁻³))²`, `AtFoe`) before this. Within an
    // ulp of that guard `|a| − |W'| r₁` may round below zero; that only
    // lowers `s_near`, a longer stick, still a bound. (`stick` keeps the
    // clamp: its spreads can exceed the guard's margin.)
    let s_near = w + (a_len - wr) / (d + eps + h1 * h1 / (2.0 * (d - eps)));
    interval(s_near, s_far, depth_scale)
}

/// The stick from the ends in the compensated frame (`Z = s / q_z`).
#[inline]
fn interval(s_near: f32, s_far: f32, depth_scale: f32) -> Option<DepthInterval> {
    let z_far = s_far / depth_scale;
    let z_near = fmax(s_near / depth_scale, 0.0);
    (z_far.is_finite() && z_far >= z_near).then_some(DepthInterval { z_near, z_far })
}
