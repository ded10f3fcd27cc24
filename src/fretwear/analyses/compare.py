"""``fretwear compare CASE.toml``: the DLFT against the time-domain reference on one case.

* A ``periodic`` case at a frequency: the DLFT periodic solve
(:func:`fretwear.hb.periodic.solve_periodic`,
  the case's harmonics, samples, penalty and solver) and the time-domain steady state of the
  same model (:func:`fretwear.timedomain.steady.steady_state`). One figure ``compare.png``
  (observed
  displacement over one period by both methods, contact-state maps side by side, harmonic
  amplitudes), and a table of relative differences: harmonic-1 amplitude at the observed
  points, friction energy per cycle, stick fraction, with the classification of the
  time-domain response and the wall times.
* A quasi-static ``wear`` case: the DLFT wear (:func:`fretwear.wear.simulate.simulate_wear`, the
case's
  options) and :func:`fretwear.timedomain.quasistatic.incremental_wear` to the same cycle count; one
  figure
  ``compare-wear.png`` overlays the worn profiles.

Relative differences are ``(time - dlft) / |time|``: the time integration is the reference.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap

from fretwear import api
from fretwear.analyses import figures as plots
from fretwear.analyses.common import (
    basis_of,
    cell_edges,
    interface_abscissa,
    si_scale,
    solve_options_of,
)
from fretwear.analyses.run import load_case
from fretwear.analyses.transient import period_friction_energy, state_fractions
from fretwear.errors import InputError
from fretwear.hb.options import PERIODIC
from fretwear.hb.reduce import condense, exact_condenser
from fretwear.hb.solution import PeriodicSolution
from fretwear.io.case import build_model
from fretwear.timedomain.options import (
    IncrementalWearOptions,
    IntegrationOptions,
    SteadyStateOptions,
)
from fretwear.timedomain.quasistatic import incremental_wear
from fretwear.timedomain.results import SteadyStateResult
from fretwear.timedomain.steady import steady_state

#: cycles computed by the incremental wear reference (at most; the jump sets the rest)
WEAR_COMPUTED_CYCLES = 200


@dataclass
class Comparison:
    """Outcome of :func:`compare_periodic` or :func:`compare_wear`.

    rows : ``(quantity, dlft, time, relative difference)``; values in SI units, NaN where a
        method has no value.
    classification : of the time-domain response (``""`` for wear).
    dlft_converged : the DLFT solve (or wear run) converged.
    wall_times : method -> wall time [s].
    figure : the figure written (None without ``outdir``).
    """

    rows: list = field(default_factory=list)
    classification: str = ""
    dlft_converged: bool = True
    wall_times: dict = field(default_factory=dict)
    figure: Path | None = None
    notes: list = field(default_factory=list)

    def table(self) -> str:
        """The rows as a fixed-width text table."""
        lines = [f"{'quantity':<34} {'DLFT':>12} {'time domain':>12} {'rel. diff':>10}"]
        for name, a, b, r in self.rows:
            lines.append(f"{name:<34} {a:>12.5g} {b:>12.5g} {r:>10.2e}")
        lines += [f"wall time {k}: {v:.2f} s" for k, v in self.wall_times.items()]
        if self.classification:
            lines.append(f"time-domain response: {self.classification}")
        return "\n".join(lines + self.notes)


def relative(dlft: float, ref: float) -> float:
    """``(ref - dlft) / |ref|`` (NaN when ``ref`` is 0 or either is NaN)."""
    return (ref - dlft) / abs(ref) if ref and math.isfinite(ref) else math.nan


# --- periodic ----------------------------------------------------------------------------------
def _time_amplitudes(ss: SteadyStateResult, name: str) -> np.ndarray:
    """Amplitude of harmonics 1..nh of an observed point (d, nh) [m]."""
    c = ss.harmonics[name]
    nh = (c.shape[0] - 1) // 2
    return np.hypot(c[1:nh + 1], c[nh + 1:]).T


def _dlft_amplitudes(sol: PeriodicSolution, name: str, nh: int) -> np.ndarray:
    """Amplitude of harmonics 1..nh (NaN where not kept) (d, nh) [m]."""
    amp = sol.observed_amplitude(name)
    out = np.full((amp.shape[0], nh), np.nan)
    for j, h in enumerate(sol.basis.harmonics):
        if h <= nh:
            out[:, h - 1] = amp[:, j]
    return out


def periodic_rows(model, sol: PeriodicSolution | None, ss: SteadyStateResult) -> list:
    """Rows of the comparison table (see :class:`Comparison`)."""
    area = np.asarray(model.contact.area, float)
    nh = (next(iter(ss.harmonics.values())).shape[0] - 1) // 2
    rows = []
    for p in model.observed:
        at = _time_amplitudes(ss, p.name)[:, 0]
        ad = _dlft_amplitudes(sol, p.name, nh)[:, 0] if sol is not None else at * np.nan
        for k, (a, b) in enumerate(zip(ad, at, strict=True)):
            rows.append((f"|u_{'xyz'[k]}| harmonic 1 at {p.name} [m]", a, b, relative(a, b)))
    e_t = float(period_friction_energy(ss.last).sum())
    s_t = float(state_fractions(ss.last.state.T, area)[1])
    e_d = float(sol.friction_energy().sum()) if sol is not None else math.nan
    s_d = float(area @ sol.state_fractions()[:, 1] / area.sum()) if sol is not None else math.nan
    rows.append(("friction energy per cycle [J]", e_d, e_t, relative(e_d, e_t)))
    rows.append(("stick fraction [-]", s_d, s_t, relative(s_d, s_t)))
    return rows


def _draw_state(ax, x, state: np.ndarray, label: str) -> None:
    """Contact-state map (nc, N) of one method on ``ax``."""
    order = np.argsort(x, kind="stable")
    n = state.shape[1]
    cmap = ListedColormap(plots.STATE_COLOURS)
    ax.pcolormesh(cell_edges(x[order]), (np.arange(n + 1) - 0.5) / n, state[order].T, cmap=cmap,
                  norm=BoundaryNorm([-0.5, 0.5, 1.5, 2.5], cmap.N), shading="flat")
    ax.set_title(f"contact state, {label} (blue stick, orange slip, grey separation)",
                 fontsize="small")
    ax.set_ylabel("t / T [-]")


def plot_periodic_comparison(model, sol, ss: SteadyStateResult, path: Path, *,
                             title: str | None = None) -> Path:
    """Observed displacement over a period, contact-state maps and harmonic amplitudes."""
    name = model.observed[0].name
    fig, axes = plots.new_figure(2, 2, title=title, panel_size=(6.0, 3.6))
    u_t = ss.last.observed[name][:, 0]
    t_t = np.arange(u_t.size) / u_t.size
    k, unit = si_scale(u_t - u_t.mean(), "m")
    ax = axes[0, 0]
    ax.plot(t_t, k * (u_t - u_t.mean()), lw=2.6, zorder=2.0,  # wide, below the DLFT
            label=f"time domain ({ss.classification})")
    if sol is not None:
        u_d = sol.observed_time(name)[0][0]
        ax.plot(sol.tau / (2 * np.pi), k * (u_d - u_d.mean()), "--", lw=1.2, zorder=2.1,
                label="DLFT")
    ax.set(xlabel="t / T [-]", ylabel=f"u_x - mean at {name} [{unit}]")
    ax.legend(fontsize="small")
    ax.grid(True, alpha=0.3)
    ax = axes[0, 1]
    a_t = _time_amplitudes(ss, name)[0]
    h = np.arange(1, a_t.size + 1)
    ax.bar(h - 0.2, a_t, 0.4, label="time domain")
    if sol is not None:
        ax.bar(h + 0.2, _dlft_amplitudes(sol, name, a_t.size)[0], 0.4, label="DLFT")
    ax.set_yscale("log")
    ax.set(xlabel="harmonic", ylabel=f"|u_x| at {name} [m]")
    ax.legend(fontsize="small")
    x = _contact_abscissa(model)
    _draw_state(axes[1, 0], x, ss.last.state.T, "time domain")
    if sol is not None:
        _draw_state(axes[1, 1], x, sol.state, "DLFT")
    else:
        axes[1, 1].text(0.5, 0.5, "DLFT did not converge", ha="center", va="center")
    for ax in axes[1]:
        ax.set_xlabel("contact node position along T1 [m]")
    return plots.save(fig, path)


def _contact_abscissa(model) -> np.ndarray:
    """Position of the contact nodes along the interface (for figures)."""
    import xarray as xr

    pos = np.asarray(model.contact.coords, float).reshape(len(model.contact.area), -1)
    ds = xr.Dataset({"contact_position": (("contact_node", "axis"), pos)},
                    coords={"axis": list("xyz"[: pos.shape[1]])})
    return interface_abscissa(ds)[0]


def compare_periodic(model, analysis: dict, outdir: Path | None, *, steps_per_period: int = 512,
                     max_periods: int = 20_000, title: str | None = None) -> Comparison:
    """DLFT periodic solve against the time-domain steady state (module docstring).

    Parameters
    ----------
    model : the model; analysis : the validated ``periodic`` table (at a frequency);
    outdir : folder of ``compare.png`` (None: no figure); steps_per_period : time steps per
    period of the integration; max_periods : its period budget; title : figure title.
    """
    if analysis.get("quasi_static"):
        raise InputError("compare: a quasi-static periodic case has no time-domain dynamic "
                         "counterpart; give a frequency (or a quasi-static wear case)")
    basis = basis_of(analysis)
    f_hz = float(analysis["frequency"])
    t0 = time.perf_counter()
    cond = exact_condenser(model)  # one condensation of the model for the whole solve
    reduced = condense(model, f_hz, basis.orders, condenser=cond)
    # the DLFT alone: never started by the time integration it is compared with
    sol = api.solve_periodic(model, basis, frequency=f_hz,
                             options=solve_options_of(analysis, PERIODIC), reduced=reduced,
                             eps=analysis["eps"], time_domain=False, condenser=cond)
    stats = sol.stats
    if not sol.success:  # a failed solve is never compared (its last iterate is no result)
        sol = None
    t_dlft = time.perf_counter() - t0
    ss = steady_state(model, f_hz,
                      options=SteadyStateOptions(max_periods=max_periods,
                                                 harmonics=max(basis.harmonics)),
                      integration=IntegrationOptions(steps_per_period=steps_per_period))
    out = Comparison(periodic_rows(model, sol, ss), ss.classification, sol is not None,
                     {"DLFT": t_dlft, "time domain": ss.wall_time})
    out.notes.append(f"time domain: {ss.n_periods} periods x {steps_per_period} steps")
    if sol is None:
        out.notes.append(f"DLFT did not converge: {stats.message} (relative residual "
                         f"{stats.residual:.3g} after {stats.iterations} iterations)")
    if outdir is not None:
        out.figure = plot_periodic_comparison(model, sol, ss, Path(outdir) / "compare.png",
                                              title=title)
    return out


# --- wear --------------------------------------------------------------------------------------
def _reference_jump(n_cycles: int, stability_jump: float) -> int:
    """Cycle jump of the incremental reference: about ``WEAR_COMPUTED_CYCLES`` computed cycles,
    at most half the explicit stability limit of the slow scale when it is known."""
    jump = max(1, math.ceil(n_cycles / WEAR_COMPUTED_CYCLES))
    if math.isfinite(stability_jump) and stability_jump > 0:
        jump = min(jump, max(1, int(0.5 * stability_jump)))
    return jump


def compare_wear(model, analysis: dict, outdir: Path | None, *, steps_per_cycle: int = 128,
                 title: str | None = None) -> Comparison:
    """DLFT wear against incremental wear at the DLFT run's final cycle count."""
    from fretwear.analyses.wear import options_from_table, penalty_of
    from fretwear.wear import BalanceSetup

    if not analysis.get("quasi_static"):
        raise InputError("compare: the incremental wear reference is quasi-static; set "
                         "quasi_static = true in the wear case")
    basis = basis_of(analysis)
    cond = exact_condenser(model)  # shared by both methods: the same static condensation
    res = api.simulate_wear(model, basis, quasi_static=True,
                            options=options_from_table(analysis),
                            balance=BalanceSetup(condenser=cond, **penalty_of(analysis)),
                            time_domain=False)
    n = int(round(float(res.history.cycles[-1])))
    jump = _reference_jump(n, res.stability_jump)
    inc = incremental_wear(model, n_cycles=max(n, 1),
                           options=IncrementalWearOptions(steps_per_cycle=steps_per_cycle,
                                                          cycle_jump=jump),
                           condenser=cond)
    w_d, w_t = res.final_wear, inc.wear[-1]
    area = np.asarray(model.contact.area, float)
    rows = [("maximum wear depth [m]", w_d.max(), w_t.max(), relative(w_d.max(), w_t.max())),
            ("worn volume [m^3]", w_d @ area, w_t @ area, relative(w_d @ area, w_t @ area)),
            ("profile: max |dW| / max W [-]", 0.0, float(np.abs(w_t - w_d).max() / w_t.max()),
             math.nan)]
    out = Comparison(rows, "", res.success, {"DLFT wear": res.wall_time,
                                               "incremental wear": inc.wall_time})
    out.notes.append(f"{n} cycles; DLFT {res.history.n_steps} slow steps ({res.stop_reason}); "
                     f"incremental {inc.computed_cycles} computed cycles x {steps_per_cycle} "
                     f"load steps, jump {jump}")
    if outdir is not None:
        out.figure = plot_wear_comparison(model, res.history, inc, Path(outdir) /
                                          "compare-wear.png", title=title)
    return out


def plot_wear_comparison(model, hist, inc, path: Path, *, title: str | None = None) -> Path:
    """Worn profiles of both methods at up to four common cycle counts."""
    x = _contact_abscissa(model)
    o = np.argsort(x, kind="stable")
    fig, axes = plots.new_figure(title=title, panel_size=(7.0, 3.8))
    ax = axes[0, 0]
    k, unit = si_scale(inc.wear, "m")
    picks = sorted({int(i) for i in np.linspace(0, inc.cycles.size - 1, 4).round()})
    for c, i in enumerate(picks):
        n = inc.cycles[i]
        colour = f"C{c}"
        ax.plot(x[o], k * inc.wear[i][o], color=colour, lw=2.6, alpha=0.6, zorder=2.0,
                label=f"incremental, {n:.3g} cycles")  # a band below the DLFT's line
        w = np.array([np.interp(n, hist.cycles, hist.wear_depth[:, j])
                      for j in range(x.size)])
        ax.plot(x[o], k * w[o], "--", color=colour, marker=".", label=f"DLFT, {n:.3g} cycles")
    ax.set(xlabel="contact node position along T1 [m]", ylabel=f"wear depth [{unit}]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="x-small", ncol=2)
    return plots.save(fig, path)


# --- command -----------------------------------------------------------------------------------
def compare_case(path: Path | str, outdir: Path | str | None = None, *,
                 steps_per_period: int = 512, max_periods: int = 20_000) -> Comparison:
    """Run the comparison a case file calls for, write the figure, print the table.

    Parameters
    ----------
    path : a ``periodic`` case at a frequency, or a quasi-static ``wear`` case.
    outdir : figure folder (default ``<case stem>-compare`` next to the case).
    steps_per_period : time steps per period (periodic) or load steps per cycle (wear).
    max_periods : period budget of the steady-state integration.
    """
    case = load_case(path)
    a = case.analysis
    out_dir = Path(outdir) if outdir is not None else case.path.with_name(
        f"{case.path.stem}-compare")
    out_dir.mkdir(parents=True, exist_ok=True)
    model = build_model(case)
    if a["type"] == "periodic":
        res = compare_periodic(model, a, out_dir, steps_per_period=steps_per_period,
                               max_periods=max_periods, title=case.title)
    elif a["type"] == "wear":
        res = compare_wear(model, a, out_dir, steps_per_cycle=steps_per_period,
                           title=case.title)
    else:
        raise InputError(f"compare: analysis.type = {a['type']!r}; expected a \"periodic\" "
                         "or a quasi-static \"wear\" case")
    print(res.table())
    print(f"figure:  {res.figure}")
    return res
