#!/usr/bin/env bash
# Harness overhead per scenario (README "Running at scale", "Harness overhead"): runs
# `physval run -j 1 --overhead FILE` on the given scenarios (default: the built-in suite)
# and prints, for every scene whose engines step for more than 0.1 s of CPU (all scenes
# with --all), the engines' stepping, the harness's CPU beyond it and their ratio, then
# the suite's sum. The references are not overhead and are shown apart.
#
#   scripts/overhead.sh [--all] [--physval PATH] [--keep DIR] [PATH...] [-- physval options]
#
# -j 1 so that each figure is one process's own; run it on an idle machine (the load
# average is printed before and after). The output goes to a folder made by mktemp
# (TMPDIR=/dev/shm puts it on tmpfs). Needs python3.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
physval="$here/build/physval"
all=0
keep=""
paths=()
extra=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --all) all=1; shift ;;
    --physval) physval="$2"; shift 2 ;;
    --keep) keep="$2"; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    *) paths+=("$1"); shift ;;
  esac
done
[[ ${#paths[@]} -gt 0 ]] || paths=("$here/validation/scenarios")
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
# The series and scene files are created here (TMPDIR, else /tmp): their creation is part of
# the harness's CPU, and on an ext4 without a journal it depends on how many files were
# deleted there in the last minutes (README "Harness overhead", ninth pass).
echo "output folder: $work ($(stat -f -c %T "$work" 2>/dev/null || echo unknown))"
status=0
"$physval" run "${paths[@]}" -j 1 --quiet --out "$work/out" --overhead "$work/overhead.json" "${extra[@]}" || status=$?
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"
if [[ ! -f "$work/overhead.json" ]]; then
  echo "overhead.sh: physval wrote no overhead file (exit status $status)" >&2
  exit 2
fi
[[ -z "$keep" ]] || { mkdir -p "$keep"; cp -r "$work/out" "$work/overhead.json" "$keep/"; }
ALL=$all python3 - "$work/overhead.json" <<'PY'
import json, os, sys
d = json.load(open(sys.argv[1]))
show_all = os.environ.get("ALL") == "1"
head = f"{'scenario':28s} {'runs':>4s} {'step wall':>10s} {'step CPU':>9s} {'runs':>7s} {'compare':>8s} {'write':>7s} {'overhead':>9s} {'%':>7s} {'reference':>10s}"
print(head)
print("-" * len(head))
def pct(v):
    return f"{v:6.1f}%" if v is not None else "     -"
for s in sorted(d["scenarios"], key=lambda s: -s["stepping_cpu_seconds"]):
    if not show_all and s["stepping_cpu_seconds"] <= 0.1:
        continue
    print(f"{s['scenario'][:28]:28s} {s['runs']:4d} {s['stepping_wall_seconds']:9.3f}s {s['stepping_cpu_seconds']:8.3f}s "
          f"{s['runs_harness_cpu_seconds']:6.3f}s {s['compare_cpu_seconds']:7.3f}s {s['write_cpu_seconds']:6.3f}s "
          f"{s['overhead_cpu_seconds']:8.3f}s {pct(s['overhead_percent'])} {s['reference_cpu_seconds']:9.3f}s")
u = d["suite"]
print("-" * len(head))
print(f"{'suite (' + str(len(d['scenarios'])) + ' scenarios)':28s} {'':4s} {u['stepping_wall_seconds']:9.3f}s {u['stepping_cpu_seconds']:8.3f}s "
      f"{'':7s} {'':8s} {'':7s} {u['overhead_cpu_seconds']:8.3f}s {pct(u['overhead_percent'])} {u['reference_cpu_seconds']:9.3f}s")
print(f"  of which not charged to a scenario (start, loading, table): {u['unattributed_cpu_seconds']:.3f}s; "
      f"physval and children in all: {u['process_cpu_seconds']:.3f}s CPU")
PY
exit $status
