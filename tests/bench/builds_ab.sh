#!/usr/bin/env bash
# Two builds of tilesplat-bench measured A/B in the same run, alternated ROUNDS times so that a shared
# machine's drifting speed affects both alike (the before/after tables of docs/benchmarks.md):
#   1. the frame: SCENE at 1920x1080, view 0, the radix sort; GPU frame and per-pass medians over 5 frames;
#   2. the sort micro-benchmark at 2^22 random keys, 32 and 64 bits: radix against std::sort in the same run.
#
#   bash tests/bench/builds_ab.sh BEFORE_BENCH AFTER_BENCH [SCENE] [CAMERAS] [ROUNDS]
#
# BEFORE_BENCH and AFTER_BENCH are tilesplat-bench executables (e.g. one built from an older commit and
# copied aside). Defaults: the 500k-Gaussian playbot of ../shared/scenes with its cameras, 3 rounds.
# Prints one Markdown table row per run.
set -euo pipefail
before="$(realpath "${1:?usage: builds_ab.sh BEFORE_BENCH AFTER_BENCH [SCENE] [CAMERAS] [ROUNDS]}")"
after="$(realpath "${2:?usage: builds_ab.sh BEFORE_BENCH AFTER_BENCH [SCENE] [CAMERAS] [ROUNDS]}")"
source "$(dirname "$0")/bench_paths.sh" "" "${3:-}" "${4:-}"
rounds="${5:-3}"
require_files builds_ab "$before" "$after" "$scene" "$cameras"
echo "builds_ab: $(basename "$scene"), $rounds rounds; before $("$before" --version), after $("$after" --version)" >&2

# The median column of a metric row of the frame table.
metric() { awk -v name="$1" '$0 ~ "^  " name " " { print $(NF - 2); exit }'; }
# "median ms (ratio)" of a row of the sort table: bits, sorter.
sort_row() { awk -v bits="$1" -v who="$2" '$1 == bits && $3 == who { print $5 " (" $7 ")"; exit }'; }

echo "| round | build | projection | depth_sort | key_emission | tile_sort | composite | GPU frame | radix 32-bit (vs std::sort) | radix 64-bit (vs std::sort) |"
echo "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"
for ((round = 1; round <= rounds; round++)); do
  for build in before after; do
    bench="${!build}"
    frame=$("$bench" "$scene" --cameras "$cameras" --view 0 --width 1920 --height 1080 --sort radix --warmup 1 \
      --repeat 5 2> /dev/null)
    sorts=$("$bench" --sort-bench --sort radix --sort-sizes 22 --key-bits 32,64 --warmup 1 --repeat 3 2> /dev/null)
    row="| $round | $build |"
    for pass in projection depth_sort key_emission tile_sort composite "gpu frame"; do
      row="$row $(echo "$frame" | metric "$pass") |"
    done
    row="$row $(echo "$sorts" | sort_row 32 radix) ms |"
    row="$row $(echo "$sorts" | sort_row 64 radix) ms |"
    echo "$row"
  done
done
