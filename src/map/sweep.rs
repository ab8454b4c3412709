//! The map following the vehicle: the whole-batch bound on a batch's
//! forward coordinates ([`View`]) and the point-by-point sweep of the
//! batches the camera is passing (module docs of [`super`], "What leaves
//! the map").

use super::*;

/// Where a batch is against the camera this frame.
pub(super) enum Whole {
    Ahead,
    Behind,
    Passing,
}

/// A batch's forward coordinates this frame: a key-frame point `P` is
/// `g · P + g0` ahead of the camera (vehicle frame), `g = Aᵀ w`, `g0 = w · b`
/// with `w` the forward axis; `dg = |g − w|` bounds how far that is from
/// the key frame's own forward coordinate `w · P` (`|(g − w) · P| ≤ dg |P|`).
///
/// # The whole batch at once
/// For a stick end `P = z r`, `r = (x, y, 1)`, the forward coordinate is
/// `z (g · r) + g0`, and `g · r = w · r + (g − w) · r` lies within `dg
/// |r| ≤ dg c` of the ray's forward rate `w · r` (`c` the batch's `ray`).
/// With the batch's rates in `[d₀, d₁]` and depths in `[z₀, z₁]`, every
/// end's rate `g · r` is in `[k₀, k₁] = [d₀ − dg c, d₁ + dg c]`, so its
/// forward coordinate is at least `z₀ k₀ + g0` when `k₀ ≥ 0` (`z₁ k₀ + g0`
/// otherwise) and at most `z₁ k₁ + g0` when `k₁ ≥ 0` (`z₀ k₁ + g0`
/// otherwise): [`View::whole`]. A turn of the camera moves the rates by
/// `dg c`, a few hundredths for a turn of a degree or two, so the bound
/// holds on to a batch ahead however far its points reach (until the
/// twentieth session the bound was the extent of the forward coordinates
/// less `dg |P|`'s largest value: a turn of 1° since the key frame made a
/// batch reaching 200 away with its nearest end 4 away "passing", and each
/// of its points dropped for room was tested, `docs/PERFORMANCE.md`).
///
/// Rounding: the `f32` evaluation of a point's `g · r` is within `2⁻²¹ c`
/// of the exact value (three products and two sums of terms at most `|g|
/// |r| ≈ c`), `w · r` likewise, and the product with `z` and the sum with
/// `g0` add `2⁻²³ (z c + |g0|)`: `2⁻²⁰ c` on the rates and `2⁻¹⁹ (z₁ c +
/// |g0|)` on the result cover both, and the bound's own few operations.
pub(super) struct View {
    pub(super) g: [f32; 3],
    pub(super) g0: f32,
    pub(super) dg: f32,
    pub(super) lat: f32,
    /// The radius less its `Z_far λ`, bounded over the whole batch: `(ρ +
    /// (φ + 2⁻²⁰) reach)` rounded up twice (`reach` bounds every entry's
    /// `|P_K|` bound, [`radius`]): a point's sweep test is then as cheap as
    /// without motion errors, and no smaller than its own radius.
    pub(super) rest: f32,
}

impl View {
    pub(super) fn of<const B: usize>(b: &Batch<B>, tilt: (f32, f32)) -> View {
        let w = forward_axis(tilt);
        let g = mat3_vec(&mat3_transpose(&b.a), w);
        let d = [g[0] - w[0], g[1] - w[1], g[2] - w[2]];
        View {
            g,
            g0: dot3(w, b.b),
            dg: sqrt(dot3(d, d)) * 1.000_01 + 1e-7,
            lat: b.lat,
            rest: (b.rho + (b.phi + EVAL_ROUNDING) * b.reach) * (ROUND_UP * ROUND_UP),
        }
    }

    /// The whole batch ahead, behind (sticks and radii), or neither
    /// (the type's docs).
    pub(super) fn whole<const B: usize>(&self, b: &Batch<B>) -> Whole {
        let (lowest, highest, radius) = self.extremes(b);
        if highest + radius < 0.0 {
            Whole::Behind
        } else if lowest >= 0.0 {
            Whole::Ahead
        } else {
            Whole::Passing
        }
    }

    /// [`Self::whole`]'s bounds: below every stick end's forward
    /// coordinate, above every one (the rounding taken off and added), and
    /// above every point's radius.
    pub(super) fn extremes<const B: usize>(&self, b: &Batch<B>) -> (f32, f32, f32) {
        let ((d0, d1), (z0, z1)) = (b.dir, b.depth);
        let spread = (self.dg + ULP20) * b.ray;
        let (k0, k1) = (d0 - spread, d1 + spread);
        let lowest = k0 * if k0 >= 0.0 { z0 } else { z1 };
        let highest = k1 * if k1 >= 0.0 { z1 } else { z0 };
        let round = 2.0 * ULP20 * (z1 * b.ray + self.g0.abs());
        // (`reach` bounds `|P_K|`, and so `Z_far`, over the batch.)
        let radius = self.rest + self.lat * b.reach * ROUND_UP;
        (lowest + self.g0 - round, highest + self.g0 + round, radius)
    }

    /// Whether a live point's whole stick, widened by its radius (its `Z_far
    /// λ` and the batch's bound of the rest, `rest`), is behind. (A live
    /// entry's far code is 1 to `UNBOUNDED − 1`, [`RoadMap::retire`]: its
    /// depth needs no test of the range's ends.)
    #[inline(always)]
    pub(super) fn behind(&self, e: &Entry, scale: &DepthScale) -> bool {
        let dir = self.g[0] * e.x + self.g[1] * e.y + self.g[2];
        let zf = scale.depth_inner(e.far);
        // The stick's forward coordinate is largest at its far end when it
        // points forward, at its near end otherwise.
        let ahead = dir * if dir >= 0.0 { zf } else { scale.depth(e.near) } + self.g0;
        ahead + zf * self.lat * ROUND_UP + self.rest < 0.0
    }
}

/// The sweep's test of `n` ring slots from slot `start` (modulo `M`):
/// each live entry behind the camera ([`View::behind`]) is dropped;
/// returns how many were. (Out of line: the test's registers stay its
/// own.)
#[inline(never)]
fn sweep_run<const M: usize>(
    (ring, start, n): (&mut [Entry; M], usize, usize),
    view: &View,
    scale: &DepthScale,
) -> u16 {
    let mut dropped = 0u16;
    for j in start..start + n {
        if let Some(e) = ring.get_mut(j % M) {
            if e.live() && view.behind(e, scale) {
                *e = Entry::DEAD;
                dropped += 1;
            }
        }
    }
    dropped
}

impl<const B: usize, const M: usize> RoadMap<B, M> {
    /// The point-by-point sweep of the frame the last [`Self::carry`]
    /// carried the map into: in the batches it found the camera passing,
    /// test up to [`SWEEP_PER_FRAME`] points a boundary and drop those
    /// behind (module docs). Nothing in between may add or retire a batch
    /// (the fusion sweeps after its pass, before any retirement, or not at
    /// all); a second sweep before the next carry tests nothing.
    ///
    /// Work: at most [`SWEEP_PER_FRAME`] point tests per boundary.
    pub(crate) fn sweep(&mut self) {
        let passing = core::mem::take(&mut self.passing);
        for k in 0..B {
            self.sweep_boundary(k, &passing);
        }
        self.pop_dead();
    }

    /// Test up to [`SWEEP_PER_FRAME`] points of `boundary` in the batches
    /// the camera is passing (`passing`, by batch slot), from the sweep's
    /// slot on; drop those behind.
    pub(super) fn sweep_boundary(&mut self, boundary: usize, passing: &[bool; MAP_BATCHES]) {
        let used = self.used.get(boundary).map_or(0, |&u| usize::from(u));
        let mut pos = self.sweep.get(boundary).map_or(0, |&c| usize::from(c));
        if pos >= used {
            pos = 0;
        }
        let tail = self.tail.get(boundary).map_or(0, |&t| usize::from(t));
        let mut left = SWEEP_PER_FRAME;
        let mut offset = 0usize;
        for i in 0..usize::from(self.count) {
            let slot = self.slot(i);
            let Some(b) = self.batches.get(slot).copied() else {
                break;
            };
            let len = b.len.get(boundary).map_or(0, |&l| usize::from(l));
            let end = offset + len;
            let pass = passing.get(slot).copied().unwrap_or(false);
            if pos >= end || left == 0 {
                offset = end;
                continue;
            }
            if !pass || !b.live_on(boundary) {
                pos = end;
                offset = end;
                continue;
            }
            let view = View::of(&b, self.tilt);
            let n = (end - pos).min(left);
            let mut dropped = 0u16;
            if let Some(ring) = self.entries.get_mut(boundary) {
                let run = (ring, tail + pos, n);
                dropped = sweep_run::<M>(run, &view, &self.scale);
            }
            if let Some(lv) = self
                .batches
                .get_mut(slot)
                .and_then(|b| b.live.get_mut(boundary))
            {
                *lv = lv.saturating_sub(dropped);
            }
            self.drops.behind = self.drops.behind.wrapping_add(u32::from(dropped));
            left -= n;
            pos += n;
            offset = end;
        }
        if pos >= used {
            pos = 0;
        }
        if let Some(c) = self.sweep.get_mut(boundary) {
            *c = pos as u16;
        }
    }
}
