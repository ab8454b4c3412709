//! The key-frame fusion and the road map (issue 13) against ground truth
//! from the independent `f64` generator (`src/drives.rs`): containment over
//! seeded random drives, the narrowing with the number of partner frames,
//! wrong two-view matches caught, the map in the vehicle frame, and bad
//! inputs.

use host_tests::drives::{
    run, tally, Drive, DriveFamily, DriveSpec, HostFusion, MotionNoise, Noise, Run, Tally,
};
use host_tests::synth::{self, Road, Scenario};
use host_tests::{scenarios, B, N};
use roadstereo::fusion::{
    ChainedMotion, FusedStatus, Fusion, FusionConfig, FusionError, KeyReason,
};
use roadstereo::{Config, Frame, Motion, Pixel, Status};

/// Frames per drive (the issue asks for at least 12).
const FRAMES: usize = 14;
/// Drives per family in the containment runs (8 families: 304 drives).
const PER_FAMILY: usize = 38;

/// The first `count` seeds of `family` whose drive sees both boundaries
/// in every frame, rendered; and the seeds skipped.
fn drives(family: DriveFamily, count: usize, frames: usize) -> (Vec<(u64, Drive)>, usize) {
    let (mut out, mut skipped) = (Vec::new(), 0);
    let mut seed = 0u64;
    while out.len() < count {
        match DriveSpec::new(family, seed, frames).render() {
            Some(d) => out.push((seed, d)),
            None => skipped += 1,
        }
        seed += 1;
    }
    (out, skipped)
}

fn pct(a: usize, b: usize) -> String {
    if b == 0 {
        "–".into()
    } else {
        format!("{:.2} %", 100.0 * a as f64 / b as f64)
    }
}

/// Every family's drives through the fusion (default policy) with one
/// detector variant and optional motion errors: per family the tally
/// against the truth, printed as a table; every fused point (two or more
/// agreeing pairs) holds the truth, every wrong two-view stick is caught
/// or harmless, and no two-view stick whose correspondent exists misses.
fn containment(noise: Noise, motion: Option<MotionNoise>, per_family: usize) -> Tally {
    use std::fmt::Write as _;
    let policy = FusionConfig::DEFAULT;
    let mut all = Tally::default();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "\n{} boundaries{}, {FRAMES} frames a drive, default policy (8 partners, 500 ‰):",
        noise.name(),
        motion.map_or(String::new(), |m| format!(
            ", motion off by up to {} per translation component and {:.2}° per axis, bounds configured",
            m.delta,
            m.eps.to_degrees()
        ))
    );
    let _ = writeln!(out, "| family | drives (skipped) | key frames | fused points (≥ 2 pairs) holding the truth | single-pair points holding it | inconsistent | wrong two-view sticks | caught | harmless | wrong single | wrong fused |");
    let _ = writeln!(
        out,
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for family in DriveFamily::ALL {
        let (ds, skipped) = drives(family, per_family, FRAMES);
        let mut t = Tally::default();
        for (seed, d) in &ds {
            let input = d.input(noise, motion, *seed);
            let r = run(d, &input, policy, |_, _| {});
            t.add(&tally(d, &r));
        }
        let _ = writeln!(
            out,
            "| {} | {} ({skipped}) | {} | {} / {} ({}) | {} / {} ({}) | {} | {} | {} | {} | {} | {} |",
            family.name(),
            t.drives,
            t.key_frames,
            t.consistent_contained,
            t.consistent,
            pct(t.consistent_contained, t.consistent),
            t.single_contained,
            t.single,
            pct(t.single_contained, t.single),
            t.inconsistent,
            t.wrong_pairs,
            t.caught,
            t.harmless,
            t.wrong_single,
            t.wrong_fused
        );
        all.add(&t);
    }
    let _ = writeln!(
        out,
        "all: {} drives, {} of {} fused point snapshots hold the truth; {} wrong two-view sticks ({} with a correspondent): {} caught, {} harmless, {} single, {} wrong fused",
        all.drives,
        all.consistent_contained,
        all.consistent,
        all.wrong_pairs,
        all.wrong_pairs_observed,
        all.caught,
        all.harmless,
        all.wrong_single,
        all.wrong_fused
    );
    print!("{out}");
    assert!(all.drives >= 300 || per_family < PER_FAMILY);
    assert_eq!(
        all.consistent_contained, all.consistent,
        "a fused interval misses the truth"
    );
    assert_eq!(all.wrong_fused, 0);
    assert_eq!(
        all.wrong_pairs_observed, 0,
        "a two-view stick with a correspondent misses"
    );
    assert!(all.consistent > 100_000 / if motion.is_some() { 10 } else { 1 });
    all
}

#[test]
fn containment_rounded() {
    containment(Noise::Rounded, None, PER_FAMILY);
}

#[test]
fn containment_disc_noise() {
    containment(Noise::Disc, None, PER_FAMILY);
}

#[test]
fn containment_with_motion_errors() {
    // About 2.5 % of a frame's travel per translation component, 0.1° per
    // axis: the composed bounds keep every fused interval guaranteed.
    let m = MotionNoise {
        delta: 0.01,
        eps: 0.1f64.to_radians(),
    };
    containment(Noise::Rounded, Some(m), PER_FAMILY);
}

/// The S-bend built to make frames see disjoint stretches of a boundary:
/// the left edge bends out of view on the left (curvature −1/10.5) and back
/// in far ahead (+1/10.5 from 4.7 on), seen by a high camera (h = 1.5, tilt
/// 19°); the vehicle moves 0.34 forward and 0.05 to the left while turning
/// 2.9° left, in nine frames a quarter of that apart. The key frame sees
/// only the edge's far stretch, beyond the bend; frames 5 and 6 only its
/// near stretch, entering at the bottom; frames 7 and 8 both again. The key
/// frame's epipolar lines meet the near stretch at points consistent with
/// both images: wrong two-view matches, which the earlier partners'
/// intervals contradict.
fn disjoint_stretch_drive() -> Drive {
    let k = 0.095;
    let road = Road {
        width: 1.4,
        curvature_a: -k,
        curvature_b: k,
        switch_at: 4.7,
        ..Road::straight(1.4)
    };
    let mut s = Scenario::new(
        "disjoint_stretches",
        road,
        synth::Drive {
            forward: 0.34,
            lateral: -0.05,
            yaw: (-2.9f64).to_radians(),
            ..Default::default()
        },
    );
    s.height = 1.5;
    s.tilt = 19f64.to_radians();
    let fractions: Vec<f64> = (0..=8).map(|i| f64::from(i) * 0.25).collect();
    Drive::through_scenario(&s, &fractions).expect("both edges in view")
}

fn wrong_match_report(name: &str, t: &Tally) {
    println!(
        "{name}: {} wrong two-view sticks ({} with a correspondent in the partner frame): {} flagged inconsistent, {} harmless (the fused interval still holds the truth), {} single, {} wrong fused; {} fused snapshots hold the truth of {}",
        t.wrong_pairs,
        t.wrong_pairs_observed,
        t.caught,
        t.harmless,
        t.wrong_single,
        t.wrong_fused,
        t.consistent_contained,
        t.consistent
    );
}

#[test]
fn wrong_matches_on_disjoint_stretches_are_flagged() {
    let d = disjoint_stretch_drive();
    let policy = FusionConfig::new(8, 0).expect("policy");
    let mut all = Tally::default();
    for (v, noise) in [Noise::Rounded, Noise::Disc].into_iter().enumerate() {
        let input = d.input(noise, None, v as u64);
        let r = run(&d, &input, policy, |_, _| {});
        let t = tally(&d, &r);
        wrong_match_report(&format!("built on purpose, {}", noise.name()), &t);
        all.add(&t);
    }
    // The scenario does what it is built for.
    assert!(all.wrong_pairs >= 10, "{all:?}");
    assert_eq!(all.wrong_pairs, all.caught + all.harmless, "{all:?}");
    assert_eq!(all.consistent, all.consistent_contained);
}

/// Today's wrong two-view points of the 1000 random scenarios (points
/// `ok` whose correspondent is not in frame 2 and whose stick misses the
/// truth), each scenario driven through with three frames between its
/// two (a quarter of the motion apart), the first frame the key frame:
/// every one is flagged.
#[test]
fn wrong_matches_of_the_random_scenarios_are_flagged() {
    let mut seeds = Vec::new();
    let mut two_view_wrong = 0;
    for seed in 0..1000 {
        let s = scenarios::random(seed);
        let r = s.render();
        if r.frame1.is_empty() {
            continue;
        }
        let p = host_tests::reconstruct(&r, &s.intrinsics, true, Config::default());
        let wrong = host_tests::point_stats(&r, &s.intrinsics, &p)
            .iter()
            .filter(|st| st.status == Status::Ok && !st.observed && !st.contained())
            .count();
        if wrong > 0 {
            seeds.push(seed);
            two_view_wrong += wrong;
        }
    }
    println!(
        "the 1000 random scenarios: {two_view_wrong} wrong two-view points in scenarios {seeds:?}"
    );
    assert!(two_view_wrong > 0);
    let policy = FusionConfig::new(8, 0).expect("policy");
    let mut all = Tally::default();
    for seed in seeds {
        let s = scenarios::random(seed);
        let d = Drive::through_scenario(&s, &[0.0, 0.25, 0.5, 0.75, 1.0]).expect("drive");
        let input = d.input(Noise::Rounded, None, seed);
        let r = run(&d, &input, policy, |_, _| {});
        all.add(&tally(&d, &r));
    }
    wrong_match_report("random scenarios, driven through", &all);
    assert!(all.wrong_pairs >= two_view_wrong);
    assert_eq!(all.wrong_pairs, all.caught, "{all:?}");
    assert_eq!(all.consistent, all.consistent_contained);
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Widths of the first key frame's points after 1, 2, 4, 8 partners.
#[derive(Default)]
struct Narrowing {
    /// Relative widths `(z_far − z_near)/z_true` at each partner count, of
    /// the points with an unflagged interval after the first partner.
    widths: [Vec<f64>; 4],
    /// Per point, width after 1 over width after n.
    ratios: [Vec<f64>; 4],
    population: usize,
    /// Of the population, the points the 8th partner still matched.
    matched_at_8: usize,
    /// Per point, width after 1 over width after 8, for the points the 8th
    /// partner matched and for the others.
    kept: Vec<f64>,
    lost: Vec<f64>,
}

const COUNTS: [usize; 4] = [1, 2, 4, 8];

impl Narrowing {
    fn add(&mut self, d: &Drive, r: &Run) {
        let Some(rec) = r.keys.first() else { return };
        let Some(first) = rec.fused.first() else {
            return;
        };
        for (b, pts) in first.iter().enumerate() {
            for (i, p0) in pts.iter().enumerate() {
                let Some(iv0) = p0.interval.filter(|_| !p0.status.is_flagged()) else {
                    continue;
                };
                let z = d.z_true(rec.key, b, i);
                let w0 = f64::from(iv0.z_far - iv0.z_near) / z;
                self.population += 1;
                let matched = rec
                    .pairs
                    .get(7)
                    .is_some_and(|p| p[b][i].status == Status::Ok);
                self.matched_at_8 += usize::from(matched);
                for (slot, &n) in COUNTS.iter().enumerate() {
                    let Some(p) = rec.fused.get(n - 1).map(|s| s[b][i]) else {
                        continue;
                    };
                    let Some(iv) = p.interval.filter(|_| !p.status.is_flagged()) else {
                        continue;
                    };
                    let w = f64::from(iv.z_far - iv.z_near) / z;
                    self.widths[slot].push(w);
                    self.ratios[slot].push(w0 / w);
                    if n == 8 {
                        if matched {
                            self.kept.push(w0 / w);
                        } else {
                            self.lost.push(w0 / w);
                        }
                    }
                }
            }
        }
    }

    fn row(&self, name: &str) -> (String, f64) {
        let m: Vec<f64> = self.widths.iter().map(|w| median(w.clone())).collect();
        let gain = m[0] / m[3];
        (
            format!(
                "| {name} | {} | {:.3} | {:.3} ({:.2}×) | {:.3} ({:.2}×) | {:.3} (**{:.2}×**) | {:.2}× | {:.0} % | {:.2}× | {:.2}× |",
                self.population,
                m[0],
                m[1],
                m[0] / m[1],
                m[2],
                m[0] / m[2],
                m[3],
                gain,
                median(self.ratios[3].clone()),
                100.0 * self.matched_at_8 as f64 / self.population.max(1) as f64,
                median(self.kept.clone()),
                median(self.lost.clone())
            ),
            gain,
        )
    }
}

/// The paper's Fig. 6 set-up as a drive: the camera of Sec. 3 (h = 1, tilt
/// 23°, f = 800), the right curve of radius 15 and width 1.3, 0.4 forward
/// a frame along it, the heading leading the road's by the turn over 1.5
/// and wobbling ±2°.
fn fig6_drive(frames: usize) -> Drive {
    let mut s = DriveSpec::new(DriveFamily::Fig6, 0, frames);
    s.name = "fig6 (r = 15, 0.4 a frame)".into();
    s.road = Road {
        curvature_a: 1.0 / 15.0,
        curvature_b: 1.0 / 15.0,
        ..Road::straight(1.3)
    };
    s.step = 0.4;
    s.yaw_bias = 1.5 / 15.0;
    s.render().expect("both edges in view")
}

/// The narrowing table: the median relative width of the first key frame's
/// fused intervals after 1, 2, 4 and 8 partner frames (the policy keeps it
/// for 8), over the points with an interval after the first; the goal is
/// 3× narrower after 8 on the Fig. 6 set-up and on the random drives.
#[test]
fn fused_intervals_narrow_with_the_partners() {
    let policy = FusionConfig::new(8, 0).expect("policy");
    let mut lines = vec![
        "| drives | points | after 1 | after 2 | after 4 | after 8 | per point, median | still matched by the 8th | per point, those | per point, the others |".to_string(),
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|".to_string(),
    ];
    let fig6 = fig6_drive(FRAMES);
    let mut n = Narrowing::default();
    for v in 0..4u64 {
        let input = fig6.input(
            if v % 2 == 0 {
                Noise::Rounded
            } else {
                Noise::Disc
            },
            None,
            v,
        );
        n.add(&fig6, &run(&fig6, &input, policy, |_, _| {}));
    }
    let (row, fig6_gain) = n.row("Fig. 6 set-up (4 noise draws)");
    lines.push(row);
    let mut pooled = Narrowing::default();
    let mut gains = Vec::new();
    for family in DriveFamily::ALL {
        let (ds, _) = drives(family, 20, FRAMES);
        let mut n = Narrowing::default();
        for (seed, d) in &ds {
            let input = d.input(Noise::Rounded, None, *seed);
            let r = run(d, &input, policy, |_, _| {});
            n.add(d, &r);
            pooled.add(d, &r);
        }
        let (row, gain) = n.row(&format!("{} (20)", family.name()));
        lines.push(row);
        gains.push((family.name(), gain));
    }
    let (row, pooled_gain) = pooled.row("all random drives (160)");
    lines.push(row);
    println!("{}", lines.join("\n"));
    assert!(fig6_gain >= 3.0, "Fig. 6: {fig6_gain:.2}×");
    assert!(pooled_gain >= 3.0, "random drives: {pooled_gain:.2}×");
    for (name, g) in gains {
        assert!(g >= 2.5, "{name}: {g:.2}×");
    }
}
