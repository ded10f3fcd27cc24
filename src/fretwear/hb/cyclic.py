"""The condensation of one sector of a tuned disk under an engine-order excitation, and its
linear analyses (cyclic modes, forced response), harmonic index by harmonic index.

Temporal harmonic ``n`` of a travelling wave of engine order ``EO`` lives in the harmonic
index ``k = n EO mod N`` (Petrov, ASME J. Eng. Gas Turbines Power 126, 2004;
:mod:`fretwear.model.cyclic`): with ``U = T_k q`` (the right boundary the left one turned and
phased by ``e^{i k 2 pi / N}``) the sector's dynamic stiffness of harmonic ``n`` is the
complex Hermitian (for ``K``, ``M``; ``i`` times Hermitian for the damping)

    Z_k(n w) = T_k^H (K + i D - (n w)^2 M + i n w C) T_k,      F_k,n = T_k^H F_n,

and the condensation on the contact DOFs (eq. 19) is the one of :mod:`fretwear.hb.reduce` on
that model: :class:`CyclicCondenser` keeps one exact :class:`~fretwear.hb.reduce.Condenser` per
harmonic index and gives each temporal harmonic the one of its index. The contact of the
sector then sees its own motion, ``u(t) = Re sum_n U_n e^{i n w t}`` (real: the balance's
cos/sin blocks of a complex ``Z_r``, :func:`fretwear.hb.reduce.to_real_blocks`, hold for any
complex block), so the periodic solve, sweeps and wear run on the sector unchanged.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fretwear.errors import InputError
from fretwear.hb.reduce import Condenser, Reduced, Structure, _fingerprint
from fretwear.model.checks import model_argument, whole_number
from fretwear.model.core import Model
from fretwear.model.cyclic import (
    CyclicSector,
    harmonic_index,
    harmonic_model,
    relative_harmonic_model,
)
from fretwear.model.interfaces import observed_map
from fretwear.resources import require_memory
from fretwear.threads import limited
from fretwear.validate import reals

#: at most this many kept DOFs: cyclic modes by a dense Hermitian eigensolver
DENSE_MODES = 600


def _engine_order(engine_order) -> int:
    """An integer (negative: the wave travelling the other way)."""
    return whole_number(engine_order, "engine_order")


def _structure_k(sector: CyclicSector, k: int) -> tuple[Structure, sp.csr_matrix]:
    """The :class:`~fretwear.hb.reduce.Structure` of harmonic index ``k`` (complex matrices
    allowed, in the relative coordinates of its pairs, inter-blade ones phased) and its
    ``T_k``; the loads are set by :meth:`CyclicCondenser.read_loads`."""
    rel, T, P = relative_harmonic_model(sector, k)
    obs_out, obs, S = observed_map(rel, P)
    return Structure(
        K=sp.csr_matrix(rel.K), M=sp.csr_matrix(rel.M),
        C=None if rel.C is None else sp.csr_matrix(rel.C),
        D=None if rel.D is None else sp.csr_matrix(rel.D),
        load_harmonics=None, fixed=np.asarray(rel.fixed_dofs, dtype=np.int64),
        cdofs=np.asarray(rel.contact.dofs, dtype=np.int64).reshape(-1),
        frame=np.asarray(rel.contact.frame, dtype=float), obs=np.asarray(obs, np.int64),
        load_vectors=[], P=P, obs_out=np.asarray(obs_out, np.int64), S=S,
        fingerprint=None), T


class CyclicCondenser(Condenser):
    """The exact condensation of one sector under a travelling wave of ``engine_order``
    (module docstring), with the interface of :class:`~fretwear.hb.reduce.Condenser`: its own
    blocks are those of harmonic index 0 (the static condensation, the preload); harmonic
    ``n`` is condensed by the condenser of ``k = n EO mod N``. Contact and observed nodes
    must not lie on the right cyclic boundary (it is the next sector's left one). Recovery
    gives the sector's DOFs (right boundary included). Made by :func:`cyclic_condenser`.

    The time-domain fallback integrates the model it is given, which for a sector lacks its
    cyclic boundaries: ``models_in_time = False`` tells the periodic solve, the sweep and the
    wear run to go without it. The static condensation with load vectors
    (:func:`~fretwear.hb.reduce.condense_static`: quasi-static time stepping) is refused."""

    #: the drivers' time-domain fallback does not model the sector's cyclic boundaries
    models_in_time = False

    def __init__(self, sector: CyclicSector, engine_order: int, dense: bool | None = None):
        self.sector = sector
        self.engine_order = _engine_order(engine_order)
        self._keep_all = False  # keep_interior: every index's, new ones too
        self._dense = dense
        self._fp = _fingerprint(sector.model)
        self._subs: dict[int, tuple[Condenser, sp.csr_matrix]] = {}
        structure, T = _structure_k(sector, 0)
        super().__init__(structure, dense)
        self._subs[0] = (self, T)
        self.read_loads(sector.model)

    def index(self, n) -> np.ndarray:
        """The harmonic index of temporal harmonic(s) ``n``."""
        return harmonic_index(n, self.engine_order, self.sector.n_sectors)

    def _sub(self, k: int) -> tuple[Condenser, sp.csr_matrix]:
        if k not in self._subs:
            structure, T = _structure_k(self.sector, k)
            cond = Condenser(structure, self._dense)
            self._subs[k] = (cond, T)
            self._set_loads(cond, T)
            if self._keep_all:
                cond.keep_interior()
        return self._subs[k]

    def _set_loads(self, cond: Condenser, T: sp.csr_matrix) -> None:
        model = self._loads_of  # the loads of the model last checked (read at each use)
        Th = T.conj().T.tocsr()
        P = cond.structure.P
        Pt = None if P is None else P.conj().T.tocsr()  # P^H: complex for inter-blade pairs

        def harmonics(nmax):
            F = (Th @ model.load_harmonics(nmax).T)
            return (F if Pt is None else Pt @ F).T

        cond.structure.load_harmonics = harmonics
        vecs = [Th @ np.asarray(ld.vector, dtype=float) for ld in model.loads]
        cond.structure.load_vectors = vecs if Pt is None else [Pt @ v for v in vecs]
        cond._load_cache = {}

    # -- the Condenser interface --------------------------------------------------------------
    def loads(self, F, lu, Zci):
        """Eq. 19's loads on harmonic index 0's DOFs; load vectors of the sector's own DOFs
        (:func:`~fretwear.hb.reduce.condense_static`) are refused."""
        if np.shape(F)[0] != self.structure.ndof:
            raise InputError("cyclic condenser: the static condensation of load vectors "
                             "(condense_static, quasi-static time stepping, incremental wear) "
                             "is not available on a sector; use condense / solve_periodic")
        return super().loads(F, lu, Zci)

    def check(self, model: Model) -> CyclicCondenser:
        if _fingerprint(model) != self._fp:  # the matrices (by identity), DOFs, frames
            raise InputError("condenser: this cyclic condenser was built for another sector "
                             "model, or for this one before its matrices, fixed DOFs, contact "
                             "DOFs, frames or observed points changed; build one for it "
                             "(fretwear.hb.cyclic.cyclic_condenser(sector, engine_order))")
        self.read_loads(model)
        return self

    def read_loads(self, model: Model) -> None:
        """Read the loads of ``model`` (the sector's, same matrices) for every index."""
        self._loads_of = model
        for cond, T in self._subs.values():
            self._set_loads(cond, T)

    def reduced(self, omega: float, orders, quasi_static: bool = False,
                frequency: float | None = None) -> Reduced:
        """The sector's :class:`~fretwear.hb.reduce.Reduced` model on ``orders`` at ``omega``
        [rad/s]: harmonic ``n``'s blocks from harmonic index ``n EO mod N``."""
        orders = np.asarray(orders, dtype=np.int64)
        self.check_size(orders)  # every index's blocks as harmonic index 0's (same sizes)
        return self._by_index("reduced", omega, orders, quasi_static, frequency)

    def _by_index(self, name: str, omega: float, orders: np.ndarray, arg,
                  frequency: float | None) -> Reduced | None:
        """The :class:`~fretwear.hb.reduce.Reduced` model on ``orders`` at ``omega`` [rad/s]
        gathered from each harmonic index's condenser's method ``name`` (``"reduced"``: ``arg``
        is ``quasi_static``; ``"nearby"``: ``tol``) on that index's harmonics; None when one
        gives None. Its ``estimate`` (``"nearby"``): the largest of the indices'."""
        ks = self.index(orders)
        m, no, nb = self.m, self.structure.obs.size, orders.size
        Zr = np.zeros((nb, m, m), dtype=complex)
        Fr = np.zeros((nb, m), dtype=complex)
        oA = np.zeros((nb, no, m), dtype=complex)
        ob = np.zeros((nb, no), dtype=complex)
        estimates = []
        for k in np.unique(ks):
            sel = np.flatnonzero(ks == k)
            cond, _ = self._sub(int(k))
            get = getattr(super(), name) if cond is self else getattr(cond, name)
            r = get(omega, orders[sel], arg, frequency)
            if r is None:
                return None
            Zr[sel], Fr[sel], oA[sel], ob[sel] = r.Z, r.F, r.obs_A, r.obs_b
            if r.estimate is not None:
                estimates.append(r.estimate)
        obs_dofs = (np.concatenate([np.asarray(p.dofs, np.int64)
                                    for p in self.sector.model.observed])
                    if self.sector.model.observed else np.zeros(0, np.int64))
        quasi_static = name == "reduced" and bool(arg)
        return Reduced(float(omega), orders, Zr, Fr, oA, ob, obs_dofs, quasi_static,
                       math.nan if frequency is None else float(frequency),
                       max(estimates) if estimates else None)

    def keep_interior(self) -> bool:
        """Keep the interior solutions of every harmonic index's latest exact condensation
        (:meth:`~fretwear.hb.reduce.Condenser.keep_interior`), for :meth:`nearby`."""
        self._keep_all = True
        return all([self._keep() if cond is self else cond.keep_interior()
                    for cond, _ in self._subs.values()])

    def nearby(self, omega: float, orders, tol: float, frequency: float | None = None
               ) -> Reduced | None:
        """As :meth:`reduced` from each harmonic index's local bases
        (:meth:`~fretwear.hb.reduce.Condenser.nearby`, with its ``tol`` and ``estimate``);
        None when one gives none."""
        orders = np.asarray(orders, dtype=np.int64)
        return self._by_index("nearby", omega, orders, tol, frequency)

    def recover(self, omega: float, orders, u_loc, quasi_static: bool = False) -> np.ndarray:
        """The sector's DOFs ``U_n`` (nb, ndof) complex [m] from ``u_loc`` (nb, m): each
        harmonic recovered on its index's kept DOFs and expanded by ``T_k``."""
        orders = np.asarray(orders, dtype=np.int64)
        out = np.zeros((orders.size, self.sector.model.ndof), dtype=complex)
        for b, n in enumerate(orders):
            cond, T = self._sub(int(self.index(n)))
            get = super().recover if cond is self else cond.recover
            q = get(omega, [int(n)], np.asarray(u_loc)[b:b + 1], quasi_static)[0]
            out[b] = T @ q
        return out


@model_argument
def cyclic_condenser(sector: CyclicSector, engine_order: int) -> CyclicCondenser:
    """A :class:`CyclicCondenser` of ``sector`` under the engine order ``engine_order``: pass
    it as ``condenser=`` with ``sector.model`` to any periodic solve, sweep or wear run."""
    return CyclicCondenser(sector, engine_order)


@model_argument
@limited
def cyclic_modes(sector: CyclicSector, k: int, n_modes: int = 6) -> tuple[np.ndarray,
                                                                          np.ndarray]:
    """The ``n_modes`` lowest modes of harmonic index (nodal diameter) ``k`` of the disk,
    contact free: ``(frequencies [Hz], shapes (n_modes, ndof) complex on the sector's DOFs,
    right boundary included)``. The eigenproblem ``T_k^H K T_k x = w^2 T_k^H M T_k x`` is
    complex Hermitian (real for ``k = 0`` and ``N/2``); indices ``k`` and ``N - k`` share their
    frequencies (the two travelling directions of one standing family)."""
    if isinstance(k, bool) or not isinstance(k, int | np.integer) or not \
            0 <= k < sector.n_sectors:
        raise InputError(f"k = {k!r}: expected a harmonic index 0..{sector.n_sectors - 1}")
    n_modes = whole_number(n_modes, "n_modes", low=1)
    red, T = harmonic_model(sector, int(k))
    free = red.free_dofs()
    K = red.K.tocsr()[free][:, free]
    M = red.M.tocsr()[free][:, free]
    n_modes = min(int(n_modes), free.size)
    # the complex Lanczos basis (2 k + 1 vectors), the modes and their expansion to the
    # sector's DOFs, and the dense work arrays
    require_memory(16.0 * (free.size * (2 * n_modes + 1) + 3 * red.ndof * n_modes)
                   + 48.0 * (2 * n_modes + 1) ** 2,
                   f"{n_modes:,} modes of harmonic index {k} of a sector of {red.ndof:,} DOFs")
    if M.nnz == 0 or not np.any(M.diagonal()):
        raise InputError("cyclic modes: the sector has no mass (material.rho = 0 or a zero mass "
                         "matrix); modes need a mass")
    try:
        if free.size <= DENSE_MODES:
            w2, X = sla.eigh(K.toarray(), M.toarray(), subset_by_index=[0, n_modes - 1])
        else:
            w2, X = spla.eigsh(K.tocsc(), n_modes, M.tocsc(), sigma=0.0, which="LM",
                               v0=np.random.default_rng(0).standard_normal(K.shape[0]))
            order = np.argsort(w2)
            w2, X = w2[order], X[:, order]
    except (np.linalg.LinAlgError, RuntimeError) as exc:  # (ARPACK's errors are RuntimeErrors)
        raise InputError(f"cyclic modes of harmonic index {k}: the eigenproblem is singular "
                         "(a DOF without mass, or a motion with neither stiffness nor mass): "
                         "give every DOF a mass (material.rho > 0) and hold the sector") from exc
    q = np.zeros((red.ndof, n_modes), dtype=complex)
    q[free] = X
    return np.sqrt(np.maximum(w2, 0.0)) / (2 * np.pi), (T @ q).T


@model_argument
@limited
def cyclic_frf(sector: CyclicSector, engine_order: int, frequencies) -> np.ndarray:
    """Linear response of the sector to the engine-order excitation, contact free:
    ``U_1`` (nf, ndof) complex [m] on the sector's DOFs at each excitation frequency [Hz]
    (the first harmonic of the loads; index ``k = EO mod N``): ``T_k (Z_k)^-1 T_k^H F_1``."""
    eo = _engine_order(engine_order)
    frequencies = np.atleast_1d(reals(frequencies, "frequencies", low=0.0))
    require_memory(16.0 * frequencies.size * sector.model.ndof,
                   f"a sector FRF of {frequencies.size:,} frequencies on "
                   f"{sector.model.ndof:,} DOFs")
    k = int(harmonic_index(1, eo, sector.n_sectors))
    red, T = harmonic_model(sector, k)
    free = red.free_dofs()
    F = (T.conj().T @ sector.model.load_harmonics(1)[1])[free]
    K, M = red.K.tocsc()[free][:, free], red.M.tocsc()[free][:, free]
    C = None if red.C is None else red.C.tocsc()[free][:, free]
    D = None if red.D is None else red.D.tocsc()[free][:, free]
    out = np.zeros((np.size(frequencies), sector.model.ndof), dtype=complex)
    for i, f in enumerate(np.atleast_1d(np.asarray(frequencies, float))):
        w = 2 * np.pi * f
        Z = K.astype(complex) - w * w * M
        if D is not None:
            Z = Z + 1j * D
        if C is not None:
            Z = Z + 1j * w * C
        q = np.zeros(red.ndof, dtype=complex)
        q[free] = spla.spsolve(Z.tocsc(), F)
        out[i] = T @ q
    return out
