"""The nonlinear FRF of a worn interface (paper Fig. 24)."""

from __future__ import annotations

import numpy as np

from fretwear.hb.fourier import FourierBasis
from fretwear.model.core import Model


def frf_worn(model: Model, wear, frequencies_hz, basis: FourierBasis, *, anchor=None,
             point: str | None = None, solver: str = "powell", spacing: str = "linear",
             condenser=None, **kwargs):
    """Nonlinear FRF with the worn gap ``gap + wear`` (paper Fig. 24).

    Parameters
    ----------
    model : the structure; wear : (nc,) wear depths [m] (e.g. ``result.final_wear``, or 0).
    frequencies_hz : ``(f_min, f_max, n_points)`` [Hz].
    basis : Fourier basis.
    anchor : stick anchors of the first point (default: static preload).
    point : unused here (kept for the documented signature); read amplitudes with
        ``SweepResult.amplitude(point, axis)``.
    condenser : the condenser of ``model`` (:func:`fretwear.hb.reduce.exact_condenser` or
        :func:`fretwear.hb.modal.modal_condenser`, e.g. the wear run's); None: a new exact one
        for the sweep.
    solver, spacing, **kwargs : passed to :func:`fretwear.hb.sweep.sweep`.

    Returns
    -------
    :class:`fretwear.hb.sweep.SweepResult` (``success``, ``message``).
    """
    from fretwear.hb.sweep import sweep

    f_min, f_max, n_points = frequencies_hz
    gap = np.broadcast_to(np.asarray(model.contact.gap, float), (model.contact.n_nodes,))
    gap = gap + np.asarray(wear, float)
    return sweep(model, basis, float(f_min), float(f_max), int(n_points), spacing=spacing,
                 gap=gap, anchor=anchor, solver=solver, condenser=condenser, **kwargs)
