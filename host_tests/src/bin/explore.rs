use host_tests::*;
use roadstereo::{Config, Status};

fn main() {
    let k = synth::Intrinsics::default();
    let mut scen = scenarios::named();
    scen.push(scenarios::degenerate());
    let args: Vec<String> = std::env::args().collect();
    if args.len() > 1 {
        let n: u64 = args[1].parse().unwrap();
        scen = (0..n).map(scenarios::random).collect();
    }
    let (mut tot_in, mut tot_ok) = (0, 0);
    for s in &scen {
        let r = s.render();
        for quant in [false, true] {
            let p = reconstruct(&r, &k, quant, Config::default());
            let st = p.structure();
            let counts = st.status_counts();
            let mut worst: f64 = 0.0;
            let mut miss = 0;
            let mut n_ok = 0;
            for (bi, b) in st.boundaries().iter().enumerate() {
                for (i, pr) in b.points().iter().enumerate() {
                    if pr.status() != Status::Ok {
                        continue;
                    }
                    n_ok += 1;
                    let zt = r.frame1[bi][i].camera[2];
                    let z = pr.depth().unwrap() as f64;
                    worst = worst.max(((z - zt) / zt).abs());
                    let iv = pr.interval().unwrap();
                    if !(iv.z_near as f64 <= zt && zt <= iv.z_far as f64) {
                        miss += 1;
                        if quant && args.len() > 1 {
                            eprintln!("  miss {} b{bi} i{i} zt={zt:.3} z={z:.3} [{:.3},{:.3}] p1={:?} p2={:?}", s.name, iv.z_near, iv.z_far, pr.pixel1(), pr.pixel2());
                        }
                    }
                }
            }
            if quant { tot_in += n_ok; tot_ok += n_ok - miss; }
            if args.len() == 1 || miss > 0 {
            println!(
                "{:22} {} pts {:3}+{:3} ok {:3} worst {:.4}% miss {} counts {:?} T={:.3?} A={:.2?}",
                s.name,
                if quant { "Q" } else { "E" },
                r.frame1.first().map_or(0, |b| b.len()),
                r.frame1.get(1).map_or(0, |b| b.len()),
                n_ok,
                worst * 100.0,
                miss,
                counts,
                r.translation,
                r.angles.map(|a| a.to_degrees())
            );
            }
        }
    }
    println!("quantised: {tot_ok}/{tot_in} contained");
}
