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

source tests/bench/ab_rows.sh  # bench_paths.sh made the repository root the working directory
ab_header "texel buffers"
for ((round = 1; round <= rounds; round++)); do
  ab_row "$round" no env TILESPLAT_TEXEL_BUFFERS=0 "$bench"
  ab_row "$round" yes env TILESPLAT_TEXEL_BUFFERS=1 "$bench"
done
