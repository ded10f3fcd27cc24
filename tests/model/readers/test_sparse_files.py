"""Matrix Market and Harwell-Boeing files written by SciPy, the symmetric RSA form that ANSYS's
HBMAT writes (made here from the RUA file SciPy writes by changing the type and keeping the
lower triangle), and truncated files."""

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.readers import DofMap, read_fe
from fretwear.model.readers.sparse_files import read_harwell_boeing

RNG = np.random.default_rng(11)
A = sp.random(8, 8, density=0.4, random_state=RNG)
K = (A @ A.T + sp.identity(8)).tocsr()
DOFS = DofMap(np.repeat([1, 2, 3, 4], 2), np.tile([1, 2], 4))


def test_scipy_files_round_trip(tmp_path):
    """K in Harwell-Boeing and M in Matrix Market (17 digits): the same matrices bit for bit."""
    scipy.io.hb_write(str(tmp_path / "K.rua"), K.tocsc())
    scipy.io.mmwrite(str(tmp_path / "M.mtx"), 2 * K, precision=17)
    fe = read_fe(tmp_path / "K.rua", tmp_path / "M.mtx", dofmap=DOFS)
    np.testing.assert_array_equal(fe.K.toarray(), K.toarray())
    np.testing.assert_array_equal(fe.M.toarray(), 2 * K.toarray())


def test_symmetric_harwell_boeing(tmp_path):
    """An RSA file (lower triangle) reads as the whole symmetric matrix."""
    scipy.io.hb_write(str(tmp_path / "L.rua"), sp.tril(K).tocsc())
    lines = (tmp_path / "L.rua").read_text().splitlines(keepends=True)
    lines[2] = "RSA" + lines[2][3:]
    (tmp_path / "K.rsa").write_text("".join(lines))
    np.testing.assert_array_equal(read_harwell_boeing(tmp_path / "K.rsa").toarray(),
                                  K.toarray())


def test_bad_files_are_one_line(tmp_path):
    """A truncated Harwell-Boeing file, a DOF map of the wrong size, no DOF map: one line."""
    scipy.io.hb_write(str(tmp_path / "K.rua"), K.tocsc())
    lines = (tmp_path / "K.rua").read_text().splitlines()
    (tmp_path / "cut.rua").write_text("\n".join(lines[:-3]) + "\n")
    with pytest.raises(InputError, match="truncated") as exc:
        read_harwell_boeing(tmp_path / "cut.rua")
    assert "\n" not in str(exc.value)
    with pytest.raises(InputError, match=r"DOF map has 6 rows; expected \(6, 6\)"):
        read_fe(tmp_path / "K.rua", tmp_path / "K.rua", dofmap=DofMap([1, 1, 1, 2, 2, 2],
                                                                       [1, 2, 3] * 2))
    with pytest.raises(InputError, match="carries no DOF map"):
        read_fe(tmp_path / "K.rua", tmp_path / "K.rua")
