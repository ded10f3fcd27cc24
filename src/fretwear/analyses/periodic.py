"""The ``"periodic"`` analysis of case files: the DLFT periodic response at one frequency.

:func:`run_periodic` calls :func:`fretwear.api.solve_periodic` (the DLFT solve with the public
API's time-domain fallback), turns its result into a results dataset (schema in
``docs/results.md``), figures and ParaView files; :data:`PERIODIC` is the analysis
(:mod:`fretwear.analyses.registry` lists it).

A periodic solve that did not converge is never saved as a result: the run writes a results
file with the solver diagnostics as attributes and no solution variables, and reports the
failure (``converged = 0``, exit status 1).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from fretwear import api
from fretwear.analyses import figures as plots
from fretwear.analyses.base import Analysis, RunContext, RunOutput
from fretwear.analyses.common import (
    STOP_TOL,
    basis_of,
    check_sampling,
    condenser_of,
    default_of,
    figure_path,
    geometry,
    harmonic_balance_fields,
    interface_abscissa,
    live_axes,
    pad_axes,
    period_coordinates,
    si_scale,
    solve_options_of,
    solver_attributes,
    titled,
)
from fretwear.analyses.figure_style import MARKED_POINTS, series_style
from fretwear.errors import InputError
from fretwear.hb import fallbacks
from fretwear.hb.contact import STATE_NAMES
from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.inputs import QUASI_STATIC_FREQUENCY
from fretwear.hb.options import PERIODIC as PERIODIC_SOLVE
from fretwear.hb.penalty import penalty
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.reduce import condense, recover
from fretwear.hb.slow_mode import slow_mode
from fretwear.hb.solution import PeriodicSolution
from fretwear.hb.solvers import SolveStats
from fretwear.hb.stability import DENSE_MAX, problem_of, stability
from fretwear.io.results import (
    no_fields_line,
    nodal_vectors,
    output_mesh,
    variable,
    write_pvd,
    write_vtu,
)
from fretwear.io.schema import Field, Flag, Integer, Number, join


# --- dataset -------------------------------------------------------------------------------
def _observed_variables(sol: PeriodicSolution, points: list[str], n_axes: int) -> dict:
    """Displacement and velocity of the observed points over a period, per harmonic (none
    when the model observes no point)."""
    if not points:
        return {}
    coeffs, disp, vel, amp, stops = [], [], [], [], []
    for name in points:
        u, v = sol.observed_time(name)
        d = u.shape[0]
        coeffs.append(sol.observed[name])
        disp.append(u)
        vel.append(v)
        amp.append(sol.observed_amplitude(name))
        stops.append(np.array([sol.stops_per_period(name, a, STOP_TOL) for a in range(d)],
                              dtype=float))
    pa = ("point", "axis")
    return {
        "displacement_coefficients": variable(
            pa + ("harmonic_coefficient",), pad_axes(coeffs, n_axes), "m",
            "Fourier coefficients of the displacement of the observed point"),
        "displacement": variable(pa + ("tau",), pad_axes(disp, n_axes), "m",
                                 "displacement of the observed point over one period"),
        "velocity": variable(pa + ("tau",), pad_axes(vel, n_axes), "m/s",
                             "velocity of the observed point over one period"),
        "displacement_harmonic_amplitude": variable(
            pa + ("harmonic",), pad_axes(amp, n_axes), "m",
            "amplitude of each kept harmonic of the displacement of the observed point"),
        "stops_per_period": variable(
            pa, pad_axes(stops, n_axes), "1",
            f"intervals per period with |velocity| <= {STOP_TOL:g} x its peak"),
    }


def _contact_variables(sol: PeriodicSolution) -> dict:
    """Harmonics, time histories and per-node summaries of the interface."""
    ncc = ("contact_node", "component", "harmonic_coefficient")
    nct = ("contact_node", "component", "tau")
    p_mean, p_max, p_amp = sol.pressure_stats()
    s_path, s_amp, s_mean = sol.slip_stats()
    energy = sol.friction_energy()
    return {
        "contact_displacement_coefficients": variable(
            ncc, sol.U, "m", "Fourier coefficients of the contact node displacement, "
            "contact-local components"),
        "contact_force_coefficients": variable(
            ncc, sol.lam, "N", "Fourier coefficients of the force of the structure on the "
            "obstacle (normal positive in compression), contact-local components"),
        "corrected_displacement_coefficients": variable(
            ncc, sol.X, "m", "Fourier coefficients of the corrected displacement X (satisfies "
            "the contact law), contact-local components"),
        "contact_force": variable(
            nct, sol.lam_t, "N", "force of the structure on the obstacle over one period "
            "(normal positive in compression), contact-local components"),
        "corrected_displacement": variable(
            nct, sol.x_t, "m", "corrected displacement X over one period, contact-local "
            "components"),
        "contact_state": variable(
            ("contact_node", "tau"), sol.state.astype(np.int8), "1",
            "contact state over one period", flag_values=np.array([0, 1, 2], dtype=np.int8),
            flag_meanings=" ".join(STATE_NAMES)),
        "contact_pressure": variable(("contact_node", "tau"), sol.pressure_t(), "Pa",
                                     "normal contact pressure over one period"),
        "pressure_mean": variable("contact_node", p_mean, "Pa",
                                  "normal contact pressure, mean over the period"),
        "pressure_max": variable("contact_node", p_max, "Pa",
                                 "normal contact pressure, maximum over the period"),
        "pressure_amplitude": variable("contact_node", p_amp, "Pa",
                                       "normal contact pressure, half range over the period"),
        "slip_path": variable("contact_node", s_path, "m",
                              "length of the slip path per period (corrected displacement)"),
        "slip_amplitude": variable("contact_node", s_amp, "m",
                                   "half range of the corrected tangential displacement (T1)"),
        "slip_mean_position": variable("contact_node", s_mean, "m",
                                       "mean corrected tangential position (T1)"),
        "dissipated_energy": variable("contact_node", energy, "J",
                                      "energy dissipated by friction per period"),
        "total_dissipated_energy": variable(
            (), float(energy.sum()), "J",
            "energy dissipated by friction per period over the interface"),
        "contact_gap": variable("contact_node", sol.gap, "m",
                                "normal gap (initial gap + wear) used"),
    }


def periodic_dataset(model, sol: PeriodicSolution, points: list[str]) -> xr.Dataset:
    """The results dataset of a converged periodic solution (``docs/results.md``)."""
    coords, data = geometry(model, points)
    coords.update(period_coordinates(sol.basis))
    data.update(_observed_variables(sol, points, coords["axis"].size))
    data.update(_contact_variables(sol))
    return xr.Dataset(data, coords=coords)


# --- run -----------------------------------------------------------------------------------
def _frequency_text(f_hz: float, quasi_static: bool) -> str:
    return "quasi-static loading" if quasi_static else plots.format_frequency(f_hz)


def _failure_summary(stats: SolveStats, analysis: dict, where: str,
                     sol: PeriodicSolution | None = None) -> str:
    tried = ""
    if sol is not None and sol.attempts:
        tried = f"; attempts: {', '.join(a.method for a in sol.attempts)}"
    text = (
        f"periodic solve at {where} did not converge: {stats.message} (relative residual "
        f"{stats.residual:.3g} > tol {analysis['tol']:g} after {stats.iterations} iterations, "
        f"solver {stats.solver or analysis['solver']}{tried}). No solution was saved."
    )
    if sol is not None and sol.time_domain:
        return f"{text}\n{sol.time_domain}"
    return text + " Try a larger max_iter, another solver (powell, newton, hybr) or another eps."


def _periodic_summary(sol: PeriodicSolution, ds: xr.Dataset, analysis: dict, where: str
                      ) -> str:
    st = sol.stats
    w = ds["contact_area"].values / ds["contact_area"].values.sum()
    frac = w @ sol.state_fractions()
    lines = [
        f"periodic at {where}: converged in {st.iterations} iterations ({st.solver}, relative "
        f"residual {st.residual:.2e}, {st.wall_time:.2f} s); eps = {sol.eps:.4g} N/m "
        f"({analysis['eps']})",
        f"interface ({sol.state.shape[0]} nodes): "
        + ", ".join(f"{n} {100 * x:.1f} %" for n, x in zip(STATE_NAMES, frac, strict=True))
        + f" of contact area x period; friction energy "
        f"{float(ds['total_dissipated_energy']):.4g} J per cycle",
    ]
    for name in ds["point"].values:
        amp = ds["displacement_harmonic_amplitude"].sel(point=name)
        stops = ds["stops_per_period"].sel(point=name)
        parts = []
        for axis in ds["axis"].values:
            a = amp.sel(axis=axis).values
            if np.all(np.isnan(a)):
                continue
            parts.append(f"{axis}: |u_{sol.basis.harmonics[0]}| = {a[0]:.4g} m, "
                         f"{int(stops.sel(axis=axis))} stops/period")
        lines.append(f"{name}: " + "; ".join(parts))
    return "\n".join(lines)


def run_periodic(model, analysis: dict, case, context: RunContext) -> RunOutput:
    """Periodic response at one frequency (:func:`fretwear.hb.periodic.solve_periodic`).

    Parameters
    ----------
    model : the model; analysis : the validated ``[analysis]`` table; case : the case;
    context : results folder (progress: unused, a single solve).

    Returns
    -------
    RunOutput; ``success`` False (and no solution variables) when the solve failed.
    """
    basis = basis_of(analysis)
    qs = analysis["quasi_static"]
    f_hz = float(analysis.get("frequency", QUASI_STATIC_FREQUENCY))
    # the run's condensation of the model (the case file's choice), for every call
    cond = condenser_of(model, analysis, None if qs else f_hz, max(basis.harmonics))
    reduced = condense(model, f_hz, basis.orders, quasi_static=qs, condenser=cond)
    eps = penalty(analysis["eps"], model=model, reduced=reduced, condenser=cond)
    sol = api.solve_periodic(model, basis, frequency=f_hz, quasi_static=qs,
                             options=solve_options_of(analysis, PERIODIC_SOLVE), reduced=reduced,
                             eps=eps, time_domain=analysis["time_domain"], condenser=cond)
    stats = sol.stats
    attrs = {**solver_attributes(stats, analysis, eps), "excitation_frequency": f_hz,
             "quasi_static": int(qs),
             "attempts": "; ".join(f"{a.method}/{a.solver}/{'yes' if a.success else 'no'}/"
                                   f"{a.residual:.1e}" for a in sol.attempts),
             "time_domain": sol.time_domain, **cond.choice.attributes()}
    where = _frequency_text(f_hz, qs)
    verdict = ""
    if sol.success and analysis["hill_stability"] and not qs:
        verdict, hill_attrs = hill_verdict(model, sol, cond)
        attrs.update(hill_attrs)
    slow_line = ""
    if sol.success and not qs:
        slow_line, slow_attrs = slow_verdict(model, sol, cond)
        attrs.update(slow_attrs)
    if not sol.success:  # never saved as a result: the diagnostics only
        return RunOutput(xr.Dataset(attrs=attrs), [],
                         _failure_summary(stats, analysis, where, sol), False,
                         warnings=list(sol.warnings))
    points = [p.name for p in model.observed]
    ds = periodic_dataset(model, sol, points)
    ds.attrs.update(attrs)
    figures = periodic_figures(ds, case, context.out_dir, titled(case.title, where))
    files = []
    if output_mesh(model) is not None and case.output["vtu"]:
        files.append(write_period_fields(model, sol, context.out_dir / "periodic.pvd",
                                         condenser=cond))
    if model.meta.get("cyclic") is not None and case.output.get("whole_disk"):
        files.append(write_disk_fields(model, sol, context.out_dir / "periodic-disk.pvd",
                                       condenser=cond))
    summary = _periodic_summary(sol, ds, analysis, where)
    if verdict:
        summary += "\n" + verdict
    if slow_line:
        summary += "\n" + slow_line
    if case.output["vtu"] and no_fields_line(model):
        summary += "\n" + no_fields_line(model)
    fallback = fallbacks.of_solutions([sol], sol.stats.wall_time).line(
        "solves", fallbacks.eps_hint("eps" in analysis))
    if fallback:
        summary += "\n" + fallback
    return RunOutput(ds, figures, summary + "\n" + cond.choice.summary(), True, files,
                     warnings=list(sol.warnings))


def slow_verdict(model, sol: PeriodicSolution, cond) -> tuple[str, dict]:
    """Is the state held only weakly along some direction (:func:`fretwear.hb.slow_mode.
    slow_mode`: the balance's near-null direction, e.g. the interface's mean tangential
    position where every node slips at some instant)? The attribute ``slow_multiplier`` (its
    real Floquet multiplier nearest 1; NaN: no such direction, or not computed) and a summary
    line where a start elsewhere relaxes to the state over more than
    :data:`fretwear.hb.slow_mode.SLOW_PERIODS` periods or moves away from it (empty
    otherwise)."""
    attrs = {"slow_multiplier": float("nan")}
    if sol.U.size > DENSE_MAX:  # Hill's matrix is formed densely: not computed (before the
        return "", attrs  # condensation and the structure's matrices are built for it)
    try:
        prob = problem_of(model, sol, condenser=cond)
        sm = slow_mode(prob, sol.U.reshape(prob.m, prob.H), structure_dynamics(model, cond))
    except (InputError, np.linalg.LinAlgError):  # beyond the dense Hill matrix, a sector, a
        return "", attrs  # singular structure with its contact held, ...: not computed
    attrs["slow_multiplier"] = sm.multiplier
    if sm.multiplier > 1 or sm.slow():
        return sm.line(), attrs
    return "", attrs


def hill_verdict(model, sol: PeriodicSolution, cond) -> tuple[str, dict]:
    """What the converged periodic state is, by Hill's method
    (:func:`fretwear.hb.stability.stability`): one summary line and the attributes
    ``hill_stable`` (1 stable, 0 unstable, -1 not computed or undecided: the largest
    multiplier an unrefined candidate), ``floquet_multipliers`` (the
    largest few, text), ``neutral_directions`` (tangential directions of nodes that stick all
    period: the state is then one member of a family of stuck states, which the anchors
    select and a time integration need not reach) and ``stability_notes`` (why not
    computed)."""
    attrs = {"hill_stable": -1, "floquet_multipliers": "", "neutral_directions": -1,
             "stability_notes": ""}
    try:
        fl = stability(model, sol, condenser=cond)
    except InputError as exc:
        attrs["stability_notes"] = str(exc)
        return (f"stability by Hill's method not computed: {exc}. The state is a periodic "
                "solution of the truncated balance; whether the structure settles to it is "
                "not known (a time integration from it: fretwear.timedomain.check_periodic)",
                attrs)
    crit = fl.critical(3)
    text = ", ".join(f"{abs(r):.4g}" + ("" if abs(r.imag) <= 1e-6 * abs(r) else
                                         f" (arg {np.degrees(np.angle(r)):.1f} deg)")
                     for r in crit)
    attrs.update(hill_stable=int(fl.stable), floquet_multipliers=text,
                 neutral_directions=int(fl.neutral))
    top = int(np.argmax(np.abs(fl.multipliers))) if fl.multipliers.size else -1
    confirmed = top < 0 or fl.kind[top] != "candidate"
    if not fl.stable and not confirmed:
        line = (f"stability UNDECIDED by Hill's method: the largest multiplier, |rho| = "
                f"{fl.max_multiplier:.4g}, is an unrefined candidate of the frozen-memory "
                "problem or of the truncated interior (raise the refinement, "
                "fretwear.hb.stability.HillOptions(refine=), or integrate in time from the "
                "state: fretwear.timedomain.check_periodic)")
        attrs["hill_stable"] = -1
    elif not fl.stable:
        r = crit[0]
        how = ("a real multiplier above 1 (a fold's middle branch)" if r.real > 0 and
               abs(r.imag) <= 1e-6 * abs(r) else "a real multiplier below -1 (period "
               "doubling)" if abs(r.imag) <= 1e-6 * abs(r) else "a complex pair outside the "
               "unit circle (Neimark-Sacker: a quasi-periodic response)")
        line = (f"UNSTABLE by Hill's method: {how}, |rho| = {abs(r):.4g}; the structure "
                "does not stay on this state, a time integration leaves it")
    else:
        line = f"stable by Hill's method (largest |rho| {fl.max_multiplier:.4g})"
    if fl.neutral:
        line += (f"; {fl.neutral} tangential direction(s) of nodes that stick all period are "
                 "neutral (multiplier 1): the state is one member of a family of stuck states "
                 "(the static anchors select it), and a time integration may settle on "
                 "another member")
    if not fl.reliable:
        line += "; some exponents were not refined (Floquet candidates only)"
    return line, attrs


def periodic_figures(ds: xr.Dataset, case, outdir: Path, title: str) -> list[Path]:
    """The figures of a periodic run (``case.output``: whether and in which format)."""
    figures = []
    for point in ds["point"].values:
        p = figure_path(case, outdir, f"periodic-{point}")
        if p is not None:
            figures.append(plot_observed_period(ds, p, str(point), title=title))
    for stem, plot in (("contact-state", plots.plot_state_map), ("contact-profiles", plot_profiles),
                       ("hysteresis", plot_hysteresis)):
        p = figure_path(case, outdir, stem)
        if p is not None:
            figures.append(plot(ds, p, title=title))
    p = figure_path(case, outdir, "interface-maps")
    if p is not None and plots.wants_interface_maps(ds):
        state = ds["contact_state"].values
        fields = [("mean pressure", ds["pressure_mean"].values, "Pa"),
                  ("max pressure", ds["pressure_max"].values, "Pa"),
                  ("stick fraction", np.mean(state == 1, axis=1), "-"),
                  ("slip path", ds["slip_path"].values, "m")]
        figures.append(plots.plot_interface_maps(ds, fields, p, title=title))
    return figures


def write_period_fields(model, sol: PeriodicSolution, pvd: Path, *, condenser=None) -> Path:
    """ParaView time series of the whole displacement field over one period.

    Every DOF is recovered from the contact solution (:func:`fretwear.hb.reduce.recover`, exact)
    and sampled at the ``N`` instants of the period: one ``.vtu`` per instant in the folder
    ``pvd.stem`` (point arrays ``displacement`` [m], ``contact_state`` and
    ``contact_pressure`` [Pa] on both surfaces of node-to-node pairs, NaN off the
    interfaces), stepped through by the ``.pvd`` with
    the time [s] as time step; on the mesh, or on the node file's points of a model from FE
    matrices (:func:`fretwear.io.results.output_mesh`). ``condenser``: the condenser that
    condensed ``sol`` (:func:`fretwear.hb.reduce.exact_condenser`; None: a new exact one).

    Returns
    -------
    The ``.pvd`` file.
    """
    b = sol.basis
    nc, d, H = sol.U.shape
    u_loc = b.to_complex(sol.U.reshape(nc * d, H))  # (k+1, m), orders [0, h1, ..]
    full = recover(model, sol.frequency, b.orders, u_loc, quasi_static=sol.quasi_static,
                   condenser=condenser)
    samples = b.to_time(b.from_complex(full))  # (ndof, N)
    mesh = output_mesh(model)
    nn = mesh.points.shape[0]
    nodes = mesh.point_index(model.contact.node_ids)
    state = np.full((nn, b.n_samples), np.nan)
    pressure = np.full((nn, b.n_samples), np.nan)
    state[nodes] = sol.state
    pressure[nodes] = sol.pressure_t()
    c = model.contact
    if c.has_pairs:  # both surfaces of a pair: its partner node shows the same contact
        pair = c.paired()
        partners = mesh.point_index(np.asarray(c.partner_ids)[pair])
        state[partners] = sol.state[pair]
        pressure[partners] = sol.pressure_t()[pair]
    folder = pvd.parent / pvd.stem
    entries = []
    for j, t in enumerate(sol.time):
        path = write_vtu(folder / f"period-{j:03d}.vtu", mesh,
                         {"displacement": nodal_vectors(mesh, samples[:, j]),
                          "contact_state": state[:, j], "contact_pressure": pressure[:, j]},
                         {"time": t, "tau": b.tau[j]})
        entries.append((t, path))
    return write_pvd(pvd, entries)


def write_disk_fields(model, sol: PeriodicSolution, pvd: Path, *, condenser) -> Path:
    """ParaView time series of the whole tuned disk over one period, rebuilt from the
    sector's solution (``model.meta["cyclic"]``, its engine order ``model.meta
    ["engine_order"]``; :func:`fretwear.model.cyclic.disk_harmonics` on the sector's DOFs
    recovered by ``condenser``): one ``.vtu`` per instant on the mesh of
    :func:`fretwear.model.cyclic.disk_mesh`, with the point arrays ``displacement`` [m] (the
    disk's axes) and ``sector`` (the sector number of each node), stepped through by the
    ``.pvd`` with the time [s] as time step.

    Returns
    -------
    The ``.pvd`` file.
    """
    from fretwear.model.cyclic import disk_harmonics, disk_mesh

    sector = model.meta["cyclic"]
    b = sol.basis
    nc, d, H = sol.U.shape
    u_loc = b.to_complex(sol.U.reshape(nc * d, H))
    full = recover(model, sol.frequency, b.orders, u_loc, quasi_static=sol.quasi_static,
                   condenser=condenser)  # (k+1, ndof) of sector 0
    per = disk_harmonics(sector, model.meta["engine_order"], b.orders, full)
    mesh = disk_mesh(sector)
    nn = model.mesh.points.shape[0]
    samples = np.concatenate([b.to_time(b.from_complex(u)) for u in per])  # (N ndof, ns)
    which = np.repeat(np.arange(sector.n_sectors), nn).astype(float)
    folder = pvd.parent / pvd.stem
    entries = []
    for j, t in enumerate(sol.time):
        path = write_vtu(folder / f"disk-{j:03d}.vtu", mesh,
                         {"displacement": nodal_vectors(mesh, samples[:, j]), "sector": which},
                         {"time": t, "tau": b.tau[j]})
        entries.append((t, path))
    return write_pvd(pvd, entries)


# --- figures -------------------------------------------------------------------------------
def _stopped_spans(v: np.ndarray, tol: float = STOP_TOL) -> list[tuple[int, int]]:
    """Runs ``(first, last)`` of samples where ``|v| <= tol * max |v|`` (not wrapped)."""
    va = np.abs(v)
    stopped = va <= tol * max(float(va.max()), 1e-300)
    spans, start = [], None
    for j, s in enumerate(stopped):
        if s and start is None:
            start = j
        if not s and start is not None:
            spans.append((start, j - 1))
            start = None
    if start is not None:
        spans.append((start, len(v) - 1))
    return spans


def plot_observed_period(ds: xr.Dataset, path: Path, point: str, *, title: str | None = None
                         ) -> Path:
    """Displacement and velocity of an observed point over one period (cf. paper Fig. 16).

    One column per axis; the displacement is drawn about its mean (given in the panel title:
    a static offset would hide the vibration); grey bands mark the intervals where the point
    stops (|v| below ``STOP_TOL`` of its peak); the time axis is ``t / T`` (fraction of the
    period).
    """
    axes_names = live_axes(ds, point)
    fig, axes = plots.new_figure(2, max(len(axes_names), 1), title=title, sharex=True)
    n = ds.sizes["tau"]
    t = np.append(ds["tau"].values, 2 * np.pi) / (2 * np.pi)
    for col, axis in enumerate(axes_names):
        u = ds["displacement"].sel(point=point, axis=axis).values
        v = ds["velocity"].sel(point=point, axis=axis).values
        mean = float(u.mean())
        for row, (y, name, unit) in enumerate(((u - mean, "u", "m"), (v, "v", "m/s"))):
            ax = axes[row, col]
            k, unit = si_scale(y, unit)
            ax.plot(t, k * np.append(y, y[0]), color="tab:blue")
            for a, b in _stopped_spans(v):
                ax.axvspan(a / n, (b + 1) / n, color="0.85", lw=0)
            ax.set_ylabel(f"{name}_{axis}{' - mean' if name == 'u' else ''} at {point} "
                          f"[{unit}]")
            ax.grid(True, alpha=0.3)
        stops = int(ds["stops_per_period"].sel(point=point, axis=axis))
        km, um = si_scale(mean, "m")
        axes[0, col].set_title(f"{axis}: mean {km * mean:.4g} {um}, {stops} stop(s) per period"
                               + (" (grey)" if stops else ""), fontsize="medium")
        axes[1, col].set_xlabel("t / T [-] (fraction of the period)")
    return plots.save(fig, path)


def plot_profiles(ds: xr.Dataset, path: Path, *, title: str | None = None) -> Path:
    """Normal pressure, slip and friction energy along the interface."""
    x, xlabel = interface_abscissa(ds)
    o = np.argsort(x, kind="stable")
    fig, axes = plots.new_figure(3, 1, title=title, panel_size=(7.0, 2.6), sharex=True)
    ax = axes[0, 0]
    k, unit = si_scale(ds["pressure_max"].values, "Pa")
    marked = x.size <= MARKED_POINTS
    first, second = series_style(0, 2, markers=marked), series_style(1, 2, markers=marked)
    ax.plot(x[o], k * ds["pressure_mean"].values[o], label="mean", **first)
    ax.plot(x[o], k * ds["pressure_max"].values[o], label="maximum", **second)
    ax.set_ylabel(f"normal pressure [{unit}]")
    ax.legend(fontsize="small")
    ax = axes[1, 0]
    k, unit = si_scale(ds["slip_path"].values, "m")
    ax.plot(x[o], k * ds["slip_amplitude"].values[o], color="tab:orange",
            label="slip amplitude (half range, T1)", **first)
    ax.plot(x[o], k * ds["slip_path"].values[o], color="tab:red",
            label="slip path per period", **second)
    ax.set_ylabel(f"slip [{unit}]")
    ax.legend(fontsize="small")
    ax = axes[2, 0]
    k, unit = si_scale(ds["dissipated_energy"].values, "J")
    ax.plot(x[o], k * ds["dissipated_energy"].values[o], marker=".", color="tab:purple")
    ax.set_ylabel(f"friction energy\nper period [{unit}]")
    ax.set_xlabel(xlabel)
    for ax in axes[:, 0]:
        ax.grid(True, alpha=0.3)
    return plots.save(fig, path)


def loop_nodes(energy: np.ndarray, n: int = 4) -> list[int]:
    """Up to ``n`` contact nodes for hysteresis loops, in interface order: the ``n - 1`` most
    dissipative ones (nodes that slip) and the least dissipative one (a stuck node, for
    contrast); nodes evenly spaced along the interface when none slips."""
    nc = energy.size
    if not np.any(energy > 0):
        return sorted({int(i) for i in np.linspace(0, nc - 1, min(n, nc)).round()})
    ranked = np.argsort(-energy, kind="stable")
    slipping = [int(i) for i in ranked[: n - 1] if energy[i] > 0]
    picks = set(slipping) | {int(ranked[-1])}
    return sorted(picks)


def plot_hysteresis(ds: xr.Dataset, path: Path, *, title: str | None = None) -> Path:
    """Tangential force against corrected tangential displacement (T1) over one period for a
    few nodes: the loop area is the energy dissipated by friction."""
    nodes = loop_nodes(ds["dissipated_energy"].values)
    x, xlabel = interface_abscissa(ds)
    ncols = min(2, len(nodes))
    nrows = -(-len(nodes) // ncols)
    fig, axes = plots.new_figure(nrows, ncols, title=title, panel_size=(4.8, 3.6))
    x_all = ds["corrected_displacement"].sel(component="T1").values
    f_all = ds["contact_force"].sel(component="T1").values
    for j, ax in enumerate(axes.ravel()):
        if j >= len(nodes):
            ax.set_axis_off()
            continue
        i = nodes[j]
        xt = x_all[i] - x_all[i].mean()
        kx, ux = si_scale(xt, "m")
        kf, uf = si_scale(f_all[i], "N")
        ax.plot(kx * np.append(xt, xt[0]), kf * np.append(f_all[i], f_all[i][0]),
                color="tab:red")
        ax.plot(kx * xt[0], kf * f_all[i][0], "o", color="tab:red", ms=4, label="t = 0")
        where = f"{x[i]:.4g} m" if xlabel.endswith("[m]") else f"#{i}"
        ke, ue = si_scale(ds["dissipated_energy"].values[i], "J")
        ax.set_title(f"node {i} at {where}: {ke * float(ds['dissipated_energy'][i]):.3g} "
                     f"{ue} per period", fontsize="medium")
        ax.set_xlabel(f"corrected tangential displacement X_T1 - mean [{ux}]")
        ax.set_ylabel(f"tangential force [{uf}]")
        ax.grid(True, alpha=0.3)
    return plots.save(fig, path)


# --- registration ---------------------------------------------------------------------------
def _frequency_needed(out: dict, path: str) -> None:
    """Rule: ``frequency`` is required unless ``quasi_static``."""
    if not out.get("quasi_static") and "frequency" not in out:
        raise InputError(f"missing required key {join(path, 'frequency')!r} (excitation "
                         "frequency [Hz]: a number > 0; only a quasi_static analysis can do "
                         "without)")


_EPS_RULES = ('"auto": the spectral radius of Z_r over the kept harmonics (the paper); '
              '"top": that of Z_r at the highest kept harmonic; "stiff": ten times "top"; '
              '"contact": "stiff" on rigid sliders under a prescribed normal load, "top" '
              'elsewhere; '
              '"static": that of the static '
              "reduced stiffness K_r; or a value")

PERIODIC = Analysis.define(
    "periodic",
    {
        "frequency": Field(Number(lo=0, lo_open=True), "excitation frequency (required unless "
                           "quasi_static; then it only scales time, default 1 Hz)", unit="Hz"),
        "quasi_static": Field(Flag(), "drop inertia and damping (slow cyclic loading); the "
                              "friction law stays path dependent over the period",
                              default=default_of(solve_periodic, "quasi_static")),
        "time_domain": Field(Flag(), "where every attempt of the solve strategy fails, "
                             "integrate in time from rest: a periodic steady state starts one "
                             "more solve, any other response (drifting, quasi-periodic) is "
                             "reported as the reason", default=default_of(api.solve_periodic,
                                                                          "time_domain")),
        "time_domain_periods": Field(Integer(lo=10), "forcing periods allowed to the time "
                                     "integration (time_domain)",
                                     default=PERIODIC_SOLVE.time_domain_periods),
        "hill_stability": Field(Flag(), "what the converged state is, by Hill's method on the "
                                "balance's Jacobian: stable, unstable (and how), or one member "
                                "of a family of stuck states; in the summary and the "
                                "attributes `hill_stable`, `floquet_multipliers`, "
                                "`neutral_directions`, `stability_notes`. Dense on the contact "
                                "DOFs (a few hundred, times the harmonics; a large interior "
                                "enters through its low modes)",
                                default=False),
        **harmonic_balance_fields(PERIODIC_SOLVE, default_of(solve_periodic, "eps"),
                                  "DLFT penalty: " + _EPS_RULES),
    },
    run_periodic,
    checks=(_frequency_needed, check_sampling),
    doc="Periodic response at one frequency with the frictional interface (DLFT, paper "
    "section 3). A solve that does not converge saves no solution: `results.nc` then holds "
    "the solver diagnostics only, and the run exits with status 1. Writes "
    "`periodic-<point>.png` (displacement and velocity over a period; grey bands where the "
    "point stops), `contact-state.png` (separation/stick/slip along the interface over the "
    "period), `contact-profiles.png` (pressure, slip, friction energy along the interface), "
    "`hysteresis.png` (tangential force against slip for a few nodes) and, for meshes, "
    "`periodic.pvd` (the displacement field over the period; ParaView's time slider plays it); "
    "for a sector with `[output] whole_disk = true`, `periodic-disk.pvd` (the whole disk "
    "rebuilt from the sector).",
    preload_check=True,
)

