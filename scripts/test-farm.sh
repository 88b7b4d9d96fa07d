#!/usr/bin/env bash
# Integration test of farm rendering on a real, private, one-node Slurm cluster (docs/farm/README.md).
#
# Installs slurm-wlm and munge from Debian if missing, builds pmr (scripts/setup.sh), starts munged,
# slurmctld and slurmd as this script's own processes with a private configuration under a temporary
# directory (an existing Slurm installation's configuration is not touched), then:
#   1. submits scripts/farm/slurm-array.sbatch as an array of 4 tasks over 16 turntable frames and
#      checks that every frame was rendered exactly once, is complete (pmr verify) and is byte-identical
#      to the same frame rendered by one process without sharding (wall times of both are printed);
#   2. submits a second array, cancels one task mid-way (scancel), checks that pmr verify reports
#      missing frames, resubmits with the same command (--resume) and checks the set is complete.
# Every daemon it started is stopped (by the process ids it recorded) and its temporary state removed,
# also when a check fails. Run as root (or with sudo for the package installation and the daemons).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)

log() { echo "test-farm: $*" >&2; }
fail() { log "FAILED: $*"; exit 1; }

if [ "$(id -u)" -ne 0 ]; then
  fail "run as root: the private Slurm cluster runs its daemons as root (SlurmUser=root)"
fi
missing=()
for p in slurm-wlm munge; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  log "installing ${missing[*]}"
  apt-get update -q >/dev/null
  # the packages' own services are not wanted: this script starts private daemons
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}" >/dev/null
fi
bash scripts/setup.sh build >/dev/null
PMR="$ROOT/build/pmr"

TMP=$(mktemp -d /tmp/pmr-farm-XXXXXX)
PIDS=()
cleanup() {
  for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${PIDS[@]}"; do
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
  done
  rm -rf "$TMP"
}
trap cleanup EXIT

# ---- a private munge and a one-node Slurm --------------------------------------------------------
mkdir -p "$TMP/munge" "$TMP/state" "$TMP/spool" "$TMP/out"
chmod 700 "$TMP/munge"
dd if=/dev/urandom of="$TMP/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$TMP/munge/munge.key"
munged --key-file="$TMP/munge/munge.key" --socket="$TMP/munge/munge.socket" \
       --pid-file="$TMP/munge/munged.pid" --log-file="$TMP/munge/munged.log" \
       --seed-file="$TMP/munge/munged.seed" --force
for _ in $(seq 50); do [ -s "$TMP/munge/munged.pid" ] && break; sleep 0.1; done
PIDS+=("$(cat "$TMP/munge/munged.pid")")

NODE=$(hostname -s)
CPUS=$(nproc)
MEM=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 512 ))
export SLURM_CONF="$TMP/slurm.conf"
cat > "$SLURM_CONF" <<EOF
ClusterName=pmrtest
SlurmctldHost=$NODE
SlurmUser=root
SlurmdUser=root
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$TMP/munge/munge.socket
StateSaveLocation=$TMP/state
SlurmdSpoolDir=$TMP/spool
SlurmctldPidFile=$TMP/slurmctld.pid
SlurmdPidFile=$TMP/slurmd.pid
SlurmctldLogFile=$TMP/slurmctld.log
SlurmdLogFile=$TMP/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
SlurmdTimeout=60
InactiveLimit=0
MinJobAge=300
JobCompType=jobcomp/none
NodeName=$NODE CPUs=$CPUS RealMemory=$MEM State=UNKNOWN
PartitionName=test Nodes=$NODE Default=YES MaxTime=INFINITE State=UP OverSubscribe=YES
EOF
slurmctld -D -f "$SLURM_CONF" > "$TMP/slurmctld.out" 2>&1 &
PIDS+=($!)
slurmd -D -f "$SLURM_CONF" > "$TMP/slurmd.out" 2>&1 &
PIDS+=($!)
ready=0
for _ in $(seq 100); do
  if sinfo -h -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then ready=1; break; fi
  sleep 0.2
done
[ $ready -eq 1 ] || { tail -5 "$TMP/slurmctld.log" "$TMP/slurmd.log" >&2 || true; fail "the private Slurm node did not come up"; }
log "private Slurm up on $NODE ($CPUS CPUs)"

# ---- 1. an array of 4 tasks over 16 frames against one process -----------------------------------
ARGS=(--turntable 360:16 --views 8 --view-size 128x64 --display 480x270)
FRAMES=0:15
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }'; }
t0=$(now)
jid=$(sbatch --parsable --array=0-3 --cpus-per-task=1 --chdir="$TMP" --export=ALL,PMR="$PMR" \
      scripts/farm/slurm-array.sbatch "$TMP/out/a" "$FRAMES" "${ARGS[@]}")
wait_job() {  # waits until job $1 has left the queue, at most $2 seconds
  local deadline=$(( $(date +%s) + $2 ))
  while squeue -h -j "$1" 2>/dev/null | grep -q .; do
    [ "$(date +%s)" -lt "$deadline" ] || { scancel "$1" || true; fail "job $1 did not finish within $2 s"; }
    sleep 0.5
  done
}
wait_job "$jid" 300
t_array=$(since "$t0")
t0=$(now)
POCL_MAX_PTHREAD_COUNT=$CPUS "$PMR" render --frames "$FRAMES" --out "$TMP/out/single" -q "${ARGS[@]}" 2>/dev/null
t_single=$(since "$t0")
log "4-task array: ${t_array} s wall; one process: ${t_single} s wall (16 frames)"

"$PMR" verify "$TMP/out/a" --frames "$FRAMES" >/dev/null || fail "pmr verify reports missing frames after the array"
# every frame rendered exactly once over the 4 tasks' logs
done_lines=$(cat "$TMP"/pmr-render-"$jid"_*.log | grep -oE 'frame [0-9]+ written' | sort)
[ "$(echo "$done_lines" | wc -l)" -eq 16 ] || fail "expected 16 rendered frames in the task logs, got: $done_lines"
[ "$(echo "$done_lines" | uniq | wc -l)" -eq 16 ] || fail "a frame was rendered twice: $done_lines"
for f in $(seq 0 15); do
  n=$(printf 'frame_%04d' "$f")
  for ext in exr json; do
    cmp -s "$TMP/out/a/$n.$ext" "$TMP/out/single/$n.$ext" || fail "$n.$ext differs from the unsharded render"
  done
done
log "array: 16 frames, each rendered once, byte-identical to one process"

# ---- 2. a task cancelled mid-way, verify, resubmit ------------------------------------------------
# frames slow enough (seconds each, 4 tasks on the cores) that the cancel lands before task 1 is done
ARGS2=(--turntable 360:16 --views 32 --view-size 1024x512 --display 3840x2160)
submit2() {
  sbatch --parsable --array=0-3 --cpus-per-task=1 --chdir="$TMP" --export=ALL,PMR="$PMR" \
    scripts/farm/slurm-array.sbatch "$TMP/out/b" "$FRAMES" "${ARGS2[@]}"
}
jid2=$(submit2)
# cancel task 1 once it has finished its first frame (its frames are 1, 5, 9, 13)
deadline=$(( $(date +%s) + 120 ))
until [ -e "$TMP/out/b/frame_0001.exr" ]; do
  [ "$(date +%s)" -lt "$deadline" ] || fail "task 1 of the second array did not start"
  sleep 0.1
done
scancel "${jid2}_1"
wait_job "$jid2" 300
if "$PMR" verify "$TMP/out/b" --frames "$FRAMES" > "$TMP/missing.txt" 2>/dev/null; then
  fail "pmr verify found nothing missing after a cancelled task"
fi
log "after scancel, pmr verify reports frames $(cat "$TMP/missing.txt") missing"
ls -A "$TMP/out/b" | grep -q '^\.' && fail "a temporary file was left behind: $(ls -A "$TMP/out/b" | grep '^\.')"
jid3=$(submit2)
wait_job "$jid3" 300
"$PMR" verify "$TMP/out/b" --frames "$FRAMES" >/dev/null || fail "the resubmitted array left frames missing"
log "resubmitted with --resume: all 16 frames complete"
log "PASSED"
