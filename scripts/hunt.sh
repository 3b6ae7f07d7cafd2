#!/usr/bin/env bash
# The hunt for wrong greens: writes grids of scenes a user would write, runs them through
# `physval run` on every engine, and holds each run's verdict against an oracle from
# physics (closed forms, symmetry, a run's own final state). Prints every wrong green
# (physval said `ok` while the physics is wrong) and every case where core, the
# reference, is wrong; exits 1 when it finds any, 0 when none, 2 on a usage error.
#
#   scripts/hunt.sh [BUILD_DIR] [-j N]      (default: build, every core)
#
# Grids (README, *The hunt for wrong greens*):
#   through   a fast ball or point (30-300 m/s) meets a resting ball: through it within a step
#   onfloor   a point starting on a floor (0 to 1e-3 m above it) under g; on it: bad input
#   apex      a 10 m drop expected back up at 10 m (met at t = 0): bad input
#   wide      a 10 m drop onto floors 2 m to 20 km wide: the energy drift must not change
#   vtrough   a ball into a symmetric V (half-angle 50-85 deg, e 0/0.3/0.7, both wall orders)
#   headon    head-on pairs, mass ratios 1e-6..1e6, e 0/0.5/1, sizes 1 mm..1 km, with their
#             closed forms as [expect]: core must meet them; no engine may pass a 10% miss
set -euo pipefail
build=build
jobs=$(nproc)
while (($#)); do
  case "$1" in
    -j) jobs="$2"; shift 2 ;;
    -h|--help) sed -n 2,18p "$0"; exit 0 ;;
    *) build="$1"; shift ;;
  esac
done
physval="$build/physval"
[ -x "$physval" ] || { echo "hunt: no $physval (build first, or give the build folder)" >&2; exit 2; }
work=$(mktemp -d /tmp/physval-hunt.XXXXXX)
trap 'rm -rf "$work"' EXIT
engines=$("$physval" engines --json | python3 -c 'import json,sys; print(",".join(e["name"] for e in json.load(sys.stdin)))')
echo "hunt: engines $engines, scenes in $work"

python3 - "$work/scenes" <<'EOF'
import math, os, sys
out = sys.argv[1]
os.makedirs(out, exist_ok=True)
def write(name, text):
    open(os.path.join(out, name + ".toml"), "w").write(text)

# through: shot (circle r 0.05 or point) at speed v towards a resting 0.5 m ball.
for shape in ["circle", "point"]:
    for v in [30, 60, 100, 150, 300]:
        for steps in [60, 30]:
            for off in [0.0, 0.02]:
                n = f"through_{shape}_{v}_{steps}_{int(off*100)}"
                body = 'shape = "point"' if shape == "point" else "radius = 0.05"
                write(n, f'''name = "{n}"
duration = 0.5
dt = "1/{steps}"
[[bodies]]
name = "shot"
{body}
mass = 0.01
position = [-3.0, {off}]
velocity = [{v}.0, 0.0]
[[bodies]]
name = "target"
radius = 0.5
mass = 1.0
position = [0.0, 0.0]
''')

# onfloor: a point on a floor, at rest or moving into it, e = 0. On the line to round-off
# (no side) it is bad input: those go to a folder of their own, which `check` must refuse.
for i, y in enumerate(["0.0", "1e-15", "1e-9", "1e-6", "1e-3"]):
    for vy in ["0.0", "-1.0"]:
        n = f"onfloor_{i}_{'still' if vy == '0.0' else 'down'}"
        if float(y) < 1e-12:
            n = "refuse_" + n
        write(n, f'''name = "{n}"
description = "y0 = {y}"
duration = 1.0
dt = "1/60"
[world]
gravity = [0.0, -9.81]
[[bodies]]
name = "p"
shape = "point"
position = [0.0, {y}]
velocity = [0.0, {vy}]
restitution = 0.0
[[walls]]
name = "floor"
from = [-5.0, 0.0]
to = [5.0, 0.0]
''')

# An apex the start already meets (a 10 m drop expected back at 10 m): bad input.
for h in ["10.0", "10.0005"]:
    n = f"refuse_apex_{h.replace('.', 'p')}"
    write(n, f'''name = "{n}"
duration = 4.0
[world]
gravity = [0.0, -9.81]
[[bodies]]
name = "ball"
radius = 0.5
position = [0.0, 10.0]
[[walls]]
name = "floor"
from = [-5.0, -0.5]
to = [5.0, -0.5]
[ode]
restitution_threshold = 20.0
[expect]
apex = [ {{ body = "ball", height = {h} }} ]
''')

# wide: the same 10 m drop onto floors of several widths.
for w in [1, 5, 100, 10000]:
    n = f"wide_{w}"
    write(n, f'''name = "{n}"
duration = 4.5
dt = "1/60"
[world]
gravity = [0.0, -9.8]
[[bodies]]
name = "ball"
radius = 0.5
position = [0.0, 10.0]
[[walls]]
name = "floor"
from = [-{w}.0, 0.0]
to = [{w}.0, 0.0]
''')

# vtrough: a ball meets both faces of a symmetric V at once.
for deg in [50, 60, 65, 68, 70, 75, 80, 85]:
    for e in [0.0, 0.3, 0.7]:
        for order in [0, 1]:
            a = math.radians(deg)
            faces = [("left", -1), ("right", 1)][::(-1 if order else 1)]
            walls = "".join(f'''[[walls]]
name = "{nm}"
from = [0.0, 0.0]
to = [{s * 10 * math.sin(a)!r}, {10 * math.cos(a)!r}]
restitution = {e}
''' for nm, s in faces)
            n = f"vtrough_{deg}_{int(e*10)}_{order}"
            write(n, f'''name = "{n}"
duration = 3.0
dt = "1/60"
engines = ["core"]
[world]
gravity = [0.0, -9.81]
[[bodies]]
name = "b"
radius = 0.5
position = [0.0, {0.5 / math.sin(a) + 2.0!r}]
velocity = [0.0, -2.0]
restitution = {e}
{walls}''')

# headon: closed-form velocities after one head-on impact, at many scales.
for k, ratio in enumerate([1e-6, 1e-3, 1.0, 1e3, 1e6]):
    for e in [0.0, 0.5, 1.0]:
        for scale in [1e-3, 1.0, 1e3]:
            m1, m2 = 1.0, ratio
            u1, u2 = 2.0 * scale, -1.0 * scale
            r = 0.5 * scale
            v1 = (m1 * u1 + m2 * u2 - m2 * e * (u1 - u2)) / (m1 + m2)
            v2 = (m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2)
            n = f"headon_{k}_{int(e*10)}_{int(round(math.log10(scale)))+3}"
            tol = 1e-6 * max(abs(u1), abs(u2))
            write(n, f'''name = "{n}"
description = "m2/m1 = {ratio}, e = {e}, scale {scale} m"
duration = {3.0!r}
dt = "1/600"
[[bodies]]
name = "a"
radius = {r!r}
mass = {m1!r}
position = [{-2.0 * scale!r}, 0.0]
velocity = [{u1!r}, 0.0]
restitution = {e}
[[bodies]]
name = "b"
radius = {r!r}
mass = {m2!r}
position = [{2.0 * scale!r}, 0.0]
velocity = [{u2!r}, 0.0]
restitution = {e}
[expect]
final = [ {{ body = "a", velocity = [{v1!r}, 0.0], tolerance = {tol!r} }},
          {{ body = "b", velocity = [{v2!r}, 0.0], tolerance = {tol!r} }} ]
''')
EOF

mkdir -p "$work/refuse"
mv "$work"/scenes/refuse_*.toml "$work/refuse/"
bad=0
for f in "$work"/refuse/*.toml; do
  set +e
  "$physval" check "$f" > "$work/check.txt" 2>&1
  s=$?
  set -e
  if [ "$s" != 2 ] || ! grep -q "$(basename "$f"):[0-9]*:[0-9]*: " "$work/check.txt"; then
    echo "WRONG GREEN $(basename "$f" .toml): bad input accepted (check exit $s)"
    bad=1
  fi
done
set +e
"$physval" run "$work/scenes" --engines "$engines" --out "$work/out" -j "$jobs" --quiet --no-cache > "$work/run.txt" 2>&1
status=$?
set -e
if [ "$status" -ge 2 ]; then cat "$work/run.txt" >&2; echo "hunt: physval run exited $status" >&2; exit 2; fi

set +e
python3 - "$work/out/results.json" "$work/scenes" <<'EOF'
import json, math, re, sys
runs = json.load(open(sys.argv[1]))["runs"]
found = []
def green(r):
    return r["status"] == "ok" or r.get("known_divergence")
def final(r, i):
    return r["final"][i]
drift = {}
for r in runs:
    sc, eng = r["scenario"], r["engine"]
    if r["status"] in ("unsupported", "error"):
        continue
    if sc.startswith("through_"):
        if green(r) and final(r, 0)["position"][0] > final(r, 1)["position"][0]:
            found.append(f"WRONG GREEN {sc} {eng}: the shot ended beyond the target (went through it), status {r['status']}")
        if eng == "core" and final(r, 0)["position"][0] > final(r, 1)["position"][0]:
            found.append(f"CORE WRONG {sc}: the shot went through the target")
    elif sc.startswith("onfloor_"):
        y = final(r, 0)["position"][1]
        if y < -1e-6 and green(r):
            found.append(f"WRONG GREEN {sc} {eng}: the point ended {y:.3g} m below the floor it started on, status {r['status']}")
        if eng == "core" and y < -1e-6:
            found.append(f"CORE WRONG {sc}: core let the point through the floor (y = {y:.3g} m)")
    elif sc.startswith("wide_"):
        d = r["metrics"].get("energy_drift")
        if d is not None:
            drift.setdefault(eng, {})[int(sc.split("_")[1])] = d
    elif sc.startswith("vtrough_") and eng == "core":
        x, vx = final(r, 0)["position"][0], final(r, 0)["velocity"][0]
        if abs(x) > 1e-6 or abs(vx) > 1e-6:
            found.append(f"CORE WRONG {sc}: a symmetric scene ends at x = {x:.3g} m, vx = {vx:.3g} m/s "
                         f"(status {r['status']}; the mirror order gives the mirror answer)")
    elif sc.startswith("headon_"):
        misses = [c for c in r["checks"] if c["what"].startswith("expect.")]
        if eng == "core" and any(not c["pass"] for c in misses):
            found.append(f"CORE WRONG {sc}: misses its closed form: " +
                         "; ".join(f"{c['what']} off by {c['value']}" for c in misses if not c["pass"]))
        # No run may pass while a final velocity is 10% (of the approach speed) off the closed form.
        for c in misses:
            if c["pass"] and c["value"] is not None and c["value"] > 0.1 * c["limit"] / 1e-6:
                found.append(f"WRONG GREEN {sc} {eng}: {c['what']} off by {c['value']:.3g} passed")
for eng, by_width in drift.items():
    base = by_width.get(1)
    for w, d in sorted(by_width.items()):
        if base and base > 1e-12 and abs(d / base - 1.0) > 0.01:
            found.append(f"WRONG SCALE wide_{w} {eng}: energy_drift {d:.3g} against {base:.3g} on a 2 m floor "
                         f"(the same motion)")
for f in found:
    print(f)
print(f"hunt: {len(runs)} runs, {len(found)} findings")
sys.exit(1 if found else 0)
EOF
found=$?
set -e
[ "$found" -le 1 ] || exit 2
exit $((found | bad))
