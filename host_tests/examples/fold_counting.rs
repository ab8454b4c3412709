//! Measures a rule the library does **not** have yet (issue 11 §4, the
//! per-family yield): which of the points the fold test flags a counting
//! rule could give back, and at what risk, over the certification's
//! scenarios (`host_tests::certify`). Run:
//!
//! ```text
//! cd host_tests && cargo run --release --example fold_counting [scenarios per family] [tolerance px]
//! ```
//!
//! The fold test (`src/fold.rs`) flags a frame-1 point `p₁` whose ray from
//! the FOE `F` meets the frame-1 polyline again at `q`: a frame-2 crossing
//! in `p₁`'s band could be `q`'s image. Moving forwards an image lies
//! beyond its frame-1 point on the ray, so for the points the certification
//! loses (the S-bend's near side, whose `q` lies on the far side of the
//! bend, nearer `F`) `q`'s image is either before `p₁` or beyond it. The
//! **counting rule**: keep the fold when a frame-1 crossing lies beyond
//! `p₁`; otherwise, if the frame-2 polyline crosses the ray between the
//! frame-1 crossings and `p₁` often enough that every frame-1 crossing
//! before `p₁` can have its image there (each `q` a distinct frame-2
//! crossing at or beyond it and before `p₁`: Hall's condition, greedily),
//! no frame-1 point on the ray is left to be the image's source beyond
//! `p₁` but `p₁` itself, and the point is searched as if it did not fold.
//! (It assumes what the fold test assumes: the frame-2 crossings come from
//! frame-1 points the detector saw.)
//!
//! Here the rule is evaluated in `f64` on the detected polylines, with
//! the true rotation's compensation and the exact ray (the library would
//! use its bands): for each point the shipped processor flags `folded`,
//! the result it gets with the fold test off
//! (`Processor::without_fold_test_against_kept`) is the rescued result
//! where the rule allows it. Printed per family and variant: ideal points,
//! the shipped recall (ideal points `ok`), the share of ideal points
//! `folded`, the rescued points, the rescued share of the ideal points,
//! and the two risks: rescued `ok` points whose correspondent is not in
//! frame 2 (wrong matches) and rescued `ok` points whose stick misses the
//! truth.
use host_tests::certify::{foe_h, run_with, Case, Fold, Variant};
use host_tests::scenarios::Family;
use roadstereo::Status;

/// Where the segments of `poly` cross the line `F + t d` (`p₁` at `t =
/// 1`), the segments `skip` names left out.
fn crossings(
    poly: &[[f64; 2]],
    f: [f64; 2],
    d: [f64; 2],
    skip: impl Fn(usize) -> bool,
) -> Vec<f64> {
    let n = [-d[1], d[0]];
    let dd = d[0] * d[0] + d[1] * d[1];
    let side = |p: [f64; 2]| n[0] * (p[0] - f[0]) + n[1] * (p[1] - f[1]);
    (0..poly.len().saturating_sub(1))
        .filter(|&j| !skip(j))
        .filter_map(|j| {
            let (a, b) = (poly[j], poly[j + 1]);
            let (sa, sb) = (side(a), side(b));
            if (sa > 0.0 && sb > 0.0) || (sa < 0.0 && sb < 0.0) || (sa == 0.0 && sb == 0.0) {
                return None;
            }
            let u = sa / (sa - sb);
            let x = [a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])];
            Some((d[0] * (x[0] - f[0]) + d[1] * (x[1] - f[1])) / dd)
        })
        .collect()
}

/// The counting rule for one point: frame-1 crossings `q` and frame-2
/// crossings `c` on its ray (`t`), `tol` in `t`.
fn rescued(mut q: Vec<f64>, c: Vec<f64>, tol: f64) -> bool {
    if q.iter().any(|&t| t > 1.0 - tol) {
        return false;
    }
    let mut c: Vec<f64> = c
        .into_iter()
        .filter(|&t| t > 0.0 && t < 1.0 - tol)
        .collect();
    q.sort_by(f64::total_cmp);
    c.sort_by(f64::total_cmp);
    // Hall's condition, greedily: the farthest `q` takes the farthest `c`.
    for &qt in q.iter().rev() {
        match c.last() {
            Some(&ct) if ct >= qt - tol => {
                c.pop();
            }
            _ => return false,
        }
    }
    true
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let per: u64 = args.first().and_then(|s| s.parse().ok()).unwrap_or(66);
    let tol_px: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1.0);
    println!("| family | variant | ideal | recall shipped | ideal `folded` | rescued | rescued / ideal | rescued `ok` without a correspondent | rescued sticks missing the truth |");
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|");
    for fam in Family::ALL {
        for v in Variant::ALL {
            let mut t = [0usize; 7];
            for seed in 0..per {
                let Some(case) = Case::new(fam, seed) else {
                    continue;
                };
                let input = case.input(v);
                let k = &case.scenario.intrinsics;
                let m = case.rendered.motion();
                let (Ok(on), Ok(off)) = (
                    run_with(k, &m, &input, Fold::Tested),
                    run_with(k, &m, &input, Fold::Untested),
                ) else {
                    continue;
                };
                let foe = foe_h(&case.rendered, k);
                let e = input.e1 + input.e2;
                for (b, tb) in case.truth.iter().enumerate() {
                    let c1: Vec<[f64; 2]> = input.frame1[b]
                        .iter()
                        .map(|p| case.rendered.compensate(k, f64::from(p.u), f64::from(p.v)))
                        .collect();
                    let f2: Vec<[f64; 2]> = input
                        .frame2
                        .get(b)
                        .map(|q| q.iter().map(|p| [f64::from(p.u), f64::from(p.v)]).collect())
                        .unwrap_or_default();
                    for (i, tr) in tb.iter().enumerate() {
                        let ideal = tr.ideal(e);
                        t[0] += usize::from(ideal);
                        let o = &on[b][i];
                        t[1] += usize::from(ideal && o.status == Status::Ok);
                        if o.status != Status::Folded {
                            continue;
                        }
                        t[2] += usize::from(ideal);
                        let x = &off[b][i];
                        // Moving forwards only (the FOE's third coordinate is W').
                        if x.status != Status::Ok || foe[2] <= 0.0 {
                            continue;
                        }
                        let f = [foe[0] / foe[2], foe[1] / foe[2]];
                        let d = [c1[i][0] - f[0], c1[i][1] - f[1]];
                        let tol = tol_px / (d[0] * d[0] + d[1] * d[1]).sqrt();
                        // The fold test's window: segments i − 4 ..= i + 3 are its own.
                        let q: Vec<f64> = crossings(&c1, f, d, |j| j + 5 > i && j < i + 4)
                            .into_iter()
                            .filter(|&t| t > 0.0)
                            .collect();
                        if !rescued(q, crossings(&f2, f, d, |_| false), tol) {
                            continue;
                        }
                        t[3] += 1;
                        t[4] += usize::from(ideal);
                        if !tr.observed {
                            t[5] += 1;
                        } else if !x.contains(tr.z_true) {
                            t[6] += 1;
                        }
                    }
                }
            }
            let pc = |a: usize| 100.0 * a as f64 / t[0].max(1) as f64;
            println!(
                "| {} | {} | {} | {:.1} % | {:.1} % | {} | {:.1} % | {} | {} |",
                fam.name(),
                v.name(),
                t[0],
                pc(t[1]),
                pc(t[2]),
                t[3],
                pc(t[4]),
                t[5],
                t[6]
            );
        }
    }
}
