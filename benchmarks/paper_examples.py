"""Time the full set of the paper's examples (``fretwear reproduce``), run by run.

Runs every run of :data:`fretwear.paper.runs.RUNS` and the two extra computations into a fresh
work folder (or ``--work DIR``: finished runs there are read back and not timed again), then
prints the wall time of each, the total, and each run's time as a ratio to the paper's
quasi-static wear run (``wear-quasistatic``, the Table 1 reference that the same machine ran
in the same call; `benchmarks/paper_table1.py` times the two Table 1 runs alone). The last
lines are ``wall_total_s=<seconds>`` and ``wall_<run>_s=<seconds>`` for each run.

BLAS threads: one (set before numpy is imported). Wall times on a shared machine are noisy.

Usage::

    python benchmarks/paper_examples.py [--jobs 2] [--quick] [--work DIR] [--report FILE.md]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

from fretwear.paper.report import write_report  # noqa: E402
from fretwear.paper.runs import run_all  # noqa: E402 (after the BLAS thread setting)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--jobs", type=int, default=1, help="runs at a time (default 1)")
    p.add_argument("--quick", action="store_true", help="reduced numerics (not the paper's)")
    p.add_argument("--work", type=Path, default=None, help="work folder (default: temporary)")
    p.add_argument("--report", type=Path, default=None, help="where to write the report")
    a = p.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="fretwear-paper-") as tmp:
        work = a.work if a.work is not None else Path(tmp)
        t0 = time.perf_counter()
        outcomes = run_all(work, quick=a.quick, jobs=a.jobs,
                           say=lambda line: print(line, flush=True))
        total = time.perf_counter() - t0
        if a.report is not None:
            doc = write_report(Path(work).resolve(), a.report.resolve(), outcomes,
                               quick=a.quick, wall=total, jobs=a.jobs)
            print(f"report: {doc}")
    ref = next((o.seconds for o in outcomes if o.key == "wear-quasistatic"
                and o.status == "done"), None)
    print()
    print(f"{'run':<24} {'status':<14} {'wall [s]':>9} {'/ wear-quasistatic':>19}")
    for o in outcomes:
        ratio = f"{o.seconds / ref:19.1f}" if ref else f"{'n/a':>19}"
        print(f"{o.key:<24} {o.status:<14} {o.seconds:9.1f} {ratio}")
    print(f"jobs={a.jobs} quick={a.quick} cores={os.cpu_count()}")
    print(f"wall_total_s={total:.1f}")
    for o in outcomes:
        print(f"wall_{o.key.replace('-', '_')}_s={o.seconds:.1f}")
    return 0 if all(o.status in ("done", "up to date") for o in outcomes) else 1


if __name__ == "__main__":
    sys.exit(main())
