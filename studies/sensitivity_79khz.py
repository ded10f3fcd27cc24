"""How reproducible is the 79 kHz wear path? Twin runs that differ by 1e-12.

Write-up: docs/studies/79khz-wear.md, "How reproducible the path is".

From about 1e8 cycles on, the 79 kHz wear run of the paper's beam (example
``salles2011-79khz``) takes its wear rates from time integrations of the structure (the
periodic balance is lost at ~1.3e7 cycles, ``studies/balance_end_79khz.py``). This script
measures how sensitive that path is, on two time scales, with the same code and settings:

1. runs the case to ``--max-cycles`` (default 1.5e8, about 40 slow steps) in ``--workdir``
   (or, with ``--from DIR``, starts from the run in ``DIR``: its ``case.toml`` and
   ``wear-checkpoint.npz``, left unchanged);
2. *fast scale*: integrates the structure at the last step's wear twice for ``--periods``
   periods (default 1500) from the run's last time-integration state, once as it is and once
   with the initial velocity scaled by ``1 + 1e-12`` (not the displacement: it holds the
   static preload, about 1e4 times the vibration), and prints the distance between the twins
   (largest contact displacement difference at the start of each period, relative to the
   peak-to-peak contact motion) against the periods elapsed, with the growth rate fitted from
   where the distance has grown 100-fold to where it reaches 1e-3 (sustained exponential
   growth is a positive largest Lyapunov exponent: the response is chaotic, not only
   quasi-periodic); then the wear rate averaged as a slow step does (300 + 500 periods) on
   both twins, against the scatter of two consecutive 500-period windows of one of them and
   the ``rate_scatter`` the run records for such a window;
3. *slow scale*: continues the wear run from its checkpoint for ``--steps`` slow steps
   (default 40) twice, as it is and with the wear depths scaled by ``1 + 1e-12``, and prints
   how the two worn profiles separate (largest depth difference relative to the largest depth,
   at equal cycle counts) and their worn-volume rates (``--steps 0``: skipped).

If the twins separate to a few per cent within the run, the wear profile at a far cycle count
is not a reproducible function of the settings (tolerance, window lengths, step history): any
change of the algorithm, a speed-up included, moves it by that much or more.

Usage::

    python studies/sensitivity_79khz.py [--workdir DIR] [--max-cycles 1.5e8]
        [--from RUN_DIR] [--periods 1500] [--steps 40]
"""

from __future__ import annotations

import argparse
import contextlib
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from balance_end_79khz import run_to_failure  # noqa: E402

PERTURBATION = 1e-12
CHUNK = 50  # periods per integration call of the fast twins (recorded in full, then thinned)


def period_starts(model, frequency, U0, V0, wear, periods, steps):
    """Contact displacements at the start of every period (periods, nc * d) and the peak-to-peak
    contact motion over the last chunk [m]."""
    import numpy as np

    from fretwear.timedomain.integrate import integrate
    from fretwear.timedomain.options import InitialState, IntegrationOptions

    out, U, V, ptp = [], U0, V0, 0.0
    done = 0
    while done < periods:
        n = min(CHUNK, periods - done)
        r = integrate(model, frequency, options=IntegrationOptions(steps_per_period=steps),
                      start=InitialState(U0=U, V0=V, wear=wear), n_periods=n, record=n)
        x = r.u_loc.reshape(r.u_loc.shape[0], -1)
        out.append(x[::steps])
        ptp = float(np.ptp(x, axis=0).max())
        U, V, done = r.U, r.V, done + n
    return np.concatenate(out), ptp


def growth_rate(d):
    """Fitted exponential growth rate [1/period] of ``d`` from where it has grown 100-fold
    (and is above 1e-10) to where it reaches 1e-3, or None (fewer than 10 periods there)."""
    import numpy as np

    lo = max(100.0 * float(d[0]), 1e-10)
    above = np.flatnonzero(d > lo)
    if above.size == 0:
        return None
    idx = np.arange(above[0], d.size)
    idx = idx[np.cumsum(d[idx] >= 1e-3) == 0]
    if idx.size < 10:
        return None
    return float(np.polyfit(idx, np.log(d[idx]), 1)[0])


def fast_twins(folder: Path, periods: int) -> None:
    import numpy as np

    from fretwear.analyses.run import load_case
    from fretwear.hb.fourier import FourierBasis
    from fretwear.io.case import build_model
    from fretwear.timedomain.averaged_rate import default_steps, time_averaged_rate
    from fretwear.timedomain.options import AveragingOptions
    from fretwear.wear import wear_coefficients

    with np.load(folder / "wear-checkpoint.npz") as z:
        U0, V0, W = z["state_td_U"], z["state_td_V"], z["state_W"]
    if U0.size == 0:
        print("the last step is a balanced one: no time-integration state to start from")
        return
    case = load_case(folder / "case.toml")
    model = build_model(case)
    a = case.analysis
    f_hz = float(a["frequency"])
    basis = FourierBasis.up_to(int(a["harmonics"]), int(a["n_samples"]))
    steps = default_steps(basis, a.get("time_domain_steps"))
    t0 = time.perf_counter()
    xa, ptp = period_starts(model, f_hz, U0, V0, W, periods, steps)
    xb, _ = period_starts(model, f_hz, U0, V0 * (1 + PERTURBATION), W, periods, steps)
    d = np.abs(xa - xb).max(axis=1) / ptp
    print(f"fast twins ({periods} periods each, {time.perf_counter() - t0:.1f} s): distance / "
          f"peak-to-peak contact motion ({ptp:.3g} m) after n periods")
    marks = [n for n in (0, 25, 50, 100, 200, 400, 800, 1200, periods - 1) if n < periods]
    print("  " + ", ".join(f"n={n}: {d[n]:.1e}" for n in marks))
    rate = growth_rate(d)
    if rate is None:
        print("  no sustained growth (no sign of chaos at this state)")
    else:
        print(f"  growth rate {rate:.4f} per period (distance x10 every {np.log(10) / rate:.0f}"
              f" periods): largest Lyapunov exponent > 0")
    coef = wear_coefficients(model)
    area = np.asarray(model.contact.area, float)
    ga = time_averaged_rate(model, f_hz, basis, coef, W, U0=U0, V0=V0)
    gb = time_averaged_rate(model, f_hz, basis, coef, W, U0=U0, V0=V0 * (1 + PERTURBATION))
    ga2 = time_averaged_rate(model, f_hz, basis, coef, W, U0=ga.U_end, V0=ga.V_end,
                             options=AveragingOptions(settle=0))

    def diff(g1, g2):
        return (f"{np.abs(g1.g - g2.g).max() / g1.g.max():.3f} of the largest node rate, "
                f"{abs(np.dot(area, g1.g - g2.g)) / np.dot(area, g1.g):.3f} of the volume rate")

    print(f"  averaged rates (300 + 500 periods): twins differ by {diff(ga, gb)} "
          f"({ga.kind} / {gb.kind}); two consecutive windows of one twin by {diff(ga, ga2)}")
    print(f"  rate_scatter of the first twin's window (two half-windows): {ga.scatter:.2g}")


def slow_twins(folder: Path, workdir: Path, steps: int) -> None:
    import numpy as np

    from fretwear.analyses.run import run_case
    from fretwear.paper.catalogue import edit_case_text
    from fretwear.wear import read_history

    with np.load(folder / "wear-checkpoint.npz") as z:
        data = {k: z[k] for k in z.files}
    step0, N0 = int(data["state_step"]), float(data["state_cycles"])
    text = edit_case_text((folder / "case.toml").read_text(encoding="utf-8"), "analysis",
                          {"max_cycles": 1e12, "max_steps": step0 + int(steps)})
    runs = {}
    for key, scale in (("control", 1.0), ("perturbed", 1.0 + PERTURBATION)):
        twin = workdir / f"twin-{key}"
        if twin.exists():
            shutil.rmtree(twin)
        twin.mkdir(parents=True)
        data_k = dict(data)
        data_k["state_W"] = data["state_W"] * scale
        np.savez(twin / "wear-checkpoint.npz", **data_k)
        (twin / "case.toml").write_text(text, encoding="utf-8")
        t0 = time.perf_counter()
        run_case(twin / "case.toml", twin, progress=False, resume=True, echo=False)
        runs[key] = read_history(twin / "wear-checkpoint.npz")
        print(f"slow twin '{key}': steps {step0} -> {runs[key].n_steps - 1}, "
              f"N = {N0:.4g} -> {runs[key].cycles[-1]:.4g} ({time.perf_counter() - t0:.0f} s)")
    a, b = runs["control"], runs["perturbed"]
    print("worn profiles of the twins at equal cycles (b's steps, a interpolated):")
    print("  step, N, max|W_b - W_a| / max W_a, worn volume b / a - 1, volume rate a, b")
    last = b.n_steps - 1
    for k in sorted({*range(step0 + 1, last + 1, max(1, steps // 8)), last}):
        N = float(b.cycles[k])
        if N > a.cycles[-1]:
            break
        j = int(np.clip(np.searchsorted(a.cycles, N), 1, a.n_steps - 1))
        t = (N - a.cycles[j - 1]) / (a.cycles[j] - a.cycles[j - 1])
        Wa = (1 - t) * a.wear_depth[j - 1] + t * a.wear_depth[j]
        va = (1 - t) * a.worn_volume[j - 1] + t * a.worn_volume[j]
        print(f"  {k}, {N:.4e}, {np.abs(b.wear_depth[k] - Wa).max() / Wa.max():.2e}, "
              f"{b.worn_volume[k] / va - 1:+.2e}, {a.volume_rate[j]:.3e}, "
              f"{b.volume_rate[k]:.3e}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workdir", type=Path, default=None,
                    help="folder of the runs (default: a temporary folder)")
    ap.add_argument("--max-cycles", type=float, default=1.5e8)
    ap.add_argument("--from", dest="source", type=Path, default=None,
                    help="start from this run folder (case.toml, wear-checkpoint.npz)")
    ap.add_argument("--periods", type=int, default=1500)
    ap.add_argument("--steps", type=int, default=40)
    args = ap.parse_args(argv)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    with contextlib.ExitStack() as stack:
        workdir = args.workdir or Path(stack.enter_context(tempfile.TemporaryDirectory()))
        if args.source is not None:
            folder = args.source
        else:
            t0 = time.perf_counter()
            folder = run_to_failure(workdir, args.max_cycles)
            print(f"run to N = {args.max_cycles:.3g}: {time.perf_counter() - t0:.1f} s")
        fast_twins(folder, args.periods)
        if args.steps > 0:
            slow_twins(folder, workdir, args.steps)
    return 0


if __name__ == "__main__":
    sys.exit(main())
