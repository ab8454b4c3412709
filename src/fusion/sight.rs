//! What a partner frame can see of the key frame's rays: the check that a
//! pair's match could be the true correspondent's.
//!
//! # Why
//! A pair's stick is guaranteed only where the point's true correspondent
//! is in the partner's data. When it is not (the point's ray has left the
//! partner's image, or its boundary's rows there), the band may still meet
//! the partner's boundary elsewhere, and that match's stick can fall inside
//! a correct but wide stick of another pair: the two "agree" and the
//! intersection is the wrong one's (an adversarial review: a correct first
//! partner's stick `[9.21, 371]`, a later partner's wrong `[14.7, 16.9]`
//! for a truth of 11.7 whose image was 28 px off the partner's left edge;
//! `Consistent`, and into the map 3.08 from its stick with a radius of
//! 0.011). Interval logic alone cannot tell: the wrong stick is inside the
//! right one.
//!
//! # The rule
//! Say a pair `c` is *right* when the point's true correspondent is in
//! its partner's data: its stick `S_c` holds the truth. Assume that a
//! partner that sees the truth's depth along the ray has it in its data
//! (its polyline covers its boundary wherever that is in the window,
//! below), so that its pair is right, and suppose one pair is right. With
//! `H` the lowest near end of the point's sticks (their hull's), `U` a
//! depth from which every partner so far was shown to see the ray (`V_j ⊃
//! [U, ∞)` for what partner `j` sees, `V_j`), and `F` the sticks'
//! intersection: the truth is at least `H` (it is in `S_c`); if it is at
//! least `U`, every partner sees it, every pair is right and it is in
//! `F`; otherwise it lies in `[H, U)`. So it lies in
//!
//! `[H, max(F.far, U)]`   where `H < U`,   and in `F` where `H ≥ U`
//!
//! (`H ≤ F`'s near end always). The check widens the point's interval to
//! that ([`crate::fusion::FusedStatus::Widened`]) rather than flag it: it
//! holds the truth under the assumption, and the point is kept, in the
//! map too. (Until a later round the check flagged every such point
//! `PartlyUnseen` and kept it out of the map: on the demo drive most near
//! points by a key frame's 6th partner, 13 % of the random drives' fused
//! snapshots.) A partner shown to see none of the ray (an empty window,
//! or one the ray's far end misses) gives no finite `U`: such a point is
//! flagged [`crate::fusion::FusedStatus::PartlyUnseen`] and stays out of
//! the map. Both are running extremes, so the interval does not depend on
//! the pairs' order (but for the probes' rounding towards a wider `U`,
//! below), and neither moves back once widened or flagged. A first pair
//! changes nothing (one stick: under the assumption it is the right one).
//! `H` is each stick's own near end, not raised
//! to where its own partner was shown to see: the window is shrunk by the
//! margins, so a right partner whose truth lies within them of its image's
//! edge is shown to see only from beyond its truth, and raising `H` there
//! let a wrong pair through (a second review's three views: a right stick
//! `[9.58, 24.07]` whose truth, 13.69, was 0.8 px inside its partner's
//! edge, and a wrong `[22.98, 28.06]`, fused `[22.98, 24.07]`). If no pair
//! is right (two wrong pairs that agree), nothing in the views can tell:
//! `docs/FUSION.md`, "Limits".
//!
//! # Seen from a depth on
//! The ray's points at depths `[d, ∞)` map into the partner (motion
//! `R, T`: frame-2 coordinates `Rᵀ (P − T)`) to `P(z) = z a − b`, `a = Rᵀ r`
//! for the detected pixel's ray `r = (x, y, 1)`, `b = Rᵀ T`; with `a_z > 0`
//! and `P_z(d) > 0` their images are the segment from the image of depth
//! `d` to the image at infinity, inside the convex window (the partner's
//! columns and its boundary's rows, shrunk by a margin) when both ends are.
//! The tests are linear in `P`: `P_x ≥ ū₀ P_z` and so on, no division.
//! The margins cover what moves the true ray's image from the detected
//! one's, to first order: in the window, `e₂` (the polyline's own error)
//! and the rotation error's `f Σε (1 + ū² + v̄²)` (a turn `ε` about the
//! partner's axes moves a normalised image point by at most `Σε (1 + x² +
//! y²)` in each coordinate); in the tests, the translation error (`T` off
//! by `δ` in each frame-1 axis is off by at most `√3 δ` in each partner
//! axis, which moves `P_x − ū P_z` by at most `√3 δ (1 + |ū|)`) and the key
//! pixel's `e₁` (its ray's direction off by `ε₁ = e₁/f`, so `P` by `ε₁ d`).
//! First-order margins, not a derived bound: the zero wrong unflagged
//! fused points is what the tests show (`docs/FUSION.md`), and two wrong
//! pairs that agree are beyond any margin ("Limits").
//!
//! A point's `U` is set by probing: each pair `j` asks whether its partner
//! sees the ray from `H/2` (`H` counting this pair's stick); a yes makes
//! `H/2` partner `j`'s depth, a no the exact one ([`Sight::seen_from`],
//! rounded up over its own terms' rounding; a partner that sees none of
//! the ray: `U` infinite, and the pair that brings `H` below it flags).
//! `H` and `U` are kept as exact `f32` in the cell's rival slot since the
//! twenty-fourth session (16-bit codes, `H` rounded down and `U` up,
//! before: `src/fusion/key.rs`, `Cell`). So `U_j` is
//! partner `j`'s depth or above it, never below: the rule errs towards
//! widening (a larger `U` only widens). That makes it depend a little on
//! the pairs' order after all: a later, lower `H` is compared with an
//! earlier probe's `H/2`, not with that partner's exact depth (a review's
//! two sticks, `[10, 12]` seen from 3.06 and `[4, 11]` seen from 0.98,
//! widen in that order and not in the other). It never widens less than
//! the rule with exact depths would.
//! Assumes the partner's polyline covers its boundary wherever that is in
//! the image (rows from its first point's to its last's).

use crate::camera::{Camera, Pixel};
use crate::config::Config;
use crate::math::{fmax, fmin};
use crate::motion::Motion;

/// What one partner sees of the key frame's rays on one boundary.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sight {
    /// `Rᵀ`, by rows: a key-frame direction in partner coordinates.
    rt: [[f32; 3]; 3],
    /// `Rᵀ T`.
    b: [f32; 3],
    /// The key camera's normalisation, `x = u·kx + ox`, `y = v·ky + oy`.
    key: [f32; 4],
    /// The window, normalised: `ū₀ ≤ x ≤ ū₁`, `v̄₀ ≤ y ≤ v̄₁`.
    win: [f32; 4],
    /// `1 + |ū|` for each of the window's four sides, in the order of
    /// `win`: a change of `P` by at most `ε` in each coordinate moves the
    /// side's value `P_x − ū P_z` (and so on) by at most `ε (1 + |ū|)`.
    side: [f32; 4],
    /// The translation error in partner axes, `√3 δ`, and the key pixel's,
    /// `ε₁ = e₁/min(f)` (normalised): the slack of a side at depth `d` is
    /// `(1 + |ū|)(√3 δ + ε₁ d)`.
    err: [f32; 2],
}

impl Sight {
    /// The sight of a partner whose camera is `cam` and whose boundary has
    /// the points `points` (the motion `m` from the key frame, the pair's
    /// configuration `cfg`); `None` when the window is empty (nothing is
    /// seen: fewer than two points, or rows narrower than the margin).
    pub(crate) fn new(
        key_cam: &Camera,
        cam: &Camera,
        points: &[Pixel],
        m: &Motion,
        cfg: &Config,
    ) -> Option<Self> {
        let (Some(first), Some(last)) = (points.first(), points.last()) else {
            return None;
        };
        let r = m.rotation_matrix();
        let t = m.translation();
        let mut rt = [[0.0f32; 3]; 3];
        for (i, row) in rt.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                // (Indices below 3.)
                *v = r.get(j).and_then(|c| c.get(i)).copied().unwrap_or(0.0);
            }
        }
        let b = [
            rt[0][0] * t[0] + rt[0][1] * t[1] + rt[0][2] * t[2],
            rt[1][0] * t[0] + rt[1][1] * t[1] + rt[1][2] * t[2],
            rt[2][0] * t[0] + rt[2][1] * t[1] + rt[2][2] * t[2],
        ];
        let (v_lo, v_hi) = if first.v <= last.v {
            (first.v, last.v)
        } else {
            (last.v, first.v)
        };
        // The rotation error's shift, from the window before its margin
        // (module docs).
        let eps = cfg.rotation_error();
        let mu = fmax(cam.cx(), f32::from(cam.width()) - 1.0 - cam.cx()).abs() / cam.fx();
        let mv = fmax((v_lo - cam.cy()).abs(), (v_hi - cam.cy()).abs()) / cam.fy();
        let turn = (eps[0] + eps[1] + eps[2]) * (1.0 + mu * mu + mv * mv);
        let margin = cfg.e2() + fmax(cam.fx(), cam.fy()) * turn;
        let (u0, u1) = (margin, f32::from(cam.width()) - 1.0 - margin);
        let (v0, v1) = (v_lo + margin, v_hi - margin);
        // (A NaN fails.)
        if !(u0 < u1 && v0 < v1) {
            return None;
        }
        let win = [
            (u0 - cam.cx()) / cam.fx(),
            (u1 - cam.cx()) / cam.fx(),
            (v0 - cam.cy()) / cam.fy(),
            (v1 - cam.cy()) / cam.fy(),
        ];
        let side = win.map(|w| 1.0 + w.abs());
        // (`√3` rounded up: the translation's error in partner axes.)
        let err = [
            cfg.translation_error() * 1.7321,
            cfg.e1() / fmin(key_cam.fx(), key_cam.fy()),
        ];
        Some(Self {
            rt,
            b,
            key: [
                1.0 / key_cam.fx(),
                -key_cam.cx() / key_cam.fx(),
                1.0 / key_cam.fy(),
                -key_cam.cy() / key_cam.fy(),
            ],
            win,
            side,
            err,
        })
    }

    /// The ray of the key-frame pixel `p`, `(x, y, 1)`, in partner
    /// coordinates: `a = Rᵀ r`.
    #[inline(always)]
    fn direction(&self, p: Pixel) -> [f32; 3] {
        let x = p.u * self.key[0] + self.key[1];
        let y = p.v * self.key[2] + self.key[3];
        let [r0, r1, r2] = self.rt;
        [
            r0[0] * x + r0[1] * y + r0[2],
            r1[0] * x + r1[1] * y + r1[2],
            r2[0] * x + r2[1] * y + r2[2],
        ]
    }

    /// Whether the partner sees the ray of the key-frame pixel `p` at every
    /// depth from `d` on (module docs).
    #[inline(always)]
    pub(crate) fn sees_from(&self, p: Pixel, d: f32) -> bool {
        let a = self.direction(p);
        let p = [
            d * a[0] - self.b[0],
            d * a[1] - self.b[1],
            d * a[2] - self.b[2],
        ];
        // At infinity the direction `a` (the key pixel's error alone), at
        // `d` the point `P` (the translation's too). (A NaN fails.)
        let [delta, e1] = self.err;
        inside(a, &self.win, &self.side, e1) && inside(p, &self.win, &self.side, delta + e1 * d)
    }
}

impl Sight {
    /// The depth from which the partner sees the ray of the key-frame
    /// pixel `p` ([`Self::sees_from`] holds from it on, up to rounding),
    /// rounded up; `f32::INFINITY` when it does not see the ray's far end
    /// (nor any depth, then). Each of the window's sides is a linear
    /// bound on the depth, `d (c·a) ≥ s + c·b` with `c·a > 0` when the far
    /// end is seen: the largest of them, and `P_z > 0`'s.
    pub(crate) fn seen_from(&self, p: Pixel) -> f32 {
        let a = self.direction(p);
        let b = self.b;
        let (w, k) = (self.win, self.side);
        let [delta, e1] = self.err;
        // (Side: the coefficient of the depth and the bound's right-hand
        // side, `d (c·a − k ε₁) ≥ c·b + k δ`, and the sums of their terms'
        // magnitudes, which bound their rounding.)
        let sides = [
            ((a[2], a[2].abs()), (b[2], b[2].abs())),
            (
                (
                    a[0] - w[0] * a[2] - k[0] * e1,
                    a[0].abs() + (w[0] * a[2]).abs() + k[0] * e1,
                ),
                (
                    b[0] - w[0] * b[2] + k[0] * delta,
                    b[0].abs() + (w[0] * b[2]).abs() + k[0] * delta,
                ),
            ),
            (
                (
                    w[1] * a[2] - a[0] - k[1] * e1,
                    (w[1] * a[2]).abs() + a[0].abs() + k[1] * e1,
                ),
                (
                    w[1] * b[2] - b[0] + k[1] * delta,
                    (w[1] * b[2]).abs() + b[0].abs() + k[1] * delta,
                ),
            ),
            (
                (
                    a[1] - w[2] * a[2] - k[2] * e1,
                    a[1].abs() + (w[2] * a[2]).abs() + k[2] * e1,
                ),
                (
                    b[1] - w[2] * b[2] + k[2] * delta,
                    b[1].abs() + (w[2] * b[2]).abs() + k[2] * delta,
                ),
            ),
            (
                (
                    w[3] * a[2] - a[1] - k[3] * e1,
                    (w[3] * a[2]).abs() + a[1].abs() + k[3] * e1,
                ),
                (
                    w[3] * b[2] - b[1] + k[3] * delta,
                    (w[3] * b[2]).abs() + b[1].abs() + k[3] * delta,
                ),
            ),
        ];
        let mut e = 0.0f32;
        for ((c, c_abs), (rhs, rhs_abs)) in sides {
            // Each rounded by at most a few units of the last place of its
            // terms' magnitudes (`a`, `b` and `w` themselves by as much):
            // `2⁻²⁰` of them, against the bound. (A NaN fails: not seen.)
            let c_lo = c - c_abs * POS_ERR;
            if !(c_lo > 0.0) {
                return f32::INFINITY;
            }
            e = fmax(e, (rhs + rhs_abs * POS_ERR) / c_lo);
        }
        // (The division's rounding, and the probe's, `Self::sees_from`,
        // whose own terms round at `d` about as these do.)
        let e = e * (1.0 + POS_ERR);
        if e.is_finite() {
            e
        } else {
            f32::INFINITY
        }
    }
}

/// The relative rounding allowed for the sight's linear terms: `2⁻²⁰`
/// (each term is a handful of `f32` operations, `2⁻²⁴` each).
const POS_ERR: f32 = 9.54e-7;

/// `q` in front of the camera and inside the window's cone, each side by
/// `side · e` (`q` off by at most `e` in each coordinate stays inside).
#[inline(always)]
fn inside(q: [f32; 3], win: &[f32; 4], side: &[f32; 4], e: f32) -> bool {
    q[2] > 0.0
        && q[0] - win[0] * q[2] >= side[0] * e
        && win[1] * q[2] - q[0] >= side[1] * e
        && q[1] - win[2] * q[2] >= side[2] * e
        && win[3] * q[2] - q[1] >= side[3] * e
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;

    fn cam() -> Camera {
        Camera::new(800.0, 780.0, 255.5, 239.5, 512, 480).unwrap()
    }

    /// A random forward-ish motion, rotations up to 0.1 rad an axis.
    fn motion(g: &mut Rng) -> Motion {
        let t = [g.next() - 0.5, 0.4 * (g.next() - 0.5), 0.2 + 2.0 * g.next()];
        let r = [
            0.2 * (g.next() - 0.5),
            0.2 * (g.next() - 0.5),
            0.2 * (g.next() - 0.5),
        ];
        Motion::new(t, r).unwrap()
    }

    /// A random partner's sight under `cfg` (a random motion; the
    /// partner's boundary from a row in the upper half to one in the
    /// lower) and a random key-frame pixel; `None` where the partner's
    /// window is empty.
    fn random_sight(g: &mut Rng, cfg: &Config) -> Option<(Sight, Pixel)> {
        let m = motion(g);
        let rows = [
            Pixel::new(100.0, 80.0 + 200.0 * g.next()),
            Pixel::new(300.0, 300.0 + 180.0 * g.next()),
        ];
        let s = Sight::new(&cam(), &cam(), &rows, &m, cfg)?;
        Some((s, Pixel::new(512.0 * g.next(), 480.0 * g.next())))
    }

    /// A partner that sees a ray only from [`DepthScale::unbounded_from`]
    /// (`2 s`) on sees none of it worth having: `sight_exact` gives
    /// `SEEN_NONE` there (the point is flagged `PartlyUnseen`, as when `U`
    /// was coded, whose codes end there), and the exact depth below it.
    /// (A review of the twenty-fourth session's exact `U` found such
    /// depths widening points to beyond what the map can hold.)
    #[test]
    fn a_partner_seen_only_from_beyond_the_codes_sees_none() {
        use super::super::code::DepthScale;
        use super::super::key::{sight_exact, SEEN_NONE};
        let cfg = Config::DEFAULT;
        let scale = DepthScale::for_max_depth(cfg.max_depth());
        let limit = scale.unbounded_from();
        let mut g = Rng(0x5EED_0007);
        let (mut beyond, mut within) = (0, 0);
        for _ in 0..100_000 {
            let Some((s, p)) = random_sight(&mut g, &cfg) else {
                continue;
            };
            let (e, got) = (s.seen_from(p), sight_exact(p, &s, &scale));
            if e.is_finite() && e >= limit {
                beyond += 1;
                assert_eq!(got, SEEN_NONE, "{e}");
            } else {
                within += usize::from(e.is_finite());
                assert_eq!(got.to_bits(), e.to_bits());
            }
        }
        assert!(beyond > 10 && within > 1000, "{beyond} {within}");
    }

    /// The exact depth from which the partner sees a ray is where the probe
    /// turns from no to yes: the probe says yes just above it and at every
    /// depth beyond (up to 10⁴ times it), no 10 % below (and 0.1 % below
    /// in all but 1 % of the cases: the rounding allowed); where it says
    /// the far end is not seen, no probe says yes.
    #[test]
    fn the_exact_depth_is_where_the_probe_turns() {
        let mut g = Rng(0x5EED_0007);
        let (mut finite, mut unseen, mut loose) = (0, 0, 0usize);
        for case in 0..20_000 {
            let cfg = Config::DEFAULT
                .with_translation_error(0.02 * g.next())
                .unwrap()
                .with_rotation_error([0.002 * g.next(); 3])
                .unwrap();
            let Some((s, p)) = random_sight(&mut g, &cfg) else {
                continue;
            };
            let e = s.seen_from(p);
            if e == f32::INFINITY {
                unseen += 1;
                for d in [0.1, 1.0, 10.0, 100.0, 1.0e4] {
                    assert!(!s.sees_from(p, d), "case {case}: seen at {d}");
                }
                continue;
            }
            finite += 1;
            assert!(e >= 0.0, "case {case}: {e}");
            for k in [1.0001f32, 1.01, 2.0, 10.0, 1.0e4] {
                let d = fmax(e, 1.0e-3) * k;
                assert!(s.sees_from(p, d), "case {case}: not seen at {d} (from {e})");
            }
            if e > 1.0e-3 {
                // (Rounded up by the terms' rounding: where a side is
                // nearly along the ray it can be loose, never by much.)
                assert!(!s.sees_from(p, e * 0.9), "case {case}: seen below {e}");
                loose += usize::from(s.sees_from(p, e * 0.999));
            }
        }
        assert!(finite > 2_000 && unseen > 2_000, "{finite} / {unseen}");
        assert!(loose * 100 < finite, "{loose} of {finite} loose by 0.1 %");
    }

    /// What the probe says is seen from `d` on, every perturbation the
    /// margins cover sees, projected independently of the module's code:
    /// the key pixel moved by `e₁` (8 directions), the translation by `δ`
    /// in each frame-1 axis and the rotation by `ε` about each frame-2 axis
    /// (the corners of their boxes), at depths from `d` (taken at the exact
    /// depth, where the probe's window is tight) to `10³ d`: the point lands
    /// in the partner's columns and its boundary's rows, up to 0.05 px (the
    /// margins are first-order). Without the rotation's, the translation's
    /// or `e₁`'s margin it does not.
    #[test]
    fn every_perturbation_within_the_errors_sees_what_the_probe_sees() {
        let mut g = Rng(0x5EED_0A11);
        let (mut cases, mut projections) = (0, 0usize);
        let c = cam();
        for case in 0..3_000 {
            let delta = 0.05 * g.next();
            let eps = [0.003 * g.next(), 0.003 * g.next(), 0.003 * g.next()];
            // (`e₂` small, so that its margin hides none of the others.)
            let cfg = Config::new(0.5 + 1.5 * g.next(), 0.01, 10.0, 1000.0)
                .unwrap()
                .with_translation_error(delta)
                .unwrap()
                .with_rotation_error(eps)
                .unwrap();
            let m = motion(&mut g);
            let (v_lo, v_hi) = (40.0 + 150.0 * g.next(), 300.0 + 170.0 * g.next());
            let rows = [Pixel::new(100.0, v_lo), Pixel::new(300.0, v_hi)];
            let Some(s) = Sight::new(&c, &c, &rows, &m, &cfg) else {
                continue;
            };
            let p = Pixel::new(512.0 * g.next(), 480.0 * g.next());
            let e = s.seen_from(p);
            let d = fmax(e, 0.05) * 1.0001;
            if !(e.is_finite() && s.sees_from(p, d)) {
                continue;
            }
            cases += 1;
            let r = m.rotation_matrix();
            let t = m.translation();
            for k in 0..16 {
                let a = k as f32 * core::f32::consts::FRAC_PI_4;
                let e1 = cfg.e1() * 0.999;
                let q = Pixel::new(p.u + e1 * libm::cosf(a), p.v + e1 * libm::sinf(a));
                let sign = |b: u32| if k >> b & 1 == 0 { 1.0 } else { -1.0 };
                let dt = [sign(0) * delta, sign(1) * delta, sign(2) * delta];
                let turn = [sign(1) * eps[0], sign(2) * eps[1], sign(3) * eps[2]];
                // R_true = R Rε (the error about frame-2's axes).
                let re = Motion::new([0.0, 0.0, 1.0], turn)
                    .unwrap()
                    .rotation_matrix();
                let rt: [[f32; 3]; 3] = core::array::from_fn(|i| {
                    core::array::from_fn(|j| (0..3).map(|l| r[i][l] * re[l][j]).sum())
                });
                let tt = [t[0] + dt[0], t[1] + dt[1], t[2] + dt[2]];
                let [x, y] = c.normalise(q);
                for z in [d, 1.5 * d, 4.0 * d, 1.0e3 * d] {
                    let w = [x * z - tt[0], y * z - tt[1], z - tt[2]];
                    // Rᵀ w: frame-2 coordinates.
                    let p2: [f32; 3] =
                        core::array::from_fn(|j| (0..3).map(|i| rt[i][j] * w[i]).sum());
                    assert!(p2[2] > 0.0, "case {case}: behind");
                    let u2 = c.fx() * p2[0] / p2[2] + c.cx();
                    let v2 = c.fy() * p2[1] / p2[2] + c.cy();
                    assert!(
                        (-0.05..=511.05).contains(&u2) && (v_lo - 0.05..=v_hi + 0.05).contains(&v2),
                        "case {case}: ({u2}, {v2}) outside at depth {z} (seen from {e}; rows {v_lo}–{v_hi})"
                    );
                    projections += 1;
                }
            }
        }
        assert!(cases > 300, "{cases} cases");
        assert!(projections > 20_000, "{projections}");
    }

    /// The window: the image's columns and the boundary's rows, each shrunk
    /// by the margin `e₂ + f Σε`; a boundary's rows narrower than twice
    /// the margin see nothing.
    #[test]
    fn the_window_is_the_columns_and_the_boundarys_rows() {
        let m = Motion::new([0.0, 0.0, 1.0], [0.0; 3]).unwrap();
        let cfg = Config::DEFAULT;
        let rows = [Pixel::new(10.0, 200.0), Pixel::new(20.0, 300.0)];
        let s = Sight::new(&cam(), &cam(), &rows, &m, &cfg).unwrap();
        // A point on the optical axis's row band, far: seen from about
        // where its image reaches the window's edge.
        let inside = Pixel::new(255.5, 250.0);
        assert!(s.sees_from(inside, 1.0e3));
        let above = Pixel::new(255.5, 150.0);
        assert!(!s.sees_from(above, 1.0e3), "rows above the boundary's");
        let e = s.seen_from(inside);
        // v − c_y = 10.5 at infinity; at depth d it is 10.5 d/(d − 1),
        // the window's last row 300 − e₂ − 0 (no rotation error).
        let limit = 300.0 - cfg.e2() - 239.5;
        let expect = limit / (limit - 10.5);
        assert!((e - expect).abs() < 0.05 * expect, "{e} against {expect}");
        let thin = [Pixel::new(10.0, 200.0), Pixel::new(20.0, 200.5)];
        assert!(Sight::new(&cam(), &cam(), &thin, &m, &cfg).is_none());
        assert!(Sight::new(&cam(), &cam(), &[], &m, &cfg).is_none());
    }
}
