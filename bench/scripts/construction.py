#!/usr/bin/env python3
"""Ray construction per ray, before and after, measured in one alternating run.

usage: construction.py --rays DIR [--before-rev REV] [--before-bin BIN] [--after-bin BIN]
                       [--scenes DIR] [--city-dir DIR] [--stride 8] [--runs 3] [--rounds 3]
                       [--out docs/bench/CONSTRUCTION.md]

Runs `trace` of two builds of the CLI in alternation (before, after, before, ...) on every
scene, ray set and mode, with the 4-wide BVH from the SAH BVH, and writes a Markdown table.
`--before-bin` defaults to a build of `--before-rev` (default f5262d3, the last commit whose
`f32` rays were set up in `f64`), made in a temporary git worktree with the current
`prepare_rays` (and the helpers it calls) spliced in; `--after-bin` defaults to
`target/release/raykernel`. Both builds then time ray construction the same way (every
traced record turned into a kernel ray and stored into a vector touched beforehand, timed apart
from tracing), so the "construction" columns compare the kernels' constructors; "in the loop"
is what the current per-ray loop pays over tracing pre-built rays (per ray minus pre-built),
which the before build cannot measure (it had no per-ray loop: a caller paid construction plus
tracing).
"""
import argparse
import glob
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
from datetime import date

SCENES = ["bunny", "sponza", "kitchen"]


def cpu_name():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


# The harness that times construction, spliced from the current host into the before build's
# trace.rs: `prepare_rays`, the helpers it calls, and `every`, which gathers the traced records
# as the current callers do (each inserted before `prepare_rays` where the before build lacks
# it), each with the host file it comes from.
HARNESS = [("prepare_rays", "trace.rs"), ("placeholder", "trace.rs"), ("every", "rayfile.rs")]

# The before build's calls `prepare_rays::<S>(records, stride)`; the current one takes the
# traced records, gathered first.
OLD_CALL = re.compile(r"prepare_rays::<(\w+)>\(([^,()]+), ([^()]+)\)")


def gather_at_calls(text):
    """`text` with every two-argument call of `prepare_rays` given `every`'s records instead."""
    return OLD_CALL.sub(r"prepare_rays::<\1>(&crate::trace::every(\2, \3))", text)


def function_span(text, name):
    """The function `name` in `text` (a host source file) as (start, end) offsets, or None."""
    for prefix in ("pub fn ", "fn "):
        for after in ("<", "("):
            start = text.find(f"\n{prefix}{name}{after}")
            if start >= 0:
                end = text.find("\n}\n", start)
                return start + 1, end + 3
    return None


def splice_harness(current, old, path):
    """`old` with the current harness functions in place of its own; `current` maps each host
    file name to its current text."""
    for name, source in HARNESS:
        span = function_span(current[source], name)
        if span is None:
            sys.exit(f"no {name} in the current host's {source}")
        body = current[source][span[0]:span[1]]
        mine = function_span(old, name)
        if mine is not None:
            old = old[:mine[0]] + body + old[mine[1]:]
        else:
            at = function_span(old, HARNESS[0][0])
            if at is None:
                sys.exit(f"no {HARNESS[0][0]} in {path}")
            old = old[:at[0]] + body + "\n" + old[at[0]:]
    return old


def build_before(rev, repo):
    """Builds the CLI at `rev` in a temporary worktree, with the current harness that times
    construction spliced in ([`HARNESS`]), so both builds time it alike; returns the binary's
    path."""
    work = tempfile.mkdtemp(prefix="raykernel-before-")
    tree = os.path.join(work, "tree")
    target = os.path.join(work, "target")
    subprocess.run(["git", "-C", repo, "worktree", "add", "-q", "--detach", tree, rev], check=True)
    try:
        current = {}
        for _, source in HARNESS:
            with open(os.path.join(repo, "host/src", source)) as f:
                current[source] = f.read()
        old_path = os.path.join(tree, "host/src/trace.rs")
        with open(old_path) as f:
            old = f.read()
        with open(old_path, "w") as f:
            f.write(splice_harness(current, old, old_path))
        for path in glob.glob(os.path.join(tree, "host/src/**/*.rs"), recursive=True):
            with open(path) as f:
                text = f.read()
            if OLD_CALL.search(text):
                with open(path, "w") as f:
                    f.write(gather_at_calls(text))
        subprocess.run(["cargo", "build", "--release", "-q", "-p", "raykernel-host"],
                       cwd=tree, env={**os.environ, "CARGO_TARGET_DIR": target}, check=True)
    finally:
        subprocess.run(["git", "-C", repo, "worktree", "remove", "--force", tree], check=False)
    for name in ("raykernel", "host"):
        path = os.path.join(target, "release", name)
        if os.path.exists(path):
            return path
    sys.exit(f"no CLI binary in {target}/release after building {rev}")


def trace(binary, scene, rays, mode, stride, runs):
    """One `trace` run; returns its JSON summary."""
    out = tempfile.NamedTemporaryFile(suffix=".hits", delete=False).name
    cmd = [binary, "trace", scene, rays, "--out", out, "--mode", mode, "--accel", "bvh4",
           "--stride", str(stride), "--runs", str(runs)]
    res = subprocess.run(cmd, capture_output=True, text=True, check=True)
    os.unlink(out)
    lines = [l for l in res.stdout.splitlines() if l.startswith("{")]
    if not lines:
        sys.exit(f"no JSON from {' '.join(cmd)}")
    return json.loads(lines[-1])


def ns(ms, rays):
    return ms * 1e6 / rays


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rays", required=True, help="ray files from make_rays.py --out DIR")
    ap.add_argument("--scenes", default="../shared/scenes")
    ap.add_argument("--city-dir", help="city.obj and its ray files (make_tiled.py, make_rays.py)")
    ap.add_argument("--before-rev", default="f5262d3")
    ap.add_argument("--before-bin")
    ap.add_argument("--after-bin", default="target/release/raykernel")
    ap.add_argument("--stride", type=int, default=8)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--out", default="docs/bench/CONSTRUCTION.md")
    args = ap.parse_args()

    repo = subprocess.run(["git", "rev-parse", "--show-toplevel"], capture_output=True,
                          text=True, check=True).stdout.strip()
    after_rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                               text=True, check=True).stdout.strip()
    before = args.before_bin or build_before(args.before_rev, repo)
    after = args.after_bin
    if not os.path.exists(after):
        sys.exit(f"{after} not found: cargo build --release -p raykernel-host")

    sets = [(s, os.path.join(args.scenes, f"{s}.obj"), args.rays) for s in SCENES]
    if args.city_dir:
        sets.append(("city", os.path.join(args.city_dir, "city.obj"), args.city_dir))
    rows = []
    for name, obj, ray_dir in sets:
        for kind in ("primary", "incoherent"):
            rays = os.path.join(ray_dir, f"{name}.{kind}.rays")
            if not (os.path.exists(obj) and os.path.exists(rays)):
                print(f"skipped: {name} {kind} ({obj} or {rays} missing)", file=sys.stderr)
                continue
            for mode in ("f32", "fixed"):
                b_setup, a_setup, ratio, a_loop, b_total, a_per_ray = [], [], [], [], [], []
                for _ in range(args.rounds):
                    b = trace(before, obj, rays, mode, args.stride, args.runs)
                    a = trace(after, obj, rays, mode, args.stride, args.runs)
                    n = a["rays"]
                    bs, as_ = ns(b["setup_ms"], b["rays"]), ns(a["setup_ms"], n)
                    b_setup.append(bs)
                    a_setup.append(as_)
                    ratio.append(as_ / bs)
                    a_loop.append(ns(a["per_ray_ms"] - a["trace_ms"], n))
                    b_total.append(ns(b["setup_ms"] + b["trace_ms"], b["rays"]))
                    a_per_ray.append(ns(a["per_ray_ms"], n))
                med = statistics.median
                rows.append((name, kind, mode, med(b_setup), med(a_setup), med(ratio),
                             med(a_loop), med(b_total), med(a_per_ray)))
                print(name, kind, mode, [round(x, 1) for x in rows[-1][3:]], file=sys.stderr)

    lines = [
        "# Ray construction, before and after",
        "",
        f"machine: {cpu_name()}, {os.cpu_count()} cores; date: {date.today().isoformat()}",
        "",
        f"- command: `python3 bench/scripts/construction.py --rays {args.rays}"
        + (f" --city-dir {args.city_dir}" if args.city_dir else "")
        + f" --stride {args.stride} --runs {args.runs} --rounds {args.rounds}`",
        f"- before: the CLI built at `{args.before_rev}` (`f32` rays normalised in `f64`); "
        f"after: the CLI built at `{after_rev}`",
        f"- 4-wide BVH from the SAH BVH, every {args.stride}th ray, {args.rounds} rounds "
        f"alternating before and after, each the median of {args.runs} runs; the table gives "
        "medians over the rounds (the ratio is the median of per-round ratios)",
        "",
        "`construction` is the current `prepare_rays` in both builds (spliced into the before "
        "build): every record turned into a kernel ray and stored into a vector whose pages "
        "were touched beforehand, timed apart from tracing. `in the loop` is what the "
        "current per-ray loop pays for construction: per ray minus pre-built, both traced in "
        "the same run. `per ray` is what a caller pays per query: before, construction and "
        "tracing one after the other (the before build had no per-ray loop); after, the "
        "per-ray loop.",
        "",
        "| scene | rays | mode | construction before ns | construction after ns | after ÷ before "
        "| in the loop after ns | per ray before ns | per ray after ns |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for (name, kind, mode, bs, as_, r, loop, bt, apr) in rows:
        lines.append(f"| {name} | {kind} | {mode} | {bs:.1f} | {as_:.1f} | {r:.2f}× "
                     f"| {loop:.1f} | {bt:.1f} | {apr:.1f} |")
    with open(args.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"wrote {args.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
