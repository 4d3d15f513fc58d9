#!/usr/bin/env bash
# The Python package as a user gets it: a wheel built from this checkout (`pip wheel .`, its build
# dependencies from PyPI), installed into a fresh virtual environment, and the package's pytest suite
# run there against the installed module (not the source tree). Then the tests marked `gsplat`, which
# hold tilesplat.rasterization() to gsplat's own PyTorch functions, in a second environment: Debian's
# python3 with its python3-torch (a CPU build; cmake/setup-deps.sh installs it) and gsplat from PyPI
# (installed without its dependencies: PyPI's torch would bring CUDA).
#
#   bash python/run_tests.sh [BUILD_DIR]
#
# BUILD_DIR (default build) holds tilesplat-render, which the tests compare the module with to the bit.
# With TILESPLAT_NO_SKIPS=1 (as .ci/run sets it) a test that would skip fails instead.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
work="$root/build-python-test"
rm -rf "$work/venv" "$work/wheels"
mkdir -p "$work"
python3 -m venv "$work/venv"
"$work/venv/bin/python" -m pip install --quiet --upgrade pip
echo "python: building the wheel (pip wheel $root)"
"$work/venv/bin/python" -m pip wheel --wheel-dir "$work/wheels" "$root"
wheel=$(ls "$work"/wheels/tilesplat-*.whl)
echo "python: installing $(basename "$wheel") into a fresh virtual environment"
"$work/venv/bin/python" -m pip install --quiet "$wheel" pytest
cd "$work"  # away from the source tree: `import tilesplat` must find the installed package
"$work/venv/bin/python" -c "import tilesplat; print('python: tilesplat', tilesplat.__version__, 'from', tilesplat.__file__)"
TILESPLAT_RENDER_EXE="$build/apps/tilesplat-render" \
  "$work/venv/bin/python" -m pytest -p no:cacheprovider -ra -m "not gsplat" "$root/python/tests"

gsplat_version=1.5.3
echo "python: gsplat $gsplat_version's PyTorch functions against tilesplat.rasterization() (Debian's python3-torch)"
rm -rf "$work/venv-gsplat"
/usr/bin/python3 -m venv --system-site-packages "$work/venv-gsplat"
"$work/venv-gsplat/bin/python" -m pip install --quiet --upgrade pip
if ! "$work/venv-gsplat/bin/python" -m pip install --quiet --no-deps "$wheel" 2>/dev/null; then
  # /usr/bin/python3 is another Python than python3 on the PATH: a wheel of its own.
  "$work/venv-gsplat/bin/python" -m pip wheel --quiet --no-deps --wheel-dir "$work/wheels-gsplat" "$root"
  "$work/venv-gsplat/bin/python" -m pip install --quiet --no-deps "$work"/wheels-gsplat/tilesplat-*.whl
fi
"$work/venv-gsplat/bin/python" -m pip install --quiet --no-deps "gsplat==$gsplat_version"
"$work/venv-gsplat/bin/python" -m pip install --quiet pytest
TILESPLAT_RENDER_EXE="$build/apps/tilesplat-render" \
  "$work/venv-gsplat/bin/python" -m pytest -p no:cacheprovider -ra -s -m gsplat "$root/python/tests"  # -s: the measures
echo "python: the example (examples/python/render_orbit.py)"
"$work/venv/bin/python" "$root/examples/python/render_orbit.py" "$root/scenes/playbot_lod3/playbot_lod3_31000_sh2.ply" \
  "$work/orbit" --frames 8 --width 320 --height 180
[[ $(ls "$work"/orbit/frame_*.png | wc -l) -eq 8 ]]
