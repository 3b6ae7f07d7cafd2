#!/usr/bin/env bash
# The GitHub Actions recipe (.github/workflows/physval.yml), tested here without GitHub:
# lays out the build job's artifact as upload-artifact/download-artifact would (the
# paths the workflow uploads, their common `build/` folder stripped), runs the shard
# job's and the merge job's `run:` steps as written in the file (matrix.shard and
# $SHARDS substituted) in a folder that looks like the checkout, and compares the merged
# results, JUnit file, series and exit status with a single `physval gate` of the same
# suite run from the build tree. A workflow that uploaded too little (an engine plugin
# left behind) gates fewer runs and fails here.
#
#   scripts/test-github-workflow.sh [BUILD_DIR]      (default: build)
set -euo pipefail

here=$(cd "$(dirname "$0")/.." && pwd)
build=$(realpath "${1:-$here/build}")
workflow="$here/.github/workflows/physval.yml"
[ -x "$build/physval" ] || { echo "test-github-workflow: no physval in $build (build it first)" >&2; exit 2; }

work=$(mktemp -d /tmp/physval-ghwf.XXXXXX)
trap '[ "${KEEP:-0}" = 1 ] && echo "test-github-workflow: kept $work" || rm -rf "$work"' EXIT

# The workflow's pieces, read from the file itself.
python3 - "$workflow" "$work" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
work = sys.argv[2]
def job(name):
    m = re.search(r"^  " + name + r":\n((?:    .*\n|\s*\n)*)", text, re.M)
    if not m:
        sys.exit(f"test-github-workflow: no job {name!r} in the workflow")
    return m.group(1)
def run_steps(body):
    steps, lines, i = [], body.split("\n"), 0
    while i < len(lines):
        m = re.match(r"^(\s*)- run: (.*)$", lines[i])
        if m:
            if m.group(2).strip() == "|":
                indent, block = None, []
                i += 1
                while i < len(lines) and (lines[i].strip() == "" or indent is None or lines[i].startswith(indent)):
                    if lines[i].strip() == "":
                        i += 1
                        continue
                    if indent is None:
                        indent = re.match(r"^\s*", lines[i]).group(0)
                        if len(indent) <= len(m.group(1)):
                            break
                    block.append(lines[i][len(indent):])
                    i += 1
                steps.append("\n".join(block))
                continue
            steps.append(m.group(2))
        i += 1
    return steps
def upload_paths(body):
    m = re.search(r"upload-artifact@\S+\n\s+with:\n(?:\s+name: .*\n)?\s+path: (\|\n((?:\s{12,}\S.*\n)+)|(.*)\n)", body)
    if not m:
        sys.exit("test-github-workflow: the build job uploads nothing")
    return [p.strip() for p in (m.group(2) or m.group(3)).split("\n") if p.strip()]
shards = int(re.search(r"^\s+SHARDS: (\d+)", text, re.M).group(1))
matrix = [int(s) for s in re.search(r"shard: \[([\d, ]+)\]", job("shard")).group(1).split(",")]
if matrix != list(range(shards)):
    sys.exit(f"test-github-workflow: matrix {matrix} is not 0..SHARDS-1 (SHARDS = {shards})")
gate = [s for s in run_steps(job("shard")) if "physval gate" in s]
merge = [s for s in run_steps(job("merge")) if "physval merge" in s]
if len(gate) != 1 or len(merge) != 1:
    sys.exit("test-github-workflow: want one gate step in the shard job and one merge step in the merge job")
open(f"{work}/shards", "w").write(str(shards))
open(f"{work}/uploads", "w").write("\n".join(upload_paths(job("build"))) + "\n")
open(f"{work}/gate.sh", "w").write(gate[0] + "\n")
open(f"{work}/merge.sh", "w").write(merge[0] + "\n")
PY
shards=$(cat "$work/shards")

# The build job's artifact: each uploaded path, `build/` -> the build folder, with the
# common `build/` prefix stripped as upload-artifact does.
mkdir -p "$work/artifact"
while read -r path; do
  [ -n "$path" ] || continue
  [[ "$path" == build/* ]] || { echo "test-github-workflow: uploaded path $path is not under build/" >&2; exit 1; }
  src="$build/${path#build/}"
  [ -e "$src" ] || { echo "test-github-workflow: the workflow uploads $path, which the build does not make" >&2; exit 1; }
  mkdir -p "$work/artifact/$(dirname "${path#build/}")"
  cp -r "$src" "$work/artifact/${path#build/}"
done <"$work/uploads"

# A checkout: the suite and the scripts, as actions/checkout gives them. No environment
# from ctest or the caller reaches the engines (a bundled-plugin folder set by ctest
# would hide a missing upload).
checkout() { mkdir -p "$1"; ln -s "$here/validation" "$1/validation"; ln -s "$here/scripts" "$1/scripts"; }
clean_env=(env -u PHYSVAL_BUNDLED_PLUGIN_DIR -u PHYSVAL_PLUGIN_PATH XDG_CACHE_HOME="$work/cache")

for ((i = 0; i < shards; i++)); do
  checkout "$work/shard-job-$i"
  cp -r "$work/artifact" "$work/shard-job-$i/bin"
  sed -e "s/\${{ matrix.shard }}/$i/g" "$work/gate.sh" >"$work/shard-job-$i/step.sh"
  (cd "$work/shard-job-$i" && SHARDS=$shards "${clean_env[@]}" bash -e step.sh) || {
    echo "test-github-workflow: shard $i's step failed" >&2; exit 1; }
done

checkout "$work/merge-job"
mkdir -p "$work/merge-job/artifacts"
cp -r "$work/artifact" "$work/merge-job/artifacts/physval"
for ((i = 0; i < shards; i++)); do cp -r "$work/shard-job-$i/shard-$i" "$work/merge-job/artifacts/shard-$i"; done
merged_status=0
(cd "$work/merge-job" && SHARDS=$shards "${clean_env[@]}" bash -e ../merge.sh) || merged_status=$?

single_status=0
(cd "$here" && "${clean_env[@]}" "$build/physval" gate validation/scenarios --quiet --out "$work/single" \
   --junit "$work/single.xml") || single_status=$?

"$here/scripts/compare-runs.sh" test-github-workflow "$work/single" "$work/single.xml" "$single_status" \
  "$work/merge-job/merged" "$work/merge-job/merged/junit.xml" "$merged_status" || {
  echo "test-github-workflow: FAILED (KEEP=1 keeps $work)" >&2; exit 1; }
[ -s "$work/merge-job/merged/report.html" ] || { echo "test-github-workflow: the merge step wrote no report" >&2; exit 1; }
echo "test-github-workflow: ok: the workflow's $shards shards merged = one gate from the build tree (exit status $single_status)"
