"""Analyses by name: the registry that case files and ``fretwear run`` look them up in.

An analysis module registers itself when imported::

    from fretwear.analyses.registry import RunOutput, register
    from fretwear.io.schema import Field, Integer

    def run(model, analysis, case, outdir, progress):
        ...                         # compute, write figures into outdir
        return RunOutput(dataset, figures, summary, success)

    register("periodic", {"n_harmonics": Field(Integer(lo=1), "kept harmonics", default=7)},
             run, doc="One paragraph for docs/case-files.md.")

and is listed once in :data:`ANALYSIS_MODULES` (imported the first time the registry is
used). The schema's keys form the ``[analysis]`` table of a case file (``type`` is added);
:func:`fretwear.analyses.run.load_case` validates it before anything runs;
:func:`fretwear.analyses.run.run_case` runs a case file from end to end.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from fretwear.errors import InputError
from fretwear.io.schema import Table

if TYPE_CHECKING:
    import xarray as xr

#: modules that register analyses when imported: add one line per analysis module
ANALYSIS_MODULES = (
    "fretwear.analyses.linear",  # "modes", "frf"
    "fretwear.analyses.periodic",  # "periodic"
    "fretwear.analyses.sweep",  # "sweep"
    "fretwear.analyses.transient",  # "transient", "incremental-wear"
    "fretwear.analyses.wear",  # "wear"
)

@dataclass
class RunOutput:
    """What an analysis returns.

    Attributes
    ----------
    dataset : the results (``docs/results.md``: every variable with ``units`` and
        ``long_name``, no complex values); :func:`run_case` adds the global attributes.
    figures : figure files written (in ``outdir``).
    summary : a few lines for the terminal (also ``message``).
    success : False if some solve did not converge (the results file records it as its
        ``converged`` attribute).
    files : other files written (e.g. ParaView ``.vtu``/``.pvd``).
    results : the results file, set by :func:`run_case`.
    warnings : reasons for caution about the whole run, one line each (e.g. the static preload
        solve that gives the stick anchors did not converge); :func:`run_case` prints them and
        records them in the ``warnings`` attribute of the results.
    """

    dataset: xr.Dataset
    figures: list[Path] = field(default_factory=list)
    summary: str = ""
    success: bool = True
    files: list[Path] = field(default_factory=list)
    results: Path | None = None
    warnings: list[str] = field(default_factory=list)

    @property
    def message(self) -> str:
        """What the run found (``summary``)."""
        return self.summary


RunFunction = Callable[..., RunOutput]


@dataclass(frozen=True)
class Analysis:
    """A registered analysis: its ``[analysis]`` table schema, its run function and the files
    it keeps in the results folder besides ``results.nc`` (e.g. a checkpoint)."""

    name: str
    schema: Table
    run: RunFunction
    files: tuple[str, ...] = ()
    preload_check: bool = False


_REGISTRY: dict[str, Analysis] = {}
_loaded = False


def register(name: str, schema: Table | Mapping, run: RunFunction, *, doc: str = "",
             checks: tuple = (), files: tuple[str, ...] = (),
             preload_check: bool = False) -> None:
    """Make an analysis available to case files as ``[analysis] type = name``.

    Parameters
    ----------
    name : the ``type`` value.
    schema : a :class:`fretwear.io.schema.Table`, or a dict ``key -> Field`` of the table's keys
        (without ``type``).
    run : ``run(model, analysis, case, outdir, progress) -> RunOutput`` with ``model`` the
        :class:`~fretwear.model.core.Model`, ``analysis`` the validated table (a dict with
        defaults filled in, including ``type``), ``case`` the :class:`fretwear.io.case.Case`
        (title, output options, ``resume``), ``outdir`` the results folder (a
        :class:`~pathlib.Path` that exists) and ``progress`` whether to show progress bars.
        Bad input found while running raises :class:`~fretwear.errors.InputError`.
    doc : paragraph for ``docs/case-files.md`` (when ``schema`` is a dict).
    checks : rules across keys (when ``schema`` is a dict), e.g.
        ``fretwear.io.schema.increasing("f_min", "f_max", "Hz")``.
    files : names of the files the analysis writes in ``outdir`` as it goes (checkpoints);
        :func:`fretwear.analyses.run.run_case` refuses a folder in their place before
        anything runs.
    preload_check : the analysis runs the contact law (vibration, wear):
        :func:`fretwear.analyses.run.run_case` first solves the static contact under the
        preload and warns about an interface that no node of touches
        (:func:`fretwear.hb.preload.preload_contact`).
    """
    table = schema if isinstance(schema, Table) else Table(dict(schema), tuple(checks), doc)
    if "type" in table.fields:
        raise ValueError(f"analysis {name!r}: 'type' is added by the registry, not the schema")
    old = _REGISTRY.get(name)
    if old is not None and old.run is not run:
        raise ValueError(f"analysis {name!r} is already registered by {old.run.__module__}")
    _REGISTRY[name] = Analysis(name, table, run, tuple(files), bool(preload_check))


def _load() -> None:
    """Import :data:`ANALYSIS_MODULES` once; the analyses are then listed in the order of that
    tuple (and of registration within a module), whichever module was imported first."""
    global _loaded
    if not _loaded:
        _loaded = True
        for module in ANALYSIS_MODULES:
            importlib.import_module(module)
        rank = {module: i for i, module in enumerate(ANALYSIS_MODULES)}
        ordered = sorted(_REGISTRY.items(),
                         key=lambda item: rank.get(item[1].run.__module__, len(rank)))
        _REGISTRY.clear()
        _REGISTRY.update(ordered)


def analysis_tables() -> dict[str, Table]:
    """``type -> Table`` of every registered analysis (for case validation and docs)."""
    _load()
    return {name: a.schema for name, a in _REGISTRY.items()}


def available() -> list[str]:
    """Names of the registered analyses."""
    _load()
    return list(_REGISTRY)


def get(name: str) -> Analysis:
    """The registered analysis ``name``; an InputError lists the available ones."""
    _load()
    if name not in _REGISTRY:
        raise InputError(
            f"analysis.type = {name!r} is not available; expected one of: {', '.join(_REGISTRY)}"
        )
    return _REGISTRY[name]
