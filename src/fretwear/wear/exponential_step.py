"""The exponential Euler slow step: the pseudo-time steps of the worn state directly
(:mod:`fretwear.wear.worn_state`; issue 29).

The march's step (:func:`fretwear.wear.schemes.advance`, scheme ``"rosenbrock"``) is the
linearly implicit Euler step on ``dW/dN = g(W)`` (paper eq. 29),

    W_{k+1} = W_k + dN (I - dN Js)^-1 g(W_k),      then the DLFT balance (eq. 22) at W_{k+1},

``Js = dg/dW`` along balanced solutions. Where wear moves load onto a stuck neighbour until it
slips, ``Js`` has a growing mode (eigenvalue ``lam > 0``: the neighbour's rate grows as
``e^{lam N}``); ``I - dN Js`` is singular at ``dN lam = 1``, and the march keeps
``dN lam <= 0.5`` (:data:`fretwear.wear.options.GROWTH_LIMIT`): on Stromberg's beam the two
bursts of such a slip cost about 20 of its 75 steps, each growing the rate by at most
``e^0.5``.

Where such a mode would cut the march's jump, the step is instead the exponential Euler
step (Hochbruck and Ostermann, Acta Numerica 19, 2010, section 2.2)
integrates the linearised equation ``dW/dN = g(W_k) + Js (W - W_k)`` exactly:

    W_{k+1} = W_k + dN phi1(dN Js) g(W_k),      phi1(z) = (e^z - 1) / z,

then the same balance. It has the linearly implicit step's stiff limit (both tend to Newton's
step on ``g = 0``, ``-Js^-1 g``, as ``dN Js -> -inf``: the pseudo-transient continuation of
:mod:`fretwear.wear.worn_state` keeps its end) and follows a growing mode exactly, so its
steps are bounded by ``dN lam <= EXP_GROWTH_LIMIT`` and by the error control
(:mod:`fretwear.wear.step_control`, the same local error estimate and the same tolerance),
which judges what the linearisation misses (contact states that switch). ``phi1(dN Js) g`` is
the last column of the exponential of the bordered matrix ``[[dN Js, g], [0, 0]]`` (Higham,
Functions of Matrices, SIAM 2008, section 10.7.4).

Elsewhere the step is the march's, to the bit: the exponential step, although more accurate,
moves the path, and the worn state depends on it (on a reduced Stromberg triangle beam,
exponential steps throughout land 1.15 % of the deepest wear from the march's state, the
march's own steps 0.22 %). Everything else is the march's step too: the history rule of the
stick anchors, the predictor of the balance from ``dU~/dW``, the retries of a failed
balance, the rejection of a step whose error estimate exceeds the tolerance.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.linalg as sla

from fretwear.wear.options import GROWTH_LIMIT, MIN_JUMP_FRACTION, WearOptions
from fretwear.wear.schemes import StepStart, accept, balance_after
from fretwear.wear.slow_problem import SlowProblem
from fretwear.wear.state import SlowStep

#: the largest ``dN lam`` of a growing mode ``lam`` of ``Js`` in one step (a growth of the
#: mode by ``e^2`` at most; the error control judges the step)
EXP_GROWTH_LIMIT = 2.0


def increment(Js, g, dN: float) -> np.ndarray:
    """The exact increment ``dN phi1(dN Js) g`` (nc,) [m] of ``dW/dN = g + Js (W - W_k)``
    over ``dN`` cycles (module docstring): ``Js`` (nc, nc) [1/cycle], ``g`` (nc,) [m/cycle]."""
    g = np.asarray(g, float)
    nc = g.size
    B = np.zeros((nc + 1, nc + 1))
    B[:nc, :nc] = dN * np.asarray(Js, float)
    B[:nc, nc] = g
    return dN * sla.expm(B)[:nc, nc]


def exponential_step(sp: SlowProblem, st: SlowStep, opts: WearOptions):
    """One accepted slow step from ``st``: ``(new_state, record, failure)``,
    ``(None, None, message)`` when its balance failed after ``opts.max_retries`` smaller
    jumps. The exponential Euler step where ``Js`` has a growing mode ``lam`` that would cut
    the march's jump (``dN lam > GROWTH_LIMIT``), up to ``dN lam = EXP_GROWTH_LIMIT``; the
    march's step otherwise (:func:`fretwear.wear.schemes.advance`, the same numbers: the
    path of a march where nothing grows)."""
    t0 = time.perf_counter()
    anchor = st.U.reshape(sp.nc, sp.d, sp.H)[:, 1:, 0].copy()  # the history rule
    sp.set_state(st.W, anchor)
    Js, dUdW = sp.slow_jacobian(st.U, with_dUdW=True)
    dN = min(st.jump, opts.max_jump, opts.max_cycles - st.cycles)
    floor = max(opts.min_jump, MIN_JUMP_FRACTION * st.cycles)
    lam_plus = float(np.max(np.linalg.eigvals(Js).real))
    exponential = lam_plus > 0 and dN * lam_plus > GROWTH_LIMIT  # the march would cut it
    if exponential:
        dN = min(dN, EXP_GROWTH_LIMIT / lam_plus)

    start = StepStart(st.W, st.U, st.g, anchor)

    def attempt(dN):  # the balance at the end of a jump of dN (as advance's _attempt)
        if exponential:
            dW = increment(Js, st.g, dN)
        else:  # the march's step, to the bit
            dW = dN * np.linalg.solve(np.eye(sp.nc) - dN * Js, st.g)
        return balance_after(sp, opts, start, np.maximum(dW, 0.0), dUdW)  # wear never decreases

    return accept(sp, opts, st, anchor, attempt, (dN, floor, floor), (t0, 1, 0))
