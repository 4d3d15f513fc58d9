"""Gradients from Python without torch: Renderer.backward and reference_backward on numpy arrays, and
rasterization_backward for numpy callers of rasterization(), each against the float64 reference or against
central differences of the forward."""

import numpy as np
import pytest

import tilesplat
from conftest import BUNDLED_PLAYBOT


@pytest.fixture(scope="module")
def playbot():
    scene = tilesplat.load_scene(BUNDLED_PLAYBOT)
    renderer = tilesplat.Renderer(validation=True)
    renderer.set_scene(scene)
    return scene, renderer


def relative_error(ours, reference):
    return float(np.linalg.norm(ours - reference) / max(np.linalg.norm(reference), 1e-30))


def test_backward_matches_the_float64_reference(playbot):
    scene, renderer = playbot
    camera = tilesplat.Camera.orbit(scene, 160, 90, azimuth_deg=30)
    rng = np.random.default_rng(1)
    grads = dict(grad_rgb=rng.uniform(-1, 1, (90, 160, 3)).astype(np.float32),
                 grad_alpha=rng.uniform(-1, 1, (90, 160)).astype(np.float32),
                 grad_expected_depth=rng.uniform(-0.1, 0.1, (90, 160)).astype(np.float32))
    renderer.render(camera, reuse_lists=True)
    ours = renderer.backward(camera, **grads, reuse_lists=True)
    assert renderer.last_frame_stats["reused_sorted_lists"]
    assert [name for name, _ in renderer.last_frame_stats["passes"]] == ["composite_backward", "projection_backward"]
    reference = tilesplat.reference_backward(camera, scene, **grads)
    for name in ("positions", "log_scales", "rotations", "opacity_logits", "sh", "means2d"):
        assert ours[name].shape == reference[name].shape, name
        assert relative_error(ours[name], reference[name]) < 1e-4, name
    assert ours["sh"].shape == (scene.size, 9, 3) and ours["unformed"] == 0
    assert np.abs(ours["positions"]).sum() > 0
    assert renderer.validation_messages == 0


def test_backward_refuses_what_it_does_not_cover(playbot):
    scene, renderer = playbot
    camera = tilesplat.Camera.orbit(scene, 32, 24)
    grad = np.ones((24, 32, 3), np.float32)
    with pytest.raises(NotImplementedError, match="stochastic compositor"):
        renderer.backward(camera, grad_rgb=grad, compositor="stochastic")
    with pytest.raises(tilesplat.NotDifferentiable, match="accuracy mode depth16"):
        renderer.backward(camera, grad_rgb=grad, accuracy="depth16")
    with pytest.raises(ValueError, match=r"grad_rgb must have the shape \(24, 32, 3\)"):
        renderer.backward(camera, grad_rgb=np.ones((24, 32), np.float32))
    with pytest.raises(ValueError, match="grad_alpha holds a non-finite value"):
        renderer.backward(camera, grad_alpha=np.full((24, 32), np.nan, np.float32))


def random_inputs(n, seed):
    rng = np.random.default_rng(seed)
    means = rng.uniform(-1, 1, (n, 3)) * [1.0, 0.6, 0.5] + [0, 0, 4]
    return dict(means=means, quats=rng.normal(size=(n, 4)), scales=np.exp(rng.uniform(-3.2, -2.2, (n, 3))),
                opacities=rng.uniform(0.1, 0.9, n), colors=rng.uniform(0.1, 0.9, (n, 3)),
                viewmats=np.eye(4)[None], Ks=np.array([[[60.0, 0, 32], [0, 60.0, 20], [0, 0, 1]]]), width=64,
                height=40, backgrounds=np.array([[0.2, 0.3, 0.4]]), packed=False)


def test_rasterization_backward_against_finite_differences():
    """The numpy path: keep_backward_state, then rasterization_backward; each gsplat parameter's gradient
    against central differences of rasterization() itself (in float32, so a coarse step and tolerance)."""
    inputs = random_inputs(60, 2)
    rng = np.random.default_rng(3)
    grad_colors = rng.uniform(-1, 1, (1, 40, 64, 3)).astype(np.float32)
    grad_alphas = rng.uniform(-1, 1, (1, 40, 64, 1)).astype(np.float32)

    def loss(**changed):
        colors, alphas, _ = tilesplat.rasterization(**{**inputs, **changed})
        return float((colors.astype(np.float64) * grad_colors).sum() + (alphas * grad_alphas).sum())

    _, _, meta = tilesplat.rasterization(**inputs, keep_backward_state=True)
    grads = tilesplat.rasterization_backward(meta["backward_state"], grad_colors, grad_alphas)
    assert grads["unformed"] == 0
    checked = 0
    for name, index, step in (("means", (5, 0), 1e-3), ("means", (7, 2), 1e-3), ("scales", (3, 1), 1e-4),
                              ("opacities", (11,), 1e-3), ("colors", (13, 2), 1e-3), ("quats", (17, 3), 1e-3),
                              ("backgrounds", (0, 1), 1e-3)):
        plus, minus = inputs[name].copy(), inputs[name].copy()
        plus[index] += step
        minus[index] -= step
        numeric = (loss(**{name: plus}) - loss(**{name: minus})) / (2 * step)
        analytic = float(grads[name][index])
        assert abs(analytic - numeric) <= 2e-2 * abs(numeric) + 2e-3, (name, index, analytic, numeric)
        checked += abs(numeric) > 1e-3
    assert checked >= 5  # the chosen parameters move the loss


def test_a_trained_scene_leaves_as_the_trainers_ply(tmp_path):
    """Scene.write_ply: the arrays a trainer ends with, written as the PLY every viewer reads and loaded back
    to the bit (its quaternions normalized, as every reader gives them)."""
    rng = np.random.default_rng(4)
    n = 50
    arrays = dict(positions=rng.normal(size=(n, 3)).astype(np.float32),
                  log_scales=rng.uniform(-5, 0, (n, 3)).astype(np.float32),
                  rotations=rng.normal(size=(n, 4)).astype(np.float32),
                  opacity_logits=rng.normal(size=n).astype(np.float32),
                  sh=rng.normal(size=(n, 16, 3)).astype(np.float32))
    scene = tilesplat.Scene.from_arrays(**arrays)
    path = tmp_path / "trained.ply"
    scene.write_ply(path)
    back = tilesplat.load_scene(path)
    for name in ("positions", "log_scales", "opacity_logits", "sh"):
        assert np.array_equal(getattr(back, name), arrays[name]), name
    q = arrays["rotations"].astype(np.float64)
    np.testing.assert_allclose(back.rotations, q / np.linalg.norm(q, axis=1, keepdims=True), atol=1e-7)
    with pytest.raises(RuntimeError, match="no_such_directory"):
        scene.write_ply(tmp_path / "no_such_directory" / "trained.ply")
    assert not (tmp_path / "no_such_directory").exists()
