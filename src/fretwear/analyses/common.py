"""Helpers shared by several analyses: observed points, figure paths, the geometry of a results
dataset, the harmonic-balance keys of ``[analysis]`` tables, solver attributes, array padding,
interface abscissae, SI prefixes, figure titles and the contact under the preload.

Figure functions shared by several analyses are in :mod:`fretwear.analyses.figures`.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr

from fretwear.errors import InputError
from fretwear.files import inside, safe_name
from fretwear.hb.condensers import METHODS, CondensationChoice, condenser
from fretwear.hb.cyclic import cyclic_condenser
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.penalty import RULES
from fretwear.hb.preload import preload_contact
from fretwear.hb.solvers import SOLVERS, SolveStats
from fretwear.io.results import label_coordinate, variable
from fretwear.io.schema import AnyOf, Field, Integer, ListOf, Number, Text, fail, join
from fretwear.model.cyclic import harmonic_index

#: contact-local components of the contact nodes (normal, tangents)
COMPONENTS = ("N", "T1", "T2")
#: structure axes
AXES = ("x", "y", "z")
#: |v| below this fraction of its peak counts as stopped (as ``stops_per_period``)
STOP_TOL = 5e-2


# --- the contact under the preload ------------------------------------------------------------
#: global attribute of the results of the analyses that run the contact law: the interfaces
#: that no node of touches under the static loads (comma-separated; empty: none)
OPEN_ATTRIBUTE = "open_under_preload"
#: global attribute of every results file: the run's warnings, one per line (empty: none)
WARNINGS_ATTRIBUTE = "warnings"


def preload_notes(model, condenser=None) -> tuple[list[str], list[str]]:
    """Warnings about interfaces that no node touches under the static loads (the preload),
    and the names of those interfaces (:func:`fretwear.hb.preload.preload_contact`).

    A run on such an interface is kept (a clearance that the vibration closes is a model a
    user may mean), but it is almost always a mistake (a gap of the wrong sign, a load pulling
    the bodies apart, a partner surface that is not the one meant), so the run says it before
    it starts and the results file records it (:data:`OPEN_ATTRIBUTE`). ``condenser``: the
    run's condenser of ``model`` (:func:`fretwear.hb.reduce.exact_condenser`; None: a new one).
    """
    pre = preload_contact(model, condenser=condenser)
    if not pre.success:
        return ([f"warning: the static contact problem under the preload did not converge "
                 f"({pre.message}); the contact of the interfaces before the vibration is not "
                 "known"], [])
    gap = np.broadcast_to(np.asarray(model.contact.gap, dtype=float), (model.contact.n_nodes,))
    where = model.contact.interface_index()
    notes = []
    names = pre.open_interfaces()
    for name in names:
        k = pre.names.index(name)
        nodes = where == k
        why = (f"its smallest initial gap is {float(gap[nodes].min()):.3g} m"
               if float(gap[nodes].min()) > 0 else
               "the static loads do not press its nodes together")
        notes.append(f"warning: interface {name!r} is open at all its {int(nodes.sum())} nodes "
                     f"under the static loads (the preload; {why}): friction and wear can act "
                     "there only where the vibration closes it; check the gap, the direction "
                     "of the static loads and the contact surfaces")
    return notes, names


# --- observed points, figures, geometry -----------------------------------------------------
def check_points(model, requested) -> list[str]:
    """The observed points to report: ``requested`` (the ``points`` key), checked against the
    model's observed points, or all of them when it is None."""
    names = [p.name for p in model.observed]
    if requested is None:
        return names
    unknown = [p for p in requested if p not in names]
    if unknown:
        fail("analysis.points", requested,
             "names of observed points: " + (", ".join(repr(n) for n in names) or "(none)"))
    return list(requested)


def figure_path(case, outdir: Path, stem: str) -> Path | None:
    """``outdir/stem.<figure_format>``, or None when the case's output asks for no figures.
    ``stem`` may hold user names (observed points): it is made safe as a file name
    (:func:`fretwear.files.safe_name`), so the file is always in ``outdir``."""
    out = case.output
    if not out["figures"]:
        return None
    return inside(outdir, outdir / f"{safe_name(stem)}.{out['figure_format']}")


def geometry(model, points: list[str]) -> tuple[dict, dict]:
    """Coordinates (``point``, ``axis``, ``contact_node``, ``component``) and position variables
    (``point_position``, ``contact_position``, ``contact_area``) of the observed points and
    contact nodes: the shared part of every results dataset (``docs/results.md``)."""
    c = model.contact
    nc, d = c.dofs.shape
    n_axes = max([d] + [len(model.observed_point(p).dofs) for p in points])
    coords = {
        "point": label_coordinate("point", points),
        "axis": label_coordinate("axis", AXES[:n_axes]),
        "contact_node": variable("contact_node", np.arange(nc), "1", "contact node, from 0"),
        "component": label_coordinate("component", COMPONENTS[:d]),
    }
    pos = np.full((len(points), n_axes), np.nan)
    for i, name in enumerate(points):
        xyz = np.asarray(model.observed_point(name).coords, dtype=float).reshape(-1)
        pos[i, : min(xyz.size, n_axes)] = xyz[:n_axes]
    cpos = np.full((nc, n_axes), np.nan)
    cc = np.asarray(c.coords, dtype=float).reshape(nc, -1)
    cpos[:, : min(cc.shape[1], n_axes)] = cc[:, :n_axes]
    data = {
        "point_position": variable(("point", "axis"), pos, "m", "position of the observed point"),
        "contact_position": variable(("contact_node", "axis"), cpos, "m",
                                     "position of the contact node"),
        "contact_area": variable("contact_node", np.asarray(c.area, dtype=float), "m^2",
                                 "tributary area of the contact node"),
        "contact_interface": interface_labels(model),
    }
    return coords, data


def interface_labels(model):
    """The interface name of every contact node (contact_node), a label variable."""
    c = model.contact
    names = np.asarray(c.names(), dtype=str)[c.interface_index()]
    return variable("contact_node", names, "1", "interface of the contact node (its name)")


def live_axes(ds: xr.Dataset, point: str) -> list[str]:
    """The axes ``point`` has (``point_position`` is NaN on the others)."""
    pos = ds["point_position"].sel(point=point)
    return [str(a) for a in ds["axis"].values if np.isfinite(pos.sel(axis=a).values)]


def pad_axes(arrays: list[np.ndarray], n_axes: int) -> np.ndarray:
    """Stack per-point arrays ``(d_p, ...)`` into ``(n_points, n_axes, ...)``, NaN-padded."""
    trailing = arrays[0].shape[1:] if arrays else ()
    out = np.full((len(arrays), n_axes) + trailing, np.nan)
    for i, a in enumerate(arrays):
        out[i, : a.shape[0]] = a
    return out


def period_coordinates(basis: FourierBasis) -> dict:
    """Coordinates ``harmonic_coefficient``, ``tau`` [rad] and ``harmonic`` of ``basis``."""
    return {
        "harmonic_coefficient": label_coordinate("harmonic_coefficient", basis.labels()),
        "tau": variable("tau", basis.tau, "rad", "angle tau = omega t over one period"),
        "harmonic": variable("harmonic", np.asarray(basis.harmonics), "1",
                             "kept harmonic number"),
    }


# --- defaults ------------------------------------------------------------------------------
def default_of(func: Callable, name: str):
    """The default of the keyword ``name`` of ``func``: the signature of the function an
    analysis calls is the one definition of a case-file key's default (e.g.
    ``default_of(solve_periodic, "tol")``)."""
    param = inspect.signature(func).parameters[name]
    if param.default is inspect.Parameter.empty:
        raise ValueError(f"{func.__qualname__}() has no default for {name!r}")
    return param.default


# --- harmonic-balance keys of [analysis] tables --------------------------------------------
def harmonic_list(value) -> list[int]:
    """Kept harmonics from the ``harmonics`` key: ``Nh`` -> ``[1..Nh]``, a list -> sorted."""
    if isinstance(value, int):
        return list(range(1, value + 1))
    return sorted(int(h) for h in value)


def basis_of(analysis: dict) -> FourierBasis:
    """The Fourier basis an ``[analysis]`` table asks for (``harmonics``, ``n_samples``)."""
    return FourierBasis(tuple(harmonic_list(analysis["harmonics"])), analysis["n_samples"])


def check_sampling(out: dict, path: str) -> None:
    """Rule: ``n_samples`` exceeds twice the highest kept harmonic (no aliasing)."""
    if "harmonics" not in out or "n_samples" not in out:
        return
    top = max(harmonic_list(out["harmonics"]))
    if out["n_samples"] <= 2 * top:
        fail(join(path, "n_samples"), out["n_samples"],
             f"more than {2 * top} samples per period (twice the highest harmonic, {top})")


def basis_fields() -> dict:
    """The keys ``harmonics`` and ``n_samples`` of the Fourier basis, with the defaults of
    :meth:`fretwear.hb.fourier.FourierBasis.up_to`."""
    return {
        "harmonics": Field(
            AnyOf((Integer(lo=1), ListOf(Integer(lo=1), non_empty=True, unique=True))),
            "kept harmonics: Nh keeps 1, 2, .., Nh; a list keeps those listed (e.g. [1, 3, 5])",
            default=default_of(FourierBasis.up_to, "nh")),
        "n_samples": Field(Integer(lo=3), "time samples per period N of the contact law "
                           "(more than twice the highest harmonic)",
                           default=default_of(FourierBasis.up_to, "n_samples")),
    }


def condensation_fields() -> dict:
    """The keys of the condensation (``condensation``, ``condensation_modes``,
    ``condensation_cutoff``, ``condensation_tol``), with the defaults of
    :func:`fretwear.hb.condensers.condenser` (docs/case-files.md, "Condensation")."""
    return {
        "condensation": Field(
            Text(METHODS), 'condensation on the contact DOFs: "exact" (eq. 19 at every '
            'harmonic and frequency), "modal" (one Craig-Bampton basis for every frequency, '
            'with its error check) or "auto" (the modal one for large models where its check '
            "passes, else exact; see Condensation below)",
            default=default_of(condenser, "method")),
        "condensation_modes": Field(
            Integer(lo=0), "modal: the number of fixed-interface modes kept (checked, not "
            "raised; default: those below condensation_cutoff, raised until the check "
            "passes)"),
        "condensation_cutoff": Field(
            Number(lo=0, lo_open=True), "modal: keep the modes below this multiple of the "
            "highest harmonic frequency (then raised until the check passes)",
            default=default_of(condenser, "cutoff"), unit="-"),
        "condensation_tol": Field(
            Number(lo=0, lo_open=True), "modal: bound on the relative error of the check "
            "against the exact condensation at the highest harmonic frequency",
            default=default_of(condenser, "tol"), unit="-"),
    }


def condenser_of(model, analysis: dict, f_max: float | None, max_order: int):
    """The run's condenser of ``model`` as the ``[analysis]`` table asks
    (:func:`condensation_fields`; :func:`fretwear.hb.condensers.condenser`) for excitation
    frequencies up to ``f_max`` [Hz] (None: a quasi-static run, exact) and harmonic orders
    up to ``max_order``; its ``choice`` goes to the run summary and the results attributes.

    A sector of a case file's ``[cyclic]`` table (``model.meta["cyclic"]``, set by
    :func:`fretwear.io.case.build_model`) gets the exact
    :class:`~fretwear.hb.cyclic.CyclicCondenser` of its engine order, whatever the table asks
    (a modal condensation per harmonic index is not available); its choice adds ``N``,
    ``EO`` and the harmonic index of each harmonic up to ``max_order``
    (:class:`CyclicChoice`)."""
    sector = model.meta.get("cyclic")
    if sector is not None:
        cond = cyclic_condenser(sector, model.meta["engine_order"])
        asked = analysis.get("condensation", "auto")
        reason = "one exact condensation per harmonic index (a sector of a disk)"
        cond.choice = CyclicChoice(CondensationChoice(asked, "exact", reason),
                                   sector.n_sectors, cond.engine_order, int(max_order))
        return cond
    return condenser(model, analysis.get("condensation", "auto"), f_max=f_max,
                     max_order=int(max_order), modes=analysis.get("condensation_modes"),
                     cutoff=analysis.get("condensation_cutoff", default_of(condenser, "cutoff")),
                     tol=analysis.get("condensation_tol", default_of(condenser, "tol")))


def mistuning_attributes(model) -> dict:
    """The results attributes of a mistuned disk (``model.meta["mistuning"]``, a case file's
    ``[cyclic.mistuning]``): ``mistuned_sectors`` (N), ``engine_order`` and the factors
    ``mistuning_young``, ``mistuning_mu``, ``mistuning_wear`` (N each); ``{}`` otherwise."""
    mt = model.meta.get("mistuning")
    if mt is None:
        return {}
    return {"mistuned_sectors": int(mt.n_sectors),
            "engine_order": int(model.meta["engine_order"]),
            "mistuning_young": np.asarray(mt.young, float),
            "mistuning_mu": np.asarray(mt.mu, float),
            "mistuning_wear": np.asarray(mt.wear, float)}


#: the analyses that run on a sector of a case file's ``[cyclic]`` table
SECTOR_ANALYSES = ("cyclic-modes", "periodic", "sweep", "wear")


def check_sector_analysis(model, name: str, analysis: dict) -> None:
    """Refuse, in one line, an analysis that would treat a sector (``model.meta["cyclic"]``)
    as a structure with free cyclic boundaries: those not in :data:`SECTOR_ANALYSES`, and a
    sweep's linear references (contact-law-free FRFs of the whole model)."""
    if model.meta.get("cyclic") is None:
        return
    if name not in SECTOR_ANALYSES:
        raise InputError(f'analysis.type = "{name}": not available on a sector ([cyclic]); '
                         f"expected one of {', '.join(SECTOR_ANALYSES)}")
    if analysis.get("linear_references"):
        fail("analysis.linear_references", analysis["linear_references"],
             "none on a sector ([cyclic]): the linear FRFs would leave its cyclic boundaries "
             "free")


@dataclass(frozen=True)
class CyclicChoice:
    """The condensation choice of a sector (:func:`condenser_of`): ``base``'s, with the
    number of sectors ``n_sectors``, the ``engine_order`` and the harmonic index ``k = n EO
    mod N`` of every harmonic ``n = 0 .. max_order`` in the summary and attributes."""

    base: CondensationChoice
    n_sectors: int
    engine_order: int
    max_order: int

    def indices(self) -> np.ndarray:
        """(max_order + 1,) the harmonic index of harmonics 0 .. max_order."""
        return harmonic_index(np.arange(self.max_order + 1), self.engine_order, self.n_sectors)

    def summary(self) -> str:
        pairs = ", ".join(f"{n}: {k}" for n, k in enumerate(self.indices()))
        return (f"{self.base.summary()}\ncyclic sector: N = {self.n_sectors}, engine order "
                f"{self.engine_order}, harmonic index of each harmonic {{{pairs}}}")

    def attributes(self) -> dict:
        return {**self.base.attributes(), "cyclic_sectors": int(self.n_sectors),
                "engine_order": int(self.engine_order),
                "harmonic_index": self.indices().astype(np.int64)}


def harmonic_balance_fields(solve: SolveOptions, eps_default, eps_doc: str) -> dict:
    """The keys of the DLFT analyses' tables (``harmonics``, ``n_samples``, ``eps``,
    ``solver``, ``tol``, ``max_iter``) with the ``eps`` description ``eps_doc``; the defaults
    are those of the solve record the analysis runs with (``solve``:
    :data:`fretwear.hb.options.PERIODIC`, :data:`fretwear.hb.options.SWEEP_POINT`), of the
    penalty of the function it calls (``eps_default``) and of
    :meth:`~fretwear.hb.fourier.FourierBasis.up_to`."""
    return {
        **basis_fields(),
        **condensation_fields(),
        "eps": Field(AnyOf((Text(RULES), Number(lo=0, lo_open=True))), eps_doc,
                     default=eps_default, unit="N/m"),
        "solver": Field(Text(SOLVERS), '"powell" (hybrid dog-leg, LAPACK), "newton" (damped '
                        'Newton) or "hybr" (MINPACK hybrj, as in the paper)',
                        default=solve.solver),
        "tol": Field(Number(lo=0, lo_open=True), "relative residual of the convergence test "
                     "|f(U)| <= tol |Z_r U| (paper section 3.2)", default=solve.tol,
                     unit="-"),
        "max_iter": Field(Integer(lo=1), "maximum solver iterations per frequency",
                          default=solve.max_iter),
    }


def solve_options_of(analysis: dict, base: SolveOptions) -> SolveOptions:
    """The :class:`~fretwear.hb.options.SolveOptions` of an ``[analysis]`` table: ``base``
    with the table's ``solver``, ``tol``, ``max_iter`` and ``time_domain_periods`` (those it
    has)."""
    keys = ("solver", "tol", "max_iter", "time_domain_periods")
    return base.replace(**{k: analysis[k] for k in keys if k in analysis})


def solver_attributes(stats: SolveStats, analysis: dict, eps: float) -> dict:
    """Solver settings and statistics of one solve as NetCDF attributes (numbers and strings
    only): solver, message, residual, iterations, evaluations, wall time, eps and its rule,
    harmonics, samples."""
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


# --- figure helpers ------------------------------------------------------------------------
def titled(title: str, suffix: str) -> str:
    """``"title: suffix"``, or ``title`` when it already says ``suffix``."""
    return title if suffix.lower() in title.lower() else f"{title}: {suffix}"


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


def cell_edges(x: np.ndarray) -> np.ndarray:
    """Cell edges around increasing or decreasing centres ``x`` (for ``pcolormesh``)."""
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
