"""Mortar pairing with dual shape functions (fretwear.model.mortar).

References independent of the code under test:

* biorthogonality of the dual shape functions, ``int Phi_i N_j = delta_ij int N_i``, by a
  tensor Gauss rule of high order on the reference facet;
* the patch test: two bodies of one material, meshed apart, under a uniform pressure on a
  frictionless interface are in a uniform stress state (the exact solution is linear, so
  the finite elements hold it): every contact node carries ``p x`` its area, to rounding; the
  node-to-segment pairing fails it (shown, so that the test can fail);
* matching meshes: the mortar weights are ``(1, 0, ...)`` exactly and the solution is the
  node-to-node one bit for bit.
"""

import numpy as np
import pytest

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.model import (
    ContactSpec,
    Damping,
    Material,
    Spring,
    Traction,
    box,
    from_mesh,
    join,
    rectangle,
)
from fretwear.model.interfaces import pair_transform
from fretwear.model.mortar import _dual, mortar
from fretwear.model.projection import closest_on_facet

STEEL = Material(210e9, 0.3, 7800.0)
P = 20e6
STATIC = FourierBasis.up_to(1, 8)


@pytest.mark.parametrize("k", [2, 3, 4])
def test_dual_shape_functions_are_biorthogonal(k):
    """On the reference segment, triangle and square, by a 6 x 6 Gauss rule (exact for
    these polynomials): ``int Phi_i N_j = delta_ij int N_i`` to rounding."""
    x, w = np.polynomial.legendre.leggauss(6)
    if k == 2:
        facet = np.array([[0.0, 0.0], [1.0, 0.0]])
        pts = [(np.array([0.5 + 0.5 * a, 0.0]), 0.5 * wa) for a, wa in zip(x, w, strict=True)]
    else:
        facet = (np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]) if k == 3 else
                 np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]))
        pts = []
        for a, wa in zip(x, w, strict=True):
            for b, wb in zip(x, w, strict=True):
                u, v = 0.5 + 0.5 * a, 0.5 + 0.5 * b
                if k == 3:  # Duffy map of the square onto the triangle
                    pts.append((np.array([u * (1 - v), v, 0.0]), 0.25 * wa * wb * (1 - v)))
                else:
                    pts.append((np.array([u, v, 0.0]), 0.25 * wa * wb))
    G = np.zeros((k, k))
    mass = np.zeros(k)
    for p, wq in pts:
        N = closest_on_facet(facet, p)[0]
        G += wq * np.outer(_dual(N[None], k)[0], N)
        mass += wq * N
    np.testing.assert_allclose(G, np.diag(mass), rtol=0, atol=1e-14)


def blocks_2d(nu, nb, pairing="auto", mu=0.0):
    """A 20 x 10 mm block (nu x 2 Q4) pressed on a 20 x 5 mm base (nb x 1 Q4) on rollers,
    held at its top left corner (where the uniform solution does not move along x)."""
    mesh = join(("upper", rectangle(0.02, 0.01, nu, 2, origin=(0.0, 0.005))),
                ("base", rectangle(0.02, 0.005, nb, 1)))
    return from_mesh(mesh, STEEL, supports=[Spring("upper.top_left", "x", 1e3),
                                            ("base.bottom", "y"), ("base.bottom_left", "x")],
                     loads=[Traction("upper.top", pressure=P, waveform="constant")],
                     contact=ContactSpec("upper.bottom", mu=mu, partner="base.top",
                                         pairing=pairing))


def blocks_3d(pairing):
    """A 10 x 10 x 4 mm block (3 x 2 x 1 hexahedra) on a base (2 x 3 x 1), on rollers."""
    mesh = join(("upper", box(0.01, 0.01, 0.004, 3, 2, 1, origin=(0, 0, 0.004))),
                ("base", box(0.01, 0.01, 0.004, 2, 3, 1)))
    corner = [Spring((0, 0, 0.008), "x", 1e3), Spring((0, 0, 0.008), "y", 1e3),
              Spring((0.01, 0, 0.008), "y", 1e3)]
    return from_mesh(mesh, STEEL, supports=[*corner, ("base.zmin", "z"), ("base.xmin", "x"),
                                            ("base.ymin", "y")],
                     loads=[Traction("upper.zmax", pressure=P, waveform="constant")],
                     contact=ContactSpec("upper.zmin", mu=0.0, partner="base.zmax",
                                         pairing=pairing))


def pressure_error(model):
    """Largest relative deviation of the static normal force per area from ``P``."""
    sol = solve_periodic(model, STATIC, frequency=100.0, options=SolveOptions(tol=1e-13),
                         raise_on_failure=True)
    d = model.dim
    lam0 = sol.lam.reshape(model.contact.n_nodes, d, -1)[:, 0, 0]
    return np.abs(lam0 / model.contact.area / P - 1.0).max()


@pytest.mark.parametrize("nu, nb", [(3, 5), (7, 5)])
def test_patch_test_2d(nu, nb):
    """Uniform pressure across 3 | 5 and 7 | 5 elements: every node carries p x its area
    (measured 1e-12: the rounding of the solve; tolerance 1e-10). Node-to-segment misses
    it by percents on 3 | 5 (measured 13 %)."""
    assert pressure_error(blocks_2d(nu, nb)) < 1e-10
    if nu == 3:
        assert pressure_error(blocks_2d(nu, nb, "node-to-segment")) > 0.05


def test_patch_test_3d():
    """Uniform pressure across 3 x 2 | 2 x 3 hexahedra faces: p x area at every node
    (measured 1.3e-12; tolerance 1e-10); node-to-segment: 20 % off."""
    model = blocks_3d("mortar")
    assert model.contact.segments is not None
    assert pressure_error(model) < 1e-10
    assert pressure_error(blocks_3d("node-to-segment")) > 0.05


@pytest.mark.parametrize("pairing", ["mortar", "node-to-segment"])
def test_mortar_on_matching_meshes_is_node_to_node(pairing):
    """4 | 4 elements with friction under a harmonic tangential load: the mortar (and the
    node-to-segment) weights are exactly one-hot, ``P`` is the node-to-node one, and the
    periodic solution (stick and slip) is the node-to-node one bit for bit."""
    def model(pairing):
        mesh = join(("upper", rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005))),
                    ("base", rectangle(0.02, 0.005, 4, 1)))
        return from_mesh(
            mesh, STEEL, damping=Damping(loss_factor=0.02),
            supports=[Spring("upper.top_left", "x", 1e7), ("base.bottom", "all")],
            loads=[Traction("upper.top", pressure=P, waveform="constant"),
                   Traction("upper.right", traction=(-1e7, 0.0), waveform="cos")],
            contact=ContactSpec("upper.bottom", mu=0.3, partner="base.top", pairing=pairing))
    nn, mo = model("node-to-node"), model(pairing)
    w = mo.contact.segments.weights
    np.testing.assert_array_equal(np.sort(w, axis=1)[:, ::-1][:, 0], 1.0)
    np.testing.assert_array_equal(np.sort(w, axis=1)[:, :-1], 0.0)
    np.testing.assert_array_equal(mo.contact.partner_dofs, nn.contact.partner_dofs)
    assert (pair_transform(mo.contact, mo.ndof) != pair_transform(nn.contact, nn.ndof)).nnz == 0
    basis = FourierBasis.up_to(3, 32)
    a = solve_periodic(nn, basis, frequency=2000.0, options=SolveOptions(tol=1e-12),
                       raise_on_failure=True)
    b = solve_periodic(mo, basis, frequency=2000.0, options=SolveOptions(tol=1e-12),
                       raise_on_failure=True)
    assert np.any(a.state == 2) and np.any(a.state == 1)
    np.testing.assert_array_equal(a.lam, b.lam)
    np.testing.assert_array_equal(a.U, b.U)


def test_coverage_of_a_node_half_off_the_master_face():
    """A slave segment [0, 2] (t in [0, 1]) against a master face [1, 3]: the covered part is
    t in [1/2, 1]; by hand, 2 int_{1/2}^{1} (2 - 3t) dt = -1/4 and 2 int_{1/2}^{1} (3t - 1) dt
    = 5/4, over int N = 1: coverages -0.25 and 1.25 (far from 1: such nodes are refused)."""
    pts = np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [3.0, 0.0]])
    mo = mortar(pts, np.array([0, 1]), np.array([[0, 1]]), np.array([[2, 3]]))
    np.testing.assert_allclose(mo.coverage, [-0.25, 1.25], rtol=1e-14)


@pytest.mark.parametrize("k", [2, 3, 4])
def test_shape_functions_of_points_on_a_facet(k):
    """The batch shape functions at points of a (non-parallelogram) facet, made from known
    facet coordinates, are those coordinates' shape functions (to 1e-13; the quadrilateral's
    are found by Gauss-Newton)."""
    from fretwear.model.mortar import shape_functions

    rng = np.random.default_rng(5)
    if k == 2:
        x = np.array([[0.0, 0.0, 0.0], [1.0, 0.3, 0.2]])
        t = rng.uniform(0, 1, 20)
        N = np.column_stack([1 - t, t])
    elif k == 3:
        x = np.array([[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.2, 0.9, 0.1]])
        u = rng.dirichlet(np.ones(3), 20)
        N = u
    else:
        x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.2, 1.0, 0.0], [0.1, 0.8, 0.0]])
        xi, eta = rng.uniform(-1, 1, (2, 20))
        N = 0.25 * np.column_stack([(1 - xi) * (1 - eta), (1 + xi) * (1 - eta),
                                    (1 + xi) * (1 + eta), (1 - xi) * (1 + eta)])
    np.testing.assert_allclose(shape_functions(x, N @ x), N, rtol=0, atol=1e-13)


def tet_block(lx, ly, lz, n, origin):
    """A box of n = (nx, ny, nz) cubes, each cut into 6 tetrahedra along its main diagonal
    (Kuhn: conforming across cubes), with triangle boundaries "xmin" ... "zmax" cut along the
    same diagonals."""
    from itertools import permutations

    from fretwear.model.core import Mesh

    nx, ny, nz = n
    g = np.stack(np.meshgrid(*(np.linspace(0, s, m + 1) for s, m in
                               ((lx, nx), (ly, ny), (lz, nz))), indexing="ij"), axis=-1)
    points = g.reshape(-1, 3) + np.asarray(origin, float)

    def at(i, j, k):
        return (i * (ny + 1) + j) * (nz + 1) + k

    cells = []
    for i in range(nx):
        for j in range(ny):
            for k in range(nz):
                for perm in permutations(range(3)):
                    c = np.array([i, j, k])
                    path = [at(*c)]
                    for axis in perm:
                        c[axis] += 1
                        path.append(at(*c))
                    x = points[path]
                    if np.linalg.det(x[1:] - x[0]) < 0:
                        path[1], path[2] = path[2], path[1]
                    cells.append(path)
    boundaries = {}
    for axis, name in enumerate("xyz"):
        for side, end in (("min", 0), ("max", (nx, ny, nz)[axis])):
            tri = []
            others = [a for a in range(3) if a != axis]
            for u in range((nx, ny, nz)[others[0]]):
                for v in range((nx, ny, nz)[others[1]]):
                    corner = {}
                    for du in (0, 1):
                        for dv in (0, 1):
                            c = [0, 0, 0]
                            c[axis], c[others[0]], c[others[1]] = end, u + du, v + dv
                            corner[du, dv] = at(*c)
                    lo, hi = corner[0, 0], corner[1, 1]
                    tri += [[lo, corner[1, 0], hi], [lo, corner[0, 1], hi]]
            boundaries[name + side] = np.array(tri)
    return Mesh(points, np.array(cells), "tetra", boundaries, {})


def test_patch_test_3d_tetrahedra():
    """Uniform pressure across triangle faces of 3 x 2 | 2 x 3 cubes cut into tetrahedra
    (clipped triangles, the triangle's dual functions): p x area at every node, to 1e-10 as
    on hexahedra."""
    mesh = join(("upper", tet_block(0.01, 0.01, 0.004, (3, 2, 1), (0, 0, 0.004))),
                ("base", tet_block(0.01, 0.01, 0.004, (2, 3, 1), (0, 0, 0))))
    corner = [Spring((0, 0, 0.008), "x", 1e3), Spring((0, 0, 0.008), "y", 1e3),
              Spring((0.01, 0, 0.008), "y", 1e3)]
    model = from_mesh(mesh, STEEL, supports=[*corner, ("base.zmin", "z"), ("base.xmin", "x"),
                                             ("base.ymin", "y")],
                      loads=[Traction("upper.zmax", pressure=P, waveform="constant")],
                      contact=ContactSpec("upper.zmin", mu=0.0, partner="base.zmax"))
    assert model.contact.segments is not None
    assert pressure_error(model) < 1e-10


def test_mortar_pairs_in_a_cyclic_sector_are_refused():
    """Refused, in one line naming the pairing: the harmonic-index model of a sector
    (model.cyclic.relative_harmonic_model) changes to relative coordinates ``q_a = q'_a + c
    R^s q'_b``, one partner node for each contact node, which a mortar or node-to-segment
    pair (several weighted master nodes for each contact node) is not. Both ways in: a
    sector model whose own contact has segment pairs, and a neighbour contact asking for
    ``pairing = "mortar"``."""
    import dataclasses

    from helpers.cyclic import sector_model

    from fretwear.errors import InputError
    from fretwear.model.core import Segments
    from fretwear.model.cyclic import harmonic_model, neighbour_contact

    sector, model = sector_model(8)
    c = model.contact
    segs = Segments(np.full((c.n_nodes, 2, 2), -1), np.zeros((c.n_nodes, 2)),
                    np.full((c.n_nodes, 2), -1))
    bad = dataclasses.replace(sector, model=dataclasses.replace(
        model, contact=dataclasses.replace(c, segments=segs)))
    with pytest.raises(InputError, match="mortar pairs .* in a cyclic sector") as exc:
        harmonic_model(bad, 3)
    assert "\n" not in str(exc.value)
    harmonic_model(sector, 3)  # the same sector with node-to-node pairs is accepted
    slit, _ = sector_model(8, slit=True)
    for pairing in ("mortar", "node-to-segment"):
        spec = ContactSpec("slit_a", mu=0.3, partner="slit_b", name="n2", pairing=pairing)
        with pytest.raises(InputError, match=f"pairing = '{pairing}' between neighbour") as exc:
            neighbour_contact(slit, spec)
        assert "\n" not in str(exc.value)


@pytest.mark.parametrize("case", ["q4", "seg"])
def test_weights_of_the_facet_by_facet_implementation(case):
    """The whole-array build gives the weights and coverages that the former facet-by-facet
    loop gave (recorded in tests/data/mortar-reference.npz): a 4 x 3 quadrilateral face on
    a 3 x 4 one, both with their in-plane node positions jittered by up to 0.2 mm (general
    overlaps: 3- to 8-sided clipped polygons), and 7 segments on 5 in 2D. The same master
    nodes; weights and coverages to 1e-14 (sums of the same products in another order)."""
    from pathlib import Path

    ref = np.load(Path(__file__).resolve().parents[1] / "data" / "mortar-reference.npz")
    sf = ref[f"{case}_sf"]
    got = mortar(ref[f"{case}_points"], np.unique(sf), sf, ref[f"{case}_mf"])
    np.testing.assert_array_equal(got.nodes, ref[f"{case}_nodes"])
    np.testing.assert_allclose(got.weights, ref[f"{case}_weights"], rtol=0, atol=1e-14)
    np.testing.assert_allclose(got.coverage, ref[f"{case}_coverage"], rtol=0, atol=1e-14)
    assert np.any((ref[f"{case}_weights"] != 0).sum(axis=1) > 2)  # nodes with several masters
