#!/bin/bash
# A real one-node Slurm cluster on this machine, stood up from Debian's slurm-wlm and munge: a
# munge key, munged, slurmctld and slurmd started as plain daemons (no systemd) with their
# configuration, state and sockets in a scratch directory, on ports of their own. Through it, the
# scripts of scripts/slurm: a reference rendered as 4 shards (a job array) and merged by a job
# that waits for them, checked against one render of as many samples (merge_check: the pixels
# within their standard errors, the noise estimates consistent); and a small bench plan run as
# an array, collected by a dependent job, with the rows and sections of the same bench run here.
# Skipped (exit 77), saying why, where the cluster cannot start: not root, packages missing.
# Usage: test_slurm.sh GLINT MERGE_CHECK SCRIPTS_DIR TMP
set -u
glint=$1 merge_check=$2 scripts=$3 base=$4
skip() { echo "test_slurm: skipped: $*"; exit 77; }
fail() { echo "test_slurm: FAILED: $*"; failed=1; }
[ "$(id -u)" -eq 0 ] || skip "needs root to run munged and slurmd (here uid $(id -u))"
for p in munged slurmctld slurmd sbatch squeue scontrol; do
  command -v "$p" >/dev/null || [ -x "/usr/sbin/$p" ] || skip "$p missing (apt-get install slurm-wlm munge; scripts/deps.sh does)"
done
export PATH="$PATH:/usr/sbin"

t="$base/slurm"
rm -rf "$t" && mkdir -p "$t" && chmod 700 "$t" || exit 1
t=$(cd "$t" && pwd)
pids=()
cleanup() {
  # Only what this test started, by its own process ids.
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null; done
}
trap cleanup EXIT

# munge: a key of its own, its socket in the scratch directory.
mkdir -m 711 "$t/munge" && dd if=/dev/urandom of="$t/munge/key" bs=1024 count=1 status=none && chmod 400 "$t/munge/key"
munged -F -f --key-file="$t/munge/key" --socket="$t/munge/sock" --pid-file="$t/munge/pid" \
  --log-file="$t/munge/log" --seed-file="$t/munge/seed" &
pids+=($!)

# Two free ports: the first of a random pair in the dynamic range that nothing listens on.
port=0
for _ in $(seq 50); do
  p=$((20000 + RANDOM % 20000))
  if ! (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null && ! (exec 3<>"/dev/tcp/127.0.0.1/$((p + 1))") 2>/dev/null; then
    port=$p
    break
  fi
done
[ "$port" -ne 0 ] || skip "no free port pair for slurmctld and slurmd"
host=$(hostname -s)
mkdir -p "$t/state" "$t/spool"
cat >"$t/slurm.conf" <<CONF
ClusterName=glinttest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$t/munge/sock
CredType=cred/munge
StateSaveLocation=$t/state
SlurmdSpoolDir=$t/spool
SlurmctldPidFile=$t/slurmctld.pid
SlurmdPidFile=$t/slurmd.pid
SlurmctldLogFile=$t/slurmctld.log
SlurmdLogFile=$t/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
PlugStackConfig=$t/plugstack.conf
NodeName=$host NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
: >"$t/plugstack.conf"
export SLURM_CONF="$t/slurm.conf"
for _ in $(seq 50); do [ -S "$t/munge/sock" ] && break; sleep 0.1; done
[ -S "$t/munge/sock" ] || skip "munged did not start: $(tail -n 3 "$t/munge/log" 2>/dev/null)"
slurmctld -D -i -f "$t/slurm.conf" >"$t/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$t/slurm.conf" >"$t/slurmd.out" 2>&1 &
pids+=($!)
up=0
for _ in $(seq 100); do
  if sinfo -h -o %T 2>/dev/null | grep -Eq '^(idle|mixed|allocated)'; then up=1; break; fi
  sleep 0.2
done
[ "$up" -eq 1 ] || skip "the one-node cluster did not come up: $(tail -n 3 "$t/slurmctld.log" "$t/slurmd.log" 2>/dev/null | tr '\n' ' ')"
echo "test_slurm: cluster up (slurmctld on port $port, node $host)"

# Waits until none of the given jobs is queued or running (at most $2 seconds); 0 when done.
wait_jobs() {
  for _ in $(seq $(($2 * 5))); do
    [ -z "$(squeue -h -j "$1" 2>/dev/null)" ] && return 0
    sleep 0.2
  done
  return 1
}
job_ids() { grep -o 'job [0-9]*' | awk '{print $2}' | paste -sd, -; }
failed=0
export GLINT="$glint"
work="$t/work"
mkdir -p "$work" && cd "$work" || exit 1

# A reference in 4 shards, then its merge, queued by the script; and here, one render of as many
# samples with another seed.
scene=(builtin:doorway --size 32x24 --max-depth 1 --threads 1)
out=$("$scripts/submit-reference.sh" 4 shards ref.exr "${scene[@]}" --spp 64 --seed 11) || fail "submit-reference.sh: $out"
echo "test_slurm: $out"
ids=$(echo "$out" | job_ids)
wait_jobs "$ids" 120 || fail "the reference's jobs did not finish in 120 s: $(squeue)"
[ -f ref.exr ] || fail "no merged reference: $(cat glint-*.log 2>/dev/null)"
ls shards
"$glint" render "${scene[@]}" --spp 64 --seed 12 --shard 0/1 --out single.exr --quiet || fail "the single render"
"$merge_check" ref.exr single.exr || fail "the merged reference against a single render"

# A bench plan: 2 runs, an array of 2 tasks and the collect after them.
"$glint" bench builtin:doorway --reference ref.exr --methods pt,vsl --times 0.05,0.1 --threads 1 --jobs plan --quiet ||
  fail "glint bench --jobs"
out=$("$scripts/submit-bench.sh" plan) || fail "submit-bench.sh: $out"
echo "test_slurm: $out"
ids=$(echo "$out" | job_ids)
wait_jobs "$ids" 120 || fail "the bench's jobs did not finish in 120 s: $(squeue)"
"$glint" bench builtin:doorway --reference ref.exr --methods pt,vsl --times 0.05,0.1 --threads 1 --out local --quiet ||
  fail "the local bench"
for f in results.csv summary.csv report.md error-vs-time.svg error-vs-time.png; do
  [ -s "plan/$f" ] || fail "the collect wrote no plan/$f: $(cat glint-*.log 2>/dev/null)"
done
[ "$(cut -d, -f1-3 plan/results.csv)" = "$(cut -d, -f1-3 local/results.csv)" ] || fail "results.csv rows differ from a local run's"
[ "$(cut -d, -f1-5 plan/summary.csv)" = "$(cut -d, -f1-5 local/summary.csv)" ] || fail "summary.csv rows differ from a local run's"
[ "$(grep '^#' plan/report.md)" = "$(grep '^#' local/report.md)" ] || fail "report.md's sections differ from a local run's"
[ "$failed" -eq 0 ] && echo "test_slurm: passed"
exit "$failed"
