//! Crate-private numerics: the one place that decides how each function is computed.
//!
//! Everything is `f32` (the Cortex-M4F FPU is single precision). `libm` gives
//! correctly rounded or near-correctly rounded results on every target, so the
//! host build and the firmware build compute the same numbers.

/// Square root, for `x ≥ 0` (0 for anything else, NaN included).
///
/// The hot path needs two square roots per point and the Cortex-M4F build
/// of `libm::sqrtf` is a ~60-instruction software routine (the `VSQRT`
/// instruction is not reachable from stable `no_std` Rust without `asm!`).
/// So: `micromath`'s bit-level estimate (within ~5 %), then three Newton
/// steps (`y ← (y + x/y)/2`, quadratic convergence: 5e-2 → 1.3e-3 → 8e-7 →
/// f32 rounding). The test `sqrt_matches_libm` pins the relative error at
/// 2e-7 over the whole range used. Same operations on host and target, so
/// both compute the same bits.
#[inline]
pub(crate) fn sqrt(x: f32) -> f32 {
    if x.is_nan() || x <= 0.0 {
        return 0.0;
    }
    if x == f32::INFINITY {
        return x;
    }
    let mut y = micromath::F32(x).sqrt().0;
    y = 0.5 * (y + x / y);
    y = 0.5 * (y + x / y);
    0.5 * (y + x / y)
}

/// [`sqrt`] for an input the caller knows to be positive, finite and not
/// tiny (the hot path's squared lengths, `x ≥ 1e-30`): the same Newton
/// steps without the checks, each written `y/2 + (x/2)/y`, one instruction
/// fewer per step. Halving is exact away from subnormals, so this is
/// `(y + x/y)/2` rounded once, as in [`sqrt`]: the same bits (test
/// `sqrt_pos_is_sqrt`).
///
/// The first estimate is [`sqrt_estimate`].
#[inline]
pub(crate) fn sqrt_pos(x: f32) -> f32 {
    let h = 0.5 * x;
    let mut y = sqrt_estimate(x);
    y = 0.5 * y + h / y;
    y = 0.5 * y + h / y;
    0.5 * y + h / y
}

/// `1/√x` for `x` positive, finite and normal (`1e-30 < x < 1e30`), with
/// no division: the bit-level estimate `0x5f37_5a86 − bits/2` (within
/// 3.5 %), then three Newton steps `y ← y (3/2 − (x/2) y²)` (quadratic
/// convergence: 3.5e-2 → 1.8e-3 → 4.7e-6 → f32 rounding). The result is
/// within `2.5 · 2⁻²⁴` of `1/√x` relative, and `x · rsqrt_pos(x)` within
/// `3.1 · 2⁻²⁴` of `√x` (the test `rsqrt_pos_error` checks every mantissa
/// of both exponent parities, which is every case: the error does not
/// depend on the exponent otherwise). [`RSQRT_UP`] times either bounds it
/// from above.
#[inline(always)]
pub(crate) fn rsqrt_pos(x: f32) -> f32 {
    let h = 0.5 * x;
    let mut y = f32::from_bits(0x5f37_5a86_u32.wrapping_sub(x.to_bits() >> 1));
    y = y * (1.5 - (h * y) * y);
    y = y * (1.5 - (h * y) * y);
    y * (1.5 - (h * y) * y)
}

/// `1 + 2⁻²¹`: [`rsqrt_pos`]'s result, or `x` times it, times this (rounded
/// to nearest once more) is at least the exact `1/√x`, or `√x`.
pub(crate) const RSQRT_UP: f32 = 1.0 + 4.768_371_6e-7;

/// `micromath`'s first estimate of `√x` (half the exponent, by adding the
/// bits of 1.0 and shifting) without its branch for negative input, which
/// [`sqrt_pos`]'s callers rule out (test `sqrt_estimate_is_micromaths`).
#[inline(always)]
fn sqrt_estimate(x: f32) -> f32 {
    f32::from_bits((x.to_bits() >> 1) + (0x3f80_0000 >> 1))
}

/// Sine and cosine of an angle in radians, **`|x| ≤ π/2` only** (no
/// range reduction: beyond it the result is silently wrong). For any
/// angle a caller gives, use [`sin_cos_reduced`].
///
/// Callers that may use this one, each with its range established before
/// the call: `Motion::new` (`|angle| ≤` `MAX_ROTATION_RAD`, 60°),
/// `Config::new` (0.1°–89°), the tilt grid of `geometry` (0°–60°), the
/// ground interval of `analysis` (rays checked to be in `(0, π/2)`), and
/// [`sin_cos_reduced`] on its reduced argument (`|r| ≤ π/4 + 1e-3`).
///
/// `libm`'s `sinf`/`cosf` reduce their argument in double precision, which
/// on the single-precision FPU becomes software `f64` (`__aeabi_d*`), and
/// `micromath`'s are accurate to ~1e-3 only (0.8 px at f = 800 px). On
/// `|x| ≤ π/2` the Taylor series to x¹³ is exact to ~6e-11 before rounding;
/// evaluated in Horner form in `f32`. The test `sin_cos_match_libm` pins
/// the error at 3e-7.
pub(crate) const fn sin_cos(x: f32) -> (f32, f32) {
    let x2 = x * x;
    let s = x
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0
                    + x2 * (-1.0 / 5040.0
                        + x2 * (1.0 / 362_880.0
                            + x2 * (-1.0 / 39_916_800.0 + x2 * (1.0 / 6_227_020_800.0)))))));
    let c = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0
                + x2 * (-1.0 / 720.0
                    + x2 * (1.0 / 40_320.0
                        + x2 * (-1.0 / 3_628_800.0
                            + x2 * (1.0 / 479_001_600.0 + x2 * (-1.0 / 87_178_291_200.0)))))));
    (s, c)
}

/// Largest angle magnitude, radians (2¹³ ≈ 1304 turns), that the
/// library's single-precision range reduction handles; beyond it an angle
/// is rejected with [`AngleError::TooLarge`]. Every public function taking an angle accepts
/// at least `[−MAX_ANGLE_RAD, MAX_ANGLE_RAD]` unless its docs say
/// otherwise.
pub const MAX_ANGLE_RAD: f32 = 8192.0;

/// Why an angle was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum AngleError {
    /// The angle is NaN or infinite.
    NotFinite,
    /// `|angle|` exceeds [`MAX_ANGLE_RAD`], the range the single-precision
    /// reduction is exact for.
    TooLarge,
    /// The angle is outside the range the function is defined for (each
    /// such function documents its range).
    OutOfDomain,
}

impl core::error::Error for AngleError {}

impl core::fmt::Display for AngleError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::NotFinite => "angle is NaN or infinite",
            Self::TooLarge => "angle magnitude above 8192 rad",
            Self::OutOfDomain => "angle outside the function's range",
        })
    }
}

/// π/2 in three parts (Cody–Waite): `PIO2_HI` has 8 significant bits and
/// `PIO2_MID` 11, so `k · PIO2_HI` and `k · PIO2_MID` are exact for
/// `|k| < 2¹³`; `PIO2_LO` is the `f32` nearest the rest. Their sum is π/2
/// to 1.8e-15 (test `pio2_split_is_exact`). Given by their bits: 1.5703125
/// (201/128), 4.837512969970703125e-4 (8116 · 2⁻²⁴), 7.549790126404332e-8.
const PIO2_HI: f32 = f32::from_bits(0x3fc9_0000);
const PIO2_MID: f32 = f32::from_bits(0x39fd_a000);
const PIO2_LO: f32 = f32::from_bits(0x33a2_2169);

/// `x = k · π/2 + r`: a nearest quarter turn `k` and the remainder `r`,
/// for `|x| ≤` [`MAX_ANGLE_RAD`]. `k` comes from `x · 2/π` rounded in
/// `f32`, which can pick the other neighbour within 4e-4 of a half, so
/// `|r| ≤ π/4 + 1e-3` (well inside [`sin_cos`]'s `π/2`).
///
/// Cody–Waite in `f32` without fused multiply-add: `|k| ≤ 5216 < 2¹³`, so
/// `k · PIO2_HI` and `k · PIO2_MID` are exact; `x − k · PIO2_HI` is exact
/// (both are multiples of `x`'s last place, and the difference, below
/// `π/4 + 3.1e-4 |x|`, needs no more bits than `x`), and so is the next
/// subtraction (multiples of 2⁻²⁴ below 1); only the last step rounds. The
/// error of `r` is at most half an ulp of `r` plus `|k| · 1.8e-15` (the
/// split's truncation), below 4e-8 over the whole range. For
/// `|x| ≤ 0.78`, `k = 0` and `r = x` exactly.
fn reduce_quarter_turns(x: f32) -> Result<(f32, i32), AngleError> {
    if !x.is_finite() {
        return Err(AngleError::NotFinite);
    }
    if x.abs() > MAX_ANGLE_RAD {
        return Err(AngleError::TooLarge);
    }
    let q = x * core::f32::consts::FRAC_2_PI;
    // Nearest integer (half away from zero); |q| ≤ 5216, so the cast is in
    // range. A `k` off by one where `q` is within rounding of a half only
    // makes `|r|` exceed π/4 by that rounding.
    let k = (q + if q < 0.0 { -0.5 } else { 0.5 }) as i32;
    let kf = k as f32;
    let r = ((x - kf * PIO2_HI) - kf * PIO2_MID) - kf * PIO2_LO;
    Ok((r, k))
}

/// Sine and cosine of any angle `|x| ≤` [`MAX_ANGLE_RAD`] (radians),
/// reduced in single precision ([`reduce_quarter_turns`]) and evaluated
/// with [`sin_cos`] on the remainder: absolute error at most 1.2e-7 over
/// the whole range (tests `sin_cos_reduced_matches_libm` here, against
/// `libm`'s `sinf`/`cosf`, and `host_tests/tests/angles.rs`, against
/// `libm`'s `f64` `sin`/`cos`). NaN, infinite or larger
/// angles are a typed error. For `|x| ≤ 0.78` the bits are those of
/// [`sin_cos`].
///
/// Every public function that takes an angle from its caller uses this
/// one (or validates the angle into [`sin_cos`]'s range first).
pub(crate) fn sin_cos_reduced(x: f32) -> Result<(f32, f32), AngleError> {
    let (r, k) = reduce_quarter_turns(x)?;
    let (s, c) = sin_cos(r);
    // sin/cos of r + k π/2, by the quadrant k mod 4 (two's complement:
    // k & 3 is k mod 4 also for negative k).
    Ok(match k & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    })
}

/// The angle equivalent to `x` in `[−π, π]` (radians), for `|x| ≤`
/// [`MAX_ANGLE_RAD`]: `r + j · π/2` with [`reduce_quarter_turns`]'s
/// remainder and `j = k mod 4` in `{−1, 0, 1, 2}`. Within 3e-7 of the
/// exact value; `x` itself (the same bits) for `|x| ≤ 0.78`.
pub(crate) fn reduce_angle(x: f32) -> Result<f32, AngleError> {
    use core::f32::consts::{FRAC_PI_2, PI};
    let (r, k) = reduce_quarter_turns(x)?;
    Ok(match k & 3 {
        0 => r,
        1 => r + FRAC_PI_2,
        2 => {
            // r + π, folded into [−π, π].
            if r > 0.0 {
                r - PI
            } else {
                r + PI
            }
        }
        _ => r - FRAC_PI_2,
    })
}

/// `atan(x)` in single precision (no `libm`: its `f32` functions reduce in
/// `f64`): range reduction `atan(x) = 2 atan(x / (1 + √(1 + x²)))` to
/// `|x| ≤ 0.42`, then 13 terms of the series. The test `atan_matches_libm`
/// pins the error at 5e-7.
pub(crate) fn atan(x: f32) -> f32 {
    use core::f32::consts::FRAC_PI_2;
    if x.abs() > 1.0 {
        let a = atan_unit(1.0 / x);
        return if x > 0.0 {
            FRAC_PI_2 - a
        } else {
            -FRAC_PI_2 - a
        };
    }
    atan_unit(x)
}

fn atan_unit(x: f32) -> f32 {
    let y = x / (1.0 + sqrt(1.0 + x * x));
    let y2 = y * y;
    let (mut term, mut sum, mut k) = (y, y, 1.0f32);
    for _ in 0..12 {
        term *= -y2;
        k += 2.0;
        sum += term / k;
    }
    2.0 * sum
}

/// `atan2(y, x)` in single precision (0 for the origin).
pub(crate) fn atan2(y: f32, x: f32) -> f32 {
    use core::f32::consts::{FRAC_PI_2, PI};
    if x == 0.0 && y == 0.0 {
        return 0.0;
    }
    if x.abs() >= y.abs() {
        let a = atan_unit(y / x);
        if x > 0.0 {
            a
        } else if y >= 0.0 {
            a + PI
        } else {
            a - PI
        }
    } else {
        let a = atan_unit(x / y);
        if y > 0.0 {
            FRAC_PI_2 - a
        } else {
            -FRAC_PI_2 - a
        }
    }
}

/// `asin(x)`, `x` clamped to `[−1, 1]`.
pub(crate) fn asin(x: f32) -> f32 {
    let x = x.clamp(-1.0, 1.0);
    atan2(x, sqrt(1.0 - x * x))
}

/// `max` by comparison. `f32::max` is a call to `fmaxf` on the Cortex-M4F
/// (no `VMAXNM` before Armv8); inputs here are never NaN.
#[inline(always)]
pub(crate) fn fmax(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// `min` by comparison (see [`fmax`]).
#[inline(always)]
pub(crate) fn fmin(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// 2-D cross product `a.x*b.y - a.y*b.x`.
#[inline]
pub(crate) fn cross(a: [f32; 2], b: [f32; 2]) -> f32 {
    a[0] * b[1] - a[1] * b[0]
}

/// 2-D dot product.
#[inline]
pub(crate) fn dot(a: [f32; 2], b: [f32; 2]) -> f32 {
    a[0] * b[0] + a[1] * b[1]
}

/// `a - b`.
#[inline]
pub(crate) fn sub(a: [f32; 2], b: [f32; 2]) -> [f32; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// A 3×3 matrix, row major.
pub(crate) type Mat3 = [[f32; 3]; 3];

/// Matrix product `a · b`.
pub(crate) fn mat3_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let [b0, b1, b2] = *b;
    a.map(|[x, y, z]| {
        [
            x * b0[0] + y * b1[0] + z * b2[0],
            x * b0[1] + y * b1[1] + z * b2[1],
            x * b0[2] + y * b1[2] + z * b2[2],
        ]
    })
}

/// Transpose.
pub(crate) fn mat3_transpose(a: &Mat3) -> Mat3 {
    let [[a00, a01, a02], [a10, a11, a12], [a20, a21, a22]] = *a;
    [[a00, a10, a20], [a01, a11, a21], [a02, a12, a22]]
}

/// Matrix-vector product `a · v`.
pub(crate) fn mat3_vec(a: &Mat3, v: [f32; 3]) -> [f32; 3] {
    a.map(|[x, y, z]| x * v[0] + y * v[1] + z * v[2])
}

/// `a · b` for three terms, computed as if in twice the precision and
/// rounded once (Ogita, Rump and Oishi's `Dot2`, with Dekker's split
/// product and Knuth's two-sum, no fused multiply-add): within `2⁻²⁴
/// |a · b| + 10 · 2⁻⁴⁸ Σ |aᵢ bᵢ|` of the exact value, where the plain
/// sum is only within `γ₃ Σ |aᵢ bᵢ|` (all of it lost when the terms
/// cancel). Exact splitting needs `|aᵢ|, |bᵢ| < 2¹¹³` and products far
/// from the underflow range: for the translation (`|T| ≤ 10⁶`) against a
/// rotation's entries it holds.
pub(crate) fn dot3_accurate(a: [f32; 3], b: [f32; 3]) -> f32 {
    // Dekker: x = hi + lo with hi on the upper 12 bits.
    let split = |x: f32| {
        let c = 4097.0 * x;
        let hi = c - (c - x);
        (hi, x - hi)
    };
    // The product and its exact error.
    let two_prod = |x: f32, y: f32| {
        let p = x * y;
        let ((xh, xl), (yh, yl)) = (split(x), split(y));
        (p, ((xh * yh - p) + xh * yl + xl * yh) + xl * yl)
    };
    // The sum and its exact error.
    let two_sum = |x: f32, y: f32| {
        let s = x + y;
        let z = s - x;
        (s, (x - (s - z)) + (y - z))
    };
    let (p0, e0) = two_prod(a[0], b[0]);
    let (p1, e1) = two_prod(a[1], b[1]);
    let (p2, e2) = two_prod(a[2], b[2]);
    let (s1, f1) = two_sum(p0, p1);
    let (s2, f2) = two_sum(s1, p2);
    s2 + (((e0 + e1) + e2) + (f1 + f2))
}

/// Largest finite magnitude accepted for translations, in the caller's unit.
pub(crate) const MAX_TRANSLATION: f32 = 1.0e6;

#[cfg(test)]
mod tests {
    /// [`dot3_accurate`] against `f64`, on cancelling rotation-like terms:
    /// within its bound, and nearly always the correctly rounded value.
    #[test]
    fn dot3_accurate_rounds_about_once() {
        let mut rng = crate::test_rng::Rng(0xd072_0001);
        let (mut worst, mut worst_plain) = (0.0f64, 0.0f64);
        for case in 0..200_000 {
            let a = [0.0; 3].map(|_: f32| (rng.next() - 0.5) * 2.0);
            let scale = [1.0e-6f32, 1.0, 1.0e6][case % 3];
            let mut b = [0.0; 3].map(|_: f32| (rng.next() - 0.5) * 2.0 * scale);
            // Make the first two terms cancel (`a₀ b₀ ≈ −a₁ b₁`).
            if case % 2 == 0 && a[0] != 0.0 {
                b[0] = -a[1] * b[1] / a[0] * (1.0 + (rng.next() - 0.5) * 1.0e-4);
                b[2] *= 1.0e-4;
            }
            let exact: f64 = (0..3).map(|i| f64::from(a[i]) * f64::from(b[i])).sum();
            let mag: f64 = (0..3)
                .map(|i| (f64::from(a[i]) * f64::from(b[i])).abs())
                .sum();
            let got = f64::from(dot3_accurate(a, b));
            let bound = exact.abs() * 2f64.powi(-24) + 10.0 * 2f64.powi(-48) * mag;
            assert!(
                (got - exact).abs() <= bound,
                "case {case}: {got} vs {exact}"
            );
            if case % 2 == 0 && exact != 0.0 {
                let plain: f64 = f64::from(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
                worst = worst.max((got - exact).abs() / exact.abs());
                worst_plain = worst_plain.max((plain - exact).abs() / exact.abs());
            }
        }
        // Relative to the cancelled result (cancellations to 10⁻⁸ of the
        // terms): within a few roundings (4·10⁻⁷, the bound's second
        // term), where the plain sum is off by 10 times the result.
        assert!(worst < 1.0e-6 && worst_plain > 1.0, "{worst} {worst_plain}");
    }

    use super::*;

    #[test]
    fn sqrt_estimate_is_micromaths() {
        let mut x = 1.0e-30f32;
        while x < 1.0e30 {
            let ours = sqrt_estimate(x);
            assert_eq!(ours.to_bits(), micromath::F32(x).sqrt().0.to_bits(), "{x}");
            x *= 1.001_3;
        }
    }

    /// [`rsqrt_pos`] over every mantissa of `[1, 4)` (both exponent
    /// parities): within `2.5 · 2⁻²⁴` relative, `x · y` within `3.1 · 2⁻²⁴`
    /// of `√x`, and both times [`RSQRT_UP`] at least the exact value.
    #[test]
    fn rsqrt_pos_error() {
        let (mut b, end) = (1.0f32.to_bits(), 4.0f32.to_bits());
        while b < end {
            let x = f32::from_bits(b);
            let y = rsqrt_pos(x);
            let t = 1.0 / f64::from(x).sqrt();
            assert!((f64::from(y) / t - 1.0).abs() <= 2.5 / 16_777_216.0, "{x}");
            let r = x * y;
            let s = f64::from(x).sqrt();
            assert!((f64::from(r) / s - 1.0).abs() <= 3.1 / 16_777_216.0, "{x}");
            assert!(
                f64::from(y * RSQRT_UP) >= t && f64::from(r * RSQRT_UP) >= s,
                "{x}"
            );
            b += 1;
        }
        for x in [1.0e-30f32, 3.7e-20, 1.0e-5, 0.3, 7.0, 1.0e12, 9.9e29] {
            let t = 1.0 / f64::from(x).sqrt();
            assert!(
                (f64::from(rsqrt_pos(x)) / t - 1.0).abs() <= 2.5 / 16_777_216.0,
                "{x}"
            );
        }
    }

    #[test]
    fn sqrt_pos_is_sqrt() {
        let mut x = 1.0e-30f32;
        let mut n = 0;
        while x < 1.0e30 {
            assert_eq!(sqrt_pos(x).to_bits(), sqrt(x).to_bits(), "{x}");
            x *= 1.000_37;
            n += 1;
        }
        assert!(n > 300_000);
    }

    #[test]
    fn sqrt_matches_libm() {
        let mut x = 1.0e-30f32;
        while x < 1.0e30 {
            for f in [1.0f32, 1.37, 2.0, 3.1, 5.9, 7.77] {
                let v = x * f;
                let want = libm::sqrtf(v);
                let got = sqrt(v);
                assert!(
                    ((got - want) / want).abs() <= 2.0e-7,
                    "sqrt({v}) = {got}, want {want}"
                );
            }
            x *= 10.0;
        }
        assert_eq!(sqrt(0.0), 0.0);
        assert_eq!(sqrt(-1.0), 0.0);
        assert_eq!(sqrt(f32::NAN), 0.0);
    }

    #[test]
    fn sin_cos_match_libm() {
        for i in -1000..=1000 {
            let x = i as f32 * core::f32::consts::FRAC_PI_2 / 1000.0;
            let (s, c) = sin_cos(x);
            assert!((s - libm::sinf(x)).abs() <= 3.0e-7, "sin({x})");
            assert!((c - libm::cosf(x)).abs() <= 3.0e-7, "cos({x})");
        }
    }

    /// `f32` `x ≥ 0` (normal) times 2⁶², exactly, as an integer.
    fn scaled_2_62(x: f32) -> u128 {
        let b = x.to_bits();
        let e = (b >> 23) & 0xff;
        let m = u128::from((b & 0x7f_ffff) | 0x80_0000);
        // x = m · 2^(e − 150); times 2^62 is m · 2^(e − 88) (e ≥ 88 here).
        m << (e - 88)
    }

    /// The split constants have the bits [`reduce_quarter_turns`] relies
    /// on, and their sum is π/2 to 1.8e-15 (π/2 · 2⁶² in integers, from
    /// the digits of π).
    #[test]
    fn pio2_split_is_exact() {
        let significant = |x: f32| 24 - (x.to_bits() & 0x7f_ffff | 0x80_0000).trailing_zeros();
        assert!(significant(PIO2_HI) <= 8 && significant(PIO2_MID) <= 11);
        // |k| < 2^13 over the accepted range, so k · PIO2_HI, k · PIO2_MID are exact.
        const { assert!(MAX_ANGLE_RAD * core::f32::consts::FRAC_2_PI + 1.0 < 8192.0) };
        const PIO2_TIMES_2_62: u128 = 0x6487_ed51_10b4_611a;
        let sum = scaled_2_62(PIO2_HI) + scaled_2_62(PIO2_MID) + scaled_2_62(PIO2_LO);
        // 1.8e-15 · 2^62 = 8301.
        assert!(sum.abs_diff(PIO2_TIMES_2_62) <= 8301, "{sum:#x}");
    }

    /// Absolute error of `sin_cos_reduced(x)` against `libm`'s `sinf` and
    /// `cosf` (which reduce exactly, in `f64`, and round to within an ulp).
    /// Asserted at most 1.2e-7 (two ulps of 1; measured: 6e-8, one ulp).
    fn reduced_error(x: f32) -> f32 {
        let (s, c) = sin_cos_reduced(x).unwrap();
        fmax((s - libm::sinf(x)).abs(), (c - libm::cosf(x)).abs())
    }

    /// At and beyond the accepted range: a table of angles, a dense sweep
    /// of `[−8192, 8192]`, and the worst case for the reduction, the
    /// `f32`s within 8 ulps of every multiple of π/2 in range.
    #[test]
    fn sin_cos_reduced_matches_libm() {
        use core::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
        let up = |x: f32| f32::from_bits(x.to_bits() + 1);
        let ok = [
            0.0f32,
            -0.0,
            f32::from_bits(1),
            -f32::from_bits(1),
            1.0e-38,
            FRAC_PI_4,
            up(FRAC_PI_4),
            FRAC_PI_2,
            -FRAC_PI_2,
            up(FRAC_PI_2),
            3.0 * FRAC_PI_4,
            PI,
            -PI,
            2.0 * PI,
            6.0,
            7.0,
            -7.0,
            100.0,
            -1000.0,
            8191.5,
            MAX_ANGLE_RAD,
            -MAX_ANGLE_RAD,
        ];
        for x in ok {
            assert!(reduced_error(x) <= 1.2e-7, "x = {x}: {}", reduced_error(x));
        }
        for (x, want) in [
            (up(MAX_ANGLE_RAD), AngleError::TooLarge),
            (-up(MAX_ANGLE_RAD), AngleError::TooLarge),
            (1.0e5, AngleError::TooLarge),
            (1.0e30, AngleError::TooLarge),
            (f32::MAX, AngleError::TooLarge),
            (-f32::MAX, AngleError::TooLarge),
            (f32::INFINITY, AngleError::NotFinite),
            (f32::NEG_INFINITY, AngleError::NotFinite),
            (f32::NAN, AngleError::NotFinite),
        ] {
            assert_eq!(sin_cos_reduced(x), Err(want), "x = {x}");
            assert_eq!(reduce_angle(x), Err(want), "x = {x}");
        }
        // Signs of zero survive.
        let (s, c) = sin_cos_reduced(-0.0).unwrap();
        assert!(s == 0.0 && s.is_sign_negative() && c == 1.0);
        let mut worst = 0.0f32;
        for i in -400_000..=400_000 {
            let x = i as f32 * (MAX_ANGLE_RAD / 400_000.0);
            worst = fmax(worst, reduced_error(x));
        }
        for k in (-5215..=5215).filter(|&k| k != 0) {
            let near = k as f32 * FRAC_PI_2;
            for d in -8i64..=8 {
                // Steps of one ulp in magnitude (the sign bit stays).
                let x = f32::from_bits((i64::from(near.to_bits()) + d) as u32);
                if x.abs() <= MAX_ANGLE_RAD {
                    worst = fmax(worst, reduced_error(x));
                }
            }
        }
        assert!(worst <= 1.2e-7, "worst {worst}");
    }

    /// Where no reduction happens the reduced functions give the bits of
    /// the plain ones: the hot path and the checked path agree.
    #[test]
    fn reduction_keeps_small_angles_exact() {
        for i in -78_000..=78_000 {
            let x = i as f32 * 1.0e-5;
            let (s, c) = sin_cos(x);
            let (rs, rc) = sin_cos_reduced(x).unwrap();
            assert_eq!(
                (s.to_bits(), c.to_bits()),
                (rs.to_bits(), rc.to_bits()),
                "{x}"
            );
            assert_eq!(reduce_angle(x).unwrap().to_bits(), x.to_bits(), "{x}");
        }
    }

    /// `reduce_angle` gives an angle in `[−π, π]` with the sine and cosine
    /// of the original: within 4e-7 of `libm`'s (its own error below 2.5e-7
    /// plus theirs, twice).
    #[test]
    fn reduce_angle_is_equivalent_and_in_range() {
        use core::f32::consts::PI;
        for i in -400_000..=400_000 {
            let x = i as f32 * ((MAX_ANGLE_RAD - 1.0e-2) / 400_000.0) + 1.0e-3;
            let r = reduce_angle(x).unwrap();
            assert!((-PI..=PI).contains(&r), "{x} -> {r}");
            let ds = (libm::sinf(r) - libm::sinf(x)).abs();
            let dc = (libm::cosf(r) - libm::cosf(x)).abs();
            assert!(ds <= 4.0e-7 && dc <= 4.0e-7, "{x} -> {r}: {ds} {dc}");
        }
    }

    #[test]
    fn atan_matches_libm() {
        for i in -2000..=2000 {
            let x = i as f32 * 0.01;
            assert!((atan(x) - libm::atanf(x)).abs() <= 5.0e-7, "atan({x})");
            for j in [-3.0f32, -0.5, 0.0, 0.7, 2.0] {
                assert!(
                    (atan2(x, j) - libm::atan2f(x, j)).abs() <= 1.0e-6,
                    "atan2({x}, {j})"
                );
            }
        }
        for i in -100..=100 {
            let x = i as f32 * 0.01;
            assert!((asin(x) - libm::asinf(x)).abs() <= 1.0e-6, "asin({x})");
        }
    }
}
