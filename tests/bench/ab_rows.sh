# Sourced by the A/B scripts of tests/bench (texel_buffers_ab.sh, builds_ab.sh): one Markdown table of a
# frame's per-pass medians and the radix sort's ratio to std::sort, a row per measured run. Needs $scene and
# $cameras (bench_paths.sh).

# The table's header; $1 names the column that tells the runs apart.
ab_header() {
  echo "| round | $1 | projection | depth_sort | key_emission | tile_sort | composite | GPU frame | radix 32-bit (vs std::sort) | radix 64-bit (vs std::sort) |"
  echo "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"
}

# The median column of a metric row of the frame table.
ab_metric() { awk -v name="$1" '$0 ~ "^  " name " " { print $(NF - 2); exit }'; }
# "median ms (ratio)" of a row of the sort table: bits, sorter.
ab_sort_row() { awk -v bits="$1" -v who="$2" '$1 == bits && $3 == who { print $5 " (" $7 ")"; exit }'; }

# ab_row ROUND LABEL BENCH...: runs BENCH (a tilesplat-bench command, e.g. `env VAR=1 path/tilesplat-bench`)
#   1. on the scene at 1920x1080, view 0, the radix sort: GPU frame and per-pass medians over 5 frames;
#   2. as the sort micro-benchmark at 2^22 random keys, 32 and 64 bits: radix against std::sort in the same run;
# and prints the row.
ab_row() {
  local round="$1" label="$2"
  shift 2
  local frame sorts row
  frame=$("$@" "$scene" --cameras "$cameras" --view 0 --width 1920 --height 1080 --sort radix --warmup 1 --repeat 5 \
    2> /dev/null)
  sorts=$("$@" --sort-bench --sort radix --sort-sizes 22 --key-bits 32,64 --warmup 1 --repeat 3 2> /dev/null)
  row="| $round | $label |"
  for pass in projection depth_sort key_emission tile_sort composite "gpu frame"; do
    row="$row $(echo "$frame" | ab_metric "$pass") |"
  done
  row="$row $(echo "$sorts" | ab_sort_row 32 radix) ms |"
  row="$row $(echo "$sorts" | ab_sort_row 64 radix) ms |"
  echo "$row"
}
