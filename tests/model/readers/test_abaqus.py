"""Abaqus .mtx readers: the sample files that abaqus-mtx-parser ships (read by that package's
own parser as the reference), files of the documented format, and bad files."""

from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import fe_files

from fretwear.errors import InputError
from fretwear.model.readers import DofMap, read_fe


def _samples():
    try:
        import abaqus_mtx_parser
    except ImportError:
        return []
    root = Path(abaqus_mtx_parser.__file__).parent / "mtx"
    return sorted(root.rglob("*.mtx"))


@pytest.mark.parametrize("path", _samples(), ids=lambda p: f"{p.parent.name}-{p.stem}")
def test_samples_of_abaqus_mtx_parser(path):
    """K and M equal those of abaqus-mtx-parser (independent parser, same files), and the DOF
    map gives each retained node the DOFs of its user-element line (6, or 3 then 6 at the
    nodes from position 46 in the recovery sample)."""
    from abaqus_mtx_parser import parse_mtx

    fe = read_fe(path)
    ref = parse_mtx(str(path))
    np.testing.assert_array_equal(fe.K.toarray(), ref.stiffness)
    np.testing.assert_array_equal(fe.M.toarray(), ref.mass)
    assert fe.dofs.size == ref.stiffness.shape[0]
    counts = np.unique(fe.dofs.node, return_counts=True)[1]
    assert set(counts.tolist()) <= {3, 6}


def test_abaqus_samples_are_tested_in_ci():
    """The test extra installs abaqus-mtx-parser (126 kB): its samples must be found."""
    pytest.importorskip("abaqus_mtx_parser")
    assert len(_samples()) >= 4


def test_documented_formats_round_trip(tmp_path):
    """*SUBSTRUCTURE MATRIX OUTPUT (with viscous and structural damping) and *MATRIX GENERATE
    files written from the documented format read back to the last bit (17 digits)."""
    rng = np.random.default_rng(5)
    A = rng.standard_normal((9, 9))
    K = A @ A.T + np.eye(9)
    dofs = DofMap(np.repeat([5, 8, 11], 3), np.tile([1, 2, 3], 3))
    fe_files.write_abaqus_substructure(tmp_path / "se.mtx", {
        "STIFFNESS": K, "MASS": 2 * K, "VISCOUS DAMPING": 3 * K, "STRUCTURAL DAMPING": 4 * K},
        dofs)
    fe = read_fe(tmp_path / "se.mtx")
    np.testing.assert_array_equal(fe.dofs.node, dofs.node)
    for got, f in ((fe.K, 1), (fe.M, 2), (fe.C, 3), (fe.D, 4)):
        np.testing.assert_array_equal(got.toarray(), f * K)
    for name, B in (("K_STIF1.mtx", K), ("K_MASS1.mtx", 2 * K)):
        fe_files.write_abaqus_matrix_input(tmp_path / name, sp.csr_matrix(B), dofs)
    fe = read_fe(tmp_path / "K_STIF1.mtx", tmp_path / "K_MASS1.mtx")
    np.testing.assert_array_equal(fe.K.toarray(), K)
    np.testing.assert_array_equal(fe.M.toarray(), 2 * K)


def test_bad_abaqus_files_are_one_line(tmp_path):
    """A truncated matrix block, a file without *USER ELEMENT, a non-number: one line each."""
    K = np.eye(6) * 2.0
    dofs = DofMap(np.repeat([1, 2], 3), np.tile([1, 2, 3], 2))
    fe_files.write_abaqus_substructure(tmp_path / "se.mtx", {"STIFFNESS": K, "MASS": K}, dofs)
    lines = (tmp_path / "se.mtx").read_text().splitlines()
    (tmp_path / "cut.mtx").write_text("\n".join(lines[:-2]) + "\n")
    with pytest.raises(InputError, match="truncated") as exc:
        read_fe(tmp_path / "cut.mtx")
    assert "\n" not in str(exc.value)
    (tmp_path / "none.mtx").write_text("*MATRIX,TYPE=STIFFNESS\n1.0\n")
    with pytest.raises(InputError, match="USER ELEMENT"):
        read_fe(tmp_path / "none.mtx")
    (tmp_path / "nan.mtx").write_text("1,1, 1,1, abc\n")
    with pytest.raises(InputError, match="line 1"):
        read_fe(tmp_path / "nan.mtx", tmp_path / "nan.mtx")
