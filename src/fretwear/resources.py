"""What the machine can hold: a case that cannot fit is refused before it allocates.

A size that cannot fit (a mesh of 1e9 elements, 1e9 samples per period, a Matrix Market header
announcing 1e9 rows) would otherwise end in a MemoryError deep inside numpy after minutes of
work, or take the machine down. Estimates are rough (within a small factor) and only refuse
what clearly cannot fit.
"""

from __future__ import annotations

import os

from fretwear.errors import InputError


def machine_memory() -> int:
    """Physical memory of the machine [bytes] (0 when the system does not say)."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 0


def gib(nbytes: float) -> str:
    """``nbytes`` in GiB, for messages."""
    return f"{nbytes / 2**30:.3g} GiB"


def require_memory(nbytes: float, what: str, fraction: float = 0.9) -> None:
    """Refuse ``what`` when its estimated memory ``nbytes`` exceeds ``fraction`` of the
    machine's memory, saying both figures."""
    total = machine_memory()
    if total and nbytes > fraction * total:
        raise InputError(f"{what} needs about {gib(nbytes)} of memory; this machine has "
                         f"{gib(total)}: make it smaller")
