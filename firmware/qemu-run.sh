#!/usr/bin/env bash
# Cargo runner for thumbv7em-none-eabihf (.cargo/config.toml): boots an ELF in QEMU mps2-an386,
# decodes its defmt log (semihosting → QEMU's stdout) with defmt-print, and exits with QEMU's
# status, which is the firmware's semihosting exit status (0 ok, 1 panic/HardFault/test failure).
#
#   cargo run  --target thumbv7em-none-eabihf -p hemi-firmware     # the firmware, UART0 on a pty
#   cargo test --target thumbv7em-none-eabihf -p hemi-firmware     # on-target tests, UART0 unused
#
# Environment:
#   HEMI_QEMU_TIMEOUT  seconds before QEMU is killed (exit 124); 0 = none. Default: 120, and none
#                      for the firmware binary when stdin is a terminal (an interactive session).
#   HEMI_QEMU_SERIAL   QEMU -serial backend for UART0. Default: `pty` for the firmware binary
#                      (QEMU prints "char device redirected to /dev/pts/N"), `null` for tests
#                      and examples.
#   HEMI_QEMU          the qemu-system-arm to use.
#   HEMI_QEMU_ARGS     extra QEMU arguments, split on spaces (e.g. "-icount shift=0" for the
#                      `icount` example's calibration).
set -uo pipefail

if [ $# -lt 1 ]; then
    echo "usage: $0 ELF [args...]" >&2
    exit 2
fi
ELF="$1"
QEMU="${HEMI_QEMU:-qemu-system-arm}"

if ! command -v "$QEMU" >/dev/null 2>&1; then
    echo "qemu-run: $QEMU not found; install it with: apt-get install -y qemu-system-arm" >&2
    exit 127
fi
if ! command -v defmt-print >/dev/null 2>&1; then
    echo "qemu-run: defmt-print not found; install it with: cargo install defmt-print --locked" >&2
    exit 127
fi

# Only the firmware binary serves the link; test executables (target/<triple>/<profile>/deps/)
# and examples do not use UART0.
is_firmware=0
case "$ELF" in
    */deps/* | */examples/*) ;;
    */hemi-firmware) is_firmware=1 ;;
esac
if [ "$is_firmware" = 1 ]; then
    serial="${HEMI_QEMU_SERIAL:-pty}"
else
    serial="${HEMI_QEMU_SERIAL:-null}"
fi
if [ -n "${HEMI_QEMU_TIMEOUT:-}" ]; then
    secs="$HEMI_QEMU_TIMEOUT"
elif [ "$is_firmware" = 1 ] && [ -t 0 ]; then
    secs=0
else
    secs=120
fi

# With -serial pty, QEMU prints "char device redirected to /dev/pts/N (label serial0)" on stdout
# before the CPU starts, ahead of the binary defmt stream: pass that one line to stderr so the
# user sees it and defmt-print does not choke on it.
split_pty_line() {
    if [ "$serial" = pty ]; then
        IFS= read -r first && printf '%s\n' "$first" >&2
    fi
    cat
}

# --foreground keeps QEMU in the terminal's process group, so a Ctrl-C reaches it too (without
# it, timeout moves QEMU to a group of its own and Ctrl-C leaves it running).
timeout --foreground --kill-after=5 "$secs" "$QEMU" \
    -machine mps2-an386 -cpu cortex-m4 \
    -display none -monitor none \
    -semihosting-config enable=on,target=native \
    -serial "$serial" \
    -kernel "$ELF" \
    ${HEMI_QEMU_ARGS:-} \
    | split_pty_line | defmt-print -e "$ELF"
status=("${PIPESTATUS[@]}")
qemu_status="${status[0]}"
if [ "$qemu_status" = 124 ]; then
    echo "qemu-run: timed out after ${secs}s (HEMI_QEMU_TIMEOUT); the firmware never exited" >&2
elif [ "${status[2]}" != 0 ] && [ "$qemu_status" = 0 ]; then
    echo "qemu-run: defmt-print failed (status ${status[2]})" >&2
    exit "${status[2]}"
fi
exit "$qemu_status"
