"""Exact condensation of a linear model onto its contact DOFs, harmonic by harmonic.

For harmonic order ``n`` the dynamic stiffness of the structure is (paper eq. 18, written with
complex amplitudes ``u(t) = Re U_n e^{i n w t}``)

    Z_n = K + i D - (n w)^2 M + i n w C     (n >= 1),      Z_0 = K,

with ``D`` the hysteretic damping matrix (a loss factor eta gives ``D = eta K``). Splitting the
free DOFs into contact DOFs ``c`` and the others ``i``, the contact forces act on ``c`` only,
so (Nacivet et al. 2003; paper eq. 19)

    Z_r = Z_cc - Z_ci Z_ii^-1 Z_ic,      F_r = F_c - Z_ci Z_ii^-1 F_i,

loses nothing: every other DOF is recovered as ``U_i = Z_ii^-1 (F_i - Z_ic U_c)``. The reduced
quantities are expressed in the contact-local frames (normal, tangential), node-major.
The quasi-static variant drops inertia and damping (``Z_n = K`` for every ``n``), keeping the
time ordering of the friction law over the period; :func:`condense_static` gives the same
static condensation in real arithmetic with the condensed loads of any load vectors (the
quasi-static load steps of :mod:`fretwear.timedomain.integrate`). Both use one implementation
of eq. 19 (:func:`_schur`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from fretwear.errors import InputError
from fretwear.model.core import Model
from fretwear.model.interfaces import observed_map, relative_model


@dataclass
class Reduced:
    """Reduced dynamic stiffness and loads on the contact DOFs for one frequency.

    Attributes
    ----------
    omega : excitation circular frequency ``2 pi frequency`` [rad/s] (0 allowed when
        ``quasi_static``).
    orders : (nb,) harmonic orders ``[0, h1, .., hk]``.
    Z : (nb, m, m) complex reduced dynamic stiffness [N/m] in contact-local coordinates,
        ``m = n_contact * d``, rows/columns node-major ``[N, T1, (T2)]``.
    F : (nb, m) complex reduced load amplitudes [N] (``F[0]`` is the static load).
    obs_A, obs_b : (nb, no, m), (nb, no) complex: observed DOFs ``U_o = obs_A @ u_loc + obs_b``.
    obs_dofs : (no,) global DOFs of the observed points, in the order of ``model.observed``.
    quasi_static : True when inertia and damping were dropped.
    frequency : excitation frequency [Hz], as given to :func:`condense`.
    """

    omega: float
    orders: np.ndarray
    Z: np.ndarray
    F: np.ndarray
    obs_A: np.ndarray
    obs_b: np.ndarray
    obs_dofs: np.ndarray
    quasi_static: bool = False
    frequency: float = math.nan

    def __post_init__(self):
        if math.isnan(self.frequency):
            self.frequency = self.omega / (2 * np.pi)

    @property
    def m(self) -> int:
        return int(self.Z.shape[1])

    def spectral_radius(self) -> float:
        """Largest ``|eigenvalue|`` of ``Z_r`` over the kept harmonics [N/m]: the paper's
        default for the DLFT penalty ``eps`` (section 3.2)."""
        return float(max(np.max(np.abs(np.linalg.eigvals(z))) for z in self.Z))


def dynamic_stiffness(model: Model, frequency: float, n: int, quasi_static: bool = False):
    """Sparse complex ``Z_n`` [N/m] on all DOFs (eq. 18 in complex form) at the excitation
    ``frequency`` [Hz] (harmonic ``n`` of it)."""
    return _dynamic_stiffness(model, 2 * np.pi * frequency, n, quasi_static)


def _dynamic_stiffness(model: Model, omega: float, n: int, quasi_static: bool = False):
    """:func:`dynamic_stiffness` at the circular frequency ``omega`` [rad/s]."""
    K = model.K.tocsc()
    if n == 0 or quasi_static:
        return K.astype(complex)
    w = n * omega
    Z = K.astype(complex) - (w * w) * model.M.tocsc()
    if model.D is not None:
        Z = Z + 1j * model.D.tocsc()
    if model.C is not None:
        Z = Z + (1j * w) * model.C.tocsc()
    return Z.tocsc()


def _partition(model: Model):
    free = model.free_dofs()
    cdofs = model.contact.dofs.reshape(-1)
    if np.intersect1d(cdofs, model.fixed_dofs).size:
        raise InputError("contact DOFs cannot also be fixed (Dirichlet) DOFs")
    is_c = np.zeros(model.ndof, dtype=bool)
    is_c[cdofs] = True
    idofs = free[~is_c[free]]
    return cdofs, idofs


def _frame_matrix(model: Model) -> np.ndarray:
    """Block-diagonal R (m, m) with ``u_loc = R @ U[cdofs]``."""
    frame = model.contact.frame
    nc, d, _ = frame.shape
    R = np.zeros((nc * d, nc * d))
    for p in range(nc):
        R[p * d : (p + 1) * d, p * d : (p + 1) * d] = frame[p]
    return R


def _factor(Zii, n: int, omega: float):
    """Sparse LU of ``Z_ii``; a singular matrix becomes an InputError naming the cause."""
    try:
        lu = spla.splu(Zii.tocsc())
    except RuntimeError as exc:
        raise InputError(
            f"the structure with its contact DOFs held (node-to-node pairs glued) is singular "
            f"at harmonic {n} "
            f"(excitation {omega / (2 * np.pi):.6g} Hz): part of the model can move with "
            "nothing to hold it (add springs or fixed DOFs), or the frequency is an "
            "eigenfrequency of the undamped structure with a clamped interface"
        ) from exc
    diag = np.abs(lu.U.diagonal())
    if diag.size and diag.min() <= 1e-13 * diag.max():
        raise InputError(
            f"the structure with its contact DOFs held (node-to-node pairs glued) is (nearly) "
            f"singular at harmonic {n}: "
            "part of the model can move with nothing to hold it (add springs or fixed DOFs)"
        )
    return lu


def _schur(Z, cdofs, idofs, R, n: int, omega: float):
    """Exact condensation of one (dynamic) stiffness ``Z`` onto the contact DOFs (eq. 19).

    Returns ``(Z_r, lu, X, Z_ci)`` with ``Z_r = R (Z_cc - Z_ci Z_ii^-1 Z_ic) R^T`` in the
    contact-local frame, ``lu`` the sparse LU of ``Z_ii`` (None without interior DOFs) and
    ``X = Z_ii^-1 Z_ic``. ``Z`` real (statics) or complex (one harmonic).
    """
    m = cdofs.size
    Zc_rows = Z[cdofs]
    Zcc = Zc_rows[:, cdofs].toarray()
    Zci = Zc_rows[:, idofs]
    if idofs.size:
        lu = _factor(Z[idofs][:, idofs], n, omega)
        X = lu.solve(Z[idofs][:, cdofs].toarray())  # Z_ii^-1 Z_ic
        S = Zcc - Zci @ X
    else:
        lu, X, S = None, np.zeros((0, m), dtype=Z.dtype), Zcc
    return R @ S @ R.T, lu, X, Zci


def _condensed_load(F, cdofs, idofs, R, lu, Zci):
    """``F_r = R (F_c - Z_ci Z_ii^-1 F_i)`` (eq. 19) and ``Z_ii^-1 F_i`` (None without interior
    DOFs) for a load vector ``F`` (ndof,) or one per column (ndof, k)."""
    if lu is None:
        return R @ F[cdofs], None
    xf = lu.solve(F[idofs])  # Z_ii^-1 F_i
    return R @ (F[cdofs] - Zci @ xf), xf


@dataclass
class StaticCondensation:
    """Exact static condensation of the free structure onto the contact DOFs (``Z = K``).

    ``K_r u_loc + lambda = F_r`` with ``u_loc`` the local contact displacements [m] and
    ``lambda`` the contact forces [N], both node-major ``[N, T1, (T2)]`` (``m = nc * d``).
    Made by :func:`condense_static`; the per-harmonic :func:`condense` with
    ``quasi_static=True`` gives the same ``K_r`` for every harmonic.

    Attributes
    ----------
    K : (m, m) condensed stiffness in the local frame [N/m], symmetric.
    """

    K: np.ndarray
    _model: Model
    _cdofs: np.ndarray
    _idofs: np.ndarray
    _R: np.ndarray
    _lu: object
    _Kci: object
    _P: object = None  # U = P U' for node-to-node pairs (model.interfaces), None without

    def loads(self, F) -> np.ndarray:
        """Condensed loads ``F_r`` (..., m) [N] of load vectors ``F`` (..., ndof) [N]."""
        F = np.asarray(F, dtype=float)
        if self._P is not None:
            F = (self._P.T @ F.reshape(-1, F.shape[-1]).T).T.reshape(F.shape)
        cols = F.reshape(-1, F.shape[-1]).T  # one load per column
        Fr, _ = _condensed_load(cols, self._cdofs, self._idofs, self._R, self._lu, self._Kci)
        return Fr.T.reshape(F.shape[:-1] + (self._R.shape[0],))

    def recover(self, u_loc, F) -> np.ndarray:
        """All DOFs ``U`` (ndof,) [m] from the local contact displacements ``u_loc`` (m,) under
        the load ``F`` (ndof,): ``U_i = K_ii^-1 (F_i - K_ic U_c)``; fixed DOFs are zero."""
        U = np.zeros(self._model.ndof)
        Uc = self._R.T @ np.asarray(u_loc, dtype=float)
        U[self._cdofs] = Uc
        F = np.asarray(F, float)
        if self._P is not None:
            F = self._P.T @ F
        if self._lu is not None:
            K = self._model.K.tocsr()
            U[self._idofs] = self._lu.solve(F[self._idofs]
                                            - K[self._idofs][:, self._cdofs] @ Uc)
        return U if self._P is None else self._P @ U


def condense_static(model: Model) -> StaticCondensation:
    """Exact static condensation of ``model`` onto its contact DOFs (eq. 19 with ``Z = K``).

    The same computation as :func:`condense` (:func:`_schur`), in real arithmetic, with the
    condensed loads of any load vectors (e.g. the loads at the phases of a quasi-static
    cycle) and the exact recovery of every DOF.
    """
    model, P = relative_model(model)
    cdofs, idofs = _partition(model)
    R = _frame_matrix(model)
    Kr, lu, _, Kci = _schur(model.K.tocsc().astype(float), cdofs, idofs, R, 0, 0.0)
    return StaticCondensation(np.ascontiguousarray(0.5 * (Kr + Kr.T)), model, cdofs, idofs, R,
                              lu, Kci, P)


def condense(model: Model, frequency: float, orders, *, quasi_static: bool = False) -> Reduced:
    """Condense ``model`` onto its contact DOFs for harmonic ``orders`` (``[0, h1, .., hk]``)
    at the excitation ``frequency`` [Hz] (0 allowed when ``quasi_static``).

    Implements eq. (17)-(19) with sparse LU of ``Z_ii`` per harmonic. Returns a
    :class:`Reduced` in contact-local coordinates with the observed-DOF recovery rows
    (``Reduced.omega = 2 pi frequency`` [rad/s], ``Reduced.frequency`` as given).
    """
    return _condense(model, 2 * np.pi * frequency, orders, quasi_static=quasi_static,
                     frequency=frequency)


def _condense(model: Model, omega: float, orders, *, quasi_static: bool = False,
              frequency: float | None = None) -> Reduced:
    """:func:`condense` at the circular frequency ``omega`` [rad/s] (``frequency`` [Hz]:
    recorded in the result, default ``omega / 2 pi``)."""
    orders = np.asarray(orders, dtype=np.int64)
    model, P = relative_model(model)  # node-to-node pairs: relative coordinates U = P U'
    cdofs, idofs = _partition(model)
    R = _frame_matrix(model)
    m = cdofs.size
    obs_out, obs, S = observed_map(model, P)  # U[obs_out] = S @ U'[obs]
    F_all = model.load_harmonics(int(orders.max()) if orders.size else 0)
    # where each observed DOF lives: contact (index in cdofs), interior (index in idofs), fixed
    pos_c = {int(g): j for j, g in enumerate(cdofs)}
    pos_i = {int(g): j for j, g in enumerate(idofs)}
    nb = orders.size
    Zr = np.zeros((nb, m, m), dtype=complex)
    Fr = np.zeros((nb, m), dtype=complex)
    oA = np.zeros((nb, obs.size, m), dtype=complex)
    ob = np.zeros((nb, obs.size), dtype=complex)
    cache = {}  # quasi-static: every harmonic shares Z_0 = K
    for b, n in enumerate(orders):
        key = 0 if (n == 0 or quasi_static) else int(n)
        if key not in cache:
            Z = _dynamic_stiffness(model, omega, int(n), quasi_static)
            Zr_n, lu, X, Zci = _schur(Z, cdofs, idofs, R, int(n), omega)
            A = np.zeros((obs.size, m), dtype=complex)
            for j, g in enumerate(obs):
                g = int(g)
                if g in pos_c:
                    A[j] = R[:, pos_c[g]]  # U_c = R^T u_loc
                elif g in pos_i:
                    A[j] = -(X[pos_i[g]] @ R.T)
            cache[key] = (Zr_n, A, lu, Zci)
        Zr[b], oA[b], lu, Zci = cache[key]
        Fr[b], xf = _condensed_load(F_all[n].astype(complex), cdofs, idofs, R, lu, Zci)
        if xf is not None:
            for j, g in enumerate(obs):
                if int(g) in pos_i:
                    ob[b, j] = xf[pos_i[int(g)]]
    if S is not None:
        oA = np.einsum("oj,bjm->bom", S.toarray(), oA)
        ob = ob @ S.toarray().T
    return Reduced(float(omega), orders, Zr, Fr, oA, ob, obs_out, bool(quasi_static),
                   math.nan if frequency is None else float(frequency))


def recover(model: Model, frequency: float, orders, u_loc: np.ndarray, *,
            quasi_static: bool = False) -> np.ndarray:
    """All DOFs ``U_n`` (nb, ndof) complex [m] from the contact-local amplitudes ``u_loc``
    (nb, m) [m] of the harmonic ``orders`` at the excitation ``frequency`` [Hz].

    ``U_i = Z_ii^-1 (F_i - Z_ic U_c)`` per harmonic (exact recovery of the condensation);
    fixed DOFs are zero.
    """
    return _recover(model, 2 * np.pi * frequency, orders, u_loc, quasi_static=quasi_static)


def _recover(model: Model, omega: float, orders, u_loc: np.ndarray, *,
             quasi_static: bool = False) -> np.ndarray:
    """:func:`recover` at the circular frequency ``omega`` [rad/s]."""
    orders = np.asarray(orders, dtype=np.int64)
    model, P = relative_model(model)  # node-to-node pairs: U = P U'
    cdofs, idofs = _partition(model)
    R = _frame_matrix(model)
    F_all = model.load_harmonics(int(orders.max()) if orders.size else 0)
    out = np.zeros((orders.size, model.ndof), dtype=complex)
    for b, n in enumerate(orders):
        Uc = R.T @ np.asarray(u_loc[b], dtype=complex)
        out[b, cdofs] = Uc
        if idofs.size:
            Z = _dynamic_stiffness(model, omega, int(n), quasi_static)
            lu = _factor(Z[idofs][:, idofs], int(n), omega)
            out[b, idofs] = lu.solve(F_all[n][idofs] - Z[idofs][:, cdofs] @ Uc)
    return out if P is None else (P @ out.T).T


def to_real_blocks(Zc: np.ndarray, orders: np.ndarray) -> np.ndarray:
    """Real block operator for the basis ``[0, cos.., sin..]`` from complex per-harmonic blocks.

    With ``U = a - i b``, ``Z U = (Zr a + Zi b) - i (Zr b - Zi a)``, so harmonic n >= 1 maps
    ``[a; b]`` by ``[[Zr, Zi], [-Zi, Zr]]`` (eq. 18: ``Zi = n w C`` for viscous damping).
    Returns (m*(1+2k), m*(1+2k)) in *DOF-major* order: index ``j*(1+2k) + c`` for reduced DOF
    ``j`` and real coefficient ``c``.
    """
    nb, m, _ = Zc.shape
    k = nb - 1
    H = 1 + 2 * k
    out = np.zeros((m, H, m, H))
    out[:, 0, :, 0] = Zc[0].real
    for b in range(1, nb):
        zr, zi = Zc[b].real, Zc[b].imag
        ca, cb = b, k + b
        out[:, ca, :, ca] = zr
        out[:, ca, :, cb] = zi
        out[:, cb, :, ca] = -zi
        out[:, cb, :, cb] = zr
    return out.reshape(m * H, m * H)


def loads_to_real(Fc: np.ndarray) -> np.ndarray:
    """Real coefficient array (m, 1+2k) from complex load amplitudes (nb, m)."""
    a0 = Fc[0].real[:, None]
    return np.hstack([a0, Fc[1:].real.T, -Fc[1:].imag.T])
