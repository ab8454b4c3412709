//! The epipolar geometry of a frame pair (paper Sec. 2, steps 1–3): exact
//! rotation compensation, the focus of expansion and the epipolar vector of
//! a point.
//!
//! # Rotation compensation (step 1), exact
//! A frame-1 pixel `p₁` is mapped by the homography `H = K₂ Rᵀ K₁⁻¹` to
//! `p₁'`, where it would be seen from the frame-2 orientation without
//! translation. With `q = Rᵀ K₁⁻¹ p₁` (third component `q_z`), a point at
//! frame-1 depth `Z` on that ray has depth `s = Z · q_z` in the compensated
//! frame, and the remaining motion is the pure translation
//! `T' = Rᵀ T = (U', V', W')`.
//!
//! # Epipolar line (steps 2–3)
//! In pixels, with `c₂` the frame-2 principal point, define
//! `a = W'(p₁' − c₂) − (f_x U', f_y V')`. From eq. 2.2 (per axis, with the
//! focal lengths of frame 2) the frame-2 point is
//! `p₂ = p₁' + a / (s − W')`,
//! so the disparity `d = p₂ − p₁'` is parallel to `a`. Writing `p₂ = p₁' + τ a`,
//! a point in front of both cameras (`s > 0`, `s − W' > 0`) has
//! `τ > 0` and, when `W' < 0`, `τ < 1/|W'|`. For `W' ≠ 0`, `a = W'(p₁' − FOE)`
//! with `FOE = c₂ + (f_x U', f_y V')/W'` (eq. A.1): the search range is the
//! half-line from `p₁'` away from the FOE when `W' > 0` and the segment from
//! `p₁'` to the FOE when `W' < 0`, exactly as in the paper. When `W' = 0` the
//! FOE is at infinity and all epipolar lines are parallel to `−(U', V')`
//! (ordinary stereo, eq. 3.3); the same formulas hold unchanged, and
//! `s = W' + 1/τ` (eq. 2.3 along the disparity, see [`crate::depth`]).
//!
//! # The error disc after compensation (`r₁`)
//! The true frame-1 pixel is within `e₁` of the detected `p`; the search
//! needs a radius `r₁` about the *computed* `p₁'` that holds the *exact*
//! compensation of every such pixel (`PairGeometry::point_disc_radius`,
//! and frame-wide `PairGeometry::frame_disc_radius`). It is exact in the
//! geometry and bounds every rounding; nothing is linearised.
//!
//! **The geometry.** Write `h₀, h₁, h₂` for the rows of `H` on `(u, v)`
//! and `X, Y, Z` for the exact row values at `p` (`Z = q_z`,
//! `P = (X, Y)/Z`). At the true pixel `p + δ` the exact compensation is
//! `(X + h₀·δ, Y + h₁·δ)/(Z + h₂·δ)`, and its difference from `P` is
//! exactly `(Z/(Z + h₂·δ)) J δ` with `J = [h₀ − P_x h₂; h₁ − P_y h₂]/Z`, the
//! Jacobian at the *detected* pixel. `|h₂·δ| ≤ e₁ |h₂|₁`, so with
//! `x = e₁ |h₂|₁/Z ≤ ½` the displacement is at most `σ e₁/(1 − x) ≤
//! σ e₁ (1 + 2x)` for any `σ ≥ ‖J‖₂` (the larger of `J`'s 1- and ∞-norms,
//! [`Compensated::stretch`]). Step 1 flags a point with `Δ/q_z` above
//! `HALF_KAPPA_MAX` (`½ − 2⁻²⁰`, so every point above ½), and
//! `Δ ≥ e₁ |h₂|₁` (`PairGeometry::depth_scale_error`), so `x ≤ ½` on
//! every accepted point: the change of `q_z` across the disc costs at most
//! a factor 2, and `1 + 2x` says how much (an earlier `r₁ = e₁ σ` at the
//! detected pixel fell 23 % short for a 4 px focal length and `e₁ = 12`).
//!
//! **The rounding.** Each entry of the computed `H` is within `γ₇` of the
//! exact one relative to the same sums with positive terms; a row's value
//! at a pixel is computed within `γ₃` more (its `u` and `v` terms each see
//! their product and two sums). So it is within `E_i = 10 · 2⁻²⁴ Ā_i` of
//! the exact value (`γ₇ + γ₃` and their product are `10 · 2⁻²⁴` plus
//! about `80 · 2⁻⁴⁸`, which the `1 + 10⁻⁶ > 1 + 16 · 2⁻²⁴` that `Ā_i`
//! is rounded up by covers), `Ā_i` that row of `|K₂| |Rᵀ| |K₁⁻¹|`
//! against the image's largest coordinates (`row_bounds`). `Δ` carries
//! `8 E_z`, so an accepted point has `E_z/q_z ≤ 1/16`. Then the computed
//! coordinate `p_x = X_c · fl(1/Z_c)` is within
//! `(16/15) (E_x + |p_x| E_z)/Z_c + 2⁻²³ |p_x|` of `P_x` (from
//! `X_c/Z_c − P_x = (ΔX − P_x ΔZ)/Z_c`, solved for `|P_x|`), and both
//! coordinates together within `ρ = 1.074 (E_x + E_y + u E_z)/q_z +
//! 1.048 · 2⁻²³ u` (in the code `6.4·10⁻⁷ (Ā_x + Ā_y + u Ā_z)/q_z +
//! 1.25·10⁻⁷ u`), `u = |p_x| + |p_y|`. The computed `σ` is short of
//! `‖J‖` by at most a relative `2ζ` (`ζ = 2E_z/q_z`, the rounding of
//! `1/q_z`), plus `2⁻²⁰ (|h|₁ + u |h₂|₁)/q_z` (the entries' and the
//! arithmetic's rounding, `|h|₁` the 2×2 block with positive terms) and
//! `1.07 ρ |h₂|₁/q_z` (the rounding of `p_x`, `p_y` in `J`, which `e₁`
//! turns into at most `1.07 ρ x`). And `1/(1 − x)` with the exact `Z` is
//! at most `(1 + 2x)(1 + 0.54ζ)` because `x + 4ζ ≤ ½`. Altogether
//!
//! `r₁ = e₁ (σ (1 + 2ζ) + 2⁻²⁰ (|h|₁ + u |h₂|₁)/q_z) (1 + 2x)(1 + 2⁻²⁰)
//!       + ρ (1 + 1.2 x (1 + 2x))`
//!
//! (the last `2⁻²⁰` for this line's own roundings), plus the rotation
//! error's shift ([`crate::motion_error`], taken at the disc's point
//! farthest from the principal point) and the search's own slack
//! (`crate::depth`). The earlier slack, `2⁻²⁰` of the frame-2
//! coordinates, missed the compensation's rounding when the frame-1
//! coordinates are large (a principal point at 16 200 px: 1.2·10⁻⁴ px
//! of slack against 1.2·10⁻³ px of rounding). For an ordinary camera
//! (512 × 480, `e₁ = 0.5`, rotations to 5°) `r₁` is within 0.5 % of
//! `e₁ σ`.
//!
//! **Frame-wide** (`PairGeometry::frame_disc_radius`), the same terms at
//! their bounds over the accepted points (`1/q_z ≤ 1/zlow`, `u` at most
//! the corners' extremes and `2S`, `x` clamped at ½). The corners' own
//! `p_x`, `p_y`, from which the stretch bound takes its extremes, are
//! computed where `E_z/q_z ≤ 1/16` need not hold; but `zlow ≤ z_min −
//! 2.5 E_z` bounds the same quotient `(E_x + |p_x| E_z)/(Z_c − E_z)` by
//! `ρ` at `1/zlow`, coordinate by coordinate, which the stretch bound's
//! `1.07 ρ |h₂|₁/zlow` and `u`'s `2ρ` use.
//!
//! Test `error_disc_holds_every_pixel_within_e1` checks the disc against
//! `f64` on ordinary and adversarial cameras; it fails with `r₁ = e₁ σ`,
//! with or without `ρ`, and with `1 + x` for `1 + 2x`. It sees the
//! geometry and, at `e₁ = 0`, that the rounding needs a term; the
//! rounding met on its points is 4–13 % of `ρ`, so it cannot tell the
//! smaller terms' margins (a review found that halving `ρ` or dropping
//! `ζ` passes it): those rest on the argument above.
//!
//! **The focus of expansion** comes from `T' = Rᵀ T`. Its components
//! cancel when the rotation turns against the translation (`U' = r₀₀ T_x
//! + r₂₀ T_z` with both terms about 0.11 and the result 10⁻⁵), and a plain
//! `f32` sum, within `γ₃ |Rᵀ| |T|`, then put the focus of a 10⁵ px
//! focal length 7.6·10⁻⁴ px off, six times the slack: moving backwards, an
//! adversary found an `ok` point whose truth lay 14 % below its stick
//! (`host_tests/tests/adversarial_containment.rs`). `T'` is now rounded
//! about once (`math::dot3_accurate`, twice the precision without
//! `f64`), so the focus is within a few roundings of its own coordinates
//! and its offset `d` from `c₂` (`ε`, `PairGeometry::foe_rounding`).
//! * Moving forwards, the geometry with the computed focus is the true one
//!   with the frame-1 point moved by `(1 − 1/k) ε` (`k ≥ 1`), at most
//!   `|ε| min(1, 3L/(|e − c₂| + L))` (`PairGeometry::foe_shift`; `L`
//!   the view's reach from `c₂`, and step 1 refuses a point whose `r₁ +
//!   e₂` passes `L`, so that the true points lie within `2L` of `c₂`),
//!   which `r₁` adds.
//! * Moving backwards the correspondent, seen from the computed focus,
//!   is moved in frame 2 by `(1 − k) ε` (`0 < k < 1`), `(1 − k) = d/|p₁'
//!   − e|`: the same bound, which `e₂` adds.
//! * Sideways (`W' = 0`) there is no focus: `a = −(f U', f V')` rounds
//!   once a component, relative to itself, which the slack covers.
//!
//! The exact geometry is that of the motion's matrix
//! ([`Motion::rotation_matrix`]); how closely that matrix follows the
//! angles is `Motion::new`'s (entries within `3·10⁻⁷` for angles to
//! 60° as far as searched, not derived,
//! `motion::tests::the_matrix_is_within_3e_7_of_its_angles_rotation`;
//! `1.7·10⁻⁷` here until reviews found 1.91 and 2.74·10⁻⁷), a rotation
//! error of that size that [`crate::Config::with_rotation_error`] covers
//! where it matters (a long focal length: `f · 10⁻⁷` pixels).
//!
//! Where the localisation errors put the true correspondent (the error band
//! around this line) and the depth interval it gives are in
//! [`crate::depth`]; how lines through the FOE are told apart by one number
//! in `crate::pencil`.

use crate::camera::{Camera, Pixel};
use crate::math::{dot3_accurate, fmax, fmin, mat3_transpose, mat3_vec, Mat3};
use crate::motion::Motion;

/// The largest `Δ/q_z` step 1 of the processor accepts (`Δ` the bound on
/// `q_z`'s change, [`PairGeometry::depth_scale_error`]), and the
/// certificate of a whole image asks of every pixel
/// ([`PairGeometry::certifies_image`]): `½ − 2⁻²⁰`. The stick's ends are
/// widened by `κ = 2Δ/q_z` plus the rounding of `1/q_z` (`2.4·10⁻⁷`), the
/// near end times `1 − κ`, which must stay above 0: with `½` itself `κ`
/// reached `1 + 2⁻²²`, and a stick whose near end lay behind the camera
/// (`s_near < 0`, the depth unbounded below) came out `ok` with a
/// positive near end (an adversarial review, twenty-ninth session;
/// `host_tests/tests/adversarial_containment.rs`,
/// `no_ok_stick_where_q_z_is_known_to_half_its_value`). Here `κ ≤
/// 1 − 2⁻¹⁹ + 2.4·10⁻⁷ < 1 − 2⁻²¹` (doubling is exact, and so is `1 − κ`
/// this near 1).
pub(crate) const HALF_KAPPA_MAX: f32 = 0.5 - 1.0 / 1_048_576.0;

/// A composed motion's largest scale error `s` a pair uses (the fusion's
/// pairs; [`PairGeometry::composition_error`]): `1 − 2⁻²⁰`. The stick's
/// near ends are multiplied by `1 − s` (the wedge paths) and `1 − s −
/// 2.4·10⁻⁷` (the band path), which must stay above 0 for the same
/// reason as `κ`'s ([`HALF_KAPPA_MAX`]): below this both are at least
/// `2⁻²⁰ − 2.4·10⁻⁷ > 7·10⁻⁷`. From it on the pair takes `s` as infinite,
/// every far end unbounded.
pub(crate) const SCALE_ERROR_MAX: f32 = 1.0 - 1.0 / 1_048_576.0;

/// The epipolar geometry of one frame pair, computed once per frame.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PairGeometry {
    h: Mat3,
    r: Mat3,
    k2: (f32, f32, f32, f32),
    /// `T' = Rᵀ T`, the compensated translation.
    tp: [f32; 3],
    w: f32,
    /// `(f_x U', f_y V')`, frame-2 pixels × length unit.
    g: [f32; 2],
    c2: [f32; 2],
    /// An upper bound on [`Compensated::stretch`] over the whole frame-1
    /// image with its margin (infinity when none is known).
    stretch_bound: f32,
    /// The compensated points the processor accepts: `[u_min, u_max,
    /// v_min, v_max]`, the frame-2 image grown by its larger side on every
    /// side (see [`PairGeometry::in_view`]).
    view: [f32; 4],
    /// How far `q_z` can move per pixel of frame-1 localisation error:
    /// `|h₂₀| + |h₂₁|` (the homography's last row is `q_z` of a pixel).
    qz_per_px: f32,
    /// The largest `|K₁⁻¹ p|` (ray length) over the frame-1 image.
    ray_max: f32,
    /// `1/min(f_x, f_y)` of camera 1, rounded up: how much longer a ray
    /// can get per pixel its point moves (the true pixel lies up to `e₁`
    /// off the detected one, outside the image too:
    /// [`Self::depth_scale_error`]).
    ray_per_px: f32,
    /// `[Ā_x, Ā_y, Ā_z]`: each row of `H`, its sums made of positive terms
    /// (`|K₂| |Rᵀ| |K₁⁻¹|`), against the largest pixel coordinates; a
    /// row's computed value at any pixel is within `E_i = 10 · 2⁻²⁴ Ā_i` of the
    /// exact one (module docs, "The error disc after compensation").
    rows: [f32; 3],
    /// The largest `|p_x|` plus the largest `|p_y|` over the compensated
    /// corners of the frame-1 image (when there is a stretch bound).
    corner_u: f32,
    /// `|h₀₀| + |h₀₁| + |h₁₀| + |h₁₁|` with positive terms, which scales
    /// the rounding of a point's stretch.
    hsum: f32,
    /// A lower bound on the computed `q_z` of every pixel of the frame-1
    /// image with its margin (not positive when there is none).
    zlow: f32,
    /// A bound on how far the computed focus of expansion lies from the
    /// exact one (of the exact `T' = Rᵀ T`), pixels; see
    /// [`Self::foe_rounding`].
    foe_round: f32,
}

/// A frame-1 pixel after exact rotation compensation.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Compensated {
    /// `p₁' = K₂ Rᵀ K₁⁻¹ p₁`, frame-2 pixels, as `[u, v]` (the per-frame
    /// path's form; [`Compensated::pixel`] gives the [`Pixel`]).
    pub(crate) pixel: [f32; 2],
    /// `1/q_z`: frame-1 depth `Z` and compensated depth `s` relate as
    /// `Z = s / q_z`.
    pub(crate) inv_depth_scale: f32,
    /// Upper bound on how much the homography stretches a small
    /// displacement at `p₁` (max of the 1- and ∞-norms of its Jacobian,
    /// both ≥ the spectral norm).
    pub(crate) stretch: f32,
}

impl Compensated {
    /// `p₁' = K₂ Rᵀ K₁⁻¹ p₁`: where the frame-1 pixel lies in frame 2 once
    /// the rotation is undone.
    pub fn pixel(&self) -> Pixel {
        Pixel::new(self.pixel[0], self.pixel[1])
    }
    /// `1/q_z`: frame-1 depth `Z` and compensated depth `s` relate as
    /// `Z = s / q_z`.
    pub fn inv_depth_scale(&self) -> f32 {
        self.inv_depth_scale
    }
    /// Upper bound on how much the homography stretches a small
    /// displacement at `p₁` (max of the 1- and ∞-norms of its Jacobian,
    /// both ≥ the spectral norm).
    pub fn stretch(&self) -> f32 {
        self.stretch
    }
}

impl PairGeometry {
    /// Geometry for frame 1 seen by `cam1`, frame 2 by `cam2`, and `motion`.
    pub fn new(cam1: &Camera, cam2: &Camera, motion: &Motion) -> Self {
        let rt = mat3_transpose(&motion.rotation_matrix());
        // `T' = Rᵀ T` rounded about once ([`dot3_accurate`]): its
        // components cancel when the motion is turned against the
        // translation, and a plain sum then puts the focus of expansion
        // far off (module docs, "The focus of expansion").
        let t = motion.translation();
        let tp = rt.map(|r| dot3_accurate(r, t));
        // `|Rᵀ| |T|`, which scales the rounding of `T'` (`γ₃` of it).
        let rt_abs = rt.map(|r| r.map(f32::abs));
        let tp_abs = mat3_vec(&rt_abs, motion.translation().map(f32::abs));
        // Camera::new guarantees fx, fy >= 1: the divisions are safe.
        let (ifx, ify) = (1.0 / cam1.fx(), 1.0 / cam1.fy());
        let (kx, ky) = (-cam1.cx() * ifx, -cam1.cy() * ify);
        // H = K₂ Rᵀ K₁⁻¹ with the zeros of the intrinsic matrices skipped.
        let (fx2, fy2, cx2, cy2) = (cam2.fx(), cam2.fy(), cam2.cx(), cam2.cy());
        let h = homography(&rt, (ifx, ify, kx, ky), (fx2, fy2, cx2, cy2));
        // The same sums with every term made positive: each entry of `h`
        // is within `γ₇` of these of the exact entry of
        // `K₂ Rᵀ K₁⁻¹` (module docs, "The error disc after compensation").
        let habs = homography(
            &rt_abs,
            (ifx, ify, kx.abs(), ky.abs()),
            (fx2, fy2, cx2.abs(), cy2.abs()),
        );
        let (w2, h2) = (f32::from(cam2.width()), f32::from(cam2.height()));
        let grow = fmax(w2, h2);
        let rows = row_bounds(&habs, cam1);
        let (stretch_bound, zmin, corner_u) = stretch_bound(&h, cam1);
        Self {
            h,
            r: motion.rotation_matrix(),
            k2: (fx2, fy2, cx2, cy2),
            tp,
            w: tp[2],
            g: [fx2 * tp[0], fy2 * tp[1]],
            c2: [cx2, cy2],
            stretch_bound,
            view: [-grow, w2 - 1.0 + grow, -grow, h2 - 1.0 + grow],
            // (|h₂₀| + |h₂₁| of the exact H: one rounding each.)
            qz_per_px: (habs[2][0] + habs[2][1]) * (1.0 + 9.6e-7),
            ray_max: ray_max(cam1),
            ray_per_px: fmax(ifx, ify) * (1.0 + 9.6e-7),
            foe_round: foe_rounding(tp, tp_abs, [fx2, fy2], [cx2, cy2]),
            rows,
            corner_u,
            hsum: (habs[0][0] + habs[0][1] + habs[1][0] + habs[1][1]) * (1.0 + 9.6e-7),
            // A computed q_z is within `E_z` of the exact one, at a corner
            // and at any pixel, so no pixel's is below the smallest
            // corner's less `2 E_z`: 2.5 E_z, and a relative 2⁻²⁰ for this
            // line's own rounding.
            zlow: {
                let z = (zmin - 1.5e-6 * rows[2]) * (1.0 - 9.6e-7);
                // (A NaN is no bound: 0, so the geometry stays equal to itself.)
                if z > 0.0 {
                    z
                } else {
                    0.0
                }
            },
        }
    }

    /// A bound on the distance, pixels, of the computed focus of
    /// expansion from the exact one (`T' = Rᵀ T` is computed within about
    /// one rounding of each component, [`dot3_accurate`], then `f U'`, the
    /// quotient and the sum round once each); 0 when `W' = 0` (no focus).
    ///
    /// With the true focus `e` and the computed `e' = e + ε`, a
    /// correspondent `p₂ − e = k (p₁' − e)` (`k` the ratio of the
    /// distances from the focus) is `p₂ − e' = k (p₁' + (1 − 1/k) ε − e')
    /// = k (p₁' − e') + (k − 1) ε`: moving forwards (`k ≥ 1`) the computed
    /// focus's geometry with the frame-1 point moved by `(1 − 1/k) ε`,
    /// moving backwards (`0 < k < 1`) with the correspondent moved by `(1 −
    /// k) ε`, each at most `|ε|` and bounded by [`Self::foe_shift`], which
    /// `crate::processor` adds to `r₁` or to `e₂`.
    pub(crate) fn foe_rounding(&self) -> f32 {
        self.foe_round
    }

    /// The shift that [`Self::foe_rounding`] stands for: moving forwards
    /// of the frame-1 point, `(1 − 1/k) |ε| = d |ε| / |p₂ − e|`; moving
    /// backwards of the correspondent in frame 2, `(1 − k) |ε| = d |ε| /
    /// |p₁' − e|` (`d` the disparity, `k` the ratio of the true points'
    /// distances from the true focus `e`; module docs). Either factor is
    /// below 1. With `L` the largest distance from the principal point
    /// `c₂` of anything in view ([`Self::view_reach`]) and `D = |e − c₂|`:
    /// the detected compensated point is in view ([`Self::in_view`]) and
    /// the true one within `r₁` of it, so `|p₁' − c₂| ≤ L + r₁`; the true
    /// correspondent lies within `e₂` of a polyline inside the image, so
    /// `|p₂ − c₂| ≤ L + e₂`. Moving forwards `1 − 1/k = 1 − |p₁' −
    /// e|/|p₂ − e| ≤ 1 − (D − L − r₁)/(D + L + e₂) = (2L + r₁ + e₂)/(D +
    /// L + e₂)`, backwards `1 − k ≤ (2L + r₁ + e₂)/(D + L + r₁)`; both at
    /// most `(2L + r₁ + e₂)/(D + L)`, which falls as `D` grows. Step 1
    /// accepts only `r₁ + e₂ ≤ L` ([`Self::r1_cap`]), so the shift is at
    /// most `|ε| min(1, 3L/(D + L))`, with `D` at least the computed
    /// focus's distance less `|ε|`. (A far focus rounds by many pixels,
    /// but its lines barely turn.)
    ///
    /// Until a review (thirtieth session) the factor was `4L/D` from `D >
    /// 2L` on, from the disparity's bound `2L` for points in view: the
    /// true points need not be, and on a 2 × 2 image (`L` ≈ 3.5 px) with
    /// `e₂` = 100 px it fell short (0.014 against up to 0.19 at `D` = 1 000 px, `e₁` =
    /// 100 px too).
    /// `3L/(D + L)` is below `4L/D` everywhere, so no stick widens.
    pub(crate) fn foe_shift(&self) -> f32 {
        self.foe_shift_of(self.foe_rounding())
    }

    /// [`Self::foe_shift`] for a focus known to within `eps` pixels.
    pub(crate) fn foe_shift_of(&self, eps: f32) -> f32 {
        let Some(e) = self.focus_of_expansion() else {
            return 0.0;
        };
        let l = self.view_reach();
        let (ex, ey) = (e.u - self.c2[0], e.v - self.c2[1]);
        // (The true focus is within `eps` of the computed one: at least
        // this far from the principal point. Until a review it was the
        // computed focus's distance, which a composed motion's focus
        // error, `composition_error`, can make far too large. The
        // distance scaled by the larger offset: `ex² + ey²` overflows
        // from about 1.8·10¹⁹ px on, and a reviewer found the shift 0
        // there, `de` infinite, for a focal length of 10⁵ px and `W/U`
        // of 10⁻¹⁵; `m (1 + q²)^½` rounds a few times, within the 10⁻⁵.)
        let m = fmax(ex.abs(), ey.abs());
        let q = fmin(ex.abs(), ey.abs()) / m;
        let de = m * crate::math::sqrt(1.0 + q * q) * (1.0 - 1.0e-5) - eps;
        // (A NaN keeps the whole rounding, as does a distance that is not
        // finite: from `D > 2L` on the factor is below 1.)
        if de > 2.0 * l && de < f32::INFINITY {
            eps * (3.0 * l / (de + l)) * (1.0 + 1.0e-5)
        } else {
            eps
        }
    }

    /// `L`: the largest distance from the principal point `c₂` of anything
    /// in view ([`Self::in_view`]), rounded up by a relative 10⁻⁵.
    pub(crate) fn view_reach(&self) -> f32 {
        let [u0, u1, v0, v1] = self.view;
        let (dx, dy) = (
            fmax((u0 - self.c2[0]).abs(), (u1 - self.c2[0]).abs()),
            fmax((v0 - self.c2[1]).abs(), (v1 - self.c2[1]).abs()),
        );
        crate::math::sqrt(dx * dx + dy * dy) * (1.0 + 1.0e-5)
    }

    /// The largest `r₁` step 1 accepts for frame-2 errors `e2`: `L − e₂`
    /// ([`Self::view_reach`]), rounded down, so that a true frame-1 point
    /// and a true correspondent both lie within `2L` of `c₂`, as
    /// [`Self::foe_shift`] needs. Negative (every point refused) when `e₂`
    /// is past `L`: a 2 × 2 image with `e₂` above about 3.5 px. For the
    /// paper's 512 × 480 camera `L` is about 1 074 px.
    pub(crate) fn r1_cap(&self, e2: f32) -> f32 {
        let l = self.view_reach();
        (l - e2) - l * 1.0e-6
    }

    /// Where the motion given may be off the true one by its composition's
    /// rounding (`T` by at most `mt`, `R` by at most `mr` as a matrix,
    /// `|R_t v − R v| ≤ mr |v|`: [`crate::Config`]'s `motion_rounding`),
    /// `T' = Rᵀ T` is off by a vector `(a, c, b)` of length at most `dt =
    /// mr (|T| + mt) + (1 + mr) mt` (`(R_t − R)ᵀ T_t + Rᵀ (T_t − T)`). The
    /// focus `e = c₂ + (f_x U', f_y V')/W'` moves by exactly `(f_x a − d_x
    /// b, f_y c − d_y b)/W'_t` (`d = e − c₂`), at most `√(f² + |d|²) dt /
    /// (|W'| − dt)` (`f` the larger focal length; Cauchy–Schwarz), and
    /// `W'` by a relative `dt/(|W'| − dt)`: once the focus's error is a
    /// shift ([`Self::foe_rounding`]) the scale of every depth. Returns
    /// `(focus error, pixels; scale)`, rounded up; both infinite when `dt`
    /// is not below `|W'|/2` (no focus, or `W'`'s sign in doubt: nothing
    /// can be certified).
    pub(crate) fn composition_error(&self, mt: f32, mr: f32) -> (f32, f32) {
        let dt = composition_dt(self.translation_norm() * (1.0 + 1.0e-5), mt, mr);
        let w = self.tp[2].abs();
        // (A NaN fails.)
        if !(dt < 0.5 * w) {
            return (f32::INFINITY, f32::INFINITY);
        }
        let Some(e) = self.focus_of_expansion() else {
            return (f32::INFINITY, f32::INFINITY);
        };
        let (fx, fy, _, _) = self.k2;
        let f = fmax(fx, fy);
        let (dx, dy) = (e.u - self.c2[0], e.v - self.c2[1]);
        let wl = (w - dt) * (1.0 - 1.0e-5);
        let eps = crate::math::sqrt(f * f + dx * dx + dy * dy) * dt / wl * (1.0 + 1.0e-5);
        let scale = dt / wl * (1.0 + 1.0e-5);
        if eps.is_finite() && scale.is_finite() {
            (eps, scale)
        } else {
            (f32::INFINITY, f32::INFINITY)
        }
    }

    /// How far the rotation compensation of a frame-1 pixel moves, in
    /// frame-2 pixels, when the motion's matrix is off by at most `mr`
    /// (`|R_t v − R v| ≤ mr |v|`, the composition's rounding), at a
    /// compensated point whose normalised offset from the principal point
    /// is at most that of `p` on each axis: the compensated ray `r' = Rᵀ
    /// q` (`q` the frame-1 ray) moves by a vector `η`, `|η| ≤ mr |q| ≈ mr
    /// |r'|`, so its image `(x', y')` by `(|η_xy| + ρ' |η_z|)/(r'_z −
    /// |η_z|) ≤ mr (1 + ρ'²)/(1 − mr √(1 + ρ'²))` (Cauchy–Schwarz, `ρ'² =
    /// x'² + y'²`), times the larger focal length in pixels; rounded up
    /// (`|q| ≤ |r'| (1 + 10⁻⁵)`: `R` within `10⁻⁵` of a rotation).
    /// Infinite where the bound fails.
    pub(crate) fn composition_shift(&self, p: [f32; 2], mr: f32) -> f32 {
        let (fx, fy, cx, cy) = self.k2;
        let (x, y) = ((p[0] - cx) / fx, (p[1] - cy) / fy);
        let rho2 = x * x + y * y;
        let m = mr * (1.0 + 1.0e-5);
        let den = 1.0 - m * crate::math::sqrt(1.0 + rho2);
        // (A NaN fails.)
        if !(den > 0.5) {
            return f32::INFINITY;
        }
        let s = fmax(fx, fy) * m * (1.0 + rho2) / den * (1.0 + 1.0e-5);
        if s.is_finite() {
            s
        } else {
            f32::INFINITY
        }
    }

    /// The point of the frame-2 view widened by `r` farthest from the
    /// principal point along each axis (where a shift bound that grows
    /// with both distances is largest over every point in view within `r`
    /// of it).
    pub(crate) fn far_corner(&self, r: f32) -> [f32; 2] {
        let [u0, u1, v0, v1] = self.view;
        let (cx, cy) = (self.c2[0], self.c2[1]);
        [
            cx + (fmax((u0 - cx).abs(), (u1 - cx).abs()) + r),
            cy + (fmax((v0 - cy).abs(), (v1 - cy).abs()) + r),
        ]
    }

    /// The rotation `R` of the motion.
    pub(crate) fn rotation(&self) -> &Mat3 {
        &self.r
    }

    /// `|T|`, the length of the translation.
    pub(crate) fn translation_norm(&self) -> f32 {
        let [tx, ty, tz] = self.tp;
        crate::math::sqrt(tx * tx + ty * ty + tz * tz)
    }

    /// Frame-2 intrinsics `(f_x, f_y, c_x, c_y)`.
    pub(crate) fn camera2_intrinsics(&self) -> (f32, f32, f32, f32) {
        self.k2
    }

    /// The frame-2 principal point.
    pub(crate) fn c2(&self) -> [f32; 2] {
        self.c2
    }

    /// `(f_x U', f_y V')`.
    pub(crate) fn g(&self) -> [f32; 2] {
        self.g
    }

    /// `W'`, the forward component of the rotation-compensated translation.
    pub fn w(&self) -> f32 {
        self.w
    }

    /// The focus of expansion in frame-2 pixels (eq. A.1 with the
    /// compensated translation), `None` when it is at infinity (`W' = 0`)
    /// or beyond the range of `f32`.
    pub fn focus_of_expansion(&self) -> Option<Pixel> {
        if self.w == 0.0 {
            return None;
        }
        let f = [
            self.c2[0] + self.g[0] / self.w,
            self.c2[1] + self.g[1] / self.w,
        ];
        (f[0].is_finite() && f[1].is_finite()).then_some(Pixel::new(f[0], f[1]))
    }

    /// The epipolar vector `a = W'(p − c₂) − (f_x U', f_y V')` of a
    /// compensated point `p` (frame-2 pixels): the direction of its
    /// disparity, `p₂ = p + τ a`.
    #[inline(always)]
    pub(crate) fn epipolar_vector(&self, p: [f32; 2]) -> [f32; 2] {
        [
            self.w * (p[0] - self.c2[0]) - self.g[0],
            self.w * (p[1] - self.c2[1]) - self.g[1],
        ]
    }

    /// Exact rotation compensation of a frame-1 pixel with its own stretch
    /// bound; `None` when the ray points behind the frame-2 camera
    /// orientation (`q_z ≤ 1e-6`).
    pub fn compensate(&self, p1: Pixel) -> Option<Compensated> {
        self.compensate_with(p1, None)
    }

    /// [`Self::compensate`] with `stretch` as the stretch bound (the
    /// frame-wide one, [`Self::frame_stretch`]), or the point's own when
    /// `None`.
    #[inline(always)]
    pub(crate) fn compensate_with(&self, p1: Pixel, stretch: Option<f32>) -> Option<Compensated> {
        let [x, y, z] = mat3_vec(&self.h, [p1.u, p1.v, 1.0]);
        if z <= 1.0e-6 {
            return None;
        }
        let iz = 1.0 / z;
        let (px, py) = (x * iz, y * iz);
        let stretch = stretch.unwrap_or_else(|| {
            // Jacobian of (x/z, y/z) with respect to (u, v).
            let [[h00, h01, _], [h10, h11, _], [h20, h21, _]] = self.h;
            let j00 = (h00 - px * h20) * iz;
            let j01 = (h01 - px * h21) * iz;
            let j10 = (h10 - py * h20) * iz;
            let j11 = (h11 - py * h21) * iz;
            let n1 = fmax(j00.abs() + j10.abs(), j01.abs() + j11.abs());
            let ninf = fmax(j00.abs() + j01.abs(), j10.abs() + j11.abs());
            fmax(n1, ninf)
        });
        Some(Compensated {
            pixel: [px, py],
            inv_depth_scale: iz,
            stretch,
        })
    }

    /// [`Self::compensate_with`] with the frame-wide stretch bound `stretch`
    /// for a pixel known to compensate in front ([`Self::certifies_image`]):
    /// the same values without the test of `q_z`.
    #[inline(always)]
    pub(crate) fn compensate_certified(&self, p1: Pixel, stretch: f32) -> Compensated {
        let [x, y, z] = mat3_vec(&self.h, [p1.u, p1.v, 1.0]);
        let iz = 1.0 / z;
        Compensated {
            pixel: [x * iz, y * iz],
            inv_depth_scale: iz,
            stretch,
        }
    }

    /// Whether every pixel of `cam`'s image with its margin passes the
    /// processor's step-1 checks (module `processor`): `q_z > 10⁻⁶`, the
    /// compensated point [`Self::in_view`], and `dse / q_z ≤`
    /// [`HALF_KAPPA_MAX`] for the bound `dse` on `q_z`'s change, each
    /// computed in `f32`.
    ///
    /// On the image rectangle `q_z = h₂₀u + h₂₁v + h₂₂` is affine and, where
    /// it is positive, the compensated coordinates are linear-fractional,
    /// so all three take their extremes at the corners. A pixel's computed
    /// `q_z` is within `2⁻²² A` of the exact value (`A = |h₂₀| u_max +
    /// |h₂₁| v_max + |h₂₂|`, three roundings), and so is each corner's;
    /// the corners are required to pass with twice that, and the
    /// coordinates within twice their own rounding bound of the view's
    /// edges. Then no point of the image fails, and step 1 can skip the
    /// checks (the same results, bit for bit).
    pub(crate) fn certifies_image(&self, cam: &Camera, dse: f32) -> bool {
        let m = crate::camera::IMAGE_MARGIN_PX;
        let (u1, v1) = (
            f32::from(cam.width()) - 1.0 + m,
            f32::from(cam.height()) - 1.0 + m,
        );
        let (umax, vmax) = (fmax(m, u1), fmax(m, v1));
        let bound = |r: [f32; 3]| r[0].abs() * umax + r[1].abs() * vmax + r[2].abs();
        let [hx, hy, hz] = self.h;
        let (ax, ay, az) = (bound(hx), bound(hy), bound(hz));
        let corners = [[-m, -m], [u1, -m], [-m, v1], [u1, v1]];
        let mut zmin = f32::INFINITY;
        for [u, v] in corners {
            zmin = fmin(zmin, mat3_vec(&self.h, [u, v, 1.0])[2]);
        }
        // The smallest q_z any pixel computes, over a relative 2⁻²⁰.
        let zlow = (zmin - 9.6e-7 * az) * (1.0 - 9.6e-7);
        // (A NaN fails.)
        if !(zlow > 1.0e-6 && dse <= HALF_KAPPA_MAX * zlow * (1.0 - 9.6e-7)) {
            return false;
        }
        let p = corners.map(|[u, v]| {
            let [x, y, z] = mat3_vec(&self.h, [u, v, 1.0]);
            let iz = 1.0 / z;
            [x * iz, y * iz]
        });
        let (mut bx, mut by) = (0.0f32, 0.0f32);
        for [px, py] in p {
            (bx, by) = (fmax(bx, px.abs()), fmax(by, py.abs()));
        }
        // Twice the rounding bound of a computed coordinate, at a pixel or
        // at a corner: (|Δx| + |p| |Δq_z|)/q_z plus its own rounding.
        let ex = 4.8e-7 * ((ax + bx * az) / zlow + bx);
        let ey = 4.8e-7 * ((ay + by * az) / zlow + by);
        let [u0, u1, v0, v1] = self.view;
        // (A NaN fails.)
        p.iter()
            .all(|&[px, py]| px - ex >= u0 && px + ex <= u1 && py - ey >= v0 && py + ey <= v1)
    }

    /// The frame-wide stretch bound, if there is one.
    pub(crate) fn frame_stretch(&self) -> Option<f32> {
        self.stretch_bound.is_finite().then_some(self.stretch_bound)
    }

    /// Whether a compensated point lies within the frame-2 image grown by
    /// its larger side on every side (a NaN fails).
    ///
    /// A point farther out can only correspond to a frame-2 point at a
    /// disparity larger than the image: for `W' > 0` with the FOE in view
    /// none at all (the frame-2 point lies farther from the FOE), otherwise
    /// a depth below about `|T| f / width`, closer to the camera than the
    /// travel of one frame. The processor flags such points
    /// ([`crate::Status::OutOfView`]); the bound also keeps every
    /// coordinate the search handles below `3 × 16 384` px, where `f32`
    /// resolves 4·10⁻³ px.
    #[inline(always)]
    pub(crate) fn in_view(&self, p: [f32; 2]) -> bool {
        let [u0, u1, v0, v1] = self.view;
        p[0] >= u0 && p[0] <= u1 && p[1] >= v0 && p[1] <= v1
    }

    /// The largest coordinate magnitude of anything the search compares:
    /// the accepted compensated points and the frame-2 image (pixels).
    pub(crate) fn coordinate_scale(&self) -> f32 {
        let [u0, u1, v0, v1] = self.view;
        fmax(fmax(u0.abs(), u1.abs()), fmax(v0.abs(), v1.abs()))
    }

    /// The bound on how far `q_z` moves when the frame-1 point moves within
    /// `e1` pixels and the rotation is off by up to `rotation_error`
    /// radians about each axis: `e₁ (|h₂₀| + |h₂₁|)` for the pixel (the
    /// last row of `H` is `q_z` as a function of the pixel) plus
    /// `1.05 Σε |K₁⁻¹ p|` for the rotation (`q_z` is the third column of
    /// `R` against the ray; each elementary rotation's derivative has unit
    /// norm, 5 % for the second order, the sum of the angles being at most
    /// 0.1 rad), the ray's length taken at the **true** pixel, which lies
    /// up to `e₁` off the detected one and so up to `e₁` outside the image:
    /// `|K₁⁻¹ p_t| ≤ |K₁⁻¹ p| + e₁/min(f_x, f_y)` (the pixel step is `(δu/f_x,
    /// δv/f_y, 0)` in the ray), rounded up. (Until the twenty-ninth session
    /// the image's own largest ray: an adversarial review's 8 × 8 image at
    /// `f = 10` with `e₁ = 100` px and a rotation error of 0.02 had a true
    /// `q_z` of 0.792 against a computed 1 and `κ` 0.05, and an `ok` point's
    /// truth 14.7 % past its far end; `host_tests/tests/adversarial_containment.rs`,
    /// `the_rotation_errors_change_of_q_z_is_taken_at_the_true_pixel`.)
    ///
    /// Plus `8 E_z` for the rounding of the computed `q_z`
    /// itself (at most `E_z`, [`row_bounds`]), which also bounds that
    /// rounding relative to an accepted point's `q_z`: step 1 flags a point
    /// whose `Δ/q_z` exceeds [`HALF_KAPPA_MAX`], just under ½, so an
    /// accepted one has `E_z/q_z ≤ 1/16`
    /// (module docs, "The error disc after compensation").
    pub(crate) fn depth_scale_error(&self, e1: f32, rotation_error: [f32; 3]) -> f32 {
        let [ex, ey, ez] = rotation_error;
        let ray = (self.ray_max + e1 * self.ray_per_px) * (1.0 + 9.6e-7);
        e1 * self.qz_per_px + 1.05 * (ex + ey + ez) * ray + 4.77e-6 * self.rows[2]
    }

    /// The radius of the compensated error disc (module docs, "The error
    /// disc after compensation") of every point step 1 accepts from the
    /// frame-1 image, without a rotation error; `None` when the frame has
    /// no stretch bound.
    ///
    /// An accepted point's terms are bounded frame-wide: its stretch by the
    /// stretch bound, `1/q_z` by `1/zlow`, `u = |p_x| + |p_y|` by the
    /// corners' (the extremes of `p_x` and `p_y` are at corners, as for the
    /// stretch bound, rounded by at most `ρ` each; and `u ≤ 2S` in view),
    /// and `x` by its own `½`. [`Self::disc_bound`] grows with each. The
    /// stretch bound takes its extremes from the corners' rounded `p_x`,
    /// `p_y`: that moves each Jacobian entry by up to `ρ |h₂ⱼ| / zlow`,
    /// added to it.
    pub(crate) fn frame_disc_radius(&self, e1: f32) -> Option<f32> {
        // (A NaN fails.)
        if !(self.stretch_bound.is_finite() && self.zlow > 0.0) {
            return None;
        }
        let iz = 1.0 / self.zlow;
        let in_view = 2.0 * self.coordinate_scale();
        let u = fmin(in_view, self.corner_u + 2.0 * self.rounding(in_view, iz));
        let stretch = self.stretch_bound + 1.07 * self.rounding(u, iz) * self.qz_per_px * iz;
        let r = self.disc_bound(e1, stretch, iz, u);
        r.is_finite().then_some(r)
    }

    /// The radius of the compensated error disc of one point `c` that step
    /// 1 accepts (module docs, "The error disc after compensation"),
    /// without a rotation error's shift.
    #[inline(always)]
    pub(crate) fn point_disc_radius(&self, c: &Compensated, e1: f32) -> f32 {
        let u = c.pixel[0].abs() + c.pixel[1].abs();
        self.disc_bound(e1, c.stretch, c.inv_depth_scale, u)
    }

    /// `ρ = 1.074 (E_x + E_y + u E_z)/q_z + 1.048 · 2⁻²³ u`, the bound on a
    /// compensated point's rounding (module docs).
    #[inline(always)]
    fn rounding(&self, u: f32, iz: f32) -> f32 {
        let [ax, ay, az] = self.rows;
        6.4e-7 * ((ax + ay + u * az) * iz) + 1.25e-7 * u
    }

    /// `r = e₁ (σ (1 + 2ζ) + 2⁻²⁰ (|h|₁ + u |h₂|₁)/q_z) (1 + 2x)(1 + 2⁻²⁰) +
    /// ρ (1 + 1.2 x (1 + 2x))`, `ζ = 2 E_z/q_z`, `x = min(e₁ |h₂|₁/q_z, ½)`, for a
    /// point with stretch `σ`, `1/q_z = iz` and `u = |p_x| + |p_y|` (module
    /// docs, "The error disc after compensation").
    #[inline(always)]
    fn disc_bound(&self, e1: f32, stretch: f32, iz: f32, u: f32) -> f32 {
        let zeta = 1.192e-6 * self.rows[2] * iz;
        let x = fmin(e1 * self.qz_per_px * iz, 0.5);
        let jac = stretch * (1.0 + 2.0 * zeta) + 9.54e-7 * (self.hsum + u * self.qz_per_px) * iz;
        let grow = 1.0 + 2.0 * x;
        e1 * jac * (grow * (1.0 + 9.6e-7)) + self.rounding(u, iz) * (1.0 + 1.2 * x * grow)
    }
}

/// `K₂ Rᵀ K₁⁻¹` from `Rᵀ`, `K₁⁻¹`'s entries `(1/f_x, 1/f_y, −c_x/f_x,
/// −c_y/f_y)` and `K₂`'s `(f_x, f_y, c_x, c_y)`, with the zeros of the
/// intrinsic matrices skipped (or the same sums of positive terms, from
/// their magnitudes).
fn homography(
    rt: &Mat3,
    (ifx, ify, kx, ky): (f32, f32, f32, f32),
    k2: (f32, f32, f32, f32),
) -> Mat3 {
    let (fx2, fy2, cx2, cy2) = k2;
    let [a, b, c] = rt.map(|[r0, r1, r2]| [r0 * ifx, r1 * ify, r0 * kx + r1 * ky + r2]);
    let row = |f: f32, r: [f32; 3], k: f32| {
        [
            f * r[0] + k * c[0],
            f * r[1] + k * c[1],
            f * r[2] + k * c[2],
        ]
    };
    [row(fx2, a, cx2), row(fy2, b, cy2), c]
}

/// [`PairGeometry::foe_rounding`] from `T'` (computed), `|Rᵀ| |T|` and
/// frame 2's focal lengths and principal point: per axis, with `δ =
/// 1.0001 · 2⁻²⁴ |T'| + 10 · 2⁻⁴⁸ |Rᵀ| |T|` bounding `T'`'s rounding
/// ([`dot3_accurate`]) and `d` the focus's
/// offset from the principal point, `(f δ_U + |d| δ_W)/|W'|` for `T'`,
/// `2 · 2⁻²⁴ |d|` for `f U'` and the quotient and `2⁻²⁴ |e|` for the sum,
/// doubled (the second order, and this function's own rounding); the two
/// axes summed.
fn foe_rounding(tp: [f32; 3], tp_abs: [f32; 3], f: [f32; 2], c: [f32; 2]) -> f32 {
    let w = tp[2].abs();
    // (A NaN or no focus: no claim, 0; the processor finds no focus then.)
    if !(w > 0.0) {
        return 0.0;
    }
    let dt = |t: f32, a: f32| 6.0e-8 * t.abs() + 4.0e-14 * a;
    let ([tu, tv, tw], [au, av, aw]) = (tp, tp_abs);
    let (du, dv, dw) = (dt(tu, au), dt(tv, av), dt(tw, aw));
    let axis = |fi: f32, ti: f32, dt: f32, ci: f32| {
        let d = (fi * ti / tp[2]).abs();
        ((fi * dt + d * dw) / w + 1.2e-7 * d + 6.0e-8 * (ci.abs() + d)) * 2.0
    };
    let e = axis(f[0], tp[0], du, c[0]) + axis(f[1], tp[1], dv, c[1]);
    if e.is_finite() {
        e
    } else {
        f32::INFINITY
    }
}

/// The error of `T' = Rᵀ T` when `T` (length `tn`) is off by at most `mt`
/// and the matrix by at most `mr` (`|R_t v − R v| ≤ mr |v|`): `mr (tn +
/// mt) + (1 + mr) mt`, from `(R_t − R)ᵀ T_t + Rᵀ (T_t − T)`, rounded up
/// ([`PairGeometry::composition_error`], and the fusion's chain).
pub(crate) fn composition_dt(tn: f32, mt: f32, mr: f32) -> f32 {
    (mr * (tn + mt) + (1.0 + mr) * mt) * (1.0 + 1.0e-5)
}

/// An upper bound on `|K⁻¹ p|` over the image of `cam` with its margin.
fn ray_max(cam: &Camera) -> f32 {
    let m = crate::camera::IMAGE_MARGIN_PX;
    let dx = fmax(cam.cx() + m, f32::from(cam.width()) - 1.0 + m - cam.cx()) / cam.fx();
    let dy = fmax(cam.cy() + m, f32::from(cam.height()) - 1.0 + m - cam.cy()) / cam.fy();
    // Rounded up by a relative 1e-5.
    crate::math::sqrt(1.0 + dx * dx + dy * dy) * (1.0 + 1.0e-5)
}

/// An upper bound on the stretch of `h` (see [`Compensated::stretch`]) over
/// the image of `cam` with its margin, or infinity.
///
/// On the image rectangle `z = h₂₀u + h₂₁v + h₂₂` is linear and the
/// compensated coordinates `x/z`, `y/z` are linear-fractional, so with
/// `z > 0` all three take their extremes at the corners. Each entry of the
/// Jacobian, e.g. `(h₀₀ − p_x h₂₀)/z`, is then bounded by the larger of its
/// numerator's values at the extremes of `p_x` over the smallest `z`; the
/// 1- and ∞-norms of those bounds bound the stretch everywhere. It exceeds
/// the largest point's own value by under 1 % for rotations up to 1° about
/// each axis and under 5 % up to 5° (test `frame_stretch_bound_holds_and_is_tight`),
/// and saves the computation per point.
/// Also returns the smallest computed `q_z` of the corners and the largest
/// `|p_x|` plus the largest `|p_y|` of the compensated corners.
fn stretch_bound(h: &Mat3, cam: &Camera) -> (f32, f32, f32) {
    let m = crate::camera::IMAGE_MARGIN_PX;
    let (u1, v1) = (
        f32::from(cam.width()) - 1.0 + m,
        f32::from(cam.height()) - 1.0 + m,
    );
    let [[h00, h01, h02], [h10, h11, h12], [h20, h21, h22]] = *h;
    // A row of H at the corners: (h_0 u + h_1 v) + h_2, as `mat3_vec` sums.
    let row = |a: f32, b: f32, c: f32| {
        let (au0, au1, bv0, bv1) = (a * -m, a * u1, b * -m, b * v1);
        [au0 + bv0 + c, au1 + bv0 + c, au0 + bv1 + c, au1 + bv1 + c]
    };
    let (xs, ys, zs) = (row(h00, h01, h02), row(h10, h11, h12), row(h20, h21, h22));
    let [z0, z1, z2, z3] = zs;
    let zmin = fmin(fmin(z0, z1), fmin(z2, z3));
    // (A NaN corner gives a NaN bound below, which is refused too.)
    if zmin.is_nan() || zmin <= 1.0e-3 {
        return (f32::INFINITY, zmin, f32::INFINITY);
    }
    let extremes = |ps: [f32; 4]| {
        let [p0, p1, p2, p3] = ps;
        let (lo01, hi01) = if p0 < p1 { (p0, p1) } else { (p1, p0) };
        let (lo23, hi23) = if p2 < p3 { (p2, p3) } else { (p3, p2) };
        (fmin(lo01, lo23), fmax(hi01, hi23))
    };
    let (xmin, xmax) = extremes([xs[0] / z0, xs[1] / z1, xs[2] / z2, xs[3] / z3]);
    let (ymin, ymax) = extremes([ys[0] / z0, ys[1] / z1, ys[2] / z2, ys[3] / z3]);
    let bound =
        |c: f32, p0: f32, p1: f32, k: f32| fmax((c - p0 * k).abs(), (c - p1 * k).abs()) / zmin;
    let j00 = bound(h00, xmin, xmax, h20);
    let j01 = bound(h01, xmin, xmax, h21);
    let j10 = bound(h10, ymin, ymax, h20);
    let j11 = bound(h11, ymin, ymax, h21);
    let n1 = fmax(j00 + j10, j01 + j11);
    let ninf = fmax(j00 + j01, j10 + j11);
    // A relative 1e-5 covers the rounding of this computation.
    let b = fmax(n1, ninf) * (1.0 + 1.0e-5);
    let u = fmax(xmin.abs(), xmax.abs()) + fmax(ymin.abs(), ymax.abs());
    (if b.is_finite() { b } else { f32::INFINITY }, zmin, u)
}

/// `[Ā_x, Ā_y, Ā_z]`: `h_i0 u_max + h_i1 v_max + h_i2` for each row of
/// `habs` (the entries of `H` with their sums made of positive terms), with
/// `u_max`, `v_max` the largest coordinate magnitudes of `cam`'s image with
/// its margin. A row's value at a pixel, computed as `mat3_vec` does (the
/// `u` and `v` terms each see their product and two sums), is within
/// `γ₃ A_i` of the value of the computed entries (`A_i ≤ Ā_i` with
/// `|h_ij|`), and that within `γ₇ Ā_i` of the exact `K₂ Rᵀ K₁⁻¹`'s (each
/// entry is at most seven roundings deep): together under `E_i = 10 ·
/// 2⁻²⁴ Ā_i`, the second order covered by this rounding up.
fn row_bounds(h: &Mat3, cam: &Camera) -> [f32; 3] {
    let m = crate::camera::IMAGE_MARGIN_PX;
    let umax = fmax(m, f32::from(cam.width()) - 1.0 + m);
    let vmax = fmax(m, f32::from(cam.height()) - 1.0 + m);
    // Rounded up by a relative 1e-6 (five roundings).
    h.map(|r| (r[0].abs() * umax + r[1].abs() * vmax + r[2].abs()) * (1.0 + 1.0e-6))
}

#[cfg(test)]
mod tests;
