//! The board the firmware is built for: one explicit choice, the feature
//! `board-f405` (an STM32F405, on QEMU's netduinoplus2) or none (the
//! emulated mps2-an386). A board is its memory map (chosen by `build.rs`
//! from the same feature), its core clock (SysTick's source, for the
//! instruction counter) and the QEMU machine `cargo xtask` runs it on.
//!
//! To add a board: a feature in `Cargo.toml` (implying `firmware`), its
//! memory map in `boards/` (beside `stm32f405.x`) and its arm in
//! `build.rs`, its constants here (and its feature in the default's
//! `not(any(...))`), and its QEMU machine in `xtask/src/firmware.rs`
//! (`Board`; `docs/VEHICLE.md`, "The firmware and the boards", lists every place).

/// The board's name, as the firmware logs it.
#[cfg(not(any(feature = "board-f405")))]
pub const NAME: &str = "mps2-an386";
/// The core clock, hertz: SysTick counts it.
#[cfg(not(any(feature = "board-f405")))]
pub const CORE_HZ: u64 = 25_000_000;

/// The board's name, as the firmware logs it.
#[cfg(feature = "board-f405")]
pub const NAME: &str = "stm32f405";
/// The core clock, hertz: SysTick counts it.
#[cfg(feature = "board-f405")]
pub const CORE_HZ: u64 = 168_000_000;
