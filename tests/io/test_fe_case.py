"""Case files with matrices exported by an FE code ([model] type = "matrices" with `format`):
the 2D block written as a Nastran DMIG punch file and an Abaqus .inp node file, the sections
naming nodes by id and node set; the model equals the one built in Python with from_fe, and
mistakes give one line naming the key."""

import numpy as np
import pytest
from helpers import fe_files as ff
from helpers.blocks import block

from fretwear.analyses.run import load_case
from fretwear.errors import InputError
from fretwear.io.case import build_model
from fretwear.model.readers import NodeContact, NodeForce, from_fe, read_fe

CASE = """
title = "block from DMIG"
[model]
type = "matrices"
format = "dmig"
K = "block.pch"
nodes = "block.inp"
[damping]
loss_factor = 0.01
[[contact]]
nodes = "bottom"
normal = [0.0, -1.0]
mu = 0.5
area = 1e-3
wear_coefficient = 1e-12
[[loads]]
nodes = "top"
force = [0.0, -500.0]
waveform = "constant"
[[loads]]
nodes = [2, 5]
force = [100.0, 0.0]
waveform = "cos"
[[fixed]]
nodes = [{fixed}]
direction = "x"
[observed]
corner = 21
[analysis]
type = "modes"
"""


def _files(tmp_path, text=CASE, fixed="19"):
    model = block(2)
    dofs = ff.dofmap_of(model)
    ff.write_dmig(tmp_path / "block.pch", {"KAAX": model.K, "MAAX": model.M}, dofs)
    pts = model.mesh.points
    bottom = np.flatnonzero(np.isclose(pts[:, 1], 0.0)) + 1
    top = np.flatnonzero(np.isclose(pts[:, 1], pts[:, 1].max())) + 1
    lines = ["*NODE"] + [f"{i + 1}, {float(x)!r}, {float(y)!r}" for i, (x, y) in enumerate(pts)]
    lines += ["*NSET, NSET=bottom", ", ".join(map(str, bottom)),
              "*NSET, NSET=top", ", ".join(map(str, top)), "*ELEMENT, TYPE=CPE4"]
    lines += [", ".join(map(str, [e + 1, *(cell + 1)])) for e, cell in
              enumerate(model.mesh.cells)]
    (tmp_path / "block.inp").write_text("\n".join(lines) + "\n")
    (tmp_path / "case.toml").write_text(text.replace("{fixed}", fixed))
    return model, bottom, top


def test_case_file_gives_the_python_model(tmp_path):
    """Every section against from_fe called directly with the same records."""
    mesh_model, bottom, top = _files(tmp_path)
    got = build_model(load_case(tmp_path / "case.toml"))
    fe = read_fe(tmp_path / "block.pch")
    from fretwear.model.build import Damping
    from fretwear.model.readers import read_nodes

    ref = from_fe(fe, contact=NodeContact(bottom, 0.5, normal=[0.0, -1.0], area=1e-3,
                                          wear_coefficient=1e-12),
                  nodes=read_nodes(tmp_path / "block.inp"), damping=Damping(loss_factor=0.01),
                  loads=[NodeForce(top, [0.0, -500.0], "constant"),
                         NodeForce([2, 5], [100.0, 0.0], "cos")],
                  fixed=[([19], [1])], observed={"corner": 21})
    for what in ("K", "M", "D"):
        assert abs(getattr(got, what) - getattr(ref, what)).max() == 0.0
    np.testing.assert_array_equal(got.contact.dofs, ref.contact.dofs)
    np.testing.assert_array_equal(got.contact.coords, mesh_model.mesh.points[bottom - 1])
    np.testing.assert_array_equal(got.fixed_dofs, [2 * 18])
    assert got.loads[0].vector.sum() == pytest.approx(-500.0 * top.size)
    np.testing.assert_array_equal(got.observed[0].coords, mesh_model.mesh.points[20])
    assert got.contact.wear_coefficient == 1e-12
    # the ParaView points: the .inp's nodes with their rows (node-major here) and elements
    np.testing.assert_array_equal(got.fe_mesh.points, mesh_model.mesh.points)
    np.testing.assert_array_equal(got.fe_mesh.rows.ravel(), np.arange(got.ndof))
    assert got.fe_mesh.cell_type == mesh_model.mesh.cell_type
    np.testing.assert_array_equal(got.fe_mesh.cells, mesh_model.mesh.cells)


def test_frames_from_the_node_file_without_a_normal(tmp_path):
    """No `normal`: the frames come from the .inp's CPE4 faces on the bottom nodes, those of
    the block meshed (its bottom face's outward normal and tangent), node for node; area =
    "mesh" gives its nodal areas (to rounding: 1e-15 relative)."""
    mesh_model, bottom, _ = _files(tmp_path, CASE.replace("normal = [0.0, -1.0]\n", "")
                                   .replace("area = 1e-3", 'area = "mesh"'))
    got = build_model(load_case(tmp_path / "case.toml"))
    np.testing.assert_allclose(got.contact.area, mesh_model.contact.area, rtol=1e-15, atol=0)
    np.testing.assert_array_equal(got.contact.node_ids, bottom)
    np.testing.assert_array_equal(mesh_model.contact.node_ids + 1, bottom)
    np.testing.assert_array_equal(got.contact.frame, mesh_model.contact.frame)


@pytest.mark.parametrize("edit, msg", [
    (("{fixed}", "999"), "node 999 is not in the matrices' DOF map"),
    (('nodes = "bottom"', 'nodes = "floor"'), "no node set of that name"),
    (('K = "block.pch"', 'K = "block.pch"\nM = "block.pch"'), "model.M: format 'dmig' holds"),
    (('format = "dmig"', 'format = "op4"'), "carries no DOF map"),
    (("normal = [0.0, -1.0]", "normal = [0.0, -1.0, 0.0]"), "expected 2 components"),
    (("mu = 0.5", "mu = 0.5\ntolerance = 1e-6"), "'tolerance' needs 'partners'"),
    (("mu = 0.5", 'mu = 0.5\npairing = "mortar"'), "pairing or tolerance without partners"),
])
def test_mistakes_are_one_line(tmp_path, edit, msg):
    _files(tmp_path, CASE.replace(*edit) if edit[0] != "{fixed}" else CASE, fixed=(
        edit[1] if edit[0] == "{fixed}" else "19"))
    with pytest.raises(InputError, match=msg) as exc:
        build_model(load_case(tmp_path / "case.toml"))
    assert "\n" not in str(exc.value)


JOINT = """
title = "non-matching joint"
[model]
type = "matrices"
format = "dmig"
K = "joint.pch"
nodes = "joint.inp"
[[contact]]
nodes = "bottom"
partners = "top"
pairing = "mortar"
mu = 0.3
area = "mesh"
[[fixed]]
nodes = "held"
[analysis]
type = "modes"
"""


def test_non_matching_joint_from_a_case_file(tmp_path):
    """A 4 | 5 element joint (block on a held base, mortar pairs) as DMIG + .inp with node
    sets: the pairs' weights, partner nodes, frames and areas are the meshed model's (the
    geometry comes from the .inp's 17-digit coordinates, so to rounding: 1e-15)."""
    from fretwear.model import ContactSpec, Material, Spring, from_mesh, join, rectangle

    mesh = join(("block", rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005))),
                ("base", rectangle(0.02, 0.005, 5, 1)))
    m0 = from_mesh(mesh, Material(210e9, 0.3, 7800.0),
                   supports=[Spring("block.top_left", "x", 1e7), ("base.bottom", "all")],
                   contact=ContactSpec("block.bottom", mu=0.3, partner="base.top"))
    ff.write_dmig(tmp_path / "joint.pch", {"KAAX": m0.K, "MAAX": m0.M}, ff.dofmap_of(m0))
    sets = {name: np.unique(mesh.boundaries[key]) + 1 for name, key in
            (("bottom", "block.bottom"), ("top", "base.top"), ("held", "base.bottom"))}
    lines = ["*NODE"] + [f"{i + 1}, {float(x)!r}, {float(y)!r}"
                         for i, (x, y) in enumerate(mesh.points)]
    for name, ids in sets.items():
        lines += [f"*NSET, NSET={name}", ", ".join(map(str, ids))]
    lines += ["*ELEMENT, TYPE=CPE4"] + [", ".join(map(str, [e + 1, *(cell + 1)]))
                                        for e, cell in enumerate(mesh.cells)]
    (tmp_path / "joint.inp").write_text("\n".join(lines) + "\n")
    (tmp_path / "case.toml").write_text(JOINT)
    got = build_model(load_case(tmp_path / "case.toml")).contact
    c0 = m0.contact
    order = np.argsort(c0.node_ids)  # the node set lists the nodes by increasing id
    np.testing.assert_array_equal(got.node_ids, c0.node_ids[order] + 1)
    np.testing.assert_array_equal(got.segments.ids, np.where(c0.segments.ids >= 0,
                                                             c0.segments.ids + 1, -1)[order])
    np.testing.assert_allclose(got.segments.weights, c0.segments.weights[order], atol=1e-15)
    np.testing.assert_allclose(got.frame, c0.frame[order], atol=1e-15)
    np.testing.assert_allclose(got.area, c0.area[order], rtol=1e-15)
