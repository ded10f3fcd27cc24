"""ANSYS matrices: the ``.full`` file of a modal or substructure run (through the optional
``ansys-mapdl-reader``: ``pip install fretwear[ansys]``), or Harwell-Boeing files written by
``HBMAT`` with their ``.mapping`` file (no extra package).

In MAPDL, ``WRFULL`` after the solution (or ``EQSLV`` runs that keep the ``.full``) leaves
``file.full`` with K and M and the node id and DOF label of each equation. ``HBMAT, name, ,
, ASCII, STIFF, NO, YES`` writes K as a Harwell-Boeing file and ``name.mapping`` (equation,
node, label per line); ``HBMAT`` with ``MASS`` writes M likewise.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.readers.dofmap import DofMap, FEMatrices


def read_ansys_full(path) -> FEMatrices:
    """K and M and the DOF map of an ANSYS ``.full`` file (``ansys-mapdl-reader``)."""
    path = Path(path)
    src = str(path)
    if not path.is_file():
        raise InputError(f"ANSYS file {src!r} does not exist")
    try:
        from ansys.mapdl import reader as mapdl_reader
    except ImportError:
        raise InputError(f"reading ANSYS .full files ({src!r}) needs the optional package "
                         "ansys-mapdl-reader: pip install 'fretwear[ansys]' (or export K and "
                         "M with HBMAT and read the Harwell-Boeing files)") from None
    try:
        full = mapdl_reader.read_binary(src)
        dof_ref, K, M = full.load_km(sort=False)
    except Exception as exc:  # the reader raises many kinds on a bad or truncated file
        raise InputError(f"cannot read ANSYS .full file {src!r}: {exc}") from None
    dof_ref = np.asarray(dof_ref, dtype=np.int64)
    # ansys-mapdl-reader gives one triangle of the symmetric K and M
    K, M = (_symmetric_from_triangle(sp.csr_matrix(A, dtype=float)) for A in (K, M))
    dofs = DofMap(dof_ref[:, 0], dof_ref[:, 1] + 1)
    return FEMatrices(K, M, dofs, source=src)


def _symmetric_from_triangle(A: sp.csr_matrix) -> sp.csr_matrix:
    """``A`` filled in when it holds only one triangle of a symmetric matrix."""
    if sp.triu(A, 1).nnz == 0 or sp.tril(A, -1).nnz == 0:
        A = A + sp.triu(A, 1).T + sp.tril(A, -1).T
    return sp.csr_matrix(A)
