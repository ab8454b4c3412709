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
    for (n, bytes) in [
        (32, &include_bytes!("../../src/bin/data/bench_32.bin")[..]),
        (64, &include_bytes!("../../src/bin/data/bench_64.bin")[..]),
        (128, &include_bytes!("../../src/bin/data/bench_128.bin")[..]),
        (256, &include_bytes!("../../src/bin/data/bench_256.bin")[..]),
        (512, &include_bytes!("../../src/bin/data/bench_512.bin")[..]),
    ] {
        let (k, frames) = drive::bench_pair(n);
        assert_eq!(
            drive::encode(&k, &frames),
            bytes.to_vec(),
            "bench_{n}.bin is stale"
        );
        // Exactly n points per boundary, as the benchmark claims.
        for f in &frames {
            assert!(f.boundaries.iter().all(|b| b.len() == n));
        }
    }
    // The decoder reads back what the encoder wrote.
    let (_, back) = drive::decode(include_bytes!("../../src/bin/data/drive.bin")).expect("decodes");
    assert_eq!(back.len(), 24);
    assert!(back
        .iter()
        .all(|f| f.boundaries.iter().all(|b| b.len() <= 256)));
}
