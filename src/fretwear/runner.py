"""Analyses by name, and running a case file from end to end.

An analysis module registers itself when imported::

    from fretwear.runner import RunOutput, register
    from fretwear.schema import Field, Integer

    def run(model, analysis, case, outdir, progress):
        ...                         # compute, write figures into outdir
        return RunOutput(dataset, figures, summary, converged)

    register("periodic", {"n_harmonics": Field(Integer(lo=1), "kept harmonics", default=7)},
             run, doc="One paragraph for docs/case-files.md.")

and is listed once in :data:`ANALYSIS_MODULES` (imported the first time the registry is
used). The schema's keys form the ``[analysis]`` table of a case file (``type`` is added);
:func:`fretwear.case.load_case` validates it before anything runs.

:func:`run_case` loads and validates a case, builds the model, runs the analysis, writes
``results.nc`` (:mod:`fretwear.results`) and prints a short summary.

Long analyses (wear) that want ``--resume`` save their state in ``outdir`` with
:func:`fretwear.results.atomic_write` as they go, and read it back when ``case.resume`` is
true; on Ctrl-C, :func:`run_case` reports the files saved during the run.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from fretwear import __version__
from fretwear.errors import InputError
from fretwear.schema import Table

if TYPE_CHECKING:
    import xarray as xr

#: modules that register analyses when imported: add one line per analysis module
ANALYSIS_MODULES = (
    "fretwear.run_linear",  # "modes", "frf"
    "fretwear.run_dlft",  # "periodic", "sweep"
    "fretwear.run_transient",  # "transient", "incremental-wear"
    "fretwear.run_wear",  # "wear"
)

RESULTS_FILE = "results.nc"


@dataclass
class RunOutput:
    """What an analysis returns.

    Attributes
    ----------
    dataset : the results (``docs/results.md``: every variable with ``units`` and
        ``long_name``, no complex values); :func:`run_case` adds the global attributes.
    figures : figure files written (in ``outdir``).
    summary : a few lines for the terminal.
    converged : False if some solve did not converge (the file records it).
    files : other files written (e.g. ParaView ``.vtu``/``.pvd``).
    results : the results file, set by :func:`run_case`.
    """

    dataset: xr.Dataset
    figures: list[Path] = field(default_factory=list)
    summary: str = ""
    converged: bool = True
    files: list[Path] = field(default_factory=list)
    results: Path | None = None


RunFunction = Callable[..., RunOutput]


@dataclass(frozen=True)
class Analysis:
    """A registered analysis: its ``[analysis]`` table schema and its run function."""

    name: str
    schema: Table
    run: RunFunction


_REGISTRY: dict[str, Analysis] = {}
_loaded = False


def register(name: str, schema: Table | Mapping, run: RunFunction, *, doc: str = "",
             checks: tuple = ()) -> None:
    """Make an analysis available to case files as ``[analysis] type = name``.

    Parameters
    ----------
    name : the ``type`` value.
    schema : a :class:`fretwear.schema.Table`, or a dict ``key -> Field`` of the table's keys
        (without ``type``).
    run : ``run(model, analysis, case, outdir, progress) -> RunOutput`` with ``model`` the
        :class:`~fretwear.model.core.Model`, ``analysis`` the validated table (a dict with
        defaults filled in, including ``type``), ``case`` the :class:`fretwear.case.Case`
        (title, output options, ``resume``), ``outdir`` the results folder (a
        :class:`~pathlib.Path` that exists) and ``progress`` whether to show progress bars.
        Bad input found while running raises :class:`~fretwear.errors.InputError`.
    doc : paragraph for ``docs/case-files.md`` (when ``schema`` is a dict).
    checks : rules across keys (when ``schema`` is a dict), e.g.
        ``fretwear.schema.increasing("f_min", "f_max", "Hz")``.
    """
    table = schema if isinstance(schema, Table) else Table(dict(schema), tuple(checks), doc)
    if "type" in table.fields:
        raise ValueError(f"analysis {name!r}: 'type' is added by the registry, not the schema")
    old = _REGISTRY.get(name)
    if old is not None and old.run is not run:
        raise ValueError(f"analysis {name!r} is already registered by {old.run.__module__}")
    _REGISTRY[name] = Analysis(name, table, run)


def _load() -> None:
    global _loaded
    if not _loaded:
        _loaded = True
        for module in ANALYSIS_MODULES:
            importlib.import_module(module)


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


# --- running a case ---------------------------------------------------------------------
class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C during a run; ``message`` says what was saved."""

    def __init__(self, message: str):
        super().__init__(message)
        self.message = message


def _up_to_date(results: Path, case) -> bool:
    """True when ``results`` holds a converged run of exactly this case file text."""
    from fretwear.results import read_results

    if not results.is_file():
        return False
    try:
        attrs = read_results(results).attrs
    except InputError:
        return False
    return attrs.get("case_file") == case.text and int(attrs.get("converged", 0)) == 1


def _saved_since(outdir: Path, start: float) -> list[Path]:
    if not outdir.is_dir():
        return []
    return sorted(p for p in outdir.rglob("*")
                  if p.is_file() and not p.name.startswith(".") and p.stat().st_mtime >= start)


def _interrupted_message(outdir: Path, start: float) -> str:
    saved = _saved_since(outdir, start)
    if not saved:
        return "interrupted: nothing was saved"
    names = ", ".join(str(p.relative_to(outdir)) for p in saved[:6])
    more = f" and {len(saved) - 6} more" if len(saved) > 6 else ""
    return (f"interrupted: saved in {outdir}: {names}{more} (no {RESULTS_FILE} unless listed; "
            "run again with --resume to continue where it can)")


def run_case(path: Path | str, outdir: Path | str | None = None, progress: bool = True,
             resume: bool = False, echo: bool = True) -> RunOutput:
    """Load, validate, build, run and save a case file.

    Parameters
    ----------
    path : the ``.toml`` case file.
    outdir : results folder; default from ``[output] directory`` (see
        :meth:`fretwear.case.Case.output_dir`).
    progress : show progress bars (stderr).
    resume : skip the run when ``outdir/results.nc`` already holds a converged run of the
        same case text; analyses that checkpoint continue from their checkpoint
        (``case.resume``).
    echo : print the summary (stdout).

    Returns
    -------
    RunOutput, with ``results`` the NetCDF file written.

    Raises
    ------
    InputError, ConvergenceError
        With a message for the user.
    RunInterrupted
        On Ctrl-C, with a message saying what was saved.
    """
    from fretwear.case import build_model, load_case, observed_notes
    from fretwear.results import read_results, write_results

    case = load_case(path)
    case.resume = resume
    analysis = get(case.analysis["type"])
    out_dir = case.output_dir(outdir)
    results_path = out_dir / RESULTS_FILE
    say = print if echo else (lambda *a, **k: None)
    say(f"fretwear {__version__}: {case.title} ({case.path.name}, analysis {analysis.name})")
    if resume and _up_to_date(results_path, case):
        ds = read_results(results_path)
        say(f"results are up to date: {results_path}")
        return RunOutput(ds, summary="up to date", results=results_path)
    start = time.time()
    try:
        model = build_model(case)
        for note in observed_notes(case, model):
            say(note)
        out_dir.mkdir(parents=True, exist_ok=True)
        out = analysis.run(model, case.analysis, case, out_dir, progress)
        out.results = write_results(
            results_path, out.dataset, title=case.title, analysis_type=analysis.name,
            converged=out.converged, case_text=case.text, case_path=str(case.path),
            analysis=case.analysis,
        )
    except KeyboardInterrupt:
        raise RunInterrupted(_interrupted_message(out_dir, start)) from None
    if out.summary:
        say(out.summary)
    if not out.converged:
        say("warning: some solves did not converge (results.nc has converged = 0)")
    say(f"results: {out.results}  ({time.time() - start:.1f} s)")
    for p in out.figures:
        say(f"figure:  {p}")
    for p in out.files:
        say(f"file:    {p}")
    return out
