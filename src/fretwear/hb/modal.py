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
when it exceeds ``tol`` (keep more modes, or condense exactly); with ``raise_modes`` the
modes are first raised until it passes (:func:`next_mode_count`). With ``residual`` the basis
also holds the static responses to the constraint modes' inertia loads (the residual
flexibility of the omitted modes: one basis accurate over a whole band,
:meth:`ModalCondenser._residual_vectors`). :func:`fretwear.hb.condensers.condenser` chooses
between this and the exact condensation.

Cost: one real LU of ``K_ii`` and ``m`` real solves (``Psi``), a shift-invert Lanczos for the
modes, and projections; then ``O(m^2 q)`` per harmonic and frequency, against one complex
LU and ``m`` complex solves per harmonic and frequency for the exact condensation.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from fretwear.errors import InputError
from fretwear.hb import hmatrix, schur
from fretwear.hb.modal_operator import ReducedOperator
from fretwear.hb.reduce import (
    BLOCK,
    Condenser,
    Reduced,
    _column,
    _factor,
    _solve,
    _structure,
)
from fretwear.model.checks import model_argument
from fretwear.model.core import Model
from fretwear.resources import require_memory
from fretwear.validate import number, whole

log = logging.getLogger(__name__)

#: keep the fixed-interface modes up to this multiple of the highest harmonic frequency
CUTOFF = 3.0
#: default bound on the relative error of ``Z_r`` (and ``F_r``) at the highest frequency
TOL = 1e-3
#: random probe vectors of the error check
PROBES = 4
#: raising the number of modes (``raise_modes``): at least this many after none
MIN_RAISE = 8
#: ... and at most this many (beyond, the interior is not well represented by modes: the
#: exact condensation is the better choice)
MAX_MODES = 512
#: how :meth:`ModalCondenser.reduced` returns ``Z_r`` (the class's ``representation``).
#: ``"auto"`` takes the operator where the periodic solve takes the operator Jacobian (more
#: than :data:`OPERATOR_MIN_UNKNOWNS` real unknowns ``m H``: the dense Jacobian forms every
#: block anyway below), the dense blocks otherwise. On the partial-slip pad of
#: benchmarks/scale_3d.py at 1024 contact nodes the path of Powell's solve once depended on
#: rounding (a 1e-15 change of the start sent either representation into a crawl); with
#: Powell's watchdog stretches (fretwear.hb.solvers.WATCHDOG_AFTER) both representations
#: and both starts converge (docs/studies/large-interface-solve.md, "Powell near the law's
#: kinks")
REPRESENTATIONS = ("auto", "dense", "operator", "compressed")
#: real unknowns ``m H`` above which ``"auto"`` takes the operator: where the periodic solve
#: takes the operator Jacobian (fretwear.hb.problem.DENSE_JACOBIAN_MAX, which this module,
#: a layer below, does not import; tests/hb/test_modal_operator.py checks that they agree)
OPERATOR_MIN_UNKNOWNS = 3000
#: relative error of the compressed ``X^cc`` (``representation="compressed"``): the
#: partial-slip pad's solution moved by 6e-6 at 256 and 3.6e-5 at 1024 contact nodes with it
#: (docs/studies/large-interface-solve.md), below the modal check's default TOL
COMPRESS_TOL = 1e-6


@dataclass(frozen=True)
class Representation:
    """How :meth:`ModalCondenser.reduced` returns ``Z_r`` (the condenser's ``representation``:
    a string is this record's ``kind``). ``kind``: one of :data:`REPRESENTATIONS`
    (:class:`ModalCondenser` says what each is); ``compress``: the bound of ``"compressed"``,
    ``||X - X_H||_F <= compress ||X||_F`` for each shared ``X^cc``, a relative error in
    (0, 1) (:data:`COMPRESS_TOL` when None; the other kinds take none)."""

    kind: str = "auto"
    compress: float | None = None

    def __post_init__(self):
        if self.kind not in REPRESENTATIONS:
            raise InputError(f"representation = {self.kind!r}: expected one of "
                             + ", ".join(f'"{r}"' for r in REPRESENTATIONS))
        compress = _compress_bound(self.compress)
        if compress is not None and self.kind != "compressed":
            raise InputError(f"compress = {compress!r} with representation {self.kind!r}: "
                             'expected None (only "compressed" has a bound)')
        if self.kind == "compressed" and compress is None:
            compress = COMPRESS_TOL
        object.__setattr__(self, "compress", compress)

    @classmethod
    def of(cls, value) -> Representation:
        """``value`` itself, or the record of the kind ``value`` names."""
        return value if isinstance(value, Representation) else cls(value)


def next_mode_count(n_modes: int, n_interior: int) -> int | None:
    """The number of modes to try after ``n_modes`` failed the error check: twice as many, at
    least :data:`MIN_RAISE`, at most :data:`MAX_MODES` and ``n_interior - 2`` (the
    Lanczos limit); None when ``n_modes`` already is the most."""
    top = min(MAX_MODES, n_interior - 2)
    if n_modes >= top:
        return None
    return min(max(2 * n_modes, MIN_RAISE), top)


class CheckFailed(InputError):
    """The modal condensation's error check failed (its message says by how much): the
    automatic choice (:func:`fretwear.hb.condensers.condenser`) then condenses exactly."""


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
    raise_modes : when the check fails, keep more modes (:func:`next_mode_count`: doubled,
        at least :data:`MIN_RAISE`, at most :data:`MAX_MODES`) until it passes, instead of
        raising at once; an InputError only when :data:`MAX_MODES` modes do not pass.
    residual : add the static responses of the interior to the constraint modes' inertia
        loads (``m`` vectors, :meth:`_residual_vectors`): the omitted modes' error falls from
        ``(w / w_k)^2`` to ``(w / w_k)^4``; ``q`` grows by ``m``.
    representation : how :meth:`reduced` returns ``Z_r`` (a :class:`Representation`, or its
        ``kind`` alone): ``"dense"`` (an (nb, m, m) array),
        ``"operator"`` (a :class:`~fretwear.hb.modal_operator.ReducedOperator`: the
        frequency-independent ``X^cc`` shared by every harmonic plus a rank-``q`` term per
        harmonic) or ``"auto"`` (the operator above :data:`OPERATOR_MIN_UNKNOWNS` real
        unknowns ``m H``, the dense blocks below: :data:`REPRESENTATIONS`). The same
        condensation either way (to rounding). ``"compressed"``: the operator, whose shared
        ``X^cc`` are also held compressed (:func:`fretwear.hb.hmatrix.compress`, a
        hierarchical low-rank form of the contact nodes' positions with
        ``||X - X_H||_F <= compress ||X||_F``, ``compress`` the record's bound), once for
        every frequency; the solver's
        products take those (below ``m^2`` per column), the blocks it forms (the
        preconditioner's) stay exact.

    Attributes
    ----------
    n_modes : fixed-interface modes kept; q : reduced interior coordinates (modes + load
    responses (+ residual vectors)); mode_frequencies : (n_modes,) [Hz]; error : relative error
    of the check; residual : whether the residual vectors are in the basis; representation :
    ``"dense"``, ``"operator"`` (``"compressed"`` among them) or ``"auto"``; compress : the
    compression's bound (``"compressed"``; None otherwise).
    """

    #: how the projections were made (logged by :func:`modal_condenser`)
    path = "static modes (m solves with K_ii)"

    def __init__(self, model: Model, f_max: float, max_order: int, *, modes: int | None = None,
                 cutoff: float = CUTOFF, tol: float = TOL, raise_modes: bool = False,
                 residual: bool = False, representation: str | Representation = "auto"):
        self._check_args(f_max, modes, cutoff, tol)
        rep = Representation.of(representation)
        self._set_compress(model, rep.compress)
        self.representation = "operator" if rep.kind == "compressed" else rep.kind
        super().__init__(_structure(model), dense=False)
        if not self.ni:
            raise InputError("the model has no interior DOFs: nothing to represent by modes")
        # Psi (n_i x m), with the residual vectors a second n_i x m, K_ii Psi of the
        # projections a third, and the projected blocks of K, M, C, D (m x m each)
        require_memory(8.0 * (self.ni * self.m * (3 if residual else 2) + 5 * self.m**2),
                       f"a modal condensation of {self.ni:,} interior and {self.m:,} contact "
                       "DOFs (its static modes, n_i x m, and projected blocks, m x m)")
        self.f_max, self.max_order, self.tol = float(f_max), int(max_order), float(tol)
        lu = self.factor(0.0, 0, True)  # real LU of K_ii, kept
        # static constraint modes Psi = -K_ii^-1 K_ic (blocked multi-RHS solves)
        Psi = np.empty((self.ni, self.m))
        for j0 in range(0, self.m, BLOCK):
            cols = slice(j0, min(j0 + BLOCK, self.m))
            Psi[:, cols] = -lu.solve(self.K.ic[:, cols].toarray())
        self.Psi = Psi
        # + static responses of the loads' interior parts (and, with ``residual``, of the
        # constraint modes' inertia loads): the modes' companions in the basis
        vecs = self.structure.load_vectors
        Fl = (np.column_stack([v[self.idofs] for v in vecs]) if vecs
              else np.zeros((self.ni, 0)))
        extra = [lu.solve(Fl) if Fl.shape[1] else Fl]
        if residual:
            extra.append(self._residual_vectors(lu))
        self.residual = bool(residual)
        self._exact = None  # the exact side of the error check, computed once
        # fixed-interface modes up to the cutoff, by shift-invert Lanczos on the kept LU;
        # with raise_modes, more of them until the error check passes (next_mode_count)
        f_cut = cutoff * self.max_order * self.f_max
        self._basis(*self._modes(lu, modes, f_cut), np.column_stack(extra))
        while raise_modes and self.error > self.tol:
            k = next_mode_count(self.n_modes, self.ni)
            if k is None:
                break
            self._basis(*self._modes(lu, k, f_cut), np.column_stack(extra))
        if self.error > self.tol:
            raise CheckFailed(
                f"modal condensation with {self.n_modes} modes (up to "
                f"{(self.mode_frequencies.max() if self.n_modes else 0.0):.6g} Hz): relative "
                f"error {self.error:.3g} of Z_r at harmonic {self.max_order} of {f_max:.6g} Hz"
                f" > tol = {tol:g}; keep more modes (modes=, cutoff=), add the residual "
                "vectors (residual=True) or condense exactly")

    # -- construction -------------------------------------------------------------------------
    @staticmethod
    def _check_args(f_max, modes, cutoff, tol):
        """One InputError for an ``f_max`` that is not a positive frequency, ``modes`` that
        is not None or a number of modes, or a ``cutoff`` or ``tol`` not a positive number."""
        if not (isinstance(f_max, int | float) and math.isfinite(f_max) and f_max > 0):
            raise InputError(f"f_max = {f_max!r}: expected a positive frequency [Hz]")
        if modes is not None and (isinstance(modes, bool) or not isinstance(modes, int)
                                  or modes < 0):
            raise InputError(f"modes = {modes!r}: expected a number of modes >= 0")
        for name, value in (("cutoff", cutoff), ("tol", tol)):
            if (isinstance(value, bool) or not isinstance(value, int | float)
                    or not math.isfinite(value) or value <= 0):
                raise InputError(f"{name} = {value!r}: expected a positive number")

    def _basis(self, mode_frequencies, Phi, extra):
        """Interior basis ``V``: the modes ``Phi`` and the static vectors ``extra``, scaled and
        orthonormalised (pivoted QR, dependent columns dropped); then the projections and the
        error check."""
        self.mode_frequencies, self.n_modes = mode_frequencies, Phi.shape[1]
        V = np.column_stack([Phi, extra])
        if V.shape[1]:
            V = V / np.maximum(np.linalg.norm(V, axis=0), 1e-300)  # modes ~ 1/sqrt(kg), loads ~ m
            Q, r, _ = sla.qr(V, mode="economic", pivoting=True)
            keep = np.abs(np.diag(r)) > 1e-10 * abs(r[0, 0])
            V = Q[:, keep]
        self.V, self.q = V, V.shape[1]
        self._static = {}  # the frequency-independent blocks of reduced(): harmonic 0
        self._project()
        self.error = self._check()

    def _residual_vectors(self, lu) -> np.ndarray:
        """``K_ii^-1 (M_ii Psi + M_ic)`` (n_i, m): the static response of the interior to the
        inertia loads of the constraint modes' motion. The exact interior motion is
        ``u_i = Psi u_c + w^2 Z_ii^-1 (M_ii Psi + M_ic) u_c``; with these vectors in the basis
        the omitted modes enter through their residual flexibility (the first term of
        ``Z_ii^-1 = K_ii^-1 + w^2 K_ii^-1 M_ii K_ii^-1 + ..``), and their error falls from
        ``(w / w_k)^2`` to ``(w / w_k)^4`` of the first omitted mode ``w_k`` (docs/theory.md,
        "Large interfaces")."""
        X = np.empty((self.ni, self.m))
        Mic = self.M.ic
        for j0 in range(0, self.m, BLOCK):
            cols = slice(j0, min(j0 + BLOCK, self.m))
            B = self.M.ii @ self.Psi[:, cols]
            B += Mic[:, cols] if isinstance(Mic, np.ndarray) else Mic[:, cols].toarray()
            X[:, cols] = lu.solve(B)
        return X

    def _modes(self, lu, modes, f_cut):
        Kii, Mii = self.K.ii, self.M.ii
        n = self.ni
        op = spla.LinearOperator((n, n), matvec=lambda x: lu.solve(np.asarray(x, float)),
                                 dtype=float)
        if modes == 0 or n < 3:
            return np.zeros(0), np.zeros((n, 0))
        k = min(modes if modes is not None else 20, n - 2)
        while True:
            # the Lanczos basis (2 k + 1 vectors of n), the k modes and its dense work arrays
            require_memory(8.0 * n * (3 * k + 2) + 24.0 * (2 * k + 1) ** 2,
                           f"{k:,} fixed-interface modes of {n:,} interior DOFs")
            # a fixed start vector: SciPy's default is drawn from fresh entropy, and the modes
            # of a degenerate eigenspace (a square pad) then differ by rounding from run to
            # run, and with them every result computed from the condensation
            lam, Phi = spla.eigsh(Kii, k=k, M=Mii, sigma=0.0, which="LM", OPinv=op,
                                  v0=np.random.default_rng(0).standard_normal(n))
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
        """``proj_local``: the reduced matrices ``X^cc`` (m, m), ``X^cq`` (m, q), ``X^qc``
        (q, m), ``X^qq`` (q, q) of ``K, M, C, D`` in the coordinates ``(u_c, q)``, rotated
        once into the contact-local frames (``R X^cc R^T, R X^cq, X^qc R^T, X^qq``):
        :meth:`reduced` then needs no rotation of an m x m block per harmonic and frequency
        (0.9 s of the 1.3 s of a harmonic at 1024 nodes)."""
        Psi, V, R = self.Psi, self.V, self.R
        self.proj_local = {}
        for name in ("K", "M", "C", "D"):
            B = getattr(self, name)
            if B is None:
                continue
            cq = (B.ci @ V) + Psi.T @ (B.ii @ V)
            if name == "K":  # K_ii Psi = -K_ic: the static condensation K_r, and
                # K^qc = V^T (K_ic + K_ii Psi) = 0 (not formed: K_ii Psi is the second
                # largest product of the condensation, 2 s CPU at 1024 contact nodes)
                cc = B.cc + B.ci @ Psi
                qc = np.zeros((V.shape[1], Psi.shape[1]))
            else:
                XiiPsi = B.ii @ Psi
                cc = B.cc + B.ci @ Psi + (B.ic.T @ Psi).T + _gram(Psi, XiiPsi, B.ii)
                qc = (B.ic.T @ V).T + V.T @ XiiPsi
            qq = V.T @ (B.ii @ V)
            self.proj_local[name] = (self._rotate(cc), R @ cq, (R @ qc.T).T, qq)
            del cc

    def _zr(self, omega, n, quasi_static):
        """``(Z^cc, Z^cq, Z^qc, Z^qq)`` of harmonic ``n`` (eq. 18 on the reduced
        coordinates) in the contact-local frames, formed."""
        proj = self.proj_local
        out = list(proj["K"])
        if n == 0 or quasi_static:
            return out
        w = n * omega
        for name, c in (("M", -(w * w)), ("D", 1j), ("C", 1j * w)):
            if name in proj:
                for i, x in enumerate(proj[name]):
                    t = np.multiply(x, c)  # one new array per term (m x m for Z^cc)
                    t += out[i]
                    out[i] = t
        return out

    def _parts(self, omega, n, quasi_static, F):
        """Condensed ``Z_r`` formed, ``Z^qq^-1 Z^qc`` and the condensed load and modal
        coordinates of ``F`` (ndof,) for harmonic ``n``, in the contact-local frames
        (``R Z_r R^T``, ``Z^qq^-1 Z^qc R^T``, ``R F_r``). Real blocks stay real (an undamped
        structure) whatever the loads."""
        cc, cq, qc, qq = self._zr(omega, n, quasi_static)
        Fi = F[self.idofs]
        Fc = self.R @ (F[self.cdofs] + _real_times(self.Psi.T, Fi))
        Fq = _real_times(self.V.T, Fi)
        if self.q:
            Y, qF = np.linalg.solve(qq, qc), np.linalg.solve(qq, Fq)
            S = cq @ Y
            np.subtract(cc, S, out=S)  # cc - cq Y in the product's array (m x m)
            return S, Y, Fc - cq @ qF, qF
        return cc, np.zeros((0, self.m)), Fc, np.zeros(0)

    def _check(self) -> float:
        """Relative error of ``Z_r`` on :data:`PROBES` random vectors, of the observed
        interior DOFs' response to them and of ``F_r``, at the highest harmonic of ``f_max``,
        against the exact condensation (eq. 19); ``Z_r`` applied as the operator (no m x m
        block formed)."""
        n, omega = self.max_order, 2 * np.pi * self.f_max
        F = self.structure.load_harmonics(n)[n]
        if self._exact is None:  # one LU of Z_ii and a few solves, however many bases tried
            P = np.random.default_rng(0).standard_normal((self.m, PROBES))
            lu = _factor(self._z("ii", omega, n, False), n, omega)
            self._used(lu)
            Zci, Zic = self._z("ci", omega, n, False), self._z("ic", omega, n, False)
            X = _solve(lu, Zic @ P)  # Z_ii^-1 Z_ic P: the interior response to the probes
            exact = self._z("cc", omega, n, False) @ P - Zci @ X
            Fe = F[self.cdofs] - Zci @ _solve(lu, F[self.idofs]) if np.any(F) else None
            self._exact = (P, X, exact, Fe)
        P, X, exact, Fe = self._exact
        R = self.R
        parts = self._op_parts(omega, n, False, F)
        SP = R.T @ self._operator([parts]).matmat(np.zeros(P.shape[1], np.int64), R @ P)
        err = np.linalg.norm(SP - exact, axis=0) / np.linalg.norm(exact, axis=0)
        e = float(err.max())
        rows = np.array([i for _, i in self.obs_i], dtype=np.int64)
        if rows.size:  # recovery of the observed interior DOFs: -(Psi - V Y R) P vs -X
            Y = parts[2] @ R if parts[2] is not None else np.zeros((0, self.m))
            mod = (self._psi_at(rows) - self.V[rows] @ Y) @ P
            e = max(e, float(np.linalg.norm(mod + X[rows]) / np.linalg.norm(X[rows])))
        if Fe is not None:
            e = max(e, float(np.linalg.norm(R.T @ parts[3] - Fe)
                             / max(np.linalg.norm(Fe), 1e-300)))
        return e

    # -- the Condenser interface --------------------------------------------------------------
    def check_size(self, orders) -> None:
        """Refuse (one InputError with the estimate and the machine's memory) a reduced
        model on ``orders`` that cannot fit, before it allocates: per harmonic the dense
        ``Z_r`` block (``m x m``, none for the operator), the rank-``q`` term of the operator
        or ``Z^qq^-1 Z^qc`` (``q x m``), the observation rows and loads; the load amplitudes
        of every order up to the highest and the Fourier basis of the balance (as
        :meth:`fretwear.hb.reduce.Condenser.check_size`)."""
        orders = np.asarray(orders, dtype=np.int64)
        if not orders.size:
            return
        nb, k = orders.size, int(orders.max())
        m, no, q = self.m, self.structure.obs.size, self.q
        zr = 0.0 if self._as_operator(orders) else 16.0 * m * m
        per_order = zr + 16.0 * (q * m + no * m + no + m)
        basis = 8.0 * (2 * k + 2) * (2 * k + 1) * 4
        require_memory(nb * per_order + 16.0 * (k + 1) * self.structure.ndof + basis,
                       f"a modal condensation on {nb} harmonic orders (up to {k}) with "
                       f"{m:,} contact DOFs and {q:,} interior coordinates")

    def reduced(self, omega: float, orders, quasi_static: bool = False,
                frequency: float | None = None) -> Reduced:
        """The :class:`~fretwear.hb.reduce.Reduced` model on ``orders`` at ``omega`` [rad/s]
        from the modal representation (``Z`` an array or an operator: ``representation``)."""
        orders = np.asarray(orders, dtype=np.int64)
        self.check_size(orders)
        if self._as_operator(orders):
            return self._reduced_operator(omega, orders, quasi_static, frequency)
        m, no, nb, R = self.m, self.structure.obs.size, orders.size, self.R
        F_all = self.structure.load_harmonics(int(orders.max()) if orders.size else 0)
        # undamped (or static) blocks are real: stored real, half the memory, and the
        # solvers' products need no real copy of them (hb/krylov.py)
        real = quasi_static or not np.any(orders) or not ({"C", "D"} & set(self.proj_local))
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
            Zr[b], Y, Fr[b], qF = self._parts(omega, int(n), quasi_static, F_all[n])
            for j, c in self.obs_c:
                oA[b, j] = _column(R, c)
            if rows.size:
                # u_i = Psi u_c + V q, q = qF - Y u_c (Y taking the local u_loc = R u_c):
                # rows at the interior observed DOFs
                A = self._psi_at(rows) @ R.T - self.V[rows] @ Y
                for (j, _), a, bo in zip(self.obs_i, A, self.V[rows] @ qF, strict=True):
                    oA[b, j], ob[b, j] = a, bo
            if static and int(n) == 0:  # K alone: real, whatever the storage of this call
                self._static[key] = (np.array(F_all[n]), Zr[b].real.copy(), Fr[b].copy(),
                                     oA[b].copy(), ob[b].copy())
        return self._result(omega, orders, Zr, Fr, oA, ob, quasi_static, frequency)

    # -- Z_r as an operator (representation "operator"; the blocked condenser's only one) ----
    def _as_operator(self, orders: np.ndarray) -> bool:
        """Whether :meth:`reduced` on ``orders`` returns the operator: ``representation``
        ``"operator"``, or ``"auto"`` above :data:`OPERATOR_MIN_UNKNOWNS` real unknowns
        (``m`` times one coefficient for order 0, two for every other order)."""
        if self.representation != "auto":
            return self.representation == "operator"
        return self.m * int(np.sum(np.where(orders == 0, 1, 2))) > OPERATOR_MIN_UNKNOWNS

    def _op_terms(self, omega, n, quasi_static):
        """``(coef, Z^cq, Z^qc, Z^qq)`` of harmonic ``n``: the coefficients of the stored
        ``X^cc`` (:data:`NAMES` order) and the modal blocks (contact-local frames)."""
        proj = self.proj_local
        names = list(proj)
        coef = np.zeros(len(names), dtype=complex)
        coef[0] = 1.0
        cq, qc, qq = (x.astype(complex) for x in proj["K"][1:])  # not X^cc: m x m
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

    def _op_parts(self, omega, n, quasi_static, F):
        """``(coef, U, Y, Fr, qF)`` of harmonic ``n`` in the contact-local frames:
        ``Z_r = sum coef X^cc - U Y``, ``Y = Z^qq^-1 Z^qc R^T``, ``Fr = R F_r``."""
        coef, cq, qc, qq = self._op_terms(omega, n, quasi_static)
        Fi = F[self.idofs]
        Fc = self.R @ (F[self.cdofs] + _real_times(self.Psi.T, Fi))
        Fq = self.V.T @ Fi
        if self.q:
            Y, qF = np.linalg.solve(qq, qc), np.linalg.solve(qq, Fq)
            return coef, cq, Y, Fc - cq @ qF, qF
        return coef, None, None, Fc, np.zeros(0)

    def _operator(self, parts) -> ReducedOperator:
        """The :class:`ReducedOperator` of the blocks ``parts`` (:meth:`_op_parts` each)."""
        mats = [self.proj_local[nm][0] for nm in self.proj_local]
        if getattr(self, "_twins", None) is None:  # GMRES's compressed twins, made once
            self._twins = {}
        return ReducedOperator(mats, np.array([p[0] for p in parts]), [p[1] for p in parts],
                               [p[2] for p in parts], symmetric=self._symmetric(),
                               coords=self._coords, twins=self._twins)

    def _symmetric(self) -> bool:
        """Whether ``K, M, C, D`` are symmetric (then so is every ``Z_r(n)``), found once."""
        if getattr(self, "_sym", None) is not None:
            return self._sym
        out = True
        for nm in self.proj_local:
            A = getattr(self.structure, nm)
            out = out and abs(A - A.T).max() <= 1e-12 * abs(A).max()
        self._sym = bool(out)
        return self._sym

    def _reduced_operator(self, omega, orders, quasi_static, frequency) -> Reduced:
        """:meth:`reduced` with ``Z`` a :class:`~fretwear.hb.modal_operator.ReducedOperator`
        (no dense ``m x m`` block per harmonic)."""
        orders = np.asarray(orders, dtype=np.int64)
        m, no, nb, R = self.m, self.structure.obs.size, orders.size, self.R
        F_all = self.structure.load_harmonics(int(orders.max()) if orders.size else 0)
        Fr = np.zeros((nb, m), dtype=complex)
        oA = np.zeros((nb, no, m), dtype=complex)
        ob = np.zeros((nb, no), dtype=complex)
        rows = np.array([i for _, i in self.obs_i], dtype=np.int64)
        parts = []
        for b, n in enumerate(orders):
            p = self._op_parts(omega, int(n), quasi_static, F_all[n])
            parts.append(p)
            Fr[b] = p[3]
            for j, c in self.obs_c:
                oA[b, j] = _column(R, c)
            if rows.size:
                A = self._psi_at(rows) @ R.T - (self.V[rows] @ p[2] if p[2] is not None else 0.0)
                bo = self.V[rows] @ p[4] if p[2] is not None else np.zeros(rows.size)
                for (j, _), a, v in zip(self.obs_i, np.atleast_2d(A), bo, strict=True):
                    oA[b, j], ob[b, j] = a, v
        Z = self._operator(parts)
        Z.products = self._compressed()
        return self._result(omega, orders, Z, Fr, oA, ob, quasi_static, frequency)

    def _set_compress(self, model: Model, compress) -> None:
        """Keep ``compress`` (checked: :func:`_compress_bound`) and the contact nodes'
        positions it needs."""
        self.compress = _compress_bound(compress)
        self._coords = np.asarray(model.contact.coords, dtype=float)
        self._products = None

    def _compressed(self) -> list | None:
        """The compressed ``X^cc`` (``compress``), made on first use and kept: they do not
        depend on the frequency."""
        if self.compress is None:
            return None
        if self._products is None:
            self._products = [hmatrix.compress(self.proj_local[nm][0], self._coords,
                                               self.compress) for nm in self.proj_local]
        return self._products

    def _psi_at(self, rows: np.ndarray) -> np.ndarray:
        """The rows ``rows`` of ``Psi`` (len(rows), m)."""
        return self.Psi[rows]

    def _rotate(self, S: np.ndarray) -> np.ndarray:
        """``R S R^T`` (the contact-local frames) node block by node block in one pass over
        ``S`` (:func:`_rotate_blocks`)."""
        F = np.ascontiguousarray(self.structure.frame, dtype=float)
        out = np.empty_like(S)
        _rotate_blocks(np.ascontiguousarray(S), F, out)
        return out

    def recover(self, omega: float, orders, u_loc, quasi_static: bool = False) -> np.ndarray:
        """All DOFs (nb, ndof) from ``u_loc`` (nb, m) through the modal representation
        (``u_i = Psi u_c + V q``)."""
        orders = np.asarray(orders, dtype=np.int64)
        F_all = self.structure.load_harmonics(int(orders.max()) if orders.size else 0)
        out = np.zeros((orders.size, self.structure.ndof), dtype=complex)
        for b, n in enumerate(orders):
            u = np.asarray(u_loc[b], dtype=complex)
            Uc = self.R.T @ u
            # Y and qF only (no m x m block): Y takes the contact-local u
            _, _, Y, _, qF = self._op_parts(omega, int(n), quasi_static, F_all[n])
            out[b, self.cdofs] = Uc
            ui = _real_times(self.Psi, Uc)
            if Y is not None:
                ui = ui + _real_times(self.V, qF - Y @ u)
            out[b, self.idofs] = ui
        P = self.structure.P
        return out if P is None else (P @ out.T).T


@njit(cache=True)
def _rotate_blocks(S, F, out):
    """``out = R S R^T`` for the block-diagonal ``R`` of the node frames ``F`` (nc, d, d):
    ``out_pq = F_p S_pq F_q^T`` for every pair of nodes, read and written once (the batched
    NumPy form with its transposed copies took 0.55 s per m x m matrix at 1024 contact
    nodes)."""
    nc, d = F.shape[0], F.shape[1]
    t = np.empty((d, d))
    for p in range(nc):
        for q in range(nc):
            for i in range(d):
                for b in range(d):
                    acc = 0.0
                    for a in range(d):
                        acc += F[p, i, a] * S[p * d + a, q * d + b]
                    t[i, b] = acc
            for i in range(d):
                for j in range(d):
                    acc = 0.0
                    for b in range(d):
                        acc += t[i, b] * F[q, j, b]
                    out[p * d + i, q * d + j] = acc


def _gram(Psi: np.ndarray, X: np.ndarray, Bii) -> np.ndarray:
    """``Psi^T X`` for ``X = B_ii Psi``: where ``B_ii`` is exactly symmetric, so is the
    product, and only its upper triangle is computed (``BLOCK`` columns at a time, then
    mirrored): half the ``2 n_i m^2`` flops of the largest product of the condensation (the
    projected mass at 1024 contact nodes: 2.3e11)."""
    m = Psi.shape[1]
    symmetric = (not (Bii != Bii.T).nnz if sp.issparse(Bii)
                 else np.array_equal(Bii, np.transpose(Bii)))
    if not symmetric:
        return Psi.T @ X
    out = np.empty((m, m))
    for j0 in range(0, m, BLOCK):
        js = slice(j0, min(j0 + BLOCK, m))
        out[:js.stop, js] = Psi[:, :js.stop].T @ X[:, js]  # rows up to the block's end
        out[js, :j0] = out[:j0, js].T  # the mirror of the rows above the block
    return out


def _real_times(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``A @ x`` for a real ``A`` and a real or complex ``x`` without the complex copy of
    ``A`` that NumPy's mixed product makes (600 MB for ``Psi^T`` at 1024 contact nodes)."""
    if np.iscomplexobj(x) and not np.iscomplexobj(A):
        return A @ x.real + 1j * (A @ x.imag)
    return A @ x


@model_argument
def modal_condenser(model: Model, f_max: float, max_order: int, *, modes: int | None = None,
                    cutoff: float = CUTOFF, tol: float = TOL, raise_modes: bool = False,
                    residual: bool = False, compress: float | None = None) -> ModalCondenser:
    """A :class:`ModalCondenser` of ``model`` for excitation frequencies up to ``f_max`` [Hz]
    and harmonic orders up to ``max_order``, checked against the exact condensation (an
    :class:`~fretwear.errors.InputError` when its error exceeds ``tol``; ``modes``, ``cutoff``,
    ``raise_modes``, ``residual``: see the class; ``compress``: None, or the relative error
    ``tol`` of the compressed operator (``representation="compressed"`` with that bound);
    :func:`fretwear.hb.condensers.condenser` chooses them, and between this and the exact
    condensation).

    Pass it as ``condenser=`` to every condensation of ``model`` that should use it
    (:func:`~fretwear.hb.reduce.condense`, periodic solves, sweeps, wear runs, recovery), as
    :func:`~fretwear.hb.reduce.exact_condenser`'s condenser is passed; it refuses another
    model, or this one after an edit of its matrices.

    Which condenser (its ``path``, also logged): with CHOLMOD (``fretwear[fast]``), no
    ``residual``, symmetric matrices and a positive definite ``K_ii``, from
    :data:`SCHUR_MIN_CONTACT` contact DOFs on, a :class:`SchurModalCondenser` (the projected
    contact blocks by partial factorisations, no ``m`` solves); otherwise, where the dense
    storage (:func:`dense_storage_gib`) exceeds :data:`DENSE_STORAGE_GIB`, a
    :class:`BlockedModalCondenser` (the same condensation without ``Psi`` or dense blocks per
    harmonic), else a :class:`ModalCondenser`.
    """
    max_order = whole(max_order, "max_order", low=0)
    if modes is not None:
        modes = whole(modes, "modes", low=0)  # 0: the static modes and load responses alone
    f_max = number(f_max, "f_max", low=0.0, open_low=True, unit="Hz")
    compress = _compress_bound(compress)
    rep = "auto" if compress is None else Representation("compressed", compress)
    out = None
    if _partial_factorisations_apply(model, residual):
        try:
            out = SchurModalCondenser(model, f_max, max_order, modes=modes, cutoff=cutoff,
                                      tol=tol, raise_modes=raise_modes, representation=rep)
        except NotFactorisable as e:  # nonsymmetric, or K_ii indefinite: the static modes
            log.info("no partial factorisations: %s", e)
    if out is None and dense_storage_gib(model, max_order) > DENSE_STORAGE_GIB:
        # the blocked condenser keeps every mode below the cutoff (or ``modes``) and adds no
        # residual vectors: their m extra solves are what it cannot afford at this size
        out = BlockedModalCondenser(model, f_max, max_order, modes=modes, cutoff=cutoff,
                                    tol=tol, compress=compress)
    elif out is None:
        out = ModalCondenser(model, f_max, max_order, modes=modes, cutoff=cutoff, tol=tol,
                             raise_modes=raise_modes, residual=residual, representation=rep)
    log.info("modal condensation by %s", out.path)
    return out


class NotFactorisable(InputError):
    """:class:`SchurModalCondenser` of a model whose matrices CHOLMOD cannot factorise (not
    symmetric, or ``K_ii`` not positive definite): :func:`modal_condenser` then takes the
    static modes."""


#: contact DOFs from which :func:`modal_condenser` takes the partial factorisations
#: (:class:`SchurModalCondenser`) where they apply: measured on the pad of
#: benchmarks/scale_3d.py (docs/studies/large-interface-solve.md, "The contact blocks by
#: partial factorisations")
SCHUR_MIN_CONTACT = 3072
#: the contact rows ``L_ci`` of the factor of ``K`` (contact DOFs last) hold at most this
#: fraction of ``n_i m``: 24 %, 16 %, 12 % measured on the pad at 256, 1024, 2304 contact
#: nodes (docs/studies/large-interface-solve.md)
SCHUR_FILL = 0.25


def schur_bytes(ni: int, m: int, matrices: int) -> float:
    """Estimated peak memory [bytes] of a :class:`SchurModalCondenser` of ``ni`` interior and
    ``m`` contact DOFs projecting ``matrices`` of ``K, M, C, D``: the projected ``X^cc``
    (``m x m`` each), the product ``L_cc L_cc^T`` and its copies (three more), and the factor
    of ``K``'s contact rows and front (:data:`SCHUR_FILL` of ``ni m`` and ``m^2 / 2``) twice,
    CHOLMOD's and kvxopt's copy (values and int64 rows, 16 bytes an entry). At 4096 contact
    nodes of the pad (``ni`` = 98,304, ``m`` = 12,288, K and M) 16.9 GiB against the 16.7
    GiB peak measured (docs/studies/large-interface-solve.md)."""
    factor = 2 * 16.0 * (SCHUR_FILL * ni * m + m * m / 2)
    return 8.0 * (matrices + 3) * m * m + factor


def _partial_factorisations_apply(model: Model, residual: bool) -> bool:
    """Whether :func:`modal_condenser` tries a :class:`SchurModalCondenser`: CHOLMOD here,
    no residual vectors and at least :data:`SCHUR_MIN_CONTACT` contact DOFs (the class
    itself refuses nonsymmetric matrices and an indefinite ``K_ii``: :class:`NotFactorisable`)."""
    m = int(np.asarray(model.contact.dofs).size)
    return not residual and m >= SCHUR_MIN_CONTACT and schur.available()


def _symmetric_matrices(model: Model) -> bool:
    """Whether ``K, M, C, D`` of ``model`` are symmetric (to 1e-12 of their largest entry)."""
    for A in (model.K, model.M, model.C, model.D):
        if A is not None and A.shape[0]:
            A = sp.csr_matrix(A)
            if abs(A - A.T).max() > 1e-12 * abs(A).max():
                return False
    return True


def _compress_bound(compress) -> float | None:
    """``compress`` checked: None or a relative error in (0, 1)."""
    if compress is None:
        return None
    if (isinstance(compress, bool) or not isinstance(compress, int | float)
            or not 0 < compress < 1):
        raise InputError(f"compress = {compress!r}: expected None or a relative error in "
                         "(0, 1)")
    return float(compress)


#: above this estimated storage [GiB] :func:`modal_condenser` builds the blocked condenser
#: (1024 contact nodes of benchmarks/scale_3d.py: 1.1 GiB, dense; 4096: 22.5 GiB, blocked)
DENSE_STORAGE_GIB = 6.0


def dense_storage_gib(model: Model, max_order: int) -> float:
    """The arrays of :class:`ModalCondenser` that grow with the interface [GiB]: ``Psi``
    (``n_i x m``), the projected ``K^cc, M^cc`` in both frames and the ``max_order + 1``
    real blocks of ``Z_r`` (``m x m`` each), ``m`` the contact DOFs."""
    m = int(np.asarray(model.contact.dofs).size)
    ni = max(int(model.ndof) - m, 0)
    return 8.0 * (ni * m + (max_order + 5) * m * m) / 2**30


# -- the blocked modal condensation (large interfaces) ---------------------------------------
# The same condensation as ModalCondenser (the same modes, load responses and error check)
# without Psi held whole (n_i x m: 9.7 GB at 4096 contact nodes of benchmarks/scale_3d.py's
# pad) or Z_r as H + 1 dense m x m blocks (1.2 GB each there): the projections are built
# BLOCK columns at a time, Psi^T W = -K_ci K_ii^-1 W (K symmetric) by a second sparse
# multi-right-hand-side solve; the loads, the recovery and the observed interior rows take
# Psi x and Psi^T y by one solve each; the projected X^cc are kept in the contact-local frames
# only, shared by every harmonic of a ReducedOperator (fretwear.hb.modal_operator), whose
# products the solver's operator path takes (fretwear.hb.operator_blocks). Memory: len(X^cc)
# m^2 reals (two undamped) instead of (H + 3) m^2 + 2 n_i m; time: twice the solves of Psi.
# The second solve (Psi^T W for X^cc of M, C, D) is kept on purpose: with Psi stored instead,
# Psi^T W is a dense product of n_i m^2 flops (symmetric half) against 4 nnz(L) m for the
# solves through the Cholesky factor L of K_ii: 1.2e11 against 4.7e10 at 1024 contact nodes
# of benchmarks/scale_3d.py's pad (n_i = 12,288, nnz(L) = 3.8e6), 1.5e13 against about 5e12
# at 4096 (n_i = 98,304, nnz(L) about 1e8), and Psi holds 9 GiB there. The forward half of
# the solve does not help either (Psi^T W = -Y^T L^-1 P W with Y = L^-1 P K_ic, but Y keeps
# 15 % of its n_i m entries, more than L's: measured at 1024), nor does a backward solve on
# the rows K_ci needs only (their ancestors in the elimination tree hold 96 % of L).
# docs/theory.md, "Large interfaces"; docs/studies/large-interface-solve.md.

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
    """:class:`ModalCondenser` without ``Psi`` or dense blocks per harmonic (the comment
    above); the same parameters and interface. ``reduced()`` returns a
    :class:`~fretwear.hb.reduce.Reduced` whose ``Z`` is a
    :class:`~fretwear.hb.modal_operator.ReducedOperator`. Made by
    :func:`fretwear.hb.modal.modal_condenser` for large interfaces."""

    representation = "operator"  # it holds no Psi to form dense blocks from
    path = "blocked static modes (2 m solves with K_ii)"

    def __init__(self, model: Model, f_max: float, max_order: int, *, modes: int | None = None,
                 cutoff: float = CUTOFF, tol: float = TOL, compress: float | None = None):
        self._check_args(f_max, modes, cutoff, tol)
        self._set_compress(model, compress)
        Condenser.__init__(self, _structure(model), dense=False)
        if not self.ni:
            raise InputError("the model has no interior DOFs: nothing to represent by modes")
        # the projected X^cc of K, M, C, D (m x m each) and a block of BLOCK columns of
        # Psi and of the projections at a time (n_i x BLOCK, a few)
        require_memory(8.0 * (4 * self.m**2 + 6 * self.ni * min(BLOCK, self.m)),
                       f"a blocked modal condensation of {self.ni:,} interior and "
                       f"{self.m:,} contact DOFs (its projected blocks, m x m)")
        self.f_max, self.max_order, self.tol = float(f_max), int(max_order), float(tol)
        lu = self.factor(0.0, 0, True)  # real LU of K_ii, kept
        self._lu0 = lu
        self._exact = None  # the exact side of the error check
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
        # the many-column solves are done: the dense panels they were made on (3.3 GiB at
        # 4096 contact nodes) are not held through the solves that follow (few columns)
        lu.release()  # (a sparse factorisation: the interior is never dense here)
        self.error = self._check()
        self._raise_if_inaccurate(f_max, tol)

    @staticmethod
    def _basis(Phi, Xl):
        """The modes and load responses, orthonormalised (as ModalCondenser)."""
        V = np.column_stack([Phi, Xl])
        if V.shape[1]:
            V = V / np.maximum(np.linalg.norm(V, axis=0), 1e-300)
            Q, r, _ = sla.qr(V, mode="economic", pivoting=True)
            V = Q[:, np.abs(np.diag(r)) > 1e-10 * abs(r[0, 0])]
        return V

    def _raise_if_inaccurate(self, f_max, tol):
        if self.error > self.tol:
            raise CheckFailed(
                f"modal condensation with {self.n_modes} modes (up to "
                f"{(self.mode_frequencies.max() if self.n_modes else 0.0):.6g} Hz): relative "
                f"error {self.error:.3g} of Z_r at harmonic {self.max_order} of {f_max:.6g} Hz"
                f" > tol = {tol:g}; keep more modes (modes=, cutoff=) or condense exactly")

    # -- construction -------------------------------------------------------------------------
    def _project(self):
        """``proj_local``: the blocks ``(R X^cc R^T, R X^cq, X^qc R^T, X^qq)`` of every matrix
        of ``K, M, C, D`` present, built ``BLOCK`` columns (whole nodes) at a time.

        While a block ``Psi_js`` is in hand its rows of ``X^cq = X_ci V + Psi^T X_ii V`` are
        taken from it (``Psi_js^T (X_ii V)``, no solve), and ``K^qc = V^T (K_ic + K_ii Psi)
        = 0`` is not formed (as :class:`ModalCondenser`). The one product that needs the
        whole ``Psi``, ``Psi^T W`` for ``X^cc`` of ``M, C, D``, is ``-K_ci K_ii^-1 W``: a
        second solve of the block (the comment above :data:`NAMES` says why it is not a
        product with a stored ``Psi``)."""
        lu, V, K, R = self._lu0, self.V, self.K, self.R
        names = [nm for nm in NAMES if getattr(self, nm) is not None]
        others = [nm for nm in names if nm != "K"]
        m, q, d = self.m, self.q, self.structure.frame.shape[1]
        cc = {nm: np.empty((m, m)) for nm in names}
        qc = {nm: np.zeros((q, m)) for nm in names}
        XiiV = {nm: np.asarray(getattr(self, nm).ii @ V) for nm in names}
        cq = {nm: np.asarray(getattr(self, nm).ci @ V) for nm in names}
        step = max(d, BLOCK // d * d)
        for j0 in range(0, m, step):
            js = slice(j0, min(j0 + step, m))
            Psi = -lu.solve(K.ic[:, js].toarray())  # (ni, B)
            for nm in names:
                cq[nm][js] += Psi.T @ XiiV[nm]
            W = {}
            for nm in others:
                B = getattr(self, nm)
                W[nm] = np.asarray(B.ic[:, js].toarray() + B.ii @ Psi)  # X_ic + X_ii Psi
                qc[nm][:, js] = V.T @ W[nm]
            # Psi^T W = -K_ci K_ii^-1 W for every matrix but K (K_ii Psi = -K_ic: W_K = 0)
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
            self.proj_local[nm] = (cc[nm], R @ cq[nm],
                                   self._rotate_columns(qc[nm], slice(0, m)), V.T @ XiiV[nm])

    def _psi_at(self, rows: np.ndarray) -> np.ndarray:
        return self._psi_rows  # the observed rows, found once (Psi is never formed)

    def _rotate_columns(self, A: np.ndarray, js: slice) -> np.ndarray:
        """``A R_js^T`` for the columns ``js`` (whole nodes) of the frame matrix."""
        F = self.structure.frame
        d = F.shape[1]
        nodes = F[js.start // d : js.stop // d]
        out = np.einsum("rpj,pij->rpi", A.reshape(A.shape[0], -1, d), nodes)
        return out.reshape(A.shape)


# -- the modal condensation by partial factorisations (large interfaces, CHOLMOD) ------------
class _FewColumns:
    """A factorisation whose ``solve`` takes :meth:`~fretwear.hb.sparse_lu._Factor.solve_few`
    (the products with ``Psi`` of :class:`SchurModalCondenser` are of a few columns)."""

    def __init__(self, lu):
        self.lu = lu

    def solve(self, B):
        return self.lu.solve_few(B)


class SchurModalCondenser(BlockedModalCondenser):
    """:class:`ModalCondenser` whose projected contact blocks ``X^cc`` come from partial
    Cholesky factorisations of ``K`` and ``K -/+ h X`` (:mod:`fretwear.hb.schur`: ``K^cc``
    exact, the others by a central difference, error :data:`schur.Difference`), not from
    ``Psi``: no ``m`` solves. ``Psi`` is never formed (as :class:`BlockedModalCondenser`);
    ``X^cq = X_ci V + Psi^T X_ii V`` takes a solve of ``q`` columns. The same parameters as
    :class:`ModalCondenser` but ``residual`` (its ``m`` solves are what this path avoids), the
    same modes, error check and interface; ``representation`` as :class:`ModalCondenser`
    (the dense blocks apply ``Psi`` by solves). Needs CHOLMOD (``fretwear[fast]``) and
    symmetric ``K, M, C, D``. Made by :func:`modal_condenser` where it is faster.

    Attributes (besides :class:`ModalCondenser`'s): ``contact``: the
    :class:`~fretwear.hb.schur.ContactBlocks` record (its ``differences``: the step and
    estimated error of each ``X^cc`` by difference; ``cc`` emptied once rotated into
    ``proj_local``)."""

    path = "partial factorisations (CHOLMOD)"

    def __init__(self, model: Model, f_max: float, max_order: int, *, modes: int | None = None,
                 cutoff: float = CUTOFF, tol: float = TOL, raise_modes: bool = False,
                 representation: str | Representation = "auto"):
        self._check_args(f_max, modes, cutoff, tol)
        rep = Representation.of(representation)
        self._set_compress(model, rep.compress)
        self.representation = "operator" if rep.kind == "compressed" else rep.kind
        Condenser.__init__(self, _structure(model), dense=False)
        if not self.ni:
            raise InputError("the model has no interior DOFs: nothing to represent by modes")
        if not schur.available():
            raise InputError("a modal condensation by partial factorisations needs CHOLMOD "
                             "(pip install 'fretwear[fast]'); modal_condenser falls back to "
                             "the static modes without it")
        if not _symmetric_matrices(model):
            raise NotFactorisable("a modal condensation by partial factorisations needs "
                                  "symmetric K, M, C, D (CHOLMOD factorises K -/+ h X); build "
                                  "a ModalCondenser instead")
        names = [nm for nm in NAMES if getattr(self, nm) is not None]
        require_memory(schur_bytes(self.ni, self.m, len(names)),
                       f"a modal condensation by partial factorisations of {self.ni:,} "
                       f"interior and {self.m:,} contact DOFs (its projected blocks, m x m, "
                       f"and the factor of K)")
        self.f_max, self.max_order, self.tol = float(f_max), int(max_order), float(tol)
        lu = self.factor(0.0, 0, True)  # CHOLMOD's Cholesky of K_ii, kept
        if getattr(lu, "name", "") != "cholmod":  # CHOLMOD refused K_ii: not definite
            raise NotFactorisable("a modal condensation by partial factorisations needs a positive "
                              "definite K_ii (CHOLMOD refused it; the factorisations of K -/+ "
                              "h X would fail); build a ModalCondenser instead")
        self._lu0, self._exact, self._cc_local = lu, None, None
        self.residual = False
        few = _FewColumns(lu)
        self.Psi = _StaticModes(few, self.K)
        self.contact = schur.contact_blocks(
            self.K, {nm: getattr(self, nm) for nm in names if nm != "K"}, few)
        rows = np.array([i for _, i in self.obs_i], dtype=np.int64)
        self._psi_rows = self.Psi.rows(rows) if rows.size else np.zeros((0, self.m))
        vecs = self.structure.load_vectors
        Fl = (np.column_stack([v[self.idofs] for v in vecs]) if vecs
              else np.zeros((self.ni, 0)))
        Xl = few.solve(Fl) if Fl.shape[1] else Fl
        f_cut = cutoff * self.max_order * self.f_max
        self._set_basis(*self._modes(lu, modes, f_cut), Xl)
        while raise_modes and self.error > self.tol:
            k = next_mode_count(self.n_modes, self.ni)
            if k is None:
                break
            self._set_basis(*self._modes(lu, k, f_cut), Xl)
        self._raise_if_inaccurate(f_max, tol)

    def _set_basis(self, mode_frequencies, Phi, Xl):
        """The basis of the modes ``Phi`` and load responses ``Xl``, its projections and the
        error check (the ``X^cc`` found once: they do not depend on the basis)."""
        self.mode_frequencies, self.n_modes = mode_frequencies, Phi.shape[1]
        self.V = self._basis(Phi, Xl)
        self.q = self.V.shape[1]
        self._static = {}
        self._project()
        self.error = self._check()

    def _project(self):
        """``proj_local`` (as :class:`ModalCondenser`): ``X^cc`` from the partial
        factorisations rotated once into the contact-local frames; ``X^cq = X_ci V +
        Psi^T (X_ii V)`` by a solve of ``q`` columns, ``X^qc = (X^cq)^T`` (``X`` symmetric;
        ``K^qc = 0``), ``X^qq = V^T X_ii V``."""
        V, R = self.V, self.R
        if self._cc_local is None:
            self._cc_local = {}
            for nm in list(self.contact.cc):
                self._cc_local[nm] = self._rotate(self.contact.cc.pop(nm))
        self.proj_local = {}
        for nm in NAMES:
            B = getattr(self, nm)
            if B is None:
                continue
            XiiV = np.asarray(B.ii @ V)
            cq = np.asarray(B.ci @ V) + (self.Psi.T @ XiiV if self.q else 0.0)
            qc = np.zeros((self.q, self.m)) if nm == "K" else cq.T
            self.proj_local[nm] = (self._cc_local[nm], R @ cq, (R @ qc.T).T, V.T @ XiiV)
