"""Time spent in fallbacks by the shipped examples, the tutorial and a 3D lap joint worn to
1e7 cycles, measured the same way on any version of fretwear (docs/studies/fallbacks.md).

    PYTHONPATH=<tree>/src python studies/fallback_time.py examples OUT [--only a,b]
    PYTHONPATH=<tree>/src python studies/fallback_time.py tutorial OUT
    PYTHONPATH=<tree>/src python studies/fallback_time.py lapjoint OUT [--frequency F]
    python studies/fallback_time.py table BEFORE_OUT AFTER_OUT   (the markdown table)

Versions before the fallbacks were summarised print nothing about them, so this script
measures from the outside, with hooks that exist in every version:

- ``ladder``: the wall time of the attempts after the first one of every periodic solve and
  every sweep point (each attempt records its wall time), for the solves made through
  ``fretwear.hb.periodic.solve_periodic`` and ``fretwear.hb.sweep.sweep``;
- ``td``: the wall time inside the time-domain fallback (``FALLBACK.start`` and
  ``FALLBACK.averaged_rate``: time integrations that start a balance or give a wear rate);
- ``wear_td_steps``: the wall time of the slow steps whose rate did not come from a balance
  warm-started from the previous step (results ``time_domain_start`` > 0);
- the run's wall and CPU seconds, and, where the version prints it, its own summary line.

Each example runs in this process (``fretwear run`` through :func:`fretwear.cli.main`), with
the shortened settings of ``scripts/examples_regression.py`` (:data:`SHORTEN`).
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import functools
import io
import json
import os
import sys
import time
import tomllib
from pathlib import Path

for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import numpy as np  # noqa: E402

import fretwear  # noqa: E402

ROOT = Path(fretwear.__file__).resolve().parents[2]
EXAMPLES = Path(fretwear.__file__).resolve().parent / "examples"
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
from examples_regression import SHORTEN  # noqa: E402

#: shorter still than ``SHORTEN`` (the machine was shared by eight runs): fewer frequencies
#: and cycles, the same in both versions; the adaptive wear steps crowd at the start of a
#: run, where the balances are hardest, so most steps and their fallbacks remain
FAST = {
    "salles2011-frf": {"n_points": 20},
    "salles2011-30khz": {"max_cycles": 2e5},
    "salles2011-35khz": {"max_cycles": 2e5},
    "salles2011-70khz": {"max_cycles": 1e5},
    "salles2011-79khz": {"max_cycles": 1e5},
    "salles2011-79khz-frf-worn": {"max_cycles": 1e5, "frf_before_after": {
        "f_min": 7.6e4, "f_max": 8.2e4, "n_points": 5, "spacing": "linear"}},
    "dovetail-frf": {"n_points": 6, "linear_points": 50},
    "dovetail-wear": {"max_cycles": 3e4},
    "platform-damper-frf": {"n_points": 8},
    "bladed-disk-wear": {"max_cycles": 1e5},
}


class Clock:
    """Seconds accumulated by the hooks."""

    def __init__(self):
        self.ladder = 0.0
        self.td = 0.0
        self.solves = 0
        self.fell_back = 0

    def points(self, points):
        for p in points:
            self.solves += 1
            attempts = list(getattr(p, "attempts", []) or [])
            if len(attempts) > 1:
                self.fell_back += 1
                self.ladder += sum(float(a.wall_time) for a in attempts[1:])


def _timed(fn):
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            CLOCK[0].td += time.perf_counter() - t0
    return wrapper


#: the clock the hooks add to (:func:`install` puts them in once; each run gets a new clock)
CLOCK = [Clock()]


def use(clock: Clock) -> Clock:
    """Make ``clock`` the one the hooks add to (installing them on the first call)."""
    if not getattr(use, "installed", False):
        install()
        use.installed = True
    CLOCK[0] = clock
    return clock


def install() -> None:
    """Wrap the periodic solve, the sweep and the time-domain fallback wherever imported."""
    import importlib
    import pkgutil

    for m in pkgutil.walk_packages(fretwear.__path__, "fretwear."):
        if any(s in m.name for s in (".paper", ".study", "examples", "__main__")):
            continue
        with contextlib.suppress(Exception):
            importlib.import_module(m.name)
    from fretwear.hb import periodic, sweep
    from fretwear.timedomain import fallback as tdf

    fb = tdf.FALLBACK
    new_fb = dataclasses.replace(fb, start=_timed(fb.start),
                                 averaged_rate=_timed(fb.averaged_rate))
    sp, sw = periodic.solve_periodic, sweep.sweep

    @functools.wraps(sp)
    def solve_periodic(*args, **kwargs):
        sol = sp(*args, **kwargs)
        CLOCK[0].points([sol])
        return sol

    @functools.wraps(sw)
    def sweep_(*args, **kwargs):
        res = sw(*args, **kwargs)
        CLOCK[0].points(res.points)
        return res

    for mod in list(sys.modules.values()):
        if not getattr(mod, "__name__", "").startswith("fretwear"):
            continue
        for name, value in list(vars(mod).items()):
            if value is fb:
                setattr(mod, name, new_fb)
            elif value is sp:
                setattr(mod, name, solve_periodic)
            elif value is sw:
                setattr(mod, name, sweep_)


def _wear_td_steps(results: Path) -> float:
    import xarray as xr

    if not results.exists():
        return float("nan")
    with xr.open_dataset(results) as ds:
        if "time_domain_start" not in ds or "step_wall_time" not in ds:
            return 0.0
        r = np.asarray(ds["time_domain_start"].values)[1:]
        w = np.asarray(ds["step_wall_time"].values)[1:]
        return float(w[r > 0].sum())


def measure(label: str, run, clock: Clock, out: Path) -> dict:
    """Run ``run()`` (which returns the results file or None) and return the record."""
    buf = io.StringIO()
    t0, c0 = time.perf_counter(), time.process_time()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
        try:
            results = run()
            status = "ok"
        except SystemExit as e:
            results, status = None, f"exit {e.code}"
        except Exception as e:  # noqa: BLE001 (a failed run is a row of the table too)
            results, status = None, f"{type(e).__name__}: {e}"
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    text = buf.getvalue()
    summary = [ln.strip() for ln in text.splitlines() if ln.strip().startswith("fallbacks:")
               or "fallbacks:" in ln]
    rec = {"case": label, "status": status, "wall": round(wall, 2), "cpu": round(cpu, 2),
           "ladder": round(clock.ladder, 2), "td": round(clock.td, 2),
           "solves": clock.solves, "fell_back": clock.fell_back,
           "wear_td_steps": round(_wear_td_steps(results), 2) if results else None,
           "summary": summary, "load": os.getloadavg()[0]}
    (out / f"{label}.log").write_text(text)
    with open(out / "fallbacks.jsonl", "a") as f:
        f.write(json.dumps(rec) + "\n")
    print(json.dumps(rec), flush=True)
    return rec


def _write_case(name: str, out: Path) -> Path:
    import tomli_w

    data = tomllib.loads((EXAMPLES / f"{name}.toml").read_text())
    data["analysis"].update(SHORTEN.get(name, {}))
    data["analysis"].update(FAST.get(name, {}))
    model = data.get("model", {})
    for key in ("mesh", "file", "K", "M", "C"):
        if isinstance(model.get(key), str) and not Path(model[key]).is_absolute():
            model[key] = str(EXAMPLES / model[key])
    case = out / f"{name}.toml"
    case.write_bytes(tomli_w.dumps(data).encode())
    return case


def examples(out: Path, only: list[str] | None) -> None:
    from fretwear import cli

    names = sorted(p.stem for p in EXAMPLES.glob("*.toml"))
    for name in names:
        if only and name not in only:
            continue
        clock = use(Clock())
        case = _write_case(name, out)
        dest = out / name

        def run(case=case, dest=dest):
            cli.main(["run", str(case), "-o", str(dest), "--no-progress"])
            return dest / "results.nc"
        measure(name, run, clock, out)


def _tutorial_model():
    """The model of docs/tutorial.md (2D lap joint), built with the calls every version has."""
    return _lap_model(dim=2)


def _lap_model(dim: int):
    """Two steel plates 60 x 4 mm (20 mm wide), overlapping 30 mm, the bolt over 10 mm of the
    overlap (20 MPa), a transverse 10 kPa harmonic traction on the upper plate, mu = 0.3, both
    surfaces wearing (k = 1e-14 1/Pa): docs/tutorial.md, in 2D or 3D (hexahedra 2 x 10 x 2 mm).
    The part of the face that touches and the bolt's pressure are given without ``region``
    (which older versions lack): a boundary of the overlap's facets and a pressure function."""
    from fretwear import model as fm

    if dim == 2:
        lower = fw_rect(0.0)
        upper = fw_rect(0.030)
        names = {"bottom": "bottom", "top": "top", "left": "left", "right": "right"}
    else:
        lower = fm.box(0.060, 0.020, 0.004, 30, 2, 2)
        upper = fm.box(0.060, 0.020, 0.004, 30, 2, 2, origin=(0.030, 0.0, 0.004))
        names = {"bottom": "zmin", "top": "zmax", "left": "xmin", "right": "xmax"}
    mesh = fm.join(("lower", lower), ("upper", upper))
    fac = np.asarray(mesh.boundaries[f"upper.{names['bottom']}"])
    x = mesh.points[fac, 0]
    keep = np.all((x > 0.030 - 1e-9) & (x < 0.060 + 1e-9), axis=1)
    mesh.boundaries["upper.overlap"] = fac[keep]

    def bolt(xyz):
        return np.where((xyz[:, 0] > 0.040 - 1e-9) & (xyz[:, 0] < 0.050 + 1e-9), 20e6, 0.0)

    shake = (0.0, -1e4) if dim == 2 else (0.0, 0.0, -1e4)
    steel = fretwear.Material(E=210e9, nu=0.3, rho=7800.0)
    kw = {"thickness": 0.020} if dim == 2 else {}
    import inspect
    held = "supports" if "supports" in inspect.signature(fretwear.from_mesh).parameters else "fixed"
    kw[held] = [(f"lower.{names['left']}", "all"), (f"upper.{names['right']}", "all")]
    return fretwear.from_mesh(
        mesh, steel, damping=fretwear.Damping(loss_factor=0.002),
        loads=[fretwear.Traction(f"upper.{names['top']}", pressure=bolt, name="bolt"),
               fretwear.Traction(f"upper.{names['top']}", traction=shake, waveform="cos",
                                 name="shaker")],
        contact=fretwear.ContactSpec(f"upper.{'overlap'}", partner=f"lower.{names['top']}",
                                     mu=0.3, wear_coefficient=1e-14,
                                     partner_wear_coefficient=1e-14),
        observed={"joint": (0.045, 0.008) if dim == 2 else (0.045, 0.010, 0.008)},
        **kw)


def fw_rect(x0: float):
    from fretwear import model as fm

    return fm.rectangle(0.060, 0.004, 30, 2, origin=(x0, 0.0 if x0 == 0.0 else 0.004))


def _write(result, name, out, model, basis):
    """results.nc where the version can write it from Python; None otherwise."""
    w = getattr(fretwear, "write_results", None)
    if w is None:
        from fretwear.wear import history

        if hasattr(result, "history"):
            h = result.history
            import xarray as xr
            ds = xr.Dataset({"time_domain_start": ("step", np.asarray(h.rescued)),
                             "step_wall_time": ("step", np.asarray(h.wall_time))})
            p = out / name / "results.nc"
            p.parent.mkdir(parents=True, exist_ok=True)
            ds.to_netcdf(p)
            del history
            return p
        return None
    return w(result, out / name, model, basis)


def tutorial(out: Path) -> None:
    """The tutorial's runs (sweep 26 points, periodic at the peak, wear to 1e7 cycles in 30
    steps at most, worn FRF), each measured."""
    from fretwear.wear import WearOptions

    model = _tutorial_model()
    basis = fretwear.FourierBasis.up_to(3, 64)
    state = {}

    def sweep(name):
        clock = use(Clock())

        def run():
            r = fretwear.sweep(model, basis, 400.0, 1400.0, 26)
            state["f_peak"] = float(r.frequency_hz[np.nanargmax(r.amplitude("joint", 1))])
            return None
        measure(name, run, clock, out)

    sweep("tutorial-sweep")
    clock = use(Clock())
    measure("tutorial-periodic",
            lambda: fretwear.solve_periodic(model, basis, frequency=state["f_peak"]) and None,
            clock, out)
    clock = use(Clock())

    def wear():
        w = fretwear.simulate_wear(model, basis, frequency=state["f_peak"],
                                   options=WearOptions(max_cycles=1e7, max_steps=30))
        state["wear"] = w.final_wear
        print("wear:", w.message, "depth", float(np.max(w.final_wear)))
        return _write(w, "tutorial-wear", out, model, basis)
    measure("tutorial-wear", wear, clock, out)
    clock = use(Clock())
    measure("tutorial-frf-worn", lambda: _frf_worn(model, basis, state["wear"]), clock, out)
    print("f_peak", state["f_peak"])


def _frf_worn(model, basis, wear):
    import inspect

    params = list(inspect.signature(fretwear.frf_worn).parameters)
    if params[1] == "wear":   # older order: (model, wear, (f_min, f_max, n), basis)
        fretwear.frf_worn(model, wear, (400.0, 1400.0, 26), basis)
    else:
        fretwear.frf_worn(model, basis, wear, 400.0, 1400.0, 26)


def lapjoint(out: Path, frequency: float | None) -> None:
    """The issue's case: a 3D lap joint built as the tutorial does, worn to 1e7 cycles with
    the default eps at its resonance (found by a 9-point sweep unless ``frequency``)."""
    from fretwear.wear import WearOptions

    model = _lap_model(dim=3)
    basis = fretwear.FourierBasis.up_to(3, 64)
    if frequency is None:
        clock = use(Clock())
        state = {}

        def run():
            r = fretwear.sweep(model, basis, 300.0, 1500.0, 9)
            state["f"] = float(r.frequency_hz[np.nanargmax(r.amplitude("joint", 2))])
            print("f_peak", state["f"])
        measure("lapjoint3d-sweep", run, clock, out)
        frequency = state["f"]
    clock = use(Clock())

    def wear():
        w = fretwear.simulate_wear(model, basis, frequency=frequency,
                                   options=WearOptions(max_cycles=1e7))
        print("wear:", w.message, "depth", float(np.max(w.final_wear)), "f", frequency)
        return _write(w, "lapjoint3d-wear", out, model, basis)
    measure("lapjoint3d-wear", wear, clock, out)


def fallback_seconds(rec: dict) -> float:
    """The seconds in fallbacks of a record, counted alike for every version: the attempts
    after the first (``ladder``) plus the time in time integrations, the larger of ``td``
    and ``wear_td_steps`` (the second holds the first for a wear run: not counted twice)."""
    return rec["ladder"] + max(rec["td"], rec["wear_td_steps"] or 0.0)


def table(before: Path, after: Path) -> str:
    """The markdown table of two measurement folders (every ``fallbacks.jsonl`` below each):
    one row per case, before and after."""
    def read(root):
        rows = {}
        for f in sorted(root.rglob("fallbacks.jsonl")):
            for line in f.read_text().splitlines():
                r = json.loads(line)
                rows[r["case"]] = r
        return rows

    b, a = read(before), read(after)
    out = ["| case | before: fallback s / wall s (share) | CPU s | after: fallback s / wall s "
           "(share) | CPU s | after: the run's own summary |",
           "|---|---|---|---|---|---|"]

    def cell(r):
        if r is None:
            return "not run", ""
        if r["status"] != "ok":
            return f"{r['status'][:40]}", f"{r['cpu']:.1f}"
        fb = fallback_seconds(r)
        return (f"{fb:.1f} / {r['wall']:.1f} ({100 * fb / max(r['wall'], 1e-9):.0f} %)",
                f"{r['cpu']:.1f}")

    for case in sorted(set(b) | set(a)):
        rb, ra = b.get(case), a.get(case)
        own = "; ".join(ra["summary"]) if ra and ra["summary"] else ""
        own = own.replace("|", "/")[:160] or ("none printed" if ra else "")
        out.append(f"| {case} | {' | '.join(cell(rb))} | {' | '.join(cell(ra))} | {own} |")
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=("examples", "tutorial", "lapjoint", "table"))
    ap.add_argument("out", type=Path)
    ap.add_argument("after", type=Path, nargs="?")
    ap.add_argument("--only", default="")
    ap.add_argument("--frequency", type=float, default=None)
    a = ap.parse_args(argv)
    if a.what == "table":
        print(table(a.out, a.after))
        return 0
    a.out.mkdir(parents=True, exist_ok=True)
    print("fretwear from", fretwear.__file__, flush=True)
    if a.what == "examples":
        examples(a.out, [s for s in a.only.split(",") if s] or None)
    elif a.what == "tutorial":
        tutorial(a.out)
    else:
        lapjoint(a.out, a.frequency)
    return 0


if __name__ == "__main__":
    sys.exit(main())
