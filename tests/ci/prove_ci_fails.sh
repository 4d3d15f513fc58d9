#!/usr/bin/env bash
# Proves that .ci/run fails when it should: on a scratch clone of this checkout's HEAD it breaks one
# thing at a time and checks that .ci/run exits non-zero with the broken step marked FAILED in its
# summary. Run by hand (it builds the project once, about 10 minutes on 2 cores), not by CI:
#
#   bash tests/ci/prove_ci_fails.sh [SCRATCH_DIR]
#
#   1. no ../shared beside the clone            -> step shared-scenes fails
#   2. a source file that does not compile       -> step build fails
#   3. a test that fails                         -> step tests fails
#   4. the cluster's package setup fails         -> step cluster-setup fails (run with CI_STEPS, so that
#      the half hour of steps before it is not repeated)
#   5. a test that hangs                         -> step tests fails, its suite named as a timeout after its
#      limit (TILESPLAT_TEST_TIMEOUT) and the hung test shown, not the whole run killed (CI_STEPS:
#      configure, build, tests)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
shared="$(cd "$root/.." && pwd)/shared"
scratch="${1:-$(mktemp -d /tmp/tilesplat-ci-proof.XXXXXX)}"
[ -d "$shared/scenes" ] || { echo "prove: $shared/scenes not found (needed for cases 2 to 4)" >&2; exit 2; }
results=()

# expect_failure CASE STEP DIR [ENV...]: runs DIR/.ci/run, which must exit non-zero with STEP FAILED.
expect_failure() {
  local name="$1" failing_step="$2" dir="$3"
  shift 3
  local log="$scratch/$name.log" status=0
  echo "== case $name: expecting step '$failing_step' to fail (log: $log) =="
  (cd "$dir" && env -u CI -u TILESPLAT_SHARED_SCENES "$@" bash .ci/run >"$log" 2>&1) || status=$?
  if [ "$status" -eq 0 ]; then
    tail -n 20 "$log"
    echo "prove: case $name: .ci/run exited 0" >&2
    exit 1
  fi
  if ! grep -q -E "^$failing_step +[0-9-]+ +[0-9-]+ +FAILED" "$log"; then
    tail -n 20 "$log"
    echo "prove: case $name: .ci/run failed (exit $status), but not at step '$failing_step'" >&2
    exit 1
  fi
  results+=("case $name: .ci/run exited $status, step $failing_step FAILED")
  sed -n '/== CI summary ==/,$p' "$log"
}

# 1. A clone with no ../shared beside it.
git clone -q "$root" "$scratch/alone/main"
expect_failure missing-shared shared-scenes "$scratch/alone/main"

# 2-4 share one clone (and so one build) with ../shared beside it.
git clone -q "$root" "$scratch/with-shared/main"
ln -s "$shared" "$scratch/with-shared/shared"
clone="$scratch/with-shared/main"

echo '#error "deliberately broken by tests/ci/prove_ci_fails.sh"' >>"$clone/engine/src/version.cpp"
expect_failure broken-build build "$clone"
git -C "$clone" checkout -q -- engine/src/version.cpp

cat >>"$clone/tests/test_sha256.cpp" <<'TEST'
TEST(DeliberatelyBroken, FailsSoThatCiMustFail) { EXPECT_EQ(1, 2) << "deliberately broken by prove_ci_fails.sh"; }
TEST
expect_failure failing-test tests "$clone"
git -C "$clone" checkout -q -- tests/test_sha256.cpp

sed -i 's|  --cluster) pkgs+=(slurm-wlm munge) ;;|  --cluster) echo "setup: deliberately broken" >\&2; exit 1 ;;|' "$clone/cmake/setup-deps.sh"
grep -q "deliberately broken" "$clone/cmake/setup-deps.sh"
expect_failure broken-cluster-setup cluster-setup "$clone" CI_STEPS="shared-scenes cluster-setup slurm"

git -C "$clone" checkout -q -- cmake/setup-deps.sh

# 5. A test that never ends, in a suite of tests that pass: ctest stops the suite (one ctest test, one
# process: tests/register_test_suites.cmake) at its limit and names it, and the suite's output, which the
# log shows, ends at the test that hung; the step fails, the run goes on to its summary. The limit is
# lowered to 20 s for the proof (600 s in CI).
cat >>"$clone/tests/test_sha256.cpp" <<'TEST'
TEST(Sha256, DeliberatelyHungNeverEnds) { for (;;) std::this_thread::sleep_for(std::chrono::seconds(1)); }
TEST
sed -i '1i #include <chrono>\n#include <thread>' "$clone/tests/test_sha256.cpp"
sed -i 's/^set(TILESPLAT_TEST_TIMEOUT 600 /set(TILESPLAT_TEST_TIMEOUT 20 /' "$clone/tests/CMakeLists.txt"
grep -q '^set(TILESPLAT_TEST_TIMEOUT 20 ' "$clone/tests/CMakeLists.txt"
rm -f "$clone/build/CMakeCache.txt"
expect_failure hung-test tests "$clone" CI_STEPS="shared-scenes configure build tests"
grep -q -E "Sha256\.\* .*\*\*\*Timeout" "$scratch/hung-test.log" ||
  { echo "prove: case hung-test: ctest did not name the hung suite as a timeout" >&2; exit 1; }
grep -q -F "[ RUN      ] Sha256.DeliberatelyHungNeverEnds" "$scratch/hung-test.log" ||
  { echo "prove: case hung-test: the log does not show the test that hung" >&2; exit 1; }
results+=("case hung-test: $(grep -m1 -E 'Sha256\.\* .*Timeout' "$scratch/hung-test.log" | tr -s '. ')")
git -C "$clone" checkout -q -- tests/test_sha256.cpp tests/CMakeLists.txt

echo
printf '%s\n' "${results[@]}"
echo "prove: all 5 deliberate breakages made .ci/run fail at the step that broke"
