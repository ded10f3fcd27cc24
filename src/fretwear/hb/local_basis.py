"""The condensation near a frequency condensed exactly, from that condensation's own interior
solutions (a Galerkin projection on them): what a sweep's continuation uses between its
recorded points (docs/theory.md, "Cost of the condensation").

The exact condensation (eq. 19) of harmonic ``n`` at ``w_a`` solves ``Z_ii(n w_a) X = Z_ic``
and ``Z_ii x_F = F_i`` (``m + 1`` right-hand sides on one LU). Writing the interior motion at
a nearby frequency in the span of ``W = [X, x_F]``, ``u_i = W a`` (a Galerkin projection with
the test space ``W^T``: ``Z`` is complex symmetric; ``W^H`` for the complex Hermitian blocks of
a sector's harmonic index), the condensation becomes the same Schur complement on ``q = m + 1``
coordinates,

    Z_r(w) = Z_cc - Z_cq Z_qq^-1 Z_qc,    F_r(w) = F_c - Z_cq Z_qq^-1 W^T F_i,

which is exact at ``w_a`` (``Z_ii(w_a) W = [Z_ic, F_i]``: ``Z_qq^-1 Z_qc`` is the identity
there) and, the exact ``Z_r`` being stationary in the interior motion, off by the square of
the interior response's change away from it. Nothing is factorised or solved on the interior:
``Z_qq(w) = W^T [Z_ic, F_i](w_a) - ((n w)^2 - (n w_a)^2) W^T M_ii W + i n (w - w_a) W^T C_ii W``
needs one dense product ``W^T M_ii W`` (and ``C``'s) per reference frequency, and each new
frequency a dense solve of order ``q``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class LocalBasis:
    """The projected blocks of harmonic ``n`` at the reference frequency ``omega`` [rad/s]
    (module docstring); made by :func:`local_basis`, evaluated by :meth:`blocks`.

    Attributes
    ----------
    omega : reference circular frequency [rad/s]; n : harmonic order.
    G : dict of (q, q) blocks: ``"0"`` the projected ``Z_ii(n w_a)``, ``"M"``, ``"C"``.
    qc, cq : dicts of (q, m) and (m, q) blocks (same keys), ``cq`` in the global frame.
    fq : (q,) projected interior load; Wo : (no_i, q) rows of ``W`` at the interior observed
    DOFs.
    """

    omega: float
    n: int
    G: dict
    qc: dict
    cq: dict
    fq: np.ndarray
    Wo: np.ndarray

    def blocks(self, omega: float):
        """``(Z_cq, Y, Y_F)`` at ``omega`` [rad/s]: ``Z_cq`` (m, q) and ``Y = Z_qq^-1 Z_qc``
        (q, m), ``Y_F = Z_qq^-1 W^T F_i`` (q,): the interior coordinates of unit contact
        motions and of the load (the exact ``Z_ii^-1 [Z_ic, F_i]`` in the basis ``W``)."""
        w, wa = self.n * omega, self.n * self.omega
        coef = {"0": 1.0, "M": -(w * w - wa * wa), "C": 1j * (w - wa)}
        Zqq = sum(coef[k] * g for k, g in self.G.items())
        Zqc = sum(coef[k] * g for k, g in self.qc.items())
        Zcq = sum(coef[k] * g for k, g in self.cq.items())
        Y = np.linalg.solve(Zqq, np.column_stack([Zqc, self.fq]))
        return Zcq, Y[:, :-1], Y[:, -1]


def local_basis(cond, omega: float, n: int, X: np.ndarray, xf: np.ndarray,
                Fi: np.ndarray) -> LocalBasis:
    """The :class:`LocalBasis` of harmonic ``n`` of the exact condenser ``cond``
    (:class:`~fretwear.hb.reduce.Condenser`) at ``omega`` [rad/s] from its interior solutions
    there: ``X = Z_ii^-1 Z_ic`` (n_i, m), ``xf = Z_ii^-1 F_i`` (n_i,), ``Fi`` the interior
    load (n_i,)."""
    load = bool(np.any(xf))  # no load at this harmonic: no load column
    W = (np.column_stack([X, xf]) if load else X).astype(complex)
    scale = np.linalg.norm(W, axis=0)
    scale[scale == 0] = 1.0
    W /= scale
    real = all(np.asarray(getattr(B.ii, "data", B.ii)).dtype.kind != "c"
               for B in (cond.K, cond.M, cond.C, cond.D) if B is not None)
    left = W.T if real else W.conj().T  # complex symmetric: W^T; Hermitian blocks: W^H
    Zic = _dense(cond._z("ic", omega, n, False))  # formed once: G's and qc's
    Zci = cond._z("ci", omega, n, False)
    rhs = (np.column_stack([Zic, Fi]) if load else Zic) / scale
    # (Z_ii(w_a) W, by the solves' own identity: no product with Z_ii)
    G = {"0": left @ rhs}
    qc = {"0": left @ Zic}
    cq = {"0": _times(Zci, W)}
    for key, B in (("M", cond.M), ("C", cond.C)):
        if B is None:
            continue
        G[key] = left @ _times(B.ii, W)
        qc[key] = left @ _dense(B.ic)
        cq[key] = _times(B.ci, W)
    rows = np.array([i for _, i in cond.obs_i], dtype=np.int64)
    return LocalBasis(float(omega), int(n), G, qc, cq, left @ Fi, W[rows])


def _dense(A) -> np.ndarray:
    return A if isinstance(A, np.ndarray) else A.toarray()


def _times(A, W) -> np.ndarray:
    """``A @ W`` for a sparse or dense ``A`` (an ndarray)."""
    return np.asarray(A @ W)
