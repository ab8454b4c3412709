use host_tests::{frame, scenarios, synth, B, N};
use roadstereo::{Config, Motion, Processor, Status, Step};
fn main() {
    let mut tot = [0u32; 13];
    let mode = std::env::args().nth(1).unwrap_or("t".into());
    for seed in 0..60u64 {
        let s = scenarios::random(seed);
        let r = s.render();
        let cam = s.intrinsics.camera();
        let m = r.motion();
        let t = m.translation();
        let travel = t.iter().map(|x| x * x).sum::<f32>().sqrt();
        let (mu, config) = if mode == "t" {
            let delta = 0.05 * travel;
            let mut g = synth::Rng(seed ^ 0xA5A5);
            let used = t.map(|x| x + (g.uniform(-1.0, 1.0) as f32) * delta);
            (
                Motion::new(used, m.angles()).unwrap(),
                Config::default()
                    .with_translation_error(delta)
                    .unwrap()
                    .with_work_budget(
                        std::env::var("WB")
                            .ok()
                            .and_then(|s| s.parse().ok())
                            .unwrap_or(40),
                    )
                    .unwrap(),
            )
        } else if mode == "r" {
            let eps = 0.3f32.to_radians();
            let mut g = synth::Rng(seed ^ 0x5A5A);
            let a = m.angles();
            let used = [0, 1, 2].map(|i| a[i] + (g.uniform(-1.0, 1.0) as f32) * eps);
            (
                Motion::new(m.translation(), used).unwrap(),
                Config::default()
                    .with_rotation_error([eps; 3])
                    .unwrap()
                    .with_work_budget(
                        std::env::var("WB")
                            .ok()
                            .and_then(|s| s.parse().ok())
                            .unwrap_or(40),
                    )
                    .unwrap(),
            )
        } else {
            (m, Config::default())
        };
        let f1 = frame(cam, &synth::Rendered::pixels(&r.frame1, true));
        let f2 = frame(cam, &synth::Rendered::pixels(&r.frame2, true));
        let mut p = Box::new(Processor::<N, B>::new(config));
        assert!(matches!(p.process(&f1, None), Ok(Step::First)));
        let st = p.process_against_kept(&f2, &mu).unwrap();
        for (t, c) in tot.iter_mut().zip(st.status_counts().iter()) {
            *t += *c as u32;
        }
    }
    for (c, s) in tot.iter().zip(Status::ALL) {
        if *c > 0 {
            print!("{}={} ", s.name(), c);
        }
    }
    println!();
}
