"""The ``"nonlinear-modes"`` analysis of case files: a nonlinear mode of the structure with
its frictional interface, by the Extended Periodic Motion Concept (natural frequency and
damping ratio against amplitude, from stuck to sliding).

:func:`run_nonlinear_modes` calls :func:`fretwear.api.nonlinear_mode`
(:func:`fretwear.hb.nonlinear_modes.nonlinear_mode`), turns the backbone into a results dataset
(schema in ``docs/results.md``) and the backbone figure; :data:`NONLINEAR_MODES` is the
analysis (:mod:`fretwear.analyses.registry` lists it). Amplitudes past a failed continuation
step are kept as NaN with ``converged = 0`` and the reason in the ``message`` attribute.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from fretwear import api
from fretwear.analyses import figures as plots
from fretwear.analyses.base import Analysis, RunContext, RunOutput
from fretwear.analyses.common import (
    basis_of,
    check_points,
    check_sampling,
    condensation_fields,
    default_of,
    figure_path,
    geometry,
    harmonic_balance_fields,
    live_axes,
    pad_axes,
    period_coordinates,
    solve_options_of,
    titled,
)
from fretwear.analyses.figure_style import MARKED_POINTS, series_style
from fretwear.errors import InputError
from fretwear.hb.contact import STATE_NAMES
from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis, amplitude
from fretwear.hb.mode_synthesis import DAMPING, modal_forces, synthesize
from fretwear.hb.nonlinear_modes import Backbone
from fretwear.hb.nonlinear_modes import nonlinear_mode as _core
from fretwear.hb.options import SolveOptions
from fretwear.io.results import variable
from fretwear.io.schema import Field, Integer, ListOf, Number, Text, increasing, requires

AMPLITUDE_UNIT = "m kg^0.5"
#: modal amplitudes accepted: a displacement of 1e-9 to 1e5 m (fretwear.limits) times the
#: square root of a mass of 1e-12 to 1e12 kg, with margin
_AMPLITUDE = Number(lo=1e-20, hi=1e12)


# --- dataset -------------------------------------------------------------------------------
def _observed(model, bb: Backbone, points: list[str], n_axes: int, na: int):
    """``(coefficients (na, point, axis, H), amplitudes (na, point, axis, k))`` of the observed
    points, NaN past the converged amplitudes."""
    basis = bb.basis
    H, k = basis.size, basis.k
    coef = np.full((na, len(points), n_axes, H), np.nan)
    start, where = 0, {}
    for p in model.observed:
        where[p.name] = slice(start, start + len(p.dofs))
        start += len(p.dofs)
    for i, pt in enumerate(bb.points):
        if pt.observed is None:
            continue
        coef[i] = pad_axes([pt.observed[where[name]] for name in points], n_axes)
    amp = np.full((na, len(points), n_axes, k), np.nan)
    amp[:] = amplitude(coef, basis)
    return coef, amp


def modes_dataset(model, bb: Backbone, amplitudes: np.ndarray, points: list[str]) -> xr.Dataset:
    """The results dataset of a nonlinear mode (``docs/results.md``): one row per requested
    modal amplitude, NaN (``converged = 0``) past a failed continuation."""
    coords, data = geometry(model, points)
    basis: FourierBasis = bb.basis
    na, nc = amplitudes.size, model.contact.n_nodes
    coords["modal_amplitude"] = variable(
        "modal_amplitude", amplitudes, AMPLITUDE_UNIT,
        "modal amplitude: mass norm sqrt(U1^H M U1) of the fundamental harmonic of the motion")
    coords.update(period_coordinates(basis))
    n_axes = coords["axis"].size
    done = len(bb.points)

    def field(name, fill=np.nan):
        out = np.full(na, fill, dtype=float)
        out[:done] = bb.array(name) if done else []
        return out

    state = np.full((na, nc, basis.n_samples), -1, dtype=np.int8)
    node_e = np.full((na, nc), np.nan)
    fractions = np.full((na, 3), np.nan)
    area = np.asarray(model.contact.area, dtype=float) * np.ones(nc)
    w = area / area.sum()
    for i, p in enumerate(bb.points):
        state[i] = p.state
        if p.node_energy is not None:
            node_e[i] = p.node_energy
        fractions[i] = [w @ np.mean(p.state == s, axis=1) for s in range(3)]
    coef, amp = _observed(model, bb, points, n_axes, na)
    a = "modal_amplitude"
    conv = np.zeros(na, dtype=np.int8)
    conv[:done] = [p.success for p in bb.points]
    data.update({
        "backbone_frequency": variable(a, field("frequency"), "Hz",
                                      "natural frequency of the nonlinear mode"),
        "damping_ratio": variable(a, field("damping_ratio"), "1",
                                  "damping ratio of the nonlinear mode, xi / (2 omega)"),
        "modal_damping": variable(a, field("xi"), "1/s",
                                  "mass-proportional damping xi the EPMC compensates"),
        "converged": variable(a, conv, "1", "the continuation reached this amplitude",
                              flag_values=np.array([0, 1], dtype=np.int8),
                              flag_meanings="no yes"),
        "friction_energy": variable(a, field("energy"), "J",
                                    "energy dissipated by friction per period"),
        "dissipated_energy": variable((a, "contact_node"), node_e, "J",
                                      "energy dissipated by friction per period at the node"),
        "mode_harmonics": variable((a, "point", "axis", "harmonic_coefficient"), coef, "m",
                               "real Fourier coefficients of the observed displacement"),
        "response_amplitude": variable((a, "point", "axis", "harmonic"), amp, "m",
                                       "amplitude of each kept harmonic of the observed "
                                       "displacement"),
        "contact_state": variable((a, "contact_node", "tau"), state, "1",
                                  "contact state: 0 separation, 1 stick, 2 slip (-1: not "
                                  "converged)"),
        "residual": variable(a, field("residual"), "1", "final relative residual"),
        "iterations": variable(a, field("iterations", 0).astype(np.int64), "1",
                               "corrector iterations"),
    })
    for s, name in enumerate(STATE_NAMES):
        data[f"{name}_fraction"] = variable(a, fractions[:, s], "1",
                                            f"fraction of contact area x period in {name}")
    return xr.Dataset(data, coords=coords)


def _summary(bb: Backbone, ds: xr.Dataset) -> str:
    n = int(ds["converged"].sum())
    lines = [f"modes_converged={n}/{ds.sizes['modal_amplitude']}"]
    if bb.message:
        lines.append(bb.message)
    if n:
        f, z = ds["backbone_frequency"].values, ds["damping_ratio"].values
        a = ds["modal_amplitude"].values
        j = int(np.nanargmax(z))
        lines.append(f"frequency {plots.format_frequency(f[0])} at {a[0]:.3g} {AMPLITUDE_UNIT}"
                     f" -> {plots.format_frequency(f[n - 1])} at {a[n - 1]:.3g}; largest "
                     f"damping ratio {z[j]:.3g} at {a[j]:.3g} {AMPLITUDE_UNIT}")
    return "\n".join(lines)


def synthesis_dataset(model, bb: Backbone, analysis: dict, dyn, points: list[str],
                      shape: tuple[int, int]) -> tuple[xr.Dataset, object]:
    """The forced response to the model's loads synthesised from the mode
    (:func:`fretwear.api.mode_frf`) and the direct sweep beside it (:func:`fretwear.api.sweep`,
    same basis): variables on ``modal_amplitude`` and ``sweep_frequency``; ``shape``: the
    sizes of the modes dataset's ``modal_amplitude`` and ``axis``; also the
    :class:`~fretwear.hb.mode_synthesis.ModalFRF`."""
    na, n_axes = shape
    if not bb.points:
        raise InputError("synthesis: the nonlinear mode has no converged amplitude")
    forces = modal_forces(model, bb, dyn=dyn)
    if not np.all(forces > 0):
        raise InputError("synthesis_f_min/synthesis_f_max: the synthesised forced response "
                         "needs a periodic load ([[loads]] with a cos or sin waveform) that "
                         "the mode's shape does not leave unexcited")
    syn = synthesize(bb, forces, damping=analysis["synthesis_damping"])
    res = api.sweep(model, bb.basis, analysis["synthesis_f_min"], analysis["synthesis_f_max"],
                    analysis["synthesis_points"])
    done = len(bb.points)

    def per_amp(x):
        out = np.full(na, np.nan)
        out[:done] = x
        return out

    a = "modal_amplitude"
    amp = np.full((len(res.points), len(points), n_axes), np.nan)
    for j, name in enumerate(points):
        for ax in range(len(model.observed_point(name).dofs)):
            amp[:, j, ax] = res.amplitude(name, ax)
    data = {
        "synthesis_frequency_low": variable(a, per_amp(syn.omega_lo / (2 * np.pi)), "Hz",
                                            "lower excitation frequency at which the "
                                            "synthesised forced response has this amplitude"),
        "synthesis_frequency_high": variable(a, per_amp(syn.omega_hi / (2 * np.pi)), "Hz",
                                             "upper excitation frequency at which the "
                                             "synthesised forced response has this amplitude"),
        "modal_force": variable(a, per_amp(syn.modal_force), "N kg^-0.5",
                                "the loads' first harmonic projected on the mass-normalised "
                                "mode, |phi^H F_1|"),
        "sweep_response_amplitude": variable(("sweep_frequency", "point", "axis"), amp, "m",
                                             "amplitude of harmonic 1 of the observed "
                                             "displacement in the direct sweep"),
    }
    coords = {"sweep_frequency": variable("sweep_frequency", res.frequency_hz, "Hz",
                                          "excitation frequency of the direct sweep")}
    return xr.Dataset(data, coords=coords), syn


# --- run -----------------------------------------------------------------------------------
def run_nonlinear_modes(model, analysis: dict, case, context: RunContext) -> RunOutput:
    """A nonlinear mode over an amplitude range (:func:`fretwear.api.nonlinear_mode`).

    Parameters
    ----------
    model : the model; analysis : the validated ``[analysis]`` table; case : the case;
    context : the results folder.

    Returns
    -------
    RunOutput; ``success`` False when the continuation stopped before the last amplitude.
    """
    points = check_points(model, analysis.get("points"))
    basis = basis_of(analysis)
    amps = np.geomspace(analysis["amplitude_min"], analysis["amplitude_max"],
                        analysis["n_amplitudes"])
    dyn = structure_dynamics(model)
    bb = api.nonlinear_mode(model, basis, amps, mode=analysis["mode"],
                            interface=analysis["interface"], masters=analysis["masters"],
                            eps=analysis["eps"],
                            options=solve_options_of(analysis, SolveOptions()), dyn=dyn)
    ds = modes_dataset(model, bb, amps, points)
    synthesis = analysis.get("synthesis_f_min") is not None
    if synthesis:
        extra, _ = synthesis_dataset(model, bb, analysis, dyn, points,
                                     (amps.size, ds.sizes["axis"]))
        ds = xr.merge([ds, extra], combine_attrs="override")
    ds.attrs.update({
        "message": bb.message, "notes": "\n".join(bb.notes),
        "total_wall_time": float(bb.wall_time), "eps": float(bb.eps),
        "eps_rule": str(analysis["eps"]), "solver": analysis["solver"],
        "tol": float(analysis["tol"]),
        "harmonics": ", ".join(str(h) for h in basis.harmonics),
        "n_samples": int(basis.n_samples),
    })
    figures = []
    p = figure_path(case, context.out_dir, "backbone")
    if p is not None:
        figures.append(plot_backbone(ds, p, title=titled(case.title, "nonlinear mode")))
    p = figure_path(case, context.out_dir, "mode-frf") if synthesis else None
    if p is not None:
        figures.append(plot_mode_frf(ds, p, title=titled(case.title, "single-mode FRF")))
    return RunOutput(ds, figures, _summary(bb, ds), bb.success, warnings=list(bb.notes))


# --- figures -------------------------------------------------------------------------------
def plot_backbone(ds: xr.Dataset, path: Path, *, title: str | None = None) -> Path:
    """Natural frequency and damping ratio against the modal amplitude (log x), and the
    amplitude of harmonic 1 of the observed points (the backbone)."""
    a = ds["modal_amplitude"].values
    f = ds["backbone_frequency"].values
    z = ds["damping_ratio"].values
    rows = 3 if ds.sizes.get("point", 0) else 2
    fig, axes = plots.new_figure(rows, 1, title=title, panel_size=(7.5, 3.0), sharex=True)
    ax = axes[0, 0]
    ax.plot(a, f, color="k", marker=".", ms=3)
    ax.set_ylabel("natural frequency [Hz]")
    ax = axes[1, 0]
    ax.plot(a, z, color="tab:purple", marker=".", ms=3)
    ax.set_ylabel("damping ratio [-]")
    if rows == 3:
        ax = axes[2, 0]
        h = int(ds["harmonic"].values[0])
        curves = [(point, axis) for point in ds["point"].values
                  for axis in live_axes(ds, str(point)) or [str(ds["axis"].values[0])]]
        for j, (point, axis) in enumerate(curves):
            y = ds["response_amplitude"].sel(point=point, axis=axis, harmonic=h).values
            if np.any(y > 0):
                ax.plot(a, np.where(y > 0, y, np.nan), label=f"{point} {axis}",
                        **series_style(j, len(curves), markers=a.size <= MARKED_POINTS))
        ax.set_yscale("log")
        ax.set_ylabel(f"|u_{h}| [m]")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize="small")
    for ax in axes[:, 0]:
        ax.set_xscale("log")
        ax.grid(True, which="both", alpha=0.3)
    axes[-1, 0].set_xlabel(f"modal amplitude [{AMPLITUDE_UNIT}]")
    return plots.save(fig, path)


def plot_mode_frf(ds: xr.Dataset, path: Path, *, title: str | None = None) -> Path:
    """The forced response synthesised from the mode (harmonic 1 of each observed point
    against the excitation frequency, both frequencies of every amplitude) beside the
    direct sweep."""
    fig, axes = plots.new_figure(1, 1, title=title, panel_size=(7.5, 4.0))
    ax = axes[0, 0]
    h = int(ds["harmonic"].values[0])
    lo, hi = ds["synthesis_frequency_low"].values, ds["synthesis_frequency_high"].values
    for k, point in enumerate(ds["point"].values):
        for axis in live_axes(ds, str(point)) or [str(ds["axis"].values[0])]:
            y = ds["response_amplitude"].sel(point=point, axis=axis, harmonic=h).values
            f = np.concatenate([lo, hi[::-1]])
            yy = np.concatenate([y, y[::-1]])
            ok = np.isfinite(f) & np.isfinite(yy)
            color = f"C{k}"
            ax.plot(f[ok], yy[ok], color=color, label=f"{point} {axis}: single mode")
            ys = ds["sweep_response_amplitude"].sel(point=point, axis=axis).values
            ax.plot(ds["sweep_frequency"].values, ys, "o", color=color, ms=3, mfc="none",
                    label=f"{point} {axis}: direct sweep")
    ax.set_xlabel("excitation frequency [Hz]")
    ax.set_ylabel(f"|u_{h}| [m]")
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize="small")
    return plots.save(fig, path)


#: the keys of the synthesised forced response (docs/theory.md section 11)
SYNTHESIS_FIELDS = {
    "synthesis_f_min": Field(Number(lo=0, lo_open=True), "with `synthesis_f_max`: also "
                             "the forced response to the case's loads synthesised from "
                             "the mode (single-nonlinear-mode theory), beside a direct "
                             "sweep over this band", unit="Hz"),
    "synthesis_f_max": Field(Number(lo=0, lo_open=True), "upper end of the direct "
                             "sweep's band", unit="Hz"),
    "synthesis_points": Field(Integer(lo=2, hi=10_000), "frequencies of the direct "
                              "sweep", default=41),
    "synthesis_damping": Field(Text(DAMPING), 'the mode\'s damping in the synthesis: '
                               '"viscous" (xi W, the EPMC\'s reading) or "hysteretic" '
                               "(xi w, rate-independent)", default="viscous"),
}


# --- registration ---------------------------------------------------------------------------
NONLINEAR_MODES = Analysis.define(
    "nonlinear-modes",
    {
        "mode": Field(Integer(lo=1), "the linear mode the branch starts from, numbered from 1 "
                      "by increasing frequency with the interface `interface`",
                      default=default_of(api.nonlinear_mode, "mode")),
        "interface": Field(Text(api.MODE_INTERFACES), '"stuck": the modes of the structure '
                           "with its contact points held (contact springs included: the "
                           'branch\'s low-amplitude end); "sliding": the frictionless '
                           "structure's, whose nearest stuck mode is followed",
                           default=default_of(api.nonlinear_mode, "interface")),
        "amplitude_min": Field(_AMPLITUDE, "smallest modal amplitude (mass norm of the "
                               "fundamental harmonic of the motion)", required=True,
                               unit=AMPLITUDE_UNIT),
        "amplitude_max": Field(_AMPLITUDE, "largest modal amplitude", required=True,
                               unit=AMPLITUDE_UNIT),
        **SYNTHESIS_FIELDS,
        "n_amplitudes": Field(Integer(lo=2, hi=10_000), "modal amplitudes of the result, "
                              "log-spaced (the continuation adds steps where one fails)",
                              default=30),
        "masters": Field(Integer(lo=1), "modes of the structure with its contact points held "
                         "kept as unknowns (the rest condensed exactly)",
                         default=default_of(_core, "masters")),
        "points": Field(ListOf(Text(), non_empty=True, unique=True),
                        "observed points to report (default: all)"),
        # the condensation keys are not among them: the mode's structure is reduced on its
        # own modes (``masters``), exactly, with no frequency band to build a modal one for
        **{k: f for k, f in harmonic_balance_fields(
            SolveOptions(), default_of(_core, "eps"),
            'DLFT penalty: "top" (the contact springs themselves where there are some: the '
            "exact value; else the spectral radius of Z_r at the highest kept harmonic), "
            '"static", "auto" or a value').items() if k not in condensation_fields()},
    },
    run_nonlinear_modes,
    checks=(increasing("amplitude_min", "amplitude_max", AMPLITUDE_UNIT), check_sampling,
            requires("synthesis_f_min", "synthesis_f_max"),
            requires("synthesis_f_max", "synthesis_f_min"),
            increasing("synthesis_f_min", "synthesis_f_max", "Hz")),
    doc="Nonlinear mode by the Extended Periodic Motion Concept (Krack 2015; docs/theory.md, "
    '"Nonlinear modes"): the periodic motion of the structure without its periodic loads '
    "(the static ones stay: the preload) with a negative mass-proportional damping that makes "
    "it periodic, over a range of modal amplitudes, on the exact DLFT law. Results: natural "
    "frequency, damping ratio, observed harmonics, contact states and friction energy per "
    "amplitude. Writes `backbone.png` (frequency, damping ratio and observed amplitude "
    "against the modal amplitude); with `synthesis_f_min`/`synthesis_f_max`, the forced "
    "response to the loads synthesised from the mode beside a direct sweep (`mode-frf.png`)."
    " The run exits with status 1 when the continuation "
    "stops before `amplitude_max`.",
    preload_check=True,
)
