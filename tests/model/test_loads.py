"""Consistent nodal forces and nodal areas of boundaries (fretwear.model.loads).

References independent of the code under test: consistent nodal forces and tributary areas
worked out by hand for straight edges and flat faces, and the resultants of uniform loads
(pressure x area).
"""

import numpy as np
import pytest
from helpers.meshes import meshes_3d

from fretwear.errors import InputError
from fretwear.model.core import Mesh
from fretwear.model.loads import (
    boundary_load,
    boundary_measure,
    nodal_areas,
    nodal_force,
    resultant,
)
from fretwear.model.mesh import rectangle


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


def test_2d_nodal_areas_are_half_the_adjacent_edges():
    """On an unevenly divided bottom edge, each node's area is half the length of each edge
    it touches times the thickness (the tributary length, by hand), and boundary_measure is
    the edge's length. Exact up to rounding (1e-12)."""
    base = rectangle(1.0, 0.5, 5, 1)
    pts = base.points.copy()
    xs = np.array([0.0, 0.1, 0.35, 0.5, 0.8, 1.0])
    pts[:, 0] = np.tile(xs, 2)
    m = Mesh(pts, base.cells, "quad", base.boundaries, base.node_sets)
    nodes, area = nodal_areas(m, "bottom", thickness=0.02)
    h = np.diff(xs)
    expected = 0.02 * 0.5 * (np.r_[0.0, h] + np.r_[h, 0.0])
    assert nodes.tolist() == list(range(6))
    np.testing.assert_allclose(area, expected, rtol=1e-12)
    assert boundary_measure(m, "bottom") == pytest.approx(1.0, rel=1e-14)
