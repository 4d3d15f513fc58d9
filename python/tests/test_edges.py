"""Hard cases through the Python edges (issue 58): a scene whose colours are finite but far outside [0, 1]
renders finite arrays from render() and rasterization(), and its EXR stays finite, the values past a type's
range saturated to the type's largest finite value and counted."""

import numpy as np
import pytest

import tilesplat

FLOAT_MAX = float(np.finfo(np.float32).max)


def three_splats(dc):
    """Three overlapping splats straight ahead at depth 3, the middle one in front and of SH DC `dc` (degree 0)."""
    positions = np.array([[-0.3, 0, 3.03], [0, 0, 3.0], [0.3, 0, 3.06]], np.float32)
    sh = np.array([[0.5] * 3, [dc] * 3, [0.5] * 3], np.float32).reshape(3, 1, 3)
    return tilesplat.Scene.from_arrays(positions, np.full((3, 3), -1.5, np.float32),
                                       np.tile(np.array([1, 0, 0, 0], np.float32), (3, 1)),
                                       np.full(3, 4.0, np.float32), sh)


@pytest.fixture(scope="module")
def renderer():
    return tilesplat.Renderer(validation=True)


@pytest.mark.parametrize("dc, past_float, past_half", [(1e20, True, True), (400.0, False, True),
                                                         (-1e20, False, False)])
def test_huge_colours_stay_finite_in_arrays_and_files(renderer, tmp_path, dc, past_float, past_half):
    renderer.set_scene(three_splats(dc))
    camera = tilesplat.Camera.look_at([0, 0, 0], [0, 0, 3], [0, -1, 0], 64, 48, 60.0)
    image = renderer.render(camera)
    assert np.isfinite(image.rgba).all() and np.isfinite(image.depth).all()
    assert renderer.last_frame_stats["saturated"] == {}  # render() returns floats: nothing saturates

    saturated = image.write_exr(tmp_path / "linear.exr")
    assert (sum(saturated.values()) > 0) == past_float, saturated
    stored = tilesplat.read_exr(tmp_path / "linear.exr")  # encoded back to display values
    assert np.isfinite(stored.rgba).all()
    if not past_float:  # where every value fits, the file is the frame
        np.testing.assert_allclose(stored.rgba, image.rgba, rtol=1e-5, atol=2e-6)

    saturated_half = image.write_exr(tmp_path / "half.exr", half=True)
    assert (sum(saturated_half.values()) > 0) == past_half, saturated_half
    assert set(saturated_half) <= {"R", "G", "B", "A"}
    assert np.isfinite(tilesplat.read_exr(tmp_path / "half.exr").rgba).all()

    # gsplat's rasterization() of the same Gaussians: finite, and the engine's frame.
    viewmat = np.eye(4)
    K = np.array([[camera.fx, 0, camera.cx], [0, camera.fy, camera.cy], [0, 0, 1]])
    colors, alphas, _ = tilesplat.rasterization(
        means=np.array([[-0.3, 0, 3.03], [0, 0, 3.0], [0.3, 0, 3.06]]), quats=np.tile([1.0, 0, 0, 0], (3, 1)),
        scales=np.full((3, 3), np.exp(-1.5)), opacities=np.full(3, 1 / (1 + np.exp(-4.0))),
        colors=np.array([[0.5] * 3, [dc] * 3, [0.5] * 3]).reshape(3, 1, 3), sh_degree=0, viewmats=viewmat[None],
        Ks=K[None], width=64, height=48)
    assert np.isfinite(colors).all() and np.isfinite(alphas).all()
    np.testing.assert_allclose(colors[0], image.rgba[..., :3], rtol=1e-5, atol=1e-5)
