"""Node coordinates and node sets of the mesh that exported matrices came from, read from the
FE code's input file: Nastran bulk data (``GRID`` cards, basic coordinates; the ``CQUAD4``,
``CTRIA3``, ``CTETRA``, ``CHEXA`` connectivity for ParaView), Abaqus ``.inp`` (``*NODE``,
``*NSET``, ``*ELEMENT``) and ANSYS ``.cdb`` (``NBLOCK``, node components ``CMBLOCK``, the
solid-format ``EBLOCK``).

Only the positions are read (frames, pairing, output); the matrices carry the mechanics.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fretwear.errors import InputError
from fretwear.model.readers.nastran import _fields, nastran_real


@dataclass
class NodeTable:
    """Node ids, their coordinates [m] (n, 3), named node sets (name -> ids) and the
    elements' connectivity by node ids (number of nodes -> (ne, k) ids), for output only."""

    ids: np.ndarray
    xyz: np.ndarray
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)
    elements: dict[int, np.ndarray] = field(default_factory=dict)

    def coordinates(self, ids, dim: int, what: str) -> np.ndarray:
        """Coordinates (len(ids), dim) of the given node ids."""
        ids = np.asarray(ids, dtype=np.int64).reshape(-1)
        order = np.argsort(self.ids)
        pos = np.searchsorted(self.ids[order], ids).clip(0, max(self.ids.size - 1, 0))
        bad = (self.ids.size == 0) | (self.ids[order][pos] != ids)
        if np.any(bad):
            raise InputError(f"{what}: node {int(ids[np.flatnonzero(bad)[0]])} is not in the "
                             "node file; expected nodes of the mesh the matrices came from")
        return self.xyz[order[pos], :dim]


def read_nodes(path) -> NodeTable:
    """The nodes of a Nastran (``.bdf``, ``.dat``, ``.nas``, ``.blk``), Abaqus (``.inp``) or
    ANSYS (``.cdb``) input file."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"node file {str(path)!r} does not exist")
    suffix = path.suffix.lower()
    text = path.read_text(errors="replace")
    if suffix == ".inp":
        table = _abaqus_nodes(text, str(path))
    elif suffix == ".cdb":
        table = _ansys_nodes(text, str(path))
    elif suffix in (".bdf", ".dat", ".nas", ".blk", ".pch", ".fem"):
        table = _nastran_nodes(text, str(path))
    else:
        raise InputError(f"node file {str(path)!r}: unknown suffix {suffix!r}; expected .bdf "
                         "(.dat, .nas), .inp or .cdb")
    if table.ids.size == 0:
        raise InputError(f"node file {str(path)!r} defines no node")
    return table


#: Nastran element cards read for output: name -> number of nodes (after EID and PID)
NASTRAN_ELEMENTS = {"CTRIA3": 3, "CQUAD4": 4, "CTETRA": 4, "CHEXA": 8}


def _nastran_nodes(text: str, src: str) -> NodeTable:
    ids, xyz, elements, bad = [], [], {}, []
    lines = text.splitlines()
    for k, raw in enumerate(lines):
        line = raw.split("$")[0].expandtabs(8)
        first, data = _fields(line)
        if first.upper() in NASTRAN_ELEMENTS:
            try:
                _nastran_element(first.upper(), data, lines, k, src, elements)
            except InputError as exc:  # told once the nodes are known to be there
                bad.append(exc)
            continue
        if first.upper().rstrip("*") != "GRID":
            continue
        if first.endswith("*"):  # large field: x, y on this line, z on the continuation
            data = data + _fields(lines[k + 1].expandtabs(8))[1] if k + 1 < len(lines) else data
        where = f"{src}, line {k + 1} (GRID)"
        if data[1].strip() not in ("", "0"):
            raise InputError(f"{where}: coordinate system CP = {data[1]}; expected positions "
                             "in the basic system (CP blank or 0)")
        try:
            ids.append(int(data[0]))
        except ValueError:
            raise InputError(f"{where}: node id {data[0]!r}; expected an integer") from None
        xyz.append([nastran_real(v or "0", where) for v in data[2:5]])
    if bad and ids:
        raise bad[0]
    return NodeTable(np.array(ids, dtype=np.int64), np.array(xyz, dtype=float).reshape(-1, 3),
                     elements=_arrays(elements))


def _nastran_element(card: str, data: list, lines: list, k: int, src: str,
                     elements: dict) -> None:
    """The node ids of one small- or free-field element card (its continuation line read for
    ``CHEXA``) added to ``elements``."""
    n = NASTRAN_ELEMENTS[card]
    fields = list(data[2:])
    if len(fields) < n and k + 1 < len(lines):
        fields += _fields(lines[k + 1].split("$")[0].expandtabs(8))[1]
    try:
        nodes = [int(v) for v in fields[:n]]
    except ValueError:
        raise InputError(f"{src}, line {k + 1} ({card}): node ids {fields[:n]!r}; expected "
                         f"{n} integers") from None
    elements.setdefault(n, []).append(nodes)


def _arrays(elements: dict) -> dict[int, np.ndarray]:
    return {n: np.array(v, dtype=np.int64).reshape(-1, n) for n, v in elements.items() if v}


def _abaqus_nodes(text: str, src: str) -> NodeTable:
    ids, xyz, sets, elements = [], [], {}, {}
    state, current, generate, pending = None, None, False, []
    for k, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("**"):
            continue
        if line.startswith("*"):
            parts = [p.strip() for p in line[1:].split(",")]
            key = parts[0].upper()
            params = {p.partition("=")[0].strip().upper(): p.partition("=")[2].strip()
                      for p in parts[1:]}
            state = key if key in ("NODE", "NSET", "ELEMENT") else None
            pending = []
            if key == "NSET":
                current = params.get("NSET", "")
                generate = "GENERATE" in params
                sets.setdefault(current, [])
            continue
        tok = [t for t in line.rstrip(",").split(",") if t.strip()]
        try:
            if state == "NODE":
                ids.append(int(tok[0]))
                xyz.append(([float(t) for t in tok[1:4]] + [0.0, 0.0])[:3])
            elif state == "ELEMENT":  # id, nodes; a line ending with "," goes on
                pending.extend(int(t) for t in tok)
                if not line.endswith(","):
                    elements.setdefault(len(pending) - 1, []).append(pending[1:])
                    pending = []
            elif state == "NSET":
                if generate:
                    a, b, step = (int(t) for t in (tok + ["1"])[:3])
                    sets[current].extend(range(a, b + 1, step))
                else:
                    sets[current].extend(int(t) for t in tok)
        except (ValueError, IndexError):
            raise InputError(f"{src}, line {k}: {line[:60]!r}; expected numbers (a node set "
                             "given by name inside *NSET is not read)") from None
    return NodeTable(np.array(ids, dtype=np.int64), np.array(xyz, dtype=float).reshape(-1, 3),
                     {name: np.array(v, dtype=np.int64) for name, v in sets.items()},
                     _arrays(elements))


def _ansys_nodes(text: str, src: str) -> NodeTable:
    ids, xyz, sets, elements = [], [], {}, {}
    lines = text.splitlines()
    try:
        _ansys_blocks(lines, ids, xyz, sets, src, elements)
    except (ValueError, IndexError):
        raise InputError(f"{src}: cannot read its NBLOCK, EBLOCK or CMBLOCK (a truncated or "
                         "malformed file?)") from None
    return NodeTable(np.array(ids, dtype=np.int64), np.array(xyz, dtype=float).reshape(-1, 3),
                     sets, _arrays(elements))


def _ansys_elements(lines, k: int, src: str, elements: dict) -> int:
    """The elements of the ``EBLOCK`` (solid format) whose format line is line ``k``: on each
    element's line field 9 the number of nodes, 12-19 the first eight nodes, the others on
    the next line; up to the ``-1`` line. Returns the line after the block."""
    widths = _fortran_widths(lines[k], src, k + 1)
    k += 1
    while k < len(lines) and not lines[k].strip().startswith("-1"):
        vals = [int(v) for v in _fixed_columns(lines[k], widths) if v.strip()]
        n = vals[8]
        nodes = vals[11:11 + min(n, 8)]
        if n > 8:
            k += 1
            nodes += [int(v) for v in _fixed_columns(lines[k], widths) if v.strip()][:n - 8]
        elements.setdefault(n, []).append(nodes)
        k += 1
    return k


def _ansys_blocks(lines, ids, xyz, sets, src: str, elements: dict) -> None:
    k = 0
    while k < len(lines):
        head = lines[k].strip().upper()
        if head.startswith("EBLOCK") and "SOLID" in head:
            k = _ansys_elements(lines, k + 1, src, elements)
            continue
        if head.startswith("NBLOCK"):
            fmt = lines[k + 1]
            widths = _fortran_widths(fmt, src, k + 2)
            k += 2
            while k < len(lines) and not lines[k].strip().startswith(("N,", "-1")):
                vals = _fixed_columns(lines[k], widths)
                ids.append(int(vals[0]))
                coords = [float(v) if v.strip() else 0.0 for v in vals[3:6]]
                xyz.append((coords + [0.0, 0.0, 0.0])[:3])
                k += 1
        elif head.startswith("CMBLOCK"):
            parts = [p.strip() for p in lines[k].split("!")[0].split(",")]
            name, kind, count = parts[1], parts[2].upper(), int(parts[3])
            k += 2
            items = []
            while len(items) < count and k < len(lines):
                items.extend(int(t) for t in lines[k].split())
                k += 1
            if kind == "NODE":
                sets[name] = _expand_ranges(items)
            continue
        k += 1


def _fortran_widths(fmt: str, src: str, line: int) -> list[int]:
    """Field widths of a format like ``(3i9,6e21.13e3)``."""
    import re

    widths = []
    for count, _kind, width in re.findall(r"(\d*)([ie])(\d+)(?:\.\d+)?(?:e\d+)?",
                                          fmt.lower()):
        widths.extend([int(width)] * int(count or 1))
    if len(widths) < 4:
        raise InputError(f"{src}, line {line}: NBLOCK format {fmt.strip()!r} not understood")
    return widths


def _fixed_columns(line: str, widths: list[int]) -> list[str]:
    out, pos = [], 0
    for w in widths:
        out.append(line[pos:pos + w])
        pos += w
    return out


def _expand_ranges(items: list[int]) -> np.ndarray:
    """ANSYS component lists: a negative entry ``-b`` after ``a`` means ``a..b``."""
    out = []
    for i, v in enumerate(items):
        if v < 0:
            out.extend(range(items[i - 1] + 1, -v + 1))
        else:
            out.append(v)
    return np.array(out, dtype=np.int64)
