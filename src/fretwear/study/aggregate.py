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
  of FRFs) and each member's peak (``peak_response_amplitude``, ``peak_frequency``: of the
  family of FRFs over the excitation level, ``analysis.excitation_scale``, the curves a
  joint engineer reads first); for a split sweep (:mod:`fretwear.study.sweep_split`) the
  chunks joined into one sweep instead;
* nonlinear-modes members: each member's own modal amplitudes (``member_modal_amplitude``),
  the abscissa of its stacked ``backbone_frequency`` and ``damping_ratio``;
* worn-state members: each member's final worn profile, worn volume and maximum depth (the
  names of the wear members' final state), why it stopped and the kind of worn state it
  reached (``member_worn_state_kind``);
* transient (and periodic) members: the peak and RMS of each observed displacement less its
  mean over the (last) period (``displacement_peak``, ``displacement_rms``);
* mistuned disks (``[cyclic.mistuning]``): each member's blade responses and amplification
  factor against Whitehead's bound (:mod:`fretwear.study.mistuning`).

Members whose frequencies differ (continuation adds points where each member needs them) or
whose kept harmonics differ cannot be stacked as they are. Their variables along a frequency
dimension (``frequency``, ``linear_frequency``) are then interpolated, linearly in frequency,
onto the union of the members' frequencies (so each member's own points keep their values
exactly; NaN outside a member's band and next to its points that did not converge), and the
harmonics are the union of the members' (NaN for a harmonic a member did not keep). The
attribute ``common_grid`` says so, and each member's own response is kept as well with its own
coordinate: ``member_frequency`` and ``member_response_amplitude`` along ``member_point``
(NaN-padded to the longest member).
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


FREQUENCY_DIMS = ("frequency", "linear_frequency")
LABEL_DIMS = ("harmonic",)
COMMON_GRID = ("the members' {dims} differ: their responses are interpolated linearly in "
               "frequency onto the union of the members' frequencies ({n} points; each "
               "member's own points exact, NaN outside its band), harmonics not kept by a "
               "member are NaN; member_response_amplitude keeps each member's own points")


def _differing(done: dict, dims) -> list[str]:
    """The dims among ``dims`` whose coordinate is not the same in every member."""
    first = next(iter(done.values()))
    out = []
    for d in dims:
        have = [ds for ds in done.values() if d in ds.coords]
        if have and any(d not in ds.coords or not np.array_equal(ds[d].values, first[d].values)
                        for ds in done.values()):
            out.append(d)
    return out


def _on_grid(var: xr.DataArray, dim: str, grid: np.ndarray) -> xr.DataArray:
    """``var`` at the frequencies ``grid`` (which holds every frequency of ``var``), linear in
    ``var[dim]`` (sorted, the first of equal frequencies kept: a fold is seen as one branch
    here, ``member_response_amplitude`` keeps it whole); NaN outside the member's band or
    between a point and a NaN neighbour. Integer variables (flags) keep their values at the
    member's own frequencies only."""
    f = var[dim].values.astype(float)
    order = np.unique(f, return_index=True)[1]
    xp, fp = f[order], np.moveaxis(var.values[order], var.dims.index(dim), 0)
    new = np.full((grid.size, *fp.shape[1:]), np.nan)
    if var.dtype.kind == "f" and xp.size > 1:
        new = _interp(grid, xp, fp.astype(float))
    new[np.searchsorted(grid, xp)] = fp  # exact at its own points, even beside a NaN
    coords = {d: var[d] for d in var.dims if d != dim and d in var.coords}
    return xr.DataArray(np.moveaxis(new, 0, var.dims.index(dim)), dims=var.dims,
                        coords={**coords, dim: grid}, attrs=var.attrs)


def _regrid(done: dict) -> tuple[dict, dict, str]:
    """The members' datasets on common frequency grids and harmonics (see the module
    docstring), each member's own response, and the note (empty: nothing to do)."""
    freq = _differing(done, FREQUENCY_DIMS)
    labels = _differing(done, LABEL_DIMS)
    if not freq and not labels:
        return done, {}, ""
    grids = {d: np.unique(np.concatenate([ds[d].values.astype(float) for ds in done.values()
                                          if d in ds.coords])) for d in freq}
    union = {d: np.unique(np.concatenate([ds[d].values for ds in done.values()
                                          if d in ds.coords])) for d in labels}
    out = {}
    for key, ds in done.items():
        new = {}
        for name, var in ds.data_vars.items():
            if var.dtype.kind not in "fiub":
                continue
            for d in labels:
                if d in var.dims:
                    var = var.astype(float).reindex({d: union[d]})
            for d in freq:
                if d in var.dims:
                    var = _on_grid(var, d, grids[d])
            new[name] = var
        coords = {k: v for k, v in ds.coords.items() if not set(v.dims) & {*freq, *labels}}
        regridded = xr.Dataset(new).assign_coords(coords)
        for d in (*freq, *labels):
            if d in ds.coords and d in regridded.dims:
                regridded[d].attrs.update(ds[d].attrs)
        out[key] = regridded
    own = _own_responses(done) if "frequency" in freq else {}
    n = grids["frequency"].size if "frequency" in grids else 0
    what = " and ".join(["frequencies"] * bool(freq) + ["harmonics"] * bool(labels))
    return out, own, COMMON_GRID.format(dims=what, n=n)


def _own_responses(done: dict) -> dict:
    """Each member's frequencies and response amplitude on its own points (NaN-padded)."""
    have = {k: ds for k, ds in done.items() if "response_amplitude" in ds}
    if not have:
        return {}
    n = max(ds.sizes["frequency"] for ds in have.values())
    first = next(iter(have.values()))["response_amplitude"]
    rest = [d for d in first.dims if d != "frequency"]
    if any(ds["response_amplitude"].dims != first.dims for ds in have.values()):
        return {}
    union = {d: np.unique(np.concatenate([ds[d].values for ds in have.values()]))
             if d in LABEL_DIMS else first[d].values for d in rest if d in first.coords}
    shape = [union[d].size if d in union else first.sizes[d] for d in rest]
    keys = sorted(done)
    freq = np.full((len(keys), n), np.nan)
    amp = np.full((len(keys), n, *shape), np.nan)
    for i, k in enumerate(keys):
        if k not in have:
            continue
        var = have[k]["response_amplitude"]
        for d in LABEL_DIMS:
            if d in var.dims:
                var = var.astype(float).reindex({d: union[d]})
        m = var.sizes["frequency"]
        freq[i, :m] = have[k]["frequency"].values
        amp[i, :m] = var.transpose("frequency", *rest).values
    return {"keys": keys, "frequency": freq, "amplitude": amp, "dims": rest,
            "attrs": dict(first.attrs)}


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


def _peaks(stacked: dict, coords: dict) -> dict:
    """Each member's largest amplitude of harmonic 1 of the first observed point (the
    largest over its axes) over the band, and its frequency (``peak_response_amplitude``,
    ``peak_frequency``): the curve of the peak against a varied key (e.g. the excitation
    level)."""
    if "response_amplitude" not in stacked or "frequency" not in coords:
        return {}
    dims, arr, attrs = stacked["response_amplitude"]
    if dims[:2] != ("member", "frequency"):
        return {}
    sel = arr
    with np.errstate(all="ignore"), _quiet():
        for d in dims[2:]:  # point, axis, harmonic: the first point, the largest axis, the
            sel = np.nanmax(sel, axis=2) if d == "axis" else sel[:, :, 0]  # first harmonic
        ok = np.any(np.isfinite(sel), axis=1)
        j = np.argmax(np.where(np.isfinite(sel), sel, -np.inf), axis=1)
    rows = np.arange(sel.shape[0])
    f = np.asarray(coords["frequency"][1], float)
    return {
        "peak_response_amplitude": ("member", np.where(ok, sel[rows, j], np.nan),
                                    {"units": attrs.get("units", "m"), "long_name":
                                     "largest amplitude of harmonic 1 of the first observed "
                                     "point (largest over its axes) over the band"}),
        "peak_frequency": ("member", np.where(ok, f[j], np.nan),
                           {"units": "Hz", "long_name": "frequency of the member's "
                            "peak_response_amplitude"}),
    }


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


def _own_variables(members: list[Member], own: dict) -> dict:
    """``member_frequency`` and ``member_response_amplitude`` (see the module docstring)."""
    if not own:
        return {}
    row = {k: i for i, k in enumerate(own["keys"])}
    n = own["frequency"].shape[1]
    freq = np.full((len(members), n), np.nan)
    amp = np.full((len(members), *own["amplitude"].shape[1:]), np.nan)
    for i, m in enumerate(members):
        if m.index in row:
            freq[i], amp[i] = own["frequency"][row[m.index]], own["amplitude"][row[m.index]]
    return {
        "member_frequency": (("member", "member_point"), freq,
                             {"units": "Hz", "long_name": "the member's own frequencies "
                              "(NaN past its last point)"}),
        "member_response_amplitude": (("member", "member_point", *own["dims"]), amp,
                                      {**own["attrs"], "long_name": "the member's response "
                                       "amplitude at its own frequencies"}),
    }


def _backbone_amplitudes(members: list[Member], done: dict, stacked: dict) -> dict:
    """Nonlinear-modes members: each member's own modal amplitudes
    (``member_modal_amplitude``), the abscissa of its backbone and damping curve (the
    stacked ``backbone_frequency`` and ``damping_ratio``), whether or not the members' grids
    of amplitude agree."""
    if "backbone_frequency" not in stacked:
        return {}
    n = stacked["backbone_frequency"][1].shape[1]
    amp = np.full((len(members), n), np.nan)
    attrs = {}
    for i, m in enumerate(members):
        if m.index in done and "modal_amplitude" in done[m.index].coords:
            amp[i] = done[m.index]["modal_amplitude"].values
            attrs = dict(done[m.index]["modal_amplitude"].attrs)
    return {"member_modal_amplitude": (("member", "modal_amplitude"), amp, {
        "units": attrs.get("units", "m kg^0.5"),
        "long_name": "the member's modal amplitudes (abscissa of its backbone_frequency "
                     "and damping_ratio)"})}


def _worn_states(members: list[Member], done: dict) -> dict:
    """Worn-state members (their results have ``worn_state_kind``): each member's worn
    profile, worn volume and maximum depth at its last pseudo-time step (the worn state when
    it was reached), what kind of state it reached and why it stopped."""
    have = {k: ds for k, ds in done.items() if "worn_state_kind" in ds.attrs}
    if not have:
        return {}
    nc = max(ds.sizes["contact_node"] for ds in have.values())
    vol, depth = np.full(len(members), np.nan), np.full(len(members), np.nan)
    prof = np.full((len(members), nc), np.nan)
    for i, m in enumerate(members):
        ds = have.get(m.index)
        if ds is not None:
            w = ds["wear_depth"].values[-1]
            prof[i, : w.size], depth[i] = w, w.max()
            vol[i] = ds["worn_volume"].values[-1]

    def attr(name):
        return np.array([str(have[m.index].attrs.get(name, "")) if m.index in have else ""
                         for m in members])

    return {
        "final_worn_volume": ("member", vol, {"units": "m^3", "long_name": "final worn volume"}),
        "final_max_wear_depth": ("member", depth,
                                 {"units": "m", "long_name": "final maximum wear depth"}),
        "final_wear_depth": (("member", "contact_node"), prof,
                             {"units": "m", "long_name": "final worn profile"}),
        "member_stop_reason": ("member", attr("stop_reason"),
                               {"long_name": "why the wear run stopped"}),
        "member_worn_state_kind": ("member", attr("worn_state_kind"),
                                   {"long_name": "the worn state the member reached "
                                    "(null_wear_rate, steady_wear, no_wear or "
                                    "not_reached)"}),
    }


def _transient_peaks(stacked: dict) -> dict:
    """Transient (and periodic) members: the peak and the RMS over the (last) period of each
    observed displacement less its mean over the period (``displacement_peak``,
    ``displacement_rms``), which a response that is not periodic (subharmonic,
    quasi-periodic, irregular) has as well as a harmonic amplitude."""
    if "displacement" not in stacked or stacked["displacement"][0][-1] != "tau":
        return {}
    dims, arr, attrs = stacked["displacement"]
    with np.errstate(all="ignore"), _quiet():
        dyn = arr - np.nanmean(arr, axis=-1, keepdims=True)  # the static offset apart
        peak = np.nanmax(np.abs(dyn), axis=-1)
        rms = np.sqrt(np.nanmean(dyn**2, axis=-1))
    unit = attrs.get("units", "m")
    over = "over the period (transient: the last period), its mean over it subtracted"
    return {"displacement_peak": (dims[:-1], peak, {"units": unit, "long_name": "largest "
                                  f"|displacement| of the observed point {over}"}),
            "displacement_rms": (dims[:-1], rms, {"units": unit, "long_name": "RMS of the "
                                 f"displacement of the observed point {over}"})}


def aggregate(study, members: list[Member], records: list[MemberRecord], outdir) -> xr.Dataset:
    """The study's dataset (see the module docstring)."""
    done = _open(outdir, members, records)
    done, own, note = _regrid(done) if done else (done, {}, "")
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
        data.update(_own_variables(members, own))
        data.update(_peaks(stacked, coords))
        data.update(_backbone_amplitudes(members, done, stacked))
        data.update(_worn_states(members, done))
        data.update(_transient_peaks(stacked))
    amp_data, amp_attrs = amplification(members, done)
    data.update(amp_data)
    ds = xr.Dataset(data, coords=coords)
    if note:
        ds.attrs["common_grid"] = note
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
