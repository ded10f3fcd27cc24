"""Building a Model from a mesh (fretwear.model.build).

References independent of the code under test: the paper's beam data (Salles et al. 2011,
section 4.2), hand-computed tributary areas and resultants, and the exact solution of a
block pressed on a frictionless support (uniform stress, so the contact reaction per unit
area equals the applied pressure at every node).
"""

import math

import numpy as np
import pytest
import scipy.sparse.linalg as spla
from helpers.beams import STEEL, H, L, W, paper_beam

from fretwear.errors import InputError
from fretwear.model.build import (
    ContactSpec,
    Material,
    NodalForce,
    Spring,
    Traction,
    from_mesh,
)
from fretwear.model.core import Load
from fretwear.model.fem import assemble
from fretwear.model.mesh import box, rectangle


def solve_held(model, held):
    """Static solution with the DOFs ``held`` at zero; returns U and F - K U (the reactions:
    with the core convention K U + T^T lambda = F, the contact forces are
    lambda = frame @ (F - K U) at each contact node)."""
    F = model.load_harmonics(0)[0].real
    free = np.setdiff1d(np.arange(model.ndof), held)
    U = np.zeros(model.ndof)
    U[free] = spla.spsolve(model.K[free][:, free].tocsc(), F[free])
    return U, F - model.K @ U


# --------------------------------------------------------------------------------------------
def test_paper_beam_model():
    """Every field of the paper's beam against hand values: 93 nodes / 186 DOFs; 31 contact
    nodes ordered by x with frame [n, t] = [(0, -1), (1, 0)]; tributary areas (L/30) x W,
    halved at both ends, adding up to L x W exactly; the spring adds 1e4 N/m to the x DOF
    of node (0, h/2) only; D = 0.001 K of the structure; resultants of P and Q; observed
    point P_e on its node. Exact up to rounding (1e-12 relative)."""
    model = paper_beam()
    c = model.contact
    assert model.ndof == 186 and model.dim == 2 and model.thickness == W
    assert c.n_nodes == 31 and c.mu == 0.3 and c.wear_coefficient == 1e-11
    np.testing.assert_allclose(c.coords[:, 0], np.linspace(0, L, 31), atol=1e-15)
    np.testing.assert_array_equal(c.coords[:, 1], 0.0)
    np.testing.assert_array_equal(c.frame, np.tile([[0.0, -1.0], [1.0, 0.0]], (31, 1, 1)))
    np.testing.assert_array_equal(c.dofs, 2 * c.node_ids[:, None] + [0, 1])
    area = np.full(31, L / 30 * W)
    area[[0, -1]] /= 2
    np.testing.assert_allclose(c.area, area, rtol=1e-12)
    assert c.area.sum() == pytest.approx(L * W, rel=1e-14)
    np.testing.assert_array_equal(c.gap, 0.0)

    K0, M = assemble(rectangle(L, H, 30, 2), STEEL.E, STEEL.nu, STEEL.rho, W)
    spring = (model.K - K0).tocoo()
    spring.eliminate_zeros()
    node = 31  # (0, h/2)
    assert spring.nnz == 1 and (spring.row[0], spring.col[0]) == (2 * node, 2 * node)
    assert spring.data[0] == pytest.approx(1e4, rel=1e-9)
    assert abs(model.D - 1e-3 * K0).max() == 0.0 and model.C is None
    assert abs(model.M - M).max() == 0.0

    P, Q = model.loads
    assert (P.name, P.waveform, Q.name, Q.waveform) == ("P", "constant", "Q", "sin")
    np.testing.assert_allclose(P.vector.reshape(-1, 2).sum(0), [0, -1e4 * L * W], atol=1e-12)
    np.testing.assert_allclose(Q.vector.reshape(-1, 2).sum(0), [-1e4 * H * W, 0], atol=1e-12)
    pe = model.observed_point("Pe")
    assert pe.coords.tolist() == [L, H / 2] and pe.dofs.tolist() == [2 * 61, 2 * 61 + 1]
    assert len(model.fixed_dofs) == 0


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45])
def test_frictionless_block_uniform_contact_reaction(nu):
    """A block on a frictionless support under a uniform pressure p on top. Holding the
    contact normal DOFs (as the frictionless contact does, no gap), leaving the tangential
    DOFs free and stopping rigid sliding with one x spring at the top-left corner, the exact
    solution is a uniform stress sigma_yy = -p with free lateral expansion; FE reproduces it
    exactly (patch test). So at every contact node the normal contact force divided by its
    tributary area equals p, the tangential force is zero and the spring carries nothing:
    to rounding (1e-9)."""
    p = 2.5e6
    mesh = rectangle(0.04, 0.01, 8, 3)
    model = from_mesh(mesh, Material(70e9, nu), thickness=0.02,
                      supports=[Spring("top_left", "x", 1e8)],
                      loads=[Traction("top", pressure=p)],
                      contact=ContactSpec("bottom", mu=0.0))
    c = model.contact
    U, R = solve_held(model, c.dofs[:, 1])  # normal is -y: hold the y DOFs
    lam = np.einsum("nij,nj->ni", c.frame, R[c.dofs])  # frame @ (F - K U) per node
    np.testing.assert_allclose(lam[:, 0] / c.area, p, rtol=1e-9)
    np.testing.assert_allclose(lam[:, 1], 0.0, atol=1e-9 * p * c.area.max())
    assert abs(U[2 * mesh.node_sets["top_left"][0]]) < 1e-12  # spring unloaded


def test_frictionless_block_3d_uniform_contact_reaction():
    """The same in 3D on hexahedra: a box on its zmin face, pressure on zmax, x springs at
    two corners and a y spring to stop rigid sliding and spinning; the contact force per
    consistent nodal area equals p at every node (corner, edge and interior nodes carry
    areas in the ratio 1:2:4). To rounding (1e-9)."""
    p = 1e6
    mesh = box(0.03, 0.02, 0.01, 3, 2, 2)
    top = mesh.points[:, 2] == 0.01
    corner = lambda x, y: tuple(mesh.points[top & (mesh.points[:, 0] == x)  # noqa: E731
                                            & (mesh.points[:, 1] == y)][0])
    model = from_mesh(mesh, Material(200e9, 0.25),
                      supports=[Spring(corner(0, 0), "x", 1e9), Spring(corner(0, 0.02), "x", 1e9),
                               Spring(corner(0, 0), "y", 1e9)],
                      loads=[Traction("zmax", pressure=p)],
                      contact=ContactSpec("zmin", mu=0.0))
    c = model.contact
    normal_dof = c.dofs[:, 2]  # normal (0, 0, -1)
    np.testing.assert_array_equal(c.frame[:, 0], np.tile([0.0, 0.0, -1.0], (c.n_nodes, 1)))
    _, R = solve_held(model, normal_dof)
    lam = np.einsum("nij,nj->ni", c.frame, R[c.dofs])
    np.testing.assert_allclose(lam[:, 0] / c.area, p, rtol=1e-9)
    assert sorted(set(np.round(c.area / c.area.min(), 12))) == [1.0, 2.0, 4.0]
    assert c.area.sum() == pytest.approx(0.03 * 0.02, rel=1e-14)


def test_contact_frames_and_areas_3d():
    """Default 3D frame on a tilted plane: rows orthonormal and right-handed, n = given
    normal, t1 = projection of x on the plane; on the xmax face t1 falls back to the y axis.
    Contact areas of tetrahedral faces add up to the face area."""
    mesh = box(1.0, 1.0, 1.0, 2, 2, 2)
    n = np.array([0.0, -0.6, -0.8])  # tilted obstacle under the zmin face
    model = from_mesh(mesh, STEEL, supports=[Spring("xmin", "x", 1e6), Spring("ymin", "y", 1e6),
                                            Spring("xmax", "y", 1e6)],
                      contact=ContactSpec("zmin", mu=0.5, normal=tuple(n)))
    F = model.contact.frame[0]
    np.testing.assert_allclose(F @ F.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(F) == pytest.approx(1.0)
    np.testing.assert_allclose(F[0], n)
    np.testing.assert_allclose(F[1], [1.0, 0.0, 0.0], atol=1e-15)
    model = from_mesh(mesh, STEEL, supports=[Spring("ymin", "y", 1e6), Spring("zmin", "z", 1e6),
                                            Spring("zmax", "y", 1e6)],
                      contact=ContactSpec("xmax", mu=0.5))
    np.testing.assert_allclose(model.contact.frame[0], [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
                               atol=1e-15)
    assert model.contact.area.sum() == pytest.approx(1.0, rel=1e-14)


def test_contact_options_2d():
    """Right face as contact: default tangent (0, 1); a user tangent (0, -1) is kept; the
    gap function sees the node coordinates; a negative gap (interference) is accepted."""
    mesh = rectangle(0.1, 0.02, 10, 4)
    springs = [Spring("left", "y", 1e6)]
    m1 = from_mesh(mesh, STEEL, supports=springs, contact=ContactSpec("right", mu=0.1))
    np.testing.assert_array_equal(m1.contact.frame[0], [[1, 0], [0, 1]])
    np.testing.assert_allclose(m1.contact.coords[:, 1], np.linspace(0, 0.02, 5))
    m2 = from_mesh(mesh, STEEL, supports=springs,
                   contact=ContactSpec("right", mu=0.1, tangent=(0, -1),
                                       gap=lambda x: 1e-6 * x[:, 1] - 1e-8))
    np.testing.assert_array_equal(m2.contact.frame[0], [[1, 0], [0, -1]])
    np.testing.assert_allclose(m2.contact.gap, 1e-6 * m2.contact.coords[:, 1] - 1e-8)


def test_springs_fixed_and_loads_conventions():
    """A spring on a node set shares its stiffness equally (total = stiffness); an infinite
    spring and a fixed pair give fixed DOFs; a nodal force on a set is shared equally; a
    Fourier waveform keeps its coefficients; a core.Load passes through."""
    mesh = rectangle(0.1, 0.01, 10, 2)
    K0, _ = assemble(mesh, STEEL.E, STEEL.nu, STEEL.rho, 1.0)
    right = mesh.node_sets["right"]
    extra = np.zeros(mesh.points.shape[0] * 2)
    extra[5] = 1.0
    model = from_mesh(
        mesh, STEEL,
        supports=[Spring("right", "x", 3e6), Spring("top_left", "x", math.inf),
                  ((0.05, 0.01), "all")],
        loads=[NodalForce("right", (0.0, -9.0), waveform="fourier",
                          coefficients={1: (1.0, 0.0), 3: (0.2, 0.0)}),
               Load(extra, "cos", name="extra")],
        contact=ContactSpec("bottom", mu=0.2),
    )
    dK = (model.K - K0).diagonal()
    np.testing.assert_allclose(dK[2 * right], 1e6, rtol=1e-9)
    assert np.count_nonzero(np.abs(dK) > 1e-3) == 3
    top_left, mid_top = mesh.node_sets["top_left"][0], 2 * 11 + 5
    assert model.fixed_dofs.tolist() == sorted([2 * top_left, 2 * mid_top, 2 * mid_top + 1])
    f = model.loads[0].vector.reshape(-1, 2)
    np.testing.assert_allclose(f[right], [[0.0, -3.0]] * 3)
    assert model.loads[0].coefficients == {1: (1.0, 0.0), 3: (0.2, 0.0)}
    assert model.loads[1].name == "extra" and model.loads[1].vector[5] == 1.0


# --------------------------------------------------------------------------------------------
# bad inputs: one InputError each, with a message naming the problem
# --------------------------------------------------------------------------------------------
def test_material_errors():
    with pytest.raises(InputError, match=r"nu = 0.5.*expected -1 < nu < 0.5"):
        Material(210e9, 0.5)
    with pytest.raises(InputError, match=r"nu = -1;"):
        Material(210e9, -1.0)
    with pytest.raises(InputError, match=r"E = -2e\+11 Pa; expected E > 0"):
        Material(-2e11, 0.3)
    with pytest.raises(InputError, match="density rho = -1 kg"):
        Material(2e11, 0.3, -1.0)


def test_unknown_boundary_lists_the_available_ones():
    with pytest.raises(InputError, match=r"unknown boundary 'botom'.*\['bottom', 'left', "
                                         r"'right', 'top'\]"):
        paper_beam(contact=ContactSpec("botom", mu=0.3))
    with pytest.raises(InputError, match=r"no node set or boundary of that name.*bottom_left"):
        paper_beam(supports=[Spring("corner", "x", 1e4)])


def test_empty_contact_set():
    mesh = rectangle(L, H, 4, 2)
    mesh.boundaries["nothing"] = np.zeros((0, 2), dtype=np.int64)
    with pytest.raises(InputError, match="boundary 'nothing' is empty: no contact nodes"):
        from_mesh(mesh, STEEL, contact=ContactSpec("nothing", mu=0.3))


def test_other_bad_inputs():
    with pytest.raises(InputError, match="exactly one of pressure"):
        Traction("top")
    with pytest.raises(InputError, match="exactly one of pressure"):
        Traction("top", pressure=1.0, traction=(0.0, 1.0))
    with pytest.raises(InputError, match=r"stiffness = -1.0; expected a value >= 0"):
        Spring("left", "x", -1.0)
    with pytest.raises(InputError, match=r"mu = -0.1; expected a value >= 0"):
        ContactSpec("bottom", mu=-0.1)
    with pytest.raises(InputError, match=r"waveform = 'square'"):
        Traction("top", pressure=1.0, waveform="square")
    with pytest.raises(InputError, match="needs coefficients"):
        NodalForce("top", (1.0, 0.0), waveform="fourier")
    with pytest.raises(InputError, match=r"thickness = 0.0"):
        paper_beam(thickness=0.0)
    with pytest.raises(InputError, match=r"no mesh node there \(nearest node 31"):
        paper_beam(supports=[Spring((0.0, 0.004), "x", 1e4)])
    with pytest.raises(InputError, match="infinite stiffness .* needs an axis direction"):
        paper_beam(supports=[Spring((0.0, H / 2), (1.0, 1.0), math.inf)])
    with pytest.raises(InputError, match="normal .* points into the structure"):
        paper_beam(contact=ContactSpec("bottom", mu=0.3, normal=(0.0, 1.0)))
    with pytest.raises(InputError, match="not orthogonal"):
        paper_beam(contact=ContactSpec("bottom", mu=0.3, tangent=(1.0, 1.0)))
    with pytest.raises(InputError, match=r"node 0 at \(0.0, 0.0\) is a contact node with a "
                                         r"fixed DOF \(x\)"):
        paper_beam(supports=[Spring("left", "x", math.inf)])
    with pytest.raises(InputError, match="the gap function returned shape"):
        paper_beam(contact=ContactSpec("bottom", mu=0.3, gap=lambda x: 0.0 * x))
    with pytest.raises(InputError, match="thickness .* only applies to 2D"):
        from_mesh(box(1, 1, 1, 1, 1, 1), STEEL, thickness=0.5,
                  contact=ContactSpec("zmin", mu=0.1))


def test_two_flank_contact_gets_per_node_normals():
    """A contact boundary made of the bottom and right faces (two flanks at a right angle):
    every node gets the outward normal of its flank, the corner node the average of its two
    facets' normals weighted by their lengths (0.025 m along x, 0.005 m along y), each frame
    orthonormal; exact geometry, to rounding."""
    mesh = rectangle(0.1, 0.01, 4, 2)
    mesh.boundaries["corner"] = np.vstack([mesh.boundaries["bottom"], mesh.boundaries["right"]])
    c = from_mesh(mesh, STEEL, contact=ContactSpec("corner", mu=0.1),
                  supports=[Spring((0.0, 0.005), "x", 1e4)]).contact
    x = c.coords
    corner = np.isclose(x[:, 0], 0.1) & np.isclose(x[:, 1], 0.0)
    bottom = np.isclose(x[:, 1], 0.0) & ~corner
    right = np.isclose(x[:, 0], 0.1) & ~corner
    np.testing.assert_allclose(c.frame[bottom, 0], [[0.0, -1.0]] * bottom.sum(), atol=1e-15)
    np.testing.assert_allclose(c.frame[right, 0], [[1.0, 0.0]] * right.sum(), atol=1e-15)
    expected = np.array([0.005, -0.025]) / math.hypot(0.005, 0.025)
    np.testing.assert_allclose(c.frame[corner, 0], [expected], atol=1e-15)
    gram = c.frame @ np.swapaxes(c.frame, 1, 2)
    np.testing.assert_allclose(gram, np.broadcast_to(np.eye(2), gram.shape), atol=1e-14)


def test_folded_contact_boundary_is_refused():
    """A triangle's two sides meeting at an 11 degree tip: their outward normals are 169
    degrees apart at the tip node: one message naming the node."""
    from fretwear.model.core import Mesh

    mesh = Mesh(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.2]]), np.array([[0, 1, 2]]),
                "triangle", boundaries={"tip": np.array([[0, 1], [2, 0]])})
    with pytest.raises(InputError, match="normals flip between neighbouring facets at node 0"):
        from_mesh(mesh, STEEL, contact=ContactSpec("tip", mu=0.1))


