//! Host reference for the firmware demo: process the embedded drive
//! (`src/bin/data/drive.bin`) with the host build of the same code and print,
//! per frame, the status counts and the result digest in the demo's own
//! `frame=…` format, so `cargo xtask demo --check` can compare them.

use host_tests::drive;
use roadstereo::{Config, Frame, Motion, Pixel, Processor, Status, Step};

fn main() -> std::process::ExitCode {
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "../src/bin/data/drive.bin".into());
    let Ok(bytes) = std::fs::read(&path) else {
        eprintln!("fwref: cannot read {path}");
        return std::process::ExitCode::from(2);
    };
    let Some((cam, frames)) = drive::decode(&bytes) else {
        eprintln!("fwref: bad drive data in {path}");
        return std::process::ExitCode::from(2);
    };
    let mut p = Box::new(Processor::<256, 2>::new(Config::default()));
    for (i, f) in frames.iter().enumerate() {
        let mut frame = Frame::<256, 2>::new(cam);
        for b in &f.boundaries {
            let pts: Vec<Pixel> = b.iter().map(|q| Pixel::new(q[0], q[1])).collect();
            if frame.push_boundary(&pts).is_err() {
                eprintln!("fwref: frame {i}: bad boundary");
                return std::process::ExitCode::from(2);
            }
        }
        let motion = if f.translation == [0.0; 3] {
            None
        } else {
            Motion::new(f.translation, f.rotation).ok()
        };
        match p.process(&frame, motion.as_ref()) {
            Ok(Step::First) => {}
            Ok(Step::Structure(s)) => {
                let c = s.status_counts();
                let g = |st: Status| c[st as usize];
                println!(
                    "frame={} points={} ok={} ambiguous={} at_foe={} behind={} no_intersection={} grazing={} nonpositive={} beyond={} unbounded={} folded={} out_of_view={} boundary_end={} over_budget={} digest={:08x}",
                    i,
                    c.iter().sum::<usize>(),
                    g(Status::Ok),
                    g(Status::Ambiguous),
                    g(Status::AtFoe),
                    g(Status::BehindCamera),
                    g(Status::NoIntersection),
                    g(Status::Grazing),
                    g(Status::NonPositiveDepth),
                    g(Status::BeyondMaxDepth),
                    g(Status::Unbounded),
                    g(Status::Folded),
                    g(Status::OutOfView),
                    g(Status::BoundaryEnd),
                    g(Status::OverBudget),
                    s.digest()
                );
            }
            Err(e) => {
                eprintln!("fwref: frame {i}: {e}");
                return std::process::ExitCode::from(2);
            }
        }
    }
    std::process::ExitCode::SUCCESS
}
