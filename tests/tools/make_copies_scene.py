#!/usr/bin/env python3
"""Writes a scene file (docs/scene-format.md) of many transformed copies of one capture: a big test scene
without a big download. The copies stand on a square grid in the x-z plane, `--spacing` world units apart,
each turned about the vertical axis by its own angle, so that no two views of copies are alike. A camera
named "overview" looks at the whole grid from above the front edge.

  python3 tests/tools/make_copies_scene.py ../shared/scenes/playbot_lod0_500000_sh2.ply --copies 216 \\
      --spacing 2.5 -o /tmp/big/playbot_x216.json

tilesplat reads the capture once however many copies name it (docs/big-scenes.md).

With --merged-ply FILE.ply it also writes the placed copies as one PLY of distinct Gaussians at SH degree 0 (the
scene file's merge, its colour bands dropped): a big single file, for measuring what reading one costs. With
--merged-spz FILE.spz it writes them as one SPZ (version 3, gzip) at the capture's SH degree, quantized as SPZ
quantizes. Both need the tilesplat Python module (python/README.md) and numpy.
"""

import argparse
import json
import math
import os
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("model", help="the capture every copy is of (any format tilesplat reads)")
    parser.add_argument("--copies", type=int, required=True, help="how many copies (1 to 100000)")
    parser.add_argument("--spacing", type=float, default=2.5, help="world units between neighbours (default 2.5)")
    parser.add_argument("--width", type=int, default=1920, help="the overview camera's width (default 1920)")
    parser.add_argument("--height", type=int, default=1080, help="its height (default 1080)")
    parser.add_argument("-o", "--output", required=True, help="the scene file to write (.json)")
    parser.add_argument("--merged-ply", help="also write the merged copies as one SH0 binary PLY")
    parser.add_argument("--merged-spz", help="also write the merged copies as one SPZ (version 3)")
    args = parser.parse_args()
    if not 1 <= args.copies <= 100000:
        sys.exit(f"make_copies_scene: --copies must be 1 to 100000, got {args.copies}")
    if not (args.spacing > 0 and math.isfinite(args.spacing)):
        sys.exit(f"make_copies_scene: --spacing must be positive, got {args.spacing}")
    if not os.path.exists(args.model):
        sys.exit(f"make_copies_scene: {args.model}: no such file")
    if not args.output.endswith(".json"):
        sys.exit(f"make_copies_scene: the scene file must end in .json, got {args.output}")

    out_dir = os.path.dirname(os.path.abspath(args.output))
    model = os.path.relpath(os.path.abspath(args.model), out_dir)
    side = math.ceil(math.sqrt(args.copies))
    half = (side - 1) * args.spacing / 2
    models = []
    for i in range(args.copies):
        row, column = divmod(i, side)
        models.append({
            "path": model,
            "translation": [round(column * args.spacing - half, 6), 0, round(row * args.spacing - half, 6)],
            "rotation_deg": [0, (i * 137.5) % 360, 0],  # the golden angle: every copy turned differently
        })
    # Looking down at the grid's centre from above its front edge (world up is -y, as the trainer's).
    extent = max(half, args.spacing)
    eye = [0, -0.9 * extent, 1.6 * extent]
    scene = {
        "version": 1,
        "models": models,
        "cameras": [{"name": "overview", "width": args.width, "height": args.height,
                     "look_at": {"eye": eye, "target": [0, 0, 0], "fov_deg": 50}}],
    }
    os.makedirs(out_dir, exist_ok=True)
    with open(args.output, "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")
    print(f"make_copies_scene: {args.copies} copies of {args.model} on a {side}x{side} grid -> {args.output}")
    if args.merged_ply:
        write_merged_ply(args.output, args.merged_ply)
    if args.merged_spz:
        write_merged_spz(args.output, args.merged_spz)


def write_merged_ply(scene_file, path):
    """The scene file's copies, merged by tilesplat, as one binary little-endian PLY at SH degree 0."""
    import numpy as np
    import tilesplat

    scene = tilesplat.load_scene(scene_file)
    n = scene.size
    names = ["x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2",
             "rot_0", "rot_1", "rot_2", "rot_3"]
    columns = [scene.positions, scene.sh[:, 0, :], scene.opacity_logits[:, None], scene.log_scales,
               scene.rotations]
    header = f"ply\nformat binary_little_endian 1.0\nelement vertex {n}\n"
    header += "".join(f"property float {name}\n" for name in names) + "end_header\n"
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        step = 1 << 22  # a few million Gaussians at a time: the whole table at once would double the memory
        for first in range(0, n, step):
            rows = np.concatenate([np.asarray(c[first:first + step], np.float32) for c in columns], axis=1)
            f.write(np.ascontiguousarray(rows, "<f4").tobytes())
    print(f"make_copies_scene: {n:,} Gaussians (SH0) -> {path}")


def write_merged_spz(scene_file, path, fractional_bits=12):
    """The scene file's copies, merged by tilesplat, as one SPZ version 3: a gzip stream of a 16-byte header
    and the attributes one after another (the layout engine/src/scene/spz_reader.cpp reads), each written
    a few million Gaussians at a time. SPZ's axes are RUB, the engine's RDF: y and z flip, and with them the
    quaternions' y and z and the SH bands of odd parity in y and z."""
    import gzip
    import struct

    import numpy as np
    import tilesplat

    scene = tilesplat.load_scene(scene_file)
    n, degree = scene.size, scene.sh_degree
    flip = np.array([1, -1, -1], np.float64)
    sh_flip = np.array([-1, -1, 1, -1, 1, 1, -1, 1, -1, 1, -1, -1, 1, -1, 1], np.float64)[:(degree + 1) ** 2 - 1]
    step = 1 << 22

    def quantized(values, scale, offset):
        return np.clip(np.rint(np.asarray(values, np.float64) * scale + offset), 0, 255).astype(np.uint8)

    def positions(a, b):
        fixed = np.rint(np.asarray(scene.positions[a:b], np.float64) * flip * (1 << fractional_bits))
        if np.abs(fixed).max(initial=0) >= 1 << 23:
            sys.exit(f"make_copies_scene: positions past +-{2 ** (23 - fractional_bits)} do not fit SPZ's 24 bits")
        fixed = fixed.astype(np.int64) & 0xFFFFFF
        return np.stack([fixed & 0xFF, (fixed >> 8) & 0xFF, fixed >> 16], axis=-1).astype(np.uint8)

    def alphas(a, b):
        return quantized(1 / (1 + np.exp(-np.asarray(scene.opacity_logits[a:b], np.float64))), 255, 0)

    def colours(a, b):
        return quantized(scene.sh[a:b, 0, :], 0.15 * 255, 0.5 * 255)

    def scales(a, b):
        return quantized(scene.log_scales[a:b], 16, 160)

    def rotations(a, b):
        q = np.asarray(scene.rotations[a:b], np.float64)  # w x y z, unit
        xyzw = np.concatenate([q[:, 1:] * flip, q[:, :1]], axis=1)
        largest = np.abs(xyzw).argmax(axis=1)
        xyzw *= np.where(xyzw[np.arange(len(xyzw)), largest] < 0, -1, 1)[:, None]
        packed = largest.astype(np.uint64)
        for j in range(4):  # the three smaller ones in order, each a sign and 9 bits of |v| / sqrt(1/2)
            v = xyzw[:, j]
            field = (np.rint(np.minimum(np.abs(v) / math.sqrt(0.5), 1) * 511).astype(np.uint64) |
                     (v < 0).astype(np.uint64) << np.uint64(9))
            packed = np.where(largest == j, packed, packed << np.uint64(10) | field)
        return packed.astype("<u4")

    def sh(a, b):
        rest = np.asarray(scene.sh[a:b, 1:, :], np.float64) * sh_flip[None, :, None]
        return quantized(rest, 128, 128)

    with gzip.open(path, "wb", compresslevel=1) as f:
        f.write(struct.pack("<IIIBBBB", 0x5053474E, 3, n, degree, fractional_bits, 0, 0))
        for attribute in [positions, alphas, colours, scales, rotations] + ([sh] if degree > 0 else []):
            for first in range(0, n, step):
                f.write(np.ascontiguousarray(attribute(first, min(n, first + step))).tobytes())
    print(f"make_copies_scene: {n:,} Gaussians (SH{degree}) -> {path} ({os.path.getsize(path):,} bytes)")


if __name__ == "__main__":
    main()
