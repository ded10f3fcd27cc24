"""One results file for a study: the members' results stacked along a ``member`` dimension.

``study.nc`` holds, for every member, its status and message and the values of the varied
keys (coordinates along ``member``), and every variable of the members' ``results.nc`` whose
shape is the same for all of them (NaN for members that failed or did not converge: a failed
solve is never a result). Two kinds get more:

* wear members (their results have ``cycles``): the worn volume, the maximum wear depth and
  the worn profile interpolated (linearly in cycles) on a common grid of ``cycle`` from 0 to
  the longest run, NaN past a member's last step; their mean and 5/50/95 % quantiles over the
  members that reached each cycle (``members_reached``), and each member's final state;
* sweep members: the envelope (min, max) of the response amplitude over the members (the band
  of FRFs); for a split sweep (:mod:`fretwear.study.sweep_split`) the chunks joined into one
  sweep instead;
* mistuned disks (``[cyclic.mistuning]``): each member's blade responses and amplification
  factor against Whitehead's bound (:mod:`fretwear.study.mistuning`).
"""

from __future__ import annotations

import contextlib
import warnings

import numpy as np
import xarray as xr

from fretwear.io.results import read_results
from fretwear.study.members import Member
from fretwear.study.mistuning import amplification
from fretwear.study.runner import RESULTS_FILE, MemberRecord

QUANTILES = (0.05, 0.5, 0.95)
N_CYCLES = 201


def _open(outdir, members: list[Member], records: list[MemberRecord]) -> dict:
    """Member index -> its dataset, for the members whose run succeeded."""
    out = {}
    for m, r in zip(members, records, strict=True):
        if r.status == "ok":
            out[m.index] = read_results(outdir / m.folder_name / RESULTS_FILE).load()
    return out


def _member_coords(members: list[Member]) -> dict:
    """The varied keys along ``member``: scalar values as coordinates, lists as variables."""
    keys = list(dict.fromkeys(k for m in members for k in m.values))
    coords = {"member": ("member", np.array([m.index for m in members]),
                         {"long_name": "study member, from 0"})}
    for key in keys:
        vals = [m.values.get(key) for m in members]
        if any(isinstance(v, list) for v in vals):
            n = max(len(v) if isinstance(v, list) else 1 for v in vals)
            arr = np.full((len(vals), n), np.nan)
            for i, v in enumerate(vals):
                if v is not None:
                    arr[i, : len(v) if isinstance(v, list) else 1] = v
            coords[key] = (("member", f"{key}_item"), arr,
                           {"long_name": f"case key {key} of the member (per item)"})
        elif all(isinstance(v, int | float) and not isinstance(v, bool) for v in vals):
            coords[key] = ("member", np.array(vals, dtype=float),
                           {"long_name": f"case key {key} of the member"})
        else:
            coords[key] = ("member", np.array([str(v) for v in vals]),
                           {"long_name": f"case key {key} of the member"})
    return coords


def _stack(members: list[Member], done: dict, skip_dims=("step",)) -> dict:
    """The variables with the same dims and shape in every successful member, stacked."""
    if not done:
        return {}
    first = next(iter(done.values()))
    out = {}
    for name, var in first.data_vars.items():
        if any(d in skip_dims for d in var.dims) or var.dtype.kind not in "fiub":
            continue
        if not all(name in ds and ds[name].shape == var.shape and ds[name].dims == var.dims
                   for ds in done.values()):
            continue
        arr = np.full((len(members), *var.shape), np.nan)
        for i, m in enumerate(members):
            if m.index in done:
                arr[i] = done[m.index][name].values
        out[name] = (("member", *var.dims), arr, dict(var.attrs))
    return out


def _shared_coords(done: dict, variables: dict) -> dict:
    """Coordinates of the stacked variables' dims, when every member has the same."""
    if not done:
        return {}
    first = next(iter(done.values()))
    dims = {d for v in variables.values() for d in v[0]} - {"member"}
    out = {}
    for d in dims:
        if d in first.coords and all(
                d in ds.coords and np.array_equal(ds[d].values, first[d].values)
                for ds in done.values()):
            out[d] = (d, first[d].values, dict(first[d].attrs))
    return out


def _interp(x: np.ndarray, xp: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """``fp`` (steps, ...) at ``x``, linear in ``xp``; NaN outside [xp[0], xp[-1]]."""
    flat = fp.reshape(fp.shape[0], -1)
    out = np.full((x.size, flat.shape[1]), np.nan)
    inside = (x >= xp[0]) & (x <= xp[-1])
    for j in range(flat.shape[1]):
        out[inside, j] = np.interp(x[inside], xp, flat[:, j])
    return out.reshape((x.size, *fp.shape[1:]))


def _stats(name: str, arr: np.ndarray, dims: tuple, unit: str, what: str) -> dict:
    """Mean and quantiles over ``member`` (axis 0), NaN-aware."""
    with np.errstate(all="ignore"), _quiet():
        mean = np.nanmean(arr, axis=0)
        q = np.nanquantile(arr, QUANTILES, axis=0)
    return {
        f"{name}_mean": (dims, mean, {"units": unit, "long_name": f"mean of {what} over the "
                                      "members that reached the cycle"}),
        f"{name}_quantile": (("quantile", *dims), q,
                             {"units": unit, "long_name": f"5/50/95 % quantiles of {what} "
                              "over the members that reached the cycle"}),
    }


@contextlib.contextmanager
def _quiet():
    """No RuntimeWarning for all-NaN slices (cycles no member reached)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


def _wear(members: list[Member], done: dict) -> tuple[dict, dict]:
    """The wear statistics on a common cycle grid and each member's final state."""
    ends = [float(ds["cycles"].values[-1]) for ds in done.values()]
    grid = np.linspace(0.0, max(ends), N_CYCLES)
    first = next(iter(done.values()))
    nc = first.sizes["contact_node"]
    vol = np.full((len(members), grid.size), np.nan)
    depth = np.full_like(vol, np.nan)
    prof = np.full((len(members), grid.size, nc), np.nan)
    final = {k: np.full(len(members), np.nan) for k in ("cycles", "volume", "depth")}
    final_prof = np.full((len(members), nc), np.nan)
    for i, m in enumerate(members):
        ds = done.get(m.index)
        if ds is None or ds.sizes["contact_node"] != nc:
            continue
        cyc = ds["cycles"].values
        w = ds["wear_depth"].values
        vol[i] = _interp(grid, cyc, ds["worn_volume"].values)
        depth[i] = _interp(grid, cyc, w.max(axis=1))
        prof[i] = _interp(grid, cyc, w)
        final["cycles"][i], final["volume"][i] = cyc[-1], ds["worn_volume"].values[-1]
        final["depth"][i], final_prof[i] = w[-1].max(), w[-1]
    coords = {
        "cycle": ("cycle", grid, {"units": "1", "long_name": "common grid of cycle counts"}),
        "quantile": ("quantile", np.array(QUANTILES), {"long_name": "quantile level"}),
    }
    data = {
        "worn_volume_on_cycles": (("member", "cycle"), vol,
                                  {"units": "m^3", "long_name": "worn volume of the member "
                                   "(NaN past its last step)"}),
        "max_wear_depth_on_cycles": (("member", "cycle"), depth,
                                     {"units": "m", "long_name": "maximum wear depth of the "
                                      "member"}),
        "wear_depth_on_cycles": (("member", "cycle", "contact_node"), prof,
                                 {"units": "m", "long_name": "worn profile of the member"}),
        "members_reached": ("cycle", np.isfinite(vol).sum(axis=0),
                            {"units": "1", "long_name": "members whose run reached the cycle"}),
        "final_cycles": ("member", final["cycles"], {"units": "1",
                                                     "long_name": "last cycle count"}),
        "final_worn_volume": ("member", final["volume"], {"units": "m^3",
                                                          "long_name": "final worn volume"}),
        "final_max_wear_depth": ("member", final["depth"],
                                 {"units": "m", "long_name": "final maximum wear depth"}),
        "final_wear_depth": (("member", "contact_node"), final_prof,
                             {"units": "m", "long_name": "final worn profile"}),
        "member_stop_reason": ("member", np.array(
            [str(done[m.index].attrs.get("stop_reason", "")) if m.index in done else ""
             for m in members]), {"long_name": "why the wear run stopped"}),
    }
    data.update(_stats("worn_volume", vol, ("cycle",), "m^3", "the worn volume"))
    data.update(_stats("max_wear_depth", depth, ("cycle",), "m", "the maximum wear depth"))
    data.update(_stats("wear_depth", prof, ("cycle", "contact_node"), "m", "the worn profile"))
    return coords, data


def _frf_band(stacked: dict) -> dict:
    if "response_amplitude" not in stacked:
        return {}
    dims, arr, attrs = stacked["response_amplitude"]
    with np.errstate(all="ignore"), _quiet():
        lo, hi = np.nanmin(arr, axis=0), np.nanmax(arr, axis=0)
    return {"response_amplitude_min": (dims[1:], lo, {**attrs, "long_name": "smallest "
                                                      "response amplitude over the members"}),
            "response_amplitude_max": (dims[1:], hi, {**attrs, "long_name": "largest "
                                                      "response amplitude over the members"})}


def aggregate(study, members: list[Member], records: list[MemberRecord], outdir) -> xr.Dataset:
    """The study's dataset (see the module docstring)."""
    done = _open(outdir, members, records)
    coords = _member_coords(members)
    data = {
        "member_status": ("member", np.array([r.status for r in records]),
                          {"long_name": "ok, not converged, failed or not run"}),
        "member_message": ("member", np.array([r.message for r in records]),
                           {"long_name": "summary of the run or why it failed"}),
        "member_seconds": ("member", np.array([r.seconds for r in records], float),
                           {"units": "s", "long_name": "wall time of the member's run"}),
    }
    is_wear = bool(done) and all("cycles" in ds and "step" in ds.dims for ds in done.values())
    stacked = _stack(members, done)
    stacked = {k: v for k, v in stacked.items() if "wall_time" not in k}
    data.update(stacked)
    coords.update(_shared_coords(done, stacked))
    if is_wear:
        c, d = _wear(members, done)
        coords.update(c)
        data.update(d)
    else:
        data.update(_frf_band(stacked))
    amp_data, amp_attrs = amplification(members, done)
    data.update(amp_data)
    ds = xr.Dataset(data, coords=coords)
    ds.attrs.update(amp_attrs)
    ds.attrs.update({
        "title": study.title, "study_kind": study.kind, "study_file": study.text,
        "base_case": str(study.base), "members": len(members),
        "members_ok": sum(r.status == "ok" for r in records),
        "members_not_converged": sum(r.status == "not converged" for r in records),
        "members_failed": sum(r.status == "failed" for r in records),
        "members_not_run": sum(r.status == "not run" for r in records),
    })
    return ds
