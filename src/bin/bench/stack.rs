//! Stack painting: fill the free stack below the current stack pointer with
//! a pattern, run `f`, and find how deep it wrote. Reading and writing raw
//! stack memory needs `unsafe`; this is measurement code in the benchmark
//! binary only (the library forbids `unsafe`).

const PATTERN: u32 = 0xDEAD_BEEF;
extern "C" {
    static mut __sheap: u32;
}

#[inline(never)]
pub fn high_water(f: impl FnOnce()) -> u32 {
    let sp = cortex_m::register::msp::read() as usize;
    let bottom = core::ptr::addr_of_mut!(__sheap) as usize;
    // Leave 256 bytes below the current frame for this function itself.
    let top = (sp - 256) & !3;
    let mut a = bottom;
    while a < top {
        // SAFETY: [bottom, top) is free stack memory below the live stack
        // (cortex-m-rt puts the stack at the top of RAM, growing down to
        // the end of .bss at __sheap); nothing else uses it.
        unsafe { core::ptr::write_volatile(a as *mut u32, PATTERN) };
        a += 4;
    }
    f();
    let mut a = bottom;
    // SAFETY: as above; reading back the painted region.
    while a < top && unsafe { core::ptr::read_volatile(a as *const u32) } == PATTERN {
        a += 4;
    }
    (sp - a) as u32
}
