"""The time-domain analyses of case files: ``"transient"`` and ``"incremental-wear"``.

``"transient"`` integrates the forced response in time with exact contact and friction
(:func:`fretwear.timedomain.steady.steady_state` or
:func:`fretwear.timedomain.integrate.integrate`) and writes
the last forcing period (observed points, contact nodes, harmonics, contact states, energy
terms), the once-per-period (Poincare) samples and the classification of the response.
``"incremental-wear"`` runs quasi-static load steps with Archard wear applied as it goes
(:func:`fretwear.timedomain.quasistatic.incremental_wear`) and writes the wear history.

Variable names follow ``docs/results.md``: the names of the ``periodic`` analysis where the
meaning is the same (the last period is sampled at ``tau_j = 2 pi j / steps_per_period``),
new names where it differs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from fretwear.analyses import figures as plots
from fretwear.analyses.base import Analysis, RunContext, RunOutput
from fretwear.analyses.common import (
    default_of,
    figure_path,
    geometry,
    interface_abscissa,
    pad_axes,
    si_scale,
    titled,
)
from fretwear.analyses.figure_style import MARKED_POINTS, series_style
from fretwear.hb.contact import STATE_NAMES
from fretwear.hb.fourier import FourierBasis, amplitude
from fretwear.io.results import label_coordinate, variable
from fretwear.io.schema import Field, Integer, Number, Text, fail, join
from fretwear.timedomain.integrate import integrate
from fretwear.timedomain.options import (
    IncrementalWearOptions,
    InitialState,
    IntegrationOptions,
    SteadyStateOptions,
)
from fretwear.timedomain.quasistatic import incremental_wear
from fretwear.timedomain.results import IncrementalWearResult, TransientResult
from fretwear.timedomain.steady import classify_sequence, fourier_coefficients, steady_state

#: forcing periods integrated after a steady-state run for the Poincare / drift figure
POINCARE_PERIODS = 128
#: energy terms of :class:`~fretwear.timedomain.integrate.TransientResult` -> (variable, long name)
ENERGY_TERMS = {
    "external": ("cumulative_external_work", "work of the loads since the period start"),
    "friction": ("cumulative_friction_dissipation",
                 "energy dissipated by friction since the period start"),
    "normal": ("cumulative_normal_contact_work",
               "work of the normal contact forces since the period start (impacts, >= 0)"),
    "damping": ("cumulative_damping_dissipation",
                "energy dissipated by damping since the period start"),
    "numerical": ("cumulative_numerical_dissipation",
                  "algorithmic dissipation of the time scheme since the period start"),
    "mechanical": ("mechanical_energy", "kinetic + elastic energy at t + h/2"),
}


# --- transient: computation ------------------------------------------------------------------
def _continue(model, frequency: float, U, V, n_periods: int, steps: int) -> TransientResult:
    """``n_periods`` more periods at ``frequency`` [Hz] from the state ``(U, V)``, the last
    one recorded."""
    return integrate(model, frequency, n_periods=n_periods,
                     options=IntegrationOptions(steps_per_period=steps),
                     start=InitialState(U0=U, V0=V), record=1, keep_poincare=n_periods)


def _classify_record(run: TransientResult, tol: float):
    """Classification of the Poincare samples of the observed points of ``run``."""
    names = list(run.poincare)
    P = np.hstack([run.poincare[n] for n in names])
    means = np.hstack([run.period_mean[n] for n in names])
    scale = max(float(np.ptp(run.observed[n], axis=0).max()) for n in names)
    return classify_sequence(P, means, tol=tol, scale=scale, min_window=min(128, len(P)))


def time_run(model, analysis: dict, frequency: float, progress: bool):
    """Integrate at ``frequency`` [Hz] as ``analysis`` asks.

    Returns
    -------
    ``(last, classification, periods_before, info)``: ``last`` the
    :class:`~fretwear.timedomain.integrate.TransientResult` whose last recorded period is reported
    and
    whose Poincare samples are drawn; ``classification`` a
    :class:`~fretwear.timedomain.integrate.Classification`; ``periods_before`` the periods
    integrated
    before ``last`` started; ``info`` attributes (periods, wall time [s]).
    """
    steps = analysis["steps_per_period"]
    if analysis["mode"] == "fixed":
        n = analysis["n_periods"]
        last = integrate(model, frequency, n_periods=n,
                         options=IntegrationOptions(steps_per_period=steps), record=1,
                         keep_poincare=n, progress=progress)
        cls = _classify_record(last, analysis["tol"])
        return last, cls, 0, {"periods": n, "time_wall_time": last.wall_time}
    ss = steady_state(model, frequency,
                      options=SteadyStateOptions(max_periods=analysis["max_periods"],
                                                 tol=analysis["tol"],
                                                 harmonics=analysis["harmonics"]),
                      integration=IntegrationOptions(steps_per_period=steps))
    last = _continue(model, frequency, ss.U, ss.V, POINCARE_PERIODS, steps)
    info = {"periods": ss.n_periods + POINCARE_PERIODS,
            "time_wall_time": ss.wall_time + last.wall_time}
    return last, ss.diagnostics, ss.n_periods, info


def period_friction_energy(last: TransientResult) -> np.ndarray:
    """Friction energy dissipated by each contact node over the last period (nc,) [J].

    ``sum_n lam_T(t_n) . (u_T(t_{n+1}) - u_T(t_n))`` (the force at ``t_n`` acts over the step
    ``t_n -> t_{n+1}``); the last step closes the period on its first sample, exact for a
    periodic response.
    """
    lam_t = last.lam[:, :, 1:]
    u_t = last.u_loc[:, :, 1:]
    du = np.roll(u_t, -1, axis=0) - u_t
    return np.einsum("nci,nci->c", lam_t, du)


# --- transient: dataset ----------------------------------------------------------------------
def _period_coordinates(steps: int, nh: int) -> dict:
    labels = FourierBasis.up_to(nh, steps).labels()
    return {
        "tau": variable("tau", 2 * np.pi * np.arange(steps) / steps, "rad",
                        "angle tau = omega t over the last period (from its start)"),
        "harmonic_coefficient": label_coordinate("harmonic_coefficient", labels),
        "harmonic": variable("harmonic", np.arange(1, nh + 1), "1", "harmonic number"),
    }


def _observed_variables(last: TransientResult, points: list[str], n_axes: int, nh: int
                        ) -> dict:
    """Last-period histories and harmonics of the observed points."""
    basis = FourierBasis.up_to(nh, last.steps_per_period)
    coeffs = [fourier_coefficients(last.observed[p], nh).T for p in points]  # (d, 2nh+1)
    pa = ("point", "axis")
    return {
        "displacement": variable(pa + ("tau",), pad_axes([last.observed[p].T for p in points],
                                                          n_axes), "m",
                                 "displacement of the observed point over one period"),
        "velocity": variable(pa + ("tau",), pad_axes([last.velocities[p].T for p in points],
                                                      n_axes), "m/s",
                             "velocity of the observed point over one period"),
        "displacement_coefficients": variable(
            pa + ("harmonic_coefficient",), pad_axes(coeffs, n_axes), "m",
            "Fourier coefficients of the displacement of the observed point"),
        "displacement_harmonic_amplitude": variable(
            pa + ("harmonic",), pad_axes([amplitude(c, basis) for c in coeffs], n_axes), "m",
            "amplitude of each kept harmonic of the displacement of the observed point"),
    }


def _poincare_variables(last: TransientResult, points: list[str], n_axes: int,
                        periods_before: int) -> dict:
    """Once-per-period samples and period means of the observed points (``time`` dim)."""
    T = 2 * np.pi / last.omega
    n_kept = len(next(iter(last.poincare.values())))
    start = periods_before + last.n_periods - n_kept
    pa = ("time", "point", "axis")

    def stack(d):
        return np.moveaxis(pad_axes([d[p].T for p in points], n_axes), 2, 0)

    return {
        "time": variable("time", (start + np.arange(n_kept)) * T, "s",
                         "start of the forcing period (from the start of the integration)"),
        "poincare_displacement": variable(pa, stack(last.poincare), "m",
                                          "displacement of the observed point at the start of "
                                          "each period (Poincare section)"),
        "period_mean_displacement": variable(pa, stack(last.period_mean), "m",
                                             "displacement of the observed point, mean over "
                                             "each period"),
    }


def _contact_variables(last: TransientResult, nh: int) -> dict:
    """Last-period contact histories, harmonics, states and friction energy."""
    nct = ("contact_node", "component", "tau")
    ncc = ("contact_node", "component", "harmonic_coefficient")
    energy = period_friction_energy(last)
    return {
        "contact_displacement": variable(
            nct, np.transpose(last.u_loc, (1, 2, 0)), "m",
            "displacement of the contact node over one period, contact-local components"),
        "contact_force": variable(
            nct, np.transpose(last.lam, (1, 2, 0)), "N", "force of the structure on the "
            "obstacle over one period (normal positive in compression), contact-local "
            "components"),
        "contact_displacement_coefficients": variable(
            ncc, np.transpose(fourier_coefficients(last.u_loc, nh), (1, 2, 0)), "m",
            "Fourier coefficients of the contact node displacement, contact-local components"),
        "contact_force_coefficients": variable(
            ncc, np.transpose(fourier_coefficients(last.lam, nh), (1, 2, 0)), "N",
            "Fourier coefficients of the force of the structure on the obstacle (normal "
            "positive in compression), contact-local components"),
        "contact_state": variable(
            ("contact_node", "tau"), last.state.T.astype(np.int8), "1",
            "contact state over one period", flag_values=np.array([0, 1, 2], dtype=np.int8),
            flag_meanings=" ".join(STATE_NAMES)),
        "dissipated_energy": variable("contact_node", energy, "J",
                                      "energy dissipated by friction per period"),
        "total_dissipated_energy": variable(
            (), float(energy.sum()), "J",
            "energy dissipated by friction per period over the interface"),
    }


def _energy_variables(last: TransientResult) -> dict:
    return {name: variable("tau", last.energy[key], "J", long)
            for key, (name, long) in ENERGY_TERMS.items()}


def state_fractions(state: np.ndarray, area: np.ndarray) -> np.ndarray:
    """Area-weighted fractions of contact area x time in separation, stick, slip (3,).

    ``state`` is (nc, N) (node, instant); ``area`` (nc,) [m^2].
    """
    w = np.asarray(area, float) / np.sum(area)
    return np.array([w @ (state == s).mean(axis=1) for s in range(3)])


def transient_dataset(model, last: TransientResult, points: list[str], nh: int,
                      periods_before: int) -> xr.Dataset:
    """The results dataset of a ``transient`` run (``docs/results.md``, ``transient``)."""
    coords, data = geometry(model, points)
    n_axes = coords["axis"].size
    coords.update(_period_coordinates(last.steps_per_period, nh))
    pc = _poincare_variables(last, points, n_axes, periods_before)
    coords["time"] = pc.pop("time")
    data.update(pc)
    data.update(_observed_variables(last, points, n_axes, nh))
    data.update(_contact_variables(last, nh))
    data.update(_energy_variables(last))
    return xr.Dataset(data, coords=coords)


def _transient_attributes(ds, cls, info: dict, f_hz: float, analysis: dict, last) -> dict:
    frac = state_fractions(ds["contact_state"].values, ds["contact_area"].values)
    return {
        "classification": cls.kind, "periodicity_error": float(cls.periodicity_error),
        "drift_rate": float(cls.drift_rate), "rotation": float(cls.rotation),
        "repetition_order": int(cls.order), "excitation_frequency": f_hz,
        "mode": analysis["mode"], "steps_per_period": int(analysis["steps_per_period"]),
        "periods": int(info["periods"]), "wall_time": float(info["time_wall_time"]),
        "energy_residual": float(last.energy_residual()),
        **{f"{n}_fraction": float(x) for n, x in zip(STATE_NAMES, frac, strict=True)},
    }


# --- transient: figures ------------------------------------------------------------------------
def _live_axes(ds: xr.Dataset, point: str) -> list[str]:
    pos = ds["point_position"].sel(point=point)
    return [str(a) for a in ds["axis"].values if np.isfinite(pos.sel(axis=a).values)]


def plot_last_period(ds: xr.Dataset, path: Path, point: str, *, title: str | None = None
                     ) -> Path:
    """Displacement of an observed point over the last period, about its mean, per axis."""
    axes_names = _live_axes(ds, point)
    fig, axes = plots.new_figure(1, len(axes_names), title=title)
    t = ds["tau"].values / (2 * np.pi)
    for ax, axis in zip(axes[0], axes_names, strict=True):
        u = ds["displacement"].sel(point=point, axis=axis).values
        k, unit = si_scale(u - u.mean(), "m")
        ax.plot(t, k * (u - u.mean()), color="tab:blue")
        km, um = si_scale(u.mean(), "m")
        ax.set_title(f"{axis}: mean {km * u.mean():.4g} {um}", fontsize="medium")
        ax.set_ylabel(f"u_{axis} - mean at {point} [{unit}]")
        ax.set_xlabel("t / T [-] (last period)")
        ax.grid(True, alpha=0.3)
    return plots.save(fig, path)


def plot_poincare(ds: xr.Dataset, path: Path, point: str, *, title: str | None = None) -> Path:
    """Poincare samples and period means of an observed point against the period count: a
    periodic response is flat, a drifting one slopes, a quasi-periodic one oscillates."""
    axes_names = _live_axes(ds, point)
    fig, axes = plots.new_figure(len(axes_names), 1, title=title, panel_size=(7.0, 2.8),
                                 sharex=True)
    n = ds["time"].values * float(ds.attrs.get("excitation_frequency", 1.0))
    for ax, axis in zip(axes[:, 0], axes_names, strict=True):
        p = ds["poincare_displacement"].sel(point=point, axis=axis).values
        m = ds["period_mean_displacement"].sel(point=point, axis=axis).values
        k, unit = si_scale(np.concatenate([p, m]), "m")
        ax.plot(n, k * p, ".", ms=3, label="at the period start (Poincare)")
        ax.plot(n, k * m, "-", color="tab:red", label="period mean")
        ax.set_ylabel(f"u_{axis} at {point} [{unit}]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize="small")
    axes[-1, 0].set_xlabel("forcing periods from the start [-]")
    axes[0, 0].set_title(f"response: {ds.attrs.get('classification', '?')}",
                         fontsize="medium")
    return plots.save(fig, path)


def transient_figures(ds: xr.Dataset, case, outdir: Path, title: str) -> list[Path]:
    """The figures of a transient run (``case.output``: whether and in which format)."""
    figures = []
    for point in ds["point"].values:
        for stem, plot in (("transient", plot_last_period), ("poincare", plot_poincare)):
            p = figure_path(case, outdir, f"{stem}-{point}")
            if p is not None:
                figures.append(plot(ds, p, str(point), title=title))
    p = figure_path(case, outdir, "contact-state")
    if p is not None:
        figures.append(plots.plot_state_map(ds, p, title=title))
    return figures


# --- transient: run ----------------------------------------------------------------------------
def _transient_summary(ds: xr.Dataset) -> str:
    a = ds.attrs
    lines = [
        f"transient at {plots.format_frequency(a['excitation_frequency'])}: "
        f"{a['classification']} after {a['periods']} periods ({a['wall_time']:.2f} s; "
        f"periodicity error {a['periodicity_error']:.3g}, drift {a['drift_rate']:.3g} m/period)",
        "last period: " + ", ".join(f"{n} {100 * a[f'{n}_fraction']:.1f} %" for n in
                                    STATE_NAMES)
        + f" of contact area x period; friction energy "
        f"{float(ds['total_dissipated_energy']):.4g} J per cycle",
    ]
    for point in ds["point"].values:
        amp = ds["displacement_harmonic_amplitude"].sel(point=point)
        parts = [f"|u_{ax}_1| = {float(amp.sel(axis=ax)[0]):.4g} m"
                 for ax in _live_axes(ds, str(point))]
        lines.append(f"{point}: " + ", ".join(parts))
    return "\n".join(lines)


def run_transient(model, analysis: dict, case, context: RunContext) -> RunOutput:
    """Time integration at one frequency (see the module docstring).

    Parameters
    ----------
    model : the model; analysis : the validated ``[analysis]`` table; case : the case;
    context : results folder, progress bar (``fixed`` mode).

    Returns
    -------
    RunOutput; ``success`` False when a steady-state run ends ``"transient"`` (undecided at
    ``max_periods``).
    """
    f_hz = float(analysis["frequency"])
    last, cls, before, info = time_run(model, analysis, f_hz, context.progress)
    points = [p.name for p in model.observed]
    ds = transient_dataset(model, last, points, analysis["harmonics"], before)
    ds.attrs.update(_transient_attributes(ds, cls, info, f_hz, analysis, last))
    title = titled(case.title, plots.format_frequency(f_hz))
    figures = transient_figures(ds, case, context.out_dir, title)
    converged = analysis["mode"] == "fixed" or cls.kind != "transient"
    return RunOutput(ds, figures, _transient_summary(ds), converged)


def _check_harmonics(out: dict, path: str) -> None:
    """Rule: ``steps_per_period`` exceeds twice ``harmonics``."""
    if "harmonics" in out and out.get("steps_per_period", 0) <= 2 * out["harmonics"]:
        fail(join(path, "steps_per_period"), out["steps_per_period"],
             f"more than {2 * out['harmonics']} steps (twice harmonics)")


TRANSIENT = Analysis.define(
    "transient",
    {
        "frequency": Field(Number(lo=0, lo_open=True), "excitation frequency", required=True,
                           unit="Hz"),
        "mode": Field(Text(("steady-state", "fixed")), '"steady-state": integrate until the '
                      "response is classified (periodic, subharmonic, drifting, "
                      'quasi-periodic, irregular) or max_periods; "fixed": exactly n_periods',
                      default="steady-state"),
        "steps_per_period": Field(Integer(lo=8), "fixed time steps per forcing period",
                                  default=default_of(IntegrationOptions, "steps_per_period")),
        "max_periods": Field(Integer(lo=1), "steady-state: give up after this many periods",
                             default=default_of(SteadyStateOptions, "max_periods")),
        "n_periods": Field(Integer(lo=1), "fixed: periods integrated from rest", default=200),
        "tol": Field(Number(lo=0, lo_open=True), "relative periodicity tolerance of the "
                     "classification", default=default_of(SteadyStateOptions, "tol"), unit="-"),
        "harmonics": Field(Integer(lo=1), "highest harmonic of the last period reported: "
                           "Nh reports 1, 2, .., Nh",
                           default=default_of(SteadyStateOptions, "harmonics")),
    },
    run_transient,
    checks=(_check_harmonics,),
    doc="Forced response integrated in time from rest with exact unilateral contact and "
    "Coulomb friction (`fretwear.timedomain.integrate`, no penalty, no harmonic truncation); the "
    "hysteretic loss factor becomes the equivalent viscous damping at the forcing frequency. "
    f"A steady-state run is followed by {POINCARE_PERIODS} more periods for the drift figure; "
    "the last one is reported. The run exits with status 1 when a steady-state run is still "
    "undecided (`transient`) at max_periods. Writes `transient-<point>.png` (displacement "
    "over the last period), `poincare-<point>.png` (once-per-period samples and period means: "
    "drift, quasi-periodicity) and `contact-state.png`.",
    preload_check=True,
)


# --- incremental wear --------------------------------------------------------------------------
def incremental_dataset(model, r: IncrementalWearResult) -> xr.Dataset:
    """The results dataset of an ``incremental-wear`` run (``docs/results.md``)."""
    coords, data = geometry(model, [p.name for p in model.observed])
    coords["step"] = variable("step", np.arange(r.cycles.size), "1",
                              "slow-scale (wear) step: a recorded computed cycle")
    sn = ("step", "contact_node")
    data.update({
        "cycles": variable("step", r.cycles, "1", "physical cycle count N"),
        "wear_depth": variable(sn, r.wear, "m", "wear depth W"),
        "worn_volume": variable("step", r.worn_volume, "m^3", "worn volume"),
        "cycle_pressure_mean": variable(sn, r.pressure, "Pa", "normal contact pressure, mean "
                                        "over the load steps of the computed cycle"),
        "cycle_slip": variable(sn, r.slip, "m", "slip distance over the computed cycle"),
        "cycle_dissipation": variable("step", r.dissipation, "J",
                                      "friction dissipation over the computed cycle"),
    })
    return xr.Dataset(data, coords=coords)


def plot_incremental_profiles(ds: xr.Dataset, path: Path, *, title: str | None = None,
                              n: int = 5) -> Path:
    """Wear depth along the interface at up to ``n`` recorded cycle counts."""
    x, xlabel = interface_abscissa(ds)
    o = np.argsort(x, kind="stable")
    rows = sorted({int(i) for i in np.linspace(0, ds.sizes["step"] - 1,
                                               min(n, ds.sizes["step"])).round()})
    fig, axes = plots.new_figure(title=title, panel_size=(7.0, 3.6))
    ax = axes[0, 0]
    k, unit = si_scale(ds["wear_depth"].values, "m")
    for j, i in enumerate(rows):
        ax.plot(x[o], k * ds["wear_depth"].values[i][o],
                label=f"{int(ds['cycles'][i]):.3g} cycles",
                **series_style(j, len(rows), markers=x.size <= MARKED_POINTS))
    ax.set_xlabel(xlabel)
    ax.set_ylabel(f"wear depth [{unit}]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return plots.save(fig, path)


def run_incremental_wear(model, analysis: dict, case, context: RunContext) -> RunOutput:
    """Quasi-static incremental wear (:func:`fretwear.timedomain.quasistatic.incremental_wear`)."""
    r = incremental_wear(model, n_cycles=analysis["n_cycles"],
                         options=IncrementalWearOptions(
                             steps_per_cycle=analysis["steps_per_cycle"],
                             cycle_jump=analysis["cycle_jump"],
                             record_every=analysis["record_every"]),
                         progress=context.progress)
    ds = incremental_dataset(model, r)
    ds.attrs.update({"computed_cycles": int(r.computed_cycles), "cycle_jump": int(r.cycle_jump),
                     "steps_per_cycle": int(r.steps_per_cycle), "k_w": float(r.k_w),
                     "wall_time": float(r.wall_time)})
    figures = []
    p = figure_path(case, context.out_dir, "wear-profile")
    if p is not None:
        figures.append(plot_incremental_profiles(ds, p, title=titled(case.title, "wear")))
    w = ds["wear_depth"].values[-1]
    summary = (f"incremental wear: {int(r.cycles[-1])} cycles ({r.computed_cycles} computed, "
               f"jump {r.cycle_jump}) in {r.wall_time:.2f} s; maximum wear depth "
               f"{w.max():.4g} m, worn volume {float(r.worn_volume[-1]):.4g} m^3")
    return RunOutput(ds, figures, summary, True)


INCREMENTAL_WEAR = Analysis.define(
    "incremental-wear",
    {
        "steps_per_cycle": Field(Integer(lo=2), "quasi-static load steps per cycle",
                                 default=default_of(IncrementalWearOptions, "steps_per_cycle")),
        "n_cycles": Field(Integer(lo=1), "load cycles (physical, counting the jumps)",
                          default=default_of(incremental_wear, "n_cycles")),
        "cycle_jump": Field(Integer(lo=1), "cycles represented by each computed cycle "
                            "(explicit Euler on the slow scale)",
                            default=default_of(IncrementalWearOptions, "cycle_jump")),
        "record_every": Field(Integer(lo=1), "record every this many computed cycles (and "
                              "the last)",
                              default=default_of(IncrementalWearOptions, "record_every")),
    },
    run_incremental_wear,
    doc="Quasi-static fretting wear by load steps "
    "(`fretwear.timedomain.quasistatic.incremental_wear`, in "
    "the spirit of Stromberg 1997): exact contact and incremental Coulomb friction at every "
    "load step, Archard wear (k_w = contact.wear_coefficient) applied after each step; "
    "inertia and damping are ignored. Writes `wear-profile.png` (wear depth along the "
    "interface at a few cycle counts).",
    preload_check=True,
)
