#!/usr/bin/env bash
# The Slurm recipe, tested: starts a one-node Slurm cluster (Debian's slurmctld, slurmd
# and munge; `scripts/setup.sh --slurm` installs them), submits a job array whose task I
# runs `physval gate SUITE --shard I/N`, waits, merges the N folders with `physval merge`
# and compares the merged results.json (timings aside), JUnit file and exit status with
# a single `physval gate` of the same suite. Exits nonzero on any difference.
#
#   scripts/test-slurm.sh [--shards N] [--physval EXE] [SUITE...]
#
# Defaults: 3 shards, build/physval, validation/scenarios. Runs as root (the daemons run
# as root, everything else in a temporary folder); stops what it started on exit.
set -euo pipefail

here=$(cd "$(dirname "$0")/.." && pwd)
shards=3
physval="$here/build/physval"
suite=()
while (($#)); do
  case "$1" in
    --shards) shards=$2; shift 2 ;;
    --physval) physval=$2; shift 2 ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) suite+=("$(realpath "$1")"); shift ;;
  esac
done
((${#suite[@]})) || suite=("$here/validation/scenarios")
physval=$(realpath "$physval")
[ -x "$physval" ] || { echo "test-slurm: no physval at $physval (build it first)" >&2; exit 2; }
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || { echo "test-slurm: --shards needs a whole number >= 1" >&2; exit 2; }
for tool in slurmctld slurmd munged sbatch sinfo; do
  command -v "$tool" >/dev/null || { echo "test-slurm: $tool missing: run scripts/setup.sh --slurm" >&2; exit 2; }
done
[ "$(id -u)" = 0 ] || { echo "test-slurm: run as root (slurmd and munged are started here)" >&2; exit 2; }

work=$(mktemp -d /tmp/physval-slurm.XXXXXX)
chmod 755 "$work"
started_munge=0
cleanup() {
  for pid_file in "$work/slurmd.pid" "$work/slurmctld.pid"; do
    [ -s "$pid_file" ] && kill "$(cat "$pid_file")" 2>/dev/null || true
  done
  if ((started_munge)) && [ -s /run/munge/munged.pid ]; then kill "$(cat /run/munge/munged.pid)" 2>/dev/null || true; fi
  sleep 1
  if [ "${KEEP:-0}" = 1 ]; then echo "test-slurm: kept $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT

# munge: the key the package made (or a new one), its run folder, the daemon.
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  if [ ! -s /etc/munge/munge.key ]; then
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
  fi
  chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key
  mkdir -p /run/munge && chown munge:munge /run/munge
  runuser -u munge -- /usr/sbin/munged --force 2>/dev/null || /usr/sbin/munged --force
  started_munge=1
  for _ in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.1; done
fi
munge -n | unmunge | grep -q Success || { echo "test-slurm: munge does not work" >&2; exit 1; }

# slurm.conf: one node (this machine), one partition; paths in $work.
node=$(hostname)
cpus=$(nproc)
mem_mb=$(( $(awk '/MemAvailable/ {print int($2 / 1024)}' /proc/meminfo) - 1024 ))
((mem_mb > 256)) || mem_mb=256
mkdir -p "$work/state" "$work/spool" "$work/logs"
cat >"$work/slurm.conf" <<CONF
ClusterName=physval
SlurmctldHost=$node
SlurmUser=root
SlurmdUser=root
SlurmctldPort=16817
SlurmdPort=16818
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobAcctGatherType=jobacct_gather/none
ReturnToService=2
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
NodeName=$node CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=physval Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$work/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 100); do
  sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed|allocated)' && break
  sleep 0.2
done
sinfo -h -o '%P %T %C' || true
sinfo -h -o %T | grep -qE '^(idle|mixed|allocated)' || {
  echo "test-slurm: the node did not come up; slurmctld.log and slurmd.log:" >&2
  tail -n 20 "$work/slurmctld.log" "$work/slurmd.log" >&2
  exit 1
}

# The array: task I runs shard I of N. A gate that fails (exit 1) is a result to merge;
# only exit 2 (bad input) or a crash fails the task. One core per task.
cat >"$work/shard.sh" <<'JOB'
#!/usr/bin/env bash
set -u
i=$SLURM_ARRAY_TASK_ID
n=$SLURM_ARRAY_TASK_COUNT
"$PHYSVAL" gate "${SUITE[@]}" --shard "$i/$n" -j 1 --no-cache --quiet --out "$WORK/shard-$i"
status=$?
echo "$status" >"$WORK/shard-$i.status"
[ "$status" -le 1 ]
JOB
chmod +x "$work/shard.sh"
# Arrays do not cross the environment: the suite goes as one line, split in the job.
sed -i 's|"${SUITE\[@\]}"|$SUITE_LINE|' "$work/shard.sh"
export PHYSVAL="$physval" WORK="$work" SUITE_LINE="${suite[*]}"
echo "test-slurm: sbatch --array=0-$((shards - 1)) (physval gate --shard I/$shards of ${suite[*]})"
sbatch --wait --array=0-$((shards - 1)) --cpus-per-task=1 --chdir="$work" --output="$work/logs/shard-%a.out" \
  --job-name=physval-shards "$work/shard.sh"

shard_dirs=()
for ((i = 0; i < shards; i++)); do
  cat "$work/logs/shard-$i.out"
  shard_dirs+=("$work/shard-$i")
done
merged_status=0
"$physval" merge "${shard_dirs[@]}" --out "$work/merged" --junit "$work/merged.xml" || merged_status=$?
single_status=0
"$physval" gate "${suite[@]}" -j "$cpus" --no-cache --quiet --out "$work/single" --junit "$work/single.xml" || single_status=$?

fail=0
"$here/scripts/compare-runs.sh" test-slurm "$work/single" "$work/single.xml" "$single_status" \
  "$work/merged" "$work/merged.xml" "$merged_status" || fail=1
if ((fail)); then
  echo "test-slurm: FAILED (KEEP=1 keeps $work)" >&2
  exit 1
fi
echo "test-slurm: ok: $shards Slurm array tasks merged = one run (exit status $single_status, JUnit, series)"
