"""tilesplat: 3D Gaussian Splatting on Vulkan compute, from Python.

Scenes, cameras and the renderer of the C++ engine, with numpy arrays in and out::

    import tilesplat
    scene = tilesplat.load_scene("scene.ply")
    renderer = tilesplat.Renderer()          # the first discrete GPU, else the first device (lavapipe)
    renderer.set_scene(scene)
    camera = tilesplat.Camera.orbit(scene, 960, 540, azimuth_deg=30)
    image = renderer.render(camera)
    settings = tilesplat.RenderSettings(antialiasing="mip", background=[1, 1, 1])
    image = renderer.render(camera, settings, accuracy="depth16")  # keywords override the settings
    image.rgba                               # (540, 960, 4) float32, premultiplied display values (sRGB)
    image.preview()                          # (540, 960, 3) uint8 to show, as the PNG holds it
    image.write_exr("frame.exr")

Errors carry the engine's messages: tilesplat.SceneError (a ValueError) for a bad scene file, ValueError
for a bad argument, FileNotFoundError for a missing file.
"""

from ._core import (
    Camera,
    CameraView,
    Image,
    LodSelection,
    LodSet,
    MappedPly,
    NotDifferentiable,
    Renderer,
    RenderSettings,
    Scene,
    SceneError,
    SceneInParts,
    SceneInstances,
    Shutter,
    ThinLens,
    __version__,
    aperture_for_f_stop,
    camera_between,
    camera_path,
    compare_images,
    devices,
    effect_sample_point,
    lens_sample,
    lens_sample_camera,
    lens_samples,
    load_cameras,
    load_scene,
    orbit_cameras,
    read_exr,
    reference_backward,
    render_reference,
    shutter_time,
    shutter_times,
    sort_strategies,
)
from .gsplat_compat import rasterization, rasterization_backward

__all__ = [
    "Camera",
    "CameraView",
    "Image",
    "LodSelection",
    "LodSet",
    "MappedPly",
    "NotDifferentiable",
    "Renderer",
    "RenderSettings",
    "Scene",
    "SceneError",
    "SceneInParts",
    "SceneInstances",
    "Shutter",
    "ThinLens",
    "__version__",
    "aperture_for_f_stop",
    "camera_between",
    "camera_path",
    "compare_images",
    "devices",
    "effect_sample_point",
    "lens_sample",
    "lens_sample_camera",
    "lens_samples",
    "load_cameras",
    "load_scene",
    "orbit_cameras",
    "rasterization",
    "rasterization_backward",
    "read_exr",
    "reference_backward",
    "render_reference",
    "shutter_time",
    "shutter_times",
    "sort_strategies",
]
