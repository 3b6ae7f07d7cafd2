#!/usr/bin/env python3
"""Bound gravitational systems at many parameters, judged against physics (README, "The
bound-system rules"; branch boundverdict).

Writes scenes (two-body Kepler orbits at several periapses, eccentricities, steps and mass
ratios, and about a static sun; the built-in close_encounter at several offsets and steps; hierarchical 3-5 body
systems), runs them with one or two physval binaries and holds every run against the
closed forms, never against physval's own figures:

- two bodies (centre of mass at rest at the origin): the true semi-major axis
  a = -G m1 m2 / (2 E0) and period P = 2 pi sqrt(a^3 / (G (m1 + m2))). The run's a comes from
  its settled energy (median of the last quarter), its period from its positions alone
  (the times between maxima of the separation), and its angular momentum from the series.
  The orbit's size is also taken from the positions alone, (r_max + r_min) / 2 over the last
  40% of the run. wrong: it ends unbound, or either a or the period is off by more than 2x
  (or under 1/2); right: both a, the period and the angular momentum within 10%.
- more bodies: energy is conserved exactly; the scale is the binding energy E_b (-E0, or
  the most bound pair's). wrong: the settled energy moved by more than E_b (or crossed 0 and
  stayed); right: by less than E_b / 10.
Between the two is grey (reported, not counted).

A wrong green is a wrong run physval calls ok; a false red a right run it calls diverged.

  python3 scripts/boundhunt.py --physval build/physval [--before /work/main/build/physval] \
      [--out /tmp/boundhunt] [--quick]
"""
import argparse
import csv
import json
import math
import os
import random
import statistics
import subprocess
import sys


def ident(s):
    """A scenario name physval accepts ([a-z0-9_]+): 0.01 -> 0p01, 1e-3 -> 1em3."""
    return s.replace(".", "p").replace("-", "m")


def fmt(x):
    return repr(float(x))


def body(name, m, pos, vel, radius=None):
    s = f'[[bodies]]\nname = "{name}"\nshape = "point"\nmass = {fmt(m)}\n'
    s += f"position = [{fmt(pos[0])}, {fmt(pos[1])}]\nvelocity = [{fmt(vel[0])}, {fmt(vel[1])}]\n"
    return s


def kepler_scene(rp, ra, dt, q, periods=2.5):
    """Two bodies, masses 1 and q, G = 1, relative orbit from apoapsis ra to periapsis rp,
    centre of mass at rest at the origin."""
    m1, m2 = 1.0, q
    M = m1 + m2
    a = 0.5 * (ra + rp)
    va = math.sqrt(M * 2.0 * rp / (ra * (ra + rp)))   # relative speed at apoapsis
    P = 2 * math.pi * math.sqrt(a ** 3 / M)
    # body 1 at -m2/M ra, body 2 at m1/M ra; velocities opposite, in the ratio of the masses
    x1, x2 = -m2 / M * ra, m1 / M * ra
    v1, v2 = -m2 / M * va, m1 / M * va
    name = ident(f"kepler_rp{rp:g}_ra{ra:g}_dt{dt:g}_q{q:g}")
    s = f'name = "{name}"\nduration = {fmt(periods * P)}\ndt = {fmt(dt)}\n[world]\nnewtonian = true\nG = 1.0\n'
    s += body("one", m1, (x1, 0.0), (0.0, v1)) + body("two", m2, (x2, 0.0), (0.0, v2))
    s += "[gate]\nenergy_drift = 1\n"
    return name, s, {"kind": "kepler", "m1": m1, "m2": m2, "a": a, "P": P}


def static_sun_scene(rp, dt, periods=2.5):
    """A planet of 1e-3 kg about a static sun of 1 kg at the origin (G = 1): the sun's mass
    attracts through the static body, whose binding is the planet's own energy."""
    ra = 1.0
    a = 0.5 * (ra + rp)
    va = math.sqrt(2.0 * rp / (ra * (ra + rp)))
    P = 2 * math.pi * math.sqrt(a ** 3)
    name = ident(f"static_sun_rp{rp:g}_dt{dt:g}")
    s = f'name = "{name}"\nduration = {fmt(periods * P)}\ndt = {fmt(dt)}\n[world]\nnewtonian = true\nG = 1.0\n'
    s += '[[bodies]]\nname = "one"\nradius = 0.002\nmass = 1.0\nstatic = true\nposition = [0.0, 0.0]\n'
    s += body("two", 1e-3, (ra, 0.0), (0.0, va))
    s += "[gate]\nenergy_drift = 1\n"
    return name, s, {"kind": "kepler", "m1": 1.0, "m2": 1e-3, "a": a, "P": P, "static": True}


def close_encounter_scene(offset, dt):
    name = ident(f"encounter_y{offset:g}_dt{dt:g}")
    s = f'name = "{name}"\nduration = 12.0\ndt = {fmt(dt)}\n[world]\nnewtonian = true\nG = 1.0\nsoftening = 0.01\n'
    v = 0.7071067811865476
    s += body("a", 1.0, (0.5, 0.0), (0.0, v)) + body("b", 1.0, (-0.5, 0.0), (0.0, -v))
    s += body("intruder", 0.5, (-8.0, offset), (1.5, 0.0))
    s += "[gate]\nenergy_drift = 1\n"
    return name, s, {"kind": "nbody"}


def hierarchical_scene(n, seed, dt):
    """A tight binary (1 + 1 kg, separation 0.4-1 m, circular) and n - 2 outer bodies on
    near-circular orbits about it at 3-8 m (masses 0.05-0.5 kg), G = 1; random phases."""
    rng = random.Random(seed)
    sep = rng.uniform(0.4, 1.0)
    v = math.sqrt(2.0 / sep) / 2
    bodies = [("a", 1.0, (sep / 2, 0.0), (0.0, v)), ("b", 1.0, (-sep / 2, 0.0), (0.0, -v))]
    inner_mass = 2.0
    r = 3.0
    for i in range(n - 2):
        r = r * rng.uniform(1.6, 2.2)
        m = rng.uniform(0.05, 0.5)
        phi = rng.uniform(0, 2 * math.pi)
        vc = math.sqrt(inner_mass / r) * rng.uniform(0.8, 1.05)
        bodies.append((f"p{i}", m, (r * math.cos(phi), r * math.sin(phi)), (-vc * math.sin(phi), vc * math.cos(phi))))
        inner_mass += m
    # centre of mass at rest at the origin
    M = sum(b[1] for b in bodies)
    cx = sum(b[1] * b[2][0] for b in bodies) / M
    cy = sum(b[1] * b[2][1] for b in bodies) / M
    ux = sum(b[1] * b[3][0] for b in bodies) / M
    uy = sum(b[1] * b[3][1] for b in bodies) / M
    name = ident(f"hier_n{n}_s{seed}_dt{dt:g}")
    s = f'name = "{name}"\nduration = 30.0\ndt = {fmt(dt)}\n[world]\nnewtonian = true\nG = 1.0\nsoftening = 0.001\n'
    for nm, m, p, vv in bodies:
        s += body(nm, m, (p[0] - cx, p[1] - cy), (vv[0] - ux, vv[1] - uy))
    s += "[gate]\nenergy_drift = 1\n"
    return name, s, {"kind": "nbody"}


def scenes(quick):
    out = []
    rps = [0.5, 0.1, 0.03, 0.01, 0.005] if not quick else [0.1, 0.01]
    dts = [1e-2, 1e-3] if not quick else [1e-3]
    for rp in rps:
        for dt in dts:
            for q in ([1e-3, 1.0] if not quick else [1e-3]):
                out.append(kepler_scene(rp, 1.0, dt, q))
    for rp in ([0.3, 0.03, 0.01] if not quick else [0.03]):
        for dt in dts:
            out.append(static_sun_scene(rp, dt))
    for offset in ([0.3, 0.5, 0.8, 1.2] if not quick else [0.8]):
        for dt in ([1e-3, 2e-3, 5e-3] if not quick else [2e-3]):
            out.append(close_encounter_scene(offset, dt))
    for n in ([3, 4, 5] if not quick else [3]):
        for seed in ([1, 2] if not quick else [1]):
            for dt in ([1e-2, 2e-3] if not quick else [1e-2]):
                out.append(hierarchical_scene(n, seed, dt))
    return out


def read_series(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows


def settled(t, E):
    tail = [e for tt, e in zip(t, E) if tt >= t[0] + 0.75 * (t[-1] - t[0]) and math.isfinite(e)]
    return statistics.median(tail) if tail else float("nan")


def judge(kind, info, rows, pairs_binding):
    t = [float(r["t"]) for r in rows]
    E = [float(r["energy"]) for r in rows]
    L = [float(r["angular_momentum"]) for r in rows]
    E0 = E[0]
    Es = settled(t, E)
    # the sign change test: ended above 0 (from below)
    unbound = E0 < 0 and E[-1] > 0 and E[-1] - E0 > 0
    if kind == "kepler":
        m1, m2 = info["m1"], info["m2"]
        a_true = -m1 * m2 / (2 * E0)
        a_run = -m1 * m2 / (2 * Es) if Es < 0 else float("inf")
        # separation maxima from positions
        x = [(float(r["x_two"]) - float(r["x_one"]), float(r["y_two"]) - float(r["y_one"])) for r in rows]
        d = [math.hypot(*v) for v in x]
        maxima = [t[k] for k in range(1, len(d) - 1) if d[k] > d[k - 1] and d[k] >= d[k + 1]]
        P_run = (maxima[-1] - maxima[0]) / (len(maxima) - 1) if len(maxima) >= 2 else float("nan")
        P_true = 2 * math.pi * math.sqrt(a_true ** 3 / (m1 if info.get("static") else m1 + m2))
        # the orbit's size from its positions alone: (r_max + r_min) / 2 over the last 40% of
        # the run (one period of the 2.5 the scene runs, if the period is right)
        win = [dd for tt, dd in zip(t, d) if tt >= t[0] + 0.6 * (t[-1] - t[0])]
        ag = (max(win) + min(win)) / 2 / a_true
        ra_ = a_run / a_true
        rP = P_run / P_true if math.isfinite(P_run) else float("nan")
        dL = abs(L[-1] - L[0]) / abs(L[0])
        if unbound or not (0.5 <= ra_ <= 2.0) or not (0.5 <= ag <= 2.0) or (math.isfinite(rP) and not (0.5 <= rP <= 2.0)):
            cls = "wrong"
        elif abs(ra_ - 1) <= 0.1 and abs(ag - 1) <= 0.1 and (not math.isfinite(rP) or abs(rP - 1) <= 0.1) and dL <= 0.1:
            cls = "right"
        else:
            cls = "grey"
        return cls, f"a_run/a={ra_:.3g} a_geom/a={ag:.3g} P_run/P={rP:.3g} dL/L={dL:.2g} E0={E0:.3g} E_settled={Es:.3g}"
    Eb = max(-E0, pairs_binding)
    change = abs(Es - E0) / Eb if Eb > 0 else float("nan")
    if unbound or change > 1.0:
        cls = "wrong"
    elif change < 0.1:
        cls = "right"
    else:
        cls = "grey"
    return cls, f"|E_settled-E0|/E_b={change:.3g} E0={E0:.3g} E_settled={Es:.3g} E_b={Eb:.3g}"


def pair_binding(toml_text):
    """The most bound pair's binding energy from the bodies we wrote (G = 1)."""
    import re
    soft = 0.0
    m = re.search(r"softening = ([-0-9.e]+)", toml_text)
    if m:
        soft = float(m.group(1))
    bl = []
    for blk in toml_text.split("[[bodies]]")[1:]:
        mass = float(re.search(r"mass = ([-0-9.e]+)", blk).group(1))
        p = [float(v) for v in re.search(r"position = \[([^\]]*)\]", blk).group(1).split(",")]
        vm = re.search(r"velocity = \[([^\]]*)\]", blk)
        v = [float(x) for x in vm.group(1).split(",")] if vm else [0.0, 0.0]
        bl.append((mass, p, v))
    best = 0.0
    for i in range(len(bl)):
        for j in range(i + 1, len(bl)):
            mi, pi, vi = bl[i]
            mj, pj, vj = bl[j]
            mu = mi * mj / (mi + mj)
            k = 0.5 * mu * ((vi[0] - vj[0]) ** 2 + (vi[1] - vj[1]) ** 2)
            u = -mi * mj / math.sqrt((pi[0] - pj[0]) ** 2 + (pi[1] - pj[1]) ** 2 + soft ** 2)
            best = max(best, -(k + u))
    return best


def series_csv_flag(physval):
    # The series are read as CSV: `--series-csv` where the binary has it (a binary older than
    # the .bin series files writes CSV anyway).
    h = subprocess.run([physval, "run", "--help"], capture_output=True, text=True)
    return ["--series-csv"] if "--series-csv" in h.stdout + h.stderr else []


def run(physval, scene_dir, out):
    r = subprocess.run([physval, "run", scene_dir, "--out", out, "-j2", "--no-cache", "--quiet"] + series_csv_flag(physval),
                       capture_output=True, text=True)
    if r.returncode not in (0, 1):
        sys.exit(f"{physval} failed ({r.returncode}): {r.stdout[-2000:]} {r.stderr[-2000:]}")
    with open(os.path.join(out, "results.json")) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--physval", required=True)
    ap.add_argument("--before")
    ap.add_argument("--out", default="/tmp/boundhunt")
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args()
    scene_dir = os.path.join(args.out, "scenes")
    os.makedirs(scene_dir, exist_ok=True)
    infos, texts = {}, {}
    for name, text, info in scenes(args.quick):
        with open(os.path.join(scene_dir, name + ".toml"), "w") as f:
            f.write(text)
        infos[name], texts[name] = info, text
    builds = [("after", args.physval)] + ([("before", args.before)] if args.before else [])
    verdicts = {}
    for label, exe in builds:
        res = run(exe, scene_dir, os.path.join(args.out, label))
        for r in res["runs"]:
            verdicts[(label, r["scenario"], r["engine"])] = (r["status"], r.get("reason", ""))
    counts = {label: {"wrong_green": 0, "false_red": 0, "wrong": 0, "right": 0, "grey": 0} for label, _ in builds}
    lines = []
    for name in sorted(infos):
        sdir = os.path.join(args.out, "after", "series", name)
        if not os.path.isdir(sdir):
            continue
        for f in sorted(os.listdir(sdir)):
            if not f.endswith(".csv") or f == "reference.csv":
                continue
            engine = f[:-4]
            rows = read_series(os.path.join(sdir, f))
            if len(rows) < 2:
                continue
            cls, detail = judge(infos[name]["kind"], infos[name], rows, pair_binding(texts[name]))
            row = f"{name:34s} {engine:9s} {cls:6s}"
            for label, _ in builds:
                st, _reason = verdicts.get((label, name, engine), ("?", ""))
                if st in ("unsupported", "error"):
                    continue
                counts[label][cls] += 1
                if cls == "wrong" and st == "ok":
                    counts[label]["wrong_green"] += 1
                if cls == "right" and st == "diverged":
                    counts[label]["false_red"] += 1
                row += f" {label}={st}"
            lines.append(row + "  " + detail)
    print("\n".join(lines))
    for label, _ in builds:
        c = counts[label]
        print(f"{label}: {c['wrong']} wrong, {c['right']} right, {c['grey']} grey runs; "
              f"wrong greens {c['wrong_green']}, false reds {c['false_red']}")


if __name__ == "__main__":
    main()
