"""Reproduce the examples of Salles et al. (2011), figure by figure.

``fretwear reproduce`` (or ``fretwear example run salles2011 --all``) runs every shipped
example of the paper (:data:`RUNS`, ordinary case files with a few documented edits), two
computations that are not case files (load stepping for Fig. 5, the FRF before and after
wear for Fig. 24), draws one figure per group of the paper's figures and writes a Markdown
report: for each figure and for Table 1, what the paper states and what fretwear computes,
side by side, with the cause of every difference (:mod:`fretwear.paper.report`).

Every run keeps its results in ``WORKDIR/<key>/`` (``results.nc``, the run's own figures and,
for wear runs, a checkpoint), so the command is resumable: run it again after an interruption
and the finished runs are read back, the interrupted wear runs continue from their checkpoint.
A run that fails or does not converge is reported as such in the report, never compared as a
result. ``quick = True`` cuts the numerics (fewer harmonics, shorter bands and runs) to check
the machinery in a minute; its numbers are not the reproduction.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fretwear import api
from fretwear.analyses.run import RunInterrupted, load_case, run_case
from fretwear.errors import FretwearError, InputError
from fretwear.examples.builders import stromberg_beam
from fretwear.files import atomic_write
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.reduce import exact_condenser
from fretwear.io.case import build_model
from fretwear.paper.catalogue import (
    EXTRA_KEYS,
    FRF_WORN_BAND,
    RUN_KEYS,
    RUNS,
    STROMBERG_CYCLES,
    STROMBERG_JUMP,
    Run,
    edit_case_text,
    run_case_text,
    toml_value,
)
from fretwear.paper.report import load, write_report
from fretwear.timedomain.options import IncrementalWearOptions
from fretwear.timedomain.quasistatic import incremental_wear
from fretwear.wear.worn_frf import WORN_FRF


# --- running ----------------------------------------------------------------------------------
@dataclass
class Outcome:
    """What happened to one run: ``status`` is "done", "up to date", "not converged" or
    "failed"; ``message`` says why; ``seconds`` of wall time in this call."""

    key: str
    status: str
    message: str = ""
    seconds: float = 0.0


def _save_npz(path: Path, **arrays) -> None:
    """Write ``path`` (``.npz``) complete or not at all
    (:func:`fretwear.io.results.atomic_write`)."""

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)

    atomic_write(path, write)


def _settings_match(path: Path, settings: str) -> bool:
    if not path.is_file():
        return False
    with np.load(path) as z:
        return str(z["settings"]) == settings


def run_one(key: str, workdir: Path | str, quick: bool = False,
            progress: bool = False) -> Outcome:
    """Run the case file of run ``key`` (or the extra computation ``key``) into
    ``workdir/key``; an up-to-date result is kept. Never raises for a failed solve: the
    outcome says what happened."""

    workdir = Path(workdir)
    folder = workdir / key
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    try:
        if key == "stromberg-load-stepping":
            status = _load_stepping(folder, quick)
        elif key == "frf-worn-79khz":
            status = _frf_worn(folder, workdir / "wear-79khz", quick)
        else:
            run = next(r for r in RUNS if r.key == key)
            path = folder / "case.toml"
            text = run_case_text(run, quick)
            if not path.is_file() or path.read_text(encoding="utf-8") != text:
                path.write_text(text, encoding="utf-8")
            out = run_case(path, folder, progress=progress, resume=True, echo=False)
            status = ("up to date" if out.summary == "up to date"
                      else "done" if out.success else "not converged")
    except FretwearError as exc:
        return Outcome(key, "failed", " ".join(str(exc).split()), time.perf_counter() - t0)
    return Outcome(key, status, "", time.perf_counter() - t0)


def _load_stepping(folder: Path, quick: bool) -> str:
    """Stromberg's kind of method on the section 4.1 beam: load stepping with exact contact,
    incremental Coulomb friction and Archard after every step (fretwear.timedomain.integrate)."""

    cycles = 200 if quick else STROMBERG_CYCLES
    steps = 32 if quick else 64
    settings = f"cycles={cycles} steps={steps} jump={STROMBERG_JUMP}"
    path = folder / "load-stepping.npz"
    if _settings_match(path, settings):
        return "up to date"
    model = stromberg_beam()
    res = incremental_wear(model, n_cycles=cycles,
                           options=IncrementalWearOptions(steps_per_cycle=steps,
                                                          cycle_jump=STROMBERG_JUMP))
    x = np.asarray(model.contact.coords, float)[:, 0]
    _save_npz(path, settings=settings, x=x, wear=np.asarray(res.wear)[-1],
              cycles=float(cycles), steps=steps, jump=STROMBERG_JUMP)
    return "done"


def _frf_worn(folder: Path, wear_dir: Path, quick: bool) -> str:
    """The nonlinear FRF of the paper's beam before and after the 79 kHz wear (Fig. 24)."""

    ds = load(wear_dir.parent, wear_dir.name)
    if ds is None:
        raise InputError(f"{wear_dir / 'results.nc'}: no converged result of the 79 kHz wear "
                         "run (missing, unreadable or not converged): no worn interface to use")
    wear = ds["wear_depth"].values[-1]
    f_min, f_max, n = (7e4, 9e4, 5) if quick else FRF_WORN_BAND
    h, s = (1, 16) if quick else (7, 128)
    settings = (f"band={f_min},{f_max},{n} h={h} s={s} time_domain=1 "
                f"wear={float(np.sum(wear)):.12e} cycles={float(ds['cycles'].values[-1]):.6e}")
    path = folder / "frf-worn.npz"
    if _settings_match(path, settings):
        return "up to date"
    model = build_model(load_case(wear_dir / "case.toml"))
    basis = FourierBasis.up_to(h, s)
    cond = exact_condenser(model)  # one condensation of the beam for both FRFs
    out = {}
    for name, w in (("unworn", np.zeros_like(wear)), ("worn", wear)):
        r = api.frf_worn(model, basis, w, f_min, f_max, n, options=WORN_FRF,
                         time_domain=True, condenser=cond)
        out[f"{name}_summary"] = r.summary()
        out[f"{name}_frequency"] = r.frequency_hz
        out[f"{name}_amplitude"] = r.amplitude("Pe", 0, 1)
        out[f"{name}_converged"] = r.point_success
    _save_npz(path, settings=settings, wear=wear, **out)
    bad = sum(int((~out[f"{k}_converged"]).sum()) for k in ("unworn", "worn"))
    return "done" if bad == 0 else "not converged"


def plan(only: Iterable[str] | None = None) -> list[str]:
    """The keys to run, in order (longest first, the extras after what they need)."""
    keys = list(RUN_KEYS) + list(EXTRA_KEYS)
    if only is None:
        return keys
    only = list(only)
    unknown = [k for k in only if k not in keys]
    if unknown:
        raise InputError(f"unknown reproduction run(s) {', '.join(unknown)}; expected some "
                         f"of: {', '.join(keys)}")
    return [k for k in keys if k in only]


def run_all(workdir: Path | str, *, quick: bool = False, jobs: int = 1,
            only: Iterable[str] | None = None, progress: bool = False,
            say: Callable[[str], None] = print) -> list[Outcome]:
    """Run every run of :func:`plan` into ``workdir``; ``jobs`` processes at a time.

    Ctrl-C stops the runs; what was finished (and the wear checkpoints) stays in
    ``workdir`` and the same call continues from there.
    """
    from concurrent.futures import ProcessPoolExecutor, as_completed
    from multiprocessing import get_context


    if jobs < 1:
        raise InputError(f"jobs = {jobs}: expected a number of processes >= 1")
    workdir = Path(workdir).expanduser().resolve()
    workdir.mkdir(parents=True, exist_ok=True)
    keys = plan(only)
    first = [k for k in keys if k != "frf-worn-79khz"]
    later = [k for k in keys if k == "frf-worn-79khz"]
    outcomes: list[Outcome] = []

    def note(o: Outcome) -> None:
        outcomes.append(o)
        say(f"{o.key:<24} {o.status:<14} {o.seconds:8.1f} s" + (f"  {o.message}"
                                                                 if o.message else ""))

    saved = f"finished runs and wear checkpoints are kept in {workdir}; run the same " \
            "command again to continue"
    try:
        if jobs == 1:
            for k in first + later:
                note(run_one(k, workdir, quick, progress))
        else:
            with ProcessPoolExecutor(jobs, mp_context=get_context("spawn")) as pool:
                futures = [pool.submit(run_one, k, workdir, quick) for k in first]
                for fut in as_completed(futures):
                    note(fut.result())
            for k in later:
                note(run_one(k, workdir, quick, progress))
    except KeyboardInterrupt:
        raise RunInterrupted(f"interrupted: {saved}") from None
    return outcomes


def reproduce(workdir: Path | str, doc: Path | str | None = None, *, quick: bool = False,
              jobs: int = 1, only: Iterable[str] | None = None, progress: bool = False,
              say: Callable[[str], None] = print) -> Path:
    """Run the reproduction into ``workdir`` and write the report ``doc`` (default
    ``workdir/reproduction.md``, figures in the folder ``<doc stem>/`` beside it).
    Returns the report's path."""

    workdir = Path(workdir).expanduser().resolve()
    t0 = time.perf_counter()
    outcomes = run_all(workdir, quick=quick, jobs=jobs, only=only, progress=progress, say=say)
    doc = workdir / "reproduction.md" if doc is None else Path(doc).expanduser().resolve()
    path = write_report(workdir, doc, outcomes, quick=quick,
                        wall=time.perf_counter() - t0, jobs=jobs)
    say(f"report: {path}")
    return path


__all__ = ["EXTRA_KEYS", "RUNS", "RUN_KEYS", "Outcome", "Run", "edit_case_text", "plan",
           "reproduce", "run_all", "run_case_text", "run_one", "toml_value"]
