"""The nonlinear FRF of a worn interface (paper Fig. 24)."""

from __future__ import annotations

import numpy as np

from fretwear.hb.fourier import FourierBasis
from fretwear.model.core import Model


def frf_worn(model: Model, basis: FourierBasis, wear, f_min: float, f_max: float,
             n_points: int, *, anchor=None, spacing: str = "linear", condenser=None,
             **kwargs):
    """Nonlinear FRF with the worn gap ``gap + wear`` (paper Fig. 24): the sweep of
    :func:`fretwear.hb.sweep.sweep` (same argument order) with the model's gap opened by
    ``wear``.

    Parameters
    ----------
    model, basis : the structure and the Fourier basis.
    wear : (nc,) wear depths [m] (e.g. ``result.final_wear``, or 0).
    f_min, f_max, n_points : the frequency band [Hz] and its number of grid frequencies.
    anchor : (nc, d-1) stick anchors of the first point [m] (default: static preload).
    spacing : ``"linear"`` (default) or ``"log"``.
    **kwargs : the other keywords of :func:`fretwear.hb.sweep.sweep` (``eps``, ``solver``,
        ``time_domain``, ...), with its defaults. Read amplitudes with
        ``SweepResult.amplitude(point, axis)``.
    condenser : the condenser of ``model`` (:func:`fretwear.hb.reduce.exact_condenser` or
        :func:`fretwear.hb.modal.modal_condenser`, e.g. the wear run's); None: a new exact one
        for the sweep.

    Returns
    -------
    :class:`fretwear.hb.sweep.SweepResult` (``success``, ``message``).
    """
    from fretwear.hb.sweep import sweep

    gap = np.broadcast_to(np.asarray(model.contact.gap, float), (model.contact.n_nodes,))
    gap = gap + np.asarray(wear, float)
    return sweep(model, basis, float(f_min), float(f_max), int(n_points), spacing=spacing,
                 gap=gap, anchor=anchor, condenser=condenser, **kwargs)
