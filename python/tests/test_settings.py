"""tilesplat.RenderSettings: the C++ RenderSettings bound once, its fields by render()'s keywords, taken by
Renderer.render and render_reference with keyword overrides."""

import numpy as np
import pytest

import tilesplat
from conftest import BUNDLED_PLAYBOT, BUNDLED_SH3


def test_the_defaults_are_the_engines():
    settings = tilesplat.RenderSettings()
    # The C++ defaults (tilesplat/render_settings.h), read through the binding, not restated by it.
    assert settings.sort == "auto"
    assert settings.depth and settings.splat_count and settings.reuse_lists
    assert settings.accuracy == "reference"
    assert settings.antialiasing == "classic" and settings.compositor == "sorted"
    assert settings.stochastic_frames == 16 and settings.seed == 1 and settings.stochastic_sampler == "hash"
    assert not settings.stochastic_accumulate and not settings.accumulate_samples
    assert settings.background == [0.0, 0.0, 0.0]
    assert settings.near_plane == pytest.approx(0.2) and settings.max_alpha == pytest.approx(0.99)
    assert settings.lens is None and settings.shutter is None and settings.region is None
    assert settings.memory_budget == 0 and settings.splat_budget == 0
    assert repr(settings) == "RenderSettings()"
    assert settings == tilesplat.RenderSettings()


def test_fields_are_set_by_name_and_checked_when_set():
    settings = tilesplat.RenderSettings(accuracy="depth16+sh1", compositor="stochastic", seed=7,
                                        region=(1, 2, 30, 40), lens=tilesplat.ThinLens(0.1, 2.0, 8))
    assert settings.accuracy == "depth16+sh1"
    assert settings.region == (1, 2, 30, 40)
    assert settings.lens.samples == 8
    assert repr(settings).startswith("RenderSettings(accuracy='depth16+sh1', compositor='stochastic', seed=7")
    changed = settings.replace(seed=8, region=None)
    assert changed.seed == 8 and changed.region is None
    assert settings.seed == 7, "replace() changes a copy"
    assert changed != settings
    assert set(tilesplat.RenderSettings.fields) >= {"sort", "accuracy", "lens", "shutter", "region", "memory_budget"}
    # The engine's own parsers check each field as it is set, with the messages render() gives.
    with pytest.raises(ValueError, match="radiall"):
        settings.accuracy = "radiall"
    with pytest.raises(ValueError, match="antialiasing must be one of classic, antialiased, mip, got 'gauss'"):
        tilesplat.RenderSettings(antialiasing="gauss")
    with pytest.raises(TypeError, match=r"RenderSettings.depth must be a bool, got str"):
        settings.depth = "yes"
    with pytest.raises(TypeError, match=r"RenderSettings.seed must be a non-negative int"):
        settings.seed = -1
    with pytest.raises(TypeError, match="RenderSettings\\(\\) got an unexpected keyword argument 'colour'"):
        tilesplat.RenderSettings(colour="red")
    assert settings.accuracy == "depth16+sh1", "a refused value leaves the field as it was"


def test_render_takes_settings_and_keyword_overrides():
    scene = tilesplat.load_scene(BUNDLED_PLAYBOT)
    renderer = tilesplat.Renderer(validation=True)
    renderer.set_scene(scene)
    camera = tilesplat.Camera.orbit(scene, 96, 54, azimuth_deg=40)
    settings = tilesplat.RenderSettings(antialiasing="mip", background=[0.2, 0.3, 0.4], splat_count=False)
    by_keywords = renderer.render(camera, antialiasing="mip", background=[0.2, 0.3, 0.4], splat_count=False)
    by_settings = renderer.render(camera, settings)
    assert np.array_equal(by_settings.rgba, by_keywords.rgba)
    assert by_settings.splat_count is None
    # A keyword overrides the settings' field; the settings object is left as it was.
    overridden = renderer.render(camera, settings, antialiasing="classic")
    assert np.array_equal(overridden.rgba, renderer.render(camera, background=[0.2, 0.3, 0.4]).rgba)
    assert settings.antialiasing == "mip"
    region = renderer.render(camera, settings, region=(10, 20, 30, 12))
    assert np.array_equal(region.rgba, by_settings.rgba[20:32, 10:40])
    with pytest.raises(TypeError, match="render\\(\\) got an unexpected keyword argument 'antialias'"):
        renderer.render(camera, antialias="mip")
    with pytest.raises(TypeError, match="incompatible function arguments"):
        renderer.render(camera, {"antialiasing": "mip"})


def test_render_reference_takes_the_same_settings():
    scene = tilesplat.load_scene(BUNDLED_SH3)
    camera = tilesplat.Camera.orbit(scene, 48, 32, azimuth_deg=10)
    settings = tilesplat.RenderSettings(accuracy="resort8", background=[1, 1, 1])
    reference = tilesplat.render_reference(camera, scene=scene, settings=settings)
    by_keywords = tilesplat.render_reference(camera, scene=scene, accuracy="resort8", background=[1, 1, 1])
    assert np.array_equal(reference.rgba, by_keywords.rgba)
    renderer = tilesplat.Renderer()
    gpu = renderer.render(camera, settings, scene=scene)
    assert tilesplat.compare_images(gpu, reference)["psnr_db"] > 50
