"""The ``"worn-state"`` analysis of case files: where fretting wear stops, found directly.

Runs :func:`fretwear.wear.worn_state.worn_state` (pseudo-transient continuation on the slow
equation of paper eq. 29, docs/theory.md "The worn state directly") at one excitation
frequency (or quasi-static), with a checkpoint in the results folder so that
``fretwear run CASE.toml --resume`` continues an interrupted run. The results file is the
``wear`` analysis's dataset of the pseudo-time steps (its last step is the state; the step
sizes are pseudo-time, so ``cycles`` and ``jump`` are named ``pseudo_time`` and
``pseudo_jump``) with the verdict: the null-wear-rate residual, the last correction and the
estimated cycles a march needs to get within 1 % of the state (docs/results.md,
``worn-state``). Figures: the worn profile, pressure and slip before and at the state, the
residual over the steps, maps for 3D or several interfaces, and the nonlinear FRFs before and
after when asked (paper Fig. 24).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from fretwear import api
from fretwear.analyses import figures as plots
from fretwear.analyses.base import Analysis, RunContext, RunOutput
from fretwear.analyses.figure_style import MARKED_POINTS, series_style
from fretwear.analyses.wear import (
    SCHEMA as WEAR_SCHEMA,
)
from fretwear.analyses.wear import (
    _profile,
    _x_along,
    before_after_frf,
    maps_and_frf_figures,
    options_from_table,
    penalty_of,
    slow_run_setup,
    wear_dataset,
)
from fretwear.hb.fourier import FourierBasis
from fretwear.io.results import variable
from fretwear.io.schema import Field, Integer, Number, fail
from fretwear.wear import BalanceSetup, RunControl, WearResult
from fretwear.wear.worn_state import WornStateOptions, WornStateResult

CHECKPOINT_FILE = "worn-state-checkpoint.npz"
_DEFAULTS = WornStateOptions()


def options_of(a: dict) -> WornStateOptions:
    """:class:`~fretwear.wear.worn_state.WornStateOptions` from the validated table."""
    wear = {k: a[k] for k in ("law", "energy_coefficient", "partner_energy_coefficient",
                              "solver", "tol", "time_domain_rescue", "time_domain_settle",
                              "time_domain_average", "time_domain_steps",
                              "checkpoint_every_s") if k in a}
    return WornStateOptions(wear=options_from_table(wear), tolerance=a["residual_tolerance"],
                            depth_tolerance=a["depth_tolerance"], max_steps=a["max_steps"],
                            path_tolerance=a["path_tolerance"])


def worn_state_dataset(model, res: WornStateResult, basis: FourierBasis, *, frequency_hz,
                       frf=None, opts: WornStateOptions):
    """The results dataset (docs/results.md, ``worn-state``)."""
    w = opts.wear
    as_wear = WearResult(res.history, res.initial, res.final, res.kind, res.message,
                         res.success, res.wall_time, penalty=res.penalty)
    ds = wear_dataset(model, as_wear, basis, frequency_hz=frequency_hz, frf=frf, law=w.law,
                      energy_coefficients=(w.energy_coefficient,
                                           w.partner_energy_coefficient))
    ds = ds.rename({"cycles": "pseudo_time", "jump": "pseudo_jump"}).drop_vars(
        ["stability_jump"])
    ds["pseudo_time"].attrs.update(long_name="pseudo-time of the step (cycles of a linearly "
                                   "implicit step; not physical cycles)")
    ds["pseudo_jump"].attrs.update(long_name="pseudo-time step")
    ds["null_wear_rate_residual"] = variable(
        (), res.residual, "1", "null-wear-rate residual: largest wear rate over the largest "
        "initial one, at the last step")
    ds["last_correction"] = variable((), res.correction, "1", "last change of the wear "
                                     "depths over the deepest wear")
    ds["cycles_to_state_estimate"] = variable(
        (), res.cycles_to_1pc, "1", "ESTIMATE of the cycles a march needs to get within 1 % "
        "of the deepest wear of the state (NaN: not reached)")
    ds.attrs.update({"worn_state_kind": res.kind, "worn_state_message": res.message})
    return ds


def plot_worn_state(ds, path: Path, *, title=None) -> Path:
    """Worn depth of each surface at the state; mean pressure and slip path per cycle of the
    unworn interface and at the state; along the interface."""
    x, xlabel = _x_along(ds)
    fig, axes = plots.new_figure(3, 1, title=title, sharex=True)
    surf = ds["worn_depth_surface"].values[-1]
    marked = x.size <= MARKED_POINTS
    both = bool(np.any(surf[:, 1] > 0))
    _profile(axes[0, 0], x, surf[:, 0] * 1e6, label="contact surface",
             **series_style(0, 1 + both, markers=marked))
    if both:
        _profile(axes[0, 0], x, surf[:, 1] * 1e6, label="partner surface",
                 **series_style(1, 2, markers=marked))
    axes[0, 0].set_ylabel("worn depth [um]")
    for j, (k, lab) in enumerate(((0, "unworn"), (-1, "worn state"))):
        style = series_style(j, 2, markers=marked)
        _profile(axes[1, 0], x, ds["pressure_mean"].values[k] / 1e6, label=lab, **style)
        _profile(axes[2, 0], x, ds["slip_path"].values[k] * 1e6, label=lab, **style)
    axes[1, 0].set_ylabel("mean pressure [MPa]")
    axes[2, 0].set_ylabel("slip path / cycle [um]")
    axes[2, 0].set_xlabel(xlabel)
    for ax in axes[:, 0]:
        ax.grid(True, alpha=0.3)
        ax.legend()
    return plots.save(fig, path)


def plot_residual(ds, path: Path, *, title=None) -> Path:
    """The largest wear rate over the initial one at every pseudo-time step."""
    fig, axes = plots.new_figure(1, 1, title=title)
    ax = axes[0, 0]
    rate = ds["wear_rate"].values.max(axis=1)
    r = rate / rate[0] if rate[0] > 0 else rate
    ax.semilogy(np.arange(r.size), np.where(r > 0, r, np.nan), marker=".")
    ax.set_xlabel("pseudo-time step")
    ax.set_ylabel("max wear rate / initial")
    ax.grid(True, which="both", alpha=0.3)
    return plots.save(fig, path)


def _figures(ds, case, outdir: Path) -> list[Path]:
    out = case.output
    if not out["figures"]:
        return []
    fmt, t = out["figure_format"], case.title
    figs = [plot_worn_state(ds, outdir / f"worn-state.{fmt}", title=f"{t}: worn state"),
            plot_residual(ds, outdir / f"worn-state-residual.{fmt}",
                          title=f"{t}: null-wear-rate residual")]
    return figs + maps_and_frf_figures(
        ds, outdir / f"worn-state-maps.{fmt}", f"{t}: worn state", "at the state",
        (outdir, "frf-worn-state", fmt, f"{t}: FRF before wear / at the worn state"))


def run_worn_state(model, analysis: dict, case, context: RunContext) -> RunOutput:
    """The worn state directly (module docstring)."""
    a = analysis
    opts = options_of(a)
    quasi, f_hz, basis, fb, cond = slow_run_setup(model, a)
    res = api.worn_state(model, basis, frequency=f_hz, quasi_static=quasi, options=opts,
                         balance=BalanceSetup(condenser=cond, **penalty_of(a)),
                         run=RunControl(checkpoint=context.out_dir / CHECKPOINT_FILE,
                                        resume=context.resume, progress=context.progress))
    frf, frf_note, sweeps = before_after_frf(model, basis, a, fb, cond, res.wear)
    ds = worn_state_dataset(model, res, basis, frequency_hz=f_hz, frf=frf, opts=opts)
    ds.attrs.update(cond.choice.attributes())
    figures = _figures(ds, case, context.out_dir)
    w = res.wear
    lines = [
        res.message,
        f"{res.history.n_steps - 1} pseudo-time steps, {res.dlft_solves} DLFT solves, wall "
        f"{res.wall_time:.1f} s"
        + (f" (resumed from step {res.resumed_from})" if res.resumed_from >= 0 else ""),
        f"worn volume {res.worn_volume:.4e} m^3, max depth {w.max():.4e} m at contact node "
        f"{int(np.argmax(w))}",
    ]
    if res.kind == "null_wear_rate":
        lines.append(f"a march would need about {res.cycles_to_1pc:.3g} cycles to get within "
                     "1 % of this state (an estimate)")
    if frf_note:
        lines.append(frf_note)
    lines.append(cond.choice.summary())
    warnings = list(res.warnings)
    for name, sw in sweeps.items():
        warnings += [f"FRF {name}: {x}" for x in sw.warnings]
    return RunOutput(ds, figures, "\n".join(lines), res.success,
                     [context.out_dir / CHECKPOINT_FILE], warnings=warnings)


def _check_table(out: dict, path: str) -> None:
    """A frequency unless quasi-static; k_e with the energy law."""
    if not out.get("quasi_static") and "frequency" not in out:
        fail(f"{path}.frequency" if path else "frequency", None,
             "an excitation frequency [Hz] (or quasi_static = true)")
    if out.get("law") == "energy" and "energy_coefficient" not in out:
        fail(f"{path}.energy_coefficient" if path else "energy_coefficient", None,
             "k_e [m^3/J] for law = \"energy\"")


_SHARED = ("frequency", "quasi_static", "harmonics", "n_samples", "condensation",
           "condensation_modes", "condensation_cutoff", "condensation_tol", "eps", "solver",
           "tol", "law", "energy_coefficient", "partner_energy_coefficient",
           "time_domain_rescue", "time_domain_settle", "time_domain_average",
           "time_domain_steps", "checkpoint_every_s", "frf_before_after")
_UNIT = Number(lo=0, lo_open=True, hi=1, hi_open=True)

#: keys of the ``[analysis]`` table of ``type = "worn-state"``
SCHEMA = {
    **{k: WEAR_SCHEMA[k] for k in _SHARED if k in WEAR_SCHEMA},
    "residual_tolerance": Field(_UNIT, "the state is reached when the largest wear rate is "
                                "at most this fraction of the largest initial one (the "
                                "null-wear-rate residual)", default=_DEFAULTS.tolerance,
                                unit="-"),
    "depth_tolerance": Field(_UNIT, "... and the last correction of the wear depths at most "
                             "this fraction of the deepest wear",
                             default=_DEFAULTS.depth_tolerance, unit="-"),
    "path_tolerance": Field(_UNIT, "local error per step (relative to the deepest wear) of "
                            "the steps that follow the path while the slipping nodes change",
                            default=_DEFAULTS.path_tolerance, unit="-"),
    "max_steps": Field(Integer(lo=1), "pseudo-time steps before giving up (then success is "
                       "false, with the residual)", default=_DEFAULTS.max_steps),
}
DOC = (
    "The worn state directly: the wear depths at which the wear rate vanishes (every node "
    "that carries load sticks), by pseudo-transient continuation on the slow equation with "
    "the DLFT balance inside (docs/theory.md, \"The worn state directly\"); or steady wear "
    "when the wear goes on (gross slip); or, honestly, not reached, with the residual. A "
    "checkpoint `worn-state-checkpoint.npz` in the results folder lets `fretwear run "
    "CASE.toml --resume` continue an interrupted run. Writes `worn-state.png`, "
    "`worn-state-residual.png`, with several or 3D interfaces `worn-state-maps.png`, with "
    "`frf_before_after` `frf-worn-state-<point>.png`."
)

WORN_STATE = Analysis.define("worn-state", SCHEMA, run_worn_state, checks=(_check_table,),
                             doc=DOC, files=(CHECKPOINT_FILE,), preload_check=True)
