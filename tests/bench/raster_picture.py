#!/usr/bin/env python3
"""docs/images/raster_vs_sorted.png: the bundled playbot through the sorted and the raster compositor, their
difference and the splats each blends per pixel (the raster has no early-out). Needs the tilesplat Python package
(python/) and matplotlib:

    python3 tests/bench/raster_picture.py docs/images/raster_vs_sorted.png
"""
import sys

import matplotlib
import numpy as np
import tilesplat

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend)

out = sys.argv[1] if len(sys.argv) > 1 else "raster_vs_sorted.png"
scene = tilesplat.load_scene("scenes/playbot_lod3/playbot_lod3_31000_sh2.ply")
renderer = tilesplat.Renderer()
renderer.set_scene(scene)
camera = tilesplat.Camera.orbit(scene, 480, 270)
tiles = renderer.render(camera, sort="radix")
raster = renderer.render(camera, sort="radix", compositor="raster")
difference = np.abs(raster.rgba[..., :3] - tiles.rgba[..., :3]).max(axis=2)
extra_splats = raster.splat_count.astype(float) - tiles.splat_count.astype(float)

fig, ax = plt.subplots(2, 2, figsize=(12, 7.4))
ax[0, 0].imshow(tiles.preview())
ax[0, 0].set_title("sorted compositor (tiles, compute)")
ax[0, 1].imshow(raster.preview())
ax[0, 1].set_title("raster compositor (quads, hardware blend)")
shown = ax[1, 0].imshow(difference, cmap="magma", vmin=0, vmax=max(float(difference.max()), 1e-6))
ax[1, 0].set_title("|raster - sorted|, max %.4f (display values)" % difference.max())
fig.colorbar(shown, ax=ax[1, 0], fraction=0.03)
shown = ax[1, 1].imshow(extra_splats, cmap="viridis")
ax[1, 1].set_title("splats blended: raster minus sorted (no early-out)")
fig.colorbar(shown, ax=ax[1, 1], fraction=0.03)
for a in ax.flat:
    a.axis("off")
fig.suptitle("playbot_lod3 (31k), 480x270, lavapipe: the raster compositor against the sorted one")
fig.tight_layout()
fig.savefig(out, dpi=80)
print("max |raster - sorted| %.6f; splats blended: sorted %d, raster %d" %
      (difference.max(), tiles.splat_count.sum(), raster.splat_count.sum()))
