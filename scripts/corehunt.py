#!/usr/bin/env python3
"""The core hunt against closed forms (README: "The core hunt against closed forms").

Writes families of scenes whose answer is known in closed form (or by an exact map), runs
them on core through `physval run` (so the converged reference is built too), and judges
every run itself: core's final state and contact times against the closed form, and the
reference against the same closed form whenever it claims to have converged. Prints each
finding; exits 1 if there is any.

usage: scripts/corehunt.py PHYSVAL WORKDIR [-j N] [--family NAME ...]
"""
import json
import math
import os
import subprocess
import sys

G0 = 9.8


def f(x):
    return repr(float(x))


def vec(v):
    return "[%s, %s]" % (f(v[0]), f(v[1]))


def body(name, p, v=(0.0, 0.0), r=0.1, m=1.0, e=1.0, extra=""):
    shape = 'shape = "point"\n' if r == 0 else "radius = %s\n" % f(r)
    return ("[[bodies]]\nname = \"%s\"\n%smass = %s\nposition = %s\nvelocity = %s\nrestitution = %s\n%s\n"
            % (name, shape, f(m), vec(p), vec(v), f(e), extra))


def wall(name, a, b, e=1.0, mu=0.0, mus=None):
    mus = mu if mus is None else mus
    return ("[[walls]]\nname = \"%s\"\nfrom = %s\nto = %s\nrestitution = %s\nfriction = %s\nstatic_friction = %s\n\n"
            % (name, vec(a), vec(b), f(e), f(mu), f(mus)))


def header(name, duration, dt, gravity=(0.0, 0.0), wind=(0.0, 0.0), extra_world="", allow_overlap=False):
    s = 'name = "%s"\nduration = %s\ndt = %s\n' % (name, f(duration), f(dt))
    if allow_overlap:
        s += "allow_initial_overlap = true\n"
    s += "\n[world]\ngravity = %s\nwind = %s\n%s\n" % (vec(gravity), vec(wind), extra_world)
    return s


def bisect(fn, a, b, it=200):
    fa = fn(a)
    for _ in range(it):
        m = 0.5 * (a + b)
        fm = fn(m)
        if (fm > 0) == (fa > 0):
            a, fa = m, fm
        else:
            b = m
        if b - a < 1e-15 * max(1.0, abs(a)):
            break
    return 0.5 * (a + b)


def first_root(fn, t0, t1, n=600):
    """The earliest time in (t0, t1] where fn (positive at t0+) becomes <= 0."""
    prev = t0
    for k in range(1, n + 1):
        t = t0 + (t1 - t0) * k / n
        if fn(t) <= 0:
            return bisect(fn, prev, t)
        prev = t
    return None


class Case:
    def __init__(self, family, name, toml, judge, core_integrator=None):
        self.family, self.name, self.toml, self.judge = family, name, toml, judge
        if core_integrator:
            self.toml += '[core]\nintegrator = "%s"\n' % core_integrator


def dist(a, b):
    return math.hypot(a[0] - b[0], a[1] - b[1])


# ---------------------------------------------------------------------------------------
# Family 1: drag + contact
# ---------------------------------------------------------------------------------------

def linear_drag_path(x0, v0, m, k, g, wind, W, r, e, T):
    """Ball with linear drag k towards wind, gravity g, between a floor y=0 (x < W) and a
    wall x = W. Returns (contacts [(name, t)], final x, v) or None when too close to rest
    or a corner."""
    tau = m / k
    vinf = (wind[0], wind[1] - G0 * tau) if g else (wind[0], wind[1])
    t, x, v = 0.0, list(x0), list(v0)
    contacts = []

    def at(s):
        ex = math.exp(-s / tau)
        return ([x[i] + vinf[i] * s + tau * (v[i] - vinf[i]) * (1 - ex) for i in range(2)],
                [vinf[i] + (v[i] - vinf[i]) * ex for i in range(2)])

    while True:
        gw = lambda s: (W - r) - at(s)[0][0]
        gf = lambda s: at(s)[0][1] - r
        rem = T - t
        tw = first_root(gw, 0.0, rem) if at(rem)[0][0] > W - r - 1e-12 or True else None
        tf = first_root(gf, 0.0, rem)
        cand = [(s, n) for s, n in ((tw, "wall"), (tf, "floor")) if s is not None]
        if not cand:
            p, vv = at(rem)
            return contacts, p, vv
        s, n = min(cand)
        p, vv = at(s)
        if s < 1e-9 and contacts:
            return None
        if n == "wall":
            if p[1] < 3 * r:
                return None
            vv[0] = -e * vv[0]
        else:
            if p[0] > W - 3 * r:
                return None
            vv[1] = -e * vv[1]
            if abs(vv[1]) < 0.3:
                return None  # near the rest regime: rest_speed and Zeno are not this family
        t += s
        contacts.append((n, t))
        x, v = p, vv


def quad_drag_1d(y0, u0, m, k2, w, r, e, T):
    """Vertical fall/throw with quadratic drag k2 towards a vertical wind w, onto a floor at
    y = 0 (ball radius r). Returns contacts [t], final y, v."""
    c = k2 / m
    vt = math.sqrt(G0 / c)
    t, y, v = 0.0, y0, u0
    contacts = []

    def at(s):
        u = v - w
        # du/ds = -g - c|u|u
        if u > 0:
            phi0 = math.atan(u / vt)
            ts = phi0 * vt / G0  # time to u = 0
            if s <= ts:
                ph = phi0 - G0 * s / vt
                return (y + w * s + (vt * vt / G0) * math.log(math.cos(ph) / math.cos(phi0)), w + vt * math.tan(ph))
            ya = y + w * ts + (vt * vt / G0) * math.log(1.0 / math.cos(phi0))
            s2 = s - ts
            return (ya + w * s2 - (vt * vt / G0) * math.log(math.cosh(G0 * s2 / vt)),
                    w - vt * math.tanh(G0 * s2 / vt))
        # u <= 0: falling relative to the air; |u| < vt assumed
        a = -u / vt
        if a >= 1:
            raise ValueError("beyond terminal")
        ph0 = math.atanh(a)
        ph = ph0 + G0 * s / vt
        return (y + w * s - (vt * vt / G0) * math.log(math.cosh(ph) / math.cosh(ph0)), w - vt * math.tanh(ph))

    while True:
        rem = T - t
        gap = lambda s: at(s)[0] - r
        s = first_root(gap, 0.0, rem) if not (contacts == [] and y0 == r and u0 < 0) else 0.0
        if s is None:
            yy, vv = at(rem)
            return contacts, yy, vv
        yy, vv = at(s)
        vv = -e * vv
        if abs(vv) < 0.3:
            return None
        t += s
        contacts.append(t)
        y, v = r, vv


def family_drag():
    cases = []
    idx = 0
    # linear drag, wind, thrown at a wall and a floor
    for k in (0.02, 0.12, 0.5, 2.0):
        for e in (1.0, 0.8, 0.5):
            for speed, ang in ((8.0, 40.0), (15.0, 30.0), (30.0, 10.0)):
                for wind in ((0.0, 0.0), (-3.0, 0.0), (4.0, 2.0)):
                    for dt in (1.0 / 60, 1.0 / 240):
                        idx += 1
                        m, r, W, T = 0.45, 0.11, 6.0, 2.5
                        v0 = (speed * math.cos(math.radians(ang)), speed * math.sin(math.radians(ang)))
                        x0 = (0.0, 1.0)
                        res = linear_drag_path(x0, v0, m, k, True, wind, W, r, e, T)
                        if res is None or not res[0]:
                            continue
                        contacts, p, v = res
                        name = "lin_%d" % idx
                        toml = header(name, T, dt, (0.0, -G0), wind)
                        toml += body("ball", x0, v0, r, m, e, "drag_linear = %s\n" % f(k))
                        toml += wall("floor", (-200.0, 0.0), (W, 0.0), e)
                        toml += wall("wall", (W, 0.0), (W, 40.0), e)
                        cases.append(Case("drag", name, toml, judge_final({"ball": (p, v)}, contacts), "rk4"))
    # an impact exactly at a step's end, and at t = 0
    for k in (0.1, 1.0):
        for n in (3, 10, 37):
            idx += 1
            m, r, e, W = 0.45, 0.11, 0.8, 50.0
            x0, v0 = (0.0, 2.0), (1.0, 0.0)
            res = linear_drag_path(x0, v0, m, k, True, (0.0, 0.0), W, r, e, 1.5)
            if res is None or not res[0]:
                continue
            t1 = res[0][0][1]
            dt = t1 / n
            T = 1.5 * t1
            res = linear_drag_path(x0, v0, m, k, True, (0.0, 0.0), W, r, e, T)
            if res is None:
                continue
            name = "lin_stepend_%d" % idx
            toml = header(name, T, dt, (0.0, -G0))
            toml += body("ball", x0, v0, r, m, e, "drag_linear = %s\n" % f(k))
            toml += wall("floor", (-200.0, 0.0), (W, 0.0), e)
            cases.append(Case("drag", name, toml, judge_final({"ball": (res[1], res[2])}, res[0]), "rk4"))
    # quadratic drag, vertical, with vertical wind, onto a floor; impacts at t = 0 too
    for k2 in (0.005, 0.02, 0.1):
        for e in (1.0, 0.7):
            for u0 in (-3.0, 0.0, 6.0):
                for w in (0.0, 1.5, -2.0):
                    for y0 in (0.1, 2.0):
                        for dt in (1.0 / 60, 1.0 / 200):
                            idx += 1
                            m, r, T = 0.3, 0.1, 2.0
                            if y0 == r and u0 >= 0:
                                continue
                            try:
                                res = quad_drag_1d(y0, u0, m, k2, w, r, e, T)
                            except ValueError:
                                continue
                            if res is None:
                                continue
                            contacts, y, v = res
                            name = "quad_%d" % idx
                            toml = header(name, T, dt, (0.0, -G0), (0.0, w))
                            toml += body("ball", (0.0, y0), (0.0, u0), r, m, e, "drag_quadratic = %s\n" % f(k2))
                            toml += wall("floor", (-5.0, 0.0), (5.0, 0.0), e)
                            cases.append(Case("drag", name, toml,
                                              judge_final({"ball": ((0.0, y), (0.0, v))}, [("floor", c) for c in contacts]), "rk4"))
    return cases


# ---------------------------------------------------------------------------------------
# Family 2: slopes
# ---------------------------------------------------------------------------------------

def slope_closed_form(th, mus, muk, v0, T):
    s_, c_ = math.sin(th), math.cos(th)
    t = 0.0
    s, v = 0.0, v0
    stick = math.tan(th) <= mus
    if v == 0.0:
        if stick:
            return 0.0, 0.0
        a = G0 * (s_ - muk * c_)
        return 0.5 * a * T * T, a * T
    if v > 0:
        a = G0 * (s_ - muk * c_)
        if a >= 0:
            return v * T + 0.5 * a * T * T, v + a * T
        t1 = v / -a
        if t1 >= T:
            return v * T + 0.5 * a * T * T, v + a * T
        return v * t1 + 0.5 * a * t1 * t1, 0.0
    a = G0 * (s_ + muk * c_)
    t1 = -v / a
    if t1 >= T:
        return v * T + 0.5 * a * T * T, v + a * T
    s1 = v * t1 + 0.5 * a * t1 * t1
    if stick:
        return s1, 0.0
    a2 = G0 * (s_ - muk * c_)
    r = T - t1
    return s1 + 0.5 * a2 * r * r, a2 * r


def family_slopes():
    cases = []
    idx = 0
    angles = (1, 3, 7, 10, 15, 22, 30, 37, 45, 53, 60, 70, 80, 89)
    mus_l = (0.0, 0.1, 0.3, 0.577, 1.0, 3.0)
    for deg in angles:
        th = math.radians(deg)
        for mus in mus_l:
            for frac in (0.0, 0.5, 1.0):
                muk = mus * frac
                if frac == 0.5 and mus == 0.0:
                    continue
                if abs(math.tan(th) - mus) < 1e-6:
                    continue
                for v0 in (0.0, 1.5, -2.0):
                    for segs in (1, 3, 2):
                        idx += 1
                        if (idx % 2) and segs == 3:
                            continue
                        T, r, dt = 1.5, 0.1, 1.0 / 60
                        s, v = slope_closed_form(th, mus, muk, v0, T)
                        d = (math.cos(th), -math.sin(th))
                        n = (math.sin(th), math.cos(th))
                        L = max(abs(s), 3.0) + 5.0
                        p0 = (r * n[0], r * n[1])
                        pT = (s * d[0] + r * n[0], s * d[1] + r * n[1])
                        vT = (v * d[0], v * d[1])
                        name = "slope_%d" % idx
                        toml = header(name, T, dt, (0.0, -G0))
                        toml += body("ball", p0, (v0 * d[0], v0 * d[1]), r, 1.0, 0.0)
                        # pieces from -L to +L along d (drawn from the upper end down: the
                        # left of the point order is the side away from... a wall is two-sided)
                        cuts = [-L + 2 * L * k / segs for k in range(segs + 1)]
                        if segs == 2:
                            cuts[1] = 0.5  # a junction the ball slides over (downhill)
                        if segs == 3:
                            cuts[1] = -0.37 * L if segs == 3 else cuts[1]
                            cuts[2] = 0.0 if segs == 3 else cuts[2]  # a junction under the ball
                        mats = ""
                        for j in range(segs):
                            a = (cuts[j] * d[0], cuts[j] * d[1])
                            b = (cuts[j + 1] * d[0], cuts[j + 1] * d[1])
                            toml += wall("s%d" % j, a, b, 0.0, muk, mus)
                            mats += ('[[materials]]\na = "ball"\nb = "s%d"\nfriction = %s\nstatic_friction = %s\n\n'
                                     % (j, f(muk), f(mus)))
                        toml += mats
                        cases.append(Case("slopes", name, toml, judge_final({"ball": (pT, vT)}, None, pos_tol=1e-7)))
    # a V: a ball at rest touching both faces at the bottom, and at rest high on one face
    for deg in (10, 30, 45, 60, 80):
        th = math.radians(deg)
        for mu in (0.0, 0.5, 2.0):
            idx += 1
            r, T = 0.1, 1.5
            # faces y = |x| tan(th); a ball touching both: centre at (0, r / cos th)
            p0 = (0.0, r / math.cos(th))
            name = "vee_bottom_%d" % idx
            toml = header(name, T, 1.0 / 60, (0.0, -G0))
            toml += body("ball", p0, (0.0, 0.0), r, 1.0, 0.0)
            L = 5.0
            toml += wall("left", (-L * math.cos(th), L * math.sin(th)), (0.0, 0.0), 0.0, mu)
            toml += wall("right", (0.0, 0.0), (L * math.cos(th), L * math.sin(th)), 0.0, mu)
            toml += '[[materials]]\na = "ball"\nb = "left"\nfriction = %s\n\n[[materials]]\na = "ball"\nb = "right"\nfriction = %s\n\n' % (f(mu), f(mu))
            cases.append(Case("slopes", name, toml, judge_final({"ball": (p0, (0.0, 0.0))}, None, pos_tol=1e-9)))
            if mu > 0 and math.tan(th) < mu:
                idx += 1
                # at rest on the right face, 2 m up it: stays
                dd = (math.cos(th), math.sin(th))
                nn = (-math.sin(th), math.cos(th))
                p1 = (2 * dd[0] + r * nn[0], 2 * dd[1] + r * nn[1])
                name = "vee_side_%d" % idx
                toml = header(name, T, 1.0 / 60, (0.0, -G0))
                toml += body("ball", p1, (0.0, 0.0), r, 1.0, 0.0)
                toml += wall("left", (-L * math.cos(th), L * math.sin(th)), (0.0, 0.0), 0.0, mu)
                toml += wall("right", (0.0, 0.0), (L * math.cos(th), L * math.sin(th)), 0.0, mu)
                toml += '[[materials]]\na = "ball"\nb = "left"\nfriction = %s\n\n[[materials]]\na = "ball"\nb = "right"\nfriction = %s\n\n' % (f(mu), f(mu))
                cases.append(Case("slopes", name, toml, judge_final({"ball": (p1, (0.0, 0.0))}, None, pos_tol=1e-9)))
    return cases


# ---------------------------------------------------------------------------------------
# Family 3: the pi billiard
# ---------------------------------------------------------------------------------------

def billiard_map(M, e):
    v1, v2 = 0.0, -1.0
    n = 0
    while n < 3000000:
        if v2 < v1:  # light catches... heavy moving left faster than light: ball-ball
            # momentum and restitution
            vc = (v1 + M * v2) / (1 + M)
            v1n = vc + e * (vc - v1) if False else (v1 + M * v2 + M * e * (v2 - v1)) / (1 + M)
            v2n = (v1 + M * v2 + e * (v1 - v2)) / (1 + M)
            v1, v2 = v1n, v2n
            n += 1
        elif v1 < 0:
            v1 = -e * v1
            n += 1
        else:
            return n, v1, v2
    return None  # no end within 3e6 impacts: inelastic collapse (or nearly)


def family_billiard():
    cases = []
    for k in range(6):
        for e in (1.0, 0.9999, 0.99):
            M = 100.0 ** k
            mp = billiard_map(M, e)
            name = "pi_k%d_e%s" % (k, str(e).replace(".", "p"))
            T = 8.0
            toml = header(name, T, 0.01)
            toml += body("light", (1.0, 0.0), (0.0, 0.0), 0.1, 1.0, e)
            toml += body("heavy", (2.0, 0.0), (-1.0, 0.0), 0.1, M, e)
            toml += wall("wall", (0.0, -1.0), (0.0, 1.0), e)
            if mp is None:
                cases.append(Case("billiard", name, toml, judge_order(M)))
            else:
                n, v1, v2 = mp
                cases.append(Case("billiard", name, toml, judge_velocities({"light": (v1, 0.0), "heavy": (v2, 0.0)},
                                                                             note="%d collisions" % n)))
    return cases


# ---------------------------------------------------------------------------------------
# Family 4: Newton's cradle
# ---------------------------------------------------------------------------------------

def family_cradle():
    cases = []
    for N in range(2, 8):
        for law in ("simultaneous", "sequential"):
            for gap in (0.3, 0.0, 0.25):
                u, r = 1.0, 0.1
                xs = [2 * r * i for i in range(1, N)]
                name = "cradle_n%d_%s_g%d" % (N, law, int(gap * 100))
                T, dt = 1.0, 0.1 if gap == 0.25 else 1.0 / 60
                toml = header(name, T, dt)
                toml += body("b0", (-gap, 0.0), (u, 0.0), r, 1.0, 1.0)
                for i, x in enumerate(xs):
                    toml += body("b%d" % (i + 1), (x, 0.0), (0.0, 0.0), r, 1.0, 1.0)
                toml += '[core]\nimpact_law = "%s"\n' % law
                t0 = gap / u
                if law == "simultaneous":
                    vs = [u * (2 - N) / N] + [2 * u / N] * (N - 1)
                else:
                    vs = [0.0] * (N - 1) + [u]
                fin = {}
                for i in range(N):
                    x0 = -gap if i == 0 else xs[i - 1]
                    fin["b%d" % i] = ((x0 + (u * t0 if i == 0 else 0.0) + vs[i] * (T - t0), 0.0), (vs[i], 0.0))
                cases.append(Case("cradle", name, toml, judge_final(fin, None, pos_tol=1e-9)))
    return cases


# ---------------------------------------------------------------------------------------
# Family 5: Kepler
# ---------------------------------------------------------------------------------------

def kepler(mu, q, ecc, t):
    a = q / (1 - ecc)
    n = math.sqrt(mu / a ** 3)
    Mm = n * t
    Mm = math.fmod(Mm, 2 * math.pi)
    E = Mm if ecc < 0.8 else math.pi
    for _ in range(200):
        dE = (E - ecc * math.sin(E) - Mm) / (1 - ecc * math.cos(E))
        E -= dE
        if abs(dE) < 1e-16:
            break
    x = a * (math.cos(E) - ecc)
    y = a * math.sqrt(1 - ecc * ecc) * math.sin(E)
    Edot = n / (1 - ecc * math.cos(E))
    vx = -a * math.sin(E) * Edot
    vy = a * math.sqrt(1 - ecc * ecc) * math.cos(E) * Edot
    return (x, y), (vx, vy), 2 * math.pi / n


def family_kepler():
    cases = []
    for ecc in (0.0, 0.3, 0.6, 0.9, 0.97, 0.99):
        for m2 in (1.0, 1e-3):
            for per_dt in (100, 400):
                m1, Gc, q = 1.0, 1.0, 0.5
                mu = Gc * (m1 + m2)
                _, _, P = kepler(mu, q, ecc, 0.0)
                T = 1.37 * P
                dt = P / per_dt
                rp, rv, _ = kepler(mu, q, ecc, T)
                w1, w2 = -m2 / (m1 + m2), m1 / (m1 + m2)
                v0 = math.sqrt(mu * (1 + ecc) / q)
                name = "kepler_e%s_m%s_n%d" % (str(ecc).replace(".", "p"), "eq" if m2 == 1 else "small", per_dt)
                toml = header(name, T, dt, extra_world="newtonian = true\nG = 1.0\n")
                toml += body("a", (w1 * q, 0.0), (0.0, w1 * v0), 0, m1)
                toml += body("b", (w2 * q, 0.0), (0.0, w2 * v0), 0, m2)
                fin = {"a": ((w1 * rp[0], w1 * rp[1]), (w1 * rv[0], w1 * rv[1])),
                       "b": ((w2 * rp[0], w2 * rp[1]), (w2 * rv[0], w2 * rv[1]))}
                cases.append(Case("kepler", name, toml, judge_final(fin, None, pos_tol=None), "rk4"))
    return cases


# ---------------------------------------------------------------------------------------
# Family 6: projectiles, thrust, touching at t = 0, mass ratios, particles
# ---------------------------------------------------------------------------------------

def family_misc():
    cases = []
    # projectile bouncing on a floor, e, exact (constant forces)
    for e in (1.0, 0.75, 0.5):
        for vy0 in (0.0, 4.0, -3.0):
            for dt in (1.0 / 60, 1.0 / 7):
                r, y0, vx = 0.2, 3.0, 1.3
                T = 2.5
                t, y, vy, contacts = 0.0, y0, vy0, []
                ok = True
                while True:
                    # y + vy s - g s^2/2 = r
                    disc = vy * vy + 2 * G0 * (y - r)
                    s = (vy + math.sqrt(disc)) / G0
                    if s < 1e-12:
                        s = (vy + math.sqrt(disc)) / G0
                    if t + s > T:
                        rem = T - t
                        y, vy = y + vy * rem - 0.5 * G0 * rem * rem, vy - G0 * rem
                        break
                    t += s
                    vimp = vy - G0 * s
                    vy = -e * vimp
                    y = r
                    contacts.append(("floor", t))
                    if vy < 0.5:
                        ok = False
                        break
                if not ok:
                    continue
                name = "proj_e%d_v%s_dt%d" % (int(e * 100), str(int(vy0)).replace("-", "n"), int(1 / dt))
                toml = header(name, T, dt, (0.0, -G0))
                toml += body("ball", (0.0, y0), (vx, vy0), r, 1.0, e)
                toml += wall("floor", (-10.0, 0.0), (20.0, 0.0), e)
                cases.append(Case("misc", name, toml, judge_final({"ball": ((vx * T, y), (vx, vy))}, contacts, pos_tol=1e-9)))
    # a thrust table linear in speed: a = a0 - c |v| along the heading, v along it
    for a0, c in ((3.0, 0.5), (10.0, 2.0)):
        for v0 in (0.0, 2.0):
            for integ in ("velocity_verlet", "rk4"):
                T, dt = 3.0, 0.05
                vmax = 40.0
                vinf = a0 / c
                v = vinf + (v0 - vinf) * math.exp(-c * T)
                x = vinf * T + (v0 - vinf) * (1 - math.exp(-c * T)) / c
                name = "thrust_a%d_c%d_v%d_%s" % (a0, int(c * 10), v0, integ[:3])
                toml = header(name, T, dt)
                toml += body("car", (0.0, 0.0), (v0, 0.0), 0.2, 1.0, 1.0,
                             "[bodies.thrust]\nspeeds = [0.0, %s]\naccel = [%s, %s]\n" % (f(vmax), f(a0), f(a0 - c * vmax)))
                tol = 1e-4 if integ == "velocity_verlet" else 1e-6
                cases.append(Case("misc", name, toml, judge_final({"car": ((x, 0.0), (v, 0.0))}, None, pos_tol=tol), integ))
    # head-on at mass ratios to 1e9, touching at t = 0 or apart
    for lg in (0, 3, 6, 9, -9):
        for e in (1.0, 0.5, 0.0):
            for gap in (0.0, 0.5):
                m1, m2 = 1.0, 10.0 ** lg
                u1, u2 = 1.0, -0.5
                r = 0.25
                T, dt = 2.0, 1.0 / 60
                t0 = gap / (u1 - u2)
                v1 = (m1 * u1 + m2 * u2 + m2 * e * (u2 - u1)) / (m1 + m2)
                v2 = (m1 * u1 + m2 * u2 + m1 * e * (u1 - u2)) / (m1 + m2)
                x1 = -r - gap / 2
                x2 = r + gap / 2
                f1 = x1 + u1 * t0 + v1 * (T - t0)
                f2 = x2 + u2 * t0 + v2 * (T - t0)
                name = "headon_m%s_e%d_g%d" % (str(lg).replace("-", "n"), int(e * 10), int(gap * 10))
                toml = header(name, T, dt)
                toml += body("a", (x1, 0.0), (u1, 0.0), r, m1, e)
                toml += body("b", (x2, 0.0), (u2, 0.0), r, m2, e)
                cases.append(Case("misc", name, toml, judge_final({"a": ((f1, 0.0), (v1, 0.0)), "b": ((f2, 0.0), (v2, 0.0))},
                                                                  [("a-b", t0)], pos_tol=1e-9)))
    # a trail of particles with speed 0: each starts on the parent and follows its path
    for g in ((0.0, 0.0), (0.0, -G0)):
        for rate in (7.0, 60.0, 333.0):
            for dt in (1.0 / 60, 1.0 / 13):
                T = 1.0
                p0, v0 = (0.0, 5.0), (3.0, 2.0)
                name = "trail_g%d_r%d_dt%d" % (int(-g[1]), int(rate), int(1 / dt))
                toml = header(name, T, dt, g)
                toml += body("rocket", p0, v0, 0.1, 1.0, 1.0)
                toml += ('[[emitters]]\nname = "tr"\nparent = "rocket"\nmode = "trail"\nrate = %s\nspeed = 0.0\nlifetime = 5.0\n'
                         'gravity = %s\n\n' % (f(rate), "true" if g[1] else "false"))
                pT = (p0[0] + v0[0] * T, p0[1] + v0[1] * T + 0.5 * g[1] * T * T)
                vT = (v0[0], v0[1] + g[1] * T)
                cases.append(Case("particles", name, toml, judge_trail(pT, vT, rate, T)))
    return cases


# ---------------------------------------------------------------------------------------
# Family: junctions (a ball started on, beside or sliding into the junction of two pieces
# of a slope: collinear, concave, convex; core/tests/corehunt_test.cpp holds the same)
# ---------------------------------------------------------------------------------------

JUNCTION_MU = ((0.0, 0.0), (0.1, 0.1), (0.3, 0.15), (0.577, 0.2885), (1.0, 0.5), (3.0, 1.5))


def down_dir(th):
    return (math.cos(th), -math.sin(th))


def up_normal(th):
    return (math.sin(th), math.cos(th))


def add(p, q, k=1.0):
    return (p[0] + k * q[0], p[1] + k * q[1])


def slope_pieces_toml(pieces, mus, muk):
    toml, mats = "", ""
    for j, (a, b) in enumerate(pieces):
        toml += wall("p%d" % j, a, b, 0.0, muk, mus)
        mats += ('[[materials]]\na = "ball"\nb = "p%d"\nfriction = %s\nstatic_friction = %s\n\n' % (j, f(muk), f(mus)))
    return toml + mats


def ulp_of(J):
    m = max(abs(J[0]), abs(J[1]), 1.0)
    return math.ldexp(1.0, math.frexp(m)[1] - 1 - 52)


def family_junctions():
    cases = []
    T, r, dt = 1.5, 0.1, 1.0 / 60
    g = (0.0, -G0)
    # collinear: on the junction or 1, 4 ulps either side; 2 pieces or 3 (a second
    # junction 0.5 m down)
    for deg in (1, 10, 30, 45, 53, 60, 70, 80, 89):
        th = math.radians(deg)
        d, n = down_dir(th), up_normal(th)
        for mus, muk in JUNCTION_MU:
            if abs(math.tan(th) - mus) < 1e-6:
                continue
            for v0 in (1.5, 0.0, -1.5):
                for J in ((0.0, 0.0), (3.7, -1.3)):
                    u = ulp_of(J)
                    for k in (0, 1, -1, 4, -4):
                        for npieces in (2, 3):
                            L = 20.0
                            pieces = [(add(J, d, -L), J)]
                            if npieces == 2:
                                pieces.append((J, add(J, d, L)))
                            else:
                                pieces += [(J, add(J, d, 0.5)), (add(J, d, 0.5), add(J, d, L))]
                            p0 = add(add(J, d, k * u), n, r)
                            sT, vT = slope_closed_form(th, mus, muk, v0, T)
                            name = "collinear_%d_%s_%s_%s_%d_%d_%d" % (deg, str(mus).replace(".", "p"), str(v0).replace(".", "p").replace("-", "m"),
                                                                     "o" if J[0] == 0 else "j", k + 4, npieces, len(cases))
                            toml = header(name, T, dt, g) + body("ball", p0, (v0 * d[0], v0 * d[1]), r, 1.0, 0.0)
                            toml += slope_pieces_toml(pieces, mus, muk)
                            cases.append(Case("junctions", name, toml,
                                              judge_final({"ball": (add(p0, d, sT), (vT * d[0], vT * d[1]))}, None, pos_tol=1e-7)))
    # concave: thB = thA - dth; in the pocket (touching both) or from 0.3 m up A into it
    for degA in (10, 30, 45, 60, 80):
        for ddeg in (5, 20, 40):
            if degA - ddeg < 3:
                continue
            thA, thB, dth = math.radians(degA), math.radians(degA - ddeg), math.radians(ddeg)
            dA, nA, dB, nB = down_dir(thA), up_normal(thA), down_dir(thB), up_normal(thB)
            for mus, muk in JUNCTION_MU:
                if abs(math.tan(thA) - mus) < 1e-6 or abs(math.tan(thB) - mus) < 1e-6:
                    continue
                J = (3.7, -1.3)
                pieces = [(add(J, dA, -20.0), J), (J, add(J, dB, 20.0))]
                c = r / (1.0 + nA[0] * nB[0] + nA[1] * nB[1])
                pocket = (J[0] + c * (nA[0] + nB[0]), J[1] + c * (nA[1] + nB[1]))
                for v0 in (0.0, 1.5):
                    for k in (0, 1, -1):
                        p0 = add(pocket, dB, k * ulp_of(J))
                        sT, vT = slope_closed_form(thB, mus, muk, v0, T)
                        name = "concave_pocket_%d_%d_%s_%s_%d_%d" % (degA, ddeg, str(mus).replace(".", "p"), str(v0).replace(".", "p"), k + 1, len(cases))
                        toml = header(name, T, dt, g) + body("ball", p0, (v0 * dB[0], v0 * dB[1]), r, 1.0, 0.0)
                        toml += slope_pieces_toml(pieces, mus, muk)
                        cases.append(Case("junctions", name, toml,
                                          judge_final({"ball": (add(p0, dB, sT), (vT * dB[0], vT * dB[1]))}, None, pos_tol=1e-7)))
                    aA = G0 * (math.sin(thA) - muk * math.cos(thA))
                    if v0 == 0.0 and math.tan(thA) <= mus:
                        continue
                    D = 0.3
                    if aA == 0.0:
                        t1 = D / v0
                    else:
                        disc = v0 * v0 + 2 * aA * D
                        if disc <= 0:
                            continue
                        t1 = (-v0 + math.sqrt(disc)) / aA
                    if not t1 < T - 0.1:
                        continue
                    v1 = v0 + aA * t1
                    vn, vt = v1 * math.sin(dth), v1 * math.cos(dth)
                    # the contact slides into the impact: kinetic friction acts through it
                    vt2 = vt - min(muk * vn, vt)
                    sB, vB = slope_closed_form(thB, mus, muk, vt2, T - t1)
                    p0 = add(pocket, dA, -D)
                    name = "concave_into_%d_%d_%s_%s_%d" % (degA, ddeg, str(mus).replace(".", "p"), str(v0).replace(".", "p"), len(cases))
                    toml = header(name, T, dt, g) + body("ball", p0, (v0 * dA[0], v0 * dA[1]), r, 1.0, 0.0)
                    toml += slope_pieces_toml(pieces, mus, muk)
                    cases.append(Case("junctions", name, toml,
                                      judge_final({"ball": (add(pocket, dB, sB), (vB * dB[0], vB * dB[1]))}, None, pos_tol=1e-7)))
    # convex: thB = thA + dth, fast enough to lift off at the junction (v^2 > 1.2 g r cos thA);
    # judged halfway through its flight (the run ends there)
    for degA in (0, 10, 30, 45, 60):
        for ddeg in (5, 20, 40):
            thA, thB = math.radians(degA), math.radians(degA + ddeg)
            dA, nA, dB, nB = down_dir(thA), up_normal(thA), down_dir(thB), up_normal(thB)
            for mus, muk in JUNCTION_MU:
                if abs(math.tan(thA) - mus) < 1e-6:
                    continue
                J = (3.7, -1.3)
                pieces = [(add(J, dA, -20.0), J), (J, add(J, dB, 20.0))]
                for v0 in (1.5, 3.0):
                    for k in (0, 1, -1, None):   # None: from 0.3 m up A
                        D = 0.3 if k is None else 0.0
                        p0 = add(add(J, dA, -D if k is None else k * ulp_of(J)), nA, r)
                        t1, vJ = 0.0, v0
                        if D > 0:
                            s1, _ = slope_closed_form(thA, mus, muk, v0, 10.0)
                            if s1 < D:
                                continue
                            aA = G0 * (math.sin(thA) - muk * math.cos(thA))
                            t1 = D / v0 if aA == 0 else (-v0 + math.sqrt(v0 * v0 + 2 * aA * D)) / aA
                            vJ = v0 + aA * t1
                        if not vJ * vJ > 1.2 * G0 * r * math.cos(thA):
                            continue
                        pJ = add(J, nA, r)
                        vel = (vJ * dA[0], vJ * dA[1])
                        c0 = (pJ[0] - J[0]) * nB[0] + (pJ[1] - J[1]) * nB[1] - r
                        c1 = vel[0] * nB[0] + vel[1] * nB[1]
                        c2 = 0.5 * (g[0] * nB[0] + g[1] * nB[1])
                        tl = (-c1 - math.sqrt(c1 * c1 - 4 * c2 * c0)) / (2 * c2)
                        if not tl > 0:
                            continue
                        tm = 0.5 * tl
                        dur = t1 + tm
                        steps = max(1, math.ceil(dur * 60))
                        want = (pJ[0] + vel[0] * tm, pJ[1] + vel[1] * tm + 0.5 * g[1] * tm * tm)
                        vw = (vel[0], vel[1] + g[1] * tm)
                        name = "convex_%d_%d_%s_%s_%s_%d" % (degA, ddeg, str(mus).replace(".", "p"), str(v0).replace(".", "p"),
                                                            "up" if k is None else str(k + 1), len(cases))
                        toml = header(name, dur, dur / steps, g) + body("ball", p0, (v0 * dA[0], v0 * dA[1]), r, 1.0, 0.0)
                        toml += slope_pieces_toml(pieces, mus, muk)
                        cases.append(Case("junctions", name, toml, judge_final({"ball": (want, vw)}, None, pos_tol=1e-7)))
    return cases


# ---------------------------------------------------------------------------------------
# Judges: each returns a list of finding strings for core's run and for the reference
# ---------------------------------------------------------------------------------------

def ref_final(series_dir, names):
    path = os.path.join(series_dir, "reference.csv")
    if not os.path.exists(path):
        return None
    with open(path) as fh:
        lines = fh.read().strip().split("\n")
    head = lines[0].split(",")
    last = lines[-1].split(",")
    out = {}
    for n in names:
        try:
            out[n] = (float(last[head.index("x_" + n)]), float(last[head.index("y_" + n)]))
        except ValueError:
            return None
    return out


def travel_scale(fin, run):
    return max([1.0] + [abs(c) for p, _ in fin.values() for c in p])


def judge_final(fin, contacts, pos_tol=1e-6):
    def judge(run, ref, series_dir):
        out = []
        scale = travel_scale(fin, run)
        got = {b["body"]: b for b in run["final"]}
        worst = 0.0
        for n, (p, v) in fin.items():
            if n not in got:
                out.append("core: body %s missing" % n)
                continue
            dp = dist(got[n]["position"], p)
            dv = dist(got[n]["velocity"], v)
            worst = max(worst, dp)
            tol = pos_tol if pos_tol is not None else None
            if tol is not None and dp > tol * scale:
                out.append("core %s: |x - x_cf| = %.3g m (tol %.1g), |v - v_cf| = %.3g" % (n, dp, tol * scale, dv))
        if contacts:
            ct = [c["time"] for c in run["contacts"]]
            want = [t for _, t in contacts]
            if len(ct) != len(want):
                out.append("core: %d contacts, closed form %d (%s vs %s)" % (len(ct), len(want),
                           ["%.6f" % t for t in ct[:6]], ["%.6f" % t for t in want[:6]]))
            else:
                err = max(abs(a - b) for a, b in zip(ct, want))
                if err > max(1e-6, 2 * run["dt"] if pos_tol is None else 1e-6):
                    out.append("core: contact times off by %.3g s" % err)
        # the reference against the closed form when it says converged
        if ref and ref.get("available") and ref.get("converged"):
            rf = ref_final(series_dir, list(fin))
            if rf:
                for n, (p, _) in fin.items():
                    dp = dist(rf[n], p)
                    lim = 1e-6 * scale + 1e-9 + 1e-11 * scale  # + the csv's 12 digits
                    if dp > 10 * lim:
                        out.append("REFERENCE converged (conv err %.2g) but %s is %.3g m from the closed form (limit %.2g)"
                                   % (ref["convergence_error"], n, dp, lim))
        return out, worst
    return judge


def judge_velocities(vel, note=""):
    def judge(run, ref, series_dir):
        out = []
        got = {b["body"]: b for b in run["final"]}
        worst = 0.0
        for n, v in vel.items():
            dv = dist(got[n]["velocity"], v)
            worst = max(worst, dv)
            if dv > 1e-6 * max(1.0, math.hypot(*v)):
                out.append("core %s: v = %s, exact map %s (%s)" % (n, got[n]["velocity"], v, note))
        return out, worst
    return judge


def judge_order(M):
    """No closed end (inelastic collapse): an ok run keeps wall | light | heavy in order
    and does not gain energy."""
    def judge(run, ref, series_dir):
        out = []
        got = {b["body"]: b for b in run["final"]}
        xl, xh = got["light"]["position"][0], got["heavy"]["position"][0]
        vl, vh = got["light"]["velocity"][0], got["heavy"]["velocity"][0]
        if run["status"] == "ok" and not (xl >= 0.1 - 1e-9 and xh - xl >= 0.2 - 1e-9):
            out.append("core ok but out of order: light %.6g, heavy %.6g" % (xl, xh))
        ke = 0.5 * vl * vl + 0.5 * M * vh * vh
        if ke > 0.5 * M * (1 + 1e-9):
            out.append("core gained energy: %.6g > %.6g" % (ke, 0.5 * M))
        if run["status"] == "ok" and max(abs(vl), abs(vh)) > 1e-6:
            out.append("core ok, light %.4g m/s, heavy %.4g m/s: the collapse's limit is both at rest" % (vl, vh))
        return out, 0.0
    return judge


def judge_trail(pT, vT, rate, T):
    def judge(run, ref, series_dir):
        out = []
        worst = 0.0
        nparts = 0
        for b in run["final"]:
            if not b["body"].startswith("tr#") or not b.get("alive", True):
                continue
            nparts += 1
            dp = dist(b["position"], pT)
            worst = max(worst, dp)
            if dp > 1e-9:
                out.append("core particle %s: %.3g m from the parent's path" % (b["body"], dp))
                break
        want = int(math.floor(rate * T + 1e-9))  # at k / rate, k >= 1
        if nparts < want - 1 or nparts > want:
            out.append("core: %d particles alive at the end, %d emitted by then" % (nparts, want))
        return out, worst
    return judge


FAMILIES = {"drag": family_drag, "slopes": family_slopes, "junctions": family_junctions, "billiard": family_billiard,
            "cradle": family_cradle, "kepler": family_kepler, "misc": family_misc}


def main():
    args = sys.argv[1:]
    physval, work = args[0], args[1]
    jobs = "2"
    fams = []
    judge_only = "--judge-only" in args
    i = 2
    while i < len(args):
        if args[i] == "-j":
            jobs = args[i + 1]
            i += 2
        elif args[i] == "--family":
            fams.append(args[i + 1])
            i += 2
        else:
            i += 1
    fams = fams or list(FAMILIES)
    total = 0
    findings = 0
    for fam in fams:
        cases = FAMILIES[fam]()
        d = os.path.join(work, fam, "scenes")
        os.makedirs(d, exist_ok=True)
        for fn in os.listdir(d):
            os.remove(os.path.join(d, fn))
        for c in cases:
            with open(os.path.join(d, c.name + ".toml"), "w") as fh:
                fh.write(c.toml)
        out = os.path.join(work, fam, "out")
        if not judge_only:
          subprocess.run([physval, "run", d, "--engines", "core", "--out", out, "-j", jobs, "--no-cache", "--quiet", "--series-csv"],
                       stdout=subprocess.DEVNULL)
        with open(os.path.join(out, "results.json")) as fh:
            res = json.load(fh)
        runs = {r["scenario"]: r for r in res["runs"]}
        refs = {r["scenario"]: r for r in res["references"]}
        nf = 0
        for c in cases:
            total += 1
            run = runs.get(c.name)
            if run is None:
                print("[%s] %s: no run" % (fam, c.name))
                nf += 1
                continue
            msgs = []
            if run["status"] != "ok":
                msgs.append("core status %s: %s" % (run["status"], run.get("reason", "")))
            if run.get("limits_hit"):
                msgs.append("core limits_hit %s" % run["limits_hit"])
            ref = refs.get(c.name)
            m, worst = c.judge(run, ref, os.path.join(out, "series", c.name))
            msgs += m
            if fam == "drag" and ref and not ref.get("converged"):
                msgs.append("reference not converged: %s" % ref.get("reason"))
            if msgs:
                nf += 1
                print("[%s] %s (%s s stepping): %s" % (fam, c.name, run.get("wall_seconds"), "; ".join(msgs)))
        print("family %s: %d runs, %d with findings" % (fam, len(cases), nf))
        findings += nf
    print("total: %d runs, %d with findings" % (total, findings))
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
