#!/usr/bin/env bash
# Builds the firmware example around a baked mesh and runs it under QEMU (Cortex-M4F,
# mps2-an386): prints the check grid's hash and the render check tile's hashes (the firmware
# itself fails if a tile differs from the kernel's, render_golden.h). --gc-sections links only
# the functions the firmware calls. Usage: build.sh BAKED_FILE [EXPECTED_HASH]
# From the repository root; needs arm-none-eabi-gcc, qemu-system-arm and the thumbv7em target.
set -euo pipefail
baked=$1
expect=${2:-}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
out=$(mktemp -d)
cp "$baked" "$out/mesh.bin"
cargo build -p raykernel-c --release --target thumbv7em-none-eabihf
arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -O2 -std=c11 \
    -ffp-contract=off -ffreestanding -nostdlib -Wall -Wextra -Werror -Wl,--gc-sections \
    -I "$root/capi/include" -I "$root/capi/examples/common" -Wa,-I,"$out" \
    -T "$here/link.ld" "$here/startup.c" "$here/main.c" "$here/mesh.S" \
    "$root/target/thumbv7em-none-eabihf/release/libraykernel_c.a" -lgcc \
    -o "$out/firmware.elf"
arm-none-eabi-size "$out/firmware.elf"
status=0
output=$(timeout 120 qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic -monitor none \
    -semihosting-config enable=on,target=native -kernel "$out/firmware.elf" 2>&1) || status=$?
echo "$output"
rm -rf "$out"
if [ "$status" -ne 0 ]; then
    echo "firmware failed (exit $status)" >&2
    exit 1
fi
if [ -n "$expect" ] && ! grep -q "grid_hash 0x$expect" <<<"$output"; then
    echo "firmware hash differs from raykernel bake's ($expect)" >&2
    exit 1
fi
