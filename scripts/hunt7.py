#!/usr/bin/env python3
"""The seventh hunt (README, *The seventh hunt*): leaves the earlier hunts noted and never
examined, each scene run through `physval` and judged here against physics computed here
(a closed box, closed forms, step counts), never against physval's own numbers.

  scripts/hunt7.py [BUILD_DIR] [WORKDIR] [--family F,...] [-j N] [--quick]

Families:
  particles  explosions and trails (20-3000 m/s) in a closed box of walls or a surface loop,
             core's `exact` and `lecture` collision modes, destroy_on_collision both ways, dt
             1/60 and 1/10, sampled every step: a run with an alive particle outside the box
             at any sample must not be `ok` (containment follows particles since this hunt).
  graze      a 0.5 m ball at 80 m/s passing a resting 0.5 m ball within one 1/30 s step,
             0.55-0.95 of the radii's sum off its centre (an overlap on the straight relative
             path of 0.1-0.9 of the radius), equal masses, e = 1: the closed form is the
             elastic impact. A run in which b never moved went through the other ball or
             skipped the glancing impact: it must not be `ok` (deeper than half the radius the
             escape rule; shallower, since graze2, the skipped impact against the reference).
  long       a free point over 1e6-1e7 steps with a short last step (duration not a whole
             number of steps), core: the final position v T to round-off and `steps` = the
             step count; and `physval run --dt`, `physval sweep --dt` / `--duration` past the
             most steps a run takes (1e9) must be bad input (exit 2), never run.
  massratio  two balls touching at t = 0 and closing (mass ratios 1e-9..1e9, e 0, 0.5, 1) and
             a light ball resting on a heavy one on a floor: the closed form (they part at once
             with Newton's velocities); core must meet it, and no engine may be `ok` with its
             position_divergence below its own miss of the closed form.
  materials  head-on pairs whose bodies have unequal restitution (the pair's is the smaller):
             the closed form, judged as massratio.

Exit 1 when any finding (a wrong green, or core/the reference off its closed form), 0 when
none, 2 on a usage error.
"""
import csv, json, math, os, subprocess, sys

NOTES = []


def fmt(x):
    return repr(float(x))


def vec(v):
    return f"[{fmt(v[0])}, {fmt(v[1])}]"


def box_walls(w, h, e, as_surface=False):
    c = [(-w, 0.0), (w, 0.0), (w, h), (-w, h)]
    if as_surface:   # counter-clockwise loop: the surface faces its left, the inside
        pts = ", ".join(vec(p) for p in c + [c[0]])
        return f'[[surfaces]]\nname = "loop"\npoints = [{pts}]\nrestitution = {fmt(e)}\n'
    s = ""
    for k in range(4):
        a, b = c[k], c[(k + 1) % 4]
        s += f'[[walls]]\nname = "w{k}"\nfrom = {vec(a)}\nto = {vec(b)}\nrestitution = {fmt(e)}\n'
    return s


# ---------------------------------------------------------------- particles
def gen_particles(out, truth, quick):
    w, h = 1.0, 2.0
    for mode in ["explode", "trail"]:
        for speed in ([300.0] if quick else [20.0, 300.0, 3000.0]):
            for coll in ["exact", "lecture"]:
                for destroy in ([False] if quick else [False, True]):
                    for cont in (["walls"] if quick else ["walls", "surface"]):
                        for dts_ in (["1/60"] if quick else ["1/60", "1/10"]):
                            name = f"p7_{mode}_v{int(speed)}_{coll}_d{int(destroy)}_{cont}_dt{dts_.replace('/', 'o')}"
                            text = f"""name = "{name}"
duration = 1.0
dt = "{dts_}"
sample_interval = "{dts_}"
[world]
gravity = [0.0, -9.8]
[[bodies]]
name = "shell"
radius = 0.05
position = [0.1, 1.0]
velocity = [0.5, 1.0]
{box_walls(w, h, 0.8, cont == "surface")}
[[emitters]]
name = "em"
parent = "shell"
mode = "{mode}"
{"at = 0.1" if mode == "explode" else "rate = 60.0"}
{"count = 60" if mode == "explode" else ""}
speed = {fmt(speed)}
lifetime = 2.0
destroy_on_collision = {"true" if destroy else "false"}
seed = 3
[core]
collision = "{coll}"
"""
                            open(os.path.join(out, name + ".toml"), "w").write(text)
                            truth[name] = dict(family="particles", w=w, h=h)


def judge_particles(name, t, res, out, find):
    for r in res["runs"]:
        if r["engine"] != "core":
            continue
        path = os.path.join(out, "series", name, "core.csv")
        rows = list(csv.reader(open(path)))
        head = rows[0]
        cols = [i for i, c in enumerate(head) if c.startswith("x_em#")]
        outside, first = 0, None
        for row in rows[1:]:
            for i in cols:
                try:
                    x, y = float(row[i]), float(row[i + 1])
                except ValueError:
                    continue
                if x != x or y != y:
                    continue   # not born yet, or dead
                if not (-t["w"] - 1e-9 <= x <= t["w"] + 1e-9 and -1e-9 <= y <= t["h"] + 1e-9):
                    outside += 1
                    first = first or (row[0], head[i][2:], x, y)
        if outside and r["status"] == "ok":
            find(name, "core", f"`ok` with particles outside the closed box at {outside} particle-samples (first {first})")
        elif outside:
            NOTES.append(f"{name} [core]: {r['status']}, particles outside the box ({outside} particle-samples): "
                         f"{r['reason'][:90]}")
        elif r["status"] != "ok":
            NOTES.append(f"{name} [core]: {r['status']} with every particle inside: {r['reason'][:90]}")


# ---------------------------------------------------------------- graze
def elastic_equal(off, v):
    """Equal masses, e = 1, a at (-, off) moving +x at v, b at rest: (va, vb) after the impact."""
    n = (math.sqrt(1 - off * off), -off)   # from a (above, at y = off) to b at contact, unit (radii sum 1)
    vn = v * n[0]
    return (v - vn * n[0], -vn * n[1]), (vn * n[0], vn * n[1])


def gen_graze(out, truth, quick):
    offs = [0.6, 0.75, 0.8, 0.9] if quick else [0.55, 0.6, 0.65, 0.7, 0.74, 0.76, 0.8, 0.85, 0.9, 0.95]
    for off in offs:
        name = f"graze_off{int(round(off * 100))}"
        text = f"""name = "{name}"
duration = 0.5
dt = "1/30"
[[bodies]]
name = "a"
radius = 0.5
position = [-1.4, {fmt(off)}]
velocity = [80.0, 0.0]
restitution = 1.0
[[bodies]]
name = "b"
radius = 0.5
position = [0.0, 0.0]
restitution = 1.0
"""
        open(os.path.join(out, name + ".toml"), "w").write(text)
        va, vb = elastic_equal(off, 80.0)
        truth[name] = dict(family="graze", off=off, va=va, vb=vb, depth=(1.0 - off) / 0.5)


def judge_graze(name, t, res, out, find):
    for r in res["runs"]:
        if r["status"] == "unsupported":
            continue
        fin = {b["body"]: b for b in r["final"]}
        va, vb = fin["a"]["velocity"], fin["b"]["velocity"]
        # b never moved: nothing struck it (a may have been slowed by Box2D's speed cap)
        untouched = abs(va[1]) < 1e-3 and math.hypot(*vb) < 1e-3
        miss = max(math.hypot(va[0] - t["va"][0], va[1] - t["va"][1]), math.hypot(vb[0] - t["vb"][0], vb[1] - t["vb"][1]))
        if r["engine"] == "core" and miss > 1e-6:
            find(name, "core", f"off the elastic impact's closed form by {miss:.3g} m/s ({r['status']})")
        if untouched and r["status"] == "ok":
            # Deeper than half the radius: the escape rule; shallower (more than its 2% slop):
            # a skipped impact against the converged reference's contact (graze2).
            find(name, r["engine"], f"passed {t['depth']:.2f} of the radius into the other ball untouched, `ok`")


# ---------------------------------------------------------------- long runs
def gen_long(out, truth, quick):
    for steps in ([1_000_000] if quick else [1_000_000, 3_000_000]):
        dt = 1e-3
        T = (steps - 0.5) * dt   # the last step is half a step
        name = f"long_{steps}"
        text = f"""name = "{name}"
duration = {fmt(T)}
dt = {fmt(dt)}
engines = ["core"]
[[bodies]]
name = "a"
shape = "point"
position = [0.0, 0.0]
velocity = [3.0, -2.0]
"""
        open(os.path.join(out, name + ".toml"), "w").write(text)
        truth[name] = dict(family="long", steps=steps, x=(3.0 * T, -2.0 * T))


def judge_long(name, t, res, out, find):
    for r in res["runs"]:
        if r["engine"] != "core":
            continue
        if r["steps"] != t["steps"]:
            find(name, "core", f"{r['steps']} steps, the duration takes {t['steps']}")
        x = r["final"][0]["position"]
        err = math.hypot(x[0] - t["x"][0], x[1] - t["x"][1])
        if err > 1e-9 * math.hypot(*t["x"]) * max(1.0, t["steps"] / 1e6):
            find(name, "core", f"final position {x} off v T = {t['x']} by {err:.3g} m ({r['status']})")


def long_limits(physval, work, find):
    """Step counts past Scene::kMaxSteps through every door: exit 2, at once."""
    p = os.path.join(work, "limit.toml")
    open(p, "w").write('name = "limit"\nduration = 900000000.0\ndt = 1.0\n[[bodies]]\nname = "a"\nshape = "point"\n'
                       'position = [0.0, 0.0]\nvelocity = [1.0, 0.0]\n')
    for args in (["run", p, "--dt", "1e-3"], ["run", p, "--duration", "2e9"], ["gate", p, "--dt", "0.5"],
                 ["sweep", p, "--dt", "1,1e-3"], ["sweep", p, "--dt", "1", "--duration", "4294967296"],
                 ["sweep", p, "--dt", "1,0.5"]):
        try:
            q = subprocess.run([physval] + args + ["--engines", "core", "--no-cache", "--out", os.path.join(work, "limit-out")],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, timeout=20)
            rc = q.returncode
        except subprocess.TimeoutExpired:
            rc = "still running after 20 s"
        if rc != 2:
            find("limit", "-", f"`physval {' '.join(args[:1] + args[2:])}` past 1e9 steps: exit {rc}, not 2 (bad input)")
    return 6


# ---------------------------------------------------------------- mass ratios touching at t = 0
def gen_massratio(out, truth, quick):
    ratios = [1e-9, 1e-3, 1.0, 1e3, 1e9] if quick else [1e-9, 1e-6, 1e-3, 1.0, 1e3, 1e6, 1e9]
    for q in ratios:
        for e in ([0.5] if quick else [0.0, 0.5, 1.0]):
            m1, m2 = 1.0, q
            u1, u2 = 2.0, -1.0
            v1 = (m1 * u1 + m2 * u2 - m2 * e * (u1 - u2)) / (m1 + m2)
            v2 = (m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2)
            T = 1.0
            name = f"mr_touch_q{q:.0e}_e{e}".replace(".", "p").replace("+", "").replace("-", "m")
            text = f"""name = "{name}"
duration = {fmt(T)}
dt = "1/60"
[[bodies]]
name = "a"
radius = 0.5
mass = {fmt(m1)}
position = [-0.5, 0.0]
velocity = [{fmt(u1)}, 0.0]
restitution = {fmt(e)}
[[bodies]]
name = "b"
radius = 0.5
mass = {fmt(m2)}
position = [0.5, 0.0]
velocity = [{fmt(u2)}, 0.0]
restitution = {fmt(e)}
"""
            open(os.path.join(out, name + ".toml"), "w").write(text)
            truth[name] = dict(family="massratio", vel={"a": (v1, 0.0), "b": (v2, 0.0)},
                               final={"a": (-0.5 + v1 * T, 0.0), "b": (0.5 + v2 * T, 0.0)}, scale=abs(u1 - u2) * T)


def gen_materials(out, truth, quick):
    """Per-pair restitution (the smaller of the two): head-on pairs with unequal e, apart at t = 0."""
    for ea, eb in ([(1.0, 0.3)] if quick else [(1.0, 0.3), (0.3, 1.0), (0.9, 0.5), (0.0, 1.0)]):
        for q in ([1.0] if quick else [1.0, 3.0, 1e3]):
            e = min(ea, eb)
            m1, m2, u1, u2 = 1.0, q, 2.0, -1.0
            v1 = (m1 * u1 + m2 * u2 - m2 * e * (u1 - u2)) / (m1 + m2)
            v2 = (m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2)
            tc = 1.0 / (u1 - u2)   # the gap of 1 m closes at 3 m/s
            T = 1.0
            name = f"mat_ea{ea}_eb{eb}_q{q:g}".replace(".", "p")
            text = f"""name = "{name}"
duration = {fmt(T)}
dt = "1/240"
[[bodies]]
name = "a"
radius = 0.5
mass = {fmt(m1)}
position = [-1.0, 0.0]
velocity = [{fmt(u1)}, 0.0]
restitution = {fmt(ea)}
[[bodies]]
name = "b"
radius = 0.5
mass = {fmt(m2)}
position = [1.0, 0.0]
velocity = [{fmt(u2)}, 0.0]
restitution = {fmt(eb)}
"""
            open(os.path.join(out, name + ".toml"), "w").write(text)
            xa = -1.0 + u1 * tc + v1 * (T - tc)
            xb = 1.0 + u2 * tc + v2 * (T - tc)
            truth[name] = dict(family="materials", final={"a": (xa, 0.0), "b": (xb, 0.0)}, scale=abs(u1 - u2) * T)


def judge_massratio(name, t, res, out, find):
    for r in res["runs"]:
        if r["status"] == "unsupported":
            continue
        fin = {b["body"]: b for b in r["final"]}
        miss = max(math.hypot(fin[b]["position"][0] - x[0], fin[b]["position"][1] - x[1]) for b, x in t["final"].items())
        if r["engine"] == "core" and miss > 1e-6 * t["scale"]:
            find(name, "core", f"off the closed form by {miss:.3g} m ({r['status']})")
        pd = r["metrics"].get("position_divergence")
        if r["status"] == "ok" and miss > 0.1 * t["scale"] and (pd is None or pd < 0.5 * miss):
            find(name, r["engine"], f"`ok`, {miss:.3g} m off the closed form, position_divergence {pd}")


# ---------------------------------------------------------------- driver
FAMILIES = {"particles": (gen_particles, judge_particles), "graze": (gen_graze, judge_graze),
            "long": (gen_long, judge_long), "massratio": (gen_massratio, judge_massratio),
            "materials": (gen_materials, judge_massratio)}


def main(argv):
    build, work, fams, jobs, quick = "build", "/tmp/hunt7", list(FAMILIES), 2, False
    pos = []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("--family", "-j") and i + 1 < len(argv):
            if a == "--family":
                fams = argv[i + 1].split(",")
            else:
                jobs = int(argv[i + 1])
            i += 2
            continue
        if a == "--quick":
            quick = True
        elif a.startswith("-"):
            print(__doc__)
            return 2
        else:
            pos.append(a)
        i += 1
    if pos:
        build = pos[0]
    if len(pos) > 1:
        work = pos[1]
    for f in fams:
        if f not in FAMILIES:
            print(f"unknown family {f}; one of {', '.join(FAMILIES)}", file=sys.stderr)
            return 2
    physval = os.path.join(build, "physval")
    findings = []

    def find(scen, engine, what):
        findings.append((scen, engine, what))

    total_runs = 0
    for fam in fams:
        out = os.path.join(work, fam)
        scenes = os.path.join(out, "scenes")
        os.makedirs(scenes, exist_ok=True)
        for f in os.listdir(scenes):
            os.remove(os.path.join(scenes, f))
        truth = {}
        gen, judge = FAMILIES[fam]
        gen(scenes, truth, quick)
        res_dir = os.path.join(out, "out")
        p = subprocess.run([physval, "run", scenes, "--out", res_dir, "-j", str(jobs), "--no-cache", "--series-csv"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if p.returncode not in (0, 1):
            print(f"{fam}: physval run exited {p.returncode}: {p.stderr[-400:]}", file=sys.stderr)
            return 2
        data = json.load(open(os.path.join(res_dir, "results.json")))
        by = {}
        for r in data["runs"]:
            by.setdefault(r["scenario"], {"runs": []})["runs"].append(r)
            total_runs += 1
        n0 = len(findings)
        for name, t in truth.items():
            if name not in by:
                find(name, "-", "no runs")
                continue
            judge(name, t, by[name], res_dir, find)
        extra = long_limits(physval, out, find) if fam == "long" else 0
        print(f"{fam}: {len(truth)} scenes, {sum(len(by[n]['runs']) for n in by)} runs"
              f"{f' + {extra} limit commands' if extra else ''}, {len(findings) - n0} findings", flush=True)
    for scen, engine, what in findings:
        print(f"FINDING {scen} [{engine}]: {what}")
    for n in NOTES:
        print(f"note {n}")
    print(f"hunt7: {total_runs} runs, {len(findings)} findings, {len(NOTES)} notes")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
