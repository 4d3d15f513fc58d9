#!/usr/bin/env python3
"""Draws what a splat budget does to a LOD set (docs/big-scenes.md): from one view, the finest level, the
levels the budget chose, those levels as colours (level 0 red, 1 green, 2 blue, 3 and on grey), and the
coarsest level, side by side in one PNG with each panel's Gaussians and PSNR against the finest.

  python tests/tools/lod_figure.py LOD-META.json CAMERAS.json --view 0 --budget 62000 --width 480 -o lod.png

Needs the tilesplat Python module (python/README.md) and Pillow.
"""

import argparse
import sys

import numpy as np
from PIL import Image, ImageDraw

import tilesplat

LEVEL_COLOURS = [(0.9, 0.15, 0.1), (0.15, 0.75, 0.2), (0.15, 0.35, 0.95)]
SH_C0 = 0.28209479177387814  # the DC band's constant: colour = SH_C0 * dc + 0.5


def by_level_colour(lods, selection, scene):
    """The selected scene with each chunk's Gaussians in its level's flat colour (view-independent)."""
    dc = np.empty((scene.size, 3), np.float32)
    sizes = {level: lods.chunk_sizes(level) for level in range(lods.levels)}
    at = 0
    for chunk, level in enumerate(selection.chunk_levels):
        if level < 0:
            continue
        count = sizes[level][chunk]
        colour = LEVEL_COLOURS[level] if level < len(LEVEL_COLOURS) else (0.6, 0.6, 0.6)
        dc[at:at + count] = (np.array(colour, np.float32) - 0.5) / SH_C0
        at += count
    assert at == scene.size, (at, scene.size)
    return tilesplat.Scene.from_arrays(scene.positions, scene.log_scales, scene.rotations, scene.opacity_logits,
                                       dc.reshape(-1, 1, 3))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("lod_set", help="the LOD set's lod-meta.json")
    parser.add_argument("cameras", help="a cameras.json, transforms.json or COLMAP model")
    parser.add_argument("--view", type=int, default=0)
    parser.add_argument("--budget", type=int, required=True, help="the splat budget")
    parser.add_argument("--width", type=int, default=480, help="each panel's width")
    parser.add_argument("-o", "--output", required=True, help="the PNG to write")
    args = parser.parse_args()

    lods = tilesplat.LodSet(args.lod_set)
    views = tilesplat.load_cameras(args.cameras)
    if not 0 <= args.view < len(views):
        sys.exit(f"lod_figure: --view {args.view} is out of range: {args.cameras} has {len(views)} views")
    view = views[args.view].camera
    camera = view.resized(args.width, round(view.height * args.width / view.width))
    renderer = tilesplat.Renderer()
    selection = lods.select(camera, args.budget)
    chosen = lods.load_selection(selection)
    finest = renderer.render(camera, scene=lods.load_level(0))
    coarsest = lods.levels - 1
    panels = [
        (finest, f"level 0: {lods.level_size(0):,}"),
        (renderer.render(camera, scene=chosen), f"budget {args.budget:,}: {selection.splats:,}"),
        (renderer.render(camera, scene=by_level_colour(lods, selection, chosen)), "its levels: 0 red, 1 green, 2 blue"),
        (renderer.render(camera, scene=lods.load_level(coarsest)), f"level {coarsest}: {lods.level_size(coarsest):,}"),
    ]
    height = camera.height
    figure = Image.new("RGB", (args.width * len(panels), height + 20), "white")
    draw = ImageDraw.Draw(figure)
    for i, (image, label) in enumerate(panels):
        figure.paste(Image.fromarray(image.preview()), (i * args.width, 20))
        if i in (1, 3):
            label += f", {tilesplat.compare_images(finest, image)['psnr_db']:.1f} dB"
        draw.text((i * args.width + 6, 4), label, fill="black")
    figure.save(args.output)
    print(f"lod_figure: {args.output}: {len(panels)} panels of {args.width}x{height}, {selection.splats:,} "
          f"Gaussians under the budget of {args.budget:,}")


if __name__ == "__main__":
    main()
