"""Node coordinates and node sets from Nastran, Abaqus and ANSYS input files written here from
the documented card formats (reference: the numbers written)."""

import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.model.readers import read_nodes

BDF = """$ grids: small field, free field, large field
GRID    1               0.0     1.5-3   2.0
GRID,2,,1.0,2.0,3.0
GRID*   {:>16}{:>16}{:>16}{:>16}
*       {:>16}
CQUAD4  1       1       1       2       3       3
"""
INP = """*HEADING
** nodes
*NODE
 10, 0.0, 0.5, 1.0
 11, 1.0, 0.5, 1.0
 12, 2.0, 0.5
*NSET, NSET=face
 10, 11
*NSET, NSET=all, GENERATE
 10, 12, 1
*ELEMENT, TYPE=C3D8
"""
CDB = """NBLOCK,6,SOLID,         3,         3
(3i9,6e21.13e3)
        1        0        0 1.0000000000000E+000 2.0000000000000E+000 3.0000000000000E+000
        2        0        0 4.0000000000000E+000
        7        0        0 0.0000000000000E+000-1.0000000000000E+000
N,R5.3,LOC,       -1,
CMBLOCK,TOP,NODE,        2  ! a node component
(8i10)
         1        -2
"""


def test_nastran_grids(tmp_path):
    (tmp_path / "m.bdf").write_text(BDF.format(3, 0, "4.00000000D+00", "5.0000000+0", "6.0"))
    t = read_nodes(tmp_path / "m.bdf")
    np.testing.assert_array_equal(t.ids, [1, 2, 3])
    np.testing.assert_allclose(t.xyz, [[0, 1.5e-3, 2], [1, 2, 3], [4, 5, 6]], rtol=1e-15)
    np.testing.assert_array_equal(t.coordinates([3, 1], 2, "x"), [[4, 5], [0, 1.5e-3]])
    with pytest.raises(InputError, match="node 9 is not in the node file"):
        t.coordinates([9], 3, "contact nodes")


def test_abaqus_nodes_and_sets(tmp_path):
    (tmp_path / "m.inp").write_text(INP)
    t = read_nodes(tmp_path / "m.inp")
    np.testing.assert_array_equal(t.ids, [10, 11, 12])
    np.testing.assert_allclose(t.xyz[2], [2.0, 0.5, 0.0])
    np.testing.assert_array_equal(t.node_sets["face"], [10, 11])
    np.testing.assert_array_equal(t.node_sets["all"], [10, 11, 12])


def test_ansys_nblock_and_components(tmp_path):
    (tmp_path / "m.cdb").write_text(CDB)
    t = read_nodes(tmp_path / "m.cdb")
    np.testing.assert_array_equal(t.ids, [1, 2, 7])
    np.testing.assert_allclose(t.xyz, [[1, 2, 3], [4, 0, 0], [0, -1, 0]])
    np.testing.assert_array_equal(t.node_sets["TOP"], [1, 2])


def test_bad_node_files(tmp_path):
    (tmp_path / "m.stl").write_text("solid\n")
    with pytest.raises(InputError, match="unknown suffix"):
        read_nodes(tmp_path / "m.stl")
    (tmp_path / "e.bdf").write_text("CQUAD4  1\n")
    with pytest.raises(InputError, match="defines no node"):
        read_nodes(tmp_path / "e.bdf")
    (tmp_path / "cp.bdf").write_text("GRID    1       2       0.0     1.0     2.0\n")
    with pytest.raises(InputError, match="coordinate system CP = 2"):
        read_nodes(tmp_path / "cp.bdf")


def _i9(*values):
    return "".join(f"{v:9d}" for v in values)


EBLOCK = "\n".join(["EBLOCK,19,SOLID,         2,         2", "(19i9)",
                    _i9(1, 1, 1, 1, 0, 0, 0, 0, 8, 0, 1, 1, 2, 3, 4, 5, 6, 7, 8),
                    _i9(1, 1, 1, 1, 0, 0, 0, 0, 10, 0, 2, 1, 2, 3, 4, 5, 6, 7, 8),
                    _i9(9, 10), _i9(-1)]) + "\n"


def test_elements_for_paraview(tmp_path):
    """Element connectivity by node ids as written here from each code's documented card
    layout: Nastran CQUAD4 (small field) and CHEXA (free field with its continuation line),
    Abaqus *ELEMENT (one line, and one going on after a trailing comma), ANSYS solid EBLOCK
    (8 nodes on the element's line, the 9th and 10th on the next)."""
    (tmp_path / "m.bdf").write_text(BDF.format(3, 0, "4.0", "5.0", "6.0")
                                    + "CHEXA,2,1,1,2,3,4,5,6\n,7,8\n")
    t = read_nodes(tmp_path / "m.bdf")
    np.testing.assert_array_equal(t.elements[4], [[1, 2, 3, 3]])
    np.testing.assert_array_equal(t.elements[8], [[1, 2, 3, 4, 5, 6, 7, 8]])
    (tmp_path / "m.inp").write_text(INP + "1, 10, 11, 12, 10,\n 11, 12, 10, 11\n"
                                    "*ELEMENT, TYPE=CPE4\n2, 10, 11, 12, 12\n")
    t = read_nodes(tmp_path / "m.inp")
    np.testing.assert_array_equal(t.elements[8], [[10, 11, 12, 10, 11, 12, 10, 11]])
    np.testing.assert_array_equal(t.elements[4], [[10, 11, 12, 12]])
    (tmp_path / "m.cdb").write_text(CDB + EBLOCK)
    t = read_nodes(tmp_path / "m.cdb")
    np.testing.assert_array_equal(t.elements[8], [[1, 2, 3, 4, 5, 6, 7, 8]])
    np.testing.assert_array_equal(t.elements[10], [[1, 2, 3, 4, 5, 6, 7, 8, 9, 10]])
    (tmp_path / "bad.bdf").write_text(BDF.format(3, 0, "4.0", "5.0", "6.0")
                                      + "CTRIA3  1       1       1       x       3\n")
    with pytest.raises(InputError, match=r"line 7 \(CTRIA3\)"):
        read_nodes(tmp_path / "bad.bdf")
