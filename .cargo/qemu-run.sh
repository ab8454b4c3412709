#!/usr/bin/env bash
# Cargo runner for thumbv7em-none-eabihf: run the ELF on QEMU's mps2-an386
# (Cortex-M4 with FPU; or the machine QEMU_MACHINE names, e.g.
# netduinoplus2 for a firmware built with the board-f405 feature),
# semihosting on, one instruction = 32 ns of virtual time (-icount
# shift=5, deterministic), defmt log decoded by defmt-print. The exit code
# is the firmware's semihosting exit code. Arguments after the ELF go to
# QEMU (e.g. `-serial chardev:...` for the link firmware).
set -euo pipefail
elf="$1"
shift
machine="${QEMU_MACHINE:-mps2-an386}"
cpu=()
if [ "$machine" = "mps2-an386" ]; then
  cpu=(-cpu cortex-m4)
fi
qemu-system-arm "${cpu[@]}" -machine "$machine" -nographic \
  -semihosting-config enable=on,target=native -icount shift=5 \
  "$@" -kernel "$elf" | defmt-print -e "$elf"
