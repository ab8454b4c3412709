#!/usr/bin/env bash
# Cargo runner for thumbv7em-none-eabihf: run the ELF on QEMU's mps2-an386
# (Cortex-M4 with FPU), semihosting on, one instruction = 32 ns of virtual
# time (-icount shift=5, deterministic), defmt log decoded by defmt-print.
# The exit code is the firmware's semihosting exit code. Arguments after
# the ELF go to QEMU (e.g. `-serial chardev:...` for the link firmware).
set -euo pipefail
elf="$1"
shift
qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
  -semihosting-config enable=on,target=native -icount shift=5 \
  "$@" -kernel "$elf" | defmt-print -e "$elf"
