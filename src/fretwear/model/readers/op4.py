"""Nastran OP4 files (``OUTPUT4``): ASCII and binary, real matrices, read from the documented
format (MSC Nastran DMAP Programmer's Guide, OUTPUT4) with NumPy alone.

A matrix is a header (``NCOL NROW NF NTYPE NAME``), then one record a column holding values,
``ICOL IROW NW`` followed by ``NW`` words, and a closing record with ``ICOL = NCOL + 1``.
``IROW > 0``: a dense column, values from row ``IROW``. ``IROW = 0``: a sparse column, its
``NW`` words are strings, each a header and its values: ``IS = IROW + 65536 (L + 1)`` (one
word, ``L`` words of values; ``NROW > 0``) or ``L IROW`` (two words, ``L - 1`` words of
values; ``NROW < 0``, the "big matrix" form). A double-precision value (NTYPE 2) is two
words. The binary file is Fortran unformatted: every record framed by its length in bytes
(4-byte integers, either byte order: the header record is 24 bytes long).

The values are converted as whole arrays (no loop over terms): the dovetail's OP4 of
2.3e5 terms a matrix reads in a fraction of a second.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.readers.fields import byte_lines, reals

_FMT = re.compile(r"(\d+)P?,?(\d+)[EDed](\d+)\.(\d+)")
_INTS = re.compile(r"^\s*-?\d+(\s+-?\d+){0,2}\s*$")


def read_op4(path) -> dict[str, sp.csr_matrix]:
    """Every real matrix of an OP4 file, ASCII or binary: name -> sparse matrix.

    Raises
    ------
    InputError
        A missing file, a complex matrix, a truncated or malformed record (its line, or its
        byte offset), no matrix.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"OP4 file {str(path)!r} does not exist")
    data = path.read_bytes()
    out = _binary(data, str(path)) if b"\x00" in data[:64] else _ascii(data, str(path))
    if not out:
        raise InputError(f"OP4 file {str(path)!r} holds no matrix")
    return out


def _matrix(name, typ, nrow, ncol, rows, cols, vals, src):
    if typ not in (1, 2):
        raise InputError(f"OP4 file {src!r}: matrix {name} has type {typ} (complex); expected "
                         "a real matrix (type 1 or 2)")
    rows, cols = np.asarray(rows, np.int64), np.asarray(cols, np.int64)
    if rows.size and (rows.max() >= nrow or rows.min() < 0 or cols.max() >= ncol
                      or cols.min() < 0):
        raise InputError(f"OP4 file {src!r}: matrix {name} has a term out of its {nrow} x "
                         f"{ncol} size (a malformed file)")
    return sp.csr_matrix((np.asarray(vals, float), (rows, cols)), shape=(nrow, ncol))


def _runs(starts, lengths):
    """``starts[i] + 0 .. lengths[i] - 1`` for every run, concatenated."""
    lengths = np.asarray(lengths, np.int64)
    offset = np.repeat(np.cumsum(lengths) - lengths, lengths)
    return np.repeat(np.asarray(starts, np.int64), lengths) + np.arange(lengths.sum()) - offset


# --- ASCII ------------------------------------------------------------------------------------
def _ascii(data: bytes, src: str) -> dict[str, sp.csr_matrix]:
    """Records are told apart by their look: a column header has three integers, a string
    header one (``IS``) or two (``L IROW``), and value lines hold reals; the values of a record
    are those up to the next integer line, whatever the word count says (writers count
    double-precision words differently)."""
    lines = data.decode(errors="replace").splitlines()
    n = len(lines)
    ints = np.array([("." not in x) and bool(_INTS.match(x)) for x in lines] or [False])[:n]
    idx = np.flatnonzero(ints)
    tok = [lines[i].split() for i in idx]
    count = np.array([len(t) for t in tok], dtype=np.int64)
    t = np.array([(t + [0, 0])[:3] for t in tok], dtype=np.int64).reshape(-1, 3)
    blank = np.array([not x.strip() for x in lines], dtype=bool)
    out = {}
    k = 0
    while k < n:
        if blank[k]:
            k += 1
            continue
        try:
            head = lines[k]
            ncol, nrow, _form, typ = (int(head[i:i + 8]) for i in range(0, 32, 8))
        except ValueError:
            raise InputError(f"OP4 file {src!r}, line {k + 1}: {head[:40]!r} is not a matrix "
                             "header (NCOL NROW NF NTYPE NAME format; a malformed file?)") from None
        name = head[32:40].strip().upper()
        m = _FMT.search(head[40:])
        if not m:
            raise InputError(f"OP4 file {src!r}, line {k + 1}: no number format after the "
                             f"name {name!r} (e.g. 1P,3E23.16)")
        per_line, width = int(m.group(2)), int(m.group(3))
        lo = np.searchsorted(idx, k + 1)
        close = np.flatnonzero((idx[lo:] > k) & (count[lo:] == 3) & (t[lo:, 0] > ncol))
        if close.size == 0:
            raise InputError(f"OP4 file {src!r}: matrix {name} (line {k + 1}) has no closing "
                             "record (a truncated file)")
        hi = lo + close[0]
        where = f"OP4 file {src!r}, matrix {name}"
        out[name] = _ascii_matrix(lines, (idx[lo:hi + 1], count[lo:hi], t[lo:hi]),
                                  (k, per_line, width), (name, typ, abs(nrow), ncol), where)
        k = idx[hi] + 1 + -(-int(t[hi, 2]) // per_line)
    return out


def _ascii_matrix(lines, records, layout, size, where):
    """One matrix from its integer lines ``records`` (line numbers with the closing one,
    token counts, tokens) and the value lines between them."""
    at, count, t = records
    k, per_line, width = layout
    name, typ, nrow, ncol = size
    if count.size == 0:
        return _matrix(name, typ, nrow, ncol, [], [], [], where)
    first, last = k + 1, at[-1]
    body = lines[first:last]
    is_val = np.ones(len(body), dtype=bool)
    is_val[at[:-1] - first] = False
    vlines = [body[i] for i in np.flatnonzero(is_val)]
    u8 = byte_lines(vlines, per_line * width)  # (n, per_line * width) bytes
    fields = np.strings.strip(u8.view(f"S{width}").reshape(len(vlines), per_line))
    filled = fields != b""
    vals = reals(fields[filled], where)
    # values per line of the matrix body, then per integer record (up to the next one)
    per_body_line = np.zeros(len(body) + 1, dtype=np.int64)
    per_body_line[1:][is_val] = filled.sum(axis=1)
    cum = np.cumsum(per_body_line)
    ends = np.append(at[1:-1] - first, len(body))
    nvals = cum[ends] - cum[at[:-1] - first + 1]
    col_head = count == 3
    if not col_head[0]:
        raise InputError(f"{where}: a string header before the first column header (a "
                         "malformed file)")
    col = t[np.maximum.accumulate(np.where(col_head, np.arange(count.size), 0)), 0] - 1
    row = np.where(col_head, t[:, 1], np.where(count == 2, t[:, 1], t[:, 0] % 65536)) - 1
    owns = ~(col_head & (t[:, 1] == 0))  # a sparse column's header holds no values itself
    start = np.concatenate([[0], np.cumsum(nvals)[:-1]])
    keep = owns & (nvals > 0)
    rows = _runs(row[keep], nvals[keep])
    cols = np.repeat(col[keep], nvals[keep])
    pick = _runs(start[keep], nvals[keep])
    return _matrix(name, typ, nrow, ncol, rows, cols, vals[pick], where)


# --- binary -----------------------------------------------------------------------------------
def _binary(data: bytes, src: str) -> dict[str, sp.csr_matrix]:
    """The Fortran records of a binary OP4: header, column records, closing record."""
    for order in "<>":
        if np.frombuffer(data[:4], f"{order}i4")[0] == 24:
            break
    else:
        raise InputError(f"OP4 file {src!r} is binary but does not open with a 24-byte header "
                         "record (4-byte integers); expected a binary OP4 of Nastran OUTPUT4")
    i4 = np.dtype(f"{order}i4")
    pos, out = 0, {}
    try:
        while pos < len(data):
            head, pos = _record(data, pos, i4)
            ncol, nrow, _form, typ = np.frombuffer(head[:16], i4).tolist()
            name = head[16:24].decode(errors="replace").strip().upper()
            if typ not in (1, 2):
                _matrix(name, typ, 0, 0, [], [], [], src)
            real = np.dtype(f"{order}f{4 * typ}")
            rows, cols, vals = [], [], []
            while True:
                rec, pos = _record(data, pos, i4)
                icol, irow, nw = np.frombuffer(rec[:12], i4).tolist()
                if icol > ncol:
                    break
                r, v = _column(rec[12:12 + 4 * nw], irow, nrow < 0, (i4, real, typ))
                rows.append(r)
                vals.append(v)
                cols.append(np.full(r.size, icol - 1))
            cat = (lambda a: np.concatenate(a) if a else [])  # noqa: E731
            out[name] = _matrix(name, typ, abs(nrow), ncol, cat(rows), cat(cols), cat(vals),
                                src)
    except (ValueError, IndexError):
        raise InputError(f"OP4 file {src!r} (binary): cannot read the record at byte {pos} (a "
                         "truncated or malformed file)") from None
    return out


def _record(data: bytes, pos: int, i4) -> tuple[bytes, int]:
    """One Fortran unformatted record from byte ``pos``: its bytes and the position after it."""
    n = int(np.frombuffer(data[pos:pos + 4], i4)[0])
    end = pos + 4 + n
    if n < 12 or end + 4 > len(data) or int(np.frombuffer(data[end:end + 4], i4)[0]) != n:
        raise ValueError(pos)
    return data[pos + 4:end], end + 4


def _column(words: bytes, irow: int, big: bool, types):
    """Rows (0-based) and values of one column record's words."""
    i4, real, typ = types
    if irow > 0:  # dense from irow
        v = np.frombuffer(words, real)
        return irow - 1 + np.arange(v.size), v
    rows, vals, p = [], [], 0
    while p < len(words):  # strings: a header, then its values
        if big:
            length, row = np.frombuffer(words[p:p + 8], i4).tolist()
            nw, p = length - 1, p + 8
        else:
            is_ = int(np.frombuffer(words[p:p + 4], i4)[0])
            nw, row, p = is_ // 65536 - 1, is_ % 65536, p + 4
        if nw <= 0 or p + 4 * nw > len(words):
            raise ValueError(p)
        v = np.frombuffer(words[p:p + 4 * nw], real)
        rows.append(row - 1 + np.arange(v.size))
        vals.append(v)
        p += 4 * nw
    return np.concatenate(rows), np.concatenate(vals)
