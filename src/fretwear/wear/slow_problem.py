"""The coupled problem of one slow step: the DLFT balance (paper eq. 22) as a function of the
wear depths ``W``, the wear rate ``g(U~, W)`` (eq. 29) with its derivatives, and the slow
Jacobian ``dg/dW`` along balanced solutions.
"""

from __future__ import annotations

import numpy as np

from fretwear.hb import contact as law
from fretwear.hb import solvers
from fretwear.hb.fallback import TimeDomainFallback
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import Reduced
from fretwear.hb.solution import PeriodicSolution, assemble_solution
from fretwear.hb.solvers import SolveStats, solve, solve_identity_rows
from fretwear.model.core import Model
from fretwear.resources import require_memory
from fretwear.wear.kernels import slip_work, slip_work_gradient


def newton(fun, x0, scale, *, tol=1e-9, max_iter=30) -> tuple[np.ndarray, SolveStats]:
    """Newton's method of :mod:`fretwear.hb.solvers` (backtracking on ``|f|^2``, the LU of the
    rows that are not plain identity rows) for the warm-started balances of the slow steps.
    Returns ``(x, stats)``."""
    x, _, st = solvers.newton(fun, x0, scale, tol=tol, max_iter=max_iter)
    return x, st


class SlowProblem:
    """The DLFT balance with wear as a function of the wear depths (one frequency).

    Parameters
    ----------
    model : the model; reduced : its condensation on ``[0] + basis.harmonics``.
    basis : Fourier basis.
    coef : (nc,) wear factors ``c_p`` [1/N] (:func:`~fretwear.wear.laws.wear_coefficients`).
    eps : DLFT penalty: ``"auto"`` (default, spectral radius of ``Z_r``), ``"static"`` or a
        positive number [N/m] (:func:`fretwear.hb.penalty.penalty`).
    anchor : (nc, d-1) stick anchors [m].
    time_domain : the fallback of failed balances (None: none).
    condenser : the condenser of ``model`` that made ``reduced``
        (:func:`fretwear.hb.reduce.exact_condenser`): the full-field recoveries of the run
        (the start of a time integration) use it; None: a new exact one at each.
    jacobian : how the Newton step is computed (:data:`fretwear.hb.options.JACOBIANS`).

    The wear depths ``W`` (nc,) [m] enter the DLFT as the normal gap ``gap0 + W``; ``E_W`` puts
    ``W_p`` into the static coefficient of the normal DOF of node ``p``.
    """

    def __init__(self, model: Model, reduced: Reduced, basis: FourierBasis, coef, *, eps="auto",
                 anchor=None, time_domain: TimeDomainFallback | None = None, condenser=None,
                 jacobian="auto"):
        self.model = model
        self.condenser = condenser
        self.time_domain = time_domain  # fallback of failed balances (None: none)
        self.gap0 = np.broadcast_to(np.asarray(model.contact.gap, float),
                                    (model.contact.n_nodes,)).copy()
        self.prob = DLFTProblem(reduced, model.contact, basis, gap=self.gap0, eps=eps,
                                anchor=anchor, jacobian=jacobian)
        p = self.prob
        self.nc, self.d, self.H, self.m = p.nc, p.d, p.H, p.m
        self.n = p.m * p.H
        self.dH = p.d * p.H
        self.eps = p.eps
        self.coef = np.asarray(coef, float)
        # index of (node p, normal component, static coefficient) in the DOF-major unknowns
        self.iw = np.arange(self.nc) * self.dH
        self._epsI_Z = None

    # -- helpers --------------------------------------------------------------------------
    def set_state(self, W, anchor):
        self.prob.set_gap(self.gap0 + np.asarray(W, float))
        self.prob.anchor = np.array(anchor, float)

    def epsI_minus_Z(self):
        """``d lambda_u~ / dU~ = eps I - Z`` (n, n), cached (the dense path only: on the
        operator path of large interfaces :meth:`rows_epsI_minus_Z` never forms it)."""
        if self._epsI_Z is None:
            A = -self.prob.Z.copy()
            A[np.diag_indices(self.n)] += self.eps
            self._epsI_Z = A
        return self._epsI_Z

    def rows_epsI_minus_Z(self, V):
        """``V_p^T (eps I - Z~)[rows of node p]`` for every node: (nc, n) from ``V`` (nc, dH).
        Dense path: with the formed ``eps I - Z~``; operator path
        (:class:`~fretwear.hb.krylov.KrylovJacobian`): by harmonic blocks
        (:meth:`~fretwear.hb.krylov.HarmonicBlocks.node_rows`), without the ``n x n``
        matrix (17 GiB at 1024 nodes and 7 harmonics)."""
        if self.prob.jacobian == "dense":
            A = self.epsI_minus_Z().reshape(self.nc, self.dH, self.n)
            return np.einsum("pi,pij->pj", V, A)
        out = -self.prob.blocks.node_rows(V)
        out.reshape(self.nc, self.nc, self.dH)[np.arange(self.nc), np.arange(self.nc)] += (
            self.eps * V)
        return out

    def rate(self, U):
        """Wear depth per cycle ``g = c S`` (nc,) [m] at ``U`` (m, H) with the current gap."""
        lu, lx, state, _ = self.prob.time_law(U)
        return self.coef * slip_work(lu, lx, state, self.eps)

    def rate_and_gradient(self, U):
        """``g`` (nc,) [m], ``dg/dU~`` (nc, n) [m/m] and ``dg/dW`` (nc,) [-] (diagonal) at the
        current gap: ``dg/dU~ = c dS/dlambda_u~ (eps I - Z)``, ``dg/dW = -eps c dS/dlambda_u,N0``.
        """
        p = self.prob
        lu, lx, state, _ = p.time_law(U)
        S, dS = slip_work_gradient(lu, lx, state, p.mu, p.Q, self.eps)
        g = self.coef * S
        gU = self.coef[:, None] * self.rows_epsI_minus_Z(dS)
        gW = -self.eps * self.coef * dS[:, 0]
        return g, gU, gW, (lu, lx, state)

    def dfdW(self, lu, lx, state):
        """``df/dW`` (n, nc) = ``-eps E_W + eps G E_W`` (G block-diagonal per node)."""
        p = self.prob
        # same arguments as DLFTProblem.residual (stick anchors for all-stick nodes)
        G = law.dlft_jacobian(lu, lx, state, p.mu, p.P, p.Q, self.eps * p.anchor, p.tol,
                              p.max_sweeps)
        out = np.zeros((self.n, self.nc))
        for q in range(self.nc):
            rows = slice(q * self.dH, (q + 1) * self.dH)
            out[rows, q] = self.eps * G[q][:, 0]
            out[q * self.dH, q] -= self.eps
        return out

    # -- residuals -------------------------------------------------------------------------
    def balance(self, U, jacobian=True):
        """DLFT residual ``f`` (n,) and Jacobian (n, n) at ``U`` (m, H), current gap."""
        return self.prob.residual(U, jacobian)

    def coupled(self, x, W_k, dN, jacobian=True):
        """Backward Euler residual on ``x = [U~ (n), W (nc)]``.

        ``R = [f(U~; W), eps (W - W_k - dN g(U~, W))]`` and its Jacobian
        ``[[J, df/dW], [-eps dN dg/dU~, eps (I - dN dg/dW)]]``.
        """
        U = x[: self.n].reshape(self.m, self.H)
        W = x[self.n :]
        self.prob.set_gap(self.gap0 + W)
        f, J = self.prob.residual(U, jacobian)
        if not jacobian:
            g = self.rate(U)
            return np.concatenate([f, self.eps * (W - W_k - dN * g)]), None
        g, gU, gW, (lu, lx, state) = self.rate_and_gradient(U)
        R = np.concatenate([f, self.eps * (W - W_k - dN * g)])
        n, nc = self.n, self.nc
        if not isinstance(J, np.ndarray):  # the operator path of large interfaces
            require_memory(8.0 * (n + nc) ** 2, "the coupled Newton Jacobian of the implicit "
                           "wear step (implicit_newton = \"coupled\"; the default "
                           "\"nested\" one does not form it)")
            J = J.toarray()
        JJ = np.empty((n + nc, n + nc))
        JJ[:n, :n] = J
        JJ[:n, n:] = self.dfdW(lu, lx, state)
        JJ[n:, :n] = -self.eps * dN * gU
        JJ[n:, n:] = 0.0
        JJ[n + np.arange(nc), n + np.arange(nc)] = self.eps * (1.0 - dN * gW)
        return R, JJ

    def slow_jacobian(self, U, with_dUdW=False):
        """Total ``dg/dW`` (nc, nc) [-] along the balanced solution at ``U`` (current gap):
        ``dg/dW + dg/dU~ dU~/dW`` with ``dU~/dW = -J^-1 df/dW`` (implicit function theorem on
        the DLFT balance). Its eigenvalues set the stability limit of explicit Euler,
        ``dN < 2 / rho``. With ``with_dUdW`` also returns ``dU~/dW`` (n, nc)."""
        f, J = self.balance(U, True)
        g, gU, gW, (lu, lx, state) = self.rate_and_gradient(U)
        dUdW = -solve_identity_rows(J, self.dfdW(lu, lx, state))
        Js = np.diag(gW) + gU @ dUdW
        return (Js, dUdW) if with_dUdW else Js

    def needs_iterative_solves(self, U) -> bool:
        """Whether the balance's step at ``U`` is solved by GMRES (operator path, active set
        above :data:`fretwear.hb.krylov.ACTIVE_DENSE_MAX`): then the slow Jacobian costs one
        iterative solve per contact node and :meth:`slow_radius` estimates its spectral
        radius from products instead."""
        from fretwear.hb.krylov import ACTIVE_DENSE_MAX

        if self.prob.jacobian == "dense":
            return False
        _, J = self.balance(U, True)
        return (not isinstance(J, np.ndarray)
                and J.active_nodes().size * self.dH > ACTIVE_DENSE_MAX)

    def slow_radius(self, U) -> float:
        """Spectral radius of the slow Jacobian ``Js`` at ``U`` (explicit Euler's stability
        limit ``2 / rho``): the eigenvalues of :meth:`slow_jacobian`, or, when the step is
        iterative (:meth:`needs_iterative_solves`), ARPACK on the products
        ``Js v = dg/dW v - dg/dU~ J^-1 (df/dW v)`` (one solve each, to 1e-3 relative: a
        bound on the jump, not a result)."""
        if self.nc < 4 or not self.needs_iterative_solves(U):  # (ARPACK: k < nc - 1)
            return float(np.max(np.abs(np.linalg.eigvals(self.slow_jacobian(U)))))
        import scipy.sparse.linalg as spla

        _, J = self.balance(U, True)
        _, gU, gW, (lu, lx, state) = self.rate_and_gradient(U)
        dfdW = self.dfdW(lu, lx, state)

        def product(v):
            v = np.real(np.asarray(v)).reshape(-1)
            return gW * v - gU @ J.solve(dfdW @ v)

        op = spla.LinearOperator((self.nc, self.nc), matvec=product, dtype=float)
        try:
            lam = spla.eigs(op, k=1, which="LM", tol=1e-3, return_eigenvectors=False,
                            v0=np.ones(self.nc))
        except spla.ArpackNoConvergence as e:
            lam = e.eigenvalues
        return float(np.max(np.abs(lam))) if np.size(lam) else 0.0

    # -- solves --------------------------------------------------------------------------
    def solve_balance(self, W, anchor, U0, *, options: SolveOptions, fast=True):
        """Periodic solution at wear ``W`` from ``U0``: ``(U (m, H), stats)``.

        With ``fast``, :func:`newton` first (warm starts converge in a few steps); if it fails,
        ``options.solver`` of :mod:`fretwear.hb.solvers` from the same start (``options``:
        its ``tol`` and ``max_iter`` too)."""
        self.set_state(W, anchor)
        p = self.prob

        def fun(x, jac=True):
            return p.residual(x.reshape(self.m, self.H), jac)

        def scale(x):
            return p.scale(x.reshape(self.m, self.H))

        x0 = np.asarray(U0, float).reshape(-1)
        its = 0
        if fast:
            x, st = newton(fun, x0, scale, tol=options.tol, max_iter=min(options.max_iter, 15))
            if st.success:
                return x.reshape(self.m, self.H), st
            its = st.iterations
        x, _, st = solve(fun, x0, scale, method=options.solver, tol=options.tol,
                         max_iter=options.max_iter)
        st.iterations += its
        return x.reshape(self.m, self.H), st

    def solve_implicit(self, W_k, dN, anchor, U0, W0, *, options: SolveOptions):
        """Backward Euler step: ``(U, W_{k+1}, stats)`` from the guess ``(U0, W0)``."""
        self.set_state(W0, anchor)
        p = self.prob
        W_k = np.asarray(W_k, float)

        def fun(x, jac=True):
            return self.coupled(x, W_k, dN, jac)

        x0 = np.concatenate([np.asarray(U0, float).reshape(-1), np.asarray(W0, float)])
        x, _, st = solve(fun, x0, lambda x: p.scale(x[: self.n].reshape(self.m, self.H)),
                         method=options.solver, tol=options.tol, max_iter=options.max_iter)
        return x[: self.n].reshape(self.m, self.H), x[self.n :].copy(), st

    def solution(self, U, W, anchor, stats) -> PeriodicSolution:
        """Post-processed periodic solution at ``(U, W)``."""
        self.set_state(W, anchor)
        return assemble_solution(self.prob, U, self.model, stats)

    def shift_guess(self, U, dW):
        """Warm start for a wear change ``dW``: nodes in contact follow the gap (``X_N = 0``
        means ``U_N,0 = gap + W``)."""
        U1 = np.array(U, float).reshape(self.nc, self.d, self.H)
        U1[:, 0, 0] += dW
        return U1.reshape(self.m, self.H)
