//! Step 4's general band path ([`match_point`]): every point the wedge
//! paths do not take (moving backwards, a translation error, no key).

use super::*;

/// Step 4 for one point left by steps 1–2 in `r`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn match_point<const N: usize>(
    pair: &Pair,
    keying: &Keying,
    near_foe: f32,
    r: &PointResult,
    b2: &[Pixel],
    index: &mut Index<N>,
    work: &mut Work,
    matcher: Matcher,
) -> PointResult {
    let (p1, p, iz, r1, key) = (r.pixel1, r.pixel2.arr(), r.z, r.z_near, r.z_far);
    let geom = &pair.geom;
    let a = geom.epipolar_vector(p);
    let spread_a = if pair.translation > 0.0 {
        crate::motion_error::spread(
            geom.rotation(),
            geom.camera2_intrinsics(),
            p,
            pair.translation,
        )
        .0
    } else {
        0.0
    };
    let errors = PointErrors {
        r1,
        e2: pair.e2(),
        e2_csc: pair.e2_csc(),
        spread_a,
        spread_w: pair.spread_w,
    };
    let Ok(band) = Band::new(p, a, geom.w(), &errors, near_foe) else {
        return PointResult::flagged(p1, Status::AtFoe);
    };
    let cot_twice = pair.config.cot_twice;
    // Moving backwards, a cheap test rejects most of the wide key
    // interval's segments (half-plane keys; see `Radial`).
    let orient = match matcher {
        Matcher::Indexed => index.orient(),
        Matcher::Reference => 1.0,
    };
    let radial = match (keying.pencil, pair.foe) {
        (Pencil::Half { side, .. }, Some(foe)) => {
            let (k, m) = keying.key(p);
            let own = if orient < 0.0 {
                (-k - m, -k + m)
            } else {
                (k - m, k + m)
            };
            Radial::new(&band, (foe, side), own, near_foe)
        }
        _ => None,
    };
    let mut walk = Walker::new(band, b2, cot_twice, radial);
    let outcome = match matcher {
        Matcher::Reference => {
            for j in 0..b2.len().saturating_sub(1) {
                let iv = match (b2.get(j), b2.get(j + 1)) {
                    (Some(a), Some(b)) => raw_interval(keying, a.arr(), b.arr()),
                    _ => (f32::NEG_INFINITY, f32::INFINITY),
                };
                if Visitor::segment(&mut walk, j, iv).0 == Flow::Stop {
                    break;
                }
            }
            walk.outcome()
        }
        Matcher::Indexed => {
            let query = band_query(pair, keying, &band, key, near_foe);
            let with_near = geom.w() < 0.0;
            match index.visit(query, with_near, None, work, &mut walk) {
                Err(OutOfWork) => return PointResult::flagged(p1, Status::OverBudget),
                Ok(()) => walk.outcome(),
            }
        }
    };
    conclude(pair, p1, iz, &band, &errors, outcome)
}

/// The key interval to search for a band (see [`Band::key_half_width`]
/// and [`Keying::around`]).
fn band_query(pair: &Pair, keying: &Keying, band: &Band, key: f32, near_foe: f32) -> Query {
    const NOTHING: Query = Query::Keys(f32::INFINITY, f32::NEG_INFINITY);
    if keying.angular() {
        match band.key_half_width(near_foe, pair.exhaustive(), keying.key_scale) {
            crate::depth::Reach::Within(t, m) => match keying.around(band.p, key, t, m) {
                Some((lo, hi)) => Query::Keys(lo, hi),
                None => NOTHING,
            },
            crate::depth::Reach::Everything => Query::Everything,
        }
    } else {
        // The hull of the corners' keys, within the image's reach.
        let from_p = (band.p[0] - pair.geom.c2()[0]).abs()
            + (band.p[1] - pair.geom.c2()[1]).abs()
            + pair.reach;
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for c in band.corners(from_p) {
            let (k, m) = keying.key(c);
            if !k.is_finite() {
                return Query::Everything;
            }
            lo = crate::math::fmin(lo, k - m);
            hi = crate::math::fmax(hi, k + m);
        }
        Query::Keys(lo, hi)
    }
}

/// The point's result from the walk's outcome: depth (eq. 2.3) and stick.
fn conclude(
    pair: &Pair,
    p1: Pixel,
    iz: f32,
    band: &Band,
    errors: &PointErrors,
    outcome: Outcome,
) -> PointResult {
    let (lam, lo, hi) = match outcome {
        Outcome::Match { lam, lo, hi, .. } => (lam, lo, hi),
        Outcome::Flag(s) => return PointResult::flagged(p1, s),
    };
    let p2 = band.point_at(lam);
    let mut depths = band.depths(errors, lam, lo, hi);
    // A composed motion's scale error (`Pair::scale_motion`): the ends
    // outwards by `1 ± s`, and a rounding more (the wedge paths have it in
    // `W'↑`, `W'↓`).
    let s = pair.scale_motion;
    if s > 0.0 {
        depths =
            depths.map(|(z, near, far)| (z, near * (1.0 - s - 2.4e-7), far * (1.0 + s + 2.4e-7)));
    }
    finish_point(pair, p1, p2, iz, depths)
}
