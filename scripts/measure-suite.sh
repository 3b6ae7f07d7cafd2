#!/usr/bin/env bash
# The README's scale figures, measured side by side in one run (README, "Running at
# scale"): the built-in suite at -j 1 and -j 2, without and with a warm reference cache,
# and memory per body on a generated 100k-circle gas. Prints a Markdown table.
#
#   scripts/measure-suite.sh [--physval EXE] [--bodies N] [--steps S]
#
# Defaults: build/physval, 100000 bodies, 60 steps. Wall time, user+sys CPU of physval
# and its children, and the largest max RSS among them (GNU time). Run it on an idle
# machine: the load average is printed before and after.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
physval="$here/build/physval"
bodies=100000
steps=60
while (($#)); do
  case "$1" in
    --physval) physval=$2; shift 2 ;;
    --bodies) bodies=$2; shift 2 ;;
    --steps) steps=$2; shift 2 ;;
    -h|--help) sed -n '2,10p' "$0"; exit 0 ;;
    *) echo "measure-suite: unknown argument $1" >&2; exit 2 ;;
  esac
done
physval=$(realpath "$physval")
[ -x /usr/bin/time ] || { echo "measure-suite: needs GNU time (apt-get install time)" >&2; exit 2; }
work=$(mktemp -d /tmp/physval-measure.XXXXXX)
trap 'rm -rf "$work"' EXIT
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores, $("$physval" --version 2>/dev/null | head -1)"

# One measured command: wall s, CPU s (user+sys, children included), max RSS MB.
measure() {
  local label=$1; shift
  /usr/bin/time -f "%e %U %S %M" -o "$work/time" "$@" >"$work/out" 2>&1 || true
  read -r wall user sys rss <"$work/time"
  printf '| %s | %.2f s | %.2f s | %.0f MB |\n' "$label" "$wall" "$(echo "$user + $sys" | bc -l)" "$(echo "$rss / 1024" | bc -l)"
}
stepping() {   # the engines' stepping wall time summed over a results.json
  python3 -c 'import json,sys; print("%.2f" % sum(r.get("wall_seconds") or 0 for r in json.load(open(sys.argv[1]))["runs"]))' "$1"
}

suite="$here/validation/scenarios"
echo
echo "Built-in suite (\`physval run validation/scenarios --quiet\`), one run each:"
echo
echo "| | wall | user+sys CPU (with children) | max RSS |"
echo "|---|---|---|---|"
measure '`-j 1 --no-cache`' "$physval" run "$suite" --quiet -j 1 --no-cache --out "$work/j1"
measure '`-j 2 --no-cache`' "$physval" run "$suite" --quiet -j 2 --no-cache --out "$work/j2"
"$physval" run "$suite" --quiet -j 2 --cache "$work/cache" --out "$work/fill" >/dev/null 2>&1 || true
measure '`-j 1`, warm cache' "$physval" run "$suite" --quiet -j 1 --cache "$work/cache" --out "$work/c1"
measure '`-j 2`, warm cache' "$physval" run "$suite" --quiet -j 2 --cache "$work/cache" --out "$work/c2"
echo
echo "Engines' stepping, summed wall_seconds of the runs: $(stepping "$work/j1/results.json") s at -j 1 (uncached), $(stepping "$work/c1/results.json") s at -j 1 (warm cache)."

python3 - "$bodies" "$steps" "$work/gas.toml" <<'PY'
import math, random, sys
n, steps, path = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
side = math.ceil(math.sqrt(n)); spacing = 0.25; half = side * spacing / 2 + 0.5
out = [f'name = "gas_{n}"\ndt = 0.0166666666666666667\nduration = {steps / 60.0!r}\n[core]\nbroadphase = "grid"\n']
for k, (a, b, c, d) in enumerate([(-half, -half, -half, half), (half, -half, half, half), (-half, -half, half, -half), (-half, half, half, half)]):
    out.append(f'[[walls]]\nname = "w{k}"\nfrom = [{a!r}, {b!r}]\nto = [{c!r}, {d!r}]\n')
rng = random.Random(7)
for i in range(n):
    x = (i % side) * spacing - half + 0.5 + spacing / 2
    y = (i // side) * spacing - half + 0.5 + spacing / 2
    out.append(f'[[bodies]]\nname = "c{i}"\nradius = 0.05\nposition = [{x!r}, {y!r}]\nvelocity = [{rng.uniform(-1, 1)!r}, {rng.uniform(-1, 1)!r}]\n')
open(path, "w").write("".join(out))
PY
echo
echo "Memory, a generated ${bodies}-circle gas in a walled box, $steps steps of 1/60 s:"
echo
echo "| | wall | user+sys CPU | max RSS | per body |"
echo "|---|---|---|---|---|"
for what in check run; do
  if [ $what = check ]; then cmd=("$physval" check "$work/gas.toml"); label='`physval check` (loading)'
  else cmd=("$physval" run "$work/gas.toml" --engines core -j 1 --no-cache --quiet --out "$work/gas"); label='`physval run --engines core -j 1 --no-cache`'; fi
  /usr/bin/time -f "%e %U %S %M" -o "$work/time" "${cmd[@]}" >"$work/out" 2>&1 || true
  read -r wall user sys rss <"$work/time"
  printf '| %s | %.1f s | %.1f s | %.0f MB | %.2f kB |\n' "$label" "$wall" "$(echo "$user + $sys" | bc -l)" \
    "$(echo "$rss / 1024" | bc -l)" "$(echo "$rss * 1.024 / $bodies" | bc -l)"
done
echo
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
