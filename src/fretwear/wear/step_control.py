"""Error control of the slow steps: the local error estimate of a step and the next jump.

The local error is estimated by the defect against the trapezoidal rule
``|W_{k+1} - W_k - dN (g(W_k) + g(W_{k+1}))/2|`` (no extra solve), relative to the current
maximum wear depth; the jump then grows or shrinks with the square root of
``tolerance / error`` (first-order schemes).
"""

from __future__ import annotations

import math

import numpy as np

from fretwear.wear.options import WearOptions


def local_error(dN, W1, W_k, g1, g0) -> float:
    """Local error estimate: the defect of the step against the trapezoidal rule,
    ``max |W1 - W_k - dN (g0 + g1) / 2|``, relative to ``max W1``.

    For explicit and backward Euler it is ``0.5 dN max|g1 - g0|`` (the classical estimate of
    their local error); for the linearly implicit step it also catches an increment that does
    not match the rates at either end (a slow Jacobian made stale by a change of contact states).
    """
    scale = float(np.max(np.abs(W1))) if np.size(W1) else 0.0
    defect = np.asarray(W1) - np.asarray(W_k) - 0.5 * dN * (np.asarray(g0) + np.asarray(g1))
    num = float(np.max(np.abs(defect))) if np.size(defect) else 0.0
    if num == 0.0:
        return 0.0
    return num / scale if scale > 0 else math.inf


def root(x: float, order: int) -> float:
    """``x^(1 / (order + 1))``: the factor on a jump that brings a local error growing as
    ``dN^(order + 1)`` from ``tolerance / x`` to the tolerance (``math.sqrt`` for the
    first-order schemes, to the bit)."""
    return math.sqrt(x) if order == 1 else x ** (1.0 / (order + 1))


def next_jump(dN: float, err: float, opts: WearOptions, fixed: float,
              grow_limit: float = 5.0, order: int = 1) -> float:
    """The jump proposed after an accepted step of ``dN`` cycles with error estimate ``err``
    (``fixed``, the jump in force, without ``adaptive``) of a scheme of ``order`` (its local
    error grows as ``dN^(order + 1)``)."""
    if not opts.adaptive:
        return fixed
    grow = 5.0 if err == 0.0 else min(5.0, max(0.2, 0.9 * root(opts.tolerance / err, order)))
    return dN * min(grow, grow_limit)
