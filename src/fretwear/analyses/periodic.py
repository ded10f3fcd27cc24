"""The DLFT analyses of case files: ``"periodic"`` (one frequency) and ``"sweep"`` (nonlinear FRF).

Each run function calls the solver (:func:`fretwear.hb.periodic.solve_periodic`,
:func:`fretwear.hb.sweep.sweep`), turns its result into a results dataset (schema in
``docs/results.md``), figures and ParaView files, and registers itself with
:mod:`fretwear.analyses.registry`.

A periodic solve that did not converge is never saved as a result: the run writes a results
file with the solver diagnostics as attributes and no solution variables, and reports the
failure (``converged = 0``, exit status 1). In a sweep, points that did not converge are kept
as NaN with ``converged = 0`` and the reason in ``flags``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.patches import Patch
from tqdm import tqdm

from fretwear import linear
from fretwear.analyses import figures as plots
from fretwear.analyses.linear import _check_points, _figure_path, _geometry
from fretwear.analyses.registry import RunOutput, register
from fretwear.errors import InputError
from fretwear.hb.contact import STATE_NAMES
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.periodic import PeriodicSolution, solve_periodic
from fretwear.hb.reduce import condense, recover
from fretwear.hb.solvers import SOLVERS, SolveStats
from fretwear.hb.sweep import SweepResult, sweep
from fretwear.io.results import label_coordinate, nodal_vectors, variable, write_pvd, write_vtu
from fretwear.io.schema import (
    AnyOf,
    Field,
    Flag,
    Integer,
    ListOf,
    Number,
    Text,
    fail,
    increasing,
    join,
)
from fretwear.timedomain.fallback import FALLBACK
from fretwear.timedomain.stability import sweep_check

#: colours of the contact states (separation, stick, slip) in every figure
STATE_COLOURS = ("0.85", "tab:blue", "tab:orange")
STOP_TOL = 5e-2  # |v| below this fraction of its peak counts as stopped (as stops_per_period)


# --- [analysis] keys shared by both analyses ----------------------------------------------
def harmonic_list(value) -> list[int]:
    """Kept harmonics from the ``harmonics`` key: ``Nh`` -> ``[1..Nh]``, a list -> sorted."""
    if isinstance(value, int):
        return list(range(1, value + 1))
    return sorted(int(h) for h in value)


def basis_of(analysis: dict) -> FourierBasis:
    """The Fourier basis an ``[analysis]`` table asks for."""
    return FourierBasis(tuple(harmonic_list(analysis["harmonics"])), analysis["n_samples"])


def _check_sampling(out: dict, path: str) -> None:
    """Rule: ``n_samples`` exceeds twice the highest kept harmonic (no aliasing)."""
    if "harmonics" not in out or "n_samples" not in out:
        return
    top = max(harmonic_list(out["harmonics"]))
    if out["n_samples"] <= 2 * top:
        fail(join(path, "n_samples"), out["n_samples"],
             f"more than {2 * top} samples per period (twice the highest harmonic, {top})")


def _common_fields(eps_default: str, eps_doc: str, max_iter: int) -> dict:
    return {
        "harmonics": Field(
            AnyOf((Integer(lo=1), ListOf(Integer(lo=1), non_empty=True, unique=True))),
            "kept harmonics: Nh keeps 1, 2, .., Nh; a list keeps those listed (e.g. [1, 3, 5])",
            default=7),
        "n_samples": Field(Integer(lo=3), "time samples per period N of the contact law "
                           "(more than twice the highest harmonic)", default=128),
        "eps": Field(AnyOf((Text(("auto", "static")), Number(lo=0, lo_open=True))), eps_doc,
                     default=eps_default, unit="N/m"),
        "solver": Field(Text(SOLVERS), '"powell" (hybrid dog-leg, LAPACK), "newton" (damped '
                        'Newton) or "hybr" (MINPACK hybrj, as in the paper)', default="powell"),
        "tol": Field(Number(lo=0, lo_open=True), "relative residual of the convergence test "
                     "|f(U)| <= tol |Z_r U| (paper section 3.2)", default=1e-8, unit="-"),
        "max_iter": Field(Integer(lo=1), "maximum solver iterations per frequency",
                          default=max_iter),
    }


def _penalty(model, eps, omega: float, basis: FourierBasis, quasi_static: bool = False,
             reduced=None) -> float:
    """The DLFT penalty [N/m] of the ``eps`` key: ``"auto"`` the spectral radius of ``Z_r``
    over the kept harmonics (paper), ``"static"`` that of the static ``K_r``, or the number."""
    if eps == "auto":
        red = reduced if reduced is not None else condense(model, omega, basis.orders,
                                                           quasi_static=quasi_static)
        return red.spectral_radius()
    if eps == "static":
        return condense(model, 0.0, [0], quasi_static=True).spectral_radius()
    return float(eps)


def _solver_attributes(stats: SolveStats, analysis: dict, eps: float) -> dict:
    """Solver settings and statistics as NetCDF attributes (numbers and strings only)."""
    return {
        "solver": str(stats.solver or analysis["solver"]),
        "solver_message": str(stats.message),
        "residual": float(stats.residual),
        "tol": float(analysis["tol"]),
        "iterations": int(stats.iterations),
        "nfev": int(stats.nfev),
        "njev": int(stats.njev),
        "wall_time": float(stats.wall_time),
        "eps": float(eps),
        "eps_rule": str(analysis["eps"]),
        "harmonics": ", ".join(str(h) for h in harmonic_list(analysis["harmonics"])),
        "n_samples": int(analysis["n_samples"]),
    }


def titled(title: str, suffix: str) -> str:
    """``"title: suffix"``, or ``title`` when it already says ``suffix``."""
    return title if suffix.lower() in title.lower() else f"{title}: {suffix}"


# --- small array helpers -------------------------------------------------------------------
def _pad_axes(arrays: list[np.ndarray], n_axes: int) -> np.ndarray:
    """Stack per-point arrays ``(d_p, ...)`` into ``(n_points, n_axes, ...)``, NaN-padded."""
    trailing = arrays[0].shape[1:] if arrays else ()
    out = np.full((len(arrays), n_axes) + trailing, np.nan)
    for i, a in enumerate(arrays):
        out[i, : a.shape[0]] = a
    return out


def _period_coordinates(basis: FourierBasis) -> dict:
    return {
        "harmonic_coefficient": label_coordinate("harmonic_coefficient", basis.labels()),
        "tau": variable("tau", basis.tau, "rad", "angle tau = omega t over one period"),
        "harmonic": variable("harmonic", np.asarray(basis.harmonics), "1",
                             "kept harmonic number"),
    }


# --- periodic: dataset ----------------------------------------------------------------------
def _observed_variables(sol: PeriodicSolution, points: list[str], n_axes: int) -> dict:
    """Displacement and velocity of the observed points over a period, per harmonic."""
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
            pa + ("harmonic_coefficient",), _pad_axes(coeffs, n_axes), "m",
            "Fourier coefficients of the displacement of the observed point"),
        "displacement": variable(pa + ("tau",), _pad_axes(disp, n_axes), "m",
                                 "displacement of the observed point over one period"),
        "velocity": variable(pa + ("tau",), _pad_axes(vel, n_axes), "m/s",
                             "velocity of the observed point over one period"),
        "displacement_harmonic_amplitude": variable(
            pa + ("harmonic",), _pad_axes(amp, n_axes), "m",
            "amplitude of each kept harmonic of the displacement of the observed point"),
        "stops_per_period": variable(
            pa, _pad_axes(stops, n_axes), "1",
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
    coords, data = _geometry(model, points)
    coords.update(_period_coordinates(sol.basis))
    data.update(_observed_variables(sol, points, coords["axis"].size))
    data.update(_contact_variables(sol))
    return xr.Dataset(data, coords=coords)


# --- periodic: run --------------------------------------------------------------------------
def _frequency_text(f_hz: float, quasi_static: bool) -> str:
    return "quasi-static loading" if quasi_static else plots.format_frequency(f_hz)


def _failure_summary(stats: SolveStats, analysis: dict, where: str) -> str:
    return (
        f"periodic solve at {where} did not converge: {stats.message} (relative residual "
        f"{stats.residual:.3g} > tol {analysis['tol']:g} after {stats.iterations} iterations, "
        f"solver {stats.solver or analysis['solver']}). No solution was saved. Try a larger "
        "max_iter, another solver (powell, newton, hybr) or another eps."
    )


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


def run_periodic(model, analysis: dict, case, outdir: Path, progress: bool) -> RunOutput:
    """Periodic response at one frequency (:func:`fretwear.hb.periodic.solve_periodic`).

    Parameters
    ----------
    model : the model; analysis : the validated ``[analysis]`` table; case : the case;
    outdir : results folder; progress : unused (a single solve).

    Returns
    -------
    RunOutput; ``converged`` False (and no solution variables) when the solve failed.
    """
    basis = basis_of(analysis)
    qs = analysis["quasi_static"]
    f_hz = float(analysis.get("frequency", 1.0))
    omega = 2 * np.pi * f_hz
    reduced = condense(model, omega, basis.orders, quasi_static=qs)
    eps = _penalty(model, analysis["eps"], omega, basis, qs, reduced)
    sol, stats = solve_periodic(model, basis, omega=omega, quasi_static=qs, reduced=reduced,
                                eps=eps, solver=analysis["solver"], tol=analysis["tol"],
                                max_iter=analysis["max_iter"])
    attrs = {**_solver_attributes(stats, analysis, eps), "excitation_frequency": f_hz,
             "quasi_static": int(qs)}
    where = _frequency_text(f_hz, qs)
    if sol is None:
        return RunOutput(xr.Dataset(attrs=attrs), [], _failure_summary(stats, analysis, where),
                         False)
    points = [p.name for p in model.observed]
    ds = periodic_dataset(model, sol, points)
    ds.attrs.update(attrs)
    figures = _periodic_figures(ds, case, outdir, titled(case.title, where))
    files = []
    if model.mesh is not None and case.output["vtu"]:
        files.append(write_period_fields(model, sol, outdir / "periodic.pvd"))
    return RunOutput(ds, figures, _periodic_summary(sol, ds, analysis, where), True, files)


def _periodic_figures(ds: xr.Dataset, case, outdir: Path, title: str) -> list[Path]:
    figures = []
    for point in ds["point"].values:
        p = _figure_path(case, outdir, f"periodic-{point}")
        if p is not None:
            figures.append(plot_observed_period(ds, p, str(point), title=title))
    for stem, plot in (("contact-state", plot_state_map), ("contact-profiles", plot_profiles),
                       ("hysteresis", plot_hysteresis)):
        p = _figure_path(case, outdir, stem)
        if p is not None:
            figures.append(plot(ds, p, title=title))
    return figures


def write_period_fields(model, sol: PeriodicSolution, pvd: Path) -> Path:
    """ParaView time series of the whole displacement field over one period.

    Every DOF is recovered from the contact solution (:func:`fretwear.hb.reduce.recover`, exact)
    and sampled at the ``N`` instants of the period: one ``.vtu`` per instant in the folder
    ``pvd.stem`` (point arrays ``displacement`` [m], ``contact_state`` and
    ``contact_pressure`` [Pa], NaN off the interface), stepped through by the ``.pvd`` with
    the time [s] as time step.

    Returns
    -------
    The ``.pvd`` file.
    """
    b = sol.basis
    nc, d, H = sol.U.shape
    u_loc = b.to_complex(sol.U.reshape(nc * d, H))  # (k+1, m), orders [0, h1, ..]
    full = recover(model, sol.omega, b.orders, u_loc, quasi_static=sol.quasi_static)
    samples = b.to_time(b.from_complex(full))  # (ndof, N)
    mesh = model.mesh
    nn = mesh.points.shape[0]
    nodes = np.asarray(model.contact.node_ids)
    state = np.full((nn, b.n_samples), np.nan)
    pressure = np.full((nn, b.n_samples), np.nan)
    state[nodes] = sol.state
    pressure[nodes] = sol.pressure_t()
    folder = pvd.parent / pvd.stem
    entries = []
    for j, t in enumerate(sol.time):
        path = write_vtu(folder / f"period-{j:03d}.vtu", mesh,
                         {"displacement": nodal_vectors(mesh, samples[:, j]),
                          "contact_state": state[:, j], "contact_pressure": pressure[:, j]},
                         {"time": t, "tau": b.tau[j]})
        entries.append((t, path))
    return write_pvd(pvd, entries)


# --- periodic: figures ----------------------------------------------------------------------
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


def _live_axes(ds: xr.Dataset, point: str) -> list[str]:
    """The axes ``point`` has (``point_position`` is NaN on the others)."""
    pos = ds["point_position"].sel(point=point)
    return [str(a) for a in ds["axis"].values if np.isfinite(pos.sel(axis=a).values)]


def plot_observed_period(ds: xr.Dataset, path: Path, point: str, *, title: str | None = None
                         ) -> Path:
    """Displacement and velocity of an observed point over one period (cf. paper Fig. 16).

    One column per axis; the displacement is drawn about its mean (given in the panel title:
    a static offset would hide the vibration); grey bands mark the intervals where the point
    stops (|v| below ``STOP_TOL`` of its peak); the time axis is ``t / T`` (fraction of the
    period).
    """
    axes_names = _live_axes(ds, point)
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


def interface_abscissa(ds: xr.Dataset) -> tuple[np.ndarray, str]:
    """Where to draw each contact node along a figure's x axis, and the axis label.

    The coordinate along which a straight interface runs, if it runs along an axis; else the
    distance along the chain of nodes (2D); else the node number.
    """
    pos = ds["contact_position"].values
    nc = pos.shape[0]
    index = (np.arange(nc, dtype=float), "contact node")
    if nc < 2 or not np.all(np.isfinite(pos[:, :2])):
        return index
    live = [a for a in range(pos.shape[1]) if np.all(np.isfinite(pos[:, a]))]
    span = [a for a in live if np.ptp(pos[:, a]) > 0]
    if len(span) == 1 and np.unique(pos[:, span[0]]).size == nc:
        a = span[0]
        return pos[:, a], f"{ds['axis'].values[a]} [m]"
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pos[:, live], axis=0), axis=1))])
    if len(live) == 2 and np.all(np.diff(s) > 0):
        return s, "distance along the interface [m]"
    return index


def _edges(x: np.ndarray) -> np.ndarray:
    """Cell edges around increasing or decreasing centres ``x``."""
    if x.size == 1:
        return np.array([x[0] - 0.5, x[0] + 0.5])
    mid = 0.5 * (x[1:] + x[:-1])
    return np.concatenate([[2 * x[0] - mid[0]], mid, [2 * x[-1] - mid[-1]]])


_PREFIXES = {-15: "f", -12: "p", -9: "n", -6: "\u00b5", -3: "m", 0: "", 3: "k", 6: "M", 9: "G"}


def si_scale(values, unit: str) -> tuple[float, str]:
    """``(factor, prefixed unit)`` so that ``factor * values`` reads between 1 and 1000
    (e.g. ``1.2e-9 m`` -> ``1.2 nm``); ``(1, unit)`` when there is nothing to scale."""
    v = np.abs(np.asarray(values, dtype=float))
    v = v[np.isfinite(v) & (v > 0)]
    if v.size == 0:
        return 1.0, unit
    e = int(np.clip(3 * np.floor(np.log10(v.max()) / 3), -15, 9))
    return 10.0 ** -e, _PREFIXES[e] + unit


def plot_state_map(ds: xr.Dataset, path: Path, *, title: str | None = None) -> Path:
    """Contact state of every node over one period: separation, stick, slip."""
    x, xlabel = interface_abscissa(ds)
    order = np.argsort(x, kind="stable")
    n = ds.sizes["tau"]
    t_edges = (np.arange(n + 1) - 0.5) / n
    state = ds["contact_state"].values[order].T  # (N, nc)
    fig, axes = plots.new_figure(title=title, panel_size=(7.5, 4.0))
    ax = axes[0, 0]
    cmap = ListedColormap(STATE_COLOURS)
    ax.pcolormesh(_edges(x[order]), t_edges, state, cmap=cmap,
                  norm=BoundaryNorm([-0.5, 0.5, 1.5, 2.5], cmap.N), shading="flat")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("t / T [-] (fraction of the period)")
    handles = [Patch(facecolor=c, edgecolor="0.5", label=s)
               for c, s in zip(STATE_COLOURS, STATE_NAMES, strict=True)]
    ax.legend(handles=handles, title="contact state", loc="upper left",
              bbox_to_anchor=(1.01, 1.0), fontsize="small")
    return plots.save(fig, path)


def plot_profiles(ds: xr.Dataset, path: Path, *, title: str | None = None) -> Path:
    """Normal pressure, slip and friction energy along the interface."""
    x, xlabel = interface_abscissa(ds)
    o = np.argsort(x, kind="stable")
    fig, axes = plots.new_figure(3, 1, title=title, panel_size=(7.0, 2.6), sharex=True)
    ax = axes[0, 0]
    k, unit = si_scale(ds["pressure_max"].values, "Pa")
    ax.plot(x[o], k * ds["pressure_mean"].values[o], marker=".", label="mean")
    ax.plot(x[o], k * ds["pressure_max"].values[o], marker=".", linestyle="--",
            label="maximum")
    ax.set_ylabel(f"normal pressure [{unit}]")
    ax.legend(fontsize="small")
    ax = axes[1, 0]
    k, unit = si_scale(ds["slip_path"].values, "m")
    ax.plot(x[o], k * ds["slip_amplitude"].values[o], marker=".", color="tab:orange",
            label="slip amplitude (half range, T1)")
    ax.plot(x[o], k * ds["slip_path"].values[o], marker=".", linestyle="--", color="tab:red",
            label="slip path per period")
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


# --- sweep: dataset -------------------------------------------------------------------------
def _per_point(result: SweepResult, value, fill=np.nan, dtype=float) -> np.ndarray:
    """``value(point)`` for each converged sweep point (``fill`` elsewhere)."""
    return np.array([value(p) if p.converged else fill for p in result.points], dtype=dtype)


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


def _sweep_point_variables(result: SweepResult) -> dict:
    fr = np.array([_state_fractions(p.solution) if p.converged else np.full(3, np.nan)
                   for p in result.points]).reshape(-1, 3)
    f = "frequency"
    data = {
        "converged": variable(f, result.converged.astype(np.int8), "1",
                              "the periodic solve converged", flag_values=np.array(
                                  [0, 1], dtype=np.int8), flag_meanings="no yes"),
        "how": variable(f, np.array([p.how for p in result.points], dtype=str), "1",
                        "how the point was reached: grid, substep, retry, arclength, eps-x10, "
                        "time-start"),
        "flags": variable(f, np.array(["; ".join(p.flags) for p in result.points], dtype=str),
                          "1", "reasons for caution (empty: none)"),
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


def _linear_references(model, freqs: np.ndarray, interfaces: list[str], points: list[str],
                       n_axes: int) -> dict:
    """Amplitudes of the linear FRFs with the requested interfaces at the sweep frequencies."""
    amp = np.full((len(interfaces), freqs.size, len(points), n_axes), np.nan)
    for i, interface in enumerate(interfaces):
        r = linear.frf(model, freqs, interface=interface)
        for j, name in enumerate(points):
            u = np.abs(r.observed[name])
            amp[i, :, j, : u.shape[1]] = u
    return {"linear_response_amplitude": variable(
        ("interface", "frequency", "point", "axis"), amp, "m",
        "amplitude of the linear FRF with the interface held (stuck) or frictionless "
        "(sliding), harmonic 1 of the loads")}


def sweep_dataset(model, result: SweepResult, basis: FourierBasis, points: list[str],
                  references: list[str]) -> xr.Dataset:
    """The results dataset of a sweep (``docs/results.md``)."""
    coords, data = _geometry(model, points)
    freqs = result.frequency_hz
    coords["frequency"] = variable("frequency", freqs, "Hz", "excitation frequency")
    coords["harmonic"] = _period_coordinates(basis)["harmonic"]
    n_axes = coords["axis"].size
    data.update(_response_variables(result, basis, model, points, n_axes))
    data.update(_sweep_point_variables(result))
    if references:
        coords["interface"] = label_coordinate("interface", references)
        data.update(_linear_references(model, freqs, references, points, n_axes))
    return xr.Dataset(data, coords=coords)


# --- sweep: run -----------------------------------------------------------------------------
def _sweep_summary(result: SweepResult, ds: xr.Dataset) -> str:
    lines = [result.summary()]
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


def run_sweep(model, analysis: dict, case, outdir: Path, progress: bool) -> RunOutput:
    """Nonlinear FRF: periodic solutions over a frequency band (:func:`fretwear.hb.sweep.sweep`).

    Parameters
    ----------
    model : the model; analysis : the validated ``[analysis]`` table; case : the case;
    outdir : results folder; progress : show a progress bar.

    Returns
    -------
    RunOutput; ``converged`` False when some point did not converge.
    """
    points = _check_points(model, analysis.get("points"))
    basis = basis_of(analysis)
    eps = {"static": "static", "auto": "per-frequency"}.get(analysis["eps"], analysis["eps"])
    n = analysis["n_points"]
    with tqdm(total=n, desc="sweep", disable=not progress, leave=False, unit="freq") as bar:
        def tick(i, total, pt):
            bar.update(1)
            bar.set_postfix_str(f"{plots.format_frequency(pt.frequency_hz)}"
                                f"{'' if pt.converged else ' (not converged)'}")

        result = sweep(model, basis, analysis["f_min"], analysis["f_max"], n,
                       spacing=analysis["spacing"], eps=eps, solver=analysis["solver"],
                       tol=analysis["tol"], max_iter=analysis["max_iter"],
                       continuation=analysis["continuation"],
                       time_domain=FALLBACK if analysis["time_domain"] else None,
                       time_domain_periods=analysis["time_domain_periods"],
                       check=(sweep_check(model, max_periods=analysis["time_domain_periods"])
                              if analysis["check_stability"] else None),
                       progress=tick)
    ds = sweep_dataset(model, result, basis, points, analysis["linear_references"])
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
    })
    figures = []
    for point in points:
        p = _figure_path(case, outdir, f"sweep-{point}")
        if p is not None:
            figures.append(plot_sweep(ds, p, point, title=titled(case.title, "nonlinear FRF")))
    p = _figure_path(case, outdir, "sweep-interface")
    if p is not None:
        figures.append(plot_sweep_interface(ds, p, title=titled(case.title,
                                                                  "contact interface")))
    grid_ok = all(p.converged for p in result.points if p.on_grid)
    return RunOutput(ds, figures, _sweep_summary(result, ds), grid_ok)


# --- sweep: figures -------------------------------------------------------------------------
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


def plot_sweep(ds: xr.Dataset, path: Path, point: str, *, title: str | None = None) -> Path:
    """Nonlinear FRF at one observed point (log-log, one panel per axis), with the linear
    references of the dataset (cf. paper Fig. 14)."""
    axes_names = _live_axes(ds, point) or [str(ds["axis"].values[0])]
    fig, axes = plots.new_figure(len(axes_names), 1, title=title, panel_size=(7.5, 3.8),
                                 sharex=True)
    f = ds["frequency"].values
    h = int(ds["harmonic"].values[0])
    conv = ds["converged"].values.astype(bool)
    flagged = np.array([bool(s) for s in ds["flags"].values])
    for ax, axis in zip(axes[:, 0], axes_names, strict=True):
        if "linear_response_amplitude" in ds:
            for interface in ds["interface"].values:
                y = ds["linear_response_amplitude"].sel(interface=interface, point=point,
                                                        axis=axis).values
                ax.plot(f, np.where(y > 0, y, np.nan), label=f"linear, {interface}",
                        **plots.INTERFACE_STYLE.get(str(interface), {}))
        y = ds["response_amplitude"].sel(point=point, axis=axis, harmonic=h).values
        ax.plot(f, np.where(y > 0, y, np.nan), color="k", marker=".", ms=3,
                label=f"friction, harmonic {h}")
        half = 0.5 * ds["response_peak_to_peak"].sel(point=point, axis=axis).values
        ax.plot(f, np.where(half > 0, half, np.nan), color="0.5", lw=0.8, linestyle=":",
                label="friction, half peak-to-peak")
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
    ax.plot(f, np.where(e > 0, e, np.nan), color="tab:purple", marker=".", ms=3)
    _mark_failures(ax, f, conv, flagged, e)
    ax.set_yscale("log")
    ax.set_ylabel("friction energy\nper period [J]")
    if not conv.all() or (flagged & conv).any():
        ax.legend(fontsize="small")
    ax = axes[1, 0]
    for colour, name in zip(STATE_COLOURS, STATE_NAMES, strict=True):
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
def _frequency_needed(out: dict, path: str) -> None:
    """Rule: ``frequency`` is required unless ``quasi_static``."""
    if not out.get("quasi_static") and "frequency" not in out:
        raise InputError(f"missing required key {join(path, 'frequency')!r} (excitation "
                         "frequency [Hz]: a number > 0; only a quasi_static analysis can do "
                         "without)")


_EPS_AUTO = ('"auto": the spectral radius of Z_r over the kept harmonics (the paper); '
             '"static": that of the static reduced stiffness K_r; or a value')

register(
    "periodic",
    {
        "frequency": Field(Number(lo=0, lo_open=True), "excitation frequency (required unless "
                           "quasi_static; then it only scales time, default 1 Hz)", unit="Hz"),
        "quasi_static": Field(Flag(), "drop inertia and damping (slow cyclic loading); the "
                              "friction law stays path dependent over the period",
                              default=False),
        **_common_fields("auto", "DLFT penalty: " + _EPS_AUTO, 200),
    },
    run_periodic,
    checks=(_frequency_needed, _check_sampling),
    doc="Periodic response at one frequency with the frictional interface (DLFT, paper "
    "section 3). A solve that does not converge saves no solution: `results.nc` then holds "
    "the solver diagnostics only, and the run exits with status 1. Writes "
    "`periodic-<point>.png` (displacement and velocity over a period; grey bands where the "
    "point stops), `contact-state.png` (separation/stick/slip along the interface over the "
    "period), `contact-profiles.png` (pressure, slip, friction energy along the interface), "
    "`hysteresis.png` (tangential force against slip for a few nodes) and, for meshes, "
    "`periodic.pvd` (the displacement field over the period; ParaView's time slider plays it).",
)

register(
    "sweep",
    {
        "f_min": Field(Number(lo=0, lo_open=True), "lowest frequency", required=True, unit="Hz"),
        "f_max": Field(Number(lo=0, lo_open=True), "highest frequency", required=True, unit="Hz"),
        "n_points": Field(Integer(lo=2), "number of grid frequencies (the sweep may add "
                          "intermediate points where a step fails)", default=200),
        "spacing": Field(Text(("log", "linear")), "frequency spacing", default="log"),
        "continuation": Field(Flag(), "pseudo-arclength continuation when a frequency step "
                              "fails (passes folds of the response curve)", default=True),
        "time_domain": Field(Flag(), "where a point still fails, integrate in time from the "
                             "neighbour: a periodic steady state starts one more solve, any "
                             "other response (drifting, quasi-periodic) is reported as the "
                             "reason", default=True),
        "time_domain_periods": Field(Integer(lo=10), "forcing periods allowed to each time "
                                     "integration (time_domain, check_stability)",
                                     default=3000),
        "check_stability": Field(Flag(), "check every converged point in time (does the "
                                 "structure settle to it?); slow", default=False),
        "points": Field(ListOf(Text(), non_empty=True, unique=True),
                        "observed points to report (default: all)"),
        "linear_references": Field(
            ListOf(Text(linear.INTERFACES), unique=True),
            'linear FRFs drawn with the nonlinear one: "sliding" (frictionless), "stuck", '
            '"free"', default=[]),
        **_common_fields(
            "static",
            'DLFT penalty: "static": the spectral radius of the static reduced stiffness K_r, '
            'the same at every frequency (a smooth FRF); "auto": the paper\'s rule (spectral '
            "radius of Z_r) at each frequency; or a value", 40),
    },
    run_sweep,
    checks=(increasing("f_min", "f_max", "Hz"), _check_sampling),
    doc="Nonlinear FRF: periodic responses with the frictional interface over a frequency "
    "band, each point starting from its neighbours (continuation). Points that do not "
    "converge are kept as NaN with `converged = 0` and the reason in `flags`; the run then "
    "exits with status 1. Writes `sweep-<point>.png` (amplitude against frequency, with the "
    "linear references) and `sweep-interface.png` (friction energy and contact states).",
)
