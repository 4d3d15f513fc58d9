#!/usr/bin/env bash
# A real Slurm cluster on this machine runs docs/cluster/render-array.sbatch: munged, slurmctld and
# slurmd start from a generated single-node slurm.conf in a temporary folder; a 4-task array renders
# an orbit of the bundled playbot; one task is cancelled midway with scancel, the merge must name its
# missing frames, the array is submitted again and resumes, and the merged frames must equal an
# unsharded run's bit for bit. Every daemon started here is stopped by its PID on the way out, also
# on failure; a daemon that does not start fails the test with its log.
#
#   bash tests/cluster/slurm_test.sh [BUILD]      (needs root and: bash cmake/setup-deps.sh --cluster)
set -euo pipefail
cd "$(dirname "$0")/../.."
repo=$(pwd)
build="$repo/${1:-build}"
render="$build/apps/tilesplat-render"
compare="$build/tests/tilesplat_compare_exr"
scene="$repo/scenes/playbot_lod3/playbot_lod3_31000_sh2.ply"
frames=(--orbit 64 --width 960 --height 540)  # 16 frames a task: long enough to cancel one midway
tasks=4

work=$(mktemp -d /tmp/tilesplat-slurm.XXXXXX)
chmod 755 "$work"  # munged wants its socket's folders reachable
mkdir -p "$work/munge" "$work/state" "$work/spool" "$work/log" "$work/whole" "$work/out"
chmod 700 "$work/munge"
export SLURM_CONF="$work/slurm.conf" TILESPLAT_RENDER="$render"
step() { echo "slurm test: $*"; }

pid_files=()
stop_daemons() {
  local status=$?
  for pid_file in "${pid_files[@]}"; do
    [ -s "$pid_file" ] || continue
    local pid
    pid=$(cat "$pid_file")
    kill "$pid" 2>/dev/null || true
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
  done
  if [ "$status" -eq 0 ]; then rm -rf "$work"; else echo "slurm test: the daemons' logs are in $work/log"; fi
}
trap stop_daemons EXIT

fail() {
  echo "slurm test: FAILED: $*"
  for log in "$work"/log/*; do
    [ -f "$log" ] || continue
    echo "---- $log"
    tail -n 25 "$log"
  done
  exit 1
}

for tool in munged slurmctld slurmd sbatch scancel sinfo; do
  command -v "$tool" >/dev/null || fail "$tool not found: run bash cmake/setup-deps.sh --cluster"
done
[ -x "$render" ] && [ -x "$compare" ] || fail "build $build first (tilesplat-render, tilesplat_compare_exr)"

# munge: a fresh key, its socket in the temporary folder.
head -c 1024 /dev/urandom >"$work/munge/munge.key"
chmod 400 "$work/munge/munge.key"
socket="$work/munge/munge.socket"
pid_files+=("$work/munge/munged.pid")
munged --force --key-file="$work/munge/munge.key" --socket="$socket" --pid-file="$work/munge/munged.pid" \
  --seed-file="$work/munge/munged.seed" --log-file="$work/log/munged.log" || fail "munged did not start"
munge -n -S "$socket" | unmunge -S "$socket" >/dev/null || fail "munge cannot encode and decode a credential"

# Ports of our own, so that a Slurm already on the machine is not disturbed.
port=$((20000 + RANDOM % 20000))
host=$(hostname -s)
cat >"$SLURM_CONF" <<EOF
ClusterName=tilesplat-test
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
pid_files+=("$work/slurmctld.pid" "$work/slurmd.pid")
slurmctld -i >>"$work/log/slurmctld.out" 2>&1 || fail "slurmctld did not start"
slurmd >>"$work/log/slurmd.out" 2>&1 || fail "slurmd did not start"
for _ in $(seq 60); do
  [ "$(sinfo -h -o %T 2>/dev/null)" = "idle" ] && break
  sleep 0.5
done
[ "$(sinfo -h -o %T 2>/dev/null)" = "idle" ] || fail "the node did not come up idle: $(sinfo 2>&1 | tr '\n' ' ')"
step "munged, slurmctld and slurmd up on $host (ports $port, $((port + 1)))"

"$render" "$scene" "${frames[@]}" -o "$work/whole/frame_%05d.exr" --quiet || fail "the unsharded run failed"
step "unsharded run: $(ls "$work/whole" | grep -c exr) frames"

# The first submission; task 1 is cancelled once it has finished two frames.
submit() {  # submit LOG: sbatch --wait of the docs' script, its job id in LOG's first line
  sbatch --wait --parsable --array=0-$((tasks - 1)) --output="$work/log/task-%A_%a.log" \
    docs/cluster/render-array.sbatch "$scene" "$work/out" "${frames[@]}" >"$1" 2>&1
}
submit "$work/first.out" &
sbatch_pid=$!
manifest1="$work/out/manifest.shard-1-of-$tasks.jsonl"
for _ in $(seq 1200); do
  [ -s "$work/first.out" ] && [ -f "$manifest1" ] && [ "$(wc -l <"$manifest1")" -ge 2 ] && break
  kill -0 "$sbatch_pid" 2>/dev/null || break
  sleep 0.05
done
job=$(head -n 1 "$work/first.out" | cut -d';' -f1)
[[ "$job" =~ ^[0-9]+$ ]] || fail "sbatch printed no job id: $(cat "$work/first.out")"
scancel "${job}_1" || fail "scancel ${job}_1 failed"
first_status=0
wait "$sbatch_pid" || first_status=$?
done_at_cancel=$(wc -l <"$manifest1")
[ "$first_status" -ne 0 ] || fail "sbatch --wait reported success although task 1 was cancelled"
[ "$done_at_cancel" -lt 16 ] || fail "task 1 finished all its frames before scancel reached it"
step "job $job: task 1 cancelled after $done_at_cancel of its 16 frames (sbatch --wait exit $first_status)"

if merge=$("$render" --merge-manifests "$work/out" 2>&1); then fail "the merge passed with task 1 unfinished"; fi
grep -q "frames are in no manifest" <<<"$merge" || fail "the merge did not name the missing frames: $merge"
step "merge refuses: ${merge#*error: }"

submit "$work/second.out" || fail "the resubmitted array failed: $(cat "$work/second.out")"
second=$(head -n 1 "$work/second.out" | cut -d';' -f1)
# Whole lines, so that "2 already done" cannot pass for "12 already done": each task's log must have
# tilesplat-render's resume line with its own shard and count.
expect_resume_line() {  # expect_resume_line TASK DONE
  local log="$work/log/task-${second}_$1.log"
  grep -q -x -E "tilesplat-render: shard $1/$tasks \([^)]*\): 16 of 64 frames, $2 already done \(manifest and checksums match\), skipped" "$log" ||
    fail "task $1 of job $second should have skipped $2 frames: $(cat "$log")"
}
expect_resume_line 1 "$done_at_cancel"
for task in 0 2 3; do expect_resume_line "$task" 16; done
step "job $second: task 1 skipped its $done_at_cancel frames and rendered the rest; tasks 0, 2, 3 skipped all 16"

"$render" --merge-manifests "$work/out" >"$work/merge.log" 2>&1 || fail "the merge failed: $(cat "$work/merge.log")"
step "$(cat "$work/merge.log")"
count=0
for whole in "$work"/whole/frame_*.exr; do
  "$compare" "$whole" "$work/out/$(basename "$whole")" >/dev/null || fail "$(basename "$whole") differs from the unsharded run"
  count=$((count + 1))
done
[ "$count" -eq 64 ] || fail "expected 64 frames, compared $count"
step "passed: all $count frames of the resumed 4-task array equal the unsharded run bit for bit"
