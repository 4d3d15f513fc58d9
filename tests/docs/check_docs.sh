#!/usr/bin/env bash
# The API reference is complete and stays so: Doxygen over the public headers (docs/Doxyfile.in)
# gives no warning, and the same run over a copy of the headers with one public function left
# undocumented fails, naming it.
# usage: tests/docs/check_docs.sh BUILD_DIR/docs/Doxyfile
set -euo pipefail
doxyfile=${1:?usage: check_docs.sh DOXYFILE}
root=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

if ! (cat "$doxyfile"; echo "OUTPUT_DIRECTORY = $work/complete") | doxygen - >"$work/complete.log" 2>&1; then
  cat "$work/complete.log"
  echo "the API reference has warnings (above)"
  exit 1
fi
if grep -q -E "warning|error" "$work/complete.log"; then
  cat "$work/complete.log"
  exit 1
fi
echo "API reference: $(ls "$work"/complete/html/*.html | wc -l) pages, no warnings"

cp -r "$root/engine/include/tilesplat" "$work/headers"
sed -i 's|^}  // namespace tilesplat$|TILESPLAT_API int an_undocumented_function(int value);\n}  // namespace tilesplat|' \
  "$work/headers/scene.h"
grep -q an_undocumented_function "$work/headers/scene.h"
version_h=$(grep -o '[^ ]*/tilesplat/version.h' "$doxyfile")
if (cat "$doxyfile"; echo "INPUT = $work/headers $version_h"; echo "OUTPUT_DIRECTORY = $work/broken"
    echo "USE_MDFILE_AS_MAINPAGE =") | doxygen - >"$work/broken.log" 2>&1; then
  echo "Doxygen accepted a public function without documentation"
  exit 1
fi
grep "an_undocumented_function" "$work/broken.log"
echo "an undocumented public function fails the docs build, as it must"
