"""A one-node friction oscillator and its references, shared by the tests of the time-domain
solvers (tests/timedomain/test_integrate.py, test_steady.py)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.integrate import solve_ivp

from fretwear.model.core import ContactInterface, Load, Model, ObservedPoint


def hz(w: float) -> float:
    """The frequency [Hz] of the circular frequency ``w`` [rad/s] (the references of this file
    are written in ``w``; the solvers take Hz)."""
    return w / (2 * np.pi)


def slider(*, m=1.0, k=1.0, N=1.0, F0=1.0, mu=0.3, mn=1.0, waveform="cos", c=0.0):
    """Single-DOF friction oscillator: DOF 0 = normal (mass ``mn``, no stiffness, pressed on
    the obstacle by the constant load ``N``), DOF 1 = tangential (mass m, spring k, optional
    dashpot c, force ``F0 cos(omega t)``)."""
    K = sp.csr_matrix(np.diag([0.0, k]))
    M = sp.csr_matrix(np.diag([mn, m]))
    C = sp.csr_matrix(np.diag([0.0, c])) if c else None
    contact = ContactInterface(dofs=np.array([[0, 1]]), frame=np.eye(2)[None],
                               gap=np.zeros(1), area=np.ones(1), mu=mu, coords=np.zeros((1, 2)))
    loads = [Load(np.array([N, 0.0]), "constant", name="normal"),
             Load(np.array([0.0, F0]), waveform, name="Q")]
    return Model(K=K, M=M, C=C, contact=contact, loads=loads,
                 observed=[ObservedPoint("x", np.array([1]), np.zeros(1))])


def event_driven(*, m, k, Ff, F0, w, t_end, t_eval):
    """Stick-slip oscillator integrated event by event (x(0) = x'(0) = 0): slip phases solve
    ``m x'' = F0 cos(wt) - k x - s Ff`` until x' = 0; stick phases hold x until
    ``|F0 cos(wt) - k x| = Ff``. Returns x at ``t_eval`` and the list of stick intervals."""
    F = lambda t: F0 * np.cos(w * t)
    t, x, v = 0.0, 0.0, 0.0
    R = F(0.0) - k * x
    mode = 0 if abs(R) <= Ff else np.sign(R)
    out = np.full(t_eval.shape, np.nan)
    sticks = []
    while t < t_end:
        if mode == 0:
            xs = x

            def g(tt, y, xs=xs):
                return abs(F(tt) - k * xs) - Ff

            g.terminal, g.direction = True, 1
            sol = solve_ivp(lambda tt, y: [0.0], (t, t_end), [x], events=g, max_step=0.5)
            tn = sol.t_events[0][0] if sol.t_events[0].size else t_end
            sel = (t_eval >= t) & (t_eval <= tn)
            out[sel] = xs
            sticks.append((t, tn))
            t = tn
            mode = np.sign(F(t) - k * x)
        else:
            s = mode

            def rhs(tt, y, s=s):
                return [y[1], (F(tt) - k * y[0] - s * Ff) / m]

            def ev(tt, y):
                return y[1]

            ev.terminal, ev.direction = True, -s
            sol = solve_ivp(rhs, (t, t_end), [x, v], events=ev, rtol=1e-12, atol=1e-14,
                            method="DOP853", dense_output=True, max_step=0.5)
            tn = sol.t_events[0][0] if sol.t_events[0].size else t_end
            sel = (t_eval >= t) & (t_eval <= tn)
            if sel.any():
                out[sel] = sol.sol(t_eval[sel])[0]
            x, v, t = sol.sol(tn)[0], 0.0, tn
            R = F(t) - k * x
            mode = 0 if abs(R) <= Ff else np.sign(R)
    return out, sticks
