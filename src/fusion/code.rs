//! Depths in 16 bits, rounded outwards: the compact intervals of the road
//! map. (The fusion's cells kept their rival intervals in these codes until
//! the twenty-fourth session; they are exact `f32` now, [`super::key`].)
//!
//! A code is the top of an `f32`'s bits relative to a power of two `s` at
//! or above the configuration's maximum depth: for `z/s` in `[2⁻¹⁵, 2)` the
//! code is `(e − 112) · 2¹² + m`, with `e` the biased exponent of `z/s` and
//! `m` the top 12 bits of its mantissa. Codes are ordered like the depths
//! they stand for, so an interval's intersection is the larger of the near
//! codes and the smaller of the far codes, and an interval is empty exactly
//! when its near code exceeds its far code. A near end is rounded **down**
//! (the mantissa cut: at most `2⁻¹²` of the value), a far end **up**, so
//! the depths a coded interval stands for always include the interval
//! coded: rounding never loses the truth. Near the ends of the range, code
//! 0 is depth 0 (anything below `2⁻¹⁵ s`, where a far end becomes code 1)
//! and `0xFFFF` is an unbounded far end (anything from `2 s` on, and NaN).
//! Dividing by a power of two is exact, so the host and the vehicle
//! controller compute the same codes.

/// Smallest exponent (biased) of `z/s` with a code of its own: `2⁻¹⁵`.
const EXP_BASE: u32 = 127 - 15;
/// The unbounded far end.
pub(crate) const UNBOUNDED: u16 = 0xFFFF;
/// `EXP_BASE · 2¹²`: a positive `z/s`'s bits shifted right by 11, less
/// this, are its code (before the range's clamp).
const CODE_BASE: i32 = (EXP_BASE << 12) as i32;

/// The power of two `s` the codes are relative to, and its inverse.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct DepthScale {
    s: f32,
    inv: f32,
}

impl DepthScale {
    /// The smallest power of two at or above `max_depth` (between `2⁻¹²⁰`
    /// and `2¹²⁰`; a NaN or non-positive value gives `2¹⁰`).
    pub(crate) const fn for_max_depth(max_depth: f32) -> Self {
        let mut e: i32 = 10;
        if max_depth > 0.0 && max_depth.is_finite() {
            let bits = max_depth.to_bits();
            e = ((bits >> 23) & 0xFF) as i32 - 127;
            if bits & 0x007F_FFFF != 0 {
                e += 1;
            }
        }
        if e < -120 {
            e = -120;
        }
        if e > 120 {
            e = 120;
        }
        Self {
            s: f32::from_bits(((e + 127) as u32) << 23),
            inv: f32::from_bits(((127 - e) as u32) << 23),
        }
    }

    /// `s`.
    #[cfg(test)]
    pub(crate) fn scale(&self) -> f32 {
        self.s
    }

    /// The code of a near end: the largest code not above `z`.
    ///
    /// For `z > 0`, `(z/s)`'s bits shifted right by 11 are `e · 2¹² + m`
    /// (the sign bit is 0), so the code is that less `EXP_BASE · 2¹²`,
    /// clamped to `[0, UNBOUNDED − 1]`: below `2⁻¹⁵ s` (and an underflow
    /// to 0) code 0, from `2 s` on (and infinity) the top code of a near
    /// end. No branch on the exponent.
    #[inline]
    pub(crate) fn down(&self, z: f32) -> u16 {
        // (A NaN fails the comparison. Rare: laid out of the way.)
        if !(z > 0.0) {
            core::hint::cold_path();
            return 0;
        }
        let c = ((z * self.inv).to_bits() >> 11) as i32 - CODE_BASE;
        c.clamp(0, i32::from(UNBOUNDED - 1)) as u16
    }

    /// The code of a far end: the smallest code not below `z` (at least 1
    /// for `z > 0`: code 0 stands for depth 0). As [`Self::down`], plus one
    /// where any of the 11 bits cut is set, clamped to `[1, UNBOUNDED]`.
    /// (Until a twentieth session's rewrite the exponent's tests gave code
    /// 0 to `z = 2⁻¹⁵ s` exactly, a far end rounded down to depth 0;
    /// `codes_agree_with_their_definition` checks every exponent.)
    #[cfg(test)]
    pub(crate) fn up(&self, z: f32) -> u16 {
        self.up_unclamped(z).clamp(0, i32::from(UNBOUNDED)) as u16
    }

    /// [`Self::up`] before its clamp to `UNBOUNDED` (from `2 s` on, and
    /// for a NaN, above it; 0 for `z ≤ 0`, at least 1 for `z > 0`). With
    /// [`Self::up`], the reference the tests hold `up_no_nan` to
    /// (the map's far ends; the fusion's cells keep exact depths since the
    /// twenty-fourth session, [`super::key`]).
    #[cfg(test)]
    pub(crate) fn up_unclamped(&self, z: f32) -> i32 {
        if !(z > 0.0) {
            core::hint::cold_path();
            return if z.is_nan() { i32::MAX } else { 0 };
        }
        let b = (z * self.inv).to_bits();
        let c = (b >> 11) as i32 - CODE_BASE + i32::from(b & 0x7FF != 0);
        c.max(1)
    }

    /// The near code of a map entry: [`Self::down`] of a `z` that is not a
    /// NaN, without the comparison and without the clamp at the top:
    /// `(z/s)`'s bits as a **signed** integer shifted right by 11 are the
    /// positive `z`'s `e · 2¹² + m` as before, and negative for every
    /// negative `z` (`−0.0` and `−∞` included), so the clamp at 0 gives
    /// those code 0, as [`Self::down`]'s test does; `+0.0`'s bits are 0,
    /// below `EXP_BASE · 2¹²`: code 0 too. So the same code as
    /// [`Self::down`] wherever that is below `UNBOUNDED − 1`, and the same
    /// at `UNBOUNDED − 1` itself where the unclamped code is that; past it
    /// (`z/s` at or above `2 − 2⁻¹²`, where [`Self::down`] clamps), the
    /// unclamped code's low 16 bits, a code of no meaning. There a far end
    /// at or above `z` has a far code of at least `UNBOUNDED`
    /// (`up_no_nan`, the tests' form), past every entry's limit, so no entry is
    /// made (an admitted cell's ends are in order, `z_near ≤ z_far`, and
    /// the codes are monotone: [`crate::map`]'s `entry_of`).
    /// `codes_without_their_test_agree` checks both, for every exponent of
    /// either sign.
    ///
    /// For the map's entries, whose ends are never NaN (a cell's ends are a
    /// pair's finite stick, a range's validated ends, their intersections,
    /// and a widened point's `H` and finite `U`, [`super::key`]): about 3
    /// instructions an entry fewer than the test and its branch, and
    /// without the clamp at the top (the `u16`'s cut, which the compiler
    /// also takes for the subtraction of `EXP_BASE · 2¹²`, a multiple of
    /// `2¹⁶`) about 3 more since the twenty-ninth session: the bench's
    /// `partners_1` drive 78.0 → 75.35 instructions a key-frame point.
    ///
    /// (Not the body of [`Self::down`] behind its test: there the unsigned
    /// shift lets the clamp be one unsigned comparison, and the signed one
    /// measured 2 instructions a conflicting point dearer on the bench's
    /// wobbling road, 166 → 168.)
    #[inline(always)]
    pub(crate) fn down_for_entry(&self, z: f32) -> u16 {
        let c = ((z * self.inv).to_bits() as i32 >> 11) - CODE_BASE;
        // (`c` is below `2²¹`: its low 16 bits, no panic.)
        c.max(0) as u16
    }

    /// `up_unclamped` (the tests' reference) at least 1 (a far end's
    /// code, the map's entries) of a `z` that is not a NaN, without the
    /// comparison: as [`Self::down_for_entry`], every `z ≤ 0` (`−0.0`
    /// included) gets a negative code before the clamp to 1, as
    /// `up_unclamped`'s 0 does. The same for every `z` but a NaN
    /// (`codes_without_their_test_agree`). The cut bits' round up as
    /// `⌊(b + 2¹¹ − 1) / 2¹¹⌋`, the bits `b` as a signed integer, which is
    /// `⌈b / 2¹¹⌉` for either sign: for every `z` but a NaN `b + 2¹¹ − 1`
    /// is below `0x7F80_0800`, no overflow (a NaN wraps, no panic). (Until
    /// the twenty-ninth session `⌊b / 2¹¹⌋` plus whether a cut bit was set:
    /// about 2 instructions an entry more, `partners_1` 75.35 → 73.6.) A
    /// NaN is outside the contract either way: one with the sign bit set
    /// got code 1 before and does now, and one whose bits are at least
    /// `0x7FFF_F801` wraps to code 1 now where it got a code past every
    /// limit before; the map's ends are never NaN (`down_for_entry`).
    /// (The tests' form since the thirtieth session: the map's entries
    /// take [`Self::up_no_nan_unclamped`] and clamp after their limit's
    /// comparison.)
    #[cfg(test)]
    pub(crate) fn up_no_nan(&self, z: f32) -> i32 {
        self.up_no_nan_unclamped(z).max(1)
    }

    /// `up_no_nan` (the tests') before its clamp to 1: 0 or negative for `z`
    /// below the smallest far code's depth (`z ≤ 0` included). The map's
    /// entries compare it with their limit first and clamp after
    /// (`map::retire::entry_of`).
    #[inline(always)]
    pub(crate) fn up_no_nan_unclamped(&self, z: f32) -> i32 {
        let b = (z * self.inv).to_bits() as i32;
        (b.wrapping_add(0x7FF) >> 11) - CODE_BASE
    }

    /// `2 s`: from here on a far end's code is [`UNBOUNDED`] (and a near
    /// end's the top one). The fusion's sight check takes a partner that
    /// sees a ray only from here on as seeing none of it
    /// (`super::key::SEEN_NONE`).
    #[inline]
    pub(crate) fn unbounded_from(&self) -> f32 {
        2.0 * self.s
    }

    /// The depth a code stands for (0 for code 0, infinity for
    /// [`UNBOUNDED`]).
    #[inline]
    pub(crate) fn depth(&self, code: u16) -> f32 {
        if code == 0 {
            return 0.0;
        }
        if code == UNBOUNDED {
            return f32::INFINITY;
        }
        self.depth_inner(code)
    }

    /// [`DepthScale::depth`] of a code from 1 to `UNBOUNDED − 1` (a live
    /// map entry's far end), without the tests of the range's two ends:
    /// the same value for those codes.
    #[inline]
    pub(crate) fn depth_inner(&self, code: u16) -> f32 {
        let c = u32::from(code);
        f32::from_bits((((c >> 12) + EXP_BASE) << 23) | ((c & 0xFFF) << 11)) * self.s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;

    #[test]
    fn scale_is_the_next_power_of_two() {
        assert_eq!(DepthScale::for_max_depth(1000.0).scale(), 1024.0);
        assert_eq!(DepthScale::for_max_depth(1024.0).scale(), 1024.0);
        assert_eq!(DepthScale::for_max_depth(0.3).scale(), 0.5);
        assert_eq!(DepthScale::for_max_depth(f32::NAN).scale(), 1024.0);
        assert_eq!(DepthScale::for_max_depth(f32::MAX).scale(), 2f32.powi(120));
    }

    #[test]
    fn codes_round_outwards_and_keep_the_order() {
        let mut g = Rng(0x1234_5678);
        for max_depth in [1000.0f32, 1.0, 3.0e5] {
            let sc = DepthScale::for_max_depth(max_depth);
            let mut prev = (0.0f32, 0u16, 0u16);
            let mut zs: [f32; 4000] = [0.0; 4000];
            for z in zs.iter_mut() {
                // Log-uniform over 30 octaves around the scale.
                *z = sc.scale() * 2f32.powf(g.next() * 30.0 - 25.0);
            }
            zs.sort_by(f32::total_cmp);
            for z in zs {
                let (lo, hi) = (sc.down(z), sc.up(z));
                assert!(sc.depth(lo) <= z && z <= sc.depth(hi), "{z}: {lo} {hi}");
                assert!(lo <= hi);
                // Tight within the range: one code step, 2⁻¹² relative.
                if z >= sc.scale() * 2f32.powi(-15) && z < sc.scale() {
                    assert!(sc.depth(hi) - sc.depth(lo) <= z * 2f32.powi(-11), "{z}");
                }
                // Monotone.
                assert!(z >= prev.0 && lo >= prev.1 && hi >= prev.2);
                prev = (z, lo, hi);
            }
        }
    }

    /// The codes as first written, exponent and mantissa apart, with the
    /// far end's one fix: a positive `z` never codes 0.
    fn reference(sc: &DepthScale, z: f32) -> (u16, u16) {
        // Exponents from `EXP_BASE` to `EXP_BASE + 15`: `z/s` below 2.
        const EXP_SPAN: u32 = 16;
        let down = if !(z > 0.0) {
            0
        } else {
            let b = (z * sc.inv).to_bits();
            let e = b >> 23;
            if e < EXP_BASE {
                0
            } else if e >= EXP_BASE + EXP_SPAN {
                UNBOUNDED - 1
            } else {
                let code = ((e - EXP_BASE) << 12) | ((b >> 11) & 0xFFF);
                code.min(u32::from(UNBOUNDED) - 1) as u16
            }
        };
        let up = if !(z > 0.0) {
            if z.is_nan() {
                UNBOUNDED
            } else {
                0
            }
        } else {
            let b = (z * sc.inv).to_bits();
            let e = b >> 23;
            if e < EXP_BASE {
                1
            } else if e >= EXP_BASE + EXP_SPAN {
                UNBOUNDED
            } else {
                let code =
                    (((e - EXP_BASE) << 12) | ((b >> 11) & 0xFFF)) + u32::from(b & 0x7FF != 0);
                code.clamp(1, u32::from(UNBOUNDED)) as u16
            }
        };
        (down, up)
    }

    /// The clamped codes against [`reference`] for every exponent of
    /// `z/s` (all 256, both signs) with the mantissa's edges and random
    /// mantissas, and NaN, for five scales; and the edge the first codes
    /// got wrong: `2⁻¹⁵ s`, whose far end coded 0 (depth 0).
    #[test]
    fn codes_agree_with_their_definition() {
        let mut g = Rng(0x0C0D_E5ED);
        for max_depth in [1000.0f32, 1.0, 3.0e5, 1e-30, 1e30] {
            let sc = DepthScale::for_max_depth(max_depth);
            for sign in [0u32, 1 << 31] {
                for e in 0..256u32 {
                    let mut ms = [0, 1, 0x7FF, 0x800, 0x7F_F800, 0x7F_FFFF, 0x40_0000, 0];
                    for m in 0..200 {
                        let r = (g.next() * 8_388_608.0) as u32 & 0x7F_FFFF;
                        let m = [r, r & !0x7FF, r | 0x7FF][m % 3];
                        ms[7] = m;
                        for m in ms {
                            let q = f32::from_bits(sign | e << 23 | m);
                            // `z = q·s` (exact but at the ends of the range).
                            let z = q * sc.scale();
                            assert_eq!((sc.down(z), sc.up(z)), reference(&sc, z), "{z:e}");
                            // The unclamped far code (the map's limit
                            // test): the clamped one wherever that is
                            // below `UNBOUNDED`, at or above it (and so
                            // past every far-code limit) where it is not.
                            let (u, raw) = (sc.up(z), sc.up_unclamped(z));
                            if z > 0.0 && u < UNBOUNDED {
                                assert_eq!(raw, i32::from(u), "{z:e}");
                            } else if u == UNBOUNDED {
                                assert!(raw >= i32::from(UNBOUNDED), "{z:e}");
                            }
                        }
                    }
                }
            }
            let edge = sc.scale() * 2f32.powi(-15);
            assert_eq!((sc.down(edge), sc.up(edge)), (0, 1));
            assert!(sc.depth(sc.up(edge)) >= edge);
            let nan = f32::NAN;
            assert_eq!((sc.down(nan), sc.up(nan)), (0, UNBOUNDED));
            assert!(sc.up_unclamped(nan) > i32::from(UNBOUNDED));
            assert_eq!(sc.up_unclamped(-0.0).max(1), 1);
        }
    }

    /// [`DepthScale::down_for_entry`] and `DepthScale::up_no_nan`
    /// against [`DepthScale::down`] and [`DepthScale::up_unclamped`] (at
    /// least 1) for every exponent of either sign, mantissas at the cut's
    /// edges and 64 random ones an exponent, each as it is and times the
    /// scale, over scales from `2⁻¹²⁰` to `2¹²⁰` (about half a million
    /// values): the same codes for everything but a NaN (zeros and
    /// infinities included), but for the near code past the top, where the
    /// far code of the same `z` is past every limit.
    #[test]
    fn codes_without_their_test_agree() {
        let mut g = Rng(0x0C0D_E5EE);
        let (mut checked, mut past_top) = (0u32, 0u32);
        for max_depth in [1000.0f32, 1.0, 3.0e5, 1e-30, 1e30, 1e-36, 1e36] {
            let sc = DepthScale::for_max_depth(max_depth);
            for sign in [0u32, 1 << 31] {
                for e in 0..256u32 {
                    let edges = [0, 1, 0x7FF, 0x800, 0x7F_F800, 0x7F_FFFF, 0x40_0000];
                    let random = (0..64).map(|m| {
                        let r = (g.next() * 8_388_608.0) as u32 & 0x7F_FFFF;
                        [r, r & !0x7FF, r | 0x7FF][m % 3]
                    });
                    for m in edges.into_iter().chain(random) {
                        let q = f32::from_bits(sign | e << 23 | m);
                        for z in [q, q * sc.scale()] {
                            if z.is_nan() {
                                continue;
                            }
                            let (near, down) = (sc.down_for_entry(z), sc.down(z));
                            if down < UNBOUNDED - 1 {
                                assert_eq!(near, down, "{z:e}");
                            } else if near != down {
                                // Past the top: any far end at or above `z`
                                // has a far code past every limit.
                                assert!(sc.up_no_nan(z) >= i32::from(UNBOUNDED), "{z:e}");
                                past_top += 1;
                            }
                            assert_eq!(sc.up_no_nan(z), sc.up_unclamped(z).max(1), "{z:e}");
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert!(checked > 450_000, "{checked}");
        assert!(past_top > 1000, "{past_top}");
    }

    #[test]
    fn ends_of_the_range() {
        let sc = DepthScale::for_max_depth(1000.0);
        assert_eq!(sc.down(0.0), 0);
        assert_eq!(sc.down(-1.0), 0);
        assert_eq!(sc.down(f32::NAN), 0);
        assert_eq!(sc.up(f32::NAN), UNBOUNDED);
        assert_eq!(sc.up(-1.0), 0);
        assert_eq!(sc.up(1e-9), 1);
        assert!(sc.depth(1) >= 1e-9);
        assert_eq!(sc.up(f32::INFINITY), UNBOUNDED);
        assert_eq!(sc.up(2048.0), UNBOUNDED);
        assert_eq!(sc.down(f32::INFINITY), UNBOUNDED - 1);
        assert!(sc.depth(UNBOUNDED - 1) <= 2048.0);
        assert_eq!(sc.depth(UNBOUNDED), f32::INFINITY);
        // Just below 2 s the far end rounds up to unbounded, never wraps.
        assert_eq!(sc.up(2047.9999), UNBOUNDED);
        // Exact codes stay put.
        assert_eq!(sc.down(1.0), sc.up(1.0));
        assert_eq!(sc.depth(sc.down(1.0)), 1.0);
    }
}
