"""ANSYS .full files through the optional ansys-mapdl-reader (its shipped file.full, when the
extra is installed), and the one-line message naming the extra when it is not."""

import builtins

import numpy as np
import pytest
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.readers import read_fe


def test_shipped_full_file():
    """file.full of ansys-mapdl-reader: K and M symmetric (one triangle in the file, filled
    in), the DOF map its (node, DOF index) table with components from 1; against the package's
    own sorted matrices (load_km(sort=True)) as the reference."""
    reader = pytest.importorskip("ansys.mapdl.reader")
    from ansys.mapdl.reader import examples

    fe = read_fe(examples.fullfile)
    assert abs(fe.K - fe.K.T).max() == 0.0 and abs(fe.M - fe.M.T).max() == 0.0
    dof_ref, K, _ = reader.read_binary(examples.fullfile).load_km(sort=True)
    order = np.lexsort((fe.dofs.component, fe.dofs.node))
    np.testing.assert_array_equal(fe.dofs.node[order], dof_ref[:, 0])
    np.testing.assert_array_equal(fe.dofs.component[order], dof_ref[:, 1] + 1)
    Kref = (K + K.T - sp.diags(K.diagonal())).toarray()  # one triangle in the file
    np.testing.assert_allclose(fe.K.toarray()[np.ix_(order, order)], Kref, rtol=0, atol=0)


def test_missing_extra_is_one_line(tmp_path, monkeypatch):
    """Without ansys-mapdl-reader the message names the extra to install."""
    path = tmp_path / "file.full"
    path.write_bytes(b"\x00" * 64)
    real_import = builtins.__import__

    def no_ansys(name, *args, **kwargs):
        if name.startswith("ansys"):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_ansys)
    with pytest.raises(InputError, match=r"pip install 'fretwear\[ansys\]'") as exc:
        read_fe(path)
    assert "\n" not in str(exc.value)
