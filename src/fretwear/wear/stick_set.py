"""The stick-set jump: the null-wear-rate state that follows from a set of sticking nodes,
found by a handful of DLFT balances instead of a march (issue 29; docs/theory.md, "The worn
state directly").

At a null-wear-rate state ``g(W*) = 0`` (paper eq. 29) every contact node either sticks all
period (no slip, no wear) or carries no load: it has worn until it just touches, its worn gap
equal to its largest closure over the period. Given the set ``R`` of the nodes that wear (the
complement of the stick set ``S``), the state is one balance:

1. the DLFT balance (eq. 22) with the nodes of ``R`` lifted off (their gap opened by ``D``,
   far more than any closure), the nodes of ``S`` at their gap and stick anchors;
2. each node ``p`` of ``R`` worn until it just touches: ``W_p = W_p + D - s_p``, ``s_p`` its
   smallest separation over the period (never below its present wear: a node already clear
   keeps it); the balance at these depths is the one of step 1 (a node that just touches
   carries nothing);
3. consistency: the wear rate there. The nodes of ``S`` that slip now (the load the worn
   nodes shed made them slip) join ``R`` and the loop goes on (an active-set iteration on
   the complementarity "stick, or unloaded"); it ends when the largest rate is at most
   ``tolerance`` of the reference one.

The nodes of ``S`` keep the wear and anchors of the state the jump starts from: the worn
state depends on the path (a node that slipped for a while before it stuck keeps that partial
wear; a loaded node that sticks now may slip and wear later, once its neighbours have
unloaded), and a jump from a state that has not yet passed those events misses them. The
caller (:func:`fretwear.wear.worn_state.worn_state`) therefore takes the jump only from states
of the path, and accepts it only when the jumps from two states agree and the path is heading
for them (:class:`fretwear.wear.worn_state._Jumps`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fretwear.hb.options import SolveOptions
from fretwear.wear.slow_problem import SlowProblem

#: a node wears when its rate exceeds this fraction of the reference rate
WEARS = 1e-9
#: the lift-off ``D`` is this many times the largest displacement and wear, then x 100 at
#: most twice if a lifted node still touches
LIFT = 100.0
#: Newton iterations of each balance of a jump (a jump that needs more is dropped: the
#: caller goes on along the path)
MAX_ITER = 12


@dataclass(frozen=True)
class StickSetState:
    """A null-wear-rate state from :func:`stick_set_state`.

    Attributes
    ----------
    W : (nc,) wear depths [m]; U : (m, H) its balance; g : (nc,) its rate [m/cycle].
    worn : (nc,) the nodes unloaded by the jump (outside the stick set).
    rounds : active-set rounds taken.
    """

    W: np.ndarray
    U: np.ndarray
    g: np.ndarray
    worn: np.ndarray
    rounds: int


def stick_set_state(sp: SlowProblem, W, U, anchor, g, *, g0: float, options: SolveOptions,
                    tolerance: float = 1e-6, max_rounds: int = 8
                    ) -> tuple[StickSetState | None, int]:
    """The null-wear-rate state from the balanced state ``(W, U, anchor)`` with rate ``g``
    (module docstring): ``(state, iterations)``, ``state`` None when a balance failed or the
    active set did not settle in ``max_rounds`` (``iterations``: the Newton iterations
    spent either way). ``g0`` [m/cycle] is the reference rate of ``tolerance`` and
    :data:`WEARS`; ``options`` the solves' (at most :data:`MAX_ITER` iterations)."""
    W = np.asarray(W, float)
    U = np.asarray(U, float).reshape(sp.m, sp.H)
    worn = np.asarray(g, float) > WEARS * g0
    opts = options.replace(max_iter=min(options.max_iter, MAX_ITER))
    its = 0
    for rounds in range(1, max_rounds + 1):
        W1, U1, n = _lifted(sp, W, U, anchor, worn, opts)
        its += n
        if W1 is None:
            return None, its
        sep = separation(sp, U1)
        W2 = np.where(worn, np.maximum(W, W1 - sep), W)
        U2, st = sp.solve_balance(W2, anchor, U1, options=opts)
        its += st.iterations
        if not st.success:
            return None, its
        sp.set_state(W2, anchor)
        g2 = sp.rate(U2)
        if float(np.max(g2)) <= tolerance * g0:
            return StickSetState(W2, U2, g2, worn, rounds), its
        more = worn | (g2 > WEARS * g0)
        if np.array_equal(more, worn):  # an unloaded node wears: not a state of this set
            return None, its
        worn, U = more, U2
    return None, its


def _lifted(sp: SlowProblem, W, U, anchor, worn, opts: SolveOptions):
    """The balance with the ``worn`` nodes lifted off: ``(W1, U1, iterations)``, ``W1``
    None when it failed or a lifted node still touches after two larger lifts."""
    D = LIFT * (float(np.max(np.abs(U))) + float(np.max(W)))
    its = 0
    for _ in range(3):
        W1 = W + np.where(worn, D, 0.0)
        U1, st = sp.solve_balance(W1, anchor, U, options=opts)
        its += st.iterations
        if not st.success:
            return None, None, its
        sp.set_state(W1, anchor)
        if np.all(separation(sp, U1)[worn] > 0):
            return W1, U1, its
        D *= LIFT
    return None, None, its


def separation(sp: SlowProblem, U) -> np.ndarray:
    """(nc,) the smallest normal separation over the period [m] of every node separated all
    period at the balance ``U`` (current gap), 0 for the others: ``-lambda_u,N / eps``
    (eq. 23: a separated node has ``lambda = 0``, so ``lambda_u = eps (U - W~)``)."""
    lu, _, st, _ = sp.prob.time_law(U)
    sep = np.min(-lu[:, 0, :], axis=1) / sp.eps
    return np.where(np.all(st == 0, axis=1), np.maximum(sep, 0.0), 0.0)
