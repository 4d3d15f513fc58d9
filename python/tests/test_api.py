"""The engine's API from Python: scenes as numpy views, cameras, the renderer, images, errors."""

import pathlib
import subprocess
import tempfile
import threading
import time

import numpy as np
import pytest

import tilesplat
from conftest import BUNDLED_PLAYBOT, BUNDLED_SH3, REPO


def test_version_is_the_projects():
    cmake = (REPO / "CMakeLists.txt").read_text()
    assert f"project(tilesplat VERSION {tilesplat.__version__}" in cmake
    assert tilesplat.devices(), "no Vulkan device"
    assert "radix" in tilesplat.sort_strategies()


def test_scene_arrays_are_views_of_the_scene():
    scene = tilesplat.load_scene(BUNDLED_SH3)
    assert scene.size == 64 and scene.sh_degree == 3
    assert scene.positions.shape == (64, 3) and scene.positions.dtype == np.float32
    assert scene.log_scales.shape == (64, 3)
    assert scene.rotations.shape == (64, 4)
    assert scene.opacity_logits.shape == (64,)
    assert scene.sh.shape == (64, 16, 3)
    np.testing.assert_allclose(np.linalg.norm(scene.rotations, axis=1), 1, rtol=1e-6)
    # A view: what the scene holds, not a copy taken once.
    view = scene.positions
    view[0, 0] = 123.0
    assert scene.positions[0, 0] == 123.0


def test_every_format_loads(shared_scenes):
    formats = shared_scenes / "formats"
    reference = tilesplat.load_scene(BUNDLED_SH3)
    for name in ["playcanvas_test_64_sh3.compressed.ply", "playcanvas_test_64_sh3.glb",
                 "playcanvas_test_64_sh3.sog", "playcanvas_test_64_sh3.v3.spz", "playcanvas_test_64_sh3.v4.spz"]:
        scene = tilesplat.load_scene(formats / name)
        assert scene.size == reference.size and scene.sh_degree == 3, name
        # Lossy formats, some of which reorder the Gaussians: every mean of the lossless PLY has one
        # within a centimetre in the file.
        distances = np.linalg.norm(reference.positions[:, None, :] - scene.positions[None, :, :], axis=2)
        assert distances.min(axis=1).max() < 0.01, name
    # GaussianSplats3D's .ksplat at each compression level (its own generator's files, tests/data/ksplat).
    ksplats = REPO / "tests" / "data" / "ksplat"
    for level in range(3):
        scene = tilesplat.load_scene(ksplats / f"playcanvas_test_64_sh3_l{level}_sh2.ksplat")
        assert scene.size == reference.size and scene.sh_degree == 2, level
        distances = np.linalg.norm(reference.positions[:, None, :] - scene.positions[None, :, :], axis=2)
        assert distances.min(axis=1).max() < 1e-4, level
    # glTF with an SPZ stream, as each Khronos draft places it (tests/data/gltf_spz): SPZ's 12-bit position step.
    for glb in sorted((REPO / "tests" / "data" / "gltf_spz").glob("*.glb")):
        scene = tilesplat.load_scene(glb)
        assert scene.size == reference.size and scene.sh_degree == 3, glb.name
        assert np.abs(scene.positions - reference.positions).max() < 1.3e-4, glb.name
    # Spark's .rad (its own build-lod's files, tests/data/rad): the LOD tree's leaves, positions as float32 bytes.
    for rad in sorted((REPO / "tests" / "data" / "rad").glob("*.rad")):
        scene = tilesplat.load_scene(rad)
        assert scene.size == reference.size, rad.name
        distances = np.linalg.norm(reference.positions[:, None, :] - scene.positions[None, :, :], axis=2)
        assert distances.min(axis=1).max() == 0, rad.name
    scene_file = tilesplat.load_scene(REPO / "scenes" / "two_playbots.json")
    assert scene_file.size == 2 * tilesplat.load_scene(BUNDLED_PLAYBOT).size


def test_cameras_from_a_camera_set_and_of_its_own_making():
    views = tilesplat.load_cameras(REPO / "scenes" / "playbot_lod3" / "playbot_lod3_31000_sh2.json")
    assert len(views) > 1
    assert views[0].camera.width > 0 and views[0].name
    small = views[0].camera.resized(160, 90)
    assert (small.width, small.height) == (160, 90)
    look = tilesplat.Camera.look_at([0, 0, -5], [0, 0, 0], [0, -1, 0], 64, 48, 50.0)
    assert look.position == [0, 0, -5] and look.width == 64


@pytest.fixture(scope="module")
def playbot_renderer():
    scene = tilesplat.load_scene(BUNDLED_PLAYBOT)
    renderer = tilesplat.Renderer(validation=True)
    renderer.set_scene(scene)
    return scene, renderer


def test_render_returns_numpy_images_and_stats(playbot_renderer):
    scene, renderer = playbot_renderer
    image = renderer.render(tilesplat.Camera.orbit(scene, 160, 90, azimuth_deg=30))
    assert image.rgba.shape == (90, 160, 4) and image.rgba.dtype == np.float32
    assert np.isfinite(image.rgba).all()
    alpha = image.rgba[..., 3]
    assert alpha.min() >= 0 and alpha.max() <= 1 and alpha.max() > 0.5
    assert image.depth.shape == (90, 160) and image.splat_count.dtype == np.uint32
    stats = renderer.last_frame_stats
    assert stats["gaussians"] == scene.size and stats["visible"] > 0
    assert stats["sort_strategy"] == renderer.sort_strategy_for("auto")
    assert [name for name, _ in stats["passes"]][0] == "projection"
    no_outputs = renderer.render(tilesplat.Camera.orbit(scene, 32, 18), depth=False, splat_count=False)
    assert no_outputs.depth is None and no_outputs.splat_count is None
    assert renderer.validation_messages == 0


def test_render_equals_the_cpp_app_to_the_bit(playbot_renderer, render_exe, tmp_path):
    scene, renderer = playbot_renderer
    exr = tmp_path / "app.exr"
    subprocess.run([render_exe, str(BUNDLED_PLAYBOT), "--width", "160", "--height", "90", "--azimuth", "30",
                    "--mode", "depth16", "-o", str(exr)], check=True, capture_output=True)
    ours = renderer.render(tilesplat.Camera.orbit(scene, 160, 90, azimuth_deg=30), accuracy="depth16")
    # Both through the same EXR writer and reader (scene-linear on disk), so equal renders read back equal.
    ours.write_exr(tmp_path / "ours.exr")
    from_app, from_module = tilesplat.read_exr(exr), tilesplat.read_exr(tmp_path / "ours.exr")
    assert np.array_equal(from_module.rgba, from_app.rgba)
    assert np.array_equal(from_module.depth, from_app.depth)
    assert np.array_equal(from_module.splat_count, from_app.splat_count)
    assert np.array_equal(ours.splat_count, from_app.splat_count)


def test_a_scene_from_arrays_renders_as_the_loaded_one(playbot_renderer):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 96, 54, azimuth_deg=120)
    loaded = renderer.render(camera)
    rebuilt = tilesplat.Scene.from_arrays(scene.positions, scene.log_scales, scene.rotations,
                                          scene.opacity_logits, scene.sh)
    other = tilesplat.Renderer()
    other.set_scene(rebuilt)
    again = other.render(camera)
    assert np.array_equal(loaded.rgba, again.rgba)
    # float64 input is converted, not refused.
    as_double = tilesplat.Scene.from_arrays(scene.positions.astype(np.float64), scene.log_scales,
                                            scene.rotations, scene.opacity_logits, scene.sh)
    assert as_double.size == scene.size


def test_settings_are_keyword_arguments(playbot_renderer):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 96, 54)
    exact = renderer.render(camera, sort="radix")
    for sort in ["onesweep", "tile-local"]:
        assert np.array_equal(renderer.render(camera, sort=sort).rgba, exact.rgba), sort
    mip = renderer.render(camera, antialiasing="mip")
    assert not np.array_equal(mip.rgba, exact.rgba)
    stochastic = renderer.render(camera, compositor="stochastic", stochastic_frames=64, seed=3)
    assert tilesplat.compare_images(stochastic, exact)["psnr_db"] > 20
    stratified = renderer.render(camera, compositor="stochastic", stochastic_frames=64, seed=3,
                                 stochastic_sampler="stratified")
    assert not np.array_equal(stratified.rgba, stochastic.rgba)
    assert (tilesplat.compare_images(stratified, exact)["psnr_db"]
            > tilesplat.compare_images(stochastic, exact)["psnr_db"])
    with pytest.raises(ValueError, match="stochastic_sampler must be one of hash, stratified, sobol, got 'blue'"):
        renderer.render(camera, compositor="stochastic", stochastic_sampler="blue")
    # Frames that add up across calls: four calls of one frame are one call of four.
    for calls in range(1, 5):
        accumulated = renderer.render(camera, compositor="stochastic", stochastic_frames=1,
                                      stochastic_accumulate=True)
        assert renderer.last_frame_stats["accumulated_frames"] == calls
    four = renderer.render(camera, compositor="stochastic", stochastic_frames=4)
    assert np.array_equal(accumulated.rgba, four.rgba)
    white = renderer.render(camera, background=[1, 1, 1])
    assert white.rgba[0, 0, :3].min() > 0.5 or exact.rgba[0, 0, 3] > 0.5


def test_a_scene_in_parts_under_a_memory_budget(playbot_renderer):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 160, 90, azimuth_deg=30)
    whole = renderer.render(camera)
    other = tilesplat.Renderer(validation=True)
    parts = other.render(camera, scene=scene, memory_budget=4 << 20)
    stats = other.last_frame_stats
    assert stats["scene_parts"] >= 4 and stats["peak_device_bytes"] <= (4 << 20) * 1.01
    assert stats["depth_order_ms"] > 0
    assert np.array_equal(parts.rgba, whole.rgba)
    assert np.array_equal(parts.depth, whole.depth)
    assert np.array_equal(parts.splat_count, whole.splat_count)
    with pytest.raises(ValueError, match="leaves no room for a Gaussian"):
        other.render(camera, scene=scene, memory_budget=1 << 16)
    assert other.validation_messages == 0


def test_a_scene_past_the_device_renders_in_parts_without_a_budget(playbot_renderer, monkeypatch):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 160, 90, azimuth_deg=30)
    whole = renderer.render(camera)
    assert renderer.device_info["max_allocation_size"] >= 1 << 27
    assert renderer.device_info["device_memory"] >= renderer.device_info["max_allocation_size"]
    # A device whose largest allocation (1 MiB) is below the scene's spherical harmonics (3.3 MB).
    monkeypatch.setenv("TILESPLAT_MAX_ALLOCATION", "1M")
    small = tilesplat.Renderer(validation=True)
    monkeypatch.delenv("TILESPLAT_MAX_ALLOCATION")
    assert small.device_info["max_allocation_size"] == 1 << 20
    parts = small.render(camera, scene=scene)
    assert small.last_frame_stats["scene_parts"] >= 4
    assert np.array_equal(parts.rgba, whole.rgba)
    assert np.array_equal(parts.depth, whole.depth)
    assert small.validation_messages == 0


def test_a_region_is_the_whole_frames_pixels(playbot_renderer, monkeypatch):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 160, 90, azimuth_deg=30)
    whole = renderer.render(camera)
    part = renderer.render(camera, region=(10, 21, 100, 30))
    assert part.rgba.shape == (30, 100, 4)
    assert np.array_equal(part.rgba, whole.rgba[21:51, 10:110])
    assert np.array_equal(part.depth, whole.depth[21:51, 10:110])
    with pytest.raises(ValueError, match="reaches past the 160x90 image"):
        renderer.render(camera, region=(100, 0, 100, 10))
    # An image past the device's largest allocation renders in bands of rows.
    monkeypatch.setenv("TILESPLAT_MAX_ALLOCATION", "256K")
    small = tilesplat.Renderer(validation=True)
    monkeypatch.delenv("TILESPLAT_MAX_ALLOCATION")
    banded = small.render(camera, scene=scene)
    assert small.last_frame_stats["image_bands"] == 6
    assert np.array_equal(banded.rgba, whole.rgba)
    assert small.validation_messages == 0


def test_the_float64_reference(playbot_renderer):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 96, 54, azimuth_deg=30)
    gpu = renderer.render(camera)
    reference = tilesplat.render_reference(camera, scene=scene)
    assert reference.rgba.shape == gpu.rgba.shape
    assert tilesplat.compare_images(gpu, reference)["psnr_db"] > 60
    part = tilesplat.render_reference(camera, scene=scene, region=(10, 5, 40, 20))
    assert np.array_equal(part.rgba, reference.rgba[5:25, 10:50])
    with pytest.raises(ValueError, match="one of scene and instances"):
        tilesplat.render_reference(camera)


def test_an_accuracy_mode_reaches_the_renderer_and_the_reference(playbot_renderer):
    # radial: the depth sort by distance from the camera; the reference sorts the same way.
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 96, 54, azimuth_deg=30)
    radial = renderer.render(camera, accuracy="radial")
    assert tilesplat.compare_images(radial, tilesplat.render_reference(camera, scene=scene, accuracy="radial"))[
        "psnr_db"
    ] > 60
    assert not np.array_equal(radial.rgba, renderer.render(camera).rgba)
    with pytest.raises(ValueError, match="radiall"):
        renderer.render(camera, accuracy="radiall")


def test_a_scene_files_moving_models_blur_under_an_open_shutter(playbot_renderer):
    _, renderer = playbot_renderer
    instances = tilesplat.SceneInstances(REPO / "scenes" / "moving_playbots.json")
    assert instances.moves and instances.size == 62000
    camera = tilesplat.Camera.orbit(instances.scene_at(0), 96, 54, azimuth_deg=0)
    # Closed: the scene where it is at time 0.
    renderer.set_scene(instances.scene_at(0))
    still = renderer.render(camera)
    assert np.array_equal(renderer.render(camera, instances=instances).rgba, still.rgba)
    # Open over a still camera: the linear mean of the frames of the scene at the shutter's times.
    shutter = tilesplat.Shutter(open=0.0, close=1.0, samples=3)
    blurred = renderer.render(camera, instances=instances, shutter=shutter)
    assert renderer.last_frame_stats["samples"] == 3
    frames = []
    for t in tilesplat.shutter_times(0.0, 1.0, 3):
        renderer.set_scene(instances.scene_at(t))
        frames.append(renderer.render(camera))
    assert tilesplat.compare_images(blurred, frames[1])["psnr_db"] < 40

    # The mean in linear light (docs/effects.md): each premultiplied display colour decoded as A decode(C / A).
    def decode(v):
        return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)

    def encode(v):
        return np.where(v <= 0.0031308, v * 12.92, 1.055 * np.power(np.maximum(v, 0), 1 / 2.4) - 0.055)

    linear, alpha = 0, 0
    for frame in frames:
        a = frame.rgba[..., 3:].astype(np.float64)
        c = frame.rgba[..., :3].astype(np.float64)
        linear = linear + a * decode(np.divide(c, a, out=np.zeros_like(c), where=a > 0))
        alpha = alpha + a
    linear, alpha = linear / len(frames), alpha / len(frames)
    mean = alpha * encode(np.divide(linear, alpha, out=np.zeros_like(linear), where=alpha > 0))
    assert np.abs(mean - blurred.rgba[..., :3]).max() <= 1e-5
    assert np.abs(alpha[..., 0] - blurred.rgba[..., 3]).max() <= 1e-6
    with pytest.raises(ValueError, match="one of scene, lod_set and instances"):
        renderer.render(camera, instances=instances, scene=instances.scene_at(0))
    # Set once, the copies are placed at each time sample by the renderer: the same frame, and samples
    # that add up a call at a time.
    renderer.set_scene(instances)
    assert np.array_equal(renderer.render(camera).rgba, still.rgba)
    assert np.array_equal(renderer.render(camera, shutter=shutter).rgba, blurred.rgba)
    sobol = tilesplat.Shutter(open=0.0, close=1.0, samples=4, pattern="sobol")
    all_four = renderer.render(camera, shutter=sobol)
    for call in range(4):
        accumulated = renderer.render(camera, shutter=sobol, accumulate_samples=True)
    assert renderer.last_frame_stats["accumulated_samples"] == 4
    assert np.abs(accumulated.rgba - all_four.rgba).max() <= 2e-5


def test_a_ply_read_part_by_part_is_the_loaded_scenes_frame(playbot_renderer):
    scene, renderer = playbot_renderer
    mapped = tilesplat.MappedPly(BUNDLED_PLAYBOT)
    assert mapped.size == scene.size and mapped.sh_degree == scene.sh_degree
    assert np.array_equal(mapped.load().positions, scene.positions)
    camera = tilesplat.Camera.orbit(scene, 160, 90, azimuth_deg=30)
    whole = renderer.render(camera, scene=scene)
    in_parts = renderer.render(camera, mapped_ply=mapped, memory_budget=4 << 20)
    assert renderer.last_frame_stats["scene_parts"] > 1
    assert np.array_equal(in_parts.rgba, whole.rgba) and np.array_equal(in_parts.depth, whole.depth)
    with pytest.raises(ValueError, match="one of scene, lod_set and instances"):
        renderer.render(camera, scene=scene, mapped_ply=mapped)
    with pytest.raises(tilesplat.SceneError, match="ASCII PLY cannot be read part by part"):
        ascii_ply = pathlib.Path(tempfile.mkdtemp()) / "ascii.ply"
        names = ["x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2",
                 "rot_0", "rot_1", "rot_2", "rot_3"]
        ascii_ply.write_text("ply\nformat ascii 1.0\nelement vertex 1\n" +
                             "".join(f"property float {name}\n" for name in names) +
                             "end_header\n0 0 0 0 0 0 0 -3 -3 -3 1 0 0 0\n")
        tilesplat.MappedPly(ascii_ply)
    renderer.set_scene(scene)  # the other tests render the scene set
    assert renderer.validation_messages == 0


def test_an_spz_or_a_sog_read_part_by_part_is_the_loaded_scenes_frame(shared_scenes):
    # A renderer of its own: a budget counts every buffer a renderer holds, and the shared one's have grown.
    renderer = tilesplat.Renderer(validation=True)
    path = shared_scenes / "formats" / "playbot_lod6_1873_sh2.v4.spz"
    scene = tilesplat.load_scene(path)
    in_parts = tilesplat.SceneInParts(path)
    assert tilesplat.MappedPly is tilesplat.SceneInParts  # the earlier name
    assert in_parts.size == scene.size and in_parts.sh_degree == scene.sh_degree
    assert tilesplat.SceneInParts.whole_scene_bytes(path) == scene.size * (11 + 3 * 9) * 4
    assert np.array_equal(in_parts.load().sh, scene.sh)
    camera = tilesplat.Camera.orbit(scene, 160, 90, azimuth_deg=30)
    parts = renderer.render(camera, in_parts=in_parts, memory_budget=1300 << 10)
    assert renderer.last_frame_stats["scene_parts"] > 1
    whole = renderer.render(camera, scene=scene)
    assert np.array_equal(parts.rgba, whole.rgba) and np.array_equal(parts.depth, whole.depth)
    with pytest.raises(ValueError, match="not both"):
        renderer.render(camera, in_parts=in_parts, mapped_ply=in_parts)
    sog = shared_scenes / "formats" / "playbot_lod6_1873_sh2.sog"
    sog_whole = renderer.render(camera, scene=tilesplat.load_scene(sog))
    sog_parts = renderer.render(camera, in_parts=tilesplat.SceneInParts(sog), memory_budget=1300 << 10)
    assert renderer.last_frame_stats["scene_parts"] > 1
    assert np.array_equal(sog_parts.rgba, sog_whole.rgba)
    assert renderer.validation_messages == 0


def test_a_lod_set_by_level_and_under_a_splat_budget(playbot_renderer):
    _, renderer = playbot_renderer
    lods = tilesplat.LodSet(REPO / "tests" / "data" / "playbot_lod_set" / "lod-meta.json")
    assert lods.levels == 3 and lods.chunks == 42
    assert [lods.level_size(level) for level in range(3)] == [31000, 7750, 1550]
    assert [sum(lods.chunk_sizes(level)) for level in range(3)] == [31000, 7750, 1550]
    finest = lods.load_level(0)
    assert finest.size == 31000 and finest.sh_degree == 2
    camera = tilesplat.Camera.orbit(finest, 160, 90, azimuth_deg=30)
    everything = lods.select(camera, splat_budget=10**6)
    assert everything.splats == 31000 and set(everything.chunk_levels) == {0}
    some = lods.select(camera, splat_budget=5000)
    assert some.splats <= 5000 and not some.over_budget and len(some.chunk_levels) == 42
    chosen = lods.load_selection(some)
    assert chosen.size == some.splats
    whole = renderer.render(camera, scene=finest)
    budget = renderer.render(camera, scene=chosen)
    assert 15 < tilesplat.compare_images(whole, budget)["psnr_db"] < 100
    assert lods.select(camera, splat_budget=10).over_budget
    direct = renderer.render(camera, lod_set=lods, splat_budget=5000)
    assert np.array_equal(direct.rgba, budget.rgba)
    assert renderer.last_frame_stats["gaussians"] == some.splats
    assert np.array_equal(renderer.render(camera, lod_set=lods).rgba, whole.rgba)
    with pytest.raises(ValueError, match="splat_budget applies to a lod_set"):
        renderer.render(camera, scene=finest, splat_budget=5000)
    with pytest.raises(ValueError, match="there is no level 3"):
        lods.load_level(3)
    assert renderer.validation_messages == 0


def test_raster_compositor(playbot_renderer):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 96, 54)
    raster = renderer.render(camera, compositor="raster")
    # The raster rule differs from the tile compositor only by its missing early-out and tile rectangles.
    assert tilesplat.compare_images(raster, renderer.render(camera))["psnr_db"] > 60
    with pytest.raises(ValueError, match="raster"):
        renderer.render(camera, compositor="billboard")


def test_images_write_exr_and_png(playbot_renderer, tmp_path):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 64, 36)
    image = renderer.render(camera)
    image.write_exr(tmp_path / "a.exr", camera=camera)
    image.write_png(tmp_path / "a.png", exposure_stops=1, tone_map="aces")
    back = tilesplat.read_exr(tmp_path / "a.exr")
    # On disk the colours are scene-linear: they come back through the sRGB curve and its inverse.
    np.testing.assert_allclose(back.rgba, image.rgba, atol=2e-6)
    assert np.array_equal(back.splat_count, image.splat_count)
    # Z as tilesplat-render writes it: the depth where splats were blended, far (1e10) where none was.
    empty = image.splat_count == 0
    assert empty.any() and not empty.all()
    assert np.array_equal(back.depth[~empty], image.depth[~empty]) and (back.depth[empty] == 1e10).all()
    assert (tmp_path / "a.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    # preview(): the PNG's pixels to show (matplotlib's imshow): the display values as they are, in bytes.
    preview = image.preview()
    assert preview.dtype == np.uint8 and preview.shape == (36, 64, 3)
    expected = np.round(np.clip(image.rgba[..., :3], 0, 1) * 255).astype(np.uint8)
    assert np.abs(preview.astype(int) - expected).max() <= 1  # float32 against the engine's double rounding
    graded = image.preview(exposure_stops=1, tone_map="aces")
    assert graded.shape == preview.shape and not np.array_equal(graded, preview)
    with pytest.raises(ValueError, match="tone_map must be one of"):
        image.preview(tone_map="filmic")
    with pytest.raises(ValueError, match="exposure"):
        image.preview(exposure_stops=40)


def test_errors_are_python_exceptions_with_the_engines_messages(tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.ply"):
        tilesplat.load_scene(tmp_path / "missing.ply")
    truncated = tmp_path / "truncated.ply"
    truncated.write_bytes(BUNDLED_SH3.read_bytes()[:2000])
    with pytest.raises(tilesplat.SceneError, match="truncated.ply"):
        tilesplat.load_scene(truncated)
    assert issubclass(tilesplat.SceneError, ValueError)
    good = tilesplat.load_scene(BUNDLED_SH3)
    with pytest.raises(ValueError, match=r"log_scales must have the shape \(64, 3\), got \(64, 2\)"):
        tilesplat.Scene.from_arrays(good.positions, good.log_scales[:, :2], good.rotations, good.opacity_logits,
                                    good.sh)
    nan_positions = good.positions.copy()
    nan_positions[5, 1] = np.nan
    with pytest.raises(ValueError, match="positions holds a non-finite value"):
        tilesplat.Scene.from_arrays(nan_positions, good.log_scales, good.rotations, good.opacity_logits, good.sh)
    with pytest.raises(ValueError, match="sh must have 1, 4, 9 or 16 coefficients"):
        tilesplat.Scene.from_arrays(good.positions, good.log_scales, good.rotations, good.opacity_logits,
                                    good.sh[:, :5])
    renderer = tilesplat.Renderer()
    renderer.set_scene(good)
    camera = tilesplat.Camera.orbit(good, 32, 32)
    with pytest.raises(ValueError, match="antialiasing must be one of classic, antialiased, mip, got 'gauss'"):
        renderer.render(camera, antialiasing="gauss")
    with pytest.raises(ValueError):
        renderer.render(camera, accuracy="depth12")
    with pytest.raises(RuntimeError, match="no Vulkan device matches"):
        tilesplat.Renderer(device="no-such-device")


def test_render_releases_the_gil(playbot_renderer):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 640, 360)
    renderer.render(camera)  # compile the pipelines first
    start = time.perf_counter()
    renderer.render(camera, reuse_lists=False)
    frame = time.perf_counter() - start

    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    ticker = threading.Thread(target=tick)
    ticker.start()
    for _ in range(3):
        renderer.render(camera, reuse_lists=False)
    done.set()
    ticker.join()
    gaps = np.diff(ticks)
    # With the GIL held through a frame the ticker would stall for a whole frame.
    assert len(ticks) > 10 and gaps.max() < max(0.5 * frame, 0.02), (frame, gaps.max())


def test_camera_paths_orbits_and_host_matrices(tmp_path):
    scene = tilesplat.load_scene(BUNDLED_SH3)
    orbit = tilesplat.orbit_cameras(scene, 4, 64, 36, elevation_deg=30)
    assert len(orbit) == 4 and orbit[0] == tilesplat.Camera.orbit(scene, 64, 36, elevation_deg=30)
    assert orbit[1] == tilesplat.Camera.orbit(scene, 64, 36, azimuth_deg=90, elevation_deg=30)
    keys = tmp_path / "fly.json"
    keys.write_text('{"keyframes": [{"position": [0, -1, 4], "look_at": [0, 0, 0], "fov": 50},'
                    ' {"position": [3, -1, 2], "look_at": [0, 0, 0], "fov": 40}]}')
    path = tilesplat.camera_path(keys, 5, 64, 36)
    assert len(path) == 5 and path[0].position == [0, -1, 4] and path[-1].position == [3, -1, 2]
    # A Vulkan-convention perspective (y flipped, depth 0..1), 60 degrees vertical, from the origin.
    f = 1 / np.tan(np.radians(30))
    near, far = 0.1, 100.0
    projection = np.zeros((4, 4))
    projection[0, 0], projection[1, 1] = f * 36 / 64, -f
    projection[2, 2], projection[2, 3] = far / (near - far), near * far / (near - far)
    projection[3, 2] = -1
    camera = tilesplat.Camera.from_matrices(np.eye(4).T.flatten().tolist(), projection.T.flatten().tolist(), 64, 36)
    assert camera.fx == pytest.approx(18 * f) and camera.fy == pytest.approx(18 * f)
    assert camera.position == pytest.approx([0, 0, 0])
    with pytest.raises(ValueError, match="clip must be vulkan or opengl"):
        tilesplat.Camera.from_matrices(np.eye(4).flatten().tolist(), projection.T.flatten().tolist(), 64, 36, "d3d")


def test_depth_of_field_through_a_thin_lens(playbot_renderer):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 96, 54, azimuth_deg=30)
    pinhole = renderer.render(camera)
    assert np.array_equal(renderer.render(camera, lens=tilesplat.ThinLens()).rgba, pinhole.rgba)  # off: the pinhole
    lens = tilesplat.ThinLens(aperture_diameter=0.2, focus_distance=2.0, samples=4)
    blurred = renderer.render(camera, lens=lens)
    assert renderer.last_frame_stats["samples"] == 4
    assert tilesplat.compare_images(blurred, pinhole)["psnr_db"] < 45
    # The definition: the mean in linear light of the samples' pinhole frames.
    samples = tilesplat.lens_samples(4)
    assert len(samples) == 4 and all(x * x + y * y <= 1 for x, y in samples)
    frames = [renderer.render(tilesplat.lens_sample_camera(camera, lens, s)).rgba for s in samples]
    decode = lambda c: np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)  # noqa: E731
    encode = lambda l: np.where(l <= 0.0031308, l * 12.92, 1.055 * l ** (1 / 2.4) - 0.055)  # noqa: E731
    linear = [np.concatenate([f[..., 3:] * decode(np.where(f[..., 3:] > 0, f[..., :3] / np.maximum(f[..., 3:], 1e-30),
                                                                  f[..., :3])), f[..., 3:]], -1)
              for f in frames]
    mean = np.mean(linear, axis=0)
    alpha = mean[..., 3:]
    expected = np.where(alpha > 0, alpha * encode(mean[..., :3] / np.maximum(alpha, 1e-30)), encode(mean[..., :3]))
    np.testing.assert_allclose(blurred.rgba[..., :3], expected, atol=2e-5)
    assert tilesplat.aperture_for_f_stop(camera, 2.0) > 0
    with pytest.raises(ValueError, match="focus_distance"):
        tilesplat.ThinLens(aperture_diameter=0.1, focus_distance=0)


def test_lens_samples_that_add_up_call_after_call(playbot_renderer):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 96, 54, azimuth_deg=30)
    point = tilesplat.effect_sample_point(3)
    assert len(point) == 3 and all(0 <= x < 1 for x in point)
    assert tilesplat.lens_sample("sobol", 3, 1) == tilesplat.lens_sample("sobol", 3, 64)  # whatever the count
    assert tilesplat.lens_sample("even", 2, 4) == tilesplat.lens_samples(4)[2]
    assert tilesplat.shutter_time(0.0, 0.5, "sobol", 3, 1) == 0.5 * point[2]
    lens = tilesplat.ThinLens(aperture_diameter=0.2, focus_distance=2.0, samples=6, pattern="sobol")
    assert lens.pattern == "sobol"
    six = renderer.render(camera, lens=lens)
    for calls in range(1, 7):
        accumulated = renderer.render(camera, lens=lens, accumulate_samples=True)
        assert renderer.last_frame_stats["accumulated_samples"] == calls
    np.testing.assert_allclose(accumulated.rgba, six.rgba, atol=2e-5)
    with pytest.raises(ValueError, match="pattern must be sobol"):
        renderer.render(camera, lens=tilesplat.ThinLens(aperture_diameter=0.2, focus_distance=2.0),
                        accumulate_samples=True)
    with pytest.raises(ValueError, match="known: even, sobol"):
        tilesplat.ThinLens(aperture_diameter=0.2, focus_distance=2.0, pattern="halton")


def test_motion_blur_through_a_shutter(playbot_renderer):
    scene, renderer = playbot_renderer
    start = tilesplat.Camera.orbit(scene, 96, 54, azimuth_deg=30)
    end = tilesplat.Camera.orbit(scene, 96, 54, azimuth_deg=45)
    still = renderer.render(start)
    closed = tilesplat.Shutter(open=0.5, close=0.5, samples=4, end_camera=end)
    assert np.array_equal(renderer.render(start, shutter=closed).rgba, still.rgba)
    shutter = tilesplat.Shutter(open=0.0, close=1.0, samples=4, end_camera=end)
    blurred = renderer.render(start, shutter=shutter)
    assert renderer.last_frame_stats["samples"] == 4
    assert tilesplat.shutter_times(0.0, 1.0, 4) == [0.125, 0.375, 0.625, 0.875]
    frames = [renderer.render(tilesplat.camera_between(start, end, t)) for t in tilesplat.shutter_times(0, 1, 4)]
    # Alpha is the plain mean of the frames' alphas (colours are averaged in linear light).
    np.testing.assert_allclose(blurred.rgba[..., 3], np.mean([f.rgba[..., 3] for f in frames], axis=0), atol=1e-6)
    assert tilesplat.compare_images(blurred, still)["psnr_db"] < 40
    with pytest.raises(ValueError, match="0 <= open <= close <= 1"):
        tilesplat.Shutter(open=0.6, close=0.2, end_camera=end)
    # A rolling shutter: the top half from the first time's frame, the bottom half from the second's.
    rolling = tilesplat.Shutter(open=0.0, close=1.0, samples=2, end_camera=end, scan="top-to-bottom")
    assert rolling.scan == "top-to-bottom"
    rolled = renderer.render(start, shutter=rolling)
    halves = [renderer.render(tilesplat.camera_between(start, end, t)) for t in (0.25, 0.75)]
    rows = rolled.rgba.shape[0]
    assert np.array_equal(rolled.rgba[: rows // 2], halves[0].rgba[: rows // 2])
    assert np.array_equal(rolled.rgba[rows // 2 :], halves[1].rgba[rows // 2 :])
    with pytest.raises(ValueError, match="unknown shutter scan 'diagonal'"):
        tilesplat.Shutter(scan="diagonal")


def test_camera_models(playbot_renderer):
    scene, renderer = playbot_renderer
    camera = tilesplat.Camera.orbit(scene, 96, 64, azimuth_deg=30)
    assert camera.model == "pinhole" and list(camera.distortion) == [0.0] * 8
    fisheye = camera.fisheye(200)
    assert fisheye.model == "fisheye" and fisheye.position == camera.position
    wide = renderer.render(fisheye)
    assert tilesplat.compare_images(wide, renderer.render(camera))["psnr_db"] < 30  # another image
    distorted = tilesplat.Camera.orbit(scene, 96, 64, azimuth_deg=30)
    distorted.model = "opencv"
    distorted.distortion = [-0.1, 0.02, 0, 0, 0, 0, 0, 0]
    assert 20 < tilesplat.compare_images(renderer.render(distorted), renderer.render(camera))["psnr_db"] < 60
    orthographic = camera.orthographic(3.0)
    assert orthographic.model == "orthographic" and orthographic.fy == pytest.approx(64 / 3.0)
    assert renderer.render(orthographic).rgba[..., 3].max() > 0.5
    panorama = tilesplat.Camera.orbit(scene, 128, 64, azimuth_deg=30).equirectangular()
    assert panorama.model == "equirectangular" and panorama.fx == pytest.approx(128 / (2 * np.pi))
    assert renderer.render(panorama).rgba[..., 3].max() > 0.5
    with pytest.raises(ValueError, match="unknown camera model 'equirect'"):
        camera.model = "equirect"
    bad = camera.fisheye(180)
    bad.distortion = [0, 0, 0, 0, 0.1, 0, 0, 0]
    with pytest.raises(RuntimeError, match="the fisheye camera has 4 distortion coefficients"):
        renderer.render(bad)
