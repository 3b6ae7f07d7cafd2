#!/usr/bin/env python3
"""The twelfth hunt: features combined, each scene run through `physval` on every engine and
judged here against physics computed here (closed forms, an RK4 at a tiny step), never against
physval's own numbers. Helpers (fmt, vec, ident, write, the final-state judge, run_hunt) come
from scripts/hunt8.py.

  scripts/hunt12.py [BUILD_DIR] [WORKDIR] [--family F,...] [-j N] [--quick]

Families:
  rotplane     a ball under gravity and a thrust table (constant, along a heading) meeting one
               wall drawn at 0-2.5 rad, e 0 and 0.5, mu 0-0.6: the flight, the impact with
               Coulomb friction (dvt = min(mu (1 + e) vn, vt)), sliding along the wall with the
               thrust's and gravity's normal parts pressing it, to a stop and held or on.
  dragslope    a ball released on a slope drawn as a rotated wall (0.2-1.0 rad), friction, and
               linear drag towards a wind with a part along the normal (which changes the normal
               force), or quadratic drag in still air: the closed forms (exp, tanh).
  quadbounce   a ball with quadratic drag dropped onto a floor, e 0.5-1: the fall (tanh), the
               rise (tan), bounce by bounce; and thrown at a wall with quadratic drag and
               gravity, bounced off it (RK4 at 1e-4 s with the impact located to 1e-13 s).
  rotbox       a point or a 5 cm ball at 5-5000 m/s in a square box of four walls rotated by
               0.1-0.785 rad, no gravity, e 1: the unfolded straight line; no engine may be
               `ok` with the body outside the box.
  staticball   a ball thrown under gravity at a static circle, off its centre line, e 1 and
               0.5: the parabola to the impact (root of |p(t) - c| = R + r), the reflection
               about the normal, the parabola on.
  dome         a ball sliding over the top of a static circle (v0^2 < g (R + r)), mu 0 and 0.1,
               e 0 and 1: turning about it until N = 0 (RK4), then the parabola. Known: with e 1
               core hits its event cap at once (a finding per scene, not fixed); with e 0 it
               micro-bounces (first order, the reference honestly "not converged").
  pocket       a ball dropped onto two static circles side by side: both impacts at once, on
               the centre line, bouncing with e (0, 0.5, 1) and at rest in the pocket.
  triple       2, 3 or 4 balls at equal angles meeting a resting ball of mass 0.5-100 at one
               instant: by symmetry it stays at rest and each comes back at e v.
  thrustwall   a speed-dependent thrust table (one row, or gear rows at gear 2.4, throttle 0.7)
               carrying a ball into a wall drawn at 0, 0.4 and 2.2 rad, e 0-1, with and without
               linear drag: RK4 at 1e-4 s with the impacts located by bisection and a ball pressed
               onto the wall held there; without drag the reference must converge.
  newtonwall   two equal bodies under Newtonian gravity (softening 0 and 0.5 m) falling onto a
               wall between them, e 1 and 0.5: RK4 of the separation, bounce by bounce.

Every family: core (exact for piecewise-constant forces) must meet the closed form to 1e-6 of
the scene's size where the family says so; a converged reference must meet it within ten
times its convergence error; no engine may be `ok` with its position_divergence below half its
miss of the closed form (a miss above 2% of the size). Exit 1 when any finding, 0 when none,
2 on a usage error.
"""
import math, os, sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hunt8  # noqa: E402
from hunt8 import fmt, vec, ident, write, G0 as G  # noqa: E402


def rot(v, a):
    c, s = math.cos(a), math.sin(a)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


# ---------------------------------------------------------------- rotplane
def plane_ball(p, v, A, e, mu, T, r, max_impacts=4):
    """A ball (radius r) with constant acceleration A over the plane y = 0 (local frame), from
    p, v (p[1] >= r). Returns (p, v, kind) at T or None when the scene is too close to a
    threshold or makes more impacts than max_impacts (Zeno) so the closed form would be long."""
    x, y = p
    vx, vy = v
    ax, ay = A
    t = 0.0
    impacts = 0
    while True:
        # on the plane: sliding or held
        if abs(y - r) < 1e-12 and abs(vy) < 1e-12:
            if ay >= -1e-9:
                return None   # lifted or grazing: not this family
            n = -ay
            rem = T - t
            if abs(vx) > 1e-12:
                s = 1.0 if vx > 0 else -1.0
                a = ax - s * mu * n
                if a * s < 0:   # decelerating: stops?
                    ts = -vx / a
                    if ts < rem:
                        x += vx * ts + 0.5 * a * ts * ts
                        t += ts
                        vx = 0.0
                        if abs(abs(ax) - mu * n) < 0.05:
                            return None
                        continue
                x += vx * rem + 0.5 * a * rem * rem
                vx += a * rem
                return (x, r), (vx, 0.0), "slides"
            if abs(ax) <= mu * n:
                if mu * n - abs(ax) < 0.05:
                    return None
                return (x, r), (0.0, 0.0), "held"
            s = 1.0 if ax > 0 else -1.0
            a = ax - s * mu * n
            x += 0.5 * a * rem * rem
            return (x, r), (a * rem, 0.0), "slides"
        # flight to y = r: y + vy t + ay t^2 / 2 = r
        h = y - r
        # the first root of h + vy t + ay t^2 / 2 = 0 with t > 0
        disc = vy * vy - 2 * ay * h
        if ay == 0.0:
            tc = -h / vy if vy < 0 else math.inf
        elif disc < 0:
            tc = math.inf
        else:
            roots = sorted(x for x in ((-vy - math.sqrt(disc)) / ay, (-vy + math.sqrt(disc)) / ay) if x > 1e-12)
            tc = roots[0] if roots else math.inf
            if ay > 0 and abs(disc) < 0.05 * vy * vy:
                return None   # a graze of the plane: either answer is round-off
        if t + tc >= T:
            dt = T - t
            if abs(t + tc - T) < 1e-3:
                return None
            return (x + vx * dt + 0.5 * ax * dt * dt, y + vy * dt + 0.5 * ay * dt * dt), (vx + ax * dt, vy + ay * dt), "flies"
        x += vx * tc + 0.5 * ax * tc * tc
        vx += ax * tc
        vn = -(vy + ay * tc)
        t += tc
        y = r
        impacts += 1
        if impacts > max_impacts or vn < 0.3:
            return None
        dvt = min(mu * (1 + e) * vn, abs(vx))
        if abs(mu * (1 + e) * vn - abs(vx)) < 0.02:
            return None
        vx -= math.copysign(dvt, vx) if vx != 0 else 0.0
        if abs(vx) < 1e-12:
            vx = 0.0
        vy = e * vn
        if e == 0.0:
            vy = 0.0


def gen_rotplane(out, truth, quick):
    r, T, m = 0.2, 2.0, 1.5
    alphas = [0.0, 0.5, 2.5] if quick else [0.0, 0.3, 0.5, 1.1, 1.9, 2.5, -0.7]
    thrusts = [(6.0, 0.3)] if quick else [(0.0, 0.0), (6.0, 0.3), (6.0, -2.0), (14.0, -1.2), (4.0, 3.0)]
    es = [0.0, 0.5]
    mus = [0.3] if quick else [0.0, 0.3, 0.6]
    starts = [((0.0, 1.0), (2.0, 0.0))] if quick else [((0.0, 1.0), (2.0, 0.0)), ((0.0, 2.0), (-1.0, -3.0))]
    for al in alphas:
        for a, beta in thrusts:
            for e in es:
                for mu in mus:
                    for si, (p0, v0) in enumerate(starts):
                        g_loc = rot((0.0, -G), -al)
                        A = (g_loc[0] + a * math.cos(beta), g_loc[1] + a * math.sin(beta))
                        res = plane_ball(p0, v0, A, e, mu, T, r)
                        if res is None:
                            continue
                        pl, vl, kind = res
                        pw, vw = rot(pl, al), rot(vl, al)
                        name = f"rp_al{ident(al)}_a{ident(a)}_b{ident(beta)}_e{ident(e)}_mu{ident(mu)}_s{si}"
                        L = 400.0
                        fr, to = rot((-L, 0.0), al), rot((L, 0.0), al)
                        thrust = "" if a == 0.0 else f"""[bodies.thrust]
speeds = [0.0, 1000.0]
accel = [{fmt(a)}, {fmt(a)}]
"""
                        write(out, name, f"""name = "{name}"
duration = {fmt(T)}
dt = "1/60"
[world]
gravity = [0.0, {fmt(-G)}]
[[bodies]]
name = "b"
radius = {fmt(r)}
mass = {fmt(m)}
position = {vec(rot(p0, al))}
velocity = {vec(rot(v0, al))}
angle = {fmt(al + beta)}
friction = {fmt(mu)}
restitution = {fmt(e)}
{thrust}[[walls]]
name = "plane"
from = {vec(fr)}
to = {vec(to)}
friction = {fmt(mu)}
restitution = {fmt(e)}
""")
                        truth[name] = dict(final={"b": (pw, vw)}, exact=True, scale=max(1.0, math.dist(pw, rot(p0, al))), kind=kind)


# ---------------------------------------------------------------- dragslope
def gen_dragslope(out, truth, quick):
    r, T, m = 0.2, 2.5, 2.0
    ths = [0.4] if quick else [0.2, 0.4, 0.7, 1.0]
    mus = [0.2] if quick else [0.0, 0.2, 0.5]
    for th in ths:
        # the slope goes down to the right: direction d = (cos th, -sin th), outward normal n = (sin th, cos th)
        d = (math.cos(th), -math.sin(th))
        n = (math.sin(th), math.cos(th))
        for mu in mus:
            # linear drag towards a wind
            for k in ([0.8] if quick else [0.3, 0.8, 2.0]):
                for w in ([(3.0, 4.0)] if quick else [(0.0, 0.0), (3.0, 4.0), (-5.0, 2.0), (4.0, -6.0)]):
                    c = k / m
                    wt = w[0] * d[0] + w[1] * d[1]
                    wn = w[0] * n[0] + w[1] * n[1]
                    N = G * math.cos(th) - c * wn     # per unit mass, pressing
                    if N < 0.3:
                        continue
                    push = G * math.sin(th) + c * wt     # along d, at rest
                    if abs(abs(push) - mu * N) < 0.1:
                        continue
                    if abs(push) <= mu * N:
                        s, vend = 0.0, 0.0
                        kind = "held"
                    else:
                        sg = 1.0 if push > 0 else -1.0
                        A = push - sg * mu * N     # v' = A - c v (v along d, from 0, keeps sign sg)
                        vinf = A / c
                        vend = vinf * (1 - math.exp(-c * T))
                        s = vinf * (T - (1 - math.exp(-c * T)) / c)
                        kind = "slides"
                    p0 = (n[0] * r, n[1] * r)
                    pw = (p0[0] + s * d[0], p0[1] + s * d[1])
                    vw = (vend * d[0], vend * d[1])
                    name = f"ds_th{ident(th)}_mu{ident(mu)}_k{ident(k)}_w{ident(w[0])}_{ident(w[1])}"
                    write(out, name, f"""name = "{name}"
duration = {fmt(T)}
[world]
gravity = [0.0, {fmt(-G)}]
wind = {vec(w)}
[[bodies]]
name = "b"
radius = {fmt(r)}
mass = {fmt(m)}
position = {vec(p0)}
friction = {fmt(mu)}
restitution = 0.0
drag_linear = {fmt(k)}
[[walls]]
name = "slope"
from = {vec((-100 * d[0], -100 * d[1]))}
to = {vec((100 * d[0], 100 * d[1]))}
friction = {fmt(mu)}
restitution = 0.0
""")
                    truth[name] = dict(final={"b": (pw, vw)}, exact=False, scale=max(1.0, abs(s)), kind=kind)
            # quadratic drag in still air: v' = A - c2 v^2
            for k2 in ([0.1] if quick else [0.02, 0.1, 0.5]):
                c2 = k2 / m
                A = G * math.sin(th) - mu * G * math.cos(th)
                if A < 0.2:
                    continue
                V = math.sqrt(A / c2)
                q = math.sqrt(A * c2)
                vend = V * math.tanh(q * T)
                s = math.log(math.cosh(q * T)) / c2
                p0 = (n[0] * r, n[1] * r)
                pw = (p0[0] + s * d[0], p0[1] + s * d[1])
                vw = (vend * d[0], vend * d[1])
                name = f"dsq_th{ident(th)}_mu{ident(mu)}_k{ident(k2)}"
                write(out, name, f"""name = "{name}"
duration = {fmt(T)}
[world]
gravity = [0.0, {fmt(-G)}]
[[bodies]]
name = "b"
radius = {fmt(r)}
mass = {fmt(m)}
position = {vec(p0)}
friction = {fmt(mu)}
restitution = 0.0
drag_quadratic = {fmt(k2)}
[[walls]]
name = "slope"
from = {vec((-100 * d[0], -100 * d[1]))}
to = {vec((100 * d[0], 100 * d[1]))}
friction = {fmt(mu)}
restitution = 0.0
""")
                truth[name] = dict(final={"b": (pw, vw)}, exact=False, scale=max(1.0, abs(s)), kind="slides")


# ---------------------------------------------------------------- quadbounce
def quad_drop(h, e, c, T, r):
    """A ball dropped from rest at height h (centre r + h) with quadratic drag c = k2 / m onto a
    floor, restitution e: (y, vy) at T, or None when too many bounces."""
    V = math.sqrt(G / c)
    y, v, t = h, 0.0, 0.0   # y: height of the bottom above the floor
    for _ in range(8):
        # fall from y with downward speed s0 = -v >= 0
        s0 = -v
        ph0 = math.atanh(s0 / V)
        tf = (math.acosh(math.cosh(ph0) * math.exp(G * y / V ** 2)) - ph0) * V / G
        if t + tf >= T:
            dt = T - t
            ph = G * dt / V + ph0
            fallen = V ** 2 / G * (math.log(math.cosh(ph)) - math.log(math.cosh(ph0)))
            return y - fallen + r, -V * math.tanh(ph)
        t += tf
        vi = V * math.tanh(G * tf / V + ph0)
        if abs(t - T) < 1e-3 or vi < 0.3:
            return None
        u = e * vi   # up
        ps = math.atan(u / V)
        ta = V * ps / G
        if t + ta >= T:
            dt = T - t
            a = ps - G * dt / V
            return V ** 2 / G * math.log(math.cos(a) / math.cos(ps)) + r, V * math.tan(a)
        t += ta
        y = V ** 2 / G * math.log(1 / math.cos(ps))
        v = 0.0
        if abs(t - T) < 1e-3:
            return None
    return None


def rk4_drag_wall(p, v, k2, m, wall_x, e, T, r, h=1e-4):
    """A ball with quadratic drag and gravity thrown at a vertical wall x = wall_x (its face at
    wall_x - r for the centre), restitution e, one impact at most, located by bisection."""
    c = k2 / m

    def f(s):
        x, y, vx, vy = s
        sp = math.hypot(vx, vy)
        return (vx, vy, -c * sp * vx, -G - c * sp * vy)

    def step(s, dt):
        k1 = f(s)
        k2_ = f(tuple(a + dt / 2 * b for a, b in zip(s, k1)))
        k3 = f(tuple(a + dt / 2 * b for a, b in zip(s, k2_)))
        k4 = f(tuple(a + dt * b for a, b in zip(s, k3)))
        return tuple(a + dt / 6 * (b1 + 2 * b2 + 2 * b3 + b4) for a, b1, b2, b3, b4 in zip(s, k1, k2_, k3, k4))

    s = (p[0], p[1], v[0], v[1])
    t = 0.0
    hit = False
    face = wall_x - r
    while t < T - 1e-15:
        dt = min(h, T - t)
        s2 = step(s, dt)
        if not hit and s2[0] > face:
            lo, hi = 0.0, dt
            for _ in range(60):
                mid = (lo + hi) / 2
                if step(s, mid)[0] > face:
                    hi = mid
                else:
                    lo = mid
            sc = step(s, lo)
            s = (face, sc[1], -e * sc[2], sc[3])
            t += lo
            hit = True
            if abs(t - T) < 1e-3:
                return None
            continue
        s, t = s2, t + dt
    if not hit:
        return None
    return (s[0], s[1]), (s[2], s[3])


def gen_quadbounce(out, truth, quick):
    r, m = 0.1, 0.5
    for h in ([2.0] if quick else [0.5, 2.0, 8.0]):
        for e in ([0.8] if quick else [0.5, 0.8, 1.0]):
            for k2 in ([0.02] if quick else [0.005, 0.02, 0.1]):
                T = 3.0
                res = quad_drop(h, e, k2 / m, T, r)
                if res is None:
                    continue
                y, vy = res
                name = f"qb_h{ident(h)}_e{ident(e)}_k{ident(k2)}"
                write(out, name, f"""name = "{name}"
duration = {fmt(T)}
dt = "1/120"
[world]
gravity = [0.0, {fmt(-G)}]
[[bodies]]
name = "b"
radius = {fmt(r)}
mass = {fmt(m)}
position = [0.0, {fmt(h + r)}]
restitution = {fmt(e)}
drag_quadratic = {fmt(k2)}
[[walls]]
name = "floor"
from = [-50.0, 0.0]
to = [50.0, 0.0]
restitution = {fmt(e)}
""")
                truth[name] = dict(final={"b": ((0.0, y), (0.0, vy))}, exact=False, scale=max(1.0, h), kind="drop")
    # thrown at a wall with air drag
    for spd in ([15.0] if quick else [8.0, 15.0, 30.0]):
        for ang in ([0.4] if quick else [0.2, 0.6]):
            for e in ([0.7] if quick else [0.4, 1.0]):
                k2, T, wall = 0.01, 1.2, 6.0
                v0 = (spd * math.cos(ang), spd * math.sin(ang))
                res = rk4_drag_wall((0.0, 5.0), v0, k2, m, wall, e, T, r)
                if res is None:
                    continue
                pw, vw = res
                name = f"qw_v{ident(spd)}_a{ident(ang)}_e{ident(e)}"
                write(out, name, f"""name = "{name}"
duration = {fmt(T)}
dt = "1/120"
[world]
gravity = [0.0, {fmt(-G)}]
[[bodies]]
name = "b"
radius = {fmt(r)}
mass = {fmt(m)}
position = [0.0, 5.0]
velocity = {vec(v0)}
restitution = {fmt(e)}
drag_quadratic = {fmt(k2)}
[[walls]]
name = "wall"
from = [{fmt(wall)}, -100.0]
to = [{fmt(wall)}, 100.0]
restitution = {fmt(e)}
""")
                truth[name] = dict(final={"b": (pw, vw)}, exact=False, scale=max(1.0, math.dist(pw, (0.0, 5.0))), kind="wall")


# ---------------------------------------------------------------- rotbox
def fold(u, lo, hi):
    w = hi - lo
    q = (u - lo) % (2 * w)
    return lo + (q if q <= w else 2 * w - q), (1.0 if q <= w else -1.0)


def gen_rotbox(out, truth, quick):
    T = 1.0
    for phi in ([0.3] if quick else [0.1, 0.3, 0.785, 1.2]):
        for W in ([4.0] if quick else [0.6, 4.0, 40.0]):
            for spd in ([500.0] if quick else [5.0, 50.0, 500.0, 5000.0]):
                for psi_name, psi in (("ax", 0.0), ("d17", math.radians(17.0)), ("diag", math.pi / 4)):
                    if quick and psi_name == "d17":
                        continue
                    for shape, r in (("point", 0.0), ("ball", 0.05)):
                        if W <= 4 * r:
                            continue
                        vl = (spd * math.cos(psi), spd * math.sin(psi))
                        pl0 = (0.0, 0.0) if psi_name != "diag" else (0.1 * W, -0.05 * W)
                        lo, hi = -W / 2 + r, W / 2 - r
                        x, sx = fold(pl0[0] + vl[0] * T, lo, hi)
                        y, sy = fold(pl0[1] + vl[1] * T, lo, hi)
                        pw, vw = rot((x, y), phi), rot((sx * vl[0], sy * vl[1]), phi)
                        corners = [rot(c, phi) for c in ((-W / 2, -W / 2), (W / 2, -W / 2), (W / 2, W / 2), (-W / 2, W / 2))]
                        walls = "".join(f"""[[walls]]
name = "w{i}"
from = {vec(corners[i])}
to = {vec(corners[(i + 1) % 4])}
""" for i in range(4))
                        body = 'shape = "point"' if r == 0 else f"radius = {fmt(r)}"
                        name = f"rb_phi{ident(phi)}_w{ident(W)}_v{ident(spd)}_{psi_name}_{shape}"
                        write(out, name, f"""name = "{name}"
duration = {fmt(T)}
[[bodies]]
name = "b"
{body}
position = {vec(rot(pl0, phi))}
velocity = {vec(rot(vl, phi))}
{walls}""")
                        truth[name] = dict(final={"b": (pw, vw)}, exact=True, scale=W, kind="box", box=(phi, W / 2),
                                           bounces=spd * T / W)


# ---------------------------------------------------------------- staticball
def gen_staticball(out, truth, quick):
    R, r, T = 1.0, 0.2, 1.6
    for off in ([0.5] if quick else [0.0, 0.2, 0.5, 0.9, 1.1]):
        for e in ([0.5] if quick else [1.0, 0.5]):
            for vx0 in ([0.0] if quick else [0.0, 1.5]):
                p0, v0 = (off - vx0 * 0.5, 4.0), (vx0, 0.0)

                def pos(t):
                    return (p0[0] + v0[0] * t, p0[1] + v0[1] * t - 0.5 * G * t * t)

                D = R + r

                def gap(t):
                    p = pos(t)
                    return math.hypot(*p) - D
                # first root of gap on [0, T] by scanning then bisection
                tc, n = None, 4000
                for i in range(n):
                    a, b = T * i / n, T * (i + 1) / n
                    if gap(a) > 0 >= gap(b):
                        for _ in range(100):
                            mid = (a + b) / 2
                            if gap(mid) > 0:
                                a = mid
                            else:
                                b = mid
                        tc = a
                        break
                if tc is None:
                    continue
                pc = pos(tc)
                vc = (v0[0], v0[1] - G * tc)
                d = math.hypot(*pc)
                nn = (pc[0] / d, pc[1] / d)
                vn = vc[0] * nn[0] + vc[1] * nn[1]
                if vn > -0.5 or abs(tc - T) < 0.05:
                    continue
                v1 = (vc[0] - (1 + e) * vn * nn[0], vc[1] - (1 + e) * vn * nn[1])
                rem = T - tc
                # no second impact before T
                ok = True
                for i in range(1, 2001):
                    s = rem * i / 2000
                    q = (pc[0] + v1[0] * s, pc[1] + v1[1] * s - 0.5 * G * s * s)
                    if math.hypot(*q) < D - 1e-9:
                        ok = False
                        break
                if not ok:
                    continue
                pw = (pc[0] + v1[0] * rem, pc[1] + v1[1] * rem - 0.5 * G * rem * rem)
                vw = (v1[0], v1[1] - G * rem)
                name = f"sb_off{ident(off)}_e{ident(e)}_vx{ident(vx0)}"
                write(out, name, f"""name = "{name}"
duration = {fmt(T)}
[world]
gravity = [0.0, {fmt(-G)}]
[[bodies]]
name = "b"
radius = {fmt(r)}
position = {vec(p0)}
velocity = {vec(v0)}
restitution = {fmt(e)}
[[bodies]]
name = "rock"
static = true
radius = {fmt(R)}
position = [0.0, 0.0]
restitution = {fmt(e)}
""")
                truth[name] = dict(final={"b": (pw, vw)}, exact=True, scale=max(1.0, math.dist(pw, p0)), kind="rock")


# ---------------------------------------------------------------- dome
def dome_state(D, v0, mu, T, h=2e-6):
    """A ball sliding over the top of a static circle (centre distance D), from the top at speed
    v0, kinetic friction mu: turning until N = 0 (RK4 at h), then the parabola. (p, v) at T,
    or None when it is still on the dome at T."""
    def f(s):
        ph, w = s
        n = G * math.cos(ph) - D * w * w
        return (w, (G * math.sin(ph) - mu * max(n, 0.0)) / D)
    s, t = (0.0, v0 / D), 0.0
    while G * math.cos(s[0]) - D * s[1] ** 2 > 0:
        if t >= T or (mu > 0 and s[1] <= 0):
            return None
        k1 = f(s)
        k2 = f((s[0] + h / 2 * k1[0], s[1] + h / 2 * k1[1]))
        k3 = f((s[0] + h / 2 * k2[0], s[1] + h / 2 * k2[1]))
        k4 = f((s[0] + h * k3[0], s[1] + h * k3[1]))
        s2 = (s[0] + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]), s[1] + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]))
        n2 = G * math.cos(s2[0]) - D * s2[1] ** 2
        if n2 <= 0:   # locate N = 0 within the step by bisection
            lo, hi = 0.0, h
            for _ in range(50):
                mid = (lo + hi) / 2
                k2m = f((s[0] + mid / 2 * k1[0], s[1] + mid / 2 * k1[1]))
                k3m = f((s[0] + mid / 2 * k2m[0], s[1] + mid / 2 * k2m[1]))
                k4m = f((s[0] + mid * k3m[0], s[1] + mid * k3m[1]))
                sm = (s[0] + mid / 6 * (k1[0] + 2 * k2m[0] + 2 * k3m[0] + k4m[0]), s[1] + mid / 6 * (k1[1] + 2 * k2m[1] + 2 * k3m[1] + k4m[1]))
                if G * math.cos(sm[0]) - D * sm[1] ** 2 > 0:
                    lo = mid
                else:
                    hi = mid
            s, t = sm, t + mid
            break
        s, t = s2, t + h
    ph, w = s
    if t >= T - 0.05:
        return None
    p = (D * math.sin(ph), D * math.cos(ph))
    v = (D * w * math.cos(ph), -D * w * math.sin(ph))
    rem = T - t
    return (p[0] + v[0] * rem, p[1] + v[1] * rem - 0.5 * G * rem * rem), (v[0], v[1] - G * rem)


def gen_dome(out, truth, quick):
    T = 1.5
    for R, r in ([(1.0, 0.2)] if quick else [(1.0, 0.2), (3.0, 0.05), (0.3, 0.3)]):
        for v0 in ([1.0] if quick else [0.3, 1.0, 2.0]):
            for mu in ([0.0] if quick else [0.0, 0.1]):
                for e in ([0.0] if quick else [0.0, 1.0]):
                    for dts in (["1/60"] if quick else ["1/60", "1/240"]):
                        D = R + r
                        if v0 * v0 >= G * D:
                            continue
                        res = dome_state(D, v0, mu, T)
                        if res is None:
                            continue
                        pw, vw = res
                        name = f"dome_rr{ident(R)}_r{ident(r)}_v{ident(v0)}_mu{ident(mu)}_e{ident(e)}_dt{dts.replace('/', 'o')}"
                        write(out, name, f"""name = "{name}"
duration = {fmt(T)}
dt = "{dts}"
[world]
gravity = [0.0, {fmt(-G)}]
[[bodies]]
name = "b"
radius = {fmt(r)}
position = [0.0, {fmt(D)}]
velocity = [{fmt(v0)}, 0.0]
restitution = {fmt(e)}
friction = {fmt(mu)}
[[bodies]]
name = "rock"
static = true
radius = {fmt(R)}
position = [0.0, 0.0]
restitution = {fmt(e)}
friction = {fmt(mu)}
""")
                        truth[name] = dict(final={"b": (pw, vw)}, exact=False, scale=max(1.0, math.dist(pw, (0.0, D))), kind="dome",
                                           elastic=(e == 1.0))


# ---------------------------------------------------------------- pocket
def gen_pocket(out, truth, quick):
    """A ball dropped onto two static circles side by side (a pocket): it meets both at once,
    symmetrically, so it stays on the centre line, bouncing with e and at rest (e 0) in the
    pocket: hunt8.bounce_state with the impact height sqrt((R + r)^2 - s^2)."""
    T = 2.0
    for R, r, s in ([(0.5, 0.3, 0.6)] if quick else [(0.5, 0.3, 0.6), (1.0, 0.1, 1.05), (0.2, 1.0, 1.0)]):
        for h in ([1.0] if quick else [0.3, 1.0]):
            for e in ([0.0, 1.0] if quick else [0.0, 0.5, 1.0]):
                for dts in (["1/60"] if quick else ["1/60", "1/33"]):
                    yc = math.sqrt((R + r) ** 2 - s * s)
                    y, vy = hunt8.bounce_state(h, e, T)
                    pw, vw = (0.0, yc + y), (0.0, vy)
                    name = f"pk_rr{ident(R)}_r{ident(r)}_s{ident(s)}_h{ident(h)}_e{ident(e)}_dt{dts.replace('/', 'o')}"
                    write(out, name, f"""name = "{name}"
duration = {fmt(T)}
dt = "{dts}"
[world]
gravity = [0.0, {fmt(-G)}]
[[bodies]]
name = "b"
radius = {fmt(r)}
position = [0.0, {fmt(yc + h)}]
restitution = {fmt(e)}
[[bodies]]
name = "left"
static = true
radius = {fmt(R)}
position = [{fmt(-s)}, 0.0]
restitution = {fmt(e)}
[[bodies]]
name = "right"
static = true
radius = {fmt(R)}
position = [{fmt(s)}, 0.0]
restitution = {fmt(e)}
""")
                    truth[name] = dict(final={"b": (pw, vw)}, exact=True, scale=max(1.0, h), kind="pocket")


# ---------------------------------------------------------------- triple
def gen_triple(out, truth, quick):
    """k balls (2 or 3, at equal angles) of mass m moving at speed v straight at a ball of mass M
    at rest, all meeting it at one instant: by symmetry M stays at rest, and each comes back at
    e v (any simultaneous law; a sequential one breaks the symmetry)."""
    T, rr, v, d0 = 2.0, 0.5, 2.0, 3.0
    for k in ([2, 3] if quick else [2, 3, 4]):
        for M in ([3.0] if quick else [0.5, 1.0, 3.0, 100.0]):
            for e in ([0.5] if quick else [0.0, 0.5, 1.0]):
                for rot0 in ([0.0] if quick else [0.0, 0.3]):
                    tc = (d0 - 2 * rr) / v
                    bodies = f"""[[bodies]]
name = "hub"
radius = {fmt(rr)}
mass = {fmt(M)}
position = [0.0, 0.0]
restitution = {fmt(e)}
"""
                    final = {"hub": ((0.0, 0.0), (0.0, 0.0))}
                    for i in range(k):
                        a = rot0 + 2 * math.pi * i / k
                        u = (math.cos(a), math.sin(a))
                        dist = 2 * rr + e * v * (T - tc)
                        final[f"s{i}"] = ((u[0] * dist, u[1] * dist), (u[0] * e * v, u[1] * e * v))
                        bodies += f"""[[bodies]]
name = "s{i}"
radius = {fmt(rr)}
mass = 1.0
position = {vec((u[0] * d0, u[1] * d0))}
velocity = {vec((-u[0] * v, -u[1] * v))}
restitution = {fmt(e)}
"""
                    name = f"tri_k{k}_m{ident(M)}_e{ident(e)}_rot{ident(rot0)}"
                    write(out, name, f"""name = "{name}"
duration = {fmt(T)}
{bodies}""")
                    truth[name] = dict(final=final, exact=True, scale=d0, kind="triple")


# ---------------------------------------------------------------- thrustwall
def interp(xs, ys, x):
    if x <= xs[0]:
        return ys[0]
    if x >= xs[-1]:
        return ys[-1]
    for i in range(len(xs) - 1):
        if x <= xs[i + 1]:
            u = (x - xs[i]) / (xs[i + 1] - xs[i])
            return ys[i] + u * (ys[i + 1] - ys[i])


def thrust_wall_state(v0, speeds, rows, gears, gear, throttle, k, m, X, e, T, r, h=1e-4):
    """Local frame: heading +x, a wall with its face at x = X - r for the centre, no gravity;
    thrust a = table(|v|, gear) throttle along +x, linear drag k towards still air. RK4 at h,
    impacts located by bisection, a contact that closes slower than 1e-7 m/s rests on the wall
    (the thrust then presses it; it slides along the frictionless wall). (p, v) at T or None."""
    if gears:
        gi = [interp(gears, [row[j] for row in rows], gear) for j in range(len(speeds))]
    else:
        gi = rows[0]

    def acc(vx, vy):
        a = interp(speeds, gi, math.hypot(vx, vy)) * throttle
        return a - k / m * vx, -k / m * vy

    def f(s, resting):
        x, y, vx, vy = s
        ax, ay = acc(vx, vy)
        if resting:
            return (0.0, vy, 0.0, ay)
        return (vx, vy, ax, ay)

    def step(s, dt, resting):
        k1 = f(s, resting)
        k2_ = f(tuple(a + dt / 2 * b for a, b in zip(s, k1)), resting)
        k3 = f(tuple(a + dt / 2 * b for a, b in zip(s, k2_)), resting)
        k4 = f(tuple(a + dt * b for a, b in zip(s, k3)), resting)
        return tuple(a + dt / 6 * (b1 + 2 * b2 + 2 * b3 + b4) for a, b1, b2, b3, b4 in zip(s, k1, k2_, k3, k4))

    face = X - r
    s, t, resting, impacts = (0.0, 0.0, v0[0], v0[1]), 0.0, False, 0
    while t < T - 1e-15:
        dt = min(h, T - t)
        s2 = step(s, dt, resting)
        if not resting and s2[0] > face:
            lo, hi = 0.0, dt
            for _ in range(60):
                mid = (lo + hi) / 2
                if step(s, mid, False)[0] > face:
                    hi = mid
                else:
                    lo = mid
            sc = step(s, lo, False)
            t += lo
            impacts += 1
            if abs(t - T) < 2e-3 or impacts > 200:
                return None
            vn = sc[2]
            if vn < 1e-7 or e == 0.0:
                if acc(0.0, sc[3])[0] <= 0:
                    return None   # not pressed: not this family
                resting = True
                s = (face, sc[1], 0.0, sc[3])
            else:
                if 0.0 < vn < 0.02:
                    return None   # a Zeno tail near T: core ends it at its rest speed
                s = (face, sc[1], -e * vn, sc[3])
            continue
        s, t = s2, t + dt
    if resting and acc(0.0, s[3])[0] <= 0:
        return None
    return (s[0], s[1]), (s[2], s[3])


def gen_thrustwall(out, truth, quick):
    r, m, T, X = 0.2, 2.0, 2.5, 3.0
    tables = {"lin": ([0.0, 4.0, 10.0], [[6.0, 3.0, 0.0]], None, 0.0),
              "gear": ([0.0, 5.0], [[2.0, 1.0], [8.0, 4.0]], [1.0, 3.0], 2.4)}
    for tname, (speeds, rows, gears, gear) in tables.items():
        for al in ([0.0] if quick else [0.0, 0.4, 2.2]):
            for v0 in ([(-3.0, 1.0), (12.0, 0.0)] if quick else [(0.0, 0.0), (-3.0, 1.0), (5.0, 4.0), (12.0, 0.0)]):
                for e in ([0.0, 0.5] if quick else [0.0, 0.5, 1.0]):
                    for k in ([0.0] if quick else [0.0, 0.6]):
                        throttle = 0.7
                        res = thrust_wall_state(v0, speeds, rows, gears, gear, throttle, k, m, X, e, T, r)
                        if res is None:
                            continue
                        pl, vl = res
                        pw, vw = rot(pl, al), rot(vl, al)
                        a_rows = "[" + ", ".join("[" + ", ".join(fmt(x) for x in row) + "]" for row in rows) + "]" if gears else \
                            "[" + ", ".join(fmt(x) for x in rows[0]) + "]"
                        gear_keys = f"gears = [{', '.join(fmt(g) for g in gears)}]\ngear = {fmt(gear)}\n" if gears else ""
                        fr, to = rot((X, -100.0), al), rot((X, 100.0), al)
                        name = f"tw_{tname}_al{ident(al)}_v{ident(v0[0])}_{ident(v0[1])}_e{ident(e)}_k{ident(k)}"
                        write(out, name, f"""name = "{name}"
duration = {fmt(T)}
[[bodies]]
name = "b"
radius = {fmt(r)}
mass = {fmt(m)}
position = [0.0, 0.0]
velocity = {vec(rot(v0, al))}
angle = {fmt(al)}
restitution = {fmt(e)}
drag_linear = {fmt(k)}
[bodies.thrust]
speeds = [{', '.join(fmt(x) for x in speeds)}]
accel = {a_rows}
{gear_keys}throttle = {fmt(throttle)}
[[walls]]
name = "wall"
from = {vec(fr)}
to = {vec(to)}
restitution = {fmt(e)}
""")
                        # without drag the reference must converge (main before hunt12: the event cap
                        # whenever the ball arrived where the table gives 0 and stopped, e 0)
                        truth[name] = dict(final={"b": (pw, vw)}, exact=False, scale=max(1.0, math.hypot(*pw)), kind="thrustwall",
                                           must_converge=(k == 0.0))


# ---------------------------------------------------------------- newtonwall
def newton_wall_state(GM2, x0, v0, e, T, r, soft=0.0, h=1e-4):
    """Two equal bodies at -x and +x (x > r) attracting each other (each a = -G m / ((2x)^2 + soft^2)
    times 2x / sqrt((2x)^2 + soft^2)), a wall x = 0 between them that both meet at once: x(t) by
    RK4 at h, impacts located by bisection. Returns (x, vx) at T or None."""
    def a_of(x):
        d = 2 * x
        return -GM2 * d / (d * d + soft * soft) ** 1.5

    def step(s, dt):
        x, v = s
        k1 = (v, a_of(x))
        k2 = (v + dt / 2 * k1[1], a_of(x + dt / 2 * k1[0]))
        k3 = (v + dt / 2 * k2[1], a_of(x + dt / 2 * k2[0]))
        k4 = (v + dt * k3[1], a_of(x + dt * k3[0]))
        return (x + dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0]), v + dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1]))

    s, t, n = (x0, v0), 0.0, 0
    while t < T - 1e-15:
        dt = min(h, T - t)
        s2 = step(s, dt)
        if s2[0] < r:
            lo, hi = 0.0, dt
            for _ in range(60):
                mid = (lo + hi) / 2
                if step(s, mid)[0] < r:
                    hi = mid
                else:
                    lo = mid
            sc = step(s, lo)
            t += lo
            n += 1
            if abs(t - T) < 2e-3 or n > 6 or -sc[1] < 0.05:
                return None
            s = (r, -e * sc[1])
            continue
        s, t = s2, t + dt
    return s


def gen_newtonwall(out, truth, quick):
    r, m = 0.2, 1.0
    for Gv in ([5.0] if quick else [1.0, 5.0, 20.0]):
        for x0 in ([2.0] if quick else [1.0, 2.0]):
            for e in ([0.5] if quick else [1.0, 0.5]):
                for soft in ([0.0] if quick else [0.0, 0.5]):
                    T = 3.0
                    GM2 = Gv * m
                    res = newton_wall_state(GM2, x0, 0.0, e, T, r, soft)
                    if res is None:
                        continue
                    x, v = res
                    name = f"nw_g{ident(Gv)}_x{ident(x0)}_e{ident(e)}_s{ident(soft)}"
                    write(out, name, f"""name = "{name}"
duration = {fmt(T)}
[world]
newtonian = true
G = {fmt(Gv)}
softening = {fmt(soft)}
[[bodies]]
name = "l"
radius = {fmt(r)}
mass = {fmt(m)}
position = [{fmt(-x0)}, 0.0]
restitution = {fmt(e)}
[[bodies]]
name = "r"
radius = {fmt(r)}
mass = {fmt(m)}
position = [{fmt(x0)}, 0.0]
restitution = {fmt(e)}
[[walls]]
name = "wall"
from = [0.0, -10.0]
to = [0.0, 10.0]
restitution = {fmt(e)}
""")
                    truth[name] = dict(final={"l": ((-x, 0.0), (-v, 0.0)), "r": ((x, 0.0), (v, 0.0))}, exact=False,
                                       scale=max(1.0, x0), kind="newtonwall")


# ---------------------------------------------------------------- judging
def judge_box(name, t, runs, find):
    phi, half = t["box"]
    for r in runs:
        if r["status"] in ("unsupported", "error"):
            continue
        fin = {b["body"]: b for b in r["final"]}
        if "b" not in fin:
            continue
        x, y = rot(fin["b"]["position"], -phi)
        out = max(abs(x), abs(y)) - half
        if out > 1e-6 * half and r["status"] == "ok":
            find(name, r["engine"], f"`ok` with the body {out:.3g} m outside the box (escaped_bodies "
                 f"{r['metrics'].get('escaped_bodies')})")


def judge_one(name, t, runs, ref, res_dir, find):
    if t["kind"] == "box":
        judge_box(name, t, runs, find)
        if t["bounces"] > 2000:
            # core to 1e-6 of the box is asked only up to 2000 bounces (hunt.sh: 1e-7 after 16,000
            # axis-aligned); beyond, the containment judge alone
            t = dict(t, exact=False)
    if t["kind"] == "dome" and t["elastic"]:
        for r in runs:
            if r["engine"] == "core" and "event cap" in r["reason"]:
                find(name, "core", "diverged at the event cap on a ball sliding over an elastic static circle, so "
                     "no reference and no engine measured (known, not fixed: a static circle has no curved support)")
    hunt8.judge(name, t, runs, ref, res_dir, find)


FAMILIES = {"rotplane": gen_rotplane, "dragslope": gen_dragslope, "quadbounce": gen_quadbounce,
            "rotbox": gen_rotbox, "staticball": gen_staticball, "dome": gen_dome, "pocket": gen_pocket,
            "triple": gen_triple, "thrustwall": gen_thrustwall, "newtonwall": gen_newtonwall}


def main(argv):
    return hunt8.run_hunt("hunt12", __doc__, FAMILIES, judge_one, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
