"""tilesplat.rasterization(): gsplat's forward signature, shapes and render modes, rendered by the engine."""

import time

import numpy as np
import pytest

import tilesplat
from conftest import BUNDLED_PLAYBOT


def gsplat_inputs(scene):
    """A loaded scene's Gaussians as gsplat takes them: activated scales and opacities, SH [N, K, 3]."""
    return dict(means=scene.positions, quats=scene.rotations, scales=np.exp(scene.log_scales.astype(np.float64)),
                opacities=1 / (1 + np.exp(-scene.opacity_logits.astype(np.float64))), colors=scene.sh,
                sh_degree=scene.sh_degree)


def view_and_intrinsics(camera):
    """gsplat's viewmat (world to camera) and K of a tilesplat camera."""
    rotation = np.array(camera.rotation).reshape(3, 3)
    viewmat = np.eye(4)
    viewmat[:3, :3] = rotation
    viewmat[:3, 3] = -rotation @ np.array(camera.position)
    K = np.array([[camera.fx, 0, camera.cx], [0, camera.fy, camera.cy], [0, 0, 1]])
    return viewmat, K


@pytest.fixture(scope="module")
def playbot():
    scene = tilesplat.load_scene(BUNDLED_PLAYBOT)
    cameras = [tilesplat.Camera.orbit(scene, 160, 90, azimuth_deg=a) for a in (30, 200)]
    return scene, cameras


def test_matches_the_engine_render_of_the_same_scene(playbot):
    scene, cameras = playbot
    views = [view_and_intrinsics(c) for c in cameras]
    colors, alphas, meta = tilesplat.rasterization(**gsplat_inputs(scene), viewmats=np.stack([v for v, _ in views]),
                                                   Ks=np.stack([k for _, k in views]), width=160, height=90,
                                                   near_plane=0.2, render_mode="RGB+ED")
    assert colors.shape == (2, 90, 160, 4) and alphas.shape == (2, 90, 160, 1)
    assert meta["n_cameras"] == 2 and len(meta["visible"]) == 2 and meta["sort_strategy"]
    renderer = tilesplat.Renderer()
    renderer.set_scene(scene)
    for c, camera in enumerate(cameras):
        reference = renderer.render(camera, max_alpha=0.999)  # gsplat's cap, as rasterization() blends
        # The same frame up to the float32 rounding of exp(log scale) and sigmoid(logit) on the way in.
        difference = np.abs(colors[c, ..., :3] - reference.rgba[..., :3]).max()
        psnr = 10 * np.log10(1 / np.mean((colors[c, ..., :3] - reference.rgba[..., :3]) ** 2))
        print(f"[ measure  ] camera {c}: PSNR {psnr:.1f} dB, max abs {difference:.2e}")
        assert psnr >= 60 and difference < 2e-3
        np.testing.assert_allclose(alphas[c, ..., 0], reference.rgba[..., 3], atol=2e-3)
        covered = reference.rgba[..., 3] > 0.5
        np.testing.assert_allclose(colors[c, ..., 3][covered], reference.depth[covered], rtol=1e-3)


def test_render_modes_relate_as_gsplats(playbot):
    scene, cameras = playbot
    viewmat, K = view_and_intrinsics(cameras[0])
    inputs = dict(**gsplat_inputs(scene), viewmats=viewmat[None], Ks=K[None], width=160, height=90)
    rgb, alpha, _ = tilesplat.rasterization(**inputs, render_mode="RGB")
    d, _, _ = tilesplat.rasterization(**inputs, render_mode="D")
    ed, _, _ = tilesplat.rasterization(**inputs, render_mode="ED")
    rgbd, _, _ = tilesplat.rasterization(**inputs, render_mode="RGB+D")
    assert rgb.shape[-1] == 3 and d.shape[-1] == 1 and ed.shape[-1] == 1 and rgbd.shape[-1] == 4
    np.testing.assert_array_equal(rgbd[..., :3], rgb)
    np.testing.assert_array_equal(rgbd[..., 3:], d)
    covered = alpha > 1e-3
    np.testing.assert_allclose(d[covered], (ed * alpha)[covered], rtol=1e-6)
    white, _, _ = tilesplat.rasterization(**inputs, backgrounds=np.ones((1, 3)))
    np.testing.assert_allclose(white, rgb + (1 - alpha), atol=1e-6)


def test_rgb_colors_near_and_far_planes():
    # Three opaque splats straight ahead at depths 0.1, 1 and 5, red, green and blue.
    means = np.array([[0, 0, 0.1], [0, 0, 1.0], [0, 0, 5.0]])
    inputs = dict(means=means, quats=np.tile([1.0, 0, 0, 0], (3, 1)), scales=np.array([[0.01] * 3, [0.3] * 3,
                  [2.0] * 3]), opacities=np.full(3, 0.99), colors=np.eye(3), viewmats=np.eye(4)[None],
                  Ks=np.array([[[50.0, 0, 16], [0, 50.0, 16], [0, 0, 1]]]), width=32, height=32)
    nearest = lambda **extra: tilesplat.rasterization(**inputs, **extra)[0][0, 16, 16]  # noqa: E731
    np.testing.assert_allclose(nearest(near_plane=0.01), [0.99, 0, 0], atol=0.02)  # the red one in front
    np.testing.assert_allclose(nearest(near_plane=0.5), [0, 0.99, 0], atol=0.02)  # culled: green
    far = nearest(near_plane=0.5, far_plane=0.9)
    assert far.max() < 1e-6  # nothing left between the planes
    _, _, meta = tilesplat.rasterization(**inputs, near_plane=0.5, far_plane=3.0)
    assert meta["visible"] == [1]
    per_camera = np.stack([np.eye(3), np.eye(3)[::-1]])  # [C, N, 3]: blue, green, red for camera 1
    two, _, _ = tilesplat.rasterization(**{**inputs, "viewmats": np.stack([np.eye(4)] * 2),
                                            "Ks": np.concatenate([inputs["Ks"]] * 2), "colors": per_camera},
                                        near_plane=0.01)
    np.testing.assert_allclose(two[1, 16, 16], [0, 0, 0.99], atol=0.02)


def test_what_it_does_not_do_is_said():
    inputs = dict(means=np.zeros((1, 3)), quats=[[1.0, 0, 0, 0]], scales=np.ones((1, 3)), opacities=[0.5],
                  colors=np.ones((1, 3)), viewmats=np.eye(4)[None], Ks=np.eye(3)[None], width=8, height=8)
    for argument, value in [("camera_model", "fisheye"), ("with_ut", True), ("eps2d", 0.1),
                            ("radius_clip", 1.0), ("distributed", True), ("covars", np.zeros((1, 3, 3)))]:
        with pytest.raises(NotImplementedError, match=argument):
            tilesplat.rasterization(**inputs, **{argument: value})
    with pytest.raises(NotImplementedError, match="unknown_option"):
        tilesplat.rasterization(**inputs, unknown_option=1)
    with pytest.raises(ValueError, match=r"quats must have the shape \(1, 4\), got \(1, 3\)"):
        tilesplat.rasterization(**{**inputs, "quats": [[1.0, 0, 0]]})
    with pytest.raises(ValueError, match="render_mode must be one of"):
        tilesplat.rasterization(**inputs, render_mode="RGB+N")
    with pytest.raises(ValueError, match="non-finite"):
        tilesplat.rasterization(**{**inputs, "means": [[np.nan, 0, 1]]})
    for bad in (np.array([[1 + 2j, 0, 1]]), [["a", "b", "c"]], np.array([[True, False, True]])):
        with pytest.raises(ValueError, match="means must hold real numbers"):
            tilesplat.rasterization(**{**inputs, "means": bad})
    with pytest.raises(ValueError, match="opacities must be in"):
        tilesplat.rasterization(**{**inputs, "opacities": [1.5]})


@pytest.mark.parametrize("change, message", [
    (dict(far_plane=float("nan")), "far_plane must be beyond near_plane"),
    (dict(far_plane=0.005), "far_plane must be beyond near_plane"),
    (dict(near_plane=float("nan")), "near_plane must be a positive finite number"),
    (dict(near_plane=0.0), "near_plane must be a positive finite number"),
    (dict(Ks=[[[10.0, 0.5, 4], [0, 10, 4], [0, 0, 1]]]), "Ks must be pinhole intrinsics"),
    (dict(Ks=[[[10.0, 0, 4], [0, 10, 4], [0, 0, 2]]]), "Ks must be pinhole intrinsics"),
    (dict(Ks=[[[-10.0, 0, 4], [0, 10, 4], [0, 0, 1]]]), "Ks must have positive focal lengths"),
    (dict(Ks=np.eye(3)[None].repeat(2, axis=0)), r"Ks must have the shape \(1, 3, 3\)"),
    (dict(Ks=np.eye(3)), r"Ks must have the shape \(1, 3, 3\)"),
    (dict(scales=[[0.0, 1, 1]]), "scales must be positive"),
    (dict(scales=[[-1.0, 1, 1]]), "scales must be positive"),
    (dict(backgrounds=np.zeros((2, 3))), r"backgrounds must have the shape \(1, 3\)"),
    (dict(backgrounds=np.zeros(3)), r"backgrounds must have the shape \(1, 3\)"),
    (dict(width=0), "width must be a positive integer"),
    (dict(width=-8), "width must be a positive integer"),
    (dict(height=0), "height must be a positive integer"),
    (dict(height=8.5), "height must be a positive integer"),
    (dict(colors=np.ones((1, 3, 3)), sh_degree=1), "colors holds 3 SH coefficients, sh_degree 1 needs 4"),
    (dict(colors=np.ones((1, 1, 3)), sh_degree=3), "colors holds 1 SH coefficients, sh_degree 3 needs 16"),
])
def test_bad_arguments_are_refused_naming_them(change, message):
    """Each a ValueError naming the argument, before any rendering: never an empty image."""
    inputs = dict(means=[[0.0, 0, 2]], quats=[[1.0, 0, 0, 0]], scales=np.full((1, 3), 0.5), opacities=[0.5],
                  colors=np.ones((1, 3)), viewmats=np.eye(4)[None], Ks=[[[10.0, 0, 4], [0, 10, 4], [0, 0, 1]]],
                  width=8, height=8)
    colors, _, _ = tilesplat.rasterization(**inputs)  # the unchanged call draws
    assert colors.shape == (1, 8, 8, 3) and colors.max() > 0
    with pytest.raises(ValueError, match=message):
        tilesplat.rasterization(**{**inputs, **change})


def test_a_batch_of_cameras_costs_less_than_separate_calls(playbot):
    scene, _ = playbot
    inputs = gsplat_inputs(scene)
    views = [view_and_intrinsics(c) for c in tilesplat.orbit_cameras(scene, 8, 320, 180)]
    viewmats, Ks = np.stack([v for v, _ in views]), np.stack([k for _, k in views])
    tilesplat.rasterization(**inputs, viewmats=viewmats[:1], Ks=Ks[:1], width=320, height=180)  # warm up
    start = time.perf_counter()
    batch, _, _ = tilesplat.rasterization(**inputs, viewmats=viewmats, Ks=Ks, width=320, height=180)
    batched = time.perf_counter() - start
    start = time.perf_counter()
    single = [tilesplat.rasterization(**inputs, viewmats=viewmats[c:c + 1], Ks=Ks[c:c + 1], width=320,
                                      height=180)[0] for c in range(8)]
    separate = time.perf_counter() - start
    print(f"[ measure  ] 8 cameras of 320x180: one call {batched * 1e3:.1f} ms, 8 calls {separate * 1e3:.1f} ms")
    np.testing.assert_array_equal(batch, np.concatenate(single))
