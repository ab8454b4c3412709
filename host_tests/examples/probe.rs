//! Debug probe: one scenario point, its truth and its result.
use host_tests::{point_stats, reconstruct, scenarios};
use roadstereo::Config;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().cloned().unwrap_or("crest".into());
    let b: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(0);
    let i: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(77);
    let quant = args.get(3).map(|s| s == "q").unwrap_or(true);
    let s = if let Some(seed) = name.strip_prefix("random_") {
        scenarios::random(seed.parse().unwrap())
    } else if let Some((fam, seed)) = name.split_once(':') {
        scenarios::Family::from_name(fam)
            .unwrap()
            .scenario(seed.parse().unwrap())
    } else {
        scenarios::named()
            .into_iter()
            .find(|s| s.name == name)
            .unwrap()
    };
    let r = s.render();
    println!("translation {:?} angles {:?}", r.translation, r.angles);
    let k = s.intrinsics;
    let budget: u32 = std::env::var("BUDGET")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(40);
    let p = reconstruct(
        &r,
        &k,
        quant,
        Config::default().with_work_budget(budget).unwrap(),
    );
    let st = point_stats(&r, &k, &p);
    let counts = p.structure().status_counts();
    for (s, c) in counts.iter() {
        if c > 0 {
            print!("{}={} ", s.name(), c);
        }
    }
    println!();
    for pt in st
        .iter()
        .filter(|x| x.boundary == b && x.index + 3 >= i && x.index <= i + 3)
    {
        let res = &p.structure().boundaries()[b].points()[pt.index];
        println!(
            "i{} {:?} p1 {:?} p2 {:?} z {:.5} [{:.5},{:.5}] true {:.5} d {:.2} ang {:.1} obs {}",
            pt.index,
            pt.status,
            res.pixel1(),
            res.pixel2(),
            pt.z,
            pt.z_near,
            pt.z_far,
            pt.z_true,
            pt.disparity,
            pt.angle_deg,
            pt.observed
        );
    }
    // True frame-2 position of point i's 3-D point.
    let tp = r.frame1[b][i];
    let w = {
        let (c, m, v) = (r.pose1.centre, r.pose1.rot, tp.camera);
        [0, 1, 2].map(|i| c[i] + m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
    };
    let c2 = r.pose2.to_camera(w);
    println!(
        "true p2 = ({:.3}, {:.3})",
        k.cx + k.fx * c2[0] / c2[2],
        k.cy + k.fy * c2[1] / c2[2]
    );
    // True crossing angles of every point of boundary b: the true epipolar
    // direction (p2 - p1') vs the true frame-2 curve's tangent at p2.
    let mut hist = [0usize; 10];
    for (ii, tp) in r.frame1[b].iter().enumerate() {
        let w = {
            let (c, m, v) = (r.pose1.centre, r.pose1.rot, tp.camera);
            [0, 1, 2].map(|i| c[i] + m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
        };
        let proj = |w: [f64; 3]| {
            let c = r.pose2.to_camera(w);
            [k.cx + k.fx * c[0] / c[2], k.cy + k.fy * c[1] / c[2]]
        };
        let p2 = proj(w);
        let p1c = r.compensate(&k, tp.u, tp.v);
        let d = [p2[0] - p1c[0], p2[1] - p1c[1]];
        // tangent: neighbouring world points along the curve
        let seg = tp.arc as usize;
        let curve = &r.world[if b == 0 { 0 } else { 1 }];
        let (a, c) = (
            curve[seg.saturating_sub(2)],
            curve[(seg + 2).min(curve.len() - 1)],
        );
        let (pa, pc) = (proj(a), proj(c));
        let t = [pc[0] - pa[0], pc[1] - pa[1]];
        let cr = (d[0] * t[1] - d[1] * t[0]).abs();
        let dt = (d[0] * t[0] + d[1] * t[1]).abs();
        let ang = cr.atan2(dt).to_degrees();
        let dl = d[0].hypot(d[1]);
        let bin = ((ang / 5.0) as usize).min(9);
        hist[bin] += 1;
        if ii % 40 == 0 {
            let res = &p.structure().boundaries()[b].points()[ii];
            println!(
                "i{ii} angle {ang:.1} disparity {dl:.1} status {:?}",
                res.status()
            );
        }
    }
    println!("angle histogram (5 deg bins): {hist:?}");
}

#[allow(dead_code)]
fn unused() {}
