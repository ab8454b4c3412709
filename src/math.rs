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

/// `micromath`'s first estimate of `√x` (half the exponent, by adding the
/// bits of 1.0 and shifting) without its branch for negative input, which
/// [`sqrt_pos`]'s callers rule out (test `sqrt_estimate_is_micromaths`).
#[inline(always)]
fn sqrt_estimate(x: f32) -> f32 {
    f32::from_bits((x.to_bits() >> 1) + (0x3f80_0000 >> 1))
}

/// Sine and cosine of an angle in radians, `|x| ≤ π/2` (callers validate).
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

/// Largest finite magnitude accepted for translations, in the caller's unit.
pub(crate) const MAX_TRANSLATION: f32 = 1.0e6;

#[cfg(test)]
mod tests {
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
