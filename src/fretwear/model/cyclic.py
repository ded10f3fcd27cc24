"""One sector of a cyclically symmetric structure (a bladed disk) and its harmonic indices.

A disk of ``N`` identical sectors: sector ``j`` is sector 0 turned by ``j alpha``,
``alpha = 2 pi / N``, about an axis (a unit vector through a point). The sector's *left*
boundary turned by ``+alpha`` lands on its *right* boundary, which is the left boundary of
sector 1. Under a travelling wave of engine order ``EO`` (a tuned disk), harmonic ``n`` of
sector ``j`` is that of sector 0 times ``e^{i n EO j alpha}`` (in the sector's own axes);
it lives in the harmonic index (nodal diameter family) ``k = n EO mod N`` and the right
boundary of the sector is then its left one, turned and phased (Petrov, ASME J. Eng. Gas
Turbines Power 126, 2004; Thomas, Int. J. Numer. Meth. Eng. 14, 1979):

    U_right = e^{i k alpha} R U_left,        R: the rotation by alpha of the DOF components.

Keeping every DOF but the right boundary's (``q``), ``U = T_k q`` and the sector's equations
become ``T_k^H Z T_k q = T_k^H F`` (the forces of the neighbour on the left boundary are the
sector's own right-boundary forces, turned back): complex Hermitian matrices per harmonic
index (:func:`harmonic_model`). A negative ``EO`` is the wave travelling the other way.

:func:`whole_disk` assembles the ``N`` sectors (each turned into the disk's axes) with the
loads of the travelling wave: the independent reference of the sector's results.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.build import _contact
from fretwear.model.checks import model_argument, whole_number
from fretwear.model.core import ContactInterface, Load, Model, ObservedPoint
from fretwear.model.interfaces import check_distinct, combine
from fretwear.model.supports import Neighbours, check_supported
from fretwear.resources import require_memory


@dataclass
class CyclicSector:
    """A sector model with its cyclic symmetry (made by :func:`cyclic_sector`).

    model : the sector (its matrices, loads on sector 0, contact, observed points).
    n_sectors : ``N`` (>= 2).
    axis : (3,) unit vector of the rotation axis; point : (3,) a point of the axis [m].
    left_dofs, right_dofs : (nb, d) int, the DOFs of the matched boundary nodes: right node
        ``b`` is left node ``b`` turned by ``+2 pi / N``.
    left_coords, right_coords : (nb, d) their positions [m].
    node_dofs : (nn, d) int, every group of DOFs that turns as a vector (a node's components);
        used to turn a sector into the disk's axes (:func:`whole_disk`).
    rotation : (d, d) the rotation by ``2 pi / N`` of a vector's components.
    neighbour : (nc,) bool, the contact nodes whose partner is in the *next* sector (an
        inter-blade contact, :func:`neighbour_contact`; ``partner_dofs`` then holds the DOFs
        of the partner's image in this sector), or None: every partner in the sector.
    """

    model: Model
    n_sectors: int
    axis: np.ndarray
    point: np.ndarray
    left_dofs: np.ndarray
    right_dofs: np.ndarray
    left_coords: np.ndarray
    right_coords: np.ndarray
    node_dofs: np.ndarray
    rotation: np.ndarray
    neighbour: np.ndarray | None = None

    def neighbour_nodes(self) -> np.ndarray:
        """(nc,) bool: the contact nodes paired with a node of the next sector."""
        if self.neighbour is None:
            return np.zeros(self.model.contact.n_nodes, dtype=bool)
        return np.asarray(self.neighbour, dtype=bool)

    @property
    def angle(self) -> float:
        """The sector angle ``2 pi / N`` [rad]."""
        return 2 * np.pi / self.n_sectors

    @property
    def dim(self) -> int:
        return int(self.left_dofs.shape[1])

    def turn(self, j: int) -> np.ndarray:
        """(d, d) rotation of sector ``j`` (by ``j 2 pi / N``)."""
        return rotation_matrix(self.axis, j * self.angle, self.dim)

    def kept_dofs(self) -> np.ndarray:
        """The DOFs ``q`` of the reduction: every DOF of the sector but the right boundary's."""
        keep = np.ones(self.model.ndof, dtype=bool)
        keep[self.right_dofs.reshape(-1)] = False
        return np.flatnonzero(keep)


def harmonic_index(n, engine_order: int, n_sectors: int):
    """The harmonic index ``k = n EO mod N`` of temporal harmonic ``n`` (int or array)."""
    return np.mod(np.asarray(n, dtype=np.int64) * int(engine_order), int(n_sectors))


def rotation_matrix(axis, angle: float, dim: int) -> np.ndarray:
    """(dim, dim) rotation by ``angle`` [rad] about the unit ``axis`` (3,) (right-hand rule);
    in 2D the axis is ``(0, 0, +-1)`` and the rotation is in the plane."""
    a = np.asarray(axis, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    if dim == 2:
        s = s * np.sign(a[2])
        return np.array([[c, -s], [s, c]])
    K = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + s * K + (1 - c) * (K @ K)


def _axis(axis, point, dim: int) -> tuple[np.ndarray, np.ndarray]:
    try:
        a = np.asarray(axis, dtype=float).reshape(-1)
        p = np.asarray(point, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"axis = {axis!r}, point = {point!r}: expected 3 numbers each") from None
    if a.size != 3 or not np.all(np.isfinite(a)) or abs(np.linalg.norm(a) - 1.0) > 1e-9:
        raise InputError(f"axis = {axis!r}: expected a unit vector of 3 components")
    if dim == 2 and (abs(a[0]) > 0 or abs(a[1]) > 0):
        raise InputError(f"axis = {axis!r}: a 2D sector turns about (0, 0, 1) or (0, 0, -1)")
    if p.size == 2 and dim == 2:
        p = np.append(p, 0.0)
    if p.size != 3 or not np.all(np.isfinite(p)):
        raise InputError(f"point = {point!r}: expected a point of the axis, 3 coordinates [m]")
    return a, p


def _count(n_sectors) -> int:
    if isinstance(n_sectors, bool) or not isinstance(n_sectors, int | np.integer) \
            or n_sectors < 2:
        raise InputError(f"n_sectors = {n_sectors!r}: expected an integer >= 2")
    return int(n_sectors)


def match_boundaries(left_coords, right_coords, axis, point, n_sectors: int,
                     tolerance: float) -> np.ndarray:
    """``order`` (nb,) with right node ``order[b]`` at left node ``b`` turned by ``2 pi / N``
    about the axis; an unmatched node is an InputError with its distance to the nearest
    right node."""
    L = np.asarray(left_coords, float)
    Rc = np.asarray(right_coords, float)
    d = L.shape[1]
    if L.shape != Rc.shape:
        raise InputError(f"cyclic boundaries: the left one has {L.shape[0]} nodes, the right "
                         f"one {Rc.shape[0]}; expected the same nodes turned by 2 pi / {n_sectors}")
    c = np.asarray(point, float)[:d]

    def turned(angle):
        return c + (L - c) @ rotation_matrix(axis, angle, d).T

    order = np.empty(L.shape[0], dtype=np.int64)
    X = turned(2 * np.pi / n_sectors)
    for b, x in enumerate(X):
        dist = np.linalg.norm(Rc - x, axis=1)
        j = int(np.argmin(dist))
        if dist[j] > tolerance:
            back = np.min(np.linalg.norm(Rc - turned(-2 * np.pi / n_sectors)[b], axis=1))
            hint = (" (the boundaries match turned the other way: swap left and right)"
                    if back <= tolerance else "")
            raise InputError(
                f"cyclic boundaries: left node {b} at {np.round(L[b], 12).tolist()} turned by "
                f"2 pi / {n_sectors} is {dist[j]:.3g} m from the nearest right node (tolerance "
                f"{tolerance:.3g} m){hint}")
        order[b] = j
    if np.unique(order).size != order.size:
        raise InputError("cyclic boundaries: two left nodes turn onto the same right node; "
                         "expected a one-to-one match")
    return order


@model_argument
def cyclic_sector(model: Model, n_sectors: int, left, right, *, axis=(0.0, 0.0, 1.0),
                  point=(0.0, 0.0, 0.0), tolerance: float | None = None) -> CyclicSector:
    """The sector ``model`` (built from a mesh) of a disk of ``n_sectors`` sectors.

    ``left``, ``right``: the names of the cyclic boundaries (mesh boundaries or node sets);
    ``left`` turned by ``+2 pi / n_sectors`` about ``axis`` (a unit vector, right-hand rule)
    through ``point`` [m] must land on ``right`` node by node within ``tolerance`` [m]
    (default ``1e-6`` of the model's size). Node DOFs are ``d i + c`` (a mesh model).
    """
    mesh = model.mesh
    if mesh is None:
        raise InputError("cyclic_sector: the model has no mesh; use cyclic_sector_from_dofs "
                         "for a model of user matrices")
    d = mesh.dim

    def nodes(name, what):
        if name in mesh.boundaries:
            return np.unique(np.asarray(mesh.boundaries[name]).reshape(-1))
        if name in mesh.node_sets:
            return np.unique(np.asarray(mesh.node_sets[name]).reshape(-1))
        raise InputError(f"{what} = {name!r}: no boundary or node set of that name; the mesh "
                         f"has {sorted(set(mesh.boundaries) | set(mesh.node_sets))}")

    ln, rn = nodes(left, "left"), nodes(right, "right")
    dofs = np.arange(model.ndof, dtype=np.int64).reshape(-1, d)
    if tolerance is None:
        tolerance = 1e-6 * float(np.ptp(mesh.points, axis=0).max())
    return cyclic_sector_from_dofs(model, n_sectors, (dofs[ln], mesh.points[ln]),
                                   (dofs[rn], mesh.points[rn]), axis=axis, point=point,
                                   tolerance=tolerance, node_dofs=dofs)


def cyclic_sector_from_dofs(model: Model, n_sectors: int, left, right, *,
                            axis=(0.0, 0.0, 1.0), point=(0.0, 0.0, 0.0),
                            tolerance: float = 1e-9, node_dofs=None) -> CyclicSector:
    """The sector ``model`` (any model, user matrices included) with its cyclic boundaries
    ``left``, ``right`` each given as ``(dofs, coords)``: the DOFs (nb, d) and positions
    (nb, d) [m] of their nodes, in any order (matched here); ``node_dofs`` (nn, d): the DOF
    groups that turn as vectors (default: ``d i + c``, every DOF in a node)."""
    n = _count(n_sectors)
    (left_dofs, left_coords), (right_dofs, right_coords) = left, right
    d = int(model.dim)
    a, p = _axis(axis, point, d)
    ld = np.asarray(left_dofs, dtype=np.int64).reshape(-1, d)
    rd = np.asarray(right_dofs, dtype=np.int64).reshape(-1, d)
    if ld.size == 0:
        raise InputError("left: the cyclic boundary has no node")
    if np.intersect1d(ld, rd).size:
        raise InputError("cyclic boundaries: a node belongs to both the left and the right one "
                         "(a node on the axis); expected two distinct boundaries")
    order = match_boundaries(np.asarray(left_coords, float).reshape(-1, d),
                             np.asarray(right_coords, float).reshape(-1, d), a, p, n,
                             float(tolerance))
    rd = rd[order]
    rc = np.asarray(right_coords, float).reshape(-1, d)[order]
    if node_dofs is None:
        node_dofs = np.arange(model.ndof, dtype=np.int64).reshape(-1, d)
    R = rotation_matrix(a, 2 * np.pi / n, d)
    sector = CyclicSector(model, n, a, p, ld, rd, np.asarray(left_coords, float).reshape(-1, d),
                          rc, np.asarray(node_dofs, dtype=np.int64).reshape(-1, d), R)
    _check_fixed(sector)
    return sector


def _check_fixed(sector: CyclicSector) -> None:
    """A held right-boundary DOF must be the image of held left DOFs (``R`` row)."""
    fixed = np.zeros(sector.model.ndof, dtype=bool)
    fixed[np.asarray(sector.model.fixed_dofs, dtype=np.int64)] = True
    R = sector.rotation
    for b in range(sector.left_dofs.shape[0]):
        for c in range(sector.dim):
            if fixed[sector.right_dofs[b, c]]:
                cols = sector.left_dofs[b][np.abs(R[c]) > 1e-12]
                if not fixed[cols].all():
                    raise InputError(
                        f"fixed DOFs: right-boundary DOF {sector.right_dofs[b, c]} is held but "
                        f"its left-boundary image (DOFs {cols.tolist()}) is not; hold both")


def transform(sector: CyclicSector, k: int) -> sp.csr_matrix:
    """Sparse complex ``T_k`` (ndof, nq): ``U = T_k q`` with ``q`` the kept DOFs
    (:meth:`CyclicSector.kept_dofs`) and ``U_right = e^{i k alpha} R U_left``."""
    keep = sector.kept_dofs()
    ndof, nq = sector.model.ndof, keep.size
    pos = np.full(ndof, -1, dtype=np.int64)
    pos[keep] = np.arange(nq)
    phase = np.exp(1j * k * sector.angle)
    d = sector.dim
    rows = [keep]
    cols = [np.arange(nq)]
    vals = [np.ones(nq, dtype=complex)]
    R = sector.rotation
    for c in range(d):
        for e in range(d):
            if R[c, e] != 0.0:
                rows.append(sector.right_dofs[:, c])
                cols.append(pos[sector.left_dofs[:, e]])
                vals.append(np.full(sector.left_dofs.shape[0], phase * R[c, e]))
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(ndof, nq))


def _positions(sector: CyclicSector, dofs, what: str) -> np.ndarray:
    keep = sector.kept_dofs()
    pos = np.full(sector.model.ndof, -1, dtype=np.int64)
    pos[keep] = np.arange(keep.size)
    dofs = np.asarray(dofs, dtype=np.int64)
    out = np.where(dofs >= 0, pos[np.maximum(dofs, 0)], -1)
    if np.any((dofs >= 0) & (out < 0)):
        raise InputError(f"{what}: a node on the right cyclic boundary; put it on the left one "
                         "(the right boundary is the left one of the next sector)")
    return out


@model_argument
def neighbour_contact(sector: CyclicSector, spec) -> CyclicSector:
    """The sector with an inter-blade contact added (a damper, a shroud): ``spec`` a
    :class:`~fretwear.model.build.ContactSpec` whose ``boundary`` A touches the *next*
    sector's copy of the boundary ``spec.partner`` B (B turned by ``+2 pi / N`` lands on A,
    node by node within ``spec.tolerance``). The contact law acts on ``U_A - U_B(next
    sector)``, which in the sector's own coordinates is, harmonic by harmonic (Petrov 2004),

        U_rel,n = U_A,n - e^{+i n EO 2 pi / N} R U_B,n

    (:func:`relative_harmonic_model`); the normal default is A's outward normal.

    The sector is then checked to be held with this contact in every family
    (:func:`~fretwear.model.supports.check_supported` with the pairs to the next sector): a
    body held only by its contacts, one of them with the next sector (a wedge damper between
    two platforms), needs no spring; build such a sector with
    :func:`~fretwear.model.build.unchecked_from_mesh` (:func:`~fretwear.model.build.from_mesh`
    would refuse it before this contact is known)."""
    model = sector.model
    mesh = model.mesh
    if mesh is None:
        raise InputError("neighbour_contact: the sector model has no mesh")
    if spec.partner is None or spec.partner == spec.boundary:
        raise InputError(f"contact {spec.name!r}: partner = {spec.partner!r}; an inter-blade "
                         "contact pairs a boundary with another boundary of the sector (the "
                         "next sector's copy of it)")
    if spec.partner not in mesh.boundaries:
        raise InputError(f"contact {spec.name!r}: unknown partner boundary {spec.partner!r}")
    if spec.pairing in ("node-to-segment", "mortar"):
        raise InputError(f"contact {spec.name!r}: pairing = {spec.pairing!r} between "
                         "neighbour sectors is not supported (the harmonic-index model takes "
                         "one partner node a contact node); expected matching nodes (pairing "
                         '= "auto" or "node-to-node")')
    c = _contact(mesh, dataclasses.replace(spec, partner=None, partner_wear_coefficient=0.0,
                                           pairing="auto"),
                 model.thickness)
    d = mesh.dim
    b_nodes = np.unique(np.asarray(mesh.boundaries[spec.partner]).reshape(-1))
    tol = spec.tolerance if spec.tolerance is not None else \
        1e-6 * float(np.ptp(mesh.points, axis=0).max())
    order = match_boundaries(mesh.points[b_nodes], c.coords, sector.axis, sector.point,
                             sector.n_sectors, tol) if b_nodes.size == c.n_nodes else None
    if order is None:
        raise InputError(f"contact {spec.name!r}: boundary {spec.boundary!r} has {c.n_nodes} "
                         f"nodes, its partner {spec.partner!r} {b_nodes.size}; expected the "
                         "partner turned by 2 pi / N onto the boundary node by node")
    partner = np.empty(c.n_nodes, dtype=np.int64)
    partner[order] = b_nodes  # A node order[b] is B node b turned
    c = dataclasses.replace(c, partner_dofs=d * partner[:, None] + np.arange(d),
                            partner_ids=partner,
                            partner_wear_coefficient=spec.partner_wear_coefficient)
    contact = combine([model.contact, c])
    check_distinct(contact)
    neighbour = np.concatenate([sector.neighbour_nodes(), np.ones(c.n_nodes, dtype=bool)])
    out = dataclasses.replace(sector, model=dataclasses.replace(model, contact=contact),
                              neighbour=neighbour)
    check_supported(out.model, Neighbours(neighbour, sector.rotation, sector.n_sectors))
    return out


def harmonic_model(sector: CyclicSector, k: int) -> tuple[Model, sp.csr_matrix]:
    """The sector reduced to harmonic index ``k`` and its ``T_k``: a :class:`Model` on the
    kept DOFs ``q`` with the complex Hermitian ``T_k^H K T_k`` (and ``M``, ``C``, ``D``), the
    contact and observed DOFs renumbered, and no loads (they depend on the temporal harmonic:
    ``T_k^H F_n``). For ``k = 0`` and ``k = N/2`` the matrices are real."""
    model = sector.model
    T = transform(sector, k)
    real = (k % sector.n_sectors == 0) or (2 * k == sector.n_sectors)
    Th = T.conj().T.tocsr()

    def tr(A):
        if A is None:
            return None
        B = (Th @ sp.csr_matrix(A) @ T).tocsr()
        return B.real.tocsr() if real else B

    c = model.contact
    if c.segments is not None:
        raise InputError("contact: node-to-segment or mortar pairs (non-matching interface "
                         "meshes) in a cyclic sector are not supported (the harmonic-index "
                         "model takes one partner node a contact node); expected node-to-node "
                         'pairs (pairing = "node-to-node", matching nodes)')
    contact = dataclasses.replace(
        c, dofs=_positions(sector, c.dofs, "contact"),
        partner_dofs=None if c.partner_dofs is None
        else _positions(sector, c.partner_dofs, "contact partner"))
    observed = [ObservedPoint(p.name, _positions(sector, p.dofs, f"observed point {p.name!r}"),
                              p.coords) for p in model.observed]
    fixed = np.asarray(model.fixed_dofs, dtype=np.int64)
    keep = sector.kept_dofs()
    fixed_q = np.flatnonzero(np.isin(keep, fixed))
    red = dataclasses.replace(model, K=tr(model.K), M=tr(model.M), C=tr(model.C), D=tr(model.D),
                              loads=[], contact=contact, observed=observed, fixed_dofs=fixed_q,
                              mesh=None, name=f"{model.name} (harmonic index {k})")
    return red, T


def relative_harmonic_model(sector: CyclicSector, k: int):
    """``(rel, T_k, P_k)``: :func:`harmonic_model` in the relative coordinates of its pairs,
    ``q = P_k q'`` with ``q_a = q'_a + c R^s q'_b`` for a pair ``(a, b)``: ``c = 1``, ``s = 0``
    inside the sector, ``c = e^{i k 2 pi / N}``, ``s = 1`` for a partner in the next sector
    (:func:`neighbour_contact`). ``rel`` has ``P_k^H A P_k`` for every matrix and the pairs
    dropped (node-to-rigid on the relative DOFs); ``P_k`` is None without pairs. The
    observed DOFs keep their numbers: their displacement is ``(P_k q')[dofs]``."""
    red, T = harmonic_model(sector, k)
    c = red.contact
    if not c.has_pairs:
        return red, T, None
    nq = red.ndof
    if np.intersect1d(np.asarray(red.fixed_dofs), np.asarray(c.dofs).reshape(-1)).size:
        raise InputError("contact DOFs cannot also be fixed (Dirichlet) DOFs")
    pd = np.asarray(c.partner_dofs, dtype=np.int64)
    dofs = np.asarray(c.dofs, dtype=np.int64)
    nb = sector.neighbour_nodes()
    phase = np.exp(1j * k * sector.angle)
    rows, cols, vals = [np.arange(nq)], [np.arange(nq)], [np.ones(nq, dtype=complex)]
    d = sector.dim
    for p in np.flatnonzero(pd[:, 0] >= 0):
        B = phase * sector.rotation if nb[p] else np.eye(d)
        rows.append(np.repeat(dofs[p], d))
        cols.append(np.tile(pd[p], d))
        vals.append(B.reshape(-1).astype(complex))
    P = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(nq, nq))
    if k % sector.n_sectors == 0 or 2 * k == sector.n_sectors:
        P = P.real.tocsr()
    Ph = P.conj().T.tocsr()

    def tr(A):
        return None if A is None else (Ph @ A @ P).tocsr()

    rel = dataclasses.replace(red, K=tr(red.K), M=tr(red.M), C=tr(red.C), D=tr(red.D),
                              contact=dataclasses.replace(c, partner_dofs=None))
    return rel, T, P


# --------------------------------------------------------------------------------------------
# the whole disk: the independent reference
# --------------------------------------------------------------------------------------------
def check_disk(sector: CyclicSector) -> None:
    """Refuse (one InputError with the estimate and the machine's memory) a whole disk of
    ``sector`` that cannot fit, before it is built: per sector the stored entries of its
    matrices (the disk's, and the temporaries of their assembly), its DOF maps and block
    rotations."""
    m = sector.model
    stored = sum(X.nnz if sp.issparse(X) else np.size(X)
                 for X in (m.K, m.M, m.C, m.D) if X is not None)
    n = sector.n_sectors
    require_memory(n * (36.0 * stored + 8.0 * m.ndof * (3 + 3 * sector.dim)),
                   f"the whole disk of {n:,} sectors of {m.ndof:,} DOFs")


def _disk_numbering(sector: CyclicSector) -> tuple[np.ndarray, int]:
    """``maps`` (N, ndof): disk DOF of every DOF of sector ``j`` (its right boundary is the
    next sector's left one), and the disk's number of DOFs."""
    check_disk(sector)
    keep = sector.kept_dofs()
    n, nq = sector.n_sectors, keep.size
    pos = np.full(sector.model.ndof, -1, dtype=np.int64)
    pos[keep] = np.arange(nq)
    maps = np.empty((n, sector.model.ndof), dtype=np.int64)
    for j in range(n):
        maps[j, keep] = j * nq + np.arange(nq)
        maps[j, sector.right_dofs.reshape(-1)] = ((j + 1) % n) * nq + \
            pos[sector.left_dofs.reshape(-1)]
    return maps, n * nq


def _turn_dofs(sector: CyclicSector, j: int) -> sp.csr_matrix:
    """Sparse (ndof, ndof) block rotation of sector ``j``'s DOF groups (identity elsewhere)."""
    ndof = sector.model.ndof
    Q = sector.turn(j)
    g = sector.node_dofs
    d = sector.dim
    grouped = np.zeros(ndof, dtype=bool)
    grouped[g.reshape(-1)] = True
    rows = [np.repeat(g, d, axis=1).reshape(-1), np.flatnonzero(~grouped)]
    cols = [np.tile(g, (1, d)).reshape(-1), np.flatnonzero(~grouped)]
    vals = [np.broadcast_to(Q.reshape(1, -1), (g.shape[0], d * d)).reshape(-1),
            np.ones(int((~grouped).sum()))]
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(ndof, ndof))


def sector_maps(sector: CyclicSector) -> tuple[list[sp.csr_matrix], int]:
    """``A_j`` (ndof_disk, ndof) for every sector: ``U_disk`` (disk axes) receives sector
    ``j``'s DOFs (its own axes) as ``A_j U_j``; sector ``j``'s DOFs are ``A_j^T U_disk``."""
    maps, nd = _disk_numbering(sector)
    ndof = sector.model.ndof
    out = []
    for j in range(sector.n_sectors):
        G = sp.csr_matrix((np.ones(ndof), (maps[j], np.arange(ndof))), shape=(nd, ndof))
        out.append((G @ _turn_dofs(sector, j)).tocsr())
    return out, nd


def _wave_loads(loads: list[Load], A: list[sp.csr_matrix], engine_order: int,
                angle: float) -> list[Load]:
    """The sector's loads on every sector of the disk with the phases of the travelling wave
    (harmonic ``n`` of sector ``j``: ``e^{i n EO j alpha}``), as ``"fourier"`` loads."""
    out = []
    for ld in loads:
        if ld.waveform == "triangle":
            raise InputError(f"load {ld.name!r}: a triangle waveform has infinitely many "
                             "harmonics; give it as a \"fourier\" load to build the disk")
        nmax = max([1] + [int(n) for n in (ld.coefficients or {})])
        a, b = ld.fourier_coefficients(nmax)
        for j, Aj in enumerate(A):
            c = (a - 1j * b) * np.exp(1j * np.arange(nmax + 1) * engine_order * j * angle)
            coeffs = {n: (float(c[n].real), float(-c[n].imag)) for n in range(nmax + 1)}
            out.append(Load(Aj @ np.asarray(ld.vector, float), "fourier", coeffs,
                            f"{ld.name} sector {j}"))
    return out


@model_argument
def whole_disk(sector: CyclicSector, engine_order: int = 0) -> Model:
    """The disk of ``N`` copies of the sector, turned into the disk's axes, merged at the
    cyclic boundaries, every sector with the sector's contact (frames turned) and loads
    (phased by the travelling wave of ``engine_order``); observed points of sector 0. The
    reference of the cyclic reduction (no mesh kept)."""
    engine_order = whole_number(engine_order, "engine_order")
    m = sector.model
    A, nd = sector_maps(sector)

    def assemble(X):
        if X is None:
            return None
        X = sp.csr_matrix(X)
        return sum((Aj @ X @ Aj.T for Aj in A), sp.csr_matrix((nd, nd))).tocsr()

    maps, _ = _disk_numbering(sector)
    fixed = np.unique(np.concatenate([maps[j, np.asarray(m.fixed_dofs, np.int64)]
                                      for j in range(sector.n_sectors)]))
    return dataclasses.replace(
        m, K=assemble(m.K), M=assemble(m.M), C=assemble(m.C), D=assemble(m.D),
        loads=_wave_loads(m.loads, A, int(engine_order), sector.angle),
        contact=_disk_contact(sector, m.contact, maps),
        observed=[ObservedPoint(p.name, maps[0, np.asarray(p.dofs, np.int64)], p.coords)
                  for p in m.observed],
        fixed_dofs=fixed, mesh=None, name=f"{m.name} (whole disk of {sector.n_sectors})")


def _disk_contact(sector: CyclicSector, c: ContactInterface, maps) -> ContactInterface:
    """Every sector's copy of the contact record: DOFs renumbered, frames and positions
    turned into the disk's axes, per-node values repeated."""
    n, d = sector.n_sectors, c.dim
    if c.normal_load is not None:
        raise InputError("whole_disk: a prescribed normal load is not phased per sector; "
                         "the disk reference takes unilateral contacts")
    pt = sector.point[:d]

    def tile(v):
        if v is None or np.ndim(v) == 0:
            return v
        return np.concatenate([np.asarray(v)] * n)

    dofs, frames, coords, partners = [], [], [], []
    nb = sector.neighbour_nodes()
    for j in range(n):
        Q = sector.turn(j)
        dofs.append(maps[j, c.dofs])
        frames.append(np.asarray(c.frame) @ Q.T)
        coords.append(pt + (np.asarray(c.coords, float) - pt) @ Q.T)
        if c.partner_dofs is not None:
            pdofs = np.asarray(c.partner_dofs)
            where = np.where(nb[:, None], maps[(j + 1) % n, np.maximum(pdofs, 0)],
                             maps[j, np.maximum(pdofs, 0)])
            partners.append(np.where(pdofs >= 0, where, -1))
    return dataclasses.replace(
        c, dofs=np.concatenate(dofs), frame=np.concatenate(frames), gap=tile(c.gap),
        area=tile(c.area), mu=tile(c.mu), coords=np.concatenate(coords),
        node_ids=tile(c.node_ids), wear_coefficient=tile(c.wear_coefficient),
        partner_dofs=None if c.partner_dofs is None else np.concatenate(partners),
        partner_ids=tile(c.partner_ids),
        partner_wear_coefficient=tile(c.partner_wear_coefficient),
        interface=tile(c.interface), kn=tile(c.kn), kt=tile(c.kt))


# --------------------------------------------------------------------------------------------
# the whole disk rebuilt from a sector's response (output)
# --------------------------------------------------------------------------------------------
def disk_harmonics(sector: CyclicSector, engine_order: int, orders, U) -> np.ndarray:
    """The harmonics of every sector of the tuned disk in the disk's axes, from the sector's:
    ``U`` (nb, ndof) complex, harmonic ``orders[b]`` of sector 0 (its DOFs, right boundary
    included); returns (N, nb, ndof): sector ``j``'s harmonic ``n`` is
    ``Q_j U_n e^{i n EO j 2 pi / N}`` (``Q_j`` the turn by ``j 2 pi / N`` of each node's
    components), the travelling wave of the module docstring."""
    U = np.asarray(U, dtype=complex)
    orders = np.asarray(orders, dtype=np.int64)
    require_memory(16.0 * (sector.n_sectors + 2) * U.size,
                   f"the harmonics of {sector.n_sectors:,} sectors ({U.size:,} values each)")
    out = np.empty((sector.n_sectors, *U.shape), dtype=complex)
    for j in range(sector.n_sectors):
        phase = np.exp(1j * orders * int(engine_order) * j * sector.angle)
        out[j] = (_turn_dofs(sector, j) @ (U * phase[:, None]).T).T
    return out


def disk_mesh(sector: CyclicSector):
    """The mesh of the whole disk for output: ``N`` copies of the sector's mesh, copy ``j``
    turned by ``j 2 pi / N`` about the axis (nodes ``j nn .. (j + 1) nn - 1``; the nodes of
    the cyclic boundaries are repeated, once per sector that has them)."""
    from fretwear.model.core import Mesh

    mesh = sector.model.mesh
    if mesh is None:
        raise InputError("disk_mesh: the sector model has no mesh")
    nn, d = mesh.points.shape
    require_memory(2.0 * sector.n_sectors * (mesh.points.nbytes + np.asarray(mesh.cells).nbytes),
                   f"the mesh of {sector.n_sectors:,} sectors")
    pt = sector.point[:d]
    points = np.concatenate([pt + (mesh.points - pt) @ sector.turn(j).T
                             for j in range(sector.n_sectors)])
    cells = np.concatenate([np.asarray(mesh.cells) + j * nn for j in range(sector.n_sectors)])
    return Mesh(points, cells, mesh.cell_type)
