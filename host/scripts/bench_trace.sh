#!/usr/bin/env bash
# Single-threaded trace benchmark on the shared scenes (WORKLOAD.md protocol: 3 full runs of
# build + trace in one process, medians). Prints a Markdown table with the machine line.
# `Mrays/s` is `host trace`'s per-ray figure (each ray constructed from its record in the timed
# loop); `pre-built` traces rays constructed ahead; `setup ns` is that construction per ray.
# usage: bench_trace.sh RAYS_DIR [extra trace flags...]
set -euo pipefail
rays=${1:?usage: bench_trace.sh RAYS_DIR [trace flags]}
shift
root=$(cd "$(dirname "$0")/../.." && pwd)
scenes=${SCENES_DIR:-$root/../shared/scenes}
host=$root/target/release/raykernel
cargo build --quiet --release -p raykernel-host --manifest-path "$root/Cargo.toml"
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')
echo "machine: $cpu, $(nproc) cores; $(rustc --version); single thread; flags: ${*:-(defaults)}"
echo
echo "| scene | rays | mode | build ms | Mrays/s | pre-built Mrays/s | setup ns/ray | nodes | bytes/tri | depth |"
echo "|---|---|---|---:|---:|---:|---:|---:|---:|---:|"
out=$(mktemp)
for scene in bunny sponza kitchen; do
    for kind in primary incoherent; do
        for mode in f32 fixed; do
            json=$("$host" trace "$scenes/$scene.obj" "$rays/$scene.$kind.rays" --out "$out" --mode "$mode" --runs 3 "$@" | tail -n 1)
            python3 - "$scene" "$kind" "$mode" "$json" <<'PY'
import json, sys
scene, kind, mode, j = sys.argv[1], sys.argv[2], sys.argv[3], json.loads(sys.argv[4])
print(f"| {scene} | {kind} | {mode} | {j['build_ms']:.1f} | {j['mrays_per_s']:.2f} | {j['mrays_per_s_prebuilt']:.2f} | {j['setup_ns_per_ray']:.1f} | {j['nodes']} | {j['bytes_per_tri']:.1f} | {j['depth']} |")
PY
        done
    done
done
rm -f "$out"
