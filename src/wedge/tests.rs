use super::*;
use crate::depth::tests::band_point;
use crate::depth::{Band, PointErrors};
use crate::test_rng::Rng;

/// A forward depth (`s > W'`) for [`band_point`].
fn forward(rng: &mut Rng, wf: f64) -> Option<f64> {
    Some(wf + 0.01 + 60.0 * f64::from(rng.next()) * f64::from(rng.next()))
}

/// Whether the band of `p` ([`Band`], no translation error) holds `q`
/// (true too where `p` has no band).
fn band_holds(
    q: [f32; 2],
    (w, g, c2): (f32, [f32; 2], [f32; 2]),
    p: [f32; 2],
    (r1, e2): (f32, f32),
) -> bool {
    let band = Band::new(
        p,
        [w * (p[0] - c2[0]) - g[0], w * (p[1] - c2[1]) - g[1]],
        w,
        &PointErrors {
            r1,
            e2,
            e2_csc: e2 * 11.52,
            spread_a: 0.0,
            spread_w: 0.0,
        },
        0.0,
    );
    band.map_or(true, |b| Band::contains(&b.vertex(q)))
}

/// Every point the band holds (a true frame-1 point within `r₁`, any
/// depth, a polyline point within `e₂` of its correspondent, computed in
/// `f64`) lies in the wedge: its key interval meets the wedge's, and
/// the wedge walk takes it as a piece (`W' > 0`, no translation error;
/// keys on either side of the FOE's row).
#[test]
fn wedge_holds_every_band_point() {
    let mut rng = Rng(0x3ed9_e001);
    let mut inside = 0;
    let key_scale = 9.536_743e-7 * 1024.0;
    for case in 0..40_000 {
        let w = 0.05 + rng.next();
        let g = [(rng.next() - 0.5) * 300.0, (rng.next() - 0.5) * 300.0];
        let c2 = [255.5f32, 239.5];
        let foe = [c2[0] + g[0] / w, c2[1] + g[1] / w];
        let p = [512.0 * rng.next(), 480.0 * rng.next()];
        let (r1, e2) = (0.05 + rng.next(), 0.05 + rng.next());
        let Some(q) = band_point(&mut rng, (w, g, c2), p, (r1, e2), forward) else {
            continue;
        };
        // The boundary's side of the FOE's row: q's, and q keyed.
        let dq = [q[0] - foe[0], q[1] - foe[1]];
        let side = if dq[1] >= 0.0 { 1.0 } else { -1.0 };
        let t = side * dq[1];
        if !(t >= 4.0 && q[0].abs() < 3000.0 && q[1].abs() < 3000.0) {
            continue;
        }
        let orient = if rng.next() < 0.5 { 1.0 } else { -1.0 };
        // p's own key (step 1's), or none (the exact edge keys).
        let key = if rng.next() < 0.2 {
            crate::pencil::NO_KEY
        } else {
            crate::pencil::half_key(p, (foe, side, 4.0), key_scale).0
        };
        let Ok(wedge) = Wedge::new(
            p,
            (foe, side),
            (r1, e2, e2 * 11.52),
            (key, key_scale, orient),
        ) else {
            continue;
        };
        let i = 1.0 / (dq[0].abs() + t);
        let (k, m) = (orient * (dq[0] * i), key_scale * i + ULP20);
        assert!(
            k + m >= wedge.kl && k - m <= wedge.kh,
            "case {case}: key {k} ± {m} outside [{}, {}]",
            wedge.kl,
            wedge.kh
        );
        let v = wedge.vertex(q);
        let mut walk = WedgeWalk::NEW;
        let r = walk.take(&wedge, 5, (&v, &v), (k - m, k + m), 10, 11.34);
        assert!(
            walk.next == 6 || r == Err(Status::Grazing),
            "case {case}: q {q:?} not in the wedge of {p:?} (foe {foe:?})"
        );
        // And the band itself holds it (the wedge is the larger).
        assert!(
            band_holds(q, (w, g, c2), p, (r1, e2)),
            "case {case}: q outside the band"
        );
        inside += 1;
    }
    assert!(inside > 5_000, "{inside}");
}

/// [`wedge_holds_every_band_point`] for pseudo-angle keys
/// ([`Wedge::new_angular`]): every band point's key, with its margin,
/// meets a copy (a multiple of 4 away) of the wedge's interval, and
/// the walk takes it as a piece. The FOE anywhere near the image, the
/// point and the polyline point on either side of its row.
#[test]
fn angular_wedge_holds_every_band_point() {
    use crate::pencil::{Keying, Pencil};
    let mut rng = Rng(0x5a1e_77c3);
    let mut inside = 0;
    let key_scale = 9.536_743e-7 * 1024.0;
    for case in 0..40_000 {
        let w = 0.05 + rng.next();
        let foe = [512.0 * rng.next(), 480.0 * rng.next()];
        let c2 = [255.5f32, 239.5];
        let g = [w * (foe[0] - c2[0]), w * (foe[1] - c2[1])];
        let p = [512.0 * rng.next(), 480.0 * rng.next()];
        let (r1, e2) = (0.05 + rng.next(), 0.05 + rng.next());
        let Some(q) = band_point(&mut rng, (w, g, c2), p, (r1, e2), forward) else {
            continue;
        };
        if !(q[0].abs() < 3000.0 && q[1].abs() < 3000.0) {
            continue;
        }
        let keying = Keying {
            pencil: Pencil::Angular { foe },
            eps: 0.0,
            key_scale,
            period: 4.0,
        };
        let (kq, mq) = keying.key(q);
        if !kq.is_finite() {
            continue;
        }
        let orient = if rng.next() < 0.5 { 1.0 } else { -1.0 };
        let key = keying.key(p).0;
        let Ok(wedge) = Wedge::new_angular(p, foe, (r1, e2, e2 * 11.52), (key, key_scale, orient))
        else {
            continue;
        };
        // The copy of q's oriented key nearest the wedge's.
        let k = orient * kq;
        let mid = 0.5 * (wedge.kl + wedge.kh);
        let shift = 4.0 * libm::roundf((k - mid) * 0.25);
        let (lo, hi) = (k - mq - shift, k + mq - shift);
        assert!(
            hi >= wedge.kl && lo <= wedge.kh,
            "case {case}: key {k} ± {mq} (copy {lo}..{hi}) outside [{}, {}]",
            wedge.kl,
            wedge.kh
        );
        let v = wedge.vertex(q);
        let mut walk = WedgeWalk::NEW;
        let r = walk.take(&wedge, 5, (&v, &v), (lo, hi), 10, 11.34);
        assert!(
            walk.next == 6 || r == Err(Status::Grazing),
            "case {case}: q {q:?} not in the wedge of {p:?} (foe {foe:?})"
        );
        // And the band itself holds it (the wedge is the larger).
        assert!(
            band_holds(q, (w, g, c2), p, (r1, e2)),
            "case {case}: q outside the band"
        );
        inside += 1;
    }
    assert!(inside > 5_000, "{inside}");
}

/// The stick of [`Wedge::stick`], refined by the piece's lines or not,
/// holds every depth the error model allows: a true frame-1 point
/// within `r₁` of `p₁'` and a true correspondent on its ray from the
/// FOE within `e₂` of the piece (both just inside, at the extremes of
/// the ratio the disc allows, in `f64`). Pieces are short polylines
/// through the ray at 3–90°, straight or jittered like a pixel
/// staircase, with disparities of 0–12 px: most of them small enough
/// for the refinement. Also checks that the refinement never widens
/// the stick of the piece's range and that it often narrows it.
#[test]
fn refined_stick_holds_every_consistent_depth() {
    extern crate std;
    let mut rng = Rng(0x57_1c_4e_11);
    let (mut checked, mut refined, mut narrower, mut bounded_only_refined) = (0, 0, 0, 0);
    for case in 0..80_000 {
        let w = 0.05 + rng.next();
        let foe = [512.0 * rng.next(), 480.0 * rng.next()];
        let ang = core::f32::consts::TAU * rng.next();
        let rho = 20.0 + 400.0 * rng.next();
        let dir = [libm::cosf(ang), libm::sinf(ang)];
        let p = [foe[0] + rho * dir[0], foe[1] + rho * dir[1]];
        let (r1, e2) = (0.05 + rng.next(), 0.05 + rng.next());
        let Ok((wedge, _)) = Wedge::frame(p, foe, (r1, e2, e2 * 11.52)) else {
            continue;
        };
        // The piece: through the ray at `disp` beyond p, at `phi`.
        let disp = 12.0 * rng.next() * rng.next();
        let phi = (3.0 + 87.0 * rng.next()).to_radians();
        let side = if rng.next() < 0.5 { 1.0 } else { -1.0 };
        let t = [
            dir[0] * libm::cosf(phi) - side * dir[1] * libm::sinf(phi),
            dir[1] * libm::cosf(phi) + side * dir[0] * libm::sinf(phi),
        ];
        let c = [p[0] + disp * dir[0], p[1] + disp * dir[1]];
        let n = 2 + (rng.next() * 6.0) as usize;
        let step = 0.3 + 4.0 * rng.next();
        let jitter = if rng.next() < 0.5 { 0.0 } else { 0.5 };
        let start = -(n as f32 - 1.0) * step * rng.next();
        let poly: std::vec::Vec<Pixel> = (0..n)
            .map(|i| {
                let a = start + step * i as f32;
                let j = [jitter * (rng.next() - 0.5), jitter * (rng.next() - 0.5)];
                Pixel::new(c[0] + a * t[0] + j[0], c[1] + a * t[1] + j[1])
            })
            .collect();
        let mut walk = WedgeWalk::NEW;
        let mut stop = false;
        for j in 0..n - 1 {
            let (a, b) = (wedge.vertex(poly[j].arr()), wedge.vertex(poly[j + 1].arr()));
            if walk.take_met(&wedge, j, (&a, &b), n - 1, 11.34).is_err() {
                stop = true;
                break;
            }
        }
        let Outcome::Match { lam, lo, hi, end } = walk.outcome() else {
            continue;
        };
        if stop {
            continue;
        }
        // The piece: from the first segment with a part to `end`.
        let has_part = |j: usize| {
            let (a, b) = (wedge.vertex(poly[j].arr()), wedge.vertex(poly[j + 1].arr()));
            wedge.part(&a, &b).is_some()
        };
        let Some(start) = (0..end).find(|&j| has_part(j)) else {
            continue;
        };
        let piece = (start, end);
        let coarse = wedge.depths(stick_w(w), r1, (lam, lo, hi));
        let outcome = Outcome::Match { lam, lo, hi, end };
        // Every stick a partial credit gave (the truth is checked in
        // each below).
        let mut partials = std::vec::Vec::new();
        let Some(stick) = (match wedge.refines(&outcome) {
            Some(e) => {
                refined += 1;
                // The crossing from the piece alone is the walk's, bit
                // for bit.
                let mut unlimited = u32::MAX;
                let (x, stick, unpaid) = wedge
                    .refined(&poly, e, (stick_w(w), r1), &mut unlimited)
                    .expect("the piece again");
                assert!(!unpaid, "case {case}: unlimited credit");
                assert_eq!(x.to_bits(), lam.to_bits(), "case {case}: crossing");
                // A short credit: each segment it pays costs
                // REFINE_UNITS, an unpaid one keeps its range's bound,
                // so the stick lies between the full refinement's and
                // the coarse one, and with no credit it is the coarse.
                let segs = (e - piece.0) as u32;
                let credits = (0..=segs + 1)
                    .flat_map(|k| [k * REFINE_UNITS, k * REFINE_UNITS + REFINE_UNITS - 1]);
                for give in credits {
                    let mut credit = give;
                    let (xs, short, unpaid) = wedge
                        .refined(&poly, e, (stick_w(w), r1), &mut credit)
                        .expect("the piece again");
                    assert_eq!(xs.to_bits(), lam.to_bits(), "case {case}: crossing");
                    let paid_now = give / REFINE_UNITS;
                    assert_eq!(credit, give - paid_now.min(segs) * REFINE_UNITS);
                    assert_eq!(unpaid, paid_now < segs, "case {case}: {give} for {segs}");
                    if give == 0 {
                        assert_eq!(short, coarse, "case {case}: no credit, the coarse stick");
                    }
                    if let (Some((_, fnr, ffr)), Some((_, pn, pf))) = (stick, short) {
                        assert!(
                            pn <= fnr && pf >= ffr,
                            "case {case}: [{pn}, {pf}] inside the refined [{fnr}, {ffr}]"
                        );
                    }
                    if let (Some((_, cn, cf)), Some((_, pn, pf))) = (coarse, short) {
                        assert!(
                            pf <= cf * (1.0 + 4e-6) && pn >= cn * (1.0 - 4e-6),
                            "case {case}: [{pn}, {pf}] wider than the coarse [{cn}, {cf}]"
                        );
                    }
                    if let Some((_, pn, pf)) = short {
                        partials.push((pn, pf));
                    }
                }
                stick
            }
            None => coarse,
        }) else {
            continue;
        };
        let (_, s_near, s_far) = stick;
        match coarse {
            Some((_, cn, cf)) => {
                assert!(
                    s_far <= cf * (1.0 + 4e-6) && s_near >= cn * (1.0 - 4e-6),
                    "case {case}: refined [{s_near}, {s_far}] wider than [{cn}, {cf}]"
                );
                narrower += usize::from(s_far < cf * 0.99);
            }
            None => bounded_only_refined += 1,
        }
        // True configurations, in f64, relative to the FOE.
        let (f0, f1) = (f64::from(foe[0]), f64::from(foe[1]));
        let p1 = [f64::from(p[0]) - f0, f64::from(p[1]) - f1];
        let (r1t, e2t) = (0.999 * f64::from(r1), 0.999 * f64::from(e2));
        // The bounds are linear along a segment: their extremes are at
        // the piece's vertices, p₂ on the e₂ circle about one (24
        // directions); and 16 random points of the piece's e₂ strip.
        let vertices = piece.1 + 1 - piece.0;
        for sample in 0..vertices * 24 + 16 {
            let (q, th, rr) = if sample < vertices * 24 {
                let v = poly[piece.0 + sample / 24].arr();
                let q = [f64::from(v[0]) - f0, f64::from(v[1]) - f1];
                (q, std::f64::consts::TAU * (sample % 24) as f64 / 24.0, e2t)
            } else {
                // q on a segment of the piece, p₂ within e₂ of it.
                let j = piece.0
                    + ((rng.next() * (piece.1 - piece.0) as f32) as usize)
                        .min(piece.1 - piece.0 - 1);
                let u = f64::from(rng.next());
                let (a, b) = (poly[j].arr(), poly[j + 1].arr());
                let q = [
                    f64::from(a[0]) + u * (f64::from(b[0]) - f64::from(a[0])) - f0,
                    f64::from(a[1]) + u * (f64::from(b[1]) - f64::from(a[1])) - f1,
                ];
                let th = std::f64::consts::TAU * f64::from(rng.next());
                (q, th, e2t * (1.0 - f64::from(rng.next()).powi(4)))
            };
            let p2 = [q[0] + rr * th.cos(), q[1] + rr * th.sin()];
            // The ratios k with |k p₂ − p₁'| ≤ r₁: a quadratic in k.
            let (aa, bb) = (p2[0] * p2[0] + p2[1] * p2[1], p2[0] * p1[0] + p2[1] * p1[1]);
            let cc = p1[0] * p1[0] + p1[1] * p1[1] - r1t * r1t;
            let disc = bb * bb - aa * cc;
            if disc < 0.0 || aa <= 0.0 {
                continue;
            }
            for k in [(bb - disc.sqrt()) / aa, (bb + disc.sqrt()) / aa, bb / aa] {
                if !(k > 0.0 && k < 1.0) {
                    continue;
                }
                let s = f64::from(w) / (1.0 - k);
                assert!(
                    s >= f64::from(s_near) && s <= f64::from(s_far),
                    "case {case}: true s {s} (k {k}) outside [{s_near}, {s_far}] \
                     (p {p:?}, foe {foe:?}, r1 {r1}, e2 {e2}, piece {piece:?} of {poly:?})"
                );
                for &(pn, pf) in &partials {
                    assert!(
                        s >= f64::from(pn) && s <= f64::from(pf),
                        "case {case}: true s {s} outside the partial [{pn}, {pf}]"
                    );
                }
                checked += 1;
            }
        }
    }
    std::eprintln!("{checked} checked, refined {refined}, narrower {narrower}, bounded only when refined {bounded_only_refined}");
    assert!(checked > 200_000, "{checked} checked");
    assert!(
        refined > 10_000 && narrower > 5_000 && bounded_only_refined > 1_000,
        "refined {refined}, narrower {narrower}, bounded only when refined {bounded_only_refined}"
    );
}
