"""Checks of the arguments of a periodic solve and of the drivers built on it (sweeps, wear
runs): one :class:`~fretwear.errors.InputError` naming the argument, the value and what is
expected.
"""

from __future__ import annotations

import numpy as np

from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis
from fretwear.limits import check_range
from fretwear.model.core import Model

#: the frequency of a quasi-static solve that gives none [Hz]: inertia and damping are
#: dropped, so it only sets the time scale (one load cycle per second); case files use it too
QUASI_STATIC_FREQUENCY = 1.0
#: highest harmonic inspected when checking that the loads act on the kept harmonics
LOAD_CHECK_HARMONICS = 64


def check_inputs(model, basis, frequency, *, quasi_static: bool = False, anchor=None,
                 U0=None) -> float:
    """Check the arguments of a periodic solve (and of the drivers built on it); return the
    frequency as a float [Hz].

    The frequency is required for a dynamic solve (``frequency=None``: an InputError); a
    quasi-static solve may omit it and then runs at :data:`QUASI_STATIC_FREQUENCY`.

    Raises TypeError for a model or basis of the wrong kind and InputError (a ValueError)
    naming the argument for: a basis with no harmonic; a frequency outside
    :data:`fretwear.limits.RANGES` or not > 0 for a dynamic solve; an ``anchor`` or ``U0`` of
    the wrong shape or not finite; loads whose periodic part acts only on harmonics the basis
    does not keep (the response would be static, reported as a converged solution).
    """
    if not isinstance(model, Model):
        raise TypeError(f"model = {model!r}: expected a fretwear Model (fretwear.from_mesh, "
                        "fretwear.from_matrices)")
    if not isinstance(basis, FourierBasis):
        raise TypeError(f"basis = {basis!r}: expected a fretwear FourierBasis")
    if not basis.harmonics:
        raise InputError("basis keeps no harmonic: expected at least one (e.g. "
                         "FourierBasis.up_to(7, 128))")
    if frequency is None:
        if not quasi_static:
            raise InputError("frequency is missing: expected the excitation frequency [Hz] "
                             "> 0 (only a quasi-static solve may omit it)")
        frequency = QUASI_STATIC_FREQUENCY
    f = check_range(frequency, "frequency", "frequency")
    if not quasi_static and f <= 0.0:
        raise InputError(f"frequency = {frequency!r} Hz: expected > 0 for a dynamic solve "
                         "(quasi_static=True drops inertia and damping)")
    nc, d = model.contact.n_nodes, model.contact.dim
    for name, value, shapes in (("anchor", anchor, [(nc, d - 1)]),
                                ("U0", U0, [(nc, d, basis.size), (nc * d, basis.size)])):
        if value is None:
            continue
        a = np.asarray(value)
        if a.dtype.kind not in "fiu" or a.shape not in shapes or not np.all(np.isfinite(a)):
            raise InputError(f"{name} has shape {a.shape} (dtype {a.dtype}): expected finite "
                             f"real values of shape {' or '.join(map(str, shapes))}")
    nmax = max(LOAD_CHECK_HARMONICS, max(basis.harmonics))
    acting = set()
    for load in model.loads:  # the waveforms' coefficients: no (harmonics x DOFs) array
        a, b = load.fourier_coefficients(nmax)
        vec = np.asarray(load.vector)
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))
                and np.all(np.isfinite(vec))):
            raise InputError(f"load {load.name!r} holds non-finite values (nan or inf)")
        if np.any(vec != 0):
            acting |= {n for n in range(1, nmax + 1) if a[n] != 0 or b[n] != 0}
    acting = sorted(acting)
    if acting and not set(acting) & set(basis.harmonics):
        raise InputError(f"the periodic loads act on harmonics {acting[:8]} but the basis "
                         f"keeps {list(basis.harmonics)}: the response would be static; keep "
                         "the harmonics of the loads")
    return f
