#!/usr/bin/env bash
# Writes this folder's .rad files with Spark's own encoder: build-lod from github.com/sparkjsdev/spark
# (rust/build-lod, built with `cargo build --release -p build-lod --no-default-features`; the default GPU
# feature only speeds up SH clustering). CI does not run it; the files are committed.
#
#   bash make_rad.sh PATH/TO/build-lod [SHARED_SCENES]
set -euo pipefail
build_lod="$1"
scenes="${2:-$(cd "$(dirname "$0")/../../../.." && pwd)/shared/scenes}"
out="$(cd "$(dirname "$0")" && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# build-lod names its output after its input (NAME-lod.rad, NAME-lod-0.radc): one copy of the source per file.
make() {  # make NAME [FLAGS...]
  local name="$1"
  shift
  cp "$scenes/playcanvas_test_64_sh3.ply" "$work/$name.ply"
  (cd "$work" && "$build_lod" "$@" "$name.ply" >"$name.log" 2>&1) || { cat "$work/$name.log"; exit 1; }
}
make playcanvas_test_64_sh3                                # the default: quality (Bhattacharyya) LOD tree
make playcanvas_test_64_sh3_quick --quick                  # tiny-lod
make playcanvas_test_64_sh3_sh1 --max-sh=1                 # SH clamped to degree 1
make playcanvas_test_64_sh3_clustered --cluster-sh-cpu     # SH as a codebook and a label per splat
make playcanvas_test_64_sh3_chunked --rad-chunked          # the chunk in a .radc file beside the .rad
cp "$work"/*-lod.rad "$work"/*.radc "$out/"
ls -l "$out"/*.rad "$out"/*.radc
