"""A model built in Python run through the case files' run and results path
(:func:`fretwear.run`), and results obtained in Python written as the case files write them
(:func:`fretwear.write_results`, :func:`fretwear.plot`).

:func:`run` takes the ``[analysis]`` and ``[output]`` keys of a case file
(``docs/case-files.md``) as keywords, validates them with the same schema (the same one-line
messages, naming ``analysis.KEY``), and runs them with
:func:`fretwear.analyses.run.run_built`, the function ``fretwear run`` ends in: the same
``results.nc``, figures and ParaView files as the case file with the same model. The results
file's ``case_file`` attribute holds the ``[analysis]`` and ``[output]`` tables it ran, as
TOML, under a comment saying that the model was built in Python.

:func:`write_results` and :func:`plot` take a result of :func:`fretwear.sweep`,
:func:`fretwear.solve_periodic`, :func:`fretwear.simulate_wear` or :func:`fretwear.integrate`
with the model and basis it was computed with, and write what the analysis of that kind writes:
the results dataset (``docs/results.md``) through :func:`fretwear.io.results.write_results`, and
its figures.
"""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import tomli_w

from fretwear.analyses.base import RunContext, RunOutput
from fretwear.analyses.registry import analysis_tables
from fretwear.analyses.run import RESULTS_FILE, check_output, run_built
from fretwear.errors import InputError
from fretwear.io.case import OUTPUT, Case
from fretwear.io.results import output_mesh
from fretwear.io.schema import Context, Variant, show
from fretwear.model.checks import model_argument
from fretwear.threads import limited
from fretwear.validate import flag, is_real
from fretwear.validate import path as file_path

#: the file name a Python run stands for in messages and in ``case_path``
PYTHON_CASE = "python-model.toml"
#: harmonics of the last period reported for a time integration (``basis`` None)
TRANSIENT_HARMONICS = 5


def _plain(value):
    """``value`` as TOML can hold it (numpy scalars and arrays as numbers and lists)."""
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, Path):
        return str(value)
    return value


def python_case(analysis, keys: dict, output: Path, title: str = "") -> Case:
    """The :class:`~fretwear.io.case.Case` of a Python run: the ``[analysis]`` table (``analysis``
    a type name with its ``keys``, or a dict with ``type``) and the ``[output]`` keys among
    ``keys`` (``figures``, ``figure_format``, ``vtu``), validated as a case file's."""
    tables = analysis_tables()
    if isinstance(analysis, dict):
        table = dict(analysis)
        if "type" not in table:
            raise InputError(f"analysis = {show(analysis)}: expected a type name (e.g. "
                             "'sweep') or a dict with 'type'")
    elif isinstance(analysis, str):
        table = {"type": analysis}
    else:
        raise InputError(f"analysis = {show(analysis)}: expected an analysis type name ("
                         f"{', '.join(tables)}) or a dict of [analysis] keys with 'type'")
    out_keys = {k: keys.pop(k) for k in list(keys) if k in OUTPUT.fields and k != "directory"}
    table.update(keys)
    raw = {"analysis": _plain(table), "output": _plain(out_keys)}
    if title:
        raw = {"title": str(title), **raw}
    ctx = Context(Path.cwd())
    checked = Variant(dict(tables), key_doc="analysis type").check(raw["analysis"], "analysis",
                                                                   ctx)
    out = OUTPUT.check(raw["output"], "output", ctx)
    text = ("# a model built in Python, run with fretwear.run(): the tables it ran\n"
            + tomli_w.dumps(raw))
    return Case(path=output / PYTHON_CASE, title=str(title) or "model built in Python",
                text=text, raw=raw, model={}, analysis=checked, output=out)


@model_argument
@limited
def run(model, analysis, output, *, title: str = "", progress: bool = False,
        resume: bool = False, echo: bool = False, **keys) -> RunOutput:
    """Run ``model`` (built in Python) as a case file with this analysis would run: the same
    ``results.nc``, figures and ParaView files in ``output``.

    Parameters
    ----------
    model : a :class:`~fretwear.model.core.Model` (``fw.from_mesh``, ``fw.from_matrices``...).
    analysis : the analysis type (``"sweep"``, ``"periodic"``, ``"wear"``, ``"transient"``,
        ``"modes"``, ``"frf"``, ...), its keys given as ``keys``; or a dict holding the whole
        ``[analysis]`` table with its ``type``.
    output : the results folder (made if needed).
    title : the title of figures and of the results file.
    progress : progress bars (stderr).
    resume : as ``fretwear run --resume`` (continue from a checkpoint in ``output``).
    echo : print the summary as ``fretwear run`` does.
    **keys : the keys of the ``[analysis]`` table of ``docs/case-files.md`` (for a sweep:
        ``f_min``, ``f_max``, ``n_points``, ``harmonics``, ``n_samples``, ``eps``, ...) and
        of ``[output]`` (``figures``, ``figure_format``, ``vtu``), each checked as in a case
        file (an unknown or bad key is one InputError naming ``analysis.KEY``).

    Returns
    -------
    :class:`~fretwear.analyses.base.RunOutput`: ``success``, ``message``, ``dataset``,
    ``results`` (the ``results.nc`` written), ``figures``, ``files``.
    """
    out_dir = file_path(output, "output").expanduser().resolve()
    case = python_case(analysis, dict(keys), out_dir, title)
    return run_built(model, case, out_dir, RunContext(out_dir, resume=resume,
                                                      progress=progress), echo=echo)


# --- results obtained in Python ---------------------------------------------------------------
def _kind(result) -> str:
    from fretwear.hb.solution import PeriodicSolution
    from fretwear.hb.sweep_result import SweepResult
    from fretwear.timedomain.results import TransientResult
    from fretwear.wear import WearResult

    for kind, cls in (("sweep", SweepResult), ("periodic", PeriodicSolution),
                      ("wear", WearResult), ("transient", TransientResult)):
        if isinstance(result, cls):
            check_record(kind, result)
            return kind
    raise InputError(f"result = {type(result).__name__}: expected the result of fw.sweep, "
                     "fw.frf_worn, fw.solve_periodic, fw.simulate_wear or fw.integrate")


def _check_basis(basis) -> None:
    """``basis`` is None, a FourierBasis, or (for a time integration) a whole number of
    harmonics >= 1."""
    from fretwear.hb.fourier import FourierBasis

    if basis is None or isinstance(basis, FourierBasis):
        return
    if isinstance(basis, bool) or not isinstance(basis, int | np.integer) or not \
            1 <= basis <= 2**62:
        raise InputError(f"basis = {repr(basis)[:60]}; expected the FourierBasis of the "
                         "result (or, for a time integration, a number of harmonics >= 1)")


def check_record(kind: str, result) -> None:
    """Refuse a result record whose fields are not what fretwear writes in it (a record
    built or edited by hand): one InputError naming the field."""
    from fretwear.hb.solution import PeriodicSolution, non_finite
    from fretwear.hb.sweep_result import SweepPoint
    from fretwear.wear.history import WearHistory
    from fretwear.wear.options import STOP_REASONS

    def bad(field, expected):
        value = getattr(result, field)
        raise InputError(f"result.{field} = {repr(value)[:60]}; expected {expected}")

    if kind == "sweep":
        pts = result.points
        if not isinstance(pts, list) or not pts or not all(isinstance(p, SweepPoint)
                                                            for p in pts):
            bad("points", "a non-empty list of the sweep's points (SweepPoint)")
    elif kind == "periodic":
        why = non_finite(result)
        if why:
            raise InputError(f"result holds non-finite values in {why}: not a solution")
    elif kind == "wear":
        if not isinstance(result.history, WearHistory):
            bad("history", "the run's WearHistory")
        for field in ("initial", "final"):
            if getattr(result, field) is not None and not isinstance(getattr(result, field),
                                                                     PeriodicSolution):
                bad(field, "a PeriodicSolution or None")
        if not isinstance(result.success, bool | np.bool_):
            bad("success", "True or False")
        if not isinstance(result.message, str):
            bad("message", "a string")
        if result.stop_reason not in (*STOP_REASONS, ""):
            bad("stop_reason", f"one of {list(STOP_REASONS)}")
        if not (is_real(result.wall_time) and 0 <= result.wall_time <= 1e12):
            bad("wall_time", "a number of seconds >= 0")


def results_dataset(result, model, basis, points=None, frequency=None):
    """The results dataset (``docs/results.md``) of a result obtained in Python, as the
    analysis of its kind builds it: ``(kind, dataset)``. ``frequency`` [Hz]: a wear run's
    excitation frequency (default: that of its first balanced step)."""
    from fretwear.analyses.common import check_points

    kind = _kind(result)
    names = check_points(model, points)
    if kind == "sweep":
        from fretwear.analyses.sweep import sweep_dataset

        return kind, sweep_dataset(model, result, basis, names, [])
    if kind == "periodic":
        from fretwear.analyses.periodic import periodic_dataset

        return kind, periodic_dataset(model, result, names)
    if kind == "transient":
        from fretwear.analyses.transient import transient_dataset

        if result.t.size > 1.5 * result.steps_per_period:
            raise InputError(f"result: a time integration recording {result.t.size} samples; "
                             "its results report the last period: integrate with "
                             "record='last' (the default)")
        nh = basis if isinstance(basis, int) else TRANSIENT_HARMONICS
        return kind, transient_dataset(model, result, names, nh, 0)
    from fretwear.analyses.wear import wear_dataset

    if frequency is None:
        sol = result.initial or result.final
        frequency = sol.omega / (2.0 * math.pi) if sol is not None else 0.0
    return kind, wear_dataset(model, result, basis, frequency_hz=float(frequency))


@model_argument
def write_results(result, output, model, basis=None, *, title: str = "", points=None,
                  frequency=None) -> Path:
    """Write ``output/results.nc`` for a result obtained in Python, in the format of the
    case-file route (``docs/results.md``; read it back with :func:`fretwear.read_results`).

    Parameters
    ----------
    result : what :func:`fretwear.sweep` (or ``frf_worn``), :func:`fretwear.solve_periodic`,
        :func:`fretwear.simulate_wear` or :func:`fretwear.integrate` returned.
    output : the results folder (made if needed).
    model, basis : the model and Fourier basis the result was computed with (for a time
        integration, the number of harmonics of the last period to report, default 5).
    title : the title recorded in the file.
    points : observed points to report (default: every one of the model).
    frequency : a wear run's excitation frequency [Hz] (default: that of its first balanced
        step).

    Returns
    -------
    The path of the file written.
    """
    _check_basis(basis)
    from fretwear.io.results import write_results as write

    out_dir = file_path(output, "output").expanduser().resolve()
    check_output(out_dir, [RESULTS_FILE])
    kind, ds = results_dataset(result, model, basis, points, frequency)
    return write(out_dir / RESULTS_FILE, ds, title=title or "results obtained in Python",
                 analysis_type=kind, converged=bool(result.success),
                 case_text="# results obtained in Python (fretwear.write_results)\n",
                 case_path="", analysis={"type": kind})


@model_argument
def plot(result, output, model, basis=None, *, title: str = "", fmt: str = "png",
         vtu: bool = True) -> list[Path]:
    """The figures (and, for a model with a mesh and ``vtu``, the ParaView files) the analysis
    of ``result``'s kind writes, into ``output``, for a result obtained in Python.

    Parameters
    ----------
    result, output, model, basis, title : as :func:`write_results`.
    fmt : figure file format (``"png"``, ``"pdf"``, ``"svg"``).
    vtu : write ParaView ``.vtu``/``.pvd`` files where the model has a mesh (or, built from
        FE matrices, a node file).

    Returns
    -------
    The files written.
    """
    _check_basis(basis)
    flag(vtu, "vtu")
    out_dir = file_path(output, "output").expanduser().resolve()
    check_output(out_dir)
    kind, ds = results_dataset(result, model, basis)
    name = title or "results obtained in Python"
    case = SimpleNamespace(title=name, output={"figures": True, "figure_format": fmt,
                                               "vtu": vtu})
    files = []
    if kind == "sweep":
        from fretwear.analyses.sweep import sweep_figures

        files += sweep_figures(ds, case, out_dir)
    elif kind == "periodic":
        from fretwear.analyses.periodic import periodic_figures, write_period_fields

        files += periodic_figures(ds, case, out_dir, name)
        if vtu and output_mesh(model) is not None:
            files.append(write_period_fields(model, result, out_dir / "periodic.pvd"))
    elif kind == "transient":
        from fretwear.analyses.transient import transient_figures

        files += transient_figures(ds, case, out_dir, name)
    else:
        from fretwear.analyses.wear import wear_figures, write_wear_fields

        files += wear_figures(ds, case, out_dir, [])
        if vtu and output_mesh(model) is not None:
            files.append(write_wear_fields(model, ds, out_dir / "wear.pvd"))
    return files
