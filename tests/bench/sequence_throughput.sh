#!/usr/bin/env bash
# What rendering many frames in one process buys, and whether a long run's memory stays flat:
#   1. the views of a camera set in one tilesplat-render process (--views all) against one process per
#      view (--view N), frames per second of each, wall clock including loading and device creation;
#   2. the resident memory of an orbit after 5 and after 100 frames (the manifest records it per frame).
#
#   bash tests/bench/sequence_throughput.sh [BUILD] [SCENE] [CAMERAS] [WIDTHxHEIGHT] [ORBIT_SIZE]
#
# Defaults: build/, the 500k-Gaussian playbot of ../shared/scenes with its cameras, 1920x1080 views,
# 480x270 orbit frames. Prints a Markdown table; the outputs go to a temporary folder, removed after.
set -euo pipefail
source "$(dirname "$0")/bench_paths.sh"
size="${4:-1920x1080}"
orbit_size="${5:-480x270}"
render="$build/apps/tilesplat-render"
require_files sequence_throughput "$render" "$scene" "$cameras"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
seconds() { awk -v a="$1" -v b="$2" 'BEGIN { print b - a }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", a / b }'; }
width="${size%x*}" height="${size#*x}"

views=$(grep -o '"img_name"' "$cameras" | wc -l)
echo "sequence_throughput: $(basename "$scene"), $views views at $size; $("$render" --version)" >&2

mkdir -p "$work/one" "$work/separate" "$work/orbit"
start=$(now)
"$render" "$scene" --cameras "$cameras" --views all --width "$width" --height "$height" \
  -o "$work/one/view_%02d.exr" --quiet
one=$(seconds "$start" "$(now)")

start=$(now)
for ((view = 0; view < views; view++)); do
  "$render" "$scene" --cameras "$cameras" --view "$view" --width "$width" --height "$height" \
    -o "$work/separate/view_$view.exr" 2>/dev/null
done
separate=$(seconds "$start" "$(now)")

"$render" "$scene" --orbit 100 --width "${orbit_size%x*}" --height "${orbit_size#*x}" \
  -o "$work/orbit/frame_%03d.exr" --quiet
# The manifest's lines are in completion order, which is frame order in one process.
resident() { sed -n "$1p" "$work/orbit/manifest.jsonl" | grep -o '"resident_mib":[0-9.]*' | cut -d: -f2; }
after5=$(resident 5)
after100=$(resident 100)

printf '| run | frames | wall s | frames/s |\n|---|---:|---:|---:|\n'
printf '| one process (--views all) | %d | %.2f | %s |\n' "$views" "$one" "$(ratio "$views" "$one")"
printf '| one process per view (--view N) | %d | %.2f | %s |\n' "$views" "$separate" "$(ratio "$views" "$separate")"
printf '\n| orbit at %s | resident MiB |\n|---|---:|\n' "$orbit_size"
printf '| after 5 frames | %.1f |\n| after 100 frames | %.1f |\n' "$after5" "$after100"
