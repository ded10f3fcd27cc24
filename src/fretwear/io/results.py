"""Results files: one NetCDF file per run (xarray, h5netcdf engine), and ParaView fields.

The schema (variables, dimensions, units per analysis type) is documented in
``docs/results.md``. Rules every analysis follows:

* dimension names come from :data:`DIMENSIONS` (shared by all analyses);
* every variable and coordinate has ``units`` and ``long_name`` attributes
  (:func:`check_schema` refuses a dataset without them);
* NetCDF has no complex type: a complex amplitude ``U`` (``u(t) = Re U e^{i omega t}``) is
  stored as ``<name>_amplitude = |U|`` and ``<name>_phase = arg U`` [rad], so that
  ``u(t) = amplitude cos(omega t + phase)`` (:func:`complex_variables`, :func:`to_complex`);
* files are written atomically (:func:`atomic_write`): a results file is never half-written,
  and an interrupted write keeps the previous file.

Global attributes: ``fretwear_version``, ``title``, ``analysis_type``, ``created_utc`` (ISO
8601), ``case_file`` (the case file text), ``case_path``, ``analysis_options`` (the validated
``[analysis]`` table as JSON) and ``converged`` (1 or 0).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from datetime import UTC, datetime
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
import xarray as xr

from fretwear import __version__
from fretwear.errors import ConvergenceError, InputError
from fretwear.files import atomic_write
from fretwear.validate import path as file_path

ENGINE = "h5netcdf"

#: Shared dimension names: name -> (description, units of its coordinate).
DIMENSIONS = {
    "interface": ("linear interface: free, sliding or stuck", "1"),
    "mode": ("mode number, from 1 by increasing frequency", "1"),
    "frequency": ("excitation frequency", "Hz"),
    "harmonic_coefficient": ('real Fourier coefficient: "0", "c1", .., "s1", .. (eq. 16)', "1"),
    "time": ("time", "s"),
    "tau": ("angle tau = omega t over one period", "rad"),
    "step": ("slow-scale (wear) step", "1"),
    "harmonic": ("kept harmonic number", "1"),
    "modal_amplitude": ("modal amplitude of a nonlinear mode", "m kg^0.5"),
    "point": ("observed point, by name", "1"),
    "axis": ("component in the structure's axes: x, y(, z)", "1"),
    "contact_node": ("contact node, from 0", "1"),
    "component": ("contact-local component: N (normal), T1, T2 (tangential)", "1"),
    "dof": ("degree of freedom of the model, from 0", "1"),
    "contact_state": ("contact state: separation, stick, slip", "1"),
    "wear_state": ("interface before and after wear: unworn, worn", "1"),
    "surface": ("worn surface: the contact node's, its partner's", "1"),
}


# --- building datasets ----------------------------------------------------------------
def variable(dims, values, units: str, long_name: str, **attrs) -> xr.Variable:
    """An ``xarray.Variable`` with the two required attributes."""
    return xr.Variable(dims, np.asarray(values), {"units": units, "long_name": long_name,
                                                  **attrs})


def complex_variables(name: str, dims, values, units: str, long_name: str) -> dict:
    """``{name_amplitude, name_phase}`` variables for a complex amplitude array.

    Parameters
    ----------
    name : stem of the variable names.
    dims : dimension names of ``values``.
    values : complex array; ``u(t) = Re(values e^{i omega t})``.
    units : units of the amplitude.
    long_name : what the quantity is.
    """
    values = np.asarray(values, dtype=complex)
    return {
        f"{name}_amplitude": variable(dims, np.abs(values), units, f"{long_name}, amplitude"),
        f"{name}_phase": variable(
            dims, np.angle(values), "rad",
            f"{long_name}, phase (u(t) = amplitude cos(omega t + phase))",
        ),
    }


def to_complex(ds: xr.Dataset, name: str) -> xr.DataArray:
    """The complex amplitude ``amplitude * exp(i phase)`` of a stored pair."""
    amp, ph = ds[f"{name}_amplitude"], ds[f"{name}_phase"]
    out = amp * np.exp(1j * ph)
    out.attrs = {"units": amp.attrs.get("units", ""),
                 "long_name": amp.attrs.get("long_name", name).replace(", amplitude", "")}
    return out


def label_coordinate(dim: str, labels, long_name: str | None = None) -> xr.Variable:
    """A coordinate of string labels (interface, point, axis, component, ...)."""
    return variable(dim, np.asarray(list(labels), dtype=str), "1",
                    long_name or DIMENSIONS.get(dim, (dim,))[0])


def check_schema(ds: xr.Dataset) -> None:
    """Refuse a dataset with a variable lacking ``units``/``long_name``, or a complex one.

    Raises
    ------
    ValueError
        Naming the offending variable (a programming error in an analysis, not user input).
    """
    for name, var in list(ds.coords.items()) + list(ds.data_vars.items()):
        missing = [a for a in ("units", "long_name") if a not in var.attrs]
        if missing:
            raise ValueError(f"results variable {name!r} has no {' and no '.join(missing)}")
        if np.iscomplexobj(var.values):
            raise ValueError(
                f"results variable {name!r} is complex: store it with complex_variables()"
            )


#: variables that hold a solution (displacements, velocities, contact forces, wear depths):
#: NaN or inf in one of them means the computation failed, so the writer refuses it
#: (:func:`check_finite`); along a dimension that a ``converged`` flag shares (a sweep's
#: ``frequency``), only the converged entries are checked, and the axes a point does not have
#: (NaN over all of them: a point of fewer DOFs than the model's axes) are padding
SOLUTION_VARIABLES = ("displacement", "velocity", "displacement_coefficients",
                      "displacement_harmonic_amplitude", "contact_displacement_coefficients",
                      "contact_force_coefficients", "corrected_displacement_coefficients",
                      "contact_force", "corrected_displacement", "contact_displacement",
                      "wear_depth", "worn_volume")


def _checked_values(ds: xr.Dataset, name: str) -> np.ndarray:
    """The values of ``ds[name]`` that must be finite: the converged entries, without the
    padded axes of points."""
    var = ds[name]
    values = np.asarray(var.values, dtype=float)
    dims = list(var.dims)
    flag = ds.data_vars.get("converged")
    if flag is not None and flag.ndim == 1 and flag.dims[0] in dims:
        values = np.compress(np.asarray(flag.values).astype(bool), values,
                             axis=dims.index(flag.dims[0]))
    if "axis" in dims and values.size:
        keep = [dims.index(d) for d in ("point", "axis") if d in dims]
        other = tuple(i for i in range(values.ndim) if i not in keep)
        padded = np.all(np.isnan(values), axis=other, keepdims=True) if other else \
            np.isnan(values)
        if not np.all(padded):  # a point with no finite axis at all is not padding
            values = values[~np.broadcast_to(padded, values.shape)]
    return values


def check_finite(ds: xr.Dataset) -> None:
    """Refuse a dataset whose solution variables (:data:`SOLUTION_VARIABLES`) hold NaN or
    inf: a :class:`~fretwear.errors.ConvergenceError` naming the variable, so that a failed
    computation is never written as a result."""
    for name in SOLUTION_VARIABLES:
        if name not in ds.data_vars or np.asarray(ds[name].values).dtype.kind not in "fc":
            continue
        if not np.all(np.isfinite(_checked_values(ds, name))):
            what = ds[name].attrs.get("long_name", "")
            raise ConvergenceError(f"results variable {name!r} ({what}) holds non-finite "
                                   "values (NaN or inf): the computation failed; no results "
                                   "file was written")


# --- writing ----------------------------------------------------------------------------
def run_attributes(*, title: str, analysis_type: str, converged: bool, case_text: str = "",
                   case_path: str = "", analysis: Mapping | None = None) -> dict:
    """The global attributes of a results file (see module docstring)."""
    return {
        "fretwear_version": __version__,
        "title": title,
        "analysis_type": analysis_type,
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
        "case_file": case_text,
        "case_path": case_path,
        "analysis_options": json.dumps(dict(analysis or {}), default=str),
        "converged": int(bool(converged)),
    }


def write_results(path: Path | str, ds: xr.Dataset, **attrs) -> Path:
    """Check the schema and write ``ds`` atomically to the NetCDF file ``path``.

    Parameters
    ----------
    path : the ``.nc`` file.
    ds : the dataset (every variable with ``units`` and ``long_name``; no complex values).
    **attrs : keyword arguments of :func:`run_attributes` (``title``, ``analysis_type``,
        ``converged``, ``case_text``, ``case_path``, ``analysis``).

    Returns
    -------
    The absolute path written.
    """
    check_schema(ds)
    check_finite(ds)
    ds = ds.copy()
    ds.attrs = {**ds.attrs, **run_attributes(**attrs)}
    return atomic_write(path, lambda tmp: ds.to_netcdf(tmp, engine=ENGINE))


def read_results(path: Path | str) -> xr.Dataset:
    """Load a results file fully into memory (the file is closed on return).

    Returns
    -------
    :class:`xarray.Dataset`: every variable with ``units`` (SI, frequencies in Hz) and
    ``long_name`` attributes; the run's global attributes (``converged``, the case text,
    solver settings); schema in ``docs/results.md``.

    Raises
    ------
    InputError
        The file does not exist or is not a NetCDF file.
    """
    path = file_path(path, "path")
    path = Path(path)
    if not path.is_file():
        raise InputError(f"results file {str(path)!r} does not exist")
    try:
        with xr.open_dataset(path, engine=ENGINE) as ds:
            return ds.load()
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read results file {str(path)!r}: {exc}") from None


# --- ParaView ----------------------------------------------------------------------------
def nodal_vectors(mesh, vector: np.ndarray) -> np.ndarray:
    """A DOF vector ``(ndof,)`` of a mesh model as nodal vectors ``(nn, dim)``.

    Mesh models number DOFs node-major (``dim*i + c``, :mod:`fretwear.model.core`); the
    points of a model from FE matrices (``model.fe_mesh``) name each translation's DOF in
    ``mesh.rows`` (NaN where the matrices have none).
    """
    vector = np.asarray(vector)
    if getattr(mesh, "rows", None) is None:
        return vector.reshape(mesh.points.shape[0], mesh.dim)
    out = np.full(mesh.rows.shape, np.nan, dtype=vector.dtype if vector.dtype.kind == "c"
                  else float)
    have = mesh.rows >= 0
    out[have] = vector[mesh.rows[have]]
    return out


def output_mesh(model):
    """The mesh of a model's ParaView files: its mesh, or the node file's points of a model
    from FE matrices (``model.fe_mesh``); None when there is neither (:func:`no_fields_line`
    says why)."""
    return model.mesh if model.mesh is not None else getattr(model, "fe_mesh", None)


def no_fields_line(model) -> str:
    """The one line saying that no ParaView file is written for a model without a mesh and
    why ('' when it has one)."""
    if output_mesh(model) is not None:
        return ""
    if model.meta.get("source") == "fe":
        why = "its matrices came without a node file (give the mesh file: model.nodes)"
    else:
        why = "the model is matrices without node coordinates"
    return f"no ParaView (.vtu) files: {why}"


def write_vtu(path: Path | str, mesh, point_data: Mapping, field_data: Mapping | None = None
              ) -> Path:
    """Write a mesh and nodal fields to a ParaView ``.vtu`` file (meshio), atomically.

    Parameters
    ----------
    path : the ``.vtu`` file.
    mesh : a :class:`fretwear.model.core.Mesh`.
    point_data : name -> ``(nn,)`` scalars or ``(nn, d)`` vectors (real; 2D vectors are
        padded with a zero z component so that ParaView's Warp By Vector works).
    field_data : name -> scalar or small array stored with the mesh (e.g. a frequency).

    Returns
    -------
    The absolute path written.
    """
    import meshio

    nn = mesh.points.shape[0]
    points = np.zeros((nn, 3))
    points[:, : mesh.dim] = mesh.points
    data = {}
    for name, values in point_data.items():
        v = np.asarray(values, dtype=float)
        if v.shape[0] != nn:
            raise ValueError(f"point data {name!r} has {v.shape[0]} rows, the mesh {nn} nodes")
        if v.ndim == 2 and v.shape[1] < 3:
            v = np.hstack([v, np.zeros((nn, 3 - v.shape[1]))])
        data[name] = v
    fields = {k: np.atleast_1d(np.asarray(v, dtype=float)) for k, v in (field_data or {}).items()}
    m = meshio.Mesh(points, [(mesh.cell_type, np.asarray(mesh.cells))], point_data=data,
                    field_data=fields)
    return atomic_write(path, lambda tmp: meshio.write(tmp, m, file_format="vtu"))


def write_pvd(path: Path | str, entries) -> Path:
    """Write a ParaView collection (``.pvd``) that steps through ``.vtu`` files.

    Parameters
    ----------
    path : the ``.pvd`` file.
    entries : ``(timestep, file)`` pairs; files are written relative to the ``.pvd`` folder.
        ParaView's time slider then walks through them (e.g. one mode per step).
    """
    path = Path(path).resolve()
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "  <Collection>"]
    for step, file in entries:
        rel = os.path.relpath(Path(file).resolve(), path.parent).replace(os.sep, "/")
        lines.append(f'    <DataSet timestep="{float(step):g}" part="0" file={quoteattr(rel)}/>')
    lines += ["  </Collection>", "</VTKFile>", ""]
    text = "\n".join(lines)
    return atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
