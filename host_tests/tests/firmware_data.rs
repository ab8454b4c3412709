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
