#!/usr/bin/env bash
# Checks `raykernel trace` on the shared scenes: every BVH builder, the 4-wide and 8-wide BVHs, the
# uniform grid and the kd-tree against brute force, byte for byte.
#
# usage: host/scripts/check_trace.sh RAYS_DIR
#
# RAYS_DIR holds NAME.primary.rays and NAME.incoherent.rays, as written by
#   python3 ../shared/bench/make_rays.py --out RAYS_DIR bunny sponza kitchen
#
# For each scene, ray set and mode (f32, fixed):
#   - traces the whole file with each builder (sah, median, midpoint), the 4-wide and 8-wide BVHs
#     (SAH; the 8-wide by both walks, --coherent), the grid and the kd-tree, and checks the eight
#     hit files are identical;
#   - traces every STRIDE-th ray with --accel linear, each builder, the wide BVHs (the 8-wide by
#     both walks), the grid and the kd-tree, and checks each strided hit file equals the linear
#     one (cmp);
# then prints the fixed-vs-f32 agreement of the SAH primary hits per scene (compare-hits --scene
# --rays), which classifies every ray whose prim differs; any "unexplained" one (farther than the
# quantization bound from every edge of both triangles, and not a depth tie) is a failure.
# One summary line per run; exits non-zero if any pair of files that must match differs, or any
# fixed-vs-f32 difference is unexplained.
#
# Environment: STRIDE (default 64), SCENES (default "bunny sponza kitchen"),
# KINDS (default "primary incoherent"), SCENES_DIR (default ../shared/scenes beside the
# workspace), HOST_BIN (default: build and use target/release/raykernel), OUT (directory for hit
# files; default a temporary one, removed at the end).
set -euo pipefail

if [ $# -ne 1 ] || [ ! -d "$1" ]; then
    echo "usage: $0 RAYS_DIR  (make it with: python3 ../shared/bench/make_rays.py --out RAYS_DIR)" >&2
    exit 2
fi
rays_dir=$1
root=$(cd "$(dirname "$0")/../.." && pwd)
stride=${STRIDE:-64}
scenes=${SCENES:-bunny sponza kitchen}
kinds=${KINDS:-primary incoherent}
scenes_dir=${SCENES_DIR:-$root/../shared/scenes}
builders="sah median midpoint"
accels="bvh4 bvh8 grid kdtree"
modes="f32 fixed"

if [ -z "${HOST_BIN:-}" ]; then
    cargo build --quiet --release --manifest-path "$root/Cargo.toml" -p raykernel-host
    target_dir=$(cargo metadata --format-version 1 --no-deps --manifest-path "$root/Cargo.toml" |
        python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
    HOST_BIN=$target_dir/release/raykernel
fi
if [ -n "${OUT:-}" ]; then
    out=$OUT
    mkdir -p "$out"
else
    out=$(mktemp -d)
    trap 'rm -rf "$out"' EXIT
fi

failures=0

# trace LABEL OUT_FILE ARGS...: runs `raykernel trace`, prints one summary line from its JSON.
trace() {
    local label=$1 hits=$2
    shift 2
    local json
    json=$("$HOST_BIN" trace "$@" --out "$hits" | tail -n 1)
    python3 -c '
import json, sys
r = json.loads(sys.argv[2])
print("%-44s rays=%-8d hits=%-8d bad=%d build=%8.1f ms trace=%9.1f ms %7.3f Mrays/s nodes=%d depth=%d B/tri=%.1f" % (
    sys.argv[1], r["rays"], r["hits"], r["bad_rays"], r["build_ms"], r["trace_ms"],
    r["mrays_per_s"], r["nodes"], r["depth"], r["bytes_per_tri"]))' "$label" "$json"
}

# same LABEL A B: cmp two hit files, report and count a difference.
same() {
    if cmp -s "$2" "$3"; then
        printf '%-44s identical\n' "$1"
    else
        printf '%-44s DIFFERENT: %s\n' "$1" "$(cmp "$2" "$3" 2>&1 | head -n 1)"
        failures=$((failures + 1))
    fi
}

for scene in $scenes; do
    obj=$scenes_dir/$scene.obj
    for kind in $kinds; do
        rays=$rays_dir/$scene.$kind.rays
        for mode in $modes; do
            tag=$scene.$kind.$mode
            for b in $builders; do
                trace "$tag $b" "$out/$tag.$b.hits" "$obj" "$rays" --mode "$mode" --accel bvh --builder "$b"
            done
            for a in $accels; do
                trace "$tag $a" "$out/$tag.$a.hits" "$obj" "$rays" --mode "$mode" --accel "$a"
            done
            trace "$tag bvh8-coherent" "$out/$tag.bvh8-coherent.hits" "$obj" "$rays" \
                --mode "$mode" --accel bvh8 --coherent
            for b in median midpoint $accels bvh8-coherent; do
                same "$tag $b == sah (full)" "$out/$tag.$b.hits" "$out/$tag.sah.hits"
            done
            trace "$tag linear /$stride" "$out/$tag.linear.s$stride.hits" "$obj" "$rays" \
                --mode "$mode" --accel linear --stride "$stride"
            for b in $builders; do
                trace "$tag $b /$stride" "$out/$tag.$b.s$stride.hits" "$obj" "$rays" \
                    --mode "$mode" --accel bvh --builder "$b" --stride "$stride"
                same "$tag $b == linear (/$stride)" "$out/$tag.$b.s$stride.hits" \
                    "$out/$tag.linear.s$stride.hits"
            done
            for a in $accels; do
                trace "$tag $a /$stride" "$out/$tag.$a.s$stride.hits" "$obj" "$rays" \
                    --mode "$mode" --accel "$a" --stride "$stride"
                same "$tag $a == linear (/$stride)" "$out/$tag.$a.s$stride.hits" \
                    "$out/$tag.linear.s$stride.hits"
            done
            trace "$tag bvh8-coherent /$stride" "$out/$tag.bvh8-coherent.s$stride.hits" "$obj" \
                "$rays" --mode "$mode" --accel bvh8 --coherent --stride "$stride"
            same "$tag bvh8-coherent == linear (/$stride)" \
                "$out/$tag.bvh8-coherent.s$stride.hits" "$out/$tag.linear.s$stride.hits"
            # Keep only what the agreement report below needs.
            rm -f "$out/$tag.median.hits" "$out/$tag.midpoint.hits" "$out/$tag".*.s"$stride".hits \
                "$out/$tag.bvh4.hits" "$out/$tag.bvh8.hits" "$out/$tag.bvh8-coherent.hits" \
                "$out/$tag.grid.hits" \
                "$out/$tag.kdtree.hits"
        done
    done
done

case " $kinds " in
*" primary "*)
    echo
    echo "fixed vs f32, SAH, primary rays (reference f32); every ray whose prim differs must pass"
    echo "within the fixed-point quantization bound of an edge, or of the other triangle (depth tie):"
    for scene in $scenes; do
        json=$("$HOST_BIN" compare-hits "$out/$scene.primary.f32.sah.hits" \
            "$out/$scene.primary.fixed.sah.hits" \
            --scene "$scenes_dir/$scene.obj" --rays "$rays_dir/$scene.primary.rays" | tail -n 1)
        printf '%-10s %s\n' "$scene" "$json"
        unexplained=$(python3 -c 'import json, sys; print(json.loads(sys.argv[1])["unexplained"])' "$json")
        if [ "$unexplained" -gt 0 ]; then
            printf '%-10s UNEXPLAINED: %s rays differ between f32 and fixed beyond quantization\n' \
                "$scene" "$unexplained"
            failures=$((failures + 1))
        fi
    done
    ;;
esac

echo
if [ "$failures" -gt 0 ]; then
    echo "check_trace: $failures comparison(s) DIFFERENT or UNEXPLAINED" >&2
    exit 1
fi
echo "check_trace: all BVH, wide BVH, grid and kd-tree hit files match brute force (stride $stride) and each other;" \
    "fixed vs f32 differences are all within quantization"
