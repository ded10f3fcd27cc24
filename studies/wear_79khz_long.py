"""The 79 kHz wear run of the paper's beam continued far beyond 2e8 cycles: is there a plateau?

The reproduction (``fretwear reproduce``, docs/reproduction.md) stops the 79 kHz runs at 2e8
cycles without a plateau. The paper's Table 1 counts 6007 computed slow steps with jumps of up
to 1e7 cycles, i.e. up to 6e10 physical cycles, so its plateau may lie far beyond 2e8. This
script continues the two reproduction runs, the default adaptive scheme (``wear-79khz``) and
the paper's explicit Euler with fixed jumps of 1e7 cycles (``wear-79khz-explicit``), to
``--max-cycles`` with ``fretwear run --resume`` semantics: each run lives in
``WORKDIR/<key>/`` and continues from its checkpoint, so a run that is interrupted (or seeded
with the reproduction's folders, ``--seed REPRO_DIR``) goes on where it stopped.

It prints, for each run: the cycle count reached, slow steps and wall time, the range of the
worn-volume rate over the initial one since 2e8 cycles, and at the last step: the "pillars"
(contact nodes whose slip path per cycle is below 1e-3 of the largest and whose mean pressure
is above twice the mean), the share of the load carried by nodes that slip, and the centroid
of the mean normal contact force (x = L/2 for this beam: friction and the spring act on the
contact line and Q has zero mean, so the mean moment balance fixes it; its largest deviation
over the history is printed as a check of the results). A plateau needs all the load on
sticking nodes, so it needs sticking nodes on both sides of L/2 (or at it).
It draws ``docs/studies/figures/wear-79khz-long.png``: wear profiles at selected cycle counts
and the worn-volume rate against cycles for both runs.

Usage::

    python studies/wear_79khz_long.py [--workdir DIR] [--seed REPRO_DIR]
        [--max-cycles 3e9] [--only KEY] [--plot-only]
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
from pathlib import Path

KEYS = ("wear-79khz", "wear-79khz-explicit")
FIGURE = (Path(__file__).resolve().parents[1] / "docs" / "studies" / "figures"
          / "wear-79khz-long.png")


def case_text(key: str, max_cycles: float) -> str:
    from fretwear.paper.catalogue import RUNS, edit_case_text, run_case_text

    run = next(r for r in RUNS if r.key == key)
    return edit_case_text(run_case_text(run, False), "analysis", {"max_cycles": float(max_cycles)})


def run(key: str, workdir: Path, max_cycles: float, seed: Path | None) -> None:
    from fretwear.analyses.run import run_case

    folder = workdir / key
    folder.mkdir(parents=True, exist_ok=True)
    ck, src = folder / "wear-checkpoint.npz", None if seed is None else seed / key
    if src is not None and not ck.is_file() and (src / ck.name).is_file():
        shutil.copy2(src / ck.name, ck)
    path = folder / "case.toml"
    path.write_text(case_text(key, max_cycles), encoding="utf-8")
    out = run_case(path, folder, progress=sys.stderr.isatty(), resume=True, echo=False)
    print(f"{key}: {out.summary.splitlines()[0] if out.summary else ''}")


def history(folder: Path):
    """The run's :class:`fretwear.wear.WearHistory` from its checkpoint, or None."""
    from fretwear.wear import read_history

    ck = folder / "wear-checkpoint.npz"
    return read_history(ck) if ck.is_file() else None


def facts(h, x, area) -> dict:
    """What the last step says about a plateau (see module docstring)."""
    import numpy as np

    p, path = h.pressure_mean[-1], h.slip_path[-1]
    pbar = float(np.dot(area, p) / area.sum())
    stuck = path <= 1e-3 * path.max()
    pillars = np.flatnonzero(stuck & (p > 2.0 * pbar))
    load = np.dot(area, p)
    centroid = float(np.dot(area * p, x) / load)
    P = h.pressure_mean
    centroids = (P * area) @ x / (P @ area)
    vr = h.volume_rate / h.volume_rate[0]
    late = h.cycles >= 2e8
    return {
        "cycles": float(h.cycles[-1]), "steps": len(h.cycles) - 1,
        "wall": float(np.sum(h.wall_time)), "rate": float(vr[-1]),
        "rate_range": (float(vr[late].min()), float(vr[late].max())) if late.any() else None,
        "pillars_mm": [round(1e3 * float(x[i]), 1) for i in pillars],
        "pillar_load": float(np.dot(area[pillars], p[pillars]) / load),
        "slipping_load": float(np.dot(area[~stuck], p[~stuck]) / load),
        "centroid_mm": 1e3 * centroid,
        "centroid_dev_um": 1e6 * float(np.max(np.abs(centroids - 0.5 * (x.min() + x.max())))),
        "straddle": bool(pillars.size and x[pillars].min() <= centroid <= x[pillars].max()),
        "max_depth_nm": 1e9 * float(h.wear_depth[-1].max()),
    }


def plot(histories: dict, model) -> Path:
    """The figure from the runs' histories (``{key: WearHistory or None}``)."""
    import numpy as np

    from fretwear.analyses import figures as plots

    x = 1e3 * np.asarray(model.contact.coords, float)[:, 0]
    fig, axes = plots.new_figure(1, 4, panel_size=(4.2, 3.6),
                                 title="79 kHz wear continued (paper beam, 7 harmonics)")
    axes = axes[0]
    for ax, key in zip(axes[:2], KEYS, strict=True):
        h = histories.get(key)
        if h is None:
            continue
        n = h.cycles
        picks = [int(np.argmin(abs(n - t))) for t in (2e8, 5e8, 1e9, 2e9, 5e9, 1e10)
                 if t < 0.9 * n[-1]] + [len(n) - 1]
        for k in picks:
            ax.plot(x, 1e9 * h.wear_depth[k], label=f"N = {n[k]:.3g}")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("wear depth [nm]")
        ax.set_title(key, fontsize=9)
        ax.legend(fontsize=7)
    ax = axes[2]
    for key in KEYS:
        h = histories.get(key)
        if h is not None:
            ax.plot(h.cycles, h.worn_volume, label=key)
    ax.set_xlabel("cycles N")
    ax.set_ylabel("worn volume [m^3]")
    ax.legend(fontsize=7)
    ax = axes[3]
    for key in KEYS:
        h = histories.get(key)
        if h is not None:
            ax.semilogy(h.cycles, h.volume_rate / h.volume_rate[0], ".", ms=2,
                        label=key)
    ax.axhline(1e-3, color="k", lw=0.8, ls="--", label="plateau test (1e-3)")
    ax.set_xlabel("cycles N")
    ax.set_ylabel("worn-volume rate / initial")
    ax.legend(fontsize=7)
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    return plots.save(fig, FIGURE, dpi=90)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workdir", type=Path, default=Path("/tmp/fretwear-79khz-long"))
    ap.add_argument("--seed", type=Path, default=None,
                    help="a `fretwear reproduce` work directory to continue from")
    ap.add_argument("--max-cycles", type=float, default=3e9)
    ap.add_argument("--only", choices=KEYS, default=None)
    ap.add_argument("--plot-only", action="store_true")
    ap.add_argument("--threads", type=int, default=None,
                    help="BLAS threads (default: OPENBLAS_NUM_THREADS if set, else 1)")
    a = ap.parse_args(argv)
    if a.threads is not None:
        os.environ["OPENBLAS_NUM_THREADS"] = str(a.threads)
    else:
        os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    import numpy as np

    from fretwear.analyses.run import load_case
    from fretwear.io.case import build_model

    keys = KEYS if a.only is None else (a.only,)
    if not a.plot_only:
        for key in keys:
            run(key, a.workdir, a.max_cycles, a.seed)
    model = None
    histories = {key: history(a.workdir / key) for key in KEYS}  # each checkpoint read once
    for key, h in histories.items():
        if h is None:
            print(f"{key}: no checkpoint in {a.workdir / key}")
            continue
        if model is None:
            model = build_model(load_case(a.workdir / key / "case.toml"))
            x = np.asarray(model.contact.coords, float)[:, 0]
            area = np.asarray(model.contact.area, float)
        f = facts(h, x, area)
        rr = f["rate_range"]
        print(f"{key}: N = {f['cycles']:.3g} in {f['steps']} steps, {f['wall']:.0f} s of step "
              f"wall time; worn-volume rate / initial {f['rate']:.3g} at the end"
              + (f", {rr[0]:.3g} to {rr[1]:.3g} since N = 2e8" if rr else "")
              + f"; max depth {f['max_depth_nm']:.1f} nm")
        print(f"{key}: last step: pillars at x = {f['pillars_mm']} mm carry "
              f"{100 * f['pillar_load']:.0f} % of the load, slipping nodes "
              f"{100 * f['slipping_load']:.0f} %; mean normal force centroid x = "
              f"{f['centroid_mm']:.2f} mm (largest deviation from L/2 over the history "
              f"{f['centroid_dev_um']:.2g} um); pillars "
              f"{'straddle' if f['straddle'] else 'do not straddle'} it")
    if model is not None:
        print(f"figure: {plot(histories, model)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
