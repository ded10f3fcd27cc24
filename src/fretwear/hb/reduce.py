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
of eq. 19 (:meth:`Condenser.schur`).

The prepared condensation of a structure is an object the caller owns, as scikit-fem's
``Basis`` is built once and passed to ``asm``: :func:`exact_condenser` builds a
:class:`Condenser` (the modal one is :func:`fretwear.hb.modal.modal_condenser`), and every
function that condenses takes it as ``condenser=`` (None: a new exact one for that call
alone; build one and pass it for repeated calls). A condenser remembers the model it was
built for and refuses another one (:meth:`Condenser.check`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.hb import sparse_lu
from fretwear.limits import RANGES
from fretwear.model.checks import model_argument
from fretwear.model.core import Model
from fretwear.model.interfaces import observed_map, relative_model
from fretwear.resources import require_memory
from fretwear.validate import number


@dataclass
class Reduced:
    """Reduced dynamic stiffness and loads on the contact DOFs for one frequency.

    Attributes
    ----------
    omega : excitation circular frequency ``2 pi frequency`` [rad/s] (0 allowed when
        ``quasi_static``).
    orders : (nb,) harmonic orders ``[0, h1, .., hk]``.
    Z : (nb, m, m) complex reduced dynamic stiffness [N/m] in contact-local coordinates,
        ``m = n_contact * d``, rows/columns node-major ``[N, T1, (T2)]``; real when every
        block is (an undamped structure or a static problem through the modal condensation of
        fretwear.hb.modal: half the memory, no real copy for the solvers' products).
    F : (nb, m) complex reduced load amplitudes [N] (``F[0]`` is the static load).
    obs_A, obs_b : (nb, no, m), (nb, no) complex: observed DOFs ``U_o = obs_A @ u_loc + obs_b``.
    obs_dofs : (no,) global DOFs of the observed points, in the order of ``model.observed``.
    quasi_static : True when inertia and damping were dropped.
    frequency : excitation frequency [Hz], as given to :func:`condense`.
    estimate : None for an exact condensation; for a model from the local bases
        (:meth:`Condenser.nearby`) the estimate of its relative error in ``Z`` and ``F``
        (the worst harmonic): a point converged on it is polished on the exact condensation
        before a sweep records it (:meth:`fretwear.hb.branch.Problems.polish`).
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
    estimate: float | None = None

    def __post_init__(self):
        self.omega = number(self.omega, "Reduced omega", low=0.0, unit="rad/s")
        self.orders = whole_orders(self.orders)
        nb = self.orders.size
        for name, ndim in (("Z", 3), ("F", 2), ("obs_A", 3), ("obs_b", 2)):
            a = getattr(self, name)
            if name == "Z" and hasattr(a, "arrays"):  # the modal ReducedOperator: its arrays
                ok = a.shape[0] == nb and all(np.all(np.isfinite(x)) for x in a.arrays())
            else:
                ok = (isinstance(a, np.ndarray) and a.ndim == ndim and a.shape[0] == nb
                      and a.dtype.kind in "fc" and bool(np.all(np.isfinite(a))))
            if not ok:
                raise InputError(f"Reduced {name} = {repr(a)[:50]}; expected a finite "
                                 f"{ndim}-dimensional array, one block per order ({nb})")
        m = self.Z.shape[1]
        if self.Z.shape[2] != m or self.F.shape[1] != m or self.obs_A.shape[2] != m:
            raise InputError(f"Reduced arrays of inconsistent sizes: Z {self.Z.shape}, F "
                             f"{self.F.shape}, obs_A {self.obs_A.shape}")
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
    return _dynamic_stiffness(_structure(model, relative=False), 2 * np.pi * frequency, n,
                              quasi_static)


@dataclass
class Structure:
    """What the condensation reads from a model, read in one place (:func:`_structure`).

    K, M : (ndof, ndof) sparse CSR [N/m], [kg]; C, D : viscous [N s/m] and hysteretic [N/m]
    damping or None; load_harmonics : ``nmax -> (nmax+1, ndof)`` complex load amplitudes [N]
    (:meth:`fretwear.model.core.Model.load_harmonics`); fixed : held DOFs; cdofs : (m,)
    contact DOFs node-major; frame : (nc, d, d) local frames; obs : global DOFs of the
    observed points in the order of ``model.observed``; load_vectors : the loads' (ndof,)
    vectors [N]. With node-to-node pairs every field is in the relative coordinates ``U'``
    (``U = P U'``, :func:`fretwear.model.interfaces.relative_model`), ``obs`` holds the
    primed DOFs the observed ones depend on and ``U[obs_out] = S @ U'[obs]``; ``P``, ``S``
    are None without pairs (``obs_out = obs``). fingerprint : what the condensation depends on
    in the model read (:func:`_fingerprint`; None for the model's own coordinates).
    """

    K: sp.csr_matrix
    M: sp.csr_matrix
    C: sp.csr_matrix | None
    D: sp.csr_matrix | None
    load_harmonics: object
    fixed: np.ndarray
    cdofs: np.ndarray
    frame: np.ndarray
    obs: np.ndarray
    load_vectors: list
    P: sp.csr_matrix | None = None
    obs_out: np.ndarray | None = None
    S: sp.csr_matrix | None = None
    fingerprint: tuple | None = None

    @property
    def ndof(self) -> int:
        return int(self.K.shape[0])


def _structure(model: Model, relative: bool = True) -> Structure:
    """The structure's matrices, loads, contact DOFs and observed DOFs as the condensation
    sees them: every read of ``model.K/M/C/D``, the loads and the observed DOFs in this module
    goes through here, and the change of coordinates of node-to-node pairs (``U = P U'``)
    applies here (``relative=False``: the model's own coordinates). The loads are read by
    :func:`_read_loads`, the same code that reads them again at each use of a condenser."""
    P = None
    given, fp = model, None
    if relative:
        fp = _fingerprint(model)
        model, P = relative_model(model)  # node-to-node pairs: relative coordinates U = P U'
        obs_out, obs, S = observed_map(model, P)  # U[obs_out] = S @ U'[obs]
    else:
        obs_out = obs = (np.concatenate([np.asarray(p.dofs, dtype=np.int64)
                                         for p in model.observed])
                         if model.observed else np.zeros(0, dtype=np.int64))
        S = None
    s = Structure(
        K=sp.csr_matrix(model.K), M=sp.csr_matrix(model.M),
        C=None if model.C is None else sp.csr_matrix(model.C),
        D=None if model.D is None else sp.csr_matrix(model.D),
        load_harmonics=None,
        fixed=np.asarray(model.fixed_dofs, dtype=np.int64),
        cdofs=np.asarray(model.contact.dofs, dtype=np.int64).reshape(-1),
        frame=np.asarray(model.contact.frame, dtype=float), obs=np.asarray(obs, np.int64),
        load_vectors=[], P=P, obs_out=np.asarray(obs_out, np.int64), S=S, fingerprint=fp)
    _read_loads(s, given)
    return s


def _read_loads(s: Structure, model: Model) -> None:
    """Point ``s`` at the current loads of ``model`` (``P^T F`` in the relative coordinates of
    node-to-node pairs): ``load_harmonics`` reads them at each call, ``load_vectors`` now."""
    P = s.P
    if P is None:
        s.load_harmonics = model.load_harmonics
        s.load_vectors = [np.asarray(ld.vector, dtype=float) for ld in model.loads]
        return
    Pt = P.T.tocsr()
    s.load_harmonics = lambda nmax: (Pt @ model.load_harmonics(nmax).T).T
    s.load_vectors = [Pt @ np.asarray(ld.vector, dtype=float) for ld in model.loads]


def _fingerprint(model: Model) -> tuple:
    """What a :class:`Condenser` depends on: the matrices (identity, pattern size and a sum of
    their entries, so an edit in place is seen), the fixed DOFs, contact DOFs, partners and
    frames, and the observed points (not the loads: they are read at each use)."""
    def mat(A):
        if A is None:
            return None
        data = A.data if sp.issparse(A) else np.asarray(A)
        return (id(A), getattr(A, "nnz", data.size), float(np.sum(data)),
                float(np.sum(np.abs(data))))

    c = model.contact
    return (mat(model.K), mat(model.M), mat(model.C), mat(model.D),
            np.asarray(model.fixed_dofs).tobytes(), np.asarray(c.dofs).tobytes(),
            np.asarray(c.frame, float).tobytes(),
            None if getattr(c, "partner_dofs", None) is None
            else np.asarray(c.partner_dofs).tobytes(),
            None if getattr(c, "segments", None) is None
            else np.asarray(c.segments.weights, float).tobytes()
            + np.asarray(c.segments.dofs).tobytes(),
            tuple(tuple(np.asarray(p.dofs).tolist()) for p in model.observed))


def _dynamic_stiffness(s: Structure, omega: float, n: int, quasi_static: bool = False):
    """Sparse complex ``Z_n`` of the structure ``s`` at the circular frequency ``omega``."""
    K = s.K.tocsc()
    if n == 0 or quasi_static:
        return K.astype(complex)
    w = n * omega
    Z = K.astype(complex) - (w * w) * s.M.tocsc()
    if s.D is not None:
        Z = Z + 1j * s.D.tocsc()
    if s.C is not None:
        Z = Z + (1j * w) * s.C.tocsc()
    return Z.tocsc()


def _partition(s: Structure):
    cdofs = s.cdofs
    if np.intersect1d(cdofs, s.fixed).size:
        raise InputError("contact DOFs cannot also be fixed (Dirichlet) DOFs")
    keep = np.ones(s.ndof, dtype=bool)
    keep[s.fixed] = False
    keep[cdofs] = False
    return cdofs, np.flatnonzero(keep)


def _frame_matrix(s: Structure) -> sp.csr_matrix:
    """Block-diagonal R (m, m) with ``u_loc = R @ U[cdofs]``; sparse above ``DENSE_MAX``
    contact DOFs (a dense R made the rotation ``R S R^T`` of a large interface cost
    ``4 m^3``)."""
    nc, d, _ = s.frame.shape
    if nc * d > DENSE_MAX:
        return sp.block_diag(list(s.frame), format="csr")
    R = np.zeros((nc * d, nc * d))
    for p in range(nc):
        R[p * d : (p + 1) * d, p * d : (p + 1) * d] = s.frame[p]
    return R


def _column(R, c: int) -> np.ndarray:
    """Column ``c`` of the frame matrix (dense or sparse) as a 1-D array."""
    return R[:, c] if isinstance(R, np.ndarray) else R[:, [c]].toarray()[:, 0]


def _singular(n: int, omega: float, near: bool) -> InputError:
    if near:
        return InputError(
            f"the structure with its contact DOFs held (node-to-node pairs glued) is (nearly) "
            f"singular at harmonic {n}: "
            "part of the model can move with nothing to hold it (add springs or fixed DOFs)")
    return InputError(
        f"the structure with its contact DOFs held (node-to-node pairs glued) is singular "
        f"at harmonic {n} "
        f"(excitation {omega / (2 * np.pi):.6g} Hz): part of the model can move with "
        "nothing to hold it (add springs or fixed DOFs), or the frequency is an "
        "eigenfrequency of the undamped structure with a clamped interface")


class _DenseLU:
    """LAPACK LU of a small dense ``Z_ii`` with the interface of SuperLU's ``solve``."""

    name = "lapack"

    def __init__(self, A, n, omega):
        try:
            with warnings.catch_warnings():  # singular: the message below says why
                warnings.simplefilter("ignore", sla.LinAlgWarning)
                self.lu = sla.lu_factor(A, check_finite=False)
        except (ValueError, sla.LinAlgError) as exc:
            raise _singular(n, omega, False) from exc
        diag = np.abs(np.diag(self.lu[0]))
        if diag.size and (not np.all(np.isfinite(diag)) or diag.min() <= 1e-13 * diag.max()):
            raise _singular(n, omega, diag.min() > 0)

    def solve(self, b):
        return sla.lu_solve(self.lu, b, check_finite=False)


def _factor(Zii, n: int, omega: float):
    """LU of ``Z_ii`` (sparse: :func:`fretwear.hb.sparse_lu.factor`, CHOLMOD's Cholesky for a
    real symmetric one where installed, else SuperLU; LAPACK for a dense array); a singular
    matrix becomes an InputError naming the cause. The factorisation's ``name`` says which
    backend made it."""
    if isinstance(Zii, np.ndarray):
        return _DenseLU(Zii, n, omega)
    Zii = Zii.tocsc()
    if Zii.dtype.kind == "c" and not np.any(Zii.data.imag):
        # an undamped structure: Z_ii = K_ii - (n w)^2 M_ii is real; a real factorisation
        # costs a quarter of the complex one and solves complex right-hand sides by parts
        Zii = sp.csc_matrix((np.ascontiguousarray(Zii.data.real), Zii.indices, Zii.indptr),
                            shape=Zii.shape)
    try:
        return sparse_lu.factor(Zii, "spd" if _real_symmetric(Zii) else "general")
    except sparse_lu.SingularError as exc:
        raise _singular(n, omega, exc.near) from exc


def _real_symmetric(A) -> bool:
    """True for a real sparse ``A`` equal to its transpose to rounding (the interior
    stiffness ``K_ii``): the only kind a Cholesky factorisation may take."""
    if A.dtype.kind == "c":
        return False
    scale = abs(A).max() if A.nnz else 0.0
    return A.nnz == 0 or abs(A - A.T).max() <= 1e-12 * scale


#: at most this many interior DOFs: the condensation works on dense arrays (LAPACK). Below it
#: the sparse machinery costs more than the arithmetic (docs/theory.md, "Cost of the
#: condensation": measured crossover 100-180 interior DOFs, benchmarks/condense_small.py).
DENSE_MAX = 150
#: at most this many interior DOFs: the harmonics of a dense condensation are condensed
#: together in one batched solve (:meth:`Condenser._reduced_batched`); above it the
#: arithmetic dominates and the per-harmonic LUs are kept for the recovery
BATCH_MAX = 32
#: right-hand sides per block of the multi-RHS sparse solves: bounds the memory of
#: ``Z_ii^-1 Z_ic`` to ``n_i x BLOCK`` complex values.
BLOCK = 256
#: bytes of factorisations a :class:`Condenser` keeps for reuse (static LU first).
LU_BUDGET = 2**29
#: bytes of interior solutions ``Z_ii^-1 [Z_ic, F_i]`` a :class:`Condenser` may keep (one
#: frequency, every harmonic) for :meth:`Condenser.nearby`; above, it keeps none
INTERIOR_BUDGET = 2**28


@dataclass
class _Blocks:
    """One matrix split into contact (c) and interior (i) blocks: ``cc`` dense, ``ci``
    sparse CSR (or dense), ``ic`` sparse CSC (or dense), ``ii`` sparse CSC or dense."""

    cc: np.ndarray
    ci: object
    ic: object
    ii: object


def _split(A, cdofs, idofs, dense: bool) -> _Blocks | None:
    if A is None:
        return None
    if dense and A.shape[0] <= 2 * DENSE_MAX:  # a small matrix: numpy slicing is cheaper
        A = A.toarray()
        return _Blocks(A[np.ix_(cdofs, cdofs)], A[np.ix_(cdofs, idofs)],
                       A[np.ix_(idofs, cdofs)], A[np.ix_(idofs, idofs)])
    A = A.tocsr()
    rows_c, rows_i = A[cdofs], A[idofs]
    ci, ic, ii = rows_c[:, idofs], rows_i[:, cdofs].tocsc(), rows_i[:, idofs].tocsc()
    if dense:
        ci, ic, ii = ci.toarray(), ic.toarray(), ii.toarray()
    return _Blocks(rows_c[:, cdofs].toarray(), ci, ic, ii)


class Condenser:
    """The exact condensation (eq. 19) of one structure, prepared once and reused across
    harmonics, frequencies, sweep points and wear steps.

    The partition, the frame rotation and the contact/interior blocks of ``K, M, C, D`` are
    extracted once; per harmonic only ``Z_ii`` is formed and factorised (the static LU of
    ``K_ii`` is kept: harmonic 0 at every frequency, quasi-static solves, recovery). Small
    models (``n_i <= DENSE_MAX``) work on dense arrays with LAPACK; large ones use SuperLU
    with blocked multi-right-hand-side solves (``BLOCK`` columns at a time, so the dense
    ``Z_ii^-1 Z_ic`` is never held whole). Made by :func:`exact_condenser` and owned by the
    caller, who passes it (``condenser=``) to every condensation of the same model.
    """

    def __init__(self, structure: Structure, dense: bool | None = None):
        s = self.structure = structure
        self.cdofs, self.idofs = _partition(s)
        self.R = _frame_matrix(s)
        self.m, self.ni = self.cdofs.size, self.idofs.size
        self.dense = self.ni <= DENSE_MAX if dense is None else bool(dense)
        args = (self.cdofs, self.idofs, self.dense)
        self.K, self.M = _split(s.K, *args), _split(s.M, *args)
        self.C, self.D = _split(s.C, *args), _split(s.D, *args)
        pos_c = {int(g): j for j, g in enumerate(self.cdofs)}
        pos_i = {int(g): j for j, g in enumerate(self.idofs)}
        # observed DOFs: on the contact (column of R), interior (row of Z_ii^-1), or fixed
        self.obs_c = [(j, pos_c[int(g)]) for j, g in enumerate(s.obs) if int(g) in pos_c]
        self.obs_i = [(j, pos_i[int(g)]) for j, g in enumerate(s.obs) if int(g) in pos_i]
        self._lus: dict = {}
        self._static = None
        self._load_cache: dict = {}
        # interior solutions of the latest exact condensation per harmonic, and their local
        # bases (keep_interior, nearby): None when not kept
        self._interior: dict | None = None
        self._bases: dict = {}
        self._last_X = None
        #: the sparse (or dense) solvers that factorised ``Z_ii`` so far (``"cholmod"``,
        #: ``"superlu"``, ``"lapack"``: :mod:`fretwear.hb.sparse_lu`)
        self.lu_backends: set[str] = set()

    def _used(self, lu) -> None:
        """Record (and log, the first time) the backend that made the factorisation ``lu``."""
        name = getattr(lu, "name", "superlu")
        if name not in self.lu_backends:
            self.lu_backends.add(name)
            sparse_lu.log.info("condensation: interior matrices factorised by %s", name)

    # -- the model it belongs to ---------------------------------------------------------------
    def check(self, model: Model) -> Condenser:
        """Refuse ``model`` (:class:`~fretwear.errors.InputError`) unless this condenser was
        built for it as it is now (the same matrices, unedited, fixed DOFs, contact DOFs and
        frames, observed points); then read its current loads, which may change between calls
        (:meth:`read_loads`). Returns the condenser."""
        if _fingerprint(model) != self.structure.fingerprint:
            raise InputError(
                "condenser: built for another model, or for this model before its matrices, "
                "fixed DOFs, contact DOFs, frames or observed points changed; build one for "
                "this model (fretwear.exact_condenser(model) or "
                "fretwear.modal_condenser(model, f_max, max_order))")
        self.read_loads(model)
        return self

    def read_loads(self, model: Model) -> None:
        """Read the loads of ``model`` anew (the condensation of the structure is kept; the
        loads condensed at the next call are the model's at that call)."""
        self._load_cache = {}
        _read_loads(self.structure, model)

    # -- the blocks of Z_n ------------------------------------------------------------------
    def _z(self, part: str, omega: float, n: int, quasi_static: bool):
        """Block ``part`` (``"cc"``, ``"ci"``, ``"ic"``, ``"ii"``) of ``Z_n`` (eq. 18)."""
        K = getattr(self.K, part)
        if n == 0 or quasi_static:
            return K  # real: the static LU and products stay in real arithmetic
        w = n * omega
        Z = K.astype(complex) - (w * w) * getattr(self.M, part)
        if self.D is not None:
            Z = Z + 1j * getattr(self.D, part)
        if self.C is not None:
            Z = Z + (1j * w) * getattr(self.C, part)
        return Z

    @staticmethod
    def _key(omega, n, quasi_static):
        return ("static",) if (n == 0 or quasi_static) else (float(omega), int(n))

    def factor(self, omega: float, n: int, quasi_static: bool = False):
        """LU of ``Z_ii`` for harmonic ``n`` at ``omega`` [rad/s] (None without interior
        DOFs); kept for reuse within :data:`LU_BUDGET` bytes."""
        if not self.ni:
            return None
        key = self._key(omega, n, quasi_static)
        lu = self._lus.get(key)
        if lu is None:
            lu = _factor(self._z("ii", omega, n, quasi_static), n, omega)
            self._used(lu)
            size = 16 * self.ni**2 if self.dense else lu.nbytes
            if size <= LU_BUDGET:
                if key != ("static",):  # keep the static LU and the latest frequency only
                    for k in [k for k in self._lus if k != ("static",) and k[0] != key[0]]:
                        del self._lus[k]
                self._lus[key] = lu
        return lu

    def schur(self, omega: float, n: int, quasi_static: bool = False):
        """``(Z_r, lu, Zci, Xo)``: the condensed ``Z_r = R (Z_cc - Z_ci Z_ii^-1 Z_ic) R^T``
        (eq. 19) in the contact-local frame, the LU of ``Z_ii``, ``Z_ci`` and the rows of
        ``Z_ii^-1 Z_ic`` at the interior observed DOFs (``len(obs_i)``, m). The static one
        (harmonic 0, quasi-static) is computed once and kept (read-only arrays)."""
        static = n == 0 or quasi_static
        if static and self._static is not None:
            return self._static
        out = self._schur(omega, n, quasi_static)
        if static:
            for a in (out[0], out[3]):
                a.flags.writeable = False
            self._static = out
        return out

    def _schur(self, omega: float, n: int, quasi_static: bool):
        S = self._z("cc", omega, n, quasi_static)
        lu = self.factor(omega, n, quasi_static)
        if lu is None:
            return self.R @ S @ self.R.T, None, None, np.zeros((0, self.m))
        Zci = self._z("ci", omega, n, quasi_static)
        Zic = self._z("ic", omega, n, quasi_static)
        rows = np.array([i for _, i in self.obs_i], dtype=np.int64)
        Xo = np.zeros((rows.size, self.m), dtype=S.dtype)
        S = S.copy()
        keep = self._interior is not None and not (n == 0 or quasi_static)
        self._last_X = np.empty((self.ni, self.m), dtype=complex) if keep else None
        for j0 in range(0, self.m, BLOCK):  # blocked multi-RHS solves
            cols = slice(j0, min(j0 + BLOCK, self.m))
            B = Zic[:, cols]
            X = lu.solve(B if isinstance(B, np.ndarray) else B.toarray())  # Z_ii^-1 Z_ic
            S[:, cols] -= Zci @ X
            Xo[:, cols] = X[rows]
            if keep:
                self._last_X[:, cols] = X
        return self.R @ S @ self.R.T, lu, Zci, Xo

    def loads(self, F, lu, Zci):
        """``F_r = R (F_c - Z_ci Z_ii^-1 F_i)`` (eq. 19) and ``Z_ii^-1 F_i`` (None without
        interior DOFs) for a load vector ``F`` (ndof,) or one per column (ndof, k)."""
        if lu is None:
            return self.R @ F[self.cdofs], None
        xf = _solve(lu, F[self.idofs])
        return self.R @ (F[self.cdofs] - Zci @ xf), xf

    # -- the reduced model --------------------------------------------------------------------
    def reduced(self, omega: float, orders, quasi_static: bool = False,
                frequency: float | None = None) -> Reduced:
        """The :class:`Reduced` model on harmonic ``orders`` at ``omega`` [rad/s]."""
        orders = np.asarray(orders, dtype=np.int64)
        m, no, nb = self.m, self.structure.obs.size, orders.size
        self.check_size(orders)
        F_all = self.load_harmonics(int(orders.max()) if orders.size else 0)
        if (self.dense and self.ni <= BATCH_MAX and isinstance(self.R, np.ndarray)
                and not quasi_static and omega > 0):
            out = self._reduced_batched(omega, orders, F_all)
            if out is not None:
                return self._result(omega, orders, *out, quasi_static, frequency)
        Zr = np.zeros((nb, m, m), dtype=complex)
        Fr = np.zeros((nb, m), dtype=complex)
        oA = np.zeros((nb, no, m), dtype=complex)
        ob = np.zeros((nb, no), dtype=complex)
        done = {}  # quasi-static: every harmonic shares Z_0 = K
        for b, n in enumerate(orders):
            key = self._key(omega, int(n), quasi_static)
            if key not in done:
                Zr_n, lu, Zci, Xo = self.schur(omega, int(n), quasi_static)
                A = np.zeros((no, m), dtype=complex)
                for j, c in self.obs_c:
                    A[j] = _column(self.R, c)  # U_c = R^T u_loc
                for (j, _), x in zip(self.obs_i, Xo, strict=True):
                    A[j] = -(x @ self.R.T)
                done[key] = (Zr_n, A, lu, Zci)
            Zr[b], oA[b], lu, Zci = done[key]
            Fr[b], xf = self.loads(F_all[n], lu, Zci)
            for j, i in self.obs_i:
                ob[b, j] = xf[i]
            if self._last_X is not None and key[0] != "static":
                refs = self._interior.setdefault(int(n), [])
                refs[:] = [r for r in refs if r[0] != float(omega)][-1:]  # the two latest
                refs.append((float(omega), self._last_X, xf, F_all[n][self.idofs]))
                self._last_X = None
        return self._result(omega, orders, Zr, Fr, oA, ob, quasi_static, frequency)

    # -- nearby frequencies from the interior solutions (fretwear.hb.local_basis) -----------
    def keep_interior(self) -> bool:
        """Keep, from now on, the interior solutions of the latest exact condensation of
        each harmonic for :meth:`nearby`; False (and nothing kept) where that is not
        available: the batched path of tiny models, subclasses with their own reduction (the
        modal condenser), or more than :data:`INTERIOR_BUDGET` bytes."""
        return type(self).reduced is Condenser.reduced and self._keep()

    def _keep(self) -> bool:
        """:meth:`keep_interior` without asking whether ``reduced`` is this class's."""
        batched = self.dense and self.ni <= BATCH_MAX
        if batched or not self.ni or 16.0 * self.ni * (self.m + 1) * 8 > INTERIOR_BUDGET:
            return False  # (at most 8 harmonics within the budget)
        if self._interior is None:
            self._interior = {}
        return True

    def nearby(self, omega: float, orders, tol: float, frequency: float | None = None
               ) -> Reduced | None:
        """The :class:`Reduced` model on ``orders`` at ``omega`` [rad/s] from the interior
        solutions of the latest exact condensation of each harmonic
        (:func:`fretwear.hb.local_basis.local_basis`: exact at its frequency, off by the
        square of the interior response's change away from it; always the latest, so that a
        difference quotient in frequency never spans two bases), or None where its error
        estimate at ``omega`` exceeds ``tol`` (relative, in ``Z_r`` or ``F_r``, of any
        harmonic), or a harmonic has fewer than two exact condensations kept. The estimate
        (the result's field ``estimate``) is the error's leading term at the distance
        from the basis's frequency, scaled by the two latest bases' disagreement one spacing
        beyond the later one (:meth:`_disagreement`). Harmonic 0 is the exact static
        condensation. No factorisation and no interior solve
        (:meth:`keep_interior`)."""
        orders = np.asarray(orders, dtype=np.int64)
        dyn = [int(n) for n in orders if n > 0]
        if self._interior is None or any(len(self._interior.get(n, ())) < 2 for n in dyn):
            return None
        F_all = self.load_harmonics(int(orders.max()))
        estimate = 0.0
        for n in dyn:  # the estimate first: no block formed for a model it refuses
            dis, h = self._disagreement(n, F_all[n])
            # from the latest basis: one until the next exact condensation (a difference
            # quotient in frequency never spans two)
            d = abs(omega - self._interior[n][-1][0])
            estimate = max(estimate, dis * max(d / h, d * d / (3 * h * h)))
            if not estimate <= tol:
                return None
        m, no, nb = self.m, self.structure.obs.size, orders.size
        Zr = np.zeros((nb, m, m), dtype=complex)
        Fr = np.zeros((nb, m), dtype=complex)
        oA = np.zeros((nb, no, m), dtype=complex)
        ob = np.zeros((nb, no), dtype=complex)
        for b, n in enumerate(orders):
            if n == 0:
                Zr_0, lu, Zci, Xo = self.schur(0.0, 0)
                Zr[b], oA[b] = Zr_0, self._obs_rows(Xo)
                Fr[b], xf = self.loads(F_all[0], lu, Zci)
                for j, i in self.obs_i:
                    ob[b, j] = xf[i]
                continue
            near = self._near(omega, int(n), self._interior[int(n)][-1], F_all[n])
            if near is None:
                return None
            Zr[b], Fr[b], (A, x) = near
            oA[b] = self._obs_rows(A)
            for (j, _), v in zip(self.obs_i, x, strict=True):
                ob[b, j] = v
        out = self._result(omega, orders, Zr, Fr, oA, ob, False, frequency)
        out.estimate = estimate  # the declared field (no second validation of the arrays)
        return out

    def _disagreement(self, n: int, Fn) -> tuple[float, float]:
        """``(D, h)``: the relative disagreement ``D`` (the larger of ``Z_r``'s and ``F_r``'s)
        of harmonic ``n``'s two latest local bases (at ``a``, ``b``; ``h = |b - a|`` [rad/s])
        one spacing beyond the later one, at ``2 b - a`` (D infinite when a basis is unusable
        there). An error ``E (w - a)^2`` of each basis (the stationary Galerkin projection)
        makes ``D = 3 |E| h^2``; one linear in the distance, ``E |w - a|`` (the load of a
        damped sector's complex Hermitian blocks, whose adjoint differs from ``X`` by the loss
        factor), ``D = |E| h``: the estimate at a distance ``d`` from the nearer basis is the
        larger, ``D max(d / h, d^2 / (3 h^2))`` (:meth:`nearby`)."""
        (a, *_), (b, *_) = refs = self._interior[n]
        key = ("disagreement", n, a, b)
        out = self._bases.get(key)
        if out is None:
            both = [self._near(2 * b - a, n, r, Fn) for r in refs]
            if any(x is None for x in both):
                out = (math.inf, abs(b - a))
            else:
                (Z1, F1, _), (Z2, F2, _) = both
                out = (max(_rel(Z1, Z2), _rel(F1, F2)), abs(b - a))
            self._bases[key] = out
        return out

    def _near(self, omega: float, n: int, ref, Fn):
        """``(Z_r, F_r, (Xo, xo))`` of harmonic ``n`` at ``omega`` from the local basis of the
        reference ``ref`` (its frequency, interior solutions and load); None when the loads
        changed since or its projected interior matrix is singular there."""
        from fretwear.hb.local_basis import local_basis

        w_a, X, xf, Fi = ref
        if not np.array_equal(Fi, Fn[self.idofs]):
            return None
        basis = self._bases.get((n, w_a))
        if basis is None:
            kept = {(n2, r[0]) for n2, rs in self._interior.items() for r in rs}
            self._bases = {k: v for k, v in self._bases.items()  # those of kept references
                           if k in kept or (k[0] == "disagreement" and k[1:3] in kept)}
            basis = self._bases[(n, w_a)] = local_basis(self, w_a, n, X, xf, Fi)
        try:
            Zcq, Y, yF = basis.blocks(omega)
        except np.linalg.LinAlgError:
            return None
        S = self._z("cc", omega, n, False) - Zcq @ Y
        R = self.R
        return (R @ S @ R.T, R @ (Fn[self.cdofs] - Zcq @ yF),
                (basis.Wo @ Y, basis.Wo @ yF))

    def check_size(self, orders) -> None:
        """Refuse (one InputError with the estimate and the machine's memory) a condensation
        on ``orders`` that cannot fit, before it allocates: per harmonic the condensed
        blocks, the observation rows and the factorisation of ``Z_ii`` kept until all are
        done (dense: ``16 n_i^2`` bytes; sparse: ten times the nonzeros of ``K``, a rough
        fill), the load amplitudes of every order up to the highest, and the Fourier basis
        that the balance needs with it (at least ``2 k + 2`` samples of ``2 k + 1``
        coefficients, four arrays)."""
        orders = np.asarray(orders, dtype=np.int64)
        if not orders.size:
            return
        nb, k = orders.size, int(orders.max())
        m, no, ni = self.m, self.structure.obs.size, self.ni
        lu = 16.0 * ni * ni if self.dense else 160.0 * self.structure.K.nnz
        per_order = 16.0 * (2 * m * m + no * m + no + m) + lu
        basis = 8.0 * (2 * k + 2) * (2 * k + 1) * 4
        require_memory(nb * per_order + 16.0 * (k + 1) * self.structure.ndof + basis,
                       f"a balance of {nb} harmonic orders (up to {k}) on {self.structure.ndof:,}"
                       f" DOFs ({m} at the contact)")

    def load_harmonics(self, nmax: int) -> np.ndarray:
        """The structure's load amplitudes (nmax+1, ndof) complex [N], kept until
        :meth:`read_loads` reads the model's loads again (a sweep condenses the same loads at
        every frequency)."""
        F = self._load_cache.get(nmax)
        if F is None:
            F = np.asarray(self.structure.load_harmonics(nmax))
            F.flags.writeable = False
            self._load_cache = {nmax: F}
        return F

    def _obs_rows(self, Xo):
        """Observation rows ``A`` (.., no, m): ``U_o = A u_loc`` (+ the load part), from the
        rows ``Xo`` (.., len(obs_i), m) of ``Z_ii^-1 Z_ic`` at the interior observed DOFs."""
        A = np.zeros(Xo.shape[:-2] + (self.structure.obs.size, self.m), dtype=complex)
        for j, c in self.obs_c:
            A[..., j, :] = _column(self.R, c)  # U_c = R^T u_loc
        for k, (j, _) in enumerate(self.obs_i):
            A[..., j, :] = -(Xo[..., k, :] @ self.R.T)
        return A

    def _reduced_batched(self, omega: float, orders, F_all):
        """``(Z_r, F_r, obs_A, obs_b)`` of a tiny dense model (``n_i <= BATCH_MAX``) with the
        harmonics ``n >= 1`` condensed together (one batched LAPACK solve): the same eq. 19
        as :meth:`schur` and :meth:`loads`, without their per-harmonic Python work, which
        dominated small sweeps. Harmonic 0 (the kept static condensation) and the load
        blocks do not depend on the frequency and are prepared once per ``orders``. None
        when a ``Z_ii`` is (nearly) singular: the per-harmonic path then says why."""
        m = self.m
        key = ("batched", orders.tobytes())
        prep = self._load_cache.get(key)
        if prep is None:
            prep = self._load_cache[key] = self._batched_prep(orders, F_all)
        dyn, n_dyn, Fc, Fi_eye, Zr, Fr, oA, ob = prep
        Zr, Fr, oA, ob = Zr.copy(), Fr.copy(), oA.copy(), ob.copy()
        w = n_dyn * omega
        R = self.R

        def block(part):
            Z = getattr(self.K, part) - (w * w)[:, None, None] * getattr(self.M, part)
            if self.D is not None:
                Z = Z + 1j * getattr(self.D, part)
            if self.C is not None:
                Z = Z + (1j * w)[:, None, None] * getattr(self.C, part)
            return Z.astype(complex, copy=False)

        S = block("cc")
        if self.ni:
            Zii = block("ii")
            Zci = block("ci")
            try:  # [Z_ii^-1 Z_ic, Z_ii^-1 F_i, Z_ii^-1]
                X = np.linalg.solve(Zii, np.concatenate([block("ic"), Fi_eye], axis=2))
            except np.linalg.LinAlgError:
                return None
            inv = X[:, :, m + 1:]  # condition number (1-norm) beyond 1e13: nearly singular
            cond = (np.abs(Zii).sum(axis=1).max(axis=1) * np.abs(inv).sum(axis=1).max(axis=1))
            if not (np.all(np.isfinite(cond)) and np.all(cond < 1e13)):
                return None
            S = S - Zci @ X[:, :, :m]
            Fc = Fc - (Zci @ X[:, :, m:])[:, :, 0]
            rows = np.array([i for _, i in self.obs_i], dtype=np.int64)
            oA[dyn] = self._obs_rows(X[:, rows, :m])
            ob[np.ix_(dyn, [j for j, _ in self.obs_i])] = X[:, rows, m]
        Zr[dyn] = R @ S @ R.T
        Fr[dyn] = Fc @ R.T
        return Zr, Fr, oA, ob

    def _batched_prep(self, orders, F_all):
        """What :meth:`_reduced_batched` reuses at every frequency for ``orders``: the
        dynamic harmonics, their loads on the contact and interior DOFs (the latter with the
        identity beside them: the batched solve also gives ``Z_ii^-1``), and the arrays of
        the result with harmonic 0 (and the observation rows without interior DOFs) filled."""
        m, no, nb = self.m, self.structure.obs.size, orders.size
        dyn = np.flatnonzero(orders > 0)
        Fd = F_all[orders[dyn]]
        Zr = np.zeros((nb, m, m), dtype=complex)
        Fr = np.zeros((nb, m), dtype=complex)
        oA = np.zeros((nb, no, m), dtype=complex)
        ob = np.zeros((nb, no), dtype=complex)
        if not self.ni:
            oA[dyn] = self._obs_rows(np.zeros((dyn.size, 0, m)))
        for b in np.flatnonzero(orders == 0):  # the static condensation
            Zr_0, lu, Zci, Xo = self.schur(0.0, 0)
            Zr[b] = Zr_0
            oA[b] = self._obs_rows(Xo)
            Fr[b], xf = self.loads(F_all[0], lu, Zci)
            for j, i in self.obs_i:
                ob[b, j] = xf[i]
        Fi_eye = np.concatenate([Fd[:, self.idofs, None],
                                 np.eye(self.ni)[None].repeat(dyn.size, axis=0)], axis=2)
        return dyn, orders[dyn].astype(float), Fd[:, self.cdofs], Fi_eye, Zr, Fr, oA, ob

    def _result(self, omega, orders, Zr, Fr, oA, ob, quasi_static, frequency) -> Reduced:
        """The :class:`Reduced` model, its observed rows mapped back from the relative
        coordinates of node-to-node pairs (``U[obs_out] = S U'[obs]``)."""
        S = self.structure.S
        if S is not None:
            oA = np.einsum("oj,bjm->bom", S.toarray(), oA)
            ob = ob @ S.toarray().T
        return Reduced(float(omega), orders, Zr, Fr, oA, ob, self.structure.obs_out,
                       bool(quasi_static), math.nan if frequency is None else float(frequency))

    def recover(self, omega: float, orders, u_loc, quasi_static: bool = False) -> np.ndarray:
        """All DOFs ``U_n`` (nb, ndof) complex [m] from ``u_loc`` (nb, m):
        ``U_i = Z_ii^-1 (F_i - Z_ic U_c)``; fixed DOFs are zero."""
        orders = np.asarray(orders, dtype=np.int64)
        F_all = self.structure.load_harmonics(int(orders.max()) if orders.size else 0)
        out = np.zeros((orders.size, self.structure.ndof), dtype=complex)
        for b, n in enumerate(orders):
            Uc = self.R.T @ np.asarray(u_loc[b], dtype=complex)
            out[b, self.cdofs] = Uc
            if self.ni:
                lu = self.factor(omega, int(n), quasi_static)
                rhs = F_all[n][self.idofs] - self._z("ic", omega, int(n), quasi_static) @ Uc
                out[b, self.idofs] = _solve(lu, rhs)
        P = self.structure.P
        return out if P is None else (P @ out.T).T


def _rel(a, b) -> float:
    """``|a - b| / |b|`` (Frobenius; 0 for two zero arrays)."""
    nb = np.linalg.norm(b)
    d = np.linalg.norm(a - b)
    return float(d / nb) if nb > 0 else (0.0 if d == 0 else math.inf)


def _solve(lu, B):
    """``Z_ii^-1 B`` with a factorisation of :func:`_factor`; a real LU (the static one)
    solves a complex ``B`` by its real and imaginary parts."""
    if not isinstance(lu, _DenseLU):
        return lu.solve(B)  # sparse_lu: a real factorisation solves a complex B by parts
    cplx = lu.lu[0].dtype.kind == "c"
    if cplx or B.dtype.kind != "c":
        return lu.solve(B)
    if not np.any(B.imag):
        return lu.solve(np.ascontiguousarray(B.real)).astype(complex)
    return lu.solve(np.ascontiguousarray(B.real)) + 1j * lu.solve(np.ascontiguousarray(B.imag))


@model_argument
def exact_condenser(model: Model) -> Condenser:
    """A new exact :class:`Condenser` of ``model`` (eq. 19): build it once and pass it
    (``condenser=``) to every condensation, solve, sweep or wear run of this model, which then
    share its prepared blocks and kept factorisations. It refuses another model, or this one
    after an edit of its matrices (:meth:`Condenser.check`); the loads are read at each use."""
    return Condenser(_structure(model))


def condenser_for(model: Model, condenser=None):
    """The condenser a driver uses for ``model``: ``condenser`` checked against ``model``
    (:meth:`Condenser.check`, which also reads the model's current loads), or, when None, a
    new exact one (:func:`exact_condenser`)."""
    if condenser is None:
        return exact_condenser(model)
    if not callable(getattr(condenser, "check", None)):
        raise InputError(f"condenser = {type(condenser).__name__} object: expected a condenser "
                         "(fretwear.exact_condenser(model) or fretwear.modal_condenser(model, "
                         "f_max, max_order)) or None")
    condenser.check(model)
    return condenser


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
    _cond: Condenser
    _lu: object
    _Kci: object

    @property
    def _P(self):
        """``U = P U'`` for node-to-node pairs (model.interfaces), None without."""
        return self._cond.structure.P

    def loads(self, F) -> np.ndarray:
        """Condensed loads ``F_r`` (..., m) [N] of load vectors ``F`` (..., ndof) [N]."""
        F = np.asarray(F, dtype=float)
        if self._P is not None:
            F = (self._P.T @ F.reshape(-1, F.shape[-1]).T).T.reshape(F.shape)
        cols = F.reshape(-1, F.shape[-1]).T  # one load per column
        Fr, _ = self._cond.loads(cols, self._lu, self._Kci)
        return Fr.T.reshape(F.shape[:-1] + (self._cond.m,))

    def recover(self, u_loc, F) -> np.ndarray:
        """All DOFs ``U`` (ndof,) [m] from the local contact displacements ``u_loc`` (m,) under
        the load ``F`` (ndof,): ``U_i = K_ii^-1 (F_i - K_ic U_c)``; fixed DOFs are zero."""
        c = self._cond
        U = np.zeros(c.structure.ndof)
        Uc = c.R.T @ np.asarray(u_loc, dtype=float)
        U[c.cdofs] = Uc
        F = np.asarray(F, float)
        if self._P is not None:
            F = self._P.T @ F
        if self._lu is not None:
            U[c.idofs] = self._lu.solve(F[c.idofs] - c.K.ic @ Uc)
        return U if self._P is None else self._P @ U


def condense_static(model: Model, *, condenser=None) -> StaticCondensation:
    """Exact static condensation of ``model`` onto its contact DOFs (eq. 19 with ``Z = K``).

    The same computation as :func:`condense` (:meth:`Condenser.schur`), in real arithmetic,
    with the condensed loads of any load vectors (e.g. the loads at the phases of a
    quasi-static cycle) and the exact recovery of every DOF. ``condenser``: the condenser of
    ``model`` (:func:`exact_condenser`; None: a new one for this call).
    """
    cond = condenser_for(model, condenser)
    Kr, lu, Kci, _ = cond.schur(0.0, 0, True)
    return StaticCondensation(np.ascontiguousarray(0.5 * (Kr + Kr.T)), cond, lu, Kci)


@model_argument
def whole_orders(orders) -> np.ndarray:
    """``orders`` as an int64 array after checking it holds distinct whole numbers in
    ``[0, 2^62]``, at least one (an InputError naming ``orders`` otherwise)."""
    if isinstance(orders, str | bytes):
        raise InputError(f"orders = {orders!r}; expected harmonic orders (whole numbers >= 0)")
    try:
        a = np.asarray(orders)
    except (TypeError, ValueError):
        raise InputError("orders: expected a list of harmonic orders") from None
    if a.ndim != 1 or not a.size or a.dtype.kind not in "iu" or np.any(a < 0) or np.any(
            a > 2**62) or np.unique(a).size != a.size:
        raise InputError(f"orders = {orders!r}; expected distinct harmonic orders, whole "
                         "numbers >= 0, at least one (e.g. [0, 1, 2, 3])")
    return a.astype(np.int64)


def condense(model: Model, frequency: float, orders, *, quasi_static: bool = False,
             condenser=None) -> Reduced:
    """Condense ``model`` onto its contact DOFs for harmonic ``orders`` (``[0, h1, .., hk]``)
    at the excitation ``frequency`` [Hz] (0 allowed when ``quasi_static``).

    Implements eq. (17)-(19) with one LU of ``Z_ii`` per harmonic. ``condenser``: the
    condenser of ``model`` (:func:`exact_condenser`, or
    :func:`fretwear.hb.modal.modal_condenser`), which keeps its prepared blocks and
    factorisations between calls; None builds a new exact one for this call alone (build one
    and pass it when condensing the same model more than once). Returns a :class:`Reduced` in
    contact-local coordinates with the observed-DOF recovery rows
    (``Reduced.omega = 2 pi frequency`` [rad/s], ``Reduced.frequency`` as given).
    """
    frequency = number(frequency, "frequency", low=0.0, high=RANGES["frequency"][1], unit="Hz")
    if not (quasi_static or frequency > 0):
        raise InputError("frequency = 0 Hz: expected a frequency > 0 [Hz] (or quasi_static)")
    orders = whole_orders(orders)
    return _condense(model, 2 * np.pi * frequency, orders, quasi_static=quasi_static,
                     frequency=frequency, condenser=condenser)


def _condense(model: Model, omega: float, orders, *, quasi_static: bool = False,
              frequency: float | None = None, condenser=None) -> Reduced:
    """:func:`condense` at the circular frequency ``omega`` [rad/s] (``frequency`` [Hz]:
    recorded in the result, default ``omega / 2 pi``)."""
    return condenser_for(model, condenser).reduced(omega, orders, quasi_static, frequency)


def recover(model: Model, frequency: float, orders, u_loc: np.ndarray, *,
            quasi_static: bool = False, condenser=None) -> np.ndarray:
    """All DOFs ``U_n`` (nb, ndof) complex [m] from the contact-local amplitudes ``u_loc``
    (nb, m) [m] of the harmonic ``orders`` at the excitation ``frequency`` [Hz].

    ``U_i = Z_ii^-1 (F_i - Z_ic U_c)`` per harmonic (exact recovery of the condensation);
    fixed DOFs are zero. ``condenser``: as for :func:`condense` (the one that condensed the
    solution: a modal one recovers through its modes).
    """
    return _recover(model, 2 * np.pi * frequency, orders, u_loc, quasi_static=quasi_static,
                    condenser=condenser)


def _recover(model: Model, omega: float, orders, u_loc: np.ndarray, *,
             quasi_static: bool = False, condenser=None) -> np.ndarray:
    """:func:`recover` at the circular frequency ``omega`` [rad/s]."""
    return condenser_for(model, condenser).recover(omega, orders, u_loc, quasi_static)


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
    view = out.transpose(1, 3, 0, 2)  # (H, H, m, m): the coefficient blocks, every harmonic
    view[0, 0] = Zc[0].real
    ca = np.arange(1, nb)
    cb = ca + k
    zr, zi = Zc[1:].real, Zc[1:].imag
    view[ca, ca] = zr
    view[ca, cb] = zi
    view[cb, ca] = -zi
    view[cb, cb] = zr
    return out.reshape(m * H, m * H)


def loads_to_real(Fc: np.ndarray) -> np.ndarray:
    """Real coefficient array (m, 1+2k) from complex load amplitudes (nb, m)."""
    a0 = Fc[0].real[:, None]
    return np.hstack([a0, Fc[1:].real.T, -Fc[1:].imag.T])
