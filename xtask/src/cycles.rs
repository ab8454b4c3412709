//! An estimate of Cortex-M4F cycles from a traced instruction sequence.
//!
//! QEMU counts instructions, not cycles. This model prices each executed
//! instruction from its mnemonic, whether it was a taken branch, and
//! whether the instruction before it was a load, after the timings of the
//! Cortex-M4 Technical Reference Manual (ARM DDI 0439B, r0p1: Table 3-1,
//! "Cortex-M4 instruction set summary", and Table 7-1, "FPU instruction
//! set"), zero wait states:
//!
//! | instruction | cycles |
//! |---|---:|
//! | `VDIV.F32`, `VSQRT.F32` | 14 |
//! | `VMLA`, `VMLS`, `VNMLA`, `VNMLS`, `VFMA`, `VFMS`, `VFNMA`, `VFNMS` | 3 |
//! | single-register load (`LDR`, `LDRB`, `LDRH`, `LDRSB`, `LDRSH`, `LDREX*`, `VLDR` of an `s` register) | 2, or 1 right after another single-register load (pipelined) |
//! | register list (`LDM`, `STM`, `PUSH`, `POP`, `VLDM`, `VSTM`, `VPUSH`, `VPOP`) and two-register transfers (`LDRD`, `STRD`, `VLDR`/`VSTR` of a `d` register) | 1 + N, N the words moved (a `d` register is two) |
//! | taken branch: the next traced pc is not the fall-through address (`B<cc>`, `CBZ`/`CBNZ`, `BL`, `BLX`, `BX`, `POP`/`LDR`/`MOV` into `pc`, ...) | the instruction's own cycles + 2 (the pipeline refill P, 1 to 3 in the TRM) |
//! | everything else, stores of one register included (the write buffer takes them) | 1 |
//!
//! Sources and checks. The figures are the TRM's as reproduced in TI's
//! SWCU192 (CC13x2/CC26x2 Technical Reference Manual), Table 3-25 (the
//! Cortex-M4F instructions: 1 for ALU, `MUL` and `MLA`, 2 for a load,
//! 1 + N for lists, 1 + P for a taken branch, P = 1..3) and Table 3-27 (the
//! FPU: `VDIV` 14, the multiply-accumulate class and its fused forms 3,
//! `VLDR` 2 (3 for a double), `VLDM`/`VPOP` 1 + N floats or 1 + 2N
//! doubles), and its load/store timing notes (`STR` one cycle through the
//! write buffer; a load is pipelined with the load or store after it,
//! saving that one a cycle; `LDR pc` at least 5, `TBB`/`TBH` at least 6).
//! `VSQRT` 14: GCC's Cortex-M4 FPU pipeline description (`cortex-m4-fpu.md`)
//! reserves the FPU for the same 14 cycles for `fdivs` and `fsqrts`.
//! This is the model issue 11 names (VDIV 14, VMLA class 3, loads 2 or 1,
//! taken branches 3, the rest 1), with register lists at 1 + N.
//!
//! Not modelled, so a real part may differ either way: flash wait states
//! (an STM32F4's ART accelerator hides most of them on straight-line code),
//! the refill's 1-3 spread (alignment and width of the target), a load or
//! store whose address depends on the instruction before (+1), `VMOV`
//! between core and FPU registers (2 for a pair in Table 3-27), `SDIV`/`UDIV`
//! (2-12), `LDR pc` and `TBB`/`TBH` beyond the refill, integer instructions
//! that overlap a `VDIV` (they complete out of order), and conditional
//! instructions an `IT` block skips (priced as if executed; QEMU's trace
//! does not say).

/// What the model needs to know about one instruction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// `VDIV.F32`, `VSQRT.F32`.
    DivSqrt,
    /// The multiply-accumulate class, fused or not.
    MulAcc,
    /// A single-register load.
    Load,
    /// A register list or a two-register transfer of `words` words.
    Transfer { words: u64, load: bool },
    /// Everything else.
    Other,
}

/// `VDIV.F32`, `VSQRT.F32`.
pub const DIV_SQRT: u64 = 14;
/// The multiply-accumulate class.
pub const MUL_ACC: u64 = 3;
/// A single-register load; [`LOAD_PIPELINED`] right after another.
pub const LOAD: u64 = 2;
/// A single-register load right after another single-register load.
pub const LOAD_PIPELINED: u64 = 1;
/// The pipeline refill after a taken branch (P, 1 to 3 in the TRM).
pub const REFILL: u64 = 2;

/// The model in a few lines, for the printed output.
pub const SUMMARY: &str = "\
estimated cycles: Cortex-M4 TRM timings (ARM DDI 0439B, Tables 3-1 and 7-1, as reproduced in TI SWCU192 Tables 3-25/3-27; VSQRT as GCC's cortex-m4-fpu.md), zero wait states:
  VDIV/VSQRT 14; VMLA/VMLS/VNMLA/VNMLS/VFMA/VFMS/VFNMA/VFNMS 3; single-register loads (LDR*, VLDR) 2, 1 right after another (pipelined);
  LDM/STM/PUSH/POP/VLDM/VSTM/VPUSH/VPOP and LDRD/STRD 1 + words moved; a taken branch (next traced pc not the fall-through, POP/LDR into pc
  included) its own cycles + 2 (refill P, 1-3 in the TRM); the rest 1. Not modelled: flash wait states, address-dependency stalls,
  VMOV core<->FPU pairs (2), SDIV/UDIV (2-12), overlap with VDIV, IT-skipped instructions (priced as executed).";

/// The condition codes an `IT` block appends to a mnemonic.
const CONDITIONS: [&str; 17] = [
    "eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt", "gt", "le",
    "al",
];

const DIV_SQRT_OPS: [&str; 2] = ["vdiv", "vsqrt"];
const MUL_ACC_OPS: [&str; 8] = [
    "vmla", "vmls", "vnmla", "vnmls", "vfma", "vfms", "vfnma", "vfnms",
];
const LOAD_OPS: [&str; 13] = [
    "ldr", "ldrb", "ldrh", "ldrsb", "ldrsh", "ldrt", "ldrbt", "ldrht", "ldrsbt", "ldrsht", "ldrex",
    "ldrexb", "ldrexh",
];
const LIST_LOAD_OPS: [&str; 11] = [
    "ldm", "ldmia", "ldmfd", "ldmdb", "ldmea", "pop", "vldm", "vldmia", "vldmdb", "vpop", "ldrd",
];
const LIST_STORE_OPS: [&str; 11] = [
    "stm", "stmia", "stmea", "stmdb", "stmfd", "push", "vstm", "vstmia", "vstmdb", "vpush", "strd",
];

/// The mnemonic without its width or type suffix (`.w`, `.f32`) and
/// without the condition an `IT` block gave it (`ldrlo` -> `ldr`; `vmls`
/// stays `vmls`, it is a mnemonic of its own).
fn base(mnemonic: &str) -> &str {
    let m = mnemonic.split('.').next().unwrap_or(mnemonic);
    let known = |b: &str| {
        DIV_SQRT_OPS.contains(&b)
            || MUL_ACC_OPS.contains(&b)
            || LOAD_OPS.contains(&b)
            || b == "vldr"
            || b == "vstr"
            || LIST_LOAD_OPS.contains(&b)
            || LIST_STORE_OPS.contains(&b)
    };
    if known(m) {
        return m;
    }
    match m.len().checked_sub(2).map(|cut| m.split_at(cut)) {
        Some((head, cond)) if CONDITIONS.contains(&cond) && known(head) => head,
        _ => m,
    }
}

/// Words a register list `{r4, r5, lr}`, `{d8, d9}` or `{s0-s3}` moves
/// (a `d` register is two).
fn list_words(operands: &str) -> u64 {
    let inner = operands
        .split_once('{')
        .and_then(|(_, r)| r.split_once('}'))
        .map_or("", |(l, _)| l);
    let words = |r: &str| if r.starts_with('d') { 2 } else { 1 };
    let number = |r: &str| r.get(1..).and_then(|n| n.parse::<u64>().ok());
    inner
        .split(',')
        .map(str::trim)
        .filter(|r| !r.is_empty())
        .map(|r| match r.split_once('-') {
            Some((lo, hi)) => match (number(lo.trim()), number(hi.trim())) {
                (Some(a), Some(b)) if b >= a => (b - a + 1) * words(lo),
                _ => words(lo),
            },
            None => words(r),
        })
        .sum()
}

/// The class of an instruction from its disassembly (`vldr s0, [r6, #28]`).
pub fn classify(text: &str) -> Class {
    let mut parts = text.splitn(2, ' ');
    let mnemonic = parts.next().unwrap_or("").to_ascii_lowercase();
    let operands = parts.next().unwrap_or("").trim();
    let double = operands.starts_with('d');
    match base(&mnemonic) {
        b if DIV_SQRT_OPS.contains(&b) => Class::DivSqrt,
        b if MUL_ACC_OPS.contains(&b) => Class::MulAcc,
        "vldr" | "vstr" if double => Class::Transfer {
            words: 2,
            load: mnemonic.starts_with("vldr"),
        },
        "vldr" => Class::Load,
        b if LOAD_OPS.contains(&b) => Class::Load,
        "ldrd" | "strd" => Class::Transfer {
            words: 2,
            load: mnemonic.starts_with("ldrd"),
        },
        b if LIST_LOAD_OPS.contains(&b) => Class::Transfer {
            words: list_words(operands),
            load: true,
        },
        b if LIST_STORE_OPS.contains(&b) => Class::Transfer {
            words: list_words(operands),
            load: false,
        },
        _ => Class::Other,
    }
}

/// The model's state along a trace: whether the last instruction was a
/// single-register load (the next one then pipelines).
#[derive(Default)]
pub struct Model {
    after_load: bool,
}

impl Model {
    /// Cycles of the next executed instruction, of class `class`, `taken`
    /// when the instruction traced after it is not at its fall-through
    /// address.
    pub fn step(&mut self, class: Class, taken: bool) -> u64 {
        let own = match class {
            Class::DivSqrt => DIV_SQRT,
            Class::MulAcc => MUL_ACC,
            Class::Load if self.after_load => LOAD_PIPELINED,
            Class::Load => LOAD,
            Class::Transfer { words, .. } => 1 + words,
            Class::Other => 1,
        };
        self.after_load = class == Class::Load && !taken;
        own + if taken { REFILL } else { 0 }
    }
}

/// What a stretch of the trace executed, and the estimate of its cycles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    pub instructions: u64,
    pub cycles: u64,
    /// `VDIV.F32` and `VSQRT.F32`.
    pub div_sqrt: u64,
    /// Instructions that read memory (single loads, `LDRD`, lists).
    pub loads: u64,
    /// Taken branches (the next traced pc is not the fall-through).
    pub taken: u64,
}

impl Tally {
    /// Count one executed instruction that cost `cycles`.
    pub fn add(&mut self, class: Class, taken: bool, cycles: u64) {
        self.instructions += 1;
        self.cycles += cycles;
        self.div_sqrt += u64::from(class == Class::DivSqrt);
        self.loads += u64::from(matches!(
            class,
            Class::Load | Class::Transfer { load: true, .. }
        ));
        self.taken += u64::from(taken);
    }

    /// Estimated cycles per instruction.
    pub fn cpi(&self) -> f64 {
        self.cycles as f64 / self.instructions.max(1) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classes_from_the_disassembly() {
        assert_eq!(classify("vdiv.f32 s0, s2, s0"), Class::DivSqrt);
        assert_eq!(classify("vsqrt.f32 s0, s0"), Class::DivSqrt);
        assert_eq!(classify("vmla.f32 s0, s1, s2"), Class::MulAcc);
        assert_eq!(classify("vmls.f32 s0, s1, s2"), Class::MulAcc);
        assert_eq!(classify("vnmls.f32 s0, s1, s2"), Class::MulAcc);
        assert_eq!(classify("vfma.f32 s0, s1, s2"), Class::MulAcc);
        assert_eq!(classify("vmul.f32 s0, s1, s2"), Class::Other);
        assert_eq!(classify("ldr r6, [r7, #0x8]"), Class::Load);
        assert_eq!(classify("ldrlo r0, [r1]"), Class::Load);
        assert_eq!(classify("ldrsh.w r0, [r1, #2]"), Class::Load);
        assert_eq!(classify("vldr s0, [r6, #28]"), Class::Load);
        assert_eq!(classify("vldrlo s0, [r6, #28]"), Class::Load);
        assert_eq!(
            classify("vldr d0, [r0]"),
            Class::Transfer {
                words: 2,
                load: true
            }
        );
        assert_eq!(
            classify("ldrd r8, r2, [r6]"),
            Class::Transfer {
                words: 2,
                load: true
            }
        );
        assert_eq!(
            classify("strd r1, r1, [r0, #8]"),
            Class::Transfer {
                words: 2,
                load: false
            }
        );
        assert_eq!(
            classify("push {r4, r5, r6, r7, lr}"),
            Class::Transfer {
                words: 5,
                load: false
            }
        );
        assert_eq!(
            classify("pop.w {r8, r9, r10, r11}"),
            Class::Transfer {
                words: 4,
                load: true
            }
        );
        assert_eq!(
            classify("ldmne.w r0, {r1, r2, r3}"),
            Class::Transfer {
                words: 3,
                load: true
            }
        );
        assert_eq!(
            classify("vpush {d8, d9, d10, d11, d12, d13, d14, d15}"),
            Class::Transfer {
                words: 16,
                load: false
            }
        );
        assert_eq!(
            classify("vldmia r0!, {s0-s3}"),
            Class::Transfer {
                words: 4,
                load: true
            }
        );
        assert_eq!(classify("str r2, [sp, #0x34]"), Class::Other);
        assert_eq!(classify("vstr s0, [sp, #36]"), Class::Other);
        assert_eq!(classify("bls 0x1234 <f+0x10>"), Class::Other);
        assert_eq!(classify("bl 0x1234 <f>"), Class::Other);
        assert_eq!(classify("it ne"), Class::Other);
        assert_eq!(classify("vmovgt.f32 s0, s1"), Class::Other);
    }

    #[test]
    fn loads_pipeline_and_branches_refill() {
        let mut m = Model::default();
        assert_eq!(m.step(Class::Load, false), LOAD);
        assert_eq!(m.step(Class::Load, false), LOAD_PIPELINED);
        assert_eq!(m.step(Class::Other, false), 1);
        assert_eq!(m.step(Class::Load, false), LOAD);
        assert_eq!(m.step(Class::Other, true), 1 + REFILL);
        assert_eq!(m.step(Class::Load, false), LOAD);
        // pop {r4, r5, pc}: 1 + 3, then the refill.
        assert_eq!(
            m.step(
                Class::Transfer {
                    words: 3,
                    load: true
                },
                true
            ),
            4 + REFILL
        );
        assert_eq!(m.step(Class::Load, false), LOAD);
        assert_eq!(m.step(Class::DivSqrt, false), DIV_SQRT);
        assert_eq!(m.step(Class::MulAcc, false), MUL_ACC);
    }

    #[test]
    fn a_tally_counts_the_mix() {
        let mut t = Tally::default();
        t.add(Class::DivSqrt, false, 14);
        t.add(Class::Load, false, 2);
        t.add(
            Class::Transfer {
                words: 2,
                load: false,
            },
            false,
            3,
        );
        t.add(Class::Other, true, 3);
        assert_eq!(
            t,
            Tally {
                instructions: 4,
                cycles: 22,
                div_sqrt: 1,
                loads: 1,
                taken: 1
            }
        );
        assert_eq!(t.cpi(), 5.5);
    }
}
