#!/usr/bin/env python3
"""The e < 1 bounce grid (branch verdict10): a ball dropped from h on a floor, restitution e on
ball and floor, uniform gravity, a step of k fall times t_f = sqrt(2 h / g), duration
2 dt + 0.37 t_f (two steps and a short last one). Writes the 32 scenes, runs physval on them
(core only, or --engines), and holds core's final state against the closed form
(hunt8.bounce_state): prints, per scene, core's status, its reason's head and its error.

  python3 scripts/bouncegrid.py build/physval OUT [--engines core]
"""
import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from hunt8 import G0, bounce_state, fmt, ident  # noqa: E402

R = 0.1


def scenes():
    for h in [0.1, 1.0]:
        tf = math.sqrt(2 * h / G0)
        for e in [0.7, 0.9, 0.95, 0.99]:
            for k in [0.5, 3.0, 10.0, 30.0]:
                dt = k * tf
                T = 2 * dt + 0.37 * tf
                y, vy = bounce_state(h, e, T)
                name = f"bounce_h{ident(h)}_e{ident(e)}_x{ident(k)}"
                text = f"""name = "{name}"
duration = {fmt(T)}
dt = {fmt(dt)}
[world]
gravity = [0.0, {fmt(-G0)}]
[[bodies]]
name = "b"
radius = {fmt(R)}
position = [0.0, {fmt(h + R)}]
restitution = {fmt(e)}
[[walls]]
name = "floor"
from = [-1.0, 0.0]
to = [1.0, 0.0]
restitution = {fmt(e)}
"""
                yield name, text, (y + R, vy), h


def e_of(name):
    return float(name.split("_e")[1].split("_")[0].replace("p", "."))


def main():
    physval, out = sys.argv[1], sys.argv[2]
    engines = sys.argv[sys.argv.index("--engines") + 1] if "--engines" in sys.argv else "core"
    sdir = os.path.join(out, "scenes")
    os.makedirs(sdir, exist_ok=True)
    truth = {}
    for name, text, (y, vy), h in scenes():
        open(os.path.join(sdir, name + ".toml"), "w").write(text)
        truth[name] = (y, vy, h)
    subprocess.run([physval, "run", sdir, "--engines", engines, "--out", os.path.join(out, "run"), "-j2", "--no-cache", "--series-csv",
                    "--quiet"], check=False)
    res = json.load(open(os.path.join(out, "run", "results.json")))
    okwrong = 0
    for r in sorted(res["runs"], key=lambda r: (r["scenario"], r["engine"])):
        y, vy, h = truth[r["scenario"]]
        f = r["final"][0]
        dy = abs(f["position"][1] - y)
        dv = abs(f["velocity"][1] - vy)
        # every sampled state too (series/<scenario>/<engine>.csv: t, ..., x_b, y_b)
        csv = os.path.join(out, "run", "series", r["scenario"], r["engine"] + ".csv")
        if os.path.exists(csv):
            for line in open(csv).read().split("\n")[1:]:
                if not line:
                    continue
                c = line.split(",")
                yt, _ = bounce_state(h, e_of(r["scenario"]), float(c[0]))
                dy = max(dy, abs(float(c[-1]) - (yt + R)))
        wrong = dy > 1e-6 * h + 1e-9 or dv > 1e-6 * math.sqrt(2 * G0 * h)
        if r["status"] == "ok" and wrong:
            okwrong += 1
        print(f'{r["scenario"]:26s} {r["engine"]:6s} {r["status"]:9s} max dy {dy:9.3g} m final dv {dv:9.3g} m/s '
              f'{"WRONG" if wrong else "right"}{"  <-- ok and wrong" if r["status"] == "ok" and wrong else ""}  '
              f'{r["reason"][:150]}')
    print(f"ok and wrong: {okwrong} of {len(res['runs'])}")


if __name__ == "__main__":
    main()
