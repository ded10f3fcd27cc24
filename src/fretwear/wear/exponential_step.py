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

import math
import time

import numpy as np
import scipy.linalg as sla

from fretwear.wear.events import first_event, pattern_along
from fretwear.wear.options import GROWTH_LIMIT, MIN_JUMP_FRACTION, WearOptions
from fretwear.wear.schemes import StepStart, accept, balance_after
from fretwear.wear.slow_problem import SlowProblem
from fretwear.wear.state import SlowStep

#: the largest ``dN lam`` of a growing mode ``lam`` of ``Js`` in one step (a growth of the
#: mode by ``e^2`` at most; the error control judges the step)
EXP_GROWTH_LIMIT = 2.0
#: with ``events``, the largest ``dN lam`` of a growing mode over which the first
#: contact-state event is looked for (a growth of ``e^8``: the stuck neighbour slips before)
EVENT_GROWTH_LIMIT = 8.0


def increment(Js, g, dN: float) -> np.ndarray:
    """The exact increment ``dN phi1(dN Js) g`` (nc,) [m] of ``dW/dN = g + Js (W - W_k)``
    over ``dN`` cycles (module docstring): ``Js`` (nc, nc) [1/cycle], ``g`` (nc,) [m/cycle]."""
    g = np.asarray(g, float)
    nc = g.size
    B = np.zeros((nc + 1, nc + 1))
    B[:nc, :nc] = dN * np.asarray(Js, float)
    B[:nc, nc] = g
    return dN * sla.expm(B)[:nc, nc]


def phi(Js, v, dN: float, k: int) -> np.ndarray:
    """``phi_k(dN Js) v`` (nc,), ``phi_k(z) = sum_j z^j / (j + k)!``, from the exponential of
    the bordered matrix ``[[dN Js, v e_1^T], [0, S]]``, ``S`` the ``k x k`` shift (Higham,
    Functions of Matrices, section 10.7.4; Hochbruck and Ostermann 2010, eq. 2.10):
    its last column holds ``phi_k(dN Js) v``."""
    v = np.asarray(v, float)
    nc = v.size
    B = np.zeros((nc + k, nc + k))
    B[:nc, :nc] = dN * np.asarray(Js, float)
    B[:nc, nc] = v
    B[nc + np.arange(k - 1), nc + 1 + np.arange(k - 1)] = 1.0
    return sla.expm(B)[:nc, -1]


def rosenbrock_error(Js, dN: float, dW, g0, g1) -> np.ndarray:
    """The local error estimate (nc,) [m] of the exponential Rosenbrock-Euler step
    ``dW = dN phi1(dN Js) g0``: ``2 dN phi3(dN Js) D`` with the nonlinear remainder
    ``D = g1 - g0 - Js dW`` (``g1`` the rate at ``W_k + dW``). It is the correction of the
    embedded third-order method exprb32 (Hochbruck, Ostermann and Schweitzer, SIAM J. Numer.
    Anal. 47, 2009, section 5.1), so the error of the second-order step is ``O(dN^3)``; it
    costs no balance (``g1`` is the step's own)."""
    D = np.asarray(g1, float) - np.asarray(g0, float) - np.asarray(Js, float) @ dW
    return 2.0 * dN * phi(Js, D, dN, 3)


def exponential_step(sp: SlowProblem, st: SlowStep, opts: WearOptions, order: int = 1,
                     cycles: float | None = None, events: bool = False):
    """One accepted slow step from ``st``: ``(new_state, record, failure)``,
    ``(None, None, message)`` when its balance failed after ``opts.max_retries`` smaller
    jumps.

    ``order = 1``: the exponential Euler step where ``Js`` has a growing mode ``lam`` that
    would cut the march's jump (``dN lam > GROWTH_LIMIT``), up to ``dN lam =
    EXP_GROWTH_LIMIT``; the march's step otherwise (:func:`fretwear.wear.schemes.advance`,
    the same numbers: the path of a march where nothing grows), with the march's error
    control.

    ``order = 2``: the exponential step everywhere (with the exact slow Jacobian it is the
    exponential Rosenbrock-Euler method, of second order: Hochbruck, Ostermann and
    Schweitzer 2009), its error estimated by :func:`rosenbrock_error` and the jump
    controlled with the cube root of ``tolerance / error``.

    ``events``: where a growing mode binds, the step ends just past the first change of the
    contact-state pattern predicted along the linearised path within ``dN lam <=
    EVENT_GROWTH_LIMIT`` (:mod:`fretwear.wear.events`; the growth ends when the loaded
    neighbour slips), else at ``EXP_GROWTH_LIMIT``; the next step starts from the jump the
    controller had proposed. Measured in docs/studies/method-costs.md ("Events along the
    path"): it does not pay, hence off by default.

    ``cycles``: the cycle count the error control's floor is a fraction of
    (``MIN_JUMP_FRACTION``; None: ``st.cycles``). The pseudo-time of the worn state's
    continuation passes the cycles of its path steps alone: after a relaxation step of
    ``1e9`` pseudo-cycles the floor would otherwise accept any jump below ``1e4``."""
    t0 = time.perf_counter()
    anchor = st.U.reshape(sp.nc, sp.d, sp.H)[:, 1:, 0].copy()  # the history rule
    sp.set_state(st.W, anchor)
    Js, dUdW = sp.slow_jacobian(st.U, with_dUdW=True)
    dN = min(st.jump, opts.max_jump, opts.max_cycles - st.cycles)
    floor = max(opts.min_jump, MIN_JUMP_FRACTION * (st.cycles if cycles is None else cycles))
    lam_plus = float(np.max(np.linalg.eigvals(Js).real))
    growing = lam_plus > 0 and dN * lam_plus > GROWTH_LIMIT  # the march would cut it
    exponential = order == 2 or growing
    look = min(dN, EVENT_GROWTH_LIMIT / lam_plus) if growing else dN
    proposal, cut = dN, False
    if growing:
        dN = min(dN, EXP_GROWTH_LIMIT / lam_plus)

    def path(dN):  # W(dN) - W_k on the linearised path, wear never decreasing
        return np.maximum(increment(Js, st.g, dN), 0.0)

    if events and growing:  # the step ends just past the first event, if it comes first
        event = first_event(pattern_along(sp, st.W, st.U, anchor, path, dUdW), look)
        if event is not None:
            dN, exponential, cut = event[1], True, True

    start = StepStart(st.W, st.U, st.g, anchor)

    def attempt(dN):  # the balance at the end of a jump of dN (as advance's _attempt)
        if exponential:
            dW = path(dN)
        else:  # the march's step, to the bit; wear never decreases
            dW = np.maximum(dN * np.linalg.solve(np.eye(sp.nc) - dN * Js, st.g), 0.0)
        return balance_after(sp, opts, start, dW, dUdW)

    error = None
    if order == 2:
        def estimate(dN, W1, g1):  # relative to the deepest wear, as local_error
            scale = float(np.max(np.abs(W1)))
            e = float(np.max(np.abs(rosenbrock_error(Js, dN, W1 - st.W, st.g, g1))))
            return 0.0 if e == 0.0 else (e / scale if scale > 0 else math.inf)
        error = (estimate, 2)
    new, record, msg = accept(sp, opts, st, anchor, attempt, (dN, floor, floor), (t0, 1, 0),
                              error)
    if cut and new is not None:
        # an event, not the error, ended the step: the next one starts from the jump the
        # controller had proposed (the next slow Jacobian caps it again where it must)
        new.jump = max(new.jump, proposal)
    return new, record, msg
