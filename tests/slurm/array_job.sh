#!/usr/bin/env bash
# test_slurm_array: a real single-node Slurm (slurmctld and slurmd on this host, munge for authentication) runs a
# 4-task array job over a 12-frame sweep with `algray batch` (shards from the array's variables); every frame must
# exist exactly once and match a single-process batch byte for byte. Daemons that do not start fail the test
# with their logs.
#   array_job.sh ALGRAY_BINARY WORK_DIR
set -uo pipefail
test_name=test_slurm_array
# Its own fail(), below, also prints the daemons' logs.
source "$(dirname "$0")/../support/script_test.sh"
algray=$1
work=$2
rm -rf "$work"
mkdir -p "$work"/{state,spool,run,single,array}
started_munged=0

fail() {
  echo "test_slurm_array: $*" >&2
  for log in "$work"/slurmctld.log "$work"/slurmd.log "$work"/munged.log; do
    [ -f "$log" ] && { echo "--- $log" >&2; tail -n 40 "$log" >&2; }
  done
  stop
  exit 1
}
stop() {
  [ -n "${SLURM_CONF:-}" ] && scontrol shutdown >/dev/null 2>&1
  for pid in "$work"/run/slurmd.pid "$work"/run/slurmctld.pid; do
    [ -f "$pid" ] && kill "$(cat "$pid")" 2>/dev/null
  done
  if [ "$started_munged" = 1 ]; then pkill -f "munged.*$work" 2>/dev/null; fi
}

for tool in munged slurmctld slurmd sbatch squeue sinfo scontrol; do
  command -v "$tool" >/dev/null || fail "$tool not found: install munge, slurmctld, slurmd and slurm-client (scripts/install-deps.sh does)"
done

# munge: this test's own daemon and socket, so that it needs nothing running and leaves nothing behind.
socket="$work/run/munge.socket"
if [ ! -s /etc/munge/munge.key ]; then fail "no /etc/munge/munge.key (the munge package makes one)"; fi
munged --force --socket="$socket" --pid-file="$work/run/munged.pid" --log-file="$work/munged.log" \
       --seed-file="$work/run/munged.seed" || fail "munged did not start"
started_munged=1

host=$(hostname -s)
cpus=$(nproc)
export SLURM_CONF="$work/slurm.conf"
cat > "$SLURM_CONF" <<CONF
ClusterName=algraytest
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmctldPort=16817
SlurmdPort=16818
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/run/slurmctld.pid
SlurmdPidFile=$work/run/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -f "$SLURM_CONF" || fail "slurmctld did not start"
slurmd -f "$SLURM_CONF" || fail "slurmd did not start"
for _ in $(seq 60); do
  state=$(sinfo -h -o %T 2>/dev/null | head -n1)
  [ "$state" = idle ] && break
  sleep 0.5
done
[ "$state" = idle ] || fail "the node did not become idle (sinfo: '$state')"

# The sweep: 12 frames of a growing ball, once in one process, once as a 4-task array.
scene=$(growing_ball_scene)
jobs='[defaults]
set = { image = { width = 32, height = 24 } }
[[job]]
name = "grow"
scene = "ball.toml"
output = "grow_{frame:02}.png"
sweep.r = { from = 0.4, to = 1.5, steps = 12 }'
for dir in single array; do
  echo "$scene" > "$work/$dir/ball.toml"
  echo "$jobs" > "$work/$dir/jobs.toml"
done
(cd "$work/single" && "$algray" batch jobs.toml) || fail "the single-process batch failed"

job=$(cd "$work/array" && POCL_MAX_PTHREAD_COUNT=1 sbatch --parsable --array=0-3 --cpus-per-task=1 \
        --output="$work/array/task-%a.out" --wrap "$algray batch jobs.toml") || fail "sbatch refused the job"
for _ in $(seq 600); do
  [ -z "$(squeue -h -j "$job" 2>/dev/null)" ] && break
  sleep 0.5
done
[ -z "$(squeue -h -j "$job" 2>/dev/null)" ] || fail "job $job still queued or running after 300 s: $(squeue -j "$job")"

status=0
for k in 0 1 2 3; do
  log="$work/array/jobs.log.shard-$k-of-4.jsonl"
  [ -f "$log" ] || { echo "no log from task $k:" >&2; cat "$work/array/task-$k.out" >&2; status=1; }
done
count=$(cat "$work"/array/jobs.log.shard-*-of-4.jsonl 2>/dev/null | grep -c '"status":"ok"')
[ "$count" = 12 ] || { echo "expected 12 frames rendered once each, the logs have $count" >&2; status=1; }
for f in $(seq -f %02g 0 11); do
  cmp -s "$work/single/grow_$f.png" "$work/array/grow_$f.png" || { echo "frame $f differs or is missing" >&2; status=1; }
done
(cd "$work/array" && "$algray" batch jobs.toml --merge-logs) || status=1
[ "$(wc -l < "$work/array/jobs.log.jsonl")" = 12 ] || { echo "the merged log is not 12 lines" >&2; status=1; }
[ $status = 0 ] || fail "the array job's frames are wrong (above)"
echo "test_slurm_array: job $job, 4 tasks: 12 frames, each once, identical to one process"
stop
