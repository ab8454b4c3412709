//! The frames embedded in the firmware (`src/bin/data/`) are exactly what
//! the generator produces (regenerate with `cargo run --bin drive_data`).

use host_tests::drive;

#[test]
fn embedded_frames_match_the_generator() {
    let (k, frames) = drive::demo(24, 256);
    assert_eq!(
        drive::encode(&k, &frames),
        include_bytes!("../../src/bin/data/drive.bin").to_vec(),
        "drive.bin is stale"
    );
    // The smallest row step between consecutive points of any boundary.
    let min_row_step = |frames: &[drive::DriveFrame]| {
        frames
            .iter()
            .flat_map(|f| f.boundaries.iter())
            .flat_map(|b| b.windows(2).map(|w| (w[1][1] - w[0][1]).abs()))
            .fold(f32::INFINITY, f32::min)
    };
    for (n, bytes) in [
        (32, &include_bytes!("../../src/bin/data/bench_32.bin")[..]),
        (64, &include_bytes!("../../src/bin/data/bench_64.bin")[..]),
        (128, &include_bytes!("../../src/bin/data/bench_128.bin")[..]),
        (256, &include_bytes!("../../src/bin/data/bench_256.bin")[..]),
        (512, &include_bytes!("../../src/bin/data/bench_512.bin")[..]),
    ] {
        let (k, frames) = drive::bench_pair_one_per_row(n);
        assert_eq!(
            drive::encode(&k, &frames),
            bytes.to_vec(),
            "bench_{n}.bin is stale"
        );
        // Exactly n points per boundary, as the benchmark claims, at most
        // one per image row (what a row-scanning detector gives).
        for f in &frames {
            assert!(f.boundaries.iter().all(|b| b.len() == n));
        }
        assert!(
            min_row_step(&frames) >= 0.999,
            "bench_{n}: {}",
            min_row_step(&frames)
        );
    }
    for (n, bytes) in [
        (
            256,
            &include_bytes!("../../src/bin/data/stress_256.bin")[..],
        ),
        (
            512,
            &include_bytes!("../../src/bin/data/stress_512.bin")[..],
        ),
    ] {
        let (k, frames) = drive::bench_pair(n);
        assert_eq!(
            drive::encode(&k, &frames),
            bytes.to_vec(),
            "stress_{n}.bin is stale"
        );
        // The stress pairs crowd a boundary to well over a point per row.
        assert!(
            min_row_step(&frames) < 0.6,
            "stress_{n}: {}",
            min_row_step(&frames)
        );
    }
    // The decoder reads back what the encoder wrote.
    let (_, back) = drive::decode(include_bytes!("../../src/bin/data/drive.bin")).expect("decodes");
    assert_eq!(back.len(), 24);
    assert!(back
        .iter()
        .all(|f| f.boundaries.iter().all(|b| b.len() <= 256)));
}

/// The adversarial family (`src/bin/data/adv_*.bin` and the firmware's
/// table `adversarial.rs`) is exactly what the generator writes from
/// `host_tests/src/drive/adversarial.rs` and `adversarial_found.json`
/// (regenerate with `cargo run --release --bin adversarial`), and every
/// pair passes the library's validation: two boundaries of exactly N
/// points in each frame, rows strictly one way, every boundary
/// accepted by `Frame::push_boundary`, the motion by `Motion::new`.
#[test]
fn adversarial_frames_match_the_generator_and_pass_validation() {
    use drive::adversarial::{self, family, render, SIZES};
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src/bin/data");
    let members = family();
    assert!(members.len() >= 12, "hand-made and searched members");
    let mut names = std::collections::HashSet::new();
    for m in &members {
        assert!(names.insert(m.name.clone()), "{} twice", m.name);
        assert!(
            m.name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_'),
            "{}: a name the firmware log can carry",
            m.name
        );
        for n in SIZES {
            let (k, frames) =
                render(&m.params, n).unwrap_or_else(|e| panic!("{} {n}: {e}", m.name));
            let path = dir.join(adversarial::file_name(&m.name, n));
            let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(
                drive::encode(&k, &frames) == bytes,
                "{} is stale",
                path.display()
            );
            // Read back as the firmware reads it, then validated by the library.
            let (cam, back) = drive::decode(&bytes).expect("decodes");
            assert_eq!((cam.width(), cam.height()), (k.width, k.height));
            assert_eq!(back.len(), 2, "{} {n}: a pair", m.name);
            for f in &back {
                assert_eq!(f.boundaries.len(), 2, "{} {n}: two boundaries", m.name);
                let bs = pixels(&f.boundaries);
                for b in &bs {
                    assert_eq!(b.len(), n, "{} {n}: N points per boundary", m.name);
                    // Rows strictly one way (the library's own rule); most
                    // members have one point per row, the forward spirals
                    // about an FOE inside the image up to two.
                    assert!(
                        b.windows(2).all(|w| w[1].v < w[0].v)
                            || b.windows(2).all(|w| w[1].v > w[0].v),
                        "{} {n}: rows one way",
                        m.name
                    );
                }
                let _ = host_tests::frame(cam, &bs); // panics if rejected
            }
            assert!(roadstereo::Motion::new(back[1].translation, back[1].rotation).is_ok());
            assert_eq!(back[0].translation, [0.0; 3], "frame 1 has no motion");
        }
    }
    let table = std::fs::read_to_string(dir.join("adversarial.rs")).expect("adversarial.rs");
    assert_eq!(
        table,
        adversarial::firmware_table(&members),
        "adversarial.rs is stale"
    );
    // Only the generator's files under that name.
    let on_disk = std::fs::read_dir(&dir)
        .expect("data dir")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|f| f.starts_with("adv_"))
        .count();
    assert_eq!(
        on_disk,
        members.len() * SIZES.len(),
        "stray adv_*.bin files"
    );
}

/// The family's base is the representative pair: its parameters render
/// the bench's `bench_N.bin` bit for bit.
#[test]
fn adversarial_base_is_the_representative_pair() {
    for n in [64, 128, 256, 512] {
        let (k, f) =
            drive::adversarial::render(&drive::adversarial::Params::fig6(), n).expect("valid");
        let (kb, fb) = drive::bench_pair_one_per_row(n);
        assert_eq!(drive::encode(&k, &f), drive::encode(&kb, &fb), "N = {n}");
    }
}

/// The pairs reviews found by hill climbing (`src/bin/data/rev_*.bin`,
/// `rev8_*.bin`, `rev9_*.bin`, `rev10_*.bin`, `rev11_*.bin`,
/// the bench's `FOUND`, stored as found): each decodes as the firmware
/// reads it, two frames of two boundaries of the N the bench runs it at,
/// every boundary accepted by `Frame::push_boundary` (with the file's
/// camera; the frame 1 of `rev_e4`, `rev_f1`, `rev_g1`, `rev_h1`, `rev_x3`,
/// `rev8_a`, `rev8_b`, `rev8_l` and `rev9_s` has
/// its own too, `Found::camera1`, which the bench checks as it loads it), the motion by `Motion::new`; and the bench's
/// table (`src/bin/bench/pairs.rs`) names every file.
#[test]
fn found_pairs_pass_validation() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../src/bin/data");
    let bench = std::fs::read_to_string(dir.join("../bench/pairs.rs")).expect("bench/pairs.rs");
    let found = [
        ("rev_a1", 64),
        ("rev_b1", 256),
        ("rev_b2", 64),
        ("rev_c1", 512),
        ("rev_c2", 256),
        ("rev_d2", 512),
        ("rev_e2", 64),
        ("rev_e4", 64),
        ("rev_f1", 64),
        ("rev_g1", 512),
        ("rev_h1", 512),
        ("rev_x3", 64),
        ("rev8_a", 64),
        ("rev8_b", 128),
        ("rev8_l", 512),
        ("rev8_s", 512),
        ("rev9_s", 512),
        ("rev10_l1", 512),
        ("rev10_l2", 512),
        ("rev10_off", 512),
        ("rev11_e", 512),
        ("rev11_u1", 512),
        ("rev12_a", 512),
        ("rev12_c", 512),
        ("rev12_d", 512),
        ("rev13_a", 512),
        ("rev14_c1", 512),
        ("rev15_c", 512),
    ];
    for (name, n) in found {
        assert!(
            bench.contains(&format!(
                "name: \"{name}\",\n        n: {n},\n        data: include_bytes!(\"../data/{name}.bin\"),"
            )),
            "{name} in FOUND"
        );
        let bytes = std::fs::read(dir.join(format!("{name}.bin"))).expect("found pair");
        let (cam, back) = drive::decode(&bytes).expect("decodes");
        assert_eq!(back.len(), 2, "{name}: a pair");
        for f in &back {
            assert_eq!(f.boundaries.len(), 2, "{name}: two boundaries");
            let bs = pixels(&f.boundaries);
            for b in &bs {
                assert_eq!(b.len(), n, "{name}: N points a boundary");
            }
            let _ = host_tests::frame(cam, &bs); // panics if rejected
        }
        assert!(roadstereo::Motion::new(back[1].translation, back[1].rotation).is_ok());
    }
    let on_disk = std::fs::read_dir(&dir)
        .expect("data dir")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|f| f.starts_with("rev"))
        .count();
    assert_eq!(on_disk, found.len(), "stray rev_*.bin files");
}

/// A decoded frame's boundaries as the library's pixels.
fn pixels(boundaries: &[Vec<[f32; 2]>]) -> Vec<Vec<roadstereo::Pixel>> {
    boundaries
        .iter()
        .map(|b| {
            b.iter()
                .map(|q| roadstereo::Pixel::new(q[0], q[1]))
                .collect()
        })
        .collect()
}
