"""ANSYS matrices: the ``.full`` file of a modal or substructure run, or Harwell-Boeing files
written by ``HBMAT`` with their ``.mapping`` file.

In MAPDL, ``WRFULL`` after the solution (or ``EQSLV`` runs that keep the ``.full``) leaves
``file.full`` with K and M and the node id and DOF label of each equation. ``HBMAT, name, ,
, ASCII, STIFF, NO, YES`` writes K as a Harwell-Boeing file and ``name.mapping`` (equation,
node, label per line); ``HBMAT`` with ``MASS`` writes M likewise.

The ``.full`` file is read here from its documented layout (ANSYS's binary file format, the
``fdfull.inc`` header): records of 4-byte words ``[n, flags, n words of data, n]`` (bit 31 of
``flags``: integers, else doubles); the 100-word standard header (item 1 the file number 4), the
full header (``neqn`` equations, ``numdof`` DOF labels, the pointers to K, M and the DOF
tables), the DOF labels (1-6: UX, UY, UZ, ROTX, ROTY, ROTZ), the node ids, the number of DOFs
of each node, the constraint table (negative: a DOF held by a constraint, left out here), and
one pair of records a column of K and of M (row numbers, values; one triangle of the symmetric
matrix). A file whose records MAPDL wrote compressed (flag bits 3 or 4) is read through the
optional ``ansys-mapdl-reader`` (``pip install fretwear[ansys]``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.readers.dofmap import DofMap, FEMatrices

#: positions in the full header of the items read (``fdfull.inc``, symbolic assembly)
FULL_HEADER = {"fun": 0, "neqn": 1, "numdof": 7, "ntermKl": 8, "ntermKh": 9, "lumpm": 10,
               "keyuns": 13, "ptrSTFl": 18, "ptrSTFh": 19, "ntermMh": 21, "ptrMASl": 26,
               "ptrMASh": 27, "nNodes": 32, "ntermMl": 33, "ptrDOFl": 35, "ptrDOFh": 36}
INT_FLAG = 0x80  # bit 7 of a record's flag byte: integers
COMPRESSED = 0x18  # bits 3, 4: sparse-compressed records


class _Compressed(Exception):
    """A record compressed by MAPDL: read through ansys-mapdl-reader."""


def read_ansys_full(path) -> FEMatrices:
    """K and M and the DOF map of an ANSYS ``.full`` file."""
    path = Path(path)
    src = str(path)
    if not path.is_file():
        raise InputError(f"ANSYS file {src!r} does not exist")
    words = np.fromfile(path, dtype="<i4")
    try:
        return _read_full(words, src)
    except _Compressed:
        return _read_with_mapdl_reader(src)
    except InputError:
        raise
    except (IndexError, ValueError):  # a pointer past the end, a record of odd length
        raise InputError(f"ANSYS .full file {src!r} ends inside a record or holds a record "
                         "that is not where its header points (a truncated or damaged "
                         "file?)") from None


def _record(words: np.ndarray, at: int, src: str, what: str) -> tuple[np.ndarray, int]:
    """The data of the record at word ``at`` (int32 or float64) and the word after it."""
    n = int(words[at])
    flags = (int(words[at + 1]) >> 24) & 0xFF
    if flags & COMPRESSED:
        raise _Compressed
    end = at + 2 + n
    if n < 0 or end >= words.size or int(words[end]) != n:
        raise InputError(f"ANSYS .full file {src!r}: the {what} record at word {at} is not "
                         f"whole ({n} words announced, file of {words.size}); expected an "
                         "uncut .full file")
    data = words[at + 2:end]
    if not flags & INT_FLAG:
        data = data.view("<f8")
    return data, end + 1


def _long(h: np.ndarray, low: str, high: str) -> int:
    return (int(h[FULL_HEADER[high]]) << 32) + (int(h[FULL_HEADER[low]]) & 0xFFFFFFFF)


def _read_full(words: np.ndarray, src: str) -> FEMatrices:
    if words.size < 103 or int(words[0]) != 100 or int(words[2]) != 4:
        raise InputError(f"{src!r} is not an ANSYS .full file (its standard header does not "
                         "give file number 4); expected the Jobname.full of a MAPDL run")
    h, at = _record(words, 103, src, "full header")
    h = h.astype(np.int64)
    neqn, numdof, nnodes = (int(h[FULL_HEADER[k]]) for k in ("neqn", "numdof", "nNodes"))
    if h[FULL_HEADER["lumpm"]] or h[FULL_HEADER["keyuns"]]:
        raise InputError(f"ANSYS .full file {src!r} holds a lumped or non-symmetric matrix; "
                         "expected symmetric K and M (LUMPM, OFF)")
    labels, at = _record(words, at, src, "DOF labels")
    nodes, _ = _record(words, at, src, "node ids")
    per_node, at = _record(words, _long(h, "ptrDOFl", "ptrDOFh"), src, "DOFs per node")
    const, _ = _record(words, at, src, "constraints")
    if labels.size != numdof or nodes.size != nnodes or per_node.size != nnodes \
            or int(per_node.sum()) != neqn or const.size != neqn:
        raise InputError(f"ANSYS .full file {src!r}: its DOF tables do not match its header "
                         f"({neqn} equations, {nnodes} nodes); expected a whole .full file")
    index = np.concatenate([np.arange(k) for k in per_node.tolist()]).astype(np.int64)
    comp = np.asarray(labels, dtype=np.int64)[index]
    if np.any((comp < 1) | (comp > 6)):
        bad = int(comp[(comp < 1) | (comp > 6)][0])
        raise InputError(f"ANSYS .full file {src!r}: DOF label {bad}; expected UX .. ROTZ "
                         "(1-6)")
    node = np.repeat(np.asarray(nodes, dtype=np.int64), per_node)
    K = _matrix(words, _long(h, "ptrSTFl", "ptrSTFh"), _long(h, "ntermKl", "ntermKh"), neqn,
                src, "K")
    M = _matrix(words, _long(h, "ptrMASl", "ptrMASh"), _long(h, "ntermMl", "ntermMh"), neqn,
                src, "M")
    free = np.flatnonzero(np.asarray(const) >= 0)
    K, M = (A[free][:, free].tocsr() for A in (K, M))
    return FEMatrices(K, M, DofMap(node[free], comp[free]), source=src)


def _matrix(words: np.ndarray, at: int, nterm: int, neqn: int, src: str, what: str):
    """The symmetric matrix stored one column a record pair (rows from 1, values) from word
    ``at`` (one triangle in the file, the other filled in); empty when ``nterm`` is 0."""
    if nterm == 0:
        raise InputError(f"ANSYS .full file {src!r} holds no {what} matrix; expected K and M "
                         "(a modal or substructure run's .full)")
    rows, cols, vals = [], [], []
    for j in range(neqn):
        r, at = _record(words, at, src, f"{what} column {j + 1} rows")
        v, at = _record(words, at, src, f"{what} column {j + 1} values")
        if v.dtype.kind != "f" or v.size != r.size:
            raise InputError(f"ANSYS .full file {src!r}: {what} column {j + 1} has {r.size} "
                             f"rows but {v.size} values; expected one value a row")
        rows.append(np.asarray(r, dtype=np.int64) - 1)
        cols.append(np.full(r.size, j, dtype=np.int64))
        vals.append(v)
    r, c, v = (np.concatenate(a) for a in (rows, cols, vals))
    if r.size != nterm or np.any((r < 0) | (r >= neqn)):
        raise InputError(f"ANSYS .full file {src!r}: {what} has {r.size} terms, its header "
                         f"{nterm}; expected a whole .full file")
    A = sp.coo_matrix((v, (r, c)), shape=(neqn, neqn)).tocsr()
    return _symmetric_from_triangle(A)


def _read_with_mapdl_reader(src: str) -> FEMatrices:
    """A ``.full`` file with compressed records, through ``ansys-mapdl-reader``."""
    try:
        from ansys.mapdl import reader as mapdl_reader
    except ImportError:
        raise InputError(f"ANSYS .full file {src!r} has compressed records: reading them "
                         "needs the optional package ansys-mapdl-reader: pip install "
                         "'fretwear[ansys]' (or export K and M with HBMAT and read the "
                         "Harwell-Boeing files)") from None
    try:
        full = mapdl_reader.read_binary(src)
        dof_ref, K, M = full.load_km(sort=False)
    except Exception as exc:  # the reader raises many kinds on a bad or truncated file
        raise InputError(f"cannot read ANSYS .full file {src!r}: {exc}") from None
    dof_ref = np.asarray(dof_ref, dtype=np.int64)
    held = np.asarray(full.const, dtype=np.int64).reshape(-1, 2)
    free = np.flatnonzero(~np.isin(dof_ref[:, 0] * 8 + dof_ref[:, 1], held[:, 0] * 8
                                   + held[:, 1]))
    # ansys-mapdl-reader gives one triangle of the symmetric K and M
    K, M = (_symmetric_from_triangle(sp.csr_matrix(A, dtype=float))[free][:, free].tocsr()
            for A in (K, M))
    dofs = DofMap(dof_ref[free, 0], dof_ref[free, 1] + 1)
    return FEMatrices(K, M, dofs, source=src)


def _symmetric_from_triangle(A: sp.csr_matrix) -> sp.csr_matrix:
    """``A`` filled in when it holds only one triangle of a symmetric matrix."""
    if sp.triu(A, 1).nnz == 0 or sp.tril(A, -1).nnz == 0:
        A = A + sp.triu(A, 1).T + sp.tril(A, -1).T
    return sp.csr_matrix(A)
