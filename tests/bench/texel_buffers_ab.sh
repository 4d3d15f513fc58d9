#!/usr/bin/env bash
# What the CPU-driver texel-buffer layouts buy, measured A/B in the same runs: the same binary with
# TILESPLAT_TEXEL_BUFFERS=0 (every pass through buffer device addresses, as before) and =1 (the default
# on CPU drivers), alternated ROUNDS times so that a shared machine's drifting speed affects both alike.
#   1. the frame: tilesplat-bench on SCENE at 1920x1080, view 0, the radix sort; GPU frame and per-pass medians;
#   2. the sort micro-benchmark at 2^22 random keys, 32 and 64 bits: radix against std::sort in the same run.
#
#   bash tests/bench/texel_buffers_ab.sh [BUILD] [SCENE] [CAMERAS] [ROUNDS]
#
# Defaults: build/, the 500k-Gaussian playbot of ../shared/scenes with its cameras, 3 rounds. Prints one
# Markdown table row per run.
set -euo pipefail
source "$(dirname "$0")/bench_paths.sh"
rounds="${4:-3}"
bench="$build/apps/tilesplat-bench"
require_files texel_buffers_ab "$bench" "$scene" "$cameras"
echo "texel_buffers_ab: $(basename "$scene"), $rounds rounds; $("$bench" --version)" >&2

# The median column of a metric row of the frame table.
metric() { awk -v name="$1" '$0 ~ "^  " name " " { print $(NF - 2); exit }'; }
# "median ms (ratio)" of a row of the sort table: bits, sorter.
sort_row() { awk -v bits="$1" -v who="$2" '$1 == bits && $3 == who { print $5 " (" $7 ")"; exit }'; }

echo "| round | texel buffers | projection | depth_sort | key_emission | tile_sort | composite | GPU frame | radix 32-bit (vs std::sort) | radix 64-bit (vs std::sort) |"
echo "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"
for ((round = 1; round <= rounds; round++)); do
  for texel in 0 1; do
    frame=$(TILESPLAT_TEXEL_BUFFERS=$texel "$bench" "$scene" --cameras "$cameras" --view 0 --width 1920 \
      --height 1080 --sort radix --warmup 1 --repeat 5 2> /dev/null)
    sorts=$(TILESPLAT_TEXEL_BUFFERS=$texel "$bench" --sort-bench --sort radix --sort-sizes 22 --key-bits 32,64 \
      --warmup 1 --repeat 3 2> /dev/null)
    row="| $round | $([ "$texel" = 1 ] && echo yes || echo no) |"
    for pass in projection depth_sort key_emission tile_sort composite "gpu frame"; do
      row="$row $(echo "$frame" | metric "$pass") |"
    done
    row="$row $(echo "$sorts" | sort_row 32 radix) ms |"
    row="$row $(echo "$sorts" | sort_row 64 radix) ms |"
    echo "$row"
  done
done
