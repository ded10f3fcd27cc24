"""A :class:`~fretwear.model.core.Model` from matrices exported by an FE code, everything named
by the code's node ids: contact nodes and their partners, held DOFs, observed points, forces.

:func:`from_fe` turns node ids into rows with the matrices' :class:`~.dofmap.DofMap` and hands
the rows to :func:`~fretwear.model.matrices.from_matrices` (which checks the matrices, the
frames and the supports). A Craig-Bampton superelement is such a set of matrices: its contact
nodes are boundary nodes, its modal coordinates scalar points (component 0) that nothing names.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from fretwear.errors import InputError
from fretwear.model.build import Damping
from fretwear.model.core import Load, Mesh, Model
from fretwear.model.matrices import ContactDofs, from_matrices
from fretwear.model.readers.dofmap import FEMatrices
from fretwear.model.readers.nodes import NodeTable

AXES = {"x": 1, "y": 2, "z": 3}


@dataclass
class NodeContact:
    """A frictional interface named by node ids (the contact record of :func:`from_fe`).

    Attributes
    ----------
    nodes : (nc,) node ids, or the name of a node set of the ``nodes`` table.
    mu : Coulomb friction coefficient [-].
    normal : (d,) or (nc, d), optional
        The normal of each node in the global axes, pointing from the node's body into the
        obstacle (or into the partner's body); the tangents are chosen from it. Give
        ``normal`` or ``frames``.
    frames : (nc, d, d), optional
        Orthonormal rows ``[n, t1(, t2)]`` of each node in the global axes.
    partners : (nc,) node ids or a node-set name, optional
        Node-to-node pairs: each node's partner on the other body (same order).
    gap, area, wear_coefficient, partner_wear_coefficient, name, kn, kt : as in
        :class:`~fretwear.model.matrices.ContactDofs` (gap [m], area [m^2], k_w [1/Pa],
        stiffness [N/m]).
    """

    nodes: object
    mu: float
    normal: object = None
    frames: object = None
    partners: object = None
    gap: object = 0.0
    area: object = 1.0
    wear_coefficient: float = 0.0
    partner_wear_coefficient: float = 0.0
    name: str = "contact"
    kn: object = None
    kt: object = None


@dataclass
class NodeForce:
    """A force on nodes: ``force`` [N] (d,) on each node of ``nodes`` or (nn, d) one per node,
    times the waveform (as :class:`~fretwear.model.core.Load`)."""

    nodes: object
    force: object
    waveform: str = "cos"
    name: str = "load"
    coefficients: dict | None = None


def _ids(value, table: NodeTable | None, what: str) -> np.ndarray:
    """Node ids from ids or a node-set name."""
    if isinstance(value, str):
        if table is None or value not in table.node_sets:
            have = [] if table is None else sorted(table.node_sets)
            raise InputError(f"{what} = {value!r}: no node set of that name (the node file "
                             f"has {have}); expected node ids or a node set")
        return np.asarray(table.node_sets[value], dtype=np.int64)
    a = np.atleast_1d(np.asarray(value))
    if a.size == 0 or not np.issubdtype(a.dtype, np.number) or np.any(a != np.round(a)):
        raise InputError(f"{what} = {value!r}; expected node ids (integers) or a node set name")
    return a.astype(np.int64).reshape(-1)


def frames_from_normals(normal, nc: int, dim: int, what: str = "normal") -> np.ndarray:
    """Orthonormal frames ``[n, t1(, t2)]`` (nc, d, d) from normals (d,) or (nc, d): ``t1`` is
    the global axis least aligned with ``n``, made orthogonal to it; ``t2 = n x t1``."""
    try:
        n = np.broadcast_to(np.asarray(normal, dtype=float), (nc, dim)).copy()
    except (TypeError, ValueError):
        raise InputError(f"{what} = {normal!r}; expected a vector of {dim} numbers or one per "
                         f"node ({nc}, {dim})") from None
    norm = np.linalg.norm(n, axis=1)
    if not np.all(np.isfinite(n)) or np.any(norm == 0.0):
        raise InputError(f"{what}: a zero or non-finite normal; expected unit-able vectors")
    n /= norm[:, None]
    if dim == 2:
        return np.stack([n, np.column_stack([-n[:, 1], n[:, 0]])], axis=1)
    axis = np.eye(3)[np.argmin(np.abs(n), axis=1)]
    t1 = axis - np.sum(axis * n, axis=1)[:, None] * n
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    return np.stack([n, t1, np.cross(n, t1)], axis=1)


def _contact_dofs(contacts, fe: FEMatrices, table, dim: int) -> tuple[ContactDofs, dict]:
    comps = list(range(1, dim + 1))
    parts = []
    for k, c in enumerate(contacts):
        if not isinstance(c, NodeContact):
            raise InputError(f"contact[{k}] = {c!r}; expected a NodeContact(nodes, mu, ...)")
        label = f"contact {c.name!r}"
        ids = _ids(c.nodes, table, f"{label} nodes")
        rows = fe.dofs.rows(ids, comps, f"{label} nodes")
        prow = None
        if c.partners is not None:
            pids = _ids(c.partners, table, f"{label} partners")
            if isinstance(c.partners, str):  # a node set: each node's coincident partner
                pids = _coincident(ids, pids, table, dim, f"{label} partners")
            if pids.size != ids.size:
                raise InputError(f"{label}: {pids.size} partners for {ids.size} nodes; expected "
                                 "one partner per node")
            prow = fe.dofs.rows(pids, comps, f"{label} partners")
        if (c.normal is None) == (c.frames is None):
            raise InputError(f"{label}: give either normal or frames (the contact directions)")
        frames = (frames_from_normals(c.normal, ids.size, dim, f"{label} normal")
                  if c.frames is None else np.asarray(c.frames, dtype=float))
        parts.append((c, ids, rows, prow, frames, None if c.partners is None else pids))
    nc = [p[1].size for p in parts]
    per = lambda f: np.concatenate([np.broadcast_to(np.asarray(f(p[0]), dtype=float),  # noqa: E731
                                                    (n,)) for p, n in zip(parts, nc, strict=True)])
    rows = np.concatenate([p[2] for p in parts])
    paired = [p[3] is not None for p in parts]
    if any(paired) and not all(paired):
        raise InputError("contact: node-to-node interfaces (with partners) and node-to-rigid "
                         "ones cannot be mixed in one model built from FE matrices")
    ids = np.concatenate([p[1] for p in parts])
    coords = None if table is None else table.coordinates(ids, dim, "contact nodes")
    stiff = {k: (None if all(getattr(p[0], k) is None for p in parts)
                 else per(lambda c, k=k: np.inf if getattr(c, k) is None else getattr(c, k)))
             for k in ("kn", "kt")}
    contact = ContactDofs(
        normal_dofs=rows[:, 0], tangential_dofs=rows[:, 1:] if dim == 3 else rows[:, 1],
        mu=float(parts[0][0].mu), gap=per(lambda c: c.gap), area=per(lambda c: c.area),
        frames=np.concatenate([p[4] for p in parts]), coords=coords,
        name=str(parts[0][0].name),
        partner_dofs=np.concatenate([p[3] for p in parts]) if all(paired) else None,
        kn=stiff["kn"], kt=stiff["kt"])
    extra = {"mu": per(lambda c: c.mu), "wear": per(lambda c: c.wear_coefficient),
             "pwear": per(lambda c: c.partner_wear_coefficient), "ids": ids,
             "pids": np.concatenate([p[5] for p in parts]) if all(paired) else None,
             "interface": np.repeat(np.arange(len(parts)), nc),
             "names": tuple(str(p[0].name) for p in parts)}
    return contact, extra


def _coincident(ids, pool, table: NodeTable, dim: int, what: str, rtol=1e-6) -> np.ndarray:
    """For each node of ``ids`` the node of ``pool`` at its position (within ``rtol`` times
    the size of the nodes' extent)."""
    from scipy.spatial import cKDTree

    a = table.coordinates(ids, dim, what)
    b = table.coordinates(pool, dim, what)
    size = float(np.linalg.norm(np.ptp(np.vstack([a, b]), axis=0))) or 1.0
    dist, k = cKDTree(b).query(a)
    far = np.flatnonzero(dist > rtol * size)
    if far.size:
        raise InputError(f"{what}: node {int(ids[far[0]])} has no partner at its position "
                         f"(nearest {dist[far[0]]:.3g} m away, tolerance {rtol * size:.3g} m); "
                         "expected coincident nodes on the two faces")
    return np.asarray(pool, dtype=np.int64)[k]


def _loads(loads, fe: FEMatrices, table, dim: int) -> list[Load]:
    out = []
    for k, ld in enumerate(loads):
        if isinstance(ld, Load):
            out.append(ld)
            continue
        if not isinstance(ld, NodeForce):
            raise InputError(f"loads[{k}] = {ld!r}; expected a NodeForce or a Load")
        ids = _ids(ld.nodes, table, f"load {ld.name!r} nodes")
        try:
            f = np.broadcast_to(np.asarray(ld.force, dtype=float), (ids.size, dim))
        except (TypeError, ValueError):
            raise InputError(f"load {ld.name!r}: force {ld.force!r}; expected {dim} numbers "
                             f"[N] or one row per node ({ids.size}, {dim})") from None
        rows = fe.dofs.rows(ids, list(range(1, dim + 1)), f"load {ld.name!r} nodes")
        vec = np.zeros(fe.dofs.size)
        np.add.at(vec, rows.ravel(), f.ravel())
        out.append(Load(vec, ld.waveform, ld.coefficients, ld.name))
    return out


def _fixed(fixed, fe: FEMatrices, table) -> np.ndarray:
    """Rows held at zero from ``(nodes, components)`` pairs (components: a list of 1-6, an
    axis name or ``"all"``: every component of the nodes)."""
    rows = []
    for k, item in enumerate(fixed):
        try:
            nodes, comps = item
        except (TypeError, ValueError):
            raise InputError(f"fixed[{k}] = {item!r}; expected (nodes, components)") from None
        ids = _ids(nodes, table, f"fixed[{k}] nodes")
        if comps == "all":
            mask = np.isin(fe.dofs.node, ids)
            fe.dofs.rows(ids, [], f"fixed[{k}] nodes")  # every node known
            rows.append(np.flatnonzero(mask))
            continue
        comps = [AXES[c] if isinstance(c, str) and c in AXES else c
                 for c in ([comps] if isinstance(comps, (str, int)) else comps)]
        rows.append(fe.dofs.rows(ids, comps, f"fixed[{k}] nodes").ravel())
    return np.unique(np.concatenate(rows)) if rows else np.zeros(0, dtype=np.int64)


def from_fe(fe: FEMatrices, *, contact, nodes: NodeTable | None = None, damping=None,
            loads=(), fixed=(), observed=None, name: str = "fe") -> Model:
    """A model from an FE code's matrices, with everything named by node ids.

    Parameters
    ----------
    fe : the matrices and their DOF map (:func:`fretwear.model.readers.read_fe`).
    contact : NodeContact or a sequence of them (all node-to-rigid, or all node-to-node).
    nodes : NodeTable, optional
        Node coordinates and node sets of the mesh the matrices came from
        (:func:`~fretwear.model.readers.nodes.read_nodes`): coordinates of the contact nodes
        and observed points for output, node sets to name nodes, and the points of the
        ParaView output (``model.fe_mesh``, :func:`fe_mesh`); without it no ParaView file is
        written.
    damping : Damping, optional (loss factor, Rayleigh factors); the matrices' own C and D
        (exported damping) are used when present and ``damping`` does not give them.
    loads : NodeForce or Load (on the rows of the matrices) items.
    fixed : ``(nodes, components)`` pairs held at zero (components 1-6, "x", "y", "z",
        or ``"all"``).
    observed : dict name -> node id (its translations are reported).
    name : label of the model.

    The model's dimension is 3 when the DOF map has z translations (component 3), else 2.
    """
    if not isinstance(fe, FEMatrices):
        raise InputError(f"fe = {fe!r}; expected FEMatrices (fretwear.model.readers.read_fe)")
    dim = 3 if np.any(fe.dofs.component == 3) else 2
    contacts = [contact] if isinstance(contact, NodeContact) else list(contact)
    if not contacts:
        raise InputError("contact: expected at least one NodeContact")
    cdofs, extra = _contact_dofs(contacts, fe, nodes, dim)
    damping = damping or Damping()
    if not isinstance(damping, Damping):
        raise InputError(f"damping = {damping!r} is not a Damping(...)")
    if damping.C is None and fe.C is not None:
        damping = dataclasses.replace(damping, C=fe.C)
    if damping.D is None and fe.D is not None and damping.loss_factor == 0.0:
        damping = dataclasses.replace(damping, D=fe.D)
    obs = {}
    for key, node in (observed or {}).items():
        ids = _ids(node, nodes, f"observed {key!r}")
        obs[key] = fe.dofs.rows(ids[:1], list(range(1, dim + 1)), f"observed {key!r}").ravel()
    model = from_matrices(fe.K, fe.M, contact=cdofs, damping=damping,
                          loads=_loads(loads, fe, nodes, dim), fixed_dofs=_fixed(fixed, fe, nodes),
                          observed=obs or None, name=name)
    model.meta = {"source": "fe", "file": fe.source}
    model.dim = dim
    if nodes is not None:
        for p in model.observed:
            p.coords = nodes.coordinates(_ids(observed[p.name], nodes, p.name)[:1], dim,
                                         f"observed {p.name!r}")[0]
    if nodes is not None:
        model.fe_mesh = fe_mesh(fe, nodes, dim)
    ci = model.contact
    ci.node_ids = extra["ids"]
    ci.partner_ids = extra["pids"]
    if np.unique(extra["mu"]).size > 1:
        ci.mu = extra["mu"]
    ci.wear_coefficient = (extra["wear"] if np.unique(extra["wear"]).size > 1
                           else float(extra["wear"][0]))
    ci.partner_wear_coefficient = (extra["pwear"] if np.unique(extra["pwear"]).size > 1
                                   else float(extra["pwear"][0]))
    for what, v in (("wear_coefficient", extra["wear"]), ("partner_wear_coefficient",
                                                         extra["pwear"]), ("mu", extra["mu"])):
        if np.any(v < 0) or not np.all(np.isfinite(v)):
            raise InputError(f"contact {what}: {v[(v < 0) | ~np.isfinite(v)][0]:g}; "
                             "expected a finite value >= 0")
    if len(contacts) > 1:
        ci.interface = extra["interface"]
        ci.interface_names = extra["names"]
    return model


#: meshio cell types of elements by (dimension, number of nodes)
CELL_TYPES = {(2, 3): "triangle", (2, 4): "quad", (3, 4): "tetra", (3, 8): "hexahedron"}


def fe_mesh(fe: FEMatrices, table: NodeTable, dim: int) -> Mesh:
    """The points of the ParaView output of a model from FE matrices: every node of ``table``
    with a translation in the matrices' DOF map, in the node file's order, with ``rows`` the
    DOF of each translation (-1 where the matrices have none) and ``ids`` the node ids; the
    cells are the node file's elements of the commonest kind whose nodes are all points (the
    nodes as ``vertex`` cells when there is none, e.g. a superelement's boundary nodes)."""
    key = fe.dofs.node * 8 + fe.dofs.component
    order = np.argsort(key)
    comps = np.arange(1, dim + 1)
    want = table.ids[:, None] * 8 + comps[None, :]
    pos = np.searchsorted(key[order], want).clip(0, max(key.size - 1, 0))
    found = key[order][pos] == want
    rows = np.where(found, order[pos], -1)
    keep = np.any(found, axis=1)
    ids, rows = table.ids[keep], rows[keep]
    index = {int(n): i for i, n in enumerate(ids.tolist())}
    cells, cell_type = np.arange(ids.size, dtype=np.int64)[:, None], "vertex"
    best = 0
    for n, conn in sorted(table.elements.items()):
        kind = CELL_TYPES.get((dim, n))
        inside = np.all(np.isin(conn, ids), axis=1)
        if kind is not None and np.count_nonzero(inside) > best:
            best = int(np.count_nonzero(inside))
            cells = np.vectorize(index.__getitem__, otypes=[np.int64])(conn[inside])
            cell_type = kind
    return Mesh(table.xyz[keep, :dim].copy(), cells, cell_type, rows=rows, ids=ids)
