"""Paths and helpers the package's tests share: the repository's bundled scenes, ../shared beside it,
and tilesplat-render for the comparisons with the C++ app (TILESPLAT_RENDER_EXE)."""

import os
import pathlib

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
SHARED = pathlib.Path(os.environ.get("TILESPLAT_SHARED_SCENES", REPO.parent / "shared" / "scenes"))
BUNDLED_PLAYBOT = REPO / "scenes" / "playbot_lod3" / "playbot_lod3_31000_sh2.ply"
BUNDLED_SH3 = REPO / "scenes" / "playcanvas_test" / "playcanvas_test_64_sh3.ply"


def require(condition, reason):
    """Skips the test when `condition` is false; with TILESPLAT_NO_SKIPS=1 (as CI runs) a skip is a
    failure, so that a missing input cannot pass unnoticed."""
    if condition:
        return
    if os.environ.get("TILESPLAT_NO_SKIPS") == "1":
        pytest.fail(reason + " (TILESPLAT_NO_SKIPS=1: nothing may be skipped)")
    pytest.skip(reason)


@pytest.fixture
def render_exe():
    exe = os.environ.get("TILESPLAT_RENDER_EXE", str(REPO / "build" / "apps" / "tilesplat-render"))
    require(os.path.exists(exe), "tilesplat-render not built (set TILESPLAT_RENDER_EXE)")
    return exe


@pytest.fixture
def shared_scenes():
    require(SHARED.is_dir(), f"{SHARED} not found (the shared scenes beside the repository)")
    return SHARED


def pytest_configure(config):
    config.addinivalue_line("markers", "gsplat: needs torch and gsplat; python/run_tests.sh runs these in a "
                                       "virtual environment that has them (pytest -m gsplat)")
