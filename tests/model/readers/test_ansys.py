"""ANSYS .full files: read from their documented layout (a small model written here from it,
tests/helpers/fe_files.py, and ansys-mapdl-reader's shipped file.full, written by MAPDL, when
that package is installed), compressed files through the optional ansys-mapdl-reader and the
one-line message naming the extra when it is missing; damaged files in one line."""

import builtins

import numpy as np
import pytest
import scipy.sparse as sp
from helpers import fe_files as ff
from helpers.blocks import block

from fretwear.errors import InputError
from fretwear.model.readers import read_fe


@pytest.fixture(scope="module")
def small():
    """The 2D block's K, M and DOF map (node id = mesh node number + 1)."""
    m = block(2)
    return m.K, m.M, ff.dofmap_of(m)


def test_written_full_file_round_trip(small, tmp_path):
    """K, M and the DOF map come back bit for bit (doubles stored as they are); DOFs held by
    a constraint (negative in the constraint table) are left out of the matrices and the
    map."""
    K, M, dofs = small
    ff.write_ansys_full(tmp_path / "a.full", K, M, dofs)
    fe = read_fe(tmp_path / "a.full")
    np.testing.assert_array_equal(fe.dofs.node, dofs.node)
    np.testing.assert_array_equal(fe.dofs.component, dofs.component)
    assert abs(fe.K - K).max() == 0.0 and abs(fe.M - M).max() == 0.0
    held = np.array([0, 1, 7])
    ff.write_ansys_full(tmp_path / "b.full", K, M, dofs, held=held)
    fe = read_fe(tmp_path / "b.full")
    free = np.setdiff1d(np.arange(dofs.size), held)
    np.testing.assert_array_equal(fe.dofs.node, dofs.node[free])
    assert abs(fe.K - K[free][:, free]).max() == 0.0
    assert abs(fe.M - M[free][:, free]).max() == 0.0


def test_damaged_full_files_are_one_line(small, tmp_path):
    """A truncated file, another binary file and a non-symmetric flag each give one line."""
    K, M, dofs = small
    ff.write_ansys_full(tmp_path / "a.full", K, M, dofs)
    data = (tmp_path / "a.full").read_bytes()
    cases = {"cut.full": data[: len(data) // 2], "head.full": data[:300],
             "other.full": b"\x64\x00\x00\x00" + b"\x00" * 500}
    words = np.frombuffer(data, "<i4").copy()
    words[105 + 13] = 1  # keyuns: a non-symmetric matrix
    cases["uns.full"] = words.tobytes()
    for name, raw in cases.items():
        (tmp_path / name).write_bytes(raw)
        with pytest.raises(InputError) as exc:
            read_fe(tmp_path / name)
        assert "\n" not in str(exc.value) and name in str(exc.value)
    with pytest.raises(InputError, match="non-symmetric"):
        read_fe(tmp_path / "uns.full")


def test_written_file_through_the_reader_package(small, tmp_path):
    """ansys-mapdl-reader reads the file written here as the reader of fretwear does (a check
    of the writer against an independent reader; skipped without the package)."""
    reader = pytest.importorskip("ansys.mapdl.reader")
    from fretwear.model.readers.ansys import _read_with_mapdl_reader

    K, M, dofs = small
    ff.write_ansys_full(tmp_path / "a.full", K, M, dofs, held=[2, 3])
    ours, theirs = read_fe(tmp_path / "a.full"), _read_with_mapdl_reader(tmp_path / "a.full")
    assert reader.read_binary(str(tmp_path / "a.full")).neqn == dofs.size
    np.testing.assert_array_equal(ours.dofs.node, theirs.dofs.node)
    np.testing.assert_array_equal(ours.dofs.component, theirs.dofs.component)
    assert abs(ours.K - theirs.K).max() == 0.0 and abs(ours.M - theirs.M).max() == 0.0


def test_shipped_full_file():
    """file.full of ansys-mapdl-reader (written by MAPDL 18.0, 63 of its 963 equations held):
    K and M symmetric (one triangle in the file, filled in), the DOF map its (node, DOF)
    table without the held DOFs; against the package's own sorted matrices (load_km(sort=True),
    the held rows empty there) as the reference, and the package's reader of the same file."""
    reader = pytest.importorskip("ansys.mapdl.reader")
    from ansys.mapdl.reader import examples

    from fretwear.model.readers.ansys import _read_with_mapdl_reader

    fe = read_fe(examples.fullfile)
    assert fe.dofs.size == 900
    assert abs(fe.K - fe.K.T).max() == 0.0 and abs(fe.M - fe.M.T).max() == 0.0
    full = reader.read_binary(examples.fullfile)
    dof_ref, K, _ = full.load_km(sort=True)
    held = np.isin(dof_ref[:, 0] * 8 + dof_ref[:, 1], full.const[:, 0] * 8 + full.const[:, 1])
    order = np.lexsort((fe.dofs.component, fe.dofs.node))
    np.testing.assert_array_equal(fe.dofs.node[order], dof_ref[~held, 0])
    np.testing.assert_array_equal(fe.dofs.component[order], dof_ref[~held, 1] + 1)
    Kref = (K + K.T - sp.diags(K.diagonal())).toarray()[np.ix_(~held, ~held)]
    np.testing.assert_allclose(fe.K.toarray()[np.ix_(order, order)], Kref, rtol=0, atol=0)
    other = _read_with_mapdl_reader(examples.fullfile)
    assert abs(other.K - fe.K).max() == 0.0 and abs(other.M - fe.M).max() == 0.0


def test_missing_extra_is_one_line(small, tmp_path, monkeypatch):
    """A .full file with compressed records (the flag bit 27 of MAPDL 19+'s /FCOMP, set
    here on the full header) needs ansys-mapdl-reader; without it the message names the
    extra to install."""
    K, M, dofs = small
    ff.write_ansys_full(tmp_path / "a.full", K, M, dofs)
    words = np.fromfile(tmp_path / "a.full", "<i4")
    words[104] |= 0x08 << 24
    path = tmp_path / "file.full"
    words.tofile(path)
    real_import = builtins.__import__

    def no_ansys(name, *args, **kwargs):
        if name.startswith("ansys"):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_ansys)
    with pytest.raises(InputError, match=r"pip install 'fretwear\[ansys\]'") as exc:
        read_fe(path)
    assert "\n" not in str(exc.value) and "compressed" in str(exc.value)
