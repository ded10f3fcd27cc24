"""Events located along the linearised slow path: where the contact-state pattern of the
interface changes (issue 29).

Between two changes of the pattern (which nodes slip during the period, which open) the slow
equation ``dW/dN = g(W)`` (paper eq. 29) is smooth, and a step from ``W_k`` follows it by the
linearised path ``W(N) = W_k + N phi1(N Js) g(W_k)`` (the exponential Euler path of
:mod:`fretwear.wear.exponential_step`). Along it the balance is predicted by the
implicit-function derivative ``dU~/dW`` that the slow Jacobian is made of,
``U~(N) = U~_k + dU~/dW (W(N) - W_k)``, and the contact law (eq. 23) at that prediction says
which state each node is in at each time sample: the pattern the balance would have there.
:func:`first_event` finds the first ``N`` at which the pattern differs from the step's, by
sampling the step and bisecting, and :func:`pattern_along` gives that pattern as a function
of ``N`` for a slow problem. A step that ends just past the event lands on the new pattern,
where the next slow Jacobian is right (used by
:func:`fretwear.wear.exponential_step.exponential_step` with ``events``, where a growing
mode binds). Events passed inside one step are grouped by the step's error control, as in
the march. Measured in docs/studies/method-costs.md, "Events along the path": the pattern
that matters for the cost is that of every time sample, which changes on nearly every step.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from fretwear.wear.slow_problem import SlowProblem


def first_event(key: Callable[[float], object], dN: float, *, samples: int = 8,
                rel_tol: float = 1e-3, start: float = 1e-3) -> tuple[float, float] | None:
    """The first ``N`` in ``(start dN, dN]`` at which ``key(N)`` (a pattern, compared with
    ``==``) differs from ``key(start dN)``, bracketed: ``(before, after)`` with the pattern
    of ``before`` the start's, ``after``'s another and ``after - before <= rel_tol after``;
    None when every sample has the start's pattern. The reference is taken a little into
    the step (``start``), not at its very beginning: a node that sits on the boundary of its
    state there (a stick margin of exactly 1, the law's tolerance) would flip at the first
    rounding of the prediction and announce an event at ``N = 0``. The step is sampled at
    ``samples`` geometrically spaced points (``dN 2^-(samples-1)`` up to ``dN``: an event
    early in a long step is found as well as a late one), then bisected. An event that
    starts and ends between two samples is not seen (the error control of the step still
    judges it)."""
    if dN <= 0:
        return None
    lo = start * dN
    ref = key(lo)
    grid = dN * 2.0 ** -np.arange(samples - 1, -1, -1.0)
    for N in grid[grid > lo]:
        if key(float(N)) != ref:
            hi = float(N)
            break
        lo = float(N)
    else:
        return None
    while hi - lo > rel_tol * hi:
        mid = 0.5 * (lo + hi)
        if key(mid) != ref:
            hi = mid
        else:
            lo = mid
    return lo, hi


def pattern(sp: SlowProblem, W, U, anchor) -> tuple[np.ndarray, np.ndarray]:
    """``(slipping, opening)`` (nc,) booleans: the nodes that slip, and those separated, at
    some time sample of the contact law at ``U`` (m, H) with the wear ``W`` (nc,) [m] and the
    stick anchors ``anchor``."""
    sp.set_state(W, anchor)
    _, _, state, _ = sp.prob.time_law(U)
    state = np.asarray(state)
    return np.any(state == 2, axis=1), np.any(state == 0, axis=1)


def pattern_along(sp: SlowProblem, W, U, anchor, path: Callable[[float], np.ndarray],
                  dUdW) -> Callable[[float], tuple]:
    """``key(N)``: the pattern (:func:`pattern`, as bytes, comparable with ``==``)
    predicted at ``N`` cycles along the linearised path from the balanced state ``(W, U)``:
    ``path(N)`` (nc,) [m] is ``W(N) - W_k`` on it (the exponential step's, module docstring:
    :func:`fretwear.wear.exponential_step.increment`, wear never decreasing), ``dUdW`` (n, nc)
    the balance's derivative at ``(W, U)`` (:meth:`SlowProblem.slow_jacobian`)."""
    W = np.asarray(W, float)
    U = np.asarray(U, float).reshape(sp.m, sp.H)

    def key(N: float) -> tuple:
        dW = path(N)
        slip, opened = pattern(sp, W + dW, U + (dUdW @ dW).reshape(sp.m, sp.H), anchor)
        return slip.tobytes(), opened.tobytes()

    return key
