"""The command line: ``fretwear run``, ``compare``, ``example``, ``reproduce``, ``study``,
``fretwear --version``.

Exit status: 0 success; 1 the run finished but some solve did not converge (the results file
says ``converged = 0``); 2 bad input or a failed solve (one line ``error: ...`` on stderr,
never a traceback); 130 interrupted by Ctrl-C, 143 terminated by SIGTERM (e.g. by a batch
scheduler at the end of a job's time; handled as Ctrl-C: a wear run saves its checkpoint, and a
line says what was saved).
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import signal
import sys
import threading
import warnings
from importlib import resources
from pathlib import Path

# The solves are many dense problems of ~1000 unknowns: threaded BLAS gains little there and
# oversubscribes small machines (a 10x slower LU was measured on a busy 2-core machine).
# Set before numpy loads; a user's own setting wins.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from fretwear import __version__  # noqa: E402 (after the BLAS thread setting)
from fretwear.errors import FretwearError, InputError, interrupted  # noqa: E402 (after the BLAS thread setting)
from fretwear.io.schema import suggest  # noqa: E402 (after the BLAS thread setting)


# --- examples -----------------------------------------------------------------------------
def examples() -> dict[str, Path]:
    """Shipped example case files: name (file stem) -> path, sorted by name."""
    folder = Path(str(resources.files("fretwear") / "examples"))
    return {p.stem: p for p in sorted(folder.glob("*.toml"))}


def example_path(name: str) -> Path:
    """The case file of example ``name``; an InputError lists the available ones."""
    found = examples()
    if name not in found:
        raise InputError(f"unknown example {name!r}; expected one of: {', '.join(found)}"
                         f"{suggest(name, found)}")
    return found[name]


def _example_title(path: Path) -> str:
    from fretwear.io.case import read_toml

    try:
        return str(read_toml(path)[1].get("title", ""))
    except InputError:
        return "(unreadable)"


# --- commands -----------------------------------------------------------------------------
def _run(case: Path, outdir, resume: bool, progress: bool) -> int:
    from fretwear.analyses.run import run_case

    out = run_case(case, outdir=outdir, progress=progress, resume=resume)
    return 0 if out.success else 1


def cmd_run(args) -> int:
    return _run(Path(args.case), args.output, args.resume, not args.no_progress)


def cmd_compare(args) -> int:
    from fretwear.analyses.compare import compare_case

    res = compare_case(Path(args.case), args.output, steps_per_period=args.steps)
    return 0 if res.dlft_converged else 1


def cmd_example_list(args) -> int:
    found = examples()
    width = max((len(n) for n in found), default=0)
    for name, path in found.items():
        print(f"{name:<{width}}  {_example_title(path)}")
    return 0


def cmd_example_show(args) -> int:
    sys.stdout.write(example_path(args.name).read_text(encoding="utf-8"))
    return 0


def cmd_example_run(args) -> int:
    if args.all:
        if args.name != "salles2011":
            raise InputError(f"--all runs the paper's set: expected `fretwear example run "
                             f"salles2011 --all`, not {args.name!r}")
        return _reproduce(args.output, None, False, 1, None, not args.no_progress)
    path = example_path(args.name)
    outdir = args.output if args.output is not None else Path.cwd() / f"{args.name}-results"
    return _run(path, outdir, args.resume, not args.no_progress)


def _reproduce(workdir, doc, quick: bool, jobs: int, only, progress: bool) -> int:
    from fretwear.paper.runs import reproduce

    workdir = workdir if workdir is not None else Path.cwd() / "salles2011-reproduction"
    reproduce(workdir, doc, quick=quick, jobs=jobs, only=only, progress=progress)
    return 0


def cmd_reproduce(args) -> int:
    only = [k.strip() for k in args.only.split(",") if k.strip()] if args.only else None
    return _reproduce(args.output, args.doc, args.quick, args.jobs, only,
                      not args.no_progress)


def cmd_study(args) -> int:
    from fretwear.study.run import run_study, shipped_studies

    if args.list:
        from fretwear.io.case import read_toml

        found = shipped_studies()
        width = max((len(n) for n in found), default=0)
        for name, path in found.items():
            print(f"{name:<{width}}  {read_toml(path)[1].get('title', '')}")
        return 0
    if args.study is None:
        raise InputError("fretwear study: expected a study file STUDY.toml (or --list)")
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers {args.workers}: expected a positive number of worker "
                         "processes")
    res = run_study(args.study, args.output, scheduler=args.scheduler, workers=args.workers,
                    progress=not args.no_progress, collect=args.collect)
    return 0 if res.success else 1


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="fretwear",
        description="Coupled vibration and fretting wear of frictional contact interfaces "
        "(DLFT with wear, Salles et al. 2011).",
    )
    p.add_argument("--version", action="version", version=f"fretwear {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    def run_options(q):
        q.add_argument("-o", "--output", metavar="DIR", type=Path, default=None,
                       help="results folder (default: [output] directory of the case)")
        q.add_argument("--resume", action="store_true",
                       help="skip a run whose results are complete; continue from a checkpoint")
        q.add_argument("--no-progress", action="store_true", help="no progress bars")

    r = sub.add_parser("run", help="run a case file", description="Run a TOML case file.")
    r.add_argument("case", metavar="CASE.toml", help="the case file")
    run_options(r)
    r.set_defaults(func=cmd_run)

    c = sub.add_parser("compare", help="DLFT against the time-domain reference on a case",
                       description="Run a periodic case (or a quasi-static wear case) with "
                       "the DLFT and with the time-domain reference; one figure and a table "
                       "of relative differences.")
    c.add_argument("case", metavar="CASE.toml", help="the case file")
    c.add_argument("-o", "--output", metavar="DIR", type=Path, default=None,
                   help="figure folder (default: CASE-compare next to the case)")
    c.add_argument("--steps", type=int, default=512, metavar="N",
                   help="time steps per period (wear: load steps per cycle; default 512)")
    c.set_defaults(func=cmd_compare)

    e = sub.add_parser("example", help="list, show or run the shipped examples",
                       description="The shipped examples are ordinary case files.")
    esub = e.add_subparsers(dest="action", required=True, metavar="ACTION")
    esub.add_parser("list", help="list the examples").set_defaults(func=cmd_example_list)
    s = esub.add_parser("show", help="print an example case file")
    s.add_argument("name")
    s.set_defaults(func=cmd_example_show)
    x = esub.add_parser("run", help="run an example (results in ./NAME-results or -o DIR)")
    x.add_argument("name")
    run_options(x)
    x.add_argument("--all", action="store_true",
                   help="with NAME = salles2011: every example of the paper and the "
                   "comparison report (as `fretwear reproduce`)")
    x.set_defaults(func=cmd_example_run)

    rp = sub.add_parser(
        "reproduce", help="run the paper's examples and write the comparison with the paper",
        description="Run every example of Salles et al. (2011) (resumable: finished runs "
        "are kept, wear runs continue from their checkpoint), draw one figure per group of "
        "the paper's figures and write a Markdown report: the paper's statement and "
        "fretwear's result side by side. The full set took 41 min of run time (summed "
        "over the runs) on 2 cores.")
    rp.add_argument("-o", "--output", metavar="DIR", type=Path, default=None,
                    help="work folder of the runs (default ./salles2011-reproduction)")
    rp.add_argument("--doc", metavar="FILE.md", type=Path, default=None,
                    help="the report (default DIR/reproduction.md; figures in a folder of "
                    "the same name beside it)")
    rp.add_argument("--jobs", type=int, default=1, metavar="N",
                    help="runs at a time (processes; default 1)")
    rp.add_argument("--only", metavar="KEYS", default=None,
                    help="comma-separated runs to do (default all; the report covers what "
                    "the work folder holds)")
    rp.add_argument("--quick", action="store_true",
                    help="reduced numerics to check the machinery in a minute or two (not "
                    "the reproduction)")
    rp.add_argument("--no-progress", action="store_true", help="no progress bars")
    rp.set_defaults(func=cmd_reproduce)

    st = sub.add_parser(
        "study", help="run a study (grid, samples, ensemble, split sweep) on Dask",
        description="Run the members of a study file (a base case file and what varies) on "
        "Dask distributed: a local cluster on this machine's cores, or an existing cluster "
        "with --scheduler. Each member writes its own results; a rerun skips the finished "
        "ones. Writes study.nc (a member dimension) and the study's figures (docs/study.md).")
    st.add_argument("study", metavar="STUDY.toml", nargs="?", default=None,
                    help="the study file, or the name of a shipped study")
    st.add_argument("-o", "--output", metavar="DIR", type=Path, default=None,
                    help="results folder (default: [output] directory of the study file, "
                    "else STUDY-results beside it)")
    st.add_argument("--scheduler", metavar="ADDRESS", default=None,
                    help="address of a running Dask scheduler (tcp://host:8786); default: a "
                    "local cluster")
    st.add_argument("--workers", metavar="N", type=int, default=None,
                    help="worker processes of the local cluster (default: the number of cores)")
    st.add_argument("--collect", action="store_true",
                    help="run nothing: write study.nc and the figures of the members finished "
                    "so far (e.g. while the study runs elsewhere)")
    st.add_argument("--list", action="store_true", help="list the shipped study files")
    st.add_argument("--no-progress", action="store_true", help="no progress bar")
    st.set_defaults(func=cmd_study)
    return p


class TerminateAsInterrupt:
    """Within ``with``: SIGTERM raises KeyboardInterrupt, as Ctrl-C does, so that a run
    stopped by ``kill`` or a batch scheduler saves what it can (a wear checkpoint) and says so.

    ``received`` is then True. Only the first SIGTERM interrupts: later ones are ignored, so
    that the save they would otherwise cut short completes. The previous handler is restored
    on exit. Outside the main thread (where Python allows no handler) it does nothing.
    """

    def __init__(self):
        self.received = False
        self._previous = None

    def _handle(self, signum, frame):
        if not self.received:
            self.received = True
            raise KeyboardInterrupt

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGTERM, self._handle)
        return self

    def __exit__(self, *exc):
        if self._previous is not None:
            signal.signal(signal.SIGTERM, self._previous)
            self._previous = None
        return False


class _SayHandler(logging.Handler):
    """The lines of the ``"fretwear"`` logger (fallbacks as they happen,
    :mod:`fretwear.hb.fallbacks`) printed as notes on stdout, above any progress bar."""

    def emit(self, record: logging.LogRecord) -> None:
        if record.name != "fretwear":  # not the modules' own loggers (fretwear.hb.sparse_lu)
            return
        from tqdm import tqdm

        tqdm.write(f"note: {record.getMessage()}", file=sys.stdout)


@contextlib.contextmanager
def _said_lines():
    """Print the ``"fretwear"`` logger's INFO lines while the command runs."""
    logger, handler = logging.getLogger("fretwear"), _SayHandler(logging.INFO)
    level = logger.level
    logger.addHandler(handler)
    logger.setLevel(logging.INFO)
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)


@contextlib.contextmanager
def _one_line_warnings():
    """Python warnings printed as one line each, ``warning: Category: message`` on stderr (not
    the file, line number and source line of Python's default format) while the command
    runs."""

    def show(message, category, filename, lineno, file=None, line=None):
        text = " ".join(str(message).split())
        print(f"warning: {category.__name__}: {text}", file=file or sys.stderr)

    with warnings.catch_warnings():
        warnings.showwarning = show
        yield


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``fretwear`` command; returns the exit status."""
    args = _parser().parse_args(argv)
    term = TerminateAsInterrupt()
    try:
        with term, _said_lines(), _one_line_warnings():
            return args.func(args)
    except FretwearError as exc:
        print(f"error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, SystemError) as exc:
        if not interrupted(exc):
            raise
        message = getattr(exc, "message", "interrupted: nothing was saved")
        if term.received:
            message = message.replace("interrupted", "terminated (SIGTERM)", 1)
        print(message, file=sys.stderr)
        return 128 + int(signal.SIGTERM) if term.received else 130
    except BrokenPipeError:  # e.g. `fretwear example show NAME | head`: not an error
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
