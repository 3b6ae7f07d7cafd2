#!/usr/bin/env bash
# Compares two physval output folders as the scale-out recipes promise: results.json equal
# apart from timings, the JUnit files equal apart from times, the series/ folders byte for
# byte, and the two exit statuses equal. Used by scripts/test-slurm.sh and
# scripts/test-github-workflow.sh.
#
#   scripts/compare-runs.sh NAME SINGLE_DIR SINGLE_JUNIT SINGLE_STATUS MERGED_DIR MERGED_JUNIT MERGED_STATUS
set -uo pipefail
name=$1 single=$2 single_xml=$3 single_status=$4 merged=$5 merged_xml=$6 merged_status=$7
fail=0
if [ "$merged_status" != "$single_status" ]; then
  echo "$name: DIFFERENT exit status: merged $merged_status, single $single_status" >&2
  fail=1
fi
python3 - "$name" "$single/results.json" "$merged/results.json" <<'PY' || fail=1
import json, sys
name = sys.argv[1]
# Timings and the machine context differ from run to run; everything else must not.
def timing(key):
    return key in ("wall_seconds", "load_seconds", "context") or key.endswith("cpu_seconds") or key.startswith("harness")
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if not timing(k)}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
single, merged = (strip(json.load(open(p))) for p in sys.argv[2:4])
if single != merged:
    for key in sorted(set(single) | set(merged)):
        if single.get(key) != merged.get(key):
            print(f"{name}: results.json differ in {key!r}", file=sys.stderr)
    sys.exit(1)
print(f"{name}: results.json equal apart from timings ({len(single['runs'])} runs)")
PY
if ! diff <(sed -E 's/ (time|timestamp)="[^"]*"//g' "$single_xml") \
          <(sed -E 's/ (time|timestamp)="[^"]*"//g' "$merged_xml") >/dev/null; then
  echo "$name: DIFFERENT JUnit files" >&2
  fail=1
fi
if ! diff -r "$single/series" "$merged/series" >/dev/null; then
  echo "$name: DIFFERENT series/" >&2
  fail=1
fi
exit $fail
