"""Part of a face (fretwear.model.regions): contact, tractions, springs and nodal forces
restricted to coordinate ranges of a boundary or node set.

References: the measure of the selected part of a face (its length times the thickness),
the resultant of a uniform pressure on it (pressure x measure) and the node count of a
structured mesh, all known in closed form.
"""

import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.model import ContactSpec, Material, NodalForce, Spring, Traction, from_mesh, rectangle
from fretwear.model.regions import bounding_region, check_region, inside, restricted

STEEL = Material(210e9, 0.3, 7800.0)


def plate(**kw):
    """A 40 x 4 mm plate (8 x 1 Q4: 5 mm elements), 10 mm thick, on a rigid flat under part
    of its bottom face, held by springs at its left face."""
    mesh = rectangle(0.04, 0.004, 8, 1)
    args = dict(thickness=0.01, supports=[Spring("left", "x", 1e7), Spring("left", "y", 1e7)],
                contact=ContactSpec("bottom", mu=0.3, region={"x": (0.01, 0.025)}))
    args.update(kw)
    return mesh, from_mesh(mesh, STEEL, **args)


def test_contact_region_keeps_the_facets_inside():
    """x in [10, 25] mm: the nodes at 10, 15, 20, 25 mm, of total area 15 mm x 10 mm (the
    areas add up to the selected facets' measure, to rounding); the edge nodes get half an
    element, as on the edge of a whole face."""
    _, model = plate()
    c = model.contact
    np.testing.assert_allclose(c.coords[:, 0], [0.01, 0.015, 0.02, 0.025], rtol=0, atol=1e-15)
    np.testing.assert_allclose(c.area.sum(), 0.015 * 0.01, rtol=1e-14)
    np.testing.assert_allclose(c.area, [2.5e-5, 5e-5, 5e-5, 2.5e-5], rtol=1e-14)


def test_a_facet_half_inside_is_left_out():
    """x in [12, 25] mm cuts the element [10, 15]: only the facets with all nodes inside
    count (15 to 25 mm), so the ends of a range need not fall on mesh lines."""
    _, model = plate(contact=ContactSpec("bottom", mu=0.3, region={"x": (0.012, 0.025)}))
    np.testing.assert_allclose(model.contact.coords[:, 0], [0.015, 0.02, 0.025], atol=1e-15)


def test_traction_spring_and_force_regions():
    """A pressure on x in [0, 20] mm of the top has the resultant p x 20 mm x 10 mm (closed
    form); a spring on the part x >= 30 mm of the top acts on its 3 nodes only; a nodal force
    on the same part is shared by those 3 nodes."""
    p = 1e6
    held = [Spring("left", "x", 1e7), Spring("left", "y", 1e7)]
    mesh, model = plate(loads=[Traction("top", pressure=p, region={"x": (0.0, 0.02)}),
                               NodalForce("top", (0.0, -3.0), region={"x": (0.03, 0.04)})],
                        supports=[Spring("top", "x", 3e7, region={"x": (0.03, 0.04)}), *held])
    _, bare = plate(supports=held)
    f = model.loads[0].vector.reshape(-1, 2)
    np.testing.assert_allclose(f[:, 1].sum(), -p * 0.02 * 0.01, rtol=1e-14)
    assert np.all(f[mesh.points[:, 0] > 0.02 + 1e-12] == 0.0)
    g = model.loads[1].vector.reshape(-1, 2)
    hit = np.flatnonzero(g[:, 1] != 0.0)
    np.testing.assert_allclose(mesh.points[hit, 0], [0.03, 0.035, 0.04], atol=1e-15)
    np.testing.assert_allclose(g[hit, 1], -1.0, rtol=1e-15)
    added = (model.K - bare.K).toarray()
    expected = np.zeros_like(added)
    expected[2 * hit, 2 * hit] = 1e7  # 3e7 N/m shared by the 3 nodes, along x
    np.testing.assert_allclose(added, expected, rtol=0, atol=1e-6)


def test_restricted_mesh_and_text_of_a_region():
    mesh = rectangle(0.04, 0.004, 8, 1)
    part, name = restricted(mesh, "bottom", {"x": [0.0, 0.01]}, "here")
    assert name == "bottom[region]" and part.boundaries[name].shape == (2, 2)
    assert "bottom[region]" not in mesh.boundaries  # the original mesh is not changed
    nodes = np.unique(mesh.boundaries["bottom"])
    assert inside(mesh, nodes, {"X": (0.0, 0.01)}).sum() == 3
    assert bounding_region(mesh, nodes) == "{x = [0, 0.04]}"


@pytest.mark.parametrize("region, message", [
    ({"z": (0.0, 1.0)}, r"region: axis 'z'; expected one of \['x', 'y'\] for a 2D model"),
    ({"x": (0.02, 0.01)}, r"region.x = \(0.02, 0.01\); expected a range \[lo, hi\]"),
    ({"x": "a"}, r"region.x = 'a'; expected a range"),
    ({}, r"expected a table of coordinate ranges"),
    ({"x": (0.011, 0.014)}, r"region \{'x': \(0.011, 0.014\)\} holds no facet of boundary "
                            r"'bottom' .* spans x in \[0, 0.04\], y in \[0, 0\]"),
])
def test_bad_regions_get_one_line(region, message):
    with pytest.raises(InputError, match=message):
        plate(contact=ContactSpec("bottom", mu=0.3, region=region))


def test_spring_region_without_nodes_is_named():
    with pytest.raises(InputError, match=r"spring at 'top': region \{'x': \(1.0, 2.0\)\} holds "
                                         r"none of its 9 nodes"):
        plate(supports=[Spring("top", "x", 1e7, region={"x": (1.0, 2.0)})])


def test_check_region_returns_axis_indices():
    assert check_region({"y": (0, 1), "x": [-1, 2]}, 3) == {1: (0.0, 1.0), 0: (-1.0, 2.0)}
