#!/usr/bin/env bash
# Fuzzes the scene readers: builds the libFuzzer harnesses with clang + ASan + UBSan in build-fuzz/,
# replays every committed regression input (tests/fuzz/regressions/READER/), then fuzzes each reader
# for SECONDS, seeded with a few Gaussians cut from every PLY in the shared scenes and scenes/.
#
#   bash tests/fuzz/run.sh [SECONDS]     (default 60; env: TILESPLAT_SHARED_SCENES, FUZZ_BUILD_DIR, FUZZ_CXX,
#                                         FUZZ_JOBS: readers fuzzed at once, default the cores)
#
# libFuzzer's output goes to BUILD/fuzz_READER.log. On a finding (crash, sanitizer report, an
# exception other than SceneError, a timeout, more than 2 GB of memory) it prints the log's tail and
# the input, saved under BUILD/artifacts/READER/, and fails. Fix it, then keep the input as a
# regression: copy it to tests/fuzz/regressions/READER/ under a name that says what it was.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds="${1:-60}"
build="${FUZZ_BUILD_DIR:-build-fuzz}"
scenes="${TILESPLAT_SHARED_SCENES:-$(cd .. && pwd)/shared/scenes}"
readers=(ply splat ksplat spz sog compressed_ply gltf rad cameras scene_file lod_set scene_in_parts)
fuzz_flags=(-timeout=10 -rss_limit_mb=2048)
max_len() {  # a SOG zip or a GLB of 64 Gaussians with SH3 is about 20 kB; the rest fit in 16 kB
  case "$1" in sog | gltf | lod_set | scene_in_parts | ksplat | rad) echo 65536 ;; *) echo 16384 ;; esac
}

mkdir -p "$build"
findings() {  # the end of a libFuzzer log without its progress lines
  grep -v -E '^#[0-9]+[[:space:]]+(NEW|REDUCE|pulse|INITED|RELOAD)|^Executed ' "$1" | tail -n 50
}
quiet() {  # quiet LOG COMMAND...: runs COMMAND with its output in LOG, shown only when it fails
  local log="$1"
  shift
  "$@" >"$log" 2>&1 || { tail -n 40 "$log"; echo "fuzz: failed: $* (log: $log)"; return 1; }
}
quiet "$build/setup.log" bash cmake/setup-deps.sh --fuzz
echo "fuzz: $(head -n 1 "$build/setup.log" | cut -c1-100); $("${FUZZ_CXX:-clang++}" --version | head -n 1)"
quiet "$build/configure.log" env CXX="${FUZZ_CXX:-clang++}" \
  cmake -S . -B "$build" -G Ninja -DTILESPLAT_FUZZ=ON
quiet "$build/build.log" cmake --build "$build" -j2

seed_dirs=(scenes)
[ -d "$scenes" ] && seed_dirs=("$scenes" scenes) || echo "fuzz: $scenes not found, seeding from scenes/ only"
rm -rf "$build/seeds"
quiet "$build/seeds.log" "$build/tests/fuzz/make_ply_seeds" "$build/seeds/ply" "${seed_dirs[@]}"
echo "fuzz: $(tail -n 1 "$build/seeds.log")"
# The other readers are seeded with the small real files of each format in the shared scenes.
seed() {  # seed READER FILE...: copies the files that exist
  mkdir -p "$build/seeds/$1"
  local reader="$1"
  shift
  for file in "$@"; do [ -f "$file" ] && cp "$file" "$build/seeds/$reader/" || true; done
}
head -c 2048 "$scenes/plant_113648.splat" >"$build/seeds/plant_64.splat" 2>/dev/null || true
seed splat "$scenes/train_3pts.splat" "$build/seeds/plant_64.splat"
seed ksplat tests/data/ksplat/playcanvas_test_64_sh3_l{0,1,2}_sh2.ksplat
seed rad tests/data/rad/*.rad tests/data/rad/*.radc
seed spz "$scenes/train_3pts.spz" "$scenes/formats/playcanvas_test_64_sh3.v3.spz" "$scenes/formats/playcanvas_test_64_sh3.v4.spz"
seed sog "$scenes/formats/playcanvas_test_64_sh3.sog"
seed compressed_ply "$scenes/playcanvas_test_64.compressed.ply" "$scenes/formats/playcanvas_test_64_sh3.compressed.ply"
seed gltf "$scenes/formats/playcanvas_test_64_sh3.glb" tests/data/gltf_spz/*.glb
# The part-by-part reader's dispatch: a few of the PLY seeds, and an SPZ, a SOG, a .ksplat and a .rad.
seed scene_in_parts "$scenes/formats/playcanvas_test_64_sh3.v4.spz" "$scenes/formats/playcanvas_test_64_sh3.sog" \
  tests/data/ksplat/playcanvas_test_64_sh3_l1_sh2.ksplat tests/data/rad/playcanvas_test_64_sh3_sh1-lod.rad \
  $(find "$build/seeds/ply" -type f | sort | head -n 8)
# LOD set indexes: splat-transform's own (its chunk files are not beside the harness's folder: the index
# parses, its loads fail) and the valid indexes over the harness's c.ply in regressions/lod_set/.
seed lod_set tests/data/playbot_lod_set/lod-meta.json
# The camera readers (fuzz_cameras.cpp: the first byte picks the reader) from a COLMAP camera of each lens
# family and a transforms.json of each nerfstudio model.
mkdir -p "$build/seeds/cameras"
n=0
for line in "1 OPENCV 64 48 50 50 32 24 -0.1 0.02 0.001 -0.001" "1 SIMPLE_RADIAL_FISHEYE 64 48 30 32 24 0.05" \
  "1 FULL_OPENCV 64 48 50 50 32 24 -0.1 0.02 0.001 -0.001 0.002 0.01 -0.003 0.0005" \
  "1 OPENCV_FISHEYE 64 48 30 30 32 24 0.05 -0.01 0.002 -0.0003"; do
  printf '\002%s\n' "$line" >"$build/seeds/cameras/colmap_$((n += 1))"
done
for model in '"OPENCV", "k1": -0.1, "p1": 0.001' '"OPENCV_FISHEYE", "k1": 0.05, "k4": -0.001' '"EQUIRECTANGULAR"'; do
  printf '\004"camera_model": %s, "fl_x": 50, "w": 64, "h": 48, "frames": [{"transform_matrix": %s}]}' "$model" \
    '[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 4], [0, 0, 0, 1]]' >"$build/seeds/cameras/transforms_$((n += 1))"
done

# libFuzzer's timeout is wall-clock: a process the machine stops or starves for a while reports
# one on whatever input it was running. Such a "timeout" that replays in time is not a finding.
stalled() {  # stalled FUZZER ARTIFACT_DIR
  local found=("$2"*)
  [ ${#found[@]} -eq 1 ] && [[ "$(basename "${found[0]}")" == timeout-* ]] &&
    "$1" -timeout=10 -rss_limit_mb=2048 "${found[0]}" >/dev/null 2>&1
}

# fuzz_reader READER: replays READER's regression inputs, then fuzzes it for SECONDS; prints what it
# found and fails on a finding.
fuzz_reader() {
  local reader="$1"
  local fuzzer="$build/tests/fuzz/fuzz_$reader"
  local regressions="tests/fuzz/regressions/$reader"
  local log="$build/fuzz_$reader.log"
  local artifacts="$build/artifacts/$reader/"
  rm -rf "$artifacts"
  mkdir -p "$regressions" "$build/corpus/$reader" "$build/seeds/$reader" "$artifacts"
  # Each regression input once, whole (no -max_len), no mutation.
  local inputs
  mapfile -t inputs < <(find "$regressions" -type f | sort)
  if [ ${#inputs[@]} -gt 0 ] &&
     ! "$fuzzer" -timeout=10 -rss_limit_mb=2048 "${inputs[@]}" >"$build/regressions_$reader.log" 2>&1; then
    findings "$build/regressions_$reader.log"
    echo "fuzz: FAILED: a regression input of $regressions crashes fuzz_$reader again"
    return 1
  fi
  echo "fuzz: $reader: ${#inputs[@]} regression inputs replay cleanly"
  # New inputs go to the first directory (BUILD/corpus, kept between local runs), never to the seeds
  # or the committed regressions.
  local dict=()
  [ -f "tests/fuzz/$reader.dict" ] && dict=(-dict="tests/fuzz/$reader.dict")
  if "$fuzzer" "${fuzz_flags[@]}" -max_len="$(max_len "$reader")" -max_total_time="$seconds" -print_final_stats=1 \
       "${dict[@]}" -artifact_prefix="$artifacts" \
       "$build/corpus/$reader" "$build/seeds/$reader" "$regressions" >"$log" 2>&1; then
    local runs cov
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1)
    echo "fuzz: $reader: ${seconds}s, ${runs:-?} inputs, $cov, no findings (log: $log)"
  elif stalled "$fuzzer" "$artifacts"; then
    echo "fuzz: $reader: a timeout that does not reproduce (the process was stalled, not the input slow): ignored"
  else
    findings "$log"
    echo "fuzz: FAILED: fuzz_$reader found a problem; the input is in $artifacts:"
    ls -l "$artifacts"
    echo "fuzz: reproduce with: $fuzzer ${artifacts}FILE ; once fixed, copy the file to $regressions/"
    return 1
  fi
}

# The readers are fuzzed side by side, one a core (libFuzzer runs one process on one core; FUZZ_JOBS
# sets how many at once): each still gets its SECONDS. Each one's messages are printed, in the readers'
# order, once it is done; its exit status is kept in a file, so that none can be lost.
jobs_at_once="${FUZZ_JOBS:-$(nproc)}"
for reader in "${readers[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs_at_once" ]; do wait -n || true; done  # until one is done
  rm -f "$build/fuzz_$reader.status"
  (
    status=0
    fuzz_reader "$reader" >"$build/fuzz_$reader.out" 2>&1 || status=$?
    echo "$status" >"$build/fuzz_$reader.status"
  ) &
done
wait
status=0
for reader in "${readers[@]}"; do
  cat "$build/fuzz_$reader.out"
  reader_status=$(cat "$build/fuzz_$reader.status" 2>/dev/null || echo unknown)
  if [ "$reader_status" != 0 ]; then
    echo "fuzz: $reader: failed (exit status $reader_status)"
    status=1
  fi
done
exit $status
