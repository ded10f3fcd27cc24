"""Nastran matrices: DMIG cards (punch files of ``DMIGPCH`` / ``EXTSEOUT`` and bulk data)
and OP4 files (ASCII), read from the documented formats with NumPy alone.

A DMIG card set carries its DOF map: every term is named by grid (or scalar point) id and
component. A superelement exported by ``EXTSEOUT(ASMBULK, EXTBULK, DMIGPCH)`` writes its
boundary and modal stiffness, mass and damping as ``KAAX``, ``MAAX``, ``BAAX`` (viscous) and
``K4AX`` (structural); its modal coordinates are scalar points (component 0). An OP4 file
holds bare matrices: its DOF map comes from a separate file (:func:`~.dofmap.read_dofmap`).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.readers.dofmap import DofMap, FEMatrices

#: default DMIG names of K, M, C (viscous) and D (structural) of an EXTSEOUT superelement
DMIG_NAMES = {"K": "KAAX", "M": "MAAX", "C": "BAAX", "D": "K4AX"}

_IMPLICIT_EXP = re.compile(r"^([+-]?[0-9.]+)([+-][0-9]+)$")


def nastran_real(text: str, where: str) -> float:
    """A Nastran real field: ``1.5``, ``1.5E+3``, ``1.5D+3`` or ``1.5+3`` (implied E)."""
    t = text.strip().upper().replace("D", "E")
    m = _IMPLICIT_EXP.match(t)
    if m:
        t = f"{m.group(1)}E{m.group(2)}"
    try:
        return float(t)
    except ValueError:
        raise InputError(f"{where}: {text.strip()!r} is not a number") from None


def _int(text: str, where: str) -> int:
    try:
        return int(text.strip() or "0")
    except ValueError:
        raise InputError(f"{where}: {text.strip()!r}; expected an integer") from None


def _fields(line: str) -> tuple[str, list[str]]:
    """The first field and the data fields of one line (small, large or free field)."""
    if "," in line:
        tok = [t.strip() for t in line.split(",")]
        return tok[0], (tok[1:] + [""] * 8)[:8]
    first = line[:8].strip()
    if first.endswith("*") or first.startswith("*"):
        body = line[8:72].ljust(64)
        return first, [body[i:i + 16].strip() for i in range(0, 64, 16)]
    body = line[8:72].ljust(64)
    return first, [body[i:i + 8].strip() for i in range(0, 64, 8)]


def _dmig_cards(text: str, where: str) -> list[tuple[int, list[str]]]:
    """The DMIG cards of a bulk-data or punch text: (line number, data fields) each."""
    cards: list[tuple[int, list[str]]] = []
    current = None
    for k, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("$")[0].rstrip("\n")
        if not line.strip():
            continue
        first, data = _fields(line.expandtabs(8))
        head = first.upper()
        if head.rstrip("*") == "DMIG":
            current = [k, list(data)]
            cards.append(current)
        elif current is not None and (not head or head[0] in "+*"):
            current[1].extend(data)
        else:
            current = None  # another card: its continuations are not ours
    return cards


def read_dmig(path) -> dict[str, tuple[DofMap, DofMap, sp.coo_matrix, int]]:
    """Every DMIG matrix of a file: name -> (row map, column map, matrix, IFO).

    Rows and columns are numbered in sorted (grid, component) order. A symmetric matrix
    (IFO 6) given by one triangle is filled in.

    Raises
    ------
    InputError
        A missing file, no DMIG card, a card without header, complex terms (TIN 3, 4), a term
        given twice, a symmetric matrix with both (i, j) and (j, i) given.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"Nastran file {str(path)!r} does not exist")
    src = str(path)
    cards = _dmig_cards(path.read_text(errors="replace"), src)
    if not cards:
        raise InputError(f"Nastran file {src!r} has no DMIG card; expected DMIG matrices "
                         "(DMIGPCH punch file or bulk data)")
    headers: dict[str, int] = {}
    terms: dict[str, list] = {}
    for line, f in cards:
        name = f[0].upper()
        where = f"{src}, line {line} (DMIG {name})"
        if f[1] in ("0", ""):  # header: NAME 0 IFO TIN TOUT POLAR _ NCOL
            if f[1] == "" and len(f) < 4:
                raise InputError(f"{where}: truncated card")
            ifo, tin = _int(f[2], where), _int(f[3], where)
            if tin not in (1, 2):
                raise InputError(f"{where}: TIN = {tin} (complex terms); expected a real matrix "
                                 "(TIN 1 or 2)")
            headers[name] = ifo
            terms.setdefault(name, [])
            continue
        if name not in headers:
            raise InputError(f"{where}: column card before the DMIG {name} header (field 2 = "
                             "0); expected the header card first")
        gj, cj = _int(f[1], where), _int(f[2], where)
        entries = f[4:]
        n_groups = len(entries) // 4
        if not any(e.strip() for e in entries):
            raise InputError(f"{where}: column ({gj}, {cj}) has no terms (a truncated card?)")
        for g in range(n_groups):
            gi, ci, a = entries[4 * g:4 * g + 3]
            if not gi and not ci and not a:
                continue
            if not gi or not a:
                raise InputError(f"{where}: term {g + 1} of column ({gj}, {cj}) lacks its grid "
                                 "or value (a truncated card?)")
            terms[name].append((_int(gi, where), _int(ci, where), gj, cj,
                                nastran_real(a, where)))
    return {name: _assemble(name, headers[name], terms[name], src) for name in headers}


def _assemble(name, ifo, terms, src):
    if not terms:
        raise InputError(f"{src}: DMIG {name} has a header but no terms (a truncated file?)")
    t = np.array([x[:4] for x in terms], dtype=np.int64)
    vals = np.array([x[4] for x in terms], dtype=float)
    if ifo == 6:  # one map for rows and columns
        keys = np.unique(np.concatenate([t[:, 0:2], t[:, 2:4]]), axis=0)
        rmap = cmap = DofMap(keys[:, 0], keys[:, 1])
    else:
        rk, ck = np.unique(t[:, 0:2], axis=0), np.unique(t[:, 2:4], axis=0)
        rmap, cmap = DofMap(rk[:, 0], rk[:, 1]), DofMap(ck[:, 0], ck[:, 1])
    ri = _index(rmap, t[:, 0], t[:, 1])
    ci = _index(cmap, t[:, 2], t[:, 3])
    pos = ri * cmap.size + ci
    uniq, counts = np.unique(pos, return_counts=True)
    if np.any(counts > 1):
        p = int(uniq[counts > 1][0])
        raise InputError(f"{src}: DMIG {name} gives term ({rmap.node[p // cmap.size]}, "
                         f"{rmap.component[p // cmap.size]}) x ({cmap.node[p % cmap.size]}, "
                         f"{cmap.component[p % cmap.size]}) twice")
    A = sp.coo_matrix((vals, (ri, ci)), shape=(rmap.size, cmap.size))
    if ifo == 6:
        off = ri != ci
        both = np.intersect1d(pos[off], (ci * cmap.size + ri)[off])
        if both.size:
            raise InputError(f"{src}: DMIG {name} is symmetric (IFO 6) but gives both terms "
                             "(i, j) and (j, i); expected one triangle")
        A = (A + sp.coo_matrix((vals[off], (ci[off], ri[off])), shape=A.shape)).tocoo()
    return rmap, cmap, A, ifo


def _index(dmap: DofMap, node, comp):
    key = dmap.node * 8 + dmap.component
    order = np.argsort(key)
    return order[np.searchsorted(key[order], node * 8 + comp)]


def _square(mats: dict, name: str, what: str, src: str, dofs: DofMap | None):
    rmap, cmap, A, ifo = mats[name]
    if rmap.size != cmap.size or np.any(rmap.node != cmap.node) or np.any(
            rmap.component != cmap.component):
        raise InputError(f"{src}: DMIG {name} ({what}) is not square on one set of DOFs; "
                         "expected a square matrix (IFO 1 or 6)")
    if dofs is None:
        return rmap, A.tocsr()
    # onto the rows of dofs (K's): a DOF of K absent from this matrix has zero terms there
    rows = _lookup(dofs, rmap, f"{src}: DMIG {name} ({what})")
    P = sp.csr_matrix((np.ones(rmap.size), (rows, np.arange(rmap.size))),
                      shape=(dofs.size, rmap.size))
    return dofs, (P @ A.tocsr() @ P.T).tocsr()


def _lookup(dofs: DofMap, sub: DofMap, where: str) -> np.ndarray:
    key = dofs.node * 8 + dofs.component
    order = np.argsort(key)
    skey = sub.node * 8 + sub.component
    pos = np.searchsorted(key[order], skey).clip(0, key.size - 1)
    bad = key[order][pos] != skey
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise InputError(f"{where}: DOF (node {sub.node[i]}, component {sub.component[i]}) is "
                         "not a DOF of K; expected the DOFs of K")
    return order[pos]


def read_nastran_dmig(path, names: dict | None = None) -> FEMatrices:
    """K, M (and C, D where present) from the DMIG cards of a Nastran file.

    Parameters
    ----------
    path : a punch file (``DMIGPCH``) or bulk data holding DMIG cards.
    names : dict, optional
        DMIG name of ``"K"``, ``"M"``, ``"C"`` (viscous), ``"D"`` (structural damping);
        default :data:`DMIG_NAMES` (``KAAX``, ``MAAX``, ``BAAX``, ``K4AX``). K and M must be
        there; C and D are read when present.
    """
    src = str(path)
    mats = read_dmig(path)
    chosen = {**DMIG_NAMES, **{k: str(v).upper() for k, v in (names or {}).items()}}
    bad = set(chosen) - set(DMIG_NAMES)
    if bad:
        raise InputError(f"names: unknown key {sorted(bad)[0]!r}; expected K, M, C, D")
    for what in ("K", "M"):
        if chosen[what] not in mats:
            raise InputError(f"{src}: no DMIG {chosen[what]} ({what}); the file has "
                             f"{sorted(mats)}; name the {what} matrix (names = "
                             f"{{'{what}': ...}})")
    dofs, K = _square(mats, chosen["K"], "K", src, None)
    out = {"K": K}
    for what in ("M", "C", "D"):
        if chosen[what] in mats:
            out[what] = _square(mats, chosen[what], what, src, dofs)[1]
    return FEMatrices(out["K"], out["M"], dofs, C=out.get("C"), D=out.get("D"), source=src)


# --- OP4 (ASCII) ----------------------------------------------------------------------------
_OP4_FMT = re.compile(r"(\d+)P?,?(\d+)[EDed](\d+)\.(\d+)")


def read_op4(path) -> dict[str, sp.csr_matrix]:
    """Every real matrix of an ASCII OP4 file: name -> sparse matrix.

    Dense columns (``ICOL IROW NW`` then ``NW`` values) and the sparse forms (``IROW = 0``,
    strings of ``L IROW`` or packed ``IS``) of Nastran's OUTPUT4 are read; binary OP4 files are
    refused with a message (write them with ``FORMATTED``).
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"OP4 file {str(path)!r} does not exist")
    src = str(path)
    data = path.read_bytes()
    if b"\x00" in data[:64]:
        raise InputError(f"OP4 file {src!r} is binary; expected an ASCII OP4 (Nastran "
                         "OUTPUT4 with FORMATTED, or pyNastran's write_op4(is_binary=False))")
    lines = data.decode(errors="replace").splitlines()
    out = {}
    k = 0
    try:
        while k < len(lines):
            if not lines[k].strip():
                k += 1
                continue
            name, A, k = _op4_matrix(lines, k, src)
            out[name] = A
    except (IndexError, ValueError):
        raise InputError(f"OP4 file {src!r}: cannot read the record at line {k + 1} (a "
                         "truncated or malformed file)") from None
    if not out:
        raise InputError(f"OP4 file {src!r} holds no matrix")
    return out


_INTS = re.compile(r"^\s*-?\d+(\s+-?\d+){0,2}\s*$")


def _op4_matrix(lines, k, src):
    """One matrix from line ``k`` (its header): name, matrix, the line after it.

    Records are told apart by their look: a column header has three integers, a string header
    of a sparse column one (packed ``IS``) or two (``L IROW``), and value lines hold reals; the
    values of a string are those up to the next integer line, whatever the word count says
    (writers count double-precision words differently).
    """
    head = lines[k]
    ncol, nrow, _form, typ = (int(head[i:i + 8]) for i in range(0, 32, 8))
    name = head[32:40].strip().upper()
    m = _OP4_FMT.search(head[40:])
    if not m:
        raise InputError(f"OP4 file {src!r}, line {k + 1}: no number format after the name "
                         f"{name!r} (e.g. 1P,3E23.16)")
    per_line, width = int(m.group(2)), int(m.group(3))
    if typ not in (1, 2):
        raise InputError(f"OP4 file {src!r}: matrix {name} has type {typ} (complex); expected "
                         "a real matrix (type 1 or 2)")
    nrow = abs(nrow)
    k += 1
    rows, cols, vals = [], [], []
    while True:
        tok = lines[k].split()
        if len(tok) != 3 or not _INTS.match(lines[k]):
            raise ValueError(lines[k])
        icol, irow = int(tok[0]), int(tok[1])
        k += 1
        if icol > ncol:  # the closing record: its NW words on whole lines
            k += -(-int(tok[2]) // per_line)
            break
        v, k = _op4_values(lines, k, width)
        if irow != 0:  # dense column from row irow
            rows.extend(range(irow - 1, irow - 1 + len(v)))
            cols.extend([icol - 1] * len(v))
            vals.extend(v)
            continue
        while k < len(lines) and _INTS.match(lines[k]) and len(lines[k].split()) < 3:
            tok = lines[k].split()  # a string header: L IROW, or IS = (L + 1) 65536 + IROW
            row = int(tok[1]) if len(tok) == 2 else int(tok[0]) % 65536
            v, k = _op4_values(lines, k + 1, width)
            rows.extend(range(row - 1, row - 1 + len(v)))
            cols.extend([icol - 1] * len(v))
            vals.extend(v)
    if rows and (max(rows) >= nrow or min(rows) < 0):
        raise ValueError("row out of range")
    A = sp.csr_matrix((np.array(vals, dtype=float), (rows, cols)), shape=(nrow, ncol))
    return name, A, k


def _op4_values(lines, k, width):
    """The reals on the lines from ``k`` up to the next line of integers (or the end)."""
    out = []
    while k < len(lines) and lines[k].strip() and not _INTS.match(lines[k]):
        line = lines[k].rstrip()
        k += 1
        out.extend(nastran_real(line[i:i + width], "OP4 value")
                   for i in range(0, len(line), width) if line[i:i + width].strip())
    return out, k


def read_nastran_op4(path, dofs: DofMap, names: dict | None = None) -> FEMatrices:
    """K, M (and C, D where present) from an ASCII OP4 file, on the rows of ``dofs``.

    ``names`` as for :func:`read_nastran_dmig` (default ``KAAX``, ``MAAX``, ``BAAX``,
    ``K4AX``; any other names when the file holds exactly K and M: give them).
    """
    src = str(path)
    mats = read_op4(path)
    chosen = {**DMIG_NAMES, **{k: str(v).upper() for k, v in (names or {}).items()}}
    for what in ("K", "M"):
        if chosen[what] not in mats:
            raise InputError(f"{src}: no OP4 matrix {chosen[what]} ({what}); the file has "
                             f"{sorted(mats)}; name the {what} matrix (names = "
                             f"{{'{what}': ...}})")
    out = {w: mats[chosen[w]] for w in ("K", "M", "C", "D") if chosen[w] in mats}
    return FEMatrices(out["K"], out["M"], dofs, C=out.get("C"), D=out.get("D"), source=src)
