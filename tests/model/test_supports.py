"""Is a model held? (fretwear.model.supports)

References independent of the code under test: rigid motions known by construction (a beam
with its only x spring removed can translate along x; a box held by one x spring at a corner
can slide along y and spin about the vertical line through the spring), the rigid-body
fields of a point cloud written out by hand, and the connected components of meshes joined
from separate pieces.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from helpers.beams import STEEL, H, L, W, paper_beam

from fretwear.errors import InputError
from fretwear.model.build import ContactSpec, Spring, from_mesh
from fretwear.model.fem import assemble
from fretwear.model.mesh import box, join, rectangle
from fretwear.model.supports import (
    bodies,
    check_supported,
    rigid_body_modes,
    rigid_motion_check,
)


def test_beam_on_frictionless_support_without_x_spring():
    """The paper's beam without its x spring: only friction would hold it along x."""
    with pytest.raises(InputError, match=r"can translate along x with nothing to hold it but "
                                         r"friction: add a spring or a fixed DOF"):
        paper_beam(supports=[])


def test_free_motions_are_named():
    """2D block touching on its right face with nothing else: free to slide along y. 3D box
    on its zmin face held by one x spring at the corner (0, 0, 1): free to slide along y
    and to spin about the vertical line through the spring, x = 0... i.e. the z axis
    through the points with y = 0 (reported at the point closest to the centroid)."""
    with pytest.raises(InputError, match="can translate along y with nothing"):
        from_mesh(rectangle(0.1, 0.02, 4, 2), STEEL, contact=ContactSpec("right", mu=0.3))
    with pytest.raises(InputError, match=r"can rotate about an axis along z through "
                                         r"\(0.5, 0, 0.5\) and translate along y with"):
        from_mesh(box(1.0, 1.0, 1.0, 2, 2, 2), STEEL, contact=ContactSpec("zmin", mu=0.3),
                  supports=[Spring((0.0, 0.0, 1.0), "x", 1e5)])


def test_generic_rigid_motion_check():
    """The matrix check used for user matrices, on the paper's beam K: passes with the x
    spring, and without it names the x DOFs (a rigid x translation); check_supported falls
    back to it for a model without a mesh."""
    model = paper_beam()
    held = model.contact.dofs[:, 1]
    rigid_motion_check(model.K, held)
    K0, _ = assemble(rectangle(L, H, 30, 2), STEEL.E, STEEL.nu, STEEL.rho, W)
    with pytest.raises(InputError, match=r"singular \(1 zero-energy motion\(s\)\): DOFs \[0, 2, 4"):
        rigid_motion_check(K0, held)
    model.mesh = None
    check_supported(model)
    model.K = sp.csr_matrix(K0)
    with pytest.raises(InputError, match="nothing to hold them but friction"):
        check_supported(model)


def test_rigid_body_modes_of_a_point_cloud():
    """The fields written out by hand for three points in 2D (translations x, y; rotation
    about z through the centroid, scaled by the bounding-box diagonal) and four in 3D
    (three translations, three rotations omega x (p - centre) / size): exact (the same few
    operations on exactly representable numbers)."""
    p = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0]])
    R, centre, size = rigid_body_modes(p)
    np.testing.assert_array_equal(centre, p.mean(axis=0))
    assert size == np.sqrt(5.0)
    x = (p - centre) / size
    np.testing.assert_array_equal(R[:, 0], [1, 0, 1, 0, 1, 0])
    np.testing.assert_array_equal(R[:, 1], [0, 1, 0, 1, 0, 1])
    np.testing.assert_array_equal(R[:, 2], np.column_stack([-x[:, 1], x[:, 0]]).ravel())
    q = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]])
    R, centre, size = rigid_body_modes(q)
    assert R.shape == (12, 6) and size == 3.0
    x = (q - centre) / size
    for k, w in enumerate(np.eye(3)):
        np.testing.assert_array_equal(R[:, k], np.tile(w, 4))
        np.testing.assert_array_equal(R[:, 3 + k], np.cross(w, x).ravel())


def test_bodies_are_the_connected_pieces_of_a_mesh():
    """Two rectangles joined into one mesh without a shared node are two bodies: every node
    of the first piece in body 0, every node of the second in body 1."""
    one, two = rectangle(0.02, 0.01, 2, 1), rectangle(0.02, 0.01, 3, 1, origin=(0.0, 0.02))
    body = bodies(join(("one", one), ("two", two)))
    n1 = one.points.shape[0]
    assert set(body[:n1].tolist()) == {0} and set(body[n1:].tolist()) == {1}
    assert bodies(one).tolist() == [0] * n1


def test_two_bodies_without_the_spring_name_the_body():
    """A block on a held base, node-to-node, without the block's tangential spring: the
    block (its node set from join) can slide along x; the message names it, not a node."""
    from fretwear.model.build import Material

    block = rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005))
    mesh = join(("block", block), ("base", rectangle(0.02, 0.005, 4, 1)))
    with pytest.raises(InputError, match=r"body 'block' can translate along x with nothing "
                                         r"to hold it but friction: add a spring") as err:
        from_mesh(mesh, Material(210e9, 0.3, 7800.0), supports=[("base.bottom", "all")],
                  contact=ContactSpec("block.bottom", mu=0.3, partner="base.top"))
    assert "Spring(at, 'x', stiffness)" in str(err.value)


def test_unsupported_case_file_speaks_toml(tmp_path):
    """The same refusal from a case file gives the remedy as case-file blocks."""
    from fretwear.analyses.run import load_case
    from fretwear.io.case import build_model

    text = """\
[model]
type = "rectangle"
length = 0.1
height = 0.01
nx = 4
ny = 1
thickness = 0.01
[material]
E = 210e9
nu = 0.3
rho = 7800.0
[contact]
boundary = "bottom"
mu = 0.3
[analysis]
type = "modes"
"""
    (tmp_path / "case.toml").write_text(text)
    with pytest.raises(InputError, match=r"can translate along x with nothing to hold it but "
                                         r"friction: add a \[\[springs\]\] block") as err:
        build_model(load_case(tmp_path / "case.toml"))
    assert "Spring(" not in str(err.value) and "\n" not in str(err.value)
