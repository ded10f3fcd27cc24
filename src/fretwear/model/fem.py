"""Stiffness and mass matrices of a linear elastic mesh (scikit-fem), node-major DOFs.

2D meshes are in plane strain: the matrices are those of a slab of out-of-plane width
``thickness`` (they are scikit-fem's per-unit-width matrices times the thickness). DOF
``dim*i + c`` is component ``c`` (x, y, z) of mesh node ``i``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.limits import check_range
from fretwear.model.core import Mesh
from fretwear.validate import is_real

# meshio/VTK hexahedron node k is scikit-fem's local node _HEX_TO_SKFEM.index(k): scikit-fem
# local node j sits at the VTK node _HEX_TO_SKFEM[j].
_HEX_TO_SKFEM = [0, 4, 3, 1, 7, 5, 2, 6]


def check_material(E, nu, rho) -> tuple[float, float, float]:
    """Validate isotropic elastic constants; return them as floats.

    Raises
    ------
    InputError
        Unless ``E > 0`` [Pa], ``-1 < nu < 0.5`` and ``rho >= 0`` [kg/m^3], all finite.
    """
    vals = []
    for value, what in ((E, "Young's modulus E"), (nu, "Poisson's ratio nu"),
                        (rho, "density rho")):
        if not is_real(value):
            raise InputError(f"{what} = {value!r} is not a number")
        v = float(value)
        if not np.isfinite(v):
            raise InputError(f"{what} = {value!r}; expected a finite number")
        vals.append(v)
    E, nu, rho = vals
    if E <= 0.0:
        raise InputError(f"Young's modulus E = {E:g} Pa; expected E > 0")
    check_range(E, "modulus", "Young's modulus E")
    if not -1.0 < nu < 0.5:
        raise InputError(
            f"Poisson's ratio nu = {nu:g}; expected -1 < nu < 0.5 (nu = 0.5 is incompressible, "
            "which this displacement formulation cannot represent)"
        )
    if rho < 0.0:
        raise InputError(f"density rho = {rho:g} kg/m^3; expected rho >= 0")
    check_range(rho, "density", "density rho")
    return E, nu, rho


def check_thickness(thickness, dim: int) -> float:
    """Validate the out-of-plane width [m] (2D) or require 1 (3D)."""
    if not is_real(thickness):
        raise InputError(f"thickness = {thickness!r} is not a number [m]")
    t = float(thickness)
    if not np.isfinite(t) or t <= 0.0:
        raise InputError(f"thickness = {thickness!r}; expected an out-of-plane width > 0 [m]")
    if dim == 2:
        check_range(t, "length", "thickness")
    if dim == 3 and t != 1.0:
        raise InputError(
            f"thickness = {thickness!r} given for a 3D mesh; the thickness (out-of-plane "
            "width) only applies to 2D plane strain meshes: leave it at 1"
        )
    return t


def skfem_mesh(mesh: Mesh):
    """The scikit-fem mesh and scalar linear element of a :class:`Mesh`.

    Node numbers are kept (scikit-fem node ``i`` is mesh node ``i``); only the local node
    order of hexahedra is converted from meshio's to scikit-fem's.
    """
    import skfem

    table = {
        "quad": (skfem.MeshQuad1, skfem.ElementQuad1, 2),
        "triangle": (skfem.MeshTri1, skfem.ElementTriP1, 2),
        "hexahedron": (skfem.MeshHex1, skfem.ElementHex1, 3),
        "tetra": (skfem.MeshTet1, skfem.ElementTetP1, 3),
    }
    if mesh.cell_type not in table:
        raise InputError(
            f"cell type {mesh.cell_type!r} is not supported; expected one of {sorted(table)}"
        )
    mesh_cls, elem_cls, dim = table[mesh.cell_type]
    points = np.asarray(mesh.points, dtype=float)
    if points.ndim != 2 or points.shape[1] != dim:
        raise InputError(
            f"{mesh.cell_type} mesh has points of shape {points.shape}; expected (n, {dim})"
        )
    cells = np.asarray(mesh.cells, dtype=np.int64)
    if mesh.cell_type == "hexahedron":
        cells = cells[:, _HEX_TO_SKFEM]
    return mesh_cls(np.ascontiguousarray(points.T), np.ascontiguousarray(cells.T)), elem_cls()


def node_major(basis) -> np.ndarray:
    """Permutation ``p`` with ``A_node_major = A_skfem[p][:, p]`` for a vector basis.

    ``p[dim*i + c]`` is scikit-fem's number of component ``c`` at node ``i``.
    """
    return np.asarray(basis.nodal_dofs, dtype=np.int64).T.reshape(-1)


def check_nodes_used(mesh: Mesh) -> None:
    """Raise InputError if some node belongs to no cell (it would have no stiffness)."""
    used = np.zeros(mesh.points.shape[0], dtype=bool)
    used[np.asarray(mesh.cells, dtype=np.int64).ravel()] = True
    if not used.all():
        free = np.flatnonzero(~used)
        raise InputError(
            f"{free.size} mesh node(s) belong to no cell (first: node {int(free[0])} at "
            f"{mesh.points[free[0]].tolist()}); remove unused nodes from the mesh"
        )


def assemble(mesh: Mesh, E, nu, rho, thickness=1.0) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Stiffness and consistent mass matrices of an isotropic linear elastic mesh.

    Parameters
    ----------
    mesh : Mesh
        Linear cells: quad, triangle (2D plane strain), hexahedron, tetra (3D).
    E : float
        Young's modulus [Pa].
    nu : float
        Poisson's ratio [-], ``-1 < nu < 0.5``.
    rho : float
        Density [kg/m^3] (0 gives a zero mass matrix).
    thickness : float
        Out-of-plane width [m] of a 2D mesh; must be 1 for 3D.

    Returns
    -------
    K, M : scipy.sparse.csr_matrix
        (ndof, ndof) stiffness [N/m] and mass [kg], ``ndof = dim * n_nodes``, node-major DOFs.
        Full Gauss integration (exact for the mass, and for the stiffness of parallelogram
        quads and parallelepiped hexahedra).
    """
    import skfem
    from skfem.helpers import dot
    from skfem.models.elasticity import lame_parameters

    E, nu, rho = check_material(E, nu, rho)
    thickness = check_thickness(thickness, mesh.dim)
    check_nodes_used(mesh)
    m, elem = skfem_mesh(mesh)
    basis = skfem.Basis(m, skfem.ElementVector(elem))

    @skfem.BilinearForm
    def mass(u, v, w):
        return rho * dot(u, v)

    lam, mu = lame_parameters(E, nu)

    @skfem.BilinearForm
    def elasticity(u, v, w):
        # sigma(u) : eps(v) = 2 mu eps(u) : eps(v) + lam div u div v, the form of scikit-fem's
        # linear_elasticity written out: that one builds an identity tensor at every pair of
        # basis functions (half of the build of benchmarks/scale_3d.py's pad: 13 of 26 s
        # at 1024 contact nodes)
        # (2 mu eps(u) : eps(v) = mu (grad u : grad v + grad u : grad v^T))
        gu, gv = u.grad, v.grad
        return (mu * (np.einsum("ij...,ij...->...", gu, gv)
                      + np.einsum("ij...,ji...->...", gu, gv))
                + lam * np.einsum("ii...->...", gu) * np.einsum("ii...->...", gv))

    K = skfem.asm(elasticity, basis)
    M = skfem.asm(mass, basis)
    p = node_major(basis)
    K = (thickness * K.tocsr())[p][:, p]
    M = (thickness * M.tocsr())[p][:, p]
    return _symmetric(K), _symmetric(M)


def _symmetric(A: sp.spmatrix) -> sp.csr_matrix:
    """Exactly symmetric copy (removes rounding asymmetry of the quadrature)."""
    A = (0.5 * (A + A.T)).tocsr()
    A.sort_indices()
    return A
