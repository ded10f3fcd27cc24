"""A long frequency sweep split across workers: chunks of the band, joined and checked.

A ``[split]`` study cuts the base sweep's frequency grid into ``chunks`` consecutive pieces
that share their end frequencies (:func:`fretwear.study.members.expand`); each chunk is an
ordinary sweep member (continuation inside the chunk, its first point started as any sweep
starts). Where two chunks meet, the same frequency was solved twice: once at the end of a
continuation, once from the start of the next chunk. :func:`join_chunks` compares the two
response amplitudes there (the largest difference over points, axes and harmonics, relative
to the largest amplitude): within ``join_rtol`` the two solves found the same periodic
solution and the chunks are joined into one sweep; beyond it the join is flagged (the two
sides followed different branches, e.g. on an overhanging resonance), never hidden.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from fretwear.study.runner import RESULTS_FILE


def join_difference(left: xr.Dataset, right: xr.Dataset) -> tuple[float, float]:
    """The shared frequency of two neighbouring chunks and the relative difference of their
    response amplitudes there (NaN when they do not share their end frequency)."""
    f_left, f_right = float(left["frequency"].values[-1]), float(right["frequency"].values[0])
    if not np.isclose(f_left, f_right, rtol=1e-12, atol=0.0):
        return f_left, float("nan")
    a = left["response_amplitude"].isel(frequency=-1).values
    b = right["response_amplitude"].isel(frequency=0).values
    scale = max(float(np.nanmax(np.abs(a))), float(np.nanmax(np.abs(b))), np.finfo(float).tiny)
    return f_left, float(np.nanmax(np.abs(a - b)) / scale)


def join_chunks(study, members, records, outdir) -> xr.Dataset:
    """The chunks of a split sweep joined into one sweep dataset (each join's frequency,
    difference and verdict as variables along ``join``); the chunks that did not succeed
    leave their part of the band out and ``complete = 0``."""
    from fretwear.io.results import read_results

    rtol = study.split["join_rtol"]
    chunks = []
    for m, r in zip(members, records, strict=True):
        ds = read_results(outdir / m.folder_name / RESULTS_FILE).load() if r.status == "ok" \
            else None
        chunks.append(ds)
    freqs, diffs, ok = [], [], []
    for left, right in zip(chunks[:-1], chunks[1:], strict=True):
        if left is None or right is None:
            freqs.append(np.nan)
            diffs.append(np.nan)
            ok.append(0)
            continue
        f, d = join_difference(left, right)
        freqs.append(f)
        diffs.append(d)
        ok.append(int(np.isfinite(d) and d <= rtol))
    pieces = [ds if i == 0 or chunks[i - 1] is None else ds.isel(frequency=slice(1, None))
              for i, ds in enumerate(chunks) if ds is not None]
    if pieces:
        by_freq = [n for n, v in pieces[0].data_vars.items() if "frequency" in v.dims]
        joined = xr.concat([p[by_freq] for p in pieces], dim="frequency",
                           data_vars="all", coords="minimal", compat="override",
                           join="outer")
        rest = pieces[0].drop_vars(by_freq).drop_dims("frequency", errors="ignore")
        parts = [joined]
        by_lin = [n for n, v in rest.data_vars.items() if "linear_frequency" in v.dims]
        if by_lin:  # each chunk's linear references on its own grid: their union
            lin = xr.concat([p[by_lin] for p in pieces], dim="linear_frequency",
                            data_vars="all", coords="minimal", compat="override",
                            join="outer")
            parts.append(lin.drop_duplicates("linear_frequency").sortby("linear_frequency"))
            rest = rest.drop_vars(by_lin).drop_dims("linear_frequency", errors="ignore")
        joined = xr.merge([*parts, rest], compat="override", join="outer")
    else:
        joined = xr.Dataset()
    joined["join_frequency"] = ("join", np.array(freqs, float),
                                {"units": "Hz", "long_name": "frequency shared by two chunks"})
    joined["join_difference"] = ("join", np.array(diffs, float),
                                 {"units": "1", "long_name": "largest difference of the response "
                                  "amplitudes of the two chunks there, relative to the largest "
                                  "amplitude"})
    joined["join_ok"] = ("join", np.array(ok, np.int8),
                         {"units": "1", "long_name": f"1: difference <= join_rtol = {rtol:g}"})
    joined["chunk_status"] = ("chunk", np.array([r.status for r in records]),
                              {"long_name": "status of each chunk's sweep"})
    joined.attrs.update({
        "title": study.title, "study_kind": "split", "study_file": study.text,
        "base_case": str(study.base), "chunks": len(members),
        "complete": int(all(r.status == "ok" for r in records)),
        "joins_ok": int(all(ok)),
    })
    return joined
