#!/usr/bin/env bash
# Cargo runner for board builds (.cargo/board.toml): loads an ELF into an MPS2+ (AN386) board
# through a debug probe with `probe-rs run`, starts it, and prints its defmt log (RTT) decoded
# until Ctrl-C. The QEMU builds use firmware/qemu-run.sh instead.
#
#   cargo board-run                  # alias: builds the board firmware and runs it here
#   firmware/probe-run.sh ELF        # an ELF built before
#
# The chip is the board's, described in firmware/mps2-an386.yaml (probe-rs has no built-in
# target for it). Environment:
#   PROBE_RS_CHIP   another part from `probe-rs chip list`, e.g. when porting to an MCU with flash
#                   (its memory map must then be in memory.x too)
#   PROBE_RS_PROBE  which probe, when several are attached (probe-rs reads it)
set -euo pipefail

if [ $# -lt 1 ]; then
    echo "usage: $0 ELF [probe-rs run options...]" >&2
    exit 2
fi
if ! command -v probe-rs >/dev/null 2>&1; then
    echo "probe-run: probe-rs not found; install it with: cargo install probe-rs-tools --locked" >&2
    echo "(it takes 20+ minutes to build; CI never needs it)" >&2
    exit 127
fi
if [ -n "${PROBE_RS_CHIP:-}" ]; then
    exec probe-rs run --chip "$PROBE_RS_CHIP" "$@"
fi
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
exec probe-rs run --chip-description-path "$here/mps2-an386.yaml" --chip MPS2_AN386 "$@"
