"""The ``"sweep"`` analysis of case files: the nonlinear FRF (DLFT periodic responses over a
frequency band).

:func:`run_sweep` calls :func:`fretwear.api.sweep` (:func:`fretwear.hb.sweep.sweep` with the
public API's time-domain fallback), turns its result into a results dataset (schema in
``docs/results.md``) and figures; :data:`SWEEP` is the analysis
(:mod:`fretwear.analyses.registry` lists it). Points that did not converge are kept as NaN
with ``converged = 0`` and the reason in ``flags``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from tqdm import tqdm

from fretwear import api, linear
from fretwear.analyses import figures as plots
from fretwear.analyses.base import Analysis, RunContext, RunOutput
from fretwear.analyses.common import (
    basis_of,
    check_points,
    check_sampling,
    condenser_of,
    default_of,
    figure_path,
    geometry,
    harmonic_balance_fields,
    live_axes,
    period_coordinates,
    solve_options_of,
    titled,
)
from fretwear.errors import interrupted
from fretwear.hb import fallbacks
from fretwear.hb.branch import NEARBY_TOL
from fretwear.hb.contact import STATE_NAMES
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SWEEP as SWEEP_OPTIONS
from fretwear.hb.solution import PeriodicSolution
from fretwear.hb.sweep import SweepResult
from fretwear.hb.sweep_stability import SweepStability, sweep_stability
from fretwear.io.results import label_coordinate, variable, write_results
from fretwear.io.schema import Field, Flag, Integer, ListOf, Number, Text, increasing
from fretwear.levels import excitation_scaled
from fretwear.timedomain.stability import sweep_check

#: the points computed so far, saved after every grid frequency (``--resume`` continues)
CHECKPOINT_FILE = "sweep-checkpoint.npz"


# --- dataset -------------------------------------------------------------------------------
def _per_point(result: SweepResult, value, fill=np.nan, dtype=float) -> np.ndarray:
    """``value(point)`` for each converged sweep point (``fill`` elsewhere)."""
    return np.array([value(p) if p.success else fill for p in result.points], dtype=dtype)


def _state_fractions(sol: PeriodicSolution) -> np.ndarray:
    """Fractions of contact area x period in separation, stick, slip (3,)."""
    w = sol.area / sol.area.sum()
    return w @ sol.state_fractions()


def _response_variables(result: SweepResult, basis: FourierBasis, model, points: list[str],
                        n_axes: int) -> dict:
    nf, k = len(result.points), basis.k
    amp = np.full((nf, len(points), n_axes, k), np.nan)
    ptp = np.full((nf, len(points), n_axes), np.nan)
    for i, name in enumerate(points):
        for a in range(len(model.observed_point(name).dofs)):
            for j, h in enumerate(basis.harmonics):
                amp[:, i, a, j] = result.amplitude(name, a, h)
            ptp[:, i, a] = 2.0 * result.amplitude(name, a, None)
    return {
        "response_amplitude": variable(
            ("frequency", "point", "axis", "harmonic"), amp, "m",
            "amplitude of each kept harmonic of the displacement of the observed point"),
        "response_peak_to_peak": variable(
            ("frequency", "point", "axis"), ptp, "m",
            "peak-to-peak displacement of the observed point over the period"),
    }


def _attempts(attempts) -> str:
    """The attempts of a point as one line: ``grid/powell/no/5.3e-04; eps-continuation/...``."""
    return "; ".join(f"{a.method}/{a.solver}/{'yes' if a.success else 'no'}/{a.residual:.1e}"
                     for a in attempts)


def _sweep_point_variables(result: SweepResult) -> dict:
    fr = np.array([_state_fractions(p.solution) if p.success else np.full(3, np.nan)
                   for p in result.points]).reshape(-1, 3)
    f = "frequency"
    data = {
        "converged": variable(f, result.point_success.astype(np.int8), "1",
                              "the periodic solve converged", flag_values=np.array(
                                  [0, 1], dtype=np.int8), flag_meanings="no yes"),
        "how": variable(f, np.array([p.how for p in result.points], dtype=str), "1",
                        "how the point was reached: grid, substep, retry, arclength, jump, "
                        "eps-continuation, harmonic-continuation, time-start"),
        "flags": variable(f, np.array(["; ".join(p.flags) for p in result.points], dtype=str),
                          "1", "reasons for caution (empty: none)"),
        "attempts": variable(f, np.array([_attempts(p.attempts) for p in result.points],
                                         dtype=str), "1",
                             "every attempt at this frequency, in order: method/solver/"
                             "converged or not/relative residual"),
        "friction_energy": variable(
            f, _per_point(result, lambda p: p.solution.friction_energy().sum()), "J",
            "energy dissipated by friction per period over the interface"),
        "iterations": variable(f, np.array([p.stats.iterations for p in result.points]), "1",
                               "solver iterations of the last solve at this frequency"),
        "wall_time": variable(f, np.array([p.stats.wall_time for p in result.points], float),
                              "s", "wall time of the last solve at this frequency"),
        "residual": variable(f, np.array([p.stats.residual for p in result.points], float),
                             "1", "final relative residual |f(U)| / |Z_r U|"),
        "penalty": variable(f, _per_point(result, lambda p: p.solution.eps), "N/m",
                            "DLFT penalty eps used"),
    }
    for s, name in enumerate(STATE_NAMES):
        data[f"{name}_fraction"] = variable(
            f, fr[:, s], "1", f"fraction of contact area x period in {name}")
    return data


def _per_interface_variables(result: SweepResult, model) -> dict:
    """Friction energy and contact-state fractions of each contact interface (the
    ``contact_name`` dimension, in the order of ``[[contact]]``), NaN where not converged."""
    c = model.contact
    where = c.interface_index()
    names = c.names()
    area = np.asarray(c.area, float)
    nf, ni = len(result.points), len(names)
    energy = np.full((nf, ni), np.nan)
    frac = np.full((nf, ni, 3), np.nan)
    for i, p in enumerate(result.points):
        if not p.success:
            continue
        e = p.solution.friction_energy()
        states = p.solution.state_fractions()
        for k in range(ni):
            nodes = where == k
            energy[i, k] = e[nodes].sum()
            a = area[nodes]
            w = a / a.sum() if a.sum() > 0 else np.full(a.size, 1.0 / a.size)
            frac[i, k] = w @ states[nodes]
    dims = ("frequency", "contact_name")
    data = {"interface_friction_energy": variable(
        dims, energy, "J", "energy dissipated by friction per period over each interface")}
    for s, name in enumerate(STATE_NAMES):
        data[f"interface_{name}_fraction"] = variable(
            dims, frac[:, :, s], "1", f"fraction of each interface's area x period in {name}")
    return data


def linear_reference_grid(f_min: float, f_max: float, spacing: str, sweep_hz,
                          linear_points: int = 200) -> np.ndarray:
    """The frequencies [Hz] of the linear reference FRFs of a sweep: ``linear_points`` over
    ``[f_min, f_max]`` with the sweep's ``spacing``, and every frequency of the sweep itself
    (so that the nonlinear and the linear responses compare point by point), in increasing
    order. A linear FRF costs a few sparse solves per resonance however fine its grid
    (:func:`fretwear.linear.frf`, ``method="projected"``), so the default resolves resonance
    peaks far narrower than the nonlinear grid does."""
    grid = linear.frequency_grid(f_min, f_max, linear_points, spacing)
    own = np.unique(np.asarray(sweep_hz, float))
    if own.size:  # a grid point within rounding of a sweep frequency is that frequency
        i = np.clip(np.searchsorted(own, grid), 1, max(own.size - 1, 1))
        near = np.minimum(np.abs(grid - own[i - 1]), np.abs(grid - own[np.minimum(
            i, own.size - 1)]))
        grid = grid[near > 1e-9 * grid]
    return np.unique(np.concatenate([grid, own]))


def _linear_references(model, freqs: np.ndarray, interfaces: list[str], points: list[str],
                       n_axes: int) -> dict:
    """Amplitudes of the linear FRFs with the requested interfaces at ``freqs`` [Hz]
    (the ``linear_frequency`` dimension)."""
    amp = np.full((len(interfaces), freqs.size, len(points), n_axes), np.nan)
    for i, interface in enumerate(interfaces):
        r = linear.frf(model, freqs, interface=interface, method="projected")
        for j, name in enumerate(points):
            u = np.abs(r.observed[name])
            amp[i, :, j, : u.shape[1]] = u
    return {"linear_response_amplitude": variable(
        ("interface", "linear_frequency", "point", "axis"), amp, "m",
        "amplitude of the linear FRF with the interface held (stuck) or frictionless "
        "(sliding), harmonic 1 of the loads")}


def sweep_dataset(model, result: SweepResult, basis: FourierBasis, points: list[str],
                  references: list[str], linear_hz=None) -> xr.Dataset:
    """The results dataset of a sweep (``docs/results.md``); ``linear_hz``: the frequencies
    of the linear references [Hz] (:func:`linear_reference_grid`; default the sweep's own)."""
    coords, data = geometry(model, points)
    freqs = result.frequency_hz
    coords["frequency"] = variable("frequency", freqs, "Hz", "excitation frequency")
    coords["harmonic"] = period_coordinates(basis)["harmonic"]
    n_axes = coords["axis"].size
    data.update(_response_variables(result, basis, model, points, n_axes))
    data.update(_sweep_point_variables(result))
    coords["contact_name"] = label_coordinate("contact_name", model.contact.names())
    data.update(_per_interface_variables(result, model))
    if references:
        lf = freqs if linear_hz is None else np.asarray(linear_hz, float)
        coords["interface"] = label_coordinate("interface", references)
        coords["linear_frequency"] = variable("linear_frequency", lf, "Hz",
                                              "frequency of the linear reference FRFs")
        data.update(_linear_references(model, lf, references, points, n_axes))
    return xr.Dataset(data, coords=coords)


# --- stability (Hill's method; issue 31) ----------------------------------------------------
def stability_variables(st: SweepStability) -> dict:
    """``stable``, ``floquet_multiplier_max`` and ``jacobian_sign`` per sweep point."""
    f = "frequency"
    return {
        "stable": variable(f, st.stable, "1", "stability of the periodic solution by Hill's "
                           "method: 1 stable, 0 unstable, -1 not computed",
                           flag_values=np.array([-1, 0, 1], dtype=np.int8),
                           flag_meanings="unknown unstable stable"),
        "floquet_multiplier_max": variable(f, st.max_multiplier, "1",
                                           "largest modulus of the Floquet multipliers"),
        "jacobian_sign": variable(f, st.det_sign, "1", "sign of the determinant of the "
                                  "balance's Jacobian (0: not computed); a change between "
                                  "neighbours is a fold or a branch point"),
    }


def stability_attributes(st: SweepStability) -> dict:
    """``branch_events`` (one line per event) and ``stability_notes``."""
    return {"branch_events": "\n".join(e.line() for e in st.events),
            "stability_notes": "\n".join(st.notes),
            "stability_wall_time": float(np.sum(st.wall_time))}


# --- run -----------------------------------------------------------------------------------
def condensation_line(result: SweepResult) -> str:
    """One summary line of how the sweep's frequencies were condensed ("" when every one
    was condensed exactly): the frequencies the continuation added on a local basis of the
    latest exact condensations (hb/local_basis.py, within ``NEARBY_TOL`` by its estimate),
    and the recorded points from them re-solved on the exact condensation."""
    c = result.condensations
    if not c.get("nearby"):
        return ""
    failed = c.get("polish_failed", 0)
    return (f"condensation: {c.get('exact', 0)} exact condensations, {c['nearby']} frequencies "
            f"added by the continuation on a local basis of the exact ones (estimated error "
            f"<= {NEARBY_TOL:g}); {c.get('polished', 0)} recorded points from those re-solved "
            f"on their exact condensation (counted among the exact ones)"
            + (f", {failed} failed there and left out" if failed else ""))


def _sweep_summary(result: SweepResult, ds: xr.Dataset) -> str:
    lines = [result.summary()]
    if result.resumed_from > 0:
        lines[0] += f" (resumed after {result.resumed_from} grid frequencies)"
    h = int(ds["harmonic"].values[0])
    amp = ds["response_amplitude"].sel(harmonic=h)
    f = ds["frequency"].values
    for point in ds["point"].values:
        for axis in ds["axis"].values:
            y = amp.sel(point=point, axis=axis).values
            if np.all(np.isnan(y)):
                continue
            i = int(np.nanargmax(y))
            lines.append(f"{point} {axis}: max |u_{h}| = {y[i]:.4g} m at "
                         f"{plots.format_frequency(f[i])}")
    return "\n".join(lines)


def sweep_figures(ds: xr.Dataset, case, outdir: Path) -> list[Path]:
    """The figures of a sweep (``case.output``: whether and in which format): the FRF of
    each observed point and the interface's energy and states."""
    figures = []
    for point in ds["point"].values:
        p = figure_path(case, outdir, f"sweep-{point}")
        if p is not None:
            figures.append(plot_sweep(ds, p, str(point),
                                      title=titled(case.title, "nonlinear FRF")))
    p = figure_path(case, outdir, "sweep-interface")
    if p is not None:
        figures.append(plot_sweep_interface(ds, p, title=titled(case.title,
                                                                  "contact interface")))
    return figures


def run_sweep(model, analysis: dict, case, context: RunContext) -> RunOutput:
    """Nonlinear FRF: periodic solutions over a frequency band (:func:`fretwear.hb.sweep.sweep`).

    Parameters
    ----------
    model : the model; analysis : the validated ``[analysis]`` table; case : the case;
    context : results folder, resume (from ``sweep-checkpoint.npz``), progress bar.

    Returns
    -------
    RunOutput; ``success`` False when some point did not converge.
    """
    points = check_points(model, analysis.get("points"))
    basis = basis_of(analysis)
    n = analysis["n_points"]
    model = excitation_scaled(model, analysis["excitation_scale"])
    # the run's condensation of the model (the case file's choice: one modal basis for the
    # whole band where chosen), for every call
    cond = condenser_of(model, analysis, analysis["f_max"], max(basis.harmonics))
    with tqdm(total=n, desc="sweep", disable=not context.progress, leave=False,
              unit="freq") as bar:
        def tick(i, total, pt):
            bar.update(1)
            bar.set_postfix_str(f"{plots.format_frequency(pt.frequency_hz)}"
                                f"{'' if pt.success else ' (not converged)'}")

        options = SWEEP_OPTIONS.replace(
            solve=solve_options_of(analysis, SWEEP_OPTIONS.solve), spacing=analysis["spacing"],
            eps=analysis["eps"], eps_band=analysis.get("eps_band"),
            continuation=analysis["continuation"],
            flag=(sweep_check(model, max_periods=analysis["time_domain_periods"],
                              condenser=cond)
                  if analysis["check_stability"] else None),
            progress=tick, checkpoint=context.out_dir / CHECKPOINT_FILE, resume=context.resume)
        try:
            result = api.sweep(model, basis, analysis["f_min"], analysis["f_max"], n,
                               options=options, time_domain=analysis["time_domain"],
                               condenser=cond)
        except (KeyboardInterrupt, SystemError) as exc:
            if not interrupted(exc) or getattr(exc, "partial", None) is None:
                raise
            write_partial(model, exc.partial, basis, analysis, case, context.out_dir)
            raise KeyboardInterrupt from None
    linear_hz = linear_reference_grid(analysis["f_min"], analysis["f_max"],
                                      analysis["spacing"], result.frequency_hz,
                                      analysis["linear_points"])
    ds = sweep_dataset(model, result, basis, points, analysis["linear_references"], linear_hz)
    events = []
    if analysis["hill_stability"]:
        st = sweep_stability(model, result, condenser=cond)
        ds = ds.assign(stability_variables(st))
        ds.attrs.update(stability_attributes(st))
        events = [e.line() for e in st.events]
    flagged = [f"{p.frequency_hz:.6g} Hz: " + "; ".join(p.flags)
               for p in result.points if p.flags]
    ds.attrs.update({
        "sweep_converged": result.summary().splitlines()[0].split("=", 1)[1],
        "flagged_points": "\n".join(flagged),
        "total_wall_time": float(result.wall_time),
        "solver": analysis["solver"], "tol": float(analysis["tol"]),
        "eps_rule": str(analysis["eps"]),
        "harmonics": ", ".join(str(h) for h in basis.harmonics),
        "n_samples": int(basis.n_samples),
        **cond.choice.attributes(),
    })
    figures = sweep_figures(ds, case, context.out_dir)
    grid_ok = all(p.success for p in result.points if p.on_grid)
    cost = fallbacks.of_solutions(result.points, result.wall_time)
    said = [line for line in (condensation_line(result), cost.continuation_line("frequencies"),
                              cost.line("frequencies", fallbacks.eps_hint("eps" in analysis)))
            if line]
    summary = "\n".join([_sweep_summary(result, ds), *events, *said, cond.choice.summary()])
    return RunOutput(ds, figures, summary, grid_ok, warnings=list(result.warnings))


#: the results of an interrupted sweep, beside its checkpoint (attribute ``complete = 0``)
PARTIAL_FILE = "sweep-partial.nc"


def write_partial(model, partial: SweepResult, basis: FourierBasis, analysis: dict, case,
                  out_dir: Path):
    """The points an interrupted sweep computed (``partial``, those of its checkpoint) as a
    results file (:data:`PARTIAL_FILE`: the variables of ``results.nc`` on the frequencies
    reached, without the linear references; ``complete = 0``, ``converged = 0``) to look at
    while the sweep is not finished; None when no point was computed. ``--resume``
    continues from the checkpoint and writes ``results.nc``."""
    if not partial.points:
        return None
    f = partial.frequency_hz
    message = (f"interrupted after {len(f)} of {analysis['n_points']} grid frequencies "
               f"({plots.format_frequency(f.min())} to {plots.format_frequency(f.max())}): "
               "partial results (run again with --resume to continue)")
    ds = sweep_dataset(excitation_scaled(model, analysis["excitation_scale"]), partial, basis,
                       check_points(model, analysis.get("points")), [])
    ds.attrs.update({"complete": 0, "message": message,
                     "sweep_converged": partial.summary().splitlines()[0].split("=", 1)[1]})
    return write_results(out_dir / PARTIAL_FILE, ds, title=case.title, analysis_type="sweep",
                         converged=False, case_text=case.text, case_path=str(case.path),
                         analysis=analysis)


# --- figures -------------------------------------------------------------------------------
def _mark_failures(ax, f: np.ndarray, converged: np.ndarray, flagged: np.ndarray, y) -> None:
    """Red crosses along the bottom at points that did not converge; orange rings on
    converged points that carry flags."""
    bad = ~converged
    if bad.any():
        ax.plot(f[bad], np.full(bad.sum(), 0.03), "x", color="tab:red",
                transform=ax.get_xaxis_transform(), label=f"not converged ({bad.sum()})")
    ring = flagged & converged
    if ring.any():
        ax.plot(f[ring], y[ring], "o", mfc="none", color="tab:orange", ms=7,
                label=f"flagged ({ring.sum()})")


def _plot_branch(ax, f: np.ndarray, y: np.ndarray, stable, *, label: str) -> None:
    """The nonlinear FRF: solid where stable or not classified, dashed along the stretches
    where Hill's method found the solution unstable (each dashed stretch joins its
    neighbours, so the curve stays continuous)."""
    if stable is None or not np.any(stable == 0):
        ax.plot(f, y, color="k", marker=".", ms=3, label=label)
        return
    bad = stable == 0
    near = bad | np.r_[bad[1:], False] | np.r_[False, bad[:-1]]
    solid = np.where(bad, np.nan, y)
    ax.plot(f, solid, color="k", marker=".", ms=3, label=label)
    ax.plot(f, np.where(near, y, np.nan), color="k", linestyle="--", lw=1.0)
    ax.plot(f[bad], y[bad], "o", mfc="none", color="k", ms=3, ls="none",
            label=f"unstable (Hill, {int(bad.sum())})")


def plot_sweep(ds: xr.Dataset, path: Path, point: str, *, title: str | None = None) -> Path:
    """Nonlinear FRF at one observed point (log-log, one panel per axis), with the linear
    references of the dataset (cf. paper Fig. 14)."""
    axes_names = live_axes(ds, point) or [str(ds["axis"].values[0])]
    fig, axes = plots.new_figure(len(axes_names), 1, title=title, panel_size=(7.5, 3.8),
                                 sharex=True)
    f = ds["frequency"].values
    h = int(ds["harmonic"].values[0])
    conv = ds["converged"].values.astype(bool)
    flagged = np.array([bool(s) for s in ds["flags"].values])
    for ax, axis in zip(axes[:, 0], axes_names, strict=True):
        if "linear_response_amplitude" in ds:
            lin = ds["linear_response_amplitude"]
            fl = ds[lin.dims[1]].values  # linear_frequency (frequency in older files)
            for interface in ds["interface"].values:
                y = lin.sel(interface=interface, point=point, axis=axis).values
                ax.plot(fl, np.where(y > 0, y, np.nan), label=f"linear, {interface}",
                        **plots.INTERFACE_STYLE.get(str(interface), {}))
        y = ds["response_amplitude"].sel(point=point, axis=axis, harmonic=h).values
        _plot_branch(ax, f, np.where(y > 0, y, np.nan),
                     ds["stable"].values if "stable" in ds else None,
                     label=f"friction, harmonic {h}")
        half = 0.5 * ds["response_peak_to_peak"].sel(point=point, axis=axis).values
        ax.plot(f, np.where(half > 0, half, np.nan), color="0.5", lw=2.4, linestyle="-",
                alpha=0.5, zorder=1.5, label="friction, half peak-to-peak")  # a band below
        _mark_failures(ax, f, conv, flagged, y)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylabel(f"|u_{axis}| at {point} [m]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize="small", loc="best")
    axes[-1, 0].set_xlabel("frequency [Hz]")
    return plots.save(fig, path)


def plot_sweep_interface(ds: xr.Dataset, path: Path, *, title: str | None = None) -> Path:
    """Friction energy per cycle and the contact state fractions against frequency."""
    f = ds["frequency"].values
    conv = ds["converged"].values.astype(bool)
    flagged = np.array([bool(s) for s in ds["flags"].values])
    fig, axes = plots.new_figure(2, 1, title=title, panel_size=(7.5, 3.2), sharex=True)
    ax = axes[0, 0]
    e = ds["friction_energy"].values
    several = "contact_name" in ds.dims and ds.sizes["contact_name"] > 1
    ax.plot(f, np.where(e > 0, e, np.nan), color="tab:purple", marker=".", ms=3,
            label="all interfaces" if several else None)
    if several:  # each interface's share, e.g. the two flanks of a blade root
        styles = ("--", ":", "-.", (0, (5, 1)), (0, (1, 3)))
        for k, name in enumerate(ds["contact_name"].values):
            ek = ds["interface_friction_energy"].sel(contact_name=name).values
            ax.plot(f, np.where(ek > 0, ek, np.nan), color="0.35",
                    linestyle=styles[k % len(styles)], lw=1.0, label=str(name))
    _mark_failures(ax, f, conv, flagged, e)
    ax.set_yscale("log")
    ax.set_ylabel("friction energy\nper period [J]")
    if several or not conv.all() or (flagged & conv).any():
        ax.legend(fontsize="small")
    ax = axes[1, 0]
    for colour, name in zip(plots.STATE_COLOURS, STATE_NAMES, strict=True):
        ax.plot(f, ds[f"{name}_fraction"].values, color="0.5" if name == "separation" else
                colour, label=name)
    ax.set_ylim(-0.02, 1.02)
    ax.set_ylabel("fraction of contact\narea x period [-]")
    ax.legend(fontsize="small", title="contact state")
    ax.set_xlabel("frequency [Hz]")
    for ax in axes[:, 0]:
        ax.set_xscale("log")
        ax.grid(True, which="both", alpha=0.3)
    return plots.save(fig, path)


# --- registration ---------------------------------------------------------------------------
SWEEP = Analysis.define(
    "sweep",
    {
        "f_min": Field(Number(lo=0, lo_open=True), "lowest frequency", required=True, unit="Hz"),
        "f_max": Field(Number(lo=0, lo_open=True), "highest frequency", required=True, unit="Hz"),
        "n_points": Field(Integer(lo=2), "number of grid frequencies (the sweep may add "
                          "intermediate points where a step fails)", default=200),
        "spacing": Field(Text(("log", "linear")), "frequency spacing",
                         default=SWEEP_OPTIONS.spacing),
        "continuation": Field(Flag(), "pseudo-arclength continuation when a frequency step "
                              "fails (passes folds of the response curve)",
                              default=SWEEP_OPTIONS.continuation),
        "time_domain": Field(Flag(), "where a point still fails, integrate in time from the "
                             "neighbour: a periodic steady state starts one more solve, any "
                             "other response (drifting, quasi-periodic) is reported as the "
                             "reason", default=default_of(api.sweep, "time_domain")),
        "time_domain_periods": Field(Integer(lo=10), "forcing periods allowed to each time "
                                     "integration (time_domain, check_stability)",
                                     default=SWEEP_OPTIONS.solve.time_domain_periods),
        "check_stability": Field(Flag(), "check every converged point in time (does the "
                                 "structure settle to it?); slow", default=False),
        "hill_stability": Field(Flag(), "Floquet multipliers of every converged point by "
                                "Hill's method on the balance's Jacobian: `stable`, the "
                                "largest multiplier, the sign of det J, and the folds, "
                                "period-doubling and Neimark-Sacker points between "
                                "neighbours; unstable stretches dashed in the figure. Dense on "
                                "the contact DOFs (a few hundred, times the harmonics; a large "
                                "interior enters through its low modes); a point it cannot "
                                "treat is left unknown with the reason in `stability_notes`",
                                default=False),
        "points": Field(ListOf(Text(), non_empty=True, unique=True),
                        "observed points to report (default: all)"),
        "excitation_scale": Field(Number(lo=0, lo_open=True), "factor on every load that "
                                  "varies in time (the constant ones, a preload, kept): one "
                                  "excitation level; a study varying it gives the family of "
                                  "FRFs over the level (docs/study.md)", default=1.0),
        "eps_band": Field(ListOf(Number(lo=0, lo_open=True), sizes=(2,)),
                          'the band [f_min, f_max] over which eps = "contact", "stiff" or '
                          '"top" takes its median '
                          "(default: the sweep's band; the chunks of a split sweep give "
                          "the whole band, so that they share the whole sweep's eps)", unit="Hz"),
        "linear_references": Field(
            ListOf(Text(linear.INTERFACES), unique=True),
            'linear FRFs drawn with the nonlinear one: "sliding" (frictionless), "stuck", '
            '"free"', default=[]),
        "linear_points": Field(Integer(lo=2, hi=100_000), "frequencies of the linear "
                               "references over [f_min, f_max] (the sweep's spacing; the "
                               "sweep's own frequencies are added): their own fine grid, a "
                               "few sparse solves per resonance however many points",
                               default=default_of(linear_reference_grid, "linear_points")),
        **harmonic_balance_fields(
            SWEEP_OPTIONS.solve, SWEEP_OPTIONS.eps,
            'DLFT penalty, one value for the whole sweep (a smooth FRF): "contact": "stiff" '
            'where every contact node is a rigid slider under a prescribed normal load, "top" '
            'elsewhere (chosen from measurements, docs/studies/eps-rule.md); "top": the '
            "spectral radius of Z_r at the highest kept harmonic, its median over the band; "
            '"stiff": ten times "top"; '
            '"static": that of the static reduced stiffness K_r; or a value. "auto": the '
            "paper's rule (spectral radius of Z_r over the kept harmonics) at each frequency"),
    },
    run_sweep,
    checks=(increasing("f_min", "f_max", "Hz"), check_sampling),
    files=(CHECKPOINT_FILE,),
    doc="Nonlinear FRF: periodic responses with the frictional interface over a frequency "
    "band, each point starting from its neighbours (continuation). Points that do not "
    "converge are kept as NaN with `converged = 0` and the reason in `flags`; the run then "
    "exits with status 1. The points computed so far are saved in `sweep-checkpoint.npz` after "
    "every grid frequency: `fretwear run CASE.toml --resume` continues a killed sweep to the "
    "same result; an interrupted one (Ctrl-C, SIGTERM) also writes them as `sweep-partial.nc` "
    "(attribute `complete = 0`) to look at. Writes `sweep-<point>.png` (amplitude against "
    "frequency, with the linear references) and `sweep-interface.png` (friction energy and "
    "contact states).",
    preload_check=True,
)
