//! Host reference for the firmware demo: process the embedded drive
//! (`src/bin/data/drive.bin`) with the host build of the same code (the
//! key-frame fusion around the processor) and print, per frame, the status
//! counts, the result digest and the fusion's figures and digest in the
//! demo's own `frame=…` format, so `cargo xtask demo --check` can compare
//! them.

use host_tests::drive;
use roadstereo::fusion::{ChainedMotion, FusedStatus, Fusion, FusionConfig};
use roadstereo::{Config, Frame, Motion, Pixel, Status};

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
    let policy = FusionConfig::DEFAULT
        .with_tilt(23f32.to_radians())
        .expect("tilt");
    let mut fusion = Box::new(Fusion::<256, 2, 512>::new(Config::default(), policy));
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
        let chained = motion.map(|m| ChainedMotion {
            from: (i as u32).wrapping_sub(1),
            motion: m,
        });
        let step = match fusion.step(i as u32, &frame, chained.as_ref()) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("fwref: frame {i}: {e}");
                return std::process::ExitCode::from(2);
            }
        };
        if i == 0 {
            continue;
        }
        let s = fusion.structure();
        let Some(key) = fusion.key() else {
            eprintln!("fwref: frame {i}: no key frame");
            return std::process::ExitCode::from(2);
        };
        let counts = key.counts();
        let mut widths: Vec<f32> = (0..2)
            .flat_map(|b| key.points(b).collect::<Vec<_>>())
            .filter(|p| p.status == FusedStatus::Consistent)
            .filter_map(|p| p.interval)
            .map(|iv| (iv.z_far - iv.z_near) / (0.5 * (iv.z_far + iv.z_near)))
            .collect();
        widths.sort_unstable_by(f32::total_cmp);
        let median = widths.get(widths.len() / 2).copied().unwrap_or(0.0);
        let map = fusion.map();
        let c = s.status_counts();
        let g = |st: Status| c.get(st);
        println!(
            "frame={} points={} ok={} ambiguous={} at_foe={} behind={} no_intersection={} grazing={} nonpositive={} beyond={} unbounded={} folded={} out_of_view={} boundary_end={} over_budget={} digest={:08x} key={} partner={} retired={} fused={} single={} inconsistent={} conflicts={} width_permille={} map={} map_behind={} map_room={} fusion_digest={:08x}",
            i,
            c.total(),
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
            s.digest(),
            key.id(),
            step.partner,
            step.retired.is_some(),
            counts.consistent,
            counts.single,
            counts.inconsistent,
            step.paired.unwrap_or_default().conflicts,
            (median * 1000.0) as u32,
            map.points(0).count() + map.points(1).count(),
            map.drops().behind,
            map.drops().capacity,
            fusion.digest()
        );
    }
    std::process::ExitCode::SUCCESS
}
