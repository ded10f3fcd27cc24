"""The linear analyses of case files: ``"modes"`` and ``"frf"`` (see :mod:`fretwear.linear`).

Each function turns :mod:`fretwear.linear` results into a results dataset (schema in
``docs/results.md``), figures and ParaView files; :data:`MODES` and :data:`FRF` are the
analyses (:mod:`fretwear.analyses.registry` lists them).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from tqdm import tqdm

from fretwear import linear
from fretwear.analyses import figures as plots
from fretwear.analyses.base import Analysis, RunContext, RunOutput
from fretwear.analyses.common import AXES, check_points, default_of, figure_path, geometry
from fretwear.errors import InputError
from fretwear.hb.reduce import exact_condenser
from fretwear.io.results import (
    complex_variables,
    label_coordinate,
    no_fields_line,
    nodal_vectors,
    output_mesh,
    variable,
    write_pvd,
    write_vtu,
)
from fretwear.io.schema import Field, Integer, ListOf, Number, Text, increasing

_INTERFACES = Field(
    ListOf(Text(linear.INTERFACES), non_empty=True, unique=True),
    'linear limits of the contact: "free" (no contact), "sliding" (normal held, frictionless), '
    '"stuck" (every contact DOF held)',
    default=["sliding", "stuck"],
)


# --- helpers ------------------------------------------------------------------------------------
def _need_mass(model) -> None:
    if model.M.nnz == 0 or not np.any(model.M.diagonal()):
        raise InputError("the model has no mass: modes and FRFs need material.rho > 0 (or a "
                         "non-zero mass matrix)")


def _pad_points(values_by_point: dict, points: list[str], n_axes: int, shape0) -> np.ndarray:
    """Stack per-point arrays ``(n, d_p)`` into ``(*shape0, n_points, n_axes)``, NaN-padded
    (``n <= shape0[0]``: an interface may have fewer modes than the longest one)."""
    dtype = complex if any(np.iscomplexobj(v) for v in values_by_point.values()) else float
    out = np.full(tuple(shape0) + (len(points), n_axes), np.nan, dtype=dtype)
    for i, name in enumerate(points):
        v = np.asarray(values_by_point[name])
        out[: v.shape[0], i, : v.shape[1]] = v
    return out


# --- modes ----------------------------------------------------------------------------------
def run_modes(model, analysis: dict, case, context: RunContext) -> RunOutput:
    """Normal modes for each requested interface (:func:`fretwear.linear.modes`)."""
    _need_mass(model)
    interfaces = analysis["interfaces"]
    points = [p.name for p in model.observed]
    results = []
    for interface in tqdm(interfaces, desc="modes", disable=not context.progress, leave=False):
        results.append(linear.modes(model, analysis["n_modes"], interface=interface,
                                    f_max=analysis.get("f_max")))
    nm = max(len(r.frequency_hz) for r in results)
    c = model.contact
    nc, d = c.dofs.shape
    freq = np.full((len(results), nm), np.nan)
    shape = np.full((len(results), nm, model.ndof), np.nan)
    cshape = np.full((len(results), nm, nc, d), np.nan)
    obs = []
    for i, r in enumerate(results):
        k = len(r.frequency_hz)
        freq[i, :k] = r.frequency_hz
        shape[i, :k] = r.shapes
        # contact-local components: u_loc[p] = frame[p] @ U[dofs[p]]
        cshape[i, :k] = np.einsum("pab,mpb->mpa", c.frame, r.shapes[:, c.dofs])
        obs.append(r.observed)
    coords, data = geometry(model, points)
    n_axes = coords["axis"].size
    coords["interface"] = label_coordinate("interface", interfaces)
    coords["mode"] = variable("mode", np.arange(1, nm + 1), "1", "mode number")
    coords["dof"] = variable("dof", np.arange(model.ndof), "1", "degree of freedom of the model")
    oshape = np.stack([_pad_points(o, points, n_axes, (nm,)) for o in obs])
    unit = "kg^-1/2"
    note = "mass-normalised (phi^T M phi = 1)"
    data.update({
        "natural_frequency": variable(("interface", "mode"), freq, "Hz", "natural frequency"),
        "mode_shape": variable(("interface", "mode", "dof"), shape, unit,
                               f"mode shape, {note}, structure axes"),
        "observed_shape": variable(("interface", "mode", "point", "axis"), oshape, unit,
                                   f"mode shape at the observed point, {note}"),
        "contact_shape": variable(("interface", "mode", "contact_node", "component"), cshape,
                                  unit, f"mode shape at the contact node, {note}, contact-local "
                                  "components"),
    })
    ds = xr.Dataset(data, coords=coords)
    figures, files = [], []
    for interface, r in zip(interfaces, results, strict=True):
        if model.mesh is not None and len(r.frequency_hz):
            p = figure_path(case, context.out_dir, f"modes-{interface}")
            if p is not None:
                figures.append(plots.plot_mode_shapes(
                    model.mesh, r.frequency_hz, r.shapes, p,
                    title=f"{case.title}: modes, {interface} interface"))
        if output_mesh(model) is not None and len(r.frequency_hz) and case.output["vtu"]:
            files.append(_write_mode_files(output_mesh(model), r, context.out_dir, interface))
    p = figure_path(case, context.out_dir, "natural-frequencies")
    if p is not None:
        figures.append(plots.plot_natural_frequencies(ds, p, title=case.title))
    lines = []
    for interface, r in zip(interfaces, results, strict=True):
        fs = ", ".join(f"{f:.5g}" for f in r.frequency_hz[:12]) or "none"
        more = " ..." if len(r.frequency_hz) > 12 else ""
        lines.append(f"{interface:>8}: {len(r.frequency_hz)} modes [Hz]: {fs}{more}")
    if case.output["vtu"] and no_fields_line(model):
        lines.append(no_fields_line(model))
    return RunOutput(ds, figures, "\n".join(lines), True, files)


def _write_mode_files(mesh, r, outdir: Path, interface: str) -> Path:
    """One ``.vtu`` per mode (array ``mode_shape``) and a ``.pvd`` stepping through them."""
    folder = outdir / f"modes-{interface}"
    entries = []
    for k, (f, phi) in enumerate(zip(r.frequency_hz, r.shapes, strict=True)):
        path = write_vtu(folder / f"mode-{k + 1:03d}.vtu", mesh,
                         {"mode_shape": nodal_vectors(mesh, phi)},
                         {"mode": k + 1, "frequency_hz": f})
        entries.append((k + 1, path))
    return write_pvd(outdir / f"modes-{interface}.pvd", entries)


MODES = Analysis.define(
    "modes",
    {
        "n_modes": Field(Integer(lo=1), "number of lowest modes per interface",
                         default=default_of(linear.modes, "n_modes")),
        "f_max": Field(Number(lo=0, lo_open=True), "if given: every mode up to this frequency "
                       "(n_modes is then ignored)", unit="Hz"),
        "interfaces": _INTERFACES,
    },
    run_modes,
    doc="Normal modes of the undamped structure with a linear interface. Writes "
    "`modes-<interface>.png` (deformed mesh), `natural-frequencies.png` and, for meshes, "
    "`modes-<interface>.pvd` (open in ParaView; the time slider steps through the modes).",
)


# --- FRF ------------------------------------------------------------------------------------
def _frf_chunked(model, freqs, interface: str, method: str, bar,
                 condenser=None) -> linear.FRFResult:
    """:func:`fretwear.linear.frf` in chunks so that the progress bar moves (``condenser``:
    the run's, for ``method = "condensed"``)."""
    parts = []
    for chunk in np.array_split(freqs, min(len(freqs), 50)):
        parts.append(linear.frf(model, chunk, interface=interface, method=method,
                                condenser=condenser))
        bar.update(len(chunk))
    return linear.FRFResult(
        interface, freqs,
        {k: np.concatenate([p.observed[k] for p in parts]) for k in parts[0].observed},
        np.concatenate([p.contact for p in parts]),
        np.concatenate([p.reaction for p in parts]),
        method,
    )


def run_frf(model, analysis: dict, case, context: RunContext) -> RunOutput:
    """Frequency response functions for each requested interface."""
    _need_mass(model)
    points = check_points(model, analysis.get("points"))
    linear.check_frf_size(model, analysis["n_points"], analysis["method"])
    freqs = linear.frequency_grid(analysis["f_min"], analysis["f_max"], analysis["n_points"],
                                  analysis["spacing"])
    interfaces = analysis["interfaces"]
    # the run's condensation of the model, for every chunk and interface (condensed FRFs)
    cond = exact_condenser(model) if analysis["method"] == "condensed" else None
    results = []
    with tqdm(total=len(freqs) * len(interfaces), desc="frf", disable=not context.progress,
              leave=False, unit="freq") as bar:
        for interface in interfaces:
            bar.set_postfix_str(interface)
            results.append(_frf_chunked(model, freqs, interface, analysis["method"], bar,
                                        cond))
    coords, data = geometry(model, points)
    n_axes = coords["axis"].size
    coords["interface"] = label_coordinate("interface", interfaces)
    coords["frequency"] = variable("frequency", freqs, "Hz", "excitation frequency")
    u = np.stack([_pad_points({p: r.observed[p] for p in points}, points, n_axes,
                              (len(freqs),)) for r in results])
    dims_c = ("interface", "frequency", "contact_node", "component")
    data.update(complex_variables("displacement", ("interface", "frequency", "point", "axis"),
                                  u, "m", "displacement of the observed point"))
    data.update(complex_variables("contact_displacement", dims_c,
                                  np.stack([r.contact for r in results]), "m",
                                  "displacement of the contact node, contact-local components"))
    data.update(complex_variables("contact_force", dims_c,
                                  np.stack([r.reaction for r in results]), "N",
                                  "force of the structure on the obstacle (normal positive in "
                                  "compression), contact-local components"))
    ds = xr.Dataset(data, coords=coords)
    figures = []
    for point in points:
        p = figure_path(case, context.out_dir, f"frf-{point}")
        if p is not None:
            figures.append(plots.plot_frf(ds, p, point, title=f"{case.title}: FRF at {point}"))
    return RunOutput(ds, figures, _frf_summary(results, points, model), True)


def _frf_summary(results, points, model) -> str:
    """Peak amplitude and resonances per interface, point and axis; components whose response
    is rounding noise (below 1e-9 of the largest of the interface) are left out."""
    lines = []
    for r in results:
        largest = max((np.abs(r.observed[p]).max() for p in points), default=0.0)
        for name in points:
            d = len(model.observed_point(name).dofs)
            for k in range(d):
                if np.abs(r.observed[name][:, k]).max() <= 1e-9 * largest:
                    continue
                n, f = linear.count_resonances(r, name, k)
                fs = ", ".join(f"{x:.4g}" for x in f[:8]) + (" ..." if n > 8 else "")
                peak = np.abs(r.observed[name][:, k]).max()
                lines.append(f"{r.interface:>8}: {name} {AXES[k]}: max |u| = {peak:.3e} m, "
                             f"{n} resonances [Hz]: {fs or '-'}")
    return "\n".join(lines)


FRF = Analysis.define(
    "frf",
    {
        "f_min": Field(Number(lo=0, lo_open=True), "lowest frequency", required=True, unit="Hz"),
        "f_max": Field(Number(lo=0, lo_open=True), "highest frequency", required=True, unit="Hz"),
        "n_points": Field(Integer(lo=2), "number of frequencies", default=200),
        "spacing": Field(Text(("log", "linear")), "frequency spacing",
                         default=default_of(linear.frequency_grid, "spacing")),
        "interfaces": _INTERFACES,
        "points": Field(ListOf(Text(), non_empty=True, unique=True),
                        "observed points to report (default: all)"),
        "method": Field(Text(linear.FRF_METHODS), '"direct" (sparse solve of the whole model) '
                        'or "condensed" (on the contact DOFs), both exact; "projected" (for '
                        "fine grids: exact solves at a few frequencies span a space the model "
                        "is projected on, to a backward error of 1e-8 at every frequency)",
                        default=default_of(linear.frf, "method")),
    },
    run_frf,
    checks=(increasing("f_min", "f_max", "Hz"),),
    doc="Forced response to the harmonic (n = 1) part of the loads with a linear interface "
    "(the static part is ignored). Writes `frf-<point>.png` (amplitude, log-log, one curve per "
    "interface).",
)
