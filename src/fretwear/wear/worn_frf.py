"""The nonlinear FRF of a worn interface (paper Fig. 24)."""

from __future__ import annotations

import numpy as np

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions, SweepOptions, sweep_options
from fretwear.model.core import Model

#: the settings of a worn FRF: a sweep on a linear grid (the paper's Fig. 24)
WORN_FRF = SweepOptions(spacing="linear")


def frf_worn(model: Model, wear, frequencies_hz, basis: FourierBasis, *, anchor=None,
             point: str | None = None, options: SweepOptions | SolveOptions = WORN_FRF,
             condenser=None):
    """Nonlinear FRF with the worn gap ``gap + wear`` (paper Fig. 24).

    Parameters
    ----------
    model : the structure; wear : (nc,) wear depths [m] (e.g. ``result.final_wear``, or 0).
    frequencies_hz : ``(f_min, f_max, n_points)`` [Hz].
    basis : Fourier basis.
    anchor : stick anchors of the first point (default: static preload).
    point : unused here (kept for the documented signature); read amplitudes with
        ``SweepResult.amplitude(point, axis)``.
    options : :class:`~fretwear.hb.options.SweepOptions` of the sweep (default
        :data:`WORN_FRF`: as a sweep's, on a linear grid); a
        :class:`~fretwear.hb.options.SolveOptions` stands for ``WORN_FRF`` with that solve.
    condenser : the condenser of ``model``, as for :func:`fretwear.hb.sweep.sweep`.

    Returns
    -------
    :class:`fretwear.hb.sweep.SweepResult` (``success``, ``message``).
    """
    from fretwear.hb.sweep import sweep

    f_min, f_max, n_points = frequencies_hz
    gap = np.broadcast_to(np.asarray(model.contact.gap, float), (model.contact.n_nodes,))
    gap = gap + np.asarray(wear, float)
    return sweep(model, basis, float(f_min), float(f_max), int(n_points),
                 options=sweep_options(options, WORN_FRF), gap=gap, anchor=anchor,
                 condenser=condenser)
