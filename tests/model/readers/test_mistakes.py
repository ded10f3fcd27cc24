"""The mistakes the issue lists, for every matrix format: a truncated file, a wrong DOF map,
an absent node id and a non-symmetric K each stop with one InputError line (never a
traceback). The files are the small 2D block's K and M written from the documented formats
(tests/helpers/fe_files.py) or by SciPy; a file cut in the middle of a line or record is the
truncated file (a text file cut exactly at a line end between two DMIG cards or two Abaqus
matrix-input terms is a valid shorter file: no reader can tell, docs/api.md says so)."""

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import fe_files as ff
from helpers.blocks import block

from fretwear.errors import InputError
from fretwear.model.readers import DofMap, NodeContact, from_fe, read_fe, write_dofmap


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """name -> (read_fe arguments, keyword arguments, the file to cut) of every format."""
    d = tmp_path_factory.mktemp("mistakes")
    m = block(2)
    dofs = ff.dofmap_of(m)
    K, M = m.K, m.M
    write_dofmap(d / "dofs.txt", dofs)
    ff.write_dmig(d / "m.pch", {"KAAX": K, "MAAX": M}, dofs)
    ff.write_op4(d / "a.op4", {"KAAX": K, "MAAX": M})
    ff.write_op4(d / "b.op4", {"KAAX": K, "MAAX": M}, sparse=True, binary=True)
    ff.write_abaqus_substructure(d / "se.mtx", {"STIFFNESS": K, "MASS": M}, dofs)
    ff.write_abaqus_matrix_input(d / "K-input.mtx", K, dofs)
    ff.write_abaqus_matrix_input(d / "M-input.mtx", M, dofs)
    ff.write_ansys_full(d / "m.full", K, M, dofs)
    ff.write_matrix_market(d / "K.mtx", K)
    ff.write_matrix_market(d / "M.mtx", M)
    ff.write_harwell_boeing(d / "K.rua", K)
    ff.write_harwell_boeing(d / "M.rua", M)
    mapped = {"dofmap": d / "dofs.txt"}
    return m, d, {
        "dmig": ((d / "m.pch",), {}),
        "op4 ascii": ((d / "a.op4",), mapped),
        "op4 binary": ((d / "b.op4",), mapped),
        "abaqus": ((d / "se.mtx",), {}),
        "abaqus-matrix-input": ((d / "K-input.mtx", d / "M-input.mtx"),
                                {"format": "abaqus-matrix-input"}),
        "ansys-full": ((d / "m.full",), {}),
        "matrix-market": ((d / "K.mtx", d / "M.mtx"), mapped),
        "harwell-boeing": ((d / "K.rua", d / "M.rua"), mapped)}


FORMATS = ["dmig", "op4 ascii", "op4 binary", "abaqus", "abaqus-matrix-input", "ansys-full",
           "matrix-market", "harwell-boeing"]


def _one_line(call):
    with pytest.raises(InputError) as exc:
        call()
    text = str(exc.value)
    assert "\n" not in text and "Traceback" not in text
    return text


@pytest.mark.parametrize("fmt", FORMATS)
def test_truncated_files(files, fmt):
    """Cut at 30 %, 60 % and 95 % of its bytes (inside a line or record), the K file (or the
    one file) is refused in one line naming it; the whole file reads back K (the control)."""
    m, d, cases = files
    args, kw = cases[fmt]
    fe = read_fe(*args, **kw)
    assert abs(fe.K - m.K).max() <= 1e-9 * abs(m.K).max()
    raw = args[0].read_bytes()
    for frac in (0.3, 0.6, 0.95):
        cut = d / f"cut-{args[0].name}"
        cut.write_bytes(raw[: int(len(raw) * frac)])
        text = _one_line(lambda cut=cut: read_fe(cut, *args[1:], **kw))
        assert cut.name in text, text


@pytest.mark.parametrize("fmt", FORMATS)
def test_wrong_dof_map_absent_node(files, fmt):
    """A DOF map of the wrong size (formats that need one) or a DOF map given to a format that
    carries its own, and a contact node id that is not in the matrices: one line each."""
    m, d, cases = files
    args, kw = cases[fmt]
    if "dofmap" in kw:
        short = DofMap(np.arange(1, 11), np.ones(10))
        assert "DOF map has 10 rows" in _one_line(lambda: read_fe(*args, **{**kw,
                                                                             "dofmap": short}))
    else:
        assert "carries its own DOF map" in _one_line(
            lambda: read_fe(*args, **{**kw, "dofmap": d / "dofs.txt"}))
    fe = read_fe(*args, **kw)
    bad = NodeContact(nodes=[12345], mu=0.3, normal=[0.0, -1.0])
    assert "node 12345 is not in the matrices' DOF map" in _one_line(
        lambda: from_fe(fe, contact=bad))


def test_non_symmetric_k(files, tmp_path):
    """A K whose two triangles differ (the formats that can hold both: OP4, Matrix Market,
    Harwell-Boeing, Abaqus matrix input; DMIG IFO 6, the Abaqus substructure and .full keep
    one triangle, and a .full flagged non-symmetric is refused by test_ansys.py) is refused
    by from_fe in one line."""
    m, d, _ = files
    dofs = ff.dofmap_of(m)
    K = m.K.tolil()
    K[0, 1] += 1e-3 * abs(m.K).max()
    K = sp.csr_matrix(K)
    ff.write_op4(tmp_path / "k.op4", {"KAAX": K, "MAAX": m.M})
    ff.write_matrix_market(tmp_path / "K.mtx", K)
    ff.write_harwell_boeing(tmp_path / "K.rua", K)
    C = K.tocoo()
    (tmp_path / "K-input.mtx").write_text("".join(
        f"{dofs.node[i]},{dofs.component[i]}, {dofs.node[j]},{dofs.component[j]}, {float(v)!r}\n"
        for i, j, v in zip(C.row, C.col, C.data, strict=True)))
    contact = ff.contacts_of(m)[0]
    for args, kw in (((tmp_path / "k.op4",), {"dofmap": d / "dofs.txt"}),
                     ((tmp_path / "K.mtx", d / "M.mtx"), {"dofmap": d / "dofs.txt"}),
                     ((tmp_path / "K.rua", d / "M.rua"), {"dofmap": d / "dofs.txt"}),
                     ((tmp_path / "K-input.mtx", d / "M-input.mtx"),
                      {"format": "abaqus-matrix-input"})):
        fe = read_fe(*args, **kw)
        assert "K is not symmetric" in _one_line(lambda fe=fe: from_fe(fe, contact=contact))
