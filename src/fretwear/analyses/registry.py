"""Analyses by name: the registry that case files and ``fretwear run`` look them up in.

Each analysis module defines its :class:`~fretwear.analyses.base.Analysis` as a module
constant (:mod:`fretwear.analyses.base` shows how); this module imports them by name, plain
imports that the import contracts see, and lists them in :data:`ANALYSES`, in the order of
``docs/case-files.md`` and of the messages that name them. Adding an analysis is its module
and one line here. The schema's keys form the ``[analysis]`` table of a case file (``type`` is
added); :func:`fretwear.analyses.run.load_case` validates it before anything runs;
:func:`fretwear.analyses.run.run_case` runs a case file from end to end.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from types import MappingProxyType

from fretwear.analyses.base import Analysis
from fretwear.analyses.cyclic_modes import CYCLIC_MODES
from fretwear.analyses.linear import FRF, MODES
from fretwear.analyses.nonlinear_modes import NONLINEAR_MODES
from fretwear.analyses.periodic import PERIODIC
from fretwear.analyses.sweep import SWEEP
from fretwear.analyses.transient import INCREMENTAL_WEAR, TRANSIENT
from fretwear.analyses.wear import WEAR
from fretwear.analyses.worn_state import WORN_STATE
from fretwear.errors import InputError
from fretwear.io.schema import Table

#: every analysis, in the order of ``docs/case-files.md``
ANALYSES: tuple[Analysis, ...] = (MODES, FRF, CYCLIC_MODES, PERIODIC, SWEEP, NONLINEAR_MODES,
                                  TRANSIENT, INCREMENTAL_WEAR, WEAR, WORN_STATE)


def by_name(analyses: Iterable[Analysis]) -> Mapping[str, Analysis]:
    """``name -> analysis`` in the order given (read-only); a ValueError names a name given
    twice and the run functions of both."""
    out: dict[str, Analysis] = {}
    for a in analyses:
        if not isinstance(a, Analysis):
            raise TypeError(f"{a!r}: expected an Analysis")
        old = out.get(a.name)
        if old is not None:
            raise ValueError(f"analysis {a.name!r} is defined twice: by "
                             f"{old.run.__module__}.{old.run.__qualname__} and by "
                             f"{a.run.__module__}.{a.run.__qualname__}")
        out[a.name] = a
    return MappingProxyType(out)


_BY_NAME = by_name(ANALYSES)


def analysis_tables() -> dict[str, Table]:
    """``type -> Table`` of every analysis (for case validation and docs)."""
    return {name: a.schema for name, a in _BY_NAME.items()}


def available() -> list[str]:
    """Names of the analyses."""
    return list(_BY_NAME)


def get(name: str) -> Analysis:
    """The analysis ``name``; an InputError lists the available ones."""
    if name not in _BY_NAME:
        raise InputError(
            f"analysis.type = {name!r} is not available; expected one of: {', '.join(_BY_NAME)}"
        )
    return _BY_NAME[name]
