"""The projected contact blocks ``X^cc`` of the modal condensation by partial Cholesky
factorisations, without the ``m`` solves of the static constraint modes (docs/theory.md,
"Large interfaces").

The Craig-Bampton projection (:mod:`fretwear.hb.modal`) needs, for every matrix ``X`` of
``K, M, C, D``, the contact block ``X^cc = T^T X T`` with ``T = [I; Psi]`` (contact DOFs
first here) and ``Psi = -K_ii^-1 K_ic``: made from ``Psi``, that is ``m`` solves with
``K_ii`` (twice for the blocked condenser). Here instead:

* ``K^cc = K_cc - K_ci K_ii^-1 K_ic`` is the Schur complement of ``K_ii``: the trailing
  ``m x m`` block of a Cholesky factorisation ``P K P^T = L L^T`` whose ordering ``P`` puts
  the interior DOFs first (a fill-reducing AMD order of ``K_ii``) and the contact DOFs last
  gives it exactly, ``K^cc = L_cc L_cc^T``. CHOLMOD (kvxopt) factorises with that ordering
  (one method, no postordering; a probe vector checks it kept it); the contact block is one
  dense front of ``m^3 / 3`` flops. ``K^cc`` is only positive semi-definite (the interface
  carries the structure: a pad has a rigid motion normal to it), so ``alpha I`` is added to
  ``K_cc`` (``alpha`` the largest diagonal entry of ``K_cc``) and taken off ``L_cc L_cc^T``:
  the Schur complement of the shifted matrix is ``K^cc + alpha I`` exactly, well conditioned.
* For another matrix ``X``, the Schur complement ``S(sigma)`` of ``K - sigma X`` has
  ``dS/dsigma (0) = -(X_cc + X_ci Psi + Psi^T X_ic + Psi^T X_ii Psi) = -X^cc`` exactly
  (differentiate ``S = A_cc - A_ci A_ii^-1 A_ic`` with ``dA^-1 = A^-1 X A^-1`` and use
  ``K_ci K_ii^-1 = -Psi^T``, ``K`` symmetric). ``X^cc`` is taken as the central difference
  ``(S(-h) - S(h)) / (2 h)`` of two more partial factorisations. Its truncation error is
  ``~ (h nu)^2`` relative, ``nu`` the largest ``|eig(K_ii^-1 X_ii)|`` (for ``M``: one over
  the lowest fixed-interface eigenvalue), its rounding ``~ eps (|S| + alpha) / (h |X^cc|)``;
  ``h`` balances the two (:func:`step`). Measured against the condensation through ``Psi``
  on the pad of benchmarks/scale_3d.py: ``K^cc`` to 5e-15 relative, ``M^cc`` to 3e-9
  (docs/studies/large-interface-solve.md, "The contact blocks by partial factorisations").

The rest of the projection needs ``Psi`` only against the ``q`` columns of the interior basis
(``Psi^T Y = -K_ci K_ii^-1 Y``: a solve of ``q`` columns). Cost, measured on that pad
(CPU, load 6): at 1024 contact nodes a tie with the ``m`` solves of the dense condenser
(8.8-10.8 s against 9.6-13.2 s), at 2304 95.6 s against 129.7 s for the ``2 m`` solves of
the blocked one; three factorisations whose contact front (``m^3``: its update, CHOLMOD's
factorisation of it and the product ``L_cc L_cc^T``) dominates. CHOLMOD is needed
(``fretwear[fast]``): SciPy has no partial factorisation, and without kvxopt
:func:`fretwear.hb.modal.modal_condenser` keeps the path through ``Psi``.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numba import njit
from scipy.linalg.lapack import dlauum

from fretwear.errors import InputError
from fretwear.hb import sparse_lu

#: the relative errors of the central difference measured on the pad of
#: benchmarks/scale_3d.py at 256 contact nodes (docs/studies/large-interface-solve.md):
#: truncation ``TRUNCATION (h nu)^2``, rounding ``ROUNDING eps rho / (h nu)``
TRUNCATION = 0.2
ROUNDING = 2.0
#: power iterations that estimate ``nu`` (the largest ``|eig(K_ii^-1 X_ii)|``), and the margin
#: that covers their estimate's shortfall (it converges from below)
POWER_STEPS = 8
MARGIN = 2.0


def available() -> bool:
    """Whether the partial factorisations can run: CHOLMOD is the backend of real symmetric
    positive definite matrices here (kvxopt installed, not forced off by
    ``FRETWEAR_SPARSE_LU``)."""
    try:
        return sparse_lu.default_backend() == "cholmod"
    except InputError:  # a forced backend not available: the caller says so elsewhere
        return False


@dataclass(frozen=True)
class Difference:
    """How one ``X^cc`` (``X`` not ``K``) was found: ``step`` ``h`` of the central difference,
    ``nu`` the estimate of the largest ``|eig(K_ii^-1 X_ii)|`` (at least ``X``'s largest
    entry over ``K``'s: :func:`contact_blocks`), ``error`` the estimated
    relative error ``TRUNCATION (h nu)^2 + ROUNDING eps rho / (h nu)`` with the achieved
    ``rho = (|S| + alpha) nu / |X^cc|`` (max-norms)."""

    step: float
    nu: float
    error: float


@dataclass
class ContactBlocks:
    """The projected contact blocks ``X^cc`` (m, m) by name (``"K"``, ``"M"``, ``"C"``,
    ``"D"``, in the global frames), the :class:`Difference` of each but ``K``, the
    factorisations made and the nonzeros of the contact rows ``L_ci`` of ``L``."""

    cc: dict
    differences: dict
    factorisations: int
    nnz_contact_rows: int


class PartialFactor:
    """Schur complements onto the contact DOFs of matrices with the pattern of ``K`` (module
    docstring): the interior ordering (AMD of ``K_ii``) is found once.

    Parameters: ``K`` the blocks of the stiffness (``ii``, ``ic``, ``ci``, ``cc``:
    :func:`fretwear.hb.reduce._split`, sparse but ``cc``)."""

    def __init__(self, K):
        self._kvx = importlib.import_module("kvxopt")
        self._cholmod = importlib.import_module("kvxopt.cholmod")
        amd = importlib.import_module("kvxopt.amd")
        self.ni, self.m = K.ii.shape[0], np.shape(K.cc)[0]
        self.p_i = np.array(amd.order(self._spmatrix(K.ii)), dtype=np.int64).ravel()
        self.alpha = float(np.max(np.abs(np.diag(np.asarray(K.cc))))) or 1.0
        self.nnz_contact_rows = 0

    def _spmatrix(self, A):
        C = sp.coo_matrix(A)
        kvx = self._kvx
        return kvx.spmatrix(kvx.matrix(np.ascontiguousarray(C.data, dtype=float)),
                            kvx.matrix(C.row.astype(np.int64)),
                            kvx.matrix(C.col.astype(np.int64)), C.shape)

    def schur(self, ii, ic, ci, cc) -> np.ndarray:
        """``cc - ci ii^-1 ic`` (m, m), dense, symmetric, from the partial factorisation of
        ``[[ii, ic], [ci, cc + alpha I]]`` with the interior first in its AMD order. Raises
        ``ArithmeticError``/``ValueError`` when ``ii`` is not positive definite (CHOLMOD's)
        and RuntimeError when its factor does not reproduce the matrix (the ordering not kept,
        or a factorisation left incomplete)."""
        ni, m, cholmod = self.ni, self.m, self._cholmod
        A = sp.bmat([[ii, ic], [ci, sp.csr_matrix(np.asarray(cc))
                                + self.alpha * sp.identity(m)]], format="csc")
        p = np.concatenate([self.p_i, ni + np.arange(m, dtype=np.int64)])
        Ak = self._spmatrix(A)
        # kvxopt's options are global (restored below, under a lock: another thread's
        # factorisation would see them, or save them changed and restore them so): one
        # ordering method (the given one: by default CHOLMOD also tries its own and keeps the
        # best) and no postordering
        with sparse_lu.CHOLMOD_OPTIONS:
            saved = dict(cholmod.options)
            cholmod.options["nmethods"] = 1
            cholmod.options["postorder"] = False
            try:
                F = cholmod.symbolic(Ak, p=self._kvx.matrix(p))
                cholmod.numeric(Ak, F)
                Lk = cholmod.getfactor(F)
            finally:
                cholmod.options.clear()
                cholmod.options.update(saved)
        del F, Ak
        ptr, rows, vals = Lk.CCS
        del Lk
        ptr = np.asarray(ptr, dtype=np.int64).ravel()
        rows = np.asarray(rows, dtype=np.int64).ravel()
        vals = np.asarray(vals, dtype=float).ravel()
        L = sp.csc_matrix((vals, rows, ptr), shape=A.shape)
        x = np.random.default_rng(0).standard_normal(ni + m)
        y = np.empty_like(x)
        y[p] = x
        Ax = (A @ y)[p]  # P A P^T x
        if not np.linalg.norm(L @ (L.T @ x) - Ax) <= 1e-10 * np.linalg.norm(Ax):
            raise RuntimeError("CHOLMOD's factor does not reproduce the matrix: another "
                               "ordering than the one given, or a matrix not positive "
                               "definite (a factorisation left incomplete)")
        del L
        # the contact rows: L_ci (sparse, its fill measured) and L_cc (dense lower triangle)
        self.nnz_contact_rows = int(np.count_nonzero(rows[:ptr[ni]] >= ni))
        S = _lower_product(ptr[ni:] - ptr[ni], rows[ptr[ni]:] - ni, vals[ptr[ni]:], m)
        S[np.diag_indices(m)] -= self.alpha
        return S


def _lower_product(ptr, rows, vals, m: int) -> np.ndarray:
    """``L L^T`` (m, m), symmetric, for the lower triangular ``L`` given by compressed columns
    (``ptr``, ``rows``, ``vals``), by LAPACK's ``dlauum`` (``m^3 / 3`` flops: a third of a
    general product's): with ``J`` the reversal of the order, ``U = J L J`` is upper
    triangular and ``L L^T = J (U U^T) J``."""
    U = np.zeros((m, m), order="F")
    counts = np.diff(ptr)
    if np.array_equal(counts, m - np.arange(m)) and np.all(rows[ptr[:-1]] == np.arange(m)):
        for j in range(m):  # a dense front (as CHOLMOD's supernodes): rows j..m-1 in order
            U[:m - j, m - 1 - j] = vals[ptr[j]:ptr[j + 1]][::-1]
    else:  # entries placed one by one
        U[m - 1 - rows, m - 1 - np.repeat(np.arange(m), counts)] = vals
    P, info = dlauum(U, lower=0, overwrite_c=1)  # upper triangle of U U^T
    if info:
        raise RuntimeError(f"dlauum: info = {info}")
    S = np.empty((m, m))
    _reversed_symmetric(P, S)
    return S


@njit(cache=True)
def _reversed_symmetric(P, out):
    """``out[i, j] = P[m-1-i, m-1-j]`` with ``P`` symmetric and only its upper triangle
    read, tile by tile (both arrays' rows and columns stay in cache: the strided copies of
    NumPy took as long as the product at 1024 contact nodes)."""
    m = P.shape[0]
    tile = 64
    for i0 in range(0, m, tile):
        for j0 in range(0, m, tile):
            for i in range(i0, min(i0 + tile, m)):
                a = m - 1 - i
                for j in range(j0, min(j0 + tile, m)):
                    b = m - 1 - j
                    out[i, j] = P[a, b] if a <= b else P[b, a]


def _nu(lu, Xii, rng) -> float:
    """An estimate of the largest ``|eig(K_ii^-1 X_ii)|`` (:data:`POWER_STEPS` power
    iterations through the factorisation ``lu`` of ``K_ii``), times :data:`MARGIN`."""
    x = rng.standard_normal(Xii.shape[0])
    x /= np.linalg.norm(x)
    nu = 0.0
    for _ in range(POWER_STEPS):
        y = lu.solve(Xii @ x)
        nu = float(np.linalg.norm(y))
        if nu == 0.0:
            return 0.0
        x = y / nu
    return MARGIN * nu


def _largest(B) -> float:
    """The largest ``|entry|`` of the blocks ``B`` (``ii``, ``ic``, ``cc``; ``ci`` is
    ``ic``'s transpose: the matrices are symmetric), 0 for none."""
    vals = [sp.csr_matrix(b).data if sp.issparse(b) else np.asarray(b)
            for b in (B.ii, B.ic, B.cc)]
    # max and -min: no |.| copy of the dense m x m contact block
    return max(max(float(v.max()), -float(v.min())) if v.size else 0.0 for v in vals)


def step(nu: float, rho: float) -> float:
    """The step ``h`` of the central difference that balances its truncation
    ``TRUNCATION (h nu)^2`` and rounding ``ROUNDING eps rho / (h nu)``:
    ``(h nu)^3 = ROUNDING eps rho / (2 TRUNCATION)``, at most ``1e-2 / nu``."""
    t = (ROUNDING * np.finfo(float).eps * rho / (2 * TRUNCATION)) ** (1.0 / 3.0)
    return min(t, 1e-2) / nu


def contact_blocks(K, others: dict, lu) -> ContactBlocks:
    """``X^cc`` of ``K`` and of every matrix of ``others`` (name: blocks as ``K``'s; each
    symmetric) by partial factorisations (module docstring); ``lu`` a factorisation of
    ``K_ii`` (for the estimates of ``nu``). Needs kvxopt (:func:`available`)."""
    pf = PartialFactor(K)
    S0 = pf.schur(K.ii, K.ic, K.ci, K.cc)
    cc, diffs, count = {"K": S0}, {}, 1
    scale = float(np.max(np.abs(S0))) + pf.alpha
    rng = np.random.default_rng(0)
    for name, X in others.items():
        nu = _nu(lu, X.ii, rng)
        # |X^cc| is not known before: the contact block of X stands for it (its interior
        # block where the contact block has a zero diagonal)
        xcc = (float(np.max(np.abs(np.diag(np.asarray(X.cc))), initial=0.0))
               or float(np.max(np.abs(X.ii.diagonal()), initial=0.0)))
        # X's largest entry over K's bounds nu from below: where X lives on the contact DOFs
        # alone (dashpots at the interface: X_ii = 0, the power iterations give 0, S(sigma)
        # is quadratic and its central difference exact) or mostly, the step keeps h X a
        # small fraction of K, so that K -/+ h X stays positive definite and the rounding
        # small; where X is carried by the interior, nu is the larger (its largest entry is
        # on its diagonal, X_jj / K_jj <= nu)
        nu = max(nu, _largest(X) / _largest(K)) or 1.0  # X = 0: X^cc = 0 at any step
        h = step(nu, scale * nu / max(xcc, 1e-300 * scale))
        Sm = pf.schur(K.ii + h * X.ii, K.ic + h * X.ic, K.ci + h * X.ci,
                      np.asarray(K.cc) + h * np.asarray(X.cc))
        Sp = pf.schur(K.ii - h * X.ii, K.ic - h * X.ic, K.ci - h * X.ci,
                      np.asarray(K.cc) - h * np.asarray(X.cc))
        count += 2
        Xcc = Sp
        np.subtract(Sm, Sp, out=Xcc)
        Xcc /= 2.0 * h  # S(-h) = S(0) + h X^cc + ..: X^cc = (S(-h) - S(h)) / 2h
        del Sm
        rho = scale * nu / max(float(np.max(np.abs(Xcc))), 1e-300)
        t = h * nu
        diffs[name] = Difference(h, nu, TRUNCATION * t * t
                                 + ROUNDING * np.finfo(float).eps * rho / t)
        cc[name] = Xcc
    return ContactBlocks(cc, diffs, count, pf.nnz_contact_rows)
