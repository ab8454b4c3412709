//! The search index's work as a boundary grows denser, where it is a
//! weakness of the index and not of the method (issue 11's scaling budget:
//! the per-point cost at N = 512 within 1.25 times that at N = 64 on the
//! adversarial family; `cargo xtask bench` measures the instructions, here
//! the work units, the same on every machine).
//!
//! `fwd_spiral` (log spirals about an FOE in the image, spurious points in
//! both frames): a spurious frame-1 point out past the FOE and back makes
//! two segments of about half a turn on the fold test's pseudo-angle keys.
//! From N = 256 on their two half turns were unwrapped the same way round,
//! the rest of the boundary's keys a turn below the first part's, the
//! index loose and its orientation reversed, and each fold query ran the
//! boundary: 29 915 units at N = 512 against 1 464 at N = 64 (2.55 times
//! a point). The fold test's index now takes the turn back
//! (`Index::turns_back` in `src/search/build.rs`): 1.16 times.

use host_tests::drive::adversarial::{family, library_pair, render};
use roadstereo::Processor;

/// Work units a point for a member's frame pair at `n` points a boundary.
fn units_per_point(name: &str, n: usize) -> f64 {
    let m = family()
        .into_iter()
        .find(|m| m.name == name)
        .expect("member");
    let (k, frames) = render(&m.params, n).expect("renders");
    let (f1, f2, motion) = library_pair(&k, &frames);
    let mut p = Box::new(Processor::<512, 2>::new(m.errors.config()));
    p.process(&f1, None).expect("frame 1");
    p.process(&f2, Some(&motion)).expect("frame 2");
    let s = p.structure();
    let points: usize = s.boundaries().iter().map(|b| b.points().len()).sum();
    f64::from(s.work_units().0) / points as f64
}

#[test]
fn a_spurious_points_half_turns_do_not_make_the_fold_test_walk_the_boundary() {
    let (small, large) = (
        units_per_point("fwd_spiral", 64),
        units_per_point("fwd_spiral", 512),
    );
    let ratio = large / small;
    println!("fwd_spiral: {small:.1} units a point at N = 64, {large:.1} at N = 512 ({ratio:.2}x)");
    assert!(ratio <= 1.25, "{small} -> {large}: {ratio:.2}x");
}
