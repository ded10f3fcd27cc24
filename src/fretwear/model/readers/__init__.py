"""Matrices exported by FE codes, with the DOF map (node id, component) of their rows.

:func:`read_fe` reads K, M (and exported damping) from Nastran DMIG (punch or bulk data) and
OP4, Abaqus ``.mtx`` (``*SUBSTRUCTURE MATRIX OUTPUT``, ``*MATRIX GENERATE``), ANSYS ``.full``
(compressed ones through the optional ``ansys-mapdl-reader``) and Harwell-Boeing (``HBMAT``),
and Matrix Market;
:func:`~.nodes.read_nodes` the node coordinates and node sets of the mesh (``.bdf``, ``.inp``,
``.cdb``); :func:`~.fe_model.from_fe` builds the model with everything named by node ids;
:func:`~.superelement.craig_bampton` reduces full matrices to a superelement.
"""

from __future__ import annotations

from pathlib import Path

from fretwear.errors import InputError
from fretwear.model.readers.dofmap import DofMap, FEMatrices, read_dofmap, write_dofmap
from fretwear.model.readers.fe_model import NodeContact, NodeForce, from_fe
from fretwear.model.readers.nodes import NodeTable, read_nodes
from fretwear.model.readers.superelement import Superelement, craig_bampton

FORMATS = ("dmig", "op4", "abaqus", "abaqus-matrix-input", "ansys-full", "matrix-market",
           "harwell-boeing")

__all__ = ["FORMATS", "DofMap", "FEMatrices", "NodeContact", "NodeForce", "NodeTable",
           "Superelement", "craig_bampton", "detect_format", "from_fe", "read_dofmap",
           "read_fe", "read_nodes", "write_dofmap"]


def detect_format(path) -> str:
    """The format of a matrix file from its suffix and first bytes."""
    path = Path(path)
    suffix = path.suffix.lower()
    try:
        with path.open("rb") as f:
            head = f.read(4096)
    except OSError:
        raise InputError(f"matrix file {str(path)!r} does not exist") from None
    if head.startswith(b"%%MatrixMarket"):
        return "matrix-market"
    if suffix == ".op4":
        return "op4"
    if suffix == ".full":
        return "ansys-full"
    if b"DMIG" in head.upper():
        return "dmig"
    if b"*USER ELEMENT" in head.upper() or b"*MATRIX" in head.upper():
        return "abaqus"
    if suffix == ".mtx":
        return "abaqus-matrix-input"
    return "harwell-boeing"


def read_fe(K, M=None, *, format: str | None = None, C=None, D=None, dofmap=None,
            names: dict | None = None) -> FEMatrices:
    """K, M (and C, D) and the DOF map from an FE code's files.

    Parameters
    ----------
    K : the file holding K: for DMIG, Abaqus substructure (``.mtx``) and ANSYS ``.full``
        files, the one file holding every matrix (``M`` not given).
    M, C, D : the files of M and the viscous and hysteretic damping, for formats with one
        matrix a file (Matrix Market, Harwell-Boeing, Abaqus ``*MATRIX GENERATE``).
    format : one of :data:`FORMATS` (default: from the suffix and the first bytes).
    dofmap : DofMap or file (``node component`` per line, or ANSYS's ``.mapping``): the DOF
        map of formats that do not carry one (OP4, Matrix Market, Harwell-Boeing).
    names : DMIG or OP4 matrix names ``{"K": .., "M": .., "C": .., "D": ..}`` (default
        ``KAAX``, ``MAAX``, ``BAAX``, ``K4AX``).
    """
    from fretwear.model.readers import abaqus, ansys, nastran, sparse_files

    fmt = format or detect_format(K)
    if fmt not in FORMATS:
        raise InputError(f"format = {fmt!r}; expected one of {list(FORMATS)}")
    single = fmt in ("dmig", "op4", "abaqus", "ansys-full")
    if single and (M is not None or C is not None or D is not None):
        raise InputError(f"a {fmt} file holds every matrix: give it alone (K = file), not M, "
                         "C or D files")
    if not single and M is None:
        raise InputError(f"format {fmt}: one matrix a file; expected the M file too")
    needs_map = fmt in ("op4", "matrix-market", "harwell-boeing")
    if needs_map and dofmap is None:
        raise InputError(f"format {fmt} carries no DOF map: give dofmap (a file of 'node "
                         "component' lines, or ANSYS's .mapping)")
    if not needs_map and dofmap is not None:
        raise InputError(f"format {fmt} carries its own DOF map: do not give dofmap")
    if needs_map and not isinstance(dofmap, DofMap):
        dofmap = read_dofmap(dofmap)
    if fmt == "dmig":
        return nastran.read_nastran_dmig(K, names)
    if fmt == "op4":
        return nastran.read_nastran_op4(K, dofmap, names)
    if fmt == "abaqus":
        return abaqus.read_abaqus_substructure(K)
    if fmt == "abaqus-matrix-input":
        return abaqus.read_abaqus_matrix_input(K, M, C, D)
    if fmt == "ansys-full":
        return ansys.read_ansys_full(K)
    return sparse_files.read_matrix_files(K, M, dofmap, C=C, D=D)
