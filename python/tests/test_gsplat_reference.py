"""tilesplat.rasterization() held to gsplat's own PyTorch functions (gsplat_reference.py) on the CPU, for
every render mode and both rasterize modes, on the bundled scenes and on random inputs; and torch tensors
in and out. These need torch and gsplat: python/run_tests.sh runs them (marker `gsplat`) in a virtual
environment with Debian's python3-torch and gsplat from PyPI.
"""

import importlib
import time

import numpy as np
import pytest

import tilesplat
from conftest import BUNDLED_PLAYBOT, BUNDLED_SH3, require
from test_rasterization import gsplat_inputs, view_and_intrinsics

pytestmark = pytest.mark.gsplat

RENDER_MODES = ("RGB", "D", "ED", "RGB+D", "RGB+ED")
RASTERIZE_MODES = ("classic", "antialiased")
MIN_PSNR_DB = 60.0


def _importable(name):
    try:
        importlib.import_module(name)
        return True
    except ImportError:
        return False


@pytest.fixture(scope="module")
def reference():
    require(_importable("torch") and _importable("gsplat"), "torch and gsplat are not installed")
    import gsplat
    import gsplat_reference

    print(f"[ measure  ] gsplat {gsplat.__version__}, torch {importlib.import_module('torch').__version__}")
    return gsplat_reference


def psnr_and_max_abs(ours, theirs, peak):
    """PSNR against `peak` (1 for colours and alpha, the frame's largest reference value for depths) and
    the largest absolute difference."""
    mse = float(np.mean((ours.astype(np.float64) - theirs) ** 2))
    psnr = float("inf") if mse == 0 else 10 * np.log10(peak * peak / mse)
    return psnr, float(np.abs(ours - theirs).max())


def compare(reference, label, inputs, render_mode, rasterize_mode):
    """Renders `inputs` with both, prints the measures and holds every channel to MIN_PSNR_DB."""
    start = time.perf_counter()
    theirs_colors, theirs_alphas = reference.rasterization(**inputs, render_mode=render_mode,
                                                           rasterize_mode=rasterize_mode)
    reference_s = time.perf_counter() - start
    start = time.perf_counter()
    ours_colors, ours_alphas, _ = tilesplat.rasterization(**inputs, render_mode=render_mode,
                                                          rasterize_mode=rasterize_mode)
    ours_s = time.perf_counter() - start
    theirs_colors, theirs_alphas = theirs_colors.numpy(), theirs_alphas.numpy()
    assert ours_colors.shape == theirs_colors.shape and ours_alphas.shape == theirs_alphas.shape

    measures = {"alpha": psnr_and_max_abs(ours_alphas, theirs_alphas, 1.0)}
    if render_mode.startswith("RGB"):
        measures["rgb"] = psnr_and_max_abs(ours_colors[..., :3], theirs_colors[..., :3], 1.0)
    if "D" in render_mode:
        depth_peak = float(np.abs(theirs_colors[..., -1]).max())
        measures["depth"] = psnr_and_max_abs(ours_colors[..., -1], theirs_colors[..., -1], depth_peak)
    shown = ", ".join(f"{name} {psnr:.1f} dB (max abs {most:.1e})" for name, (psnr, most) in measures.items())
    print(f"[ measure  ] {label} {render_mode} {rasterize_mode}: {shown}; gsplat's PyTorch functions "
          f"{reference_s * 1e3:.0f} ms, tilesplat {ours_s * 1e3:.0f} ms")
    for name, (psnr, _) in measures.items():
        assert psnr >= MIN_PSNR_DB, f"{label} {render_mode} {rasterize_mode}: {name} {psnr:.1f} dB"


def bundled_inputs(path, width, height, azimuths):
    scene = tilesplat.load_scene(path)
    views = [view_and_intrinsics(tilesplat.Camera.orbit(scene, width, height, azimuth_deg=a)) for a in azimuths]
    return dict(**gsplat_inputs(scene), viewmats=np.stack([v for v, _ in views]),
                Ks=np.stack([k for _, k in views]), width=width, height=height, near_plane=0.2)


@pytest.fixture(scope="module")
def playbot_inputs():
    return bundled_inputs(BUNDLED_PLAYBOT, 160, 96, [40])


@pytest.fixture(scope="module")
def sh3_inputs():
    return bundled_inputs(BUNDLED_SH3, 96, 64, [20, 250])


@pytest.mark.parametrize("rasterize_mode", RASTERIZE_MODES)
@pytest.mark.parametrize("render_mode", RENDER_MODES)
def test_bundled_playbot_matches_gsplat(reference, playbot_inputs, render_mode, rasterize_mode):
    compare(reference, "playbot_lod3 (31,000, SH 2)", playbot_inputs, render_mode, rasterize_mode)


@pytest.mark.parametrize("rasterize_mode", RASTERIZE_MODES)
@pytest.mark.parametrize("render_mode", RENDER_MODES)
def test_bundled_sh3_scene_matches_gsplat(reference, sh3_inputs, render_mode, rasterize_mode):
    compare(reference, "playcanvas_test (64, SH 3), 2 cameras", sh3_inputs, render_mode, rasterize_mode)


def random_inputs(seed, sh_degree):
    """Gaussians in a box before two cameras (one with an off-centre principal point): random rotations,
    anisotropic scales, opacities up to 1 (some reach gsplat's alpha cap), colours or SH coefficients,
    and backgrounds."""
    rng = np.random.default_rng(seed)
    n = 3000
    means = rng.uniform([-1.5, -1.0, 2.0], [1.5, 1.0, 6.0], (n, 3))
    quats = rng.normal(size=(n, 4))
    scales = np.exp(rng.uniform(-4.5, -1.5, (n, 3)))
    opacities = np.where(rng.random(n) < 0.2, 1.0, rng.uniform(0.05, 1.0, n))
    if sh_degree is None:
        colors = rng.uniform(0, 1, (n, 3))
    else:
        colors = rng.normal(0, 0.4, (n, (sh_degree + 1) ** 2, 3))
    viewmats = np.stack([np.eye(4), np.eye(4)])
    angle = 0.2  # the second camera turned about y and moved sideways
    viewmats[1, :3, :3] = [[np.cos(angle), 0, -np.sin(angle)], [0, 1, 0], [np.sin(angle), 0, np.cos(angle)]]
    viewmats[1, :3, 3] = [0.5, 0.1, 0.3]
    Ks = np.array([[[110.0, 0, 64], [0, 110.0, 40], [0, 0, 1]], [[90.0, 0, 50], [0, 95.0, 45], [0, 0, 1]]])
    return dict(means=means, quats=quats, scales=scales, opacities=opacities, colors=colors, sh_degree=sh_degree,
                viewmats=viewmats, Ks=Ks, width=128, height=80, backgrounds=rng.uniform(0, 1, (2, 3)))


@pytest.mark.parametrize("sh_degree", [None, 1, 3])
@pytest.mark.parametrize("rasterize_mode", RASTERIZE_MODES)
def test_random_gaussians_match_gsplat(reference, sh_degree, rasterize_mode):
    inputs = random_inputs(7 + (sh_degree or 0), sh_degree)
    for render_mode in RENDER_MODES:
        compare(reference, f"random 3,000 (colours {'RGB' if sh_degree is None else f'SH {sh_degree}'})", inputs,
                render_mode, rasterize_mode)


def test_torch_tensors_in_and_out(reference, playbot_inputs):
    import torch

    as_tensors = {k: torch.as_tensor(v, dtype=torch.float32) if isinstance(v, np.ndarray) else v
                  for k, v in playbot_inputs.items()}
    colors, alphas, meta = tilesplat.rasterization(**as_tensors, render_mode="RGB+ED")
    assert isinstance(colors, torch.Tensor) and isinstance(alphas, torch.Tensor)
    assert colors.dtype == torch.float32 and tuple(colors.shape) == (1, 96, 160, 4) and colors.grad_fn is None
    numpy_colors, numpy_alphas, _ = tilesplat.rasterization(**playbot_inputs, render_mode="RGB+ED")
    # The same frame as from numpy, up to the float32 rounding of the inputs' conversion.
    np.testing.assert_allclose(colors.numpy(), numpy_colors, atol=1e-5)
    np.testing.assert_allclose(alphas.numpy(), numpy_alphas, atol=1e-5)
    assert meta["n_isects"][0] > 0 and meta["tile_width"] == 10 and meta["tile_height"] == 6

    # Gradients are asked for: the results are in the autograd graph, and the backward fills .grad.
    means = as_tensors["means"].clone().requires_grad_(True)
    colors, alphas, meta = tilesplat.rasterization(**{**as_tensors, "means": means}, packed=False)
    assert colors.requires_grad and colors.grad_fn is not None
    np.testing.assert_allclose(colors.detach().numpy(), numpy_colors[..., :3], atol=1e-5)
    (colors.sum() + alphas.sum()).backward()
    assert means.grad is not None and means.grad.shape == means.shape and float(means.grad.abs().sum()) > 0
    assert meta["unformed"] == 0
    with torch.no_grad():
        colors, _, _ = tilesplat.rasterization(**{**as_tensors, "means": means})
    assert colors.grad_fn is None
    # packed=True (gsplat's default) has no backward here: said before any work.
    with pytest.raises(NotImplementedError, match="packed=True has no backward pass"):
        tilesplat.rasterization(**{**as_tensors, "means": means})


GRADIENT_GROUPS = ("means", "quats", "scales", "opacities", "colors")


def gradients_of(rasterize, inputs, render_mode, rasterize_mode, seed, **extra):
    """d(sum of random weights times every output)/d(each input), in float64 through torch's autograd."""
    import torch

    tensors = {k: torch.tensor(np.asarray(v), dtype=torch.float64, requires_grad=k in GRADIENT_GROUPS)
               if isinstance(v, np.ndarray) else v for k, v in inputs.items()}
    colors, alphas = rasterize(**tensors, render_mode=render_mode, rasterize_mode=rasterize_mode, **extra)[:2]
    generator = torch.Generator().manual_seed(seed)
    weights = torch.rand(colors.shape, generator=generator, dtype=torch.float64) * 2 - 1
    alpha_weights = torch.rand(alphas.shape, generator=generator, dtype=torch.float64) * 2 - 1
    ((colors.double() * weights).sum() + (alphas.double() * alpha_weights).sum()).backward()
    # An input the outputs do not depend on (the colours of a depth-only mode) has no gradient: zeros.
    return {k: np.zeros(tensors[k].shape) if tensors[k].grad is None else tensors[k].grad.numpy()
            for k in GRADIENT_GROUPS}


def compare_gradients(reference, label, inputs, render_mode, rasterize_mode, bound):
    start = time.perf_counter()
    theirs = gradients_of(reference.rasterization, inputs, render_mode, rasterize_mode, 5)
    reference_s = time.perf_counter() - start
    start = time.perf_counter()
    ours = gradients_of(tilesplat.rasterization, inputs, render_mode, rasterize_mode, 5, packed=False)
    ours_s = time.perf_counter() - start
    errors = {k: float(np.linalg.norm(ours[k] - theirs[k]) / max(np.linalg.norm(theirs[k]), 1e-30))
              for k in GRADIENT_GROUPS}
    shown = "  ".join(f"{k} {e:.1e}" for k, e in errors.items())
    print(f"[ measure  ] gradients {label} {render_mode} {rasterize_mode}: relative error {shown}; forward+backward "
          f"gsplat's PyTorch functions {reference_s * 1e3:.0f} ms, tilesplat {ours_s * 1e3:.0f} ms")
    for k, e in errors.items():
        assert e < bound, f"{label} {render_mode} {rasterize_mode}: {k} gradient {e:.2e} from gsplat's"


@pytest.mark.parametrize("rasterize_mode", RASTERIZE_MODES)
@pytest.mark.parametrize("render_mode", RENDER_MODES)
def test_gradients_match_gsplats_autograd_on_random_gaussians(reference, render_mode, rasterize_mode):
    """Against gsplat's PyTorch functions differentiated by torch in float64: the same math, so the
    gradients agree but for the pixels where the two renderers' cut-offs (tile reach, alpha 1/255) or float32
    rounding make a splat count at one pixel in one and not the other."""
    inputs = random_inputs(21, 3)
    inputs = {**inputs, "viewmats": inputs["viewmats"][:1], "Ks": inputs["Ks"][:1], "backgrounds": None}
    compare_gradients(reference, "random 3,000 SH 3", inputs, render_mode, rasterize_mode, 2e-2)


@pytest.mark.parametrize("rasterize_mode", RASTERIZE_MODES)
def test_gradients_match_gsplats_autograd_on_the_bundled_scenes(reference, playbot_inputs, sh3_inputs,
                                                                rasterize_mode):
    compare_gradients(reference, "playbot_lod3 (31,000, SH 2)", playbot_inputs, "RGB", rasterize_mode, 2e-2)
    compare_gradients(reference, "playcanvas_test (64, SH 3), 2 cameras", sh3_inputs, "RGB+ED", rasterize_mode, 2e-2)


def test_gsplats_default_strategy_densifies_on_top(reference):
    """gsplat's DefaultStrategy reads meta's means2d gradient, radii, width, height and n_cameras: a few
    training steps with it on tilesplat.rasterization() clone, split and prune as it does on gsplat's own."""
    import torch
    from gsplat.strategy import DefaultStrategy

    inputs = random_inputs(22, None)
    n = inputs["means"].shape[0]
    params = torch.nn.ParameterDict({
        "means": torch.nn.Parameter(torch.tensor(inputs["means"], dtype=torch.float32)),
        "quats": torch.nn.Parameter(torch.tensor(inputs["quats"], dtype=torch.float32)),
        "scales": torch.nn.Parameter(torch.log(torch.tensor(inputs["scales"], dtype=torch.float32))),
        "opacities": torch.nn.Parameter(torch.logit(torch.tensor(np.clip(inputs["opacities"], 0.01, 0.99),
                                                                 dtype=torch.float32))),
        "colors": torch.nn.Parameter(torch.tensor(inputs["colors"], dtype=torch.float32)),
    })
    optimizers = {k: torch.optim.Adam([p], lr=1e-3) for k, p in params.items()}
    strategy = DefaultStrategy(refine_start_iter=2, refine_every=3, reset_every=1000, grow_grad2d=1e-6,
                               prune_opa=0.02, verbose=False)
    strategy.check_sanity(params, optimizers)
    state = strategy.initialize_state()
    viewmats = torch.tensor(inputs["viewmats"][:1], dtype=torch.float32)
    Ks = torch.tensor(inputs["Ks"][:1], dtype=torch.float32)
    target = torch.full((1, 80, 128, 3), 0.5)
    for step in range(7):
        colors, alphas, meta = tilesplat.rasterization(
            params["means"], params["quats"], torch.exp(params["scales"]), torch.sigmoid(params["opacities"]),
            params["colors"], viewmats, Ks, 128, 80, packed=False, absgrad=False)
        strategy.step_pre_backward(params, optimizers, state, step, meta)
        loss = ((colors - target) ** 2).mean()
        loss.backward()
        assert meta["means2d"].grad is not None and float(meta["means2d"].grad.abs().sum()) > 0
        for optimizer in optimizers.values():
            optimizer.step()
            optimizer.zero_grad(set_to_none=True)
        strategy.step_post_backward(params, optimizers, state, step, meta, packed=False)
    grown = params["means"].shape[0]
    print(f"[ measure  ] DefaultStrategy on tilesplat.rasterization(): {n} -> {grown} Gaussians in 7 steps")
    assert grown != n
    assert all(p.shape[0] == grown for p in params.values())
