//! The indexed crossing search gives exactly the brute-force results.

use host_tests::{frame, scenarios, synth, BruteForce, B, N};
use roadstereo::{Config, Processor, Step};

fn both(s: &synth::Scenario, quantised: bool) {
    let r = s.render();
    let cam = s.intrinsics.camera();
    let f1 = frame(cam, &synth::Rendered::pixels(&r.frame1, quantised));
    let f2 = frame(cam, &synth::Rendered::pixels(&r.frame2, quantised));
    let m = r.motion();
    let mut fast = Box::new(Processor::<N, B>::new(Config::default()));
    let mut slow = Box::new(Processor::<N, B>::new(Config::default()));
    assert!(matches!(fast.process(&f1, None), Ok(Step::First)));
    assert_eq!(slow.process_with(&f1, None, &mut BruteForce), Ok(true));
    assert!(matches!(
        fast.process(&f2, Some(&m)),
        Ok(Step::Structure(_))
    ));
    assert_eq!(slow.process_with(&f2, Some(&m), &mut BruteForce), Ok(false));
    assert_eq!(
        fast.structure(),
        slow.structure(),
        "{} (quantised: {quantised})",
        s.name
    );
}

#[test]
fn indexed_search_equals_brute_force_on_named_scenarios() {
    let mut all = scenarios::named();
    all.push(scenarios::degenerate());
    for s in &all {
        both(s, false);
        both(s, true);
    }
}

#[test]
fn indexed_search_equals_brute_force_on_random_scenarios() {
    for seed in 0..300 {
        let s = scenarios::random(seed);
        both(&s, false);
        both(&s, true);
    }
}
