"""Stiffness, mass and consistent loads (fretwear.model.fem, fretwear.model.loads).

References independent of the code under test: the exact linear-elastic solution of a
uniform stress state (patch test), the body's volume, rigid-body motions, the
Euler-Bernoulli frequencies of a free-free beam, and consistent nodal forces worked out by
hand for straight edges and flat faces.
"""

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from fretwear.errors import InputError
from fretwear.model.core import Mesh
from fretwear.model.fem import assemble
from fretwear.model.loads import (
    boundary_load,
    boundary_measure,
    nodal_areas,
    nodal_force,
    resultant,
)
from fretwear.model.mesh import box, rectangle

E, NU, RHO = 210e9, 0.3, 7800.0
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


# --------------------------------------------------------------------------------------------
# consistent loads
# --------------------------------------------------------------------------------------------
def test_uniform_pressure_resultant_2d():
    """Sum of the nodal forces of a pressure p on the top edge = -p x length x thickness
    along y (the pressure pushes on the body); each interior node carries p x h x t, each
    end node half of it (hand values). Exact up to rounding."""
    m = rectangle(0.1, 0.01, 30, 2)
    f = boundary_load(m, "top", pressure=1e4, thickness=0.01).reshape(-1, 2)
    np.testing.assert_allclose(f.sum(axis=0), [0.0, -1e4 * 0.1 * 0.01], atol=1e-15)
    top = m.node_sets["top"]
    expected = np.full(31, -1e4 * 0.1 / 30 * 0.01)
    expected[[0, -1]] /= 2
    np.testing.assert_allclose(f[top, 1], expected, rtol=1e-12)
    assert np.all(np.delete(f, top, axis=0) == 0.0)
    np.testing.assert_allclose(resultant(m, "right", traction=(2.0, -3.0), thickness=0.5),
                               [2.0 * 0.01 * 0.5, -3.0 * 0.01 * 0.5], rtol=1e-12)
    assert boundary_measure(m, "left") == pytest.approx(0.01, rel=1e-14)


def test_linear_traction_exact_nodal_values():
    """A traction varying linearly along a non-uniformly divided edge: the exact consistent
    forces of a 2-node edge from x1 to x2 are L/6 (2 t1 + t2) and L/6 (t1 + 2 t2), summed
    over the edges by hand. Exact up to rounding (1e-12)."""
    base = rectangle(1.0, 0.5, 5, 1)
    pts = base.points.copy()
    xs = np.array([0.0, 0.1, 0.35, 0.5, 0.8, 1.0])
    pts[:, 0] = np.tile(xs, 2)
    m = Mesh(pts, base.cells, "quad", base.boundaries, base.node_sets)
    tx = lambda x: 3.0 + 2.0 * x  # noqa: E731
    ty = lambda x: -1.0 + 0.5 * x  # noqa: E731
    f = boundary_load(m, "bottom",
                      traction=lambda p: np.column_stack([tx(p[:, 0]), ty(p[:, 0])]),
                      thickness=2.0).reshape(-1, 2)
    expected = np.zeros((6, 2))
    for k in range(5):
        x1, x2 = xs[k], xs[k + 1]
        for c, t in enumerate((tx, ty)):
            expected[k, c] += (x2 - x1) / 6 * (2 * t(x1) + t(x2))
            expected[k + 1, c] += (x2 - x1) / 6 * (t(x1) + 2 * t(x2))
    np.testing.assert_allclose(f[:6], 2.0 * expected, rtol=1e-12)
    # the same with a linearly varying pressure on the bottom (outward normal -y)
    fp = boundary_load(m, "bottom", pressure=lambda p: tx(p[:, 0]), thickness=2.0)
    np.testing.assert_allclose(fp.reshape(-1, 2)[:6, 1], 2.0 * expected[:, 0], rtol=1e-12)


@pytest.mark.parametrize("kind", ["hexahedron", "tetra"])
def test_pressure_on_a_face_3d(kind):
    """Pressure p on the zmax face of a 0.3 x 0.2 box: resultant -p x 0.06 along z, and the
    nodal areas add up to the face area (exact up to rounding)."""
    m = meshes_3d()[kind]
    f = resultant(m, "zmax", pressure=5.0)
    np.testing.assert_allclose(f, [0.0, 0.0, -5.0 * 0.06], atol=1e-14)
    nodes, area = nodal_areas(m, "zmax")
    assert area.sum() == pytest.approx(0.06, rel=1e-13)
    assert np.all(area > 0) and len(nodes) == 4 * 3


def test_load_argument_errors():
    m = rectangle(1.0, 1.0, 2, 2)
    with pytest.raises(InputError, match="exactly one of pressure"):
        boundary_load(m, "top")
    with pytest.raises(InputError, match="exactly one of pressure"):
        boundary_load(m, "top", pressure=1.0, traction=(1.0, 0.0))
    with pytest.raises(InputError, match=r"unknown boundary 'up'.*\['bottom', 'left'"):
        boundary_load(m, "up", pressure=1.0)
    with pytest.raises(InputError, match="traction"):
        boundary_load(m, "top", traction=(1.0, 0.0, 0.0))
    with pytest.raises(InputError, match="returned shape"):
        boundary_load(m, "top", pressure=lambda x: np.ones(3))


def test_nodal_force():
    m = rectangle(1.0, 1.0, 1, 1)
    f = nodal_force(m, 3, (1.0, -2.0))
    assert f.tolist() == [0, 0, 0, 0, 0, 0, 1.0, -2.0]
    assert nodal_force(9, 1, (0.0, 0.0, 4.0)).tolist() == [0, 0, 0, 0, 0, 4.0, 0, 0, 0]
    with pytest.raises(InputError, match="node number"):
        nodal_force(m, 4, (1.0, 0.0))


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
