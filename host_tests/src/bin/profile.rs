//! Host profiling aid: run the N = 256 benchmark pair many times
//! (`valgrind --tool=callgrind target/release/profile`).
use host_tests::drive;
use roadstereo::{Config, Frame, Motion, Pixel, Processor};

fn main() {
    let (k, frames) = drive::bench_pair(256);
    let cam = k.camera();
    let mk = |f: &drive::DriveFrame| {
        let mut fr = Frame::<512, 2>::new(cam);
        for b in &f.boundaries {
            let p: Vec<Pixel> = b.iter().map(|q| Pixel::new(q[0], q[1])).collect();
            fr.push_boundary(&p).unwrap();
        }
        fr
    };
    let (f1, f2) = (mk(&frames[0]), mk(&frames[1]));
    let m = Motion::new(frames[1].translation, frames[1].rotation).unwrap();
    let mut p = Box::new(Processor::<512, 2>::new(Config::default()));
    let mut acc = 0u32;
    for _ in 0..200 {
        p.reset();
        let _ = p.process(&f1, None);
        let _ = p.process(std::hint::black_box(&f2), Some(&m));
        acc ^= p.structure().digest();
    }
    println!("{acc:08x}");
}
