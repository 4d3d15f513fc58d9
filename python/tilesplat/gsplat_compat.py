"""gsplat's rasterization() on tilesplat: the same arguments, shapes and returns, rendered by the Vulkan
engine on any device (lavapipe included), with its backward pass (Renderer.backward) in torch's autograd.

The inputs are gsplat's activated parameters (scales, opacities in [0, 1]); the engine stores the trainer's
(log scales, opacity logits), so they are converted on the way in, which costs a float32 rounding of each
scale and opacity. Frames are blended with gsplat's rules (alpha capped at 0.999, RenderSettings::max_alpha).
What the engine does not do raises NotImplementedError naming the argument.

numpy arrays and torch tensors are both taken; torch is never imported unless a tensor is passed. With
tensors (on any device: they travel through the CPU) the results are tensors on the device of `means`.
When an input requires gradients (and autograd is on), the results are in the autograd graph: their
backward runs the engine's backward passes (docs/gradients.md) and gives means, quats, scales, opacities,
colors and backgrounds their gradients, and meta["means2d"] its .grad (and .absgrad with absgrad=True), as
gsplat's densification strategies read them. numpy callers get the same gradients from
rasterization_backward().
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


_GRADIENT_INPUTS = ("means", "quats", "scales", "opacities", "colors", "backgrounds")
_uploads = 0  # set_scene calls made here: which upload a renderer's scene is (_Frame.upload)


class _Frame:
    """One rasterization() call, checked and converted: what the forward rendered and its backward needs."""

    def __init__(self, **fields):
        self.__dict__.update(fields)
        self.upload = None  # (_uploads at the upload, camera key) of the scene on the renderer

    def set_scene_for(self, c):
        """Uploads the scene camera c sees (its colours, its far plane's cut) unless the renderer has it."""
        global _uploads
        key = (c if self.per_camera else None, None if self.keep[c].all() else c)
        if self.upload is not None and self.upload == (_uploads, key):
            return
        rows = self.keep[c]
        sh = self.sh[c] if self.per_camera else self.sh
        scene = Scene.from_arrays(self.means[rows], self.log_scales[rows], self.quats[rows], self.logits[rows], sh[rows])
        self.renderer.set_scene(scene)
        _uploads += 1
        self.upload = (_uploads, key)

    def settings(self, c):
        background = [0.0, 0.0, 0.0] if self.backgrounds is None else self.backgrounds[c].tolist()
        return dict(self.base_settings, background=background)


def _projected_means_and_radii(frame):
    """gsplat's means2d [C, N, 2] (pixels) and radii [C, N, 2] (int32: the 3-sigma half extents of each
    axis of the dilated 2D covariance, 0 where the Gaussian is not drawn: at or before the near plane, at or
    beyond the far plane, or off the image), from the same pinhole math as the engine's projection."""
    cameras, n = len(frame.cameras), frame.means.shape[0]
    means2d = np.zeros((cameras, n, 2), np.float32)
    radii = np.zeros((cameras, n, 2), np.int32)
    q = frame.quats.astype(np.float64)
    q = q / np.maximum(np.linalg.norm(q, axis=1, keepdims=True), 1e-300)
    w, x, y, z = q.T
    rotations = np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                          2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                          2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1).reshape(n, 3, 3)
    rs = rotations * np.exp(frame.log_scales.astype(np.float64))[:, None, :]
    dilation = 0.3
    for c, camera in enumerate(frame.cameras):
        view = frame.viewmats[c]
        t = frame.means.astype(np.float64) @ view[:3, :3].T + view[:3, 3]
        tz = t[:, 2]
        drawn = (tz > frame.near_plane) & (tz < frame.far_plane)
        tz_safe = np.where(drawn, tz, 1.0)
        fx, fy, cx, cy = camera.fx, camera.fy, camera.cx, camera.cy
        u = fx * t[:, 0] / tz_safe + cx
        v = fy * t[:, 1] / tz_safe + cy
        limit_x = 1.3 * 0.5 * camera.width / fx
        limit_y = 1.3 * 0.5 * camera.height / fy
        tx = np.clip(t[:, 0] / tz_safe, -limit_x, limit_x) * tz_safe
        ty = np.clip(t[:, 1] / tz_safe, -limit_y, limit_y) * tz_safe
        j = np.zeros((n, 2, 3))
        j[:, 0, 0] = fx / tz_safe
        j[:, 0, 2] = -fx * tx / tz_safe ** 2
        j[:, 1, 1] = fy / tz_safe
        j[:, 1, 2] = -fy * ty / tz_safe ** 2
        m = j @ view[:3, :3] @ rs  # [N, 2, 3]: J W R S
        half = 3.0 * np.sqrt(np.stack([(m[:, 0] ** 2).sum(1) + dilation, (m[:, 1] ** 2).sum(1) + dilation], axis=1))
        extent = np.ceil(half)
        on_image = (u + extent[:, 0] > 0) & (u - extent[:, 0] < camera.width) & \
                   (v + extent[:, 1] > 0) & (v - extent[:, 1] < camera.height)
        drawn &= on_image & np.isfinite(extent).all(axis=1)
        means2d[c] = np.where(drawn[:, None], np.stack([u, v], axis=1), 0.0)
        radii[c] = np.where(drawn[:, None], np.minimum(extent, np.iinfo(np.int32).max), 0).astype(np.int32)
    return means2d, radii


def _render(frame, meta):
    """The forward: every camera's frame into (render_colors, render_alphas), its measures into meta."""
    cameras = len(frame.cameras)
    channels = (3 if frame.colour_out else 0) + (1 if frame.depth_out else 0)
    render_colors = np.zeros((cameras, frame.height, frame.width, channels), np.float32)
    render_alphas = np.zeros((cameras, frame.height, frame.width, 1), np.float32)
    for c, camera in enumerate(frame.cameras):
        frame.set_scene_for(c)
        image = frame.renderer.render(camera, **frame.settings(c))
        stats = frame.renderer.last_frame_stats
        meta["visible"].append(stats["visible"])
        meta["n_isects"].append(stats["intersections"])
        meta["gpu_ms"].append(stats["gpu_ms"])
        meta["sort_strategy"] = stats["sort_strategy"]
        alpha = image.rgba[..., 3]
        render_alphas[c, ..., 0] = alpha
        if frame.colour_out:
            render_colors[c, ..., :3] = image.rgba[..., :3]
        if frame.depth_out:
            expected = image.depth
            render_colors[c, ..., -1] = expected if frame.render_mode.endswith("ED") else expected * alpha
    return render_colors, render_alphas


def _backward(frame, grad_colors, grad_alphas):
    """dL/d(each input) from dL/d(render_colors) and dL/d(render_alphas) (numpy, or None for no gradient):
    the engine's backward per camera, its gradients of the trainer's parameters (log scales, logits, SH)
    turned into gsplat's (scales, opacities, colors). Returns a dict of arrays, with means2d and
    means2d_abs [C, N, 2] and the gradient of backgrounds [C, 3] (the pixels' colour gradients times the
    transmittance they saw the background through)."""
    cameras, n = len(frame.cameras), frame.means.shape[0]
    out = {name: np.zeros(shape, np.float32) for name, shape in (
        ("means", (n, 3)), ("quats", (n, 4)), ("log_scales", (n, 3)), ("logits", (n,)),
        ("sh", (cameras,) + frame.sh.shape[1:] if frame.per_camera else frame.sh.shape),
        ("means2d", (cameras, n, 2)), ("means2d_abs", (cameras, n, 2)), ("backgrounds", (cameras, 3)))}
    unformed = 0
    # The last camera first: its lists are the renderer's still (reuse_lists), so its forward is not redrawn.
    for c in reversed(range(cameras)):
        grads = {}
        if grad_colors is not None:
            g = grad_colors[c]
            if frame.colour_out:
                grads["grad_rgb"] = np.ascontiguousarray(g[..., :3], np.float32)
            if frame.depth_out:
                name = "grad_expected_depth" if frame.render_mode.endswith("ED") else "grad_accumulated_depth"
                grads[name] = np.ascontiguousarray(g[..., -1], np.float32)
        if grad_alphas is not None:
            grads["grad_alpha"] = np.ascontiguousarray(grad_alphas[c, ..., 0], np.float32)
        if not grads:
            continue
        frame.set_scene_for(c)
        g = frame.renderer.backward(frame.cameras[c], **grads, **dict(frame.settings(c), reuse_lists=True))
        unformed += g["unformed"]
        rows = frame.keep[c]
        out["means"][rows] += g["positions"]
        out["quats"][rows] += g["rotations"]
        out["log_scales"][rows] += g["log_scales"]
        out["logits"][rows] += g["opacity_logits"]
        if frame.per_camera:
            out["sh"][c][rows] += g["sh"]
        else:
            out["sh"][rows] += g["sh"]
        out["means2d"][c][rows] = g["means2d"]
        out["means2d_abs"][c][rows] = g["means2d_abs"]
        if "grad_rgb" in grads:
            transmittance = 1.0 - frame.alphas[c]
            out["backgrounds"][c] = (grads["grad_rgb"].astype(np.float64) * transmittance).reshape(-1, 3).sum(axis=0)
    # The trainer's parameters to gsplat's: scale = exp(log scale), opacity = sigmoid(logit), colour =
    # C0 * dc + 0.5 (without sh_degree).
    out["scales"] = out.pop("log_scales") / frame.scales
    clipped = np.clip(frame.opacities.astype(np.float64), 1e-12, 1 - 1e-7)
    out["opacities"] = (out.pop("logits") / (clipped * (1 - clipped))).astype(np.float32)
    sh = out.pop("sh")
    if frame.sh_degree is None:
        out["colors"] = sh[..., 0, :] / np.float32(_SH_C0)
    else:
        out["colors"] = np.zeros(frame.colors_shape, np.float32)
        out["colors"][:, :sh.shape[1], :] = sh
    out["unformed"] = unformed
    return out


_AUTOGRAD = None


def _autograd(torch):
    """The two autograd functions: _Project gives meta["means2d"] a place in the graph (its backward passes
    nothing on, since _Rasterize's already carries the whole gradient to the inputs), so that
    means2d.retain_grad() sees the screen gradient _Rasterize's backward hands it."""
    global _AUTOGRAD
    if _AUTOGRAD is None:
        class Project(torch.autograd.Function):
            @staticmethod
            def forward(ctx, means2d, *inputs):
                ctx.input_count = len(inputs)
                return means2d.clone()

            @staticmethod
            def backward(ctx, grad_means2d):
                return (None,) * (1 + ctx.input_count)

        class Rasterize(torch.autograd.Function):
            @staticmethod
            def forward(ctx, frame, render_colors, render_alphas, means2d, *inputs):
                ctx.frame = frame
                ctx.input_names = frame.gradient_inputs
                ctx.device = render_colors.device
                return render_colors.clone(), render_alphas.clone()

            @staticmethod
            def backward(ctx, grad_colors, grad_alphas):
                frame = ctx.frame
                to_numpy = (lambda g: None if g is None else g.detach().cpu().numpy())
                grads = _backward(frame, to_numpy(grad_colors), to_numpy(grad_alphas))
                means2d = frame.means2d_tensor
                if frame.absgrad and means2d is not None:
                    means2d.absgrad = torch.from_numpy(grads["means2d_abs"]).to(ctx.device)
                frame.meta["unformed"] = grads["unformed"]
                result = [None, None, None, torch.from_numpy(grads["means2d"]).to(ctx.device)]
                for name in ctx.input_names:
                    result.append(torch.from_numpy(np.ascontiguousarray(grads[name])).to(ctx.device)
                                  .to(getattr(frame, name + "_dtype")))
                return tuple(result)

        _AUTOGRAD = (Project, Rasterize)
    return _AUTOGRAD


def rasterization_backward(state, grad_colors=None, grad_alphas=None):
    """The gradients of rasterization() for numpy callers: `state` is meta["backward_state"] of a call made
    with keep_backward_state=True, grad_colors and grad_alphas dL/d(its render_colors, render_alphas) (None:
    the loss did not read them). Returns a dict of numpy arrays shaped as the inputs: means, quats, scales,
    opacities, colors, backgrounds, and means2d and means2d_abs [C, N, 2], with 'unformed' (drawn Gaussians
    whose gradient was not finite, set to zero)."""
    return _backward(state, None if grad_colors is None else np.asarray(grad_colors, np.float32),
                     None if grad_alphas is None else np.asarray(grad_alphas, np.float32))


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
                  segmented=False, covars=None, with_ut=False, with_eval3d=False, renderer=None, keep_backward_state=False, **others):
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

    Gradients (torch tensors that require them, autograd on): the results are in the autograd graph, and
    meta adds gsplat's "means2d" [C, N, 2] (its .grad, and .absgrad with absgrad=True, set by the backward),
    "radii" [C, N, 2] (int32, 0: not drawn) and "gaussian_ids" None, so that gsplat's DefaultStrategy and
    MCMCStrategy run on top; after the backward meta["unformed"] counts the drawn Gaussians whose gradient
    was not finite (set to zero). The backward covers packed=False (NotImplementedError otherwise, before any
    work), the pinhole camera and both rasterize modes. numpy callers: keep_backward_state=True puts
    meta["backward_state"] for rasterization_backward().

    Differences from gsplat: without sh_degree, colours below 0 are clamped to 0 (the engine's colour is
    max(C0 * dc + 0.5, 0)); channel_chunk and sparse_grad change nothing here. renderer: a
    tilesplat.Renderer to use (default: one on the default device, kept between calls).
    """
    if others:
        raise NotImplementedError("rasterization(): " + ", ".join(sorted(others)) + " not supported by tilesplat")
    _unsupported(radius_clip=(radius_clip, 0.0), eps2d=(eps2d, 0.3), tile_size=(tile_size, 16),
                 distributed=(distributed, False), camera_model=(camera_model, "pinhole"),
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
    originals = dict(means=means, quats=quats, scales=scales, opacities=opacities, colors=colors,
                     backgrounds=backgrounds)
    wants_gradients = [name for name, value in originals.items() if _is_tensor(value) and value.requires_grad]
    if wants_gradients:
        import torch

        if not torch.is_grad_enabled():
            wants_gradients = []
    if (wants_gradients or keep_backward_state) and packed:
        raise NotImplementedError("rasterization(): packed=True has no backward pass in tilesplat; pass "
                                  "packed=False to train (gradients were asked for: " +
                                  (", ".join(wants_gradients) or "keep_backward_state") + ")")
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
    cameras_list = [_camera(viewmats[c], Ks[c], width, height) for c in range(cameras)]
    # gsplat culls means at or beyond the far plane; the engine has none, so they leave the scene.
    keep = [means.astype(np.float64) @ viewmats[c, 2, :3] + viewmats[c, 2, 3] < far_plane for c in range(cameras)]
    frame = _Frame(renderer=renderer, cameras=cameras_list, means=means, quats=quats, scales=scales,
                   opacities=opacities, log_scales=log_scales, logits=logits, sh=sh, per_camera=per_camera,
                   keep=keep, backgrounds=backgrounds, width=width, height=height, render_mode=render_mode,
                   colour_out=colour_out, depth_out=depth_out, sh_degree=sh_degree, viewmats=viewmats,
                   near_plane=float(near_plane), far_plane=float(far_plane), absgrad=absgrad,
                   colors_shape=np.shape(colors) if not _is_tensor(colors) else tuple(colors.shape),
                   gradient_inputs=wants_gradients, means2d_tensor=None,
                   base_settings=dict(near_plane=float(near_plane), antialiasing=_RASTERIZE_MODES[rasterize_mode],
                                      max_alpha=_GSPLAT_MAX_ALPHA, depth=depth_out, splat_count=False,
                                      reuse_lists=False))
    meta = {"width": width, "height": height, "n_cameras": cameras, "tile_size": _TILE_SIZE,
            "tile_width": -(-width // _TILE_SIZE), "tile_height": -(-height // _TILE_SIZE),
            "near_plane": near_plane, "far_plane": far_plane, "visible": [], "n_isects": [], "gpu_ms": [],
            "sort_strategy": None}
    render_colors, render_alphas = _render(frame, meta)
    frame.alphas = render_alphas
    if keep_backward_state:
        meta["backward_state"] = frame
    if not tensors_in:
        return render_colors, render_alphas, meta

    import torch

    device = originals["means"].device
    colors_out = torch.from_numpy(render_colors).to(device)
    alphas_out = torch.from_numpy(render_alphas).to(device)
    if not wants_gradients:
        return colors_out, alphas_out, meta
    Project, Rasterize = _autograd(torch)
    for name in wants_gradients:
        setattr(frame, name + "_dtype", originals[name].dtype)
    inputs = [originals[name] for name in wants_gradients]
    means2d_values, radii = _projected_means_and_radii(frame)
    means2d = Project.apply(torch.from_numpy(means2d_values).to(device), *inputs)
    frame.means2d_tensor = means2d
    colors_out, alphas_out = Rasterize.apply(frame, colors_out, alphas_out, means2d, *inputs)
    meta.update(means2d=means2d, radii=torch.from_numpy(radii).to(device), gaussian_ids=None)
    frame.meta = meta
    return colors_out, alphas_out, meta
