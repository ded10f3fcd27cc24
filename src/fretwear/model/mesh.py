"""Finite element meshes: structured generators, file import (meshio) and facet geometry.

Every function returns or takes a :class:`fretwear.model.core.Mesh`. Supported cells are the
linear ones: ``"quad"`` and ``"triangle"`` in 2D (plane strain), ``"hexahedron"`` and
``"tetra"`` in 3D, with meshio's (VTK's) local node order.

Boundaries are named sets of facets (2-node lines in 2D, 4-node quads or 3-node triangles in
3D). Facets are stored *oriented outward*: in 2D the body lies on the left of each edge (the
outward normal of the edge ``a -> b`` is ``(dy, -dx) / length``); in 3D the facet nodes turn
counter-clockwise seen from outside (right-hand rule gives the outward normal).
"""

from __future__ import annotations

import contextlib
import io

import numpy as np

from fretwear.errors import InputError
from fretwear.limits import RANGES, check_range
from fretwear.model.core import Mesh
from fretwear.resources import require_memory
from fretwear.validate import instance, is_real, reals
from fretwear.validate import path as check_path

CELL_DIM = {"quad": 2, "triangle": 2, "hexahedron": 3, "tetra": 3}
FACET_TYPE = {"quad": "line", "triangle": "line", "hexahedron": "quad", "tetra": "triangle"}

# Local facets of each cell (meshio / VTK node order). The orientation is not relied upon:
# orient_facets() fixes it with the cell centroid.
_LOCAL_FACETS = {
    "quad": np.array([[0, 1], [1, 2], [2, 3], [3, 0]]),
    "triangle": np.array([[0, 1], [1, 2], [2, 0]]),
    "hexahedron": np.array(
        [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    ),
    "tetra": np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]),
}


# --------------------------------------------------------------------------------------------
# structured meshes
# --------------------------------------------------------------------------------------------
def _positive(value, what: str) -> float:
    if not is_real(value):
        raise InputError(f"{what} = {value!r} is not a number; expected a length > 0 [m]")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} = {value!r} is not a number; expected a length > 0 [m]") from None
    if not np.isfinite(v) or v <= 0.0:
        raise InputError(f"{what} = {value!r}; expected a finite length > 0 [m]")
    return check_range(v, "length", what)


def _fits(n_cells: int, dofs_per_cell: int, what: str) -> None:
    """Refuse a mesh whose assembly cannot fit in memory: scikit-fem assembles each of K and
    M from ``n_cells * dofs_per_cell^2`` (row, column, value) triplets (24 bytes each)."""
    require_memory(2 * 24.0 * n_cells * dofs_per_cell**2, f"a mesh of {n_cells:.3g} {what}")


def _count(value, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise InputError(f"{what} = {value!r}; expected an integer number of elements >= 1")
    return int(value)


def _origin(origin, d: int) -> np.ndarray:
    o = np.asarray(origin, dtype=float).reshape(-1)
    if o.size != d or not np.all(np.isfinite(o)) or np.any(np.abs(o) > RANGES["length"][1]):
        raise InputError(f"origin = {origin!r}; expected {d} finite coordinates [m] of "
                         f"magnitude up to {RANGES['length'][1]:g} m")
    return o


def rectangle(length, height, nx, ny, origin=(0.0, 0.0)) -> Mesh:
    """Structured mesh of 4-node quadrilaterals on ``[x0, x0+length] x [y0, y0+height]``.

    Parameters
    ----------
    length, height : float
        Sizes along x and y [m].
    nx, ny : int
        Number of elements along x and y.
    origin : (2,) float
        Lower-left corner ``(x0, y0)`` [m].

    Returns
    -------
    Mesh
        Node ``i + (nx+1) j`` sits at ``(x0 + i length/nx, y0 + j height/ny)``. Cells are
        counter-clockwise. Boundaries ``"bottom"``, ``"right"``, ``"top"``, ``"left"`` are
        ``(n, 2)`` edges listed in order counter-clockwise around the body (so bottom runs
        towards +x and top towards -x), each edge oriented outward. Node sets with the same
        four names list the boundary nodes by increasing x (bottom, top) or y (left, right);
        node sets ``"bottom_left"``, ``"bottom_right"``, ``"top_left"``, ``"top_right"`` hold
        one corner node each.
    """
    length, height = _positive(length, "length"), _positive(height, "height")
    nx, ny = _count(nx, "nx"), _count(ny, "ny")
    _fits(nx * ny, 8, "quadrilaterals")
    x0, y0 = _origin(origin, 2)
    x = x0 + np.linspace(0.0, length, nx + 1)
    y = y0 + np.linspace(0.0, height, ny + 1)
    X, Y = np.meshgrid(x, y)  # (ny+1, nx+1), x fastest
    points = np.column_stack([X.ravel(), Y.ravel()])
    ids = np.arange((nx + 1) * (ny + 1)).reshape(ny + 1, nx + 1)
    cells = np.column_stack(
        [ids[:-1, :-1].ravel(), ids[:-1, 1:].ravel(), ids[1:, 1:].ravel(), ids[1:, :-1].ravel()]
    )
    bottom, top, left, right = ids[0, :], ids[-1, :], ids[:, 0], ids[:, -1]

    def chain(nodes):
        return np.column_stack([nodes[:-1], nodes[1:]])

    boundaries = {
        "bottom": chain(bottom),
        "right": chain(right),
        "top": chain(top[::-1]),
        "left": chain(left[::-1]),
    }
    node_sets = {
        "bottom": bottom.copy(),
        "top": top.copy(),
        "left": left.copy(),
        "right": right.copy(),
        "bottom_left": np.array([ids[0, 0]]),
        "bottom_right": np.array([ids[0, -1]]),
        "top_left": np.array([ids[-1, 0]]),
        "top_right": np.array([ids[-1, -1]]),
    }
    return Mesh(points, cells.astype(np.int64), "quad", boundaries, node_sets)


def box(lx, ly, lz, nx, ny, nz, origin=(0.0, 0.0, 0.0)) -> Mesh:
    """Structured mesh of 8-node hexahedra on ``[x0, x0+lx] x [y0, y0+ly] x [z0, z0+lz]``.

    Parameters
    ----------
    lx, ly, lz : float
        Sizes along x, y, z [m].
    nx, ny, nz : int
        Number of elements along each axis.
    origin : (3,) float
        Corner with the smallest coordinates [m].

    Returns
    -------
    Mesh
        Node ``i + (nx+1) (j + (ny+1) k)``; cells in meshio/VTK order (bottom face
        counter-clockwise seen from +z, then the top face). Boundaries ``"xmin"``, ``"xmax"``,
        ``"ymin"``, ``"ymax"``, ``"zmin"``, ``"zmax"`` are ``(n, 4)`` quad facets oriented
        outward; node sets with the same names hold their nodes (increasing node number).
    """
    lx, ly, lz = (_positive(v, w) for v, w in ((lx, "lx"), (ly, "ly"), (lz, "lz")))
    nx, ny, nz = (_count(v, w) for v, w in ((nx, "nx"), (ny, "ny"), (nz, "nz")))
    _fits(nx * ny * nz, 24, "hexahedra")
    o = _origin(origin, 3)
    axes = [o[0] + np.linspace(0, lx, nx + 1), o[1] + np.linspace(0, ly, ny + 1),
            o[2] + np.linspace(0, lz, nz + 1)]
    Z, Y, X = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")  # (nz+1, ny+1, nx+1)
    points = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    ids = np.arange(points.shape[0]).reshape(nz + 1, ny + 1, nx + 1)  # [k, j, i]
    c = [ids[:-1, :-1, :-1], ids[:-1, :-1, 1:], ids[:-1, 1:, 1:], ids[:-1, 1:, :-1],
         ids[1:, :-1, :-1], ids[1:, :-1, 1:], ids[1:, 1:, 1:], ids[1:, 1:, :-1]]
    cells = np.column_stack([a.ravel() for a in c]).astype(np.int64)

    def quads(face, flip):
        # face: 2D array of node ids [a, b]; facets (a,b),(a,b+1),(a+1,b+1),(a+1,b) turn
        # counter-clockwise around the normal (axis b) x (axis a); flip reverses it.
        q = np.column_stack([face[:-1, :-1].ravel(), face[:-1, 1:].ravel(),
                             face[1:, 1:].ravel(), face[1:, :-1].ravel()])
        return q[:, ::-1] if flip else q

    # ids[k, j, i]: for a fixed k, rows j, cols i: (i then j) turn ccw about +z.
    boundaries = {
        "zmin": quads(ids[0], True),
        "zmax": quads(ids[-1], False),
        "ymin": quads(ids[:, 0, :], False),   # rows k, cols i: x then z -> ccw about -y
        "ymax": quads(ids[:, -1, :], True),
        "xmin": quads(ids[:, :, 0], True),    # rows k, cols j: y then z -> ccw about +x
        "xmax": quads(ids[:, :, -1], False),
    }
    node_sets = {name: np.unique(f) for name, f in boundaries.items()}
    mesh = Mesh(points, cells, "hexahedron", boundaries, node_sets)
    return mesh


def join(*parts: tuple[str, Mesh]) -> Mesh:
    """One mesh of several bodies that share no node: ``join(("blade", m1), ("disc", m2))``.

    The bodies keep their nodes (coincident nodes of two bodies stay distinct: a node-to-node
    interface pairs them, :class:`fretwear.model.build.ContactSpec` ``partner``); node
    numbers of later bodies are offset by the earlier bodies' node counts. Every boundary and
    node set is renamed ``"<body>.<name>"``, and each body's nodes form a node set named after
    the body.

    Raises InputError for meshes of different dimension or cell type, or repeated names.
    """
    if not parts:
        raise InputError("join: expected at least one (name, mesh) pair")
    names = [str(n) for n, _ in parts]
    if len(set(names)) != len(names):
        raise InputError(f"join: body names {names} repeat; expected distinct names")
    kinds = {(m.dim, m.cell_type) for _, m in parts}
    if len(kinds) != 1:
        raise InputError(f"join: the meshes have (dimension, cell type) {sorted(kinds)}; "
                         "expected one kind")
    points, cells, boundaries, node_sets = [], [], {}, {}
    offset = 0
    for name, m in parts:
        points.append(np.asarray(m.points, dtype=float))
        cells.append(np.asarray(m.cells, dtype=np.int64) + offset)
        for key, f in m.boundaries.items():
            boundaries[f"{name}.{key}"] = np.asarray(f, dtype=np.int64) + offset
        for key, s in m.node_sets.items():
            node_sets[f"{name}.{key}"] = np.asarray(s, dtype=np.int64) + offset
        node_sets[name] = offset + np.arange(m.points.shape[0])
        offset += m.points.shape[0]
    cell_type = parts[0][1].cell_type
    return Mesh(np.vstack(points), np.vstack(cells), cell_type, boundaries, node_sets)


def transformed(mesh: Mesh, rotation, shift=None) -> Mesh:
    """The mesh moved rigidly: ``x -> rotation @ x + shift`` (``rotation`` (d, d)
    orthogonal with determinant 1, ``shift`` (d,) [m])."""
    instance(mesh, Mesh, "mesh", "a fretwear Mesh (fretwear.rectangle, box, read_mesh)")
    R = reals(rotation, "rotation", ndim=2)
    d = mesh.dim
    if R.shape != (d, d) or not np.allclose(R @ R.T, np.eye(d), atol=1e-12) \
            or np.linalg.det(R) <= 0:
        raise InputError(f"rotation has shape {R.shape}; expected a ({d}, {d}) rotation matrix")
    t = np.zeros(d) if shift is None else reals(shift, "shift")
    if t.shape != (d,):
        raise InputError(f"shift has shape {t.shape}; expected ({d},) [m]")
    return Mesh(mesh.points @ R.T + t, mesh.cells.copy(), mesh.cell_type,
                {k: v.copy() for k, v in mesh.boundaries.items()},
                {k: v.copy() for k, v in mesh.node_sets.items()})


# --------------------------------------------------------------------------------------------
# facet geometry
# --------------------------------------------------------------------------------------------
def _facet_vectors(points: np.ndarray, facets: np.ndarray) -> np.ndarray:
    """Non-normalised normal of each facet from its node order (right-hand rule) (nf, d)."""
    p = points[facets]
    if facets.shape[1] == 2:
        t = p[:, 1] - p[:, 0]
        return np.column_stack([t[:, 1], -t[:, 0]])
    if facets.shape[1] == 3:
        return np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    return np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])


def facet_cells(mesh: Mesh, facets: np.ndarray, what: str = "boundary") -> np.ndarray:
    """Index of the cell that owns each boundary facet (nf,).

    Raises
    ------
    InputError
        If a facet is not a face of exactly one cell (not in the mesh, or interior).
    """
    facets = np.asarray(facets, dtype=np.int64)
    local = _LOCAL_FACETS[mesh.cell_type]
    nfl, kf = local.shape
    if facets.ndim != 2 or facets.shape[1] != kf:
        raise InputError(
            f"{what}: facets have shape {facets.shape}; a {mesh.cell_type} mesh needs "
            f"(n, {kf}) {FACET_TYPE[mesh.cell_type]} facets"
        )
    allf = np.sort(mesh.cells[:, local].reshape(-1, kf), axis=1)
    both = np.vstack([allf, np.sort(facets, axis=1)])
    _, inv = np.unique(both, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    n_uniq = int(inv.max()) + 1
    count = np.bincount(inv[: allf.shape[0]], minlength=n_uniq)
    owner = np.full(n_uniq, -1, dtype=np.int64)
    owner[inv[: allf.shape[0]]] = np.arange(allf.shape[0]) // nfl
    mine = inv[allf.shape[0]:]
    bad = np.flatnonzero(count[mine] != 1)
    if bad.size:
        f = facets[bad[0]]
        kind = "is not a face of any cell" if count[mine[bad[0]]] == 0 else "is interior"
        raise InputError(
            f"{what}: facet with nodes {f.tolist()} {kind} ({bad.size} such facets); "
            "a boundary must be made of faces on the outer surface of the mesh"
        )
    return owner[mine]


def orient_facets(mesh: Mesh, facets: np.ndarray, what: str = "boundary") -> np.ndarray:
    """Return ``facets`` with each facet's node order flipped where needed to point outward."""
    facets = np.array(facets, dtype=np.int64, copy=True)
    owner = facet_cells(mesh, facets, what)
    normal = _facet_vectors(mesh.points, facets)
    centre = mesh.points[facets].mean(axis=1)
    cell_centre = mesh.points[mesh.cells[owner]].mean(axis=1)
    flip = np.einsum("ij,ij->i", normal, centre - cell_centre) < 0.0
    facets[flip] = facets[flip, ::-1]
    return facets


def facet_normals(mesh: Mesh, facets: np.ndarray) -> np.ndarray:
    """Unit outward normals (nf, d) of facets already oriented outward (see module docstring).

    For a warped 4-node facet the normal is that of its diagonals' cross product.
    """
    v = _facet_vectors(mesh.points, np.asarray(facets, dtype=np.int64))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def boundary(mesh: Mesh, name: str) -> np.ndarray:
    """The facets of a named boundary, with a clear error listing the available names."""
    if not isinstance(name, str) or name not in mesh.boundaries:
        raise InputError(
            f"unknown boundary {name!r}; the mesh has boundaries {sorted(mesh.boundaries)}"
        )
    return np.asarray(mesh.boundaries[name], dtype=np.int64)


def model_size(mesh: Mesh) -> float:
    """Diagonal of the bounding box of the mesh [m]."""
    return float(np.linalg.norm(mesh.points.max(axis=0) - mesh.points.min(axis=0)))


# --------------------------------------------------------------------------------------------
# reading
# --------------------------------------------------------------------------------------------
_VERTEX_TYPES = ("vertex",)


def read(path) -> Mesh:
    """Read a mesh file with meshio (Gmsh ``.msh`` v2.2 and v4.1, and any format meshio reads).

    Parameters
    ----------
    path : str or Path
        The mesh file.

    Returns
    -------
    Mesh
        A 2D mesh (``"triangle"`` or ``"quad"`` cells; the z coordinate must be zero and is
        dropped) or a 3D mesh (``"tetra"`` or ``"hexahedron"`` cells). Named boundaries come
        from named groups (Gmsh physical groups, or meshio cell sets) of facets: lines in 2D,
        triangles or quads in 3D; they are oriented outward. Named groups of vertices become
        node sets, and every boundary also gets a node set of the same name holding its
        nodes (merged with a vertex group of the same name, if any). Nodes used by no cell
        are removed and the remaining ones renumbered in their original order; duplicate
        cells (as Gmsh writes for an entity in several physical groups) are kept once; 2D
        cells are made counter-clockwise. A named group of body cells (a physical volume in
        3D, a physical surface in 2D: a body, e.g. for its material) becomes a node set of
        its cells' nodes; groups of edges in 3D are ignored.

    Raises
    ------
    InputError
        Missing or unreadable file; no supported cells, several cell types (mixed meshes)
        or unsupported (e.g. quadratic) cells; a 2D mesh out of the plane z = 0; a named
        group mixing facet types.
    """
    import meshio

    path = check_path(path, "path")
    if not path.is_file():
        raise InputError(f"mesh file {str(path)!r} does not exist")
    chatter = io.StringIO()
    try:
        # meshio prints to stdout/stderr and may call sys.exit() on a file it cannot parse
        with contextlib.redirect_stdout(chatter), contextlib.redirect_stderr(chatter):
            m = meshio.read(path)
    except (Exception, SystemExit) as exc:
        why = " ".join((str(exc) if not isinstance(exc, SystemExit) else "").split()
                       + chatter.getvalue().split()) or type(exc).__name__
        raise InputError(
            f"cannot read mesh file {str(path)!r} with meshio ({why}); expected a Gmsh .msh "
            "(v2.2 or v4.1) or another format meshio reads"
        ) from None

    types = {block.type for block in m.cells}
    volume = [t for t in types if meshio_dim(t) == 3]
    surface = [t for t in types if meshio_dim(t) == 2]
    body_dim = 3 if volume else 2
    body_types = volume if volume else surface
    if not body_types:
        raise InputError(
            f"mesh file {str(path)!r} has no 2D or 3D cells (found {sorted(types)}); expected "
            "triangle or quad cells (2D) or tetra or hexahedron cells (3D)"
        )
    unsupported = [t for t in body_types if t not in CELL_DIM]
    if unsupported or len(body_types) > 1:
        raise InputError(
            f"mesh file {str(path)!r} has {body_dim}D cells of types {sorted(body_types)}; "
            "expected a single linear type: triangle or quad (2D), tetra or hexahedron (3D)"
        )
    cell_type = body_types[0]
    facet_type = FACET_TYPE[cell_type]

    cells = np.vstack([b.data for b in m.cells if b.type == cell_type]).astype(np.int64)
    cells = _unique_rows(cells)

    points = np.asarray(m.points, dtype=float)
    bad = np.flatnonzero(~np.all(np.isfinite(points), axis=1))
    if bad.size:
        raise InputError(f"mesh file {str(path)!r}: node {int(bad[0])} has coordinates "
                         f"{points[int(bad[0])].tolist()}; expected finite coordinates [m]")
    if body_dim == 2:
        if points.shape[1] == 3:
            size = max(float(np.ptp(points[:, :2], axis=0).max()), 1e-300)
            if np.any(np.abs(points[:, 2]) > 1e-12 * size):
                raise InputError(
                    f"mesh file {str(path)!r}: a 2D mesh must lie in the plane z = 0 "
                    f"(found z up to {np.abs(points[:, 2]).max():.3g} m)"
                )
            points = points[:, :2]
    elif points.shape[1] != 3:
        raise InputError(f"mesh file {str(path)!r}: 3D cells need 3 point coordinates")

    groups = _named_groups(m)
    boundaries: dict[str, np.ndarray] = {}
    node_sets: dict[str, np.ndarray] = {}
    for name, blocks in groups.items():
        facet_blocks = [a for t, a in blocks if t == facet_type]
        vertex_blocks = [a for t, a in blocks if t in _VERTEX_TYPES]
        vertex_blocks += [a for t, a in blocks if t == cell_type]  # a body: its nodes
        wrong = sorted({t for t, _ in blocks if meshio_dim(t) == body_dim - 1} - {facet_type})
        if wrong:
            raise InputError(
                f"mesh file {str(path)!r}: group {name!r} holds {wrong} facets; a boundary "
                f"of a {cell_type} mesh must be made of {facet_type} facets"
            )
        if facet_blocks:
            boundaries[name] = _unique_rows(np.vstack(facet_blocks).astype(np.int64))
        if vertex_blocks:
            node_sets[name] = np.unique(np.concatenate([a.ravel() for a in vertex_blocks]))

    # drop unused nodes and renumber
    used = np.unique(cells)
    new = np.full(points.shape[0], -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    for name, f in list(boundaries.items()) + list(node_sets.items()):
        if np.any(new[f] < 0):
            raise InputError(
                f"mesh file {str(path)!r}: group {name!r} uses nodes that belong to no "
                f"{cell_type} cell"
            )
    points = points[used]
    cells = new[cells]
    boundaries = {k: new[v] for k, v in boundaries.items()}
    node_sets = {k: new[v] for k, v in node_sets.items()}

    if body_dim == 2:
        cells = _counter_clockwise(points, cells)
    mesh = Mesh(points, cells, cell_type, {}, {})
    for name, f in boundaries.items():
        mesh.boundaries[name] = orient_facets(mesh, f, f"boundary {name!r}")
        nodes = np.unique(f)
        if name in node_sets:
            nodes = np.union1d(nodes, node_sets[name])
        node_sets[name] = nodes
    mesh.node_sets = node_sets
    check_cells(mesh, f"mesh file {str(path)!r}")
    return mesh


#: for each corner of a hexahedron (meshio/VTK node order), three neighbours that make a
#: right-handed triad in a positively oriented element
_HEX_TRIADS = ((1, 3, 4), (2, 0, 5), (3, 1, 6), (0, 2, 7), (7, 5, 0), (4, 6, 1), (5, 7, 2),
               (6, 4, 3))


def corner_jacobians(points: np.ndarray, cells: np.ndarray, cell_type: str) -> np.ndarray:
    """(ne, k) determinant of the element map's Jacobian at each corner [m^d] (up to a factor
    of the reference element): positive at every corner for a valid, positively oriented
    linear element; a sign change inside the element (a self-intersecting or inverted
    quadrilateral or hexahedron) shows as a corner value <= 0."""
    p = points[cells]
    if cell_type in ("quad", "triangle"):
        nxt, prv = np.roll(p, -1, axis=1), np.roll(p, 1, axis=1)
        a, b = nxt - p, prv - p
        return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    if cell_type == "tetra":
        e = p[:, 1:] - p[:, :1]
        return np.abs(np.linalg.det(e))[:, None]  # orientation is free; the volume is not
    if cell_type == "hexahedron":
        tri = np.asarray(_HEX_TRIADS)
        e = p[:, tri, :] - p[:, :, None, :]  # (ne, 8, 3 neighbours, 3)
        return np.linalg.det(e)
    raise InputError(f"cell type {cell_type!r}; expected quad, triangle, hexahedron or tetra")


def check_cells(mesh: Mesh, what: str = "mesh") -> None:
    """Refuse a mesh with non-finite coordinates or an element that is degenerate, inverted
    or self-intersecting (a corner Jacobian <= 0, :func:`corner_jacobians`), naming the first
    such element, its nodes and the corner."""
    pts = np.asarray(mesh.points, float)
    bad = np.flatnonzero(~np.all(np.isfinite(pts), axis=1))
    if bad.size:
        i = int(bad[0])
        raise InputError(f"{what}: node {i} has coordinates {pts[i].tolist()}; expected finite "
                         f"coordinates [m] ({bad.size} node(s) are not finite)")
    if mesh.cells.size == 0:
        raise InputError(f"{what} has no cells")
    if mesh.cells.min() < 0 or mesh.cells.max() >= pts.shape[0]:
        raise InputError(f"{what}: a cell refers to a node that does not exist (node numbers "
                         f"from 0 to {pts.shape[0] - 1} expected)")
    jac = corner_jacobians(pts, np.asarray(mesh.cells), mesh.cell_type)
    size = float(np.ptp(pts, axis=0).max()) if pts.size else 0.0
    tiny = 1e-12 * size ** pts.shape[1]
    wrong = jac <= tiny
    if np.any(wrong):
        e, c = (int(v[0]) for v in np.nonzero(wrong))
        kind = "degenerate (zero size)" if abs(jac[e, c]) <= tiny else (
            "inverted or self-intersecting")
        raise InputError(
            f"{what}: {mesh.cell_type} element {e} with nodes {mesh.cells[e].tolist()} is "
            f"{kind}: the Jacobian of its map is {jac[e, c]:.3g} at its corner node "
            f"{int(mesh.cells[e][c])}; expected > 0 at every corner (a valid, positively "
            "oriented element)")


def meshio_dim(cell_type: str) -> int:
    """Topological dimension of a meshio cell type (0 for unknown types)."""
    if cell_type.startswith(("tetra", "hexahedron", "wedge", "pyramid")):
        return 3
    if cell_type.startswith(("triangle", "quad", "polygon")):
        return 2
    if cell_type.startswith("line"):
        return 1
    return 0


def _unique_rows(a: np.ndarray) -> np.ndarray:
    """Rows of ``a`` without duplicates (same nodes in any order), first occurrence kept."""
    _, first = np.unique(np.sort(a, axis=1), axis=0, return_index=True)
    return a[np.sort(first)]


def _counter_clockwise(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    p = points[cells]
    x, y = p[..., 0], p[..., 1]
    area2 = np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)
    if np.any(area2 == 0.0):
        i = int(np.flatnonzero(area2 == 0.0)[0])
        raise InputError(f"cell {i} with nodes {cells[i].tolist()} has zero area")
    cells = cells.copy()
    cells[area2 < 0] = cells[area2 < 0, ::-1]
    return cells


def _named_groups(m) -> dict[str, list[tuple[str, np.ndarray]]]:
    """name -> list of (meshio cell type, (n, k) connectivity) from a meshio mesh.

    Uses meshio ``cell_sets`` when present (Gmsh v4 and most formats), and the
    ``gmsh:physical`` cell data with ``field_data`` names (Gmsh v2.2).
    """
    groups: dict[str, list[tuple[str, np.ndarray]]] = {}
    for name, per_block in (m.cell_sets or {}).items():
        if name.startswith("gmsh:"):
            continue
        for block, idx in zip(m.cells, per_block, strict=False):
            if idx is not None and len(idx):
                groups.setdefault(name, []).append((block.type, block.data[np.asarray(idx)]))
    phys = (m.cell_data or {}).get("gmsh:physical")
    if phys is not None and m.field_data:
        for name, (tag, dim) in ((k, v[:2]) for k, v in m.field_data.items()):
            if name in groups:
                continue
            for block, tags in zip(m.cells, phys, strict=False):
                if meshio_dim(block.type) != int(dim):
                    continue
                sel = np.asarray(tags) == int(tag)
                if np.any(sel):
                    groups.setdefault(name, []).append((block.type, block.data[sel]))
    return groups
