use host_tests::*;
use roadstereo::{Config, PairGeometry, Pixel, Status};

fn main() {
    let k = synth::Intrinsics::default();
    let n: u64 = std::env::args().nth(1).unwrap().parse().unwrap();
    let tol: f32 = std::env::args().nth(2).unwrap().parse().unwrap();
    let (mut miss, mut caught, mut good_flagged, mut good) = (0, 0, 0, 0);
    for seed in 0..n {
        let s = scenarios::random(seed);
        let r = s.render();
        let p = reconstruct(&r, &k, true, Config::default());
        let st = p.structure();
        let cam = k.camera();
        let geom = PairGeometry::new(&cam, &cam, &r.motion());
        let w = geom.w();
        let f1 = synth::Rendered::pixels(&r.frame1, true);
        for (bi, b) in st.boundaries().iter().enumerate() {
            let comp: Vec<[f32; 2]> = f1[bi].iter().map(|p| geom.compensate(*p).unwrap().pixel).collect();
            for (i, pr) in b.points().iter().enumerate() {
                if pr.status() != Status::Ok { continue; }
                let c = geom.compensate(pr.pixel1()).unwrap();
                let line = geom.line(&c);
                let alen = line.a2.sqrt();
                let mut other = 0;
                for j in 0..comp.len() - 1 {
                    let (v0, v1) = (comp[j], comp[j + 1]);
                    let s0 = line.a[0] * (v0[1] - c.pixel[1]) - line.a[1] * (v0[0] - c.pixel[0]);
                    let s1 = line.a[0] * (v1[1] - c.pixel[1]) - line.a[1] * (v1[0] - c.pixel[0]);
                    if (s0 >= 0.0) == (s1 >= 0.0) { continue; }
                    let u = s0 / (s0 - s1);
                    let p = [v0[0] + u * (v1[0] - v0[0]), v0[1] + u * (v1[1] - v0[1])];
                    let tau = ((p[0] - c.pixel[0]) * line.a[0] + (p[1] - c.pixel[1]) * line.a[1]) / line.a2;
                    let on_ray = if w > 0.0 { tau > -1.0 / w } else if w < 0.0 { tau < -1.0 / w } else { true };
                    if on_ray && (tau * alen).abs() > tol { other += 1; }
                }
                let zt = r.frame1[bi][i].camera[2];
                let iv = pr.interval().unwrap();
                let inside = iv.z_near as f64 <= zt && zt <= iv.z_far as f64;
                if !inside { miss += 1; if other > 0 { caught += 1 } else { eprintln!("uncaught {seed} b{bi} i{i} p1={:?}", pr.pixel1()); } }
                else { good += 1; if other > 0 { good_flagged += 1 } }
            }
        }
        let _ = Pixel::new(0.0, 0.0);
    }
    println!("miss {miss} caught {caught}; good {good} flagged {good_flagged}");
}
