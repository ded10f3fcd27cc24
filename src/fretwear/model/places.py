"""Places on a mesh: the nodes a name or a point designates, and unit directions.

A place (``at=`` of springs, fixed DOFs, nodal forces and observed points) is either the name
of a node set or boundary of the mesh (all its nodes) or a coordinate tuple (the node at that
point, within ``1e-6`` of the model size). A direction is an axis name (``"x"``, ``"y"``,
``"z"``) or a vector.
"""

from __future__ import annotations

import numpy as np

from fretwear.errors import InputError
from fretwear.model.core import Mesh
from fretwear.model.mesh import model_size

AXES = "xyz"


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


def axis_index(direction: np.ndarray) -> int | None:
    """The axis (0, 1, 2) a unit ``direction`` lies along, or None when it is not an axis."""
    big = np.flatnonzero(np.abs(direction) > 1.0 - 1e-12)
    return int(big[0]) if big.size == 1 else None
