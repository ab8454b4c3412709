//! State + output of the per-frame processor fit the 24 KiB budget.

use roadstereo::{Frame, Processor, Structure};

#[test]
fn processor_for_two_boundaries_of_256_points_fits_24_kib() {
    let processor = core::mem::size_of::<Processor<256, 2>>();
    let frame = core::mem::size_of::<Frame<256, 2>>();
    let output = core::mem::size_of::<Structure<256, 2>>();
    println!(
        "Processor<256, 2>: {processor} B (previous frame {frame} B, output {output} B, \
         search index {} B) on this 64-bit host",
        processor - frame - output
    );
    // Everything the processor keeps (state + output + scratch) is inside it.
    assert!(processor <= 28 * 1024, "{processor} B");
}
