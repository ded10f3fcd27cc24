"""Checks of the arguments of the public API, shared so that every entry point answers a wrong
argument as a case file does: one :class:`~fretwear.errors.InputError` naming the argument, the
value and what is expected, never a deep error or a silent acceptance.

A number is a real number (int, float or a numpy scalar): a string (``"1"``), a bool or None is
refused rather than converted, since ``float("1")`` would hide a mistake that the case files
(typed TOML) cannot make. :class:`ArgumentTypeError` is both an InputError and a TypeError, for
an argument of the wrong kind (a model that is None).
"""

from __future__ import annotations

import math
import numbers
import os
from pathlib import Path

import numpy as np

from fretwear.errors import InputError


class ArgumentTypeError(InputError, TypeError):
    """An argument of the wrong kind (an InputError, and a TypeError as Python raises)."""


def is_real(value) -> bool:
    """True for a real number that is not a bool (int, float, numpy integer or float)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)


def number(value, what: str, *, low: float | None = None, high: float | None = None,
           open_low: bool = False, allow_inf: bool = False, unit: str = "") -> float:
    """``value`` as a float, after checking it is a real number (not a string or a bool),
    finite (unless ``allow_inf``) and in ``[low, high]`` (``(low, high]`` with
    ``open_low``)."""
    u = f" {unit}" if unit else ""
    if not is_real(value):
        raise InputError(f"{what} = {value!r} is not a number" + (f" [{unit}]" if unit else ""))
    v = float(value)
    if math.isnan(v) or (math.isinf(v) and not allow_inf):
        raise InputError(f"{what} = {value!r}; expected a finite number"
                         + (f" [{unit}]" if unit else ""))
    below = low is not None and (v <= low if open_low else v < low)
    if below or (high is not None and v > high):
        lo = "" if low is None else f"{'>' if open_low else '>='} {low:g}"
        hi = "" if high is None else f"<= {high:g}"
        rng = " and ".join(s for s in (lo, hi) if s)
        raise InputError(f"{what} = {value!r}{u}; expected a value {rng}")
    return v


#: the largest magnitude of a whole-number argument, as of the case files' integer keys (below
#: numpy's int64 limit; no count or index of a model comes near it)
WHOLE_MAX = 2**62


def whole(value, what: str, *, low: int | None = None, high: int | None = None) -> int:
    """``value`` as an int, after checking it is an integer (not a float, string or bool) in
    ``[low, high]``."""
    if not isinstance(value, numbers.Integral) or isinstance(value, bool | np.bool_):
        raise InputError(f"{what} = {value!r}; expected a whole number")
    v = int(value)
    low = -WHOLE_MAX if low is None else max(low, -WHOLE_MAX)
    high = WHOLE_MAX if high is None else min(high, WHOLE_MAX)
    if (low is not None and v < low) or (high is not None and v > high):
        rng = " and ".join(s for s in ("" if low is None else f">= {low}",
                                       "" if high is None else f"<= {high}") if s)
        raise InputError(f"{what} = {value!r}; expected a whole number {rng}")
    return v


def reals(value, what: str, *, low: float | None = None, open_low: bool = False,
          ndim: int | None = None, empty: bool = False) -> np.ndarray:
    """``value`` as a float array, after checking it holds real numbers only (no strings),
    all finite, ``> low`` (``open_low``) or ``>= low``, with ``ndim`` dimensions and not empty
    unless ``empty``."""
    if isinstance(value, str | bytes):
        raise InputError(f"{what} = {value!r}; expected numbers, not a string")
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):  # ragged sequences
        raise InputError(f"{what} = {value!r}; expected an array of numbers") from None
    if a.dtype.kind not in "iuf":
        raise InputError(f"{what} = {_short(value)} (dtype {a.dtype}); expected real numbers")
    a = a.astype(float)
    if ndim is not None and a.ndim != ndim:
        raise InputError(f"{what} has shape {a.shape}; expected {ndim} dimension(s)")
    if not empty and a.size == 0:
        raise InputError(f"{what} is empty; expected at least one value")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{what} holds non-finite values (nan or inf); expected finite ones")
    if low is not None and np.any(a <= low if open_low else a < low):
        bad = a[a <= low] if open_low else a[a < low]
        raise InputError(f"{what} holds {bad.ravel()[0]:g}; expected values "
                         f"{'>' if open_low else '>='} {low:g}")
    return a


def path(value, what: str) -> Path:
    """``value`` as a Path, after checking it is a str or an os.PathLike (not None)."""
    if not isinstance(value, str | os.PathLike) or (isinstance(value, str) and not value):
        raise ArgumentTypeError(f"{what} = {value!r}; expected a file path (str or Path)")
    return Path(value)


def choice(value, what: str, options) -> str:
    """``value`` after checking it is one of ``options``."""
    if not isinstance(value, str) or value not in options:
        raise InputError(f"{what} = {value!r}; expected one of {list(options)}")
    return value


def flag(value, what: str) -> bool:
    """``value`` after checking it is True or False."""
    if not isinstance(value, bool | np.bool_):
        raise InputError(f"{what} = {value!r}; expected True or False")
    return bool(value)


def instance(value, kind: type, what: str, expected: str):
    """``value`` after checking it is a ``kind`` (:class:`ArgumentTypeError` naming
    ``expected`` otherwise)."""
    if not isinstance(value, kind):
        raise ArgumentTypeError(f"{what} = {_short(value)}; expected {expected}")
    return value


def _short(value, n: int = 60) -> str:
    r = repr(value)
    return r if len(r) <= n else r[: n - 3] + "..."
