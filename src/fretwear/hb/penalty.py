"""The DLFT penalty ``eps`` [N/m] from its rule: one function for every solver and analysis.

The penalty of the DLFT contact law (paper eq. 23) is given by a rule, spelt the same in case
files and in Python:

* ``"auto"``: the spectral radius of ``Z_r`` over the kept harmonics at the frequency of the
  solve (largest ``|eigenvalue|`` of ``Z_r(n w)``, ``n = 0, h1, .., hk``): the paper's rule
  (section 3.2). In a sweep it is applied point by point.
* ``"static"``: the spectral radius of the static reduced stiffness ``K_r = Z_r(0)``, the same
  at every frequency (the default of sweeps: docs/theory.md, "The penalty eps").
* a positive number [N/m], used as given.
"""

from __future__ import annotations

import math
from numbers import Real

import numpy as np

from fretwear.errors import InputError
from fretwear.hb.connectors import connect
from fretwear.hb.reduce import Reduced, condense
from fretwear.model.core import Model

#: the rules :func:`penalty` accepts besides a positive number [N/m]
RULES = ("auto", "static")


def check_rule(rule) -> str | float:
    """``rule`` if it is ``"auto"``, ``"static"`` or a positive finite number (as a float);
    otherwise an :class:`~fretwear.errors.InputError` (a ``ValueError``) naming ``eps``."""
    if isinstance(rule, str) and rule in RULES:
        return rule
    if isinstance(rule, Real) and not isinstance(rule, bool):
        value = float(rule)
        if value > 0 and math.isfinite(value):
            return value
    raise InputError(f"eps = {rule!r}: expected \"auto\" (spectral radius of Z_r over the kept "
                     "harmonics), \"static\" (spectral radius of the static K_r) or a positive "
                     "number [N/m]")


def penalty(rule, *, model: Model | None = None, frequency: float = 0.0, orders=None,
            quasi_static: bool = False, reduced: Reduced | None = None) -> float:
    """The DLFT penalty [N/m] of ``rule`` (module docstring) at the excitation ``frequency``.

    Parameters
    ----------
    rule : ``"auto"``, ``"static"`` or a positive number [N/m].
    model : the structure (needed unless ``reduced`` is given).
    frequency, orders, quasi_static : the frequency [Hz], harmonic orders ``[0, h1, .., hk]``
        and inertia setting of the solve (``"auto"`` only, when ``reduced`` is not given).
    reduced : the condensation of the solve (:func:`fretwear.hb.reduce.condense`) if already
        computed: ``"auto"`` then takes its blocks; ``"static"`` without a ``model`` takes its
        order-0 block, which is ``K_r`` at every frequency.

    Returns
    -------
    eps [N/m], positive.
    """
    rule = check_rule(rule)
    if not isinstance(rule, str):
        return rule
    if rule == "auto":
        if reduced is None:
            if model is None or orders is None:
                raise ValueError('eps = "auto" needs the reduced model or the model and orders')
            reduced = connect(condense(model, frequency, orders, quasi_static=quasi_static),
                              model.contact)
        return reduced.spectral_radius()
    if model is not None:
        return connect(condense(model, 0.0, [0], quasi_static=True),
                       model.contact).spectral_radius()
    if reduced is None or int(reduced.orders[0]) != 0:
        raise ValueError('eps = "static" needs the model or a reduced model with order 0')
    return float(np.max(np.abs(np.linalg.eigvals(reduced.Z[0]))))
