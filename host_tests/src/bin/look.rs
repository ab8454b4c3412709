use host_tests::*;
use roadstereo::Config;
fn main() {
    let k = synth::Intrinsics::default();
    let seed: u64 = std::env::args().nth(1).unwrap().parse().unwrap();
    let bi: usize = std::env::args().nth(2).unwrap().parse().unwrap();
    let s = scenarios::random(seed);
    println!("{:?}", s);
    let r = s.render();
    println!("T {:?} A {:?}", r.translation, r.angles.map(|a| a.to_degrees()));
    let p = reconstruct(&r, &k, true, Config::default());
    let b1 = &r.frame1[bi]; let b2 = &r.frame2[bi];
    println!("f1: n={} first {:?} last {:?}", b1.len(), (b1[0].u, b1[0].v), (b1.last().unwrap().u, b1.last().unwrap().v));
    println!("f2: n={} first {:?} last {:?}", b2.len(), (b2[0].u, b2[0].v), (b2.last().unwrap().u, b2.last().unwrap().v));
    let cam = k.camera();
    let geom = roadstereo::PairGeometry::new(&cam, &cam, &r.motion());
    println!("foe {:?} w {}", geom.focus_of_expansion(), geom.w());
    let st = p.structure();
    for (i, pr) in st.boundaries()[bi].points().iter().enumerate().take(60) {
        // true frame-2 projection
        let pc = r.frame1[bi][i].camera;
        // to world then cam2
        let pw = { let m = r.pose1.rot; let c = r.pose1.centre; [0,1,2].map(|a| c[a] + m[a][0]*pc[0] + m[a][1]*pc[1] + m[a][2]*pc[2]) };
        let q = r.pose2.to_camera(pw);
        let t2 = (k.cx + k.f * q[0]/q[2], k.cy + k.f*q[1]/q[2]);
        println!("{i:3} p1=({:.0},{:.0}) st={:?} z={:?} zt={:.3} p2={:?} true2=({:.1},{:.1})", pr.pixel1().u, pr.pixel1().v, pr.status(), pr.depth(), pc[2], pr.pixel2().map(|p| (p.u, p.v)), t2.0, t2.1);
    }
}
