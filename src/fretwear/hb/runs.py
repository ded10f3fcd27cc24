"""One run of a solver on a DLFT balance (:class:`~fretwear.hb.problem.DLFTProblem`, paper
eq. 20-28) from a start: what every rung of the attempt ladder (:mod:`fretwear.hb.attempts`)
and the polish of a sweep's points on their exact condensation
(:meth:`fretwear.hb.branch.Problems.polish`) call, so that they run the solvers the same way.
"""

from __future__ import annotations

import time

import numpy as np

from fretwear.hb.kinks import local_phase
from fretwear.hb.options import KRYLOV, SolveOptions
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.solvers import solve


def run(prob: DLFTProblem, x0, options: SolveOptions, max_slow: int | None = None):
    """One run of ``options.solver`` on ``prob`` from ``x0`` (m, H) to ``options.tol`` in at
    most ``options.max_iter`` iterations: ``(x (m, H), stats)`` (converged or the last
    iterate; ``stats.wall_time`` the whole run's). ``max_slow``: the solver's progress test
    (:func:`fretwear.hb.solvers.solve`; None: none). Powell's local phase where its steps
    crawl: :func:`fretwear.hb.kinks.local_phase`, unless the problem's Krylov options turn
    it off (:attr:`~fretwear.hb.options.KrylovOptions.local_phase`)."""

    def fun(x, jac=True):
        return prob.residual(x.reshape(prob.m, prob.H), jac)

    t0 = time.perf_counter()
    x, _, st = solve(fun, np.asarray(x0, float).reshape(-1),
                     lambda x: prob.scale(x.reshape(prob.m, prob.H)), method=options.solver,
                     tol=options.tol, max_iter=options.max_iter, max_slow=max_slow,
                     local=local_phase(prob) if (prob.krylov or KRYLOV).local_phase else None)
    st.wall_time = time.perf_counter() - t0
    return x.reshape(prob.m, prob.H), st
