"""Build a :class:`~fretwear.model.core.Model` from a finite element mesh.

The user describes the structure with small dataclasses (:class:`Material`, :class:`Damping`,
:class:`Spring`, :class:`Traction`, :class:`NodalForce`, :class:`ContactSpec`) and calls
:func:`from_mesh`. Every input is checked and a bad one raises
:class:`~fretwear.errors.InputError` naming the value and what is expected.

Places (``at=``) are given either as the name of a node set or boundary of the mesh (all its
nodes) or as a coordinate tuple (the node at that point, within ``1e-6`` of the model size).

:func:`check_supported` and :func:`rigid_motion_check` refuse models that the contact alone
cannot hold: with every contact node held in its normal direction (as a frictionless contact
does) and every fixed DOF held, the stiffness must be non-singular; otherwise nothing but
friction holds the structure and the problem has no unique solution.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from fretwear.errors import InputError
from fretwear.limits import check_loss_factor
from fretwear.model.core import WAVEFORMS, ContactInterface, Load, Mesh, Model, ObservedPoint
from fretwear.model.fem import assemble, check_material, check_thickness
from fretwear.model.interfaces import combine, relative_model
from fretwear.model.loads import boundary_load, nodal_areas
from fretwear.model.mesh import boundary as _boundary
from fretwear.model.mesh import check_cells, facet_normals, model_size, orient_facets

AXES = "xyz"


# --------------------------------------------------------------------------------------------
# input dataclasses
# --------------------------------------------------------------------------------------------
def _finite(value, what: str, *, minimum=None, allow_inf=False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} = {value!r} is not a number") from None
    if math.isnan(v) or (math.isinf(v) and not allow_inf):
        raise InputError(f"{what} = {value!r}; expected a finite number")
    if minimum is not None and v < minimum:
        raise InputError(f"{what} = {value!r}; expected a value >= {minimum}")
    return v


def _check_waveform(waveform, coefficients, what: str) -> None:
    if waveform not in WAVEFORMS:
        raise InputError(f"{what}: waveform = {waveform!r}; expected one of {list(WAVEFORMS)}")
    if waveform == "fourier":
        if not isinstance(coefficients, dict) or not coefficients:
            raise InputError(
                f"{what}: waveform 'fourier' needs coefficients = {{n: (a_n, b_n)}}; got "
                f"{coefficients!r}"
            )
        for n, ab in coefficients.items():
            try:
                ok = int(n) >= 0 and int(n) == float(n) and len(ab) == 2
                ok = ok and all(np.isfinite(float(c)) for c in ab)
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise InputError(
                    f"{what}: Fourier coefficient {n!r}: {ab!r}; expected an integer harmonic "
                    "n >= 0 mapped to a pair (a_n, b_n) of finite numbers [N or Pa]"
                )
    elif coefficients is not None:
        raise InputError(f"{what}: coefficients are only used with waveform 'fourier' "
                         f"(waveform is {waveform!r})")


@dataclass
class Material:
    """Isotropic linear elastic material.

    E : Young's modulus [Pa] (> 0); nu : Poisson's ratio [-] (-1 < nu < 0.5);
    rho : density [kg/m^3] (>= 0; 0 for quasi-static analyses).
    """

    E: float
    nu: float
    rho: float = 0.0

    def __post_init__(self):
        self.E, self.nu, self.rho = check_material(self.E, self.nu, self.rho)


@dataclass
class Damping:
    """Linear damping of the structure.

    loss_factor : hysteretic loss factor eta [-]: ``Model.D = eta K`` (dynamic stiffness
        ``K (1 + i eta)`` on harmonics ``n >= 1``).
    rayleigh_mass, rayleigh_stiffness : ``Model.C = a M + b K`` with ``a`` [1/s] and ``b`` [s].
    ``K`` is the stiffness of the structure alone (springs to ground are undamped).
    """

    loss_factor: float = 0.0
    rayleigh_mass: float = 0.0
    rayleigh_stiffness: float = 0.0

    def __post_init__(self):
        self.loss_factor = check_loss_factor(self.loss_factor, "damping loss_factor")
        self.rayleigh_mass = _finite(self.rayleigh_mass, "damping rayleigh_mass", minimum=0.0)
        self.rayleigh_stiffness = _finite(self.rayleigh_stiffness,
                                          "damping rayleigh_stiffness", minimum=0.0)


@dataclass
class Spring:
    """A linear spring to ground.

    at : node-set or boundary name, or coordinates of a node [m].
    direction : ``"x"``, ``"y"``, ``"z"`` or a vector (normalised here).
    stiffness : [N/m], >= 0. It is the *total* stiffness: when ``at`` names several nodes
        each gets ``stiffness / n_nodes`` along ``direction``, so that a rigid translation of
        the set along ``direction`` is resisted by ``stiffness``. ``math.inf`` holds the DOF
        (Dirichlet condition on every node of ``at``); only axis directions are allowed then.
    """

    at: str | tuple
    direction: str | tuple
    stiffness: float

    def __post_init__(self):
        self.stiffness = _finite(self.stiffness, f"spring at {self.at!r}: stiffness",
                                 minimum=0.0, allow_inf=True)


@dataclass
class Traction:
    """A distributed load on a boundary, times a waveform of ``tau = omega t``.

    boundary : boundary name. pressure : [Pa] along the inward normal (positive pushes on the
    body), or a function of coordinates (n, d) -> (n,). traction : vector [Pa] in global
    axes, or a function (n, d) -> (n, d). Give exactly one of them.
    waveform : one of :data:`fretwear.model.core.WAVEFORMS`; ``"constant"`` is a static load.
    coefficients : ``{n: (a_n, b_n)}`` for ``waveform="fourier"``.
    name : label (default ``"traction on <boundary>"``).
    """

    boundary: str
    pressure: float | Callable | None = None
    traction: tuple | Callable | None = None
    waveform: str = "constant"
    name: str | None = None
    coefficients: dict | None = None

    def __post_init__(self):
        what = f"traction on {self.boundary!r}"
        if (self.pressure is None) == (self.traction is None):
            raise InputError(
                f"{what}: give exactly one of pressure (Pa, along the inward normal) and "
                f"traction (vector in Pa); got pressure={self.pressure!r}, "
                f"traction={self.traction!r}"
            )
        _check_waveform(self.waveform, self.coefficients, what)


@dataclass
class NodalForce:
    """A point force, times a waveform of ``tau = omega t``.

    at : node-set or boundary name, or coordinates of a node [m]. force : vector [N] in
    global axes; it is the *total* force, shared equally by the nodes of ``at``.
    waveform, coefficients, name : as for :class:`Traction`.
    """

    at: str | tuple
    force: tuple
    waveform: str = "constant"
    name: str | None = None
    coefficients: dict | None = None

    def __post_init__(self):
        _check_waveform(self.waveform, self.coefficients, f"nodal force at {self.at!r}")


@dataclass
class ContactSpec:
    """A frictional contact interface: a boundary against a rigid obstacle (node-to-rigid),
    or against a second elastic body (node-to-node, ``partner``).

    boundary : boundary name (its nodes are the contact nodes).
    mu : Coulomb friction coefficient [-], >= 0.
    normal : unit vector from the structure into the obstacle (one for every node). Default:
        the outward normal of the boundary: the same for every node on a flat boundary; on a
        curved or multi-flank boundary each node's normal is the area-weighted average of the
        outward normals of the facets around it (two neighbouring facets whose normals turn
        by more than 90 degrees are refused).
    tangent : 2D: the tangent (must be orthogonal to the normal); default
        ``t = (-n_y, n_x)`` or its opposite, whichever has ``t_x > 0`` (``t_y > 0`` if
        ``t_x = 0``), so the bottom face (``n = (0, -1)``) gets ``t = (1, 0)``.
        3D: the first tangent ``t1``, or a pair ``(t1, t2)``; default ``t1`` = projection of
        the x axis on the contact plane (the y axis if the normal is within ~6 degrees of x),
        ``t2 = n x t1``.
    gap : initial normal gap [m] (>= 0 open, < 0 an initial interference), a number or a
        function of the contact node coordinates (nc, d) -> (nc,).
    wear_coefficient : Archard coefficient k_w [1/Pa], >= 0, of the boundary's surface.
    name : label (interfaces of one model have distinct names).
    partner : the boundary of the second body (node-to-node): every contact node is paired
        with the partner node at the same position (within ``tolerance``); the contact law
        acts on their relative displacement, with equal and opposite forces. None:
        node-to-rigid.
    tolerance : largest distance [m] between paired nodes; default ``1e-6`` times the model
        size.
    partner_wear_coefficient : Archard coefficient k_w [1/Pa], >= 0, of the partner's
        surface; the gap opens by the sum of the two worn depths.
    normal_stiffness, tangential_stiffness : contact stiffness per unit area [Pa/m] in series
        with the contact law (:mod:`fretwear.hb.connectors`); each node gets the value times
        its area [N/m]. ``inf`` (default): rigid.
    normal_pressure : friction under a prescribed normal load: the pressure [Pa]; each node
        carries ``pressure x area x g(omega t)`` (``normal_waveform``) whatever its normal
        motion. None (default): unilateral contact.

    Contact nodes are ordered by increasing coordinate along the tangent (2D) or along
    ``t2`` then ``t1`` (3D) of the boundary's mean frame, so that profiles come out ordered.
    Each node's area is its consistent nodal area (see
    :func:`fretwear.model.loads.nodal_areas`).
    """

    boundary: str
    mu: float
    normal: tuple | None = None
    tangent: tuple | None = None
    gap: float | Callable = 0.0
    wear_coefficient: float = 0.0
    name: str = "contact"
    partner: str | None = None
    tolerance: float | None = None
    partner_wear_coefficient: float = 0.0
    normal_stiffness: float = np.inf
    tangential_stiffness: float = np.inf
    normal_pressure: float | None = None
    normal_waveform: str = "constant"

    def __post_init__(self):
        what = f"contact {self.name!r}"
        self.mu = _finite(self.mu, f"{what}: friction coefficient mu", minimum=0.0)
        self.wear_coefficient = _finite(self.wear_coefficient, f"{what}: wear_coefficient",
                                        minimum=0.0)
        self.partner_wear_coefficient = _finite(
            self.partner_wear_coefficient, f"{what}: partner_wear_coefficient", minimum=0.0)
        if self.partner is None and self.partner_wear_coefficient > 0.0:
            raise InputError(f"{what}: partner_wear_coefficient = "
                             f"{self.partner_wear_coefficient!r} without a partner boundary: a "
                             "rigid obstacle does not wear")
        if self.tolerance is not None:
            self.tolerance = _finite(self.tolerance, f"{what}: tolerance", minimum=0.0)
        if not callable(self.gap):
            self.gap = _finite(self.gap, f"{what}: gap")


# --------------------------------------------------------------------------------------------
# locating nodes and directions
# --------------------------------------------------------------------------------------------
def find_node(mesh: Mesh, point, *, tol: float | None = None, what: str = "point") -> int:
    """Number of the node at ``point`` [m].

    Raises InputError if the nearest node is farther than ``tol`` (default ``1e-6`` times the
    model size); ``tol = math.inf`` accepts the nearest node whatever its distance.
    """
    p = np.asarray(point, dtype=float).reshape(-1) if not isinstance(point, str) else None
    if p is None or p.size != mesh.dim or not np.all(np.isfinite(p)):
        raise InputError(f"{what} = {point!r}; expected {mesh.dim} coordinates [m]")
    dist = np.linalg.norm(mesh.points - p, axis=1)
    i = int(np.argmin(dist))
    tol = 1e-6 * model_size(mesh) if tol is None else tol
    if dist[i] > tol:
        raise InputError(
            f"{what} = {tuple(p.tolist())}: no mesh node there (nearest node {i} at "
            f"{tuple(mesh.points[i].tolist())}, {dist[i]:.3g} m away; tolerance {tol:.3g} m)"
        )
    return i


def nodes_at(mesh: Mesh, at, what: str = "at") -> np.ndarray:
    """Nodes named by ``at``: a node-set or boundary name, or coordinates of one node."""
    if isinstance(at, str):
        if at in mesh.node_sets:
            nodes = np.unique(np.asarray(mesh.node_sets[at], dtype=np.int64))
        elif at in mesh.boundaries:
            nodes = np.unique(np.asarray(mesh.boundaries[at], dtype=np.int64))
        else:
            raise InputError(
                f"{what} = {at!r}: no node set or boundary of that name; the mesh has node "
                f"sets {sorted(mesh.node_sets)} and boundaries {sorted(mesh.boundaries)}"
            )
        if nodes.size == 0:
            raise InputError(f"{what} = {at!r} names an empty set of nodes")
        return nodes
    return np.array([find_node(mesh, at, what=what)])


def unit_direction(direction, dim: int, what: str = "direction") -> np.ndarray:
    """Unit vector from ``"x"``, ``"y"``, ``"z"`` or a vector of ``dim`` components."""
    if isinstance(direction, str):
        key = direction.strip().lower()
        if key not in AXES[:dim]:
            raise InputError(
                f"{what} = {direction!r}; expected one of {list(AXES[:dim])} or a vector of "
                f"{dim} components"
            )
        return np.eye(dim)[AXES.index(key)]
    try:
        v = np.asarray(direction, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        v = np.zeros(0)
    big = np.abs(v).max() if v.size == dim and np.all(np.isfinite(v)) else 0.0
    if big > 0.0:  # only the direction counts: scale first so that the norm cannot overflow
        v = v / big
    n = np.linalg.norm(v) if big > 0.0 else 0.0
    if n == 0.0:
        raise InputError(
            f"{what} = {direction!r}; expected one of {list(AXES[:dim])} or a non-zero vector "
            f"of {dim} components"
        )
    return v / n


def _axis_index(direction: np.ndarray) -> int | None:
    big = np.flatnonzero(np.abs(direction) > 1.0 - 1e-12)
    return int(big[0]) if big.size == 1 else None


# --------------------------------------------------------------------------------------------
# pieces of the model
# --------------------------------------------------------------------------------------------
def _springs_and_fixed(mesh: Mesh, springs, fixed) -> tuple[sp.csr_matrix, np.ndarray]:
    d = mesh.dim
    ndof = d * mesh.points.shape[0]
    rows, cols, vals, held = [], [], [], []
    for s in springs:
        if not isinstance(s, Spring):
            raise InputError(f"springs: {s!r} is not a Spring(at, direction, stiffness)")
        what = f"spring at {s.at!r}"
        nodes = nodes_at(mesh, s.at, f"{what}: at")
        n = unit_direction(s.direction, d, f"{what}: direction")
        if math.isinf(s.stiffness):
            axis = _axis_index(n)
            if axis is None:
                raise InputError(
                    f"{what}: an infinite stiffness (fixed DOF) needs an axis direction "
                    f"({list(AXES[:d])}); got direction {s.direction!r}"
                )
            held.append(d * nodes + axis)
            continue
        if s.stiffness == 0.0:
            continue
        k = s.stiffness / nodes.size
        dofs = d * nodes[:, None] + np.arange(d)  # (n, d)
        rows.append(np.repeat(dofs, d, axis=1).ravel())
        cols.append(np.tile(dofs, (1, d)).ravel())
        vals.append(np.tile(k * np.outer(n, n).ravel(), nodes.size))
    for item in fixed:
        if isinstance(item, str) or not isinstance(item, Sequence) or len(item) != 2:
            raise InputError(f"fixed: {item!r}; expected a pair (at, direction) with direction "
                             f"one of {list(AXES[:d])} or 'all'")
        at, direction = item
        nodes = nodes_at(mesh, at, f"fixed {item!r}: at")
        if isinstance(direction, str) and direction.strip().lower() == "all":
            held.append((d * nodes[:, None] + np.arange(d)).ravel())
            continue
        axis = _axis_index(unit_direction(direction, d, f"fixed {item!r}: direction"))
        if axis is None:
            raise InputError(f"fixed {item!r}: direction must be an axis {list(AXES[:d])} or "
                             f"'all'; got {direction!r}")
        held.append(d * nodes + axis)
    if rows:
        Ks = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                           shape=(ndof, ndof))
    else:
        Ks = sp.csr_matrix((ndof, ndof))
    fixed_dofs = np.unique(np.concatenate(held)) if held else np.zeros(0, dtype=np.int64)
    return Ks, fixed_dofs.astype(np.int64)


def _loads(mesh: Mesh, loads, thickness: float) -> list[Load]:
    d = mesh.dim
    ndof = d * mesh.points.shape[0]
    out = []
    for item in loads:
        if isinstance(item, Traction):
            vec = boundary_load(mesh, item.boundary, pressure=item.pressure,
                                traction=item.traction, thickness=thickness)
            name = item.name or f"traction on {item.boundary}"
        elif isinstance(item, NodalForce):
            nodes = nodes_at(mesh, item.at, f"nodal force at {item.at!r}")
            f = np.asarray(item.force, dtype=float).reshape(-1)
            if f.size != d or not np.all(np.isfinite(f)):
                raise InputError(f"nodal force at {item.at!r}: force = {item.force!r}; "
                                 f"expected {d} finite components [N]")
            vec = np.zeros(ndof)
            vec.reshape(-1, d)[nodes] += f / nodes.size
            name = item.name or f"force at {item.at}"
        elif isinstance(item, Load):
            vec = np.asarray(item.vector, dtype=float)
            if vec.shape != (ndof,):
                raise InputError(f"load {item.name!r}: vector of shape {vec.shape}; expected "
                                 f"({ndof},) for this mesh")
            _check_waveform(item.waveform, item.coefficients, f"load {item.name!r}")
            out.append(Load(vec.copy(), item.waveform, item.coefficients, item.name))
            continue
        else:
            raise InputError(f"loads: {item!r} is not a Traction, NodalForce or Load")
        out.append(Load(vec, item.waveform, item.coefficients, name))
    return out


def _tangents(n: np.ndarray, tangent, what: str) -> np.ndarray:
    """Rows ``[n, t1(, t2)]`` of an orthonormal contact frame (no negative zeros)."""
    return _frame(n, tangent, what) + 0.0


def _frame(n: np.ndarray, tangent, what: str) -> np.ndarray:
    d = n.size
    if d == 2:
        t = np.array([-n[1], n[0]])
        if tangent is not None:
            given = unit_direction(tangent, 2, f"{what}: tangent")
            if abs(given @ n) > 1e-6:
                raise InputError(f"{what}: tangent {tangent!r} is not orthogonal to the normal "
                                 f"{tuple(n.tolist())}")
            t = given
        elif t[0] < -1e-12 or (abs(t[0]) <= 1e-12 and t[1] < 0):
            t = -t
        return np.vstack([n, t])
    if tangent is None:
        e = np.eye(3)[0] if abs(n[0]) < 0.995 else np.eye(3)[1]
        t1 = e - (e @ n) * n
        t1 /= np.linalg.norm(t1)
        return np.vstack([n, t1, np.cross(n, t1)])
    arr = np.asarray(tangent, dtype=object)
    pair = arr.ndim == 2 or (arr.ndim == 1 and arr.size == 2 and not np.isscalar(arr[0]))
    vecs = [unit_direction(v, 3, f"{what}: tangent") for v in (tangent if pair else [tangent])]
    t1 = vecs[0]
    t2 = vecs[1] if pair else np.cross(n, t1)
    F = np.vstack([n, t1, t2])
    if np.abs(F @ F.T - np.eye(3)).max() > 1e-6:
        raise InputError(f"{what}: normal {tuple(n.tolist())} and tangent(s) {tangent!r} are "
                         "not orthonormal")
    return F


def nodal_normals(mesh: Mesh, facets: np.ndarray, nodes: np.ndarray,
                  what: str = "boundary") -> np.ndarray:
    """Outward unit normals (n, d) at ``nodes``: the area-weighted average of the outward
    normals of the (outward-oriented) ``facets`` around each node.

    Raises InputError for a node without facets or with a vanishing average, and where two
    facets around one node have normals more than 90 degrees apart (a boundary that folds
    back: its normal flips between neighbours).
    """
    v = np.asarray(mesh_facet_vectors(mesh, facets), dtype=float)  # |v| ~ facet measure
    unit = v / np.linalg.norm(v, axis=1, keepdims=True)
    pos = np.full(mesh.points.shape[0], -1, dtype=np.int64)
    pos[nodes] = np.arange(nodes.size)
    total = np.zeros((nodes.size, mesh.dim))
    k = facets.shape[1]
    for j in range(k):
        np.add.at(total, pos[facets[:, j]], v)
    # the most opposed pair of facets around each node
    for j in range(k):
        p = pos[facets[:, j]]
        mean = total[p] / np.linalg.norm(total[p], axis=1, keepdims=True)
        cos = np.einsum("ij,ij->i", unit, mean)
        bad = np.flatnonzero(~(cos > 0.0))
        if bad.size:
            node = int(facets[bad[0], j])
            raise InputError(
                f"{what}: the outward normals flip between neighbouring facets at node {node} "
                f"{tuple(np.round(mesh.points[node], 12).tolist())} (more than 90 degrees "
                "apart): split the boundary into flanks, one interface each"
            )
    norm = np.linalg.norm(total, axis=1)
    return total / norm[:, None]


def mesh_facet_vectors(mesh: Mesh, facets: np.ndarray) -> np.ndarray:
    """Outward normals of oriented facets scaled by the facet's length or area (nf, d)."""
    n = facet_normals(mesh, facets)
    p = mesh.points[facets]
    if facets.shape[1] == 2:
        size = np.linalg.norm(p[:, 1] - p[:, 0], axis=1)
    elif facets.shape[1] == 3:
        size = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    else:
        size = 0.5 * np.linalg.norm(np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1]), axis=1)
    return n * size[:, None]


def match_nodes(mesh: Mesh, nodes: np.ndarray, partner: str, tolerance: float | None,
                what: str) -> np.ndarray:
    """The node of boundary ``partner`` at the position of each of ``nodes`` (n,).

    Raises InputError naming the first node without a partner within ``tolerance`` [m]
    (default ``1e-6`` times the model size), its position and the distance to the nearest
    partner node, and a partner node matched twice.
    """
    from scipy.spatial import cKDTree  # lazy: scipy.spatial is slow to import

    if partner not in mesh.boundaries:
        raise InputError(f"{what}: unknown partner boundary {partner!r}; the mesh has "
                         f"boundaries {sorted(mesh.boundaries)}")
    cand = np.unique(_boundary(mesh, partner))
    if cand.size == 0:
        raise InputError(f"{what}: partner boundary {partner!r} is empty")
    tol = 1e-6 * model_size(mesh) if tolerance is None else tolerance
    dist, idx = cKDTree(mesh.points[cand]).query(mesh.points[nodes])
    far = np.flatnonzero(dist > tol)
    if far.size:
        i = int(far[np.argmax(dist[far])])
        raise InputError(
            f"{what}: node {int(nodes[i])} at {tuple(np.round(mesh.points[nodes[i]], 12).tolist())}"
            f" has no node of boundary {partner!r} within {tol:.3g} m (nearest: node "
            f"{int(cand[idx[i]])}, {dist[i]:.3g} m away; {far.size} such nodes): the two "
            "boundaries need matching nodes (or a larger tolerance)"
        )
    out = cand[idx]
    same = np.intersect1d(out, nodes)
    if same.size:
        raise InputError(f"{what}: node {int(same[0])} is on both boundaries of the pair; the "
                         "two bodies need their own nodes at the interface")
    values, counts = np.unique(out, return_counts=True)
    if np.any(counts > 1):
        j = int(values[counts > 1][0])
        raise InputError(f"{what}: node {j} of boundary {partner!r} is the partner of "
                         f"{int(counts.max())} contact nodes; expected one-to-one pairs")
    return out


def _contact(mesh: Mesh, spec: ContactSpec, thickness: float) -> ContactInterface:
    if not isinstance(spec, ContactSpec):
        raise InputError(f"contact: {spec!r} is not a ContactSpec")
    what = f"contact {spec.name!r}"
    if spec.boundary not in mesh.boundaries:
        hint = " (a node set: contact needs a boundary of facets)" \
            if spec.boundary in mesh.node_sets else ""
        raise InputError(f"{what}: unknown boundary {spec.boundary!r}{hint}; the mesh has "
                         f"boundaries {sorted(mesh.boundaries)}")
    facets = _boundary(mesh, spec.boundary)
    if facets.shape[0] == 0:
        raise InputError(f"{what}: boundary {spec.boundary!r} is empty: no contact nodes")
    facets = orient_facets(mesh, facets, f"boundary {spec.boundary!r}")
    outward = facet_normals(mesh, facets)
    mean = outward.mean(axis=0)
    mean /= np.linalg.norm(mean)
    nodes, area = nodal_areas(mesh, spec.boundary, thickness)
    if np.any(~(area > 0.0)):
        i = int(np.flatnonzero(~(area > 0.0))[0])
        raise InputError(f"{what}: node {int(nodes[i])} at "
                         f"{tuple(np.round(mesh.points[nodes[i]], 12).tolist())} has a zero "
                         f"contact area ({area[i]:.3g} m^2): degenerate facets on boundary "
                         f"{spec.boundary!r}")
    per_node = None
    if spec.normal is None:
        dev = np.linalg.norm(outward - mean, axis=1).max()
        n = mean
        if dev > 1e-6:  # curved or multi-flank: one normal per node
            per_node = nodal_normals(mesh, facets, nodes, f"{what}: boundary {spec.boundary!r}")
    else:
        n = unit_direction(spec.normal, mesh.dim, f"{what}: normal")
        if n @ mean <= 0.0:
            raise InputError(
                f"{what}: normal {spec.normal!r} points into the structure; it must point from "
                f"the structure into the obstacle (the boundary's outward normal is "
                f"{tuple(np.round(mean, 6).tolist())})"
            )
    frame = _tangents(n, spec.tangent, what)

    coords = mesh.points[nodes]
    if mesh.dim == 2:
        order = np.argsort(coords @ frame[1], kind="stable")
    else:
        order = np.lexsort((coords @ frame[1], coords @ frame[2]))
    nodes, area, coords = nodes[order], area[order], coords[order]
    nc, d = nodes.size, mesh.dim
    if per_node is None:
        frames = np.broadcast_to(frame, (nc, d, d)).copy()
    else:
        frames = np.array([_node_frame(v, frame, spec.tangent, what)
                           for v in per_node[order]])

    if callable(spec.gap):
        gap = np.asarray(spec.gap(coords.copy()), dtype=float)
        if gap.shape != (nc,) or not np.all(np.isfinite(gap)):
            raise InputError(f"{what}: the gap function returned shape {gap.shape}; expected "
                             f"({nc},) finite values [m] for the {nc} contact nodes")
    else:
        gap = np.full(nc, float(spec.gap))
    partner = dict(partner_dofs=None, partner_ids=None)
    if spec.partner is not None:
        other = match_nodes(mesh, nodes, spec.partner, spec.tolerance, what)
        partner = dict(partner_dofs=d * other[:, None] + np.arange(d), partner_ids=other)
    return ContactInterface(
        dofs=d * nodes[:, None] + np.arange(d),
        frame=frames,
        gap=gap,
        area=area,
        mu=spec.mu,
        coords=coords,
        node_ids=nodes,
        wear_coefficient=spec.wear_coefficient,
        name=spec.name,
        partner_wear_coefficient=spec.partner_wear_coefficient,
        normal_load=(None if spec.normal_pressure is None else
                     Load(float(spec.normal_pressure) * area, spec.normal_waveform, None,
                          "normal load")),
        kn=_contact_stiffness(spec.normal_stiffness, area, f"{what}: normal_stiffness"),
        kt=_contact_stiffness(spec.tangential_stiffness, area,
                              f"{what}: tangential_stiffness"),
        **partner,
    )


def _node_frame(n: np.ndarray, mean_frame: np.ndarray, tangent, what: str) -> np.ndarray:
    """The frame of one node of a curved boundary: its normal ``n``; 2D: the tangent turned
    from the normal, signed like the mean frame's; 3D: ``t1`` the projection of the mean
    frame's ``t1`` on the node's tangent plane (continuous along the boundary)."""
    if n.size == 2:
        t = np.array([-n[1], n[0]])
        if t @ mean_frame[1] < 0.0:
            t = -t
        return np.vstack([n, t]) + 0.0
    t1 = mean_frame[1] - (mean_frame[1] @ n) * n
    if np.linalg.norm(t1) < 1e-6:
        t1 = mean_frame[2] - (mean_frame[2] @ n) * n
    t1 /= np.linalg.norm(t1)
    return np.vstack([n, t1, np.cross(n, t1)]) + 0.0


def _contact_stiffness(per_area, area, what: str):
    """Per-node contact stiffness [N/m] from a stiffness per unit area [Pa/m]; None if rigid."""
    k = float(per_area)
    if not k > 0:
        raise InputError(f"{what} = {per_area!r}: expected a stiffness per area > 0 [Pa/m] "
                         "(inf: rigid)")
    return None if math.isinf(k) else k * np.asarray(area, float)


def _observed(mesh: Mesh, observed) -> list[ObservedPoint]:
    if observed is None:
        return []
    if not isinstance(observed, dict):
        raise InputError(f"observed = {observed!r}; expected a dict name -> coordinates")
    out = []
    d = mesh.dim
    for name, where in observed.items():
        if isinstance(where, str):
            nodes = nodes_at(mesh, where, f"observed {name!r}")
            if nodes.size != 1:
                raise InputError(f"observed {name!r}: {where!r} holds {nodes.size} nodes; "
                                 "expected a single node or coordinates")
            i = int(nodes[0])
        else:
            i = find_node(mesh, where, tol=math.inf, what=f"observed {name!r}")
        out.append(ObservedPoint(str(name), d * i + np.arange(d), mesh.points[i].copy()))
    return out


# --------------------------------------------------------------------------------------------
# the model
# --------------------------------------------------------------------------------------------
def from_mesh(mesh: Mesh, material: Material, *, thickness=1.0, damping: Damping | None = None,
              springs=(), fixed=(), loads=(), contact, observed=None,
              name: str = "model") -> Model:
    """A linear elastic model of a mesh with one or several contact interfaces.

    Parameters
    ----------
    mesh : Mesh
        2D (plane strain) or 3D mesh (:mod:`fretwear.model.mesh`).
    material : Material, or dict body -> Material
        One material, or one per body: ``body`` names a node set (e.g. the body names of
        :func:`fretwear.model.mesh.join`); a cell belongs to the body that holds all its
        nodes, and every cell must belong to exactly one body, or to the key ``None``
        (every cell of no listed body).
    thickness : float
        Out-of-plane width [m] of a 2D mesh; 1 in 3D.
    damping : Damping, optional
    springs : sequence of Spring
        Springs to ground, added to ``K`` (infinite ones become fixed DOFs).
    fixed : sequence of (at, direction)
        DOFs held at zero; ``direction`` is an axis name or ``"all"``.
    loads : sequence of Traction, NodalForce or core.Load
    contact : ContactSpec or sequence of ContactSpec
        The interfaces (node-to-rigid, or node-to-node with ``partner``), one record for
        all (:func:`fretwear.model.interfaces.combine`: a node belongs to one interface).
    observed : dict, optional
        name -> coordinates [m] (the nearest node, reported with its exact coordinates) or
        the name of a one-node node set.
    name : str

    Returns
    -------
    Model
        ``K`` = structure + springs, ``M``, ``C``/``D`` from ``damping``, node-major DOFs.

    Raises
    ------
    InputError
        For any bad input, a contact node with a fixed DOF, or a structure that only
        friction could hold (:func:`check_supported`).
    """
    if not isinstance(mesh, Mesh):
        raise InputError(f"mesh = {mesh!r} is not a fretwear Mesh")
    check_cells(mesh)
    if damping is not None and not isinstance(damping, Damping):
        raise InputError(f"damping = {damping!r} is not a Damping(...)")
    thickness = check_thickness(thickness, mesh.dim)
    if isinstance(material, dict):
        K0, M = _assemble_bodies(mesh, material, thickness)
        material = next(iter(material.values()))
    elif not isinstance(material, Material):
        raise InputError(f"material = {material!r} is not a Material(E, nu, rho)")
    else:
        K0, M = assemble(mesh, material.E, material.nu, material.rho, thickness)
    Ks, fixed_dofs = _springs_and_fixed(mesh, springs, fixed)
    specs = [contact] if isinstance(contact, ContactSpec) else list(contact) \
        if isinstance(contact, Sequence) and not isinstance(contact, str) else [contact]
    interface = combine([_contact(mesh, spec, thickness) for spec in specs])
    clash = np.intersect1d(interface.dofs.ravel(), fixed_dofs)
    if clash.size:
        node = int(clash[0]) // mesh.dim
        which = interface.names()[int(interface.interface_index()[
            np.flatnonzero(np.any(interface.dofs == clash[0], axis=1))[0]])]
        raise InputError(
            f"contact {which!r}: node {node} at {tuple(mesh.points[node].tolist())} "
            f"is a contact node with a fixed DOF ({AXES[int(clash[0]) % mesh.dim]}); contact "
            "DOFs cannot be fixed: hold the structure at nodes off the contact boundary, or "
            "use a stiff finite spring"
        )
    C = D = None
    if damping is not None:
        if damping.loss_factor > 0.0:
            D = (damping.loss_factor * K0).tocsr()
        if damping.rayleigh_mass > 0.0 or damping.rayleigh_stiffness > 0.0:
            C = (damping.rayleigh_mass * M + damping.rayleigh_stiffness * K0).tocsr()
    model = Model(
        K=(K0 + Ks).tocsr(),
        M=M,
        contact=interface,
        C=C,
        D=D,
        loads=_loads(mesh, loads, thickness),
        observed=_observed(mesh, observed),
        fixed_dofs=fixed_dofs,
        dim=mesh.dim,
        mesh=mesh,
        thickness=thickness if mesh.dim == 2 else 1.0,
        name=str(name),
        meta={"source": "mesh", "material": {"E": material.E, "nu": material.nu,
                                              "rho": material.rho}},
    )
    check_supported(model)
    return model


def _assemble_bodies(mesh: Mesh, materials: dict, thickness: float):
    """``K, M`` of a mesh whose bodies (node sets) have their own materials."""
    nn, d = mesh.points.shape
    cells = np.asarray(mesh.cells, dtype=np.int64)
    owner = np.full(cells.shape[0], -1, dtype=np.int64)
    K = sp.csr_matrix((d * nn, d * nn))
    M = sp.csr_matrix((d * nn, d * nn))
    named = [(b, m) for b, m in materials.items() if b is not None]
    if None in materials:  # the cells of no listed body
        named.append((None, materials[None]))
    for b, (body, mat) in enumerate(named):
        if not isinstance(mat, Material):
            raise InputError(f"material[{body!r}] = {mat!r} is not a Material(E, nu, rho)")
        if body is None:
            mine = np.flatnonzero(owner < 0)
            if mine.size == 0:
                continue
        elif body not in mesh.node_sets:
            raise InputError(f"material: no body (node set) named {body!r}; the mesh has node "
                             f"sets {sorted(mesh.node_sets)}")
        else:
            inside = np.zeros(nn, dtype=bool)
            inside[np.asarray(mesh.node_sets[body], dtype=np.int64)] = True
            mine = np.flatnonzero(np.all(inside[cells], axis=1))
        twice = mine[owner[mine] >= 0]
        if twice.size:
            raise InputError(f"material: cell {int(twice[0])} belongs to two bodies "
                             f"({named[owner[twice[0]]][0]!r} and {body!r})")
        owner[mine] = b
        nodes = np.unique(cells[mine])
        local = np.full(nn, -1, dtype=np.int64)
        local[nodes] = np.arange(nodes.size)
        part = Mesh(mesh.points[nodes], local[cells[mine]], mesh.cell_type)
        Kb, Mb = assemble(part, mat.E, mat.nu, mat.rho, thickness)
        dofs = (d * nodes[:, None] + np.arange(d)).ravel()
        S = sp.csr_matrix((np.ones(dofs.size), (dofs, np.arange(dofs.size))),
                          shape=(d * nn, dofs.size))
        K = K + S @ Kb @ S.T
        M = M + S @ Mb @ S.T
    if np.any(owner < 0):
        c = int(np.flatnonzero(owner < 0)[0])
        raise InputError(f"material: cell {c} (nodes {cells[c].tolist()}) belongs to none of the "
                         f"bodies {list(materials)}")
    return K.tocsr(), M.tocsr()


# --------------------------------------------------------------------------------------------
# support checks
# --------------------------------------------------------------------------------------------
def rigid_body_modes(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Rigid-body displacement fields of a set of nodes.

    Returns
    -------
    R : (ndof, 3) in 2D, (ndof, 6) in 3D
        Columns: unit translations along x, y(, z), then rotations about the z axis (2D) or
        about x, y, z (3D) through the centroid, scaled by ``1 / size`` so that every entry
        is at most about 1 [m/m].
    centre : (d,) centroid [m]; size : bounding-box diagonal [m].
    """
    points = np.asarray(points, dtype=float)
    nn, d = points.shape
    centre = points.mean(axis=0)
    size = float(np.linalg.norm(np.ptp(points, axis=0))) or 1.0
    x = (points - centre) / size
    if d == 2:
        rot = [np.column_stack([-x[:, 1], x[:, 0]])]
    else:
        rot = [np.cross(e, x) for e in np.eye(3)]
    cols = [np.tile(e, nn) for e in np.eye(d)] + [r.ravel() for r in rot]
    return np.column_stack(cols), centre, size


def _rref(N: np.ndarray) -> np.ndarray:
    """Reduced row echelon form of the rows of N (k, nr), to describe motions simply."""
    A = N.copy()
    r = 0
    for c in range(A.shape[1]):
        if r == A.shape[0]:
            break
        p = r + int(np.argmax(np.abs(A[r:, c])))
        if abs(A[p, c]) < 1e-8:
            continue
        A[[r, p]] = A[[p, r]]
        A[r] /= A[r, c]
        others = np.arange(A.shape[0]) != r
        A[others] -= np.outer(A[others, c], A[r])
        r += 1
    A[np.abs(A) < 1e-10] = 0.0
    return A[:r]


def _fmt_vec(v: np.ndarray) -> str:
    axis = _axis_index(v / np.linalg.norm(v))
    if axis is not None:
        return AXES[axis]
    return "(" + ", ".join(f"{c:.3g}" for c in v / np.linalg.norm(v)) + ")"


def _describe(a: np.ndarray, d: int, centre: np.ndarray, size: float) -> str:
    """Words for the rigid motion with coefficients ``a`` on :func:`rigid_body_modes`."""
    t = a[:d]
    w = a[d:] / size  # rotation per unit of the coefficient [rad]
    if np.linalg.norm(w) * size < 1e-9:
        return f"translate along {_fmt_vec(t)}"
    pt = lambda p: "(" + ", ".join(  # noqa: E731
        f"{c:.4g}" for c in np.round(p / size, 5) * size + 0.0) + ")"
    if d == 2:
        w = float(w[0])
        p = centre + np.array([-t[1], t[0]]) / w
        return f"rotate about the z axis through {pt(p)}"
    p = centre + np.cross(w, t) / (w @ w)
    slide = (w @ t) / np.linalg.norm(w)
    extra = " and slide along it" if abs(slide) > 1e-9 * np.linalg.norm(t) + 1e-300 else ""
    return f"rotate about an axis along {_fmt_vec(w)} through {pt(p)}{extra}"


def check_supported(model: Model) -> None:
    """Refuse a model that only friction could hold.

    With every contact node held in its normal direction and every fixed DOF held, ``K``
    must be non-singular. For a model with a mesh, the rigid-body modes of the nodes are
    tested exactly (a mode is free if it moves no held direction and costs no strain or
    spring energy); for a model from matrices :func:`rigid_motion_check` is used.

    Raises
    ------
    InputError
        Naming the free motion(s), e.g. "the structure can translate along x".
    """
    if model.mesh is None:
        c = model.contact
        normal_dofs = c.dofs[np.arange(c.n_nodes), np.argmax(np.abs(c.frame[:, 0, :]), axis=1)]
        # pairs: in the relative coordinates the normal DOF of node a holds n . (U_a - U_b)
        rigid_motion_check(relative_model(model)[0].K, np.union1d(normal_dofs,
                                                                  model.fixed_dofs))
        return
    d = model.dim
    points = model.mesh.points
    body = bodies(model.mesh)
    nb = int(body.max()) + 1
    # the rigid-body modes of every body (a mesh of several bodies: join, node-to-node pairs)
    parts = []
    for k in range(nb):
        nodes = np.flatnonzero(body == k)
        Rk, centre_k, size_k = rigid_body_modes(points[nodes])
        dofs = (d * nodes[:, None] + np.arange(d)).ravel()
        Rfull = np.zeros((model.ndof, Rk.shape[1]))
        Rfull[dofs] = Rk
        parts.append((Rfull, centre_k, size_k, int(nodes[0])))
    R = np.hstack([p[0] for p in parts])
    c = model.contact
    # K R vanishes for the elastic structure (up to rounding); what remains is the springs'
    # reaction to each rigid mode. Entries within a rounding bound are cleared, and each
    # remaining row (a DOF with a spring) becomes a constraint like a held DOF.
    KR = model.K @ R
    KR[np.abs(KR) <= 64 * np.finfo(float).eps * (abs(model.K) @ np.abs(R))] = 0.0
    springs = KR[np.any(KR != 0.0, axis=1)]
    springs = springs / np.linalg.norm(springs, axis=1, keepdims=True)
    Rrel = R[c.dofs]
    if c.has_pairs:  # a pair holds the relative normal displacement n . (U_a - U_b)
        pd = np.asarray(c.partner_dofs)
        Rrel = Rrel - np.where(pd[..., None] >= 0, R[np.maximum(pd, 0)], 0.0)
    A = np.vstack([
        np.einsum("nd,ndr->nr", c.frame[:, 0, :], Rrel),
        R[np.asarray(model.fixed_dofs, dtype=np.int64)],
        springs,
    ])
    _, s, Vt = np.linalg.svd(A)
    rank = int(np.sum(s > 1e-8 * max(1.0, s.max(initial=0.0))))
    free = Vt[rank:].T  # rigid motions that move no held direction and strain no spring
    if free.shape[1] == 0:
        return
    nr = parts[0][0].shape[1]
    motions = []
    for a in _rref(free.T):
        k = int(np.argmax([np.abs(a[j * nr:(j + 1) * nr]).max() for j in range(nb)]))
        _, centre_k, size_k, first = parts[k]
        words = _describe(a[k * nr:(k + 1) * nr], d, centre_k, size_k)
        if nb > 1:
            others = [j for j in range(nb) if j != k and np.abs(a[j * nr:(j + 1) * nr]).max()
                      > 1e-8]
            who = f"the body of node {first}" + (" (with others)" if others else "")
            words = f"{who} can {words}"
        motions.append(words)
    hint = ", ".join(f"Spring(at, {AXES[i]!r}, stiffness)" for i in range(d))
    lead = "the structure can " if nb == 1 else ""
    raise InputError(
        "with the contact held only along its normal (frictionless), " + lead
        + (", ".join(motions[:-1]) + " and " if len(motions) > 1 else "") + motions[-1]
        + " with nothing to hold it but friction: add a spring or a fixed DOF (springs = ["
        + hint + "] or fixed = [(at, direction)]) at a node off the contact boundary"
    )


def bodies(mesh: Mesh) -> np.ndarray:
    """The body of every node (nn,) int: the connected components of the mesh's cells."""
    from scipy.sparse.csgraph import connected_components

    cells = np.asarray(mesh.cells, dtype=np.int64)
    nn = mesh.points.shape[0]
    k = cells.shape[1]
    rows = np.repeat(cells, k, axis=1).ravel()
    cols = np.tile(cells, (1, k)).ravel()
    graph = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(nn, nn))
    return connected_components(graph, directed=False)[1]


def rigid_motion_check(K, held_dofs, *, dense_limit: int = 600) -> None:
    """Refuse a stiffness matrix that is singular once ``held_dofs`` are held.

    The matrix restricted to the other DOFs is scaled to unit diagonal and its smallest
    eigenvalues are computed (dense below ``dense_limit`` DOFs, else shift-invert Lanczos);
    an eigenvalue below ``1e-12`` times the largest (a zero-energy motion up to rounding)
    means the structure can move with nothing but friction to hold it.

    Parameters
    ----------
    K : (n, n) sparse or dense symmetric stiffness [N/m]
    held_dofs : int array
        DOFs held (contact normal DOFs and fixed DOFs).

    Raises
    ------
    InputError
        Naming the DOFs that move in a zero-energy motion.
    """
    K = sp.csr_matrix(K)
    n = K.shape[0]
    mask = np.ones(n, dtype=bool)
    mask[np.asarray(held_dofs, dtype=np.int64)] = False
    free = np.flatnonzero(mask)
    if free.size == 0:
        return
    Kff = K[free][:, free]
    diag = Kff.diagonal()
    zero = np.flatnonzero(diag <= 0.0)
    if zero.size:
        raise InputError(
            f"DOF(s) {free[zero][:10].tolist()} have no stiffness (diagonal of K <= 0) and are "
            "neither contact normal DOFs nor fixed: nothing holds them but friction; add "
            "stiffness (a spring to ground) or fix them (fixed_dofs)"
        )
    s = 1.0 / np.sqrt(diag)
    S = sp.diags(s) @ Kff @ sp.diags(s)
    scale = float(abs(S).sum(axis=1).max())  # >= largest eigenvalue
    if free.size <= dense_limit:
        lam, V = sla.eigh(S.toarray())
        lam, V = lam[:6], V[:, :6]
    else:
        lam, V = spla.eigsh(S.tocsc(), k=6, sigma=-1e-6 * scale, which="LM")
    bad = lam < 1e-12 * scale
    if not np.any(bad):
        return
    u = s * V[:, int(np.argmin(lam))]
    moving = free[np.abs(u) > 0.1 * np.abs(u).max()]
    listed = moving[:10].tolist() + (["..."] if moving.size > 10 else [])
    raise InputError(
        f"the stiffness matrix with the contact normal DOFs and the fixed DOFs held is "
        f"singular ({int(bad.sum())} zero-energy motion(s)): DOFs {listed} can move with "
        "nothing to hold them but friction; add stiffness there (a spring to ground) or fix "
        "DOFs (fixed_dofs)"
    )
