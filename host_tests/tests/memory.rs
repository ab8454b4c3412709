//! State + output of the per-frame processor fit their budget: exactly
//! what they need (`docs/VEHICLE.md`, "Memory"; issue 11 allows up to 28 KiB).

use roadstereo::{Frame, Processor, Structure};

#[test]
fn processor_for_two_boundaries_of_256_points_fits_its_budget() {
    let processor = core::mem::size_of::<Processor<256, 2>>();
    let frame = core::mem::size_of::<Frame<256, 2>>();
    let output = core::mem::size_of::<Structure<256, 2>>();
    println!(
        "Processor<256, 2>: {processor} B (previous frame {frame} B, output {output} B, \
         search index {} B) on this 64-bit host",
        processor - frame - output
    );
    // Everything the processor keeps (state + output + scratch) is inside it.
    // 26 892 B on the 32-bit target (asserted at compile time there); the
    // host's `usize` fields make it 60 B more.
    assert!(processor <= 26_952, "{processor} B");
}

/// The key-frame fusion's state and the road map beside the processor fit
/// 24 KiB (issue 13): 2 × 256 key-frame points (20 B each: their majority
/// and rival intervals exact since the twenty-fourth session) and a map of
/// 2 × 512 points (12 B each) with its batches. (The library asserts it at
/// compile time for 32-bit targets, and the bench prints the Cortex-M4F
/// figures.)
#[test]
fn fusion_state_and_map_fit_24_kib() {
    use roadstereo::fusion::{Fusion, KeyFrame};
    use roadstereo::map::RoadMap;
    let fusion = core::mem::size_of::<Fusion<256, 2, 512>>();
    let processor = core::mem::size_of::<Processor<256, 2>>();
    let key = core::mem::size_of::<KeyFrame<256, 2>>();
    let map = core::mem::size_of::<RoadMap<2, 512>>();
    println!(
        "Fusion<256, 2, 512>: {fusion} B = processor {processor} B + {} B (key frame {key} B, map {map} B) on this 64-bit host",
        fusion - processor
    );
    assert!(fusion - processor <= 24 * 1024, "{} B", fusion - processor);
    assert!(key <= 20 * 2 * 256 + 64 && map <= 12 * 2 * 512 + 1024);
}
