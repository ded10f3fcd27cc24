"""Nonlinear elimination of the contact nodes that hold a DLFT residual near its root: the
local phase of Powell's solve where its steps crawl.

Near the root of a large interface in partial slip, Powell's iteration can crawl (dog-leg
steps reducing ``|f|`` by a few per cent each) while almost all of the residual sits on a few
contact nodes (on the 1024-node partial-slip pad of benchmarks/scale_3d.py: two nodes holding
94 % of ``|f|^2``, sticking all period with their start state at the corner of a closing stick
set, where the root has them slip at 7 samples; the other nodes within ``1e-10`` of the root).
There the residual has a square-root branch: it leaves its linear model within ``2e-4`` of
the Newton step with no node changing regime, and no Newton-type step of the whole system gets
through (docs/studies/large-interface-solve.md, "The crawl's iterate: a square-root branch of
the law").

:func:`eliminate` solves the balance of those nodes and their neighbours alone, the other
unknowns held: their ``lambda_u`` is linear in their own unknowns (eq. 23, ``lambda_u = F - Z
U + eps (U - W)``, the coupling through the held nodes a constant) and their law the one of
the whole problem, so the subproblem's residual is that of the full problem on those rows,
exactly (up to the compression's bound where the operator carries compressed forms: the full
residual's products are then the compressed ones, the subproblem's block is cut from the exact
matrices). Its Jacobian is formed (a few nodes: ``k d H`` unknowns) and the subproblem solved
by Powell. After it, a Newton step of the whole system is the Newton step of the system with
those nodes eliminated (their rows hold ``f = 0``), on which their branch no longer acts
(Lanzkron, Rose and Wilkes 1996, nonlinear elimination). :func:`local_phase` makes the rounds
of both that :func:`fretwear.hb.solvers.powell` calls as its ``local``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fretwear.hb import contact as law
from fretwear.hb.reduce import to_real_blocks
from fretwear.hb.solvers import _lu_step, powell, solve_identity_rows, vector_norm

#: the nodes eliminated: the fewest, largest per-node residuals holding this share of
#: ``|f|^2`` (on the 1024-node crawl 14 nodes, the two worst and their neighbours: with the
#: two worst alone, 94 % of ``|f|^2``, the neighbours took the residual up and the Newton
#: steps after the elimination did not converge)
SHARE = 0.999
#: at least this many nodes (the largest per-node residuals): from the 1024-node crawl's
#: iterate at ``|f|`` 1.6e-3, where 3 nodes held 99.9 %, their elimination moved the
#: residual to the neighbours and two rounds ended above the start; with 16, four rounds
#: converged (docs/studies/large-interface-solve.md, "Entering the local phase sooner")
MIN_NODES = 16
#: at most this many nodes (their subproblem's Jacobian is formed: ``k d H`` unknowns)
MAX_NODES = 32
#: the subproblem is solved to this fraction of the whole residual's norm on its rows
LOCAL_RTOL = 1e-3
#: Powell iterations of the subproblem
LOCAL_MAX_ITER = 200
#: rounds of the local phase (:func:`local_phase`: an elimination and a Newton step of the
#: whole), each after the first reducing ``|f|`` by :data:`ROUND_RATE`
ROUNDS = 4
ROUND_RATE = 0.5
#: the relative residual of the Newton step after an elimination (GMRES on an operator
#: Jacobian; a formed one is solved exactly): 1e-3 halved the phase's CPU from the
#: 1024-node crawl (12 to 6 s) against 1e-6, ending at 6e-9 (the test asked 3e-7)
NEWTON_RTOL = 1e-3


@dataclass
class Elimination:
    """What :func:`eliminate` did: the nodes, the norm of their residual before and after
    (``before``, ``after``), and the subproblem's Powell iterations."""

    nodes: np.ndarray
    before: float
    after: float
    iterations: int


def worst_nodes(f: np.ndarray, nc: int, share: float | None = None,
                max_nodes: int | None = None) -> np.ndarray:
    """The fewest nodes (sorted) whose residuals hold ``share`` of ``|f|^2`` (default
    :data:`SHARE`), at most ``max_nodes`` (default :data:`MAX_NODES`); ``f`` (m H,)
    DOF-major, ``nc`` nodes."""
    share = SHARE if share is None else share
    max_nodes = MAX_NODES if max_nodes is None else max_nodes
    per = np.sum(np.reshape(f, (nc, -1)) ** 2, axis=1)
    order = np.argsort(per)[::-1]
    cum = np.cumsum(per[order])
    k = int(np.searchsorted(cum, share * cum[-1])) + 1
    return np.sort(order[:min(max(k, MIN_NODES), max_nodes)])


def _block(prob, dofs: np.ndarray) -> np.ndarray:
    """The real block operator ``Z~`` on ``dofs`` (k H, k H), DOF-major."""
    Z = prob.reduced.Z
    if isinstance(Z, np.ndarray):
        Zc = Z[:, dofs][:, :, dofs]
    else:  # a ReducedOperator (hb/modal_operator.py)
        Zc = np.stack([Z.block(b, rows=dofs, cols=dofs) for b in range(len(Z))])
    return to_real_blocks(Zc, prob.reduced.orders)


class FormedOperator:
    """A formed Jacobian offered to :func:`fretwear.hb.solvers.powell` as an operator (the
    interface of :class:`fretwear.hb.krylov.KrylovJacobian`: products, transpose, column
    norms and an exact LU solve), so that Powell's watchdog stretches, which serve the
    operator Jacobians of large interfaces, serve the subproblem cut from one: with the
    monotone test alone its Powell crawled (the 1024-node crawl's 9 worst nodes: 200
    iterations to 7 % of the start; with the stretches 12 iterations to 6e-6)."""

    gmres_iterations = 0
    #: Powell keeps the first Jacobian's variable scales, as on the operator Jacobians of
    #: the default :class:`~fretwear.hb.options.KrylovOptions` (what the phase was measured
    #: with)
    first_scales = True

    def __init__(self, J: np.ndarray):
        self.J = J
        self.shape = J.shape

    def __matmul__(self, v):
        return self.J @ v

    @property
    def T(self):
        return self.J.T

    def column_norms(self) -> np.ndarray:
        return np.linalg.norm(self.J, axis=0)

    def solve(self, b, rtol=None) -> np.ndarray:
        return solve_identity_rows(self.J, b)


def subproblem(prob, U: np.ndarray, nodes: np.ndarray):
    """The balance of ``nodes`` alone at ``U`` (m, H), the other unknowns held:
    ``(fun, x0, dofs)`` with ``fun(x, jac) -> (f, J)`` on the ``k d H`` unknowns of those
    nodes (the formed Jacobian ``eps I - G (eps I - Z_BB)`` as a :class:`FormedOperator`,
    its matrix ``.J``), equal to the rows of
    ``prob.residual`` at ``U`` with those unknowns replaced."""
    d, H = prob.d, prob.H
    nodes = np.asarray(nodes)
    dofs = (nodes[:, None] * d + np.arange(d)).reshape(-1)
    lam0 = prob.lambda_u(U)[dofs].reshape(-1)
    U0 = np.array(U[dofs], dtype=float).reshape(-1)
    ZB = _block(prob, dofs)
    A = prob.eps * np.eye(ZB.shape[0]) - ZB  # d lambda_u / d U on those rows
    W = prob.W[dofs].reshape(-1)
    mu = np.ascontiguousarray(prob.mu[nodes])
    start = np.ascontiguousarray(prob.eps * prob.anchor[nodes])
    normal = None if prob.normal is None else np.ascontiguousarray(prob.normal[nodes])
    k = nodes.size
    n = k * d * H

    def fun(x, jac=True):
        lam = lam0 + A @ (x - U0)
        lu = np.ascontiguousarray(prob.basis.to_time(lam.reshape(k * d, H)).reshape(k, d, -1))
        lx, state, _ = law.dlft_time(lu, mu, start, prob.tol, prob.max_sweeps, normal)
        Lx = prob.basis.to_freq(lx.reshape(k * d, -1)).reshape(-1)
        f = prob.eps * (x - W) - Lx
        if not jac:
            return f, None
        G = law.dlft_jacobian(lu, lx, state, mu, prob.P, prob.Q, start, prob.tol,
                              prob.max_sweeps, normal)
        GA = np.matmul(G, A.reshape(k, d * H, n)).reshape(n, n)
        return f, FormedOperator(prob.eps * np.eye(n) - GA)

    return fun, U0, dofs


def eliminate(prob, U: np.ndarray, f: np.ndarray, target: float):
    """Solve the balance of the nodes holding most of the residual ``f`` (m H,) at ``U``
    (m, H) (:func:`worst_nodes`) with the others held, to :data:`LOCAL_RTOL` of its start
    or ``target`` (an absolute ``|f|``), whichever is larger. Returns ``(U', report)``:
    ``U`` with those nodes' unknowns replaced (a copy; ``U`` itself if the subproblem did
    not reduce their residual), and an :class:`Elimination`."""
    nodes = worst_nodes(f, prob.nc)
    fun, x0, dofs = subproblem(prob, U, nodes)
    f0 = vector_norm(np.reshape(f, (prob.m, -1))[dofs])
    tol_abs = max(LOCAL_RTOL * f0, target)
    scale = max(vector_norm(x0) * prob.eps, 1e-300)
    x, fl, st = powell(fun, x0, lambda x: scale, tol=tol_abs / scale,
                       max_iter=LOCAL_MAX_ITER)
    after = vector_norm(fl)
    if not after < f0:
        return U, Elimination(nodes, f0, f0, st.iterations)
    out = np.array(U, dtype=float)
    out[dofs] = x.reshape(dofs.size, prob.H)
    return out, Elimination(nodes, f0, after, st.iterations)


def local_phase(prob, record=None):
    """The local phase of :func:`fretwear.hb.solvers.powell` (its ``local``) for the DLFT
    balance ``prob`` on flat unknowns: ``local(x, f, target) -> x'``. Up to :data:`ROUNDS`
    rounds, each an elimination (:func:`eliminate`) and a Newton step of the whole system
    from its point (to :data:`NEWTON_RTOL`), while each round after the first ends with
    ``|f|`` below :data:`ROUND_RATE` times the last one's and above ``target`` (the first
    may end above where it began: the elimination moves the residual to the neighbours);
    returns the best point reached (``x`` itself if none was better). On the 1024-node
    crawl (docs/studies/large-interface-solve.md) it ended the crawl. ``record``: a list to
    which each round appends ``(Elimination, |f| after it, |f| after the Newton step)``
    (studies). The callable counts its evaluations of the whole balance in its attributes
    ``nfev`` and ``njev`` (residuals, Jacobians; the subproblems' are not: a few nodes'),
    which Powell adds to its own."""
    shape = (prob.m, prob.H)

    def local(x, f, target):
        best, fbest = x, vector_norm(f)
        last = np.inf
        for _ in range(ROUNDS):
            U, rep = eliminate(prob, np.reshape(x, shape), f, 0.1 * target)
            fe, J = prob.residual(U, True)
            x = U.reshape(-1) + _lu_step(J, fe, None if isinstance(J, np.ndarray)
                                        else NEWTON_RTOL)
            f, _ = prob.residual(x.reshape(shape), False)
            local.nfev += 2
            local.njev += 1
            fn = vector_norm(f)
            if record is not None:
                record.append((rep, vector_norm(fe), fn))
            if fn < fbest:
                best, fbest = x, fn
            if fn <= target or not fn < ROUND_RATE * last:
                break
            last = fn
        return best

    local.nfev = local.njev = 0
    return local
