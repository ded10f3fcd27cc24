"""DOF maps: node ids to rows, and the one-line messages of a wrong map (reference: the maps
written here by hand)."""

import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.model.readers import DofMap, read_dofmap, write_dofmap


def test_rows_of_nodes():
    m = DofMap([7, 7, 3, 3, 9], [1, 2, 1, 2, 0])
    np.testing.assert_array_equal(m.rows([3, 7], [1, 2]), [[2, 3], [0, 1]])
    np.testing.assert_array_equal(m.nodes(), [3, 7, 9])
    with pytest.raises(InputError, match="node 5 is not in the matrices' DOF map"):
        m.rows([5], [1])
    with pytest.raises(InputError, match="node 9 has no component 1"):
        m.rows([9], [1])


def test_a_wrong_map_is_one_line():
    for bad, msg in ((([1, 1], [1, 1]), "listed more than once"),
                     (([1, 2], [1]), "2 node ids but 1 components"),
                     (([1], [7]), "component 7"),
                     (([1.5], [1]), "must be integers")):
        with pytest.raises(InputError, match=msg) as exc:
            DofMap(*bad)
        assert "\n" not in str(exc.value)


def test_files_both_forms(tmp_path):
    """'node component' lines (written by write_dofmap) and ANSYS's HBMAT mapping file."""
    m = DofMap([1, 1, 2], [1, 3, 2])
    write_dofmap(tmp_path / "d.txt", m)
    back = read_dofmap(tmp_path / "d.txt")
    np.testing.assert_array_equal(back.node, m.node)
    np.testing.assert_array_equal(back.component, m.component)
    (tmp_path / "k.mapping").write_text(" Matrix Eqn   Node   DOF\n      1      4     UX\n"
                                        "      2      4     UY\n      3      5  ROTZ\n")
    a = read_dofmap(tmp_path / "k.mapping")
    np.testing.assert_array_equal(a.node, [4, 4, 5])
    np.testing.assert_array_equal(a.component, [1, 2, 6])
    (tmp_path / "bad.txt").write_text("1 1\n1 x\n")
    with pytest.raises(InputError, match="line 2"):
        read_dofmap(tmp_path / "bad.txt")
    with pytest.raises(InputError, match="does not exist"):
        read_dofmap(tmp_path / "none.txt")
