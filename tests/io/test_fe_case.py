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


@pytest.mark.parametrize("edit, msg", [
    (("{fixed}", "999"), "node 999 is not in the matrices' DOF map"),
    (('nodes = "bottom"', 'nodes = "floor"'), "no node set of that name"),
    (('K = "block.pch"', 'K = "block.pch"\nM = "block.pch"'), "model.M: format 'dmig' holds"),
    (('format = "dmig"', 'format = "op4"'), "carries no DOF map"),
    (("normal = [0.0, -1.0]", "normal = [0.0, -1.0, 0.0]"), "expected 2 components"),
])
def test_mistakes_are_one_line(tmp_path, edit, msg):
    _files(tmp_path, CASE.replace(*edit) if edit[0] != "{fixed}" else CASE, fixed=(
        edit[1] if edit[0] == "{fixed}" else "19"))
    with pytest.raises(InputError, match=msg) as exc:
        build_model(load_case(tmp_path / "case.toml"))
    assert "\n" not in str(exc.value)
