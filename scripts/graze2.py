#!/usr/bin/env python3
"""Glancing impacts skipped within one step (README, *The seventh hunt*, branch graze2).

  scripts/graze2.py [BUILD_DIR] [WORKDIR] [-j N] [--quick]

A ball a (radius ra, mass ra^2) at speed v along +x passes a resting ball b (radius rb, mass
rb^2), its line `off` x (ra + rb) off b's centre (0 to 0.99), e = 1, no field, the impact at
a phase 0.3 or 0.7 into a step; v 3-300 m/s, rb/ra 1 and 0.3, dt 1/30 and 1/120. The closed
form (the elastic impact of two discs, computed here) says b leaves at a speed > 0 whenever
off < 1. A run in which b never moved (its speed below 1e-6 v) and a's velocity is the one
it had (Box2D's speed cap aside) skipped the impact: a wrong green when it is `ok` and the
straight path overlapped by more than the slop (2% of the smaller radius; on Box2D at least
3.25 of its 5 mm linear slop, its time of impact's allowance; closed form: depth = (1 - off)
(ra + rb)). A run that did strike b (b's speed within 25% of the closed
form's) but is `diverged` by a skipped impact is a false red. A run whose ball a was slowed
(Box2D's cap of 2 m a step) passes later than the closed form's impact: not judged. Prints the counts; exit 1 on
any wrong green or false red, 0 when none, 2 on a usage error.
"""
import json, math, os, subprocess, sys


def fmt(x):
    return repr(float(x))


def closed_form(off, v, ra, rb):
    S = ra + rb
    y0 = off * S
    n = (math.sqrt(max(0.0, 1 - off * off)), -off)   # a -> b at contact, unit
    ma, mb = ra * ra, rb * rb
    J = 2.0 * ma * mb / (ma + mb) * v * n[0]
    return (v - J / ma * n[0], -J / ma * n[1]), (J / mb * n[0], J / mb * n[1])


def main(argv):
    build, work, jobs, quick = "build", "/tmp/graze2", 2, False
    pos = []
    i = 0
    while i < len(argv):
        if argv[i] == "-j" and i + 1 < len(argv):
            jobs = int(argv[i + 1])
            i += 2
            continue
        if argv[i] == "--quick":
            quick = True
        elif argv[i].startswith("-"):
            print(__doc__)
            return 2
        else:
            pos.append(argv[i])
        i += 1
    if pos:
        build = pos[0]
    if len(pos) > 1:
        work = pos[1]
    scenes = os.path.join(work, "scenes")
    os.makedirs(scenes, exist_ok=True)
    for f in os.listdir(scenes):
        os.remove(os.path.join(scenes, f))
    offs = [0.0, 0.5, 0.8, 0.9, 0.97] if quick else [0.0, 0.2, 0.4, 0.6, 0.7, 0.8, 0.9, 0.95, 0.97, 0.99]
    speeds = [30.0, 300.0] if quick else [3.0, 30.0, 80.0, 300.0]
    ratios = [1.0] if quick else [1.0, 0.3]
    dts = [(30, "1/30")] if quick else [(30, "1/30"), (120, "1/120")]
    phases = [0.3] if quick else [0.3, 0.7]
    truth = {}
    for off in offs:
        for v in speeds:
            for rr in ratios:
                for hz, dt in dts:
                    for ph in phases:
                        ra, rb = 0.5, 0.5 * rr
                        S = ra + rb
                        y0 = off * S
                        xc = -math.sqrt(max(0.0, S * S - y0 * y0))   # a's x at contact
                        tc = (2 + ph) / hz                            # contact in the third step
                        x0 = xc - v * tc
                        name = f"g_off{int(round(off * 100))}_v{int(v)}_r{int(rr * 10)}_dt{hz}_p{int(ph * 10)}"
                        text = (f'name = "{name}"\nduration = {fmt(max(0.2, 12.0 / hz))}\ndt = "{dt}"\n'
                                f'[[bodies]]\nname = "a"\nradius = {fmt(ra)}\nmass = {fmt(ra * ra)}\n'
                                f'position = [{fmt(x0)}, {fmt(y0)}]\nvelocity = [{fmt(v)}, 0.0]\nrestitution = 1.0\n'
                                f'[[bodies]]\nname = "b"\nradius = {fmt(rb)}\nmass = {fmt(rb * rb)}\n'
                                f'position = [0.0, 0.0]\nrestitution = 1.0\n')
                        open(os.path.join(scenes, name + ".toml"), "w").write(text)
                        va, vb = closed_form(off, v, ra, rb)
                        # The deepest overlap at a step's end on the straight flight: a pass an
                        # engine sees overlapping there (already separating) is resolved as an
                        # overlap; only what the path adds beyond it is judged (README).
                        ends = max(max(0.0, S - math.hypot(x0 + v * k / hz, y0)) for k in range(0, 13))
                        truth[name] = dict(end_depth=ends / min(ra, rb), off=off, v=v, va=va, vb=vb, depth=(1 - off) * S / min(ra, rb), rmin=min(ra, rb),
                                           slop=0.02)
    res = os.path.join(work, "out")
    p = subprocess.run([os.path.join(build, "physval"), "run", scenes, "--out", res, "-j", str(jobs), "--no-cache",
                        "--quiet"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if p.returncode not in (0, 1):
        print(f"physval run exited {p.returncode}: {p.stderr[-400:]}", file=sys.stderr)
        return 2
    data = json.load(open(os.path.join(res, "results.json")))
    wrong, false_red, skipped, struck, runs, capped, at_end = [], [], 0, 0, 0, 0, 0
    for r in data["runs"]:
        if r["status"] == "unsupported":
            continue
        runs += 1
        t = truth[r["scenario"]]
        fin = {b["body"]: b for b in r["final"]}
        va, vb = fin["a"]["velocity"], fin["b"]["velocity"]
        vbn = math.hypot(*t["vb"])
        untouched = math.hypot(*vb) < 1e-6 * t["v"] and abs(va[1]) < 1e-6 * t["v"]
        if r["engine"] == "core":
            miss = max(math.hypot(va[0] - t["va"][0], va[1] - t["va"][1]), math.hypot(vb[0] - t["vb"][0], vb[1] - t["vb"][1]))
            if miss > 1e-6 * t["v"]:
                wrong.append(f"{r['scenario']} [core]: off the closed form by {miss:.3g} m/s ({r['status']})")
            continue
        if abs(math.hypot(*va) - t["v"]) > 1e-6 * t["v"] and untouched:
            capped += 1   # Box2D's speed cap: a slower ball, its pass later than the closed form's
            continue
        if untouched and vbn > 0:
            skipped += 1
            # Box2D's own allowance: its time of impact stops a pair 3.25 linear slops
            # (3.25 x 5 mm) into each other by design, bullets or not (README).
            slop = max(t["slop"], 0.01625 / t["rmin"]) if r["engine"] == "box2d" else t["slop"]
            if r["status"] == "ok" and t["depth"] - t["end_depth"] <= 1.001 * slop:
                at_end += 1   # seen overlapping at a step's end: left (README)
            elif r["status"] == "ok" and t["depth"] > 1.001 * slop:
                wrong.append(f"{r['scenario']} [{r['engine']}]: skipped the impact ({t['depth']:.3f} of the smaller "
                             f"radius deep on the straight path), `ok`")
        elif vbn > 0 and abs(math.hypot(*vb) - vbn) <= 0.25 * vbn:
            struck += 1
            if r["status"] == "diverged" and "skipped impact" in r.get("reason", ""):
                false_red.append(f"{r['scenario']} [{r['engine']}]: struck b ({math.hypot(*vb):.3g} m/s, closed form "
                                 f"{vbn:.3g}) but diverged: {r['reason'][:120]}")
    for w in wrong:
        print("WRONG GREEN " + w)
    for f in false_red:
        print("FALSE RED " + f)
    print(f"graze2: {len(truth)} scenes, {runs} runs ({skipped} skipped the impact, {struck} struck b near the "
          f"closed form, {capped} with a speed-capped ball not judged, {at_end} `ok` skips whose depth a step's end already showed, left): {len(wrong)} wrong greens, {len(false_red)} false reds")
    return 1 if wrong or false_red else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
