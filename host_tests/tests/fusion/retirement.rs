//! A retiring key frame's points entering the map over two steps: the same map as a whole retirement, the share, conflicts and rests.

use super::*;

/// What a lockstep run of a split and a whole retirement counted
/// ([`lockstep_split_and_whole`]).
#[derive(Default)]
struct Lockstep {
    /// Retirements cut at their share, and those of them at a motion or
    /// error limit (a step without a pair).
    split: u32,
    split_at_limit: u32,
    /// Rests a range constraint between the two steps entered.
    constrained: u32,
    steps: u32,
}

/// One drive through two fusions in lockstep, one retiring whole (share
/// 1000 ‰), one at a share of 30 ‰, with the motion `motion(j, key)` for
/// frame `j` (`key`: the whole one's key frame, [`Fusion::key_id`]): the
/// same steps, each retirement's counts adding up across its two steps,
/// the map between them holding the points entered so far, and after the
/// next step (or a range constraint in between) the same fusion (its key
/// frame, map and counters: the digest).
fn lockstep_split_and_whole(
    d: &Drive,
    seed: u64,
    mut motion: impl FnMut(usize, Option<u32>) -> Option<ChainedMotion>,
    c: &mut Lockstep,
) {
    let input = d.input(Noise::Disc, None, seed);
    let policy = FusionConfig::DEFAULT
        .with_tilt(d.spec.tilt as f32)
        .expect("tilt");
    let whole_policy = policy.with_retirement_share(1000).expect("share");
    let mut whole = Box::new(HostFusion::new(input.config(), whole_policy));
    let mut parts = Box::new(HostFusion::new(
        input.config(),
        policy.with_retirement_share(30).expect("share"),
    ));
    let mut pending: Option<roadstereo::map::Retired> = None;
    for j in 0..d.frames.len() {
        let frame = input.frame(&d.spec.intrinsics, j);
        let m = motion(j, whole.key_id());
        let a = whole.step(j as u32, &frame, m.as_ref()).expect("step");
        let b = parts.step(j as u32, &frame, m.as_ref()).expect("step");
        c.steps += 1;
        assert_eq!(a.paired, b.paired, "{} frame {j}", d.spec.name);
        assert_eq!(a.new_key, b.new_key);
        assert!(a.finished.is_none() && a.retired.is_none_or(|r| r.pending == 0));
        // The rest of the last step's retirement, and what it added up to.
        match (pending.take(), b.finished) {
            (None, None) => {}
            (Some(p), Some(f)) => {
                assert_eq!(f.key, p.key);
                assert_eq!(f.entered + f.unbounded + f.unfit, p.pending, "{f:?} {p:?}");
            }
            (p, f) => panic!("{} frame {j}: pending {p:?}, finished {f:?}", d.spec.name),
        }
        match (a.retired, b.retired) {
            (None, None) => {}
            (Some(w), Some(r)) if r.pending == 0 => assert_eq!(w, r),
            (Some(w), Some(r)) => {
                c.split += 1;
                if b.paired.is_none() {
                    c.split_at_limit += 1;
                }
                assert_eq!((w.key, w.dropped), (r.key, r.dropped));
                assert_eq!(
                    (w.unverified, w.inconsistent),
                    (r.unverified, r.inconsistent)
                );
                assert!(r.entered < w.entered, "{w:?} {r:?}");
                assert_eq!(
                    w.entered + w.unbounded + w.unfit,
                    r.entered + r.unbounded + r.unfit + r.pending
                );
                let held: usize = (0..B).map(|k| parts.map().len(k)).sum();
                let all: usize = (0..B).map(|k| whole.map().len(k)).sum();
                assert_eq!(held + (w.entered - r.entered) as usize, all);
                pending = Some(r);
                // Now and then a range constraint (a wide one, on the new
                // key frame's first point, on both) enters the rest before
                // the next step.
                if c.split.is_multiple_of(3) {
                    let (ka, kb) = (whole.key_ref(), parts.key_ref());
                    if let (Some(ka), Some(kb)) = (ka, kb) {
                        let x = whole.constrain(ka, 0, 0, 0.0, 1.0e4);
                        let y = parts.constrain(kb, 0, 0, 0.0, 1.0e4);
                        assert_eq!(x, y);
                        if y.is_ok() {
                            c.constrained += 1;
                            assert_eq!(whole.digest(), parts.digest());
                        }
                    }
                }
                continue;
            }
            (w, r) => panic!("{} frame {j}: {w:?} against {r:?}", d.spec.name),
        }
        assert_eq!(whole.digest(), parts.digest(), "{} frame {j}", d.spec.name);
    }
}

/// A retirement cut at its share ([`FusionConfig::with_retirement_share`])
/// enters the rest at the start of the next step: after that step the
/// fusion is the one a whole retirement leaves, and the counts add up
/// ([`lockstep_split_and_whole`]). Also with a range constraint between
/// the two steps, which enters the rest then.
#[test]
fn a_retirement_over_two_steps_leaves_the_whole_ones_map() {
    let mut c = Lockstep::default();
    for family in DriveFamily::ALL {
        let (ds, _) = drives(family, 3, 24);
        for (seed, d) in &ds {
            let given = d.input(Noise::Disc, None, *seed).given;
            lockstep_split_and_whole(d, *seed, |j, _| given_into(&given, j), &mut c);
        }
    }
    println!(
        "retirement over two steps: {} of the retirements split, {} finished by a range constraint, {} steps equal to a whole retirement's after the next",
        c.split, c.constrained, c.steps
    );
    assert!(
        c.split > 20 && c.constrained > 2,
        "{} {}",
        c.split,
        c.constrained
    );
}

/// The inverse of motion `m` (`Rᵀ`, `−Rᵀ T`; its angles recovered in
/// `f64` in the convention of [`Motion::new`], `R = R_y(β) R_x(α)
/// R_z(γ)`).
fn inverse(m: &Motion) -> Motion {
    let r = m.rotation_matrix();
    let t = m.translation();
    // Rᵀ's entries: rt[i][j] = r[j][i].
    let rt = |i: usize, j: usize| f64::from(r[j][i]);
    let alpha = (-rt(1, 2)).asin();
    let beta = rt(0, 2).atan2(rt(2, 2));
    let gamma = rt(1, 0).atan2(rt(1, 1));
    let mut back = [0.0f32; 3];
    for (i, b) in back.iter_mut().enumerate() {
        *b = -(0..3).map(|k| rt(i, k) * f64::from(t[k])).sum::<f64>() as f32;
    }
    Motion::new(back, [alpha as f32, beta as f32, gamma as f32]).expect("inverse")
}

/// A retirement at a motion limit (a step without a pair: the motion from
/// the key frame composes to no translation) is cut at the share too, its
/// rest entered at the start of the next step, and leaves the whole
/// one's fusion after it ([`lockstep_split_and_whole`]). Every fifth
/// frame comes back to the key frame (the inverse of the drive's motions
/// since it), then the drive goes on from there (the next motion is the
/// drive's own, from the frame that came back, the new key frame).
#[test]
fn a_retirement_at_a_motion_limit_over_two_steps_leaves_the_whole_ones_map() {
    let mut c = Lockstep::default();
    let mut limits = 0u32;
    for family in DriveFamily::ALL {
        let (ds, _) = drives(family, 2, 24);
        for (seed, d) in &ds {
            let given = d.input(Noise::Disc, None, *seed).given;
            lockstep_split_and_whole(
                d,
                *seed,
                |j, key| {
                    let own = given_into(&given, j);
                    let Some(key) = key.map(|k| k as usize).filter(|&k| k + 1 < j) else {
                        return own;
                    };
                    if !j.is_multiple_of(5) {
                        return own;
                    }
                    // The chain from the key frame to frame j − 1, undone.
                    let mut chain = given[key];
                    for g in &given[key + 1..j - 1] {
                        chain = chain.then(g).expect("composed");
                    }
                    limits += 1;
                    Some(ChainedMotion {
                        from: j as u32 - 1,
                        motion: inverse(&chain),
                    })
                },
                &mut c,
            );
        }
    }
    println!(
        "retirement at a motion limit over two steps: {} of {limits} limits split ({} retirements split in all), {} finished by a range constraint, {} steps",
        c.split_at_limit, c.split, c.constrained, c.steps
    );
    assert!(c.split_at_limit > 10, "{} of {limits}", c.split_at_limit);
}

/// A road whose edges, all but their `still` nearest points of `n` a
/// boundary, are moved `offset` across (`f64`; the paper's camera at
/// height 1.2 over a flat road, its rows 250–478, the camera at `x` across,
/// looking along the road).
fn moved_road_frame(x: f64, offset: f64, n: usize, still: usize) -> Frame<N, B> {
    let cam = synth::Intrinsics::default().camera();
    let mut f = Frame::new(cam);
    for edge in [-0.6f64, 0.6] {
        let pts: Vec<Pixel> = (0..n)
            .filter_map(|i| {
                let v = 250.0 + 228.0 * i as f64 / (n - 1) as f64;
                let z = 800.0 * 1.2 / (v - 239.5);
                let e = if i < n - still { edge + offset } else { edge };
                let u = 255.5 + 800.0 * (e - x) / z;
                (0.0..=511.0)
                    .contains(&u)
                    .then(|| Pixel::new(u as f32, v as f32))
            })
            .collect();
        f.push_boundary(&pts).expect("valid");
    }
    f
}

/// A retiring step whose pass conflicts enters fewer points (the share
/// less half the conflicts, `RoadMap::retire`), and the rest no more than
/// the share leaves without the cut (a conflicting point is not admitted):
/// the bench's `jumping` drive (0.08 a frame sideways, both edges but
/// their 22 nearest points jumping by a table within each 8 frames, the
/// pairs disagreeing), in lockstep with the same fusion retiring whole
/// (1000 ‰, which the conflicts do not cut): the same steps, the counts
/// adding up across the two steps, and after the next step the same
/// fusion (the digest).
#[test]
fn a_retiring_step_whose_pass_conflicts_enters_less_and_the_rest_next() {
    const OFFSETS: [f64; 8] = [0.0, 0.12, 0.12, 0.0, 0.12, -0.2455, -0.12, 0.24];
    let mut whole = Box::new(HostFusion::new(
        Config::DEFAULT,
        FusionConfig::DEFAULT
            .with_retirement_share(1000)
            .expect("share"),
    ));
    let mut parts = Box::new(HostFusion::new(Config::DEFAULT, FusionConfig::DEFAULT));
    let permille = FusionConfig::DEFAULT.retirement_share();
    let (mut x, mut dir) = (0.0f64, 1.0f64);
    let (mut cut, mut all_next, mut pending) = (0u32, 0u32, None);
    for j in 0..48u32 {
        let m = (j > 0).then(|| {
            x += 0.08 * dir;
            ChainedMotion {
                from: j - 1,
                motion: Motion::new([(0.08 * dir) as f32, 0.0, 0.0], [0.0; 3]).expect("motion"),
            }
        });
        if j > 0 && j % 8 == 0 {
            dir = -dir;
        }
        let frame = moved_road_frame(x, OFFSETS[j as usize % 8], 256, 22);
        let a = whole.step(j, &frame, m.as_ref()).expect("step");
        let b = parts.step(j, &frame, m.as_ref()).expect("step");
        assert_eq!((a.paired, a.new_key), (b.paired, b.new_key), "frame {j}");
        if let Some(p) = pending.take() {
            let (p, rest_bound): (roadstereo::map::Retired, u32) = p;
            let f = b.finished.expect("the rest of the retirement");
            assert_eq!(f.entered + f.unbounded + f.unfit, p.pending);
            assert!(p.pending <= rest_bound, "{p:?}: {rest_bound}");
            assert_eq!(whole.digest(), parts.digest(), "frame {j}");
        }
        let (Some(w), Some(r)) = (a.retired, b.retired) else {
            assert_eq!(a.retired, b.retired);
            continue;
        };
        let conflicts = b.paired.map_or(0, |p| p.conflicts);
        // The key frame that retired: `key` shows its final state.
        let total: u32 = (0..B)
            .map(|k| parts.key().map_or(0, |kf| kf.len(k)) as u32)
            .sum();
        let share = (total * u32::from(permille)).div_ceil(1000);
        let looked = r.entered + r.unbounded;
        assert!(
            looked <= share.saturating_sub(conflicts.div_ceil(2)),
            "frame {j}: {r:?}, {conflicts} conflicts, share {share}"
        );
        assert_eq!(
            w.entered + w.unbounded + w.unfit,
            r.entered + r.unbounded + r.unfit + r.pending
        );
        if conflicts > 0 && r.pending > 0 {
            cut += 1;
            all_next += u32::from(looked == 0);
        }
        pending = (r.pending > 0).then_some((r, total - share));
    }
    println!("retirements cut by their pass's conflicts: {cut} ({all_next} with every entry in the next step)");
    assert!(cut >= 3, "{cut}");
}

/// A retirement looks at no more of the key frame's points than its share
/// (entered or left out as unbounded), whatever their order: here the
/// first points of the boundary have ranges past the depth codes (left
/// out), the rest are bounded by the pairs. A review found the share
/// passed by as many points as were left out before the entries (the
/// count of looked-at points was checked only where one was left out).
#[test]
fn a_retirement_looks_at_no_more_than_its_share() {
    let cam = synth::Intrinsics::default().camera();
    // A ground edge from far to near, its first `far` points near the
    // horizon (no pair bounds them: only a range fuses them).
    let edge = |n: f32, far: usize| {
        let mut f = Frame::<N, B>::new(cam);
        let pts: Vec<Pixel> = (0..40)
            .map(|i| {
                let z = if i < far {
                    4000.0 - 200.0 * i as f32
                } else {
                    16.75 - 0.25 * (i - far) as f32
                } - 0.25 * n;
                Pixel::new(255.5 - 800.0 * (1.0 + 0.05 * n) / z, 239.5 + 800.0 / z)
            })
            .collect();
        f.push_boundary(&pts).expect("valid");
        f
    };
    let step = Motion::new([0.05, 0.0, 0.25], [0.0; 3]).expect("motion");
    for (share, left_out) in [(100, 3), (200, 6), (300, 10), (500, 12), (1000, 5)] {
        let edge = |n: f32| edge(n, left_out);
        let policy = FusionConfig::new(2, 0)
            .and_then(|p| p.with_map_min_pairs(1))
            .and_then(|p| p.with_retirement_share(share))
            .expect("policy");
        let mut f = Box::new(HostFusion::new(Config::DEFAULT, policy));
        f.step(0, &edge(0.0), None).expect("key");
        let key = f.key_ref().expect("key");
        for i in 0..left_out {
            f.constrain(key, 0, i, 1.0, 1.0e30).expect("a valid range");
        }
        let total = f.key().expect("key").len(0) as u32;
        let allowed = (total * u32::from(share)).div_ceil(1000);
        let (mut looked, mut rest, mut retired) = (0, 0, 0);
        for id in 1..=3u32 {
            let m = ChainedMotion {
                from: id - 1,
                motion: step,
            };
            let s = f.step(id, &edge(id as f32), Some(&m)).expect("step");
            if let Some(r) = s.retired {
                retired += 1;
                looked = r.entered + r.unbounded;
                assert!(looked <= allowed, "share {share}: {r:?}, {allowed} allowed");
                assert_eq!(r.unbounded, left_out.min(allowed as usize) as u32, "{r:?}");
                rest = r.pending;
            }
            if let Some(r) = s.finished {
                assert_eq!(r.entered + r.unbounded + r.unfit, rest, "{r:?}");
                rest = 0;
            }
        }
        assert_eq!(retired, 1, "share {share}");
        assert_eq!(rest, 0, "share {share}: the rest entered");
        if share < 1000 {
            assert_eq!(looked, allowed, "share {share}: the whole share used");
        }
    }
}

/// Found by a review of the retirement over two steps: a retirement that
/// looked at its whole share, half of it left out as unbounded, said
/// nothing was pending (`Retired::pending` 0) and the next step still
/// reported a rest of it (`finished`, every count 0). Key frame 0 has 12
/// points, each given a range (6 bounded, 6 past the map's depth codes:
/// `max_depth` 30), one empty partner and one that matches nothing.
#[test]
fn a_retirement_with_nothing_pending_reports_no_rest() {
    let cam = roadstereo::Camera::new(800.0, 800.0, 255.5, 239.5, 512, 480).expect("camera");
    let mut key_frame = Frame::<16, 1>::new(cam);
    let pts: Vec<Pixel> = (0..12)
        .map(|i| {
            let (x, z) = (-1.0f32, 5.0 + i as f32);
            Pixel::new(255.5 + 800.0 * x / z, 239.5 + 800.0 / z)
        })
        .collect();
    key_frame.push_boundary(&pts).expect("valid");
    let mut stub = Frame::<16, 1>::new(cam);
    stub.push_boundary(&[Pixel::new(505.0, 470.0), Pixel::new(500.0, 460.0)])
        .expect("valid");
    let base = Config::new(0.5, 0.5, 10.0, 30.0).expect("config");
    for share in [1000, 500] {
        let policy = FusionConfig::new(2, 0)
            .and_then(|p| p.with_map_min_pairs(1))
            .and_then(|p| p.with_retirement_share(share))
            .expect("policy");
        let mut f = Box::new(Fusion::<16, 1, 64>::new(base, policy));
        f.step(0, &key_frame, None).expect("key");
        let key = f.key_ref().expect("key");
        for i in 0..12 {
            let far = if i < 6 { 20.0 } else { 1.0e4 };
            f.constrain(key, 0, i, 0.0, far).expect("range");
        }
        let m = Motion::new([0.0, 0.0, 0.25], [0.0; 3]).expect("motion");
        let chained = |from| Some(ChainedMotion { from, motion: m });
        f.step(1, &Frame::new(cam), chained(0).as_ref())
            .expect("step");
        let r = f
            .step(2, &stub, chained(1).as_ref())
            .expect("step")
            .retired
            .expect("key frame 0 retires");
        let next = f.step(3, &stub, chained(2).as_ref()).expect("step");
        let rest = next
            .finished
            .map_or(0, |x| x.entered + x.unbounded + x.unfit);
        // Every point accounted for over the two steps, once.
        assert_eq!(
            (
                r.entered + next.finished.map_or(0, |x| x.entered),
                r.unbounded + next.finished.map_or(0, |x| x.unbounded)
            ),
            (6, 6),
            "share {share}: {r:?} {next:?}"
        );
        assert_eq!(rest, r.pending, "share {share}: {r:?} {next:?}");
        // A rest is reported exactly when one was pending.
        assert_eq!(
            next.finished.is_some(),
            r.pending > 0,
            "share {share}: {r:?} {next:?}"
        );
        assert_eq!(r.pending, if share == 1000 { 0 } else { 6 }, "{r:?}");
    }
}
