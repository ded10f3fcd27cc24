"""Run every shipped example and compare two such runs: the check that a change of the code's
structure leaves every results file the same to rounding.

    python scripts/examples_regression.py run OUT_DIR [--full] [--only NAME,NAME]
    python scripts/examples_regression.py compare OLD_DIR NEW_DIR [--rtol 1e-9]

``run`` runs each shipped case file (``fretwear run``, one process per example, one BLAS
thread) into ``OUT_DIR/NAME``. Without ``--full``, the examples that take minutes are run
shortened (fewer frequencies, fewer cycles: :data:`SHORTEN`, printed), the same way in both
runs; ``--full`` runs every example as shipped (about 45 minutes on 2 cores).

``compare`` reads both ``results.nc`` of every example and prints, per example, the largest
difference of any numeric variable relative to that variable's largest magnitude, the
variables that differ in shape or exist in one file only, and the attributes that differ
(run times and versions apart). It exits 1 when an example differs by more than ``--rtol``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "src" / "fretwear" / "examples"

#: overrides of the long examples (``[analysis]`` keys) for a run of a few minutes
SHORTEN = {
    "salles2011-frf": {"n_points": 30},
    "salles2011-30khz": {"max_cycles": 2e6},
    "salles2011-35khz": {"max_cycles": 2e6},
    "salles2011-70khz": {"max_cycles": 5e5},
    "salles2011-79khz": {"max_cycles": 5e5},
    "salles2011-79khz-frf-worn": {"max_cycles": 5e5, "frf_before_after": {
        "f_min": 7.6e4, "f_max": 8.2e4, "n_points": 7, "spacing": "linear"}},
    "dovetail-frf": {"n_points": 8, "linear_points": 100},
    "dovetail-wear": {"max_cycles": 1e5},
    "platform-damper-frf": {"n_points": 12},
}

#: attributes that record when, how long, where or with what, not what
VOLATILE = ("wall", "seconds", "version", "created", "host", "elapsed", "date", "path",
            "case_file", "cpu")
#: variables that record how long
VOLATILE_VARIABLES = ("wall_time", "step_wall_time")


def _write_case(name: str, out: Path, full: bool) -> Path:
    import tomli_w

    data = tomllib.loads((EXAMPLES / f"{name}.toml").read_text())
    if not full:
        data["analysis"].update(SHORTEN.get(name, {}))
    # relative paths of the example (meshes, matrices) stay valid from the new folder
    model = data.get("model", {})
    for key in ("mesh", "file", "K", "M", "C"):
        if isinstance(model.get(key), str) and not Path(model[key]).is_absolute():
            model[key] = str(EXAMPLES / model[key])
    case = out / f"{name}.toml"
    case.write_bytes(tomli_w.dumps(data).encode())
    return case


def run(out: Path, full: bool, only: list[str] | None) -> int:
    out.mkdir(parents=True, exist_ok=True)
    names = sorted(p.stem for p in EXAMPLES.glob("*.toml"))
    if only:
        names = [n for n in names if n in only]
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1",
               PYTHONPATH=str(ROOT / "src"))
    status = 0
    for name in names:
        case = _write_case(name, out, full)
        short = "" if full or name not in SHORTEN else f" (shortened: {SHORTEN[name]})"
        t0 = time.perf_counter()
        p = subprocess.run([sys.executable, "-m", "fretwear", "run", str(case), "-o",
                            str(out / name), "--no-progress"], capture_output=True, text=True,
                           env=env, cwd=out)
        (out / f"{name}.log").write_text(p.stdout + p.stderr)
        print(f"{name}{short}: exit {p.returncode}, {time.perf_counter() - t0:.1f} s",
              flush=True)
        status |= p.returncode not in (0, 1)
    return status


def _numeric(a) -> bool:
    return np.issubdtype(a.dtype, np.number) or a.dtype == bool


def compare(old: Path, new: Path, rtol: float) -> int:
    import xarray as xr

    worst_all = 0.0
    bad = []
    for f_old in sorted(old.glob("*/results.nc")):
        name = f_old.parent.name
        f_new = new / name / "results.nc"
        if not f_new.exists():
            print(f"{name}: no results.nc in {new}")
            bad.append(name)
            continue
        a, b = xr.open_dataset(f_old), xr.open_dataset(f_new)
        notes, worst, where = [], 0.0, ""
        for v in sorted(set(a.variables) | set(b.variables)):
            if v in VOLATILE_VARIABLES or v.endswith("_seconds"):
                continue
            if v not in a.variables or v not in b.variables:
                notes.append(f"{v} only in {'old' if v in a.variables else 'new'}")
                continue
            x, y = a[v].values, b[v].values
            if x.shape != y.shape:
                notes.append(f"{v} shape {x.shape} -> {y.shape}")
                continue
            if not (_numeric(x) and _numeric(y)):
                if not np.array_equal(x, y):
                    notes.append(f"{v} differs")
                continue
            x, y = np.asarray(x, complex), np.asarray(y, complex)
            same_nan = np.array_equal(np.isnan(x), np.isnan(y))
            if not same_nan:
                notes.append(f"{v} NaN pattern differs")
                continue
            ok = ~np.isnan(x)
            if not ok.any():
                continue
            scale = np.max(np.abs(x[ok])) or 1.0
            d = float(np.max(np.abs(x[ok] - y[ok])) / scale)
            if d > worst:
                worst, where = d, v
        for k in sorted(set(a.attrs) | set(b.attrs)):
            if any(s in k.lower() for s in VOLATILE):
                continue
            if str(a.attrs.get(k)) != str(b.attrs.get(k)):
                notes.append(f"attribute {k}: {str(a.attrs.get(k))[:60]!r} -> "
                             f"{str(b.attrs.get(k))[:60]!r}")
        worst_all = max(worst_all, worst)
        flag = "" if worst <= rtol and not notes else "  <-- differs"
        print(f"{name}: largest relative difference {worst:.2e} ({where or '-'}){flag}")
        for n in notes:
            print(f"    {n}")
        if flag:
            bad.append(name)
    print(f"largest relative difference over the examples: {worst_all:.2e}")
    print(f"examples that differ: {', '.join(bad) if bad else 'none'}")
    return 1 if bad else 0


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("out", type=Path)
    r.add_argument("--full", action="store_true")
    r.add_argument("--only", default=None)
    c = sub.add_parser("compare")
    c.add_argument("old", type=Path)
    c.add_argument("new", type=Path)
    c.add_argument("--rtol", type=float, default=1e-9)
    a = p.parse_args()
    if a.cmd == "run":
        return run(a.out.resolve(), a.full, a.only.split(",") if a.only else None)
    return compare(a.old, a.new, a.rtol)


if __name__ == "__main__":
    sys.exit(main())
