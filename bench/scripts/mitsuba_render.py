#!/usr/bin/env python3
"""Renders a raykernel scene file with Mitsuba 3 (variant scalar_rgb), an independent path tracer.

Usage: mitsuba_render.py SCENE.json OUT_DIR --spp 1,2,4 --reference-spp N [--reference-threads K]

The scene may hold only what both renderers describe the same way: diffuse materials (two-sided,
as raykernel's surfaces are), triangle objects without motion, `rect` lights, a pinhole camera, the
box filter and the `path` integrator. Anything else is an error, not an approximation.

Each sample count renders single-threaded with Mitsuba's `independent` sampler, and each power
of 4 from 4 on with its `ldsampler` (low discrepancy, which takes only those), timed around `mi.render` (after an untimed warm-up); the reference renders with
`--reference-threads`, untimed. Images go to OUT_DIR as raw little-endian float32 RGB, rows top to
bottom; OUT_DIR/mitsuba.json lists them with their timings and Mitsuba's version.
"""

import argparse
import json
import sys
import time
from pathlib import Path

# Each sampler and the sample counts it takes as given (ldsampler rounds others, 1 included, up).
SAMPLERS = {
    "independent": lambda spp: True,
    "ldsampler": lambda spp: spp >= 4 and (spp & (spp - 1)) == 0 and (spp.bit_length() - 1) % 2 == 0,
}


def fail(msg):
    print(f"mitsuba_render.py: {msg}", file=sys.stderr)
    sys.exit(2)


def write_obj(path, triangles):
    """Triangles as an OBJ of unshared vertices (three per triangle, as raykernel keeps them)."""
    lines = []
    for t in triangles:
        for p in t:
            lines.append("v %r %r %r" % tuple(float(x) for x in p))
    for k in range(len(triangles)):
        lines.append(f"f {3 * k + 1} {3 * k + 2} {3 * k + 3}")
    path.write_text("\n".join(lines) + "\n")


def rect_light(mi, rect):
    """raykernel's `rect` light (corner + a·edge_u + b·edge_v, emitting towards edge_u × edge_v)
    as Mitsuba's rectangle ([-1, 1]², normal +z) with an area emitter."""
    import numpy as np

    c = np.asarray(rect["corner"], dtype=np.float64)
    u = np.asarray(rect["edge_u"], dtype=np.float64)
    v = np.asarray(rect["edge_v"], dtype=np.float64)
    n = np.cross(u, v)
    n /= np.linalg.norm(n)
    m = np.identity(4)
    m[:3, 0] = u / 2
    m[:3, 1] = v / 2
    m[:3, 2] = n
    m[:3, 3] = c + u / 2 + v / 2
    return {
        "type": "rectangle",
        "to_world": mi.ScalarTransform4f(m.tolist()),
        "emitter": {"type": "area", "radiance": {"type": "rgb", "value": rect["radiance"]}},
    }


def scene_dict(mi, scene, sampler, spp, mesh_dir):
    cam = scene["camera"]
    settings = scene.get("settings", {})
    if cam.get("aperture_radius", 0.0) != 0.0:
        fail("a thin-lens camera is not compared (set aperture_radius to 0)")
    if settings.get("integrator") != "path":
        fail("only the path integrator is compared")
    if settings.get("filter", "box") != "box":
        fail("only the box filter is compared")
    materials = {}
    for m in scene["materials"]:
        if set(m) != {"name", "diffuse"}:
            fail(f"material {m['name']!r}: only diffuse materials are compared")
        materials[m["name"]] = {
            "type": "twosided",
            "bsdf": {
                "type": "diffuse",
                "reflectance": {"type": "rgb", "value": m["diffuse"]["albedo"]},
            },
        }
    d = {
        "type": "scene",
        "integrator": {
            "type": "path",
            "max_depth": settings.get("max_path_length", 5),
            "hide_emitters": False,
        },
        "sensor": {
            "type": "perspective",
            "fov": cam["vfov_deg"],
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=cam["eye"], target=cam["look_at"], up=cam["up"]
            ),
            "film": {
                "type": "hdrfilm",
                "width": settings["width"],
                "height": settings["height"],
                "pixel_format": "rgb",
                "rfilter": {"type": "box"},
            },
            "sampler": {"type": sampler, "sample_count": spp},
        },
    }
    for i, o in enumerate(scene["objects"]):
        if set(o) - {"material", "triangles"} or "triangles" not in o:
            fail(f"object {i}: only static triangle objects are compared")
        path = mesh_dir / f"object{i}.obj"
        if not path.exists():
            write_obj(path, o["triangles"])
        d[f"object{i}"] = {
            "type": "obj",
            "filename": str(path),
            "face_normals": True,
            "bsdf": materials[o["material"]],
        }
    for i, light in enumerate(scene.get("lights", [])):
        if set(light) != {"rect"}:
            fail(f"light {i}: only rect lights are compared")
        d[f"light{i}"] = rect_light(mi, light["rect"])
    bg = scene.get("background", [0.0, 0.0, 0.0])
    if any(bg):
        d["background"] = {"type": "constant", "radiance": {"type": "rgb", "value": bg}}
    return d


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", type=Path)
    ap.add_argument("out", type=Path)
    ap.add_argument("--spp", required=True)
    ap.add_argument("--reference-spp", type=int, required=True)
    ap.add_argument("--reference-threads", type=int, default=1)
    args = ap.parse_args()
    try:
        import drjit as dr
        import mitsuba as mi
        import numpy as np
    except ImportError as e:
        fail(f"cannot import Mitsuba 3 ({e}): pip install mitsuba")
    mi.set_variant("scalar_rgb")
    scene = json.loads(args.scene.read_text())
    args.out.mkdir(parents=True, exist_ok=True)

    def render(sampler, spp, threads, name):
        dr.set_thread_count(threads)
        s = mi.load_dict(scene_dict(mi, scene, sampler, spp, args.out))
        start = time.perf_counter()
        img = mi.render(s, spp=spp, seed=0)
        seconds = time.perf_counter() - start
        arr = np.asarray(img, dtype=np.float32)
        if arr.shape != (scene["settings"]["height"], scene["settings"]["width"], 3):
            fail(f"unexpected image shape {arr.shape}")
        arr.astype("<f4").tofile(args.out / name)
        return seconds

    render("independent", 1, 1, "warmup.f32")
    out = {"version": mi.__version__, "renders": []}
    spps = [int(x) for x in args.spp.split(",")]
    for sampler, takes in SAMPLERS.items():
        for spp in filter(takes, spps):
            name = f"mitsuba_{sampler}_{spp}.f32"
            seconds = render(sampler, spp, 1, name)
            out["renders"].append({"sampler": sampler, "spp": spp, "seconds": seconds, "file": name})
    name = f"mitsuba_reference_{args.reference_spp}.f32"
    render("independent", args.reference_spp, args.reference_threads, name)
    out["reference"] = {"sampler": "independent", "spp": args.reference_spp, "file": name}
    (args.out / "mitsuba.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
