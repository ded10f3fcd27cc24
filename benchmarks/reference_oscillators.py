"""Reference periodic responses of two friction oscillators, independent of any harmonic balance.

Problem (a): one DOF (m = 1, k = 1, c = 0.02) with a Jenkins element (spring kt = 0.5 in series
with a Coulomb slider of threshold mu N = 0.5), forcing F cos(w t), F = 0.2.
Problem (b): two-DOF chain ground -k1- m1 -k2- m2 (m = 1, 1; k = 1, 1), each mass damped to
the ground (c = 0.02, 0.02: a diagonal damping matrix), forcing F cos(w t) on mass 1, mass 2
rubbing on the ground with a rigid Coulomb contact (mu N = 0.5).

Both are piecewise-linear: between switches the motion is a linear ODE. The response is found
by event-driven integration (scipy DOP853, rtol 1e-12, every stick/slip switch located as an
event of the integrator, so no switch is smeared) and Newton shooting on the period map
(finite-difference Jacobian) until the periodic state repeats to 1e-10. The first-harmonic
amplitude A1 of the observed DOF (u of (a), mass 1 of (b)) is integrated with the motion
(``int u cos``, ``int u sin`` as extra states). The peak of A1 over the frequency is found by a
golden-section search on a bracket from a coarse grid.

Used by benchmarks/peers.py and studies/eps_rule.py; shares no code with fretwear.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

RTOL, ATOL = 1e-12, 1e-14


class Jenkins:
    """Problem (a). State ``(u, v, z)``: mass position, velocity, slider position."""

    def __init__(self, m=1.0, k=1.0, c=0.02, kt=0.5, muN=0.5, F=0.2):
        self.m, self.k, self.c, self.kt, self.muN, self.F = m, k, c, kt, muN, F

    def period(self, y0, w):
        """Integrate one period from ``y0 = (u, v, z)``; returns the end state and A1."""
        T = 2 * np.pi / w
        u, v, z = map(float, y0)
        t = 0.0
        ic = isn = 0.0
        f = self.kt * (u - z)
        mode = 0 if abs(f) < self.muN else (1 if f > 0 else -1)
        if mode:
            z = u - mode * self.muN / self.kt
        guard = 0
        while t < T - 1e-14 * T and guard < 200:
            guard += 1
            if mode == 0:
                z0 = z

                def rhs(tt, y, z0=z0):
                    fs = self.kt * (y[0] - z0)
                    a = (self.F * math.cos(w * tt) - self.c * y[1] - self.k * y[0] - fs) / self.m
                    return [y[1], a, y[0] * math.cos(w * tt), y[0] * math.sin(w * tt)]

                def ev(tt, y, z0=z0):
                    return abs(self.kt * (y[0] - z0)) - self.muN
                ev.terminal, ev.direction = True, 1
            else:
                s = mode

                def rhs(tt, y, s=s):
                    a = (self.F * math.cos(w * tt) - self.c * y[1] - self.k * y[0]
                         - s * self.muN) / self.m
                    return [y[1], a, y[0] * math.cos(w * tt), y[0] * math.sin(w * tt)]

                def ev(tt, y, s=s):
                    return y[1] * s
                ev.terminal, ev.direction = True, -1
            sol = solve_ivp(rhs, (t, T), [u, v, ic, isn], method="DOP853", rtol=RTOL,
                            atol=ATOL, events=ev)
            u, v, ic, isn = sol.y[:, -1]
            t = sol.t[-1]
            if sol.status == 1:  # a switch
                if mode == 0:
                    f = self.kt * (u - z)
                    mode = 1 if f > 0 else -1
                else:
                    z = u - mode * self.muN / self.kt
                    # stick unless the acceleration keeps pushing the same way
                    a = (self.F * math.cos(w * t) - self.c * v - self.k * u
                         - mode * self.muN) / self.m
                    if a * mode <= 0:
                        mode = 0
                    v = 0.0
        if mode:
            z = u - mode * self.muN / self.kt
        a1 = 2 / T * ic
        b1 = 2 / T * isn
        return np.array([u, v, z]), math.hypot(a1, b1)


class Chain:
    """Problem (b). State ``(u1, v1, u2, v2)``; mass 2 rubs on the ground."""

    def __init__(self, m=(1.0, 1.0), k=(1.0, 1.0), c=(0.02, 0.02), muN=0.5, F=0.2):
        self.m, self.k, self.c, self.muN, self.F = m, k, c, muN, F

    def _forces(self, t, y, w):
        u1, v1, u2, v2 = y
        k1, k2 = self.k
        c1, c2 = self.c
        f1 = self.F * math.cos(w * t) - k1 * u1 - c1 * v1 - k2 * (u1 - u2)
        f2 = k2 * (u1 - u2) - c2 * v2  # on mass 2, before friction
        return f1, f2

    def period(self, y0, w):
        T = 2 * np.pi / w
        y = [float(x) for x in y0]
        t = 0.0
        ic = isn = 0.0
        _, f2 = self._forces(0.0, y, w)
        if abs(y[3]) > 0:
            mode = 1 if y[3] > 0 else -1
        else:
            mode = 0 if abs(f2) < self.muN else (1 if f2 > 0 else -1)
        guard = 0
        m1, m2 = self.m
        while t < T - 1e-14 * T and guard < 200:
            guard += 1
            if mode == 0:
                y[3] = 0.0

                def rhs(tt, s):
                    f1, _ = self._forces(tt, s[:4], w)
                    return [s[1], f1 / m1, 0.0, 0.0, s[0] * math.cos(w * tt),
                            s[0] * math.sin(w * tt)]

                def ev(tt, s):
                    _, f2 = self._forces(tt, s[:4], w)
                    return abs(f2) - self.muN
                ev.terminal, ev.direction = True, 1
            else:
                sg = mode

                def rhs(tt, s, sg=sg):
                    f1, f2 = self._forces(tt, s[:4], w)
                    return [s[1], f1 / m1, s[3], (f2 - sg * self.muN) / m2,
                            s[0] * math.cos(w * tt), s[0] * math.sin(w * tt)]

                def ev(tt, s, sg=sg):
                    return s[3] * sg
                ev.terminal, ev.direction = True, -1
            sol = solve_ivp(rhs, (t, T), y + [ic, isn], method="DOP853", rtol=RTOL,
                            atol=ATOL, events=ev)
            *y, ic, isn = sol.y[:, -1]
            y = list(y)
            t = sol.t[-1]
            if sol.status == 1:
                if mode == 0:
                    _, f2 = self._forces(t, y, w)
                    mode = 1 if f2 > 0 else -1
                else:
                    y[3] = 0.0
                    _, f2 = self._forces(t, y, w)
                    mode = 0 if abs(f2) < self.muN else (1 if f2 > 0 else -1)
        return np.array(y), math.hypot(2 / T * ic, 2 / T * isn)


def periodic(system, w, y0=None, tol=1e-10, warm_periods=60, max_newton=30):
    """The periodic state and its A1 at ``w`` [rad/s]: integrate ``warm_periods`` periods, then
    Newton shooting on ``P(y) - y`` (finite-difference Jacobian) to ``|P(y) - y| <= tol``
    (relative to the state's size). Returns ``(y, A1, residual)``."""
    n = 3 if isinstance(system, Jenkins) else 4
    y = np.zeros(n) if y0 is None else np.asarray(y0, float)
    for _ in range(warm_periods):
        y, _ = system.period(y, w)
    scale = max(np.abs(y).max(), 1e-3)
    for _ in range(max_newton):
        Py, a1 = system.period(y, w)
        r = Py - y
        if np.abs(r).max() <= tol * scale:
            return Py, a1, np.abs(r).max() / scale
        J = np.zeros((n, n))
        h = 1e-7 * scale
        for j in range(n):
            e = np.zeros(n)
            e[j] = h
            J[:, j] = (system.period(y + e, w)[0] - Py) / h
        try:
            dy = np.linalg.lstsq(J - np.eye(n), -r, rcond=1e-12)[0]
        except np.linalg.LinAlgError:
            dy = r
        # damped step: keep a step that reduces the residual, else iterate the map
        for lam in (1.0, 0.5, 0.25):
            yn = y + lam * dy
            if np.abs(system.period(yn, w)[0] - yn).max() < np.abs(r).max():
                y = yn
                break
        else:
            y = Py
    Py, a1 = system.period(y, w)
    return Py, a1, np.abs(Py - y).max() / scale


def peak(system, w_lo, w_hi, n_grid=13, tol=1e-8):
    """Peak ``(w, A1)`` of the first-harmonic amplitude over ``[w_lo, w_hi]``: a coarse grid,
    then golden-section search on the bracket around its maximum (continuation of the
    periodic state from point to point)."""
    ws = np.linspace(w_lo, w_hi, n_grid)
    y = None
    amps = []
    states = []
    for w in ws:
        y, a1, _ = periodic(system, w, y)
        amps.append(a1)
        states.append(y)
    i = int(np.argmax(amps))
    a, b = ws[max(i - 1, 0)], ws[min(i + 1, n_grid - 1)]
    g = (math.sqrt(5) - 1) / 2
    ystart = states[i]
    cache = {}

    def amp(w):
        if w not in cache:
            cache[w] = periodic(system, w, ystart, warm_periods=5)[1]
        return cache[w]

    c, d = b - g * (b - a), a + g * (b - a)
    while b - a > tol * (w_lo + w_hi):
        if amp(c) > amp(d):
            b, d = d, c
            c = b - g * (b - a)
        else:
            a, c = c, d
            d = a + g * (b - a)
    w = 0.5 * (a + b)
    return w, amp(w)


if __name__ == "__main__":
    import time

    t0 = time.perf_counter()
    print("(a) Jenkins: peak", peak(Jenkins(), 1.1, 1.3), f"{time.perf_counter() - t0:.1f} s")
    t0 = time.perf_counter()
    print("(b) chain:   peak", peak(Chain(), 1.4, 1.6), f"{time.perf_counter() - t0:.1f} s")
