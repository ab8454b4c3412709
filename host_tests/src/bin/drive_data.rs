//! Write the firmware's embedded frame data: `drive_data OUT_DIR`
//! (default `../src/bin/data`): `drive.bin` (the demo drive, 24 frames, up
//! to 256 points per boundary), `bench_N.bin` for N = 32 … 512 (one
//! detector point per image row: [`drive::bench_pair_one_per_row`]) and
//! `stress_N.bin` for N = 256, 512 (the paper's 512 × 480 camera sampled at
//! up to 3.4 points per row: [`drive::bench_pair`]), and the adversarial
//! family, `adv_<member>_N.bin` for N = 64 … 512 with the firmware's table
//! `adversarial.rs` ([`drive::adversarial`]; the `adversarial` tool writes
//! the same and can search for new members).

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
    type Make = fn(usize) -> (host_tests::synth::Intrinsics, Vec<drive::DriveFrame>);
    let sets: [(&str, Make, &[usize]); 2] = [
        (
            "bench",
            drive::bench_pair_one_per_row,
            &[32, 64, 128, 256, 512],
        ),
        ("stress", drive::bench_pair, &[256, 512]),
    ];
    for (name, make, sizes) in sets {
        for &n in sizes {
            let (k, frames) = make(n);
            let counts: Vec<Vec<usize>> = frames
                .iter()
                .map(|f| f.boundaries.iter().map(Vec::len).collect())
                .collect();
            println!(
                "{name} {n}: {}x{} camera, points {counts:?}",
                k.width, k.height
            );
            std::fs::write(
                dir.join(format!("{name}_{n}.bin")),
                drive::encode(&k, &frames),
            )?;
        }
    }
    let members = drive::adversarial::family();
    let bytes = drive::adversarial::write_all(&dir, &members).map_err(std::io::Error::other)?;
    println!(
        "adversarial: {} members x N = {:?}, {bytes} bytes",
        members.len(),
        drive::adversarial::SIZES
    );
    Ok(())
}
