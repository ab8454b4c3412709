//! Crate-private numerics: the one place that decides how each function is computed.
//!
//! Everything is `f32` (the Cortex-M4F FPU is single precision). `libm` gives
//! correctly rounded or near-correctly rounded results on every target, so the
//! host build and the firmware build compute the same numbers.

/// Square root (`libm`, identical on host and target).
#[inline]
pub(crate) fn sqrt(x: f32) -> f32 {
    libm::sqrtf(x)
}

/// Sine and cosine of an angle in radians.
#[inline]
pub(crate) fn sin_cos(x: f32) -> (f32, f32) {
    (libm::sinf(x), libm::cosf(x))
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

/// A "pseudo-angle" of a direction: a number in `[0, 4)` that increases
/// strictly with the true angle, starting at straight up in the image
/// (`-y`, since `y` points down) and turning clockwise on screen
/// (up → right → down → left). One division, no trigonometry.
/// The zero vector maps to 0 (callers treat that case separately).
#[inline]
pub(crate) fn pseudo_angle(d: [f32; 2]) -> f32 {
    // Rotate so that "up" (0,-1) becomes the +x axis: (x, y) -> (-y, x).
    let x = -d[1];
    let y = d[0];
    let l1 = x.abs() + y.abs();
    if l1 <= 0.0 {
        return 0.0;
    }
    let p = y / l1; // in [-1, 1]
    if x >= 0.0 {
        if y >= 0.0 {
            p // [0, 1]
        } else {
            4.0 + p // (3, 4)
        }
    } else {
        2.0 - p // (1, 3]
    }
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
    fn pseudo_angle_is_monotone_in_the_true_angle() {
        let mut last = -1.0;
        for i in 0..3600 {
            // True angle measured from "up", clockwise on screen.
            let t = (i as f32) * core::f32::consts::PI * 2.0 / 3600.0;
            let d = [libm::sinf(t), -libm::cosf(t)];
            let p = pseudo_angle(d);
            assert!(p > last, "not increasing at step {i}: {p} <= {last}");
            assert!((0.0..4.0).contains(&p));
            last = p;
        }
    }

    #[test]
    fn pseudo_angle_cardinal_directions() {
        assert_eq!(pseudo_angle([0.0, -1.0]), 0.0);
        assert_eq!(pseudo_angle([1.0, 0.0]), 1.0);
        assert_eq!(pseudo_angle([0.0, 1.0]), 2.0);
        assert_eq!(pseudo_angle([-1.0, 0.0]), 3.0);
    }
}
