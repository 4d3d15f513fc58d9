"""gsplat's forward rasterization on the CPU, from gsplat's own pure-PyTorch functions, to hold
tilesplat.rasterization() to.

gsplat's `rendering._rasterization` (its PyTorch version of rasterization()) still calls three CUDA kernels
and nerfacc. This follows it step by step with the CPU functions gsplat ships in `gsplat.cuda._torch_impl`
for all but the last step:

  covariances       _quat_scale_to_covar_preci
  projection        _fully_fused_projection (eps2d, near and far planes, the antialiased compensation)
  colours           _spherical_harmonics, then max(colour + 0.5, 0) as _rasterization does
  tile lists        _isect_tiles and _isect_offset_encode (the per-tile lists sorted by depth)
  compositing       composite_tiles() below: gsplat's rasterize_to_pixels kernel
                    (gsplat/cuda/csrc/RasterizeToPixels3DGSFwd.cu) in PyTorch, because the PyTorch
                    version of it needs a CUDA kernel (rasterize_to_indices_in_range) and nerfacc's.

Everything runs in float32, as gsplat does on the GPU.
"""

import math

import torch
from gsplat.cuda._torch_impl import (_fully_fused_projection, _isect_offset_encode, _isect_tiles,
                                     _quat_scale_to_covar_preci, _spherical_harmonics)

# The constants of gsplat's rasterize_to_pixels kernel.
ALPHA_MAX = 0.999
ALPHA_MIN = 1.0 / 255.0
TRANSMITTANCE_MIN = 1e-4


def composite_tiles(means2d, conics, colors, opacities, width, height, tile_size, isect_offsets, flatten_ids,
                    backgrounds=None):
    """gsplat's rasterize_to_pixels forward for one batch of images [I]: each pixel (centre x + 0.5,
    y + 0.5) walks its tile's list front to back; sigma < 0 and alpha < 1/255 skip a splat, alpha is capped
    at 0.999, and a pixel stops before the splat that would take its transmittance to 1e-4 or below.

    means2d [I, N, 2], conics [I, N, 3], colors [I, N, D], opacities [I, N], isect_offsets [I, TH, TW],
    flatten_ids [M] (indices into I * N). Returns colours [I, H, W, D] and alphas [I, H, W, 1].

    All the tiles advance together, one list position per step (vectorised over every pixel), so the
    loop runs as many times as the longest list is long.
    """
    images, n = means2d.shape[:2]
    channels = colors.shape[-1]
    tiles_y, tiles_x = isect_offsets.shape[1:]
    starts = isect_offsets.reshape(-1).long()
    ends = torch.cat([starts[1:], torch.tensor([flatten_ids.numel()])])
    lengths = ends - starts

    # Every pixel of every image, with its tile's index.
    ys, xs = torch.meshgrid(torch.arange(height), torch.arange(width), indexing="ij")
    image = torch.arange(images)[:, None, None].expand(images, height, width).reshape(-1)
    px = xs.reshape(-1).repeat(images).float() + 0.5
    py = ys.reshape(-1).repeat(images).float() + 0.5
    tile = (image * tiles_y + (ys.reshape(-1).repeat(images) // tile_size)) * tiles_x + \
        xs.reshape(-1).repeat(images) // tile_size

    flat_means = means2d.reshape(-1, 2)
    flat_conics = conics.reshape(-1, 3)
    flat_colors = colors.reshape(-1, channels)
    flat_opacities = opacities.reshape(-1)
    transmittance = torch.ones(px.shape[0])
    accumulated = torch.zeros(px.shape[0], channels)
    done = torch.zeros(px.shape[0], dtype=torch.bool)
    for step in range(int(lengths.max()) if lengths.numel() else 0):
        active = (step < lengths[tile]) & ~done
        if not active.any():
            break
        pixels = active.nonzero().squeeze(1)
        splat = flatten_ids[starts[tile[pixels]] + step].long()
        dx = flat_means[splat, 0] - px[pixels]  # the kernel's delta = mean - pixel
        dy = flat_means[splat, 1] - py[pixels]
        conic = flat_conics[splat]
        sigma = 0.5 * (conic[:, 0] * dx * dx + conic[:, 2] * dy * dy) + conic[:, 1] * dx * dy
        alpha = torch.clamp_max(flat_opacities[splat] * torch.exp(-sigma), ALPHA_MAX)
        blended = (sigma >= 0) & (alpha >= ALPHA_MIN)
        next_t = transmittance[pixels] * (1 - alpha)
        stops = blended & (next_t <= TRANSMITTANCE_MIN)
        done[pixels[stops]] = True
        blended &= ~stops
        weight = torch.where(blended, alpha * transmittance[pixels], torch.zeros_like(alpha))
        accumulated[pixels] += weight[:, None] * flat_colors[splat]
        transmittance[pixels] = torch.where(blended, next_t, transmittance[pixels])

    render_alphas = (1 - transmittance).reshape(images, height, width, 1)
    render_colors = accumulated.reshape(images, height, width, channels)
    if backgrounds is not None:
        render_colors = render_colors + transmittance.reshape(images, height, width, 1) * \
            backgrounds[:, None, None, :]
    return render_colors, render_alphas


def rasterization(means, quats, scales, opacities, colors, viewmats, Ks, width, height, near_plane=0.01,
                  far_plane=1e10, eps2d=0.3, sh_degree=None, tile_size=16, backgrounds=None, render_mode="RGB",
                  rasterize_mode="classic"):
    """gsplat.rendering._rasterization's forward on the CPU, for one batch of C cameras (no batch dims):
    the arguments and returns of gsplat.rasterization() (render_colors, render_alphas), torch tensors."""
    to = dict(dtype=torch.float32)
    means, quats, scales = (torch.as_tensor(a, **to) for a in (means, quats, scales))
    opacities, colors = torch.as_tensor(opacities, **to), torch.as_tensor(colors, **to)
    viewmats, Ks = torch.as_tensor(viewmats, **to), torch.as_tensor(Ks, **to)
    cameras, n = viewmats.shape[0], means.shape[0]

    covars, _ = _quat_scale_to_covar_preci(quats, scales, True, False, triu=False)
    radii, means2d, depths, conics, compensations = _fully_fused_projection(
        means, covars, viewmats, Ks, width, height, eps2d=eps2d, near_plane=near_plane, far_plane=far_plane,
        calc_compensations=rasterize_mode == "antialiased")
    opacities = torch.broadcast_to(opacities[None, :], (cameras, n))
    if compensations is not None:
        opacities = opacities * compensations

    tiles_x, tiles_y = math.ceil(width / tile_size), math.ceil(height / tile_size)
    _, isect_ids, flatten_ids = _isect_tiles(means2d, radii, depths, tile_size, tiles_x, tiles_y)
    isect_offsets = _isect_offset_encode(isect_ids, cameras, tiles_x, tiles_y)

    if sh_degree is None:
        colors = torch.broadcast_to(colors[None], (cameras, n, 3)) if colors.dim() == 2 else colors
    else:
        camtoworlds = torch.inverse(viewmats)
        dirs = means[None, :, :] - camtoworlds[:, None, :3, 3]
        shs = torch.broadcast_to(colors[None], (cameras,) + tuple(colors.shape))
        colors = torch.clamp_min(_spherical_harmonics(sh_degree, dirs, shs) + 0.5, 0.0)

    if backgrounds is not None:
        backgrounds = torch.as_tensor(backgrounds, **to)
    if render_mode in ("RGB+D", "RGB+ED"):
        colors = torch.cat((colors, depths[..., None]), dim=-1)
        if backgrounds is not None:
            backgrounds = torch.cat([backgrounds, torch.zeros(cameras, 1)], dim=-1)
    elif render_mode in ("D", "ED"):
        colors = depths[..., None]
        if backgrounds is not None:
            backgrounds = torch.zeros(cameras, 1)

    render_colors, render_alphas = composite_tiles(means2d, conics, colors, opacities, width, height, tile_size,
                                                   isect_offsets, flatten_ids, backgrounds)
    if render_mode in ("ED", "RGB+ED"):
        render_colors = torch.cat([render_colors[..., :-1],
                                   render_colors[..., -1:] / render_alphas.clamp(min=1e-10)], dim=-1)
    return render_colors, render_alphas
