#!/usr/bin/env bash
# Behaviour unchanged, pixel for pixel: the frame-hash table (tests/tools/frame_hashes) of an older
# commit against this checkout's. The older commit is installed into a scratch prefix and the tool is
# built against it through find_package, so the tool's own source is the same on both sides.
#
#   bash tests/bench/frame_hashes_ab.sh BASE_COMMIT [BUILD_DIR] [SCENE] [CAMERAS] [WIDTH HEIGHT]
#
# BUILD_DIR is this checkout's build (default build), which must have built tilesplat_frame_hashes.
# Defaults: the 31,000-Gaussian playbot (SH degree 2) of ../shared/scenes at 480x270. Prints both
# tables side by side and exits 1 when any hash differs.
set -euo pipefail
cd "$(dirname "$0")/../.."
base="${1:?usage: frame_hashes_ab.sh BASE_COMMIT [BUILD_DIR] [SCENE] [CAMERAS] [WIDTH HEIGHT]}"
build="${2:-build}"
shared="${TILESPLAT_SHARED_SCENES:-../shared/scenes}"
scene="${3:-$shared/playbot_lod3_31000_sh2.ply}"
cameras="${4:-$shared/cameras/playbot_lod3_31000_sh2.json}"
width="${5:-480}"
height="${6:-270}"
after_tool="$build/tests/tools/frame_hashes/tilesplat_frame_hashes"
for f in "$after_tool" "$scene" "$cameras"; do
  [[ -e "$f" ]] || { echo "frame_hashes_ab: $f: not found" >&2; exit 1; }
done

work="${TILESPLAT_AB_DIR:-/tmp/tilesplat_frame_hashes_ab}/$(git rev-parse --short "$base")"
if [[ ! -d "$work/prefix" ]]; then
  rm -rf "$work"
  mkdir -p "$work"
  git worktree add --detach "$work/src" "$base" >&2
  trap 'git worktree remove --force "$work/src" >/dev/null 2>&1 || true' EXIT
  cmake -S "$work/src" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DTILESPLAT_BUILD_TESTS=OFF \
    -DTILESPLAT_BUILD_APPS=OFF -DTILESPLAT_BUILD_VIEWER=OFF -DCMAKE_INSTALL_PREFIX="$work/prefix" >&2
  cmake --build "$work/build" >&2
  cmake --install "$work/build" >&2
fi
# The tool from this checkout's source, against the older library (rebuilt when the source changed).
cmake -S tests/tools/frame_hashes -B "$work/tool" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" >/dev/null
cmake --build "$work/tool" >&2

echo "frame_hashes_ab: $(basename "$scene") at ${width}x$height; before $base, after $(git rev-parse --short HEAD)$(
  git diff --quiet HEAD || echo ' (with uncommitted changes)')" >&2
"$work/tool/tilesplat_frame_hashes" "$scene" "$cameras" "$width" "$height" >"$work/before.txt"
"$after_tool" "$scene" "$cameras" "$width" "$height" >"$work/after.txt"
rows=$(wc -l <"$work/before.txt")
echo "| settings | strategy | before | after |"
echo "| --- | --- | --- | --- |"
paste -d' ' "$work/before.txt" "$work/after.txt" | awk '{
  n = NF / 2; name = $1; for (i = 2; i < n - 1; ++i) name = name " " $i;
  printf "| %s | %s | %s | %s%s |\n", name, $(n - 1), $n, $(2 * n), ($n == $(2 * n) ? "" : " DIFFERS") }'
if cmp -s "$work/before.txt" "$work/after.txt"; then
  echo "frame_hashes_ab: all $rows frames equal" >&2
else
  echo "frame_hashes_ab: $(diff "$work/before.txt" "$work/after.txt" | grep -c '^>') of $rows frames differ" >&2
  exit 1
fi
