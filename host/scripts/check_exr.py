#!/usr/bin/env python3
"""Check that an OpenEXR file holds the same linear values as a PFM, bit for bit.

Usage: python3 host/scripts/check_exr.py IMAGE.exr IMAGE.pfm
Reads the EXR with the OpenEXR Python bindings (`pip install openexr`) and the PFM with numpy;
exits 0 when every R, G, B value is the same 32-bit float, 1 otherwise.
"""

import sys

import numpy as np
import OpenEXR


def read_pfm(path):
    with open(path, "rb") as f:
        data = f.read()
    header, rest = data.split(b"\n", 1)
    size, rest = rest.split(b"\n", 1)
    scale, pixels = rest.split(b"\n", 1)
    if header != b"PF":
        sys.exit(f"{path}: not a colour PFM")
    width, height = (int(x) for x in size.split())
    dtype = "<f4" if float(scale) < 0 else ">f4"
    image = np.frombuffer(pixels, dtype=dtype, count=width * height * 3).reshape(height, width, 3)
    return image[::-1]  # PFM rows run bottom to top


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    exr_path, pfm_path = sys.argv[1:]
    with OpenEXR.File(exr_path) as f:
        channels = f.channels()
        rgb = channels.get("RGB") or channels.get("RGBA")
        if rgb is None:
            sys.exit(f"{exr_path}: no RGB channels (has {sorted(channels)})")
        exr = np.asarray(rgb.pixels)[:, :, :3]
    pfm = read_pfm(pfm_path)
    if exr.dtype != np.float32:
        sys.exit(f"{exr_path}: channels are {exr.dtype}, not 32-bit floats")
    if exr.shape != pfm.shape:
        sys.exit(f"sizes differ: EXR {exr.shape}, PFM {pfm.shape}")
    differ = int(np.count_nonzero(exr.view(np.uint32) != pfm.astype(np.float32).view(np.uint32)))
    if differ:
        sys.exit(f"{differ} values differ between {exr_path} and {pfm_path}")
    print(f"same linear values: {exr.shape[1]}x{exr.shape[0]} pixels, {exr_path} == {pfm_path}")


if __name__ == "__main__":
    main()
