"""gsplat's forward rasterization() on tilesplat: the same arguments, shapes and returns, rendered by the
Vulkan engine on any device (lavapipe included). Forward only: no gradients.

The inputs are gsplat's activated parameters (scales, opacities in [0, 1]); the engine stores the trainer's
(log scales, opacity logits), so they are converted on the way in, which costs a float32 rounding of each
scale and opacity. Frames are blended with gsplat's rules (alpha capped at 0.999, RenderSettings::max_alpha).
What the engine does not do raises NotImplementedError naming the argument.

numpy arrays and torch tensors are both taken; torch is never imported unless a tensor is passed. With
tensors (on any device: they travel through the CPU) the results are tensors on the device of `means`.
Results of inputs that require gradients carry a backward that raises NotImplementedError.
"""

import numpy as np

from ._core import Camera, Renderer, Scene

_SH_C0 = 0.28209479177387814  # the degree-0 SH basis constant: colour = C0 * dc + 0.5
_GSPLAT_MAX_ALPHA = 0.999  # gsplat's rasterize_to_pixels caps alpha here (3DGS: 0.99)
_TILE_SIZE = 16
_RENDER_MODES = ("RGB", "D", "ED", "RGB+D", "RGB+ED")
_RASTERIZE_MODES = {"classic": "classic", "antialiased": "antialiased"}

_renderer = None


def _default_renderer():
    """One renderer for every call (its pipelines are built once): the default device."""
    global _renderer
    if _renderer is None:
        _renderer = Renderer()
    return _renderer


def _is_tensor(value):
    """Whether `value` is a torch tensor, without importing torch."""
    return type(value).__module__.split(".")[0] == "torch" and hasattr(value, "detach")


def _array(name, value, shape, dtype=np.float32):
    """`value` (array-like or torch tensor) as a C-contiguous array of `dtype` with `shape` (None: any size
    on that axis)."""
    if _is_tensor(value):
        value = value.detach().cpu().numpy()
    array = np.asarray(value)
    if array.dtype.kind not in "fiu":
        raise ValueError(f"{name} must hold real numbers, got dtype {array.dtype}")
    array = np.ascontiguousarray(array, dtype=dtype)
    if array.ndim != len(shape) or any(want is not None and got != want for got, want in zip(array.shape, shape)):
        expected = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
        raise ValueError(f"{name} must have the shape {expected}, got {tuple(array.shape)}")
    if not np.isfinite(array).all():
        raise ValueError(f"{name} holds a non-finite value")
    return array


def _camera(viewmat, K, width, height):
    """A tilesplat Camera from gsplat's world-to-camera matrix (OpenCV axes: x right, y down, z forward,
    as tilesplat's) and its intrinsics."""
    rotation = viewmat[:3, :3].astype(np.float64)
    translation = viewmat[:3, 3].astype(np.float64)
    if not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-4) or np.linalg.det(rotation) < 0:
        raise ValueError("viewmats must hold rigid transforms (a rotation and a translation)")
    camera = Camera()
    camera.width, camera.height = int(width), int(height)
    camera.fx, camera.fy = float(K[0, 0]), float(K[1, 1])
    camera.cx, camera.cy = float(K[0, 2]), float(K[1, 2])
    camera.rotation = rotation.flatten().tolist()
    camera.position = (-rotation.T @ translation).tolist()
    return camera


def _as_tensors(means, inputs, outputs):
    """The results as torch tensors on the device of `means`; when an input requires gradients (and
    autograd is on), joined to them by a backward that says this is forward only."""
    import torch

    results = tuple(torch.from_numpy(output).to(means.device) for output in outputs)
    needing_grad = [t for t in inputs if _is_tensor(t) and t.requires_grad]
    if needing_grad and torch.is_grad_enabled():
        results = _forward_only(torch).apply(len(results), *results, *needing_grad)
    return results


_FORWARD_ONLY = None


def _forward_only(torch):
    """An autograd function that passes the results through and refuses a backward pass."""
    global _FORWARD_ONLY
    if _FORWARD_ONLY is None:
        class ForwardOnly(torch.autograd.Function):
            @staticmethod
            def forward(ctx, count, *tensors):
                return tuple(t.clone() for t in tensors[:count])

            @staticmethod
            def backward(ctx, *grads):
                raise NotImplementedError("tilesplat.rasterization() is forward only: it has no backward pass "
                                          "(train with gsplat; render with tilesplat)")

        _FORWARD_ONLY = ForwardOnly
    return _FORWARD_ONLY


def _unsupported(**arguments):
    for name, (value, default) in arguments.items():
        if (value is not None) if default is None else (value != default):
            shown = type(value).__name__ if isinstance(value, np.ndarray) else repr(value)
            raise NotImplementedError(f"rasterization(): {name}={shown} is not supported by tilesplat "
                                      f"(only {default!r}): it renders the forward pass of pinhole cameras")


def rasterization(means, quats, scales, opacities, colors, viewmats, Ks, width, height, near_plane=0.01,
                  far_plane=1e10, radius_clip=0.0, eps2d=0.3, sh_degree=None, packed=True, tile_size=16,
                  backgrounds=None, render_mode="RGB", sparse_grad=False, absgrad=False,
                  rasterize_mode="classic", channel_chunk=32, distributed=False, camera_model="pinhole",
                  segmented=False, covars=None, with_ut=False, with_eval3d=False, renderer=None, **others):
    """gsplat.rasterization()'s forward pass on tilesplat.

    means [N, 3], quats [N, 4] (w x y z, any length), scales [N, 3], opacities [N] in [0, 1], colors [N, 3]
    (or [C, N, 3] per camera) RGB, or with sh_degree SH coefficients [N, K, 3] with K >= (sh_degree + 1)^2;
    viewmats [C, 4, 4] world-to-camera, Ks [C, 3, 3]; backgrounds [C, 3].

    Returns (render_colors [C, H, W, X], render_alphas [C, H, W, 1], meta), X = 3 for "RGB", 1 for "D" and
    "ED", 4 for "RGB+D" and "RGB+ED". D is the alpha-weighted depth sum, ED = D / alpha (0 where no splat
    was blended). numpy arrays in give numpy arrays out; torch tensors give tensors on the device of
    `means` (the type of `means` decides).

    meta holds gsplat's scalar entries (width, height, n_cameras, tile_size, tile_width, tile_height,
    near_plane, far_plane) and what the engine measures per camera: "visible" Gaussians, "n_isects" (tile
    intersections, gsplat's name) and "gpu_ms", with the "sort_strategy" that ran. gsplat's per-Gaussian
    tensors (radii, means2d, conics, ...) stay on the device and are not returned.

    Differences from gsplat: without sh_degree, colours below 0 are clamped to 0 (the engine's colour is
    max(C0 * dc + 0.5, 0)); packed, channel_chunk and sparse_grad change nothing here. renderer: a
    tilesplat.Renderer to use (default: one on the default device, kept between calls).
    """
    if others:
        raise NotImplementedError("rasterization(): " + ", ".join(sorted(others)) + " not supported by tilesplat")
    _unsupported(radius_clip=(radius_clip, 0.0), eps2d=(eps2d, 0.3), tile_size=(tile_size, 16),
                 absgrad=(absgrad, False), distributed=(distributed, False), camera_model=(camera_model, "pinhole"),
                 segmented=(segmented, False), covars=(covars, None), with_ut=(with_ut, False),
                 with_eval3d=(with_eval3d, False))
    if render_mode not in _RENDER_MODES:
        raise ValueError(f"render_mode must be one of {', '.join(_RENDER_MODES)}, got {render_mode!r}")
    if rasterize_mode not in _RASTERIZE_MODES:
        raise ValueError(f"rasterize_mode must be classic or antialiased, got {rasterize_mode!r}")

    for name, size in (("width", width), ("height", height)):
        if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size <= 0:
            raise ValueError(f"{name} must be a positive integer, got {size!r}")
    if not np.isfinite(near_plane) or near_plane <= 0:
        raise ValueError(f"near_plane must be a positive finite number, got {near_plane!r}")
    if np.isnan(far_plane) or far_plane <= near_plane:
        raise ValueError(f"far_plane must be beyond near_plane ({near_plane!r}), got {far_plane!r}")

    tensors_in = _is_tensor(means)
    tensor_inputs = (means, quats, scales, opacities, colors, viewmats, Ks, backgrounds)
    means = _array("means", means, (None, 3))
    n = means.shape[0]
    quats = _array("quats", quats, (n, 4))
    scales = _array("scales", scales, (n, 3))
    opacities = _array("opacities", opacities, (n,))
    viewmats = _array("viewmats", viewmats, (None, 4, 4), np.float64)
    cameras = viewmats.shape[0]
    Ks = _array("Ks", Ks, (cameras, 3, 3), np.float64)
    # A pinhole's intrinsics: focal lengths and principal point only (tilesplat's camera has no skew).
    if (Ks[:, 0, 1] != 0).any() or (Ks[:, 1, 0] != 0).any() or (Ks[:, 2] != [0, 0, 1]).any():
        raise ValueError("Ks must be pinhole intrinsics [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]: a non-zero skew "
                         "(K[0, 1]) or another last row is not supported")
    if (Ks[:, 0, 0] <= 0).any() or (Ks[:, 1, 1] <= 0).any():
        raise ValueError("Ks must have positive focal lengths (K[0, 0], K[1, 1])")
    if (scales <= 0).any():
        raise ValueError("scales must be positive")
    if ((opacities < 0) | (opacities > 1)).any():
        raise ValueError("opacities must be in [0, 1]")
    if sh_degree is None:
        per_camera = (colors.dim() if _is_tensor(colors) else np.ndim(colors)) == 3
        colors = _array("colors", colors, (cameras, n, 3) if per_camera else (n, 3))
        sh = ((colors - 0.5) / _SH_C0)[..., None, :]  # degree 0: [.., N, 1, 3]
    else:
        if sh_degree not in (0, 1, 2, 3):
            raise ValueError(f"sh_degree must be 0..3, got {sh_degree}")
        per_camera = False
        coefficients = (sh_degree + 1) ** 2
        sh = _array("colors", colors, (n, None, 3))
        if sh.shape[1] < coefficients:
            raise ValueError(f"colors holds {sh.shape[1]} SH coefficients, sh_degree {sh_degree} needs "
                             f"{coefficients}")
        sh = sh[:, :coefficients, :]
    if backgrounds is not None:
        backgrounds = _array("backgrounds", backgrounds, (cameras, 3))

    # The trainer's parameters, as the engine stores them. A probability of exactly 0 or 1 has no finite
    # logit: the nearest ones that have are used (an alpha at the cap or below 1/255 either way).
    log_scales = np.log(scales.astype(np.float64)).astype(np.float32)
    clipped = np.clip(opacities.astype(np.float64), 1e-12, 1 - 1e-7)
    logits = np.log(clipped / (1 - clipped)).astype(np.float32)

    renderer = renderer or _default_renderer()
    colour_out = render_mode.startswith("RGB")
    depth_out = "D" in render_mode
    settings = dict(near_plane=float(near_plane), antialiasing=_RASTERIZE_MODES[rasterize_mode],
                    max_alpha=_GSPLAT_MAX_ALPHA, depth=depth_out, splat_count=False, reuse_lists=False)
    channels = (3 if colour_out else 0) + (1 if depth_out else 0)
    render_colors = np.zeros((cameras, height, width, channels), np.float32)
    render_alphas = np.zeros((cameras, height, width, 1), np.float32)
    meta = {"width": width, "height": height, "n_cameras": cameras, "tile_size": _TILE_SIZE,
            "tile_width": -(-width // _TILE_SIZE), "tile_height": -(-height // _TILE_SIZE),
            "near_plane": near_plane, "far_plane": far_plane, "visible": [], "n_isects": [], "gpu_ms": [],
            "sort_strategy": None}

    uploaded = None
    for c in range(cameras):
        camera = _camera(viewmats[c], Ks[c], width, height)
        # gsplat culls means at or beyond the far plane; the engine has none, so they leave the scene.
        depths = means.astype(np.float64) @ viewmats[c, 2, :3] + viewmats[c, 2, 3]
        keep = depths < far_plane
        key = (c if per_camera else None, None if keep.all() else c)
        if key != uploaded:
            rows = slice(None) if keep.all() else keep
            scene = Scene.from_arrays(means[rows], log_scales[rows], quats[rows], logits[rows],
                                      sh[c][rows] if per_camera else sh[rows])
            renderer.set_scene(scene)
            uploaded = key
        background = [0.0, 0.0, 0.0] if backgrounds is None else backgrounds[c].tolist()
        image = renderer.render(camera, background=background, **settings)
        stats = renderer.last_frame_stats
        meta["visible"].append(stats["visible"])
        meta["n_isects"].append(stats["intersections"])
        meta["gpu_ms"].append(stats["gpu_ms"])
        meta["sort_strategy"] = stats["sort_strategy"]
        alpha = image.rgba[..., 3]
        render_alphas[c, ..., 0] = alpha
        if colour_out:
            render_colors[c, ..., :3] = image.rgba[..., :3]
        if depth_out:
            expected = image.depth
            render_colors[c, ..., -1] = expected if render_mode.endswith("ED") else expected * alpha
    if tensors_in:
        render_colors, render_alphas = _as_tensors(tensor_inputs[0], tensor_inputs,
                                                   (render_colors, render_alphas))
    return render_colors, render_alphas, meta
