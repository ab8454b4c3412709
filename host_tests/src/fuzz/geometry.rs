//! [`road_geometry`] on views of a drawn road (camera height and tilt,
//! two boundaries, sticks around the true depths, wrong matches) mixed
//! with special values, bad sticks and bad counts.
//!
//! Oracles: no panic and no hang (issue 15, item 1 was an endless sweep);
//! input errors exactly as documented, naming the first bad sample (an
//! independent check of the rules); every `Ok` finite with `lo <= hi`,
//! the tilt within `[0°, 60°]` widened by a grid step, the outliers as
//! given; same input, same output; and where the samples are as drawn
//! from one road (sticks of ±1 % or more) with no more wrong matches than
//! allowed (some above the horizon), `Ok` with that road's height and
//! tilt in the ranges.

use roadstereo::geometry::{
    road_geometry, GeometryError, Sample, SampleIndex, MAX_NORMALISED, MAX_SAMPLE_DEPTH, MAX_VIEWS,
    MIN_POINTS,
};

use super::{Outcome, Source};

/// Capacity for all points together.
pub const CAP: usize = 64;

/// One case: views (left and right samples) and the outliers allowed.
#[derive(Debug, Clone)]
pub struct Case {
    /// The views.
    pub views: Vec<(Vec<Sample>, Vec<Sample>)>,
    /// Points that may disagree.
    pub outliers: usize,
    /// The road's camera height and tilt (radians) the samples were drawn
    /// from, when every sample is as drawn (no mutation) and every stick
    /// is at least ±1 % (so the `f32` rounding of a sample cannot put the
    /// truth outside it); with the number of wrong matches drawn.
    pub truth: Option<(f64, f64, usize)>,
}

/// A boundary's samples, the wrong matches among them and the stick's
/// half-width.
fn side(src: &mut Source, h: f64, tilt: f64, lateral: f64, n: usize) -> (Vec<Sample>, usize, f64) {
    let (s, c) = tilt.sin_cos();
    let stick = src.pick(&[0.0, 0.01, 0.05, 0.3]);
    let mut wrong = 0;
    let v = (0..n)
        .map(|i| {
            // Rows below the horizon, nearest first.
            let k = src.range(0.02, 0.6) * (1.0 - i as f64 / (n as f64 + 1.0)) + 0.005;
            let mut y = (k - s) / c;
            let z = h / k;
            let mut z = z;
            if src.chance(1, 12) {
                wrong += 1;
                if src.chance(1, 3) {
                    // A wrong match above the horizon of the true tilt
                    // (its ray misses the plane there; a review found the
                    // height sweep mishandling such points).
                    y = -s / c - src.range(0.01, 0.5);
                } else {
                    z *= src.range(0.3, 3.0);
                }
            }
            Sample {
                x: (lateral / z) as f32,
                y: y as f32,
                z_near: (z * (1.0 - stick)) as f32,
                z_far: (z * (1.0 + stick)) as f32,
            }
        })
        .collect();
    (v, wrong, stick)
}

/// Draw a case.
pub fn generate(src: &mut Source) -> Case {
    let h = src.range(0.5, 3.0);
    let tilt = src.range(0.0, 0.5);
    let nv = match src.below(16) {
        0 => 0,
        1 => MAX_VIEWS + 1,
        2 => MAX_VIEWS,
        _ => 1 + src.index(2),
    };
    let count = |src: &mut Source| match src.below(16) {
        0 => src.index(MIN_POINTS),
        1 => CAP + 1,
        _ => MIN_POINTS + src.index(16),
    };
    let (mut wrong, mut least_stick) = (0usize, f64::INFINITY);
    let mut views: Vec<(Vec<Sample>, Vec<Sample>)> = (0..nv)
        .map(|_| {
            let (nl, nr) = (count(src), count(src));
            let w = src.range(2.0, 12.0);
            let (l, wl, sl) = side(src, h, tilt, -w / 2.0, nl);
            let (r, wr, sr) = side(src, h, tilt, w / 2.0, nr);
            wrong += wl + wr;
            least_stick = least_stick.min(sl).min(sr);
            (l, r)
        })
        .collect();
    let mutations = if src.chance(1, 2) {
        0
    } else {
        1 + src.below(3)
    };
    let truth = (mutations == 0 && least_stick >= 0.01).then_some((h, tilt, wrong));
    for _ in 0..mutations {
        if views.is_empty() {
            break;
        }
        let v = src.index(views.len());
        let b = if src.chance(1, 2) {
            &mut views[v].0
        } else {
            &mut views[v].1
        };
        if b.is_empty() {
            continue;
        }
        let i = src.index(b.len());
        let p = &mut b[i];
        match src.below(6) {
            0 => p.x = src.special(),
            1 => p.y = src.special(),
            2 => p.z_near = src.special(),
            3 => {
                p.z_far = src.pick(&[
                    f32::INFINITY,
                    3.0e38,
                    MAX_SAMPLE_DEPTH,
                    MAX_SAMPLE_DEPTH.next_up(),
                    1.0e30,
                ])
            }
            4 => core::mem::swap(&mut p.z_near, &mut p.z_far),
            _ => {
                p.y = src.pick(&[1.0, -1.0, MAX_NORMALISED, -MAX_NORMALISED.next_up(), 0.0]);
            }
        }
    }
    let outliers = match src.below(8) {
        0 => src.pick(&[usize::MAX, 1 << 20, CAP]),
        1..=3 => src.index(4),
        _ => 0,
    };
    Case {
        views,
        outliers,
        truth,
    }
}

/// The documented input error of `views`, if any.
fn expected_error(views: &[(&[Sample], &[Sample])], outliers: usize) -> Option<GeometryError> {
    if views.is_empty() {
        return Some(GeometryError::TooFewPoints);
    }
    if views.len() > MAX_VIEWS {
        return Some(GeometryError::TooManyViews);
    }
    for (l, r) in views {
        if l.len() < MIN_POINTS || r.len() < MIN_POINTS {
            return Some(GeometryError::TooFewPoints);
        }
        if l.len() > CAP || r.len() > CAP {
            return Some(GeometryError::TooManyPoints);
        }
    }
    for (view, (l, r)) in views.iter().enumerate() {
        for (boundary, s) in [l, r].into_iter().enumerate() {
            for (index, p) in s.iter().enumerate() {
                let at = SampleIndex {
                    view,
                    boundary,
                    index,
                };
                if ![p.x, p.y, p.z_near, p.z_far].iter().all(|x| x.is_finite()) {
                    return Some(GeometryError::NotFinite(at));
                }
                if !(p.x.abs() <= MAX_NORMALISED
                    && p.y.abs() <= MAX_NORMALISED
                    && 0.0 <= p.z_near
                    && p.z_near <= p.z_far
                    && p.z_far <= MAX_SAMPLE_DEPTH)
                {
                    return Some(GeometryError::OutOfRange(at));
                }
            }
        }
    }
    // The plane fit: every point if they fit, else the same largest share
    // of each boundary that fits (at least one each: 2 · 16 ≤ CAP).
    let lens: Vec<usize> = views.iter().flat_map(|(l, r)| [l.len(), r.len()]).collect();
    let taken = |q: usize| lens.iter().map(|&n| n.min(q)).sum::<usize>();
    let q = (1..=CAP).take_while(|&q| taken(q) <= CAP).last()?;
    if outliers >= taken(q) {
        return Some(GeometryError::TooManyOutliers);
    }
    None
}

/// Generate a case from `src` and check it.
pub fn run(src: &mut Source) -> Outcome {
    check(&generate(src))
}

/// Check a case (panics on a finding).
pub fn check(case: &Case) -> Outcome {
    let views: Vec<(&[Sample], &[Sample])> = case
        .views
        .iter()
        .map(|(l, r)| (l.as_slice(), r.as_slice()))
        .collect();
    let r = road_geometry::<CAP>(&views, case.outliers);
    let want = expected_error(&views, case.outliers);
    let bit = match (&r, want) {
        (Err(e), Some(w)) => {
            assert_eq!(*e, w, "road_geometry: input error");
            1 + match e {
                GeometryError::TooFewPoints => 0,
                GeometryError::TooManyPoints => 1,
                GeometryError::TooManyViews => 2,
                GeometryError::NotFinite(_) => 3,
                GeometryError::OutOfRange(_) => 4,
                GeometryError::Inconsistent => 5,
                // (The enum is non-exhaustive: a variant added later counts with
                // the last one, so no other feature's bit is taken.)
                _ => 5,
            }
        }
        (Err(e), None) => {
            assert_eq!(
                *e,
                GeometryError::Inconsistent,
                "road_geometry: valid input rejected"
            );
            // Drawn from one road with no more wrong matches than allowed:
            // that road's `(θ, h)` agrees, so it is not inconsistent.
            if let Some((h, tilt, wrong)) = case.truth {
                assert!(
                    wrong > case.outliers,
                    "road_geometry: Inconsistent, but h {h} tilt {tilt} agree with all but {wrong} ≤ {} points",
                    case.outliers
                );
            }
            7
        }
        (Ok(g), None) => {
            let ranges = [
                ("height", Some(g.height)),
                ("tilt", Some(g.tilt)),
                ("width", g.width),
            ];
            for (name, x) in ranges.into_iter().filter_map(|(n, x)| Some((n, x?))) {
                assert!(
                    x.lo.is_finite() && x.hi.is_finite() && x.lo <= x.hi,
                    "road_geometry: {name} {x:?} in {g:?}"
                );
            }
            let max_tilt = 60.0f32.to_radians() + 2.0 * 0.000_872_664_6;
            assert!(
                g.tilt.lo >= 0.0 && g.tilt.hi <= max_tilt,
                "road_geometry: tilt {:?}",
                g.tilt
            );
            assert_eq!(g.outliers_allowed, case.outliers);
            // The road the samples were drawn from is in the ranges (the
            // guarantee: every `(θ, h)` that agrees with all but
            // `outliers` of the plane fit's points).
            if let Some((h, tilt, wrong)) = case.truth {
                if wrong <= case.outliers {
                    assert!(
                        g.height.contains(h as f32) && g.tilt.contains(tilt as f32),
                        "road_geometry: h {h} tilt {tilt} (wrong {wrong}) outside {g:?}"
                    );
                }
            }
            0
        }
        (Ok(g), Some(w)) => panic!("road_geometry: Ok {g:?}, expected {w:?}"),
    };
    if r.is_ok() || matches!(r, Err(GeometryError::Inconsistent)) {
        assert_eq!(
            r,
            road_geometry::<CAP>(&views, case.outliers),
            "road_geometry: not deterministic"
        );
    }
    Outcome {
        calls: 1,
        features: 1u128 << bit,
        ..Outcome::default()
    }
}
