//! Disparity analysis of Section 3 and the tilt transform of Appendix I.
//!
//! Conventions as everywhere in the crate (`x` right, `y` **down**, `z`
//! forward). The *vehicle frame* has its origin at the camera centre, `x`
//! right, `y` down (perpendicular to the ground plane the vehicle stands
//! on), `z` forward along the ground; the camera is pitched **down** by the
//! tilt `θ` about `x`. The paper's Appendix I writes `y` up; with `y` down
//! its relations read
//!
//! `U_c = U_v`,  `V_c = V_v cos θ − W_v sin θ`,  `W_c = V_v sin θ + W_v cos θ`
//!
//! (the paper's `V_c = W sin θ + V cos θ`, `W_c = W cos θ − V sin θ` with
//! its `V` and `V_c` pointing up). A ground point at horizontal distance `Z`
//! and depth `h` below the camera has camera depth `Z_c = Z cos θ + h sin θ`
//! and `Y_c = h cos θ − Z sin θ` (the paper's `h_c`, sign for `y` down).
//!
//! Substituting these into eq. 2.2 gives eq. 3.2 (see [`disparity_tilted`]);
//! the host tests check it numerically over a grid of `θ`, `Z`, `W`.
//!
//! # Angles
//! Every angle argument (radians) is reduced correctly for any
//! `|angle| ≤` [`crate::MAX_ANGLE_RAD`] (a tilt of 6 rad is the tilt of
//! `6 − 2π`); a NaN, infinite or larger angle is an [`AngleError`]
//! (`host_tests/tests/angles.rs` checks every function at and beyond its
//! range against `f64`).

use crate::geometry::Range;
use crate::math::{atan, fmax, fmin, reduce_angle, sin_cos, sin_cos_reduced, AngleError};

/// Vehicle-frame translation `(U, V, W)` → camera frame, camera pitched
/// down by `tilt` radians (Appendix I).
///
/// ```
/// use roadstereo::analysis::vehicle_to_camera;
/// // Driving 1 unit straight ahead with the camera tilted 30° down: in the
/// // camera's axes the motion goes forward and up (negative y).
/// let [u, v, w] = vehicle_to_camera([0.0, 0.0, 1.0], 30f32.to_radians())?;
/// assert!(u == 0.0 && (v + 0.5).abs() < 1e-6 && (w - 0.866_025_4).abs() < 1e-6);
/// # Ok::<(), roadstereo::AngleError>(())
/// ```
pub fn vehicle_to_camera(t: [f32; 3], tilt: f32) -> Result<[f32; 3], AngleError> {
    let (s, c) = sin_cos_reduced(tilt)?;
    Ok([t[0], c * t[1] - s * t[2], s * t[1] + c * t[2]])
}

/// Camera-frame vector → vehicle frame (inverse of [`vehicle_to_camera`]);
/// also turns reconstructed points (camera coordinates, e.g.
/// [`crate::Structure::point`]) into the vehicle frame.
pub fn camera_to_vehicle(p: [f32; 3], tilt: f32) -> Result<[f32; 3], AngleError> {
    let (s, c) = sin_cos_reduced(tilt)?;
    Ok([p[0], c * p[1] + s * p[2], -s * p[1] + c * p[2]])
}

/// Eq. 3.1: vertical disparity (pixels) of a ground point at distance `z`
/// for an untilted camera at height `h` moving forward by `w`
/// (`U = V = 0`): `d_y = f h w / (z (z − w))`. Infinite when the point is
/// not in front of both cameras (`z ≤ 0` or `z ≤ w`). (Until an adversarial
/// review only the product was tested, positive for a point behind both.)
pub fn disparity_flat(f: f32, h: f32, w: f32, z: f32) -> f32 {
    if !(z > 0.0 && z - w > 0.0) {
        return f32::INFINITY;
    }
    quotient([f, h, w], [z, z - w])
}

/// `f h w / (a b)` for `a, b > 0`, eqs. 3.1 and 3.2: the two products and
/// one quotient where both products are normal; otherwise (a product
/// overflowed or underflowed although the quotient need not: an
/// adversarial review, thirtieth session, found `NaN` for `f = h = z =
/// 10²⁰`, `w = 1`, 0 for `h = 10⁻³⁰`, `w = 10⁻²³`, `z = 2·10⁻²³`, and
/// `+∞` for a point 2·10⁻²³ ahead) from each finite factor's significand
/// and exponent apart ([`split`]): the significands' quotient, in `(1/4,
/// 8)`, scaled by 2 to the exponents' sum ([`scale`]), so that only the
/// result itself overflows or underflows. 0 for a zero factor; a
/// non-finite factor keeps the plain quotient.
fn quotient([f, h, w]: [f32; 3], [a, b]: [f32; 2]) -> f32 {
    let fh = f * h;
    let (num, den) = (fh * w, a * b);
    // (Every partial product normal: `f h` too, which a reviewer found
    // subnormal under a normal `f h w`, 1.45 % off.)
    if fh.is_normal() && num.is_normal() && den.is_normal() {
        return num / den;
    }
    if f == 0.0 || h == 0.0 || w == 0.0 {
        return 0.0;
    }
    if !(f.is_finite() && h.is_finite() && w.is_finite() && a.is_finite() && b.is_finite()) {
        return num / den;
    }
    let [(mf, ef), (mh, eh), (mw, ew), (ma, ea), (mb, eb)] = [f, h, w, a, b].map(split);
    scale(mf * mh * mw / (ma * mb), ef + eh + ew - ea - eb)
}

/// A finite, non-zero `x` as `m · 2ᵉ` with `1 ≤ |m| < 2` (the sign in
/// `m`; a subnormal `x` first scaled by `2⁶⁴`, exactly).
fn split(x: f32) -> (f32, i32) {
    let (x, bias) = if x.abs() < f32::MIN_POSITIVE {
        (x * 18_446_744_073_709_551_616.0, -64)
    } else {
        (x, 0)
    };
    let bits = x.to_bits();
    let m = f32::from_bits((bits & 0x807F_FFFF) | 0x3F80_0000);
    // (A biased exponent of at most 254: within `i32`.)
    let e = ((bits >> 23) & 0xFF) as i32 - 127;
    (m, e + bias)
}

/// `m · 2ᵏ` for `|k|` up to 1 000 (five exponents of at most 200 each):
/// steps of `2^±120`, at most nine (a bound), then one power of two in
/// the normal range.
fn scale(mut m: f32, mut k: i32) -> f32 {
    const UP: f32 = f32::from_bits(247 << 23); // 2¹²⁰
    const DOWN: f32 = f32::from_bits(7 << 23); // 2⁻¹²⁰
    for _ in 0..9 {
        if k > 120 {
            m *= UP;
            k -= 120;
        } else if k < -120 {
            m *= DOWN;
            k += 120;
        }
    }
    // (`k` in `[−120, 120]` now, or the loop's steps took `m` to 0 or
    // infinity first: a biased exponent from 7 to 247.)
    let k = k.clamp(-120, 120);
    m * f32::from_bits(((k + 127) as u32) << 23)
}

/// Eq. 3.2: vertical disparity (pixels) of a ground point at horizontal
/// distance `z` for a camera at height `h`, tilted down by `tilt`, the
/// vehicle moving forward by `w` on flat ground:
/// `d_y = f h w / (Z' (Z' − w cos θ))` with `Z' = h sin θ + z cos θ`.
/// Infinite when the point is not in front of both cameras.
pub fn disparity_tilted(f: f32, h: f32, w: f32, z: f32, tilt: f32) -> Result<f32, AngleError> {
    let (s, c) = sin_cos_reduced(tilt)?;
    let zp = h * s + z * c;
    let ahead = zp - w * c;
    // (Until the review above a product `Z' (Z' − w cos θ)` that
    // underflowed read as a point behind the camera: `+∞`.)
    Ok(if zp > 0.0 && ahead > 0.0 {
        quotient([f, h, w], [zp, ahead])
    } else {
        f32::INFINITY
    })
}

/// The stretch of flat ground in the vertical field of view: the nearest
/// and farthest horizontal distances (`lo`, `hi`) seen by a camera at
/// height `h`, tilted down by `tilt`, with half vertical field of view
/// `half_fov` (radians; `atan(rows / 2 / f_y)`), positive ahead of the
/// camera and negative behind it. The far end is `+∞` when the upper
/// edge of the view is at or above the horizon ahead, the near end `−∞`
/// when the lower edge is at or past the horizon behind. `Ok(None)` if the
/// ground is not seen, and when `h` is not positive and finite (no camera
/// above a ground). `half_fov` must be in `(0, π/2)`
/// ([`AngleError::OutOfDomain`] otherwise); `tilt` is reduced to `[−π, π]`.
///
/// A ray at the angle `α` below the horizontal ahead meets the ground
/// exactly when `α` lies in `(0, π)` (modulo a turn), at the horizontal
/// distance `h cot α`, which falls as `α` rises; the view's rays are at
/// `[tilt − half_fov, tilt + half_fov]`, shorter than half a turn, so the
/// ground seen is `h cot α` over that interval's one part in `(0, π)`.
/// (Until an adversarial review the view's lower edge had to be short of
/// the vertical: a camera tilted 80° with a half field of view of 20° saw
/// "no ground".)
pub fn ground_interval(h: f32, tilt: f32, half_fov: f32) -> Result<Option<Range>, AngleError> {
    use core::f32::consts::{FRAC_PI_2, PI, TAU};
    if !half_fov.is_finite() {
        return Err(AngleError::NotFinite);
    }
    if !(half_fov > 0.0 && half_fov < FRAC_PI_2) {
        return Err(AngleError::OutOfDomain);
    }
    let tilt = reduce_angle(tilt)?;
    // (A NaN fails.)
    if !(h > 0.0 && h < f32::INFINITY) {
        return Ok(None);
    }
    // `h cot α` for `α` in `(0, π)` (the tangent of the forward rays as
    // [`ground_in_view`] takes it, the same bits there).
    let at = |a: f32| {
        let t = if a <= FRAC_PI_2 { tan_small(a) } else { tan(a) };
        h / t
    };
    // The copy of the view (unshifted, or a turn on for a tilt near −π)
    // that meets `(0, π)`; at most one does.
    for shift in [0.0, TAU] {
        let (upper, lower) = (tilt - half_fov + shift, tilt + half_fov + shift);
        let (a, b) = (fmax(upper, 0.0), fmin(lower, PI));
        if a < b {
            let near = if lower >= PI {
                f32::NEG_INFINITY
            } else {
                at(b)
            };
            let far = if upper <= 0.0 { f32::INFINITY } else { at(a) };
            return Ok(Some(Range { lo: near, hi: far }));
        }
    }
    Ok(None)
}

/// The ground ahead in the view of a camera tilted `tilt` (in `[−π, π]`)
/// with a half field of view in `(0, π/2)`, for [`common_rows_motion`]:
/// [`ground_interval`]'s values where the view's lower edge is below the
/// horizon and short of the vertical, `None` otherwise (that model of
/// rows assumes the ground seen ahead). The rays it takes the tangent of
/// are then within [`sin_cos`]'s range.
fn ground_in_view(h: f32, tilt: f32, half_fov: f32) -> Option<(f32, f32)> {
    let lower = tilt + half_fov; // steepest ray below the horizon
    let upper = tilt - half_fov;
    if !(lower > 0.0 && lower < core::f32::consts::FRAC_PI_2) {
        return None;
    }
    let near = h / tan_small(lower);
    let far = if upper > 0.0 {
        // 0 < upper < lower < π/2.
        h / tan_small(upper)
    } else {
        f32::INFINITY
    };
    Some((near, far))
}

/// `tan x` for `|x| ≤ π/2` ([`sin_cos`]'s range).
fn tan_small(x: f32) -> f32 {
    tan_of(sin_cos(x))
}

/// `tan x` for an angle of any size, NaN for one [`sin_cos_reduced`]
/// rejects (here only a NaN from a NaN length: the angles it gets are
/// sums of validated ones).
fn tan(x: f32) -> f32 {
    sin_cos_reduced(x).map_or(f32::NAN, tan_of)
}

fn tan_of((s, c): (f32, f32)) -> f32 {
    if c.abs() > 0.0 {
        s / c
    } else {
        f32::INFINITY
    }
}

/// Eq. 3.4: the ratio `F` of the disparity for motion `n w` to that for
/// `w`, at `Z' = h sin θ + Z cos θ`: `F = n + n (n − 1) w cos θ / (Z' − n w cos θ)`.
/// `F → n` when `w ≪ Z'`.
pub fn motion_factor(n: f32, w: f32, z_prime: f32, tilt: f32) -> Result<f32, AngleError> {
    let (_, c) = sin_cos_reduced(tilt)?;
    let den = z_prime - n * w * c;
    Ok(if den > 0.0 {
        n + n * (n - 1.0) * w * c / den
    } else {
        f32::INFINITY
    })
}

/// Motion stereo: the fraction of the image rows that see the ground in
/// frame 1 whose ground point is still in view after the vehicle moves
/// forward by `w` (flat ground, camera at height `h`, tilted by `tilt`,
/// `rows` image rows, focal length `f_y`, principal point at the centre).
/// The rows lost are those of the strip the vehicle drives past.
/// `Ok(None)` if the ground is not seen ahead with the view's lower edge
/// short of the vertical (`tilt + half_fov < π/2`, the model of rows
/// here), or `rows`, `f_y` do not give a field of view, or `h` is not
/// positive and finite, or `w` not at least 0 and finite (the model is a
/// camera above the ground moving forward; until an adversarial review a
/// NaN height gave `Some(0)` and a backward `w` a "fraction" of 1.53);
/// `tilt` is reduced to `[−π, π]`.
pub fn common_rows_motion(
    h: f32,
    tilt: f32,
    f_y: f32,
    rows: f32,
    w: f32,
) -> Result<Option<f32>, AngleError> {
    let tilt = reduce_angle(tilt)?;
    // (A NaN fails.)
    if !(h > 0.0 && h < f32::INFINITY && (0.0..f32::INFINITY).contains(&w)) {
        return Ok(None);
    }
    let half = rows * 0.5;
    let half_fov = atan(half / f_y);
    if !(half_fov > 0.0 && half_fov < core::f32::consts::FRAC_PI_2) {
        return Ok(None);
    }
    let Some((near, far)) = ground_in_view(h, tilt, half_fov) else {
        return Ok(None);
    };
    // Row (from the centre, down positive) of the ground at distance d.
    let row = |d: f32| f_y * tan(atan(h / d) - tilt);
    // Rows that see the ground at all: from the bottom up to the horizon or
    // the top edge.
    let top = if far.is_finite() {
        -half
    } else {
        fmax(-half, -f_y * tan(tilt))
    };
    let seen = half - top;
    let lost = half - row(near + w);
    // (In `[0, 1]`: `lost ≥ 0` exactly, but rounding can make it negative
    // where `seen` is a sliver of a row, the horizon at the view's lower
    // edge: an adversarial review, thirtieth session, found 26 there, and
    // up to 1.04 in 878 of 2·10⁶ random inputs. There the fraction is
    // rounding's, whatever its value.)
    Ok((seen > 0.0).then(|| fmin(fmax(1.0 - lost / seen, 0.0), 1.0)))
}

/// Ordinary stereo: the fraction of the image columns common to two
/// cameras with parallel axes a baseline `u` apart, for points at depth
/// `z` (`columns` wide, focal length `f_x`): `1 − f_x u / (z · columns)`.
pub fn common_columns_stereo(f_x: f32, columns: f32, u: f32, z: f32) -> f32 {
    if z > 0.0 && columns > 0.0 {
        fmax(1.0 - f_x * u / (z * columns), 0.0)
    } else {
        0.0
    }
}

/// Appendix II A: where a point seen at row `y_true` (pixels from the
/// principal point, `y` down) by the true camera axis appears for an
/// estimated axis turned by `angle` (radians) about `x`:
/// `y_e = y_t f / (f cos θ − y_t sin θ)`. Infinite at the horizon of the
/// turned axis.
pub fn misaligned_row(y_true: f32, f: f32, angle: f32) -> Result<f32, AngleError> {
    let (s, c) = sin_cos_reduced(angle)?;
    Ok(misaligned_row_sc(y_true, f, s, c))
}

/// [`misaligned_row`] with the sine and cosine of the angle.
fn misaligned_row_sc(y_true: f32, f: f32, s: f32, c: f32) -> f32 {
    let den = f * c - y_true * s;
    if den.abs() > 0.0 {
        y_true * f / den
    } else {
        f32::INFINITY
    }
}

/// Appendix II A: the disparity `y_Q − y_P` as seen with the misaligned
/// axis, from the true rows `y_p` (frame 1) and `y_q` (frame 2):
/// `dy_e = dy_t f² cos θ / ((f cos θ − y_P sin θ)(f cos θ − y_Q sin θ))`.
pub fn misaligned_disparity(y_p: f32, y_q: f32, f: f32, angle: f32) -> Result<f32, AngleError> {
    let (s, c) = sin_cos_reduced(angle)?;
    Ok(misaligned_disparity_sc(y_p, y_q, f, s, c))
}

/// [`misaligned_disparity`] with the sine and cosine of the angle.
fn misaligned_disparity_sc(y_p: f32, y_q: f32, f: f32, s: f32, c: f32) -> f32 {
    let den = (f * c - y_p * s) * (f * c - y_q * s);
    if den.abs() > 0.0 {
        (y_q - y_p) * f * f * c / den
    } else {
        f32::INFINITY
    }
}

/// Appendix II A, Fig. A-2: the relative depth error caused by an error
/// `angle` in the camera axis, for a ground point at horizontal distance
/// `z`, camera height `h`, tilt `tilt`, forward motion `w` (vehicle frame),
/// focal length `f`: the depth of Sec. 4.1.1, `Z = (−f V + W y₂)/d_y`
/// (camera-frame motion), computed from the true and from the misaligned
/// rows. `Ok(None)` if the point is not seen in both frames.
pub fn misalignment_depth_error(
    f: f32,
    h: f32,
    tilt: f32,
    w: f32,
    z: f32,
    angle: f32,
) -> Result<Option<f32>, AngleError> {
    let t = vehicle_to_camera([0.0, 0.0, w], tilt)?;
    let p1 = vehicle_to_camera([0.0, h, z], tilt)?;
    // Before the early return: a bad angle is an error either way.
    let (s, c) = sin_cos_reduced(angle)?;
    let p2 = [p1[0] - t[0], p1[1] - t[1], p1[2] - t[2]];
    if p1[2] <= 0.0 || p2[2] <= 0.0 {
        return Ok(None);
    }
    let (y1, y2) = (f * p1[1] / p1[2], f * p2[1] / p2[2]);
    let depth = |y2: f32, dy: f32| (-f * t[1] + t[2] * y2) / dy;
    let z_true = depth(y2, y2 - y1);
    let z_est = depth(
        misaligned_row_sc(y2, f, s, c),
        misaligned_disparity_sc(y1, y2, f, s, c),
    );
    Ok((z_true.is_finite() && z_est.is_finite() && z_true != 0.0)
        .then(|| (z_est / z_true - 1.0).abs()))
}

/// The relative depth error of Sec. 4.1.1 from a disparity error `e`
/// (pixels) at disparity `d`: `e d / (d² − e²)`; infinite when `d ≤ e`.
pub fn quantisation_depth_error(d: f32, e: f32) -> f32 {
    let den = d * d - e * e;
    if d > e && den > 0.0 {
        e * d / den
    } else {
        f32::INFINITY
    }
}
