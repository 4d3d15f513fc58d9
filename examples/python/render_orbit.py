"""Renders an orbit around a scene to PNGs with the tilesplat Python package.

    python examples/python/render_orbit.py scenes/playbot_lod3/playbot_lod3_31000_sh2.ply out/ --frames 24

Each frame is also at hand as numpy arrays (image.rgba, image.depth) for whatever comes next.
"""

import argparse
import pathlib
import time

import tilesplat


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", type=pathlib.Path, help="a splat file (.ply, .spz, .sog, ...) or a scene file")
    parser.add_argument("out", type=pathlib.Path, help="folder for frame_0000.png, ...")
    parser.add_argument("--frames", type=int, default=24)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--elevation", type=float, default=20.0, help="degrees above the horizon")
    parser.add_argument("--device", default="", help="index, part of a name or UUID (tilesplat.devices())")
    args = parser.parse_args()

    scene = tilesplat.load_scene(args.scene)
    renderer = tilesplat.Renderer(device=args.device)
    renderer.set_scene(scene)
    print(f"{args.scene.name}: {scene.size:,} Gaussians on {renderer.device_info['name']}")
    args.out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    cameras = tilesplat.orbit_cameras(scene, args.frames, args.width, args.height, elevation_deg=args.elevation)
    for frame, camera in enumerate(cameras):
        image = renderer.render(camera)
        image.write_png(args.out / f"frame_{frame:04d}.png")
    seconds = time.perf_counter() - start
    print(f"{args.frames} frames of {args.width}x{args.height} in {seconds:.2f} s -> {args.out}")


if __name__ == "__main__":
    main()
