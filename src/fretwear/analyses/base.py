"""What an analysis is: its definition (:class:`Analysis`: a name, the schema of its
``[analysis]`` table and a run function), what a run is given besides the case
(:class:`RunContext`: the results folder, ``--resume``, progress bars) and what it returns
(:class:`RunOutput`).

An analysis module defines its analysis as a module constant::

    from fretwear.analyses.base import Analysis, RunContext, RunOutput
    from fretwear.io.schema import Field, Integer

    def run_periodic(model, analysis: dict, case, context: RunContext) -> RunOutput:
        ...                         # compute, write figures into context.out_dir
        return RunOutput(dataset, figures, summary, success)

    PERIODIC = Analysis.define(
        "periodic", {"n_harmonics": Field(Integer(lo=1), "kept harmonics", default=7)},
        run_periodic, doc="One paragraph for docs/case-files.md.")

and :mod:`fretwear.analyses.registry` imports it by name.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from fretwear.io.schema import Table

if TYPE_CHECKING:
    import xarray as xr


@dataclass(frozen=True)
class RunContext:
    """How a case file is run, as opposed to what it asks for (the
    :class:`~fretwear.io.case.Case`, which stays what was read from the file).

    Attributes
    ----------
    out_dir : the results folder (a :class:`~pathlib.Path` that exists); figures,
        checkpoints and ParaView files go there.
    resume : continue from the checkpoint the analysis keeps in ``out_dir``, if any
        (``fretwear run --resume``).
    progress : show progress bars (stderr).
    """

    out_dir: Path
    resume: bool = False
    progress: bool = False


@dataclass
class RunOutput:
    """What an analysis returns.

    Attributes
    ----------
    dataset : the results (``docs/results.md``: every variable with ``units`` and
        ``long_name``, no complex values); :func:`~fretwear.analyses.run.run_case` adds the
        global attributes.
    figures : figure files written (in ``out_dir``).
    summary : a few lines for the terminal (also ``message``).
    success : False if some solve did not converge (the results file records it as its
        ``converged`` attribute).
    files : other files written (e.g. ParaView ``.vtu``/``.pvd``).
    results : the results file, set by :func:`~fretwear.analyses.run.run_case`.
    warnings : reasons for caution about the whole run, one line each (e.g. the static preload
        solve that gives the stick anchors did not converge);
        :func:`~fretwear.analyses.run.run_case` prints them and records them in the
        ``warnings`` attribute of the results.
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


#: ``run(model, analysis, case, context) -> RunOutput`` (see :class:`Analysis`)
RunFunction = Callable[..., RunOutput]


@dataclass(frozen=True)
class Analysis:
    """An analysis that case files select with ``[analysis] type = name``.

    Attributes
    ----------
    name : the ``type`` value.
    schema : the :class:`~fretwear.io.schema.Table` of the ``[analysis]`` keys (without
        ``type``, which the case file adds); its ``doc`` is the paragraph of
        ``docs/case-files.md``.
    run : ``run(model, analysis, case, context) -> RunOutput`` with ``model`` the
        :class:`~fretwear.model.core.Model`, ``analysis`` the validated table (a dict with
        defaults filled in, including ``type``), ``case`` the
        :class:`~fretwear.io.case.Case` (title, output options) and ``context`` the
        :class:`RunContext` (results folder, resume, progress). Bad input found while
        running raises :class:`~fretwear.errors.InputError`.
    files : names of the files the analysis writes in the results folder as it goes
        (checkpoints); :func:`fretwear.analyses.run.run_case` refuses a folder in their place
        before anything runs.
    preload_check : the analysis runs the contact law (vibration, wear):
        :func:`fretwear.analyses.run.run_case` first solves the static contact under the
        preload and warns about an interface that no node of touches
        (:func:`fretwear.hb.preload.preload_contact`).
    """

    name: str
    schema: Table
    run: RunFunction
    files: tuple[str, ...] = ()
    preload_check: bool = False

    def __post_init__(self):
        if "type" in self.schema.fields:
            raise ValueError(f"analysis {self.name!r}: 'type' is added by the registry, not "
                             "the schema")

    @classmethod
    def define(cls, name: str, schema: Table | Mapping, run: RunFunction, *, doc: str = "",
               checks: tuple = (), files: tuple[str, ...] = (),
               preload_check: bool = False) -> Analysis:
        """The analysis ``name`` with the ``[analysis]`` keys ``schema``: a
        :class:`~fretwear.io.schema.Table`, or a dict ``key -> Field`` (without ``type``)
        completed by ``checks`` (rules across keys, e.g.
        ``fretwear.io.schema.increasing("f_min", "f_max", "Hz")``) and ``doc`` (the paragraph
        of ``docs/case-files.md``). ``run``, ``files``, ``preload_check``: as the attributes.
        """
        table = schema if isinstance(schema, Table) else Table(dict(schema), tuple(checks), doc)
        return cls(name, table, run, tuple(files), bool(preload_check))
