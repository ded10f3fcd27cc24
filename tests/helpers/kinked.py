"""A piecewise-linear problem with a kink per unknown and its known root, on which Powell's
watchdog stretches and local phase are checked (tests/hb/test_solvers.py,
tests/hb/test_kinks.py)."""

import numpy as np


def kinked(seed, n=20, slope=1000.0):
    """A piecewise-linear strongly monotone problem of n unknowns with a kink per unknown
    and its root: ``A x + D max(x - t, 0) = A x* + D max(x* - t, 0)`` with ``A`` symmetric
    positive definite and ``D >= 0`` diagonal (slopes up to ``slope``: the gradient of a
    strongly convex function, so ``x*`` is its only root); the Jacobian is that of the piece
    of ``x`` (as the DLFT law's kinks, stick / slip / separation, give). Returns ``(fun,
    x_star, scale)``, ``fun(x, need_jacobian) -> (f, J or None)`` and ``scale`` the largest
    right-hand side entry."""
    rng = np.random.default_rng(seed)
    B = rng.standard_normal((n, n))
    A = B @ B.T / n + 0.1 * np.eye(n)
    t, D, x_star = rng.standard_normal(n), slope * rng.random(n), rng.standard_normal(n)
    rhs = A @ x_star + D * np.maximum(x_star - t, 0.0)

    def fun(x, need_jacobian):
        f = A @ x + D * np.maximum(x - t, 0.0) - rhs
        return f, (A + np.diag(D * (x > t))) if need_jacobian else None

    return fun, x_star, np.abs(rhs).max()
