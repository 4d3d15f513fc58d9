#!/usr/bin/env bash
# The Python bindings under AddressSanitizer + UndefinedBehaviorSanitizer: the module (python/src) built
# in the sanitizer build against its shared library, and the package's pytest suite run on it (the tests
# not marked gsplat: those need torch, whose own libraries are not built for a sanitizer).
#
#   bash tests/ci/sanitize_python.sh BUILD_DIR     (a configured sanitizer build, as .ci/run makes it)
#
# The interpreter is not instrumented, so the sanitizer's runtime is preloaded into it (LD_PRELOAD: ASan
# must come first among the libraries). Leaks are not checked here: the interpreter keeps its objects, and
# the module's caches with them, until the process ends by design, and a suppression of the interpreter's
# frames would hide every stack, the engine's included. The engine's own leaks are checked by the C++
# suites of the sanitizer step, with the same library. Every ASan or UBSan report still fails the run
# (-fno-sanitize-recover=all, halt_on_error).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: sanitize_python.sh BUILD_DIR}" && pwd)
grep -q '^TILESPLAT_SANITIZE:STRING=.*address' "$build/CMakeCache.txt" ||
  { echo "sanitize-python: $build is not a build with TILESPLAT_SANITIZE=address" >&2; exit 1; }

venv="$build/python-venv"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
"$venv/bin/python" -m pip install --quiet --upgrade pip
"$venv/bin/python" -m pip install --quiet "nanobind>=2.0" numpy pytest

echo "sanitize-python: building tilesplat._core in $build"
cmake -S "$root" -B "$build" -DTILESPLAT_BUILD_PYTHON=ON -DPython_EXECUTABLE="$venv/bin/python" >/dev/null
cmake --build "$build" --target tilesplat_python -j2

# The package as the wheel lays it out: python/tilesplat/*.py beside the module built above.
package="$build/python-package/tilesplat"
rm -rf "$(dirname "$package")"
mkdir -p "$package"
cp "$root"/python/tilesplat/*.py "$package/"
module=$(find "$build/python" -maxdepth 1 -name '_core*.so' | head -n 1)
[ -n "$module" ] || { echo "sanitize-python: no _core module in $build/python" >&2; exit 1; }
ln -s "$module" "$package/$(basename "$module")"

# The C++ runtime is preloaded after it: the interpreter does not link libstdc++, and ASan finds the real
# __cxa_throw (which it intercepts) only in a library loaded when it starts; without it the first C++
# exception the module throws stops the process ("CHECK failed: ... real___cxa_throw").
asan_runtime=$(g++ -print-file-name=libasan.so)
cxx_runtime=$(g++ -print-file-name=libstdc++.so)
for runtime in "$asan_runtime" "$cxx_runtime"; do
  [ -f "$runtime" ] || { echo "sanitize-python: g++ names no $(basename "$runtime") ($runtime)" >&2; exit 1; }
done
cd "$build"  # away from the source tree: `import tilesplat` must find the package above
# --capture=sys: pytest captures what Python prints, not file descriptor 2, so that a sanitizer's report
# (written there by a process that then stops) stays in the log.
PYTHONPATH="$(dirname "$package")" \
  LD_PRELOAD="$asan_runtime $cxx_runtime" ASAN_OPTIONS=detect_leaks=0:halt_on_error=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  TILESPLAT_RENDER_EXE="$build/apps/tilesplat-render" \
  "$venv/bin/python" -c "import tilesplat; print('sanitize-python: tilesplat', tilesplat.__version__, 'from', tilesplat.__file__)"
PYTHONPATH="$(dirname "$package")" \
  LD_PRELOAD="$asan_runtime $cxx_runtime" ASAN_OPTIONS=detect_leaks=0:halt_on_error=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  TILESPLAT_RENDER_EXE="$build/apps/tilesplat-render" \
  "$venv/bin/python" -m pytest -p no:cacheprovider -ra --capture=sys -m "not gsplat" "$root/python/tests"
