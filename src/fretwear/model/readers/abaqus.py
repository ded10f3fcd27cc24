"""Abaqus matrices: the ``.mtx`` file of ``*SUBSTRUCTURE MATRIX OUTPUT`` and the node-based
files of ``*MATRIX GENERATE`` / ``*MATRIX OUTPUT``, read from the documented formats.

``*SUBSTRUCTURE MATRIX OUTPUT, FILE NAME=blade, STIFFNESS=YES, MASS=YES`` writes a
``*USER ELEMENT`` card whose ``** ELEMENT NODES`` comment lists the retained nodes (boundary
nodes, then the generalized-DOF nodes of the retained modes), data lines giving the active
DOFs of the nodes, and ``*MATRIX, TYPE=STIFFNESS`` / ``MASS`` / ``VISCOUS DAMPING`` /
``STRUCTURAL DAMPING`` blocks: the lower triangle row by row (symmetric), or the whole matrix
row by row (``UNSYMM``). The rows are node by node, each node's active DOFs in increasing
order. ``*MATRIX GENERATE, STIFFNESS, MASS`` with ``*MATRIX OUTPUT, FORMAT=MATRIX INPUT``
writes one file per matrix, one term a line: ``row node, row DOF, column node, column DOF,
value`` (one triangle of a symmetric matrix).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.readers.dofmap import DofMap, FEMatrices

_TYPES = {"STIFFNESS": "K", "MASS": "M", "VISCOUS DAMPING": "C", "STRUCTURAL DAMPING": "D"}


def _keyword(line: str) -> tuple[str, dict]:
    parts = [p.strip() for p in line.lstrip("*").split(",")]
    params = {}
    for p in parts[1:]:
        key, _, value = p.partition("=")
        params[key.strip().upper()] = value.strip().upper()
    return parts[0].upper(), params


def read_abaqus_substructure(path) -> FEMatrices:
    """K, M (and C, D where written) and the DOF map of a ``*SUBSTRUCTURE MATRIX OUTPUT`` file.

    Raises
    ------
    InputError
        A missing file, no ``*USER ELEMENT`` card, a node list or matrix whose length does not
        match the DOFs (a truncated file), a non-number.
    """
    path = Path(path)
    src = str(path)
    if not path.is_file():
        raise InputError(f"Abaqus matrix file {src!r} does not exist")
    nodes: list[int] = []
    dof_lines: list[list[int]] = []
    blocks: dict[str, list[str]] = {}
    unsym = in_nodes = False
    state = None
    for k, raw in enumerate(path.read_text(errors="replace").splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        where = f"{src}, line {k}"
        try:
            if line.startswith("**"):
                text = line[2:].strip()
                if text.upper().startswith("ELEMENT NODES"):
                    in_nodes = True
                elif in_nodes:
                    nodes.extend(int(t) for t in text.replace(",", " ").split())
                continue
            in_nodes = False
            if line.startswith("*"):
                key, params = _keyword(line)
                if key == "USER ELEMENT":
                    unsym = "UNSYMM" in params or "UNSYM" in params
                    state = "dofs"
                elif key == "MATRIX":
                    what = _TYPES.get(params.get("TYPE", ""))
                    if what is None:
                        raise InputError(f"{where}: *MATRIX, TYPE={params.get('TYPE')!r}; "
                                         f"expected one of {sorted(_TYPES)}")
                    state = what
                    blocks[what] = []
                else:
                    state = None
                continue
            if state == "dofs":
                dof_lines.append([int(t) for t in line.rstrip(",").split(",")])
            elif state in blocks:
                blocks[state].append(line.rstrip(","))
        except ValueError:
            raise InputError(f"{where}: {line[:60]!r} is not a list of numbers") from None
    if not dof_lines or not nodes:
        raise InputError(f"{src}: no *USER ELEMENT card with its '** ELEMENT NODES' list; "
                         "expected a file of *SUBSTRUCTURE MATRIX OUTPUT")
    dofs = _substructure_dofs(nodes, dof_lines, src)
    mats = {what: _triangle(_values(lines, f"{src}: *MATRIX {what}"), dofs.size, unsym,
                            f"{src}: *MATRIX {what}") for what, lines in blocks.items()}
    for what in ("K", "M"):
        if what not in mats:
            raise InputError(f"{src}: no *MATRIX, TYPE={'STIFFNESS' if what == 'K' else 'MASS'}"
                             f"; expected K and M (STIFFNESS=YES, MASS=YES)")
    return FEMatrices(mats["K"], mats["M"], dofs, C=mats.get("C"), D=mats.get("D"), source=src)


def _values(lines: list[str], where: str) -> np.ndarray:
    """The numbers of a matrix block's lines (comma separated), converted as one array."""
    tokens = np.array(",".join(lines).replace("D", "E").replace("d", "e").split(","))
    tokens = tokens[np.strings.strip(tokens) != ""]
    try:
        return tokens.astype(float)
    except ValueError:
        bad = next(t for t in tokens.tolist() if not _is_float(t))
        raise InputError(f"{where}: {bad.strip()[:30]!r} is not a number") from None


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _substructure_dofs(nodes, dof_lines, src) -> DofMap:
    """The DOF map of a user element: the first data line lists the DOFs of the first node
    and the nodes after it; a later line ``p, dofs..`` gives the DOFs from node position p."""
    starts = [1] + [line[0] for line in dof_lines[1:]]
    comps = [dof_lines[0]] + [line[1:] for line in dof_lines[1:]]
    node_out, comp_out = [], []
    for pos, node in enumerate(nodes, start=1):
        j = max(i for i, s in enumerate(starts) if s <= pos)
        node_out.extend([node] * len(comps[j]))
        comp_out.extend(sorted(comps[j]))
    try:
        return DofMap(np.array(node_out), np.array(comp_out))
    except InputError as exc:
        raise InputError(f"{src}: {exc}") from None


def _triangle(vals, n: int, unsym: bool, where: str) -> sp.csr_matrix:
    v = np.asarray(vals, dtype=float)
    if v.size == n * n and (unsym or n == 1):
        return sp.csr_matrix(v.reshape(n, n))
    if v.size != n * (n + 1) // 2:
        raise InputError(f"{where}: {v.size} terms for {n} DOFs; expected {n * (n + 1) // 2} "
                         f"(the lower triangle){' or ' + str(n * n) if unsym else ''} (a "
                         "truncated file or a wrong DOF list?)")
    L = np.zeros((n, n))
    L[np.tril_indices(n)] = v
    return sp.csr_matrix(L + np.tril(L, -1).T)


def read_abaqus_matrix_input(K, M, C=None, D=None) -> FEMatrices:
    """K, M (and C, D) from the node-based files of ``*MATRIX GENERATE`` (``FORMAT=MATRIX
    INPUT``: ``row node, row DOF, column node, column DOF, value`` per line), on the union of
    the DOFs they name. A symmetric matrix given by one triangle is filled in."""
    terms = {w: _read_terms(p) for w, p in (("K", K), ("M", M), ("C", C), ("D", D))
             if p is not None}
    keys = np.unique(np.concatenate([np.concatenate([t[:, 0:2], t[:, 2:4]]).astype(np.int64)
                                     for t, _ in terms.values()]), axis=0)
    dofs = DofMap(keys[:, 0], keys[:, 1])
    code = keys[:, 0] * 8 + keys[:, 1]
    out = {}
    for w, (t, vals) in terms.items():
        i = np.searchsorted(code, t[:, 0] * 8 + t[:, 1])
        j = np.searchsorted(code, t[:, 2] * 8 + t[:, 3])
        A = sp.coo_matrix((vals, (i, j)), shape=(dofs.size, dofs.size)).tocsr()
        upper, lower = sp.triu(A, 1).nnz, sp.tril(A, -1).nnz
        if upper == 0 or lower == 0:  # one triangle: fill in the other
            A = (A + sp.triu(A, 1).T + sp.tril(A, -1).T).tocsr()
        out[w] = A
    return FEMatrices(out["K"], out["M"], dofs, C=out.get("C"), D=out.get("D"),
                      source=str(K))


def _read_terms(path):
    """The terms of one ``FORMAT=MATRIX INPUT`` file, converted as whole arrays."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"Abaqus matrix file {str(path)!r} does not exist")
    text = path.read_text(errors="replace")
    raw = text.splitlines()
    number = [k for k, x in enumerate(raw, start=1) if x.strip() and not x.lstrip()
              .startswith("*")]
    if not number:
        raise InputError(f"{path}: no matrix terms (an empty or truncated file)")
    if not text.endswith("\n") and number[-1] == len(raw):
        raise InputError(f"{path}, line {len(raw)}: the file ends inside a term, without its "
                         "line end (a truncated file?); expected the whole file (add the final "
                         "newline if it is whole)")
    tokens = np.array(" ".join(raw[k - 1] for k in number).replace(",", " ").split())
    if tokens.size != 5 * len(number):  # a line without its five fields: find it
        k = next(k for k in number if len(raw[k - 1].replace(",", " ").split()) != 5)
        _bad_term(path, k, raw[k - 1])
    t = tokens.reshape(-1, 5)
    try:
        return t[:, :4].astype(np.int64), np.strings.replace(
            np.strings.upper(t[:, 4]), "D", "E").astype(float)
    except ValueError:
        for k in number:
            tok = raw[k - 1].replace(",", " ").split()
            try:
                [int(x) for x in tok[:4]] + [float(tok[4].replace("D", "E"))]
            except ValueError:
                _bad_term(path, k, raw[k - 1])
        raise


def _bad_term(path, k, line):
    raise InputError(f"{path}, line {k}: {line.strip()[:60]!r}; expected 'row node, row DOF, "
                     "column node, column DOF, value' (*MATRIX OUTPUT, FORMAT=MATRIX INPUT)")
