#!/usr/bin/env bash
# Depth of field's sample count against error and time (docs/effects.md, "Depth of field"): one view of a
# scene through one lens with N lens samples, each frame's PSNR against the 1,024-sample frame of the same
# lens, its GPU time and the time per sample. Prints a Markdown table. (Each row is one process, so a
# frame of one sample pays what a process's first frame pays; tilesplat-bench times warm pinhole frames.)
#
#   bash tests/bench/lens_samples_curve.sh [SCENE] [APERTURE] [WIDTH] [HEIGHT]
#
# Needs build/ (tilesplat-render and tests/tilesplat_compare_exr). The focus is the scene's centre.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
scene=${1:-$root/scenes/playbot_lod3/playbot_lod3_31000_sh2.ply}
aperture=${2:-0.3}
width=${3:-480}
height=${4:-270}
out=$(mktemp -d /tmp/tilesplat_lens_curve.XXXXXX)
trap 'rm -rf "$out"' EXIT

# Renders with the given lens flags into $out/NAME.exr; prints the GPU frame time in ms.
render() {
  local name="$1"
  shift
  "$root/build/apps/tilesplat-render" "$scene" --width "$width" --height "$height" --azimuth 30 \
    --background 1,1,1 "$@" -o "$out/$name.exr" --stats 2>/dev/null | awk '/^gpu frame/ {print $3}'
}
psnr() {
  "$root/build/tests/tilesplat_compare_exr" "$out/$1.exr" "$out/$2.exr" | sed -E 's/.*PSNR ([^ ]+) dB.*/\1/'
}

render pinhole >/dev/null  # the pipelines built once, outside the timed frames
pinhole_ms=$(render pinhole)
render n1024 --aperture "$aperture" --lens-samples 1024 >/dev/null
echo "$(basename "$scene"), ${width}x${height}, aperture $aperture focused on the scene's centre, over white"
echo
echo "| lens samples | GPU ms | GPU ms per sample | PSNR against 1,024 samples |"
echo "|---:|---:|---:|---:|"
echo "| pinhole (one cold frame) | $pinhole_ms | | $(psnr pinhole n1024) |"
for n in 1 2 4 8 16 32 64 128 256; do
  ms=$(render "n$n" --aperture "$aperture" --lens-samples "$n")
  echo "| $n | $ms | $(awk -v a="$ms" -v n="$n" 'BEGIN {printf "%.1f", a / n}') | $(psnr "n$n" n1024) |"
done
