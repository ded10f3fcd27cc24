"""The ``"wear"`` analysis of case files: fretting wear on the slow time scale.

Runs :func:`fretwear.wear.simulate.simulate_wear` (paper section 3.3, eq. 29-30) at one excitation
frequency (or quasi-static), with a checkpoint in the results folder so that
``fretwear run CASE.toml --resume`` continues an interrupted run to the same result; turns the
:class:`~fretwear.wear.history.WearHistory` into a results dataset (schema in ``docs/results.md``,
section ``wear``), draws the figures of the paper's section 4.2 (worn profiles, wear
kinetics, pressure and slip along the interface, worn volume) and, when asked, the nonlinear
FRFs before and after wear (paper Fig. 24).
"""

from __future__ import annotations

import math
from dataclasses import fields
from pathlib import Path

import numpy as np
import xarray as xr

from fretwear import api
from fretwear.analyses import figures as plots
from fretwear.analyses.base import Analysis, RunContext, RunOutput
from fretwear.analyses.common import (
    condensation_fields,
    condenser_of,
    default_of,
    interface_labels,
)
from fretwear.analyses.figure_style import MARKED_POINTS, series_style
from fretwear.errors import InputError, interrupted
from fretwear.files import safe_name
from fretwear.hb import fallbacks
from fretwear.hb.contact import STATE_NAMES
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import WEAR_STEP
from fretwear.hb.penalty import RULES
from fretwear.hb.solvers import SOLVERS
from fretwear.hb.sweep import frequency_grid
from fretwear.io.results import (
    label_coordinate,
    no_fields_line,
    output_mesh,
    variable,
    write_pvd,
    write_results,
    write_vtu,
)
from fretwear.io.schema import (
    MISSING,
    AnyOf,
    Field,
    Flag,
    Integer,
    ListOf,
    Number,
    Spec,
    Table,
    Text,
    fail,
    increasing,
)
from fretwear.model.projection import partner_node_values
from fretwear.timedomain.averaged_rate import RESPONSE_KINDS
from fretwear.wear import (
    LAWS,
    SCHEMES,
    BalanceSetup,
    RunControl,
    WearOptions,
    WearResult,
    simulate_wear,
)
from fretwear.wear.checkpoint import read_history
from fretwear.wear.laws import side_depths
from fretwear.wear.simulate import QUASI_STATIC_FREQUENCY
from fretwear.wear.worn_frf import WORN_FRF

#: the two worn surfaces of a contact node: its own, and its partner's (node-to-node pairs)
SURFACES = ("contact", "partner")

CHECKPOINT_FILE = "wear-checkpoint.npz"
COMPONENTS = ("N", "T1", "T2")
AXES = ("x", "y", "z")


# --- options ----------------------------------------------------------------------------------
#: the defaults of the wear options: :class:`~fretwear.wear.options.WearOptions` is their one
#: definition, for case files as for Python (the keys of its solve record,
#: :data:`SOLVE_KEYS`, from :data:`~fretwear.hb.options.WEAR_STEP`)
OPTION_DEFAULTS = {f.name: f.default for f in fields(WearOptions) if f.name != "solve"}
#: the keys of the table that set the solve record of the wear options (``WearOptions.solve``)
SOLVE_KEYS = ("solver", "tol")
OPTION_DEFAULTS.update({k: getattr(WEAR_STEP, k) for k in SOLVE_KEYS})


def option(name: str, spec: Spec, doc: str, unit: str = "", *, fill: bool = True) -> Field:
    """The ``[analysis]`` key of the wear option ``name``, with the default of
    :class:`~fretwear.wear.options.WearOptions`. A default of None (not set), or any with
    ``fill = False``, is not written into the validated table: the key is then absent and
    :func:`options_from_table` leaves the option to its default."""
    default = OPTION_DEFAULTS[name]
    filled = fill and default is not None
    return Field(spec, doc, default=default if filled else MISSING, unit=unit)


def options_from_table(a: dict) -> WearOptions:
    """:class:`~fretwear.wear.options.WearOptions` from the validated ``[analysis]`` table: its
    wear options (:data:`OPTION_KEYS`, those of the solve record into ``solve``) that are
    there; the others keep their defaults."""
    given = {k: a[k] for k in OPTION_KEYS if k in a}
    solve = WEAR_STEP.replace(**{k: given.pop(k) for k in SOLVE_KEYS if k in given})
    return WearOptions(solve=solve, **given)


def penalty_of(a: dict) -> dict:
    """The keyword ``eps`` of the wear run and of its FRFs when the table gives it, else none:
    each function then takes its own default (:func:`~fretwear.wear.simulate.simulate_wear`:
    ``"auto"``, the paper's rule; :func:`~fretwear.hb.sweep.sweep`: ``"contact"``)."""
    return {"eps": a["eps"]} if "eps" in a else {}


def _check_table(out: dict, path: str) -> None:
    """Rules across keys: a frequency unless quasi-static; k_e with the energy law (and the
    partner surfaces' k_e only with it)."""
    if not out.get("quasi_static") and "frequency" not in out:
        fail(f"{path}.frequency" if path else "frequency", None,
             "an excitation frequency [Hz] (or quasi_static = true)")
    if out.get("law") == "energy" and "energy_coefficient" not in out:
        fail(f"{path}.energy_coefficient" if path else "energy_coefficient", None,
             "k_e [m^3/J] for law = \"energy\"")
    if out.get("law") != "energy" and "partner_energy_coefficient" in out:
        key = "partner_energy_coefficient"
        fail(f"{path}.{key}" if path else key, out[key],
             "no value with law = \"archard\" (the partner surfaces' Archard coefficient is "
             "[[contact]] partner_wear_coefficient)")


# --- dataset ------------------------------------------------------------------------------------
def _steps_kept(n: int, every: int) -> np.ndarray:
    """Recorded steps kept in the results file: every ``every``-th and the last."""
    keep = np.arange(0, n, max(1, int(every)))
    if keep[-1] != n - 1:
        keep = np.append(keep, n - 1)
    return keep


def wear_dataset(model, result: WearResult, basis: FourierBasis, *, frequency_hz: float,
                 record_every: int = 1, frf=None, law: str = "archard",
                 energy_coefficients=(None, None)) -> xr.Dataset:
    """The results dataset of a wear run (``docs/results.md``, section ``wear``); ``law``
    and, for the energy law, ``energy_coefficients`` (node's surface, partner's) split the
    wear depth between the two surfaces of a pair (:func:`fretwear.wear.laws.side_depths`)."""
    h = result.history
    keep = _steps_kept(h.n_steps, record_every)
    c = model.contact
    nc, d = c.dofs.shape
    coords = {
        "step": variable("step", keep, "1", "slow-scale (wear) step"),
        "contact_node": variable("contact_node", np.arange(nc), "1", "contact node, from 0"),
        "component": label_coordinate("component", COMPONENTS[:d]),
        "harmonic_coefficient": label_coordinate("harmonic_coefficient", basis.labels()),
        "contact_state": label_coordinate("contact_state", STATE_NAMES,
                                          "contact state: separation, stick, slip"),
        "axis": label_coordinate("axis", AXES[:d]),
        "surface": label_coordinate("surface", SURFACES,
                                    "worn surface: the contact node's, its partner's"),
    }
    sn, sc = ("step", "contact_node"), ("step",)
    hist = {k: np.asarray(getattr(h, k))[keep] for k in (
        "cycles", "jump", "wear_depth", "wear_rate", "pressure_mean", "pressure_max",
        "slip_amplitude", "slip_path", "state_fraction", "friction_energy", "worn_volume",
        "volume_rate", "newton_iterations", "rejected", "error_estimate", "wall_time", "U",
        "lam", "rescued", "response", "rate_scatter")}
    cpos = np.asarray(c.coords, float).reshape(nc, -1)[:, :d]
    data = {
        "contact_position": variable(("contact_node", "axis"), cpos, "m",
                                     "position of the contact node"),
        "contact_area": variable("contact_node", np.asarray(c.area, float), "m^2",
                                 "tributary area of the contact node"),
        "contact_interface": interface_labels(model),
        "worn_depth_surface": variable(
            ("step", "contact_node", "surface"),
            np.stack(side_depths(model, hist["wear_depth"], law, *energy_coefficients),
                     axis=-1), "m",
            "worn depth of each surface (the contact node's, its partner's); their sum is W"),
        "excitation_frequency": variable((), frequency_hz, "Hz",
                                         "excitation frequency (time scale only if quasi-static)"),
        "penalty": variable((), result.penalty, "N/m", "DLFT penalty eps"),
        "stability_jump": variable((), result.stability_jump, "1",
                                   "explicit Euler stability limit 2/rho at the start, cycles"),
        "cycles": variable(sc, hist["cycles"], "1", "physical cycle count N"),
        "jump": variable(sc, hist["jump"], "1", "cycles jumped by the step"),
        "wear_depth": variable(sn, hist["wear_depth"], "m", "wear depth W"),
        "wear_rate": variable(sn, hist["wear_rate"], "m",
                              "wear depth per cycle dW1 (paper eq. 29)"),
        "pressure_mean": variable(sn, hist["pressure_mean"], "Pa",
                                          "normal contact pressure, mean over the period"),
        "pressure_max": variable(sn, hist["pressure_max"], "Pa",
                                         "normal contact pressure, maximum over the period"),
        "slip_amplitude": variable(sn, hist["slip_amplitude"], "m",
                                   "tangential displacement amplitude (half range)"),
        "slip_path": variable(sn, hist["slip_path"], "m", "slip path per cycle"),
        "state_fraction": variable(("step", "contact_node", "contact_state"),
                                   hist["state_fraction"], "1",
                                   "fraction of the period in each contact state"),
        "dissipated_energy": variable(sn, hist["friction_energy"], "J",
                                      "energy dissipated by friction per period"),
        "worn_volume": variable(sc, hist["worn_volume"], "m^3", "worn volume"),
        "worn_volume_rate": variable(sc, hist["volume_rate"], "m^3", "worn volume per cycle"),
        "newton_iterations": variable(sc, hist["newton_iterations"], "1",
                                      "nonlinear solver iterations of the step, retries "
                                      "included"),
        "rejected_attempts": variable(sc, hist["rejected"], "1",
                                      "attempts of the step rejected (error test or failed "
                                      "solve)"),
        "error_estimate": variable(sc, hist["error_estimate"], "1",
                                   "local error estimate relative to the maximum wear depth"),
        "step_wall_time": variable(sc, hist["wall_time"], "s", "wall time of the step"),
        "rate_scatter": variable(sc, hist["rate_scatter"], "1",
                                 "time-averaged steps: |v1 - v2| / (v1 + v2) of the worn-volume "
                                 "rates of the two halves of the averaging window (relative "
                                 "standard error of the rate); NaN on balanced steps"),
        "time_domain_start": variable(sc, hist["rescued"].astype(np.int8), "1",
                                      "0: balanced step; 1: balance started from a time "
                                      "integration; 2: wear rate averaged over a time "
                                      "integration (no periodic balance)"),
        "time_domain_response": variable(sc, hist["response"].astype(np.int8), "1",
                                         "response of the step's time integration: "
                                         + ", ".join(f"{i} {k}" for i, k in
                                                     enumerate(RESPONSE_KINDS))
                                         + "; -1 none integrated"),
        "contact_displacement_coefficients": variable(
            ("step", "contact_node", "component", "harmonic_coefficient"), hist["U"], "m",
            "Fourier coefficients of the contact displacements (normal includes gap + wear)"),
        "contact_force_coefficients": variable(
            ("step", "contact_node", "component", "harmonic_coefficient"), hist["lam"], "N",
            "Fourier coefficients of the contact forces (normal positive in compression)"),
    }
    if frf is not None:
        coords.update(frf["coords"])
        data.update(frf["data"])
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update({"stop_reason": result.stop_reason, "wear_message": result.message})
    return ds



def before_after_frf(model, basis, a: dict, fb: dict | None, cond, worn) -> tuple:
    """The FRFs before and after wear (the paper's Fig. 24) that ``frf_before_after`` (``fb``)
    asks for, with the worn gap ``worn`` (nc,) [m]: ``(frf data or None, summary note,
    {"unworn": SweepResult, "worn": SweepResult})``; the sweeps use the analysis's solver and
    penalty (``a``) and the run's condenser."""
    if fb is None:
        return None, "", {}
    if not model.observed:
        return None, "FRF before/after skipped: the model has no observed point", {}
    grid = (fb["f_min"], fb["f_max"], fb["n_points"])
    frf_options = WORN_FRF.replace(solve=WORN_FRF.solve.replace(solver=a["solver"]),
                                   **penalty_of(a), spacing=fb["spacing"])
    sweeps = {name: api.frf_worn(model, basis, w, *grid, options=frf_options,
                                 time_domain=fb["time_domain"], condenser=cond)
              for name, w in (("unworn", 0.0), ("worn", worn))}
    frf = _frf_data(model, sweeps, frequency_grid(*grid, fb["spacing"]))
    note = "\n".join(f"FRF {k}: {int(v.point_success.sum())}/{len(v.points)} converged"
                     for k, v in sweeps.items())
    return frf, note, sweeps


def _frf_data(model, sweeps: dict, freqs: np.ndarray) -> dict:
    """FRF variables (wear_state, frequency, point, axis) on the requested grid."""
    points = [p.name for p in model.observed]
    n_axes = max([len(p.dofs) for p in model.observed], default=1)
    states = list(sweeps)
    amp = np.full((len(states), freqs.size, len(points), n_axes), np.nan)
    conv = np.zeros((len(states), freqs.size), dtype=np.int8)
    for i, name in enumerate(states):
        res = sweeps[name]
        f = res.frequency_hz
        idx = [int(np.argmin(np.abs(f - x))) for x in freqs]
        conv[i] = res.point_success[idx]
        for j, pt in enumerate(points):
            for k in range(len(model.observed_point(pt).dofs)):
                amp[i, :, j, k] = res.amplitude(pt, k, harmonic=1)[idx]
    coords = {
        "wear_state": label_coordinate("wear_state", states, "interface before / after wear"),
        "frequency": variable("frequency", freqs, "Hz", "excitation frequency"),
        "point": label_coordinate("point", points),
    }
    data = {
        "frf_amplitude": variable(("wear_state", "frequency", "point", "axis"), amp, "m",
                                  "nonlinear FRF: amplitude of harmonic 1 of the observed "
                                  "displacement (NaN where not converged)"),
        "frf_converged": variable(("wear_state", "frequency"), conv, "1",
                                  "1 if the periodic solve converged"),
    }
    return {"coords": coords, "data": data}


# --- figures --------------------------------------------------------------------------------
def selected_steps(cycles: np.ndarray, n: int = 5) -> list[int]:
    """``n`` recorded steps spread on a log scale of cycles, first and last included."""
    s = len(cycles)
    if s <= n:
        return list(range(s))
    pos = np.log10(np.maximum(cycles, 1.0))
    targets = np.linspace(pos[1] if s > 1 else 0, pos[-1], n - 1)
    picks = {0, s - 1}
    for t in targets:
        picks.add(int(np.argmin(np.abs(pos - t))))
    return sorted(picks)


def _x_along(ds) -> tuple[np.ndarray, str]:
    pos = ds["contact_position"].values
    span = np.ptp(pos, axis=0)
    k = int(np.argmax(span))
    return pos[:, k], f"{AXES[k]} [m]"


def _profile(ax, x, y, **kw) -> None:
    """``y`` against ``x`` over the contact nodes: a line through the nodes in the order of
    ``x`` where each ``x`` is one node (a line interface), markers only where several nodes
    share an ``x`` (a surface in 3D, several interfaces side by side: a line would zig-zag
    between them; the maps of ``wear-maps.png`` show those)."""
    o = np.argsort(x, kind="stable")
    style = {"marker": ".", **kw}
    if np.unique(x).size != x.size:
        style["linestyle"] = "none"
    ax.plot(x[o], y[o], **style)


def plot_wear_profiles(ds, path: Path, *, title=None) -> Path:
    """Wear depth along the interface at selected cycle counts (paper Fig. 7, 21, 23)."""
    x, xl = _x_along(ds)
    fig, axes = plots.new_figure(title=title)
    ax = axes[0, 0]
    cyc = ds["cycles"].values
    steps = selected_steps(cyc)
    for k, i in enumerate(steps):
        _profile(ax, x, ds["wear_depth"].values[i], label=f"N = {cyc[i]:.3g}",
                 **series_style(k, len(steps), markers=x.size <= MARKED_POINTS))
    ax.set_xlabel(xl)
    ax.set_ylabel("wear depth [m]")  # in SI: the figure style writes it in µm or nm
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
    return plots.save(fig, path)


def default_nodes(ds, n: int = 5) -> list[int]:
    """Nodes to follow: the most worn ones, spread along the interface."""
    w = ds["wear_depth"].values[-1]
    order = np.argsort(-w)
    picks = []
    for p in order:
        if w[p] <= 0:
            break
        if all(abs(int(p) - q) > 1 for q in picks):
            picks.append(int(p))
        if len(picks) == n:
            break
    return sorted(picks) or [int(order[0])]


def plot_wear_kinetics(ds, path: Path, nodes, *, title=None) -> Path:
    """Wear depth against cycles for chosen nodes (paper Fig. 8, 9), log cycles."""
    x, xl = _x_along(ds)
    fig, axes = plots.new_figure(title=title)
    ax = axes[0, 0]
    cyc = ds["cycles"].values
    for k, p in enumerate(nodes):
        ax.semilogx(cyc[1:], ds["wear_depth"].values[1:, p],
                    label=f"node {p} ({xl[0]} = {x[p]:.4g} m)",
                    **series_style(k, len(nodes), markers=cyc.size <= MARKED_POINTS))
    ax.set_xlabel("cycles N")
    ax.set_ylabel("wear depth [m]")  # in SI: the figure style writes it in µm or nm
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    return plots.save(fig, path)


def plot_pressure_slip(ds, path: Path, *, title=None) -> Path:
    """Maximum pressure and tangential amplitude along the interface at selected cycle counts
    (paper Fig. 11, 13, 18, 19)."""
    x, xl = _x_along(ds)
    fig, axes = plots.new_figure(2, 1, title=title, sharex=True)
    cyc = ds["cycles"].values
    steps = selected_steps(cyc)
    for k, i in enumerate(steps):
        kw = {"label": f"N = {cyc[i]:.3g}",
              **series_style(k, len(steps), markers=x.size <= MARKED_POINTS)}
        _profile(axes[0, 0], x, ds["pressure_max"].values[i], **kw)
        _profile(axes[1, 0], x, ds["slip_amplitude"].values[i], **kw)
    axes[0, 0].set_ylabel("max normal pressure [Pa]")
    axes[1, 0].set_ylabel("tangential amplitude [m]")
    axes[1, 0].set_xlabel(xl)
    for ax in axes[:, 0]:
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize="small")
    return plots.save(fig, path)


def plot_worn_volume(ds, path: Path, *, title=None) -> Path:
    """Worn volume against cycles, log cycles (paper Fig. 25)."""
    fig, axes = plots.new_figure(title=title)
    ax = axes[0, 0]
    cyc = ds["cycles"].values
    ax.semilogx(cyc[1:], ds["worn_volume"].values[1:], marker=".")
    ax.set_xlabel("cycles N")
    ax.set_ylabel("worn volume [m^3]")
    ax.grid(True, which="both", alpha=0.3)
    return plots.save(fig, path)


def plot_frf_before_after(ds, path: Path, point: str, *, title=None) -> Path:
    """Nonlinear FRF at ``point`` before and after wear (paper Fig. 24)."""
    amp = ds["frf_amplitude"].sel(point=point)
    axes_labels = [str(a) for a in ds["axis"].values]
    fig, axes = plots.new_figure(len(axes_labels), 1, title=title, sharex=True)
    f = ds["frequency"].values
    for ax, axis in zip(axes[:, 0], axes_labels, strict=True):
        states = ds["wear_state"].values
        for k, state in enumerate(states):
            y = amp.sel(wear_state=state, axis=axis).values
            ax.semilogy(f, np.where(y > 0, y, np.nan), label=str(state),
                        **series_style(k, len(states), markers=f.size <= MARKED_POINTS))
        ax.set_ylabel(f"|u_{axis}| at {point} [m]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    axes[-1, 0].set_xlabel("frequency [Hz]")
    return plots.save(fig, path)


# --- the analysis -----------------------------------------------------------------------------
def slow_run_setup(model, a: dict) -> tuple:
    """What a wear run and a worn state read from their ``[analysis]`` table ``a``:
    ``(quasi_static, frequency [Hz], FourierBasis, frf_before_after table or None, condenser)``;
    the condenser is the case file's choice of condensation for the run and its FRFs before
    and after wear (up to the higher of the frequency and the FRF band)."""
    quasi = bool(a["quasi_static"])
    f_hz = float(a.get("frequency", QUASI_STATIC_FREQUENCY))
    basis = FourierBasis.up_to(a["harmonics"], a["n_samples"])
    fb = a.get("frf_before_after")
    top = None if quasi else max(f_hz, fb["f_max"] if fb is not None else 0.0)
    return quasi, f_hz, basis, fb, condenser_of(model, a, top, max(basis.harmonics))


def run_wear(model, analysis: dict, case, context: RunContext) -> RunOutput:
    """Fretting wear to a plateau, a depth or a cycle count (see module docstring)."""
    a = analysis
    opts = options_from_table(a)
    nc = model.contact.n_nodes
    nodes = a.get("plot_nodes")
    if nodes is not None and any(p >= nc for p in nodes):
        fail("analysis.plot_nodes", nodes, f"contact node numbers from 0 to {nc - 1}")
    quasi, f_hz, basis, fb, cond = slow_run_setup(model, a)
    try:
        result = api.simulate_wear(model, basis, frequency=f_hz, quasi_static=quasi,
                                   options=opts,
                                   balance=BalanceSetup(condenser=cond, **penalty_of(a)),
                                   run=RunControl(checkpoint=context.out_dir / CHECKPOINT_FILE,
                                                  resume=context.resume,
                                                  progress=context.progress))
    except (KeyboardInterrupt, SystemError) as exc:
        if not interrupted(exc):
            raise
        write_partial(model, basis, analysis, case, context.out_dir)
        raise KeyboardInterrupt from None
    frf, frf_note, sweeps = before_after_frf(model, basis, a, fb, cond, result.final_wear)
    ds = wear_dataset(model, result, basis, frequency_hz=f_hz, record_every=a["record_every"],
                      frf=frf, law=opts.law,
                      energy_coefficients=(opts.energy_coefficient,
                                           opts.partner_energy_coefficient))
    ds.attrs.update(cond.choice.attributes())
    figures = wear_figures(ds, case, context.out_dir, nodes)
    files = [context.out_dir / CHECKPOINT_FILE]
    if output_mesh(model) is not None and case.output["vtu"]:
        files.append(write_wear_fields(model, ds, context.out_dir / "wear.pvd"))
    if model.meta.get("cyclic") is not None and case.output.get("whole_disk"):
        files.append(write_wear_disk_fields(model, ds, context.out_dir / "wear-disk.pvd"))
    h = result.history
    area = np.asarray(model.contact.area, float)
    w = h.wear_depth[-1]
    lines = [
        result.message,
        f"slow steps {h.n_steps - 1}, Newton iterations {int(h.newton_iterations.sum())}, "
        f"rejected attempts {int(h.rejected.sum())}, wall {result.wall_time:.1f} s"
        + (f" (resumed from step {result.resumed_from})" if result.resumed_from >= 0 else ""),
        f"worn volume {float(area @ w):.4e} m^3, max depth {w.max():.4e} m at contact node "
        f"{int(np.argmax(w))}; explicit Euler stability limit at the start "
        f"{result.stability_jump:.3g} cycles",
    ]
    if frf_note:
        lines.append(frf_note)
    if case.output["vtu"] and no_fields_line(model):
        lines.append(no_fields_line(model))
    fallback = fallbacks.of_wear(h.rescued[1:], h.wall_time[1:], result.wall_time,
                                 h.response[1:]).line(
        "slow steps", fallbacks.eps_hint("eps" in a))
    if fallback:
        lines.append(fallback)
    lines.append(cond.choice.summary())
    warnings = list(result.warnings)
    for name, sw in (sweeps.items() if frf is not None else ()):
        warnings += [f"FRF {name}: {w}" for w in sw.warnings]
    return RunOutput(ds, figures, "\n".join(lines), result.success, files,
                     warnings=warnings)


#: the results of an interrupted wear run, beside its checkpoint (attribute ``complete = 0``)
PARTIAL_FILE = "wear-partial.nc"


def write_partial(model, basis: FourierBasis, analysis: dict, case, out_dir: Path):
    """The steps saved in the checkpoint of an interrupted run as a results file
    (:data:`PARTIAL_FILE`, the variables of ``results.nc``, ``complete = 0`` and
    ``converged = 0``) to look at while the run is not finished; None without a readable
    checkpoint. ``--resume`` continues from the checkpoint and writes ``results.nc``."""
    ck = out_dir / CHECKPOINT_FILE
    try:
        history = read_history(ck)
    except (InputError, OSError):
        return None
    opts = options_from_table(analysis)
    n = history.n_steps - 1
    message = (f"interrupted after {n} slow steps, N = {float(history.cycles[-1]):.4g} cycles:"
               " partial results (run again with --resume to continue)")
    result = WearResult(history, None, None, "", message, False, math.nan)
    ds = wear_dataset(model, result, basis,
                      frequency_hz=float(analysis.get("frequency", QUASI_STATIC_FREQUENCY)),
                      record_every=analysis["record_every"], law=opts.law,
                      energy_coefficients=(opts.energy_coefficient,
                                           opts.partner_energy_coefficient))
    ds.attrs.update({"complete": 0, "message": message})
    return write_results(out_dir / PARTIAL_FILE, ds, title=case.title, analysis_type="wear",
                         converged=False, case_text=case.text, case_path=str(case.path),
                         analysis=analysis)


def write_wear_fields(model, ds, pvd: Path) -> Path:
    """ParaView series of the worn surfaces: one ``.vtu`` per recorded step in the folder
    ``pvd.stem`` with the point array ``worn_depth`` [m] (each surface's own depth on its
    own nodes: the contact nodes and, at node-to-node pairs, their partners; NaN off the
    interfaces; :func:`fretwear.model.projection.partner_node_values` for
    node-to-segment partners), stepped through by the ``.pvd`` with the cycle count as time."""
    folder = pvd.parent / pvd.stem
    entries = []
    for k, cycles in enumerate(ds["cycles"].values):
        path = write_vtu(folder / f"step-{k:04d}.vtu", output_mesh(model),
                         {"worn_depth": _node_depths(model, ds, k)}, {"cycles": float(cycles)})
        entries.append((float(cycles), path))
    return write_pvd(pvd, entries)


def _node_depths(model, ds, k: int) -> np.ndarray:
    """(nn,) the worn depth [m] of every mesh node at recorded step ``k`` (NaN off the
    interfaces; :func:`write_wear_fields`)."""
    c = model.contact
    worn = ds["worn_depth_surface"].values
    mesh = output_mesh(model)
    w = np.full(mesh.points.shape[0], np.nan)
    w[mesh.point_index(c.node_ids)] = worn[k, :, 0]
    if c.has_pairs:  # node-to-segment: shape-function average on the facet nodes
        partner, depth = partner_node_values(c, worn[k, :, 1])
        w[mesh.point_index(partner)] = depth
    return w


def write_wear_disk_fields(model, ds, pvd: Path) -> Path:
    """ParaView series of the worn surfaces of the whole tuned disk rebuilt from the sector
    (``model.meta["cyclic"]``; ``[output] whole_disk``): the sector's worn depths of
    :func:`write_wear_fields` on every sector of the mesh of
    :func:`fretwear.model.cyclic.disk_mesh` (the tuned assumption: every sector wears as the
    sector; a partner surface in the next sector, as a damper's seat on the next blade, is
    that sector's copy of the partner nodes), with the point array ``sector`` (each node's
    sector), one ``.vtu`` per recorded step, the cycle count as time."""
    from fretwear.model.cyclic import disk_mesh

    sector = model.meta["cyclic"]
    mesh = disk_mesh(sector)
    nn = model.mesh.points.shape[0]
    which = np.repeat(np.arange(sector.n_sectors), nn).astype(float)
    folder = pvd.parent / pvd.stem
    entries = []
    for k, cycles in enumerate(ds["cycles"].values):
        w = np.tile(_node_depths(model, ds, k), sector.n_sectors)
        path = write_vtu(folder / f"disk-{k:04d}.vtu", mesh,
                         {"worn_depth": w, "sector": which},
                         {"cycles": float(cycles), "tuned_assumption": 1.0})
        entries.append((float(cycles), path))
    return write_pvd(pvd, entries)


def wear_figures(ds, case, outdir: Path, nodes) -> list[Path]:
    """The figures of a wear run (``case.output``: whether and in which format; ``nodes``:
    those of the wear kinetics, default :func:`default_nodes`)."""
    out = case.output
    if not out["figures"]:
        return []
    fmt = out["figure_format"]
    t = case.title
    figs = [
        plot_wear_profiles(ds, outdir / f"wear-profile.{fmt}", title=f"{t}: worn profile"),
        plot_wear_kinetics(ds, outdir / f"wear-kinetics.{fmt}",
                           nodes if nodes else default_nodes(ds), title=f"{t}: wear kinetics"),
        plot_pressure_slip(ds, outdir / f"pressure-slip.{fmt}",
                           title=f"{t}: pressure and slip"),
        plot_worn_volume(ds, outdir / f"worn-volume.{fmt}", title=f"{t}: worn volume"),
    ]
    return figs + maps_and_frf_figures(ds, outdir / f"wear-maps.{fmt}", f"{t}: worn surfaces",
                                       "last step", (outdir, "frf-worn", fmt,
                                                     f"{t}: FRF before / after wear"))


def maps_and_frf_figures(ds: xr.Dataset, maps: Path, maps_title: str, when: str,
                         frf: tuple) -> list[Path]:
    """The figures a wear run and a worn state share: maps of the worn surfaces and of the
    mean pressure at the last record (``when`` says which: "last step", "at the state"; 3D or
    several interfaces only) into ``maps``, and each observed point's FRF before and after
    wear when the run computed them: ``frf = (folder, file stem, format, title)``."""
    figs = []
    if plots.wants_interface_maps(ds):
        last = ds["worn_depth_surface"].values[-1]
        fields = [("worn depth, contact surface", last[:, 0], "m")]
        if np.any(last[:, 1] > 0):
            fields.append(("worn depth, partner surface", last[:, 1], "m"))
        fields.append((f"mean pressure ({when})", ds["pressure_mean"].values[-1], "Pa"))
        figs.append(plots.plot_interface_maps(ds, fields, maps, title=maps_title))
    if "frf_amplitude" in ds:
        folder, stem, fmt, title = frf
        for p in ds["point"].values:
            path = folder / f"{stem}-{safe_name(str(p))}.{fmt}"
            figs.append(plot_frf_before_after(ds, path, str(p), title=title))
    return figs


_POS = Number(lo=0, lo_open=True)
_FRF = Table(
    {
        "f_min": Field(_POS, "lowest frequency", required=True, unit="Hz"),
        "f_max": Field(_POS, "highest frequency", required=True, unit="Hz"),
        "n_points": Field(Integer(lo=2), "number of frequencies", default=100),
        "spacing": Field(Text(("linear", "log")), "frequency spacing",
                         default=WORN_FRF.spacing),
        "time_domain": Field(Flag(), "where a point's balance fails, integrate in time from "
                             "the neighbour (as in `frf` sweeps)",
                             default=default_of(api.frf_worn, "time_domain")),
    },
    checks=(increasing("f_min", "f_max", "Hz"),),
    doc="Nonlinear FRFs (fretwear.hb.sweep) of the unworn and the worn interface.",
)

#: keys of the ``[analysis]`` table of ``type = "wear"``
SCHEMA = {
    "frequency": Field(_POS, "excitation frequency (with quasi_static: only the time "
                       "scale; default 1 Hz)", unit="Hz"),
    "quasi_static": Field(Flag(), "drop inertia and damping (slow cyclic loading)",
                          default=default_of(simulate_wear, "quasi_static")),
    "harmonics": Field(Integer(lo=1), "kept harmonics 1..harmonics",
                       default=default_of(FourierBasis.up_to, "nh")),
    "n_samples": Field(Integer(lo=3), "time samples per period",
                       default=default_of(FourierBasis.up_to, "n_samples")),
    **condensation_fields(),
    "eps": Field(AnyOf((Text(RULES), _POS)), 'DLFT penalty: "auto" (the spectral radius of '
                 'Z_r over the kept harmonics, the paper), "top" (that of Z_r at the highest '
                 'kept harmonic), "stiff" (ten times "top"), "contact" ("stiff" on rigid sliders '
                 'under a prescribed normal load, "top" elsewhere), "static" (that of the static '
                 'K_r) or a value; default: "auto" for the wear run (simulate_wear), "contact" '
                 'for the FRFs '
                 'of frf_before_after (as sweeps)', unit="N/m"),
    # wear options: option() takes the default of WearOptions
    "solver": option("solver", Text(SOLVERS), "nonlinear solver of the first periodic solve "
                     "and the fallback of the slow steps"),
    "tol": option("tol", _POS, "relative residual of the periodic solves |f| <= tol |Z U|",
                  unit="-"),
    "law": option("law", Text(LAWS), '"archard" (k_w = contact.wear_coefficient, paper '
                  'eq. 29) or "energy" (worn volume = energy_coefficient x friction energy)'),
    "energy_coefficient": option("energy_coefficient", Number(lo=0), "k_e of the energy law "
                                 "(the surface of every contact node)", unit="m^3/J"),
    "partner_energy_coefficient": option(
        "partner_energy_coefficient", Number(lo=0), "k_e of the energy law for the partner "
        "surfaces of node-to-node pairs ([[contact]] partner); unset: they do not wear",
        unit="m^3/J"),
    "scheme": option("scheme", Text(SCHEMES), '"rosenbrock" (linearly implicit Euler, stable '
                     'for any jump, the cheapest), "implicit" (backward Euler) or "explicit" '
                     "(explicit Euler, paper eq. 30: stable only for jumps below 2/rho)"),
    "adaptive": option("adaptive", Flag(), "adapt the jump to `tolerance`; false: constant "
                       "jumps of `initial_jump`"),
    "tolerance": option("tolerance", _POS, "local error per step relative to the maximum wear "
                        "depth", unit="-"),
    "initial_jump": option("initial_jump", _POS, "first jump (default: from the slow "
                           "Jacobian's spectral radius)", unit="cycles"),
    "max_jump": option("max_jump", Number(lo=0, lo_open=True, allow_inf=True), "cap on the "
                       "jump", unit="cycles"),
    "max_cycles": option("max_cycles", _POS, "stop at this cycle count", unit="cycles"),
    "max_depth": option("max_depth", _POS, "stop when a wear depth reaches this (default: "
                        "no limit)", unit="m", fill=False),
    "plateau_rate": option("plateau_rate", Number(lo=0), "stop when the worn-volume rate falls "
                           "below this fraction of its initial value", unit="-"),
    "max_steps": option("max_steps", Integer(lo=1), "stop after this many slow steps"),
    "time_domain_rescue": option("time_domain_rescue", Flag(), "dynamic cases: when a step's "
                                 "periodic balance fails, take the step from a time "
                                 "integration: its periodic state, or its wear rate averaged "
                                 "over periods (docs/wear.md)"),
    "time_domain_settle": option("time_domain_settle", Integer(lo=0), "periods integrated "
                                 "before averaging in such a step", unit="periods"),
    "time_domain_average": option("time_domain_average", Integer(lo=2), "periods over which "
                                  "such a step averages the wear rate", unit="periods"),
    "time_domain_steps": option("time_domain_steps", Integer(lo=8), "time steps per period of "
                                "such a step (default: max(128, 8 x the highest harmonic))"),
    "record_every": Field(Integer(lo=1), "keep every n-th step in results.nc (the last "
                          "always)", default=1),
    "checkpoint_every_s": option("checkpoint_every_s", Number(lo=0), "checkpoint interval "
                                 "(0: every step)", unit="s"),
    "plot_nodes": Field(ListOf(Integer(lo=0), non_empty=True, unique=True),
                        "contact nodes of the wear-kinetics figure (default: the most "
                        "worn)"),
    "frf_before_after": Field(_FRF, "nonlinear FRFs before and after wear (paper "
                              "Fig. 24)"),
}
CHECKS = (_check_table,)
#: the keys of :data:`SCHEMA` that are wear options (:class:`~fretwear.wear.options.WearOptions`)
OPTION_KEYS = tuple(k for k in SCHEMA if k in OPTION_DEFAULTS)
DOC = (
    "Fretting wear on the slow time scale (DLFT with wear, paper section 3.3): the wear "
    "depth of every contact node evolves with the cycle count until a plateau of the worn "
    "volume, a depth or a cycle count. A checkpoint `wear-checkpoint.npz` in the results "
    "folder lets `fretwear run CASE.toml --resume` continue an interrupted run to the same "
    "result. Writes `wear-profile.png`, `wear-kinetics.png`, `pressure-slip.png`, "
    "`worn-volume.png`, with several or 3D interfaces `wear-maps.png` (worn depth of each "
    "surface over each interface), with `frf_before_after` `frf-worn-<point>.png`, and for "
    "mesh models the ParaView series `wear.pvd` of the worn surfaces; for a sector with "
    "`[output] whole_disk = true`, `wear-disk.pvd`: the worn surfaces of the whole disk, every "
    "sector with the sector's wear (the tuned assumption)."
)

WEAR = Analysis.define("wear", SCHEMA, run_wear, checks=CHECKS, doc=DOC,
                       files=(CHECKPOINT_FILE,), preload_check=True)
