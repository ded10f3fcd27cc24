"""Build a :class:`~fretwear.model.core.Model` from a finite element mesh.

The user describes the structure with small dataclasses (:class:`Material`, :class:`Damping`,
:class:`Spring`, :class:`Traction`, :class:`NodalForce`, :class:`ContactSpec`) and calls
:func:`from_mesh`. Every input is checked and a bad one raises
:class:`~fretwear.errors.InputError` naming the value and what is expected.

Places (``at=``) are given either as the name of a node set or boundary of the mesh (all its
nodes) or as a coordinate tuple (the node at that point, within ``1e-6`` of the model size;
:mod:`fretwear.model.places`).

The model is refused when the contact alone cannot hold it
(:func:`fretwear.model.supports.check_supported`).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.limits import RANGES, UnusualValueWarning, check_loss_factor, unusual
from fretwear.model.checks import check_mesh
from fretwear.model.core import WAVEFORMS, ContactInterface, Load, Mesh, Model, ObservedPoint
from fretwear.model.fem import assemble, check_material, check_thickness
from fretwear.model.interfaces import combine
from fretwear.model.loads import boundary_load, nodal_areas
from fretwear.model.mesh import boundary as _boundary
from fretwear.model.mesh import check_cells, facet_normals, orient_facets
from fretwear.model.pairing import check_pairing, pair
from fretwear.model.places import AXES, axis_index, find_node, nodes_at, unit_direction
from fretwear.model.regions import region_nodes, restricted
from fretwear.model.supports import check_supported
from fretwear.validate import is_real, number

# --------------------------------------------------------------------------------------------
# input dataclasses
# --------------------------------------------------------------------------------------------
#: the largest magnitude of a stiffness, pressure, force or damping coefficient of a model (far
#: beyond any structure; a larger one is a typo, and would make the matrices overflow)
MAGNITUDE_MAX = 1e20


def _finite(value, what: str, *, minimum=None, allow_inf=False) -> float:
    v = number(value, what, low=minimum, allow_inf=allow_inf)
    if math.isfinite(v) and abs(v) > MAGNITUDE_MAX:
        raise InputError(f"{what} = {value!r}; expected a magnitude at most {MAGNITUDE_MAX:g}"
                         + (" (inf for rigid)" if allow_inf else ""))
    return v


def _warn_unusual(*checks) -> None:
    """A UserWarning for each ``(value, kind, what)`` that is legal but almost surely a unit
    mistake (:func:`fretwear.limits.unusual`)."""
    for value, kind, what in checks:
        note = unusual(value, kind, what)
        if note:
            warnings.warn(note, UnusualValueWarning, stacklevel=4)


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
        _warn_unusual((self.E, "modulus", "Material: E"), (self.rho, "density", "Material: rho"))


@dataclass
class Damping:
    """Linear damping of the structure.

    loss_factor : hysteretic loss factor eta [-]: ``Model.D = eta K`` (dynamic stiffness
        ``K (1 + i eta)`` on harmonics ``n >= 1``).
    rayleigh_mass, rayleigh_stiffness : ``Model.C = a M + b K`` with ``a`` [1/s] and ``b`` [s].
    ``K`` is the stiffness of the structure alone (springs to ground are undamped).
    C, D : viscous [N s/m] and hysteretic [N/m] damping matrices on the DOFs of user matrices
        (:func:`fretwear.model.matrices.from_matrices` only): ``C`` is added to the Rayleigh
        damping; ``D`` is the hysteretic damping instead of ``loss_factor`` (not both).
    """

    loss_factor: float = 0.0
    rayleigh_mass: float = 0.0
    rayleigh_stiffness: float = 0.0
    C: object = field(default=None, repr=False, compare=False)
    D: object = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        if not is_real(self.loss_factor):  # not "1" or True, as a case file could not write
            raise InputError(f"damping loss_factor = {self.loss_factor!r} is not a number")
        self.loss_factor = check_loss_factor(self.loss_factor, "damping loss_factor")
        self.rayleigh_mass = _finite(self.rayleigh_mass, "damping rayleigh_mass", minimum=0.0)
        self.rayleigh_stiffness = _finite(self.rayleigh_stiffness,
                                          "damping rayleigh_stiffness", minimum=0.0)
        if self.D is not None and self.loss_factor > 0.0:
            raise InputError("give either D or loss_factor (D = loss_factor * K), not both")


@dataclass
class Spring:
    """A linear spring to ground.

    at : node-set or boundary name, or coordinates of a node [m].
    direction : ``"x"``, ``"y"``, ``"z"`` or a vector (normalised here).
    stiffness : [N/m], >= 0. It is the *total* stiffness: when ``at`` names several nodes
        each gets ``stiffness / n_nodes`` along ``direction``, so that a rigid translation of
        the set along ``direction`` is resisted by ``stiffness``. ``math.inf`` holds the DOF
        (Dirichlet condition on every node of ``at``); only axis directions are allowed then.
    region : only the nodes of ``at`` in these coordinate ranges ``{"x": (x0, x1), ...}`` [m]
        (:mod:`fretwear.model.regions`). None: all of them.
    """

    at: str | tuple
    direction: str | tuple
    stiffness: float
    region: dict | None = None

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
    region : only the facets of ``boundary`` in these coordinate ranges
        ``{"x": (x0, x1), ...}`` [m] (:mod:`fretwear.model.regions`). None: all of them.
    """

    boundary: str
    pressure: float | Callable | None = None
    traction: tuple | Callable | None = None
    waveform: str = "constant"
    name: str | None = None
    coefficients: dict | None = None
    region: dict | None = None

    def __post_init__(self):
        what = f"traction on {self.boundary!r}"
        if (self.pressure is None) == (self.traction is None):
            raise InputError(
                f"{what}: give exactly one of pressure (Pa, along the inward normal) and "
                f"traction (vector in Pa); got pressure={self.pressure!r}, "
                f"traction={self.traction!r}"
            )
        if self.pressure is not None and not callable(self.pressure):
            self.pressure = _finite(self.pressure, f"{what}: pressure")
        _check_waveform(self.waveform, self.coefficients, what)


@dataclass
class NodalForce:
    """A point force, times a waveform of ``tau = omega t``.

    at : node-set or boundary name, or coordinates of a node [m]. force : vector [N] in
    global axes; it is the *total* force, shared equally by the nodes of ``at``.
    waveform, coefficients, name, region : as for :class:`Traction` (``region``: only the
    nodes of ``at`` in the ranges share the force).
    """

    at: str | tuple
    force: tuple
    waveform: str = "constant"
    name: str | None = None
    coefficients: dict | None = None
    region: dict | None = None

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
    partner : the boundary of the second body: every contact node is paired with the
        partner node at the same position (node-to-node), or with the closest point of a
        partner facet (node-to-segment, non-matching meshes; ``pairing``); the contact law
        acts on their relative displacement, with equal and opposite forces. None:
        node-to-rigid.
    tolerance : largest distance [m] between a contact node and its partner; default
        ``1e-6`` times the model size (node-to-node), a tenth of the partner's longest facet
        edge (node-to-segment).
    pairing : ``"auto"`` (default: node-to-node when the nodes match within the tolerance,
        else mortar), ``"node-to-node"``, ``"mortar"`` or ``"node-to-segment"``
        (:mod:`fretwear.model.pairing`).
    region : part of ``boundary`` in contact: coordinate ranges ``{"x": (x0, x1), ...}`` [m]
        (:mod:`fretwear.model.regions`; a facet is in contact when all its nodes lie in the
        ranges), e.g. the overlap of a lap joint. None: the whole boundary.
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
    pairing: str = "auto"
    region: dict | None = None

    def __post_init__(self):
        what = f"contact {self.name!r}"
        if not isinstance(self.boundary, str) or not self.boundary:
            raise InputError(f"{what}: boundary = {self.boundary!r}; expected the name of a "
                             "boundary of the mesh")
        check_pairing(self.pairing, what)
        if self.pairing != "auto" and self.partner is None:
            raise InputError(f"{what}: pairing = {self.pairing!r} without a partner boundary "
                             "(pairing is for two-body contact)")
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
            size = RANGES["length"][1]  # a gap larger than any structure means no contact
            self.gap = number(self.gap, f"{what}: gap", low=-size, high=size, unit="m")
        _warn_unusual((self.mu, "friction", f"{what}: mu"),
                      (self.wear_coefficient, "wear_coefficient", f"{what}: wear_coefficient"))
        for key in ("normal_stiffness", "tangential_stiffness"):
            v = number(getattr(self, key), f"{what}: {key}", low=0.0, open_low=True,
                       allow_inf=True, unit="Pa/m")
            setattr(self, key, _finite(v, f"{what}: {key}", allow_inf=True))
        if self.normal_pressure is not None:
            self.normal_pressure = _finite(number(self.normal_pressure,
                                                  f"{what}: normal_pressure", low=0.0,
                                                  unit="Pa"), f"{what}: normal_pressure")
        waveforms = [w for w in WAVEFORMS if w != "fourier"]
        if self.normal_waveform not in waveforms:
            raise InputError(f"{what}: normal_waveform = {self.normal_waveform!r}; expected one "
                             f"of {waveforms}")
        if self.normal_pressure is None and self.normal_waveform != "constant":
            raise InputError(f"{what}: normal_waveform = {self.normal_waveform!r} without "
                             "normal_pressure: the waveform only shapes a prescribed normal "
                             "pressure (give normal_pressure, or leave the waveform out)")


# --------------------------------------------------------------------------------------------
# pieces of the model
# --------------------------------------------------------------------------------------------
def _supports(mesh: Mesh, supports) -> tuple[sp.csr_matrix, np.ndarray]:
    """The springs' stiffness ``Ks`` and the fixed DOFs of ``supports`` (springs and pairs
    ``(at, direction)``, in any order)."""
    d = mesh.dim
    ndof = d * mesh.points.shape[0]
    rows, cols, vals, held = [], [], [], []
    for item in supports:
        if not isinstance(item, Spring):
            held.append(_fixed(mesh, item))
            continue
        nodes, n = _spring_place(mesh, item)
        if math.isinf(item.stiffness):
            held.append(d * nodes + _spring_axis(item, n, d))
        elif item.stiffness != 0.0:
            k = item.stiffness / nodes.size
            dofs = d * nodes[:, None] + np.arange(d)  # (n, d)
            rows.append(np.repeat(dofs, d, axis=1).ravel())
            cols.append(np.tile(dofs, (1, d)).ravel())
            vals.append(np.tile(k * np.outer(n, n).ravel(), nodes.size))
    if rows:
        Ks = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                           shape=(ndof, ndof))
    else:
        Ks = sp.csr_matrix((ndof, ndof))
    fixed_dofs = np.unique(np.concatenate(held)) if held else np.zeros(0, dtype=np.int64)
    return Ks, fixed_dofs.astype(np.int64)


def _spring_place(mesh: Mesh, s: Spring) -> tuple[np.ndarray, np.ndarray]:
    """The nodes of a spring and its unit direction."""
    what = f"spring at {s.at!r}"
    nodes = nodes_at(mesh, s.at, f"{what}: at")
    if s.region is not None:
        nodes = region_nodes(mesh, nodes, s.region, what)
    return nodes, unit_direction(s.direction, mesh.dim, f"{what}: direction")


def _spring_axis(s: Spring, n: np.ndarray, d: int) -> int:
    """The axis an infinite spring holds (it must lie along one)."""
    axis = axis_index(n)
    if axis is None:
        raise InputError(
            f"spring at {s.at!r}: an infinite stiffness (fixed DOF) needs an axis direction "
            f"({list(AXES[:d])}); got direction {s.direction!r}"
        )
    return axis


def _fixed(mesh: Mesh, item) -> np.ndarray:
    """The DOFs a pair ``(at, direction)`` holds (``direction`` an axis or ``"all"``)."""
    d = mesh.dim
    if isinstance(item, str) or not isinstance(item, Sequence) or len(item) != 2:
        raise InputError(f"supports: {item!r}; expected a Spring(at, direction, stiffness) or "
                         f"a pair (at, direction) with direction one of {list(AXES[:d])} or "
                         "'all'")
    at, direction = item
    nodes = nodes_at(mesh, at, f"fixed {item!r}: at")
    if isinstance(direction, str) and direction.strip().lower() == "all":
        return (d * nodes[:, None] + np.arange(d)).ravel()
    axis = axis_index(unit_direction(direction, d, f"fixed {item!r}: direction"))
    if axis is None:
        raise InputError(f"fixed {item!r}: direction must be an axis {list(AXES[:d])} or "
                         f"'all'; got {direction!r}")
    return d * nodes + axis


def _loads(mesh: Mesh, loads, thickness: float) -> list[Load]:
    d = mesh.dim
    ndof = d * mesh.points.shape[0]
    out = []
    for item in loads:
        if isinstance(item, Traction):
            part, face = (mesh, item.boundary) if item.region is None else \
                restricted(mesh, item.boundary, item.region, f"traction on {item.boundary!r}")
            vec = boundary_load(part, face, pressure=item.pressure,
                                traction=item.traction, thickness=thickness)
            name = item.name or f"traction on {item.boundary}"
        elif isinstance(item, NodalForce):
            nodes = nodes_at(mesh, item.at, f"nodal force at {item.at!r}")
            if item.region is not None:
                nodes = region_nodes(mesh, nodes, item.region, f"nodal force at {item.at!r}")
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
    face = spec.boundary
    if spec.region is not None:  # part of the face
        mesh, face = restricted(mesh, spec.boundary, spec.region, what)
        facets = _boundary(mesh, face)
    facets = orient_facets(mesh, facets, f"boundary {spec.boundary!r}")
    nodes, area = nodal_areas(mesh, face, thickness)
    if np.any(~(area > 0.0)):
        i = int(np.flatnonzero(~(area > 0.0))[0])
        raise InputError(f"{what}: node {int(nodes[i])} at "
                         f"{tuple(np.round(mesh.points[nodes[i]], 12).tolist())} has a zero "
                         f"contact area ({area[i]:.3g} m^2): degenerate facets on boundary "
                         f"{spec.boundary!r}")
    frame, frames = surface_frames(mesh, facets, nodes, spec.normal, spec.tangent, what,
                                   f"boundary {spec.boundary!r}")

    coords = mesh.points[nodes]
    if mesh.dim == 2:
        order = np.argsort(coords @ frame[1], kind="stable")
    else:
        order = np.lexsort((coords @ frame[1], coords @ frame[2]))
    nodes, area, coords, frames = nodes[order], area[order], coords[order], frames[order]
    nc, d = nodes.size, mesh.dim

    if callable(spec.gap):
        gap = np.asarray(spec.gap(coords.copy()), dtype=float)
        if gap.shape != (nc,) or not np.all(np.isfinite(gap)):
            raise InputError(f"{what}: the gap function returned shape {gap.shape}; expected "
                             f"({nc},) finite values [m] for the {nc} contact nodes")
    else:
        gap = np.full(nc, float(spec.gap))
    partner = dict(partner_dofs=None, partner_ids=None)
    if spec.partner is not None:
        found = pair(mesh, nodes, frames[:, 0], spec.partner, face=facets,
                     tolerance=spec.tolerance, pairing=spec.pairing, what=what)
        partner = dict(partner_dofs=found.partner_dofs, partner_ids=found.partner_ids,
                       segments=found.segments)
        if found.segments is not None:
            gap = gap + found.gap  # the facet's distance along the normal (0 if flat)
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


def surface_frames(mesh: Mesh, facets: np.ndarray, nodes: np.ndarray, normal=None,
                   tangent=None, what: str = "contact",
                   label: str = "boundary") -> tuple[np.ndarray, np.ndarray]:
    """``(frame, frames)``: the mean contact frame (d, d) of the outward-oriented ``facets``
    and the frame (nc, d, d) of each of ``nodes`` (rows ``[n, t1(, t2)]``).

    Without ``normal`` the normal is the facets' outward normal: the same for every node on
    a flat surface; on a curved or multi-flank one each node's own (:func:`nodal_normals`),
    its tangents turned from the mean frame's (:func:`_node_frame`). A given ``normal`` (one
    for every node) must point out of the structure. ``tangent`` as in :class:`ContactSpec`.
    Meshed models (:func:`from_mesh`) and FE-matrix models with a node file's elements
    (:func:`fretwear.model.readers.from_fe`) take their frames from here.
    """
    outward = facet_normals(mesh, facets)
    mean = outward.mean(axis=0)
    mean /= np.linalg.norm(mean)
    per_node = None
    if normal is None:
        dev = np.linalg.norm(outward - mean, axis=1).max()
        n = mean
        if dev > 1e-6:  # curved or multi-flank: one normal per node
            per_node = nodal_normals(mesh, facets, nodes, f"{what}: {label}")
    else:
        n = unit_direction(normal, mesh.dim, f"{what}: normal")
        if n @ mean <= 0.0:
            raise InputError(
                f"{what}: normal {normal!r} points into the structure; it must point from "
                f"the structure into the obstacle (the boundary's outward normal is "
                f"{tuple(np.round(mean, 6).tolist())})"
            )
    frame = _tangents(n, tangent, what)
    nc, d = nodes.size, mesh.dim
    if per_node is None:
        return frame, np.broadcast_to(frame, (nc, d, d)).copy()
    return frame, np.array([_node_frame(v, frame, tangent, what) for v in per_node])


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
              supports=(), loads=(), contact, observed=None, name: str = "model") -> Model:
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
        Loss factor and Rayleigh factors (not matrices).
    supports : sequence of Spring and (at, direction) pairs
        How the structure is held: springs to ground, added to ``K`` (infinite ones hold
        their DOFs), and pairs ``(at, direction)`` holding DOFs at zero (``direction`` an
        axis name or ``"all"``), in any order.
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
        friction could hold (:func:`fretwear.model.supports.check_supported`).
    """
    model = unchecked_from_mesh(mesh, material, thickness=thickness, damping=damping,
                                supports=supports, loads=loads, contact=contact,
                                observed=observed, name=name)
    check_supported(model)
    return model


def unchecked_from_mesh(mesh: Mesh, material: Material, *, thickness=1.0,
                        damping: Damping | None = None, supports=(), loads=(), contact,
                        observed=None, name: str = "model") -> Model:
    """:func:`from_mesh` without its last check, that the structure is held
    (:func:`~fretwear.model.supports.check_supported`): for one sector of a disk whose body
    is held by a contact with the next sector (a wedge damper between two platforms), added
    by :func:`fretwear.model.cyclic.neighbour_contact`, which then checks the sector with
    it. Any other use should call :func:`from_mesh`."""
    if not isinstance(mesh, Mesh):
        raise InputError(f"mesh = {mesh!r} is not a fretwear Mesh")
    check_mesh(mesh)
    check_cells(mesh)
    if damping is not None and not isinstance(damping, Damping):
        raise InputError(f"damping = {damping!r} is not a Damping(...)")
    if damping is not None and (damping.C is not None or damping.D is not None):
        raise InputError("damping: the matrices C and D are for user matrices (from_matrices); "
                         "a mesh model takes loss_factor and the Rayleigh factors")
    thickness = check_thickness(thickness, mesh.dim)
    if isinstance(material, dict):
        K0, M = _assemble_bodies(mesh, material, thickness)
        material = next(iter(material.values()))
    elif not isinstance(material, Material):
        raise InputError(f"material = {material!r} is not a Material(E, nu, rho)")
    else:
        K0, M = assemble(mesh, material.E, material.nu, material.rho, thickness)
    if isinstance(supports, str) or not isinstance(supports, Sequence):
        raise InputError(f"supports = {supports!r}; expected a list of Spring(...) and "
                         "(at, direction) items")
    Ks, fixed_dofs = _supports(mesh, supports)
    specs = [contact] if isinstance(contact, ContactSpec) else list(contact) \
        if isinstance(contact, Sequence) and not isinstance(contact, str) else [contact]
    interface = combine([_contact(mesh, spec, thickness) for spec in specs])
    _check_contact_free(mesh, interface, fixed_dofs)
    C, D = _damping(damping, K0, M)
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
    return model


def _check_contact_free(mesh: Mesh, interface: ContactInterface, fixed_dofs) -> None:
    """Refuse a contact node with a fixed DOF, naming its interface, node and direction."""
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


def _damping(damping: Damping | None, K0, M):
    """``C, D`` of a mesh model: Rayleigh ``a M + b K0`` and ``D = eta K0`` (K0 without the
    springs), None where zero."""
    C = D = None
    if damping is not None:
        if damping.loss_factor > 0.0:
            D = (damping.loss_factor * K0).tocsr()
        if damping.rayleigh_mass > 0.0 or damping.rayleigh_stiffness > 0.0:
            C = (damping.rayleigh_mass * M + damping.rayleigh_stiffness * K0).tocsr()
    return C, D


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
            if mine.size == 0:
                raise InputError(f"material[{body!r}]: the node set {body!r} holds no whole "
                                 "cell (a boundary or a few nodes, not a body): the material "
                                 "would apply to nothing; name a body (a volume group)")
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
