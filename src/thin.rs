//! Frame 2's boundary **thinned** before it is keyed and searched: the
//! vertices that lie on the chord between their neighbours dropped.
//!
//! A row-scanning detector gives one point per image row, rounded to the
//! pixel grid, so a straight stretch of a boundary comes out as a lattice
//! staircase whose vertices lie *exactly* on a few long chords (one step
//! of two columns in every row, say). Every such vertex makes a segment
//! that steps 3 and 4 of [`crate::Processor::process`] key, index and
//! clip although the chord alone carries the same polyline. The thinning
//! replaces each run of vertices lying within `ε` of the chord between the
//! run's ends by that chord, in one pass.
//!
//! # What the thinned polyline keeps
//! The thinned polyline `Q` is a subsequence of the detected one `P` with
//! the same two ends, and every vertex of `P` lies within `ε` of the
//! segment of `Q` whose run holds it. So every segment of `P` (its two
//! ends within `ε` of the same segment of `Q`) lies within `ε` of it: the
//! `ε`-neighbourhood of a segment is convex. A true boundary within `e₂`
//! of `P` (the error model, [`crate::depth`]) is therefore within `e₂ + ε`
//! of `Q`, and every guarantee of the matching stage holds for `Q` with
//! `e₂ + ε` in place of `e₂`: the processor searches `Q` with that error
//! ([`crate::Processor::process`]), so a stick is about `ε / (r₁ + e₂)`
//! wider than with `P` (`ε = e₂/256`: a few tenths of a per cent), and a
//! match lies on `Q`, within `ε` of `P`. `Q` is again a boundary in the
//! sense of [`crate::boundary`] (finite, inside the image, strictly
//! monotone in `v`, at most `N` points).
//!
//! # The test, exactly
//! Boundaries are strictly monotone in the row `v`, so a chord from the
//! run's anchor `a` to a later vertex `j` is `u = u_a + s (v − v_a)` with
//! the slope `s = Δu_j/Δv_j` (`Δ` from `a`, `Δv` counted along the
//! boundary's direction, so positive and growing). Vertex `i` of the run
//! lies within `e` of that chord *horizontally* at its own row when `|Δu_i
//! − s Δv_i| ≤ e`, that is when `s` lies in `[(Δu_i − e)/Δv_i, (Δu_i +
//! e)/Δv_i]`; as `0 < Δv_i < Δv_j` that chord point lies on the segment
//! `a → j`, so the vertex is within `e` of the segment (the horizontal
//! distance bounds the distance). The pass keeps the intersection
//! `[lo, hi]` of those intervals over the run's vertices so far and takes
//! the next vertex `j` into the run while its own slope lies in it; else
//! the run ends at the vertex before `j`, which anchors the next run (its
//! first segment, an original one, is taken without a test). One test a
//! vertex, one more on each run's end: linear in the points.
//!
//! **Rounding.** In `f32`, each `Δ` is the exact difference rounded once
//! (`1 + α`, `|α| ≤ u = 2⁻²⁴`), `1/Δv` once more, the slope and each end of
//! an interval once or twice more. Carried through the test `s̃_j ≥ l̃_i`
//! (multiplied by the exact `Δv_i > 0`), the exact deviation is at most
//! `e (1 + 4.02 u) + 5.03 u |Δu_i| + 4.01 u |s_j Δv_i|`, and `|s_j Δv_i|
//! = |Δu_j| Δv_i/Δv_j ≤ |Δu_j|`; the same for the upper end. A vertex joins
//! a run only within `2¹⁸ e` columns of its anchor (`|Δu| ≤ 2¹⁸ e`,
//! computed), so the deviation is at most `e (1 + 9.1 · 2⁻²⁴ · 2¹⁸ (1 +
//! u)) + 4.1 u e < 1.15 e`. The pass tests with `e = ε/2`: every vertex of
//! `P` lies within `0.575 ε` of `Q`'s segment. The factors `1 + α` hold
//! for results in `f32`'s normal range; a subnormal result (an interval
//! end or slope of a tiny `e` over a long `Δv`) is rounded by up to
//! `2⁻¹⁵⁰` absolutely instead, which times `Δv < 2¹⁵` (images at most
//! [`crate::camera::MAX_IMAGE_SIDE`] rows and their margin) and a few
//! roundings stays below `2⁻¹³²` columns, under the bound's slack of
//! `0.0078 e` for every `ε ≥ 2⁻⁹⁹` px (`MIN_EPS`); below it, `e₂` under
//! `2⁻⁹¹` px, the boundary is not thinned (`thin` refuses such an `ε`). (An
//! adversary's find: at `e₂ = 10⁻⁴⁰` a vertex `36 ε` off its chord was
//! dropped, `3 333 ε` at `10⁻⁴²`; by at most about `10⁻⁴¹` px.) A vertex joins a run only
//! with a finite slope (so a finite `1/Δv`): where a subnormal `Δv`
//! overflows `1/Δv`, the run ends; a boundary whose rows are so far apart
//! that `Δv` overflows is not thinned (the rows are monotone: one test of
//! the whole boundary's span). (An adversarial review found the test passing `+∞ ≥ +∞`: a
//! run's first vertex a subnormal row gap from its anchor and far to its
//! side gave the interval `[+∞, +∞]`, and a later vertex as close in rows
//! the slope `+∞`, dropping a vertex 499 px off its chord; through the
//! processor a spike along row 0 went missing and a stick missed the
//! truth, `host_tests/tests/thin.rs`.) The run's first vertex itself is
//! taken without a test, and its interval is exact or wider: `[−∞, +∞]`
//! only where it lies within `e` of its anchor at almost the same row,
//! within `e` of any chord from the anchor; a `NaN` end (`0 · ∞`) fails
//! every later test (an interval end is replaced by a `NaN` one, not
//! kept, `!(x <= lo)`).
//!
//! # What it costs
//! About 39 instructions a vertex on the emulated Cortex-M4F (one
//! division, `VDIV`, a vertex, two where a run ends), against the keys,
//! the index and the clips of step 4 it saves on every vertex dropped.
//! Where little thins (a boundary curved or noisy at the pixel scale), it
//! does not pay: after the first 64 vertices the pass gives up where it
//! kept more than seven in eight (`gives_up`), and the boundary is
//! searched as given (its `e₂` still the widened one, which costs nothing
//! but the few tenths of a per cent). The processor's index judges a thinned
//! boundary's envelopes by what they add to each segment's own interval
//! (`crate::search`'s `Builder::uneven`): a chord standing for a long run
//! is as wide in keys as the run, and not a fold.
//!
//! # Where it runs
//! Thinning needs the room for `Q`; [`crate::Processor::process`] (and
//! [`crate::Processor::process_within`]) write it over the previous
//! frame's boundary once step 1 has taken that boundary's points (the
//! call makes the new frame the previous one at its end anyway). The calls
//! against a kept frame keep that frame and search frame 2's boundaries
//! as given; so does every call of the fusion, even its last partner's,
//! which replaces the key frame, so that every partner of a key frame is
//! searched alike (thinning that last one was tried and not kept:
//! `docs/PERFORMANCE.md`, "Frame 2's boundary thinned on every path").

use crate::camera::Pixel;
use crate::search::{expired, Tick, CHUNK};

/// How far (in units of the test's `e`) from the run's anchor, in
/// columns, a vertex may lie to join the run: the bound on the rounding of
/// the test (module docs, "Rounding").
pub(crate) const REACH: f32 = 262_144.0;

/// Whether the pass gives up on a boundary whose first [`CHUNK`]
/// vertices after its first two left `kept` vertices written: more than
/// seven in eight. (Until the twenty-sixth session three in four, which
/// gave up on boundaries of the demo drive whose first part thins little
/// and the rest more: the drive's frames 7 and 8, over the deadline,
/// and `back_radial_stair`; `docs/PERFORMANCE.md`, "Frame 2's boundary
/// thinned on every path".)
pub(crate) const fn gives_up(kept: usize) -> bool {
    kept * 8 > CHUNK * 7
}

/// The smallest `ε` the pass thins with, `2⁻⁹⁹` px (module docs,
/// "Rounding": below it a subnormal interval end rounds absolutely).
pub(crate) const MIN_EPS: f32 = f32::from_bits(28 << 23);

/// The thinning's `ε` for a frame-2 error `e₂`: `e₂/256` (module docs);
/// the processor searches with `e₂ + ε`. [`thin`] leaves a boundary as it
/// is for `ε` below [`MIN_EPS`] (`e₂` below `2⁻⁹¹` px, `e₂ = 0`
/// included), where the widening by `ε` is then only a margin.
pub(crate) fn epsilon(e2: f32) -> f32 {
    e2 * (1.0 / 256.0)
}

/// Thin the boundary `src` with the tolerance `eps` ([`epsilon`]) into
/// `out` (at least as long as `src`): the number of vertices written, a
/// subsequence of `src` with its two ends, every vertex of `src` within
/// `eps` of the segment between the two written vertices around it
/// (module docs). `None` (nothing useful written) when `src` has fewer
/// than three points, `eps` is below [`MIN_EPS`] (or NaN), `out` is too short or the
/// rows' span overflows (module docs, "Rounding"), and
/// when the first [`CHUNK`] vertices after the first two kept more than
/// seven in eight ([`gives_up`]: a boundary thinning does not pay for,
/// module docs, "What it costs").
///
/// `src` must be strictly monotone in `v` ([`crate::boundary`]); on other
/// input the result is still a subsequence with the same ends, without the
/// bound.
///
/// Under a caller's deadline `tick` asks its clock before every
/// [`CHUNK`] vertices after the first; `None` when it says the time is up
/// (what was written then is a prefix of the thinned boundary).
pub(crate) fn thin(
    src: &[Pixel],
    eps: f32,
    out: &mut [Pixel],
    tick: &mut Tick<'_>,
) -> Option<usize> {
    let e = eps * 0.5;
    // (`ε` below `MIN_EPS`, or NaN: not thinned, module docs, "Rounding".)
    if src.len() < 3 || !(eps >= MIN_EPS) || out.len() < src.len() {
        return None;
    }
    let reach = e * REACH;
    let (&first, rest) = src.split_first()?;
    let (&second, rest) = rest.split_first()?;
    // The rows are monotone, so no `Δv` is larger than the whole
    // boundary's: finite where that one is (a frame's always is).
    if !(src.last()?.v - first.v).is_finite() {
        return None;
    }
    // The test's `e` signed with the boundary's direction in `v` (strictly
    // monotone): with `Δv` signed, `[(Δu − e_s)/Δv, (Δu + e_s)/Δv]` is the
    // interval of the module docs either way (`Δv < 0` turns it round).
    let es = if second.v > first.v { e } else { -e };
    // The slope interval a vertex `Δu` columns from the run's anchor
    // allows, `r = 1/Δv`; the interval of the run's first vertex.
    let interval = |du: f32, r: f32| ((du - es) * r, (du + es) * r);
    let constraint = |a: Pixel, q: Pixel| interval(q.u - a.u, 1.0 / (q.v - a.v));
    let mut written = 0usize;
    // (`out` holds at least as many vertices as `src`: every put lands.)
    let put = |out: &mut [Pixel], written: &mut usize, p: Pixel| {
        if let Some(slot) = out.get_mut(*written) {
            *slot = p;
            *written += 1;
        }
    };
    put(out, &mut written, first);
    let mut anchor = first;
    let (mut lo, mut hi) = constraint(anchor, second);
    let mut prev = second;
    for (c, rest) in rest.chunks(CHUNK).enumerate() {
        // After the first part: nothing more where it kept too many
        // ([`gives_up`]: a boundary thinning does not pay for), or where
        // the caller's clock says the time is up.
        if c == 1 && gives_up(written) {
            return None;
        }
        if c > 0 && expired(tick) {
            return None;
        }
        for &q in rest {
            let (du, r) = (q.u - anchor.u, 1.0 / (q.v - anchor.v));
            let s = du * r;
            // (A finite slope: an overflowed `1/Δv` ends the run, module
            // docs, "Rounding"; `Δv` itself is finite, the span's test
            // above.)
            if s >= lo && s <= hi && du.abs() <= reach && s.abs() < f32::INFINITY {
                // `q` joins the run; its own interval narrows the run's
                // (a `NaN` end is taken, and fails every later test).
                let (l, h) = interval(du, r);
                lo = if l <= lo { lo } else { l };
                hi = if h >= hi { hi } else { h };
            } else {
                // The run ends at the vertex before `q`, which anchors the
                // next one (its first segment taken as it is).
                put(out, &mut written, prev);
                anchor = prev;
                (lo, hi) = constraint(anchor, q);
            }
            prev = q;
        }
    }
    put(out, &mut written, prev);
    Some(written)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::test_rng::Rng;
    use std::vec::Vec;

    /// The distance from `p` to the segment `a → b`, in `f64`.
    fn distance(p: Pixel, a: Pixel, b: Pixel) -> f64 {
        let (px, py) = (f64::from(p.u), f64::from(p.v));
        let (ax, ay) = (f64::from(a.u), f64::from(a.v));
        let (bx, by) = (f64::from(b.u), f64::from(b.v));
        let (dx, dy) = (bx - ax, by - ay);
        let l2 = dx * dx + dy * dy;
        let t = if l2 > 0.0 {
            (((px - ax) * dx + (py - ay) * dy) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        ((px - ax - t * dx).powi(2) + (py - ay - t * dy).powi(2)).sqrt()
    }

    /// Checks the module's claims on one boundary: a subsequence with the
    /// same ends, every dropped vertex within `bound` of its chord (in
    /// `f64`). Returns the thinned length.
    fn check(src: &[Pixel], eps: f32, bound: f64) -> usize {
        let mut out = std::vec![Pixel::new(0.0, 0.0); src.len()];
        let Some(m) = thin(src, eps, &mut out, &mut None) else {
            // Given up after the first part: it kept more than seven in
            // eight ([`gives_up`]; the first part's written vertices are
            // its kept ones and the run's anchor, the thinned prefix less
            // its last vertex).
            assert!(src.len() > CHUNK + 2);
            let mut first = std::vec![Pixel::new(0.0, 0.0); CHUNK + 2];
            let kept = thin(&src[..CHUNK + 2], eps, &mut first, &mut None);
            assert!(kept.is_some_and(|k| gives_up(k - 1)), "{kept:?}");
            return src.len();
        };
        let q = &out[..m];
        assert_eq!((q.first(), q.last()), (src.first(), src.last()));
        // A subsequence: each kept vertex found in order.
        let mut at = Vec::with_capacity(m);
        let mut i = 0;
        for v in q {
            while src[i] != *v {
                i += 1;
            }
            at.push(i);
        }
        for w in at.windows(2) {
            for p in &src[w[0]..=w[1]] {
                let d = distance(*p, src[w[0]], src[w[1]]);
                assert!(d <= bound, "{d} > {bound} at {w:?}");
            }
        }
        m
    }

    /// Where `ε` is tiny the interval ends are subnormal and round
    /// absolutely: below [`MIN_EPS`] nothing is thinned (an adversary's
    /// case, `e₂ = 10⁻⁴⁰`: a vertex `36 ε` off its chord was dropped), and
    /// from it on every dropped vertex still lies within `0.575 ε` of its
    /// chord, the middle vertex placed from 0 to `2.9 ε` off its chord,
    /// rows up to 16 000 apart. (With `ε` a thousand million times smaller,
    /// subnormal, the same vertices fail the bound.)
    #[test]
    fn tiny_errors_thin_within_the_bound_or_not_at_all() {
        let case = [
            Pixel::new(0.0, 0.0),
            Pixel::new(f32::from_bits(0x1388), 10_000.0),
            Pixel::new(f32::from_bits(0x5dbf), 16_000.0),
        ];
        let mut out = [Pixel::new(0.0, 0.0); 3];
        assert_eq!(thin(&case, epsilon(1e-40), &mut out, &mut None), None);
        assert_eq!(thin(&case, f32::NAN, &mut out, &mut None), None);
        assert_eq!(thin(&case, MIN_EPS * 0.99, &mut out, &mut None), None);
        assert_eq!(epsilon(256.0 * MIN_EPS), MIN_EPS);
        let mut dropped = 0;
        for k in 0..40 {
            let eps = MIN_EPS * [1.0f32, 1.5, 7.0, 1e3, 1e9][k % 5];
            for (rows, dev) in [16_000.0f32, 9_000.0, 3.0]
                .into_iter()
                .flat_map(|r| (0..30).map(move |j| (r, f64::from(j) * 0.1)))
            {
                // The middle vertex `dev · ε` to the side of the chord from
                // (u0, 0) to (u0 + du, rows), at a third of its rows.
                let u0 = f64::from(eps) * [0.0, 3.0, 1e3][k % 3];
                let du = f64::from(eps) * [0.0, 50.0, -7.0, 2e4][k % 4];
                let v1 = f64::from(rows) / 3.0;
                let mid = u0 + du / 3.0 + dev * f64::from(eps);
                let src = [
                    Pixel::new(u0 as f32, 0.0),
                    Pixel::new(mid as f32, v1 as f32),
                    Pixel::new((u0 + du) as f32, rows),
                ];
                let m = check(&src, eps, 0.575 * f64::from(eps));
                dropped += 3 - m;
            }
        }
        assert!(dropped > 100, "{dropped}");
    }

    /// Lattice staircases (a detector's rounded straight edges), rounded
    /// curves, noisy points and rows at any spacing, over cameras up to
    /// 8 000 px: every dropped vertex within `0.575 ε` of its chord, and
    /// straight staircases thinned.
    #[test]
    fn every_dropped_vertex_lies_on_its_chord() {
        let mut g = Rng(7);
        let mut dropped = 0usize;
        let mut total = 0usize;
        for case in 0..4000 {
            let width = [512.0f32, 1024.0, 2048.0, 8000.0][case % 4];
            let n = 3 + (g.next() * 300.0) as usize;
            let (u0, v0) = (g.next() * width, g.next() * 100.0);
            let slope = (g.next() - 0.5) * 8.0;
            let curve = if case % 3 == 0 {
                (g.next() - 0.5) * 0.02
            } else {
                0.0
            };
            let step = [1.0f32, 2.0, 0.37, 3.0][(case / 4) % 4];
            let round = case % 5 != 0;
            let noise = if case % 7 == 0 { 0.3 } else { 0.0 };
            let mut src = Vec::with_capacity(n);
            for k in 0..n {
                let dv = k as f32 * step;
                let mut u = u0 + slope * dv + curve * dv * dv + noise * (g.next() - 0.5);
                if round {
                    u = u.round();
                }
                src.push(Pixel::new(u, v0 + dv));
            }
            if case % 2 == 1 {
                src.reverse();
            }
            let eps = [0.5f32 / 256.0, 0.002, 0.05, 1.0][(case / 16) % 4];
            let m = check(&src, eps, 0.575 * f64::from(eps));
            dropped += n - m;
            total += n;
        }
        // Most of the staircases' vertices go.
        assert!(dropped * 3 > total, "{dropped} of {total}");
    }

    /// A boundary whose first part thins by less than an eighth (noisy
    /// points along a curve) is given up on after that part.
    #[test]
    fn a_boundary_that_does_not_thin_is_given_up() {
        let mut g = Rng(11);
        let src: Vec<Pixel> = (0..200)
            .map(|k| {
                let v = k as f32;
                Pixel::new(100.0 + 0.002 * v * v + 0.3 * g.next(), 400.0 - v)
            })
            .collect();
        let mut out = std::vec![Pixel::new(0.0, 0.0); src.len()];
        assert_eq!(thin(&src, 0.002, &mut out, &mut None), None);
        // Its first part alone (no second to give up before) is thinned.
        let part = &src[..CHUNK + 2];
        let m = check(part, 0.002, 0.575 * 0.002);
        assert!(gives_up(m), "{m}");
    }

    /// Vertices built to sit at the test's edge: on a line, each moved
    /// across it by `e` give or take a thousandth, alternately to either
    /// side, far from the origin and with runs reaching the column limit:
    /// still every dropped vertex within `0.575 ε` of its chord.
    #[test]
    fn vertices_at_the_tests_edge_stay_within_the_bound() {
        let mut g = Rng(5);
        for case in 0..2000 {
            let eps = [0.002f32, 0.5 / 256.0, 0.03][case % 3];
            let e = eps * 0.5;
            let (u0, v0) = (g.next() * 7000.0 + 500.0, g.next() * 7000.0);
            let slope = (g.next() - 0.5) * [0.5f32, 4.0, 1e3 * e][case % 3];
            let step = [1.0f32, 0.25, 3.0, 1e-3][(case / 3) % 4];
            let n = 3 + (g.next() * 200.0) as usize;
            let src: Vec<Pixel> = (0..n)
                .map(|k| {
                    let dv = k as f32 * step;
                    let side = if k % 2 == 0 { 1.0 } else { -1.0 };
                    let off = side * e * (1.0 + (g.next() - 0.5) * 2e-3);
                    Pixel::new(u0 + slope * dv + off, v0 + dv)
                })
                .collect();
            check(&src, eps, 0.575 * f64::from(eps));
        }
    }

    /// A review's finds: a run's first vertex a subnormal row gap from
    /// its anchor and 500 px aside (its interval `[+∞, +∞]`), then a
    /// vertex as close in rows (the slope `+∞`); the same decreasing; rows
    /// so far apart that `Δv` overflows (`1/Δv = 0`, the interval `[0,
    /// 0]`). No vertex is dropped farther than the bound from its chord.
    #[test]
    fn overflowed_row_gaps_end_the_run() {
        let t = f32::from_bits;
        let rising = [
            Pixel::new(0.0, 0.0),
            Pixel::new(500.0, t(1)),
            Pixel::new(1.0, t(2)),
        ];
        assert_eq!(check(&rising, 0.39, 0.575 * 0.39), 3);
        let falling = [
            Pixel::new(0.0, 0.0),
            Pixel::new(500.0, -t(1)),
            Pixel::new(1.0, -t(2)),
            Pixel::new(2.0, -1.0),
        ];
        check(&falling, 0.39, 0.575 * 0.39);
        let falling_hair = [
            Pixel::new(10.0, 2.0 * f32::MIN_POSITIVE),
            Pixel::new(400.0, f32::MIN_POSITIVE),
            Pixel::new(11.0, 0.0),
            Pixel::new(12.0, -0.5),
        ];
        check(&falling_hair, 0.002, 0.575 * 0.002);
        let huge = [
            Pixel::new(0.0, -3.0e38),
            Pixel::new(1000.0, 3.0e38),
            Pixel::new(0.0, 3.4e38),
        ];
        let mut out = [Pixel::new(0.0, 0.0); 3];
        assert_eq!(thin(&huge, 0.39, &mut out, &mut None), None);
    }

    /// A straight staircase of two columns a row: every vertex but the
    /// ends dropped; a row spacing of a hair (a `1/Δv` that overflows)
    /// ends the run instead of taking a wrong one.
    #[test]
    fn straight_runs_go_and_hair_spacing_stops_them() {
        let src: Vec<Pixel> = (0..100)
            .map(|k| Pixel::new(10.0 + 2.0 * k as f32, 300.0 - k as f32))
            .collect();
        assert_eq!(check(&src, 0.002, 0.002), 2);
        let tiny = [
            Pixel::new(10.0, 5.0),
            Pixel::new(12.0, 5.0 + 1e-38),
            Pixel::new(14.0, 6.0),
            Pixel::new(16.0, 7.0),
            Pixel::new(100.0, 8.0),
        ];
        check(&tiny, 0.002, 0.002);
        // Too short, or no tolerance: nothing done.
        let mut out = [Pixel::new(0.0, 0.0); 5];
        assert_eq!(thin(&tiny[..2], 0.002, &mut out, &mut None), None);
        assert_eq!(thin(&tiny, 0.0, &mut out, &mut None), None);
        assert_eq!(thin(&tiny, f32::NAN, &mut out, &mut None), None);
    }
}
