use roadstereo::{Config, Frame, Motion, Pixel, Processor};
fn main() {
    let path = std::env::args()
        .nth(1)
        .unwrap_or("../src/bin/data/bench_256.bin".into());
    let b = std::fs::read(path).unwrap();
    let (cam, frames) = host_tests::drive::decode(&b).unwrap();
    let mut p = Processor::<512, 2>::new(Config::DEFAULT);
    for f in frames.iter().take(2) {
        let mut fr = Frame::<512, 2>::new(cam);
        for bd in &f.boundaries {
            let pts: Vec<Pixel> = bd.iter().map(|q| Pixel::new(q[0], q[1])).collect();
            fr.push_boundary(&pts).unwrap();
        }
        let m = Motion::new(f.translation, f.rotation).ok();
        if let Ok(roadstereo::Step::Structure(s)) = p.process(&fr, m.as_ref()) {
            for b in s.boundaries() {
                let mut c = std::collections::BTreeMap::new();
                for r in b.points() {
                    *c.entry(format!("{:?}", r.status())).or_insert(0) += 1;
                }
                println!("{c:?}");
            }
        }
    }
}
