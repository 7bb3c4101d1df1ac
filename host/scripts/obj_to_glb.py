#!/usr/bin/env python3
"""Convert an OBJ mesh to a binary glTF 2.0 file (.glb), standard library only.

The mesh keeps its vertices in model space; the node that places it gets the --scale and
--translate given (a node transform, as glTF files commonly have). Faces are fan-triangulated in
file order, as the host's OBJ reader does, so triangle i of the .glb is triangle i of the OBJ.
One material: --albedo as its base colour factor (default 0.73, the host's white for OBJ
meshes, so an untransformed .glb renders like its OBJ). With --camera FILE (the shared
benchmark's `.camera` format: eye, target, up, vfov lines) the file also gets a perspective
camera node looking as that camera does.

Example: python3 host/scripts/obj_to_glb.py ../shared/scenes/bunny.obj \
    --camera ../shared/scenes/bunny.camera --out bunny.glb
"""

import argparse
import json
import math
import struct
import sys


def read_obj(path):
    """Vertex positions and fan-triangulated faces (0-based indices)."""
    positions, triangles = [], []
    with open(path, "rb") as f:
        data = f.read()
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    for line_no, raw in enumerate(data.split(b"\n"), 1):
        words = raw.split(b"#", 1)[0].split()
        if not words:
            continue
        if words[0] == b"v":
            if len(words) not in (4, 5, 7):
                sys.exit(f"{path}:{line_no}: vertex needs 3, 4 or 6 numbers")
            positions.append(tuple(float(w) for w in words[1:4]))
        elif words[0] == b"f":
            face = []
            for entry in words[1:]:
                i = int(entry.split(b"/")[0])
                face.append(i - 1 if i > 0 else len(positions) + i)
            if len(face) < 3:
                sys.exit(f"{path}:{line_no}: face needs 3 vertices")
            for k in range(1, len(face) - 1):
                triangles.append((face[0], face[k], face[k + 1]))
    for t in triangles:
        for i in t:
            if not 0 <= i < len(positions):
                sys.exit(f"{path}: vertex index {i + 1} out of range")
    if not triangles:
        sys.exit(f"{path}: no faces")
    return positions, triangles


def read_camera(path):
    cam = {}
    with open(path, encoding="utf-8-sig") as f:
        for raw in f:
            words = raw.split("#", 1)[0].split()
            if words:
                cam[words[0]] = [float(w) for w in words[1:]]
    for key in ("eye", "target", "up", "vfov"):
        if key not in cam:
            sys.exit(f"{path}: no `{key}` line")
    return cam


def sub(a, b):
    return [a[k] - b[k] for k in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def normalize(a):
    n = math.sqrt(sum(x * x for x in a))
    return [x / n for x in a]


def camera_matrix(cam):
    """Column-major world matrix of a glTF camera (it looks down its -z, +y up)."""
    eye = cam["eye"]
    fwd = normalize(sub(cam["target"], eye))
    right = normalize(cross(fwd, cam["up"]))
    up = cross(right, fwd)
    back = [-x for x in fwd]
    return right + [0.0] + up + [0.0] + back + [0.0] + list(eye) + [1.0]


def padded(data, fill):
    return data + fill * (-len(data) % 4)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("obj")
    ap.add_argument("--out", required=True)
    ap.add_argument("--camera")
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--translate", type=float, nargs=3, default=[0.0, 0.0, 0.0])
    ap.add_argument("--albedo", type=float, nargs=3, default=[0.73, 0.73, 0.73])
    args = ap.parse_args()

    positions, triangles = read_obj(args.obj)
    pos_bytes = b"".join(struct.pack("<3f", *p) for p in positions)
    idx_bytes = b"".join(struct.pack("<3I", *t) for t in triangles)
    binary = padded(pos_bytes, b"\0") + idx_bytes
    # float32 bounds, as the accessor's min/max must be.
    as_f32 = [struct.unpack("<3f", struct.pack("<3f", *p)) for p in positions]
    lo = [min(p[k] for p in as_f32) for k in range(3)]
    hi = [max(p[k] for p in as_f32) for k in range(3)]

    mesh_node = {"mesh": 0}
    if args.scale != 1.0:
        mesh_node["scale"] = [args.scale] * 3
    if args.translate != [0.0, 0.0, 0.0]:
        mesh_node["translation"] = args.translate
    doc = {
        "asset": {"version": "2.0", "generator": "raykernel host/scripts/obj_to_glb.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [mesh_node],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "materials": [
            {
                "name": "obj",
                "pbrMetallicRoughness": {"baseColorFactor": args.albedo + [1.0], "metallicFactor": 0.0},
            }
        ],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(pos_bytes), "target": 34962},
            {
                "buffer": 0,
                "byteOffset": len(padded(pos_bytes, b"\0")),
                "byteLength": len(idx_bytes),
                "target": 34963,
            },
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5125, "count": 3 * len(triangles), "type": "SCALAR"},
        ],
    }
    if args.camera:
        cam = read_camera(args.camera)
        doc["cameras"] = [
            {"type": "perspective",
             "perspective": {"yfov": math.radians(cam["vfov"][0]), "znear": 1e-3}}
        ]
        doc["nodes"].append({"camera": 0, "matrix": camera_matrix(cam)})
        doc["scenes"][0]["nodes"].append(1)

    json_chunk = padded(json.dumps(doc, separators=(",", ":")).encode(), b" ")
    bin_chunk = padded(binary, b"\0")
    total = 12 + 8 + len(json_chunk) + 8 + len(bin_chunk)
    with open(args.out, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, total))
        f.write(struct.pack("<I4s", len(json_chunk), b"JSON") + json_chunk)
        f.write(struct.pack("<I4s", len(bin_chunk), b"BIN\0") + bin_chunk)
    print(f"{args.out}: {len(positions)} vertices, {len(triangles)} triangles")


if __name__ == "__main__":
    main()
