//! Write frames k−1 and k of a drive file as a two-frame pair (for a
//! profile window): `cargo run --release --example pair_of -- IN K OUT`.
use host_tests::drive::{decode, encode, DriveFrame};
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let b = std::fs::read(&a[0]).unwrap();
    let k: usize = a[1].parse().unwrap();
    let (cam, frames) = decode(&b).unwrap();
    let intr = host_tests::synth::Intrinsics {
        fx: f64::from(cam.fx()),
        fy: f64::from(cam.fy()),
        cx: f64::from(cam.cx()),
        cy: f64::from(cam.cy()),
        width: cam.width(),
        height: cam.height(),
    };
    let first = DriveFrame {
        translation: [0.0; 3],
        rotation: [0.0; 3],
        boundaries: frames[k - 1].boundaries.clone(),
        depths: Vec::new(),
    };
    let out = encode(&intr, &[first, frames[k].clone()]);
    std::fs::write(&a[2], out).unwrap();
}
