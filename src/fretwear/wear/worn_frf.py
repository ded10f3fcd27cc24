"""The nonlinear FRF of a worn interface (paper Fig. 24)."""

from __future__ import annotations

import numpy as np

from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions, SweepOptions, sweep_options
from fretwear.model.core import Model

#: the settings of a worn FRF: a sweep on a linear grid (the paper's Fig. 24)
WORN_FRF = SweepOptions(spacing="linear")


def frf_worn(model: Model, basis: FourierBasis, wear, f_min: float, f_max: float,
             n_points: int, *, anchor=None, options: SweepOptions | SolveOptions = WORN_FRF,
             condenser=None):
    """Nonlinear FRF with the worn gap ``gap + wear`` (paper Fig. 24): the sweep of
    :func:`fretwear.hb.sweep.sweep` (same argument order) with the model's gap opened by
    ``wear``.

    Parameters
    ----------
    model, basis : the structure and the Fourier basis.
    wear : (nc,) wear depths [m] (e.g. ``result.final_wear``, or 0).
    f_min, f_max, n_points : the frequency band [Hz] and its number of grid frequencies.
    anchor : (nc, d-1) stick anchors of the first point [m] (default: static preload).
    options : :class:`~fretwear.hb.options.SweepOptions` of the sweep (default
        :data:`WORN_FRF`: as a sweep's, on a linear grid); a
        :class:`~fretwear.hb.options.SolveOptions` stands for ``WORN_FRF`` with that solve.
    condenser : the condenser of ``model`` (:func:`fretwear.hb.reduce.exact_condenser` or
        :func:`fretwear.hb.modal.modal_condenser`, e.g. the wear run's); None: a new exact one
        for the sweep.

    Returns
    -------
    :class:`fretwear.hb.sweep.SweepResult` (``success``, ``message``); read amplitudes with
    ``SweepResult.amplitude(point, axis)``.
    """
    from fretwear.hb.sweep import sweep

    gap = np.broadcast_to(np.asarray(model.contact.gap, float), (model.contact.n_nodes,))
    gap = gap + np.asarray(wear, float)
    return sweep(model, basis, float(f_min), float(f_max), int(n_points),
                 options=sweep_options(options, WORN_FRF), gap=gap, anchor=anchor,
                 condenser=condenser)
