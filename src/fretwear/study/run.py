"""A study from end to end: read the study file, expand its members, run them on Dask,
write ``study.nc`` and the figures (``fretwear study STUDY.toml`` and
:func:`fretwear.run_study`)."""

from __future__ import annotations

import textwrap
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fretwear import __version__
from fretwear.analyses.run import check_output
from fretwear.errors import InputError, interrupted
from fretwear.files import atomic_write, remove_stale_temporaries
from fretwear.study.aggregate import aggregate
from fretwear.study.figures import LEVEL_KEY, study_figures
from fretwear.study.members import expand
from fretwear.study.mistuning import summary_line
from fretwear.study.runner import (
    check_scheduler,
    check_scheduler_address,
    check_workers,
    dask_client,
    run_members,
)
from fretwear.study.spec import Study, read_study
from fretwear.study.sweep_split import join_chunks
from fretwear.validate import path as file_path

STUDY_RESULTS = "study.nc"


@dataclass
class StudyResult:
    """What a study produced: ``success`` (every member ok and, for a split sweep, every
    join checked), ``message`` (the summary), ``dataset`` (``study.nc``), the member
    ``records``, the ``results`` file and the ``figures``."""

    success: bool
    message: str
    dataset: object
    records: list
    results: Path | None = None
    figures: list = field(default_factory=list)


class StudyInterrupted(KeyboardInterrupt):
    """Ctrl-C during a study; ``message`` says what was kept."""

    def __init__(self, message: str):
        super().__init__(message)
        self.message = message


def _write_dataset(path: Path, ds) -> Path:
    def write(tmp: Path) -> None:
        ds.to_netcdf(tmp, engine="h5netcdf")

    return atomic_write(path, write)


def _wrap(text: str, width: int = 100, limit: int = 12) -> str:
    """``text`` as lines of at most ``width`` characters indented by two, broken between
    words (never inside one), at most ``limit`` lines per paragraph (the rest said as
    "...")."""
    out = []
    for para in str(text).splitlines() or [""]:
        lines = textwrap.wrap(para, width - 4, break_long_words=False,
                              break_on_hyphens=False) or [""]
        if len(lines) > limit:
            lines = [*lines[: limit - 1], "..."]
        out += ["  " + lines[0], *("    " + x for x in lines[1:])]
    return "\n".join(out)


def _summary(study: Study, records, ds) -> tuple[bool, str]:
    n = len(records)
    count = {s: sum(r.status == s for r in records)
             for s in ("ok", "not converged", "failed", "not run")}
    skipped = sum(r.skipped for r in records)
    lines = [f"{study.kind} study of {n} members: {count['ok']} ok, "
             f"{count['not converged']} not converged, {count['failed']} failed"
             + (f", {count['not run']} not run" if count["not run"] else "")
             + (f" ({skipped} finished before)" if skipped else "")]
    for r in records:
        if r.status not in ("ok", "not run"):
            lines.append(_wrap(f"member {r.index}: {r.status}: {r.message}"))
    for r in records:
        for w in filter(None, r.warnings.splitlines()):
            lines.append(_wrap(f"member {r.index}: warning: {w}"))
    if "peak_frequency" in ds and LEVEL_KEY in ds.coords:
        for lv, a, f in sorted(zip(ds[LEVEL_KEY].values, ds["peak_response_amplitude"].values,
                                   ds["peak_frequency"].values, strict=True)):
            lines.append(f"  level {lv:.4g}: peak {a:.4g} m at {f:.6g} Hz"
                         + (f", {a / lv:.4g} m per unit level" if np.isfinite(a) else ""))
    if ds.attrs.get("common_grid"):
        lines.append(_wrap(ds.attrs["common_grid"]))
    ok = count["ok"] == n
    if study.kind == "split" and "join_ok" in ds:
        bad = [f"{f:.6g} Hz ({d:.2g})" for f, d, j in zip(
            ds["join_frequency"].values, ds["join_difference"].values, ds["join_ok"].values,
            strict=True) if not j]
        if bad:
            ok = False
            lines.append(f"  joins beyond join_rtol = {study.split['join_rtol']:g}: "
                         + ", ".join(bad))
        else:
            lines.append(f"  every join within join_rtol = {study.split['join_rtol']:g}")
    if "worn_volume_quantile" in ds:
        last = ds["members_reached"].values
        k = int(last.nonzero()[0][-1]) if last.any() else 0
        q = ds["worn_volume_quantile"].values[:, k]
        lines.append(f"  worn volume at N = {float(ds['cycle'].values[k]):.3g}: median "
                     f"{q[1]:.3g} m^3, 5-95 % [{q[0]:.3g}, {q[2]:.3g}] over "
                     f"{int(last[k])} members")
    amp = summary_line(ds)
    if amp:
        lines.append(amp)
    return ok, "\n".join(lines)


def run_study(path, outdir=None, *, scheduler=None, workers: int | None = None,
              progress: bool = True, echo: bool = True, collect: bool = False) -> StudyResult:
    """Run a study file on Dask distributed.

    Parameters
    ----------
    path : the study ``.toml`` file (docs/study.md), or a shipped study's name
        (``fretwear study --list``).
    outdir : results folder; default ``[output] directory`` of the study file, else
        ``<study name>-results`` beside it. Each member runs in ``outdir/member-XXXX/``.
    scheduler : a Dask scheduler address (``tcp://host:8786``: an existing cluster), a
        ``distributed.Client`` (e.g. of a dask-jobqueue cluster), or None: the study file's
        ``scheduler``, else a LocalCluster on this machine.
    workers : worker processes of the LocalCluster (default: the study file's ``workers``,
        else the number of cores).
    progress : a progress bar over members, with the time left (stderr).
    echo : print the summary (stdout).
    collect : run nothing: write ``study.nc`` and the figures of the members finished so
        far, the others recorded as "not run" (e.g. while the study runs on a cluster).

    Returns
    -------
    StudyResult
        ``dataset`` is ``study.nc`` (``member`` dimension, varied keys as coordinates,
        statistics on a common cycle grid for wear, the band of FRFs for sweeps).

    Raises
    ------
    InputError
        A bad study file or member case (one line naming the study file and the key), an
        output folder that cannot be written, a scheduler that cannot be reached.
    StudyInterrupted
        On Ctrl-C: finished members are kept; run again to do the rest.
    """
    check_scheduler(scheduler)
    check_workers(workers)
    study = read_study(resolve_study(path))
    members = expand(study)
    address = scheduler if scheduler is not None else study.scheduler
    if isinstance(address, str) and not collect:
        check_scheduler_address(address)  # before anything is written
    out_dir = study.output_dir(outdir)
    check_output(out_dir)
    say = print if echo else (lambda *a, **k: None)
    say(f"fretwear {__version__}: study {study.title} ({study.path.name}, {len(members)} "
        f"members, base {study.base.name}) -> {out_dir}")
    for p in remove_stale_temporaries(out_dir):
        say(f"removed {p.name}: temporary file of a write that was killed")
    try:
        if collect:
            report = run_members(members, out_dir, None)
        else:
            with dask_client(scheduler if scheduler is not None else study.scheduler,
                             workers if workers is not None else study.workers) as client:
                report = run_members(members, out_dir, client, progress=progress)
    except (KeyboardInterrupt, SystemError) as exc:
        if not interrupted(exc):
            raise
        done = sum(1 for m in members if (out_dir / m.folder_name / "status.json").is_file())
        raise StudyInterrupted(f"interrupted: {done} of {len(members)} members have a status "
                               f"in {out_dir}; run the study again to do the rest") from None
    records = report.records
    if study.kind == "split":
        ds = join_chunks(study, members, records, out_dir)
    else:
        ds = aggregate(study, members, records, out_dir)
    results = _write_dataset(out_dir / STUDY_RESULTS, ds)
    figures = []
    if study.output["figures"] and any(r.status == "ok" for r in records):
        figures = study_figures(ds, out_dir, list(dict.fromkeys(
            k for m in members for k in m.values)))
    ok, message = _summary(study, records, ds)
    if study.output["figures"] and not figures and any(r.status == "ok" for r in records):
        message += ("\nfigures: none for the study (its members' results hold none of the "
                    "variables a study figure draws, or not with the same shape in every "
                    "member); each member's own figures are in its folder")
    say(message)
    say(f"results: {results}  ({report.seconds:.1f} s)")
    for p in figures:
        say(f"figure:  {p}")
    return StudyResult(ok, message, ds, records, results, figures)


# --- shipped studies ------------------------------------------------------------------------
def shipped_studies() -> dict[str, Path]:
    """The study files shipped with fretwear: name (file stem) -> path."""
    from importlib import resources

    folder = Path(str(resources.files("fretwear") / "examples" / "studies"))
    return {p.stem: p for p in sorted(folder.glob("*.toml"))}


def resolve_study(path) -> Path:
    """``path`` itself when it is a file, else the shipped study of that name."""
    file_path(path, "path")
    p = Path(path).expanduser()
    if p.is_file() or p.suffix == ".toml" or "/" in str(path):
        if not p.is_file():
            raise InputError(f"study file {str(p)!r} does not exist")
        return p
    found = shipped_studies()
    if str(path) in found:
        return found[str(path)]
    raise InputError(f"no study file {str(path)!r} and no shipped study of that name; "
                     f"expected a .toml file or one of: {', '.join(found)}")
