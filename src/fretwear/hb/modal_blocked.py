"""The modal (Craig-Bampton) condensation of :mod:`fretwear.hb.modal` built for interfaces too
large for its dense storage (docs/theory.md, "Large interfaces").

:class:`~fretwear.hb.modal.ModalCondenser` holds the static constraint modes
``Psi = -K_ii^-1 K_ic`` whole (``n_i x m``: 9.7 GB at 4096 contact nodes of the pad of
benchmarks/scale_3d.py) and returns ``Z_r`` as ``H + 1`` dense ``m x m`` blocks (1.2 GB each
there). :class:`BlockedModalCondenser` is the same condensation (the same modes, load
responses, error check) without either:

* ``Psi`` is never held: the projections are built ``BLOCK`` columns at a time, with
  ``Psi^T W = -K_ci K_ii^-1 W`` (``K`` symmetric) for the products on its left, so each block
  of columns costs two sparse multi-right-hand-side solves with the kept LU of ``K_ii``
  instead of one; the loads, the recovery and the observed interior rows take ``Psi x`` and
  ``Psi^T y`` the same way (one solve each);
* the projected ``X^cc`` (``m x m``) are rotated into the contact-local frames block by block
  and kept only there, and ``reduced()`` returns ``Z`` as a
  :class:`~fretwear.hb.modal_operator.ReducedOperator`: the shared ``X^cc`` and a rank-``q``
  term per harmonic, whose products the operator path of the solver
  (:class:`~fretwear.hb.modal_operator.OperatorBlocks`) uses.

Memory: ``len(X^cc) m^2`` reals (two for an undamped structure) instead of ``(H + 3) m^2 + 2
n_i m``. Time: the solves of ``Psi`` doubled, the rest as before.
"""

from __future__ import annotations

import numpy as np

from fretwear.errors import InputError
from fretwear.hb.modal import CUTOFF, TOL, ModalCondenser
from fretwear.hb.modal_operator import ReducedOperator
from fretwear.hb.reduce import BLOCK, Condenser, Reduced, _column, _factor, _solve, _structure
from fretwear.model.core import Model

#: the matrices of the structure, in the order of the operator's stored ``X^cc``
NAMES = ("K", "M", "C", "D")


class _StaticModes:
    """``Psi = -K_ii^-1 K_ic`` as products through the LU of ``K_ii`` (never formed):
    ``Psi @ x``, ``Psi.T @ y`` (``K`` symmetric) and ``rows(r)`` (the rows ``r`` of ``Psi``,
    few)."""

    dtype = np.dtype(float)

    def __init__(self, lu, K, transposed: bool = False):
        self.lu, self.K, self.transposed = lu, K, transposed

    @property
    def T(self) -> _StaticModes:
        return _StaticModes(self.lu, self.K, not self.transposed)

    def __matmul__(self, x):
        x = np.asarray(x)
        if self.transposed:  # Psi^T y = -K_ci K_ii^-1 y
            return -(self.K.ci @ _solve(self.lu, x))
        return -_solve(self.lu, np.asarray(self.K.ic @ x))

    def rows(self, r: np.ndarray) -> np.ndarray:
        """Rows ``r`` of ``Psi`` (len(r), m): ``-(K_ii^-1 E_r)^T K_ic``."""
        n = self.K.ii.shape[0]
        E = np.zeros((n, r.size))
        E[r, np.arange(r.size)] = 1.0
        return -np.asarray((self.K.ic.T @ _solve(self.lu, E)).T)


class BlockedModalCondenser(ModalCondenser):
    """:class:`~fretwear.hb.modal.ModalCondenser` without ``Psi`` or dense blocks per
    harmonic (module docstring); the same parameters and interface. ``reduced()`` returns a
    :class:`~fretwear.hb.reduce.Reduced` whose ``Z`` is a
    :class:`~fretwear.hb.modal_operator.ReducedOperator`. Made by
    :func:`fretwear.hb.modal.modal_condenser` for large interfaces."""

    def __init__(self, model: Model, f_max: float, max_order: int, *, modes: int | None = None,
                 cutoff: float = CUTOFF, tol: float = TOL):
        self._check_args(f_max, modes)
        Condenser.__init__(self, _structure(model), dense=False)
        if not self.ni:
            raise InputError("the model has no interior DOFs: nothing to represent by modes")
        self.f_max, self.max_order, self.tol = float(f_max), int(max_order), float(tol)
        lu = self.factor(0.0, 0, True)  # real LU of K_ii, kept
        self._lu0 = lu
        self.Psi = _StaticModes(lu, self.K)
        self.mode_frequencies, Phi = self._modes(lu, modes, cutoff * self.max_order * self.f_max)
        self.n_modes = Phi.shape[1]
        vecs = self.structure.load_vectors
        Fl = (np.column_stack([v[self.idofs] for v in vecs]) if vecs
              else np.zeros((self.ni, 0)))
        self.V = self._basis(Phi, lu.solve(Fl) if Fl.shape[1] else Fl)
        self.q = self.V.shape[1]
        rows = np.array([i for _, i in self.obs_i], dtype=np.int64)
        self._psi_rows = self.Psi.rows(rows) if rows.size else np.zeros((0, self.m))
        self._project()
        self.error = self._check()
        self._raise_if_inaccurate(f_max, tol)

    @staticmethod
    def _check_args(f_max, modes):
        import math

        if not (isinstance(f_max, int | float) and math.isfinite(f_max) and f_max > 0):
            raise InputError(f"f_max = {f_max!r}: expected a positive frequency [Hz]")
        if modes is not None and (isinstance(modes, bool) or not isinstance(modes, int)
                                  or modes < 0):
            raise InputError(f"modes = {modes!r}: expected a number of modes >= 0")

    @staticmethod
    def _basis(Phi, Xl):
        """The modes and load responses, orthonormalised (as ModalCondenser)."""
        import scipy.linalg as sla

        V = np.column_stack([Phi, Xl])
        if V.shape[1]:
            V = V / np.maximum(np.linalg.norm(V, axis=0), 1e-300)
            Q, r, _ = sla.qr(V, mode="economic", pivoting=True)
            V = Q[:, np.abs(np.diag(r)) > 1e-10 * abs(r[0, 0])]
        return V

    def _raise_if_inaccurate(self, f_max, tol):
        if self.error > self.tol:
            raise InputError(
                f"modal condensation with {self.n_modes} modes (up to "
                f"{(self.mode_frequencies.max() if self.n_modes else 0.0):.6g} Hz): relative "
                f"error {self.error:.3g} of Z_r at harmonic {self.max_order} of {f_max:.6g} Hz"
                f" > tol = {tol:g}; keep more modes (modes=, cutoff=) or condense exactly")

    # -- construction -------------------------------------------------------------------------
    def _project(self):
        """``proj_local``: the blocks ``(R X^cc R^T, R X^cq, X^qc R^T, X^qq)`` of every matrix
        of ``K, M, C, D`` present, built ``BLOCK`` columns (whole nodes) at a time."""
        lu, V, K, R = self._lu0, self.V, self.K, self.R
        names = [nm for nm in NAMES if getattr(self, nm) is not None]
        m, q, d = self.m, self.q, self.structure.frame.shape[1]
        cc = {nm: np.empty((m, m)) for nm in names}
        qc = {nm: np.empty((q, m)) for nm in names}
        step = max(d, BLOCK // d * d)
        for j0 in range(0, m, step):
            js = slice(j0, min(j0 + step, m))
            Psi = -lu.solve(K.ic[:, js].toarray())  # (ni, B)
            W = {}
            for nm in names:
                B = getattr(self, nm)
                W[nm] = np.asarray(B.ic[:, js].toarray() + B.ii @ Psi)  # X_ic + X_ii Psi
                qc[nm][:, js] = V.T @ W[nm]
            # Psi^T W = -K_ci K_ii^-1 W for every matrix but K (K_ii Psi = -K_ic: W_K = 0)
            others = [nm for nm in names if nm != "K"]
            PtW = (-(K.ci @ lu.solve(np.column_stack([W[nm] for nm in others])))
                   if others else np.zeros((m, 0)))
            for i, nm in enumerate(others):
                B = getattr(self, nm)
                cols = PtW[:, i * (js.stop - js.start):(i + 1) * (js.stop - js.start)]
                cc[nm][:, js] = B.cc[:, js] + B.ci @ Psi + cols
            cc["K"][:, js] = K.cc[:, js] + K.ci @ Psi
            for nm in names:  # rotate the block's rows, then its own nodes' columns
                cc[nm][:, js] = self._rotate_columns(R @ cc[nm][:, js], js)
        self.proj_local = {}
        for nm in names:
            B = getattr(self, nm)
            BiiV = B.ii @ V
            cq = B.ci @ V + self.Psi.T @ BiiV
            self.proj_local[nm] = (cc[nm], R @ cq, self._rotate_columns(qc[nm], slice(0, m)),
                                   V.T @ BiiV)

    def _rotate_columns(self, A: np.ndarray, js: slice) -> np.ndarray:
        """``A R_js^T`` for the columns ``js`` (whole nodes) of the frame matrix."""
        F = self.structure.frame
        d = F.shape[1]
        nodes = F[js.start // d : js.stop // d]
        out = np.einsum("rpj,pij->rpi", A.reshape(A.shape[0], -1, d), nodes)
        return out.reshape(A.shape)

    def _zr(self, omega, n, quasi_static, local=True):
        """``(coef, Z^cq, Z^qc, Z^qq)`` of harmonic ``n``: the coefficients of the stored
        ``X^cc`` (:data:`NAMES` order) and the modal blocks (contact-local frames)."""
        proj = self.proj_local
        names = list(proj)
        coef = np.zeros(len(names), dtype=complex)
        coef[0] = 1.0
        _, cq, qc, qq = (x.astype(complex) for x in proj["K"])
        if not (n == 0 or quasi_static):
            w = n * omega
            for i, nm in enumerate(names):
                c = {"K": 1.0, "M": -(w * w), "C": 1j * w, "D": 1j}[nm]
                coef[i] = c
                if nm != "K":
                    cq, qc, qq = cq + c * proj[nm][1], qc + c * proj[nm][2], qq + c * proj[nm][3]
        if not np.any(coef.imag) and not (np.any(cq.imag) or np.any(qc.imag)
                                          or np.any(qq.imag)):
            coef, cq, qc, qq = coef.real, cq.real, qc.real, qq.real
        return coef, cq, qc, qq

    def _parts(self, omega, n, quasi_static, F, local=True):
        """``(coef, U, Y, Fr, qF)`` of harmonic ``n`` in the contact-local frames:
        ``Z_r = sum coef X^cc - U Y``, ``Y = Z^qq^-1 Z^qc R^T``, ``Fr = R F_r``."""
        coef, cq, qc, qq = self._zr(omega, n, quasi_static)
        Fi = F[self.idofs]
        Fc = self.R @ (F[self.cdofs] + self.Psi.T @ Fi)
        Fq = self.V.T @ Fi
        if self.q:
            Y, qF = np.linalg.solve(qq, qc), np.linalg.solve(qq, Fq)
            return coef, cq, Y, Fc - cq @ qF, qF
        return coef, None, None, Fc, np.zeros(0)

    def _operator(self, parts) -> ReducedOperator:
        mats = [self.proj_local[nm][0] for nm in self.proj_local]
        return ReducedOperator(mats, np.array([p[0] for p in parts]), [p[1] for p in parts],
                               [p[2] for p in parts], symmetric=self._symmetric())

    def _symmetric(self) -> bool:
        """Whether ``K, M, C, D`` are symmetric (then so is every ``Z_r(n)``)."""
        out = True
        for nm in self.proj_local:
            A = getattr(self.structure, nm)
            out = out and abs(A - A.T).max() <= 1e-12 * abs(A).max()
        return bool(out)

    def _check(self) -> float:
        """As :meth:`ModalCondenser._check`, with ``Z_r`` applied as the operator."""
        n, omega = self.max_order, 2 * np.pi * self.f_max
        rng = np.random.default_rng(0)
        P = rng.standard_normal((self.m, 4))
        F = self.structure.load_harmonics(n)[n]
        parts = self._parts(omega, n, False, F)
        op = self._operator([parts])
        R = self.R
        SP = R.T @ op.matmat(np.zeros(P.shape[1], np.int64), R @ P)  # global frame
        Zii = self._z("ii", omega, n, False)
        lu = _factor(Zii, n, omega)
        Zci, Zic = self._z("ci", omega, n, False), self._z("ic", omega, n, False)
        X = _solve(lu, Zic @ P)
        exact = self._z("cc", omega, n, False) @ P - Zci @ X
        err = np.linalg.norm(SP - exact, axis=0) / np.linalg.norm(exact, axis=0)
        e = float(err.max())
        rows = np.array([i for _, i in self.obs_i], dtype=np.int64)
        if rows.size:
            Y = parts[2] @ R if parts[2] is not None else np.zeros((0, self.m))
            mod = (self._psi_rows - self.V[rows] @ Y) @ P
            e = max(e, float(np.linalg.norm(mod + X[rows]) / np.linalg.norm(X[rows])))
        if np.any(F):
            Fe = F[self.cdofs] - Zci @ _solve(lu, F[self.idofs])
            e = max(e, float(np.linalg.norm(R.T @ parts[3] - Fe)
                             / max(np.linalg.norm(Fe), 1e-300)))
        return e

    # -- the Condenser interface --------------------------------------------------------------
    def reduced(self, omega: float, orders, quasi_static: bool = False,
                frequency: float | None = None) -> Reduced:
        """The :class:`~fretwear.hb.reduce.Reduced` model on ``orders`` at ``omega``
        [rad/s], its ``Z`` a :class:`~fretwear.hb.modal_operator.ReducedOperator`."""
        orders = np.asarray(orders, dtype=np.int64)
        m, no, nb, R = self.m, self.structure.obs.size, orders.size, self.R
        F_all = self.structure.load_harmonics(int(orders.max()) if orders.size else 0)
        Fr = np.zeros((nb, m), dtype=complex)
        oA = np.zeros((nb, no, m), dtype=complex)
        ob = np.zeros((nb, no), dtype=complex)
        rows = np.array([i for _, i in self.obs_i], dtype=np.int64)
        parts = []
        for b, n in enumerate(orders):
            p = self._parts(omega, int(n), quasi_static, F_all[n])
            parts.append(p)
            Fr[b] = p[3]
            for j, c in self.obs_c:
                oA[b, j] = _column(R, c)
            if rows.size:
                A = self._psi_rows @ R.T - (self.V[rows] @ p[2] if p[2] is not None else 0.0)
                bo = self.V[rows] @ p[4] if p[2] is not None else np.zeros(rows.size)
                for (j, _), a, v in zip(self.obs_i, np.atleast_2d(A), bo, strict=True):
                    oA[b, j], ob[b, j] = a, v
        Z = self._operator(parts)
        return self._result(omega, orders, Z, Fr, oA, ob, quasi_static, frequency)

    def recover(self, omega: float, orders, u_loc, quasi_static: bool = False) -> np.ndarray:
        """All DOFs (nb, ndof) from ``u_loc`` (nb, m): ``u_i = Psi u_c + V q``."""
        orders = np.asarray(orders, dtype=np.int64)
        F_all = self.structure.load_harmonics(int(orders.max()) if orders.size else 0)
        out = np.zeros((orders.size, self.structure.ndof), dtype=complex)
        for b, n in enumerate(orders):
            Uc = self.R.T @ np.asarray(u_loc[b], dtype=complex)
            _, _, Y, _, qF = self._parts(omega, int(n), quasi_static, F_all[n])
            out[b, self.cdofs] = Uc
            ui = self.Psi @ Uc
            if Y is not None:
                ui = ui + self.V @ (qF - Y @ (self.R @ Uc))
            out[b, self.idofs] = ui
        P = self.structure.P
        return out if P is None else (P @ out.T).T
