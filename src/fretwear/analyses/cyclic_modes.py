"""The ``cyclic-modes`` analysis: the linear modes of a disk, contact free, family by family
(nodal diameter), from one sector (:func:`fretwear.hb.cyclic.cyclic_modes`); the
nodal-diameter (SAFE) diagram."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from fretwear.analyses.base import Analysis, RunContext, RunOutput
from fretwear.analyses.common import figure_path
from fretwear.analyses.figure_style import series_style
from fretwear.analyses.figures import new_figure, save
from fretwear.errors import InputError
from fretwear.hb.cyclic import cyclic_modes
from fretwear.io.results import variable
from fretwear.io.schema import Field, Integer


def run_cyclic_modes(model, analysis: dict, case, context: RunContext) -> RunOutput:
    """The ``n_modes`` lowest modes of every nodal diameter ``k = 0 .. N // 2`` (index ``k``
    and ``N - k`` share their frequencies)."""
    sector = model.meta.get("cyclic")
    if model.meta.get("mistuning") is not None:
        raise InputError('analysis.type = "cyclic-modes": the modes of the tuned sector, every '
                         "nodal diameter; [cyclic.mistuning] makes the whole mistuned disk, "
                         "which has none: remove [cyclic.mistuning]")
    if sector is None:
        raise InputError('analysis.type = "cyclic-modes": the case has no [cyclic] table; '
                         'expected a sector (or use type = "modes")')
    n = sector.n_sectors
    ks = np.arange(n // 2 + 1)
    freq = np.full((ks.size, analysis["n_modes"]), np.nan)
    for i, k in enumerate(ks):
        f, _ = cyclic_modes(sector, int(k), analysis["n_modes"])
        freq[i, :f.size] = f
    coords = {"nodal_diameter": variable("nodal_diameter", ks, "1",
                                         "nodal diameter (harmonic index k; k and N - k share "
                                         "their frequencies)"),
              "mode": variable("mode", np.arange(1, freq.shape[1] + 1), "1",
                               "mode number within the family")}
    ds = xr.Dataset({"cyclic_frequency": variable(("nodal_diameter", "mode"), freq, "Hz",
                                                   "natural frequency of the disk, contact "
                                                   "free")}, coords=coords)
    ds.attrs.update({"cyclic_sectors": int(n)})
    figures = []
    p = figure_path(case, context.out_dir, "nodal-diameter-diagram")
    if p is not None:
        figures.append(plot_nodal_diameters(ds, p, title=f"{case.title}: cyclic modes"))
    lines = [f"ND {k:>2}: " + ", ".join(f"{f:.5g}" for f in row[np.isfinite(row)]) + " Hz"
             for k, row in zip(ks, freq, strict=True)]
    return RunOutput(ds, figures, "\n".join(lines), True, [])


def plot_nodal_diameters(ds: xr.Dataset, path: Path | str, *, title: str | None = None
                         ) -> Path:
    """The nodal-diameter diagram: each family's frequency against the nodal diameter."""
    fig, axes = new_figure(title=title, panel_size=(6.0, 4.0))
    ax = axes[0, 0]
    nd = ds["nodal_diameter"].values
    modes = ds["mode"].values
    for j, m in enumerate(modes):
        f = ds["cyclic_frequency"].sel(mode=m).values
        ax.plot(nd, f, label=f"family {m}", **series_style(j, len(modes)))
    ax.set_xlabel("nodal diameter")
    ax.set_ylabel("natural frequency [Hz]")
    ax.set_xticks(nd)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return save(fig, path)


CYCLIC_MODES = Analysis.define(
    "cyclic-modes",
    {"n_modes": Field(Integer(lo=1), "modes per nodal diameter", default=6)},
    run_cyclic_modes,
    doc="Linear modes of the whole disk, contact free, per nodal diameter 0 .. N // 2, from "
    "the sector of the [cyclic] table (required). Writes `nodal-diameter-diagram.png` (the "
    "nodal-diameter or SAFE diagram).",
)
