//! The indexed crossing search gives exactly the results of the reference
//! matcher, which offers every frame-2 segment to every point's walk.

use host_tests::{frame, scenarios, synth, B, N};
use roadstereo::{Config, Processor, Step};

fn both(s: &synth::Scenario, quantised: bool) {
    let r = s.render();
    let cam = s.intrinsics.camera();
    let f1 = frame(cam, &synth::Rendered::pixels(&r.frame1, quantised));
    let f2 = frame(cam, &synth::Rendered::pixels(&r.frame2, quantised));
    let m = r.motion();
    let mut p = Box::new(Processor::<N, B>::new(Config::DEFAULT));
    assert!(matches!(p.process(&f1, None), Ok(Step::First)));
    let fast = p.process_against_kept(&f2, &m).expect("structure").clone();
    let slow = p.reference_against_kept(&f2, &m).expect("structure");
    assert_eq!(&fast, slow, "{} (quantised: {quantised})", s.name);
}

#[test]
fn indexed_search_equals_reference_on_named_scenarios() {
    let mut all = scenarios::named();
    all.push(scenarios::degenerate());
    for s in &all {
        both(s, false);
        both(s, true);
    }
}

#[test]
fn indexed_search_equals_reference_on_random_scenarios() {
    for seed in 0..300 {
        let s = scenarios::random(seed);
        both(&s, false);
        both(&s, true);
    }
}
