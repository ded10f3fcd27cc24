"""Running a case file from end to end: load and validate it against the registered analyses,
build the model, run the analysis, write ``results.nc`` (:mod:`fretwear.io.results`) and print
a short summary.

An analysis is run with the validated case (:class:`~fretwear.io.case.Case`, what the file
says) and a :class:`~fretwear.analyses.base.RunContext` (how it is run: the results folder,
``--resume``, progress bars). Long analyses (sweep, wear) that want ``--resume`` save their
state in the results folder with :func:`fretwear.files.atomic_write` as they go, and read it
back when ``context.resume`` is true; on Ctrl-C, :func:`run_case` reports the files saved
during the run. Before a run, a folder standing where a file will be written is refused, and
the temporary files of writes killed mid-way (:func:`fretwear.files.remove_stale_temporaries`)
are removed.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from fretwear import __version__
from fretwear.analyses.base import RunContext, RunOutput
from fretwear.analyses.common import (
    OPEN_ATTRIBUTE,
    WARNINGS_ATTRIBUTE,
    check_sector_analysis,
    mistuning_attributes,
    preload_notes,
)
from fretwear.analyses.registry import analysis_tables, get
from fretwear.errors import InputError, interrupted
from fretwear.files import remove_stale_temporaries
from fretwear.io import case as case_files
from fretwear.io.case import Case, build_model, ignored_notes, observed_notes, unusual_notes
from fretwear.io.results import read_results, write_results
from fretwear.threads import limited
from fretwear.validate import path as file_path

RESULTS_FILE = "results.nc"


def load_case(path: Path | str) -> Case:
    """Read and validate a case file against the registered analyses
    (:func:`fretwear.io.case.load_case`); every mistake is one InputError naming the key.

    Returns
    -------
    :class:`fretwear.io.case.Case`: the validated tables with every default filled in
    (``case.analysis``, ``case.output``, ...), the case text and its path; SI units
    (frequencies in Hz) as in ``docs/case-files.md``.
    """
    return case_files.load_case(file_path(path, "path"), analysis_tables())


def case_docs() -> str:
    """The Markdown of ``docs/case-files.md`` (every key of every registered analysis)."""
    return case_files.case_docs(analysis_tables())


def write_case_docs(path: Path | str | None = None) -> Path:
    """Write :func:`case_docs` to ``path`` (default: ``docs/case-files.md`` of the source tree)."""
    return case_files.write_case_docs(analysis_tables(), path)


# --- running a case ---------------------------------------------------------------------
class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C during a run; ``message`` says what was saved."""

    def __init__(self, message: str):
        super().__init__(message)
        self.message = message


def _up_to_date(results: Path, case) -> bool:
    """True when ``results`` holds a converged run of exactly this case file text."""
    if not results.is_file():
        return False
    try:
        attrs = read_results(results).attrs
    except InputError:
        return False
    return attrs.get("case_file") == case.text and int(attrs.get("converged", 0)) == 1


def check_output(out_dir: Path, names=()) -> bool:
    """Refuse, before anything runs, an output folder that cannot be written (a file, a path
    under a file, no permission, a name too long for the file system) and a folder where a
    file will be written (the run would fail at its first save). Makes the folder and proves
    it writable with a probe file; returns whether the folder was made here."""
    where = "choose another folder with -o DIR (or [output] directory)"
    try:
        if out_dir.exists() and not out_dir.is_dir():
            raise InputError(f"the output folder {str(out_dir)!r} is a file: {where}")
        made = not out_dir.exists()
        out_dir.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=out_dir):
            pass
    except InputError:
        raise
    except OSError as exc:
        why = exc.strerror or type(exc).__name__
        if isinstance(exc, FileExistsError | NotADirectoryError):
            why = "a part of the path is a file, not a folder"
        raise InputError(f"cannot write in the output folder {str(out_dir)!r} ({why}): "
                         f"{where}") from None
    for name in names:
        p = out_dir / name
        if p.exists() and not p.is_file():
            what = "a folder, not a file" if p.is_dir() else "not a regular file"
            raise InputError(f"{str(p)!r} is {what}: move or delete it (the run writes its "
                             f"{'results' if name == RESULTS_FILE else 'state'} there)")
    return made


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


@limited
def run_case(path: Path | str, outdir: Path | str | None = None, progress: bool = True,
             resume: bool = False, echo: bool = True) -> RunOutput:
    """Load, validate, build, run and save a case file.

    Parameters
    ----------
    path : the ``.toml`` case file.
    outdir : results folder; default from ``[output] directory`` (see
        :meth:`fretwear.io.case.Case.output_dir`).
    progress : show progress bars (stderr).
    resume : skip the run when ``outdir/results.nc`` already holds a converged run of the
        same case text; analyses that checkpoint continue from their checkpoint
        (:attr:`RunContext.resume <fretwear.analyses.base.RunContext.resume>`).
    echo : print the summary (stdout).

    Returns
    -------
    :class:`~fretwear.analyses.base.RunOutput`: ``success`` (False when some solve did not
    converge; the file's ``converged`` attribute), ``message`` (the summary printed),
    ``dataset``, ``figures``, ``files`` and ``results`` (the NetCDF file written).

    Raises
    ------
    InputError, ConvergenceError
        With a message for the user.
    RunInterrupted
        On Ctrl-C (or SIGTERM through the command line), with a message saying what was
        saved.
    """
    case = load_case(path)
    return run_built(None, case, case.output_dir(outdir),
                     RunContext(Path("."), resume=bool(resume), progress=bool(progress)),
                     echo=echo)


def run_built(model, case, out_dir: Path, how: RunContext, echo: bool = True) -> RunOutput:
    """The run of :func:`run_case` from the validated ``case`` on: build the model (unless
    ``model`` is given: a model built in Python, :func:`fretwear.run`), run the analysis into
    ``out_dir``, write ``results.nc`` and print the summary. ``how``: ``resume`` and
    ``progress`` (its ``out_dir`` is replaced by ``out_dir``)."""
    analysis = get(case.analysis["type"])
    results_path = out_dir / RESULTS_FILE
    made = check_output(out_dir, [RESULTS_FILE, *analysis.files])
    say = print if echo else (lambda *a, **k: None)
    say(f"fretwear {__version__}: {case.title} ({case.path.name}, analysis {analysis.name})")
    for p in remove_stale_temporaries(out_dir):
        say(f"removed {p.name}: temporary file of a write that was killed")
    if how.resume and _up_to_date(results_path, case):
        ds = read_results(results_path)
        say(f"results are up to date: {results_path}")
        return RunOutput(ds, summary="up to date", results=results_path)
    start = time.time()
    try:
        built = model is None
        if built:
            model = build_model(case)
        check_sector_analysis(model, analysis.name, case.analysis)
        for note in (*unusual_notes(case), *(observed_notes(case, model) if built else ())):
            say(note)
        open_names = None
        if analysis.preload_check:
            notes, open_names = preload_notes(model)
            for note in notes:
                say(note)
        context = RunContext(out_dir, resume=bool(how.resume), progress=bool(how.progress))
        out = analysis.run(model, case.analysis, case, context)
        if open_names is not None:
            out.dataset.attrs[OPEN_ATTRIBUTE] = ", ".join(open_names)
        out.dataset.attrs[WARNINGS_ATTRIBUTE] = "\n".join(out.warnings)
        out.dataset.attrs.update(mistuning_attributes(model))
        out.results = write_results(
            results_path, out.dataset, title=case.title, analysis_type=analysis.name,
            converged=out.success, case_text=case.text, case_path=str(case.path),
            analysis=case.analysis,
        )
    except (KeyboardInterrupt, SystemError) as exc:
        if not interrupted(exc):
            raise
        raise RunInterrupted(_interrupted_message(out_dir, start)) from None
    except Exception:
        if made and not any(out_dir.iterdir()):  # nothing was written: leave no empty folder
            out_dir.rmdir()
        raise
    if out.summary:
        say(out.summary)
    for w in out.warnings:
        say(f"warning: {w}")
    if isinstance(getattr(case, "raw", None), dict) and case.raw.get("analysis"):
        for note in ignored_notes(case, analysis_tables()):  # keys the analysis never read
            say(note)
    if not out.success:
        say("warning: some solves did not converge (results.nc has converged = 0)")
    say(f"results: {out.results}  ({time.time() - start:.1f} s)")
    for p in out.figures:
        say(f"figure:  {p}")
    for p in out.files:
        say(f"file:    {p}")
    return out
