"""Craig-Bampton superelements: the boundary DOFs of the FE model (the contact and observed
nodes) kept as they are, the interior DOFs replaced by their static response to the boundary
plus a few fixed-interface modes (Craig and Bampton 1968).

``U = T q``, ``q = [U_b, eta]``, ``T = [[I, 0], [Psi, Phi]]`` with ``Psi = -K_ii^-1 K_ib`` the
constraint modes and ``Phi`` the interior modes of ``(K_ii, M_ii)`` (mass-normalised), and the
superelement's matrices ``T^T K T``, ``T^T M T`` (and ``T^T C T``, ``T^T D T``, loads
``T^T F``). With every interior mode kept ``T`` is square and invertible: the superelement is
the model itself in other coordinates (same modes, same responses, to rounding). Truncated, it
is exact for static loads on the boundary and its modes converge from above as modes are added.

Superelements exported by the FE codes (Nastran DMIG ``KAAX``/``MAAX`` with modal scalar
points, Abaqus ``*SUBSTRUCTURE MATRIX OUTPUT`` with generalized DOFs) are read as any matrices
(:mod:`fretwear.model.readers`); :func:`craig_bampton` builds one from full matrices.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fretwear.errors import InputError
from fretwear.model.readers.dofmap import DofMap, FEMatrices

DENSE_MODES_LIMIT = 2000  # interior sizes up to which all modes may be asked for (dense eigh)


@dataclass
class Superelement:
    """A Craig-Bampton superelement.

    Attributes
    ----------
    fe : the superelement's matrices: the boundary DOFs (their node ids and components) then
        the modal coordinates (scalar points, component 0, ids ``modal_ids``).
    T : (n_kept, nb + nm) the transformation ``U[kept] = T q``.
    kept : (n_kept,) rows of the full matrices that ``T`` spans (all but the fixed ones).
    frequencies_hz : (nm,) the fixed-interface natural frequencies [Hz] of the kept modes.
    """

    fe: FEMatrices
    T: np.ndarray
    kept: np.ndarray
    frequencies_hz: np.ndarray

    def reduce(self, vector) -> np.ndarray:
        """A load vector (n,) on the full rows as generalised forces ``T^T F`` [N]."""
        v = np.asarray(vector, dtype=float)
        return self.T.T @ v[self.kept]

    def expand(self, q) -> np.ndarray:
        """Displacements on the kept full rows ``T q`` from superelement coordinates."""
        return self.T @ np.asarray(q)


def craig_bampton(fe: FEMatrices, boundary, *, n_modes: int | None = None, fixed=(),
                  first_modal_id: int | None = None) -> Superelement:
    """The Craig-Bampton superelement of ``fe`` on the nodes ``boundary``.

    Parameters
    ----------
    fe : full matrices with their DOF map.
    boundary : node ids whose DOFs (all their components) are kept: the contact nodes and
        their partners, observed nodes, loaded nodes whose loads must stay exact.
    n_modes : number of fixed-interface modes kept (None: all, exact; dense above a few
        thousand interior DOFs is refused).
    fixed : rows of ``fe`` held at zero (removed before the reduction).
    first_modal_id : scalar-point id of the first modal coordinate (default: the largest node
        id + 1).
    """
    b_ids = np.unique(np.asarray(boundary, dtype=np.int64).reshape(-1))
    missing = np.setdiff1d(b_ids, fe.dofs.node)
    if missing.size:
        raise InputError(f"boundary: node {int(missing[0])} is not in the matrices' DOF map; "
                         "expected node ids of the model")
    n = fe.dofs.size
    keep = np.ones(n, dtype=bool)
    keep[np.asarray(fixed, dtype=np.int64)] = False
    kept = np.flatnonzero(keep)
    is_b = np.isin(fe.dofs.node[kept], b_ids)
    b, i = kept[is_b], kept[~is_b]
    K, M = fe.K.tocsr(), fe.M.tocsr()
    Kii, Kib = K[i][:, i].tocsc(), K[i][:, b]
    Mii = M[i][:, i]
    ni = i.size
    nm = ni if n_modes is None else int(n_modes)
    if not 0 <= nm <= ni:
        raise InputError(f"n_modes = {n_modes}; expected 0 to {ni} (the interior DOFs)")
    try:
        lu = spla.splu(Kii)
    except RuntimeError:
        raise InputError("craig_bampton: the interior stiffness is singular (the boundary "
                         "and fixed DOFs do not hold the interior); add boundary nodes") from None
    Psi = -lu.solve(Kib.toarray())
    lam, Phi = _interior_modes(Kii, Mii, lu, nm)
    T = np.zeros((kept.size, b.size + nm))
    pos = np.searchsorted(kept, b)
    T[pos, np.arange(b.size)] = 1.0
    ipos = np.searchsorted(kept, i)
    T[ipos, :b.size] = Psi
    T[ipos, b.size:] = Phi
    first = int(fe.dofs.node.max()) + 1 if first_modal_id is None else int(first_modal_id)
    dofs = DofMap(np.concatenate([fe.dofs.node[b], first + np.arange(nm)]),
                  np.concatenate([fe.dofs.component[b], np.zeros(nm, dtype=np.int64)]))
    red = {w: (None if getattr(fe, w) is None else _project(getattr(fe, w), kept, T))
           for w in ("K", "M", "C", "D")}
    out = FEMatrices(red["K"], red["M"], dofs, C=red["C"], D=red["D"],
                     source=f"Craig-Bampton of {fe.source or 'matrices'}")
    return Superelement(out, T, kept, np.sqrt(np.maximum(lam, 0.0)) / (2.0 * np.pi))


def _project(A, kept, T) -> sp.csr_matrix:
    Ak = A.tocsr()[kept][:, kept]
    R = T.T @ (Ak @ T)
    return sp.csr_matrix(0.5 * (R + R.T))


def _interior_modes(Kii, Mii, lu, nm: int):
    """The ``nm`` lowest modes of ``(K_ii, M_ii)``, mass-normalised."""
    ni = Kii.shape[0]
    if nm == 0:
        return np.zeros(0), np.zeros((ni, 0))
    if nm > ni - 2 or ni <= 200:
        if ni > DENSE_MODES_LIMIT:
            raise InputError(f"n_modes = {nm} of {ni} interior DOFs: all modes need a dense "
                             f"eigensolution (up to {DENSE_MODES_LIMIT} interior DOFs); keep "
                             "fewer modes")
        lam, Phi = scipy.linalg.eigh(Kii.toarray(), Mii.toarray())
        return lam[:nm], Phi[:, :nm]
    op = spla.LinearOperator((ni, ni), matvec=lu.solve, dtype=float)
    v0 = np.random.default_rng(0).standard_normal(ni)  # a fixed start: the same modes each run
    lam, Phi = spla.eigsh(Kii, k=nm, M=Mii.tocsc(), sigma=0.0, which="LM", OPinv=op, v0=v0)
    order = np.argsort(lam)
    lam, Phi = lam[order], Phi[:, order]
    Phi /= np.sqrt(np.einsum("ij,ij->j", Phi, Mii @ Phi))
    return lam, Phi
