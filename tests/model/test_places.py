"""Places on a mesh: nodes named or pointed at, and unit directions (fretwear.model.places).

References written out by hand: the node numbering of a small rectangle (row by row from the
bottom left corner), the named sets of its edges, unit vectors of axes and diagonals.
"""

import math

import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.model.mesh import rectangle
from fretwear.model.places import axis_index, find_node, nodes_at, unit_direction


def test_direction_of_huge_or_tiny_components_is_its_unit_vector():
    """Reference: the unit vector (1, 1)/sqrt(2) written by hand; a direction's magnitude does
    not count, and [1e308, 1e308] overflowed the norm (a warning and a wrong message)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for scale in (1e308, 1e-320, 1.0):
            np.testing.assert_allclose(unit_direction([scale, scale], 2), [0.5**0.5] * 2,
                                       rtol=1e-15)


def test_axis_names_and_axis_directions():
    """"x", "Y ", "z" are the unit axes; a vector along an axis is that axis, a diagonal none;
    a name outside the dimension or a zero vector is refused."""
    np.testing.assert_array_equal(unit_direction("x", 3), [1.0, 0.0, 0.0])
    np.testing.assert_array_equal(unit_direction("Y ", 2), [0.0, 1.0])
    assert axis_index(unit_direction((0.0, 0.0, -3.0), 3)) == 2
    assert axis_index(unit_direction((1.0, 1.0), 2)) is None
    with pytest.raises(InputError, match=r"direction = 'z'; expected one of \['x', 'y'\]"):
        unit_direction("z", 2)
    with pytest.raises(InputError, match="non-zero vector of 2 components"):
        unit_direction((0.0, 0.0), 2)


def test_nodes_by_name_and_by_point():
    """On a 4 x 2 rectangle 0.4 x 0.2 m the nodes are numbered row by row from (0, 0): the
    node at (0.2, 0.1) is 5 + 2 = 7, the left edge holds 0, 5, 10, the corner set one node;
    a point off the mesh is refused with the nearest node, unless the tolerance is infinite."""
    mesh = rectangle(0.4, 0.2, 4, 2)
    assert find_node(mesh, (0.2, 0.1)) == 7
    assert nodes_at(mesh, "left").tolist() == [0, 5, 10]
    assert nodes_at(mesh, "top_right").tolist() == [14]
    assert nodes_at(mesh, (0.4, 0.0)).tolist() == [4]
    with pytest.raises(InputError, match=r"no mesh node there \(nearest node 7"):
        find_node(mesh, (0.21, 0.1))
    assert find_node(mesh, (0.21, 0.1), tol=math.inf) == 7
    with pytest.raises(InputError, match="no node set or boundary of that name"):
        nodes_at(mesh, "nowhere")
