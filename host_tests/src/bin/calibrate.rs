//! Calibration demo (Appendix II B): a synthetic calibration run with the
//! paper's camera, the recovered values against the truth (step by step and
//! joint), how the errors shrink with more points and motions, and the
//! analogue of the paper's Fig. A-5/A-6 (flow lines and their FOEs) as SVG:
//! `calibrate [OUT_DIR]` (default `../docs`).

use host_tests::calib::{calibrate_run, paper_motions, TrueCamera, CAP};
use plotters::prelude::*;
use roadstereo::calibration::{focus_of_expansion, Flow, Intrinsics, JointFit};

fn calibrate(
    cam: &TrueCamera,
    motions: &[[f64; 3]],
    n: usize,
    outliers: f64,
    seed: u64,
) -> (Vec<Vec<Flow>>, Intrinsics, JointFit) {
    calibrate_run(cam, motions, n, outliers, seed).expect("the synthetic run calibrates")
}

fn errors(k: &Intrinsics, t: &TrueCamera) -> [f64; 5] {
    [
        (f64::from(k.cx) - t.cx).hypot(f64::from(k.cy) - t.cy),
        (f64::from(k.roll) - t.roll).to_degrees().abs(),
        100.0
            * (f64::from(k.aspect().expect("positive focal lengths")) / (t.fx / t.fy) - 1.0).abs(),
        100.0 * (f64::from(k.fx) / t.fx - 1.0).abs(),
        100.0 * (f64::from(k.fy) / t.fy - 1.0).abs(),
    ]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::path::PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "../docs".into()));
    let cam = TrueCamera::default();
    let motions = paper_motions();
    let (sets, s, j) = calibrate(&cam, &motions, 50, 0.10, 1);
    println!("Calibration run: the paper's motions, 50 feature points each, 10 % wrong matches, flows on the pixel grid\n");
    println!("| parameter | truth | step by step | joint | joint σ |");
    println!("|---|---:|---:|---:|---:|");
    let k = &j.intrinsics;
    println!(
        "| c_x (px) | {:.2} | {:.2} | {:.2} | {:.2} |",
        cam.cx, s.cx, k.cx, j.sigma[0]
    );
    println!(
        "| c_y (px) | {:.2} | {:.2} | {:.2} | {:.2} |",
        cam.cy, s.cy, k.cy, j.sigma[1]
    );
    println!(
        "| roll γ (°) | {:.3} | {:.3} | {:.3} | {:.3} |",
        cam.roll.to_degrees(),
        s.roll.to_degrees(),
        k.roll.to_degrees(),
        j.sigma[2].to_degrees()
    );
    println!(
        "| aspect r | {:.4} | {:.4} | {:.4} | |",
        cam.fx / cam.fy,
        s.aspect()?,
        k.aspect()?
    );
    println!(
        "| f_x (px) | {:.1} | {:.1} | {:.1} | {:.1} |",
        cam.fx, s.fx, k.fx, j.sigma[3]
    );
    println!(
        "| f_y (px) | {:.1} | {:.1} | {:.1} | {:.1} |",
        cam.fy, s.fy, k.fy, j.sigma[4]
    );
    println!(
        "\njoint fit: {} flows, RMS misalignment {:.2} px, {} Gauss-Newton iterations\n",
        j.flows, j.rms, j.iterations
    );
    println!("Mean errors over 20 runs (c: px, γ: degrees, r, f_x, f_y: %):\n");
    println!("| points/motion | motions | method | c | γ | r | f_x | f_y |");
    println!("|---:|---:|---|---:|---:|---:|---:|---:|");
    let mut more = paper_motions();
    more.extend([
        [2.5, 0.0, 2.5],
        [-2.5, 0.0, 2.5],
        [0.0, 2.5, 2.5],
        [0.0, -2.5, 2.5],
    ]);
    for (n, ms) in [(15, &motions), (50, &motions), (150, &motions), (50, &more)] {
        let (mut es, mut ej) = ([0.0; 5], [0.0; 5]);
        for seed in 0..20 {
            let (_, s, j) = calibrate(&cam, ms, n, 0.0, 500 + seed);
            for (a, b) in es.iter_mut().zip(errors(&s, &cam)) {
                *a += b / 20.0;
            }
            for (a, b) in ej.iter_mut().zip(errors(&j.intrinsics, &cam)) {
                *a += b / 20.0;
            }
        }
        for (name, e) in [("step by step", es), ("joint", ej)] {
            if name == "step by step" && ms.len() > 5 {
                continue; // the step-by-step procedure uses the paper's five motions only
            }
            println!(
                "| {n} | {} | {name} | {:.2} | {:.3} | {:.2} | {:.2} | {:.2} |",
                ms.len(),
                e[0],
                e[1],
                e[2],
                e[3],
                e[4]
            );
        }
    }
    // Fig.: the flows of the five motions and their FOEs.
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("fig_a6_foes.svg");
    let root = SVGBackend::new(&path, (900, 700)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Flows of five known translations and their FOEs (Fig. A-5/A-6 analogue)",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(45)
        .build_cartesian_2d(-500.0f64..1050.0, 1150.0f64..-700.0)?;
    chart
        .configure_mesh()
        .x_desc("u (px)")
        .y_desc("v (px)")
        .draw()?;
    // The image.
    chart.draw_series(std::iter::once(Rectangle::new(
        [(0.0, 0.0), (511.0, 479.0)],
        BLACK.stroke_width(2),
    )))?;
    let colours = [BLACK, RED, BLUE, GREEN, MAGENTA];
    for ((set, t), col) in sets.iter().zip(&motions).zip(colours) {
        let foe = focus_of_expansion::<CAP>(set).expect("FOE").foe;
        let (fu, fv) = (f64::from(foe.u), f64::from(foe.v));
        // Each flow, and (faintly) its line continued towards the FOE.
        for f in set {
            let (a, b) = (
                (f64::from(f.from.u), f64::from(f.from.v)),
                (f64::from(f.to.u), f64::from(f.to.v)),
            );
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(fu, fv), a],
                col.mix(0.12),
            )))?;
            chart.draw_series(std::iter::once(PathElement::new(
                vec![a, b],
                col.stroke_width(2),
            )))?;
        }
        chart.draw_series(std::iter::once(Cross::new(
            (fu, fv),
            8,
            col.stroke_width(3),
        )))?;
        let tf = cam.foe(*t);
        chart.draw_series(std::iter::once(Circle::new((tf[0], tf[1]), 10, col)))?;
    }
    root.present()?;
    println!(
        "\nwrote {} (crosses: fitted FOEs; circles: true FOEs; the box: the 512 × 480 image)",
        path.display()
    );
    Ok(())
}
