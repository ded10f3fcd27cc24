"""Matrices in the exchange formats of SciPy: Matrix Market and Harwell-Boeing (``RUA``, and
``RSA`` whose one triangle is filled in), each with a DOF map read from its own file."""

from __future__ import annotations

import io
from pathlib import Path

import scipy.io
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.readers.dofmap import DofMap, FEMatrices


def read_harwell_boeing(path) -> sp.csr_matrix:
    """A real Harwell-Boeing matrix (``scipy.io.hb_read``); symmetric ones (``RSA``, one
    triangle stored, as ANSYS's ``HBMAT`` writes them) are filled in.

    Raises
    ------
    InputError
        A missing, malformed or truncated file, or a complex or pattern matrix.
    """
    path = Path(path)
    src = str(path)
    if not path.is_file():
        raise InputError(f"Harwell-Boeing file {src!r} does not exist")
    lines = path.read_text(errors="replace").splitlines(keepends=True)
    if len(lines) < 4 or len(lines[2]) < 3:
        raise InputError(f"Harwell-Boeing file {src!r} has no complete header (a truncated "
                         "file?)")
    kind = lines[2][:3].upper()
    if kind not in ("RUA", "RSA"):
        raise InputError(f"Harwell-Boeing file {src!r} holds a {kind!r} matrix; expected a "
                         "real assembled one (RUA or RSA)")
    if kind == "RSA":
        lines[2] = "RUA" + lines[2][3:]
    try:
        A = scipy.io.hb_read(io.StringIO("".join(lines)))
    except Exception as exc:  # SciPy raises ValueError, IndexError, ... on bad files
        raise InputError(f"cannot read Harwell-Boeing file {src!r}: {exc} (a truncated or "
                         "malformed file?)") from None
    A = sp.csr_matrix(A, dtype=float)
    if kind == "RSA":
        A = (A + sp.triu(A, 1).T + sp.tril(A, -1).T).tocsr()
    return A


def read_matrix_files(K, M, dofs: DofMap, C=None, D=None) -> FEMatrices:
    """K, M (and C, D) from Matrix Market (``.mtx``) or Harwell-Boeing (``.rua``, ``.rsa``,
    ``.hb``, ``.matrix``, ...) files, on the rows of ``dofs``."""
    from fretwear.model.matrices import read_matrix_market

    out = {}
    for what, path in (("K", K), ("M", M), ("C", C), ("D", D)):
        if path is None:
            continue
        if _is_matrix_market(Path(path)):
            out[what] = read_matrix_market(path)
        else:
            out[what] = read_harwell_boeing(path)
    return FEMatrices(out["K"], out["M"], dofs, C=out.get("C"), D=out.get("D"), source=str(K))


def _is_matrix_market(path: Path) -> bool:
    try:
        with path.open("rb") as f:
            return f.read(14) == b"%%MatrixMarket"
    except OSError:
        return path.suffix.lower() == ".mtx"
