"""Consistent nodal forces of distributed and point loads, and nodal areas of boundaries.

Force vectors have length ``ndof = dim * n_nodes`` with node-major DOFs (``dim*i + c``), in
newtons. In 2D (plane strain) a boundary is a curve and every surface integral is the line
integral times the out-of-plane width ``thickness``.

Loads given per unit length of a 2D boundary
-------------------------------------------
The primitive is a *pressure* or *traction* in pascals. A load quoted as a force per unit
out-of-plane width ``q`` [N/m] (Stromberg's "P = 50 MN/m") is a total force ``q * thickness``
spread uniformly over the boundary; the equivalent pressure is::

    pressure = q / boundary_measure(mesh, boundary)     # [N/m] / [m] = [Pa]

so that ``resultant(mesh, boundary, pressure=pressure, thickness=t)`` is ``q * t`` [N].
"""

from __future__ import annotations

import numpy as np

from fretwear.errors import InputError
from fretwear.model.core import Mesh
from fretwear.model.fem import check_thickness, node_major, skfem_mesh
from fretwear.model.mesh import boundary as _boundary
from fretwear.model.mesh import orient_facets

_INTORDER = 4  # exact for (linear shape function) x (load up to cubic) on straight facets


def _skfem_facets(m, facets: np.ndarray) -> np.ndarray:
    """scikit-fem facet numbers of facets given by their nodes (any node order)."""
    sk = np.sort(np.asarray(m.facets).T, axis=1)
    mine = np.sort(facets, axis=1)
    _, inv = np.unique(np.vstack([sk, mine]), axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    lookup = np.full(int(inv.max()) + 1, -1, dtype=np.int64)
    lookup[inv[: sk.shape[0]]] = np.arange(sk.shape[0])
    ids = lookup[inv[sk.shape[0]:]]
    if np.any(ids < 0):  # cannot happen for facets that passed orient_facets
        raise InputError("boundary facets do not match the mesh")
    return ids


def _facet_basis(mesh: Mesh, name: str, vector: bool):
    import skfem

    facets = orient_facets(mesh, _boundary(mesh, name), f"boundary {name!r}")
    m, elem = skfem_mesh(mesh)
    e = skfem.ElementVector(elem) if vector else elem
    return skfem.FacetBasis(m, e, facets=_skfem_facets(m, facets), intorder=_INTORDER)


def _points(w) -> np.ndarray:
    """Quadrature point coordinates (d, nf, nq) -> (nf*nq, d)."""
    x = np.asarray(w.x)
    return x.reshape(x.shape[0], -1).T


def _evaluate(value, w, d: int, what: str, vector: bool) -> np.ndarray:
    """A constant or callable load evaluated at the quadrature points, shaped like w.x."""
    x = np.asarray(w.x)
    shape = (d,) + x.shape[1:] if vector else x.shape[1:]
    if callable(value):
        out = np.asarray(value(_points(w)), dtype=float)
        n = x.shape[1] * x.shape[2]
        want = (n, d) if vector else (n,)
        if out.shape != want:
            raise InputError(
                f"{what}: the function returned shape {out.shape} for {n} points; expected "
                f"{want}"
            )
        return out.T.reshape(shape) if vector else out.reshape(shape)
    v = np.asarray(value, dtype=float)
    if vector:
        return np.broadcast_to(v.reshape(d, 1, 1), shape)
    return np.broadcast_to(v, shape)


def _check_value(value, d: int, what: str, vector: bool):
    if callable(value):
        return value
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        v = None
    want = (d,) if vector else ()
    if v is None or v.shape != want or not np.all(np.isfinite(v)):
        kind = f"a vector of {d} finite components [Pa]" if vector else "a finite number [Pa]"
        raise InputError(f"{what} = {value!r}; expected {kind} or a function of coordinates")
    return v


def boundary_load(mesh: Mesh, boundary: str, *, pressure=None, traction=None,
                  thickness=1.0) -> np.ndarray:
    """Consistent nodal forces of a pressure or a traction on a named boundary.

    Parameters
    ----------
    mesh : Mesh
    boundary : str
        Name of a boundary of ``mesh``.
    pressure : float or callable, optional
        Pressure [Pa] acting along the inward normal: a positive pressure pushes on the body.
        A callable receives the coordinates ``x`` (n, d) [m] and returns (n,) values.
    traction : (d,) float or callable, optional
        Traction vector [Pa] in global axes; a callable returns (n, d) values.
        Give exactly one of ``pressure`` and ``traction``.
    thickness : float
        Out-of-plane width [m] of a 2D mesh (1 in 3D).

    Returns
    -------
    (ndof,) float array
        ``f_i = int_boundary N_i t dA`` [N] with ``t = -pressure n`` or ``t = traction``,
        integrated with Gauss rules exact for loads up to cubic on straight facets. See the
        module docstring for loads given per unit length.
    """
    import skfem
    from skfem.helpers import dot

    d = mesh.dim
    thickness = check_thickness(thickness, d)
    if (pressure is None) == (traction is None):
        raise InputError(
            f"boundary load on {boundary!r}: give exactly one of pressure= (Pa, along the "
            f"inward normal) and traction= (vector in Pa); got pressure={pressure!r}, "
            f"traction={traction!r}"
        )
    vector = traction is not None
    value = _check_value(traction if vector else pressure,
                         d, "traction" if vector else "pressure", vector)
    basis = _facet_basis(mesh, boundary, vector=True)
    what = f"{'traction' if vector else 'pressure'} on {boundary!r}"

    if vector:
        @skfem.LinearForm
        def form(v, w):
            return dot(_evaluate(value, w, d, what, True), v)
    else:
        @skfem.LinearForm
        def form(v, w):
            return -_evaluate(value, w, d, what, False) * dot(w.n, v)

    f = thickness * skfem.asm(form, basis)[node_major(basis)]
    # shape functions of nodes off the boundary vanish there: clear their rounding residue
    off = np.ones(mesh.points.shape[0], dtype=bool)
    off[np.unique(_boundary(mesh, boundary))] = False
    f.reshape(-1, d)[off] = 0.0
    return f


def nodal_areas(mesh: Mesh, boundary: str, thickness=1.0) -> tuple[np.ndarray, np.ndarray]:
    """Consistent nodal areas of a boundary: ``a_i = int_boundary N_i dA`` [m^2].

    In 2D this is half the length of each adjacent edge times ``thickness`` (the tributary
    area); in 3D one third of each adjacent triangle, or the integral of the bilinear shape
    function over each adjacent quad. The areas add up exactly to the boundary area.

    Returns
    -------
    nodes : (n,) int array
        The boundary's nodes, increasing node number.
    area : (n,) float array
        Their areas [m^2].
    """
    import skfem

    thickness = check_thickness(thickness, mesh.dim)
    basis = _facet_basis(mesh, boundary, vector=False)

    @skfem.LinearForm
    def unit(v, w):
        return v

    a = skfem.asm(unit, basis)[np.asarray(basis.nodal_dofs[0], dtype=np.int64)]
    nodes = np.unique(_boundary(mesh, boundary))
    return nodes, thickness * a[nodes]


def boundary_measure(mesh: Mesh, boundary: str) -> float:
    """Length [m] (2D, without the thickness) or area [m^2] (3D) of a named boundary."""
    return float(nodal_areas(mesh, boundary)[1].sum())


def resultant(mesh: Mesh, boundary: str, *, pressure=None, traction=None,
              thickness=1.0) -> np.ndarray:
    """Total force (d,) [N] of :func:`boundary_load` with the same arguments."""
    f = boundary_load(mesh, boundary, pressure=pressure, traction=traction,
                      thickness=thickness)
    return f.reshape(-1, mesh.dim).sum(axis=0)


def nodal_force(mesh_or_ndof: Mesh | int, node: int, vector) -> np.ndarray:
    """A point force on one node.

    Parameters
    ----------
    mesh_or_ndof : Mesh or int
        The mesh, or the number of DOFs (then ``dim = len(vector)``).
    node : int
        Node number.
    vector : (d,) float
        Force [N] in global axes.

    Returns
    -------
    (ndof,) float array
    """
    v = np.asarray(vector, dtype=float).reshape(-1)
    if isinstance(mesh_or_ndof, Mesh):
        d, ndof = mesh_or_ndof.dim, mesh_or_ndof.points.shape[0] * mesh_or_ndof.dim
    else:
        d, ndof = v.size, int(mesh_or_ndof)
    if v.size != d or not np.all(np.isfinite(v)):
        raise InputError(f"nodal force = {vector!r}; expected {d} finite components [N]")
    if isinstance(node, bool) or not isinstance(node, (int, np.integer)) \
            or not 0 <= node < ndof // d:
        raise InputError(f"nodal force node = {node!r}; expected a node number in "
                         f"[0, {ndof // d - 1}]")
    f = np.zeros(ndof)
    f[d * int(node): d * int(node) + d] = v
    return f

