#!/usr/bin/env bash
# Checks that a host build for a newer x86-64 level (x86-64-v3: AVX2, the SSE arithmetic in its
# VEX encoding) traces the same bits as the baseline build: every hit file of `raykernel trace`
# byte-identical, with the 4-wide and the 8-wide BVH (whose box test runs in 256-bit lanes
# there), in both modes, on the shared scenes' ray sets.
#
# usage: host/scripts/check_isa.sh RAYS_DIR
#
# RAYS_DIR as for check_trace.sh. Environment: HOST_BIN (the baseline binary; default: build
# target/release/raykernel), SCENES (default "bunny sponza kitchen"), SCENES_DIR (default
# ../shared/scenes beside the workspace), STRIDE (every STRIDE-th ray; default 8).
# Prints "skipped" and exits 0 on a CPU without AVX2 (the v3 binary could not run there).
set -euo pipefail

if [ $# -ne 1 ] || [ ! -d "$1" ]; then
    echo "usage: $0 RAYS_DIR  (make it with: python3 ../shared/bench/make_rays.py --out RAYS_DIR)" >&2
    exit 2
fi
rays_dir=$1
root=$(cd "$(dirname "$0")/../.." && pwd)
scenes=${SCENES:-bunny sponza kitchen}
stride=${STRIDE:-8}
scenes_dir=${SCENES_DIR:-$root/../shared/scenes}

if ! grep -qw avx2 /proc/cpuinfo 2>/dev/null; then
    echo "skipped: this CPU has no AVX2, so an x86-64-v3 build cannot run here"
    exit 0
fi
if [ -z "${HOST_BIN:-}" ]; then
    cargo build --quiet --release --manifest-path "$root/Cargo.toml" -p raykernel-host
    HOST_BIN=$root/target/release/raykernel
fi
v3_dir=$root/target/x86-64-v3
RUSTFLAGS="-C target-cpu=x86-64-v3" cargo build --quiet --release \
    --manifest-path "$root/Cargo.toml" -p raykernel-host --target-dir "$v3_dir"
v3_bin=$v3_dir/release/raykernel

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
failures=0
for scene in $scenes; do
    for kind in primary incoherent; do
        rays=$rays_dir/$scene.$kind.rays
        [ -f "$rays" ] || { echo "missing $rays" >&2; exit 2; }
        for mode in f32 fixed; do
            for accel in bvh4 bvh8; do
                "$HOST_BIN" trace -q --accel "$accel" --mode "$mode" --stride "$stride" \
                    --out "$out/base.hits" "$scenes_dir/$scene.obj" "$rays" >/dev/null
                "$v3_bin" trace -q --accel "$accel" --mode "$mode" --stride "$stride" \
                    --out "$out/v3.hits" "$scenes_dir/$scene.obj" "$rays" >/dev/null
                label="$scene $kind $mode $accel"
                if cmp -s "$out/base.hits" "$out/v3.hits"; then
                    echo "$label: x86-64-v3 build identical ($(($(stat -c %s "$out/base.hits") / 8)) rays)"
                else
                    echo "$label: x86-64-v3 build DIFFERS from the baseline" >&2
                    failures=$((failures + 1))
                fi
            done
        done
    done
done
[ "$failures" -eq 0 ]
