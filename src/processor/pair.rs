//! One frame pair's constants ([`Pair`]): the geometry, the error
//! model's bounds as step 4 uses them, the keys; and how far a composed
//! motion may be from the exact composition ([`Rounding`], module docs of
//! [`crate::processor`], "The composition's rounding").

use super::*;

/// Everything about one frame pair that does not change from point to
/// point.
pub(super) struct Pair<'c> {
    pub(super) config: &'c Config,
    pub(super) geom: PairGeometry,
    pub(super) foe: Option<[f32; 2]>,
    pub(super) reach: f32,
    pub(super) scale: f32,
    /// What `r₁` adds to the disc: the rounding slack (see
    /// [`crate::depth`]), and moving forwards the
    /// focus of expansion's rounding.
    pub(super) slack_r1: f32,
    /// What `e₂` adds: the slack, and moving backwards the focus's
    /// rounding (as a frame-2 shift, [`PairGeometry::foe_shift`]).
    pub(super) slack_e2: f32,
    /// The largest `r₁` step 1 accepts ([`PairGeometry::r1_cap`]: the
    /// focus's shift, [`PairGeometry::foe_shift`], is bounded for true
    /// points within `2L` of the principal point).
    pub(super) r1_cap: f32,
    /// `r₁` for every point when the stretch bound is frame-wide and no
    /// rotation error is configured, and it is within `r1_cap`.
    pub(super) frame_r1: Option<f32>,
    /// `frame_r1` when, moreover, every pixel of the frame-1 image passes
    /// step 1's checks ([`PairGeometry::certifies_image`]).
    pub(super) certified_r1: Option<f32>,
    /// `Δ`, the bound on `q_z`'s change ([`PairGeometry::depth_scale_error`]).
    pub(super) depth_scale_error: f32,
    /// The translation-error bound per component (with the turn of the
    /// compensated translation by a rotation error), and `σ_w`.
    pub(super) translation: f32,
    pub(super) spread_w: f32,
    /// `2/sin φ_min = √(4 + (2 cot φ_min)²)`, for the grazing test.
    pub(super) csc_twice: f32,
    /// `W'` with the stick's outward rounding folded in
    /// ([`crate::wedge::stick_w`]), and the composition's scale error.
    pub(super) w_stick: [f32; 3],
    /// The composition's scale error `s` (module docs, "The
    /// composition's rounding"), by which the band path's stick ends
    /// move outwards.
    pub(super) scale_motion: f32,
    /// The thinning's `ε` when frame 2's boundaries are thinned
    /// ([`crate::thin`]; 0 when not), part of [`Self::e2`].
    pub(super) thin: f32,
}

impl<'c> Pair<'c> {
    /// The pair of `motion` with `config`, whose rotation error box is the
    /// configured one (`configured`) or, for a motion composed within
    /// `rounding` of the true one, that box widened to hold the matrix's
    /// error too ([`composition_box`]).
    pub(super) fn new(
        config: &'c Config,
        configured: [f32; 3],
        cam1: &Camera,
        cam2: &Camera,
        motion: &Motion,
        rounding: Rounding,
    ) -> Self {
        let geom = PairGeometry::new(cam1, cam2, motion);
        let [ex, ey, ez] = configured;
        let rotation = ex + ey + ez > 0.0;
        // A rotation error turns the true compensated translation
        // `R_tᵀ T_t` away from `Rᵀ T_t` by up to `θ |T_t|` (`θ ≤ Σε`, 5 %
        // added for the second order), and `|T_t| ≤ |T| + √3 δ` for a true
        // translation within the box `±δ`: that much more on each frame-1
        // component covers it (`Rᵀ` of the wider box holds `Rᵀ` of the
        // box plus any vector that long). (An adversary found the turn of
        // `δ` missing: `|T|` alone fell 5.7 % short of `W'`'s spread with
        // `δ = 0.3 |T|`, `ε = 0.1`; no stick missed.)
        let delta = config.translation_error;
        let translation = delta
            + if rotation {
                1.05 * (geom.translation_norm() + 1.7321 * delta) * (ex + ey + ez)
            } else {
                0.0
            };
        let spread_w = if translation > 0.0 {
            crate::motion_error::spread(
                geom.rotation(),
                geom.camera2_intrinsics(),
                geom.c2(),
                translation,
            )
            .1
        } else {
            0.0
        };
        let scale = geom.coordinate_scale();
        let slack = scale * 9.54e-7;
        // The composition's rounding (a composed motion, `crate::fusion`;
        // module docs, "The composition's rounding"): the focus's error
        // and `W'`'s relative error from `T'`'s here, the matrix's shift
        // below (and point by point in `config`, `composition_box`).
        let Rounding {
            translation: mt,
            matrix: mr,
            in_config,
        } = rounding;
        // (With `in_config` the translation error of the configuration
        // holds `T'`'s: the band path carries it, and nothing is added
        // here for it.)
        let composed = !in_config && (mt > 0.0 || mr > 0.0);
        let (foe_comp, scale_comp) = if composed {
            let (f, s) = geom.composition_error(mt, mr);
            // (The stick's near ends are multiplied by `1 − s` (the wedge
            // paths, `w_stick`) and by `1 − s − 2.4·10⁻⁷` (the band path),
            // which must stay above 0, else a near end behind the camera
            // turns positive; `composition_error`'s own test lets `s` reach
            // about `1 + 2·10⁻⁵`. From `SCALE_ERROR_MAX` on, infinite:
            // every far end unbounded, no point `ok`.)
            let s = s * 1.0001;
            let s = if s < crate::epipolar::SCALE_ERROR_MAX {
                s
            } else {
                f32::INFINITY
            };
            (f, s)
        } else {
            (0.0, 0.0)
        };
        // The focus's rounding (`PairGeometry::foe_shift`): moving
        // forwards as a shift of the frame-1 point, backwards as one of
        // the correspondent in frame 2.
        let foe = if composed {
            geom.foe_shift_of(geom.foe_rounding() + foe_comp)
        } else {
            geom.foe_shift()
        };
        let (slack_r1, slack_e2) = if geom.w() > 0.0 {
            (slack + foe, slack)
        } else {
            (slack, slack + foe)
        };
        // (No focus, or one not known to half of `W'`: nothing certified.)
        let slack_r1 = if foe_comp.is_finite() {
            slack_r1
        } else {
            f32::INFINITY
        };
        let r1_cap = geom.r1_cap(config.e2);
        let frame_r1 = match geom.frame_disc_radius(config.e1) {
            // The composition's error of the matrix shifts every
            // compensated point: at most its bound where the view,
            // widened by the disc, is farthest from the principal point.
            Some(r) if !rotation && mr > 0.0 => {
                let shift = geom.composition_shift(geom.far_corner(r + slack_r1), mr);
                Some(r + shift + slack_r1).filter(|r| r.is_finite())
            }
            Some(r) if !rotation => Some(r + slack_r1).filter(|r| r.is_finite()),
            _ => None,
        };
        // (Past the cap each point is judged alone, step 1's own test.)
        let frame_r1 = frame_r1.filter(|&r| r <= r1_cap);
        // (`q_z` moves by at most `mr |q|` with the matrix, as by a
        // rotation error of `mr` about one axis: the configured box, not
        // the one widened for the points' shift.)
        let depth_scale_error = geom.depth_scale_error(config.e1, [ex + mr, ey, ez]);
        Self {
            config,
            foe: geom.focus_of_expansion().map(Pixel::arr),
            reach: crate::math::sqrt(cam2.reach2()),
            scale,
            slack_r1,
            slack_e2,
            r1_cap,
            frame_r1,
            certified_r1: frame_r1.filter(|_| geom.certifies_image(cam1, depth_scale_error)),
            depth_scale_error,
            translation,
            spread_w,
            csc_twice: crate::math::sqrt_pos(4.0 + config.cot_twice * config.cot_twice),
            // (Moving forwards, the wedge paths: the ends widened by the
            // composition's scale, `1 ± s` outwards, before `q_z`'s; `s = 0`
            // keeps them, the products exact.)
            w_stick: {
                let [w, up, down] = crate::wedge::stick_w(geom.w());
                [w, up * (1.0 + scale_comp), down * (1.0 - scale_comp)]
            },
            scale_motion: scale_comp,
            thin: 0.0,
            geom,
        }
    }

    /// The keying for the frame-2 boundary `b2` (half-plane keys when it
    /// lies wholly above or below the FOE's row).
    pub(super) fn keying(&self, b2: Option<&[Pixel]>) -> Keying {
        let rows = b2.and_then(|b| Some((b.first()?.v, b.last()?.v)));
        Keying::choose(
            self.foe,
            (self.geom.c2(), self.geom.g(), self.geom.w()),
            self.reach,
            self.scale,
            rows,
        )
    }

    /// The radius `m` about the FOE that bands with `W' < 0` leave to the
    /// FOE-near list, for a boundary whose largest `r₁` is `r1_max`
    /// (see [`Band::key_half_width`]): `48 (r₁ + e₂) + 8` pixels, about 56
    /// for the default errors. A larger `m` narrows those bands' key
    /// intervals (about `e₂/m` in angle) but flags more points near the FOE
    /// ([`Status::AtFoe`] within `m + r₁ + e₂`).
    pub(super) fn near_foe(&self, r1_max: f32) -> f32 {
        48.0 * (r1_max + self.e2()) + 8.0
    }

    pub(super) fn e2(&self) -> f32 {
        self.config.e2 + self.slack_e2 + self.thin
    }

    /// The grazing test's allowance for the polyline's error: `e₂ · 2/sin
    /// φ_min` ([`crate::wedge`]).
    pub(super) fn e2_csc(&self) -> f32 {
        self.e2() * self.csc_twice
    }

    /// Whether a band with `W' < 0` runs into an uncertain FOE (a
    /// translation error): then every key is searched.
    pub(super) fn exhaustive(&self) -> bool {
        self.geom.w() < 0.0 && self.translation > 0.0
    }
}

/// How far a composed motion may be from the exact composition of the
/// per-frame motions by its `f32` rounding (module docs, "The
/// composition's rounding"; the fusion's chain keeps it).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Rounding {
    /// The translation's error, a length.
    pub(crate) translation: f32,
    /// The matrix's, `|R_t v − R v| ≤ matrix |v|`.
    pub(crate) matrix: f32,
    /// Whether the configuration's translation error already holds the
    /// error of `T' = Rᵀ T` these give (the chain's choice where `W'` is
    /// too small for the focus's error: [`crate::fusion`]); the matrix's
    /// shift of the compensation is carried either way.
    pub(crate) in_config: bool,
}

impl Rounding {
    /// An exact motion.
    pub(crate) const NONE: Rounding = Rounding {
        translation: 0.0,
        matrix: 0.0,
        in_config: false,
    };
}

/// `config` with its rotation error box widened by `m = 2.01 m_r
/// f_max/f_min` on every axis (`f` frame 2's focal lengths), which holds a
/// composed motion's matrix error `m_r` ([`Processor::process_composed_within`])
/// where `r₁` is bounded point by point: the box's first-order term alone,
/// `m Σ |c_k| ≥ m f_min (2 + ρ + ρ²)` (the columns of
/// `motion_error::shift_bound`), is at least twice the numerator `f_max
/// m_r (1 + ρ²)` of `PairGeometry::composition_shift`, and that shift's
/// denominator is at least `1/2` wherever the box's bound is finite (`m ρ
/// ≤ dz < 1/2`, so `m_r √(1 + ρ²) < 1/2`); the bound grows with the box,
/// so the sum holds both the configured error and the matrix's. Frame-wide
/// the exact shift is added instead ([`Pair::new`]). (The widened copy
/// keeps the per-point code as it was: a branch there for the exact shift
/// cost every pair two instructions a point in the bench firmware.)
pub(super) fn composition_box(config: &Config, cam2: &Camera, mr: f32) -> Config {
    let m = 2.01
        * mr
        * (crate::math::fmax(cam2.fx(), cam2.fy()) / crate::math::fmin(cam2.fx(), cam2.fy()));
    let mut c = *config;
    c.rotation_error = c.rotation_error.map(|e| e + m);
    c
}
