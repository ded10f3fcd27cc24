"""Contact surfaces of a model built from FE matrices: the facets of the node file's elements.

A model from an FE code's matrices has no mesh of its own, but its node file (``.bdf``,
``.inp``, ``.cdb``) usually lists the elements. Their faces whose nodes all belong to a set of
contact nodes make that set's surface: :func:`geometry` turns the node table into a
:class:`~fretwear.model.core.Mesh` (every node of the file, the elements of one kind) and
:func:`surface` finds the faces, oriented outward. From them the contact frames and the
non-matching pairing come from the same code as for meshed models
(:func:`fretwear.model.build.surface_frames`, :func:`fretwear.model.pairing.pair`).
"""

from __future__ import annotations

import numpy as np

from fretwear.errors import InputError
from fretwear.model.core import Mesh
from fretwear.model.mesh import _LOCAL_FACETS, orient_facets
from fretwear.model.readers.nodes import NodeTable

#: meshio cell types of solid (or plane) elements by (dimension, number of nodes)
CELL_TYPES = {(2, 3): "triangle", (2, 4): "quad", (3, 4): "tetra", (3, 8): "hexahedron"}


def geometry(table: NodeTable, dim: int) -> Mesh | None:
    """Every node of ``table`` (points in the table's order, ``ids`` its node ids) with the
    elements of the kind the file has most of among those of a ``dim``-D model; None when
    the file has no such element."""
    best = None
    for n, conn in sorted(table.elements.items()):
        kind = CELL_TYPES.get((dim, n))
        if kind is not None and (best is None or conn.shape[0] > best[1].shape[0]):
            best = (kind, conn)
    if best is None:
        return None
    kind, conn = best
    order = np.argsort(table.ids)
    pos = np.searchsorted(table.ids[order], conn).clip(0, table.ids.size - 1)
    bad = table.ids[order][pos] != conn
    if np.any(bad):
        raise InputError(f"node file: an element names node {int(conn[bad][0])}, which the "
                         "file does not define; expected the elements of its own nodes")
    return Mesh(table.xyz[:, :dim].copy(), order[pos], kind, ids=table.ids.copy())


def surface(mesh: Mesh, points: np.ndarray, what: str) -> np.ndarray:
    """The outward-oriented faces (nf, kf) of ``mesh`` on the outer surface whose nodes are
    all among ``points`` (point numbers); every one of ``points`` must lie on one of them."""
    local = _LOCAL_FACETS[mesh.cell_type]
    faces = mesh.cells[:, local].reshape(-1, local.shape[1])
    _, inv, count = np.unique(np.sort(faces, axis=1), axis=0, return_inverse=True,
                              return_counts=True)
    outer = count[inv.reshape(-1)] == 1
    inside = np.all(np.isin(faces, points), axis=1)
    facets = faces[outer & inside]
    lonely = np.setdiff1d(points, facets)
    if lonely.size:
        i = int(lonely[0])
        raise InputError(f"{what}: node {int(mesh.ids[i])} at "
                         f"{tuple(np.round(mesh.points[i], 12).tolist())} is on no face of the "
                         f"node file's {mesh.cell_type} elements whose nodes are all in the set "
                         f"({lonely.size} such nodes); expected the nodes of an outer surface "
                         "(or give normal / frames)")
    return orient_facets(mesh, facets, what)
