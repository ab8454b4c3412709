//! How many points the work budget flags over the random scenarios, per budget.
use host_tests::{reconstruct, scenarios};
use roadstereo::{Config, Status};
fn main() {
    for budget in [16u32, 24, 40, 64, 100, 160, 250, 400] {
        let (mut over, mut total, mut ok, mut worst) = (0usize, 0usize, 0usize, (0usize, 0u64));
        for seed in 0..300 {
            let s = scenarios::random(seed);
            let r = s.render();
            let cfg = Config::default().with_work_budget(budget).unwrap();
            let p = reconstruct(&r, &s.intrinsics, true, cfg);
            let c = p.structure().status_counts();
            let o = c[Status::OverBudget as usize];
            over += o;
            if o > worst.0 {
                worst = (o, seed);
            }
            ok += c[Status::Ok as usize];
            total += c.iter().sum::<usize>();
        }
        println!("budget {budget:4}: over_budget {over:6} of {total} points ({:.2} %), ok {ok}, worst scenario {} with {}", 100.0 * over as f64 / total as f64, worst.1, worst.0);
    }
}
