"""Numbers of FE-code text files converted as whole arrays (NumPy string functions), not one
term at a time: Nastran reals (``1.5E+3``, ``1.5D+3``, the implied exponent of ``1.5+3``),
integers, and the fixed fields of bulk-data lines (8 characters a field, 16 in large field).

On a bad entry the conversion says which one (its position in the array) in one line; the
callers name the file and line.
"""

from __future__ import annotations

import numpy as np

from fretwear.errors import InputError


def _first_bad(text: np.ndarray, convert) -> int:
    """Index of the first entry of ``text`` that ``convert`` refuses (the error path only)."""
    for i, t in enumerate(text.tolist()):
        try:
            convert(t)
        except ValueError:
            return i
    return -1


def reals(text, where: str) -> np.ndarray:
    """Nastran real fields (str or bytes strings, any shape) as floats: ``E`` or ``D``
    exponents, or an implied one (``-2.5-3``); surrounding blanks ignored.

    Raises
    ------
    InputError
        ``where``, the position and the text of the first entry that is not a number.
    """
    s = np.strings.upper(np.strings.strip(_bytes(text)))
    s = np.strings.replace(s, b"D", b"E")
    # an implied exponent: the last sign after the first character, not after an E
    p = np.maximum(np.strings.rfind(s, b"+"), np.strings.rfind(s, b"-"))
    before = np.strings.slice(s, np.maximum(p - 1, 0), np.maximum(p, 0))
    implied = (p > 0) & (before != b"E")
    if np.any(implied):
        s = s.astype(f"S{s.dtype.itemsize + 1}")
        head = np.strings.add(np.strings.slice(s[implied], 0, p[implied]), b"E")
        s[implied] = np.strings.add(head, np.strings.slice(s[implied], p[implied], None))
    try:
        return s.astype(float)
    except ValueError:
        i = _first_bad(s.ravel(), float)
        raise InputError(f"{where}: entry {i + 1} ({s.ravel()[i].decode()!r}) is not a "
                         "number") from None


def integers(text, where: str, blank: int = 0) -> np.ndarray:
    """Integer fields (str or bytes strings, any shape) as int64; a blank one is ``blank``."""
    s = np.strings.strip(_bytes(text))
    s = np.where(s == b"", str(blank).encode(), s)
    try:
        return s.astype(np.int64)
    except ValueError:
        i = _first_bad(s.ravel(), int)
        raise InputError(f"{where}: entry {i + 1} ({s.ravel()[i].decode()!r}) is not an "
                         "integer; expected an integer") from None


def _bytes(text) -> np.ndarray:
    a = np.asarray(text)
    return a if a.dtype.kind == "S" else np.char.encode(a.astype(str), "ascii", "replace")


def byte_lines(lines: list[str], width: int) -> np.ndarray:
    """Lines as an (n, width) array of bytes (ASCII; blanks past the end of a line)."""
    arr = np.array([x.encode("ascii", "replace") for x in lines], dtype=f"S{width}")
    u8 = arr.view(np.uint8).reshape(len(lines), width).copy()  # (0, width) for no line
    u8[u8 == 0] = ord(" ")
    return u8


def fixed_fields(u8: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The first field (n,) and the eight data fields (n, 8) of bulk-data lines given as bytes
    (n, 72) (:func:`byte_lines`): columns 9-72 cut in 8 fields of 8 characters, or in 4 of 16
    (large field: the first field ends or starts with ``*``) followed by 4 blank ones. Fields
    are stripped bytes, the first upper case."""
    n = u8.shape[0]
    first = np.strings.upper(np.strings.strip(np.ascontiguousarray(u8[:, :8]).view("S8")[:, 0]))
    large = np.strings.endswith(first, b"*") | np.strings.startswith(first, b"*")
    body = np.ascontiguousarray(u8[:, 8:72])
    out = body.view("S8").reshape(n, 8).astype("S16")
    wide = np.flatnonzero(large)
    out[wide, :4] = body[wide].view("S16").reshape(wide.size, 4)
    out[wide, 4:] = b""
    return first, np.strings.strip(out)
