"""A family of nonlinear FRFs over the excitation level (the figure a joint engineer draws
first): the same sweep with every time-varying load multiplied by each level, the static
loads (a preload, ``waveform = "constant"``) kept.

In a case file, the sweep's key ``excitation_scale`` is one level, and a study varying it
(``[grid] "analysis.excitation_scale" = [0.1, 0.3, 1, 3]``) gives the family, its figure
(the FRFs of every level on one axis, normalised by the level, and the peak amplitude and
frequency against the level) and its summary (:mod:`fretwear.study.figures`). In Python,
:func:`load_levels` runs the family. Each level's sweep is one of :func:`fretwear.sweep`
(continuation in frequency; the levels are independent sweeps, so one failing level does not
stop the others).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from fretwear import api
from fretwear.errors import InputError
from fretwear.model.checks import model_argument
from fretwear.threads import limited
from fretwear.validate import is_real, whole


def excitation_scaled(model, level: float):
    """``model`` with every load that varies in time multiplied by ``level`` (the constant
    loads, e.g. a preload, kept): the same model object when ``level`` is 1."""
    if isinstance(level, bool) or not isinstance(level, int | float) or not (
            math.isfinite(level) and level > 0):
        raise InputError(f"level = {level!r}: expected a finite number > 0 (the factor on the "
                         "time-varying loads)")
    if level == 1:
        return model
    loads = [ld if ld.waveform == "constant" else
             dataclasses.replace(ld, vector=np.asarray(ld.vector, float) * float(level))
             for ld in model.loads]
    return dataclasses.replace(model, loads=loads)


@dataclass
class LoadLevels:
    """The FRFs of :func:`load_levels`: ``levels`` (increasing) and ``results`` (one
    :class:`~fretwear.hb.sweep_result.SweepResult` each); ``success`` when every sweep
    converged at every point; ``message`` one line per level."""

    levels: list
    results: list

    @property
    def success(self) -> bool:
        return all(r.success for r in self.results)

    @property
    def message(self) -> str:
        return "\n".join(f"level {lv:g}: {r.message}" for lv, r in
                         zip(self.levels, self.results, strict=True))

    def peaks(self, point: str, axis=0, harmonic: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """For each level, the largest amplitude [m] of ``harmonic`` of ``point`` along
        ``axis`` over the converged points, and its frequency [Hz] (NaN where none
        converged)."""
        amp = np.full(len(self.levels), np.nan)
        freq = np.full(len(self.levels), np.nan)
        for i, r in enumerate(self.results):
            a = np.asarray(r.amplitude(point, axis, harmonic), float)
            if np.any(np.isfinite(a)):
                j = int(np.nanargmax(a))
                amp[i], freq[i] = a[j], r.frequency_hz[j]
        return amp, freq


@model_argument
@limited
def load_levels(model, basis, f_min: float, f_max: float, n_points: int, levels, *,
                options=None, condenser=None) -> LoadLevels:
    """The nonlinear FRF at each excitation level: :func:`fretwear.sweep` of the model with
    its time-varying loads multiplied by the level (the constant ones kept).

    Parameters
    ----------
    model, basis : the structure and the Fourier basis.
    f_min, f_max, n_points : the frequency band [Hz] and its number of grid frequencies.
    levels : factors > 0 on the time-varying loads (sorted here).
    options : the :class:`~fretwear.hb.options.SweepOptions` of every sweep (default that of
        :func:`fretwear.sweep`).
    condenser : the condenser of ``model`` (the loads do not change it: built once here
        when not given, and shared by every level).

    Returns
    -------
    :class:`LoadLevels`.
    """
    for name, value in (("f_min", f_min), ("f_max", f_max)):
        if not is_real(value):
            raise InputError(f"{name} = {value!r}: expected a frequency > 0 [Hz]")
    whole(n_points, "n_points")
    if isinstance(levels, str | bytes) or any(not is_real(v) for v in np.ravel(
            np.asarray(levels, dtype=object))):
        raise InputError(f"levels = {levels!r}: expected factors > 0 (numbers)")
    try:
        values = sorted(float(v) for v in levels)
    except (TypeError, ValueError):
        values = []
    if not values:
        raise InputError(f"levels = {levels!r}: expected a non-empty list of numbers > 0")
    scaled = [excitation_scaled(model, v) for v in values]  # every level checked first
    if condenser is None:
        from fretwear.hb.condensers import condenser as make

        condenser = make(model, "exact")
    extra = {} if options is None else {"options": options}
    results = [api.sweep(m, basis, f_min, f_max, n_points, condenser=condenser, **extra)
               for m in scaled]
    return LoadLevels(values, results)
