"""Sparse direct factorisations of the interior matrices of the condensations, behind one door.

The exact condensation (eq. 19, :mod:`fretwear.hb.reduce`) and the modal one
(:mod:`fretwear.hb.modal`) factorise the interior block ``Z_ii`` of the dynamic stiffness: the
real symmetric positive definite ``K_ii`` (harmonic 0, the static constraint modes
``Psi = -K_ii^-1 K_ic``, the shift-invert Lanczos of the fixed-interface modes) and the complex
symmetric ``Z_ii(n w) = K_ii - (n w)^2 M_ii + i (...)``, each solved for many right-hand sides.
:func:`factor` returns a factorisation with ``solve(B)`` (``B`` (n,) or (n, k), real or
complex) and the ``name`` of the backend that made it:

- ``"cholmod"``: the supernodal Cholesky factorisation of CHOLMOD (SuiteSparse) for the real
  symmetric positive definite matrices, from the optional extra ``fretwear[fast]`` (package
  kvxopt, whose wheels bundle SuiteSparse and OpenBLAS: no system library needed). Its
  solves of many right-hand sides (:data:`MANY` or more) go supernode by supernode through
  NumPy's BLAS 3 (:mod:`fretwear.hb.supernodal`: 4-5 x faster than CHOLMOD's own solve as
  kvxopt links it), where SuperLU's go column by column; benchmarks/sparse_solvers.py
  measures both.
- ``"superlu"``: SciPy's SuperLU, always there: every complex matrix (kvxopt's UMFPACK solved
  these 4-8 x slower than SuperLU, measured on the scale_3d pad), and every matrix when
  kvxopt is not installed. Its default column ordering (COLAMD) was measured best on these
  matrices (``MMD_AT_PLUS_A``: 5 x slower factorisation of ``K_ii`` at 1024 contact nodes).

``backend=None`` takes CHOLMOD where it applies and is installed, else SuperLU; the
environment variable ``FRETWEAR_SPARSE_LU=superlu`` forces SuperLU. :func:`default_backend`
says which one a real SPD matrix gets; every factorisation carries its ``name``, which the
condensers record (``Condenser.lu_backends``) and log.
"""

from __future__ import annotations

import importlib
import logging
import os
import threading

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fretwear.errors import InputError
from fretwear.hb.supernodal import SupernodalFactor

log = logging.getLogger(__name__)

#: the backends, preferred first
BACKENDS = ("cholmod", "superlu")
#: the kinds of matrix :func:`factor` takes: ``"spd"`` real symmetric positive definite,
#: ``"general"`` anything square (complex symmetric included)
KINDS = ("spd", "general")
#: the environment variable that forces a backend (``superlu``)
ENV = "FRETWEAR_SPARSE_LU"
#: right-hand sides from which a CHOLMOD factorisation solves through NumPy's BLAS
#: (:mod:`fretwear.hb.supernodal`) instead of CHOLMOD's own solve
MANY = 8
#: pivots spanning more than this ratio: a nearly singular matrix (as reduce's dense check)
NEAR_SINGULAR = 1e-13
#: held while kvxopt's CHOLMOD options (one dict for the process) are changed or read by a
#: symbolic analysis (here and :mod:`fretwear.hb.schur`): no state, a lock between threads
CHOLMOD_OPTIONS = threading.Lock()


class SingularError(RuntimeError):
    """The matrix is singular (``near``: nearly, its pivots span more than 13 decades)."""

    def __init__(self, near: bool):
        super().__init__("nearly singular" if near else "singular")
        self.near = near


def _kvxopt():
    """kvxopt's ``(kvxopt, cholmod)`` modules, or None when the optional extra is missing
    (or does not load)."""
    try:
        kvx = importlib.import_module("kvxopt")
        return kvx, importlib.import_module("kvxopt.cholmod")
    except ImportError:
        return None


def available() -> list[str]:
    """The backends importable here, preferred first."""
    return [b for b in BACKENDS if b == "superlu" or _kvxopt() is not None]


def default_backend() -> str:
    """The backend :func:`factor` gives a real symmetric positive definite matrix without
    ``backend=``: ``$FRETWEAR_SPARSE_LU`` if set (an :class:`~fretwear.errors.InputError` if
    it names none available here), else the first available of :data:`BACKENDS`."""
    forced = os.environ.get(ENV, "").strip().lower()
    have = available()
    if forced:
        if forced not in have:
            raise InputError(f"{ENV} = {forced!r}: expected one of the sparse solvers "
                             f"available here, {have} (cholmod: pip install 'fretwear[fast]')")
        return forced
    return have[0]


def factor(A, kind: str = "general", backend: str | None = None):
    """A factorisation of the sparse square matrix ``A`` with ``solve(B)`` and ``name``.

    ``kind``: ``"spd"`` for a real symmetric positive definite ``A`` (CHOLMOD's Cholesky when
    available; a matrix it finds not positive definite goes to SuperLU, which says whether it
    is singular), ``"general"`` otherwise (SuperLU). ``backend``: one of :func:`available`
    (None: :func:`default_backend`). Raises :class:`SingularError` for a (nearly) singular
    ``A``."""
    if kind not in KINDS:
        raise InputError(f"kind = {kind!r}: expected one of {KINDS}")
    name = default_backend() if backend is None else backend
    if name not in available():
        raise InputError(f"backend = {name!r}: expected one of {available()}")
    A = sp.csc_matrix(A)
    if name == "cholmod" and kind == "spd" and A.dtype.kind != "c":
        try:
            return _Cholmod(A)
        except (ArithmeticError, ValueError):  # not positive definite: SuperLU says why
            log.debug("CHOLMOD: not positive definite; SuperLU instead")
    return _SuperLU(A)


class _Factor:
    """What the backends share: a real factorisation solves a complex right-hand side by
    its real and imaginary parts; ``nbytes`` is the factors' memory."""

    name = ""
    complex = False
    nbytes = 0

    def solve(self, B):
        B = np.asarray(B)
        if B.dtype.kind == "c" and not self.complex:
            re = self._solve(np.ascontiguousarray(B.real, dtype=float))
            if not np.any(B.imag):
                return re.astype(complex)
            return re + 1j * self._solve(np.ascontiguousarray(B.imag, dtype=float))
        return self._solve(B.astype(complex if self.complex else float, copy=False))

    def _solve(self, B):
        raise NotImplementedError

    def solve_few(self, B):
        """``solve(B)`` for a ``B`` of a few columns (a dozen): through the backend's own
        solve, without making what only the solves of many columns use."""
        return self.solve(B)

    def release(self) -> None:
        """Drop what only the solves of many columns use (nothing here)."""


class _SuperLU(_Factor):
    """SciPy's SuperLU with its default (COLAMD) ordering."""

    name = "superlu"

    def __init__(self, A):
        self.complex = A.dtype.kind == "c"
        try:
            self.lu = spla.splu(A)
        except RuntimeError as exc:
            raise SingularError(False) from exc
        diag = np.abs(self.lu.U.diagonal())
        if diag.size and (not np.all(np.isfinite(diag))
                          or diag.min() <= NEAR_SINGULAR * diag.max()):
            raise SingularError(bool(diag.min() > 0))
        self.nbytes = (self.lu.L.nnz + self.lu.U.nnz) * (16 if self.complex else 8)

    @property
    def U(self):  # the interface of SciPy's SuperLU that callers read
        return self.lu.U

    @property
    def L(self):
        return self.lu.L

    def _solve(self, B):
        return self.lu.solve(B)


class _Cholmod(_Factor):
    """CHOLMOD's supernodal Cholesky ``P A P^T = L L^T`` (kvxopt); its pivots ``L_jj^2``
    spanning more than :data:`NEAR_SINGULAR`: nearly singular."""

    name = "cholmod"

    def __init__(self, A):
        kvx, cholmod = _kvxopt()
        self._kvx, self._cholmod = kvx, cholmod
        C = A.tocoo()
        self.A = kvx.spmatrix(kvx.matrix(np.ascontiguousarray(C.data, dtype=float)),
                              kvx.matrix(C.row.astype(np.int64)),
                              kvx.matrix(C.col.astype(np.int64)), A.shape)
        with CHOLMOD_OPTIONS:  # CHOLMOD's default options (no other thread's changes)
            self.F = cholmod.symbolic(self.A)
        cholmod.numeric(self.A, self.F)  # ArithmeticError: not positive definite
        # ValueError: not positive definite (the factor is left incomplete)
        d = np.abs(np.asarray(cholmod.diag(self.F))).ravel() ** 2
        if d.size and (not np.all(np.isfinite(d)) or d.min() <= NEAR_SINGULAR * d.max()):
            raise SingularError(bool(d.min() > 0))
        self.n = A.shape[0]
        self.nbytes = 8 * A.nnz * 8  # an estimate: kvxopt does not report the factor's size
        self._A, self._sn = A, None

    def _solve(self, B):
        if B.ndim > 1 and B.shape[1] >= MANY:
            return self._supernodal().solve(B)
        return self._own_solve(B)

    def solve_few(self, B):
        """``solve(B)`` by CHOLMOD's own solve whatever the number of columns: the supernodal
        panels of :meth:`_supernodal` cost a second factorisation (25 s at 4096 contact
        nodes of benchmarks/scale_3d.py), more than a dozen columns solved here."""
        B = np.asarray(B)
        if B.dtype.kind == "c":
            return self.solve_few(B.real) + 1j * self.solve_few(B.imag)
        return self._own_solve(B)

    def _own_solve(self, B):
        """CHOLMOD's own solve of a real ``B`` (n,) or (n, k)."""
        one = B.ndim == 1
        X = self._kvx.matrix(np.asfortranarray(B.reshape(self.n, -1), dtype=float))
        self._cholmod.solve(self.F, X)
        X = np.array(X)
        return X[:, 0] if one else X

    def _supernodal(self) -> SupernodalFactor:
        """The factor's solves with NumPy's BLAS (:mod:`fretwear.hb.supernodal`), made at the
        first solve of :data:`MANY` right-hand sides or more: a second factorisation with
        CHOLMOD's AMD ordering given explicitly and no postordering, so that the permutation
        of ``P A P^T = L L^T`` is known (``F`` stays for the solves of few columns: reading
        ``L`` out of a CHOLMOD factor consumes it), checked on a probe vector."""
        if self._sn is not None:
            return self._sn
        kvx, cholmod = self._kvx, self._cholmod
        amd = importlib.import_module("kvxopt.amd")
        C = self._A.tocoo()
        Ak = kvx.spmatrix(kvx.matrix(np.ascontiguousarray(C.data, dtype=float)),
                          kvx.matrix(C.row.astype(np.int64)),
                          kvx.matrix(C.col.astype(np.int64)), self._A.shape)
        p = np.array(amd.order(Ak), dtype=np.int64).ravel()
        with CHOLMOD_OPTIONS:  # kvxopt's options are global: restored below
            saved = dict(cholmod.options)
            cholmod.options["postorder"] = False
            try:
                F = cholmod.symbolic(Ak, p=kvx.matrix(p))
                cholmod.numeric(Ak, F)
                Lk = cholmod.getfactor(F)
            finally:
                cholmod.options.clear()
                cholmod.options.update(saved)
        ptr, rows, vals = Lk.CCS  # compressed columns as they are (no triplets: 4096
        del Lk, F  # contact nodes' factor holds 1e8 entries)
        L = sp.csc_matrix((np.asarray(vals, dtype=float).ravel(),
                           np.asarray(rows, dtype=np.int64).ravel(),
                           np.asarray(ptr, dtype=np.int64).ravel()), shape=self._A.shape)
        del ptr, rows, vals
        x = np.random.default_rng(0).standard_normal(self.n)
        Ax = self._A[p][:, p] @ x
        if not np.linalg.norm(L @ (L.T @ x) - Ax) <= 1e-10 * np.linalg.norm(Ax):
            raise RuntimeError("CHOLMOD's factor does not have the permutation it was given")
        self._sn = SupernodalFactor(L, p)  # self._A kept (the caller's K_ii): release()
        return self._sn

    def release(self) -> None:
        """Drop the dense panels of the many-column solves (:meth:`_supernodal`: 3.3 GiB at
        4096 contact nodes of benchmarks/scale_3d.py) once those solves are done; a later
        solve of many columns makes them again."""
        self._sn = None
