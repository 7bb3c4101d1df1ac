#!/usr/bin/env python3
"""Recompute the benchmark's ratios from data.json's figure rows (no other input).

usage: ratios.py DATA_JSON [--figure closest_mrays] [--ours "raykernel bvh4 sah f32"]

Prints, per scene and ray set, ours / each peer for the chosen figure (default: the
per-ray closest-hit Mrays/s, the headline), then the median per-round ratios of the
interleaved rounds (ours per ray / Embree 3 HIGH and / Embree 3 HIGH robust, ours pre-built /
tinybvh).
"""
import argparse
import json
import re
import statistics
from collections import defaultdict


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("data")
    ap.add_argument("--figure", default="closest_mrays")
    ap.add_argument("--ours", default="raykernel bvh4 sah f32")
    args = ap.parse_args()
    with open(args.data) as f:
        rows = json.load(f)["figures"]
    value = {(r["scene"], r["rays"], r["contender"], r["figure"]): r["value"] for r in rows}
    sets = sorted({(r["scene"], r["rays"]) for r in rows if r["contender"] == args.ours},
                  key=lambda k: (k[0], k[1] != "primary"))
    peers = sorted({r["contender"] for r in rows
                    if not r["contender"].startswith("raykernel") and r["figure"] == args.figure})
    print(f"ours ({args.ours}) / peer, {args.figure}")
    print("scene,rays,peer,ours,peer_value,ratio")
    for scene, rays in sets:
        ours = value.get((scene, rays, args.ours, args.figure))
        for peer in peers:
            other = value.get((scene, rays, peer, args.figure))
            if ours and other:
                print(f"{scene},{rays},{peer},{ours:.3f},{other:.3f},{ours / other:.3f}")
    rounds = defaultdict(dict)
    pattern = re.compile(r"^(closest_mrays(?:_prebuilt)?)_round(\d+)$")
    for r in rows:
        m = pattern.match(r["figure"])
        if m:
            rounds[(r["scene"], r["rays"], r["contender"], m.group(1))][int(m.group(2))] = r["value"]
    pairs = [("closest_mrays", "Embree 3 HIGH", "closest_mrays"),
             ("closest_mrays", "Embree 3 HIGH robust", "closest_mrays"),
             ("closest_mrays_prebuilt", "tinybvh 1.6 BVH2", "closest_mrays_prebuilt")]
    print("\nper-round ratios (median, min, max)")
    print("scene,rays,pair,median,min,max")
    for scene, rays in sets:
        for ours_fig, peer, peer_fig in pairs:
            a = rounds.get((scene, rays, args.ours, ours_fig), {})
            b = rounds.get((scene, rays, peer, peer_fig), {})
            ratios = [a[k] / b[k] for k in sorted(a) if k in b and b[k] > 0]
            if ratios:
                print(f"{scene},{rays},{ours_fig} / {peer},{statistics.median(ratios):.3f},"
                      f"{min(ratios):.3f},{max(ratios):.3f}")


if __name__ == "__main__":
    main()
