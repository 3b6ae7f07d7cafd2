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
#   floorslide, settle, slope, edge   one body's closed form (friction stop, bounces to rest,
#             held or sliding on a slope drawn three ways, sliding off a table's end): core
#             must meet it to 1e-6 or better
#   kink      concave and convex kinks of a track (two walls or a surface): core to 1e-7
#   inclinebounce, pointsettle   a bounce with friction on a slope, a point bouncing to rest
#   train     two balls sliding as one train (or apart) to a stop on a floor: core to 1e-8
#   catch     a ball catching another (or two touching ones) down a slope, then one block: core to 1e-8
#   draglin, dragquad, thrust, dragwall   the converged reference must meet the closed form
#   every closed-form run: an engine's position_divergence must see its miss
#   box       a point or a ball at 5-5000 m/s in a box of walls (0.3-20 m), axis, 17 deg and
#             corners, with and without gravity: core never leaves, no engine is ok outside it
#   junction  a point or a ball sliding across a floor drawn in pieces (walls or a surface,
#             level or tilted): core to 1e-8
#   particles particles (5-500 m/s) bouncing in a closed box: none may end outside
#   tiny      a 1 cm ball at 100-300 m/s off-centre through a resting 1 m ball
#   stiffdrag a ball against quadratic drag too stiff for the reference's step: a converged
#             reference must never go backwards (scripts/hunt5.py: the fifth hunt's grids)
#   hunt6     scripts/hunt6.py --quick (the sixth hunt's families, small grids): two balls in a
#             field passing through each other within a step, particles near a moving ball,
#             drag towards a diagonal wind, thrust tables at their ends, three-body orbits,
#             core's broad phases, bodies touching at t = 0
#   hunt7     scripts/hunt7.py --quick (the seventh hunt's families, small grids): particles in a
#             closed box in core's exact and lecture modes, grazes across the escape rule's
#             half radius, long runs and step limits, mass ratios touching at t = 0
#   hunt8     scripts/hunt8.py --quick (the eighth hunt's families, small grids): thrust and wind
#             with friction on a floor (the normal force from the thrust or the drag), radial
#             infall under Newtonian gravity with impacts, drops at radii 1e-4-1e4 m, passes
#             by a box's corner, a surface's tip or a wall's end, balls off a ledge
#   hunt10    scripts/hunt10.py --quick (the tenth hunt's families, small grids): Kepler orbits
#             grazing a planet, softened gravity, restitution above 1, static friction given by
#             [[materials]], scenes 1e6 m from the origin
#   hunt12    scripts/hunt12.py --quick (the twelfth hunt's families, small grids): thrust and
#             gravity against a rotated wall with friction, drag on slopes and through bounces,
#             rotated boxes, static circles, symmetric simultaneous impacts, a speed-dependent
#             thrust table into a wall, Newtonian gravity onto a wall
set -euo pipefail
build=build
jobs=$(nproc)
while (($#)); do
  case "$1" in
    -j) jobs="$2"; shift 2 ;;
    -h|--help) sed -n 2,42p "$0"; exit 0 ;;
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

# Closed forms for the models one body at a time (truth.json: the exact final state, and
# the tolerance core, the reference, must meet it to). Found by this grid: `edge`.
truth = {}
g = 9.8
def materials(pairs):
    """[[materials]] tables, one per (a, b, friction)."""
    return "".join(f"""[[materials]]
a = "{a}"
b = "{b}"
friction = {mu}
""" for a, b, mu in pairs)

def exact(name, text, pos, vel, tol, judge="core"):
    write(name, text)
    truth[name] = {"position": pos, "velocity": vel, "tol": tol, "judge": judge}

# floorslide: a ball sliding on a floor, kinetic or rolling friction mu: decelerated by
# mu g until it stops at v0^2 / (2 mu g) (T before and after the stop).
for kind in ["friction", "rolling_friction"]:
    for v0 in [0.5, 3.0, 12.0]:
        for mu in [0.05, 0.3, 1.0]:
            for frac in [0.6, 1.5]:
                for steps in [60, 240]:
                    ts = v0 / (mu * g)
                    t = min(frac * ts, ts)
                    x, v = v0 * t - 0.5 * mu * g * t * t, (v0 - mu * g * t if frac < 1 else 0.0)
                    n = f"floorslide_{kind[0]}_{v0}_{mu}_{frac}_{steps}".replace(".", "p")
                    exact(n, f"""name = "{n}"
duration = {frac * ts!r}
dt = "1/{steps}"
[world]
gravity = [0.0, -{g}]
[[bodies]]
name = "b"
radius = 0.5
position = [0.0, 0.5]
velocity = [{v0}, 0.0]
restitution = 0.0
{kind} = {mu}
[[walls]]
name = "floor"
from = [-200.0, 0.0]
to = [200.0, 0.0]
restitution = 0.0
{kind} = {mu}
""", [x, 0.5], [v, 0.0], 1e-7 * max(1.0, x))

# settle: a drop from h with restitution e, before and after it comes to rest
# (t_inf = sqrt(2h/g) (1+e)/(1-e)): the bounces' closed form at T.
def bounce_state(h, e, T):
    t = math.sqrt(2 * h / g)
    if T <= t:
        return h - 0.5 * g * T * T, -g * T
    v = e * g * t
    while v > 1e-12:
        if T <= t + 2 * v / g:
            s = T - t
            return v * s - 0.5 * g * s * s, v - g * s
        t += 2 * v / g
        v *= e
    return 0.0, 0.0
for h in [0.3, 2.0, 10.0]:
    for e in [0.0, 0.3, 0.6, 0.9]:
        tinf = math.sqrt(2 * h / g) * (1 + e) / (1 - e)
        for frac in [0.37, 0.93, 1.3]:
            for steps in [60, 1000]:
                y, vy = bounce_state(h, e, frac * tinf)
                n = f"settle_{h}_{e}_{frac}_{steps}".replace(".", "p")
                exact(n, f"""name = "{n}"
duration = {frac * tinf!r}
dt = "1/{steps}"
[world]
gravity = [0.0, -{g}]
[[bodies]]
name = "b"
radius = 0.25
position = [1.0, {h + 0.25!r}]
restitution = {e}
[[walls]]
name = "floor"
from = [-20.0, 0.0]
to = [20.0, 0.0]
restitution = {e}
""", [1.0, y + 0.25], [0.0, vy], 1e-7 * max(1.0, h))

# drag: linear drag with a wind (across) and quadratic drag (a fall): the converged
# reference must meet the closed forms (core's own step is second order).
for m in [0.5, 2.0]:
    for k in [0.1, 1.0, 5.0]:
        c, T, wx, v0x = k / m, 3.0, 3.0, -1.0
        vt = g / c
        n = f"draglin_{m}_{k}".replace(".", "p")
        exact(n, f"""name = "{n}"
duration = {T}
[world]
gravity = [0.0, -{g}]
wind = [{wx}, 0.0]
[[bodies]]
name = "b"
radius = 0.1
mass = {m}
position = [0.0, 100.0]
velocity = [{v0x}, 0.0]
drag_linear = {k}
""", [wx * T + (v0x - wx) * (1 - math.exp(-c * T)) / c, 100.0 - vt * (T - (1 - math.exp(-c * T)) / c)],
              [wx + (v0x - wx) * math.exp(-c * T), -vt * (1 - math.exp(-c * T))], 1e-8 * 100, "reference")
    for k2 in [0.01, 0.1, 1.0]:
        T = 3.0
        vt = math.sqrt(m * g / k2)
        n = f"dragquad_{m}_{k2}".replace(".", "p")
        exact(n, f"""name = "{n}"
duration = {T}
[world]
gravity = [0.0, -{g}]
[[bodies]]
name = "b"
radius = 0.1
mass = {m}
position = [0.0, 100.0]
drag_quadratic = {k2}
""", [0.0, 100.0 - vt * vt / g * math.log(math.cosh(g * T / vt))], [0.0, -vt * math.tanh(g * T / vt)],
              1e-8 * 100, "reference")

# slope: a ball at rest on a slope (a wall drawn down or up, or a surface), mu_k = 0.75
# mu_s: held iff tan(theta) <= mu_s, else a = g (sin - mu_k cos).
for deg in [10, 20, 30, 45, 60]:
    for mus in [0.2, 0.5, 0.8]:
        for how in ["wall", "wallrev", "surface"]:
            muk, th, T, L, r = 0.75 * mus, math.radians(deg), 1.5, 40.0, 0.5
            d = (math.cos(th), -math.sin(th))
            p0 = (math.sin(th) * r, math.cos(th) * r)
            a = 0.0 if math.tan(th) <= mus else g * (math.sin(th) - muk * math.cos(th))
            s = 0.5 * a * T * T
            A, B = (-L * d[0], -L * d[1]), (L * d[0], L * d[1])
            if how == "wallrev":
                A, B = B, A
            mat = f"friction = {muk}\nstatic_friction = {mus}\nrestitution = 0.0\n"
            if how == "surface":   # faces the left of its point order: downhill, left is up
                geo = f"[[surfaces]]\nname = \"slope\"\npoints = [[{A[0]!r}, {A[1]!r}], [{B[0]!r}, {B[1]!r}]]\n" + mat
            else:
                geo = f"[[walls]]\nname = \"slope\"\nfrom = [{A[0]!r}, {A[1]!r}]\nto = [{B[0]!r}, {B[1]!r}]\n" + mat
            n = f"slope_{deg}_{mus}_{how}".replace(".", "p")
            exact(n, f"""name = "{n}"
duration = {T}
[world]
gravity = [0.0, -{g}]
[[bodies]]
name = "b"
radius = {r}
position = [{p0[0]!r}, {p0[1]!r}]
{mat}{geo}""", [p0[0] + s * d[0], p0[1] + s * d[1]], [a * T * d[0], a * T * d[1]], 1e-6)

# thrust: a(v) = a0 - k v from a two-point table along a heading: v = (a0/k)(1 - e^-kt).
for a0 in [1.0, 5.0]:
    for kk in [0.2, 1.0]:
        for deg in [0, 37]:
            th, T, vinf = math.radians(deg), 4.0, a0 / kk
            v = vinf * (1 - math.exp(-kk * T))
            s = vinf * (T - (1 - math.exp(-kk * T)) / kk)
            n = f"thrust_{a0}_{kk}_{deg}".replace(".", "p")
            exact(n, f"""name = "{n}"
duration = {T}
[[bodies]]
name = "b"
radius = 0.5
position = [0.0, 0.0]
angle = {th!r}
[bodies.thrust]
speeds = [0.0, 40.0]
accel = [{a0}, {a0 - kk * 40.0!r}]
""", [s * math.cos(th), s * math.sin(th)], [v * math.cos(th), v * math.sin(th)], 1e-7 * max(1.0, s), "reference")

# edge: a ball sliding off a table's end (v^2 >= g r: it flies off at once on the
# projectile's path; the friction decelerates it up to the end). Slower ones turn about
# the end point (core rides the corner's cap since branch corner2: judged against the
# turn's closed form in core/tests/table_edge_test.cpp and convex_corner_test.cpp).
for v0 in [2.5, 3.0, 5.0]:
    for mu in [0.0, 0.1, 0.3]:
        for steps in [60, 240]:
            for off in [0.0, 0.013]:
                r, x0 = 0.5, -(1.0 + off)
                vc2 = v0 * v0 - 2 * mu * g * abs(x0)
                if vc2 < 1.02 * g * r:
                    continue
                vc = math.sqrt(vc2)
                te = (v0 - vc) / (mu * g) if mu > 0 else abs(x0) / v0
                s = 0.4
                n = f"edge_{v0}_{mu}_{steps}_{int(off * 1000)}".replace(".", "p")
                exact(n, f"""name = "{n}"
duration = {te + s!r}
dt = "1/{steps}"
[world]
gravity = [0.0, -{g}]
[[bodies]]
name = "b"
radius = {r}
position = [{x0}, {r}]
velocity = [{v0}, 0.0]
restitution = 0.0
friction = {mu}
[[walls]]
name = "table"
from = [-10.0, 0.0]
to = [0.0, 0.0]
restitution = 0.0
friction = {mu}
""", [vc * s, r - 0.5 * g * s * s], [vc, -g * s], 1e-8)
# dragwall: linear drag (and a wind) through a wall impact: the converged reference meets
# the piecewise closed form (the impact time by bisection on it).
def lin(x0, v0, c, acc, t):   # v' = acc - c v
    vt = acc / c
    return x0 + vt * t + (v0 - vt) * (1 - math.exp(-c * t)) / c, vt + (v0 - vt) * math.exp(-c * t)
for k in [0.05, 0.5, 2.0]:
    for e in [0.5, 1.0]:
        for wind in [0.0, -2.0]:
            c, r, xw = k, 0.2, 5.0
            if lin(0.0, 8.0, c, c * wind, 5.0)[0] < xw - r:
                continue   # the drag stops it short of the wall
            lo, hi = 0.0, 5.0
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if lin(0.0, 8.0, c, c * wind, mid)[0] < xw - r else (lo, mid)
            x1, vx1 = lin(0.0, 8.0, c, c * wind, hi)
            y1, vy1 = lin(5.0, 2.0, c, -g, hi)
            x2, vx2 = lin(x1, -e * vx1, c, c * wind, 0.5)
            y2, vy2 = lin(y1, vy1, c, -g, 0.5)
            n = f"dragwall_{k}_{e}_{int(-wind)}".replace(".", "p")
            exact(n, f"""name = "{n}"
duration = {hi + 0.5!r}
[world]
gravity = [0.0, -{g}]
wind = [{wind}, 0.0]
[[bodies]]
name = "b"
radius = {r}
position = [0.0, 5.0]
velocity = [8.0, 2.0]
restitution = {e}
drag_linear = {k}
[[walls]]
name = "wall"
from = [{xw}, -20.0]
to = [{xw}, 20.0]
restitution = {e}
""", [x2, y2], [vx2, vy2], 1e-8, "reference")

# kink: a ball sliding (frictionless, e 0) into an upward ramp (concave: an impact, then up
# the ramp at g sin) or off a floor onto a downward slope (convex, v^2 > g r: it flies off,
# lands, slides), the track as two walls or one surface.
for bdeg in [10, 20, 30, 45]:
    for v0 in [1.0, 3.0]:
        for how in ["walls", "surface"]:
            b, r = math.radians(bdeg), 0.5
            xc = r * (math.cos(b) - 1) / math.sin(b)
            vt = v0 * math.cos(b)
            s = 0.6 * vt / (g * math.sin(b))
            d = vt * s - 0.5 * g * math.sin(b) * s * s
            pts = [(-20.0, 0.0), (0.0, 0.0), (10 * math.cos(b), 10 * math.sin(b))]
            if how == "walls":
                geo = "".join(f"[[walls]]\nname = \"w{q}\"\nfrom = [{pts[q][0]!r}, {pts[q][1]!r}]\nto = [{pts[q + 1][0]!r}, {pts[q + 1][1]!r}]\nrestitution = 0.0\n" for q in range(2))
            else:
                geo = "[[surfaces]]\nname = \"track\"\npoints = [" + ", ".join(f"[{x!r}, {y!r}]" for x, y in pts) + "]\nrestitution = 0.0\n"
            n = f"concave_{bdeg}_{v0}_{how}".replace(".", "p")
            exact(n, f"""name = "{n}"
duration = {1.0 / v0 + s!r}
[world]
gravity = [0.0, -{g}]
[[bodies]]
name = "b"
radius = {r}
position = [{xc - 1.0!r}, {r}]
velocity = [{v0}, 0.0]
restitution = 0.0
{geo}""", [xc + d * math.cos(b), r + d * math.sin(b)],
                  [(vt - g * math.sin(b) * s) * math.cos(b), (vt - g * math.sin(b) * s) * math.sin(b)], 1e-8)
for bdeg in [10, 20, 30]:
    for v0 in [2.5, 4.0]:
        for how in ["walls", "surface"]:
            b, r = math.radians(bdeg), 0.5
            A, B, C = -0.5 * g * math.cos(b), math.sin(b) * v0, r * math.cos(b) - r
            s1 = (-B - math.sqrt(B * B - 4 * A * C)) / (2 * A)
            tdir = (math.cos(b), -math.sin(b))
            vt = v0 * tdir[0] - g * s1 * tdir[1]
            d = vt * 0.5 + 0.5 * g * math.sin(b) * 0.25
            p1 = (v0 * s1, r - 0.5 * g * s1 * s1)
            pts = [(-20.0, 0.0), (0.0, 0.0), (30 * math.cos(b), -30 * math.sin(b))]
            if how == "walls":
                geo = "".join(f"[[walls]]\nname = \"w{q}\"\nfrom = [{pts[q][0]!r}, {pts[q][1]!r}]\nto = [{pts[q + 1][0]!r}, {pts[q + 1][1]!r}]\nrestitution = 0.0\n" for q in range(2))
            else:
                geo = "[[surfaces]]\nname = \"track\"\npoints = [" + ", ".join(f"[{x!r}, {y!r}]" for x, y in pts) + "]\nrestitution = 0.0\n"
            n = f"convex_{bdeg}_{v0}_{how}".replace(".", "p")
            exact(n, f"""name = "{n}"
duration = {1.0 / v0 + s1 + 0.5!r}
[world]
gravity = [0.0, -{g}]
[[bodies]]
name = "b"
radius = {r}
position = [-1.0, {r}]
velocity = [{v0}, 0.0]
restitution = 0.0
{geo}""", [p1[0] + d * tdir[0], p1[1] + d * tdir[1]],
                  [(vt + g * math.sin(b) * 0.5) * tdir[0], (vt + g * math.sin(b) * 0.5) * tdir[1]], 1e-7)

# inclinebounce: a ball or a point dropped onto a 10-50 degree slope, e 0.3-1, mu 0-0.4:
# the impact's Newton law with Coulomb friction (the tangential change mu (1 + e) |v_n| at
# most, or all of it), then half its next flight. pointsettle: a point bouncing to rest.
for deg in [10, 30, 50]:
    for e in [0.3, 0.7, 1.0]:
        for mu in [0.0, 0.1, 0.4]:
            for shape in ["circle", "point"]:
                th = math.radians(deg)
                r = 0.3 if shape == "circle" else 0.0
                t, nn = (math.cos(th), -math.sin(th)), (math.sin(th), math.cos(th))
                p0 = (0.0, 2.0 + r / math.cos(th))
                t1 = math.sqrt(2 * (nn[1] * p0[1] - r) / (g * math.cos(th)))
                vn, vt = -g * t1 * nn[1], -g * t1 * t[1]
                dvt = 0.0 if mu == 0 else (vt if vt <= mu * (1 + e) * -vn else min(mu * (1 + e) * -vn, vt))
                v2 = (-e * vn * nn[0] + (vt - dvt) * t[0], -e * vn * nn[1] + (vt - dvt) * t[1])
                s = -e * vn / (g * math.cos(th))
                body = f"radius = {r}" if shape == "circle" else 'shape = "point"'
                n = f"inclinebounce_{deg}_{e}_{mu}_{shape}".replace(".", "p")
                exact(n, f"""name = "{n}"
duration = {t1 + s!r}
[world]
gravity = [0.0, -{g}]
[[bodies]]
name = "b"
{body}
position = [0.0, {p0[1]!r}]
restitution = {e}
friction = {mu}
[[walls]]
name = "slope"
from = [{-40 * t[0]!r}, {-40 * t[1]!r}]
to = [{40 * t[0]!r}, {40 * t[1]!r}]
restitution = {e}
friction = {mu}
""", [v2[0] * s, p0[1] - 0.5 * g * t1 * t1 + v2[1] * s - 0.5 * g * s * s], [v2[0], v2[1] - g * s], 1e-9)
for h in [0.3, 2.0]:
    for e in [0.0, 0.5, 0.9]:
        for frac in [0.5, 1.4]:
            T = frac * math.sqrt(2 * h / g) * (1 + e) / (1 - e)
            y, vy = bounce_state(h, e, T)
            n = f"pointsettle_{h}_{e}_{frac}".replace(".", "p")
            exact(n, f"""name = "{n}"
duration = {T!r}
[world]
gravity = [0.0, -{g}]
[[bodies]]
name = "b"
shape = "point"
position = [0.5, {h}]
restitution = {e}
[[walls]]
name = "floor"
from = [-5.0, 0.0]
to = [5.0, 0.0]
restitution = {e}
""", [0.5, y], [0.0, vy], 1e-8)

# train: a ball of friction mu_b touching one of mu_f ahead, both at v0 on a floor (e 0,
# no friction between them): together at g (m_b mu_b + m_f mu_f) / (m_b + m_f) when
# mu_b < mu_f, else apart at their own mu g; both stop and stay.
for mub, muf in [(0.1, 0.5), (0.5, 0.1), (0.0, 0.3), (0.3, 0.3), (0.2, 0.6)]:
    for mb, mf in [(1.0, 1.0), (3.0, 1.0), (1.0, 3.0)]:
        for v0 in [1.0, 4.0]:
            for order in [0, 1]:
                ab = g * (mub * mb + muf * mf) / (mb + mf) if mub < muf else g * mub
                af = ab if mub < muf else g * muf
                T = 1.2 * v0 / min(ab if ab > 0 else 1e9, af)
                def slid(a, x0):
                    if a == 0:
                        return x0 + v0 * T, v0
                    t = min(T, v0 / a)
                    return x0 + v0 * t - 0.5 * a * t * t, max(0.0, v0 - a * T)
                (xb, vb), (xf, vf) = slid(ab, -0.5), slid(af, 0.5)
                bodies = [("back", -0.5, mb), ("front", 0.5, mf)][::(-1 if order else 1)]
                txt = "".join(f"""[[bodies]]
name = "{nm}"
radius = 0.5
mass = {m}
position = [{x}, 0.5]
velocity = [{v0}, 0.0]
restitution = 0.0
""" for nm, x, m in bodies)
                n = f"train_{mub}_{muf}_{mb}_{mf}_{v0}_{order}".replace(".", "p")
                exact(n, f"""name = "{n}"
duration = {T!r}
[world]
gravity = [0.0, -{g}]
{txt}[[walls]]
name = "floor"
from = [-50.0, 0.0]
to = [50.0, 0.0]
restitution = 0.0
friction = 1.0
""" + materials([("back", "floor", mub), ("front", "floor", muf), ("back", "front", 0.0)]), [xb, 0.5], [vb, 0.0], 1e-8)
                truth[n]["front"] = {"position": [xf, 0.5], "velocity": [vf, 0.0]}

# catch: on a 10-40 degree slope, a ball of friction mu_b starts 0.3 m behind one of mu_f >
# mu_b, both at rest: it catches up at sqrt(2 gap / (a_b - a_f)), the e = 0 impact shares
# their momentum, and they slide on as one block at g (sin - cos (m_b mu_b + m_f mu_f) / M).
for deg in [10, 25, 40]:
    for mub, muf in [(0.0, 0.1), (0.05, 0.3), (0.1, 0.2)]:
        for mb, mf in [(1.0, 1.0), (4.0, 1.0), (1.0, 4.0)]:
            for order in [0, 1]:
                th = math.radians(deg)
                t, nn = (math.cos(th), -math.sin(th)), (math.sin(th), math.cos(th))
                ab, af = g * (math.sin(th) - mub * math.cos(th)), g * (math.sin(th) - muf * math.cos(th))
                if af <= 0:
                    continue
                t1 = math.sqrt(2 * 0.3 / (ab - af))
                v = (mb * ab + mf * af) * t1 / (mb + mf)
                a = g * math.sin(th) - g * math.cos(th) * (mb * mub + mf * muf) / (mb + mf)
                sf = 0.5 * af * t1 * t1 + v * 0.5 + 0.5 * a * 0.25
                at = lambda x: [x * t[0] + 0.5 * nn[0], x * t[1] + 0.5 * nn[1]]
                bodies = [("back", -1.3, mb), ("front", 0.0, mf)][::(-1 if order else 1)]
                txt = "".join(f"""[[bodies]]
name = "{nm}"
radius = 0.5
mass = {m}
position = [{at(x)[0]!r}, {at(x)[1]!r}]
restitution = 0.0
""" for nm, x, m in bodies)
                n = f"catch_{deg}_{mub}_{muf}_{mb}_{mf}_{order}".replace(".", "p")
                exact(n, f"""name = "{n}"
duration = {t1 + 0.5!r}
[world]
gravity = [0.0, -{g}]
{txt}[[walls]]
name = "slope"
from = [{-10 * t[0]!r}, {-10 * t[1]!r}]
to = [{60 * t[0]!r}, {60 * t[1]!r}]
restitution = 0.0
friction = 1.0
""" + materials([("back", "slope", mub), ("front", "slope", muf), ("back", "front", 0.0)]), at(sf - 1.0), [(v + 0.5 * a) * t[0], (v + 0.5 * a) * t[1]], 1e-8)
                truth[n]["front"] = {"position": at(sf), "velocity": [(v + 0.5 * a) * t[0], (v + 0.5 * a) * t[1]]}

# catch (a row): the same with a ball catching two touching balls (frictions mu_m <= mu_f,
# sliding from rest as one block at g (sin - cos (m_m mu_m + m_f mu_f) / (m_m + m_f))):
# the impact shares the three momenta at once, then one block of all three.
for deg in [10, 25, 40]:
    for mub, mum, muf in [(0.0, 0.1, 0.1), (0.05, 0.2, 0.3), (0.1, 0.15, 0.2)]:
        for mb, mm, mf in [(1.0, 1.0, 1.0), (4.0, 1.0, 1.0), (1.0, 4.0, 1.0), (1.0, 1.0, 4.0)]:
            for order in [0, 1]:
                th = math.radians(deg)
                t, nn = (math.cos(th), -math.sin(th)), (math.sin(th), math.cos(th))
                ab = g * (math.sin(th) - mub * math.cos(th))
                at_ = g * (math.sin(th) - math.cos(th) * (mm * mum + mf * muf) / (mm + mf))
                if at_ <= 0:
                    continue
                t1 = math.sqrt(2 * 0.3 / (ab - at_))
                M = mb + mm + mf
                v = (mb * ab + (mm + mf) * at_) * t1 / M
                a = g * math.sin(th) - g * math.cos(th) * (mb * mub + mm * mum + mf * muf) / M
                sm = 0.5 * at_ * t1 * t1 + v * 0.5 + 0.5 * a * 0.25
                at = lambda x: [x * t[0] + 0.5 * nn[0], x * t[1] + 0.5 * nn[1]]
                bodies = [("back", -1.3, mb, mub), ("mid", 0.0, mm, mum), ("front", 1.0, mf, muf)][::(-1 if order else 1)]
                txt = "".join(f"""[[bodies]]
name = "{nm}"
radius = 0.5
mass = {m}
position = [{at(x)[0]!r}, {at(x)[1]!r}]
restitution = 0.0
""" for nm, x, m, _ in bodies)
                mats = "".join(f"""[[materials]]
a = "{nm}"
b = "slope"
friction = {mu}
""" for nm, _, _, mu in bodies) + "".join(f"""[[materials]]
a = "{x}"
b = "{y}"
friction = 0.0
""" for x, y in [("back", "mid"), ("back", "front"), ("mid", "front")])
                n = f"catch_row_{deg}_{mub}_{mum}_{muf}_{mb}_{mm}_{mf}_{order}".replace(".", "p")
                u = [(v + 0.5 * a) * t[0], (v + 0.5 * a) * t[1]]
                exact(n, f"""name = "{n}"
duration = {t1 + 0.5!r}
[world]
gravity = [0.0, -{g}]
{txt}[[walls]]
name = "slope"
from = [{-10 * t[0]!r}, {-10 * t[1]!r}]
to = [{60 * t[0]!r}, {60 * t[1]!r}]
restitution = 0.0
friction = 1.0
{mats}""", at(sm - 1.0), u, 1e-8)
                truth[n]["mid"] = {"position": at(sm), "velocity": u}
                truth[n]["front"] = {"position": at(sm + 1.0), "velocity": u}

# box: a point or a 5 cm ball at 5-5000 m/s in a box of four walls (half-width 0.3-20 m),
# e = 1, with and without gravity, along an axis, at 17 degrees, and into the corners.
for v in [5, 50, 200, 1000, 5000]:
    for size in [0.3, 2.0, 20.0]:
        for ang in [0, 17, 45]:
            for shape in ["circle", "point"]:
                for grav in [0.0, 9.8]:
                    a = math.radians(ang)
                    body = f"radius = {min(0.05, size / 10)}" if shape == "circle" else 'shape = "point"'
                    c = [(-size, -size), (size, -size), (size, size), (-size, size)]
                    walls = "".join(f"""[[walls]]
name = "w{k}"
from = [{c[k][0]}, {c[k][1]}]
to = [{c[(k + 1) % 4][0]}, {c[(k + 1) % 4][1]}]
""" for k in range(4))
                    n = f"box_{v}_{size}_{ang}_{shape}_{int(grav)}".replace(".", "p")
                    write(n, f"""name = "{n}"
duration = 2.0
[world]
gravity = [0.0, {-grav}]
[[bodies]]
name = "b"
{body}
position = [0.0, 0.0]
velocity = [{v * math.cos(a)!r}, {v * math.sin(a)!r}]
{walls}""")

# junction: a floor drawn in pieces (2 or 7 walls, or one surface's polyline), level or
# tilted 0.3 rad: a point dropped 1 mm onto it (e = 0) or a 0.25 m ball on it slides on at v
# across the junctions (core to 1e-8; it fell through or hit the event cap there).
for kind in ["walls", "surface"]:
    for parts in [2, 7]:
        for ang in [0.0, 0.3]:
            for v in [0.5, 2.9, 3.0, 7.0]:
                for shape in ["point", "circle"]:
                    c, sn = math.cos(ang), math.sin(ang)
                    nx, ny = -sn, c
                    g = 9.81
                    r = 0.25 if shape == "circle" else 0.0
                    h = 1e-3 if shape == "point" else 0.0
                    T = 2.0
                    pts = [(-5.0 + 20.0 * i / parts) for i in range(parts + 1)]
                    P = [(u * c, u * sn) for u in pts]
                    if kind == "walls":
                        bar = "".join(f"""[[walls]]
name = "f{i}"
from = [{P[i][0]!r}, {P[i][1]!r}]
to = [{P[i + 1][0]!r}, {P[i + 1][1]!r}]
restitution = 0.0
""" for i in range(parts))
                    else:
                        pl = ", ".join(f"[{x!r}, {y!r}]" for x, y in P)
                        bar = f"""[[surfaces]]
name = "floor"
points = [{pl}]
restitution = 0.0
"""
                    body = 'shape = "point"' if shape == "point" else f"radius = {r}"
                    n = f"junction_{kind}_{parts}_{int(ang * 10)}_{v}_{shape}".replace(".", "p")
                    exact(n, f"""name = "{n}"
duration = {T}
[world]
gravity = [{g * sn!r}, {-g * c!r}]
[[bodies]]
name = "b"
{body}
position = [{(r + h) * nx!r}, {(r + h) * ny!r}]
velocity = [{v * c!r}, {v * sn!r}]
restitution = 0.0
{bar}""", [v * T * c + r * nx, v * T * sn + r * ny], [v * c, v * sn], 1e-8)

# tiny: a 1 cm ball at 100 and 300 m/s past a resting 1 m ball, 0.3 and 0.7 m off its centre
# line: through it within a step (never within 1 cm of its centre) must not be green.
for v in [100, 300]:
    for off in [0.3, 0.7]:
        for steps in [60, 30]:
            n = f"tiny_{v}_{int(off * 10)}_{steps}"
            write(n, f"""name = "{n}"
duration = 0.5
dt = "1/{steps}"
[[bodies]]
name = "shot"
radius = 0.01
mass = 0.001
position = [{-1.5 - 0.37 * v / steps!r}, {off}]
velocity = [{v}.0, 0.0]
[[bodies]]
name = "target"
radius = 1.0
mass = 1.0
position = [0.0, 0.0]
""")

# particles: a point shell in a closed 4 m box exploding (200 particles) or leaving a trail
# (200/s) at 5-500 m/s, particles bouncing: none may end outside (core only models them).
for speed in [5.0, 50.0, 500.0]:
    for steps in [60, 30]:
        for grav in [0.0, 9.81]:
            for mode in ["explode", "trail"]:
                n = f"particles_{int(speed)}_{steps}_{int(grav)}_{mode}"
                em = "at = 0.2\ncount = 200" if mode == "explode" else "rate = 200.0"
                walls = "".join(f"""[[walls]]
from = [{a[0]}, {a[1]}]
to = [{b[0]}, {b[1]}]
""" for a, b in [((-2, -2), (2, -2)), ((2, -2), (2, 2)), ((2, 2), (-2, 2)), ((-2, 2), (-2, -2))])
                write(n, f"""name = "{n}"
duration = 1.5
dt = "1/{steps}"
[world]
gravity = [0.0, {-grav}]
[[bodies]]
name = "shell"
shape = "point"
position = [0.0, 0.0]
velocity = [1.0, 0.5]
{walls}[[emitters]]
parent = "shell"
mode = "{mode}"
{em}
speed = {speed}
lifetime = 5.0
destroy_on_collision = false
""")

# stiffdrag: a ball thrown at 50-200 m/s against quadratic drag k2 = 2-10 towards a wall and a
# floor. Drag never reverses a body: a reference that says it converged must keep x >= 0
# (at k |v| dt / m = 4.2 it went 3 m backwards at dt/8 and dt/4 alike, "converged" to 0 m).
for k in [2.0, 10.0]:
    for v0 in [50.0, 200.0]:
        n = f"stiffdrag_{int(k)}_{int(v0)}"
        write(n, f"""name = "{n}"
duration = 3.0
dt = "1/60"
engines = ["core"]
[world]
gravity = [0.0, -9.81]
[[bodies]]
name = "b"
radius = 0.1
position = [0.0, 1.0]
velocity = [{v0!r}, {0.3 * v0!r}]
restitution = 0.9
drag_quadratic = {k!r}
[[walls]]
name = "wall"
from = [3.0, -1.0]
to = [3.0, 20.0]
restitution = 0.9
[[walls]]
name = "floor"
from = [-200.0, 0.0]
to = [3.0, 0.0]
restitution = 0.9
""")

import json
json.dump(truth, open(os.path.join(out, "..", "truth.json"), "w"))
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
"$physval" run "$work/scenes" --engines "$engines" --out "$work/out" -j "$jobs" --quiet --no-cache --series-csv > "$work/run.txt" 2>&1
status=$?
set -e
if [ "$status" -ge 2 ]; then cat "$work/run.txt" >&2; echo "hunt: physval run exited $status" >&2; exit 2; fi

set +e
python3 - "$work/out/results.json" "$work/scenes" <<'EOF'
import json, math, os, re, sys
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
    if sc.startswith("through_") or sc.startswith("tiny_"):
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
truth = json.load(open(os.path.join(sys.argv[2], "..", "truth.json")))
def ref_final(sc):
    path = os.path.join(sys.argv[2], "..", "out", "series", sc, "reference.csv")
    if not os.path.exists(path):
        return None
    rows = [l.strip().split(",") for l in open(path) if l.strip()]
    d = dict(zip(rows[0], map(float, rows[-1])))
    return [d["x_b"], d["y_b"]] if "x_b" in d else [d["x_back"], d["y_back"]]
refs = {x["scenario"]: x for x in json.load(open(sys.argv[1]))["references"]}
for r in runs:
    sc, eng = r["scenario"], r["engine"]
    t = truth.get(sc)
    if t is None or r["status"] in ("unsupported", "error"):
        continue
    first = "back" if sc.startswith(("train_", "catch_")) else "b"
    f = [b for b in r["final"] if b["body"] == first][0]
    err = max(math.dist(f["position"], t["position"]), math.dist(f["velocity"], t["velocity"]))
    for b in r["final"]:
        if b["body"] in t and isinstance(t[b["body"]], dict):
            e2 = t[b["body"]]
            err = max(err, math.dist(b["position"], e2["position"]), math.dist(b["velocity"], e2["velocity"]))
    if eng == "core" and t["judge"] == "core" and err > t["tol"]:
        found.append(f"CORE WRONG {sc}: {err:.3g} off its closed form (tolerance {t['tol']:.3g}), status {r['status']}")
    if eng == "core" and t["judge"] == "reference":
        ref = refs.get(sc, {})
        p = ref_final(sc)
        if ref.get("converged") and p is not None:
            e = math.dist(p, t["position"])
            if e > max(t["tol"], 10 * ref["convergence_error"]):
                found.append(f"CORE WRONG {sc}: the converged reference is {e:.3g} m off the closed form "
                             f"(convergence error {ref['convergence_error']:.3g})")
    # Every engine: its position divergence from the reference must see its miss.
    ref = refs.get(sc, {})
    pd = r["metrics"].get("position_divergence")
    p = ref_final(sc)
    if eng != "core" and ref.get("converged") and pd is not None and p is not None:
        miss = math.dist(f["position"], t["position"]) - math.dist(p, t["position"])
        if pd < 0.5 * miss - 1e-9:
            found.append(f"WRONG METRIC {sc} {eng}: ends {miss:.3g} m further from the closed form than the "
                         f"reference, position_divergence {pd:.3g}")
for r in runs:
    sc, eng = r["scenario"], r["engine"]
    if not sc.startswith("box_") or r["status"] in ("unsupported", "error"):
        continue
    half = float(sc.split("_")[2].replace("p", "."))
    p = r["final"][0]["position"]
    if max(abs(p[0]), abs(p[1])) > half + 1e-9:
        if green(r):
            found.append(f"WRONG GREEN {sc} {eng}: ended outside its box at {p}, status {r['status']}")
        if eng == "core":
            found.append(f"CORE WRONG {sc}: core left its box ({p})")
for r in runs:
    sc, eng = r["scenario"], r["engine"]
    if not sc.startswith("particles_") or r["status"] in ("unsupported", "error"):
        continue
    out = [b for b in r["final"] if b.get("alive", True) and max(map(abs, b["position"])) > 2.0 + 1e-9]
    if out:
        if green(r):
            found.append(f"WRONG GREEN {sc} {eng}: {len(out)} particles ended outside their closed box, status {r['status']}")
        if eng == "core":
            found.append(f"CORE WRONG {sc}: {len(out)} particles left their closed box")
for sc, ref in refs.items():
    if not sc.startswith("stiffdrag_") or not ref.get("converged"):
        continue
    path = os.path.join(sys.argv[2], "..", "out", "series", sc, "reference.csv")
    rows = [l.strip().split(",") for l in open(path) if l.strip()]
    xs = [float(r[rows[0].index("x_b")]) for r in rows[1:]]
    if min(xs) < 0.0:
        found.append(f"CORE WRONG {sc}: the converged reference went {-min(xs):.3g} m backwards against drag")
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
set +e
python3 "$(dirname "$0")/hunt6.py" "$build" "$work/hunt6" --quick -j "$jobs" | grep -v '^note '
found6=${PIPESTATUS[0]}
set -e
[ "$found6" -le 1 ] || exit 2
set +e
python3 "$(dirname "$0")/hunt7.py" "$build" "$work/hunt7" --quick -j "$jobs" | grep -v '^note '
found7=${PIPESTATUS[0]}
set -e
[ "$found7" -le 1 ] || exit 2
set +e
python3 "$(dirname "$0")/hunt8.py" "$build" "$work/hunt8" --quick -j "$jobs" | grep -v '^note '
found8=${PIPESTATUS[0]}
set -e
[ "$found8" -le 1 ] || exit 2
set +e
python3 "$(dirname "$0")/hunt10.py" "$build" "$work/hunt10" --quick -j "$jobs" | grep -v '^note '
found10=${PIPESTATUS[0]}
set -e
[ "$found10" -le 1 ] || exit 2
set +e
python3 "$(dirname "$0")/hunt12.py" "$build" "$work/hunt12" --quick -j "$jobs" | grep -v '^note '
found12=${PIPESTATUS[0]}
set -e
[ "$found12" -le 1 ] || exit 2
exit $((found | found6 | found7 | found8 | found10 | found12 | bad))
