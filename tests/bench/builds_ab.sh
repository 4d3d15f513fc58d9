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

source tests/bench/ab_rows.sh  # bench_paths.sh made the repository root the working directory
ab_header build
for ((round = 1; round <= rounds; round++)); do
  ab_row "$round" before "$before"
  ab_row "$round" after "$after"
done
