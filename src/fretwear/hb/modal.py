"""Modal (Craig-Bampton) representation of the condensed dynamic stiffness ``Z_r(omega)``, with
its error measured against the exact condensation (docs/theory.md, "Large interfaces").

The exact condensation (eq. 19, :mod:`fretwear.hb.reduce`) factorises ``Z_ii(n w)`` and solves
for every contact DOF, at every harmonic and every frequency. Craig and Bampton (1968) write
the interior motion as

    u_i = Psi u_c + V q,      Psi = -K_ii^-1 K_ic  (static constraint modes, exact),

with ``V`` the fixed-interface modes of ``(K_ii, M_ii)`` up to a cutoff frequency, augmented
by the static responses ``K_ii^-1 F_i`` of the load vectors (so that the static part of every
load is exact). Projecting ``K, M, C, D`` gives small matrices that are assembled once; at
any frequency and harmonic

    Z_r = Z^cc - Z^cq (Z^qq)^-1 Z^qc          (dense, m x m and q x q),

the same Schur complement on the reduced coordinates. At harmonic 0 and in the quasi-static
case it is exact (``Z^cq = 0``, ``Z^cc = K_r``); above, the error is that of the omitted
modes, which grows with frequency. :class:`ModalCondenser` therefore checks itself at the
highest frequency it is built for: ``Z_r`` and ``F_r`` applied to random probe vectors
against the exact condensation (one sparse LU of ``Z_ii`` there and a few solves); the
relative error is stored (``error``) and an :class:`~fretwear.errors.InputError` is raised
when it exceeds ``tol`` (keep more modes, or condense exactly).

Cost: one real LU of ``K_ii`` and ``m`` real solves (``Psi``), a shift-invert Lanczos for the
modes, and projections; then ``O(m^2 q)`` per harmonic and frequency, against one complex
LU and ``m`` complex solves per harmonic and frequency for the exact condensation.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from fretwear.errors import InputError
from fretwear.hb.reduce import (
    BLOCK,
    Condenser,
    Reduced,
    _column,
    _factor,
    _solve,
    _structure,
)
from fretwear.model.core import Model

#: keep the fixed-interface modes up to this multiple of the highest harmonic frequency
CUTOFF = 3.0
#: default bound on the relative error of ``Z_r`` (and ``F_r``) at the highest frequency
TOL = 1e-3
#: random probe vectors of the error check
PROBES = 4


class ModalCondenser(Condenser):
    """Craig-Bampton condensation of ``model`` for excitation frequencies up to ``f_max`` [Hz]
    and harmonic orders up to ``max_order`` (module docstring), with the interface of
    :class:`~fretwear.hb.reduce.Condenser` (``reduced``, ``recover``, ``schur`` (exact), and
    ``check``: it belongs to the model it was built for). Made by :func:`modal_condenser`.

    Parameters
    ----------
    model : the structure.
    f_max : highest excitation frequency [Hz] it will be used at (> 0).
    max_order : highest harmonic order (``basis.harmonics[-1]``).
    modes : number of fixed-interface modes to keep; default: every mode below ``cutoff``
        times ``max_order * f_max``.
    cutoff : see ``modes``.
    tol : largest relative error of ``Z_r``/``F_r`` accepted at ``max_order * f_max``.

    Attributes
    ----------
    n_modes : fixed-interface modes kept; q : reduced interior coordinates (modes + load
    responses); mode_frequencies : (n_modes,) [Hz]; error : relative error of the check.
    """

    def __init__(self, model: Model, f_max: float, max_order: int, *, modes: int | None = None,
                 cutoff: float = CUTOFF, tol: float = TOL):
        if not (isinstance(f_max, int | float) and math.isfinite(f_max) and f_max > 0):
            raise InputError(f"f_max = {f_max!r}: expected a positive frequency [Hz]")
        if modes is not None and (isinstance(modes, bool) or not isinstance(modes, int)
                                  or modes < 0):
            raise InputError(f"modes = {modes!r}: expected a number of modes >= 0")
        super().__init__(_structure(model), dense=False)
        if not self.ni:
            raise InputError("the model has no interior DOFs: nothing to represent by modes")
        self.f_max, self.max_order, self.tol = float(f_max), int(max_order), float(tol)
        lu = self.factor(0.0, 0, True)  # real LU of K_ii, kept
        # static constraint modes Psi = -K_ii^-1 K_ic (blocked multi-RHS solves)
        Psi = np.empty((self.ni, self.m))
        for j0 in range(0, self.m, BLOCK):
            cols = slice(j0, min(j0 + BLOCK, self.m))
            Psi[:, cols] = -lu.solve(self.K.ic[:, cols].toarray())
        self.Psi = Psi
        # fixed-interface modes up to the cutoff, by shift-invert Lanczos on the kept LU
        f_cut = cutoff * self.max_order * self.f_max
        self.mode_frequencies, Phi = self._modes(lu, modes, f_cut)
        self.n_modes = Phi.shape[1]
        # + static responses of the loads' interior parts, orthonormalised
        vecs = self.structure.load_vectors
        Fl = (np.column_stack([v[self.idofs] for v in vecs]) if vecs
              else np.zeros((self.ni, 0)))
        Xl = lu.solve(Fl) if Fl.shape[1] else Fl
        V = np.column_stack([Phi, Xl])
        if V.shape[1]:
            V = V / np.maximum(np.linalg.norm(V, axis=0), 1e-300)  # modes ~ 1/sqrt(kg), loads ~ m
            Q, r, _ = sla.qr(V, mode="economic", pivoting=True)
            keep = np.abs(np.diag(r)) > 1e-10 * abs(r[0, 0])
            V = Q[:, keep]
        self.V, self.q = V, V.shape[1]
        self._static = {}  # the frequency-independent blocks of reduced(): harmonic 0
        self._project()
        self.error = self._check()
        if self.error > self.tol:
            raise InputError(
                f"modal condensation with {self.n_modes} modes (up to "
                f"{(self.mode_frequencies.max() if self.n_modes else 0.0):.6g} Hz): relative "
                f"error {self.error:.3g} of Z_r at harmonic {self.max_order} of {f_max:.6g} Hz"
                f" > tol = {tol:g}; keep more modes (modes=, cutoff=) or condense exactly")

    # -- construction -------------------------------------------------------------------------
    def _modes(self, lu, modes, f_cut):
        Kii, Mii = self.K.ii, self.M.ii
        n = self.ni
        op = spla.LinearOperator((n, n), matvec=lambda x: lu.solve(np.asarray(x, float)),
                                 dtype=float)
        if modes == 0 or n < 3:
            return np.zeros(0), np.zeros((n, 0))
        k = min(modes if modes is not None else 20, n - 2)
        while True:
            lam, Phi = spla.eigsh(Kii, k=k, M=Mii, sigma=0.0, which="LM", OPinv=op)
            order = np.argsort(lam)
            lam, Phi = lam[order], Phi[:, order]
            f = np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi)
            if modes is not None:
                return f, Phi
            if f[-1] > f_cut or k >= n - 2:
                keep = f <= f_cut
                return f[keep], Phi[:, keep]
            k = min(2 * k, n - 2)

    def _project(self):
        """The reduced matrices ``X^cc`` (m, m), ``X^cq`` (m, q), ``X^qc`` (q, m), ``X^qq``
        (q, q) of ``K, M, C, D`` in the coordinates ``(u_c, q)``."""
        Psi, V = self.Psi, self.V
        self.proj = {}
        for name in ("K", "M", "C", "D"):
            B = getattr(self, name)
            if B is None:
                continue
            XiiPsi = B.ii @ Psi
            if name == "K":  # K_ii Psi = -K_ic: the static condensation K_r
                cc = B.cc + B.ci @ Psi
            else:
                cc = B.cc + B.ci @ Psi + (B.ic.T @ Psi).T + Psi.T @ XiiPsi
            cq = (B.ci @ V) + Psi.T @ (B.ii @ V)
            qc = (B.ic.T @ V).T + V.T @ XiiPsi
            qq = V.T @ (B.ii @ V)
            self.proj[name] = (cc, cq, qc, qq)
        # the same in the contact-local frames (R X^cc R^T, R X^cq, X^qc R^T, X^qq), rotated
        # once here: reduced() then needs no rotation of an m x m block per harmonic and
        # frequency (0.9 s of the 1.3 s of a harmonic at 1024 nodes)
        R = self.R
        self.proj_local = {name: (self._rotate(cc), R @ cq, (R @ qc.T).T, qq)
                           for name, (cc, cq, qc, qq) in self.proj.items()}

    def _zr(self, omega, n, quasi_static, local=False):
        """``(Z^cc, Z^cq, Z^qc, Z^qq)`` of harmonic ``n`` (eq. 18 on the reduced
        coordinates), in the contact-local frames if ``local``."""
        proj = self.proj_local if local else self.proj
        out = list(proj["K"])
        if n == 0 or quasi_static:
            return out
        w = n * omega
        for name, c in (("M", -(w * w)), ("D", 1j), ("C", 1j * w)):
            if name in proj:
                for i, x in enumerate(proj[name]):
                    out[i] = out[i] + c * x
        return out

    def _parts(self, omega, n, quasi_static, F, local=False):
        """Condensed ``Z_r``, ``Z^qq^-1 Z^qc`` and the condensed load and modal coordinates of
        ``F`` (ndof,) for harmonic ``n``: in the global contact axes, or in the contact-local
        frames if ``local`` (``R Z_r R^T``, ``Z^qq^-1 Z^qc R^T``, ``R F_r``). Real blocks
        stay real (an undamped structure) whatever the loads."""
        cc, cq, qc, qq = self._zr(omega, n, quasi_static, local)
        Fi = F[self.idofs]
        Fc = F[self.cdofs] + _real_times(self.Psi.T, Fi)
        if local:
            Fc = self.R @ Fc
        Fq = _real_times(self.V.T, Fi)
        if self.q:
            Y, qF = np.linalg.solve(qq, qc), np.linalg.solve(qq, Fq)
            return cc - cq @ Y, Y, Fc - cq @ qF, qF
        return cc, np.zeros((0, self.m)), Fc, np.zeros(0)

    def _check(self) -> float:
        """Relative error of ``Z_r`` on :data:`PROBES` random vectors, of the observed
        interior DOFs' response to them and of ``F_r``, at the highest harmonic of ``f_max``,
        against the exact condensation (eq. 19)."""
        n, omega = self.max_order, 2 * np.pi * self.f_max
        rng = np.random.default_rng(0)
        P = rng.standard_normal((self.m, PROBES))
        F = self.structure.load_harmonics(n)[n]
        S, Y, Fr, _ = self._parts(omega, n, False, F)
        Zii = self._z("ii", omega, n, False)
        lu = _factor(Zii, n, omega)
        self._used(lu)
        Zci, Zic = self._z("ci", omega, n, False), self._z("ic", omega, n, False)
        X = _solve(lu, Zic @ P)  # Z_ii^-1 Z_ic P: the interior response to the probes
        exact = self._z("cc", omega, n, False) @ P - Zci @ X
        err = np.linalg.norm(S @ P - exact, axis=0) / np.linalg.norm(exact, axis=0)
        e = float(err.max())
        rows = np.array([i for _, i in self.obs_i], dtype=np.int64)
        if rows.size:  # recovery of the observed interior DOFs: -(Psi - V Y) P vs -X
            mod = (self.Psi[rows] - self.V[rows] @ Y) @ P
            e = max(e, float(np.linalg.norm(mod + X[rows]) / np.linalg.norm(X[rows])))
        if np.any(F):
            Fe = F[self.cdofs] - Zci @ _solve(lu, F[self.idofs])
            e = max(e, float(np.linalg.norm(Fr - Fe) / max(np.linalg.norm(Fe), 1e-300)))
        return e

    # -- the Condenser interface --------------------------------------------------------------
    def reduced(self, omega: float, orders, quasi_static: bool = False,
                frequency: float | None = None) -> Reduced:
        """The :class:`~fretwear.hb.reduce.Reduced` model on ``orders`` at ``omega`` [rad/s]
        from the modal representation."""
        orders = np.asarray(orders, dtype=np.int64)
        m, no, nb, R = self.m, self.structure.obs.size, orders.size, self.R
        F_all = self.structure.load_harmonics(int(orders.max()) if orders.size else 0)
        # undamped (or static) blocks are real: stored real, half the memory, and the
        # solvers' products need no real copy of them (hb/krylov.py)
        real = quasi_static or not np.any(orders) or not ({"C", "D"} & set(self.proj))
        Zr = np.zeros((nb, m, m), dtype=float if real else complex)
        Fr = np.zeros((nb, m), dtype=complex)
        oA = np.zeros((nb, no, m), dtype=complex)
        ob = np.zeros((nb, no), dtype=complex)
        rows = np.array([i for _, i in self.obs_i], dtype=np.int64)
        for b, n in enumerate(orders):
            static = int(n) == 0 or quasi_static  # the same at every frequency: kept
            key = (int(n), bool(quasi_static) and int(n) != 0)  # harmonic 0: K alone, either way
            kept = self._static.get(key) if static else None
            if kept is not None and np.array_equal(kept[0], F_all[n]):  # same loads
                Zr[b], Fr[b], oA[b], ob[b] = kept[1:]
                continue
            Zr[b], Y, Fr[b], qF = self._parts(omega, int(n), quasi_static, F_all[n], True)
            for j, c in self.obs_c:
                oA[b, j] = _column(R, c)
            if rows.size:
                # u_i = Psi u_c + V q, q = qF - Y u_c (Y taking the local u_loc = R u_c):
                # rows at the interior observed DOFs
                A = self.Psi[rows] @ R.T - self.V[rows] @ Y
                for (j, _), a, bo in zip(self.obs_i, A, self.V[rows] @ qF, strict=True):
                    oA[b, j], ob[b, j] = a, bo
            if static and int(n) == 0:  # K alone: real, whatever the storage of this call
                self._static[key] = (np.array(F_all[n]), Zr[b].real.copy(), Fr[b].copy(),
                                     oA[b].copy(), ob[b].copy())
        return self._result(omega, orders, Zr, Fr, oA, ob, quasi_static, frequency)

    def _rotate(self, S: np.ndarray) -> np.ndarray:
        """``R S R^T`` (the contact-local frames) applied node block by node block: two
        batched products of ``d m^2`` operations each (faster than the sparse ``R``'s
        products and their copies)."""
        F = self.structure.frame
        nc, d, _ = F.shape
        m = nc * d
        T = np.matmul(F, S.reshape(nc, d, m))  # R S, node rows
        out = np.matmul(T.reshape(m, nc, d).transpose(1, 0, 2), F.transpose(0, 2, 1))
        return out.transpose(1, 0, 2).reshape(m, m)  # (R S) R^T, node columns

    def recover(self, omega: float, orders, u_loc, quasi_static: bool = False) -> np.ndarray:
        """All DOFs (nb, ndof) from ``u_loc`` (nb, m) through the modal representation
        (``u_i = Psi u_c + V q``)."""
        orders = np.asarray(orders, dtype=np.int64)
        F_all = self.structure.load_harmonics(int(orders.max()) if orders.size else 0)
        out = np.zeros((orders.size, self.structure.ndof), dtype=complex)
        for b, n in enumerate(orders):
            Uc = self.R.T @ np.asarray(u_loc[b], dtype=complex)
            _, Y, _, qF = self._parts(omega, int(n), quasi_static, F_all[n])
            out[b, self.cdofs] = Uc
            out[b, self.idofs] = _real_times(self.Psi, Uc) + _real_times(self.V,
                                                                          qF - Y @ Uc)
        P = self.structure.P
        return out if P is None else (P @ out.T).T


def _real_times(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``A @ x`` for a real ``A`` and a real or complex ``x`` without the complex copy of
    ``A`` that NumPy's mixed product makes (600 MB for ``Psi^T`` at 1024 contact nodes)."""
    if np.iscomplexobj(x) and not np.iscomplexobj(A):
        return A @ x.real + 1j * (A @ x.imag)
    return A @ x


def modal_condenser(model: Model, f_max: float, max_order: int, *, modes: int | None = None,
                    cutoff: float = CUTOFF, tol: float = TOL) -> ModalCondenser:
    """A :class:`ModalCondenser` of ``model`` for excitation frequencies up to ``f_max`` [Hz]
    and harmonic orders up to ``max_order``, checked against the exact condensation (an
    :class:`~fretwear.errors.InputError` when its error exceeds ``tol``; ``modes``, ``cutoff``:
    see the class).

    Pass it as ``condenser=`` to every condensation of ``model`` that should use it
    (:func:`~fretwear.hb.reduce.condense`, periodic solves, sweeps, wear runs, recovery), as
    :func:`~fretwear.hb.reduce.exact_condenser`'s condenser is passed; it refuses another
    model, or this one after an edit of its matrices.
    """
    return ModalCondenser(model, f_max, max_order, modes=modes, cutoff=cutoff, tol=tol)
