"""Nastran matrices: DMIG cards (punch files of ``DMIGPCH`` / ``EXTSEOUT`` and bulk data)
and OP4 files (ASCII or binary: :mod:`~.op4`), read from the documented formats with NumPy
alone.

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
from fretwear.model.readers.fields import byte_lines, fixed_fields, integers, reals
from fretwear.model.readers.op4 import read_op4

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


def _free_fields(line: str) -> tuple[str, list[str]]:
    """The first field and the eight data fields of a free-field (comma) line."""
    tok = [t.strip() for t in line.split(",")]
    return tok[0], (tok[1:] + [""] * 8)[:8]


def _fields(line: str) -> tuple[str, list[str]]:
    """The first field and the data fields of one line (small, large or free field)."""
    if "," in line:
        return _free_fields(line)
    first = line[:8].strip()
    if first.endswith("*") or first.startswith("*"):
        body = line[8:72].ljust(64)
        return first, [body[i:i + 16].strip() for i in range(0, 64, 16)]
    body = line[8:72].ljust(64)
    return first, [body[i:i + 8].strip() for i in range(0, 64, 8)]


def _dmig_lines(text: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The lines of the DMIG cards of a bulk-data or punch text: line numbers (n,), whether
    each starts a card (n,), and the eight data fields of each (n, 8, bytes). A continuation
    (first field blank or starting with ``+`` or ``*``) belongs to the card before it; the
    lines of other cards are left out. Fixed fields are cut as whole arrays."""
    lines = [r.split("$")[0] if "$" in r else r for r in text.splitlines()]
    lines = [x.expandtabs(8) if "\t" in x else x for x in lines]
    number = np.array([k for k, x in enumerate(lines, start=1) if x.strip()], dtype=np.int64)
    lines = [x for x in lines if x.strip()]
    first, fields = fixed_fields(byte_lines(lines, 72))
    for i in (k for k, x in enumerate(lines) if "," in x):  # free field, line by line
        head, data = _free_fields(lines[i])
        first[i] = head.upper().encode("ascii", "replace")[:8]
        fields[i] = [d.encode("ascii", "replace") for d in data]
    start = np.strings.strip(first, b"*") == b"DMIG"
    cont = (first == b"") | np.strings.startswith(first, b"+") | np.strings.startswith(
        first, b"*")
    cont &= ~start
    # a continuation is ours if the last card start or other card before it is a DMIG start
    event = np.where(start | ~cont, np.arange(start.size), -1)
    last = np.maximum.accumulate(event) if event.size else event
    ours = start | (cont & (last >= 0) & start[np.maximum(last, 0)])
    return number[ours], start[ours], fields[ours]


def read_dmig(path) -> dict[str, tuple[DofMap, DofMap, sp.coo_matrix, int]]:
    """Every DMIG matrix of a file: name -> (row map, column map, matrix, IFO).

    Rows and columns are numbered in sorted (grid, component) order. A symmetric matrix
    (IFO 6) given by one triangle is filled in. The fields are converted as whole arrays
    (:mod:`~.fields`): a file of 10^5 terms reads in a fraction of a second.

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
    text = path.read_text(errors="replace")
    number, start, fields = _dmig_lines(text)
    if not start.any():
        raise InputError(f"Nastran file {src!r} has no DMIG card; expected DMIG matrices "
                         "(DMIGPCH punch file or bulk data)")
    last = text.rstrip("\r\n ").count("\n") + 1
    if not text.endswith("\n") and number[-1] == last:
        raise InputError(f"Nastran file {src!r} ends inside a DMIG card, line {last}, "
                         "without its line end (a truncated file?); expected the whole file "
                         "(add the final newline if it is whole)")
    card = np.cumsum(start) - 1  # the card of each line
    heads = np.flatnonzero(start)
    name = np.strings.upper(fields[heads, 0]).astype(str)
    header = (fields[heads, 1] == b"0") | (fields[heads, 1] == b"")
    headers: dict[str, int] = {}
    for h in np.flatnonzero(header):  # one header card a matrix
        i = heads[h]
        where = f"{src}, line {number[i]} (DMIG {name[h]})"
        ifo, tin = integers(fields[i, 2:4], where)
        if tin not in (1, 2):
            raise InputError(f"{where}: TIN = {tin} (complex terms); expected a real matrix "
                             "(TIN 1 or 2)")
        headers[str(name[h])] = int(ifo)
    columns = np.flatnonzero(~header)
    unknown = [k for k in columns if str(name[k]) not in headers]
    if unknown:
        k = unknown[0]
        raise InputError(f"{src}, line {number[heads[k]]} (DMIG {name[k]}): column card before "
                         f"the DMIG {name[k]} header (field 2 = 0); expected the header card "
                         "first")
    # the groups of four fields: (name, GJ, CJ, -) opens a card, then (GI, CI, A, -) terms
    groups = fields.reshape(-1, 4)
    g_line = np.repeat(np.arange(number.size), 2)
    g_card = card[g_line]
    opening = np.zeros(groups.shape[0], dtype=bool)
    opening[2 * heads] = True
    is_term = ~opening & ~header[g_card] & np.any(groups[:, :3] != b"", axis=1)
    where = f"{src} (DMIG)"
    gj = integers(fields[heads, 1], where)
    cj = integers(fields[heads, 2], where)
    has_terms = np.zeros(heads.size, dtype=bool)
    has_terms[g_card[is_term]] = True
    empty = np.flatnonzero(~header & ~has_terms)
    if empty.size:
        k = empty[0]
        raise InputError(f"{src}, line {number[heads[k]]} (DMIG {name[k]}): column ({gj[k]}, "
                         f"{cj[k]}) has no terms (a truncated card?)")
    t = groups[is_term]
    lacking = np.flatnonzero((t[:, 0] == b"") | (t[:, 2] == b""))
    if lacking.size:
        k = g_card[is_term][lacking[0]]
        raise InputError(f"{src}, line {number[g_line[is_term][lacking[0]]]} (DMIG {name[k]}): "
                         f"a term of column ({gj[k]}, {cj[k]}) lacks its grid or value (a "
                         "truncated card?)")
    tc = g_card[is_term]
    term_name = name[tc]
    gi, ci = integers(t[:, 0], where), integers(t[:, 1], where)
    vals = reals(t[:, 2], where)
    out = {}
    for nm, ifo in headers.items():
        sel = term_name == nm
        terms = np.column_stack([gi[sel], ci[sel], gj[tc[sel]], cj[tc[sel]]])
        out[nm] = _assemble(nm, ifo, terms, vals[sel], src)
    return out


def _keys(node, comp) -> DofMap:
    """The sorted distinct (node, component) pairs (components 0-6)."""
    code = np.unique(np.asarray(node, np.int64) * 8 + np.asarray(comp, np.int64))
    return DofMap(code // 8, code % 8)


def _assemble(name, ifo, t, vals, src):
    if t.shape[0] == 0:
        raise InputError(f"{src}: DMIG {name} has a header but no terms (a truncated file?)")
    if ifo == 6:  # one map for rows and columns
        rmap = cmap = _keys(np.concatenate([t[:, 0], t[:, 2]]),
                            np.concatenate([t[:, 1], t[:, 3]]))
    else:
        rmap, cmap = _keys(t[:, 0], t[:, 1]), _keys(t[:, 2], t[:, 3])
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


def read_nastran_op4(path, dofs: DofMap, names: dict | None = None) -> FEMatrices:
    """K, M (and C, D where present) from an OP4 file (ASCII or binary, :mod:`~.op4`), on
    the rows of ``dofs``.

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
