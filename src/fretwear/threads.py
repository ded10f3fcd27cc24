"""The number of BLAS threads fretwear's drivers run with, the same from Python as from the
command line.

fretwear's solves are many dense problems of about a thousand unknowns and sparse
factorisations: threaded BLAS gains little there and oversubscribes small machines (a sweep
ran 3 to 16 times slower from a notebook than from the command line on a busy 2-core machine,
where every BLAS call spawned threads that fought the others). The command line sets
``OPENBLAS_NUM_THREADS`` and its siblings before NumPy loads; from Python NumPy is usually
loaded already, so the public drivers (:mod:`fretwear.api`, :func:`fretwear.run_case`) run
under :func:`threadpoolctl.threadpool_limits` instead, for the duration of the call only: the
user's own NumPy work outside fretwear keeps its threads.

The count is :func:`blas_threads` (default 1; the environment variable ``FRETWEAR_THREADS``,
or :func:`set_blas_threads`, changes it; ``None`` leaves the BLAS library as it is).
"""

from __future__ import annotations

import functools
import os

from fretwear.errors import InputError

_ENV = "FRETWEAR_THREADS"
_state: dict = {}


def _from_env() -> int | None:
    raw = os.environ.get(_ENV, "1").strip()
    if raw.lower() in ("", "none", "all"):
        return None
    try:
        n = int(raw)
    except ValueError:
        raise InputError(f"{_ENV} = {raw!r}: expected a whole number >= 1 or 'none' (leave "
                         "the BLAS threads as they are)") from None
    if n < 1:
        raise InputError(f"{_ENV} = {raw!r}: expected a whole number >= 1 or 'none'")
    return n


def blas_threads() -> int | None:
    """BLAS threads of fretwear's drivers (None: not limited)."""
    if "n" not in _state:
        _state["n"] = _from_env()
    return _state["n"]


def set_blas_threads(n: int | None) -> None:
    """Run fretwear's drivers with ``n`` BLAS threads from now on (``None``: as the BLAS
    library is set, e.g. by ``OPENBLAS_NUM_THREADS``). Large models whose dense blocks have
    several thousand rows may gain from more than one thread on a quiet machine."""
    if n is not None and (isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= 4096):
        raise InputError(f"set_blas_threads({n!r}): expected a whole number >= 1 or None")
    _state["n"] = n


def limited(func):
    """Decorator: run ``func`` with :func:`blas_threads` BLAS threads (restored after)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        n = blas_threads()
        if n is None:
            return func(*args, **kwargs)
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=n, user_api="blas"):
            return func(*args, **kwargs)

    return wrapper
