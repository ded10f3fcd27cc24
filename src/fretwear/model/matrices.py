"""Build a :class:`~fretwear.model.core.Model` from user matrices (any FE code, or by hand).

The user gives ``K`` and ``M`` in their own DOF numbering and says which DOFs are the normal
and tangential DOFs of each contact node. Each contact node's local frame is the identity
on ``[normal, tangential(s)]``, with the sign of the normal DOF flipped when
``normal_sign = -1`` (a *negative* displacement of that DOF closes the gap).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.io
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.limits import RANGES
from fretwear.model.build import Damping
from fretwear.model.core import WAVEFORMS, ContactInterface, Load, Model, ObservedPoint, Segments
from fretwear.model.interfaces import relative_model
from fretwear.model.supports import rigid_motion_check
from fretwear.resources import require_memory
from fretwear.validate import is_real
from fretwear.validate import path as file_path

SYMMETRY_TOL = 1e-9  # max |A - A^T| relative to max |A|


def _matrix(A, what: str, n: int | None = None) -> sp.csr_matrix:
    if A is None:
        raise InputError(f"{what} is None; expected a square real matrix")
    values = A.data if sp.issparse(A) else np.asarray(A)
    if np.iscomplexobj(values):
        raise InputError(f"{what} holds complex values; expected a real matrix (hysteretic "
                         "damping goes in D or loss_factor, not in an imaginary part of K)")
    try:
        A = sp.csr_matrix(A, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{what}: cannot be read as a real matrix ({exc})") from None
    if A.shape[0] != A.shape[1]:
        raise InputError(f"{what} has shape {A.shape}; expected a square matrix")
    if n is not None and A.shape != (n, n):
        raise InputError(f"{what} has shape {A.shape}; expected ({n}, {n}) like K")
    if not np.all(np.isfinite(A.data)):
        raise InputError(f"{what} has non-finite entries (inf or nan)")
    A.eliminate_zeros()
    A.sort_indices()
    return A


def _symmetric(A: sp.csr_matrix, what: str) -> sp.csr_matrix:
    asym = abs(A - A.T).tocoo()
    big = abs(A).max() if A.nnz else 0.0
    if asym.nnz and asym.data.max() > SYMMETRY_TOL * big:
        k = int(np.argmax(asym.data))
        i, j = int(asym.row[k]), int(asym.col[k])
        raise InputError(
            f"{what} is not symmetric: {what}[{i}, {j}] = {float(A[i, j]):g} but {what}[{j}, {i}] "
            f"= {float(A[j, i]):g} (tolerance {SYMMETRY_TOL:g} x max |{what}|); expected a "
            "symmetric matrix"
        )
    S = (0.5 * (A + A.T)).tocsr()
    S.sort_indices()
    if np.any(S.diagonal() < 0.0):
        i = int(np.flatnonzero(S.diagonal() < 0.0)[0])
        raise InputError(f"{what}[{i}, {i}] = {float(S[i, i]):g} < 0; expected a positive "
                         "semi-definite matrix")
    return S


DENSE_INERTIA_LIMIT = 400  # up to this size, dense eigenvalues; above, the sparse LDL^T pivots
# (every from_matrices call checks K, M, C and D: a dense eigvalsh of 2000 DOFs costs seconds)


def _most_negative_eigenvalue(S: sp.csr_matrix) -> float:
    """The smallest eigenvalue of the symmetric ``S`` (dense, or Lanczos for large ones)."""
    if S.shape[0] <= DENSE_INERTIA_LIMIT:
        return float(np.linalg.eigvalsh(S.toarray())[0])
    import scipy.sparse.linalg as spla

    return float(spla.eigsh(S.tocsc(), k=1, which="SA", return_eigenvectors=False,
                            v0=np.random.default_rng(0).standard_normal(S.shape[0]))[0])


def negative_eigenvalues(S: sp.csr_matrix, shift: float) -> int | None:
    """The number of eigenvalues of the symmetric ``S`` below ``-shift`` (``shift >= 0``), or
    None when it cannot be read off a factorisation.

    Sylvester's law of inertia on ``S + shift I = L D L^T``: the number of negative pivots is
    the number of negative eigenvalues. The sparse LU is taken on a symmetric ordering without
    row pivoting (``U = D L^T``); where SuperLU had to pivot anyway (a leading minor is zero)
    the count is not available (None). Small matrices get their eigenvalues densely.
    """
    import scipy.sparse.linalg as spla

    n = S.shape[0]
    A = (S + shift * sp.identity(n, format="csr")).tocsc()
    if n <= DENSE_INERTIA_LIMIT:
        return int(np.sum(np.linalg.eigvalsh(A.toarray()) < 0.0))
    try:
        lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:  # exactly singular
        return None
    if not np.array_equal(lu.perm_r, lu.perm_c):
        return None
    return int(np.sum(lu.U.diagonal() < 0.0))


def check_semidefinite(A: sp.csr_matrix, what: str, rtol: float = 1e-9) -> None:
    """Refuse a matrix whose symmetric part has an eigenvalue below ``-rtol max|A|``: a stiffness
    or mass that can store negative energy, or a damping that feeds energy in."""
    S = (0.5 * (A + A.T)).tocsr()
    big = float(abs(S).max()) if S.nnz else 0.0
    if big == 0.0 or negative_eigenvalues(S, rtol * big) == 0:
        return
    lam = _most_negative_eigenvalue(S)
    if lam >= -rtol * big:  # the count was not available and the eigenvalue says fine
        return
    raise InputError(
        f"{what} is indefinite: its (symmetric part's) smallest eigenvalue is {lam:.4g}, "
        f"below -{rtol:g} x max |{what}| = {-rtol * big:.4g}; expected a positive "
        "semi-definite matrix (no negative energy"
        + (", no energy source)" if what in ("C", "D") else ")"))


def _dofs(values, ndof: int, what: str) -> np.ndarray:
    try:
        a = np.asarray(values)
        ok = a.size == 0 or (np.issubdtype(a.dtype, np.number) and np.all(a == np.round(a)))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise InputError(f"{what} = {values!r}; expected integer DOF indices")
    a = a.astype(np.int64)
    bad = a[(a < 0) | (a >= ndof)]
    if bad.size:
        raise InputError(f"{what}: DOF {int(bad.ravel()[0])} is out of range; expected "
                         f"indices in [0, {ndof - 1}] (the matrices have {ndof} DOFs)")
    return a


def _per_node(value, nc: int, what: str, *, positive=False, signs=False) -> np.ndarray:
    try:
        if isinstance(value, str | bytes) or np.asarray(value).dtype.kind not in "iuf":
            raise ValueError(value)
        a = np.broadcast_to(np.asarray(value, dtype=float), (nc,)).copy()
    except (TypeError, ValueError):
        raise InputError(f"{what} = {value!r}; expected a number or {nc} numbers (one per "
                         "contact node)") from None
    if not np.all(np.isfinite(a)):
        raise InputError(f"{what} = {value!r}; expected finite values")
    if positive and np.any(a <= 0.0):
        raise InputError(f"{what}: {float(a[a <= 0][0]):g}; expected values > 0")
    if signs and not np.all(np.isin(a, (-1.0, 1.0))):
        raise InputError(f"{what} = {value!r}; expected +1 or -1 (scalar or per node)")
    return a


def _bounded(a: np.ndarray, bound: float, what: str) -> np.ndarray:
    """``a`` after checking every magnitude is at most ``bound``."""
    if np.any(np.abs(a) > bound):
        raise InputError(f"{what}: {float(a[np.abs(a) > bound][0]):g}; expected magnitudes <= "
                         f"{bound:g} (larger than any structure)")
    return a


def _nonnegative(value, what: str) -> float:
    if not is_real(value):
        raise InputError(f"{what} = {value!r} is not a number")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} = {value!r} is not a number") from None
    if not np.isfinite(v) or v < 0.0:
        raise InputError(f"{what} = {value!r}; expected a finite value >= 0")
    return v


@dataclass
class ContactDofs:
    """A frictional contact interface on the DOFs of user matrices: the contact record of
    :func:`from_matrices` (as :class:`~fretwear.model.build.ContactSpec` is the record of a
    mesh boundary for :func:`~fretwear.model.build.from_mesh`). Checked by
    :func:`from_matrices`, which knows the number of DOFs; its messages name a field ``f`` of
    the DOFs and frames as ``contact_f``.

    Attributes
    ----------
    normal_dofs : (nc,) int, or None with ``normal_load``
        The normal DOF of each contact node. None: the nodes have no normal DOF in the
        matrices (e.g. a one-DOF oscillator rubbing under a known normal force); their normal
        force is ``normal_load``. A normal DOF held at zero is then added per node (stiffness
        ``max diag K``, no mass, loaded by ``N(t)`` so that it stays at 0), invisible to the
        friction law, which takes ``lambda_N = N(t)``.
    tangential_dofs : (nc,) int (2D) or (nc, 2) int (3D)
        Its tangential DOF(s).
    mu : float
        Coulomb friction coefficient [-] (>= 0).
    gap : float or (nc,)
        Initial normal gap [m] (>= 0 open; negative = initial interference).
    area : float or (nc,)
        Contact area of each node [m^2] (> 0); pressures are forces divided by it.
    normal_sign : +1, -1 or (nc,) of them
        +1 if a positive displacement of the normal DOF closes the gap, else -1.
    frames : (nc, d, d), optional
        Orthonormal rows ``[n, t1(, t2)]`` of each node's frame in the axes of its DOFs
        ``[normal, tangential..]`` (e.g. DOF triplets x, y, z of a node on an inclined
        flank); default: the identity, with ``normal_sign`` on the normal.
    coords : (nc, d), optional
        Positions of the contact nodes [m], for output (zeros if not given).
    wear_coefficient : float
        Archard coefficient k_w [1/Pa].
    name : str
        Label of the contact interface.
    partner_dofs : (nc, d) int, optional
        Node-to-node contact: the DOFs of each contact node's partner on the second body, in
        the order of the node's own DOFs ``[normal, tangential..]`` (the same axes); the law
        acts on the relative displacement, with equal and opposite forces.
    partner_wear_coefficient : float
        Archard coefficient k_w [1/Pa] of the partners' surface (pairs only).
    normal_load : float, (nc,) or Load, optional
        Friction under a prescribed normal load: each node's normal force [N] (a constant, or a
        :class:`~fretwear.model.core.Load` with a (nc,) ``vector`` and a waveform for
        ``N(t)``; NaN entries: unilateral contact at that node). The slip threshold is then
        ``mu N(t)`` and no normal DOF is needed.
    kn, kt : float or (nc,), optional
        Normal and tangential contact stiffness [N/m] (> 0, ``inf`` rigid; default rigid), in
        series with the contact law (:mod:`fretwear.hb.connectors`): a finite ``kt`` is a
        Jenkins element.
    segments : Segments, optional
        Node-to-segment or mortar pairs (non-matching meshes): each node's partner facet
        nodes' DOFs (nc, k, d) and weights (:class:`~fretwear.model.core.Segments`);
        ``partner_dofs`` then holds the DOFs of each node's partner of largest weight.
    """

    normal_dofs: object
    tangential_dofs: object
    mu: float
    gap: object = 0.0
    area: object = 1.0
    normal_sign: object = 1
    frames: object = None
    coords: object = None
    wear_coefficient: float = 0.0
    name: str = "contact"
    partner_dofs: object = None
    partner_wear_coefficient: float = 0.0
    normal_load: object = None
    kn: object = None
    kt: object = None
    segments: object = None


def from_matrices(K, M, *, contact: ContactDofs, damping: Damping | None = None, loads=(),
                  fixed_dofs=(), observed=None, name: str = "matrices") -> Model:
    """A model from stiffness and mass matrices and a list of contact DOFs.

    Parameters
    ----------
    K, M : (n, n) array or scipy.sparse
        Symmetric stiffness [N/m] and mass [kg] (``M`` may be singular, e.g. massless contact
        DOFs). Symmetry is checked to ``1e-9`` relative and then enforced exactly.
    contact : ContactDofs
        The contact nodes: their DOFs, frames, gaps, areas, friction and wear coefficients,
        partners, prescribed normal load and contact stiffness.
    damping : Damping, optional
        :class:`~fretwear.model.build.Damping`: the viscous ``C`` [N s/m] and hysteretic
        ``D`` [N/m] matrices (n, n), the loss factor eta (``D = eta K``, not with ``D``) and
        the Rayleigh factors (``C = a M + b K``, added to ``C``).
    loads : sequence of :class:`~fretwear.model.core.Load` with (n,) vectors [N].
    fixed_dofs : int sequence
        DOFs held at zero (never contact DOFs).
    observed : dict, optional
        name -> DOF index or list of DOF indices.
    name : str
        Label of the model.

    Returns
    -------
    Model
        ``dim`` = 2 or 3 from the number of tangential DOFs; no mesh; ``thickness = 1``.

    Raises
    ------
    InputError
        Bad shapes, asymmetric matrices, indefinite K or M (negative energy), damping C or D
        with an indefinite symmetric part (an energy source), DOFs out of range or repeated,
        contact DOFs fixed, or a stiffness left singular with the contact normal DOFs and
        fixed DOFs held.
    """
    if not isinstance(contact, ContactDofs):
        raise InputError(f"contact = {contact!r}; expected a ContactDofs(normal_dofs, "
                         "tangential_dofs, mu, ...)")
    if damping is not None and not isinstance(damping, Damping):
        raise InputError(f"damping = {damping!r} is not a Damping(...)")
    K = _symmetric(_matrix(K, "K"), "K")
    n_user = K.shape[0]
    M = _symmetric(_matrix(M, "M", n_user), "M")
    check_semidefinite(K, "K")
    check_semidefinite(M, "M")
    K, M, dofs = _contact_dofs(contact, K, M)
    n = K.shape[0]
    fixed = _fixed_dofs(fixed_dofs, n, dofs)
    interface = _interface(contact, dofs, n)
    C, D = _damping(damping, K, M, n_user)
    model = Model(
        K=K,
        M=M,
        contact=interface,
        C=C,
        D=D,
        loads=_padded_loads(_loads(loads, n_user), n_user, contact, interface),
        observed=_observed(observed, n_user),
        fixed_dofs=fixed,
        dim=dofs.shape[1],
        mesh=None,
        thickness=1.0,
        name=str(name),
        meta={"source": "matrices"},
    )
    # each node's normal displacement is held: in the axes of its frame (for pairs in the
    # relative coordinates, where it holds n . (U_a - U_b))
    K_rel = relative_model(model)[0].K
    R = _frame_rotation(dofs, interface.frame, K_rel.shape[0])
    rigid_motion_check((R.T @ K_rel @ R).tocsr(), np.union1d(dofs[:, 0], fixed))
    return model


def _frame_rotation(dofs: np.ndarray, frame: np.ndarray, n: int) -> sp.csr_matrix:
    """``R`` (n, n) with ``U = R V``: on each contact node's DOFs ``V`` holds its local
    displacement ``[u_N, u_T..] = frame @ U[dofs]`` (normal first), elsewhere ``V = U``."""
    nc, d = dofs.shape
    keep = np.ones(n, dtype=bool)
    keep[dofs.ravel()] = False
    rows = np.concatenate([np.flatnonzero(keep), np.repeat(dofs, d, axis=1).ravel()])
    cols = np.concatenate([np.flatnonzero(keep), np.tile(dofs, (1, d)).ravel()])
    # R[dofs_i[a], dofs_i[b]] = frame_i[b, a]: U[dofs_i] = frame_i^T u_loc
    vals = np.concatenate([np.ones(keep.sum()), np.swapaxes(frame, 1, 2).reshape(-1)])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


def _contact_dofs(contact: ContactDofs, K, M):
    """``K, M`` (with a held normal DOF added per node when ``normal_dofs`` is None) and the
    contact DOFs (nc, d) ``[normal, tangential..]`` of every node, checked."""
    n = K.shape[0]
    tang = _dofs(contact.tangential_dofs, n, "contact_tangential_dofs")
    if contact.normal_dofs is None:
        if contact.normal_load is None:
            raise InputError("contact_normal_dofs = None: expected a normal_load (the normal "
                             "force of contact nodes without a normal DOF)")
        nc = tang.shape[0]
        k_pad = float(np.max(np.abs(K.diagonal()))) if K.nnz else 1.0
        K = sp.block_diag([K, sp.identity(nc) * (k_pad or 1.0)], format="csr")
        M = sp.block_diag([M, sp.csr_matrix((nc, nc))], format="csr")
        normal = np.arange(n, n + nc, dtype=np.int64)
    else:
        normal = _dofs(contact.normal_dofs, n, "contact_normal_dofs").reshape(-1)
    nc = normal.size
    if nc == 0:
        raise InputError("contact_normal_dofs is empty; expected at least one contact node")
    if tang.shape == (nc,):
        tang = tang[:, None]
    if tang.ndim != 2 or tang.shape[0] != nc or tang.shape[1] not in (1, 2):
        raise InputError(
            f"contact_tangential_dofs has shape {np.shape(contact.tangential_dofs)}; expected "
            f"({nc},) in 2D or ({nc}, 2) in 3D for {nc} contact normal DOFs"
        )
    dofs = np.column_stack([normal, tang])
    values, counts = np.unique(dofs, return_counts=True)
    if np.any(counts > 1):
        raise InputError(f"contact DOF {int(values[counts > 1][0])} is listed more than once; "
                         "each contact DOF must be distinct")
    return K, M, dofs


def _fixed_dofs(fixed_dofs, n: int, dofs: np.ndarray) -> np.ndarray:
    """The fixed DOFs, checked: in range, listed once, no contact DOF."""
    fixed = _dofs(fixed_dofs, n, "fixed_dofs").reshape(-1)
    values, counts = np.unique(fixed, return_counts=True)
    if np.any(counts > 1):
        raise InputError(f"fixed_dofs lists DOF {int(values[counts > 1][0])} more than once")
    clash = np.intersect1d(fixed, dofs)
    if clash.size:
        raise InputError(f"DOF {int(clash[0])} is both a contact DOF and a fixed DOF; contact "
                         "DOFs cannot be fixed")
    return fixed


def _interface(contact: ContactDofs, dofs: np.ndarray, n: int) -> ContactInterface:
    """The model's :class:`ContactInterface` from the record (every field checked)."""
    nc, dim = dofs.shape
    frame = _frames(contact, nc, dim)
    partner = _partner(contact.partner_dofs, dofs, n, contact.segments)
    if contact.coords is None:
        xyz = np.zeros((nc, dim))
    else:
        xyz = np.asarray(contact.coords, dtype=float)
        if xyz.shape != (nc, dim) or not np.all(np.isfinite(xyz)):
            raise InputError(f"coords has shape {xyz.shape}; expected ({nc}, {dim}) finite "
                             "positions [m] of the contact nodes")
    interface = ContactInterface(
        dofs=dofs,
        frame=frame,
        gap=_bounded(_per_node(contact.gap, nc, "gap"), RANGES["length"][1], "gap [m]"),
        area=_bounded(_per_node(contact.area, nc, "area", positive=True), 1e10, "area"),
        mu=float(_bounded(np.asarray(_nonnegative(contact.mu, "friction coefficient mu")),
                          1e3, "friction coefficient mu")),
        coords=xyz,
        node_ids=np.full(nc, -1, dtype=np.int64),
        wear_coefficient=_nonnegative(contact.wear_coefficient, "wear_coefficient"),
        name=str(contact.name),
        partner_dofs=partner,
        partner_ids=None if partner is None else np.full(nc, -1, dtype=np.int64),
        partner_wear_coefficient=_nonnegative(contact.partner_wear_coefficient,
                                              "partner_wear_coefficient"),
        normal_load=_normal_load(contact.normal_load, nc),
        kn=_stiffness(contact.kn, nc, "kn"),
        kt=_stiffness(contact.kt, nc, "kt"),
        segments=None if partner is None else contact.segments,
    )
    if contact.normal_dofs is None and np.isnan(interface.normal_load.vector).any():
        raise InputError("normal_load has NaN entries (unilateral nodes) but the nodes have no "
                         "normal DOF (contact_normal_dofs = None)")
    return interface


def _frames(contact: ContactDofs, nc: int, dim: int) -> np.ndarray:
    """Each node's frame (nc, d, d): ``contact.frames`` checked orthonormal, or the identity
    with ``normal_sign`` on the normal."""
    sign = _per_node(contact.normal_sign, nc, "normal_sign", signs=True)
    frame = np.broadcast_to(np.eye(dim), (nc, dim, dim)).copy()
    frame[:, 0, 0] = sign
    if contact.frames is None:
        return frame
    frame = np.asarray(contact.frames, dtype=float)
    if frame.shape != (nc, dim, dim) or not np.all(np.isfinite(frame)):
        raise InputError(f"contact_frames has shape {frame.shape}; expected ({nc}, {dim}, "
                         f"{dim}) finite frames [n, t1(, t2)] of the {nc} contact nodes")
    err = np.abs(frame @ np.swapaxes(frame, 1, 2) - np.eye(dim)).max(axis=(1, 2))
    if np.any(err > 1e-9):
        p = int(np.argmax(err))
        raise InputError(f"contact_frames[{p}] is not orthonormal (rows [n, t1(, t2)] "
                         f"off by {err[p]:.3g})")
    return frame


def _partner(partner_dofs, dofs: np.ndarray, n: int, segments=None) -> np.ndarray | None:
    """The partners' DOFs (nc, d) of node-to-node pairs, checked; None without pairs. With
    ``segments`` (non-matching pairs) the partners (of largest weight) may repeat, and the
    segments' DOFs are checked."""
    if partner_dofs is None:
        return None
    nc, dim = dofs.shape
    partner = _dofs(partner_dofs, n, "contact_partner_dofs")
    if partner.shape != (nc, dim):
        raise InputError(f"contact_partner_dofs has shape {partner.shape}; expected "
                         f"({nc}, {dim}): the DOFs of each node's partner, ordered like "
                         "its own [normal, tangential..]")
    if segments is not None:
        _segments(segments, nc, dim, n, dofs)
        if np.intersect1d(partner, dofs).size:
            raise InputError("contact_partner_dofs: a partner DOF is also a contact DOF; each "
                             "pair has its own two nodes")
        return partner
    clash = np.intersect1d(partner, dofs)
    if clash.size or np.unique(partner).size != partner.size:
        raise InputError("contact_partner_dofs: a partner DOF is also a contact DOF or "
                         "is listed twice; each pair has its own two nodes")
    return partner


def _segments(segments, nc: int, dim: int, n: int, dofs: np.ndarray) -> None:
    """Check the DOFs (nc, k, d) and weights (nc, k) of node-to-segment pairs."""
    if not isinstance(segments, Segments):
        raise InputError(f"contact segments = {segments!r}; expected a Segments(dofs, weights, "
                         "ids)")
    sd = np.asarray(segments.dofs)
    w = np.asarray(segments.weights, dtype=float)
    if sd.ndim != 3 or sd.shape[0] != nc or sd.shape[2] != dim or w.shape != sd.shape[:2]:
        raise InputError(f"contact segments: dofs {sd.shape} and weights {w.shape}; expected "
                         f"({nc}, k, {dim}) and ({nc}, k)")
    used = sd[sd >= 0]
    if np.any(used >= n) or np.intersect1d(used, dofs).size:
        raise InputError("contact segments: a partner DOF out of range or also a contact DOF")
    if not np.allclose(w.sum(axis=1), 1.0, atol=1e-12, rtol=0.0):
        raise InputError("contact segments: the weights of a node do not add up to 1")


def _damping(damping: Damping | None, K: sp.csr_matrix, M: sp.csr_matrix, n_user: int):
    """``C, D`` (n, n) of the model from the user's ``damping``, zero on the added normal DOFs
    (``K, M`` of size n >= n_user)."""
    if damping is None:
        return None, None
    n = K.shape[0]
    pad = sp.csr_matrix((n - n_user, n - n_user))
    C = D = None
    if damping.C is not None:
        C = _matrix(damping.C, "C", n_user)
        check_semidefinite(C, "C")
    if damping.rayleigh_mass > 0.0 or damping.rayleigh_stiffness > 0.0:
        Cr = (damping.rayleigh_mass * M[:n_user, :n_user]
              + damping.rayleigh_stiffness * K[:n_user, :n_user])
        C = _matrix(Cr if C is None else C + Cr, "C")
    if C is not None:
        C = sp.block_diag([C, pad], format="csr")
    if damping.D is not None:
        D = _matrix(damping.D, "D", n_user)
        check_semidefinite(D, "D")
        D = sp.block_diag([D, pad], format="csr")
    elif damping.loss_factor > 0.0:
        D = (damping.loss_factor * K).tocsr()
        if n > n_user:
            D[n_user:, n_user:] = 0.0
            D.eliminate_zeros()
    return C, D


def _normal_load(value, nc: int) -> Load | None:
    """The prescribed normal load of ``from_matrices``: a constant or (nc,) force [N], or a
    :class:`Load` with a (nc,) vector (NaN entries: unilateral nodes)."""
    if value is None:
        return None
    if isinstance(value, Load):
        vec = np.asarray(value.vector, dtype=float)
        if vec.shape != (nc,) or np.isinf(vec).any():
            raise InputError(f"normal_load: vector of shape {vec.shape}; expected ({nc},) normal "
                             "forces [N] (NaN: unilateral contact at that node)")
        if value.waveform not in WAVEFORMS:
            raise InputError(f"normal_load: waveform {value.waveform!r}; expected one of "
                             f"{list(WAVEFORMS)}")
        return Load(vec.copy(), value.waveform, value.coefficients, value.name)
    try:
        vec = np.broadcast_to(np.asarray(value, dtype=float), (nc,)).copy()
    except (TypeError, ValueError):
        raise InputError(f"normal_load = {value!r}; expected a force [N], {nc} forces or a "
                         "Load") from None
    if np.isinf(vec).any():
        raise InputError(f"normal_load = {value!r}; expected finite forces [N]")
    return Load(vec, "constant", None, "normal load")


def _stiffness(value, nc: int, what: str) -> np.ndarray | None:
    """A contact stiffness per node [N/m] (> 0, inf allowed), or None (rigid)."""
    if value is None:
        return None
    try:
        k = np.broadcast_to(np.asarray(value, dtype=float), (nc,)).copy()
    except (TypeError, ValueError):
        raise InputError(f"{what} = {value!r}; expected a stiffness [N/m] or {nc} of "
                         "them") from None
    if np.isnan(k).any() or np.any(k <= 0):
        raise InputError(f"{what} = {value!r}; expected a stiffness > 0 [N/m] (inf: rigid)")
    return k


def _loads(loads, n: int) -> list[Load]:
    out = []
    for load in loads:
        if not isinstance(load, Load):
            raise InputError(f"loads: {load!r} is not a fretwear Load(vector, waveform, ...)")
        vec = np.asarray(load.vector, dtype=float)
        if vec.shape != (n,) or not np.all(np.isfinite(vec)):
            raise InputError(f"load {load.name!r}: vector of shape {vec.shape}; expected ({n},) "
                             "finite nodal forces [N]")
        if load.waveform not in WAVEFORMS:
            raise InputError(f"load {load.name!r}: waveform {load.waveform!r}; expected one of "
                             f"{list(WAVEFORMS)}")
        out.append(Load(vec.copy(), load.waveform, load.coefficients, load.name))
    return out


def _padded_loads(loads: list[Load], n_user: int, contact: ContactDofs,
                  interface: ContactInterface) -> list[Load]:
    """The loads on the normal DOFs added for a prescribed normal load (``normal_dofs`` None):
    zero there, and the load ``N(t)`` on them so that they stay at 0."""
    if contact.normal_dofs is not None:
        return loads
    nc = interface.n_nodes
    sign = _per_node(contact.normal_sign, nc, "normal_sign", signs=True)
    out = [Load(np.concatenate([ld.vector, np.zeros(nc)]), ld.waveform, ld.coefficients,
                ld.name) for ld in loads]
    nl = interface.normal_load
    out.append(Load(np.concatenate([np.zeros(n_user), sign * nl.vector]), nl.waveform,
                    nl.coefficients, "normal load"))
    return out


def _observed(observed, n: int) -> list[ObservedPoint]:
    if observed is None:
        return []
    if not isinstance(observed, dict):
        raise InputError(f"observed = {observed!r}; expected a dict name -> DOF index or list "
                         "of DOF indices")
    out = []
    for key, dofs in observed.items():
        d = _dofs(dofs, n, f"observed {key!r}").reshape(-1)
        if d.size == 0:
            raise InputError(f"observed {key!r} lists no DOF")
        out.append(ObservedPoint(str(key), d, np.zeros(d.size)))
    return out


def read_matrix_market(path, *, shape: tuple | None = None):
    """Read a Matrix Market file (``scipy.io.mmread``).

    Parameters
    ----------
    path : str or Path
    shape : tuple, optional
        Expected shape: ``(n, n)`` for a matrix, ``(n,)`` for a vector.

    Returns
    -------
    scipy.sparse.csr_matrix or (n,) float array
        A single row or column is returned as a dense vector; anything else as a sparse
        matrix.

    Raises
    ------
    InputError
        Missing or malformed file, a pattern-only file (no values), complex entries, a
        shape other than ``shape``, or a size that cannot fit in memory (checked from the
        header before reading).
    """
    path = file_path(path, "path")
    if not path.is_file():
        raise InputError(f"Matrix Market file {str(path)!r} does not exist")
    try:
        rows, cols, entries, fmt, field, symmetry = scipy.io.mminfo(str(path))
    except Exception as exc:  # scipy raises ValueError, IndexError, ... on bad headers
        raise InputError(f"cannot read Matrix Market file {str(path)!r}: {exc}") from None
    if field == "pattern":
        raise InputError(f"Matrix Market file {str(path)!r} holds a pattern only (no values); "
                         "expected real values")
    if shape is not None and (len(shape) == 2 and (rows, cols) != tuple(shape)
                              or len(shape) == 1 and rows * cols != shape[0]):
        raise InputError(f"Matrix Market file {str(path)!r} holds shape {(rows, cols)}; "
                         f"expected {tuple(shape)}")
    stored = rows * cols if fmt == "array" else entries * (2 if symmetry != "general" else 1)
    # values and indices as read, then as CSR (values, column indices, row pointers)
    require_memory(40.0 * stored + 16.0 * (rows + 1),
                   f"Matrix Market file {str(path)!r} ({rows} x {cols}, {stored} values)")
    try:
        A = scipy.io.mmread(str(path))
    except Exception as exc:  # scipy raises ValueError, IndexError, ... on bad files
        raise InputError(f"cannot read Matrix Market file {str(path)!r}: {exc}") from None
    if np.iscomplexobj(A.data if sp.issparse(A) else A):
        raise InputError(f"Matrix Market file {str(path)!r} holds complex values; expected "
                         "real ones")
    if 1 in A.shape:
        out = np.asarray(A.toarray() if sp.issparse(A) else A, dtype=float).reshape(-1)
    else:
        out = sp.csr_matrix(A, dtype=float)
    if shape is not None and tuple(out.shape) != tuple(shape):
        raise InputError(f"Matrix Market file {str(path)!r} holds shape {out.shape}; expected "
                         f"{tuple(shape)}")
    return out
