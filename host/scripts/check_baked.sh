#!/usr/bin/env bash
# Checks baked files on the shared scenes: for each scene, mode (f32, fixed) and tree (bvh,
# bvh4), `raykernel bake` then `raykernel trace-baked` (load in place, all checks, no build) must give
# hit files byte-identical to `raykernel trace` building the same tree in process.
#
# usage: host/scripts/check_baked.sh RAYS_DIR
#
# RAYS_DIR holds NAME.primary.rays and NAME.incoherent.rays, as written by
#   python3 ../shared/bench/make_rays.py --out RAYS_DIR suzanne
# Environment: SCENES (default "suzanne"), KINDS (default "primary incoherent"), SCENES_DIR
# (default ../shared/scenes beside the workspace), HOST_BIN (default target/release/raykernel).
set -euo pipefail

if [ $# -ne 1 ] || [ ! -d "$1" ]; then
    echo "usage: $0 RAYS_DIR" >&2
    exit 2
fi
rays_dir=$1
root=$(cd "$(dirname "$0")/../.." && pwd)
scenes=${SCENES:-suzanne}
kinds=${KINDS:-primary incoherent}
scenes_dir=${SCENES_DIR:-$root/../shared/scenes}
host=${HOST_BIN:-$root/target/release/raykernel}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
checked=0
for scene in $scenes; do
    for mode in f32 fixed; do
        for accel in bvh bvh4; do
            baked="$out/$scene.$mode.$accel.baked"
            "$host" bake "$scenes_dir/$scene.obj" --out "$baked" --accel "$accel" --mode "$mode" \
                | tail -n 1
            for kind in $kinds; do
                rays="$rays_dir/$scene.$kind.rays"
                "$host" trace "$scenes_dir/$scene.obj" "$rays" --out "$out/built.hits" \
                    --accel "$accel" --mode "$mode" >/dev/null
                "$host" trace-baked "$baked" "$rays" --out "$out/baked.hits" | tail -n 1
                if ! cmp -s "$out/built.hits" "$out/baked.hits"; then
                    echo "$scene $kind $mode $accel: baked hits differ from the built tree's" >&2
                    exit 1
                fi
                checked=$((checked + 1))
            done
        done
    done
done
echo "check_baked: $checked hit files of baked trees identical to the built trees'"
