"""Meshes for the element and load tests: distorted interiors, and the same structured grids
cut into triangles and tetrahedra (tests/model/)."""

import numpy as np

from fretwear.model.core import Mesh
from fretwear.model.mesh import box, rectangle

KUHN = [[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]]


def distort(mesh, amount, seed=0):
    """Move interior nodes at random by up to ``amount`` times the smallest cell size (the
    boundary nodes stay, so the boundary facets stay straight/flat and evenly spaced)."""
    rng = np.random.default_rng(seed)
    on_boundary = np.zeros(len(mesh.points), bool)
    for f in mesh.boundaries.values():
        on_boundary[np.unique(f)] = True
    h = min(np.ptp(mesh.points[mesh.cells[0]], axis=0))
    pts = mesh.points.copy()
    pts[~on_boundary] += amount * h * rng.uniform(-1, 1, (np.sum(~on_boundary), mesh.dim))
    return Mesh(pts, mesh.cells, mesh.cell_type, mesh.boundaries, mesh.node_sets)


def triangles(mesh):
    """Split each quad of a 2D mesh along its 0-2 diagonal."""
    tri = mesh.cells[:, [[0, 1, 2], [0, 2, 3]]].reshape(-1, 3)
    return Mesh(mesh.points, tri, "triangle", mesh.boundaries, mesh.node_sets)


def tetrahedra(mesh):
    """Split each hexahedron in 6 tetrahedra around its 0-6 diagonal (conforming on a
    structured grid); the box faces become pairs of triangles along the matching diagonal."""
    tets = mesh.cells[:, KUHN].reshape(-1, 4)
    faces = tets[:, [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]].reshape(-1, 3)
    _, inv, count = np.unique(np.sort(faces, axis=1), axis=0, return_inverse=True,
                              return_counts=True)
    outer = faces[count[inv.ravel()] == 1]
    centre = mesh.points[outer].mean(axis=1)
    lo, hi = mesh.points.min(axis=0), mesh.points.max(axis=0)
    tris = {}
    for axis, a in enumerate("xyz"):
        tris[a + "min"] = outer[np.isclose(centre[:, axis], lo[axis])]
        tris[a + "max"] = outer[np.isclose(centre[:, axis], hi[axis])]
    return Mesh(mesh.points, tets, "tetra", tris, mesh.node_sets)


def meshes_2d():
    q = distort(rectangle(0.3, 0.2, 6, 4, origin=(0.1, -0.05)), 0.25)
    return {"quad": q, "triangle": triangles(q)}


def meshes_3d():
    h = distort(box(0.3, 0.2, 0.1, 3, 2, 2), 0.2)
    return {"hexahedron": h, "tetra": tetrahedra(box(0.3, 0.2, 0.1, 3, 2, 2))}
