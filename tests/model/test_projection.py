"""Closest points on facets and node-to-segment weights (fretwear.model.projection).

References: brute-force minimum distance over a dense sampling of each facet (independent
of the closed-form and Newton projections), the interpolation identity ``sum N_k x_k = x``
at the returned point, and the kinematic patch test: an affine displacement field plus a
rigid translation ``delta`` of one body gives the relative displacement ``delta`` at every
contact node of a non-matching interface (linear fields are interpolated exactly).
"""

import numpy as np
import pytest

from fretwear.model import ContactSpec, Material, Spring, from_mesh, join, rectangle
from fretwear.model.core import ContactInterface, Segments
from fretwear.model.projection import closest_on_facet, partner_node_values, project, snapped

STEEL = Material(210e9, 0.3, 7800.0)
FACETS = {
    2: np.array([[0.0, 0.0, 0.0], [1.0, 0.2, 0.1]]),
    3: np.array([[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.2, 0.9, 0.1]]),
    4: np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.1], [1.2, 1.0, 0.0], [0.1, 0.8, 0.0]]),
}


def samples(x, n=201):
    """Points of facet ``x`` on a fine grid of its parameters."""
    s = np.linspace(0.0, 1.0, n)
    if x.shape[0] == 2:
        return np.outer(1 - s, x[0]) + np.outer(s, x[1])
    u, v = np.meshgrid(s, s)
    u, v = u.ravel(), v.ravel()
    if x.shape[0] == 3:
        keep = u + v <= 1.0
        u, v = u[keep], v[keep]
        return np.outer(1 - u - v, x[0]) + np.outer(u, x[1]) + np.outer(v, x[2])
    return (np.outer((1 - u) * (1 - v), x[0]) + np.outer(u * (1 - v), x[1])
            + np.outer(u * v, x[2]) + np.outer((1 - u) * v, x[3]))


@pytest.mark.parametrize("k", [2, 3, 4])
def test_closest_point_is_the_sampled_minimum(k):
    """40 random points around each facet: the distance to the returned point equals the
    brute-force minimum over 201 (x 201) samples, within the sampling step squared over the
    distance (about 3e-5 here: tolerance 1e-4 of the facet size), and never less than it by
    more than rounding; the weights interpolate the returned point exactly."""
    x = FACETS[k]
    rng = np.random.default_rng(3)
    grid = samples(x)
    for p in rng.uniform(-0.5, 1.5, (40, 3)):
        w, q = closest_on_facet(x, p)
        np.testing.assert_allclose(w @ x, q, rtol=0, atol=1e-14)
        assert abs(w.sum() - 1.0) < 1e-14 and np.all(w >= -1e-14)
        best = np.linalg.norm(grid - p, axis=1).min()
        got = np.linalg.norm(q - p)
        assert got <= best + 1e-12 and got >= best - 1e-4


def test_node_on_a_master_node_gets_exactly_one_weight():
    """A point within rounding of a facet node has the weights (0, ..., 1, ..., 0) exactly
    (so that matching meshes reproduce node-to-node pairs bit for bit)."""
    x = FACETS[4]
    for j in range(4):
        w, _ = closest_on_facet(x, x[j] + 1e-15)
        e = np.zeros(4)
        e[j] = 1.0
        np.testing.assert_array_equal(snapped(w), e)
    np.testing.assert_array_equal(snapped(np.array([0.5 + 1e-12, 0.5 - 1e-12, 1e-13])),
                                  [0.5 + 1e-12, 0.5 - 1e-12, 0.0])


def lap(nu, nb, **kw):
    """A 20 x 10 mm block (nu x 2 Q4) on a 20 x 5 mm base (nb x 1 Q4)."""
    mesh = join(("block", rectangle(0.02, 0.01, nu, 2, origin=(0.0, 0.005))),
                ("base", rectangle(0.02, 0.005, nb, 1)))
    return mesh, from_mesh(mesh, STEEL, supports=[Spring("block.top_left", "x", 1e7),
                                                  ("base.bottom", "all")],
                           contact=ContactSpec("block.bottom", mu=0.3, partner="base.top",
                                               **kw))


@pytest.mark.parametrize("pairing", ["node-to-segment", "mortar"])
def test_affine_field_and_rigid_slip_give_uniform_relative_motion(pairing):
    """Kinematic patch test on 3 against 5 elements: U = A x + b on both bodies plus a
    rigid translation delta of the block: every contact node's local relative displacement
    is frame @ delta, to rounding (1e-12 of |delta|)."""
    mesh, model = lap(3, 5, pairing=pairing)
    c = model.contact
    assert c.segments is not None
    A = np.array([[1e-4, -2e-4], [3e-4, 5e-5]])
    delta = np.array([2e-6, -1e-6])
    U = mesh.points @ A.T + np.array([1e-6, 2e-6])
    U[mesh.node_sets["block"]] += delta
    r = (c.local_transform(model.ndof) @ U.ravel()).reshape(-1, 2)
    np.testing.assert_allclose(r, c.frame @ delta, rtol=0, atol=1e-12 * np.abs(delta).max())


def test_projection_of_a_node_off_every_facet():
    """A node beyond the end of a face goes to its end point, at its true distance."""
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.5, 0.3]])
    proj = project(pts, np.array([3]), np.array([[0, 1], [1, 2]]))
    np.testing.assert_array_equal(proj.weights, [[0.0, 1.0]])
    np.testing.assert_array_equal(proj.nodes, [[-1, 2]])
    np.testing.assert_allclose(proj.distance, [np.hypot(0.5, 0.3)], rtol=1e-15)


def test_partner_values_by_the_same_weights():
    """A uniform value stays uniform on the facet nodes; a node-to-node record gives each
    partner its pair's value."""
    seg = Segments(dofs=np.zeros((3, 2, 2), int), weights=np.array([[1.0, 0.0], [0.5, 0.5],
                                                                     [0.25, 0.75]]),
                   ids=np.array([[7, -1], [7, 8], [7, 8]]))
    c = ContactInterface(np.zeros((3, 2), int), np.zeros((3, 2, 2)), np.zeros(3),
                         np.array([1.0, 2.0, 3.0]), 0.3, np.zeros((3, 2)),
                         partner_dofs=np.zeros((3, 2), int), segments=seg)
    ids, v = partner_node_values(c, np.full(3, 4.0))
    np.testing.assert_array_equal(ids, [7, 8])
    np.testing.assert_allclose(v, 4.0, rtol=1e-15)
    nn = ContactInterface(np.zeros((2, 2), int), np.zeros((2, 2, 2)), np.zeros(2), np.ones(2),
                          0.3, np.zeros((2, 2)), partner_dofs=np.array([[4, 5], [-1, -1]]),
                          partner_ids=np.array([2, -1]))
    ids, v = partner_node_values(nn, np.array([1.0, 2.0]))
    np.testing.assert_array_equal(ids, [2])
    np.testing.assert_array_equal(v, [1.0])
