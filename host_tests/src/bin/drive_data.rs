//! Write the firmware's embedded frame data: `drive_data OUT_DIR`
//! (default `../src/bin/data`): `drive.bin` (the demo drive, 24 frames, up
//! to 256 points per boundary) and `bench_N.bin` for N = 32 … 512.

use host_tests::drive;

fn main() -> std::io::Result<()> {
    let dir = std::path::PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "../src/bin/data".into()),
    );
    std::fs::create_dir_all(&dir)?;
    let (k, frames) = drive::demo(24, 256);
    for (i, f) in frames.iter().enumerate() {
        let n: Vec<usize> = f.boundaries.iter().map(Vec::len).collect();
        println!("drive frame {i}: points {n:?}");
    }
    std::fs::write(dir.join("drive.bin"), drive::encode(&k, &frames))?;
    for n in [32, 64, 128, 256, 512] {
        let (k, frames) = drive::bench_pair(n);
        let counts: Vec<Vec<usize>> = frames
            .iter()
            .map(|f| f.boundaries.iter().map(Vec::len).collect())
            .collect();
        println!("bench {n}: points {counts:?}");
        std::fs::write(
            dir.join(format!("bench_{n}.bin")),
            drive::encode(&k, &frames),
        )?;
    }
    Ok(())
}
