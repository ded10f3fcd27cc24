"""ParaView output of models built from FE matrices: the small 2D block on its rigid flat
(tests/helpers/blocks.py) run from its mesh and run again from its matrices exported with the
mesh as Nastran bulk data (GRID and CQUAD4 cards, tests/helpers/fe_files.py), whose .vtu files
must hold the same points, cells and point data: the reference is the meshed model's own
output, an independent path (node-major DOFs and mesh node numbers there, the DOF map and
node ids here)."""

import dataclasses

import meshio
import numpy as np
import pytest
from helpers import fe_files as ff
from helpers.blocks import block

import fretwear as fw
from fretwear.io.results import no_fields_line, nodal_vectors
from fretwear.model import (
    ContactSpec,
    Damping,
    Material,
    Spring,
    Traction,
    from_mesh,
    join,
    rectangle,
)
from fretwear.model.readers import DofMap, FEMatrices, from_fe, read_fe, read_nodes


def _from_files(m0, d):
    """``m0`` exported to DMIG (K, M, D) and a .bdf, read back; and ``m0`` with the matrices
    as the 10-digit DMIG file holds them."""
    dofs = ff.dofmap_of(m0)
    ff.write_dmig(d / "m.pch", {"KAAX": m0.K, "MAAX": m0.M, "K4AX": m0.D}, dofs)
    ff.write_bdf_mesh(d / "mesh.bdf", m0)
    fe = read_fe(d / "m.pch")
    m1 = from_fe(fe, contact=ff.contacts_of(m0), nodes=read_nodes(d / "mesh.bdf"),
                 loads=ff.forces_of(m0), fixed=ff.fixed_of(m0),
                 observed=ff.observed_of(m0), name=m0.name)
    return dataclasses.replace(m0, K=fe.K, M=fe.M, D=fe.D), m1


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    """The meshed block and the same block from DMIG matrices and a .bdf node file."""
    m0 = block(2, 0.01)
    m0.contact.wear_coefficient = 1e-12
    return _from_files(m0, tmp_path_factory.mktemp("fe-paraview"))


def _vtus(folder):
    return [meshio.read(p) for p in sorted(folder.glob("*.vtu"))]


def _same_files(a, b):
    """Same points, cells and point data to rounding (1e-12 of each array's largest)."""
    va, vb = _vtus(a), _vtus(b)
    assert len(va) == len(vb) > 0
    for x, y in zip(va, vb, strict=True):
        np.testing.assert_array_equal(x.points, y.points)
        assert x.cells[0].type == y.cells[0].type == "quad"
        np.testing.assert_array_equal(x.cells[0].data, y.cells[0].data)
        assert sorted(x.point_data) == sorted(y.point_data)
        for name, v in x.point_data.items():
            w = y.point_data[name]
            np.testing.assert_array_equal(np.isnan(v), np.isnan(w))
            scale = max(np.nanmax(np.abs(v)), 1e-300)
            np.testing.assert_allclose(np.nan_to_num(w), np.nan_to_num(v), rtol=0,
                                       atol=1e-12 * scale, err_msg=name)


def test_periodic_and_wear_fields_equal_the_mesh_models(models, tmp_path):
    """periodic.pvd (displacement, contact state and pressure), wear.pvd (worn depth) and
    modes-stuck.pvd (mode shapes) of the model from matrices + .bdf equal the meshed
    model's. Both solve the same 10-digit
    matrices with the same contact DOFs in the same order, so the fields agree to rounding
    (1e-12 relative: the sparse factorisations see the DOFs in the same order)."""
    m0, m1 = models
    for k, m in enumerate((m0, m1)):
        fw.run(m, "periodic", tmp_path / f"p{k}", frequency=2000.0, harmonics=3, n_samples=32,
               eps=1e12, figures=False)
        fw.run(m, "wear", tmp_path / f"w{k}", frequency=2000.0, harmonics=3, n_samples=32,
               eps=1e12, max_steps=1, figures=False)
        fw.run(m, "modes", tmp_path / f"m{k}", n_modes=3, interfaces=["stuck"], figures=False)
    _same_files(tmp_path / "p0" / "periodic", tmp_path / "p1" / "periodic")
    _same_files(tmp_path / "m0" / "modes-stuck", tmp_path / "m1" / "modes-stuck")
    _same_files(tmp_path / "w0" / "wear", tmp_path / "w1" / "wear")
    assert np.isfinite(_vtus(tmp_path / "w1" / "wear")[-1].point_data["worn_depth"]).sum() \
        == m1.contact.n_nodes


def test_pairs_show_on_both_surfaces(tmp_path):
    """Two blocks (4 x 1 elements each, matching nodes on the interface, node-to-node pairs):
    the contact state and pressure of a pair show on its node and on its partner, as for the
    meshed model (the partners named by node id, mapped to points)."""
    mesh = join(("lower", rectangle(0.02, 0.005, 4, 1)),
                ("upper", rectangle(0.02, 0.005, 4, 1, origin=(0.0, 0.005))))
    steel = Material(210e9, 0.3, 7800.0)
    m = from_mesh(mesh, steel, supports=[("lower.bottom", "all"),
                                         Spring("upper.top", "x", 1e7)],
                  loads=[Traction("upper.top", pressure=1e6),
                         Traction("upper.top", traction=(2e5, 0.0), waveform="cos")],
                  contact=ContactSpec("upper.bottom", mu=0.3, partner="lower.top"),
                  damping=Damping(loss_factor=0.01))
    assert m.contact.has_pairs
    m0, m1 = _from_files(m, tmp_path)
    for k, model in enumerate((m0, m1)):
        fw.run(model, "periodic", tmp_path / f"p{k}", frequency=2000.0, harmonics=1,
               n_samples=16, eps=1e12, figures=False)
    _same_files(tmp_path / "p0" / "periodic", tmp_path / "p1" / "periodic")
    data = _vtus(tmp_path / "p1" / "periodic")[0].point_data["contact_state"]
    assert np.isfinite(data).sum() == 2 * m.contact.n_nodes


def test_without_node_file_one_line_says_so(models, tmp_path):
    """The model from matrices without its node file writes no .vtu and its summary says so
    in one line naming the key to give."""
    m1 = dataclasses.replace(models[1], fe_mesh=None)
    out = fw.run(m1, "periodic", tmp_path / "p", frequency=2000.0, harmonics=1, n_samples=16,
                 eps=1e12, figures=False)
    assert not list((tmp_path / "p").rglob("*.vtu"))
    line = [x for x in out.message.splitlines() if "ParaView" in x]
    assert line == [no_fields_line(m1)] and "model.nodes" in line[0]
    assert no_fields_line(models[0]) == "" and no_fields_line(models[1]) == ""


def test_superelement_points_without_elements(tmp_path):
    """Nodes whose matrices lack a translation (a superelement keeps its boundary nodes only,
    a scalar point carries a modal coordinate) show NaN there; with no element whose nodes
    are all in the matrices the points are vertex cells (the numbers are set by hand)."""
    (tmp_path / "n.inp").write_text("*NODE\n1, 0., 0.\n2, 1., 0.\n3, 1., 1.\n4, 0., 1.\n"
                                    "*ELEMENT, TYPE=CPE4\n1, 1, 2, 3, 4\n")
    table = read_nodes(tmp_path / "n.inp")
    np.testing.assert_array_equal(table.elements[4], [[1, 2, 3, 4]])
    dofs = DofMap([1, 1, 3, 3, 100], [1, 2, 1, 2, 0])
    from fretwear.model.readers.fe_model import fe_mesh

    I5 = np.eye(5)
    mesh = fe_mesh(FEMatrices(I5, I5, dofs), table, 2)
    np.testing.assert_array_equal(mesh.ids, [1, 3])
    np.testing.assert_array_equal(mesh.rows, [[0, 1], [2, 3]])
    assert mesh.cell_type == "vertex"
    np.testing.assert_array_equal(nodal_vectors(mesh, np.arange(5.0)), [[0, 1], [2, 3]])
    np.testing.assert_array_equal(mesh.point_index([3, 1]), [1, 0])
    full = fe_mesh(FEMatrices(np.eye(8), np.eye(8), DofMap(np.repeat([1, 2, 3, 4], 2),
                                                           np.tile([1, 2], 4))), table, 2)
    assert full.cell_type == "quad"
    np.testing.assert_array_equal(full.cells, [[0, 1, 2, 3]])
