//! The narrowing of the fused intervals with the number of partner frames.

use super::containment::wrong_match_report;
use super::*;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Widths of the first key frame's points after 1, 2, 4, 8 partners.
#[derive(Default)]
pub(super) struct Narrowing {
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
    pub(super) fn add(&mut self, d: &Drive, r: &Run) {
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

    pub(super) fn row(&self, name: &str) -> (String, f64) {
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
        n.add(&fig6, &run(&fig6, &input, policy, |_, _, _| {}));
    }
    let (row, fig6_gain) = n.row("Fig. 6 set-up (4 noise draws)");
    lines.push(row);
    let mut pooled = Narrowing::default();
    let mut gains = Vec::new();
    let mut wrong = Tally::default();
    for family in DriveFamily::ALL {
        let (ds, _) = drives(family, 20, FRAMES);
        let mut n = Narrowing::default();
        for (seed, d) in &ds {
            let input = d.input(Noise::Rounded, None, *seed);
            let r = run(d, &input, policy, |_, _, _| {});
            n.add(d, &r);
            pooled.add(d, &r);
            wrong.add(&tally(d, &r));
        }
        let (row, gain) = n.row(&format!("{} (20)", family.name()));
        lines.push(row);
        gains.push((family.name(), gain));
    }
    let (row, pooled_gain) = pooled.row("all random drives (160)");
    lines.push(row);
    println!("{}", lines.join("\n"));
    // Key frames kept for 8 partners see more wrong two-view matches (their
    // later partners see less of the key frame's stretch).
    wrong_match_report("the 160 random drives, 8 partners a key frame", &wrong);
    assert_eq!(wrong.consistent, wrong.consistent_contained);
    assert_eq!(wrong.wrong_fused, 0);
    assert!(fig6_gain >= 3.0, "Fig. 6: {fig6_gain:.2}×");
    assert!(pooled_gain >= 3.0, "random drives: {pooled_gain:.2}×");
    for (name, g) in gains {
        assert!(g >= 2.5, "{name}: {g:.2}×");
    }
}
