//! Effect of translation errors on the reconstruction (paper, Sec. 4.2).
//!
//! An error in the translation moves every point at once (it is "global to
//! the scene"). For one correspondence `(p₁, p₂)` the depth along the
//! disparity (eq. 2.3 in the least-squares form of [`crate::depth`]) is
//!
//! `s(T) = W' + (a·a)/(a·d)`, `a = W'(p₁' − c₂) − (f_x U', f_y V')`,
//! `d = p₂ − p₁'`, `T' = Rᵀ T`, `Z = s / q_z`,
//!
//! so its derivatives with respect to `T` are in closed form
//! ([`depth_sensitivity`]): with `a` linear in `T'`,
//! `ds = dW' + [2 (a·da)(a·d) − (a·a)(da·d)] / (a·d)²`, and
//! `∂s/∂T = R ∂s/∂T'`.
//!
//! The guaranteed stick with a bounded translation error is part of the
//! per-point pipeline: [`crate::Config::with_translation_error`].
//!
//! # Rotation errors (Sec. 5 leaves them open)
//! An error `ω` in the rotation moves the rotation-compensated point `p₁'`
//! by the rotational flow at `(x, y)` (normalised frame-2 coordinates):
//! `δx = f_x (x y ω_x − (1 + x²) ω_y + y ω_z)`,
//! `δy = f_y ((1 + y²) ω_x − x y ω_y − x ω_z)` to first order. For
//! `|ω_k| ≤ ε_k` the first-order flow `F` is at most `Σ_k |flow column
//! k| ε_k` long.
//!
//! # The rotation's shift
//! The rest is bounded exactly, not to first order (an earlier bound,
//! `F + f (1 + x² + y²) (Σ ε_k)²`, fell 21 % short at the edge of a
//! 150 px-focal image with a 0.1 rad error: the second order grows as
//! `|x| (1 + x²)`). For the ray `r = (x, y, 1)` and an error rotation
//! `ΔR` of angle `θ = |ω| ≤ Σ ε_k`, `ΔR − I − [ω]× = (1 − cos θ) [n]×² +
//! (sin θ − θ) [n]×`, so `ΔR r = r + ω × r + η` with `|η| ≤ (θ²/2 +
//! θ³/6) |r|`. The projection moves by `(δ_xy − p δ_z)/(1 + δ_z)` for `δ
//! = ΔR r − r`, and `(ω × r)_xy − p (ω × r)_z` is the flow `F`, so the
//! shift is `(F + η_xy − p η_z)/(1 + δ_z)`, at most `(|F| + f |η| (1 +
//! |p|))/(1 − |δ_z|)` pixels with `|δ_z| ≤ ε_x |y| + ε_y |x| + |η|`
//! (`f` the larger focal length; no claim where `|δ_z| ≥ 1/2`, far off
//! the camera's axis) — [`rotation_shift_bound`], rounded up by `10⁻⁵`
//! relative. With [`crate::Config::with_rotation_error`] that
//! shift is added to the frame-1 localisation error of every point, so the
//! stick holds for any rotation error in the box. At `f = 800` px a 1° error
//! about `x` or `y` moves points by about 14 px at the image centre, about
//! `z` by up to `1° × 350 px ≈ 6` px at the image corners (the paper: "10
//! pixels" and "4 or 5 pixels").

use crate::camera::{Camera, Pixel};
use crate::epipolar::PairGeometry;
use crate::math::{dot, mat3_transpose, mat3_vec};
use crate::motion::Motion;

/// Depth `Z` (frame-1 camera coordinates) of the correspondence
/// `p1 → p2` under `motion`, by eq. 2.3 in least squares along the
/// disparity: the "brute-force re-triangulation" with a given motion.
/// `None` when the geometry is degenerate (point at the FOE, no disparity,
/// behind the camera).
///
/// ```
/// use roadstereo::{motion_error::depth_of_correspondence, Camera, Motion, Pixel};
/// let cam = Camera::new(800.0, 800.0, 256.0, 240.0, 512, 480).unwrap();
/// // A point at depth 5 straight below the axis, camera moving forward 0.5.
/// let m = Motion::new([0.0, 0.0, 0.5], [0.0; 3]).unwrap();
/// let (p1, p2) = (Pixel::new(256.0, 240.0 + 800.0 / 5.0), Pixel::new(256.0, 240.0 + 800.0 / 4.5));
/// let z = depth_of_correspondence(&cam, &cam, &m, p1, p2).unwrap();
/// assert!((z - 5.0).abs() < 1e-4);
/// ```
pub fn depth_of_correspondence(
    cam1: &Camera,
    cam2: &Camera,
    motion: &Motion,
    p1: Pixel,
    p2: Pixel,
) -> Option<f32> {
    let g = PairGeometry::new(cam1, cam2, motion);
    let c = g.compensate(p1)?;
    let a = g.epipolar_vector(c.pixel);
    let a2 = dot(a, a);
    let d = [p2.u - c.pixel[0], p2.v - c.pixel[1]];
    let ad = dot(a, d);
    if ad.is_nan() || ad <= 0.0 || a2 <= 0.0 {
        return None;
    }
    let s = g.w() + a2 / ad;
    let z = s * c.inv_depth_scale;
    z.is_finite().then_some(z)
}

/// The closed-form derivatives `∂Z/∂(U, V, W)` of the depth of the
/// correspondence `p1 → p2` with respect to the translation (frame-1
/// camera coordinates), the rotation held fixed. `None` as for
/// [`depth_of_correspondence`].
pub fn depth_sensitivity(
    cam1: &Camera,
    cam2: &Camera,
    motion: &Motion,
    p1: Pixel,
    p2: Pixel,
) -> Option<[f32; 3]> {
    let g = PairGeometry::new(cam1, cam2, motion);
    let c = g.compensate(p1)?;
    let a = g.epipolar_vector(c.pixel);
    let d = [p2.u - c.pixel[0], p2.v - c.pixel[1]];
    let (aa, ad) = (dot(a, a), dot(a, d));
    if ad.is_nan() || ad <= 0.0 || aa <= 0.0 {
        return None;
    }
    // da/dT' for T' = (U', V', W'): (−f_x, 0), (0, −f_y), (p₁' − c₂).
    let rel = [c.pixel[0] - cam2.cx(), c.pixel[1] - cam2.cy()];
    let da = [[-cam2.fx(), 0.0], [0.0, -cam2.fy()], rel];
    let dw = [0.0, 0.0, 1.0];
    let mut grad_tp = [0.0f32; 3];
    for ((gk, dak), dwk) in grad_tp.iter_mut().zip(da.iter()).zip(dw.iter()) {
        *gk = dwk + (2.0 * dot(a, *dak) * ad - aa * dot(*dak, d)) / (ad * ad);
    }
    // ∂s/∂T = R ∂s/∂T' (T' = Rᵀ T), then Z = s / q_z.
    let r = motion.rotation_matrix();
    let grad = mat3_vec(&r, grad_tp);
    let inv = c.inv_depth_scale;
    let out = grad.map(|x| x * inv);
    out.iter().all(|x| x.is_finite()).then_some(out)
}

/// How far a box of translation errors (`±delta` on each frame-1 camera
/// component) can move the vector `a` of a compensated point and the
/// forward component `W'`: `(Σᵢ |∂a/∂Tᵢ| δ, Σᵢ |∂W'/∂Tᵢ| δ)`.
pub(crate) fn spread(
    rotation: &[[f32; 3]; 3],
    cam2: (f32, f32, f32, f32),
    p1c: [f32; 2],
    delta: f32,
) -> (f32, f32) {
    let (fx, fy, cx, cy) = cam2;
    let rt = mat3_transpose(rotation);
    let rel = [p1c[0] - cx, p1c[1] - cy];
    let [r0, r1, r2] = rt;
    let (mut sa, mut sw) = (0.0f32, 0.0f32);
    for i in 0..3 {
        let (a0, a1, a2) = (
            r0.get(i).copied().unwrap_or(0.0),
            r1.get(i).copied().unwrap_or(0.0),
            r2.get(i).copied().unwrap_or(0.0),
        );
        // Column i of (∂a/∂T') Rᵀ.
        let col = [-fx * a0 + rel[0] * a2, -fy * a1 + rel[1] * a2];
        sa += crate::math::sqrt(dot(col, col));
        sw += a2.abs();
    }
    (sa * delta, sw * delta)
}

/// Upper bound (pixels) on how far an error of at most `eps` (radians, about
/// the `x`, `y`, `z` axes) in the rotation moves a rotation-compensated
/// point at `p` (frame-2 pixels) seen by `cam2`. See the module docs.
/// Infinite for `Σ |eps| > 0.1` rad (or NaN), where the bound is not
/// claimed; the sign of a component does not matter (`|ω_k| ≤ |eps_k|`).
///
/// ```
/// use roadstereo::{motion_error::rotation_shift_bound, Camera, Pixel};
/// let cam = Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).unwrap();
/// let b = rotation_shift_bound(Pixel::new(255.5, 239.5), &cam, [0.001, 0.0, 0.0]);
/// assert!((b - 0.8).abs() < 0.01); // f·ε at the principal point
/// ```
pub fn rotation_shift_bound(p: Pixel, cam2: &Camera, eps: [f32; 3]) -> f32 {
    shift_bound(
        [p.u, p.v],
        (cam2.fx(), cam2.fy(), cam2.cx(), cam2.cy()),
        eps,
    )
}

/// The box of rotation errors about the frame-2 camera's `x`, `y`, `z`
/// axes (what [`rotation_shift_bound`] and
/// [`crate::Config::with_rotation_error`] take) that holds every error of
/// at most `eps` (radians) in the Euler angles `(α, β, γ)` of
/// [`Motion::new`], at the angles `angles`.
///
/// The two are the same only near zero rotation. With `R = R_y(β) R_x(α)
/// R_z(γ)` and each angle off by `δ`, the error rotation `Rᵀ R'` (the one
/// that moves the compensated points) is `rot(u_β, δβ) rot(u_α, δα)
/// rot(e_z, δγ)` with `u_α = R_z(γ)ᵀ e_x = (cos γ, −sin γ, 0)` and `u_β =
/// (R_x(α) R_z(γ))ᵀ e_y = (cos α sin γ, cos α cos γ, −sin α)`: to first
/// order the rotation vector `δα u_α + δβ u_β + δγ e_z`, whose components
/// are bounded by the sums of `|δ_j| |u_j,k|`. The product's higher terms
/// (Baker–Campbell–Hausdorff: a commutator of two rotation vectors is at
/// most the product of their lengths) add at most `s²` to each component,
/// `s = Σ |δ_j| ≤ 0.1` (generously; [`rotation_shift_bound`] claims nothing
/// above it anyway). Each component is rounded up by `2⁻²⁰` relative. So at
/// `γ = 5°` an error of `ε` in `α` alone gives `(0.996 ε, 0.087 ε, 0)`, not
/// `(ε, 0, 0)`: a box of `ε` per axis would not hold it.
///
/// The processor takes the matrix [`Motion::new`] builds from the angles
/// given for the motion, and that matrix is within `3·10⁻⁷` of their
/// exact rotation an entry ([`Motion::rotation_matrix`]: measured, not
/// derived), so where the angles are the truth within `eps` that
/// difference is part of the error too. `R_f32ᵀ R_exact` is `I` plus a
/// part whose antisymmetric half is a rotation with components of at most
/// `√3 · 3·10⁻⁷` (a column of `R_f32` sums to at most about `√3` in
/// absolute value) and whose symmetric half (`R_f32`'s non-orthogonality)
/// this argument does not bound: each component of the box gets
/// [`MATRIX_AXIS_ERROR`] more, and the pixel a compensated point moves by
/// the whole difference is measured within about an eighth of the
/// box's shift bound (host test `the_converted_box_holds_the_matrix_whole`:
/// image corners, edges and centre, 25 000 angle triples to 60°, bounds of
/// `10⁻⁹` rad). (Without the term the `s²` term covered the matrix only
/// for `s` above about `5.5·10⁻⁴`: an adversary's note.) Bounds of exactly
/// 0 give the box 0: the motion is then taken as given, as without
/// bounds.
///
/// Angles as [`Motion::new`] takes them (`|angle| ≤`
/// [`crate::motion::MAX_ROTATION_RAD`]), or an [`crate::AngleError`].
///
/// ```
/// use roadstereo::motion_error::euler_error_box;
/// let e = 0.001;
/// let b = euler_error_box([0.0, 0.3, 0.0], [e, e, e]).unwrap();
/// // Without α and γ the axes are the angles' own (β is about y anyway).
/// assert!(b.iter().all(|&k| k >= e && k < 1.01 * e));
/// let b = euler_error_box([0.0, 0.0, 0.5], [e, 0.0, 0.0]).unwrap();
/// assert!(b[1] > 0.47 * e); // an error in α reaches the y axis
/// ```
pub fn euler_error_box(
    angles: [f32; 3],
    eps: [f32; 3],
) -> Result<[f32; 3], crate::math::AngleError> {
    for a in angles {
        if !a.is_finite() {
            return Err(crate::math::AngleError::NotFinite);
        }
        if a.abs() > crate::motion::MAX_ROTATION_RAD {
            return Err(crate::math::AngleError::TooLarge);
        }
    }
    let (sa, ca) = crate::math::sin_cos_reduced(angles[0])?;
    let (sg, cg) = crate::math::sin_cos_reduced(angles[2])?;
    let ([ea, eb, eg], second, up) = euler_terms(eps);
    Ok([
        (ea * cg.abs() + eb * (ca * sg).abs() + second) * up,
        (ea * sg.abs() + eb * (ca * cg).abs() + second) * up,
        (eb * sa.abs() + eg + second) * up,
    ])
}

/// [`euler_error_box`] at any angles: a box about the axes that holds
/// every error of at most `eps` in the Euler angles whatever the angles
/// are (each `|cos|` and `|sin|` of the at-angle box taken as 1, and
/// rounded up twice, so it holds that box component by component even
/// where a computed sine or cosine is an ulp above 1). What
/// to configure a key-frame fusion with when a front end sends the
/// angles' bounds over the link ([`crate::wire::FrameJob::run_fused`]
/// compares each frame's at-angle box with the fusion's bounds).
///
/// ```
/// use roadstereo::motion_error::{euler_error_box, euler_error_box_any_angles};
/// let eps = [0.001, 0.002, 0.0005];
/// let any = euler_error_box_any_angles(eps);
/// let at = euler_error_box([0.3, -0.9, 1.0], eps).unwrap();
/// assert!(at.iter().zip(&any).all(|(a, b)| a <= b));
/// assert!(roadstereo::Config::DEFAULT.with_rotation_error(any).is_ok());
/// ```
pub fn euler_error_box_any_angles(eps: [f32; 3]) -> [f32; 3] {
    let ([ea, eb, eg], second, up) = euler_terms(eps);
    [
        (ea + eb + second) * up * up,
        (ea + eb + second) * up * up,
        (eb + eg + second) * up * up,
    ]
}

/// The parts both Euler boxes share: the bounds' sizes, the term each
/// component gets whatever the angles (the second order and the matrix's
/// rounding, none for bounds of 0), and the factor that rounds a
/// component up.
fn euler_terms(eps: [f32; 3]) -> ([f32; 3], f32, f32) {
    let e = eps.map(f32::abs);
    let s = e[0] + e[1] + e[2];
    let second = if s > 0.0 {
        s * s + MATRIX_AXIS_ERROR
    } else {
        0.0
    };
    (e, second, 1.0 + 9.536_743e-7)
}

/// What the matrix [`Motion::new`] builds may turn about each axis against
/// the exact rotation of its angles: `√3 · 3·10⁻⁷` rounded up
/// ([`euler_error_box`]).
pub const MATRIX_AXIS_ERROR: f32 = 6.0e-7;

/// [`rotation_shift_bound`] on the per-frame path: `p` as `[u, v]`, the
/// intrinsics as `(f_x, f_y, c_x, c_y)`.
#[inline]
pub(crate) fn shift_bound(p: [f32; 2], cam2: (f32, f32, f32, f32), eps: [f32; 3]) -> f32 {
    let (fx, fy, cx, cy) = cam2;
    let total = eps[0].abs() + eps[1].abs() + eps[2].abs();
    if total.is_nan() || total > 0.1 {
        return f32::INFINITY;
    }
    let (x, y) = ((p[0] - cx) / fx, (p[1] - cy) / fy);
    let cols = [
        [fx * x * y, fy * (1.0 + y * y)],
        [fx * (1.0 + x * x), fy * x * y],
        [fx * y, fy * x],
    ];
    let mut b = 0.0f32;
    for (c, e) in cols.iter().zip(eps.iter()) {
        b += crate::math::sqrt(dot(*c, *c)) * e.abs();
    }
    // The rest, exactly bounded (module docs, "The rotation's shift"):
    // `ΔR r = r + ω × r + η` with `|η| ≤ (θ²/2 + θ³/6) |r|`, `θ = |ω| ≤
    // Σ ε`, and the shift `(F + η_xy − p η_z)/(1 + δ_z)` with `|δ_z| ≤
    // ε_x |y| + ε_y |x| + |η|`.
    let f = if fx > fy { fx } else { fy };
    let rho2 = x * x + y * y;
    let eta = total * total * (0.5 + total / 6.0) * crate::math::sqrt(1.0 + rho2);
    let dz = eps[0].abs() * y.abs() + eps[1].abs() * x.abs() + eta;
    // (A NaN fails.)
    if !(dz < 0.5) {
        return f32::INFINITY;
    }
    let rest = f * eta * (1.0 + crate::math::sqrt(rho2));
    // Rounded up by a relative 1e-5 (a few dozen roundings of 2⁻²⁴).
    (b + rest) / (1.0 - dz) * (1.0 + 1.0e-5)
}

/// Depth of the frame-1 pixel `p1` when its match is re-found, under
/// `motion`, on the frame-2 boundary taken as the straight line through
/// `p2` with direction `dir`: `τ = (p₂ − p₁') × b / (a × b)`,
/// `s = W' + 1/τ`, `Z = s/q_z` — the closed-form response of the whole
/// pipeline (epipolar line, intersection, triangulation) to a motion change
/// where the boundary is locally straight. `None` if the line misses (or
/// runs along) the boundary, or the depth is not positive.
pub fn depth_on_boundary(
    cam1: &Camera,
    cam2: &Camera,
    motion: &Motion,
    p1: Pixel,
    p2: Pixel,
    dir: [f32; 2],
) -> Option<f32> {
    let g = PairGeometry::new(cam1, cam2, motion);
    let c = g.compensate(p1)?;
    let a = g.epipolar_vector(c.pixel);
    let den = crate::math::cross(a, dir);
    if den == 0.0 || den.is_nan() {
        return None;
    }
    let tau = crate::math::cross([p2.u - c.pixel[0], p2.v - c.pixel[1]], dir) / den;
    if tau.is_nan() || tau <= 0.0 {
        return None;
    }
    let z = (g.w() + 1.0 / tau) * c.inv_depth_scale;
    (z.is_finite() && z > 0.0).then_some(z)
}

/// The over- and under-estimated depths of the point matched at `p2` on a
/// boundary with local direction `dir` when each translation component `k`
/// alone is off by `±delta[k]` (Sec. 4.2, Fig. 10), in closed form
/// ([`depth_on_boundary`]): `[(low, high); 3]`. `None` as for that function.
pub fn translation_error_effect(
    cam1: &Camera,
    cam2: &Camera,
    motion: &Motion,
    p1: Pixel,
    p2: Pixel,
    dir: [f32; 2],
    delta: [f32; 3],
) -> Option<[(f32, f32); 3]> {
    let t = motion.translation();
    let mut out = [(0.0f32, 0.0f32); 3];
    for (k, (o, dk)) in out.iter_mut().zip(delta.iter()).enumerate() {
        let at = |sign: f32| {
            let mut tt = t;
            if let Some(c) = tt.get_mut(k) {
                *c += sign * dk;
            }
            let m = Motion::new(tt, motion.angles()).ok()?;
            depth_on_boundary(cam1, cam2, &m, p1, p2, dir)
        };
        let (a, b) = (at(-1.0)?, at(1.0)?);
        *o = if a <= b { (a, b) } else { (b, a) };
    }
    Some(out)
}
