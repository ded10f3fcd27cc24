"""Contact frames and non-matching pairing of models from FE matrices, from the node file's
elements (fretwear.model.readers.surfaces), against the model built from the mesh itself.

The reference is the meshed model (from_mesh): its matrices are handed to from_fe as an FE
code exports them (rows named node id = mesh node number + 1), its mesh written as Nastran
bulk data (GRID and CQUAD4 cards) and read back as the node file, and the contact named by
node ids with no normal and no frames. Both paths then share the frame and pairing code, so
frames, pairing weights and gaps must agree to rounding (1e-15, the last bits of the bulk
data's 17-digit coordinates), and the periodic solutions to 1e-10 relative (the solver's
own convergence; in practice they agree to ~1e-14).
"""

import dataclasses

import numpy as np
import pytest
from helpers import fe_files as ff

from fretwear import simulate_wear, solve_periodic
from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
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
    transformed,
)
from fretwear.model.readers import FEMatrices, NodeContact, NodeTable, from_fe, read_nodes
from fretwear.model.readers.surfaces import geometry, surface
from fretwear.wear import WearOptions

BASIS = FourierBasis.up_to(3, 32)
F_HZ = 2000.0
STEEL = Material(210e9, 0.3, 7800.0)
R = 0.02  # radius of the curved contact face [m]
KW = (1e-13, 3e-13)  # Archard coefficients of the joint's two surfaces [1/Pa]


def arc_block():
    """A 10 x 4 mm block (6 x 2 Q4) bent so that its bottom is an arc of radius R (0.5 rad),
    pressed on a rigid surface of the same shape and driven tangentially: each contact node
    has its own normal (a constant normal would be wrong by up to 0.25 rad)."""
    mesh = rectangle(0.01, 0.004, 6, 2)
    x, y = mesh.points.T
    theta, r = (x - 0.005) / R, R + y
    mesh = dataclasses.replace(mesh, points=np.column_stack([r * np.sin(theta),
                                                             r * np.cos(theta)]))
    return from_mesh(mesh, STEEL, damping=Damping(loss_factor=0.02),
                     supports=[Spring("top", "x", 1e7)],
                     loads=[Traction("top", pressure=1e6),
                            Traction("top", traction=(2.5e5, 0.0), waveform="cos")],
                     contact=ContactSpec("bottom", mu=0.5))


def inclined_joint():
    """A 20 x 10 mm block (4 x 2 Q4) on a 20 x 5 mm base of 5 x 1 Q4 held at its bottom
    (non-matching: mortar pairs), the whole joint turned by 0.3 rad; both surfaces wear."""
    mesh = join(("block", rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005))),
                ("base", rectangle(0.02, 0.005, 5, 1)))
    c, s = np.cos(0.3), np.sin(0.3)
    mesh = transformed(mesh, [[c, -s], [s, c]])
    return from_mesh(
        mesh, STEEL, damping=Damping(loss_factor=0.02),
        supports=[Spring("block.top_left", "x", 1e7), ("base.bottom", "all")],
        loads=[Traction("block.top", pressure=20e6),
               Traction("block.right", traction=(-1e7 * c, -1e7 * s), waveform="cos")],
        contact=ContactSpec("block.bottom", mu=0.3, partner="base.top", wear_coefficient=KW[0],
                            partner_wear_coefficient=KW[1]))


def exported(model, tmp_path):
    """The model's matrices with its DOF map, and its mesh read back from a .bdf file."""
    ff.write_bdf_mesh(tmp_path / "mesh.bdf", model)
    return FEMatrices(model.K, model.M, ff.dofmap_of(model), D=model.D), \
        read_nodes(tmp_path / "mesh.bdf")


def rebuilt(model, fe, table, contact):
    return from_fe(fe, contact=contact, nodes=table, loads=ff.forces_of(model),
                   fixed=ff.fixed_of(model), name=model.name)


def assert_same_solution(m0, m1):
    opts = SolveOptions(tol=1e-12)
    s0, s1 = (solve_periodic(m, BASIS, F_HZ, options=opts, raise_on_failure=True)
              for m in (m0, m1))
    for what in ("U", "lam"):
        a, b = getattr(s1, what), getattr(s0, what)
        assert abs(a - b).max() <= 1e-10 * abs(b).max(), what


def test_frames_of_a_curved_face_from_the_node_file(tmp_path):
    """No normal given: each node's frame from the element faces on the contact nodes equals
    the meshed model's (per-node normals of the arc), so do the nodal areas (area = "mesh")
    and the periodic solution; a constant normal (the override) would be off by the arc's
    half angle."""
    m0 = arc_block()
    c0 = m0.contact
    assert np.ptp(c0.frame[:, 0, 0]) > 0.4  # normals spread over the arc
    fe, table = exported(m0, tmp_path)
    m1 = rebuilt(m0, fe, table, NodeContact(nodes=c0.node_ids + 1, mu=0.5, area="mesh"))
    np.testing.assert_allclose(m1.contact.frame, c0.frame, rtol=0, atol=1e-15)
    np.testing.assert_allclose(m1.contact.area, c0.area, rtol=1e-14, atol=0)
    assert_same_solution(m0, m1)
    flat = rebuilt(m0, fe, table, NodeContact(nodes=c0.node_ids + 1, mu=0.5, area=c0.area,
                                              normal=[0.0, -1.0]))
    assert np.abs(flat.contact.frame[:, 0] - c0.frame[:, 0]).max() > 0.2


def test_frames_of_an_inclined_hexahedral_face(tmp_path):
    """3D: a 2 x 2 x 1 hexahedral box turned about an oblique axis, on its zmin face (CHEXA
    cards): the frames [n, t1, t2] from the node file equal the meshed model's."""
    from scipy.spatial.transform import Rotation

    mesh = transformed(box(0.01, 0.01, 0.005, 2, 2, 1),
                       Rotation.from_rotvec([0.3, -0.2, 0.1]).as_matrix())
    m0 = from_mesh(mesh, STEEL, supports=[Spring("zmax", "x", 1e7), Spring("zmax", "y", 1e7)],
                   contact=ContactSpec("zmin", mu=0.5))
    fe, table = exported(m0, tmp_path)
    c0 = m0.contact
    m1 = from_fe(fe, contact=NodeContact(nodes=c0.node_ids + 1, mu=0.5), nodes=table)
    assert np.abs(c0.frame[:, 0, 2]).min() < 0.99  # not an axis
    np.testing.assert_allclose(m1.contact.frame, c0.frame, rtol=0, atol=1e-15)


def test_mortar_pairing_of_a_non_matching_joint_from_the_node_file(tmp_path):
    """An inclined 4 | 5 element joint: the mortar weights, partner nodes, gaps, frames and
    areas from the node file's elements equal the meshed model's, and so do the periodic
    solution and one wear step (both surfaces worn). The partner surface named by a node set
    gives the same."""
    m0 = inclined_joint()
    c0 = m0.contact
    assert c0.segments is not None
    fe, table = exported(m0, tmp_path)
    base_top = np.unique(m0.mesh.boundaries["base.top"]) + 1
    contact = NodeContact(nodes=c0.node_ids + 1, mu=0.3, area="mesh", partners=base_top,
                          pairing="mortar", wear_coefficient=KW[0],
                          partner_wear_coefficient=KW[1])
    m1 = rebuilt(m0, fe, table, contact)
    c1 = m1.contact
    seg0, seg1 = c0.segments, c1.segments
    np.testing.assert_array_equal(seg1.ids, np.where(seg0.ids >= 0, seg0.ids + 1, -1))
    np.testing.assert_array_equal(seg1.dofs, seg0.dofs)
    np.testing.assert_allclose(seg1.weights, seg0.weights, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(c1.partner_ids, c0.partner_ids + 1)
    np.testing.assert_array_equal(c1.partner_dofs, c0.partner_dofs)
    np.testing.assert_allclose(c1.gap, c0.gap, rtol=0, atol=1e-15)
    np.testing.assert_allclose(c1.frame, c0.frame, rtol=0, atol=1e-15)
    np.testing.assert_allclose(c1.area, c0.area, rtol=1e-14, atol=0)
    assert_same_solution(m0, m1)
    w0, w1 = (simulate_wear(m, BASIS, F_HZ, options=WearOptions(max_steps=1)).final_wear
              for m in (m0, m1))
    assert w0.max() > 0
    assert abs(w1 - w0).max() <= 1e-10 * w0.max()  # measured 3e-14
    table.node_sets["base_top"] = base_top
    m2 = rebuilt(m0, fe, table, dataclasses.replace(contact, partners="base_top",
                                                    pairing="auto"))
    np.testing.assert_array_equal(m2.contact.segments.weights, seg1.weights)


def test_faces_of_a_node_set_are_the_mesh_boundary_oriented_outward():
    """The faces found on the base's top nodes are the mesh's boundary facets, each turned
    to point out of the base (its outward normal is +y), whatever the cells' order."""
    mesh = join(("block", rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005))),
                ("base", rectangle(0.02, 0.005, 5, 1)))
    ids = np.arange(len(mesh.points)) + 1
    table = NodeTable(ids, np.column_stack([mesh.points, np.zeros(ids.size)]),
                      elements={4: mesh.cells[::-1] + 1})
    geo = geometry(table, 2)
    facets = surface(geo, np.unique(mesh.boundaries["base.top"]), "partner")
    np.testing.assert_array_equal(np.sort(np.sort(facets, axis=1), axis=0),
                                  np.sort(np.sort(mesh.boundaries["base.top"], axis=1), axis=0))
    t = geo.points[facets[:, 1]] - geo.points[facets[:, 0]]
    assert np.all(-t[:, 0] > 0.0)  # the normal (t_y, -t_x) of a segment facet points up


def test_matching_faces_keep_node_to_node_pairs(tmp_path):
    """Partners as a node set on a matching joint (4 | 4): node-to-node pairs (no
    segments), the meshed model's."""
    mesh = join(("block", rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005))),
                ("base", rectangle(0.02, 0.005, 4, 1)))
    m0 = from_mesh(mesh, STEEL, supports=[Spring("block.top_left", "x", 1e7),
                                          ("base.bottom", "all")],
                   contact=ContactSpec("block.bottom", mu=0.3, partner="base.top"))
    fe, table = exported(m0, tmp_path)
    table.node_sets["top"] = np.unique(mesh.boundaries["base.top"]) + 1
    m1 = rebuilt(m0, fe, table, NodeContact(nodes=m0.contact.node_ids + 1, mu=0.3,
                                            partners="top"))
    assert m1.contact.segments is None
    np.testing.assert_array_equal(m1.contact.partner_ids, m0.contact.partner_ids + 1)
    np.testing.assert_array_equal(m1.contact.frame, m0.contact.frame)


def test_mistakes_are_one_line(tmp_path):
    """No node file with elements, a node off the surface, a pairing without partners."""
    m0 = arc_block()
    fe, table = exported(m0, tmp_path)
    nodes = m0.contact.node_ids + 1
    with pytest.raises(InputError, match="give either normal or frames"):
        from_fe(fe, contact=NodeContact(nodes=nodes, mu=0.5),
                nodes=NodeTable(table.ids, table.xyz))
    inner = np.array([int(nodes[0]), int(nodes[1]), 8 + 1])  # node 8 is inside the block
    with pytest.raises(InputError, match="is on no face"):
        from_fe(fe, contact=NodeContact(nodes=inner, mu=0.5), nodes=table)
    with pytest.raises(InputError, match="without partners"):
        from_fe(fe, contact=NodeContact(nodes=nodes, mu=0.5, pairing="mortar"), nodes=table)
