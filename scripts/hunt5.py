#!/usr/bin/env python3
"""The fifth hunt's grids (README, *The fifth hunt*): scenes the independent checkers write,
each judged here against physics computed here (closed forms, symmetry, containment,
energy), never against physval's own output.

  scripts/hunt5.py gen DIR          writes DIR/scenes/*.toml and DIR/truth.json
  scripts/hunt5.py judge DIR        reads DIR/out/results.json; prints findings, exit 1 if any

Families: pile (circles dropped into a box of walls or thin solid boxes), slope (a circle
sliding on a wall used as an incline, mu_s/mu_k, from rest, down, up), triple (a ball onto
two, three balls meeting at 120 degrees, numberings and mirrors), dragwall (quadratic and
linear drag, thrown at a wall and a floor), escape (a fast body in a box of thin walls or
thin solid boxes, big dt, CCD settings), long (1e6-1e7 steps of free flight and of a
bouncing ball, durations and steps at float limits).
"""
import json, math, os, sys

G = 9.81
WIDE = os.environ.get("HUNT5_WIDE") == "1"


def gen(root):
    out = os.path.join(root, "scenes")
    os.makedirs(out, exist_ok=True)
    truth = {}

    def write(name, text, **t):
        open(os.path.join(out, name + ".toml"), "w").write(text)
        truth[name] = t

    def walls_box(w, h, e=1.0, mu=0.0, thick=0.0, kind="walls"):
        """A closed container [-w, w] x [0, h]: four walls, or four thin solid boxes
        whose inner faces are the container's sides."""
        s = ""
        if kind == "walls":
            c = [(-w, 0.0), (w, 0.0), (w, h), (-w, h)]
            for k in range(4):
                a, b = c[k], c[(k + 1) % 4]
                s += f"""[[walls]]
name = "w{k}"
from = [{a[0]!r}, {a[1]!r}]
to = [{b[0]!r}, {b[1]!r}]
restitution = {e!r}
friction = {mu!r}
"""
        else:
            boxes = [((-w - thick, -thick), (w + thick, 0.0)), ((w, 0.0), (w + thick, h)),
                     ((-w - thick, h), (w + thick, h + thick)), ((-w - thick, 0.0), (-w, h))]
            for k, (lo, hi) in enumerate(boxes):
                s += f"""[[boxes]]
name = "s{k}"
min = [{lo[0]!r}, {lo[1]!r}]
max = [{hi[0]!r}, {hi[1]!r}]
restitution = {e!r}
friction = {mu!r}
"""
        return s

    # (a) pile: n circles dropped into a box (walls or thin boxes), e, mu, dt, sizes, masses.
    import random
    for n in ([40, 60] if WIDE else [3, 8, 20]):
        for e in ([0.0, 0.9] if WIDE else [0.0, 0.5, 1.0]):
            for mu in [0.0, 0.4]:
                for dt in (["1/10", "1/5"] if WIDE else ["1/60", "1/20"]):
                    for kind in ["walls", "boxes"]:
                        rnd = random.Random(n * 1000 + int(e * 10) + int(mu * 10) * 7 + len(dt) + len(kind))
                        w, h = (3.0, 8.0) if WIDE else (1.5, 6.0)
                        vmax = 30.0 if WIDE else 3.0
                        bodies = ""
                        placed = []
                        i = 0
                        while len(placed) < n and i < 10000:
                            i += 1
                            r = rnd.choice([0.1, 0.15, 0.25])
                            x = rnd.uniform(-w + r, w - r)
                            y = rnd.uniform(0.5 + r, h - r)
                            if all(math.hypot(x - px, y - py) > r + pr + 1e-3 for px, py, pr in placed):
                                placed.append((x, y, r))
                        for k, (x, y, r) in enumerate(placed):
                            m = rnd.choice([0.1, 1.0, 10.0])
                            bodies += f"""[[bodies]]
name = "p{k}"
radius = {r}
mass = {m}
position = [{x!r}, {y!r}]
velocity = [{rnd.uniform(-vmax, vmax)!r}, {rnd.uniform(-vmax, vmax)!r}]
restitution = {e}
friction = {mu}
"""
                        name = f"pile_{n}_{int(e*10)}_{int(mu*10)}_{dt.split('/')[-1]}_{kind}"
                        write(name, f"""name = "{name}"
duration = 3.0
dt = "{dt}"
[world]
gravity = [0.0, -9.81]
{bodies}{walls_box(w, h, e, mu, 0.05, kind)}""", family="pile", w=w, h=h, radii=[p[2] for p in placed])

    # (b) slope: a circle on a wall used as an incline. Closed form along the slope
    # (s down-slope positive): kinetic mu_k while sliding, static mu_s from rest.
    def slope_state(th, mus, muk, v0, T):
        sn, cs = math.sin(th), math.cos(th)
        ad = G * (sn - muk * cs)   # sliding down
        au = -G * (sn + muk * cs)  # moving up: decelerates
        held = math.tan(th) <= mus
        s, v, t = 0.0, v0, 0.0
        if v0 < 0:   # up the slope (negative s)
            a = G * (sn + muk * cs)  # acceleration (towards +s) while moving up
            t1 = -v0 / a
            if T <= t1:
                return v0 * T + 0.5 * a * T * T, v0 + a * T
            s = v0 * t1 + 0.5 * a * t1 * t1
            v, t = 0.0, t1
        if v == 0.0:
            if held:
                return s, 0.0
            return s + 0.5 * ad * (T - t) ** 2, ad * (T - t)
        # moving down at v > 0
        if ad >= 0:
            return s + v * (T - t) + 0.5 * ad * (T - t) ** 2, v + ad * (T - t)
        t1 = v / -ad
        if T - t <= t1:
            return s + v * (T - t) + 0.5 * ad * (T - t) ** 2, v + ad * (T - t)
        s += v * t1 + 0.5 * ad * t1 * t1
        # stopped: held iff static friction can (tan <= mu_s)
        if held:
            return s, 0.0
        return s + 0.5 * ad * (T - t - t1) ** 2, ad * (T - t - t1)

    for deg in ([1, 45, 80, 89] if WIDE else [5, 15, 25, 35, 50, 70]):
        for mus, muk in ([(0.0, 0.0), (1.0, 0.99), (5.0, 0.1), (60.0, 50.0)] if WIDE else
                         [(0.0, 0.0), (0.3, 0.2), (0.5, 0.3), (0.8, 0.5), (1.2, 1.0), (0.3, 0.3)]):
            for v0 in [0.0, 2.0, -2.0]:
                for order in ["down", "up"]:
                    th = math.radians(deg)
                    sn, cs = math.sin(th), math.cos(th)
                    if abs(math.tan(th) - mus) < 1e-6:
                        continue
                    r, T, L = (0.001 if WIDE else 0.2), 2.0, 200.0
                    d = (cs, -sn)        # down-slope direction
                    nrm = (sn, cs)       # outward normal
                    a_pt = (-L * cs / 2, L * sn / 2)
                    b_pt = (L * cs / 2, -L * sn / 2)
                    if order == "up":
                        a_pt, b_pt = b_pt, a_pt
                    s, v = slope_state(th, mus, muk, v0, T)
                    pos = [r * nrm[0] + s * d[0], r * nrm[1] + s * d[1]]
                    vel = [v * d[0], v * d[1]]
                    name = f"slope_{deg}_{int(mus*10)}_{int(muk*10)}_{int(v0)}_{order}".replace("-", "m")
                    write(name, f"""name = "{name}"
duration = {T}
dt = "1/60"
[world]
gravity = [0.0, -9.81]
[[bodies]]
name = "b"
radius = {r}
position = [{r * nrm[0]!r}, {r * nrm[1]!r}]
velocity = [{v0 * d[0]!r}, {v0 * d[1]!r}]
restitution = 0.0
[[walls]]
name = "incline"
from = [{a_pt[0]!r}, {a_pt[1]!r}]
to = [{b_pt[0]!r}, {b_pt[1]!r}]
restitution = 0.0
[[materials]]
a = "b"
b = "incline"
friction = {muk}
static_friction = {mus}
[expect]
final = [ {{ body = "b", position = [{pos[0]!r}, {pos[1]!r}], velocity = [{vel[0]!r}, {vel[1]!r}], tolerance = 1e-3 }} ]
""", family="slope", position=pos, velocity=vel, tol=1e-6)

    # (c) triple: a ball dropped centred onto two balls resting apart (gap) on a floor, and
    # three balls meeting at 120 degrees; every numbering; mirror symmetry is the oracle.
    perms = [(0, 1, 2), (2, 1, 0), (1, 0, 2), (1, 2, 0)]
    for e in ([0.3, 0.9] if WIDE else [0.0, 0.5, 1.0]):
        for mu in ([0.0, 1.0] if WIDE else [0.0, 0.3]):
            for gap in ([1e-9, 0.5] if WIDE else [0.0, 0.1]):
                for mass_top in ([1e-3, 1e3] if WIDE else [0.5, 1.0, 4.0]):
                    for pi, perm in enumerate(perms):
                        r = 0.5
                        bs = [("top", mass_top, (0.0, 3.0)), ("left", 1.0, (-(r + gap / 2), r)), ("right", 1.0, (r + gap / 2, r))]
                        body = ""
                        for k in perm:
                            nm, m, p = bs[k]
                            body += f"""[[bodies]]
name = "{nm}"
radius = {r}
mass = {m}
position = [{p[0]!r}, {p[1]!r}]
restitution = {e}
friction = {mu}
"""
                        name = f"triple_drop_{int(e*10)}_{int(mu*10)}_{int(gap*10)}_{int(mass_top*10)}_{pi}"
                        write(name, f"""name = "{name}"
duration = 3.0
dt = "1/60"
allow_initial_overlap = false
[world]
gravity = [0.0, -9.81]
{body}[[walls]]
name = "floor"
from = [-20.0, 0.0]
to = [20.0, 0.0]
restitution = {e}
friction = {mu}
""", family="triple_drop", group=f"triple_drop_{int(e*10)}_{int(mu*10)}_{int(gap*10)}_{int(mass_top*10)}")
    for e in ([0.3, 0.9] if WIDE else [0.0, 0.5, 1.0]):
        for v in ([100.0, 1000.0] if WIDE else [1.0, 10.0]):
            for dt in (["1/60", "1/2"] if WIDE else ["1/60", "1/7"]):
                for pi, perm in enumerate(perms):
                    r = 0.5
                    bs = []
                    for k in range(3):
                        a = math.radians(90 + 120 * k)
                        # meet at t = 0.5 + dt/3 (off the step grid) at the centre, touching
                        dist = r / math.cos(math.radians(30)) + v * 0.5337
                        bs.append((f"b{k}", (dist * math.cos(a), dist * math.sin(a)), (-v * math.cos(a), -v * math.sin(a))))
                    body = ""
                    for k in perm:
                        nm, p, vv = bs[k]
                        body += f"""[[bodies]]
name = "{nm}"
radius = {r}
position = [{p[0]!r}, {p[1]!r}]
velocity = [{vv[0]!r}, {vv[1]!r}]
restitution = {e}
"""
                    name = f"triple_meet_{int(e*10)}_{int(v)}_{dt.split('/')[-1]}_{pi}"
                    write(name, f"""name = "{name}"
duration = 1.5
dt = "{dt}"
{body}""", family="triple_meet", e=e, v=v)

    # (d) drag: a ball thrown at a wall then the floor with quadratic (or linear) drag, e 0.5-1.
    for kind in ["quadratic", "linear"]:
        for k in ([2.0, 10.0] if WIDE else [0.01, 0.1, 0.5]):
            for e in ([0.0, 0.9] if WIDE else [0.5, 1.0]):
                for v0 in ([50.0, 200.0] if WIDE else [5.0, 20.0]):
                    name = f"dragwall_{kind}_{int(k*100)}_{int(e*10)}_{int(v0)}"
                    key = "drag_quadratic" if kind == "quadratic" else "drag_linear"
                    write(name, f"""name = "{name}"
duration = 3.0
dt = "1/60"
[world]
gravity = [0.0, -9.81]
[[bodies]]
name = "b"
radius = 0.1
position = [0.0, 1.0]
velocity = [{v0!r}, {v0 * 0.3!r}]
restitution = {e}
{key} = {k}
[[walls]]
name = "wall"
from = [3.0, -1.0]
to = [3.0, 20.0]
restitution = {e}
[[walls]]
name = "floor"
from = [-200.0, 0.0]
to = [3.0, 0.0]
restitution = {e}
""", family="dragwall", kind=kind, k=k, e=e, v0=v0, r=0.1, x0=[0.0, 1.0], vel0=[v0, v0 * 0.3], wall=3.0, T=3.0)

    # (e) escape: a fast body in a box of walls or thin boxes, big dt, CCD on/off.
    for shape in ["circle", "point"]:
        for v in ([1e4, 1e5] if WIDE else [20.0, 200.0, 2000.0]):
            for dt in (["1/60", "1/1"] if WIDE else ["1/60", "1/10", "1/2"]):
                for kind, thick in ([("boxes", 0.02), ("boxes", 1.0)] if WIDE else [("walls", 0.0), ("boxes", 0.001), ("boxes", 0.05)]):
                    for ccd in ["default", "off", "on"]:
                        if kind == "walls" and ccd == "on" and shape == "point":
                            continue
                        w, h = 1.0, 2.0
                        body = 'shape = "point"' if shape == "point" else "radius = 0.05"
                        opts = ""
                        if ccd == "off":
                            opts = "[box2d]\ncontinuous = false\n[bullet]\nccd = false\n"
                        elif ccd == "on":
                            opts = "[bullet]\nccd = true\ncontact_processing_threshold = 1e30\n"
                        a = math.atan2(1.0, 0.9) if WIDE else 0.37   # WIDE: aimed at the corner (1, 2)
                        name = f"escape_{shape}_{int(v)}_{dt.split('/')[-1]}_{kind}_{int(thick*1000)}_{ccd}"
                        write(name, f"""name = "{name}"
duration = 2.0
dt = "{dt}"
[world]
gravity = [0.0, -9.81]
[[bodies]]
name = "b"
{body}
position = [0.1, 1.0]
velocity = [{v * math.cos(a)!r}, {v * math.sin(a)!r}]
{walls_box(w, h, 1.0, 0.0, thick, kind)}{opts}""", family="escape", w=w, h=h)

    # (f) long: free flight and a bounce at 1e6-1e7 steps; durations at float limits.
    for steps, dt in [(1_000_000, 1e-6), (10_000_000, 1e-7), (4_000_000, 0.25)]:
        T = steps * dt
        name = f"long_free_{steps}_{str(dt).replace('.', 'p').replace('-', 'm')}"
        # A point thrown sideways in zero gravity (free flight, exactly linear).
        write(name, f"""name = "{name}"
duration = {T!r}
dt = {dt!r}
engines = ["core", "box2d", "bullet", "chipmunk", "ode"]
sample_interval = {T / 100!r}
[[bodies]]
name = "b"
radius = 0.1
position = [0.0, 0.0]
velocity = [1.0, 0.5]
""", family="long_free", position=[T, 0.5 * T], velocity=[1.0, 0.5])
    for T, dt in [(1e-300, 1e-303), (1e300, 1e297), (5e-324 * 1000, 5e-324), (1e15, 1e10)]:
        name = f"long_limit_{abs(math.frexp(T)[1])}_{abs(math.frexp(dt)[1])}_{'s' if T < 1 else 'b'}"
        write(name, f"""name = "{name}"
duration = {T!r}
dt = {dt!r}
[[bodies]]
name = "b"
radius = 0.1
position = [0.0, 0.0]
velocity = [1e-3, 0.0]
""", family="long_free", position=[1e-3 * T, 0.0], velocity=[1e-3, 0.0])

    json.dump(truth, open(os.path.join(root, "truth.json"), "w"), indent=0)
    print(f"hunt5: {len(truth)} scenes")


def quad_drag_truth(t, dt=1e-5):
    """RK4 at a small step with exact-time impacts (bisected): the ball against the wall
    x = wall - r (from the left) and the floor y = r."""
    k, kind, e, r, wall = t["k"], t["kind"], t["e"], t["r"], t["wall"]
    x, y = t["x0"]
    vx, vy = t["vel0"]
    T = t["T"]

    def acc(s):
        vx, vy = s[2], s[3]
        sp = math.hypot(vx, vy)
        c = k * sp if kind == "quadratic" else k
        return (vx, vy, -c * vx, -G - c * vy)

    def rk(s, h):
        k1 = acc(s)
        k2 = acc([s[i] + h / 2 * k1[i] for i in range(4)])
        k3 = acc([s[i] + h / 2 * k2[i] for i in range(4)])
        k4 = acc([s[i] + h * k3[i] for i in range(4)])
        return [s[i] + h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]) for i in range(4)]

    s = [x, y, vx, vy]
    tt = 0.0
    resting = False
    while tt < T - 1e-15:
        h = min(dt, T - tt)
        if resting:
            # on the floor after bouncing to rest vertically: vx decays by drag only
            s = [s[0], r, s[2], 0.0]
        step = (lambda st, hh: (lambda n: [n[0], r, n[2], 0.0])(rk(st, hh))) if resting else rk
        n = step(s, h)
        hit = None
        if n[0] > wall - r:
            hit = "wall"
        elif n[1] < r:
            hit = "floor"
        if hit is None:
            s, tt = n, tt + h
            continue
        lo, hi = 0.0, h
        for _ in range(60):
            mid = (lo + hi) / 2
            m = step(s, mid)
            if (m[0] > wall - r) if hit == "wall" else (m[1] < r):
                hi = mid
            else:
                lo = mid
        s = step(s, lo)
        tt += lo
        if hit == "wall":
            s[2] = -e * s[2]
        else:
            s[3] = -e * s[3]
            if abs(s[3]) < 1e-6:
                resting = True
    return [s[0], s[1]], [s[2], s[3]]


def judge(root):
    res = json.load(open(os.path.join(root, "out", "results.json")))
    truth = json.load(open(os.path.join(root, "truth.json")))
    refs = {x["scenario"]: x for x in res["references"]}
    found = []

    def green(r):
        return r["status"] == "ok" or r.get("known_divergence")

    def fb(r, name):
        return [b for b in r["final"] if b["body"] == name][0]

    groups = {}
    for r in res["runs"]:
        sc, eng = r["scenario"], r["engine"]
        t = truth.get(sc)
        if t is None or r["status"] in ("unsupported", "error"):
            if r["status"] == "error":
                found.append(f"ERROR {sc} {eng}: {r['reason'][:160]}")
            continue
        fam = t["family"]
        if fam in ("pile", "escape"):
            w, h = t["w"], t["h"]
            outside = [b["body"] for b in r["final"] if b.get("alive", True) and
                       (abs(b["position"][0]) > w + 1e-9 or b["position"][1] < -1e-9 or b["position"][1] > h + 1e-9)]
            if outside and green(r):
                found.append(f"WRONG GREEN {sc} {eng}: {len(outside)} bodies ended outside the box ({outside[:3]}), status {r['status']}")
            if outside and eng == "core":
                found.append(f"CORE WRONG {sc}: {outside} outside")
            if fam == "pile" and green(r):
                # final overlap of two bodies deeper than the smaller radius, not an escape?
                fs = [b for b in r["final"] if b.get("alive", True)]
                radii = t["radii"]
                for i in range(len(fs)):
                    for j in range(i + 1, len(fs)):
                        d = math.dist(fs[i]["position"], fs[j]["position"])
                        ri, rj = radii[int(fs[i]["body"][1:])], radii[int(fs[j]["body"][1:])]
                        if d < min(ri, rj):
                            found.append(f"WRONG GREEN {sc} {eng}: {fs[i]['body']} and {fs[j]['body']} end {d:.3g} m apart (radii {ri}, {rj})")
                mp = r["metrics"].get("max_penetration")
                for b in fs:
                    k = int(b["body"][1:])
                    y = b["position"][1]
                    pen = radii[k] - min(y, w - abs(b["position"][0]), h - y)
                    if mp is not None and pen > mp + 1e-9:
                        found.append(f"WRONG METRIC {sc} {eng}: {b['body']} ends {pen:.3g} m into a side, max_penetration {mp:.3g}")
        elif fam == "slope":
            f = fb(r, "b")
            err = max(math.dist(f["position"], t["position"]), math.dist(f["velocity"], t["velocity"]))
            if eng == "core" and err > t["tol"]:
                found.append(f"CORE WRONG {sc}: {err:.3g} off the closed form, status {r['status']}")
            chk = [c for c in r["checks"] if c["what"].startswith("expect.final")]
            for c in chk:
                key = "position" if c["what"].endswith("position") else "velocity"
                e1 = math.dist(f[key], t[key])
                if c["pass"] and e1 > 1e-3 + 1e-9:
                    found.append(f"WRONG GREEN {sc} {eng}: {c['what']} passed, true error {e1:.3g}")
            ref = refs.get(sc, {})
            pd = r["metrics"].get("position_divergence")
            if eng != "core" and ref.get("converged") and pd is not None:
                perr = math.dist(f["position"], t["position"])
                if pd < 0.5 * perr - 1e-6:
                    found.append(f"WRONG METRIC {sc} {eng}: {perr:.3g} m off the closed form, position_divergence {pd:.3g}")
        elif fam == "triple_drop":
            groups.setdefault((t["group"], eng), []).append(r)
            top, L, R = fb(r, "top"), fb(r, "left"), fb(r, "right")
            asym = max(abs(top["position"][0]), abs(L["position"][0] + R["position"][0]), abs(L["position"][1] - R["position"][1]),
                       abs(top["velocity"][0]))
            if eng == "core" and asym > 1e-6:
                found.append(f"CORE WRONG {sc}: mirror asymmetry {asym:.3g} m, status {r['status']}")
        elif fam == "triple_meet":
            groups.setdefault((sc.rsplit("_", 1)[0], eng), []).append(r)
            sp = [math.hypot(*b["velocity"]) for b in r["final"]]
            dist = [math.hypot(*b["position"]) for b in r["final"]]
            px = sum(b["velocity"][0] for b in r["final"])
            py = sum(b["velocity"][1] for b in r["final"])
            E0 = 1.5 * t["v"] ** 2
            E1 = sum(0.5 * s * s for s in sp)
            asym = max(max(sp) - min(sp), max(dist) - min(dist))
            if eng == "core":
                if asym > 1e-6 * t["v"]:
                    found.append(f"CORE WRONG {sc}: 120-degree symmetry broken by {asym:.3g}, status {r['status']}")
                if E1 > E0 * (1 + 1e-9):
                    found.append(f"CORE WRONG {sc}: energy gained {E1 - E0:.3g}")
                if abs(min(sp) - t["e"] * t["v"]) > 1e-6 * t["v"]:
                    found.append(f"CORE WRONG {sc}: speeds {sp} after a symmetric e = {t['e']} impact (expected {t['e'] * t['v']})")
            if green(r) and E1 > E0 * 1.01:
                found.append(f"WRONG GREEN {sc} {eng}: energy {E0:.4g} -> {E1:.4g} J in a meeting that can only lose it, "
                             f"energy_gain {r['metrics'].get('energy_gain')}")
        elif fam == "dragwall":
            pos, vel = quad_drag_truth(t)
            f = fb(r, "b")
            err = math.dist(f["position"], pos)
            ref = refs.get(sc, {})
            if eng == "core" and ref.get("converged"):
                p = ref_final(root, sc)
                if p is not None:
                    e2 = math.dist(p, pos)
                    if e2 > max(1e-4, 10 * ref["convergence_error"]):
                        found.append(f"CORE WRONG {sc}: converged reference {e2:.3g} m off the integrated truth "
                                     f"(convergence error {ref['convergence_error']:.3g})")
            pd = r["metrics"].get("position_divergence")
            p = ref_final(root, sc)
            if eng != "core" and ref.get("converged") and pd is not None and p is not None:
                miss = err - math.dist(p, pos)
                if pd < 0.5 * miss - 1e-6:
                    found.append(f"WRONG METRIC {sc} {eng}: {miss:.3g} m further off, position_divergence {pd:.3g}")
        elif fam == "long_free":
            f = fb(r, "b")
            err = math.dist(f["position"], t["position"])
            scale = max(1e-300, math.hypot(*t["position"]))
            if err > 1e-6 * scale and green(r):
                found.append(f"WRONG GREEN {sc} {eng}: free flight ends {err:.3g} m off x0 + v T ({scale:.3g} m), status {r['status']}")
    # numbering: every numbering of one scene must give the same final state (core).
    for (g, eng), rs in groups.items():
        if eng != "core" or len(rs) < 2:
            continue
        base = {b["body"]: b for b in rs[0]["final"]}
        for r in rs[1:]:
            d = max(math.dist(b["position"], base[b["body"]]["position"]) for b in r["final"])
            if d > 1e-6:
                found.append(f"CORE WRONG {g}: numberings differ by {d:.3g} m ({rs[0]['scenario']} vs {r['scenario']}), "
                             f"statuses {rs[0]['status']}/{r['status']}")
    for f in found:
        print(f)
    print(f"hunt5: {len(res['runs'])} runs, {len(found)} findings")
    return 1 if found else 0


def ref_final(root, sc):
    path = os.path.join(root, "out", "series", sc, "reference.csv")
    if not os.path.exists(path):
        return None
    rows = [l.strip().split(",") for l in open(path) if l.strip()]
    d = dict(zip(rows[0], map(float, rows[-1])))
    return [d["x_b"], d["y_b"]]


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in ("gen", "judge"):
        print(__doc__)
        sys.exit(2)
    if sys.argv[1] == "gen":
        gen(sys.argv[2])
    else:
        sys.exit(judge(sys.argv[2]))
