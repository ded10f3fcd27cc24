"""Stiffness and mass (fretwear.model.fem); the consistent loads are in test_loads.py.

References independent of the code under test: the exact linear-elastic solution of a
uniform stress state (patch test), the body's volume, rigid-body motions and the
Euler-Bernoulli frequencies of a free-free beam.
"""

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from helpers.meshes import meshes_2d, meshes_3d

from fretwear.errors import InputError
from fretwear.model.core import Mesh
from fretwear.model.fem import assemble
from fretwear.model.mesh import rectangle

E, NU, RHO = 210e9, 0.3, 7800.0


def lame(E, nu):
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def hand_consistent_forces(mesh, sigma, thickness):
    """Nodal forces of the traction sigma.n on every boundary facet, by hand: each node of a
    straight edge (flat triangle) gets 1/2 (1/3) of the facet's force; each node of a
    rectangular quad facet 1/4 of it (all exact for a uniform traction)."""
    f = np.zeros((len(mesh.points), mesh.dim))
    for facets in mesh.boundaries.values():
        p = mesh.points[facets]
        if mesh.dim == 2:
            t = p[:, 1] - p[:, 0]
            nA = np.column_stack([t[:, 1], -t[:, 0]]) * thickness  # outward normal x length
        elif facets.shape[1] == 3:
            nA = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        else:
            nA = np.cross(p[:, 1] - p[:, 0], p[:, 3] - p[:, 0])  # rectangle: side x side
        force = nA @ sigma.T  # (nf, d): sigma n A
        for k in range(facets.shape[1]):
            np.add.at(f, facets[:, k], force / facets.shape[1])
    return f.ravel()


# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["quad", "triangle", "hexahedron", "tetra"])
def test_patch_test(kind):
    """Patch test on distorted meshes: under the linear displacement u = A x + b the exact
    stress is uniform, sigma = lambda tr(eps) I + 2 mu eps (plane strain in 2D); K u must
    equal the consistent nodal forces of the traction sigma.n on the boundary, computed by
    hand (zero at interior nodes). Tolerance 1e-9 of the largest force: exact up to
    rounding of sums of ~30 terms of size E h."""
    mesh = {**meshes_2d(), **meshes_3d()}[kind]
    d, thickness = mesh.dim, (0.07 if mesh.dim == 2 else 1.0)
    rng = np.random.default_rng(1)
    A = 1e-3 * rng.standard_normal((d, d))
    u = (mesh.points @ A.T + 1e-4 * rng.standard_normal(d)).ravel()
    eps = 0.5 * (A + A.T)
    lam, mu = lame(E, NU)
    sigma = lam * np.trace(eps) * np.eye(d) + 2 * mu * eps
    K, _ = assemble(mesh, E, NU, RHO, thickness)
    expected = hand_consistent_forces(mesh, sigma, thickness)
    np.testing.assert_allclose(K @ u, expected, atol=1e-9 * np.abs(expected).max())


@pytest.mark.parametrize("kind", ["quad", "triangle", "hexahedron", "tetra"])
def test_total_mass(kind):
    """Each direction's total mass 1^T M 1_c equals rho x volume (2D: area x thickness),
    with the volume from the box sizes; exact up to rounding (1e-12)."""
    mesh = {**meshes_2d(), **meshes_3d()}[kind]
    d, thickness = mesh.dim, (0.07 if mesh.dim == 2 else 1.0)
    volume = 0.3 * 0.2 * (0.07 if d == 2 else 0.1)
    _, M = assemble(mesh, E, NU, RHO, thickness)
    for c in range(d):
        ones = np.zeros((len(mesh.points), d))
        ones[:, c] = 1.0
        ones = ones.ravel()
        assert ones @ (M @ np.ones(M.shape[0])) == pytest.approx(RHO * volume, rel=1e-12)
        assert ones @ M @ ones == pytest.approx(RHO * volume, rel=1e-12)


@pytest.mark.parametrize("kind", ["quad", "triangle", "hexahedron", "tetra"])
def test_rigid_body_modes(kind):
    """K times a rigid translation or rotation (built from node coordinates) is zero up to
    rounding: 1e-12 of |K| |u|. K and M are symmetric, node-major."""
    mesh = {**meshes_2d(), **meshes_3d()}[kind]
    d = mesh.dim
    K, M = assemble(mesh, E, NU, RHO, 0.07 if d == 2 else 1.0)
    x = mesh.points - mesh.points.mean(axis=0)
    modes = [np.tile(e, len(x)) for e in np.eye(d)]
    if d == 2:
        modes.append(np.column_stack([-x[:, 1], x[:, 0]]).ravel())
    else:
        modes += [np.cross(e, x).ravel() for e in np.eye(3)]
    scale = abs(K).max()
    for u in modes:
        assert np.abs(K @ u).max() <= 1e-12 * scale * np.abs(u).max()
    assert abs(K - K.T).max() == 0.0 and abs(M - M.T).max() == 0.0


def test_free_free_beam_frequencies_converge_to_euler_bernoulli():
    """First two bending frequencies of a free-free plane-strain beam (L/h = 50) against
    Euler-Bernoulli, f = (beta L)^2 / (2 pi L^2) sqrt(E' I / (rho A)), E' = E/(1-nu^2).

    Nested refinements with square Q4 elements (ny = 1, 2, 4, 8 through the height):
    * the frequencies decrease monotonically (consistent-mass conforming FE eigenvalues are
      upper bounds that decrease under nested refinement);
    * the error against Euler-Bernoulli decreases monotonically: 25 %, 7 %, 1.6 %, 0.3 %
      (mode 1);
    * successive differences shrink by a factor close to 4: second-order convergence of the
      eigenvalues for bilinear elements, once the coarse meshes' shear locking is gone;
    * the Richardson extrapolate f_8 - (f_4 - f_8)/3 is within 0.3 % (mode 1) and 0.6 %
      (mode 2) of Euler-Bernoulli: shear and rotary inertia (Timoshenko) lower the 2D
      frequencies by about 0.15 % and 0.45 % at this slenderness.
    """
    L, h, t = 0.5, 0.01, 0.01
    Ep = E / (1 - NU**2)
    beta_L = np.array([4.730040745, 7.853204624])
    f_eb = beta_L**2 / (2 * np.pi * L**2) * np.sqrt(Ep * h**2 / 12 / RHO)
    freqs = []
    for ny in (1, 2, 4, 8):
        K, M = assemble(rectangle(L, h, 50 * ny, ny), E, NU, RHO, t)
        sigma = (2 * np.pi * 0.7 * f_eb[0]) ** 2
        w2 = spla.eigsh(K, M=M, k=5, sigma=sigma, which="LM", return_eigenvectors=False)
        f = np.sort(np.sqrt(np.abs(w2))) / (2 * np.pi)
        freqs.append(f[f > 0.5 * f_eb[0]][:2])  # skip the three rigid-body modes
    freqs = np.array(freqs)
    error = np.abs(freqs / f_eb - 1)
    assert np.all(np.diff(freqs, axis=0) < 0)
    assert np.all(np.diff(error, axis=0) < 0)
    diffs = -np.diff(freqs, axis=0)
    ratio = diffs[-2] / diffs[-1]
    assert np.all((ratio > 3.5) & (ratio < 4.5)), ratio
    extrapolated = freqs[-1] - diffs[-1] / 3
    assert abs(extrapolated[0] / f_eb[0] - 1) < 3e-3
    assert abs(extrapolated[1] / f_eb[1] - 1) < 6e-3
    assert error[-1, 0] < 5e-3


def test_bad_material():
    m = rectangle(1.0, 1.0, 1, 1)
    with pytest.raises(InputError, match=r"nu = 0.5.*-1 < nu < 0.5"):
        assemble(m, E, 0.5, RHO)
    with pytest.raises(InputError, match=r"E = -1 Pa; expected E > 0"):
        assemble(m, -1.0, NU, RHO)
    with pytest.raises(InputError, match="density"):
        assemble(m, E, NU, -1.0)
    with pytest.raises(InputError, match="thickness"):
        assemble(m, E, NU, RHO, thickness=0.0)


def test_unused_node_is_refused():
    m = rectangle(1.0, 1.0, 1, 1)
    m = Mesh(np.vstack([m.points, [[5.0, 5.0]]]), m.cells, "quad")
    with pytest.raises(InputError, match="belong to no cell"):
        assemble(m, E, NU, RHO)


@pytest.mark.parametrize("E", [1e308, 1e-300, 0.5, 2e13])
def test_youngs_modulus_outside_the_documented_range_is_refused(E):
    """Reference: fretwear.limits.RANGES["modulus"] = [1, 1e13] Pa."""
    from fretwear.model.fem import check_material

    with pytest.raises(InputError, match=r"Young's modulus E = .* Pa: expected a magnitude in "
                                         r"\[1, 1e\+13\] Pa"):
        check_material(E, 0.3, 7800.0)


@pytest.mark.parametrize("rho", [1e-300, 1e-4, 2e5])
def test_density_outside_the_documented_range_is_refused(rho):
    """Reference: fretwear.limits.RANGES["density"] = 0, or [1e-3, 1e5] kg/m^3 (a density of
    1e-300 made the mass matrix underflow and the solve fail deep inside LAPACK)."""
    from fretwear.model.fem import check_material

    with pytest.raises(InputError, match=r"density rho = .* kg/m\^3: expected 0 or a magnitude "
                                         r"in \[0.001, 100000\] kg/m\^3"):
        check_material(2e11, 0.3, rho)
    assert check_material(2e11, 0.3, 0.0)[2] == 0.0  # massless stays legal


def test_stiffness_equals_scikit_fem_linear_elasticity():
    """The elasticity form written out (2 mu eps(u) : eps(v) + lam div u div v) assembles the
    stiffness of scikit-fem's own linear_elasticity form (an independent implementation of
    the same form) to 1e-14 relative (rounding: the same quadrature, other sums) on a
    hexahedral and a quadrilateral (plane strain) mesh."""
    import skfem
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    from fretwear.model import box, rectangle
    from fretwear.model.fem import _symmetric, assemble, node_major, skfem_mesh

    for mesh, nu in ((box(0.01, 0.012, 0.003, 4, 3, 2), 0.3), (rectangle(0.01, 0.004, 5, 3),
                                                               0.25)):
        K, _ = assemble(mesh, 210e9, nu, 7800.0)
        m, elem = skfem_mesh(mesh)
        basis = skfem.Basis(m, skfem.ElementVector(elem))
        p = node_major(basis)
        ref = skfem.asm(linear_elasticity(*lame_parameters(210e9, nu)), basis).tocsr()
        ref = _symmetric(ref[p][:, p])
        assert abs(K - ref).max() <= 1e-14 * abs(ref).max()
